/* sy_bench_lights.c — `sy bench lights` (issue 39, many lights): the path tracer's light tree
 * against its power-proportional selection (the alias table) at equal time, on a generated scene
 * written to a glTF file and loaded by the normal loader (see sy_bench.h). */
#include "sy_bench.h"
#ifdef SY_HAVE_EMBREE
#include "sy_mediator_rt.h"
#endif
#include "sy_load.h"
#include "sy_output.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#ifdef SY_HAVE_EMBREE
/* >>scene: a floor (half-size 60) with 30 box occluders, `quads` small emissive quads (0.3 x 0.3,
 * facing down, 2 .. 6 above the floor, 8 materials of emissive strength 2 .. 37) and `points`
 * point lights (0.3 .. 3 above, intensities 0.2 .. 20 cd log-uniform, varied colours); a camera
 * above looking down at it. Written as PATH.gltf + PATH.bin. */
static uint32_t lcg(uint32_t *s)
{
    *s = *s * 1664525u + 1013904223u;
    return *s >> 8;
}
static float frnd(uint32_t *s) { return (float)lcg(s) * (1.0f / 16777216.0f); }

typedef struct gbuf {
    float *pos;
    uint32_t *idx;
    uint32_t nv, ni;
} gbuf;

static void put_v(gbuf *g, float x, float y, float z)
{
    g->pos[3 * g->nv] = x, g->pos[3 * g->nv + 1] = y, g->pos[3 * g->nv + 2] = z;
    g->nv++;
}

static void minmax(const float *p, uint32_t n, float lo[3], float hi[3])
{
    for (int k = 0; k < 3; ++k) lo[k] = INFINITY, hi[k] = -INFINITY;
    for (uint32_t i = 0; i < n; ++i)
        for (int k = 0; k < 3; ++k) lo[k] = fminf(lo[k], p[3 * i + k]), hi[k] = fmaxf(hi[k], p[3 * i + k]);
}

#define GROUPS 8

static sy_result write_scene(const char *stem, uint32_t quads, uint32_t points, float aspect, sy_error *err)
{
    /* meshes: 0 floor, 1 cube, 2 + g emissive group g; each one primitive */
    gbuf g[2 + GROUPS];
    const int ng = quads < GROUPS ? (int)quads : GROUPS; /* emissive meshes (none empty) */
    uint32_t per = (quads + (uint32_t)ng - 1) / (uint32_t)ng;
    memset(g, 0, sizeof g);
    for (int m = 0; m < 2 + ng; ++m) {
        uint32_t nq = m == 0 ? 1 : m == 1 ? 3 : per;
        g[m].pos = malloc((size_t)nq * 4 * 3 * sizeof(float) + 8 * 3 * sizeof(float));
        g[m].idx = malloc((size_t)nq * 6 * sizeof(uint32_t) + 36 * sizeof(uint32_t));
        if (!g[m].pos || !g[m].idx) {
            for (int k = 0; k <= m; ++k) free(g[k].pos), free(g[k].idx);
            return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bench lights: out of memory");
        }
    }
    const float L = 60.0f;
    put_v(&g[0], -L, 0, -L), put_v(&g[0], -L, 0, L), put_v(&g[0], L, 0, L), put_v(&g[0], L, 0, -L);
    static const uint32_t quad_idx[6] = {0, 1, 2, 0, 2, 3};
    for (int k = 0; k < 6; ++k) g[0].idx[g[0].ni++] = quad_idx[k];
    static const float cube_v[8][3] = {{-.5f, -.5f, -.5f}, {.5f, -.5f, -.5f}, {.5f, .5f, -.5f}, {-.5f, .5f, -.5f},
                                       {-.5f, -.5f, .5f},  {.5f, -.5f, .5f},  {.5f, .5f, .5f},  {-.5f, .5f, .5f}};
    static const uint32_t cube_i[36] = {0, 3, 2, 0, 2, 1, 4, 5, 6, 4, 6, 7, 0, 4, 7, 0, 7, 3,
                                        1, 2, 6, 1, 6, 5, 0, 1, 5, 0, 5, 4, 3, 7, 6, 3, 6, 2};
    for (int v = 0; v < 8; ++v) put_v(&g[1], cube_v[v][0], cube_v[v][1], cube_v[v][2]);
    for (int k = 0; k < 36; ++k) g[1].idx[g[1].ni++] = cube_i[k];
    uint32_t rs = 0x1234567u;
    const float s = 0.3f;
    for (uint32_t q = 0; q < quads; ++q) {
        gbuf *e = &g[2 + q % (uint32_t)ng];
        float x = frnd(&rs) * 80.0f - 40.0f, z = frnd(&rs) * 80.0f - 40.0f, h = 2.0f + 4.0f * frnd(&rs);
        uint32_t b = e->nv;
        put_v(e, x, h, z), put_v(e, x + s, h, z), put_v(e, x + s, h, z + s), put_v(e, x, h, z + s); /* faces -y */
        for (int k = 0; k < 6; ++k) e->idx[e->ni++] = b + quad_idx[k];
    }
    /* the binary buffer: per mesh positions then indices */
    char path[1024];
    snprintf(path, sizeof path, "%s.bin", stem);
    FILE *fb = fopen(path, "wb");
    if (!fb) {
        for (int m = 0; m < 2 + ng; ++m) free(g[m].pos), free(g[m].idx);
        return sy_error_set(err, SY_ERR_IO, "bench lights: cannot write %s", path);
    }
    size_t off[2 + GROUPS][2], total = 0;
    for (int m = 0; m < 2 + ng; ++m) {
        off[m][0] = total;
        fwrite(g[m].pos, sizeof(float), 3u * g[m].nv, fb);
        total += 12u * g[m].nv;
        off[m][1] = total;
        fwrite(g[m].idx, sizeof(uint32_t), g[m].ni, fb);
        total += 4u * g[m].ni;
    }
    bool bin_ok = fclose(fb) == 0;
    snprintf(path, sizeof path, "%s.gltf", stem);
    FILE *f = bin_ok ? fopen(path, "w") : NULL;
    if (!f) {
        for (int m = 0; m < 2 + ng; ++m) free(g[m].pos), free(g[m].idx);
        return sy_error_set(err, SY_ERR_IO, "bench lights: cannot write %s", path);
    }
    const char *base = strrchr(stem, '/');
    base = base ? base + 1 : stem;
    fprintf(f, "{\"asset\":{\"version\":\"2.0\",\"generator\":\"sy bench lights\"},\n");
    fprintf(f, "\"extensionsUsed\":[\"KHR_lights_punctual\",\"KHR_materials_emissive_strength\"],\n");
    fprintf(f, "\"buffers\":[{\"uri\":\"%s.bin\",\"byteLength\":%zu}],\n\"bufferViews\":[", base, total);
    for (int m = 0; m < 2 + ng; ++m)
        fprintf(f, "%s{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%u,\"target\":34962},"
                   "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%u,\"target\":34963}",
                m ? "," : "", off[m][0], 12u * g[m].nv, off[m][1], 4u * g[m].ni);
    fprintf(f, "],\n\"accessors\":[");
    for (int m = 0; m < 2 + ng; ++m) {
        float lo[3], hi[3];
        minmax(g[m].pos, g[m].nv, lo, hi);
        fprintf(f, "%s{\"bufferView\":%d,\"componentType\":5126,\"count\":%u,\"type\":\"VEC3\",\"min\":[%g,%g,%g],"
                   "\"max\":[%g,%g,%g]},{\"bufferView\":%d,\"componentType\":5125,\"count\":%u,\"type\":\"SCALAR\"}",
                m ? "," : "", 2 * m, g[m].nv, (double)lo[0], (double)lo[1], (double)lo[2], (double)hi[0], (double)hi[1],
                (double)hi[2], 2 * m + 1, g[m].ni);
    }
    fprintf(f, "],\n\"materials\":[{\"name\":\"floor\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.6,0.6,0.6,1],"
               "\"metallicFactor\":0,\"roughnessFactor\":0.8}},{\"name\":\"box\",\"pbrMetallicRoughness\":"
               "{\"baseColorFactor\":[0.7,0.35,0.25,1],\"metallicFactor\":0,\"roughnessFactor\":0.5}}");
    for (int k = 0; k < GROUPS; ++k) {
        float c[3] = {1.0f, 0.7f + 0.3f * (float)(k % 3) / 2.0f, 0.5f + 0.5f * (float)(k % 4) / 3.0f};
        double strength = 2.0 * pow(37.0 / 2.0, (double)k / (GROUPS - 1));
        fprintf(f, ",{\"name\":\"emitter%d\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[0,0,0,1],\"metallicFactor\":0},"
                   "\"emissiveFactor\":[%g,%g,%g],\"extensions\":{\"KHR_materials_emissive_strength\":"
                   "{\"emissiveStrength\":%g}}}",
                k, (double)c[0], (double)c[1], (double)c[2], strength);
    }
    fprintf(f, "],\n\"meshes\":[");
    for (int m = 0; m < 2 + ng; ++m)
        fprintf(f, "%s{\"primitives\":[{\"attributes\":{\"POSITION\":%d},\"indices\":%d,\"material\":%d}]}", m ? "," : "",
                2 * m, 2 * m + 1, m);
    fprintf(f, "],\n\"extensions\":{\"KHR_lights_punctual\":{\"lights\":[");
    for (uint32_t i = 0; i < points; ++i) {
        float c[3] = {0.6f + 0.4f * frnd(&rs), 0.6f + 0.4f * frnd(&rs), 0.6f + 0.4f * frnd(&rs)};
        double in = 0.2 * pow(100.0, (double)frnd(&rs));
        fprintf(f, "%s{\"type\":\"point\",\"color\":[%g,%g,%g],\"intensity\":%g}", i ? "," : "", (double)c[0],
                (double)c[1], (double)c[2], in);
    }
    fprintf(f, "]}},\n\"cameras\":[{\"type\":\"perspective\",\"perspective\":{\"yfov\":0.9,\"aspectRatio\":%g,"
               "\"znear\":0.1,\"zfar\":500}}],\n\"nodes\":[",
            (double)aspect);
    /* camera at (0, 30, 62), pitched down atan(30 / 62) */
    double a = atan2(30.0, 62.0);
    fprintf(f, "{\"camera\":0,\"translation\":[0,30,62],\"rotation\":[%g,0,0,%g]}", -sin(a / 2), cos(a / 2));
    fprintf(f, ",{\"mesh\":0}");
    for (int m = 0; m < ng; ++m) fprintf(f, ",{\"mesh\":%d}", 2 + m);
    for (int i = 0; i < 30; ++i) {
        float sx = 2.0f + 4.0f * frnd(&rs), sy = 1.0f + 3.0f * frnd(&rs), sz = 2.0f + 4.0f * frnd(&rs);
        float x = frnd(&rs) * 70.0f - 35.0f, z = frnd(&rs) * 70.0f - 35.0f;
        fprintf(f, ",{\"mesh\":1,\"translation\":[%g,%g,%g],\"scale\":[%g,%g,%g]}", (double)x, (double)(0.5f * sy),
                (double)z, (double)sx, (double)sy, (double)sz);
    }
    for (uint32_t i = 0; i < points; ++i) {
        float x = frnd(&rs) * 80.0f - 40.0f, z = frnd(&rs) * 80.0f - 40.0f, h = 0.3f + 2.7f * frnd(&rs);
        fprintf(f, ",{\"translation\":[%g,%g,%g],\"extensions\":{\"KHR_lights_punctual\":{\"light\":%u}}}", (double)x,
                (double)h, (double)z, i);
    }
    uint32_t nn = 1 + 1 + (uint32_t)ng + 30 + points;
    fprintf(f, "],\n\"scenes\":[{\"nodes\":[");
    for (uint32_t i = 0; i < nn; ++i) fprintf(f, "%s%u", i ? "," : "", i);
    fprintf(f, "]}],\"scene\":0}\n");
    for (int m = 0; m < 2 + ng; ++m) free(g[m].pos), free(g[m].idx);
    if (fclose(f) != 0) return sy_error_set(err, SY_ERR_IO, "bench lights: cannot write %s", path);
    return SY_OK;
}

/* relMSE of a against ref over the RGB of n pixels: mean of (a - r)^2 / (r^2 + 0.01) */
static double rel_mse(const float *a, const float *ref, size_t n)
{
    double s = 0.0;
    for (size_t i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c) {
            double r = ref[4 * i + c], d = (double)a[4 * i + c] - r;
            s += d * d / (r * r + 0.01);
        }
    return s / (3.0 * (double)n);
}

static double mean_of(const float *a, size_t n)
{
    double s = 0.0;
    for (size_t i = 0; i < n; ++i) s += a[4 * i] + a[4 * i + 1] + a[4 * i + 2];
    return s / (3.0 * (double)n);
}

typedef struct run {
    const char *name, *params;
    sy_window *win;
    sy_layer img;
    double seconds; /* timed passes (the first, with the scene's translation, is not) */
    uint32_t spp;
} run;

/* One pass of spp samples with seed; its time is added to *secs. */
static sy_result frame(run *u, sy_scene *scene, sy_context_pool *pool, uint32_t seed, uint32_t spp, double *secs,
                       sy_error *err)
{
    sy_window_render_opts ro = {.seed = seed, .sample_count = spp};
    double t0 = sy_time_now();
    sy_result r = sy_window_render(u->win, scene, pool, &ro, &u->img, err);
    *secs += sy_time_now() - t0;
    u->spp += spp;
    return r;
}
#endif

sy_result sy_bench_lights(uint32_t quads, uint32_t points, uint32_t width, uint32_t height, double seconds,
                          const char *out_dir, sy_error *err)
{
#ifndef SY_HAVE_EMBREE
    (void)quads, (void)points, (void)width, (void)height, (void)seconds, (void)out_dir;
    SY_BENCH_WITHOUT(err, "lights", "SY_WITH_EMBREE");
#else
    if (quads == 0) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "bench lights: at least one emissive quad");
    char dir[512];
    if (out_dir) {
        snprintf(dir, sizeof dir, "%s", out_dir);
    } else {
        snprintf(dir, sizeof dir, "/tmp/sy_bench_lights_XXXXXX");
        if (!mkdtemp(dir)) return sy_error_set(err, SY_ERR_IO, "bench lights: cannot create a temporary directory");
    }
    char stem[600];
    snprintf(stem, sizeof stem, "%s/many_lights", dir);
    sy_result r = write_scene(stem, quads, points, (float)width / (float)height, err);
    if (r != SY_OK) return r;
    char path[700];
    snprintf(path, sizeof path, "%s.gltf", stem);
    loaded ld;
    double t0 = sy_time_now();
    if ((r = sy_cli_load(path, NULL, true, &ld, err)) != SY_OK) return r;
    printf("sy bench lights: %s (%u emissive quads = %u triangles, %u point lights, 30 boxes over a floor), loaded in "
           "%.2f s; %ux%u, path tracer, %u threads\n",
           path, quads, 2 * quads, points, sy_time_now() - t0, width, height, (unsigned)sysconf(_SC_NPROCESSORS_ONLN));
    sy_context_pool *pool = NULL;
    r = sy_context_pool_create(&pool, err);
    /* the reference's parameters differ in text only (max_depth's default): a context of its own */
    run runs[3] = {{.name = "reference (tree)", .params = "light_tree=on,max_depth=64"},
                   {.name = "light tree", .params = "light_tree=on"},
                   {.name = "alias table (by power)", .params = "light_tree=off"}};
    for (int k = 0; k < 3 && r == SY_OK; ++k) {
        sy_viewport *vp;
        sy_viewport_desc vd = {.root = ld.root, .camera = ld.camera, .background = ld.background, .backend = "pathtracer",
                               .params = runs[k].params};
        r = sy_window_create(width, height, &runs[k].win, err);
        if (r == SY_OK) r = sy_window_add_viewport(runs[k].win, &vd, &vp, err);
        if (r == SY_OK) r = sy_layer_create(width, height, &runs[k].img, err);
    }
    /* the first pass of each (translation, BVH and light-tree build) is not timed, but counted */
    const uint32_t seeds[3] = {7777u, 1u, 1u};
    for (int k = 0; k < 3 && r == SY_OK; ++k) {
        double s;
        r = frame(&runs[k], ld.scene, pool, seeds[k], 1, &s, err);
    }
    sy_context *ctx = NULL; /* the tree's context: its counters */
    if (r == SY_OK) {
        sy_params pp = {0};
        if (sy_params_parse("light_tree=on", &pp, err) == SY_OK &&
            sy_context_pool_get(pool, ld.scene, "pathtracer", &pp, ld.root.id, &ctx, err) != SY_OK)
            ctx = NULL;
    }
    /* equal time: 1-spp passes of the tree and the alias table interleaved (the same load on both)
     * until each has `seconds` of render time */
    while (r == SY_OK && (runs[1].seconds < seconds || runs[2].seconds < seconds))
        for (int k = 1; k <= 2 && r == SY_OK; ++k)
            if (runs[k].seconds < seconds) r = frame(&runs[k], ld.scene, pool, seeds[k], 1, &runs[k].seconds, err);
    /* the reference: the tree with another seed, 8 x the time */
    while (r == SY_OK && runs[0].seconds < 8.0 * seconds) r = frame(&runs[0], ld.scene, pool, seeds[0], 4, &runs[0].seconds, err);
    if (r == SY_OK) {
        size_t n = (size_t)width * height;
        double e1 = rel_mse(runs[1].img.rgba, runs[0].img.rgba, n), e2 = rel_mse(runs[2].img.rgba, runs[0].img.rgba, n);
        for (int k = 0; k < 3; ++k) {
            printf("  %-24s %6u spp in %7.2f s (%7.1f spp/s)  mean %.5f", runs[k].name, runs[k].spp, runs[k].seconds,
                   runs[k].spp / fmax(runs[k].seconds, 1e-9), mean_of(runs[k].img.rgba, n));
            if (k) printf("  relMSE %.5f", k == 1 ? e1 : e2);
            printf("\n");
        }
        printf("  equal time: the alias table's error / the tree's = %.2f x (the issue's target: >= 5 x); time to the "
               "tree's error ~ %.2f x (relMSE ~ 1 / time)\n",
               e2 / e1, e2 / e1);
        printf("  the reference's own noise (1/8 of the time) inflates both errors, the tree's most: the ratio is a "
               "lower bound\n");
        /* build and update cost of the tree */
        sy_mediator_rt_counters c = {0};
        if (ctx) sy_mediator_rt_counters_get(sy_context_state(ctx), &c);
        printf("  light tree: %u lights, %.2f MB (%.0f bytes per light), built in %.2f ms\n", c.light_tree_lights,
               (double)c.light_tree_bytes / 1048576.0, (double)c.light_tree_bytes / fmax(1.0, (double)c.light_tree_lights),
               1e3 * c.light_tree_build_seconds);
        out_opts oo = {0};
        static const char *const names[3] = {"reference", "tree", "alias"};
        for (int k = 0; k < 3 && r == SY_OK; ++k) {
            char png[700];
            snprintf(png, sizeof png, "%s/%s.png", dir, names[k]);
            r = sy_cli_write_image(png, &runs[k].img, &oo, err);
        }
        if (r == SY_OK) printf("  images (equal time): %s/{tree,alias,reference}.png\n", dir);
        /* one light's update: the first point light's intensity doubles; the next pass refits */
        uint32_t lid = r == SY_OK ? sy_scene_next(ld.scene, SY_TYPE_LIGHT, 0) : 0;
        if (lid) {
            sy_light lh = {lid};
            sy_light_data d = *sy_light_get(ld.scene, lh);
            d.name = NULL;
            d.intensity *= 2.0f;
            double s;
            r = sy_light_set(ld.scene, lh, &d, err);
            if (r == SY_OK) r = sy_scene_commit(ld.scene, NULL, err);
            s = 0.0;
            if (r == SY_OK) r = frame(&runs[1], ld.scene, pool, seeds[1], 1, &s, err);
            if (r == SY_OK && ctx) {
                sy_mediator_rt_counters_get(sy_context_state(ctx), &c);
                printf("  one light's update (intensity x 2): refit of %u changed light(s) in %.2f ms (%llu refits, %llu "
                       "builds); the pass with it %.3f s\n",
                       c.light_tree_refit_changed, 1e3 * c.light_tree_refit_seconds,
                       (unsigned long long)c.light_tree_refits, (unsigned long long)c.light_tree_builds, s);
            }
        }
    }
    for (int k = 0; k < 3; ++k) {
        sy_layer_destroy(&runs[k].img);
        sy_window_destroy(runs[k].win);
    }
    sy_context_pool_destroy(pool);
    sy_cli_loaded_free(&ld);
    return r;
#endif
}
