/* sy_rt_math.h — small inline float3 / matrix helpers used inside the ray-tracing back-end, with
 * the per-sample functions built on them: sine and cosine of 2 pi u, atan2 and acos without libm,
 * the environments' lat-long mapping, CDF searches.
 * Header-only; internal to backends/rt (the public API uses plain float arrays). */
#ifndef SY_RT_MATH_H
#define SY_RT_MATH_H

#include <math.h>
#include <stdbool.h>
#include <stdint.h>

typedef struct sy_rt_v3 { float x, y, z; } sy_rt_v3;

static inline sy_rt_v3 v3(float x, float y, float z) { sy_rt_v3 r = {x, y, z}; return r; }
static inline sy_rt_v3 v3_load(const float *p) { return v3(p[0], p[1], p[2]); }
static inline sy_rt_v3 v3_add(sy_rt_v3 a, sy_rt_v3 b) { return v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline sy_rt_v3 v3_sub(sy_rt_v3 a, sy_rt_v3 b) { return v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline sy_rt_v3 v3_mul(sy_rt_v3 a, sy_rt_v3 b) { return v3(a.x * b.x, a.y * b.y, a.z * b.z); }
static inline sy_rt_v3 v3_scale(sy_rt_v3 a, float s) { return v3(a.x * s, a.y * s, a.z * s); }
static inline sy_rt_v3 v3_madd(sy_rt_v3 a, sy_rt_v3 b, float s) { return v3(a.x + b.x * s, a.y + b.y * s, a.z + b.z * s); }
static inline float v3_dot(sy_rt_v3 a, sy_rt_v3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline sy_rt_v3 v3_cross(sy_rt_v3 a, sy_rt_v3 b)
{
    return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline float v3_length(sy_rt_v3 a) { return sqrtf(v3_dot(a, a)); }
/* Normalises a; returns (0,0,0) for a zero-length vector. */
static inline sy_rt_v3 v3_normalize(sy_rt_v3 a)
{
    float l2 = v3_dot(a, a);
    return l2 > 0.0f ? v3_scale(a, 1.0f / sqrtf(l2)) : v3(0.0f, 0.0f, 0.0f);
}
/* Offset for secondary rays leaving point p (scales with its magnitude: float precision). */
/* sin(2 pi u) and cos(2 pi u) for u in [0, 1) without a libm call (the samplers' azimuths): the
 * quadrant from 4u, then sin and cos of the offset from the quadrant's middle (|x| <= pi/4) by their
 * Taylor series to x^9 / x^8 (truncation below 4e-7) and a rotation by pi/4. */
static inline void sy_rt_sincos_2pi(float u, float *s_out, float *c_out)
{
    float q4 = u * 4.0f;
    int q = (int)q4;
    float x = (q4 - (float)q - 0.5f) * 1.57079633f, x2 = x * x;
    float sx = x * (1.0f + x2 * (-1.0f / 6.0f + x2 * (1.0f / 120.0f + x2 * (-1.0f / 5040.0f + x2 * (1.0f / 362880.0f)))));
    float cx = 1.0f + x2 * (-0.5f + x2 * (1.0f / 24.0f + x2 * (-1.0f / 720.0f + x2 * (1.0f / 40320.0f))));
    /* angle pi/4 + x within the quadrant */
    float s = (sx + cx) * 0.70710678f, c = (cx - sx) * 0.70710678f;
    switch (q & 3) {
    case 0: *s_out = s, *c_out = c; break;
    case 1: *s_out = c, *c_out = -s; break;
    case 2: *s_out = -s, *c_out = -c; break;
    default: *s_out = -c, *c_out = s; break;
    }
}
static inline bool v3_is_zero(sy_rt_v3 a) { return a.x == 0.0f && a.y == 0.0f && a.z == 0.0f; }
static inline float v3_luminance(sy_rt_v3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }
static inline float sy_rt_clampf(float v, float lo, float hi) { return v < lo ? lo : (v > hi ? hi : v); }
/* max / min as one SSE instruction (fmaxf is a libm call without -ffinite-math-only): a NaN in a
 * gives b, so pass the fallback (a constant) as b. */
static inline float sy_rt_maxf(float a, float b) { return a > b ? a : b; }
static inline float sy_rt_minf(float a, float b) { return a < b ? a : b; }
/* sin from cos (or cos from sin): sqrt(1 - c^2), 0 where rounding takes 1 - c^2 below 0 (and for a NaN c) */
static inline float sy_rt_sin_of_cos(float c) { return sqrtf(sy_rt_maxf(1.0f - c * c, 0.0f)); }
/* atan(a) for 0 <= a <= 1 and acos(c) for -1 <= c <= 1 without a libm call (the environment's
 * per-sample lat-long look-ups spent 9 % of a Whitted render of the demo in libm's atan2f and acosf):
 * the polynomials of Abramowitz and Stegun, Handbook of Mathematical Functions, 4.4.49 (|error| <=
 * 2e-8) and 4.4.46 (2e-8); in float arithmetic within 1.1e-7 and 2.6e-7 of the true angle, a few
 * ulp. A NaN gives a NaN. */
static inline float sy_rt_atan_unit(float a)
{
    float s = a * a;
    return a * (1.0f + s * (-0.3333314528f + s * (0.1999355085f + s * (-0.1420889944f + s * (0.1065626393f +
                s * (-0.0752896400f + s * (0.0429096138f + s * (-0.0161657367f + s * 0.0028662257f))))))));
}
static inline float sy_rt_acosf(float c)
{
    float a = fabsf(c);
    float p = 1.5707963050f + a * (-0.2145988016f + a * (0.0889789874f + a * (-0.0501743046f + a * (0.0308918810f +
              a * (-0.0170881256f + a * (0.0066700901f + a * -0.0012624911f))))));
    float r = sqrtf(1.0f - a) * p; /* a > 1: NaN, as acosf */
    return c < 0.0f ? 3.14159265f - r : r;
}
/* atan2(y, x) of finite x, y: the same quadrants and signed zeros as atan2f */
static inline float sy_rt_atan2f(float y, float x)
{
    float ax = fabsf(x), ay = fabsf(y);
    if (isnan(ax) || isnan(ay)) return x + y;
    float r = ay > ax ? 1.57079633f - sy_rt_atan_unit(ax / ay) : (ax > 0.0f ? sy_rt_atan_unit(ay / ax) : 0.0f);
    if (signbit(x)) r = 3.14159265f - r; /* x = -0 too: atan2(0, -0) = pi, as atan2f (the poles' u) */
    return copysignf(r, y);
}
/* The lat-long (equirectangular) mapping of environments and backgrounds (docs/BACKENDS.md):
 * u = 0.5 + atan2(x, -z) / 2 pi (u = 0.5 looks down -z), v = theta / pi from +y (v = 0 up).
 * sy_rt_latlong_dir is its inverse; *st gets sin(theta) (the mapping's area factor). */
static inline void sy_rt_latlong_uv(sy_rt_v3 d, float *u, float *v)
{
    *u = 0.5f + sy_rt_atan2f(d.x, -d.z) * 0.159154943f;
    *v = sy_rt_acosf(sy_rt_clampf(d.y, -1.0f, 1.0f)) * 0.318309886f;
}
static inline sy_rt_v3 sy_rt_latlong_dir(float u, float v, float *st)
{
    float phi = (u - 0.5f) * 2.0f * 3.14159265358979f, theta = v * 3.14159265358979f;
    float s = sinf(theta);
    *st = s;
    return v3(s * sinf(phi), cosf(theta), -s * cosf(phi));
}
/* The last i < n with cdf[i] <= x in a non-decreasing table (0 when there is none; NaN x: 0), by
 * binary search with a select per step: Whitted's emitters' inversion, and the environment's
 * within the cells its guide table leaves (sy_rt_cdf_find). (A search's time is its loads, each
 * waiting on the one before: a branch per step was as fast.) */
static inline uint32_t sy_rt_cdf_last_le(const float *cdf, uint32_t n, float x)
{
    uint32_t i = 0;
    for (uint32_t len = n; len > 1u; len -= len / 2u) i = cdf[i + len / 2u] <= x ? i + len / 2u : i;
    return i;
}
/* The guide table g (n entries) of a non-decreasing CDF of n + 1 entries (cdf[0] = 0): g[k], the
 * last i < n with cdf[i] <= k / n (sy_rt_cdf_find) */
static inline void sy_rt_cdf_guide(const float *cdf, uint32_t n, uint32_t *g)
{
    uint32_t i = 0;
    for (uint32_t k = 0; k < n; ++k) {
        float t = (float)k / (float)n;
        while (i + 1u < n && cdf[i + 1u] <= t) ++i;
        g[k] = i;
    }
}
/* Index i with cdf[i] <= u < cdf[i+1] in a non-decreasing CDF of n + 1 entries (the last i < n with
 * cdf[i] <= u, then on past empty cells), through its guide table g (sy_rt_cdf_guide): u's step of
 * the n equal steps of [0, 1) bounds the search to the cells between its guide entry and the next
 * one's, mostly one or two, where a binary search over the whole table makes about log2(n) loads,
 * each waiting on the one before (the environment's rows: Whitted's demo 0.94x the time). The same
 * index as that search (`rt_math`): where rounding puts u outside its step's cells, the whole
 * table is searched, or the index stepped on. */
static inline uint32_t sy_rt_cdf_find(const float *cdf, const uint32_t *g, uint32_t n, float u)
{
    float un = u * (float)n;
    uint32_t k = un > 0.0f ? (un < (float)n ? (uint32_t)un : n - 1u) : 0u;
    uint32_t lo = g[k], hi = k + 1u < n ? g[k + 1u] + 1u : n;
    if (!(cdf[lo] <= u)) lo = 0u, hi = n; /* u below its step's first cell (rounding; NaN) */
    lo += sy_rt_cdf_last_le(cdf + lo, hi - lo, u);
    while (lo + 1u < n && cdf[lo + 1u] <= u) ++lo;         /* past the next step's guide: a safety net, never seen */
    while (lo + 1u < n && !(cdf[lo + 1u] > cdf[lo])) ++lo; /* skip empty cells */
    return lo;
}
static inline float v3_max_abs(sy_rt_v3 a) { return sy_rt_maxf(fabsf(a.x), sy_rt_maxf(fabsf(a.y), fabsf(a.z))); }
static inline float sy_rt_ray_eps(sy_rt_v3 p) { return 1e-4f * (1.0f + v3_max_abs(p)); }
/* The shadow segment from a ray origin o (a shading point offset along its normal) to a point q
 * sampled on an emitter: *dir (unit) and *tmax, stopping sy_rt_ray_eps(q) short of q along the
 * segment itself, so that it ends on o's side of the emitter. (A segment aimed from the shading
 * point but started at the offset origin can end behind the emitter's plane where the normal
 * faces away from the emitter and the emitter is seen at a grazing angle: the emitter then
 * shadowed itself, 1.7 % of the demo's shadow rays.) False where nothing of it is left: q within
 * that distance of o, nothing can block it. */
static inline bool sy_rt_segment_to(sy_rt_v3 o, sy_rt_v3 q, sy_rt_v3 *dir, float *tmax)
{
    sy_rt_v3 v = v3_sub(q, o);
    float l = v3_length(v);
    if (!(l > 0.0f)) return false;
    *dir = v3_scale(v, 1.0f / l);
    *tmax = l - sy_rt_ray_eps(q);
    return *tmax > 0.0f;
}

/* Column-major 4x4 (glTF): point and direction transforms. */
static inline sy_rt_v3 m4_point(const float *m, sy_rt_v3 p)
{
    return v3(m[0] * p.x + m[4] * p.y + m[8] * p.z + m[12],
              m[1] * p.x + m[5] * p.y + m[9] * p.z + m[13],
              m[2] * p.x + m[6] * p.y + m[10] * p.z + m[14]);
}
static inline sy_rt_v3 m4_dir(const float *m, sy_rt_v3 d)
{
    return v3(m[0] * d.x + m[4] * d.y + m[8] * d.z,
              m[1] * d.x + m[5] * d.y + m[9] * d.z,
              m[2] * d.x + m[6] * d.y + m[10] * d.z);
}
/* 3x3 row-major matrix times vector (used for the normal matrix). */
static inline sy_rt_v3 m3_mul(const float *n, sy_rt_v3 v)
{
    return v3(n[0] * v.x + n[1] * v.y + n[2] * v.z,
              n[3] * v.x + n[4] * v.y + n[5] * v.z,
              n[6] * v.x + n[7] * v.y + n[8] * v.z);
}

/* 32-bit integer hash (lowbias32 by Chris Wellons), for per-pixel sample rotations. */
static inline uint32_t sy_rt_hash32(uint32_t x)
{
    x ^= x >> 16; x *= 0x7feb352dU;
    x ^= x >> 15; x *= 0x846ca68bU;
    x ^= x >> 16;
    return x;
}
/* Maps 32 random bits to a float in [0, 1). */
static inline float sy_rt_u01(uint32_t x) { return (float)(x >> 8) * (1.0f / 16777216.0f); }

#endif /* SY_RT_MATH_H */
