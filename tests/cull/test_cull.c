/* test_cull.c — the remote culling service (apps/cull/sy_cull.h): ranking by covered pixels,
 * occlusion, the budget cut, the JSON answer, bad queries naming their field, unknown ids; the
 * coverage capability it asks (sy_context_coverage); the GLB
 * writer (formats/sy_gltf_write.h) round trip through sy_gltf_load; the poses of moved objects
 * (sy_culler_poses_json); the generated plant's counts. */
#include "../support/sy_check.h"
#include "sy_cull.h"
#include "sy_gltf.h"
#include "sy_gltf_write.h"
#include "sy_mediators.h"
#include "sy_plant.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MUST(call)                                                                           \
    do {                                                                                     \
        sy_result must_r_ = (call);                                                          \
        if (must_r_ != SY_OK) {                                                              \
            fprintf(stderr, "%s:%d: %s failed: %s\n", __FILE__, __LINE__, #call, err.message); \
            exit(1);                                                                         \
        }                                                                                    \
    } while (0)

static sy_error err;

/* A unit box mesh [-0.5, 0.5]^3 (24 vertices, 12 triangles) with one material. */
static sy_mesh box_mesh(sy_scene *s, sy_material mat)
{
    float pos[72], nrm[72];
    uint32_t idx[36];
    static const float N[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (int f = 0; f < 6; ++f) {
        const float *n = N[f];
        float u[3] = {n[1], n[2], n[0]}, v[3] = {n[1] * u[2] - n[2] * u[1], n[2] * u[0] - n[0] * u[2], n[0] * u[1] - n[1] * u[0]};
        for (int k = 0; k < 4; ++k) {
            float su = (k == 1 || k == 2) ? 0.5f : -0.5f, sv = k >= 2 ? 0.5f : -0.5f;
            for (int a = 0; a < 3; ++a) {
                pos[(f * 4 + k) * 3 + a] = 0.5f * n[a] + su * u[a] + sv * v[a];
                nrm[(f * 4 + k) * 3 + a] = n[a];
            }
        }
        uint32_t b = (uint32_t)f * 4;
        uint32_t t[6] = {b, b + 1, b + 2, b, b + 2, b + 3};
        memcpy(idx + f * 6, t, sizeof t);
    }
    sy_blob *bp, *bn, *bi;
    MUST(sy_blob_create_copy(pos, sizeof pos, &bp, &err));
    MUST(sy_blob_create_copy(nrm, sizeof nrm, &bn, &err));
    MUST(sy_blob_create_copy(idx, sizeof idx, &bi, &err));
    sy_primitive p = {.positions = bp, .normals = bn, .indices = bi, .material = mat};
    sy_mesh m;
    MUST(sy_mesh_create(s, "box", &m, &err));
    MUST(sy_mesh_set_primitives(s, m, &p, 1, &err));
    sy_blob_release(bp), sy_blob_release(bn), sy_blob_release(bi);
    return m;
}

static sy_node box_node(sy_scene *s, sy_node parent, sy_mesh m, const char *name, float x, float y, float z, float size)
{
    sy_node n;
    float t[3] = {x, y, z}, q[4] = {0, 0, 0, 1}, sc[3] = {size, size, size};
    MUST(sy_node_create(s, name, &n, &err));
    MUST(sy_node_set_trs(s, n, t, q, sc, &err));
    MUST(sy_node_set_mesh(s, n, m, &err));
    MUST(sy_node_set_flags(s, n, SY_NODE_VISIBLE, &err));
    MUST(sy_node_add_child(s, parent, n, &err));
    return n;
}

static const char VIEW[] = "\"position\":[0,0,10],\"orientation\":[0,0,0,1],\"fov\":40,\"width\":160,\"height\":120";

static char *query(sy_culler *c, const char *body, sy_result want, const char *needle)
{
    char *json = NULL;
    sy_error e = {0};
    sy_result r = sy_culler_query_json(c, body, strlen(body), &json, &e);
    EXPECT_MSG(r == want, "query %s: result %d (want %d): %s", body, (int)r, (int)want, e.message);
    if (needle) EXPECT_MSG(strstr(e.message, needle) != NULL, "query %s: message '%s' lacks '%s'", body, e.message, needle);
    return json;
}

/* Four boxes seen from +Z: near (big, in front), hidden (small, right behind near), side and far. */
static void test_boxes(void)
{
    sy_scene *s;
    sy_context_pool *pool;
    MUST(sy_scene_create(&s, &err));
    MUST(sy_context_pool_create(&pool, &err));
    sy_material_data md = *(const sy_material_data *)sy_object_defaults(SY_TYPE_MATERIAL);
    md.base_color[0] = 0.25f, md.base_color[1] = 0.5f, md.base_color[2] = 0.75f, md.base_color[3] = 1;
    md.metallic = 0.3f, md.roughness = 0.6f, md.emissive[0] = 0.5f, md.emissive[1] = 0.25f, md.emissive_strength = 2;
    /* a base colour texture larger than SY_CULL_TEXTURE_MAX_SIDE: the GLB carries it halved */
    enum { TW = 2 * SY_CULL_TEXTURE_MAX_SIDE + 200, TH = 300 };
    uint8_t *tpx = malloc((size_t)TW * TH * 4);
    for (size_t i = 0; i < (size_t)TW * TH * 4; ++i) tpx[i] = (uint8_t)(i % 4 == 3 ? 255 : (i / 4) % 251);
    sy_blob *tblob;
    MUST(sy_blob_create_take(tpx, (size_t)TW * TH * 4, &tblob, &err));
    sy_texture tex;
    const sy_image_info tinfo = {TW, TH, 4, SY_PIXEL_U8_SRGB};
    MUST(sy_texture_create(s, "pattern", &tex, &err));
    MUST(sy_texture_set_image(s, tex, &tinfo, tblob, &err));
    sy_blob_release(tblob);
    md.base_color_texture.texture = tex;
    sy_material mat;
    MUST(sy_material_create(s, "blue", &mat, &err));
    MUST(sy_material_set(s, mat, &md, &err));
    sy_mesh box = box_mesh(s, mat);
    sy_node root;
    MUST(sy_node_create(s, "root", &root, &err));
    MUST(sy_node_set_flags(s, root, SY_NODE_VISIBLE, &err));
    sy_node near = box_node(s, root, box, "near", 0, 0, 0, 2);
    sy_node hidden = box_node(s, root, box, "hidden", 0, 0, -3, 1);
    sy_node side = box_node(s, root, box, "side", 2.2f, 0, 0, 1);
    sy_node far = box_node(s, root, box, "far", -2.5f, 1, -6, 0.6f);
    MUST(sy_scene_commit(s, NULL, &err));
    sy_culler *c;
    MUST(sy_culler_create(s, pool, root, NULL, &c, &err));

    char body[512];
    snprintf(body, sizeof body, "{%s,\"budget\":1000}", VIEW);
    char *json = query(c, body, SY_OK, NULL);
    cJSON *doc = json ? cJSON_Parse(json) : NULL;
    EXPECT_MSG(doc != NULL, "answer is JSON: %s", json ? json : "(null)");
    if (doc) {
        cJSON *objs = cJSON_GetObjectItem(doc, "objects");
        int n = cJSON_GetArraySize(objs);
        EXPECT_MSG(n == 3, "3 visible objects (hidden is occluded), got %d: %s", n, json);
        double last = 1e30;
        bool saw_hidden = false, saw[3] = {false, false, false};
        for (cJSON *o = objs ? objs->child : NULL; o; o = o->next) {
            double px = cJSON_GetObjectItem(o, "pixels")->valuedouble;
            uint32_t id = (uint32_t)cJSON_GetObjectItem(o, "id")->valuedouble;
            EXPECT_MSG(px <= last && px > 0, "pixels descending and positive: %g after %g", px, last);
            EXPECT_MSG(cJSON_GetObjectItem(o, "triangles")->valuedouble == 12, "a box has 12 triangles");
            last = px;
            saw_hidden |= id == hidden.id;
            saw[0] |= id == near.id, saw[1] |= id == side.id, saw[2] |= id == far.id;
        }
        EXPECT_MSG(!saw_hidden && saw[0] && saw[1] && saw[2], "near, side, far listed; hidden not");
        EXPECT_MSG(objs && objs->child && (uint32_t)cJSON_GetObjectItem(objs->child, "id")->valuedouble == near.id,
                   "the near box covers the most pixels");
        EXPECT_MSG(cJSON_GetObjectItem(doc, "total_objects")->valuedouble == 4, "total_objects 4");
        EXPECT_MSG(cJSON_GetObjectItem(doc, "total_triangles")->valuedouble == 48, "total_triangles 48");
        EXPECT_MSG(cJSON_GetObjectItem(doc, "visible_objects")->valuedouble == 3, "visible_objects 3");
        EXPECT_MSG(cJSON_GetObjectItem(doc, "triangles")->valuedouble == 36, "triangles 36");
        cJSON *cov = cJSON_GetObjectItem(doc, "coverage");
        EXPECT_MSG(cJSON_GetArraySize(cov) == 2 && cov->child->valuedouble == 160, "coverage at the full size");
        cJSON *bmin = cJSON_GetObjectItem(cJSON_GetObjectItem(doc, "bounds"), "min");
        EXPECT_MSG(cJSON_GetArraySize(bmin) == 3 && fabs(bmin->child->valuedouble - -2.8) < 1e-6, "bounds.min x = far box's -2.8");
        cJSON_Delete(doc);
    }
    free(json);

    /* the budget cut: 12 keeps the first only, 30 the first two, 0 none */
    sy_cull_view v;
    uint64_t b;
    snprintf(body, sizeof body, "{%s,\"budget\":0}", VIEW);
    MUST(sy_cull_parse_query(body, strlen(body), &v, &b, &err));
    EXPECT_MSG(b == 0 && v.width == 160 && v.height == 120 && v.fov_degrees == 40 && v.position[2] == 10, "parsed view");
    sy_cull_result res, full;
    MUST(sy_culler_query(c, &v, 1000, &full, &err));
    uint64_t budgets[3] = {12, 30, 0};
    uint32_t want[3] = {1, 2, 0};
    for (int i = 0; i < 3; ++i) {
        MUST(sy_culler_query(c, &v, budgets[i], &res, &err));
        EXPECT_MSG(res.count == want[i] && res.triangles <= budgets[i], "budget %llu: %u objects (want %u), %llu triangles",
                   (unsigned long long)budgets[i], res.count, want[i], (unsigned long long)res.triangles);
        for (uint32_t k = 0; k < res.count; ++k) EXPECT_MSG(res.objects[k].id == full.objects[k].id, "the cut keeps the ranking's head");
        EXPECT_MSG(res.visible_objects == 3, "visible objects counted before the cut");
        sy_cull_result_free(&res);
    }
    /* reduced resolution: at most 4800 pixels (80 x 60), the same ranking */
    sy_culler *small;
    sy_culler_options so = {.max_coverage_pixels = 4800};
    MUST(sy_culler_create(s, NULL, root, &so, &small, &err));
    MUST(sy_culler_query(small, &v, 1000, &res, &err));
    EXPECT_MSG(res.coverage_width == 80 && res.coverage_height == 60, "coverage grid %ux%u", res.coverage_width, res.coverage_height);
    EXPECT_MSG(res.count == 3 && res.objects[0].id == near.id && res.objects[0].pixels * 3 < full.objects[0].pixels,
               "reduced grid: same head, fewer pixels");
    sy_cull_result_free(&res);
    sy_culler_destroy(small);

    /* the capability the culler asks (SY_CAP_COVERAGE, sy_context_coverage): a class offers it and
     * counts what the culler ranks; a class without it refuses, naming itself */
    const sy_mediator_class *cov = sy_mediator_with_caps(SY_CAP_COVERAGE);
    EXPECT_MSG(cov && cov->coverage, "a registered class offers SY_CAP_COVERAGE");
    sy_camera_view cam = sy_cull_view_camera(&v);
    sy_coverage_entry *ce = NULL;
    uint32_t cn = 0;
    sy_context *ctx;
    if (cov) {
        MUST(sy_context_create(s, cov->name, NULL, root.id, &ctx, &err));
        MUST(sy_context_sync(ctx, &err));
        MUST(sy_context_coverage(ctx, &cam, v.width, v.height, &ce, &cn, &err));
        EXPECT_MSG(cn == 3 && ce[0].node_id == full.objects[0].id && ce[0].pixels == full.objects[0].pixels,
                   "sy_context_coverage: %u nodes, the culler's head first", cn);
        free(ce);
        sy_context_release(ctx);
    }
    MUST(sy_context_create(s, "whitted", NULL, root.id, &ctx, &err));
    sy_error ue = {0};
    ce = (sy_coverage_entry *)&ue, cn = 7;
    EXPECT_MSG(sy_context_coverage(ctx, &cam, v.width, v.height, &ce, &cn, &ue) == SY_ERR_UNSUPPORTED && !ce && cn == 0 &&
                   strstr(ue.message, "whitted"), "whitted counts no coverage: %s", ue.message);
    sy_context_release(ctx);

    /* a hidden node (visibility flag) is no object; the index follows commits */
    MUST(sy_node_set_flags(s, side, 0, &err));
    MUST(sy_scene_commit(s, NULL, &err));
    MUST(sy_culler_query(c, &v, 1000, &res, &err));
    EXPECT_MSG(res.total_objects == 3 && res.count == 2, "after hiding one: total %u kept %u", res.total_objects, res.count);
    sy_cull_result_free(&res);
    uint8_t *glb = NULL;
    size_t len = 0;
    EXPECT_MSG(sy_culler_object_glb(c, side.id, &glb, &len, &err) == SY_ERR_NOT_FOUND, "a hidden object is not found");
    MUST(sy_node_set_flags(s, side, SY_NODE_VISIBLE, &err));
    MUST(sy_scene_commit(s, NULL, &err));

    /* bad queries: each names its field */
    static const struct {
        const char *body;
        sy_result code;
        const char *needle;
    } bad[] = {
        {"", SY_ERR_PARSE, "empty"},
        {"{", SY_ERR_PARSE, "not valid JSON"},
        {"[1,2]", SY_ERR_PARSE, "object"},
        {"{} x", SY_ERR_PARSE, "after"},
        {"{\"position\":[0,0,10]}", SY_ERR_INVALID_ARGUMENT, "'orientation' is missing"},
        {"{\"position\":[0,0],\"orientation\":[0,0,0,1],\"fov\":40,\"width\":10,\"height\":10,\"budget\":5}", SY_ERR_INVALID_ARGUMENT, "position must be an array of 3"},
        {"{\"position\":[0,0,\"a\"],\"orientation\":[0,0,0,1],\"fov\":40,\"width\":10,\"height\":10,\"budget\":5}", SY_ERR_INVALID_ARGUMENT, "position[2]"},
        {"{\"position\":[0,0,1e999],\"orientation\":[0,0,0,1],\"fov\":40,\"width\":10,\"height\":10,\"budget\":5}", SY_ERR_INVALID_ARGUMENT, "position[2] must be finite"},
        /* issue 32: 1e19 passed (the bound was 1e30) and Embree aborted on the ray origin */
        {"{\"position\":[1e19,0,0],\"orientation\":[0,0,0,1],\"fov\":40,\"width\":10,\"height\":10,\"budget\":5}", SY_ERR_INVALID_ARGUMENT, "position.x must be a finite number at most 1e+12"},
        {"{\"position\":[0,-1.1e12,0],\"orientation\":[0,0,0,1],\"fov\":40,\"width\":10,\"height\":10,\"budget\":5}", SY_ERR_INVALID_ARGUMENT, "position.y"},
        {"{\"position\":[0,0,NaN],\"orientation\":[0,0,0,1],\"fov\":40,\"width\":10,\"height\":10,\"budget\":5}", SY_ERR_PARSE, "JSON"},
        {"{\"position\":[0,0,1],\"orientation\":[0,0,0,0],\"fov\":40,\"width\":10,\"height\":10,\"budget\":5}", SY_ERR_INVALID_ARGUMENT, "orientation must be a nonzero"},
        {"{\"position\":[0,0,1],\"orientation\":[0,0,0,1],\"fov\":180,\"width\":10,\"height\":10,\"budget\":5}", SY_ERR_INVALID_ARGUMENT, "fov"},
        {"{\"position\":[0,0,1],\"orientation\":[0,0,0,1],\"fov\":0,\"width\":10,\"height\":10,\"budget\":5}", SY_ERR_INVALID_ARGUMENT, "fov"},
        {"{\"position\":[0,0,1],\"orientation\":[0,0,0,1],\"fov\":40,\"width\":0,\"height\":10,\"budget\":5}", SY_ERR_INVALID_ARGUMENT, "width must be an integer 1..16384"},
        {"{\"position\":[0,0,1],\"orientation\":[0,0,0,1],\"fov\":40,\"width\":10,\"height\":100000,\"budget\":5}", SY_ERR_INVALID_ARGUMENT, "height must be an integer"},
        {"{\"position\":[0,0,1],\"orientation\":[0,0,0,1],\"fov\":40,\"width\":10.5,\"height\":10,\"budget\":5}", SY_ERR_INVALID_ARGUMENT, "width must be an integer"},
        {"{\"position\":[0,0,1],\"orientation\":[0,0,0,1],\"fov\":40,\"width\":10,\"height\":10,\"budget\":-1}", SY_ERR_INVALID_ARGUMENT, "budget must be an integer"},
        {"{\"position\":[0,0,1],\"orientation\":[0,0,0,1],\"fov\":40,\"width\":10,\"height\":10,\"budget\":1e15}", SY_ERR_INVALID_ARGUMENT, "budget"},
        {"{\"position\":[0,0,1],\"orientation\":[0,0,0,1],\"fov\":\"wide\",\"width\":10,\"height\":10,\"budget\":5}", SY_ERR_INVALID_ARGUMENT, "fov must be a number"},
        {"{\"position\":[0,0,1],\"orientation\":[0,0,0,1],\"fov\":40,\"width\":10,\"height\":10,\"budget\":5,\"zoom\":2}", SY_ERR_INVALID_ARGUMENT, "unknown field 'zoom'"},
        {"{\"position\":[0,0,1],\"position\":[0,0,1],\"orientation\":[0,0,0,1],\"fov\":40,\"width\":10,\"height\":10,\"budget\":5}", SY_ERR_INVALID_ARGUMENT, "twice"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) free(query(c, bad[i].body, bad[i].code, bad[i].needle));
    char *big = malloc(SY_CULL_MAX_BODY + 2);
    memset(big, ' ', SY_CULL_MAX_BODY + 1);
    big[SY_CULL_MAX_BODY + 1] = 0;
    free(query(c, big, SY_ERR_LIMIT, "limit"));
    free(big);
    /* deep nesting is refused by cJSON, not a crash */
    char deep[4200];
    memset(deep, '[', sizeof deep - 1);
    deep[sizeof deep - 1] = 0;
    free(query(c, deep, SY_ERR_PARSE, "JSON"));

    /* ids */
    uint32_t id;
    EXPECT_MSG(sy_cull_parse_id("123", 3, &id, &err) == SY_OK && id == 123, "id 123");
    EXPECT_MSG(sy_cull_parse_id("0", 1, &id, &err) == SY_ERR_INVALID_ARGUMENT, "id 0 refused");
    EXPECT_MSG(sy_cull_parse_id("12a", 3, &id, &err) == SY_ERR_INVALID_ARGUMENT, "id 12a refused");
    EXPECT_MSG(sy_cull_parse_id("4294967296", 10, &id, &err) == SY_ERR_INVALID_ARGUMENT, "id 2^32 refused");
    EXPECT_MSG(sy_cull_parse_id("", 0, &id, &err) == SY_ERR_INVALID_ARGUMENT, "empty id refused");
    EXPECT_MSG(sy_culler_object_glb(c, 999999, &glb, &len, &err) == SY_ERR_NOT_FOUND && !glb, "unknown id: not found");
    EXPECT_MSG(strstr(err.message, "999999") != NULL, "the message names the id: %s", err.message);
    EXPECT_MSG(sy_culler_object_glb(c, root.id, &glb, &len, &err) == SY_ERR_NOT_FOUND, "a node without a mesh is no object");

    /* GLB round trip of one object: geometry, its world placement, the material */
    MUST(sy_culler_object_glb(c, far.id, &glb, &len, &err));
    EXPECT_MSG(len > 12 && !memcmp(glb, "glTF", 4), "GLB magic");
    sy_scene *back;
    sy_gltf_info info = {0};
    MUST(sy_scene_create(&back, &err));
    MUST(sy_gltf_load_memory(glb, len, "object.glb", "", back, NULL, &info, &err));
    MUST(sy_scene_commit(back, NULL, &err));
    EXPECT_MSG(info.counts.triangles == 12 && info.counts.meshes == 1 && info.counts.nodes == 1 && info.counts.materials == 1,
               "counts: %u triangles %u meshes %u nodes %u materials", info.counts.triangles, info.counts.meshes,
               info.counts.nodes, info.counts.materials);
    sy_bounds wb, ob;
    MUST(sy_node_world_bounds(back, info.root, &wb, &err));
    MUST(sy_node_world_bounds(s, far, &ob, &err));
    for (int a = 0; a < 3; ++a)
        EXPECT_MSG(fabsf(wb.min[a] - ob.min[a]) < 1e-5f && fabsf(wb.max[a] - ob.max[a]) < 1e-5f, "bounds axis %d: %g..%g vs %g..%g",
                   a, wb.min[a], wb.max[a], ob.min[a], ob.max[a]);
    uint32_t nk = 0;
    const uint32_t *kids = sy_node_children(sy_node_get(back, info.root), &nk);
    const sy_node_data *kd = nk == 1 ? sy_node_get(back, (sy_node){kids[0]}) : NULL;
    EXPECT_MSG(kd && kd->name && !strcmp(kd->name, "far"), "the node keeps its name");
    const sy_mesh_data *mdb = kd ? sy_mesh_get(back, kd->mesh) : NULL;
    const sy_material_data *mb = mdb && mdb->primitives.count == 1 ? sy_material_get(back, mdb->primitives.items[0].material) : NULL;
    EXPECT_MSG(mb != NULL, "a material came back");
    if (mb) {
        for (int k = 0; k < 4; ++k) EXPECT_MSG(fabsf(mb->base_color[k] - md.base_color[k]) < 1e-6f, "base colour %d", k);
        EXPECT_MSG(fabsf(mb->metallic - 0.3f) < 1e-6f && fabsf(mb->roughness - 0.6f) < 1e-6f, "metallic / roughness");
        EXPECT_MSG(fabsf(mb->emissive[0] - 0.5f) < 1e-6f && fabsf(mb->emissive[1] - 0.25f) < 1e-6f && fabsf(mb->emissive_strength - 2) < 1e-6f,
                   "emission %g %g x %g", mb->emissive[0], mb->emissive[1], mb->emissive_strength);
        EXPECT_MSG(sy_primitive_vertex_count(&mdb->primitives.items[0]) == 24 && mdb->primitives.items[0].normals, "24 vertices with normals");
        /* the texture: halved until it fits SY_CULL_TEXTURE_MAX_SIDE, each texel the mean of its 2 x 2 */
        const sy_texture_data *tb = mb->base_color_texture.texture.id ? sy_texture_get(back, mb->base_color_texture.texture) : NULL;
        EXPECT_MSG(tb != NULL, "the base colour texture came back");
        if (tb) {
            const uint8_t *q = sy_blob_data(tb->pixels);
            uint32_t want_w = (TW + 3) / 4, want_h = (TH + 3) / 4; /* halved twice: 2248 -> 1124 -> 562 */
            EXPECT_MSG(tb->info.width == want_w && tb->info.height == want_h && tb->info.channels == 4,
                       "texture %ux%u x %u, want %ux%u x 4", tb->info.width, tb->info.height, tb->info.channels, want_w, want_h);
            const sy_texture_data *ts = sy_texture_get(s, tex);
            const uint8_t *o = sy_blob_data(ts->pixels);
            double sum = 0; /* texel (1, 1): the mean of source texels 4..7 x 4..7 (two halvings, each rounded) */
            for (int y = 4; y < 8; ++y)
                for (int x = 4; x < 8; ++x) sum += o[((size_t)y * TW + x) * 4];
            EXPECT_MSG(q && fabs(q[((size_t)1 * want_w + 1) * 4] - sum / 16) <= 1.0, "texel (1, 1): %u, want %.2f",
                       q ? q[((size_t)1 * want_w + 1) * 4] : 0, sum / 16);
        }
    }
    sy_gltf_info_free(&info);
    free(glb);
    sy_scene_destroy(back);

    sy_cull_result_free(&full);
    /* poses: none moved as loaded; side moved (its matrix), then back where it was (still listed:
     * a client holds it moved) */
    char *pj = NULL;
    MUST(sy_culler_poses_json(c, &pj, &err));
    EXPECT_MSG(pj && strstr(pj, "\"objects\":[]"), "no object moved yet: %s", pj ? pj : "(null)");
    free(pj);
    const float q0[4] = {0, 0, 0, 1}, one[3] = {1, 1, 1}, moved_t[3] = {2.2f, 1.5f, 0}, home_t[3] = {2.2f, 0, 0};
    for (int pass = 0; pass < 2; ++pass) {
        MUST(sy_node_set_trs(s, side, pass ? home_t : moved_t, q0, one, &err));
        MUST(sy_scene_commit(s, NULL, &err));
        MUST(sy_culler_poses_json(c, &pj, &err));
        cJSON *pd = pj ? cJSON_Parse(pj) : NULL, *po = pd ? cJSON_GetObjectItem(pd, "objects") : NULL;
        cJSON *first = po && cJSON_GetArraySize(po) == 1 ? cJSON_GetArrayItem(po, 0) : NULL;
        cJSON *m = first ? cJSON_GetArrayItem(cJSON_GetObjectItem(first, "matrices"), 0) : NULL;
        EXPECT_MSG(first && (uint32_t)cJSON_GetObjectItem(first, "id")->valuedouble == side.id && cJSON_GetArraySize(m) == 16 &&
                       fabs(cJSON_GetArrayItem(m, 13)->valuedouble - (pass ? 0.0 : 1.5)) < 1e-6,
                   "pass %d: side (id %u) alone, its matrix's y translation %g: %s", pass, side.id, pass ? 0.0 : 1.5, pj);
        cJSON_Delete(pd);
        free(pj);
    }
    sy_culler_destroy(c);
    sy_context_pool_destroy(pool);
    sy_scene_destroy(s);
}

/* A plant of 300 objects: counts agree between generator, culler and a GLB round trip. */
static void test_plant(void)
{
    sy_scene *s;
    MUST(sy_scene_create(&s, &err));
    sy_plant_desc d = {.triangles = 300000, .objects = 300, .seed = 7};
    sy_plant_info pi;
    MUST(sy_plant_generate(s, &d, &pi, &err));
    MUST(sy_scene_commit(s, NULL, &err));
    EXPECT_MSG(pi.objects == 300 && pi.grid == 4, "300 objects on a 4 x 4 grid: %u, %u", pi.objects, pi.grid);
    EXPECT_MSG(pi.triangles > 270000 && pi.triangles < 330000, "about 300k triangles: %llu", (unsigned long long)pi.triangles);
    sy_culler *c;
    MUST(sy_culler_create(s, NULL, pi.root, NULL, &c, &err));
    /* the generator's own count equals what the meshes hold */
    sy_cull_view v = {{0, 6, 0}, {0, 0, 0, 1}, 60, 320, 180};
    sy_cull_result r;
    MUST(sy_culler_query(c, &v, 1ull << 40, &r, &err));
    EXPECT_MSG(r.total_objects == 300 && r.total_triangles == pi.triangles, "culler totals %u / %llu vs plant %llu",
               r.total_objects, (unsigned long long)r.total_triangles, (unsigned long long)pi.triangles);
    EXPECT_MSG(r.count == r.visible_objects && r.visible_objects > 10 && r.visible_objects < 300,
               "an unlimited budget keeps every visible object: %u of %u", r.count, r.visible_objects);
    uint64_t budget = r.visible_triangles / 3;
    sy_cull_result_free(&r);
    MUST(sy_culler_query(c, &v, budget, &r, &err));
    EXPECT_MSG(r.triangles <= budget && r.count < r.visible_objects, "budget %llu: %llu triangles, %u of %u objects",
               (unsigned long long)budget, (unsigned long long)r.triangles, r.count, r.visible_objects);
    for (uint32_t i = 1; i < r.count; ++i) EXPECT_MSG(r.objects[i].pixels <= r.objects[i - 1].pixels, "ranked by pixels");
    sy_cull_result_free(&r);
    sy_culler_destroy(c);

    /* the whole plant as GLB and back */
    uint8_t *glb;
    size_t len;
    MUST(sy_gltf_write_subtree(s, pi.root, NULL, &glb, &len, &err));
    sy_scene *back;
    sy_gltf_info info = {0};
    MUST(sy_scene_create(&back, &err));
    MUST(sy_gltf_load_memory(glb, len, "plant.glb", "", back, NULL, &info, &err));
    MUST(sy_scene_commit(back, NULL, &err));
    EXPECT_MSG(info.counts.nodes == 300 && info.counts.meshes == pi.meshes, "nodes %u meshes %u (plant %u)", info.counts.nodes,
               info.counts.meshes, pi.meshes);
    sy_gltf_placement *pl;
    uint32_t np;
    MUST(sy_gltf_placements_collect(back, info.root, &pl, &np, &err));
    uint64_t tris = 0;
    for (uint32_t i = 0; i < np; ++i) {
        const sy_mesh_data *m = sy_mesh_get(back, pl[i].mesh);
        for (uint32_t k = 0; m && k < m->primitives.count; ++k) tris += sy_primitive_triangle_count(&m->primitives.items[k]);
    }
    EXPECT_MSG(np == 300 && tris == pi.triangles, "placements %u triangles %llu", np, (unsigned long long)tris);
    sy_bounds wb;
    MUST(sy_node_world_bounds(back, info.root, &wb, &err));
    for (int a = 0; a < 3; ++a)
        EXPECT_MSG(fabsf(wb.min[a] - pi.bounds.min[a]) < 1e-3f && fabsf(wb.max[a] - pi.bounds.max[a]) < 1e-3f, "plant bounds axis %d", a);
    free(pl);
    sy_gltf_info_free(&info);
    sy_scene_destroy(back);
    free(glb);
    sy_scene_destroy(s);
}

int main(void)
{
    if (sy_mediators_register_builtin(&err) != SY_OK) {
        fprintf(stderr, "register: %s\n", err.message);
        return 1;
    }
    test_boxes();
    test_plant();
    return sy_check_finish("cull");
}
