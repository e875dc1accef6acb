/* sy_rt_sampler.c — Owen-scrambled Sobol points (see sy_rt_sampler.h). */
#include "sy_rt_sampler.h"
#include "sy_rt_math.h"

static void build_tables(sy_rt_sobol *s);

/* the first step of a set's per-pixel seed (sy_rt_sobol.set_hash) */
static inline uint32_t set_hash(uint32_t set)
{
    return sy_rt_hash32(set * 0x9e3779b9u + 0x632be5abu);
}
static inline uint32_t set_hash_at(const sy_rt_sobol *s, uint32_t set)
{
    return set < SY_RT_SOBOL_SETS ? s->set_hash[set] : set_hash(set);
}

void sy_rt_sobol_init(sy_rt_sobol *s)
{
    /* Joe-Kuo new-joe-kuo-6.21201, dimensions 2..4 (s, a, m); dimension 1 is van der Corput. */
    static const uint32_t deg[4] = {0, 1, 2, 3}, poly[4] = {0, 0, 1, 1};
    static const uint32_t m[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 3, 0}, {1, 3, 1}};
    for (uint32_t k = 0; k < 32; ++k) s->v[0][k] = 1u << (31u - k);
    for (uint32_t d = 1; d < 4; ++d) {
        uint32_t sd = deg[d], a = poly[d];
        for (uint32_t k = 0; k < 32; ++k) {
            if (k < sd) {
                s->v[d][k] = m[d][k] << (31u - k);
                continue;
            }
            uint32_t x = s->v[d][k - sd] ^ (s->v[d][k - sd] >> sd);
            for (uint32_t j = 1; j < sd; ++j)
                if ((a >> (sd - 1u - j)) & 1u) x ^= s->v[d][k - j];
            s->v[d][k] = x;
        }
    }
    build_tables(s);
    for (uint32_t set = 0; set < SY_RT_SOBOL_SETS; ++set) s->set_hash[set] = set_hash(set);
}

uint32_t sy_rt_sobol_raw(const sy_rt_sobol *s, uint32_t index, uint32_t dim)
{
    uint32_t x = 0;
    for (uint32_t k = 0; index; index >>= 1, ++k)
        if (index & 1u) x ^= s->v[dim][k];
    return x;
}

static inline uint32_t reverse_bits(uint32_t x)
{
    x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
    x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
    x = ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
#if defined(__GNUC__)
    return __builtin_bswap32(x);
#else
    x = ((x >> 8) & 0x00ff00ffu) | ((x & 0x00ff00ffu) << 8);
    return (x >> 16) | (x << 16);
#endif
}

/* Burley's improved Laine-Karras permutation; applied to a bit-reversed value and reversed back it
 * is the nested uniform (Owen) scramble. */
static inline uint32_t laine_karras(uint32_t x, uint32_t seed)
{
    x ^= x * 0x3d20adeau;
    x += seed;
    x *= (seed >> 16) | 1u;
    x ^= x * 0x05526c56u;
    x ^= x * 0x53a22864u;
    return x;
}

/* The tables hold everything bit-reversed, so that a point costs one reversal per dimension (and
 * one for the index) instead of two: with j = LK(R(index)) the scrambled index is R(j), and byte b
 * of j selects the reversed direction numbers of index bits 31 - 8b - m. */
static void build_tables(sy_rt_sobol *s)
{
    for (uint32_t d = 0; d < 4; ++d)
        for (uint32_t b = 0; b < 4; ++b)
            for (uint32_t x = 0; x < 256; ++x) {
                uint32_t r = 0;
                for (uint32_t m = 0; m < 8; ++m)
                    if (x & (1u << m)) r ^= reverse_bits(s->v[d][31u - 8u * b - m]);
                s->t[b][x][d] = r;
            }
}

/* The lanes' scramble seeds are the hashes of seed + d x 0x68e31da4 (d = 0..3). */
#define LANE_STEP 0x68e31da4u

#if defined(__GNUC__)
/* The four dimensions' scrambles side by side (GCC / Clang vector extensions: SSE2 on x86-64). */
typedef uint32_t sy_u32x4 __attribute__((vector_size(16)));

#if !defined(__clang__)
typedef uint8_t sy_u8x16 __attribute__((vector_size(16)));
/* Each byte's bits reversed by two table look-ups of its nibbles, then each lane's bytes reversed:
 * three byte shuffles (pshufb in the SSE4.1 and AVX2 clones; the default clone, for CPUs without
 * SSSE3, gets GCC's generic code) instead of five rounds of shifts and masks, the Sobol point's
 * longest dependent stretch (DamagedHelmet's render 5 % faster with the signed conversion below).
 * Clang has no variable __builtin_shuffle: it keeps the shifts and masks. */
static inline sy_u32x4 reverse_bits4(sy_u32x4 x)
{
    /* a nibble reversed, as the high nibble (of a low one) and as the low nibble (of a high one) */
    const sy_u8x16 rev_hi = {0x00, 0x80, 0x40, 0xc0, 0x20, 0xa0, 0x60, 0xe0, 0x10, 0x90, 0x50, 0xd0, 0x30, 0xb0, 0x70, 0xf0};
    const sy_u8x16 rev_lo = {0x0, 0x8, 0x4, 0xc, 0x2, 0xa, 0x6, 0xe, 0x1, 0x9, 0x5, 0xd, 0x3, 0xb, 0x7, 0xf};
    const sy_u8x16 bswap = {3, 2, 1, 0, 7, 6, 5, 4, 11, 10, 9, 8, 15, 14, 13, 12};
    sy_u8x16 b = (sy_u8x16)x;
    sy_u8x16 r = __builtin_shuffle(rev_hi, b & 0x0f) | __builtin_shuffle(rev_lo, (sy_u8x16)((sy_u32x4)b >> 4) & 0x0f);
    return (sy_u32x4)__builtin_shuffle(r, bswap);
}
#else
static inline sy_u32x4 reverse_bits4(sy_u32x4 x)
{
    x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
    x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
    x = ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
    x = ((x >> 8) & 0x00ff00ffu) | ((x & 0x00ff00ffu) << 8);
    return (x >> 16) | (x << 16);
}
#endif

/* One clone per instruction set (the loader picks at start-up): SSE4.1's pmulld multiplies four
 * lanes in one instruction where SSE2 needs six (5-8 % of a path-traced frame on the Cornell box).
 * GCC only: clang 14 leaves the function's symbol undefined when a program links the static archive
 * (the clang fuzz build's web and culling targets link this back-end). */
#if defined(__clang__)
#define SY_RT_SAMPLE4_CLONES
#else
#define SY_RT_SAMPLE4_CLONES __attribute__((target_clones("avx2", "sse4.1", "default")))
#endif

/* the set's seed and the lanes' (sy_rt_hash32 of each lane's seed, side by side) */
__attribute__((always_inline)) static inline sy_u32x4 lanes_of(const sy_rt_sobol *s, uint32_t pixel_seed, uint32_t set,
                                                              uint32_t *seed)
{
    uint32_t sd = sy_rt_hash32(pixel_seed ^ set_hash_at(s, set));
    sy_u32x4 h = {sd, sd + LANE_STEP, sd + 2u * LANE_STEP, sd + 3u * LANE_STEP};
    h ^= h >> 16, h *= 0x7feb352du, h ^= h >> 15, h *= 0x846ca68bu, h ^= h >> 16;
    *seed = sd;
    return h;
}

/* the point at index from the set's seed and the lanes' */
__attribute__((always_inline)) static inline void point_of(const sy_rt_sobol *s, uint32_t seed, sy_u32x4 h,
                                                          uint32_t index, float out[4])
{
    uint32_t j = laine_karras(reverse_bits(index), seed);
    uint32_t j0 = j & 0xffu, j1 = (j >> 8) & 0xffu, j2 = (j >> 16) & 0xffu, j3 = j >> 24;
    sy_u32x4 x = *(const sy_u32x4 *)s->t[0][j0] ^ *(const sy_u32x4 *)s->t[1][j1] ^ *(const sy_u32x4 *)s->t[2][j2] ^
                 *(const sy_u32x4 *)s->t[3][j3];
    x ^= x * 0x3d20adeau;
    x += h;
    x *= (h >> 16) | 1u;
    x ^= x * 0x05526c56u;
    x ^= x * 0x53a22864u;
    x = reverse_bits4(x) >> 8;
    /* (as signed: every lane is below 2^24, so the same value, and x86 converts signed lanes in one
     * instruction where unsigned ones take six) */
    for (uint32_t d = 0; d < 4; ++d) out[d] = (float)(int32_t)x[d] * (1.0f / 16777216.0f);
}

SY_RT_SAMPLE4_CLONES
void sy_rt_sobol_sample4(const sy_rt_sobol *s, uint32_t pixel_seed, uint32_t set, uint32_t index, float out[4])
{
    uint32_t seed;
    sy_u32x4 h = lanes_of(s, pixel_seed, set, &seed);
    point_of(s, seed, h, index, out);
}

SY_RT_SAMPLE4_CLONES
void sy_rt_sobol_seed_of(const sy_rt_sobol *s, uint32_t pixel_seed, uint32_t set, sy_rt_sobol_seed *out)
{
    *(sy_u32x4 *)out->lane = lanes_of(s, pixel_seed, set, &out->seed);
}

SY_RT_SAMPLE4_CLONES
void sy_rt_sobol_sample4_seeded(const sy_rt_sobol *s, const sy_rt_sobol_seed *k, uint32_t index, float out[4])
{
    point_of(s, k->seed, *(const sy_u32x4 *)k->lane, index, out);
}
#else
void sy_rt_sobol_seed_of(const sy_rt_sobol *s, uint32_t pixel_seed, uint32_t set, sy_rt_sobol_seed *out)
{
    out->seed = sy_rt_hash32(pixel_seed ^ set_hash_at(s, set));
    for (uint32_t d = 0; d < 4; ++d) out->lane[d] = sy_rt_hash32(out->seed + d * LANE_STEP);
}

void sy_rt_sobol_sample4_seeded(const sy_rt_sobol *s, const sy_rt_sobol_seed *k, uint32_t index, float out[4])
{
    uint32_t j = laine_karras(reverse_bits(index), k->seed);
    for (uint32_t d = 0; d < 4; ++d) {
        uint32_t rr = s->t[0][j & 0xffu][d] ^ s->t[1][(j >> 8) & 0xffu][d] ^ s->t[2][(j >> 16) & 0xffu][d] ^ s->t[3][j >> 24][d];
        uint32_t x = reverse_bits(laine_karras(rr, k->lane[d]));
        out[d] = (float)(x >> 8) * (1.0f / 16777216.0f);
    }
}

void sy_rt_sobol_sample4(const sy_rt_sobol *s, uint32_t pixel_seed, uint32_t set, uint32_t index, float out[4])
{
    sy_rt_sobol_seed k;
    sy_rt_sobol_seed_of(s, pixel_seed, set, &k);
    sy_rt_sobol_sample4_seeded(s, &k, index, out);
}
#endif
