/* it_util.h — small helpers shared by the integration tests: the check kit
 * (tests/support/sy_check.h; the tests use its counted EXPECT form, which keeps going, and end with
 * sy_check_finish, or it_finish_last when the last test may skip), MUST, test-data lookup with the
 * "skip = exit 77" rule, scratch directories, the picture back-ends to compare (it_backends), a
 * stub back-end for capability tests, and scene-building shortcuts (scenes, pools, unlit quads,
 * lights, one-viewport windows, camera views by hand) and image measures (coverage IoU, region
 * means, pixels). */
#ifndef IT_UTIL_H
#define IT_UTIL_H

#include "../support/sy_check.h"
#include "../support/sy_scratch.h"
#include "sy_mediator.h"
#include "sy_mediators.h"
#include "sy_scene.h"
#include "sy_viewport.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* A call returning sy_result that must succeed; aborts the test on failure (later steps depend on it). */
#define MUST(call)                                                                                                   \
    do {                                                                                                             \
        sy_error must_err_ = {0};                                                                                    \
        sy_error *err = &must_err_;                                                                                  \
        sy_result must_r_ = (call);                                                                                  \
        if (must_r_ != SY_OK) {                                                                                      \
            fprintf(stderr, "%s:%d: %s failed: %s (%s)\n", __FILE__, __LINE__, #call, must_err_.message,            \
                    sy_result_str(must_r_));                                                                         \
            exit(1);                                                                                                 \
        }                                                                                                            \
    } while (0)

static inline void it_register(void)
{
    sy_error e = {0};
    if (sy_mediators_register_builtin(&e) != SY_OK) {
        fprintf(stderr, "sy_mediators_register_builtin: %s\n", e.message);
        exit(1);
    }
}

/* The start of a test's main: the built-in back-ends registered (it_register); the folder of
 * `--write DIR` (the test writes its images there), or NULL without it. */
static inline const char *it_start(int argc, char **argv)
{
    it_register();
    return argc == 3 && !strcmp(argv[1], "--write") ? argv[2] : NULL;
}

/* Path of a test-data file, or exit 77 (skipped) with the reason when it is absent. */
static inline const char *it_testdata(const char *rel, char *buf, size_t size)
{
    snprintf(buf, size, "%s/%s", SY_TESTDATA_DIR, rel);
    if (access(buf, R_OK) != 0) {
        printf("SKIP: test data %s not found (SY_TESTDATA_DIR=%s)\n", buf, SY_TESTDATA_DIR);
        exit(77);
    }
    return buf;
}

#if __has_include("sy_gltf.h") /* the tests that link the formats */
#include "sy_gltf.h"
/* A new scene holding the glTF file at path (not committed); *info: the loader's (sy_gltf_info_free);
 * aborts on failure. */
static inline sy_scene *it_load_gltf(const char *path, sy_gltf_info *info)
{
    sy_scene *s;
    MUST(sy_scene_create(&s, err));
    MUST(sy_gltf_load(path, s, NULL, info, err));
    return s;
}
#endif

/* Blob from a copy of memory; aborts on failure. */
static inline sy_blob *it_blob(const void *data, size_t size)
{
    sy_blob *b = NULL;
    MUST(sy_blob_create_copy(data, size, &b, err));
    return b;
}

/* A square in the z=0 plane facing +Z, centred at (cx, cy) of half-size h. */
static inline sy_primitive it_quad_prim(float cx, float cy, float h, sy_material mat)
{
    const float pos[12] = {cx - h, cy - h, 0, cx + h, cy - h, 0, cx + h, cy + h, 0, cx - h, cy + h, 0};
    const float nrm[12] = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
    const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
    sy_primitive p = {0};
    p.positions = it_blob(pos, sizeof pos);
    p.normals = it_blob(nrm, sizeof nrm);
    p.indices = it_blob(idx, sizeof idx);
    p.material = mat;
    return p;
}

/* A mesh of `count` quads (one primitive each) given as (cx, cy, h) triples. */
static inline sy_mesh it_quad_mesh(sy_scene *s, const char *name, const float (*quads)[3], const sy_material *mats,
                            uint32_t count)
{
    sy_primitive prims[8];
    sy_mesh m;
    MUST(sy_mesh_create(s, name, &m, err));
    for (uint32_t i = 0; i < count; ++i) prims[i] = it_quad_prim(quads[i][0], quads[i][1], quads[i][2], mats[i]);
    MUST(sy_mesh_set_primitives(s, m, prims, count, err));
    for (uint32_t i = 0; i < count; ++i) sy_primitive_release(&prims[i]);
    return m;
}

/* A material of base colour (r, g, b): unlit (the Whitted tracer shows exactly its base colour),
 * or Lambert (roughness 1, not metallic). */
static inline sy_material it_material_rgb(sy_scene *s, const char *name, float r, float g, float b, bool unlit)
{
    sy_material m;
    MUST(sy_material_create(s, name, &m, err));
    sy_material_data d = *sy_material_get(s, m);
    d.name = (char *)name;
    d.base_color[0] = r, d.base_color[1] = g, d.base_color[2] = b, d.base_color[3] = 1.0f;
    if (unlit) d.unlit = 1;
    else d.metallic = 0.0f, d.roughness = 1.0f;
    MUST(sy_material_set(s, m, &d, err));
    return m;
}

static inline sy_material it_unlit(sy_scene *s, const char *name, float r, float g, float b)
{
    return it_material_rgb(s, name, r, g, b, true);
}

static inline sy_material it_lambert(sy_scene *s, const char *name, float r, float g, float b)
{
    return it_material_rgb(s, name, r, g, b, false);
}

/* A light of the given type and intensity (the rest at the defaults), on no node yet. */
static inline sy_light it_light(sy_scene *s, const char *name, sy_light_type type, float intensity)
{
    sy_light l;
    MUST(sy_light_create(s, name, &l, err));
    sy_light_data ld = *sy_light_get(s, l);
    ld.type = type;
    ld.intensity = intensity;
    MUST(sy_light_set(s, l, &ld, err));
    return l;
}

/* A directional light "sun" of intensity 3 on a new node at (0, 0, 3), its -Z turned 45 degrees
 * about Y: it travels (-1, 0, -1)/sqrt(2), so a caster's shadow falls towards -x (the clip tests). */
static inline void it_sun_45(sy_scene *s)
{
    sy_light lamp = it_light(s, "sun", SY_LIGHT_DIRECTIONAL, 3.0f);
    sy_node ln;
    MUST(sy_node_create(s, "sun", &ln, err));
    MUST(sy_node_set_light(s, ln, lamp, err));
    const float t[3] = {0, 0, 3}, q[4] = {0, sinf(0.3926991f), 0, cosf(0.3926991f)}, one[3] = {1, 1, 1};
    MUST(sy_node_set_trs(s, ln, t, q, one, err));
}

/* A stub back-end for the tests of what a capability guards: it renders a cleared layer and counts
 * its renders in it_stub_renders. A test defines its class with these functions and only the caps
 * it wants (the capability under test left out), e.g.
 *   {.name = "test_noclip", .caps = SY_CAP_DEPTH, IT_STUB_FUNCTIONS} */
static int it_stub_renders __attribute__((unused));
static inline sy_result it_stub_create(const sy_mediator_create_args *a, void **st, sy_error *e)
{
    (void)a, (void)e;
    *st = malloc(1);
    return SY_OK;
}
static inline void it_stub_destroy(void *st) { free(st); }
static inline sy_result it_stub_sync(void *st, const sy_changes *c, sy_error *e)
{
    (void)st, (void)c, (void)e;
    return SY_OK;
}
static inline sy_result it_stub_render(void *st, const sy_render_request *r, sy_layer *l, sy_error *e)
{
    (void)st, (void)r, (void)e;
    it_stub_renders++;
    sy_layer_clear(l);
    return SY_OK;
}
#define IT_STUB_FUNCTIONS .create = it_stub_create, .destroy = it_stub_destroy, .sync = it_stub_sync, .render = it_stub_render

/* The end of a main whose last test, last(arg), needs the shared test data and may skip (exit 77 in
 * it_testdata): checks failed so far end the test first, so a skip cannot hide them; then
 * sy_check_finish(name). */
static inline int it_finish_last(const char *name, void (*last)(const char *), const char *arg)
{
    if (sy_check_failures) return sy_check_finish(name);
    last(arg);
    return sy_check_finish(name);
}

/* The picture back-ends the integration tests compare (raster where it was built). */
static const char *const it_backends[] __attribute__((unused)) = {
#ifdef SY_HAVE_RASTER
    "raster",
#endif
    "whitted", "pathtracer"};
#define IT_NBACKENDS (sizeof it_backends / sizeof it_backends[0])

/* A new, empty scene (sy_scene_destroy); aborts on failure. */
static inline sy_scene *it_scene(void)
{
    sy_scene *s;
    MUST(sy_scene_create(&s, err));
    return s;
}

/* A new, empty context pool (sy_context_pool_destroy); aborts on failure. */
static inline sy_context_pool *it_pool(void)
{
    sy_context_pool *pool;
    MUST(sy_context_pool_create(&pool, err));
    return pool;
}

/* A w x h window with the one viewport vd (its handle in *vp when vp is not NULL). */
static inline sy_window *it_window(uint32_t w, uint32_t h, const sy_viewport_desc *vd, sy_viewport **vp)
{
    sy_window *win;
    MUST(sy_window_create(w, h, &win, err));
    MUST(sy_window_add_viewport(win, vd, vp, err));
    return win;
}

static inline void it_set_translation(sy_scene *s, sy_node n, float x, float y, float z)
{
    const float t[3] = {x, y, z}, q[4] = {0, 0, 0, 1}, one[3] = {1, 1, 1};
    MUST(sy_node_set_trs(s, n, t, q, one, err));
}

/* A node at (x, y, z) carrying a new perspective camera named name (yfov radians, znear 0.01, the
 * image's aspect, infinite far plane), looking down -Z. */
static inline sy_node it_camera_node(sy_scene *s, const char *name, float x, float y, float z, float yfov)
{
    sy_camera c;
    sy_node n;
    MUST(sy_camera_create(s, name, &c, err));
    sy_camera_data cd = *sy_camera_get(s, c);
    cd.name = (char *)name;
    cd.projection = SY_PROJECTION_PERSPECTIVE;
    cd.yfov = yfov;
    cd.aspect = 0.0f;
    cd.znear = 0.01f;
    cd.zfar = 0.0f;
    MUST(sy_camera_set(s, c, &cd, err));
    MUST(sy_node_create(s, name, &n, err));
    MUST(sy_node_set_camera(s, n, c, err));
    it_set_translation(s, n, x, y, z);
    return n;
}

/* Perspective view from (0, 0, dist) looking down -Z with a symmetric window of half-size tan_half. */
static inline sy_camera_view it_view_down_z(float dist, float tan_half)
{
    sy_camera_view v;
    memset(&v, 0, sizeof v);
    v.camera_to_world = sy_mat4_identity();
    v.camera_to_world.m[14] = dist;
    v.projection = SY_PROJECTION_PERSPECTIVE;
    v.window[0] = -tan_half, v.window[1] = tan_half, v.window[2] = -tan_half, v.window[3] = tan_half;
    v.znear = 0.01f;
    v.zfar = 0.0f;
    return v;
}

/* Continuous pixel coordinates of world point p seen through view v on a w x h image (row 0 on
 * top), computed by hand from the view's definition. Returns false behind the camera. */
static inline bool it_project(const sy_camera_view *v, const float p[3], uint32_t w, uint32_t h, float *px, float *py)
{
    *px = *py = NAN;
    sy_mat4 inv;
    if (!sy_mat4_invert(&v->camera_to_world, &inv)) return false;
    float c[3];
    sy_mat4_transform_point(&inv, p, c);
    float tx, ty;
    if (v->projection == SY_PROJECTION_PERSPECTIVE) {
        if (c[2] >= 0.0f) return false;
        tx = c[0] / -c[2];
        ty = c[1] / -c[2];
    } else {
        tx = c[0];
        ty = c[1];
    }
    *px = (tx - v->window[0]) / (v->window[1] - v->window[0]) * (float)w;
    *py = (v->window[3] - ty) / (v->window[3] - v->window[2]) * (float)h;
    return true;
}

/* The whole w x h image of ctx seen through view into *img (created here; the caller destroys it);
 * samples: a progressive back-end's sample count (0: its default). */
static inline sy_result it_render_full(sy_context *ctx, const sy_camera_view *view, uint32_t w, uint32_t h,
                                       uint32_t samples, sy_layer *img, sy_error *err)
{
    sy_render_request req;
    memset(&req, 0, sizeof req);
    req.camera = *view;
    req.full_width = req.rect_w = w;
    req.full_height = req.rect_h = h;
    req.sample_count = samples;
    sy_result r = sy_layer_create(w, h, img, err);
    return r != SY_OK ? r : sy_context_render(ctx, &req, img, err);
}

/* Coverage IoU of two images (a pixel is covered where alpha > 0.5); 1 when neither covers any. */
static inline double it_coverage_iou(const sy_layer *a, const sy_layer *b)
{
    size_t both = 0, any = 0, n = (size_t)a->width * a->height;
    for (size_t i = 0; i < n; ++i) {
        bool ca = a->rgba[4 * i + 3] > 0.5f, cb = b->rgba[4 * i + 3] > 0.5f;
        both += ca && cb;
        any += ca || cb;
    }
    return any ? (double)both / (double)any : 1.0;
}

static inline const float *it_px(const sy_layer *l, uint32_t x, uint32_t y) { return l->rgba + 4 * ((size_t)y * l->width + x); }

static inline bool it_px_is(const sy_layer *l, uint32_t x, uint32_t y, float r, float g, float b, float a)
{
    const float *p = it_px(l, x, y);
    return p[0] == r && p[1] == g && p[2] == b && p[3] == a;
}

/* Bitwise equality of one pixel (colour and depth) of two equally sized layers. */
static inline bool it_px_same(const sy_layer *a, const sy_layer *b, uint32_t x, uint32_t y)
{
    size_t i = (size_t)y * a->width + x;
    return memcmp(a->rgba + 4 * i, b->rgba + 4 * i, 4 * sizeof(float)) == 0 &&
           memcmp(a->depth + i, b->depth + i, sizeof(float)) == 0;
}

static inline bool it_layers_identical(const sy_layer *a, const sy_layer *b)
{
    size_t n = (size_t)a->width * a->height;
    return a->width == b->width && a->height == b->height && memcmp(a->rgba, b->rgba, n * 4 * sizeof(float)) == 0 &&
           memcmp(a->depth, b->depth, n * sizeof(float)) == 0;
}

/* Mean RGB over the pixels of img whose image-plane point at distance dist lies in [x0, x1] x
 * [y0, y1], for a view straight down -Z with a 45-degree yfov and the image's aspect (the framing
 * view of a scene seen from above); returns the mean's luminance (Rec. 709), -1 when no pixel is in
 * the region. rgb (the mean) may be NULL. */
static inline double it_region_mean(const sy_layer *img, float dist, float x0, float x1, float y0, float y1, double rgb[3])
{
    const uint32_t w = img->width, h = img->height;
    const float t = tanf(0.3926991f), a = (float)w / (float)h;
    double sum[3] = {0, 0, 0}, mean[3];
    uint32_t count = 0;
    for (uint32_t py = 0; py < h; ++py)
        for (uint32_t px = 0; px < w; ++px) {
            float x = (-t * a + (px + 0.5f) / (float)w * 2.0f * t * a) * dist;
            float y = (t - (py + 0.5f) / (float)h * 2.0f * t) * dist;
            if (x < x0 || x > x1 || y < y0 || y > y1) continue;
            const float *c = it_px(img, px, py);
            for (int k = 0; k < 3; ++k) sum[k] += c[k];
            count++;
        }
    for (int k = 0; k < 3; ++k) mean[k] = count ? sum[k] / count : 0.0;
    if (rgb) memcpy(rgb, mean, sizeof mean);
    return count ? 0.2126 * mean[0] + 0.7152 * mean[1] + 0.0722 * mean[2] : -1.0;
}

#endif /* IT_UTIL_H */
