/* test_sync.c — incremental mediator sync through the "whitted" context, checked by the adapter's
 * counters and by pixel-exact images.
 *
 * Scene (built in code, no test data): a root with N = 50 leaf children in a 10 x 5 grid, each
 * with its own one-quad mesh (leaf 0's mesh has two quads = two primitives), plus a group node
 * holding 3 nodes that share one mesh (instancing). Materials are unlit, so a pixel covered by a
 * quad shows exactly its base colour and an uncovered one is transparent black with depth +inf.
 *
 * Checks: one leaf moved -> 1 placement, same instance count, image differs only around the old
 * and new screen rectangles; moved back -> bit-identical to the first image; group moved ->
 * placements == subtree size (4); node destroyed -> instances drop by its primitive count; hidden
 * (flags, also inherited from a group) -> disappears, shown again -> back; material colour ->
 * new colour on screen without new instances; attachment-only changes -> no placement work and an
 * identical image; pool returns the same context for the same arguments and a new one for other
 * parameters; a second context (snapshot path) renders the same image as the incremental one. */
#include "it_util.h"
#include "sy_mediator_rt.h"

#define N 50
#define IMG 160
#define SPACING 1.5f
#define HALF 0.25f /* quad half-size */
#define CAM_DIST 10.0f
#define TAN_HALF 0.8f /* the plane z = 0 shows [-8, 8]^2 */

typedef struct fixture {
    sy_scene *s;
    sy_node root, leaf[N], group, shared[3];
    sy_material leaf_mat, leaf_mat2, shared_mat;
    sy_mesh shared_mesh;
    sy_camera_view view;
} fixture;

static void leaf_pos(uint32_t i, float *x, float *y)
{
    *x = ((float)(i % 10) - 4.5f) * SPACING;
    *y = ((float)(i / 10) - 2.0f) * SPACING + 0.75f; /* rows at y = -2.25 .. 3.75 */
}

static void shared_pos(uint32_t i, float *x, float *y)
{
    *x = ((float)i - 1.0f) * 2.0f;
    *y = -5.0f; /* below the grid */
}

static void build(fixture *f)
{
    memset(f, 0, sizeof *f);
    MUST(sy_scene_create(&f->s, err));
    f->leaf_mat = it_unlit(f->s, "leaf", 0.8f, 0.6f, 0.2f);
    f->leaf_mat2 = it_unlit(f->s, "leaf2", 0.1f, 0.9f, 0.3f);
    f->shared_mat = it_unlit(f->s, "shared", 0.2f, 0.3f, 0.9f);
    MUST(sy_node_create(f->s, "root", &f->root, err));
    MUST(sy_node_set_flags(f->s, f->root, SY_NODE_VISIBLE, err));
    for (uint32_t i = 0; i < N; ++i) {
        char name[32];
        snprintf(name, sizeof name, "leaf%u", i);
        /* each leaf has its own mesh, modelled at the origin; the node's transform places it */
        const float quads[2][3] = {{0, 0, HALF}, {0, 0.5f, 0.1f}};
        const sy_material mats[2] = {f->leaf_mat, f->leaf_mat2};
        sy_mesh m = it_quad_mesh(f->s, name, quads, mats, i == 0 ? 2 : 1);
        MUST(sy_node_create(f->s, name, &f->leaf[i], err));
        MUST(sy_node_set_mesh(f->s, f->leaf[i], m, err));
        MUST(sy_node_set_flags(f->s, f->leaf[i], SY_NODE_VISIBLE, err));
        float x, y;
        leaf_pos(i, &x, &y);
        it_set_translation(f->s, f->leaf[i], x, y, 0);
        MUST(sy_node_add_child(f->s, f->root, f->leaf[i], err));
    }
    const float q[1][3] = {{0, 0, HALF}};
    f->shared_mesh = it_quad_mesh(f->s, "shared", q, &f->shared_mat, 1);
    MUST(sy_node_create(f->s, "group", &f->group, err));
    MUST(sy_node_set_flags(f->s, f->group, SY_NODE_VISIBLE, err));
    MUST(sy_node_add_child(f->s, f->root, f->group, err));
    for (uint32_t i = 0; i < 3; ++i) {
        MUST(sy_node_create(f->s, "shared user", &f->shared[i], err));
        MUST(sy_node_set_mesh(f->s, f->shared[i], f->shared_mesh, err));
        MUST(sy_node_set_flags(f->s, f->shared[i], SY_NODE_VISIBLE, err));
        float x, y;
        shared_pos(i, &x, &y);
        it_set_translation(f->s, f->shared[i], x, y, 0);
        MUST(sy_node_add_child(f->s, f->group, f->shared[i], err));
    }
    MUST(sy_scene_commit(f->s, NULL, err));
    f->view = it_view_down_z(CAM_DIST, TAN_HALF);
}

static void render(sy_context *ctx, const fixture *f, sy_layer *out)
{
    sy_render_request req;
    memset(&req, 0, sizeof req);
    req.camera = f->view;
    req.full_width = req.full_height = req.rect_w = req.rect_h = IMG;
    MUST(sy_context_render(ctx, &req, out, err));
}

static sy_mediator_rt_counters counters(sy_context *ctx)
{
    sy_mediator_rt_counters c;
    sy_mediator_rt_counters_get(sy_context_state(ctx), &c);
    return c;
}

static void commit_sync(fixture *f, sy_context *ctx)
{
    MUST(sy_scene_commit(f->s, NULL, err));
    MUST(sy_context_sync(ctx, err));
}

/* Screen rectangle (pixels, inclusive, with a margin) of the world square centred at (x, y, 0). */
typedef struct rect { int x0, y0, x1, y1; } rect;
static rect screen_rect(const fixture *f, float x, float y, float h, int margin)
{
    float ax, ay, bx, by;
    const float a[3] = {x - h, y + h, 0}, b[3] = {x + h, y - h, 0};
    it_project(&f->view, a, IMG, IMG, &ax, &ay);
    it_project(&f->view, b, IMG, IMG, &bx, &by);
    rect r = {(int)floorf(ax) - margin, (int)floorf(ay) - margin, (int)floorf(bx) + margin, (int)floorf(by) + margin};
    return r;
}

static bool in_rect(const rect *r, int x, int y) { return x >= r->x0 && x <= r->x1 && y >= r->y0 && y <= r->y1; }

/* Pixel containing the world point (x, y, 0). */
static void pixel_of(const fixture *f, float x, float y, uint32_t *px, uint32_t *py)
{
    const float p[3] = {x, y, 0};
    float fx, fy;
    it_project(&f->view, p, IMG, IMG, &fx, &fy);
    *px = (uint32_t)fx;
    *py = (uint32_t)fy;
}

/* shared user i's centre (x, y) and its pixel */
static void shared_pixel(const fixture *f, uint32_t i, float *x, float *y, uint32_t *px, uint32_t *py)
{
    shared_pos(i, x, y);
    pixel_of(f, *x, *y, px, py);
}

static uint32_t count_changed(const sy_layer *a, const sy_layer *b, const rect *allowed, uint32_t nallowed,
                              uint32_t *outside)
{
    uint32_t changed = 0;
    *outside = 0;
    for (uint32_t y = 0; y < IMG; ++y)
        for (uint32_t x = 0; x < IMG; ++x)
            if (!it_px_same(a, b, x, y)) {
                changed++;
                bool ok = false;
                for (uint32_t k = 0; k < nallowed; ++k) ok |= in_rect(&allowed[k], (int)x, (int)y);
                if (!ok) (*outside)++;
            }
    return changed;
}

int main(void)
{
    it_register();
    fixture f;
    build(&f);

    sy_context *ctx;
    MUST(sy_context_create(f.s, "whitted", NULL, 0, &ctx, err));
    MUST(sy_context_sync(ctx, err));
    sy_mediator_rt_counters c0 = counters(ctx);
    const uint32_t total_inst = (N + 1) + 3; /* leaf 0 has two primitives */
    EXPECT_MSG(c0.instances == total_inst, "instances %u, expected %u", c0.instances, total_inst);
    EXPECT_MSG(c0.meshes == 2 * 1 + (N - 1) + 1, "back-end meshes %u (one per primitive, shared mesh once)", c0.meshes);
    EXPECT_MSG(c0.last_sync_placements == 1 + N + 1 + 3, "first sync placed %u nodes", c0.last_sync_placements);

    sy_layer img0, img1, img2;
    MUST(sy_layer_create(IMG, IMG, &img0, err));
    MUST(sy_layer_create(IMG, IMG, &img1, err));
    MUST(sy_layer_create(IMG, IMG, &img2, err));
    render(ctx, &f, &img0);
    EXPECT(sy_layer_count_nonfinite(&img0) == 0);

    /* every leaf and shared node shows its colour at its centre; between them there is nothing */
    for (uint32_t i = 0; i < N; ++i) {
        float x, y;
        uint32_t px, py;
        leaf_pos(i, &x, &y);
        pixel_of(&f, x, y, &px, &py);
        EXPECT_MSG(it_px_is(&img0, px, py, 0.8f, 0.6f, 0.2f, 1.0f), "leaf %u not visible at pixel %u,%u", i, px, py);
        float d = img0.depth[py * IMG + px];
        EXPECT_MSG(fabsf(d - CAM_DIST) < 1e-3f, "leaf %u depth %f, expected %f", i, d, CAM_DIST);
        pixel_of(&f, x + 0.75f, y + 0.75f, &px, &py); /* the gap between four leaves */
        EXPECT_MSG(it_px_is(&img0, px, py, 0, 0, 0, 0) && isinf(img0.depth[py * IMG + px]), "gap near leaf %u not empty", i);
    }
    for (uint32_t i = 0; i < 3; ++i) {
        float x, y;
        uint32_t px, py;
        shared_pixel(&f, i, &x, &y, &px, &py);
        EXPECT_MSG(it_px_is(&img0, px, py, 0.2f, 0.3f, 0.9f, 1.0f), "shared user %u not visible", i);
    }
    {   /* leaf 0's second primitive (a small quad above its centre) */
        float x, y;
        uint32_t px, py;
        leaf_pos(0, &x, &y);
        pixel_of(&f, x, y + 0.5f, &px, &py);
        EXPECT_MSG(it_px_is(&img0, px, py, 0.1f, 0.9f, 0.3f, 1.0f), "leaf 0's second primitive not visible");
    }

    /* ---- move one leaf: one placement, same instances, local image change ---- */
    const uint32_t k = 23;
    float kx, ky;
    leaf_pos(k, &kx, &ky);
    it_set_translation(f.s, f.leaf[k], kx + 0.6f, ky, 0);
    commit_sync(&f, ctx);
    sy_mediator_rt_counters c1 = counters(ctx);
    EXPECT_MSG(c1.last_sync_placements == 1, "moving one leaf recomputed %u placements", c1.last_sync_placements);
    EXPECT_MSG(c1.last_sync_entries == 1, "moving one leaf gave %u change entries", c1.last_sync_entries);
    EXPECT(c1.instances == total_inst && c1.meshes == c0.meshes);
    render(ctx, &f, &img1);
    {
        rect allowed[2] = {screen_rect(&f, kx, ky, HALF, 1), screen_rect(&f, kx + 0.6f, ky, HALF, 1)};
        uint32_t outside, changed = count_changed(&img0, &img1, allowed, 2, &outside);
        printf("move leaf: %u pixels changed, %u outside the old/new rectangles\n", changed, outside);
        EXPECT(changed > 0);
        EXPECT_MSG(outside == 0, "%u pixels changed away from the moved leaf", outside);
        uint32_t px, py;
        pixel_of(&f, kx - 0.2f, ky, &px, &py); /* uncovered now */
        EXPECT(it_px_is(&img1, px, py, 0, 0, 0, 0) && isinf(img1.depth[py * IMG + px]));
        pixel_of(&f, kx + 0.6f, ky, &px, &py); /* newly covered */
        EXPECT(it_px_is(&img1, px, py, 0.8f, 0.6f, 0.2f, 1.0f));
    }
    /* move it back: bit-identical to the first image */
    it_set_translation(f.s, f.leaf[k], kx, ky, 0);
    commit_sync(&f, ctx);
    EXPECT(counters(ctx).last_sync_placements == 1);
    render(ctx, &f, &img2);
    EXPECT_MSG(it_layers_identical(&img0, &img2), "moving a leaf back does not restore the first image");

    /* ---- a group's transform: the group and its 3 children are re-placed ---- */
    it_set_translation(f.s, f.group, 0.0f, 0.4f, 0.0f);
    commit_sync(&f, ctx);
    sy_mediator_rt_counters c2 = counters(ctx);
    EXPECT_MSG(c2.last_sync_placements == 4, "moving the group recomputed %u placements, expected 4",
               c2.last_sync_placements);
    EXPECT(c2.instances == total_inst);
    render(ctx, &f, &img1);
    {
        rect allowed[6];
        for (uint32_t i = 0; i < 3; ++i) {
            float x, y;
            shared_pos(i, &x, &y);
            allowed[2 * i] = screen_rect(&f, x, y, HALF, 1);
            allowed[2 * i + 1] = screen_rect(&f, x, y + 0.4f, HALF, 1);
            uint32_t px, py;
            pixel_of(&f, x, y + 0.45f, &px, &py); /* above the old square, inside the new one */
            EXPECT_MSG(it_px_is(&img1, px, py, 0.2f, 0.3f, 0.9f, 1.0f), "shared user %u did not move with its group", i);
        }
        uint32_t outside;
        count_changed(&img0, &img1, allowed, 6, &outside);
        EXPECT_MSG(outside == 0, "%u pixels changed away from the group's children", outside);
    }
    it_set_translation(f.s, f.group, 0.0f, 0.0f, 0.0f);
    commit_sync(&f, ctx);
    render(ctx, &f, &img2);
    EXPECT_MSG(it_layers_identical(&img0, &img2), "moving the group back does not restore the first image");

    /* ---- attachment-only changes: no instance or placement work, same image ---- */
    {
        sy_attachment a = {.key = "nobody.understands.this", .kind = SY_ATTACH_INT, .value.i = 42};
        MUST(sy_object_set_attachment(f.s, SY_TYPE_NODE, f.leaf[5].id, &a, err));
        MUST(sy_object_set_attachment(f.s, SY_TYPE_NODE, f.group.id, &a, err));
        MUST(sy_object_set_attachment(f.s, SY_TYPE_MESH, f.shared_mesh.id, &a, err));
        MUST(sy_object_set_attachment(f.s, SY_TYPE_MATERIAL, f.leaf_mat.id, &a, err));
        commit_sync(&f, ctx);
        sy_mediator_rt_counters c = counters(ctx);
        EXPECT_MSG(c.last_sync_entries == 4, "attachments gave %u entries", c.last_sync_entries);
        EXPECT_MSG(c.last_sync_placements == 0, "attachment-only change recomputed %u placements", c.last_sync_placements);
        EXPECT(c.instances == total_inst && c.meshes == c0.meshes && c.materials == c0.materials);
        render(ctx, &f, &img2);
        EXPECT_MSG(it_layers_identical(&img0, &img2), "attachment-only change altered the image");
    }

    /* ---- material colour: new colour on screen, no new instances or placements ---- */
    {
        sy_material_data d = *sy_material_get(f.s, f.shared_mat);
        d.base_color[0] = 1.0f, d.base_color[1] = 0.0f, d.base_color[2] = 0.5f;
        MUST(sy_material_set(f.s, f.shared_mat, &d, err));
        commit_sync(&f, ctx);
        sy_mediator_rt_counters c = counters(ctx);
        EXPECT(c.instances == total_inst && c.materials == c0.materials);
        EXPECT_MSG(c.last_sync_placements == 0, "a material change recomputed %u placements", c.last_sync_placements);
        render(ctx, &f, &img1);
        rect allowed[3];
        for (uint32_t i = 0; i < 3; ++i) {
            float x, y;
            uint32_t px, py;
            shared_pixel(&f, i, &x, &y, &px, &py);
            EXPECT_MSG(it_px_is(&img1, px, py, 1.0f, 0.0f, 0.5f, 1.0f), "shared user %u does not show the new colour", i);
            allowed[i] = screen_rect(&f, x, y, HALF, 1);
        }
        uint32_t outside;
        count_changed(&img0, &img1, allowed, 3, &outside);
        EXPECT_MSG(outside == 0, "material change altered %u pixels of other objects", outside);
    }

    /* ---- hide via flags (inherited by children), show again ---- */
    {
        uint32_t lx, ly;
        float x, y;
        leaf_pos(7, &x, &y);
        pixel_of(&f, x, y, &lx, &ly);
        MUST(sy_node_set_flags(f.s, f.leaf[7], 0, err));
        MUST(sy_node_set_flags(f.s, f.group, 0, err));
        commit_sync(&f, ctx);
        EXPECT_MSG(counters(ctx).last_sync_placements == 5, "hiding a leaf and a group re-placed %u",
                   counters(ctx).last_sync_placements);
        render(ctx, &f, &img2);
        EXPECT_MSG(it_px_is(&img2, lx, ly, 0, 0, 0, 0) && isinf(img2.depth[ly * IMG + lx]), "hidden leaf still visible");
        for (uint32_t i = 0; i < 3; ++i) {
            uint32_t px, py;
            shared_pixel(&f, i, &x, &y, &px, &py);
            EXPECT_MSG(it_px_is(&img2, px, py, 0, 0, 0, 0), "child %u of a hidden group still visible", i);
        }
        MUST(sy_node_set_flags(f.s, f.leaf[7], SY_NODE_VISIBLE, err));
        MUST(sy_node_set_flags(f.s, f.group, SY_NODE_VISIBLE, err));
        commit_sync(&f, ctx);
        render(ctx, &f, &img2);
        EXPECT_MSG(it_layers_identical(&img1, &img2), "showing hidden nodes again does not restore the image");
    }

    /* ---- destroy a node: instances drop by its primitive count (leaf 0 has 2) ---- */
    {
        uint32_t before = counters(ctx).instances;
        MUST(sy_object_destroy(f.s, SY_TYPE_NODE, f.leaf[0].id, err));
        commit_sync(&f, ctx);
        uint32_t after = counters(ctx).instances;
        EXPECT_MSG(after + 2 == before, "destroying a 2-primitive node: instances %u -> %u", before, after);
        MUST(sy_object_destroy(f.s, SY_TYPE_NODE, f.leaf[1].id, err));
        commit_sync(&f, ctx);
        EXPECT_MSG(counters(ctx).instances + 3 == before, "destroying a 1-primitive node: instances %u -> %u", after,
                   counters(ctx).instances);
        render(ctx, &f, &img2);
        for (uint32_t i = 0; i < 2; ++i) {
            float x, y;
            uint32_t px, py;
            leaf_pos(i, &x, &y);
            pixel_of(&f, x, y, &px, &py);
            EXPECT_MSG(it_px_is(&img2, px, py, 0, 0, 0, 0), "destroyed leaf %u still visible", i);
        }
        rect allowed[2];
        for (uint32_t i = 0; i < 2; ++i) {
            float x, y;
            leaf_pos(i, &x, &y);
            allowed[i] = screen_rect(&f, x, y + 0.2f, HALF + 0.2f, 1);
        }
        uint32_t outside;
        count_changed(&img1, &img2, allowed, 2, &outside);
        EXPECT_MSG(outside == 0, "destroying leaves altered %u other pixels", outside);
    }

    /* ---- a second context on the same scene: the snapshot path gives the same image ---- */
    {
        sy_context_pool *pool = it_pool();
        sy_context *a, *b, *c;
        MUST(sy_context_pool_get(pool, f.s, "whitted", NULL, 0, &a, err));
        MUST(sy_context_pool_get(pool, f.s, "whitted", NULL, 0, &b, err));
        EXPECT_MSG(a == b, "the pool created two contexts for the same arguments");
        sy_params p;
        MUST(sy_params_parse("max_depth=3", &p, err));
        MUST(sy_context_pool_get(pool, f.s, "whitted", &p, 0, &c, err));
        EXPECT_MSG(c != a, "different back-end parameters returned the same context");
        sy_context *d;
        MUST(sy_context_pool_get(pool, f.s, "whitted", &p, 0, &d, err));
        EXPECT(d == c);
        EXPECT(sy_context_pool_size(pool) == 2);
        EXPECT(a != ctx);
        MUST(sy_context_sync(a, err));
        MUST(sy_context_sync(c, err));
        sy_mediator_rt_counters ca = counters(a), cc = counters(c), cx = counters(ctx);
        EXPECT_MSG(ca.instances == cx.instances && cc.instances == cx.instances,
                   "snapshot contexts have %u / %u instances, the incremental one %u", ca.instances, cc.instances,
                   cx.instances);
        render(ctx, &f, &img1);
        render(a, &f, &img2);
        EXPECT_MSG(it_layers_identical(&img1, &img2), "a fresh context renders differently from the incremental one");
        render(c, &f, &img2);
        EXPECT_MSG(it_layers_identical(&img1, &img2), "max_depth=3 changed an image of unlit quads");
        /* a change reaches every context */
        it_set_translation(f.s, f.leaf[9], 0, 0, -100.0f);
        MUST(sy_scene_commit(f.s, NULL, err));
        MUST(sy_context_sync(a, err));
        MUST(sy_context_sync(ctx, err));
        EXPECT(counters(a).last_sync_placements == 1 && counters(ctx).last_sync_placements == 1);
        render(ctx, &f, &img1);
        render(a, &f, &img2);
        EXPECT(it_layers_identical(&img1, &img2));
        sy_context_pool_destroy(pool);
    }

    sy_layer_destroy(&img0);
    sy_layer_destroy(&img1);
    sy_layer_destroy(&img2);
    sy_context_release(ctx);
    sy_scene_destroy(f.s);
    return sy_check_finish("integration_sync");
}
