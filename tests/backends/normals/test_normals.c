/* test_normals.c — the "normals" test back-end, added through its own folder and one build line
 * (issue 16), used by the library like any built-in one:
 *   1. sy_mediators_register_builtin() registered it (the generated list) and its capabilities say
 *      what it is: depth, tiles, analysis.
 *   2. A tessellated unit sphere seen from +Z: every covered pixel's colour decodes to a normal
 *      within 8 degrees of the analytic sphere normal at the hit point reconstructed from the
 *      pixel's depth; coverage IoU against whitted (spp=1) >= 0.99 and depth within 0.1 %.
 *   3. An incremental change (the sphere moved +X) moves the image: the centre now sees the
 *      sphere's left side (normal x < 0).
 *   4. A sub-rectangle equals that part of the whole image; an unknown parameter is refused by name. */
#include "../../support/sy_check.h"
#include "sy_demo.h"
#include "sy_mediators.h"
#include "sy_stats.h"
#include "sy_viewport.h"

#include <math.h>
#include <string.h>

#define W 64
#define H 64

typedef struct fixture {
    sy_scene *scene;
    sy_node sphere, cam;
} fixture;

static int build(fixture *fx)
{
    sy_error e = {0};
    sy_material m;
    sy_mesh mesh;
    sy_camera c;
    CHECK_OK(sy_scene_create(&fx->scene, &e), e);
    CHECK_OK(sy_material_create(fx->scene, "grey", &m, &e), e);
    CHECK_OK(sy_demo_sphere(fx->scene, 1.0f, 96, 48, m, &mesh, &e), e);
    CHECK_OK(sy_node_create(fx->scene, "sphere", &fx->sphere, &e), e);
    CHECK_OK(sy_node_set_mesh(fx->scene, fx->sphere, mesh, &e), e);
    CHECK_OK(sy_node_set_flags(fx->scene, fx->sphere, SY_NODE_VISIBLE, &e), e);
    CHECK_OK(sy_camera_create(fx->scene, "cam", &c, &e), e);
    sy_camera_data cd = {.projection = SY_PROJECTION_PERSPECTIVE, .yfov = 0.6f, .aspect = 1.0f, .znear = 0.1f};
    CHECK_OK(sy_camera_set(fx->scene, c, &cd, &e), e);
    CHECK_OK(sy_node_create(fx->scene, "camera", &fx->cam, &e), e);
    const float t[3] = {0, 0, 5}, q[4] = {0, 0, 0, 1}, one[3] = {1, 1, 1};
    CHECK_OK(sy_node_set_trs(fx->scene, fx->cam, t, q, one, &e), e);
    CHECK_OK(sy_node_set_camera(fx->scene, fx->cam, c, &e), e);
    CHECK_OK(sy_scene_commit(fx->scene, NULL, &e), e);
    return 0;
}

static int render(fixture *fx, sy_context_pool *pool, const char *backend, const char *params, sy_layer *out,
                  sy_camera_view *view)
{
    sy_error e = {0};
    sy_window *win = NULL;
    sy_viewport *vp = NULL;
    sy_viewport_desc vd = {.root = fx->sphere, .camera = fx->cam, .backend = backend, .params = params};
    CHECK_OK(sy_window_create(W, H, &win, &e), e);
    CHECK_OK(sy_window_add_viewport(win, &vd, &vp, &e), e);
    if (view) CHECK_OK(sy_viewport_camera_view(vp, fx->scene, W, H, view, &e), e);
    CHECK_OK(sy_layer_create(W, H, out, &e), e);
    sy_window_render_opts ro = {0};
    CHECK_OK(sy_window_render(win, fx->scene, pool, &ro, out, &e), e);
    sy_window_destroy(win);
    return 0;
}

/* normal decoded from pixel i */
static void decoded(const sy_layer *l, size_t i, float n[3])
{
    for (int k = 0; k < 3; ++k) n[k] = 2.0f * l->rgba[i * 4 + k] - 1.0f;
}

int main(void)
{
    sy_error e = {0};
    CHECK_OK(sy_mediators_register_builtin(&e), e);
    const sy_mediator_class *cls = sy_mediator_find("normals");
    CHECK_MSG(cls != NULL, "the normals back-end is not registered: the generated registration list misses it");
    CHECK(cls->caps == (SY_CAP_DEPTH | SY_CAP_TILES | SY_CAP_ANALYSIS));

    fixture fx = {0};
    CHECK(build(&fx) == 0);
    sy_context_pool *pool = NULL;
    CHECK_OK(sy_context_pool_create(&pool, &e), e);
    sy_layer n = {0}, w = {0};
    sy_camera_view view;
    CHECK(render(&fx, pool, "normals", NULL, &n, &view) == 0);
    CHECK(render(&fx, pool, "whitted", "spp=1", &w, NULL) == 0);

    /* 2. normals against the analytic sphere, depth and coverage against whitted */
    size_t covered = 0;
    double worst = 1.0, depth_err = 0;
    for (uint32_t y = 0; y < H; ++y)
        for (uint32_t x = 0; x < W; ++x) {
            size_t i = (size_t)y * W + x;
            if (!isfinite(n.depth[i])) continue;
            covered++;
            float u = view.window[0] + (x + 0.5f) / W * (view.window[1] - view.window[0]);
            float v = view.window[3] - (y + 0.5f) / H * (view.window[3] - view.window[2]);
            float p[3] = {u * n.depth[i], v * n.depth[i], 5.0f - n.depth[i]}; /* camera at z=5, unrotated */
            float len = sqrtf(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]), nn[3];
            decoded(&n, i, nn);
            float nl = sqrtf(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2]);
            double c = (p[0] * nn[0] + p[1] * nn[1] + p[2] * nn[2]) / (len * nl);
            if (c < worst) worst = c;
            if (isfinite(w.depth[i])) {
                double de = fabs(n.depth[i] - w.depth[i]) / w.depth[i];
                if (de > depth_err) depth_err = de;
            }
        }
    double iou = 0;
    CHECK_OK(sy_layer_coverage_iou(&n, &w, &iou, &e), e);
    size_t ci = (size_t)(H / 2) * W + W / 2;
    printf("sphere: %zu pixels covered, worst normal %.2f degrees from the analytic one, depth error %.2g, "
           "IoU with whitted %.4f, centre (%.3f %.3f %.3f)\n",
           covered, acos(worst) * 180.0 / 3.14159265, depth_err, iou, n.rgba[ci * 4], n.rgba[ci * 4 + 1],
           n.rgba[ci * 4 + 2]);
    CHECK(covered > 500 && covered < W * H); /* the sphere fills part of the view */
    CHECK(worst > cos(8.0 * 3.14159265 / 180.0));
    CHECK(depth_err < 1e-3);
    CHECK(iou >= 0.99);
    CHECK(n.rgba[ci * 4 + 2] > 0.97f); /* the centre faces the camera: +Z */

    /* 3. incremental: the sphere moves +X by 0.5; the centre pixel now sees its left side */
    const float t[3] = {0.5f, 0, 0}, q[4] = {0, 0, 0, 1}, one[3] = {1, 1, 1};
    CHECK_OK(sy_node_set_trs(fx.scene, fx.sphere, t, q, one, &e), e);
    CHECK_OK(sy_scene_commit(fx.scene, NULL, &e), e);
    sy_layer moved = {0};
    CHECK(render(&fx, pool, "normals", NULL, &moved, NULL) == 0);
    float nc[3];
    decoded(&moved, ci, nc);
    printf("moved +X: centre normal (%.3f %.3f %.3f)\n", nc[0], nc[1], nc[2]);
    CHECK(nc[0] < -0.3f);
    CHECK(sy_context_pool_size(pool) == 2); /* the same contexts, synced incrementally */

    /* 4. sub-rectangle and parameters */
    sy_context *ctx = NULL;
    CHECK_OK(sy_context_pool_get(pool, fx.scene, "normals", NULL, fx.sphere.id, &ctx, &e), e);
    sy_render_request req = {.camera = view, .full_width = W, .full_height = H, .rect_x = 10, .rect_y = 20, .rect_w = 30,
                             .rect_h = 17};
    sy_layer part = {0};
    CHECK_OK(sy_layer_create(30, 17, &part, &e), e);
    CHECK_OK(sy_context_render(ctx, &req, &part, &e), e);
    for (uint32_t y = 0; y < 17; ++y)
        for (uint32_t x = 0; x < 30; ++x)
            CHECK(memcmp(&part.rgba[((size_t)y * 30 + x) * 4], &moved.rgba[((size_t)(y + 20) * W + x + 10) * 4],
                         4 * sizeof(float)) == 0);
    sy_params bad;
    CHECK_OK(sy_params_parse("spp=4", &bad, &e), e);
    sy_context *bc = NULL;
    CHECK_ERR(sy_context_create(fx.scene, "normals", &bad, 0, &bc, &e), SY_ERR_INVALID_ARGUMENT, e);
    CHECK(strstr(e.message, "spp") != NULL);

    sy_layer_destroy(&n), sy_layer_destroy(&w), sy_layer_destroy(&moved), sy_layer_destroy(&part);
    sy_context_pool_destroy(pool);
    sy_scene_destroy(fx.scene);
    printf("backend_normals: ok\n");
    return 0;
}
