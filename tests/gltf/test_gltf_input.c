/* test_gltf_input.c — synthetic glTF / GLB files written to a temporary directory: valid ones
 * (strip / fan conversion, sparse accessors, textures in two roles, texture transform, GLB equals
 * glTF, parentless-node default scene) and malformed ones. For every malformed file the load must
 * fail with a message naming the file and the specific problem, and leave no object in the scene
 * and no blob alive. Needs no shared test data. */
#include "../support/sy_check.h"
#include "../support/sy_scratch.h"
#include "sy_gltf.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static char g_dir[256];

/* ---- file generation ---- */

static char *base64_uri(const void *data, size_t n, const char *mime)
{
    static const char tbl[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    const uint8_t *b = data;
    size_t cap = strlen(mime) + 32 + (n + 2) / 3 * 4;
    char *s = malloc(cap), *o;
    o = s + sprintf(s, "data:%s;base64,", mime);
    for (size_t i = 0; i < n; i += 3) {
        uint32_t v = (uint32_t)b[i] << 16 | (i + 1 < n ? (uint32_t)b[i + 1] << 8 : 0) | (i + 2 < n ? b[i + 2] : 0);
        *o++ = tbl[v >> 18 & 63];
        *o++ = tbl[v >> 12 & 63];
        *o++ = i + 1 < n ? tbl[v >> 6 & 63] : '=';
        *o++ = i + 2 < n ? tbl[v & 63] : '=';
    }
    *o = '\0';
    return s;
}

static void write_file(const char *name, const void *data, size_t n, char *path_out)
{
    sprintf(path_out, "%s/%s", g_dir, name);
    FILE *f = fopen(path_out, "wb");
    if (!f || fwrite(data, 1, n, f) != n) {
        fprintf(stderr, "cannot write %s\n", path_out);
        exit(1);
    }
    fclose(f);
}

/* The standard buffer: 3 (or 4) float3 positions, then 3 ushort indices + 2 bytes padding. */
typedef struct std_buffer {
    float pos[9];
    uint16_t idx[4];
} std_buffer;

static std_buffer standard_buffer(void)
{
    std_buffer b = {{0, 0, 0, 1, 0, 0, 0, 1, 0}, {0, 1, 2, 0}};
    return b;
}

/* Writes `json_fmt` (one %s: the buffer's data URI) with the given buffer bytes. */
static void write_gltf(const char *name, const char *json_fmt, const void *buf, size_t n, char *path_out)
{
    char *uri = base64_uri(buf, n, "application/octet-stream");
    size_t cap = strlen(json_fmt) + strlen(uri) + 1;
    char *json = malloc(cap);
    snprintf(json, cap, json_fmt, uri);
    write_file(name, json, strlen(json), path_out);
    free(json);
    free(uri);
}

static void put_u32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
    p[2] = (uint8_t)(v >> 16);
    p[3] = (uint8_t)(v >> 24);
}

/* GLB with a JSON chunk and a BIN chunk (both padded to 4 bytes). Caller frees. */
static uint8_t *make_glb(const char *json, const void *bin, size_t bin_len, size_t *size_out)
{
    size_t jl = (strlen(json) + 3) & ~(size_t)3, bl = (bin_len + 3) & ~(size_t)3;
    size_t total = 12 + 8 + jl + (bin ? 8 + bl : 0);
    uint8_t *g = calloc(1, total);
    memcpy(g, "glTF", 4);
    put_u32(g + 4, 2);
    put_u32(g + 8, (uint32_t)total);
    put_u32(g + 12, (uint32_t)jl);
    put_u32(g + 16, 0x4E4F534Au);
    memset(g + 20, ' ', jl);
    memcpy(g + 20, json, strlen(json));
    if (bin) {
        put_u32(g + 20 + jl, (uint32_t)bl);
        put_u32(g + 24 + jl, 0x004E4942u);
        memcpy(g + 28 + jl, bin, bin_len);
    }
    *size_out = total;
    return g;
}

/* ---- building blocks of the JSON documents ---- */
#define ASSET "\"asset\":{\"version\":\"2.0\"}"
#define BUF "\"buffers\":[{\"byteLength\":44,\"uri\":\"%s\"}]"
#define VIEWS "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":6}]"
#define ACC_POS "{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}"
#define ACC_IDX "{\"bufferView\":1,\"componentType\":5123,\"count\":3,\"type\":\"SCALAR\"}"
#define ACCS "\"accessors\":[" ACC_POS "," ACC_IDX "]"
#define MESHES "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1,\"material\":0}]}]"
#define MATS "\"materials\":[{\"name\":\"m\"}]"
#define NODES "\"nodes\":[{\"mesh\":0}]"
#define SCENES "\"scene\":0,\"scenes\":[{\"nodes\":[0]}]"
#define DOC(buf, views, accs, meshes, mats, nodes, scenes, extra)                                                      \
    "{" ASSET "," buf "," views "," accs "," meshes "," mats "," nodes "," scenes extra "}"
#define STD DOC(BUF, VIEWS, ACCS, MESHES, MATS, NODES, SCENES, "")

/* 2x2 RGBA PNG */
static const char k_png_uri[] = "data:image/png;base64,iVBORw0KGgoAAAANSUhEUgAAAAIAAAACCAYAAABytg0kAAAAE0lEQVR4nGP4z8DwHwyBNAg0AABJSQl4KKDbdwAAAABJRU5ErkJggg==";

/* ---- running a case ---- */

/* The last node of s named name, or NULL. */
static const sy_node_data *node_named(sy_scene *s, const char *name)
{
    const sy_node_data *nd = NULL;
    for (uint32_t id = sy_scene_next(s, SY_TYPE_NODE, 0); id; id = sy_scene_next(s, SY_TYPE_NODE, id)) {
        const sy_node_data *x = sy_node_get(s, (sy_node){id});
        if (x->name && !strcmp(x->name, name)) nd = x;
    }
    return nd;
}

/* The node named "moved" exists and its translation has these x and z. */
static bool moved_to(sy_scene *s, float x, float z)
{
    const sy_node_data *nd = node_named(s, "moved");
    return nd && nd->transform.translation[0] == x && nd->transform.translation[2] == z;
}

typedef struct outcome {
    sy_result r;
    sy_error err;
} outcome;

/* Loads path into a fresh scene; checks that a failure left nothing behind. */
static outcome run(const char *path, const sy_gltf_options *opt, sy_scene **keep)
{
    outcome o;
    memset(&o, 0, sizeof o);
    long blobs = sy_blob_live_count();
    sy_scene *s = NULL;
    sy_error e = {0};
    if (sy_scene_create(&s, &e)) {
        fprintf(stderr, "scene: %s\n", e.message);
        exit(1);
    }
    sy_gltf_info info;
    o.r = sy_gltf_load(path, s, opt, &info, &o.err);
    if (o.r != SY_OK) {
        for (int t = SY_TYPE_TEXTURE; t < SY_TYPE_COUNT; t++)
            EXPECT_MSG(sy_scene_count(s, (sy_object_type)t) == 0, "%s: %u leftover %s objects", path,
                       sy_scene_count(s, (sy_object_type)t), sy_object_type_name((sy_object_type)t));
        EXPECT_MSG(info.camera_nodes == NULL && info.warnings == NULL, "%s: info not cleared", path);
        uint64_t frame;
        EXPECT_MSG(sy_scene_commit(s, &frame, &e) == SY_OK, "%s: commit after failure: %s", path, e.message);
    }
    sy_gltf_info_free(&info);
    if (keep && o.r == SY_OK) {
        *keep = s;
    } else {
        sy_scene_destroy(s);
        EXPECT_MSG(sy_blob_live_count() == blobs, "%s: %ld blobs leaked", path, sy_blob_live_count() - blobs);
    }
    return o;
}

/* Writes json_fmt with buf as file name (write_gltf) and loads it into *s (the caller destroys it);
 * true when it loaded, a failed check naming the file and the reason otherwise. */
static bool write_load(const char *name, const char *json_fmt, const void *buf, size_t n, char *path, sy_scene **s)
{
    write_gltf(name, json_fmt, buf, n, path);
    outcome o = run(path, NULL, s);
    EXPECT_MSG(o.r == SY_OK, "%s: %s", name, o.err.message);
    return o.r == SY_OK;
}

static void expect_fail(const char *name, const char *path, const sy_gltf_options *opt, sy_result code, const char *substr)
{
    outcome o = run(path, opt, NULL);
    const char *base = strrchr(path, '/') ? strrchr(path, '/') + 1 : path;
    EXPECT_MSG(o.r != SY_OK, "%s: load succeeded", name);
    if (o.r == SY_OK) return;
    EXPECT_MSG(code == SY_OK || o.r == code, "%s: result %s, expected %s (%s)", name, sy_result_str(o.r), sy_result_str(code),
               o.err.message);
    EXPECT_MSG(strstr(o.err.message, base) != NULL, "%s: message does not name the file: %s", name, o.err.message);
    EXPECT_MSG(strstr(o.err.message, substr) != NULL, "%s: message lacks '%s': %s", name, substr, o.err.message);
    printf("ok bad %-28s %s\n", name, o.err.message);
}

static void bad_json_case(const char *name, const char *json_fmt, sy_result code, const char *substr)
{
    char path[512], fname[128];
    std_buffer b = standard_buffer();
    snprintf(fname, sizeof fname, "%s.gltf", name);
    write_gltf(fname, json_fmt, &b, sizeof b, path);
    expect_fail(name, path, NULL, code, substr);
}

static void local_image_case(const char *name, const char *json_fmt, const char *substr)
{
    char path[512], fname[128];
    std_buffer b = standard_buffer();
    snprintf(fname, sizeof fname, "%s.gltf", name);
    write_gltf(fname, json_fmt, &b, sizeof b, path);
    sy_scene *s = NULL;
    if (sy_scene_create(&s, NULL) != SY_OK) exit(1);
    sy_gltf_info info;
    sy_error e = {0};
    sy_result r = sy_gltf_load(path, s, NULL, &info, &e);
    bool warned = false;
    for (uint32_t k = 0; r == SY_OK && k < info.stored_warning_count; k++) warned |= strstr(info.warnings[k], substr) != NULL;
    EXPECT_MSG(r == SY_OK && warned, "%s: loads with a warning naming '%s' (%s)", name, substr, e.message);
    EXPECT_MSG(sy_scene_count(s, SY_TYPE_TEXTURE) == 0 && sy_scene_count(s, SY_TYPE_MESH) > 0, "%s: no texture, mesh loaded", name);
    sy_gltf_info_free(&info);
    sy_scene_destroy(s);
}

static void test_bad_json(void)
{
    bad_json_case("truncated_json", "{\"asset\":{\"version\":\"2.0\"},\"nodes\":[{\"mesh\":0}", SY_ERR_PARSE, "invalid glTF");
    bad_json_case("not_json", "this is not json", SY_ERR_PARSE, "invalid glTF");
    bad_json_case("accessor_index", DOC(BUF, VIEWS, ACCS, "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":7}}]}]", MATS, NODES, SCENES, ""),
                  SY_ERR_PARSE, "POSITION 7 out of range");
    bad_json_case("indices_index", DOC(BUF, VIEWS, ACCS, "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":9}]}]", MATS, NODES, SCENES, ""),
                  SY_ERR_PARSE, "indices");
    bad_json_case("view_index", DOC(BUF, VIEWS, "\"accessors\":[{\"bufferView\":5,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}," ACC_IDX "]", MESHES, MATS, NODES, SCENES, ""),
                  SY_ERR_PARSE, "accessors[0]: bufferView 5 out of range");
    bad_json_case("buffer_index", DOC(BUF, "\"bufferViews\":[{\"buffer\":3,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":6}]", ACCS, MESHES, MATS, NODES, SCENES, ""),
                  SY_ERR_PARSE, "bufferViews[0]: buffer 3 out of range");
    bad_json_case("mesh_index", DOC(BUF, VIEWS, ACCS, MESHES, MATS, "\"nodes\":[{\"mesh\":4}]", SCENES, ""),
                  SY_ERR_PARSE, "nodes[0]: mesh 4 out of range");
    bad_json_case("material_index", DOC(BUF, VIEWS, ACCS, "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"material\":2}]}]", MATS, NODES, SCENES, ""),
                  SY_ERR_PARSE, "material 2 out of range");
    bad_json_case("texture_index", DOC(BUF, VIEWS, ACCS, MESHES, "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":3}}}]", NODES, SCENES, ""),
                  SY_ERR_PARSE, "materials[0].baseColorTexture: texture 3 out of range");
    bad_json_case("image_index", DOC(BUF, VIEWS, ACCS, MESHES, MATS, NODES, SCENES, ",\"textures\":[{\"source\":2}]"),
                  SY_ERR_PARSE, "textures[0]: source 2 out of range");
    bad_json_case("camera_index", DOC(BUF, VIEWS, ACCS, MESHES, MATS, "\"nodes\":[{\"mesh\":0,\"camera\":1}]", SCENES, ""),
                  SY_ERR_PARSE, "nodes[0]: camera 1 out of range");
    /* tinygltf reads indices into an int: 2^40 wrapped to mesh 0, a silent wrong scene (issue 32) */
    bad_json_case("index_2_40", DOC(BUF, VIEWS, ACCS, MESHES, MATS, "\"nodes\":[{\"mesh\":1099511627776}]", SCENES, ""),
                  SY_ERR_PARSE, "nodes[0].mesh is not an index");
    bad_json_case("index_negative", DOC(BUF, VIEWS, ACCS, "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":-4294967296}}]}]", MATS, NODES, SCENES, ""),
                  SY_ERR_PARSE, "meshes[0].primitives[0].attributes.POSITION is not an index");
    bad_json_case("child_2_32", DOC(BUF, VIEWS, ACCS, MESHES, MATS, "\"nodes\":[{\"mesh\":0,\"children\":[4294967296]}]", SCENES, ""),
                  SY_ERR_PARSE, "nodes[0].children[0] is not an index");
    bad_json_case("child_index", DOC(BUF, VIEWS, ACCS, MESHES, MATS, "\"nodes\":[{\"mesh\":0,\"children\":[9]}]", SCENES, ""),
                  SY_ERR_PARSE, "nodes[0].children[0]: node 9 out of range");
    bad_json_case("scene_node_index", DOC(BUF, VIEWS, ACCS, MESHES, MATS, NODES, "\"scenes\":[{\"nodes\":[3]}]", ""),
                  SY_ERR_PARSE, "scenes[0].nodes[0]: node 3 out of range");
    bad_json_case("scene_index", DOC(BUF, VIEWS, ACCS, MESHES, MATS, NODES, "\"scene\":2,\"scenes\":[{\"nodes\":[0]}]", ""),
                  SY_ERR_PARSE, "scene 2 out of range");
    bad_json_case("light_index", DOC(BUF, VIEWS, ACCS, MESHES, MATS, "\"nodes\":[{\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}}]", SCENES, ""),
                  SY_ERR_PARSE, "light 0 out of range");
    bad_json_case("accessor_count", DOC(BUF, VIEWS, "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":1000000,\"type\":\"VEC3\"}," ACC_IDX "]", MESHES, MATS, NODES, SCENES, ""),
                  SY_ERR_PARSE, "accessors[0]: byteOffset 0 + count 1000000 * stride 12 exceeds bufferView 0 length 36");
    bad_json_case("accessor_offset", DOC(BUF, VIEWS, "\"accessors\":[{\"bufferView\":0,\"byteOffset\":4,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}," ACC_IDX "]", MESHES, MATS, NODES, SCENES, ""),
                  SY_ERR_PARSE, "byteOffset 4 + count 3 * stride 12 exceeds bufferView 0 length 36");
    bad_json_case("accessor_overflow", DOC(BUF, VIEWS, "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4611686018427387904,\"type\":\"VEC3\"}," ACC_IDX "]", MESHES, MATS, NODES, SCENES, ""),
                  SY_ERR_PARSE, "exceeds bufferView 0");
    bad_json_case("view_past_buffer", DOC(BUF, "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":8,\"byteLength\":40},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":6}]", ACCS, MESHES, MATS, NODES, SCENES, ""),
                  SY_ERR_PARSE, "bufferViews[0]: byteOffset 8 + byteLength 40 exceeds buffer 0 length 44");
    bad_json_case("stride_small", DOC(BUF, "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36,\"byteStride\":4},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":6}]", ACCS, MESHES, MATS, NODES, SCENES, ""),
                  SY_ERR_PARSE, "byteStride 4 of bufferView 0 is smaller than the element size 12");
    bad_json_case("component_type", DOC(BUF, VIEWS, "\"accessors\":[{\"bufferView\":0,\"componentType\":5130,\"count\":1,\"type\":\"VEC3\"}," ACC_IDX "]", MESHES, MATS, NODES, SCENES, ""),
                  SY_ERR_PARSE, "componentType 5130");
    bad_json_case("prim_mode", DOC(BUF, VIEWS, ACCS, "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"mode\":9}]}]", MATS, NODES, SCENES, ""),
                  SY_ERR_PARSE, "mode 9");
    bad_json_case("two_parents", DOC(BUF, VIEWS, ACCS, MESHES, MATS, "\"nodes\":[{\"children\":[2]},{\"children\":[2]},{\"mesh\":0}]", "\"scenes\":[{\"nodes\":[0,1]}]", ""),
                  SY_ERR_PARSE, "nodes[2] has two parents");
    bad_json_case("cycle", DOC(BUF, VIEWS, ACCS, MESHES, MATS, "\"nodes\":[{\"mesh\":0},{\"children\":[2]},{\"children\":[1]}]", "\"scenes\":[{\"nodes\":[0]}]", ""),
                  SY_ERR_PARSE, "cycle");
    bad_json_case("self_child", DOC(BUF, VIEWS, ACCS, MESHES, MATS, "\"nodes\":[{\"mesh\":0,\"children\":[0]}]", "\"scenes\":[{\"nodes\":[]}]", ""),
                  SY_ERR_PARSE, "cycle");
    bad_json_case("root_twice", DOC(BUF, VIEWS, ACCS, MESHES, MATS, NODES, "\"scenes\":[{\"nodes\":[0,0]}]", ""),
                  SY_ERR_PARSE, "nodes[0] is listed twice as a root");
    bad_json_case("root_not_root", DOC(BUF, VIEWS, ACCS, MESHES, MATS, "\"nodes\":[{\"children\":[1]},{\"mesh\":0}]", "\"scenes\":[{\"nodes\":[0,1]}]", ""),
                  SY_ERR_PARSE, "nodes[1] is not a root node");
    bad_json_case("ext_required", DOC(BUF, VIEWS, ACCS, MESHES, MATS, NODES, SCENES, ",\"extensionsRequired\":[\"EXT_lights_image_based\"]"),
                  SY_ERR_UNSUPPORTED, "'EXT_lights_image_based' is not supported");
    bad_json_case("deep_json", "{\"asset\":{\"version\":\"2.0\"},\"extras\":[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]}",
                  SY_ERR_LIMIT, "JSON nesting deeper than 64");
    bad_json_case("sparse_index", DOC(BUF, VIEWS, "\"accessors\":[{\"componentType\":5126,\"count\":3,\"type\":\"VEC3\",\"sparse\":{\"count\":1,\"indices\":{\"bufferView\":0,\"byteOffset\":15,\"componentType\":5121},\"values\":{\"bufferView\":0}}}," ACC_IDX "]", MESHES, MATS, NODES, SCENES, ""),
                  SY_ERR_PARSE, "accessors[0].sparse.indices[0]: index 63 >= accessor count 3");
    bad_json_case("bad_alpha_mode", DOC(BUF, VIEWS, ACCS, MESHES, "\"materials\":[{\"alphaMode\":\"SOMETIMES\"}]", NODES, SCENES, ""),
                  SY_ERR_PARSE, "alphaMode 'SOMETIMES'");
    bad_json_case("bad_camera", DOC(BUF, VIEWS, ACCS, MESHES, MATS, NODES, SCENES, ",\"cameras\":[{\"type\":\"perspective\",\"perspective\":{\"yfov\":-1,\"znear\":0.1}}]"),
                  SY_ERR_PARSE, "cameras[0]: yfov");
    /* a bad image is local (issue 6): the load succeeds, its textures go missing with a warning */
    local_image_case("missing_image", DOC(BUF, VIEWS, ACCS, MESHES, MATS, NODES, SCENES, ",\"textures\":[{\"source\":0}],\"images\":[{\"uri\":\"missing.png\"}]"),
                     "images[0] ('missing.png')");
    local_image_case("corrupt_image", DOC(BUF, VIEWS, ACCS, MESHES, MATS, NODES, SCENES, ",\"textures\":[{\"source\":0}],\"images\":[{\"uri\":\"data:image/png;base64,iVBORw0KGgoAAAAAAAAAAAAA\"}]"),
                     "images[0]: cannot decode image");
    /* a truncated Radiance file where a PNG should be: stb_image would loop for ever on it; only PNG
     * and JPEG are decoded (seen hanging before) */
    local_image_case("radiance_image", DOC(BUF, VIEWS, ACCS, MESHES, MATS, NODES, SCENES, ",\"textures\":[{\"source\":0}],\"images\":[{\"uri\":\"data:image/png;base64,Iz9SQURJQU5DRQpGT1JNQVQ9MzItYml0X3JsZV9yZ2JlCgotWSAxICtYIDI2NAoCAgEIiA==\"}]"),
                     "images[0]: Radiance HDR image content, not a PNG or JPEG image");
    bad_json_case("image_view_range", DOC(BUF, "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":6},{\"buffer\":0,\"byteOffset\":40,\"byteLength\":4000}]", ACCS, MESHES, MATS, NODES, SCENES, ",\"images\":[{\"bufferView\":2,\"mimeType\":\"image/png\"}]"),
                  SY_ERR_PARSE, "exceeds buffer 0 length 44");
    bad_json_case("missing_buffer", "{" ASSET ",\"buffers\":[{\"byteLength\":44,\"uri\":\"missing.bin\"}]}", SY_ERR_NOT_FOUND, "missing.bin");
}

/* Buffer contents that are wrong: index values, non-finite positions. Both fail after the
 * material was created, so they also exercise the rollback. */
static void test_bad_data(void)
{
    char path[512];
    std_buffer b = standard_buffer();
    b.idx[2] = 5;
    write_gltf("index_value.gltf", STD, &b, sizeof b, path);
    expect_fail("index_value", path, NULL, SY_ERR_PARSE, "index 5 at position 2 (accessor 1) >= vertex count 3");

    b = standard_buffer();
    b.pos[4] = NAN;
    write_gltf("nan_position.gltf", STD, &b, sizeof b, path);
    expect_fail("nan_position", path, NULL, SY_ERR_PARSE, "accessors[0] (POSITION of meshes[0].primitives[0]): non-finite");

    b = standard_buffer();
    write_gltf("limits.gltf", STD, &b, sizeof b, path);
    sy_gltf_options opt = {0};
    opt.max_vertices = 2;
    expect_fail("max_vertices", path, &opt, SY_ERR_LIMIT, "3 vertices exceed the limit of 2");
    opt = (sy_gltf_options){0};
    opt.max_file_bytes = 16;
    expect_fail("max_file_bytes", path, &opt, SY_ERR_LIMIT, "limit");

    char json[4096];
    snprintf(json, sizeof json, DOC(BUF, VIEWS, ACCS, MESHES, MATS, NODES, SCENES, ",\"images\":[{\"uri\":\"%s\"}]"), "%s", k_png_uri);
    write_gltf("image_limit.gltf", json, &b, sizeof b, path);
    opt = (sy_gltf_options){0};
    opt.max_image_pixels = 3;
    { /* an image over the limit is refused before decoding and is local: a missing texture + warning */
        sy_scene *s = NULL;
        if (sy_scene_create(&s, NULL) != SY_OK) exit(1);
        sy_gltf_info info;
        sy_error e = {0};
        sy_result r = sy_gltf_load(path, s, &opt, &info, &e);
        bool warned = false;
        for (uint32_t k = 0; r == SY_OK && k < info.stored_warning_count; k++)
            warned |= strstr(info.warnings[k], "image 2x2 exceeds the limit of 3 pixels") != NULL;
        EXPECT_MSG(r == SY_OK && warned, "max_image_pixels: loads with a warning (%s)", e.message);
        sy_gltf_info_free(&info);
        sy_scene_destroy(s);
    }

    sprintf(path, "%s/does_not_exist.gltf", g_dir);
    expect_fail("missing_file", path, NULL, SY_ERR_NOT_FOUND, "does_not_exist.gltf");
}

static void test_bad_glb(void)
{
    const char *json = "{" ASSET ",\"buffers\":[{\"byteLength\":44}]," VIEWS "," ACCS "," MESHES "," MATS "," NODES "," SCENES "}";
    std_buffer b = standard_buffer();
    size_t n;
    char path[512];
    uint8_t *g = make_glb(json, &b, sizeof b, &n);

    write_file("good.glb", g, n, path);
    outcome o = run(path, NULL, NULL);
    EXPECT_MSG(o.r == SY_OK, "good.glb: %s", o.err.message);
    { /* the same bytes from memory (sy_gltf_load_memory, as the fuzz targets load), and a GLB
       * whose header length is one byte short of the input, named in the message */
        sy_scene *s = NULL;
        if (sy_scene_create(&s, NULL) != SY_OK) exit(1);
        sy_gltf_info info;
        sy_error e = {0};
        sy_result r = sy_gltf_load_memory(g, n, "mem.glb", g_dir, s, NULL, &info, &e);
        EXPECT_MSG(r == SY_OK && sy_scene_count(s, SY_TYPE_MESH) == 1, "good.glb from memory: %s", e.message);
        sy_gltf_info_free(&info);
        sy_scene_destroy(s);
        if (sy_scene_create(&s, NULL) != SY_OK) exit(1);
        r = sy_gltf_load_memory(g, n - 1, "short.glb", g_dir, s, NULL, NULL, &e);
        EXPECT_MSG(r == SY_ERR_PARSE && strstr(e.message, "short.glb") && strstr(e.message, "total length"),
                   "short GLB from memory: %s", e.message);
        sy_gltf_options small = {0};
        small.max_file_bytes = n - 1;
        r = sy_gltf_load_memory(g, n, "big.glb", g_dir, s, &small, NULL, &e);
        EXPECT_MSG(r == SY_ERR_LIMIT && strstr(e.message, "big.glb"), "memory input over max_file_bytes: %s", e.message);
        sy_scene_destroy(s);
    }

    uint8_t *c = malloc(n + 16);
    struct {
        const char *name;
        size_t off;
        uint32_t value;
        const char *substr;
    } cases[] = {
        {"glb_magic", 0, 0x12345678u, "wrong magic"},
        {"glb_version", 4, 3, "GLB version 3 is not supported"},
        {"glb_length_small", 8, 100, "GLB total length 100 does not equal the file size"},
        {"glb_length_big", 8, 0x7fffffffu, "does not equal the file size"},
        {"glb_json_len", 12, 0xfffffff0u, "GLB chunk 0 length 4294967280 exceeds"},
        {"glb_json_type", 16, 0x11111111u, "GLB chunk 0 has type"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        memcpy(c, g, n);
        put_u32(c + cases[k].off, cases[k].value);
        char fname[64];
        snprintf(fname, sizeof fname, "%s.glb", cases[k].name);
        write_file(fname, c, n, path);
        expect_fail(cases[k].name, path, NULL, SY_OK, cases[k].substr);
    }
    /* BIN chunk length that lies: the BIN chunk header follows the padded JSON chunk */
    uint32_t jl = (uint32_t)g[12] | (uint32_t)g[13] << 8 | (uint32_t)g[14] << 16 | (uint32_t)g[15] << 24;
    memcpy(c, g, n);
    put_u32(c + 20 + jl, 48);
    write_file("glb_bin_len.glb", c, n, path);
    expect_fail("glb_bin_len", path, NULL, SY_ERR_PARSE, "GLB chunk 1 length 48 exceeds the 44 bytes left");
    /* truncated file (length field adjusted so only the chunk table is wrong) */
    memcpy(c, g, n);
    put_u32(c + 8, (uint32_t)(n - 10));
    write_file("glb_truncated.glb", c, n - 10, path);
    expect_fail("glb_truncated", path, NULL, SY_ERR_PARSE, "GLB chunk 1 length");
    /* too short for a header */
    write_file("glb_short.glb", "glTF\2\0", 6, path);
    expect_fail("glb_short", path, NULL, SY_ERR_PARSE, "GLB header truncated");
    free(c);
    free(g);
}

/* ---- valid synthetic files ---- */

static const float *blob_f(const sy_blob *b) { return b ? (const float *)sy_blob_data(b) : NULL; }

static void test_valid(void)
{
    char path[512];
    sy_scene *s = NULL;

    /* animations[0]: a static load places nodes at the first frame (LINEAR: first output value;
     * CUBICSPLINE: the value of the first (in-tangent, value, out-tangent) triple) */
    {
        float data[2 + 6 + 12] = {0, 1, 1, 2, 3, 4, 5, 6, /* cubic scale: */ 9, 9, 9, 2, 2, 2, 9, 9, 9, 0, 0, 0};
        const char *fmt = "{" ASSET ",\"buffers\":[{\"byteLength\":80,\"uri\":\"%s\"}],"
                          "\"bufferViews\":[{\"buffer\":0,\"byteLength\":80}],"
                          "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":2,\"type\":\"SCALAR\",\"min\":[0],\"max\":[1]},"
                          "{\"bufferView\":0,\"byteOffset\":8,\"componentType\":5126,\"count\":2,\"type\":\"VEC3\"},"
                          "{\"bufferView\":0,\"byteOffset\":32,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"}],"
                          "\"nodes\":[{\"name\":\"moved\",\"translation\":[7,7,7]}],"
                          "\"animations\":[{\"samplers\":[{\"input\":0,\"output\":1},{\"input\":0,\"output\":2,\"interpolation\":\"CUBICSPLINE\"}],"
                          "\"channels\":[{\"sampler\":0,\"target\":{\"node\":0,\"path\":\"translation\"}},"
                          "{\"sampler\":1,\"target\":{\"node\":0,\"path\":\"scale\"}}]}]}";
        if (write_load("anim.gltf", fmt, data, sizeof data, path, &s)) {
            EXPECT_MSG(moved_to(s, 1, 3), "first frame translation (1, 2, 3), not the static (7, 7, 7)");
            const sy_node_data *nd = node_named(s, "moved");
            EXPECT_MSG(nd && nd->transform.scale[0] == 2 && nd->transform.scale[2] == 2, "CUBICSPLINE first value (2, 2, 2)");
        }
        sy_scene_destroy(s);
        s = NULL;
    }

    /* issue 14 (finding 3): an animation output accessor without bufferView declares 2^40 elements;
     * only its first value is used (here a sparse substitution), so the count costs nothing. Before
     * the fix the whole accessor was read: calloc of 12 TiB (out of memory; ASan: abort). */
    {
        uint8_t data[24];
        const float in[2] = {0, 1}, val[3] = {4, 5, 6};
        const uint32_t sidx = 0;
        memcpy(data, in, 8);
        memcpy(data + 8, &sidx, 4);
        memcpy(data + 12, val, 12);
        const char *fmt = "{" ASSET ",\"buffers\":[{\"byteLength\":24,\"uri\":\"%s\"}],"
                          "\"bufferViews\":[{\"buffer\":0,\"byteLength\":8},{\"buffer\":0,\"byteOffset\":8,\"byteLength\":4},"
                          "{\"buffer\":0,\"byteOffset\":12,\"byteLength\":12}],"
                          "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":2,\"type\":\"SCALAR\",\"min\":[0],\"max\":[1]},"
                          "{\"componentType\":5126,\"count\":1099511627776,\"type\":\"VEC3\",\"sparse\":{\"count\":1,"
                          "\"indices\":{\"bufferView\":1,\"componentType\":5125},\"values\":{\"bufferView\":2}}}],"
                          "\"nodes\":[{\"name\":\"moved\"}],"
                          "\"animations\":[{\"samplers\":[{\"input\":0,\"output\":1}],"
                          "\"channels\":[{\"sampler\":0,\"target\":{\"node\":0,\"path\":\"translation\"}}]}]}";
        if (write_load("anim_output_count.gltf", fmt, data, sizeof data, path, &s))
            EXPECT_MSG(moved_to(s, 4, 6), "anim_output_count: first frame translation (4, 5, 6) from the sparse value");
        sy_scene_destroy(s);
        s = NULL;
    }

    /* strip and fan over 4 non-indexed vertices, plus a sparse POSITION accessor without bufferView */
    {
        float pos[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
        uint8_t buf[64] = {0};
        memcpy(buf, pos, sizeof pos);
        uint16_t sidx[2] = {1, 0};
        float sval[3] = {5, 6, 7};
        memcpy(buf + 48, sidx, 4);
        memcpy(buf + 52, sval, 12);
        const char *fmt = "{" ASSET ",\"buffers\":[{\"byteLength\":64,\"uri\":\"%s\"}],"
                          "\"bufferViews\":[{\"buffer\":0,\"byteLength\":48},{\"buffer\":0,\"byteOffset\":48,\"byteLength\":4},{\"buffer\":0,\"byteOffset\":52,\"byteLength\":12}],"
                          "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"},"
                          "{\"componentType\":5126,\"count\":3,\"type\":\"VEC3\",\"sparse\":{\"count\":1,\"indices\":{\"bufferView\":1,\"componentType\":5123},\"values\":{\"bufferView\":2}}}],"
                          "\"meshes\":[{\"name\":\"strip\",\"primitives\":[{\"attributes\":{\"POSITION\":0},\"mode\":5}]},"
                          "{\"name\":\"fan\",\"primitives\":[{\"attributes\":{\"POSITION\":0},\"mode\":6}]},"
                          "{\"name\":\"sparse\",\"primitives\":[{\"attributes\":{\"POSITION\":1}}]}],"
                          "\"nodes\":[{\"mesh\":0},{\"mesh\":1},{\"mesh\":2}]}";
        if (write_load("modes.gltf", fmt, buf, sizeof buf, path, &s)) {
            const uint32_t want_strip[6] = {0, 1, 2, 1, 3, 2}, want_fan[6] = {1, 2, 0, 2, 3, 0};
            EXPECT_MSG(sy_scene_count(s, SY_TYPE_NODE) == 4, "modes.gltf: parentless nodes become roots");
            for (uint32_t id = sy_scene_next(s, SY_TYPE_MESH, 0); id; id = sy_scene_next(s, SY_TYPE_MESH, id)) {
                const sy_mesh_data *m = sy_mesh_get(s, (sy_mesh){id});
                EXPECT_MSG(m->primitives.count == 1, "one primitive");
                const sy_primitive *p = &m->primitives.items[0];
                if (!strcmp(m->name, "sparse")) {
                    const float *f = blob_f(p->positions);
                    EXPECT_MSG(f && f[0] == 0 && f[3] == 5 && f[4] == 6 && f[5] == 7 && f[6] == 0, "sparse values");
                    EXPECT_MSG(p->indices == NULL, "non-indexed list stays non-indexed");
                    continue;
                }
                const uint32_t *want = !strcmp(m->name, "strip") ? want_strip : want_fan;
                /* no NORMAL: flat-shaded, which leaves the vertices as they are (no normals made, not
                 * de-indexed); the strip or fan becomes a list of indices into them */
                EXPECT_MSG(p->indices && sy_blob_size(p->indices) == 6 * sizeof(uint32_t) && sy_primitive_vertex_count(p) == 4 &&
                               !p->normals,
                           "%s: 2 flat-shaded triangles over the 4 vertices", m->name);
                const float *f = blob_f(p->positions);
                EXPECT_MSG(f && !memcmp(f, pos, sizeof pos), "%s: positions unchanged", m->name);
                const uint32_t *ix = p->indices ? sy_blob_data(p->indices) : NULL;
                for (int k = 0; ix && k < 6 && sy_blob_size(p->indices) == 24; k++)
                    EXPECT_MSG(ix[k] == want[k], "%s: winding, corner %d: index %u, expected %u", m->name, k, ix[k], want[k]);
            }
        }
        sy_scene_destroy(s);
        s = NULL;
    }

    /* issue 39: an indexed cube without NORMAL (8 shared corners, 36 indices) with TEXCOORD_0, a
     * TANGENT the spec says to ignore without normals, and a normal-mapped material: it keeps its 8
     * vertices and its index buffer (flat shading is the back-ends' job), has neither normals nor
     * tangents, and the normal map loads (no tangents are generated for it) */
    {
        struct {
            float pos[24], uv[16], tan[32];
            uint16_t idx[36];
        } cube;
        for (int v = 0; v < 8; v++) {
            for (int a = 0; a < 3; a++) cube.pos[3 * v + a] = (v >> a & 1) ? 0.5f : -0.5f;
            cube.uv[2 * v] = (float)(v & 1), cube.uv[2 * v + 1] = (float)(v >> 1 & 1);
            const float t[4] = {1, 0, 0, 1};
            memcpy(cube.tan + 4 * v, t, sizeof t);
        }
        for (int f = 0; f < 6; f++) { /* face f: axis f / 2, side f % 2; corners in cyclic order */
            int a = f / 2, u = (a + 1) % 3, w = (a + 2) % 3, side = f % 2, c[4];
            const int cu[4] = {0, 1, 1, 0}, cw[4] = {0, 0, 1, 1};
            for (int k = 0; k < 4; k++) c[k] = side << a | cu[k] << u | cw[k] << w;
            /* (u, w, a) is right-handed: this order winds counter-clockwise about +a */
            const int t6[6] = {0, 1, 2, 0, 2, 3}, r6[6] = {0, 2, 1, 0, 3, 2};
            for (int k = 0; k < 6; k++) cube.idx[6 * f + k] = (uint16_t)c[side ? t6[k] : r6[k]];
        }
        char fmt[4096];
        snprintf(fmt, sizeof fmt,
                 "{" ASSET ",\"buffers\":[{\"byteLength\":%zu,\"uri\":\"%%s\"}],"
                 "\"bufferViews\":[{\"buffer\":0,\"byteLength\":96},{\"buffer\":0,\"byteOffset\":96,\"byteLength\":64},"
                 "{\"buffer\":0,\"byteOffset\":160,\"byteLength\":128},{\"buffer\":0,\"byteOffset\":288,\"byteLength\":72}],"
                 "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":8,\"type\":\"VEC3\"},"
                 "{\"bufferView\":1,\"componentType\":5126,\"count\":8,\"type\":\"VEC2\"},"
                 "{\"bufferView\":2,\"componentType\":5126,\"count\":8,\"type\":\"VEC4\"},"
                 "{\"bufferView\":3,\"componentType\":5123,\"count\":36,\"type\":\"SCALAR\"}],"
                 "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1,\"TANGENT\":2},\"indices\":3,\"material\":0}]}],"
                 "\"materials\":[{\"normalTexture\":{\"index\":0}}],\"textures\":[{\"source\":0}],\"images\":[{\"uri\":\"%s\"}],"
                 "\"nodes\":[{\"mesh\":0}]," SCENES "}",
                 sizeof cube, k_png_uri);
        if (write_load("flat_cube.gltf", fmt, &cube, sizeof cube, path, &s)) {
            const sy_mesh_data *m = sy_mesh_get(s, (sy_mesh){sy_scene_next(s, SY_TYPE_MESH, 0)});
            const sy_primitive *p = m && m->primitives.count == 1 ? &m->primitives.items[0] : NULL;
            EXPECT_MSG(p && sy_primitive_vertex_count(p) == 8 && p->indices && sy_blob_size(p->indices) == 36 * sizeof(uint32_t),
                       "flat_cube: 8 shared vertices and 36 indices kept (%u vertices)", p ? (unsigned)sy_primitive_vertex_count(p) : 0u);
            EXPECT_MSG(p && !p->normals && !p->tangents && p->texcoords0, "flat_cube: no normals, the file's tangents ignored, uv kept");
            const uint32_t *ix = p && p->indices ? sy_blob_data(p->indices) : NULL;
            for (int k = 0; ix && k < 36 && sy_blob_size(p->indices) == 36 * sizeof(uint32_t); k++)
                EXPECT_MSG(ix[k] == cube.idx[k], "flat_cube: index %d is %u, expected %u", k, ix[k], cube.idx[k]);
            const float *f = p ? blob_f(p->positions) : NULL;
            EXPECT_MSG(f && sy_blob_size(p->positions) == sizeof cube.pos && !memcmp(f, cube.pos, sizeof cube.pos),
                       "flat_cube: positions unchanged");
            const sy_material_data *md = p ? sy_material_get(s, p->material) : NULL;
            EXPECT_MSG(md && md->normal_texture.texture.id, "flat_cube: the normal map is kept");
        }
        sy_scene_destroy(s);
        s = NULL;
    }

    /* one glTF texture used as colour and as data: two sy textures; transform, sampler, colours */
    {
        uint8_t buf[56];
        std_buffer b = standard_buffer();
        memcpy(buf, &b, 44);
        const uint8_t cols[12] = {255, 0, 0, 0, 0, 255, 0, 0, 0, 0, 255, 0};
        memcpy(buf + 44, cols, 12);
        char fmt[4096];
        snprintf(fmt, sizeof fmt,
                 "{" ASSET ",\"buffers\":[{\"byteLength\":56,\"uri\":\"%%s\"}],"
                 "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":6},{\"buffer\":0,\"byteOffset\":44,\"byteLength\":12,\"byteStride\":4}],"
                 "\"accessors\":[" ACC_POS "," ACC_IDX ",{\"bufferView\":2,\"componentType\":5121,\"normalized\":true,\"count\":3,\"type\":\"VEC3\"}],"
                 "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"COLOR_0\":2},\"indices\":1,\"material\":0}]}],"
                 "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0,\"extensions\":{\"KHR_texture_transform\":{\"offset\":[0.5,0.25],\"rotation\":1.5,\"scale\":[2,3]}}}},"
                 "\"normalTexture\":{\"index\":0,\"scale\":0.5},\"emissiveFactor\":[1,1,1],"
                 "\"extensions\":{\"KHR_materials_emissive_strength\":{\"emissiveStrength\":3},\"KHR_materials_ior\":{\"ior\":1.3},\"KHR_materials_transmission\":{\"transmissionFactor\":0.75},"
                 "\"KHR_materials_clearcoat\":{\"clearcoatFactor\":2,\"clearcoatNormalTexture\":{\"index\":0,\"scale\":0.25}},"
                 "\"KHR_materials_volume\":{\"thicknessFactor\":0.5,\"attenuationDistance\":-1}}}],"
                 "\"textures\":[{\"source\":0,\"sampler\":0}],\"samplers\":[{\"wrapS\":33071,\"wrapT\":33648,\"magFilter\":9728}],"
                 "\"images\":[{\"uri\":\"%s\"}],"
                 "\"cameras\":[{\"name\":\"cam\",\"type\":\"perspective\",\"perspective\":{\"yfov\":0.5,\"znear\":0.1}}],"
                 "\"nodes\":[{\"mesh\":0,\"children\":[1]},{\"camera\":0,\"name\":\"eye\"}]," SCENES ","
                 "\"extensionsRequired\":[\"KHR_texture_transform\"]}",
                 k_png_uri);
        write_gltf("textures.gltf", fmt, buf, sizeof buf, path);
        sy_gltf_info info;
        sy_error e = {0};
        sy_scene_create(&s, &e);
        sy_result r = sy_gltf_load(path, s, NULL, &info, &e);
        EXPECT_MSG(r == SY_OK, "textures.gltf: %s", e.message);
        if (r == SY_OK) {
            EXPECT_MSG(sy_scene_count(s, SY_TYPE_TEXTURE) == 2, "two textures for two roles");
            const sy_material_data *m = sy_material_get(s, (sy_material){sy_scene_next(s, SY_TYPE_MATERIAL, 0)});
            const sy_texture_data *bc = sy_texture_get(s, m->base_color_texture.texture);
            const sy_texture_data *nm = sy_texture_get(s, m->normal_texture.texture);
            EXPECT_MSG(bc && nm && bc != nm, "distinct textures");
            EXPECT_MSG(bc && bc->info.format == SY_PIXEL_U8_SRGB && bc->info.width == 2 && bc->info.channels == 4, "colour texture");
            EXPECT_MSG(nm && nm->info.format == SY_PIXEL_U8_LINEAR, "data texture");
            EXPECT_MSG(bc && nm && sy_hash_equal(sy_blob_hash(bc->pixels), sy_blob_hash(nm->pixels)), "same pixels");
            EXPECT_MSG(bc && bc->sampler.wrap_s == SY_WRAP_CLAMP && bc->sampler.wrap_t == SY_WRAP_MIRROR &&
                       bc->sampler.mag_filter == SY_FILTER_NEAREST,
                       "sampler");
            EXPECT_MSG(bc && ((const uint8_t *)sy_blob_data(bc->pixels))[15] == 128, "pixel alpha");
            EXPECT_MSG(m->base_color_texture.offset[0] == 0.5f && m->base_color_texture.offset[1] == 0.25f &&
                       m->base_color_texture.rotation == 1.5f && m->base_color_texture.uv_scale[1] == 3.0f,
                       "texture transform");
            EXPECT_MSG(m->normal_texture.scale == 0.5f && m->emissive_strength == 3.0f && fabsf(m->ior - 1.3f) < 1e-6f &&
                       m->transmission == 0.75f,
                       "material extensions");
            /* out of range: clamped with a warning naming material and factor; the coat's normal map
             * is the normal texture's (data role) */
            EXPECT_MSG(m->clearcoat == 1.0f && m->clearcoat_normal_texture.scale == 0.25f &&
                           m->clearcoat_normal_texture.texture.id == m->normal_texture.texture.id,
                       "clearcoat %g, normal scale %g", (double)m->clearcoat, (double)m->clearcoat_normal_texture.scale);
            EXPECT_MSG(m->thickness == 0.5f && m->attenuation_distance == 0.0f, "volume");
            bool clamp_warned = false, attenuation_warned = false;
            for (uint32_t w = 0; w < info.stored_warning_count; w++) {
                clamp_warned |= strstr(info.warnings[w], "materials[0].KHR_materials_clearcoat.clearcoatFactor: 2 is outside") != NULL;
                attenuation_warned |= strstr(info.warnings[w], "attenuationDistance: -1 is outside") != NULL;
            }
            EXPECT_MSG(clamp_warned && attenuation_warned, "clamping warned (%u warnings)", info.stored_warning_count);
            const sy_mesh_data *md = sy_mesh_get(s, (sy_mesh){sy_scene_next(s, SY_TYPE_MESH, 0)});
            const float *col = blob_f(md->primitives.items[0].colors);
            EXPECT_MSG(col && col[0] == 1 && col[1] == 0 && col[3] == 1 && col[5] == 1 && col[7] == 1, "vec3 unorm colours: %g %g %g %g / %g %g %g %g",
                       col ? col[0] : -1, col ? col[1] : -1, col ? col[2] : -1, col ? col[3] : -1, col ? col[4] : -1,
                       col ? col[5] : -1, col ? col[6] : -1, col ? col[7] : -1);
            EXPECT_MSG(info.camera_node_count == 1, "camera list");
            sy_node cn;
            EXPECT_MSG(sy_gltf_find_camera(s, &info, "cam", &cn, &e) == SY_OK, "find by camera name");
            EXPECT_MSG(sy_gltf_find_camera(s, &info, "eye", &cn, &e) == SY_OK, "find by node name");
            const sy_camera_data *cd = sy_camera_get(s, sy_node_get(s, cn)->camera);
            EXPECT_MSG(cd && cd->aspect == 0 && cd->zfar == 0, "absent aspect / zfar are 0");
        }
        sy_gltf_info_free(&info);
        sy_scene_destroy(s);
        s = NULL;
    }

    /* the same model as .gltf and as .glb: deep-equal scenes */
    {
        std_buffer b = standard_buffer();
        write_gltf("same.gltf", STD, &b, sizeof b, path);
        const char *json = "{" ASSET ",\"buffers\":[{\"byteLength\":44}]," VIEWS "," ACCS "," MESHES "," MATS "," NODES "," SCENES "}";
        size_t n;
        uint8_t *g = make_glb(json, &b, sizeof b, &n);
        char gpath[512];
        write_file("same.glb", g, n, gpath);
        free(g);
        sy_scene *a = NULL, *c = NULL;
        outcome o1 = run(path, NULL, &a), o2 = run(gpath, NULL, &c);
        EXPECT_MSG(o1.r == SY_OK && o2.r == SY_OK, "same: %s / %s", o1.err.message, o2.err.message);
        if (a && c) {
            sy_error diff = {0};
            EXPECT_MSG(sy_scene_equal(a, c, &diff), "gltf vs glb: %s", diff.message);
        }
        sy_scene_destroy(a);
        sy_scene_destroy(c);
    }
}

/* KHR_materials_variants: the mappings land in the info, switching sets the primitives' materials
 * (and back), an unknown variant lists the file's, a mapping naming a missing variant is refused. */
static void test_variants(void)
{
    const char *mats = "\"materials\":[{\"name\":\"red\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[1,0,0,1]}},"
                       "{\"name\":\"green\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[0,1,0,1]}},"
                       "{\"name\":\"blue\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[0,0,1,1]}}]";
    for (int bad = 0; bad < 2; bad++) {
        char fmt[2048], path[512];
        snprintf(fmt, sizeof fmt,
                 "{" ASSET ",\"buffers\":[{\"byteLength\":44,\"uri\":\"%%s\"}]," VIEWS "," ACCS ","
                 "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1,\"material\":0,"
                 "\"extensions\":{\"KHR_materials_variants\":{\"mappings\":[{\"material\":1,\"variants\":[0]},"
                 "{\"material\":2,\"variants\":[%s]}]}}}]}],"
                 "%s," NODES "," SCENES ","
                 "\"extensions\":{\"KHR_materials_variants\":{\"variants\":[{\"name\":\"Leaf\"},{\"name\":\"Sky\"}]}},"
                 "\"extensionsUsed\":[\"KHR_materials_variants\"]}",
                 bad ? "5" : "1", mats);
        std_buffer b = standard_buffer();
        write_gltf(bad ? "variants_bad.gltf" : "variants.gltf", fmt, &b, sizeof b, path);
        sy_scene *s = NULL;
        sy_gltf_info info;
        sy_error e = {0};
        sy_scene_create(&s, &e);
        sy_result r = sy_gltf_load(path, s, NULL, &info, &e);
        if (bad) {
            EXPECT_MSG(r == SY_ERR_PARSE && strstr(e.message, "variants_bad.gltf") &&
                           strstr(e.message, "meshes[0].primitives[0].KHR_materials_variants") && strstr(e.message, "variant 5"),
                       "a mapping naming variant 5 of 2: %s", e.message);
        } else {
            EXPECT_MSG(r == SY_OK, "variants.gltf: %s", e.message);
            EXPECT_MSG(info.variant_count == 2 && !strcmp(info.variant_names[1], "Sky") && info.variant_use_count == 2,
                       "variant info");
            sy_mesh mesh = {sy_scene_next(s, SY_TYPE_MESH, 0)};
#define PRIM_COLOR(k) (sy_material_get(s, sy_mesh_get(s, mesh)->primitives.items[0].material)->base_color[k])
            EXPECT(PRIM_COLOR(0) == 1.0f); /* the default: red */
            EXPECT_MSG(sy_gltf_select_variant(s, &info, "Sky", &e) == SY_OK && PRIM_COLOR(2) == 1.0f && PRIM_COLOR(0) == 0.0f,
                       "Sky: %s", e.message);
            EXPECT_MSG(sy_gltf_select_variant(s, &info, "0", &e) == SY_OK && PRIM_COLOR(1) == 1.0f, "variant 0: %s", e.message);
            EXPECT_MSG(sy_gltf_select_variant(s, &info, NULL, &e) == SY_OK && PRIM_COLOR(0) == 1.0f, "default: %s", e.message);
#undef PRIM_COLOR
            r = sy_gltf_select_variant(s, &info, "Night", &e);
            EXPECT_MSG(r == SY_ERR_NOT_FOUND && strstr(e.message, "0 \"Leaf\", 1 \"Sky\""), "unknown variant: %s", e.message);
            sy_gltf_info_free(&info);
        }
        sy_scene_destroy(s);
    }
}

int main(void)
{
    make_scratch_dir(g_dir, sizeof g_dir, "gltf_test");
    long blobs = sy_blob_live_count();
    test_bad_json();
    test_bad_data();
    test_bad_glb();
    test_valid();
    test_variants();
    EXPECT_MSG(sy_blob_live_count() == blobs, "blob leak");
    char cmd[512];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", g_dir);
    if (system(cmd) != 0) fprintf(stderr, "warning: could not remove %s\n", g_dir);
    return sy_check_finish("gltf_input");
}
