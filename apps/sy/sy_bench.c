/* sy_bench.c — sync and ray benchmarks (see sy_bench.h). */
#include "sy_bench.h"

#include "sy_compose.h"
#include "sy_demo.h"
#include "sy_height_field.h"
#ifdef SY_HAVE_RASTER
#include "sy_mediator_raster.h"
#endif
#ifdef SY_HAVE_EMBREE
#include "sy_mediator_rt.h"
#endif

/* A benchmark of a back-end this build lacks (SY_WITH_EMBREE / SY_WITH_RASTER off) says so. */
#define SY_BENCH_WITHOUT(err, what, option)                                                                            \
    return sy_error_set(err, SY_ERR_UNSUPPORTED, "sy bench: %s needs a back-end this sy was built without (%s=OFF)",   \
                        what, option)

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

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
        static const float q[4] = {0, 0, 0, 1}, one[3] = {1, 1, 1};
        float t[3] = {0.01f * (float)(i + 1), 0.0f, 0.0f};
        double a = sy_time_now();
        r = sy_node_set_trs(s, leaf, t, q, one, err);
        if (r == SY_OK) r = sy_scene_commit(s, NULL, err);
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
    size_t log_bytes = 0;
    if (r == SY_OK) {
        printf("sy bench sync: %u nodes (%u groups x %u), %u triangles, %u repeats\n", groups * per_group, groups,
               per_group, total_tris, repeats);
        printf("  scene build (core)               %9.3f ms\n", t_build * 1e3);
    }
    sync_result sr = {.total = buf, .core = buf + repeats, .embree = buf + 2u * repeats, .ours = buf + 3u * repeats};
#ifdef SY_HAVE_EMBREE
    sr.has_embree = true;
    if (r == SY_OK) r = bench_sync_backend(s, "whitted", root, leaf, repeats, &log_bytes, &sr, err);
    if (r == SY_OK) print_sync("whitted (Embree)", &sr, repeats, groups * per_group);
#endif
#ifdef SY_HAVE_RASTER
    if (r == SY_OK) {
        sr.has_embree = false;
        sy_error e2 = {0};
        sy_result r2 = bench_sync_backend(s, "raster", root, leaf, repeats, log_bytes ? NULL : &log_bytes, &sr, &e2);
        if (r2 == SY_OK) print_sync("raster (OpenGL)", &sr, repeats, 0);
        else printf("  raster (OpenGL): skipped: %s\n", e2.message); /* no GL provider here: not an error */
    }
#endif
    if (r == SY_OK) printf("  change log per change           %10zu bytes\n", log_bytes);
    sy_scene_destroy(s);
    free(buf);
    return r;
#endif
}

sy_result sy_bench_rays(sy_scene *scene, const sy_viewport_desc *vd, uint32_t width, uint32_t height, uint32_t repeats,
                        sy_error *err)
{
#ifndef SY_HAVE_EMBREE
    (void)scene, (void)vd, (void)width, (void)height, (void)repeats;
    SY_BENCH_WITHOUT(err, "rays (whitted)", "SY_WITH_EMBREE");
#else
    sy_window *win = NULL;
    sy_viewport *vp = NULL;
    sy_context *ctx = NULL;
    sy_camera_view view;
    sy_result r = sy_window_create(width, height, &win, err);
    if (r == SY_OK) r = sy_window_add_viewport(win, vd, &vp, err);
    if (r == SY_OK) r = sy_viewport_camera_view(vp, scene, width, height, &view, err);
    if (r == SY_OK) r = sy_context_create(scene, "whitted", NULL, vd->root.id, &ctx, err);
    if (r == SY_OK) r = sy_context_sync(ctx, err);
    sy_mediator_rt_bench b;
    if (r == SY_OK) r = sy_mediator_rt_bench_rays(sy_context_state(ctx), &view, width, height, repeats, &b, err);
    if (r == SY_OK) {
        printf("sy bench rays: %ux%u primary rays, %u threads, best of %u\n", width, height, b.threads, repeats);
        printf("  whitted back-end (primary)  %8.2f Mrays/s\n", b.ours_mrays);
        printf("  raw Embree rtcIntersect1    %8.2f Mrays/s\n", b.raw_mrays);
        printf("  overhead                    %8.1f %%   (goal < 25 %%)\n", b.overhead_percent);
    }
    sy_context_release(ctx);
    sy_window_destroy(win);
    return r;
#endif
}

static double best_of(double a, double b) { return a < b ? a : b; }

sy_result sy_bench_viewports(uint32_t width, uint32_t height, uint32_t repeats, sy_error *err)
{
    /* 1. compositing: two full-HD layers, half covered by the top one at a nearer depth */
    sy_layer a = {0}, b = {0};
    sy_result r = sy_layer_create(1920, 1080, &a, err);
    if (r == SY_OK) r = sy_layer_create(1920, 1080, &b, err);
    if (r != SY_OK) {
        sy_layer_destroy(&a);
        return r;
    }
    for (size_t i = 0; i < (size_t)1920 * 1080; ++i) {
        for (int c = 0; c < 4; ++c) a.rgba[4 * i + c] = 0.5f, b.rgba[4 * i + c] = (i & 1) ? 0.25f : 0.0f;
        a.depth[i] = 5.0f;
        b.depth[i] = (i & 1) ? 2.0f : INFINITY;
    }
    double t_depth = 1e30, t_over = 1e30;
    for (uint32_t k = 0; k < repeats; ++k) {
        double t0 = sy_time_now();
        sy_layer_composite(&a, &b, 0, 0, SY_COMPOSITE_DEPTH);
        double t1 = sy_time_now();
        sy_layer_composite(&a, &b, 0, 0, SY_COMPOSITE_ALPHA_OVER);
        double t2 = sy_time_now();
        t_depth = best_of(t_depth, t1 - t0);
        t_over = best_of(t_over, t2 - t1);
    }
    sy_layer_destroy(&a);
    sy_layer_destroy(&b);
    printf("sy bench viewports\n");
    printf("  composite 2 x 1920x1080, depth       %8.3f ms  (one core, best of %u; goal < 5 ms)\n", t_depth * 1e3,
           repeats);
    printf("  composite 2 x 1920x1080, alpha-over  %8.3f ms\n", t_over * 1e3);

    /* 2. switching back-ends on the demo scene */
    sy_scene *s = NULL;
    sy_demo_info demo;
    sy_context_pool *pool = NULL;
    if ((r = sy_scene_create(&s, err)) || (r = sy_demo_build(s, &demo, err)) || (r = sy_scene_commit(s, NULL, err)) ||
        (r = sy_context_pool_create(&pool, err))) {
        sy_scene_destroy(s);
        return r;
    }
    uint32_t nb = sy_mediator_count();
    for (uint32_t i = 0; i < nb && r == SY_OK; ++i) {
        const char *name = sy_mediator_at(i)->name;
        sy_compose_spec spec = {.backend = name, .root = demo.root, .camera = demo.camera,
                                .background = demo.background, .eye_separation = 0.065f, .zero_parallax = 4.0f};
        sy_layer img = {0}, right = {0};
        double first = 0, again = 0, mono = 1e30, sbs = 1e30;
        for (uint32_t k = 0; k < 2 && r == SY_OK; ++k) { /* first use translates, second reuses the context */
            double t0 = sy_time_now();
            sy_context *ctx;
            r = sy_context_pool_get(pool, s, name, NULL, demo.root.id, &ctx, err);
            if (r == SY_OK) r = sy_context_sync(ctx, err);
            if (k) again = sy_time_now() - t0;
            else first = sy_time_now() - t0;
        }
        for (uint32_t k = 0; k < repeats && r == SY_OK; ++k) {
            spec.stereo = SY_STEREO_NONE;
            double t0 = sy_time_now();
            r = sy_compose_render(s, pool, &spec, width, height, NULL, &img, &right, err);
            mono = best_of(mono, sy_time_now() - t0);
            sy_layer_destroy(&img);
            if (r != SY_OK) break;
            spec.stereo = SY_STEREO_SBS;
            t0 = sy_time_now();
            r = sy_compose_render(s, pool, &spec, width, height, NULL, &img, &right, err);
            sbs = best_of(sbs, sy_time_now() - t0);
            sy_layer_destroy(&img);
        }
        if (r == SY_OK)
            printf("  %-10s first use %9.3f ms, switch back %7.3f ms; per eye: mono %8.3f ms, stereo %8.3f ms "
                   "(overhead %+.1f %%)\n",
                   name, first * 1e3, again * 1e3, mono * 1e3, sbs * 0.5e3, (sbs * 0.5 / mono - 1.0) * 100.0);
    }
    printf("  contexts in the pool: %u (one per back-end: both eyes share one)\n", sy_context_pool_size(pool));
    sy_context_pool_destroy(pool);
    sy_scene_destroy(s);
    return r;
}

/* >>bench raster: our frame against the floor (the same buffers, trivial shader), transform
 * latency and uploads per frame, for one scene. */
static inline double median_of(double *t, uint32_t n) /* inline: used only with the rasterizer */
{
    qsort(t, n, sizeof *t, cmp_double);
    return t[n / 2];
}

sy_bench_spread sy_bench_spread_of(double *v, uint32_t n)
{
    qsort(v, n, sizeof *v, cmp_double);
    double med = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
    return (sy_bench_spread){v[0], med, v[n - 1]};
}

#ifdef SY_HAVE_RASTER
static sy_result bench_raster_scene(const char *label, sy_scene *scene, const sy_viewport_desc *vd, sy_node moved,
                                    uint32_t width, uint32_t height, uint32_t repeats, sy_error *err)
{
    sy_window *win = NULL;
    sy_viewport *vp = NULL;
    sy_context *ctx = NULL;
    sy_layer layer = {0};
    sy_camera_view view = {0};
    sy_params params;
    double *t = calloc(repeats, sizeof *t);
    sy_result r = t ? sy_window_create(width, height, &win, err) : sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bench: out of memory");
    if (r == SY_OK) r = sy_window_add_viewport(win, vd, &vp, err);
    if (r == SY_OK) r = sy_viewport_camera_view(vp, scene, width, height, &view, err);
    if (r == SY_OK) r = sy_params_parse(vd->params, &params, err);
    if (r == SY_OK) r = sy_context_create(scene, "raster", &params, vd->root.id, &ctx, err);
    double t0 = sy_time_now();
    if (r == SY_OK) r = sy_context_sync(ctx, err);
    double t_sync = sy_time_now() - t0;
    if (r == SY_OK) r = sy_layer_create(width, height, &layer, err);
    sy_render_request rq = {.camera = view, .full_width = width, .full_height = height, .rect_w = width, .rect_h = height,
                            .background_id = vd->background.id};
    void *st = ctx ? sy_context_state(ctx) : NULL;
    double latency = 0;
    sy_bench_spread ours = {0}, floor_t = {0}, floor_lit = {0}, ratio = {0}, ratio_lit = {0};
    sy_mediator_raster_counters first = {0}, steady = {0}, moved_c = {0};
    if (r == SY_OK) r = sy_context_render(ctx, &rq, &layer, err); /* warm-up: first frame, shadow maps, shaders */
    if (r == SY_OK) sy_mediator_raster_counters_get(st, &first);
    if (r == SY_OK) r = sy_mediator_raster_render_floor(st, &rq, false, &layer, err); /* their warm-ups */
    if (r == SY_OK) r = sy_mediator_raster_render_floor(st, &rq, true, &layer, err);
    if (r == SY_OK) r = sy_context_render(ctx, &rq, &layer, err);
    if (r == SY_OK) sy_mediator_raster_counters_get(st, &steady);
    /* ours and the floors alternate frame by frame, so that other load on the machine weighs on
     * all alike; the ratios are taken per repeat */
    double *tf = r == SY_OK ? calloc(4u * (size_t)repeats, sizeof *tf) : NULL;
    if (r == SY_OK && !tf) r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bench: out of memory");
    double *tl = tf + repeats, *q0 = tl + repeats, *q1 = q0 + repeats;
    for (uint32_t i = 0; i < repeats && r == SY_OK; ++i) {
        double a = sy_time_now();
        r = sy_context_render(ctx, &rq, &layer, err);
        t[i] = sy_time_now() - a;
        a = sy_time_now();
        if (r == SY_OK) r = sy_mediator_raster_render_floor(st, &rq, false, &layer, err);
        tf[i] = sy_time_now() - a;
        a = sy_time_now();
        if (r == SY_OK) r = sy_mediator_raster_render_floor(st, &rq, true, &layer, err);
        tl[i] = sy_time_now() - a;
        q0[i] = t[i] / tf[i];
        q1[i] = t[i] / tl[i];
    }
    if (r == SY_OK) {
        ours = sy_bench_spread_of(t, repeats);
        floor_t = sy_bench_spread_of(tf, repeats);
        floor_lit = sy_bench_spread_of(tl, repeats);
        ratio = sy_bench_spread_of(q0, repeats);
        ratio_lit = sy_bench_spread_of(q1, repeats);
    }
    free(tf);
    for (uint32_t i = 0; i < repeats && r == SY_OK; ++i) {
        static const float q[4] = {0, 0, 0, 1}, one[3] = {1, 1, 1};
        float tr[3] = {0.001f * (float)(i + 1), 0.0f, 0.0f};
        double a = sy_time_now();
        r = sy_node_set_trs(scene, moved, tr, q, one, err);
        if (r == SY_OK) r = sy_scene_commit(scene, NULL, err);
        if (r == SY_OK) r = sy_context_sync(ctx, err);
        if (r == SY_OK) r = sy_context_render(ctx, &rq, &layer, err);
        t[i] = sy_time_now() - a;
    }
    if (r == SY_OK) {
        latency = median_of(t, repeats);
        sy_mediator_raster_counters_get(st, &moved_c);
        printf("  %s: %llu triangles, %u meshes, %u instances (%llu shaded deferred, on %.1f %% of the pixels), %ux%u, %u "
               "MSAA samples, %u shadow maps\n",
               label, (unsigned long long)moved_c.triangles_drawn, moved_c.meshes, moved_c.instances,
               (unsigned long long)moved_c.deferred_draws, 100.0 * (double)moved_c.deferred_pixels / ((double)width * height),
               width, height, moved_c.msaa_samples, moved_c.shadow_maps);
        printf("    first sync (upload)            %10.2f ms  (%llu vertex/index buffers, %llu textures)\n", t_sync * 1e3,
               (unsigned long long)first.total_vertex_buffer_uploads, (unsigned long long)first.total_texture_uploads);
        printf("    frame (median of %u)           %10.2f ms  (%.2f .. %.2f)\n", repeats, ours.median * 1e3, ours.min * 1e3,
               ours.max * 1e3);
        printf("    floor: same buffers, trivial   %10.2f ms  (%.2f .. %.2f)  one colour\n", floor_t.median * 1e3,
               floor_t.min * 1e3, floor_t.max * 1e3);
        printf("    floor lit: trivial lit         %10.2f ms  (%.2f .. %.2f)  one directional light, Lambert on the "
               "vertex normals\n",
               floor_lit.median * 1e3, floor_lit.min * 1e3, floor_lit.max * 1e3);
        printf("    ratio frame / floor            %10.2f x   (%.2f .. %.2f, per repeat)\n", ratio.median, ratio.min,
               ratio.max);
        printf("    ratio frame / trivial lit      %10.2f x   (%.2f .. %.2f, per repeat; goal <= 1.1 lit)\n",
               ratio_lit.median, ratio_lit.min, ratio_lit.max);
        printf("    transform change -> frame done %10.2f ms  (commit + sync + render, median)\n", latency * 1e3);
        printf("    uploads per steady frame       %10llu buffers, %llu textures, %llu uniform blocks\n",
               (unsigned long long)steady.vertex_buffer_uploads, (unsigned long long)steady.texture_uploads,
               (unsigned long long)steady.uniform_buffer_uploads);
        printf("    uploads per moved frame        %10llu buffers, %llu textures, %llu uniform blocks, %llu model matrices\n",
               (unsigned long long)moved_c.vertex_buffer_uploads, (unsigned long long)moved_c.texture_uploads,
               (unsigned long long)moved_c.uniform_buffer_uploads, (unsigned long long)moved_c.model_matrix_updates);
    }
    sy_layer_destroy(&layer);
    sy_context_release(ctx);
    sy_window_destroy(win);
    free(t);
    return r;
}
#endif

/* Adds a point light above the generated scene and a sky background (ambient light). */
#ifdef SY_HAVE_RASTER
static sy_result bench_raster_light_scene(sy_scene *s, sy_node root, sy_background *bg_out, sy_error *err)
{
    static const float q[4] = {0, 0, 0, 1}, one[3] = {1, 1, 1}, at[3] = {1.2f, 3.0f, 3.0f};
    sy_light lamp;
    sy_node n;
    sy_light_data ld = *(const sy_light_data *)sy_object_defaults(SY_TYPE_LIGHT);
    ld.intensity = 20.0f;
    sy_background_data bd = *(const sy_background_data *)sy_object_defaults(SY_TYPE_BACKGROUND);
    bd.color[0] = 0.18f, bd.color[1] = 0.24f, bd.color[2] = 0.34f, bd.color[3] = 1.0f;
    sy_result r;
    if ((r = sy_light_create(s, "bench lamp", &lamp, err)) || (r = sy_light_set(s, lamp, &ld, err)) ||
        (r = sy_node_create(s, "bench lamp", &n, err)) || (r = sy_node_set_trs(s, n, at, q, one, err)) ||
        (r = sy_node_set_light(s, n, lamp, err)) || (r = sy_node_add_child(s, root, n, err)) ||
        (r = sy_background_create(s, "bench sky", bg_out, err)) || (r = sy_background_set(s, *bg_out, &bd, err)))
        return r;
    return sy_scene_commit(s, NULL, err);
}
#endif

sy_result sy_bench_raster(sy_scene *scene, const sy_viewport_desc *vd, const char *label, uint32_t width,
                          uint32_t height, uint32_t repeats, sy_error *err)
{
#ifndef SY_HAVE_RASTER
    (void)scene, (void)vd, (void)label, (void)width, (void)height, (void)repeats;
    SY_BENCH_WITHOUT(err, "raster", "SY_WITH_RASTER");
#else
    sy_viewport_desc d = *vd;
    if (!d.params) d.params = "gl=osmesa";
    sy_params p;
    sy_result r = sy_params_parse(d.params, &p, err);
    if (r != SY_OK) return r;
    const char *gl = sy_params_get(&p, "gl");
    printf("sy bench raster: %s\n", gl ? gl : "osmesa");
    r = bench_raster_scene(label, scene, &d, d.root, width, height, repeats, err);
    /* generated geometry-bound scene: 100 meshes x 10000 triangles */
    sy_scene *s = NULL;
    sy_node root = {0}, leaf = {0};
    if (r == SY_OK) r = sy_scene_create(&s, err);
    if (r == SY_OK) r = sy_demo_bench_scene(s, 1, 100, 10000, &root, &leaf, err);
    if (r == SY_OK) r = sy_scene_commit(s, NULL, err);
    sy_viewport_desc g = {.root = root, .backend = "raster", .params = d.params};
    if (r == SY_OK) r = bench_raster_scene("generated 1M triangles", s, &g, leaf, width, height, repeats, err);
    /* the same scene lit (a point light and a sky that gives ambient light): the generated scene
     * has neither, so the lines above shade with the unlit variant (black non-emissive surfaces) */
    if (r == SY_OK) r = bench_raster_light_scene(s, root, &g.background, err);
    if (r == SY_OK) r = bench_raster_scene("generated 1M triangles, lit", s, &g, leaf, width, height, repeats, err);
    sy_scene_destroy(s);
    return r;
#endif
}

/* >>bench load (formats, issue 6) ------------------------------------------------------------ */
#include "sy_file.h"
#include "sy_gltf.h"
#include "sy_gltf_shim.h"

#include <dirent.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <signal.h>
#include <unistd.h>

static int cmp_cstr(const void *a, const void *b) { return strcmp(*(char *const *)a, *(char *const *)b); }

/* Resident set of this process in KiB (/proc/self/statm), 0 when unknown. */
static long rss_now_kib(void)
{
    FILE *f = fopen("/proc/self/statm", "r");
    long size = 0, res = 0;
    if (f) {
        if (fscanf(f, "%ld %ld", &size, &res) != 2) res = 0;
        fclose(f);
    }
    return res * (sysconf(_SC_PAGESIZE) / 1024);
}

/* Peak RSS growth (KiB) of one sy_gltf_load in a forked child: the child's high-water mark minus
 * its resident size at the start, so the parent's own footprint does not count. -1 on failure. */
static long load_peak_kib(const char *path)
{
    int fds[2];
    if (pipe(fds) != 0) return -1;
    pid_t pid = fork();
    if (pid < 0) {
        close(fds[0]);
        close(fds[1]);
        return -1;
    }
    if (pid == 0) {
        close(fds[0]);
        long base = rss_now_kib(), peak = -1;
        sy_scene *s;
        sy_gltf_info info = {0};
        if (sy_scene_create(&s, NULL) == SY_OK && sy_gltf_load(path, s, NULL, &info, NULL) == SY_OK) {
            struct rusage ru;
            getrusage(RUSAGE_SELF, &ru);
            peak = ru.ru_maxrss - base;
        }
        ssize_t w = write(fds[1], &peak, sizeof peak);
        _exit(w == (ssize_t)sizeof peak ? 0 : 1);
    }
    close(fds[1]);
    long peak = -1;
    if (read(fds[0], &peak, sizeof peak) != (ssize_t)sizeof peak) peak = -1;
    close(fds[0]);
    int status;
    waitpid(pid, &status, 0);
    return peak;
}

/* Bytes the load reads: the file plus, for .gltf, the other files of its directory (buffers,
 * images; a sample variant directory holds exactly one model). */
static double input_bytes(const char *path)
{
    struct stat st;
    if (stat(path, &st) != 0) return 0;
    double total = (double)st.st_size;
    size_t n = strlen(path);
    if (n < 5 || strcmp(path + n - 5, ".gltf") != 0) return total;
    char dir[4096];
    snprintf(dir, sizeof dir, "%s", path);
    char *slash = strrchr(dir, '/');
    if (slash) *slash = '\0';
    else snprintf(dir, sizeof dir, ".");
    DIR *d = opendir(dir);
    struct dirent *e;
    while (d && (e = readdir(d)) != NULL) {
        char p[8192];
        snprintf(p, sizeof p, "%s/%s", dir, e->d_name);
        if (strcmp(p, path) != 0 && e->d_name[0] != '.' && stat(p, &st) == 0 && S_ISREG(st.st_mode))
            total += (double)st.st_size;
    }
    if (d) closedir(d);
    return total;
}

static sy_result bench_one_load(const char *label, const char *path, uint32_t repeats, sy_error *err)
{
    double *tp = malloc(repeats * sizeof(double)), *tl = malloc(repeats * sizeof(double));
    sy_result r = (tp && tl) ? SY_OK : sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bench load: out of memory");
    char dir[4096];
    snprintf(dir, sizeof dir, "%s", path);
    char *slash = strrchr(dir, '/');
    if (slash) slash[1] = '\0';
    else dir[0] = '\0';
    size_t n = strlen(path);
    bool binary = n > 4 && !strcmp(path + n - 4, ".glb");
    sy_gltf_shim_limits lim = {.max_file_bytes = (size_t)2 << 30, .max_image_pixels = (uint64_t)1 << 26};
    uint32_t tris = 0;
    for (uint32_t k = 0; r == SY_OK && k < repeats; k++) {
        /* tinygltf alone: read + parse (buffers, image decoding), nothing else */
        double t0 = sy_time_now();
        void *bytes = NULL;
        size_t size = 0;
        r = sy_file_read_all(path, (size_t)2 << 30, &bytes, &size, err);
        if (r == SY_OK) r = sy_gltf_shim_parse_only(bytes, size, binary, dir, &lim, err);
        free(bytes);
        tp[k] = sy_time_now() - t0;
        if (r) break;
        /* the whole loader: read, parse, validate, convert, create the scene objects */
        sy_scene *s = NULL;
        sy_gltf_info info = {0};
        if ((r = sy_scene_create(&s, err))) break;
        t0 = sy_time_now();
        r = sy_gltf_load(path, s, NULL, &info, err);
        tl[k] = sy_time_now() - t0;
        tris = info.counts.triangles;
        sy_gltf_info_free(&info);
        sy_scene_destroy(s);
    }
    if (r == SY_OK) {
        qsort(tp, repeats, sizeof(double), cmp_double);
        qsort(tl, repeats, sizeof(double), cmp_double);
        double parse = tp[repeats / 2], load = tl[repeats / 2], bytes = input_bytes(path);
        long peak = load_peak_kib(path);
        printf("%-34s %9.2f %9u %10.2f %10.2f %7.2fx %9.1f %7.2fx\n", label, bytes / 1048576.0, tris, parse * 1e3,
               load * 1e3, parse > 0 ? load / parse : 0.0, peak >= 0 ? (double)peak / 1024.0 : -1.0,
               peak >= 0 && bytes > 0 ? (double)peak * 1024.0 / bytes : 0.0);
        fflush(stdout);
    } else {
        sy_error_prefix(err, "%s", label);
    }
    free(tp);
    free(tl);
    return r;
}

/* A .glb with a (grid + 1)^2-vertex grid of 2 * grid^2 triangles: POSITION, NORMAL, TEXCOORD_0,
 * uint32 indices; written through sy_atomic_file. */
static sy_result write_grid_glb(const char *path, uint32_t grid, sy_error *err)
{
    size_t nv = (size_t)(grid + 1) * (grid + 1), ni = (size_t)grid * grid * 6;
    size_t pos_b = nv * 12, nrm_b = nv * 12, uv_b = nv * 8, idx_b = ni * 4, bin = pos_b + nrm_b + uv_b + idx_b;
    uint8_t *b = malloc(bin);
    if (!b) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bench load: out of memory");
    float *pos = (float *)b, *nrm = (float *)(b + pos_b), *uv = (float *)(b + pos_b + nrm_b);
    uint32_t *idx = (uint32_t *)(b + pos_b + nrm_b + uv_b);
    for (uint32_t y = 0; y <= grid; y++)
        for (uint32_t x = 0; x <= grid; x++) {
            size_t v = (size_t)y * (grid + 1) + x;
            float fx = (float)x / (float)grid, fy = (float)y / (float)grid;
            pos[3 * v] = fx; pos[3 * v + 1] = 0.05f * sinf(12.0f * fx) * cosf(9.0f * fy); pos[3 * v + 2] = fy;
            nrm[3 * v] = 0; nrm[3 * v + 1] = 1; nrm[3 * v + 2] = 0;
            uv[2 * v] = fx; uv[2 * v + 1] = fy;
        }
    size_t k = 0;
    for (uint32_t y = 0; y < grid; y++)
        for (uint32_t x = 0; x < grid; x++) {
            uint32_t a = y * (grid + 1) + x, c = a + grid + 1;
            idx[k++] = a; idx[k++] = c; idx[k++] = a + 1;
            idx[k++] = a + 1; idx[k++] = c; idx[k++] = c + 1;
        }
    char json[2048];
    int jn = snprintf(json, sizeof json,
        "{\"asset\":{\"version\":\"2.0\",\"generator\":\"sy bench load\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
        "\"nodes\":[{\"mesh\":0}],\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,"
        "\"TEXCOORD_0\":2},\"indices\":3}]}],\"buffers\":[{\"byteLength\":%zu}],\"bufferViews\":["
        "{\"buffer\":0,\"byteOffset\":0,\"byteLength\":%zu},{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu},"
        "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu},{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu}],"
        "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":%zu,\"type\":\"VEC3\",\"min\":[0,-0.05,0],"
        "\"max\":[1,0.05,1]},{\"bufferView\":1,\"componentType\":5126,\"count\":%zu,\"type\":\"VEC3\"},"
        "{\"bufferView\":2,\"componentType\":5126,\"count\":%zu,\"type\":\"VEC2\"},"
        "{\"bufferView\":3,\"componentType\":5125,\"count\":%zu,\"type\":\"SCALAR\"}]}",
        bin, pos_b, pos_b, nrm_b, pos_b + nrm_b, uv_b, pos_b + nrm_b + uv_b, idx_b, nv, nv, nv, ni);
    while (jn % 4) json[jn++] = ' ';
    uint32_t hdr[5] = {0x46546C67u, 2, (uint32_t)(12 + 8 + jn + 8 + bin), (uint32_t)jn, 0x4E4F534Au};
    uint32_t bhdr[2] = {(uint32_t)bin, 0x004E4942u};
    sy_atomic_file af = {0};
    sy_result r = sy_atomic_file_begin(path, &af, err);
    if (r == SY_OK) {
        if (fwrite(hdr, 4, 5, af.fp) != 5 || fwrite(json, 1, (size_t)jn, af.fp) != (size_t)jn ||
            fwrite(bhdr, 4, 2, af.fp) != 2 || fwrite(b, 1, bin, af.fp) != bin) {
            sy_atomic_file_abort(&af);
            r = sy_error_set(err, SY_ERR_IO, "%s: write failed", path);
        } else {
            r = sy_atomic_file_commit(&af, err);
        }
    }
    free(b);
    return r;
}

sy_result sy_bench_load(const char *data_dir, uint32_t tris, uint32_t repeats, sy_error *err)
{
    printf("sy bench load: median of %u loads; 'tinygltf' = read + tinygltf parse alone (buffers, images decoded),\n"
           "'sy load' = sy_gltf_load into a fresh scene; peak = RSS growth of one load in a forked child\n\n",
           (unsigned)repeats);
    printf("%-34s %9s %9s %10s %10s %8s %9s %8s\n", "model", "file MB", "tris", "tinygltf", "sy load", "ratio",
           "peak MB", "peak/file");
    printf("%-34s %9s %9s %10s %10s %8s %9s %8s\n", "", "", "", "ms", "ms", "", "", "");
    sy_result r = SY_OK;
    DIR *d = opendir(data_dir);
    if (!d) {
        printf("(no sample models: %s not found)\n", data_dir);
    } else {
        char **names = NULL;
        size_t count = 0, cap = 0;
        struct dirent *e;
        while ((e = readdir(d)) != NULL) {
            if (e->d_name[0] == '.' || e->d_name[0] == '_') continue;
            if (count == cap) {
                cap = cap ? cap * 2 : 64;
                char **nn = realloc(names, cap * sizeof *nn);
                if (!nn) break;
                names = nn;
            }
            names[count] = strdup(e->d_name);
            if (names[count]) count++;
        }
        closedir(d);
        qsort(names, count, sizeof *names, cmp_cstr);
        for (size_t i = 0; i < count && r == SY_OK; i++) {
            /* one variant per model: the binary one when present */
            static const char *const variants[][2] = {{"glTF-Binary", ".glb"}, {"glTF", ".gltf"}};
            char path[4096];
            bool found = false;
            for (int v = 0; v < 2 && !found; v++) {
                snprintf(path, sizeof path, "%s/%s/%s/%s%s", data_dir, names[i], variants[v][0], names[i], variants[v][1]);
                struct stat st;
                found = stat(path, &st) == 0;
            }
            if (found) r = bench_one_load(names[i], path, repeats, err);
        }
        for (size_t i = 0; i < count; i++) free(names[i]);
        free(names);
    }
    if (r != SY_OK) return r;
    /* generated model */
    char dir[] = "/tmp/sy_bench_load_XXXXXX", path[128];
    if (!mkdtemp(dir)) return sy_error_set(err, SY_ERR_IO, "bench load: cannot create a temporary directory");
    snprintf(path, sizeof path, "%s/grid.glb", dir);
    uint32_t grid = (uint32_t)ceil(sqrt((double)tris / 2.0));
    char label[64];
    snprintf(label, sizeof label, "generated grid (%u tris)", 2 * grid * grid);
    r = write_grid_glb(path, grid, err);
    if (r == SY_OK) r = bench_one_load(label, path, repeats, err);
    unlink(path);
    rmdir(dir);
    return r;
}

/* >>memory (issue 19): peak RSS per triangle of a generated height field, rendered by a ray
 * tracer in a forked child (each measurement starts from a clean process). */

/* Resident high-water mark of this process in KiB (/proc/self/status VmHWM, else ru_maxrss). */
static long rss_peak_kib(void)
{
    FILE *f = fopen("/proc/self/status", "r");
    long kib = -1;
    char line[256];
    while (f && fgets(line, sizeof line, f))
        if (sscanf(line, "VmHWM: %ld kB", &kib) == 1) break;
    if (f) fclose(f);
    if (kib < 0) {
        struct rusage ru;
        getrusage(RUSAGE_SELF, &ru);
        kib = ru.ru_maxrss;
    }
    return kib;
}

#ifdef SY_HAVE_EMBREE
typedef struct mem_report {
    int ok;
    char message[sizeof(((sy_error *)0)->message)];
    uint32_t tris;
    long base_kib, scene_kib, peak_kib;    /* RSS at the start, after the scene, high-water mark */
    double blob_bytes, build_s, frame_s;  /* scene blob payload; translation; one frame */
    sy_mediator_rt_counters c;
} mem_report;

/* The child: scene -> commit -> context (translation) -> one frame; fills *o. */
static void mem_measure(uint32_t tris, const char *glb, const char *backend, uint32_t width, uint32_t height, mem_report *o)
{
    sy_error err = {0};
    sy_scene *s = NULL;
    sy_window *win = NULL;
    sy_context_pool *pool = NULL;
    sy_context *ctx = NULL;
    sy_layer img = {0};
    sy_node node = {0};
    o->base_kib = rss_now_kib();
    sy_result r = sy_scene_create(&s, &err);
    if (r == SY_OK && glb) {
        sy_gltf_info info = {0};
        r = sy_gltf_load(glb, s, NULL, &info, &err);
        o->tris = info.counts.triangles;
        sy_gltf_info_free(&info);
    } else if (r == SY_OK) {
        r = sy_height_field_generate(s, tris, &node, &o->tris, &err);
    }
    if (r == SY_OK) r = sy_scene_commit(s, NULL, &err);
    o->scene_kib = rss_now_kib();
    for (uint32_t id = sy_scene_next(s, SY_TYPE_MESH, 0); r == SY_OK && id; id = sy_scene_next(s, SY_TYPE_MESH, id)) {
        const sy_mesh_data *m = sy_object_get(s, SY_TYPE_MESH, id);
        for (uint32_t i = 0; i < m->primitives.count; ++i) {
            const sy_primitive *p = &m->primitives.items[i];
            o->blob_bytes += (double)(sy_blob_size(p->positions) + sy_blob_size(p->normals) + sy_blob_size(p->tangents) +
                                      sy_blob_size(p->texcoords0) + sy_blob_size(p->texcoords1) +
                                      sy_blob_size(p->colors) + sy_blob_size(p->indices));
        }
    }
    sy_viewport_desc vd = {.root = node, .backend = backend}; /* .glb: node {0} = every root */
    const sy_mediator_class *cls = sy_mediator_find(backend);
    sy_window_render_opts ro = {.sample_count = cls && (sy_mediator_class_caps(cls, NULL) & SY_CAP_PROGRESSIVE) ? 1u : 0u};
    sy_params pp = {0};
    double t0 = sy_time_now();
    if (r == SY_OK) r = sy_window_create(width, height, &win, &err);
    if (r == SY_OK) r = sy_window_add_viewport(win, &vd, NULL, &err);
    if (r == SY_OK) r = sy_context_pool_create(&pool, &err);
    if (r == SY_OK) r = sy_layer_create(width, height, &img, &err);
    if (r == SY_OK) r = sy_context_pool_get(pool, s, backend, &pp, node.id, &ctx, &err);
    if (r == SY_OK) r = sy_context_sync(ctx, &err);
    double t1 = sy_time_now();
    if (r == SY_OK) r = sy_window_render(win, s, pool, &ro, &img, &err);
    double t2 = sy_time_now();
    o->build_s = t1 - t0;
    o->frame_s = t2 - t1;
    o->peak_kib = rss_peak_kib();
    if (r == SY_OK) sy_mediator_rt_counters_get(sy_context_state(ctx), &o->c);
    o->ok = r == SY_OK;
    if (r != SY_OK) snprintf(o->message, sizeof o->message, "%s", err.message);
    /* the process ends here: nothing is freed (the parent reads the report) */
    (void)img;
}

/* Runs mem_measure in a forked child and returns its report through a pipe. */
static sy_result mem_run(uint32_t tris, const char *glb, const char *backend, uint32_t width, uint32_t height, mem_report *o,
                         sy_error *err)
{
    memset(o, 0, sizeof *o);
    int fds[2];
    if (pipe(fds) != 0) return sy_error_set(err, SY_ERR_IO, "bench memory: pipe failed");
    fflush(stdout);
    pid_t pid = fork();
    if (pid < 0) {
        close(fds[0]), close(fds[1]);
        return sy_error_set(err, SY_ERR_IO, "bench memory: fork failed");
    }
    if (pid == 0) {
        close(fds[0]);
        mem_report rep;
        memset(&rep, 0, sizeof rep);
        mem_measure(tris, glb, backend, width, height, &rep);
        ssize_t w = write(fds[1], &rep, sizeof rep);
        _exit(w == (ssize_t)sizeof rep ? 0 : 1);
    }
    close(fds[1]);
    size_t got = 0;
    while (got < sizeof *o) {
        ssize_t n = read(fds[0], (char *)o + got, sizeof *o - got);
        if (n <= 0) break;
        got += (size_t)n;
    }
    close(fds[0]);
    int status = 0;
    waitpid(pid, &status, 0);
    if (got != sizeof *o) {
        if (WIFSIGNALED(status))
            return sy_error_set(err, SY_ERR_IO, "bench memory: %s: the measuring process was killed by signal %d%s", backend,
                                WTERMSIG(status), WTERMSIG(status) == SIGKILL ? " (out of memory?)" : "");
        return sy_error_set(err, SY_ERR_IO, "bench memory: %s: the measuring process gave no report", backend);
    }
    if (!o->ok) return sy_error_set(err, SY_ERR_IO, "bench memory: %s: %s", backend, o->message);
    return SY_OK;
}
#endif

sy_result sy_bench_memory(uint32_t tris, const char *backend, bool glb, uint32_t width, uint32_t height, sy_error *err)
{
#ifndef SY_HAVE_EMBREE
    (void)tris, (void)backend, (void)glb, (void)width, (void)height;
    SY_BENCH_WITHOUT(err, "memory (whitted, pathtracer)", "SY_WITH_EMBREE");
#else
    static const char *const both[] = {"whitted", "pathtracer"};
    const char *const *list = backend ? &backend : both;
    const sy_mediator_class *cls = backend ? sy_mediator_find(backend) : NULL;
    if (backend && (!cls || (cls != sy_mediator_rt_whitted_class() && cls != sy_mediator_rt_pathtracer_class())))
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "bench memory: -b %s: expected one of the ray tracers (whitted, pathtracer)",
                            backend);
    uint32_t n = backend ? 1u : 2u;
    printf("sy bench memory: a height field of ~%u unique triangles (positions, normals, UVs, uint32 indices)\n"
           "%s, the mediator and the back-end, one %ux%u frame, in a forked child each;\n"
           "peak = the child's RSS high-water mark (VmHWM) less its RSS at the start\n\n",
           tris, glb ? "loaded from a .glb (sy_gltf_load), through the scene's blobs" : "through the scene's blobs", width,
           height);
    char dir[] = "/tmp/sy_bench_memory_XXXXXX", path[128] = "";
    sy_result r = SY_OK;
    if (glb) {
        if (!mkdtemp(dir)) return sy_error_set(err, SY_ERR_IO, "bench memory: cannot create a temporary directory");
        snprintf(path, sizeof path, "%s/height_field.glb", dir);
        uint32_t grid = (uint32_t)ceil(sqrt((double)tris / 2.0));
        r = write_grid_glb(path, grid, err);
    }
    for (uint32_t i = 0; i < n && r == SY_OK; ++i) {
        mem_report o;
        if ((r = mem_run(tris, glb ? path : NULL, list[i], width, height, &o, err)) != SY_OK) break;
        double t = (double)o.tris, peak = (double)(o.peak_kib - o.base_kib) * 1024.0;
        double scene = (double)(o.scene_kib - o.base_kib) * 1024.0;
        const sy_mediator_rt_counters *c = &o.c;
        printf("%s: %u triangles, translation %.2f s, first frame %.2f s\n", list[i], o.tris, o.build_s, o.frame_s);
        printf("  peak RSS                      %9.1f MB  %7.1f bytes/triangle\n", peak / 1e6, peak / t);
        printf("  scene (RSS after commit)      %9.1f MB  %7.1f bytes/triangle\n", scene / 1e6, scene / t);
        printf("    of which mesh blobs         %9.1f MB  %7.1f bytes/triangle\n", o.blob_bytes / 1e6, o.blob_bytes / t);
        printf("  back-end copies (normals, UV) %9.1f MB  %7.1f bytes/triangle\n", (double)c->mesh_bytes / 1e6,
               (double)c->mesh_bytes / t);
        printf("  shared with the blobs         %9.1f MB  %7.1f bytes/triangle  (not counted again)\n",
               (double)c->shared_bytes / 1e6, (double)c->shared_bytes / t);
        printf("  Embree now (buffers, BVH)     %9.1f MB  %7.1f bytes/triangle\n", (double)c->embree_bytes / 1e6,
               (double)c->embree_bytes / t);
        printf("  Embree peak (+ build scratch) %9.1f MB  %7.1f bytes/triangle\n", (double)c->embree_peak_bytes / 1e6,
               (double)c->embree_peak_bytes / t);
        double rest = peak - scene - (double)c->mesh_bytes - (double)c->embree_peak_bytes;
        printf("  rest (frame buffers, threads) %9.1f MB  %7.1f bytes/triangle\n", rest / 1e6, rest / t);
        fflush(stdout);
    }
    if (glb) {
        unlink(path);
        rmdir(dir);
    }
    return r;
#endif
}

/* >>pathtracer (issue 3): samples/s and Mrays/s of the path tracer next to the Whitted back-end on
 * the same scene, and the restart latency after a transform change. */
#ifdef SY_HAVE_EMBREE
static sy_result pt_bench_frame(sy_window *win, sy_scene *scene, sy_context_pool *pool, uint32_t samples, sy_layer *out,
                                double *secs, sy_error *err)
{
    sy_window_render_opts ro = {.sample_count = samples};
    double t0 = sy_time_now();
    sy_result r = sy_window_render(win, scene, pool, &ro, out, err);
    *secs = sy_time_now() - t0;
    return r;
}
#endif

sy_result sy_bench_pathtracer(sy_scene *scene, const sy_viewport_desc *vd, const char *label, uint32_t width,
                              uint32_t height, uint32_t passes, sy_error *err)
{
#ifndef SY_HAVE_EMBREE
    (void)scene, (void)vd, (void)label, (void)width, (void)height, (void)passes;
    SY_BENCH_WITHOUT(err, "pathtracer", "SY_WITH_EMBREE");
#else
    sy_window *win_w = NULL, *win_p = NULL;
    sy_viewport *vp;
    sy_context_pool *pool = NULL;
    sy_layer img = {0};
    double *t = calloc(passes, sizeof *t), whitted = INFINITY, first = 0, t_dummy;
    sy_viewport_desc dw = *vd, dp = *vd;
    dw.backend = "whitted";
    dp.backend = "pathtracer";
    sy_result r = t ? sy_window_create(width, height, &win_w, err) : sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bench: out of memory");
    if (r == SY_OK) r = sy_window_create(width, height, &win_p, err);
    if (r == SY_OK) r = sy_window_add_viewport(win_w, &dw, &vp, err);
    if (r == SY_OK) r = sy_window_add_viewport(win_p, &dp, &vp, err);
    if (r == SY_OK) r = sy_context_pool_create(&pool, err);
    if (r == SY_OK) r = sy_layer_create(width, height, &img, err);
    /* Whitted: best of 3 frames after a warm-up (translation is not timed) */
    for (uint32_t i = 0; i < 4 && r == SY_OK; ++i) {
        double s;
        r = pt_bench_frame(win_w, scene, pool, 0, &img, &s, err);
        if (i) whitted = fmin(whitted, s);
    }
    /* path tracer: warm-up pass, then `passes` passes of 1 sample per pixel */
    if (r == SY_OK) r = pt_bench_frame(win_p, scene, pool, 1, &img, &t_dummy, err);
    sy_context *ctx = NULL;
    sy_params pp = {0};
    if (r == SY_OK) r = sy_context_pool_get(pool, scene, "pathtracer", &pp, vd->root.id, &ctx, err);
    uint64_t rays = 0;
    for (uint32_t i = 0; i < passes && r == SY_OK; ++i) {
        r = pt_bench_frame(win_p, scene, pool, 1, &img, &t[i], err);
        sy_mediator_rt_counters c;
        sy_mediator_rt_counters_get(sy_context_state(ctx), &c);
        rays += c.last_render_rays;
    }
    double total = 0;
    for (uint32_t i = 0; i < passes; ++i) total += t[i];
    /* restart latency: move the first node with a mesh a little, then time sync + the first pass */
    uint32_t moved = 0;
    for (uint32_t id = sy_scene_next(scene, SY_TYPE_NODE, 0); id && !moved; id = sy_scene_next(scene, SY_TYPE_NODE, id)) {
        const sy_node_data *nd = sy_object_get(scene, SY_TYPE_NODE, id);
        if (nd->mesh.id) moved = id;
    }
    sy_mediator_stats st = {0};
    if (r == SY_OK && moved) {
        sy_node n = {moved};
        sy_mat4 m = sy_node_get(scene, n)->transform.matrix;
        m.m[13] += 0.01f;
        r = sy_node_set_matrix(scene, n, &m, err);
        if (r == SY_OK) r = sy_scene_commit(scene, NULL, err);
        if (r == SY_OK) r = pt_bench_frame(win_p, scene, pool, 1, &img, &first, err);
        if (r == SY_OK) sy_context_stats(ctx, &st);
    }
    if (r == SY_OK) {
        qsort(t, passes, sizeof *t, cmp_double);
        double med = t[passes / 2], px = (double)width * height;
        printf("%s, %ux%u:\n", label, width, height);
        printf("  whitted                 %8.3f s/frame  %8.2f frames/s\n", whitted, 1.0 / whitted);
        printf("  pathtracer (1 spp pass) %8.3f s/pass   %8.2f samples/s (spp)  %7.2f Msamples/s  %7.2f Mrays/s  "
               "(%.1f rays/sample, %u passes)\n",
               med, passes / total, px * passes / total * 1e-6, (double)rays / total * 1e-6, (double)rays / (px * passes),
               passes);
        printf("  pass / whitted frame    %8.2f x\n", med / whitted);
        if (moved)
            printf("  restart after a transform change: first new pass %.3f s = %.2f x one pass (samples after it: %llu)\n",
                   first, first / med, (unsigned long long)st.samples);
    }
    free(t);
    sy_layer_destroy(&img);
    sy_context_pool_destroy(pool);
    sy_window_destroy(win_w);
    sy_window_destroy(win_p);
    return r;
#endif
}

/* ---- sy bench filters (issue 7): noise-reduction filters of backends/filters ---------------- */
#include "sy_filter_adaptive.h"
#include "sy_filter_atrous.h"
#include "sy_filter_jbu.h"
#include "sy_filter_metrics.h"
#include "sy_filter_pixel.h"
#include "sy_filter_radiance.h"
#include "sy_filter_synth.h"
#include "sy_png.h"

#include <time.h>

static double fb_cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

enum { FB_NONE, FB_PIXEL, FB_PIXEL_BRUTE, FB_RADIANCE, FB_ATROUS, FB_JBU, FB_ADAPTIVE, FB_COUNT };
static const char *const fb_names[FB_COUNT] = {"none", "pixel", "pixel-brute", "radiance", "atrous", "jbu", "adaptive"};

static sy_result fb_fail(sy_error *err, const sy_filter_error *fe, const char *what)
{
    return sy_error_set(err, fe->status == SY_FILTER_ERROR_OUT_OF_MEMORY ? SY_ERR_OUT_OF_MEMORY : SY_ERR_BACKEND,
                        "bench filters: %s: %s", what, fe->message);
}

/* one filter application; pixel filters: a forced pass of *keep (created on first use, as a
 * viewport keeps its filter object between frames) */
static sy_filter_status fb_apply(int m, const sy_filter_frame *f, uint32_t threads, float *out, sy_filter_pixel **keep,
                                 sy_filter_error *fe)
{
    sy_filter_status s = SY_FILTER_OK;
    if (m == FB_PIXEL || m == FB_PIXEL_BRUTE) {
        sy_filter_pixel_params p;
        sy_filter_pixel_params_default(&p);
        p.threads = threads;
        if (m == FB_PIXEL_BRUTE) p.kernel = SY_FILTER_PIXEL_BRUTE, p.aa_recovery = false;
        if (!*keep) s = sy_filter_pixel_create(&p, keep, fe);
        if (!s) s = sy_filter_pixel_set_params(*keep, &p, fe);
        if (!s) s = sy_filter_pixel_run(*keep, f, (uint32_t)f->spp_uniform, true, out, NULL, fe);
    } else if (m == FB_ATROUS) {
        sy_filter_atrous_params p;
        sy_filter_atrous_params_default(&p);
        p.threads = threads;
        s = sy_filter_atrous(&p, f, out, NULL, fe);
    } else if (m == FB_JBU) {
        sy_filter_jbu_params p;
        sy_filter_jbu_params_default(&p);
        p.threads = threads;
        s = sy_filter_jbu(&p, f, out, NULL, fe);
    } else if (m == FB_ADAPTIVE) {
        sy_filter_adaptive_params p;
        sy_filter_adaptive_params_default(&p);
        p.threads = threads;
        s = sy_filter_adaptive(&p, f, out, NULL, NULL, fe);
    } else {
        size_t n = (size_t)f->width * f->height;
        for (size_t i = 0; i < n; ++i)
            for (int c = 0; c < 4; ++c) out[4 * i + c] = c < 3 ? f->color[4 * i + c] : 1.0f;
    }
    return s;
}

static double fb_median(double *v, uint32_t n)
{
    qsort(v, n, sizeof *v, cmp_double);
    return v[n / 2];
}

/* Median wall time of one 1-spp path-tracing pass of the built-in demo scene at width x height (after
 * a warm-up pass that includes the translation): the yardstick the pixel filter's cost is given in. */
static sy_result fb_pt_pass(uint32_t width, uint32_t height, uint32_t repeats, double *secs, sy_error *err)
{
#ifndef SY_HAVE_EMBREE
    (void)width, (void)height, (void)repeats, (void)secs;
    SY_BENCH_WITHOUT(err, "filters (a path-traced pass)", "SY_WITH_EMBREE");
#else
    sy_scene *s = NULL;
    sy_demo_info demo;
    sy_window *win = NULL;
    sy_viewport *vp = NULL;
    sy_context_pool *pool = NULL;
    sy_layer img = {0};
    double *t = calloc(repeats, sizeof *t), warm;
    sy_result r = t ? sy_scene_create(&s, err) : sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bench filters: out of memory");
    if (r == SY_OK) r = sy_demo_build(s, &demo, err);
    if (r == SY_OK) r = sy_scene_commit(s, NULL, err);
    sy_viewport_desc vd = {.root = demo.root, .camera = demo.camera, .background = demo.background,
                           .backend = "pathtracer"};
    if (r == SY_OK) r = sy_window_create(width, height, &win, err);
    if (r == SY_OK) r = sy_window_add_viewport(win, &vd, &vp, err);
    if (r == SY_OK) r = sy_context_pool_create(&pool, err);
    if (r == SY_OK) r = sy_layer_create(width, height, &img, err);
    if (r == SY_OK) r = pt_bench_frame(win, s, pool, 1, &img, &warm, err);
    for (uint32_t i = 0; i < repeats && r == SY_OK; ++i) r = pt_bench_frame(win, s, pool, 1, &img, &t[i], err);
    if (r == SY_OK) {
        qsort(t, repeats, sizeof *t, cmp_double);
        *secs = t[repeats / 2];
    }
    sy_layer_destroy(&img);
    sy_context_pool_destroy(pool);
    sy_window_destroy(win);
    sy_scene_destroy(s);
    free(t);
    return r;
#endif
}

sy_result sy_bench_filters(uint32_t width, uint32_t height, uint32_t repeats, const char *png_path, sy_error *err)
{
    sy_filter_error fe = {0};
    sy_filter_synth *syn = NULL;
    if (sy_filter_synth_create(width, height, 12345, &syn, &fe)) return fb_fail(err, &fe, "surrogate");
    size_t n = (size_t)width * height;
    float *out = malloc(4 * n * sizeof(float));
    double *t = calloc(repeats, sizeof *t);
    sy_result r = out && t ? SY_OK : sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bench filters: out of memory");
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    printf("sy bench filters: analytic render surrogate (two Lambertian planes, depth step, checker texture, smooth\n"
           "indirect light with a shadow edge, Exp(1) path noise), %ux%u, %ld cores\n\n", width, height, cores);
    /* 1. cost per filtered frame at 4 spp (median of repeats; all cores, then one thread) */
    for (int k = 0; k < 4 && r == SY_OK; ++k) sy_filter_synth_step(syn);
    sy_filter_frame f = sy_filter_synth_frame(syn);
    printf("filter time per frame at 4 spp (median of %u; wall time, and the CPU time the process used, which\n"
           "does not grow when other processes load the machine):\n", repeats);
    printf("  %-12s %12s %12s %12s %9s\n", "method", "all cores ms", "CPU ms", "1 thread ms", "speed-up");
    double t_pixel = 0;
    for (int m = FB_PIXEL; m < FB_COUNT && r == SY_OK; ++m) {
        double med[2] = {0, 0}, cpu = 0;
        for (int th = 0; th < 2 && r == SY_OK; ++th) {
            uint32_t reps = m == FB_PIXEL_BRUTE ? 1 : repeats;
            sy_filter_pixel *keep = NULL;
            if ((m == FB_PIXEL || m == FB_PIXEL_BRUTE) && fb_apply(m, &f, th ? 1 : 0, out, &keep, &fe)) /* warm-up */
                r = fb_fail(err, &fe, fb_names[m]);
            double c0 = fb_cpu_now();
            for (uint32_t i = 0; i < reps && r == SY_OK; ++i) {
                double a = sy_time_now();
                if (m == FB_RADIANCE) {
                    sy_filter_radiance_params p;
                    sy_filter_radiance_params_default(&p);
                    p.threads = th ? 1 : 0;
                    p.warmup_frames = 0; /* the variance-driven radius of frame 4 */
                    sy_filter_radiance *rf = NULL;
                    sy_filter_radiance_input in = sy_filter_synth_rf_input(syn);
                    if (sy_filter_radiance_create(&p, &rf, &fe) ||
                        sy_filter_radiance_frame(rf, &in, out, NULL, &fe))
                        r = fb_fail(err, &fe, fb_names[m]);
                    sy_filter_radiance_destroy(rf);
                } else if (fb_apply(m, &f, th ? 1 : 0, out, &keep, &fe))
                    r = fb_fail(err, &fe, fb_names[m]);
                t[i] = sy_time_now() - a;
            }
            if (th == 0) cpu = (fb_cpu_now() - c0) / reps;
            sy_filter_pixel_destroy(keep);
            med[th] = fb_median(t, reps);
        }
        if (m == FB_PIXEL) t_pixel = med[0];
        printf("  %-12s %12.2f %12.2f %12.2f %8.2fx\n", fb_names[m], med[0] * 1e3, cpu * 1e3, med[1] * 1e3,
               med[1] / med[0]);
    }
    if (r == SY_OK)
        printf("  fast pixel filter: %.1f ms per filtered frame (target < 50 ms at 640x480 on 2 cores;\n"
               "  on an otherwise idle machine wall time ~ CPU ms / cores)\n", t_pixel * 1e3);
    double pt_pass = 0;
    if (r == SY_OK) r = fb_pt_pass(width, height, repeats, &pt_pass, err);
    if (r == SY_OK)
        printf("  path tracing (demo scene, %ux%u, all cores): %.1f ms per 1-spp pass (median of %u);\n"
               "  fast pixel filter = %.2f x one path-tracing pass at 1 spp\n\n", width, height, pt_pass * 1e3,
               repeats, t_pixel / pt_pass);
    /* 2. quality against the converged image, progressive: every method sees the same samples */
    static const uint32_t spps[] = {1, 4, 16, 64, 256};
    enum { NS = sizeof spps / sizeof spps[0] };
    uint32_t scale = (width + 319) / 320, tw = width / scale, th = height / scale;
    size_t sheet_w = (size_t)tw * (FB_COUNT + 1), sheet_h = (size_t)th * NS;
    float *sheet = png_path ? calloc(sheet_w * sheet_h * 4, sizeof(float)) : NULL;
    if (png_path && !sheet && r == SY_OK) r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bench filters: out of memory");
    sy_filter_pixel *pf = NULL;
    sy_filter_radiance *rf = NULL;
    sy_filter_pixel_params pp;
    sy_filter_pixel_params_default(&pp);
    pp.schedule_start = 1; /* filter frames 1, 2, 4, 8, ...: every checkpoint below is a filter frame */
    float *rf_out = malloc(4 * n * sizeof(float)), *pix_out = malloc(4 * n * sizeof(float));
    if (r == SY_OK && (!rf_out || !pix_out)) r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bench filters: out of memory");
    if (r == SY_OK && (sy_filter_pixel_create(&pp, &pf, &fe) || sy_filter_radiance_create(NULL, &rf, &fe)))
        r = fb_fail(err, &fe, "create");
    const float *ref = sy_filter_synth_reference(syn);
    if (r == SY_OK) {
        printf("quality against the converged image (RMSE / relMSE / SSIM; pixel: 2^i schedule from frame 1;\n"
               "radiance: filtered every frame; others applied at the checkpoint):\n");
        printf("  %5s %-12s %9s %9s %7s %10s %9s\n", "spp", "method", "RMSE", "relMSE", "SSIM", "relMSE/PT", "ms");
    }
    sy_filter_synth_reset(syn);
    uint32_t si = 0;
    double rf_ms = 0, px_ms = 0;
    for (uint32_t k = 1; k <= spps[NS - 1] && r == SY_OK; ++k) {
        sy_filter_synth_step(syn);
        f = sy_filter_synth_frame(syn);
        sy_filter_radiance_input in = sy_filter_synth_rf_input(syn);
        sy_filter_stats st;
        if (sy_filter_radiance_frame(rf, &in, rf_out, &st, &fe)) {
            r = fb_fail(err, &fe, "radiance");
            break;
        }
        rf_ms = st.seconds * 1e3;
        if (sy_filter_pixel_run(pf, &f, k, false, pix_out, &st, &fe)) {
            r = fb_fail(err, &fe, "pixel");
            break;
        }
        px_ms = st.seconds * 1e3;
        if (k != spps[si]) continue;
        double base_rel = 0;
        for (int m = 0; m < FB_COUNT && r == SY_OK; ++m) {
            const float *img = out;
            double ms = 0;
            if (m == FB_RADIANCE) img = rf_out, ms = rf_ms;
            else if (m == FB_PIXEL) img = pix_out, ms = px_ms;
            else {
                double a = sy_time_now();
                if (m == FB_PIXEL_BRUTE && width * height > 400000u) continue;
                sy_filter_pixel *once = NULL;
                if (fb_apply(m, &f, 0, out, &once, &fe)) r = fb_fail(err, &fe, fb_names[m]);
                sy_filter_pixel_destroy(once);
                ms = (sy_time_now() - a) * 1e3;
            }
            sy_filter_metrics mt;
            if (r == SY_OK && sy_filter_metrics_compute(img, ref, width, height, 4, &mt, &fe))
                r = fb_fail(err, &fe, "metrics");
            if (r != SY_OK) break;
            if (m == FB_NONE) base_rel = mt.relmse;
            printf("  %5u %-12s %9.5f %9.5f %7.4f %9.2fx %9.1f\n", k, fb_names[m], mt.rmse, mt.relmse, mt.ssim,
                   mt.relmse > 0 ? base_rel / mt.relmse : 0.0, ms);
            for (uint32_t y = 0; sheet && y < th; ++y) /* tile: box-downscaled image */
                for (uint32_t x = 0; x < tw; ++x)
                    for (int c = 0; c < 4; ++c) {
                        double acc = 0;
                        for (uint32_t dy = 0; dy < scale; ++dy)
                            for (uint32_t dx = 0; dx < scale; ++dx)
                                acc += img[4 * ((size_t)(y * scale + dy) * width + x * scale + dx) + c];
                        sheet[4 * ((si * (size_t)th + y) * sheet_w + (size_t)m * tw + x) + c] =
                            c == 3 ? 1.0f : (float)(acc / (scale * scale));
                    }
        }
        for (uint32_t y = 0; sheet && y < th; ++y)
            for (uint32_t x = 0; x < tw; ++x)
                for (int c = 0; c < 4; ++c)
                    sheet[4 * ((si * (size_t)th + y) * sheet_w + (size_t)FB_COUNT * tw + x) + c] =
                        ref[4 * ((size_t)(y * scale) * width + x * scale) + c];
        ++si;
    }
    if (r == SY_OK && sheet) {
        r = sy_png_write(png_path, (int)sheet_w, (int)sheet_h, sheet, NULL, err);
        if (r == SY_OK)
            printf("\ncontact sheet %s: rows = spp 1, 4, 16, 64, 256; columns = none, pixel, pixel-brute (blank above\n"
                   "400k pixels), radiance, atrous, jbu, adaptive, reference\n", png_path);
    }
    sy_filter_pixel_destroy(pf);
    sy_filter_radiance_destroy(rf);
    free(rf_out), free(pix_out), free(sheet), free(out), free(t);
    sy_filter_synth_destroy(syn);
    return r;
}

/* ---- sy bench filters SCENE: the same comparison on the path tracer's real buffers ---------- */
#include "sy_exr.h"

sy_result sy_bench_filters_scene(sy_scene *scene, const sy_viewport_desc *vd, const char *label, uint32_t width,
                                 uint32_t height, const char *reference_exr, const char *png_path, sy_error *err)
{
#ifndef SY_HAVE_EMBREE
    (void)scene, (void)vd, (void)label, (void)width, (void)height, (void)reference_exr, (void)png_path;
    SY_BENCH_WITHOUT(err, "filters on a scene (pathtracer)", "SY_WITH_EMBREE");
#else
    sy_filter_error fe = {0};
    sy_exr_image *refimg = NULL;
    sy_window *win = NULL;
    sy_viewport *vp = NULL;
    sy_context_pool *pool = NULL;
    sy_layer img = {0}, img_rf = {0};
    sy_viewport_desc dp = *vd, dp_rf;
    dp.backend = "pathtracer";
    /* radiance filtering is no display filter: it needs the path tracer's stored-sample hook, so it
     * runs in its own viewport (filter=radiance), on the same samples (same seed, deterministic) */
    char rf_params[512];
    snprintf(rf_params, sizeof rf_params, "%s%sfilter=radiance", vd->params ? vd->params : "",
             vd->params && *vd->params ? "," : "");
    dp_rf = dp;
    dp_rf.params = rf_params;
    sy_window *win_rf = NULL;
    sy_viewport *vp_rf = NULL;
    size_t n = (size_t)width * height;
    float *ref = malloc(4 * n * sizeof(float)), *out = malloc(4 * n * sizeof(float)), *pos = malloc(3 * n * sizeof(float));
    float *pix_out = malloc(4 * n * sizeof(float));
    sy_result r = ref && out && pos && pix_out ? SY_OK : sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bench filters: out of memory");
    if (r == SY_OK) r = sy_exr_read(reference_exr, &refimg, err);
    if (r == SY_OK && (refimg->width != (int)width || refimg->height != (int)height))
        r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "bench filters: reference %s is %dx%d, the render %ux%u",
                         reference_exr, refimg->width, refimg->height, width, height);
    const float *rc[3] = {NULL, NULL, NULL};
    if (r == SY_OK) {
        rc[0] = sy_exr_image_channel(refimg, "R"), rc[1] = sy_exr_image_channel(refimg, "G");
        rc[2] = sy_exr_image_channel(refimg, "B");
        if (!rc[0] || !rc[1] || !rc[2])
            r = sy_error_set(err, SY_ERR_PARSE, "bench filters: reference %s has no R, G, B channels", reference_exr);
    }
    for (size_t i = 0; r == SY_OK && i < n; ++i)
        for (int c = 0; c < 4; ++c) ref[4 * i + c] = c < 3 ? rc[c][i] : 1.0f;
    /* camera: world matrix and vertical field of view, for positions and the headlight */
    float m[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}, yfov = 0.0f;
    if (r == SY_OK && vd->camera.id) {
        sy_mat4 w;
        const sy_node_data *nd = sy_node_get(scene, vd->camera);
        const sy_camera_data *cd = nd && nd->camera.id ? sy_camera_get(scene, nd->camera) : NULL;
        if (cd && cd->yfov > 0.0f && sy_node_world_matrix(scene, vd->camera, &w, err) == SY_OK) {
            memcpy(m, w.m, sizeof m);
            yfov = cd->yfov;
        }
    }
    if (r == SY_OK && yfov <= 0.0f)
        r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "bench filters: %s needs a perspective camera node", label);
    if (r == SY_OK) r = sy_window_create(width, height, &win, err);
    if (r == SY_OK) r = sy_window_add_viewport(win, &dp, &vp, err);
    if (r == SY_OK) r = sy_window_create(width, height, &win_rf, err);
    if (r == SY_OK) r = sy_window_add_viewport(win_rf, &dp_rf, &vp_rf, err);
    if (r == SY_OK) r = sy_context_pool_create(&pool, err);
    if (r == SY_OK) r = sy_layer_create(width, height, &img, err);
    if (r == SY_OK) r = sy_layer_create(width, height, &img_rf, err);
    sy_filter_pixel *pf = NULL;
    sy_filter_pixel_params pp;
    sy_filter_pixel_params_default(&pp);
    pp.schedule_start = 1;
    if (r == SY_OK && sy_filter_pixel_create(&pp, &pf, &fe)) r = fb_fail(err, &fe, "pixel");
    static const uint32_t spps[] = {1, 4, 16, 64, 256};
    enum { NS = sizeof spps / sizeof spps[0] };
    uint32_t methods[] = {FB_NONE, FB_PIXEL, FB_PIXEL_BRUTE, FB_RADIANCE, FB_ATROUS, FB_JBU, FB_ADAPTIVE};
    enum { NM = sizeof methods / sizeof methods[0] };
    size_t sheet_w = (size_t)width * (NM + 1), sheet_h = (size_t)height * NS;
    float *sheet = png_path && r == SY_OK ? calloc(sheet_w * sheet_h * 4, sizeof(float)) : NULL;
    if (r == SY_OK && png_path && !sheet) r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bench filters: out of memory");
    if (r == SY_OK) {
        printf("%s, %ux%u, path tracer buffers against %s (radiance: the path tracer's stored-sample\n"
               "hook, filtered every 1-spp pass, same samples; pixel: 2^i schedule from frame 1):\n", label, width,
               height, reference_exr);
        printf("  %5s %-12s %9s %9s %7s %10s %9s\n", "spp", "method", "RMSE", "relMSE", "SSIM", "relMSE/PT", "ms");
    }
    sy_context *ctx = NULL, *ctx_rf = NULL;
    sy_params none = {0}, rfp = {0};
    if (r == SY_OK) r = sy_params_parse(rf_params, &rfp, err);
    double pass_s = 0, t_pixel_ms = 0, rf_pass_s = 0, t_rf_ms = 0;
    uint32_t si = 0;
    for (uint32_t k = 1; k <= spps[NS - 1] && r == SY_OK; ++k) {
        double s;
        r = pt_bench_frame(win, scene, pool, 1, &img, &s, err);
        pass_s += s;
        if (r == SY_OK && !ctx) r = sy_context_pool_get(pool, scene, "pathtracer", &none, vd->root.id, &ctx, err);
        if (r == SY_OK) r = pt_bench_frame(win_rf, scene, pool, 1, &img_rf, &s, err); /* pass + radiance frame */
        rf_pass_s += s;
        if (r == SY_OK && !ctx_rf) r = sy_context_pool_get(pool, scene, "pathtracer", &rfp, vd->root.id, &ctx_rf, err);
        sy_mediator_rt_filter_info rfi = {0};
        if (r == SY_OK) sy_mediator_rt_filter_info_get(sy_context_state(ctx_rf), &rfi);
        if (r == SY_OK && k == 4) t_rf_ms = rfi.seconds * 1e3;
        sy_mediator_rt_aovs a = {0};
        if (r == SY_OK) r = sy_mediator_rt_aovs_get(sy_context_state(ctx), &a, err);
        if (r == SY_OK && (a.width != width || a.height != height))
            r = sy_error_set(err, SY_ERR_BACKEND, "bench filters: feature buffers are %ux%u, expected %ux%u", a.width,
                             a.height, width, height);
        if (r == SY_OK && sy_filter_position_from_depth(width, height, m, yfov, a.planes[4], pos, &fe))
            r = fb_fail(err, &fe, "positions");
        sy_filter_frame f = {.width = width, .height = height, .color_channels = 4, .variance_channels = 3,
                             .color = a.planes[0], .variance = a.planes[1], .albedo = a.planes[2],
                             .normal = a.planes[3], .depth = a.planes[4], .position = pos, .direct = a.planes[5],
                             .indirect = a.planes[6], .spp_uniform = (float)(a.samples ? a.samples : k), .has_camera = true,
                             .camera_position = {m[12], m[13], m[14]}};
        sy_filter_stats st;
        if (r == SY_OK && sy_filter_pixel_run(pf, &f, k, false, pix_out, &st, &fe)) r = fb_fail(err, &fe, "pixel");
        if (r == SY_OK && st.filter_pass && k == 4) t_pixel_ms = st.seconds * 1e3; /* the 4-spp pass */
        if (r == SY_OK && k == spps[si]) {
            double base_rel = 0;
            for (int mi = 0; mi < NM && r == SY_OK; ++mi) {
                int meth = (int)methods[mi];
                const float *im = out;
                double ms = meth == FB_PIXEL ? st.seconds * 1e3 : meth == FB_RADIANCE ? rfi.seconds * 1e3 : 0;
                if (meth == FB_PIXEL)
                    im = pix_out;
                else if (meth == FB_RADIANCE)
                    im = img_rf.rgba;
                else {
                    sy_filter_pixel *once = NULL;
                    double t0 = sy_time_now();
                    if (fb_apply(meth, &f, 0, out, &once, &fe)) r = fb_fail(err, &fe, fb_names[meth]);
                    ms = (sy_time_now() - t0) * 1e3;
                    sy_filter_pixel_destroy(once);
                }
                sy_filter_metrics mt;
                if (r == SY_OK && sy_filter_metrics_compute(im, ref, width, height, 4, &mt, &fe))
                    r = fb_fail(err, &fe, "metrics");
                if (r != SY_OK) break;
                if (meth == FB_NONE) base_rel = mt.relmse;
                printf("  %5u %-12s %9.5f %9.5f %7.4f %9.2fx %9.1f\n", k, fb_names[meth], mt.rmse, mt.relmse, mt.ssim,
                       mt.relmse > 0 ? base_rel / mt.relmse : 0.0, ms);
                for (uint32_t y = 0; sheet && y < height; ++y)
                    for (uint32_t x = 0; x < width; ++x) { /* opaque: uncovered background shows black */
                        float *d = sheet + 4 * ((si * (size_t)height + y) * sheet_w + (size_t)mi * width + x);
                        const float *sp = im + 4 * ((size_t)y * width + x);
                        d[0] = sp[0], d[1] = sp[1], d[2] = sp[2], d[3] = 1.0f;
                    }
            }
            for (uint32_t y = 0; sheet && y < height; ++y)
                memcpy(sheet + 4 * ((si * (size_t)height + y) * sheet_w + (size_t)NM * width), ref + 4 * (size_t)y * width,
                       4 * width * sizeof(float));
            ++si;
        }
        sy_mediator_rt_aovs_free(&a);
    }
    if (r == SY_OK) {
        double pass_ms = pass_s / spps[NS - 1] * 1e3;
        printf("  path tracing: %.1f ms per 1-spp pass; fast pixel filter pass at 4 spp %.1f ms = %.2f x one pass\n",
               pass_ms, t_pixel_ms, t_pixel_ms / pass_ms);
        printf("  radiance filtering: %.1f ms per 1-spp pass with records + filter frame (frame 4: filter %.1f ms = "
               "%.2f x one plain pass)\n", rf_pass_s / spps[NS - 1] * 1e3, t_rf_ms, t_rf_ms / pass_ms);
    }
    if (r == SY_OK && sheet) {
        r = sy_png_write(png_path, (int)sheet_w, (int)sheet_h, sheet, NULL, err);
        if (r == SY_OK)
            printf("  contact sheet %s: rows = spp 1, 4, 16, 64, 256; columns = none, pixel, pixel-brute, radiance,\n"
                   "  atrous, jbu, adaptive, reference\n", png_path);
    }
    sy_filter_pixel_destroy(pf);
    free(sheet), free(ref), free(out), free(pos), free(pix_out);
    if (refimg) sy_exr_image_free(refimg);
    sy_layer_destroy(&img);
    sy_layer_destroy(&img_rf);
    sy_context_pool_destroy(pool);
    sy_window_destroy(win);
    sy_window_destroy(win_rf);
    return r;
#endif
}
