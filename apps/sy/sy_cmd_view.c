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

#ifdef SY_HAVE_GLFW
int sy_cmd_view(int argc, char **argv)
{
    const char *scene = NULL, *backend = NULL, *camera = NULL, *overlay = NULL, *composite = "depth",
               *shot = NULL;
    const char *view_filter = NULL; /* --filter: initial path tracer display filter */
    float view_threshold = 0.0f;    /* --threshold (0 = default) */
    const char *view_keys = NULL;   /* --keys: scripted key presses (tests) */
    uint32_t w = 960, h = 540, frames = 0;
    sy_cluster_cli_opts clo = {0}; /* --cluster ... (sy_cluster_cli.c; --frames is the viewer's own) */
    static const struct option lo[] = {
        {"camera", required_argument, NULL, OPT_CAMERA}, {"overlay", required_argument, NULL, OPT_OVERLAY},
        {"composite", required_argument, NULL, OPT_COMPOSITE}, {"frames", required_argument, NULL, OPT_FRAMES},
        {"screenshot", required_argument, NULL, OPT_SCREENSHOT}, {"filter", required_argument, NULL, OPT_FILTER},
        {"threshold", required_argument, NULL, OPT_THRESHOLD}, {"keys", required_argument, NULL, OPT_KEYS},
        {"spp", required_argument, NULL, OPT_SPP}, /* cluster: samples per server and frame */
        {"budget", required_argument, NULL, OPT_BUDGET}, /* the frame-time governor's budget (ms) */
        SY_CLUSTER_CLI_OPTIONS, VIEW_OPTIONS, COMMON_OPTIONS};
    double budget = 0.0;
    int c, status = 0;
    optind = 0;
    while ((c = sy_cli_next_sized_option("view", argc, argv, SHORT_OPTIONS("b:w:h:"), lo, 16, &w, &h, &status)) != -1) {
        char *end = NULL;
        switch (c) {
        case OPT_STOP: return status;
        case 'b': backend = optarg; break;
        case OPT_CAMERA: camera = optarg; break;
        case OPT_OVERLAY: overlay = optarg; break;
        case OPT_COMPOSITE: composite = optarg; break;
        case OPT_FRAMES:
            if (!sy_cli_parse_u32(optarg, 1, 1000000, &frames)) return sy_cli_bad_value("--frames", optarg);
            break;
        case OPT_SCREENSHOT: shot = optarg; break;
        case OPT_FILTER: view_filter = optarg; break;
        case OPT_THRESHOLD: /* the range: sy_view_run says why */
            view_threshold = strtof(optarg, &end);
            if (end == optarg || *end) return sy_cli_bad_value("--threshold", optarg);
            break;
        case OPT_KEYS: view_keys = optarg; break;
        case OPT_BUDGET:
            if (!sy_cli_parse_double(optarg, 1.0, 10000.0, &budget)) return sy_cli_bad_value("--budget", optarg);
            break;
        case OPT_SPP:
            if (!sy_cli_parse_u32(optarg, 1, 100000000u, &clo.samples)) return sy_cli_bad_value("--spp", optarg);
            break;
        default:
            if (!sy_cluster_cli_getopt(c, optarg, &clo)) return sy_cli_bad_value(sy_cli_option_name(lo, c), optarg);
        }
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
    sy_view_args va = {.scene = ld.scene, .backend = backend, .width = w, .height = h, .frames = frames, .screenshot = shot};
    va.filter = view_filter;
    va.threshold = view_threshold;
    va.keys = view_keys;
    va.budget_ms = budget;
    va.cluster = clo.cluster ? &clo : NULL;
    va.spec.root = ld.root;
    va.spec.camera = ld.camera;
    va.spec.background = ld.background;
    va.spec.eye_separation = 0.065f;
    va.spec.zero_parallax = 2.0f;
    va.spec.backend = backend;
    sy_result r = overlay ? sy_cli_add_overlay(&ld, overlay, composite, &va.spec, &err) : SY_OK;
    if (r == SY_OK) r = sy_view_run(&va, &err);
    sy_cli_loaded_free(&ld);
    return r == SY_OK ? 0 : sy_cli_fail(&err);
}
#endif
