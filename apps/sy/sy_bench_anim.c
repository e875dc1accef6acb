/* sy_bench_anim.c — `sy bench anim [--tris VERTICES] [--nodes NODES] [--repeats FRAMES]`: what an
 * animated frame costs, step by step (issue 35), on the user's path: each scene is written to a .glb
 * in a temporary directory and loaded by sy_gltf_load, and its frames are played by the scene clock.
 *   1. a skinned mesh: a tube of about VERTICES vertices (default 10^5; 64 per ring) skinned to a
 *      chain of 16 joints (2 influences per vertex), one LINEAR rotation channel per joint (25 keys
 *      over 2 s);
 *   2. NODES animated nodes (default 10^4): a 100-wide grid of cubes (one shared mesh), each node
 *      with a LINEAR rotation and a LINEAR translation channel (5 keys over 2 s).
 * Per frame (FRAMES frames spread over the clip; median (min .. max) in ms):
 *   - clock evaluation (sy_scene_set_time_ex), commit (sy_scene_commit), change list
 *     (sy_scene_consumer_pull) and the mirror's sync with a back-end that keeps nothing, of which
 *     the deformation (sy_mirror_sync_stats.deform_seconds);
 *   - per back-end (whitted, pathtracer, raster, those built): the context's sync, of which the
 *     deformation, the deformed vertices' update (the ray tracers: copy + Embree BVH refit; the
 *     rasterizer: vertex buffer re-upload) and the ray tracers' top-level commit, beside the same
 *     frames' top-level commit in a second context that builds it for frequent updates where most
 *     instances move (Embree's dynamic scene at LOW quality: sy_mediator_rt_set_top_fast; the two
 *     contexts synced in turn first), as a ratio; the frame (clock +
 *     commit + sync) against translating the same frame from scratch (a new context and its first
 *     sync at the last frame's time: the BVHs built, the buffers made), as a ratio;
 *   - the skinned mesh with 1 and with 3 contexts on the scene (whitted, pathtracer, raster; those
 *     that start, the rest whitted again): the deformation per frame summed over the contexts, with
 *     each mirror deforming its own copy (sharing off, as before sy_deform_cache.h) and with the
 *     poses shared (one deformation per pose for every context), and the ratio of the two. */
#include "sy_bench.h"
#include "sy_deform_cache.h"
#include "sy_anim.h"
#include "sy_commit.h"
#include "sy_file.h"
#include "sy_gltf.h"
#include "sy_mirror.h"
#ifdef SY_HAVE_EMBREE
#include "sy_mediator_rt.h"
#endif
#ifdef SY_HAVE_RASTER
#include "sy_mediator_raster.h"
#endif

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define JOINTS SY_BENCH_TUBE_JOINTS
#define SEGMENTS SY_BENCH_TUBE_SEGMENTS
#define SKIN_KEYS 25u
#define NODE_KEYS 5u
#define DURATION 2.0f

/* A growing JSON text (the glTF part of the .glb). */
typedef struct jtext {
    char *s;
    size_t n, cap;
    bool oom;
} jtext;

static void jt(jtext *j, const char *fmt, ...)
{
    if (j->oom) return;
    for (;;) {
        va_list ap;
        va_start(ap, fmt);
        int k = vsnprintf(j->s ? j->s + j->n : NULL, j->s ? j->cap - j->n : 0, fmt, ap);
        va_end(ap);
        if (k < 0) {
            j->oom = true;
            return;
        }
        if (j->s && j->n + (size_t)k < j->cap) {
            j->n += (size_t)k;
            return;
        }
        size_t cap = (j->cap ? j->cap * 2 : 65536) + (size_t)k;
        char *s = realloc(j->s, cap);
        if (!s) {
            j->oom = true;
            return;
        }
        j->s = s, j->cap = cap;
    }
}

/* Writes a GLB of json + bin (bin's size a multiple of 4) through sy_atomic_file. */
static sy_result write_glb(const char *path, jtext *j, const void *bin, size_t bin_bytes, sy_error *err)
{
    while (j->n % 4) jt(j, " ");
    if (j->oom) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bench anim: out of memory (glTF JSON)");
    if (j->n + bin_bytes + 28 > UINT32_MAX) return sy_error_set(err, SY_ERR_LIMIT, "bench anim: %s: over 4 GiB", path);
    uint32_t hdr[5] = {0x46546C67u, 2, (uint32_t)(12 + 8 + j->n + 8 + bin_bytes), (uint32_t)j->n, 0x4E4F534Au};
    uint32_t bhdr[2] = {(uint32_t)bin_bytes, 0x004E4942u};
    sy_atomic_file af = {0};
    sy_result r = sy_atomic_file_begin(path, &af, err);
    if (r != SY_OK) return r;
    if (fwrite(hdr, 4, 5, af.fp) != 5 || fwrite(j->s, 1, j->n, af.fp) != j->n || fwrite(bhdr, 4, 2, af.fp) != 2 ||
        fwrite(bin, 1, bin_bytes, af.fp) != bin_bytes) {
        sy_atomic_file_abort(&af);
        return sy_error_set(err, SY_ERR_IO, "%s: write failed", path);
    }
    return sy_atomic_file_commit(&af, err);
}

/* The skinned tube (height 2 along +Y, radius 0.1; the chain of joints along it) and its clip. */
static sy_result write_skinned_glb(const char *path, uint32_t want_vertices, uint32_t *nv_out, uint32_t *nt_out,
                                   sy_error *err)
{
    uint32_t rings = want_vertices / SEGMENTS < 2 ? 2 : want_vertices / SEGMENTS;
    size_t nv = (size_t)rings * SEGMENTS, nt = (size_t)(rings - 1) * SEGMENTS * 2;
    size_t off[9] = {0};
    const size_t sizes[8] = {nv * 12, nv * 12, nv * 8, nv * 16, nt * 12, JOINTS * 64, SKIN_KEYS * 4,
                             (size_t)JOINTS * SKIN_KEYS * 16};
    for (int i = 0; i < 8; ++i) off[i + 1] = off[i] + sizes[i];
    uint8_t *b = calloc(1, off[8]);
    if (!b) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bench anim: out of memory (%zu vertices)", nv);
    float *pos = (float *)(b + off[0]), *nrm = (float *)(b + off[1]), *w = (float *)(b + off[3]);
    uint16_t *jn = (uint16_t *)(b + off[2]);
    uint32_t *idx = (uint32_t *)(b + off[4]);
    float *ibm = (float *)(b + off[5]), *times = (float *)(b + off[6]), *rot = (float *)(b + off[7]);
    float seg = 2.0f / (float)(JOINTS - 1);
    sy_bench_tube(rings, pos, nrm, NULL, jn, w, idx);
    for (uint32_t k = 0; k < JOINTS; ++k) { /* column-major: a translation by -(joint k's height) */
        float *m = ibm + 16 * k;
        m[0] = m[5] = m[10] = m[15] = 1.0f;
        m[13] = -seg * (float)k;
    }
    for (uint32_t i = 0; i < SKIN_KEYS; ++i) times[i] = DURATION * (float)i / (float)(SKIN_KEYS - 1);
    for (uint32_t k = 0; k < JOINTS; ++k)
        for (uint32_t i = 0; i < SKIN_KEYS; ++i) {
            float a = 0.3f * sinf(6.2831853f * (float)i / (float)(SKIN_KEYS - 1) + 0.4f * (float)k);
            float *q = rot + 4 * ((size_t)k * SKIN_KEYS + i);
            q[0] = 0.0f, q[1] = 0.0f, q[2] = sinf(0.5f * a), q[3] = cosf(0.5f * a);
        }
    jtext j = {0};
    jt(&j, "{\"asset\":{\"version\":\"2.0\",\"generator\":\"sy bench anim\"},\"scene\":0,\"scenes\":[{\"nodes\":[0,1]}],"
           "\"nodes\":[{\"name\":\"tube\",\"mesh\":0,\"skin\":0}");
    for (uint32_t k = 0; k < JOINTS; ++k) {
        jt(&j, ",{\"name\":\"joint%u\",\"translation\":[0,%g,0]", k, k ? (double)seg : 0.0);
        if (k + 1 < JOINTS) jt(&j, ",\"children\":[%u]", k + 2);
        jt(&j, "}");
    }
    jt(&j, "],\"skins\":[{\"inverseBindMatrices\":5,\"joints\":[");
    for (uint32_t k = 0; k < JOINTS; ++k) jt(&j, "%s%u", k ? "," : "", k + 1);
    jt(&j, "]}],\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,\"JOINTS_0\":2,"
           "\"WEIGHTS_0\":3},\"indices\":4}]}],\"buffers\":[{\"byteLength\":%zu}],\"bufferViews\":[",
       off[8]);
    for (int i = 0; i < 8; ++i) jt(&j, "%s{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu}", i ? "," : "", off[i], sizes[i]);
    jt(&j, "],\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":%zu,\"type\":\"VEC3\","
           "\"min\":[-0.1,0,-0.1],\"max\":[0.1,2,0.1]},{\"bufferView\":1,\"componentType\":5126,\"count\":%zu,"
           "\"type\":\"VEC3\"},{\"bufferView\":2,\"componentType\":5123,\"count\":%zu,\"type\":\"VEC4\"},"
           "{\"bufferView\":3,\"componentType\":5126,\"count\":%zu,\"type\":\"VEC4\"},"
           "{\"bufferView\":4,\"componentType\":5125,\"count\":%zu,\"type\":\"SCALAR\"},"
           "{\"bufferView\":5,\"componentType\":5126,\"count\":%u,\"type\":\"MAT4\"},"
           "{\"bufferView\":6,\"componentType\":5126,\"count\":%u,\"type\":\"SCALAR\",\"min\":[0],\"max\":[%g]}",
       nv, nv, nv, nv, nt * 3, JOINTS, SKIN_KEYS, (double)DURATION);
    for (uint32_t k = 0; k < JOINTS; ++k)
        jt(&j, ",{\"bufferView\":7,\"byteOffset\":%zu,\"componentType\":5126,\"count\":%u,\"type\":\"VEC4\"}",
           (size_t)k * SKIN_KEYS * 16, SKIN_KEYS);
    jt(&j, "],\"animations\":[{\"name\":\"bend\",\"samplers\":[");
    for (uint32_t k = 0; k < JOINTS; ++k) jt(&j, "%s{\"input\":6,\"output\":%u,\"interpolation\":\"LINEAR\"}", k ? "," : "", 7 + k);
    jt(&j, "],\"channels\":[");
    for (uint32_t k = 0; k < JOINTS; ++k)
        jt(&j, "%s{\"sampler\":%u,\"target\":{\"node\":%u,\"path\":\"rotation\"}}", k ? "," : "", k, k + 1);
    jt(&j, "]}]}");
    sy_result r = write_glb(path, &j, b, off[8], err);
    free(j.s);
    free(b);
    *nv_out = (uint32_t)nv, *nt_out = (uint32_t)nt;
    return r;
}

/* NODES cubes in a 100-wide grid under one root, each turning about Y and bobbing. */
static sy_result write_nodes_glb(const char *path, uint32_t nodes, sy_error *err)
{
    static const float cube[8][3] = {{-.3f, -.3f, -.3f}, {.3f, -.3f, -.3f}, {.3f, .3f, -.3f}, {-.3f, .3f, -.3f},
                                     {-.3f, -.3f, .3f},  {.3f, -.3f, .3f},  {.3f, .3f, .3f},  {-.3f, .3f, .3f}};
    static const uint16_t tri[36] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                                     3, 6, 2, 3, 7, 6, 0, 4, 7, 0, 7, 3, 1, 2, 6, 1, 6, 5};
    size_t off[6] = {0};
    const size_t sizes[5] = {sizeof cube, sizeof tri, NODE_KEYS * 4, (size_t)nodes * NODE_KEYS * 16,
                             (size_t)nodes * NODE_KEYS * 12};
    for (int i = 0; i < 5; ++i) off[i + 1] = off[i] + sizes[i];
    uint8_t *b = calloc(1, off[5]);
    if (!b) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bench anim: out of memory (%u nodes)", nodes);
    memcpy(b + off[0], cube, sizeof cube);
    memcpy(b + off[1], tri, sizeof tri);
    float *times = (float *)(b + off[2]), *rot = (float *)(b + off[3]), *tr = (float *)(b + off[4]);
    for (uint32_t i = 0; i < NODE_KEYS; ++i) times[i] = DURATION * (float)i / (float)(NODE_KEYS - 1);
    for (uint32_t n = 0; n < nodes; ++n) {
        float x = (float)(n % 100), z = (float)(n / 100), phase = 0.37f * (float)n;
        for (uint32_t i = 0; i < NODE_KEYS; ++i) {
            float a = phase + 1.5707963f * (float)i, *q = rot + 4 * ((size_t)n * NODE_KEYS + i), *t = tr + 3 * ((size_t)n * NODE_KEYS + i);
            q[0] = 0.0f, q[1] = sinf(0.5f * a), q[2] = 0.0f, q[3] = cosf(0.5f * a);
            t[0] = x, t[1] = 0.2f * sinf(a), t[2] = z;
        }
    }
    jtext j = {0};
    jt(&j, "{\"asset\":{\"version\":\"2.0\",\"generator\":\"sy bench anim\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
           "\"nodes\":[{\"name\":\"grid\",\"children\":[");
    for (uint32_t n = 0; n < nodes; ++n) jt(&j, "%s%u", n ? "," : "", n + 1);
    jt(&j, "]}");
    for (uint32_t n = 0; n < nodes; ++n) jt(&j, ",{\"mesh\":0,\"translation\":[%u,0,%u]}", n % 100, n / 100);
    jt(&j, "],\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1}]}],"
           "\"buffers\":[{\"byteLength\":%zu}],\"bufferViews\":[",
       off[5]);
    for (int i = 0; i < 5; ++i) jt(&j, "%s{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu}", i ? "," : "", off[i], sizes[i]);
    jt(&j, "],\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":8,\"type\":\"VEC3\","
           "\"min\":[-0.3,-0.3,-0.3],\"max\":[0.3,0.3,0.3]},{\"bufferView\":1,\"componentType\":5123,\"count\":36,"
           "\"type\":\"SCALAR\"},{\"bufferView\":2,\"componentType\":5126,\"count\":%u,\"type\":\"SCALAR\","
           "\"min\":[0],\"max\":[%g]}",
       NODE_KEYS, (double)DURATION);
    for (uint32_t n = 0; n < nodes; ++n) /* rotations 3 + 2n, translations 4 + 2n */
        jt(&j, ",{\"bufferView\":3,\"byteOffset\":%zu,\"componentType\":5126,\"count\":%u,\"type\":\"VEC4\"}"
               ",{\"bufferView\":4,\"byteOffset\":%zu,\"componentType\":5126,\"count\":%u,\"type\":\"VEC3\"}",
           (size_t)n * NODE_KEYS * 16, NODE_KEYS, (size_t)n * NODE_KEYS * 12, NODE_KEYS);
    jt(&j, "],\"animations\":[{\"name\":\"spin\",\"samplers\":[");
    for (uint32_t n = 0; n < 2 * nodes; ++n) jt(&j, "%s{\"input\":2,\"output\":%u}", n ? "," : "", 3 + n);
    jt(&j, "],\"channels\":[");
    for (uint32_t n = 0; n < nodes; ++n)
        jt(&j, "%s{\"sampler\":%u,\"target\":{\"node\":%u,\"path\":\"rotation\"}},"
               "{\"sampler\":%u,\"target\":{\"node\":%u,\"path\":\"translation\"}}",
           n ? "," : "", 2 * n, n + 1, 2 * n + 1, n + 1);
    jt(&j, "]}]}");
    sy_result r = write_glb(path, &j, b, off[5], err);
    free(j.s);
    free(b);
    return r;
}

enum { S_CLOCK, S_COMMIT, S_PULL, S_SYNC, S_DEFORM, S_UPDATE, S_TOP, S_FRAME, S_TOP_FAST, S_COUNT };

/* Per-frame samples of one sink (the no-op mirror or a back-end). */
typedef struct samples {
    double *v[S_COUNT];
    uint32_t n;
} samples;

static double median_of(const samples *s, int k)
{
    double *tmp = malloc(sizeof *tmp * (s->n ? s->n : 1));
    if (!tmp) return 0.0;
    memcpy(tmp, s->v[k], sizeof *tmp * s->n);
    double m = s->n ? sy_bench_spread_of(tmp, s->n).median : 0.0;
    free(tmp);
    return m;
}

static void row(const char *what, const samples *s, int k)
{
    double *tmp = malloc(sizeof *tmp * (s->n ? s->n : 1));
    if (!tmp || !s->n) {
        free(tmp);
        return;
    }
    memcpy(tmp, s->v[k], sizeof *tmp * s->n);
    sy_bench_spread sp = sy_bench_spread_of(tmp, s->n);
    printf("    %-46s %9.3f ms (%.3f .. %.3f)\n", what, 1e3 * sp.median, 1e3 * sp.min, 1e3 * sp.max);
    free(tmp);
}

/* Frame i's time of `frames` spread over [t0, t1] (never the first key: every channel moves). */
static double frame_time(double t0, double t1, uint32_t i, uint32_t frames) { return t0 + (t1 - t0) * (double)(i + 1) / (double)(frames + 1); }

/* Clock + commit of frame i into s (times in sm). */
static sy_result step_clock(sy_scene *s, sy_animation clip, double t, samples *sm, uint32_t i, sy_anim_stats *st, sy_error *err)
{
    double a = sy_time_now();
    sy_result r = sy_scene_set_time_ex(s, clip, t, st, err);
    double b = sy_time_now();
    if (r == SY_OK) r = sy_scene_commit(s, NULL, err);
    double c = sy_time_now();
    sm->v[S_CLOCK][i] = b - a, sm->v[S_COMMIT][i] = c - b;
    return r;
}

/* The last sync's deformation of a context: seconds, primitive instances deformed, of them shared. */
static void ctx_deform(sy_context *ctx, bool rt, double *sec, uint32_t *deformed, uint32_t *shared)
{
    *sec = 0.0, *deformed = *shared = 0;
#ifdef SY_HAVE_EMBREE
    if (rt) {
        sy_mediator_rt_counters rc;
        sy_mediator_rt_counters_get(sy_context_state(ctx), &rc);
        *sec = rc.last_sync_deform_seconds, *deformed = rc.last_sync_deformed, *shared = rc.last_sync_deform_shared;
    }
#endif
#ifdef SY_HAVE_RASTER
    if (!rt) {
        sy_mediator_raster_counters rc;
        sy_mediator_raster_counters_get(sy_context_state(ctx), &rc);
        *sec = rc.last_sync_deform_seconds, *deformed = rc.last_sync_deformed, *shared = rc.last_sync_deform_shared;
    }
#endif
    (void)ctx, (void)rt;
}

/* 1 and 3 contexts on one scene, the poses shared or not: deformation per frame over all contexts. */
static sy_result bench_contexts(sy_scene *s, sy_animation clip, uint32_t root, double t0, double t1, samples *sm, sy_error *err)
{
    static const char *const want[] = {"whitted", "pathtracer", "raster"};
    const char *names[3];
    bool rt[3]; /* a ray tracer's counters (want[0], want[1]) or the rasterizer's */
    sy_context *ctx[3] = {NULL, NULL, NULL};
    uint32_t n = 0;
    sy_result r = sy_scene_set_time(s, clip, t0, err);
    if (r == SY_OK) r = sy_scene_commit(s, NULL, err);
    for (size_t k = 0; k < 3 && r == SY_OK; ++k) {
        bool found = sy_mediator_find(want[k]) != NULL;
        const char *b = found ? want[k] : "whitted";
        sy_error e2 = {0};
        if (!sy_mediator_find(b) || sy_context_create(s, b, NULL, root, &ctx[n], &e2) != SY_OK) continue;
        rt[n] = !found || k < 2;
        names[n++] = b;
    }
    for (; n && n < 3 && r == SY_OK; ++n) { /* fewer back-ends start here: whitted again */
        names[n] = "whitted";
        rt[n] = true;
        r = sy_context_create(s, "whitted", NULL, root, &ctx[n], err);
    }
    if (r != SY_OK || n < 3) {
        for (uint32_t k = 0; k < 3; ++k) sy_context_release(ctx[k]);
        if (r == SY_OK) printf("  several contexts: skipped (no ray tracer built)\n");
        return r;
    }
    printf("  contexts on one scene (deformation per frame, summed over the contexts; poses deformed / shared):\n");
    double base = 0.0, unshared3 = 0.0, shared3 = 0.0;
    static const struct { uint32_t contexts; bool sharing; const char *what; } runs[3] = {
        {1, true, "1 context (%s)"}, {3, false, "3 contexts, each deforms its own (sharing off)"},
        {3, true, "3 contexts, poses shared (sy_deform_cache)"}};
    for (int run = 0; run < 3 && r == SY_OK; ++run) {
        sy_deform_cache_set_sharing(runs[run].sharing);
        uint32_t nc = runs[run].contexts, made = 0, taken = 0;
        for (uint32_t k = 0; k < nc && r == SY_OK; ++k) r = sy_context_sync(ctx[k], err); /* catch up */
        for (uint32_t i = 0; i < sm->n && r == SY_OK; ++i) {
            r = step_clock(s, clip, frame_time(t0, t1, i, sm->n), sm, i, NULL, err);
            sm->v[S_DEFORM][i] = 0.0;
            for (uint32_t k = 0; k < nc && r == SY_OK; ++k) {
                r = sy_context_sync(ctx[k], err);
                double sec;
                uint32_t d, sh;
                ctx_deform(ctx[k], rt[k], &sec, &d, &sh);
                sm->v[S_DEFORM][i] += sec;
                made += d - sh, taken += sh;
            }
        }
        if (r != SY_OK) break;
        char what[96];
        snprintf(what, sizeof what, runs[run].what, names[0]);
        row(what, sm, S_DEFORM);
        printf("      %.2f poses deformed, %.2f shared per frame\n", (double)made / sm->n, (double)taken / sm->n);
        double m = median_of(sm, S_DEFORM);
        if (run == 0) base = m;
        else if (run == 1) unshared3 = m;
        else shared3 = m;
    }
    sy_deform_cache_set_sharing(true);
    if (r == SY_OK)
        printf("    3 contexts / 1 context: %.2f sharing off, %.2f shared (shared / off %.3f)\n", unshared3 / base,
               shared3 / base, shared3 / unshared3);
    for (uint32_t k = 0; k < 3; ++k) sy_context_release(ctx[k]);
    return r;
}

/* One scene (loaded from path): the no-op mirror, then each back-end. */
static sy_result bench_scene(const char *label, const char *path, uint32_t frames, bool contexts, sy_error *err)
{
    sy_scene *s = NULL;
    sy_gltf_info info = {0};
    samples sm = {.n = frames};
    for (int k = 0; k < S_COUNT; ++k) sm.v[k] = calloc(frames, sizeof(double));
    sy_result r = SY_OK;
    for (int k = 0; k < S_COUNT && r == SY_OK; ++k)
        if (!sm.v[k]) r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bench anim: out of memory");
    double a = sy_time_now();
    if (r == SY_OK) r = sy_scene_create(&s, err);
    if (r == SY_OK) r = sy_gltf_load(path, s, NULL, &info, err);
    if (r == SY_OK && info.animation_count != 1)
        r = sy_error_set(err, SY_ERR_PARSE, "bench anim: %s: %u animations loaded, 1 expected", path, info.animation_count);
    double load = sy_time_now() - a, t0 = 0.0, t1 = 0.0;
    sy_animation clip = r == SY_OK ? info.animations[0] : (sy_animation){0};
    if (r == SY_OK) r = sy_scene_time_range(s, clip, &t0, &t1, err);
    sy_anim_stats ast = {0};
    if (r == SY_OK) r = sy_scene_set_time_ex(s, clip, t0, &ast, err);
    if (r == SY_OK) r = sy_scene_commit(s, NULL, err);
    if (r == SY_OK)
        printf("\n%s\n  %s loaded by sy_gltf_load in %.1f ms; clip %.2f .. %.2f s, %u channels; %u frames\n", label, path,
               1e3 * load, t0, t1, ast.channels, frames);
    /* the change list and the mirror with a back-end that keeps nothing */
    if (r == SY_OK) {
        sy_mirror *m = NULL;
        uint32_t consumer = 0, entries = 0;
        sy_mirror_desc d = {"bench mirror", info.root.id, &sy_bench_nop_mirror, NULL};
        sy_changes *c = NULL;
        r = sy_mirror_create(&d, &m, err);
        if (r == SY_OK) r = sy_scene_consumer_add(s, &consumer, err);
        if (r == SY_OK) r = sy_scene_consumer_pull(s, consumer, &c, err);
        if (r == SY_OK) r = sy_mirror_sync(m, c, NULL, err);
        sy_changes_release(c);
        c = NULL;
        for (uint32_t i = 0; i < frames && r == SY_OK; ++i) {
            r = step_clock(s, clip, frame_time(t0, t1, i, frames), &sm, i, NULL, err);
            double b = sy_time_now();
            if (r == SY_OK) r = sy_scene_consumer_pull(s, consumer, &c, err);
            double e = sy_time_now();
            sy_mirror_sync_stats ms = {0};
            if (r == SY_OK) r = sy_mirror_sync(m, c, &ms, err);
            sm.v[S_PULL][i] = e - b, sm.v[S_SYNC][i] = sy_time_now() - e, sm.v[S_DEFORM][i] = ms.deform_seconds;
            if (c) entries = sy_changes_count(c);
            sy_changes_release(c);
            c = NULL;
        }
        if (r == SY_OK) {
            char what[96];
            row("clock (sy_scene_set_time)", &sm, S_CLOCK);
            row("commit (change list sealed, world matrices)", &sm, S_COMMIT);
            snprintf(what, sizeof what, "change list pulled (%u entries)", entries);
            row(what, &sm, S_PULL);
            row("mirror sync, no-op back-end", &sm, S_SYNC);
            row("  of which deformation (sy_deform_primitive)", &sm, S_DEFORM);
        }
        if (consumer) sy_scene_consumer_remove(s, consumer);
        sy_mirror_destroy(m);
    }
    /* per back-end: a frame against translating that frame from scratch */
    static const char *const backends[] = {"whitted", "pathtracer", "raster"};
    for (size_t bk = 0; bk < sizeof backends / sizeof backends[0] && r == SY_OK; ++bk) {
        if (!sy_mediator_find(backends[bk])) continue;
        bool rt = bk < 2;
        sy_context *ctx = NULL, *ctx_fast = NULL;
        sy_error e2 = {0};
        sy_result r2 = sy_scene_set_time(s, clip, t0, &e2);
        if (r2 == SY_OK) r2 = sy_scene_commit(s, NULL, &e2);
        if (r2 == SY_OK) r2 = sy_context_create(s, backends[bk], NULL, info.root.id, &ctx, &e2);
        if (r2 == SY_OK) r2 = sy_context_sync(ctx, &e2);
#ifdef SY_HAVE_EMBREE
        /* the ray tracers: a second context whose top level is built for frequent updates where
         * most instances move (sy_mediator_rt_set_top_fast: Embree's dynamic scene, LOW quality),
         * synced with the same frames, before or after the first in turn */
        if (r2 == SY_OK && rt) r2 = sy_context_create(s, backends[bk], NULL, info.root.id, &ctx_fast, &e2);
        if (r2 == SY_OK && rt) {
            sy_mediator_rt_set_top_fast(sy_context_state(ctx_fast), true);
            r2 = sy_context_sync(ctx_fast, &e2);
        }
#endif
        for (uint32_t i = 0; i < frames && r2 == SY_OK; ++i) {
            r2 = step_clock(s, clip, frame_time(t0, t1, i, frames), &sm, i, NULL, &e2);
            sm.v[S_TOP_FAST][i] = 0.0;
            if (r2 == SY_OK && ctx_fast && i % 2) r2 = sy_context_sync(ctx_fast, &e2);
#ifdef SY_HAVE_EMBREE
            if (r2 == SY_OK && ctx_fast && i % 2) {
                sy_mediator_rt_counters rc;
                sy_mediator_rt_counters_get(sy_context_state(ctx_fast), &rc);
                sm.v[S_TOP_FAST][i] = rc.last_sync_top_commit_seconds;
            }
#endif
            double b = sy_time_now();
            if (r2 == SY_OK) r2 = sy_context_sync(ctx, &e2);
            sm.v[S_SYNC][i] = sy_time_now() - b;
            if (r2 == SY_OK && ctx_fast && !(i % 2)) r2 = sy_context_sync(ctx_fast, &e2);
#ifdef SY_HAVE_EMBREE
            if (r2 == SY_OK && ctx_fast && !(i % 2)) {
                sy_mediator_rt_counters rc;
                sy_mediator_rt_counters_get(sy_context_state(ctx_fast), &rc);
                sm.v[S_TOP_FAST][i] = rc.last_sync_top_commit_seconds;
            }
#endif
            sm.v[S_FRAME][i] = sm.v[S_CLOCK][i] + sm.v[S_COMMIT][i] + sm.v[S_SYNC][i];
            sm.v[S_DEFORM][i] = sm.v[S_UPDATE][i] = sm.v[S_TOP][i] = 0.0;
#ifdef SY_HAVE_EMBREE
            if (r2 == SY_OK && rt) {
                sy_mediator_rt_counters rc;
                sy_mediator_rt_counters_get(sy_context_state(ctx), &rc);
                sm.v[S_DEFORM][i] = rc.last_sync_deform_seconds, sm.v[S_UPDATE][i] = rc.last_sync_refit_seconds;
                sm.v[S_TOP][i] = rc.last_sync_top_commit_seconds;
            }
#endif
#ifdef SY_HAVE_RASTER
            if (r2 == SY_OK && !rt) {
                sy_mediator_raster_counters rc;
                sy_mediator_raster_counters_get(sy_context_state(ctx), &rc);
                sm.v[S_DEFORM][i] = rc.last_sync_deform_seconds, sm.v[S_UPDATE][i] = rc.last_sync_upload_seconds;
            }
#endif
        }
        sy_context_release(ctx);
        sy_context_release(ctx_fast);
        ctx = NULL;
        /* the last frame, translated from scratch: a new context and its first sync */
        double scratch = 0.0;
        if (r2 == SY_OK) {
            double b = sy_time_now();
            r2 = sy_context_create(s, backends[bk], NULL, info.root.id, &ctx, &e2);
            if (r2 == SY_OK) r2 = sy_context_sync(ctx, &e2);
            scratch = sy_time_now() - b;
            sy_context_release(ctx);
        }
        if (r2 != SY_OK) { /* no GL provider here, say: not an error of the benchmark */
            printf("  %s: skipped: %s\n", backends[bk], e2.message);
            continue;
        }
        printf("  %s:\n", backends[bk]);
        row("clock + commit + sync (the frame)", &sm, S_FRAME);
        row("  context sync", &sm, S_SYNC);
        row("    of which deformation", &sm, S_DEFORM);
        row(rt ? "    of which vertex copy + BVH refit" : "    of which vertex buffer upload", &sm, S_UPDATE);
        if (rt) {
            row("    of which top-level commit", &sm, S_TOP);
            row("    top-level commit, dynamic LOW (same frames)", &sm, S_TOP_FAST);
            double a = median_of(&sm, S_TOP), q = median_of(&sm, S_TOP_FAST);
            if (a > 0.0 && q > 0.0) printf("      dynamic LOW / MEDIUM (the default) %.3f\n", q / a);
        }
        double f = median_of(&sm, S_FRAME);
        printf("    %-46s %9.3f ms   frame / scratch %.4f (x%.0f)\n", "from scratch (new context + first sync)",
               1e3 * scratch, f / scratch, scratch / f);
    }
    if (r == SY_OK && contexts) r = bench_contexts(s, clip, info.root.id, t0, t1, &sm, err);
    for (int k = 0; k < S_COUNT; ++k) free(sm.v[k]);
    sy_gltf_info_free(&info);
    sy_scene_destroy(s);
    return r;
}

sy_result sy_bench_anim(uint32_t vertices, uint32_t nodes, uint32_t frames, sy_error *err)
{
    char dir[] = "/tmp/sy_bench_anim_XXXXXX", skinned[128], grid[128];
    if (!mkdtemp(dir)) return sy_error_set(err, SY_ERR_IO, "bench anim: cannot create a temporary directory");
    snprintf(skinned, sizeof skinned, "%s/skinned_tube.glb", dir);
    snprintf(grid, sizeof grid, "%s/animated_nodes.glb", dir);
    uint32_t nv = 0, nt = 0;
    printf("sy bench anim: each scene written to a .glb and loaded by sy_gltf_load; per frame, median (min .. max) "
           "of %u frames\n",
           frames);
    sy_result r = write_skinned_glb(skinned, vertices, &nv, &nt, err);
    char label[160];
    snprintf(label, sizeof label, "skinned mesh: %u vertices, %u triangles, %u joints (2 influences per vertex)", nv, nt,
             JOINTS);
    if (r == SY_OK) r = bench_scene(label, skinned, frames, true, err);
    unlink(skinned);
    if (r == SY_OK) r = write_nodes_glb(grid, nodes, err);
    snprintf(label, sizeof label, "animated nodes: %u cubes (one shared mesh), a rotation and a translation channel each",
             nodes);
    if (r == SY_OK) r = bench_scene(label, grid, frames, false, err);
    unlink(grid);
    rmdir(dir);
    return r;
}
