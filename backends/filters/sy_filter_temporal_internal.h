/* sy_filter_temporal_internal.h — the calls between the temporal stage's modules (not installed):
 * the row loops' inlining and instruction-set attributes, branch-free min / max, the a-trous
 * edge-stopping weight (expneg, tested in test_filters_temporal), and the
 * reprojection of a row into the previous history (sy_filter_temporal_reproject.c), which
 * sy_filter_temporal.c's integration pass calls per row. Thread-safety: the functions are pure
 * (they write only their output rows), any thread. */
#ifndef SY_FILTER_TEMPORAL_INTERNAL_H
#define SY_FILTER_TEMPORAL_INTERNAL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

/* the helpers of the row loops inline into every clone of them (GCC's early inliner leaves a "cold"
 * call otherwise, and the loop does not vectorise) */
#if defined(__GNUC__)
#define SY_TEMPORAL_INLINE __attribute__((always_inline))
#else
#define SY_TEMPORAL_INLINE
#endif

/* The row loops that carry the work, one tap (dx, dy) over columns [x0, x1): restrict parameters
 * (GCC does not vectorise them through local restrict pointers), no branch, no division. x86-64
 * GCC: AVX-512 and AVX2 clones beside the SSE2 default, picked at load time (the same operations in
 * the same order per lane, no FMA contraction in ISO C mode: the same results; the AVX-512 clone,
 * 16 lanes, took the filter's CPU time from 92-107 to 77-83 ms per 640x360 frame, `sy bench
 * temporal`, alternating runs under load). */
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define SY_TEMPORAL_CLONES __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define SY_TEMPORAL_CLONES
#endif

/* branch-free min / max without the library call GCC emits for fmaxf's NaN rules */
static inline SY_TEMPORAL_INLINE float fmx(float a, float b)
{
    return a > b ? a : b;
}
static inline SY_TEMPORAL_INLINE float fmn(float a, float b)
{
    return a < b ? a : b;
}

/* The a-trous edge-stopping weight, exp(-x) for x >= 0 (NaN counts as large) as 2^(-x log2 e) with
 * the power of 2 interpolated linearly between integers (Schraudolph 1999, "A fast, compact
 * approximation of the exponential function"): the float's bits are the integer part of
 * 127 x 2^23 - x 2^23 / ln 2, so the integer part of x log2 e lands in the exponent and the
 * fraction, linearly, in the mantissa. Within -0.0003 % and +6.2 % of exp(-x), monotone, 1 at
 * x = 0; four operations instead of a degree-5 polynomial's sixteen, which were a third of the
 * fused a-trous loop: the a-trous phase 0.87x, every quality line of `sy bench temporal` the same
 * or slightly lower in error (docs/FILTERS.md, "A cheaper edge-stopping weight"). x is clamped to
 * xmax (callers pass EXP_MAX). xmax reaches the row loop through memory, not as a constant: with a
 * constant, GCC folds the clamped case into a branch of its own and then cannot vectorise the AVX2
 * clone.
 * EXP_MAX is 16: a clamped tap's weight, at most 0.125 x 1.14e-7 = 1.4e-8 (e^-16 = 1.13e-7), is
 * below half an ulp of any sum of weights (the centre alone is 0.25), so it changes none, and it
 * and its square (the variance's weight) stay normal floats. Clamped at 87 (as before), far taps'
 * weights and their squares were subnormal, which this machine computes slowly: the a-trous phase
 * about 0.8x with 16 on the demo (docs/FILTERS.md, "Subnormal weights"). */
#define EXP_MAX 16.0f
static inline SY_TEMPORAL_INLINE float expneg(float x, float xmax)
{
    x = fmn(x, xmax);
    int32_t bits = (int32_t)(1065353216.0f - x * 12102203.0f); /* 127 x 2^23 - x 2^23 / ln 2 */
    float s;
    memcpy(&s, &bits, sizeof s);
    return s;
}

/* Whether sy_filter_temporal_reproject_row may take its AVX2 path (an x86-64 CPU with AVX2 and a
 * compiler that has the intrinsics); ask once per frame. */
bool sy_filter_temporal_reproject_avx2(void);

/* Bilinear reprojection of a row's hits into the previous history (reproject's rule, branch-free so
 * that it vectorises with gathers): the points' previous positions pa pb pc (the frame's, moved back
 * by the object motion), normals na nb nc, depth z and hit h (planes, the row's w pixels); M the
 * previous world_to_pixel, base its history (hw x hh, 17 planes hn apart: illum 3, dir 3, moments
 * 4, length, position 3, normal 3), dtol / ntol the depth and normal tolerances. Out: R (11 planes n
 * apart: the history, 0 where none fits) and ru (1 where reused). avx2 (from
 * sy_filter_temporal_reproject_avx2): 8 pixels at a time (gathers, or plain loads where the 8
 * pixels' taps lie side by side), the same results. */
void sy_filter_temporal_reproject_row(bool avx2, int w, size_t n, const float *M, int hw, int hh, size_t hn,
                                      const float *base, float dtol, float ntol, const float *pa, const float *pb,
                                      const float *pc, const float *na, const float *nb, const float *nc,
                                      const float *z, const float *h, float *R, float *ru);

#endif
