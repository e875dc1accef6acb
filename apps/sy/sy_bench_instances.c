/* sy_bench_instances.c — `sy bench instances`: one big mesh instanced many times (10^3 x 10^6 = 10^9
 * triangles by default) in every picture back-end: the first frame (translation included), the
 * frame time of an orbit around it, the triangles the rasterizer drew (levels of detail, view
 * culling), peak memory, and the coverage of each back-end against Whitted's (IoU). Three scenes:
 * the one generated in the process, and on the user's path (issue 39) the same written to a .glb
 * with normals and UVs and to a .glb of positions and indices alone (as many exported files are),
 * each loaded by sy_cli_load, the loader `sy render` uses. Each back-end runs the three one after
 * the other (this machine's speed drifts over minutes); the files' numbers are the ones that
 * matter, the summary gives their ratios. */
#include "sy_bench.h"

#include "sy_gltf_write.h" /* sy_gltf_placements_collect */
#include "sy_height_field.h"
#include "sy_load.h"
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
#include <unistd.h>

static long peak_rss_kib(void)
{
    struct rusage ru;
    return getrusage(RUSAGE_SELF, &ru) == 0 ? ru.ru_maxrss : -1;
}

/* The orbit's camera node (its matrix set per frame by place_camera), not under the root. */
static sy_result make_camera(sy_scene *s, sy_node *cam, sy_error *err)
{
    sy_camera c;
    sy_camera_data cd = *(const sy_camera_data *)sy_object_defaults(SY_TYPE_CAMERA);
    cd.yfov = 0.8f;
    cd.znear = 0.05f;
    sy_result r = sy_camera_create(s, "orbit", &c, err);
    if (r == SY_OK) r = sy_camera_set(s, c, &cd, err);
    if (r == SY_OK) r = sy_node_create(s, "orbit camera", cam, err);
    if (r == SY_OK) r = sy_node_set_camera(s, *cam, c, err);
    return r;
}

/* The scene: `instances` nodes on a square grid under one root, each instancing the same height
 * field of about `tris` triangles (1 x 1 m, sy_height_field_generate), turned about Y. */
static sy_result build(sy_scene *s, uint32_t instances, uint32_t tris, sy_node *root, uint32_t *tris_out, sy_error *err)
{
    sy_node first;
    sy_result r = sy_height_field_generate(s, tris, &first, tris_out, err);
    if (r != SY_OK) return r;
    sy_mesh mesh = sy_node_get(s, first)->mesh;
    uint32_t side = (uint32_t)ceil(sqrt((double)instances));
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

/* What a scene holds under root: its placements of meshes, the distinct meshes among them, the
 * triangles placed, and whether every placed primitive has normals (the loader keeps a mesh without
 * them indexed and shades it flat). */
typedef struct shape {
    uint32_t placements, meshes;
    double triangles;
    bool normals;
} shape;

static sy_result scene_shape(const sy_scene *s, sy_node root, shape *out, sy_error *err)
{
    sy_gltf_placement *pl = NULL;
    uint32_t n = 0;
    sy_result r = sy_gltf_placements_collect(s, root, &pl, &n, err);
    if (r != SY_OK) return r;
    *out = (shape){.placements = n, .normals = true};
    uint32_t *seen = calloc(n ? n : 1, sizeof *seen);
    if (!seen) r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bench instances: out of memory");
    for (uint32_t i = 0; i < n && r == SY_OK; ++i) {
        const sy_mesh_data *md = sy_mesh_get(s, pl[i].mesh);
        if (!md) continue;
        for (uint32_t k = 0; k < md->primitives.count; ++k) {
            const sy_primitive *p = &md->primitives.items[k];
            out->triangles += sy_primitive_triangle_count(p);
            if (!p->normals) out->normals = false;
        }
        bool dup = false;
        for (uint32_t j = 0; j < out->meshes && !dup; ++j) dup = seen[j] == pl[i].mesh.id;
        if (!dup) seen[out->meshes++] = pl[i].mesh.id;
    }
    free(seen);
    free(pl);
    return r;
}

/* One of the three scenes: its objects and what its table rows say. */
typedef struct bench_scene {
    const char *label;
    sy_scene *s; /* owned (generated) or ld's (loaded) */
    loaded ld;   /* the files: as sy_cli_load gave them */
    sy_node root, cam;
    sy_layer ref; /* Whitted's first frame: the reference of the coverage IoU */
} bench_scene;

/* One back-end's numbers on one scene. */
typedef struct run_row {
    double first, p50, max, iou;
    unsigned long long drawn, culled;
} run_row;

/* One back-end on one scene seen from its camera: the first frame (the translation included: a
 * fresh context pool), the orbit's frames, the rasterizer's counters, coverage IoU against the
 * scene's reference (Whitted's first frame, taken here when sc->ref is empty). */
static sy_result run_one(const sy_mediator_class *cls, bench_scene *sc, float extent, uint32_t width, uint32_t height,
                         uint32_t frames, uint32_t orbit, run_row *out, sy_error *err)
{
    sy_context_pool *pool = NULL;
    sy_window *win = NULL;
    sy_layer img = {0};
    double *ft = NULL;
    *out = (run_row){.iou = -1.0};
    sy_viewport_desc vd = {.root = sc->root, .camera = sc->cam, .backend = cls->name};
    sy_result r = sy_context_pool_create(&pool, err);
    if (r == SY_OK) r = place_camera(sc->s, sc->cam, extent, 0, frames, err);
    if (r == SY_OK && (r = sy_window_create(width, height, &win, err)) == SY_OK)
        r = sy_window_add_viewport(win, &vd, NULL, err);
    if (r == SY_OK) r = sy_layer_create(width, height, &img, err);
    sy_window_render_opts ro = {.sample_count = 1};
    double a = sy_time_now();
    if (r == SY_OK) r = sy_window_render(win, sc->s, pool, &ro, &img, err);
    out->first = sy_time_now() - a;
    if (r == SY_OK && !sc->ref.rgba) {
        sc->ref = img;
        img = (sy_layer){0};
        r = sy_layer_create(width, height, &img, err);
    } else if (r == SY_OK) {
        r = sy_layer_coverage_iou(&img, &sc->ref, &out->iou, err);
    }
    ft = orbit ? calloc(orbit, sizeof *ft) : NULL;
    if (orbit && !ft && r == SY_OK) r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bench instances: out of memory");
    for (uint32_t k = 1; k <= orbit && r == SY_OK; ++k) {
        a = sy_time_now();
        r = place_camera(sc->s, sc->cam, extent, k, frames, err);
        if (r == SY_OK) r = sy_window_render(win, sc->s, pool, &ro, &img, err);
        ft[k - 1] = sy_time_now() - a;
    }
#ifdef SY_HAVE_RASTER
    sy_context *ctx = NULL;
    if (r == SY_OK && cls == sy_mediator_raster_class() && /* its counters: triangles drawn, instances culled */
        sy_context_pool_get(pool, sc->s, cls->name, NULL, sc->root.id, &ctx, err) == SY_OK) {
        sy_mediator_raster_counters c = {0};
        sy_mediator_raster_counters_get(sy_context_state(ctx), &c);
        out->drawn = c.triangles_drawn;
        out->culled = c.instances_culled;
    }
#endif
    if (r == SY_OK && orbit) {
        qsort(ft, orbit, sizeof *ft, sy_bench_cmp_double);
        out->p50 = ft[orbit / 2];
        out->max = ft[orbit - 1];
    }
    free(ft);
    sy_layer_destroy(&img);
    sy_window_destroy(win);
    sy_context_pool_destroy(pool); /* only one back-end's scene is held at a time */
    return r;
}

/* a / b as "R.RRx", "-" where either is missing or 0 */
static const char *ratio_s(char buf[16], double a, double b)
{
    if (a > 0.0 && b > 0.0) snprintf(buf, 16, "%.2fx", a / b);
    else snprintf(buf, 16, "-");
    return buf;
}

/* The generated scene through a .glb at path (sy_bench_reload_glb: written, then loaded as `sy
 * render` loads it), the loaded shape checked against the generated scene's (the same placements of
 * one shared mesh, the same triangles; normals as written). */
static sy_result through_file(bench_scene *sc, const sy_scene *gen, sy_node groot, const char *path, const shape *want,
                              bool normals, sy_error *err)
{
    uint64_t bytes = 0;
    double t0 = sy_time_now();
    sy_result r = sy_bench_reload_glb(gen, groot, path, "sy bench instances", &sc->ld, &bytes, err);
    if (r != SY_OK) return r;
    double secs = sy_time_now() - t0;
    sc->s = sc->ld.scene, sc->root = sc->ld.root;
    shape got = {0};
    r = scene_shape(sc->s, sc->root, &got, err);
    if (r == SY_OK && (got.placements != want->placements || got.meshes != 1 || got.triangles != want->triangles ||
                       got.normals != normals))
        return sy_error_set(err, SY_ERR_PARSE,
                            "bench instances: %s read back as %u placements of %u meshes, %.0f triangles, normals %s "
                            "(written: %u placements of 1 mesh, %.0f triangles, normals %s)",
                            path, got.placements, got.meshes, got.triangles, got.normals ? "yes" : "no",
                            want->placements, want->triangles, normals ? "yes" : "no");
    if (r == SY_OK)
        printf("  %s: %s, %.1f MB, written and loaded by sy_cli_load in %.2f s: %u placements of 1 mesh, %.3g "
               "triangles, normals %s\n", sc->label, path, (double)bytes / 1e6, secs, got.placements, got.triangles,
               got.normals ? "yes" : "no");
    return r == SY_OK ? make_camera(sc->s, &sc->cam, err) : r;
}

/* The generated scene's shared mesh reduced to positions and indices (no normals, no UVs). */
static sy_result strip_normals(sy_scene *s, sy_node root, sy_error *err)
{
    const sy_node_data *rd = sy_node_get(s, root);
    uint32_t nc = 0;
    const uint32_t *kids = rd ? sy_node_children(rd, &nc) : NULL;
    const sy_node_data *kd = nc ? sy_node_get(s, (sy_node){kids[0]}) : NULL;
    const sy_mesh_data *md = kd ? sy_mesh_get(s, kd->mesh) : NULL;
    if (!md || md->primitives.count != 1)
        return sy_error_set(err, SY_ERR_INVALID_OPERATION, "bench instances: the generated mesh is missing");
    sy_primitive p = md->primitives.items[0];
    p.normals = NULL, p.texcoords0 = NULL;
    return sy_mesh_set_primitives(s, kd->mesh, &p, 1, err);
}

sy_result sy_bench_instances(uint32_t instances, uint32_t tris, uint32_t width, uint32_t height, uint32_t frames,
                             const char *only, const char *out_dir, sy_error *err)
{
    const sy_mediator_class *only_cls = only ? sy_mediator_find(only) : NULL;
    if (only && !only_cls) return sy_error_set(err, SY_ERR_NOT_FOUND, "sy bench instances: no back-end '%s'", only);
    uint32_t mesh_tris = 0, side = (uint32_t)ceil(sqrt((double)instances));
    float extent = 1.25f * (float)side;
    shape want = {0};
    bench_scene sc[3] = {{.label = "generated"}, {.label = "file with normals"}, {.label = "file without normals"}};
    sy_scene *gen = NULL; /* the generated scene, written to the files with its mesh reduced: built twice */
    sy_node groot = {0};
    char dir[512] = "/tmp/sy_bench_instances_XXXXXX", path[2][600] = {"", ""};
    bool have_dir = false; /* a temporary folder of ours, removed at the end */
    double t0 = sy_time_now();
    sy_result r = sy_scene_create(&sc[0].s, err);
    if (r == SY_OK) r = build(sc[0].s, instances, tris, &sc[0].root, &mesh_tris, err);
    if (r == SY_OK) r = make_camera(sc[0].s, &sc[0].cam, err);
    if (r == SY_OK) r = scene_shape(sc[0].s, sc[0].root, &want, err);
    if (r != SY_OK) goto done;
    printf("sy bench instances: %u instances of a %u-triangle mesh = %.3g triangles, %ux%u, %u orbit frames "
           "(scene built in %.2f s)\n", instances, mesh_tris, (double)instances * mesh_tris, width, height, frames,
           sy_time_now() - t0);
    /* the user's path: the same scene through files, with normals and without */
    if (out_dir)
        snprintf(dir, sizeof dir, "%s", out_dir);
    else if (!(have_dir = mkdtemp(dir) != NULL))
        r = sy_error_set(err, SY_ERR_IO, "bench instances: cannot create a temporary directory");
    snprintf(path[0], sizeof path[0], "%s/instances.glb", dir);
    snprintf(path[1], sizeof path[1], "%s/instances_no_normals.glb", dir);
    if (r == SY_OK) r = sy_scene_create(&gen, err);
    if (r == SY_OK) r = build(gen, instances, tris, &groot, &mesh_tris, err);
    if (r == SY_OK) r = through_file(&sc[1], gen, groot, path[0], &want, true, err);
    if (r == SY_OK) r = strip_normals(gen, groot, err);
    if (r == SY_OK) r = through_file(&sc[2], gen, groot, path[1], &want, false, err);
    sy_scene_destroy(gen);
    if (r != SY_OK) goto done;
    /* per back-end the three scenes one after the other, so that a change in the machine's load
     * weighs on the three alike; Whitted first (every scene's coverage reference) */
    printf("  %-11s %-21s %12s %12s %12s %10s %14s %8s %10s\n", "back-end", "scene", "first frame", "frame p50",
           "frame max", "fps", "tris drawn", "culled", "IoU");
    const sy_mediator_class *ref_cls = sy_mediator_rt_whitted_class();
    run_row rows[16][3];
    const sy_mediator_class *done_cls[16];
    uint32_t nb = 0;
    for (int pass = 0; pass < 2 && r == SY_OK; ++pass)
        for (uint32_t b = 0; b < sy_mediator_count() && r == SY_OK && nb < 16; ++b) {
            const sy_mediator_class *cls = sy_mediator_at(b);
            if (cls->caps & (SY_CAP_ANALYSIS | SY_CAP_REMOTE)) continue; /* picture back-ends only */
            if ((pass == 0) != (cls == ref_cls)) continue;
            if (only_cls && cls != only_cls && cls != ref_cls) continue;
            /* -b: the reference still gives its first frame (for the IoU), without the orbit */
            uint32_t orbit = only_cls && cls != only_cls ? 0 : frames;
            for (int k = 0; k < 3 && r == SY_OK; ++k) {
                run_row *o = &rows[nb][k];
                r = run_one(cls, &sc[k], extent, width, height, frames, orbit, o, err);
                if (r != SY_OK) break;
                char iou_s[32] = "reference", drawn_s[32] = "-", culled_s[32] = "-";
                if (o->iou >= 0.0) snprintf(iou_s, sizeof iou_s, "%.4f", o->iou);
                if (o->drawn)
                    snprintf(drawn_s, sizeof drawn_s, "%llu", o->drawn),
                        snprintf(culled_s, sizeof culled_s, "%llu", o->culled);
                printf("  %-11s %-21s %10.2f s %10.1f ms %10.1f ms %10.2f %14s %8s %10s\n", cls->name, sc[k].label,
                       o->first, o->p50 * 1e3, o->max * 1e3, o->p50 > 0 ? 1.0 / o->p50 : 0.0, drawn_s, culled_s, iou_s);
                fflush(stdout);
            }
            done_cls[nb++] = cls;
        }
    if (r == SY_OK) {
        printf("  peak RSS %.1f MB (the three scenes held at once); IoU: coverage (finite depth) against Whitted's "
               "first frame of the same scene\n", (double)peak_rss_kib() / 1024.0);
        printf("summary: ratios of the times above (first frame, frame p50)\n");
        printf("  %-11s %25s %25s\n", "back-end", "no normals / normals", "normals / generated");
        for (uint32_t i = 0; i < nb; ++i) {
            const run_row *g = &rows[i][0], *a = &rows[i][1], *n = &rows[i][2];
            char r0[16], r1[16], r2[16], r3[16];
            printf("  %-11s %12s %12s %12s %12s\n", done_cls[i]->name, ratio_s(r0, n->first, a->first),
                   ratio_s(r1, n->p50, a->p50), ratio_s(r2, a->first, g->first), ratio_s(r3, a->p50, g->p50));
        }
    }
done:
    for (int k = 0; k < 2 && have_dir; ++k) unlink(path[k]);
    if (have_dir) rmdir(dir);
    for (int k = 0; k < 3; ++k) sy_layer_destroy(&sc[k].ref);
    sy_scene_destroy(sc[0].s);
    for (int k = 1; k < 3; ++k) sy_cli_loaded_free(&sc[k].ld);
    return r;
}
