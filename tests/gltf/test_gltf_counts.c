/* test_gltf_counts.c — `sy info` counts of EVERY glTF / GLB file under TESTDATA/gltf checked against
 * values computed independently from the file's JSON with cJSON (no tinygltf involved): nodes,
 * meshes, primitives, triangles (per mode: lists count / 3, strips and fans count - 2), skipped
 * primitives (no POSITION or no complete element), points and line segments (LINES pairs, LINE_LOOP
 * n, LINE_STRIP n - 1), materials, textures, images, cameras and KHR_lights_punctual lights; and, in
 * the loaded scene, the triangle total, the vertices of the triangle primitives (as many as the
 * file's POSITION accessors: a primitive without NORMAL, flat-shaded, keeps its shared vertices and
 * its indices) and normals exactly where the file has NORMAL. (Tangents are not checked here:
 * images are refused before decoding, so no material has a normal map to generate them for.) A file
 * that requires an extension sy does not read must be refused naming it, and only such a file.
 * Usage: test_gltf_counts TESTDATA_DIR (exit 77 when the data is absent). */
#include "../support/sy_check.h"
#include "sy_gltf.h"

#include <cJSON.h>
#include <dirent.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static int g_refused = 0;

/* One count of `file` against the value read from its JSON (the message names the file). */
static void expect_count(const char *file, const char *what, uint64_t got, uint64_t want)
{
    EXPECT_MSG(got == want, "%s: %s = %llu, expected %llu", file, what, (unsigned long long)got,
               (unsigned long long)want);
}

typedef struct expected {
    uint64_t nodes, meshes, primitives, triangles, skipped, materials, textures, images, cameras, lights, points,
        segments, flat, tri_vertices; /* triangle primitives without NORMAL; their POSITION counts summed */
} expected;

/* The file's JSON (a GLB's first chunk), parsed; NULL when the test's own reading fails. */
static cJSON *read_json(const char *file)
{
    FILE *f = fopen(file, "rb");
    if (!f) return NULL;
    unsigned char *bytes = NULL;
    size_t n = 0, cap = 0, got;
    do {
        if (n == cap) {
            cap = cap ? 2 * cap : 1 << 16;
            unsigned char *nb = realloc(bytes, cap);
            if (!nb) break;
            bytes = nb;
        }
        got = fread(bytes + n, 1, cap - n, f);
        n += got;
    } while (got > 0);
    fclose(f);
    if (!bytes) return NULL;
    const char *text = (const char *)bytes;
    size_t len = n;
    if (n >= 20 && memcmp(bytes, "glTF", 4) == 0) { /* GLB: the first chunk is JSON */
#define U32(o) ((uint32_t)bytes[o] | (uint32_t)bytes[(o) + 1] << 8 | (uint32_t)bytes[(o) + 2] << 16 | (uint32_t)bytes[(o) + 3] << 24)
        len = U32(12);
        if (U32(16) != 0x4E4F534Au || 20ull + len > n) len = 0, text = NULL;
        else text = (const char *)bytes + 20;
#undef U32
    }
    cJSON *doc = text ? cJSON_ParseWithLength(text, len) : NULL;
    free(bytes);
    return doc;
}

static const cJSON *get(const cJSON *o, const char *k) { return cJSON_GetObjectItemCaseSensitive(o, k); }
static uint64_t arr(const cJSON *o, const char *k) { return cJSON_IsArray(get(o, k)) ? (uint64_t)cJSON_GetArraySize(get(o, k)) : 0; }

/* accessors[index].count, or false when the file does not have it */
static bool accessor_count(const cJSON *acc, const cJSON *index, uint64_t *count)
{
    if (!cJSON_IsNumber(index)) return false;
    const cJSON *c = get(cJSON_GetArrayItem(acc, (int)index->valuedouble), "count");
    if (!cJSON_IsNumber(c) || c->valuedouble < 0) return false;
    *count = (uint64_t)c->valuedouble;
    return true;
}

static bool compute(const cJSON *d, expected *e)
{
    memset(e, 0, sizeof *e);
    e->nodes = arr(d, "nodes");
    e->meshes = arr(d, "meshes");
    e->materials = arr(d, "materials");
    e->textures = arr(d, "textures");
    e->images = arr(d, "images");
    e->cameras = arr(d, "cameras");
    e->lights = arr(get(get(d, "extensions"), "KHR_lights_punctual"), "lights");
    const cJSON *acc = get(d, "accessors"), *m, *p;
    cJSON_ArrayForEach(m, get(d, "meshes"))
    {
        cJSON_ArrayForEach(p, get(m, "primitives"))
        {
            e->primitives++;
            const cJSON *mode_j = get(p, "mode"), *attrs = get(p, "attributes");
            int mode = cJSON_IsNumber(mode_j) ? (int)mode_j->valuedouble : 4;
            if (!get(attrs, "POSITION")) {
                e->skipped++;
                continue;
            }
            uint64_t count = 0, vertices = 0;
            if (!accessor_count(acc, get(attrs, "POSITION"), &count)) return false;
            vertices = count;
            if (get(p, "indices") && !accessor_count(acc, get(p, "indices"), &count)) return false;
            if (mode < 4) { /* points; lines: pairs, loops: n (n >= 3), strips: n - 1 */
                uint64_t el = mode == 0 ? count : mode == 1 ? count / 2 : count < 2 ? 0 : mode == 2 && count >= 3 ? count : count - 1;
                if (el == 0) e->skipped++;
                if (mode == 0) e->points += el;
                else e->segments += el;
                continue;
            }
            uint64_t t = mode == 4 ? count / 3 : (count >= 3 ? count - 2 : 0);
            if (t == 0) e->skipped++;
            e->triangles += t;
            if (t && !get(attrs, "NORMAL")) e->flat++;
            if (t) e->tri_vertices += vertices;
        }
    }
    return true;
}

/* The first extension the file requires that sy does not read (read from the JSON), or NULL. */
static const char *unsupported_required(const cJSON *doc)
{
    const cJSON *x;
    cJSON_ArrayForEach(x, get(doc, "extensionsRequired"))
    {
        if (!cJSON_IsString(x)) continue;
        bool known = false;
        for (const char *const *k = sy_gltf_supported_extensions(); *k && !known; ++k) known = strcmp(x->valuestring, *k) == 0;
        if (!known) return x->valuestring;
    }
    return NULL;
}

static void check_file(const char *file, uint32_t *models)
{
    cJSON *doc = read_json(file);
    expected e;
    bool read = doc && compute(doc, &e);
    EXPECT_MSG(read, "%s: the test's own JSON reading failed", file);
    if (!read) {
        cJSON_Delete(doc);
        return;
    }
    sy_scene *scene = NULL;
    sy_error err = {0};
    if (sy_scene_create(&scene, &err) != SY_OK) {
        fprintf(stderr, "scene: %s\n", err.message);
        exit(1);
    }
    sy_gltf_info info = {0};
    /* images are refused before decoding (they become missing textures with a warning): counts do
     * not depend on pixels, and decoding every texture would make this test slow under ASan */
    sy_gltf_options opts = {0};
    opts.max_image_pixels = 1;
    sy_result r = sy_gltf_load(file, scene, &opts, &info, &err);
    const char *unsupported = unsupported_required(doc);
    if (unsupported) {
        g_refused++;
        char quoted[256];
        snprintf(quoted, sizeof quoted, "'%s'", unsupported);
        bool refused = r == SY_ERR_UNSUPPORTED && strstr(err.message, quoted);
        EXPECT_MSG(refused, "%s: requires %s: want SY_ERR_UNSUPPORTED naming it, got %s: %s", file, unsupported,
                   sy_result_str(r), r ? err.message : "loaded");
        if (refused) printf("refused as it should be (requires %s, not read by sy): %s\n", unsupported, file);
    } else if (r != SY_OK) {
        EXPECT_MSG(r == SY_OK, "%s: load failed: %s", file, err.message);
    } else {
        (*models)++;
        const sy_gltf_counts *c = &info.counts;
        const struct {
            const char *what;
            uint64_t got, want;
        } counts[] = {
            {"nodes", c->nodes, e.nodes}, {"meshes", c->meshes, e.meshes}, {"primitives", c->primitives, e.primitives},
            {"triangles", c->triangles, e.triangles}, {"skipped_primitives", c->skipped_primitives, e.skipped},
            {"points", c->points, e.points}, {"line_segments", c->line_segments, e.segments},
            {"materials", c->materials, e.materials}, {"textures", c->textures, e.textures}, {"images", c->images, e.images},
            {"cameras", c->cameras, e.cameras}, {"lights", c->lights, e.lights},
        };
        for (size_t i = 0; i < sizeof counts / sizeof counts[0]; ++i)
            expect_count(file, counts[i].what, counts[i].got, counts[i].want);
        /* the scene itself: every mesh is created, whether referenced or not */
        uint64_t tris = 0, prims = 0, without_normals = 0, tri_vertices = 0;
        for (uint32_t id = sy_scene_next(scene, SY_TYPE_MESH, 0); id; id = sy_scene_next(scene, SY_TYPE_MESH, id)) {
            const sy_mesh_data *m = sy_object_get(scene, SY_TYPE_MESH, id);
            for (uint32_t k = 0; k < m->primitives.count; k++) {
                const sy_primitive *p = &m->primitives.items[k];
                prims++;
                tris += sy_primitive_triangle_count(p);
                if (p->topology == SY_TOPOLOGY_TRIANGLES) tri_vertices += sy_primitive_vertex_count(p);
                if (!p->normals && p->topology == SY_TOPOLOGY_TRIANGLES) without_normals++; /* strokes: own normals */
            }
        }
        expect_count(file, "scene triangles", tris, e.triangles);
        expect_count(file, "scene primitives", prims, e.primitives - e.skipped);
        expect_count(file, "triangle primitives without normals (flat)", without_normals, e.flat);
        expect_count(file, "vertices of the triangle primitives", tri_vertices, e.tri_vertices);
    }
    sy_gltf_info_free(&info);
    sy_scene_destroy(scene);
    cJSON_Delete(doc);
}

typedef struct file_list {
    char **items;
    size_t count, cap;
} file_list;

static bool ends_with(const char *s, const char *suffix)
{
    size_t n = strlen(s), k = strlen(suffix);
    return n >= k && strcmp(s + n - k, suffix) == 0;
}

/* Every .gltf and .glb file under dir, recursively. */
static void find_files(const char *dir, file_list *out)
{
    DIR *d = opendir(dir);
    if (!d) return;
    struct dirent *de;
    while ((de = readdir(d))) {
        if (de->d_name[0] == '.') continue;
        size_t len = strlen(dir) + strlen(de->d_name) + 2;
        char *path = malloc(len);
        if (!path) break;
        snprintf(path, len, "%s/%s", dir, de->d_name);
        struct stat st;
        if (stat(path, &st) != 0) {
            free(path);
            continue;
        }
        if (S_ISDIR(st.st_mode)) {
            find_files(path, out);
            free(path);
        } else if (S_ISREG(st.st_mode) && (ends_with(path, ".gltf") || ends_with(path, ".glb"))) {
            if (out->count == out->cap) {
                size_t cap = out->cap ? 2 * out->cap : 64;
                char **ni = realloc(out->items, cap * sizeof *ni);
                if (!ni) {
                    free(path);
                    break;
                }
                out->items = ni;
                out->cap = cap;
            }
            out->items[out->count++] = path;
        } else {
            free(path);
        }
    }
    closedir(d);
}

static int cmp_str(const void *a, const void *b) { return strcmp(*(char *const *)a, *(char *const *)b); }

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: test_gltf_counts TESTDATA_DIR\n");
        return 2;
    }
    char root[4096];
    snprintf(root, sizeof root, "%s/gltf", argv[1]);
    struct stat st;
    if (stat(root, &st) != 0 || !S_ISDIR(st.st_mode)) {
        printf("SKIP: %s not found (shared test data absent)\n", root);
        return 77;
    }
    file_list files = {0};
    find_files(root, &files);
    qsort(files.items, files.count, sizeof *files.items, cmp_str);
    uint32_t models = 0;
    for (size_t i = 0; i < files.count; ++i) check_file(files.items[i], &models);
    printf("%zu files, %u loaded, %d refused for an unsupported required extension\n", files.count, models,
           g_refused);
    EXPECT_MSG(files.count >= 30, "only %zu glTF files found under %s", files.count, root);
    for (size_t i = 0; i < files.count; ++i) free(files.items[i]);
    free(files.items);
    return sy_check_finish("gltf_counts");
}
