/* test_scene.c — sy_scene: handles, dirty marking and no-op sets, validation, world matrices,
 * incremental (dirty-subtree-only) updates, bounds, DAGs and attachments. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../support/sy_check.h"
#include "../support/sy_scene_test.h"
#include "sy_changes.h"
#include "sy_scene.h"

static const float T0[3] = {0, 0, 0}, Q0[4] = {0, 0, 0, 1}, S1[3] = {1, 1, 1};

/* Pulls what the consumer has pending after a commit; the caller releases it. */
static sy_changes *commit_pull(sy_scene *s, uint32_t consumer)
{
    sy_error e = {0};
    sy_changes *c = NULL;
    if (sy_scene_commit(s, NULL, &e) != SY_OK || sy_scene_consumer_pull(s, consumer, &c, &e) != SY_OK) {
        fprintf(stderr, "commit/pull failed: %s\n", e.message);
        return NULL;
    }
    return c;
}

static const sy_change *find_entry(const sy_changes *c, uint32_t type, uint32_t id)
{
    for (uint32_t i = 0; i < sy_changes_count(c); ++i) {
        const sy_change *e = sy_changes_get(c, i);
        if (e->type == type && e->id == id) return e;
    }
    return NULL;
}

/* Creates one node per name, in order: names[i] into *out[i]. */
static int create_nodes(sy_scene *s, size_t n, const char *const *names, sy_node *const *out)
{
    sy_error e = {0};
    for (size_t i = 0; i < n; ++i) CHECK_OK(sy_node_create(s, names[i], out[i], &e), e);
    return 0;
}

/* ------------------------------------------------------------------ handles */
SY_SCENE_TEST(test_handles)
{
    sy_node a, b;
    CHECK_OK(sy_node_create(s, "a", &a, &e), e);
    CHECK_OK(sy_node_create(s, NULL, &b, &e), e);
    CHECK(a.id != 0 && b.id != 0 && a.id != b.id);
    CHECK(sy_object_is_valid(s, SY_TYPE_NODE, a.id));
    CHECK(strcmp(sy_node_get(s, a)->name, "a") == 0);
    CHECK(sy_node_get(s, b)->name == NULL);
    CHECK(sy_scene_count(s, SY_TYPE_NODE) == 2);

    /* id 0 is never valid */
    sy_node zero = {0};
    CHECK(!sy_object_is_valid(s, SY_TYPE_NODE, 0));
    CHECK(sy_node_get(s, zero) == NULL);
    CHECK_ERR(sy_node_set_flags(s, zero, 0, &e), SY_ERR_INVALID_HANDLE, e);
    CHECK_ERR(sy_object_destroy(s, SY_TYPE_NODE, 0, &e), SY_ERR_INVALID_HANDLE, e);
    /* unknown type, an index past the pool */
    CHECK(!sy_object_is_valid(s, SY_TYPE_NONE, a.id));
    CHECK(!sy_object_is_valid(s, SY_TYPE_COUNT, a.id));
    CHECK(!sy_object_is_valid(s, SY_TYPE_NODE, a.id + 1000));
    uint32_t dummy;
    CHECK_ERR(sy_object_create(s, SY_TYPE_COUNT, "x", &dummy, &e), SY_ERR_INVALID_ARGUMENT, e);

    /* stale after destroy */
    uint32_t old = a.id;
    CHECK_OK(sy_object_destroy(s, SY_TYPE_NODE, a.id, &e), e);
    CHECK(!sy_object_is_valid(s, SY_TYPE_NODE, old));
    CHECK(sy_node_get(s, a) == NULL);
    CHECK_ERR(sy_node_set_trs(s, a, T0, Q0, S1, &e), SY_ERR_INVALID_HANDLE, e);
    CHECK_ERR(sy_object_destroy(s, SY_TYPE_NODE, old, &e), SY_ERR_INVALID_HANDLE, e);
    sy_attachment at = {.key = "k", .kind = SY_ATTACH_INT, .value.i = 1};
    CHECK_ERR(sy_object_set_attachment(s, SY_TYPE_NODE, old, &at, &e), SY_ERR_INVALID_HANDLE, e);
    sy_mat4 w;
    CHECK_ERR(sy_node_world_matrix(s, a, &w, &e), SY_ERR_INVALID_HANDLE, e);
    CHECK(sy_scene_count(s, SY_TYPE_NODE) == 1);

    /* the slot is reused with a different id; the old handle stays invalid */
    sy_node c;
    CHECK_OK(sy_node_create(s, "c", &c, &e), e);
    CHECK((c.id & SY_HANDLE_INDEX_MASK) == (old & SY_HANDLE_INDEX_MASK));
    CHECK(c.id != old);
    CHECK(!sy_object_is_valid(s, SY_TYPE_NODE, old));
    CHECK(sy_node_get(s, a) == NULL);
    CHECK(strcmp(sy_node_get(s, c)->name, "c") == 0);

    /* iteration in slot order */
    uint32_t seen = 0;
    for (uint32_t id = sy_scene_next(s, SY_TYPE_NODE, 0); id; id = sy_scene_next(s, SY_TYPE_NODE, id)) {
        CHECK(id == c.id || id == b.id);
        seen++;
    }
    CHECK(seen == 2);
    CHECK(sy_scene_next(s, SY_TYPE_MESH, 0) == 0);

    /* generation overflow: a slot is reused until its generation is exhausted, then retired;
     * no id ever repeats */
    enum { ROUNDS = 1100 };
    uint32_t *ids = malloc(sizeof *ids * ROUNDS);
    CHECK(ids);
    for (uint32_t i = 0; i < ROUNDS; ++i) {
        sy_light l;
        CHECK_OK(sy_light_create(s, NULL, &l, &e), e);
        ids[i] = l.id;
        CHECK_OK(sy_object_destroy(s, SY_TYPE_LIGHT, l.id, &e), e);
        if (i % 64 == 0) CHECK_OK(sy_scene_commit(s, NULL, &e), e);
    }
    for (uint32_t i = 0; i < ROUNDS; ++i)
        for (uint32_t j = i + 1; j < ROUNDS; ++j) CHECK_MSG(ids[i] != ids[j], "id %#x repeats (%u, %u)", ids[i], i, j);
    CHECK((ids[0] & SY_HANDLE_INDEX_MASK) == (ids[SY_HANDLE_MAX_GENERATION - 1] & SY_HANDLE_INDEX_MASK));
    CHECK((ids[0] & SY_HANDLE_INDEX_MASK) != (ids[SY_HANDLE_MAX_GENERATION] & SY_HANDLE_INDEX_MASK));
    free(ids);
    CHECK(sy_scene_count(s, SY_TYPE_LIGHT) == 0);
    sy_scene_destroy(NULL);
    return 0;
}

/* ------------------------------------------------------------------ dirty marks and no-op sets */
SY_SCENE_TEST(test_dirty_noop)
{
    uint32_t con;
    CHECK_OK(sy_scene_consumer_add(s, &con, &e), e);
    CHECK(!sy_scene_has_pending(s));
    /* created and destroyed in one frame: nothing is pending, and a commit delivers no change */
    sy_node tmp;
    CHECK_OK(sy_node_create(s, "tmp", &tmp, &e), e);
    CHECK(sy_scene_has_pending(s));
    CHECK_OK(sy_object_destroy(s, SY_TYPE_NODE, tmp.id, &e), e);
    CHECK(!sy_scene_has_pending(s));
    sy_changes *none = NULL;
    CHECK_OK(sy_scene_commit(s, NULL, &e), e);
    CHECK_OK(sy_scene_consumer_pull(s, con, &none, &e), e);
    CHECK(none == NULL || sy_changes_count(none) == 0); /* no change list, or an empty one */
    sy_changes_release(none);
    sy_node n;
    sy_material m;
    CHECK_OK(sy_node_create(s, "n", &n, &e), e);
    CHECK_OK(sy_material_create(s, "m", &m, &e), e);
    CHECK(sy_scene_has_pending(s));
    sy_changes *c = commit_pull(s, con);
    CHECK(c && sy_changes_count(c) == 2);
    sy_changes_release(c);
    CHECK(!sy_scene_has_pending(s));

    /* setting the values it already has changes nothing */
    CHECK_OK(sy_node_set_trs(s, n, T0, Q0, S1, &e), e);
    CHECK_OK(sy_node_set_flags(s, n, SY_NODE_VISIBLE, &e), e);
    CHECK_OK(sy_node_set_children(s, n, NULL, 0, &e), e);
    CHECK_OK(sy_object_set_field(s, SY_TYPE_NODE, n.id, SY_NODE_NAME, &(const char *){"n"}, &e), e);
    sy_material_data md = *sy_material_get(s, m);
    CHECK_OK(sy_material_set(s, m, &md, &e), e);
    CHECK(!sy_scene_has_pending(s));
    c = commit_pull(s, con);
    CHECK(c && sy_changes_count(c) == 0);
    sy_changes_release(c);

    /* a real change marks exactly that field; setting it back within the frame still reports it */
    const float t1[3] = {1, 2, 3};
    CHECK_OK(sy_node_set_trs(s, n, t1, Q0, S1, &e), e);
    CHECK(sy_scene_has_pending(s));
    md.roughness = 0.25f;
    md.emissive[1] = 2.0f;
    CHECK_OK(sy_material_set(s, m, &md, &e), e);
    c = commit_pull(s, con);
    CHECK(c && sy_changes_count(c) == 2);
    const sy_change *en = find_entry(c, SY_TYPE_NODE, n.id), *em = find_entry(c, SY_TYPE_MATERIAL, m.id);
    CHECK(en && em);
    CHECK(en->mask == SY_BIT(SY_NODE_TRANSFORM) && en->flags == 0);
    CHECK(em->mask == (SY_BIT(SY_MATERIAL_ROUGHNESS) | SY_BIT(SY_MATERIAL_EMISSIVE)));
    const sy_node_data *nd = en->data;
    CHECK(nd->transform.translation[2] == 3.0f && nd->transform.matrix.m[12] == 1.0f);
    CHECK(((const sy_material_data *)em->data)->roughness == 0.25f);
    sy_changes_release(c);

    /* names: NULL -> "x" -> NULL */
    CHECK_OK(sy_object_set_field(s, SY_TYPE_NODE, n.id, SY_NODE_NAME, &(const char *){NULL}, &e), e);
    CHECK(sy_node_get(s, n)->name == NULL);
    CHECK(sy_scene_has_pending(s));
    c = commit_pull(s, con);
    en = find_entry(c, SY_TYPE_NODE, n.id);
    CHECK(en && en->mask == SY_BIT(SY_NODE_NAME) && ((const sy_node_data *)en->data)->name == NULL);
    sy_changes_release(c);
    CHECK_OK(sy_object_set_field(s, SY_TYPE_NODE, n.id, SY_NODE_NAME, &(const char *){NULL}, &e), e);
    CHECK(!sy_scene_has_pending(s));

    /* blob fields compare by content: an equal child list in a new blob is a no-op */
    sy_node k;
    CHECK_OK(sy_node_create(s, "k", &k, &e), e);
    CHECK_OK(sy_node_set_children(s, n, &k, 1, &e), e);
    sy_changes_release(commit_pull(s, con));
    CHECK_OK(sy_node_set_children(s, n, &k, 1, &e), e);
    CHECK(!sy_scene_has_pending(s));
    /* the matrix form of the same transform is a different value (mode differs) */
    sy_mat4 mm = sy_mat4_from_trs(t1, Q0, S1);
    CHECK_OK(sy_node_set_matrix(s, n, &mm, &e), e);
    CHECK(sy_scene_has_pending(s));
    CHECK(sy_node_get(s, n)->transform.mode == SY_TRANSFORM_MATRIX);
    sy_changes_release(commit_pull(s, con));
    CHECK_OK(sy_node_set_matrix(s, n, &mm, &e), e);
    CHECK(!sy_scene_has_pending(s));

    /* generic setter: a TRS transform's matrix is recomputed from T, R and S, whatever the caller put there */
    sy_transform tr = sy_node_get(s, n)->transform;
    tr.mode = SY_TRANSFORM_TRS;
    memcpy(tr.translation, (float[3]){4, 5, 6}, sizeof tr.translation);
    tr.matrix = sy_mat4_identity();
    CHECK_OK(sy_object_set_field(s, SY_TYPE_NODE, n.id, SY_NODE_TRANSFORM, &tr, &e), e);
    CHECK(sy_node_get(s, n)->transform.matrix.m[12] == 4.0f && sy_node_get(s, n)->transform.matrix.m[14] == 6.0f);
    return 0;
}

/* ------------------------------------------------------------------ validation */
SY_SCENE_TEST(test_validation)
{
    sy_node n;
    CHECK_OK(sy_node_create(s, "n", &n, &e), e);
    CHECK_OK(sy_scene_commit(s, NULL, &e), e);

    /* transforms */
    const float tn[3] = {0, NAN, 0}, ti[3] = {INFINITY, 0, 0}, qn[4] = {0, 0, NAN, 1};
    CHECK_ERR(sy_node_set_trs(s, n, tn, Q0, S1, &e), SY_ERR_INVALID_ARGUMENT, e);
    CHECK_ERR(sy_node_set_trs(s, n, ti, Q0, S1, &e), SY_ERR_INVALID_ARGUMENT, e);
    CHECK_ERR(sy_node_set_trs(s, n, T0, qn, S1, &e), SY_ERR_INVALID_ARGUMENT, e);
    CHECK_ERR(sy_node_set_trs(s, n, T0, Q0, tn, &e), SY_ERR_INVALID_ARGUMENT, e);
    sy_mat4 bad = sy_mat4_identity();
    bad.m[13] = NAN;
    CHECK_ERR(sy_node_set_matrix(s, n, &bad, &e), SY_ERR_INVALID_ARGUMENT, e);
    bad.m[13] = -INFINITY;
    CHECK_ERR(sy_node_set_matrix(s, n, &bad, &e), SY_ERR_INVALID_ARGUMENT, e);
    sy_transform tr = sy_node_get(s, n)->transform;
    tr.mode = 7;
    CHECK_ERR(sy_object_set_field(s, SY_TYPE_NODE, n.id, SY_NODE_TRANSFORM, &tr, &e), SY_ERR_INVALID_ARGUMENT, e);
    CHECK_ERR(sy_node_set_flags(s, n, 1u << 9, &e), SY_ERR_INVALID_ARGUMENT, e);
    CHECK_ERR(sy_object_set_field(s, SY_TYPE_NODE, n.id, SY_NODE_FIELD_COUNT, &tr, &e), SY_ERR_INVALID_ARGUMENT, e);
    CHECK_ERR(sy_object_set_field(s, SY_TYPE_NODE, n.id, SY_FIELD_ATTACHMENTS, &tr, &e), SY_ERR_INVALID_ARGUMENT, e);
    /* refused sets leave the object unchanged and record nothing */
    CHECK(!sy_scene_has_pending(s));
    sy_mat4 idm = sy_mat4_identity();
    CHECK(sy_mat4_equal(&sy_node_get(s, n)->transform.matrix, &idm));

    /* references */
    sy_mesh gone;
    CHECK_OK(sy_mesh_create(s, "gone", &gone, &e), e);
    CHECK_OK(sy_object_destroy(s, SY_TYPE_MESH, gone.id, &e), e);
    CHECK_ERR(sy_node_set_mesh(s, n, gone, &e), SY_ERR_INVALID_HANDLE, e);
    CHECK_ERR(sy_node_set_light(s, n, (sy_light){12345}, &e), SY_ERR_INVALID_HANDLE, e);
    CHECK_ERR(sy_node_set_camera(s, n, (sy_camera){99}, &e), SY_ERR_INVALID_HANDLE, e);
    CHECK_OK(sy_node_set_mesh(s, n, (sy_mesh){0}, &e), e); /* {0} = none */

    /* meshes */
    sy_mesh m;
    CHECK_OK(sy_mesh_create(s, "m", &m, &e), e);
    const float pos[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    const uint32_t idx_ok[6] = {0, 1, 2, 0, 2, 3}, idx_bad[6] = {0, 1, 2, 0, 2, 4};
    sy_blob *bpos = sy_test_blob(pos, sizeof pos), *bpos3 = sy_test_blob(pos, 3 * 12), *bodd = sy_test_blob(pos, 13);
    sy_blob *bidx = sy_test_blob(idx_ok, sizeof idx_ok), *bidx_bad = sy_test_blob(idx_bad, sizeof idx_bad);
    sy_blob *bidx_part = sy_test_blob(idx_ok, 5 * 4), *bnorm3 = sy_test_blob(pos, 3 * 12), *bnorm4 = sy_test_blob(pos, 4 * 12);
    float nanpos[3][3] = {{0, 0, 0}, {1, 0, 0}, {0, NAN, 0}};
    sy_blob *bnan = sy_test_blob(nanpos, sizeof nanpos);
    sy_primitive p = {.positions = bpos, .indices = bidx};
    CHECK_OK(sy_mesh_set_primitives(s, m, &p, 1, &e), e);
    p.indices = bidx_bad; /* index 4 with 4 vertices */
    CHECK_ERR(sy_mesh_set_primitives(s, m, &p, 1, &e), SY_ERR_INVALID_ARGUMENT, e);
    CHECK_MSG(strstr(e.message, "past the vertex count") != NULL, "%s", e.message);
    p.indices = bidx_part; /* 5 indices */
    CHECK_ERR(sy_mesh_set_primitives(s, m, &p, 1, &e), SY_ERR_INVALID_ARGUMENT, e);
    p.indices = bidx;
    p.normals = bnorm3; /* 3 normals for 4 vertices */
    CHECK_ERR(sy_mesh_set_primitives(s, m, &p, 1, &e), SY_ERR_INVALID_ARGUMENT, e);
    p.normals = bnorm4;
    CHECK_OK(sy_mesh_set_primitives(s, m, &p, 1, &e), e);
    p.tangents = bnorm4; /* 48 bytes = 3 tangents, not 4 */
    CHECK_ERR(sy_mesh_set_primitives(s, m, &p, 1, &e), SY_ERR_INVALID_ARGUMENT, e);
    p.tangents = NULL;
    p.texcoords0 = bnorm4; /* 48 bytes = 6 texcoords */
    CHECK_ERR(sy_mesh_set_primitives(s, m, &p, 1, &e), SY_ERR_INVALID_ARGUMENT, e);
    p.texcoords0 = NULL;
    p.colors = bnorm3;
    CHECK_ERR(sy_mesh_set_primitives(s, m, &p, 1, &e), SY_ERR_INVALID_ARGUMENT, e);
    p.colors = NULL;
    p.positions = bodd; /* 13 bytes */
    CHECK_ERR(sy_mesh_set_primitives(s, m, &p, 1, &e), SY_ERR_INVALID_ARGUMENT, e);
    p.positions = NULL;
    CHECK_ERR(sy_mesh_set_primitives(s, m, &p, 1, &e), SY_ERR_INVALID_ARGUMENT, e);
    sy_primitive nonidx = {.positions = bpos}; /* 4 vertices, no indices: not whole triangles */
    CHECK_ERR(sy_mesh_set_primitives(s, m, &nonidx, 1, &e), SY_ERR_INVALID_ARGUMENT, e);
    nonidx.positions = bnan;
    CHECK_ERR(sy_mesh_set_primitives(s, m, &nonidx, 1, &e), SY_ERR_INVALID_ARGUMENT, e);
    nonidx.positions = bpos3;
    nonidx.material.id = 777;
    CHECK_ERR(sy_mesh_set_primitives(s, m, &nonidx, 1, &e), SY_ERR_INVALID_HANDLE, e);
    nonidx.material.id = 0;
    /* the second primitive is bad: the whole set is refused, the mesh keeps its old primitives */
    sy_primitive two[2] = {nonidx, {.positions = bpos, .indices = bidx_bad}};
    CHECK_ERR(sy_mesh_set_primitives(s, m, two, 2, &e), SY_ERR_INVALID_ARGUMENT, e);
    CHECK(sy_mesh_get(s, m)->primitives.count == 1);
    CHECK(sy_mesh_get(s, m)->primitives.items[0].normals == bnorm4);
    CHECK_ERR(sy_mesh_set_primitives(s, m, NULL, 2, &e), SY_ERR_INVALID_ARGUMENT, e);
    two[1].indices = bidx;
    CHECK_OK(sy_mesh_set_primitives(s, m, two, 2, &e), e);
    CHECK(sy_primitive_vertex_count(&sy_mesh_get(s, m)->primitives.items[1]) == 4);
    CHECK(sy_primitive_triangle_count(&sy_mesh_get(s, m)->primitives.items[1]) == 2);
    CHECK(sy_primitive_triangle_count(&sy_mesh_get(s, m)->primitives.items[0]) == 1);

    /* textures */
    sy_texture tex;
    CHECK_OK(sy_texture_create(s, "t", &tex, &e), e);
    sy_image_info info = {2, 2, 4, SY_PIXEL_U8_SRGB};
    uint8_t px[16] = {0};
    sy_blob *bpx = sy_test_blob(px, 16), *bpx15 = sy_test_blob(px, 15);
    CHECK_OK(sy_texture_set_image(s, tex, &info, bpx, &e), e);
    CHECK_ERR(sy_texture_set_image(s, tex, &info, bpx15, &e), SY_ERR_INVALID_ARGUMENT, e);
    CHECK_ERR(sy_texture_set_image(s, tex, &info, NULL, &e), SY_ERR_INVALID_ARGUMENT, e);
    info.format = SY_PIXEL_F32; /* needs 64 bytes */
    CHECK_ERR(sy_texture_set_image(s, tex, &info, bpx, &e), SY_ERR_INVALID_ARGUMENT, e);
    info.format = SY_PIXEL_U8_LINEAR;
    info.channels = 5;
    CHECK_ERR(sy_texture_set_image(s, tex, &info, bpx, &e), SY_ERR_INVALID_ARGUMENT, e);
    info.channels = 4;
    info.width = 0;
    CHECK_ERR(sy_texture_set_image(s, tex, &info, bpx, &e), SY_ERR_INVALID_ARGUMENT, e);
    sy_sampler smp = {SY_WRAP_MIRROR, 3, 0, 0};
    CHECK_ERR(sy_texture_set_sampler(s, tex, &smp, &e), SY_ERR_INVALID_ARGUMENT, e);
    smp.wrap_t = SY_WRAP_CLAMP;
    CHECK_OK(sy_texture_set_sampler(s, tex, &smp, &e), e);

    /* materials, lights, cameras, backgrounds */
    sy_material mat;
    CHECK_OK(sy_material_create(s, "mat", &mat, &e), e);
    sy_material_data md = *sy_material_get(s, mat);
    md.roughness = -0.5f;
    CHECK_ERR(sy_material_set(s, mat, &md, &e), SY_ERR_INVALID_ARGUMENT, e);
    md.roughness = NAN;
    CHECK_ERR(sy_material_set(s, mat, &md, &e), SY_ERR_INVALID_ARGUMENT, e);
    md.roughness = 0.5f;
    md.alpha_mode = 3;
    CHECK_ERR(sy_material_set(s, mat, &md, &e), SY_ERR_INVALID_ARGUMENT, e);
    md.alpha_mode = SY_ALPHA_MASK;
    md.normal_texture.texture.id = 4242;
    CHECK_ERR(sy_material_set(s, mat, &md, &e), SY_ERR_INVALID_HANDLE, e);
    md.normal_texture.texture = tex;
    md.normal_texture.texcoord = 2;
    CHECK_ERR(sy_material_set(s, mat, &md, &e), SY_ERR_INVALID_ARGUMENT, e);
    md.normal_texture.texcoord = 1;
    md.ior = 0.5f;
    CHECK_ERR(sy_material_set(s, mat, &md, &e), SY_ERR_INVALID_ARGUMENT, e);
    /* nothing of the refused sets reached the material (all fields validated first) */
    CHECK(sy_material_get(s, mat)->roughness == 1.0f && sy_material_get(s, mat)->alpha_mode == SY_ALPHA_OPAQUE);
    md.ior = 1.33f;
    CHECK_OK(sy_material_set(s, mat, &md, &e), e);
    CHECK(sy_material_get(s, mat)->normal_texture.texture.id == tex.id);
    CHECK(sy_material_get(s, (sy_material){0})->roughness == 1.0f); /* {0}: defaults */

    sy_light l;
    sy_camera cam;
    CHECK_OK(sy_light_create(s, "l", &l, &e), e);
    CHECK_OK(sy_camera_create(s, "c", &cam, &e), e);
    sy_light_data ld = *sy_light_get(s, l);
    ld.intensity = -1;
    CHECK_ERR(sy_light_set(s, l, &ld, &e), SY_ERR_INVALID_ARGUMENT, e);
    ld.intensity = 5;
    ld.type = 9;
    CHECK_ERR(sy_light_set(s, l, &ld, &e), SY_ERR_INVALID_ARGUMENT, e);
    ld.type = SY_LIGHT_SPOT;
    CHECK_OK(sy_light_set(s, l, &ld, &e), e);
    sy_camera_data cd = *sy_camera_get(s, cam);
    cd.yfov = 0;
    CHECK_ERR(sy_camera_set(s, cam, &cd, &e), SY_ERR_INVALID_ARGUMENT, e);
    cd.yfov = 1;
    cd.znear = 0;
    CHECK_ERR(sy_camera_set(s, cam, &cd, &e), SY_ERR_INVALID_ARGUMENT, e);
    cd.znear = 0.1f;
    CHECK_OK(sy_camera_set(s, cam, &cd, &e), e);
    sy_background bg;
    CHECK_OK(sy_background_create(s, "bg", &bg, &e), e);
    sy_background_data bd = *sy_background_get(s, bg);
    bd.color[2] = INFINITY;
    CHECK_ERR(sy_background_set(s, bg, &bd, &e), SY_ERR_INVALID_ARGUMENT, e);
    bd.color[2] = 0.5f;
    bd.environment.id = 31337;
    CHECK_ERR(sy_background_set(s, bg, &bd, &e), SY_ERR_INVALID_HANDLE, e);
    bd.environment = tex;
    CHECK_OK(sy_background_set(s, bg, &bd, &e), e);

    /* attachments */
    sy_attachment at = {.key = "", .kind = SY_ATTACH_INT};
    CHECK_ERR(sy_object_set_attachment(s, SY_TYPE_NODE, n.id, &at, &e), SY_ERR_INVALID_ARGUMENT, e);
    at.key = "k";
    at.kind = 0;
    CHECK_ERR(sy_object_set_attachment(s, SY_TYPE_NODE, n.id, &at, &e), SY_ERR_INVALID_ARGUMENT, e);
    at.kind = SY_ATTACH_STRING;
    at.value.s = NULL;
    CHECK_ERR(sy_object_set_attachment(s, SY_TYPE_NODE, n.id, &at, &e), SY_ERR_INVALID_ARGUMENT, e);

    sy_blob *all[] = {bpos, bpos3, bodd, bidx, bidx_bad, bidx_part, bnorm3, bnorm4, bnan, bpx, bpx15};
    for (size_t i = 0; i < sizeof all / sizeof all[0]; ++i) sy_blob_release(all[i]);
    return 0;
}

/* ------------------------------------------------------------------ children: cycles, duplicates, stale */
SY_SCENE_TEST(test_children_validation)
{
    sy_node a, b, c, d, x;
    CHECK(create_nodes(s, 5, (const char *const[]){"a", "b", "c", "d", "x"}, (sy_node *const[]){&a, &b, &c, &d, &x}) == 0);
    CHECK_OK(sy_node_set_children(s, a, &b, 1, &e), e);
    CHECK_OK(sy_node_add_child(s, b, c, &e), e); /* a -> b -> c */
    CHECK(sy_node_parent_count(s, c) == 1 && sy_node_parent(s, c, 0).id == b.id);
    CHECK(sy_node_parent_count(s, a) == 0);

    /* a node under its own descendant */
    CHECK_ERR(sy_node_set_children(s, c, &a, 1, &e), SY_ERR_INVALID_ARGUMENT, e);
    CHECK_ERR(sy_node_add_child(s, c, b, &e), SY_ERR_INVALID_ARGUMENT, e);
    CHECK_ERR(sy_node_add_child(s, b, a, &e), SY_ERR_INVALID_ARGUMENT, e);
    CHECK_ERR(sy_node_add_child(s, a, a, &e), SY_ERR_INVALID_ARGUMENT, e);
    /* duplicates */
    sy_node dup[3] = {d, x, d};
    CHECK_ERR(sy_node_set_children(s, a, dup, 3, &e), SY_ERR_INVALID_ARGUMENT, e);
    CHECK_ERR(sy_node_add_child(s, a, b, &e), SY_ERR_INVALID_ARGUMENT, e);
    /* stale and zero children */
    sy_node gone;
    CHECK_OK(sy_node_create(s, "gone", &gone, &e), e);
    CHECK_OK(sy_object_destroy(s, SY_TYPE_NODE, gone.id, &e), e);
    sy_node stale[2] = {d, gone};
    CHECK_ERR(sy_node_set_children(s, a, stale, 2, &e), SY_ERR_INVALID_HANDLE, e);
    sy_node zero[2] = {d, {0}};
    CHECK_ERR(sy_node_set_children(s, a, zero, 2, &e), SY_ERR_INVALID_HANDLE, e);
    /* a raw child blob that is not whole ids */
    uint8_t three[3] = {1, 2, 3};
    sy_blob *b3 = sy_test_blob(three, 3);
    CHECK_ERR(sy_object_set_field(s, SY_TYPE_NODE, a.id, SY_NODE_CHILDREN, &b3, &e), SY_ERR_INVALID_ARGUMENT, e);
    sy_blob_release(b3);
    /* nothing of that changed the graph */
    uint32_t nc;
    const uint32_t *ch = sy_node_children(sy_node_get(s, a), &nc);
    CHECK(nc == 1 && ch[0] == b.id);
    CHECK(sy_node_parent_count(s, d) == 0 && sy_node_parent_count(s, x) == 0);

    /* a DAG is fine: d under both a and c, and a sibling order change is fine */
    CHECK_OK(sy_node_add_child(s, a, d, &e), e);
    CHECK_OK(sy_node_add_child(s, c, d, &e), e);
    CHECK(sy_node_parent_count(s, d) == 2 && sy_node_parent(s, d, 0).id == a.id && sy_node_parent(s, d, 1).id == c.id);
    sy_node order[2] = {d, b};
    CHECK_OK(sy_node_set_children(s, a, order, 2, &e), e);
    CHECK(sy_node_parent_count(s, d) == 2 && sy_node_parent_count(s, b) == 1);
    /* moving b under x: removing it from a and adding it to x */
    CHECK_OK(sy_node_set_children(s, a, &d, 1, &e), e);
    CHECK(sy_node_parent_count(s, b) == 0);
    CHECK_OK(sy_node_add_child(s, x, b, &e), e);
    CHECK(sy_node_parent_count(s, b) == 1 && sy_node_parent(s, b, 0).id == x.id);
    /* now c -> a would be legal (a is no longer above c) */
    CHECK_OK(sy_node_add_child(s, c, a, &e), e);
    /* ... and then x under d would close x->b->c->a->d->x */
    CHECK_ERR(sy_node_add_child(s, d, x, &e), SY_ERR_INVALID_ARGUMENT, e);

    /* after a child is destroyed, its parent keeps the stale id (readers skip it), and adding
     * another child still works */
    CHECK_OK(sy_object_destroy(s, SY_TYPE_NODE, d.id, &e), e);
    ch = sy_node_children(sy_node_get(s, a), &nc);
    CHECK(nc == 1 && ch[0] == d.id);
    sy_node y;
    CHECK_OK(sy_node_create(s, "y", &y, &e), e);
    CHECK_OK(sy_node_add_child(s, a, y, &e), e);
    CHECK(sy_node_parent_count(s, y) == 1);
    CHECK_OK(sy_scene_commit(s, NULL, &e), e);
    return 0;
}

/* ------------------------------------------------------------------ world matrices */
SY_SCENE_TEST(test_world_chain)
{
    sy_node a, b, c;
    CHECK(create_nodes(s, 3, (const char *const[]){"a", "b", "c"}, (sy_node *const[]){&a, &b, &c}) == 0);
    const float h = (float)sqrt(0.5);
    const float ta[3] = {10, 0, 0}, tb[3] = {0, 5, 0}, qb[4] = {0, 0, h, h}, sc[3] = {2, 2, 2};
    CHECK_OK(sy_node_set_trs(s, a, ta, Q0, S1, &e), e);
    CHECK_OK(sy_node_set_trs(s, b, tb, qb, S1, &e), e); /* 90 deg about z */
    CHECK_OK(sy_node_set_trs(s, c, T0, Q0, sc, &e), e);
    CHECK_OK(sy_node_add_child(s, a, b, &e), e);
    CHECK_OK(sy_node_add_child(s, b, c, &e), e);
    /* before the first commit, world matrices are not computed yet (identity) */
    sy_mat4 w;
    CHECK_OK(sy_node_world_matrix(s, c, &w, &e), e);
    sy_mat4 id = sy_mat4_identity();
    CHECK(sy_mat4_equal(&w, &id));
    uint64_t frame = 0;
    CHECK_OK(sy_scene_commit(s, &frame, &e), e);
    CHECK(frame == 1 && sy_scene_frame(s) == 1);
    CHECK(sy_scene_last_commit_world_updates(s) == 3);
    const sy_mat4 *ma = &sy_node_get(s, a)->transform.matrix, *mb = &sy_node_get(s, b)->transform.matrix,
                  *mc = &sy_node_get(s, c)->transform.matrix;
    sy_mat4 ab = sy_mat4_mul(ma, mb), abc = sy_mat4_mul(&ab, mc);
    CHECK_OK(sy_node_world_matrix(s, a, &w, &e), e);
    CHECK(sy_mat4_equal(&w, ma));
    CHECK_OK(sy_node_world_matrix(s, b, &w, &e), e);
    CHECK(sy_mat4_equal(&w, &ab));
    CHECK_OK(sy_node_world_matrix(s, c, &w, &e), e);
    CHECK(sy_mat4_equal(&w, &abc));
    /* and by hand: c's local (1,0,0) -> scaled (2,0,0) -> rotated (0,2,0) -> +tb (0,7,0) -> +ta (10,7,0) */
    float p[3] = {1, 0, 0}, o[3];
    sy_mat4_transform_point(&w, p, o);
    CHECK_NEAR(o[0], 10, 1e-5);
    CHECK_NEAR(o[1], 7, 1e-5);
    CHECK_NEAR(o[2], 0, 1e-5);
    /* matrix mode */
    sy_mat4 mm = sy_mat4_identity();
    mm.m[14] = -3;
    CHECK_OK(sy_node_set_matrix(s, a, &mm, &e), e);
    CHECK_OK(sy_scene_commit(s, NULL, &e), e);
    CHECK_OK(sy_node_world_matrix(s, c, &w, &e), e);
    sy_mat4_transform_point(&w, p, o);
    CHECK_NEAR(o[0], 0, 1e-5);
    CHECK_NEAR(o[1], 7, 1e-5);
    CHECK_NEAR(o[2], -3, 1e-5);
    /* detaching c makes it a root: its world is its own matrix */
    CHECK_OK(sy_node_set_children(s, b, NULL, 0, &e), e);
    CHECK_OK(sy_scene_commit(s, NULL, &e), e);
    CHECK_OK(sy_node_world_matrix(s, c, &w, &e), e);
    CHECK(sy_mat4_equal(&w, mc));
    CHECK(sy_scene_last_commit_world_updates(s) == 1);
    return 0;
}

/* Dirty subtrees only: a tree
 *        r
 *      /   \
 *     m1    m2
 *    / \     \
 *   l1  l2    k
 *   |
 *   ll
 */
SY_SCENE_TEST(test_world_incremental)
{
    sy_node r, m1, m2, l1, l2, k, ll;
    sy_node *all[] = {&r, &m1, &m2, &l1, &l2, &k, &ll};
    for (int i = 0; i < 7; ++i) {
        CHECK_OK(sy_node_create(s, NULL, all[i], &e), e);
        const float t[3] = {(float)i, (float)(i * i), 1.0f};
        CHECK_OK(sy_node_set_trs(s, *all[i], t, Q0, S1, &e), e);
    }
    sy_node rc[2] = {m1, m2}, m1c[2] = {l1, l2};
    CHECK_OK(sy_node_set_children(s, r, rc, 2, &e), e);
    CHECK_OK(sy_node_set_children(s, m1, m1c, 2, &e), e);
    CHECK_OK(sy_node_add_child(s, m2, k, &e), e);
    CHECK_OK(sy_node_add_child(s, l1, ll, &e), e);
    CHECK_OK(sy_scene_commit(s, NULL, &e), e);
    CHECK(sy_scene_last_commit_world_updates(s) == 7);
    CHECK_OK(sy_scene_commit(s, NULL, &e), e);
    CHECK(sy_scene_last_commit_world_updates(s) == 0);
    sy_mat4 wk_before;
    CHECK_OK(sy_node_world_matrix(s, k, &wk_before, &e), e);

    /* a middle node: its subtree only (m1, l1, l2, ll) */
    const float h = (float)sqrt(0.5), q[4] = {h, 0, 0, h}, t[3] = {0, 0, 4}, sc[3] = {1, 3, 1};
    CHECK_OK(sy_node_set_trs(s, m1, t, q, sc, &e), e);
    CHECK_OK(sy_scene_commit(s, NULL, &e), e);
    CHECK(sy_scene_last_commit_world_updates(s) == 4);
    sy_mat4 w, wk;
    CHECK_OK(sy_node_world_matrix(s, k, &wk, &e), e);
    CHECK(sy_mat4_equal(&wk, &wk_before));
    const sy_mat4 *M[7];
    for (int i = 0; i < 7; ++i) M[i] = &sy_node_get(s, *all[i])->transform.matrix;
    sy_mat4 x = sy_mat4_mul(M[0], M[1]);
    x = sy_mat4_mul(&x, M[3]);
    x = sy_mat4_mul(&x, M[6]);
    CHECK_OK(sy_node_world_matrix(s, ll, &w, &e), e);
    CHECK(sy_mat4_equal(&w, &x));

    /* a leaf: one update */
    CHECK_OK(sy_node_set_trs(s, ll, t, Q0, S1, &e), e);
    CHECK_OK(sy_scene_commit(s, NULL, &e), e);
    CHECK(sy_scene_last_commit_world_updates(s) == 1);
    /* two disjoint subtrees: l2 (1) and m2 (m2, k) */
    CHECK_OK(sy_node_set_trs(s, l2, t, Q0, sc, &e), e);
    CHECK_OK(sy_node_set_trs(s, m2, t, q, S1, &e), e);
    CHECK_OK(sy_scene_commit(s, NULL, &e), e);
    CHECK(sy_scene_last_commit_world_updates(s) == 3);
    /* the root: everything */
    CHECK_OK(sy_node_set_trs(s, r, t, q, sc, &e), e);
    CHECK_OK(sy_scene_commit(s, NULL, &e), e);
    CHECK(sy_scene_last_commit_world_updates(s) == 7);
    /* a node and its own ancestor in the same frame (child first): still correct */
    const float t2[3] = {-1, -2, -3};
    CHECK_OK(sy_node_set_trs(s, ll, t2, q, S1, &e), e);
    CHECK_OK(sy_node_set_trs(s, m1, t2, Q0, sc, &e), e);
    CHECK_OK(sy_scene_commit(s, NULL, &e), e);
    CHECK(sy_scene_last_commit_world_updates(s) <= 5);
    for (int i = 0; i < 7; ++i) M[i] = &sy_node_get(s, *all[i])->transform.matrix;
    x = sy_mat4_mul(M[0], M[1]);
    x = sy_mat4_mul(&x, M[3]);
    x = sy_mat4_mul(&x, M[6]);
    CHECK_OK(sy_node_world_matrix(s, ll, &w, &e), e);
    CHECK(sy_mat4_equal(&w, &x));
    /* re-parenting a subtree updates that subtree only: l1 (with ll) moves under k */
    sy_node only_l2 = l2;
    CHECK_OK(sy_node_set_children(s, m1, &only_l2, 1, &e), e);
    CHECK_OK(sy_node_add_child(s, k, l1, &e), e);
    CHECK_OK(sy_scene_commit(s, NULL, &e), e);
    CHECK(sy_scene_last_commit_world_updates(s) == 2);
    x = sy_mat4_mul(M[0], M[2]);
    x = sy_mat4_mul(&x, M[5]);
    x = sy_mat4_mul(&x, M[3]);
    x = sy_mat4_mul(&x, M[6]);
    CHECK_OK(sy_node_world_matrix(s, ll, &w, &e), e);
    CHECK(sy_mat4_equal(&w, &x));
    /* destroying m2 makes k a root: k's subtree (k, l1, ll) is recomputed */
    CHECK_OK(sy_object_destroy(s, SY_TYPE_NODE, m2.id, &e), e);
    CHECK_OK(sy_scene_commit(s, NULL, &e), e);
    CHECK(sy_scene_last_commit_world_updates(s) == 3);
    CHECK(sy_node_parent_count(s, k) == 0);
    CHECK_OK(sy_node_world_matrix(s, k, &w, &e), e);
    CHECK(sy_mat4_equal(&w, &sy_node_get(s, k)->transform.matrix));
    return 0;
}

/* ------------------------------------------------------------------ bounds */
static int make_tri_mesh(sy_scene *s, sy_mesh *m, const float pos[9])
{
    sy_error e = {0};
    CHECK_OK(sy_mesh_create(s, "tri", m, &e), e);
    sy_blob *b = sy_test_blob(pos, 36);
    sy_primitive p = {.positions = b};
    CHECK_OK(sy_mesh_set_primitives(s, *m, &p, 1, &e), e);
    sy_blob_release(b);
    return 0;
}

static int bounds_is(const sy_bounds *b, float x0, float y0, float z0, float x1, float y1, float z1, double eps)
{
    CHECK_NEAR(b->min[0], x0, eps);
    CHECK_NEAR(b->min[1], y0, eps);
    CHECK_NEAR(b->min[2], z0, eps);
    CHECK_NEAR(b->max[0], x1, eps);
    CHECK_NEAR(b->max[1], y1, eps);
    CHECK_NEAR(b->max[2], z1, eps);
    return 0;
}

SY_SCENE_TEST(test_bounds)
{
    const float tri[9] = {0, 0, 0, 1, 0, 0, 0, 2, 0};
    sy_mesh m;
    CHECK(make_tri_mesh(s, &m, tri) == 0);
    sy_bounds b;
    CHECK_OK(sy_mesh_bounds(s, m, &b, &e), e);
    CHECK(bounds_is(&b, 0, 0, 0, 1, 2, 0, 0) == 0);

    sy_node root, n;
    CHECK_OK(sy_node_create(s, "root", &root, &e), e);
    CHECK_OK(sy_node_create(s, "n", &n, &e), e);
    const float tr[3] = {0, 0, 5}, tn[3] = {10, 0, 0}, sn[3] = {2, 2, 2};
    CHECK_OK(sy_node_set_trs(s, root, tr, Q0, S1, &e), e);
    CHECK_OK(sy_node_set_trs(s, n, tn, Q0, sn, &e), e);
    CHECK_OK(sy_node_set_mesh(s, n, m, &e), e);
    CHECK_OK(sy_node_add_child(s, root, n, &e), e);
    CHECK_OK(sy_scene_commit(s, NULL, &e), e);
    CHECK_OK(sy_node_world_bounds(s, n, &b, &e), e);
    CHECK(bounds_is(&b, 10, 0, 5, 12, 4, 5, 0) == 0);
    CHECK_OK(sy_node_world_bounds(s, root, &b, &e), e);
    CHECK(bounds_is(&b, 10, 0, 5, 12, 4, 5, 0) == 0);
    b = sy_scene_world_bounds(s);
    CHECK(bounds_is(&b, 10, 0, 5, 12, 4, 5, 0) == 0);

    /* moving the parent moves the bounds */
    const float tr2[3] = {0, -1, 0};
    CHECK_OK(sy_node_set_trs(s, root, tr2, Q0, S1, &e), e);
    CHECK_OK(sy_scene_commit(s, NULL, &e), e);
    CHECK_OK(sy_node_world_bounds(s, n, &b, &e), e);
    CHECK(bounds_is(&b, 10, -1, 0, 12, 3, 0, 0) == 0);
    /* rotating the child 90 degrees about z: (x, y) -> (-y, x) */
    const float h = (float)sqrt(0.5), qz[4] = {0, 0, h, h};
    CHECK_OK(sy_node_set_trs(s, n, tn, qz, sn, &e), e);
    CHECK_OK(sy_scene_commit(s, NULL, &e), e);
    CHECK_OK(sy_node_world_bounds(s, root, &b, &e), e);
    CHECK(bounds_is(&b, 6, -1, 0, 10, 1, 0, 1e-5) == 0);

    /* changing the mesh data updates every user's bounds */
    const float tri2[9] = {0, 0, -1, 1, 1, 1, 0, 0, 0};
    sy_blob *b2 = sy_test_blob(tri2, 36);
    sy_primitive p = {.positions = b2};
    CHECK_OK(sy_mesh_set_primitives(s, m, &p, 1, &e), e);
    sy_blob_release(b2);
    CHECK_OK(sy_scene_commit(s, NULL, &e), e);
    CHECK_OK(sy_node_world_bounds(s, root, &b, &e), e);
    CHECK(bounds_is(&b, 8, -1, -2, 10, 1, 2, 1e-5) == 0);

    /* a second mesh on a sibling extends the root's bounds; then removing the first node's mesh */
    sy_node sib;
    sy_mesh m2;
    const float tri3[9] = {-5, 0, 0, -4, 0, 0, -5, 1, 0};
    CHECK(make_tri_mesh(s, &m2, tri3) == 0);
    CHECK_OK(sy_node_create(s, "sib", &sib, &e), e);
    CHECK_OK(sy_node_set_mesh(s, sib, m2, &e), e);
    CHECK_OK(sy_node_add_child(s, root, sib, &e), e);
    CHECK_OK(sy_scene_commit(s, NULL, &e), e);
    CHECK_OK(sy_node_world_bounds(s, root, &b, &e), e);
    CHECK(bounds_is(&b, -5, -1, -2, 10, 1, 2, 1e-5) == 0);
    CHECK_OK(sy_node_set_mesh(s, n, (sy_mesh){0}, &e), e);
    CHECK_OK(sy_scene_commit(s, NULL, &e), e);
    CHECK_OK(sy_node_world_bounds(s, root, &b, &e), e);
    CHECK(bounds_is(&b, -5, -1, 0, -4, 0, 0, 1e-6) == 0);
    CHECK_OK(sy_node_world_bounds(s, n, &b, &e), e);
    CHECK(sy_bounds_is_empty(&b));
    /* destroying the mesh of sib (stale reference: absent) empties the root */
    CHECK_OK(sy_object_destroy(s, SY_TYPE_MESH, m2.id, &e), e);
    CHECK_OK(sy_scene_commit(s, NULL, &e), e);
    CHECK_OK(sy_node_world_bounds(s, root, &b, &e), e);
    CHECK(sy_bounds_is_empty(&b));
    CHECK(sy_node_get(s, sib)->mesh.id == m2.id); /* the reference is kept */
    b = sy_scene_world_bounds(s);
    CHECK(sy_bounds_is_empty(&b));
    CHECK_ERR(sy_mesh_bounds(s, m2, &b, &e), SY_ERR_INVALID_HANDLE, e);
    return 0;
}

SY_SCENE_TEST(test_dag)
{
    sy_mesh m;
    const float tri[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    CHECK(make_tri_mesh(s, &m, tri) == 0);
    sy_node top, p1, p2, shared;
    CHECK(create_nodes(s, 4, (const char *const[]){"top", "p1", "p2", "shared"}, (sy_node *const[]){&top, &p1, &p2, &shared}) == 0);
    const float t1[3] = {10, 0, 0}, t2[3] = {-10, 0, 0};
    CHECK_OK(sy_node_set_trs(s, p1, t1, Q0, S1, &e), e);
    CHECK_OK(sy_node_set_trs(s, p2, t2, Q0, S1, &e), e);
    CHECK_OK(sy_node_set_mesh(s, shared, m, &e), e);
    sy_node kids[2] = {p1, p2};
    CHECK_OK(sy_node_set_children(s, top, kids, 2, &e), e);
    CHECK_OK(sy_node_add_child(s, p1, shared, &e), e);
    CHECK_OK(sy_node_add_child(s, p2, shared, &e), e);
    CHECK_OK(sy_scene_commit(s, NULL, &e), e);
    CHECK(sy_node_parent_count(s, shared) == 2);
    CHECK(sy_node_parent(s, shared, 0).id == p1.id && sy_node_parent(s, shared, 1).id == p2.id);
    CHECK(sy_node_parent(s, shared, 2).id == 0);
    sy_bounds b;
    CHECK_OK(sy_node_world_bounds(s, p1, &b, &e), e);
    CHECK(bounds_is(&b, 10, 0, 0, 11, 1, 0, 0) == 0);
    CHECK_OK(sy_node_world_bounds(s, p2, &b, &e), e);
    CHECK(bounds_is(&b, -10, 0, 0, -9, 1, 0, 0) == 0);
    CHECK_OK(sy_node_world_bounds(s, top, &b, &e), e); /* both instances */
    CHECK(bounds_is(&b, -10, 0, 0, 11, 1, 0, 0) == 0);
    b = sy_scene_world_bounds(s);
    CHECK(bounds_is(&b, -10, 0, 0, 11, 1, 0, 0) == 0);
    /* the primary (first) parent places the shared node */
    sy_mat4 w;
    CHECK_OK(sy_node_world_matrix(s, shared, &w, &e), e);
    CHECK(w.m[12] == 10);
    /* moving the shared node moves both instances */
    const float ts[3] = {0, 5, 0};
    CHECK_OK(sy_node_set_trs(s, shared, ts, Q0, S1, &e), e);
    CHECK_OK(sy_scene_commit(s, NULL, &e), e);
    CHECK_OK(sy_node_world_bounds(s, top, &b, &e), e);
    CHECK(bounds_is(&b, -10, 5, 0, 11, 6, 0, 0) == 0);
    /* destroying the primary parent: the other one takes over */
    CHECK_OK(sy_object_destroy(s, SY_TYPE_NODE, p1.id, &e), e);
    CHECK_OK(sy_scene_commit(s, NULL, &e), e);
    CHECK(sy_node_parent_count(s, shared) == 1 && sy_node_parent(s, shared, 0).id == p2.id);
    CHECK_OK(sy_node_world_matrix(s, shared, &w, &e), e);
    CHECK(w.m[12] == -10 && w.m[13] == 5);
    CHECK_OK(sy_node_world_bounds(s, top, &b, &e), e);
    CHECK(bounds_is(&b, -10, 5, 0, -9, 6, 0, 0) == 0);
    return 0;
}

/* The world-matrix walk (sy_scene_walk): every path, depth first in child order, placements by
 * sy_placement_child, invisible subtrees skipped on request, stale children reported. */
typedef struct walk_log {
    uint32_t n, ids[16], depth[16];
    sy_placement place[16];
    bool stale[16];
} walk_log;

static sy_result walk_record(void *user, const sy_walk_step *st, sy_error *err)
{
    walk_log *w = user;
    if (w->n == 16) return sy_error_set(err, SY_ERR_LIMIT, "walk_record: too many");
    w->ids[w->n] = st->node.id, w->depth[w->n] = st->depth, w->stale[w->n] = st->data == NULL;
    if (st->data) w->place[w->n] = st->place;
    w->n++;
    return SY_OK;
}

SY_SCENE_TEST(test_walk)
{
    sy_node top, p1, p2, shared, gone;
    CHECK(create_nodes(s, 5, (const char *const[]){"top", "p1", "p2", "shared", "gone"}, (sy_node *const[]){&top, &p1, &p2, &shared, &gone}) == 0);
    const float tt[3] = {0, 0, 1}, t1[3] = {10, 0, 0}, t2[3] = {-10, 0, 0}, ts[3] = {0, 5, 0}, s2[3] = {2, 2, 2};
    CHECK_OK(sy_node_set_trs(s, top, tt, Q0, S1, &e), e);
    CHECK_OK(sy_node_set_trs(s, p1, t1, Q0, S1, &e), e);
    CHECK_OK(sy_node_set_trs(s, p2, t2, Q0, s2, &e), e);
    CHECK_OK(sy_node_set_trs(s, shared, ts, Q0, S1, &e), e);
    sy_node kids[2] = {p1, p2};
    CHECK_OK(sy_node_set_children(s, top, kids, 2, &e), e);
    CHECK_OK(sy_node_add_child(s, p1, shared, &e), e);
    CHECK_OK(sy_node_add_child(s, p2, shared, &e), e);
    CHECK_OK(sy_node_add_child(s, p2, gone, &e), e);
    CHECK_OK(sy_object_destroy(s, SY_TYPE_NODE, gone.id, &e), e); /* p2 keeps the stale id */
    /* no commit: the walk reads the current fields */
    walk_log w = {0};
    CHECK_OK(sy_scene_walk(s, top, NULL, 0, walk_record, &w, &e), e);
    const uint32_t order[6] = {top.id, p1.id, shared.id, p2.id, shared.id, gone.id}, depth[6] = {0, 1, 2, 1, 2, 2};
    CHECK_MSG(w.n == 6, "%u steps", w.n);
    for (uint32_t i = 0; i < 6; ++i) EXPECT_MSG(w.ids[i] == order[i] && w.depth[i] == depth[i], "step %u", i);
    CHECK(w.stale[5] && !w.stale[4]);
    /* shared under p1: (0,5,0) + (10,0,0) + (0,0,1); under p2: 2 x (0,5,0) + (-10,0,0) + (0,0,1) */
    EXPECT(w.place[2].world.m[12] == 10 && w.place[2].world.m[13] == 5 && w.place[2].world.m[14] == 1);
    EXPECT(w.place[4].world.m[12] == -10 && w.place[4].world.m[13] == 10 && w.place[4].world.m[14] == 1);
    EXPECT(w.place[4].world.m[0] == 2 && w.place[4].visible);
    /* the rule itself: a path's start is its own local matrix; a child multiplies in */
    sy_mat4 l = sy_node_get(s, p2)->transform.matrix;
    sy_placement a = sy_placement_child(NULL, &l, SY_NODE_VISIBLE), b = sy_placement_child(&a, &l, 0);
    EXPECT(sy_mat4_equal(&a.world, &l) && a.visible && !b.visible && b.world.m[12] == -30);
    /* invisible p1: its subtree is skipped on request, reported as not visible otherwise */
    CHECK_OK(sy_node_set_flags(s, p1, 0, &e), e);
    memset(&w, 0, sizeof w);
    CHECK_OK(sy_scene_walk(s, top, NULL, SY_WALK_VISIBLE_ONLY, walk_record, &w, &e), e);
    CHECK_MSG(w.n == 4 && w.ids[1] == p2.id, "%u steps", w.n);
    memset(&w, 0, sizeof w);
    CHECK_OK(sy_scene_walk(s, top, NULL, 0, walk_record, &w, &e), e);
    CHECK(w.n == 6 && !w.place[1].visible && !w.place[2].visible && w.place[4].visible);
    /* above: the placement the root hangs under */
    sy_placement up = {.world = sy_mat4_identity(), .visible = false};
    up.world.m[13] = 100;
    memset(&w, 0, sizeof w);
    CHECK_OK(sy_scene_walk(s, p2, &up, 0, walk_record, &w, &e), e);
    CHECK(w.n == 3 && w.place[0].world.m[13] == 100 && !w.place[0].visible);
    memset(&w, 0, sizeof w);
    CHECK_OK(sy_scene_walk(s, p2, &up, SY_WALK_VISIBLE_ONLY, walk_record, &w, &e), e);
    CHECK(w.n == 0);
    /* the callback's error stops the walk; a stale root is a stale step */
    CHECK_OK(sy_node_set_flags(s, p1, SY_NODE_VISIBLE, &e), e);
    sy_node many[16];
    for (int i = 0; i < 16; ++i) CHECK_OK(sy_node_create(s, "k", &many[i], &e), e);
    CHECK_OK(sy_node_set_children(s, p1, many, 16, &e), e);
    memset(&w, 0, sizeof w);
    CHECK_ERR(sy_scene_walk(s, top, NULL, 0, walk_record, &w, &e), SY_ERR_LIMIT, e);
    CHECK(w.n == 16);
    memset(&w, 0, sizeof w);
    CHECK_OK(sy_scene_walk(s, gone, NULL, 0, walk_record, &w, &e), e);
    CHECK(w.n == 1 && w.stale[0]);
    return 0;
}

/* Values every back-end refuses (or misreads) are refused by the core setters, naming the object,
 * the field and the reason (issue 33, item 8). */
SY_SCENE_TEST(test_camera_clip_range)
{
    uint32_t con;
    CHECK_OK(sy_scene_consumer_add(s, &con, &e), e);
    sy_camera cam;
    CHECK_OK(sy_camera_create(s, "c", &cam, &e), e);
    sy_camera_data cd = *sy_camera_get(s, cam);
    /* zfar at or in front of znear: every back-end refuses the render (raster and rt: "clip range") */
    cd.znear = 1.0f, cd.zfar = 0.5f;
    EXPECT_ERR(sy_camera_set(s, cam, &cd, &e), SY_ERR_INVALID_ARGUMENT, e);
    EXPECT_SAYS(e, "zfar");
    cd.zfar = 1.0f;
    EXPECT_ERR(sy_camera_set(s, cam, &cd, &e), SY_ERR_INVALID_ARGUMENT, e);
    EXPECT(sy_camera_get(s, cam)->znear == 0.01f && sy_camera_get(s, cam)->zfar == 0.0f); /* unchanged */
    cd.zfar = 0.0f; /* 0 = infinite: any znear */
    CHECK_OK(sy_camera_set(s, cam, &cd, &e), e);
    cd.zfar = 2.0f;
    CHECK_OK(sy_camera_set(s, cam, &cd, &e), e);
    /* one field at a time: checked against the other as it is */
    float far_in_front = 0.5f, near_behind = 3.0f, ok = 1.5f;
    EXPECT_ERR(sy_object_set_field(s, SY_TYPE_CAMERA, cam.id, SY_CAMERA_ZFAR, &far_in_front, &e), SY_ERR_INVALID_ARGUMENT, e);
    EXPECT_SAYS(e, "camera");
    EXPECT_ERR(sy_object_set_field(s, SY_TYPE_CAMERA, cam.id, SY_CAMERA_ZNEAR, &near_behind, &e), SY_ERR_INVALID_ARGUMENT, e);
    CHECK_OK(sy_object_set_field(s, SY_TYPE_CAMERA, cam.id, SY_CAMERA_ZNEAR, &ok, &e), e);
    /* a whole set moving both planes past each other is checked as a whole, not field by field */
    cd = *sy_camera_get(s, cam);
    cd.znear = 10.0f, cd.zfar = 100.0f;
    CHECK_OK(sy_camera_set(s, cam, &cd, &e), e);
    /* and a replica applies it the same way */
    sy_scene *rep;
    CHECK_OK(sy_scene_create(&rep, &e), e);
    sy_changes *c = commit_pull(s, con);
    CHECK(c != NULL);
    CHECK_OK(sy_scene_apply(rep, c, &e), e);
    sy_changes_release(c);
    cd.znear = 200.0f, cd.zfar = 300.0f; /* the replica sets znear first: 200 is past the old zfar */
    CHECK_OK(sy_camera_set(s, cam, &cd, &e), e);
    c = commit_pull(s, con);
    CHECK(c != NULL);
    CHECK_OK(sy_scene_apply(rep, c, &e), e);
    sy_changes_release(c);
    CHECK(sy_camera_get(rep, cam)->znear == 200.0f && sy_camera_get(rep, cam)->zfar == 300.0f);
    sy_scene_destroy(rep);
    return 0;
}

SY_SCENE_TEST(test_texture_info_validation)
{
    sy_texture tex;
    CHECK_OK(sy_texture_create(s, "t", &tex, &e), e);
    /* an image with a size needs 1..4 channels (every back-end refuses 0) and a known pixel format
     * (format 0 was read as float by the mediators, past the end of the pixels) */
    sy_image_info info = {2, 2, 0, SY_PIXEL_U8_SRGB};
    EXPECT_ERR(sy_object_set_field(s, SY_TYPE_TEXTURE, tex.id, SY_TEXTURE_INFO, &info, &e), SY_ERR_INVALID_ARGUMENT, e);
    EXPECT_SAYS(e, "channels");
    info.channels = 4;
    info.format = 0;
    EXPECT_ERR(sy_object_set_field(s, SY_TYPE_TEXTURE, tex.id, SY_TEXTURE_INFO, &info, &e), SY_ERR_INVALID_ARGUMENT, e);
    EXPECT_SAYS(e, "format");
    info.format = SY_PIXEL_U8_LINEAR;
    CHECK_OK(sy_object_set_field(s, SY_TYPE_TEXTURE, tex.id, SY_TEXTURE_INFO, &info, &e), e);
    /* no image (the default, all zero) stays legal */
    sy_image_info none = {0, 0, 0, 0};
    CHECK_OK(sy_object_set_field(s, SY_TYPE_TEXTURE, tex.id, SY_TEXTURE_INFO, &none, &e), e);
    return 0;
}

/* ------------------------------------------------------------------ attachments */
SY_SCENE_TEST(test_attachments)
{
    long live0 = sy_blob_live_count();
    uint32_t con;
    CHECK_OK(sy_scene_consumer_add(s, &con, &e), e);
    sy_camera cam;
    CHECK_OK(sy_camera_create(s, "cam", &cam, &e), e);
    sy_changes_release(commit_pull(s, con));

    char key[8] = "bbb", val[16] = "volume";
    sy_blob *blob = sy_test_blob("payload", 7);
    sy_attachment a_int = {.key = key, .kind = SY_ATTACH_INT, .value.i = -7};
    sy_attachment a_str = {.key = "aaa", .kind = SY_ATTACH_STRING, .value.s = val};
    sy_attachment a_vec = {.key = "ccc", .kind = SY_ATTACH_VEC4, .value.v = {1, 2, 3, 4}};
    sy_attachment a_blob = {.key = "ddd", .kind = SY_ATTACH_BLOB, .value.blob = blob};
    sy_attachment a_flt = {.key = "a", .kind = SY_ATTACH_FLOAT, .value.f = 0.125};
    CHECK_OK(sy_object_set_attachment(s, SY_TYPE_CAMERA, cam.id, &a_int, &e), e);
    CHECK_OK(sy_object_set_attachment(s, SY_TYPE_CAMERA, cam.id, &a_blob, &e), e);
    CHECK_OK(sy_object_set_attachment(s, SY_TYPE_CAMERA, cam.id, &a_str, &e), e);
    CHECK_OK(sy_object_set_attachment(s, SY_TYPE_CAMERA, cam.id, &a_vec, &e), e);
    CHECK_OK(sy_object_set_attachment(s, SY_TYPE_CAMERA, cam.id, &a_flt, &e), e);
    /* keys and strings are copied */
    strcpy(key, "zzz");
    strcpy(val, "changed");
    sy_blob_release(blob); /* the scene holds its own reference */
    uint32_t n;
    const sy_attachment *at = sy_object_attachments(s, SY_TYPE_CAMERA, cam.id, &n);
    CHECK(n == 5);
    const char *order[5] = {"a", "aaa", "bbb", "ccc", "ddd"};
    for (uint32_t i = 0; i < 5; ++i) CHECK_MSG(strcmp(at[i].key, order[i]) == 0, "attachment %u is '%s'", i, at[i].key);
    CHECK(at[0].kind == SY_ATTACH_FLOAT && at[0].value.f == 0.125);
    CHECK(at[1].kind == SY_ATTACH_STRING && strcmp(at[1].value.s, "volume") == 0);
    CHECK(at[2].kind == SY_ATTACH_INT && at[2].value.i == -7);
    CHECK(at[3].kind == SY_ATTACH_VEC4 && at[3].value.v[3] == 4);
    CHECK(at[4].kind == SY_ATTACH_BLOB && sy_blob_size(at[4].value.blob) == 7 &&
          memcmp(sy_blob_data(at[4].value.blob), "payload", 7) == 0);
    const sy_attachment *f = sy_object_find_attachment(s, SY_TYPE_CAMERA, cam.id, "ccc");
    CHECK(f && f->value.v[1] == 2);
    CHECK(sy_object_find_attachment(s, SY_TYPE_CAMERA, cam.id, "cc") == NULL);

    /* attachment-only change: one entry with only the attachments bit and the full set */
    sy_changes *c = commit_pull(s, con);
    CHECK(c && sy_changes_count(c) == 1);
    const sy_change *en = sy_changes_get(c, 0);
    CHECK(en->type == SY_TYPE_CAMERA && en->id == cam.id && en->flags == 0);
    CHECK(en->mask == SY_BIT(SY_FIELD_ATTACHMENTS));
    CHECK(en->attachment_count == 5 && strcmp(en->attachments[2].key, "bbb") == 0);
    CHECK(en->attachments[4].value.blob != NULL);
    sy_changes_release(c);

    /* same value again: no change */
    strcpy(key, "bbb");
    CHECK_OK(sy_object_set_attachment(s, SY_TYPE_CAMERA, cam.id, &a_int, &e), e);
    CHECK(!sy_scene_has_pending(s));
    /* replace with another kind under the same key */
    sy_attachment a_rep = {.key = "bbb", .kind = SY_ATTACH_STRING, .value.s = "now a string"};
    CHECK_OK(sy_object_set_attachment(s, SY_TYPE_CAMERA, cam.id, &a_rep, &e), e);
    at = sy_object_attachments(s, SY_TYPE_CAMERA, cam.id, &n);
    CHECK(n == 5 && at[2].kind == SY_ATTACH_STRING && strcmp(at[2].value.s, "now a string") == 0);
    /* replacing the first and the last keys */
    sy_attachment a_first = {.key = "a", .kind = SY_ATTACH_INT, .value.i = 1};
    sy_attachment a_last = {.key = "ddd", .kind = SY_ATTACH_INT, .value.i = 2};
    CHECK_OK(sy_object_set_attachment(s, SY_TYPE_CAMERA, cam.id, &a_first, &e), e);
    CHECK_OK(sy_object_set_attachment(s, SY_TYPE_CAMERA, cam.id, &a_last, &e), e);
    at = sy_object_attachments(s, SY_TYPE_CAMERA, cam.id, &n);
    CHECK(n == 5 && at[0].value.i == 1 && at[4].kind == SY_ATTACH_INT && at[4].value.i == 2);
    CHECK(sy_blob_live_count() == live0); /* the replaced blob attachment released its blob */
    /* remove */
    CHECK_OK(sy_object_remove_attachment(s, SY_TYPE_CAMERA, cam.id, "ccc", &e), e);
    CHECK_ERR(sy_object_remove_attachment(s, SY_TYPE_CAMERA, cam.id, "ccc", &e), SY_ERR_NOT_FOUND, e);
    CHECK_OK(sy_object_remove_attachment(s, SY_TYPE_CAMERA, cam.id, "a", &e), e);
    CHECK_OK(sy_object_remove_attachment(s, SY_TYPE_CAMERA, cam.id, "ddd", &e), e);
    at = sy_object_attachments(s, SY_TYPE_CAMERA, cam.id, &n);
    CHECK(n == 2 && strcmp(at[0].key, "aaa") == 0 && strcmp(at[1].key, "bbb") == 0);
    c = commit_pull(s, con);
    CHECK(c && sy_changes_count(c) == 1);
    en = sy_changes_get(c, 0);
    CHECK(en->mask == SY_BIT(SY_FIELD_ATTACHMENTS) && en->attachment_count == 2);
    sy_changes_release(c);
    CHECK_OK(sy_object_remove_attachment(s, SY_TYPE_CAMERA, cam.id, "aaa", &e), e);
    CHECK_OK(sy_object_remove_attachment(s, SY_TYPE_CAMERA, cam.id, "bbb", &e), e);
    CHECK(sy_object_attachments(s, SY_TYPE_CAMERA, cam.id, &n) == NULL || n == 0);
    CHECK(n == 0);
    c = commit_pull(s, con);
    CHECK(c && sy_changes_count(c) == 1 && sy_changes_get(c, 0)->attachment_count == 0 &&
          sy_changes_get(c, 0)->mask == SY_BIT(SY_FIELD_ATTACHMENTS));
    sy_changes_release(c);
    /* attachments on every type */
    for (uint32_t t = SY_TYPE_TEXTURE; t < SY_TYPE_COUNT; ++t) {
        uint32_t id;
        CHECK_OK(sy_object_create(s, t, "o", &id, &e), e);
        CHECK_OK(sy_object_set_attachment(s, t, id, &a_vec, &e), e);
        CHECK(sy_object_find_attachment(s, t, id, "ccc") != NULL);
    }
    return 0;
}

SY_CHECK_MAIN("test_scene", SY_TEST(test_handles), SY_TEST(test_dirty_noop), SY_TEST(test_validation),
              SY_TEST(test_camera_clip_range), SY_TEST(test_texture_info_validation), SY_TEST(test_children_validation),
              SY_TEST(test_world_chain), SY_TEST(test_world_incremental), SY_TEST(test_bounds), SY_TEST(test_dag),
              SY_TEST(test_walk), SY_TEST(test_attachments))
