/* test_pathtracer_motion.c — the path tracer's temporal reuse follows moving objects (object motion,
 * mediators/rt/sy_mediator_rt_filter.c "object motion").
 *
 * A checkered wall (two greys, unit squares) at z = 0 and a ball of radius 0.35 in six red and green
 * meridian stripes in front of it, sliding 0.08 per frame in x and 0.04 towards the camera (about 2
 * pixels a frame), lit by the default studio environment (no lights: noisy at 1 sample); 1 sample
 * per pixel per frame at 64 x 48, 16 frames, temporal=1, (a) a still camera, (b) a camera panning
 * 0.03 per frame. Each frame is rendered by three contexts of the same scene: temporal_motion=1
 * (the object motion), temporal_motion=0 (camera motion only, as before: a still camera restarts
 * the accumulation on every move and shows one sample per pixel; a panning camera reprojects the
 * ball's history from where the ball no longer is, and rejects or mixes it) and a 256-sample
 * reference without temporal reuse. relMSE = mean (x - ref)^2 / (ref^2 + 0.01) over the RGB of the
 * ball's pixels (the reference's object_id plane; only those whose 3 x 3 neighbourhood is the ball:
 * the silhouette's pixels measure the filter's edges) and of the wall's, over frames 6..15 (the
 * first six build the history):
 *   - the ball: at least 2x lower with the motion than without, in each case (measured: still
 *     camera 0.0236 against 0.343, 14.5x; panning 0.0305 against 0.0738, 2.4x);
 *   - the wall: not worse (at most 1.1 x without);
 *   - the frames with the motion show the estimate (temporal_last) with moving pixels counted;
 *     without it the still camera's frames are the plain accumulation.
 * Then the camera and the ball rest: the accumulation continues, blended with the estimate, and
 * from 64 samples on is the plain accumulation bit for bit (a converged still is never changed); a
 * material change under it restarts the accumulation, shown alone (no estimate), and a move after
 * that is a moving frame again.
 * Prints the numbers per frame. */
#include "it_util.h"
#include "it_temporal.h"
#include "sy_mediator_rt.h"

typedef struct fixture {
    it_temporal_rig rig; /* its scene, root, window and the pools: 0 the motion on, 1 off, 2 reference */
    sy_node wall, ball, cam_node;
    sy_material light_grey;
} fixture;

/* A sphere of radius 0.35 about the origin (24 x 16 segments, smooth normals) in six meridian
 * stripes, red and green by turns: one primitive per stripe. */
static sy_mesh sphere(sy_scene *s, const sy_material rg[2])
{
    enum { SEG = 24, RINGS = 16, STRIPES = 6, PER = SEG / STRIPES };
    sy_primitive prims[STRIPES];
    for (int k = 0; k < STRIPES; ++k) {
        float pos[(PER + 1) * (RINGS + 1) * 3], nrm[(PER + 1) * (RINGS + 1) * 3];
        uint32_t idx[PER * RINGS * 6], ni = 0;
        for (int r = 0; r <= RINGS; ++r)
            for (int j = 0; j <= PER; ++j) {
                float th = 3.14159265f * (float)r / RINGS, ph = 6.2831853f * (float)(k * PER + j) / SEG;
                float n[3] = {sinf(th) * cosf(ph), cosf(th), sinf(th) * sinf(ph)};
                for (int c = 0; c < 3; ++c) pos[3 * (r * (PER + 1) + j) + c] = 0.35f * n[c], nrm[3 * (r * (PER + 1) + j) + c] = n[c];
            }
        for (int r = 0; r < RINGS; ++r)
            for (int j = 0; j < PER; ++j) {
                uint32_t a = (uint32_t)(r * (PER + 1) + j), b = a + 1, c = a + PER + 1, d = c + 1;
                const uint32_t q[6] = {a, b, d, a, d, c};
                for (int t = 0; t < 6; ++t) idx[ni++] = q[t];
            }
        memset(&prims[k], 0, sizeof prims[k]);
        prims[k].positions = it_blob(pos, sizeof pos);
        prims[k].normals = it_blob(nrm, sizeof nrm);
        prims[k].indices = it_blob(idx, sizeof idx);
        prims[k].material = rg[k % 2];
    }
    sy_mesh m;
    MUST(sy_mesh_create(s, "ball", &m, err));
    MUST(sy_mesh_set_primitives(s, m, prims, STRIPES, err));
    for (int k = 0; k < STRIPES; ++k) sy_primitive_release(&prims[k]);
    return m;
}

/* The ball at frame f: sliding 0.08 per frame in x and 0.04 towards the camera (turned 0.3 radians
 * about the vertical). */
static void place_ball(fixture *fx, int f)
{
    float a = 0.3f;
    const float t[3] = {-0.6f + 0.08f * (float)f, 0.0f, 0.4f + 0.04f * (float)f}, q[4] = {0, sinf(0.5f * a), 0, cosf(0.5f * a)},
                one[3] = {1, 1, 1};
    MUST(sy_node_set_trs(fx->rig.s, fx->ball, t, q, one, err));
}

static void build(fixture *fx)
{
    memset(fx, 0, sizeof *fx);
    sy_material grey[2], rg[2];
    sy_mesh wall = it_rig_scene(&fx->rig, grey, rg);
    sy_scene *s = fx->rig.s;
    fx->light_grey = grey[0];
    sy_mesh ball = sphere(s, rg);
    MUST(sy_node_create(s, "wall", &fx->wall, err));
    MUST(sy_node_set_mesh(s, fx->wall, wall, err));
    MUST(sy_node_create(s, "ball", &fx->ball, err));
    MUST(sy_node_set_mesh(s, fx->ball, ball, err));
    place_ball(fx, 0);
    fx->cam_node = it_camera_node(s, "cam", 0, 0, 2.5f, 0.8f);
    sy_node kids[3] = {fx->wall, fx->ball, fx->cam_node};
    for (int i = 0; i < 3; ++i) MUST(sy_node_add_child(s, fx->rig.root, kids[i], err));
    MUST(sy_scene_commit(s, NULL, err));
    it_rig_init(&fx->rig, W, H, fx->cam_node, "temporal_motion");
}

/* One sequence: the ball slides; pan: the camera too. */
static void sequence(fixture *fx, bool pan)
{
    const char *name = pan ? "panning camera" : "still camera";
    double sum[2][2] = {{0}}, cnt[2][2] = {{0}}; /* [motion on/off][wall/ball] */
    for (int f = 0; f < FRAMES; ++f) {
        place_ball(fx, f);
        MUST(sy_scene_commit(fx->rig.s, NULL, err));
        sy_mat4 m = sy_mat4_identity();
        m.m[12] = pan ? -0.2f + 0.03f * (float)f : 0.0f, m.m[14] = 2.5f;
        sy_viewport_set_view(fx->rig.vp, &m);
        for (int k = 0; k < 2; ++k) {
            it_rig_render(&fx->rig, k, 1);
            EXPECT(sy_layer_count_nonfinite(&fx->rig.img[k]) == 0);
            sy_mediator_rt_filter_info fi;
            sy_mediator_rt_filter_info_get(sy_context_state(it_rig_ctx(&fx->rig, k)), &fi);
            if (f > 0 && k == 0)
                EXPECT_MSG(fi.temporal_last && fi.temporal_moving_pixels > 0, "%s frame %d: estimate %d, moving pixels %llu",
                           name, f, fi.temporal_last, (unsigned long long)fi.temporal_moving_pixels);
            if (f > 0 && k == 1)
                EXPECT_MSG(fi.temporal_last == pan && fi.temporal_moving_pixels == 0,
                           "%s frame %d without object motion: estimate %d", name, f, fi.temporal_last);
        }
        it_rig_render(&fx->rig, 2, REF_SPP);
        sy_aovs a;
        MUST(sy_context_aovs(it_rig_ctx(&fx->rig, 2), &a, err));
        const float *ids = NULL;
        for (uint32_t p = 0; p < a.count; ++p)
            if (!strcmp(a.planes[p].name, "object_id")) ids = a.planes[p].data;
        EXPECT(ids && a.width == W && a.height == H);
        uint8_t mask[W * H];
        size_t ball_px = 0;
        /* the ball's pixels whose 3 x 3 neighbourhood is the ball too (its silhouette's pixels, half wall,
         * measure the filter's edges, not the reuse); 2: the ball's silhouette (counted nowhere) */
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                int in = 0, all = 0;
                for (int dy = -1; dy <= 1; ++dy)
                    for (int dx = -1; dx <= 1; ++dx) {
                        int xx = x + dx < 0 ? 0 : x + dx >= W ? W - 1 : x + dx, yy = y + dy < 0 ? 0 : y + dy >= H ? H - 1 : y + dy;
                        in += ids && ids[yy * W + xx] == (float)fx->ball.id;
                        ++all;
                    }
                mask[y * W + x] = in == all ? 1 : in ? 2 : 0;
                ball_px += in == all;
            }
        sy_aovs_free(&a);
        EXPECT_MSG(ball_px > 80, "%s frame %d: %zu ball pixels", name, f, ball_px);
        if (f < FIRST) continue;
        double fs[2][2] = {{0}}, fc[2][2] = {{0}};
        for (int k = 0; k < 2; ++k) {
            it_rel_mse_classes(&fx->rig.img[k], &fx->rig.img[2], mask, 2, fs[k], fc[k]);
            for (int j = 0; j < 2; ++j) sum[k][j] += fs[k][j], cnt[k][j] += fc[k][j];
        }
        printf("%s frame %2d: ball relMSE %.4f with object motion, %.4f camera only; wall %.4f, %.4f\n", name, f,
               fs[0][1] / fc[0][1], fs[1][1] / fc[1][1], fs[0][0] / fc[0][0], fs[1][0] / fc[1][0]);
    }
    double ball[2], wall[2];
    for (int k = 0; k < 2; ++k) ball[k] = sum[k][1] / cnt[k][1], wall[k] = sum[k][0] / cnt[k][0];
    printf("%s, frames %d..%d: ball relMSE %.5f with object motion, %.5f camera only (%.2fx); wall %.5f, %.5f\n", name,
           FIRST, FRAMES - 1, ball[0], ball[1], ball[1] / ball[0], wall[0], wall[1]);
    EXPECT_MSG(ball[1] >= 2.0 * ball[0], "%s: the ball's relMSE %.5f with motion, %.5f without: not 2x lower", name, ball[0],
               ball[1]);
    EXPECT_MSG(wall[0] <= 1.1 * wall[1], "%s: the wall's relMSE %.5f with motion, %.5f without: worse", name, wall[0],
               wall[1]);
}

int main(void)
{
    it_register();
    fixture fx;
    build(&fx);
    sequence(&fx, false);
    sequence(&fx, true);
    /* the camera and the ball rest: blended with the estimate at first, then the accumulation bit
     * for bit (from 64 samples on) */
    sy_context *ctx = it_rig_ctx(&fx.rig, 0);
    for (uint32_t k = 2; k <= 65; ++k) {
        it_rig_render(&fx.rig, 0, 1);
        sy_mediator_rt_aovs a;
        MUST(sy_mediator_rt_aovs_get(sy_context_state(ctx), &a, err));
        bool same = !memcmp(a.planes[0], fx.rig.img[0].rgba, (size_t)W * H * 4 * sizeof(float));
        EXPECT_MSG(a.samples == k, "still frame %u: %u samples", k, a.samples);
        sy_mediator_rt_aovs_free(&a);
        sy_mediator_rt_filter_info fi;
        sy_mediator_rt_filter_info_get(sy_context_state(ctx), &fi);
        EXPECT_MSG(!fi.temporal_last && same == (k >= 64), "still frame %u: estimate %d, the accumulation %d", k,
                   fi.temporal_last, same);
    }
    /* a change that is not a move (a material) under the still camera: the accumulation restarts and
     * shows alone, as before; a move after it is a moving frame again */
    sy_material_data md = *sy_material_get(fx.rig.s, fx.light_grey);
    md.name = "light grey";
    md.base_color[0] = 0.7f;
    MUST(sy_material_set(fx.rig.s, fx.light_grey, &md, err));
    for (int step = 0; step < 2; ++step) {
        if (step) place_ball(&fx, 3);
        MUST(sy_scene_commit(fx.rig.s, NULL, err));
        it_rig_render(&fx.rig, 0, 1);
        sy_mediator_rt_aovs a;
        MUST(sy_mediator_rt_aovs_get(sy_context_state(ctx), &a, err));
        bool same = !memcmp(a.planes[0], fx.rig.img[0].rgba, (size_t)W * H * 4 * sizeof(float));
        EXPECT_MSG(a.samples == 1, "after the %s: %u samples", step ? "move" : "material change", a.samples);
        sy_mediator_rt_aovs_free(&a);
        sy_mediator_rt_filter_info fi;
        sy_mediator_rt_filter_info_get(sy_context_state(ctx), &fi);
        EXPECT_MSG(fi.temporal_last == (step == 1) && same == (step == 0),
                   "after the %s: estimate %d, the accumulation %d", step ? "move" : "material change", fi.temporal_last,
                   same);
    }
    it_rig_destroy(&fx.rig);
    return sy_check_finish("integration_pathtracer_motion");
}
