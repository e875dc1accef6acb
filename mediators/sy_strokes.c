/* sy_strokes.c — line and point primitives tessellated into tubes and balls (see sy_strokes.h).
 *
 * Sections: >>shapes (icosahedron, tube basis)  >>counting  >>tessellation */
#include "sy_strokes.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* >>shapes: the unit icosahedron (circumradius 1) and its faces (wound outwards at run time). */
static const float ICO_V[SY_STROKES_BALL_VERTICES][3] = {
    {-0.525731f, 0.850651f, 0.0f},  {0.525731f, 0.850651f, 0.0f},  {-0.525731f, -0.850651f, 0.0f},
    {0.525731f, -0.850651f, 0.0f},  {0.0f, -0.525731f, 0.850651f}, {0.0f, 0.525731f, 0.850651f},
    {0.0f, -0.525731f, -0.850651f}, {0.0f, 0.525731f, -0.850651f}, {0.850651f, 0.0f, -0.525731f},
    {0.850651f, 0.0f, 0.525731f},   {-0.850651f, 0.0f, -0.525731f}, {-0.850651f, 0.0f, 0.525731f},
};
static const uint8_t ICO_F[SY_STROKES_BALL_TRIANGLES][3] = {
    {0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
    {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
    {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1},
};


/* Face f of the icosahedron wound counter-clockwise seen from outside. */
static void ico_face(uint32_t f, uint32_t out[3])
{
    const uint8_t *t = ICO_F[f];
    float e1[3], e2[3], n[3], c[3];
    sy_vec3_sub(ICO_V[t[1]], ICO_V[t[0]], e1);
    sy_vec3_sub(ICO_V[t[2]], ICO_V[t[0]], e2);
    sy_vec3_cross(e1, e2, n);
    for (int k = 0; k < 3; ++k) c[k] = ICO_V[t[0]][k] + ICO_V[t[1]][k] + ICO_V[t[2]][k];
    bool flip = sy_vec3_dot(n, c) < 0.0f;
    out[0] = t[0];
    out[1] = flip ? t[2] : t[1];
    out[2] = flip ? t[1] : t[2];
}

/* >>counting */
typedef struct stroke_src {
    uint32_t per;         /* 2 (lines) or 1 (points) */
    uint32_t elements;    /* segments or points */
    uint32_t nv;          /* source vertices */
    const uint32_t *idx;  /* NULL: vertex k*per + j */
    const float *pos;
} stroke_src;

static bool src_of(const sy_primitive *p, stroke_src *s)
{
    memset(s, 0, sizeof *s);
    if (p->topology != SY_TOPOLOGY_LINES && p->topology != SY_TOPOLOGY_POINTS) return false;
    s->per = p->topology == SY_TOPOLOGY_LINES ? 2u : 1u;
    s->nv = sy_primitive_vertex_count(p);
    s->pos = sy_blob_data(p->positions);
    s->idx = sy_blob_data(p->indices);
    s->elements = sy_primitive_element_count(p);
    if (!s->pos) return false;
    if (s->idx)
        for (uint64_t k = 0; k < (uint64_t)s->elements * s->per; ++k)
            if (s->idx[k] >= s->nv) return false;
    return true;
}

static uint32_t vertex_of(const stroke_src *s, uint32_t e, uint32_t j)
{
    return s->idx ? s->idx[(size_t)e * s->per + j] : e * s->per + j;
}

static bool zero_length(const stroke_src *s, uint32_t e)
{
    const float *a = s->pos + 3 * (size_t)vertex_of(s, e, 0), *b = s->pos + 3 * (size_t)vertex_of(s, e, 1);
    return a[0] == b[0] && a[1] == b[1] && a[2] == b[2];
}

/* Tubes, balls (and marks the joint vertices in `joint` when given, nv bytes). */
static void count(const stroke_src *s, uint8_t *joint, uint64_t *tubes, uint64_t *balls)
{
    *tubes = 0;
    *balls = 0;
    if (s->per == 1) {
        *balls = s->elements;
        return;
    }
    for (uint32_t e = 0; e < s->elements; ++e) {
        if (!zero_length(s, e)) ++*tubes;
        for (uint32_t j = 0; j < 2; ++j) {
            uint32_t v = vertex_of(s, e, j);
            if (joint && !joint[v]) {
                joint[v] = 1;
                ++*balls;
            }
        }
    }
}

uint64_t sy_strokes_triangle_count(const sy_primitive *p)
{
    if (p->topology == SY_TOPOLOGY_TRIANGLES) return 0;
    stroke_src s;
    if (!src_of(p, &s)) return UINT64_MAX;
    uint8_t *joint = s.per == 2 ? calloc(s.nv ? s.nv : 1, 1) : NULL;
    if (s.per == 2 && !joint) return UINT64_MAX;
    uint64_t tubes, balls;
    count(&s, joint, &tubes, &balls);
    free(joint);
    return tubes * SY_STROKES_TUBE_TRIANGLES + balls * SY_STROKES_BALL_TRIANGLES;
}

/* >>tessellation */
typedef struct out_arrays {
    float *pos, *nrm, *uv0, *uv1, *col;
    uint32_t *idx;
    uint32_t nv, nt;
    const float *suv0, *suv1, *scol; /* source attributes */
} out_arrays;

static void put_vertex(out_arrays *o, const float *p, const float *n, uint32_t src)
{
    uint32_t v = o->nv++;
    memcpy(o->pos + 3 * (size_t)v, p, 12);
    memcpy(o->nrm + 3 * (size_t)v, n, 12);
    if (o->uv0) memcpy(o->uv0 + 2 * (size_t)v, o->suv0 + 2 * (size_t)src, 8);
    if (o->uv1) memcpy(o->uv1 + 2 * (size_t)v, o->suv1 + 2 * (size_t)src, 8);
    if (o->col) memcpy(o->col + 4 * (size_t)v, o->scol + 4 * (size_t)src, 16);
}

static void put_tri(out_arrays *o, uint32_t a, uint32_t b, uint32_t c)
{
    uint32_t *t = o->idx + 3 * (size_t)o->nt++;
    t[0] = a, t[1] = b, t[2] = c;
}

static void ball(out_arrays *o, const float *c, float r, uint32_t src)
{
    uint32_t base = o->nv;
    for (uint32_t k = 0; k < SY_STROKES_BALL_VERTICES; ++k) {
        float p[3] = {c[0] + r * ICO_V[k][0], c[1] + r * ICO_V[k][1], c[2] + r * ICO_V[k][2]};
        put_vertex(o, p, ICO_V[k], src);
    }
    for (uint32_t f = 0; f < SY_STROKES_BALL_TRIANGLES; ++f) {
        uint32_t t[3];
        ico_face(f, t);
        put_tri(o, base + t[0], base + t[1], base + t[2]);
    }
}

static void tube(out_arrays *o, const float *a, const float *b, float r, uint32_t va, uint32_t vb)
{
    float d[3];
    sy_vec3_sub(b, a, d);
    float len = sqrtf(sy_vec3_dot(d, d));
    for (int k = 0; k < 3; ++k) d[k] /= len;
    /* u: perpendicular to d, from the world axis least aligned with it; v = d x u */
    float ax[3] = {0, 0, 0};
    int m = fabsf(d[0]) <= fabsf(d[1]) ? (fabsf(d[0]) <= fabsf(d[2]) ? 0 : 2) : (fabsf(d[1]) <= fabsf(d[2]) ? 1 : 2);
    ax[m] = 1.0f;
    float u[3], v[3];
    sy_vec3_cross(d, ax, u);
    float ul = sqrtf(sy_vec3_dot(u, u));
    for (int k = 0; k < 3; ++k) u[k] /= ul;
    sy_vec3_cross(d, u, v);
    uint32_t base = o->nv;
    for (uint32_t s = 0; s < SY_STROKES_TUBE_SIDES; ++s) {
        float ang = 6.28318531f * (float)s / (float)SY_STROKES_TUBE_SIDES, cs = cosf(ang), sn = sinf(ang);
        float n[3] = {cs * u[0] + sn * v[0], cs * u[1] + sn * v[1], cs * u[2] + sn * v[2]};
        float pa[3] = {a[0] + r * n[0], a[1] + r * n[1], a[2] + r * n[2]};
        float pb[3] = {b[0] + r * n[0], b[1] + r * n[1], b[2] + r * n[2]};
        put_vertex(o, pa, n, va); /* base + 2s */
        put_vertex(o, pb, n, vb); /* base + 2s + 1 */
    }
    for (uint32_t s = 0; s < SY_STROKES_TUBE_SIDES; ++s) {
        uint32_t s1 = (s + 1) % SY_STROKES_TUBE_SIDES;
        uint32_t a0 = base + 2 * s, b0 = a0 + 1, a1 = base + 2 * s1, b1 = a1 + 1;
        /* angle grows counter-clockwise around d (v = d x u): these face outwards */
        put_tri(o, a0, a1, b1);
        put_tri(o, a0, b1, b0);
    }
}

sy_result sy_strokes_tessellate(const sy_primitive *p, float width, const char *what, sy_primitive *out,
                                sy_error *err)
{
    memset(out, 0, sizeof *out);
    if (!what) what = "stroke";
    stroke_src s;
    if (!src_of(p, &s))
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: not a valid line or point primitive", what);
    if (!(width > 0.0f) || !isfinite(width))
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: stroke width %g is not finite and > 0", what,
                            (double)width);
    uint8_t *joint = s.per == 2 ? calloc(s.nv ? s.nv : 1, 1) : NULL;
    if (s.per == 2 && !joint) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", what);
    uint64_t tubes, balls;
    count(&s, joint, &tubes, &balls);
    uint64_t tris = tubes * SY_STROKES_TUBE_TRIANGLES + balls * SY_STROKES_BALL_TRIANGLES;
    uint64_t verts = tubes * 2 * SY_STROKES_TUBE_SIDES + balls * SY_STROKES_BALL_VERTICES;
    if (tris == 0) {
        free(joint);
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: no stroke to draw", what);
    }
    if (tris > SY_STROKES_MAX_TRIANGLES || verts > SY_STROKES_MAX_TRIANGLES) {
        free(joint);
        return sy_error_set(err, SY_ERR_LIMIT, "%s: %llu stroke triangles exceed the limit of %u", what,
                            (unsigned long long)tris, SY_STROKES_MAX_TRIANGLES);
    }
    out_arrays o = {0};
    o.suv0 = sy_blob_data(p->texcoords0);
    o.suv1 = sy_blob_data(p->texcoords1);
    o.scol = sy_blob_data(p->colors);
    size_t nv = (size_t)verts, nt = (size_t)tris; /* < 2^28: the products below fit */
    o.pos = malloc(nv * 12);
    o.nrm = malloc(nv * 12);
    o.idx = malloc(nt * 12);
    o.uv0 = o.suv0 ? malloc(nv * 8) : NULL;
    o.uv1 = o.suv1 ? malloc(nv * 8) : NULL;
    o.col = o.scol ? malloc(nv * 16) : NULL;
    sy_result r = SY_OK;
    if (!o.pos || !o.nrm || !o.idx || (o.suv0 && !o.uv0) || (o.suv1 && !o.uv1) || (o.scol && !o.col)) {
        r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", what);
        goto done;
    }
    float rad = 0.5f * width;
    if (s.per == 1) {
        for (uint32_t e = 0; e < s.elements; ++e) {
            uint32_t v = vertex_of(&s, e, 0);
            ball(&o, s.pos + 3 * (size_t)v, rad, v);
        }
    } else {
        for (uint32_t e = 0; e < s.elements; ++e) {
            if (zero_length(&s, e)) continue;
            uint32_t va = vertex_of(&s, e, 0), vb = vertex_of(&s, e, 1);
            tube(&o, s.pos + 3 * (size_t)va, s.pos + 3 * (size_t)vb, rad, va, vb);
        }
        for (uint32_t v = 0; v < s.nv; ++v)
            if (joint[v]) ball(&o, s.pos + 3 * (size_t)v, rad, v);
    }
    /* the result: every blob takes its array (freed by the blob) */
    float **arrs[5] = {&o.pos, &o.nrm, &o.uv0, &o.uv1, &o.col};
    size_t sizes[5] = {nv * 12, nv * 12, nv * 8, nv * 8, nv * 16};
    sy_blob **dst[5] = {&out->positions, &out->normals, &out->texcoords0, &out->texcoords1, &out->colors};
    for (int k = 0; k < 5 && r == SY_OK; ++k) {
        if (!*arrs[k]) continue;
        r = sy_blob_create_take(*arrs[k], sizes[k], dst[k], err);
        if (r != SY_OK) free(*arrs[k]);
        *arrs[k] = NULL;
    }
    if (r == SY_OK) {
        r = sy_blob_create_take(o.idx, nt * 12, &out->indices, err);
        if (r != SY_OK) free(o.idx);
        o.idx = NULL;
    }
    if (r == SY_OK) {
        out->material = p->material;
        out->topology = SY_TOPOLOGY_TRIANGLES;
    } else {
        sy_primitive_release(out);
    }
done:
    free(joint);
    free(o.pos);
    free(o.nrm);
    free(o.uv0);
    free(o.uv1);
    free(o.col);
    free(o.idx);
    return r;
}
