/* sy_bench_deform.c — `sy bench deform [--tris VERTICES] [--repeats FRAMES]`: the cost of a skinned
 * frame (issue 35). A generated tube of about VERTICES vertices (default 10^5; 64 per ring, two
 * triangles per quad) skinned to a chain of 16 joints (two influences per vertex), each frame every
 * joint turned a little (16 node transforms set, commit, sync). Reported, median (min .. max) in ms:
 *   - the deform step alone: sy_deform_primitive over the mesh (what the mirror runs per pose), on
 *     one thread and on its own threads (the ratio);
 *   - the mirror's sync with a back-end that does nothing (deform + the new blobs + bookkeeping);
 *   - per back-end (whitted, raster): a frame's set + commit + sync (the deformed mesh refitted /
 *     re-uploaded in place) against building that back-end's scene from scratch (context creation
 *     and first sync: the BVH built, the buffers made), as a ratio. */
#include "sy_bench.h"
#include "sy_commit.h"
#include "sy_deform.h"
#include "sy_mirror.h"
#ifdef SY_HAVE_EMBREE
#include "sy_mediator_rt.h"
#endif

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define JOINTS SY_BENCH_TUBE_JOINTS
#define SEGMENTS SY_BENCH_TUBE_SEGMENTS

typedef struct tube {
    sy_node root, mesh_node, joints[JOINTS];
    sy_mat4 ibm[JOINTS];
    uint32_t vertices, triangles;
} tube;

/* The tube (height 2 along +Y, radius 0.1) and its skin into s. */
static sy_result make_tube(sy_scene *s, uint32_t want_vertices, tube *t, sy_error *err)
{
    uint32_t rings = want_vertices / SEGMENTS < 2 ? 2 : want_vertices / SEGMENTS;
    uint32_t nv = rings * SEGMENTS, nt = (rings - 1) * SEGMENTS * 2;
    float *pos = malloc(sizeof(float) * 3 * nv), *nrm = malloc(sizeof(float) * 3 * nv), *w = calloc(4 * (size_t)nv, sizeof(float));
    uint32_t *j = calloc(4 * (size_t)nv, sizeof(uint32_t)), *idx = malloc(sizeof(uint32_t) * 3 * (size_t)nt);
    sy_result r = SY_OK;
    if (!pos || !nrm || !w || !j || !idx) r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bench deform: out of memory");
    float seg = 2.0f / (float)(JOINTS - 1);
    if (r == SY_OK) sy_bench_tube(rings, pos, nrm, j, NULL, w, idx);
    sy_primitive p = {0};
    sy_mesh m;
    if (r == SY_OK) r = sy_blob_create_take(pos, sizeof(float) * 3 * nv, &p.positions, err), pos = NULL;
    if (r == SY_OK) r = sy_blob_create_take(nrm, sizeof(float) * 3 * nv, &p.normals, err), nrm = NULL;
    if (r == SY_OK) r = sy_blob_create_take(j, sizeof(uint32_t) * 4 * nv, &p.joints, err), j = NULL;
    if (r == SY_OK) r = sy_blob_create_take(w, sizeof(float) * 4 * nv, &p.weights, err), w = NULL;
    if (r == SY_OK) r = sy_blob_create_take(idx, sizeof(uint32_t) * 3 * nt, &p.indices, err), idx = NULL;
    if (r == SY_OK) r = sy_mesh_create(s, "tube", &m, err);
    if (r == SY_OK) r = sy_mesh_set_primitives(s, m, &p, 1, err);
    sy_primitive_release(&p);
    free(pos), free(nrm), free(w), free(j), free(idx);
    if (r == SY_OK) r = sy_node_create(s, "root", &t->root, err);
    if (r == SY_OK) r = sy_node_create(s, "skinned", &t->mesh_node, err);
    if (r == SY_OK) r = sy_node_set_mesh(s, t->mesh_node, m, err);
    if (r == SY_OK) r = sy_node_add_child(s, t->root, t->mesh_node, err);
    for (uint32_t k = 0; k < JOINTS && r == SY_OK; ++k) {
        static const float q[4] = {0, 0, 0, 1}, one[3] = {1, 1, 1};
        float tr[3] = {0.0f, k ? seg : 0.0f, 0.0f};
        r = sy_node_create(s, "joint", &t->joints[k], err);
        if (r == SY_OK) r = sy_node_set_trs(s, t->joints[k], tr, q, one, err);
        if (r == SY_OK) r = sy_node_add_child(s, k ? t->joints[k - 1] : t->root, t->joints[k], err);
        t->ibm[k] = sy_mat4_identity();
        t->ibm[k].m[13] = -seg * (float)k;
    }
    if (r == SY_OK) r = sy_node_set_skin(s, t->mesh_node, t->joints, t->ibm, JOINTS, t->joints[0], err);
    if (r == SY_OK) r = sy_scene_commit(s, NULL, err);
    t->vertices = nv, t->triangles = nt;
    return r;
}

/* Frame i's pose: every joint turned about Z by a few degrees. */
static sy_result pose(sy_scene *s, const tube *t, uint32_t i, sy_error *err)
{
    sy_result r = SY_OK;
    float seg = 2.0f / (float)(JOINTS - 1);
    for (uint32_t k = 0; k < JOINTS && r == SY_OK; ++k) {
        float a = 0.05f * sinf(0.3f * (float)(i + 1) + 0.2f * (float)k);
        const float q[4] = {0, 0, sinf(0.5f * a), cosf(0.5f * a)}, one[3] = {1, 1, 1}, tr[3] = {0.0f, k ? seg : 0.0f, 0.0f};
        r = sy_node_set_trs(s, t->joints[k], tr, q, one, err);
    }
    return r == SY_OK ? sy_scene_commit(s, NULL, err) : r;
}

static void print_row(const char *what, double *v, uint32_t n, double scratch)
{
    sy_bench_spread sp = sy_bench_spread_of(v, n);
    printf("  %-42s %9.3f ms (%.3f .. %.3f)", what, 1e3 * sp.median, 1e3 * sp.min, 1e3 * sp.max);
    if (scratch > 0) printf("   from scratch %9.3f ms, ratio %.3f", 1e3 * scratch, sp.median / scratch);
    printf("\n");
}

sy_result sy_bench_deform(uint32_t vertices, uint32_t repeats, sy_error *err)
{
    sy_scene *s;
    sy_result r = sy_scene_create(&s, err);
    if (r != SY_OK) return r;
    tube t;
    memset(&t, 0, sizeof t);
    r = make_tube(s, vertices, &t, err);
    double *v = calloc(repeats, sizeof *v);
    if (r == SY_OK && !v) r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bench deform: out of memory");
    if (r == SY_OK)
        printf("sy bench deform: a tube of %u vertices, %u triangles, skinned to %u joints (2 influences per vertex), "
               "%u frames\n",
               t.vertices, t.triangles, JOINTS, repeats);
    /* the deform step alone, on the mesh as the scene holds it */
    if (r == SY_OK) {
        const sy_mesh_data *md = sy_mesh_get(s, sy_node_get(s, t.mesh_node)->mesh);
        const sy_primitive *p = &md->primitives.items[0];
        float *pos = malloc(sizeof(float) * 3 * t.vertices), *nrm = malloc(sizeof(float) * 3 * t.vertices);
        sy_mat4 jm[JOINTS];
        double one = 0.0; /* the single-thread median, for the ratio */
        for (int pass = 0; pass < 2 && pos && nrm; ++pass) {
            for (uint32_t i = 0; i < repeats; ++i) {
                for (uint32_t k = 0; k < JOINTS; ++k) {
                    jm[k] = sy_mat4_identity();
                    jm[k].m[12] = 0.001f * (float)i;
                    jm[k] = sy_mat4_mul(&jm[k], &t.ibm[k]);
                }
                sy_deform_input in = {.primitive = p, .joints = jm, .joint_count = JOINTS, .max_threads = pass ? 0u : 1u};
                double a = sy_time_now();
                sy_deform_primitive(&in, pos, nrm, NULL, NULL);
                v[i] = sy_time_now() - a;
            }
            if (pass == 0) {
                print_row("deform step, 1 thread", v, repeats, 0);
                one = sy_bench_spread_of(v, repeats).median;
            } else {
                sy_bench_spread sp = sy_bench_spread_of(v, repeats);
                print_row("deform step, threads (sy_deform_primitive)", v, repeats, 0);
                printf("    threads against 1 thread: %.3f\n", sp.median / one);
            }
        }
        free(pos), free(nrm);
    }
    /* the mirror with a back-end that does nothing */
    if (r == SY_OK) {
        sy_mirror *m = NULL;
        uint32_t consumer = 0;
        sy_mirror_desc d = {"bench mirror", t.root.id, &sy_bench_nop_mirror, NULL};
        sy_changes *c = NULL;
        r = sy_mirror_create(&d, &m, err);
        if (r == SY_OK) r = sy_scene_consumer_add(s, &consumer, err);
        if (r == SY_OK) r = sy_scene_consumer_pull(s, consumer, &c, err);
        double a = sy_time_now();
        if (r == SY_OK) r = sy_mirror_sync(m, c, NULL, err);
        double scratch = sy_time_now() - a;
        sy_changes_release(c);
        for (uint32_t i = 0; i < repeats && r == SY_OK; ++i) {
            r = pose(s, &t, i, err);
            a = sy_time_now();
            if (r == SY_OK) r = sy_scene_consumer_pull(s, consumer, &c, err);
            if (r == SY_OK) r = sy_mirror_sync(m, c, NULL, err);
            v[i] = sy_time_now() - a;
            sy_changes_release(c);
            c = NULL;
        }
        if (r == SY_OK) print_row("mirror sync, no-op back-end", v, repeats, scratch);
        if (consumer) sy_scene_consumer_remove(s, consumer);
        sy_mirror_destroy(m);
    }
    /* per back-end: a frame against the scene built from scratch */
    static const char *const backends[] = {"whitted", "raster"};
    for (size_t b = 0; b < 2 && r == SY_OK; ++b) {
        if (!sy_mediator_find(backends[b])) continue;
        sy_context *ctx = NULL;
        sy_error e2 = {0};
        double a = sy_time_now();
        sy_result r2 = sy_context_create(s, backends[b], NULL, t.root.id, &ctx, &e2);
        if (r2 == SY_OK) r2 = sy_context_sync(ctx, &e2);
        double scratch = sy_time_now() - a;
        double top = 0.0; /* whitted: Embree's commit of the scene at the end of each sync */
        for (uint32_t i = 0; i < repeats && r2 == SY_OK; ++i) {
            a = sy_time_now();
            r2 = pose(s, &t, i + repeats, &e2);
            if (r2 == SY_OK) r2 = sy_context_sync(ctx, &e2);
            v[i] = sy_time_now() - a;
#ifdef SY_HAVE_EMBREE
            if (r2 == SY_OK && b == 0) {
                sy_mediator_rt_counters rc;
                sy_mediator_rt_counters_get(sy_context_state(ctx), &rc);
                top += rc.last_sync_top_commit_seconds / repeats;
            }
#endif
        }
        char what[64];
        snprintf(what, sizeof what, "%s: set + commit + sync", backends[b]);
        if (r2 == SY_OK) print_row(what, v, repeats, scratch);
        if (r2 == SY_OK && top > 0.0) printf("    of which the top-level commit, mean %9.3f ms\n", 1e3 * top);
        if (r2 != SY_OK) printf("  %s: skipped: %s\n", backends[b], e2.message); /* no GL provider here: not an error */
        sy_context_release(ctx);
    }
    free(v);
    sy_scene_destroy(s);
    return r;
}
