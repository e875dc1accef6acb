/* sy_cmd_view.c — `sy view SCENE`: the interactive viewer's command line (the viewer itself:
 * sy_view.c; built with GLFW, SY_HAVE_GLFW). */
#include "sy_commands.h"
#include "sy_cli.h"
#include "sy_cluster_cli.h"
#include "sy_load.h"
#include "sy_view.h"

#include "sy_mediators.h"
#include "sy_viewport.h"

#include <stdlib.h>
#include <string.h>

#ifdef SY_HAVE_GLFW
int sy_cmd_view(int argc, char **argv)
{
    const char *scene = NULL, *backend = NULL, *camera = NULL, *overlay = NULL, *composite = "depth",
               *shot = NULL;
    const char *view_filter = NULL; /* --filter: initial path tracer display filter */
    float view_threshold = 0.0f;    /* --threshold (0 = default) */
    const char *view_keys = NULL;   /* --keys: scripted key presses (tests) */
    const char *bookmarks = NULL;   /* --bookmarks FILE (default: SCENE.bookmarks beside the scene) */
    sy_compose_spec cut = {0};      /* --clip A,B,C,D ..., --clip-cap RRGGBB: the start section planes */
    bool no_temporal = false;       /* --no-temporal */
    uint32_t w = 960, h = 540, frames = 0;
    sy_cluster_cli_opts clo = {0}; /* --cluster ... (sy_cluster_cli.c; --frames is the viewer's own) */
    double budget = 0.0;
    const sy_cli_opt opts[] = {
        SY_CLI_OPT_TEXT(NULL, 'b', &backend), SY_CLI_OPT_TEXT("camera", OPT_CAMERA, &camera),
        SY_CLI_OPT_TEXT("overlay", OPT_OVERLAY, &overlay), SY_CLI_OPT_TEXT("composite", OPT_COMPOSITE, &composite),
        SY_CLI_OPT_UINT("frames", OPT_FRAMES, &frames, 1, 1000000), SY_CLI_OPT_TEXT("screenshot", OPT_SCREENSHOT, &shot),
        SY_CLI_OPT_TEXT("filter", OPT_FILTER, &view_filter),
        SY_CLI_OPT_FLOAT_ANY("threshold", OPT_THRESHOLD, &view_threshold), /* the range: sy_view_run says why */
        SY_CLI_OPT_TEXT("keys", OPT_KEYS, &view_keys),
        SY_CLI_OPT_UINT("spp", OPT_SPP, &clo.samples, 1, 100000000u), /* cluster: samples per server and frame */
        SY_CLI_OPT_REAL("budget", OPT_BUDGET, &budget, 1.0, 10000.0), /* the frame-time governor's budget (ms) */
        SY_CLI_OPT_FLAG("no-temporal", OPT_NO_TEMPORAL, &no_temporal), /* no temporal reuse on moving frames */
        SY_CLI_OPT_CODE("clip", OPT_CLIP, true), SY_CLI_OPT_CODE("clip-cap", OPT_CLIP_CAP, true),
        SY_CLI_OPT_TEXT("bookmarks", OPT_BOOKMARKS, &bookmarks)}; /* the saved views' file */
    sy_cli_parser p = {SY_CLI_ARGS("view", argc, argv, opts), .w = &w, .h = &h, .min_size = 16, .cluster = true,
                       .view = true};
    int c, status;
    while ((c = sy_cli_parse(&p)) != -1) { /* the cluster's options come back */
        if (c == OPT_STOP) return p.status;
        if (c == OPT_CLIP) {
            if (sy_cli_add_clip_plane(optarg, cut.clip_planes, &cut.clip_count)) return 2;
            continue;
        }
        if (c == OPT_CLIP_CAP) {
            if (sy_cli_parse_cap_color(optarg, cut.clip_cap_color)) return 2;
            cut.clip_cap = true;
            continue;
        }
        if (!sy_cluster_cli_getopt(c, optarg, &clo)) return sy_cli_bad_value(sy_cli_option_name(p.lo, c), optarg);
    }
    if ((status = sy_cli_scene_operand("view", argc, argv, &scene))) return status;
    sy_error err = {0};
    if (!backend && !(backend = sy_cli_default_backend(&err))) return sy_cli_fail(&err);
    if (!sy_mediator_find(backend)) {
        sy_error_set(&err, SY_ERR_NOT_FOUND, "back-end '%s' is not registered (see sy backends)", backend);
        return sy_cli_fail(&err);
    }
    loaded ld;
    if (sy_cli_load(scene, camera, true, &ld, &err) != SY_OK) return sy_cli_fail(&err);
    sy_view_args va = {.scene = ld.scene, .backend = backend, .width = w, .height = h, .frames = frames, .screenshot = shot,
                       .clip = sy_cli_default_clip(&ld)};
    va.filter = view_filter;
    va.threshold = view_threshold;
    va.keys = view_keys;
    va.no_temporal = no_temporal;
    va.budget_ms = budget;
    va.cluster = clo.cluster ? &clo : NULL;
    va.spec.root = ld.root;
    va.spec.camera = ld.camera;
    va.spec.background = ld.background;
    va.spec.eye_separation = 0.065f;
    va.spec.zero_parallax = 2.0f;
    va.spec.backend = backend;
    va.spec.clip_count = cut.clip_count;
    memcpy(va.spec.clip_planes, cut.clip_planes, sizeof va.spec.clip_planes);
    va.spec.clip_cap = cut.clip_cap;
    memcpy(va.spec.clip_cap_color, cut.clip_cap_color, sizeof va.spec.clip_cap_color);
    char *marks = NULL; /* the saved views beside the scene file (not for the built-in demo) */
    va.bookmarks = sy_cli_bookmarks_file(scene, bookmarks, &marks);
    sy_result r = overlay ? sy_cli_add_overlay(&ld, overlay, composite, &va.spec, &err) : SY_OK;
    if (r == SY_OK) r = sy_view_run(&va, &err);
    free(marks);
    sy_cli_loaded_free(&ld);
    return r == SY_OK ? 0 : sy_cli_fail(&err);
}
#endif
