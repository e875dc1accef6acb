/* sy_bench_raster.c — `sy bench raster`: the rasterizer's frame against the floor (the same
 * buffers drawn with a trivial shader), transform latency and uploads per frame (see sy_bench.h),
 * on the given scene and on a generated one, as generated and through a .glb (the user's path). */
#include "sy_bench.h"

#include "sy_demo.h"
#include "sy_load.h"
#ifdef SY_HAVE_RASTER
#include "sy_mediator_raster.h"
#endif

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* >>bench raster: our frame against the floor (the same buffers, trivial shader), transform
 * latency and uploads per frame, for one scene. */
static inline double median_of(double *t, uint32_t n) /* inline: used only with the rasterizer */
{
    qsort(t, n, sizeof *t, sy_bench_cmp_double);
    return t[n / 2];
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
        double a = sy_time_now();
        r = sy_bench_move(scene, moved, 0.001f * (float)(i + 1), err);
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
    /* generated geometry-bound scene: 100 meshes x 10000 triangles; and the user's path (issue 39):
     * the same written to a .glb and loaded by sy_cli_load, as sy render loads it */
    sy_scene *s = NULL;
    sy_node root = {0}, leaf = {0}, fleaf = {0};
    loaded ld = {0};
    if (r == SY_OK) r = sy_scene_create(&s, err);
    if (r == SY_OK) r = sy_demo_bench_scene(s, 1, 100, 10000, &root, &leaf, err);
    if (r == SY_OK) r = sy_scene_commit(s, NULL, err);
    if (r == SY_OK) r = sy_bench_reload_glb(s, root, NULL, "sy bench raster", &ld, NULL, err);
    if (r == SY_OK) r = sy_bench_first_mesh_node(ld.scene, ld.root, &fleaf, err);
    sy_viewport_desc g = {.root = root, .backend = "raster", .params = d.params};
    sy_viewport_desc gf = {.root = ld.root, .backend = "raster", .params = d.params};
    if (r == SY_OK) r = bench_raster_scene("generated 1M triangles", s, &g, leaf, width, height, repeats, err);
    if (r == SY_OK)
        r = bench_raster_scene("the same through a .glb", ld.scene, &gf, fleaf, width, height, repeats, err);
    /* the same scenes lit (a point light and a sky that gives ambient light): the generated scene
     * has neither, so the lines above shade with the unlit variant (black non-emissive surfaces) */
    if (r == SY_OK) r = bench_raster_light_scene(s, root, &g.background, err);
    if (r == SY_OK) r = bench_raster_light_scene(ld.scene, ld.root, &gf.background, err);
    if (r == SY_OK) r = bench_raster_scene("generated 1M triangles, lit", s, &g, leaf, width, height, repeats, err);
    if (r == SY_OK)
        r = bench_raster_scene("the same through a .glb, lit", ld.scene, &gf, fleaf, width, height, repeats, err);
    sy_cli_loaded_free(&ld);
    sy_scene_destroy(s);
    return r;
#endif
}
