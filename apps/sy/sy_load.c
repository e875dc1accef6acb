/* sy_load.c — how sy loads a SCENE (sy_load.h): the built-in demo, glTF, X3D or an Assimp format
 * (OBJ, FBX, COLLADA, PLY, STL, ...) recognised by content,
 * the loader options of every command (--allow-path, --strict, --max-scene-mb), a default camera,
 * the world flags, X3D fields of view, and --overlay FILE[:BACKEND]. */
#include "sy_load.h"
#include "sy_cli.h"

#include "sy_anim.h"
#include "sy_bookmarks.h"
#include "sy_demo.h"
#include "sy_log.h"
#include "sy_mediators.h"
#include "sy_viewport.h"
#include "sy_sniff.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

sy_load_options sy_cli_load_opts;

void sy_cli_loaded_free(loaded *l)
{
    sy_gltf_info_free(&l->gltf);
    sy_x3d_info_free(&l->x3d);
    sy_assimp_info_free(&l->assimp);
    sy_scene_destroy(l->scene);
    memset(l, 0, sizeof *l);
}

/* A file without a camera gets one framing its bounds (as a real camera node, so every back-end
 * sees the same view); a file with neither punctual lights nor emissive materials gets a
 * directional headlight from that camera, so that it is not black. The headlight is reported on
 * stderr. */
static sy_result add_defaults(loaded *ld, sy_error *err)
{
    sy_scene *s = ld->scene;
    sy_result r = SY_OK;
    sy_mat4 cam_world;
    if (!ld->camera.id) {
        sy_bounds b;
        if ((r = sy_node_world_bounds(s, ld->root, &b, err))) return r;
        sy_camera_view v = sy_camera_view_frame_bounds(&b, 1.0f);
        sy_camera cam;
        sy_camera_data cd = *(const sy_camera_data *)sy_object_defaults(SY_TYPE_CAMERA);
        cd.yfov = 2.0f * atanf(v.window[3]);
        cd.znear = v.znear;
        if ((r = sy_camera_create(s, "default camera", &cam, err)) || (r = sy_camera_set(s, cam, &cd, err)) ||
            (r = sy_node_create(s, "default camera", &ld->camera, err)) ||
            (r = sy_node_set_matrix(s, ld->camera, &v.camera_to_world, err)) ||
            (r = sy_node_set_camera(s, ld->camera, cam, err)))
            return r;
        cam_world = v.camera_to_world;
    } else if ((r = sy_node_world_matrix(s, ld->camera, &cam_world, err))) {
        return r;
    }
    (void)cam_world;
    return sy_scene_commit(s, NULL, err);
}

/* "x,y,z" (exactly three finite numbers) from text up to stop into v. */
static bool parse_vec3(const char *text, const char *stop, float v[3])
{
    int n = 0;
    return sy_cli_parse_floats(text, (size_t)(stop - text), 3, 3, v, &n);
}

static int view_usage(const char *opt, const char *value, const char *why)
{
    fprintf(stderr, "sy: error: %s %s: %s\n", opt, value, why);
    return 2;
}

int sy_cli_view_option(int c, const char *value)
{
    sy_view_options *v = &sy_cli_load_opts.view;
    if (c == OPT_FOV) {
        double deg = 0;
        if (!sy_cli_parse_double(value, 0.0, 180.0, &deg) || !(deg > 0.0 && deg < 180.0))
            return view_usage("--fov", value, "expected the vertical field of view in degrees, above 0 and below 180");
        v->fov = (float)(deg * 3.14159265358979323846 / 180.0);
        return 0;
    }
    if (c == OPT_BOOKMARK) { /* FILE:N, a saved view of sy view (sy_bookmarks.h): the --look-at it holds */
        const char *colon = strrchr(value, ':');
        uint64_t slot = 0;
        if (!colon || colon == value || !sy_cli_parse_uint(colon + 1, 1, SY_BOOKMARKS_MAX, &slot))
            return view_usage("--bookmark", value, "expected FILE:N, N a saved view 1..9 (sy view: Ctrl+N saves one)");
        size_t len = (size_t)(colon - value);
        char *path = malloc(len + 1);
        if (!path) return view_usage("--bookmark", value, "out of memory");
        memcpy(path, value, len);
        path[len] = '\0';
        sy_bookmark slots[SY_BOOKMARKS_MAX + 1];
        sy_error e = {0};
        sy_result r = sy_bookmarks_load(path, slots, &e);
        free(path);
        if (r != SY_OK) return view_usage("--bookmark", value, e.message);
        const sy_bookmark *b = &slots[(int)slot];
        if (!b->set) return view_usage("--bookmark", value, "the file holds no view in that slot");
        if (v->look_at || v->bookmark)
            return view_usage("--bookmark", value, "--look-at and --bookmark both place the camera; give one of them");
        memcpy(v->eye, b->eye, sizeof v->eye);
        memcpy(v->target, b->target, sizeof v->target);
        memcpy(v->up, b->up, sizeof v->up);
        if (b->fov > 0 && !(v->fov > 0)) v->fov = b->fov; /* its field of view, unless --fov gives one */
        v->look_at = v->bookmark = true;
    } else if (c == OPT_LOOK_AT) {
        if (v->bookmark) return view_usage("--look-at", value, "--look-at and --bookmark both place the camera; give one of them");
        const char *c1 = strchr(value, ':'), *c2 = c1 ? strchr(c1 + 1, ':') : NULL, *end = value + strlen(value);
        if (!c1 || (c2 && strchr(c2 + 1, ':')))
            return view_usage("--look-at", value, "expected EYE:TARGET or EYE:TARGET:UP, each x,y,z (e.g. 0,1,5:0,0,0)");
        float up[3] = {0, 1, 0};
        if (!parse_vec3(value, c1, v->eye))
            return view_usage("--look-at", value, "EYE is not x,y,z (three finite numbers)");
        if (!parse_vec3(c1 + 1, c2 ? c2 : end, v->target))
            return view_usage("--look-at", value, "TARGET is not x,y,z (three finite numbers)");
        if (c2 && !parse_vec3(c2 + 1, end, up)) return view_usage("--look-at", value, "UP is not x,y,z (three finite numbers)");
        if (!sy_coords_in_range(v->eye, 3) || !sy_coords_in_range(v->target, 3))
            return view_usage("--look-at", value, "a coordinate beyond 1e12 (SY_COORD_MAX)");
        sy_mat4 m;
        if (v->eye[0] == v->target[0] && v->eye[1] == v->target[1] && v->eye[2] == v->target[2])
            return view_usage("--look-at", value, "EYE and TARGET are the same point");
        if (!sy_mat4_look_at(v->eye, v->target, up, &m))
            return view_usage("--look-at", value, "UP is zero or parallel to the viewing direction (give another UP)");
        memcpy(v->up, up, sizeof up);
        v->look_at = true;
    } else { /* OPT_ORBIT */
        float a[3] = {0, 0, 0};
        int n = 0;
        if (!sy_cli_parse_floats(value, strlen(value), 2, 3, a, &n))
            return view_usage("--orbit", value, "expected AZ,EL or AZ,EL,DIST (degrees, degrees, scene units; finite numbers)");
        if (!(a[1] >= -90.0f && a[1] <= 90.0f)) return view_usage("--orbit", value, "EL must be from -90 to 90 degrees");
        if (n == 3 && !(a[2] > 0.0f && a[2] <= SY_COORD_MAX))
            return view_usage("--orbit", value, "DIST must be above 0 (and at most 1e12)");
        if (!(fabsf(a[0]) <= 1e6f)) return view_usage("--orbit", value, "AZ must be within +-1e6 degrees");
        v->azimuth = a[0], v->elevation = a[1], v->dist = n == 3 ? a[2] : 0.0f;
        v->orbit = true;
    }
    if (v->look_at && v->orbit) {
        fprintf(stderr, "sy: error: %s and --orbit both place the camera; give one of them\n", v->bookmark ? "--bookmark" : "--look-at");
        return 2;
    }
    return 0;
}

int sy_cli_node_option(int c, const char *value)
{
    sy_node_options *o = &sy_cli_load_opts.nodes;
    const char *opt = c == OPT_HIDE ? "--hide" : c == OPT_ISOLATE ? "--isolate" : "--select";
    const char **list = c == OPT_HIDE ? o->hide : c == OPT_ISOLATE ? o->isolate : o->select;
    uint32_t *n = c == OPT_HIDE ? &o->hide_count : c == OPT_ISOLATE ? &o->isolate_count : &o->select_count;
    if (!*value) return view_usage(opt, "''", "expected a node name or number");
    if (*n == SY_MAX_NODE_OPTIONS) {
        fprintf(stderr, "sy: error: %s: at most %d nodes\n", opt, SY_MAX_NODE_OPTIONS);
        return 2;
    }
    list[(*n)++] = value;
    return 0;
}

sy_result sy_cli_find_nodes(const sy_scene *s, const char *opt, const char *node, sy_node *out, uint32_t max,
                            uint32_t *count_out, sy_error *err)
{
    *count_out = 0;
    uint64_t num = 0;
    bool is_num = sy_cli_parse_uint(node, 0, UINT32_MAX, &num);
    if (is_num && sy_node_get(s, (sy_node){(uint32_t)num})) { /* the id sy pick prints */
        out[(*count_out)++] = (sy_node){(uint32_t)num};
        return SY_OK;
    }
    uint32_t k = 0;
    for (uint32_t id = sy_scene_next(s, SY_TYPE_NODE, 0); id; id = sy_scene_next(s, SY_TYPE_NODE, id), ++k) {
        const sy_node_data *d = sy_node_get(s, (sy_node){id});
        bool match = is_num ? k == num : d && d->name && !strcmp(d->name, node);
        if (match && *count_out < max) out[(*count_out)++] = (sy_node){id};
        if (match && is_num) break;
    }
    if (*count_out) return SY_OK;
    return sy_error_set(err, SY_ERR_NOT_FOUND,
                        "%s %s: no such node (a node name, the node id sy pick prints, or an index below %u)", opt,
                        node, sy_scene_count(s, SY_TYPE_NODE));
}

/* The node options (sy_cli_load_opts.nodes) on the loaded scene: see sy_cli_load in sy_load.h. */
static sy_result apply_nodes(loaded *ld, sy_error *err)
{
    const sy_node_options *o = &sy_cli_load_opts.nodes;
    if (!o->hide_count && !o->isolate_count && !o->select_count) return SY_OK;
    enum { MAX_MATCHES = 4096 };
    sy_node *found = malloc(MAX_MATCHES * sizeof *found);
    if (!found) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "node options: out of memory");
    uint32_t nf = 0, m;
    sy_result r = SY_OK;
    for (uint32_t i = 0; i < o->isolate_count && r == SY_OK; ++i)
        if ((r = sy_cli_find_nodes(ld->scene, "--isolate", o->isolate[i], found + nf, MAX_MATCHES - nf, &m, err)) == SY_OK)
            nf += m;
    if (r == SY_OK && o->isolate_count) r = sy_scene_isolate(ld->scene, found, nf, err);
    for (uint32_t i = 0; i < o->hide_count && r == SY_OK; ++i) {
        r = sy_cli_find_nodes(ld->scene, "--hide", o->hide[i], found, MAX_MATCHES, &m, err);
        for (uint32_t k = 0; k < m && r == SY_OK; ++k) r = sy_node_set_visible(ld->scene, found[k], false, err);
    }
    for (uint32_t i = 0; i < o->select_count && r == SY_OK; ++i) {
        r = sy_cli_find_nodes(ld->scene, "--select", o->select[i], found, MAX_MATCHES, &m, err);
        for (uint32_t k = 0; k < m && r == SY_OK; ++k) r = sy_node_set_selected(ld->scene, found[k], true, err);
    }
    free(found);
    return r == SY_OK ? sy_scene_commit(ld->scene, NULL, err) : r;
}

/* The view options (sy_cli_load_opts.view) on the loaded scene: see sy_cli_load in sy_load.h. */
static sy_result apply_view(loaded *ld, sy_error *err)
{
    const sy_view_options *v = &sy_cli_load_opts.view;
    if (!v->look_at && !v->orbit && !(v->fov > 0)) return SY_OK;
    sy_scene *s = ld->scene;
    const sy_node_data *nd = ld->camera.id ? sy_node_get(s, ld->camera) : NULL;
    const sy_camera_data *cur = nd ? sy_camera_get(s, nd->camera) : NULL;
    sy_camera_data c = cur ? *cur : *(const sy_camera_data *)sy_object_defaults(SY_TYPE_CAMERA);
    if (!cur) c.yfov = 0.7853982f; /* the default camera's (sy_camera_view_frame_bounds) */
    c.name = (char *)"command-line camera";
    if (v->fov > 0) {
        if (c.projection == SY_PROJECTION_ORTHOGRAPHIC)
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "--fov: the camera is orthographic (it has no field of view)");
        c.yfov = v->fov;
    }
    sy_mat4 m;
    if (v->look_at) {
        if (!sy_mat4_look_at(v->eye, v->target, v->up, &m))
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "--look-at: no view (eye == target or up along the view)");
    } else if (v->orbit) {
        sy_bounds b;
        sy_result r = sy_node_world_bounds(s, ld->root, &b, err);
        if (r) return r;
        float ctr[3] = {0, 0, 0}, rad = 1.0f, ext2 = 0.0f;
        if (!sy_bounds_is_empty(&b)) { /* as sy_camera_view_frame_bounds: the bounds' sphere */
            for (int i = 0; i < 3; ++i) {
                float e = 0.5f * (b.max[i] - b.min[i]);
                ctr[i] = 0.5f * (b.min[i] + b.max[i]);
                ext2 += e * e;
            }
            rad = sqrtf(ext2);
            if (!(rad > 1e-6f)) rad = 1.0f;
        }
        float dist = v->dist;
        if (!(dist > 0)) {
            if (c.projection == SY_PROJECTION_ORTHOGRAPHIC) dist = 2.0f * rad;
            else {
                float half = 0.5f * c.yfov;
                if (c.aspect > 0.0f && c.aspect < 1.0f) half = atanf(tanf(half) * c.aspect); /* the narrower side */
                dist = rad / sinf(half) * 1.05f;
            }
        }
        double az = v->azimuth * 3.14159265358979323846 / 180.0, el = v->elevation * 3.14159265358979323846 / 180.0;
        float back[3] = {(float)(cos(el) * sin(az)), (float)sin(el), (float)(cos(el) * cos(az))};
        float eye[3] = {ctr[0] + back[0] * dist, ctr[1] + back[1] * dist, ctr[2] + back[2] * dist};
        float up[3] = {0, 1, 0};
        if (fabsf(v->elevation) > 89.99f) { /* straight down (up): the image's up is away from (towards) AZ */
            float k = v->elevation > 0 ? -1.0f : 1.0f;
            up[0] = k * (float)sin(az), up[1] = 0.0f, up[2] = k * (float)cos(az);
        }
        if (!sy_mat4_look_at(eye, ctr, up, &m))
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "--orbit: no view at distance %g", (double)dist);
    }
    sy_camera cam;
    sy_result r;
    if ((r = sy_camera_create(s, "command-line camera", &cam, err)) || (r = sy_camera_set(s, cam, &c, err))) return r;
    if (v->look_at || v->orbit) {
        sy_node node;
        if ((r = sy_node_create(s, "command-line camera", &node, err)) || (r = sy_node_set_matrix(s, node, &m, err)) ||
            (r = sy_node_set_camera(s, node, cam, err)))
            return r;
        ld->camera = node;
    } else if ((r = sy_node_set_camera(s, ld->camera, cam, err))) { /* --fov alone: the chosen camera, in place */
        return r;
    }
    return sy_scene_commit(s, NULL, err);
}

/* What the loader skipped or repaired is on the log already (the loaders report it through sy_log:
 * sy: warning: FILE: item: what); with --strict any of it fails the load. */
static sy_result report_warnings(const char *path, uint32_t total, sy_error *err)
{
    if (sy_cli_load_opts.strict && total)
        return sy_error_set(err, SY_ERR_PARSE, "%s: %u warning%s and --strict given; nothing rendered", path, total,
                            total == 1 ? "" : "s");
    return SY_OK;
}

/* A loader's camera selector over its info struct (sy_gltf_find_camera, sy_x3d_find_camera). */
typedef sy_result (*camera_finder)(const sy_scene *s, const void *info, const char *sel, sy_node *out, sy_error *err);
static sy_result find_gltf_camera(const sy_scene *s, const void *info, const char *sel, sy_node *out, sy_error *err)
{
    return sy_gltf_find_camera(s, info, sel, out, err);
}
static sy_result find_x3d_camera(const sy_scene *s, const void *info, const char *sel, sy_node *out, sy_error *err)
{
    return sy_x3d_find_camera(s, info, sel, out, err);
}

/* The confinement and budget options every loader takes alike (sy_gltf_options, sy_x3d_options,
 * sy_assimp_options name them the same). */
#define LOADER_OPTIONS                                                                                  \
    {.allowed_roots = sy_cli_load_opts.roots, .allowed_root_count = sy_cli_load_opts.root_count,        \
     .max_scene_bytes = sy_cli_load_opts.max_scene_bytes}

/* What each file format's branch does after its loader returned r: the warnings (--strict), the
 * file's root, and the camera sel names (found by find in info) or else the file's first; errors
 * after the load name the file. */
static sy_result loaded_view(loaded *out, const char *path, const char *sel, sy_result r, uint32_t warnings,
                             sy_node root, const sy_node *cameras, uint32_t camera_count, camera_finder find,
                             const void *info, sy_error *err)
{
    if (r == SY_OK) r = report_warnings(path, warnings, err);
    if (r != SY_OK) return r;
    out->root = root;
    if (sel) r = find(out->scene, info, sel, &out->camera, err);
    else if (camera_count) out->camera = cameras[0];
    if (r != SY_OK) sy_error_prefix(err, "%s", path);
    return r;
}

/* The scene format of path, from its content (sy_sniff.h): a file of another kind is refused,
 * named for what it is; one that is not recognised goes to the loader its name suggests (which
 * then says what is wrong with it): .x3d to X3D, an extension Assimp reads to Assimp, the rest to
 * glTF. */
static sy_result recognise(const char *path, sy_file_format *fmt, bool *assimp, sy_error *err)
{
    *fmt = SY_FORMAT_UNKNOWN;
    sy_error ignore = {0};
    const char *dot = strrchr(path, '.'), *slash = strrchr(path, '/');
    const char *ext = dot && (!slash || dot > slash) ? dot : "";
    bool own = !strcasecmp(ext, ".gltf") || !strcasecmp(ext, ".glb") || !strcasecmp(ext, ".x3d");
    *assimp = false;
    if (sy_sniff_file(path, fmt, &ignore) != SY_OK) return SY_OK; /* the loader reports a missing file */
    *assimp = sy_file_format_is_assimp(*fmt) || (*fmt == SY_FORMAT_UNKNOWN && !own && sy_assimp_reads_extension(ext));
    if (*fmt == SY_FORMAT_UNKNOWN || sy_file_format_is_scene(*fmt)) return SY_OK;
    return sy_error_set(err, SY_ERR_UNSUPPORTED,
                        "%s: %s content, which sy does not read as a scene (it reads glTF 2.0, X3D in XML encoding, and "
                        "OBJ, FBX, COLLADA, PLY, STL, 3MF, 3DS, glTF 1.0 and the other formats Assimp reads)",
                        path, sy_file_format_name(*fmt));
}

sy_result sy_cli_load(const char *path, const char *camera_sel, bool defaults, loaded *out, sy_error *err)
{
    memset(out, 0, sizeof *out);
    sy_file_format fmt = SY_FORMAT_UNKNOWN;
    bool assimp = false;
    double t0 = sy_time_now();
    sy_result r = sy_scene_create(&out->scene, err);
    if (r != SY_OK) return r;
    if (strcmp(path, "demo") == 0) {
        sy_demo_info d;
        r = sy_demo_build(out->scene, &d, err);
        if (r == SY_OK) {
            out->root = d.root;
            out->camera = d.camera;
            out->background = d.background;
            if (camera_sel && strcmp(camera_sel, "0") != 0 && strcmp(camera_sel, "camera") != 0)
                r = sy_error_set(err, SY_ERR_NOT_FOUND, "demo: no camera '%s' (available: 0 \"camera\")", camera_sel);
        }
    } else if ((r = recognise(path, &fmt, &assimp, err)) != SY_OK) {
        /* named for what it is: not a scene format the loaders read */
    } else if (assimp) {
        out->is_assimp = true;
        sy_assimp_options ao = LOADER_OPTIONS;
        r = sy_assimp_load(path, out->scene, &ao, &out->assimp, err);
        const sy_assimp_info *ai = &out->assimp;
        /* the glTF loader's camera selector over the same list of camera nodes */
        sy_gltf_info view = {.camera_nodes = ai->camera_nodes, .camera_node_count = ai->camera_node_count};
        r = loaded_view(out, path, camera_sel, r, ai->warning_count, ai->root, ai->camera_nodes, ai->camera_node_count,
                        find_gltf_camera, &view, err);
    } else if (fmt == SY_FORMAT_X3D || (fmt == SY_FORMAT_UNKNOWN && strlen(path) > 4 &&
                                        !strcasecmp(path + strlen(path) - 4, ".x3d"))) {
        out->is_x3d = true;
        sy_x3d_options xo = LOADER_OPTIONS;
        r = sy_x3d_load(path, out->scene, &xo, &out->x3d, err);
        r = loaded_view(out, path, camera_sel, r, out->x3d.warning_count, out->x3d.root, out->x3d.camera_nodes,
                        out->x3d.camera_node_count, find_x3d_camera, &out->x3d, err);
        if (r == SY_OK) out->background = out->x3d.background;
    } else {
        out->is_gltf = true;
        sy_gltf_options go = LOADER_OPTIONS;
        r = sy_gltf_load(path, out->scene, &go, &out->gltf, err);
        r = loaded_view(out, path, camera_sel, r, out->gltf.warning_count, out->gltf.root, out->gltf.camera_nodes,
                        out->gltf.camera_node_count, find_gltf_camera, &out->gltf, err);
        if (r == SY_OK && sy_cli_load_opts.variant &&
            (r = sy_gltf_select_variant(out->scene, &out->gltf, sy_cli_load_opts.variant, err)) != SY_OK)
            sy_error_prefix(err, "%s", path);
    }
    if (r == SY_OK && sy_cli_load_opts.variant && !out->is_gltf)
        r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: --variant: material variants are a glTF extension "
                         "(KHR_materials_variants); this is not a glTF file", path);
    if (r == SY_OK) r = sy_scene_commit(out->scene, NULL, err);
    if (r == SY_OK && (out->is_gltf || out->is_x3d || out->is_assimp) && defaults) r = add_defaults(out, err);
    if (r == SY_OK) r = apply_view(out, err); /* --look-at, --orbit, --fov */
    if (r == SY_OK) r = apply_nodes(out, err); /* --isolate, --hide, --select */
    /* the user's world choices: sy_world (formats) maps them onto the world object */
    if (r == SY_OK && !sy_world_options_empty(&sy_cli_load_opts.world) &&
        (r = sy_world_apply(out->scene, &out->background, &sy_cli_load_opts.world, err)) == SY_OK)
        r = sy_scene_commit(out->scene, NULL, err);
    if (r != SY_OK) sy_cli_loaded_free(out);
    else
        sy_log(SY_LOG_DEBUG, "sy", path, "loaded in %.3f s: %u nodes, %u meshes, %u materials, %u lights, %u cameras",
               sy_time_now() - t0, sy_scene_count(out->scene, SY_TYPE_NODE), sy_scene_count(out->scene, SY_TYPE_MESH),
               sy_scene_count(out->scene, SY_TYPE_MATERIAL), sy_scene_count(out->scene, SY_TYPE_LIGHT),
               sy_scene_count(out->scene, SY_TYPE_CAMERA));
    return r;
}

sy_animation sy_cli_default_clip(const loaded *ld)
{
    sy_animation every = {0}, first = {sy_scene_next(ld->scene, SY_TYPE_ANIMATION, 0)};
    if (!(ld->is_gltf || ld->is_assimp) || sy_scene_count(ld->scene, SY_TYPE_ANIMATION) < 2) return every;
    size_t n = 0, cap = 0;
    sy_u32_pair *ct = NULL; /* (target, clip) pairs, by target: two clips drive one object when one target has two */
    for (uint32_t id = first.id; id; id = sy_scene_next(ld->scene, SY_TYPE_ANIMATION, id)) {
        uint32_t nch = 0;
        const sy_anim_channel *ch = sy_animation_channels(sy_animation_get(ld->scene, (sy_animation){id}), &nch);
        if (n + nch > cap) {
            size_t nc = (n + nch) * 2;
            sy_u32_pair *g = realloc(ct, nc * sizeof *g);
            if (!g) {
                free(ct);
                return first; /* out of memory: the safe choice */
            }
            ct = g, cap = nc;
        }
        for (uint32_t k = 0; k < nch; ++k) ct[n++] = (sy_u32_pair){ch[k].node, id};
    }
    qsort(ct, n, sizeof *ct, sy_u32_pair_cmp);
    bool shared = false;
    for (size_t k = 1; k < n && !shared; ++k) shared = ct[k].key == ct[k - 1].key && ct[k].value != ct[k - 1].value;
    free(ct);
    return shared ? first : every;
}

int sy_cli_set_time(loaded *ld, const char *clip, double seconds, sy_error *err)
{
    sy_animation a = sy_cli_default_clip(ld);
    if (!sy_scene_count(ld->scene, SY_TYPE_ANIMATION)) {
        if (clip) {
            fprintf(stderr, "sy render: error: --clip %s: the scene has no animations\n", clip);
            return 2;
        }
        sy_log(SY_LOG_NOTE, "sy", NULL, "--at %g: the scene has no animations; it is shown as loaded", seconds);
        return 0;
    }
    if (clip) {
        sy_error fe = {0};
        if (sy_animation_find(ld->scene, clip, &a, &fe) != SY_OK) {
            fprintf(stderr, "sy render: error: --clip %s: %s\n", clip, fe.message);
            return 2;
        }
    } else if (a.id && !ld->clip_noted) {
        const sy_animation_data *d = sy_animation_get(ld->scene, a);
        sy_log(SY_LOG_NOTE, "sy", NULL, "playing clip 0 (%s) of %u; --clip NAME|INDEX plays another",
               d && d->name ? d->name : "unnamed", sy_scene_count(ld->scene, SY_TYPE_ANIMATION));
        ld->clip_noted = true;
    }
    sy_anim_stats st;
    if (sy_scene_set_time_ex(ld->scene, a, seconds, &st, err) != SY_OK || sy_scene_commit(ld->scene, NULL, err) != SY_OK)
        return 1;
    sy_log(SY_LOG_DEBUG, "sy", NULL, "--at %g: %u clip(s), %u channels evaluated (%u morph weight channels not yet)", seconds,
           st.clips, st.channels, st.weights);
    return 0;
}

/* X3D Viewpoint fieldOfView covers the smaller image side: adapt yfov to the output size. */
void sy_cli_default_size(const loaded *ld, uint32_t *w, uint32_t *h)
{
    float aspect = 1.0f;
    const sy_node_data *cn = ld->camera.id ? sy_node_get(ld->scene, ld->camera) : NULL;
    const sy_camera_data *cd = cn ? sy_camera_get(ld->scene, cn->camera) : NULL;
    if (cd && cd->aspect > 0) aspect = cd->aspect;
    if (ld->camera.id == 0 && !ld->is_gltf) aspect = 1.0f;
    if (!*w && !*h) *h = 512, *w = (uint32_t)lroundf(512 * aspect);
    else if (!*w) *w = (uint32_t)lroundf((float)*h * aspect);
    else if (!*h) *h = (uint32_t)lroundf((float)*w / aspect);
    if (!*w) *w = 1;
    if (!*h) *h = 1;
}

void sy_cli_fit_x3d_cameras(loaded *ld, uint32_t w, uint32_t h)
{
    sy_error e = {0};
    if (sy_cli_load_opts.view.fov > 0) return; /* --fov: the user's vertical angle stands */
    if (sy_x3d_fit_cameras(ld->scene, &ld->x3d, (float)w / (float)h, &e) != SY_OK ||
        sy_scene_commit(ld->scene, NULL, &e) != SY_OK)
        sy_log(SY_LOG_WARNING, "sy", NULL, "viewpoint field of view not adapted: %s", e.message);
}

/* --overlay FILE[:BACKEND]: loads FILE into the same scene under its own root and layers it over
 * the main viewport with the --composite mode (depth, over, replace). */
sy_result sy_cli_add_overlay(loaded *ld, const char *arg, const char *composite, sy_compose_spec *spec, sy_error *err)
{
    char path[4096];
    const char *colon = strrchr(arg, ':');
    const char *backend = colon && colon[1] && !strchr(colon, '/') ? colon + 1 : NULL;
    size_t n = backend ? (size_t)(colon - arg) : strlen(arg);
    if (n >= sizeof path) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "--overlay: path too long");
    memcpy(path, arg, n);
    path[n] = '\0';
    if (!strcmp(composite, "depth")) spec->overlay_composite = SY_COMPOSITE_DEPTH;
    else if (!strcmp(composite, "over")) spec->overlay_composite = SY_COMPOSITE_ALPHA_OVER;
    else if (!strcmp(composite, "replace")) spec->overlay_composite = SY_COMPOSITE_REPLACE;
    else return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "--composite %s: expected depth, over or replace", composite);
    if (!backend) backend = sy_mediator_find("raster") ? "raster" : spec->backend;
    if (!sy_mediator_find(backend)) return sy_error_set(err, SY_ERR_NOT_FOUND, "--overlay %s: back-end '%s' is not registered", arg, backend);
    sy_gltf_info info = {0};
    sy_gltf_options go = {.allowed_roots = sy_cli_load_opts.roots, .allowed_root_count = sy_cli_load_opts.root_count,
                          .max_scene_bytes = sy_cli_load_opts.max_scene_bytes};
    sy_result r = sy_gltf_load(path, ld->scene, &go, &info, err);
    if (r == SY_OK) r = report_warnings(path, info.warning_count, err);
    if (r == SY_OK) r = sy_scene_commit(ld->scene, NULL, err);
    if (r != SY_OK) {
        sy_gltf_info_free(&info);
        sy_error_prefix(err, "overlay");
        return r;
    }
    spec->has_overlay = true;
    spec->overlay_root = info.root;
    spec->overlay_backend = backend;
    sy_gltf_info_free(&info);
    return SY_OK;
}

const char *sy_cli_bookmarks_file(const char *scene, const char *given, char **owned)
{
    *owned = NULL;
    if (given) return given;
    if (!strcmp(scene, "demo") || !(*owned = malloc(strlen(scene) + sizeof ".bookmarks"))) return NULL;
    sprintf(*owned, "%s.bookmarks", scene);
    return *owned;
}
