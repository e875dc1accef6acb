/* test_viewport.c — windows, viewports and compositing end to end.
 *
 *   1. sy_layer_composite maths on hand-made layers: replace, depth (nearer wins, ties keep the
 *      destination), premultiplied alpha-over (colour and depth rules), offsets and clipping.
 *   2. A two-viewport window: a whitted viewport of root A under an alpha-over overlay viewport of
 *      a second root B; both render, the overlay covers A only where it has coverage (even though B
 *      is farther), transparent elsewhere; the same with depth compositing lets the nearer A win;
 *      deactivating the overlay leaves A alone; two contexts in the pool (one per root).
 *   3. Stereo: sy_camera_view_eye left/right from a rotated, translated camera: a point on the
 *      zero-parallax plane projects to the same pixel in both eyes, a nearer point has positive
 *      (crossed) disparity xL - xR equal to the value derived by hand, a farther one negative; no
 *      vertical parallax. Then the same through real renders of a side-by-side stereo window.
 *   4. Back-end switching: an unknown name fails with a message listing the available back-ends
 *      and leaves the viewport as it was; switching parameters and back uses the cached context. */
#include "it_util.h"

/* ---------------------------------------------------------------- 1. compositing maths */
static void set_px(sy_layer *l, uint32_t x, uint32_t y, float r, float g, float b, float a, float d)
{
    float *p = l->rgba + 4 * ((size_t)y * l->width + x);
    p[0] = r, p[1] = g, p[2] = b, p[3] = a;
    l->depth[(size_t)y * l->width + x] = d;
}

static bool px_eq(const sy_layer *l, uint32_t x, uint32_t y, float r, float g, float b, float a, float d)
{
    const float *p = it_px(l, x, y);
    float ld = l->depth[(size_t)y * l->width + x];
    bool ok = fabsf(p[0] - r) < 1e-6f && fabsf(p[1] - g) < 1e-6f && fabsf(p[2] - b) < 1e-6f && fabsf(p[3] - a) < 1e-6f &&
              (isinf(d) ? isinf(ld) && ld > 0 : fabsf(ld - d) < 1e-6f);
    if (!ok)
        fprintf(stderr, "  pixel %u,%u is (%g %g %g %g | %g), expected (%g %g %g %g | %g)\n", x, y, p[0], p[1], p[2], p[3],
                ld, r, g, b, a, d);
    return ok;
}

/* A w x 1 layer of the pixels px[x] = (r g b a | depth). */
static void make_row(sy_layer *l, uint32_t w, const float (*px)[5])
{
    MUST(sy_layer_create(w, 1, l, err));
    for (uint32_t x = 0; x < w; ++x) set_px(l, x, 0, px[x][0], px[x][1], px[x][2], px[x][3], px[x][4]);
}

/* Checks row 0 of l against want[x] = (r g b a | depth), x < w. */
static void expect_row(const sy_layer *l, uint32_t w, const float (*want)[5])
{
    for (uint32_t x = 0; x < w; ++x)
        EXPECT_MSG(px_eq(l, x, 0, want[x][0], want[x][1], want[x][2], want[x][3], want[x][4]), "pixel %u", x);
}

/* dst 2x1: (0.4 0.4 0.4 1 | 5) and (0.1 0.2 0.3 1 | 2) */
static void make_dst(sy_layer *dst)
{
    make_row(dst, 2, (const float[][5]){{0.4f, 0.4f, 0.4f, 1.0f, 5.0f}, {0.1f, 0.2f, 0.3f, 1.0f, 2.0f}});
}

static void test_composite_math(void)
{
    sy_layer dst, src;
    /* fresh layers: transparent black, +inf depth */
    MUST(sy_layer_create(3, 2, &dst, err));
    EXPECT(px_eq(&dst, 2, 1, 0, 0, 0, 0, INFINITY));
    sy_layer_destroy(&dst);

    /* half-covering, nearer than dst[0]; empty */
    make_row(&src, 2, (const float[][5]){{0.2f, 0.1f, 0.0f, 0.5f, 3.0f}, {0.0f, 0.0f, 0.0f, 0.0f, INFINITY}});

    /* replace: src wins everywhere, depth included (also the empty pixel) */
    make_dst(&dst);
    sy_layer_composite(&dst, &src, 0, 0, SY_COMPOSITE_REPLACE);
    expect_row(&dst, 2, (const float[][5]){{0.2f, 0.1f, 0.0f, 0.5f, 3.0f}, {0, 0, 0, 0, INFINITY}});
    sy_layer_destroy(&dst);

    /* depth: nearer wins (3 < 5), +inf never wins */
    make_dst(&dst);
    sy_layer_composite(&dst, &src, 0, 0, SY_COMPOSITE_DEPTH);
    expect_row(&dst, 2, (const float[][5]){{0.2f, 0.1f, 0.0f, 0.5f, 3.0f}, {0.1f, 0.2f, 0.3f, 1.0f, 2.0f}});
    /* farther and equal depths keep the destination */
    sy_layer far;
    make_row(&far, 2, (const float[][5]){{1, 1, 1, 1, 3.5f}, {1, 1, 1, 1, 2.0f}});
    sy_layer_composite(&dst, &far, 0, 0, SY_COMPOSITE_DEPTH);
    expect_row(&dst, 2, (const float[][5]){{0.2f, 0.1f, 0.0f, 0.5f, 3.0f}, {0.1f, 0.2f, 0.3f, 1.0f, 2.0f}});
    sy_layer_destroy(&far);
    sy_layer_destroy(&dst);

    /* alpha-over (premultiplied): out = src + dst * (1 - src.a);
     * (0.2 0.1 0 0.5) over (0.4 0.4 0.4 1) = (0.4 0.3 0.2 1); depth: the nearer of the two where
     * the source has coverage; an empty source pixel changes nothing */
    make_dst(&dst);
    sy_layer_composite(&dst, &src, 0, 0, SY_COMPOSITE_ALPHA_OVER);
    expect_row(&dst, 2, (const float[][5]){{0.4f, 0.3f, 0.2f, 1.0f, 3.0f}, {0.1f, 0.2f, 0.3f, 1.0f, 2.0f}});
    /* a covering source pixel farther than the destination keeps the destination's depth */
    sy_layer over;
    make_row(&over, 1, (const float[][5]){{0.25f, 0.0f, 0.0f, 0.25f, 9.0f}});
    sy_layer_composite(&dst, &over, 1, 0, SY_COMPOSITE_ALPHA_OVER);
    EXPECT(px_eq(&dst, 1, 0, 0.25f + 0.1f * 0.75f, 0.2f * 0.75f, 0.3f * 0.75f, 1.0f, 2.0f));
    /* onto transparent black, alpha-over equals the source */
    sy_layer clear;
    MUST(sy_layer_create(1, 1, &clear, err));
    sy_layer_composite(&clear, &over, 0, 0, SY_COMPOSITE_ALPHA_OVER);
    EXPECT(px_eq(&clear, 0, 0, 0.25f, 0.0f, 0.0f, 0.25f, 9.0f));
    sy_layer_destroy(&clear);
    sy_layer_destroy(&over);
    sy_layer_destroy(&dst);
    sy_layer_destroy(&src);

    /* offsets and clipping: a 2x2 source at (2, 1) of a 3x2 destination touches pixel (2, 1) only */
    MUST(sy_layer_create(3, 2, &dst, err));
    MUST(sy_layer_create(2, 2, &src, err));
    for (uint32_t y = 0; y < 2; ++y)
        for (uint32_t x = 0; x < 2; ++x) set_px(&src, x, y, 1.0f + (float)x, 10.0f + (float)y, 0, 1, 1);
    sy_layer_composite(&dst, &src, 2, 1, SY_COMPOSITE_REPLACE);
    for (uint32_t y = 0; y < 2; ++y)
        for (uint32_t x = 0; x < 3; ++x)
            if (x == 2 && y == 1) EXPECT(px_eq(&dst, x, y, 1.0f, 10.0f, 0, 1, 1));
            else EXPECT(px_eq(&dst, x, y, 0, 0, 0, 0, INFINITY));
    sy_layer_composite(&dst, &src, 3, 0, SY_COMPOSITE_REPLACE); /* entirely outside: no-op */
    EXPECT(px_eq(&dst, 2, 0, 0, 0, 0, 0, INFINITY));
    sy_layer_destroy(&dst);
    sy_layer_destroy(&src);
}

/* ---------------------------------------------------------------- scenes */
/* A visible node with one unlit quad of half-size h centred at (x, y, z). */
static sy_node quad_node(sy_scene *s, const char *name, float x, float y, float z, float h, sy_material m)
{
    const float q[1][3] = {{0, 0, h}};
    sy_mesh mesh = it_quad_mesh(s, name, q, &m, 1);
    sy_node n;
    MUST(sy_node_create(s, name, &n, err));
    MUST(sy_node_set_mesh(s, n, mesh, err));
    MUST(sy_node_set_flags(s, n, SY_NODE_VISIBLE, err));
    it_set_translation(s, n, x, y, z);
    return n;
}

/* ---------------------------------------------------------------- 2. layered viewports */
#define LW 96
#define LH 64

static void pixel_of(const sy_camera_view *v, float x, float y, float z, uint32_t w, uint32_t h, uint32_t *px,
                     uint32_t *py)
{
    const float p[3] = {x, y, z};
    float fx, fy;
    it_project(v, p, w, h, &fx, &fy);
    *px = (uint32_t)fx;
    *py = (uint32_t)fy;
}

static void test_layered(void)
{
    sy_scene *s = it_scene();
    sy_material ma = it_unlit(s, "a", 0.9f, 0.2f, 0.1f), mb = it_unlit(s, "b", 0.1f, 0.3f, 0.8f);
    /* A: near (z = 0) square left of centre; B: a second root, farther (z = -1), overlapping A */
    sy_node a = quad_node(s, "A", -0.6f, 0.0f, 0.0f, 0.5f, ma);
    sy_node b = quad_node(s, "B", 0.0f, 0.0f, -1.0f, 0.5f, mb);
    sy_node cam = it_camera_node(s, "cam", 0, 0, 4, 0.8f);
    MUST(sy_scene_commit(s, NULL, err));
    EXPECT(sy_node_parent_count(s, a) == 0 && sy_node_parent_count(s, b) == 0);

    sy_context_pool *pool = it_pool();
    sy_window *win;
    sy_viewport *va, *vb;
    MUST(sy_window_create(LW, LH, &win, err));
    /* spp=1: one centre ray per pixel, so edge pixels are exactly one quad's colour and the checks
     * below see compositing alone (the default 4 strata blend colours at edges) */
    sy_viewport_desc da = {.root = a, .camera = cam, .backend = "whitted", .params = "spp=1", .composite = SY_COMPOSITE_REPLACE};
    sy_viewport_desc db = {.root = b, .camera = cam, .backend = "whitted", .params = "spp=1", .composite = SY_COMPOSITE_ALPHA_OVER};
    MUST(sy_window_add_viewport(win, &da, &va, err));
    MUST(sy_window_add_viewport(win, &db, &vb, err));
    EXPECT(sy_window_viewport_count(win) == 2 && sy_window_viewport(win, 1) == vb);
    sy_layer img, only_a;
    MUST(sy_layer_create(LW, LH, &img, err));
    MUST(sy_layer_create(LW, LH, &only_a, err));
    MUST(sy_window_render(win, s, pool, NULL, &img, err));
    EXPECT_MSG(sy_context_pool_size(pool) == 2, "pool holds %u contexts, expected one per root", sy_context_pool_size(pool));
    EXPECT(sy_layer_count_nonfinite(&img) == 0);

    sy_camera_view view;
    MUST(sy_viewport_camera_view(va, s, LW, LH, &view, err));
    uint32_t x, y;
    pixel_of(&view, -0.9f, 0.0f, 0.0f, LW, LH, &x, &y); /* A only */
    EXPECT_MSG(it_px_is(&img, x, y, 0.9f, 0.2f, 0.1f, 1.0f), "A not visible under the overlay");
    EXPECT(fabsf(img.depth[y * LW + x] - 4.0f) < 1e-3f);
    pixel_of(&view, 0.5f, 0.0f, -1.0f, LW, LH, &x, &y); /* B only */
    EXPECT_MSG(it_px_is(&img, x, y, 0.1f, 0.3f, 0.8f, 1.0f), "overlay B not visible");
    EXPECT(fabsf(img.depth[y * LW + x] - 5.0f) < 1e-3f);
    uint32_t ox, oy;
    pixel_of(&view, -0.25f, 0.0f, 0.0f, LW, LH, &ox, &oy); /* A in front of B: alpha-over draws B anyway */
    EXPECT_MSG(it_px_is(&img, ox, oy, 0.1f, 0.3f, 0.8f, 1.0f), "alpha-over overlay does not cover A");
    EXPECT_MSG(fabsf(img.depth[oy * LW + ox] - 4.0f) < 1e-3f, "alpha-over depth should stay the nearer (A's)");
    EXPECT_MSG(it_px_is(&img, 1, 1, 0, 0, 0, 0) && isinf(img.depth[LW + 1]), "empty corner is not transparent");

    /* inactive overlay: exactly A's own image */
    sy_viewport_set_active(vb, false);
    EXPECT(!sy_viewport_active(vb));
    MUST(sy_window_render(win, s, pool, NULL, &only_a, err));
    EXPECT(it_px_is(&only_a, ox, oy, 0.9f, 0.2f, 0.1f, 1.0f));
    uint32_t differ = 0, differ_outside_b = 0;
    for (uint32_t j = 0; j < LH; ++j)
        for (uint32_t i = 0; i < LW; ++i)
            if (!it_px_same(&img, &only_a, i, j)) {
                differ++;
                if (it_px(&img, i, j)[2] != 0.8f) differ_outside_b++;
            }
    EXPECT_MSG(differ > 0 && differ_outside_b == 0, "overlay changed %u pixels, %u of them not B's", differ, differ_outside_b);
    sy_viewport_set_active(vb, true);

    /* the same layers with depth compositing: the nearer A wins where they overlap */
    sy_window *wd;
    sy_viewport *v1, *v2;
    MUST(sy_window_create(LW, LH, &wd, err));
    db.composite = SY_COMPOSITE_DEPTH;
    MUST(sy_window_add_viewport(wd, &da, &v1, err));
    MUST(sy_window_add_viewport(wd, &db, &v2, err));
    sy_layer dimg;
    MUST(sy_layer_create(LW, LH, &dimg, err));
    MUST(sy_window_render(wd, s, pool, NULL, &dimg, err));
    EXPECT(sy_context_pool_size(pool) == 2); /* same scenes, back-end and roots: shared contexts */
    EXPECT_MSG(it_px_is(&dimg, ox, oy, 0.9f, 0.2f, 0.1f, 1.0f), "depth compositing: the nearer A does not win");
    pixel_of(&view, 0.5f, 0.0f, -1.0f, LW, LH, &x, &y);
    EXPECT(it_px_is(&dimg, x, y, 0.1f, 0.3f, 0.8f, 1.0f));

    /* ---- 4. back-end switching ---- */
    sy_error e = {0};
    sy_result r = sy_viewport_set_backend(vb, "no-such-renderer", NULL, &e);
    EXPECT_MSG(r != SY_OK, "switching to an unknown back-end succeeded");
    EXPECT_MSG(strstr(e.message, "no-such-renderer") && strstr(e.message, "whitted"),
               "message does not name the request and the available back-ends: '%s'", e.message);
    printf("unknown back-end: %s\n", e.message);
    EXPECT(strcmp(sy_viewport_backend(vb), "whitted") == 0);
    sy_viewport *bad = NULL;
    sy_viewport_desc dbad = {.backend = "no-such-renderer"};
    memset(&e, 0, sizeof e);
    EXPECT(sy_window_add_viewport(win, &dbad, &bad, &e) != SY_OK && bad == NULL && strstr(e.message, "whitted"));
    EXPECT(sy_window_viewport_count(win) == 2);
    sy_layer again;
    MUST(sy_layer_create(LW, LH, &again, err));
    MUST(sy_window_render(win, s, pool, NULL, &again, err)); /* still renders with the old back-end */
    EXPECT(it_layers_identical(&img, &again));
    /* switching to other parameters makes one new context; switching back reuses the cached one */
    MUST(sy_viewport_set_backend(vb, "whitted", "spp=1,max_depth=2", err));
    MUST(sy_window_render(win, s, pool, NULL, &again, err));
    EXPECT(sy_context_pool_size(pool) == 3);
    EXPECT(it_layers_identical(&img, &again));
    MUST(sy_viewport_set_backend(vb, "whitted", "spp=1", err));
    MUST(sy_window_render(win, s, pool, NULL, &again, err));
    EXPECT(sy_context_pool_size(pool) == 3);
    EXPECT(it_layers_identical(&img, &again));

    sy_layer_destroy(&again);
    sy_layer_destroy(&dimg);
    sy_window_destroy(wd);
    sy_layer_destroy(&img);
    sy_layer_destroy(&only_a);
    sy_window_destroy(win);
    sy_context_pool_destroy(pool);
    sy_scene_destroy(s);
}

/* ---------------------------------------------------------------- 3. stereo */
static void test_stereo_math(void)
{
    /* camera at (1, 2, 3), turned 30 degrees about Y, off-centre-free symmetric window */
    const float t[3] = {1, 2, 3}, q[4] = {0, sinf(0.2617994f), 0, cosf(0.2617994f)}, one[3] = {1, 1, 1};
    sy_camera_view mono;
    memset(&mono, 0, sizeof mono);
    mono.camera_to_world = sy_mat4_from_trs(t, q, one);
    mono.projection = SY_PROJECTION_PERSPECTIVE;
    mono.window[0] = -0.6f, mono.window[1] = 0.6f, mono.window[2] = -0.4f, mono.window[3] = 0.4f;
    mono.znear = 0.01f;
    const float sep = 0.065f, zp = 2.0f;
    const uint32_t w = 600, h = 400;
    sy_camera_view l = sy_camera_view_eye(&mono, SY_EYE_LEFT, sep, zp);
    sy_camera_view r = sy_camera_view_eye(&mono, SY_EYE_RIGHT, sep, zp);
    sy_camera_view m = sy_camera_view_eye(&mono, SY_EYE_MONO, sep, zp);
    EXPECT(memcmp(&m, &mono, sizeof m) == 0);
    /* eyes sit at -/+ sep/2 along the camera's own X axis */
    float right_axis[3], zero[3] = {0, 0, 0}, xaxis[3] = {1, 0, 0}, lo[3], ro[3];
    sy_mat4_transform_dir(&mono.camera_to_world, xaxis, right_axis);
    sy_mat4_transform_point(&l.camera_to_world, zero, lo);
    sy_mat4_transform_point(&r.camera_to_world, zero, ro);
    for (int i = 0; i < 3; ++i) {
        EXPECT(fabsf(lo[i] - (t[i] - 0.5f * sep * right_axis[i])) < 1e-5f);
        EXPECT(fabsf(ro[i] - (t[i] + 0.5f * sep * right_axis[i])) < 1e-5f);
    }
    /* points given in the mono camera's frame, mapped to world */
    const float depths[3] = {zp, 1.0f, 5.0f};
    for (int k = 0; k < 3; ++k) {
        float pc[3] = {0.3f, -0.2f, -depths[k]}, pw[3];
        sy_mat4_transform_point(&mono.camera_to_world, pc, pw);
        float lx, ly, rx, ry;
        EXPECT(it_project(&l, pw, w, h, &lx, &ly) && it_project(&r, pw, w, h, &rx, &ry));
        float disparity = lx - rx;
        /* by hand: x_eye = (X -/+ ...) ; disparity = sep (1/z - 1/zp) / (window width) * w */
        float expect = sep * (1.0f / depths[k] - 1.0f / zp) / (mono.window[1] - mono.window[0]) * (float)w;
        printf("stereo: depth %.1f: left %.4f,%.4f right %.4f,%.4f disparity %.4f px (expected %.4f)\n", depths[k], lx,
               ly, rx, ry, disparity, expect);
        EXPECT_MSG(fabsf(disparity - expect) < 1e-3f, "disparity %.5f at depth %.1f, expected %.5f", disparity, depths[k],
                   expect);
        EXPECT_MSG(fabsf(ly - ry) < 1e-3f, "vertical parallax %.5f", ly - ry);
        if (k == 0) EXPECT_MSG(fabsf(disparity) < 1e-3f, "zero-parallax point differs by %.5f px", disparity);
        if (k == 1) EXPECT_MSG(disparity > 1.0f, "nearer point: disparity %.4f is not positive", disparity);
        if (k == 2) EXPECT_MSG(disparity < -1.0f, "farther point: disparity %.4f is not negative", disparity);
    }
}

/* Centroid (pixel centres) of the pixels of colour c inside columns [x0, x0 + w). */
static bool centroid(const sy_layer *img, uint32_t x0, uint32_t w, const float c[3], float *cx, float *cy)
{
    double sx = 0, sy = 0;
    uint32_t n = 0;
    for (uint32_t y = 0; y < img->height; ++y)
        for (uint32_t x = x0; x < x0 + w; ++x)
            if (it_px_is(img, x, y, c[0], c[1], c[2], 1.0f)) {
                sx += x + 0.5;
                sy += y + 0.5;
                n++;
            }
    if (!n) return false;
    *cx = (float)(sx / n) - (float)x0;
    *cy = (float)(sy / n);
    return true;
}

static void test_stereo_render(void)
{
    sy_scene *s = it_scene();
    const float cz[3] = {0.9f, 0.9f, 0.1f}, cn[3] = {0.1f, 0.9f, 0.9f};
    sy_material mz = it_unlit(s, "zp", cz[0], cz[1], cz[2]), mn = it_unlit(s, "near", cn[0], cn[1], cn[2]);
    sy_node root;
    MUST(sy_node_create(s, "root", &root, err));
    MUST(sy_node_set_flags(s, root, SY_NODE_VISIBLE, err));
    /* camera at z = 3: the zero-parallax quad at z = 1 (distance 2), the near one at z = 2 (distance 1) */
    MUST(sy_node_add_child(s, root, quad_node(s, "on zero parallax", -0.4f, 0.1f, 1.0f, 0.15f, mz), err));
    MUST(sy_node_add_child(s, root, quad_node(s, "near", 0.15f, -0.1f, 2.0f, 0.08f, mn), err));
    sy_node cam = it_camera_node(s, "cam", 0, 0, 3, 1.0f);
    MUST(sy_scene_commit(s, NULL, err));

    const uint32_t half = 96, h = 96;
    const float sep = 0.3f, zp = 2.0f;
    sy_window *win;
    sy_viewport *vl, *vr;
    MUST(sy_window_create(2 * half, h, &win, err));
    /* spp=1: hard edges, so the centroids below measure the frusta alone */
    sy_viewport_desc d = {.width = half, .height = h, .root = root, .camera = cam, .backend = "whitted",
                          .params = "spp=1", .eye = SY_EYE_LEFT, .eye_separation = sep, .zero_parallax = zp};
    MUST(sy_window_add_viewport(win, &d, &vl, err));
    d.x = half;
    d.eye = SY_EYE_RIGHT;
    MUST(sy_window_add_viewport(win, &d, &vr, err));
    sy_context_pool *pool = it_pool();
    sy_layer img;
    MUST(sy_layer_create(2 * half, h, &img, err));
    MUST(sy_window_render(win, s, pool, NULL, &img, err));
    EXPECT_MSG(sy_context_pool_size(pool) == 1, "both eyes should share one context (pool size %u)", sy_context_pool_size(pool));

    float lzx, lzy, rzx, rzy, lnx, lny, rnx, rny;
    bool ok = centroid(&img, 0, half, cz, &lzx, &lzy) && centroid(&img, half, half, cz, &rzx, &rzy) &&
              centroid(&img, 0, half, cn, &lnx, &lny) && centroid(&img, half, half, cn, &rnx, &rny);
    EXPECT_MSG(ok, "a quad is missing from one eye's image");
    if (ok) {
        sy_camera_view mono;
        sy_viewport_set_camera(vl, cam);
        MUST(sy_viewport_camera_view(vl, s, 2 * half, h, &mono, err));
        /* near quad: expected disparity from the left eye's actual window width */
        float expect = sep * (1.0f / 1.0f - 1.0f / zp) / (mono.window[1] - mono.window[0]) * (float)half;
        printf("stereo render: zero-parallax quad x %.2f / %.2f, near quad x %.2f / %.2f (expected disparity %.2f)\n",
               lzx, rzx, lnx, rnx, expect);
        EXPECT_MSG(fabsf(lzx - rzx) <= 0.5f && fabsf(lzy - rzy) <= 0.01f, "zero-parallax quad moves between eyes");
        EXPECT_MSG(fabsf((lnx - rnx) - expect) <= 1.0f && lnx - rnx > 0.0f, "near quad disparity %.2f, expected %.2f",
                   lnx - rnx, expect);
        EXPECT(fabsf(lny - rny) <= 0.01f);
    }
    sy_layer_destroy(&img);
    sy_context_pool_destroy(pool);
    sy_window_destroy(win);
    sy_scene_destroy(s);
}

int main(void)
{
    it_register();
    test_composite_math();
    test_layered();
    test_stereo_math();
    test_stereo_render();
    return sy_check_finish("integration_viewport");
}
