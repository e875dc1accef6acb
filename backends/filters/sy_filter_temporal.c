/* sy_filter_temporal.c — temporal reuse for moving progressive frames: reprojection, history
 * clamping in YCoCg, moving averages of colour and moments, variance-guided a-trous; see
 * sy_filter_temporal.h. */
#include "sy_filter_temporal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* branch-free min / max without the library call GCC emits for fmaxf's NaN rules */
static inline float fmx(float a, float b)
{
    return a > b ? a : b;
}
static inline float fmn(float a, float b)
{
    return a < b ? a : b;
}

/* One frame's history: what the next frame reprojects. */
typedef struct hist {
    uint32_t w, h;
    size_t cap;  /* pixels allocated */
    float *illum; /* 3: demodulated indirect part (or colour) after the first a-trous pass */
    float *dir;   /* 3: demodulated direct part (0 without the split) */
    float *mom;   /* 4: luminance moments of the indirect part (or colour), then of the direct part */
    float *len;   /* 1: history length (frames); 0 = nothing to reuse (miss, bad pixel) */
    float *pos;   /* 3: world position */
    float *nrm;   /* 3: normal */
    float world_to_pixel[16];
} hist;

struct sy_filter_temporal {
    sy_filter_temporal_params p;
    hist h[2];
    int prev;      /* index of the previous frame's history in h */
    bool have_prev;
    size_t cap;    /* pixels of the working buffers */
    float *illum, *mod, *lum, *zgrad, *vbl;
    float *dcur; /* the direct part's new samples (0 without the split) */
    /* the blended part, its variance and luminance, and the a-trous ping-pong buffers: [0] the
     * indirect part (or the colour), [1] the direct part */
    struct plane {
        float *acc, *var, *lacc, *a, *b, *va, *vb, *la, *lb;
    } pl[2];
    uint8_t *ok, *hit; /* hit: 0 = none (miss, bad pixel), 1 = a hit without a normal, 2 = with one */
};

void sy_filter_temporal_params_default(sy_filter_temporal_params *p)
{
    /* [tuned on `sy bench temporal` (Cornell box and demo, 1 spp per frame); SVGF's published
     * sigma_l = 4, sigma_z = 1; alpha 0.1 (SVGF: 0.2) for a lower error at 1 spp] */
    *p = (sy_filter_temporal_params){.alpha = 0.1f, .alpha_moments = 0.2f, .max_history = 32, .clamp_gamma = 2.0f,
                                     .depth_tolerance = 0.03f, .normal_tolerance = 0.8f, .atrous_iterations = 4,
                                     .sigma_luminance = 4.0f, .sigma_normal = 64.0f, .sigma_depth = 1.0f, .threads = 0};
}

sy_filter_status sy_filter_temporal_params_check(const sy_filter_temporal_params *p, sy_filter_report *err)
{
    sy_filter_status s;
    if (!p) return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "temporal: params is NULL");
    if ((s = sy_filter_check_range(p->alpha, 1e-6f, 1.0f, "temporal: alpha", err))) return s;
    if ((s = sy_filter_check_range(p->alpha_moments, 1e-6f, 1.0f, "temporal: alpha_moments", err))) return s;
    if (p->max_history < 1 || p->max_history > 1024)
        return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "temporal: max_history = %u: must be 1..1024",
                              p->max_history);
    if ((s = sy_filter_check_range(p->clamp_gamma, 0.0f, 100.0f, "temporal: clamp_gamma", err))) return s;
    if ((s = sy_filter_check_positive(p->depth_tolerance, "temporal: depth_tolerance", err))) return s;
    if ((s = sy_filter_check_range(p->normal_tolerance, -1.0f, 1.0f, "temporal: normal_tolerance", err))) return s;
    if (p->atrous_iterations > 8)
        return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "temporal: atrous_iterations = %u: must be 0..8",
                              p->atrous_iterations);
    if ((s = sy_filter_check_positive(p->sigma_luminance, "temporal: sigma_luminance", err))) return s;
    if ((s = sy_filter_check_nonnegative(p->sigma_normal, "temporal: sigma_normal", err))) return s;
    if ((s = sy_filter_check_positive(p->sigma_depth, "temporal: sigma_depth", err))) return s;
    if (p->threads > SY_FILTER_MAX_THREADS)
        return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "temporal: threads = %u: at most %u", p->threads,
                              SY_FILTER_MAX_THREADS);
    return SY_FILTER_OK;
}

/* A pixel without a normal (0, 0, 0: a specular chain that never reached a diffuse surface) agrees
 * only with another such pixel; two normals agree when their cosine is at least tol. */
static inline bool has_normal(const float *n)
{
    return n[0] * n[0] + n[1] * n[1] + n[2] * n[2] > 0.25f;
}

static inline bool normals_agree(const float *a, const float *b, float tol)
{
    bool ha = has_normal(a), hb = has_normal(b);
    return ha != hb ? false : !ha || a[0] * b[0] + a[1] * b[1] + a[2] * b[2] >= tol;
}

static void hist_free(hist *h)
{
    free(h->illum), free(h->dir), free(h->mom), free(h->len), free(h->pos), free(h->nrm);
    memset(h, 0, sizeof *h);
}

static bool hist_reserve(hist *h, size_t n)
{
    if (n <= h->cap) return true;
    hist_free(h);
    h->illum = malloc(3 * n * sizeof(float)), h->dir = malloc(3 * n * sizeof(float)), h->mom = malloc(4 * n * sizeof(float));
    h->len = malloc(n * sizeof(float)), h->pos = malloc(3 * n * sizeof(float)), h->nrm = malloc(3 * n * sizeof(float));
    if (!h->illum || !h->dir || !h->mom || !h->len || !h->pos || !h->nrm) {
        hist_free(h);
        return false;
    }
    h->cap = n;
    return true;
}

static void work_free(sy_filter_temporal *t)
{
    free(t->illum), free(t->mod), free(t->lum), free(t->zgrad), free(t->vbl), free(t->dcur);
    t->illum = t->mod = t->lum = t->zgrad = t->vbl = t->dcur = NULL;
    for (int k = 0; k < 2; ++k) {
        struct plane *q = &t->pl[k];
        free(q->acc), free(q->var), free(q->lacc), free(q->a), free(q->b), free(q->va), free(q->vb), free(q->la);
        free(q->lb);
        memset(q, 0, sizeof *q);
    }
    free(t->ok), free(t->hit);
    t->ok = t->hit = NULL;
    t->cap = 0;
}

static bool work_reserve(sy_filter_temporal *t, size_t n)
{
    if (n <= t->cap) return true;
    work_free(t);
    size_t f3 = 3 * n * sizeof(float), f1 = n * sizeof(float);
    bool ok = (t->illum = malloc(f3)) && (t->mod = malloc(f3)) && (t->dcur = malloc(f3)) && (t->lum = malloc(f1)) &&
              (t->zgrad = malloc(f1)) && (t->vbl = malloc(f1)) && (t->ok = malloc(n)) && (t->hit = malloc(n));
    for (int k = 0; k < 2 && ok; ++k) {
        struct plane *q = &t->pl[k];
        ok = (q->acc = malloc(f3)) && (q->a = malloc(f3)) && (q->b = malloc(f3)) && (q->var = malloc(f1)) &&
             (q->lacc = malloc(f1)) && (q->va = malloc(f1)) && (q->vb = malloc(f1)) && (q->la = malloc(f1)) &&
             (q->lb = malloc(f1));
    }
    if (!ok) {
        work_free(t);
        return false;
    }
    t->cap = n;
    return true;
}

sy_filter_status sy_filter_temporal_create(const sy_filter_temporal_params *p, sy_filter_temporal **out,
                                           sy_filter_report *err)
{
    if (!out) return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "temporal: out is NULL");
    *out = NULL;
    sy_filter_temporal_params d;
    if (!p) sy_filter_temporal_params_default(&d), p = &d;
    sy_filter_status s = sy_filter_temporal_params_check(p, err);
    if (s) return s;
    sy_filter_temporal *t = calloc(1, sizeof *t);
    if (!t) return sy_filter_fail(err, SY_FILTER_ERROR_OUT_OF_MEMORY, "temporal: out of memory");
    t->p = *p;
    *out = t;
    return SY_FILTER_OK;
}

void sy_filter_temporal_destroy(sy_filter_temporal *t)
{
    if (!t) return;
    hist_free(&t->h[0]), hist_free(&t->h[1]);
    work_free(t);
    free(t);
}

void sy_filter_temporal_reset(sy_filter_temporal *t)
{
    if (t) t->have_prev = false;
}

sy_filter_status sy_filter_temporal_set_params(sy_filter_temporal *t, const sy_filter_temporal_params *p,
                                               sy_filter_report *err)
{
    if (!t) return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "temporal: state is NULL");
    sy_filter_status s = sy_filter_temporal_params_check(p, err);
    if (!s) t->p = *p;
    return s;
}

/* ---- the passes ---- */

typedef struct tctx {
    sy_filter_temporal *t;
    const sy_filter_frame *in;
    const hist *prev; /* NULL: no history */
    hist *next;
    /* a-trous pass */
    const float *src, *vsrc, *lsrc, *srcd;
    float *dst, *vdst, *ldst;
    int step;
    float *keep; /* NULL, or where this pass's output goes (the next history's colour) */
    float *out;
} tctx;

static inline bool finite3(const float *v)
{
    return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]);
}

/* demodulation; validity */
static void demod_rows(void *vc, uint32_t y0, uint32_t y1)
{
    tctx *c = vc;
    sy_filter_temporal *t = c->t;
    const sy_filter_frame *in = c->in;
    size_t w = in->width, cc = in->color_channels;
    for (size_t i = (size_t)y0 * w; i < (size_t)y1 * w; ++i) {
        const float *col = in->color + cc * i, *al = in->albedo + 3 * i;
        float d = in->depth[i];
        bool split = in->direct && in->indirect;
        bool ok = finite3(col) && finite3(al) && finite3(in->normal + 3 * i) && !isnan(d) && d > -INFINITY &&
                  (!split || (finite3(in->direct + 3 * i) && finite3(in->indirect + 3 * i)));
        bool hit = ok && isfinite(d) && finite3(in->position + 3 * i);
        t->ok[i] = ok, t->hit[i] = (uint8_t)(hit ? (has_normal(in->normal + 3 * i) ? 2 : 1) : 0);
        for (int q = 0; q < 3; ++q) {
            float m = hit && al[q] > 0.01f ? al[q] : 1.0f; /* dark albedo keeps the radiance (as a-trous) */
            t->mod[3 * i + q] = m;
            t->illum[3 * i + q] = ok ? (split ? in->indirect[3 * i + q] : col[q]) / m : 0.0f;
            t->dcur[3 * i + q] = ok && split ? in->direct[3 * i + q] / m : 0.0f;
        }
        t->lum[i] = sy_filter_luminance(t->illum + 3 * i);
    }
}

static inline void to_ycocg(const float *c, float *o)
{
    o[0] = 0.25f * c[0] + 0.5f * c[1] + 0.25f * c[2];
    o[1] = 0.5f * c[0] - 0.5f * c[2];
    o[2] = -0.25f * c[0] + 0.5f * c[1] - 0.25f * c[2];
}

static inline void from_ycocg(const float *y, float *o)
{
    o[0] = y[0] + y[1] - y[2];
    o[1] = y[0] + y[2];
    o[2] = y[0] - y[1] - y[2];
}

/* Bilinear reprojection of world point p (normal n, depth z) into the previous history; false when
 * no tap fits. */
static bool reproject(const sy_filter_temporal *t, const hist *h, const float *p, const float *n, float z,
                      float illum[3], float dir[3], float mom[4], float *len)
{
    const float *M = h->world_to_pixel;
    float X = M[0] * p[0] + M[4] * p[1] + M[8] * p[2] + M[12];
    float Y = M[1] * p[0] + M[5] * p[1] + M[9] * p[2] + M[13];
    float W = M[3] * p[0] + M[7] * p[1] + M[11] * p[2] + M[15];
    if (!(W > 1e-12f)) return false;
    float x = X / W - 0.5f, y = Y / W - 0.5f;
    if (!(x > -1.0f && y > -1.0f && x < (float)h->w && y < (float)h->h)) return false;
    int x0 = (int)floorf(x), y0 = (int)floorf(y);
    float fx = x - (float)x0, fy = y - (float)y0;
    float tol = t->p.depth_tolerance * z, tol2 = 64.0f * tol * tol;
    float sw = 0, acc[11] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
    for (int k = 0; k < 4; ++k) {
        int xx = x0 + (k & 1), yy = y0 + (k >> 1);
        if (xx < 0 || yy < 0 || xx >= (int)h->w || yy >= (int)h->h) continue;
        size_t j = (size_t)yy * h->w + (size_t)xx;
        if (!(h->len[j] > 0.0f)) continue;
        const float *pj = h->pos + 3 * j, *nj = h->nrm + 3 * j;
        float d[3] = {pj[0] - p[0], pj[1] - p[1], pj[2] - p[2]};
        float plane = fabsf(d[0] * n[0] + d[1] * n[1] + d[2] * n[2]);
        if (!(plane <= tol) || !(d[0] * d[0] + d[1] * d[1] + d[2] * d[2] <= tol2)) continue;
        if (!normals_agree(n, nj, t->p.normal_tolerance)) continue;
        float wk = ((k & 1) ? fx : 1.0f - fx) * ((k >> 1) ? fy : 1.0f - fy);
        if (!(wk > 0.0f)) continue;
        for (int q = 0; q < 3; ++q) acc[q] += wk * h->illum[3 * j + q], acc[6 + q] += wk * h->dir[3 * j + q];
        acc[3] += wk * h->mom[4 * j], acc[4] += wk * h->mom[4 * j + 1], acc[5] += wk * h->len[j];
        acc[9] += wk * h->mom[4 * j + 2], acc[10] += wk * h->mom[4 * j + 3];
        sw += wk;
    }
    if (!(sw > 1e-3f)) return false;
    for (int q = 0; q < 3; ++q) illum[q] = acc[q] / sw, dir[q] = acc[6 + q] / sw;
    mom[0] = acc[3] / sw, mom[1] = acc[4] / sw, mom[2] = acc[9] / sw, mom[3] = acc[10] / sw, *len = acc[5] / sw;
    return true;
}

/* clamps colour c to the YCoCg box mean +- gamma sd of the sums m1, m2 of count 1/ic */
static inline void clamp_box(float *c, const float *m1, const float *m2, float ic, float gamma)
{
    float v[3];
    to_ycocg(c, v);
    for (int q = 0; q < 3; ++q) {
        float mu = m1[q] * ic, var = m2[q] * ic - mu * mu, sd = sqrtf(var > 0.0f ? var : 0.0f);
        float lo = mu - gamma * sd, up = mu + gamma * sd;
        v[q] = v[q] < lo ? lo : v[q] > up ? up : v[q];
    }
    from_ycocg(v, c);
}

/* depth gradient, reprojection, clamping, moving averages, variance; the next history's geometry */
static void integrate_rows(void *vc, uint32_t y0, uint32_t y1)
{
    tctx *c = vc;
    sy_filter_temporal *t = c->t;
    const sy_filter_frame *in = c->in;
    const sy_filter_temporal_params *P = &t->p;
    int w = (int)in->width, hgt = (int)in->height;
    hist *nx = c->next;
    struct plane *pi = &t->pl[0], *pd = &t->pl[1];
    for (int y = (int)y0; y < (int)y1; ++y)
        for (int x = 0; x < w; ++x) {
            size_t i = (size_t)y * w + x;
            float *acc = pi->acc + 3 * i, *da = pd->acc + 3 * i;
            const float *cur = t->illum + 3 * i, *dc = t->dcur + 3 * i;
            if (!t->hit[i]) {
                memcpy(acc, cur, 3 * sizeof(float));
                memcpy(da, dc, 3 * sizeof(float));
                pi->var[i] = pd->var[i] = 0.0f, t->zgrad[i] = 0.0f;
                pi->lacc[i] = t->lum[i], pd->lacc[i] = sy_filter_luminance(dc);
                nx->len[i] = 0.0f;
                for (int q = 0; q < 4; ++q) nx->mom[4 * i + q] = 0.0f;
                for (int q = 0; q < 3; ++q) nx->pos[3 * i + q] = nx->nrm[3 * i + q] = 0.0f;
                continue;
            }
            float z = in->depth[i];
            const float *p = in->position + 3 * i, *n = in->normal + 3 * i;
            /* 3x3 neighbourhood of the new samples: YCoCg boxes, luminance moments, depth gradient */
            float m1[3] = {0, 0, 0}, m2[3] = {0, 0, 0}, d1[3] = {0, 0, 0}, d2[3] = {0, 0, 0};
            float l1 = 0, l2 = 0, e1 = 0, e2 = 0, cnt = 0, zg = 0;
            for (int dy = -1; dy <= 1; ++dy) {
                int yy = y + dy;
                if (yy < 0 || yy >= hgt) continue;
                for (int dx = -1; dx <= 1; ++dx) {
                    int xx = x + dx;
                    if (xx < 0 || xx >= w) continue;
                    size_t j = (size_t)yy * w + xx;
                    if (!t->hit[j]) continue;
                    float v[3];
                    to_ycocg(t->illum + 3 * j, v);
                    for (int q = 0; q < 3; ++q) m1[q] += v[q], m2[q] += v[q] * v[q];
                    to_ycocg(t->dcur + 3 * j, v);
                    for (int q = 0; q < 3; ++q) d1[q] += v[q], d2[q] += v[q] * v[q];
                    float lj = t->lum[j], ej = sy_filter_luminance(t->dcur + 3 * j);
                    l1 += lj, l2 += lj * lj, e1 += ej, e2 += ej * ej;
                    cnt += 1.0f;
                    if ((dx == 0) != (dy == 0)) zg = fmx(zg, fabsf(in->depth[j] - z));
                }
            }
            t->zgrad[i] = zg;
            float ic = 1.0f / cnt;
            float hi[3] = {0, 0, 0}, hd[3] = {0, 0, 0}, hm[4] = {0, 0, 0, 0}, hl = 0.0f;
            bool reused = c->prev && reproject(t, c->prev, p, n, z, hi, hd, hm, &hl);
            if (reused && P->clamp_gamma > 0.0f) {
                clamp_box(hi, m1, m2, ic, P->clamp_gamma);
                clamp_box(hd, d1, d2, ic, P->clamp_gamma);
            }
            if (!reused) hl = 0.0f;
            float a = reused ? fmx(P->alpha, 1.0f / (hl + 1.0f)) : 1.0f;
            float am = reused ? fmx(P->alpha_moments, 1.0f / (hl + 1.0f)) : 1.0f;
            for (int q = 0; q < 3; ++q) {
                acc[q] = hi[q] + a * (cur[q] - hi[q]);
                da[q] = hd[q] + a * (dc[q] - hd[q]);
            }
            float l = t->lum[i], e = sy_filter_luminance(dc);
            float mo[4] = {hm[0] + am * (l - hm[0]), hm[1] + am * (l * l - hm[1]), hm[2] + am * (e - hm[2]),
                           hm[3] + am * (e * e - hm[3])};
            float len = fmn(hl + 1.0f, (float)P->max_history);
            for (int q = 0; q < 4; ++q) nx->mom[4 * i + q] = mo[q];
            nx->len[i] = len;
            pi->lacc[i] = sy_filter_luminance(acc), pd->lacc[i] = sy_filter_luminance(da);
            if (len < 4.0f) { /* short history: the spatial variance of the new samples */
                float mu = l1 * ic, me = e1 * ic;
                pi->var[i] = fmx(0.0f, l2 * ic - mu * mu), pd->var[i] = fmx(0.0f, e2 * ic - me * me);
            } else {
                pi->var[i] = fmx(0.0f, mo[1] - mo[0] * mo[0]), pd->var[i] = fmx(0.0f, mo[3] - mo[2] * mo[2]);
            }
            memcpy(nx->pos + 3 * i, p, 3 * sizeof(float));
            memcpy(nx->nrm + 3 * i, n, 3 * sizeof(float));
        }
}

/* the variance blurred 3x3 (B-spline, step 1) over pixels of the centre's class: guides the
 * luminance edge stop of an a-trous pass */
static void vblur_rows(void *vc, uint32_t y0, uint32_t y1)
{
    static const float hk[3] = {0.25f, 0.5f, 0.25f};
    tctx *c = vc;
    sy_filter_temporal *t = c->t;
    int w = (int)c->in->width, hgt = (int)c->in->height;
    const uint8_t *cls = t->hit;
    for (int y = (int)y0; y < (int)y1; ++y)
        for (int x = 0; x < w; ++x) {
            size_t i = (size_t)y * w + x;
            if (!cls[i]) {
                t->vbl[i] = 0.0f;
                continue;
            }
            float vb = 0, vw = 0;
            for (int dy = -1; dy <= 1; ++dy) {
                int yy = y + dy;
                if (yy < 0 || yy >= hgt) continue;
                for (int dx = -1; dx <= 1; ++dx) {
                    int xx = x + dx;
                    if (xx < 0 || xx >= w) continue;
                    size_t j = (size_t)yy * w + xx;
                    float k = cls[j] == cls[i] ? hk[dx + 1] * hk[dy + 1] : 0.0f;
                    vb += k * c->vsrc[j], vw += k;
                }
            }
            t->vbl[i] = vb / vw; /* vw > 0: the centre */
        }
}

/* one a-trous pass (3x3 B-spline, taps c->step apart) over hits; neighbours only of the centre's
 * class (hit with a normal, hit without one) */
static void atrous_rows(void *vc, uint32_t y0, uint32_t y1)
{
    static const float hk[3] = {0.25f, 0.5f, 0.25f};
    tctx *c = vc;
    sy_filter_temporal *t = c->t;
    const sy_filter_frame *in = c->in;
    const sy_filter_temporal_params *P = &t->p;
    int w = (int)in->width, hgt = (int)in->height, s = c->step;
    const uint8_t *cls = t->hit;
    const float *L = c->lsrc, *Z = in->depth, *N = in->normal;
    for (int y = (int)y0; y < (int)y1; ++y)
        for (int x = 0; x < w; ++x) {
            size_t i = (size_t)y * w + x;
            const float *ci = c->src + 3 * i;
            float *o = c->dst + 3 * i;
            uint8_t ki = cls[i];
            if (!ki) {
                o[0] = ci[0], o[1] = ci[1], o[2] = ci[2];
                c->vdst[i] = c->vsrc[i], c->ldst[i] = L[i];
            } else {
                float li = L[i], zi = Z[i];
                const float *ni = N + 3 * i;
                float sn = ki == 2 ? P->sigma_normal : 0.0f;
                float inv_l = 1.0f / (P->sigma_luminance * sqrtf(t->vbl[i]) + 1e-6f);
                float inv_z = 1.0f / (P->sigma_depth * (float)s * t->zgrad[i] + 1e-6f * zi + 1e-9f);
                float k0 = hk[1] * hk[1]; /* the centre: exactly its kernel weight */
                float a0 = k0 * ci[0], a1 = k0 * ci[1], a2 = k0 * ci[2], W = k0, V = k0 * k0 * c->vsrc[i];
                for (int dy = -1; dy <= 1; ++dy) {
                    int yy = y + dy * s;
                    if (yy < 0 || yy >= hgt) continue;
                    for (int dx = -1; dx <= 1; ++dx) {
                        int xx = x + dx * s;
                        if ((dx == 0 && dy == 0) || xx < 0 || xx >= w) continue;
                        size_t j = (size_t)yy * w + xx;
                        if (cls[j] != ki) continue;
                        const float *nj = N + 3 * j;
                        float dn = 1.0f - (ni[0] * nj[0] + ni[1] * nj[1] + ni[2] * nj[2]);
                        float dl = li - L[j], dz = zi - Z[j];
                        float arg = (dl < 0 ? -dl : dl) * inv_l + (dz < 0 ? -dz : dz) * inv_z * ((dx && dy) ? 0.70710678f : 1.0f) +
                                    sn * (dn > 0.0f ? dn : 0.0f);
                        float k = hk[dx + 1] * hk[dy + 1] * sy_filter_expneg(arg);
                        const float *cj = c->src + 3 * j;
                        a0 += k * cj[0], a1 += k * cj[1], a2 += k * cj[2];
                        W += k, V += k * k * c->vsrc[j];
                    }
                }
                float iw = 1.0f / W;
                o[0] = a0 * iw, o[1] = a1 * iw, o[2] = a2 * iw;
                c->vdst[i] = V * iw * iw;
                c->ldst[i] = sy_filter_luminance(o);
            }
            if (c->keep) memcpy(c->keep + 3 * i, o, 3 * sizeof(float));
        }
}

static void remod_rows(void *vc, uint32_t y0, uint32_t y1)
{
    tctx *c = vc;
    sy_filter_temporal *t = c->t;
    const sy_filter_frame *in = c->in;
    size_t w = in->width, cc = in->color_channels;
    for (size_t i = (size_t)y0 * w; i < (size_t)y1 * w; ++i) {
        float *o = c->out + 4 * i;
        for (int q = 0; q < 3; ++q) o[q] = (c->src[3 * i + q] + c->srcd[3 * i + q]) * t->mod[3 * i + q];
        o[3] = cc == 4 && isfinite(in->color[4 * i + 3]) ? in->color[4 * i + 3] : 1.0f;
    }
}

sy_filter_status sy_filter_temporal_run(sy_filter_temporal *t, const sy_filter_frame *in, const float world_to_pixel[16],
                                        float *out, sy_filter_temporal_stats *stats, sy_filter_report *err)
{
    struct timespec t0, t1, c0, c1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c0);
    if (!t) return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "temporal: state is NULL");
    uint32_t need = SY_FILTER_NEED_COLOR | SY_FILTER_NEED_ALBEDO | SY_FILTER_NEED_NORMAL | SY_FILTER_NEED_DEPTH |
                    SY_FILTER_NEED_POSITION;
    sy_filter_status s = sy_filter_check_frame(in, need, "temporal", err);
    if (s) return t->have_prev = false, s;
    if (!out || !world_to_pixel)
        return t->have_prev = false,
               sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "temporal: output or world_to_pixel is NULL");
    for (int k = 0; k < 16; ++k)
        if (!isfinite(world_to_pixel[k]))
            return t->have_prev = false, sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT,
                                                        "temporal: world_to_pixel[%d] is not finite", k);
    size_t n = (size_t)in->width * in->height;
    hist *nx = &t->h[1 - t->prev];
    if (!work_reserve(t, n) || !hist_reserve(nx, n)) {
        t->have_prev = false;
        return sy_filter_fail(err, SY_FILTER_ERROR_OUT_OF_MEMORY, "temporal: out of memory for %ux%u", in->width,
                              in->height);
    }
    tctx c = {.t = t, .in = in, .prev = t->have_prev ? &t->h[t->prev] : NULL, .next = nx, .out = out};
    uint32_t th = t->p.threads, rows = in->height;
    sy_filter_parallel_rows(th, rows, demod_rows, &c);
    sy_filter_parallel_rows(th, rows, integrate_rows, &c);
    /* the a-trous passes: the indirect part (or the colour), then the direct part when split */
    bool split = in->direct && in->indirect;
    const float *out_part[2] = {t->pl[0].acc, t->pl[1].acc};
    float *keep[2] = {nx->illum, nx->dir};
    for (int k = 0; k < 2; ++k) {
        struct plane *q = &t->pl[k];
        const float *src = q->acc, *vsrc = q->var, *lsrc = q->lacc;
        uint32_t iters = k == 0 || split ? t->p.atrous_iterations : 0;
        /* the next history: the first pass's output for the indirect part (as SVGF); the direct part's
         * unfiltered blend (fed back, its filtered output let emitter light creep over their edges
         * frame after frame: Cornell box relMSE 0.077 against 0.023, `sy bench temporal`, 16 frames) */
        bool feed = k == 0;
        if (iters == 0 || !feed) memcpy(keep[k], q->acc, 3 * n * sizeof(float));
        for (uint32_t it = 0; it < iters; ++it) {
            c.src = src, c.vsrc = vsrc, c.lsrc = lsrc;
            c.dst = (it & 1) ? q->b : q->a, c.vdst = (it & 1) ? q->vb : q->va, c.ldst = (it & 1) ? q->lb : q->la;
            c.step = 1 << it, c.keep = it == 0 && feed ? keep[k] : NULL;
            sy_filter_parallel_rows(th, rows, vblur_rows, &c);
            sy_filter_parallel_rows(th, rows, atrous_rows, &c);
            src = c.dst, vsrc = c.vdst, lsrc = c.ldst;
        }
        out_part[k] = src;
    }
    c.src = out_part[0], c.srcd = out_part[1];
    sy_filter_parallel_rows(th, rows, remod_rows, &c);
    nx->w = in->width, nx->h = in->height;
    memcpy(nx->world_to_pixel, world_to_pixel, sizeof nx->world_to_pixel);
    t->prev = 1 - t->prev;
    t->have_prev = true;
    if (stats) {
        sy_filter_temporal_stats st = {.pixels = n};
        double hsum = 0;
        uint64_t hits = 0;
        for (size_t i = 0; i < n; ++i) {
            st.nonfinite += !t->ok[i];
            if (!t->hit[i]) continue;
            hits++, hsum += nx->len[i];
            if (nx->len[i] > 1.0f) st.reprojected++;
            else st.disoccluded++;
        }
        st.mean_history = hits ? hsum / (double)hits : 0.0;
        clock_gettime(CLOCK_MONOTONIC, &t1);
        clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c1);
        st.cpu_seconds = (double)(c1.tv_sec - c0.tv_sec) + 1e-9 * (double)(c1.tv_nsec - c0.tv_nsec);
        st.seconds = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
        *stats = st;
    }
    return SY_FILTER_OK;
}
