/* sy_plant.c — the generated plant of the culling benchmark and tests (see sy_plant.h): prototype
 * meshes (cylinders, domes, boxes, tori) built once per kind / variant / material, one node per
 * object with a scaled, rotated placement inside its unit cell. */
#include "sy_plant.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PLANT_SLOTS 25u
#define PLANT_VARIANTS 4u
#define PLANT_CELL 24.0f
#define PLANT_PI 3.14159265358979f

/* >>kinds */
enum { K_TANK, K_VESSEL, K_PIPE, K_COLUMN, K_BOX, K_TORUS, K_COUNT };
enum { M_TANK, M_VESSEL, M_PIPE_Y, M_PIPE_G, M_PIPE_R, M_PIPE_B, M_CONCRETE, M_STEEL, M_VALVE, M_COUNT };

/* Tessellation of a kind at detail d and variant factor f: segments around, rings along. */
typedef struct tess {
    uint32_t seg, rings, dome;
} tess;

static uint32_t clampu(double v, uint32_t lo, uint32_t hi)
{
    if (!(v > lo)) return lo;
    if (v > hi) return hi;
    return (uint32_t)lround(v);
}

static const float variant_factor[PLANT_VARIANTS] = {0.6f, 0.85f, 1.15f, 1.4f};

static tess tess_of(int kind, double d, uint32_t variant)
{
    double f = d * variant_factor[variant];
    switch (kind) {
    case K_TANK: return (tess){clampu(48 * f, 6, 4096), clampu(12 * f, 1, 4096), clampu(8 * f, 2, 2048)};
    case K_VESSEL: return (tess){clampu(32 * f, 6, 4096), clampu(10 * f, 1, 4096), clampu(6 * f, 2, 2048)};
    case K_PIPE: return (tess){clampu(16 * f, 4, 4096), clampu(8 * f, 1, 4096), 0};
    case K_COLUMN: return (tess){clampu(12 * f, 4, 4096), clampu(2 * f, 1, 4096), 0};
    case K_TORUS: return (tess){clampu(24 * f, 4, 4096), clampu(8 * f, 3, 4096), 0};
    default: return (tess){0, 0, 0};
    }
}

/* Triangles of a prototype (must match build_mesh). */
static uint64_t tris_of(int kind, tess t)
{
    uint64_t s = t.seg, r = t.rings, dm = t.dome;
    switch (kind) {
    case K_TANK: return 2 * s * r + (2 * s * (dm - 1) + s) + s; /* side, dome, bottom cap */
    case K_VESSEL: return 2 * s * r + 2 * (2 * s * (dm - 1) + s);
    case K_PIPE: return 2 * s * r + 2 * (2 * s + 2 * 2 * s); /* tube + two flanges (outer side, two faces) */
    case K_COLUMN: return 2 * s * r + 2 * s;
    case K_BOX: return 12;
    case K_TORUS: return 2 * s * r;
    default: return 0;
    }
}

/* One slot of a unit: kind, material, and a placement function's selector. */
typedef struct slot_def {
    int kind, material;
} slot_def;
static const slot_def slots[PLANT_SLOTS] = {
    {K_TANK, M_TANK},     {K_TANK, M_TANK},     {K_VESSEL, M_VESSEL}, {K_VESSEL, M_VESSEL}, {K_BOX, M_CONCRETE},
    {K_BOX, M_CONCRETE},  {K_BOX, M_STEEL},     {K_BOX, M_CONCRETE},  {K_PIPE, M_PIPE_Y},   {K_PIPE, M_PIPE_G},
    {K_PIPE, M_PIPE_R},   {K_PIPE, M_PIPE_B},   {K_PIPE, M_PIPE_Y},   {K_PIPE, M_PIPE_G},   {K_PIPE, M_PIPE_R},
    {K_PIPE, M_PIPE_B},   {K_PIPE, M_PIPE_Y},   {K_PIPE, M_PIPE_G},   {K_COLUMN, M_STEEL},  {K_COLUMN, M_STEEL},
    {K_COLUMN, M_STEEL},  {K_COLUMN, M_STEEL},  {K_TORUS, M_VALVE},   {K_TORUS, M_VALVE},   {K_TORUS, M_VALVE},
};

static uint32_t hash32(uint32_t x)
{
    x ^= x >> 16, x *= 0x7feb352du, x ^= x >> 15, x *= 0x846ca68bu, x ^= x >> 16;
    return x;
}
/* A uniform value in [0, 1) for object i, channel c. */
static float jitter(uint32_t seed, uint32_t i, uint32_t c)
{
    return (float)(hash32(seed * 0x9e3779b9u ^ hash32(i * 8u + c)) >> 8) / 16777216.0f;
}

/* >>mesh building */
typedef struct mbuf {
    float *pos, *nrm;
    uint32_t *idx;
    uint32_t nv, ni, cap_v, cap_i;
    bool failed;
} mbuf;

static uint32_t mb_vertex(mbuf *b, float x, float y, float z, float nx, float ny, float nz)
{
    if (b->nv == b->cap_v) {
        uint32_t nc = b->cap_v ? b->cap_v * 2 : 256;
        float *p = realloc(b->pos, sizeof(float) * 3 * nc), *n = p ? realloc(b->nrm, sizeof(float) * 3 * nc) : NULL;
        if (p) b->pos = p;
        if (n) b->nrm = n;
        if (!p || !n) {
            b->failed = true;
            return 0;
        }
        b->cap_v = nc;
    }
    float l = sqrtf(nx * nx + ny * ny + nz * nz);
    if (l > 0) nx /= l, ny /= l, nz /= l;
    float *p = b->pos + 3 * b->nv, *n = b->nrm + 3 * b->nv;
    p[0] = x, p[1] = y, p[2] = z, n[0] = nx, n[1] = ny, n[2] = nz;
    return b->nv++;
}

static void mb_tri(mbuf *b, uint32_t a, uint32_t c, uint32_t d)
{
    if (b->failed) return;
    if (b->ni + 3 > b->cap_i) {
        uint32_t nc = b->cap_i ? b->cap_i * 2 : 768;
        uint32_t *i = realloc(b->idx, sizeof(uint32_t) * nc);
        if (!i) {
            b->failed = true;
            return;
        }
        b->idx = i, b->cap_i = nc;
    }
    b->idx[b->ni++] = a, b->idx[b->ni++] = c, b->idx[b->ni++] = d;
}

/* A grid of (seg + 1) x (rings + 1) vertices from f(u, v) (counter-clockwise seen from outside when
 * u runs around +Y counter-clockwise seen from above and v runs up). */
typedef void (*surf_fn)(float u, float v, const float *prm, float p[3], float n[3]);
static void mb_surface(mbuf *b, uint32_t seg, uint32_t rings, surf_fn f, const float *prm)
{
    uint32_t base = b->nv;
    for (uint32_t j = 0; j <= rings; ++j)
        for (uint32_t i = 0; i <= seg; ++i) {
            float p[3], n[3];
            f((float)i / (float)seg, (float)j / (float)rings, prm, p, n);
            mb_vertex(b, p[0], p[1], p[2], n[0], n[1], n[2]);
        }
    for (uint32_t j = 0; j < rings; ++j)
        for (uint32_t i = 0; i < seg; ++i) {
            uint32_t a = base + j * (seg + 1) + i, c = a + seg + 1;
            mb_tri(b, a, a + 1, c);
            mb_tri(b, a + 1, c + 1, c);
        }
}

/* prm: radius, y0, y1 */
static void surf_cyl(float u, float v, const float *prm, float p[3], float n[3])
{
    float a = 2 * PLANT_PI * u, c = cosf(a), s = sinf(a);
    p[0] = prm[0] * c, p[1] = prm[1] + (prm[2] - prm[1]) * v, p[2] = -prm[0] * s;
    n[0] = c, n[1] = 0, n[2] = -s;
}

/* A disc at height y, radius r, facing up (up > 0) or down. */
static void mb_disc(mbuf *b, uint32_t seg, float r0, float r1, float y, float up)
{
    uint32_t base = b->nv;
    for (uint32_t i = 0; i <= seg; ++i) {
        float a = 2 * PLANT_PI * (float)i / (float)seg, c = cosf(a), s = sinf(a);
        mb_vertex(b, r1 * c, y, -r1 * s, 0, up, 0);
        if (r0 > 0) mb_vertex(b, r0 * c, y, -r0 * s, 0, up, 0);
    }
    if (r0 > 0) { /* annulus: 2 triangles per segment */
        for (uint32_t i = 0; i < seg; ++i) {
            uint32_t o = base + 2 * i, in = o + 1, o2 = o + 2, in2 = o + 3;
            if (up > 0) mb_tri(b, in, o, o2), mb_tri(b, in, o2, in2);
            else mb_tri(b, in, o2, o), mb_tri(b, in, in2, o2);
        }
    } else { /* fan around a centre vertex */
        uint32_t c = mb_vertex(b, 0, y, 0, 0, up, 0);
        for (uint32_t i = 0; i < seg; ++i) {
            if (up > 0) mb_tri(b, c, base + i, base + i + 1);
            else mb_tri(b, c, base + i + 1, base + i);
        }
    }
}

/* A dome of radius 1 (xz) and height h above y0 (h < 0: below), rings rings; the pole is a fan. */
static void mb_dome(mbuf *b, uint32_t seg, uint32_t rings, float y0, float h)
{
    uint32_t base = b->nv;
    for (uint32_t j = 0; j < rings; ++j) {
        float t = 0.5f * PLANT_PI * (float)j / (float)rings, cr = cosf(t), sr = sinf(t);
        for (uint32_t i = 0; i <= seg; ++i) {
            float a = 2 * PLANT_PI * (float)i / (float)seg, c = cosf(a), s = sinf(a);
            /* ellipsoid normal: (x, y / h^2, z) scaled */
            mb_vertex(b, cr * c, y0 + h * sr, -cr * s, cr * c, sr / h, -cr * s);
        }
    }
    uint32_t pole = mb_vertex(b, 0, y0 + h, 0, 0, h > 0 ? 1.0f : -1.0f, 0);
    for (uint32_t j = 0; j + 1 < rings; ++j)
        for (uint32_t i = 0; i < seg; ++i) {
            uint32_t a = base + j * (seg + 1) + i, c = a + seg + 1;
            if (h > 0) mb_tri(b, a, a + 1, c), mb_tri(b, a + 1, c + 1, c);
            else mb_tri(b, a, c, a + 1), mb_tri(b, a + 1, c, c + 1);
        }
    uint32_t last = base + (rings - 1) * (seg + 1);
    for (uint32_t i = 0; i < seg; ++i) {
        if (h > 0) mb_tri(b, last + i, last + i + 1, pole);
        else mb_tri(b, last + i, pole, last + i + 1);
    }
}

static void mb_box(mbuf *b)
{
    static const float nrm[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (int f = 0; f < 6; ++f) {
        const float *n = nrm[f];
        /* two tangent axes u, v with u x v = n */
        float u[3] = {n[1] != 0 ? 1.0f : 0.0f, 0, n[1] != 0 ? 0.0f : 1.0f}, v[3];
        if (n[0] != 0) u[0] = 0, u[1] = 0, u[2] = -n[0];
        if (n[2] != 0) u[0] = n[2], u[1] = 0, u[2] = 0;
        if (n[1] != 0) u[0] = 1, u[1] = 0, u[2] = 0;
        v[0] = n[1] * u[2] - n[2] * u[1], v[1] = n[2] * u[0] - n[0] * u[2], v[2] = n[0] * u[1] - n[1] * u[0];
        uint32_t base = b->nv;
        for (int k = 0; k < 4; ++k) {
            float su = (k == 1 || k == 2) ? 0.5f : -0.5f, sv = k >= 2 ? 0.5f : -0.5f;
            float p[3];
            for (int a = 0; a < 3; ++a) p[a] = 0.5f * n[a] + su * u[a] + sv * v[a];
            mb_vertex(b, p[0], p[1] + 0.5f, p[2], n[0], n[1], n[2]);
        }
        mb_tri(b, base, base + 1, base + 2);
        mb_tri(b, base, base + 2, base + 3);
    }
}

/* prm: major radius R, minor radius r */
static void surf_torus(float u, float v, const float *prm, float p[3], float n[3])
{
    float a = 2 * PLANT_PI * u, t = 2 * PLANT_PI * v, ca = cosf(a), sa = sinf(a), ct = cosf(t), st = sinf(t);
    n[0] = ct * ca, n[1] = st, n[2] = -ct * sa;
    p[0] = (prm[0] + prm[1] * ct) * ca, p[1] = prm[1] * st, p[2] = -(prm[0] + prm[1] * ct) * sa;
}

/* Unit prototypes (y up, base at y = 0): see sy_plant.h for how nodes scale them. */
static void build_mesh(mbuf *b, int kind, tess t)
{
    switch (kind) {
    case K_TANK: { /* cylinder 0..0.85, dome 0.85..1, bottom disc */
        float prm[3] = {1, 0, 0.85f};
        mb_surface(b, t.seg, t.rings, surf_cyl, prm);
        mb_dome(b, t.seg, t.dome, 0.85f, 0.15f);
        mb_disc(b, t.seg, 0, 1, 0, -1);
        break;
    }
    case K_VESSEL: { /* capsule along y: domes 0..0.12 and 0.88..1 */
        float prm[3] = {1, 0.12f, 0.88f};
        mb_surface(b, t.seg, t.rings, surf_cyl, prm);
        mb_dome(b, t.seg, t.dome, 0.88f, 0.12f);
        mb_dome(b, t.seg, t.dome, 0.12f, -0.12f);
        break;
    }
    case K_PIPE: { /* tube radius 1 along y, flanges radius 1.6 at both ends */
        float prm[3] = {1, 0, 1}, f0[3] = {1.6f, 0, 0.015f}, f1[3] = {1.6f, 0.985f, 1};
        mb_surface(b, t.seg, t.rings, surf_cyl, prm);
        mb_surface(b, t.seg, 1, surf_cyl, f0);
        mb_disc(b, t.seg, 1, 1.6f, 0, -1);
        mb_disc(b, t.seg, 1, 1.6f, 0.015f, 1);
        mb_surface(b, t.seg, 1, surf_cyl, f1);
        mb_disc(b, t.seg, 1, 1.6f, 0.985f, -1);
        mb_disc(b, t.seg, 1, 1.6f, 1, 1);
        break;
    }
    case K_COLUMN: {
        float prm[3] = {1, 0, 1};
        mb_surface(b, t.seg, t.rings, surf_cyl, prm);
        mb_disc(b, t.seg, 0, 1, 1, 1);
        mb_disc(b, t.seg, 0, 1, 0, -1);
        break;
    }
    case K_BOX: mb_box(b); break;
    case K_TORUS: {
        float prm[2] = {1, 0.12f};
        mb_surface(b, t.seg, t.rings, surf_torus, prm);
        break;
    }
    }
}

/* >>placement: translation, rotation (quaternion), scale of object i in its unit */
typedef struct place {
    float t[3], q[4], s[3];
} place;

static place place_of(uint32_t seed, uint32_t i, uint32_t slot, float cx, float cz)
{
    place p = {{cx, 0, cz}, {0, 0, 0, 1}, {1, 1, 1}};
    float j0 = jitter(seed, i, 0), j1 = jitter(seed, i, 1);
    const float h = 0.70710678f; /* sin / cos of 45 degrees: quarter turns */
    switch (slot) {
    case 0: /* big tank */
        p.t[0] += 6, p.t[2] += 6;
        p.s[0] = p.s[2] = 3.0f + 1.2f * j0, p.s[1] = 10 + 6 * j1;
        break;
    case 1:
        p.t[0] -= 6, p.t[2] -= 6;
        p.s[0] = p.s[2] = 2.2f + 0.8f * j0, p.s[1] = 7 + 5 * j1;
        break;
    case 2: /* vessel along x: local +y -> +x (-90 degrees about z) */
        p.t[0] += -10, p.t[1] = 1.6f, p.t[2] += 6;
        p.q[2] = -h, p.q[3] = h;
        p.s[0] = p.s[2] = 1.1f + 0.4f * j0, p.s[1] = 7 + 2 * j1;
        break;
    case 3: /* vessel along z: local +y -> +z (90 degrees about x) */
        p.t[0] += 6, p.t[1] = 1.6f, p.t[2] += -10;
        p.q[0] = h, p.q[3] = h;
        p.s[0] = p.s[2] = 1.1f + 0.4f * j0, p.s[1] = 7 + 2 * j1;
        break;
    case 4: /* control building */
        p.s[0] = 6, p.s[1] = 4 + 5 * j0, p.s[2] = 5 + j1;
        break;
    case 5: /* pump base */
        p.t[0] -= 5, p.t[2] += 1;
        p.s[0] = 2, p.s[1] = 1.2f + j0, p.s[2] = 3;
        break;
    case 6: /* pump */
        p.t[0] += 5, p.t[2] -= 1;
        p.s[0] = 2.5f, p.s[1] = 1.5f + j0, p.s[2] = 2;
        break;
    case 7: /* shed */
        p.t[2] -= 1.5f, p.t[0] -= 1, p.t[2] += -5;
        p.s[0] = 4, p.s[1] = 2.5f + 2 * j0, p.s[2] = 3;
        break;
    default:
        if (slot >= 8 && slot < 13) { /* pipes along x at z = +10.2 .. +11.8, full cell length */
            uint32_t k = slot - 8;
            p.t[0] -= 0.5f * PLANT_CELL, p.t[1] = 3.0f + 1.1f * (float)k, p.t[2] += 10.2f + 0.4f * (float)k;
            p.q[2] = -h, p.q[3] = h;
            p.s[0] = p.s[2] = 0.12f + 0.18f * j0, p.s[1] = PLANT_CELL;
        } else if (slot >= 13 && slot < 18) { /* pipes along z at x = +10.2 .. +11.8 */
            uint32_t k = slot - 13;
            p.t[0] += 10.2f + 0.4f * (float)k, p.t[1] = 3.5f + 1.1f * (float)k, p.t[2] -= 0.5f * PLANT_CELL;
            p.q[0] = h, p.q[3] = h;
            p.s[0] = p.s[2] = 0.12f + 0.18f * j0, p.s[1] = PLANT_CELL;
        } else if (slot >= 18 && slot < 22) { /* rack columns */
            static const float xz[4][2] = {{11, 11}, {-1, 11}, {11, -1}, {11, -11}};
            p.t[0] += xz[slot - 18][0], p.t[2] += xz[slot - 18][1];
            p.s[0] = p.s[2] = 0.25f, p.s[1] = 9.5f;
        } else { /* valve wheels, upright (axis along x: 90 degrees about z) */
            static const float xyz[3][3] = {{-5, 2.6f, 1}, {5, 2.8f, -1}, {-10.5f, 1.6f, 9}};
            const float *o = xyz[slot - 22];
            p.t[0] += o[0], p.t[1] = o[1] + 0.5f * j0, p.t[2] += o[2];
            p.q[2] = h, p.q[3] = h;
            p.s[0] = p.s[1] = p.s[2] = 0.5f + 0.3f * j1;
        }
    }
    return p;
}

static uint32_t variant_of(uint32_t seed, uint32_t i)
{
    return hash32(i ^ (seed * 0x85ebca6bu)) % PLANT_VARIANTS;
}

/* Total triangles for detail d (objects counted per kind and variant). */
static uint64_t total_at(const uint64_t count[K_COUNT][PLANT_VARIANTS], double d)
{
    uint64_t t = 0;
    for (int k = 0; k < K_COUNT; ++k)
        for (uint32_t v = 0; v < PLANT_VARIANTS; ++v) t += count[k][v] * tris_of(k, tess_of(k, d, v));
    return t;
}

static sy_result make_materials(sy_scene *s, sy_material mats[M_COUNT], sy_error *err)
{
    static const struct {
        const char *name;
        float rgb[3], metallic, roughness, emissive[3];
    } defs[M_COUNT] = {
        {"tank", {0.82f, 0.82f, 0.78f}, 0.1f, 0.5f, {0, 0, 0}},
        {"vessel", {0.55f, 0.6f, 0.66f}, 0.6f, 0.4f, {0, 0, 0}},
        {"pipe yellow", {0.85f, 0.65f, 0.1f}, 0.0f, 0.6f, {0, 0, 0}},
        {"pipe green", {0.15f, 0.55f, 0.2f}, 0.0f, 0.6f, {0, 0, 0}},
        {"pipe red", {0.7f, 0.12f, 0.1f}, 0.0f, 0.6f, {0, 0, 0}},
        {"pipe blue", {0.12f, 0.3f, 0.75f}, 0.0f, 0.6f, {0, 0, 0}},
        {"concrete", {0.55f, 0.54f, 0.5f}, 0.0f, 0.9f, {0, 0, 0}},
        {"steel", {0.36f, 0.37f, 0.4f}, 0.9f, 0.35f, {0, 0, 0}},
        {"valve", {0.75f, 0.1f, 0.08f}, 0.2f, 0.5f, {0, 0, 0}},
    };
    sy_material_data md = *(const sy_material_data *)sy_object_defaults(SY_TYPE_MATERIAL);
    for (int m = 0; m < M_COUNT; ++m) {
        md.name = NULL;
        memcpy(md.base_color, defs[m].rgb, sizeof defs[m].rgb);
        md.base_color[3] = 1;
        md.metallic = defs[m].metallic, md.roughness = defs[m].roughness;
        memcpy(md.emissive, defs[m].emissive, sizeof md.emissive);
        sy_result r = sy_material_create(s, defs[m].name, &mats[m], err);
        if (r == SY_OK) r = sy_material_set(s, mats[m], &md, err);
        if (r != SY_OK) return r;
    }
    return SY_OK;
}

static const char *const kind_names[K_COUNT] = {"tank", "vessel", "pipe", "column", "box", "valve"};

/* The prototype mesh of (kind, variant, material), created on first use. */
static sy_result proto_mesh(sy_scene *s, int kind, uint32_t variant, int material, double d, const sy_material mats[M_COUNT],
                            sy_mesh *cache, uint32_t *meshes, sy_error *err)
{
    sy_mesh *slot = &cache[(kind * PLANT_VARIANTS + variant) * M_COUNT + material];
    if (slot->id) return SY_OK;
    mbuf b = {0};
    build_mesh(&b, kind, tess_of(kind, d, variant));
    if (b.failed) {
        free(b.pos), free(b.nrm), free(b.idx);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "plant: out of memory building a %s mesh", kind_names[kind]);
    }
    sy_blob *bp = NULL, *bn = NULL, *bi = NULL;
    sy_result r = sy_blob_create_copy(b.pos, sizeof(float) * 3 * b.nv, &bp, err);
    if (r == SY_OK) r = sy_blob_create_copy(b.nrm, sizeof(float) * 3 * b.nv, &bn, err);
    if (r == SY_OK) r = sy_blob_create_copy(b.idx, sizeof(uint32_t) * b.ni, &bi, err);
    free(b.pos), free(b.nrm), free(b.idx);
    char name[64];
    snprintf(name, sizeof name, "%s v%u m%d", kind_names[kind], variant, material);
    sy_primitive p = {.positions = bp, .normals = bn, .indices = bi, .material = mats[material]};
    if (r == SY_OK) r = sy_mesh_create(s, name, slot, err);
    if (r == SY_OK) r = sy_mesh_set_primitives(s, *slot, &p, 1, err);
    sy_blob_release(bp), sy_blob_release(bn), sy_blob_release(bi);
    if (r == SY_OK) (*meshes)++;
    return r;
}

sy_result sy_plant_generate(sy_scene *s, const sy_plant_desc *desc, sy_plant_info *out, sy_error *err)
{
    memset(out, 0, sizeof *out);
    uint64_t want = desc && desc->triangles ? desc->triangles : 10000000u;
    uint32_t n = desc && desc->objects ? desc->objects : 10000u, seed = desc ? desc->seed : 0;
    if (n > (1u << 22)) return sy_error_set(err, SY_ERR_LIMIT, "plant: %u objects exceed the limit %u", n, 1u << 22);
    if (want > (1ull << 34)) return sy_error_set(err, SY_ERR_LIMIT, "plant: %llu triangles exceed the limit 2^34", (unsigned long long)want);
    /* objects per kind and variant, then the detail factor whose total comes closest to want */
    uint64_t count[K_COUNT][PLANT_VARIANTS] = {{0}};
    for (uint32_t i = 0; i < n; ++i) count[slots[i % PLANT_SLOTS].kind][variant_of(seed, i)]++;
    double lo = 0.01, hi = 512;
    for (int it = 0; it < 60; ++it) {
        double mid = sqrt(lo * hi);
        if (total_at(count, mid) < want) lo = mid;
        else hi = mid;
    }
    uint64_t tlo = total_at(count, lo), thi = total_at(count, hi);
    double d = (want - (tlo < want ? tlo : want)) <= (thi > want ? thi - want : 0) ? lo : hi;

    uint32_t units = (n + PLANT_SLOTS - 1) / PLANT_SLOTS, grid = 1;
    while ((uint64_t)grid * grid < units) grid++;
    sy_material mats[M_COUNT];
    sy_mesh *cache = calloc((size_t)K_COUNT * PLANT_VARIANTS * M_COUNT, sizeof *cache);
    sy_node *nodes = malloc(sizeof *nodes * (n ? n : 1));
    sy_result r = cache && nodes ? SY_OK : sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "plant: out of memory for %u objects", n);
    if (r == SY_OK) r = make_materials(s, mats, err);
    if (r == SY_OK) r = sy_node_create(s, "plant", &out->root, err);
    if (r == SY_OK) r = sy_node_set_flags(s, out->root, SY_NODE_VISIBLE, err);
    out->bounds = sy_bounds_empty();
    float half = 0.5f * PLANT_CELL * (float)(grid - 1);
    for (uint32_t i = 0; r == SY_OK && i < n; ++i) {
        uint32_t u = i / PLANT_SLOTS, slot = i % PLANT_SLOTS, v = variant_of(seed, i);
        const slot_def *sd = &slots[slot];
        float cx = PLANT_CELL * (float)(u % grid) - half, cz = PLANT_CELL * (float)(u / grid) - half;
        place p = place_of(seed, i, slot, cx, cz);
        r = proto_mesh(s, sd->kind, v, sd->material, d, mats, cache, &out->meshes, err);
        char name[48];
        snprintf(name, sizeof name, "%s %u", kind_names[sd->kind], i);
        if (r == SY_OK) r = sy_node_create(s, name, &nodes[i], err);
        if (r == SY_OK) r = sy_node_set_trs(s, nodes[i], p.t, p.q, p.s, err);
        if (r == SY_OK) r = sy_node_set_mesh(s, nodes[i], cache[(sd->kind * PLANT_VARIANTS + v) * M_COUNT + sd->material], err);
        if (r == SY_OK) r = sy_node_set_flags(s, nodes[i], SY_NODE_VISIBLE, err);
        if (r == SY_OK) {
            sy_bounds mb;
            r = sy_mesh_bounds(s, cache[(sd->kind * PLANT_VARIANTS + v) * M_COUNT + sd->material], &mb, err);
            sy_mat4 m = sy_mat4_from_trs(p.t, p.q, p.s);
            sy_bounds wb = sy_bounds_transform(&mb, &m);
            sy_bounds_add_bounds(&out->bounds, &wb);
            out->triangles += tris_of(sd->kind, tess_of(sd->kind, d, v));
        }
    }
    if (r == SY_OK) r = sy_node_set_children(s, out->root, nodes, n, err);
    if (r == SY_OK) {
        out->objects = n, out->grid = grid, out->cell = PLANT_CELL;
        out->corridor_x = PLANT_CELL * (float)(grid / 2) - half - 11.1f;
    }
    free(cache);
    free(nodes);
    return r;
}
