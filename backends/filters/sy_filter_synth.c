/* sy_filter_synth.c — analytic progressive-render surrogate (see sy_filter_synth.h). */
#include "sy_filter_synth.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

struct sy_filter_synth {
    uint32_t w, h, spp;
    uint64_t rng;
    float *color, *var, *albedo, *normal, *depth, *position, *direct, *indirect, *ref;
    double *mean, *m2; /* Welford per channel of the per-sample colour */
    double *ind_mean, *ind_m2; /* Welford of the indirect luminance (radiance filter variance) */
    float *E;          /* incident radiance per pixel */
    sy_filter_rf_shading *sh;
    sy_filter_rf_sample *sm;
};

static double uniform01(uint64_t *s)
{
    *s ^= *s << 13, *s ^= *s >> 7, *s ^= *s << 17;
    return ((*s >> 11) + 0.5) * (1.0 / 9007199254740992.0);
}

void sy_filter_synth_destroy(sy_filter_synth *s)
{
    if (!s) return;
    free(s->color), free(s->var), free(s->albedo), free(s->normal), free(s->depth), free(s->position);
    free(s->direct), free(s->indirect), free(s->ref), free(s->mean), free(s->m2), free(s->ind_mean);
    free(s->ind_m2), free(s->E), free(s->sh), free(s->sm);
    free(s);
}

sy_filter_status sy_filter_synth_create(uint32_t w, uint32_t h, uint64_t seed, sy_filter_synth **out,
                                        sy_filter_report *err)
{
    if (!out) return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "synth: out is NULL");
    *out = NULL;
    if (w == 0 || h == 0 || w > 8192 || h > 8192)
        return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "synth: size %ux%u outside 1..8192", w, h);
    sy_filter_synth *s = calloc(1, sizeof *s);
    if (!s) return sy_filter_fail(err, SY_FILTER_ERROR_OUT_OF_MEMORY, "synth: out of memory");
    size_t n = (size_t)w * h;
    s->w = w, s->h = h, s->rng = seed ? seed : 0x9e3779b97f4a7c15ull;
    s->color = malloc(4 * n * sizeof(float)), s->var = malloc(3 * n * sizeof(float));
    s->albedo = malloc(3 * n * sizeof(float)), s->normal = malloc(3 * n * sizeof(float));
    s->depth = malloc(n * sizeof(float)), s->position = malloc(3 * n * sizeof(float));
    s->direct = malloc(3 * n * sizeof(float)), s->indirect = malloc(3 * n * sizeof(float));
    s->ref = malloc(4 * n * sizeof(float)), s->mean = malloc(3 * n * sizeof(double)), s->m2 = malloc(3 * n * sizeof(double));
    s->ind_mean = malloc(n * sizeof(double)), s->ind_m2 = malloc(n * sizeof(double)), s->E = malloc(n * sizeof(float));
    s->sh = calloc(n, sizeof *s->sh), s->sm = calloc(n, sizeof *s->sm);
    if (!s->color || !s->var || !s->albedo || !s->normal || !s->depth || !s->position || !s->direct || !s->indirect ||
        !s->ref || !s->mean || !s->m2 || !s->ind_mean || !s->ind_m2 || !s->E || !s->sh || !s->sm) {
        sy_filter_synth_destroy(s);
        return sy_filter_fail(err, SY_FILTER_ERROR_OUT_OF_MEMORY, "synth: out of memory for %ux%u", w, h);
    }
    float pa = 1.0f / (float)h; /* vertical field of view ~ 53 degrees */
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            size_t i = (size_t)y * w + x;
            float u = ((float)x + 0.5f) / (float)w, v = ((float)y + 0.5f) / (float)h;
            bool right = u >= 0.5f;
            float d = right ? 6.0f : 2.5f;
            float dir[3] = {((float)x + 0.5f - (float)w / 2) * pa, ((float)h / 2 - (float)y - 0.5f) * pa, -1.0f};
            float dl = sqrtf(dir[0] * dir[0] + dir[1] * dir[1] + 1.0f);
            int cs = (int)(h / 12 > 4 ? h / 12 : 4);
            bool check = v < 0.6f && (((x / cs) + (y / cs)) & 1);
            float a[3] = {0.75f, 0.72f, 0.68f};
            if (check) a[0] = 0.8f, a[1] = 0.25f, a[2] = 0.15f;
            if (right) a[0] *= 0.5f, a[2] = 0.75f;
            /* smooth indirect light with a sharp shadow boundary the range buffer does not see */
            float E = 0.6f + 0.35f * sinf(6.0f * u) * cosf(5.0f * v);
            if (!right && v > 0.7f && u > 0.15f && u < 0.35f) E *= 0.3f;
            if (right) E *= 0.45f;
            s->E[i] = E;
            sy_filter_rf_shading *sh = s->sh + i;
            for (int c = 0; c < 3; ++c) {
                s->albedo[3 * i + c] = a[c];
                s->direct[3 * i + c] = a[c] * (right ? 0.15f : 0.35f) * (v < 0.5f ? 1.0f : 0.8f);
                s->ref[4 * i + c] = s->direct[3 * i + c] + a[c] * E;
                s->position[3 * i + c] = dir[c] * d;
                sh->position[c] = dir[c] * d;
                sh->ray_dir[c] = dir[c] / dl;
                sh->wo[c] = -dir[c] / dl;
                sh->throughput[c] = 1.0f;
                sh->diffuse[c] = a[c];
                sh->direct[c] = s->direct[3 * i + c];
            }
            s->ref[4 * i + 3] = 1.0f;
            s->normal[3 * i + 0] = 0.0f, s->normal[3 * i + 1] = 0.0f, s->normal[3 * i + 2] = 1.0f;
            sh->normal[2] = 1.0f;
            s->depth[i] = d; /* camera-axis distance */
            sh->path_length = d * dl;
            sh->flags = SY_FILTER_RF_VALID;
        }
    *out = s;
    sy_filter_synth_reset(s);
    return SY_FILTER_OK;
}

void sy_filter_synth_reset(sy_filter_synth *s)
{
    size_t n = (size_t)s->w * s->h;
    s->spp = 0;
    memset(s->mean, 0, 3 * n * sizeof(double));
    memset(s->m2, 0, 3 * n * sizeof(double));
    memset(s->ind_mean, 0, n * sizeof(double));
    memset(s->ind_m2, 0, n * sizeof(double));
    memset(s->color, 0, 4 * n * sizeof(float));
    memset(s->var, 0, 3 * n * sizeof(float));
    memset(s->indirect, 0, 3 * n * sizeof(float));
}

void sy_filter_synth_step(sy_filter_synth *s)
{
    size_t n = (size_t)s->w * s->h;
    uint32_t k = ++s->spp;
    for (size_t i = 0; i < n; ++i) {
        double u1 = uniform01(&s->rng), u2 = uniform01(&s->rng), r = sqrt(u1);
        double X = -log(uniform01(&s->rng)); /* Exp(1) */
        sy_filter_rf_shading *sh = s->sh + i;
        sy_filter_rf_sample *sm = s->sm + i;
        float L = (float)(s->E[i] * X);
        memcpy(sm->position, sh->position, sizeof sm->position);
        memcpy(sm->normal, sh->normal, sizeof sm->normal);
        sm->wi[0] = (float)(r * cos(6.283185307179586 * u2)), sm->wi[1] = (float)(r * sin(6.283185307179586 * u2));
        sm->wi[2] = (float)sqrt(1.0 - u1);
        sm->radiance[0] = sm->radiance[1] = sm->radiance[2] = L;
        sm->hit_distance = INFINITY;
        sm->flags = SY_FILTER_RF_VALID;
        double lum_ind = 0;
        for (int c = 0; c < 3; ++c) {
            float ind = s->albedo[3 * i + c] * L; /* Lambert + cosine sampling: f cos / p = albedo */
            sh->pt_indirect[c] = ind;
            double smp = (double)s->direct[3 * i + c] + ind;
            double dlt = smp - s->mean[3 * i + c];
            s->mean[3 * i + c] += dlt / k;
            s->m2[3 * i + c] += dlt * (smp - s->mean[3 * i + c]);
            s->color[4 * i + c] = (float)s->mean[3 * i + c];
            s->indirect[3 * i + c] = (float)(s->mean[3 * i + c] - s->direct[3 * i + c]);
            s->var[3 * i + c] = k > 1 ? (float)(s->m2[3 * i + c] / (k - 1) / k) : 0.0f;
        }
        lum_ind = 0.2126 * sh->pt_indirect[0] + 0.7152 * sh->pt_indirect[1] + 0.0722 * sh->pt_indirect[2];
        double dl = lum_ind - s->ind_mean[i];
        s->ind_mean[i] += dl / k;
        s->ind_m2[i] += dl * (lum_ind - s->ind_mean[i]);
        sh->variance = k > 1 ? (float)(s->ind_m2[i] / (k - 1)) : 0.0f;
        s->color[4 * i + 3] = 1.0f;
    }
}

uint32_t sy_filter_synth_spp(const sy_filter_synth *s) { return s->spp; }

sy_filter_frame sy_filter_synth_frame(const sy_filter_synth *s)
{
    return (sy_filter_frame){.width = s->w, .height = s->h, .color_channels = 4, .variance_channels = 3,
                             .color = s->color, .variance = s->var, .albedo = s->albedo, .normal = s->normal,
                             .depth = s->depth, .position = s->position, .direct = s->direct,
                             .indirect = s->indirect, .spp_uniform = s->spp ? (float)s->spp : 1.0f,
                             .has_camera = true, .camera_position = {0.0f, 0.0f, 0.0f}};
}

sy_filter_radiance_input sy_filter_synth_rf_input(const sy_filter_synth *s)
{
    return (sy_filter_radiance_input){.width = s->w, .height = s->h, .pixel_angle = 1.0f / (float)s->h,
                                      .shading = s->sh, .samples = s->sm};
}

const float *sy_filter_synth_reference(const sy_filter_synth *s) { return s->ref; }
