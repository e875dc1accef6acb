/* sy_bench_governor.c — `sy bench governor`: the frame-time governor on an orbiting camera with
 * every picture back-end (see sy_bench_governor.h). */
#include "sy_bench_governor.h"

#include "sy_bench.h"
#include "sy_compose.h"
#include "sy_governor.h"
#include "sy_height_field.h"
#include "sy_orbit.h"

#include "sy_cli.h"
#include "sy_load.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#define GOV_DUCK "../shared/testdata/gltf/Duck/glTF-Binary/Duck.glb"
#define GOV_STEP_DEG 2.0      /* orbit step per frame */
#define GOV_FULL_FRAMES 5     /* full-size frames without the governor (reference) */
#define GOV_PI 3.14159265358979323846

typedef struct gov_scene {
    const char *label;
    sy_scene *scene;
    sy_node root;     /* {0}: every root */
    sy_node cam;      /* the orbiting camera (a top-level node) */
    sy_bounds bounds; /* of the scene before the camera was added */
    uint32_t tris;    /* 0 = not counted */
} gov_scene;

typedef struct gov_opts {
    double budget_ms;
    uint32_t frames, width, height;
    bool trace; /* --trace: one line per governed frame */
} gov_opts;

/* The orbiting camera: a perspective camera (45 degrees) on a top-level node. */
static sy_result gov_add_camera(gov_scene *gs, sy_error *err)
{
    sy_result r = sy_scene_commit(gs->scene, NULL, err);
    if (r != SY_OK) return r;
    gs->bounds = gs->root.id ? (sy_bounds){0} : sy_scene_world_bounds(gs->scene);
    if (gs->root.id && (r = sy_node_world_bounds(gs->scene, gs->root, &gs->bounds, err)) != SY_OK) return r;
    if (sy_bounds_is_empty(&gs->bounds))
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: the scene has no geometry to orbit", gs->label);
    sy_camera_data cd = *(const sy_camera_data *)sy_object_defaults(SY_TYPE_CAMERA);
    cd.projection = SY_PROJECTION_PERSPECTIVE;
    cd.yfov = (float)(45.0 * GOV_PI / 180.0);
    cd.aspect = 0.0f;
    cd.zfar = 0.0f;
    sy_camera cam;
    float dx = gs->bounds.max[0] - gs->bounds.min[0], dy = gs->bounds.max[1] - gs->bounds.min[1],
          dz = gs->bounds.max[2] - gs->bounds.min[2];
    float radius = 0.5f * sqrtf(dx * dx + dy * dy + dz * dz);
    cd.znear = radius * 0.01f;
    if ((r = sy_camera_create(gs->scene, "orbit", &cam, err)) || (r = sy_camera_set(gs->scene, cam, &cd, err)) ||
        (r = sy_node_create(gs->scene, "orbit", &gs->cam, err)) || (r = sy_node_set_camera(gs->scene, gs->cam, cam, err)))
        return r;
    return SY_OK;
}

/* Places the camera at orbit step i: around the bounds' centre, 25 degrees up, framing the
 * bounding sphere; commits. */
static sy_result gov_orbit(gov_scene *gs, uint32_t i, sy_error *err)
{
    const sy_bounds *b = &gs->bounds;
    float c[3], d2 = 0.0f;
    for (int k = 0; k < 3; ++k) c[k] = 0.5f * (b->min[k] + b->max[k]), d2 += (b->max[k] - b->min[k]) * (b->max[k] - b->min[k]);
    float radius = 0.5f * sqrtf(d2), dist = 1.15f * radius / sinf((float)(22.5 * GOV_PI / 180.0));
    sy_orbit o = {.target = {c[0], c[1], c[2]}, .yaw = (float)(i * GOV_STEP_DEG * GOV_PI / 180.0),
                  .pitch = (float)(25.0 * GOV_PI / 180.0), .dist = dist};
    sy_mat4 m;
    sy_orbit_matrix(&o, &m);
    sy_result r = sy_node_set_matrix(gs->scene, gs->cam, &m, err);
    return r == SY_OK ? sy_scene_commit(gs->scene, NULL, err) : r;
}

/* One frame of back-end `backend` at w x h (samples for a progressive one) at orbit step i; the
 * seconds of the whole frame (camera, commit, sync, render, composite). */
static sy_result gov_frame(gov_scene *gs, sy_context_pool *pool, const char *backend, uint32_t i, uint32_t w, uint32_t h,
                           uint32_t samples, float preview, double *secs, sy_error *err)
{
    double t0 = sy_time_now();
    sy_compose_spec spec = {.backend = backend, .root = gs->root, .camera = gs->cam};
    sy_window_render_opts ro = {.sample_count = samples, .preview = preview};
    sy_layer img = {0};
    sy_result r = gov_orbit(gs, i, err);
    if (r == SY_OK) r = sy_compose_render(gs->scene, pool, &spec, w, h, &ro, &img, NULL, err);
    sy_layer_destroy(&img);
    *secs = sy_time_now() - t0;
    return r;
}

static double cpu_now(void) /* seconds of CPU this process used (all its threads) */
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static double percentile(const double *sorted, uint32_t n, double p) /* nearest rank */
{
    uint32_t k = (uint32_t)ceil(p * n);
    return sorted[k ? k - 1 : 0];
}

static int cmp_d(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* One back-end on one scene: the translation frame, the full-size reference, then the governed run. */
static sy_result gov_backend(gov_scene *gs, const sy_mediator_class *cls, const gov_opts *o, bool tty, sy_error *err)
{
    sy_context_pool *pool = NULL;
    sy_governor *gov = NULL;
    double *iv = calloc(o->frames, sizeof *iv), full[GOV_FULL_FRAMES], first = 0, scale_sum = 0;
    sy_result r = iv ? SY_OK : sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bench governor: out of memory");
    if (r == SY_OK) r = sy_context_pool_create(&pool, err);
    if (r == SY_OK) r = sy_governor_create(&(sy_governor_desc){.budget_ms = o->budget_ms}, &gov, err);
    uint32_t caps = sy_mediator_class_caps(cls, NULL), step = 0;
    /* the translation (a new context's snapshot): left out of everything below */
    if (r == SY_OK) r = gov_frame(gs, pool, cls->name, step++, o->width, o->height, 1, 1.0f, &first, err);
    for (uint32_t k = 0; r == SY_OK && k < GOV_FULL_FRAMES; ++k)
        r = gov_frame(gs, pool, cls->name, step++, o->width, o->height, 1, 1.0f, &full[k], err);
    uint32_t over = 0;
    double t_prev = sy_time_now(), t_start = t_prev, cpu_start = cpu_now();
    for (uint32_t i = 0; r == SY_OK && i < o->frames; ++i) {
        sy_governor_frame f;
        double secs;
        sy_governor_plan(gov, o->width, o->height, caps, true, sy_time_now() * 1e3, &f); /* moves every frame */
        r = gov_frame(gs, pool, cls->name, step++, f.width, f.height, f.samples, f.preview, &secs, err);
        sy_governor_report(gov, &f, secs * 1e3);
        double now = sy_time_now();
        iv[i] = (now - t_prev) * 1e3; /* frame interval: planning, camera, commit, sync, render */
        t_prev = now;
        over += iv[i] > o->budget_ms;
        scale_sum += f.scale;
        if (o->trace)
            printf("    %s frame %u: %ux%u scale %.3f samples %u: frame %.1f ms, interval %.1f ms\n", cls->name, i, f.width,
                   f.height, (double)f.scale, f.samples, secs * 1e3, iv[i]);
        if (tty && (i % 8 == 7 || i + 1 == o->frames)) {
            fprintf(stderr, "\r  %-12s frame %u/%u   ", cls->name, i + 1, o->frames);
            fflush(stderr);
        }
    }
    if (tty) fprintf(stderr, "\r%50s\r", "");
    /* the share of the machine's cores this process had during the governed frames: well below 1
     * on a machine shared with other work (includes OpenMP's spinning) */
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    double share = (cpu_now() - cpu_start) / ((sy_time_now() - t_start) * (double)(cores > 0 ? cores : 1));
    if (r == SY_OK) {
        double fixed, per;
        bool model = sy_governor_cost(gov, true, &fixed, &per);
        qsort(iv, o->frames, sizeof *iv, cmp_d);
        sy_bench_spread fs = sy_bench_spread_of(full, GOV_FULL_FRAMES);
        double p95 = percentile(iv, o->frames, 0.95);
        printf("  %-11s %9.1f %10.1f %8.1f %8.1f %8.1f %7.2f%s %8.0f%% %6.2f %5.0f%%   ", cls->name, first * 1e3,
               fs.median * 1e3, percentile(iv, o->frames, 0.5), p95, iv[o->frames - 1], p95 / o->budget_ms,
               p95 <= 1.2 * o->budget_ms ? " " : "!", 100.0 * over / o->frames, scale_sum / o->frames, 100.0 * share);
        sy_governor_desc d;
        sy_governor_settings(gov, &d);
        if (model) printf("%.1f ms + %.1f ms/Mpixel%s\n", fixed, per * 1e6,
                          scale_sum / o->frames <= 1.05 * d.min_scale ? " (at the smallest scale)" : "");
        else printf("-\n");
        fflush(stdout); /* a row at a time, also into a file */
    }
    sy_governor_destroy(gov);
    sy_context_pool_destroy(pool);
    free(iv);
    return r;
}

static sy_result gov_scene_run(gov_scene *gs, const gov_opts *o, sy_error *err)
{
    bool tty = sy_is_terminal(2);
    if (gs->tris) printf("%s (%u triangles)\n", gs->label, gs->tris);
    else printf("%s\n", gs->label);
    printf("  %-11s %9s %10s %8s %8s %8s %8s %9s %6s %6s   %s\n", "back-end", "first ms", "full ms", "p50 ms", "p95 ms",
           "max ms", "p95/bud", "over bud", "scale", "cpu", "cost model (moving frames)");
    sy_result r = SY_OK;
    for (uint32_t i = 0; r == SY_OK && i < sy_mediator_count(); ++i) {
        const sy_mediator_class *cls = sy_mediator_at(i);
        if (sy_mediator_class_caps(cls, NULL) & (SY_CAP_ANALYSIS | SY_CAP_REMOTE)) continue; /* pictures only */
        r = gov_backend(gs, cls, o, tty, err);
        if (r != SY_OK) sy_error_prefix(err, "bench governor: %s on %s", cls->name, gs->label);
    }
    return r;
}

int sy_cmd_bench_governor(int argc, char **argv)
{
    gov_opts o = {.budget_ms = 33.0, .frames = 120, .width = 640, .height = 480};
    uint32_t tris = 1000000;
    static const char usage_text[] =
        "usage: sy bench governor [SCENE] [--budget MS] [--frames N] [-w W] [-h H] [--tris T] [--trace]\n"
        "  every picture back-end on an orbiting camera (one step per frame) through the frame-time governor:\n"
        "  p50 / p95 frame interval against the budget (default 33 ms), mean resolution scale. Without SCENE:\n"
        "  the glTF Duck (" GOV_DUCK ")\n"
        "  and a generated height field of T triangles (default 1000000), as generated and through a .glb\n"
        "  loaded as sy render loads it.\n"
        "  --trace: one line per governed frame (size, samples, time)\n";
    enum { O_BUDGET = OPT_OWN_FIRST, O_FRAMES, O_TRIS, O_TRACE };
    const sy_cli_opt opts[] = {SY_CLI_OPT_REAL("budget", O_BUDGET, &o.budget_ms, 1, 10000),
                               SY_CLI_OPT_UINT("frames", O_FRAMES, &o.frames, 1, 100000),
                               SY_CLI_OPT_UINT("tris", O_TRIS, &tris, 12, 1u << 30),
                               SY_CLI_OPT_FLAG("trace", O_TRACE, &o.trace)};
    sy_cli_parser p = {SY_CLI_ARGS("bench governor", argc, argv, opts), .w = &o.width, .h = &o.height, .min_size = 1,
                       .usage = usage_text};
    if (sy_cli_parse(&p) != -1) return p.status;
    if (argc - optind > 1) {
        fprintf(stderr, "sy bench governor: error: at most one SCENE\n%s", usage_text);
        return 2;
    }
    const char *scene = optind < argc ? argv[optind] : NULL;
    printf("sy bench governor: budget %.1f ms, %u frames per back-end at %ux%u, orbit %.0f deg per frame, %ld cores\n"
           "  (frame interval = plan + camera + commit + sync + render + composite; the machine may be shared:\n"
           "   compare rows of one run only; cpu = share of all cores this process had during the governed\n"
           "   frames; '!' marks p95 above 1.2x the budget)\n",
           o.budget_ms, o.frames, o.width, o.height, GOV_STEP_DEG, sysconf(_SC_NPROCESSORS_ONLN));
    sy_error err = {0};
    sy_result r = SY_OK;
    for (int k = 0; k < 3 && r == SY_OK; ++k) {
        gov_scene gs = {0};
        loaded ld = {0}; /* a scene file or the demo, as every command loads it (sy_load.h) */
        if (scene && k >= 1) break;
        if (k == 2) { /* the user's path: the height field written to a .glb and loaded back */
            sy_scene *hs = NULL;
            sy_node hf = {0};
            uint32_t nt = 0;
            r = sy_scene_create(&hs, &err);
            if (r == SY_OK) r = sy_height_field_generate(hs, tris, &hf, &nt, &err);
            if (r == SY_OK) r = sy_bench_reload_glb(hs, hf, NULL, "sy bench governor", &ld, NULL, &err);
            sy_scene_destroy(hs);
            gs.label = "the same through a .glb", gs.scene = ld.scene, gs.root = ld.root, gs.tris = nt;
        } else if (scene || k == 0) {
            const char *path = scene ? scene : GOV_DUCK;
            gs.label = path;
            if (!scene && access(path, R_OK) != 0) {
                printf("%s: not found (the shared test data), skipped\n", path);
                continue;
            }
            r = sy_cli_load(path, NULL, false, &ld, &err);
            gs.scene = ld.scene, gs.root = ld.root;
        } else if ((r = sy_scene_create(&gs.scene, &err)) == SY_OK) {
            gs.label = "generated height field";
            sy_node hf;
            r = sy_height_field_generate(gs.scene, tris, &hf, &gs.tris, &err);
        }
        if (r == SY_OK) r = gov_add_camera(&gs, &err);
        if (r == SY_OK) r = gov_scene_run(&gs, &o, &err);
        if (ld.scene) sy_cli_loaded_free(&ld);
        else sy_scene_destroy(gs.scene);
    }
    if (r != SY_OK) {
        fprintf(stderr, "sy: error: %s\n", err.message);
        return 1;
    }
    return 0;
}
