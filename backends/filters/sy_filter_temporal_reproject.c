/* sy_filter_temporal_reproject.c — the temporal stage's reprojection (sy_filter_temporal.c calls
 * it per row): each hit pixel's previous world position projected into the previous frame, the four
 * bilinear taps of the previous history that agree with it in depth (along the normal and in
 * distance) and normal, their weighted mean, or no history. A scalar loop written branch-free and
 * an AVX2 version with gathers (GCC does not vectorise the scalar one: 4 gathered taps of 17 planes
 * per pixel; plain loads where a group's taps lie side by side), the same operations in the
 * same order per lane, so the same results; see sy_filter_temporal_internal.h. */
#include "sy_filter_temporal_internal.h"

#include <math.h>

/* the reprojection's gathers, written with AVX2 intrinsics, picked at run time */
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define SY_TEMPORAL_AVX2 1
#include <immintrin.h>
#else
#define SY_TEMPORAL_AVX2 0
#endif

/* one bilinear tap of reproject_row: weight wk (0 when invalid) of history pixel (xx, yy) */
static inline SY_TEMPORAL_INLINE void reproject_tap(int xx, int yy, float wk, int hw, int hh, size_t hn,
                                                    const float *restrict base, float p0, float p1, float p2,
                                                    float n0, float n1, float n2, float hnc, float tol, float tol2,
                                                    float ntol, float *acc, float *sw)
{
    float inb = (float)(xx >= 0) * (float)(yy >= 0) * (float)(xx < hw) * (float)(yy < hh);
    int xc = xx > 0 ? xx : 0, yc = yy > 0 ? yy : 0;
    xc = xc < hw - 1 ? xc : hw - 1, yc = yc < hh - 1 ? yc : hh - 1;
    size_t j = (size_t)yc * (size_t)hw + (size_t)xc;
    const float *pos = base + 11 * hn, *nrm = base + 14 * hn;
    float d0 = pos[j] - p0, d1 = pos[hn + j] - p1, d2 = pos[2 * hn + j] - p2;
    float m0 = nrm[j], m1 = nrm[hn + j], m2 = nrm[2 * hn + j];
    float hnj = (float)(m0 * m0 + m1 * m1 + m2 * m2 > 0.25f); /* has_normal */
    float dot = n0 * m0 + n1 * m1 + n2 * m2;
    float ok = inb * (float)(base[10 * hn + j] > 0.0f) * (float)(fabsf(d0 * n0 + d1 * n1 + d2 * n2) <= tol) *
               (float)(d0 * d0 + d1 * d1 + d2 * d2 <= tol2) * (float)(hnc == hnj) *
               fmx(1.0f - hnc, (float)(dot >= ntol));
    float k = fmx(wk * ok, 0.0f);
#define SY_ACC(q) acc[q] += k * base[(q) * hn + j]
    SY_ACC(0), SY_ACC(1), SY_ACC(2), SY_ACC(3), SY_ACC(4), SY_ACC(5), SY_ACC(6), SY_ACC(7), SY_ACC(8), SY_ACC(9), SY_ACC(10);
#undef SY_ACC
    *sw += k;
}

/* Bilinear reprojection of a row's hits into the previous history (reproject's rule, branch-free so
 * that it vectorises with gathers): the points' previous positions pa pb pc (the frame's, moved back
 * by the object motion), normals na nb nc, depth z
 * and hit h (planes); M the previous world_to_pixel, base its history (hw x hh, 17 planes hn
 * apart: illum 3, dir 3, moments 4, length, position 3, normal 3). Out: R (11 planes n apart: the
 * history, 0 where none fits) and ru (1 where reused). */
static void reproject_row(int xa, int w, size_t n, const float *restrict M, int hw, int hh, size_t hn,
                          const float *restrict base, float dtol, float ntol, const float *restrict pa,
                          const float *restrict pb, const float *restrict pc, const float *restrict na,
                          const float *restrict nb, const float *restrict nc, const float *restrict z,
                          const float *restrict h, float *restrict R, float *restrict ru)
{
    float fw = (float)hw, fh = (float)hh;
    for (int x = xa; x < w; ++x) {
        float p0 = pa[x], p1 = pb[x], p2 = pc[x], n0 = na[x], n1 = nb[x], n2 = nc[x];
        float X = M[0] * p0 + M[4] * p1 + M[8] * p2 + M[12], Y = M[1] * p0 + M[5] * p1 + M[9] * p2 + M[13];
        float Wc = M[3] * p0 + M[7] * p1 + M[11] * p2 + M[15];
        float iW = 1.0f / fmx(Wc, 1e-12f), fx = X * iW - 0.5f, fy = Y * iW - 0.5f;
        float valid = h[x] * (float)(Wc > 1e-12f) * (float)(fx > -1.0f) * (float)(fy > -1.0f) * (float)(fx < fw) *
                      (float)(fy < fh);
        fx = fmx(-1.0f, fmn(fx, fw)), fy = fmx(-1.0f, fmn(fy, fh)); /* NaN: fw, fh (valid is 0) */
        int x0 = (int)(fx + 1.0f) - 1, y0 = (int)(fy + 1.0f) - 1; /* floor: > -1 */
        float ax = fx - (float)x0, ay = fy - (float)y0;
        float tol = dtol * z[x], tol2 = 64.0f * tol * tol;
        float hnc = (float)(n0 * n0 + n1 * n1 + n2 * n2 > 0.25f);
        float acc[11] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0}, sw = 0.0f;
        reproject_tap(x0, y0, valid * (1.0f - ax) * (1.0f - ay), hw, hh, hn, base, p0, p1, p2, n0, n1, n2, hnc, tol,
                      tol2, ntol, acc, &sw);
        reproject_tap(x0 + 1, y0, valid * ax * (1.0f - ay), hw, hh, hn, base, p0, p1, p2, n0, n1, n2, hnc, tol, tol2,
                      ntol, acc, &sw);
        reproject_tap(x0, y0 + 1, valid * (1.0f - ax) * ay, hw, hh, hn, base, p0, p1, p2, n0, n1, n2, hnc, tol, tol2,
                      ntol, acc, &sw);
        reproject_tap(x0 + 1, y0 + 1, valid * ax * ay, hw, hh, hn, base, p0, p1, p2, n0, n1, n2, hnc, tol, tol2, ntol,
                      acc, &sw);
        float u = (float)(sw > 1e-3f), isw = u / fmx(sw, 1e-3f);
#define SY_OUT(q) R[(q) * n + x] = acc[q] * isw
        SY_OUT(0), SY_OUT(1), SY_OUT(2), SY_OUT(3), SY_OUT(4), SY_OUT(5), SY_OUT(6), SY_OUT(7), SY_OUT(8), SY_OUT(9),
            SY_OUT(10);
#undef SY_OUT
        ru[x] = u;
    }
}

#if SY_TEMPORAL_AVX2
/* reproject_row for 8 pixels at a time with AVX2 gathers (the history's planes hold fewer than 2^31
 * pixels): the same operations in the same order per lane as the scalar loop (0/1 products as
 * masks, fmx / fmn as max / min, which return the second operand for NaN or equal operands as the
 * ternaries do; no FMA), so the same results; the columns after the last group of 8 go through
 * reproject_row. */
__attribute__((target("avx2"))) static void reproject_row_avx2(
    int w, size_t n, const float *restrict M, int hw, int hh, size_t hn, const float *restrict base, float dtol,
    float ntol, const float *restrict pa, const float *restrict pb, const float *restrict pc,
    const float *restrict na, const float *restrict nb, const float *restrict nc, const float *restrict z,
    const float *restrict h, float *restrict R, float *restrict ru)
{
    const __m256 one = _mm256_set1_ps(1.0f), zero = _mm256_setzero_ps(), quarter = _mm256_set1_ps(0.25f);
    const __m256 fw = _mm256_set1_ps((float)hw), fh = _mm256_set1_ps((float)hh), eps = _mm256_set1_ps(1e-12f);
    const __m256 m1 = _mm256_set1_ps(-1.0f), half = _mm256_set1_ps(0.5f), vdtol = _mm256_set1_ps(dtol);
    const __m256 vntol = _mm256_set1_ps(ntol), k64 = _mm256_set1_ps(64.0f), sw_min = _mm256_set1_ps(1e-3f);
    const __m256 sign = _mm256_set1_ps(-0.0f);
    const __m256i izero = _mm256_setzero_si256(), ione = _mm256_set1_epi32(1), iw = _mm256_set1_epi32(hw);
    const __m256i ih = _mm256_set1_epi32(hh), iwm = _mm256_set1_epi32(hw - 1), ihm = _mm256_set1_epi32(hh - 1);
    const __m256i iota = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    __m256 Mv[16];
    for (int k = 0; k < 16; ++k) Mv[k] = _mm256_set1_ps(M[k]);
    const float *pos0 = base + 11 * hn, *pos1 = base + 12 * hn, *pos2 = base + 13 * hn;
    const float *nrm0 = base + 14 * hn, *nrm1 = base + 15 * hn, *nrm2 = base + 16 * hn, *len = base + 10 * hn;
    int x = 0;
    for (; x + 8 <= w; x += 8) {
        __m256 p0 = _mm256_loadu_ps(pa + x), p1 = _mm256_loadu_ps(pb + x), p2 = _mm256_loadu_ps(pc + x);
        __m256 n0 = _mm256_loadu_ps(na + x), n1 = _mm256_loadu_ps(nb + x), n2 = _mm256_loadu_ps(nc + x);
#define SY_PROJ(a, b, c, d)                                                                                           \
    _mm256_add_ps(_mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(Mv[a], p0), _mm256_mul_ps(Mv[b], p1)),                    \
                                _mm256_mul_ps(Mv[c], p2)),                                                            \
                  Mv[d])
        __m256 X = SY_PROJ(0, 4, 8, 12), Y = SY_PROJ(1, 5, 9, 13), Wc = SY_PROJ(3, 7, 11, 15);
#undef SY_PROJ
        __m256 iW = _mm256_div_ps(one, _mm256_max_ps(Wc, eps));
        __m256 fx = _mm256_sub_ps(_mm256_mul_ps(X, iW), half), fy = _mm256_sub_ps(_mm256_mul_ps(Y, iW), half);
        __m256 vm = _mm256_and_ps(_mm256_cmp_ps(_mm256_loadu_ps(h + x), zero, _CMP_NEQ_OQ),
                                  _mm256_cmp_ps(Wc, eps, _CMP_GT_OQ));
        vm = _mm256_and_ps(vm, _mm256_and_ps(_mm256_cmp_ps(fx, m1, _CMP_GT_OQ), _mm256_cmp_ps(fy, m1, _CMP_GT_OQ)));
        vm = _mm256_and_ps(vm, _mm256_and_ps(_mm256_cmp_ps(fx, fw, _CMP_LT_OQ), _mm256_cmp_ps(fy, fh, _CMP_LT_OQ)));
        __m256 valid = _mm256_and_ps(vm, _mm256_loadu_ps(h + x)); /* h (1) where valid, else 0 */
        /* no lane can find history (misses, points outside the previous view): the taps' result,
         * zeros (every weight is 0 and the history is finite), without their 68 gathers */
        if (_mm256_movemask_ps(vm) == 0) {
            for (int q = 0; q < 11; ++q) _mm256_storeu_ps(R + (size_t)q * n + x, zero);
            _mm256_storeu_ps(ru + x, zero);
            continue;
        }
        fx = _mm256_max_ps(m1, _mm256_min_ps(fx, fw)), fy = _mm256_max_ps(m1, _mm256_min_ps(fy, fh));
        __m256i x0 = _mm256_sub_epi32(_mm256_cvttps_epi32(_mm256_add_ps(fx, one)), ione);
        __m256i y0 = _mm256_sub_epi32(_mm256_cvttps_epi32(_mm256_add_ps(fy, one)), ione);
        __m256 ax = _mm256_sub_ps(fx, _mm256_cvtepi32_ps(x0)), ay = _mm256_sub_ps(fy, _mm256_cvtepi32_ps(y0));
        __m256 tol = _mm256_mul_ps(vdtol, _mm256_loadu_ps(z + x)), tol2 = _mm256_mul_ps(_mm256_mul_ps(k64, tol), tol);
        __m256 nn = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(n0, n0), _mm256_mul_ps(n1, n1)), _mm256_mul_ps(n2, n2));
        __m256 hnc = _mm256_cmp_ps(nn, quarter, _CMP_GT_OQ); /* mask */
        __m256 acc[11], sw = zero;
        for (int q = 0; q < 11; ++q) acc[q] = zero;
        __m256 bx = _mm256_sub_ps(one, ax), by = _mm256_sub_ps(one, ay);
        for (int t = 0; t < 4; ++t) {
            int tx = t & 1, ty = t >> 1;
            __m256i xx = tx ? _mm256_add_epi32(x0, ione) : x0, yy = ty ? _mm256_add_epi32(y0, ione) : y0;
            __m256 wk = _mm256_mul_ps(_mm256_mul_ps(valid, tx ? ax : bx), ty ? ay : by);
            __m256i inb = _mm256_and_si256(_mm256_cmpgt_epi32(xx, _mm256_set1_epi32(-1)),
                                           _mm256_cmpgt_epi32(yy, _mm256_set1_epi32(-1)));
            inb = _mm256_and_si256(inb, _mm256_and_si256(_mm256_cmpgt_epi32(iw, xx), _mm256_cmpgt_epi32(ih, yy)));
            __m256i xc = _mm256_min_epi32(_mm256_max_epi32(xx, izero), iwm);
            __m256i yc = _mm256_min_epi32(_mm256_max_epi32(yy, izero), ihm);
            __m256i j = _mm256_add_epi32(_mm256_mullo_epi32(yc, iw), xc);
            /* the 8 lanes' taps on 8 consecutive history pixels (the view moved little; on the
             * demo and the Cornell box 63-73 % of the taps): one plain load of the same values
             * per plane instead of a gather */
            int jf = _mm256_cvtsi256_si32(j);
            bool run = _mm256_movemask_ps(_mm256_castsi256_ps(
                           _mm256_cmpeq_epi32(j, _mm256_add_epi32(_mm256_set1_epi32(jf), iota)))) == 0xff;
#define SY_TAP(p) (run ? _mm256_loadu_ps((p) + jf) : _mm256_i32gather_ps((p), j, 4))
            __m256 d0 = _mm256_sub_ps(SY_TAP(pos0), p0);
            __m256 d1 = _mm256_sub_ps(SY_TAP(pos1), p1);
            __m256 d2 = _mm256_sub_ps(SY_TAP(pos2), p2);
            __m256 e0 = SY_TAP(nrm0), e1 = SY_TAP(nrm1);
            __m256 e2 = SY_TAP(nrm2), ln = SY_TAP(len);
            __m256 ee = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(e0, e0), _mm256_mul_ps(e1, e1)), _mm256_mul_ps(e2, e2));
            __m256 hnj = _mm256_cmp_ps(ee, quarter, _CMP_GT_OQ);
            __m256 dot = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(n0, e0), _mm256_mul_ps(n1, e1)), _mm256_mul_ps(n2, e2));
            __m256 dn = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(d0, n0), _mm256_mul_ps(d1, n1)), _mm256_mul_ps(d2, n2));
            __m256 dd = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(d0, d0), _mm256_mul_ps(d1, d1)), _mm256_mul_ps(d2, d2));
            __m256 ok = _mm256_and_ps(_mm256_castsi256_ps(inb), _mm256_cmp_ps(ln, zero, _CMP_GT_OQ));
            ok = _mm256_and_ps(ok, _mm256_cmp_ps(_mm256_andnot_ps(sign, dn), tol, _CMP_LE_OQ));
            ok = _mm256_and_ps(ok, _mm256_cmp_ps(dd, tol2, _CMP_LE_OQ));
            ok = _mm256_andnot_ps(_mm256_xor_ps(hnc, hnj), ok); /* hnc == hnj */
            /* fmx(1 - hnc, dot >= ntol): 1 without a normal, else the test */
            ok = _mm256_and_ps(ok, _mm256_or_ps(_mm256_xor_ps(hnc, _mm256_castsi256_ps(_mm256_set1_epi32(-1))),
                                                _mm256_cmp_ps(dot, vntol, _CMP_GE_OQ)));
            __m256 k = _mm256_max_ps(_mm256_and_ps(wk, ok), zero);
            for (int q = 0; q < 10; ++q)
                acc[q] = _mm256_add_ps(acc[q], _mm256_mul_ps(k, SY_TAP(base + (size_t)q * hn)));
#undef SY_TAP
            acc[10] = _mm256_add_ps(acc[10], _mm256_mul_ps(k, ln));
            sw = _mm256_add_ps(sw, k);
        }
        __m256 u = _mm256_and_ps(_mm256_cmp_ps(sw, sw_min, _CMP_GT_OQ), one);
        __m256 isw = _mm256_div_ps(u, _mm256_max_ps(sw, sw_min));
        for (int q = 0; q < 11; ++q) _mm256_storeu_ps(R + (size_t)q * n + x, _mm256_mul_ps(acc[q], isw));
        _mm256_storeu_ps(ru + x, u);
    }
    if (x < w)
        reproject_row(x, w, n, M, hw, hh, hn, base, dtol, ntol, pa, pb, pc, na, nb, nc, z, h, R, ru);
}
#endif

bool sy_filter_temporal_reproject_avx2(void)
{
#if SY_TEMPORAL_AVX2
    return __builtin_cpu_supports("avx2");
#else
    return false;
#endif
}

void sy_filter_temporal_reproject_row(bool avx2, int w, size_t n, const float *M, int hw, int hh, size_t hn,
                                      const float *base, float dtol, float ntol, const float *pa, const float *pb,
                                      const float *pc, const float *na, const float *nb, const float *nc,
                                      const float *z, const float *h, float *R, float *ru)
{
#if SY_TEMPORAL_AVX2
    if (avx2 && hn < (size_t)1 << 31) {
        reproject_row_avx2(w, n, M, hw, hh, hn, base, dtol, ntol, pa, pb, pc, na, nb, nc, z, h, R, ru);
        return;
    }
#else
    (void)avx2;
#endif
    reproject_row(0, w, n, M, hw, hh, hn, base, dtol, ntol, pa, pb, pc, na, nb, nc, z, h, R, ru);
}
