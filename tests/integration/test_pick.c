/* test_pick.c — picking (SY_CAP_PICK) in every back-end that offers it, through the window.
 *
 *   1. Two quads at known depths (A at z = 0 behind, B at z = 1 in front, overlapping; B's mesh has
 *      a second primitive with its own material), seen from (0, 0, 3) down -Z: at chosen pixels
 *      every pick-capable back-end names the node, mesh, primitive, triangle and material computed
 *      by hand, with barycentrics, world position (within 1e-4 of the scene size), normal, distance
 *      and depth from the view's definition; a pixel beside the quads is a miss (no error); a
 *      frame rendered after the picks equals the one before (non-progressive classes). The
 *      rasterizer, Whitted and the path tracer must be among them (where built).
 *   2. A DAG: one quad node under two parents is told apart by its placement.
 *   3. Windows: a depth-composited layer answers where it is nearer, an alpha-over one wherever
 *      it hit, a replacing one always (a miss too); side-by-side stereo answers with the eye of the
 *      half the point is in, its pixel in that viewport, a point on that eye's ray.
 *   4. Bad input: NaN, infinite, outside the window or the viewport: SY_ERR_INVALID_ARGUMENT naming
 *      the values; a back-end without SY_CAP_PICK: SY_ERR_UNSUPPORTED naming it.
 *   5. A Khronos sample (DamagedHelmet; skipped with a reason when absent): at 300 random pixels,
 *      where every pick-capable back-end hits, they name the same node and triangle at >= 99 % of
 *      them and the positions agree within 1e-4 x the scene size wherever the triangle agrees.
 *
 * Measurement mode (issue 37's target): test_it_pick --agreement N SCENE.gltf... picks N random
 * pixels (seed 1) of each scene's framing view at 512x384 in every pick-capable back-end and prints,
 * per scene and over all: covered pixels (every back-end hit), coverage disagreements, the share
 * naming the same node and triangle, the largest position difference over the scene size, and the
 * largest difference between a pick's depth and the depth plane of a one-ray-per-pixel Whitted
 * render (Embree's own hit: an independent check of the shared arithmetic). */
#include "it_util.h"

#include "sy_gltf.h"

#define W 160
#define H 120
#define SIZE_TOL 1e-4 /* of the scene size */
#define CAM_Z 3.0f

/* ---------------------------------------------------------------- the back-ends under test */
static uint32_t pick_classes(const char *names[16])
{
    uint32_t n = 0;
    for (uint32_t i = 0; i < sy_mediator_count() && n < 16; ++i) {
        const sy_mediator_class *c = sy_mediator_at(i);
        if (sy_mediator_class_caps(c, NULL) & SY_CAP_PICK) names[n++] = c->name;
    }
    return n;
}

static sy_material material(sy_scene *s, const char *name)
{
    sy_material m;
    MUST(sy_material_create(s, name, &m, err));
    return m;
}

/* ---------------------------------------------------------------- 1. two quads */
typedef struct quads {
    sy_scene *s;
    sy_node a, b;
    sy_mesh ma, mb;
    sy_material mat_a, mat_b0, mat_b1;
} quads;

/* A: quad centred (-0.3, 0) half 0.6 at z = 0; B: quad centred (0.3, 0) half 0.6 at z = 1, and a
 * second primitive centred (0.3, 0.9) half 0.2 (same node, material b1). */
static void make_quads(quads *q)
{
    MUST(sy_scene_create(&q->s, err));
    q->mat_a = material(q->s, "mat-a");
    q->mat_b0 = material(q->s, "mat-b0");
    q->mat_b1 = material(q->s, "mat-b1");
    const float qa[1][3] = {{-0.3f, 0.0f, 0.6f}}, qb[2][3] = {{0.3f, 0.0f, 0.6f}, {0.3f, 0.9f, 0.2f}};
    sy_material mb[2] = {q->mat_b0, q->mat_b1};
    q->ma = it_quad_mesh(q->s, "mesh-a", qa, &q->mat_a, 1);
    q->mb = it_quad_mesh(q->s, "mesh-b", qb, mb, 2);
    MUST(sy_node_create(q->s, "A", &q->a, err));
    MUST(sy_node_set_mesh(q->s, q->a, q->ma, err));
    MUST(sy_node_create(q->s, "B", &q->b, err));
    MUST(sy_node_set_mesh(q->s, q->b, q->mb, err));
    it_set_translation(q->s, q->b, 0.0f, 0.0f, 1.0f);
    MUST(sy_scene_commit(q->s, NULL, err));
}

/* The camera: at (0, 0, CAM_Z) looking down -Z (the framing view's projection, yfov 45 degrees). */
static sy_mat4 cam_at_5(void)
{
    sy_mat4 m = sy_mat4_identity();
    m.m[14] = CAM_Z;
    return m;
}

/* A W x H window with one full viewport of backend, the camera at 5 on +z, and that view. */
static sy_window *one_viewport(const char *backend, sy_scene *s, sy_viewport **vp, sy_camera_view *view)
{
    sy_viewport_desc vd = {.backend = backend};
    sy_window *win = it_window(W, H, &vd, vp);
    sy_mat4 cam = cam_at_5();
    sy_viewport_set_view(*vp, &cam);
    MUST(sy_viewport_camera_view(*vp, s, W, H, view, err));
    return win;
}

/* What pixel (px, py) must answer, from the view's window and the quads' definition. */
typedef struct expect {
    bool hit;
    uint32_t node, mesh, primitive, triangle, material;
    double bary[3], pos[3], distance, depth;
} expect;

static expect expected(const quads *q, const sy_camera_view *v, uint32_t px, uint32_t py)
{
    expect e = {0};
    double tx = v->window[0] + (px + 0.5) / W * (v->window[1] - v->window[0]);
    double ty = v->window[3] - (py + 0.5) / H * (v->window[3] - v->window[2]);
    /* the quads front to back: B's primitives at z = 1, then A at z = 0 */
    static const struct { int node; double z, cx, cy, h; uint32_t prim; } list[3] = {
        {1, 1.0, 0.3, 0.0, 0.6, 0}, {1, 1.0, 0.3, 0.9, 0.2, 1}, {0, 0.0, -0.3, 0.0, 0.6, 0}};
    for (int k = 0; k < 3; ++k) {
        double d = CAM_Z - list[k].z, x = tx * d, y = ty * d, h = list[k].h;
        double s = (x - (list[k].cx - h)) / (2 * h), u = (y - (list[k].cy - h)) / (2 * h);
        if (s < 0 || s > 1 || u < 0 || u > 1) continue;
        e.hit = true;
        e.node = list[k].node ? q->b.id : q->a.id;
        e.mesh = list[k].node ? q->mb.id : q->ma.id;
        e.primitive = list[k].prim;
        e.material = list[k].node ? (list[k].prim ? q->mat_b1.id : q->mat_b0.id) : q->mat_a.id;
        /* triangle 0 = vertices 0 1 2 (below the diagonal s >= u), 1 = vertices 0 2 3 */
        e.triangle = s >= u ? 0 : 1;
        if (e.triangle == 0) e.bary[0] = 1 - s, e.bary[1] = s - u, e.bary[2] = u;
        else e.bary[0] = 1 - u, e.bary[1] = s, e.bary[2] = u - s;
        e.pos[0] = x, e.pos[1] = y, e.pos[2] = list[k].z;
        e.distance = sqrt(x * x + y * y + d * d);
        e.depth = d;
        return e;
    }
    return e;
}

/* Checks one pick against the expectation; the scene is about 2.4 units across. */
static void check_pick(const char *be, uint32_t px, uint32_t py, const sy_pick_result *p, const expect *e)
{
    const double tol = SIZE_TOL * 2.4;
    EXPECT_MSG(p->hit == e->hit, "%s (%u, %u): hit %d, expected %d", be, px, py, p->hit, e->hit);
    if (!e->hit || !p->hit) {
        EXPECT_MSG(p->node_id == 0 && p->triangle == 0 && p->distance == 0.0f, "%s: a miss answers more than no hit", be);
        return;
    }
    EXPECT_MSG(p->node_id == e->node && p->mesh_id == e->mesh && p->primitive == e->primitive &&
                   p->triangle == e->triangle && p->material_id == e->material && p->placement == 0,
               "%s (%u, %u): node %#x mesh %#x primitive %u triangle %u material %#x placement %u; expected %#x %#x %u %u %#x 0",
               be, px, py, p->node_id, p->mesh_id, p->primitive, p->triangle, p->material_id, p->placement, e->node,
               e->mesh, e->primitive, e->triangle, e->material);
    for (int k = 0; k < 3; ++k) {
        EXPECT_MSG(fabs(p->position[k] - e->pos[k]) <= tol, "%s (%u, %u): position[%d] %.7g, expected %.7g", be, px,
                   py, k, p->position[k], e->pos[k]);
        EXPECT_MSG(fabs(p->barycentrics[k] - e->bary[k]) <= 1e-4, "%s (%u, %u): barycentric %d %.7g, expected %.7g",
                   be, px, py, k, p->barycentrics[k], e->bary[k]);
    }
    EXPECT_MSG(fabsf(p->normal[0]) < 1e-6f && fabsf(p->normal[1]) < 1e-6f && fabsf(p->normal[2] - 1.0f) < 1e-6f,
               "%s: normal %g %g %g, expected 0 0 1", be, p->normal[0], p->normal[1], p->normal[2]);
    EXPECT_MSG(fabs(p->distance - e->distance) <= tol && fabs(p->depth - e->depth) <= tol,
               "%s (%u, %u): distance %g depth %g, expected %g %g", be, px, py, p->distance, p->depth, e->distance, e->depth);
}

static void test_quads(void)
{
    const char *names[16];
    uint32_t n = pick_classes(names);
    bool whitted = false, pathtracer = false, raster = false;
    for (uint32_t i = 0; i < n; ++i) {
        whitted |= !strcmp(names[i], "whitted");
        pathtracer |= !strcmp(names[i], "pathtracer");
        raster |= !strcmp(names[i], "raster");
    }
    EXPECT_MSG(whitted && pathtracer, "whitted and pathtracer must offer SY_CAP_PICK");
#ifdef SY_HAVE_RASTER
    EXPECT_MSG(raster, "raster must offer SY_CAP_PICK");
#else
    (void)raster;
#endif
    quads q;
    make_quads(&q);
    sy_context_pool *pool = it_pool();
    for (uint32_t b = 0; b < n; ++b) {
        sy_viewport *vp;
        sy_camera_view view;
        sy_window *win = one_viewport(names[b], q.s, &vp, &view);
        /* a pick leaves no trace in what the context renders next (the rasterizer's GL state) */
        bool progressive = (sy_mediator_class_caps(sy_mediator_find(names[b]), NULL) & SY_CAP_PROGRESSIVE) != 0;
        sy_layer before = {0}, after = {0};
        if (!progressive) {
            MUST(sy_layer_create(W, H, &before, err));
            MUST(sy_window_render(win, q.s, pool, NULL, &before, err));
        }
        uint32_t hits = 0, tested = 0;
        /* every 7th pixel of every 5th row: both quads, both triangles of each, B's two primitives,
         * the overlap (B in front) and the misses around */
        for (uint32_t py = 1; py < H; py += 5)
            for (uint32_t px = 2; px < W; px += 7) {
                expect e = expected(&q, &view, px, py);
                /* pixels whose centre lies within 1e-3 of a quad's edge or diagonal are left out: the
                 * coverage rules of a rasterizer and a ray tracer may differ there by rounding */
                bool edge = false;
                for (int dx = -1; dx <= 1 && !edge; dx += 2)
                    for (int dy = -1; dy <= 1 && !edge; dy += 2) {
                        sy_camera_view nv = view;
                        double ex_ = 1e-3 * (view.window[1] - view.window[0]) * dx, ey_ = 1e-3 * (view.window[3] - view.window[2]) * dy;
                        nv.window[0] += (float)ex_, nv.window[1] += (float)ex_, nv.window[2] += (float)ey_, nv.window[3] += (float)ey_;
                        expect o = expected(&q, &nv, px, py);
                        edge = o.hit != e.hit || o.node != e.node || o.primitive != e.primitive || o.triangle != e.triangle;
                    }
                if (edge) continue;
                sy_pick_result p;
                sy_error perr = {0};
                EXPECT_OK(sy_window_pick(win, q.s, pool, px + 0.25, py + 0.75, &p, &perr), perr);
                EXPECT(p.viewport == 0 && p.eye == SY_EYE_MONO && p.pixel_x == px && p.pixel_y == py);
                check_pick(names[b], px, py, &p, &e);
                tested++;
                hits += e.hit;
            }
        EXPECT_MSG(hits > 200 && tested - hits > 100, "%s: %u pixels tested, %u hits", names[b], tested, hits);
        if (!progressive) {
            MUST(sy_layer_create(W, H, &after, err));
            MUST(sy_window_render(win, q.s, pool, NULL, &after, err));
            EXPECT_MSG(it_layers_identical(&before, &after), "%s: the image after the picks differs from the one before",
                       names[b]);
            sy_layer_destroy(&before);
            sy_layer_destroy(&after);
        }
        sy_window_destroy(win);
    }
    sy_context_pool_destroy(pool);
    sy_scene_destroy(q.s);
}

/* ---------------------------------------------------------------- 2. a DAG */
static void test_dag(void)
{
    const char *names[16];
    uint32_t n = pick_classes(names);
    sy_scene *s = it_scene();
    sy_material m = material(s, "m");
    const float qd[1][3] = {{0.0f, 0.0f, 0.4f}};
    sy_mesh mesh = it_quad_mesh(s, "quad", qd, &m, 1);
    sy_node shared, left, right;
    MUST(sy_node_create(s, "shared", &shared, err));
    MUST(sy_node_set_mesh(s, shared, mesh, err));
    MUST(sy_node_create(s, "left", &left, err));
    MUST(sy_node_create(s, "right", &right, err));
    it_set_translation(s, left, -0.6f, 0.0f, 0.0f);
    it_set_translation(s, right, 0.6f, 0.0f, 0.0f);
    MUST(sy_node_add_child(s, left, shared, err));
    MUST(sy_node_add_child(s, right, shared, err));
    MUST(sy_scene_commit(s, NULL, err));
    sy_context_pool *pool = it_pool();
    for (uint32_t b = 0; b < n; ++b) {
        sy_viewport *vp;
        sy_camera_view view;
        sy_window *win = one_viewport(names[b], s, &vp, &view);
        uint32_t lx, ly, rx, ry;
        const float pl[3] = {-0.6f, 0.1f, 0.0f}, pr[3] = {0.6f, 0.1f, 0.0f};
        float fx, fy;
        it_project(&view, pl, W, H, &fx, &fy), lx = (uint32_t)fx, ly = (uint32_t)fy;
        it_project(&view, pr, W, H, &fx, &fy), rx = (uint32_t)fx, ry = (uint32_t)fy;
        sy_pick_result a, c;
        sy_error perr = {0};
        EXPECT_OK(sy_viewport_pick(vp, s, pool, lx, ly, &a, &perr), perr);
        EXPECT_OK(sy_viewport_pick(vp, s, pool, rx, ry, &c, &perr), perr);
        EXPECT_MSG(a.hit && c.hit && a.node_id == shared.id && c.node_id == shared.id && a.placement != c.placement,
                   "%s: DAG placements %u %u (hits %d %d)", names[b], a.placement, c.placement, a.hit, c.hit);
        EXPECT_MSG(a.position[0] < -0.2f && c.position[0] > 0.2f, "%s: positions %g, %g", names[b], a.position[0],
                   c.position[0]);
        sy_window_destroy(win);
    }
    sy_context_pool_destroy(pool);
    sy_scene_destroy(s);
}

/* ---------------------------------------------------------------- 3. layers and eyes; 4. bad input */
static const sy_mediator_class nopick_class = {.name = "test_nopick", .caps = SY_CAP_DEPTH, IT_STUB_FUNCTIONS};

static void test_window(void)
{
    quads q;
    make_quads(&q);
    sy_context_pool *pool = it_pool();
    sy_mat4 cam = cam_at_5();
    /* viewport 0: root A (replace), viewport 1: root B, in each composite mode */
    static const uint32_t modes[3] = {SY_COMPOSITE_DEPTH, SY_COMPOSITE_ALPHA_OVER, SY_COMPOSITE_REPLACE};
    for (int k = 0; k < 3; ++k) {
        sy_window *win;
        sy_viewport *v0, *v1;
        MUST(sy_window_create(W, H, &win, err));
        sy_viewport_desc d0 = {.backend = "whitted", .root = q.a};
        sy_viewport_desc d1 = {.backend = "whitted", .root = q.b, .composite = modes[k]};
        MUST(sy_window_add_viewport(win, &d0, &v0, err));
        MUST(sy_window_add_viewport(win, &d1, &v1, err));
        sy_viewport_set_view(v0, &cam);
        sy_viewport_set_view(v1, &cam);
        sy_camera_view view;
        MUST(sy_viewport_camera_view(v0, q.s, W, H, &view, err));
        uint32_t ox, oy, ax, ay;
        float fx, fy;
        const float overlap[3] = {0.0f, -0.3f, 0.0f}, only_a[3] = {-0.7f, -0.3f, 0.0f};
        it_project(&view, overlap, W, H, &fx, &fy), ox = (uint32_t)fx, oy = (uint32_t)fy;
        it_project(&view, only_a, W, H, &fx, &fy), ax = (uint32_t)fx, ay = (uint32_t)fy;
        sy_pick_result p;
        sy_error perr = {0};
        EXPECT_OK(sy_window_pick(win, q.s, pool, ox, oy, &p, &perr), perr);
        EXPECT_MSG(p.hit && p.viewport == 1 && p.node_id == q.b.id, "mode %u: overlap answered by viewport %u node %#x",
                   modes[k], p.viewport, p.node_id);
        EXPECT_OK(sy_window_pick(win, q.s, pool, ax, ay, &p, &perr), perr);
        if (modes[k] == SY_COMPOSITE_REPLACE)
            EXPECT_MSG(!p.hit && p.viewport == 1, "replace: the top layer's miss must answer (viewport %u hit %d)",
                       p.viewport, p.hit);
        else
            EXPECT_MSG(p.hit && p.viewport == 0 && p.node_id == q.a.id, "mode %u: A-only pixel answered by %u node %#x",
                       modes[k], p.viewport, p.node_id);
        /* an inactive top layer is left out */
        sy_viewport_set_active(v1, false);
        EXPECT_OK(sy_window_pick(win, q.s, pool, ox, oy, &p, &perr), perr);
        EXPECT_MSG(p.hit && p.viewport == 0 && p.node_id == q.a.id, "inactive top layer answered");
        sy_window_destroy(win);
    }

    /* side-by-side stereo: two W x H halves of a 2W x H window */
    sy_window *win;
    sy_viewport *l, *r;
    MUST(sy_window_create(2 * W, H, &win, err));
    sy_viewport_desc dl = {.backend = "whitted", .eye = SY_EYE_LEFT, .width = W, .eye_separation = 0.2f};
    sy_viewport_desc dr = {.backend = "whitted", .eye = SY_EYE_RIGHT, .x = W, .width = W, .eye_separation = 0.2f};
    MUST(sy_window_add_viewport(win, &dl, &l, err));
    MUST(sy_window_add_viewport(win, &dr, &r, err));
    sy_viewport_set_view(l, &cam);
    sy_viewport_set_view(r, &cam);
    sy_pick_result p;
    sy_error perr = {0};
    EXPECT_OK(sy_window_pick(win, q.s, pool, W + W / 2 + 0.5, H / 2 + 0.5, &p, &perr), perr);
    EXPECT_MSG(p.hit && p.viewport == 1 && p.eye == SY_EYE_RIGHT && p.pixel_x == W / 2 && p.pixel_y == H / 2,
               "stereo right half: viewport %u eye %u pixel %u,%u", p.viewport, p.eye, p.pixel_x, p.pixel_y);
    /* the point lies on the right eye's ray through that pixel (the eye is 0.1 to the right) */
    sy_camera_view rv;
    MUST(sy_viewport_camera_view(r, q.s, 2 * W, H, &rv, err));
    double tx = rv.window[0] + (W / 2 + 0.5) / W * (rv.window[1] - rv.window[0]);
    double ty = rv.window[3] - (H / 2 + 0.5) / H * (rv.window[3] - rv.window[2]);
    double d = CAM_Z - p.position[2];
    EXPECT_MSG(fabs(rv.camera_to_world.m[12] - 0.1f) < 1e-6f, "right eye at x %g", rv.camera_to_world.m[12]);
    EXPECT_MSG(fabs(p.position[0] - (0.1 + tx * d)) < 1e-4 && fabs(p.position[1] - ty * d) < 1e-4,
               "right eye: position %g %g off its ray (%g %g)", p.position[0], p.position[1], 0.1 + tx * d, ty * d);
    EXPECT_OK(sy_window_pick(win, q.s, pool, 10.0, 10.0, &p, &perr), perr);
    EXPECT(p.viewport == 0 && p.eye == SY_EYE_LEFT);

    /* 4. bad input */
    sy_error e = {0};
    EXPECT_ERR(sy_window_pick(win, q.s, pool, NAN, 3.0, &p, &e), SY_ERR_INVALID_ARGUMENT, e);
    EXPECT_SAYS(e, "nan");
    EXPECT_ERR(sy_window_pick(win, q.s, pool, 3.0, INFINITY, &p, &e), SY_ERR_INVALID_ARGUMENT, e);
    EXPECT_SAYS(e, "inf");
    EXPECT_ERR(sy_window_pick(win, q.s, pool, 2.0 * W, 3.0, &p, &e), SY_ERR_INVALID_ARGUMENT, e);
    EXPECT_SAYS(e, "320, 3");
    EXPECT_ERR(sy_window_pick(win, q.s, pool, -0.5, 3.0, &p, &e), SY_ERR_INVALID_ARGUMENT, e);
    EXPECT_SAYS(e, "-0.5");
    EXPECT(!p.hit && p.viewport == UINT32_MAX);
    EXPECT_ERR(sy_viewport_pick(l, q.s, pool, W + 3.0, 3.0, &p, &e), SY_ERR_INVALID_ARGUMENT, e);
    EXPECT_SAYS(e, "outside the viewport");
    MUST(sy_mediator_register(&nopick_class, err));
    MUST(sy_viewport_set_backend(l, "test_nopick", NULL, err));
    EXPECT_ERR(sy_window_pick(win, q.s, pool, 3.0, 3.0, &p, &e), SY_ERR_UNSUPPORTED, e);
    EXPECT_SAYS(e, "test_nopick");
    sy_window_destroy(win);
    sy_context_pool_destroy(pool);
    sy_scene_destroy(q.s);
}

/* ---------------------------------------------------------------- 5. agreement on a sample */
typedef struct agreement {
    uint32_t pixels, covered, coverage_differs, same, positions_far;
    uint32_t differ_near; /* covered pixels naming different triangles at points within 1e-4 x size (an edge) */
    double worst; /* largest position difference / scene size where the triangle agreed */
    double worst_depth; /* largest |pick depth - the depth plane of a one-ray-per-pixel Whitted render| / size */
} agreement;

static uint64_t rng_next(uint64_t *s)
{
    *s = *s * 6364136223846793005ull + 1442695040888963407ull;
    return *s >> 33;
}

/* Picks n random pixels of the framing view of the scene at path in every pick-capable back-end. */
static void agree(const char *path, uint32_t n, uint32_t w, uint32_t h, agreement *out)
{
    memset(out, 0, sizeof *out);
    const char *names[16];
    uint32_t nb = pick_classes(names);
    sy_gltf_info info;
    sy_scene *s = it_load_gltf(path, &info);
    sy_gltf_info_free(&info);
    MUST(sy_scene_commit(s, NULL, err));
    sy_bounds bb = sy_scene_world_bounds(s);
    double size = 0.0;
    for (int k = 0; k < 3; ++k) size += ((double)bb.max[k] - bb.min[k]) * ((double)bb.max[k] - bb.min[k]);
    size = sqrt(size);
    sy_context_pool *pool = it_pool();
    sy_window *win[16];
    for (uint32_t b = 0; b < nb; ++b) {
        MUST(sy_window_create(w, h, &win[b], err));
        sy_viewport_desc vd = {.backend = names[b]};
        MUST(sy_window_add_viewport(win[b], &vd, NULL, err));
    }
    /* an independent check of the points: the depth plane of a Whitted render with one ray
     * through each pixel centre (Embree's own hit distances) */
    sy_layer depth = {0};
    if (sy_mediator_find("whitted")) {
        sy_window *dw;
        MUST(sy_window_create(w, h, &dw, err));
        sy_viewport_desc vd = {.backend = "whitted", .params = "spp=1"};
        MUST(sy_window_add_viewport(dw, &vd, NULL, err));
        MUST(sy_layer_create(w, h, &depth, err));
        MUST(sy_window_render(dw, s, pool, NULL, &depth, err));
        sy_window_destroy(dw);
    }
    uint64_t seed = 1;
    for (uint32_t i = 0; i < n; ++i) {
        uint32_t x = (uint32_t)(rng_next(&seed) % w), y = (uint32_t)(rng_next(&seed) % h);
        sy_pick_result p[16];
        uint32_t hits = 0;
        for (uint32_t b = 0; b < nb; ++b) {
            sy_error perr = {0};
            EXPECT_OK(sy_window_pick(win[b], s, pool, x, y, &p[b], &perr), perr);
            hits += p[b].hit;
        }
        out->pixels++;
        if (hits && hits < nb) out->coverage_differs++;
        if (hits < nb) continue;
        out->covered++;
        if (depth.depth)
            for (uint32_t b = 0; b < nb; ++b)
                out->worst_depth = fmax(out->worst_depth, fabs((double)p[b].depth - depth.depth[(size_t)y * w + x]) / size);
        bool same = true;
        for (uint32_t b = 1; b < nb; ++b)
            same &= p[b].node_id == p[0].node_id && p[b].placement == p[0].placement &&
                    p[b].primitive == p[0].primitive && p[b].triangle == p[0].triangle;
        if (!same) {
            double far = 0.0; /* how far apart the points they name are */
            for (uint32_t b = 1; b < nb; ++b)
                for (int k = 0; k < 3; ++k) far = fmax(far, fabs((double)p[b].position[k] - p[0].position[k]) / size);
            if (far <= SIZE_TOL) out->differ_near++;
            if (getenv("SY_PICK_VERBOSE"))
                for (uint32_t b = 0; b < nb; ++b)
                    printf("  (%u, %u) %-10s node %#x placement %u primitive %u triangle %u at %.6g %.6g %.6g (%.2e x size apart)\n",
                           x, y, names[b], p[b].node_id, p[b].placement, p[b].primitive, p[b].triangle,
                           p[b].position[0], p[b].position[1], p[b].position[2], far);
            continue;
        }
        out->same++;
        double worst = 0.0;
        for (uint32_t b = 1; b < nb; ++b)
            for (int k = 0; k < 3; ++k) worst = fmax(worst, fabs((double)p[b].position[k] - p[0].position[k]) / size);
        if (worst > SIZE_TOL) out->positions_far++;
        out->worst = fmax(out->worst, worst);
    }
    for (uint32_t b = 0; b < nb; ++b) sy_window_destroy(win[b]);
    sy_layer_destroy(&depth);
    sy_context_pool_destroy(pool);
    sy_scene_destroy(s);
}

static void print_agreement(const char *name, const agreement *a)
{
    printf("%-34s pixels %5u  covered by all %5u  coverage differs %4u  same node+triangle %5u (%.2f %%; the others "
           "%u at one point within 1e-4 x size)  positions beyond 1e-4 x size %u, worst %.2e x size; depth vs "
           "Whitted's depth plane worst %.2e x size\n",
           name, a->pixels, a->covered, a->coverage_differs, a->same, a->covered ? 100.0 * a->same / a->covered : 100.0,
           a->differ_near, a->positions_far, a->worst, a->worst_depth);
}

static void test_sample(void)
{
    char buf[1024];
    snprintf(buf, sizeof buf, "%s/gltf/DamagedHelmet/glTF/DamagedHelmet.gltf", SY_TESTDATA_DIR);
    if (access(buf, R_OK) != 0) {
        printf("skip: part 5, %s absent (SY_TESTDATA_DIR=%s)\n", buf, SY_TESTDATA_DIR);
        return;
    }
    agreement a;
    agree(buf, 300, 256, 192, &a);
    print_agreement("DamagedHelmet", &a);
    EXPECT_MSG(a.covered >= 30, "only %u of 300 pixels covered", a.covered);
    EXPECT_MSG(a.same * 100 >= a.covered * 99, "%u of %u covered pixels name the same node and triangle", a.same, a.covered);
    EXPECT_MSG(a.positions_far == 0, "%u positions differ by more than 1e-4 x the scene size", a.positions_far);
    EXPECT_MSG(a.worst_depth <= SIZE_TOL, "a pick's depth differs from Whitted's depth plane by %.2e x the scene size",
               a.worst_depth);
}

int main(int argc, char **argv)
{
    it_register();
    if (argc > 2 && !strcmp(argv[1], "--agreement")) { /* measurement mode (see the file comment) */
        uint32_t n = (uint32_t)strtoul(argv[2], NULL, 10);
        agreement all = {0};
        const char *names[16];
        uint32_t nb = pick_classes(names);
        printf("back-ends:");
        for (uint32_t b = 0; b < nb; ++b) printf(" %s", names[b]);
        printf("\n");
        for (int i = 3; i < argc; ++i) {
            agreement a;
            agree(argv[i], n, 512, 384, &a);
            const char *base = strrchr(argv[i], '/');
            print_agreement(base ? base + 1 : argv[i], &a);
            all.pixels += a.pixels, all.covered += a.covered, all.coverage_differs += a.coverage_differs;
            all.same += a.same, all.differ_near += a.differ_near, all.positions_far += a.positions_far, all.worst = fmax(all.worst, a.worst);
            all.worst_depth = fmax(all.worst_depth, a.worst_depth);
        }
        print_agreement("all", &all);
        return sy_check_finish("pick agreement");
    }
    test_quads();
    test_dag();
    test_window();
    test_sample();
    return sy_check_finish("integration_pick");
}
