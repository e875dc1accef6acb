/* test_rt_sampler.c — the path tracer's sampler on its own (backends/rt internals, sy_rt_sampler.h):
 *   - the unscrambled Sobol values of dimensions 0-3 at the first indices (van der Corput and the
 *     Joe-Kuo dimensions 2-4: known values);
 *   - sy_rt_sobol_sample4 equals the construction written out from its parts (the set's seed
 *     hash(pixel seed ^ hash(set)), the index shuffled by Laine-Karras on its reversed bits, the
 *     unscrambled point at the shuffled index, each dimension Owen-scrambled with its own seed) at
 *     sets on both sides of the seed-hash table's end (SY_RT_SOBOL_SETS) and far beyond it;
 *   - a set's scramble derived once (sy_rt_sobol_seed_of, sy_rt_sobol_sample4_seeded) gives the
 *     same points bit for bit, at the same sets and pixels and at indices over all 32 bits;
 *   - stratification: for several pixels and sets, the first 2^k points' dimensions 0 and 1 form a
 *     (0,k,2)-net (every elementary interval of area 2^-k, for every shape, holds exactly one point)
 *     and dimensions 2 and 3 are each stratified in 2^k intervals. */
#include "../support/sy_check.h"
#include "sy_rt_math.h"
#include "sy_rt_sampler.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static uint32_t rev(uint32_t x)
{
    uint32_t r = 0;
    for (int b = 0; b < 32; ++b) r |= ((x >> b) & 1u) << (31 - b);
    return r;
}

/* Burley's Laine-Karras permutation (JCGT 2020, listing 2's improved constants), written out again
 * from the paper on purpose (the sampler's own is static there): the test's oracle must not share
 * the code it checks, or a wrong constant in the sampler would pass */
static uint32_t lk(uint32_t x, uint32_t seed)
{
    x ^= x * 0x3d20adeau;
    x += seed;
    x *= (seed >> 16) | 1u;
    x ^= x * 0x05526c56u;
    x ^= x * 0x53a22864u;
    return x;
}

static void reference4(const sy_rt_sobol *s, uint32_t pixel_seed, uint32_t set, uint32_t index, float out[4])
{
    uint32_t seed = sy_rt_hash32(pixel_seed ^ sy_rt_hash32(set * 0x9e3779b9u + 0x632be5abu));
    uint32_t shuffled = rev(lk(rev(index), seed));
    for (uint32_t d = 0; d < 4; ++d) {
        uint32_t x = rev(lk(rev(sy_rt_sobol_raw(s, shuffled, d)), sy_rt_hash32(seed + d * 0x68e31da4u)));
        out[d] = (float)(x >> 8) * (1.0f / 16777216.0f);
    }
}

int main(void)
{
    sy_rt_sobol *s = malloc(sizeof *s);
    if (!s) return 1;
    sy_rt_sobol_init(s);

    /* natural (not Gray-code) order; dimension 0: van der Corput; 1: (s 1, a 0, m 1); 2: (2, 1,
     * 1 3); 3: (3, 1, 1 3 1); the first three as SciPy's Sobol points (Gray-code order) list them */
    static const uint32_t want[4][8] = {
        {0u, 0x80000000u, 0x40000000u, 0xc0000000u, 0x20000000u, 0xa0000000u, 0x60000000u, 0xe0000000u},
        {0u, 0x80000000u, 0xc0000000u, 0x40000000u, 0xa0000000u, 0x20000000u, 0x60000000u, 0xe0000000u},
        {0u, 0x80000000u, 0xc0000000u, 0x40000000u, 0x60000000u, 0xe0000000u, 0xa0000000u, 0x20000000u},
        {0u, 0x80000000u, 0xc0000000u, 0x40000000u, 0x20000000u, 0xa0000000u, 0xe0000000u, 0x60000000u},
    };
    for (uint32_t d = 0; d < 4; ++d)
        for (uint32_t i = 0; i < 8; ++i)
            EXPECT_MSG(sy_rt_sobol_raw(s, i, d) == want[d][i], "Sobol dimension %u index %u: 0x%08x, want 0x%08x", d, i,
                       sy_rt_sobol_raw(s, i, d), want[d][i]);

    /* the sampler against its construction, on both sides of the set table's end */
    const uint32_t sets[] = {0u, 1u, 2u, 129u, SY_RT_SOBOL_SETS - 1u, SY_RT_SOBOL_SETS, SY_RT_SOBOL_SETS + 1u, 4096u,
                             0xfffffffu};
    const uint32_t pixels[] = {0u, 1u, 0x5bd1e995u, 0xdeadbeefu};
    int mismatches = 0;
    for (size_t a = 0; a < sizeof sets / sizeof sets[0]; ++a)
        for (size_t p = 0; p < sizeof pixels / sizeof pixels[0]; ++p)
            for (uint32_t i = 0; i < 64; ++i) {
                float got[4], ref[4];
                sy_rt_sobol_sample4(s, pixels[p], sets[a], i * 37u + (uint32_t)a, got);
                reference4(s, pixels[p], sets[a], i * 37u + (uint32_t)a, ref);
                if (memcmp(got, ref, sizeof got) != 0 && mismatches++ < 5)
                    fprintf(stderr, "FAIL: set %u pixel 0x%08x index %u: (%.7f %.7f %.7f %.7f), construction (%.7f %.7f %.7f %.7f)\n",
                            sets[a], pixels[p], i * 37u + (uint32_t)a, got[0], got[1], got[2], got[3], ref[0], ref[1],
                            ref[2], ref[3]);
            }
    EXPECT_MSG(mismatches == 0, "%d of %zu points differ from the construction", mismatches,
               sizeof sets / sizeof sets[0] * (sizeof pixels / sizeof pixels[0]) * 64);

    /* a set's scramble derived once (sy_rt_sobol_seed_of) gives the same points as sy_rt_sobol_sample4 */
    int seeded_mismatches = 0;
    for (size_t a = 0; a < sizeof sets / sizeof sets[0]; ++a)
        for (size_t p = 0; p < sizeof pixels / sizeof pixels[0]; ++p) {
            sy_rt_sobol_seed k;
            sy_rt_sobol_seed_of(s, pixels[p], sets[a], &k);
            for (uint32_t i = 0; i < 64; ++i) {
                uint32_t index = i * 0x9e3779b9u + (uint32_t)a;
                float got[4], want4[4];
                sy_rt_sobol_sample4_seeded(s, &k, index, got);
                sy_rt_sobol_sample4(s, pixels[p], sets[a], index, want4);
                if (memcmp(got, want4, sizeof got) != 0 && seeded_mismatches++ < 5)
                    fprintf(stderr, "FAIL: seeded set %u pixel 0x%08x index %u: (%.7f %.7f %.7f %.7f), want (%.7f %.7f %.7f %.7f)\n",
                            sets[a], pixels[p], index, got[0], got[1], got[2], got[3], want4[0], want4[1], want4[2],
                            want4[3]);
            }
        }
    EXPECT_MSG(seeded_mismatches == 0, "%d seeded points differ from sy_rt_sobol_sample4", seeded_mismatches);

    /* stratification of the first 2^k points */
    for (uint32_t k = 1; k <= 8; ++k)
        for (size_t a = 0; a < 4; ++a)
            for (size_t p = 0; p < sizeof pixels / sizeof pixels[0]; ++p) {
                uint32_t n = 1u << k;
                uint8_t cell[256];
                float pt[256][4];
                for (uint32_t i = 0; i < n; ++i) sy_rt_sobol_sample4(s, pixels[p], sets[a * 2], i, pt[i]);
                for (uint32_t ax = 0; ax <= k; ++ax) { /* intervals of 2^-ax x 2^-(k - ax) */
                    memset(cell, 0, sizeof cell);
                    for (uint32_t i = 0; i < n; ++i) {
                        uint32_t cx = (uint32_t)(pt[i][0] * (float)(1u << ax)), cy = (uint32_t)(pt[i][1] * (float)(1u << (k - ax)));
                        cell[(cx << (k - ax)) | cy]++;
                    }
                    int bad = 0;
                    for (uint32_t c = 0; c < n; ++c) bad += cell[c] != 1u;
                    EXPECT_MSG(bad == 0, "set %u pixel 0x%08x, first %u points, dimensions 0-1 in %ux%u intervals: %d empty or doubled",
                               sets[a * 2], pixels[p], n, 1u << ax, 1u << (k - ax), bad);
                }
                for (uint32_t d = 2; d < 4; ++d) {
                    memset(cell, 0, sizeof cell);
                    for (uint32_t i = 0; i < n; ++i) cell[(uint32_t)(pt[i][d] * (float)n)]++;
                    int bad = 0;
                    for (uint32_t c = 0; c < n; ++c) bad += cell[c] != 1u;
                    EXPECT_MSG(bad == 0, "set %u pixel 0x%08x, first %u points, dimension %u in %u intervals: %d empty or doubled",
                               sets[a * 2], pixels[p], n, d, n, bad);
                }
            }
    free(s);
    return sy_check_finish("rt_sampler");
}
