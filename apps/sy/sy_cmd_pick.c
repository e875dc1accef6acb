/* sy_cmd_pick.c — `sy pick SCENE X Y [X Y ...]`: what is under pixels of the view `sy render` would
 * draw, as JSON (the library's sy_window_pick, the back-end's SY_CAP_PICK). */
#include "sy_commands.h"
#include "sy_cli.h"
#include "sy_json.h"
#include "sy_load.h"

#include "sy_log.h"
#include "sy_viewport.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* {"id": ID, "name": NAME} of a scene object (name "" when it has none or is gone). */
static cJSON *object_ref(const sy_scene *s, sy_object_type t, uint32_t id)
{
    cJSON *o = cJSON_CreateObject();
    const char *name = NULL;
    if (id && t == SY_TYPE_NODE) {
        const sy_node_data *d = sy_object_get(s, t, id);
        name = d ? d->name : NULL;
    } else if (id && t == SY_TYPE_MESH) {
        const sy_mesh_data *d = sy_object_get(s, t, id);
        name = d ? d->name : NULL;
    } else if (id && t == SY_TYPE_MATERIAL) {
        const sy_material_data *d = sy_object_get(s, t, id);
        name = d ? d->name : NULL;
    }
    sy_json_add(o, "id", cJSON_CreateNumber(id));
    sy_json_add(o, "name", sy_json_str(name));
    return o;
}

static cJSON *floats(const float *v, int n)
{
    cJSON *a = cJSON_CreateArray();
    for (int i = 0; i < n; ++i) sy_json_add(a, NULL, sy_json_float(v[i]));
    return a;
}

static cJSON *pick_json(const sy_scene *s, double x, double y, const sy_pick_result *p, const float *plane)
{
    static const char *const eyes[3] = {"mono", "left", "right"};
    cJSON *o = cJSON_CreateObject();
    sy_json_add(o, "x", cJSON_CreateNumber(x));
    sy_json_add(o, "y", cJSON_CreateNumber(y));
    sy_json_add(o, "hit", cJSON_CreateBool(p->hit));
    if (p->viewport != UINT32_MAX) {
        sy_json_add(o, "viewport", cJSON_CreateNumber(p->viewport));
        sy_json_add(o, "eye", sy_json_str(p->eye < 3 ? eyes[p->eye] : "?"));
    }
    if (!p->hit) return o;
    sy_json_add(o, "node", object_ref(s, SY_TYPE_NODE, p->node_id));
    sy_json_add(o, "placement", cJSON_CreateNumber(p->placement));
    sy_json_add(o, "mesh", object_ref(s, SY_TYPE_MESH, p->mesh_id));
    sy_json_add(o, "primitive", cJSON_CreateNumber(p->primitive));
    sy_json_add(o, "triangle", cJSON_CreateNumber(p->triangle));
    sy_json_add(o, "barycentrics", floats(p->barycentrics, 3));
    sy_json_add(o, "position", floats(p->position, 3));
    sy_json_add(o, "normal", floats(p->normal, 3));
    sy_json_add(o, "material", object_ref(s, SY_TYPE_MATERIAL, p->material_id));
    sy_json_add(o, "distance", sy_json_float(p->distance));
    sy_json_add(o, "depth", sy_json_float(p->depth));
    if (p->cap_plane) sy_json_add(o, "cap", cJSON_CreateNumber(p->cap_plane)); /* the section plane whose cap was hit */
    double pd;
    sy_error e = {0};
    if (plane && sy_plane_distance(plane, p->position, &pd, &e) == SY_OK) sy_json_add(o, "plane_distance", sy_json_float((float)pd));
    return o;
}

/* `sy pick SCENE X Y [X Y ...]`: one JSON object per pixel (an array when more than one). */
int sy_cmd_pick(int argc, char **argv)
{
    const char *scene = NULL, *camera = NULL, *backend = NULL, *params = NULL;
    uint32_t w = 0, h = 0;
    float planes[SY_CLIP_PLANES_MAX][4], plane[4];
    uint32_t nplanes = 0;
    bool measure = false, has_plane = false, cap = false;
    float cap_rgb[3];
    const sy_cli_opt opts[] = {SY_CLI_OPT_TEXT(NULL, 'b', &backend), SY_CLI_OPT_TEXT("camera", OPT_CAMERA, &camera),
                               SY_CLI_OPT_CODE("clip", OPT_CLIP, true), SY_CLI_OPT_TEXT("params", OPT_PARAMS, &params),
                               SY_CLI_OPT_FLAG("json", OPT_JSON, NULL), /* the output is JSON anyway */
                               SY_CLI_OPT_FLAG("measure", OPT_MEASURE, &measure), /* two points: their distance */
                               SY_CLI_OPT_CODE("plane", OPT_PLANE, true), /* each hit's distance from a plane */
                               SY_CLI_OPT_CODE("clip-cap", OPT_CLIP_CAP, true)}; /* picks on the caps */
    sy_cli_parser p = {SY_CLI_ARGS("pick", argc, argv, opts), .w = &w, .h = &h, .min_size = 1, .view = true};
    int c;
    while ((c = sy_cli_parse(&p)) != -1) {
        if (c == OPT_STOP) return p.status;
        if (c == OPT_CLIP && sy_cli_add_clip_plane(optarg, planes, &nplanes)) return 2;
        if (c == OPT_PLANE && sy_cli_parse_plane("--plane", optarg, plane)) return 2;
        if (c == OPT_PLANE) has_plane = true;
        if (c == OPT_CLIP_CAP && sy_cli_parse_cap_color(optarg, cap_rgb)) return 2;
        if (c == OPT_CLIP_CAP) cap = true;
    }
    if (optind >= argc) return sy_cli_usage_of("pick", "a SCENE and pixel coordinates X Y are required");
    scene = argv[optind++];
    int n = argc - optind;
    if (n < 2 || n % 2) return sy_cli_usage_of("pick", "pixel coordinates come in pairs: X Y [X Y ...]");
    int pairs = n / 2;
    if (measure && pairs != 2) return sy_cli_usage_of("pick", "--measure takes two points: X1 Y1 X2 Y2");
    double *xy = malloc(sizeof *xy * (size_t)n);
    if (!xy) {
        sy_error e = {0};
        sy_error_set(&e, SY_ERR_OUT_OF_MEMORY, "sy pick: out of memory");
        return sy_cli_fail(&e);
    }
    for (int i = 0; i < n; ++i)
        if (!sy_cli_parse_double(argv[optind + i], -1e9, 1e9, &xy[i])) {
            free(xy);
            return sy_cli_bad_value(i % 2 ? "Y" : "X", argv[optind + i]);
        }
    sy_error err = {0};
    if (!backend && !(backend = sy_cli_default_backend(&err))) {
        free(xy);
        return sy_cli_fail(&err);
    }
    const sy_mediator_class *cls = sy_mediator_require(backend, &err);
    sy_params given = {0};
    if (!cls || sy_params_parse(params, &given, &err) != SY_OK ||
        sy_mediator_class_check_params(cls, &given, &err) != SY_OK) {
        free(xy);
        sy_log(SY_LOG_ERROR, "sy", NULL, "%s", err.message);
        return 2;
    }
    if (!(sy_mediator_class_caps(cls, &given) & SY_CAP_PICK)) {
        free(xy);
        sy_log(SY_LOG_ERROR, "sy", NULL, "sy pick: back-end %s cannot pick (sy backends lists those with 'pick')", backend);
        return 2;
    }
    if (nplanes && !(sy_mediator_class_caps(cls, &given) & SY_CAP_CLIP)) {
        free(xy);
        sy_log(SY_LOG_ERROR, "sy", NULL, "--clip: back-end %s cannot cut with section planes (sy backends lists those with 'clip')",
               backend);
        return 2;
    }
    loaded ld;
    if (sy_cli_load(scene, camera, true, &ld, &err) != SY_OK) {
        free(xy);
        return sy_cli_fail(&err);
    }
    sy_cli_default_size(&ld, &w, &h); /* the size sy render would use */
    for (int i = 0; i < pairs; ++i)
        if (!(xy[2 * i] >= 0.0 && xy[2 * i] < w && xy[2 * i + 1] >= 0.0 && xy[2 * i + 1] < h)) {
            sy_log(SY_LOG_ERROR, "sy", NULL, "sy pick: pixel (%g, %g) is outside the %ux%u image", xy[2 * i],
                   xy[2 * i + 1], w, h);
            free(xy);
            sy_cli_loaded_free(&ld);
            return 2;
        }
    if (ld.is_x3d) sy_cli_fit_x3d_cameras(&ld, w, h);
    sy_window *win = NULL;
    sy_context_pool *pool = NULL;
    sy_viewport_desc vd = {.root = ld.root, .camera = ld.camera, .backend = backend, .params = params};
    sy_viewport *vp = NULL;
    sy_result r = sy_window_create(w, h, &win, &err);
    if (r == SY_OK) r = sy_window_add_viewport(win, &vd, &vp, &err);
    if (r == SY_OK && nplanes) r = sy_viewport_set_clip_planes(vp, (const float(*)[4])planes, nplanes, &err);
    if (r == SY_OK && cap) r = sy_viewport_set_clip_cap(vp, cap_rgb, &err);
    if (r == SY_OK) r = sy_context_pool_create(&pool, &err);
    cJSON *doc = NULL, *list = NULL;
    if (r == SY_OK && pairs > 1) doc = list = cJSON_CreateArray();
    sy_pick_result two[2];
    for (int i = 0; i < pairs && r == SY_OK; ++i) {
        sy_pick_result p;
        r = sy_window_pick(win, ld.scene, pool, xy[2 * i], xy[2 * i + 1], &p, &err);
        if (r != SY_OK) break;
        if (i < 2) two[i] = p;
        cJSON *o = pick_json(ld.scene, xy[2 * i], xy[2 * i + 1], &p, has_plane ? plane : NULL);
        if (i == 0) { /* what every pick shares, first */
            cJSON *head = cJSON_CreateObject();
            sy_json_add(head, "file", sy_json_str(scene));
            sy_json_add(head, "backend", sy_json_str(backend));
            sy_json_add(head, "width", cJSON_CreateNumber(w));
            sy_json_add(head, "height", cJSON_CreateNumber(h));
            for (cJSON *k = o->child; k;) { /* o's members after the shared ones */
                cJSON *next = k->next;
                cJSON_AddItemToObject(head, k->string, cJSON_DetachItemViaPointer(o, k));
                k = next;
            }
            cJSON_Delete(o);
            o = head;
        }
        if (list) sy_json_add(list, NULL, o);
        else doc = o;
    }
    double dist = 0.0;
    if (r == SY_OK && measure && (r = sy_pick_distance(&two[0], &two[1], &dist, &err)) != SY_OK)
        sy_error_prefix(&err, "sy pick --measure: pixels (%g, %g) and (%g, %g)", xy[0], xy[1], xy[2], xy[3]);
    if (r == SY_OK && measure) { /* {"picks": [...], "distance": D, "unit": "m"} */
        cJSON *m = cJSON_CreateObject();
        sy_json_add(m, "picks", doc);
        sy_json_add(m, "distance", cJSON_CreateNumber(dist));
        float delta[3];
        for (int k = 0; k < 3; ++k) delta[k] = two[1].position[k] - two[0].position[k];
        sy_json_add(m, "delta", floats(delta, 3));
        sy_json_add(m, "unit", sy_json_str("m"));
        doc = m;
    }
    sy_context_pool_destroy(pool);
    sy_window_destroy(win);
    sy_cli_loaded_free(&ld);
    free(xy);
    if (r != SY_OK) {
        cJSON_Delete(doc);
        return sy_cli_fail(&err);
    }
    return sy_json_print(doc);
}
