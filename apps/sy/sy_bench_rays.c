/* sy_bench_rays.c — `sy bench rays`: the Whitted back-end's primary-ray throughput against raw
 * Embree on the same rays (see sy_bench.h). */
#include "sy_bench.h"
#ifdef SY_HAVE_EMBREE
#include "sy_mediator_rt.h"
#endif

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

sy_result sy_bench_rays(sy_scene *scene, const sy_viewport_desc *vd, uint32_t width, uint32_t height, uint32_t repeats,
                        sy_error *err)
{
#ifndef SY_HAVE_EMBREE
    (void)scene, (void)vd, (void)width, (void)height, (void)repeats;
    SY_BENCH_WITHOUT(err, "rays (whitted)", "SY_WITH_EMBREE");
#else
    sy_window *win = NULL;
    sy_viewport *vp = NULL;
    sy_context *ctx = NULL;
    sy_camera_view view = {0};
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
#endif
}
