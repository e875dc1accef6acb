/* test_clip_cap.c — section caps (sy_viewport_set_clip_cap, issue 37 item 2): the cut faces of
 * closed meshes filled in one colour, in every back-end that cuts.
 *
 *   1. Bad colours: NaN, negative, above 1: refused by sy_viewport_set_clip_cap and
 *      sy_camera_view_check with SY_ERR_INVALID_ARGUMENT naming the channel, the colour set before
 *      kept; NULL turns capping off.
 *   2. Which meshes are closed (sy_mirror_flat_mesh_closed): a cube wound outward (1), the same
 *      wound inward (-1), a cube with its vertices split per face (welded by position: 1), a cube
 *      missing one triangle (0), a quad (0).
 *   3. A cube cut by a plane, seen from the removed side at an angle: with capping, the pixels whose
 *      ray meets the plane inside the cube's square (worked out here, not by a back-end) are the cap
 *      colour in whitted, pathtracer and raster (>= 99 % of those a pixel away from the square's
 *      edges, none a pixel away outside them; the coverage IoU of the cap (each pixel's share of
 *      it, sum of minima over sum of maxima) >= 0.98 with the analytic one (8 x 8 rays a pixel),
 *      >= 0.99 between back-ends), their
 *      depth is the plane's (within 0.5 %); without capping none is (one sees the cube's inside);
 *      a mirrored placement of the cube (scale -1 in x) is capped the same; an open box (the cube
 *      without one triangle) is never capped. A pick of the centre pixel lands on the cap (the
 *      plane, its normal facing the eye, cap_plane 1) with capping, on the inside without.
 *      test_it_clip_cap --write DIR writes the capped
 *      images as EXR for looking at.
 *   4. Shadows see the caps: a cube cut open over a ground quad, a directional light shining into
 *      the cut: where the kept half's shadow falls the ground stays in shadow in whitted,
 *      pathtracer and raster (the cap and the kept far faces block the light; the raster's shadow
 *      maps draw the cut model with both sides), below half the lit ground, capped or not; where
 *      only the removed half shadowed it is lit (within 10 %). */
#include "it_util.h"

#include "sy_exr.h"
#include "sy_mirror_flat.h"

#define W 160
#define H 120

static const float CAP[3] = {0.9f, 0.05f, 0.6f};
#define CUT_X 0.1f /* the plane keeps x <= CUT_X */

/* ---------------------------------------------------------------- the cube */
/* The cube [-0.5, 0.5]^3: 8 corners, 12 triangles wound counter-clockwise seen from outside. */
static const float CUBE_P[8][3] = {{-0.5f, -0.5f, -0.5f}, {0.5f, -0.5f, -0.5f}, {0.5f, 0.5f, -0.5f}, {-0.5f, 0.5f, -0.5f},
                                   {-0.5f, -0.5f, 0.5f},  {0.5f, -0.5f, 0.5f},  {0.5f, 0.5f, 0.5f},  {-0.5f, 0.5f, 0.5f}};
static const uint32_t CUBE_I[36] = {0, 3, 2, 0, 2, 1, /* -z */ 4, 5, 6, 4, 6, 7, /* +z */
                                    0, 1, 5, 0, 5, 4, /* -y */ 3, 7, 6, 3, 6, 2, /* +y */
                                    0, 4, 7, 0, 7, 3, /* -x */ 1, 2, 6, 1, 6, 5 /* +x */};

/* The cube's flat description: tris of its 12 triangles (the first ones), wound in or out; split:
 * every triangle its own three vertices (24 x... 36 vertices, welded by position only). */
static void cube_flat(sy_mirror_flat_mesh *f, float *pos, uint32_t *idx, uint32_t tris, bool inward, bool split)
{
    for (uint32_t t = 0; t < tris; ++t)
        for (int k = 0; k < 3; ++k) {
            uint32_t c = CUBE_I[3 * t + (inward ? 2 - k : k)];
            if (split) {
                memcpy(pos + 3 * (3 * t + k), CUBE_P[c], sizeof CUBE_P[c]);
                idx[3 * t + k] = 3 * t + k;
            } else {
                idx[3 * t + k] = c;
            }
        }
    if (!split) memcpy(pos, CUBE_P, sizeof CUBE_P);
    *f = (sy_mirror_flat_mesh){.positions = pos, .indices = idx, .vertex_count = split ? 3 * tris : 8, .triangle_count = tris};
}

static void test_closed(void)
{
    float pos[36 * 3];
    uint32_t idx[36];
    sy_mirror_flat_mesh f;
    cube_flat(&f, pos, idx, 12, false, false);
    EXPECT_MSG(sy_mirror_flat_mesh_closed(&f) == 1, "the cube wound outward is not closed (+1): %d", sy_mirror_flat_mesh_closed(&f));
    cube_flat(&f, pos, idx, 12, true, false);
    EXPECT_MSG(sy_mirror_flat_mesh_closed(&f) == -1, "the cube wound inward is not closed (-1): %d", sy_mirror_flat_mesh_closed(&f));
    cube_flat(&f, pos, idx, 12, false, true);
    EXPECT_MSG(sy_mirror_flat_mesh_closed(&f) == 1, "the split cube (welded by position) is not closed: %d", sy_mirror_flat_mesh_closed(&f));
    cube_flat(&f, pos, idx, 11, false, false);
    EXPECT_MSG(sy_mirror_flat_mesh_closed(&f) == 0, "the cube without a triangle is closed: %d", sy_mirror_flat_mesh_closed(&f));
    const float q[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    const uint32_t qi[6] = {0, 1, 2, 0, 2, 3};
    f = (sy_mirror_flat_mesh){.positions = q, .indices = qi, .vertex_count = 4, .triangle_count = 2};
    EXPECT_MSG(sy_mirror_flat_mesh_closed(&f) == 0, "a quad is closed");
    /* two triangles over the same edge the same way (non-manifold) */
    const uint32_t twice[12] = {0, 3, 2, 0, 2, 1, 0, 3, 2, 0, 2, 1};
    cube_flat(&f, pos, idx, 12, false, false);
    f.indices = twice;
    f.triangle_count = 4;
    EXPECT_MSG(sy_mirror_flat_mesh_closed(&f) == 0, "a face drawn twice is closed");
    printf("closed: cube +1, inward -1, split +1, 11 triangles 0, quad 0, doubled face 0\n");
}

/* ---------------------------------------------------------------- 1. bad colours */
static void test_bad_colours(void)
{
    sy_viewport *vp;
    sy_viewport_desc vd = {.backend = "whitted"};
    sy_window *win = it_window(W, H, &vd, &vp);
    EXPECT_MSG(!sy_viewport_clip_cap(vp, NULL), "capping is on by default");
    MUST(sy_viewport_set_clip_cap(vp, CAP, err));
    const float bad[4][3] = {{NAN, 0, 0}, {0, -0.1f, 0}, {0, 0, 1.5f}, {INFINITY, 0, 0}};
    for (int i = 0; i < 4; ++i) {
        sy_error e = {0};
        sy_result r = sy_viewport_set_clip_cap(vp, bad[i], &e);
        EXPECT_MSG(r == SY_ERR_INVALID_ARGUMENT && strstr(e.message, "colour"), "bad colour %d: %s (%s)", i,
                   sy_result_str(r), e.message);
        if (i == 0) printf("bad cap colour: %s\n", e.message);
    }
    float got[3];
    EXPECT_MSG(sy_viewport_clip_cap(vp, got) && !memcmp(got, CAP, sizeof got), "a refused colour changed the cap");
    MUST(sy_viewport_set_clip_cap(vp, NULL, err));
    EXPECT_MSG(!sy_viewport_clip_cap(vp, NULL), "NULL did not turn capping off");
    sy_camera_view v = {.camera_to_world = sy_mat4_identity(), .window = {-1, 1, -1, 1}, .znear = 0.1f,
                        .clip_count = 1, .clip_planes = {{1, 0, 0, 0}}, .clip_cap = 1, .clip_cap_color = {0, NAN, 0}};
    sy_error e = {0};
    EXPECT_MSG(sy_camera_view_check(&v, &e) == SY_ERR_INVALID_ARGUMENT && strstr(e.message, "g = nan"),
               "sy_camera_view_check took a NaN cap colour (%s)", e.message);
    v.clip_cap_color[1] = 0.5f;
    EXPECT_MSG(sy_camera_view_check(&v, &e) == SY_OK, "sy_camera_view_check refused a good cap (%s)", e.message);
    sy_window_destroy(win);
}

/* ---------------------------------------------------------------- 3. caps in every back-end */
static sy_mat4 look_at(const float eye[3], const float target[3])
{
    float f[3] = {target[0] - eye[0], target[1] - eye[1], target[2] - eye[2]}, up[3] = {0, 1, 0};
    float l = sqrtf(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    for (int k = 0; k < 3; ++k) f[k] /= l;
    float x[3] = {f[1] * up[2] - f[2] * up[1], f[2] * up[0] - f[0] * up[2], f[0] * up[1] - f[1] * up[0]};
    l = sqrtf(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
    for (int k = 0; k < 3; ++k) x[k] /= l;
    float y[3] = {x[1] * f[2] - x[2] * f[1], x[2] * f[0] - x[0] * f[2], x[0] * f[1] - x[1] * f[0]};
    sy_mat4 m = sy_mat4_identity();
    for (int k = 0; k < 3; ++k) m.m[k] = x[k], m.m[4 + k] = y[k], m.m[8 + k] = -f[k], m.m[12 + k] = eye[k];
    return m;
}

/* The ray through (fx, fy) of the image (pixel (x, y) spans x..x+1) under the framing view's
 * projection (yfov 45 degrees, the image's aspect) placed by cam: origin and direction (not unit: its
 * camera-space z is -1). */
static void image_ray(const sy_mat4 *cam, float fx, float fy, float o[3], float d[3])
{
    const float t = tanf(0.3926991f), a = (float)W / (float)H;
    float u = (-1.0f + 2.0f * fx / W) * t * a, v = (1.0f - 2.0f * fy / H) * t;
    const float *m = cam->m;
    for (int k = 0; k < 3; ++k) o[k] = m[12 + k], d[k] = u * m[k] + v * m[4 + k] - m[8 + k];
}
static void pixel_ray(const sy_mat4 *cam, uint32_t px, uint32_t py, float o[3], float d[3])
{
    image_ray(cam, px + 0.5f, py + 0.5f, o, d);
}

/* The share of pixel (px, py) whose rays meet the plane x = CUT_X inside the cube's square (8 x 8
 * sub-pixel rays). */
static float analytic_share(const sy_mat4 *cam, int px, int py)
{
    int in = 0;
    for (int j = 0; j < 8; ++j)
        for (int i = 0; i < 8; ++i) {
            float o[3], d[3];
            image_ray(cam, px + (i + 0.5f) / 8.0f, py + (j + 0.5f) / 8.0f, o, d);
            float t = (CUT_X - o[0]) / d[0];
            in += t > 0 && fabsf(o[1] + t * d[1]) <= 0.5f && fabsf(o[2] + t * d[2]) <= 0.5f;
        }
    return in / 64.0f;
}

/* 1 where the pixel's ray meets the plane x = CUT_X inside the cube's square; with margin, only
 * where the whole 3x3 neighbourhood does (and 0 only where none of it does; -1 between). */
static int expected_cap(const sy_mat4 *cam, int px, int py, bool margin)
{
    int in = 0, n = 0;
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
            if (!margin && (dx || dy)) continue;
            int x = px + dx, y = py + dy;
            if (x < 0 || y < 0 || x >= W || y >= H) continue;
            float o[3], d[3];
            pixel_ray(cam, (uint32_t)x, (uint32_t)y, o, d);
            float t = (CUT_X - o[0]) / d[0], p1 = o[1] + t * d[1], p2 = o[2] + t * d[2];
            in += t > 0 && fabsf(p1) <= 0.5f && fabsf(p2) <= 0.5f;
            n++;
        }
    return in == n ? 1 : in == 0 ? 0 : -1;
}

/* The pixel is the cap colour (within 0.02 per channel). */
static bool is_cap(const sy_layer *l, uint32_t x, uint32_t y)
{
    const float *c = it_px(l, x, y);
    return fabsf(c[0] - CAP[0]) < 0.02f && fabsf(c[1] - CAP[1]) < 0.02f && fabsf(c[2] - CAP[2]) < 0.02f && c[3] > 0.99f;
}
/* The share of the pixel the cap covers: the grey cube's faces have red = green, the cap red - green
 * = 0.85, so an edge pixel's share is (red - green) / 0.85 (clamped to 0..1). */
static float cap_share(const sy_layer *l, uint32_t x, uint32_t y)
{
    const float *c = it_px(l, x, y);
    float f = (c[0] - c[1]) / (CAP[0] - CAP[1]);
    return f < 0.0f ? 0.0f : f > 1.0f ? 1.0f : f;
}

/* The cube's mesh in s (all 12 triangles or 11: open) of material m. */
static sy_mesh cube_mesh(sy_scene *s, uint32_t tris, sy_material m)
{
    sy_primitive p = {0};
    p.positions = it_blob(CUBE_P, sizeof CUBE_P);
    p.indices = it_blob(CUBE_I, tris * 3 * sizeof(uint32_t));
    p.material = m;
    sy_mesh mesh;
    MUST(sy_mesh_create(s, "cube", &mesh, err));
    MUST(sy_mesh_set_primitives(s, mesh, &p, 1, err));
    sy_primitive_release(&p);
    return mesh;
}

/* The scene: the cube (all 12 triangles or 11: open) at the origin, scaled by (sx, 1, 1). */
static sy_scene *cube_scene(uint32_t tris, float sx)
{
    sy_scene *s;
    MUST(sy_scene_create(&s, err));
    sy_material m;
    MUST(sy_material_create(s, "grey", &m, err));
    sy_mesh mesh = cube_mesh(s, tris, m);
    sy_node n;
    MUST(sy_node_create(s, "cube", &n, err));
    MUST(sy_node_set_mesh(s, n, mesh, err));
    const float t[3] = {0, 0, 0}, q[4] = {0, 0, 0, 1}, sc[3] = {sx, 1, 1};
    MUST(sy_node_set_trs(s, n, t, q, sc, err));
    MUST(sy_scene_commit(s, NULL, err));
    return s;
}

static void render(sy_scene *s, const char *backend, const sy_mat4 *cam, const float (*planes)[4], uint32_t nplanes,
                   const float *cap, sy_layer *out)
{
    sy_viewport *vp;
    sy_viewport_desc vd = {.backend = backend};
    sy_window *win = it_window(W, H, &vd, &vp);
    sy_viewport_set_view(vp, cam);
    MUST(sy_viewport_set_clip_planes(vp, planes, nplanes, err));
    MUST(sy_viewport_set_clip_cap(vp, cap, err));
    sy_context_pool *pool;
    MUST(sy_context_pool_create(&pool, err));
    MUST(sy_layer_create(W, H, out, err));
    sy_window_render_opts ro = {.sample_count = 16, .seed = 1};
    MUST(sy_window_render(win, s, pool, &ro, out, err));
    sy_context_pool_destroy(pool);
    sy_window_destroy(win);
}

static void test_caps(const char *write_dir)
{
    static const char *const be[3] = {"whitted", "pathtracer", "raster"};
    const float eye[3] = {1.6f, 0.8f, 1.15f}, target[3] = {0, 0, 0};
    const sy_mat4 cam = look_at(eye, target);
    const float cut[1][4] = {{-1, 0, 0, CUT_X}};
    sy_scene *cube = cube_scene(12, 1.0f), *mirrored = cube_scene(12, -1.0f), *open = cube_scene(11, 1.0f);
    static float shares[3][W * H]; /* each back-end's cap share per pixel */
    uint32_t nb = 0;
    for (int i = 0; i < 3; ++i) {
        const sy_mediator_class *cls = sy_mediator_find(be[i]);
        if (!cls || !(sy_mediator_class_caps(cls, NULL) & SY_CAP_CLIP)) continue;
        sy_layer with = {0}, without = {0}, mir = {0}, op = {0};
        render(cube, be[i], &cam, cut, 1, CAP, &with);
        render(cube, be[i], &cam, cut, 1, NULL, &without);
        render(mirrored, be[i], &cam, cut, 1, CAP, &mir);
        render(open, be[i], &cam, cut, 1, CAP, &op);
        if (write_dir) {
            char out[1200];
            snprintf(out, sizeof out, "%s/cap_%s.exr", write_dir, be[i]);
            MUST(sy_exr_write_rgba(out, (int)W, (int)H, with.rgba, with.depth, SY_EXR_PIXEL_FLOAT, err));
            snprintf(out, sizeof out, "%s/nocap_%s.exr", write_dir, be[i]);
            MUST(sy_exr_write_rgba(out, (int)W, (int)H, without.rgba, without.depth, SY_EXR_PIXEL_FLOAT, err));
        }
        uint32_t inner = 0, inner_cap = 0, inner_cap_without = 0, inner_covered_without = 0, inner_mir = 0, open_cap = 0;
        uint32_t outside_cap = 0;
        double both = 0, any = 0; /* coverage IoU with shares: sum of minima over sum of maxima */
        double depth_err = 0.0;
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                int e = expected_cap(&cam, x, y, true);
                bool c = is_cap(&with, x, y);
                float sh = cap_share(&with, x, y), ex = analytic_share(&cam, x, y);
                shares[nb][y * W + x] = sh;
                both += fminf(sh, ex);
                any += fmaxf(sh, ex);
                open_cap += is_cap(&op, x, y);
                if (e == 0) outside_cap += c;
                if (e != 1) continue;
                inner++;
                inner_cap += c;
                inner_mir += is_cap(&mir, x, y);
                inner_cap_without += is_cap(&without, x, y);
                inner_covered_without += it_px(&without, x, y)[3] > 0.99f;
                if (c && with.depth) { /* the depth of the plane point along the viewing axis */
                    float o[3], d[3];
                    pixel_ray(&cam, (uint32_t)x, (uint32_t)y, o, d);
                    float t = (CUT_X - o[0]) / d[0]; /* d's camera-space z is -1: t is the axial depth */
                    double de = fabs(with.depth[(size_t)y * W + x] - t) / t;
                    if (de > depth_err) depth_err = de;
                }
            }
        double iou = any ? (double)both / any : 0.0;
        printf("caps, %s: %u/%u inner pixels the cap colour (without capping %u, covered %u; mirrored %u), IoU with the "
               "analytic cap %.4f, cap pixels outside it %u, open box cap pixels %u, depth error %.2g\n",
               be[i], inner_cap, inner, inner_cap_without, inner_covered_without, inner_mir, iou, outside_cap, open_cap,
               depth_err);
        EXPECT_MSG(inner > 500, "the cap should cover many pixels (%u)", inner);
        EXPECT_MSG(inner_cap >= 0.99 * inner, "%s: the cut face is not covered in the cap colour (%u of %u)", be[i],
                   inner_cap, inner);
        EXPECT_MSG(inner_mir >= 0.99 * inner, "%s: the mirrored cube is not capped (%u of %u)", be[i], inner_mir, inner);
        EXPECT_MSG(iou >= 0.98, "%s: the cap is not where the plane cuts the cube (IoU %.4f)", be[i], iou);
        EXPECT_MSG(outside_cap == 0, "%s: %u cap pixels off the cut face", be[i], outside_cap);
        EXPECT_MSG(inner_cap_without == 0 && inner_covered_without >= 0.99 * inner,
                   "%s: without capping the inside should show (%u cap pixels, %u of %u covered)", be[i],
                   inner_cap_without, inner_covered_without, inner);
        EXPECT_MSG(open_cap == 0, "%s: an open box is capped (%u pixels)", be[i], open_cap);
        if (with.depth) EXPECT_MSG(depth_err < 5e-3, "%s: the cap is not at the plane's depth (%.3g)", be[i], depth_err);
        /* picks: on the cap (the plane, its normal facing the eye, cap_plane 1) with capping, on the
         * inside (a back face, no cap) without; the centre pixel sees the cut face */
        for (int capped = 0; capped < 2 && (sy_mediator_class_caps(cls, NULL) & SY_CAP_PICK); ++capped) {
            sy_viewport *vp;
            sy_viewport_desc vd = {.backend = be[i]};
            sy_window *win = it_window(W, H, &vd, &vp);
            sy_viewport_set_view(vp, &cam);
            MUST(sy_viewport_set_clip_planes(vp, cut, 1, err));
            MUST(sy_viewport_set_clip_cap(vp, capped ? CAP : NULL, err));
            sy_context_pool *pool;
            MUST(sy_context_pool_create(&pool, err));
            sy_pick_result p;
            MUST(sy_window_pick(win, cube, pool, W / 2 + 0.5, H / 2 + 0.5, &p, err));
            float o[3], d[3];
            pixel_ray(&cam, W / 2, H / 2, o, d);
            float t = (CUT_X - o[0]) / d[0];
            if (capped) {
                printf("pick on the cap, %s: (%.5f, %.5f, %.5f) normal (%.3f, %.3f, %.3f) plane %u, depth %.5f (want %.5f)\n",
                       be[i], (double)p.position[0], (double)p.position[1], (double)p.position[2], (double)p.normal[0],
                       (double)p.normal[1], (double)p.normal[2], p.cap_plane, (double)p.depth, (double)t);
                EXPECT_MSG(p.hit && p.cap_plane == 1 && fabsf(p.position[0] - CUT_X) < 1e-4f && p.normal[0] > 0.999f &&
                               fabsf(p.depth - t) < 1e-3f * t,
                           "%s: the pick is not on the cap (plane %u, x %g, normal x %g)", be[i], p.cap_plane,
                           (double)p.position[0], (double)p.normal[0]);
            } else {
                EXPECT_MSG(p.hit && p.cap_plane == 0 && p.position[0] < CUT_X - 0.01f,
                           "%s: without caps the pick should see the inside (plane %u, x %g)", be[i], p.cap_plane,
                           (double)p.position[0]);
            }
            sy_context_pool_destroy(pool);
            sy_window_destroy(win);
        }
        nb++;
        sy_layer_destroy(&with);
        sy_layer_destroy(&without);
        sy_layer_destroy(&mir);
        sy_layer_destroy(&op);
    }
    EXPECT_MSG(nb >= 2, "fewer than two back-ends cap (%u)", nb);
    for (uint32_t i = 0; i < nb; ++i)
        for (uint32_t j = i + 1; j < nb; ++j) {
            double both = 0, any = 0;
            for (size_t k = 0; k < (size_t)W * H; ++k)
                both += fminf(shares[i][k], shares[j][k]), any += fmaxf(shares[i][k], shares[j][k]);
            double v = any ? (double)both / any : 0.0;
            printf("  cap IoU %u / %u: %.4f\n", i, j, v);
            EXPECT_MSG(v >= 0.99, "back-ends %u and %u cap differently (IoU %.4f)", i, j, v);
        }
    sy_scene_destroy(cube);
    sy_scene_destroy(mirrored);
    sy_scene_destroy(open);
}

/* ---------------------------------------------------------------- 4. shadows see the caps */
/* The cube (centre z = 1) over a ground quad (z = 0, half 2), a directional light travelling
 * (-1, 0, -1) / sqrt(2) (the shadow of a point at height z falls z to its -x side), seen from
 * (0, 0, 3) straight down. The plane keeps z <= 1: the light enters the kept half of the cube
 * through the cut (the cap, when capping) and the kept far faces block it, so the ground where the
 * kept half's shadow falls (x in [-1.2, -0.8]) stays dark, with and without capping; where only the
 * removed half shadowed (x in [-1.9, -1.6]) it is lit after the cut. Every back-end that cuts. */
static void test_shadow(void)
{
    sy_scene *s;
    MUST(sy_scene_create(&s, err));
    sy_material m;
    MUST(sy_material_create(s, "grey", &m, err));
    sy_mesh cube = cube_mesh(s, 12, m);
    const float gq[1][3] = {{0, 0, 2.0f}};
    sy_mesh ground = it_quad_mesh(s, "ground", gq, &m, 1);
    sy_node nc, ng;
    MUST(sy_node_create(s, "cube", &nc, err));
    MUST(sy_node_set_mesh(s, nc, cube, err));
    it_set_translation(s, nc, 0, 0, 1.0f);
    MUST(sy_node_create(s, "ground", &ng, err));
    MUST(sy_node_set_mesh(s, ng, ground, err));
    it_sun_45(s);
    MUST(sy_scene_commit(s, NULL, err));
    sy_mat4 cam = sy_mat4_identity();
    cam.m[14] = 3.0f;
    const float cut[1][4] = {{0, 0, -1, 1.0f}};
    static const char *const be[3] = {"whitted", "pathtracer", "raster"};
    for (int i = 0; i < 3; ++i) {
        const sy_mediator_class *cls = sy_mediator_find(be[i]);
        if (!cls || !(sy_mediator_class_caps(cls, NULL) & SY_CAP_CLIP)) continue;
        sy_layer uncut = {0}, capped = {0}, open = {0};
        render(s, be[i], &cam, cut, 0, NULL, &uncut);
        render(s, be[i], &cam, cut, 1, CAP, &capped);
        render(s, be[i], &cam, cut, 1, NULL, &open);
        double lit = it_region_mean(&uncut, 3.0f, 1.0f, 1.4f, -0.3f, 0.3f, NULL);
        double kept0 = it_region_mean(&uncut, 3.0f, -1.2f, -0.8f, -0.3f, 0.3f, NULL);
        double gone0 = it_region_mean(&uncut, 3.0f, -1.9f, -1.6f, -0.3f, 0.3f, NULL);
        const sy_layer *cuts[2] = {&capped, &open};
        printf("shadow under a cut cube, %s: lit ground %.4f; the kept half's shadow %.4f uncut", be[i], lit, kept0);
        EXPECT_MSG(lit > 0.05 && kept0 < 0.5 * lit && gone0 < 0.5 * lit, "%s: no shadow of the uncut cube (%.4f, %.4f vs lit %.4f)",
                   be[i], kept0, gone0, lit);
        for (int k = 0; k < 2; ++k) {
            double kept = it_region_mean(cuts[k], 3.0f, -1.2f, -0.8f, -0.3f, 0.3f, NULL);
            double gone = it_region_mean(cuts[k], 3.0f, -1.9f, -1.6f, -0.3f, 0.3f, NULL);
            printf(", %s %.4f (the removed half's %.4f)", k ? "open" : "capped", kept, gone);
            EXPECT_MSG(kept < 0.5 * lit, "%s, %s: the light came through the cut (%.4f vs lit %.4f)", be[i], k ? "open" : "capped",
                       kept, lit);
            EXPECT_MSG(fabs(gone - lit) <= 0.1 * lit, "%s, %s: the removed half still shadows (%.4f vs lit %.4f)", be[i],
                       k ? "open" : "capped", gone, lit);
        }
        printf("\n");
        sy_layer_destroy(&uncut);
        sy_layer_destroy(&capped);
        sy_layer_destroy(&open);
    }
    sy_scene_destroy(s);
}

int main(int argc, char **argv)
{
    const char *write_dir = it_start(argc, argv);
    test_closed();
    test_bad_colours();
    test_caps(write_dir);
    test_shadow();
    return sy_check_finish("integration_clip_cap");
}
