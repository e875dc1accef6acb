/* test_rt_mediator_motion.c — the rt mediator's moving cameras (sy_context_motion_camera, issue 35:
 * a stereo pair's eyes each move with their own views) through a context of each class ("whitted",
 * "pathtracer"), on one quad that nothing moves:
 *   - a request whose camera is the open of a moving camera given blurs (differs from the sharp
 *     image), and bit for bit as it does with that camera alone: a second camera (another open, the
 *     other eye) changes nothing for the first, and each eye renders as when it was the only one;
 *   - the same open given again replaces its steps (the last close counts);
 *   - up to SY_MOTION_CAMERAS_MAX cameras, one more is SY_ERR_INVALID_ARGUMENT; before the motion
 *     is open, SY_ERR_INVALID_ARGUMENT. */
#include "../integration/it_util.h"

#define W 32
#define H 24

/* the view looking down -Z from (x, 0, 3) */
static sy_camera_view view_at(float x)
{
    sy_camera_view v = it_view_down_z(3.0f, 0.4f);
    v.window[2] = -0.3f, v.window[3] = 0.3f;
    v.camera_to_world.m[12] = x;
    return v;
}

/* Opens a motion (the scene as it is: nothing moves, native), gives it the n cameras open[i] ->
 * close[i] and renders the view `want` into *img; the motion is ended after. */
static void render_moving(sy_context *ctx, const sy_camera_view *open, const sy_camera_view *close, int n,
                          const sy_camera_view *want, sy_layer *img)
{
    bool native = false;
    sy_context_restart(ctx); /* the path tracer from sample 0, as sy render does before a motion */
    MUST(sy_context_motion_begin(ctx, 4, err));
    MUST(sy_context_motion_open(ctx, &native, err));
    EXPECT_MSG(native, "a motion of nothing is not native");
    for (int i = 0; i < n; ++i) MUST(sy_context_motion_camera(ctx, &open[i], 2, &close[i], err));
    MUST(it_render_full(ctx, want, W, H, 0, img, err));
    sy_context_motion_end(ctx);
}

int main(void)
{
    it_register();
    sy_scene *s = it_scene();
    sy_node root, geo;
    MUST(sy_node_create(s, "root", &root, err));
    sy_material m = it_unlit(s, "white", 1.0f, 1.0f, 1.0f);
    const float quads[1][3] = {{0, 0, 0.5f}};
    sy_mesh mesh = it_quad_mesh(s, "quad", quads, &m, 1);
    MUST(sy_node_create(s, "geo", &geo, err));
    MUST(sy_node_set_mesh(s, geo, mesh, err));
    MUST(sy_node_add_child(s, root, geo, err));
    MUST(sy_scene_commit(s, NULL, err));
    sy_context_pool *pool = it_pool();
    static const char *const classes[2] = {"whitted", "pathtracer"};
    for (int k = 0; k < 2; ++k) {
        if (!sy_mediator_find(classes[k])) continue;
        sy_context *ctx;
        MUST(sy_context_pool_get(pool, s, classes[k], NULL, root.id, &ctx, err));
        /* the left and right eyes, each panning 0.3 m along x over the shutter */
        sy_camera_view open[2] = {view_at(-0.03f), view_at(0.03f)}, close[2] = {view_at(0.27f), view_at(0.33f)};
        sy_layer sharp = {0}, left_alone = {0}, right_alone = {0}, left_both = {0}, right_both = {0}, left_replaced = {0};
        sy_context_restart(ctx);
        MUST(it_render_full(ctx, &open[0], W, H, 0, &sharp, err));
        render_moving(ctx, open, close, 1, &open[0], &left_alone);
        render_moving(ctx, open + 1, close + 1, 1, &open[1], &right_alone);
        render_moving(ctx, open, close, 2, &open[0], &left_both);
        render_moving(ctx, open, close, 2, &open[1], &right_both);
        EXPECT_MSG(!it_layers_identical(&sharp, &left_alone), "%s: a moving camera's image is the sharp one", classes[k]);
        EXPECT_MSG(it_layers_identical(&left_alone, &left_both), "%s: the left eye differs with the right eye's camera given too",
                   classes[k]);
        EXPECT_MSG(it_layers_identical(&right_alone, &right_both), "%s: the right eye differs with the left eye's camera given too",
                   classes[k]);
        EXPECT_MSG(!it_layers_identical(&left_both, &right_both), "%s: both eyes render one image", classes[k]);
        /* the same open again: its steps replaced (a close far away first, then the left eye's) */
        sy_camera_view twice_open[2] = {open[0], open[0]}, twice_close[2] = {view_at(2.0f), close[0]};
        render_moving(ctx, twice_open, twice_close, 2, &open[0], &left_replaced);
        EXPECT_MSG(it_layers_identical(&left_alone, &left_replaced), "%s: giving the same open again did not replace its steps",
                   classes[k]);
        /* limits: SY_MOTION_CAMERAS_MAX cameras, then an error; none before the motion is open */
        sy_error e = {0};
        EXPECT_MSG(sy_context_motion_camera(ctx, &open[0], 2, &close[0], &e) == SY_ERR_INVALID_ARGUMENT,
                   "%s: a moving camera outside a motion was taken", classes[k]);
        bool native = false;
        MUST(sy_context_motion_begin(ctx, 4, err));
        MUST(sy_context_motion_open(ctx, &native, err));
        for (int i = 0; i < SY_MOTION_CAMERAS_MAX; ++i) {
            sy_camera_view o = view_at(0.1f * (float)i), c = view_at(0.1f * (float)i + 0.3f);
            MUST(sy_context_motion_camera(ctx, &o, 2, &c, err));
        }
        sy_camera_view o = view_at(-1.0f), c = view_at(-0.7f);
        memset(&e, 0, sizeof e);
        sy_result r = sy_context_motion_camera(ctx, &o, 2, &c, &e);
        EXPECT_MSG(r == SY_ERR_INVALID_ARGUMENT && strstr(e.message, "moving cameras"),
                   "%s: camera %d of a motion: %s (%s), expected invalid argument naming the limit", classes[k],
                   SY_MOTION_CAMERAS_MAX + 1, sy_result_str(r), e.message);
        sy_context_motion_end(ctx);
        printf("%s: moving cameras per eye as alone, replaced, limited to %d\n", classes[k], SY_MOTION_CAMERAS_MAX);
        sy_layer_destroy(&sharp), sy_layer_destroy(&left_alone), sy_layer_destroy(&right_alone);
        sy_layer_destroy(&left_both), sy_layer_destroy(&right_both), sy_layer_destroy(&left_replaced);
    }
    sy_context_pool_destroy(pool);
    sy_scene_destroy(s);
    return sy_check_finish("rt_mediator_motion");
}
