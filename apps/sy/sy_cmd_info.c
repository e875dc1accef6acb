/* sy_cmd_info.c — `sy info SCENE | IMAGE.exr | IMAGE.png`: a JSON summary of a scene (counts,
 * bounds, warnings) or of an image's size and metadata. */
#include "sy_commands.h"
#include "sy_cli.h"
#include "sy_json.h"
#include "sy_load.h"

#include "sy_exr.h"
#include "sy_log.h"
#include "sy_png.h"
#include "sy_sniff.h"

#include <math.h>
#include <string.h>

/* sy info IMAGE.exr: size, channels and the header's string attributes (what sy render records) as JSON. */
static int info_exr(const char *path)
{
    sy_error err = {0};
    sy_exr_image *img = NULL;
    if (sy_exr_read(path, &img, &err) != SY_OK) return sy_cli_fail(&err);
    cJSON *doc = cJSON_CreateObject();
    sy_json_add(doc, "file", sy_json_str(path));
    sy_json_add(doc, "width", cJSON_CreateNumber(img->width));
    sy_json_add(doc, "height", cJSON_CreateNumber(img->height));
    cJSON *ch = sy_json_add(doc, "channels", cJSON_CreateArray());
    for (int i = 0; i < img->channel_count; ++i) sy_json_add(ch, NULL, sy_json_str(img->channels[i].name));
    cJSON *at = sy_json_add(doc, "attributes", cJSON_CreateObject());
    for (int i = 0; i < img->attribute_count; ++i) sy_json_add(at, img->attributes[i].name, sy_json_str(img->attributes[i].value));
    sy_exr_image_free(img);
    return sy_json_print(doc);
}

/* sy info IMAGE.png: the size and the text chunks (sy render writes its metadata there: sy:renderer,
 * sy:backend, ...), in the same shape as an EXR's (attributes) */
static int info_png(const char *path)
{
    sy_error err = {0};
    sy_png_info pi;
    if (sy_png_read_info(path, &pi, &err) != SY_OK) return sy_cli_fail(&err);
    cJSON *doc = cJSON_CreateObject();
    sy_json_add(doc, "file", sy_json_str(path));
    sy_json_add(doc, "width", cJSON_CreateNumber(pi.width));
    sy_json_add(doc, "height", cJSON_CreateNumber(pi.height));
    cJSON *at = sy_json_add(doc, "attributes", cJSON_CreateObject());
    for (int i = 0; i < pi.text_count; ++i) sy_json_add(at, pi.keys[i], sy_json_str(pi.values[i]));
    sy_png_info_free(&pi);
    return sy_json_print(doc);
}

/* counts of one kind of object in an info object */
static void jcounts(cJSON *o, const char *const *names, const uint32_t *values, size_t n)
{
    for (size_t i = 0; i < n; ++i) sy_json_add(o, names[i], cJSON_CreateNumber(values[i]));
}

/* glTF's extensionsUsed split by what the loader reads (sy_gltf_supported_extensions) and the
 * KHR_materials_variants names; the same keys, empty, for every other format (gltf NULL). */
static void add_extensions(cJSON *doc, const sy_gltf_info *gltf)
{
    cJSON *ex = sy_json_add(doc, "extensions", cJSON_CreateObject());
    cJSON *used = sy_json_add(ex, "used", cJSON_CreateArray()), *sup = sy_json_add(ex, "supported", cJSON_CreateArray()),
          *uns = sy_json_add(ex, "unsupported", cJSON_CreateArray());
    cJSON *va = sy_json_add(doc, "variants", cJSON_CreateArray());
    if (!gltf) return;
    const char *const *known = sy_gltf_supported_extensions();
    for (uint32_t i = 0; i < gltf->extensions_used_count; ++i) {
        const char *e = gltf->extensions_used[i];
        bool ok = false;
        for (size_t k = 0; known[k] && !ok; ++k) ok = !strcmp(known[k], e);
        sy_json_add(used, NULL, sy_json_str(e));
        sy_json_add(ok ? sup : uns, NULL, sy_json_str(e));
    }
    for (uint32_t i = 0; i < gltf->variant_count; ++i) sy_json_add(va, NULL, sy_json_str(gltf->variant_names[i]));
}

/* sy info's log while it loads: warnings are part of its JSON output, everything else goes to stderr. */
static void info_log(void *user, sy_log_level level, const char *module, const char *item, const char *message)
{
    if (level != SY_LOG_WARNING) sy_log_stderr(user, level, module, item, message);
}

int sy_cmd_info(int argc, char **argv)
{
    const sy_cli_opt opts[] = {SY_CLI_OPT_FLAG("json", OPT_JSON, NULL)}; /* the output is JSON anyway */
    sy_cli_parser p = {SY_CLI_ARGS("info", argc, argv, opts)};
    if (sy_cli_parse(&p) != -1) return p.status;
    if (argc - optind != 1) return sy_cli_usage_of("info", argc == optind ? "a SCENE, IMAGE.exr or IMAGE.png is required" : "one file at a time");
    const char *path = argv[optind];
    sy_file_format fmt = SY_FORMAT_UNKNOWN;
    sy_error err = {0}, ignore = {0};
    if (sy_sniff_file(path, &fmt, &ignore) != SY_OK) fmt = SY_FORMAT_UNKNOWN; /* the loader names a missing file */
    if (fmt == SY_FORMAT_PNG) return info_png(path); /* by content, as scenes are recognised */
    if (sy_cli_ends_with(path, ".exr")) return info_exr(path);
    loaded ld;
    sy_log_set_callback(info_log, NULL); /* the load's warnings go into the JSON, not also to stderr */
    sy_result lr = sy_cli_load(path, NULL, false, &ld, &err);
    sy_log_set_callback(NULL, NULL);
    if (lr != SY_OK) return sy_cli_fail(&err);
    sy_bounds b;
    sy_node_world_bounds(ld.scene, ld.root, &b, NULL);
    /* counts of what was loaded into the scene (less the synthetic root node) */
    uint32_t prims = 0, tris = 0;
    for (uint32_t id = sy_scene_next(ld.scene, SY_TYPE_MESH, 0); id; id = sy_scene_next(ld.scene, SY_TYPE_MESH, id)) {
        const sy_mesh_data *m = sy_object_get(ld.scene, SY_TYPE_MESH, id);
        prims += m->primitives.count;
        for (uint32_t i = 0; i < m->primitives.count; ++i) tris += sy_primitive_triangle_count(&m->primitives.items[i]);
    }
    /* One layout for every format: format, the file's own counts (file_counts: what it declares,
     * skipped items included), what was loaded into the scene (loaded), bounds, warnings. */
    cJSON *doc = cJSON_CreateObject();
    sy_json_add(doc, "file", sy_json_str(path));
    sy_json_add(doc, "format", sy_json_str(ld.is_gltf ? "gltf" : ld.is_x3d ? "x3d" : ld.is_assimp ? "assimp" : "demo"));
    if (ld.is_assimp) { /* which of Assimp's importers; its skins and morph targets (the clips are listed below) */
        const sy_assimp_info *ai = &ld.assimp;
        const sy_assimp_counts *ac = &ai->counts;
        sy_json_add(doc, "importer", sy_json_str(ai->format));
        sy_json_add(doc, "unit_scale", sy_json_float((double)ai->unit_scale));
        sy_json_add(doc, "up_axis", ai->up_axis < 0 ? cJSON_CreateNull() : sy_json_str(ai->up_axis == 0 ? "x" : ai->up_axis == 1 ? "y" : "z"));
        static const char *const an[] = {"skinned_meshes", "bones", "morph_targets"};
        const uint32_t av[] = {ac->skinned_meshes, ac->bones, ac->morph_targets};
        jcounts(sy_json_add(doc, "skins_and_morphs", cJSON_CreateObject()), an, av, 3);
        sy_json_add(doc, "embedded_textures", cJSON_CreateNumber(ac->embedded_textures));
    }
    static const char *const names[] = {"nodes",  "meshes", "primitives", "triangles", "materials",     "textures",
                                        "images", "lights", "cameras",    "points",    "line_segments", "skipped",
                                        "animations"};
    uint32_t v[13] = {0};
    if (ld.is_gltf) {
        const sy_gltf_counts *gc = &ld.gltf.counts;
        const uint32_t g[13] = {gc->nodes,   gc->meshes,  gc->primitives, gc->triangles,     gc->materials,
                                gc->textures, gc->images, gc->lights,     gc->cameras,       gc->points,
                                gc->line_segments, gc->skipped_primitives, gc->animations};
        memcpy(v, g, sizeof v);
    } else if (ld.is_x3d) { /* X3D declares no totals: what its nodes made (an ImageTexture is one image);
                             * its interpolators are not counted as animations (0) */
        const sy_x3d_counts *xc = &ld.x3d.counts;
        const uint32_t x[13] = {xc->nodes,    xc->meshes,   xc->primitives, xc->triangles, xc->materials,
                                xc->textures, xc->textures, xc->lights,     xc->cameras,   xc->points,
                                xc->line_segments, xc->skipped_geometry, 0};
        memcpy(v, x, sizeof v);
    } else if (ld.is_assimp) { /* what Assimp read, after its post-processing (one primitive per mesh) */
        const sy_assimp_counts *ac = &ld.assimp.counts;
        const uint32_t a[13] = {ac->nodes,    ac->meshes,     ac->meshes, ac->triangles, ac->materials,
                                ac->textures, ac->embedded_textures, ac->lights, ac->cameras, ac->points,
                                ac->line_segments, ac->skipped, ac->animations};
        memcpy(v, a, sizeof v);
    }
    if (ld.is_gltf || ld.is_x3d || ld.is_assimp) jcounts(sy_json_add(doc, "file_counts", cJSON_CreateObject()), names, v, 13);
    else sy_json_add(doc, "file_counts", cJSON_CreateNull()); /* the built-in scene: no file */
    static const char *const lnames[] = {"nodes", "meshes", "primitives", "triangles", "materials",
                                         "textures", "lights", "cameras", "animations"};
    const uint32_t lv[] = {sy_scene_count(ld.scene, SY_TYPE_NODE) - 1, sy_scene_count(ld.scene, SY_TYPE_MESH), prims,
                           tris, sy_scene_count(ld.scene, SY_TYPE_MATERIAL), sy_scene_count(ld.scene, SY_TYPE_TEXTURE),
                           sy_scene_count(ld.scene, SY_TYPE_LIGHT), sy_scene_count(ld.scene, SY_TYPE_CAMERA),
                           sy_scene_count(ld.scene, SY_TYPE_ANIMATION)};
    jcounts(sy_json_add(doc, "loaded", cJSON_CreateObject()), lnames, lv, 9);
    add_extensions(doc, ld.is_gltf ? &ld.gltf : NULL);
    /* the clips (sy_anim.h): index (what --clip takes), name, time range and duration, channels */
    cJSON *clips = sy_json_add(doc, "clips", cJSON_CreateArray());
    uint32_t ci = 0;
    for (uint32_t id = sy_scene_next(ld.scene, SY_TYPE_ANIMATION, 0); id; id = sy_scene_next(ld.scene, SY_TYPE_ANIMATION, id), ++ci) {
        const sy_animation_data *ad = sy_object_get(ld.scene, SY_TYPE_ANIMATION, id);
        float start, end;
        uint32_t nch, nsm;
        sy_animation_time_range(ad, &start, &end);
        sy_animation_channels(ad, &nch);
        sy_animation_samplers(ad, &nsm);
        cJSON *c = sy_json_add(clips, NULL, cJSON_CreateObject());
        sy_json_add(c, "index", cJSON_CreateNumber(ci));
        sy_json_add(c, "name", ad->name ? sy_json_str(ad->name) : cJSON_CreateNull());
        sy_json_add(c, "start", sy_json_float((double)start));
        sy_json_add(c, "duration", sy_json_float((double)end)); /* glTF: the clip runs from 0 to its last key */
        sy_json_add(c, "loop", cJSON_CreateBool(ad->loop != 0)); /* X3D TimeSensor.loop: --at wraps */
        sy_json_add(c, "channels", cJSON_CreateNumber(nch));
        sy_json_add(c, "samplers", cJSON_CreateNumber(nsm));
    }
    /* the cameras (what --camera takes: the index, or the node or camera name): the projection, its
     * angle or half extents, and the world position and viewing direction at load time */
    cJSON *cams = sy_json_add(doc, "cameras", cJSON_CreateArray());
    const sy_node *cn = ld.is_gltf ? ld.gltf.camera_nodes : ld.is_x3d ? ld.x3d.camera_nodes : ld.is_assimp ? ld.assimp.camera_nodes : NULL;
    uint32_t ncam = ld.is_gltf ? ld.gltf.camera_node_count : ld.is_x3d ? ld.x3d.camera_node_count
                  : ld.is_assimp ? ld.assimp.camera_node_count : 0;
    sy_node demo_cam = {0};
    if (!ld.is_gltf && !ld.is_x3d && !ld.is_assimp && ld.camera.id) demo_cam = ld.camera, cn = &demo_cam, ncam = 1;
    for (uint32_t i = 0; i < ncam; ++i) {
        const sy_node_data *nd = sy_node_get(ld.scene, cn[i]);
        const sy_camera_data *cd = nd ? sy_camera_get(ld.scene, nd->camera) : NULL;
        sy_mat4 m;
        if (!cd || sy_node_world_matrix(ld.scene, cn[i], &m, NULL) != SY_OK) continue;
        cJSON *c = sy_json_add(cams, NULL, cJSON_CreateObject());
        sy_json_add(c, "index", cJSON_CreateNumber(i));
        sy_json_add(c, "name", nd->name && *nd->name ? sy_json_str(nd->name) : cJSON_CreateNull());
        sy_json_add(c, "camera_name", cd->name && *cd->name ? sy_json_str(cd->name) : cJSON_CreateNull());
        bool ortho = cd->projection == SY_PROJECTION_ORTHOGRAPHIC;
        sy_json_add(c, "type", sy_json_str(ortho ? "orthographic" : "perspective"));
        if (ortho) {
            sy_json_add(c, "xmag", sy_json_float((double)cd->xmag));
            sy_json_add(c, "ymag", sy_json_float((double)cd->ymag));
        } else {
            sy_json_add(c, "yfov", sy_json_float((double)cd->yfov)); /* radians */
            sy_json_add(c, "yfov_degrees", sy_json_float((double)cd->yfov * 57.29577951308232));
        }
        if (cd->aspect > 0) sy_json_add(c, "aspect", sy_json_float((double)cd->aspect));
        cJSON *pos = sy_json_add(c, "position", cJSON_CreateArray()), *dir = sy_json_add(c, "direction", cJSON_CreateArray());
        float back[3] = {m.m[8], m.m[9], m.m[10]}, bl = sqrtf(back[0] * back[0] + back[1] * back[1] + back[2] * back[2]);
        for (int k = 0; k < 3; ++k) {
            sy_json_add(pos, NULL, sy_json_float((double)m.m[12 + k]));
            sy_json_add(dir, NULL, sy_json_float(bl > 0 ? -(double)back[k] / bl + 0.0 : 0.0)); /* + 0.0: no "-0" */
        }
    }
    if (sy_bounds_is_empty(&b)) {
        sy_json_add(doc, "bounds", cJSON_CreateNull());
    } else {
        cJSON *bo = sy_json_add(doc, "bounds", cJSON_CreateObject());
        cJSON *mn = sy_json_add(bo, "min", cJSON_CreateArray()), *mx = sy_json_add(bo, "max", cJSON_CreateArray());
        for (int k = 0; k < 3; ++k) {
            sy_json_add(mn, NULL, sy_json_float((double)b.min[k]));
            sy_json_add(mx, NULL, sy_json_float((double)b.max[k]));
        }
    }
    sy_json_add(doc, "warning_count", cJSON_CreateNumber(ld.gltf.warning_count + ld.x3d.warning_count + ld.assimp.warning_count)); /* all, stored or not */
    cJSON *wa = sy_json_add(doc, "warnings", cJSON_CreateArray());
    for (uint32_t i = 0; i < ld.gltf.stored_warning_count; ++i) sy_json_add(wa, NULL, sy_json_str(ld.gltf.warnings[i]));
    for (uint32_t i = 0; i < ld.x3d.stored_warning_count; ++i) sy_json_add(wa, NULL, sy_json_str(ld.x3d.warnings[i]));
    for (uint32_t i = 0; i < ld.assimp.stored_warning_count; ++i) sy_json_add(wa, NULL, sy_json_str(ld.assimp.warnings[i]));
    sy_cli_loaded_free(&ld);
    return sy_json_print(doc);
}
