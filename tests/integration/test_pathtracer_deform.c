/* test_pathtracer_deform.c — the path tracer's temporal reuse follows deforming meshes (per-vertex
 * motion, mediators/rt/sy_mediator_rt_filter.c ">>per-vertex motion" and "object motion").
 *
 * In front of a checkered wall (two greys, unit squares, z = 0), lit by the default studio
 * environment (no lights: noisy at 1 sample), two deforming meshes, both in red and green stripes
 * 0.125 wide (about 3 pixels):
 *   - a skinned bar (2 x 0.4 at z = 0.4, a 32 x 4 grid) on two joints: the first at its left end, the second at
 *     its middle (a child of the first); the vertices left of x = -0.25 follow the first, those right
 *     of 0.25 the second, blended between; the first turns -0.03 rad per frame and the second 0.09
 *     (the bar bends; its tip moves about 2 pixels a frame). Its node's own transform is ignored
 *     (glTF skins): the instance keeps the identity, only the vertices move;
 *   - a morphing patch (1.2 x 0.5 at z = 0.25, 24 x 5): one target shifts every vertex 0.6 + 0.3 x
 *     sideways and 0.25 x^2 up, its weight growing 0.1 per frame, while the node (turned 0.1 rad about z) also
 *     slides 0.02 up per frame: the motion is the morph's and the matrix's together.
 * A still camera, 1 sample per pixel per frame at 64 x 48, 16 frames, temporal=1; each frame is
 * rendered by three contexts of the same scene: temporal_deform=1 (per-vertex motion),
 * temporal_deform=0 (the rigid motion only, as before: the bar's pixels get no motion, the patch
 * the matrix's alone) and a 256-sample reference without temporal reuse. relMSE = mean (x - ref)^2 /
 * (ref^2 + 0.01) over the RGB of each mesh's inner pixels (the reference's object_id plane, 3 x 3
 * neighbourhood inside it) and of the wall's, over frames 6..15:
 *   - each deforming mesh: at least 2x lower with per-vertex motion than without;
 *   - the wall: not worse (at most 1.1x without);
 *   - the frames with it count the deformed pixels given per-vertex motion; without it none.
 * Then the meshes stop deforming and the camera pans: the frames carry no per-vertex motion (the
 * earlier poses were dropped), and turning temporal_deform off and on live changes nothing else.
 * Last, a skin loaded from glTF (the Khronos CesiumMan of ../shared/testdata; that part is skipped
 * with the reason when absent) walking under a still camera: every frame after the first gets
 * per-vertex motion on the figure, none with temporal_deform=0, and the two contexts' images differ
 * only where the figure is (the background's pixels are the same bit for bit).
 * Prints the numbers per frame. */
#include "it_util.h"
#include "it_temporal.h"
#include "sy_anim.h"
#include "sy_mediator_rt.h"

typedef struct fixture {
    it_temporal_rig rig; /* its scene, root, window and the pools: 0 the motion on, 1 off, 2 reference */
    sy_node wall, bar, j0, j1, patch, cam_node;
} fixture;

/* A tube of radius r along x over [x0, x1] about the axis (y = 0, z = 0) + (0, yc, zc), nx x na
 * cells, in stripes of `stripe` along x: two primitives (red and green cells, each cell with its own
 * four vertices so the stripes are sharp), smooth normals. Its shading varies around it (the studio
 * environment lights it from above): a surface moved across its axis shows other illumination at a
 * pixel, which the temporal filter's demodulated history tells apart (a flat, evenly lit surface
 * would not: its illumination is the same whichever stripe is under a pixel). skin: the bar's
 * joints and weights (0 left of x = -0.25, 1 right of 0.25, blended between); morph: one target
 * (0.2 x, 0.4 + 0.3 x, 0). */
static sy_mesh tube(sy_scene *s, const char *name, float x0, float x1, float yc, float zc, float r, int nx, int na,
                    float stripe, const sy_material rg[2], bool skin, bool morph)
{
    sy_primitive prims[2];
    for (int k = 0; k < 2; ++k) {
        size_t cap = (size_t)nx * na * 4;
        float *pos = malloc(cap * 3 * sizeof(float)), *nrm = malloc(cap * 3 * sizeof(float));
        float *wts = malloc(cap * 2 * sizeof(float)), *dp = malloc(cap * 3 * sizeof(float));
        uint32_t *jts = malloc(cap * 2 * sizeof(uint32_t)), *idx = malloc((size_t)nx * na * 6 * sizeof(uint32_t));
        uint32_t nv = 0, ni = 0;
        for (int i = 0; i < nx; ++i) {
            float xa = x0 + (x1 - x0) * (float)i / (float)nx, xb = x0 + (x1 - x0) * (float)(i + 1) / (float)nx;
            if ((int)floorf((0.5f * (xa + xb) - x0) / stripe) % 2 != k) continue;
            for (int j = 0; j < na; ++j) {
                float ta = 6.2831853f * (float)j / (float)na, tb = 6.2831853f * (float)(j + 1) / (float)na;
                const float c[4][2] = {{xa, ta}, {xb, ta}, {xb, tb}, {xa, tb}};
                for (int v = 0; v < 4; ++v) {
                    float x = c[v][0], cy = cosf(c[v][1]), sz = sinf(c[v][1]);
                    float *p = pos + 3 * nv, *n = nrm + 3 * nv, *d = dp + 3 * nv;
                    p[0] = x, p[1] = yc + r * cy, p[2] = zc + r * sz, n[0] = 0, n[1] = cy, n[2] = sz;
                    float w1 = x <= -0.25f ? 0.0f : x >= 0.25f ? 1.0f : (x + 0.25f) / 0.5f;
                    jts[2 * nv] = 0, jts[2 * nv + 1] = 1, wts[2 * nv] = 1.0f - w1, wts[2 * nv + 1] = w1;
                    d[0] = 0.2f * x, d[1] = 0.45f + 0.2f * x, d[2] = 0.0f;
                    ++nv;
                }
                const uint32_t q[6] = {nv - 4, nv - 2, nv - 3, nv - 4, nv - 1, nv - 2};
                for (int t = 0; t < 6; ++t) idx[ni++] = q[t];
            }
        }
        memset(&prims[k], 0, sizeof prims[k]);
        prims[k].positions = it_blob(pos, nv * 3 * sizeof(float));
        prims[k].normals = it_blob(nrm, nv * 3 * sizeof(float));
        prims[k].indices = it_blob(idx, ni * sizeof(uint32_t));
        if (skin) {
            prims[k].joints = it_blob(jts, nv * 2 * sizeof(uint32_t));
            prims[k].weights = it_blob(wts, nv * 2 * sizeof(float));
        }
        if (morph) prims[k].target_positions = it_blob(dp, nv * 3 * sizeof(float));
        prims[k].material = rg[k];
        free(pos), free(nrm), free(wts), free(dp), free(jts), free(idx);
    }
    sy_mesh m;
    MUST(sy_mesh_create(s, name, &m, err));
    MUST(sy_mesh_set_primitives(s, m, prims, 2, err));
    for (int k = 0; k < 2; ++k) sy_primitive_release(&prims[k]);
    return m;
}

static void rot_z(sy_scene *s, sy_node n, float x, float y, float z, float a)
{
    const float t[3] = {x, y, z}, q[4] = {0, 0, sinf(0.5f * a), cosf(0.5f * a)}, one[3] = {1, 1, 1};
    MUST(sy_node_set_trs(s, n, t, q, one, err));
}

/* The pose at frame f (frames past `stop` keep stop's pose). */
static void pose(fixture *fx, int f)
{
    float ph = sinf(0.4f * (float)f);
    rot_z(fx->rig.s, fx->j0, -1.0f, 0.45f + 0.3f * ph, 0.6f, -0.15f * ph);
    rot_z(fx->rig.s, fx->j1, 1.0f, 0.0f, 0.0f, 0.5f * ph);
    float w = 0.9f * ph;
    MUST(sy_node_set_weights(fx->rig.s, fx->patch, &w, 1, err));
    rot_z(fx->rig.s, fx->patch, -0.45f + 0.02f * (float)f, -0.35f, 0.0f, 0.1f);
}

static void build(fixture *fx)
{
    memset(fx, 0, sizeof *fx);
    sy_material grey[2], rg[2];
    sy_mesh wall = it_rig_scene(&fx->rig, grey, rg);
    sy_scene *s = fx->rig.s;
    /* the bar in its bind pose (world space, as glTF skins): x -1 .. 1 about y 0.45, z 0.6 */
    sy_mesh bar = tube(s, "bar", -1.0f, 1.0f, 0.45f, 0.6f, 0.18f, 32, 16, 0.5f, rg, true, false);
    /* the patch about its node: x -0.6 .. 0.6 about y 0, z 0.2 (in front of the wall, behind the bar) */
    sy_mesh patch = tube(s, "patch", -0.6f, 0.6f, 0.0f, 0.2f, 0.18f, 24, 16, 0.6f, rg, false, true);
    MUST(sy_node_create(s, "wall", &fx->wall, err));
    MUST(sy_node_set_mesh(s, fx->wall, wall, err));
    MUST(sy_node_create(s, "joint 0", &fx->j0, err));
    MUST(sy_node_create(s, "joint 1", &fx->j1, err));
    MUST(sy_node_add_child(s, fx->j0, fx->j1, err));
    MUST(sy_node_create(s, "bar", &fx->bar, err));
    MUST(sy_node_set_mesh(s, fx->bar, bar, err));
    /* inverse bind matrices: the joints' world matrices in the bind pose are translations to
     * (-1, 0.45, 0.6) and (0, 0.45, 0.6) (the pose of frame 0) */
    sy_mat4 ibm[2] = {sy_mat4_identity(), sy_mat4_identity()};
    ibm[0].m[12] = 1.0f, ibm[0].m[13] = -0.45f, ibm[0].m[14] = -0.6f;
    ibm[1].m[12] = 0.0f, ibm[1].m[13] = -0.45f, ibm[1].m[14] = -0.6f;
    const sy_node joints[2] = {fx->j0, fx->j1};
    MUST(sy_node_set_skin(s, fx->bar, joints, ibm, 2, fx->j0, err));
    MUST(sy_node_create(s, "patch", &fx->patch, err));
    MUST(sy_node_set_mesh(s, fx->patch, patch, err));
    pose(fx, 0);
    fx->cam_node = it_camera_node(s, "cam", 0, 0, 2.5f, 0.8f);
    sy_node kids[5] = {fx->wall, fx->j0, fx->bar, fx->patch, fx->cam_node};
    for (int i = 0; i < 5; ++i) MUST(sy_node_add_child(s, fx->rig.root, kids[i], err));
    MUST(sy_scene_commit(s, NULL, err));
    it_rig_init(&fx->rig, W, H, fx->cam_node, "temporal_deform");
}

static const char *const class_name[3] = {"wall", "skinned bar", "morphing patch"};

/* CesiumMan walking (frames of 1/24 s) under a still camera, 1 spp a frame, temporal reuse with and
 * without per-vertex motion. */
static void loaded_skin(void)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/gltf/CesiumMan/glTF/CesiumMan.gltf", SY_TESTDATA_DIR);
    if (access(path, R_OK) != 0) {
        printf("CesiumMan part skipped: test data %s not found\n", path);
        return;
    }
    sy_gltf_info info;
    sy_scene *s = it_load_gltf(path, &info);
    MUST(sy_scene_set_time(s, (sy_animation){0}, 0.0, err));
    MUST(sy_scene_commit(s, NULL, err));
    sy_camera_view view = it_view_down_z(3.2f, 0.27f); /* from the side, as integration_skin */
    view.camera_to_world.m[13] = 0.72f;
    view.window[0] = -0.27f * (float)W / (float)H, view.window[1] = 0.27f * (float)W / (float)H;
    sy_context *ctx[2];
    for (int k = 0; k < 2; ++k) {
        MUST(sy_context_create(s, "pathtracer", NULL, info.root.id, &ctx[k], err));
        sy_params p = {0};
        MUST(sy_params_set(&p, "temporal", "1", err));
        MUST(sy_params_set(&p, "temporal_deform", k ? "0" : "1", err));
        MUST(sy_context_set_filter(ctx[k], "none", &p, err));
    }
    for (int f = 0; f < 4; ++f) {
        MUST(sy_scene_set_time(s, (sy_animation){0}, (double)f / 24.0, err));
        MUST(sy_scene_commit(s, NULL, err));
        sy_layer img[2];
        sy_mediator_rt_filter_info fi[2];
        for (int k = 0; k < 2; ++k) {
            MUST(sy_context_sync(ctx[k], err));
            MUST(it_render_full(ctx[k], &view, W, H, 1, &img[k], err));
            sy_mediator_rt_filter_info_get(sy_context_state(ctx[k]), &fi[k]);
        }
        size_t figure = 0, differ = 0, differ_outside = 0;
        for (size_t i = 0; i < (size_t)W * H; ++i) {
            bool in = isfinite(img[0].depth[i]) || isfinite(img[1].depth[i]);
            bool d = memcmp(img[0].rgba + 4 * i, img[1].rgba + 4 * i, 4 * sizeof(float)) != 0;
            figure += in, differ += d;
            differ_outside += d && !in;
        }
        printf("CesiumMan frame %d: %llu pixels with per-vertex motion (%zu figure pixels), %llu without; %zu pixels "
               "differ, %zu of them off the figure\n",
               f, (unsigned long long)fi[0].temporal_deformed_pixels, figure,
               (unsigned long long)fi[1].temporal_deformed_pixels, differ, differ_outside);
        if (f > 0) {
            EXPECT_MSG(fi[0].temporal_last && fi[0].temporal_deformed_pixels > figure / 4,
                       "CesiumMan frame %d: estimate %d, %llu pixels with per-vertex motion of %zu", f, fi[0].temporal_last,
                       (unsigned long long)fi[0].temporal_deformed_pixels, figure);
            EXPECT_MSG(fi[1].temporal_last && fi[1].temporal_deformed_pixels == 0,
                       "CesiumMan frame %d without per-vertex motion: estimate %d, %llu deformed pixels", f,
                       fi[1].temporal_last, (unsigned long long)fi[1].temporal_deformed_pixels);
        }
        if (f > 1) EXPECT_MSG(differ > 0, "CesiumMan frame %d: the per-vertex motion changed no pixel", f);
        EXPECT_MSG(differ_outside == 0, "CesiumMan frame %d: %zu pixels off the figure differ", f, differ_outside);
        for (int k = 0; k < 2; ++k) sy_layer_destroy(&img[k]);
    }
    for (int k = 0; k < 2; ++k) sy_context_release(ctx[k]);
    sy_gltf_info_free(&info);
    sy_scene_destroy(s);
}

int main(void)
{
    it_register();
    fixture fx;
    build(&fx);
    double sum[2][3] = {{0}}, cnt[2][3] = {{0}}; /* [per-vertex on/off][wall/bar/patch] */
    for (int f = 0; f < FRAMES; ++f) {
        pose(&fx, f);
        MUST(sy_scene_commit(fx.rig.s, NULL, err));
        for (int k = 0; k < 2; ++k) {
            it_rig_render(&fx.rig, k, 1);
            EXPECT(sy_layer_count_nonfinite(&fx.rig.img[k]) == 0);
            sy_mediator_rt_filter_info fi;
            sy_mediator_rt_filter_info_get(sy_context_state(it_rig_ctx(&fx.rig, k)), &fi);
            if (f > 0 && k == 0)
                EXPECT_MSG(fi.temporal_last && fi.temporal_deformed_pixels > 100,
                           "frame %d: estimate %d, %llu pixels with per-vertex motion", f, fi.temporal_last,
                           (unsigned long long)fi.temporal_deformed_pixels);
            if (f > 0 && k == 1)
                EXPECT_MSG(fi.temporal_last && fi.temporal_deformed_pixels == 0 && fi.temporal_moving_pixels > 0,
                           "frame %d without per-vertex motion: estimate %d, %llu deformed, %llu moving pixels", f,
                           fi.temporal_last, (unsigned long long)fi.temporal_deformed_pixels,
                           (unsigned long long)fi.temporal_moving_pixels);
        }
        it_rig_render(&fx.rig, 2, REF_SPP);
        sy_aovs a;
        MUST(sy_context_aovs(it_rig_ctx(&fx.rig, 2), &a, err));
        const float *ids = NULL;
        for (uint32_t p = 0; p < a.count; ++p)
            if (!strcmp(a.planes[p].name, "object_id")) ids = a.planes[p].data;
        EXPECT(ids && a.width == W && a.height == H);
        /* per pixel: 0 the wall, 1 the bar, 2 the patch (whose 3 x 3 neighbourhood is that object
         * too: the silhouettes' pixels measure the filter's edges), 3 counted nowhere */
        uint8_t mask[W * H];
        size_t px[3] = {0};
        const float want[3] = {(float)fx.wall.id, (float)fx.bar.id, (float)fx.patch.id};
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                int cls = 3;
                for (int c = 0; c < 3 && ids; ++c) {
                    bool all = true;
                    for (int dy = -1; dy <= 1; ++dy)
                        for (int dx = -1; dx <= 1; ++dx) {
                            int xx = x + dx < 0 ? 0 : x + dx >= W ? W - 1 : x + dx, yy = y + dy < 0 ? 0 : y + dy >= H ? H - 1 : y + dy;
                            all = all && ids[yy * W + xx] == want[c];
                        }
                    if (all) cls = c;
                }
                mask[y * W + x] = (uint8_t)cls;
                if (cls < 3) px[cls]++;
            }
        sy_aovs_free(&a);
        EXPECT_MSG(px[1] > 60 && px[2] > 60, "frame %d: %zu bar, %zu patch pixels", f, px[1], px[2]);
        if (f < FIRST) continue;
        double fs[2][3] = {{0}}, fc[2][3] = {{0}};
        for (int k = 0; k < 2; ++k) {
            it_rel_mse_classes(&fx.rig.img[k], &fx.rig.img[2], mask, 3, fs[k], fc[k]);
            for (int j = 0; j < 3; ++j) sum[k][j] += fs[k][j], cnt[k][j] += fc[k][j];
        }
        printf("frame %2d: relMSE bar %.4f per-vertex, %.4f rigid only; patch %.4f, %.4f; wall %.4f, %.4f (%zu, %zu, %zu px)\n",
               f, fs[0][1] / fc[0][1], fs[1][1] / fc[1][1], fs[0][2] / fc[0][2], fs[1][2] / fc[1][2], fs[0][0] / fc[0][0],
               fs[1][0] / fc[1][0], px[1], px[2], px[0]);
    }
    for (int c = 0; c < 3; ++c) {
        double on = sum[0][c] / cnt[0][c], off = sum[1][c] / cnt[1][c];
        printf("%s, frames %d..%d: relMSE %.5f with per-vertex motion, %.5f rigid only (%.2fx)\n", class_name[c], FIRST,
               FRAMES - 1, on, off, off / on);
        if (c) EXPECT_MSG(off >= 2.0 * on, "%s: relMSE %.5f with per-vertex motion, %.5f without: not 2x lower", class_name[c], on, off);
        else EXPECT_MSG(on <= 1.1 * off, "the wall: relMSE %.5f with per-vertex motion, %.5f without: worse", on, off);
    }
    /* the meshes stop; the camera pans: moving frames without per-vertex motion (the poses of the
     * meshes that stopped were dropped after the render that followed their last change) */
    for (int f = 0; f < 3; ++f) {
        sy_mat4 m = sy_mat4_identity();
        m.m[12] = 0.03f * (float)(f + 1), m.m[14] = 2.5f;
        sy_viewport_set_view(fx.rig.vp, &m);
        it_rig_render(&fx.rig, 0, 1);
        sy_mediator_rt_filter_info fi;
        sy_mediator_rt_filter_info_get(sy_context_state(it_rig_ctx(&fx.rig, 0)), &fi);
        EXPECT_MSG(fi.temporal_last && fi.temporal_deformed_pixels == 0 && fi.temporal_moving_pixels == 0,
                   "pan %d after the meshes stopped: estimate %d, %llu deformed, %llu moving pixels", f, fi.temporal_last,
                   (unsigned long long)fi.temporal_deformed_pixels, (unsigned long long)fi.temporal_moving_pixels);
    }
    /* live: off, a deformation (rigid only), on again, a deformation (per vertex again) */
    for (int step = 0; step < 2; ++step) {
        sy_params p = {0};
        MUST(sy_params_set(&p, "temporal_deform", step ? "1" : "0", err));
        MUST(sy_context_set_filter(it_rig_ctx(&fx.rig, 0), NULL, &p, err));
        pose(&fx, FRAMES + step);
        MUST(sy_scene_commit(fx.rig.s, NULL, err));
        it_rig_render(&fx.rig, 0, 1);
        sy_mediator_rt_filter_info fi;
        sy_mediator_rt_filter_info_get(sy_context_state(it_rig_ctx(&fx.rig, 0)), &fi);
        EXPECT_MSG(fi.temporal_last && (fi.temporal_deformed_pixels > 0) == (step == 1),
                   "temporal_deform=%d live: estimate %d, %llu deformed pixels", step, fi.temporal_last,
                   (unsigned long long)fi.temporal_deformed_pixels);
    }
    it_rig_destroy(&fx.rig);
    loaded_skin();
    return sy_check_finish("integration_pathtracer_deform");
}
