/* sy_rt_accum.h — progressive accumulation buffers of the path tracer (public part in sy_rt.h):
 * per pixel running means (Welford) of colour, albedo, normal, direct and indirect radiance and
 * depth, plus the colour's sum of squared deviations for the variance. Internal to backends/rt. */
#ifndef SY_RT_ACCUM_H
#define SY_RT_ACCUM_H

#include "sy_rt_device.h"

#include <stdatomic.h>

/* Float offsets inside one pixel's record. */
enum {
    SY_RT_ACC_COLOR = 0,     /* 4: mean RGBA */
    SY_RT_ACC_M2 = 4,        /* 3: sum of squared deviations of RGB */
    SY_RT_ACC_ALBEDO = 7,    /* 3 */
    SY_RT_ACC_NORMAL = 10,   /* 3 */
    SY_RT_ACC_DIRECT = 13,   /* 3 */
    SY_RT_ACC_INDIRECT = 16, /* 3 */
    SY_RT_ACC_DEPTH = 19,    /* 1: mean depth over the samples that hit */
    SY_RT_ACC_HITS = 20,     /* 1: number of samples that hit (as float) */
    SY_RT_ACC_STRIDE = 21
};

struct sy_rt_accum {
    uint32_t width, height;
    uint32_t samples;           /* samples per pixel accumulated */
    float *data;                /* width * height * SY_RT_ACC_STRIDE */
    atomic_uint_fast64_t nonfinite;
    atomic_uint_fast64_t rays;  /* rays traced (closest-hit + shadow) by the last render call */
};

/* One path-tracing sample's outputs. */
typedef struct sy_rt_pt_sample {
    sy_rt_v3 color;
    float alpha;
    sy_rt_v3 direct;
    sy_rt_v3 albedo, normal;
    float depth; /* +INFINITY: no hit */
} sy_rt_pt_sample;

/* Adds sample number n (1-based count after adding) to the record; replaces non-finite values by
 * zero radiance and returns false when it had to. */
bool sy_rt_accum_add(float *rec, uint32_t n, const sy_rt_pt_sample *s);

#endif /* SY_RT_ACCUM_H */
