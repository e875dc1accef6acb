/* sy_gl_objects.c — the scene objects of the rasterizer's API (sy_gl.h): meshes with their levels
 * of detail, textures, materials, instances, punctual and area lights, environment and background. */
#include "sy_gl_internal.h"

#include <meshoptimizer.h>
#include <stb_image_resize.h>
#include <xxhash.h>

#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>


/* The levels of meshes above this many triangles are simplified in pieces of
 * SY_GL_LOD_PIECE_TRIANGLES, each with its own vertices (a level that fits in one piece: whole,
 * with its own vertices and its border free) (issue 39, memory on the user's path):
 * meshopt_simplify's scratch is about 100 bytes per triangle of what it is given, with per-vertex
 * arrays for every vertex it is given, even for a small level of a large mesh (a 10^7-triangle grid
 * peaked at 1.48 GB, 148 B/triangle, in `sy render -b raster`, of which about 95 in the
 * simplifier). A piece is a run of triangles in Morton order of their centroids (sorted once,
 * for level 1; later levels keep that order), with its own vertices and its border locked, so the
 * pieces fit together; its deviation is its own extent times its relative error, the level's the
 * largest. Smaller meshes are simplified whole, as before. */
#define LOD_PIECE_ABOVE (1u << 21)
#define SY_GL_LOD_PIECE_TRIANGLES (1u << 19)

static uint32_t morton_part(float v) /* v in [0, 1] -> 10 bits spread to every third bit */
{
    uint32_t x = (uint32_t)(v * 1023.0f);
    x = x > 1023u ? 1023u : x;
    x = (x | (x << 16)) & 0x030000FFu;
    x = (x | (x << 8)) & 0x0300F00Fu;
    x = (x | (x << 4)) & 0x030C30C3u;
    return (x | (x << 2)) & 0x09249249u;
}
static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

/* One level from the one before (in: n indices) in pieces: into out (room for n) the simplified
 * triangles, piece after piece; returns their index count (0 without memory) and *err the largest
 * deviation of a piece (absolute). order: the triangles of `in` in the order to cut them (NULL:
 * as they are). */
static size_t simplify_pieces(const sy_gl_mesh_desc *d, const uint32_t *in, size_t n, const uint32_t *order,
                              uint32_t *out, float *err)
{
    const size_t piece = SY_GL_LOD_PIECE_TRIANGLES, tris = n / 3u;
    uint32_t *local = malloc(sizeof *local * d->vertex_count); /* mesh vertex -> piece vertex, UINT32_MAX = none */
    uint32_t *glob = malloc(sizeof *glob * 3u * piece);      /* piece vertex -> mesh vertex */
    uint32_t *idx = malloc(sizeof *idx * 3u * piece), *dst = malloc(sizeof *dst * 3u * piece);
    float *pos = malloc(sizeof *pos * 9u * piece);
    size_t used = 0;
    *err = 0.0f;
    if (local && glob && idx && dst && pos) {
        memset(local, 0xff, sizeof *local * d->vertex_count);
        for (size_t t0 = 0; t0 < tris; t0 += piece) {
            size_t pt = tris - t0 < piece ? tris - t0 : piece;
            uint32_t nv = 0;
            for (size_t t = 0; t < pt; ++t) {
                size_t tri = order ? order[t0 + t] : t0 + t;
                for (int k = 0; k < 3; ++k) {
                    uint32_t v = in[3u * tri + (size_t)k];
                    if (local[v] == UINT32_MAX) {
                        local[v] = nv;
                        glob[nv] = v;
                        memcpy(pos + 3u * nv, d->positions + 3u * (size_t)v, 3 * sizeof(float));
                        nv++;
                    }
                    idx[3u * t + (size_t)k] = local[v];
                }
            }
            float rel = 0.0f;
            size_t target = 3u * pt / 4u / 3u * 3u;
            size_t m = meshopt_simplify(dst, idx, 3u * pt, pos, nv, 3 * sizeof(float), target, 1.0f,
                                        pt < tris ? meshopt_SimplifyLockBorder : 0u, &rel);
            float abs_err = rel * meshopt_simplifyScale(pos, nv, 3 * sizeof(float));
            if (abs_err > *err) *err = abs_err;
            for (size_t i = 0; i < m; ++i) out[used + i] = glob[dst[i]];
            used += m;
            for (uint32_t v = 0; v < nv; ++v) local[glob[v]] = UINT32_MAX;
        }
    }
    free(local), free(glob), free(idx), free(dst), free(pos);
    return used;
}

/* The triangles of the index list in Morton order of their centroids (malloc'd; NULL without
 * memory). */
static uint32_t *morton_order(const sy_gl_mesh_desc *d, const uint32_t *in, size_t tris, const float bmin[3],
                              const float bmax[3])
{
    uint64_t *keys = malloc(sizeof *keys * tris);
    uint32_t *order = keys ? malloc(sizeof *order * tris) : NULL;
    if (!order) {
        free(keys);
        return NULL;
    }
    float inv[3];
    for (int k = 0; k < 3; ++k) inv[k] = bmax[k] > bmin[k] ? 1.0f / (bmax[k] - bmin[k]) : 0.0f;
    for (size_t t = 0; t < tris; ++t) {
        float c[3] = {0.0f, 0.0f, 0.0f};
        for (int j = 0; j < 3; ++j)
            for (int k = 0; k < 3; ++k) c[k] += d->positions[3u * (size_t)in[3u * t + (size_t)j] + (size_t)k];
        uint32_t code = 0;
        for (int k = 0; k < 3; ++k) code |= morton_part((c[k] / 3.0f - bmin[k]) * inv[k]) << k;
        keys[t] = (uint64_t)code << 32 | (uint64_t)t;
    }
    qsort(keys, tris, sizeof *keys, cmp_u64);
    for (size_t t = 0; t < tris; ++t) order[t] = (uint32_t)keys[t];
    free(keys);
    return order;
}

/* Level k's indices: level 0 is the mesh's own, the others are in `levels` (the index buffer from
 * index 3 x triangle_count on). */
static const uint32_t *lod_indices(const sy_gl_mesh_desc *d, const mesh_o *m, const uint32_t *levels, uint32_t k)
{
    return k == 0u ? d->indices : levels + (m->lod_first[k] - 3u * (size_t)d->triangle_count);
}

/* The levels of detail of an indexed mesh of at least SY_GL_LOD_MIN_TRIANGLES: into *out (malloc'd;
 * NULL when there is none) each simplified level after the other, the index buffer's part after
 * the mesh's own indices (level 0, not copied: it is uploaded from the mesh's array); m->lod_*
 * describe them, lod_first counted from the buffer's start; *count_out the buffer's indices.
 * Without memory, or when a level would not shrink the one before by a fifth, the chain stops
 * there (level 0 alone is a valid chain). */
static void build_lods(const sy_gl_mesh_desc *d, mesh_o *m, uint32_t **out, size_t *count_out)
{
    size_t n0 = 3u * (size_t)d->triangle_count;
    m->lod_count = 1;
    m->lod_first[0] = 0;
    m->lod_tris[0] = d->triangle_count;
    m->lod_error[0] = m->lod_error_uv[0] = 0.0f;
    *out = NULL;
    *count_out = n0;
    if (!d->indices || d->triangle_count < SY_GL_LOD_MIN_TRIANGLES) return;
    /* the levels after 0: at most n0 * (4/5 + (4/5)^2 + ...) = 4 n0 indices, n0 / 3 in practice;
     * each level first into scratch (meshopt_simplify may need index_count entries) */
    size_t cap = n0 / 2u, used = 0;
    uint32_t *all = malloc(cap * sizeof *all), *scratch = malloc(n0 * sizeof *scratch);
    if (!all || !scratch) {
        free(all), free(scratch);
        return;
    }
    float scale = meshopt_simplifyScale(d->positions, d->vertex_count, 3 * sizeof(float)), err_sum = 0.0f;
    const bool custom_normals = d->triangle_count <= LOD_PIECE_ABOVE && sy_gli_normals_beyond_geometry(d);
    while (m->lod_count < LOD_MAX) {
        uint32_t k = m->lod_count;
        size_t prev_n = 3u * (size_t)m->lod_tris[k - 1], target = prev_n / 4u / 3u * 3u;
        if (target < 3u * 32u) break;
        float rel = 0.0f, dev_abs = 0.0f;
        size_t n;
        if (d->triangle_count > LOD_PIECE_ABOVE) { /* in pieces (level 1: in Morton order) */
            uint32_t *order = k == 1u ? morton_order(d, d->indices, prev_n / 3u, m->bmin, m->bmax) : NULL;
            n = k == 1u && !order ? 0u : simplify_pieces(d, lod_indices(d, m, all, k - 1u), prev_n, order, scratch, &dev_abs);
            free(order);
        } else {
            n = meshopt_simplify(scratch, lod_indices(d, m, all, k - 1u), prev_n, d->positions, d->vertex_count,
                                 3 * sizeof(float), target, 1.0f, 0, &rel);
            dev_abs = rel * scale;
        }
        if (n == 0 || n * 5u > prev_n * 4u) break;
        /* the shading's deviation from the mesh too (a level in pieces: positions only; measuring
         * 2^21 triangles and more would cost more than the simplification) */
        float with_uv = 0.0f;
        float shading = d->triangle_count > LOD_PIECE_ABOVE ? 0.0f
                      : sy_gli_level_shading_error(d, m->bmin, m->bmax, scratch, n / 3u, err_sum + dev_abs, custom_normals,
                                                   &with_uv);
        if (!isfinite(shading)) break;
        if (used + n > cap) {
            size_t ncap = used + n + n0 / 4u;
            uint32_t *grown = realloc(all, ncap * sizeof *all);
            if (!grown) break;
            all = grown;
            cap = ncap;
        }
        memcpy(all + used, scratch, n * sizeof *all);
        err_sum += dev_abs; /* deviation from the level before (meshoptimizer's relative error times the extent) */
        m->lod_first[k] = (uint32_t)(n0 + used);
        m->lod_tris[k] = (uint32_t)(n / 3u);
        m->lod_error[k] = fmaxf(err_sum, shading);
        m->lod_error_uv[k] = fmaxf(m->lod_error[k], with_uv);
        m->lod_count++;
        used += n;
    }
    free(scratch);
    if (!used) free(all), all = NULL;
    *out = all;
    *count_out = n0 + used;
}

/* The slot of key in the open-addressed table of 2^bits keys (0 = empty): where it is, or the empty
 * slot where it would go. */
static size_t edge_slot(const uint64_t *table, unsigned bits, uint64_t key)
{
    size_t mask = ((size_t)1 << bits) - 1u, i = (size_t)((key * 0x9E3779B97F4A7C15ull) >> (64u - bits));
    while (table[i] && table[i] != key) i = (i + 1u) & mask;
    return i;
}

/* mesh_o.lod_closed of the tris triangles idx (NULL: unindexed), vertices welded by weld (a vertex
 * to the id of its position); table: 2^bits zeroed slots, at least twice 3 tris, for the directed
 * edges (a hash set: qsort and bsearch made MetalRoughSpheresNoTextures' 10^6 triangles cost 0.55 s). Degenerate
 * triangles (two corners at one position) are left out: they cover no pixel. */
static int8_t closed_surface(const sy_gl_mesh_desc *d, const uint32_t *idx, size_t tris, const uint32_t *weld,
                             uint64_t *table, unsigned bits)
{
    size_t n = 0;
    double vol = 0.0;
    for (size_t t = 0; t < tris; ++t) {
        uint32_t c[3];
        for (int k = 0; k < 3; ++k) c[k] = weld[idx ? idx[3 * t + k] : (uint32_t)(3 * t + (size_t)k)];
        if (c[0] == c[1] || c[1] == c[2] || c[2] == c[0]) continue;
        for (int k = 0; k < 3; ++k) { /* each directed edge once (a key is never 0: its ends differ) */
            uint64_t key = (uint64_t)c[k] << 32 | c[(k + 1) % 3];
            size_t i = edge_slot(table, bits, key);
            if (table[i]) return 0;
            table[i] = key;
            n++;
        }
        const float *p0 = d->positions + 3u * (size_t)c[0], *p1 = d->positions + 3u * (size_t)c[1], *p2 = d->positions + 3u * (size_t)c[2];
        vol += p0[0] * ((double)p1[1] * p2[2] - (double)p1[2] * p2[1]) + p0[1] * ((double)p1[2] * p2[0] - (double)p1[0] * p2[2]) +
               p0[2] * ((double)p1[0] * p2[1] - (double)p1[1] * p2[0]);
    }
    if (!n || !(vol != 0.0)) return 0;
    for (size_t i = 0; i < ((size_t)1 << bits); ++i) /* and its reverse present */
        if (table[i] && !table[edge_slot(table, bits, table[i] << 32 | table[i] >> 32)]) return 0;
    return vol > 0.0 ? 1 : -1;
}

/* mesh_o.lod_closed for every level of m (levels: build_lods' levels after 0). */
static void check_closed(const sy_gl_mesh_desc *d, mesh_o *m, const uint32_t *levels)
{
    memset(m->lod_closed, 0, sizeof m->lod_closed);
    if (d->triangle_count > CLOSED_MAX_TRIANGLES) return;
    unsigned bits = 4;
    while (((size_t)1 << bits) < 6u * (size_t)d->triangle_count) bits++;
    uint32_t *weld = malloc(sizeof *weld * d->vertex_count);
    uint64_t *table = malloc(sizeof *table << bits);
    if (weld && table) {
        meshopt_generateVertexRemap(weld, NULL, d->vertex_count, d->positions, d->vertex_count, 3 * sizeof(float));
        for (uint32_t k = 0; k < m->lod_count; ++k) {
            memset(table, 0, sizeof *table << bits);
            m->lod_closed[k] = closed_surface(d, d->indices ? lod_indices(d, m, levels, k) : NULL, m->lod_tris[k], weld,
                                              table, bits);
        }
    }
    free(weld);
    free(table);
}

/* >>lod cache: what build_lods and check_closed made of a mesh, kept for the next identical one
 * (positions, normals, uv0 and indices the same bits: every input of theirs). The key of a mesh
 * the cache takes (indexed, with levels, at most LOD_CACHE_MAX_TRIANGLES), 0 for one it does not. */
static uint64_t lod_cache_key(const sy_gl_mesh_desc *d)
{
    if (!d->indices || d->triangle_count < SY_GL_LOD_MIN_TRIANGLES || d->triangle_count > LOD_CACHE_MAX_TRIANGLES)
        return 0;
    XXH3_state_t *st = XXH3_createState();
    if (!st) return 0;
    XXH3_64bits_reset(st);
    const uint32_t head[4] = {d->vertex_count, d->triangle_count, d->normals != NULL, d->uv[0] != NULL};
    XXH3_64bits_update(st, head, sizeof head);
    XXH3_64bits_update(st, d->positions, (size_t)d->vertex_count * 3 * sizeof(float));
    if (d->normals) XXH3_64bits_update(st, d->normals, (size_t)d->vertex_count * 3 * sizeof(float));
    if (d->uv[0]) XXH3_64bits_update(st, d->uv[0], (size_t)d->vertex_count * 2 * sizeof(float));
    XXH3_64bits_update(st, d->indices, (size_t)d->triangle_count * 3 * sizeof(uint32_t));
    uint64_t h = XXH3_64bits_digest(st);
    XXH3_freeState(st);
    return h ? h : 1;
}

/* The description of the levels (lod_count, lod_first, lod_tris, lod_error(_uv), lod_closed) from one
 * mesh_o to another. */
static void levels_copy(mesh_o *to, const mesh_o *from)
{
    to->lod_count = from->lod_count;
    memcpy(to->lod_first, from->lod_first, sizeof to->lod_first);
    memcpy(to->lod_tris, from->lod_tris, sizeof to->lod_tris);
    memcpy(to->lod_error, from->lod_error, sizeof to->lod_error);
    memcpy(to->lod_error_uv, from->lod_error_uv, sizeof to->lod_error_uv);
    memcpy(to->lod_closed, from->lod_closed, sizeof to->lod_closed);
}

/* Whether the cache holds the levels of d (key: lod_cache_key): then m's lod_* and *out (a malloc'd
 * copy), *count_out as build_lods gives them. */
static bool lod_cache_take(sy_gl_device *dev, uint64_t key, const sy_gl_mesh_desc *d, mesh_o *m, uint32_t **out,
                           size_t *count_out)
{
    if (!key) return false;
    for (uint32_t i = 0; i < LOD_CACHE_ENTRIES; ++i) {
        struct lod_cache_entry *e = &dev->lod_cache[i];
        if (!e->used || e->hash != key || e->mesh.vertex_count != d->vertex_count ||
            e->mesh.triangle_count != d->triangle_count) /* the counts too: another mesh's indices never */
            continue;
        uint32_t *copy = NULL;
        if (e->level_indices && !(copy = malloc(e->level_indices * sizeof *copy))) return false;
        if (copy) memcpy(copy, e->levels, e->level_indices * sizeof *copy);
        levels_copy(m, &e->mesh);
        *out = copy;
        *count_out = 3u * (size_t)d->triangle_count + e->level_indices;
        e->used = ++dev->lod_cache_clock;
        return true;
    }
    return false;
}

/* Keeps m's levels (key: lod_cache_key of d; levels: build_lods' indices after level 0, count the
 * buffer's indices) for the next identical mesh, in the least recently used entry; nothing without
 * memory. */
static void lod_cache_put(sy_gl_device *dev, uint64_t key, const sy_gl_mesh_desc *d, const mesh_o *m,
                          const uint32_t *levels, size_t count)
{
    if (!key) return;
    struct lod_cache_entry *e = &dev->lod_cache[0];
    for (uint32_t i = 1; i < LOD_CACHE_ENTRIES; ++i)
        if (dev->lod_cache[i].used < e->used) e = &dev->lod_cache[i];
    size_t n = count - 3u * (size_t)d->triangle_count;
    uint32_t *copy = n ? malloc(n * sizeof *copy) : NULL;
    if (n && !copy) return;
    if (copy) memcpy(copy, levels, n * sizeof *copy);
    free(e->levels);
    e->levels = copy;
    e->level_indices = n;
    e->hash = key;
    e->mesh.vertex_count = d->vertex_count, e->mesh.triangle_count = d->triangle_count;
    levels_copy(&e->mesh, m);
    e->used = ++dev->lod_cache_clock;
}

void sy_gli_lod_cache_free(sy_gl_device *dev)
{
    for (uint32_t i = 0; i < LOD_CACHE_ENTRIES; ++i) {
        free(dev->lod_cache[i].levels);
        memset(&dev->lod_cache[i], 0, sizeof dev->lod_cache[i]);
    }
}

/* The mesh's box, and the sphere around it that culling and levels of detail use. */
static void set_bounds(mesh_o *m, const float bmin[3], const float bmax[3])
{
    memcpy(m->bmin, bmin, 3 * sizeof *bmin);
    memcpy(m->bmax, bmax, 3 * sizeof *bmax);
    float r2 = 0.0f;
    for (int k = 0; k < 3; ++k) {
        m->centre[k] = 0.5f * (bmin[k] + bmax[k]);
        r2 += 0.25f * (bmax[k] - bmin[k]) * (bmax[k] - bmin[k]);
    }
    m->radius = sqrtf(r2);
}

static const int vertex_comps[5] = {3, 3, 2, 2, 4}; /* floats of position, normal, uv0, uv1, colour (given) */

/* The interleaved vertex buffer of a mesh (issue 39, memory on the user's path): the position and
 * colour as floats; the normal packed into 4 bytes (GL_INT_2_10_10_10_REV, signed normalised: the
 * unit vector's components to 1/511, about 0.1 degree; 8 bytes less per vertex); a uv set whose
 * coordinates all lie in [0, 1] as two 16-bit unsigned normalised numbers (to 1/65535: an eighth of
 * a texel of an 8192-texel texture; 4 bytes less), another as floats (repeating textures). A mesh
 * that is updated (a skin, a morph) goes to floats throughout at its first update: packing cost
 * a 10^5-vertex skin 1.4 ms a frame (`sy bench deform`, raster 4.1 -> 5.6 ms), and memory counts
 * where meshes are large and still. */
typedef struct vertex_layout {
    int offs[5], stride; /* bytes */
    bool n10, uv16[2];   /* the normal in 10-bit components, uv0 and uv1 in 16 bits */
} vertex_layout;

/* Whether the n uv pairs all lie in [0, 1] (NaN does not). */
static bool uv_fits_16(const float *uv, uint32_t n)
{
    for (size_t i = 0; i < 2u * (size_t)n; ++i)
        if (!(uv[i] >= 0.0f && uv[i] <= 1.0f)) return false;
    return true;
}

/* The unit normal n in GL_INT_2_10_10_10_REV (x in the low bits, w 0); a zero or non-finite normal
 * packs to 0 (the float shaders normalised it to NaN either way). */
static uint32_t pack_normal(const float n[3])
{
    const float len = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    const float s = len > 0.0f && isfinite(len) ? 511.0f / len : 0.0f;
    uint32_t p = 0;
    for (int k = 0; k < 3; ++k) {
        const float c = fminf(fmaxf(n[k] * s, -511.0f), 511.0f);
        p |= ((uint32_t)(int32_t)lrintf(c) & 0x3ffu) << (10 * k);
    }
    return p;
}

/* Whether attribute a is a uv set that l holds in 16 bits. */
static bool attr_uv16(const vertex_layout *l, int a) { return (a == 2 || a == 3) && l->uv16[a - 2]; }

/* Bytes of attribute a in layout l. */
static int attr_bytes(const vertex_layout *l, int a)
{
    return (a == 1 && l->n10) || attr_uv16(l, a) ? 4 : vertex_comps[a] * (int)sizeof(float);
}

/* The layout of the interleaved vertex buffer of the attributes present in arrays (position, normal,
 * uv0, uv1, colour; NULL = absent): packed (a mesh's creation) or all floats (its updates), the uv
 * sets packed only where they fit (uv_fits_16); returns the buffer's bytes. */
static size_t interleaved_layout(const sy_gl_mesh_desc *d, const float *const arrays[5], bool packed, vertex_layout *l)
{
    l->n10 = packed;
    for (int k = 0; k < 2; ++k) l->uv16[k] = packed && arrays[2 + k] && uv_fits_16(arrays[2 + k], d->vertex_count);
    l->stride = 0;
    for (int a = 0; a < 5; ++a) {
        l->offs[a] = l->stride;
        if (arrays[a]) l->stride += attr_bytes(l, a);
    }
    return (size_t)d->vertex_count * (size_t)l->stride;
}

/* The vertex attribute pointers of the bound vertex array to the bound GL_ARRAY_BUFFER, as l lays
 * it out. */
static void vertex_pointers(const sy_gl_fns *gl, const float *const arrays[5], const vertex_layout *l)
{
    for (int a = 0; a < 5; ++a) {
        if (!arrays[a]) continue;
        const void *at = (const void *)(uintptr_t)l->offs[a];
        gl->EnableVertexAttribArray((GLuint)a);
        if (a == 1 && l->n10) gl->VertexAttribPointer(1, 4, GL_INT_2_10_10_10_REV, GL_TRUE, l->stride, at);
        else if (attr_uv16(l, a)) gl->VertexAttribPointer((GLuint)a, 2, GL_UNSIGNED_SHORT, GL_TRUE, l->stride, at);
        else gl->VertexAttribPointer((GLuint)a, vertex_comps[a], GL_FLOAT, GL_FALSE, l->stride, at);
    }
}

/* Vertices per piece of an interleaved upload. */
#define UPLOAD_PIECE_VERTICES 65536u

/* Fills the bound GL_ARRAY_BUFFER (already sized) with the interleaved vertices, a piece of
 * UPLOAD_PIECE_VERTICES at a time (a 10^7-triangle mesh's whole interleaved copy was 16 bytes per
 * triangle at the peak, issue 39). false without memory. */
static bool upload_interleaved(const sy_gl_fns *gl, const sy_gl_mesh_desc *d, const float *const arrays[5],
                               const vertex_layout *l, const uint32_t *order)
{
    uint32_t piece = d->vertex_count < UPLOAD_PIECE_VERTICES ? d->vertex_count : UPLOAD_PIECE_VERTICES;
    unsigned char *vb = malloc((size_t)piece * (size_t)l->stride);
    if (!vb) return false;
    for (uint32_t first = 0; first < d->vertex_count; first += piece) {
        uint32_t count = d->vertex_count - first < piece ? d->vertex_count - first : piece;
        for (uint32_t i = 0; i < count; ++i) {
            size_t v = order ? order[first + i] : first + i;
            unsigned char *out = vb + (size_t)i * (size_t)l->stride;
            for (int a = 0; a < 5; ++a) {
                if (!arrays[a]) continue;
                const float *in = arrays[a] + v * (size_t)vertex_comps[a];
                if (a == 1 && l->n10) {
                    const uint32_t p = pack_normal(in);
                    memcpy(out + l->offs[1], &p, sizeof p);
                } else if (attr_uv16(l, a)) { /* a uv set in [0, 1] (uv_fits_16) */
                    const uint16_t q[2] = {(uint16_t)lrintf(in[0] * 65535.0f), (uint16_t)lrintf(in[1] * 65535.0f)};
                    memcpy(out + l->offs[a], q, sizeof q);
                } else {
                    memcpy(out + l->offs[a], in, (size_t)vertex_comps[a] * sizeof(float));
                }
            }
        }
        gl->BufferSubData(GL_ARRAY_BUFFER, (GLintptr)((size_t)first * (size_t)l->stride),
                          (GLsizeiptr)((size_t)count * (size_t)l->stride), vb);
    }
    free(vb);
    return true;
}

/* The vertex order of a mesh with levels (mesh_o.order): the coarsest level's vertices first, in
 * the order its indices name them, then each finer level's new ones, then any vertex no triangle
 * uses. Into *order (malloc'd) and *where (malloc'd, the inverse: a mesh vertex's buffer position);
 * false without memory. */
static bool level_vertex_order(const sy_gl_mesh_desc *d, const mesh_o *m, const uint32_t *levels, uint32_t **order,
                               uint32_t **where)
{
    uint32_t *o = malloc(sizeof *o * d->vertex_count), *w = malloc(sizeof *w * d->vertex_count);
    if (!o || !w) {
        free(o), free(w);
        return false;
    }
    memset(w, 0xff, sizeof *w * d->vertex_count);
    uint32_t next = 0;
    for (uint32_t k = m->lod_count; k-- > 0;) {
        const uint32_t *idx = lod_indices(d, m, levels, k);
        for (size_t i = 0; i < 3u * (size_t)m->lod_tris[k]; ++i)
            if (w[idx[i]] == UINT32_MAX) w[idx[i]] = next, o[next++] = idx[i];
    }
    for (uint32_t v = 0; v < d->vertex_count; ++v)
        if (w[v] == UINT32_MAX) w[v] = next, o[next++] = v;
    *order = o;
    *where = w;
    return true;
}

/* The box of d's positions into bmin / bmax; a position that is not finite fails, "WHAT: position I
 * is not finite". */
static sy_gl_result positions_box(const sy_gl_mesh_desc *d, const char *what, float bmin[3], float bmax[3],
                                  sy_gl_report *rep)
{
    for (int k = 0; k < 3; ++k) bmin[k] = INFINITY, bmax[k] = -INFINITY;
    for (uint32_t i = 0; i < d->vertex_count; ++i)
        for (int k = 0; k < 3; ++k) {
            float v = d->positions[3u * i + k];
            if (!isfinite(v)) return sy_gli_fail(rep, SY_GL_ERROR_INVALID_ARGUMENT, "%s: position %u is not finite", what, i);
            bmin[k] = fminf(bmin[k], v);
            bmax[k] = fmaxf(bmax[k], v);
        }
    return SY_GL_OK;
}

sy_gl_result sy_gl_mesh_create(sy_gl_device *dev, const sy_gl_mesh_desc *d, sy_gl_mesh *out)
{
    sy_gl_report *rep = dev ? dev->report : NULL;
    out->id = 0;
    if (!d || !d->positions || d->vertex_count == 0 || d->triangle_count == 0)
        return sy_gli_fail(rep, SY_GL_ERROR_INVALID_ARGUMENT, "mesh: positions and a non-zero vertex and triangle count are required");
    if (d->triangle_count > UINT32_MAX / 3u)
        return sy_gli_fail(rep, SY_GL_ERROR_LIMIT, "mesh: %u triangles exceed the index range", d->triangle_count);
    if (!d->indices && d->vertex_count != 3u * d->triangle_count)
        return sy_gli_fail(rep, SY_GL_ERROR_INVALID_ARGUMENT,
                    "mesh: without indices vertex_count (%u) must be 3 x triangle_count (%u)", d->vertex_count,
                    d->triangle_count);
    float bmin[3], bmax[3];
    sy_gl_result r = positions_box(d, "mesh", bmin, bmax, rep);
    if (r != SY_GL_OK) return r;
    if (d->indices)
        for (uint32_t i = 0; i < 3u * d->triangle_count; ++i)
            if (d->indices[i] >= d->vertex_count)
                return sy_gli_fail(rep, SY_GL_ERROR_INVALID_ARGUMENT, "mesh: index %u = %u is out of range (%u vertices)",
                            i, d->indices[i], d->vertex_count);
    r = sy_gli_current(dev, rep);
    if (r != SY_GL_OK) return r;
    mesh_o *m = sy_gli_pool_alloc(&dev->meshes);
    if (!m) return sy_gli_fail(rep, SY_GL_ERROR_OUT_OF_MEMORY, "mesh: out of memory");
    const sy_gl_fns *gl = dev->gl;
    m->vertex_count = d->vertex_count;
    m->triangle_count = d->triangle_count;
    set_bounds(m, bmin, bmax);
    uint32_t *lods = NULL;
    size_t index_count = 0;
    const uint64_t key = lod_cache_key(d);
    if (!lod_cache_take(dev, key, d, m, &lods, &index_count)) {
        build_lods(d, m, &lods, &index_count);
        check_closed(d, m, lods);
        lod_cache_put(dev, key, d, m, lods, index_count);
    }
    uint32_t *where = NULL; /* with m->order: a mesh vertex's buffer position */
    if (lods && d->vertex_count >= LOD_REORDER_VERTICES && level_vertex_order(d, m, lods, &m->order, &where))
        for (size_t i = 0; i < index_count - 3u * (size_t)d->triangle_count; ++i) lods[i] = where[lods[i]];
    m->cap_closed = (int8_t)(d->closed > 0 ? 1 : d->closed < 0 ? -1 : 0);
    gl->GenVertexArrays(1, &m->vao);
    gl->BindVertexArray(m->vao);
    /* one index buffer, then one interleaved vertex buffer: the index buffer first, so that the
     * levels' indices and the renumbering (lods, where) are freed before the vertex buffer is
     * taken */
    if (d->indices) {
        size_t bytes = index_count * sizeof(uint32_t);
        gl->GenBuffers(1, &m->ibo);
        gl->BindBuffer(GL_ELEMENT_ARRAY_BUFFER, m->ibo);
        /* the mesh's indices, then the levels: no copy of the mesh's in between; the levels are
         * written first and freed before level 0 fills its part (the buffer's pages are taken as
         * they are written: the levels' copy, 4 bytes per triangle of a grid, is not held at once) */
        size_t n0 = 3u * (size_t)d->triangle_count * sizeof(uint32_t);
        gl->BufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)bytes, lods ? NULL : d->indices, GL_STATIC_DRAW);
        const bool levels = lods != NULL;
        if (levels) gl->BufferSubData(GL_ELEMENT_ARRAY_BUFFER, (GLintptr)n0, (GLsizeiptr)(bytes - n0), lods);
        free(lods);
        if (levels && where) { /* level 0 renumbered a piece at a time */
            uint32_t piece[16384];
            size_t count = n0 / sizeof(uint32_t);
            for (size_t first = 0; first < count; first += 16384u) {
                size_t c = count - first < 16384u ? count - first : 16384u;
                for (size_t i = 0; i < c; ++i) piece[i] = where[d->indices[first + i]];
                gl->BufferSubData(GL_ELEMENT_ARRAY_BUFFER, (GLintptr)(first * sizeof(uint32_t)),
                                  (GLsizeiptr)(c * sizeof(uint32_t)), piece);
            }
        } else if (levels) {
            gl->BufferSubData(GL_ELEMENT_ARRAY_BUFFER, 0, (GLsizeiptr)n0, d->indices);
        }
        free(where);
        sy_gli_count_buffer(dev, false, bytes);
        m->indexed = true;
    }
    /* one interleaved vertex buffer (present attributes only) */
    const float *arrays[5] = {d->positions, d->normals, d->uv[0], d->uv[1], d->colors};
    vertex_layout layout;
    size_t bytes = interleaved_layout(d, arrays, true, &layout);
    m->packed = layout.n10 || layout.uv16[0] || layout.uv16[1];
    gl->GenBuffers(1, &m->vbo[0]);
    gl->BindBuffer(GL_ARRAY_BUFFER, m->vbo[0]);
    gl->BufferData(GL_ARRAY_BUFFER, (GLsizeiptr)bytes, NULL, GL_STATIC_DRAW);
    if (!upload_interleaved(gl, d, arrays, &layout, m->order)) {
        gl->BindVertexArray(0);
        sy_gl_mesh h = {m->h.id};
        sy_gl_mesh_destroy(dev, h);
        return sy_gli_fail(rep, SY_GL_ERROR_OUT_OF_MEMORY, "mesh: out of memory (%u vertices)", d->vertex_count);
    }
    sy_gli_count_buffer(dev, false, bytes);
    m->reordered = m->order != NULL; /* the order again only for an update (mesh_o.order) */
    free(m->order);
    m->order = NULL;
    for (int a = 0; a < 5; ++a) m->has_attr[a] = arrays[a] != NULL;
    vertex_pointers(gl, arrays, &layout);
    m->has_normals = d->normals != NULL;
    gl->BindVertexArray(0);
    r = sy_gli_gl_check(dev, "mesh upload", rep);
    if (r != SY_GL_OK) {
        sy_gl_mesh h = {m->h.id};
        sy_gl_mesh_destroy(dev, h);
        return r;
    }
    out->id = m->h.id;
    return SY_GL_OK;
}

/* mesh_o.order again for a reordered mesh, from its index buffer: level 0 there holds each corner's
 * buffer position, d->indices (the mesh's, unchanged since its creation) its mesh vertex; the
 * vertices no triangle uses follow the used ones in the mesh's order, as level_vertex_order placed
 * them. Fails without memory, without indices or with others than the mesh's. */
static sy_gl_result order_from_buffer(const sy_gl_fns *gl, const sy_gl_mesh_desc *d, mesh_o *m, sy_gl_report *rep)
{
    enum { PIECE = 16384 };
    static const char *const fmt = "mesh update: %s (its vertex buffer is in the order of its levels, read back from them)";
    if (!d->indices) return sy_gli_fail(rep, SY_GL_ERROR_INVALID_ARGUMENT, fmt, "the mesh's indices are required");
    uint32_t *o = malloc(sizeof *o * d->vertex_count), *piece = malloc(sizeof *piece * PIECE);
    unsigned char *used = calloc(d->vertex_count, 1);
    const char *why = NULL; /* indices other than the mesh's */
    const bool memory = o && piece && used;
    if (memory) {
        memset(o, 0xff, sizeof *o * d->vertex_count);
        gl->BindBuffer(GL_COPY_READ_BUFFER, m->ibo);
        const size_t count = 3u * (size_t)d->triangle_count;
        uint32_t next = 0;
        for (size_t first = 0; first < count && !why; first += PIECE) {
            const size_t c = count - first < PIECE ? count - first : PIECE;
            gl->GetBufferSubData(GL_COPY_READ_BUFFER, (GLintptr)(first * sizeof *piece), (GLsizeiptr)(c * sizeof *piece), piece);
            for (size_t i = 0; i < c && !why; ++i) {
                const uint32_t b = piece[i], v = d->indices[first + i];
                if (b >= d->vertex_count || v >= d->vertex_count || (o[b] != UINT32_MAX && o[b] != v)) {
                    why = "its indices are not the ones it was made with";
                    break;
                }
                o[b] = v;
                next += !used[v];
                used[v] = 1;
            }
        }
        gl->BindBuffer(GL_COPY_READ_BUFFER, 0);
        for (uint32_t p = 0; p < next && !why; ++p) /* the used vertices fill the first positions */
            if (o[p] == UINT32_MAX) why = "its indices are not the ones it was made with";
        for (uint32_t v = 0; v < d->vertex_count && !why; ++v)
            if (!used[v]) o[next++] = v;
    }
    free(piece), free(used);
    if (!memory || why) {
        free(o);
        return memory ? sy_gli_fail(rep, SY_GL_ERROR_INVALID_ARGUMENT, fmt, why)
                      : sy_gli_fail(rep, SY_GL_ERROR_OUT_OF_MEMORY, fmt, "out of memory");
    }
    m->order = o;
    return SY_GL_OK;
}

sy_gl_result sy_gl_mesh_update(sy_gl_device *dev, sy_gl_mesh mesh, const sy_gl_mesh_desc *d)
{
    sy_gl_report *rep = dev ? dev->report : NULL;
    mesh_o *m = dev ? sy_gli_pool_get(&dev->meshes, mesh.id) : NULL;
    if (!m) return sy_gli_fail(rep, SY_GL_ERROR_INVALID_HANDLE, "mesh update: stale handle 0x%08x", mesh.id);
    const float *arrays[5] = {d ? d->positions : NULL, d ? d->normals : NULL, d ? d->uv[0] : NULL, d ? d->uv[1] : NULL,
                              d ? d->colors : NULL};
    if (!d || d->vertex_count != m->vertex_count || d->triangle_count != m->triangle_count)
        return sy_gli_fail(rep, SY_GL_ERROR_INVALID_ARGUMENT, "mesh update: counts differ from the mesh's (%u vertices, %u triangles)",
                           m->vertex_count, m->triangle_count);
    for (int a = 0; a < 5; ++a)
        if (!arrays[a] != !m->has_attr[a])
            return sy_gli_fail(rep, SY_GL_ERROR_INVALID_ARGUMENT, "mesh update: attribute %d present in one and not the other", a);
    float bmin[3], bmax[3];
    sy_gl_result r = positions_box(d, "mesh update", bmin, bmax, rep);
    if (r == SY_GL_OK) r = sy_gli_current(dev, rep);
    if (r != SY_GL_OK) return r;
    const sy_gl_fns *gl = dev->gl;
    if (m->reordered && !m->order && (r = order_from_buffer(gl, d, m, rep)) != SY_GL_OK) return r;
    /* the first update turns a packed buffer to floats for good (a new buffer and attribute
     * pointers; vertex_layout) */
    const bool relayout = m->packed;
    vertex_layout layout;
    size_t bytes = interleaved_layout(d, arrays, false, &layout);
    gl->BindBuffer(GL_ARRAY_BUFFER, m->vbo[0]);
    if (relayout) gl->BufferData(GL_ARRAY_BUFFER, (GLsizeiptr)bytes, NULL, GL_STATIC_DRAW);
    bool ok = upload_interleaved(gl, d, arrays, &layout, m->order);
    if (ok && relayout) {
        gl->BindVertexArray(m->vao);
        vertex_pointers(gl, arrays, &layout);
        gl->BindVertexArray(0);
        m->packed = false;
    }
    gl->BindBuffer(GL_ARRAY_BUFFER, 0);
    if (!ok) return sy_gli_fail(rep, SY_GL_ERROR_OUT_OF_MEMORY, "mesh update: out of memory (%u vertices)", d->vertex_count);
    sy_gli_count_buffer(dev, false, bytes);
    set_bounds(m, bmin, bmax);
    sy_gli_geometry_changed(dev);
    return sy_gli_gl_check(dev, "mesh update", rep);
}

sy_gl_result sy_gl_mesh_destroy(sy_gl_device *dev, sy_gl_mesh mesh)
{
    mesh_o *m = sy_gli_pool_get(&dev->meshes, mesh.id);
    if (!m) return sy_gli_fail(dev->report, SY_GL_ERROR_INVALID_HANDLE, "%s: stale handle 0x%08x", __func__, mesh.id);
    if (sy_gli_current(dev, NULL) == SY_GL_OK) {
        dev->gl->DeleteBuffers(1, m->vbo);
        dev->gl->DeleteBuffers(1, &m->ibo);
        dev->gl->DeleteVertexArrays(1, &m->vao);
    }
    free(m->order);
    sy_gli_pool_free(&dev->meshes, m);
    sy_gli_geometry_changed(dev);
    return SY_GL_OK;
}

/* Resamples an RGBA image (8-bit, sRGB-encoded 8-bit or float; tightly packed) to nw x nh with
 * stb_image_resize's box filter (an exact 2x2 mean when a side halves), edges as the texture wraps:
 * sRGB texels are filtered in linear light, alpha linearly and unweighted, as glGenerateMipmap does.
 * false without memory. */
static bool resample(const void *src, uint32_t w, uint32_t h, void *dst, uint32_t nw, uint32_t nh, bool is_float,
                     bool srgb, const stbir_edge edge[2])
{
    return stbir_resize(src, (int)w, (int)h, 0, dst, (int)nw, (int)nh, 0, is_float ? STBIR_TYPE_FLOAT : STBIR_TYPE_UINT8, 4, 3,
                        STBIR_FLAG_ALPHA_PREMULTIPLIED, edge[0], edge[1], STBIR_FILTER_BOX, STBIR_FILTER_BOX,
                        srgb ? STBIR_COLORSPACE_SRGB : STBIR_COLORSPACE_LINEAR, NULL) == 1;
}

/* Uploads level 0 (w x h RGBA texels) to the bound texture and the whole mipmap chain below it,
 * made on the CPU: glGenerateMipmap on llvmpipe compiles a blit shader per format and filters on the
 * GL threads (0.53 s for a 2048x2048 sRGB texture, 0.12 s for the first texture of each format, in
 * TransmissionTest's first frame); the box filter here costs a few tens of milliseconds. */
static sy_gl_result upload_levels(sy_gl_device *dev, const void *level0, uint32_t w, uint32_t h, bool is_float, bool srgb,
                                  const stbir_edge edge[2], sy_gl_report *rep)
{
    const sy_gl_fns *gl = dev->gl;
    size_t texel = is_float ? 16 : 4, below = 0;
    /* A 1x1 image is uploaded as 2x2 copies of its texel with a 1x1 level below, as the stand-ins
     * are (sy_gli_make_standin): the same value under every filter and wrap, and a texture with a
     * mip level like every other, so llvmpipe does not compile one more variant of the shader for
     * a texture of one level (TextureEncodingTest's 1x1 colour swatches) */
    unsigned char quad[4 * 16];
    if (w == 1 && h == 1) {
        for (int i = 0; i < 4; ++i) memcpy(quad + (size_t)i * texel, level0, texel);
        level0 = quad, w = h = 2;
    }
    for (uint32_t lw = w, lh = h; lw > 1 || lh > 1;) {
        lw = lw > 1 ? lw / 2 : 1, lh = lh > 1 ? lh / 2 : 1;
        below += (size_t)lw * lh;
    }
    unsigned char *chain = below ? malloc(below * texel) : NULL;
    if (below && !chain)
        return sy_gli_fail(rep, SY_GL_ERROR_OUT_OF_MEMORY, "texture: out of memory (mipmaps of %ux%u)", w, h);
    GLint internal = is_float ? GL_RGBA32F : srgb ? GL_SRGB8_ALPHA8 : GL_RGBA8;
    GLenum type = is_float ? GL_FLOAT : GL_UNSIGNED_BYTE;
    const unsigned char *prev = level0;
    unsigned char *next = chain;
    for (GLint level = 0;; ++level) {
        gl->TexImage2D(GL_TEXTURE_2D, level, internal, (GLsizei)w, (GLsizei)h, 0, GL_RGBA, type, prev);
        dev->counts.texture_bytes += (size_t)w * h * texel;
        if (w == 1 && h == 1) break;
        uint32_t nw = w > 1 ? w / 2 : 1, nh = h > 1 ? h / 2 : 1;
        if (!resample(prev, w, h, next, nw, nh, is_float, srgb, edge)) {
            free(chain);
            return sy_gli_fail(rep, SY_GL_ERROR_OUT_OF_MEMORY, "texture: out of memory (mipmaps of %ux%u)", w, h);
        }
        prev = next;
        next += (size_t)nw * nh * texel;
        w = nw, h = nh;
    }
    free(chain);
    return SY_GL_OK;
}

sy_gl_result sy_gli_cube_mipmaps(sy_gl_device *dev, GLuint cube, GLuint fbo, uint32_t side, sy_gl_report *rep)
{
    const sy_gl_fns *gl = dev->gl;
    size_t below = 0;
    for (uint32_t s = side; s > 1;) s /= 2, below += (size_t)s * s;
    float *buf = malloc(((size_t)side * side + below) * 4 * sizeof(float));
    if (!buf) return sy_gli_fail(rep, SY_GL_ERROR_OUT_OF_MEMORY, "scene probes: out of memory (mipmaps of %u texels)", side);
    static const stbir_edge clamp[2] = {STBIR_EDGE_CLAMP, STBIR_EDGE_CLAMP};
    gl->BindFramebuffer(GL_FRAMEBUFFER, fbo);
    gl->ReadBuffer(GL_COLOR_ATTACHMENT0);
    gl->PixelStorei(GL_PACK_ALIGNMENT, 4);
    gl->BindTexture(GL_TEXTURE_CUBE_MAP, cube);
    for (GLenum f = 0; f < 6; ++f) {
        const GLenum face = GL_TEXTURE_CUBE_MAP_POSITIVE_X + f;
        gl->FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, face, cube, 0);
        gl->ReadPixels(0, 0, (GLsizei)side, (GLsizei)side, GL_RGBA, GL_FLOAT, buf);
        const float *prev = buf;
        float *next = buf + (size_t)side * side * 4;
        for (GLint level = 1, s = (GLint)side; s > 1; ++level) {
            GLint ns = s / 2;
            if (!resample(prev, (uint32_t)s, (uint32_t)s, next, (uint32_t)ns, (uint32_t)ns, true, false, clamp)) {
                free(buf);
                return sy_gli_fail(rep, SY_GL_ERROR_OUT_OF_MEMORY, "scene probes: out of memory (mipmaps of %u texels)", side);
            }
            gl->TexImage2D(face, level, GL_RGBA16F, ns, ns, 0, GL_RGBA, GL_FLOAT, next);
            prev = next;
            next += (size_t)ns * ns * 4;
            s = ns;
        }
    }
    free(buf);
    return SY_GL_OK;
}

sy_gl_result sy_gl_texture_create(sy_gl_device *dev, const sy_gl_texture_desc *d, sy_gl_texture *out)
{
    sy_gl_report *rep = dev ? dev->report : NULL;
    out->id = 0;
    if (!d || !d->pixels || d->width == 0 || d->height == 0 || d->channels < 1 || d->channels > 4)
        return sy_gli_fail(rep, SY_GL_ERROR_INVALID_ARGUMENT, "texture: needs pixels, a non-zero size and 1..4 channels");
    if (d->format != SY_GL_TEXEL_UNORM8 && d->format != SY_GL_TEXEL_UNORM8_SRGB && d->format != SY_GL_TEXEL_FLOAT32)
        return sy_gli_fail(rep, SY_GL_ERROR_INVALID_ARGUMENT, "texture: unknown texel format %d", (int)d->format);
    size_t n = (size_t)d->width * d->height;
    if (n / d->width != d->height || n > ((size_t)1 << 32))
        return sy_gli_fail(rep, SY_GL_ERROR_LIMIT, "texture: %ux%u is too large", d->width, d->height);
    bool is_float = d->format == SY_GL_TEXEL_FLOAT32, srgb = d->format == SY_GL_TEXEL_UNORM8_SRGB;
    uint32_t ch = d->channels, w = d->width, h = d->height;
    size_t texel = is_float ? 4 * sizeof(float) : 4;
    /* expand to RGBA in the texel type (grey -> rgb, grey+alpha -> rgb+a) */
    unsigned char *img = malloc(n * texel);
    if (!img) return sy_gli_fail(rep, SY_GL_ERROR_OUT_OF_MEMORY, "texture: out of memory (%ux%u)", w, h);
    if (is_float) {
        const float *s = d->pixels;
        float *o = (float *)img;
        for (size_t i = 0; i < n; ++i, s += ch, o += 4) {
            if (ch <= 2) o[0] = o[1] = o[2] = s[0], o[3] = ch == 2 ? s[1] : 1.0f;
            else o[0] = s[0], o[1] = s[1], o[2] = s[2], o[3] = ch == 4 ? s[3] : 1.0f;
        }
    } else {
        const unsigned char *s = d->pixels;
        unsigned char *o = img;
        for (size_t i = 0; i < n; ++i, s += ch, o += 4) {
            if (ch <= 2) o[0] = o[1] = o[2] = s[0], o[3] = ch == 2 ? s[1] : 255;
            else o[0] = s[0], o[1] = s[1], o[2] = s[2], o[3] = ch == 4 ? s[3] : 255;
        }
    }
    static const stbir_edge edges[3] = {STBIR_EDGE_WRAP, STBIR_EDGE_CLAMP, STBIR_EDGE_REFLECT};
    const stbir_edge edge[2] = {edges[(unsigned)d->wrap_s < 3u ? d->wrap_s : 0], edges[(unsigned)d->wrap_t < 3u ? d->wrap_t : 0]};
    if (w > dev->max_tex || h > dev->max_tex) { /* halve the sides until the GL holds them */
        uint32_t ow = w, oh = h;
        while (w > dev->max_tex || h > dev->max_tex) w = w > 1 ? w / 2 : 1, h = h > 1 ? h / 2 : 1;
        unsigned char *small = malloc((size_t)w * h * texel);
        if (!small || !resample(img, ow, oh, small, w, h, is_float, srgb, edge)) {
            free(small);
            free(img);
            return sy_gli_fail(rep, SY_GL_ERROR_OUT_OF_MEMORY, "texture: out of memory while downscaling");
        }
        free(img);
        img = small;
        sy_gli_warn(dev, "raster: texture %ux%u exceeds the GL limit of %u texels per side; downscaled to %ux%u", ow, oh,
                    dev->max_tex, w, h);
    }
    sy_gl_result r = sy_gli_current(dev, rep);
    tex_o *t = r == SY_GL_OK ? sy_gli_pool_alloc(&dev->textures) : NULL;
    if (r == SY_GL_OK && !t) r = sy_gli_fail(rep, SY_GL_ERROR_OUT_OF_MEMORY, "texture: out of memory");
    if (r != SY_GL_OK) {
        free(img);
        return r;
    }
    const sy_gl_fns *gl = dev->gl;
    t->width = w;
    t->height = h;
    t->wrap_s = (uint8_t)((unsigned)d->wrap_s < 3u ? d->wrap_s : 0);
    t->wrap_t = (uint8_t)((unsigned)d->wrap_t < 3u ? d->wrap_t : 0);
    t->nearest = d->nearest ? 1 : 0;
    t->is_float = is_float ? 1 : 0;
    t->srgb = srgb ? 1 : 0;
    gl->GenTextures(1, &t->tex);
    gl->BindTexture(GL_TEXTURE_2D, t->tex);
    gl->PixelStorei(GL_UNPACK_ALIGNMENT, 1);
    static const GLint wraps[3] = {GL_REPEAT, GL_CLAMP_TO_EDGE, GL_MIRRORED_REPEAT};
    gl->TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, wraps[(unsigned)d->wrap_s < 3u ? d->wrap_s : 0]);
    gl->TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, wraps[(unsigned)d->wrap_t < 3u ? d->wrap_t : 0]);
    gl->TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, d->nearest ? GL_NEAREST : GL_LINEAR);
    gl->TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, d->nearest ? GL_NEAREST_MIPMAP_LINEAR : GL_LINEAR_MIPMAP_LINEAR);
    r = upload_levels(dev, img, w, h, is_float, srgb, edge, rep);
    free(img);
    dev->counts.texture_uploads++;
    if (r == SY_GL_OK) r = sy_gli_gl_check(dev, "texture upload", rep);
    if (r != SY_GL_OK) {
        sy_gl_texture_destroy(dev, (sy_gl_texture){t->h.id});
        return r;
    }
    out->id = t->h.id;
    return SY_GL_OK;
}

sy_gl_result sy_gl_texture_destroy(sy_gl_device *dev, sy_gl_texture tex)
{
    tex_o *t = sy_gli_pool_get(&dev->textures, tex.id);
    if (!t) return sy_gli_fail(dev->report, SY_GL_ERROR_INVALID_HANDLE, "%s: stale handle 0x%08x", __func__, tex.id);
    if (sy_gli_current(dev, NULL) == SY_GL_OK) dev->gl->DeleteTextures(1, &t->tex);
    sy_gli_pool_free(&dev->textures, t);
    if (tex.id == dev->env_tex.id) { /* the environment is gone: no environment light */
        dev->env_tex.id = 0;
        dev->env_dirty = true;
    }
    return SY_GL_OK;
}

/* >>kinds: the create / update / destroy frame that materials and lights share: its name in
 * messages, its pool (offsetof(sy_gl_device, ...)), its description's check, whether its calls
 * need the device's GL context current, set (stores a checked description; fresh: a new object) and
 * drop (before the object's slot is freed). */
typedef struct gl_kind {
    const char *what;
    size_t pool;
    sy_gl_result (*check)(const void *d, sy_gl_report *rep);
    bool context;
    void (*set)(sy_gl_device *dev, void *item, const void *d, bool fresh);
    void (*drop)(sy_gl_device *dev, void *item);
} gl_kind;

static pool *kind_pool(sy_gl_device *dev, const gl_kind *k)
{
    return (pool *)((char *)dev + k->pool);
}

/* The checks that create and update make before they change anything. */
static sy_gl_result kind_check(sy_gl_device *dev, const gl_kind *k, const void *d, sy_gl_report *rep)
{
    sy_gl_result r = k->check(d, rep);
    if (r == SY_GL_OK && k->context) r = sy_gli_current(dev, rep);
    return r;
}

static sy_gl_result kind_create(sy_gl_device *dev, const gl_kind *k, const void *d, uint32_t *id)
{
    sy_gl_report *rep = dev ? dev->report : NULL;
    *id = 0;
    if (!dev) return sy_gli_fail(NULL, SY_GL_ERROR_INVALID_ARGUMENT, "%s: no device", k->what);
    sy_gl_result r = kind_check(dev, k, d, rep);
    if (r != SY_GL_OK) return r;
    slot_head *h = sy_gli_pool_alloc(kind_pool(dev, k));
    if (!h) return sy_gli_fail(rep, SY_GL_ERROR_OUT_OF_MEMORY, "%s: out of memory", k->what);
    k->set(dev, h, d, true);
    *id = h->id;
    return SY_GL_OK;
}

static sy_gl_result kind_update(sy_gl_device *dev, const gl_kind *k, uint32_t id, const void *d)
{
    sy_gl_report *rep = dev ? dev->report : NULL;
    void *item = dev ? sy_gli_pool_get(kind_pool(dev, k), id) : NULL;
    if (!item) return sy_gli_fail(rep, SY_GL_ERROR_INVALID_HANDLE, "%s update: stale handle %u", k->what, id);
    sy_gl_result r = kind_check(dev, k, d, rep);
    if (r != SY_GL_OK) return r;
    k->set(dev, item, d, false);
    return SY_GL_OK;
}

static sy_gl_result kind_destroy(sy_gl_device *dev, const gl_kind *k, uint32_t id)
{
    void *item = dev ? sy_gli_pool_get(kind_pool(dev, k), id) : NULL;
    if (!item) return sy_gli_fail(dev ? dev->report : NULL, SY_GL_ERROR_INVALID_HANDLE, "sy_gl_%s_destroy: stale handle 0x%08x", k->what, id);
    k->drop(dev, item);
    sy_gli_pool_free(kind_pool(dev, k), item);
    return SY_GL_OK;
}

/* The public calls sy_gl.h declares for kind K: sy_gl_NAME_create / _update / _destroy, each the
 * frame above. */
#define KIND_CALLS(NAME, K)                                                                                            \
    sy_gl_result sy_gl_##NAME##_create(sy_gl_device *dev, const sy_gl_##NAME##_desc *d, sy_gl_##NAME *out)             \
    { return kind_create(dev, &(K), d, &out->id); }                                                                    \
    sy_gl_result sy_gl_##NAME##_update(sy_gl_device *dev, sy_gl_##NAME h, const sy_gl_##NAME##_desc *d)                \
    { return kind_update(dev, &(K), h.id, d); }                                                                        \
    sy_gl_result sy_gl_##NAME##_destroy(sy_gl_device *dev, sy_gl_##NAME h) { return kind_destroy(dev, &(K), h.id); }

/* >>material */
void sy_gl_material_desc_init(sy_gl_material_desc *d)
{
    memset(d, 0, sizeof *d);
    for (int i = 0; i < 4; ++i) d->base_color[i] = 1.0f;
    d->metallic = d->roughness = 1.0f;
    d->normal_scale = 1.0f;
    d->occlusion_strength = 1.0f;
    d->specular = 1.0f;
    d->ior = 1.5f;
    d->alpha_cutoff = 0.5f;
    for (int i = 0; i < 3; ++i) d->specular_color[i] = d->attenuation_color[i] = 1.0f;
    d->clearcoat_normal_scale = 1.0f;
    d->iridescence_ior = 1.3f;
    d->iridescence_thickness[0] = 100.0f;
    d->iridescence_thickness[1] = 400.0f;
}

static sy_gl_result material_check(const sy_gl_material_desc *d, sy_gl_report *rep)
{
    const float *v[] = {d->base_color, d->base_color + 1, d->base_color + 2, d->base_color + 3, &d->metallic,
                        &d->roughness, d->emissive, d->emissive + 1, d->emissive + 2, &d->normal_scale,
                        &d->occlusion_strength, &d->specular, &d->transmission, &d->ior, &d->alpha_cutoff,
                        d->specular_color, d->specular_color + 1, d->specular_color + 2, &d->clearcoat,
                        &d->clearcoat_roughness, d->sheen_color, d->sheen_color + 1, d->sheen_color + 2,
                        &d->sheen_roughness, &d->thickness, &d->attenuation_distance, d->attenuation_color,
                        d->attenuation_color + 1, d->attenuation_color + 2, &d->clearcoat_normal_scale,
                        &d->anisotropy, &d->anisotropy_rotation, &d->iridescence, &d->iridescence_ior,
                        d->iridescence_thickness, d->iridescence_thickness + 1};
    for (size_t i = 0; i < sizeof v / sizeof v[0]; ++i)
        if (!isfinite(*v[i])) return sy_gli_fail(rep, SY_GL_ERROR_INVALID_ARGUMENT, "material: parameter %zu is not finite", i);
    if ((unsigned)d->alpha_mode > 2u)
        return sy_gli_fail(rep, SY_GL_ERROR_INVALID_ARGUMENT, "material: unknown alpha mode %d", (int)d->alpha_mode);
    const sy_gl_texture_ref *refs[STANDINS];
    sy_gli_material_refs(d, refs);
    for (int i = 0; i < STANDINS; ++i)
        for (int k = 0; refs[i]->transformed && k < 6; ++k)
            if (!isfinite(refs[i]->transform[k]))
                return sy_gli_fail(rep, SY_GL_ERROR_INVALID_ARGUMENT, "material: texture %d transform[%d] is not finite", i, k);
    return SY_GL_OK;
}

static void material_upload(sy_gl_device *dev, mat_o *m, bool create)
{
    mat_block b;
    sy_gli_material_block(dev, &m->d, &b);
    const sy_gl_fns *gl = dev->gl;
    gl->BindBuffer(GL_UNIFORM_BUFFER, m->ubo);
    if (create) gl->BufferData(GL_UNIFORM_BUFFER, sizeof b, &b, GL_DYNAMIC_DRAW);
    else gl->BufferSubData(GL_UNIFORM_BUFFER, 0, sizeof b, &b);
    sy_gli_count_buffer(dev, true, sizeof b);
    if (!dev->forward) sy_gli_mtab_set(dev, m->h.id & IDX_MASK, &m->d); /* beyond the table: shaded forward */
}

static sy_gl_result material_check_any(const void *d, sy_gl_report *rep)
{
    return material_check(d, rep);
}

/* A new material gets its uniform buffer; a changed one marks the shadow casters when what casts
 * changed, and the probes (what they see changed). */
static void material_set(sy_gl_device *dev, void *item, const void *desc, bool fresh)
{
    mat_o *m = item;
    const sy_gl_material_desc *d = desc;
    if (fresh) {
        m->d = *d;
        dev->gl->GenBuffers(1, &m->ubo);
        material_upload(dev, m, true);
        return;
    }
    bool shadows = sy_gli_caster_kind(&m->d) != sy_gli_caster_kind(d) || m->d.alpha_mode != SY_GL_ALPHA_OPAQUE ||
                   memcmp(m->d.emissive, d->emissive, sizeof d->emissive) != 0;
    m->d = *d;
    material_upload(dev, m, false);
    if (shadows) sy_gli_geometry_changed(dev); /* shadow casters changed */
    dev->probes_dirty = true;              /* what the probes see changed */
}

static void material_drop(sy_gl_device *dev, void *item)
{
    if (sy_gli_current(dev, NULL) == SY_GL_OK) dev->gl->DeleteBuffers(1, &((mat_o *)item)->ubo);
}

static const gl_kind material_kind = {"material", offsetof(sy_gl_device, materials), material_check_any, true,
                                      material_set, material_drop};

KIND_CALLS(material, material_kind)

/* The normal matrix of an upper 3x3 whose float inverse under- or overflows (a scale of 1e-30):
 * the transposed inverse up to a positive factor, i.e. the cofactor matrix times the sign of the
 * determinant, divided by its largest element (normals are normalised after it). false when the
 * 3x3 is singular relative to its size (|det| <= 1e-30 s^3), as sy_mat4_is_degenerate in core. */
static bool normal_mat_scaled(const float *t, float *nm)
{
    double a[3][3], s = 0.0; /* a[r][c] */
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) a[r][c] = t[c * 4 + r], s = fmax(s, fabs(a[r][c]));
    double C[3][3], big = 0.0; /* C[r][c]: cofactor of a[r][c] */
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) {
            int r1 = (r + 1) % 3, r2 = (r + 2) % 3, c1 = (c + 1) % 3, c2 = (c + 2) % 3;
            C[r][c] = a[r1][c1] * a[r2][c2] - a[r1][c2] * a[r2][c1];
            big = fmax(big, fabs(C[r][c]));
        }
    double det = a[0][0] * C[0][0] + a[0][1] * C[0][1] + a[0][2] * C[0][2];
    if (!(s > 0.0) || !(fabs(det) > 1e-30 * s * s * s) || !(big > 0.0)) return false;
    double k = (det < 0.0 ? -1.0 : 1.0) / big;
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) nm[c * 3 + r] = (float)(C[r][c] * k); /* inverse transpose = C / det */
    return true;
}

static bool set_model(inst_o *in, const float *t)
{
    float inv[16];
    for (int i = 0; i < 16; ++i)
        if (!isfinite(t[i])) return false;
    if (!sy_gli_m4_invert(t, inv)) {
        float nm[9];
        if (!normal_mat_scaled(t, nm)) return false;
        memcpy(in->model, t, sizeof in->model);
        memcpy(in->normal_mat, nm, sizeof nm);
        /* det(nm) has the sign of det(t): the adjugate's determinant is det(t)^2 */
        in->mirror = nm[0] * (nm[4] * nm[8] - nm[7] * nm[5]) - nm[3] * (nm[1] * nm[8] - nm[7] * nm[2]) +
                         nm[6] * (nm[1] * nm[5] - nm[4] * nm[2]) < 0.0f;
        return true;
    }
    memcpy(in->model, t, sizeof in->model);
    /* normal matrix = inverse transpose of the upper 3x3 */
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) in->normal_mat[c * 3 + r] = inv[r * 4 + c];
    float det = t[0] * (t[5] * t[10] - t[9] * t[6]) - t[4] * (t[1] * t[10] - t[9] * t[2]) + t[8] * (t[1] * t[6] - t[5] * t[2]);
    in->mirror = det < 0.0f;
    return true;
}

sy_gl_result sy_gl_instance_create(sy_gl_device *dev, const sy_gl_instance_desc *d, sy_gl_instance *out)
{
    sy_gl_report *rep = dev ? dev->report : NULL;
    out->id = 0;
    if (!sy_gli_pool_get(&dev->meshes, d->mesh.id))
        return sy_gli_fail(rep, SY_GL_ERROR_INVALID_HANDLE, "instance: mesh handle %u is stale", d->mesh.id);
    inst_o tmp;
    if (!set_model(&tmp, d->transform))
        return sy_gli_fail(rep, SY_GL_ERROR_INVALID_ARGUMENT, "instance: transform is not finite and invertible");
    inst_o *in = sy_gli_pool_alloc(&dev->instances);
    if (!in) return sy_gli_fail(rep, SY_GL_ERROR_OUT_OF_MEMORY, "instance: out of memory");
    set_model(in, d->transform);
    in->mesh = d->mesh;
    in->material = d->material;
    in->visible = !d->hidden;
    dev->counts.model_matrix_updates++;
    sy_gli_geometry_changed(dev);
    out->id = in->h.id;
    return SY_GL_OK;
}

sy_gl_result sy_gl_instance_set_transform(sy_gl_device *dev, sy_gl_instance inst, const float t[16])
{
    sy_gl_report *rep = dev ? dev->report : NULL;
    inst_o *in = sy_gli_pool_get(&dev->instances, inst.id);
    if (!in) return sy_gli_fail(rep, SY_GL_ERROR_INVALID_HANDLE, "instance transform: stale handle %u", inst.id);
    if (!set_model(in, t))
        return sy_gli_fail(rep, SY_GL_ERROR_INVALID_ARGUMENT, "instance transform: not finite and invertible");
    dev->counts.model_matrix_updates++;
    sy_gli_geometry_changed(dev);
    return SY_GL_OK;
}

sy_gl_result sy_gl_instance_set_material(sy_gl_device *dev, sy_gl_instance inst, sy_gl_material mat)
{
    inst_o *in = sy_gli_pool_get(&dev->instances, inst.id);
    if (!in) return sy_gli_fail(dev->report, SY_GL_ERROR_INVALID_HANDLE, "%s: stale handle 0x%08x", __func__, inst.id);
    if (in->material.id != mat.id) sy_gli_geometry_changed(dev); /* shadow casters and probes */
    in->material = mat;
    return SY_GL_OK;
}

sy_gl_result sy_gl_instance_set_visible(sy_gl_device *dev, sy_gl_instance inst, bool visible)
{
    inst_o *in = sy_gli_pool_get(&dev->instances, inst.id);
    if (!in) return sy_gli_fail(dev->report, SY_GL_ERROR_INVALID_HANDLE, "%s: stale handle 0x%08x", __func__, inst.id);
    if (in->visible != visible) sy_gli_geometry_changed(dev);
    in->visible = visible;
    return SY_GL_OK;
}

sy_gl_result sy_gl_instance_destroy(sy_gl_device *dev, sy_gl_instance inst)
{
    inst_o *in = sy_gli_pool_get(&dev->instances, inst.id);
    if (!in) return sy_gli_fail(dev->report, SY_GL_ERROR_INVALID_HANDLE, "%s: stale handle 0x%08x", __func__, inst.id);
    sy_gli_pool_free(&dev->instances, in);
    sy_gli_geometry_changed(dev);
    return SY_GL_OK;
}

static sy_gl_result light_check(const sy_gl_light_desc *d, sy_gl_report *rep)
{
    if (d->type != SY_GL_LIGHT_POINT && d->type != SY_GL_LIGHT_SPOT && d->type != SY_GL_LIGHT_DIRECTIONAL)
        return sy_gli_fail(rep, SY_GL_ERROR_INVALID_ARGUMENT, "light: unknown type %d", (int)d->type);
    const float *v[] = {d->color, d->color + 1, d->color + 2, &d->intensity, d->position, d->position + 1,
                        d->position + 2, d->direction, d->direction + 1, d->direction + 2, &d->range,
                        &d->inner_cone_angle, &d->outer_cone_angle};
    for (size_t i = 0; i < sizeof v / sizeof v[0]; ++i)
        if (!isfinite(*v[i])) return sy_gli_fail(rep, SY_GL_ERROR_INVALID_ARGUMENT, "light: parameter %zu is not finite", i);
    if (d->type != SY_GL_LIGHT_POINT && !(fabsf(d->direction[0]) + fabsf(d->direction[1]) + fabsf(d->direction[2]) > 0.0f))
        return sy_gli_fail(rep, SY_GL_ERROR_INVALID_ARGUMENT, "light: zero direction");
    return SY_GL_OK;
}

static sy_gl_result light_check_any(const void *d, sy_gl_report *rep)
{
    return light_check(d, rep);
}

/* A new, changed or destroyed light: the Lights block is written again before the next frame. */
static void light_set(sy_gl_device *dev, void *item, const void *d, bool fresh)
{
    (void)fresh;
    ((light_o *)item)->d = *(const sy_gl_light_desc *)d;
    dev->lights_dirty = true;
}

static void light_drop(sy_gl_device *dev, void *item)
{
    (void)item;
    dev->lights_dirty = true;
}

static const gl_kind light_kind = {"light", offsetof(sy_gl_device, lights), light_check_any, false, light_set, light_drop};

KIND_CALLS(light, light_kind)

void sy_gl_set_background(sy_gl_device *dev, sy_gl_background_mode mode, const float color[4], sy_gl_texture texture,
                          float intensity)
{
    if ((unsigned)mode > (unsigned)SY_GL_BACKGROUND_TEXTURE) {
        sy_gli_warn(dev, "raster: unknown background mode %d; using a transparent background", (int)mode);
        mode = SY_GL_BACKGROUND_NONE;
    }
    float c[4] = {0, 0, 0, 0};
    if (mode == SY_GL_BACKGROUND_COLOR && color)
        for (int i = 0; i < 4; ++i) {
            c[i] = color[i];
            if (!isfinite(c[i]) || c[i] < 0.0f) {
                sy_gli_warn(dev, "raster: background colour component %d (%g) is not a finite non-negative value; using 0", i,
                     (double)c[i]);
                c[i] = 0.0f;
            }
        }
    if (!isfinite(intensity) || intensity < 0.0f) {
        sy_gli_warn(dev, "raster: background intensity %g is not a finite non-negative value; using 0", (double)intensity);
        intensity = 0.0f;
    }
    dev->bg_mode = mode;
    memcpy(dev->bg_color, c, sizeof c);
    dev->bg_tex = mode == SY_GL_BACKGROUND_TEXTURE ? texture : (sy_gl_texture){0};
    dev->bg_intensity = intensity;
}

void sy_gl_set_environment(sy_gl_device *dev, sy_gl_texture texture, float intensity)
{
    if (!isfinite(intensity) || intensity < 0.0f) {
        sy_gli_warn(dev, "raster: environment intensity %g is not a finite non-negative value; using 0", (double)intensity);
        intensity = 0.0f;
    }
    if (intensity == 0.0f) texture.id = 0;
    if (texture.id == dev->env_tex.id && intensity == dev->env_intensity && (texture.id != 0) == dev->env_ready) return;
    dev->env_tex = texture;
    dev->env_intensity = intensity;
    dev->env_dirty = true;
}

void sy_gl_set_ambient(sy_gl_device *dev, const float radiance[3])
{
    float a[3];
    for (int c = 0; c < 3; ++c) {
        a[c] = radiance[c];
        if (!isfinite(a[c]) || a[c] < 0.0f) {
            sy_gli_warn(dev, "raster: ambient radiance[%d] = %g is not a finite non-negative value; using 0", c, (double)a[c]);
            a[c] = 0.0f;
        }
    }
    if (memcmp(a, dev->ambient, sizeof a)) {
        memcpy(dev->ambient, a, sizeof a);
        dev->lights_dirty = true;
    }
}

sy_gl_result sy_gl_set_area_lights(sy_gl_device *dev, const sy_gl_area_light *lights, uint32_t count)
{
    sy_gl_report *rep = dev ? dev->report : NULL;
    if (count > SY_GL_MAX_AREA_LIGHTS)
        return sy_gli_fail(rep, SY_GL_ERROR_LIMIT, "area lights: %u exceed the limit of %d", count, SY_GL_MAX_AREA_LIGHTS);
    if (count && !lights) return sy_gli_fail(rep, SY_GL_ERROR_INVALID_ARGUMENT, "area lights: NULL array");
    for (uint32_t i = 0; i < count; ++i) {
        const sy_gl_area_light *a = &lights[i];
        if (a->vertex_count != 3 && a->vertex_count != 4)
            return sy_gli_fail(rep, SY_GL_ERROR_INVALID_ARGUMENT, "area light %u: %u vertices (3 or 4 expected)", i,
                        a->vertex_count);
        for (uint32_t k = 0; k < a->vertex_count; ++k)
            for (int c = 0; c < 3; ++c)
                if (!isfinite(a->vertices[k][c]))
                    return sy_gli_fail(rep, SY_GL_ERROR_INVALID_ARGUMENT, "area light %u: vertex %u is not finite", i, k);
        for (int c = 0; c < 3; ++c)
            if (!isfinite(a->radiance[c]) || a->radiance[c] < 0.0f)
                return sy_gli_fail(rep, SY_GL_ERROR_INVALID_ARGUMENT,
                            "area light %u: radiance[%d] = %g is not a finite non-negative value", i, c, (double)a->radiance[c]);
    }
    if (count == dev->area_count && (!count || !memcmp(dev->areas, lights, count * sizeof *lights))) return SY_GL_OK;
    if (count) memcpy(dev->areas, lights, count * sizeof *lights);
    dev->area_count = count;
    dev->areas_dirty = true;
    dev->lights_dirty = true;
    return SY_GL_OK;
}
