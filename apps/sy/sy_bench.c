/* sy_bench.c — what the `sy bench` benchmarks share (sy_bench.h): the spread of a benchmark's
 * rounds, sorting, the resident set, a timed frame, a back-end that keeps nothing, a generated
 * scene through a .glb (the user's path). Each benchmark has its file: sy_bench_sync.c, sy_bench_rays.c,
 * sy_bench_viewports.c, sy_bench_raster.c, sy_bench_load.c, sy_bench_memory.c,
 * sy_bench_pathtracer.c, sy_bench_filters.c, sy_bench_limit.c, sy_bench_instances.c,
 * sy_bench_governor.c, sy_bench_cull.c, sy_bench_web.c, sy_bench_deform.c, sy_bench_anim.c;
 * sy_cmd_bench.c parses the command line. */
#include "sy_bench.h"
#include "sy_gltf_write.h"
#include "sy_load.h"
#include "sy_mirror.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/stat.h>
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

sy_result sy_bench_frame(sy_window *win, sy_scene *scene, sy_context_pool *pool, uint32_t samples, sy_layer *out,
                         double *secs, sy_error *err)
{
    sy_window_render_opts ro = {.sample_count = samples};
    double t0 = sy_time_now();
    sy_result r = sy_window_render(win, scene, pool, &ro, out, err);
    *secs = sy_time_now() - t0;
    return r;
}

sy_result sy_bench_move(sy_scene *s, sy_node n, float x, sy_error *err)
{
    static const float q[4] = {0, 0, 0, 1}, one[3] = {1, 1, 1};
    const float t[3] = {x, 0.0f, 0.0f};
    sy_result r = sy_node_set_trs(s, n, t, q, one, err);
    return r == SY_OK ? sy_scene_commit(s, NULL, err) : r;
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

void sy_bench_tube(uint32_t rings, float *pos, float *nrm, uint32_t *j32, uint16_t *j16, float *w, uint32_t *idx)
{
    const uint32_t S = SY_BENCH_TUBE_SEGMENTS, J = SY_BENCH_TUBE_JOINTS;
    float seg = 2.0f / (float)(J - 1);
    for (uint32_t i = 0; i < rings; ++i)
        for (uint32_t k = 0; k < S; ++k) {
            size_t v = (size_t)i * S + k;
            float a = 6.2831853f * (float)k / (float)S, y = 2.0f * (float)i / (float)(rings - 1);
            pos[3 * v] = 0.1f * cosf(a), pos[3 * v + 1] = y, pos[3 * v + 2] = 0.1f * sinf(a);
            nrm[3 * v] = cosf(a), nrm[3 * v + 1] = 0.0f, nrm[3 * v + 2] = sinf(a);
            uint32_t jj = (uint32_t)(y / seg);
            if (jj >= J - 1) jj = J - 2;
            float f = y / seg - (float)jj;
            if (j32) j32[4 * v] = jj, j32[4 * v + 1] = jj + 1;
            else j16[4 * v] = (uint16_t)jj, j16[4 * v + 1] = (uint16_t)(jj + 1);
            w[4 * v] = 1.0f - f, w[4 * v + 1] = f;
        }
    for (uint32_t i = 0; i + 1 < rings; ++i)
        for (uint32_t k = 0; k < S; ++k) {
            uint32_t a = i * S + k, c = i * S + (k + 1) % S, *q = idx + 6 * ((size_t)i * S + k);
            q[0] = a, q[1] = a + S, q[2] = c, q[3] = c, q[4] = a + S, q[5] = c + S;
        }
}

sy_result sy_bench_reload_glb(const sy_scene *s, sy_node root, const char *path, const char *generator,
                              struct loaded *out, uint64_t *bytes_out, sy_error *err)
{
    char dir[] = "/tmp/sy_bench_glb_XXXXXX", tmp[64] = "";
    if (!path) {
        if (!mkdtemp(dir)) return sy_error_set(err, SY_ERR_IO, "sy bench: cannot create a temporary directory");
        snprintf(tmp, sizeof tmp, "%s/scene.glb", dir);
        path = tmp;
    }
    sy_result r = sy_gltf_write_scene_file(s, root, &(sy_gltf_write_options){.generator = generator}, path, err);
    struct stat st;
    if (bytes_out) *bytes_out = r == SY_OK && stat(path, &st) == 0 ? (uint64_t)st.st_size : 0;
    if (r == SY_OK) r = sy_cli_load(path, NULL, false, out, err);
    if (tmp[0]) {
        unlink(tmp);
        rmdir(dir);
    }
    return r;
}

sy_result sy_bench_first_mesh_node(const sy_scene *s, sy_node root, sy_node *out, sy_error *err)
{
    sy_node n = root;
    for (uint32_t depth = 0; depth < 64; ++depth) {
        const sy_node_data *d = sy_node_get(s, n);
        if (!d) break;
        if (d->mesh.id) return *out = n, SY_OK;
        uint32_t count = 0;
        const uint32_t *kids = sy_node_children(d, &count);
        if (!count) break;
        n = (sy_node){kids[0]};
    }
    return sy_error_set(err, SY_ERR_NOT_FOUND, "sy bench: no mesh under the scene's first children");
}
