/* test_clip.c — section planes (SY_CAP_CLIP, issue 37 item 2) in every back-end that offers them,
 * through the window.
 *
 *   1. Bad planes: NaN, infinite, beyond SY_COORD_MAX, a zero normal, seven planes: refused by
 *      sy_viewport_set_clip_planes with SY_ERR_INVALID_ARGUMENT naming the plane, the planes set
 *      before kept; count 0 removes them; a class without SY_CAP_CLIP refuses a cut view
 *      (SY_ERR_UNSUPPORTED naming it, never called) and renders the uncut one.
 *   2. Picks respect the cut: quad B (z = 1) in front of quad A (z = 0); a plane keeping z <= 0.5
 *      removes B, and a pick where B covered A names A (at A's depth) in every clip-capable back-end.
 *   3. Shadows see the cut: a ground quad lit by a directional light at 45 degrees, a caster quad
 *      above it; the mean luminance of the caster's shadow on the ground rises from below half the
 *      lit ground's to within 10 % of it when a plane removes the caster (whitted, pathtracer, raster).
 *   4. The cut image of every back-end matches the others: DamagedHelmet (skipped with a reason when
 *      absent) cut through the middle of its bounds (x >= centre): coverage IoU >= 0.99 between
 *      every pair of clip-capable back-ends, and the cut removes coverage (IoU with the uncut < 0.8).
 *      test_it_clip --write DIR writes the cut images as EXR for looking at.
 *   5. Emitters in a removed part light nothing: an emissive quad, the only light, over a ground
 *      quad; the plane that removes it turns the ground black in whitted, pathtracer and raster. */
#include "it_util.h"

#include "sy_exr.h"
#include "sy_gltf.h"

#define W 160
#define H 120

static uint32_t clip_classes(const char *names[16])
{
    uint32_t n = 0;
    for (uint32_t i = 0; i < sy_mediator_count() && n < 16; ++i) {
        const sy_mediator_class *c = sy_mediator_at(i);
        uint32_t caps = sy_mediator_class_caps(c, NULL);
        if ((caps & SY_CAP_CLIP) && !(caps & (SY_CAP_ANALYSIS | SY_CAP_REMOTE))) names[n++] = c->name;
    }
    return n;
}

/* Renders scene through one viewport of backend (view set directly when cam is not NULL). */
static void render(sy_scene *s, const char *backend, const char *params, const sy_mat4 *cam, const float (*planes)[4],
                   uint32_t nplanes, sy_layer *out)
{
    sy_viewport *vp;
    sy_viewport_desc vd = {.backend = backend, .params = params};
    sy_window *win = it_window(W, H, &vd, &vp);
    if (cam) sy_viewport_set_view(vp, cam);
    MUST(sy_viewport_set_clip_planes(vp, planes, nplanes, err));
    sy_context_pool *pool = it_pool();
    MUST(sy_layer_create(W, H, out, err));
    sy_window_render_opts ro = {.sample_count = 16, .seed = 1};
    MUST(sy_window_render(win, s, pool, &ro, out, err));
    sy_context_pool_destroy(pool);
    sy_window_destroy(win);
}

/* Renders s from (0, 0, 3) in backend without (before) and with (after) the plane keeping z <= 0.5;
 * false, with nothing rendered, when backend is not built or cannot cut. */
static bool render_z_cut(sy_scene *s, const char *backend, sy_layer *before, sy_layer *after)
{
    const sy_mediator_class *cls = sy_mediator_find(backend);
    if (!cls || !(sy_mediator_class_caps(cls, NULL) & SY_CAP_CLIP)) return false;
    sy_mat4 cam = sy_mat4_identity();
    cam.m[14] = 3.0f;
    const float cut[1][4] = {{0, 0, -1, 0.5f}};
    *before = *after = (sy_layer){0};
    render(s, backend, NULL, &cam, cut, 0, before);
    render(s, backend, NULL, &cam, cut, 1, after);
    return true;
}

/* ---------------------------------------------------------------- 1. bad planes */
/* A class without SY_CAP_CLIP (it would draw the uncut model): a cut view must not reach it. */
static const sy_mediator_class noclip_class = {.name = "test_noclip", .caps = SY_CAP_DEPTH, IT_STUB_FUNCTIONS};

static void test_bad_planes(void)
{
    sy_scene *s = it_scene();
    sy_viewport *vp;
    sy_viewport_desc vd = {.backend = "whitted"};
    sy_window *win = it_window(W, H, &vd, &vp);
    const float good[1][4] = {{0, 1, 0, -0.5f}};
    MUST(sy_viewport_set_clip_planes(vp, good, 1, err));
    const struct { float q[4]; const char *needle; } bad[] = {
        {{NAN, 0, 0, 0}, "not finite"},   {{0, INFINITY, 0, 0}, "not finite"}, {{1, 0, 0, 1e13f}, "beyond"},
        {{0, 0, 0, 1}, "normal"},         {{0, 0, 0, 0}, "normal"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        const float two[2][4] = {{1, 0, 0, 0}, {bad[i].q[0], bad[i].q[1], bad[i].q[2], bad[i].q[3]}};
        sy_error e = {0};
        sy_result r = sy_viewport_set_clip_planes(vp, two, 2, &e);
        EXPECT_MSG(r == SY_ERR_INVALID_ARGUMENT && strstr(e.message, bad[i].needle) && strstr(e.message, "plane 1"),
              "bad plane %zu: %s (%s)", i, e.message, sy_result_str(r));
    }
    float seven[7][4];
    for (int i = 0; i < 7; ++i) seven[i][0] = 1, seven[i][1] = seven[i][2] = 0, seven[i][3] = (float)i;
    sy_error e = {0};
    EXPECT_MSG(sy_viewport_set_clip_planes(vp, seven, 7, &e) == SY_ERR_INVALID_ARGUMENT && strstr(e.message, "at most 6"),
          "seven planes: %s", e.message);
    float got[SY_CLIP_PLANES_MAX][4];
    EXPECT_MSG(sy_viewport_clip_planes(vp, got) == 1 && !memcmp(got[0], good[0], sizeof good[0]),
          "the planes set before were not kept");
    MUST(sy_viewport_set_clip_planes(vp, NULL, 0, err));
    EXPECT_MSG(sy_viewport_clip_planes(vp, NULL) == 0, "count 0 did not remove the planes");
    /* a back-end without SY_CAP_CLIP refuses a cut view, in a window render and a context render */
    MUST(sy_mediator_register(&noclip_class, err));
    MUST(sy_viewport_set_clip_planes(vp, good, 1, err));
    MUST(sy_viewport_set_backend(vp, "test_noclip", NULL, err));
    sy_context_pool *pool = it_pool();
    sy_layer img = {0};
    MUST(sy_layer_create(W, H, &img, err));
    e = (sy_error){0};
    sy_result r = sy_window_render(win, s, pool, NULL, &img, &e);
    EXPECT_MSG(r == SY_ERR_UNSUPPORTED && strstr(e.message, "test_noclip") && strstr(e.message, "SY_CAP_CLIP") &&
                   it_stub_renders == 0,
               "a class without SY_CAP_CLIP rendered a cut view: %s (%d renders)", e.message, it_stub_renders);
    printf("bad planes: refused; test_noclip without SY_CAP_CLIP: %s\n", e.message);
    MUST(sy_viewport_set_clip_planes(vp, NULL, 0, err));
    MUST(sy_window_render(win, s, pool, NULL, &img, err)); /* uncut: fine */
    EXPECT_MSG(it_stub_renders == 1, "the uncut view was not rendered (%d renders)", it_stub_renders);
    sy_layer_destroy(&img);
    sy_context_pool_destroy(pool);
    sy_window_destroy(win);
    sy_scene_destroy(s);
}

/* The scenes of 2, 3 and 5: a quad of half size h0 at z = 0 (node name0) and one of half size h1
 * at z = 1 (node name1), in materials m0 and m1; their node handles in *n0, *n1 (may be NULL). */
static void two_quads(sy_scene *s, const char *name0, float h0, sy_material m0, const char *name1, float h1,
                      sy_material m1, sy_node *n0, sy_node *n1)
{
    const float q0[1][3] = {{0, 0, h0}}, q1[1][3] = {{0, 0, h1}};
    sy_mesh a = it_quad_mesh(s, name0, q0, &m0, 1), b = it_quad_mesh(s, name1, q1, &m1, 1);
    sy_node na, nb;
    MUST(sy_node_create(s, name0, &na, err));
    MUST(sy_node_set_mesh(s, na, a, err));
    MUST(sy_node_create(s, name1, &nb, err));
    MUST(sy_node_set_mesh(s, nb, b, err));
    it_set_translation(s, nb, 0, 0, 1.0f);
    if (n0) *n0 = na;
    if (n1) *n1 = nb;
}

/* ---------------------------------------------------------------- 2. picks */
static void test_pick(void)
{
    sy_scene *s = it_scene();
    sy_material m;
    MUST(sy_material_create(s, "grey", &m, err));
    sy_node a, b;
    two_quads(s, "A", 0.8f, m, "B", 0.5f, m, &a, &b);
    MUST(sy_scene_commit(s, NULL, err));
    sy_mat4 cam = sy_mat4_identity();
    cam.m[14] = 3.0f;
    const float cut[1][4] = {{0, 0, -1, 0.5f}}; /* keeps z <= 0.5: B goes */
    const char *names[16];
    uint32_t n = clip_classes(names);
    for (uint32_t i = 0; i < n; ++i) {
        if (!(sy_mediator_class_caps(sy_mediator_find(names[i]), NULL) & SY_CAP_PICK)) continue;
        for (int with = 0; with < 2; ++with) {
            sy_viewport *vp;
            sy_viewport_desc vd = {.backend = names[i]};
            sy_window *win = it_window(W, H, &vd, &vp);
            sy_viewport_set_view(vp, &cam);
            MUST(sy_viewport_set_clip_planes(vp, cut, with ? 1 : 0, err));
            sy_context_pool *pool = it_pool();
            sy_pick_result p;
            MUST(sy_window_pick(win, s, pool, W / 2 + 0.5, H / 2 + 0.5, &p, err));
            uint32_t want = with ? a.id : b.id;
            float want_z = with ? 0.0f : 1.0f;
            EXPECT_MSG(p.hit && p.node_id == want && fabsf(p.position[2] - want_z) < 1e-4f,
                  "%s pick %s the plane: hit %d node %u (want %u) z %g", names[i], with ? "with" : "without", p.hit,
                  p.node_id, want, (double)p.position[2]);
            if (with) printf("pick through the cut, %s: node %u (A), z %.6f\n", names[i], p.node_id, (double)p.position[2]);
            sy_context_pool_destroy(pool);
            sy_window_destroy(win);
        }
    }
    sy_scene_destroy(s);
}


/* ---------------------------------------------------------------- 3. shadows */
static void test_shadow(void)
{
    sy_scene *s = it_scene();
    sy_material m;
    MUST(sy_material_create(s, "grey", &m, err));
    two_quads(s, "ground", 2.0f, m, "caster", 0.4f, m, NULL, NULL);
    it_sun_45(s); /* the caster's shadow falls on the ground around x = -1 */
    MUST(sy_scene_commit(s, NULL, err));
    const char *be[3] = {"whitted", "pathtracer", "raster"};
    for (int i = 0; i < 3; ++i) {
        sy_layer before, after;
        if (!render_z_cut(s, be[i], &before, &after)) continue; /* the caster goes, the ground stays */
        /* the shadow: the caster (half 0.4 at z = 1) moved by -1 in x; lit ground: around x = +1.2 */
        double sb = it_region_mean(&before, 3.0f, -1.3f, -0.7f, -0.3f, 0.3f, NULL);
        double sa = it_region_mean(&after, 3.0f, -1.3f, -0.7f, -0.3f, 0.3f, NULL);
        double lit = it_region_mean(&before, 3.0f, 1.0f, 1.4f, -0.3f, 0.3f, NULL);
        printf("shadow, %s: shadowed region %.4f before the cut, %.4f after; lit ground %.4f\n", be[i], sb, sa, lit);
        EXPECT_MSG(lit > 0.05 && sb < 0.5 * lit, "%s: no shadow before the cut (%.4f vs lit %.4f)", be[i], sb, lit);
        EXPECT_MSG(fabs(sa - lit) <= 0.1 * lit, "%s: the removed caster still shadows (%.4f vs lit %.4f)", be[i], sa, lit);
        sy_layer_destroy(&before);
        sy_layer_destroy(&after);
    }
    sy_scene_destroy(s);
}

/* ---------------------------------------------------------------- 5. emitters in a removed part */
/* The only light is an emissive quad (two-sided, z = 1) over a ground quad (z = 0); a plane keeping
 * z <= 0.5 removes the emitter, and with it its light: the ground goes from lit to black in every
 * back-end (before, the ray tracers' next-event estimation and the rasterizer's polygon lights
 * still lit it from the removed part: 30 %, 33 % and 40 % of the uncut Cornell box's mean). */
static void test_removed_emitter(void)
{
    sy_scene *s = it_scene();
    sy_material grey, glow;
    MUST(sy_material_create(s, "grey", &grey, err));
    MUST(sy_material_create(s, "glow", &glow, err));
    sy_material_data d = *sy_material_get(s, glow);
    d.name = (char *)"glow";
    d.emissive[0] = d.emissive[1] = d.emissive[2] = 4.0f;
    d.double_sided = 1;
    MUST(sy_material_set(s, glow, &d, err));
    two_quads(s, "ground", 2.0f, grey, "lamp", 0.3f, glow, NULL, NULL);
    MUST(sy_scene_commit(s, NULL, err));
    const char *be[3] = {"whitted", "pathtracer", "raster"};
    for (int i = 0; i < 3; ++i) {
        sy_layer before, after;
        if (!render_z_cut(s, be[i], &before, &after)) continue; /* the lamp goes, the ground stays */
        /* the ground beside the lamp (the lamp hides the ground under it from the camera) */
        double lb = it_region_mean(&before, 3.0f, 0.5f, 1.5f, -0.5f, 0.5f, NULL);
        double la = it_region_mean(&after, 3.0f, 0.5f, 1.5f, -0.5f, 0.5f, NULL);
        printf("removed emitter, %s: ground beside the lamp %.4f with it, %.4f with it cut away\n", be[i], lb, la);
        EXPECT_MSG(lb > 0.02, "%s: the lamp does not light the ground (%.4f)", be[i], lb);
        EXPECT_MSG(la <= 0.01 * lb, "%s: the removed lamp still lights the ground (%.4f of %.4f)", be[i], la, lb);
        sy_layer_destroy(&before);
        sy_layer_destroy(&after);
    }
    sy_scene_destroy(s);
}

/* ---------------------------------------------------------------- 4. a sample cut in every back-end */

static void test_sample(const char *write_dir)
{
    char buf[1024];
    const char *path = it_testdata("gltf/DamagedHelmet/glTF/DamagedHelmet.gltf", buf, sizeof buf);
    sy_gltf_info info;
    sy_scene *s = it_load_gltf(path, &info);
    MUST(sy_scene_commit(s, NULL, err));
    sy_bounds b = sy_scene_world_bounds(s);
    const float cut[1][4] = {{1, 0, 0, -0.5f * (b.min[0] + b.max[0])}};
    const char *names[16];
    uint32_t n = clip_classes(names);
    sy_layer img[16], uncut = {0};
    render(s, names[0], NULL, NULL, cut, 0, &uncut);
    for (uint32_t i = 0; i < n; ++i) {
        render(s, names[i], NULL, NULL, cut, 1, &img[i]);
        if (write_dir) {
            char out[1200];
            snprintf(out, sizeof out, "%s/clip_%s.exr", write_dir, names[i]);
            MUST(sy_exr_write_rgba(out, (int)W, (int)H, img[i].rgba, img[i].depth, SY_EXR_PIXEL_FLOAT, err));
        }
    }
    double cut_vs_uncut = it_coverage_iou(&img[0], &uncut);
    printf("DamagedHelmet cut at x >= %.4f: IoU with the uncut %s image %.4f\n", (double)-cut[0][3], names[0], cut_vs_uncut);
    EXPECT_MSG(cut_vs_uncut < 0.8, "the plane cut little away (IoU with the uncut image %.4f)", cut_vs_uncut);
    for (uint32_t i = 0; i < n; ++i)
        for (uint32_t j = i + 1; j < n; ++j) {
            double v = it_coverage_iou(&img[i], &img[j]);
            printf("  coverage IoU %s / %s: %.4f\n", names[i], names[j], v);
            EXPECT_MSG(v >= 0.99, "%s and %s cut differently (IoU %.4f)", names[i], names[j], v);
        }
    for (uint32_t i = 0; i < n; ++i) sy_layer_destroy(&img[i]);
    sy_layer_destroy(&uncut);
    sy_gltf_info_free(&info);
    sy_scene_destroy(s);
}

int main(int argc, char **argv)
{
    const char *write_dir = it_start(argc, argv);
    const char *names[16];
    uint32_t n = clip_classes(names);
    printf("back-ends with SY_CAP_CLIP:");
    for (uint32_t i = 0; i < n; ++i) printf(" %s", names[i]);
    printf("\n");
    EXPECT_MSG(n >= 2, "fewer than two back-ends cut (%u)", n);
    test_bad_planes();
    test_pick();
    test_removed_emitter();
    test_shadow();
    return it_finish_last("test_it_clip", test_sample, write_dir);
}
