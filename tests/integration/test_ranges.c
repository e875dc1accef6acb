/* test_ranges.c — numbers in range and graph fan-out, end to end (issue 32, items 1 and 4).
 *
 * Each case here ended the process or hung it before the fix:
 *   - a glTF camera at 1e19, an X3D Viewpoint at 1e19: Embree's `ray.valid()` assertion (exit 134)
 *     in Whitted and the path tracer; now the loaders refuse the file naming the node;
 *   - a node scale of 1e-20 on an axis of a shared (instanced) mesh: the same assertion, in
 *     instance space; now the ray tracer bakes such an instance and every back-end renders it
 *     (scales of 1e-30, 0 and [1,0,1] collapse: the node is hidden in every back-end);
 *   - a node scale of 0 (legal glTF, used to hide parts): "transform is singular" failed the whole
 *     render; now the node is not drawn;
 *   - an orbit zoomed out 25 times and panned 14,000 times (what a WebSocket may send): the same
 *     assertion; now the orbit stays within SY_COORD_MAX and the view renders;
 *   - placements composed beyond the range (parent scale x child translation): undrawn with a
 *     warning, and a camera placed so fails the render with an error naming the camera node;
 *   - a DAG of 2^14 paths (an X3D USE chain of 7 KB): the mirror walked it once per path and hung;
 *     2^40 paths: now refused with SY_ERR_LIMIT naming the node, before allocating;
 *   - a node with 10^6 children (a 641-byte EXT_mesh_gpu_instancing file): a quadratic duplicate
 *     check hung the load;
 *   - 64 glTF primitives sharing a 2^24-vertex accessor (3.2 GB from 3.3 KB), an X3D Extrusion of
 *     4000 x 4000 (2.9 GB from 51 KB), a USE graph of 2^30 paths: now each file's budget
 *     (sy_budget.h) refuses them before allocating, naming the file and the item.
 * Back-ends: whitted, pathtracer, and raster where built (SY_HAVE_RASTER). */
#include "it_util.h"

#include "sy_gltf.h"
#include "sy_log.h"
#include "sy_orbit.h"
#include "sy_stats.h"
#include "sy_x3d.h"

#define W 48
#define H 36

static const char *const k_backends[] = {"whitted", "pathtracer",
#ifdef SY_HAVE_RASTER
                                         "raster",
#endif
};
#define BACKEND_COUNT (sizeof k_backends / sizeof k_backends[0])

/* Renders the whole scene (camera node or framing) with one back-end; returns the result and the
 * covered pixel count in *covered. */
static sy_result render(sy_scene *s, sy_node camera, const char *backend, uint32_t *covered, sy_error *e)
{
    sy_context_pool *pool = NULL;
    sy_window *win = NULL;
    sy_layer img = {0};
    sy_result r = sy_context_pool_create(&pool, e);
    if (r == SY_OK) r = sy_window_create(W, H, &win, e);
    sy_viewport_desc d = {.camera = camera, .backend = backend};
    if (r == SY_OK) r = sy_window_add_viewport(win, &d, NULL, e);
    if (r == SY_OK) r = sy_layer_create(W, H, &img, e);
    sy_window_render_opts opts = {.sample_count = 1};
    if (r == SY_OK) r = sy_window_render(win, s, pool, &opts, &img, e);
    *covered = 0;
    if (r == SY_OK) {
        for (size_t i = 0; i < (size_t)W * H; ++i) *covered += sy_layer_covered(&img, i);
        if (sy_layer_count_nonfinite(&img)) r = sy_error_set(e, SY_ERR_INVALID_ARGUMENT, "non-finite pixels");
    }
    sy_layer_destroy(&img);
    sy_window_destroy(win);
    sy_context_pool_destroy(pool);
    return r;
}

/* A glTF document: one triangle mesh (data URI), `nodes` given verbatim, scene of `roots`. */
static sy_result load_gltf(sy_scene *s, const char *nodes, const char *roots, const char *extra, sy_error *e)
{
    char doc[4096];
    snprintf(doc, sizeof doc,
             "{\"asset\":{\"version\":\"2.0\"},"
             "\"buffers\":[{\"byteLength\":36,\"uri\":\"data:application/octet-stream;base64,"
             "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA\"}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\","
             "\"min\":[0,0,0],\"max\":[1,1,0]}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
             "\"cameras\":[{\"type\":\"perspective\",\"perspective\":{\"yfov\":0.8,\"znear\":0.01}}],"
             "\"nodes\":[%s],\"scenes\":[{\"nodes\":[%s]}],\"scene\":0%s}",
             nodes, roots, extra ? extra : "");
    sy_gltf_info info = {0};
    sy_result r = sy_gltf_load_memory(doc, strlen(doc), "ranges.gltf", ".", s, NULL, &info, e);
    sy_gltf_info_free(&info);
    return r;
}

/* An X3D document named name, loaded with the default options. */
static sy_result load_x3d(sy_scene *s, const char *doc, const char *name, sy_error *e)
{
    sy_x3d_info info = {0};
    sy_result r = sy_x3d_load_memory(doc, strlen(doc), name, ".", s, NULL, &info, e);
    sy_x3d_info_free(&info);
    return r;
}

/* A view placed at 1e19 (what: "a camera", "a Viewpoint") must be refused (r) with a message
 * naming the file, the item and the coordinate range; frees s. */
static void expect_far_refused(sy_scene *s, sy_result r, const sy_error *e, const char *file, const char *item,
                               const char *what)
{
    EXPECT_MSG(r != SY_OK && strstr(e->message, file) && strstr(e->message, item) && strstr(e->message, "coordinate range"),
               "%s at 1e19: %s (%s)", what, e->message, sy_result_str(r));
    sy_scene_destroy(s);
}

static void test_gltf_camera_far(void)
{
    sy_scene *s = it_scene();
    sy_error e = {0};
    sy_result r = load_gltf(s, "{\"mesh\":0},{\"camera\":0,\"translation\":[0,0,1e19]}", "0,1", NULL, &e);
    expect_far_refused(s, r, &e, "ranges.gltf", "nodes[1]", "a camera");
}

static void test_x3d_viewpoint_far(void)
{
    static const char doc[] =
        "<?xml version=\"1.0\"?><X3D profile=\"Interchange\" version=\"3.3\"><Scene>"
        "<Viewpoint position=\"0 0 1e19\"/>"
        "<Shape><Box/></Shape></Scene></X3D>";
    sy_scene *s = it_scene();
    sy_error e = {0};
    sy_result r = load_x3d(s, doc, "far.x3d", &e);
    expect_far_refused(s, r, &e, "far.x3d", "Viewpoint", "a Viewpoint");
}

/* One mesh used by two nodes (so the ray tracer instances it rather than baking a static mesh):
 * node 0 at the origin, node 1 with the scale under test, beside it (scale NULL: node 1 absent,
 * the reference). Every back-end renders; *covered_out[b]: pixels covered per back-end. */
static void render_scale(const char *scale, uint32_t covered_out[BACKEND_COUNT])
{
    char nodes[512];
    snprintf(nodes, sizeof nodes,
             "{\"mesh\":0},{\"mesh\":0,\"translation\":[1.5,0,0],\"scale\":%s},"
             "{\"camera\":0,\"translation\":[1,0.5,3]}",
             scale ? scale : "[1,1,1]");
    sy_scene *s = it_scene();
    MUST(load_gltf(s, nodes, scale ? "0,1,2" : "0,2", NULL, err));
    MUST(sy_scene_commit(s, NULL, err));
    sy_node cam = {0};
    for (uint32_t id = sy_scene_next(s, SY_TYPE_NODE, 0); id; id = sy_scene_next(s, SY_TYPE_NODE, id))
        if (sy_node_get(s, (sy_node){id})->camera.id) cam.id = id;
    EXPECT(cam.id != 0);
    for (size_t b = 0; b < BACKEND_COUNT; ++b) {
        uint32_t covered = 0;
        sy_error e = {0};
        sy_result r = render(s, cam, k_backends[b], &covered, &e);
        EXPECT_MSG(r == SY_OK, "scale %s, %s: %s", scale ? scale : "(reference)", k_backends[b], e.message);
        covered_out[b] = covered;
    }
    sy_scene_destroy(s);
}

/* The second node at `scale` adds (visible) or does not add (collapsed or sub-pixel) coverage to
 * the first one's, in every back-end. */
static void test_scale(const char *scale, bool second_visible)
{
    static uint32_t ref[BACKEND_COUNT];
    static bool have_ref;
    if (!have_ref) {
        render_scale(NULL, ref);
        for (size_t b = 0; b < BACKEND_COUNT; ++b) EXPECT_MSG(ref[b] > 30, "reference, %s: %u pixels", k_backends[b], ref[b]);
        have_ref = true;
    }
    uint32_t covered[BACKEND_COUNT];
    render_scale(scale, covered);
    for (size_t b = 0; b < BACKEND_COUNT; ++b)
        EXPECT_MSG(second_visible ? covered[b] > ref[b] + 30 : covered[b] <= ref[b] + 1,
                   "scale %s, %s: %u pixels covered, %u without the node", scale, k_backends[b], covered[b], ref[b]);
}

/* The orbit after 25 zoom-outs and 14,000 large pans stays in range, and renders. */
static void test_orbit(void)
{
    sy_orbit o = {{0, 0, 0}, 0.3f, 0.2f, 3.0f};
    for (int i = 0; i < 25; ++i) sy_orbit_zoom(&o, -50.0f);
    for (int i = 0; i < 14000; ++i) sy_orbit_pan(&o, 1e4f, -1e4f);
    sy_mat4 m;
    sy_orbit_matrix(&o, &m);
    EXPECT_MSG(sy_coords_in_range(m.m, 16), "orbit camera at %g %g %g", (double)m.m[12], (double)m.m[13], (double)m.m[14]);
    sy_scene *s = it_scene();
    MUST(load_gltf(s, "{\"mesh\":0},{\"camera\":0}", "0,1", NULL, err));
    sy_node cam = {0};
    for (uint32_t id = sy_scene_next(s, SY_TYPE_NODE, 0); id; id = sy_scene_next(s, SY_TYPE_NODE, id))
        if (sy_node_get(s, (sy_node){id})->camera.id) cam.id = id;
    MUST(sy_node_set_matrix(s, cam, &m, err));
    MUST(sy_scene_commit(s, NULL, err));
    for (size_t b = 0; b < BACKEND_COUNT; ++b) {
        uint32_t covered = 0;
        sy_error e = {0};
        EXPECT_MSG(render(s, cam, k_backends[b], &covered, &e) == SY_OK, "orbit view, %s: %s", k_backends[b], e.message);
    }
    sy_scene_destroy(s);
}

/* Placements whose composition leaves the range: local values are each in range, their product is
 * not. The mesh placed so is not drawn (the rest is); a camera placed so fails the render. */
static void test_composed(void)
{
    sy_scene *s = it_scene();
    /* node 1 scales by 1e6, its child 2 sits at 1e11 in its frame: 1e17 in the world */
    MUST(load_gltf(s,
                   "{\"mesh\":0},{\"scale\":[1e6,1e6,1e6],\"children\":[2,3]},{\"mesh\":0,\"translation\":[1e11,0,0]},"
                   "{\"camera\":0,\"translation\":[0,0,1e11]},{\"camera\":0,\"translation\":[0.5,0.5,2]}",
                   "0,1,4", NULL, err));
    MUST(sy_scene_commit(s, NULL, err));
    sy_node far = {0}, near = {0};
    for (uint32_t id = sy_scene_next(s, SY_TYPE_NODE, 0); id; id = sy_scene_next(s, SY_TYPE_NODE, id)) {
        const sy_node_data *nd = sy_node_get(s, (sy_node){id});
        if (!nd->camera.id) continue;
        if (nd->transform.translation[2] > 10.0f) far.id = id;
        else near.id = id;
    }
    EXPECT(far.id && near.id);
    for (size_t b = 0; b < BACKEND_COUNT; ++b) {
        uint32_t covered = 0;
        sy_error e = {0};
        sy_result r = render(s, near, k_backends[b], &covered, &e);
        EXPECT_MSG(r == SY_OK && covered > 0, "composed beyond range, %s: %s, %u pixels", k_backends[b], e.message, covered);
        char want[64];
        snprintf(want, sizeof want, "camera node %#x", far.id);
        r = render(s, far, k_backends[b], &covered, &e);
        EXPECT_MSG(r != SY_OK && strstr(e.message, want) && strstr(e.message, "coordinate range"),
                   "a camera at 1e17, %s: %s", k_backends[b], e.message);
    }
    sy_scene_destroy(s);
}

/* Two nodes per level, each with both nodes of the next level as children: 2^levels paths to the
 * leaf, which holds the mesh. */
static sy_scene *diamond(uint32_t levels, sy_node *root_out)
{
    sy_scene *s = it_scene();
    sy_material mat = it_unlit(s, "m", 0.8f, 0.8f, 0.8f);
    const float quad[1][3] = {{0, 0, 0.5f}};
    sy_mesh mesh = it_quad_mesh(s, "q", quad, &mat, 1);
    sy_node leaf;
    MUST(sy_node_create(s, "leaf", &leaf, err));
    MUST(sy_node_set_mesh(s, leaf, mesh, err));
    sy_node next[2] = {leaf, leaf};
    uint32_t next_count = 1;
    for (uint32_t l = 0; l < levels; ++l) {
        sy_node pair[2];
        for (int k = 0; k < 2; ++k) {
            MUST(sy_node_create(s, NULL, &pair[k], err));
            MUST(sy_node_set_children(s, pair[k], next, next_count, err));
        }
        next[0] = pair[0], next[1] = pair[1], next_count = 2;
    }
    MUST(sy_node_create(s, "root", root_out, err));
    MUST(sy_node_set_children(s, *root_out, next, next_count, err));
    MUST(sy_scene_commit(s, NULL, err));
    return s;
}

static void test_dag(void)
{
    sy_node root;
    sy_scene *s = diamond(13, &root); /* 2^14 placements of the leaf */
    for (size_t b = 0; b < BACKEND_COUNT; ++b) {
        uint32_t covered = 0;
        sy_error e = {0};
        EXPECT_MSG(render(s, (sy_node){0}, k_backends[b], &covered, &e) == SY_OK && covered > 0,
                   "2^14 placements, %s: %s, %u pixels", k_backends[b], e.message, covered);
    }
    sy_scene_destroy(s);
    s = diamond(39, &root); /* 2^40: the mirror (shared by every back-end) refuses it; one back-end is enough */
    {
        uint32_t covered = 0;
        sy_error e = {0};
        sy_result r = render(s, (sy_node){0}, "whitted", &covered, &e);
        EXPECT_MSG(r == SY_ERR_LIMIT && strstr(e.message, "paths"), "2^40 placements: %s (%s)", e.message, sy_result_str(r));
    }
    sy_scene_destroy(s);
}

/* EXT_mesh_gpu_instancing with a 10^6-count accessor without a buffer view (zeros): 10^6 children
 * of one node. */
static void test_many_children(void)
{
    static const char doc[] =
        "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"EXT_mesh_gpu_instancing\"],"
        "\"buffers\":[{\"byteLength\":36,\"uri\":\"data:application/octet-stream;base64,"
        "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA\"}],"
        "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
        "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\","
        "\"min\":[0,0,0],\"max\":[1,1,0]},{\"componentType\":5126,\"count\":1000000,\"type\":\"VEC3\"}],"
        "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
        "\"nodes\":[{\"mesh\":0,\"extensions\":{\"EXT_mesh_gpu_instancing\":{\"attributes\":{\"TRANSLATION\":1}}}}],"
        "\"scenes\":[{\"nodes\":[0]}],\"scene\":0}";
    sy_scene *s = it_scene();
    sy_gltf_info info = {0};
    sy_error e = {0};
    sy_result r = sy_gltf_load_memory(doc, sizeof doc - 1, "instances.gltf", ".", s, NULL, &info, &e);
    /* loaded, or refused by the file's budget with a message naming the file: never a hang */
    EXPECT_MSG(r == SY_OK || (r == SY_ERR_LIMIT && strstr(e.message, "instances.gltf")), "10^6 instances: %s (%s)",
               e.message, sy_result_str(r));
    if (r == SY_OK) EXPECT_MSG(sy_scene_count(s, SY_TYPE_NODE) >= 1000000, "%u nodes", sy_scene_count(s, SY_TYPE_NODE));
    sy_gltf_info_free(&info);
    sy_scene_destroy(s);
}

/* One budget per file (sy_budget.h): small files that asked for gigabytes are refused before the
 * allocation, naming the file and the item (each allocated 2.9-3.2 GB, or hung, before). */
static void test_budgets(void)
{
    const uint64_t budget = (uint64_t)512 << 20;
    sy_scene *s = it_scene();
    /* 64 primitives sharing one 2^24-vertex accessor without a buffer view (zeros): 3.3 KB */
    char *doc = malloc(16384);
    size_t n = (size_t)snprintf(doc, 16384,
                                "{\"asset\":{\"version\":\"2.0\"},\"accessors\":[{\"componentType\":5126,\"count\":16777216,"
                                "\"type\":\"VEC3\",\"min\":[0,0,0],\"max\":[0,0,0]}],\"meshes\":[{\"primitives\":[");
    for (int k = 0; k < 64; ++k) n += (size_t)snprintf(doc + n, 16384 - n, "%s{\"attributes\":{\"POSITION\":0}}", k ? "," : "");
    n += (size_t)snprintf(doc + n, 16384 - n, "]}],\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}],\"scene\":0}");
    sy_gltf_options go = {.max_scene_bytes = budget};
    sy_gltf_info gi = {0};
    sy_error e = {0};
    sy_result r = sy_gltf_load_memory(doc, n, "shared.gltf", ".", s, &go, &gi, &e);
    sy_gltf_info_free(&gi);
    EXPECT_MSG(r == SY_ERR_LIMIT && strstr(e.message, "shared.gltf") && strstr(e.message, "meshes[0].primitives[") &&
               strstr(e.message, "scene budget"),
               "64 x 2^24 vertices: %s (%s)", e.message, sy_result_str(r));
    free(doc);
    /* an Extrusion of 4000 x 4000 points (51 KB) */
    size_t cap = 200000;
    char *x = malloc(cap);
    n = (size_t)snprintf(x, cap, "<?xml version=\"1.0\"?><X3D><Scene><Shape><Extrusion crossSection=\"");
    for (int k = 0; k < 4000; ++k) n += (size_t)snprintf(x + n, cap - n, "%d 0 ", k);
    n += (size_t)snprintf(x + n, cap - n, "\" spine=\"");
    for (int k = 0; k < 4000; ++k) n += (size_t)snprintf(x + n, cap - n, "0 %d 0 ", k);
    n += (size_t)snprintf(x + n, cap - n, "\"/></Shape></Scene></X3D>");
    sy_x3d_options xo = {.max_scene_bytes = budget};
    sy_x3d_info xi = {0};
    r = sy_x3d_load_memory(x, n, "extrusion.x3d", ".", s, &xo, &xi, &e);
    sy_x3d_info_free(&xi);
    EXPECT_MSG(r == SY_ERR_LIMIT && strstr(e.message, "extrusion.x3d") && strstr(e.message, "Extrusion") &&
               strstr(e.message, "scene budget"),
               "Extrusion 4000 x 4000: %s (%s)", e.message, sy_result_str(r));
    /* a USE graph of 2^30 paths in 30 levels (a few KB) */
    n = (size_t)snprintf(x, cap, "<?xml version=\"1.0\"?><X3D><Scene><Transform DEF=\"a0\"><Shape><Box/></Shape></Transform>");
    for (int k = 1; k <= 30; ++k)
        n += (size_t)snprintf(x + n, cap - n,
                              "<Transform DEF=\"a%d\"><Transform><Transform USE=\"a%d\"/></Transform>"
                              "<Transform translation=\"1 0 0\"><Transform USE=\"a%d\"/></Transform></Transform>",
                              k, k - 1, k - 1);
    n += (size_t)snprintf(x + n, cap - n, "</Scene></X3D>");
    xi = (sy_x3d_info){0};
    r = sy_x3d_load_memory(x, n, "fanout.x3d", ".", s, NULL, &xi, &e); /* the default budget */
    sy_x3d_info_free(&xi);
    EXPECT_MSG(r == SY_ERR_LIMIT && strstr(e.message, "fanout.x3d") && strstr(e.message, "placements"),
               "2^30 USE paths: %s (%s)", e.message, sy_result_str(r));
    free(x);
    EXPECT_MSG(sy_scene_count(s, SY_TYPE_NODE) == 0, "refused loads leave %u nodes", sy_scene_count(s, SY_TYPE_NODE));
    sy_scene_destroy(s);
}

/* Sanitizer builds (SY_RANGES_REDUCED) render the scales that failed differently before the fix
 * (an abort, a failed render) and skip the three that repeat a kind: each scene costs every
 * back-end a new context, which is slow under ASan. */
static void scales(void)
{
#ifndef SY_RANGES_REDUCED
    test_scale("[1e-30,1e-30,1e-30]", false);
    test_scale("[1,0,1]", false);
    test_scale("[1e-3,1e-3,1e-3]", false);
#endif
    test_scale("[0,0,0]", false);
    test_scale("[1,1,1]", true);
    /* flat in its own z = 0 plane: drawn at full size, while the inverse magnifies z by 1e20 (an
     * instanced ray from the camera at z = 3 went to 3e20 in its space: Embree's assertion) */
    test_scale("[1,1,1e-20]", true);
}

/* test_it_ranges [CASE]: every case, or the one named (to see one fail alone) */
int main(int argc, char **argv)
{
    static const struct {
        const char *name;
        void (*fn)(void);
    } cases[] = {{"gltf_camera_far", test_gltf_camera_far}, {"x3d_viewpoint_far", test_x3d_viewpoint_far},
                 {"scales", scales}, {"orbit", test_orbit}, {"composed", test_composed}, {"dag", test_dag},
                 {"many_children", test_many_children}, {"budgets", test_budgets}};
    it_register();
    sy_log_set_level(SY_LOG_ERROR); /* the undrawn placements warn; the checks read results */
    bool ran = false;
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i)
        if (argc < 2 || strcmp(argv[1], cases[i].name) == 0) {
            cases[i].fn();
            ran = true;
        }
    if (!ran) {
        fprintf(stderr, "test_it_ranges: no case '%s'\n", argv[1]);
        return 2;
    }
    return sy_check_finish("integration_ranges");
}
