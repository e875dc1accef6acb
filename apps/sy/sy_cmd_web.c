/* sy_cmd_web.c — `sy web SCENE`: the view in a web browser, served by sy_web (apps/web, docs/WEB.md;
 * built with it, SY_HAVE_WEB), with the culling service's routes where it was built. */
#include "sy_commands.h"
#include "sy_cli.h"
#include "sy_load.h"
#include "sy_signals.h"

#include "sy_anim.h"
#include "sy_log.h"
#include "sy_web.h"
#ifdef SY_WEB_HAVE_CULL
#include "sy_web_cull.h"
#endif

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef SY_HAVE_WEB
/* `sy web SCENE`: the view in a web browser (apps/web/sy_web.h, docs/WEB.md). */
enum { OPT_WEB_LISTEN = 0x300, OPT_WEB_QUALITY, OPT_WEB_CLIENT_RENDER, OPT_WEB_DELAY, OPT_WEB_READ_ONLY, OPT_WEB_MIN_SCALE };
int sy_cmd_web(int argc, char **argv)
{
    const char *backend = NULL, *camera = NULL, *listen = NULL, *filter = NULL, *scene = NULL;
    const char *clip = NULL; /* --clip NAME|INDEX: the clip the timeline plays (sy_cli_default_clip without it) */
    const char *bookmarks = NULL; /* --bookmarks FILE: the saved views (default: SCENE.bookmarks, as sy view) */
    uint32_t w = 1920, h = 1200, quality = 80, delay_ms = 0;
    float threshold = 0.0f;
    double budget = 0; /* 0: the governor's default (33 ms) */
    float min_scale = 0.0f; /* 0: SY_WEB_MIN_SCALE */
    bool client_render = false, no_temporal = false, read_only = false;
    const sy_cli_opt opts[] = {
        SY_CLI_OPT_TEXT(NULL, 'b', &backend), SY_CLI_OPT_TEXT("camera", OPT_CAMERA, &camera),
        SY_CLI_OPT_TEXT("listen", OPT_WEB_LISTEN, &listen), SY_CLI_OPT_UINT("quality", OPT_WEB_QUALITY, &quality, 1, 100),
        SY_CLI_OPT_TEXT("filter", OPT_FILTER, &filter), SY_CLI_OPT_FLOAT("threshold", OPT_THRESHOLD, &threshold, 0, FLT_MAX),
        SY_CLI_OPT_REAL("budget", OPT_BUDGET, &budget, 1.0, 10000.0), /* the frame-time governor's budget (ms) */
        SY_CLI_OPT_FLOAT("min-scale", OPT_WEB_MIN_SCALE, &min_scale, 0.03125f, 1.0f), /* moving frames' smallest scale */
        SY_CLI_OPT_FLAG("client-render", OPT_WEB_CLIENT_RENDER, &client_render),
        SY_CLI_OPT_FLAG("no-temporal", OPT_NO_TEMPORAL, &no_temporal),
        SY_CLI_OPT_FLAG("read-only", OPT_WEB_READ_ONLY, &read_only), /* viewers look, they do not change the scene */
        SY_CLI_OPT_TEXT("clip", OPT_CLIP, &clip), SY_CLI_OPT_TEXT("bookmarks", OPT_BOOKMARKS, &bookmarks),
        SY_CLI_OPT_UINT("delay-ms", OPT_WEB_DELAY, &delay_ms, 0, 10000)}; /* tests only: added network delay each way */
    sy_cli_parser p = {SY_CLI_ARGS("web", argc, argv, opts), .w = &w, .h = &h, .min_size = 1, .view = true};
    if (sy_cli_parse(&p) != -1) return p.status;
    int status;
    if ((status = sy_cli_scene_operand("web", argc, argv, &scene))) return status;
    sy_error err = {0};
    if (!backend && !(backend = sy_cli_default_backend(&err))) return sy_cli_fail(&err);
    loaded ld;
    if (sy_cli_load(scene, camera, true, &ld, &err) != SY_OK) return sy_cli_fail(&err);
    sy_web_desc d = {.scene = ld.scene, .root = ld.root, .camera = ld.camera, .background = ld.background,
                     .backend = backend, .listen = listen, .max_width = w, .max_height = h, .quality = (int)quality,
                     .filter = filter, .threshold = threshold, .budget_ms = budget, .min_scale = min_scale, .delay_ms = delay_ms,
                     .no_temporal = no_temporal, .read_only = read_only, .clip = sy_cli_default_clip(&ld)};
    char *marks = NULL; /* the saved views beside the scene file (not for the built-in demo) */
    d.bookmarks = sy_cli_bookmarks_file(scene, bookmarks, &marks);
    if (clip) { /* as sy render --clip: an unknown clip is a usage error naming the clips there are */
        sy_error fe = {0};
        if (!sy_scene_count(ld.scene, SY_TYPE_ANIMATION) || sy_animation_find(ld.scene, clip, &d.clip, &fe) != SY_OK) {
            fprintf(stderr, "sy web: error: --clip %s: %s\n", clip, fe.message[0] ? fe.message : "the scene has no animations");
            free(marks);
            sy_cli_loaded_free(&ld);
            return 2;
        }
    } else if (d.clip.id) {
        const sy_animation_data *ad = sy_animation_get(ld.scene, d.clip);
        sy_log(SY_LOG_NOTE, "sy", NULL, "the timeline plays clip 0 (%s) of %u; --clip NAME|INDEX or the page's clip menu plays another",
               ad && ad->name ? ad->name : "unnamed", sy_scene_count(ld.scene, SY_TYPE_ANIMATION));
    }
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
        printf("sy web: serving %s with %s%s; open %.*s%s%s%s\n", argv[optind], backend, read_only ? " (read-only)" : "",
               host_len, url,
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
    free(marks);
    sy_cli_loaded_free(&ld);
    return r == SY_OK ? 0 : sy_cli_fail(&err);
}
#endif
