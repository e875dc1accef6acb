/* sy_bench.h — `sy bench` benchmarks. They print ratios measured in one run (never pass/fail on
 * time): sync (incremental update vs translating from scratch) and rays (our primary-ray
 * throughput vs raw Embree on the same rays). Thread-safety: single-threaded callers. */
#ifndef SY_BENCH_H
#define SY_BENCH_H

#include "sy_viewport.h"

/* Generated scene of `nodes` leaf nodes (100 per group) with ~tris triangles each; times building
 * the back-end scene from scratch (context creation + first sync) against `repeats` single
 * transform changes (commit + sync), and reports bytes of change log per change. */
sy_result sy_bench_sync(uint32_t nodes, uint32_t tris, uint32_t repeats, sy_error *err);

/* Primary-ray throughput of the whitted back-end's device against raw rtcIntersect1 for the view
 * of the viewport desc (camera or framing), width x height, best of repeats. */
sy_result sy_bench_rays(sy_scene *scene, const sy_viewport_desc *vd, uint32_t width, uint32_t height, uint32_t repeats,
                        sy_error *err);

/* Viewport costs on the demo scene: compositing two 1920x1080 layers (depth and alpha-over, one
 * core), switching a viewport's back-end away and back (the second switch must not translate the
 * scene again: reported as sync times), and stereo (side-by-side) cost per eye against mono for
 * every registered back-end, at width x height per eye. */
sy_result sy_bench_viewports(uint32_t width, uint32_t height, uint32_t repeats, sy_error *err);

#endif /* SY_BENCH_H */
