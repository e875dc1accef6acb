/* test_anim.c — the scene clock (sy_anim.h) and animation objects (sy_objects.h): the evaluator
 * against hand-computed values (STEP, LINEAR, slerp with the shortest-path flip, CUBICSPLINE by the
 * glTF spec formula, clamping, one key), what a channel leaves alone (other TRS parts, matrix nodes,
 * destroyed nodes), weight channels into the node's morph weights, validation of bad samplers and channels (each refused naming the item),
 * a change-list round trip (serialize -> deserialize -> apply: the same animation, and set_time on
 * both scenes gives equal nodes; the origin's set_time reaches the replica as a plain node change),
 * clip lookup and the play clock; material, light and camera channels (test_properties). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../support/sy_check.h"
#include "../support/sy_scene_test.h"
#include "wire_copy.h"
#include "sy_anim.h"
#include "sy_changes.h"

static sy_scene *new_scene(void)
{
    sy_scene *s = NULL;
    sy_error e = {0};
    if (sy_scene_create(&s, &e) != SY_OK) abort();
    return s;
}

static sy_node new_node(sy_scene *s, const char *name)
{
    sy_node n = {0};
    sy_error e = {0};
    if (sy_node_create(s, name, &n, &e) != SY_OK) abort();
    return n;
}

/* One-channel clip on node n: path, sampler from the arguments. */
static sy_result one_channel(sy_scene *s, sy_animation *a, sy_node n, uint32_t path, uint32_t interp, uint32_t comps,
                             uint32_t keys, const float *times, const float *values, sy_error *e)
{
    if (!a->id && sy_animation_create(s, "clip", a, e) != SY_OK) return e->code;
    sy_anim_sampler_desc sd = {interp, comps, keys, times, values};
    sy_anim_channel ch = {n.id, path, 0};
    return sy_animation_set_clip(s, *a, &sd, 1, &ch, 1, e);
}

static const float *node_t(sy_scene *s, sy_node n) { return sy_node_get(s, n)->transform.translation; }
static const float *node_r(sy_scene *s, sy_node n) { return sy_node_get(s, n)->transform.rotation; }

SY_SCENE_TEST(test_step_linear_clamp)
{
    sy_node n = new_node(s, "n");
    const float times[3] = {0.0f, 1.0f, 2.0f};
    const float vals[9] = {0, 0, 0, 10, 0, 0, 20, 4, 0};
    sy_animation a = {0};
    CHECK_OK(one_channel(s, &a, n, SY_ANIM_TRANSLATION, SY_INTERP_STEP, 3, 3, times, vals, &e), e);
    struct { double t; float x; } step[] = {{-1, 0}, {0, 0}, {0.5, 0}, {1, 10}, {1.99, 10}, {2, 20}, {7, 20}};
    for (size_t i = 0; i < sizeof step / sizeof step[0]; ++i) {
        CHECK_OK(sy_scene_set_time(s, a, step[i].t, &e), e);
        EXPECT_NEAR(node_t(s, n)[0], step[i].x, 0.0);
    }
    CHECK_OK(one_channel(s, &a, n, SY_ANIM_TRANSLATION, SY_INTERP_LINEAR, 3, 3, times, vals, &e), e);
    struct { double t; float x, y; } lin[] = {{-3, 0, 0}, {0.25, 2.5f, 0}, {1, 10, 0}, {1.5, 15, 2}, {2, 20, 4}, {9, 20, 4}};
    for (size_t i = 0; i < sizeof lin / sizeof lin[0]; ++i) {
        CHECK_OK(sy_scene_set_time(s, a, lin[i].t, &e), e);
        EXPECT_NEAR(node_t(s, n)[0], lin[i].x, 1e-6);
        EXPECT_NEAR(node_t(s, n)[1], lin[i].y, 1e-6);
    }
    /* one key: constant */
    const float one_t[1] = {0.5f}, one_v[3] = {7, 8, 9};
    CHECK_OK(one_channel(s, &a, n, SY_ANIM_TRANSLATION, SY_INTERP_LINEAR, 3, 1, one_t, one_v, &e), e);
    CHECK_OK(sy_scene_set_time(s, a, 100.0, &e), e);
    EXPECT_NEAR(node_t(s, n)[2], 9.0, 0.0);
    /* non-finite times are refused */
    CHECK_ERR(sy_scene_set_time(s, a, NAN, &e), SY_ERR_INVALID_ARGUMENT, e);
    CHECK_ERR(sy_scene_set_time(s, (sy_animation){0x12345}, 0.0, &e), SY_ERR_INVALID_HANDLE, e);
    double lo, hi;
    CHECK_OK(sy_scene_time_range(s, a, &lo, &hi, &e), e);
    EXPECT_NEAR(lo, 0.5, 0.0);
    EXPECT_NEAR(hi, 0.5, 0.0);
    return 0;
}

SY_SCENE_TEST(test_slerp)
{
    sy_node n = new_node(s, "n");
    const double h = sqrt(0.5);
    /* identity to -(90 degrees about Y): the same rotation as +90, the dot product is negative; the
     * shortest path goes through +45 degrees about Y at the middle */
    const float times[2] = {0.0f, 1.0f};
    const float q[8] = {0, 0, 0, 1, 0, (float)-h, 0, (float)-h};
    sy_animation a = {0};
    CHECK_OK(one_channel(s, &a, n, SY_ANIM_ROTATION, SY_INTERP_LINEAR, 4, 2, times, q, &e), e);
    struct { double t, angle; } cases[] = {{0.5, TEST_PI / 4}, {0.25, TEST_PI / 8}, {0.75, 3 * TEST_PI / 8}};
    for (size_t i = 0; i < 3; ++i) {
        CHECK_OK(sy_scene_set_time(s, a, cases[i].t, &e), e);
        const float *r = node_r(s, n);
        double sgn = r[3] < 0 ? -1.0 : 1.0; /* q and -q are one rotation */
        EXPECT_NEAR(sgn * r[0], 0.0, 1e-6);
        EXPECT_NEAR(sgn * r[1], sin(cases[i].angle / 2), 1e-6);
        EXPECT_NEAR(sgn * r[2], 0.0, 1e-6);
        EXPECT_NEAR(sgn * r[3], cos(cases[i].angle / 2), 1e-6);
    }
    /* a non-unit key is normalised: STEP of (0, 0, 0, 2) is the identity */
    const float q2[8] = {0, 0, 0, 2, 0, 0, 0, 2};
    CHECK_OK(one_channel(s, &a, n, SY_ANIM_ROTATION, SY_INTERP_STEP, 4, 2, times, q2, &e), e);
    CHECK_OK(sy_scene_set_time(s, a, 0.3, &e), e);
    EXPECT_NEAR(node_r(s, n)[3], 1.0, 1e-7);
    return 0;
}

SY_SCENE_TEST(test_cubic)
{
    sy_node n = new_node(s, "n");
    const float times[2] = {0.0f, 2.0f};
    /* key 0: in-tangent, value, out-tangent; key 1: the same (x only matters) */
    const float v[18] = {9, 9, 9, 1, 0, 0, 2, 0, 0, /**/ -1, 0, 0, 3, 0, 0, 9, 9, 9};
    sy_animation a = {0};
    CHECK_OK(one_channel(s, &a, n, SY_ANIM_TRANSLATION, SY_INTERP_CUBICSPLINE, 3, 2, times, v, &e), e);
    /* t = 0.5: s = 0.25, t_d = 2; p = h00 * 1 + t_d h10 * 2 + h01 * 3 + t_d h11 * (-1)
     * = 0.84375 + 0.5625 + 0.46875 + 0.09375 = 1.96875 (glTF 2.0 appendix C) */
    CHECK_OK(sy_scene_set_time(s, a, 0.5, &e), e);
    EXPECT_NEAR(node_t(s, n)[0], 1.96875, 1e-6);
    EXPECT_NEAR(node_t(s, n)[1], 0.0, 1e-6);
    /* t = 1: s = 0.5; h00 = 0.5, h10 = 0.125, h01 = 0.5, h11 = -0.125: 0.5 + 0.5 + 1.5 + 0.25 = 2.75 */
    CHECK_OK(sy_scene_set_time(s, a, 1.0, &e), e);
    EXPECT_NEAR(node_t(s, n)[0], 2.75, 1e-6);
    /* clamping: the key values, never the tangents */
    CHECK_OK(sy_scene_set_time(s, a, -1.0, &e), e);
    EXPECT_NEAR(node_t(s, n)[0], 1.0, 0.0);
    EXPECT_NEAR(node_t(s, n)[1], 0.0, 0.0);
    CHECK_OK(sy_scene_set_time(s, a, 2.0, &e), e);
    EXPECT_NEAR(node_t(s, n)[0], 3.0, 0.0);
    CHECK_OK(sy_scene_set_time(s, a, 5.0, &e), e);
    EXPECT_NEAR(node_t(s, n)[0], 3.0, 0.0);
    return 0;
}

SY_SCENE_TEST(test_what_channels_leave)
{
    sy_node n = new_node(s, "trs"), m = new_node(s, "matrix"), gone = new_node(s, "gone");
    const float t0[3] = {0, 0, 0}, r0[4] = {0, 0, 0, 1}, sc[3] = {2, 2, 2};
    CHECK_OK(sy_node_set_trs(s, n, t0, r0, sc, &e), e);
    sy_mat4 mat = {{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 5, 0, 0, 1}};
    CHECK_OK(sy_node_set_matrix(s, m, &mat, &e), e);
    const float times[2] = {0, 1}, vals[6] = {0, 0, 0, 0, 4, 0}, w[4] = {0, 1, 1, 0};
    sy_anim_sampler_desc sd[2] = {{SY_INTERP_LINEAR, 3, 2, times, vals}, {SY_INTERP_LINEAR, 2, 2, times, w}};
    sy_anim_channel ch[4] = {{n.id, SY_ANIM_TRANSLATION, 0}, {m.id, SY_ANIM_TRANSLATION, 0},
                             {gone.id, SY_ANIM_TRANSLATION, 0}, {n.id, SY_ANIM_WEIGHTS, 1}};
    sy_animation a;
    CHECK_OK(sy_animation_create(s, "walk", &a, &e), e);
    CHECK_OK(sy_animation_set_clip(s, a, sd, 2, ch, 4, &e), e);
    CHECK_OK(sy_object_destroy(s, SY_TYPE_NODE, gone.id, &e), e);
    sy_anim_stats st;
    CHECK_OK(sy_scene_set_time_ex(s, (sy_animation){0}, 0.5, &st, &e), e);
    EXPECT(st.clips == 1 && st.channels == 1 && st.skipped_matrix == 1 && st.skipped_stale == 1 && st.weights == 1);
    EXPECT_NEAR(node_t(s, n)[1], 2.0, 1e-6);
    EXPECT_NEAR(sy_node_get(s, n)->transform.scale[0], 2.0, 0.0); /* the part no channel drives stays */
    EXPECT(sy_node_get(s, m)->transform.mode == SY_TRANSFORM_MATRIX);
    EXPECT_NEAR(sy_node_get(s, m)->transform.matrix.m[12], 5.0, 0.0);
    /* the weights channel set the node's morph weights (linear at 0.5: 0.5 0.5), a matrix node too */
    uint32_t nw = 0;
    const sy_node_data *nd = sy_node_get(s, n);
    EXPECT(nd->weights && (nw = (uint32_t)(sy_blob_size(nd->weights) / 4)) == 2);
    if (nw == 2) {
        EXPECT_NEAR(((const float *)sy_blob_data(nd->weights))[0], 0.5, 1e-6);
        EXPECT_NEAR(((const float *)sy_blob_data(nd->weights))[1], 0.5, 1e-6);
    }
    CHECK_OK(sy_scene_set_time_ex(s, (sy_animation){0}, 0.25, &st, &e), e);
    nd = sy_node_get(s, n);
    EXPECT(nd->weights && sy_blob_size(nd->weights) == 8);
    if (nd->weights && sy_blob_size(nd->weights) == 8) EXPECT_NEAR(((const float *)sy_blob_data(nd->weights))[1], 0.75, 1e-6);
    /* bad weights refused by the setter, naming what */
    const float bad[2] = {0, NAN};
    CHECK_ERR(sy_node_set_weights(s, n, bad, 2, &e), SY_ERR_INVALID_ARGUMENT, e);
    EXPECT_SAYS(e, "not finite");
    /* the sampler can be read on its own too */
    float out[2];
    CHECK_OK(sy_animation_sample(sy_animation_get(s, a), 1, false, 0.25, out, 2, &e), e);
    EXPECT_NEAR(out[0], 0.25, 1e-6);
    EXPECT_NEAR(out[1], 0.75, 1e-6);
    CHECK_ERR(sy_animation_sample(sy_animation_get(s, a), 1, false, 0.25, out, 1, &e), SY_ERR_INVALID_ARGUMENT, e);
    CHECK_ERR(sy_animation_sample(sy_animation_get(s, a), 2, false, 0.25, out, 2, &e), SY_ERR_INVALID_ARGUMENT, e);
    /* lookup by index and name */
    sy_animation f;
    CHECK_OK(sy_animation_find(s, "0", &f, &e), e);
    EXPECT(f.id == a.id);
    CHECK_OK(sy_animation_find(s, "walk", &f, &e), e);
    EXPECT(f.id == a.id);
    CHECK_ERR(sy_animation_find(s, "run", &f, &e), SY_ERR_NOT_FOUND, e);
    EXPECT_SAYS(e, "0:walk");
    CHECK_ERR(sy_animation_find(s, "1", &f, &e), SY_ERR_NOT_FOUND, e);
    return 0;
}

SY_SCENE_TEST(test_validation)
{
    sy_node n = new_node(s, "n");
    sy_animation a = {0};
    const float t2[2] = {0, 1}, t_eq[2] = {1, 1}, t_dec[2] = {1, 0.5f}, t_nan[2] = {0, NAN};
    const float v6[6] = {0, 0, 0, 1, 1, 1}, v_nan[6] = {0, 0, 0, NAN, 1, 1}, v_big[6] = {0, 0, 0, 1e30f, 0, 0};
    const float q8[8] = {0, 0, 0, 1, 0, 0, 0, 0};
    /* each refused naming the item (CUBICSPLINE with one value per key is built by hand below: the
     * builder would copy three values per key from v6 and overrun) */
    const struct {
        uint32_t node, path, interp, comps, keys;
        const float *times, *values;
        sy_result code;
        const char *says; /* NULL: the code alone */
    } bad[] = {
        {n.id, SY_ANIM_TRANSLATION, SY_INTERP_LINEAR, 3, 2, t_eq, v6, SY_ERR_INVALID_ARGUMENT, "sampler 0: key time 1"},
        {n.id, SY_ANIM_TRANSLATION, SY_INTERP_LINEAR, 3, 2, t_dec, v6, SY_ERR_INVALID_ARGUMENT, "increase strictly"},
        {n.id, SY_ANIM_TRANSLATION, SY_INTERP_LINEAR, 3, 2, t_nan, v6, SY_ERR_INVALID_ARGUMENT, "times[1] is not finite"},
        {n.id, SY_ANIM_TRANSLATION, SY_INTERP_LINEAR, 3, 2, t2, v_nan, SY_ERR_INVALID_ARGUMENT, "values[3] is not finite"},
        {n.id, SY_ANIM_TRANSLATION, SY_INTERP_LINEAR, 3, 2, t2, v_big, SY_ERR_INVALID_ARGUMENT, "coordinate range"},
        {n.id, SY_ANIM_ROTATION, SY_INTERP_LINEAR, 3, 2, t2, v6, SY_ERR_INVALID_ARGUMENT, "rotation path takes 4"},
        {n.id, SY_ANIM_ROTATION, SY_INTERP_LINEAR, 4, 2, t2, q8, SY_ERR_INVALID_ARGUMENT, "zero quaternion"},
        {0x7777, SY_ANIM_TRANSLATION, SY_INTERP_LINEAR, 3, 2, t2, v6, SY_ERR_INVALID_HANDLE, "channel 0: target node"},
        {n.id, SY_ANIM_PATH_COUNT, SY_INTERP_LINEAR, 3, 2, t2, v6, SY_ERR_INVALID_ARGUMENT, "unknown path"},
        {n.id, SY_ANIM_TRANSLATION, 7, 3, 2, t2, v6, SY_ERR_INVALID_ARGUMENT, "unknown interpolation"},
        {n.id, SY_ANIM_TRANSLATION, SY_INTERP_LINEAR, 3, 0, t2, v6, SY_ERR_INVALID_ARGUMENT, "0 keys"},
        {n.id, SY_ANIM_TRANSLATION, SY_INTERP_LINEAR, 3, SY_ANIM_MAX_KEYS + 1, t2, v6, SY_ERR_LIMIT, NULL},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        CHECK_ERR(one_channel(s, &a, (sy_node){bad[i].node}, bad[i].path, bad[i].interp, bad[i].comps, bad[i].keys,
                              bad[i].times, bad[i].values, &e),
                  bad[i].code, e);
        if (bad[i].says) EXPECT_SAYS(e, bad[i].says);
    }
    /* hand-made blobs: a CUBICSPLINE sampler with one value per key, a channel naming sampler 3 */
    sy_blob *bs = NULL, *bc = NULL, *bt = NULL, *bv = NULL;
    sy_anim_sampler rec = {SY_INTERP_CUBICSPLINE, 3, 2, 0, 0};
    sy_anim_channel ch = {n.id, SY_ANIM_TRANSLATION, 0};
    CHECK_OK(sy_blob_create_copy(&rec, sizeof rec, &bs, &e), e);
    CHECK_OK(sy_blob_create_copy(&ch, sizeof ch, &bc, &e), e);
    CHECK_OK(sy_blob_create_copy(t2, sizeof t2, &bt, &e), e);
    CHECK_OK(sy_blob_create_copy(v6, sizeof v6, &bv, &e), e);
    sy_animation_data d = {NULL, bs, bc, bt, bv, 0.0f, 0};
    CHECK_ERR(sy_animation_set(s, a, &d, &e), SY_ERR_INVALID_ARGUMENT, e);
    EXPECT_SAYS(e, "x 3 for CUBICSPLINE");
    sy_blob_release(bc);
    ch.sampler = 3;
    CHECK_OK(sy_blob_create_copy(&ch, sizeof ch, &bc, &e), e);
    rec.interpolation = SY_INTERP_LINEAR;
    sy_blob_release(bs);
    CHECK_OK(sy_blob_create_copy(&rec, sizeof rec, &bs, &e), e);
    d.samplers = bs, d.channels = bc;
    CHECK_ERR(sy_animation_set(s, a, &d, &e), SY_ERR_INVALID_ARGUMENT, e);
    EXPECT_SAYS(e, "channel 0: sampler 3 of 1");
    /* a channel blob of a broken size */
    sy_blob *odd = NULL;
    CHECK_OK(sy_blob_create_copy(&ch, 5, &odd, &e), e);
    CHECK_ERR(sy_object_set_field(s, SY_TYPE_ANIMATION, a.id, SY_ANIMATION_CHANNELS, &odd, &e), SY_ERR_INVALID_ARGUMENT, e);
    EXPECT_SAYS(e, "whole 12-byte records");
    sy_blob_release(odd);
    sy_blob_release(bs), sy_blob_release(bc), sy_blob_release(bt), sy_blob_release(bv);
    /* after all the refusals the animation is still empty and evaluates to nothing */
    sy_anim_stats st;
    CHECK_OK(sy_scene_set_time_ex(s, a, 0.5, &st, &e), e);
    EXPECT(st.channels == 0);
    return 0;
}

/* The origin has two nodes and a clip; a replica gets it through a serialised snapshot. Evaluating
 * on both gives equal nodes; evaluating on the origin only and shipping the commit gives the same. */
static int test_round_trip(void)
{
    sy_error e = {0};
    sy_scene *o = new_scene(), *r = new_scene();
    sy_node p = new_node(o, "parent"), c = new_node(o, "child");
    CHECK_OK(sy_node_add_child(o, p, c, &e), e);
    const float times[3] = {0, 1, 3};
    const float tv[27] = {0, 0, 0, 1, 2, 3, 0, 1, 0, /**/ 0, 0, 0, 4, 5, 6, 1, 0, 0, /**/ 1, 1, 1, -1, 0, 2, 0, 0, 0};
    const double h = sqrt(0.5);
    const float rq[12] = {0, 0, 0, 1, 0, (float)h, 0, (float)h, (float)h, 0, 0, (float)-h};
    const float sv[6] = {1, 1, 1, 2, 0.5f, 1};
    sy_anim_sampler_desc sd[3] = {{SY_INTERP_CUBICSPLINE, 3, 3, times, tv},
                                  {SY_INTERP_LINEAR, 4, 3, times, rq},
                                  {SY_INTERP_STEP, 3, 2, times, sv}};
    sy_anim_channel ch[3] = {{p.id, SY_ANIM_TRANSLATION, 0}, {c.id, SY_ANIM_ROTATION, 1}, {c.id, SY_ANIM_SCALE, 2}};
    sy_animation a;
    CHECK_OK(sy_animation_create(o, "dance", &a, &e), e);
    CHECK_OK(sy_animation_set_clip(o, a, sd, 3, ch, 3, &e), e);
    CHECK_OK(sy_scene_commit(o, NULL, &e), e);
    wire_copy wc;
    if (wire_copy_send(&wc, o, r)) return 1;
    sy_error diff = {0};
    CHECK_MSG(sy_scene_equal(o, r, &diff), "%s", diff.message);
    const sy_animation_data *ra = sy_animation_get(r, a);
    CHECK(ra && ra->name && strcmp(ra->name, "dance") == 0);
    float lo, hi;
    sy_animation_time_range(ra, &lo, &hi);
    EXPECT_NEAR(lo, 0.0, 0.0);
    EXPECT_NEAR(hi, 3.0, 0.0);
    const double at[4] = {0.3, 1.0, 2.2, 4.0};
    for (int i = 0; i < 4; ++i) {
        CHECK_OK(sy_scene_set_time(o, a, at[i], &e), e);
        CHECK_OK(sy_scene_set_time(r, a, at[i], &e), e);
        CHECK_MSG(sy_scene_equal(o, r, &diff), "t = %g: %s", at[i], diff.message);
    }
    /* the origin alone moves; its commit carries the node fields to the replica */
    uint32_t consumer;
    CHECK_OK(sy_scene_commit(o, NULL, &e), e);
    CHECK_OK(sy_scene_commit(r, NULL, &e), e);
    CHECK_OK(sy_scene_consumer_add(o, &consumer, &e), e);
    sy_changes *first = NULL, *moved = NULL;
    CHECK_OK(sy_scene_commit(o, NULL, &e), e);
    CHECK_OK(sy_scene_consumer_pull(o, consumer, &first, &e), e); /* the snapshot */
    CHECK_OK(sy_scene_set_time(o, a, 1.7, &e), e);
    CHECK_OK(sy_scene_commit(o, NULL, &e), e);
    CHECK_OK(sy_scene_consumer_pull(o, consumer, &moved, &e), e);
    sy_changes_stats cs = sy_changes_get_stats(moved);
    EXPECT_MSG(cs.updated == 2 && cs.created == 0, "%u updated, %u created", cs.updated, cs.created);
    CHECK_OK(sy_scene_apply(r, moved, &e), e);
    CHECK_MSG(sy_scene_equal(o, r, &diff), "%s", diff.message);
    EXPECT(fabsf(sy_node_get(r, p)->transform.translation[0]) > 0.0f);
    sy_changes_release(first), sy_changes_release(moved);
    /* a hostile list: the replica refuses an animation whose times go backwards, naming it */
    sy_scene *o2 = new_scene(), *r2 = new_scene();
    sy_node n2 = new_node(o2, "n");
    sy_animation a2;
    CHECK_OK(sy_animation_create(o2, "bad", &a2, &e), e);
    CHECK_OK(one_channel(o2, &a2, n2, SY_ANIM_TRANSLATION, SY_INTERP_LINEAR, 3, 3, times, tv, &e), e);
    CHECK_OK(sy_scene_commit(o2, NULL, &e), e);
    sy_changes *s2 = NULL;
    CHECK_OK(sy_scene_snapshot(o2, &s2, &e), e);
    void *b2 = NULL;
    size_t n2size = 0;
    CHECK_OK(sy_changes_serialize(s2, NULL, NULL, &b2, &n2size, &e), e);
    /* find the times payload (0, 1, 3) in the message and swap two of them */
    const float want[3] = {0, 1, 3};
    unsigned char *hit = NULL;
    for (size_t k = 0; k + sizeof want <= n2size && !hit; ++k)
        if (!memcmp((unsigned char *)b2 + k, want, sizeof want)) hit = (unsigned char *)b2 + k;
    CHECK(hit != NULL);
    const float swapped[3] = {0, 3, 1};
    memcpy(hit, swapped, sizeof swapped);
    /* the blob record before the payload: u64 hash lo, u64 hash hi, u64 size, u8 flag; re-hash it so
     * the decoder takes the tampered payload and the replica's own check is what refuses it */
    sy_blob *sb = NULL;
    CHECK_OK(sy_blob_create_copy(swapped, sizeof swapped, &sb, &e), e);
    sy_hash128 hh = sy_blob_hash(sb);
    CHECK(hit - (unsigned char *)b2 >= 25);
    memcpy(hit - 25, &hh.lo, 8);
    memcpy(hit - 17, &hh.hi, 8);
    sy_blob_release(sb);
    sy_changes *bad = NULL;
    sy_blob_store *store2 = NULL;
    CHECK_OK(sy_blob_store_create(&store2, &e), e);
    CHECK_OK(sy_changes_deserialize(b2, n2size, store2, NULL, &bad, &e), e);
    CHECK_ERR(sy_scene_apply(r2, bad, &e), SY_ERR_INVALID_ARGUMENT, e);
    EXPECT_SAYS(e, "apply animation");
    EXPECT_SAYS(e, "increase strictly");
    sy_blob_store_destroy(store2);
    sy_changes_release(bad), sy_changes_release(s2);
    free(b2);
    sy_scene_destroy(o2), sy_scene_destroy(r2);

    wire_copy_free(&wc);
    sy_scene_destroy(o), sy_scene_destroy(r);
    return 0;
}

/* A clip with a period of its own that loops (X3D's TimeSensor cycleInterval and loop): scene time
 * t plays t mod the period; without loop it clamps; the range is [0, period]; bad periods are
 * refused naming the animation; the fields survive a rebuild of the clip. */
SY_SCENE_TEST(test_timing)
{
    sy_node n = new_node(s, "n");
    sy_animation a = {0};
    const float times[2] = {0.0f, 2.0f}, tv[6] = {0, 0, 0, 2, 0, 0};
    CHECK_OK(one_channel(s, &a, n, SY_ANIM_TRANSLATION, SY_INTERP_LINEAR, 3, 2, times, tv, &e), e);
    CHECK_OK(sy_animation_set_timing(s, a, 4.0f, true, &e), e);
    double lo = -1, hi = -1;
    CHECK_OK(sy_scene_time_range(s, a, &lo, &hi, &e), e);
    EXPECT_MSG(lo == 0.0 && hi == 4.0, "range %g %g (want 0 4)", lo, hi);
    const double at[5] = {5.0, 9.5, -1.0, 3.0, 4.0}, want[5] = {1.0, 1.5, 2.0, 2.0, 0.0};
    for (int i = 0; i < 5; ++i) {
        CHECK_OK(sy_scene_set_time(s, a, at[i], &e), e);
        float x = sy_node_get(s, n)->transform.translation[0];
        EXPECT_MSG(fabsf(x - (float)want[i]) < 1e-6f, "looping, t = %g: x %g (want %g)", at[i], (double)x, want[i]);
    }
    CHECK_OK(sy_animation_set_timing(s, a, 4.0f, false, &e), e);
    CHECK_OK(sy_scene_set_time(s, a, 5.0, &e), e);
    EXPECT_MSG(sy_node_get(s, n)->transform.translation[0] == 2.0f, "not looping, t = 5: x %g (want 2, clamped)",
               (double)sy_node_get(s, n)->transform.translation[0]);
    CHECK_ERR(sy_animation_set_timing(s, a, -1.0f, true, &e), SY_ERR_INVALID_ARGUMENT, e);
    EXPECT_SAYS(e, "period");
    CHECK_ERR(sy_animation_set_timing(s, a, NAN, false, &e), SY_ERR_INVALID_ARGUMENT, e);
    sy_animation_data d = *sy_animation_get(s, a);
    d.loop = 2;
    CHECK_ERR(sy_animation_set(s, a, &d, &e), SY_ERR_INVALID_ARGUMENT, e);
    EXPECT_SAYS(e, "loop 2");
    CHECK_OK(sy_animation_set_timing(s, a, 3.0f, true, &e), e);
    CHECK_OK(one_channel(s, &a, n, SY_ANIM_TRANSLATION, SY_INTERP_LINEAR, 3, 2, times, tv, &e), e);
    EXPECT_MSG(sy_animation_get(s, a)->cycle == 3.0f && sy_animation_get(s, a)->loop == 1, "rebuilt clip: cycle %g loop %u",
               (double)sy_animation_get(s, a)->cycle, sy_animation_get(s, a)->loop);
    return 0;
}

static int test_clock(void)
{
    sy_clock c = sy_clock_make(1.0, 3.0);
    EXPECT(c.playing && c.loop && c.time == 1.0);
    EXPECT_NEAR(sy_clock_advance(&c, 0.5), 1.5, 1e-12);
    EXPECT_NEAR(sy_clock_advance(&c, 2.0), 1.5, 1e-12); /* 3.5 wraps to 1.5 */
    c.speed = -1.0;
    EXPECT_NEAR(sy_clock_advance(&c, 1.0), 2.5, 1e-12); /* 0.5 wraps backwards to 2.5 */
    c.playing = false;
    EXPECT_NEAR(sy_clock_advance(&c, 1.0), 2.5, 0.0);
    c.playing = true, c.loop = false, c.speed = 2.0;
    EXPECT_NEAR(sy_clock_advance(&c, 1.0), 3.0, 0.0);
    EXPECT(!c.playing);
    EXPECT_NEAR(sy_clock_advance(&c, NAN), 3.0, 0.0);
    return 0;
}

/* Material, light and camera channels: each sets its object's field (base colour, its RGB or alpha
 * alone, emissive, metallic, roughness, light colour and intensity, camera yfov) at the sampled
 * value; a channel whose path names another type of object, or whose sampler has the wrong
 * component count, is refused naming it; an out-of-range value is refused by the setter and
 * counted failed; a destroyed target is skipped; a replica gets the same clip and the same values. */
SY_SCENE_TEST(test_properties)
{
    sy_material m;
    sy_light l;
    sy_camera c;
    CHECK_OK(sy_material_create(s, "paint", &m, &e), e);
    CHECK_OK(sy_light_create(s, "lamp", &l, &e), e);
    CHECK_OK(sy_camera_create(s, "eye", &c, &e), e);
    const float times[2] = {0, 2}, rgba[8] = {1, 0, 0, 1, 0, 1, 0, 0.5f}, rgb[6] = {0, 0, 1, 1, 1, 0}, one[2] = {0.2f, 0.6f};
    const float fov[2] = {0.5f, 1.0f}, inten[2] = {10, 30};
    sy_anim_sampler_desc sd[5] = {{SY_INTERP_LINEAR, 4, 2, times, rgba}, {SY_INTERP_LINEAR, 3, 2, times, rgb},
                                  {SY_INTERP_LINEAR, 1, 2, times, one},  {SY_INTERP_LINEAR, 1, 2, times, fov},
                                  {SY_INTERP_STEP, 1, 2, times, inten}};
    sy_anim_channel ch[7] = {{m.id, SY_ANIM_BASE_COLOR, 0}, {m.id, SY_ANIM_EMISSIVE, 1}, {m.id, SY_ANIM_ROUGHNESS, 2},
                             {l.id, SY_ANIM_LIGHT_COLOR, 1}, {l.id, SY_ANIM_LIGHT_INTENSITY, 4},
                             {c.id, SY_ANIM_CAMERA_YFOV, 3}, {m.id, SY_ANIM_OPACITY, 2}};
    sy_animation a;
    CHECK_OK(sy_animation_create(s, "props", &a, &e), e);
    CHECK_OK(sy_animation_set_clip(s, a, sd, 5, ch, 7, &e), e);
    sy_anim_stats st;
    CHECK_OK(sy_scene_set_time_ex(s, (sy_animation){0}, 0.5, &st, &e), e); /* u = 0.25 */
    EXPECT(st.properties == 7 && st.failed == 0 && st.channels == 0);
    const sy_material_data *md = sy_material_get(s, m);
    EXPECT_NEAR(md->base_color[0], 0.75, 1e-6);
    EXPECT_NEAR(md->base_color[1], 0.25, 1e-6);
    EXPECT_NEAR(md->base_color[3], 0.3, 1e-6); /* the opacity channel (later in the clip) set the alpha alone */
    EXPECT_NEAR(md->emissive[0], 0.25, 1e-6);
    EXPECT_NEAR(md->emissive[2], 0.75, 1e-6);
    EXPECT_NEAR(md->roughness, 0.3, 1e-6);
    EXPECT_NEAR(sy_light_get(s, l)->color[1], 0.25, 1e-6);
    EXPECT_NEAR(sy_light_get(s, l)->intensity, 10.0, 0.0); /* STEP */
    EXPECT_NEAR(sy_camera_get(s, c)->yfov, 0.625, 1e-6);
    /* a replica holds the same clip and evaluates to the same values */
    CHECK_OK(sy_scene_commit(s, NULL, &e), e);
    sy_scene *r = new_scene();
    wire_copy wc;
    if (wire_copy_send(&wc, s, r)) return 1;
    wire_copy_free(&wc);
    CHECK_OK(sy_scene_set_time(s, (sy_animation){0}, 1.5, &e), e);
    CHECK_OK(sy_scene_set_time(r, (sy_animation){0}, 1.5, &e), e);
    EXPECT(memcmp(sy_material_get(s, m)->base_color, sy_material_get(r, m)->base_color, 16) == 0);
    EXPECT_NEAR(sy_camera_get(r, c)->yfov, 0.875, 1e-6);
    EXPECT_NEAR(sy_light_get(r, l)->intensity, 10.0, 0.0);
    sy_scene_destroy(r);
    /* the DIFFUSE path sets the RGB and keeps the alpha */
    sy_animation d = {0};
    CHECK_OK(one_channel(s, &d, (sy_node){m.id}, SY_ANIM_DIFFUSE, SY_INTERP_LINEAR, 3, 2, times, rgb, &e), e);
    CHECK_OK(sy_scene_set_time(s, d, 1.0, &e), e);
    EXPECT_NEAR(sy_material_get(s, m)->base_color[0], 0.5, 1e-6);
    EXPECT_NEAR(sy_material_get(s, m)->base_color[2], 0.5, 1e-6);
    EXPECT_NEAR(sy_material_get(s, m)->base_color[3], 0.5, 1e-6); /* left by the last call (alpha 1 - 0.5) */
    /* refused: an id that is no material on a material path, a material on a node path (ids are per
     * type: the scene's second material is no object yet), the wrong component count */
    sy_animation b = {0};
    sy_material m2;
    CHECK_OK(sy_material_create(s, "second", &m2, &e), e);
    CHECK_OK(sy_object_destroy(s, SY_TYPE_MATERIAL, m2.id, &e), e);
    CHECK_ERR(one_channel(s, &b, (sy_node){m2.id}, SY_ANIM_BASE_COLOR, SY_INTERP_LINEAR, 4, 2, times, rgba, &e), SY_ERR_INVALID_HANDLE, e);
    EXPECT_SAYS(e, "base_color");
    EXPECT_SAYS(e, "material");
    sy_node n2 = new_node(s, "n2");
    CHECK_OK(sy_object_destroy(s, SY_TYPE_NODE, n2.id, &e), e);
    CHECK_ERR(one_channel(s, &b, n2, SY_ANIM_TRANSLATION, SY_INTERP_LINEAR, 3, 2, times, rgb, &e), SY_ERR_INVALID_HANDLE, e);
    EXPECT_SAYS(e, "not a live node");
    CHECK_ERR(one_channel(s, &b, (sy_node){l.id}, SY_ANIM_LIGHT_INTENSITY, SY_INTERP_LINEAR, 3, 2, times, rgb, &e),
              SY_ERR_INVALID_ARGUMENT, e);
    EXPECT_SAYS(e, "light_intensity path takes 1");
    /* an out-of-range value (a negative intensity) is refused by the light's setter: counted failed */
    const float neg[2] = {-5, -5};
    sy_animation g = {0};
    CHECK_OK(one_channel(s, &g, (sy_node){l.id}, SY_ANIM_LIGHT_INTENSITY, SY_INTERP_LINEAR, 1, 2, times, neg, &e), e);
    EXPECT(sy_scene_set_time_ex(s, g, 1.0, &st, &e) != SY_OK && st.failed == 1);
    EXPECT_SAYS(e, "channel 0");
    /* a destroyed target is skipped */
    CHECK_OK(sy_object_destroy(s, SY_TYPE_CAMERA, c.id, &e), e);
    CHECK_OK(sy_scene_set_time_ex(s, a, 1.0, &st, &e), e);
    EXPECT(st.skipped_stale == 1 && st.properties == 6);
    return 0;
}

/* The motion-blur shutter: "OPEN,CLOSE" and "S" parse; negative, NaN, infinite, open > close and
 * trailing text are refused naming the text; the time samples are the strata's midpoints. */
static int test_shutter(void)
{
    sy_error e = {0};
    sy_shutter sh = {.samples = 4};
    CHECK_OK(sy_shutter_parse("0.25,0.5", &sh, &e), e);
    EXPECT(sh.open == 0.25 && sh.close == 0.5 && sh.samples == 4 && sy_shutter_blurs(&sh));
    EXPECT_NEAR(sy_shutter_time(&sh, 1.0, 0), 1.28125, 1e-12); /* 1 + 0.25 + 0.5/4 x 0.25 */
    EXPECT_NEAR(sy_shutter_time(&sh, 1.0, 3), 1.46875, 1e-12);
    CHECK_OK(sy_shutter_parse("0.02", &sh, &e), e);
    EXPECT(sh.open == 0.0 && sh.close == 0.02);
    CHECK_OK(sy_shutter_parse("0", &sh, &e), e);
    EXPECT(!sy_shutter_blurs(&sh)); /* an instant: no blur */
    sh = (sy_shutter){0.0, 1.0, 1};
    EXPECT(!sy_shutter_blurs(&sh)); /* one time sample: no blur */
    const char *bad[] = {"-0.1", "0.2,0.1", "nan", "0,inf", "0,", ",1", "1x", "", "0,1,2", "-1,0", "2e6"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        EXPECT_MSG(sy_shutter_parse(bad[i], &sh, &e) == SY_ERR_INVALID_ARGUMENT, "'%s' accepted", bad[i]);
        EXPECT_SAYS(e, "shutter");
    }
    EXPECT(sy_shutter_parse("0.2,0.1", &sh, &e) != SY_OK && strstr(e.message, "opens"));
    return 0;
}

SY_CHECK_MAIN("core_anim", SY_TEST(test_step_linear_clamp), SY_TEST(test_slerp), SY_TEST(test_cubic),
              SY_TEST(test_what_channels_leave), SY_TEST(test_validation), SY_TEST(test_round_trip),
              SY_TEST(test_properties), SY_TEST(test_timing), SY_TEST(test_clock), SY_TEST(test_shutter))
