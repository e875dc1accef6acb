/* sy_rt_limit.c — the rays of a path-traced frame replayed with raw Embree in single, packet and
 * stream form, and the benchmark that times them against the frame (see sy_rt_limit.h). */
#include "sy_rt_limit.h"
#include "sy_rt_accum.h"

#include <omp.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define FAIL(r, ...) sy_rt_fail(dev, (r), __VA_ARGS__)

/* Rays per unit of work handed to a thread (and per rtcIntersect1M call): a multiple of 16. */
#define RUN 64u

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

/* >>replay */
const char *sy_rt_ray_form_name(sy_rt_ray_form form)
{
    static const char *const names[SY_RT_FORM_COUNT] = {"rtcIntersect1 / rtcOccluded1", "rtcIntersect4 / rtcOccluded4",
                                                         "rtcIntersect8 / rtcOccluded8", "rtcIntersect16 / rtcOccluded16",
                                                         "rtcIntersect1M / rtcOccluded1M"};
    return (unsigned)form < SY_RT_FORM_COUNT ? names[form] : "?";
}

bool sy_rt_ray_form_native(const sy_rt_device *dev, sy_rt_ray_form form)
{
    switch (form) {
    case SY_RT_FORM_4: return rtcGetDeviceProperty(dev->rtc, RTC_DEVICE_PROPERTY_NATIVE_RAY4_SUPPORTED) != 0;
    case SY_RT_FORM_8: return rtcGetDeviceProperty(dev->rtc, RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED) != 0;
    case SY_RT_FORM_16: return rtcGetDeviceProperty(dev->rtc, RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED) != 0;
    default: return true;
    }
}

static const uint32_t form_width[SY_RT_FORM_COUNT] = {1u, 4u, 8u, 16u, 1u};

/* The SoA packets are filled by offset (soa_ray, soa_hit_reset): 12 ray fields then the hit. */
_Static_assert(offsetof(struct RTCRayHit4, hit) == 12u * 4u * sizeof(float), "RTCRayHit4 layout");
_Static_assert(offsetof(struct RTCRayHit8, hit) == 12u * 8u * sizeof(float), "RTCRayHit8 layout");
_Static_assert(offsetof(struct RTCRayHit16, hit) == 12u * 16u * sizeof(float), "RTCRayHit16 layout");
_Static_assert(offsetof(struct RTCRay16, tfar) == 8u * 16u * sizeof(float), "RTCRay16 layout");
_Static_assert(offsetof(struct RTCHit16, geomID) == 6u * 16u * sizeof(float), "RTCHit16 layout");

/* Bytes of one prepared closest-hit / occlusion element of a form (a ray or a packet). */
static size_t hit_size(sy_rt_ray_form f)
{
    switch (f) {
    case SY_RT_FORM_4: return sizeof(struct RTCRayHit4);
    case SY_RT_FORM_8: return sizeof(struct RTCRayHit8);
    case SY_RT_FORM_16: return sizeof(struct RTCRayHit16);
    default: return sizeof(struct RTCRayHit);
    }
}
static size_t ray_size(sy_rt_ray_form f)
{
    switch (f) {
    case SY_RT_FORM_4: return sizeof(struct RTCRay4);
    case SY_RT_FORM_8: return sizeof(struct RTCRay8);
    case SY_RT_FORM_16: return sizeof(struct RTCRay16);
    default: return sizeof(struct RTCRay);
    }
}

struct sy_rt_ray_replay {
    const sy_rt_device *dev;
    const sy_rt_ray_log *log;
    sy_rt_ray_form form;
    void *hits, *rays; /* prepared elements, 64-byte aligned */
    size_t hit_elems, ray_elems;
};

/* Writes ray r into lane k of an SoA packet of width N (the RTCRayN layout: each field an array
 * of N floats/uints, in the order of struct RTCRay). */
static void soa_ray(float *base, uint32_t N, uint32_t k, const sy_rt_logged_ray *r)
{
    const float v[9] = {r->org[0], r->org[1], r->org[2], r->tnear, r->dir[0], r->dir[1], r->dir[2], 0.0f, r->tfar};
    for (int i = 0; i < 9; ++i) base[i * N + k] = v[i];
    uint32_t *u = (uint32_t *)(base + 9 * N);
    u[0 * N + k] = r->mask, u[1 * N + k] = 0, u[2 * N + k] = r->flags;
}
/* The hit part of an SoA packet (struct RTCHitN: Ng_x, Ng_y, Ng_z, u, v, primID, geomID, instID[0]). */
static void soa_hit_reset(float *base, uint32_t N, uint32_t k)
{
    uint32_t *u = (uint32_t *)base;
    u[6 * N + k] = RTC_INVALID_GEOMETRY_ID, u[7 * N + k] = RTC_INVALID_GEOMETRY_ID;
}

static void aos_ray(struct RTCRay *o, const sy_rt_logged_ray *r)
{
    o->org_x = r->org[0], o->org_y = r->org[1], o->org_z = r->org[2], o->tnear = r->tnear;
    o->dir_x = r->dir[0], o->dir_y = r->dir[1], o->dir_z = r->dir[2], o->time = 0.0f;
    o->tfar = r->tfar, o->mask = r->mask, o->id = 0, o->flags = r->flags;
}

static void *prepare(const sy_rt_ray_buf *b, sy_rt_ray_form form, bool hits, size_t *elems)
{
    uint32_t N = form_width[form];
    size_t n = (b->n + N - 1u) / N, sz = hits ? hit_size(form) : ray_size(form);
    *elems = n;
    if (n > SIZE_MAX / sz - 1u) return NULL;
    size_t bytes = (n * sz + 63u) & ~(size_t)63u;
    void *mem = aligned_alloc(64, bytes ? bytes : 64u);
    if (!mem) return NULL;
    memset(mem, 0, bytes);
    for (size_t i = 0; i < b->n; ++i) {
        const sy_rt_logged_ray *r = &b->v[i];
        if (N == 1u) {
            if (hits) {
                struct RTCRayHit *h = (struct RTCRayHit *)mem + i;
                aos_ray(&h->ray, r);
                h->hit.geomID = h->hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
            } else {
                aos_ray((struct RTCRay *)mem + i, r);
            }
        } else {
            float *p = (float *)((char *)mem + (i / N) * sz);
            uint32_t k = (uint32_t)(i % N);
            soa_ray(p, N, k, r);
            if (hits) soa_hit_reset(p + 12u * N, N, k);
        }
    }
    return mem;
}

sy_rt_result sy_rt_ray_replay_create(const sy_rt_device *dev, const sy_rt_ray_log *log, sy_rt_ray_form form,
                                     sy_rt_ray_replay **out)
{
    if (!dev || !log || !out || (unsigned)form >= SY_RT_FORM_COUNT)
        return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "ray replay: NULL argument or unknown form");
    sy_rt_ray_replay *rp = calloc(1, sizeof *rp);
    if (!rp) return FAIL(SY_RT_ERROR_OUT_OF_MEMORY, "ray replay: out of memory");
    rp->dev = dev;
    rp->log = log;
    rp->form = form;
    rp->hits = prepare(&log->intersect, form, true, &rp->hit_elems);
    rp->rays = rp->hits ? prepare(&log->occluded, form, false, &rp->ray_elems) : NULL;
    if (!rp->rays) {
        sy_rt_ray_replay_destroy(rp);
        return FAIL(SY_RT_ERROR_OUT_OF_MEMORY, "ray replay: cannot prepare %zu + %zu rays as %s", log->intersect.n,
                    log->occluded.n, sy_rt_ray_form_name(form));
    }
    *out = rp;
    return SY_RT_OK;
}

void sy_rt_ray_replay_destroy(sy_rt_ray_replay *rp)
{
    if (!rp) return;
    free(rp->hits);
    free(rp->rays);
    free(rp);
}

/* What a run of either query needs: where it ends (RUN rays from first, or the log's end), the
 * back-end's own context (its alpha filters read it), the scene as it renders when no instance
 * moved since the last full build (the bench builds its scene once), and the packet width. */
typedef struct run_setup {
    size_t end;
    sy_rt_ictx ictx;
    RTCScene scene;
    uint32_t N;
} run_setup;

static void run_begin(const sy_rt_ray_replay *rp, const sy_rt_ray_buf *b, size_t first, run_setup *rs)
{
    rs->end = first + RUN < b->n ? first + RUN : b->n;
    sy_rt_context_init(rp->dev, &rs->ictx, RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT);
    rs->scene = rp->dev->top;
    rs->N = form_width[rp->form];
}

/* Packet p of N lanes (of sz bytes in the form's layout) from base into local; lanes [0, count)
 * valid in the mask, the rest off. Returns count. */
static uint32_t packet_load(const void *base, size_t sz, size_t p, uint32_t N, size_t end, int *valid,
                            unsigned char *local)
{
    uint32_t count = (uint32_t)(end - p * N < N ? end - p * N : N);
    for (uint32_t k = 0; k < N; ++k) valid[k] = k < count ? -1 : 0;
    memcpy(local, (const char *)base + p * sz, sz);
    return count;
}

/* Whether logged ray r's answer in the replay differs from the log: for a closest-hit query its
 * geometry, and on a hit its primitive and instance; for an occlusion query (occ) whether it was
 * blocked (tfar < 0). */
static bool mismatch(bool occ, const sy_rt_logged_ray *r, uint32_t geom, uint32_t prim, uint32_t inst, float tfar)
{
    if (occ) return (tfar < 0.0f) != (r->geom != 0);
    return geom != r->geom || (geom != RTC_INVALID_GEOMETRY_ID && (prim != r->prim || inst != r->inst));
}

/* One run (RUN rays from index first) of closest-hit queries, or of occlusion queries when occ;
 * returns mismatches when check. */
static uint64_t run_queries(const sy_rt_ray_replay *rp, size_t first, bool check, bool occ)
{
    const sy_rt_ray_buf *b = occ ? &rp->log->occluded : &rp->log->intersect;
    run_setup rs;
    run_begin(rp, b, first, &rs);
    const size_t end = rs.end;
    const uint32_t N = rs.N;
    struct RTCIntersectContext *ctx = &rs.ictx.rtc;
    RTCScene scene = rs.scene;
    uint64_t bad = 0;
    if (rp->form == SY_RT_FORM_1 || rp->form == SY_RT_FORM_STREAM) {
        union {
            struct RTCRayHit hit[RUN];
            struct RTCRay ray[RUN];
        } local;
        uint32_t n = (uint32_t)(end - first);
        if (occ) memcpy(local.ray, (const struct RTCRay *)rp->rays + first, n * sizeof *local.ray);
        else memcpy(local.hit, (const struct RTCRayHit *)rp->hits + first, n * sizeof *local.hit);
        if (rp->form == SY_RT_FORM_STREAM && occ) rtcOccluded1M(scene, ctx, local.ray, n, sizeof *local.ray);
        else if (rp->form == SY_RT_FORM_STREAM) rtcIntersect1M(scene, ctx, local.hit, n, sizeof *local.hit);
        else if (occ) for (uint32_t i = 0; i < n; ++i) rtcOccluded1(scene, ctx, &local.ray[i]);
        else for (uint32_t i = 0; i < n; ++i) rtcIntersect1(scene, ctx, &local.hit[i]);
        for (uint32_t i = 0; check && i < n; ++i) {
            const struct RTCHit *h = &local.hit[i].hit;
            bad += occ ? mismatch(true, &b->v[first + i], 0, 0, 0, local.ray[i].tfar)
                       : mismatch(false, &b->v[first + i], h->geomID, h->primID, h->instID[0], 0.0f);
        }
        return bad;
    }
    size_t sz = occ ? ray_size(rp->form) : hit_size(rp->form);
    _Alignas(64) unsigned char local[sizeof(struct RTCRayHit16)]; /* the larger of the two layouts */
    for (size_t p = first / N; p * N < end; ++p) {
        _Alignas(64) int valid[16]; /* Embree loads the mask with aligned SIMD loads */
        uint32_t count = packet_load(occ ? rp->rays : rp->hits, sz, p, N, end, valid, local);
        if (occ && N == 4u) rtcOccluded4(valid, scene, ctx, (struct RTCRay4 *)local);
        else if (occ && N == 8u) rtcOccluded8(valid, scene, ctx, (struct RTCRay8 *)local);
        else if (occ) rtcOccluded16(valid, scene, ctx, (struct RTCRay16 *)local);
        else if (N == 4u) rtcIntersect4(valid, scene, ctx, (struct RTCRayHit4 *)local);
        else if (N == 8u) rtcIntersect8(valid, scene, ctx, (struct RTCRayHit8 *)local);
        else rtcIntersect16(valid, scene, ctx, (struct RTCRayHit16 *)local);
        const float *tfar = (const float *)local + 8u * N;             /* the ray's tfar (SOA) */
        const uint32_t *hit = (const uint32_t *)(local + 12u * N * sizeof(float)); /* the hit part */
        for (uint32_t k = 0; check && k < count; ++k) /* the hit part is read only for closest hits */
            bad += occ ? mismatch(true, &b->v[p * N + k], 0, 0, 0, tfar[k])
                       : mismatch(false, &b->v[p * N + k], hit[6 * N + k], hit[5 * N + k], hit[7 * N + k], 0.0f);
    }
    return bad;
}

double sy_rt_ray_replay_run(sy_rt_ray_replay *rp, uint64_t *mismatches)
{
    const bool check = mismatches != NULL;
    const long hit_runs = (long)((rp->log->intersect.n + RUN - 1u) / RUN);
    const long occ_runs = (long)((rp->log->occluded.n + RUN - 1u) / RUN);
    int threads = sy_rt_render_threads(rp->dev);
    uint64_t bad = 0;
    double t0 = now_s();
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads) if (threads > 1) reduction(+ : bad)
    for (long i = 0; i < hit_runs + occ_runs; ++i)
        bad += i < hit_runs ? run_queries(rp, (size_t)i * RUN, check, false)
                            : run_queries(rp, (size_t)(i - hit_runs) * RUN, check, true);
    double t = now_s() - t0;
    if (mismatches) *mismatches = bad;
    return t;
}

/* >>benchmark */
static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static void spread(double *v, uint32_t n, double out[3])
{
    qsort(v, n, sizeof *v, cmp_double);
    out[0] = v[0];
    out[1] = n % 2u ? v[n / 2u] : 0.5 * (v[n / 2u - 1u] + v[n / 2u]);
    out[2] = v[n - 1u];
}

sy_rt_result sy_rt_bench_limit(sy_rt_device *dev, const sy_rt_camera *camera, const sy_rt_render_desc *desc,
                               uint32_t repeats, sy_rt_limit_result *out)
{
    if (dev && camera) sy_rt_clip_begin(dev, camera);
    if (!dev || !camera || !desc || !out || !desc->accum)
        return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "bench limit: NULL argument (a PATHTRACER desc with an accum is needed)");
    if (desc->integrator != SY_RT_INTEGRATOR_PATHTRACER)
        return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "bench limit: the desc's integrator must be PATHTRACER");
    if (repeats == 0) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "bench limit: repeats must be >= 1");
    memset(out, 0, sizeof *out);
    sy_rt_render_desc d = *desc;
    d.progress = NULL;
    d.progress_user_data = NULL;
    d.records = NULL;
    d.stage_times = NULL;
    sy_rt_stage_times *st = calloc(1, sizeof *st);
    double *t_timed = calloc(repeats, sizeof *t_timed);
    uint64_t tick_sum = 0;
    double timed_sum = 0.0;
    sy_rt_ray_log *log = NULL;
    sy_rt_ray_replay *rp[SY_RT_FORM_COUNT] = {0};
    double *t = calloc((size_t)repeats * (2u * SY_RT_FORM_COUNT + 1u), sizeof *t);
    sy_rt_result r = t && st && t_timed ? sy_rt_ray_log_create(dev, &log) : FAIL(SY_RT_ERROR_OUT_OF_MEMORY, "bench limit: out of memory");
    /* the logged frame (also the warm-up) */
    if (r == SY_RT_OK) {
        d.ray_log = log;
        sy_rt_accum_reset(d.accum);
        r = sy_rt_render(dev, camera, &d, NULL, NULL);
        d.ray_log = NULL;
    }
    if (r == SY_RT_OK && (log->intersect.failed || log->occluded.failed))
        r = FAIL(SY_RT_ERROR_OUT_OF_MEMORY, "bench limit: out of memory logging the frame's rays (fewer samples?)");
    if (r == SY_RT_OK) {
        out->rays = log->intersect.n + log->occluded.n;
        if (out->rays != sy_rt_accum_last_rays(d.accum))
            r = FAIL(SY_RT_ERROR_INVALID_OPERATION, "bench limit: %llu rays logged but the frame counted %llu",
                     (unsigned long long)out->rays, (unsigned long long)sy_rt_accum_last_rays(d.accum));
    }
    for (int f = 0; r == SY_RT_OK && f < SY_RT_FORM_COUNT; ++f) {
        r = sy_rt_ray_replay_create(dev, log, (sy_rt_ray_form)f, &rp[f]);
        if (r == SY_RT_OK) sy_rt_ray_replay_run(rp[f], &out->mismatches[f]); /* checked, also the warm-up */
        out->native[f] = sy_rt_ray_form_native(dev, (sy_rt_ray_form)f);
    }
    /* interleaved: frame, then every form, per repeat */
    for (uint32_t i = 0; r == SY_RT_OK && i < repeats; ++i) {
        sy_rt_accum_reset(d.accum);
        double t0 = now_s();
        r = sy_rt_render(dev, camera, &d, NULL, NULL);
        t[i] = now_s() - t0;
        for (int f = 0; r == SY_RT_OK && f < SY_RT_FORM_COUNT; ++f)
            t[(size_t)(f + 1) * repeats + i] = sy_rt_ray_replay_run(rp[f], NULL);
        /* the frame again with the stage timers (its time only says what they cost) */
        if (r != SY_RT_OK) break;
        sy_rt_accum_reset(d.accum);
        d.stage_times = st;
        uint64_t k0 = sy_rt_stage_tick();
        t0 = now_s();
        r = sy_rt_render(dev, camera, &d, NULL, NULL);
        t_timed[i] = now_s() - t0;
        tick_sum += sy_rt_stage_tick() - k0;
        timed_sum += t_timed[i];
        d.stage_times = NULL;
    }
    if (r == SY_RT_OK) {
        out->width = d.width;
        out->height = d.height;
        out->samples = d.samples ? d.samples : 1u;
        out->repeats = repeats;
        out->threads = (uint32_t)sy_rt_render_threads(dev);
        out->extension_rays = log->kind_count[SY_RT_RAY_EXTENSION];
        out->shadow_rays = log->kind_count[SY_RT_RAY_SHADOW];
        out->intersect_queries = log->intersect.n;
        out->occluded_queries = log->occluded.n;
        double *share = t + (size_t)(SY_RT_FORM_COUNT + 1u) * repeats;
        for (int f = 0; f < SY_RT_FORM_COUNT; ++f)
            for (uint32_t i = 0; i < repeats; ++i)
                share[(size_t)f * repeats + i] = t[(size_t)(f + 1) * repeats + i] / t[i];
        for (int f = 0; f < SY_RT_FORM_COUNT; ++f) {
            spread(t + (size_t)(f + 1) * repeats, repeats, out->form_seconds[f]);
            spread(share + (size_t)f * repeats, repeats, out->share[f]);
        }
        spread(t, repeats, out->frame_seconds);
        double spread3[3];
        spread(t_timed, repeats, spread3);
        out->timed_frame_seconds = spread3[1];
        out->lap_ticks_tight = sy_rt_stage_lap_cost();
        uint64_t null_laps = atomic_load(&st->laps[SY_RT_STAGE_NULL]);
        out->lap_ticks = null_laps ? (double)atomic_load(&st->ticks[SY_RT_STAGE_NULL]) / (double)null_laps
                                   : out->lap_ticks_tight;
        out->stage_samples = atomic_load(&st->samples);
        out->stage_dropped = atomic_load(&st->dropped);
        double c[SY_RT_STAGE_COUNT], sum = 0.0, ns_per_tick = tick_sum ? timed_sum * 1e9 / (double)tick_sum : 1.0;
        for (int k = 0; k < SY_RT_STAGE_COUNT; ++k) {
            c[k] = (double)atomic_load(&st->ticks[k]) - out->lap_ticks * (double)atomic_load(&st->laps[k]);
            if (c[k] < 0.0) c[k] = 0.0;
            out->stage_laps += atomic_load(&st->laps[k]);
            sum += c[k];
        }
        for (int k = 0; k < SY_RT_STAGE_COUNT; ++k) {
            out->stage_share[k] = sum > 0.0 ? c[k] / sum : 0.0;
            out->stage_ns_per_sample[k] = out->stage_samples ? c[k] * ns_per_tick / (double)out->stage_samples : 0.0;
        }
    }
    for (int f = 0; f < SY_RT_FORM_COUNT; ++f) sy_rt_ray_replay_destroy(rp[f]);
    sy_rt_ray_log_destroy(log);
    free(t);
    free(t_timed);
    free(st);
    return r;
}
