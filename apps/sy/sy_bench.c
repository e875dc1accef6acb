/* sy_bench.c — what the `sy bench` benchmarks share (sy_bench.h): the spread of a benchmark's
 * rounds, sorting, the resident set, a timed frame, a back-end that keeps nothing. Each benchmark has its file: sy_bench_sync.c, sy_bench_rays.c,
 * sy_bench_viewports.c, sy_bench_raster.c, sy_bench_load.c, sy_bench_memory.c,
 * sy_bench_pathtracer.c, sy_bench_filters.c, sy_bench_limit.c, sy_bench_instances.c,
 * sy_bench_governor.c, sy_bench_cull.c, sy_bench_web.c, sy_bench_deform.c, sy_bench_anim.c;
 * sy_cmd_bench.c parses the command line. */
#include "sy_bench.h"
#include "sy_mirror.h"

#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

int sy_bench_cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

sy_bench_spread sy_bench_spread_of(double *v, uint32_t n)
{
    qsort(v, n, sizeof *v, sy_bench_cmp_double);
    double med = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
    return (sy_bench_spread){v[0], med, v[n - 1]};
}

/* Resident set of this process in KiB (/proc/self/statm), 0 when unknown. */
long sy_bench_rss_now_kib(void)
{
    FILE *f = fopen("/proc/self/statm", "r");
    long size = 0, res = 0;
    if (f) {
        if (fscanf(f, "%ld %ld", &size, &res) != 2) res = 0;
        fclose(f);
    }
    return res * (sysconf(_SC_PAGESIZE) / 1024);
}

sy_result sy_bench_frame(sy_window *win, sy_scene *scene, sy_context_pool *pool, uint32_t samples, sy_layer *out,
                         double *secs, sy_error *err)
{
    sy_window_render_opts ro = {.sample_count = samples};
    double t0 = sy_time_now();
    sy_result r = sy_window_render(win, scene, pool, &ro, out, err);
    *secs = sy_time_now() - t0;
    return r;
}

/* >>a back-end that keeps nothing (sy_bench_nop_mirror): handles numbered in turn */
static uint32_t g_next;
static sy_result nop_set(void *u, const sy_mirror_primitive_args *a, sy_error *e) { (void)u, (void)e; *a->handle = ++g_next; return SY_OK; }
static sy_result nop_update(void *u, const sy_mirror_primitive_args *a, sy_error *e) { (void)u, (void)a, (void)e; return SY_OK; }
static sy_result nop_inst(void *u, const sy_mirror_instance_args *a, sy_error *e)
{
    (void)u, (void)e;
    if (!*a->handle) *a->handle = ++g_next;
    return SY_OK;
}
static void nop_release(void *u, const sy_mirror_release_args *a) { (void)u, (void)a; }
const sy_mirror_callbacks sy_bench_nop_mirror = {.primitive_set = nop_set, .instance_set = nop_inst, .release = nop_release,
                                                 .primitive_update = nop_update};
