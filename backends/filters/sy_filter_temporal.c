/* sy_filter_temporal.c — temporal reuse for moving progressive frames: reprojection, history
 * clamping in YCoCg, moving averages of colour and moments, variance-guided a-trous; see
 * sy_filter_temporal.h.
 *
 * Layout for speed (an interactive frame's budget is a few ms): every per-pixel quantity is a
 * float plane (structure of arrays), the frame's own values are copied into planes once (misses and
 * bad pixels as finite zeros, so that a masked neighbour multiplies a finite value by 0), and the
 * neighbourhood passes (3x3 statistics, variance blur, a-trous) run tap by tap over whole rows: for
 * one tap (dx, dy) the loop over x has no branch, no division and contiguous loads, and GCC
 * vectorises it (-ftree-vectorize, CMakeLists.txt; check with -fopt-info-vec). A neighbour of
 * another class (hit with a normal, hit without one, none) gets weight 0 through a select. Per
 * pixel, the taps are summed in the order the scalar version summed them (centre, then dy, dx
 * row-major), so results do not depend on the vector width or the thread count. The reprojection
 * (4 gathered taps of the previous history per pixel), which GCC does not vectorise, has an AVX2
 * version beside the scalar loop (sy_filter_temporal_reproject.c). Passes that
 * stream the same planes run together: the direct and indirect parts share each variance blur and
 * a-trous pass (atrous_row8_2: the class, depth and normal terms once; the 3x3 statistics of both
 * parts in one loop took more instructions, 31 M against 27 M a frame: the loop's 30 streams spill
 * registers), the demodulation writes the next history's positions and normals (also the a-trous
 * passes' normal planes), the first a-trous pass of the indirect part writes into the next history
 * and the blend of the direct part too (no copies).
 *
 * Memory: planes plane_stride apart (not a multiple of 4 KiB: the same pixel of 60 planes would share
 * one L1 set), the a-trous passes prefetch the next 128 columns of every plane they read
 * (prefetch_cols: more streams than the hardware prefetchers follow), and the integration pass
 * keeps its per-block statistics and reprojected history in stack scratch (docs/FILTERS.md, "The
 * memory pass": with the variance blur computed row by row inside the a-trous pass, the stage
 * 29.6 -> 22.2 ms per 640x360 frame on 2 cores, bit for bit the same).
 *
 * Cost per 640x360 frame (callgrind, `sy bench temporal ... --cost-frames 2`, the stage with its
 * feature buffers' read): about 500 M instructions before these (the reprojection 142 M scalar,
 * the a-trous 132 M, the read 46 M single-threaded), about 300 M after (the a-trous 121 M, the
 * reprojection 30 M); see docs/FILTERS.md for wall times. */
#define _DEFAULT_SOURCE /* madvise (sys/mman.h) under -std=c11 */
#include "sy_filter_temporal.h"
#include "sy_filter_temporal_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#if defined(__linux__)
#include <sys/mman.h>
#endif

/* One frame's history: what the next frame reprojects. Planes of w*h floats, plane q of a group at
 * base + q*stride (plane_stride). */
typedef struct hist {
    uint32_t w, h;
    size_t stride; /* floats from one plane to the next (plane_stride of w*h) */
    size_t cap;   /* plane stride allocated for */
    float *illum; /* 3 planes: demodulated indirect part (or colour) after the first a-trous pass */
    float *dir;   /* 3 planes: demodulated direct part (0 without the split) */
    float *mom;   /* 4 planes: luminance moments of the indirect part (or colour), then of the direct part */
    float *len;   /* history length (frames); 0 = nothing to reuse (miss, bad pixel) */
    float *pos;   /* 3 planes: world position */
    float *nrm;   /* 3 planes: normal */
    float world_to_pixel[16];
} hist;

/* the working planes, each of width*height floats, plane_stride apart (see work_reserve for the count) */
enum {
    W_CLS,          /* class: 0 none (miss, bad pixel), 1 hit without a normal, 2 hit with one */
    W_OK,           /* 1 = finite input, else 0 */
    W_HIT,          /* 1 for a hit (class > 0), else 0 */
    W_SN,           /* the centre's normal edge stop: sigma_normal for class 2, else 0 */
    W_Z,            /* depth (0 where no hit) */
    W_MOD,          /* 3: albedo modulation (the normals, 0 where no hit, are the next history's nrm) */
    W_CUR = W_MOD + 3, /* 6: the new samples demodulated, indirect part (or colour) then direct part */
    W_LUM = W_CUR + 6, /* 2: their luminance, per part */
    W_ZG = W_LUM + 2,  /* depth gradient */
    W_IL,           /* per a-trous pass: 1 / (sigma_l sqrt(blurred variance) + 1e-6) */
    W_IZ,           /* per a-trous pass: 1 / (sigma_z step zgrad + 1e-6 z + 1e-9) */
    W_WS,           /* sums of weights */
    W_PART,         /* per part (2): acc 3, var = 4 */
    W_SCR = W_PART + 2 * 4, /* per part (2): the a-trous ping-pong planes a 3, va, b 3, vb = 8 */
    W_PP = W_SCR + 2 * 8,   /* 3: the hits' world positions at the previous frame (position + motion) */
    W_IL2 = W_PP + 3,       /* the direct part's luminance stop (W_IL's, when both parts are filtered together) */
    W_COUNT
};
/* a part's planes (part_index)  */
enum { P_ACC = 0, P_VAR = 3, P_A = 4, P_VA = 7, P_B = 8, P_VB = 11 };
/* the plane index of part k's plane off (P_*) */
static inline size_t part_index(int k, int off)
{
    return off < P_A ? (size_t)(W_PART + 4 * k + off) : (size_t)(W_SCR + 8 * k + (off - P_A));
}
/* integrate_rows works in blocks of IB columns of a row, its 3x3 statistics (S_COUNT planes of IB
 * floats: per part YCoCg sums (3) and sums of squares (3) of the new samples, luminance sum and sum
 * of squares; the count of hits) and the reprojected history (11 planes) in scratch on the stack
 * (about 15 KiB, in the L1 cache) */
enum { S_COUNT = 17, IB = 128 };

struct sy_filter_temporal {
    sy_filter_temporal_params p;
    hist h[2];
    int prev; /* index of the previous frame's history in h */
    bool have_prev;
    size_t cap;   /* pixels of the working planes */
    float *work;  /* W_COUNT planes */
    /* the last estimate returned (3 planes of est_w x est_h) and the samples each pixel counts as (a
     * fourth plane), for sy_filter_temporal_rest */
    float *est;
    size_t est_cap;
    uint32_t est_w, est_h;
    bool have_est;
};

void sy_filter_temporal_params_default(sy_filter_temporal_params *p)
{
    /* [tuned on `sy bench temporal` (Cornell box and demo, 1 spp per frame); SVGF's published
     * sigma_l = 4, sigma_z = 1; alpha 0.1 (SVGF: 0.2) for a lower error at 1 spp] */
    *p = (sy_filter_temporal_params){.alpha = 0.1f, .alpha_moments = 0.2f, .max_history = 32, .clamp_gamma = 2.0f,
                                     .depth_tolerance = 0.03f, .normal_tolerance = 0.8f, .atrous_iterations = 4,
                                     .sigma_luminance = 4.0f, .sigma_normal = 64.0f, .sigma_depth = 1.0f, .threads = 0,
                                     .rest_samples = 64};
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
    if (p->rest_samples > 1u << 20)
        return sy_filter_fail(err, SY_FILTER_ERROR_INVALID_ARGUMENT, "temporal: rest_samples = %u: at most %u",
                              p->rest_samples, 1u << 20);
    return sy_filter_check_threads(p->threads, "temporal", err);
}

/* Memory for a group of planes (free with free()). A group of 4 MiB or more is aligned to 2 MiB
 * and, on Linux, asked for transparent huge pages (madvise: under the common setting "madvise" the
 * kernel gives them only on request; a hint, without them the planes work as before): a pass reads
 * the same pixel of 20-60 planes megabytes apart, each plane's 4 KiB page a TLB entry of its own.
 * A filter-only 640x360 frame on one thread: 35 -> 33 ms, bit for bit the same (docs/FILTERS.md). */
static float *planes_alloc(size_t bytes)
{
    const size_t huge = (size_t)2 << 20;
    if (bytes < 2 * huge || bytes > SIZE_MAX - huge) return malloc(bytes);
    size_t b = (bytes + huge - 1) & ~(huge - 1);
    float *p = aligned_alloc(huge, b);
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    if (p) (void)madvise(p, b, MADV_HUGEPAGE);
#endif
    return p;
}

static void hist_free(hist *h)
{
    free(h->illum);
    memset(h, 0, sizeof *h);
}

/* The distance in floats between two planes of n pixels: n rounded up to 1024 floats (4 KiB) plus
 * 16 (one cache line), so that plane k starts k cache lines after a 4 KiB boundary. Planes exactly
 * n apart start at the same offset in a 4 KiB page for any n a multiple of 1024 (640x360, 1024x768,
 * 1920x1080 ...): the same pixel of every plane then falls in the same set of the L1 cache,
 * and a pass that reads the same pixel of 20-60 planes (the a-trous taps, the reprojection's
 * gathers) evicts its own lines (the L1 cache has 8-12 ways). Padded, they spread over consecutive
 * sets. */
static size_t plane_stride(size_t n)
{
    return n > SIZE_MAX - 2048 ? SIZE_MAX : ((n + 1023) & ~(size_t)1023) + 16;
}

/* one block of 17 planes n apart (n: plane_stride): illum 3, dir 3, mom 4, len 1, pos 3, nrm 3 */
static bool hist_reserve(hist *h, size_t n)
{
    if (n <= h->cap) return true;
    hist_free(h);
    if (n > SIZE_MAX / (17 * sizeof(float))) return false;
    float *b = planes_alloc(17 * n * sizeof(float));
    if (!b) return false;
    h->illum = b, h->cap = n;
    return true;
}

/* the planes of h, n apart (plane_stride) */
static void hist_bind(hist *h, size_t n)
{
    h->stride = n;
    h->dir = h->illum + 3 * n, h->mom = h->dir + 3 * n, h->len = h->mom + 4 * n, h->pos = h->len + n;
    h->nrm = h->pos + 3 * n;
}

static void work_free(sy_filter_temporal *t)
{
    free(t->work);
    t->work = NULL;
    t->cap = 0;
}

static bool work_reserve(sy_filter_temporal *t, size_t n)
{
    if (n <= t->cap) return true;
    work_free(t);
    if (n > SIZE_MAX / (W_COUNT * sizeof(float))) return false;
    t->work = planes_alloc(W_COUNT * n * sizeof(float));
    if (!t->work) {
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
    free(t->est);
    free(t);
}

void sy_filter_temporal_reset(sy_filter_temporal *t)
{
    if (t) t->have_prev = false, t->have_est = false;
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
    size_t n;         /* floats from one plane to the next (plane_stride of np), working planes and histories */
    size_t np;        /* pixels */
    float *W;         /* the working planes */
    /* a-trous pass: src, dst 3 planes each; with two, the direct part's src2, dst2 in the same pass */
    const float *src, *vsrc, *src2, *vsrc2;
    float *dst, *vdst, *dst2, *vdst2;
    bool two;
    int step;
    float xmax; /* EXP_MAX, through memory (see expneg) */
    bool avx2;  /* the reprojection may take its AVX2 path (sy_filter_temporal_reproject_avx2) */
    const float *outp[2]; /* the parts' final planes (remodulation) */
    const float *vout[2]; /* their final variance */
    const float *var0;    /* the indirect part's (or colour's) variance before the a-trous passes */
    float *out;
} tctx;

static inline float *plane(const tctx *c, size_t k)
{
    return c->W + k * c->n;
}

/* the columns x of a row whose tap x + off lies in [0, w) */
static inline void tap_span(int w, int off, int *x0, int *x1)
{
    *x0 = off < 0 ? -off : 0;
    *x1 = off > 0 ? w - off : w;
}

/* Software prefetch of the columns [x0, x1) of k rows p[0..k-1] (offset by off floats: a tap's
 * column shift) into the L1 cache, one request per cache line. An a-trous pass reads the same
 * columns of up to 60 planes at once, more streams than the hardware prefetchers follow: without it
 * every new line of every plane is a demand miss. Its row loop runs in chunks of PF_COLS columns
 * and, before each, requests the next chunk's lines (`sy bench temporal`, 640x360, one thread: the
 * a-trous phase 33.5 -> 25.5 ms a frame; chunks of 64 columns: 26.2). A prefetch is only a hint:
 * addresses are formed inside the planes (the caller clips the columns), nothing is read that the
 * pass would not. */
enum { PF_COLS = 128 };
static inline void prefetch_cols(const float *const *p, int k, int off, int x0, int x1)
{
    for (int r = 0; r < k; ++r)
        for (int x = x0 + off; x < x1 + off; x += 16) __builtin_prefetch(p[r] + x);
    if (x1 > x0)
        for (int r = 0; r < k; ++r) __builtin_prefetch(p[r] + x1 + off - 1); /* the last line */
}

/* the 3x3 B-spline kernel's 1D weights (the a-trous passes and the variance blur): a tap (dx, dy)
 * weighs HK[dx + 1] x HK[dy + 1] */
static const float HK[3] = {0.25f, 0.5f, 0.25f};

/* one tap of a row's 3x3 neighbourhood at step s: its direction (dx, dy), the columns [x0, x1) of
 * the row whose tap lies in the image (tap_span), and o, the offset from a pixel of the row to its
 * tap in a plane */
typedef struct tap3 {
    int dx, dy, x0, x1;
    size_t o;
} tap3;

/* the taps of row y's 3x3 neighbourhood at step s whose row lies in [0, hgt), dy then dx from -1
 * (the order the sums run in); returns how many */
static int row_taps(int w, int hgt, int y, int s, tap3 t[9])
{
    int n = 0;
    for (int dy = -1; dy <= 1; ++dy) {
        int yy = y + dy * s;
        if (yy < 0 || yy >= hgt) continue;
        for (int dx = -1; dx <= 1; ++dx, ++n) {
            t[n].dx = dx, t[n].dy = dy;
            tap_span(w, dx * s, &t[n].x0, &t[n].x1);
            t[n].o = (size_t)yy * w + (size_t)(dx * s);
        }
    }
    return n;
}

/* 0 for a finite x, NaN for NaN or an infinity (x * 0: not folded without -ffinite-math-only) */
static inline SY_TEMPORAL_INLINE float nonfinite0(float x)
{
    return x * 0.0f;
}

/* luminance (Rec. 709) of a colour: sy_filter_luminance's expression on three separate channels
 * (plane values; always inlined into the vectorised clones), for the demodulation and the a-trous
 * passes' luminance edge stop. The passes keep no luminance planes: each tap computes it from the
 * colour it loads anyway (the same expression as the blend's and the passes' results would have
 * stored, so the same values): 6 fewer planes in memory, 8 fewer streams a pass. */
static inline SY_TEMPORAL_INLINE float lum3(float r, float g, float b)
{
    return 0.2126f * r + 0.7152f * g + 0.0722f * b;
}

/* demodulation, validity, the frame's planes, for pixels [i0, i1): one function per colour channel
 * count CC (3 or 4) and direct/indirect split SPLIT, so that GCC vectorises each variant's strided
 * loads (restrict parameters: through an inlined helper it does not) */
#define SY_DEMOD_VARIANT(NAME, CC, SPLIT)                                                                             \
    SY_TEMPORAL_CLONES                                                                                               \
    static void NAME(size_t i0, size_t i1, float sn, const float *restrict col, const float *restrict al,             \
                     const float *restrict nr, const float *restrict dep, const float *restrict pos,                   \
                     const float *restrict dir, const float *restrict ind, float *restrict cls, float *restrict okp,   \
                     float *restrict hitp, float *restrict snp, float *restrict zp, float *restrict n0,                \
                     float *restrict n1, float *restrict n2, float *restrict m0, float *restrict m1,                   \
                     float *restrict m2, float *restrict c0, float *restrict c1, float *restrict c2,                   \
                     float *restrict d0, float *restrict d1, float *restrict d2, float *restrict l0,                   \
                     float *restrict l1, float *restrict q0, float *restrict q1, float *restrict q2)                   \
    {                                                                                                                 \
        const int cc = CC;                                                                                            \
        const bool split = SPLIT;                                                                                     \
    for (size_t i = i0; i < i1; ++i) {                                                                                \
        const float *cl = col + (size_t)cc * i, *a = al + 3 * i, *nn = nr + 3 * i, *p = pos + 3 * i;                  \
        float d = dep[i];                                                                                             \
        float bad = nonfinite0(cl[0]) + nonfinite0(cl[1]) + nonfinite0(cl[2]) + nonfinite0(a[0]) + nonfinite0(a[1]) + \
                    nonfinite0(a[2]) + nonfinite0(nn[0]) + nonfinite0(nn[1]) + nonfinite0(nn[2]);                     \
        if (split)                                                                                                    \
            bad += nonfinite0(dir[3 * i]) + nonfinite0(dir[3 * i + 1]) + nonfinite0(dir[3 * i + 2]) +                 \
                   nonfinite0(ind[3 * i]) + nonfinite0(ind[3 * i + 1]) + nonfinite0(ind[3 * i + 2]);                  \
        float okf = (float)(bad == 0.0f) * (float)(d == d) * (float)(d > -INFINITY);                                  \
        float pbad = nonfinite0(p[0]) + nonfinite0(p[1]) + nonfinite0(p[2]);                                          \
        float hitf = okf * (float)(d < INFINITY) * (float)(pbad == 0.0f);                                             \
        float hnf = hitf * (float)(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2] > 0.25f); /* has_normal */           \
        okp[i] = okf, cls[i] = hitf + hnf, hitp[i] = hitf, snp[i] = hnf * sn;                                         \
        zp[i] = hitf > 0.0f ? d : 0.0f;                                                                               \
        n0[i] = hitf > 0.0f ? nn[0] : 0.0f, n1[i] = hitf > 0.0f ? nn[1] : 0.0f, n2[i] = hitf > 0.0f ? nn[2] : 0.0f;   \
        q0[i] = hitf > 0.0f ? p[0] : 0.0f, q1[i] = hitf > 0.0f ? p[1] : 0.0f, q2[i] = hitf > 0.0f ? p[2] : 0.0f;      \
        /* dark albedo keeps the radiance (as a-trous); hitf x (0/1), not &&: GCC vectorises no select on a   \
         * mix of two comparisons */                                                                                  \
        float ma = hitf * (float)(a[0] > 0.01f) > 0.0f ? a[0] : 1.0f,                                                 \
              mb = hitf * (float)(a[1] > 0.01f) > 0.0f ? a[1] : 1.0f,                                                 \
              mc = hitf * (float)(a[2] > 0.01f) > 0.0f ? a[2] : 1.0f;                                                 \
        m0[i] = ma, m1[i] = mb, m2[i] = mc;                                                                           \
        float x0 = split ? ind[3 * i] : cl[0], x1 = split ? ind[3 * i + 1] : cl[1], x2 = split ? ind[3 * i + 2] : cl[2];\
        float r0 = okf > 0.0f ? x0 / ma : 0.0f, r1 = okf > 0.0f ? x1 / mb : 0.0f, r2 = okf > 0.0f ? x2 / mc : 0.0f;   \
        c0[i] = r0, c1[i] = r1, c2[i] = r2;                                                                           \
        l0[i] = lum3(r0, r1, r2);                                                                                     \
        float e0 = 0.0f, e1 = 0.0f, e2 = 0.0f;                                                                        \
        if (split)                                                                                                    \
            e0 = okf > 0.0f ? dir[3 * i] / ma : 0.0f, e1 = okf > 0.0f ? dir[3 * i + 1] / mb : 0.0f,                   \
            e2 = okf > 0.0f ? dir[3 * i + 2] / mc : 0.0f;                                                             \
        d0[i] = e0, d1[i] = e1, d2[i] = e2;                                                                           \
        l1[i] = lum3(e0, e1, e2);                                                                                     \
    }                                                                                                                 \
    }
SY_DEMOD_VARIANT(demod_c3, 3, false)
SY_DEMOD_VARIANT(demod_c4, 4, false)
SY_DEMOD_VARIANT(demod_c3_split, 3, true)
SY_DEMOD_VARIANT(demod_c4_split, 4, true)
#undef SY_DEMOD_VARIANT

static void demod_rows(void *vc, uint32_t y0, uint32_t y1)
{
    tctx *c = vc;
    const sy_filter_frame *in = c->in;
    size_t w = in->width, i0 = (size_t)y0 * w, i1 = (size_t)y1 * w;
    float sn = c->t->p.sigma_normal;
    bool split = in->direct && in->indirect;
    float *W = c->W;
    size_t n = c->n;
    hist *NX = c->next; /* the next history's normals and positions (0 where no hit) */
#define SY_DEMOD_ARGS                                                                                                 \
    i0, i1, sn, in->color, in->albedo, in->normal, in->depth, in->position, in->direct, in->indirect, W + W_CLS * n,   \
        W + W_OK * n, W + W_HIT * n, W + W_SN * n, W + W_Z * n, NX->nrm, NX->nrm + n, NX->nrm + 2 * n,                \
        W + W_MOD * n, W + (W_MOD + 1) * n, W + (W_MOD + 2) * n, W + W_CUR * n, W + (W_CUR + 1) * n,                 \
        W + (W_CUR + 2) * n, W + (W_CUR + 3) * n, W + (W_CUR + 4) * n, W + (W_CUR + 5) * n, W + W_LUM * n,          \
        W + (W_LUM + 1) * n, NX->pos, NX->pos + n, NX->pos + 2 * n
    if (in->color_channels == 4) {
        if (split) demod_c4_split(SY_DEMOD_ARGS);
        else demod_c4(SY_DEMOD_ARGS);
    } else {
        if (split) demod_c3_split(SY_DEMOD_ARGS);
        else demod_c3(SY_DEMOD_ARGS);
    }
#undef SY_DEMOD_ARGS
}

/* a-trous, one tap of kernel weight kk (zd: the diagonal's depth distance factor): neighbour planes
 * (class, depth, normal, colour, variance) then the centre's (class, colour, depth, normal, normal
 * stop, luminance and depth stops), the sums o (colour), ow (weights), ov (variance);
 * xmax: EXP_MAX. The class test multiplies: a select there keeps GCC from vectorising the AVX2 clone. */
SY_TEMPORAL_CLONES
static void atrous_tap(int x0, int x1, float kk, float zd, const float *restrict cl, const float *restrict z,
                       const float *restrict n0, const float *restrict n1, const float *restrict n2,
                       const float *restrict c0, const float *restrict c1, const float *restrict c2,
                       const float *restrict v, const float *restrict ccl, const float *restrict cc0,
                       const float *restrict cc1, const float *restrict cc2, const float *restrict cZ,
                       const float *restrict cn0,
                       const float *restrict cn1, const float *restrict cn2, const float *restrict csn,
                       const float *restrict cil, const float *restrict ciz, float *restrict o0, float *restrict o1,
                       float *restrict o2, float *restrict ow, float *restrict ov, float xmax)
{
    for (int x = x0; x < x1; ++x) {
        float dn = 1.0f - (cn0[x] * n0[x] + cn1[x] * n1[x] + cn2[x] * n2[x]);
        float arg = fabsf(lum3(cc0[x], cc1[x], cc2[x]) - lum3(c0[x], c1[x], c2[x])) * cil[x] +
                    fabsf(cZ[x] - z[x]) * ciz[x] * zd + csn[x] * fmx(dn, 0.0f);
        float k = kk * expneg(arg, xmax) * (float)(cl[x] == ccl[x]); /* e finite: 0 or e exactly */
        o0[x] += k * c0[x], o1[x] += k * c1[x], o2[x] += k * c2[x];
        ow[x] += k, ov[x] += k * k * v[x];
    }
}

/* one pixel's terms of the clamp's statistics (m: hit 1/0, a: its colour, l: its luminance): its
 * YCoCg colour v, the squares of v's channels and l, each times m, in t (m v0, m v1, m v2, m v0^2,
 * m v1^2, m v2^2, m l, m l^2); stats_tap and stats_terms both take them from here */
static inline SY_TEMPORAL_INLINE void stats_pixel(float m, float a0, float a1, float a2, float l, float *t)
{
    float v0 = 0.25f * a0 + 0.5f * a1 + 0.25f * a2, v1 = 0.5f * a0 - 0.5f * a2;
    float v2 = -0.25f * a0 + 0.5f * a1 - 0.25f * a2;
    t[0] = m * v0, t[1] = m * v1, t[2] = m * v2;
    t[3] = m * (v0 * v0), t[4] = m * (v1 * v1), t[5] = m * (v2 * v2);
    t[6] = m * l, t[7] = m * (l * l);
}

/* 3x3 statistics of one part, one tap: YCoCg sums s0-s2 and sums of squares s3-s5 of colour a,
 * luminance sum s6 and sum of squares s7, over hits (h = 1) */
SY_TEMPORAL_CLONES
static void stats_tap(int x0, int x1, const float *restrict h, const float *restrict a0, const float *restrict a1,
                      const float *restrict a2, const float *restrict l0, float *restrict s0, float *restrict s1,
                      float *restrict s2, float *restrict s3, float *restrict s4, float *restrict s5, float *restrict s6,
                      float *restrict s7)
{
    for (int x = x0; x < x1; ++x) {
        float t[8];
        stats_pixel(h[x], a0[x], a1[x], a2[x], l0[x], t);
        s0[x] += t[0], s1[x] += t[1], s2[x] += t[2], s3[x] += t[3];
        s4[x] += t[4], s5[x] += t[5], s6[x] += t[6], s7[x] += t[7];
    }
}

/* the count of hits, and the depth gradient's max over axial taps (axial 1, else 0) */
SY_TEMPORAL_CLONES
static void count_tap(int x0, int x1, float axial, const float *restrict h, const float *restrict z,
                      const float *restrict cz, float *restrict cnt, float *restrict zg)
{
    for (int x = x0; x < x1; ++x) {
        float m = h[x];
        cnt[x] += m;
        zg[x] = fmx(zg[x], (axial * m) * fabsf(z[x] - cz[x]));
    }
}

/* stats_pixel's eight terms of one part at columns [0, n) of a row, each once (t: 8 rows of IB + 2
 * floats: m v0, m v1, m v2, m v0^2, m v1^2, m v2^2, m l, m l^2), for stats_sum9 */
SY_TEMPORAL_CLONES
static void stats_terms(int n, const float *restrict h, const float *restrict a0, const float *restrict a1,
                        const float *restrict a2, const float *restrict l0, float *restrict t)
{
    enum { TS = IB + 2 };
    float *restrict t0 = t, *restrict t1 = t + TS, *restrict t2 = t + 2 * TS, *restrict t3 = t + 3 * TS;
    float *restrict t4 = t + 4 * TS, *restrict t5 = t + 5 * TS, *restrict t6 = t + 6 * TS, *restrict t7 = t + 7 * TS;
    for (int x = 0; x < n; ++x) {
        float p[8];
        stats_pixel(h[x], a0[x], a1[x], a2[x], l0[x], p);
        t0[x] = p[0], t1[x] = p[1], t2[x] = p[2], t3[x] = p[3];
        t4[x] = p[4], t5[x] = p[5], t6[x] = p[6], t7[x] = p[7];
    }
}

/* one statistic's 3x3 sums at columns [0, n) from its terms on rows y - 1 (a), y (b), y + 1 (c),
 * column x's neighbours at x, x + 1, x + 2: stats_tap's sum, the same additions in the same order
 * (from 0, the taps dy then dx from -1) */
SY_TEMPORAL_CLONES
static void stats_sum9(int n, const float *restrict a, const float *restrict b, const float *restrict c,
                       float *restrict s)
{
    for (int x = 0; x < n; ++x)
        s[x] = 0.0f + a[x] + a[x + 1] + a[x + 2] + b[x] + b[x + 1] + b[x + 2] + c[x] + c[x + 1] + c[x + 2];
}

/* the 3x3 statistics of the hits' new samples at columns [xc, xc + bw) of row y (S: S_COUNT planes
 * of IB floats, column xc at 0: per part YCoCg sums 0-2, squares 3-5, luminance 6, its square 7;
 * part 0 at 0, part 1 at 8; the count of hits at 16) and the depth gradient zg (the W_ZG row from
 * column xc: max |z_j - z| over the 4 axial hit neighbours): inside the image each pixel's terms
 * once per row, then their 3x3 sums (stats_terms, stats_sum9: stats_tap computed a pixel's YCoCg,
 * squares and products once for each of its 9 neighbours); at the image's edges tap by tap (each
 * tap's columns clipped to the block). Per pixel, the same sums in the same order either way. */
static void stats_block(const tctx *c, int y, int xc, int bw, float *S, float *zg)
{
    int w = (int)c->in->width, hgt = (int)c->in->height;
    size_t row = (size_t)y * w;
    memset(zg, 0, (size_t)bw * sizeof(float));
    float *s[S_COUNT];
    for (int k = 0; k < S_COUNT; ++k) s[k] = S + k * IB;
    /* rows y -+ 1 in the image: the columns [xl, xh) of the block whose 3 neighbours lie in the image
     * take each pixel's terms once per row (stats_terms) and their sums (stats_sum9); the image's
     * first and last column, and the first and last row, go tap by tap */
    bool rows_in = y >= 1 && y + 1 < hgt;
    int xl = xc == 0 ? 1 : 0, xh = xc + bw == w ? bw - 1 : bw;
    if (!rows_in || xh <= xl) xl = xh = 0;
    memset(S, 0, (size_t)S_COUNT * IB * sizeof(float)); /* sums from 0 */
    const float *Z = plane(c, W_Z) + xc, *H = plane(c, W_HIT) + xc;
    const float *c0 = plane(c, W_CUR) + xc, *c1 = plane(c, W_CUR + 1) + xc, *c2 = plane(c, W_CUR + 2) + xc;
    const float *d0 = plane(c, W_CUR + 3) + xc, *d1 = plane(c, W_CUR + 4) + xc, *d2 = plane(c, W_CUR + 5) + xc;
    const float *L0 = plane(c, W_LUM) + xc, *L1 = plane(c, W_LUM + 1) + xc;
    if (xh > xl) {
        float T[3 * 16 * (IB + 2)]; /* rows y - 1, y, y + 1; per row part 0's 8 terms, then part 1's */
        for (int r = 0; r < 3; ++r) {
            ptrdiff_t o = (ptrdiff_t)(y - 1 + r) * w + xl - 1; /* from block column xl - 1 */
            float *t = T + (size_t)r * 16 * (IB + 2);
            stats_terms(xh - xl + 2, H + o, c0 + o, c1 + o, c2 + o, L0 + o, t);
            stats_terms(xh - xl + 2, H + o, d0 + o, d1 + o, d2 + o, L1 + o, t + 8 * (IB + 2));
        }
        for (int k = 0; k < 16; ++k)
            stats_sum9(xh - xl, T + (size_t)k * (IB + 2), T + (size_t)(16 + k) * (IB + 2),
                       T + (size_t)(32 + k) * (IB + 2), s[k] + xl);
    }
    tap3 taps[9];
    for (int k = 0, nt = row_taps(w, hgt, y, 1, taps); k < nt; ++k) {
        int x0 = taps[k].x0 - xc, x1 = taps[k].x1 - xc; /* block columns */
        x0 = x0 > 0 ? x0 : 0, x1 = x1 < bw ? x1 : bw;
        size_t o = taps[k].o;
        float axial = (taps[k].dx == 0) != (taps[k].dy == 0) ? 1.0f : 0.0f;
        for (int e = 0; e < 2; ++e) { /* the columns [x0, x1) outside [xl, xh) */
            int a = e ? (x0 > xh ? x0 : xh) : x0, b = e ? x1 : (x1 < xl ? x1 : xl);
            if (b <= a) continue;
            stats_tap(a, b, H + o, c0 + o, c1 + o, c2 + o, L0 + o, s[0], s[1], s[2], s[3], s[4], s[5], s[6], s[7]);
            stats_tap(a, b, H + o, d0 + o, d1 + o, d2 + o, L1 + o, s[8], s[9], s[10], s[11], s[12], s[13], s[14],
                      s[15]);
        }
        count_tap(x0, x1, axial, H + o, Z + o, Z + row, s[16], zg);
    }
}

/* one YCoCg channel clamped to mean +- gamma sd of the sums m1, m2 (count 1/ic) */
static inline SY_TEMPORAL_INLINE float clamp1(float v, float m1, float m2, float ic, float gamma)
{
    float mu = m1 * ic, var = m2 * ic - mu * mu, sd = sqrtf(fmx(var, 0.0f));
    return fmx(mu - gamma * sd, fmn(v, mu + gamma * sd));
}

/* colour c (3) clamped to the YCoCg box of the sums m1 (3 planes n apart) and m2, where u = 1 (else
 * kept: a blend of finite values), loop-free so that the row loop around it vectorises */
static inline SY_TEMPORAL_INLINE void clamp3(float *c, const float *m1, const float *m2, size_t n, float ic, float gamma,
                                             float u)
{
    float y = 0.25f * c[0] + 0.5f * c[1] + 0.25f * c[2], o = 0.5f * c[0] - 0.5f * c[2],
          g = -0.25f * c[0] + 0.5f * c[1] - 0.25f * c[2];
    y = clamp1(y, m1[0], m2[0], ic, gamma), o = clamp1(o, m1[n], m2[n], ic, gamma);
    g = clamp1(g, m1[2 * n], m2[2 * n], ic, gamma);
    float nu = 1.0f - u;
    c[0] = u * (y + o - g) + nu * c[0], c[1] = u * (y + g) + nu * c[1], c[2] = u * (y - o - g) + nu * c[2];
}

/* clamping, moving averages and variance of a row's pixels [0, w), after the reprojection: h hit
 * (1/0), cur (6 planes: the new samples of both parts) and lum (2), S the 3x3 statistics (S_COUNT
 * planes), R the reprojected history (11 planes, 0 where not reused) and ru (1 where reused); S and
 * R's planes ns apart, the other groups' n apart. Out: the parts' blends a (3) and b (3), variances v0 v1;
 * the depth gradient zg masked to hits; the next history's length and moments (4, n apart).
 * Branch-free (selects as 0/1 blends of finite values) so that it vectorises. */
SY_TEMPORAL_CLONES
static void blend_row(int w, size_t n, size_t ns, float alpha, float alpha_m, float max_hist, float gamma,
                      const float *restrict h, const float *restrict cur, const float *restrict lum,
                      const float *restrict S, const float *restrict R, const float *restrict ru, float *restrict a0,
                      float *restrict a1, float *restrict a2, float *restrict b0, float *restrict b1,
                      float *restrict b2, float *restrict v0, float *restrict v1, float *restrict zg,
                      float *restrict len, float *restrict mom)
{
    const float on = gamma > 0.0f ? 1.0f : 0.0f;
    for (int x = 0; x < w; ++x) {
        float hx = h[x], u = ru[x];
        float ic = 1.0f / fmx(S[16 * ns + x], 1.0f);
        float ci[3] = {cur[x], cur[n + x], cur[2 * n + x]}, dc[3] = {cur[3 * n + x], cur[4 * n + x], cur[5 * n + x]};
        float hi[3] = {R[x], R[ns + x], R[2 * ns + x]}, hd[3] = {R[3 * ns + x], R[4 * ns + x], R[5 * ns + x]};
        float hm[4] = {R[6 * ns + x], R[7 * ns + x], R[8 * ns + x], R[9 * ns + x]}, hl = R[10 * ns + x];
        /* clamp both parts' history to the YCoCg box of the new samples (where reused; gamma 0: off) */
        clamp3(hi, S + x, S + 3 * ns + x, ns, ic, gamma, u * on);
        clamp3(hd, S + 8 * ns + x, S + 11 * ns + x, ns, ic, gamma, u * on);
        float al = fmx(alpha, 1.0f / (hl + 1.0f)), am = fmx(alpha_m, 1.0f / (hl + 1.0f)); /* hl = 0: 1 */
        float ai[3], ad[3];
        ai[0] = hi[0] + al * (ci[0] - hi[0]), ai[1] = hi[1] + al * (ci[1] - hi[1]), ai[2] = hi[2] + al * (ci[2] - hi[2]);
        ad[0] = hd[0] + al * (dc[0] - hd[0]), ad[1] = hd[1] + al * (dc[1] - hd[1]), ad[2] = hd[2] + al * (dc[2] - hd[2]);
        a0[x] = ai[0], a1[x] = ai[1], a2[x] = ai[2], b0[x] = ad[0], b1[x] = ad[1], b2[x] = ad[2];
        float l = lum[x], e = lum[n + x];
        float mo0 = hm[0] + am * (l - hm[0]), mo1 = hm[1] + am * (l * l - hm[1]), mo2 = hm[2] + am * (e - hm[2]),
              mo3 = hm[3] + am * (e * e - hm[3]);
        float ln = fmn(hl + 1.0f, max_hist);
        mom[x] = hx * mo0, mom[n + x] = hx * mo1, mom[2 * n + x] = hx * mo2, mom[3 * n + x] = hx * mo3;
        len[x] = hx * ln;
        /* short history (< 4 frames): the spatial variance of the new samples */
        float mu = S[6 * ns + x] * ic, me = S[14 * ns + x] * ic, sp = (float)(ln < 4.0f), tp = 1.0f - sp;
        float vs0 = fmx(0.0f, S[7 * ns + x] * ic - mu * mu), vs1 = fmx(0.0f, S[15 * ns + x] * ic - me * me);
        float vt0 = fmx(0.0f, mo1 - mo0 * mo0), vt1 = fmx(0.0f, mo3 - mo2 * mo2);
        v0[x] = hx * (sp * vs0 + tp * vt0), v1[x] = hx * (sp * vs1 + tp * vt1);
        zg[x] *= hx;
    }
}

/* depth gradient, reprojection, clamping, moving averages, variance; the next history's geometry:
 * per row the 3x3 statistics (vectorised), the reprojection (4 taps of the previous history per
 * pixel: sy_filter_temporal_reproject_row), then blend_row */
static void integrate_rows(void *vc, uint32_t y0, uint32_t y1)
{
    tctx *c = vc;
    sy_filter_temporal *t = c->t;
    const sy_filter_frame *in = c->in;
    const sy_filter_temporal_params *P = &t->p;
    int w = (int)in->width;
    size_t n = c->n;
    hist *nx = c->next;
    const float *H = plane(c, W_HIT);
    /* a block's 3x3 statistics and reprojected history: scratch that stays in the L1 cache (as full
     * planes, written by one pass and read by the next, they cost 29 planes of memory traffic) */
    float S[S_COUNT * IB], R[11 * IB], RU[IB];
    for (int y = (int)y0; y < (int)y1; ++y) {
        size_t row = (size_t)y * w;
        /* the next history's geometry (demod_rows wrote it) is also this row's positions and normals */
        /* where the surface points were at the previous frame: the positions, moved back by the
         * object motion (a non-finite motion finds no history) */
        const float *pp = nx->pos;
        if (in->motion) {
            float *PP = plane(c, W_PP);
            for (int x = 0; x < w; ++x) {
                size_t i = row + x;
                bool hit = H[i] > 0.0f;
                const float *mv = in->motion + 3 * i;
                for (int q = 0; q < 3; ++q) PP[q * n + i] = hit ? nx->pos[q * n + i] + mv[q] : 0.0f;
            }
            pp = PP;
        }
        const float *cur = plane(c, W_CUR) + row, *lum = plane(c, W_LUM) + row;
        float *a0 = plane(c, part_index(0, P_ACC)) + row, *a1 = plane(c, part_index(0, P_ACC + 1)) + row;
        float *a2 = plane(c, part_index(0, P_ACC + 2)) + row, *v0 = plane(c, part_index(0, P_VAR)) + row;
        float *v1 = plane(c, part_index(1, P_VAR)) + row, *zg = plane(c, W_ZG) + row;
        float *b0 = nx->dir + row, *len = nx->len + row, *mom = nx->mom + row;
        for (int xc = 0; xc < w; xc += IB) {
            int bw = w - xc < IB ? w - xc : IB;
            stats_block(c, y, xc, bw, S, zg + xc);
            if (c->prev) {
                const hist *hp = c->prev;
                sy_filter_temporal_reproject_row(c->avx2, bw, IB, hp->world_to_pixel, (int)hp->w, (int)hp->h,
                                                 hp->stride, hp->illum, P->depth_tolerance, P->normal_tolerance,
                                                 pp + row + xc, pp + n + row + xc, pp + 2 * n + row + xc,
                                                 nx->nrm + row + xc, nx->nrm + n + row + xc, nx->nrm + 2 * n + row + xc,
                                                 plane(c, W_Z) + row + xc, H + row + xc, R, RU);
            } else {
                memset(R, 0, sizeof R);
                memset(RU, 0, sizeof RU);
            }
            blend_row(bw, n, IB, P->alpha, P->alpha_moments, (float)P->max_history, P->clamp_gamma, H + row + xc,
                      cur + xc, lum + xc, S, R, RU, a0 + xc, a1 + xc, a2 + xc, b0 + xc, b0 + n + xc, b0 + 2 * n + xc,
                      v0 + xc, v1 + xc, zg + xc, len + xc, mom + xc);
        }
    }
}

/* the variance blur, one tap of kernel weight kk: neighbour class cl and variance v, centre class ccl;
 * sums vb (weighted variance) and vw (weights) */
SY_TEMPORAL_CLONES
static void vblur_tap(int x0, int x1, float kk, const float *restrict cl, const float *restrict v,
                      const float *restrict ccl, float *restrict vb, float *restrict vw)
{
    for (int x = x0; x < x1; ++x) {
        float k = kk * (float)(cl[x] == ccl[x]);
        vb[x] += k * v[x], vw[x] += k;
    }
}

/* the edge stops of a row from the blur's sums: il holds the weighted variance and receives
 * 1 / (sl sqrt(variance) + 1e-6); iz = 1 / (sz zgrad + 1e-6 z + 1e-9) */
SY_TEMPORAL_CLONES
static void stops_row(int w, float sl, float sz, const float *restrict vw, const float *restrict g,
                      const float *restrict z, float *restrict il, float *restrict iz)
{
    for (int x = 0; x < w; ++x) {
        il[x] = 1.0f / (sl * sqrtf(il[x] / vw[x]) + 1e-6f); /* vw > 0: the centre */
        iz[x] = 1.0f / (sz * g[x] + 1e-6f * z[x] + 1e-9f);
    }
}

/* vblur_tap for both parts at once (the weights are the same: the class alone) */
SY_TEMPORAL_CLONES
static void vblur_tap2(int x0, int x1, float kk, const float *restrict cl, const float *restrict v,
                       const float *restrict v2, const float *restrict ccl, float *restrict vb, float *restrict vb2,
                       float *restrict vw)
{
    for (int x = x0; x < x1; ++x) {
        float k = kk * (float)(cl[x] == ccl[x]);
        vb[x] += k * v[x], vb2[x] += k * v2[x], vw[x] += k;
    }
}

/* vblur_tap's 9 taps at once at columns [x0, x1) of a row whose taps all lie in the image (rows
 * w floats apart; cl, v, vb, vw from the row's start): per pixel the same additions in the same
 * order (from 0, dy then dx from -1: row_taps's), without 9 passes over the sums */
SY_TEMPORAL_CLONES
static void vblur_fused(int x0, int x1, ptrdiff_t w, const float *restrict cl, const float *restrict v,
                        float *restrict vb, float *restrict vw)
{
    for (int x = x0; x < x1; ++x) {
        float c = cl[x], b = 0.0f, s = 0.0f;
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                ptrdiff_t j = x + dy * w + dx;
                float k = HK[dx + 1] * HK[dy + 1] * (float)(cl[j] == c);
                b += k * v[j], s += k;
            }
        vb[x] = b, vw[x] = s;
    }
}

/* vblur_fused for both parts (vblur_tap2's taps) */
SY_TEMPORAL_CLONES
static void vblur_fused2(int x0, int x1, ptrdiff_t w, const float *restrict cl, const float *restrict v,
                         const float *restrict v2, float *restrict vb, float *restrict vb2, float *restrict vw)
{
    for (int x = x0; x < x1; ++x) {
        float c = cl[x], b = 0.0f, b2 = 0.0f, s = 0.0f;
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                ptrdiff_t j = x + dy * w + dx;
                float k = HK[dx + 1] * HK[dy + 1] * (float)(cl[j] == c);
                b += k * v[j], b2 += k * v2[j], s += k;
            }
        vb[x] = b, vb2[x] = b2, vw[x] = s;
    }
}

/* stops_row for both parts: il2 the direct part's luminance stop */
SY_TEMPORAL_CLONES
static void stops_row2(int w, float sl, float sz, const float *restrict vw, const float *restrict g,
                       const float *restrict z, float *restrict il, float *restrict il2, float *restrict iz)
{
    for (int x = 0; x < w; ++x) {
        il[x] = 1.0f / (sl * sqrtf(il[x] / vw[x]) + 1e-6f); /* vw > 0: the centre */
        il2[x] = 1.0f / (sl * sqrtf(il2[x] / vw[x]) + 1e-6f);
        iz[x] = 1.0f / (sz * g[x] + 1e-6f * z[x] + 1e-9f);
    }
}

/* The edge stops of an a-trous pass at row y: the variance blurred 3x3 (B-spline, step 1) over
 * pixels of the centre's class, turned into the pass's luminance edge stop 1 / (sigma_l
 * sqrt(blurred) + 1e-6), and the depth edge stop 1 / (sigma_z step zgrad + 1e-6 z + 1e-9); with
 * c->two, both parts' (the blur's weights and the depth stop are the same for both). atrous_rows
 * calls it for each row just before filtering it: it reads the pass's source rows y-1..y+1, which
 * the pass does not write, and its output row is still in the cache when the row is filtered. */
static void vblur_row(const tctx *c, int y)
{
    const sy_filter_temporal_params *P = &c->t->p;
    int w = (int)c->in->width, hgt = (int)c->in->height;
    const float *cls = plane(c, W_CLS), *V = c->vsrc, *Z = plane(c, W_Z), *G = plane(c, W_ZG);
    float *IL = plane(c, W_IL), *IZ = plane(c, W_IZ), *WS = plane(c, W_WS);
    float sl = P->sigma_luminance, sz = P->sigma_depth * (float)c->step;
    size_t row = (size_t)y * w;
    float *vb = IL + row, *vw = WS + row, *vb2 = plane(c, W_IL2) + row;
    /* the columns [xl, xh) whose 9 taps lie in the image in one loop (vblur_fused); the first and
     * last column, and the rows whose neighbour rows leave the image, tap by tap from 0 */
    bool rows_in = y >= 1 && y + 1 < hgt;
    int xl = rows_in && w > 2 ? 1 : 0, xh = rows_in && w > 2 ? w - 1 : 0;
    if (xh > xl) {
        if (c->two) vblur_fused2(xl, xh, w, cls + row, V + row, c->vsrc2 + row, vb, vb2, vw);
        else vblur_fused(xl, xh, w, cls + row, V + row, vb, vw);
    }
    tap3 taps[9];
    int nt = row_taps(w, hgt, y, 1, taps);
    for (int e = 0; e < 2; ++e) { /* the columns [0, xl) and [xh, w) */
        int a = e ? xh : 0, b = e ? w : xl;
        if (b <= a) continue;
        size_t nb = (size_t)(b - a) * sizeof(float);
        memset(vb + a, 0, nb);
        memset(vw + a, 0, nb);
        if (c->two) memset(vb2 + a, 0, nb);
        for (int k = 0; k < nt; ++k) {
            const tap3 *t = &taps[k];
            float kk = HK[t->dx + 1] * HK[t->dy + 1];
            int x0 = t->x0 > a ? t->x0 : a, x1 = t->x1 < b ? t->x1 : b;
            if (x1 <= x0) continue;
            if (c->two) vblur_tap2(x0, x1, kk, cls + t->o, V + t->o, c->vsrc2 + t->o, cls + row, vb, vb2, vw);
            else vblur_tap(x0, x1, kk, cls + t->o, V + t->o, cls + row, vb, vw);
        }
    }
    if (c->two) stops_row2(w, sl, sz, vw, G + row, Z + row, IL + row, vb2, IZ + row);
    else stops_row(w, sl, sz, vw, G + row, Z + row, IL + row, IZ + row);
}

/* an a-trous row's sums start with the centre's kernel weight k0 */
SY_TEMPORAL_CLONES
static void atrous_start(int w, float k0, const float *restrict c0, const float *restrict c1, const float *restrict c2,
                         const float *restrict v, float *restrict o0, float *restrict o1, float *restrict o2,
                         float *restrict ow, float *restrict ov)
{
    for (int x = 0; x < w; ++x) {
        o0[x] = k0 * c0[x], o1[x] = k0 * c1[x], o2[x] = k0 * c2[x];
        ow[x] = k0, ov[x] = k0 * k0 * v[x];
    }
}

/* an a-trous row's result: the normalised sums where the centre is a hit (h = 1), the source
 * (colour c, variance v) where not */
SY_TEMPORAL_CLONES
static void atrous_end(int w, const float *restrict h, const float *restrict c0, const float *restrict c1,
                       const float *restrict c2, const float *restrict v, const float *restrict ow,
                       float *restrict o0, float *restrict o1, float *restrict o2, float *restrict ov)
{
    for (int x = 0; x < w; ++x) {
        float m = h[x], k = 1.0f - m, iw = 1.0f / ow[x]; /* ow >= the centre's weight */
        float r0 = m * (o0[x] * iw) + k * c0[x], r1 = m * (o1[x] * iw) + k * c1[x], r2 = m * (o2[x] * iw) + k * c2[x];
        o0[x] = r0, o1[x] = r1, o2[x] = r2;
        ov[x] = m * (ov[x] * iw * iw) + k * v[x];
    }
}

/* The 8 neighbours of an a-trous pass at step s around column x, each through the caller's SY_TAP
 * (the offset from the pixel's index to its tap's: -sw above, 0 on the row, +sw below, -s, 0, +s
 * across; B3-spline weight kd or ke; depth scale for the diagonal) */
#define SY_ATROUS_TAPS8()                                                                                             \
    do {                                                                                                              \
        SY_TAP(x - sw - s, kd, dg);                                                                                   \
        SY_TAP(x - sw, ke, 1.0f);                                                                                     \
        SY_TAP(x - sw + s, kd, dg);                                                                                   \
        SY_TAP(x - s, ke, 1.0f);                                                                                      \
        SY_TAP(x + s, ke, 1.0f);                                                                                      \
        SY_TAP(x + sw - s, kd, dg);                                                                                   \
        SY_TAP(x + sw, ke, 1.0f);                                                                                     \
        SY_TAP(x + sw + s, kd, dg);                                                                                   \
    } while (0)

/* a-trous, the 8 taps of the pixels [x0, x1) of row y at once (every tap in the image: rows y - s
 * and y + s too): class, depth, normal, colour and variance planes (each from row y's start: rows
 * y -+ s are sw = s x width floats before and after), the centre's normal, luminance and depth
 * stops; the taps in the order of atrous_tap's calls, the sums in registers, then atrous_end's
 * result (o colour, ov variance; the source where the centre is no hit). One pointer per plane and
 * the taps' offsets from it (a pointer per plane and row took 39, and a row of class -1 for rows
 * outside the image, which now go tap by tap): the same results, about as fast (docs/FILTERS.md). */
SY_TEMPORAL_CLONES
static void atrous_row8(int x0, int x1, int s, ptrdiff_t sw, const float *restrict cl, const float *restrict z,
                        const float *restrict na, const float *restrict nb, const float *restrict nc,
                        const float *restrict ca, const float *restrict cb, const float *restrict cc,
                        const float *restrict v, const float *restrict sn, const float *restrict il,
                        const float *restrict iz, float *restrict o0, float *restrict o1, float *restrict o2,
                        float *restrict ov, float xmax)
{
    const float kc = 0.25f, ke = 0.125f, kd = 0.0625f, dg = 0.70710678f;
    for (ptrdiff_t x = x0; x < x1; ++x) {
        float ci = cl[x], li = lum3(ca[x], cb[x], cc[x]), zi = z[x], n0 = na[x], n1 = nb[x], n2 = nc[x];
        float si = sn[x], ii = il[x], iz_ = iz[x];
        float a0 = kc * ca[x], a1 = kc * cb[x], a2 = kc * cc[x], W = kc, V = kc * kc * v[x];
#define SY_TAP(J, KK, ZD)                                                                                             \
    do {                                                                                                              \
        ptrdiff_t j_ = (J);                                                                                           \
        float dn = 1.0f - (n0 * na[j_] + n1 * nb[j_] + n2 * nc[j_]);                                                  \
        float lj = lum3(ca[j_], cb[j_], cc[j_]);                                                                      \
        float arg = fabsf(li - lj) * ii + fabsf(zi - z[j_]) * iz_ * (ZD) + si * fmx(dn, 0.0f);                        \
        float k = (KK) * expneg(arg, xmax) * (float)(cl[j_] == ci);                                                   \
        a0 += k * ca[j_], a1 += k * cb[j_], a2 += k * cc[j_];                                                         \
        W += k, V += k * k * v[j_];                                                                                   \
    } while (0)
        SY_ATROUS_TAPS8();
#undef SY_TAP
        float h = (float)(ci > 0.0f), k = 1.0f - h, iw = 1.0f / W;
        float r0 = h * (a0 * iw) + k * ca[x], r1 = h * (a1 * iw) + k * cb[x], r2 = h * (a2 * iw) + k * cc[x];
        o0[x] = r0, o1[x] = r1, o2[x] = r2;
        ov[x] = h * (V * iw * iw) + k * v[x];
    }
}

/* atrous_row8 for both parts at once (indirect: ca, cb, cc, v, il, o*; direct: the same with 2):
 * the class, depth and normal terms are computed once for both, each part's sums as atrous_row8's
 * (the same operations in the same order: the same results as two calls) */
SY_TEMPORAL_CLONES
static void atrous_row8_2(int x0, int x1, int s, ptrdiff_t sw, const float *restrict cl, const float *restrict z,
                          const float *restrict na, const float *restrict nb, const float *restrict nc,
                          const float *restrict sn, const float *restrict iz, const float *restrict ca,
                          const float *restrict cb, const float *restrict cc, const float *restrict v,
                          const float *restrict il, float *restrict o0, float *restrict o1, float *restrict o2,
                          float *restrict ov, const float *restrict ca2, const float *restrict cb2,
                          const float *restrict cc2, const float *restrict v2, const float *restrict il2,
                          float *restrict p0, float *restrict p1, float *restrict p2, float *restrict pv, float xmax)
{
    const float kc = 0.25f, ke = 0.125f, kd = 0.0625f, dg = 0.70710678f;
    for (ptrdiff_t x = x0; x < x1; ++x) {
        float ci = cl[x], zi = z[x], n0 = na[x], n1 = nb[x], n2 = nc[x], si = sn[x], iz_ = iz[x];
        float li = lum3(ca[x], cb[x], cc[x]), ii = il[x], li2 = lum3(ca2[x], cb2[x], cc2[x]), ii2 = il2[x];
        float a0 = kc * ca[x], a1 = kc * cb[x], a2 = kc * cc[x], W = kc, V = kc * kc * v[x];
        float b0 = kc * ca2[x], b1 = kc * cb2[x], b2 = kc * cc2[x], W2 = kc, V2 = kc * kc * v2[x];
#define SY_TAP(J, KK, ZD)                                                                                             \
    do {                                                                                                              \
        ptrdiff_t j_ = (J);                                                                                           \
        float dn = 1.0f - (n0 * na[j_] + n1 * nb[j_] + n2 * nc[j_]);                                                  \
        float gz = fabsf(zi - z[j_]) * iz_ * (ZD), gn = si * fmx(dn, 0.0f), m = (float)(cl[j_] == ci);                \
        float lj = lum3(ca[j_], cb[j_], cc[j_]), lj2 = lum3(ca2[j_], cb2[j_], cc2[j_]);                               \
        float arg = fabsf(li - lj) * ii + gz + gn, arg2 = fabsf(li2 - lj2) * ii2 + gz + gn;                           \
        float k = (KK) * expneg(arg, xmax) * m, k2 = (KK) * expneg(arg2, xmax) * m;                                  \
        a0 += k * ca[j_], a1 += k * cb[j_], a2 += k * cc[j_];                                                         \
        W += k, V += k * k * v[j_];                                                                                   \
        b0 += k2 * ca2[j_], b1 += k2 * cb2[j_], b2 += k2 * cc2[j_];                                                   \
        W2 += k2, V2 += k2 * k2 * v2[j_];                                                                             \
    } while (0)
        SY_ATROUS_TAPS8();
#undef SY_TAP
        float h = (float)(ci > 0.0f), k = 1.0f - h, iw = 1.0f / W, iw2 = 1.0f / W2;
        float r0 = h * (a0 * iw) + k * ca[x], r1 = h * (a1 * iw) + k * cb[x], r2 = h * (a2 * iw) + k * cc[x];
        o0[x] = r0, o1[x] = r1, o2[x] = r2;
        ov[x] = h * (V * iw * iw) + k * v[x];
        float q0 = h * (b0 * iw2) + k * ca2[x], q1 = h * (b1 * iw2) + k * cb2[x], q2 = h * (b2 * iw2) + k * cc2[x];
        p0[x] = q0, p1[x] = q1, p2[x] = q2;
        pv[x] = h * (V2 * iw2 * iw2) + k * v2[x];
    }
}

/* Whether any of the columns [x0, x1) of a class row is a hit. The a-trous rows skip the groups of
 * MISS_GROUP columns without one (sky, background): a pixel without a hit keeps its source, so the
 * fused loop's taps there change nothing. */
enum { MISS_GROUP = 16 };
static inline bool any_hit(const float *restrict cls, int x0, int x1)
{
    int any = 0;
    for (int x = x0; x < x1; ++x) any |= cls[x] > 0.0f;
    return any != 0;
}

/* the columns [x0, x1) of row `row` of each part's colour (3 planes n apart) and variance planes
 * kept as they are: source PC, PV to destination PD, PDV (misses, any_hit) */
static void copy_misses(const float *const PC[2], const float *const PV[2], float *const PD[2],
                        float *const PDV[2], int parts, size_t n, size_t row, int x0, int x1)
{
    if (x1 <= x0) return;
    size_t b = (size_t)(x1 - x0) * sizeof(float);
    for (int k = 0; k < parts; ++k) {
        for (int q = 0; q < 3; ++q) memcpy(PD[k] + q * n + row + x0, PC[k] + q * n + row + x0, b);
        memcpy(PDV[k] + row + x0, PV[k] + row + x0, b);
    }
}

/* one a-trous pass (3x3 B-spline, taps c->step apart) over hits, tap by tap over each row;
 * neighbours only of the centre's class (hit with a normal, hit without one); a pixel without a hit
 * keeps its value. With c->two, the direct part (src2 -> dst2) in the same pass. */
static void atrous_rows(void *vc, uint32_t y0, uint32_t y1)
{
    tctx *c = vc;
    size_t n = c->n;
    int w = (int)c->in->width, hgt = (int)c->in->height, s = c->step, parts = c->two ? 2 : 1;
    const float *cls = plane(c, W_CLS), *H = plane(c, W_HIT), *Z = plane(c, W_Z);
    const float *N0 = c->next->nrm, *N1 = c->next->nrm + n, *N2 = c->next->nrm + 2 * n;
    const float *SN = plane(c, W_SN), *IZ = plane(c, W_IZ);
    /* per part: colour 3, variance, luminance stop; the outputs */
    const float *PC[2] = {c->src, c->src2}, *PV[2] = {c->vsrc, c->vsrc2};
    const float *PIL[2] = {plane(c, W_IL), plane(c, W_IL2)};
    float *PD[2] = {c->dst, c->dst2}, *PDV[2] = {c->vdst, c->vdst2};
    float *WS = plane(c, W_WS);
    const float k0 = HK[1] * HK[1]; /* the centre: exactly its kernel weight */
    /* the columns whose taps all lie in the image run fused (atrous_row8); the s columns at either
     * edge, and the rows whose neighbour rows y -+ s are not both in the image, tap by tap */
    int xa0 = s < w ? s : w, xb0 = w - s > xa0 ? w - s : xa0;
    ptrdiff_t sw = (ptrdiff_t)s * w;
    for (int y = (int)y0; y < (int)y1; ++y) {
        size_t row = (size_t)y * w;
        bool rows_in = y - s >= 0 && y + s < hgt;
        int xa = rows_in ? xa0 : w, xb = rows_in ? xb0 : w;
        vblur_row(c, y);
        if (xb > xa) {
            /* class, depth, normal 3; per part colour 3, variance: from row y */
            const float *P[13] = {cls + row, Z + row, N0 + row, N1 + row, N2 + row}; /* the guides */
            for (int k = 0; k < parts; ++k)
                for (int q = 0; q < 4; ++q) P[5 + 4 * k + q] = (q < 3 ? PC[k] + q * n : PV[k]) + row;
            float *o0 = PD[0] + row, *o1 = PD[0] + n + row, *o2 = PD[0] + 2 * n + row, *ov = PDV[0] + row;
            /* what a chunk reads at its own columns (the centre's planes and the outputs), and at
             * its columns shifted by -s, 0, +s (the 5 + 4 x parts neighbour planes' 3 rows) */
            const float *PM[12] = {SN + row, IZ + row, PIL[0] + row, o0, o1, o2, ov, /* part 0 */
                                   PIL[1] + row, PD[1] + row, PD[1] + n + row, PD[1] + 2 * n + row, PDV[1] + row};
            const float *PN[39];
            int nm = parts == 2 ? 12 : 7, nn = 0;
            for (int q = 0; q < 5 + 4 * parts; ++q)
                for (int r = -1; r <= 1; ++r) PN[nn++] = P[q] + r * sw;
#define SY_FUSED(A, B)                                                                                                \
    do {                                                                                                              \
        if (parts == 2)                                                                                               \
            atrous_row8_2((A), (B), s, sw, P[0], P[1], P[2], P[3], P[4], SN + row, IZ + row, P[5], P[6], P[7], P[8],  \
                          PIL[0] + row, o0, o1, o2, ov, P[9], P[10], P[11], P[12], PIL[1] + row, PD[1] + row,         \
                          PD[1] + n + row, PD[1] + 2 * n + row, PDV[1] + row, c->xmax);                               \
        else                                                                                                          \
            atrous_row8((A), (B), s, sw, P[0], P[1], P[2], P[3], P[4], P[5], P[6], P[7], P[8], SN + row,              \
                        PIL[0] + row, IZ + row, o0, o1, o2, ov, c->xmax);                                             \
    } while (0)
            /* groups of MISS_GROUP columns without a hit keep their source (what the fused loop gives
             * them, without its taps): a run of them [xm, xr) is copied when the next group with a
             * hit or the row's end comes, one copy per plane (a copy per group and plane took
             * longer, in the copy's start-up, than the taps it saved); the runs of groups with a
             * hit go through the loop */
            int xm = xa;
            for (int xc = xa; xc < xb; xc += PF_COLS) {
                int xe = xb - xc > PF_COLS ? xc + PF_COLS : xb, xn = xb - xe > PF_COLS ? xe + PF_COLS : xb;
                prefetch_cols(PM, nm, 0, xe, xn);
                prefetch_cols(PN, nn, -s, xe, xn);
                prefetch_cols(PN, nn, s, xe, xn);
                int xr = xc; /* [xm, xr): misses not yet copied, [xr, g): hits not yet filtered */
                for (int g = xc; g < xe; g += MISS_GROUP) {
                    int ge = xe - g > MISS_GROUP ? g + MISS_GROUP : xe;
                    if (any_hit(P[0], g, ge)) continue;
                    if (g > xr) {
                        SY_FUSED(xr, g);
                        copy_misses(PC, PV, PD, PDV, parts, n, row, xm, xr);
                        xm = g;
                    }
                    xr = ge;
                }
                if (xe > xr) {
                    SY_FUSED(xr, xe);
                    copy_misses(PC, PV, PD, PDV, parts, n, row, xm, xr);
                    xm = xe;
                }
            }
            copy_misses(PC, PV, PD, PDV, parts, n, row, xm, xb); /* the row's last run of misses */
#undef SY_FUSED
        }
        for (int k = 0; k < parts; ++k) {
            const float *C0 = PC[k], *C1 = PC[k] + n, *C2 = PC[k] + 2 * n, *V = PV[k], *IL = PIL[k];
            float *o0 = PD[k] + row, *o1 = PD[k] + n + row, *o2 = PD[k] + 2 * n + row;
            float *ov = PDV[k] + row, *ow = WS + row;
            for (int e = 0; e < 2; ++e) { /* the edges [0, xa) and [xb, w) */
                int ea = e ? xb : 0, eb = e ? w : xa;
                if (eb <= ea) continue;
                atrous_start(eb - ea, k0, C0 + row + ea, C1 + row + ea, C2 + row + ea, V + row + ea, o0 + ea,
                             o1 + ea, o2 + ea, ow + ea, ov + ea);
                tap3 taps[9];
                for (int t = 0, nt = row_taps(w, hgt, y, s, taps); t < nt; ++t) {
                    int dx = taps[t].dx, dy = taps[t].dy;
                    if (dx == 0 && dy == 0) continue;
                    int x0 = taps[t].x0 > ea ? taps[t].x0 : ea, x1 = taps[t].x1 < eb ? taps[t].x1 : eb;
                    if (x1 <= x0) continue;
                    size_t o = taps[t].o;
                    float kk = HK[dx + 1] * HK[dy + 1], zd = (dx && dy) ? 0.70710678f : 1.0f;
                    atrous_tap(x0, x1, kk, zd, cls + o, Z + o, N0 + o, N1 + o, N2 + o, C0 + o, C1 + o, C2 + o, V + o,
                               cls + row, C0 + row, C1 + row, C2 + row, Z + row, N0 + row, N1 + row, N2 + row,
                               SN + row, IL + row, IZ + row, o0, o1, o2, ow, ov, c->xmax);
                }
                atrous_end(eb - ea, H + row + ea, C0 + row + ea, C1 + row + ea, C2 + row + ea, V + row + ea, ow + ea,
                           o0 + ea, o1 + ea, o2 + ea, ov + ea);
            }
        }
    }
}

/* remodulation of pixels [0, w) of a row: out (RGBA, 4 floats per pixel) and the estimate's planes
 * e0-e2 = (a + b) x m (the parts' filtered planes, the albedo), e3 the samples the estimate counts
 * as (remod_rows); alpha from col (stride 4) where finite, else 1 (col NULL: 3 channels, 1) */
SY_TEMPORAL_CLONES
static void remod_row(int w, const float *restrict a0, const float *restrict a1, const float *restrict a2,
                      const float *restrict b0, const float *restrict b1, const float *restrict b2,
                      const float *restrict m0, const float *restrict m1, const float *restrict m2,
                      const float *restrict var0, const float *restrict vout, const float *restrict len,
                      const float *restrict col, float *restrict out, float *restrict e0, float *restrict e1,
                      float *restrict e2, float *restrict e3)
{
    for (int x = 0; x < w; ++x) {
        float r = (a0[x] + b0[x]) * m0[x], g_ = (a1[x] + b1[x]) * m1[x], b = (a2[x] + b2[x]) * m2[x];
        e0[x] = r, e1[x] = g_, e2[x] = b;
        out[4 * x] = r, out[4 * x + 1] = g_, out[4 * x + 2] = b;
        /* the samples the estimate counts as: its history length times the variance reduction of
         * the a-trous passes (blended variance / filtered variance of the indirect part or colour),
         * the latter within [1, 64] */
        float v0 = var0[x], v1 = vout[x], g = v1 > 0.0f ? v0 / v1 : 1.0f;
        e3[x] = len[x] * fmn(fmx(g, 1.0f), 64.0f);
    }
    if (col)
        for (int x = 0; x < w; ++x) {
            float al = col[4 * x + 3];
            out[4 * x + 3] = nonfinite0(al) == 0.0f ? al : 1.0f;
        }
    else
        for (int x = 0; x < w; ++x) out[4 * x + 3] = 1.0f;
}

static void remod_rows(void *vc, uint32_t y0, uint32_t y1)
{
    tctx *c = vc;
    const sy_filter_frame *in = c->in;
    size_t w = in->width, n = c->n, np = c->np; /* the estimate's planes are np apart */
    const float *m = plane(c, W_MOD), *a = c->outp[0], *b = c->outp[1];
    float *est = c->t->est;
    for (size_t y = y0; y < y1; ++y) {
        size_t i = y * w;
        remod_row((int)w, a + i, a + n + i, a + 2 * n + i, b + i, b + n + i, b + 2 * n + i, m + i, m + n + i,
                  m + 2 * n + i, c->var0 + i, c->vout[0] + i, c->next->len + i,
                  in->color_channels == 4 ? in->color + 4 * i : NULL, c->out + 4 * i, est + i, est + np + i,
                  est + 2 * np + i, est + 3 * np + i);
    }
}

sy_filter_status sy_filter_temporal_run(sy_filter_temporal *t, const sy_filter_frame *in, const float world_to_pixel[16],
                                        float *out, sy_filter_temporal_stats *stats, sy_filter_report *err)
{
    double t0 = sy_filter_clock(false);
    double c0 = sy_filter_clock(true);
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
    size_t np = (size_t)in->width * in->height, n = plane_stride(np);
    hist *nx = &t->h[1 - t->prev];
    t->have_est = false;
    if (np > t->est_cap) {
        free(t->est);
        t->est = np <= SIZE_MAX / (4 * sizeof(float)) ? planes_alloc(4 * np * sizeof(float)) : NULL;
        t->est_cap = t->est ? np : 0;
    }
    if (!t->est || !work_reserve(t, n) || !hist_reserve(nx, n)) {
        t->have_prev = false;
        return sy_filter_fail(err, SY_FILTER_ERROR_OUT_OF_MEMORY, "temporal: out of memory for %ux%u", in->width,
                              in->height);
    }
    hist_bind(nx, n);
    tctx c = {.t = t, .in = in, .prev = t->have_prev ? &t->h[t->prev] : NULL, .next = nx, .n = n, .np = np, .W = t->work,
              .xmax = EXP_MAX, .out = out};
    c.avx2 = sy_filter_temporal_reproject_avx2();
    uint32_t th = t->p.threads, rows = in->height;
    double ph[5];
    ph[0] = sy_filter_clock(false);
    sy_filter_parallel_rows(th, rows, demod_rows, &c);
    ph[1] = sy_filter_clock(false);
    sy_filter_parallel_rows(th, rows, integrate_rows, &c);
    ph[2] = sy_filter_clock(false);
    /* the a-trous passes: the indirect part (or the colour), and the direct part when split, both in
     * the same passes. The next history: the first pass's output for the indirect part (as SVGF),
     * written there directly; the direct part's unfiltered blend (fed back, its filtered output let
     * emitter light creep over their edges frame after frame: Cornell box relMSE 0.077 against 0.023,
     * `sy bench temporal`, 16 frames), which integrate_rows wrote there. */
    bool split = in->direct && in->indirect;
    uint32_t iters = t->p.atrous_iterations;
    const float *src[2] = {plane(&c, part_index(0, P_ACC)), nx->dir};
    const float *vsrc[2] = {plane(&c, part_index(0, P_VAR)), plane(&c, part_index(1, P_VAR))};
    if (iters == 0) memcpy(nx->illum, src[0], 3 * n * sizeof(float));
    c.two = split;
    for (uint32_t it = 0; it < iters; ++it) {
        float *dst[2], *vdst[2];
        for (int k = 0; k < 2; ++k) {
            dst[k] = it == 0 && k == 0 ? nx->illum : plane(&c, part_index(k, (it & 1) ? P_B : P_A));
            vdst[k] = plane(&c, part_index(k, (it & 1) ? P_VB : P_VA));
        }
        c.src = src[0], c.vsrc = vsrc[0], c.dst = dst[0], c.vdst = vdst[0];
        c.src2 = src[1], c.vsrc2 = vsrc[1], c.dst2 = dst[1], c.vdst2 = vdst[1];
        c.step = 1 << it;
        sy_filter_parallel_rows(th, rows, atrous_rows, &c);
        for (int k = 0; k < (split ? 2 : 1); ++k) src[k] = dst[k], vsrc[k] = vdst[k];
    }
    c.outp[0] = src[0], c.outp[1] = src[1];
    c.vout[0] = vsrc[0], c.vout[1] = vsrc[1];
    c.var0 = plane(&c, part_index(0, P_VAR));
    ph[3] = sy_filter_clock(false);
    sy_filter_parallel_rows(th, rows, remod_rows, &c);
    nx->w = in->width, nx->h = in->height;
    memcpy(nx->world_to_pixel, world_to_pixel, sizeof nx->world_to_pixel);
    t->prev = 1 - t->prev;
    t->have_prev = true;
    t->est_w = in->width, t->est_h = in->height, t->have_est = true;
    if (stats) {
        sy_filter_temporal_stats st = {.pixels = np};
        double hsum = 0;
        uint64_t hits = 0;
        const float *H = plane(&c, W_HIT);
        for (size_t i = 0; i < np; ++i) {
            st.nonfinite += !(c.W[W_OK * n + i] > 0.0f);
            if (!(H[i] > 0.0f)) continue;
            hits++, hsum += nx->len[i];
            if (nx->len[i] > 1.0f) st.reprojected++;
            else st.disoccluded++;
        }
        st.mean_history = hits ? hsum / (double)hits : 0.0;
        st.cpu_seconds = sy_filter_clock(true) - c0;
        st.seconds = sy_filter_clock(false) - t0;
        ph[4] = t0 + st.seconds;
        for (int k = 0; k < 4; ++k) st.phase_seconds[k] = ph[k + 1] - ph[k];
        *stats = st;
    }
    return SY_FILTER_OK;
}

bool sy_filter_temporal_rest(sy_filter_temporal *t, uint32_t width, uint32_t height, const float *accum_rgba,
                             uint32_t samples, float *out_rgba)
{
    size_t n = (size_t)width * height;
    bool blend = t && t->have_est && t->have_prev && accum_rgba && out_rgba && width == t->est_w &&
                 height == t->est_h && samples < t->p.rest_samples;
    if (!blend) {
        if (out_rgba && accum_rgba && out_rgba != accum_rgba) memcpy(out_rgba, accum_rgba, 4 * n * sizeof(float));
        if (t && samples >= t->p.rest_samples) t->have_est = false; /* converged: never again */
        return false;
    }
    /* the estimate's pixel i counts as its samples (remod_rows) times (1 - samples / rest_samples)^2:
     * the fade brings the accumulation in smoothly and exactly at rest_samples */
    const float *est = t->est, *cnt = t->est + 3 * n;
    float f = 1.0f - (float)samples / (float)t->p.rest_samples, fade = f * f, ns = (float)samples;
    for (size_t i = 0; i < n; ++i) {
        float h = cnt[i] * fade, wgt = h / (h + ns); /* 0/0 (no samples, no history): NaN, below */
        if (!(wgt > 0.0f)) wgt = 0.0f;
        for (int q = 0; q < 3; ++q) {
            float a = accum_rgba[4 * i + q];
            out_rgba[4 * i + q] = a + wgt * (est[q * n + i] - a);
        }
        out_rgba[4 * i + 3] = accum_rgba[4 * i + 3];
    }
    return true;
}
