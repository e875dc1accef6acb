/* sy_cmd_web.c — `sy web SCENE`: the view in a web browser, served by sy_web (apps/web, docs/WEB.md;
 * built with it, SY_HAVE_WEB), with the culling service's routes where it was built. */
#include "sy_commands.h"
#include "sy_cli.h"
#include "sy_load.h"
#include "sy_signals.h"

#include "sy_web.h"
#ifdef SY_WEB_HAVE_CULL
#include "sy_web_cull.h"
#endif

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef SY_HAVE_WEB
/* `sy web SCENE`: the view in a web browser (apps/web/sy_web.h, docs/WEB.md). */
enum { OPT_WEB_LISTEN = 0x300, OPT_WEB_QUALITY, OPT_WEB_CLIENT_RENDER, OPT_WEB_DELAY };
int sy_cmd_web(int argc, char **argv)
{
    const char *backend = NULL, *camera = NULL, *listen = NULL, *filter = NULL, *scene = NULL;
    uint32_t w = 1920, h = 1200, quality = 80, delay_ms = 0;
    float threshold = 0.0f;
    double budget = 0; /* 0: the governor's default (33 ms) */
    bool client_render = false;
    static const struct option lo[] = {
        {"camera", required_argument, NULL, OPT_CAMERA}, {"listen", required_argument, NULL, OPT_WEB_LISTEN},
        {"quality", required_argument, NULL, OPT_WEB_QUALITY}, {"filter", required_argument, NULL, OPT_FILTER},
        {"threshold", required_argument, NULL, OPT_THRESHOLD}, {"budget", required_argument, NULL, OPT_BUDGET},
        {"client-render", no_argument, NULL, OPT_WEB_CLIENT_RENDER},
        {"delay-ms", required_argument, NULL, OPT_WEB_DELAY}, VIEW_OPTIONS, COMMON_OPTIONS};
    int c, status = 0;
    optind = 0;
    while ((c = sy_cli_next_sized_option("web", argc, argv, SHORT_OPTIONS("b:w:h:"), lo, 1, &w, &h, &status)) != -1) {
        char *end = NULL;
        switch (c) {
        case OPT_STOP: return status;
        case 'b': backend = optarg; break;
        case OPT_CAMERA: camera = optarg; break;
        case OPT_WEB_LISTEN: listen = optarg; break;
        case OPT_WEB_QUALITY:
            if (!sy_cli_parse_u32(optarg, 1, 100, &quality)) return sy_cli_bad_value("--quality", optarg);
            break;
        case OPT_FILTER: filter = optarg; break;
        case OPT_THRESHOLD:
            threshold = strtof(optarg, &end);
            if (end == optarg || *end || !(threshold >= 0.0f) || !isfinite(threshold)) return sy_cli_bad_value("--threshold", optarg);
            break;
        case OPT_BUDGET: /* the frame-time governor's budget (ms) */
            if (!sy_cli_parse_double(optarg, 1.0, 10000.0, &budget)) return sy_cli_bad_value("--budget", optarg);
            break;
        case OPT_WEB_CLIENT_RENDER: client_render = true; break;
        case OPT_WEB_DELAY: /* tests only: an added network delay in both directions */
            if (!sy_cli_parse_u32(optarg, 0, 10000, &delay_ms)) return sy_cli_bad_value("--delay-ms", optarg);
            break;
        }
    }
    if ((status = sy_cli_scene_operand("web", argc, argv, &scene))) return status;
    sy_error err = {0};
    if (!backend && !(backend = sy_cli_default_backend(&err))) return sy_cli_fail(&err);
    loaded ld;
    if (sy_cli_load(scene, camera, true, &ld, &err) != SY_OK) return sy_cli_fail(&err);
    sy_web_desc d = {.scene = ld.scene, .root = ld.root, .camera = ld.camera, .background = ld.background,
                     .backend = backend, .listen = listen, .max_width = w, .max_height = h, .quality = (int)quality,
                     .filter = filter, .threshold = threshold, .budget_ms = budget, .delay_ms = delay_ms};
    sy_web *web = NULL;
    sy_result r = SY_OK;
#ifdef SY_WEB_HAVE_CULL
    /* remote culling: /api/cull, /api/object/ID, /api/view; --client-render: the three.js page */
    sy_web_cull *cull = NULL;
    sy_web_route routes[SY_WEB_CULL_MAX_ROUTES];
    r = sy_web_cull_create(ld.scene, ld.root, client_render ? sy_web_cull_client_dir_default() : NULL, &cull, routes,
                           &d.route_count, &err);
    d.routes = routes;
#else
    if (client_render)
        r = sy_error_set(&err, SY_ERR_UNSUPPORTED, "sy web --client-render: this sy was built without the culling "
                         "service (it needs the Embree back-ends)");
#endif
    if (r == SY_OK) r = sy_web_create(&d, &web, &err);
#ifdef SY_WEB_HAVE_CULL
    if (r == SY_OK) sy_web_cull_attach(cull, web);
#endif
    if (r == SY_OK) {
        const char *url = sy_web_url(web), *q = strchr(url, '?');
        int host_len = q ? (int)(q - url) : (int)strlen(url);
        printf("sy web: serving %s with %s; open %.*s%s%s%s\n", argv[optind], backend, host_len, url,
               client_render ? "client/client.html" : "", q ? q : "",
               strstr(url, "//0.0.0.0:") || strstr(url, "//[::]:") ? " (with this machine's name or address for the host)" : "");
        fflush(stdout);
        sy_signals_set_graceful("closing the server");
        r = sy_web_run(web, sy_signals_stop_flag(), &err);
        sy_signals_set_graceful(NULL);
    }
    sy_web_destroy(web);
#ifdef SY_WEB_HAVE_CULL
    sy_web_cull_destroy(cull);
#endif
    sy_cli_loaded_free(&ld);
    return r == SY_OK ? 0 : sy_cli_fail(&err);
}
#endif
