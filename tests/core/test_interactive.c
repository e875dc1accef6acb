/* test_interactive.c — the interactive view of sy view and sy web (core/sy_interactive.h) against a
 * recording mediator class registered here:
 *   1. the display filters are the "filter" enum of the filter class's parameter table; an unknown
 *      initial filter is refused naming them; the keys F [ ] R; the default back-end is the registry's;
 *   2. an orbit drag reaches the viewport as its view (sy_viewport_set_view) and the render's camera,
 *      while the application's change pending before the interaction is still pending after the
 *      moving frame (no commit: the scene's frame number and pending flag are as they were);
 *   3. the governor: a moving frame after a change, a back-end switch; the display filter set on the
 *      context once per change, off while moving; the 8-bit conversions. */
#include "../support/sy_check.h"
#include "sy_interactive.h"

#include <math.h>
#include <stdlib.h>

/* ---- a recording mediator class ---- */
typedef struct rec {
    sy_mat4 last_camera; /* the camera-to-world of the last render request */
    uint32_t renders, filter_calls;
    char filter[32];
} rec;
static rec *g_rec; /* the one instance (tests here make one context per class) */

static sy_result rec_create(const sy_mediator_create_args *a, void **out, sy_error *err)
{
    (void)a;
    rec *r = calloc(1, sizeof *r);
    if (!r) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "rec: out of memory");
    snprintf(r->filter, sizeof r->filter, "none");
    *out = g_rec = r;
    return SY_OK;
}
static void rec_destroy(void *s)
{
    if (g_rec == s) g_rec = NULL;
    free(s);
}
static sy_result rec_sync(void *s, const sy_changes *c, sy_error *err) { return (void)s, (void)c, (void)err, SY_OK; }
static sy_result rec_render(void *s, const sy_render_request *req, sy_layer *l, sy_error *err)
{
    (void)err;
    rec *r = s;
    r->last_camera = req->camera.camera_to_world;
    r->renders++;
    for (size_t i = 0; i < (size_t)l->width * l->height * 4; ++i) l->rgba[i] = 0.5f;
    return SY_OK;
}
static sy_result rec_set_filter(void *s, const char *name, const sy_params *opts, sy_error *err)
{
    (void)opts, (void)err;
    rec *r = s;
    snprintf(r->filter, sizeof r->filter, "%s", name);
    r->filter_calls++;
    return SY_OK;
}
static void rec_filter_info(void *s, sy_filter_info *out)
{
    memset(out, 0, sizeof *out);
    snprintf(out->name, sizeof out->name, "%s", ((rec *)s)->filter);
}
static const sy_param_decl rec_params[] = {
    {"filter", SY_PARAM_ENUM, 0, 0, "none", "none|soft|sharp", "display filter", SY_PARAM_LIVE},
    {"threshold", SY_PARAM_FLOAT, 0, 1e3, "0.01", NULL, "its threshold", SY_PARAM_LIVE},
};
static const sy_mediator_class rec_filtering = {.name = "test_filtering", .caps = SY_CAP_FILTERS | SY_CAP_PROGRESSIVE,
                                                .create = rec_create, .destroy = rec_destroy, .sync = rec_sync,
                                                .render = rec_render, .set_filter = rec_set_filter,
                                                .filter_info = rec_filter_info, .param_table = SY_PARAM_TABLE(rec_params)};
static const sy_mediator_class rec_plain = {.name = "test_plain", .create = rec_create, .destroy = rec_destroy,
                                            .sync = rec_sync, .render = rec_render, .default_rank = 5};

/* A scene with a camera node 5 in front of a mesh-less root, committed, and a context pool. */
typedef struct fixture {
    sy_scene *s;
    sy_node root, cam_node;
    sy_context_pool *pool;
} fixture;

static int fixture_init(fixture *f)
{
    sy_error e = {0};
    sy_camera cam;
    sy_camera_data cd = {.projection = SY_PROJECTION_PERSPECTIVE, .yfov = 0.8f, .znear = 0.1f, .zfar = 100.0f};
    sy_mat4 m = sy_mat4_identity();
    m.m[14] = 5.0f;
    CHECK_OK(sy_scene_create(&f->s, &e), e);
    CHECK_OK(sy_node_create(f->s, "root", &f->root, &e), e);
    CHECK_OK(sy_camera_create(f->s, "cam", &cam, &e), e);
    CHECK_OK(sy_camera_set(f->s, cam, &cd, &e), e);
    CHECK_OK(sy_node_create(f->s, "camera", &f->cam_node, &e), e);
    CHECK_OK(sy_node_set_camera(f->s, f->cam_node, cam, &e), e);
    CHECK_OK(sy_node_set_matrix(f->s, f->cam_node, &m, &e), e);
    CHECK_OK(sy_node_add_child(f->s, f->root, f->cam_node, &e), e);
    CHECK_OK(sy_scene_commit(f->s, NULL, &e), e);
    CHECK_OK(sy_context_pool_create(&f->pool, &e), e);
    return 0;
}

static void fixture_free(fixture *f)
{
    sy_context_pool_destroy(f->pool);
    sy_scene_destroy(f->s);
}

#define VIEW_TEST(name) SY_FIXTURE_TEST(name, fixture, fixture_init, fixture_free)

VIEW_TEST(test_filters_keys_backend)
{
    sy_error e = {0};
    char name[32];
    CHECK(sy_interactive_filter_count() == 3); /* none|soft|sharp, from the class's table */
    CHECK(!strcmp(sy_interactive_filter_name(0, name), "none"));
    CHECK(!strcmp(sy_interactive_filter_name(2, name), "sharp"));
    CHECK(!strcmp(sy_interactive_filter_name(4, name), "soft")); /* modulo the count */
    sy_interactive_input in;
    CHECK_ERR(sy_interactive_input_init(f->s, f->root, f->cam_node, 1.0f, "pixel", 0, &in, &e), SY_ERR_INVALID_ARGUMENT, e);
    CHECK_SAYS(e, "expected none, soft or sharp");
    CHECK_ERR(sy_interactive_input_init(f->s, f->root, f->cam_node, 1.0f, NULL, -1.0f, &in, &e), SY_ERR_INVALID_ARGUMENT, e);
    CHECK_OK(sy_interactive_input_init(f->s, f->root, f->cam_node, 1.0f, "sharp", 0, &in, &e), e);
    CHECK(in.filter == 2 && in.threshold == 0.01f);
    sy_mat4 m;
    sy_orbit_matrix(&in.orbit, &m);
    CHECK_NEAR(m.m[14], 5.0, 1e-5); /* the orbit starts at the camera's pose */
    CHECK(sy_interactive_key(&in, 'F') && in.filter == 0 && in.filter_version == 1);
    CHECK(sy_interactive_key(&in, ']') && in.threshold == 0.02f && in.filter_version == 2);
    CHECK(sy_interactive_key(&in, '[') && in.threshold == 0.01f);
    sy_interactive_drag(&in, 0, 30, 0);
    CHECK(sy_interactive_key(&in, 'r') && in.orbit.yaw == in.home.yaw);
    CHECK(!sy_interactive_key(&in, 'x'));
    float fwd[3] = {0, 0, -1}, still[3] = {0, 0, 0}, z0 = in.orbit.target[2];
    CHECK(sy_interactive_fly(&in, fwd, 0.5f)); /* forward: towards -Z, 0.8 x dist per second */
    CHECK_NEAR(in.orbit.target[2], z0 - 0.8 * 0.5 * in.orbit.dist, 1e-4);
    CHECK(!sy_interactive_fly(&in, still, 0.5f));
    uint32_t bi = 99;
    CHECK_OK(sy_interactive_backend_index(NULL, &bi, &e), e);
    CHECK(sy_mediator_at(bi) == sy_mediator_default());
    CHECK_OK(sy_interactive_backend_index("test_filtering", &bi, &e), e);
    CHECK(sy_mediator_at(bi) == &rec_filtering);
    CHECK_ERR(sy_interactive_backend_index("nope", &bi, &e), SY_ERR_NOT_FOUND, e);
    return 0;
}

VIEW_TEST(test_view_without_commit)
{
    sy_error e = {0};
    sy_window *win = NULL;
    sy_viewport *vp = NULL;
    sy_interactive *ia = NULL;
    CHECK_OK(sy_window_create(32, 24, &win, &e), e);
    sy_viewport_desc vd = {.root = f->root, .camera = f->cam_node, .backend = "test_plain"};
    CHECK_OK(sy_window_add_viewport(win, &vd, &vp, &e), e);
    CHECK(!sy_viewport_view(vp, NULL));
    CHECK_OK(sy_interactive_create(NULL, &ia, &e), e);
    sy_interactive_input in;
    CHECK_OK(sy_interactive_input_init(f->s, f->root, f->cam_node, 32.0f / 24.0f, NULL, 0, &in, &e), e);

    /* the application changes its scene and has not committed yet */
    sy_node extra;
    CHECK_OK(sy_node_create(f->s, "pending", &extra, &e), e);
    uint64_t frame = sy_scene_frame(f->s);
    CHECK(sy_scene_has_pending(f->s));

    /* the user drags: a moving frame */
    sy_interactive_drag(&in, 0, 40, -10);
    sy_mat4 want, got, set;
    sy_orbit_matrix(&in.orbit, &want);
    sy_governor_frame gf;
    sy_interactive_view iv = {.orbit = &in.orbit, .viewports = &vp, .viewport_count = 1,
                              .backend = sy_mediator_find("test_plain"), .caps = 0, .width = 32, .height = 24};
    sy_interactive_plan(ia, &iv, 0.0, &gf, &got);
    CHECK(sy_mat4_equal(&got, &want));
    CHECK(sy_viewport_view(vp, &set) && sy_mat4_equal(&set, &want));
    CHECK(sy_interactive_view_matrix(ia, &set) && sy_mat4_equal(&set, &want));
    CHECK(gf.moving && !gf.idle && gf.width > 0);
    sy_layer img;
    CHECK_OK(sy_layer_create(32, 24, &img, &e), e);
    CHECK_OK(sy_window_render(win, f->s, f->pool, NULL, &img, &e), e);
    CHECK(g_rec && g_rec->renders == 1);
    CHECK(sy_mat4_equal(&g_rec->last_camera, &want)); /* the render saw the orbit's view */
    /* ... and the scene was not committed: the application's change is still pending */
    CHECK(sy_scene_has_pending(f->s));
    CHECK(sy_scene_frame(f->s) == frame);
    sy_mat4 node_world;
    CHECK_OK(sy_node_world_matrix(f->s, f->cam_node, &node_world, &e), e);
    CHECK_NEAR(node_world.m[14], 5.0, 1e-6); /* the camera node did not move */
    sy_camera_view cv;
    CHECK_OK(sy_viewport_camera_view(vp, f->s, 32, 24, &cv, &e), e);
    CHECK(sy_mat4_equal(&cv.camera_to_world, &want));
    CHECK_NEAR(cv.window[3], tan(0.4), 1e-5); /* the camera node's projection (yfov 0.8) */
    CHECK_NEAR(cv.znear, 0.1, 1e-6);
    sy_viewport_set_view(vp, NULL); /* back to the node */
    CHECK_OK(sy_viewport_camera_view(vp, f->s, 32, 24, &cv, &e), e);
    CHECK_NEAR(cv.camera_to_world.m[14], 5.0, 1e-6);
    /* the application commits when it wants to */
    CHECK_OK(sy_scene_commit(f->s, NULL, &e), e);
    CHECK(!sy_scene_has_pending(f->s) && sy_scene_frame(f->s) == frame + 1);

    sy_layer_destroy(&img);
    sy_interactive_destroy(ia);
    sy_window_destroy(win);
    return 0;
}

VIEW_TEST(test_governor_filter_rgba8)
{
    sy_error e = {0};
    sy_interactive *ia = NULL;
    CHECK_OK(sy_interactive_create(&(sy_governor_desc){.budget_ms = 10}, &ia, &e), e);
    sy_interactive_input in;
    CHECK_OK(sy_interactive_input_init(f->s, f->root, f->cam_node, 1.0f, "soft", 0.5f, &in, &e), e);
    const sy_mediator_class *cls = sy_mediator_find("test_filtering");
    sy_interactive_view iv = {.orbit = &in.orbit, .backend = cls, .caps = cls->caps, .width = 64, .height = 64};
    sy_governor_frame gf;
    sy_interactive_plan(ia, &iv, 0.0, &gf, NULL);
    CHECK(gf.moving && !gf.filter); /* the first frame: a change */
    sy_interactive_report(ia, &gf, 5.0, false);
    /* the filter: off while moving, on when refining, set once per change */
    sy_filter_info fi;
    CHECK_OK(sy_interactive_apply_filter(ia, f->pool, f->s, f->root.id, cls, in.filter, in.threshold, in.filter_version,
                                         false, &fi, &e), e);
    CHECK(g_rec && !strcmp(fi.name, "none") && g_rec->filter_calls == 1);
    CHECK_OK(sy_interactive_apply_filter(ia, f->pool, f->s, f->root.id, cls, in.filter, in.threshold, in.filter_version,
                                         true, &fi, &e), e);
    CHECK(!strcmp(fi.name, "soft") && g_rec->filter_calls == 2);
    CHECK_OK(sy_interactive_apply_filter(ia, f->pool, f->s, f->root.id, cls, in.filter, in.threshold, in.filter_version,
                                         true, &fi, &e), e);
    CHECK(g_rec->filter_calls == 2); /* nothing changed: not set again */
    sy_interactive_key(&in, 'f');
    CHECK_OK(sy_interactive_apply_filter(ia, f->pool, f->s, f->root.id, cls, in.filter, in.threshold, in.filter_version,
                                         true, &fi, &e), e);
    CHECK(!strcmp(fi.name, "sharp") && g_rec->filter_calls == 3);
    /* a back-end without filters: nothing, no error */
    CHECK_OK(sy_interactive_apply_filter(ia, f->pool, f->s, f->root.id, sy_mediator_find("test_plain"), in.filter, in.threshold,
                                         in.filter_version, true, &fi, &e), e);
    CHECK(fi.name[0] == 0);
    /* the view rests: after the settle time the governor refines at full size */
    iv.filter_version = in.filter_version;
    for (double t = 10; t < 2000 && (gf.moving || gf.wait_ms > 0); t += 50) sy_interactive_plan(ia, &iv, t, &gf, NULL);
    CHECK(!gf.moving && gf.width == 64 && gf.height == 64 && gf.filter);
    /* 8-bit: straight alpha for a window, over black for a JPEG */
    sy_layer l;
    CHECK_OK(sy_layer_create(1, 1, &l, &e), e);
    l.rgba[0] = 0.25f, l.rgba[1] = 0.5f, l.rgba[2] = 0.0f, l.rgba[3] = 0.5f;
    uint8_t *a = sy_interactive_rgba8(&l, SY_RGBA8_STRAIGHT), *b = sy_interactive_rgba8(&l, SY_RGBA8_OVER_BLACK);
    CHECK(a && b);
    CHECK(a[0] == sy_unorm8(0.5f) && a[1] == 255 && a[2] == 0 && a[3] == sy_unorm8(0.5f));
    CHECK(b[0] == sy_unorm8(0.25f) && b[1] == sy_unorm8(0.5f) && b[2] == 0 && b[3] == 255);
    free(a);
    free(b);
    sy_layer_destroy(&l);
    sy_interactive_destroy(ia);
    return 0;
}

int main(void)
{
    sy_error e = {0};
    CHECK_OK(sy_mediator_register(&rec_filtering, &e), e);
    CHECK_OK(sy_mediator_register(&rec_plain, &e), e);
    RUN(test_filters_keys_backend);
    RUN(test_view_without_commit);
    RUN(test_governor_filter_rgba8);
    return sy_check_finish("core_interactive");
}
