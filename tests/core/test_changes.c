/* test_changes.c — change lists: commit entries and last values, create+destroy elision, consumers
 * with independent cursors and merging, log compaction, snapshots for late consumers, the wire
 * format (round trip, blob payloads sent once, limits, specific errors) and the decoder on corrupt
 * input (every truncation, random mutations, random garbage). */
#include <stdlib.h>
#include <string.h>

#include "../support/sy_check.h"
#include "../support/sy_scene_test.h"
#include "../support/sy_test_rng.h"
#include "sy_changes.h"
#include "sy_fields.h" /* internal to core: generic field compare for deep equality of entries */

static const float Q0[4] = {0, 0, 0, 1}, S1[3] = {1, 1, 1};

static uint64_t rng_state;
static uint64_t rnd(void) { return sy_test_splitmix64(&rng_state); }

static const sy_change *find_entry(const sy_changes *c, uint32_t type, uint32_t id)
{
    for (uint32_t i = 0; i < sy_changes_count(c); ++i) {
        const sy_change *e = sy_changes_get(c, i);
        if (e->type == type && e->id == id) return e;
    }
    return NULL;
}

/* Deep comparison of two entries: header, every field in the mask, attachments. */
static int entry_equal(const sy_change *a, const sy_change *b)
{
    CHECK(a->type == b->type && a->id == b->id);
    CHECK_MSG(a->flags == b->flags, "%s %#x flags %u vs %u", sy_object_type_name(a->type), a->id, a->flags, b->flags);
    CHECK_MSG(a->mask == b->mask, "%s %#x mask %#llx vs %#llx", sy_object_type_name(a->type), a->id,
              (unsigned long long)a->mask, (unsigned long long)b->mask);
    CHECK((a->data == NULL) == (b->data == NULL));
    const sy_type_desc *td = sy__type_desc(a->type);
    CHECK(td != NULL);
    for (uint32_t f = 0; f < td->field_count; ++f)
        if (a->mask & SY_BIT(f))
            CHECK_MSG(sy__field_equal(a->type, f, a->data, b->data), "%s %#x field %s differs",
                      sy_object_type_name(a->type), a->id, td->fields[f].name);
    if (a->mask & SY_BIT(SY_FIELD_ATTACHMENTS))
        CHECK(sy__attachments_equal(a->attachments, a->attachment_count, b->attachments, b->attachment_count));
    return 0;
}

static int lists_equal(const sy_changes *a, const sy_changes *b)
{
    CHECK_MSG(sy_changes_count(a) == sy_changes_count(b), "%u vs %u entries", sy_changes_count(a), sy_changes_count(b));
    for (uint32_t i = 0; i < sy_changes_count(a); ++i) CHECK(entry_equal(sy_changes_get(a, i), sy_changes_get(b, i)) == 0);
    uint64_t fa, la, fb, lb;
    sy_changes_frames(a, &fa, &la);
    sy_changes_frames(b, &fb, &lb);
    CHECK(fa == fb && la == lb);
    CHECK(sy_changes_is_snapshot(a) == sy_changes_is_snapshot(b));
    return 0;
}

/* The documented order: destructions first, then type dependency order, then id. */
static int check_order(const sy_changes *c)
{
    for (uint32_t i = 1; i < sy_changes_count(c); ++i) {
        const sy_change *p = sy_changes_get(c, i - 1), *q = sy_changes_get(c, i);
        int dp = (p->flags & SY_CHANGE_DESTROYED) ? 0 : 1, dq = (q->flags & SY_CHANGE_DESTROYED) ? 0 : 1;
        CHECK(dp <= dq);
        if (dp == dq) CHECK(p->type < q->type || (p->type == q->type && p->id < q->id));
    }
    return 0;
}

/* A scene using every type, every field kind and every attachment kind, with shared blobs. */
typedef struct rich {
    sy_texture tex, env;
    sy_material mat;
    sy_mesh mesh;
    sy_light light;
    sy_camera cam;
    sy_background bg;
    sy_node root, a, b;
    sy_blob *pixels, *pos, *attach_blob;
} rich;

static int build_rich(sy_scene *s, rich *r)
{
    sy_error e = {0};
    CHECK_OK(sy_texture_create(s, "albedo", &r->tex, &e), e);
    CHECK_OK(sy_texture_create(s, NULL, &r->env, &e), e);
    uint8_t px[2 * 3 * 4];
    for (int i = 0; i < 24; ++i) px[i] = (uint8_t)(i * 11);
    r->pixels = sy_test_blob(px, sizeof px);
    sy_image_info info = {2, 3, 4, SY_PIXEL_U8_SRGB};
    CHECK_OK(sy_texture_set_image(s, r->tex, &info, r->pixels, &e), e);
    CHECK_OK(sy_texture_set_image(s, r->env, &info, r->pixels, &e), e); /* the same blob twice */
    sy_sampler smp = {SY_WRAP_CLAMP, SY_WRAP_MIRROR, SY_FILTER_NEAREST, SY_FILTER_LINEAR};
    CHECK_OK(sy_texture_set_sampler(s, r->tex, &smp, &e), e);

    CHECK_OK(sy_material_create(s, "gold", &r->mat, &e), e);
    sy_material_data md = *sy_material_get(s, r->mat);
    md.base_color[0] = 0.9f;
    md.base_color_texture.texture = r->tex;
    md.base_color_texture.rotation = 0.5f;
    md.normal_texture.texture = r->tex;
    md.normal_texture.texcoord = 1;
    md.normal_texture.scale = 0.7f;
    md.metallic = 0.3f;
    md.emissive[2] = 4;
    md.alpha_mode = SY_ALPHA_BLEND;
    md.unlit = 1;
    md.ior = 1.45f;
    CHECK_OK(sy_material_set(s, r->mat, &md, &e), e);

    CHECK_OK(sy_mesh_create(s, "mesh", &r->mesh, &e), e);
    const float pos[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    const float nrm[4][3] = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {1, 0, 0}};
    const float tan[4][4] = {{1, 0, 0, 1}, {1, 0, 0, 1}, {1, 0, 0, 1}, {0, 1, 0, -1}};
    const float uv[4][2] = {{0, 0}, {1, 0}, {0, 1}, {1, 1}};
    const float col[4][4] = {{1, 0, 0, 1}, {0, 1, 0, 1}, {0, 0, 1, 1}, {1, 1, 1, 0.5f}};
    const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
    r->pos = sy_test_blob(pos, sizeof pos);
    sy_blob *bn = sy_test_blob(nrm, sizeof nrm), *bt = sy_test_blob(tan, sizeof tan), *buv = sy_test_blob(uv, sizeof uv);
    sy_blob *bc = sy_test_blob(col, sizeof col), *bi = sy_test_blob(idx, sizeof idx);
    sy_blob *tri = sy_test_blob(pos, 36);
    /* skin attributes (4 influences) and two morph targets on the first primitive: version 5 */
    const uint32_t jnt[16] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
    const float wgt[16] = {1, 0, 0, 0, 1, 0, 0, 0, 0.5f, 0.5f, 0, 0, 1, 0, 0, 0};
    float dpos[24];
    for (int k = 0; k < 24; ++k) dpos[k] = 0.125f * (float)(k % 5);
    /* and texture coordinate targets (version 7) */
    float duv[16];
    for (int k = 0; k < 16; ++k) duv[k] = 0.0625f * (float)(k % 3);
    sy_blob *bj = sy_test_blob(jnt, sizeof jnt), *bw = sy_test_blob(wgt, sizeof wgt), *bdp = sy_test_blob(dpos, sizeof dpos);
    sy_blob *bduv = sy_test_blob(duv, sizeof duv);
    sy_primitive prims[3] = {
        {r->pos, bn, bt, buv, buv, bc, bi, r->mat, SY_TOPOLOGY_TRIANGLES, 0.0f, bj, bw, bdp, bdp, NULL, bduv},
        {r->pos, NULL, NULL, NULL, NULL, NULL, bi, {0}, SY_TOPOLOGY_TRIANGLES, 0.0f, NULL, NULL, NULL, NULL, NULL, NULL}, /* shares positions and indices */
        {tri, NULL, NULL, NULL, NULL, NULL, NULL, r->mat, SY_TOPOLOGY_TRIANGLES, 0.0f, NULL, NULL, NULL, NULL, NULL, NULL},
    };
    CHECK_OK(sy_mesh_set_primitives(s, r->mesh, prims, 3, &e), e);
    sy_blob_release(bj);
    sy_blob_release(bw);
    sy_blob_release(bdp);
    sy_blob_release(bduv);
    sy_blob_release(bn);
    sy_blob_release(bt);
    sy_blob_release(buv);
    sy_blob_release(bc);
    sy_blob_release(bi);
    sy_blob_release(tri);

    CHECK_OK(sy_light_create(s, "sun", &r->light, &e), e);
    sy_light_data ld = *sy_light_get(s, r->light);
    ld.type = SY_LIGHT_DIRECTIONAL;
    ld.intensity = 3;
    ld.color[1] = 0.5f;
    CHECK_OK(sy_light_set(s, r->light, &ld, &e), e);
    CHECK_OK(sy_camera_create(s, "cam", &r->cam, &e), e);
    sy_camera_data cd = *sy_camera_get(s, r->cam);
    cd.projection = SY_PROJECTION_ORTHOGRAPHIC;
    cd.xmag = 4;
    cd.zfar = 100;
    CHECK_OK(sy_camera_set(s, r->cam, &cd, &e), e);
    CHECK_OK(sy_background_create(s, "sky", &r->bg, &e), e);
    sy_background_data bd = *sy_background_get(s, r->bg);
    bd.environment = r->env;
    bd.intensity = 2;
    bd.color[3] = 0;
    CHECK_OK(sy_background_set(s, r->bg, &bd, &e), e);

    CHECK_OK(sy_node_create(s, "root", &r->root, &e), e);
    CHECK_OK(sy_node_create(s, "a", &r->a, &e), e);
    CHECK_OK(sy_node_create(s, NULL, &r->b, &e), e);
    const float t[3] = {1, 2, 3}, q[4] = {0, 0.6f, 0, 0.8f}, sc[3] = {1, 2, 1};
    CHECK_OK(sy_node_set_trs(s, r->a, t, q, sc, &e), e);
    sy_mat4 m = sy_mat4_identity();
    m.m[13] = 7;
    CHECK_OK(sy_node_set_matrix(s, r->b, &m, &e), e);
    CHECK_OK(sy_node_add_child(s, r->root, r->a, &e), e);
    CHECK_OK(sy_node_add_child(s, r->root, r->b, &e), e);
    CHECK_OK(sy_node_add_child(s, r->a, r->b, &e), e); /* DAG */
    CHECK_OK(sy_node_set_mesh(s, r->a, r->mesh, &e), e);
    CHECK_OK(sy_node_set_mesh(s, r->b, r->mesh, &e), e);
    CHECK_OK(sy_node_set_light(s, r->root, r->light, &e), e);
    CHECK_OK(sy_node_set_camera(s, r->b, r->cam, &e), e);
    CHECK_OK(sy_node_set_flags(s, r->b, SY_NODE_STATIC | SY_NODE_ANIMATED, &e), e);
    const float mw[2] = {0.25f, 0.5f}, nw[2] = {1, -0.5f};
    sy_mat4 ibm = sy_mat4_identity();
    ibm.m[12] = -1;
    CHECK_OK(sy_mesh_set_weights(s, r->mesh, mw, 2, &e), e);
    CHECK_OK(sy_node_set_weights(s, r->a, nw, 2, &e), e);
    CHECK_OK(sy_node_set_skin(s, r->a, &r->b, &ibm, 1, r->root, &e), e);

    r->attach_blob = sy_test_blob("volume shader bytes", 19);
    sy_attachment at[5] = {
        {.key = "i", .kind = SY_ATTACH_INT, .value.i = -123456789012345ll},
        {.key = "f", .kind = SY_ATTACH_FLOAT, .value.f = 2.5},
        {.key = "v", .kind = SY_ATTACH_VEC4, .value.v = {1, -2, 3, -4}},
        {.key = "s", .kind = SY_ATTACH_STRING, .value.s = "pt:volume"},
        {.key = "b", .kind = SY_ATTACH_BLOB, .value.blob = r->attach_blob},
    };
    for (int i = 0; i < 5; ++i) CHECK_OK(sy_object_set_attachment(s, SY_TYPE_NODE, r->a.id, &at[i], &e), e);
    CHECK_OK(sy_object_set_attachment(s, SY_TYPE_MATERIAL, r->mat.id, &at[4], &e), e);
    CHECK_OK(sy_object_set_attachment(s, SY_TYPE_TEXTURE, r->tex.id, &at[3], &e), e);
    return 0;
}

static void rich_release(rich *r)
{
    sy_blob_release(r->pixels);
    sy_blob_release(r->pos);
    sy_blob_release(r->attach_blob);
}

/* ------------------------------------------------------------------ commit entries */
SY_SCENE_TEST(test_commit_entries)
{
    uint32_t con;
    CHECK_OK(sy_scene_consumer_add(s, &con, &e), e);
    sy_changes *c;
    CHECK_OK(sy_scene_consumer_pull(s, con, &c, &e), e); /* the (empty) snapshot */
    CHECK(sy_changes_count(c) == 0 && sy_changes_is_snapshot(c));
    sy_changes_release(c);

    sy_node n, gone, old;
    sy_light l;
    CHECK_OK(sy_node_create(s, "n", &n, &e), e);
    CHECK_OK(sy_node_create(s, "old", &old, &e), e);
    CHECK_OK(sy_light_create(s, "l", &l, &e), e);
    uint64_t frame;
    CHECK_OK(sy_scene_commit(s, &frame, &e), e);
    CHECK(frame == 1);
    CHECK_OK(sy_scene_consumer_pull(s, con, &c, &e), e);
    CHECK(sy_changes_count(c) == 3);
    sy_changes_stats st = sy_changes_get_stats(c);
    CHECK(st.created == 3 && st.destroyed == 0 && st.updated == 0);
    const sy_change *en = find_entry(c, SY_TYPE_NODE, n.id);
    CHECK(en && en->flags == SY_CHANGE_CREATED);
    CHECK(en->mask == ((SY_BIT(SY_NODE_FIELD_COUNT) - 1) | SY_BIT(SY_FIELD_ATTACHMENTS))); /* creations carry every field */
    CHECK(strcmp(((const sy_node_data *)en->data)->name, "n") == 0);
    CHECK(sy_changes_get(c, 0)->type == SY_TYPE_LIGHT); /* type order: lights before nodes */
    uint64_t f0, f1;
    sy_changes_frames(c, &f0, &f1);
    CHECK(f0 == 0 && f1 == 1);
    sy_changes_release(c);

    /* a field set three times: one entry, the last value */
    const float t1[3] = {1, 0, 0}, t2[3] = {2, 0, 0}, t3[3] = {3, 0, 0};
    CHECK_OK(sy_node_set_trs(s, n, t1, Q0, S1, &e), e);
    CHECK_OK(sy_node_set_trs(s, n, t2, Q0, S1, &e), e);
    CHECK_OK(sy_node_set_trs(s, n, t3, Q0, S1, &e), e);
    CHECK_OK(sy_node_set_flags(s, n, 0, &e), e);
    sy_light_data ld = *sy_light_get(s, l);
    for (int i = 1; i <= 3; ++i) {
        ld.intensity = (float)i * 10;
        CHECK_OK(sy_light_set(s, l, &ld, &e), e);
    }
    /* created and destroyed within the frame: no entry */
    CHECK_OK(sy_node_create(s, "gone", &gone, &e), e);
    CHECK_OK(sy_node_set_trs(s, gone, t1, Q0, S1, &e), e);
    CHECK_OK(sy_object_destroy(s, SY_TYPE_NODE, gone.id, &e), e);
    /* an existing object modified then destroyed: only the destruction */
    CHECK_OK(sy_node_set_trs(s, old, t1, Q0, S1, &e), e);
    CHECK_OK(sy_object_destroy(s, SY_TYPE_NODE, old.id, &e), e);
    CHECK_OK(sy_scene_commit(s, &frame, &e), e);
    CHECK(frame == 2);
    CHECK_OK(sy_scene_consumer_pull(s, con, &c, &e), e);
    CHECK(check_order(c) == 0);
    CHECK_MSG(sy_changes_count(c) == 3, "%u entries", sy_changes_count(c));
    CHECK(find_entry(c, SY_TYPE_NODE, gone.id) == NULL);
    en = sy_changes_get(c, 0); /* destructions first */
    CHECK(en->id == old.id && en->flags == SY_CHANGE_DESTROYED && en->mask == 0 && en->data == NULL);
    en = find_entry(c, SY_TYPE_NODE, n.id);
    CHECK(en && en->flags == 0 && en->mask == (SY_BIT(SY_NODE_TRANSFORM) | SY_BIT(SY_NODE_FLAGS)));
    CHECK(((const sy_node_data *)en->data)->transform.translation[0] == 3.0f);
    CHECK(((const sy_node_data *)en->data)->transform.matrix.m[12] == 3.0f);
    CHECK(((const sy_node_data *)en->data)->flags == 0);
    en = find_entry(c, SY_TYPE_LIGHT, l.id);
    CHECK(en && en->mask == SY_BIT(SY_LIGHT_INTENSITY) && ((const sy_light_data *)en->data)->intensity == 30.0f);
    st = sy_changes_get_stats(c);
    CHECK(st.created == 0 && st.destroyed == 1 && st.updated == 2 && st.fields == 3);
    sy_changes_frames(c, &f0, &f1);
    CHECK(f0 == 1 && f1 == 2);
    /* the list is immutable and self-contained: editing the scene afterwards does not touch it */
    CHECK_OK(sy_node_set_trs(s, n, t1, Q0, S1, &e), e);
    CHECK_OK(sy_object_destroy(s, SY_TYPE_LIGHT, l.id, &e), e);
    CHECK_OK(sy_scene_commit(s, NULL, &e), e);
    en = find_entry(c, SY_TYPE_NODE, n.id);
    CHECK(((const sy_node_data *)en->data)->transform.translation[0] == 3.0f);
    CHECK(((const sy_light_data *)find_entry(c, SY_TYPE_LIGHT, l.id)->data)->intensity == 30.0f);
    sy_changes_release(c);
    /* an empty frame */
    CHECK_OK(sy_scene_consumer_pull(s, con, &c, &e), e);
    sy_changes_release(c);
    CHECK_OK(sy_scene_commit(s, NULL, &e), e);
    CHECK_OK(sy_scene_consumer_pull(s, con, &c, &e), e);
    CHECK(sy_changes_count(c) == 0);
    sy_changes_release(c);
    /* unknown consumers */
    CHECK_ERR(sy_scene_consumer_pull(s, 0, &c, &e), SY_ERR_INVALID_HANDLE, e);
    CHECK_ERR(sy_scene_consumer_pull(s, 99, &c, &e), SY_ERR_INVALID_HANDLE, e);
    return 0;
}

/* ------------------------------------------------------------------ two consumers, merging, compaction */

/* Reference merge of consecutive per-frame lists (what a consumer pulling less often must get). */
typedef struct ref_entry {
    uint32_t type, id, flags;
    uint64_t mask;
    const sy_change *src[64]; /* latest source entry per field bit (63: attachments) */
    bool dropped;
} ref_entry;

static int check_merged(sy_changes *const *frames, uint32_t nframes, const sy_changes *merged)
{
    ref_entry *ref = calloc(1024, sizeof *ref);
    uint32_t n = 0;
    CHECK(ref);
    for (uint32_t f = 0; f < nframes; ++f)
        for (uint32_t i = 0; i < sy_changes_count(frames[f]); ++i) {
            const sy_change *c = sy_changes_get(frames[f], i);
            ref_entry *r = NULL;
            for (uint32_t k = 0; k < n; ++k)
                if (ref[k].type == c->type && ref[k].id == c->id) r = &ref[k];
            if (!r) {
                CHECK(n < 1024);
                r = &ref[n++];
                r->type = c->type;
                r->id = c->id;
            }
            if (c->flags & SY_CHANGE_DESTROYED) {
                if (r->flags & SY_CHANGE_CREATED) r->dropped = true;
                r->flags = SY_CHANGE_DESTROYED;
                r->mask = 0;
                continue;
            }
            r->flags |= c->flags;
            r->mask |= c->mask;
            for (uint32_t b = 0; b < 64; ++b)
                if (c->mask & SY_BIT(b)) r->src[b] = c;
        }
    uint32_t live = 0;
    for (uint32_t k = 0; k < n; ++k) {
        if (ref[k].dropped) {
            CHECK(find_entry(merged, ref[k].type, ref[k].id) == NULL);
            continue;
        }
        live++;
        const sy_change *m = find_entry(merged, ref[k].type, ref[k].id);
        CHECK_MSG(m != NULL, "%s %#x missing from the merged list", sy_object_type_name(ref[k].type), ref[k].id);
        CHECK(m->flags == ref[k].flags);
        CHECK_MSG(m->mask == ref[k].mask, "mask %#llx vs %#llx", (unsigned long long)m->mask,
                  (unsigned long long)ref[k].mask);
        const sy_type_desc *td = sy__type_desc(m->type);
        for (uint32_t f = 0; f < td->field_count; ++f)
            if (m->mask & SY_BIT(f))
                CHECK_MSG(sy__field_equal(m->type, f, m->data, ref[k].src[f]->data), "%s %#x field %s not the last value",
                          sy_object_type_name(m->type), m->id, td->fields[f].name);
        if (m->mask & SY_BIT(SY_FIELD_ATTACHMENTS)) {
            const sy_change *a = ref[k].src[SY_FIELD_ATTACHMENTS];
            CHECK(sy__attachments_equal(m->attachments, m->attachment_count, a->attachments, a->attachment_count));
        }
    }
    CHECK(sy_changes_count(merged) == live);
    CHECK(check_order(merged) == 0);
    free(ref);
    return 0;
}

SY_SCENE_TEST(test_two_consumers)
{
    sy_scene *ra, *rb;
    CHECK_OK(sy_scene_create(&ra, &e), e);
    CHECK_OK(sy_scene_create(&rb, &e), e);
    uint32_t ca, cb;
    CHECK_OK(sy_scene_consumer_add(s, &ca, &e), e);
    CHECK_OK(sy_scene_consumer_add(s, &cb, &e), e);
    CHECK(ca != cb);
    sy_changes *c;
    CHECK_OK(sy_scene_consumer_pull(s, ca, &c, &e), e);
    sy_changes_release(c);
    CHECK_OK(sy_scene_consumer_pull(s, cb, &c, &e), e);
    sy_changes_release(c);
    CHECK(sy_scene_log_length(s) == 0 && sy_scene_log_bytes(s) == 0);

    enum { FRAMES = 12, MAXN = 64 };
    sy_node nodes[MAXN];
    uint32_t nn = 0;
    sy_changes *window[3] = {0};
    rng_state = 42;
    for (uint32_t f = 1; f <= FRAMES; ++f) {
        /* a few edits of every kind */
        for (int k = 0; k < 3 && nn < MAXN; ++k) {
            char name[16];
            snprintf(name, sizeof name, "n%u", nn);
            CHECK_OK(sy_node_create(s, name, &nodes[nn], &e), e);
            nn++;
        }
        for (int k = 0; k < 6; ++k) {
            sy_node x = nodes[rnd() % nn];
            if (!sy_node_get(s, x)) continue;
            const float t[3] = {(float)(rnd() % 100), (float)f, (float)k};
            switch (rnd() % 4) {
            case 0: CHECK_OK(sy_node_set_trs(s, x, t, Q0, S1, &e), e); break;
            case 1: CHECK_OK(sy_node_set_flags(s, x, (uint32_t)(rnd() % 8), &e), e); break;
            case 2: {
                sy_attachment at = {.key = (rnd() & 1) ? "x" : "y", .kind = SY_ATTACH_INT, .value.i = (int64_t)(rnd() % 5)};
                CHECK_OK(sy_object_set_attachment(s, SY_TYPE_NODE, x.id, &at, &e), e);
                break;
            }
            default: {
                char nm[16];
                snprintf(nm, sizeof nm, "r%u", (unsigned)(rnd() % 4));
                CHECK_OK(sy_object_set_field(s, SY_TYPE_NODE, x.id, SY_NODE_NAME, &(const char *){nm}, &e), e);
            }
            }
        }
        /* destroy one older node, and sometimes the newest one (created this frame) */
        sy_node victim = nodes[rnd() % nn];
        if (sy_node_get(s, victim)) CHECK_OK(sy_object_destroy(s, SY_TYPE_NODE, victim.id, &e), e);
        if (f % 4 == 2 && sy_node_get(s, nodes[nn - 1])) CHECK_OK(sy_object_destroy(s, SY_TYPE_NODE, nodes[nn - 1].id, &e), e);
        uint64_t frame;
        CHECK_OK(sy_scene_commit(s, &frame, &e), e);
        CHECK(frame == f);

        /* A pulls every frame */
        CHECK(sy_scene_log_length(s) == 1 + (f - 1) % 3); /* B lags behind by up to 3 frames */
        CHECK_OK(sy_scene_consumer_pull(s, ca, &c, &e), e);
        CHECK(check_order(c) == 0);
        uint64_t f0, f1;
        sy_changes_frames(c, &f0, &f1);
        CHECK(f0 == f - 1 && f1 == f);
        CHECK_OK(sy_scene_apply(ra, c, &e), e);
        CHECK_OK(sy_scene_commit(ra, NULL, &e), e);
        CHECK_MSG(sy_scene_equal(s, ra, &e), "A after frame %u: %s", f, e.message);
        window[(f - 1) % 3] = c;
        CHECK(sy_scene_log_length(s) == 1 + (f - 1) % 3); /* A passing does not compact: B has not */
        CHECK(sy_scene_log_bytes(s) > 0);

        /* B pulls every third frame: the merge of A's three lists */
        if (f % 3 == 0) {
            CHECK_OK(sy_scene_consumer_pull(s, cb, &c, &e), e);
            sy_changes_frames(c, &f0, &f1);
            CHECK(f0 == f - 3 && f1 == f);
            CHECK(check_merged(window, 3, c) == 0);
            CHECK_OK(sy_scene_apply(rb, c, &e), e);
            CHECK_OK(sy_scene_commit(rb, NULL, &e), e);
            CHECK_MSG(sy_scene_equal(s, rb, &e), "B after frame %u: %s", f, e.message);
            sy_changes_release(c);
            for (int i = 0; i < 3; ++i) {
                sy_changes_release(window[i]);
                window[i] = NULL;
            }
            CHECK(sy_scene_log_length(s) == 0); /* everyone has passed everything */
            CHECK(sy_scene_log_bytes(s) == 0);
        }
    }
    /* removing the lagging consumer compacts the log at once */
    CHECK_OK(sy_node_set_flags(s, nodes[nn - 2], SY_NODE_STATIC, &e), e);
    CHECK_OK(sy_scene_commit(s, NULL, &e), e);
    CHECK_OK(sy_scene_consumer_pull(s, ca, &c, &e), e);
    sy_changes_release(c);
    CHECK(sy_scene_log_length(s) == 1);
    sy_scene_consumer_remove(s, cb);
    CHECK(sy_scene_log_length(s) == 0);
    CHECK_ERR(sy_scene_consumer_pull(s, cb, &c, &e), SY_ERR_INVALID_HANDLE, e);
    /* with no consumer at all, commits keep no log */
    sy_scene_consumer_remove(s, ca);
    CHECK_OK(sy_node_set_flags(s, nodes[nn - 2], 0, &e), e);
    CHECK_OK(sy_scene_commit(s, NULL, &e), e);
    CHECK(sy_scene_log_length(s) == 0);
    sy_scene_destroy(ra);
    sy_scene_destroy(rb);
    return 0;
}

/* ------------------------------------------------------------------ snapshots for new consumers */
SY_SCENE_TEST(test_late_consumers)
{
    rich r;
    CHECK(build_rich(s, &r) == 0);
    CHECK_OK(sy_scene_commit(s, NULL, &e), e);
    sy_node extra;
    CHECK_OK(sy_node_create(s, "extra", &extra, &e), e);
    CHECK_OK(sy_object_destroy(s, SY_TYPE_NODE, r.root.id, &e), e); /* a destroyed object is not in a snapshot */
    CHECK_OK(sy_scene_commit(s, NULL, &e), e);
    CHECK_OK(sy_scene_commit(s, NULL, &e), e);
    CHECK(sy_scene_log_length(s) == 0); /* nobody listening */

    /* a consumer added now: its first pull is a snapshot creating every live object */
    uint32_t late;
    CHECK_OK(sy_scene_consumer_add(s, &late, &e), e);
    sy_changes *c;
    CHECK_OK(sy_scene_consumer_pull(s, late, &c, &e), e);
    CHECK(sy_changes_is_snapshot(c));
    uint64_t f0, f1;
    sy_changes_frames(c, &f0, &f1);
    CHECK(f0 == 0 && f1 == 3);
    uint32_t live = 0;
    for (uint32_t t = 1; t < SY_TYPE_COUNT; ++t) live += sy_scene_count(s, t);
    CHECK(sy_changes_count(c) == live && live == 10);
    for (uint32_t i = 0; i < sy_changes_count(c); ++i) {
        const sy_change *en = sy_changes_get(c, i);
        CHECK(en->flags == SY_CHANGE_CREATED && en->mask == sy__type_full_mask(en->type));
        CHECK(sy_object_is_valid(s, en->type, en->id));
    }
    CHECK(find_entry(c, SY_TYPE_NODE, r.root.id) == NULL);
    CHECK(check_order(c) == 0);
    sy_scene *rep;
    CHECK_OK(sy_scene_create(&rep, &e), e);
    CHECK_OK(sy_scene_apply(rep, c, &e), e);
    CHECK_MSG(sy_scene_equal(s, rep, &e), "%s", e.message);
    CHECK_MSG(sy_scene_equal(rep, s, &e), "%s", e.message);
    sy_changes_release(c);
    /* the same as sy_scene_snapshot */
    sy_changes *snap;
    CHECK_OK(sy_scene_snapshot(s, &snap, &e), e);
    CHECK(sy_changes_count(snap) == live);
    /* ... which refuses while changes are pending */
    CHECK_OK(sy_node_set_flags(s, extra, 0, &e), e);
    sy_changes *snap2 = (sy_changes *)1;
    CHECK_ERR(sy_scene_snapshot(s, &snap2, &e), SY_ERR_INVALID_ARGUMENT, e);
    CHECK(snap2 == NULL);

    /* a consumer added while changes are pending gets its snapshot at the next commit */
    uint32_t pending;
    CHECK_OK(sy_scene_consumer_add(s, &pending, &e), e);
    CHECK_OK(sy_scene_consumer_pull(s, pending, &c, &e), e);
    CHECK(sy_changes_count(c) == 0 && !sy_changes_is_snapshot(c));
    sy_changes_release(c);
    CHECK_OK(sy_scene_commit(s, NULL, &e), e);
    CHECK_OK(sy_scene_consumer_pull(s, pending, &c, &e), e);
    CHECK(sy_changes_is_snapshot(c) && sy_changes_count(c) == live);
    const sy_change *en = find_entry(c, SY_TYPE_NODE, extra.id);
    CHECK(en && ((const sy_node_data *)en->data)->flags == 0); /* includes the change pending when added */
    sy_scene *rep2;
    CHECK_OK(sy_scene_create(&rep2, &e), e);
    CHECK_OK(sy_scene_apply(rep2, c, &e), e);
    CHECK_MSG(sy_scene_equal(s, rep2, &e), "%s", e.message);
    sy_changes_release(c);
    /* the snapshot merged with later frames */
    uint32_t third;
    CHECK_OK(sy_scene_consumer_add(s, &third, &e), e);
    CHECK_OK(sy_node_set_flags(s, extra, SY_NODE_VISIBLE, &e), e);
    sy_node newer;
    CHECK_OK(sy_node_create(s, "newer", &newer, &e), e);
    CHECK_OK(sy_object_destroy(s, SY_TYPE_NODE, r.b.id, &e), e);
    CHECK_OK(sy_scene_commit(s, NULL, &e), e);
    CHECK_OK(sy_scene_consumer_pull(s, third, &c, &e), e);
    CHECK(sy_changes_is_snapshot(c));
    CHECK(find_entry(c, SY_TYPE_NODE, r.b.id) == NULL); /* created (by the snapshot) and destroyed: absent */
    CHECK(find_entry(c, SY_TYPE_NODE, newer.id) != NULL);
    sy_scene *rep3;
    CHECK_OK(sy_scene_create(&rep3, &e), e);
    CHECK_OK(sy_scene_apply(rep3, c, &e), e);
    CHECK_MSG(sy_scene_equal(s, rep3, &e), "%s", e.message);
    sy_changes_release(c);
    /* the first late consumer gets the difference and stays equal */
    CHECK_OK(sy_scene_consumer_pull(s, late, &c, &e), e);
    CHECK(!sy_changes_is_snapshot(c));
    CHECK_OK(sy_scene_apply(rep, c, &e), e);
    CHECK_MSG(sy_scene_equal(s, rep, &e), "%s", e.message);
    sy_changes_release(c);

    sy_changes_release(snap);
    sy_scene_destroy(rep);
    sy_scene_destroy(rep2);
    sy_scene_destroy(rep3);
    rich_release(&r);
    return 0;
}

/* A snapshot applied to a replica that already holds an older state (a consumer resynchronising,
 * e.g. after a commit could not record its frame) must leave the replica equal to the origin:
 * objects the snapshot does not list are gone, listed ones are updated in place. */
SY_SCENE_TEST(test_resync_snapshot)
{
    sy_scene *rep;
    CHECK_OK(sy_scene_create(&rep, &e), e);
    rich r;
    CHECK(build_rich(s, &r) == 0);
    CHECK_OK(sy_scene_commit(s, NULL, &e), e);
    sy_changes *snap1, *snap2;
    CHECK_OK(sy_scene_snapshot(s, &snap1, &e), e);
    CHECK_OK(sy_scene_apply(rep, snap1, &e), e);
    CHECK_OK(sy_scene_commit(rep, NULL, &e), e);
    CHECK_MSG(sy_scene_equal(s, rep, &e), "%s", e.message);
    /* the origin moves on: destructions, a slot reused with a new generation, edits */
    CHECK_OK(sy_object_destroy(s, SY_TYPE_LIGHT, r.light.id, &e), e);
    CHECK_OK(sy_object_destroy(s, SY_TYPE_NODE, r.b.id, &e), e);
    sy_node reuse;
    CHECK_OK(sy_node_create(s, "reuse", &reuse, &e), e);
    CHECK((reuse.id & SY_HANDLE_INDEX_MASK) == (r.b.id & SY_HANDLE_INDEX_MASK));
    CHECK_OK(sy_node_set_flags(s, r.a, 0, &e), e);
    CHECK_OK(sy_object_remove_attachment(s, SY_TYPE_NODE, r.a.id, "i", &e), e);
    CHECK_OK(sy_scene_commit(s, NULL, &e), e);
    CHECK_OK(sy_scene_snapshot(s, &snap2, &e), e);
    CHECK_OK(sy_scene_apply(rep, snap2, &e), e);
    CHECK_OK(sy_scene_commit(rep, NULL, &e), e);
    CHECK_MSG(sy_scene_equal(s, rep, &e), "%s", e.message);
    CHECK_MSG(sy_scene_equal(rep, s, &e), "%s", e.message);
    sy_changes_release(snap1);
    sy_changes_release(snap2);
    sy_scene_destroy(rep);
    rich_release(&r);
    return 0;
}

/* ------------------------------------------------------------------ wire format */

/* A change list with creations, updates, destructions and every field kind. */
static int make_lists(sy_scene *s, rich *r, sy_changes **snapshot, sy_changes **update)
{
    sy_error e = {0};
    uint32_t con;
    CHECK_OK(sy_scene_consumer_add(s, &con, &e), e);
    CHECK(build_rich(s, r) == 0);
    CHECK_OK(sy_scene_commit(s, NULL, &e), e);
    CHECK_OK(sy_scene_consumer_pull(s, con, snapshot, &e), e);
    /* updates */
    const float t[3] = {-1, -2, -3};
    CHECK_OK(sy_node_set_trs(s, r->b, t, Q0, S1, &e), e);
    CHECK_OK(sy_object_set_field(s, SY_TYPE_NODE, r->a.id, SY_NODE_NAME, &(const char *){NULL}, &e), e);
    CHECK_OK(sy_object_remove_attachment(s, SY_TYPE_NODE, r->a.id, "f", &e), e);
    CHECK_OK(sy_object_destroy(s, SY_TYPE_LIGHT, r->light.id, &e), e);
    CHECK_OK(sy_object_destroy(s, SY_TYPE_CAMERA, r->cam.id, &e), e);
    sy_node n;
    CHECK_OK(sy_node_create(s, "fresh \xc3\xa9", &n, &e), e);
    CHECK_OK(sy_node_add_child(s, r->root, n, &e), e);
    uint8_t big[3000];
    for (size_t i = 0; i < sizeof big; ++i) big[i] = (uint8_t)(i * 7 + 1);
    sy_blob *bb = sy_test_blob(big, sizeof big);
    sy_image_info info = {10, 100, 3, SY_PIXEL_U8_LINEAR};
    CHECK_OK(sy_texture_set_image(s, r->env, &info, bb, &e), e);
    sy_blob_release(bb);
    CHECK_OK(sy_scene_commit(s, NULL, &e), e);
    CHECK_OK(sy_scene_consumer_pull(s, con, update, &e), e);
    CHECK(sy_changes_get_stats(*update).destroyed == 2 && sy_changes_get_stats(*update).created == 1);
    return 0;
}

/* The wire-format tests' fixture (SY_FIXTURE_TEST): a scene with make_lists's snapshot and update;
 * the teardown releases them and checks that no blob outlived the scene. */
typedef struct lists_fixture {
    long live0;
    sy_scene *s;
    rich r;
    sy_changes *snap, *upd;
} lists_fixture;

static int lists_setup(lists_fixture *f)
{
    sy_error e = {0};
    f->live0 = sy_blob_live_count();
    CHECK_OK(sy_scene_create(&f->s, &e), e);
    return make_lists(f->s, &f->r, &f->snap, &f->upd);
}

static void lists_teardown(lists_fixture *f)
{
    sy_changes_release(f->snap);
    sy_changes_release(f->upd);
    sy_scene_destroy(f->s);
    rich_release(&f->r);
    EXPECT_MSG(sy_blob_live_count() == f->live0, "%ld blob(s) alive after the scene, %ld before",
               sy_blob_live_count(), f->live0);
}

#define LISTS_TEST(name) SY_FIXTURE_TEST(name, lists_fixture, lists_setup, lists_teardown)

static int round_trip(const sy_changes *c)
{
    sy_error e = {0};
    void *data;
    size_t size;
    CHECK_OK(sy_changes_serialize(c, NULL, NULL, &data, &size, &e), e);
    CHECK(size >= 32);
    uint32_t magic;
    memcpy(&magic, data, 4);
    CHECK(magic == SY_CHANGES_WIRE_MAGIC);
    sy_blob_store *store;
    CHECK_OK(sy_blob_store_create(&store, &e), e);
    sy_changes *d;
    CHECK_OK(sy_changes_deserialize(data, size, store, NULL, &d, &e), e);
    CHECK(lists_equal(c, d) == 0);
    /* serialising the decoded list gives the same bytes */
    void *data2;
    size_t size2;
    CHECK_OK(sy_changes_serialize(d, NULL, NULL, &data2, &size2, &e), e);
    CHECK(size2 == size && memcmp(data, data2, size) == 0);
    free(data);
    free(data2);
    sy_changes_release(d);
    sy_blob_store_destroy(store);
    return 0;
}

LISTS_TEST(test_round_trip)
{
    sy_error e = {0};
    CHECK(round_trip(f->snap) == 0);
    CHECK(round_trip(f->upd) == 0);
    sy_changes *empty;
    CHECK_OK(sy_scene_consumer_pull(f->s, 1, &empty, &e), e);
    CHECK(sy_changes_count(empty) == 0);
    CHECK(round_trip(empty) == 0);
    sy_changes_release(empty);

    /* a replica fed through the wire equals the origin */
    sy_scene *rep;
    CHECK_OK(sy_scene_create(&rep, &e), e);
    sy_blob_store *store;
    CHECK_OK(sy_blob_store_create(&store, &e), e);
    sy_changes *lists[2] = {f->snap, f->upd};
    for (int i = 0; i < 2; ++i) {
        void *data;
        size_t size;
        CHECK_OK(sy_changes_serialize(lists[i], NULL, NULL, &data, &size, &e), e);
        sy_changes *d;
        CHECK_OK(sy_changes_deserialize(data, size, store, NULL, &d, &e), e);
        free(data);
        CHECK_OK(sy_scene_apply(rep, d, &e), e);
        sy_changes_release(d);
    }
    CHECK_MSG(sy_scene_equal(f->s, rep, &e), "%s", e.message);
    sy_blob_store_destroy(store);
    sy_scene_destroy(rep);
    return 0;
}

/* send callback: payloads only for blobs the receiver's store does not hold */
static bool send_if_missing(void *user, const sy_blob *b)
{
    return sy_blob_store_get((const sy_blob_store *)user, sy_blob_hash(b)) == NULL;
}
static bool send_none(void *user, const sy_blob *b)
{
    (void)user;
    (void)b;
    return false;
}

LISTS_TEST(test_blob_once)
{
    sy_error e = {0};

    void *full, *lean;
    size_t full_size, lean_size;
    sy_blob_store *recv;
    CHECK_OK(sy_blob_store_create(&recv, &e), e);
    CHECK_OK(sy_changes_serialize(f->snap, send_if_missing, recv, &full, &full_size, &e), e);
    sy_changes *d;
    CHECK_OK(sy_changes_deserialize(full, full_size, recv, NULL, &d, &e), e);
    CHECK(lists_equal(f->snap, d) == 0);
    sy_changes_release(d);
    size_t stored = sy_blob_store_count(recv), bytes = sy_blob_store_bytes(recv);
    CHECK_MSG(stored == 18, "%zu", stored); /* pixels, pos, normals, tangents, uv, colours, indices, tri, 2 child lists, attach blob,
                                               joints, skin weights, target deltas (twice), texture coordinate target deltas,
                                               mesh and node morph weights, node skin */
    /* the same list again: every payload is already there, none travels */
    CHECK_OK(sy_changes_serialize(f->snap, send_if_missing, recv, &lean, &lean_size, &e), e);
    CHECK_MSG(lean_size + bytes == full_size, "lean %zu + payloads %zu != full %zu", lean_size, bytes, full_size);
    CHECK_OK(sy_changes_deserialize(lean, lean_size, recv, NULL, &d, &e), e);
    CHECK(lists_equal(f->snap, d) == 0);
    CHECK(sy_blob_store_count(recv) == stored);
    /* decoded blobs are the store's (shared, not copied) */
    const sy_change *en = find_entry(d, SY_TYPE_TEXTURE, f->r.tex.id);
    CHECK(((const sy_texture_data *)en->data)->pixels == sy_blob_store_get(recv, sy_blob_hash(f->r.pixels)));
    sy_changes_release(d);
    /* a receiver lacking them: SY_ERR_NOT_FOUND naming the hash */
    sy_blob_store *empty;
    CHECK_OK(sy_blob_store_create(&empty, &e), e);
    d = (sy_changes *)1;
    CHECK_ERR(sy_changes_deserialize(lean, lean_size, empty, NULL, &d, &e), SY_ERR_NOT_FOUND, e);
    CHECK(d == NULL);
    bool named = false;
    {
        /* every blob of the list is missing: the message names one of them */
        sy_blob *cands[] = {f->r.pixels, f->r.pos, f->r.attach_blob};
        for (int i = 0; i < 3; ++i) {
            char hex[40];
            sy_hash128 h = sy_blob_hash(cands[i]);
            snprintf(hex, sizeof hex, "%016llx%016llx", (unsigned long long)h.hi, (unsigned long long)h.lo);
            if (strstr(e.message, hex)) named = true;
        }
        /* or another blob: at least a 32-digit hash */
        if (!named) {
            const char *p = strstr(e.message, "blob ");
            named = p && strspn(p + 5, "0123456789abcdef") == 32;
        }
    }
    CHECK_MSG(named, "error does not name the hash: %s", e.message);
    CHECK(sy_blob_store_count(empty) == 0);
    /* the update list: only the new texture payload and the new child list travel */
    void *upd_data;
    size_t upd_size;
    CHECK_OK(sy_changes_serialize(f->upd, send_if_missing, recv, &upd_data, &upd_size, &e), e);
    CHECK(upd_size > 3000 && upd_size < 3000 + 800);
    CHECK_OK(sy_changes_deserialize(upd_data, upd_size, recv, NULL, &d, &e), e);
    CHECK(lists_equal(f->upd, d) == 0);
    sy_changes_release(d);
    CHECK(sy_blob_store_count(recv) == stored + 2);
    free(upd_data);
    /* send_none against a store that has all: fine */
    CHECK_OK(sy_changes_serialize(f->upd, send_none, NULL, &upd_data, &upd_size, &e), e);
    CHECK(upd_size < 800);
    CHECK_OK(sy_changes_deserialize(upd_data, upd_size, recv, NULL, &d, &e), e);
    sy_changes_release(d);
    free(upd_data);

    free(full);
    free(lean);
    sy_blob_store_destroy(recv);
    sy_blob_store_destroy(empty);
    return 0;
}

/* A message with one light entry (no blobs): header 32 bytes, entry header at 32 (mask at 40). */
static int one_light_message(void **data, size_t *size)
{
    sy_error e = {0};
    sy_scene *s;
    CHECK_OK(sy_scene_create(&s, &e), e);
    uint32_t con;
    CHECK_OK(sy_scene_consumer_add(s, &con, &e), e);
    sy_light l;
    CHECK_OK(sy_light_create(s, "lamp", &l, &e), e);
    CHECK_OK(sy_scene_commit(s, NULL, &e), e);
    sy_changes *c;
    CHECK_OK(sy_scene_consumer_pull(s, con, &c, &e), e);
    CHECK(sy_changes_count(c) == 1);
    CHECK_OK(sy_changes_serialize(c, NULL, NULL, data, size, &e), e);
    sy_changes_release(c);
    sy_scene_destroy(s);
    return 0;
}

static int expect_decode_error(const void *data, size_t size, sy_result code, const char *needle,
                               const sy_changes_limits *lim)
{
    sy_error e = {0};
    sy_blob_store *st;
    CHECK_OK(sy_blob_store_create(&st, &e), e);
    sy_changes *d = (sy_changes *)1;
    sy_result r = sy_changes_deserialize(data, size, st, lim, &d, &e);
    if (code == SY_RESULT_MAX_ENUM) code = r == SY_OK ? SY_RESULT_MAX_ENUM : r; /* any error */
    CHECK_MSG(r == code, "got %s (%s), expected %s", sy_result_str(r), e.message, sy_result_str(code));
    CHECK(d == NULL);
    CHECK(e.code == code);
    CHECK_MSG(!needle || strstr(e.message, needle), "message '%s' lacks '%s'", e.message, needle);
    sy_blob_store_destroy(st);
    return 0;
}

static int test_decoder_errors(void)
{
    void *base;
    size_t size;
    CHECK(one_light_message(&base, &size) == 0);
    unsigned char *m = malloc(size + 8);
    CHECK(m);
    sy_error e = {0};
    sy_blob_store *st;
    CHECK_OK(sy_blob_store_create(&st, &e), e);
    sy_changes *d;
    CHECK_OK(sy_changes_deserialize(base, size, st, NULL, &d, &e), e);
    CHECK(sy_changes_count(d) == 1 && sy_changes_get(d, 0)->type == SY_TYPE_LIGHT);
    sy_changes_release(d);
    sy_blob_store_destroy(st);

#define RESET() memcpy(m, base, size)
    RESET();
    m[0] ^= 0xff;
    CHECK(expect_decode_error(m, size, SY_ERR_PARSE, "magic", NULL) == 0);
    RESET();
    m[4] = SY_CHANGES_WIRE_VERSION + 1; /* a version from the future */
    CHECK(expect_decode_error(m, size, SY_ERR_UNSUPPORTED, "version", NULL) == 0);
    RESET();
    m[6] = 2; /* header flags */
    CHECK(expect_decode_error(m, size, SY_ERR_PARSE, "flags", NULL) == 0);
    RESET();
    m[size] = 0; /* trailing byte */
    CHECK(expect_decode_error(m, size + 1, SY_ERR_PARSE, "trailing", NULL) == 0);
    RESET();
    m[32 + 8 + 2] |= 0x10; /* mask bit 20: lights have 7 fields */
    CHECK(expect_decode_error(m, size, SY_ERR_PARSE, "mask", NULL) == 0);
    RESET();
    m[32 + 8 + 7] = 0x40; /* mask bit 62 */
    CHECK(expect_decode_error(m, size, SY_ERR_PARSE, "mask", NULL) == 0);
    RESET();
    m[32] = 0; /* type 0 */
    CHECK(expect_decode_error(m, size, SY_ERR_PARSE, "type", NULL) == 0);
    RESET();
    m[32] = SY_TYPE_COUNT;
    CHECK(expect_decode_error(m, size, SY_ERR_PARSE, "type", NULL) == 0);
    RESET();
    m[33] = SY_CHANGE_CREATED | SY_CHANGE_DESTROYED;
    CHECK(expect_decode_error(m, size, SY_ERR_PARSE, NULL, NULL) == 0);
    RESET();
    m[33] = 4;
    CHECK(expect_decode_error(m, size, SY_ERR_PARSE, NULL, NULL) == 0);
    RESET();
    memset(m + 36, 0, 4); /* id 0 */
    CHECK(expect_decode_error(m, size, SY_ERR_PARSE, "id 0", NULL) == 0);
    RESET();
    m[24] = 2; /* two entries announced, one present */
    CHECK(expect_decode_error(m, size, SY_ERR_PARSE, NULL, NULL) == 0);
    RESET();
    m[28] = 1; /* a blob announced but none present (the entry bytes read as a blob record) */
    CHECK(expect_decode_error(m, size, SY_RESULT_MAX_ENUM, NULL, NULL) == 0);
    RESET();
    m[28] = 3; /* three blobs cannot fit in what remains */
    CHECK(expect_decode_error(m, size, SY_ERR_PARSE, "counts", NULL) == 0);
    RESET();
    memset(m + 24, 0xff, 4); /* 4 billion entries */
    CHECK(expect_decode_error(m, size, SY_ERR_LIMIT, NULL, NULL) == 0);
    sy_changes_limits lim = {.max_entries = 0, .max_string_bytes = 3};
    RESET();
    CHECK(expect_decode_error(m, size, SY_ERR_LIMIT, "string", &lim) == 0); /* "lamp" is 4 bytes */
    /* the name string: u32 length at 48 followed by "lamp" */
    uint32_t len;
    memcpy(&len, m + 48, 4);
    CHECK(len == 4 && memcmp(m + 52, "lamp", 4) == 0);
    m[53] = 0;
    CHECK(expect_decode_error(m, size, SY_ERR_PARSE, "NUL", NULL) == 0);
    RESET();
    len = 0x7fffffff;
    memcpy(m + 48, &len, 4);
    CHECK(expect_decode_error(m, size, SY_ERR_LIMIT, NULL, NULL) == 0);
    RESET();
    len = 1000;
    memcpy(m + 48, &len, 4);
    CHECK(expect_decode_error(m, size, SY_ERR_PARSE, NULL, NULL) == 0);
    free(base);

    /* blob table errors: a message with one texture and its pixels */
    {
        sy_scene *s;
        CHECK_OK(sy_scene_create(&s, &e), e);
        uint32_t con;
        CHECK_OK(sy_scene_consumer_add(s, &con, &e), e);
        sy_texture t;
        CHECK_OK(sy_texture_create(s, NULL, &t, &e), e);
        uint8_t px[4] = {1, 2, 3, 4};
        sy_blob *b = sy_test_blob(px, 4);
        sy_image_info info = {1, 1, 4, SY_PIXEL_U8_SRGB};
        CHECK_OK(sy_texture_set_image(s, t, &info, b, &e), e);
        CHECK_OK(sy_scene_commit(s, NULL, &e), e);
        sy_changes *c;
        CHECK_OK(sy_scene_consumer_pull(s, con, &c, &e), e);
        void *tm;
        size_t ts;
        CHECK_OK(sy_changes_serialize(c, NULL, NULL, &tm, &ts, &e), e);
        unsigned char *x = tm;
        /* blob record at 32: hash 16, size 8, flag 1, payload 4 */
        uint64_t bs;
        memcpy(&bs, x + 48, 8);
        CHECK(bs == 4 && x[56] == 1 && memcmp(x + 57, px, 4) == 0);
        x[57] ^= 1;
        CHECK(expect_decode_error(x, ts, SY_ERR_PROTOCOL, "hash", NULL) == 0);
        x[57] ^= 1;
        x[56] = 2;
        CHECK(expect_decode_error(x, ts, SY_ERR_PARSE, NULL, NULL) == 0);
        x[56] = 1;
        sy_changes_limits bl = {.max_blob_bytes = 3};
        CHECK(expect_decode_error(x, ts, SY_ERR_LIMIT, "blob", &bl) == 0);
        bs = 1ull << 40;
        memcpy(x + 48, &bs, 8);
        CHECK(expect_decode_error(x, ts, SY_ERR_LIMIT, NULL, NULL) == 0);
        bs = 4;
        memcpy(x + 48, &bs, 8);
        /* a blob index past the table: the pixels field is the last 4 bytes before the sampler */
        sy_blob_store *st2;
        CHECK_OK(sy_blob_store_create(&st2, &e), e);
        sy_changes *ok;
        CHECK_OK(sy_changes_deserialize(x, ts, st2, NULL, &ok, &e), e);
        CHECK(lists_equal(c, ok) == 0);
        sy_changes_release(ok);
        sy_blob_store_destroy(st2);
        size_t pix_at = ts - 4 /* attachment count */ - sizeof(sy_sampler) - 4;
        uint32_t bi;
        memcpy(&bi, x + pix_at, 4);
        CHECK(bi == 0);
        bi = 1;
        memcpy(x + pix_at, &bi, 4);
        CHECK(expect_decode_error(x, ts, SY_ERR_PARSE, "blob index", NULL) == 0);
        free(tm);
        sy_changes_release(c);
        sy_blob_release(b);
        sy_scene_destroy(s);
    }
    free(m);
#undef RESET
    return 0;
}

/* Decodes and, when it decodes, applies to a fresh copy of the replica and re-serialises. Never
 * crashes or leaks (ASan); the result is either an error or a usable list. */
static int decode_and_use(const void *data, size_t size, const sy_changes *base_snapshot, long *ok_count)
{
    sy_error e = {0};
    sy_blob_store *st;
    CHECK_OK(sy_blob_store_create(&st, &e), e);
    sy_changes *d = NULL;
    sy_result r = sy_changes_deserialize(data, size, st, NULL, &d, &e);
    if (r != SY_OK) {
        CHECK(d == NULL);
        CHECK(e.code == r && e.message[0] != '\0');
    } else {
        CHECK(d != NULL);
        (*ok_count)++;
        void *again;
        size_t again_size;
        CHECK_OK(sy_changes_serialize(d, NULL, NULL, &again, &again_size, &e), e);
        free(again);
        /* a list may legitimately name slot indices in the millions; a replica then allocates
         * pools that large, which is correct but too slow for thousands of fuzz inputs */
        bool huge = false;
        for (uint32_t i = 0; i < sy_changes_count(d); ++i)
            if ((sy_changes_get(d, i)->id & SY_HANDLE_INDEX_MASK) > 4096) huge = true;
        if (huge) {
            sy_changes_release(d);
            sy_blob_store_destroy(st);
            return 0;
        }
        sy_scene *rep;
        CHECK_OK(sy_scene_create(&rep, &e), e);
        if (base_snapshot) CHECK_OK(sy_scene_apply(rep, base_snapshot, &e), e);
        (void)sy_scene_apply(rep, d, &e); /* may refuse; must not crash */
        (void)sy_scene_commit(rep, NULL, &e);
        sy_scene_destroy(rep);
        sy_changes_release(d);
    }
    sy_blob_store_destroy(st);
    return 0;
}

LISTS_TEST(test_decoder_fuzz)
{
    rng_state = 7;
    sy_changes *msgs[2] = {f->snap, f->upd};
    sy_error e = {0};
    long ok = 0, total = 0;
    for (int mi = 0; mi < 2; ++mi) {
        void *data;
        size_t size;
        CHECK_OK(sy_changes_serialize(msgs[mi], NULL, NULL, &data, &size, &e), e);
        const sy_changes *base = mi == 1 ? f->snap : NULL;
        unsigned char *buf = malloc(size + 1);
        CHECK(buf);
        /* every truncation is an error */
        for (size_t len = 0; len < size; ++len) {
            sy_blob_store *st;
            CHECK_OK(sy_blob_store_create(&st, &e), e);
            sy_changes *d = (sy_changes *)1;
            memcpy(buf, data, len); /* a copy of exactly len bytes, so ASan sees over-reads */
            unsigned char *exact = malloc(len ? len : 1);
            CHECK(exact);
            memcpy(exact, data, len);
            sy_result rr = sy_changes_deserialize(exact, len, st, NULL, &d, &e);
            CHECK_MSG(rr != SY_OK, "truncation to %zu of %zu bytes decoded", len, size);
            CHECK(d == NULL);
            free(exact);
            sy_blob_store_destroy(st);
            total++;
        }
        /* single-byte mutations */
        for (int k = 0; k < 4000; ++k) {
            memcpy(buf, data, size);
            size_t at = (size_t)(rnd() % size);
            uint8_t v;
            switch (rnd() % 4) {
            case 0: v = (uint8_t)(buf[at] ^ (1u << (rnd() % 8))); break;
            case 1: v = 0xff; break;
            case 2: v = 0; break;
            default: v = (uint8_t)rnd(); break;
            }
            buf[at] = v;
            CHECK_MSG(decode_and_use(buf, size, base, &ok) == 0, "mutation %d at byte %zu", k, at);
            total++;
        }
        /* a few multi-byte mutations in the entry area */
        for (int k = 0; k < 1000; ++k) {
            memcpy(buf, data, size);
            for (int j = 0; j < 4; ++j) buf[(size_t)(rnd() % size)] = (uint8_t)rnd();
            CHECK(decode_and_use(buf, size, base, &ok) == 0);
            total++;
        }
        free(buf);
        free(data);
    }
    /* random garbage, with and without a valid header */
    for (int k = 0; k < 3000; ++k) {
        size_t size = (size_t)(rnd() % 200);
        unsigned char *buf = malloc(size + 1);
        CHECK(buf);
        for (size_t i = 0; i < size; ++i) buf[i] = (uint8_t)rnd();
        if ((k & 1) && size >= 32) {
            uint32_t magic = SY_CHANGES_WIRE_MAGIC;
            uint16_t ver = SY_CHANGES_WIRE_VERSION, fl = 0;
            uint32_t ne = (uint32_t)(rnd() % 3), nb = (uint32_t)(rnd() % 2);
            memcpy(buf, &magic, 4);
            memcpy(buf + 4, &ver, 2);
            memcpy(buf + 6, &fl, 2);
            memcpy(buf + 24, &ne, 4);
            memcpy(buf + 28, &nb, 4);
            if (!nb && size > 48 && (k & 2)) { /* a plausible entry header */
                buf[32] = (uint8_t)(1 + rnd() % 7);
                buf[33] = (uint8_t)(rnd() % 3);
                buf[34] = buf[35] = 0;
            }
        }
        CHECK(decode_and_use(buf, size, NULL, &ok) == 0);
        free(buf);
        total++;
    }
    printf("decoder fuzz: %ld inputs, %ld decoded to a valid list\n", total, ok);
    CHECK(ok > 0); /* some mutations (in float values) must still decode */
    return 0;
}

SY_CHECK_MAIN("test_changes", SY_TEST(test_commit_entries), SY_TEST(test_two_consumers), SY_TEST(test_late_consumers),
              SY_TEST(test_resync_snapshot), SY_TEST(test_round_trip), SY_TEST(test_blob_once),
              SY_TEST(test_decoder_errors), SY_TEST(test_decoder_fuzz))
