/* test_gltf_draco.c — KHR_draco_mesh_compression with bad input: the shared Box/glTF-Draco sample
 * (read in place) is copied into a temporary directory with one thing broken per case (Draco bytes
 * overwritten, the stream cut short, accessor counts that differ from Draco's, counts far beyond
 * the budget, a bufferView out of range). Each must fail with a message naming the file and
 * meshes[0].primitives[0], leave no object and no blob alive; the unbroken copy loads 12 triangles
 * within the Box's bounds. Before that, without shared data: a quad encoded by Draco's own encoder
 * (k_quad_drc below, made with draco::Encoder at 14 bits) loads from .gltf and from .glb (the shim
 * rebuilds the GLB around its placeholder-patched JSON) as the same scene.
 * Usage: test_gltf_draco TESTDATA_DIR (the Box cases are skipped when the sample is absent). */
#include "../support/sy_check.h"
#include "sy_file.h"
#include "sy_gltf.h"
#include "sy_graph.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "gltf_files.h"

static char g_dir[256];

/* Two triangles (0,0,0) (1,0,0) (0,1,0) and (1,0,0) (1,1,0) (0,1,0), 4 points, POSITION id 0. */
static const uint8_t k_quad_drc[] = {
    0x44, 0x52, 0x41, 0x43, 0x4f, 0x02, 0x02, 0x01, 0x01, 0x00, 0x00, 0x00, 0x04, 0x02, 0x00, 0x02,
    0x00, 0x00, 0x01, 0x1f, 0xff, 0x01, 0x11, 0x01, 0xff, 0x00, 0x00, 0x01, 0x00, 0x09, 0x03, 0x00,
    0x00, 0x02, 0x01, 0x01, 0x01, 0x00, 0x03, 0x03, 0x01, 0x30, 0x01, 0x10, 0x03, 0x00, 0x24, 0x82,
    0x4a, 0x04, 0x00, 0x00, 0x00, 0x00, 0xff, 0x3f, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x80, 0x3f, 0x0e
};

/* json with every occurrence of `from` replaced by `to` (malloc()ed); fails the test when absent. */
static char *replace(const char *json, const char *from, const char *to)
{
    size_t fl = strlen(from), tl = strlen(to), n = 0;
    for (const char *p = strstr(json, from); p; p = strstr(p + fl, from)) n++;
    if (n == 0) {
        fprintf(stderr, "'%s' not in Box.gltf\n", from);
        exit(1);
    }
    char *out = malloc(strlen(json) + n * (tl + 1) + 1), *o = out;
    for (const char *p = json, *q; (q = strstr(p, from)); p = q + fl) {
        memcpy(o, p, (size_t)(q - p));
        o += q - p;
        memcpy(o, to, tl);
        o += tl;
        json = q + fl;
    }
    strcpy(o, json);
    return out;
}

/* Writes json + bin as NAME.gltf / Box.bin and loads it: expect SY_OK (want == NULL) or the code and
 * the substring. */
static void run_case(const char *name, const char *json, const void *bin, size_t bin_len, sy_result code, const char *want)
{
    char gpath[512], bpath[512];
    snprintf(gpath, sizeof gpath, "%s/%s.gltf", g_dir, name);
    snprintf(bpath, sizeof bpath, "%s/Box.bin", g_dir);
    write_all(gpath, json, strlen(json));
    write_all(bpath, bin, bin_len);
    sy_scene *s = NULL;
    sy_error e = {0};
    EXPECT_MSG(sy_scene_create(&s, &e) == SY_OK, "scene: %s", e.message);
    long blobs = sy_blob_live_count();
    sy_gltf_info info;
    sy_result r = sy_gltf_load(gpath, s, NULL, &info, &e);
    if (!want) {
        EXPECT_MSG(r == SY_OK, "%s: %s", name, e.message);
        if (r == SY_OK) {
            uint64_t frame;
            EXPECT_MSG(sy_scene_commit(s, &frame, &e) == SY_OK, "%s: commit: %s", name, e.message);
            EXPECT_MSG(info.counts.triangles == 12, "%s: %u triangles", name, info.counts.triangles);
            sy_bounds b = sy_scene_world_bounds(s);
            for (int k = 0; k < 3; k++)
                EXPECT_MSG(fabsf(b.min[k] + 0.5f) < 1e-3f && fabsf(b.max[k] - 0.5f) < 1e-3f, "%s: bounds[%d] %g..%g", name, k,
                           b.min[k], b.max[k]);
        }
        sy_gltf_info_free(&info);
    } else {
        EXPECT_MSG(r == code, "%s: result %d, want %d (%s)", name, (int)r, (int)code, e.message);
        EXPECT_MSG(strstr(e.message, gpath) && strstr(e.message, want), "%s: message '%s' lacks '%s'", name, e.message, want);
        EXPECT_MSG(sy_scene_count(s, SY_TYPE_MESH) == 0 && sy_scene_count(s, SY_TYPE_NODE) == 0, "%s: objects left", name);
        printf("ok %-16s %s\n", name, e.message);
    }
    sy_scene_destroy(s);
    EXPECT_MSG(sy_blob_live_count() == blobs, "%s: blob leak", name);
    unlink(gpath);
    unlink(bpath);
}

static sy_scene *load_quad(const char *path)
{
    sy_scene *s = NULL;
    sy_error e = {0};
    sy_gltf_info info;
    uint64_t frame;
    if (sy_scene_create(&s, &e) != SY_OK) exit(1);
    sy_result r = sy_gltf_load(path, s, NULL, &info, &e);
    EXPECT_MSG(r == SY_OK && sy_scene_commit(s, &frame, &e) == SY_OK, "%s: %s", path, e.message);
    if (r == SY_OK) {
        EXPECT_MSG(info.counts.triangles == 2, "%s: %u triangles", path, info.counts.triangles);
        sy_bounds b = sy_scene_world_bounds(s);
        const float lo[3] = {0, 0, 0}, hi[3] = {1, 1, 0};
        for (int k = 0; k < 3; k++)
            EXPECT_MSG(fabsf(b.min[k] - lo[k]) < 1e-4f && fabsf(b.max[k] - hi[k]) < 1e-4f, "%s: bounds[%d] %g..%g", path, k,
                       b.min[k], b.max[k]);
        sy_gltf_info_free(&info);
    }
    return s;
}

static void put32(uint8_t *p, uint32_t v)
{
    for (int k = 0; k < 4; k++) p[k] = (uint8_t)(v >> (8 * k));
}

/* The generated quad as .gltf (external .bin) and as .glb: both load the same scene. */
static void test_generated_quad(void)
{
    static const char fmt[] =
        "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"KHR_draco_mesh_compression\"],"
        "\"extensionsRequired\":[\"KHR_draco_mesh_compression\"],\"buffers\":[{\"byteLength\":%zu%s}],"
        "\"bufferViews\":[{\"buffer\":0,\"byteLength\":%zu}],\"accessors\":[{\"componentType\":5123,\"count\":6,"
        "\"type\":\"SCALAR\"},{\"componentType\":5126,\"count\":4,\"type\":\"VEC3\",\"min\":[0,0,0],\"max\":[1,1,0]}],"
        "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":1},\"indices\":0,\"extensions\":"
        "{\"KHR_draco_mesh_compression\":{\"bufferView\":0,\"attributes\":{\"POSITION\":0}}}}]}],"
        "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}],\"scene\":0}";
    const size_t n = sizeof k_quad_drc;
    char json[2048], gpath[512], bpath[512], glbpath[512];
    snprintf(gpath, sizeof gpath, "%s/quad.gltf", g_dir);
    snprintf(bpath, sizeof bpath, "%s/quad.bin", g_dir);
    snprintf(glbpath, sizeof glbpath, "%s/quad.glb", g_dir);
    snprintf(json, sizeof json, fmt, n, ",\"uri\":\"quad.bin\"", n);
    write_all(gpath, json, strlen(json));
    write_all(bpath, k_quad_drc, n);
    /* GLB: header, JSON chunk (space-padded), BIN chunk (zero-padded) */
    int jl = snprintf(json, sizeof json, fmt, n, "", n);
    size_t jp = ((size_t)jl + 3) & ~(size_t)3, bp = (n + 3) & ~(size_t)3, total = 12 + 8 + jp + 8 + bp;
    uint8_t *glb = calloc(1, total);
    memcpy(glb, "glTF", 4);
    put32(glb + 4, 2);
    put32(glb + 8, (uint32_t)total);
    put32(glb + 12, (uint32_t)jp);
    memcpy(glb + 16, "JSON", 4);
    memset(glb + 20, ' ', jp);
    memcpy(glb + 20, json, (size_t)jl);
    put32(glb + 20 + jp, (uint32_t)bp);
    memcpy(glb + 24 + jp, "BIN", 4);
    memcpy(glb + 28 + jp, k_quad_drc, n);
    write_all(glbpath, glb, total);
    free(glb);
    sy_scene *a = load_quad(gpath), *b = load_quad(glbpath);
    sy_error diff = {0};
    EXPECT_MSG(sy_scene_equal(a, b, &diff), "quad .gltf vs .glb: %s", diff.message);
    sy_scene_destroy(a);
    sy_scene_destroy(b);
    unlink(gpath);
    unlink(bpath);
    unlink(glbpath);
}

int main(int argc, char **argv)
{
    const char *testdata = testdata_arg(argc, argv);
    char gpath[1024], bpath[1024];
    snprintf(gpath, sizeof gpath, "%s/gltf/Box/glTF-Draco/Box.gltf", testdata);
    snprintf(bpath, sizeof bpath, "%s/gltf/Box/glTF-Draco/Box.bin", testdata);
    make_scratch_dir(g_dir, sizeof g_dir, "gltf_draco");
    test_generated_quad();
    if (access(gpath, R_OK) != 0 || access(bpath, R_OK) != 0) {
        printf("SKIP Box cases: %s absent\n", gpath);
        rmdir(g_dir);
        return sy_check_finish("gltf_draco");
    }
    size_t jn, bn;
    char *json = read_all(gpath, &jn), *bin = read_all(bpath, &bn);
    const char *where = "meshes[0].primitives[0]: KHR_draco_mesh_compression";

    run_case("plain", json, bin, bn, SY_OK, NULL);

    /* the Draco bytes after the header overwritten */
    char *garbage = malloc(bn);
    memcpy(garbage, bin, bn);
    for (size_t i = 16; i < bn; i++) garbage[i] = (char)(0xA5 ^ (i * 31));
    run_case("corrupt", json, garbage, bn, SY_ERR_PARSE, where);
    /* not Draco at all */
    memset(garbage, 0, bn);
    run_case("zeros", json, garbage, bn, SY_ERR_PARSE, where);
    free(garbage);

    /* edits of the JSON: one text replaced, the error expected */
    static const struct {
        const char *name, *from, *to;
        sy_result code;
        const char *says; /* NULL: the primitive's extension (where) */
    } edits[] = {
        /* the stream cut short by its bufferView */
        {"truncated", "\"byteLength\": 118", "\"byteLength\": 60", SY_ERR_PARSE, NULL},
        /* accessor counts other than Draco's */
        {"vertex_count", "\"count\": 24", "\"count\": 25", SY_ERR_PARSE, "Draco data has 24 vertices, the accessors declare 25"},
        {"index_count", "\"count\": 36", "\"count\": 39", SY_ERR_PARSE,
         "Draco data has 12 triangles, the indices accessor declares 39"},
        /* counts far larger than the bytes: refused by the budget before anything is decoded */
        {"huge_count", "\"count\": 24", "\"count\": 2000000000", SY_ERR_LIMIT, "exceed what is left of the scene budget"},
        /* the extension's bufferView out of range */
        {"view_range", "\"bufferView\": 0,", "\"bufferView\": 7,", SY_ERR_PARSE, "bufferView 7 out of range"},
    };
    for (size_t k = 0; k < sizeof edits / sizeof edits[0]; ++k) {
        char *j = replace(json, edits[k].from, edits[k].to);
        run_case(edits[k].name, j, bin, bn, edits[k].code, edits[k].says ? edits[k].says : where);
        free(j);
    }

    free(json);
    free(bin);
    rmdir(g_dir);
    return sy_check_finish("gltf_draco");
}
