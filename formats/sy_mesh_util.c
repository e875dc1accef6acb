/* sy_mesh_util.c — normal / tangent generation, polygon triangulation and primitive tessellation
 * for the file loaders (see sy_mesh_util.h). */
#include "sy_mesh_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define PI_F 3.14159265358979323846f

static float v3_len(const float *a) { return sqrtf(sy_vec3_dot(a, a)); }
static bool v3_normalize(float *a)
{
    float l = v3_len(a);
    if (!(l > 1e-30f) || !isfinite(l)) return false;
    a[0] /= l; a[1] /= l; a[2] /= l;
    return true;
}

static sy_result oom(sy_error *err, const char *what) { return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", what); }

static sy_result take_blob(void *data, size_t bytes, sy_blob **slot, sy_error *err)
{
    sy_blob *b;
    sy_result r = sy_blob_create_take(data, bytes, &b, err);
    if (r) {
        free(data);
        return r;
    }
    sy_blob_release(*slot);
    *slot = b;
    return SY_OK;
}

/* Corner list of a primitive: vertex index of each triangle corner. */
static uint32_t *corner_indices(const sy_primitive *p, size_t *ncorners, sy_error *err)
{
    size_t n = p->indices ? sy_blob_size(p->indices) / 4 : sy_blob_size(p->positions) / 12;
    n -= n % 3;
    uint32_t *c = malloc((n ? n : 1) * sizeof *c);
    if (!c) {
        oom(err, "tangents");
        return NULL;
    }
    if (p->indices) memcpy(c, sy_blob_data(p->indices), n * 4);
    else for (size_t k = 0; k < n; k++) c[k] = (uint32_t)k;
    *ncorners = n;
    return c;
}

static void any_orthogonal(const float *n, float *t)
{
    float a[3] = {1, 0, 0};
    if (fabsf(n[0]) > 0.9f) { a[0] = 0; a[1] = 1; }
    float d = sy_vec3_dot(a, n);
    for (int k = 0; k < 3; k++) t[k] = a[k] - n[k] * d;
    if (!v3_normalize(t)) { t[0] = 1; t[1] = 0; t[2] = 0; }
}

sy_result sy_prim_generate_tangents(sy_primitive *p, uint32_t texcoord, sy_error *err)
{
    sy_blob *uvb = texcoord ? p->texcoords1 : p->texcoords0;
    if (!p || !p->positions || !p->normals || !uvb)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "tangents: positions, normals and TEXCOORD_%u are required",
                            (unsigned)texcoord);
    size_t nv = sy_blob_size(p->positions) / 12, n;
    uint32_t *c = corner_indices(p, &n, err);
    if (!c) return SY_ERR_OUT_OF_MEMORY;
    const float *pos = sy_blob_data(p->positions), *nrm = sy_blob_data(p->normals), *uv = sy_blob_data(uvb);
    float *acc = calloc(nv ? nv * 6 : 1, sizeof(float)); /* tangent xyz, bitangent xyz */
    float *out = malloc((nv ? nv : 1) * 16);
    if (!acc || !out) {
        free(c); free(acc); free(out);
        return oom(err, "tangents");
    }
    for (size_t t = 0; t + 2 < n; t += 3) {
        const uint32_t i[3] = {c[t], c[t + 1], c[t + 2]};
        float e1[3], e2[3];
        sy_vec3_sub(pos + 3 * i[1], pos + 3 * i[0], e1);
        sy_vec3_sub(pos + 3 * i[2], pos + 3 * i[0], e2);
        float du1 = uv[2 * i[1]] - uv[2 * i[0]], dv1 = uv[2 * i[1] + 1] - uv[2 * i[0] + 1];
        float du2 = uv[2 * i[2]] - uv[2 * i[0]], dv2 = uv[2 * i[2] + 1] - uv[2 * i[0] + 1];
        float det = du1 * dv2 - du2 * dv1;
        if (!(fabsf(det) > 1e-20f) || !isfinite(det)) continue;
        float s = 1.0f / det, T[3], B[3];
        /* glTF texcoords have v pointing down the image while normal maps have +Y up: the tangent
         * follows +u, the bitangent -v (image up), as Blender / MikkTSpace on glTF data give */
        for (int k = 0; k < 3; k++) {
            T[k] = (e1[k] * dv2 - e2[k] * dv1) * s;
            B[k] = -(e2[k] * du1 - e1[k] * du2) * s;
        }
        if (!v3_normalize(T) || !v3_normalize(B)) continue;
        for (int k = 0; k < 3; k++) { /* corner angle weight */
            float a[3], b[3];
            sy_vec3_sub(pos + 3 * i[(k + 1) % 3], pos + 3 * i[k], a);
            sy_vec3_sub(pos + 3 * i[(k + 2) % 3], pos + 3 * i[k], b);
            float la = v3_len(a), lb = v3_len(b);
            float w = (la > 0 && lb > 0) ? acosf(fmaxf(-1.0f, fminf(1.0f, sy_vec3_dot(a, b) / (la * lb)))) : 0.0f;
            float *dst = acc + 6 * i[k];
            for (int q = 0; q < 3; q++) { dst[q] += T[q] * w; dst[3 + q] += B[q] * w; }
        }
    }
    for (size_t v = 0; v < nv; v++) {
        float N[3] = {nrm[3 * v], nrm[3 * v + 1], nrm[3 * v + 2]}, T[3], *B = acc + 6 * v + 3;
        if (!v3_normalize(N)) { N[0] = 0; N[1] = 0; N[2] = 1; }
        float d = sy_vec3_dot(acc + 6 * v, N);
        for (int k = 0; k < 3; k++) T[k] = acc[6 * v + k] - N[k] * d;
        float w = 1.0f;
        if (!v3_normalize(T)) any_orthogonal(N, T);
        else {
            float nb[3];
            sy_vec3_cross(N, T, nb);
            w = sy_vec3_dot(nb, B) < 0.0f ? -1.0f : 1.0f;
        }
        memcpy(out + 4 * v, T, 12);
        out[4 * v + 3] = w;
    }
    free(c);
    free(acc);
    return take_blob(out, nv * 16, &p->tangents, err);
}

static float corner_angle(const float *positions, const uint32_t *tri, int k)
{
    float a[3], b[3];
    sy_vec3_sub(positions + 3 * (size_t)tri[(k + 1) % 3], positions + 3 * (size_t)tri[k], a);
    sy_vec3_sub(positions + 3 * (size_t)tri[(k + 2) % 3], positions + 3 * (size_t)tri[k], b);
    float la = v3_len(a), lb = v3_len(b);
    if (!(la > 0) || !(lb > 0)) return 0.0f;
    return acosf(fmaxf(-1.0f, fminf(1.0f, sy_vec3_dot(a, b) / (la * lb))));
}

#define SY_CREASE_MAX_VALENCE 512u

sy_result sy_corner_normals(const float *positions, size_t position_count, const uint32_t *pos_index,
                            size_t tri_count, float crease_angle, float **out, sy_error *err)
{
    *out = NULL;
    float *fn = malloc((tri_count ? tri_count : 1) * 24);          /* unit face normals (0 if degenerate) */
    float *ang = fn + 3 * (tri_count ? tri_count : 1);               /* corner angles, computed once */
    float *res = malloc((tri_count ? tri_count : 1) * 36);
    uint32_t *start = calloc(position_count + 1, sizeof(uint32_t)); /* CSR: corners per position */
    uint32_t *list = malloc((tri_count ? tri_count : 1) * 3 * sizeof(uint32_t));
    uint32_t *fill = malloc((position_count ? position_count : 1) * sizeof(uint32_t));
    if (!fn || !res || !start || !list || !fill) {
        free(fn); free(res); free(start); free(list); free(fill);
        return oom(err, "crease normals");
    }
    for (size_t t = 0; t < tri_count; t++) {
        const uint32_t *i = pos_index + 3 * t;
        float e1[3], e2[3];
        sy_vec3_sub(positions + 3 * (size_t)i[1], positions + 3 * (size_t)i[0], e1);
        sy_vec3_sub(positions + 3 * (size_t)i[2], positions + 3 * (size_t)i[0], e2);
        sy_vec3_cross(e1, e2, fn + 3 * t);
        if (!v3_normalize(fn + 3 * t)) fn[3 * t] = fn[3 * t + 1] = fn[3 * t + 2] = 0;
        for (int k = 0; k < 3; k++) start[i[k] + 1]++;
        if (crease_angle > 0.0f)
            for (int k = 0; k < 3; k++) ang[3 * t + (size_t)k] = corner_angle(positions, i, k);
    }
    for (size_t v = 0; v < position_count; v++) start[v + 1] += start[v];
    memcpy(fill, start, position_count * sizeof(uint32_t));
    for (size_t t = 0; t < tri_count; t++) /* corner ids 3t+k grouped by position */
        for (int k = 0; k < 3; k++) list[fill[pos_index[3 * t + k]]++] = (uint32_t)(3 * t + (size_t)k);
    free(fill);
    float cos_crease = crease_angle >= PI_F ? -2.0f : cosf(crease_angle);
    /* Per position: angle-weighted average of the faces within the crease angle; vertices shared by
     * more than SY_CREASE_MAX_VALENCE triangles keep the face normal (bounds the cost, which is
     * quadratic in the valence; such vertices are fan centres of big planar polygons). Corners at
     * one position whose faces have the same normal get the same result: it is computed once
     * (a small cache per position; coplanar fans of hostile input no longer cost valence^2). */
    enum { CACHE = 8 };
    for (size_t v = 0; v < position_count; v++) {
        uint32_t m = start[v + 1] - start[v];
        const float *cn[CACHE];
        float cr[CACHE][3];
        int nc = 0;
        for (uint32_t c0 = start[v]; c0 < start[v + 1]; c0++) {
            size_t t = list[c0] / 3;
            const float *ft = fn + 3 * t;
            float *o = res + 3 * (size_t)list[c0];
            bool ok = ft[0] != 0 || ft[1] != 0 || ft[2] != 0;
            o[0] = o[1] = o[2] = 0;
            if (ok && crease_angle > 0.0f && m <= SY_CREASE_MAX_VALENCE) {
                int hit = -1;
                for (int j = 0; j < nc && hit < 0; j++)
                    if (!memcmp(cn[j], ft, 12)) hit = j;
                if (hit >= 0) {
                    memcpy(o, cr[hit], 12);
                    continue;
                }
                for (uint32_t q = start[v]; q < start[v + 1]; q++) {
                    size_t g = list[q] / 3;
                    const float *gn = fn + 3 * g;
                    if (g != t && sy_vec3_dot(gn, ft) < cos_crease - 1e-6f) continue;
                    float w = ang[list[q]];
                    o[0] += gn[0] * w; o[1] += gn[1] * w; o[2] += gn[2] * w;
                }
            }
            if (!v3_normalize(o)) memcpy(o, ok ? ft : (const float[3]){0, 0, 1}, 12);
            if (ok && crease_angle > 0.0f && m <= SY_CREASE_MAX_VALENCE && nc < CACHE) {
                cn[nc] = ft;
                memcpy(cr[nc++], o, 12);
            }
        }
    }
    free(fn); free(start); free(list);
    *out = res;
    return SY_OK;
}

/* ---- ear clipping ---- */
static float cross2(const float *a, const float *b, const float *c)
{
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

static bool in_triangle(const float *p, const float *a, const float *b, const float *c)
{
    float d1 = cross2(a, b, p), d2 = cross2(b, c, p), d3 = cross2(c, a, p);
    return d1 >= 0 && d2 >= 0 && d3 >= 0; /* ccw triangle; boundary counts as inside */
}

size_t sy_triangulate_polygon(const float *positions, const uint32_t *poly, size_t n, uint32_t *tris, void *scratch)
{
    if (n < 3) return 0;
    size_t out = 0;
    if (n == 3) {
        tris[0] = poly[0]; tris[1] = poly[1]; tris[2] = poly[2];
        return 1;
    }
    /* Newell normal -> projection axes */
    float nn[3] = {0, 0, 0};
    for (size_t i = 0; i < n; i++) {
        const float *a = positions + 3 * (size_t)poly[i], *b = positions + 3 * (size_t)poly[(i + 1) % n];
        nn[0] += (a[1] - b[1]) * (a[2] + b[2]);
        nn[1] += (a[2] - b[2]) * (a[0] + b[0]);
        nn[2] += (a[0] - b[0]) * (a[1] + b[1]);
    }
    uint32_t *idx = scratch; /* 4 * n: ring links, reflex list, states (below) */
    float *uv = (float *)(idx + 4 * n);
    int ax = 0;
    if (fabsf(nn[1]) > fabsf(nn[ax])) ax = 1;
    if (fabsf(nn[2]) > fabsf(nn[ax])) ax = 2;
    if (!(fabsf(nn[ax]) > 0)) goto fan;
    int u = (ax + 1) % 3, w = (ax + 2) % 3;
    bool flip = nn[ax] < 0; /* make the projected polygon counter-clockwise */
    for (size_t i = 0; i < n; i++) {
        const float *p = positions + 3 * (size_t)poly[i];
        uv[2 * i] = p[u];
        uv[2 * i + 1] = flip ? -p[w] : p[w];
    }
    /* convex (every turn the same way): a fan, in linear time */
    bool convex = true;
    for (size_t k = 0; k < n && convex; k++)
        convex = cross2(uv + 2 * k, uv + 2 * ((k + 1) % n), uv + 2 * ((k + 2) % n)) >= 0;
    if (convex) goto fan;
    /* Ear clipping on a doubly linked ring. Only reflex (or straight) vertices can lie inside an
     * ear of a simple polygon, and clipping never turns a convex vertex reflex, so an ear test scans
     * the list of reflex vertices only (compacted as they turn convex or go). */
    uint32_t *prv = idx, *nxt = idx + n, *rl = idx + 2 * n, *st = idx + 3 * n; /* st: 1 reflex, 2 clipped */
    size_t nr = 0, live_r = 0;
    for (size_t k = 0; k < n; k++) {
        prv[k] = (uint32_t)((k + n - 1) % n);
        nxt[k] = (uint32_t)((k + 1) % n);
        st[k] = cross2(uv + 2 * prv[k], uv + 2 * k, uv + 2 * nxt[k]) <= 0;
        if (st[k]) rl[nr++] = (uint32_t)k;
    }
    live_r = nr;
    size_t m = n, fails = 0;
    uint32_t cur = 0;
    /* ear tests cost O(reflex) each; past this budget the rest is fanned (bounded time on hostile input) */
    uint64_t budget = (uint64_t)1 << 26;
    while (m > 3 && fails < m && budget > nr) {
        budget -= nr + 1;
        uint32_t ip = prv[cur], in = nxt[cur];
        const float *a = uv + 2 * ip, *b = uv + 2 * cur, *c = uv + 2 * in;
        bool ear = !(st[cur] & 1) && cross2(a, b, c) > 0;
        if (ear) {
            float x0 = fminf(a[0], fminf(b[0], c[0])), x1 = fmaxf(a[0], fmaxf(b[0], c[0]));
            float y0 = fminf(a[1], fminf(b[1], c[1])), y1 = fmaxf(a[1], fmaxf(b[1], c[1]));
            for (size_t k = 0; ear && k < nr; k++) {
                uint32_t v = rl[k];
                if (st[v] != 1 || v == ip || v == cur || v == in) continue;
                const float *q = uv + 2 * v;
                if (q[0] < x0 || q[0] > x1 || q[1] < y0 || q[1] > y1) continue;
                if ((q[0] == a[0] && q[1] == a[1]) || (q[0] == b[0] && q[1] == b[1]) || (q[0] == c[0] && q[1] == c[1]))
                    continue;
                if (in_triangle(q, a, b, c)) ear = false;
            }
        }
        if (!ear) {
            cur = in;
            fails++;
            continue;
        }
        tris[3 * out] = poly[ip]; tris[3 * out + 1] = poly[cur]; tris[3 * out + 2] = poly[in];
        out++;
        nxt[ip] = in;
        prv[in] = ip;
        st[cur] = 2;
        m--;
        fails = 0;
        const uint32_t nb[2] = {ip, in};
        for (int j = 0; j < 2; j++)
            if (st[nb[j]] == 1 && cross2(uv + 2 * prv[nb[j]], uv + 2 * nb[j], uv + 2 * nxt[nb[j]]) > 0) {
                st[nb[j]] = 0;
                live_r--;
            }
        if (nr > 2 * live_r + 16) { /* compact: drop clipped and convex vertices */
            size_t w = 0;
            for (size_t k = 0; k < nr; k++)
                if (st[rl[k]] == 1) rl[w++] = rl[k];
            nr = w;
        }
        cur = in;
    }
    /* remainder (3 vertices, or a self-intersecting rest): fan */
    for (size_t k = 0, v = nxt[cur]; k + 2 < m; k++, v = nxt[v]) {
        tris[3 * out] = poly[cur]; tris[3 * out + 1] = poly[v]; tris[3 * out + 2] = poly[nxt[v]];
        out++;
    }
    return out;
fan:
    for (size_t k = 1; k + 1 < n; k++) {
        tris[3 * out] = poly[0]; tris[3 * out + 1] = poly[k]; tris[3 * out + 2] = poly[k + 1];
        out++;
    }
    return out;
}

/* ---- tessellation ---- */
typedef struct builder {
    float *pos, *nrm, *uv;
    uint32_t *idx;
    size_t nv, ni, cap_v, cap_i;
    bool failed;
} builder;

static uint32_t b_vert(builder *b, float x, float y, float z, float nx, float ny, float nz, float s, float t)
{
    if (b->nv == b->cap_v) {
        size_t cap = b->cap_v ? b->cap_v * 2 : 64;
        float *p = realloc(b->pos, cap * 12), *n = p ? realloc(b->nrm, cap * 12) : NULL;
        if (p) b->pos = p;
        if (n) b->nrm = n;
        float *u = (p && n) ? realloc(b->uv, cap * 8) : NULL;
        if (!u) { b->failed = true; return 0; }
        b->uv = u;
        b->cap_v = cap;
    }
    float *p = b->pos + 3 * b->nv, *n = b->nrm + 3 * b->nv, *u = b->uv + 2 * b->nv;
    p[0] = x; p[1] = y; p[2] = z; n[0] = nx; n[1] = ny; n[2] = nz; u[0] = s; u[1] = t;
    return (uint32_t)b->nv++;
}

static void b_tri(builder *b, uint32_t i0, uint32_t i1, uint32_t i2)
{
    if (b->failed) return;
    if (b->ni + 3 > b->cap_i) {
        size_t cap = b->cap_i ? b->cap_i * 2 : 192;
        uint32_t *p = realloc(b->idx, cap * 4);
        if (!p) { b->failed = true; return; }
        b->idx = p;
        b->cap_i = cap;
    }
    b->idx[b->ni++] = i0; b->idx[b->ni++] = i1; b->idx[b->ni++] = i2;
}

static sy_result b_finish(builder *b, sy_primitive *out, sy_error *err)
{
    memset(out, 0, sizeof *out);
    sy_result r = SY_OK;
    if (b->failed || b->ni == 0) r = oom(err, "primitive tessellation");
    if (!r) r = sy_blob_create_copy(b->pos, b->nv * 12, &out->positions, err);
    if (!r) r = sy_blob_create_copy(b->nrm, b->nv * 12, &out->normals, err);
    if (!r) r = sy_blob_create_copy(b->uv, b->nv * 8, &out->texcoords0, err);
    if (!r) r = sy_blob_create_copy(b->idx, b->ni * 4, &out->indices, err);
    free(b->pos); free(b->nrm); free(b->uv); free(b->idx);
    if (r) {
        sy_blob_release(out->positions); sy_blob_release(out->normals);
        sy_blob_release(out->texcoords0); sy_blob_release(out->indices);
        memset(out, 0, sizeof *out);
    }
    return r;
}

/* X3D texcoords have t pointing up the image; the scene convention (glTF) has v pointing down:
 * every tessellator writes v = 1 - t. */
sy_result sy_tess_box(const float size[3], sy_primitive *out, sy_error *err)
{
    builder b = {0};
    float h[3] = {size[0] * 0.5f, size[1] * 0.5f, size[2] * 0.5f};
    /* faces: normal axis, sign; u axis and v axis chosen so the texture is upright as in X3D */
    static const int fa[6][3] = {{2, 0, 1}, {2, 0, 1}, {0, 2, 1}, {0, 2, 1}, {1, 0, 2}, {1, 0, 2}};
    static const float fs[6][3] = {{1, 1, 1}, {-1, -1, 1}, {1, -1, 1}, {-1, 1, 1}, {1, 1, -1}, {-1, 1, 1}};
    for (int f = 0; f < 6; f++) {
        int na = fa[f][0], ua = fa[f][1], va = fa[f][2];
        uint32_t base = 0;
        for (int k = 0; k < 4; k++) {
            float su = (k == 1 || k == 2) ? 1.0f : -1.0f, sv = (k >= 2) ? 1.0f : -1.0f;
            float p[3], n[3] = {0, 0, 0};
            p[na] = h[na] * fs[f][0];
            p[ua] = h[ua] * su * fs[f][1];
            p[va] = h[va] * sv * fs[f][2];
            n[na] = fs[f][0];
            uint32_t i = b_vert(&b, p[0], p[1], p[2], n[0], n[1], n[2], (su + 1) * 0.5f, 1.0f - (sv + 1) * 0.5f);
            if (k == 0) base = i;
        }
        /* orient counter-clockwise seen from outside */
        float e1[3], e2[3], c[3], nn[3] = {0, 0, 0};
        nn[na] = fs[f][0];
        if (b.failed) break;
        sy_vec3_sub(b.pos + 3 * (base + 1), b.pos + 3 * base, e1);
        sy_vec3_sub(b.pos + 3 * (base + 2), b.pos + 3 * base, e2);
        sy_vec3_cross(e1, e2, c);
        if (sy_vec3_dot(c, nn) >= 0) {
            b_tri(&b, base, base + 1, base + 2);
            b_tri(&b, base, base + 2, base + 3);
        } else {
            b_tri(&b, base, base + 2, base + 1);
            b_tri(&b, base, base + 3, base + 2);
        }
    }
    return b_finish(&b, out, err);
}

sy_result sy_tess_sphere(float radius, const sy_prim_tess *t, sy_primitive *out, sy_error *err)
{
    builder b = {0};
    uint32_t seg = t && t->segments ? t->segments : 32, rings = t && t->rings ? t->rings : 16;
    for (uint32_t r = 0; r <= rings; r++) {
        float th = PI_F * (float)r / (float)rings; /* from +Y (north pole) */
        for (uint32_t s = 0; s <= seg; s++) {
            /* X3D: s = 0 at -Z (back), increasing counter-clockwise seen from +Y */
            float ph = 2.0f * PI_F * (float)s / (float)seg;
            float x = -sinf(th) * sinf(ph), y = cosf(th), z = -sinf(th) * cosf(ph);
            b_vert(&b, radius * x, radius * y, radius * z, x, y, z, (float)s / (float)seg, (float)r / (float)rings);
        }
    }
    for (uint32_t r = 0; r < rings; r++)
        for (uint32_t s = 0; s < seg; s++) {
            uint32_t a = r * (seg + 1) + s, c = a + seg + 1;
            if (r > 0) b_tri(&b, a, c, a + 1);
            if (r + 1 < rings) b_tri(&b, a + 1, c, c + 1);
        }
    return b_finish(&b, out, err);
}

static void disc(builder *b, float y, float radius, float ny, uint32_t seg)
{
    uint32_t c = b_vert(b, 0, y, 0, 0, ny, 0, 0.5f, 0.5f);
    uint32_t first = (uint32_t)b->nv;
    for (uint32_t s = 0; s <= seg; s++) {
        float ph = 2.0f * PI_F * (float)s / (float)seg;
        float x = -sinf(ph), z = -cosf(ph);
        b_vert(b, radius * x, y, radius * z, 0, ny, 0, 0.5f + 0.5f * x, 0.5f + 0.5f * z * ny);
    }
    for (uint32_t s = 0; s < seg; s++) {
        if (ny > 0) b_tri(b, c, first + s, first + s + 1);
        else b_tri(b, c, first + s + 1, first + s);
    }
}

sy_result sy_tess_cone(float bottom_radius, float height, bool side, bool bottom, const sy_prim_tess *t,
                       sy_primitive *out, sy_error *err)
{
    builder b = {0};
    uint32_t seg = t && t->segments ? t->segments : 32;
    float hh = height * 0.5f, len = sqrtf(height * height + bottom_radius * bottom_radius);
    float ny = bottom_radius / len, nr = height / len;
    if (side) {
        for (uint32_t s = 0; s < seg; s++) { /* apex duplicated per segment for a proper normal */
            float ph0 = 2.0f * PI_F * (float)s / (float)seg, ph1 = 2.0f * PI_F * (float)(s + 1) / (float)seg;
            float phm = 0.5f * (ph0 + ph1);
            uint32_t a = b_vert(&b, 0, hh, 0, -sinf(phm) * nr, ny, -cosf(phm) * nr, ((float)s + 0.5f) / (float)seg, 0);
            uint32_t p0 = b_vert(&b, -sinf(ph0) * bottom_radius, -hh, -cosf(ph0) * bottom_radius, -sinf(ph0) * nr, ny,
                                 -cosf(ph0) * nr, (float)s / (float)seg, 1);
            uint32_t p1 = b_vert(&b, -sinf(ph1) * bottom_radius, -hh, -cosf(ph1) * bottom_radius, -sinf(ph1) * nr, ny,
                                 -cosf(ph1) * nr, (float)(s + 1) / (float)seg, 1);
            b_tri(&b, a, p0, p1);
        }
    }
    if (bottom) disc(&b, -hh, bottom_radius, -1.0f, seg);
    return b_finish(&b, out, err);
}

sy_result sy_tess_cylinder(float radius, float height, bool side, bool top, bool bottom, const sy_prim_tess *t,
                           sy_primitive *out, sy_error *err)
{
    builder b = {0};
    uint32_t seg = t && t->segments ? t->segments : 32;
    float hh = height * 0.5f;
    if (side) {
        uint32_t first = (uint32_t)b.nv;
        for (uint32_t s = 0; s <= seg; s++) {
            float ph = 2.0f * PI_F * (float)s / (float)seg, x = -sinf(ph), z = -cosf(ph);
            b_vert(&b, radius * x, hh, radius * z, x, 0, z, (float)s / (float)seg, 0);
            b_vert(&b, radius * x, -hh, radius * z, x, 0, z, (float)s / (float)seg, 1);
        }
        for (uint32_t s = 0; s < seg; s++) {
            uint32_t a = first + 2 * s;
            b_tri(&b, a, a + 1, a + 3);
            b_tri(&b, a, a + 3, a + 2);
        }
    }
    if (top) disc(&b, hh, radius, 1.0f, seg);
    if (bottom) disc(&b, -hh, radius, -1.0f, seg);
    return b_finish(&b, out, err);
}
