/* sy_math.c — 4x4 matrices (column-major), TRS composition, inversion and bounds (see sy_math.h). */
#include "sy_math.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

sy_mat4 sy_mat4_identity(void)
{
    sy_mat4 r = {{0}};
    r.m[0] = r.m[5] = r.m[10] = r.m[15] = 1.0f;
    return r;
}

sy_mat4 sy_mat4_mul(const sy_mat4 *a, const sy_mat4 *b)
{
    sy_mat4 r;
    for (int c = 0; c < 4; ++c)
        for (int row = 0; row < 4; ++row) {
            float s = 0.0f;
            for (int k = 0; k < 4; ++k) s += a->m[k * 4 + row] * b->m[c * 4 + k];
            r.m[c * 4 + row] = s;
        }
    return r;
}

sy_mat4 sy_mat4_from_trs(const float t[3], const float q[4], const float s[3])
{
    float x = q[0], y = q[1], z = q[2], w = q[3];
    sy_mat4 r;
    r.m[0] = (1 - 2 * (y * y + z * z)) * s[0];
    r.m[1] = (2 * (x * y + z * w)) * s[0];
    r.m[2] = (2 * (x * z - y * w)) * s[0];
    r.m[3] = 0;
    r.m[4] = (2 * (x * y - z * w)) * s[1];
    r.m[5] = (1 - 2 * (x * x + z * z)) * s[1];
    r.m[6] = (2 * (y * z + x * w)) * s[1];
    r.m[7] = 0;
    r.m[8] = (2 * (x * z + y * w)) * s[2];
    r.m[9] = (2 * (y * z - x * w)) * s[2];
    r.m[10] = (1 - 2 * (x * x + y * y)) * s[2];
    r.m[11] = 0;
    r.m[12] = t[0];
    r.m[13] = t[1];
    r.m[14] = t[2];
    r.m[15] = 1;
    return r;
}

bool sy_mat4_invert(const sy_mat4 *a, sy_mat4 *out)
{
    const float *m = a->m;
    float inv[16];
    inv[0] = m[5] * m[10] * m[15] - m[5] * m[11] * m[14] - m[9] * m[6] * m[15] + m[9] * m[7] * m[14] +
             m[13] * m[6] * m[11] - m[13] * m[7] * m[10];
    inv[4] = -m[4] * m[10] * m[15] + m[4] * m[11] * m[14] + m[8] * m[6] * m[15] - m[8] * m[7] * m[14] -
             m[12] * m[6] * m[11] + m[12] * m[7] * m[10];
    inv[8] = m[4] * m[9] * m[15] - m[4] * m[11] * m[13] - m[8] * m[5] * m[15] + m[8] * m[7] * m[13] +
             m[12] * m[5] * m[11] - m[12] * m[7] * m[9];
    inv[12] = -m[4] * m[9] * m[14] + m[4] * m[10] * m[13] + m[8] * m[5] * m[14] - m[8] * m[6] * m[13] -
              m[12] * m[5] * m[10] + m[12] * m[6] * m[9];
    inv[1] = -m[1] * m[10] * m[15] + m[1] * m[11] * m[14] + m[9] * m[2] * m[15] - m[9] * m[3] * m[14] -
             m[13] * m[2] * m[11] + m[13] * m[3] * m[10];
    inv[5] = m[0] * m[10] * m[15] - m[0] * m[11] * m[14] - m[8] * m[2] * m[15] + m[8] * m[3] * m[14] +
             m[12] * m[2] * m[11] - m[12] * m[3] * m[10];
    inv[9] = -m[0] * m[9] * m[15] + m[0] * m[11] * m[13] + m[8] * m[1] * m[15] - m[8] * m[3] * m[13] -
             m[12] * m[1] * m[11] + m[12] * m[3] * m[9];
    inv[13] = m[0] * m[9] * m[14] - m[0] * m[10] * m[13] - m[8] * m[1] * m[14] + m[8] * m[2] * m[13] +
              m[12] * m[1] * m[10] - m[12] * m[2] * m[9];
    inv[2] = m[1] * m[6] * m[15] - m[1] * m[7] * m[14] - m[5] * m[2] * m[15] + m[5] * m[3] * m[14] +
             m[13] * m[2] * m[7] - m[13] * m[3] * m[6];
    inv[6] = -m[0] * m[6] * m[15] + m[0] * m[7] * m[14] + m[4] * m[2] * m[15] - m[4] * m[3] * m[14] -
             m[12] * m[2] * m[7] + m[12] * m[3] * m[6];
    inv[10] = m[0] * m[5] * m[15] - m[0] * m[7] * m[13] - m[4] * m[1] * m[15] + m[4] * m[3] * m[13] +
              m[12] * m[1] * m[7] - m[12] * m[3] * m[5];
    inv[14] = -m[0] * m[5] * m[14] + m[0] * m[6] * m[13] + m[4] * m[1] * m[14] - m[4] * m[2] * m[13] -
              m[12] * m[1] * m[6] + m[12] * m[2] * m[5];
    inv[3] = -m[1] * m[6] * m[11] + m[1] * m[7] * m[10] + m[5] * m[2] * m[11] - m[5] * m[3] * m[10] -
             m[9] * m[2] * m[7] + m[9] * m[3] * m[6];
    inv[7] = m[0] * m[6] * m[11] - m[0] * m[7] * m[10] - m[4] * m[2] * m[11] + m[4] * m[3] * m[10] +
             m[8] * m[2] * m[7] - m[8] * m[3] * m[6];
    inv[11] = -m[0] * m[5] * m[11] + m[0] * m[7] * m[9] + m[4] * m[1] * m[11] - m[4] * m[3] * m[9] -
              m[8] * m[1] * m[7] + m[8] * m[3] * m[5];
    inv[15] = m[0] * m[5] * m[10] - m[0] * m[6] * m[9] - m[4] * m[1] * m[10] + m[4] * m[2] * m[9] +
              m[8] * m[1] * m[6] - m[8] * m[2] * m[5];
    float det = m[0] * inv[0] + m[1] * inv[4] + m[2] * inv[8] + m[3] * inv[12];
    if (det == 0.0f || !isfinite(det)) {
        *out = sy_mat4_identity();
        return false;
    }
    float r = 1.0f / det;
    for (int i = 0; i < 16; ++i) out->m[i] = inv[i] * r;
    return true;
}

void sy_mat4_transform_point(const sy_mat4 *a, const float p[3], float out[3])
{
    const float *m = a->m;
    float x = m[0] * p[0] + m[4] * p[1] + m[8] * p[2] + m[12];
    float y = m[1] * p[0] + m[5] * p[1] + m[9] * p[2] + m[13];
    float z = m[2] * p[0] + m[6] * p[1] + m[10] * p[2] + m[14];
    out[0] = x, out[1] = y, out[2] = z;
}

void sy_mat4_transform_dir(const sy_mat4 *a, const float d[3], float out[3])
{
    const float *m = a->m;
    float x = m[0] * d[0] + m[4] * d[1] + m[8] * d[2];
    float y = m[1] * d[0] + m[5] * d[1] + m[9] * d[2];
    float z = m[2] * d[0] + m[6] * d[1] + m[10] * d[2];
    out[0] = x, out[1] = y, out[2] = z;
}

bool sy_coords_in_range(const float *v, size_t n)
{
    for (size_t i = 0; i < n; ++i)
        if (!(fabsf(v[i]) <= SY_COORD_MAX)) return false; /* NaN fails too */
    return true;
}

bool sy_mat4_look_at(const float eye[3], const float target[3], const float up[3], sy_mat4 *out)
{
    for (int i = 0; i < 3; ++i)
        if (!isfinite(eye[i]) || !isfinite(target[i]) || !isfinite(up[i])) return false;
    float z[3], x[3], y[3];
    sy_vec3_sub(eye, target, z); /* the camera looks down -z: z points back from target to eye */
    float zl = sqrtf(sy_vec3_dot(z, z));
    if (!(zl > 0.0f) || !isfinite(zl)) return false;
    for (int i = 0; i < 3; ++i) z[i] /= zl;
    float ul = sqrtf(sy_vec3_dot(up, up));
    if (!(ul > 0.0f) || !isfinite(ul)) return false;
    float u[3] = {up[0] / ul, up[1] / ul, up[2] / ul};
    sy_vec3_cross(u, z, x);
    float xl = sqrtf(sy_vec3_dot(x, x));
    if (!(xl > 1e-6f)) return false; /* up parallel to the viewing direction */
    for (int i = 0; i < 3; ++i) x[i] /= xl;
    sy_vec3_cross(z, x, y);
    sy_mat4 m = {{x[0], x[1], x[2], 0, y[0], y[1], y[2], 0, z[0], z[1], z[2], 0, eye[0], eye[1], eye[2], 1}};
    *out = m;
    return true;
}

bool sy_mat4_is_degenerate(const sy_mat4 *a)
{
    const float *m = a->m; /* column-major: m[c * 4 + r] */
    double s = 0.0;
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) s = fmax(s, fabs((double)m[c * 4 + r]));
    double det = (double)m[0] * ((double)m[5] * m[10] - (double)m[9] * m[6]) -
                 (double)m[4] * ((double)m[1] * m[10] - (double)m[9] * m[2]) +
                 (double)m[8] * ((double)m[1] * m[6] - (double)m[5] * m[2]);
    return !(s > 0.0) || !(fabs(det) > 1e-30 * s * s * s);
}

bool sy_mat4_is_finite(const sy_mat4 *a)
{
    for (int i = 0; i < 16; ++i)
        if (!isfinite(a->m[i])) return false;
    return true;
}

bool sy_mat4_equal(const sy_mat4 *a, const sy_mat4 *b) { return memcmp(a->m, b->m, sizeof a->m) == 0; }

sy_bounds sy_bounds_empty(void)
{
    sy_bounds b = {{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
    return b;
}

bool sy_bounds_is_empty(const sy_bounds *b) { return !(b->min[0] <= b->max[0]); }

void sy_bounds_add_point(sy_bounds *b, const float p[3])
{
    for (int i = 0; i < 3; ++i) {
        if (p[i] < b->min[i]) b->min[i] = p[i];
        if (p[i] > b->max[i]) b->max[i] = p[i];
    }
}

void sy_bounds_add_bounds(sy_bounds *b, const sy_bounds *o)
{
    if (sy_bounds_is_empty(o)) return;
    sy_bounds_add_point(b, o->min);
    sy_bounds_add_point(b, o->max);
}

sy_bounds sy_bounds_transform(const sy_bounds *b, const sy_mat4 *m)
{
    sy_bounds r = sy_bounds_empty();
    if (sy_bounds_is_empty(b)) return r;
    for (int i = 0; i < 8; ++i) {
        float p[3] = {(i & 1) ? b->max[0] : b->min[0], (i & 2) ? b->max[1] : b->min[1],
                      (i & 4) ? b->max[2] : b->min[2]};
        float q[3];
        sy_mat4_transform_point(m, p, q);
        sy_bounds_add_point(&r, q);
    }
    return r;
}

/* The slot of key in the open-addressed set of 2^bits keys (0 = empty): where it is, or the empty
 * slot where it would go. */
static size_t edge_slot(const uint64_t *set, unsigned bits, uint64_t key)
{
    size_t mask = ((size_t)1 << bits) - 1u, i = (size_t)((key * 0x9E3779B97F4A7C15ull) >> (64u - bits));
    while (set[i] && set[i] != key) i = (i + 1u) & mask;
    return i;
}

static uint32_t hash_pos(const float *p)
{
    uint32_t w[3];
    memcpy(w, p, sizeof w);
    uint64_t h = 0x9E3779B97F4A7C15ull;
    for (int k = 0; k < 3; ++k) { /* -0 welds to +0; a 64-bit mix of each word (splitmix64's finalizer) */
        h ^= w[k] == 0x80000000u ? 0u : w[k];
        h *= 0xBF58476D1CE4E5B9ull;
        h ^= h >> 31;
    }
    h *= 0x94D049BB133111EBull;
    return (uint32_t)(h >> 32);
}

int sy_mesh_closed(const float *positions, uint32_t vertex_count, const uint32_t *indices, uint32_t triangle_count)
{
    if (!positions || !triangle_count || triangle_count > SY_MESH_CLOSED_MAX || !vertex_count) return 0;
    const uint32_t nv = vertex_count, nt = triangle_count;
    uint32_t cap = 1;
    while (cap < 2u * nv) cap <<= 1;
    uint32_t *slot = malloc((size_t)cap * sizeof *slot), *weld = malloc((size_t)nv * sizeof *weld);
    unsigned bits = 4; /* the directed edges' hash set: at least twice their count */
    while (((size_t)1 << bits) < 6u * (size_t)nt) bits++;
    uint64_t *edge = calloc((size_t)1 << bits, sizeof *edge);
    bool closed = slot && weld && edge;
    double vol = 0.0; /* six times the signed volume */
    if (closed) {
        memset(slot, 0xff, (size_t)cap * sizeof *slot);
        for (uint32_t v = 0; v < nv; ++v) { /* weld by exact position: the first vertex at a point names it */
            const float *p = positions + 3u * v;
            uint32_t h = hash_pos(p) & (cap - 1);
            for (;; h = (h + 1) & (cap - 1)) {
                if (slot[h] == UINT32_MAX) {
                    slot[h] = v;
                    weld[v] = v;
                    break;
                }
                const float *q = positions + 3u * slot[h];
                if (p[0] == q[0] && p[1] == q[1] && p[2] == q[2]) {
                    weld[v] = slot[h];
                    break;
                }
            }
        }
        size_t ne = 0; /* each directed edge once (a key is never 0: its ends differ) */
        for (uint32_t t = 0; t < nt && closed; ++t) {
            uint32_t i[3];
            for (int k = 0; k < 3; ++k) {
                uint32_t x = indices ? indices[3u * t + k] : 3u * t + k;
                if (x >= nv) closed = false;
                i[k] = closed ? weld[x] : 0;
            }
            if (i[0] == i[1] || i[1] == i[2] || i[2] == i[0]) continue; /* degenerate: no area, no edges */
            for (int k = 0; k < 3 && closed; ++k) {
                uint64_t key = (uint64_t)i[k] << 32 | i[(k + 1) % 3];
                size_t at = edge_slot(edge, bits, key);
                if (edge[at]) closed = false; /* an edge used twice the same way */
                edge[at] = key;
                ne++;
            }
            const float *p0 = positions + 3u * i[0], *p1 = positions + 3u * i[1], *p2 = positions + 3u * i[2];
            vol += p0[0] * ((double)p1[1] * p2[2] - (double)p1[2] * p2[1]) +
                   p0[1] * ((double)p1[2] * p2[0] - (double)p1[0] * p2[2]) +
                   p0[2] * ((double)p1[0] * p2[1] - (double)p1[1] * p2[0]);
        }
        closed = closed && ne > 0;
        for (size_t e = 0; closed && e < ((size_t)1 << bits); ++e) /* and its reverse present */
            if (edge[e] && !edge[edge_slot(edge, bits, edge[e] << 32 | edge[e] >> 32)]) closed = false;
    }
    free(slot);
    free(weld);
    free(edge);
    return !closed || !(vol != 0.0) ? 0 : vol > 0.0 ? 1 : -1;
}
