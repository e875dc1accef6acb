/* sy_bench_limit.c — `sy bench limit` (issue 19, part 6, "distance to the limit"): the path
 * tracer's rays per second as a share of raw Embree's on exactly the rays of its frame (see
 * sy_bench.h, sy_mediator_rt_bench_limit and backends/rt/sy_rt_limit.h), with its own usage text. */
#include "sy_bench.h"

#ifdef SY_HAVE_EMBREE
#include "sy_mediator_rt.h"
#endif

#include "sy_cli.h"
#include "sy_load.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define DEFAULT_CORNELL "../shared/testdata/cornell/cornell_box.gltf"

#ifdef SY_HAVE_EMBREE
/* rays/s from the median time (min .. max); the share: per repeat (the frame and the form timed
 * side by side), median (min .. max) */
static void print_row(const char *name, double rays, const double s[3], const double share[3], const char *note)
{
    printf("  %-32s %8.2f Mrays/s (%.2f .. %.2f)   path tracer = %5.1f %% (%.1f .. %.1f)%s%s\n", name,
           rays / s[1] * 1e-6, rays / s[2] * 1e-6, rays / s[0] * 1e-6, 100.0 * share[1], 100.0 * share[0],
           100.0 * share[2], note ? "  " : "", note ? note : "");
}
#endif

sy_result sy_bench_limit(sy_scene *scene, const sy_viewport_desc *vd, const char *label, uint32_t width,
                         uint32_t height, uint32_t spp, uint32_t repeats, sy_error *err)
{
#ifndef SY_HAVE_EMBREE
    (void)scene, (void)vd, (void)label, (void)width, (void)height, (void)spp, (void)repeats;
    return sy_error_set(err, SY_ERR_UNSUPPORTED,
                        "sy bench: limit (pathtracer) needs a back-end this sy was built without (SY_WITH_EMBREE=OFF)");
#else
    sy_window *win = NULL;
    sy_viewport *vp = NULL;
    sy_context *ctx = NULL;
    sy_camera_view view = {0};
    sy_viewport_desc d = *vd;
    d.backend = "pathtracer";
    sy_result r = sy_window_create(width, height, &win, err);
    if (r == SY_OK) r = sy_window_add_viewport(win, &d, &vp, err);
    if (r == SY_OK) r = sy_viewport_camera_view(vp, scene, width, height, &view, err);
    if (r == SY_OK) r = sy_context_create(scene, "pathtracer", NULL, vd->root.id, &ctx, err);
    if (r == SY_OK) r = sy_context_sync(ctx, err);
    sy_mediator_rt_limit b;
    if (r == SY_OK)
        r = sy_mediator_rt_bench_limit(sy_context_state(ctx), &view, vd->background.id, width, height, spp, repeats, &b, err);
    if (r == SY_OK) {
        double rays = (double)b.rays, f_mrays = rays / b.frame_seconds[1] * 1e-6;
        printf("%s, %ux%u, %u spp, %u threads, median of %u (min .. max), one run:\n", label, width, height, b.samples,
               b.threads, b.repeats);
        printf("  rays of the frame: %llu = %llu extension + %llu shadow (%llu closest-hit + %llu occlusion queries), "
               "%.2f per sample\n",
               (unsigned long long)b.rays, (unsigned long long)b.extension_rays, (unsigned long long)b.shadow_rays,
               (unsigned long long)b.intersect_queries, (unsigned long long)b.occluded_queries,
               rays / ((double)width * height * b.samples));
        printf("  %-32s %8.2f Mrays/s (%.2f .. %.2f)   frame %.1f ms (%.1f .. %.1f)\n", "path tracer (whole frame)", f_mrays,
               rays / b.frame_seconds[2] * 1e-6, rays / b.frame_seconds[0] * 1e-6, b.frame_seconds[1] * 1e3,
               b.frame_seconds[0] * 1e3, b.frame_seconds[2] * 1e3);
        for (int f = 0; f < SY_MEDIATOR_RT_LIMIT_FORMS; ++f) {
            char note[96] = "";
            if (!b.native[f]) snprintf(note, sizeof note, "(emulated by Embree: not native on this CPU/build)");
            if (b.mismatches[f])
                snprintf(note + strlen(note), sizeof note - strlen(note), "%s%llu answers differ from the frame's",
                         note[0] ? "; " : "", (unsigned long long)b.mismatches[f]);
            print_row(b.form_names[f], rays, b.form_seconds[f], b.share[f], note[0] ? note : NULL);
        }
        /* where the frame's time goes (one pixel in 8 timed, in a frame of its own per repeat) */
        double total_ns = 0.0;
        for (int k = 0; k < SY_MEDIATOR_RT_LIMIT_STAGES; ++k) total_ns += b.stage_ns_per_sample[k];
        printf("  per stage (time stamp counter on 1 pixel in 8, %.0f ticks per read subtracted (%.0f in a tight loop), %llu of %llu spans left "
               "out as preempted; timed frame %.1f ms = %+.0f %%):\n",
               b.lap_ticks, b.lap_ticks_tight, (unsigned long long)b.stage_dropped, (unsigned long long)(b.stage_laps + b.stage_dropped),
               b.timed_frame_seconds * 1e3, 100.0 * (b.timed_frame_seconds / b.frame_seconds[1] - 1.0));
        for (int k = 0; k < SY_MEDIATOR_RT_LIMIT_STAGES; ++k)
            printf("    %-32s %5.1f %%  %8.0f ns/sample\n", b.stage_names[k], 100.0 * b.stage_share[k],
                   b.stage_ns_per_sample[k]);
        double trav = b.stage_share[b.stage_traversal] + b.stage_share[b.stage_shadow];
        printf("    %-32s %5.1f %%  %8.0f ns/sample\n", "all", 100.0, total_ns);
        /* traversal inside the frame (its share of the median frame) against the raw replay */
        printf("  traversal in the frame: %.1f %% of it = %.1f ms, raw rtcIntersect1/rtcOccluded1 %.1f ms (%.2fx); "
               "the rest: %.1f ms\n",
               100.0 * trav, trav * b.frame_seconds[1] * 1e3, b.form_seconds[0][1] * 1e3,
               trav * b.frame_seconds[1] / b.form_seconds[0][1], (1.0 - trav) * b.frame_seconds[1] * 1e3);
    }
    sy_context_release(ctx);
    sy_window_destroy(win);
    return r;
#endif
}

int sy_cmd_bench_limit(int argc, char **argv)
{
    static const char usage_text[] =
        "usage: sy bench limit [SCENE] [-w W] [-h H] [--spp N] [--repeats N]\n"
        "  the path tracer's rays/s as a share of raw Embree's on the same rays (single, packets, streams);\n"
        "  default: the Cornell box (" DEFAULT_CORNELL ") and the demo, 256x256, 1 spp, 5 repeats\n";
    uint32_t w = 256, h = 256, spp = 1, repeats = 5;
    enum { O_SPP = OPT_OWN_FIRST, O_REPEATS };
    const sy_cli_opt opts[] = {SY_CLI_OPT_UINT("spp", O_SPP, &spp, 1, 1024), SY_CLI_OPT_UINT("repeats", O_REPEATS, &repeats, 1, 1000)};
    sy_cli_parser p = {SY_CLI_ARGS("bench limit", argc, argv, opts), .w = &w, .h = &h, .min_size = 1, .usage = usage_text};
    if (sy_cli_parse(&p) != -1) return p.status;
    if (argc - optind > 1) {
        fprintf(stderr, "sy bench limit: error: at most one SCENE\n%s", usage_text);
        return 2;
    }
    const char *list[2] = {optind < argc ? argv[optind] : DEFAULT_CORNELL, optind < argc ? NULL : "demo"};
    for (int i = 0; i < 2 && list[i]; ++i) {
        sy_error err = {0};
        loaded ld; /* the file's first camera, else a view framing its bounds (sy_bench_limit) */
        sy_result r = sy_cli_load(list[i], NULL, false, &ld, &err);
        sy_viewport_desc vd = {.root = ld.root, .camera = ld.camera, .background = ld.background};
        if (r == SY_OK) r = sy_bench_limit(ld.scene, &vd, list[i], w, h, spp, repeats, &err);
        sy_cli_loaded_free(&ld);
        if (r != SY_OK) {
            fprintf(stderr, "sy bench limit: error: %s\n", err.message);
            return 1;
        }
    }
    return 0;
}
