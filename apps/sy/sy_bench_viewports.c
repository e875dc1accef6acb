/* sy_bench_viewports.c — `sy bench viewports`: compositing, switching a viewport's back-end and
 * stereo against mono, on the demo scene (see sy_bench.h). */
#include "sy_bench.h"

#include "sy_compose.h"
#include "sy_demo.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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
