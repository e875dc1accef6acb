/* sy_filter.c — shared parts of the filter back-end: errors, parameter validation, frame checks,
 * NaN/Inf scan and the row-parallel pthread helper (see sy_filter.h). */
#include "sy_filter.h"

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

const char *sy_filter_status_name(sy_filter_status s)
{
    switch (s) {
    case SY_FILTER_OK: return "ok";
    case SY_FILTER_ERROR_INVALID_ARGUMENT: return "invalid argument";
    case SY_FILTER_ERROR_OUT_OF_MEMORY: return "out of memory";
    case SY_FILTER_ERROR_THREADS: return "thread creation failed";
    }
    return "unknown";
}

sy_filter_status sy_filter_fail(sy_filter_error *err, sy_filter_status status, const char *fmt, ...)
{
    if (err) {
        err->status = status;
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err->message, sizeof err->message, fmt, ap);
        va_end(ap);
    }
    return status;
}

sy_filter_status sy_filter_check_positive(float v, const char *what, sy_filter_error *err)
{
    if (!isfinite(v) || !(v > 0.0f))
        return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "%s = %g: must be a finite value > 0", what,
                              (double)v);
    return SY_FILTER_OK;
}

sy_filter_status sy_filter_check_nonnegative(float v, const char *what, sy_filter_error *err)
{
    if (!isfinite(v) || v < 0.0f)
        return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "%s = %g: must be a finite value >= 0", what,
                              (double)v);
    return SY_FILTER_OK;
}

sy_filter_status sy_filter_check_range(float v, float lo, float hi, const char *what, sy_filter_error *err)
{
    if (!isfinite(v) || v < lo || v > hi)
        return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "%s = %g: must lie in [%g, %g]", what,
                              (double)v, (double)lo, (double)hi);
    return SY_FILTER_OK;
}

sy_filter_status sy_filter_check_frame(const sy_filter_frame *f, uint32_t need, const char *filter,
                                       sy_filter_error *err)
{
    if (!f) return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "%s: frame is NULL", filter);
    if (f->width == 0 || f->height == 0 || f->width > SY_FILTER_MAX_SIDE || f->height > SY_FILTER_MAX_SIDE)
        return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "%s: image size %ux%u outside 1..%u", filter,
                              f->width, f->height, SY_FILTER_MAX_SIDE);
    static const struct {
        uint32_t bit;
        const char *name;
    } names[] = {{SY_FILTER_NEED_COLOR, "color"},   {SY_FILTER_NEED_VARIANCE, "variance"},
                 {SY_FILTER_NEED_ALBEDO, "albedo"}, {SY_FILTER_NEED_NORMAL, "normal"},
                 {SY_FILTER_NEED_DEPTH, "depth"},   {SY_FILTER_NEED_POSITION, "position"}};
    const float *bufs[] = {f->color, f->variance, f->albedo, f->normal, f->depth, f->position};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; ++i)
        if ((need & names[i].bit) && !bufs[i])
            return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "%s: the %s buffer is required but NULL",
                                  filter, names[i].name);
    if ((need & SY_FILTER_NEED_SPLIT) && (!f->direct || !f->indirect))
        return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT,
                              "%s: the direct and indirect buffers are required but NULL", filter);
    if ((need & SY_FILTER_NEED_COLOR) && f->color_channels != 3 && f->color_channels != 4)
        return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "%s: color_channels = %u: must be 3 or 4",
                              filter, f->color_channels);
    if ((need & SY_FILTER_NEED_VARIANCE) && f->variance_channels != 1 && f->variance_channels != 3)
        return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "%s: variance_channels = %u: must be 1 or 3",
                              filter, f->variance_channels);
    if (!f->spp && (!isfinite(f->spp_uniform) || f->spp_uniform < 1.0f))
        return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT,
                              "%s: no spp buffer and spp_uniform = %g: must be >= 1", filter, (double)f->spp_uniform);
    return SY_FILTER_OK;
}

static bool finite_n(const float *p, uint32_t n)
{
    for (uint32_t c = 0; c < n; ++c)
        if (!isfinite(p[c])) return false;
    return true;
}

uint64_t sy_filter_scan_finite(const sy_filter_frame *f, uint32_t need, uint8_t *mask)
{
    return sy_filter_scan_finite_rows(f, need, mask, 0, f->height);
}

uint64_t sy_filter_scan_finite_rows(const sy_filter_frame *f, uint32_t need, uint8_t *mask, uint32_t y0, uint32_t y1)
{
    uint64_t bad = 0;
    for (size_t i = (size_t)y0 * f->width; i < (size_t)y1 * f->width; ++i) {
        bool ok = true;
        if ((need & SY_FILTER_NEED_COLOR) && f->color) ok = ok && finite_n(f->color + i * f->color_channels, 3);
        if ((need & SY_FILTER_NEED_VARIANCE) && f->variance)
            ok = ok && finite_n(f->variance + i * f->variance_channels, f->variance_channels);
        if ((need & SY_FILTER_NEED_ALBEDO) && f->albedo) ok = ok && finite_n(f->albedo + i * 3, 3);
        if ((need & SY_FILTER_NEED_NORMAL) && f->normal) ok = ok && finite_n(f->normal + i * 3, 3);
        if ((need & SY_FILTER_NEED_DEPTH) && f->depth) ok = ok && !isnan(f->depth[i]) && f->depth[i] != -INFINITY;
        if ((need & SY_FILTER_NEED_POSITION) && f->position) {
            const float *p = f->position + i * 3;
            ok = ok && !isnan(p[0]) && !isnan(p[1]) && !isnan(p[2]);
        }
        if ((need & SY_FILTER_NEED_SPLIT) && f->direct && f->indirect)
            ok = ok && finite_n(f->direct + i * 3, 3) && finite_n(f->indirect + i * 3, 3);
        if (f->range) ok = ok && finite_n(f->range + i * 4, 3) && !isnan(f->range[i * 4 + 3]);
        if (f->spp) ok = ok && isfinite(f->spp[i]) && f->spp[i] >= 0.0f;
        mask[i] = ok;
        bad += !ok;
    }
    return bad;
}

float sy_filter_pixel_variance(const sy_filter_frame *f, size_t i)
{
    if (!f->variance) return 0.0f;
    if (f->variance_channels == 1) return f->variance[i] > 0.0f ? f->variance[i] : 0.0f;
    const float *v = f->variance + i * 3;
    float sd = 0.2126f * sqrtf(fmaxf(v[0], 0.0f)) + 0.7152f * sqrtf(fmaxf(v[1], 0.0f)) +
               0.0722f * sqrtf(fmaxf(v[2], 0.0f));
    return sd * sd;
}

float sy_filter_pixel_spp(const sy_filter_frame *f, size_t i)
{
    float n = f->spp ? f->spp[i] : f->spp_uniform;
    return n >= 1.0f ? n : 1.0f;
}

sy_filter_status sy_filter_position_from_depth(uint32_t w, uint32_t h, const float m[16], float yfov,
                                               const float *depth, float *out, sy_filter_error *err)
{
    if (w == 0 || h == 0 || w > SY_FILTER_MAX_SIDE || h > SY_FILTER_MAX_SIDE || !m || !depth || !out)
        return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "position from depth: bad size %ux%u or NULL buffer",
                              w, h);
    if (!(yfov > 0.0f) || !(yfov < 3.14159f))
        return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "position from depth: yfov = %g: must be in (0, pi)",
                              (double)yfov);
    float th = tanf(0.5f * yfov), aspect = (float)w / (float)h;
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            size_t i = (size_t)y * w + x;
            /* camera-space point at camera-axis distance d: (u d, v d, -d) */
            float u = (2.0f * ((float)x + 0.5f) / (float)w - 1.0f) * th * aspect;
            float v = (1.0f - 2.0f * ((float)y + 0.5f) / (float)h) * th;
            float d = depth[i];
            if (!(d < 1e18f)) d = 1e18f;
            float c[3] = {u * d, v * d, -d};
            for (int k = 0; k < 3; ++k) out[3 * i + k] = m[k] * c[0] + m[4 + k] * c[1] + m[8 + k] * c[2] + m[12 + k];
        }
    return SY_FILTER_OK;
}

uint32_t sy_filter_default_threads(void)
{
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    if (n < 1) n = 1;
    if (n > (long)SY_FILTER_MAX_THREADS) n = SY_FILTER_MAX_THREADS;
    return (uint32_t)n;
}

typedef struct band {
    sy_filter_rows_fn fn;
    void *ctx;
    uint32_t y0, y1;
} band;

static void *band_main(void *arg)
{
    band *b = arg;
    b->fn(b->ctx, b->y0, b->y1);
    return NULL;
}

sy_filter_status sy_filter_parallel_rows(uint32_t threads, uint32_t rows, sy_filter_rows_fn fn, void *ctx,
                                         sy_filter_error *err)
{
    if (threads == 0) threads = sy_filter_default_threads();
    if (threads > SY_FILTER_MAX_THREADS) threads = SY_FILTER_MAX_THREADS;
    if (threads > rows) threads = rows ? rows : 1;
    if (threads <= 1) {
        if (rows) fn(ctx, 0, rows);
        return SY_FILTER_OK;
    }
    band bands[SY_FILTER_MAX_THREADS];
    pthread_t tids[SY_FILTER_MAX_THREADS];
    bool started[SY_FILTER_MAX_THREADS] = {0};
    for (uint32_t t = 0; t < threads; ++t)
        bands[t] = (band){fn, ctx, (uint32_t)((uint64_t)rows * t / threads), (uint32_t)((uint64_t)rows * (t + 1) / threads)};
    bool failed = false;
    for (uint32_t t = 1; t < threads; ++t) {
        if (pthread_create(&tids[t], NULL, band_main, &bands[t]) == 0)
            started[t] = true;
        else
            band_main(&bands[t]), failed = true; /* run it here: the result is still complete */
    }
    band_main(&bands[0]);
    for (uint32_t t = 1; t < threads; ++t)
        if (started[t]) pthread_join(tids[t], NULL);
    (void)failed; /* degraded to fewer threads, never an incomplete image */
    (void)err;
    return SY_FILTER_OK;
}

/* ---- persistent worker pool ---------------------------------------------------------------- */

struct sy_filter_pool {
    pthread_mutex_t mu;
    pthread_cond_t go, done;
    uint32_t threads;  /* asked for (including the caller) */
    uint32_t started;  /* workers actually running */
    uint64_t gen;      /* bumped per job */
    uint32_t busy;     /* workers still in the current job */
    bool quit;
    sy_filter_rows_fn fn;
    void *ctx;
    uint32_t rows, chunk;
    atomic_uint next; /* next unclaimed row */
    pthread_t tids[SY_FILTER_MAX_THREADS];
};

static void pool_work(sy_filter_pool *p)
{
    for (;;) {
        uint32_t y0 = atomic_fetch_add(&p->next, p->chunk);
        if (y0 >= p->rows) return;
        uint32_t y1 = p->rows - y0 < p->chunk ? p->rows : y0 + p->chunk;
        p->fn(p->ctx, y0, y1);
    }
}

static void *pool_main(void *arg)
{
    sy_filter_pool *p = arg;
    uint64_t seen = 0;
    pthread_mutex_lock(&p->mu);
    for (;;) {
        while (!p->quit && p->gen == seen) pthread_cond_wait(&p->go, &p->mu);
        if (p->quit) break;
        seen = p->gen;
        pthread_mutex_unlock(&p->mu);
        pool_work(p);
        pthread_mutex_lock(&p->mu);
        if (--p->busy == 0) pthread_cond_signal(&p->done);
    }
    pthread_mutex_unlock(&p->mu);
    return NULL;
}

sy_filter_status sy_filter_pool_create(uint32_t threads, sy_filter_pool **out, sy_filter_error *err)
{
    if (!out) return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "worker pool: out is NULL");
    *out = NULL;
    if (threads == 0) threads = sy_filter_default_threads();
    if (threads > SY_FILTER_MAX_THREADS)
        return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "worker pool: threads = %u: at most %u", threads,
                              SY_FILTER_MAX_THREADS);
    sy_filter_pool *p = calloc(1, sizeof *p);
    if (!p) return sy_filter_fail(err, SY_FILTER_ERROR_OUT_OF_MEMORY, "worker pool: out of memory");
    if (pthread_mutex_init(&p->mu, NULL)) return free(p), sy_filter_fail(err, SY_FILTER_ERROR_THREADS, "worker pool: mutex");
    if (pthread_cond_init(&p->go, NULL)) {
        pthread_mutex_destroy(&p->mu), free(p);
        return sy_filter_fail(err, SY_FILTER_ERROR_THREADS, "worker pool: condition variable");
    }
    if (pthread_cond_init(&p->done, NULL)) {
        pthread_cond_destroy(&p->go), pthread_mutex_destroy(&p->mu), free(p);
        return sy_filter_fail(err, SY_FILTER_ERROR_THREADS, "worker pool: condition variable");
    }
    p->threads = threads;
    atomic_init(&p->next, 0);
    for (uint32_t t = 1; t < threads; ++t) {
        if (pthread_create(&p->tids[p->started], NULL, pool_main, p) != 0) break; /* fewer threads, same result */
        ++p->started;
    }
    *out = p;
    return SY_FILTER_OK;
}

void sy_filter_pool_destroy(sy_filter_pool *p)
{
    if (!p) return;
    pthread_mutex_lock(&p->mu);
    p->quit = true;
    pthread_cond_broadcast(&p->go);
    pthread_mutex_unlock(&p->mu);
    for (uint32_t t = 0; t < p->started; ++t) pthread_join(p->tids[t], NULL);
    pthread_cond_destroy(&p->done), pthread_cond_destroy(&p->go), pthread_mutex_destroy(&p->mu);
    free(p);
}

uint32_t sy_filter_pool_threads(const sy_filter_pool *p) { return p ? p->threads : 0; }

void sy_filter_pool_rows(sy_filter_pool *p, uint32_t rows, sy_filter_rows_fn fn, void *ctx)
{
    if (!rows) return;
    if (!p || p->started == 0 || rows < 2) {
        fn(ctx, 0, rows);
        return;
    }
    /* about 16 chunks per thread: the phases end together even when another process takes a core
     * for a while (claiming a chunk is one atomic add) */
    uint32_t chunk = rows / (16 * (p->started + 1));
    pthread_mutex_lock(&p->mu);
    p->fn = fn, p->ctx = ctx, p->rows = rows, p->chunk = chunk ? chunk : 1;
    atomic_store(&p->next, 0);
    p->busy = p->started;
    ++p->gen;
    pthread_cond_broadcast(&p->go);
    pthread_mutex_unlock(&p->mu);
    pool_work(p);
    pthread_mutex_lock(&p->mu);
    while (p->busy) pthread_cond_wait(&p->done, &p->mu);
    pthread_mutex_unlock(&p->mu);
}
