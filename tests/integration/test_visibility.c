/* test_visibility.c — visibility and selection as scene changes (issue 37 item 4) and the ID AOVs,
 * in raster, whitted and the path tracer, through the window.
 *
 *   1. Hide: a ground quad lit by a directional light at 45 degrees, a blue caster quad above it.
 *      Hiding the caster (sy_node_set_visible, one change entry) turns its pixels into the lit
 *      ground (the blue goes), removes its shadow (the shadowed region's luminance rises to within
 *      10 % of the lit ground's; it was below half of it), stops picks from naming it, and is
 *      incremental: the same context syncs one entry, keeps its instance count and draws the
 *      caster again when it is shown (pixel-identical to the first image for raster and whitted).
 *   2. Coverage: two quads side by side, one hidden: the coverage (alpha) of every pair of back-ends
 *      agrees (IoU >= 0.98, and no less than 0.005 below the pair's IoU with both shown: the
 *      rasterizer's multisampled edges and the ray tracers' jittered ones differ by about a pixel
 *      along a side), and differs from the back-end's unhidden coverage (IoU < 0.8).
 *   3. Selection: selecting the caster shifts the mean colour of its pixels toward the selection
 *      colour (red up by > 0.2, blue below 0.6 of what it was, in every back-end), draws a one-pixel outline of
 *      exactly that colour around it (between 0.5 and 2 times the caster's perimeter in pixels),
 *      and leaves the lit ground's pixels unchanged (within 1 %); picks are unchanged; 2 x 2 tiles
 *      (SY_CAP_TILES, split through the caster) equal the full frame bit for bit (whitted; raster: its
 *      outline pixels, its own tiles differ from its full frame where nothing is selected too).
 *   4. ID AOVs: the path tracer's "object_id" and "instance_id" planes hold, at every 7th pixel,
 *      the node id and placement that a pick of that pixel reports (0 where it misses), for a
 *      node placed twice (a DAG) beside another.
 *   5. Isolate and bad input: sy_scene_isolate keeps the named nodes, their ancestors and
 *      subtrees, hides the other mesh nodes and leaves lights alone; count 0 shows every node;
 *      unknown node ids are SY_ERR_INVALID_HANDLE naming the id, with nothing changed.
 *   6. A sample (CesiumMilkTruck; skipped with a reason when absent): the rear wheels ("Node.001")
 *      hidden and the front wheels ("Wheels") selected: the hidden wheels' pixels change, and the
 *      coverage of every pair of back-ends agrees (IoU >= 0.98). test_it_visibility --write DIR
 *      writes the images as EXR for looking at. */
#include "it_util.h"

#include "sy_exr.h"
#include "sy_gltf.h"
#include "sy_highlight.h"
#ifdef SY_HAVE_RASTER
#include "sy_mediator_raster.h"
#endif
#include "sy_mediator_rt.h"

#define W 160
#define H 120

static const char *const backends[3] = {"raster", "whitted", "pathtracer"};

static bool have(const char *name) { return sy_mediator_find(name) != NULL; }

/* One window and pool per back-end, kept across renders (incremental syncs). */
typedef struct view {
    sy_window *win;
    sy_viewport *vp;
    sy_context_pool *pool;
    const char *backend;
} view;

static view view_open(const char *backend, const sy_mat4 *cam)
{
    view v = {.backend = backend};
    sy_viewport_desc vd = {.backend = backend};
    v.win = it_window(W, H, &vd, &v.vp);
    if (cam) sy_viewport_set_view(v.vp, cam);
    MUST(sy_context_pool_create(&v.pool, err));
    return v;
}

static void view_close(view *v)
{
    sy_context_pool_destroy(v->pool);
    sy_window_destroy(v->win);
}

static void view_render(view *v, sy_scene *s, sy_layer *out)
{
    MUST(sy_layer_create(W, H, out, err));
    sy_window_render_opts ro = {.sample_count = 16, .seed = 1};
    MUST(sy_window_render(v->win, s, v->pool, &ro, out, err));
}

static sy_context *view_context(view *v, sy_scene *s)
{
    sy_context *ctx = NULL;
    MUST(sy_context_pool_get(v->pool, s, v->backend, NULL, 0, &ctx, err));
    return ctx;
}

/* Change entries of the last sync and live instances of the context (raster or rt counters). */
static void counters(view *v, sy_scene *s, uint32_t *entries, uint32_t *instances)
{
    void *st = sy_context_state(view_context(v, s));
    if (!strcmp(v->backend, "raster")) {
#ifdef SY_HAVE_RASTER
        sy_mediator_raster_counters c;
        sy_mediator_raster_counters_get(st, &c);
        *entries = c.last_sync_entries, *instances = c.instances;
#endif
    } else {
        sy_mediator_rt_counters c;
        sy_mediator_rt_counters_get(st, &c);
        *entries = c.last_sync_entries, *instances = c.instances;
    }
}


/* The shadow scene of test_clip: a 4 x 4 ground at z = 0, a 0.8 x 0.8 caster at z = 1 (blue,
 * lit), a sun travelling (-1, 0, -1)/sqrt(2): the caster's shadow falls around x = -1. */
typedef struct shadow_scene {
    sy_scene *s;
    sy_node ground, caster, sun;
} shadow_scene;

static shadow_scene shadow_scene_make(void)
{
    shadow_scene ss;
    MUST(sy_scene_create(&ss.s, err));
    sy_scene *s = ss.s;
    sy_material grey, blue;
    MUST(sy_material_create(s, "grey", &grey, err));
    MUST(sy_material_create(s, "blue", &blue, err));
    sy_material_data d = *sy_material_get(s, blue);
    d.name = "blue";
    d.base_color[0] = 0.1f, d.base_color[1] = 0.1f, d.base_color[2] = 0.9f;
    MUST(sy_material_set(s, blue, &d, err));
    const float ground[1][3] = {{0, 0, 2.0f}}, caster[1][3] = {{0, 0, 0.4f}};
    sy_mesh mg = it_quad_mesh(s, "ground", ground, &grey, 1), mc = it_quad_mesh(s, "caster", caster, &blue, 1);
    MUST(sy_node_create(s, "ground", &ss.ground, err));
    MUST(sy_node_set_mesh(s, ss.ground, mg, err));
    MUST(sy_node_create(s, "caster", &ss.caster, err));
    MUST(sy_node_set_mesh(s, ss.caster, mc, err));
    it_set_translation(s, ss.caster, 0, 0, 1.0f);
    sy_light lamp = it_light(s, "sun", SY_LIGHT_DIRECTIONAL, 3.0f);
    MUST(sy_node_create(s, "sun", &ss.sun, err));
    MUST(sy_node_set_light(s, ss.sun, lamp, err));
    const float t[3] = {0, 0, 3}, q[4] = {0, sinf(0.3926991f), 0, cosf(0.3926991f)}, one[3] = {1, 1, 1};
    MUST(sy_node_set_trs(s, ss.sun, t, q, one, err));
    MUST(sy_scene_commit(s, NULL, err));
    return ss;
}

static sy_mat4 cam_down(void)
{
    /* from z = 6: the default projection's near plane (half the distance from the framing camera to
     * the bounds, about 2.5 here) stays in front of the caster */
    sy_mat4 cam = sy_mat4_identity();
    cam.m[14] = 6.0f;
    return cam;
}

/* ---------------------------------------------------------------- 1. hide */
static void test_hide(void)
{
    shadow_scene ss = shadow_scene_make();
    sy_mat4 cam = cam_down();
    for (int i = 0; i < 3; ++i) {
        if (!have(backends[i])) continue;
        view v = view_open(backends[i], &cam);
        sy_layer before = {0}, after = {0}, again = {0};
        view_render(&v, ss.s, &before);
        uint32_t e0, i0, e1, i1;
        counters(&v, ss.s, &e0, &i0);
        MUST(sy_node_set_visible(ss.s, ss.caster, false, err));
        MUST(sy_scene_commit(ss.s, NULL, err));
        view_render(&v, ss.s, &after);
        counters(&v, ss.s, &e1, &i1);
        double cb[3], ca[3], lit_rgb[3], tmp[3];
        it_region_mean(&before, 5.0f, -0.3f, 0.3f, -0.3f, 0.3f, cb); /* the caster, at distance 5 */
        it_region_mean(&after, 6.0f, -0.4f, 0.4f, -0.4f, 0.4f, ca);  /* the ground under it */
        double lit = it_region_mean(&before, 6.0f, 1.0f, 1.4f, -0.3f, 0.3f, lit_rgb);
        double sb = it_region_mean(&before, 6.0f, -1.3f, -0.7f, -0.3f, 0.3f, tmp);
        double sa = it_region_mean(&after, 6.0f, -1.3f, -0.7f, -0.3f, 0.3f, tmp);
        printf("hide, %s: caster pixels rgb %.3f %.3f %.3f -> %.3f %.3f %.3f; shadow %.4f -> %.4f (lit %.4f); "
               "sync entries %u, instances %u -> %u\n",
               backends[i], cb[0], cb[1], cb[2], ca[0], ca[1], ca[2], sb, sa, lit, e1, i0, i1);
        EXPECT_MSG(cb[2] > 2.0 * cb[0], "%s: the caster is not blue before hiding (%.3f %.3f %.3f)", backends[i], cb[0],
                   cb[1], cb[2]);
        EXPECT_MSG(fabs(ca[2] - ca[0]) < 0.1 * (ca[0] + 1e-3) + 0.01,
                   "%s: the hidden caster's pixels are not the grey ground (%.3f %.3f %.3f)", backends[i], ca[0], ca[1], ca[2]);
        EXPECT_MSG(lit > 0.05 && sb < 0.5 * lit, "%s: no shadow before hiding (%.4f vs lit %.4f)", backends[i], sb, lit);
        EXPECT_MSG(fabs(sa - lit) <= 0.1 * lit, "%s: the hidden caster still shadows (%.4f vs lit %.4f)", backends[i], sa, lit);
        EXPECT_MSG(e1 == 1 && i1 == i0, "%s: hiding one node was not incremental (%u entries, instances %u -> %u)",
                   backends[i], e1, i0, i1);
        sy_pick_result p;
        if (sy_mediator_class_caps(sy_mediator_find(backends[i]), NULL) & SY_CAP_PICK) {
            MUST(sy_window_pick(v.win, ss.s, v.pool, W / 2 + 0.5, H / 2 + 0.5, &p, err));
            EXPECT_MSG(p.hit && p.node_id == ss.ground.id, "%s: a pick through the hidden caster names node %u (ground %u)",
                       backends[i], p.node_id, ss.ground.id);
        }
        /* shown again: the first image back */
        MUST(sy_node_set_visible(ss.s, ss.caster, true, err));
        MUST(sy_scene_commit(ss.s, NULL, err));
        view_render(&v, ss.s, &again);
        if (strcmp(backends[i], "pathtracer") != 0)
            EXPECT_MSG(it_layers_identical(&before, &again), "%s: showing the caster again did not restore the image",
                       backends[i]);
        else {
            double cg[3];
            it_region_mean(&again, 5.0f, -0.3f, 0.3f, -0.3f, 0.3f, cg);
            EXPECT_MSG(fabs(cg[2] - cb[2]) < 0.05 * cb[2], "pathtracer: the caster did not come back (%.3f vs %.3f)", cg[2], cb[2]);
        }
        sy_layer_destroy(&before);
        sy_layer_destroy(&after);
        sy_layer_destroy(&again);
        view_close(&v);
    }
    sy_scene_destroy(ss.s);
}

/* ---------------------------------------------------------------- 2. coverage */

/* The coverage of n back-ends' images (names) after a change against their own images before it
 * (IoU below `changed`: the change showed) and against each other (IoU at least 0.98, and at most
 * `slack` below the IoU of the two before images); what names the change. Destroys the images. */
static void expect_coverage(sy_layer *after, sy_layer *before, const char *const *names, uint32_t n, double changed,
                            double slack, const char *what)
{
    for (uint32_t i = 0; i < n; ++i) {
        double v = it_coverage_iou(&after[i], &before[i]);
        printf("%s, %s: IoU with the image before %.4f\n", what, names[i], v);
        EXPECT_MSG(v < changed, "%s: %s changed little (IoU %.4f)", names[i], what, v);
        for (uint32_t j = i + 1; j < n; ++j) {
            double w = it_coverage_iou(&after[i], &after[j]), u = it_coverage_iou(&before[i], &before[j]);
            printf("  coverage IoU %s / %s: %.4f after, %.4f before\n", names[i], names[j], w, u);
            EXPECT_MSG(w >= 0.98 && w >= u - slack, "%s: %s and %s differ (IoU %.4f; %.4f before)", what, names[i], names[j],
                       w, u);
        }
    }
    for (uint32_t i = 0; i < n; ++i) sy_layer_destroy(&after[i]), sy_layer_destroy(&before[i]);
}

static void test_coverage(void)
{
    sy_scene *s = it_scene();
    sy_material m = it_unlit(s, "white", 1, 1, 1);
    const float qa[1][3] = {{-0.53f, 0.02f, 0.47f}}, qb[1][3] = {{0.53f, 0.02f, 0.47f}};
    sy_mesh ma = it_quad_mesh(s, "a", qa, &m, 1), mb = it_quad_mesh(s, "b", qb, &m, 1);
    sy_node a, b;
    MUST(sy_node_create(s, "A", &a, err));
    MUST(sy_node_set_mesh(s, a, ma, err));
    MUST(sy_node_create(s, "B", &b, err));
    MUST(sy_node_set_mesh(s, b, mb, err));
    MUST(sy_scene_commit(s, NULL, err));
    sy_mat4 cam = sy_mat4_identity(); /* close: the quads cover most of the image (few edge pixels) */
    cam.m[14] = 2.0f;
    sy_layer full[3], img[3];
    uint32_t n = 0;
    const char *names[3];
    for (int i = 0; i < 3; ++i) {
        if (!have(backends[i])) continue;
        view v = view_open(backends[i], &cam);
        view_render(&v, s, &full[n]);
        MUST(sy_node_set_visible(s, b, false, err));
        MUST(sy_scene_commit(s, NULL, err));
        view_render(&v, s, &img[n]);
        names[n++] = backends[i];
        MUST(sy_node_set_visible(s, b, true, err));
        MUST(sy_scene_commit(s, NULL, err));
        view_close(&v);
    }
    expect_coverage(img, full, names, n, 0.8, 0.005, "hiding B");
    sy_scene_destroy(s);
}

/* ---------------------------------------------------------------- 3. selection */
static void test_select(void)
{
    shadow_scene ss = shadow_scene_make();
    sy_mat4 cam = cam_down();
    static const float col[3] = SY_HIGHLIGHT_COLOR;
    for (int i = 0; i < 3; ++i) {
        if (!have(backends[i])) continue;
        view v = view_open(backends[i], &cam);
        sy_layer plain = {0}, sel = {0};
        view_render(&v, ss.s, &plain);
        MUST(sy_node_set_selected(ss.s, ss.caster, true, err));
        MUST(sy_scene_commit(ss.s, NULL, err));
        view_render(&v, ss.s, &sel);
        double cp[3], cs[3], lp[3], ls[3];
        it_region_mean(&plain, 5.0f, -0.3f, 0.3f, -0.3f, 0.3f, cp);
        it_region_mean(&sel, 5.0f, -0.3f, 0.3f, -0.3f, 0.3f, cs);
        double lit_p = it_region_mean(&plain, 6.0f, 1.0f, 1.4f, -0.3f, 0.3f, lp);
        double lit_s = it_region_mean(&sel, 6.0f, 1.0f, 1.4f, -0.3f, 0.3f, ls);
        uint32_t outline = 0;
        for (uint32_t k = 0; k < (uint32_t)(W * H); ++k) {
            const float *c = sel.rgba + 4 * k;
            outline += c[0] == col[0] && c[1] == col[1] && c[2] == col[2] && c[3] == 1.0f;
        }
        /* the caster's side in pixels: 0.8 units at distance 5 over an image 2 tan(22.5 deg) x 5 high */
        double side = 0.8 / (2.0 * tanf(0.3926991f) * 5.0) * H;
        printf("select, %s: caster rgb %.3f %.3f %.3f -> %.3f %.3f %.3f; outline %u px (side %.0f px); lit ground "
               "%.4f -> %.4f\n",
               backends[i], cp[0], cp[1], cp[2], cs[0], cs[1], cs[2], outline, side, lit_p, lit_s);
        EXPECT_MSG(cs[0] - cp[0] > 0.2 && cs[2] < 0.6 * cp[2], "%s: the selected caster did not move toward the tint",
                   backends[i]);
        EXPECT_MSG(outline > 0.5 * 4 * side && outline < 2.0 * 4 * side, "%s: outline of %u pixels (side %.0f)",
                   backends[i], outline, side);
        EXPECT_MSG(fabs(lit_s - lit_p) <= 0.01 * lit_p, "%s: selection changed the ground (%.4f -> %.4f)", backends[i],
                   lit_p, lit_s);
        if (sy_mediator_class_caps(sy_mediator_find(backends[i]), NULL) & SY_CAP_PICK) {
            sy_pick_result p;
            MUST(sy_window_pick(v.win, ss.s, v.pool, W / 2 + 0.5, H / 2 + 0.5, &p, err));
            EXPECT_MSG(p.hit && p.node_id == ss.caster.id, "%s: the selected caster is not picked", backends[i]);
        }
        if (strcmp(backends[i], "pathtracer") != 0) { /* tiles stitch: the outline crosses tile edges alike */
            sy_camera_view cv;
            MUST(sy_viewport_camera_view(v.vp, ss.s, W, H, &cv, err));
            sy_context *ctx = view_context(&v, ss.s);
            sy_layer full = {0}, tile = {0};
            MUST(it_render_full(ctx, &cv, W, H, 0, &full, err));
            uint32_t differ = 0, outline_differ = 0;
            for (uint32_t t = 0; t < 4; ++t) { /* 2 x 2 tiles split through the caster's middle */
                uint32_t tx = t % 2 ? W / 2 : 0, ty = t / 2 ? H / 2 : 0;
                sy_render_request req;
                memset(&req, 0, sizeof req);
                req.camera = cv, req.full_width = W, req.full_height = H;
                req.rect_x = tx, req.rect_y = ty, req.rect_w = W / 2, req.rect_h = H / 2;
                MUST(sy_layer_create(W / 2, H / 2, &tile, err));
                MUST(sy_context_render(ctx, &req, &tile, err));
                for (uint32_t y = 0; y < H / 2; ++y)
                    for (uint32_t x = 0; x < W / 2; ++x) {
                        const float *a = it_px(&tile, x, y), *b = it_px(&full, tx + x, ty + y);
                        differ += memcmp(a, b, 4 * sizeof(float)) != 0;
                        bool oa = a[0] == col[0] && a[1] == col[1] && a[2] == col[2] && a[3] == 1.0f;
                        bool ob = b[0] == col[0] && b[1] == col[1] && b[2] == col[2] && b[3] == 1.0f;
                        outline_differ += oa != ob;
                    }
                sy_layer_destroy(&tile);
            }
            /* the rasterizer's own tiles differ from its full frame (shadow maps, multisampling: 486 of
             * 19200 pixels here with nothing selected), so for it the outline is what must stitch */
            bool exact = !strcmp(backends[i], "whitted");
            printf("select, %s: 2 x 2 tiles differ from the full frame at %u pixels, in the outline at %u\n", backends[i],
                   differ, outline_differ);
            EXPECT_MSG(outline_differ == 0 && (!exact || differ == 0),
                       "%s: the highlighted tiles do not stitch into the full frame (%u pixels, %u of the outline)",
                       backends[i], differ, outline_differ);
            sy_layer_destroy(&full);
        }
        MUST(sy_node_set_selected(ss.s, ss.caster, false, err));
        MUST(sy_scene_commit(ss.s, NULL, err));
        sy_layer_destroy(&plain);
        sy_layer_destroy(&sel);
        view_close(&v);
    }
    sy_scene_destroy(ss.s);
}

/* ---------------------------------------------------------------- 4. ID AOVs */
static void test_id_aovs(void)
{
    if (!have("pathtracer")) return;
    sy_scene *s = it_scene();
    sy_material m = it_unlit(s, "white", 1, 1, 1);
    const float q[1][3] = {{0, 0, 0.3f}};
    sy_mesh mq = it_quad_mesh(s, "q", q, &m, 1);
    sy_node a, b, ga, gb;
    MUST(sy_node_create(s, "A", &a, err)); /* reached twice: under ga and gb */
    MUST(sy_node_set_mesh(s, a, mq, err));
    MUST(sy_node_create(s, "B", &b, err));
    MUST(sy_node_set_mesh(s, b, mq, err));
    MUST(sy_node_create(s, "GA", &ga, err));
    MUST(sy_node_create(s, "GB", &gb, err));
    MUST(sy_node_add_child(s, ga, a, err));
    MUST(sy_node_add_child(s, gb, a, err));
    it_set_translation(s, ga, -0.8f, 0.4f, 0);
    it_set_translation(s, gb, 0.8f, 0.4f, 0);
    it_set_translation(s, b, 0, -0.5f, 0);
    MUST(sy_scene_commit(s, NULL, err));
    sy_mat4 cam = cam_down();
    view v = view_open("pathtracer", &cam);
    sy_layer img = {0};
    view_render(&v, s, &img);
    sy_aovs aov;
    MUST(sy_context_aovs(view_context(&v, s), &aov, err));
    const float *obj = NULL, *ins = NULL;
    for (uint32_t k = 0; k < aov.count; ++k) {
        if (!strcmp(aov.planes[k].name, "object_id") && aov.planes[k].channels == 1) obj = aov.planes[k].data;
        if (!strcmp(aov.planes[k].name, "instance_id") && aov.planes[k].channels == 1) ins = aov.planes[k].data;
    }
    EXPECT_MSG(obj && ins && aov.width == W && aov.height == H, "the path tracer has no object_id / instance_id planes");
    uint32_t checked = 0, hits = 0, bad = 0, seen_a[2] = {0, 0}, seen_b = 0;
    for (uint32_t k = 0; obj && ins && k < (uint32_t)(W * H); k += 7) {
        uint32_t x = k % W, y = k / W;
        sy_pick_result p;
        MUST(sy_window_pick(v.win, s, v.pool, x + 0.5, y + 0.5, &p, err));
        uint32_t want = p.hit ? p.node_id : 0, want_i = p.hit ? p.placement : 0;
        if ((uint32_t)obj[k] != want || (uint32_t)ins[k] != want_i) {
            if (bad++ < 5)
                fprintf(stderr, "  pixel %u,%u: AOV object %g instance %g, pick node %u placement %u\n", x, y,
                        (double)obj[k], (double)ins[k], want, want_i);
        }
        checked++;
        hits += p.hit;
        if (p.hit && p.node_id == a.id && p.placement < 2) seen_a[p.placement]++;
        if (p.hit && p.node_id == b.id) seen_b++;
    }
    printf("ID AOVs: %u pixels checked (%u hits: A placement 0 %u, placement 1 %u, B %u), %u disagree with sy_window_pick\n",
           checked, hits, seen_a[0], seen_a[1], seen_b, bad);
    EXPECT_MSG(bad == 0 && seen_a[0] && seen_a[1] && seen_b, "the ID AOVs disagree with the picks (%u pixels)", bad);
    sy_aovs_free(&aov);
    sy_layer_destroy(&img);
    view_close(&v);
    sy_scene_destroy(s);
}

/* ---------------------------------------------------------------- 5. isolate and bad input */
static bool visible(sy_scene *s, sy_node n) { return (sy_node_get(s, n)->flags & SY_NODE_VISIBLE) != 0; }

static void test_isolate(void)
{
    shadow_scene ss = shadow_scene_make();
    sy_scene *s = ss.s;
    sy_node group, leaf, other;
    MUST(sy_node_create(s, "group", &group, err)); /* group (mesh) -> leaf (mesh); other (mesh) apart */
    MUST(sy_node_create(s, "leaf", &leaf, err));
    MUST(sy_node_create(s, "other", &other, err));
    sy_mesh mesh = sy_node_get(s, ss.ground)->mesh;
    MUST(sy_node_set_mesh(s, group, mesh, err));
    MUST(sy_node_set_mesh(s, leaf, mesh, err));
    MUST(sy_node_set_mesh(s, other, mesh, err));
    MUST(sy_node_add_child(s, group, leaf, err));
    MUST(sy_node_add_child(s, leaf, ss.caster, err)); /* the caster below leaf */
    MUST(sy_scene_isolate(s, &leaf, 1, err));
    EXPECT_MSG(visible(s, leaf) && visible(s, group) && visible(s, ss.caster) && !visible(s, other) &&
                   !visible(s, ss.ground) && visible(s, ss.sun),
               "isolate(leaf): leaf %d group %d caster %d other %d ground %d sun %d", visible(s, leaf), visible(s, group),
               visible(s, ss.caster), visible(s, other), visible(s, ss.ground), visible(s, ss.sun));
    /* bad ids: nothing changes */
    sy_node bad[2] = {other, {0x7fffff7u}};
    sy_error e = {0};
    sy_result r = sy_scene_isolate(s, bad, 2, &e);
    EXPECT_MSG(r == SY_ERR_INVALID_HANDLE && strstr(e.message, "134217719") && !visible(s, other),
               "isolate with an unknown node: %s (%s)", e.message, sy_result_str(r));
    e = (sy_error){0};
    r = sy_node_set_visible(s, (sy_node){0x7fffff7u}, false, &e);
    EXPECT_MSG(r == SY_ERR_INVALID_HANDLE && strstr(e.message, "hide") && strstr(e.message, "134217719"),
               "hide of an unknown node: %s", e.message);
    e = (sy_error){0};
    r = sy_node_set_selected(s, (sy_node){0}, true, &e);
    EXPECT_MSG(r == SY_ERR_INVALID_HANDLE && strstr(e.message, "select"), "select of node 0: %s", e.message);
    uint32_t flags = SY_NODE_VISIBLE | (1u << 7);
    e = (sy_error){0};
    r = sy_node_set_flags(s, other, flags, &e);
    EXPECT_MSG(r == SY_ERR_INVALID_ARGUMENT, "unknown flag bit 7 accepted: %s", e.message);
    MUST(sy_scene_isolate(s, NULL, 0, err));
    EXPECT_MSG(visible(s, other) && visible(s, ss.ground), "isolate of nothing did not show every node");
    /* selection reaches the subtree along every path (the placement rule) */
    MUST(sy_node_set_selected(s, group, true, err));
    MUST(sy_scene_commit(s, NULL, err));
    sy_placement top = sy_placement_child(NULL, &sy_node_get(s, group)->transform.matrix, sy_node_get(s, group)->flags);
    sy_placement mid = sy_placement_child(&top, &sy_node_get(s, leaf)->transform.matrix, sy_node_get(s, leaf)->flags);
    EXPECT_MSG(top.selected && mid.selected && mid.visible, "the selection did not reach the subtree");
    printf("isolate and bad input: as specified\n");
    sy_scene_destroy(s);
}

/* ---------------------------------------------------------------- 6. a sample */
static sy_node find_node(sy_scene *s, const char *name)
{
    for (uint32_t id = sy_scene_next(s, SY_TYPE_NODE, 0); id; id = sy_scene_next(s, SY_TYPE_NODE, id)) {
        const sy_node_data *d = sy_node_get(s, (sy_node){id});
        if (d && d->name && !strcmp(d->name, name)) return (sy_node){id};
    }
    return (sy_node){0};
}

static void test_sample(const char *write_dir)
{
    char buf[1024];
    const char *path = it_testdata("gltf/CesiumMilkTruck/glTF/CesiumMilkTruck.gltf", buf, sizeof buf);
    sy_gltf_info info;
    sy_scene *s = it_load_gltf(path, &info);
    sy_node rear = find_node(s, "Node.001"), front = find_node(s, "Wheels");
    EXPECT_MSG(rear.id && front.id, "CesiumMilkTruck: no Node.001 or Wheels node");
    if (!rear.id || !front.id) return;
    MUST(sy_scene_commit(s, NULL, err));
    /* a view from the side, low, so every wheel shows */
    sy_bounds b = sy_scene_world_bounds(s);
    float c[3] = {(b.min[0] + b.max[0]) / 2, (b.min[1] + b.max[1]) / 2, (b.min[2] + b.max[2]) / 2};
    float r = 0.5f * sqrtf((b.max[0] - b.min[0]) * (b.max[0] - b.min[0]) + (b.max[1] - b.min[1]) * (b.max[1] - b.min[1]) +
                           (b.max[2] - b.min[2]) * (b.max[2] - b.min[2]));
    float eye[3] = {c[0] + 0.9f * r, c[1] + 0.3f * r, c[2] + 2.3f * r}, up[3] = {0, 1, 0};
    sy_mat4 cam;
    if (!sy_mat4_look_at(eye, c, up, &cam)) cam = sy_mat4_identity();
    sy_layer img[3], plain[3];
    const char *names[3];
    uint32_t n = 0;
    for (int i = 0; i < 3; ++i) {
        if (!have(backends[i])) continue;
        view v = view_open(backends[i], &cam);
        view_render(&v, s, &plain[n]);
        MUST(sy_node_set_visible(s, rear, false, err));
        MUST(sy_node_set_selected(s, front, true, err));
        MUST(sy_scene_commit(s, NULL, err));
        view_render(&v, s, &img[n]);
        MUST(sy_node_set_visible(s, rear, true, err));
        MUST(sy_node_set_selected(s, front, false, err));
        MUST(sy_scene_commit(s, NULL, err));
        if (write_dir) {
            char out[1200];
            snprintf(out, sizeof out, "%s/visibility_%s.exr", write_dir, backends[i]);
            MUST(sy_exr_write_rgba(out, (int)W, (int)H, img[n].rgba, img[n].depth, SY_EXR_PIXEL_FLOAT, err));
        }
        names[n++] = backends[i];
        view_close(&v);
    }
    /* the back-ends agree after the change, however they agreed before it */
    expect_coverage(img, plain, names, n, 0.995, INFINITY, "CesiumMilkTruck: hiding the rear wheels (front selected)");
    sy_gltf_info_free(&info);
    sy_scene_destroy(s);
}

int main(int argc, char **argv)
{
    const char *write_dir = it_start(argc, argv);
    test_isolate();
    test_hide();
    test_coverage();
    test_select();
    test_id_aovs();
    return it_finish_last("test_it_visibility", test_sample, write_dir);
}
