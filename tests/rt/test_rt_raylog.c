/* test_rt_raylog.c — the path tracer's ray log and its raw-Embree replay (backends/rt/
 * sy_rt_raylog.h, sy_rt_limit.h, `sy bench limit`), on a small open box with an area light and two instanced
 * spheres, 32x32:
 *   - logging changes nothing: the image with a log is bit-identical to the one without;
 *   - the log holds every ray the frame counted (sy_rt_accum_last_rays), at least one camera ray
 *     per sample, and shadow rays;
 *   - rtcIntersect1 / rtcOccluded1 on the logged rays give exactly the logged answers (geomID,
 *     primID, instID; occluded or not), and so do the 4/8/16 packets and the 1M streams (allowed:
 *     one in a thousand, ties between triangles at the same distance);
 *   - the check can fail: one altered answer in each list is found;
 *   - with an alpha-blended surface, shadow rays become closest-hit steps and are logged as such;
 *   - the stage timers (sy_rt_raylog.h >>stage timers) change no pixel, time one pixel in about
 *     SY_RT_STAGE_SUBSET, and see traversal, hit fetch, shading and sampling;
 *   - sy_rt_bench_limit reports consistent counts and stage shares that sum to 1; a log or stage
 *     timers with another integrator are refused. */
#include "rt_test.h"
#include "sy_rt_limit.h"

/* A box [-1, 1]^3 open at the front (z = 1): floor, ceiling, back, left and right walls; the
 * camera looks in from z = 3. */
static sy_rt_mesh box(sy_rt_device *dev)
{
    static const float p[] = {
        -1, -1, 1,  1, -1, 1,  1, -1, -1, -1, -1, -1, /* floor */
        -1, 1,  -1, 1, 1,  -1, 1, 1,  1,  -1, 1,  1,  /* ceiling */
        -1, -1, -1, 1, -1, -1, 1, 1,  -1, -1, 1,  -1, /* back */
        -1, -1, 1,  -1, -1, -1, -1, 1, -1, -1, 1, 1,  /* left */
        1,  -1, -1, 1, -1, 1,  1, 1,  1,  1,  1,  -1, /* right */
    };
    uint32_t idx[30];
    for (uint32_t f = 0; f < 5; ++f) {
        const uint32_t q[6] = {0, 1, 2, 0, 2, 3};
        for (int k = 0; k < 6; ++k) idx[6 * f + k] = 4 * f + q[k];
    }
    sy_rt_mesh_desc d = {.positions = p, .indices = idx, .vertex_count = 20, .triangle_count = 10};
    sy_rt_mesh m;
    MUST(sy_rt_mesh_create(dev, &d, &m));
    return m;
}

static sy_rt_mesh light_quad(sy_rt_device *dev)
{
    static const float p[] = {-0.3f, 0.98f, -0.3f, 0.3f, 0.98f, -0.3f, 0.3f, 0.98f, 0.3f, -0.3f, 0.98f, 0.3f};
    static const uint32_t idx[] = {0, 1, 2, 0, 2, 3};
    sy_rt_mesh_desc d = {.positions = p, .indices = idx, .vertex_count = 4, .triangle_count = 2};
    sy_rt_mesh m;
    MUST(sy_rt_mesh_create(dev, &d, &m));
    return m;
}


enum { W = 32, H = 32, SPP = 2 };

/* The frame of every render here: path tracer, W x H, SPP samples, seed 7, into a new accumulator
 * (the caller destroys d.accum). */
static sy_rt_render_desc frame_desc(sy_rt_device *dev)
{
    sy_rt_render_desc d = rt_desc(SY_RT_INTEGRATOR_PATHTRACER, W, H);
    MUST(sy_rt_accum_create(dev, W, H, &d.accum));
    d.samples = SPP;
    d.seed = 7;
    return d;
}

/* Renders one frame (2 spp, seed 7) with the log (NULL = none) into rgba; returns the rays counted. */
static uint64_t render_timed(sy_rt_device *dev, const sy_rt_camera *cam, sy_rt_ray_log *log, sy_rt_stage_times *st,
                             float *rgba)
{
    sy_rt_render_desc d = frame_desc(dev);
    sy_rt_accum *acc = d.accum;
    d.ray_log = log;
    d.stage_times = st;
    MUST(sy_rt_render(dev, cam, &d, rgba, NULL));
    uint64_t rays = sy_rt_accum_last_rays(acc);
    sy_rt_accum_destroy(acc);
    return rays;
}
static uint64_t render(sy_rt_device *dev, const sy_rt_camera *cam, sy_rt_ray_log *log, float *rgba)
{
    return render_timed(dev, cam, log, NULL, rgba);
}

/* Replays the log in every form and checks the answers. */
static void check_replay(sy_rt_device *dev, sy_rt_ray_log *log, const char *what)
{
    uint64_t total = log->intersect.n + log->occluded.n;
    for (int f = 0; f < SY_RT_FORM_COUNT; ++f) {
        sy_rt_ray_replay *rp = NULL;
        MUST(sy_rt_ray_replay_create(dev, log, (sy_rt_ray_form)f, &rp));
        uint64_t bad = ~0ull;
        double t = sy_rt_ray_replay_run(rp, &bad);
        printf("%s: %-32s %llu rays, %llu differ (%.2f ms)\n", what, sy_rt_ray_form_name((sy_rt_ray_form)f),
               (unsigned long long)total, (unsigned long long)bad, t * 1e3);
        if (f == SY_RT_FORM_1) EXPECT_MSG(bad == 0, "%s: rtcIntersect1/rtcOccluded1: %llu answers differ", what, (unsigned long long)bad);
        else EXPECT_MSG(bad * 1000u <= total, "%s: %s: %llu of %llu answers differ", what, sy_rt_ray_form_name((sy_rt_ray_form)f),
                        (unsigned long long)bad, (unsigned long long)total);
        sy_rt_ray_replay_destroy(rp);
    }
}

static uint64_t replay1(sy_rt_device *dev, sy_rt_ray_log *log)
{
    sy_rt_ray_replay *rp = NULL;
    MUST(sy_rt_ray_replay_create(dev, log, SY_RT_FORM_1, &rp));
    uint64_t bad = 0;
    sy_rt_ray_replay_run(rp, &bad);
    sy_rt_ray_replay_destroy(rp);
    return bad;
}

int main(void)
{
    sy_rt_device *dev = rt_device();
    float id[16], xf[16];
    rt_identity(id);
    rt_place(dev, box(dev), id, rt_lambert(dev, 0.7f, 0.7f, 0.7f), SY_RT_INSTANCE_BAKED);
    rt_place(dev, light_quad(dev), id, rt_emitter(dev, 8.0f, 8.0f, 8.0f), SY_RT_INSTANCE_BAKED);
    sy_rt_mesh s = rt_uv_sphere(dev, 0.3f, 16, false);
    sy_rt_material sm = rt_lambert(dev, 0.8f, 0.3f, 0.2f);
    rt_translation(xf, -0.4f, -0.7f, -0.2f);
    rt_place(dev, s, xf, sm, 0); /* instanced: instID matters */
    rt_translation(xf, 0.45f, -0.7f, 0.3f);
    rt_place(dev, s, xf, sm, 0);
    MUST(sy_rt_commit(dev));
    sy_rt_camera cam = rt_camera(3.0f, 0.45f);

    /* logging changes nothing */
    float *a = malloc(W * H * 4 * sizeof(float)), *b = malloc(W * H * 4 * sizeof(float));
    sy_rt_ray_log *log = NULL;
    MUST(sy_rt_ray_log_create(dev, &log));
    uint64_t rays_plain = render(dev, &cam, NULL, a);
    uint64_t rays_logged = render(dev, &cam, log, b);
    EXPECT_MSG(!memcmp(a, b, W * H * 4 * sizeof(float)), "the image with a ray log differs from the one without");
    EXPECT_MSG(rays_plain == rays_logged, "rays %llu without the log, %llu with it", (unsigned long long)rays_plain,
               (unsigned long long)rays_logged);

    /* stage timers change nothing and see every stage of a lit, bouncing path */
    sy_rt_stage_times st;
    memset(&st, 0, sizeof st);
    uint64_t rays_timed = render_timed(dev, &cam, NULL, &st, b);
    EXPECT_MSG(!memcmp(a, b, W * H * 4 * sizeof(float)), "the image with stage timers differs from the one without");
    EXPECT_MSG(rays_timed == rays_plain, "rays %llu with stage timers, %llu without", (unsigned long long)rays_timed,
               (unsigned long long)rays_plain);
    uint64_t timed = atomic_load(&st.samples);
    printf("stage timers: %llu of %d samples timed\n", (unsigned long long)timed, W * H * SPP);
    EXPECT_MSG(timed >= (uint64_t)W * H * SPP / SY_RT_STAGE_SUBSET / 2u && timed <= (uint64_t)W * H * SPP / SY_RT_STAGE_SUBSET * 2u,
               "stage timers: %llu of %d samples timed (about 1 in %u expected)", (unsigned long long)timed, W * H * SPP,
               SY_RT_STAGE_SUBSET);
    const sy_rt_stage seen[] = {SY_RT_STAGE_RNG,       SY_RT_STAGE_TRAVERSAL, SY_RT_STAGE_SHADOW,      SY_RT_STAGE_HIT_FETCH,
                                SY_RT_STAGE_BSDF_INIT, SY_RT_STAGE_SHADING,   SY_RT_STAGE_LIGHT,       SY_RT_STAGE_BSDF_EVAL,
                                SY_RT_STAGE_BSDF_SAMPLE, SY_RT_STAGE_ACCUM};
    for (size_t i = 0; i < sizeof seen / sizeof seen[0]; ++i)
        EXPECT_MSG(atomic_load(&st.laps[seen[i]]) > 0 && atomic_load(&st.ticks[seen[i]]) > 0, "stage '%s' never timed",
                   sy_rt_stage_name(seen[i]));
    /* every extension ray is one traversal span (spans over SY_RT_STAGE_MAX_LAP are left out) */
    EXPECT_MSG(atomic_load(&st.laps[SY_RT_STAGE_TRAVERSAL]) + atomic_load(&st.dropped) >= timed,
               "%llu traversal spans for %llu samples", (unsigned long long)atomic_load(&st.laps[SY_RT_STAGE_TRAVERSAL]),
               (unsigned long long)timed);

    /* the log holds the frame's rays */
    uint64_t total = log->intersect.n + log->occluded.n;
    printf("opaque box: %llu rays = %llu extension + %llu shadow; %zu closest-hit + %zu occlusion queries\n",
           (unsigned long long)total, (unsigned long long)log->kind_count[SY_RT_RAY_EXTENSION],
           (unsigned long long)log->kind_count[SY_RT_RAY_SHADOW], log->intersect.n, log->occluded.n);
    EXPECT_MSG(total == rays_logged, "log holds %llu rays, the frame counted %llu", (unsigned long long)total,
               (unsigned long long)rays_logged);
    EXPECT_MSG(log->kind_count[0] + log->kind_count[1] == total, "kind counts do not add up");
    EXPECT_MSG(log->kind_count[SY_RT_RAY_EXTENSION] >= (uint64_t)W * H * SPP, "fewer extension rays (%llu) than samples",
               (unsigned long long)log->kind_count[SY_RT_RAY_EXTENSION]);
    EXPECT_MSG(log->kind_count[SY_RT_RAY_EXTENSION] > (uint64_t)W * H * SPP, "no bounce in the box");
    EXPECT_MSG(log->occluded.n > 0 && log->occluded.n == log->kind_count[SY_RT_RAY_SHADOW],
               "opaque scene: every shadow ray is an occlusion query (%zu of %llu)", log->occluded.n,
               (unsigned long long)log->kind_count[SY_RT_RAY_SHADOW]);
    uint64_t hits = 0, inst = 0, occl = 0;
    for (size_t i = 0; i < log->intersect.n; ++i) {
        hits += log->intersect.v[i].geom != RTC_INVALID_GEOMETRY_ID;
        inst += log->intersect.v[i].geom != RTC_INVALID_GEOMETRY_ID && log->intersect.v[i].inst != RTC_INVALID_GEOMETRY_ID;
    }
    for (size_t i = 0; i < log->occluded.n; ++i) occl += log->occluded.v[i].geom != 0;
    EXPECT_MSG(hits > log->intersect.n / 2, "the box: most closest-hit rays hit (%llu of %zu)", (unsigned long long)hits,
               log->intersect.n);
    EXPECT_MSG(inst > 0, "no recorded hit on an instanced sphere");
    EXPECT_MSG(occl > 0 && occl < log->occluded.n, "shadow rays: %llu of %zu occluded (both kinds expected)",
               (unsigned long long)occl, log->occluded.n);

    /* the replay reproduces the answers, in every form */
    check_replay(dev, log, "opaque box");

    /* the check can fail */
    size_t k = log->intersect.n / 2;
    log->intersect.v[k].prim += 1u; /* a hit on another triangle (or, for a miss, a hit) */
    if (log->intersect.v[k].geom == RTC_INVALID_GEOMETRY_ID) log->intersect.v[k].geom = 0;
    log->occluded.v[0].geom ^= 1u;
    uint64_t bad = replay1(dev, log);
    EXPECT_MSG(bad == 2, "two altered answers, %llu found", (unsigned long long)bad);

    /* an alpha-blended pane: shadow rays step through it with closest-hit queries */
    sy_rt_material_desc md;
    sy_rt_material_desc_init(&md);
    md.base_color[3] = 0.5f;
    md.alpha_mode = SY_RT_ALPHA_BLEND;
    md.specular = 0.0f;
    sy_rt_material pane = rt_material(dev, &md);
    rt_translation(xf, 0.0f, 0.0f, 0.2f);
    rt_place(dev, rt_quad(dev, 0.4f), xf, pane, 0);
    MUST(sy_rt_commit(dev));
    sy_rt_ray_log_clear(log);
    rays_logged = render(dev, &cam, log, b);
    total = log->intersect.n + log->occluded.n;
    uint64_t shadow_steps = 0;
    for (size_t i = 0; i < log->intersect.n; ++i) shadow_steps += log->intersect.v[i].kind == SY_RT_RAY_SHADOW;
    printf("with a blended pane: %llu rays, %llu shadow steps as closest-hit queries\n", (unsigned long long)total,
           (unsigned long long)shadow_steps);
    EXPECT_MSG(total == rays_logged, "log holds %llu rays, the frame counted %llu", (unsigned long long)total,
               (unsigned long long)rays_logged);
    EXPECT_MSG(shadow_steps > 0 && log->occluded.n == 0, "blend: %llu shadow steps, %zu occlusion queries",
               (unsigned long long)shadow_steps, log->occluded.n);
    check_replay(dev, log, "blended pane");
    sy_rt_ray_log_destroy(log);

    /* the benchmark's counts */
    sy_rt_render_desc d = frame_desc(dev);
    sy_rt_accum *acc = d.accum;
    sy_rt_limit_result lr;
    MUST(sy_rt_bench_limit(dev, &cam, &d, 2, &lr));
    EXPECT_MSG(lr.rays == rays_logged && lr.extension_rays + lr.shadow_rays == lr.rays &&
               lr.intersect_queries + lr.occluded_queries == lr.rays,
               "bench counts %llu %llu %llu", (unsigned long long)lr.rays, (unsigned long long)lr.extension_rays,
               (unsigned long long)lr.shadow_rays);
    EXPECT_MSG(lr.mismatches[SY_RT_FORM_1] == 0, "bench: %llu mismatches", (unsigned long long)lr.mismatches[0]);
    for (int f = 0; f < SY_RT_FORM_COUNT; ++f)
        EXPECT_MSG(lr.share[f][0] > 0.0 && lr.share[f][0] <= lr.share[f][1] && lr.share[f][1] <= lr.share[f][2] &&
                   lr.form_seconds[f][1] > 0.0,
                   "bench: form %d spread %g %g %g", f, lr.share[f][0], lr.share[f][1], lr.share[f][2]);
    double share_sum = 0.0;
    for (int k = 0; k < SY_RT_STAGE_COUNT; ++k) share_sum += lr.stage_share[k];
    EXPECT_MSG(fabs(share_sum - 1.0) < 1e-9 && lr.stage_share[SY_RT_STAGE_TRAVERSAL] > 0.0 && lr.stage_samples > 0,
               "bench: stage shares sum to %g, traversal %g, %llu samples", share_sum,
               lr.stage_share[SY_RT_STAGE_TRAVERSAL], (unsigned long long)lr.stage_samples);

    /* a log with another integrator is refused */
    d.integrator = SY_RT_INTEGRATOR_WHITTED;
    MUST(sy_rt_ray_log_create(dev, &log));
    d.ray_log = log;
    sy_rt_result r = sy_rt_render(dev, &cam, &d, a, NULL);
    EXPECT_MSG(r == SY_RT_ERROR_INVALID_ARGUMENT && strstr(sy_rt_device_error(dev), "ray log"), "whitted with a ray log: %s: %s", sy_rt_result_str(r), sy_rt_device_error(dev));
    sy_rt_ray_log_destroy(log);
    d.ray_log = NULL;
    d.stage_times = &st;
    r = sy_rt_render(dev, &cam, &d, a, NULL);
    EXPECT_MSG(r == SY_RT_ERROR_INVALID_ARGUMENT && strstr(sy_rt_device_error(dev), "stage timers"),
               "whitted with stage timers: %s: %s", sy_rt_result_str(r), sy_rt_device_error(dev));
    sy_rt_accum_destroy(acc);
    free(a);
    free(b);
    sy_rt_device_destroy(dev);
    return sy_check_finish("test_rt_raylog");
}
