/* sy_bench_cull.c — `sy bench cull` (see sy_bench_cull.h): the culling service against the full
 * raster render on the generated plant, and geometry streaming against video streaming. */
#include "sy_bench_cull.h"

#include "sy_bench.h"
#include "sy_cull.h"
#include "sy_gltf_write.h"
#include "sy_jpeg.h"
#include "sy_load.h"
#include "sy_png.h"
#include "sy_plant.h"
#include "sy_viewport.h"

#include "sy_cli.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>


static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* >>the path: along the plant's free corridor nearest its centre (sy_plant_info.corridor_x), at 8 m
 * (above the pipe racks, below the tanks' tops) looking along it and to both sides, then rising to
 * 100 m and pitching down over the plant, where far more is visible than the budget; view i of n. */
static double smooth(double e0, double e1, double x)
{
    double t = (x - e0) / (e1 - e0);
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    return t * t * (3 - 2 * t);
}

static void path_view(const sy_plant_info *pi, uint32_t i, uint32_t n, uint32_t w, uint32_t h, sy_cull_view *v)
{
    const double deg = 3.14159265358979 / 180.0;
    double t = n > 1 ? (double)i / (double)(n - 1) : 0.0;
    double z0 = pi->bounds.min[2] + 0.3 * (pi->bounds.max[2] - pi->bounds.min[2]);
    double z1 = pi->bounds.min[2] + 0.6 * (pi->bounds.max[2] - pi->bounds.min[2]);
    double rise = smooth(0.5, 1.0, t);
    double y = 8.0 + 92.0 * rise, pitch = (-10.0 - 30.0 * rise) * deg;
    double yaw = (180.0 + 35.0 * sin(2.0 * 3.14159265358979 * 1.25 * t)) * deg; /* 180: looking along +z */
    /* q = yaw about +Y, then pitch about +X (the camera looks down its -Z) */
    double cy = cos(0.5 * yaw), sy = sin(0.5 * yaw), cp = cos(0.5 * pitch), sp = sin(0.5 * pitch);
    *v = (sy_cull_view){{pi->corridor_x, y, z0 + (z1 - z0) * t}, {cy * sp, sy * cp, -sy * sp, cy * cp}, 60.0, w, h};
}

/* Mask of covered pixels (finite depth). */
static uint64_t mask_of(const sy_layer *l, uint8_t *mask)
{
    uint64_t n = 0;
    for (size_t i = 0; i < (size_t)l->width * l->height; ++i) n += mask[i] = isfinite(l->depth[i]) ? 1 : 0;
    return n;
}

static double iou(const uint8_t *a, const uint8_t *b, size_t n)
{
    uint64_t in = 0, un = 0;
    for (size_t i = 0; i < n; ++i) in += a[i] & b[i], un += a[i] | b[i];
    return un ? (double)in / (double)un : 1.0;
}

/* JPEG bytes of the layer (sRGB over black, clamped, quality 80: what sy web streams), 0 on failure. */
static size_t jpeg_bytes(const sy_layer *l, uint8_t *rgba8, double *seconds)
{
    double t0 = now_s();
    const sy_png_options clamp = {.tonemap = SY_TONEMAP_CLAMP};
    sy_png_encode_over_black(l->rgba, (size_t)l->width * l->height, &clamp, rgba8);
    uint8_t *jpg = NULL;
    size_t size = 0;
    sy_error err = {0};
    sy_result r = sy_jpeg_encode_rgba8(rgba8, l->width, l->height, 80, &jpg, &size, &err);
    free(jpg);
    *seconds = now_s() - t0;
    return r == SY_OK ? size : 0;
}

static int cmp_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return x < y ? -1 : x > y;
}

static sy_result set_camera(sy_scene *s, sy_node cam, const sy_cull_view *v, sy_error *err)
{
    float t[3] = {(float)v->position[0], (float)v->position[1], (float)v->position[2]};
    float q[4] = {(float)v->orientation[0], (float)v->orientation[1], (float)v->orientation[2], (float)v->orientation[3]};
    float one[3] = {1, 1, 1};
    return sy_node_set_trs(s, cam, t, q, one, err);
}

/* Every object of the plant visible (keep = NULL) or only the kept ids (sorted). */
static sy_result set_visible(sy_scene *s, const uint32_t *objs, uint32_t n, const uint32_t *keep, uint32_t kept,
                             uint8_t *state, sy_error *err)
{
    for (uint32_t i = 0; i < n; ++i) {
        uint8_t want = !keep || bsearch(&objs[i], keep, kept, sizeof *keep, cmp_u32) ? 1 : 0;
        if (state[i] == want) continue;
        sy_result r = sy_node_set_flags(s, (sy_node){objs[i]}, want ? SY_NODE_VISIBLE : 0, err);
        if (r != SY_OK) return r;
        state[i] = want;
    }
    return sy_scene_commit(s, NULL, err);
}

typedef struct fetched_set {
    uint32_t *ids;
    uint32_t count;
} fetched_set;

static int run_bench(uint64_t tris, uint32_t objects, uint64_t budget, uint32_t w, uint32_t h, uint32_t frames,
                     uint32_t seed, const char *write_path)
{
    sy_error err = {0};
    sy_scene *s = NULL;
    sy_context_pool *pool = NULL;
    sy_culler *cul = NULL;
    sy_window *win = NULL;
    sy_layer full = {0}, part = {0};
    uint8_t *ma = NULL, *mb = NULL, *rgb = NULL, *state = NULL;
    uint32_t *keep = NULL;
    fetched_set fetched = {0};
    double *ious = NULL, *qtimes = NULL, *rfull = NULL, *rpart = NULL;
    bool tty = isatty(STDERR_FILENO);
    sy_plant_info pi;
    loaded ld = {0}; /* the plant through a .glb: ld.scene replaces s */
    double t0 = now_s();
    sy_result r = sy_scene_create(&s, &err);
    if (r == SY_OK) r = sy_plant_generate(s, &(sy_plant_desc){.triangles = tris, .objects = objects, .seed = seed}, &pi, &err);
    if (r == SY_OK) r = sy_scene_commit(s, NULL, &err);
    double t_gen = now_s() - t0;
    if (r != SY_OK) goto done;
    printf("sy bench cull: plant of %u objects, %llu triangles (%u shared meshes, %u x %u units of %.0f m), generated in %.2f s\n",
           pi.objects, (unsigned long long)pi.triangles, pi.meshes, pi.grid, pi.grid, pi.cell, t_gen);
    if (write_path) {
        t0 = now_s();
        r = sy_gltf_write_subtree_file(s, pi.root, &(sy_gltf_write_options){.generator = "sy bench cull"}, write_path, &err);
        if (r == SY_OK) printf("wrote %s in %.2f s (serve it: sy web %s --client-render)\n", write_path, now_s() - t0, write_path);
        goto done;
    }
    /* the user's path (issue 39): the plant written to a .glb and loaded as sy render and sy web load
     * it; the measurements run on that copy (its root's children are the plant's objects) */
    t0 = now_s();
    if ((r = sy_bench_reload_glb(s, pi.root, NULL, "sy bench cull", &ld, NULL, &err)) != SY_OK) goto done;
    sy_scene_destroy(s);
    s = ld.scene, pi.root = ld.root;
    printf("written to a .glb and loaded by sy_cli_load in %.2f s: the measurements below run on the file's copy\n",
           now_s() - t0);
    /* the service and the raster window: the plant's objects, a camera node outside the plant */
    t0 = now_s();
    if ((r = sy_context_pool_create(&pool, &err)) == SY_OK) r = sy_culler_create(s, pool, pi.root, NULL, &cul, &err);
    double t_cov = now_s() - t0;
    sy_node cam_node;
    sy_camera cam;
    sy_camera_data cd = *(const sy_camera_data *)sy_object_defaults(SY_TYPE_CAMERA);
    cd.projection = SY_PROJECTION_PERSPECTIVE, cd.yfov = (float)(60.0 * 3.14159265358979 / 180.0), cd.znear = 0.05f;
    cd.zfar = 0, cd.aspect = 0;
    if (r == SY_OK) r = sy_camera_create(s, "bench camera", &cam, &err);
    if (r == SY_OK) r = sy_camera_set(s, cam, &cd, &err);
    if (r == SY_OK) r = sy_node_create(s, "bench camera", &cam_node, &err);
    if (r == SY_OK) r = sy_node_set_camera(s, cam_node, cam, &err);
    if (r == SY_OK) r = sy_node_set_flags(s, cam_node, SY_NODE_VISIBLE, &err);
    if (r == SY_OK) r = sy_scene_commit(s, NULL, &err);
    if (r == SY_OK) r = sy_window_create(w, h, &win, &err);
    if (r == SY_OK) {
        r = sy_window_add_viewport(win, &(sy_viewport_desc){.root = pi.root, .camera = cam_node, .backend = "raster"}, NULL, &err);
        if (r != SY_OK) sy_error_prefix(&err, "bench cull: the renders to compare need the raster back-end (SY_WITH_RASTER)");
    }
    if (r == SY_OK) r = sy_layer_create(w, h, &full, &err);
    if (r == SY_OK) r = sy_layer_create(w, h, &part, &err);
    uint32_t nobj = 0;
    const uint32_t *objs = sy_node_children(sy_node_get(s, pi.root), &nobj);
    size_t npx = (size_t)w * h;
    ma = malloc(npx), mb = malloc(npx), rgb = malloc(npx * 4), state = malloc(nobj ? nobj : 1);
    fetched.ids = calloc(nobj ? nobj : 1, sizeof *fetched.ids);
    keep = malloc(sizeof *keep * (nobj ? nobj : 1));
    ious = calloc(frames, sizeof *ious), qtimes = calloc(frames, sizeof *qtimes);
    rfull = calloc(frames, sizeof *rfull), rpart = calloc(frames, sizeof *rpart);
    if (r == SY_OK && (!ma || !mb || !rgb || !state || !fetched.ids || !keep || !ious || !qtimes || !rfull || !rpart))
        r = sy_error_set(&err, SY_ERR_OUT_OF_MEMORY, "bench cull: out of memory");
    if (r != SY_OK) goto done;
    memset(state, 1, nobj);
    t0 = now_s();
    r = sy_window_render(win, s, pool, NULL, &full, &err); /* translation into the rasterizer */
    double t_raster = now_s() - t0;
    if (r != SY_OK) goto done;
    printf("coverage context built in %.2f s, raster context in %.2f s; path: %u views at %ux%u, fov 60, budget %llu triangles\n\n",
           t_cov, t_raster, frames, w, h, (unsigned long long)budget);
    printf("%4s %8s %10s %7s %10s %7s %8s %8s %9s %9s %8s %8s\n", "view", "visible", "vis tris", "kept", "drawn",
           "IoU", "new obj", "new tris", "GLB KB", "JPEG KB", "cull ms", "full ms");
    uint64_t total_fetch_tris = 0, total_glb = 0, total_jpeg = 0, max_drawn = 0, sum_drawn = 0;
    double glb_s = 0, jpeg_s = 0;
    uint32_t cov_w = 0, cov_h = 0;
    for (uint32_t f = 0; f < frames && r == SY_OK; ++f) {
        sy_cull_view v;
        path_view(&pi, f, frames, w, h, &v);
        /* the full scene */
        if ((r = set_camera(s, cam_node, &v, &err)) != SY_OK || (r = sy_scene_commit(s, NULL, &err)) != SY_OK) break;
        double a = now_s();
        if ((r = sy_window_render(win, s, pool, NULL, &full, &err)) != SY_OK) break;
        rfull[f] = now_s() - a;
        mask_of(&full, ma);
        double js;
        size_t jb = jpeg_bytes(&full, rgb, &js);
        total_jpeg += jb, jpeg_s += js;
        /* the service */
        sy_cull_result cr;
        a = now_s();
        if ((r = sy_culler_query(cul, &v, budget, &cr, &err)) != SY_OK) break;
        qtimes[f] = now_s() - a;
        cov_w = cr.coverage_width, cov_h = cr.coverage_height;
        /* the client: fetch what it has not got, draw only the kept objects */
        uint32_t new_obj = 0;
        uint64_t new_tris = 0, new_bytes = 0;
        for (uint32_t k = 0; k < cr.count && r == SY_OK; ++k) {
            keep[k] = cr.objects[k].id;
            if (bsearch(&keep[k], fetched.ids, fetched.count, sizeof *fetched.ids, cmp_u32)) continue;
            uint8_t *glb = NULL;
            size_t len = 0;
            a = now_s();
            r = sy_culler_object_glb(cul, keep[k], &glb, &len, &err);
            glb_s += now_s() - a;
            free(glb);
            new_obj++, new_tris += cr.objects[k].triangles, new_bytes += len;
            fetched.ids[fetched.count++] = keep[k];
            qsort(fetched.ids, fetched.count, sizeof *fetched.ids, cmp_u32);
        }
        uint32_t kept = cr.count;
        uint64_t drawn = cr.triangles, vis_tris = cr.visible_triangles;
        uint32_t visible = cr.visible_objects;
        sy_cull_result_free(&cr);
        if (r != SY_OK) break;
        qsort(keep, kept, sizeof *keep, cmp_u32);
        if ((r = set_visible(s, objs, nobj, keep, kept, state, &err)) != SY_OK) break;
        a = now_s();
        if ((r = sy_window_render(win, s, pool, NULL, &part, &err)) != SY_OK) break;
        rpart[f] = now_s() - a;
        if ((r = set_visible(s, objs, nobj, NULL, 0, state, &err)) != SY_OK) break;
        mask_of(&part, mb);
        ious[f] = iou(ma, mb, npx);
        total_fetch_tris += new_tris, total_glb += new_bytes, sum_drawn += drawn;
        if (drawn > max_drawn) max_drawn = drawn;
        printf("%4u %8u %10llu %7u %10llu %7.4f %8u %8llu %9.0f %9.1f %8.1f %8.1f\n", f, visible,
               (unsigned long long)vis_tris, kept, (unsigned long long)drawn, ious[f], new_obj,
               (unsigned long long)new_tris, (double)new_bytes / 1024.0, (double)jb / 1024.0, 1e3 * qtimes[f],
               1e3 * rfull[f]);
        if (tty) fprintf(stderr, "\rview %u of %u", f + 1, frames), fflush(stderr);
    }
    if (tty) fprintf(stderr, "\r%20s\r", "");
    if (r != SY_OK) goto done;
    sy_bench_spread si = sy_bench_spread_of(ious, frames), sq = sy_bench_spread_of(qtimes, frames);
    sy_bench_spread sf = sy_bench_spread_of(rfull, frames), sp = sy_bench_spread_of(rpart, frames);
    printf("\ncoverage IoU (culled vs full raster render): median %.4f (min %.4f, max %.4f)\n", si.median, si.min, si.max);
    printf("triangles drawn by the client: max %llu, mean %.0f per view, budget %llu (%.1f%% of the plant's %llu at most)\n",
           (unsigned long long)max_drawn, (double)sum_drawn / frames, (unsigned long long)budget,
           100.0 * (double)max_drawn / (double)pi.triangles, (unsigned long long)pi.triangles);
    printf("cull query (coverage %ux%u + ranking): median %.1f ms (min %.1f, max %.1f); raster full %.1f ms, culled %.1f ms (medians)\n",
           cov_w, cov_h, 1e3 * sq.median, 1e3 * sq.min, 1e3 * sq.max,
           1e3 * sf.median, 1e3 * sp.median);
    printf("over the path: %u objects fetched, %llu triangles (%.1f%% of the plant), %.2f MB of GLB (%.0f bytes per triangle, written in %.2f s)\n",
           fetched.count, (unsigned long long)total_fetch_tris, 100.0 * (double)total_fetch_tris / (double)pi.triangles,
           (double)total_glb / 1e6, total_fetch_tris ? (double)total_glb / (double)total_fetch_tris : 0.0, glb_s);
    if (total_jpeg) {
        /* video: one JPEG per frame at 30 fps; geometry: fetched once, cached by the client */
        double per_frame = (double)total_jpeg / frames, rate = per_frame * 30.0;
        printf("video of the same path (JPEG q80 of the full render at %ux%u): %.1f KB per frame (encoded in %.1f ms), "
               "%.2f MB/s at 30 fps\n", w, h, per_frame / 1024.0, 1e3 * jpeg_s / frames, rate / 1e6);
        printf("ratios: GLB bytes of the whole path = %.0f video frames = %.1f s of 30 fps video; JPEG bytes of the %u views "
               "alone %.2f MB (GLB / JPEG %.1f)\n", (double)total_glb / per_frame, (double)total_glb / rate, frames,
               (double)total_jpeg / 1e6, (double)total_glb / (double)total_jpeg);
    } else {
        printf("video: not measured (this sy was built without libturbojpeg)\n");
    }
done:
    free(ma), free(mb), free(rgb), free(state), free(keep), free(fetched.ids);
    free(ious), free(qtimes), free(rfull), free(rpart);
    sy_layer_destroy(&full), sy_layer_destroy(&part);
    sy_window_destroy(win);
    sy_culler_destroy(cul);
    sy_context_pool_destroy(pool);
    if (ld.scene) sy_cli_loaded_free(&ld); /* s is ld.scene */
    else sy_scene_destroy(s);
    if (r != SY_OK) {
        fprintf(stderr, "sy: error: %s\n", err.message);
        return 1;
    }
    return 0;
}

int sy_cmd_bench_cull(int argc, char **argv)
{
    uint64_t tris = 10000000, objects = 10000, budget = 2000000;
    uint32_t w = 640, h = 360, frames = 8, seed = 1;
    const char *write_path = NULL;
    static const char usage_text[] =
        "usage: sy bench cull [--tris N] [--objects N] [--budget T] [-w W] [-h H] [--frames N] [--seed S]\n"
        "                     [--write FILE.glb]\n"
        "  the culling service on a generated plant (default 10000000 triangles in 10000 objects) along a\n"
        "  camera path of N views (default 8) at W x H (default 640 x 360) with a budget of T triangles\n"
        "  (default 2000000): IoU of the culled raster render against the full one, triangles drawn, and\n"
        "  GLB bytes fetched against JPEG video of the same path. --write: write the plant as GLB and stop\n"
        "  (serve it with sy web FILE.glb --client-render). N and T may end in k or M: --tris 10M\n";
    enum { O_TRIS = OPT_OWN_FIRST, O_OBJECTS, O_BUDGET, O_FRAMES, O_SEED, O_WRITE };
    const sy_cli_opt opts[] = {
        SY_CLI_OPT_COUNT("tris", O_TRIS, &tris, 1, 1ull << 32), SY_CLI_OPT_COUNT("objects", O_OBJECTS, &objects, 1, 1u << 22),
        SY_CLI_OPT_COUNT("budget", O_BUDGET, &budget, 0, SY_CULL_MAX_BUDGET),
        SY_CLI_OPT_UINT("frames", O_FRAMES, &frames, 1, 100000), SY_CLI_OPT_UINT("seed", O_SEED, &seed, 0, UINT32_MAX),
        SY_CLI_OPT_TEXT("write", O_WRITE, &write_path)};
    sy_cli_parser p = {SY_CLI_ARGS("bench cull", argc, argv, opts), .w = &w, .h = &h, .min_size = 1, .usage = usage_text};
    if (sy_cli_parse(&p) != -1) return p.status;
    if (optind < argc) {
        fprintf(stderr, "sy bench cull: error: unexpected argument '%s'\n%s", argv[optind], usage_text);
        return 2;
    }
    return run_bench(tris, (uint32_t)objects, budget, w, h, frames, seed, write_path);
}
