/* sy_bench_sync.c — `sy bench sync`: a change to one node of a large generated scene, applied
 * incrementally (commit + sync), against translating the scene from scratch, per back-end, on the
 * scene as generated and written to a .glb and loaded back (the user's path; see sy_bench.h). */
#include "sy_bench.h"

#include "sy_demo.h"
#include "sy_load.h"
#ifdef SY_HAVE_EMBREE
#include "sy_mediator_rt.h"
#endif
#ifdef SY_HAVE_RASTER
#include "sy_mediator_raster.h"
#endif

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* One back-end's part of sy bench sync: translation from scratch (a new context's first sync),
 * then per repeat one transform change (set + commit + sync) with its parts: core (set + commit)
 * and, for the Embree back-ends, Embree's rebuild of the top-level BVH inside the sync. */
typedef struct sync_result {
    double full;
    double *total, *core, *embree, *ours; /* per repeat; embree stays 0 where not measured */
    uint32_t placements;
    bool has_embree;
} sync_result;

static void print_spread(const char *label, double *v, uint32_t n, const char *note)
{
    sy_bench_spread sp = sy_bench_spread_of(v, n);
    printf("    %-30s %9.3f ms  (%.3f .. %.3f)%s%s\n", label, sp.median * 1e3, sp.min * 1e3, sp.max * 1e3,
           note ? "  " : "", note ? note : "");
}

static sy_result bench_sync_backend(sy_scene *s, const char *backend, sy_node root, sy_node leaf, uint32_t repeats,
                                    size_t *log_bytes, sync_result *out, sy_error *err)
{
    sy_context *ctx = NULL;
    double t0 = sy_time_now();
    sy_result r = sy_context_create(s, backend, NULL, root.id, &ctx, err);
    if (r == SY_OK) r = sy_context_sync(ctx, err);
    out->full = sy_time_now() - t0;
    for (uint32_t i = 0; i < repeats && r == SY_OK; ++i) {
        double a = sy_time_now();
        r = sy_bench_move(s, leaf, 0.01f * (float)(i + 1), err);
        double b = sy_time_now();
        if (r == SY_OK && i == 0 && log_bytes) *log_bytes = sy_scene_log_bytes(s); /* the one sealed, unpulled list */
        if (r == SY_OK) r = sy_context_sync(ctx, err);
        double c = sy_time_now();
        out->total[i] = c - a;
        out->core[i] = b - a;
        out->embree[i] = 0.0;
#ifdef SY_HAVE_EMBREE
        if (r == SY_OK && out->has_embree) {
            sy_mediator_rt_counters rc;
            sy_mediator_rt_counters_get(sy_context_state(ctx), &rc);
            out->embree[i] = rc.last_sync_top_commit_seconds;
            if (i == 0) out->placements = rc.last_sync_placements;
        }
#endif
#ifdef SY_HAVE_RASTER
        if (r == SY_OK && !out->has_embree && i == 0) {
            sy_mediator_raster_counters rc;
            sy_mediator_raster_counters_get(sy_context_state(ctx), &rc);
            out->placements = rc.last_sync_placements;
        }
#endif
        out->ours[i] = out->total[i] - out->embree[i];
    }
    sy_context_release(ctx);
    return r;
}

static void print_sync(const char *title, sync_result *sr, uint32_t repeats, uint32_t instances)
{
    printf("  %s\n", title);
    printf("    %-30s %9.3f ms  (new context: snapshot -> back-end scene)\n", "translate from scratch", sr->full * 1e3);
    double med_total = sy_bench_spread_of(sr->total, repeats).median; /* before print_spread sorts them */
    double med_ours = sy_bench_spread_of(sr->ours, repeats).median;
    print_spread("one transform change", sr->total, repeats, "set + commit + sync, median (min .. max)");
    print_spread("  core: set + commit", sr->core, repeats, NULL);
    if (sr->has_embree) {
        char note[96];
        snprintf(note, sizeof note, "rtcCommitScene: the moved instances' scene (%u instances in all)", instances);
        print_spread("  Embree commits", sr->embree, repeats, note);
        print_spread("  ours (all but Embree's)", sr->ours, repeats, "core + pull + mirror + mediator + back-end");
    }
    printf("    ratio full / incremental       %9.1f x   (goal >= 10000)\n", sr->full / med_total);
    if (sr->has_embree) printf("    ratio full / ours              %9.1f x\n", sr->full / med_ours);
    printf("    placements recomputed          %9u\n", sr->placements);
}

sy_result sy_bench_sync(uint32_t nodes, uint32_t tris, uint32_t repeats, sy_error *err)
{
#if !defined SY_HAVE_EMBREE && !defined SY_HAVE_RASTER
    (void)nodes, (void)tris, (void)repeats;
    SY_BENCH_WITHOUT(err, "sync (whitted or raster)", "SY_WITH_EMBREE and SY_WITH_RASTER");
#else
    uint32_t per_group = nodes < 100 ? nodes : 100, groups = (nodes + per_group - 1) / per_group;
    sy_scene *s = NULL;
    double *buf = calloc((size_t)repeats * 4u, sizeof *buf);
    sy_result r = buf ? sy_scene_create(&s, err) : sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bench: out of memory");
    sy_node root = {0}, leaf = {0};
    double t0 = sy_time_now();
    if (r == SY_OK) r = sy_demo_bench_scene(s, groups, per_group, tris, &root, &leaf, err);
    if (r == SY_OK) r = sy_scene_commit(s, NULL, err);
    double t_build = sy_time_now() - t0;
    uint32_t total_tris = 0;
    for (uint32_t id = sy_scene_next(s, SY_TYPE_MESH, 0); r == SY_OK && id; id = sy_scene_next(s, SY_TYPE_MESH, id)) {
        const sy_mesh_data *m = sy_object_get(s, SY_TYPE_MESH, id);
        total_tris += sy_primitive_triangle_count(&m->primitives.items[0]);
    }
    /* the user's path (issue 39): the same scene written to a .glb and loaded by sy_cli_load */
    loaded ld = {0};
    sy_node froot = {0}, fleaf = {0};
    if (r == SY_OK) r = sy_bench_reload_glb(s, root, NULL, "sy bench sync", &ld, NULL, err);
    if (r == SY_OK) froot = ld.root, r = sy_bench_first_mesh_node(ld.scene, froot, &fleaf, err);
    size_t log_bytes = 0;
    if (r == SY_OK) {
        printf("sy bench sync: %u nodes (%u groups x %u), %u triangles, %u repeats\n", groups * per_group, groups,
               per_group, total_tris, repeats);
        printf("  scene build (core)               %9.3f ms\n", t_build * 1e3);
    }
    sync_result sr = {.total = buf, .core = buf + repeats, .embree = buf + 2u * repeats, .ours = buf + 3u * repeats};
    /* each back-end on the generated scene, then on the same through the .glb */
    for (int f = 0; f < 2 && r == SY_OK; ++f) {
        sy_scene *sc = f ? ld.scene : s;
        sy_node rt = f ? froot : root, lf = f ? fleaf : leaf;
        const char *via = f ? ", through a .glb" : "";
        char title[96];
#ifdef SY_HAVE_EMBREE
        sr.has_embree = true;
        r = bench_sync_backend(sc, "whitted", rt, lf, repeats, f ? NULL : &log_bytes, &sr, err);
        snprintf(title, sizeof title, "whitted (Embree)%s", via);
        if (r == SY_OK) print_sync(title, &sr, repeats, groups * per_group);
#endif
#ifdef SY_HAVE_RASTER
        if (r == SY_OK) {
            sr.has_embree = false;
            sy_error e2 = {0};
            sy_result r2 =
                bench_sync_backend(sc, "raster", rt, lf, repeats, f || log_bytes ? NULL : &log_bytes, &sr, &e2);
            snprintf(title, sizeof title, "raster (OpenGL)%s", via);
            if (r2 == SY_OK) print_sync(title, &sr, repeats, 0);
            else printf("  %s: skipped: %s\n", title, e2.message); /* no GL provider here: not an error */
        }
#endif
    }
    if (r == SY_OK) printf("  change log per change           %10zu bytes\n", log_bytes);
    sy_cli_loaded_free(&ld);
    sy_scene_destroy(s);
    free(buf);
    return r;
#endif
}
