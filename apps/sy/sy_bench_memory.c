/* sy_bench_memory.c — `sy bench memory` (issue 19): the peak RSS per triangle of a generated
 * height field rendered by a ray tracer, each measurement in a forked child (see sy_bench.h). */
#include "sy_bench.h"

#include "sy_gltf.h"
#include "sy_height_field.h"
#ifdef SY_HAVE_EMBREE
#include "sy_mediator_rt.h"
#endif

#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

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
    o->base_kib = sy_bench_rss_now_kib();
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
    o->scene_kib = sy_bench_rss_now_kib();
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
           tris,
           glb ? "loaded from a .glb (sy_gltf_load), through the scene's blobs"
               : "generated in the process, and the same loaded from a .glb (sy_gltf_load, the user's path),\n"
                 "through the scene's blobs",
           width, height);
    char dir[] = "/tmp/sy_bench_memory_XXXXXX", path[128] = "";
    if (!mkdtemp(dir)) return sy_error_set(err, SY_ERR_IO, "bench memory: cannot create a temporary directory");
    snprintf(path, sizeof path, "%s/height_field.glb", dir);
    uint32_t grid = (uint32_t)ceil(sqrt((double)tris / 2.0));
    sy_result r = sy_bench_write_grid_glb(path, grid, err);
    /* per back-end: generated (unless --glb), then from the file; the file's numbers are the ones
     * that matter, the ratio says what the loader adds */
    for (uint32_t i = 0; i < n && r == SY_OK; ++i) {
        double peaks[2] = {0, 0};
        for (int from_file = glb ? 1 : 0; from_file < 2 && r == SY_OK; ++from_file) {
            mem_report o;
            if ((r = mem_run(tris, from_file ? path : NULL, list[i], width, height, &o, err)) != SY_OK) break;
            double t = (double)o.tris, peak = (double)(o.peak_kib - o.base_kib) * 1024.0;
            double scene = (double)(o.scene_kib - o.base_kib) * 1024.0;
            const sy_mediator_rt_counters *c = &o.c;
            peaks[from_file] = peak / t;
            printf("%s, %s: %u triangles, translation %.2f s, first frame %.2f s\n", list[i],
                   from_file ? "from the .glb" : "generated", o.tris, o.build_s, o.frame_s);
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
        if (r == SY_OK && !glb)
            printf("%s: peak RSS from the .glb / generated %.2fx\n\n", list[i], peaks[0] > 0 ? peaks[1] / peaks[0] : 0.0);
    }
    unlink(path);
    rmdir(dir);
    return r;
#endif
}
