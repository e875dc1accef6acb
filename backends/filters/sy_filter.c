/* sy_filter.c — shared parts of the filter back-end: the error report, parameter validation, frame checks,
 * NaN/Inf scan and the row-parallel helper on OpenMP's thread team (see sy_filter.h). */
#include "sy_filter.h"

#include <math.h>
#include <omp.h>
#include <stdarg.h>
#include <stdio.h>
#include <time.h>

const char *sy_filter_status_name(sy_filter_status s)
{
    switch (s) {
    case SY_FILTER_OK: return "ok";
    case SY_FILTER_ERROR_INVALID_ARGUMENT: return "invalid argument";
    case SY_FILTER_ERROR_OUT_OF_MEMORY: return "out of memory";
    }
    return "unknown";
}

sy_filter_status sy_filter_fail(sy_filter_report *err, sy_filter_status status, const char *fmt, ...)
{
    if (err) {
        err->code = status;
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err->message, sizeof err->message, fmt, ap);
        va_end(ap);
        if (err->error) err->error(err->user, status, err->message);
    }
    return status;
}

sy_filter_status sy_filter_check_positive(float v, const char *what, sy_filter_report *err)
{
    if (!isfinite(v) || !(v > 0.0f))
        return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "%s = %g: must be a finite value > 0", what,
                              (double)v);
    return SY_FILTER_OK;
}

sy_filter_status sy_filter_check_nonnegative(float v, const char *what, sy_filter_report *err)
{
    if (!isfinite(v) || v < 0.0f)
        return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "%s = %g: must be a finite value >= 0", what,
                              (double)v);
    return SY_FILTER_OK;
}

sy_filter_status sy_filter_check_range(float v, float lo, float hi, const char *what, sy_filter_report *err)
{
    if (!isfinite(v) || v < lo || v > hi)
        return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "%s = %g: must lie in [%g, %g]", what,
                              (double)v, (double)lo, (double)hi);
    return SY_FILTER_OK;
}

sy_filter_status sy_filter_check_threads(uint32_t threads, const char *filter, sy_filter_report *err)
{
    if (threads > SY_FILTER_MAX_THREADS)
        return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "%s: threads = %u: at most %u", filter, threads,
                              SY_FILTER_MAX_THREADS);
    return SY_FILTER_OK;
}

double sy_filter_clock(bool cpu)
{
    struct timespec ts;
    clock_gettime(cpu ? CLOCK_PROCESS_CPUTIME_ID : CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

sy_filter_status sy_filter_check_frame(const sy_filter_frame *f, uint32_t need, const char *filter,
                                       sy_filter_report *err)
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
                                               const float *depth, float *out, sy_filter_report *err)
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

void sy_filter_parallel_rows(uint32_t threads, uint32_t rows, sy_filter_rows_fn fn, void *ctx)
{
    if (!rows) return;
    int team = threads ? (int)(threads < SY_FILTER_MAX_THREADS ? threads : SY_FILTER_MAX_THREADS)
                       : omp_get_max_threads();
    if ((uint32_t)team > rows) team = (int)rows;
    /* about 16 chunks per thread, handed out dynamically: the phases end together even when
     * another process takes a core for a while */
    uint32_t chunk = rows / (16u * (uint32_t)team);
    if (!chunk) chunk = 1;
    const int chunks = (int)((rows + chunk - 1) / chunk);
#pragma omp parallel for schedule(dynamic, 1) num_threads(team) if (team > 1) default(none) \
    firstprivate(fn, ctx, rows, chunk, chunks)
    for (int k = 0; k < chunks; ++k) {
        uint32_t y0 = (uint32_t)k * chunk;
        fn(ctx, y0, rows - y0 < chunk ? rows : y0 + chunk);
    }
}
