/* sy_filter_radiance.c — radiance filtering (Schwenk 2013 ch. 4), see sy_filter_radiance.h.
 * Section numbers refer to ../shared/notes/filters-spec.md. */
#include "sy_filter_radiance.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define PI_F 3.14159265358979f

struct sy_filter_radiance {
    sy_filter_radiance_params p;
    uint32_t w, h, k;
    float *accum;  /* 3/px running mean of the filtered estimate */
    float *ptacc;  /* 3/px running mean of plain PT (unbiased buffer) */
    float *svar;   /* 1/px smoothed variance of the last frame */
    float *svar2;  /* 1/px next */
    float *alpha;  /* 1/px AO factor of the last frame */
    float *alpha2;
    float *radius; /* 1/px kernel radius (px) of the last frame, 0 = correction phase */
    uint8_t *phase; /* 1 = correction */
    /* per-frame neighbour data, compact (SoA), filled from the inputs before the gather: */
    float *px, *py, *pz; /* sample position; NaN where the sample is invalid (prism test rejects) */
    float *wi[3], *rad[3]; /* sample direction and incident radiance, one array per component */
    float *var, *vw;     /* 1/px the neighbour's shading variance and 1; both 0 where its shading is
                            invalid (adding +0 leaves a sum unchanged: no branch in the gather) */
    double *ihd;         /* 1/px 1 / hit distance (0 for +INF), 0 where it does not count (<= 0) */
    uint8_t *hc;         /* 1/px 1 where the hit distance counts for AO (> 0), else 0 */
    uint8_t *ok;         /* 2/px sample ok [0, n), shading ok [n, 2n) */
};

void sy_filter_radiance_params_default(sy_filter_radiance_params *p)
{
    /* [GAP spec §2.4/§6.6]: no default T_u in the text; 0.01 = the pixel filter's threshold (about
     * one JND of relative noise). Warm-up: 4 frames (text: "usually 4-8") with r_w1 = 8 px (cost grows with r^2: ~200 taps). */
    *p = (sy_filter_radiance_params){.threshold = 0.01f, .warmup_frames = 4, .warmup_radius = 8.0f,
                                     .max_radius = 24.0f, .kernel = SY_FILTER_RF_EPANECHNIKOV,
                                     .ambient_occlusion = true, .prism_thickness = 0.25f, .grazing_epsilon = 0.1f,
                                     .glossy_limit = 128.0f, .specular_limit = 4096.0f, .unbiased_switch = false,
                                     .threads = 0};
}

sy_filter_status sy_filter_radiance_params_check(const sy_filter_radiance_params *p, sy_filter_report *err)
{
    sy_filter_status s;
    if (!p) return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "radiance filter: params is NULL");
    if ((s = sy_filter_check_positive(p->threshold, "radiance filter: threshold T_u", err))) return s;
    if (p->warmup_frames > 64)
        return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "radiance filter: warmup_frames = %u: at most 64",
                              p->warmup_frames);
    if ((s = sy_filter_check_positive(p->warmup_radius, "radiance filter: warmup_radius", err))) return s;
    if ((s = sy_filter_check_range(p->max_radius, 1.0f, 128.0f, "radiance filter: max_radius", err))) return s;
    if ((unsigned)p->kernel > SY_FILTER_RF_GAUSSIAN)
        return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "radiance filter: kernel = %d: unknown",
                              (int)p->kernel);
    if ((s = sy_filter_check_positive(p->prism_thickness, "radiance filter: prism_thickness", err))) return s;
    if ((s = sy_filter_check_positive(p->grazing_epsilon, "radiance filter: grazing_epsilon", err))) return s;
    if ((s = sy_filter_check_nonnegative(p->glossy_limit, "radiance filter: glossy_limit", err))) return s;
    if ((s = sy_filter_check_nonnegative(p->specular_limit, "radiance filter: specular_limit", err))) return s;
    return sy_filter_check_threads(p->threads, "radiance filter", err);
}

static inline float dot3(const float *a, const float *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* Lambert part of the default BSDF over a batch (restrict parameters: GCC vectorises this). */
static void bsdf_lambert(uint32_t count, const float *restrict wx, const float *restrict wy, const float *restrict wz,
                         float *restrict fr, float *restrict fg, float *restrict fb, float *restrict pd,
                         const float n[3], const float kq[4])
{
    const float n0 = n[0], n1 = n[1], n2 = n[2], k0 = kq[0], k1 = kq[1], k2 = kq[2], kc = kq[3];
    for (uint32_t m = 0; m < count; ++m) {
        float cn = wx[m] * n0 + wy[m] * n1 + wz[m] * n2;
        bool up = !(cn <= 0.0f);
        float r0 = k0 * cn, r1 = k1 * cn, r2 = k2 * cn, q = kc * cn / PI_F;
        fr[m] = up ? r0 : 0.0f;
        fg[m] = up ? r1 : 0.0f;
        fb[m] = up ? r2 : 0.0f;
        pd[m] = up ? q : 0.0f;
    }
}

void sy_filter_rf_bsdf_default_batch(const sy_filter_rf_shading *s, uint32_t count, const float *const wi[3],
                                     float *const f_cos[3], float *pdf, void *user)
{
    (void)user;
    const float *wx = wi[0], *wy = wi[1], *wz = wi[2];
    float *fr = f_cos[0], *fg = f_cos[1], *fb = f_cos[2], *pd = pdf;
    /* owner constants, hoisted with the same operations (and order) as the per-direction form */
    const float n0 = s->normal[0], n1 = s->normal[1], n2 = s->normal[2];
    float co = dot3(s->normal, s->wo);
    float ld = sy_filter_luminance(s->diffuse), ls = s->exponent > 0.0f ? sy_filter_luminance(s->specular) : 0.0f;
    float ps = ld + ls > 0.0f ? ls / (ld + ls) : 0.0f;
    float kd[3], ks[3], kp = ps * (s->exponent + 1.0f) / (2.0f * PI_F), kc = 1.0f - ps;
    for (int c = 0; c < 3; ++c) kd[c] = s->diffuse[c] / PI_F, ks[c] = s->specular[c] * (s->exponent + 2.0f) / (2.0f * PI_F);
    if (co <= 0.0f) {
        for (uint32_t m = 0; m < count; ++m) fr[m] = fg[m] = fb[m] = pdf[m] = 0.0f;
        return;
    }
    if (!(ps > 0.0f) && isfinite(kp) && isfinite(ks[0]) && isfinite(ks[1]) && isfinite(ks[2])) {
        /* no glossy lobe (ps = 0, finite constants): the lobe terms are exactly +-0, so skipping the
         * half vector gives the bit-identical result; branch-free, vectorisable */
        const float n[3] = {n0, n1, n2}, kq[4] = {kd[0], kd[1], kd[2], kc};
        bsdf_lambert(count, wx, wy, wz, fr, fg, fb, pd, n, kq);
        return;
    }
    for (uint32_t m = 0; m < count; ++m) {
        float w[3] = {wx[m], wy[m], wz[m]};
        float cn = dot3(s->normal, w);
        fr[m] = fg[m] = fb[m] = pd[m] = 0.0f;
        if (cn <= 0.0f) continue;
        float hv[3] = {w[0] + s->wo[0], w[1] + s->wo[1], w[2] + s->wo[2]};
        float hl = sqrtf(dot3(hv, hv));
        float nh = 0.0f, oh = 1.0f;
        if (hl > 0.0f) {
            for (int c = 0; c < 3; ++c) hv[c] /= hl;
            nh = fmaxf(dot3(s->normal, hv), 0.0f);
            oh = fmaxf(dot3(s->wo, hv), 1e-6f);
        }
        float lobe = ps > 0.0f ? powf(nh, s->exponent) : 0.0f;
        fr[m] = (kd[0] + ks[0] * lobe) * cn;
        fg[m] = (kd[1] + ks[1] * lobe) * cn;
        fb[m] = (kd[2] + ks[2] * lobe) * cn;
        pd[m] = kc * cn / PI_F + kp * lobe * nh / (4.0f * oh);
    }
}

void sy_filter_rf_bsdf_default(const sy_filter_rf_shading *s, const float wi[3], float f_cos[3], float *pdf,
                               void *user)
{
    const float *const w[3] = {wi + 0, wi + 1, wi + 2};
    float *const f[3] = {f_cos + 0, f_cos + 1, f_cos + 2};
    sy_filter_rf_bsdf_default_batch(s, 1, w, f, pdf, user);
}

static float kernel_w(sy_filter_rf_kernel k, float t2)
{
    switch (k) {
    case SY_FILTER_RF_EPANECHNIKOV: return 1.0f - t2;
    case SY_FILTER_RF_SILVERMAN: return (1.0f - t2) * (1.0f - t2);
    case SY_FILTER_RF_UNIFORM: return 1.0f;
    case SY_FILTER_RF_GAUSSIAN: return sy_filter_expneg(4.5f * t2);
    }
    return 1.0f - t2;
}

/* [GAP spec §2.4 kernel-shape compensation]: match the effective sample count (sum w)^2 / sum w^2
 * of the weighted disc to M_k ([DERIVED] factors of the notes). */
static float kernel_scale(sy_filter_rf_kernel k)
{
    switch (k) {
    case SY_FILTER_RF_EPANECHNIKOV: return 1.1547f;
    case SY_FILTER_RF_SILVERMAN: return 1.3416f;
    case SY_FILTER_RF_UNIFORM: return 1.0f;
    case SY_FILTER_RF_GAUSSIAN: return 1.52f;
    }
    return 1.0f;
}

static bool finite3(const float *v) { return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]); }

static bool shading_ok(const sy_filter_rf_shading *s)
{
    return (s->flags & SY_FILTER_RF_VALID) && finite3(s->position) && finite3(s->normal) && finite3(s->wo) &&
           finite3(s->ray_dir) && isfinite(s->path_length) && finite3(s->throughput) && finite3(s->diffuse) &&
           finite3(s->specular) && isfinite(s->exponent) && finite3(s->direct) && finite3(s->pt_indirect) &&
           isfinite(s->variance);
}

static bool sample_ok(const sy_filter_rf_sample *s)
{
    return (s->flags & SY_FILTER_RF_VALID) && finite3(s->position) && finite3(s->normal) && finite3(s->wi) &&
           finite3(s->radiance) && !isnan(s->hit_distance);
}

typedef struct rctx {
    sy_filter_radiance *rf;
    const sy_filter_radiance_input *in;
    const uint8_t *sok; /* sample finite + valid */
    const uint8_t *hok; /* shading finite + valid */
    sy_filter_rf_bsdf_fn bsdf;             /* used when bsdf_batch is NULL */
    sy_filter_rf_bsdf_batch_fn bsdf_batch;
} rctx;

/* Neighbours inside the kernel, waiting for one batched BSDF call (in gather order, so the sums
 * are formed in exactly the order of a per-neighbour loop). Structure of arrays. */
enum { RF_BATCH = 64, RF_LANES = 4 /* padding of the position arrays */ };
typedef struct rf_batch {
    uint32_t m;
    float wt[RF_BATCH];
    float wi[3][RF_BATCH], L[3][RF_BATCH], fc[3][RF_BATCH], pdf[RF_BATCH], term[3][RF_BATCH];
} rf_batch;

static void rf_flush(const rctx *c, const sy_filter_rf_shading *sh, rf_batch *b, double acc[3])
{
    uint32_t n = b->m;
    if (n == 0) return;
    if (c->bsdf_batch) {
        const float *const wi[3] = {b->wi[0], b->wi[1], b->wi[2]};
        float *const fc[3] = {b->fc[0], b->fc[1], b->fc[2]};
        c->bsdf_batch(sh, n, wi, fc, b->pdf, c->in->bsdf_user);
    } else {
        for (uint32_t m = 0; m < n; ++m) {
            float wi[3] = {b->wi[0][m], b->wi[1][m], b->wi[2][m]}, fc[3];
            c->bsdf(sh, wi, fc, b->pdf + m, c->in->bsdf_user);
            b->fc[0][m] = fc[0], b->fc[1][m] = fc[1], b->fc[2][m] = fc[2];
        }
    }
    /* Eq. 4.10 terms, branch-free (a direction the owner never samples, pdf <= 0 or a non-finite
     * f_cos, contributes nothing; adding +0 leaves the sum unchanged) */
    for (uint32_t m = 0; m < n; ++m) {
        float pdf = b->pdf[m], wt = b->wt[m], f0 = b->fc[0][m], f1 = b->fc[1][m], f2 = b->fc[2][m];
        bool ok = (pdf > 0.0f) & (fabsf(f0) <= FLT_MAX) & (fabsf(f1) <= FLT_MAX) & (fabsf(f2) <= FLT_MAX);
        float t0 = wt * f0 / pdf * b->L[0][m], t1 = wt * f1 / pdf * b->L[1][m], t2 = wt * f2 / pdf * b->L[2][m];
        b->term[0][m] = ok ? t0 : 0.0f;
        b->term[1][m] = ok ? t1 : 0.0f;
        b->term[2][m] = ok ? t2 : 0.0f;
    }
    for (uint32_t m = 0; m < n; ++m) acc[0] += b->term[0][m], acc[1] += b->term[1][m], acc[2] += b->term[2][m];
    b->m = 0;
}

/* Per-frame compact neighbour arrays (see struct sy_filter_radiance). */
static void rf_prep_rows(void *vctx, uint32_t y0, uint32_t y1)
{
    rctx *c = vctx;
    sy_filter_radiance *rf = c->rf;
    const sy_filter_radiance_input *in = c->in;
    for (size_t i = (size_t)y0 * rf->w; i < (size_t)y1 * rf->w; ++i) {
        const sy_filter_rf_sample *sm = in->samples + i;
        bool ok = c->sok[i] != 0;
        rf->px[i] = ok ? sm->position[0] : NAN;
        rf->py[i] = ok ? sm->position[1] : NAN;
        rf->pz[i] = ok ? sm->position[2] : NAN;
        for (int q = 0; q < 3; ++q) rf->wi[q][i] = sm->wi[q], rf->rad[q][i] = sm->radiance[q];
        rf->var[i] = c->hok[i] ? in->shading[i].variance : 0.0f;
        rf->vw[i] = c->hok[i] ? 1.0f : 0.0f;
        rf->hc[i] = sm->hit_distance > 0.0f;
        rf->ihd[i] = sm->hit_distance > 0.0f ? 1.0 / sm->hit_distance : 0.0;
    }
}

static void rf_rows(void *vctx, uint32_t y0, uint32_t y1)
{
    rctx *c = vctx;
    sy_filter_radiance *rf = c->rf;
    const sy_filter_radiance_params *p = &rf->p;
    const sy_filter_radiance_input *in = c->in;
    int w = (int)rf->w, h = (int)rf->h;
    float k = (float)rf->k;
    rf_batch batch;
    batch.m = 0;
    /* one window row (max_radius <= 128, rounded up to RF_LANES): squared kernel distance, 2 = outside */
    float t2row[2 * 128 + RF_LANES];
    for (int y = (int)y0; y < (int)y1; ++y)
        for (int x = 0; x < w; ++x) {
            size_t j = (size_t)y * w + x;
            const sy_filter_rf_shading *sh = in->shading + j;
            float est[3], pt[3];
            rf->svar2[j] = 0.0f;
            rf->alpha2[j] = 1.0f;
            rf->radius[j] = 0.0f;
            rf->phase[j] = 1;
            if (!c->hok[j]) { /* background or bad shading data: the low-variance part only */
                bool dok = finite3(sh->direct);
                for (int q = 0; q < 3; ++q) est[q] = pt[q] = dok ? sh->direct[q] : 0.0f;
                goto accumulate;
            }
            for (int q = 0; q < 3; ++q) pt[q] = sh->direct[q] + (c->sok[j] ? sh->pt_indirect[q] : 0.0f);
            float var = rf->k > 1 ? rf->svar[j] : fmaxf(sh->variance, 0.0f);
            /* next frame's variance: smoothed over this frame's kernel below; a pixel that gathers
             * nothing (correction phase) keeps its own current running estimate, so a variance
             * estimate that was low early on is refreshed instead of frozen */
            rf->svar2[j] = fmaxf(sh->variance, 0.0f);
            /* radius: warm-up schedule, then the variance-driven one (Eqs. 4.1, 4.2, 4.14) */
            float r;
            if (rf->k <= p->warmup_frames) {
                r = p->warmup_radius / sqrtf(k);
            } else {
                /* L_b = direct + filtered indirect: the running mean; before any accumulation this
                 * frame's own estimate */
                float lb = sy_filter_luminance(rf->k > 1 ? rf->accum + 3 * j : pt);
                float u = var / fmaxf(lb * lb, 1e-8f);
                float Mk = u / ((2.0f * k - 1.0f) * p->threshold);
                r = sqrtf(Mk / PI_F) * kernel_scale(p->kernel); /* [DERIVED] circular footprint */
            }
            if (p->ambient_occlusion) r *= rf->alpha[j];
            if (r > p->max_radius) r = p->max_radius;
            bool nofilter = (sh->flags & SY_FILTER_RF_NO_FILTER) || sh->exponent > p->specular_limit;
            if (r < 1.0f || nofilter) { /* correction phase: plain path tracing */
                memcpy(est, pt, sizeof est);
                goto accumulate;
            }
            rf->phase[j] = 0;
            rf->radius[j] = r;
            /* kernel projection, geometric construction (Eqs. 4.19-4.21) */
            const float *N0 = sh->normal, *D = sh->ray_dir, *P0 = sh->position;
            float dn = dot3(D, N0);
            float aD[3] = {D[0] - dn * N0[0], D[1] - dn * N0[1], D[2] - dn * N0[2]};
            float la = sqrtf(dot3(aD, aD));
            if (la < 1e-6f) { /* D parallel to N0: any tangent */
                float t[3] = {fabsf(N0[0]) < 0.9f ? 1.0f : 0.0f, fabsf(N0[0]) < 0.9f ? 0.0f : 1.0f, 0.0f};
                float tn = dot3(t, N0);
                aD[0] = t[0] - tn * N0[0], aD[1] = t[1] - tn * N0[1], aD[2] = t[2] - tn * N0[2];
                la = sqrtf(dot3(aD, aD));
            }
            for (int q = 0; q < 3; ++q) aD[q] /= la;
            float aS[3] = {aD[1] * N0[2] - aD[2] * N0[1], aD[2] * N0[0] - aD[0] * N0[2], aD[0] * N0[1] - aD[1] * N0[0]};
            float rS = r * in->pixel_angle * fmaxf(sh->path_length, 1e-6f);
            float rD = rS / fmaxf(p->grazing_epsilon, fabsf(dn));
            /* [GAP spec §2.6 delta]: prism half thickness = prism_thickness * r_S */
            float delta = p->prism_thickness * rS;
            float inv_rS = 1.0f / rS, inv_rD = 1.0f / rD;
            bool use_nu = sh->exponent > p->glossy_limit;
            int R = (int)ceilf(r);
            double acc[3] = {0, 0, 0}, W = 0, Wv = 0, accv = 0, inv_hd = 0;
            uint32_t nh = 0;
            int xa = x - R < 0 ? 0 : x - R, xb = x + R >= w ? w - 1 : x + R;
            const float n0 = N0[0], n1 = N0[1], n2 = N0[2], p0 = P0[0], p1 = P0[1], p2 = P0[2];
            const float a0 = aD[0], a1 = aD[1], a2 = aD[2], s0 = aS[0], s1 = aS[1], s2 = aS[2];
            const float *WX = rf->wi[0], *WY = rf->wi[1], *WZ = rf->wi[2], *LR = rf->rad[0], *LG = rf->rad[1],
                        *LB = rf->rad[2], *VAR = rf->var, *VW = rf->vw;
            const double *IHD = rf->ihd;
            const uint8_t *HC = rf->hc;
            const bool ao = p->ambient_occlusion;
            const sy_filter_rf_kernel kern = p->kernel;
            uint32_t bm = 0; /* batch fill, local while gathering */
            for (int dy = -R; dy <= R; ++dy) {
                int yy = y + dy;
                if (yy < 0 || yy >= h) continue;
                size_t row = (size_t)yy * w;
                const float *X = rf->px + row, *Y = rf->py + row, *Z = rf->pz + row;
                /* prism (tangent-plane distance) and ellipse test for the whole row: branch-free,
                 * vectorised, in groups of RF_LANES (the position arrays are padded; lanes past xb
                 * are computed and never read); invalid samples have NaN positions and fail */
                for (int g = 0; g <= xb - xa; g += RF_LANES)
                    for (int l = 0; l < RF_LANES; ++l) {
                        int xx = xa + g + l;
                        float d0 = X[xx] - p0, d1 = Y[xx] - p1, d2 = Z[xx] - p2;
                        float off = d0 * n0 + d1 * n1 + d2 * n2;
                        float u = (d0 * a0 + d1 * a1 + d2 * a2) * inv_rD, v = (d0 * s0 + d1 * s1 + d2 * s2) * inv_rS;
                        float t2 = u * u + v * v;
                        t2row[g + l] = fabsf(off) <= delta ? t2 : 2.0f;
                    }
                for (int xx = xa; xx <= xb; ++xx) {
                    float t2 = t2row[xx - xa];
                    if (!(t2 < 1.0f)) continue;
                    size_t i = row + (size_t)xx;
                    float ks = kernel_w(kern, t2);
                    accv += ks * VAR[i], Wv += ks * VW[i]; /* unmodified kernel; +0 without shading */
                    if (ao) inv_hd += IHD[i], nh += HC[i];
                    float nu = 1.0f;
                    if (use_nu) { /* Eq. 4.9 */
                        float cn = dot3(in->samples[i].normal, N0);
                        nu = cn > 0.0f ? powf(cn, sh->exponent) : 0.0f;
                    }
                    float wt = ks * nu;
                    if (wt <= 0.0f) continue;
                    W += wt;
                    batch.wt[bm] = wt;
                    batch.wi[0][bm] = WX[i], batch.wi[1][bm] = WY[i], batch.wi[2][bm] = WZ[i];
                    batch.L[0][bm] = LR[i], batch.L[1][bm] = LG[i], batch.L[2][bm] = LB[i];
                    if (++bm == RF_BATCH) batch.m = bm, rf_flush(c, sh, &batch, acc), bm = 0;
                }
            }
            batch.m = bm;
            rf_flush(c, sh, &batch, acc);
            if (Wv > 0) rf->svar2[j] = (float)(accv / Wv);
            if (p->ambient_occlusion && nh > 0) {
                /* [GAP spec §2.2 AO formula]: alpha = clamp(harmonic mean hit distance / kernel
                 * world radius, 0.25, 1), gathered in this loop and applied next frame */
                float hm = (float)((double)nh / inv_hd), a = hm / rS;
                rf->alpha2[j] = a < 0.25f ? 0.25f : a > 1.0f ? 1.0f : a;
            }
            if (W <= 0) {
                memcpy(est, pt, sizeof est);
            } else {
                /* [GAP spec §2.2 specular-chain throughput]: the filtered incident estimate is
                 * multiplied by the pixel's own chain throughput */
                for (int q = 0; q < 3; ++q) est[q] = sh->direct[q] + sh->throughput[q] * (float)(acc[q] / W);
            }
        accumulate:
            for (int q = 0; q < 3; ++q) {
                rf->accum[3 * j + q] += (est[q] - rf->accum[3 * j + q]) / k;
                rf->ptacc[3 * j + q] += (pt[q] - rf->ptacc[3 * j + q]) / k;
            }
        }
}

static void rf_free_buffers(sy_filter_radiance *rf)
{
    free(rf->accum), free(rf->ptacc), free(rf->svar), free(rf->svar2), free(rf->alpha), free(rf->alpha2);
    free(rf->radius), free(rf->phase);
    free(rf->px), free(rf->py), free(rf->pz), free(rf->var), free(rf->vw), free(rf->ihd), free(rf->hc);
    free(rf->ok);
    rf->px = rf->py = rf->pz = rf->var = rf->vw = NULL, rf->ihd = NULL, rf->hc = rf->ok = NULL;
    for (int q = 0; q < 3; ++q) free(rf->wi[q]), free(rf->rad[q]), rf->wi[q] = rf->rad[q] = NULL;
}

void sy_filter_radiance_destroy(sy_filter_radiance *rf)
{
    if (!rf) return;
    rf_free_buffers(rf);
    free(rf);
}

sy_filter_status sy_filter_radiance_create(const sy_filter_radiance_params *p, sy_filter_radiance **out,
                                           sy_filter_report *err)
{
    if (!out) return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "radiance filter: out is NULL");
    *out = NULL;
    sy_filter_radiance_params d;
    if (!p) sy_filter_radiance_params_default(&d), p = &d;
    sy_filter_status s = sy_filter_radiance_params_check(p, err);
    if (s) return s;
    sy_filter_radiance *rf = calloc(1, sizeof *rf);
    if (!rf) return sy_filter_fail(err, SY_FILTER_ERROR_OUT_OF_MEMORY, "radiance filter: out of memory");
    rf->p = *p;
    *out = rf;
    return SY_FILTER_OK;
}

void sy_filter_radiance_reset(sy_filter_radiance *rf)
{
    if (rf) rf->k = 0;
}

const float *sy_filter_radiance_radius(const sy_filter_radiance *rf) { return rf && rf->k ? rf->radius : NULL; }
uint32_t sy_filter_radiance_frame_index(const sy_filter_radiance *rf) { return rf ? rf->k : 0; }

/* (Re)allocates the per-pixel state for width x height; a size change resets (k = 0). */
static sy_filter_status rf_alloc(sy_filter_radiance *rf, uint32_t width, uint32_t height, sy_filter_report *err)
{
    if (rf->w == width && rf->h == height && rf->accum) return SY_FILTER_OK;
    size_t n = (size_t)width * height;
    rf_free_buffers(rf);
    rf->accum = malloc(3 * n * sizeof(float)), rf->ptacc = malloc(3 * n * sizeof(float));
    rf->svar = malloc(n * sizeof(float)), rf->svar2 = malloc(n * sizeof(float));
    rf->alpha = malloc(n * sizeof(float)), rf->alpha2 = malloc(n * sizeof(float));
    rf->radius = malloc(n * sizeof(float)), rf->phase = malloc(n);
    size_t np = n + RF_LANES; /* NaN padding: the row test reads whole groups of RF_LANES */
    rf->px = malloc(np * sizeof(float)), rf->py = malloc(np * sizeof(float)), rf->pz = malloc(np * sizeof(float));
    for (int q = 0; q < 3; ++q) rf->wi[q] = malloc(n * sizeof(float)), rf->rad[q] = malloc(n * sizeof(float));
    rf->var = malloc(n * sizeof(float)), rf->vw = malloc(n * sizeof(float)), rf->ihd = malloc(n * sizeof(double));
    rf->hc = malloc(n), rf->ok = malloc(2 * n);
    rf->w = rf->h = 0, rf->k = 0;
    if (!rf->accum || !rf->ptacc || !rf->svar || !rf->svar2 || !rf->alpha || !rf->alpha2 || !rf->radius || !rf->phase ||
        !rf->px || !rf->py || !rf->pz || !rf->wi[0] || !rf->wi[1] || !rf->wi[2] || !rf->rad[0] || !rf->rad[1] ||
        !rf->rad[2] || !rf->var || !rf->vw || !rf->ihd || !rf->hc ||
        !rf->ok)
        return sy_filter_fail(err, SY_FILTER_ERROR_OUT_OF_MEMORY, "radiance filter: out of memory for %ux%u", width,
                              height);
    for (size_t i = n; i < np; ++i) rf->px[i] = rf->py[i] = rf->pz[i] = NAN;
    rf->w = width, rf->h = height;
    return SY_FILTER_OK;
}

sy_filter_status sy_filter_radiance_seed(sy_filter_radiance *rf, uint32_t width, uint32_t height, const float *mean,
                                         uint32_t channels, const float *variance, uint32_t frames,
                                         sy_filter_report *err)
{
    if (!rf || !mean || !variance || frames == 0 || (channels != 3 && channels != 4))
        return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT,
                              "radiance filter: seed needs mean, variance, 3 or 4 channels and frames >= 1");
    if (width == 0 || height == 0 || width > SY_FILTER_MAX_SIDE || height > SY_FILTER_MAX_SIDE)
        return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "radiance filter: seed size %ux%u outside 1..%u",
                              width, height, SY_FILTER_MAX_SIDE);
    sy_filter_status s = rf_alloc(rf, width, height, err);
    if (s) return s;
    size_t n = (size_t)width * height;
    for (size_t i = 0; i < n; ++i) {
        for (int q = 0; q < 3; ++q) {
            float v = mean[channels * i + (size_t)q];
            rf->accum[3 * i + q] = rf->ptacc[3 * i + q] = isfinite(v) ? v : 0.0f;
        }
        rf->svar[i] = isfinite(variance[i]) && variance[i] > 0.0f ? variance[i] : 0.0f;
        rf->alpha[i] = 1.0f, rf->radius[i] = 0.0f, rf->phase[i] = 1;
    }
    rf->k = frames;
    return SY_FILTER_OK;
}

sy_filter_status sy_filter_radiance_frame(sy_filter_radiance *rf, const sy_filter_radiance_input *in, float *out,
                                          sy_filter_stats *stats, sy_filter_report *err)
{
    double t0 = sy_filter_clock(false);
    if (!rf || !in || !out) return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "radiance filter: NULL argument");
    if (in->width == 0 || in->height == 0 || in->width > SY_FILTER_MAX_SIDE || in->height > SY_FILTER_MAX_SIDE)
        return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "radiance filter: image size %ux%u outside 1..%u",
                              in->width, in->height, SY_FILTER_MAX_SIDE);
    if (!in->shading || !in->samples)
        return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "radiance filter: shading or samples buffer is NULL");
    sy_filter_status s = sy_filter_check_positive(in->pixel_angle, "radiance filter: pixel_angle", err);
    if (s) return s;
    size_t n = (size_t)in->width * in->height;
    if ((s = rf_alloc(rf, in->width, in->height, err))) return s;
    if (rf->k == 0) {
        memset(rf->accum, 0, 3 * n * sizeof(float));
        memset(rf->ptacc, 0, 3 * n * sizeof(float));
        for (size_t i = 0; i < n; ++i) rf->svar[i] = 0.0f, rf->alpha[i] = 1.0f;
    }
    uint8_t *ok = rf->ok;
    uint64_t bad = 0;
    for (size_t i = 0; i < n; ++i) {
        const sy_filter_rf_shading *sh = in->shading + i;
        const sy_filter_rf_sample *sm = in->samples + i;
        ok[i] = sample_ok(sm);
        ok[n + i] = shading_ok(sh);
        bool bad_i = ((sm->flags & SY_FILTER_RF_VALID) && !ok[i]) || ((sh->flags & SY_FILTER_RF_VALID) && !ok[n + i]);
        bad += bad_i;
        if (bad_i) ok[i] = 0, ok[n + i] = 0; /* a pixel with any NaN/Inf neither gives nor gathers */
    }
    rf->k++;
    rctx c = {.rf = rf, .in = in, .sok = ok, .hok = ok + n, .bsdf = in->bsdf, .bsdf_batch = in->bsdf_batch};
    if (!c.bsdf_batch && !c.bsdf) c.bsdf_batch = sy_filter_rf_bsdf_default_batch;
    sy_filter_parallel_rows(rf->p.threads, rf->h, rf_prep_rows, &c);
    sy_filter_parallel_rows(rf->p.threads, rf->h, rf_rows, &c);
    float *t = rf->svar;
    rf->svar = rf->svar2, rf->svar2 = t;
    t = rf->alpha, rf->alpha = rf->alpha2, rf->alpha2 = t;
    uint64_t corr = 0;
    for (size_t i = 0; i < n; ++i) {
        const float *src = (rf->p.unbiased_switch && rf->phase[i]) ? rf->ptacc + 3 * i : rf->accum + 3 * i;
        out[4 * i + 0] = src[0], out[4 * i + 1] = src[1], out[4 * i + 2] = src[2], out[4 * i + 3] = 1.0f;
        corr += rf->phase[i];
    }
    if (stats) {
        *stats = (sy_filter_stats){.nonfinite_samples = bad, .filtered_pixels = n - corr, .filter_pass = true,
                                   .mean_blend = (double)corr / (double)n,
                                   .seconds = sy_filter_clock(false) - t0};
    }
    return SY_FILTER_OK;
}
