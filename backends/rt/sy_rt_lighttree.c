/* sy_rt_lighttree.c — the light hierarchy: binned SAOH build, refit, importance, stochastic
 * traversal and the selection pdf (see sy_rt_lighttree.h). */
#include "sy_rt_lighttree.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define PI_F 3.14159265358979f
#define LT_BINS 12
#define LT_BINNED_DEPTH 40u   /* deeper: split at the middle index (bounds the depth on any input) */
#define LT_MAX_DEPTH 128u     /* > LT_BINNED_DEPTH + 32: the path array of the pdf */
#define LT_CONE_EPS 1e-4f     /* cone unions widen by this much (radians): float rounding never cuts a light off */

/* >>bounds */
static bool bounds_valid(const sy_rt_lt_bounds *b, bool distant)
{
    if (!(b->power > 0.0f) || !isfinite(b->power)) return false;
    for (int k = 0; k < 3; ++k)
        if (!isfinite(b->axis[k])) return false;
    if (distant) return true;
    for (int k = 0; k < 3; ++k)
        if (!isfinite(b->lo[k]) || !isfinite(b->hi[k]) || b->lo[k] > b->hi[k]) return false;
    return isfinite(b->theta_o) && isfinite(b->theta_e);
}

/* Whether light l goes into the tree (or beside its root). */
static bool light_kept(const sy_rt_lt_light *l) { return !l->dark && bounds_valid(&l->b, l->distant); }
/* Whether a kept light stands beside the root. */
static bool light_at_top(const sy_rt_lt_light *l) { return l->distant || l->top; }

/* Conty & Kulla 2018, algorithm 1: the smallest cone (of the two's form) holding both. */
static void cone_union(sy_rt_lt_bounds *out, const sy_rt_lt_bounds *a, const sy_rt_lt_bounds *b)
{
    float te = fmaxf(a->theta_e, b->theta_e);
    if (b->theta_o > a->theta_o) {
        const sy_rt_lt_bounds *s = a;
        a = b, b = s;
    }
    sy_rt_v3 aa = v3_load(a->axis), ab = v3_load(b->axis);
    float cd = sy_rt_clampf(v3_dot(aa, ab), -1.0f, 1.0f), td = acosf(cd);
    sy_rt_v3 ax = aa;
    float to;
    if (fminf(td + b->theta_o, PI_F) <= a->theta_o) {
        to = a->theta_o;
    } else {
        float o = 0.5f * (a->theta_o + td + b->theta_o) + LT_CONE_EPS;
        sy_rt_v3 perp = v3_sub(ab, v3_scale(aa, cd));
        float len = v3_length(perp);
        if (o >= PI_F || !(len > 1e-6f)) {
            to = PI_F;
        } else {
            float rot = o - a->theta_o;
            ax = v3_normalize(v3_add(v3_scale(aa, cosf(rot)), v3_scale(perp, sinf(rot) / len)));
            to = o;
        }
    }
    out->axis[0] = ax.x, out->axis[1] = ax.y, out->axis[2] = ax.z;
    out->theta_o = fminf(to, PI_F);
    out->theta_e = te;
}

/* The cosines the importance reads. */
static void bounds_finish(sy_rt_lt_bounds *b)
{
    b->cos_o = cosf(b->theta_o);
    b->sin_o = sinf(b->theta_o);
    b->cos_e = cosf(fminf(b->theta_e, 0.5f * PI_F));
}

static void bounds_union(sy_rt_lt_bounds *out, const sy_rt_lt_bounds *a, const sy_rt_lt_bounds *b)
{
    sy_rt_lt_bounds r;
    for (int k = 0; k < 3; ++k) r.lo[k] = fminf(a->lo[k], b->lo[k]), r.hi[k] = fmaxf(a->hi[k], b->hi[k]);
    r.power = a->power + b->power;
    cone_union(&r, a, b);
    *out = r; /* cos_o, sin_o, cos_e: bounds_finish, where the importance will read them */
}

static float box_area(const sy_rt_lt_bounds *b)
{
    float dx = b->hi[0] - b->lo[0], dy = b->hi[1] - b->lo[1], dz = b->hi[2] - b->lo[2];
    return 2.0f * (dx * dy + dy * dz + dz * dx);
}

/* Orientation measure M_Omega of Conty & Kulla (eq. 1). */
static float cone_measure(const sy_rt_lt_bounds *b)
{
    float to = b->theta_o, tw = fminf(to + b->theta_e, PI_F);
    float so = sinf(to), co = cosf(to);
    return 2.0f * PI_F * (1.0f - co) + 0.5f * PI_F * (2.0f * tw * so - cosf(to - 2.0f * tw) - 2.0f * to * so + co);
}

/* >>importance */
float sy_rt_lighttree_importance(const sy_rt_lt_bounds *b, sy_rt_v3 p, sy_rt_v3 n)
{
    sy_rt_v3 lo = v3_load(b->lo), hi = v3_load(b->hi);
    sy_rt_v3 c = v3_scale(v3_add(lo, hi), 0.5f), v = v3_sub(p, c), ext = v3_sub(hi, lo);
    float d2 = v3_dot(v, v), r2 = 0.25f * v3_dot(ext, ext);
    bool inside = p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y && p.z >= lo.z && p.z <= hi.z;
    float ce = 1.0f, ci = 1.0f;
    if (!inside && d2 > r2) {
        /* angles by their cosines and sines (no inverse trigonometry): theta_u, the box's angular
         * radius seen from p, is subtracted from each angle as a bound */
        float inv_d = 1.0f / sqrtf(d2);
        sy_rt_v3 wp = v3_scale(v, inv_d); /* from the light toward p */
        float sin_u = sy_rt_minf(sqrtf(r2) * inv_d, 1.0f), cos_u = sy_rt_sin_of_cos(sin_u);
        /* emission: theta' = theta - theta_o - theta_u, clamped at 0 */
        if (b->theta_o < PI_F) {
            float ct = sy_rt_clampf(v3_dot(v3_load(b->axis), wp), -1.0f, 1.0f);
            if (ct < b->cos_o) { /* theta > theta_o */
                float st = sy_rt_sin_of_cos(ct);
                float c1 = ct * b->cos_o + st * b->sin_o, s1 = st * b->cos_o - ct * b->sin_o; /* of theta - theta_o */
                if (c1 < cos_u) { /* theta - theta_o > theta_u */
                    float c2 = c1 * cos_u + s1 * sin_u;
                    if (c2 <= b->cos_e || c2 <= 0.0f) return 0.0f; /* theta' >= theta_e, or past the horizon */
                    ce = c2;
                }
            }
        }
        /* the surface: theta_i - theta_u, clamped at 0 */
        if (!v3_is_zero(n)) {
            float cti = sy_rt_clampf(-v3_dot(n, wp), -1.0f, 1.0f);
            if (cti < cos_u) {
                float sti = sy_rt_sin_of_cos(cti);
                float c2 = cti * cos_u + sti * sin_u;
                if (c2 <= 0.0f) return 0.0f;
                ci = c2;
            }
        }
    }
    float dc = sy_rt_maxf(sy_rt_maxf(d2, r2), 1e-12f);
    float w = b->power * ce * ci / dc;
    return isfinite(w) && w > 0.0f ? w : 0.0f;
}

_Static_assert(SY_RT_LT_LEAF_MAX <= 4u, "leaf_probs takes a leaf's importances in one sy_rt_lighttree_importance4");

#if defined(__GNUC__)
/* The scalar function's branches are masks here: every lane computes every term. */
typedef float lt_f4 __attribute__((vector_size(16)));
typedef int32_t lt_i4 __attribute__((vector_size(16)));
static inline lt_f4 f4_sel(lt_i4 m, lt_f4 a, lt_f4 b) { return (lt_f4)((m & (lt_i4)a) | (~m & (lt_i4)b)); }
static inline lt_f4 f4_sqrt(lt_f4 x)
{
#if defined(__SSE__)
    return __builtin_ia32_sqrtps(x);
#else
    return (lt_f4){sqrtf(x[0]), sqrtf(x[1]), sqrtf(x[2]), sqrtf(x[3])};
#endif
}
static inline lt_f4 f4_max0(lt_f4 x) { return f4_sel(x > 0.0f, x, (lt_f4){0}); } /* fmaxf(0, x) */

void sy_rt_lighttree_importance4(const sy_rt_lt_bounds *const b[4], sy_rt_v3 p, sy_rt_v3 n, float out[4])
{
    lt_f4 lx, ly, lz, hx, hy, hz, ax, ay, az, to, co, so, ce_b, pw;
    for (int i = 0; i < 4; ++i) {
        lx[i] = b[i]->lo[0], ly[i] = b[i]->lo[1], lz[i] = b[i]->lo[2];
        hx[i] = b[i]->hi[0], hy[i] = b[i]->hi[1], hz[i] = b[i]->hi[2];
        ax[i] = b[i]->axis[0], ay[i] = b[i]->axis[1], az[i] = b[i]->axis[2];
        to[i] = b[i]->theta_o, co[i] = b[i]->cos_o, so[i] = b[i]->sin_o, ce_b[i] = b[i]->cos_e, pw[i] = b[i]->power;
    }
    const lt_f4 one = {1.0f, 1.0f, 1.0f, 1.0f}, zero = {0};
    lt_f4 vx = p.x - (lx + hx) * 0.5f, vy = p.y - (ly + hy) * 0.5f, vz = p.z - (lz + hz) * 0.5f;
    lt_f4 ex = hx - lx, ey = hy - ly, ez = hz - lz;
    lt_f4 d2 = vx * vx + vy * vy + vz * vz, r2 = 0.25f * (ex * ex + ey * ey + ez * ez);
    lt_i4 inside = (p.x >= lx) & (p.x <= hx) & (p.y >= ly) & (p.y <= hy) & (p.z >= lz) & (p.z <= hz);
    lt_i4 far = ~inside & (d2 > r2);
    lt_f4 inv_d = one / f4_sqrt(d2);
    lt_f4 wx = vx * inv_d, wy = vy * inv_d, wz = vz * inv_d;
    lt_f4 su = f4_sqrt(r2) * inv_d;
    su = f4_sel(su < 1.0f, su, one);
    lt_f4 cu = f4_sqrt(f4_max0(1.0f - su * su));
    /* emission */
    lt_f4 ct = ax * wx + ay * wy + az * wz;
    ct = f4_sel(ct < -1.0f, -one, f4_sel(ct > 1.0f, one, ct));
    lt_f4 st = f4_sqrt(f4_max0(1.0f - ct * ct));
    lt_f4 c1 = ct * co + st * so, s1 = st * co - ct * so;
    lt_f4 c2e = c1 * cu + s1 * su;
    lt_i4 bend_e = far & (to < PI_F) & (ct < co) & (c1 < cu);
    lt_i4 zero_w = bend_e & ((c2e <= ce_b) | (c2e <= 0.0f));
    lt_f4 ce = f4_sel(bend_e, c2e, one);
    /* the surface */
    lt_f4 ci = one;
    if (!v3_is_zero(n)) {
        lt_f4 cti = -(n.x * wx + n.y * wy + n.z * wz);
        cti = f4_sel(cti < -1.0f, -one, f4_sel(cti > 1.0f, one, cti));
        lt_f4 sti = f4_sqrt(f4_max0(1.0f - cti * cti));
        lt_f4 c2i = cti * cu + sti * su;
        lt_i4 bend_i = far & (cti < cu);
        zero_w |= bend_i & (c2i <= 0.0f);
        ci = f4_sel(bend_i, c2i, one);
    }
    lt_f4 dc = f4_sel(d2 > r2, d2, r2);
    dc = f4_sel(dc > 1e-12f, dc, (lt_f4){1e-12f, 1e-12f, 1e-12f, 1e-12f});
    lt_f4 w = pw * ce * ci / dc;
    lt_i4 ok = ~zero_w & (w - w == zero) & (w > 0.0f); /* finite and positive */
    w = f4_sel(ok, w, zero);
    for (int i = 0; i < 4; ++i) out[i] = w[i];
}
#else
void sy_rt_lighttree_importance4(const sy_rt_lt_bounds *const b[4], sy_rt_v3 p, sy_rt_v3 n, float out[4])
{
    for (int i = 0; i < 4; ++i) out[i] = sy_rt_lighttree_importance(b[i], p, n);
}
#endif

static float distant_importance(const sy_rt_lt_bounds *b, sy_rt_v3 n)
{
    if (v3_is_zero(n)) return b->power;
    float c = -v3_dot(n, v3_load(b->axis));
    return c > 0.0f ? b->power * c : 0.0f;
}

/* >>build */
typedef struct build_task {
    uint32_t node, begin, end, depth;
} build_task;

typedef struct bin {
    sy_rt_lt_bounds b;
    uint32_t count;
} bin;

static sy_rt_v3 centroid(const sy_rt_lt_bounds *b)
{
    return v3(0.5f * (b->lo[0] + b->hi[0]), 0.5f * (b->lo[1] + b->hi[1]), 0.5f * (b->lo[2] + b->hi[2]));
}
static float v3_at(sy_rt_v3 v, int k) { return k == 0 ? v.x : (k == 1 ? v.y : v.z); }

static void bin_add(bin *bn, const sy_rt_lt_bounds *b)
{
    if (bn->count++ == 0) bn->b = *b;
    else bounds_union(&bn->b, &bn->b, b);
}

static int bin_of(float c, float lo, float scale)
{
    int i = (int)((c - lo) * scale);
    return i < 0 ? 0 : (i >= LT_BINS ? LT_BINS - 1 : i);
}

/* Finds the best binned SAOH split of refs[begin, end) (node bounds nb): axis and bin boundary
 * (the left side takes bins < *split). False when no split separates anything. */
static bool find_split(const sy_rt_lt_light *lights, const uint32_t *refs, uint32_t begin, uint32_t end,
                       const sy_rt_lt_bounds *nb, int *axis_out, int *split_out, float *clo_out, float *scale_out)
{
    sy_rt_v3 clo = v3(INFINITY, INFINITY, INFINITY), chi = v3(-INFINITY, -INFINITY, -INFINITY);
    for (uint32_t i = begin; i < end; ++i) {
        sy_rt_v3 c = centroid(&lights[refs[i]].b);
        clo = v3(fminf(clo.x, c.x), fminf(clo.y, c.y), fminf(clo.z, c.z));
        chi = v3(fmaxf(chi.x, c.x), fmaxf(chi.y, c.y), fmaxf(chi.z, c.z));
    }
    float ext[3] = {nb->hi[0] - nb->lo[0], nb->hi[1] - nb->lo[1], nb->hi[2] - nb->lo[2]};
    float lmax = fmaxf(ext[0], fmaxf(ext[1], ext[2]));
    float cext[3] = {chi.x - clo.x, chi.y - clo.y, chi.z - clo.z};
    int widest = cext[0] >= cext[1] ? (cext[0] >= cext[2] ? 0 : 2) : (cext[1] >= cext[2] ? 1 : 2);
    float best = INFINITY;
    bool found = false;
    for (int k = 0; k < 3; ++k) {
        if (!(cext[k] > 0.0f)) continue;
        if (end - begin > 4096u && k != widest) continue; /* large nodes: the widest axis only */
        bin bins[LT_BINS];
        memset(bins, 0, sizeof bins);
        float lo = v3_at(clo, k), scale = (float)LT_BINS * (1.0f - 1e-6f) / cext[k];
        for (uint32_t i = begin; i < end; ++i) {
            const sy_rt_lt_bounds *b = &lights[refs[i]].b;
            bin_add(&bins[bin_of(v3_at(centroid(b), k), lo, scale)], b);
        }
        /* suffix costs, then a sweep from the left */
        float right_cost[LT_BINS];
        bin acc = {0};
        for (int i = LT_BINS - 1; i > 0; --i) {
            if (bins[i].count) {
                if (acc.count) bounds_union(&acc.b, &acc.b, &bins[i].b);
                else acc.b = bins[i].b;
                acc.count += bins[i].count;
            }
            right_cost[i] = acc.count ? acc.b.power * box_area(&acc.b) * cone_measure(&acc.b) : -1.0f;
        }
        float kr = ext[k] > 0.0f ? lmax / ext[k] : 1.0f;
        bin left = {0};
        for (int i = 1; i < LT_BINS; ++i) {
            if (bins[i - 1].count) {
                if (left.count) bounds_union(&left.b, &left.b, &bins[i - 1].b);
                else left.b = bins[i - 1].b;
                left.count += bins[i - 1].count;
            }
            if (!left.count || right_cost[i] < 0.0f) continue;
            float cost = kr * (left.b.power * box_area(&left.b) * cone_measure(&left.b) + right_cost[i]);
            if (cost < best || !found) {
                best = cost;
                found = true;
                *axis_out = k;
                *split_out = i;
                *clo_out = lo;
                *scale_out = scale;
            }
        }
    }
    return found;
}

static void tree_reset(sy_rt_lighttree *t) { memset(t, 0, sizeof *t), t->first_skipped = SY_RT_LT_NONE; }

void sy_rt_lighttree_free(sy_rt_lighttree *t)
{
    if (!t) return;
    free(t->nodes);
    free(t->prims);
    free(t->prim_light);
    free(t->prim_leaf);
    free(t->light_prim);
    free(t->top);
    free(t->top_b);
    free(t->top_local);
    free(t->light_top);
    tree_reset(t);
}

/* The bounds of node x from its leaf's lights or its children. */
static void node_fit(sy_rt_lighttree *t, uint32_t x)
{
    sy_rt_lt_node *nd = &t->nodes[x];
    if (nd->count) {
        nd->b = t->prims[nd->child];
        for (uint32_t i = 1; i < nd->count; ++i) bounds_union(&nd->b, &nd->b, &t->prims[nd->child + i]);
    } else {
        bounds_union(&nd->b, &t->nodes[nd->child].b, &t->nodes[nd->child + 1u].b);
    }
    bounds_finish(&nd->b);
}

bool sy_rt_lighttree_build(sy_rt_lighttree *t, const sy_rt_lt_light *lights, uint32_t n, size_t max_bytes, bool *oom)
{
    tree_reset(t);
    *oom = false;
    uint32_t m = 0, nd = 0; /* lights in the tree, beside its root */
    for (uint32_t i = 0; i < n; ++i) {
        if (!light_kept(&lights[i])) {
            if (!lights[i].dark && t->skipped++ == 0) t->first_skipped = i;
        } else if (light_at_top(&lights[i])) {
            nd++;
        } else {
            m++;
        }
    }
    t->light_count = n;
    /* what the tree will hold, nodes at their bound (2m - 1) */
    size_t est = (size_t)n * sizeof(uint32_t) + (size_t)m * (sizeof(sy_rt_lt_bounds) + 2u * sizeof(uint32_t)) +
                 (size_t)(m ? 2u * m - 1u : 0u) * sizeof(sy_rt_lt_node) +
                 (size_t)nd * (sizeof(uint32_t) + sizeof(sy_rt_lt_bounds) + sizeof(bool)) +
                 (nd ? (size_t)n * sizeof(uint32_t) : 0u);
    if (max_bytes && est > max_bytes) {
        uint32_t skipped = t->skipped, first = t->first_skipped;
        tree_reset(t);
        t->skipped = skipped, t->first_skipped = first, t->bytes = est;
        return false;
    }
    t->light_prim = malloc((size_t)n * sizeof *t->light_prim + 1u);
    t->prims = malloc((size_t)m * sizeof *t->prims + 1u);
    t->prim_light = malloc((size_t)m * sizeof *t->prim_light + 1u);
    t->prim_leaf = malloc((size_t)m * sizeof *t->prim_leaf + 1u);
    t->nodes = malloc((size_t)(m ? 2u * m - 1u : 1u) * sizeof *t->nodes);
    if (nd) {
        t->top = malloc((size_t)nd * sizeof *t->top);
        t->top_b = malloc((size_t)nd * sizeof *t->top_b);
        t->top_local = malloc((size_t)nd * sizeof *t->top_local);
        t->light_top = malloc((size_t)n * sizeof *t->light_top);
    }
    build_task *stack = malloc((LT_MAX_DEPTH + 2u) * sizeof *stack);
    if (!t->light_prim || !t->prims || !t->prim_light || !t->prim_leaf || !t->nodes || !stack ||
        (nd && (!t->top || !t->top_b || !t->top_local || !t->light_top))) {
        free(stack);
        sy_rt_lighttree_free(t);
        *oom = true;
        return false;
    }
    uint32_t *refs = t->prim_light; /* partitioned in place: ends in leaf order */
    for (uint32_t i = 0; i < n; ++i) {
        t->light_prim[i] = SY_RT_LT_NONE;
        if (nd) t->light_top[i] = SY_RT_LT_NONE;
        if (!light_kept(&lights[i])) continue;
        if (light_at_top(&lights[i])) {
            t->light_top[i] = t->top_count;
            t->top_local[t->top_count] = !lights[i].distant;
            t->top_b[t->top_count] = lights[i].b;
            bounds_finish(&t->top_b[t->top_count]);
            t->top[t->top_count++] = i;
        } else {
            refs[t->prim_count++] = i;
        }
    }
    if (m) {
        uint32_t sp = 0;
        t->node_count = 1;
        t->nodes[0].parent = SY_RT_LT_NONE;
        stack[sp++] = (build_task){0, 0, m, 0};
        while (sp) {
            build_task k = stack[--sp];
            sy_rt_lt_node *node = &t->nodes[k.node];
            /* the box only (find_split's extents); node_fit makes the whole bounds at the end */
            node->b = lights[refs[k.begin]].b;
            for (uint32_t i = k.begin + 1u; i < k.end; ++i)
                for (int a = 0; a < 3; ++a) {
                    const sy_rt_lt_bounds *b = &lights[refs[i]].b;
                    node->b.lo[a] = fminf(node->b.lo[a], b->lo[a]), node->b.hi[a] = fmaxf(node->b.hi[a], b->hi[a]);
                }
            uint32_t cnt = k.end - k.begin;
            if (k.depth + 1u > t->depth) t->depth = k.depth + 1u;
            if (cnt <= SY_RT_LT_LEAF_MAX) {
                node->child = k.begin;
                node->count = cnt;
                continue;
            }
            uint32_t mid = k.begin + cnt / 2u;
            int axis, split;
            float clo, scale;
            if (k.depth < LT_BINNED_DEPTH && find_split(lights, refs, k.begin, k.end, &node->b, &axis, &split, &clo, &scale)) {
                uint32_t i = k.begin, j = k.end;
                while (i < j) {
                    if (bin_of(v3_at(centroid(&lights[refs[i]].b), axis), clo, scale) < split) {
                        ++i;
                    } else {
                        uint32_t s = refs[i];
                        refs[i] = refs[--j];
                        refs[j] = s;
                    }
                }
                if (i > k.begin && i < k.end) mid = i;
            }
            uint32_t c = t->node_count;
            t->node_count += 2u;
            node->child = c;
            node->count = 0;
            t->nodes[c].parent = t->nodes[c + 1u].parent = k.node;
            stack[sp++] = (build_task){c + 1u, mid, k.end, k.depth + 1u};
            stack[sp++] = (build_task){c, k.begin, mid, k.depth + 1u};
        }
        /* leaf order is refs order: copy the records, note each light's leaf */
        for (uint32_t i = 0; i < m; ++i) {
            t->prims[i] = lights[refs[i]].b;
            bounds_finish(&t->prims[i]);
            t->light_prim[refs[i]] = i;
        }
        for (uint32_t x = 0; x < t->node_count; ++x)
            if (t->nodes[x].count)
                for (uint32_t i = 0; i < t->nodes[x].count; ++i) t->prim_leaf[t->nodes[x].child + i] = x;
        /* the nodes' bounds again from the records (the same unions refit makes) */
        for (uint32_t x = t->node_count; x-- > 0;) node_fit(t, x);
        sy_rt_lt_node *shrunk = realloc(t->nodes, (size_t)t->node_count * sizeof *t->nodes);
        if (shrunk) t->nodes = shrunk;
    }
    free(stack);
    t->bytes = (size_t)n * sizeof(uint32_t) * (nd ? 2u : 1u) + (size_t)m * (sizeof(sy_rt_lt_bounds) + 2u * sizeof(uint32_t)) +
               (size_t)t->node_count * sizeof(sy_rt_lt_node) +
               (size_t)nd * (sizeof(uint32_t) + sizeof(sy_rt_lt_bounds) + sizeof(bool));
    return true;
}

bool sy_rt_lighttree_refit(sy_rt_lighttree *t, const sy_rt_lt_light *lights, uint32_t n, uint32_t *changed)
{
    *changed = 0;
    if (n != t->light_count) return false;
    for (uint32_t i = 0; i < n; ++i) { /* the same lights in the same places, or a rebuild */
        bool valid = light_kept(&lights[i]);
        bool in_tree = t->light_prim[i] != SY_RT_LT_NONE, in_top = t->light_top && t->light_top[i] != SY_RT_LT_NONE;
        if (valid != (in_tree || in_top)) return false;
        if (valid && light_at_top(&lights[i]) != in_top) return false;
        if (valid && in_top && t->top_local[t->light_top[i]] == lights[i].distant) return false;
    }
    uint32_t differ = 0, limit = n / 64u + 1u;
    for (uint32_t i = 0; i < n && differ <= limit; ++i) {
        uint32_t k = t->light_prim[i];
        sy_rt_lt_bounds b = lights[i].b;
        bounds_finish(&b);
        if (t->light_top && t->light_top[i] != SY_RT_LT_NONE)
            differ += memcmp(&t->top_b[t->light_top[i]], &b, sizeof b) != 0;
        else if (k != SY_RT_LT_NONE)
            differ += memcmp(&t->prims[k], &b, sizeof b) != 0;
    }
    if (differ > limit) return false; /* many changed: a fresh build (better bounds, and the image a new device gives) */
    for (uint32_t i = 0; i < n; ++i) {
        sy_rt_lt_bounds b = lights[i].b;
        bounds_finish(&b);
        if (t->light_top && t->light_top[i] != SY_RT_LT_NONE) {
            sy_rt_lt_bounds *d = &t->top_b[t->light_top[i]];
            if (memcmp(d, &b, sizeof *d)) *d = b, (*changed)++;
            continue;
        }
        uint32_t k = t->light_prim[i];
        if (k == SY_RT_LT_NONE || !memcmp(&t->prims[k], &b, sizeof b)) continue;
        t->prims[k] = b;
        (*changed)++;
        for (uint32_t x = t->prim_leaf[k]; x != SY_RT_LT_NONE; x = t->nodes[x].parent) node_fit(t, x);
    }
    return true;
}

/* >>traversal */

/* Probabilities of k (<= SY_RT_LT_LEAF_MAX) choices with weights w: by importance, or by power
 * (pw) where no choice has any (a point no light reaches keeps a proper distribution). */
static void choice_probs(float *w, const float *pw, uint32_t k)
{
    float s = 0.0f;
    for (uint32_t i = 0; i < k; ++i) s += w[i];
    if (!(s > 0.0f) || !isfinite(s)) {
        s = 0.0f;
        for (uint32_t i = 0; i < k; ++i) w[i] = pw[i], s += w[i];
    }
    for (uint32_t i = 0; i < k; ++i) w[i] = w[i] / s;
}

/* Picks among k probabilities with u; rescales u to [0, 1) within the choice. */
static uint32_t choose(const float *p, uint32_t k, float *u)
{
    float acc = 0.0f;
    for (uint32_t i = 0; i + 1u < k; ++i) {
        if (p[i] > 0.0f && *u < acc + p[i]) {
            *u = sy_rt_clampf((*u - acc) / p[i], 0.0f, 0.99999994f);
            return i;
        }
        acc += p[i];
    }
    uint32_t last = k - 1u;
    while (last > 0 && !(p[last] > 0.0f)) --last;
    *u = p[last] > 0.0f ? sy_rt_clampf((*u - acc) / p[last], 0.0f, 0.99999994f) : 0.0f;
    return last;
}

/* The bounds of top entry i (0: the root when there is a tree). */
static const sy_rt_lt_bounds *top_bounds(const sy_rt_lighttree *t, uint32_t i)
{
    return t->node_count && i == 0 ? &t->nodes[0].b : &t->top_b[i - (t->node_count ? 1u : 0u)];
}

/* The importance of top entry i at (p, n): the root and local lights by their bounds, directional
 * lights by their irradiance. */
static float top_importance(const sy_rt_lighttree *t, uint32_t i, sy_rt_v3 p, sy_rt_v3 n)
{
    bool root = t->node_count && i == 0;
    const sy_rt_lt_bounds *b = top_bounds(t, i);
    return root || t->top_local[i - (t->node_count ? 1u : 0u)] ? sy_rt_lighttree_importance(b, p, n)
                                                                : distant_importance(b, n);
}

float sy_rt_lighttree_total_importance(const sy_rt_lighttree *t, sy_rt_v3 p, sy_rt_v3 n)
{
    float s = 0.0f;
    uint32_t k = (t->node_count ? 1u : 0u) + t->top_count;
    for (uint32_t i = 0; i < k; ++i) s += top_importance(t, i, p, n);
    return s;
}

/* top entries whose importance top_prob keeps from its sum for its choice (the rest it evaluates
 * again) */
#define LT_TOP_KEPT 8u

/* The top level: the root (when there is a tree), then the lights beside it (directional ones and
 * local ones marked top), each in proportion to its importance (by power where none has any).
 * With u: chooses one (*chosen, u rescaled) and returns its probability; else returns entry
 * which's probability. */
static float top_prob(const sy_rt_lighttree *t, sy_rt_v3 p, sy_rt_v3 n, uint32_t which, float *u, uint32_t *chosen)
{
    /* weights, summed in a fixed order: pick and pdf agree */
    float s = 0.0f, ps = 0.0f, kept[LT_TOP_KEPT];
    uint32_t k = (t->node_count ? 1u : 0u) + t->top_count;
    for (uint32_t i = 0; i < k; ++i) {
        float w = top_importance(t, i, p, n);
        if (i < LT_TOP_KEPT) kept[i] = w;
        s += w;
        ps += top_bounds(t, i)->power;
    }
    bool by_power = !(s > 0.0f) || !isfinite(s);
    float total = by_power ? ps : s, acc = 0.0f;
    for (uint32_t i = 0; i < k; ++i) {
        float w = by_power ? top_bounds(t, i)->power : i < LT_TOP_KEPT ? kept[i] : top_importance(t, i, p, n);
        float pr = w / total;
        if (u) {
            if (pr > 0.0f && (*u < acc + pr || i + 1u == k)) {
                *u = sy_rt_clampf((*u - acc) / pr, 0.0f, 0.99999994f);
                *chosen = i;
                return pr;
            }
            acc += pr;
        } else if (i == which) {
            return pr;
        }
    }
    if (u) { /* rounding left u past the last nonzero entry */
        for (uint32_t i = k; i-- > 0;) {
            float w = by_power ? top_bounds(t, i)->power : top_importance(t, i, p, n);
            if (w > 0.0f) {
                *u = 0.99999994f;
                *chosen = i;
                return w / total;
            }
        }
    }
    return 0.0f;
}

/* Choices a walk's step weighs at most (a power of two): 4 = a node's grandchildren, two levels
 * down (8, three levels, measured no better: docs/BACKENDS.md "Many lights"). */
#define LT_STEP_MAX 4u

/* A step of the walk from inner node nd: its descendants as far down as every one is an inner
 * node, at most LT_STEP_MAX of them (nd's two children; where both are inner, its four
 * grandchildren; and so on), in left-to-right order into node[], with their probabilities
 * (importances, four a sy_rt_lighttree_importance4) into pr[]. Returns their number and in
 * *levels how far down they are. A step over two levels weighs each choice by its own, finer
 * bounds (the binary walk weighed the children's coarser ones first) and halves the dependent
 * steps of a walk. pick and pdf step alike. */
static uint32_t step_choices(const sy_rt_lighttree *t, const sy_rt_lt_node *nd, sy_rt_v3 p, sy_rt_v3 n,
                             uint32_t node[LT_STEP_MAX], float pr[LT_STEP_MAX], uint32_t *levels)
{
    uint32_t k = 2u;
    node[0] = nd->child, node[1] = nd->child + 1u;
    *levels = 1u;
    while (2u * k <= LT_STEP_MAX) {
        bool inner = true;
        for (uint32_t i = 0; i < k; ++i) inner = inner && !t->nodes[node[i]].count;
        if (!inner) break;
        for (uint32_t i = k; i-- > 0;) { /* in place, from the end: node[i] is read before 2i, 2i + 1 are written */
            uint32_t c = t->nodes[node[i]].child;
            node[2u * i] = c, node[2u * i + 1u] = c + 1u;
        }
        k *= 2u, ++*levels;
    }
    float pw[LT_STEP_MAX];
    for (uint32_t i = 0; i < k; i += 4u) {
        const sy_rt_lt_bounds *b[4];
        for (uint32_t j = 0; j < 4u; ++j) b[j] = &t->nodes[node[i + j < k ? i + j : i]].b;
        float w[4];
        sy_rt_lighttree_importance4(b, p, n, w);
        for (uint32_t j = 0; j < 4u && i + j < k; ++j) pr[i + j] = w[j], pw[i + j] = b[j]->power;
    }
    choice_probs(pr, pw, k);
    return k;
}

static void leaf_probs(const sy_rt_lighttree *t, const sy_rt_lt_node *nd, sy_rt_v3 p, sy_rt_v3 n, float *pr)
{
    float pw[SY_RT_LT_LEAF_MAX], w[4];
    const sy_rt_lt_bounds *b[4];
    for (uint32_t i = 0; i < 4u; ++i) b[i] = &t->prims[nd->child + (i < nd->count ? i : 0u)];
    sy_rt_lighttree_importance4(b, p, n, w);
    for (uint32_t i = 0; i < nd->count; ++i) pw[i] = t->prims[nd->child + i].power, pr[i] = w[i];
    choice_probs(pr, pw, nd->count);
}

uint32_t sy_rt_lighttree_pick(const sy_rt_lighttree *t, sy_rt_v3 p, sy_rt_v3 n, float u, float *pdf)
{
    *pdf = 0.0f;
    if (!t->node_count && !t->top_count) return SY_RT_LT_NONE;
    uint32_t top = 0;
    float prob = top_prob(t, p, n, 0, &u, &top);
    if (!(prob > 0.0f)) return SY_RT_LT_NONE;
    if (!t->node_count || top > 0) {
        *pdf = prob;
        return t->top[top - (t->node_count ? 1u : 0u)];
    }
    const sy_rt_lt_node *nd = t->nodes;
    while (!nd->count) {
        uint32_t node[LT_STEP_MAX], levels;
        float pr[LT_STEP_MAX];
        uint32_t k = step_choices(t, nd, p, n, node, pr, &levels);
        uint32_t c = choose(pr, k, &u);
        prob *= pr[c];
        nd = &t->nodes[node[c]];
    }
    float pr[SY_RT_LT_LEAF_MAX];
    leaf_probs(t, nd, p, n, pr);
    uint32_t c = choose(pr, nd->count, &u);
    prob *= pr[c];
    *pdf = prob;
    return prob > 0.0f ? t->prim_light[nd->child + c] : SY_RT_LT_NONE;
}

float sy_rt_lighttree_pdf(const sy_rt_lighttree *t, sy_rt_v3 p, sy_rt_v3 n, uint32_t light)
{
    if (light >= t->light_count) return 0.0f;
    if (t->light_top && t->light_top[light] != SY_RT_LT_NONE)
        return top_prob(t, p, n, t->light_top[light] + (t->node_count ? 1u : 0u), NULL, NULL);
    uint32_t k = t->light_prim[light];
    if (k == SY_RT_LT_NONE) return 0.0f;
    /* the path from the root, then the same products in the same order as pick */
    uint32_t path[LT_MAX_DEPTH + 1u], depth = 0;
    for (uint32_t x = t->prim_leaf[k]; x != SY_RT_LT_NONE && depth <= LT_MAX_DEPTH; x = t->nodes[x].parent) path[depth++] = x;
    if (!depth) return 0.0f;
    float prob = top_prob(t, p, n, 0, NULL, NULL);
    for (uint32_t d = depth - 1u; d > 0u;) { /* path[d]: the node the walk is at */
        uint32_t node[LT_STEP_MAX], levels;
        float pr[LT_STEP_MAX];
        uint32_t k = step_choices(t, &t->nodes[path[d]], p, n, node, pr, &levels);
        if (levels > d) return 0.0f; /* (a path that ends on an inner node: not in a built tree) */
        uint32_t c = 0;
        while (c < k && node[c] != path[d - levels]) ++c;
        if (c == k) return 0.0f; /* (not below it: not in a built tree) */
        prob *= pr[c];
        d -= levels;
    }
    const sy_rt_lt_node *leaf = &t->nodes[path[0]];
    float pr[SY_RT_LT_LEAF_MAX];
    leaf_probs(t, leaf, p, n, pr);
    return prob * pr[k - leaf->child];
}
