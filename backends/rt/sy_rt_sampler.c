/* sy_rt_sampler.c — Owen-scrambled Sobol points (see sy_rt_sampler.h). */
#include "sy_rt_sampler.h"
#include "sy_rt_math.h"

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
    for (uint32_t d = 0; d < 4; ++d)
        for (uint32_t b = 0; b < 4; ++b)
            for (uint32_t x = 0; x < 256; ++x) {
                uint32_t r = 0;
                for (uint32_t k = 0; k < 8; ++k)
                    if (x & (1u << k)) r ^= s->v[d][8u * b + k];
                s->t[d][b][x] = r;
            }
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

/* Burley's improved Laine-Karras permutation on bit-reversed values: a nested uniform scramble. */
static inline uint32_t nested_uniform_scramble(uint32_t x, uint32_t seed)
{
    x = reverse_bits(x);
    x ^= x * 0x3d20adeau;
    x += seed;
    x *= (seed >> 16) | 1u;
    x ^= x * 0x05526c56u;
    x ^= x * 0x53a22864u;
    return reverse_bits(x);
}

void sy_rt_sobol_sample4(const sy_rt_sobol *s, uint32_t pixel_seed, uint32_t set, uint32_t index, float out[4])
{
    uint32_t seed = sy_rt_hash32(pixel_seed ^ sy_rt_hash32(set * 0x9e3779b9u + 0x632be5abu));
    uint32_t i = nested_uniform_scramble(index, seed);
    for (uint32_t d = 0; d < 4; ++d) {
        const uint32_t(*t)[256] = s->t[d];
        uint32_t raw = t[0][i & 0xffu] ^ t[1][(i >> 8) & 0xffu] ^ t[2][(i >> 16) & 0xffu] ^ t[3][i >> 24];
        uint32_t x = nested_uniform_scramble(raw, sy_rt_hash32(seed + d * 0x68e31da4u));
        out[d] = (float)(x >> 8) * (1.0f / 16777216.0f);
    }
}
