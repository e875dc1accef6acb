/* test_assimp_isolate.c — the Assimp loader's import process (formats/sy_assimp_isolate.c):
 *  - a load in the import process makes exactly the scene a load in the caller's process makes
 *    (sy_scene_equal: every object at the same id, every field; the info alike), into scenes that
 *    already hold objects, a freed slot and uncommitted changes, which stay uncommitted; on an OBJ +
 *    MTL + texture the test writes and on Assimp's own test models (COLLADA with a texture, FBX);
 *  - Assimp's OutOfMemory.off (an OFF declaring 35 * 10^9 vertices, on which `assimp info` runs out
 *    of memory or time) fails quickly within the import process's address-space limit, the caller
 *    not growing;
 *  - a 20000-corner polygon (Assimp's ear clipping is quadratic: about 2 s of CPU) with
 *    max_import_seconds 1 is stopped by the CPU limit (SY_ERR_LIMIT naming the file), the caller's
 *    scene untouched;
 *  - a failed import in the child leaves the caller's scene as it was;
 *  - loads while another thread allocates without pause complete (forks amid malloc's locks);
 *  - every input in tests/fuzz/corpus_contained/assimp_<ext>/ (faults inside Assimp that fuzz.sh
 *    found and the import process contains: crashes, aborts, endless growth) fails the load with an
 *    error naming the file, the caller's scene untouched. */
#include "sy_assimp.h"
#include "sy_scene.h"

#include "../../apps/sy/sy_bench_os.h"
#include "../formats/test_util.h"
#include "assimp_quad.h"

#include <dirent.h>
#include <pthread.h>
#include <stdatomic.h>
#include <math.h>
#include <stdlib.h>
#include <time.h>

#define MODELS "/usr/share/assimp/models"

/* A scene holding a node, a material and a freed slot (generation 1 spent), with uncommitted
 * changes when `pending`. */
static sy_scene *prepared(bool pending)
{
    sy_scene *s = NULL;
    sy_error e = {0};
    if (sy_scene_create(&s, &e) != SY_OK) return NULL;
    sy_node a, b;
    sy_material m;
    EXPECT(sy_node_create(s, "kept", &a, &e) == SY_OK && sy_node_create(s, "freed", &b, &e) == SY_OK &&
           sy_material_create(s, "kept material", &m, &e) == SY_OK);
    EXPECT(sy_scene_commit(s, NULL, &e) == SY_OK);
    EXPECT(sy_object_destroy(s, SY_TYPE_NODE, b.id, &e) == SY_OK);
    if (!pending) EXPECT(sy_scene_commit(s, NULL, &e) == SY_OK);
    else {
        sy_node c;
        EXPECT(sy_node_create(s, "pending", &c, &e) == SY_OK);
    }
    return s;
}

static bool same_info(const sy_assimp_info *a, const sy_assimp_info *b)
{
    bool same = a->root.id == b->root.id && a->camera_node_count == b->camera_node_count &&
                !memcmp(&a->counts, &b->counts, sizeof a->counts) && !strcmp(a->format, b->format) &&
                a->unit_scale == b->unit_scale && a->up_axis == b->up_axis && a->warning_count == b->warning_count &&
                a->stored_warning_count == b->stored_warning_count;
    for (uint32_t k = 0; same && k < a->camera_node_count; ++k) same = a->camera_nodes[k].id == b->camera_nodes[k].id;
    for (uint32_t k = 0; same && k < a->stored_warning_count; ++k) same = !strcmp(a->warnings[k], b->warnings[k]);
    return same;
}

/* Loads path both ways into prepared scenes and compares. */
static void compare_both_ways(const char *path, bool pending)
{
    sy_scene *iso = prepared(pending), *here = prepared(pending);
    if (!iso || !here) return;
    uint64_t frame = sy_scene_frame(iso);
    sy_assimp_info ii = {0}, ih = {0};
    sy_error e = {0};
    sy_assimp_options in_proc = {.in_process = true};
    sy_result ri = sy_assimp_load(path, iso, NULL, &ii, &e);
    EXPECT_MSG(ri == SY_OK, "%s in the import process: %s", path, e.message);
    sy_result rh = sy_assimp_load(path, here, &in_proc, &ih, &e);
    EXPECT_MSG(rh == SY_OK, "%s in this process: %s", path, e.message);
    if (ri == SY_OK && rh == SY_OK) {
        sy_error diff = {0};
        EXPECT_MSG(sy_scene_equal(iso, here, &diff), "%s (%s changes before): the scenes differ: %s", path,
                   pending ? "uncommitted" : "no", diff.message);
        EXPECT_MSG(same_info(&ii, &ih), "%s: the info differs (root %#x / %#x, %u / %u warnings, format '%s' / '%s')", path,
                   ii.root.id, ih.root.id, ii.warning_count, ih.warning_count, ii.format, ih.format);
        EXPECT_MSG(sy_scene_frame(iso) == frame && sy_scene_has_pending(iso),
                   "%s: the caller's scene stays uncommitted (frame %llu, was %llu)", path,
                   (unsigned long long)sy_scene_frame(iso), (unsigned long long)frame);
        /* and both commit alike (the applied creations are recorded as local ones) */
        EXPECT(sy_scene_commit(iso, NULL, &e) == SY_OK && sy_scene_commit(here, NULL, &e) == SY_OK);
        sy_bounds bi = sy_bounds_empty(), bh = sy_bounds_empty();
        sy_node_world_bounds(iso, ii.root, &bi, NULL);
        sy_node_world_bounds(here, ih.root, &bh, NULL);
        EXPECT_MSG(!memcmp(&bi, &bh, sizeof bi) && (ii.counts.meshes == 0 || bi.max[0] >= bi.min[0]),
                   "%s: world bounds after commit", path);
        printf("%s (%s): %u meshes, %u triangles, %u materials, %u textures: the same scene both ways\n", path,
               pending ? "uncommitted changes before" : "committed before", ii.counts.meshes, ii.counts.triangles,
               ii.counts.materials, ii.counts.textures);
    }
    sy_assimp_info_free(&ii);
    sy_assimp_info_free(&ih);
    sy_scene_destroy(iso);
    sy_scene_destroy(here);
}

/* a thread that allocates and frees without pause, so that forks happen while it holds malloc's
 * locks */
static atomic_int g_stop;
static void *churn(void *arg)
{
    (void)arg;
    while (!atomic_load(&g_stop)) {
        void *volatile p = malloc(4096 + (size_t)(rand() % 65536));
        free(p);
    }
    return NULL;
}

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + (double)t.tv_nsec * 1e-9;
}

int main(void)
{
    char dir[4096], p[4300], q[4300];
    make_scratch_dir(dir, sizeof dir, "assimp_iso");
    sy_error e = {0};

    /* an OBJ + MTL + PPM texture the test writes */
    write_assimp_quad(dir, "newmtl red\nKd 0.5 0.25 0.125\nKs 1 1 1\nNs 128\nmap_Kd tex.ppm\nmap_Ka missing.png\n", p, sizeof p);
    compare_both_ways(p, true);
    compare_both_ways(p, false);

    /* Assimp's own test models (Debian assimp-testmodels) */
    static const char *const models[] = {MODELS "/Collada/duck.dae", MODELS "/FBX/box.fbx", MODELS "/Collada/cameras.dae",
                                         MODELS "/Collada/lights.dae", MODELS "/PLY/cube.ply"};
    for (size_t k = 0; k < sizeof models / sizeof models[0]; ++k) {
        if (!path_exists(models[k])) {
            printf("SKIP %s: not installed (Debian assimp-testmodels)\n", models[k]);
            continue;
        }
        compare_both_ways(models[k], true);
    }

    /* OutOfMemory.off: a count Assimp allocates for before reading */
    const char *oom = MODELS "/invalid/OutOfMemory.off";
    if (!path_exists(oom)) printf("SKIP %s: not installed (Debian assimp-testmodels)\n", oom);
    else {
        sy_scene *s = prepared(true);
        long before = sy_bench_rss_now_kib();
        double t0 = now_s();
        sy_result r = s ? sy_assimp_load(oom, s, NULL, NULL, &e) : SY_ERR_OUT_OF_MEMORY;
        double took = now_s() - t0;
        long grew = sy_bench_rss_now_kib() - before;
        printf("OutOfMemory.off: %s (%.2f s, the caller grew %ld KiB)\n", e.message, took, grew);
        EXPECT_MSG(r != SY_OK && strstr(e.message, oom), "OutOfMemory.off must fail naming the file: %s", e.message);
        EXPECT_MSG(grew < 64 * 1024, "the caller grew %ld KiB", grew);
        EXPECT_MSG(s && sy_scene_count(s, SY_TYPE_NODE) == 2 && sy_scene_count(s, SY_TYPE_MESH) == 0,
                   "the caller's scene is as it was");
        sy_scene_destroy(s);
    }

    /* a polygon of 20000 corners: quadratic ear clipping past one second of CPU */
    PATHF(p, "%s/star.obj", dir);
    FILE *f = fopen(p, "w");
    EXPECT(f != NULL);
    if (f) {
        const int n = 20000;
        for (int i = 0; i < n; ++i) {
            double a = 2.0 * 3.14159265358979 * i / n, r = i % 2 ? 0.5 : 1.0;
            fprintf(f, "v %.6f %.6f 0\n", r * cos(a), r * sin(a));
        }
        fputc('f', f);
        for (int i = 0; i < n; ++i) fprintf(f, " %d", i + 1);
        fputc('\n', f);
        fclose(f);
        sy_scene *s = prepared(false);
        sy_assimp_options one = {.max_import_seconds = 1};
        double t0 = now_s();
        sy_result r = s ? sy_assimp_load(p, s, &one, NULL, &e) : SY_ERR_OUT_OF_MEMORY;
        printf("star.obj with max_import_seconds 1: %s (%.2f s)\n", e.message, now_s() - t0);
        EXPECT_MSG(r == SY_ERR_LIMIT && strstr(e.message, p) && strstr(e.message, "CPU"),
                   "the CPU limit stops the import: %d %s", (int)r, e.message);
        EXPECT_MSG(s && sy_scene_count(s, SY_TYPE_NODE) == 1 && !sy_scene_has_pending(s), "the caller's scene is as it was");
        sy_scene_destroy(s);
    }

    /* loads while another thread allocates (glibc's malloc is fork-safe; a sanitizer build loads
     * in process when other threads exist): each completes with the same counts */
    {
        pthread_t th;
        EXPECT(pthread_create(&th, NULL, churn, NULL) == 0);
        for (int k = 0; k < 8; ++k) {
            sy_scene *s = prepared(false);
            sy_assimp_info info = {0};
            PATHF(p, "%s/quad.obj", dir);
            sy_result r = s ? sy_assimp_load(p, s, NULL, &info, &e) : SY_ERR_OUT_OF_MEMORY;
            EXPECT_MSG(r == SY_OK && info.counts.triangles == 2, "load %d beside an allocating thread: %s", k, e.message);
            sy_assimp_info_free(&info);
            sy_scene_destroy(s);
        }
        atomic_store(&g_stop, 1);
        pthread_join(th, NULL);
        printf("8 loads beside an allocating thread: done\n");
    }

    /* the contained faults fuzz.sh kept */
    DIR *cd = opendir(SY_CONTAINED_DIR);
    EXPECT_MSG(cd != NULL, "%s: %s", SY_CONTAINED_DIR, strerror(errno));
    for (struct dirent *t; cd && (t = readdir(cd)) != NULL;) {
        if (strncmp(t->d_name, "assimp_", 7) != 0) continue;
        char sub[4300], name[64];
        PATHF(sub, "%s/%s", SY_CONTAINED_DIR, t->d_name);
        snprintf(name, sizeof name, "contained.%s", t->d_name + 7); /* the extension picks Assimp's importer */
        DIR *fd = opendir(sub);
        for (struct dirent *x; fd && (x = readdir(fd)) != NULL;) {
            if (x->d_name[0] == '.') continue;
            PATHF(q, "%s/%s", sub, x->d_name);
            size_t n = 0;
            unsigned char *bytes = slurp(q, &n);
            sy_scene *s = prepared(true);
            double t0 = now_s();
            sy_result r = bytes && s ? sy_assimp_load_memory(bytes, n, name, dir, s, NULL, NULL, &e) : SY_ERR_IO;
            printf("%s/%s: %s (%.2f s)\n", t->d_name, x->d_name, r ? e.message : "loaded", now_s() - t0);
            EXPECT_MSG(r != SY_OK && strstr(e.message, name), "%s must fail naming the file", q);
            EXPECT_MSG(s && sy_scene_count(s, SY_TYPE_NODE) == 2 && sy_scene_count(s, SY_TYPE_MESH) == 0,
                       "%s: the caller's scene is as it was", q);
            sy_scene_destroy(s);
            free(bytes);
        }
        if (fd) closedir(fd);
    }
    if (cd) closedir(cd);

    remove_scratch_dir(dir);
    EXPECT_MSG(access(dir, F_OK) != 0, "the scratch folder %s and its nested folders are removed", dir);
    return sy_check_finish("test_assimp_isolate");
}
