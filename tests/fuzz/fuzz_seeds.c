/* fuzz_seeds.c — writes seed inputs that the shared test data cannot give as they are:
 *   fuzz_seeds exr OUTDIR
 *       small OpenEXR images (8x5, 3x17, 40x33) in every compression the writer has (NONE, RLE, ZIPS,
 *       ZIP, PIZ), HALF and FLOAT channels, with and without depth (the test data's EXRs are
 *       hundreds of KiB: too big to mutate quickly);
 *   fuzz_seeds changes OUTDIR FILE...
 *       the wire encoding (sy_changes_serialize) of each glTF / X3D file's snapshot, and of an
 *       incremental change list moving its root node, read in place from the test data.
 * Used by tests/fuzz/fuzz.sh before fuzzing; never part of a regular build's tests. */
#include "sy_changes.h"
#include "sy_exr.h"
#include "sy_gltf.h"
#include "sy_scene.h"
#include "sy_x3d.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int write_file(const char *dir, const char *name, const void *data, size_t size)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "wb");
    if (!f) return 1;
    size_t w = fwrite(data, 1, size, f);
    return (fclose(f) != 0 || w != size) ? 1 : 0;
}

static int exr_seeds(const char *dir)
{
    static const int sizes[3][2] = {{8, 5}, {3, 17}, {40, 33}};
    static const sy_exr_compression comps[5] = {SY_EXR_COMPRESSION_NONE, SY_EXR_COMPRESSION_RLE, SY_EXR_COMPRESSION_ZIPS,
                                                SY_EXR_COMPRESSION_ZIP, SY_EXR_COMPRESSION_PIZ};
    int n = 0;
    for (int s = 0; s < 3; s++) {
        int w = sizes[s][0], h = sizes[s][1];
        float *rgba = malloc((size_t)w * h * 4 * sizeof(float)), *z = malloc((size_t)w * h * sizeof(float));
        if (!rgba || !z) return 1;
        for (int i = 0; i < w * h; i++) {
            for (int c = 0; c < 4; c++) rgba[4 * i + c] = (float)((i * 7 + c * 13) % 23) / 7.0f;
            z[i] = i % 5 ? (float)i * 0.25f : 1.0f / 0.0f;
        }
        for (int c = 0; c < 5; c++)
            for (int t = 0; t < 2; t++) {
                sy_exr_channel_desc ch[5] = {
                    {"A", rgba, 4, 3, t ? SY_EXR_PIXEL_HALF : SY_EXR_PIXEL_FLOAT},
                    {"B", rgba, 4, 2, t ? SY_EXR_PIXEL_HALF : SY_EXR_PIXEL_FLOAT},
                    {"G", rgba, 4, 1, t ? SY_EXR_PIXEL_HALF : SY_EXR_PIXEL_FLOAT},
                    {"R", rgba, 4, 0, t ? SY_EXR_PIXEL_HALF : SY_EXR_PIXEL_FLOAT},
                    {"Z", z, 1, 0, SY_EXR_PIXEL_FLOAT},
                };
                sy_exr_write_desc d = {.width = w, .height = h, .compression = comps[c], .channels = ch,
                                       .channel_count = (s + c + t) % 2 ? 5 : 4};
                char path[4096];
                snprintf(path, sizeof path, "%s/seed_%dx%d_c%d_%s.exr", dir, w, h, (int)comps[c], t ? "half" : "float");
                sy_error e = {0};
                if (sy_exr_write(path, &d, &e) != SY_OK) {
                    fprintf(stderr, "fuzz_seeds: %s\n", e.message);
                    return 1;
                }
                n++;
            }
        free(rgba);
        free(z);
    }
    printf("fuzz_seeds: %d EXR seeds in %s\n", n, dir);
    return 0;
}

static int emit_changes(const char *dir, const char *base, int k, sy_changes *c)
{
    void *data = NULL;
    size_t size = 0;
    sy_error e = {0};
    if (sy_changes_serialize(c, NULL, NULL, &data, &size, &e) != SY_OK) return 1;
    char name[512];
    snprintf(name, sizeof name, "seed_%s_%d.sycl", base, k);
    int r = size <= (1u << 20) ? write_file(dir, name, data, size) : 0; /* bigger ones: skipped */
    free(data);
    return r;
}

static int change_seeds(const char *dir, int argc, char **argv)
{
    int n = 0;
    for (int i = 0; i < argc; i++) {
        const char *path = argv[i], *slash = strrchr(path, '/');
        const char *base = slash ? slash + 1 : path;
        size_t len = strlen(path);
        sy_scene *s;
        if (sy_scene_create(&s, NULL) != SY_OK) return 1;
        uint32_t consumer;
        sy_node root = {0};
        sy_result r;
        sy_error e = {0};
        if (sy_scene_consumer_add(s, &consumer, &e) != SY_OK) return 1;
        if (len > 4 && !strcmp(path + len - 4, ".x3d")) {
            sy_x3d_info info;
            r = sy_x3d_load(path, s, NULL, &info, &e);
            if (!r) root = info.root;
            sy_x3d_info_free(&info);
        } else {
            sy_gltf_info info;
            r = sy_gltf_load(path, s, NULL, &info, &e);
            if (!r) root = info.root;
            sy_gltf_info_free(&info);
        }
        sy_changes *c = NULL;
        if (r == SY_OK && sy_scene_commit(s, NULL, NULL) == SY_OK && sy_scene_snapshot(s, &c, NULL) == SY_OK) {
            if (emit_changes(dir, base, 0, c)) return 1;
            sy_changes_release(c);
            c = NULL;
            sy_changes *first = NULL;
            sy_scene_consumer_pull(s, consumer, &first, NULL);
            sy_changes_release(first);
            const float t[3] = {1, 2, 3}, q[4] = {0, 0, 0, 1}, sc[3] = {1, 1, 1};
            if (sy_node_set_trs(s, root, t, q, sc, NULL) == SY_OK && sy_scene_commit(s, NULL, NULL) == SY_OK &&
                sy_scene_consumer_pull(s, consumer, &c, NULL) == SY_OK) {
                if (emit_changes(dir, base, 1, c)) return 1;
                n++;
            }
            sy_changes_release(c);
            n++;
        } else {
            fprintf(stderr, "fuzz_seeds: %s skipped: %s\n", path, e.message);
        }
        sy_scene_destroy(s);
    }
    printf("fuzz_seeds: %d wire seeds in %s\n", n, dir);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc >= 3 && !strcmp(argv[1], "exr")) return exr_seeds(argv[2]);
    if (argc >= 3 && !strcmp(argv[1], "changes")) return change_seeds(argv[2], argc - 3, argv + 3);
    fprintf(stderr, "usage: fuzz_seeds exr OUTDIR | fuzz_seeds changes OUTDIR FILE...\n");
    return 1;
}
