/* sy_bench.c — sync and ray benchmarks (see sy_bench.h). */
#include "sy_bench.h"

#include "sy_compose.h"
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

static double best_of(double a, double b) { return a < b ? a : b; }

sy_result sy_bench_viewports(uint32_t width, uint32_t height, uint32_t repeats, sy_error *err)
{
    /* 1. compositing: two full-HD layers, half covered by the top one at a nearer depth */
    sy_layer a = {0}, b = {0};
    sy_result r = sy_layer_create(1920, 1080, &a, err);
    if (r == SY_OK) r = sy_layer_create(1920, 1080, &b, err);
    if (r != SY_OK) {
        sy_layer_destroy(&a);
        return r;
    }
    for (size_t i = 0; i < (size_t)1920 * 1080; ++i) {
        for (int c = 0; c < 4; ++c) a.rgba[4 * i + c] = 0.5f, b.rgba[4 * i + c] = (i & 1) ? 0.25f : 0.0f;
        a.depth[i] = 5.0f;
        b.depth[i] = (i & 1) ? 2.0f : INFINITY;
    }
    double t_depth = 1e30, t_over = 1e30;
    for (uint32_t k = 0; k < repeats; ++k) {
        double t0 = sy_time_now();
        sy_layer_composite(&a, &b, 0, 0, SY_COMPOSITE_DEPTH);
        double t1 = sy_time_now();
        sy_layer_composite(&a, &b, 0, 0, SY_COMPOSITE_ALPHA_OVER);
        double t2 = sy_time_now();
        t_depth = best_of(t_depth, t1 - t0);
        t_over = best_of(t_over, t2 - t1);
    }
    sy_layer_destroy(&a);
    sy_layer_destroy(&b);
    printf("sy bench viewports\n");
    printf("  composite 2 x 1920x1080, depth       %8.3f ms  (one core, best of %u; goal < 5 ms)\n", t_depth * 1e3,
           repeats);
    printf("  composite 2 x 1920x1080, alpha-over  %8.3f ms\n", t_over * 1e3);

    /* 2. switching back-ends on the demo scene */
    sy_scene *s = NULL;
    sy_demo_info demo;
    sy_context_pool *pool = NULL;
    if ((r = sy_scene_create(&s, err)) || (r = sy_demo_build(s, &demo, err)) || (r = sy_scene_commit(s, NULL, err)) ||
        (r = sy_context_pool_create(&pool, err))) {
        sy_scene_destroy(s);
        return r;
    }
    uint32_t nb = sy_mediator_count();
    for (uint32_t i = 0; i < nb && r == SY_OK; ++i) {
        const char *name = sy_mediator_at(i)->name;
        sy_compose_spec spec = {.backend = name, .root = demo.root, .camera = demo.camera,
                                .background = demo.background, .eye_separation = 0.065f, .zero_parallax = 4.0f};
        sy_layer img = {0}, right = {0};
        double first = 0, again = 0, mono = 1e30, sbs = 1e30;
        for (uint32_t k = 0; k < 2 && r == SY_OK; ++k) { /* first use translates, second reuses the context */
            double t0 = sy_time_now();
            sy_context *ctx;
            r = sy_context_pool_get(pool, s, name, NULL, demo.root.id, &ctx, err);
            if (r == SY_OK) r = sy_context_sync(ctx, err);
            if (k) again = sy_time_now() - t0;
            else first = sy_time_now() - t0;
        }
        for (uint32_t k = 0; k < repeats && r == SY_OK; ++k) {
            spec.stereo = SY_STEREO_NONE;
            double t0 = sy_time_now();
            r = sy_compose_render(s, pool, &spec, width, height, NULL, &img, &right, err);
            mono = best_of(mono, sy_time_now() - t0);
            sy_layer_destroy(&img);
            if (r != SY_OK) break;
            spec.stereo = SY_STEREO_SBS;
            t0 = sy_time_now();
            r = sy_compose_render(s, pool, &spec, width, height, NULL, &img, &right, err);
            sbs = best_of(sbs, sy_time_now() - t0);
            sy_layer_destroy(&img);
        }
        if (r == SY_OK)
            printf("  %-10s first use %9.3f ms, switch back %7.3f ms; per eye: mono %8.3f ms, stereo %8.3f ms "
                   "(overhead %+.1f %%)\n",
                   name, first * 1e3, again * 1e3, mono * 1e3, sbs * 0.5e3, (sbs * 0.5 / mono - 1.0) * 100.0);
    }
    printf("  contexts in the pool: %u (one per back-end: both eyes share one)\n", sy_context_pool_size(pool));
    sy_context_pool_destroy(pool);
    sy_scene_destroy(s);
    return r;
}
