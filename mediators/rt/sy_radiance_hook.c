/* sy_radiance_hook.c — path records of the path tracer -> radiance filter (see sy_radiance_hook.h). */
#include "sy_radiance_hook.h"

#include "sy_backend_status.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

struct sy_radiance_hook {
    sy_filter_radiance_params params;
    sy_filter_radiance *rf;
    uint32_t w, h;
    sy_rt_pt_record *records;
    sy_filter_rf_shading *shading;
    sy_filter_rf_sample *samples;
    float *out;       /* w*h*4 filter output */
    float *seed_var;  /* w*h per-sample luminance variance for seeding */
    double *wmean, *wm2; /* Welford of the luminance of each pixel's plain-PT indirect estimate */
    uint32_t frames;  /* frames since the reset (Welford count) */
};

/* the codes agree (sy_mediator_rt_filter.c checks them with SY_BACKEND_SAME_CODE) */
static sy_result hook_filter_fail(sy_error *err, const sy_filter_report *fe)
{
    return sy_backend_fail(err, (int)fe->code, "pathtracer radiance filter", NULL, fe->message);
}

sy_result sy_radiance_hook_create(const sy_filter_radiance_params *p, sy_radiance_hook **out, sy_error *err)
{
    *out = NULL;
    sy_radiance_hook *h = calloc(1, sizeof *h);
    if (!h) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "pathtracer radiance filter: out of memory");
    sy_filter_report fe = {0};
    if (sy_filter_radiance_create(p, &h->rf, &fe)) {
        free(h);
        return hook_filter_fail(err, &fe);
    }
    h->params = *p;
    *out = h;
    return SY_OK;
}

static void hook_free_buffers(sy_radiance_hook *h)
{
    free(h->records), free(h->shading), free(h->samples), free(h->out), free(h->seed_var), free(h->wmean), free(h->wm2);
    h->records = NULL, h->shading = NULL, h->samples = NULL, h->out = NULL, h->seed_var = NULL;
    h->wmean = h->wm2 = NULL;
    h->w = h->h = 0;
}

void sy_radiance_hook_destroy(sy_radiance_hook *h)
{
    if (!h) return;
    hook_free_buffers(h);
    sy_filter_radiance_destroy(h->rf);
    free(h);
}

void sy_radiance_hook_reset(sy_radiance_hook *h)
{
    if (!h) return;
    sy_filter_radiance_reset(h->rf);
    h->frames = 0;
}

sy_result sy_radiance_hook_set_params(sy_radiance_hook *h, const sy_filter_radiance_params *p, sy_error *err)
{
    sy_filter_radiance *rf;
    sy_filter_report fe = {0};
    if (sy_filter_radiance_create(p, &rf, &fe)) return hook_filter_fail(err, &fe);
    sy_filter_radiance_destroy(h->rf);
    h->rf = rf;
    h->params = *p;
    h->frames = 0;
    return SY_OK;
}

sy_result sy_radiance_hook_records(sy_radiance_hook *h, uint32_t w, uint32_t hgt, sy_rt_pt_record **out, sy_error *err)
{
    if (h->w != w || h->h != hgt || !h->records) {
        hook_free_buffers(h);
        size_t n = (size_t)w * hgt;
        h->records = calloc(n, sizeof *h->records);
        h->shading = calloc(n, sizeof *h->shading);
        h->samples = calloc(n, sizeof *h->samples);
        h->out = malloc(n * 4 * sizeof *h->out);
        h->seed_var = malloc(n * sizeof *h->seed_var);
        h->wmean = malloc(n * sizeof *h->wmean);
        h->wm2 = malloc(n * sizeof *h->wm2);
        if (!h->records || !h->shading || !h->samples || !h->out || !h->seed_var || !h->wmean || !h->wm2) {
            hook_free_buffers(h);
            return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "pathtracer radiance filter: out of memory for %ux%u records",
                                w, hgt);
        }
        h->w = w, h->h = hgt;
        sy_radiance_hook_reset(h);
    }
    *out = h->records;
    return SY_OK;
}

uint32_t sy_radiance_hook_frame_index(const sy_radiance_hook *h) { return h ? h->frames : 0u; }

/* The filter's (batched) BSDF callback: the owner pixel's record evaluates the path tracer's own
 * BSDF for a batch of neighbours' directions. */
static void hook_bsdf_batch(const sy_filter_rf_shading *s, uint32_t count, const float *const wi[3],
                            float *const f_cos[3], float *pdf, void *user)
{
    const sy_radiance_hook *h = user;
    sy_rt_pt_record_bsdf_batch(h->records + (s - h->shading), count, wi, f_cos, pdf);
}

/* Seeds the filter and the Welford state from an accumulation of d->prior_samples samples. */
static sy_result hook_seed(sy_radiance_hook *h, const sy_radiance_hook_frame_desc *d, sy_error *err)
{
    size_t n = (size_t)h->w * h->h;
    double N = d->prior_samples;
    for (size_t i = 0; i < n; ++i) {
        const float *v = d->prior_variance + 3 * i, *c = d->prior_color + (size_t)d->prior_color_channels * i;
        /* luminance variance per sample, channels taken as fully correlated (an upper bound) */
        double sd = 0.2126 * sqrt(fmax(v[0], 0.0)) + 0.7152 * sqrt(fmax(v[1], 0.0)) + 0.0722 * sqrt(fmax(v[2], 0.0));
        double var = sd * sd * N;
        h->seed_var[i] = (float)var;
        double ind = sy_filter_luminance(c);
        if (d->prior_direct) ind -= sy_filter_luminance(d->prior_direct + 3 * i);
        h->wmean[i] = ind;
        h->wm2[i] = N > 1 ? var * (N - 1) : 0.0;
    }
    sy_filter_report fe = {0};
    if (sy_filter_radiance_seed(h->rf, h->w, h->h, d->prior_color, d->prior_color_channels, h->seed_var,
                                d->prior_samples, &fe))
        return hook_filter_fail(err, &fe);
    h->frames = d->prior_samples;
    return SY_OK;
}

static void copy3(float *dst, const float *src) { dst[0] = src[0], dst[1] = src[1], dst[2] = src[2]; }

sy_result sy_radiance_hook_frame(sy_radiance_hook *h, const sy_radiance_hook_frame_desc *d, float *rgba,
                                 sy_filter_stats *stats, sy_error *err)
{
    if (!h->records) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "pathtracer radiance filter: no records");
    if (h->frames == 0 && d->prior_samples > 0 && d->prior_color && d->prior_variance) {
        sy_result r = hook_seed(h, d, err);
        if (r != SY_OK) return r;
    }
    size_t n = (size_t)h->w * h->h;
    double k = (double)h->frames + 1.0;
    for (size_t i = 0; i < n; ++i) {
        const sy_rt_pt_record *r = h->records + i;
        sy_filter_rf_shading *sh = h->shading + i;
        sy_filter_rf_sample *sm = h->samples + i;
        memset(sh, 0, sizeof *sh);
        memset(sm, 0, sizeof *sm);
        copy3(sh->direct, r->prefix);
        float ind[3] = {0.0f, 0.0f, 0.0f};
        bool p0 = (r->flags & SY_RT_RECORD_P0) != 0;
        if (p0) {
            for (int c = 0; c < 3; ++c) ind[c] = r->color[c] - r->prefix[c];
            copy3(sh->position, r->position), copy3(sh->normal, r->normal), copy3(sh->wo, r->wo);
            copy3(sh->ray_dir, r->ray_dir), copy3(sh->throughput, r->throughput), copy3(sh->pt_indirect, ind);
            sh->path_length = d->orthographic ? 1.0f : r->path_length;
            sh->exponent = r->glossy_exponent;
            sh->flags = SY_FILTER_RF_VALID;
            copy3(sm->position, r->position), copy3(sm->normal, r->normal), copy3(sm->wi, r->wi);
            copy3(sm->radiance, r->incident);
            sm->hit_distance = r->hit_distance;
            sm->flags = SY_FILTER_RF_VALID;
        }
        /* running variance of the plain-PT indirect estimate (a frame without P0 counts as 0);
         * a non-finite estimate is left out (the filter counts and isolates that pixel) */
        double x = sy_filter_luminance(ind);
        if (h->frames == 0) h->wmean[i] = 0.0, h->wm2[i] = 0.0;
        if (isfinite(x)) {
            double dl = x - h->wmean[i];
            if (h->frames == 0) h->wmean[i] = x, h->wm2[i] = 0.0;
            else h->wmean[i] += dl / k, h->wm2[i] += dl * (x - h->wmean[i]);
        }
        sh->variance = k > 1.0 ? (float)(h->wm2[i] / (k - 1.0)) : 0.0f;
    }
    h->frames++;
    sy_filter_radiance_input in = {.width = h->w,
                                   .height = h->h,
                                   .pixel_angle = d->pixel_angle,
                                   .shading = h->shading,
                                   .samples = h->samples,
                                   .bsdf_batch = hook_bsdf_batch,
                                   .bsdf_user = h};
    sy_filter_report fe = {0};
    if (sy_filter_radiance_frame(h->rf, &in, h->out, stats, &fe)) {
        sy_radiance_hook_reset(h);
        return hook_filter_fail(err, &fe);
    }
    if (rgba)
        for (size_t i = 0; i < n; ++i) copy3(rgba + 4 * i, h->out + 4 * i);
    return SY_OK;
}
