/* test_cluster_mediator.c — the cluster as a mediator (issue 16): a window whose viewports name the
 * "cluster" class renders through the same sy_window_render as a local one, with two render
 * servers as separate processes on 127.0.0.1.
 *   1. Side-by-side stereo with a raster overlay (depth composite), whitted on the cluster in
 *      sort-first and balanced modes: equal to the same window rendered locally (rmse <= 1e-6).
 *   2. The same layout with a cooperative path trace: coverage IoU >= 0.99 against the local
 *      composite, and its per-pixel difference from the local render no larger than the difference
 *      between two local renders with other seeds (1.25x, both at the same sample count); the
 *      merged sample count is exactly the requested one.
 *   2b. Mixed back-ends per node: the raster overlay on server 1, the cooperative path trace on
 *      server 2 (servers=), the same checks.
 *   3. A sub-rectangle request (SY_CAP_TILES) equals that rectangle of the whole image.
 *   4. Capabilities: the instance's caps follow the servers' back-end and the mode (cooperative
 *      path tracing is progressive, sort-first whitted is not; both are remote).
 *   5. Set-up refusals name the node and the reason: cooperative whitted, mode=stereo, no
 *      backend=, an unknown mode.
 *   6. Picks (SY_CAP_PICK, answered on the replica by the servers' back-end class): a cluster
 *      viewport names the same node, primitive and triangle, at the same position, as a local
 *      whitted viewport at every pixel of a grid, and misses where it misses; a change after the
 *      first pick (a node moved) is seen by the next.
 *   7. Section planes travel with the view (SY_CAP_CLIP, protocol 4): the demo cut through its
 *      centre by whitted on the cluster (sort-first, balanced) equals the same cut rendered
 *      locally (rmse <= 1e-6) and differs from the uncut image.
 *   8. Visibility and selection are scene changes (issue 37 item 4): one of the demo's objects
 *      hidden and another selected reach the servers' replicas through the change lists: the
 *      cluster image (sort-first, balanced) equals the local one (rmse <= 1e-6) and differs from
 *      the plain image; shown and deselected again, it equals the plain one.
 *   test_cluster_mediator SERVER_EXE WORK_DIR */
#include "../support/sy_check.h"
#include "server_proc.h"
#include "sy_demo.h"
#include "sy_mediator_cluster.h"
#include "sy_mediators.h"
#include "sy_viewport.h"

#include <math.h>
#include <sys/stat.h>

#define W 96
#define H 64

typedef struct fixture {
    sy_scene *scene;
    sy_demo_info d;
    sy_node overlay; /* a second root: a sphere above the demo's centre, drawn by the raster overlay */
} fixture;

static sy_result add_overlay_root(fixture *fx, sy_error *e)
{
    sy_bounds b;
    sy_material m;
    sy_mesh mesh;
    sy_result r = sy_node_world_bounds(fx->scene, fx->d.root, &b, e);
    if (!r) r = sy_material_create(fx->scene, "overlay", &m, e);
    float ext = b.max[0] - b.min[0];
    if (!r) r = sy_demo_sphere(fx->scene, 0.12f * ext, 24, 12, m, &mesh, e);
    const float t[3] = {(b.min[0] + b.max[0]) / 2, b.max[1] + 0.05f * ext, (b.min[2] + b.max[2]) / 2},
                q[4] = {0, 0, 0, 1}, one[3] = {1, 1, 1};
    if (!r) r = sy_node_create(fx->scene, "overlay", &fx->overlay, e);
    if (!r) r = sy_node_set_trs(fx->scene, fx->overlay, t, q, one, e);
    if (!r) r = sy_node_set_mesh(fx->scene, fx->overlay, mesh, e);
    if (!r) r = sy_node_set_flags(fx->scene, fx->overlay, SY_NODE_VISIBLE, e);
    return r;
}

/* Side-by-side stereo: per eye the main viewport (backend/params) and a raster overlay composited
 * by depth (overlay_backend/overlay_params; NULL = local raster); renders into out (2W x H) with a
 * fresh context pool (a fresh accumulation). */
/* Section planes set on the main viewports of render_sbs_with (part 7). */
static uint32_t g_clip_count;
static float g_clip[SY_CLIP_PLANES_MAX][4];
static const float *g_cap; /* their caps' colour (protocol 6), NULL = none */

static int render_sbs_with(fixture *fx, const char *backend, const char *params, const char *overlay_backend,
                           const char *overlay_params, uint32_t spp, uint32_t seed, sy_layer *out, uint64_t *samples_out)
{
    sy_error e = {0};
    sy_window *win = NULL;
    CHECK_OK(sy_window_create(2 * W, H, &win, &e), e);
    for (uint32_t eye = SY_EYE_LEFT; eye <= SY_EYE_RIGHT; ++eye) {
        uint32_t x = eye == SY_EYE_LEFT ? 0 : W;
        sy_viewport_desc main = {.x = x, .y = 0, .width = W, .height = H, .root = fx->d.root, .camera = fx->d.camera,
                                 .background = fx->d.background, .backend = backend, .params = params, .eye = eye,
                                 .composite = SY_COMPOSITE_REPLACE};
        sy_viewport_desc overlay = main;
        overlay.backend = overlay_backend ? overlay_backend : "raster";
        overlay.root = fx->overlay;
        overlay.params = overlay_params;
        overlay.background = (sy_background){0};
        overlay.composite = SY_COMPOSITE_DEPTH;
        sy_viewport *v = NULL;
        CHECK_OK(sy_window_add_viewport(win, &main, &v, &e), e);
        CHECK_OK(sy_viewport_set_clip_planes(v, (const float(*)[4])g_clip, g_clip_count, &e), e);
        CHECK_OK(sy_viewport_set_clip_cap(v, g_cap, &e), e);
        CHECK_OK(sy_window_add_viewport(win, &overlay, &v, &e), e);
    }
    sy_context_pool *pool = NULL;
    CHECK_OK(sy_context_pool_create(&pool, &e), e);
    CHECK_OK(sy_layer_create(2 * W, H, out, &e), e);
    sy_window_render_opts ro = {.sample_count = spp, .seed = seed};
    CHECK_OK(sy_window_render(win, fx->scene, pool, &ro, out, &e), e);
    if (samples_out) {
        sy_params pp;
        sy_context *ctx = NULL;
        CHECK_OK(sy_params_parse(params, &pp, &e), e);
        CHECK_OK(sy_context_pool_get(pool, fx->scene, backend, &pp, fx->d.root.id, &ctx, &e), e);
        sy_mediator_stats st;
        sy_context_stats(ctx, &st);
        *samples_out = st.samples;
    }
    sy_context_pool_destroy(pool);
    sy_window_destroy(win);
    return 0;
}

static int render_sbs(fixture *fx, const char *backend, const char *params, uint32_t spp, uint32_t seed, sy_layer *out,
                      uint64_t *samples_out)
{
    return render_sbs_with(fx, backend, params, NULL, NULL, spp, seed, out, samples_out);
}

static double rmse(const sy_layer *a, const sy_layer *b)
{
    double s = 0;
    size_t n = (size_t)a->width * a->height * 4;
    for (size_t i = 0; i < n; ++i) s += (double)(a->rgba[i] - b->rgba[i]) * (a->rgba[i] - b->rgba[i]);
    return sqrt(s / (double)n);
}

static double coverage_iou(const sy_layer *a, const sy_layer *b)
{
    size_t both = 0, any = 0, n = (size_t)a->width * a->height;
    for (size_t i = 0; i < n; ++i) {
        bool ca = a->rgba[i * 4 + 3] > 0.5f, cb = b->rgba[i * 4 + 3] > 0.5f;
        both += ca && cb;
        any += ca || cb;
    }
    return any ? (double)both / (double)any : 1.0;
}

static double mean_abs_diff(const sy_layer *a, const sy_layer *b)
{
    double s = 0;
    size_t n = (size_t)a->width * a->height * 4;
    for (size_t i = 0; i < n; ++i) s += fabs((double)a->rgba[i] - b->rgba[i]);
    return s / (double)n;
}

static double mean_rgb(const sy_layer *a)
{
    double s = 0;
    size_t n = (size_t)a->width * a->height;
    for (size_t i = 0; i < n; ++i) s += a->rgba[i * 4] + a->rgba[i * 4 + 1] + a->rgba[i * 4 + 2];
    return s / (3.0 * (double)n);
}

static int test_sort_first_and_balanced(fixture *fx)
{
    sy_layer local = {0}, sf = {0}, bal = {0};
    CHECK(render_sbs(fx, "whitted", NULL, 0, 0, &local, NULL) == 0);
    CHECK(render_sbs(fx, "cluster", "backend=whitted,mode=sort-first", 0, 0, &sf, NULL) == 0);
    CHECK(render_sbs(fx, "cluster", "backend=whitted,mode=balanced", 0, 0, &bal, NULL) == 0);
    double e1 = rmse(&local, &sf), e2 = rmse(&local, &bal);
    printf("stereo sbs + raster overlay, whitted: sort-first rmse %.3g, balanced rmse %.3g; mean %.4f\n", e1, e2,
           mean_rgb(&local));
    CHECK_MSG(e1 <= 1e-6 && e2 <= 1e-6, "cluster composite differs from the local one");
    CHECK_MSG(mean_rgb(&local) > 0.01, "the reference image is black: the comparison would see nothing");
    sy_layer_destroy(&local), sy_layer_destroy(&sf), sy_layer_destroy(&bal);
    return 0;
}

static int test_clip(fixture *fx)
{
    sy_bounds b = sy_scene_world_bounds(fx->scene);
    const float cx = 0.5f * (b.min[0] + b.max[0]);
    g_clip_count = 1;
    g_clip[0][0] = 1.0f, g_clip[0][1] = 0.0f, g_clip[0][2] = 0.0f, g_clip[0][3] = -cx; /* keeps x >= centre */
    sy_layer uncut = {0}, local = {0}, sf = {0}, bal = {0};
    static const float cap[3] = {1.0f, 0.0f, 1.0f}; /* with caps (protocol 6): the servers cap as the local back-end */
    g_cap = cap;
    int failed = render_sbs(fx, "whitted", NULL, 0, 0, &local, NULL) || render_sbs(fx, "cluster", "backend=whitted,mode=sort-first", 0, 0, &sf, NULL) ||
                 render_sbs(fx, "cluster", "backend=whitted,mode=balanced", 0, 0, &bal, NULL);
    g_cap = NULL;
    sy_layer nocap = {0};
    failed = failed || render_sbs(fx, "whitted", NULL, 0, 0, &nocap, NULL);
    g_clip_count = 0;
    CHECK(!failed);
    CHECK(render_sbs(fx, "whitted", NULL, 0, 0, &uncut, NULL) == 0);
    double e1 = rmse(&local, &sf), e2 = rmse(&local, &bal), d = mean_abs_diff(&local, &uncut), dc = mean_abs_diff(&local, &nocap);
    printf("section plane x >= %.3f with caps, whitted: sort-first rmse %.3g, balanced rmse %.3g; cut vs uncut mean |diff| "
           "%.4f, capped vs uncapped %.4f\n", (double)cx, e1, e2, d, dc);
    CHECK_MSG(e1 <= 1e-6 && e2 <= 1e-6, "the cluster's cut image differs from the local one");
    CHECK_MSG(d > 0.01, "the plane cut nothing away: the comparison would see nothing");
    sy_layer_destroy(&uncut), sy_layer_destroy(&local), sy_layer_destroy(&sf), sy_layer_destroy(&bal), sy_layer_destroy(&nocap);
    return 0;
}

/* Part 8: the first mesh child of the demo's root hidden, the second selected. */
static int test_visibility(fixture *fx)
{
    sy_error e = {0};
    uint32_t nc;
    const uint32_t *ch = sy_node_children(sy_node_get(fx->scene, fx->d.root), &nc);
    sy_node hide = {0}, sel = {0};
    for (uint32_t i = 0; i < nc && !sel.id; ++i) {
        const sy_node_data *d = sy_node_get(fx->scene, (sy_node){ch[i]});
        if (!d || !d->mesh.id) continue;
        if (!hide.id) hide = (sy_node){ch[i]};
        else sel = (sy_node){ch[i]};
    }
    CHECK_MSG(hide.id && sel.id, "the demo has fewer than two mesh objects under its root");
    sy_layer plain = {0}, local = {0}, sf = {0}, bal = {0}, back = {0};
    CHECK(render_sbs(fx, "whitted", NULL, 0, 0, &plain, NULL) == 0);
    CHECK_OK(sy_node_set_visible(fx->scene, hide, false, &e), e);
    CHECK_OK(sy_node_set_selected(fx->scene, sel, true, &e), e);
    CHECK_OK(sy_scene_commit(fx->scene, NULL, &e), e);
    int failed = render_sbs(fx, "whitted", NULL, 0, 0, &local, NULL) ||
                 render_sbs(fx, "cluster", "backend=whitted,mode=sort-first", 0, 0, &sf, NULL) ||
                 render_sbs(fx, "cluster", "backend=whitted,mode=balanced", 0, 0, &bal, NULL);
    CHECK_OK(sy_node_set_visible(fx->scene, hide, true, &e), e);
    CHECK_OK(sy_node_set_selected(fx->scene, sel, false, &e), e);
    CHECK_OK(sy_scene_commit(fx->scene, NULL, &e), e);
    CHECK(!failed);
    CHECK(render_sbs(fx, "cluster", "backend=whitted,mode=sort-first", 0, 0, &back, NULL) == 0);
    double e1 = rmse(&local, &sf), e2 = rmse(&local, &bal), d = mean_abs_diff(&local, &plain), e3 = rmse(&back, &plain);
    printf("node %u hidden, node %u selected, whitted: sort-first rmse %.3g, balanced rmse %.3g; vs plain mean |diff| "
           "%.4f; shown again: rmse %.3g\n",
           hide.id, sel.id, e1, e2, d, e3);
    CHECK_MSG(e1 <= 1e-6 && e2 <= 1e-6, "the servers' replicas did not hide / select as the local scene does");
    CHECK_MSG(d > 0.001, "hiding and selecting changed nothing: the comparison would see nothing");
    CHECK_MSG(e3 <= 1e-6, "shown and deselected again, the cluster image is not the plain one");
    sy_layer_destroy(&plain), sy_layer_destroy(&local), sy_layer_destroy(&sf), sy_layer_destroy(&bal), sy_layer_destroy(&back);
    return 0;
}

static int test_cooperative(fixture *fx)
{
    enum { SPP = 16 };
    sy_layer l1 = {0}, l2 = {0}, c = {0};
    uint64_t samples = 0;
    CHECK(render_sbs(fx, "pathtracer", NULL, SPP, 1, &l1, NULL) == 0);
    CHECK(render_sbs(fx, "pathtracer", NULL, SPP, 977, &l2, NULL) == 0);
    CHECK(render_sbs(fx, "cluster", "backend=pathtracer,mode=cooperative", SPP, 5, &c, &samples) == 0);
    double iou = coverage_iou(&l1, &c), noise = mean_abs_diff(&l1, &l2), diff = mean_abs_diff(&l1, &c);
    double ratio = mean_rgb(&c) / mean_rgb(&l1);
    printf("stereo sbs + raster overlay, cooperative pathtracer %d spp: IoU %.4f, |cluster - local| %.5f vs local "
           "noise %.5f, mean ratio %.4f, merged %llu samples\n",
           SPP, iou, diff, noise, ratio, (unsigned long long)samples);
    CHECK_MSG(samples == SPP, "merged %llu samples, asked for %d", (unsigned long long)samples, SPP);
    CHECK(iou >= 0.99);
    CHECK_MSG(noise > 0, "two local renders with other seeds are equal: the noise reference would see nothing");
    CHECK(diff <= 1.25 * noise);
    CHECK(fabs(ratio - 1) < 0.03);
    sy_layer_destroy(&l1), sy_layer_destroy(&l2), sy_layer_destroy(&c);
    return 0;
}

/* Mixed back-ends per node: the raster overlay renders on server 1, the cooperative path trace on
 * server 2 (servers=), in one window; it matches the local composite like test_cooperative. */
static int test_mixed_nodes(fixture *fx)
{
    enum { SPP = 16 };
    sy_layer l1 = {0}, l2 = {0}, c = {0};
    CHECK(render_sbs(fx, "pathtracer", NULL, SPP, 1, &l1, NULL) == 0);
    CHECK(render_sbs(fx, "pathtracer", NULL, SPP, 977, &l2, NULL) == 0);
    uint64_t samples = 0;
    CHECK(render_sbs_with(fx, "cluster", "backend=pathtracer,mode=cooperative,servers=2", "cluster",
                          "backend=raster,servers=1", SPP, 5, &c, &samples) == 0);
    double iou = coverage_iou(&l1, &c), noise = mean_abs_diff(&l1, &l2), diff = mean_abs_diff(&l1, &c);
    printf("raster overlay on server 1 + cooperative pathtracer on server 2: IoU %.4f, |cluster - local| %.5f vs "
           "noise %.5f, %llu samples\n",
           iou, diff, noise, (unsigned long long)samples);
    CHECK(samples == SPP);
    CHECK(iou >= 0.99);
    CHECK(diff <= 1.25 * noise);
    sy_layer_destroy(&l1), sy_layer_destroy(&l2), sy_layer_destroy(&c);
    return 0;
}

static int test_tiles_and_caps(fixture *fx)
{
    sy_error e = {0};
    sy_params pp;
    sy_context *ctx = NULL, *coop = NULL;
    CHECK_OK(sy_params_parse("backend=whitted", &pp, &e), e);
    CHECK_OK(sy_context_create(fx->scene, "cluster", &pp, fx->d.root.id, &ctx, &e), e);
    uint32_t caps = sy_context_caps(ctx);
    CHECK((caps & SY_CAP_REMOTE) && (caps & SY_CAP_DEPTH) && (caps & SY_CAP_TILES) && !(caps & SY_CAP_PROGRESSIVE));
    sy_params pc;
    CHECK_OK(sy_params_parse("backend=pathtracer,mode=cooperative", &pc, &e), e);
    CHECK_OK(sy_context_create(fx->scene, "cluster", &pc, fx->d.root.id, &coop, &e), e);
    CHECK((sy_context_caps(coop) & (SY_CAP_REMOTE | SY_CAP_PROGRESSIVE)) == (SY_CAP_REMOTE | SY_CAP_PROGRESSIVE));
    CHECK(!(sy_context_caps(coop) & SY_CAP_AOVS)); /* the feature buffers stay on the servers */
    sy_aovs a;
    CHECK_ERR(sy_context_aovs(coop, &a, &e), SY_ERR_UNSUPPORTED, e);
    sy_context_release(coop);

    CHECK_OK(sy_context_sync(ctx, &e), e);
    sy_camera_view view;
    sy_window *win = NULL;
    sy_viewport *vp = NULL;
    sy_viewport_desc vd = {.root = fx->d.root, .camera = fx->d.camera, .backend = "whitted"};
    CHECK_OK(sy_window_create(W, H, &win, &e), e);
    CHECK_OK(sy_window_add_viewport(win, &vd, &vp, &e), e);
    CHECK_OK(sy_viewport_camera_view(vp, fx->scene, W, H, &view, &e), e);
    sy_window_destroy(win);
    sy_render_request full = {.camera = view, .full_width = W, .full_height = H, .rect_w = W, .rect_h = H,
                              .background_id = fx->d.background.id};
    sy_render_request part = full;
    part.rect_x = 17, part.rect_y = 9, part.rect_w = 40, part.rect_h = 30;
    sy_layer lf = {0}, lp = {0};
    CHECK_OK(sy_layer_create(W, H, &lf, &e), e);
    CHECK_OK(sy_layer_create(40, 30, &lp, &e), e);
    CHECK_OK(sy_context_render(ctx, &full, &lf, &e), e);
    CHECK_OK(sy_context_render(ctx, &part, &lp, &e), e);
    for (uint32_t y = 0; y < 30; ++y)
        for (uint32_t x = 0; x < 40; ++x)
            for (int k = 0; k < 4; ++k)
                CHECK(lp.rgba[((size_t)y * 40 + x) * 4 + k] == lf.rgba[((size_t)(y + 9) * W + x + 17) * 4 + k]);
    printf("sub-rectangle 40x30+17+9 equals the whole image's pixels\n");
    sy_layer_destroy(&lf), sy_layer_destroy(&lp);
    sy_context_release(ctx);
    return 0;
}

static int pick_grid(sy_window *cw, sy_window *lw, fixture *fx, sy_context_pool *pool, uint32_t *hits)
{
    sy_error e = {0};
    *hits = 0;
    for (uint32_t y = 2; y < H; y += 6)
        for (uint32_t x = 3; x < W; x += 7) {
            sy_pick_result a, b;
            CHECK_OK(sy_window_pick(cw, fx->scene, pool, x, y, &a, &e), e);
            CHECK_OK(sy_window_pick(lw, fx->scene, pool, x, y, &b, &e), e);
            CHECK_MSG(a.hit == b.hit && a.node_id == b.node_id && a.primitive == b.primitive && a.triangle == b.triangle &&
                          memcmp(a.position, b.position, sizeof a.position) == 0,
                      "pixel %u,%u: cluster hit %d node %#x triangle %u, local hit %d node %#x triangle %u", x, y, a.hit,
                      a.node_id, a.triangle, b.hit, b.node_id, b.triangle);
            *hits += a.hit;
        }
    return 0;
}

static int test_pick(fixture *fx)
{
    sy_error e = {0};
    sy_window *cw = NULL, *lw = NULL;
    sy_context_pool *pool = NULL;
    /* every root: the demo and the overlay sphere */
    sy_viewport_desc cd = {.camera = fx->d.camera, .backend = "cluster", .params = "backend=whitted"};
    sy_viewport_desc ld = {.camera = fx->d.camera, .backend = "whitted"};
    CHECK_OK(sy_context_pool_create(&pool, &e), e);
    CHECK_OK(sy_window_create(W, H, &cw, &e), e);
    CHECK_OK(sy_window_create(W, H, &lw, &e), e);
    CHECK_OK(sy_window_add_viewport(cw, &cd, NULL, &e), e);
    CHECK_OK(sy_window_add_viewport(lw, &ld, NULL, &e), e);
    sy_params pp;
    CHECK_OK(sy_params_parse("backend=whitted", &pp, &e), e);
    CHECK(sy_mediator_class_caps(sy_mediator_find("cluster"), &pp) & SY_CAP_PICK);
    sy_layer img = {0};
    CHECK_OK(sy_layer_create(W, H, &img, &e), e);
    CHECK_OK(sy_window_render(cw, fx->scene, pool, NULL, &img, &e), e); /* a frame first, as a viewer does */
    uint32_t hits = 0;
    CHECK(pick_grid(cw, lw, fx, pool, &hits) == 0);
    CHECK_MSG(hits > 20, "only %u grid pixels hit", hits);
    /* a change after the first pick: the overlay sphere moves into the middle of the view (the
     * last part of the test: the scene stays so) */
    sy_bounds b;
    CHECK_OK(sy_node_world_bounds(fx->scene, fx->d.root, &b, &e), e);
    const float t[3] = {(b.min[0] + b.max[0]) / 2, (b.min[1] + b.max[1]) / 2, (b.min[2] + b.max[2]) / 2}, q[4] = {0, 0, 0, 1},
                one[3] = {1, 1, 1};
    CHECK_OK(sy_node_set_trs(fx->scene, fx->overlay, t, q, one, &e), e);
    CHECK_OK(sy_scene_commit(fx->scene, NULL, &e), e);
    CHECK_OK(sy_window_render(cw, fx->scene, pool, NULL, &img, &e), e);
    CHECK(pick_grid(cw, lw, fx, pool, &hits) == 0);
    sy_pick_result a;
    CHECK_OK(sy_window_pick(cw, fx->scene, pool, W / 2, H / 2, &a, &e), e);
    CHECK_MSG(a.hit && a.node_id == fx->overlay.id, "the moved sphere is not picked at the centre (node %#x)", a.node_id);
    printf("picks: the cluster viewport names what a local whitted viewport names (%u grid pixels hit)\n", hits);
    sy_layer_destroy(&img);
    sy_window_destroy(cw);
    sy_window_destroy(lw);
    sy_context_pool_destroy(pool);
    return 0;
}

static int refused(fixture *fx, const char *params, const char *needle)
{
    sy_error e = {0};
    sy_params pp;
    sy_context *ctx = NULL;
    CHECK_OK(sy_params_parse(params, &pp, &e), e);
    sy_result r = sy_context_create(fx->scene, "cluster", &pp, 0, &ctx, &e);
    if (r == SY_OK) sy_context_release(ctx);
    CHECK_MSG(r != SY_OK, "'%s' was accepted", params);
    CHECK_MSG(strstr(e.message, needle) != NULL, "'%s': error '%s' does not say '%s'", params, e.message, needle);
    printf("refused '%s': %s\n", params, e.message);
    return 0;
}

static int test_refusals(fixture *fx, const server *s)
{
    char node[96];
    snprintf(node, sizeof node, "server 1 (%s)", s[0].url);
    CHECK(refused(fx, "backend=whitted,mode=cooperative", node) == 0);
    CHECK(refused(fx, "backend=whitted,mode=cooperative", "sample ranges") == 0);
    CHECK(refused(fx, "backend=whitted,mode=stereo", "stereo viewports") == 0);
    CHECK(refused(fx, "mode=sort-first", "backend=NAME") == 0);
    CHECK(refused(fx, "backend=whitted,mode=sideways", "sideways") == 0);
    CHECK(refused(fx, "backend=whitted,pixels=double", "pixels=double") == 0);
    CHECK(refused(fx, "backend=whitted,servers=3", "server numbers are 1..2") == 0);
    CHECK(refused(fx, "backend=whitted,servers=1+x", "joined by '+'") == 0);
    /* typed parameters: the cluster's own keys by its table, the forwarded ones by the servers' back-end's */
    CHECK(refused(fx, "backend=whitted,samples=-1", "samples=-1 for back-end 'cluster'") == 0);
    CHECK(refused(fx, "backend=whitted,max_detph=8", "unknown parameter 'max_detph' for back-end 'whitted'") == 0);
    CHECK(refused(fx, "backend=whitted,max_detph=8", "valid: spp, env_samples, max_depth") == 0);
    CHECK(refused(fx, "backend=pathtracer,max_depth=2000", "max_depth=2000 for back-end 'pathtracer'") == 0);
    return 0;
}

int main(int argc, char **argv)
{
    if (server_proc_setup(argc, argv, "test_cluster_mediator", "")) return 2;
    atexit(kill_leftover_servers);
    sy_error e = {0};
    fixture fx = {0};
    if (sy_mediators_register_builtin(&e) || sy_scene_create(&fx.scene, &e) || sy_demo_build(fx.scene, &fx.d, &e) ||
        sy_scene_commit(fx.scene, NULL, &e) || add_overlay_root(&fx, &e) || sy_scene_commit(fx.scene, NULL, &e)) {
        fprintf(stderr, "%s\n", e.message);
        return 1;
    }
    server s[2];
    memset(s, 0, sizeof s);
    int failed = 0;
    if (start_server("s3cret", 0, &s[0]) || start_server("s3cret", 0, &s[1])) {
        failed = 1;
    } else {
        const char *urls[2] = {s[0].url, s[1].url};
        sy_cluster_client_opts co = {.urls = urls, .url_count = 2, .secret = (const uint8_t *)"s3cret", .secret_len = 6,
                                     .timeout_ms = 60000, .connect_timeout_ms = 3000};
        if (sy_mediator_cluster_register("cluster", &co, &e) != SY_OK) {
            fprintf(stderr, "register: %s\n", e.message);
            failed = 1;
        } else {
            CHECK(sy_mediator_cluster_register("cluster", &co, &e) != SY_OK); /* the name is taken */
            int r;
            failed += r = test_sort_first_and_balanced(&fx);
            printf("sort-first / balanced composite: %s\n", r ? "FAILED" : "ok");
            failed += r = test_cooperative(&fx);
            printf("cooperative composite: %s\n", r ? "FAILED" : "ok");
            failed += r = test_mixed_nodes(&fx);
            printf("mixed back-ends per node: %s\n", r ? "FAILED" : "ok");
            failed += r = test_tiles_and_caps(&fx);
            printf("tiles and capabilities: %s\n", r ? "FAILED" : "ok");
            failed += r = test_refusals(&fx, s);
            printf("set-up refusals: %s\n", r ? "FAILED" : "ok");
            failed += r = test_clip(&fx);
            printf("section planes: %s\n", r ? "FAILED" : "ok");
            failed += r = test_visibility(&fx);
            printf("visibility and selection: %s\n", r ? "FAILED" : "ok");
            failed += r = test_pick(&fx); /* last: it moves the overlay sphere */
            printf("picks: %s\n", r ? "FAILED" : "ok");
        }
    }
    for (int i = 0; i < 2; ++i) stop_server(&s[i]);
    sy_scene_destroy(fx.scene);
    if (failed) fprintf(stderr, "test_cluster_mediator: %d group(s) failed (server logs in %s)\n", failed, g_dir);
    return failed ? 1 : 0;
}
