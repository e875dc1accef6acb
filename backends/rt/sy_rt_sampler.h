/* sy_rt_sampler.h — the path tracer's low-discrepancy sampler: the first four Sobol dimensions
 * (Joe-Kuo direction numbers) as padded 4-dimensional sets, each Owen-scrambled per pixel and per
 * set with the hash-based nested uniform scramble, and the sample index shuffled the same way
 * (Burley, "Practical Hash-based Owen Scrambling", JCGT 2020). Every pixel gets a decorrelated,
 * stratified sequence; the same (pixel seed, set, index) always gives the same point.
 * Header + source; internal to backends/rt; plain data, thread-safe to share read-only. */
#ifndef SY_RT_SAMPLER_H
#define SY_RT_SAMPLER_H

#include <stdint.h>

/* sets whose seed hash is a table look-up (the path tracer's sets reach 2 + 2 x max_depth) */
enum { SY_RT_SOBOL_SETS = 1024 };

typedef struct sy_rt_sobol {
    uint32_t v[4][32];       /* direction numbers of dimensions 0..3 */
    /* per byte b of the scrambled, bit-reversed index and its value x: the XOR of the byte's direction
     * numbers, bit-reversed, of the four dimensions side by side (one 16-byte load per byte) */
    _Alignas(16) uint32_t t[4][256][4];
    /* the hash of each set below SY_RT_SOBOL_SETS (the per-pixel seed's first step: the same for
     * every pixel, so looked up, not computed, on the path's dependency chain) */
    uint32_t set_hash[SY_RT_SOBOL_SETS];
} sy_rt_sobol;

void sy_rt_sobol_init(sy_rt_sobol *s);

/* Point `index` of the 4D set `set` for the pixel whose seed is pixel_seed; out in [0, 1)^4. */
void sy_rt_sobol_sample4(const sy_rt_sobol *s, uint32_t pixel_seed, uint32_t set, uint32_t index, float out[4]);

/* What sy_rt_sobol_sample4 derives from (pixel seed, set) before it looks at the index: the set's
 * seed and its four dimensions' scramble seeds. A pixel that takes many samples derives it once per
 * set (sy_rt_sobol_seed_of) and draws its points with sy_rt_sobol_sample4_seeded, which gives
 * sy_rt_sobol_sample4's points bit for bit with two hashes fewer on each point's dependency chain.
 * Plain data, owned by the caller. */
typedef struct sy_rt_sobol_seed {
    _Alignas(16) uint32_t lane[4]; /* each dimension's scramble seed */
    uint32_t seed;                 /* the set's seed (scrambles the index) */
} sy_rt_sobol_seed;

void sy_rt_sobol_seed_of(const sy_rt_sobol *s, uint32_t pixel_seed, uint32_t set, sy_rt_sobol_seed *out);
void sy_rt_sobol_sample4_seeded(const sy_rt_sobol *s, const sy_rt_sobol_seed *k, uint32_t index, float out[4]);

/* Unscrambled 32-bit Sobol value of dimension dim (0..3) at index (tests). */
uint32_t sy_rt_sobol_raw(const sy_rt_sobol *s, uint32_t index, uint32_t dim);

#endif /* SY_RT_SAMPLER_H */
