/* sy_bench_instances.c — `sy bench instances`: one big mesh instanced many times (10^3 x 10^6 = 10^9
 * triangles by default) in every picture back-end: the first frame (translation included), the
 * frame time of an orbit around it, the triangles the rasterizer drew (levels of detail, view
 * culling), peak memory, and the coverage of each back-end against Whitted's (IoU). */
#include "sy_bench.h"

#include "sy_height_field.h"
#include "sy_log.h"
#include "sy_orbit.h"
#include "sy_stats.h"
#include "sy_mediator_rt.h"
#ifdef SY_HAVE_RASTER
#include "sy_mediator_raster.h"
#endif

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>

static long peak_rss_kib(void)
{
    struct rusage ru;
    return getrusage(RUSAGE_SELF, &ru) == 0 ? ru.ru_maxrss : -1;
}

static int cmp_d(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* The scene: `instances` nodes on a square grid under one root, each instancing the same height
 * field of about `tris` triangles (1 x 1 m, sy_height_field_generate), turned about Y; a camera node
 * (its matrix set per frame). */
static sy_result build(sy_scene *s, uint32_t instances, uint32_t tris, sy_node *root, sy_node *cam, float *extent,
                       uint32_t *tris_out, sy_error *err)
{
    sy_node first;
    sy_result r = sy_height_field_generate(s, tris, &first, tris_out, err);
    if (r != SY_OK) return r;
    sy_mesh mesh = sy_node_get(s, first)->mesh;
    uint32_t side = (uint32_t)ceil(sqrt((double)instances));
    *extent = 1.25f * (float)side;
    if ((r = sy_node_create(s, "instances", root, err)) != SY_OK) return r;
    for (uint32_t i = 0; i < instances && r == SY_OK; ++i) {
        sy_node n = first;
        if (i > 0) {
            r = sy_node_create(s, NULL, &n, err);
            if (r == SY_OK) r = sy_node_set_mesh(s, n, mesh, err);
        }
        float a = 0.7f * (float)(i % 9), t[3] = {1.25f * ((float)(i % side) - 0.5f * (float)(side - 1)), 0.0f,
                                                  1.25f * ((float)(i / side) - 0.5f * (float)(side - 1))};
        float q[4] = {0.0f, sinf(0.5f * a), 0.0f, cosf(0.5f * a)}, one[3] = {1, 1, 1};
        if (r == SY_OK) r = sy_node_set_trs(s, n, t, q, one, err);
        if (r == SY_OK) r = sy_node_add_child(s, *root, n, err);
    }
    sy_camera c;
    sy_camera_data cd = *(const sy_camera_data *)sy_object_defaults(SY_TYPE_CAMERA);
    cd.yfov = 0.8f;
    cd.znear = 0.05f;
    if (r == SY_OK) r = sy_camera_create(s, "orbit", &c, err);
    if (r == SY_OK) r = sy_camera_set(s, c, &cd, err);
    if (r == SY_OK) r = sy_node_create(s, "orbit camera", cam, err);
    if (r == SY_OK) r = sy_node_set_camera(s, *cam, c, err);
    return r;
}

/* Frame k of the orbit: once around the grid, looking down at about 35 degrees. */
static sy_result place_camera(sy_scene *s, sy_node cam, float extent, uint32_t k, uint32_t frames, sy_error *err)
{
    /* the eye at (d sin a, 0.7 d, d cos a), looking at the origin */
    float a = 6.2831853f * (float)k / (float)(frames ? frames : 1), d = 0.8f * extent;
    sy_orbit o = {.yaw = a, .pitch = atanf(0.7f), .dist = d * sqrtf(1.49f)};
    sy_mat4 m;
    sy_orbit_matrix(&o, &m);
    sy_result r = sy_node_set_matrix(s, cam, &m, err);
    return r == SY_OK ? sy_scene_commit(s, NULL, err) : r;
}

sy_result sy_bench_instances(uint32_t instances, uint32_t tris, uint32_t width, uint32_t height, uint32_t frames,
                             const char *only, sy_error *err)
{
    const sy_mediator_class *only_cls = only ? sy_mediator_find(only) : NULL;
    if (only && !only_cls) return sy_error_set(err, SY_ERR_NOT_FOUND, "sy bench instances: no back-end '%s'", only);
    sy_scene *s = NULL;
    sy_context_pool *pool = NULL;
    sy_node root = {0}, cam = {0};
    float extent = 1.0f;
    uint32_t mesh_tris = 0;
    double t0 = sy_time_now();
    sy_result r = sy_scene_create(&s, err);
    if (r == SY_OK) r = build(s, instances, tris, &root, &cam, &extent, &mesh_tris, err);
    if (r == SY_OK) r = place_camera(s, cam, extent, 0, frames, err);
    if (r == SY_OK) r = sy_context_pool_create(&pool, err);
    if (r != SY_OK) goto done;
    printf("sy bench instances: %u instances of a %u-triangle mesh = %.3g triangles, %ux%u, %u orbit frames "
           "(scene built in %.2f s)\n", instances, mesh_tris, (double)instances * mesh_tris, width, height, frames,
           sy_time_now() - t0);
    printf("  %-11s %12s %12s %12s %10s %14s %8s %10s\n", "back-end", "first frame", "frame p50", "frame max", "fps",
           "tris drawn", "culled", "IoU");
    sy_layer ref = {0};
    const char *ref_name = NULL;
    /* The reference: Whitted (one ray through each pixel centre for the depth layer); every other
     * picture back-end is compared against its first frame. */
    const sy_mediator_class *ref_cls = sy_mediator_rt_whitted_class();
#ifdef SY_HAVE_RASTER
    const sy_mediator_class *raster_cls = sy_mediator_raster_class(); /* its counters: triangles, culled */
#endif
    for (int pass = 0; pass < 2 && r == SY_OK; ++pass) /* the reference first */
        for (uint32_t b = 0; b < sy_mediator_count() && r == SY_OK; ++b) {
            const sy_mediator_class *cls = sy_mediator_at(b);
            if (cls->caps & (SY_CAP_ANALYSIS | SY_CAP_REMOTE)) continue; /* picture back-ends only */
            if ((pass == 0) != (cls == ref_cls)) continue;
            if (only_cls && cls != only_cls && cls != ref_cls) continue;
            /* -b: the reference still gives its first frame (for the IoU), without the orbit */
            uint32_t orbit = only_cls && cls != only_cls ? 0 : frames;
            sy_context_pool_destroy(pool); /* each back-end's translation is part of its first frame, */
            pool = NULL;                   /* and only one back-end's scene is held at a time */
            if ((r = sy_context_pool_create(&pool, err)) != SY_OK) break;
            sy_window *win = NULL;
            sy_layer img = {0};
            sy_viewport_desc vd = {.root = root, .camera = cam, .backend = cls->name};
            if ((r = place_camera(s, cam, extent, 0, frames, err)) != SY_OK) break;
            if ((r = sy_window_create(width, height, &win, err)) == SY_OK) r = sy_window_add_viewport(win, &vd, NULL, err);
            if (r == SY_OK) r = sy_layer_create(width, height, &img, err);
            sy_window_render_opts ro = {.sample_count = 1};
            double a = sy_time_now();
            if (r == SY_OK) r = sy_window_render(win, s, pool, &ro, &img, err);
            double first = sy_time_now() - a;
            double iou = -1.0;
            if (r == SY_OK && pass == 0) {
                ref = img;
                img = (sy_layer){0};
                ref_name = cls->name;
                r = sy_layer_create(width, height, &img, err);
            } else if (r == SY_OK && ref_name) {
                r = sy_layer_coverage_iou(&img, &ref, &iou, err);
            }
            double *ft = orbit ? calloc(orbit, sizeof *ft) : NULL;
            for (uint32_t k = 1; k <= orbit && r == SY_OK && ft; ++k) {
                a = sy_time_now();
                r = place_camera(s, cam, extent, k, frames, err);
                if (r == SY_OK) r = sy_window_render(win, s, pool, &ro, &img, err);
                ft[k - 1] = sy_time_now() - a;
            }
            unsigned long long drawn = 0, culled = 0;
#ifdef SY_HAVE_RASTER
            sy_context *ctx = NULL;
            if (r == SY_OK && cls == raster_cls &&
                sy_context_pool_get(pool, s, cls->name, NULL, root.id, &ctx, err) == SY_OK) {
                sy_mediator_raster_counters c = {0};
                sy_mediator_raster_counters_get(sy_context_state(ctx), &c);
                drawn = c.triangles_drawn;
                culled = c.instances_culled;
            }
#endif
            if (r == SY_OK) {
                double p50 = 0, mx = 0;
                if (orbit && ft) {
                    qsort(ft, orbit, sizeof *ft, cmp_d);
                    p50 = ft[orbit / 2];
                    mx = ft[orbit - 1];
                }
                char iou_s[32] = "reference", drawn_s[32] = "-", culled_s[32] = "-";
                if (iou >= 0.0) snprintf(iou_s, sizeof iou_s, "%.4f", iou);
                if (drawn) snprintf(drawn_s, sizeof drawn_s, "%llu", drawn), snprintf(culled_s, sizeof culled_s, "%llu", culled);
                printf("  %-11s %10.2f s %10.1f ms %10.1f ms %10.2f %14s %8s %10s\n", cls->name, first, p50 * 1e3, mx * 1e3,
                       p50 > 0 ? 1.0 / p50 : 0.0, drawn_s, culled_s, iou_s);
                fflush(stdout);
            }
            free(ft);
            sy_layer_destroy(&img);
            sy_window_destroy(win);
        }
    sy_layer_destroy(&ref);
    if (r == SY_OK)
        printf("  peak RSS %.1f MB; IoU: coverage (finite depth) against %s's first frame\n",
               (double)peak_rss_kib() / 1024.0, ref_name ? ref_name : "(none)");
done:
    sy_context_pool_destroy(pool);
    sy_scene_destroy(s);
    return r;
}
