/* sy_rt_accum.c — accumulation buffers and feature-buffer readback (see sy_rt.h, sy_rt_accum.h). */
#include "sy_rt_accum.h"

#include <stdlib.h>
#include <string.h>

#define FAIL(r, ...) sy_rt_fail(dev, (r), __VA_ARGS__)

sy_rt_result sy_rt_accum_create(sy_rt_device *dev, uint32_t width, uint32_t height, sy_rt_accum **out)
{
    if (!out) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "accum create: out is NULL");
    *out = NULL;
    if (width == 0 || height == 0) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "accum create: size %ux%u is empty", width, height);
    size_t n;
    if (!sy_rt_size_mul(width, height, &n) || !sy_rt_size_mul(n, SY_RT_ACC_STRIDE * sizeof(float), &n))
        return FAIL(SY_RT_ERROR_LIMIT, "accum create: %ux%u overflows size_t", width, height);
    sy_rt_accum *a = calloc(1, sizeof *a);
    float *data = calloc(1, n);
    if (!a || !data) {
        free(a);
        free(data);
        return FAIL(SY_RT_ERROR_OUT_OF_MEMORY, "accum create: cannot allocate %ux%u buffers", width, height);
    }
    a->width = width;
    a->height = height;
    a->data = data;
    atomic_init(&a->nonfinite, 0u);
    atomic_init(&a->rays, 0u);
    *out = a;
    return SY_RT_OK;
}

void sy_rt_accum_destroy(sy_rt_accum *a)
{
    if (!a) return;
    free(a->data);
    free(a);
}

void sy_rt_accum_reset(sy_rt_accum *a)
{
    if (!a) return;
    memset(a->data, 0, (size_t)a->width * a->height * SY_RT_ACC_STRIDE * sizeof(float));
    a->samples = 0;
    atomic_store(&a->nonfinite, 0u);
}

uint32_t sy_rt_accum_samples(const sy_rt_accum *a) { return a ? a->samples : 0u; }

void sy_rt_accum_size(const sy_rt_accum *a, uint32_t *w, uint32_t *h)
{
    *w = a ? a->width : 0u;
    *h = a ? a->height : 0u;
}

uint64_t sy_rt_accum_nonfinite(const sy_rt_accum *a) { return a ? (uint64_t)atomic_load(&a->nonfinite) : 0u; }

uint64_t sy_rt_accum_last_rays(const sy_rt_accum *a) { return a ? (uint64_t)atomic_load(&a->rays) : 0u; }

static bool finite3(sy_rt_v3 v) { return isfinite(v.x) && isfinite(v.y) && isfinite(v.z); }

static void mean3(float *m, sy_rt_v3 v, float inv_n)
{
    m[0] += (v.x - m[0]) * inv_n;
    m[1] += (v.y - m[1]) * inv_n;
    m[2] += (v.z - m[2]) * inv_n;
}

/* Welford's update of a channel's mean and sum of squared deviations with sample x (inv = 1 / n). */
static inline void welford(float *mean, float *m2, float x, float inv)
{
    float d = x - *mean;
    *mean += d * inv;
    *m2 += d * (x - *mean);
}

bool sy_rt_accum_add(float *r, uint32_t n, const sy_rt_pt_sample *s)
{
    sy_rt_pt_sample z = *s;
    bool ok = finite3(s->color) && finite3(s->direct) && isfinite(s->alpha) && finite3(s->albedo) && finite3(s->normal);
    if (!ok) {
        z.color = z.direct = z.albedo = z.normal = v3(0.0f, 0.0f, 0.0f);
        z.alpha = isfinite(s->alpha) ? s->alpha : 0.0f;
    }
    float inv = 1.0f / (float)n;
    /* (the channels one by one, not from a local array: GCC paired an array's first two channels
     * through the stack, and the pair's load waited for its two stores, ~20 % of this function) */
    welford(r + SY_RT_ACC_COLOR + 0, r + SY_RT_ACC_M2 + 0, z.color.x, inv);
    welford(r + SY_RT_ACC_COLOR + 1, r + SY_RT_ACC_M2 + 1, z.color.y, inv);
    welford(r + SY_RT_ACC_COLOR + 2, r + SY_RT_ACC_M2 + 2, z.color.z, inv);
    r[SY_RT_ACC_COLOR + 3] += (z.alpha - r[SY_RT_ACC_COLOR + 3]) * inv;
    mean3(r + SY_RT_ACC_ALBEDO, z.albedo, inv);
    mean3(r + SY_RT_ACC_NORMAL, z.normal, inv);
    mean3(r + SY_RT_ACC_DIRECT, z.direct, inv);
    mean3(r + SY_RT_ACC_INDIRECT, v3_sub(z.color, z.direct), inv);
    if (isfinite(z.depth)) {
        r[SY_RT_ACC_HITS] += 1.0f;
        r[SY_RT_ACC_DEPTH] += (z.depth - r[SY_RT_ACC_DEPTH]) / r[SY_RT_ACC_HITS];
    }
    return ok;
}

uint32_t sy_rt_aov_channels(sy_rt_aov aov)
{
    switch (aov) {
    case SY_RT_AOV_COLOR: return 4;
    case SY_RT_AOV_DEPTH: return 1;
    case SY_RT_AOV_VARIANCE:
    case SY_RT_AOV_ALBEDO:
    case SY_RT_AOV_NORMAL:
    case SY_RT_AOV_DIRECT:
    case SY_RT_AOV_INDIRECT: return 3;
    default: return 0;
    }
}

const char *sy_rt_aov_name(sy_rt_aov aov)
{
    static const char *names[SY_RT_AOV_COUNT] = {"color", "variance", "albedo", "normal", "depth", "direct", "indirect"};
    return (unsigned)aov < SY_RT_AOV_COUNT ? names[aov] : NULL;
}

sy_rt_result sy_rt_accum_read_rows(sy_rt_device *dev, const sy_rt_accum *a, uint32_t y0, uint32_t y1,
                                   float *const out[SY_RT_AOV_COUNT])
{
    if (!a || !out) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "accum read rows: NULL argument");
    if (y0 > y1 || y1 > a->height)
        return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "accum read rows: rows %u..%u outside 0..%u", y0, y1, a->height);
    float *col = out[SY_RT_AOV_COLOR], *var = out[SY_RT_AOV_VARIANCE], *alb = out[SY_RT_AOV_ALBEDO];
    float *nrm = out[SY_RT_AOV_NORMAL], *dep = out[SY_RT_AOV_DEPTH], *dir = out[SY_RT_AOV_DIRECT];
    float *ind = out[SY_RT_AOV_INDIRECT];
    float nn = (float)a->samples;
    bool many = a->samples > 1;
    for (size_t i = (size_t)y0 * a->width, i1 = (size_t)y1 * a->width; i < i1; ++i) {
        const float *r = a->data + i * SY_RT_ACC_STRIDE;
        if (col) memcpy(col + 4 * i, r + SY_RT_ACC_COLOR, 4 * sizeof(float));
        if (var)
            for (int k = 0; k < 3; ++k) var[3 * i + k] = many ? r[SY_RT_ACC_M2 + k] / ((nn - 1.0f) * nn) : 0.0f;
        if (alb) memcpy(alb + 3 * i, r + SY_RT_ACC_ALBEDO, 3 * sizeof(float));
        if (nrm) memcpy(nrm + 3 * i, r + SY_RT_ACC_NORMAL, 3 * sizeof(float));
        if (dep) dep[i] = r[SY_RT_ACC_HITS] > 0.0f ? r[SY_RT_ACC_DEPTH] : INFINITY;
        if (dir) memcpy(dir + 3 * i, r + SY_RT_ACC_DIRECT, 3 * sizeof(float));
        if (ind) memcpy(ind + 3 * i, r + SY_RT_ACC_INDIRECT, 3 * sizeof(float));
    }
    return SY_RT_OK;
}

sy_rt_result sy_rt_accum_read(sy_rt_device *dev, const sy_rt_accum *a, sy_rt_aov aov, float *out)
{
    if (!a || !out) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "accum read: NULL argument");
    if (!sy_rt_aov_channels(aov)) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "accum read: unknown AOV %d", (int)aov);
    float *outs[SY_RT_AOV_COUNT] = {0};
    outs[aov] = out;
    return sy_rt_accum_read_rows(dev, a, 0, a->height, outs); /* one plane of the one conversion */
}
