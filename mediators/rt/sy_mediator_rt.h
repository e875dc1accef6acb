/* sy_mediator_rt.h — the mediator between the core scene and the Embree back-end (backends/rt).
 *
 * One Embree scene adapter serving several integrators: the "whitted" class registered here (and
 * later "pathtracer" and "coverage") share this adapter; only the integrator chosen at render
 * time differs. The adapter keeps a mirror of the node graph built from change lists, flattens it
 * (one world transform per geometry placement; a DAG node reached along k paths gets k placements),
 * bakes geometry of nodes flagged SY_NODE_STATIC whose mesh is used once into the top-level BVH,
 * instances everything else (shared meshes are one BLAS), and syncs incrementally: a transform
 * change re-places the node's subtree only (rtcSetGeometryTransform, no BLAS rebuild).
 *
 * Parameters (sy_params): max_depth (1..64, default 8), light_samples (1..1024, default 16),
 * threads (0 = all cores).
 *
 * Ownership/thread-safety: as any mediator (see core/sy_mediator.h). */
#ifndef SY_MEDIATOR_RT_H
#define SY_MEDIATOR_RT_H

#include "sy_mediator.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The Whitted ray tracer class ("whitted"). Static storage. */
const sy_mediator_class *sy_mediator_rt_whitted_class(void);

/* Counters of the adapter, for tests and benchmarks. */
typedef struct sy_mediator_rt_counters {
    uint32_t instances, baked_instances, meshes, materials, textures, lights;
    uint32_t last_sync_placements; /* node placements recomputed by the last sync */
    uint32_t last_sync_entries;    /* change entries handled by the last sync */
} sy_mediator_rt_counters;
/* state is the mediator state of a context whose class is one of this adapter's classes. */
void sy_mediator_rt_counters_get(void *state, sy_mediator_rt_counters *out);

/* Ray throughput of this adapter's device on the given view (see backends/rt/sy_rt_bench.h):
 * our PRIMARY integrator against raw rtcIntersect1 on the same rays, in one run. */
typedef struct sy_mediator_rt_bench {
    double ours_mrays, raw_mrays, overhead_percent;
    uint32_t threads;
} sy_mediator_rt_bench;
sy_result sy_mediator_rt_bench_rays(void *state, const sy_camera_view *view, uint32_t width, uint32_t height,
                                    uint32_t repeats, sy_mediator_rt_bench *out, sy_error *err);

#ifdef __cplusplus
}
#endif
#endif /* SY_MEDIATOR_RT_H */
