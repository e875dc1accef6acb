/* sy_bench.c — sync and ray benchmarks (see sy_bench.h). */
#include "sy_bench.h"

#include "sy_demo.h"
#include "sy_mediator_rt.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

sy_result sy_bench_sync(uint32_t nodes, uint32_t tris, uint32_t repeats, sy_error *err)
{
    uint32_t per_group = nodes < 100 ? nodes : 100, groups = (nodes + per_group - 1) / per_group;
    sy_scene *s = NULL;
    sy_context *ctx = NULL;
    double *times = calloc(repeats, sizeof *times);
    sy_result r = times ? sy_scene_create(&s, err) : sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bench: out of memory");
    sy_node root = {0}, leaf = {0};
    double t0 = sy_time_now();
    if (r == SY_OK) r = sy_demo_bench_scene(s, groups, per_group, tris, &root, &leaf, err);
    if (r == SY_OK) r = sy_scene_commit(s, NULL, err);
    double t_build = sy_time_now() - t0;
    uint32_t total_tris = 0;
    for (uint32_t id = sy_scene_next(s, SY_TYPE_MESH, 0); r == SY_OK && id; id = sy_scene_next(s, SY_TYPE_MESH, id)) {
        const sy_mesh_data *m = sy_object_get(s, SY_TYPE_MESH, id);
        total_tris += sy_primitive_triangle_count(&m->primitives.items[0]);
    }
    /* translation from scratch: a new context's first sync (snapshot -> Embree scene, commit) */
    t0 = sy_time_now();
    if (r == SY_OK) r = sy_context_create(s, "whitted", NULL, root.id, &ctx, err);
    if (r == SY_OK) r = sy_context_sync(ctx, err);
    double t_full = sy_time_now() - t0;
    size_t log_bytes = 0;
    uint32_t placements = 0;
    for (uint32_t i = 0; i < repeats && r == SY_OK; ++i) {
        static const float q[4] = {0, 0, 0, 1}, one[3] = {1, 1, 1};
        float t[3] = {0.01f * (float)(i + 1), 0.0f, 0.0f};
        double a = sy_time_now();
        r = sy_node_set_trs(s, leaf, t, q, one, err);
        if (r == SY_OK) r = sy_scene_commit(s, NULL, err);
        if (r == SY_OK && i == 0) log_bytes = sy_scene_log_bytes(s); /* the one sealed, unpulled list */
        if (r == SY_OK) r = sy_context_sync(ctx, err);
        times[i] = sy_time_now() - a;
        if (r == SY_OK && i == 0) {
            sy_mediator_rt_counters c;
            sy_mediator_rt_counters_get(sy_context_state(ctx), &c);
            placements = c.last_sync_placements;
        }
    }
    if (r == SY_OK) {
        qsort(times, repeats, sizeof *times, cmp_double);
        double med = times[repeats / 2];
        printf("sy bench sync: %u nodes (%u groups x %u), %u triangles\n", groups * per_group, groups, per_group,
               total_tris);
        printf("  scene build (core)             %10.3f ms\n", t_build * 1e3);
        printf("  translate from scratch         %10.3f ms  (new context: snapshot -> Embree, commit)\n", t_full * 1e3);
        printf("  one transform change (median)  %10.3f ms  (commit + sync, %u repeats, min %.3f ms)\n", med * 1e3,
               repeats, times[0] * 1e3);
        printf("  ratio full / incremental       %10.1f x   (goal >= 500)\n", t_full / med);
        printf("  placements recomputed          %10u\n", placements);
        printf("  change log per change          %10zu bytes\n", log_bytes);
    }
    sy_context_release(ctx);
    sy_scene_destroy(s);
    free(times);
    return r;
}

sy_result sy_bench_rays(sy_scene *scene, const sy_viewport_desc *vd, uint32_t width, uint32_t height, uint32_t repeats,
                        sy_error *err)
{
    sy_window *win = NULL;
    sy_viewport *vp = NULL;
    sy_context *ctx = NULL;
    sy_camera_view view;
    sy_result r = sy_window_create(width, height, &win, err);
    if (r == SY_OK) r = sy_window_add_viewport(win, vd, &vp, err);
    if (r == SY_OK) r = sy_viewport_camera_view(vp, scene, width, height, &view, err);
    if (r == SY_OK) r = sy_context_create(scene, "whitted", NULL, vd->root.id, &ctx, err);
    if (r == SY_OK) r = sy_context_sync(ctx, err);
    sy_mediator_rt_bench b;
    if (r == SY_OK) r = sy_mediator_rt_bench_rays(sy_context_state(ctx), &view, width, height, repeats, &b, err);
    if (r == SY_OK) {
        printf("sy bench rays: %ux%u primary rays, %u threads, best of %u\n", width, height, b.threads, repeats);
        printf("  whitted back-end (primary)  %8.2f Mrays/s\n", b.ours_mrays);
        printf("  raw Embree rtcIntersect1    %8.2f Mrays/s\n", b.raw_mrays);
        printf("  overhead                    %8.1f %%   (goal < 25 %%)\n", b.overhead_percent);
    }
    sy_context_release(ctx);
    sy_window_destroy(win);
    return r;
}
