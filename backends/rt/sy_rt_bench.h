/* sy_rt_bench.h — ray throughput benchmark of the back-end: the PRIMARY integrator against raw
 * Embree rtcIntersect1 on exactly the same rays (same camera, scene, tiles and threads), to keep
 * the renderer's own overhead measured. Used by `sy bench rays`. */
#ifndef SY_RT_BENCH_H
#define SY_RT_BENCH_H

#include "sy_rt.h"

typedef struct sy_rt_bench_result {
    uint32_t width, height, repeats, threads;
    double primary_seconds;  /* best frame time of the PRIMARY integrator */
    double raw_seconds;      /* best frame time of raw rtcIntersect1 on the same rays */
    double primary_mrays;    /* width*height / primary_seconds / 1e6 */
    double raw_mrays;
    double overhead_percent; /* (primary_seconds / raw_seconds - 1) * 100 */
    uint64_t hits;             /* pixels whose camera ray hit something (the PRIMARY integrator's depth) */
    uint64_t differing_pixels; /* pixels where the two methods disagree: hit against miss, or depths
                                * more than 1e-4 apart (relative): 0 when they traced the same rays */
} sy_rt_bench_result;

/* Renders a width x height frame `repeats` times (>= 1) with each method, alternating, after one
 * warm-up frame each, and reports the best times. The device must be committed. */
sy_rt_result sy_rt_bench_rays(sy_rt_device *dev, const sy_rt_camera *camera, uint32_t width, uint32_t height,
                              uint32_t repeats, sy_rt_bench_result *out);

#endif /* SY_RT_BENCH_H */
