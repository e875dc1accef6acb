/* sy_bench_pathtracer.c — `sy bench pathtracer` (issue 3): samples/s and Mrays/s of the path
 * tracer next to the Whitted back-end, and the restart latency after a change (see sy_bench.h). */
#include "sy_bench.h"
#ifdef SY_HAVE_EMBREE
#include "sy_mediator_rt.h"
#endif

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* >>pathtracer (issue 3): samples/s and Mrays/s of the path tracer next to the Whitted back-end on
 * the same scene, and the restart latency after a transform change. */

sy_result sy_bench_pathtracer(sy_scene *scene, const sy_viewport_desc *vd, const char *label, uint32_t width,
                              uint32_t height, uint32_t passes, sy_error *err)
{
#ifndef SY_HAVE_EMBREE
    (void)scene, (void)vd, (void)label, (void)width, (void)height, (void)passes;
    SY_BENCH_WITHOUT(err, "pathtracer", "SY_WITH_EMBREE");
#else
    sy_window *win_w = NULL, *win_p = NULL;
    sy_viewport *vp;
    sy_context_pool *pool = NULL;
    sy_layer img = {0};
    double *t = calloc(passes, sizeof *t), whitted = INFINITY, first = 0, t_dummy;
    sy_viewport_desc dw = *vd, dp = *vd;
    dw.backend = "whitted";
    dp.backend = "pathtracer";
    sy_result r = t ? sy_window_create(width, height, &win_w, err) : sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bench: out of memory");
    if (r == SY_OK) r = sy_window_create(width, height, &win_p, err);
    if (r == SY_OK) r = sy_window_add_viewport(win_w, &dw, &vp, err);
    if (r == SY_OK) r = sy_window_add_viewport(win_p, &dp, &vp, err);
    if (r == SY_OK) r = sy_context_pool_create(&pool, err);
    if (r == SY_OK) r = sy_layer_create(width, height, &img, err);
    /* Whitted: best of 3 frames after a warm-up (translation is not timed) */
    for (uint32_t i = 0; i < 4 && r == SY_OK; ++i) {
        double s;
        r = sy_bench_frame(win_w, scene, pool, 0, &img, &s, err);
        if (i) whitted = fmin(whitted, s);
    }
    /* path tracer: warm-up pass, then `passes` passes of 1 sample per pixel */
    if (r == SY_OK) r = sy_bench_frame(win_p, scene, pool, 1, &img, &t_dummy, err);
    sy_context *ctx = NULL;
    sy_params pp = {0};
    if (r == SY_OK) r = sy_context_pool_get(pool, scene, "pathtracer", &pp, vd->root.id, &ctx, err);
    uint64_t rays = 0;
    for (uint32_t i = 0; i < passes && r == SY_OK; ++i) {
        r = sy_bench_frame(win_p, scene, pool, 1, &img, &t[i], err);
        sy_mediator_rt_counters c;
        sy_mediator_rt_counters_get(sy_context_state(ctx), &c);
        rays += c.last_render_rays;
    }
    double total = 0;
    for (uint32_t i = 0; i < passes; ++i) total += t[i];
    /* restart latency: move the first node with a mesh a little, then time sync + the first pass */
    uint32_t moved = 0;
    for (uint32_t id = sy_scene_next(scene, SY_TYPE_NODE, 0); id && !moved; id = sy_scene_next(scene, SY_TYPE_NODE, id)) {
        const sy_node_data *nd = sy_object_get(scene, SY_TYPE_NODE, id);
        if (nd->mesh.id) moved = id;
    }
    sy_mediator_stats st = {0};
    if (r == SY_OK && moved) {
        sy_node n = {moved};
        sy_mat4 m = sy_node_get(scene, n)->transform.matrix;
        m.m[13] += 0.01f;
        r = sy_node_set_matrix(scene, n, &m, err);
        if (r == SY_OK) r = sy_scene_commit(scene, NULL, err);
        if (r == SY_OK) r = sy_bench_frame(win_p, scene, pool, 1, &img, &first, err);
        if (r == SY_OK) sy_context_stats(ctx, &st);
    }
    if (r == SY_OK) {
        qsort(t, passes, sizeof *t, sy_bench_cmp_double);
        double med = t[passes / 2], px = (double)width * height;
        printf("%s, %ux%u:\n", label, width, height);
        printf("  whitted                 %8.3f s/frame  %8.2f frames/s\n", whitted, 1.0 / whitted);
        printf("  pathtracer (1 spp pass) %8.3f s/pass   %8.2f samples/s (spp)  %7.2f Msamples/s  %7.2f Mrays/s  "
               "(%.1f rays/sample, %u passes)\n",
               med, passes / total, px * passes / total * 1e-6, (double)rays / total * 1e-6, (double)rays / (px * passes),
               passes);
        printf("  pass / whitted frame    %8.2f x\n", med / whitted);
        if (moved)
            printf("  restart after a transform change: first new pass %.3f s = %.2f x one pass (samples after it: %llu)\n",
                   first, first / med, (unsigned long long)st.samples);
    }
    free(t);
    sy_layer_destroy(&img);
    sy_context_pool_destroy(pool);
    sy_window_destroy(win_w);
    sy_window_destroy(win_p);
    return r;
#endif
}
