/* test_primitives.c — line and point primitives in core (issue 15 part 4): validation (whole index
 * pairs for lines, any count for points, topology and width ranges), element / triangle counts,
 * the stroke width rule, mesh bounds grown by half the width, and the change-list round trip
 * (serialise, decode, apply to a replica, compare) of a line primitive with an explicit width; skin
 * attributes and morph targets refused when malformed; a skinned mesh's world bounds where its
 * joints put its vertices. */
#include "../support/sy_check.h"
#include "../support/sy_scene_test.h"
#include "wire_copy.h"
#include "sy_changes.h"
#include "sy_scene.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>


static const float POS[] = {0, 0, 0, 3, 0, 0, 3, 4, 0, 0, 4, 0}; /* 3 x 4 rectangle: diagonal 5 */

SY_SCENE_TEST(test_validation)
{
    sy_mesh m;
    CHECK_OK(sy_mesh_create(s, "m", &m, &e), e);
    uint32_t odd[] = {0, 1, 2}, pairs[] = {0, 1, 1, 2, 2, 3}, bad[] = {0, 9};
    sy_blob *bp = sy_test_blob(POS, sizeof POS), *bodd = sy_test_blob(odd, sizeof odd), *bpairs = sy_test_blob(pairs, sizeof pairs);
    sy_blob *bbad = sy_test_blob(bad, sizeof bad), *bp3 = sy_test_blob(POS, 36);
    sy_primitive p = {.positions = bp, .indices = bodd, .topology = SY_TOPOLOGY_LINES};
    CHECK_ERR(sy_mesh_set_primitives(s, m, &p, 1, &e), SY_ERR_INVALID_ARGUMENT, e);
    CHECK_MSG(strstr(e.message, "primitive 0") && strstr(e.message, "whole line segments"), "message: %s", e.message);
    p.indices = NULL;
    p.positions = bp3; /* 3 vertices without indices: not whole pairs */
    CHECK_ERR(sy_mesh_set_primitives(s, m, &p, 1, &e), SY_ERR_INVALID_ARGUMENT, e);
    p.positions = bp;
    p.indices = bbad;
    CHECK_ERR(sy_mesh_set_primitives(s, m, &p, 1, &e), SY_ERR_INVALID_ARGUMENT, e);
    CHECK_MSG(strstr(e.message, "past the vertex count"), "message: %s", e.message);
    p.indices = bpairs;
    p.topology = 7;
    CHECK_ERR(sy_mesh_set_primitives(s, m, &p, 1, &e), SY_ERR_INVALID_ARGUMENT, e);
    CHECK_MSG(strstr(e.message, "unknown topology 7"), "message: %s", e.message);
    p.topology = SY_TOPOLOGY_LINES;
    p.width = -1.0f;
    CHECK_ERR(sy_mesh_set_primitives(s, m, &p, 1, &e), SY_ERR_INVALID_ARGUMENT, e);
    p.width = NAN;
    CHECK_ERR(sy_mesh_set_primitives(s, m, &p, 1, &e), SY_ERR_INVALID_ARGUMENT, e);
    p.width = 0.0f;
    /* points: any count, indexed or not */
    sy_primitive pts = {.positions = bp3, .indices = bodd, .topology = SY_TOPOLOGY_POINTS};
    sy_primitive two[2] = {p, pts};
    CHECK_OK(sy_mesh_set_primitives(s, m, two, 2, &e), e);
    CHECK_OK(sy_scene_commit(s, NULL, &e), e);
    const sy_mesh_data *md = sy_mesh_get(s, m);
    CHECK(md->primitives.items[0].topology == SY_TOPOLOGY_LINES);
    CHECK(sy_primitive_element_count(&md->primitives.items[0]) == 3);
    CHECK(sy_primitive_triangle_count(&md->primitives.items[0]) == 0);
    CHECK(sy_primitive_element_count(&md->primitives.items[1]) == 3);
    /* width rule: lines 0.06 x diagonal 5 = 0.3; points over (0,0,0)-(3,4,0)... (3 vertices: 3 x 4) */
    CHECK_NEAR(sy_primitive_stroke_width(&md->primitives.items[0], NULL), SY_STROKE_LINE_FRACTION * 5.0f, 1e-6);
    CHECK_NEAR(sy_primitive_stroke_width(&md->primitives.items[1], NULL), SY_STROKE_POINT_FRACTION * 5.0f, 1e-6);
    sy_primitive explicit_w = p;
    explicit_w.width = 0.25f;
    CHECK_NEAR(sy_primitive_stroke_width(&explicit_w, NULL), 0.25, 0);
    float one[3] = {1, 1, 1};
    sy_blob *b1 = sy_test_blob(one, sizeof one);
    sy_primitive single = {.positions = b1, .topology = SY_TOPOLOGY_POINTS};
    CHECK_NEAR(sy_primitive_stroke_width(&single, NULL), SY_STROKE_MIN_WIDTH, 0); /* no extent: the floor */
    /* bounds: positions grown by half the larger (point) width */
    sy_bounds b;
    CHECK_OK(sy_mesh_bounds(s, m, &b, &e), e);
    float h = 0.5f * SY_STROKE_POINT_FRACTION * 5.0f;
    CHECK_NEAR(b.min[0], -h, 1e-6);
    CHECK_NEAR(b.max[1], 4.0f + h, 1e-6);
    CHECK_NEAR(b.min[2], -h, 1e-6);
    sy_blob_release(bp);
    sy_blob_release(bodd);
    sy_blob_release(bpairs);
    sy_blob_release(bbad);
    sy_blob_release(bp3);
    sy_blob_release(b1);
    return 0;
}

static int test_round_trip(void)
{
    sy_scene *a, *r;
    sy_error e = {0};
    CHECK_OK(sy_scene_create(&a, &e), e);
    CHECK_OK(sy_scene_create(&r, &e), e);
    sy_mesh m;
    CHECK_OK(sy_mesh_create(a, "lines", &m, &e), e);
    uint32_t pairs[] = {0, 1, 1, 2, 2, 3, 3, 0};
    sy_blob *bp = sy_test_blob(POS, sizeof POS), *bi = sy_test_blob(pairs, sizeof pairs);
    sy_primitive p = {.positions = bp, .indices = bi, .topology = SY_TOPOLOGY_LINES, .width = 0.125f};
    CHECK_OK(sy_mesh_set_primitives(a, m, &p, 1, &e), e);
    CHECK_OK(sy_scene_commit(a, NULL, &e), e);
    wire_copy wc;
    if (wire_copy_send(&wc, a, r)) return 1;
    CHECK_OK(sy_scene_commit(r, NULL, &e), e);
    CHECK_MSG(sy_scene_equal(a, r, &e), "replica differs: %s", e.message);
    const sy_mesh_data *md = sy_mesh_get(r, m);
    CHECK(md && md->primitives.count == 1 && md->primitives.items[0].topology == SY_TOPOLOGY_LINES &&
          md->primitives.items[0].width == 0.125f && sy_primitive_element_count(&md->primitives.items[0]) == 4);
    /* the width is compared: a replica with another width differs */
    sy_primitive q = p;
    q.width = 0.5f;
    CHECK_OK(sy_mesh_set_primitives(r, m, &q, 1, &e), e);
    CHECK_OK(sy_scene_commit(r, NULL, &e), e);
    CHECK(!sy_scene_equal(a, r, &e));
    /* strict decoder: a topology past the enum or a negative width in the wire is refused */
    unsigned char *w = wc.wire;
    size_t at = SIZE_MAX;
    for (size_t k = 0; k + 8 <= wc.size; k++) {
        float f;
        uint32_t t;
        memcpy(&t, w + k, 4);
        memcpy(&f, w + k + 4, 4);
        if (t == SY_TOPOLOGY_LINES && f == 0.125f) at = k;
    }
    CHECK(at != SIZE_MAX);
    sy_changes *bad = NULL;
    uint32_t seven = 7;
    memcpy(w + at, &seven, 4);
    CHECK_ERR(sy_changes_deserialize(wc.wire, wc.size, wc.store, NULL, &bad, &e), SY_ERR_PARSE, e);
    CHECK_MSG(strstr(e.message, "topology"), "message: %s", e.message);
    uint32_t lines = SY_TOPOLOGY_LINES;
    float neg = -1.0f;
    memcpy(w + at, &lines, 4);
    memcpy(w + at + 4, &neg, 4);
    CHECK_ERR(sy_changes_deserialize(wc.wire, wc.size, wc.store, NULL, &bad, &e), SY_ERR_PARSE, e);
    CHECK_MSG(strstr(e.message, "width"), "message: %s", e.message);
    wire_copy_free(&wc);
    sy_blob_release(bp);
    sy_blob_release(bi);
    sy_scene_destroy(a);
    sy_scene_destroy(r);
    return 0;
}

/* Skin attributes and morph targets: sizes, pairing, finiteness and target counts refused naming
 * the primitive; a valid set counted (influences, targets); skins on nodes check their joints. */
SY_SCENE_TEST(test_deform_validation)
{
    uint32_t j4[16] = {0}, j3[12] = {0};
    float w4[16] = {0}, dp[24] = {0};
    for (int v = 0; v < 4; ++v) w4[4 * v] = 1.0f;
    sy_mesh m;
    CHECK_OK(sy_mesh_create(s, "m", &m, &e), e);
    sy_blob *bp = sy_test_blob(POS, sizeof POS), *bj = sy_test_blob(j4, sizeof j4), *bw = sy_test_blob(w4, sizeof w4), *bj3 = sy_test_blob(j3, sizeof j3);
    sy_blob *bd2 = sy_test_blob(dp, sizeof dp), *bd1 = sy_test_blob(dp, 48);
    sy_primitive p = {.positions = bp, .joints = bj, .topology = SY_TOPOLOGY_POINTS};
    CHECK_ERR(sy_mesh_set_primitives(s, m, &p, 1, &e), SY_ERR_INVALID_ARGUMENT, e);
    CHECK_MSG(strstr(e.message, "primitive 0") && strstr(e.message, "joints without weights"), "message: %s", e.message);
    p.weights = bw;
    p.joints = bj3; /* 3 per vertex vs 4 weights */
    CHECK_ERR(sy_mesh_set_primitives(s, m, &p, 1, &e), SY_ERR_INVALID_ARGUMENT, e);
    p.joints = bj;
    w4[5] = NAN;
    sy_blob *bwn = sy_test_blob(w4, sizeof w4);
    p.weights = bwn;
    CHECK_ERR(sy_mesh_set_primitives(s, m, &p, 1, &e), SY_ERR_INVALID_ARGUMENT, e);
    CHECK_MSG(strstr(e.message, "not finite"), "message: %s", e.message);
    p.weights = bw;
    p.target_positions = bd2;
    p.target_normals = bd1; /* 2 targets vs 1 */
    CHECK_ERR(sy_mesh_set_primitives(s, m, &p, 1, &e), SY_ERR_INVALID_ARGUMENT, e);
    CHECK_MSG(strstr(e.message, "target_normals"), "message: %s", e.message);
    p.target_normals = bd2;
    CHECK_OK(sy_mesh_set_primitives(s, m, &p, 1, &e), e);
    const sy_primitive *q = &sy_mesh_get(s, m)->primitives.items[0];
    CHECK(sy_primitive_influences(q) == 4 && sy_primitive_target_count(q) == 2);
    /* skins: joints live nodes, matrices finite */
    sy_node n, j;
    CHECK_OK(sy_node_create(s, "skinned", &n, &e), e);
    CHECK_OK(sy_node_create(s, "joint", &j, &e), e);
    sy_mat4 ibm = sy_mat4_identity();
    ibm.m[5] = NAN;
    CHECK_ERR(sy_node_set_skin(s, n, &j, &ibm, 1, (sy_node){0}, &e), SY_ERR_INVALID_ARGUMENT, e);
    sy_node stale = {j.id ^ (1u << SY_HANDLE_INDEX_BITS)};
    CHECK_ERR(sy_node_set_skin(s, n, &stale, NULL, 1, (sy_node){0}, &e), SY_ERR_INVALID_HANDLE, e);
    CHECK_OK(sy_node_set_skin(s, n, &j, NULL, 1, j, &e), e);
    uint32_t nj;
    const sy_skin_joint *sj = sy_node_skin(sy_node_get(s, n), &nj);
    CHECK(nj == 1 && sj[0].node == j.id && sj[0].inverse_bind.m[0] == 1.0f && sy_node_get(s, n)->skeleton.id == j.id);
    sy_blob *all[] = {bp, bj, bw, bj3, bd2, bd1, bwn};
    for (size_t k = 0; k < sizeof all / sizeof all[0]; ++k) sy_blob_release(all[k]);
    return 0;
}

/* World bounds of a skinned mesh follow its joints (sy_scene_graph.c, skinned bounds): a bar along x
 * from 0 to 4, its right half on a joint at x = 2 that turns 90 degrees about z; the bounds are
 * those of the vertices where the deformer puts them (sum_k w_k joint world x inverse bind), the
 * skinned node's own placement (a parent moved by 5 in y) is ignored as glTF says, and moving the
 * joints' root moves the bounds. Before: the bind pose's bounds at every pose. */
static void skin_vertex(const sy_mat4 J[2], const float *w, const float *p, float out[3])
{
    for (int r = 0; r < 3; ++r)
        out[r] = 0.0f;
    for (int k = 0; k < 2; ++k)
        for (int r = 0; r < 3; ++r)
            out[r] += w[k] * (J[k].m[r] * p[0] + J[k].m[4 + r] * p[1] + J[k].m[8 + r] * p[2] + J[k].m[12 + r]);
}

SY_SCENE_TEST(test_skinned_bounds)
{
    enum { COLS = 5, NV = 2 * COLS };
    float pos[3 * NV], wt[2 * NV];
    uint32_t jn[2 * NV], idx[6 * (COLS - 1)];
    for (int c = 0; c < COLS; ++c)
        for (int r = 0; r < 2; ++r) {
            int v = 2 * c + r;
            pos[3 * v] = (float)c, pos[3 * v + 1] = 0.2f * (float)r, pos[3 * v + 2] = 0.0f;
            jn[2 * v] = 0, jn[2 * v + 1] = 1;
            wt[2 * v] = c < 2 ? 1.0f : c == 2 ? 0.5f : 0.0f; /* x < 2: joint 0; x = 2: both; x > 2: joint 1 */
            wt[2 * v + 1] = 1.0f - wt[2 * v];
        }
    for (int c = 0; c + 1 < COLS; ++c) {
        uint32_t a = (uint32_t)(2 * c), q[6] = {a, a + 2, a + 3, a, a + 3, a + 1};
        memcpy(&idx[6 * c], q, sizeof q);
    }
    sy_blob *bp = sy_test_blob(pos, sizeof pos), *bj = sy_test_blob(jn, sizeof jn), *bw = sy_test_blob(wt, sizeof wt);
    sy_blob *bi = sy_test_blob(idx, sizeof idx);
    sy_primitive p = {.positions = bp, .indices = bi, .joints = bj, .weights = bw, .topology = SY_TOPOLOGY_TRIANGLES};
    sy_mesh m;
    sy_node root, group, skinned, j[2];
    CHECK_OK(sy_mesh_create(s, "bar", &m, &e), e);
    CHECK_OK(sy_mesh_set_primitives(s, m, &p, 1, &e), e);
    CHECK_OK(sy_node_create(s, "root", &root, &e), e);
    CHECK_OK(sy_node_create(s, "group", &group, &e), e);
    CHECK_OK(sy_node_create(s, "skinned", &skinned, &e), e);
    CHECK_OK(sy_node_create(s, "j0", &j[0], &e), e);
    CHECK_OK(sy_node_create(s, "j1", &j[1], &e), e);
    CHECK_OK(sy_node_add_child(s, root, group, &e), e);
    CHECK_OK(sy_node_add_child(s, group, skinned, &e), e);
    CHECK_OK(sy_node_add_child(s, root, j[0], &e), e);
    CHECK_OK(sy_node_add_child(s, j[0], j[1], &e), e);
    const float up5[3] = {0, 5, 0}, at2[3] = {2, 0, 0}, id_q[4] = {0, 0, 0, 1}, one[3] = {1, 1, 1};
    CHECK_OK(sy_node_set_trs(s, group, up5, id_q, one, &e), e); /* ignored for the skinned mesh */
    CHECK_OK(sy_node_set_trs(s, j[1], at2, id_q, one, &e), e);
    CHECK_OK(sy_node_set_mesh(s, skinned, m, &e), e);
    sy_mat4 ibm[2] = {sy_mat4_identity(), sy_mat4_identity()};
    ibm[1].m[12] = -2.0f;
    CHECK_OK(sy_node_set_skin(s, skinned, j, ibm, 2, j[0], &e), e);
    const float h = 0.70710678f, turn[4] = {0, 0, h, h}, far[3] = {10, 0, 0};
    for (int step = 0; step < 3; ++step) {
        if (step == 1) CHECK_OK(sy_node_set_trs(s, j[1], at2, turn, one, &e), e);
        if (step == 2) CHECK_OK(sy_node_set_trs(s, j[0], far, id_q, one, &e), e);
        CHECK_OK(sy_scene_commit(s, NULL, &e), e);
        sy_mat4 J[2];
        for (int k = 0; k < 2; ++k) {
            sy_mat4 w;
            CHECK_OK(sy_node_world_matrix(s, j[k], &w, &e), e);
            J[k] = sy_mat4_mul(&w, &ibm[k]);
        }
        sy_bounds want = sy_bounds_empty(), got, all;
        for (int v = 0; v < NV; ++v) {
            float q[3];
            skin_vertex(J, &wt[2 * v], &pos[3 * v], q);
            sy_bounds_add_point(&want, q);
        }
        CHECK_OK(sy_node_world_bounds(s, skinned, &got, &e), e);
        CHECK_OK(sy_node_world_bounds(s, root, &all, &e), e);
        for (int k = 0; k < 3; ++k) {
            CHECK_MSG(fabsf(got.min[k] - want.min[k]) < 1e-4f && fabsf(got.max[k] - want.max[k]) < 1e-4f,
                      "step %d axis %d: bounds [%g, %g], the deformed vertices [%g, %g]", step, k, got.min[k], got.max[k],
                      want.min[k], want.max[k]);
            CHECK_MSG(all.min[k] <= want.min[k] + 1e-4f && all.max[k] >= want.max[k] - 1e-4f,
                      "step %d axis %d: the root's bounds [%g, %g] miss the deformed vertices [%g, %g]", step, k,
                      all.min[k], all.max[k], want.min[k], want.max[k]);
        }
    }
    sy_blob *blobs[] = {bp, bj, bw, bi};
    for (size_t k = 0; k < sizeof blobs / sizeof blobs[0]; ++k) sy_blob_release(blobs[k]);
    return 0;
}

SY_CHECK_MAIN("test_primitives", SY_TEST(test_validation), SY_TEST(test_round_trip), SY_TEST(test_deform_validation),
              SY_TEST(test_skinned_bounds))
