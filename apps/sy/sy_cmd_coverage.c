/* sy_cmd_coverage.c — `sy coverage SCENE`: the objects the camera sees and the pixels each covers, as
 * JSON (the coverage back-end, one of the Embree ones). */
#include "sy_commands.h"
#include "sy_cli.h"
#include "sy_json.h"
#include "sy_load.h"

#include "sy_mediators.h"
#include "sy_viewport.h"

#include <math.h>
#include <stdlib.h>

/* `sy coverage SCENE`: which objects the camera sees and how many pixels each covers (occlusion
 * included), most first, as JSON: a culling service for clients that load only what is visible. */
int sy_cmd_coverage(int argc, char **argv)
{
    const char *scene = NULL, *camera = NULL;
    uint32_t w = 512, h = 512, top = 0;
    const sy_cli_opt opts[] = {SY_CLI_OPT_TEXT("camera", OPT_CAMERA, &camera),
                               SY_CLI_OPT_UINT("top", OPT_TOP, &top, 1, 1u << 30),
                               SY_CLI_OPT_FLAG("json", OPT_JSON, NULL)}; /* the output is JSON anyway */
    sy_cli_parser p = {SY_CLI_ARGS("coverage", argc, argv, opts), .w = &w, .h = &h, .min_size = 1};
    if (sy_cli_parse(&p) != -1) return p.status;
    int status;
    if ((status = sy_cli_scene_operand("coverage", argc, argv, &scene))) return status;
    sy_error err = {0};
#ifndef SY_HAVE_EMBREE /* the coverage back-end is one of the Embree ones */
    (void)scene, (void)camera, (void)w, (void)h, (void)top;
    sy_error_set(&err, SY_ERR_UNSUPPORTED, "sy coverage: this sy was built without the Embree back-ends (SY_WITH_EMBREE=OFF)");
    return sy_cli_fail(&err);
#else
    loaded ld;
    if (sy_cli_load(scene, camera, true, &ld, &err) != SY_OK) return sy_cli_fail(&err);
    if (ld.is_x3d) sy_cli_fit_x3d_cameras(&ld, w, h);
    sy_window *win = NULL;
    sy_viewport *vp = NULL;
    sy_context *ctx = NULL;
    sy_camera_view view = {0};
    sy_coverage_entry *e = NULL;
    uint32_t n = 0;
    /* the first registered class that counts per-node coverage (the Embree back-ends' "coverage") */
    const sy_mediator_class *cls = sy_mediator_with_caps(SY_CAP_COVERAGE);
    sy_viewport_desc vd = {.root = ld.root, .camera = ld.camera, .backend = cls ? cls->name : ""};
    sy_result r = cls ? SY_OK : sy_error_set(&err, SY_ERR_UNSUPPORTED, "sy coverage: no registered back-end counts per-node coverage");
    if (r == SY_OK) r = sy_window_create(w, h, &win, &err);
    if (r == SY_OK) r = sy_window_add_viewport(win, &vd, &vp, &err);
    if (r == SY_OK) r = sy_viewport_camera_view(vp, ld.scene, w, h, &view, &err);
    if (r == SY_OK) r = sy_context_create(ld.scene, cls->name, NULL, ld.root.id, &ctx, &err);
    if (r == SY_OK) r = sy_context_sync(ctx, &err);
    if (r == SY_OK) r = sy_context_coverage(ctx, &view, w, h, &e, &n, &err);
    cJSON *doc = NULL;
    if (r == SY_OK) {
        uint64_t covered = 0;
        for (uint32_t i = 0; i < n; ++i) covered += e[i].pixels;
        doc = cJSON_CreateObject();
        sy_json_add(doc, "file", sy_json_str(scene));
        sy_json_add(doc, "width", cJSON_CreateNumber(w));
        sy_json_add(doc, "height", cJSON_CreateNumber(h));
        sy_json_add(doc, "covered_pixels", cJSON_CreateNumber((double)covered));
        cJSON *objs = sy_json_add(doc, "objects", cJSON_CreateArray());
        uint32_t shown = top && top < n ? top : n;
        for (uint32_t i = 0; i < shown; ++i) {
            const sy_node_data *nd = sy_object_get(ld.scene, SY_TYPE_NODE, e[i].node_id);
            cJSON *o = sy_json_add(objs, NULL, cJSON_CreateObject());
            sy_json_add(o, "node", cJSON_CreateNumber(e[i].node_id));
            sy_json_add(o, "name", sy_json_str(nd ? nd->name : NULL));
            sy_json_add(o, "pixels", cJSON_CreateNumber(e[i].pixels));
            sy_json_add(o, "fraction", cJSON_CreateNumber(round((double)e[i].pixels / ((double)w * h) * 1e6) / 1e6));
        }
    }
    free(e);
    sy_context_release(ctx);
    sy_window_destroy(win);
    sy_cli_loaded_free(&ld);
    return r == SY_OK ? sy_json_print(doc) : sy_cli_fail(&err);
#endif
}
