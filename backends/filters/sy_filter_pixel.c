/* sy_filter_pixel.c — pixel filtering (Schwenk 2013 ch. 3): range buffer composition, brute-force
 * and iterated separable cross bilateral filters with per-pixel variance reduction factor r,
 * adaptive widths, antialiasing recovery, and the blending operator with spike withholding.
 * Section numbers refer to ../shared/notes/filters-spec.md. */
#include "sy_filter_pixel.h"

#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#define MAX_TAPS 511 /* separable pass window (2R+1), R <= 255 */
#define MISS_DEPTH 1e18f /* squared differences stay finite in float */
#define EXP_SCALE 64.0f
#define EXP_TABLE 1280 /* exp(-x) tabulated on [0, 20) */
/* Planar work buffers: every plane has SLACK floats before and after its n pixels, so the
 * 4-pixel vector loads of the separable pass may run up to 3 pixels past a row's or the image's
 * end (those lanes are masked out); see sep_rows. */
#define SLACK 8
enum { PL_G = 0, PL_OK = 4, PL_V = 5, PL_T = 9, PL_B = 13, PL_RT = 17, PL_RA = 18, PL_COUNT = 19 };

struct sy_filter_pixel {
    sy_filter_pixel_params p;
    uint32_t w, h;
    bool have_pass;
    float *guide;   /* 4/px: range RGB + depth (copy used by the pass) */
    uint8_t *ok;    /* 1 = value and guide finite */
    uint8_t *gok;   /* 1 = guide finite (the range term applies with this pixel as centre) */
    float *edge;    /* 4/px: AA-recovery edge test per direction (edge_rows) */
    float *planes;  /* PL_COUNT planes of n + 2 SLACK floats: guide RGBD, ok as 0/1, the HV RGB +
                       per-sample variance (filter input, V) and two ping-pong sets (T, B), r of a
                       separable iteration (RT after the horizontal pass, RA after the vertical) */
    float *val[4], *tmp[4], *oth[4], *gpl[4], *okf, *racc, *rtmp; /* views into planes */
    float *inv, *rmin; /* 1/px: r composition over the separable iterations */
    float *sigma;   /* 1/px: spatial sigma per pixel */
    float *lf;      /* 4/px: filtered HV RGB + smoothed per-sample variance (state) */
    float *r;       /* 1/px: reduction factor of lf */
    float *a0;      /* 1/px: normalised centre weight (covariance term) */
    float *npass;   /* 1/px: spp at the pass */
    float *s;       /* 1/px: blend factor of the last run */
    float *lf3;     /* 3/px: filtered HV for diagnostics */
    float expt[EXP_TABLE + 2]; /* exp(-x) at x = i / EXP_SCALE: the separable pass's weights */
};

void sy_filter_pixel_params_default(sy_filter_pixel_params *p)
{
    *p = (sy_filter_pixel_params){
        .threshold = 0.01f, .sigma_s = 8.0f, .sigma_c = 0.02f, .sigma_d = 2.0f, .schedule_start = 4,
        .kernel = SY_FILTER_PIXEL_SEPARABLE, .iterations = 3, .adaptive_width = true, .adaptive_c = 4.0f,
        .adaptive_sigma0 = 0.0f, .spike_withholding = true, .spike_c = 2.0f, .aa_recovery = true,
        .all_high_variance = false, .use_covariance = false, .headlight_weight = 0.5f, .threads = 0,
    };
}

sy_filter_status sy_filter_pixel_params_check(const sy_filter_pixel_params *p, sy_filter_report *err)
{
    sy_filter_status s;
    if (!p) return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "pixel filter: params is NULL");
    if ((s = sy_filter_check_nonnegative(p->threshold, "pixel filter: threshold t", err))) return s;
    if ((s = sy_filter_check_positive(p->sigma_s, "pixel filter: sigma_s", err))) return s;
    if ((s = sy_filter_check_range(p->sigma_s, 0.0f, 1000.0f, "pixel filter: sigma_s", err))) return s;
    if ((s = sy_filter_check_positive(p->sigma_c, "pixel filter: sigma_c", err))) return s;
    if ((s = sy_filter_check_positive(p->sigma_d, "pixel filter: sigma_d", err))) return s;
    if (p->schedule_start == 0 || (p->schedule_start & (p->schedule_start - 1)))
        return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT,
                              "pixel filter: schedule_start = %u: must be a power of two >= 1", p->schedule_start);
    if (p->kernel != SY_FILTER_PIXEL_BRUTE && p->kernel != SY_FILTER_PIXEL_SEPARABLE)
        return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "pixel filter: kernel = %d: unknown",
                              (int)p->kernel);
    if (p->iterations < 1 || p->iterations > 8)
        return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "pixel filter: iterations = %u: must be 1..8",
                              p->iterations);
    if ((s = sy_filter_check_range(p->adaptive_c, 1.0f, 1000.0f, "pixel filter: adaptive_c", err))) return s;
    if ((s = sy_filter_check_nonnegative(p->adaptive_sigma0, "pixel filter: adaptive_sigma0", err))) return s;
    if ((s = sy_filter_check_range(p->spike_c, 1.0f, 1e6f, "pixel filter: spike_c", err))) return s;
    if ((s = sy_filter_check_range(p->headlight_weight, 0.0f, 1.0f, "pixel filter: headlight_weight", err))) return s;
    return sy_filter_check_threads(p->threads, "pixel filter", err);
}

bool sy_filter_pixel_scheduled(const sy_filter_pixel_params *p, uint32_t frame)
{
    return frame >= p->schedule_start && frame && !(frame & (frame - 1));
}

float sy_filter_blend_factor(float u, float f, float t, float c)
{
    if (!(u > t)) return 1.0f; /* case 2 (also u = f = 0) */
    if (c > 0.0f) {            /* spec 1.7 [DERIVED]: covariance c = a0 u kept */
        float den = u + f - 2.0f * c, disc = (f - c) * (f - c) - den * (f - t);
        if (disc < 0.0f || den <= 0.0f) return 0.0f;
        float s = ((f - c) + sqrtf(disc)) / den;
        return s < 0.0f ? 0.0f : s > 1.0f ? 1.0f : s;
    }
    float disc = t * u + t * f - u * f;
    if (disc < 0.0f) return 0.0f; /* case 1 */
    float s = (f + sqrtf(disc)) / (u + f);
    return s < 0.0f ? 0.0f : s > 1.0f ? 1.0f : s;
}

/* range buffer rows [y0, y1) (sy_filter_range_compose without the checks) */
static void compose_rows(const sy_filter_frame *f, const float *cam, float hw, float *out, uint32_t y0, uint32_t y1)
{
    bool headlight = cam && f->position && f->normal;
    for (size_t i = (size_t)y0 * f->width; i < (size_t)y1 * f->width; ++i) {
        const float *a = f->albedo + 3 * i;
        float k = 1.0f;
        if (headlight) {
            const float *nn = f->normal + 3 * i, *p = f->position + 3 * i;
            float v[3] = {cam[0] - p[0], cam[1] - p[1], cam[2] - p[2]};
            float lv = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
            float ln = sqrtf(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2]);
            float c = (lv > 0.0f && ln > 0.0f) ? fabsf(nn[0] * v[0] + nn[1] * v[1] + nn[2] * v[2]) / (lv * ln) : 0.0f;
            if (!isfinite(c)) c = 0.0f;
            /* unoccluded headlight at the camera, no distance falloff (a falloff would make the
             * range colour depth dependent, which the depth term already covers) */
            k = (1.0f - hw) + hw * c;
        }
        for (int c = 0; c < 3; ++c) out[4 * i + c] = a[c] * k;
        float d = f->depth[i];
        out[4 * i + 3] = d < MISS_DEPTH ? d : MISS_DEPTH;
    }
}

sy_filter_status sy_filter_range_compose(const sy_filter_frame *f, const float *cam, float hw, float *out,
                                         sy_filter_report *err)
{
    sy_filter_status s = sy_filter_check_frame(f, SY_FILTER_NEED_ALBEDO | SY_FILTER_NEED_DEPTH, "range buffer", err);
    if (s) return s;
    if ((s = sy_filter_check_range(hw, 0.0f, 1.0f, "range buffer: headlight_weight", err))) return s;
    if (!out) return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "range buffer: output is NULL");
    compose_rows(f, cam, hw, out, 0, f->height);
    return SY_FILTER_OK;
}

/* ---- filter pass -------------------------------------------------------------------------- */

typedef struct pass_ctx {
    sy_filter_pixel *pf;
    const float *src[4]; /* planes */
    float *dst[4];       /* planes (brute: dst[0] is the RGBA state lf) */
    const float *rsrc;   /* NULL = 1 everywhere (first pass of an iteration) */
    float *rdst;
    float *a0;
    float sig_scale; /* separable iteration scale of sigma */
    int dir;         /* 0 = horizontal, 1 = vertical */
    bool last;       /* vertical pass of the last iteration: write lf, r, lf3 */
    float inv2c, inv2d;
} pass_ctx;

static inline float range_arg(const float *gj, const float *gi, float inv2c, float inv2d)
{
    float dr = gj[0] - gi[0], dg = gj[1] - gi[1], db = gj[2] - gi[2], dd = gj[3] - gi[3];
    return (dr * dr + dg * dg + db * db) * inv2c + dd * dd * inv2d;
}

/* ceil(3 sigma) as the window radius (x > 0: the same integer as (int)ceilf(x), no libm call) */
static inline int radius_of(float sg)
{
    float x = 3.0f * sg;
    int r = (int)x;
    return (float)r < x ? r + 1 : r;
}

static inline bool guide_ok(const float *g)
{
    return isfinite(g[0]) && isfinite(g[1]) && isfinite(g[2]) && !isnan(g[3]);
}

/* Brute-force 2D cross bilateral (Eq. 3.6), per-pixel sigma, truncated at 3 sigma. */
static void brute_rows(void *vctx, uint32_t y0, uint32_t y1)
{
    pass_ctx *c = vctx;
    sy_filter_pixel *pf = c->pf;
    int w = (int)pf->w, h = (int)pf->h;
    for (int y = (int)y0; y < (int)y1; ++y)
        for (int x = 0; x < w; ++x) {
            size_t j = (size_t)y * w + x;
            float sg = pf->sigma[j];
            int R = (int)ceilf(3.0f * sg);
            if (R > w + h) R = w + h;
            float inv2s = 0.5f / (sg * sg);
            const float *gj = pf->guide + 4 * j;
            bool gj_ok = guide_ok(gj);
            double A = 0, A2 = 0, acc[4] = {0, 0, 0, 0}, a0 = 0;
            for (int dy = -R; dy <= R; ++dy) {
                int yy = y + dy;
                if (yy < 0 || yy >= h) continue;
                for (int dx = -R; dx <= R; ++dx) {
                    int xx = x + dx;
                    if (xx < 0 || xx >= w) continue;
                    int d2 = dx * dx + dy * dy;
                    if (d2 > R * R) continue;
                    size_t i = (size_t)yy * w + xx;
                    if (!pf->ok[i]) continue;
                    float arg = (float)d2 * inv2s + (gj_ok ? range_arg(gj, pf->guide + 4 * i, c->inv2c, c->inv2d) : 0.0f);
                    float a = sy_filter_expneg(arg);
                    if (a == 0.0f) continue;
                    A += a, A2 += (double)a * a;
                    for (int k = 0; k < 4; ++k) acc[k] += a * c->src[k][i];
                    if (i == j) a0 = a;
                }
            }
            float *o = c->dst[0] + 4 * j;
            if (A > 0) {
                for (int k = 0; k < 4; ++k) o[k] = (float)(acc[k] / A);
                c->rdst[j] = (float)(A2 / (A * A));
                c->a0[j] = (float)(a0 / A);
            } else {
                for (int k = 0; k < 4; ++k) o[k] = c->src[k][j];
                c->rdst[j] = 1.0f;
                c->a0[j] = 1.0f;
            }
            memcpy(pf->lf3 + 3 * j, o, 3 * sizeof(float));
        }
}

/* Antialiasing recovery (Sec. 3.6.5) at centre j of a 1D pass: true when a colour edge crosses
 * the pass direction here; then ahat (coverage), wedge (Eq. 3.20 goodness of fit) and the two
 * neighbours' guides g0, g2 are set. */
static bool aa_edge(const sy_filter_pixel *pf, int dir, size_t j, int x, int y, const float *gj, float *ahat_out,
                    float *wedge_out)
{
    int w = (int)pf->w, h = (int)pf->h;
    int pos = dir == 0 ? x : y, len = dir == 0 ? w : h;
    ptrdiff_t step = dir == 0 ? 1 : w;
    if (!(pos > 0 && pos < len - 1 && pf->ok[j - step] && pf->ok[j + step])) return false;
    const float *g0 = pf->guide + 4 * (j - step), *g2 = pf->guide + 4 * (j + step);
    /* cheap gate: the Sobel gradient needs a colour step across this pixel's own row */
    float e0 = g2[0] - g0[0], e1 = g2[1] - g0[1], e2 = g2[2] - g0[2];
    if (e0 * e0 + e1 * e1 + e2 * e2 < pf->p.sigma_c * pf->p.sigma_c) return false;
    /* 1D Sobel (smoothing across the pass direction, 1-2-1) of the range RGB */
    ptrdiff_t ortho = dir == 0 ? w : 1;
    int opos = dir == 0 ? y : x, olen = dir == 0 ? h : w;
    float grad[3] = {0, 0, 0}, wsum = 0;
    for (int o = -1; o <= 1; ++o) {
        if (opos + o < 0 || opos + o >= olen) continue;
        size_t jo = (size_t)((ptrdiff_t)j + o * ortho);
        if (!pf->ok[jo - step] || !pf->ok[jo + step]) continue;
        float wt = o == 0 ? 2.0f : 1.0f;
        for (int k = 0; k < 3; ++k) grad[k] += wt * (pf->guide[4 * (jo + step) + k] - pf->guide[4 * (jo - step) + k]);
        wsum += wt;
    }
    float gm = wsum > 0 ? sqrtf(grad[0] * grad[0] + grad[1] * grad[1] + grad[2] * grad[2]) / wsum : 0.0f;
    /* [GAP spec 1.10(d)]: recovery only where the Sobel gradient marks an edge stronger
     * than two colour sigmas; flat regions keep the symmetric window (no variance loss). */
    if (!(gm > 2.0f * pf->p.sigma_c)) return false;
    float d[3] = {g2[0] - g0[0], g2[1] - g0[1], g2[2] - g0[2]};
    float p1[3] = {gj[0] - g0[0], gj[1] - g0[1], gj[2] - g0[2]};
    float dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    if (!(dd > 0.0f)) return false;
    float ahat = (p1[0] * d[0] + p1[1] * d[1] + p1[2] * d[2]) / dd;
    ahat = ahat < 0.0f ? 0.0f : ahat > 1.0f ? 1.0f : ahat;
    float b2 = 0.0f;
    for (int k = 0; k < 3; ++k) {
        float e = p1[k] - ahat * d[k];
        b2 += e * e;
    }
    float wedge = sy_filter_expneg(0.5f * b2 / (pf->p.sigma_c * pf->p.sigma_c)); /* Eq. 3.20 */
    *ahat_out = ahat, *wedge_out = wedge;
    return wedge > 1e-3f;
}

/* Per filter pass (the guide and validity do not change between the separable iterations): the
 * AA-recovery edge test of both pass directions, edge[4 j + 2 dir] = ahat, [+1] = wedge (-1 where
 * the pixel is no edge pixel in that direction). */
static void edge_rows(void *vctx, uint32_t y0, uint32_t y1)
{
    sy_filter_pixel *pf = vctx;
    int w = (int)pf->w;
    for (int y = (int)y0; y < (int)y1; ++y)
        for (int x = 0; x < w; ++x) {
            size_t j = (size_t)y * w + x;
            for (int dir = 0; dir < 2; ++dir) {
                float *e = pf->edge + 4 * j + 2 * dir;
                if (!pf->gok[j] || !aa_edge(pf, dir, j, x, y, pf->guide + 4 * j, &e[0], &e[1])) e[0] = 0.0f, e[1] = -1.0f;
            }
        }
}

/* The centre pixel j of a 1D pass on an antialiased edge: three one-sided / centred range
 * windows combined by Eqs. 3.19, 3.20 (scalar, double accumulators; a few % of the pixels). */
static void sep_edge(const pass_ctx *c, size_t j, int lo, int hi, float inv2s, const float *gj, bool gj_ok, float ahat,
                     float wedge, const float *g0, const float *g2)
{
    const sy_filter_pixel *pf = c->pf;
    ptrdiff_t step = c->dir == 0 ? 1 : (ptrdiff_t)pf->w;
    float wa[MAX_TAPS], w0[MAX_TAPS], w2[MAX_TAPS];
    double Aa = 0, A0 = 0, A2 = 0;
    for (int t = lo; t <= hi; ++t) {
        size_t i = (size_t)((ptrdiff_t)j + t * step);
        float sp = (float)(t * t) * inv2s;
        int k = t - lo;
        wa[k] = w0[k] = w2[k] = 0.0f;
        if (!pf->ok[i]) continue;
        const float *gi = pf->guide + 4 * i;
        wa[k] = sy_filter_expneg(sp + (gj_ok ? range_arg(gj, gi, c->inv2c, c->inv2d) : 0.0f));
        Aa += wa[k];
        if (t <= -1) w0[k] = sy_filter_expneg(sp + range_arg(g0, gi, c->inv2c, c->inv2d)), A0 += w0[k];
        if (t >= 1) w2[k] = sy_filter_expneg(sp + range_arg(g2, gi, c->inv2c, c->inv2d)), A2 += w2[k];
    }
    /* combined normalised weights: L = w (1-a) L_0 + w a L_2 + (1-w) L_a (Eqs. 3.19, 3.20) */
    float ca = 1.0f, c0 = 0.0f, c2 = 0.0f;
    if (A0 > 0 && A2 > 0) ca = 1.0f - wedge, c0 = wedge * (1.0f - ahat), c2 = wedge * ahat;
    else if (A0 > 0 && ahat < 0.5f) ca = 1.0f - wedge, c0 = wedge;
    else if (A2 > 0 && ahat >= 0.5f) ca = 1.0f - wedge, c2 = wedge;
    double acc[4] = {0, 0, 0, 0}, rr = 0, cen = 0;
    if (Aa <= 0) ca = 0.0f;
    float sa = Aa > 0 ? ca / (float)Aa : 0.0f, s0 = A0 > 0 ? c0 / (float)A0 : 0.0f, s2 = A2 > 0 ? c2 / (float)A2 : 0.0f;
    float total = 0.0f;
    for (int t = lo; t <= hi; ++t) {
        int k = t - lo;
        float cw = sa * wa[k] + s0 * w0[k] + s2 * w2[k];
        if (cw == 0.0f) continue;
        size_t i = (size_t)((ptrdiff_t)j + t * step);
        for (int q = 0; q < 4; ++q) acc[q] += cw * c->src[q][i];
        rr += (double)cw * cw * (c->rsrc ? c->rsrc[i] : 1.0f);
        total += cw;
        if (t == 0) cen = cw;
    }
    if (total > 0.0f) {
        for (int q = 0; q < 4; ++q) c->dst[q][j] = (float)(acc[q] / total);
        c->rdst[j] = (float)(rr / ((double)total * total));
        if (c->a0) c->a0[j] *= (float)(cen / total);
    } else {
        for (int q = 0; q < 4; ++q) c->dst[q][j] = c->src[q][j];
        c->rdst[j] = c->rsrc ? c->rsrc[j] : 1.0f;
    }
}

/* 4-lane float vectors (GCC/Clang vector extensions: SSE2 on x86-64 without -march, NEON on
 * arm64). Every lane performs exactly the scalar operations in the scalar order, so the result
 * is bit-identical to a per-pixel loop; only the pixels run side by side. */
typedef float v4f __attribute__((vector_size(16)));
typedef int32_t v4i __attribute__((vector_size(16)));
static inline v4f v4_load(const float *p)
{
    v4f v;
    memcpy(&v, p, sizeof v);
    return v;
}
static inline v4f v4_splat(float x) { return (v4f){x, x, x, x}; }
static inline v4f v4_keep(v4i m, v4f a) { return (v4f)((v4i)a & m); } /* a where m, else +0 */

/* The tap weights of 4 centre pixels for offsets t = tlo..thi (tap index o0 + (t - tlo) step):
 * spatial + range argument, exp by linear interpolation in the table (relative error < 3e-5),
 * +0 outside each pixel's window, the image (horizontal) or on invalid taps. */
static inline __attribute__((always_inline)) void tap_weights(float *const G[4], const float *OK, ptrdiff_t o0,
                                                              ptrdiff_t step, int tlo, int thi, v4f cr, v4f cg, v4f cb,
                                                              v4f cd, v4f is, v4f rc, v4f rd, v4f lim, v4f xl, float wf,
                                                              bool horizontal, const float *T, v4f *wbuf)
{
    const float *g0 = G[0] + o0, *g1 = G[1] + o0, *g2 = G[2] + o0, *g3 = G[3] + o0, *ok = OK + o0;
    for (int t = tlo; t <= thi; ++t, g0 += step, g1 += step, g2 += step, g3 += step, ok += step) {
        v4f dr = cr - v4_load(g0), dg = cg - v4_load(g1), db = cb - v4_load(g2), dd = cd - v4_load(g3);
        v4f arg = v4_splat((float)(t * t)) * is + (dr * dr + dg * dg + db * db) * rc + dd * dd * rd;
        v4f xs = arg * v4_splat(EXP_SCALE);
        v4i in_t = xs < v4_splat((float)EXP_TABLE);
        xs = (v4f)(((v4i)xs & in_t) | ((v4i)v4_splat((float)EXP_TABLE) & ~in_t)); /* NaN too */
        v4i ix = __builtin_convertvector(xs, v4i);
        v4f fr = xs - __builtin_convertvector(ix, v4f);
        v4f e0 = {T[ix[0]], T[ix[1]], T[ix[2]], T[ix[3]]};
        v4f e1 = {T[ix[0] + 1], T[ix[1] + 1], T[ix[2] + 1], T[ix[3] + 1]};
        v4f a = e0 + fr * (e1 - e0);
        v4i m = (v4_load(ok) != v4_splat(0.0f)) & (v4_splat((float)abs(t)) <= lim);
        if (horizontal) {
            v4f xt = xl + v4_splat((float)t);
            m &= (xt >= v4_splat(0.0f)) & (xt < v4_splat(wf));
        }
        wbuf[t - tlo] = v4_keep(m, a);
    }
}

/* acc = {W, sum a v0..v3, sum a^2 r} += the n taps' weighted values (r = 1 without R) */
static inline __attribute__((always_inline)) void tap_sums(const float *const S[4], const float *R, ptrdiff_t o0,
                                                           ptrdiff_t step, int n, const v4f *wbuf, v4f acc[6], bool have_r)
{
    const float *s0 = S[0] + o0, *s1 = S[1] + o0, *s2 = S[2] + o0, *s3 = S[3] + o0, *r = have_r ? R + o0 : NULL;
    v4f W = acc[0], A0 = acc[1], A1 = acc[2], A2 = acc[3], A3 = acc[4], RR = acc[5];
    for (int k = 0; k < n; ++k, s0 += step, s1 += step, s2 += step, s3 += step) {
        v4f a = wbuf[k];
        W += a;
        A0 += a * v4_load(s0), A1 += a * v4_load(s1), A2 += a * v4_load(s2), A3 += a * v4_load(s3);
        if (have_r) {
            RR += a * a * v4_load(r);
            r += step;
        } else
            RR += a * a;
    }
    acc[0] = W, acc[1] = A0, acc[2] = A1, acc[3] = A2, acc[4] = A3, acc[5] = RR;
}

enum { SEG = 256 }; /* pixels of a row prepared at once (stack arrays) */

/* One 1D pass of the iterated separable filter (Sec. 3.6.1) with antialiasing recovery
 * (Sec. 3.6.5). The guide is always the original range buffer (cross filter). r propagates
 * exactly for independent inputs: r_out(j) = sum_i (a_i/A)^2 r_in(i).
 * Layout: planar (src/dst/guide/ok planes), 4 neighbouring centre pixels of a row per vector;
 * for a tap offset t their taps are 4 consecutive floats in both directions (horizontal: at
 * x + t; vertical: in row y + t), so each tap costs one vector step for 4 pixels. Lanes outside
 * a pixel's window (its own sigma, the image, invalid pixels) get weight +0, which leaves every
 * sum unchanged. Edge pixels (AA recovery) and near-identity pixels are done per pixel. */
static inline __attribute__((always_inline)) void sep_rows_body(void *vctx, uint32_t y0, uint32_t y1)
{
    pass_ctx *c = vctx;
    sy_filter_pixel *pf = c->pf;
    int w = (int)pf->w, h = (int)pf->h, dir = c->dir;
    bool aa = pf->p.aa_recovery;
    const float *OK = pf->okf, *RS = c->rsrc;
    enum { K_VEC, K_IDENT, K_EDGE };
    float rlim[SEG + 4], i2s[SEG + 4], rcv[SEG + 4], rdv[SEG + 4], crv[SEG + 4], cgv[SEG + 4], cbv[SEG + 4], cdv[SEG + 4];
    uint8_t kind[SEG + 4];
    float ahat[SEG], wedge[SEG];
    v4f wbuf[MAX_TAPS + 4];
    for (int y = (int)y0; y < (int)y1; ++y)
        for (int xs0 = 0; xs0 < w; xs0 += SEG) {
            int xs1 = xs0 + SEG < w ? xs0 + SEG : w;
            /* per-pixel set-up: sigma, window, range factors, AA edge test */
            for (int x = xs0; x < xs1 + 4; ++x) {
                int q = x - xs0;
                if (x >= xs1) { /* lanes past the segment: no taps */
                    rlim[q] = -1.0f, i2s[q] = rcv[q] = rdv[q] = crv[q] = cgv[q] = cbv[q] = cdv[q] = 0.0f, kind[q] = K_IDENT;
                    continue;
                }
                size_t j = (size_t)y * w + x;
                float sg = pf->sigma[j] * c->sig_scale;
                if (sg < 0.3f) { /* neighbour weights < exp(-5.5): the pass is the identity here */
                    rlim[q] = -1.0f, i2s[q] = rcv[q] = rdv[q] = crv[q] = cgv[q] = cbv[q] = cdv[q] = 0.0f, kind[q] = K_IDENT;
                    continue;
                }
                int R = radius_of(sg);
                if (R > (MAX_TAPS - 1) / 2) R = (MAX_TAPS - 1) / 2;
                const float *gj = pf->guide + 4 * j;
                bool gj_ok = pf->gok[j];
                i2s[q] = 0.5f / (sg * sg);
                /* a centre without a finite guide (a NaN/Inf pixel) gets spatial weights only, as in
                 * brute_rows: range factors 0 and a zero centre colour, so 0 * (finite)^2 = 0 */
                rcv[q] = gj_ok ? c->inv2c : 0.0f, rdv[q] = gj_ok ? c->inv2d : 0.0f, cdv[q] = gj_ok ? gj[3] : 0.0f;
                crv[q] = gj_ok ? gj[0] : 0.0f, cgv[q] = gj_ok ? gj[1] : 0.0f, cbv[q] = gj_ok ? gj[2] : 0.0f;
                rlim[q] = (float)R, kind[q] = K_VEC;
                if (aa && gj_ok && pf->edge[4 * j + 2 * dir + 1] >= 0.0f) {
                    ahat[q] = pf->edge[4 * j + 2 * dir], wedge[q] = pf->edge[4 * j + 2 * dir + 1];
                    kind[q] = K_EDGE;
                    rlim[q] = -1.0f;
                }
            }
            for (int x = xs0; x < xs1; x += 4) {
                int q = x - xs0;
                size_t j = (size_t)y * w + x;
                float rmax = rlim[q];
                for (int l = 1; l < 4; ++l) rmax = rlim[q + l] > rmax ? rlim[q + l] : rmax;
                v4f W = v4_splat(0.0f), A0 = W, A1 = W, A2 = W, A3 = W, RR = W;
                if (rmax >= 0.0f) {
                    int R = (int)rmax, tlo = -R, thi = R;
                    if (dir == 0) {
                        if (tlo < -(x + 3)) tlo = -(x + 3);
                        if (thi > w - 1 - x) thi = w - 1 - x;
                    } else {
                        if (tlo < -y) tlo = -y;
                        if (thi > h - 1 - y) thi = h - 1 - y;
                    }
                    v4f cr = v4_load(crv + q), cg = v4_load(cgv + q), cb = v4_load(cbv + q), cd = v4_load(cdv + q);
                    v4f is = v4_load(i2s + q), rc = v4_load(rcv + q), rd = v4_load(rdv + q), lim = v4_load(rlim + q);
                    v4f xl = {(float)x, (float)(x + 1), (float)(x + 2), (float)(x + 3)};
                    ptrdiff_t step = dir == 0 ? 1 : w, o0 = (ptrdiff_t)j + (ptrdiff_t)tlo * step;
                    /* two loops (weights, then sums) keep each one's vectors in registers; each is
                     * specialised for its direction / r input (constant arguments after inlining) */
                    if (dir == 0)
                        tap_weights(pf->gpl, OK, o0, 1, tlo, thi, cr, cg, cb, cd, is, rc, rd, lim, xl, (float)w, true,
                                    pf->expt, wbuf);
                    else
                        tap_weights(pf->gpl, OK, o0, step, tlo, thi, cr, cg, cb, cd, is, rc, rd, lim, xl, (float)w, false,
                                    pf->expt, wbuf);
                    v4f acc[6] = {W, A0, A1, A2, A3, RR};
                    if (RS)
                        tap_sums(c->src, RS, o0, step, thi - tlo + 1, wbuf, acc, true);
                    else
                        tap_sums(c->src, RS, o0, step, thi - tlo + 1, wbuf, acc, false);
                    W = acc[0], A0 = acc[1], A1 = acc[2], A2 = acc[3], A3 = acc[4], RR = acc[5];
                }
                for (int l = 0; l < 4 && x + l < xs1; ++l) {
                    size_t jl = j + (size_t)l;
                    int ql = q + l;
                    if (kind[ql] == K_VEC && W[l] > 0.0f) {
                        float iw = 1.0f / W[l];
                        c->dst[0][jl] = A0[l] * iw, c->dst[1][jl] = A1[l] * iw, c->dst[2][jl] = A2[l] * iw;
                        c->dst[3][jl] = A3[l] * iw;
                        c->rdst[jl] = RR[l] * iw * iw;
                        if (c->a0) c->a0[jl] *= (pf->ok[jl] ? 1.0f : 0.0f) * iw;
                    } else if (kind[ql] == K_EDGE) {
                        int pos = dir == 0 ? x + l : y, len = dir == 0 ? w : h;
                        int R = radius_of(pf->sigma[jl] * c->sig_scale);
                        if (R > (MAX_TAPS - 1) / 2) R = (MAX_TAPS - 1) / 2;
                        int lo = pos - R < 0 ? -pos : -R, hi = pos + R >= len ? len - 1 - pos : R;
                        ptrdiff_t st = dir == 0 ? 1 : w;
                        sep_edge(c, jl, lo, hi, i2s[ql], pf->guide + 4 * jl, true, ahat[ql], wedge[ql],
                                 pf->guide + 4 * (jl - st), pf->guide + 4 * (jl + st));
                    } else { /* identity, or no valid tap */
                        for (int k = 0; k < 4; ++k) c->dst[k][jl] = c->src[k][jl];
                        c->rdst[jl] = RS ? RS[jl] : 1.0f;
                    }
                }
            }
            if (dir == 1) /* end of an iteration: fold r_k into the composition (see filter_pass) */
                for (size_t j = (size_t)y * w + xs0; j < (size_t)y * w + xs1; ++j) {
                    float rk = c->rdst[j]; /* finite: ternaries = fmaxf/fminf here, without the calls */
                    pf->inv[j] += 1.0f / (rk > 1e-12f ? rk : 1e-12f) - 1.0f;
                    pf->rmin[j] = rk < pf->rmin[j] ? rk : pf->rmin[j];
                    if (c->last) {
                        float *lf = pf->lf + 4 * j;
                        for (int k = 0; k < 4; ++k) lf[k] = c->dst[k][j];
                        memcpy(pf->lf3 + 3 * j, lf, 3 * sizeof(float));
                        pf->r[j] = fmaxf(1.0f / (1.0f + pf->inv[j]), pf->rmin[j]);
                    }
                }
        }
}

/* The same code compiled twice: for the baseline ISA and, on x86-64, for AVX2 (VEX 3-operand
 * forms: about 28% fewer instructions), picked at run time. Only "avx2" is enabled, never FMA, so
 * no multiply-add is contracted and both give bit-identical results. */
static void sep_rows(void *vctx, uint32_t y0, uint32_t y1)
{
    sep_rows_body(vctx, y0, y1);
}
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
__attribute__((target("avx2"))) static void sep_rows_avx2(void *vctx, uint32_t y0, uint32_t y1)
{
    sep_rows_body(vctx, y0, y1);
}
static sy_filter_rows_fn sep_rows_best(void)
{
    return __builtin_cpu_supports("avx2") ? sep_rows_avx2 : sep_rows;
}
#else
static sy_filter_rows_fn sep_rows_best(void) { return sep_rows; }
#endif

typedef struct box_ctx {
    const float *src;
    const uint8_t *ok;
    float *dst, *tmp;
    int w, h, R;
} box_ctx;

static void box_h_rows(void *vctx, uint32_t y0, uint32_t y1)
{
    box_ctx *b = vctx;
    int w = b->w, R = b->R;
    for (int y = (int)y0; y < (int)y1; ++y) {
        const float *src = b->src + (size_t)y * w;
        const uint8_t *ok = b->ok + (size_t)y * w;
        for (int x = 0; x < w; ++x) {
            double s = 0;
            int n = 0, lo = x - R < 0 ? -x : -R, hi = x + R >= w ? w - 1 - x : R;
            for (int t = lo; t <= hi; ++t)
                if (ok[x + t]) s += src[x + t], ++n;
            b->tmp[(size_t)y * w + x] = n ? (float)(s / n) : NAN;
        }
    }
}

static void box_v_rows(void *vctx, uint32_t y0, uint32_t y1)
{
    box_ctx *b = vctx;
    int w = b->w, h = b->h, R = b->R;
    for (int y = (int)y0; y < (int)y1; ++y) {
        int lo = y - R < 0 ? -y : -R, hi = y + R >= h ? h - 1 - y : R;
        for (int x = 0; x < w; ++x) {
            double s = 0;
            int n = 0;
            for (int t = lo; t <= hi; ++t) {
                float v = b->tmp[(size_t)(y + t) * w + x];
                if (!isnan(v)) s += v, ++n;
            }
            b->dst[(size_t)y * w + x] = n ? (float)(s / n) : 0.0f;
        }
    }
}

/* separable (2R+1)^2 box mean over valid pixels, row-parallel */
static void box_masked(uint32_t threads, const float *src, const uint8_t *ok, float *dst, float *tmp, int w, int h,
                       int R)
{
    box_ctx b = {src, ok, dst, tmp, w, h, R};
    sy_filter_parallel_rows(threads, (uint32_t)h, box_h_rows, &b);
    sy_filter_parallel_rows(threads, (uint32_t)h, box_v_rows, &b);
}

static void free_buffers(sy_filter_pixel *pf)
{
    free(pf->guide), free(pf->ok), free(pf->gok), free(pf->edge), free(pf->planes), free(pf->inv), free(pf->rmin), free(pf->sigma), free(pf->lf);
    free(pf->r), free(pf->a0), free(pf->npass), free(pf->s), free(pf->lf3);
    pf->guide = pf->planes = pf->inv = pf->rmin = pf->sigma = pf->lf = pf->r = pf->a0 = pf->npass = pf->s = NULL;
    pf->lf3 = pf->edge = NULL, pf->ok = pf->gok = NULL;
}

void sy_filter_pixel_destroy(sy_filter_pixel *pf)
{
    if (!pf) return;
    free_buffers(pf);
    free(pf);
}

sy_filter_status sy_filter_pixel_create(const sy_filter_pixel_params *p, sy_filter_pixel **out, sy_filter_report *err)
{
    if (!out) return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "pixel filter: out is NULL");
    *out = NULL;
    sy_filter_pixel_params d;
    if (!p) sy_filter_pixel_params_default(&d), p = &d;
    sy_filter_status s = sy_filter_pixel_params_check(p, err);
    if (s) return s;
    sy_filter_pixel *pf = calloc(1, sizeof *pf);
    if (!pf) return sy_filter_fail(err, SY_FILTER_ERROR_OUT_OF_MEMORY, "pixel filter: out of memory");
    pf->p = *p;
    for (int i = 0; i <= EXP_TABLE + 1; ++i) pf->expt[i] = i >= EXP_TABLE ? 0.0f : expf(-(float)i / EXP_SCALE);
    *out = pf;
    return SY_FILTER_OK;
}

sy_filter_status sy_filter_pixel_set_params(sy_filter_pixel *pf, const sy_filter_pixel_params *p, sy_filter_report *err)
{
    if (!pf) return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "pixel filter: object is NULL");
    sy_filter_status s = sy_filter_pixel_params_check(p, err);
    if (s == SY_FILTER_OK) pf->p = *p; /* the filtered buffer stays valid; new sigmas apply next pass */
    return s;
}

void sy_filter_pixel_reset(sy_filter_pixel *pf)
{
    if (pf) pf->have_pass = false;
}

const float *sy_filter_pixel_blend(const sy_filter_pixel *pf) { return pf && pf->have_pass ? pf->s : NULL; }
const float *sy_filter_pixel_reduction(const sy_filter_pixel *pf) { return pf && pf->have_pass ? pf->r : NULL; }
const float *sy_filter_pixel_filtered(const sy_filter_pixel *pf) { return pf && pf->have_pass ? pf->lf3 : NULL; }

static sy_filter_status ensure_size(sy_filter_pixel *pf, uint32_t w, uint32_t h, sy_filter_report *err)
{
    if (pf->w == w && pf->h == h && pf->guide) return SY_FILTER_OK;
    free_buffers(pf);
    pf->have_pass = false;
    size_t n = (size_t)w * h, plen = n + 2 * SLACK;
    pf->guide = malloc(4 * n * sizeof(float));
    pf->ok = malloc(n);
    pf->gok = malloc(n);
    pf->edge = malloc(4 * n * sizeof(float));
    pf->planes = calloc(PL_COUNT * plen, sizeof(float)); /* zeroed slack: masked lanes read zeros */
    pf->inv = malloc(n * sizeof(float));
    pf->rmin = malloc(n * sizeof(float));
    pf->sigma = malloc(n * sizeof(float));
    pf->lf = malloc(4 * n * sizeof(float));
    pf->r = malloc(n * sizeof(float));
    pf->a0 = malloc(n * sizeof(float));
    pf->npass = malloc(n * sizeof(float));
    pf->s = malloc(n * sizeof(float));
    pf->lf3 = malloc(3 * n * sizeof(float));
    if (!pf->guide || !pf->ok || !pf->gok || !pf->edge || !pf->planes || !pf->inv || !pf->rmin || !pf->sigma || !pf->lf || !pf->r || !pf->a0 ||
        !pf->npass || !pf->s || !pf->lf3) {
        free_buffers(pf);
        pf->w = pf->h = 0;
        return sy_filter_fail(err, SY_FILTER_ERROR_OUT_OF_MEMORY, "pixel filter: out of memory for %ux%u", w, h);
    }
    for (int k = 0; k < 4; ++k) {
        pf->gpl[k] = pf->planes + (PL_G + k) * plen + SLACK;
        pf->val[k] = pf->planes + (PL_V + k) * plen + SLACK;
        pf->tmp[k] = pf->planes + (PL_T + k) * plen + SLACK;
        pf->oth[k] = pf->planes + (PL_B + k) * plen + SLACK;
    }
    pf->okf = pf->planes + PL_OK * plen + SLACK;
    pf->rtmp = pf->planes + PL_RT * plen + SLACK;
    pf->racc = pf->planes + PL_RA * plen + SLACK;
    pf->w = w, pf->h = h;
    return SY_FILTER_OK;
}

static void hv_lv(const sy_filter_pixel *pf, const sy_filter_frame *in, size_t i, float hv[3], float lv[3])
{
    if (!pf->p.all_high_variance && in->direct && in->indirect) {
        for (int c = 0; c < 3; ++c) hv[c] = in->indirect[3 * i + c], lv[c] = in->direct[3 * i + c];
    } else {
        for (int c = 0; c < 3; ++c) hv[c] = in->color[(size_t)in->color_channels * i + c], lv[c] = 0.0f;
    }
}

typedef struct prep_ctx {
    sy_filter_pixel *pf;
    const sy_filter_frame *in;
    uint32_t need;
    const float *bv, *bl; /* adaptive width: smoothed variance of the mean and luminance */
    float s0;
    atomic_bool any_single; /* some valid pixel has fewer than 2 samples */
    atomic_uint_least64_t bad; /* scan: NaN/Inf pixels */
} prep_ctx;

static void scan_rows(void *vctx, uint32_t y0, uint32_t y1)
{
    prep_ctx *c = vctx;
    uint64_t bad = sy_filter_scan_finite_rows(c->in, c->need, c->pf->ok, y0, y1);
    if (bad) atomic_fetch_add(&c->bad, bad);
}

/* filter input: the range buffer (given or composed), its planar copy, HV RGB + per-sample
 * variance planes, validity, spp at the pass, and the per-pass state of the r composition */
static void prep_rows(void *vctx, uint32_t y0, uint32_t y1)
{
    prep_ctx *c = vctx;
    sy_filter_pixel *pf = c->pf;
    const sy_filter_frame *in = c->in;
    size_t i0 = (size_t)y0 * pf->w, i1 = (size_t)y1 * pf->w;
    if (in->range) {
        for (size_t i = i0; i < i1; ++i) {
            memcpy(pf->guide + 4 * i, in->range + 4 * i, 4 * sizeof(float));
            if (pf->guide[4 * i + 3] > MISS_DEPTH) pf->guide[4 * i + 3] = MISS_DEPTH;
        }
    } else
        compose_rows(in, in->has_camera ? in->camera_position : NULL, pf->p.headlight_weight, pf->guide, y0, y1);
    bool single = false;
    for (size_t i = i0; i < i1; ++i) {
        float hv[3], lv[3], v[4];
        hv_lv(pf, in, i, hv, lv);
        v[0] = hv[0], v[1] = hv[1], v[2] = hv[2];
        v[3] = sy_filter_pixel_variance(in, i) * sy_filter_pixel_spp(in, i);
        const float *g = pf->guide + 4 * i;
        pf->gok[i] = guide_ok(g);
        bool ok = pf->ok[i] && pf->gok[i];
        for (int k = 0; k < 4 && ok; ++k) ok = isfinite(v[k]);
        pf->ok[i] = ok;
        pf->okf[i] = ok ? 1.0f : 0.0f;
        for (int k = 0; k < 4; ++k) pf->val[k][i] = ok ? v[k] : 0.0f, pf->gpl[k][i] = g[k];
        pf->npass[i] = sy_filter_pixel_spp(in, i);
        single = single || (ok && pf->npass[i] < 2.0f);
        pf->inv[i] = 0.0f, pf->rmin[i] = 1.0f, pf->a0[i] = 1.0f;
        if (!pf->p.adaptive_width) pf->sigma[i] = pf->p.sigma_s;
    }
    if (single) atomic_store(&c->any_single, true);
}

/* [GAP spec 1.2] single-sample variance, step 1: HV luminance of valid pixels */
static void lum_rows(void *vctx, uint32_t y0, uint32_t y1)
{
    sy_filter_pixel *pf = ((prep_ctx *)vctx)->pf;
    for (size_t i = (size_t)y0 * pf->w; i < (size_t)y1 * pf->w; ++i) {
        float v[3] = {pf->val[0][i], pf->val[1][i], pf->val[2][i]};
        pf->tmp[0][i] = pf->ok[i] ? sy_filter_luminance(v) : 0.0f;
    }
}

/* step 2: squared deviation from the 5x5 mean (tmp[1]) where n < 2 */
static void single_var_rows(void *vctx, uint32_t y0, uint32_t y1)
{
    sy_filter_pixel *pf = ((prep_ctx *)vctx)->pf;
    for (size_t i = (size_t)y0 * pf->w; i < (size_t)y1 * pf->w; ++i)
        if (pf->ok[i] && pf->npass[i] < 2.0f) {
            float d = pf->tmp[0][i] - pf->tmp[1][i];
            pf->val[3][i] = d * d * 25.0f / 24.0f;
        }
}

/* adaptive width inputs: variance of the mean (tmp[0]) and background luminance (tmp[1]) */
static void adapt_in_rows(void *vctx, uint32_t y0, uint32_t y1)
{
    prep_ctx *c = vctx;
    sy_filter_pixel *pf = c->pf;
    for (size_t i = (size_t)y0 * pf->w; i < (size_t)y1 * pf->w; ++i) {
        float hv[3], lv[3];
        hv_lv(pf, c->in, i, hv, lv);
        pf->tmp[0][i] = pf->ok[i] ? pf->val[3][i] / pf->npass[i] : 0.0f;
        pf->tmp[1][i] = pf->ok[i] ? sy_filter_luminance(hv) + sy_filter_luminance(lv) : 0.0f;
    }
}

/* Eqs. 3.15-3.17 per pixel from the box-smoothed u */
static void sigma_rows(void *vctx, uint32_t y0, uint32_t y1)
{
    prep_ctx *c = vctx;
    sy_filter_pixel *pf = c->pf;
    const sy_filter_pixel_params *p = &pf->p;
    for (size_t i = (size_t)y0 * pf->w; i < (size_t)y1 * pf->w; ++i) {
        float L = fmaxf(c->bl[i], 1e-6f);
        float u = c->bv[i] / (L * L);
        /* [GAP spec 1.10(b)]: the target f of Eq. 3.15 is the threshold t (perceived units) */
        float tgt = fmaxf(p->threshold, 1e-6f);
        float e = 0.5f * sqrtf(u / tgt) - 0.5f;
        float sg = 1.5f * (e > 0.0f ? e : 0.0f);
        float guide = c->s0 / sqrtf(fmaxf(pf->npass[i], 1.0f)); /* Eq. 3.17, n >= 1 */
        float lo = guide / p->adaptive_c, hi = guide * p->adaptive_c;
        sg = sg < lo ? lo : sg > hi ? hi : sg; /* Eq. 3.16 */
        if (sg > p->sigma_s) sg = p->sigma_s;
        pf->sigma[i] = sg < 0.25f ? 0.25f : sg;
    }
}

static void filter_pass(sy_filter_pixel *pf, const sy_filter_frame *in)
{
    const sy_filter_pixel_params *p = &pf->p;
    int w = (int)pf->w, h = (int)pf->h;
    /* filter input: HV RGB + per-sample variance (variance of the mean times n, spec 1.2 [GAP]:
     * the smoothed per-sample variance is stored so the blend can divide by the current n) */
    prep_ctx pc = {.pf = pf, .in = in};
    atomic_init(&pc.any_single, false);
    atomic_init(&pc.bad, 0);
    sy_filter_parallel_rows(pf->p.threads, pf->h, prep_rows, &pc);
    /* [GAP spec 1.2, variance before two samples]: Welford gives no variance at 1 spp. There the
     * per-sample variance is taken as the squared deviation of the pixel's HV luminance from its
     * 5x5 neighbourhood mean; the bilateral pass smooths it like any variance estimate. */
    if (atomic_load(&pc.any_single)) {
        sy_filter_parallel_rows(pf->p.threads, pf->h, lum_rows, &pc);
        box_masked(pf->p.threads, pf->tmp[0], pf->ok, pf->tmp[1], pf->tmp[2], w, h, 2);
        sy_filter_parallel_rows(pf->p.threads, pf->h, single_var_rows, &pc);
    }
    /* spatial sigma per pixel: fixed (set in prep_rows), or adaptive (Sec. 3.6.3, Eqs. 3.15-3.17) */
    if (p->adaptive_width) {
        /* u from 5x5 box-smoothed variance of the mean and background luminance (raw early
         * estimates differ too much between neighbours to size kernels from) */
        sy_filter_parallel_rows(pf->p.threads, pf->h, adapt_in_rows, &pc);
        box_masked(pf->p.threads, pf->tmp[0], pf->ok, pf->oth[0], pf->oth[2], w, h, 2);
        box_masked(pf->p.threads, pf->tmp[1], pf->ok, pf->oth[1], pf->oth[2], w, h, 2);
        float s0 = p->adaptive_sigma0 > 0.0f ? p->adaptive_sigma0 : 2.0f * p->sigma_s; /* [GAP spec 1.10(b)]:
                                           sigma_bar(0) = 2 sigma_s, so the guide equals sigma_s at frame 4 */
        pc.bv = pf->oth[0], pc.bl = pf->oth[1], pc.s0 = s0;
        sy_filter_parallel_rows(pf->p.threads, pf->h, sigma_rows, &pc);
    }
    pass_ctx c = {.pf = pf, .inv2c = 0.5f / (p->sigma_c * p->sigma_c), .inv2d = 0.5f / (p->sigma_d * p->sigma_d)};
    if (p->kernel == SY_FILTER_PIXEL_BRUTE) {
        for (int k = 0; k < 4; ++k) c.src[k] = pf->val[k];
        c.dst[0] = pf->lf, c.rdst = pf->r, c.a0 = pf->a0;
        sy_filter_parallel_rows(pf->p.threads, pf->h, brute_rows, &c);
    } else {
        /* Eq. 3.14: sigma_k = sigma sqrt(3) 2^(N-k) / sqrt(4^N - 1); sum of squares = sigma^2 */
        uint32_t N = p->iterations;
        float norm = sqrtf(3.0f) / sqrtf(powf(4.0f, (float)N) - 1.0f);
        float **cur = pf->val, **other = pf->oth;
        if (p->aa_recovery) sy_filter_parallel_rows(pf->p.threads, pf->h, edge_rows, pf);
        sy_filter_rows_fn sep = sep_rows_best();
        /* [GAP spec 1.10(a)]: r of the iterated filter. One separable iteration propagates r
         * exactly (r_k); iterations compose like convolved Gaussians, whose 1/r add up:
         * 1/r - 1 = sum_k (1/r_k - 1) (exact for untruncated Gaussians, 1 for a no-op kernel).
         * Where windows are cut (image border, range edges) repeated averaging of the same few
         * pixels gains nothing, so r is bounded below by the smallest single-iteration r_k.
         * (inv and rmin are folded in at the end of each vertical pass, lf/r/lf3 written by
         * the last one.) */
        for (uint32_t k = 1; k <= N; ++k) {
            c.sig_scale = norm * powf(2.0f, (float)(N - k));
            c.a0 = k == N ? pf->a0 : NULL;
            for (int q = 0; q < 4; ++q) c.src[q] = cur[q], c.dst[q] = pf->tmp[q];
            c.rsrc = NULL, c.rdst = pf->rtmp, c.dir = 0, c.last = false;
            sy_filter_parallel_rows(pf->p.threads, pf->h, sep, &c);
            for (int q = 0; q < 4; ++q) c.src[q] = pf->tmp[q], c.dst[q] = other[q];
            c.rsrc = pf->rtmp, c.rdst = pf->racc, c.dir = 1, c.last = k == N;
            sy_filter_parallel_rows(pf->p.threads, pf->h, sep, &c);
            float **t = cur;
            cur = other, other = t;
        }
    }
    pf->have_pass = true;
}

typedef struct blend_ctx {
    sy_filter_pixel *pf;
    const sy_filter_frame *in;
    float *out;
} blend_ctx;

static void blend_rows(void *vctx, uint32_t y0, uint32_t y1)
{
    blend_ctx *b = vctx;
    sy_filter_pixel *pf = b->pf;
    const sy_filter_frame *in = b->in;
    const sy_filter_pixel_params *p = &pf->p;
    for (size_t i = (size_t)y0 * pf->w; i < (size_t)y1 * pf->w; ++i) {
        float hv[3], lv[3], *o = b->out + 4 * i;
        hv_lv(pf, in, i, hv, lv);
        o[3] = in->color_channels == 4 ? in->color[4 * i + 3] : 1.0f;
        if (!isfinite(o[3])) o[3] = 1.0f;
        bool own_ok = pf->ok[i];
        const float *col = in->color + (size_t)in->color_channels * i;
        if (!pf->have_pass) { /* the unfiltered estimate itself (bit-exact, not LV + HV rounded) */
            for (int c = 0; c < 3; ++c) o[c] = own_ok ? col[c] : 0.0f;
            continue;
        }
        const float *lf = pf->lf + 4 * i;
        if (!own_ok) { /* NaN/Inf pixel: show the neighbourhood's filtered value only */
            bool lv_ok = isfinite(lv[0]) && isfinite(lv[1]) && isfinite(lv[2]);
            for (int c = 0; c < 3; ++c) o[c] = (lv_ok ? lv[c] : 0.0f) + lf[c];
            pf->s[i] = 0.0f;
            continue;
        }
        /* Eq. 3.10: L_b = L_f + L_lv, evaluated with the current L_lv (luminance, spec 1.2 [GAP]) */
        float lb = sy_filter_luminance(lf) + sy_filter_luminance(lv);
        float lb2 = lb * lb > 1e-12f ? lb * lb : 1e-12f;
        float n_now = sy_filter_pixel_spp(in, i);
        float u = lf[3] / n_now / lb2;                 /* smoothed Var[L_u] now (Sec. 3.3.2) */
        float f = pf->r[i] * lf[3] / pf->npass[i] / lb2; /* Eq. 3.5 at the pass's sample count */
        float cov = p->use_covariance ? pf->a0[i] * lf[3] / pf->npass[i] / lb2 : 0.0f;
        float s = sy_filter_blend_factor(u, f, p->threshold, cov);
        pf->s[i] = s;
        if (s >= 1.0f) { /* converged under the threshold: exactly the unfiltered estimate */
            for (int c = 0; c < 3; ++c) o[c] = col[c];
            continue;
        }
        for (int c = 0; c < 3; ++c) {
            float lu = hv[c];
            /* Eq. 3.18 spike withholding; [GAP spec 1.10(c)]: per RGB channel, and only while the
             * blend still mixes (s < 1) so the converged output stays exactly unbiased */
            if (p->spike_withholding && s < 1.0f) {
                float loc = lf[c] / p->spike_c, hic = lf[c] * p->spike_c;
                lu = lu < loc ? loc : lu > hic ? hic : lu;
            }
            o[c] = lv[c] + s * lu + (1.0f - s) * lf[c];
        }
    }
}

sy_filter_status sy_filter_pixel_run(sy_filter_pixel *pf, const sy_filter_frame *in, uint32_t frame, bool force_pass,
                                     float *out, sy_filter_stats *stats, sy_filter_report *err)
{
    double t0 = sy_filter_clock(false);
    if (!pf) return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "pixel filter: object is NULL");
    if (!out) return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "pixel filter: output is NULL");
    uint32_t need = SY_FILTER_NEED_COLOR | SY_FILTER_NEED_VARIANCE;
    if (!in || !in->range) need |= SY_FILTER_NEED_ALBEDO | SY_FILTER_NEED_DEPTH;
    sy_filter_status s = sy_filter_check_frame(in, need, "pixel filter", err);
    if (s) return s;
    if (pf->w != in->width || pf->h != in->height) {
        if ((s = ensure_size(pf, in->width, in->height, err))) return s;
    }
    if (!pf->p.all_high_variance && in->direct && in->indirect) need |= SY_FILTER_NEED_SPLIT;
    prep_ctx sc = {.pf = pf, .in = in, .need = need};
    atomic_init(&sc.any_single, false);
    atomic_init(&sc.bad, 0);
    sy_filter_parallel_rows(pf->p.threads, pf->h, scan_rows, &sc);
    uint64_t bad = atomic_load(&sc.bad);
    bool pass = force_pass || sy_filter_pixel_scheduled(&pf->p, frame);
    if (pass) filter_pass(pf, in);
    blend_ctx b = {.pf = pf, .in = in, .out = out};
    sy_filter_parallel_rows(pf->p.threads, pf->h, blend_rows, &b);
    if (stats) {
        size_t n = (size_t)pf->w * pf->h;
        double ssum = 0;
        if (pf->have_pass)
            for (size_t i = 0; i < n; ++i) ssum += pf->s[i];
        stats->nonfinite_samples = bad;
        stats->filtered_pixels = pf->have_pass ? n : 0;
        stats->filter_pass = pass;
        stats->mean_blend = pf->have_pass ? ssum / (double)n : 1.0;
        stats->seconds = sy_filter_clock(false) - t0;
    }
    return SY_FILTER_OK;
}
