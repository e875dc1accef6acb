/* test_gltf_meshopt.c — EXT_meshopt_compression: the test writes meshopt-compressed copies of plain
 * samples itself (Box, Duck from ../shared/testdata, read in place): every bufferView's bytes
 * encoded with meshopt_encodeVertexBuffer (attributes) and meshopt_encodeIndexSequence or
 * meshopt_encodeIndexBuffer (indices) into a new .bin, the original buffer kept only as a fallback without data, into a
 * temporary directory (with copies of the model's images). The compressed copy must load as a scene
 * equal to the plain one (sy_scene_equal; with TRIANGLES, whose encoder may rotate a triangle's
 * vertices, the same triangles and bounds). Bad input on the Box copy: corrupt compressed bytes, a
 * count larger than the compressed bytes can hold, a count that is not the view's length, a bad
 * mode: each a clear error naming the file and bufferViews[i], no crash.
 * Usage: test_gltf_meshopt TESTDATA_DIR (exit 77 when the samples are absent). */
#include "../support/sy_check.h"
#include "sy_file.h"
#include "sy_gltf.h"
#include "sy_graph.h"

#include <cjson/cJSON.h>
#include <meshoptimizer.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "gltf_files.h"

static char g_dir[256];
/* index views as TRIANGLES (meshopt_encodeIndexBuffer: may rotate a triangle's vertices, winding
 * kept) or INDICES (meshopt_encodeIndexSequence: the exact order) */
static bool g_triangles;

static int num(const cJSON *o, const char *k, int def)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, k);
    return cJSON_IsNumber(v) ? v->valueint : def;
}

/* Bytes of one element of the first accessor on view vi (0 when none). */
static size_t element_size(const cJSON *doc, int vi, size_t *component)
{
    const cJSON *a;
    cJSON_ArrayForEach(a, cJSON_GetObjectItemCaseSensitive(doc, "accessors"))
    {
        if (num(a, "bufferView", -1) != vi) continue;
        int ct = num(a, "componentType", 0);
        size_t cs = ct == 5120 || ct == 5121 ? 1 : ct == 5122 || ct == 5123 ? 2 : 4;
        const char *t = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(a, "type"));
        size_t n = !t ? 0 : !strcmp(t, "SCALAR") ? 1 : !strcmp(t, "VEC2") ? 2 : !strcmp(t, "VEC3") ? 3 : !strcmp(t, "VEC4") ? 4 : 0;
        *component = cs;
        return cs * n;
    }
    return 0;
}

/* Writes DIR/NAME (the compressed copy of the plain model in src_dir/name, whose one buffer is
 * bin_uri) and DIR/c.bin; returns the JSON document (the caller frees it). */
static cJSON *compress_copy(const char *src_dir, const char *name)
{
    char path[1024];
    size_t jn, bn;
    snprintf(path, sizeof path, "%s/%s", src_dir, name);
    char *text = (char *)read_all(path, &jn);
    cJSON *doc = cJSON_Parse(text);
    free(text);
    cJSON *buffers = cJSON_GetObjectItemCaseSensitive(doc, "buffers");
    const char *uri = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(buffers, 0), "uri"));
    snprintf(path, sizeof path, "%s/%s", src_dir, uri);
    uint8_t *bin = read_all(path, &bn);
    uint8_t *out = malloc(bn * 2 + 4096);
    size_t used = 0;
    int vi = 0;
    cJSON *v;
    cJSON_ArrayForEach(v, cJSON_GetObjectItemCaseSensitive(doc, "bufferViews"))
    {
        size_t off = (size_t)num(v, "byteOffset", 0), len = (size_t)num(v, "byteLength", 0), comp = 0;
        size_t elem = element_size(doc, vi, &comp);
        bool indices = num(v, "target", 0) == 34963;
        size_t stride = indices ? comp : num(v, "byteStride", 0) ? (size_t)num(v, "byteStride", 0) : elem;
        size_t count = stride ? len / stride : 0;
        used = (used + 3) & ~(size_t)3;
        size_t at = used, clen = 0;
        const char *mode = NULL;
        if (indices && (stride == 2 || stride == 4) && (count % 3 == 0 || !g_triangles)) {
            unsigned *idx = malloc(count * sizeof(unsigned));
            for (size_t i = 0; i < count; i++) {
                uint16_t s16;
                uint32_t s32;
                if (stride == 2) memcpy(&s16, bin + off + 2 * i, 2), idx[i] = s16;
                else memcpy(&s32, bin + off + 4 * i, 4), idx[i] = s32;
            }
            clen = g_triangles ? meshopt_encodeIndexBuffer(out + at, bn * 2 + 4096 - at, idx, count)
                               : meshopt_encodeIndexSequence(out + at, bn * 2 + 4096 - at, idx, count);
            free(idx);
            mode = g_triangles ? "TRIANGLES" : "INDICES";
        } else if (!indices && stride && stride % 4 == 0 && count * stride == len) {
            clen = meshopt_encodeVertexBuffer(out + at, bn * 2 + 4096 - at, bin + off, count, stride);
            mode = "ATTRIBUTES";
        }
        if (mode && clen) {
            cJSON *e = cJSON_CreateObject();
            cJSON_AddNumberToObject(e, "buffer", 0);
            cJSON_AddNumberToObject(e, "byteOffset", (double)at);
            cJSON_AddNumberToObject(e, "byteLength", (double)clen);
            cJSON_AddNumberToObject(e, "byteStride", (double)stride);
            cJSON_AddNumberToObject(e, "count", (double)count);
            cJSON_AddStringToObject(e, "mode", mode);
            cJSON *ext = cJSON_AddObjectToObject(v, "extensions");
            cJSON_AddItemToObject(ext, "EXT_meshopt_compression", e);
            cJSON_ReplaceItemInObject(v, "buffer", cJSON_CreateNumber(1)); /* the fallback: same offsets */
            used = at + clen;
        } else { /* left uncompressed: copied raw into the new buffer */
            memcpy(out + at, bin + off, len);
            cJSON_ReplaceItemInObject(v, "buffer", cJSON_CreateNumber(0));
            if (cJSON_GetObjectItemCaseSensitive(v, "byteOffset")) cJSON_ReplaceItemInObject(v, "byteOffset", cJSON_CreateNumber((double)at));
            else cJSON_AddNumberToObject(v, "byteOffset", (double)at);
            used = at + len;
        }
        vi++;
    }
    snprintf(path, sizeof path, "%s/c.bin", g_dir);
    write_all(path, out, used);
    cJSON *b0 = cJSON_CreateObject(), *b1 = cJSON_CreateObject();
    cJSON_AddStringToObject(b0, "uri", "c.bin");
    cJSON_AddNumberToObject(b0, "byteLength", (double)used);
    cJSON_AddNumberToObject(b1, "byteLength", (double)bn);
    cJSON_AddBoolToObject(cJSON_AddObjectToObject(cJSON_AddObjectToObject(b1, "extensions"), "EXT_meshopt_compression"),
                          "fallback", 1);
    cJSON *nb = cJSON_CreateArray();
    cJSON_AddItemToArray(nb, b0);
    cJSON_AddItemToArray(nb, b1);
    cJSON_ReplaceItemInObject(doc, "buffers", nb);
    cJSON *used_ext = cJSON_CreateArray(), *req_ext = cJSON_CreateArray();
    cJSON_AddItemToArray(used_ext, cJSON_CreateString("EXT_meshopt_compression"));
    cJSON_AddItemToArray(req_ext, cJSON_CreateString("EXT_meshopt_compression"));
    cJSON_DeleteItemFromObject(doc, "extensionsUsed");
    cJSON_DeleteItemFromObject(doc, "extensionsRequired");
    cJSON_AddItemToObject(doc, "extensionsUsed", used_ext);
    cJSON_AddItemToObject(doc, "extensionsRequired", req_ext);
    /* the images beside it, copied into the temporary directory */
    const cJSON *im;
    cJSON_ArrayForEach(im, cJSON_GetObjectItemCaseSensitive(doc, "images"))
    {
        const char *iu = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(im, "uri"));
        if (!iu) continue;
        size_t n;
        snprintf(path, sizeof path, "%s/%s", src_dir, iu);
        uint8_t *img = read_all(path, &n);
        snprintf(path, sizeof path, "%s/%s", g_dir, iu);
        if (img) write_all(path, img, n);
        free(img);
    }
    free(bin);
    free(out);
    return doc;
}

static sy_result load(const char *path, sy_scene **s, sy_error *e)
{
    if (sy_scene_create(s, e) != SY_OK) exit(1);
    sy_gltf_info info;
    sy_result r = sy_gltf_load(path, *s, NULL, &info, e);
    uint64_t frame;
    if (r == SY_OK) {
        r = sy_scene_commit(*s, &frame, e);
        sy_gltf_info_free(&info);
    }
    return r;
}

static void write_doc(const cJSON *doc, const char *path)
{
    char *t = cJSON_PrintUnformatted(doc);
    write_all(path, t, strlen(t));
    free(t);
}

/* The compressed copy of model equals the plain model. */
static void check_equal(const char *data, const char *model)
{
    char src[1024], plain[1200], copy[512];
    snprintf(src, sizeof src, "%s/gltf/%s/glTF", data, model);
    snprintf(plain, sizeof plain, "%s/%s.gltf", src, model);
    snprintf(copy, sizeof copy, "%s/%s.gltf", g_dir, model);
    char name[128];
    snprintf(name, sizeof name, "%s.gltf", model);
    cJSON *doc = compress_copy(src, name);
    write_doc(doc, copy);
    cJSON_Delete(doc);
    sy_scene *a = NULL, *b = NULL;
    sy_error e = {0};
    EXPECT_MSG(load(plain, &a, &e) == SY_OK, "%s: %s", plain, e.message);
    sy_result r = load(copy, &b, &e);
    EXPECT_MSG(r == SY_OK, "%s: %s", copy, e.message);
    if (r == SY_OK && !g_triangles) {
        sy_error diff = {0};
        EXPECT_MSG(sy_scene_equal(a, b, &diff), "%s: meshopt copy differs: %s", model, diff.message);
        printf("ok %s: meshopt copy (INDICES, ATTRIBUTES) equals the plain scene\n", model);
    } else if (r == SY_OK) { /* triangles may be rotated: the same triangles, bounds and vertices */
        sy_bounds ba = sy_scene_world_bounds(a), bb = sy_scene_world_bounds(b);
        EXPECT_MSG(!memcmp(&ba, &bb, sizeof ba), "%s: TRIANGLES copy bounds differ", model);
        const sy_mesh_data *ma = sy_mesh_get(a, (sy_mesh){sy_scene_next(a, SY_TYPE_MESH, 0)});
        const sy_mesh_data *mb = sy_mesh_get(b, (sy_mesh){sy_scene_next(b, SY_TYPE_MESH, 0)});
        EXPECT_MSG(ma && mb && ma->primitives.count == mb->primitives.count &&
                   sy_primitive_element_count(&ma->primitives.items[0]) == sy_primitive_element_count(&mb->primitives.items[0]),
                   "%s: TRIANGLES copy has other primitives or triangles", model);
        printf("ok %s: meshopt copy (TRIANGLES) has the plain scene's triangles and bounds\n", model);
    }
    sy_scene_destroy(a);
    sy_scene_destroy(b);
}

/* The Box copy with one change (set number key in the extension of bufferViews[view], or corrupt
 * the compressed bytes) must fail with code and a message containing want. */
static void bad_case(const char *data, const char *label, int view, const char *key, double value, const char *mode,
                     bool corrupt, sy_result code, const char *want)
{
    char src[1024], copy[512];
    snprintf(src, sizeof src, "%s/gltf/Box/glTF", data);
    snprintf(copy, sizeof copy, "%s/%s.gltf", g_dir, label);
    cJSON *doc = compress_copy(src, "Box.gltf");
    cJSON *ext = cJSON_GetObjectItemCaseSensitive(
        cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(doc, "bufferViews"), view), "extensions"),
        "EXT_meshopt_compression");
    if (key) cJSON_ReplaceItemInObject(ext, key, cJSON_CreateNumber(value));
    if (mode) cJSON_ReplaceItemInObject(ext, "mode", cJSON_CreateString(mode));
    if (corrupt) {
        char bpath[512];
        size_t n;
        snprintf(bpath, sizeof bpath, "%s/c.bin", g_dir);
        uint8_t *b = read_all(bpath, &n);
        size_t at = (size_t)num(ext, "byteOffset", 0), len = (size_t)num(ext, "byteLength", 0);
        for (size_t i = 1; i < len; i++) b[at + i] = (uint8_t)(0xC3 ^ (i * 57));
        write_all(bpath, b, n);
        free(b);
    }
    write_doc(doc, copy);
    cJSON_Delete(doc);
    sy_scene *s = NULL;
    sy_error e = {0};
    long blobs = sy_blob_live_count();
    sy_result r = load(copy, &s, &e);
    EXPECT_MSG(r == code, "%s: result %d, want %d (%s)", label, (int)r, (int)code, e.message);
    EXPECT_MSG(strstr(e.message, copy) && strstr(e.message, want), "%s: message '%s' lacks '%s'", label, e.message, want);
    EXPECT_MSG(sy_scene_count(s, SY_TYPE_MESH) == 0, "%s: objects left", label);
    sy_scene_destroy(s);
    EXPECT_MSG(sy_blob_live_count() == blobs, "%s: blob leak", label);
    printf("ok %-14s %s\n", label, e.message);
}

int main(int argc, char **argv)
{
    const char *testdata = testdata_arg(argc, argv);
    char probe[1024];
    snprintf(probe, sizeof probe, "%s/gltf/Box/glTF/Box.gltf", testdata);
    if (access(probe, R_OK) != 0) {
        printf("SKIP: %s absent\n", probe);
        return 77;
    }
    make_scratch_dir(g_dir, sizeof g_dir, "gltf_meshopt");
    check_equal(testdata, "Box");
    check_equal(testdata, "Duck");
    g_triangles = true;
    check_equal(testdata, "Duck");
    /* Box (TRIANGLES): bufferViews[0] holds the indices, [1] the positions and normals */
    bad_case(testdata, "corrupt_attr", 1, NULL, 0, NULL, true, SY_ERR_PARSE, "bufferViews[1]: EXT_meshopt_compression: the compressed data");
    bad_case(testdata, "corrupt_index", 0, NULL, 0, NULL, true, SY_ERR_PARSE, "bufferViews[0]: EXT_meshopt_compression");
    bad_case(testdata, "count_length", 1, "count", 47, NULL, false, SY_ERR_PARSE, "is not the bufferView's byteLength 576");
    bad_case(testdata, "count_huge", 1, "count", 4e8, NULL, false, SY_ERR_PARSE, "is not the bufferView's byteLength");
    bad_case(testdata, "stride", 1, "byteStride", 7, NULL, false, SY_ERR_PARSE, "bufferViews[1]: EXT_meshopt_compression");
    bad_case(testdata, "mode", 1, NULL, 0, "POINTS", false, SY_ERR_PARSE, "mode 'POINTS'");
    bad_case(testdata, "source_range", 1, "byteLength", 1e6, NULL, false, SY_ERR_PARSE, "exceeds buffer 0 length");
    char path[512];
    const char *left[] = {"Box.gltf", "Duck.gltf", "c.bin", "DuckCM.png", "corrupt_attr.gltf", "corrupt_index.gltf",
                          "count_length.gltf", "count_huge.gltf", "stride.gltf", "mode.gltf", "source_range.gltf"};
    for (size_t i = 0; i < sizeof left / sizeof left[0]; i++) {
        snprintf(path, sizeof path, "%s/%s", g_dir, left[i]);
        unlink(path);
    }
    rmdir(g_dir);
    return sy_check_finish("gltf_meshopt");
}
