/* sy_main.c — the `sy` command line tool: info, render, demo, bench, backends.
 *
 *   sy info SCENE                       JSON summary (counts, bounds) of a glTF file
 *   sy render SCENE -b BACKEND -o OUT.exr|png [-w W] [-h H] [--camera NAME|INDEX]
 *             [--params k=v,...] [--half] [--exposure EV] [--tonemap clamp|reinhard|aces]
 *   sy demo [-o DIR] [-w W] [-h H]      render the built-in demo scene with every back-end
 *   sy bench sync [--nodes N] [--tris T] [--repeats R]
 *   sy bench rays [SCENE] [-w W] [-h H] [--repeats R]
 *   sy backends                         list registered back-ends
 *
 * SCENE is a .gltf / .glb file or the word "demo" (the built-in scene). Errors go to stderr with
 * the file and the reason; the exit code is non-zero (1 = usage, 2 = failure). */
#include "sy_bench.h"
#include "sy_compose.h"
#include "sy_demo.h"
#include "sy_exr.h"
#include "sy_gltf.h"
#include "sy_mediators.h"
#include "sy_png.h"
#include "sy_viewport.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

/* >>loading */
typedef struct loaded {
    sy_scene *scene;
    sy_node root;
    sy_node camera; /* {0}: frame the bounds */
    sy_background background;
    sy_gltf_info gltf;
    bool is_gltf;
} loaded;

static void loaded_free(loaded *l)
{
    sy_gltf_info_free(&l->gltf);
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
    bool emissive = false;
    for (uint32_t id = sy_scene_next(s, SY_TYPE_MATERIAL, 0); id && !emissive; id = sy_scene_next(s, SY_TYPE_MATERIAL, id)) {
        const sy_material_data *m = sy_object_get(s, SY_TYPE_MATERIAL, id);
        emissive = m->emissive_strength * (m->emissive[0] + m->emissive[1] + m->emissive[2]) > 0.0f;
    }
    if (sy_scene_count(s, SY_TYPE_LIGHT) == 0 && !emissive) {
        fprintf(stderr, "sy: note: the scene has no lights; adding a directional headlight\n");
        sy_light l;
        sy_node n;
        sy_light_data ld2 = *(const sy_light_data *)sy_object_defaults(SY_TYPE_LIGHT);
        ld2.type = SY_LIGHT_DIRECTIONAL;
        ld2.intensity = 3.0f;
        /* under the root (identity for glTF), so the mediator's root filter sees it */
        if ((r = sy_light_create(s, "headlight", &l, err)) || (r = sy_light_set(s, l, &ld2, err)) ||
            (r = sy_node_create(s, "headlight", &n, err)) || (r = sy_node_set_matrix(s, n, &cam_world, err)) ||
            (r = sy_node_set_light(s, n, l, err)) || (r = sy_node_add_child(s, ld->root, n, err)))
            return r;
    }
    return sy_scene_commit(s, NULL, err);
}

static sy_result load(const char *path, const char *camera_sel, bool defaults, loaded *out, sy_error *err)
{
    memset(out, 0, sizeof *out);
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
    } else {
        out->is_gltf = true;
        r = sy_gltf_load(path, out->scene, NULL, &out->gltf, err);
        if (r == SY_OK) {
            out->root = out->gltf.root;
            if (camera_sel) r = sy_gltf_find_camera(out->scene, &out->gltf, camera_sel, &out->camera, err);
            else if (out->gltf.camera_node_count) out->camera = out->gltf.camera_nodes[0];
            if (r != SY_OK) sy_error_prefix(err, "%s", path);
        }
    }
    if (r == SY_OK) r = sy_scene_commit(out->scene, NULL, err);
    if (r == SY_OK && out->is_gltf && defaults) r = add_defaults(out, err);
    if (r != SY_OK) loaded_free(out);
    return r;
}

/* >>progress (terminal only) */
typedef struct progress_state {
    const char *label;
    double start, last_print;
    bool tty;
} progress_state;

static void progress_cb(void *user, const sy_progress *p)
{
    progress_state *ps = user;
    if (!ps->tty || p->total == 0) return;
    double now = sy_time_now();
    if (p->done != p->total && now - ps->last_print < 0.1) return;
    ps->last_print = now;
    double el = now - ps->start, frac = (double)p->done / (double)p->total;
    double eta = frac > 0 ? el / frac - el : 0;
    fprintf(stderr, "\r%s: %llu/%llu tiles (%3.0f%%) %.1f s, ETA %.1f s   ", ps->label, (unsigned long long)p->done,
            (unsigned long long)p->total, frac * 100.0, el, eta);
    if (p->done == p->total) fprintf(stderr, "\r%*s\r", 70, "");
    fflush(stderr);
}

/* >>output */
static bool ends_with(const char *s, const char *suffix)
{
    size_t n = strlen(s), m = strlen(suffix);
    return n >= m && strcasecmp(s + n - m, suffix) == 0;
}

typedef struct out_opts {
    bool half;
    sy_png_options png;
} out_opts;

static sy_result write_image(const char *path, const sy_layer *l, const out_opts *o, sy_error *err)
{
    if (ends_with(path, ".exr"))
        return sy_exr_write_rgba(path, (int)l->width, (int)l->height, l->rgba, l->depth,
                                 o->half ? SY_EXR_PIXEL_HALF : SY_EXR_PIXEL_FLOAT, err);
    if (ends_with(path, ".png")) return sy_png_write(path, (int)l->width, (int)l->height, l->rgba, &o->png, err);
    return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: output must end in .exr or .png", path);
}

/* Renders one mono viewport of the whole window with the given back-end. */
static sy_result render_scene(loaded *ld, const char *backend, const char *params, uint32_t w, uint32_t h,
                              sy_context_pool *pool, sy_layer *out, double *seconds, sy_error *err)
{
    sy_window *win = NULL;
    sy_viewport *vp;
    sy_result r = sy_window_create(w, h, &win, err);
    sy_viewport_desc vd = {
        .root = ld->root, .camera = ld->camera, .background = ld->background, .backend = backend, .params = params};
    if (r == SY_OK) r = sy_window_add_viewport(win, &vd, &vp, err);
    if (r == SY_OK) r = sy_layer_create(w, h, out, err);
    progress_state ps = {backend, sy_time_now(), 0, sy_is_terminal(2)};
    sy_window_render_opts ro = {.progress = progress_cb, .progress_user = &ps};
    double t0 = sy_time_now();
    if (r == SY_OK) r = sy_window_render(win, ld->scene, pool, &ro, out, err);
    *seconds = sy_time_now() - t0;
    sy_window_destroy(win);
    return r;
}

/* >>commands */
static int fail(const sy_error *e)
{
    fprintf(stderr, "sy: error: %s\n", e->message);
    return 2;
}

static int usage(void)
{
    fprintf(stderr,
            "usage:\n"
            "  sy info SCENE\n"
            "  sy render SCENE -b BACKEND -o OUT.exr|png [-w W] [-h H] [--camera NAME|INDEX]\n"
            "            [--params k=v,...] [--half] [--exposure EV] [--tonemap clamp|reinhard|aces]\n"
            "            [--stereo sbs|tb|anaglyph|separate] [--eye-sep M] [--zero-parallax M]\n"
            "            [--overlay FILE[:BACKEND]] [--composite depth|over|replace]\n"
            "  sy demo [-o DIR] [-w W] [-h H]\n"
            "  sy bench sync [--nodes N] [--tris T] [--repeats R]\n"
            "  sy bench rays [SCENE] [-w W] [-h H] [--repeats R]\n"
            "  sy bench viewports [-w W] [-h H] [--repeats R]\n"
            "  sy backends\n"
            "SCENE: a .gltf/.glb file, or 'demo' for the built-in scene\n");
    return 1;
}

static bool parse_u32(const char *s, uint32_t lo, uint32_t hi, uint32_t *out)
{
    char *end;
    errno = 0;
    unsigned long v = strtoul(s, &end, 10);
    if (errno || end == s || *end || v < lo || v > hi) return false;
    *out = (uint32_t)v;
    return true;
}

static void json_string(FILE *f, const char *s)
{
    fputc('"', f);
    for (; s && *s; ++s) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\') fprintf(f, "\\%c", c);
        else if (c < 0x20) fprintf(f, "\\u%04x", c);
        else fputc(c, f);
    }
    fputc('"', f);
}

static int cmd_info(int argc, char **argv)
{
    if (argc != 1) return usage();
    sy_error err = {0};
    loaded ld;
    if (load(argv[0], NULL, false, &ld, &err) != SY_OK) return fail(&err);
    sy_bounds b;
    sy_node_world_bounds(ld.scene, ld.root, &b, NULL);
    /* counts of what was loaded into the scene (less the synthetic root node) */
    uint32_t prims = 0, tris = 0;
    for (uint32_t id = sy_scene_next(ld.scene, SY_TYPE_MESH, 0); id; id = sy_scene_next(ld.scene, SY_TYPE_MESH, id)) {
        const sy_mesh_data *m = sy_object_get(ld.scene, SY_TYPE_MESH, id);
        prims += m->primitives.count;
        for (uint32_t i = 0; i < m->primitives.count; ++i) tris += sy_primitive_triangle_count(&m->primitives.items[i]);
    }
    printf("{\n  \"file\": ");
    json_string(stdout, argv[0]);
    if (ld.is_gltf) {
        const sy_gltf_counts *c = &ld.gltf.counts;
        printf(",\n  \"nodes\": %u,\n  \"meshes\": %u,\n  \"primitives\": %u,\n  \"triangles\": %u,\n"
               "  \"materials\": %u,\n  \"textures\": %u,\n  \"images\": %u,\n  \"lights\": %u,\n  \"cameras\": %u",
               c->nodes, c->meshes, c->primitives, c->triangles, c->materials, c->textures, c->images, c->lights,
               c->cameras);
    }
    printf(",\n  \"loaded\": {\"nodes\": %u, \"meshes\": %u, \"primitives\": %u, \"triangles\": %u, \"materials\": %u, "
           "\"textures\": %u, \"lights\": %u, \"cameras\": %u}",
           sy_scene_count(ld.scene, SY_TYPE_NODE) - 1, sy_scene_count(ld.scene, SY_TYPE_MESH), prims, tris,
           sy_scene_count(ld.scene, SY_TYPE_MATERIAL), sy_scene_count(ld.scene, SY_TYPE_TEXTURE),
           sy_scene_count(ld.scene, SY_TYPE_LIGHT), sy_scene_count(ld.scene, SY_TYPE_CAMERA));
    if (sy_bounds_is_empty(&b)) printf(",\n  \"bounds\": null");
    else
        printf(",\n  \"bounds\": {\"min\": [%.9g, %.9g, %.9g], \"max\": [%.9g, %.9g, %.9g]}", (double)b.min[0],
               (double)b.min[1], (double)b.min[2], (double)b.max[0], (double)b.max[1], (double)b.max[2]);
    printf(",\n  \"warnings\": [");
    for (uint32_t i = 0; i < ld.gltf.stored_warning_count; ++i) {
        printf(i ? ", " : "");
        json_string(stdout, ld.gltf.warnings[i]);
    }
    printf("]\n}\n");
    loaded_free(&ld);
    return 0;
}

/* NAME.EXT -> NAME_left.EXT and NAME_right.EXT */
static sy_result eye_paths(const char *outp, char *lp, char *rp, size_t n, sy_error *err)
{
    const char *dot = strrchr(outp, '.');
    size_t stem = dot ? (size_t)(dot - outp) : strlen(outp);
    if ((size_t)snprintf(lp, n, "%.*s_left%s", (int)stem, outp, dot ? dot : "") >= n ||
        (size_t)snprintf(rp, n, "%.*s_right%s", (int)stem, outp, dot ? dot : "") >= n)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: path too long", outp);
    return SY_OK;
}

/* --overlay FILE[:BACKEND]: loads FILE into the same scene under its own root and layers it over
 * the main viewport with the --composite mode (depth, over, replace). */
static sy_result add_overlay(loaded *ld, const char *arg, const char *composite, sy_compose_spec *spec, sy_error *err)
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
    sy_result r = sy_gltf_load(path, ld->scene, NULL, &info, err);
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

static int cmd_render(int argc, char **argv)
{
    const char *scene = NULL, *backend = NULL, *outp = NULL, *camera = NULL, *params = NULL;
    const char *overlay = NULL, *composite = "depth";
    uint32_t w = 0, h = 0;
    out_opts oo = {0};
    sy_compose_spec spec = {.eye_separation = 0.065f, .zero_parallax = 2.0f};
    sy_error perr = {0};
    for (int i = 0; i < argc; ++i) {
        const char *a = argv[i];
        bool has = i + 1 < argc;
        if (!strcmp(a, "-b") && has) backend = argv[++i];
        else if (!strcmp(a, "-o") && has) outp = argv[++i];
        else if (!strcmp(a, "-w") && has) {
            if (!parse_u32(argv[++i], 1, 16384, &w)) return usage();
        } else if (!strcmp(a, "-h") && has) {
            if (!parse_u32(argv[++i], 1, 16384, &h)) return usage();
        } else if (!strcmp(a, "--camera") && has) camera = argv[++i];
        else if (!strcmp(a, "--params") && has) params = argv[++i];
        else if (!strcmp(a, "--half")) oo.half = true;
        else if (!strcmp(a, "--exposure") && has) oo.png.exposure_stops = strtof(argv[++i], NULL);
        else if (!strcmp(a, "--tonemap") && has) {
            const char *t = argv[++i];
            oo.png.tonemap = !strcmp(t, "aces") ? SY_TONEMAP_ACES : !strcmp(t, "reinhard") ? SY_TONEMAP_REINHARD
                                                                                           : SY_TONEMAP_CLAMP;
        } else if (!strcmp(a, "--stereo") && has) {
            if (sy_stereo_mode_parse(argv[++i], &spec.stereo, &perr) != SY_OK) return fail(&perr);
        } else if (!strcmp(a, "--eye-sep") && has) spec.eye_separation = strtof(argv[++i], NULL);
        else if (!strcmp(a, "--zero-parallax") && has) spec.zero_parallax = strtof(argv[++i], NULL);
        else if (!strcmp(a, "--overlay") && has) overlay = argv[++i];
        else if (!strcmp(a, "--composite") && has) composite = argv[++i];
        else if (a[0] != '-' && !scene) scene = a;
        else {
            fprintf(stderr, "sy render: unknown or incomplete option '%s'\n", a);
            return usage();
        }
    }
    if (!scene || !backend || !outp) return usage();
    sy_error err = {0};
    if (!ends_with(outp, ".exr") && !ends_with(outp, ".png")) { /* before any loading or rendering */
        sy_error_set(&err, SY_ERR_INVALID_ARGUMENT, "%s: output must end in .exr or .png", outp);
        return fail(&err);
    }
    loaded ld;
    if (load(scene, camera, true, &ld, &err) != SY_OK) return fail(&err);
    /* default size: 512 high, width from the camera's aspect ratio when it has one */
    float aspect = 1.0f;
    const sy_node_data *cn = ld.camera.id ? sy_node_get(ld.scene, ld.camera) : NULL;
    const sy_camera_data *cd = cn ? sy_camera_get(ld.scene, cn->camera) : NULL;
    if (cd && cd->aspect > 0) aspect = cd->aspect;
    if (ld.camera.id == 0 && !ld.is_gltf) aspect = 1.0f;
    if (!w && !h) h = 512, w = (uint32_t)lroundf(512 * aspect);
    else if (!w) w = (uint32_t)lroundf((float)h * aspect);
    else if (!h) h = (uint32_t)lroundf((float)w / aspect);
    if (!w) w = 1;
    if (!h) h = 1;
    sy_context_pool *pool = NULL;
    sy_layer img = {0}, img_right = {0};
    double secs = 0;
    spec.backend = backend;
    spec.params = params;
    spec.root = ld.root;
    spec.camera = ld.camera;
    spec.background = ld.background;
    sy_result r = overlay ? add_overlay(&ld, overlay, composite, &spec, &err) : SY_OK;
    if (r == SY_OK) r = sy_context_pool_create(&pool, &err);
    progress_state ps = {backend, sy_time_now(), 0, sy_is_terminal(2)};
    sy_window_render_opts ro = {.progress = progress_cb, .progress_user = &ps};
    double t0 = sy_time_now();
    if (r == SY_OK) r = sy_compose_render(ld.scene, pool, &spec, w, h, &ro, &img, &img_right, &err);
    secs = sy_time_now() - t0;
    if (r == SY_OK) {
        size_t bad = sy_layer_count_nonfinite(&img) + (img_right.rgba ? sy_layer_count_nonfinite(&img_right) : 0);
        if (bad) fprintf(stderr, "sy render: warning: %zu pixels are not finite\n", bad);
        if (spec.stereo == SY_STEREO_SEPARATE) {
            char lp[4096], rp[4096];
            r = eye_paths(outp, lp, rp, sizeof lp, &err);
            if (r == SY_OK) r = write_image(lp, &img, &oo, &err);
            if (r == SY_OK) r = write_image(rp, &img_right, &oo, &err);
            if (r == SY_OK) printf("%s, %s: %ux%u per eye, %s, %.3f s\n", lp, rp, w, h, backend, secs);
        } else {
            r = write_image(outp, &img, &oo, &err);
            if (r == SY_OK) printf("%s: %ux%u, %s, %.3f s\n", outp, img.width, img.height, backend, secs);
        }
    }
    sy_layer_destroy(&img);
    sy_layer_destroy(&img_right);
    sy_context_pool_destroy(pool);
    loaded_free(&ld);
    return r == SY_OK ? 0 : fail(&err);
}

static int cmd_demo(int argc, char **argv)
{
    const char *dir = "out";
    uint32_t w = 800, h = 450;
    for (int i = 0; i < argc; ++i) {
        bool has = i + 1 < argc;
        if (!strcmp(argv[i], "-o") && has) dir = argv[++i];
        else if (!strcmp(argv[i], "-w") && has) {
            if (!parse_u32(argv[++i], 1, 16384, &w)) return usage();
        } else if (!strcmp(argv[i], "-h") && has) {
            if (!parse_u32(argv[++i], 1, 16384, &h)) return usage();
        } else return usage();
    }
    if (mkdir(dir, 0777) != 0 && errno != EEXIST) {
        fprintf(stderr, "sy: error: %s: cannot create directory: %s\n", dir, strerror(errno));
        return 2;
    }
    sy_error err = {0};
    loaded ld;
    if (load("demo", NULL, true, &ld, &err) != SY_OK) return fail(&err);
    sy_context_pool *pool = NULL;
    sy_result r = sy_context_pool_create(&pool, &err);
    printf("demo scene: %u nodes, %u meshes, %u materials, %ux%u\n", sy_scene_count(ld.scene, SY_TYPE_NODE),
           sy_scene_count(ld.scene, SY_TYPE_MESH), sy_scene_count(ld.scene, SY_TYPE_MATERIAL), w, h);
    for (uint32_t i = 0; i < sy_mediator_count() && r == SY_OK; ++i) {
        const char *name = sy_mediator_at(i)->name;
        sy_layer img = {0};
        double secs = 0;
        r = render_scene(&ld, name, NULL, w, h, pool, &img, &secs, &err);
        char png[1024], exr[1024];
        snprintf(png, sizeof png, "%s/demo_%s.png", dir, name);
        snprintf(exr, sizeof exr, "%s/demo_%s.exr", dir, name);
        out_opts oo = {.png = {.tonemap = SY_TONEMAP_ACES}};
        if (r == SY_OK) r = write_image(png, &img, &oo, &err);
        if (r == SY_OK) r = write_image(exr, &img, &oo, &err);
        if (r == SY_OK) printf("  %-12s %8.3f s  %s  %s\n", name, secs, png, exr);
        sy_layer_destroy(&img);
    }
    sy_context_pool_destroy(pool);
    loaded_free(&ld);
    return r == SY_OK ? 0 : fail(&err);
}

static int cmd_backends(void)
{
    for (uint32_t i = 0; i < sy_mediator_count(); ++i) {
        const sy_mediator_class *c = sy_mediator_at(i);
        printf("%s%s%s%s\n", c->name, (c->caps & SY_CAP_DEPTH) ? " depth" : "",
               (c->caps & SY_CAP_PROGRESSIVE) ? " progressive" : "", (c->caps & SY_CAP_TILES) ? " tiles" : "");
    }
    return 0;
}

static int cmd_bench(int argc, char **argv)
{
    if (argc < 1) return usage();
    uint32_t nodes = 10000, tris = 100, repeats = 0, w = 512, h = 512;
    const char *scene = NULL;
    for (int i = 1; i < argc; ++i) {
        bool has = i + 1 < argc;
        if (!strcmp(argv[i], "--nodes") && has) {
            if (!parse_u32(argv[++i], 1, 1u << 22, &nodes)) return usage();
        } else if (!strcmp(argv[i], "--tris") && has) {
            if (!parse_u32(argv[++i], 12, 1u << 20, &tris)) return usage();
        } else if (!strcmp(argv[i], "--repeats") && has) {
            if (!parse_u32(argv[++i], 1, 100000, &repeats)) return usage();
        } else if (!strcmp(argv[i], "-w") && has) {
            if (!parse_u32(argv[++i], 1, 16384, &w)) return usage();
        } else if (!strcmp(argv[i], "-h") && has) {
            if (!parse_u32(argv[++i], 1, 16384, &h)) return usage();
        } else if (argv[i][0] != '-' && !scene) scene = argv[i];
        else return usage();
    }
    sy_error err = {0};
    if (!strcmp(argv[0], "sync")) return sy_bench_sync(nodes, tris, repeats ? repeats : 50, &err) == SY_OK ? 0 : fail(&err);
    if (!strcmp(argv[0], "viewports"))
        return sy_bench_viewports(w == 512 ? 480 : w, h == 512 ? 270 : h, repeats ? repeats : 5, &err) == SY_OK
                   ? 0
                   : fail(&err);
    if (!strcmp(argv[0], "rays")) {
        loaded ld;
        if (load(scene ? scene : "demo", NULL, true, &ld, &err) != SY_OK) return fail(&err);
        sy_viewport_desc vd = {.root = ld.root, .camera = ld.camera, .backend = "whitted"};
        sy_result r = sy_bench_rays(ld.scene, &vd, w, h, repeats ? repeats : 5, &err);
        loaded_free(&ld);
        return r == SY_OK ? 0 : fail(&err);
    }
    return usage();
}

int main(int argc, char **argv)
{
    sy_error err = {0};
    if (sy_mediators_register_builtin(&err) != SY_OK) return fail(&err);
    if (argc < 2) return usage();
    const char *cmd = argv[1];
    if (!strcmp(cmd, "info")) return cmd_info(argc - 2, argv + 2);
    if (!strcmp(cmd, "render")) return cmd_render(argc - 2, argv + 2);
    if (!strcmp(cmd, "demo")) return cmd_demo(argc - 2, argv + 2);
    if (!strcmp(cmd, "bench")) return cmd_bench(argc - 2, argv + 2);
    if (!strcmp(cmd, "backends")) return cmd_backends();
    if (!strcmp(cmd, "--help") || !strcmp(cmd, "help")) {
        usage();
        return 0;
    }
    fprintf(stderr, "sy: unknown command '%s'\n", cmd);
    return usage();
}
