/* sy_text.c — flat text geometry with FreeType (see sy_text.h).
 *
 * Sections: >>earcut (polygon with holes -> triangles)  >>outlines (flattening, contour nesting)
 * >>layout (lines, justification, the primitive) */
#include "sy_text.h"

#include <ft2build.h>
#include FT_FREETYPE_H
#include FT_OUTLINE_H

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* >>earcut: a port of the earcut method (mapbox/earcut, ISC licence, algorithm only) on a node
 * pool: outer ring and holes as linked rings, holes bridged into the outer ring, then ear clipping
 * with the usual fall-backs (filter degenerate points, cure local self-intersections, split). */
typedef struct enode {
    uint32_t i;
    double x, y;
    struct enode *prev, *next;
    bool steiner;
} enode;

typedef struct ecut {
    enode *pool;
    size_t used, cap;
    uint32_t *tris;
    size_t ntris, tri_cap;
    unsigned depth;
} ecut;

static enode *e_insert(ecut *E, uint32_t i, double x, double y, enode *last)
{
    if (E->used == E->cap) return NULL;
    enode *p = &E->pool[E->used++];
    memset(p, 0, sizeof *p);
    p->i = i, p->x = x, p->y = y;
    if (!last) {
        p->prev = p->next = p;
    } else {
        p->next = last->next;
        p->prev = last;
        last->next->prev = p;
        last->next = p;
    }
    return p;
}

static void e_remove(enode *p)
{
    p->next->prev = p->prev;
    p->prev->next = p->next;
}

static double e_area(const enode *p, const enode *q, const enode *r)
{
    return (q->y - p->y) * (r->x - q->x) - (q->x - p->x) * (r->y - q->y);
}

static bool e_equals(const enode *a, const enode *b) { return a->x == b->x && a->y == b->y; }

static bool e_in_tri(double ax, double ay, double bx, double by, double cx, double cy, double px, double py)
{
    return (cx - px) * (ay - py) >= (ax - px) * (cy - py) && (ax - px) * (by - py) >= (bx - px) * (ay - py) &&
           (bx - px) * (cy - py) >= (cx - px) * (by - py);
}

static int e_sign(double v) { return v > 0 ? 1 : v < 0 ? -1 : 0; }

static bool e_on_segment(const enode *p, const enode *q, const enode *r)
{
    return q->x <= fmax(p->x, r->x) && q->x >= fmin(p->x, r->x) && q->y <= fmax(p->y, r->y) && q->y >= fmin(p->y, r->y);
}

static bool e_intersects(const enode *p1, const enode *q1, const enode *p2, const enode *q2)
{
    int o1 = e_sign(e_area(p1, q1, p2)), o2 = e_sign(e_area(p1, q1, q2));
    int o3 = e_sign(e_area(p2, q2, p1)), o4 = e_sign(e_area(p2, q2, q1));
    if (o1 != o2 && o3 != o4) return true;
    if (o1 == 0 && e_on_segment(p1, p2, q1)) return true;
    if (o2 == 0 && e_on_segment(p1, q2, q1)) return true;
    if (o3 == 0 && e_on_segment(p2, p1, q2)) return true;
    if (o4 == 0 && e_on_segment(p2, q1, q2)) return true;
    return false;
}

static bool e_intersects_polygon(const enode *a, const enode *b)
{
    const enode *p = a;
    do {
        if (p->i != a->i && p->next->i != a->i && p->i != b->i && p->next->i != b->i && e_intersects(p, p->next, a, b))
            return true;
        p = p->next;
    } while (p != a);
    return false;
}

static bool e_locally_inside(const enode *a, const enode *b)
{
    return e_area(a->prev, a, a->next) < 0 ? e_area(a, b, a->next) >= 0 && e_area(a, a->prev, b) >= 0
                                           : e_area(a, b, a->prev) < 0 || e_area(a, a->next, b) < 0;
}

static bool e_middle_inside(const enode *a, const enode *b)
{
    const enode *p = a;
    bool inside = false;
    double px = (a->x + b->x) / 2, py = (a->y + b->y) / 2;
    do {
        if (((p->y > py) != (p->next->y > py)) && p->next->y != p->y &&
            (px < (p->next->x - p->x) * (py - p->y) / (p->next->y - p->y) + p->x))
            inside = !inside;
        p = p->next;
    } while (p != a);
    return inside;
}

static bool e_valid_diagonal(const enode *a, const enode *b)
{
    return a->next->i != b->i && a->prev->i != b->i && !e_intersects_polygon(a, b) &&
           ((e_locally_inside(a, b) && e_locally_inside(b, a) && e_middle_inside(a, b) &&
             (e_area(a->prev, a, b->prev) != 0 || e_area(a, b->prev, b) != 0)) ||
            (e_equals(a, b) && e_area(a->prev, a, a->next) > 0 && e_area(b->prev, b, b->next) > 0));
}

/* Splits the ring by the diagonal a-b into two; returns the new node next to b. */
static enode *e_split(ecut *E, enode *a, enode *b)
{
    if (E->used + 2 > E->cap) return NULL;
    enode *a2 = e_insert(E, a->i, a->x, a->y, NULL), *b2 = e_insert(E, b->i, b->x, b->y, NULL);
    enode *an = a->next, *bp = b->prev;
    a->next = b;
    b->prev = a;
    a2->next = an;
    an->prev = a2;
    b2->next = a2;
    a2->prev = b2;
    bp->next = b2;
    b2->prev = bp;
    return b2;
}

static enode *e_filter(enode *start, enode *end)
{
    if (!start) return start;
    if (!end) end = start;
    enode *p = start;
    bool again;
    do {
        again = false;
        if (!p->steiner && (e_equals(p, p->next) || e_area(p->prev, p, p->next) == 0)) {
            e_remove(p);
            p = end = p->prev;
            if (p == p->next) break;
            again = true;
        } else {
            p = p->next;
        }
    } while (again || p != end);
    return end;
}

static void e_emit(ecut *E, const enode *a, const enode *b, const enode *c)
{
    if (E->ntris == E->tri_cap) return;
    uint32_t *t = E->tris + 3 * E->ntris++;
    t[0] = a->i, t[1] = b->i, t[2] = c->i;
}

static bool e_is_ear(const enode *ear)
{
    const enode *a = ear->prev, *b = ear, *c = ear->next;
    if (e_area(a, b, c) >= 0) return false; /* reflex */
    double x0 = fmin(a->x, fmin(b->x, c->x)), x1 = fmax(a->x, fmax(b->x, c->x));
    double y0 = fmin(a->y, fmin(b->y, c->y)), y1 = fmax(a->y, fmax(b->y, c->y));
    for (const enode *p = c->next; p != a; p = p->next)
        if (p->x >= x0 && p->x <= x1 && p->y >= y0 && p->y <= y1 &&
            e_in_tri(a->x, a->y, b->x, b->y, c->x, c->y, p->x, p->y) && e_area(p->prev, p, p->next) >= 0)
            return false;
    return true;
}

static enode *e_cure(ecut *E, enode *start)
{
    enode *p = start;
    do {
        enode *a = p->prev, *b = p->next->next;
        if (!e_equals(a, b) && e_intersects(a, p, p->next, b) && e_locally_inside(a, b) && e_locally_inside(b, a)) {
            e_emit(E, a, p, b);
            e_remove(p);
            e_remove(p->next);
            p = start = b;
        }
        p = p->next;
    } while (p != start);
    return e_filter(p, NULL);
}

static void e_linked(ecut *E, enode *ear, int pass);

static void e_split_earcut(ecut *E, enode *start)
{
    enode *a = start;
    do {
        for (enode *b = a->next->next; b != a->prev; b = b->next) {
            if (a->i != b->i && e_valid_diagonal(a, b)) {
                enode *c = e_split(E, a, b);
                if (!c) return;
                a = e_filter(a, a->next);
                c = e_filter(c, c->next);
                e_linked(E, a, 0);
                e_linked(E, c, 0);
                return;
            }
        }
        a = a->next;
    } while (a != start);
}

static void e_linked(ecut *E, enode *ear, int pass)
{
    if (!ear || E->depth > 256) return; /* bounded recursion: a hostile ring stays partly open */
    E->depth++;
    enode *stop = ear;
    while (ear->prev != ear->next) {
        enode *prev = ear->prev, *next = ear->next;
        if (e_is_ear(ear)) {
            e_emit(E, prev, ear, next);
            e_remove(ear);
            ear = next->next;
            stop = next->next;
            continue;
        }
        ear = next;
        if (ear == stop) {
            if (pass == 0) e_linked(E, e_filter(ear, NULL), 1);
            else if (pass == 1) e_linked(E, e_cure(E, e_filter(ear, NULL)), 2);
            else e_split_earcut(E, ear);
            break;
        }
    }
    E->depth--;
}

static double ring_area(const double *xy, size_t a, size_t b)
{
    double s = 0;
    for (size_t i = a, j = b - 1; i < b; j = i++) s += (xy[2 * j] - xy[2 * i]) * (xy[2 * i + 1] + xy[2 * j + 1]);
    return s;
}

static enode *e_ring(ecut *E, const double *xy, size_t a, size_t b, bool clockwise)
{
    enode *last = NULL;
    if (clockwise == (ring_area(xy, a, b) > 0)) {
        for (size_t i = a; i < b; i++)
            if (!(last = e_insert(E, (uint32_t)i, xy[2 * i], xy[2 * i + 1], last))) return NULL;
    } else {
        for (size_t i = b; i-- > a;)
            if (!(last = e_insert(E, (uint32_t)i, xy[2 * i], xy[2 * i + 1], last))) return NULL;
    }
    if (last && e_equals(last, last->next)) {
        e_remove(last);
        last = last->next;
    }
    return last;
}

static bool e_sector_contains(const enode *m, const enode *p)
{
    return e_area(m->prev, m, p->prev) < 0 && e_area(p->next, m, m->next) < 0;
}

static enode *e_bridge(enode *hole, enode *outer)
{
    enode *p = outer, *m = NULL;
    double hx = hole->x, hy = hole->y, qx = -INFINITY;
    do {
        if (hy <= p->y && hy >= p->next->y && p->next->y != p->y) {
            double x = p->x + (hy - p->y) * (p->next->x - p->x) / (p->next->y - p->y);
            if (x <= hx && x > qx) {
                qx = x;
                m = p->x < p->next->x ? p : p->next;
                if (x == hx) return m;
            }
        }
        p = p->next;
    } while (p != outer);
    if (!m) return NULL;
    enode *stop = m;
    double mx = m->x, my = m->y, tan_min = INFINITY;
    p = m;
    do {
        if (hx >= p->x && p->x >= mx && hx != p->x &&
            e_in_tri(hy < my ? hx : qx, hy, mx, my, hy < my ? qx : hx, hy, p->x, p->y)) {
            double tan = fabs(hy - p->y) / (hx - p->x);
            if (e_locally_inside(p, hole) &&
                (tan < tan_min || (tan == tan_min && (p->x > m->x || (p->x == m->x && e_sector_contains(m, p)))))) {
                m = p;
                tan_min = tan;
            }
        }
        p = p->next;
    } while (p != stop);
    return m;
}

static int cmp_leftmost(const void *a, const void *b)
{
    const enode *x = *(enode *const *)a, *y = *(enode *const *)b;
    return x->x < y->x ? -1 : x->x > y->x;
}

size_t sy_text_triangulate(const double *xy, size_t n, const size_t *ring_start, size_t rings, uint32_t *tris)
{
    if (rings == 0 || n < 3) return 0;
    ecut E = {0};
    E.cap = SY_TEXT_TRIANGULATE_CAPACITY(n, rings); /* ring nodes, bridges (2 each), splits */
    E.tri_cap = E.cap; /* every triangle removes at least one node */
    E.pool = malloc(E.cap * sizeof *E.pool);
    enode **holes = rings > 1 ? malloc((rings - 1) * sizeof *holes) : NULL;
    if (!E.pool || (rings > 1 && !holes)) {
        free(E.pool);
        free(holes);
        return 0;
    }
    E.tris = tris;
    enode *outer = e_ring(&E, xy, ring_start[0], ring_start[1], true);
    if (outer && outer->next != outer->prev) {
        size_t nh = 0;
        for (size_t k = 1; k < rings; k++) {
            if (ring_start[k + 1] - ring_start[k] < 3) continue;
            enode *list = e_ring(&E, xy, ring_start[k], ring_start[k + 1], false);
            if (!list) continue;
            if (list == list->next) list->steiner = true;
            enode *left = list, *p = list;
            do {
                if (p->x < left->x || (p->x == left->x && p->y < left->y)) left = p;
                p = p->next;
            } while (p != list);
            holes[nh++] = left;
        }
        if (nh) qsort(holes, nh, sizeof *holes, cmp_leftmost);
        for (size_t k = 0; k < nh; k++) {
            enode *bridge = e_bridge(holes[k], outer);
            if (!bridge) continue;
            enode *rev = e_split(&E, bridge, holes[k]);
            if (!rev) break;
            e_filter(rev, rev->next);
            outer = e_filter(bridge, bridge->next);
        }
        e_linked(&E, outer, 0);
    }
    /* earcut's rings are clockwise in y-up terms: make every triangle counter-clockwise */
    size_t out = 0;
    for (size_t t = 0; t < E.ntris; t++) {
        uint32_t a = tris[3 * t], b = tris[3 * t + 1], c = tris[3 * t + 2];
        double cr = (xy[2 * b] - xy[2 * a]) * (xy[2 * c + 1] - xy[2 * a + 1]) -
                    (xy[2 * b + 1] - xy[2 * a + 1]) * (xy[2 * c] - xy[2 * a]);
        if (cr == 0) continue;
        tris[3 * out] = a;
        tris[3 * out + 1] = cr > 0 ? b : c;
        tris[3 * out + 2] = cr > 0 ? c : b;
        out++;
    }
    free(E.pool);
    free(holes);
    return out;
}

/* >>outlines: contours of one glyph as flat rings (font units). */
typedef struct rings {
    double *xy;
    size_t n, cap;
    size_t *start; /* ring k: [start[k], start[k+1]) */
    size_t count, scap;
    double cx, cy; /* current point */
    bool oom;
} rings;

/* buf (of *cap elements of elem bytes) with room for need elements: the same buffer when it has,
 * else reallocated to first elements or twice the capacity, doubled until need fits (*cap
 * updated). NULL when out of memory (buf and *cap unchanged). */
static void *grow(void *buf, size_t *cap, size_t need, size_t first, size_t elem)
{
    if (need <= *cap) return buf;
    size_t c = *cap ? *cap * 2 : first;
    while (c < need) c *= 2;
    void *p = realloc(buf, c * elem);
    if (p) *cap = c;
    return p;
}

static void r_point(rings *R, double x, double y)
{
    if (R->oom) return;
    double *xy = grow(R->xy, &R->cap, R->n + 1, 256, 2 * sizeof *xy);
    if (!xy) {
        R->oom = true;
        return;
    }
    R->xy = xy;
    R->xy[2 * R->n] = x;
    R->xy[2 * R->n + 1] = y;
    R->n++;
    R->cx = x;
    R->cy = y;
}

static void r_close(rings *R)
{
    if (R->oom) return;
    size_t *start = grow(R->start, &R->scap, R->count + 2, 16, sizeof *start);
    if (!start) {
        R->oom = true;
        return;
    }
    R->start = start;
    if (R->count == 0) R->start[0] = 0;
    size_t begin = R->start[R->count];
    /* the closing point repeats the first: drop it */
    if (R->n > begin + 1 && R->xy[2 * (R->n - 1)] == R->xy[2 * begin] && R->xy[2 * (R->n - 1) + 1] == R->xy[2 * begin + 1])
        R->n--;
    if (R->n - begin < 3) { /* not a polygon */
        R->n = begin;
        return;
    }
    R->count++;
    R->start[R->count] = R->n;
}

static int o_move(const FT_Vector *to, void *user)
{
    rings *R = user;
    if (R->count == 0 && !R->scap) {
        R->start = malloc(16 * sizeof *R->start);
        if (!R->start) return R->oom = true, 1;
        R->scap = 16;
        R->start[0] = 0;
    }
    if (R->n > R->start[R->count]) r_close(R);
    r_point(R, (double)to->x, (double)to->y);
    return R->oom;
}

static int o_line(const FT_Vector *to, void *user)
{
    rings *R = user;
    r_point(R, (double)to->x, (double)to->y);
    return R->oom;
}

static int o_conic(const FT_Vector *c, const FT_Vector *to, void *user)
{
    rings *R = user;
    double x0 = R->cx, y0 = R->cy;
    for (int k = 1; k <= SY_TEXT_CONIC_STEPS; k++) {
        double t = (double)k / SY_TEXT_CONIC_STEPS, u = 1 - t;
        r_point(R, u * u * x0 + 2 * u * t * (double)c->x + t * t * (double)to->x,
                u * u * y0 + 2 * u * t * (double)c->y + t * t * (double)to->y);
    }
    return R->oom;
}

static int o_cubic(const FT_Vector *c1, const FT_Vector *c2, const FT_Vector *to, void *user)
{
    rings *R = user;
    double x0 = R->cx, y0 = R->cy;
    for (int k = 1; k <= SY_TEXT_CUBIC_STEPS; k++) {
        double t = (double)k / SY_TEXT_CUBIC_STEPS, u = 1 - t;
        double a = u * u * u, b = 3 * u * u * t, cc = 3 * u * t * t, d = t * t * t;
        r_point(R, a * x0 + b * (double)c1->x + cc * (double)c2->x + d * (double)to->x,
                a * y0 + b * (double)c1->y + cc * (double)c2->y + d * (double)to->y);
    }
    return R->oom;
}

static bool point_in_ring(const double *xy, size_t a, size_t b, double px, double py)
{
    bool in = false;
    for (size_t i = a, j = b - 1; i < b; j = i++) {
        double xi = xy[2 * i], yi = xy[2 * i + 1], xj = xy[2 * j], yj = xy[2 * j + 1];
        if ((yi > py) != (yj > py) && px < (xj - xi) * (py - yi) / (yj - yi) + xi) in = !in;
    }
    return in;
}

/* >>layout */
typedef struct builder {
    float *pos;
    uint32_t *idx;
    size_t nv, nt, cap_v, cap_t, max_t;
    sy_result r;
} builder;

static bool b_reserve(builder *B, size_t nv, size_t nt, sy_error *err)
{
    if (B->nt + nt > B->max_t) {
        B->r = sy_error_set(err, SY_ERR_LIMIT, "text: more than %zu triangles", B->max_t);
        return false;
    }
    float *pos = grow(B->pos, &B->cap_v, B->nv + nv, 1024, 3 * sizeof *pos);
    if (!pos) goto oom;
    B->pos = pos;
    uint32_t *idx = grow(B->idx, &B->cap_t, B->nt + nt, 1024, 3 * sizeof *idx);
    if (!idx) goto oom;
    B->idx = idx;
    return true;
oom:
    B->r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "text: out of memory");
    return false;
}

/* Triangulates the rings of one glyph placed at (ox, oy) scaled by s into the builder. */
static bool glyph_geometry(builder *B, const rings *R, double s, double ox, double oy, sy_error *err)
{
    size_t nr = R->count;
    if (nr == 0) return true;
    int *depth = calloc(nr, sizeof *depth);
    double *area = malloc(nr * sizeof *area);
    size_t *members = malloc((nr + 1) * sizeof *members), *start = malloc((nr + 1) * sizeof *start);
    double *xy = malloc(R->n * 2 * sizeof *xy);
    uint32_t *tris = malloc(SY_TEXT_TRIANGULATE_CAPACITY(R->n, nr) * 3 * sizeof *tris);
    bool ok = depth && area && members && start && xy && tris;
    if (!ok) B->r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "text: out of memory");
    for (size_t k = 0; ok && k < nr; k++) {
        size_t a = R->start[k], b = R->start[k + 1];
        area[k] = fabs(ring_area(R->xy, a, b));
        for (size_t j = 0; j < nr; j++)
            if (j != k && point_in_ring(R->xy, R->start[j], R->start[j + 1], R->xy[2 * a], R->xy[2 * a + 1])) depth[k]++;
    }
    for (size_t k = 0; ok && k < nr; k++) {
        if (depth[k] % 2) continue; /* a hole: placed with its outer contour */
        /* the outer ring, then every hole whose innermost enclosing even contour is k */
        size_t m = 0, n = 0;
        members[m++] = k;
        for (size_t h = 0; h < nr; h++) {
            if (depth[h] != depth[k] + 1) continue;
            size_t a = R->start[h];
            if (!point_in_ring(R->xy, R->start[k], R->start[k + 1], R->xy[2 * a], R->xy[2 * a + 1])) continue;
            members[m++] = h;
        }
        for (size_t q = 0; q < m; q++) {
            start[q] = n;
            size_t a = R->start[members[q]], b = R->start[members[q] + 1];
            memcpy(xy + 2 * n, R->xy + 2 * a, (b - a) * 2 * sizeof *xy);
            n += b - a;
        }
        start[m] = n;
        size_t nt = sy_text_triangulate(xy, n, start, m, tris);
        if (!b_reserve(B, n, nt, err)) {
            ok = false;
            break;
        }
        for (size_t v = 0; v < n; v++) {
            float *p = B->pos + 3 * (B->nv + v);
            p[0] = (float)(ox + s * xy[2 * v]);
            p[1] = (float)(oy + s * xy[2 * v + 1]);
            p[2] = 0.0f;
        }
        for (size_t t = 0; t < nt * 3; t++) B->idx[3 * B->nt + t] = (uint32_t)(B->nv + tris[t]);
        B->nv += n;
        B->nt += nt;
    }
    free(depth); free(area); free(members); free(start); free(xy); free(tris);
    return ok;
}

/* Next code point of a UTF-8 string (strict: overlong, surrogate or truncated -> U+FFFD). */
static uint32_t utf8_next(const unsigned char **sp)
{
    const unsigned char *s = *sp;
    uint32_t c = *s++;
    int extra = c < 0x80 ? 0 : (c & 0xE0) == 0xC0 ? 1 : (c & 0xF0) == 0xE0 ? 2 : (c & 0xF8) == 0xF0 ? 3 : -1;
    if (extra < 0) {
        *sp = s;
        return 0xFFFD;
    }
    static const uint32_t min_of[4] = {0, 0x80, 0x800, 0x10000};
    c &= extra == 0 ? 0x7F : (0x3F >> extra);
    for (int k = 0; k < extra; k++) {
        if ((*s & 0xC0) != 0x80) {
            *sp = s;
            return 0xFFFD;
        }
        c = c << 6 | (*s++ & 0x3F);
    }
    *sp = s;
    if (c < min_of[extra] || c > 0x10FFFF || (c >= 0xD800 && c <= 0xDFFF)) return 0xFFFD;
    return c;
}

/* Advance width of one line in font units (kerning included). */
static double line_width(FT_Face face, const char *line)
{
    double w = 0;
    FT_UInt prev = 0;
    for (const unsigned char *s = (const unsigned char *)line; *s;) {
        FT_UInt g = FT_Get_Char_Index(face, utf8_next(&s));
        if (prev && FT_HAS_KERNING(face)) {
            FT_Vector k;
            if (!FT_Get_Kerning(face, prev, g, FT_KERNING_UNSCALED, &k)) w += (double)k.x;
        }
        if (!FT_Load_Glyph(face, g, FT_LOAD_NO_SCALE | FT_LOAD_NO_HINTING)) w += (double)face->glyph->advance.x;
        prev = g;
    }
    return w;
}

sy_result sy_text_build(const sy_text_desc *d, sy_primitive *out, sy_text_stats *stats, sy_error *err)
{
    memset(out, 0, sizeof *out);
    if (stats) memset(stats, 0, sizeof *stats);
    if (!d || !d->font_path || (d->line_count && !d->lines) || !(d->size > 0) || !isfinite(d->size) ||
        !(d->spacing >= 0) || !isfinite(d->spacing) || d->major < SY_TEXT_BEGIN || d->major > SY_TEXT_END ||
        d->minor > SY_TEXT_END)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "text: invalid description");
    FT_Library lib;
    if (FT_Init_FreeType(&lib)) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "text: FreeType initialisation failed");
    FT_Face face;
    if (FT_New_Face(lib, d->font_path, 0, &face)) {
        FT_Done_FreeType(lib);
        return sy_error_set(err, SY_ERR_NOT_FOUND, "text: font '%s' missing or unreadable", d->font_path);
    }
    builder B = {.max_t = d->max_triangles ? d->max_triangles : (size_t)1 << 24};
    rings R = {0};
    double s = (double)d->size / (double)(face->units_per_EM ? face->units_per_EM : 1000);
    double h = (double)d->size * (double)d->spacing;
    double asc = (double)face->ascender * s, desc = (double)face->descender * s;
    double top = asc, bottom = -(double)(d->line_count ? d->line_count - 1 : 0) * h + desc;
    double yoff = d->minor == SY_TEXT_BEGIN ? -top : d->minor == SY_TEXT_END ? -bottom
                  : d->minor == SY_TEXT_MIDDLE ? -(top + bottom) / 2 : 0.0;
    FT_Outline_Funcs funcs = {o_move, o_line, o_conic, o_cubic, 0, 0};
    uint32_t glyphs = 0;
    for (size_t l = 0; l < d->line_count && B.r == SY_OK; l++) {
        const char *line = d->lines[l] ? d->lines[l] : "";
        double w = line_width(face, line) * s;
        double x = d->major == SY_TEXT_MIDDLE ? -w / 2 : d->major == SY_TEXT_END ? -w : 0.0;
        double y = yoff - (double)l * h;
        FT_UInt prev = 0;
        for (const unsigned char *p = (const unsigned char *)line; *p && B.r == SY_OK;) {
            FT_UInt g = FT_Get_Char_Index(face, utf8_next(&p));
            if (prev && FT_HAS_KERNING(face)) {
                FT_Vector k;
                if (!FT_Get_Kerning(face, prev, g, FT_KERNING_UNSCALED, &k)) x += (double)k.x * s;
            }
            prev = g;
            glyphs++;
            if (FT_Load_Glyph(face, g, FT_LOAD_NO_SCALE | FT_LOAD_NO_HINTING)) continue;
            FT_GlyphSlot gs = face->glyph;
            if (gs->format == FT_GLYPH_FORMAT_OUTLINE && gs->outline.n_contours > 0) {
                R.n = 0;
                R.count = 0;
                if (R.start) R.start[0] = 0;
                int e = FT_Outline_Decompose(&gs->outline, &funcs, &R);
                if (!e && !R.oom && R.start && R.n > R.start[R.count]) r_close(&R);
                if (R.oom) B.r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "text: out of memory");
                else if (!e) glyph_geometry(&B, &R, s, x, y, err);
            }
            x += (double)gs->advance.x * s;
        }
    }
    free(R.xy);
    free(R.start);
    FT_Done_Face(face);
    FT_Done_FreeType(lib);
    sy_result r = B.r;
    if (r == SY_OK && B.nt) {
        float *nrm = malloc(B.nv * 12);
        if (!nrm) r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "text: out of memory");
        for (size_t v = 0; nrm && v < B.nv; v++) nrm[3 * v] = 0, nrm[3 * v + 1] = 0, nrm[3 * v + 2] = 1;
        if (!r && (r = sy_blob_create_take(B.pos, B.nv * 12, &out->positions, err)) == SY_OK) B.pos = NULL;
        if (!r && (r = sy_blob_create_take(nrm, B.nv * 12, &out->normals, err)) == SY_OK) nrm = NULL;
        if (!r && (r = sy_blob_create_take(B.idx, B.nt * 12, &out->indices, err)) == SY_OK) B.idx = NULL;
        free(nrm);
        if (r) sy_primitive_release(out);
    }
    free(B.pos);
    free(B.idx);
    if (stats && r == SY_OK) {
        stats->glyphs = glyphs;
        stats->triangles = (uint32_t)B.nt;
    }
    return r;
}
