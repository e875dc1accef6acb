/* sy_gl_device.c — the rasterizer: object pools, uploads (counted), shadow maps, the main PBR
 * pass with sorted alpha blending, MSAA resolve and read-back into the shared layer conventions
 * (see sy_gl.h).
 *
 * Sections: >>pools  >>math  >>device  >>mesh  >>texture  >>material  >>instance/light  >>render */
#include "sy_gl.h"
#include "sy_gl_context.h"
#include "sy_gl_ibl.h"
#include "sy_gl_shaders.h"

#include <meshoptimizer.h>

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define IDX_BITS 20u
#define IDX_MASK ((1u << IDX_BITS) - 1u)
#define SHADOW_SIZE_DEFAULT 2048u
enum { UNIT_BASE = 0, UNIT_MR, UNIT_NRM, UNIT_OCC, UNIT_EMIS, UNIT_SHADOW, UNIT_ENV_SPEC, UNIT_ENV_IRR, UNIT_BRDF,
       UNIT_LTC1, UNIT_LTC2, UNIT_CUBE_SHADOW0, UNIT_CUBE_SHADOW1, UNIT_PROBE, UNIT_COUNT };
/* Scene probes: mirror-like and glass instances see the scene, not only the environment. Each of
 * the first SY_GL_MAX_PROBES such instances gets a cube map rendered from its bounding-box centre
 * (the instance itself left out, other probed instances showing the environment), with a mip
 * chain for roughness; re-rendered only when geometry, materials, lights or the environment
 * change, never for a camera move. Its side (probe_size_for) follows the largest frame rendered so
 * far, from PROBE_SIZE_MIN to PROBE_SIZE_MAX texels: a 90 degree face needs no more texels than
 * about half the frame's width has (a small first frame renders four times fewer probe pixels,
 * issue 32), and it never shrinks, so a view whose resolution drops while it moves (sy view, sy
 * web) does not re-render its probes. */
#define SY_GL_MAX_PROBES 4u
#define PROBE_SIZE_MIN 32u
#define PROBE_SIZE_MAX 256u
#define PROBE_MAX_ROUGHNESS 0.4f
enum { BIND_MATERIAL = 0, BIND_LIGHTS = 1, BIND_AREAS = 2 };
/* Deferred shading (see sy_gl_shaders.c, sy_gl_gbuf_fs): the shading pass samples no material
 * texture, so the G-buffer and the material table use the material units. */
enum { UNIT_GCOL = UNIT_BASE, UNIT_GDEPTH = UNIT_MR, UNIT_MTAB = UNIT_NRM };
#define MTAB_TEXELS 3u      /* RGBA32F texels per material row (sy_gl_deferred_fs) */
#define MTAB_MAX_ROWS 256u /* the G-buffer's key holds 8 bits of material row (sy_gl_shaders.c) */
#define DEFERRED_PROGS 16u  /* shading-pass programs kept (one per frame lighting variant) */
#define RECT_TILE 8u        /* the deferred pass shades the RECT_TILE-pixel tiles G-buffer instances touch */
#define PM_SPARE 32u        /* main programs kept for other light signatures than the current one */
/* Instances whose forward shading would run on more pixels per triangle than this stay forward:
 * on big triangles the forward pass already shades about once per pixel, and the G-buffer pass
 * is extra (measured with sy bench raster: the demo's spheres at 24-37 pixels per triangle are
 * faster forward, the 1M-triangle scene's meshes at 2-8 deferred). */
#define DEFERRED_MAX_PX_PER_TRI 16.0f

static sy_gl_result fail(char *err, size_t len, sy_gl_result r, const char *fmt, ...)
{
    if (err && len) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err, len, fmt, ap);
        va_end(ap);
    }
    return r;
}

/* >>pools: every object struct starts with {id, gen}; id 0 = free slot. */
typedef struct slot_head {
    uint32_t id, gen;
} slot_head;

typedef struct pool {
    void *items;
    uint32_t count, cap, live;
    size_t elem;
} pool;

static void *pool_at(const pool *p, uint32_t i) { return (char *)p->items + (size_t)i * p->elem; }

static void *pool_get(const pool *p, uint32_t id)
{
    uint32_t i = id & IDX_MASK;
    if (!id || i >= p->count) return NULL;
    slot_head *h = pool_at(p, i);
    return h->id == id ? h : NULL;
}

static void *pool_alloc(pool *p)
{
    uint32_t i = 1; /* slot 0 unused, so ids are never 0 */
    for (; i < p->count; ++i)
        if (((slot_head *)pool_at(p, i))->id == 0) break;
    if (i >= IDX_MASK) return NULL;
    if (i >= p->count) {
        if (i >= p->cap) {
            uint32_t nc = p->cap ? p->cap * 2 : 64;
            void *n = realloc(p->items, p->elem * nc);
            if (!n) return NULL;
            memset((char *)n + p->elem * p->cap, 0, p->elem * (nc - p->cap));
            p->items = n;
            p->cap = nc;
        }
        p->count = i + 1;
    }
    slot_head *h = pool_at(p, i);
    uint32_t gen = (h->gen + 1u) & ((1u << (32 - IDX_BITS)) - 1u);
    if (!gen) gen = 1;
    memset(h, 0, p->elem);
    h->gen = gen;
    h->id = (gen << IDX_BITS) | i;
    p->live++;
    return h;
}

static void pool_free(pool *p, void *item)
{
    slot_head *h = item;
    uint32_t gen = h->gen;
    memset(h, 0, p->elem);
    h->gen = gen;
    p->live--;
}

/* Levels of detail (meshoptimizer): level 0 is the mesh; each further level is simplified from the
 * one before to about a quarter of its triangles, all levels in one index buffer. */
#define LOD_MAX 12

typedef struct mesh_o {
    slot_head h;
    GLuint vao, vbo[1], ibo;
    uint32_t vertex_count, triangle_count;
    bool has_normals, indexed, has_attr[5];
    float bmin[3], bmax[3];
    float centre[3], radius;     /* bounding sphere of the box (object space) */
    uint32_t lod_count;          /* levels, 1 = the mesh only */
    uint32_t lod_first[LOD_MAX], lod_tris[LOD_MAX]; /* first index, triangles */
    float lod_error[LOD_MAX];    /* object-space deviation from level 0 (bound, metres) */
} mesh_o;

typedef struct tex_o {
    slot_head h;
    GLuint tex;
    uint32_t width, height; /* level 0 as uploaded */
} tex_o;

typedef struct mat_o {
    slot_head h;
    GLuint ubo;
    sy_gl_material_desc d;
} mat_o;

typedef struct inst_o {
    slot_head h;
    sy_gl_mesh mesh;
    sy_gl_material material;
    float model[16], normal_mat[9];
    bool mirror, visible;
    uint32_t lod;  /* level chosen for the last view drawn (choose_lod); shadow maps reuse it */
    float px_per_tri; /* the last main view: its projected bounding-sphere area over its level's triangles */
} inst_o;

typedef struct light_o {
    slot_head h;
    sy_gl_light_desc d;
} light_o;

typedef struct targets {
    uint32_t w, h, samples;
    GLuint fbo, color, depthlin, depth_rb;
    GLuint rfbo, rcolor, rdepthlin; /* resolve targets when samples > 1 */
} targets;

/* Main-pass shader variant bits (the SY_* defines of sy_gl_shaders.c). */
enum {
    VAR_LEAN = 1,     /* mesh without uv1 and colours */
    VAR_MASK = 2,     /* alpha mask: the only variants with discard */
    VAR_TEX = 4,      /* the material samples a texture */
    VAR_NMAP = 8,     /* ... a normal map (only with VAR_TEX and lighting) */
    VAR_LIGHTS = 16,  /* punctual lights present */
    VAR_ENV = 32,     /* environment light (prefiltered cube maps) */
    VAR_SHADOW = 64,  /* punctual shadow maps (only with VAR_LIGHTS) */
    VAR_NL_SHIFT = 7, /* bits 7-9: the light count when 1..VAR_NL_MAX (one call per light with constant
                       * uniform-block offsets and shadow kinds: variant_sig), 0 = a loop over the
                       * Lights block */
    VAR_NL_MAX = 7,
    VAR_AREA = 1024,    /* emissive polygons (LTC) */
    VAR_ASHADOW = 2048, /* area-light shadow maps (only with VAR_AREA) */
    VAR_TRANS = 4096,   /* the material transmits (refracts the environment; only with VAR_ENV or VAR_PROBE) */
    VAR_PROBE = 8192,   /* the instance reflects and refracts its own scene probe instead of the environment */
    VAR_COUNT = 16384
};

struct sy_gl_device {
    sy_gl_context *ctx;
    const sy_gl_fns *gl;
    char info[256];
    sy_gl_log_fn log;
    void *log_user;
    uint32_t msaa, max_tex, shadow_size;
    pool meshes, textures, materials, instances, lights;
    GLuint prog_resolve, prog_floor, prog_floor_lit;
    GLint resolve_rects; /* prog_resolve's u_rects (sy_gl_rect_vs: the whole target or the tiles the deferred pass leaves) */
    struct main_prog { /* main-pass variants, built on first use, indexed by VAR_* bits (main_program) */
        GLuint prog;
        GLint model, normal_mat, mvp, cam_pos, cam_fwd, ortho, ortho_z, mirror, has_normals, probe_lod;
        uint64_t frame; /* the frame whose view uniforms it holds */
        uint64_t sig;   /* the lights' signature it was built for (variant_sig) */
        int var;        /* its variant bits (in pm_spare) */
    } pm[VAR_COUNT];
    /* programs of earlier light signatures, kept so that lights toggled back and forth (a shadow
     * turned off and on, an emissive object hidden and shown) do not recompile each time; reused
     * in turn when full */
    struct main_prog pm_spare[PM_SPARE];
    uint32_t pm_spare_next;
    uint64_t frame_no;
    uint32_t light_count, shadow_count, area_shadow_count; /* as uploaded by lights_upload: they pick the variants */
    /* lights_upload: what the shaders' straight-line light code is built for. Bits 2i, 2i + 1:
     * punctual light i's kind of shadow (i < VAR_NL_MAX; shade_light: 0 none, 1 map, 2 + s cube s);
     * bits 48 + 2i, 49 + 2i: punctual light i's type (shade_light's lt: 0 point, 1 point with a
     * range, 2 spot, 3 directional) */
    uint64_t light_sig;
    struct {
        GLuint prog;
        GLint model, lightvp;
    } ps[2];
    struct {
        GLint model, view, proj;
    } uf[2]; /* the floors: unlit, trivial lit */
    GLuint default_ubo, lights_ubo, empty_vao;
    GLuint standin[5]; /* per material texture unit, bound where the material has no texture (make_standin) */
    GLuint shadow_tex, shadow_fbo;
    GLuint cube_tex[SY_GL_MAX_CUBE_SHADOWS]; /* point-light depth cube maps, made on first use */
    uint32_t cube_size;
    struct {
        GLuint cube;
        uint32_t inst; /* instance pool index */
    } probes[SY_GL_MAX_PROBES];
    uint32_t probe_count;
    GLuint probe_fbo, probe_depth;
    uint32_t probe_size; /* the probes' side in texels (0: none made yet; see probe_size_for) */
    bool probes_dirty, in_probe_pass;
    targets t;
    bool lights_dirty;
    /* deferred shading */
    bool forward; /* sy_gl_device_desc.forward */
    struct { /* the G-buffer pass: perspective, orthographic */
        GLuint prog;
        GLint normal_mat, mvp, ppu, ortho_z, has_normals, keys;
    } ug[2];
    struct {
        int var;        /* the lighting variant bits */
        uint64_t sig;   /* and the lights' signature (variant_sig) */
        GLuint prog;
        GLint unproj, inv_view, px, cam_pos, cam_fwd, ortho, rects;
    } dp[DEFERRED_PROGS];
    uint32_t dp_count, dp_next; /* dp_next: the slot a new program takes once all are used */
    float *mtab_cpu;                 /* material table: row i = the material of pool index i, row 0 = default */
    uint32_t mtab_cpu_rows, mtab_limit; /* rows held; rows a texture may have (GL_MAX_TEXTURE_SIZE) */
    GLuint mtab;                     /* its texture, MTAB_TEXELS x mtab_rows */
    uint32_t mtab_rows, mtab_dirty_lo, mtab_dirty_hi; /* rows [lo, hi) changed since the last upload */
    uint64_t deferred_draws;         /* instances drawn into the G-buffer in the last main pass */
    /* where the deferred pass shades (rect_add): pixel rectangles (x0, y0, x1, y1) bounding the
     * G-buffer instances of the last main pass, or everywhere (rect_all) */
    uint32_t (*rects)[4];
    uint32_t rect_count, rect_cap;
    bool rect_all;
    uint64_t deferred_pixels; /* the pixels the last deferred pass shaded */
    uint8_t *tiles;       /* rect_tiles: RECT_TILE-pixel tiles the rectangles touch, then both lists of */
    float (*spans)[4];    /* tile runs in NDC (sy_gl_rect_vs) */
    uint32_t *runs;       /* rect_tiles' scratch: two per tile column */
    size_t tiles_cap;     /* tiles and spans hold (in tiles) */
    /* background (camera rays only) */
    sy_gl_background_mode bg_mode;
    float bg_color[4], bg_intensity;
    sy_gl_texture bg_tex;
    GLuint prog_sky;
    GLint sky_inv_vp, sky_size_int;
    /* environment light */
    sy_gl_texture env_tex;
    float env_intensity;
    bool env_dirty, env_ready;
    sy_gl_ibl ibl;
    /* emissive polygons */
    sy_gl_area_light areas[SY_GL_MAX_AREA_LIGHTS];
    uint32_t area_count;
    GLuint areas_ubo;
    bool areas_dirty;
    float ambient[3];
    bool warned_lights;
    sy_gl_upload_counts counts, frame, mark;
    uint32_t shadow_maps;
    uint64_t tris, draws;
    float lod_pixels;    /* sy_gl_set_lod */
    uint64_t culled;     /* instances outside the view in the last main pass */
    float *scratch;
    size_t scratch_len;
};

static void warn(sy_gl_device *dev, const char *fmt, ...)
{
    if (!dev->log) return;
    char msg[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    dev->log(dev->log_user, msg);
}

/* >>math (column-major 4x4) */
static void m4_mul(const float *a, const float *b, float *o)
{
    float r[16];
    for (int c = 0; c < 4; ++c)
        for (int row = 0; row < 4; ++row) {
            float s = 0.0f;
            for (int k = 0; k < 4; ++k) s += a[k * 4 + row] * b[c * 4 + k];
            r[c * 4 + row] = s;
        }
    memcpy(o, r, sizeof r);
}

static bool m4_invert(const float *m, float *out)
{
    double inv[16], det;
    inv[0] = m[5] * m[10] * m[15] - m[5] * m[11] * m[14] - m[9] * m[6] * m[15] + m[9] * m[7] * m[14] + m[13] * m[6] * m[11] - m[13] * m[7] * m[10];
    inv[4] = -m[4] * m[10] * m[15] + m[4] * m[11] * m[14] + m[8] * m[6] * m[15] - m[8] * m[7] * m[14] - m[12] * m[6] * m[11] + m[12] * m[7] * m[10];
    inv[8] = m[4] * m[9] * m[15] - m[4] * m[11] * m[13] - m[8] * m[5] * m[15] + m[8] * m[7] * m[13] + m[12] * m[5] * m[11] - m[12] * m[7] * m[9];
    inv[12] = -m[4] * m[9] * m[14] + m[4] * m[10] * m[13] + m[8] * m[5] * m[14] - m[8] * m[6] * m[13] - m[12] * m[5] * m[10] + m[12] * m[6] * m[9];
    inv[1] = -m[1] * m[10] * m[15] + m[1] * m[11] * m[14] + m[9] * m[2] * m[15] - m[9] * m[3] * m[14] - m[13] * m[2] * m[11] + m[13] * m[3] * m[10];
    inv[5] = m[0] * m[10] * m[15] - m[0] * m[11] * m[14] - m[8] * m[2] * m[15] + m[8] * m[3] * m[14] + m[12] * m[2] * m[11] - m[12] * m[3] * m[10];
    inv[9] = -m[0] * m[9] * m[15] + m[0] * m[11] * m[13] + m[8] * m[1] * m[15] - m[8] * m[3] * m[13] - m[12] * m[1] * m[11] + m[12] * m[3] * m[9];
    inv[13] = m[0] * m[9] * m[14] - m[0] * m[10] * m[13] - m[8] * m[1] * m[14] + m[8] * m[2] * m[13] + m[12] * m[1] * m[10] - m[12] * m[2] * m[9];
    inv[2] = m[1] * m[6] * m[15] - m[1] * m[7] * m[14] - m[5] * m[2] * m[15] + m[5] * m[3] * m[14] + m[13] * m[2] * m[7] - m[13] * m[3] * m[6];
    inv[6] = -m[0] * m[6] * m[15] + m[0] * m[7] * m[14] + m[4] * m[2] * m[15] - m[4] * m[3] * m[14] - m[12] * m[2] * m[7] + m[12] * m[3] * m[6];
    inv[10] = m[0] * m[5] * m[15] - m[0] * m[7] * m[13] - m[4] * m[1] * m[15] + m[4] * m[3] * m[13] + m[12] * m[1] * m[7] - m[12] * m[3] * m[5];
    inv[14] = -m[0] * m[5] * m[14] + m[0] * m[6] * m[13] + m[4] * m[1] * m[14] - m[4] * m[2] * m[13] - m[12] * m[1] * m[6] + m[12] * m[2] * m[5];
    inv[3] = -m[1] * m[6] * m[11] + m[1] * m[7] * m[10] + m[5] * m[2] * m[11] - m[5] * m[3] * m[10] - m[9] * m[2] * m[7] + m[9] * m[3] * m[6];
    inv[7] = m[0] * m[6] * m[11] - m[0] * m[7] * m[10] - m[4] * m[2] * m[11] + m[4] * m[3] * m[10] + m[8] * m[2] * m[7] - m[8] * m[3] * m[6];
    inv[11] = -m[0] * m[5] * m[11] + m[0] * m[7] * m[9] + m[4] * m[1] * m[11] - m[4] * m[3] * m[9] - m[8] * m[1] * m[7] + m[8] * m[3] * m[5];
    inv[15] = m[0] * m[5] * m[10] - m[0] * m[6] * m[9] - m[4] * m[1] * m[10] + m[4] * m[2] * m[9] + m[8] * m[1] * m[6] - m[8] * m[2] * m[5];
    det = m[0] * inv[0] + m[1] * inv[4] + m[2] * inv[8] + m[3] * inv[12];
    if (!(fabs(det) > 1e-30) || !isfinite(det)) return false;
    for (int i = 0; i < 16; ++i) out[i] = (float)(inv[i] / det);
    return true;
}

static void v3_norm(float *v)
{
    float l = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (l > 0.0f)
        for (int i = 0; i < 3; ++i) v[i] /= l;
}

static float dot3f(const float *a, const float *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static void cross3(const float *a, const float *b, float *o)
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

/* World-to-light view looking from eye along dir. */
enum { CASTER_NONE, CASTER_OPAQUE, CASTER_MASKED };

/* How a material casts shadows in the shadow maps (render_shadow_layer). */
static int caster_kind(const sy_gl_material_desc *d)
{
    if (d->emissive[0] > 0.0f || d->emissive[1] > 0.0f || d->emissive[2] > 0.0f) return CASTER_NONE;
    if (d->transmission * (1.0f - d->metallic) >= 0.5f) return CASTER_NONE;
    return d->alpha_mode == SY_GL_ALPHA_OPAQUE ? CASTER_OPAQUE : CASTER_MASKED;
}

/* A depth texture array compared in the shader (hardware PCF); outside it reads as lit. */
static GLuint shadow_array(const sy_gl_fns *gl, uint32_t size, uint32_t layers)
{
    GLuint t = 0;
    gl->GenTextures(1, &t);
    gl->BindTexture(GL_TEXTURE_2D_ARRAY, t);
    gl->TexImage3D(GL_TEXTURE_2D_ARRAY, 0, GL_DEPTH_COMPONENT32F, (GLsizei)size, (GLsizei)size, (GLsizei)layers, 0,
                   GL_DEPTH_COMPONENT, GL_FLOAT, NULL);
    gl->TexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    gl->TexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    gl->TexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_BORDER);
    gl->TexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_BORDER);
    static const float border[4] = {1, 1, 1, 1};
    gl->TexParameterfv(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_BORDER_COLOR, border);
    gl->TexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    gl->TexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
    return t;
}

/* The cube-map faces in GL order as (right, up, forward): rendering a face with this camera and a
 * 90-degree frustum fills it as GL's cube sampling reads it (window x and y along right and up). */
static const float cube_faces[6][3][3] = {
    {{0, 0, -1}, {0, -1, 0}, {1, 0, 0}},  {{0, 0, 1}, {0, -1, 0}, {-1, 0, 0}}, {{1, 0, 0}, {0, 0, 1}, {0, 1, 0}},
    {{1, 0, 0}, {0, 0, -1}, {0, -1, 0}}, {{1, 0, 0}, {0, -1, 0}, {0, 0, 1}},  {{-1, 0, 0}, {0, -1, 0}, {0, 0, -1}}};

static void cube_face_view(const float *eye, int f, float *view)
{
    const float(*b)[3] = cube_faces[f];
    float m[16] = {b[0][0], b[1][0], -b[2][0], 0, b[0][1], b[1][1], -b[2][1], 0, b[0][2], b[1][2], -b[2][2], 0, 0, 0, 0, 1};
    for (int i = 0; i < 3; ++i) m[12 + i] = -(m[i] * eye[0] + m[4 + i] * eye[1] + m[8 + i] * eye[2]);
    memcpy(view, m, sizeof m);
}

/* A depth cube map compared in the shader (hardware PCF, seamless across faces). */
static GLuint shadow_cube(const sy_gl_fns *gl, uint32_t size)
{
    GLuint t = 0;
    gl->GenTextures(1, &t);
    gl->BindTexture(GL_TEXTURE_CUBE_MAP, t);
    for (int f = 0; f < 6; ++f)
        gl->TexImage2D(GL_TEXTURE_CUBE_MAP_POSITIVE_X + (GLenum)f, 0, GL_DEPTH_COMPONENT32F, (GLsizei)size, (GLsizei)size, 0,
                       GL_DEPTH_COMPONENT, GL_FLOAT, NULL);
    gl->TexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    gl->TexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    gl->TexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    gl->TexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    gl->TexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
    gl->TexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    gl->TexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
    return t;
}

static void look_along(const float *eye, const float *dir, float *view)
{
    float z[3] = {-dir[0], -dir[1], -dir[2]}, up[3] = {0, 1, 0}, x[3], y[3];
    v3_norm(z);
    if (fabsf(z[1]) > 0.99f) {
        up[1] = 0;
        up[2] = 1;
    }
    cross3(up, z, x);
    v3_norm(x);
    cross3(z, x, y);
    float m[16] = {x[0], y[0], z[0], 0, x[1], y[1], z[1], 0, x[2], y[2], z[2], 0, 0, 0, 0, 1};
    for (int i = 0; i < 3; ++i) m[12 + i] = -(m[i] * eye[0] + m[4 + i] * eye[1] + m[8 + i] * eye[2]);
    memcpy(view, m, sizeof m);
}

/* Projection from an image-plane window (tangent space at distance 1, or camera units for ortho). */
static void projection(bool ortho, double l, double r, double b, double t, double n, double f, float *p)
{
    memset(p, 0, 16 * sizeof *p);
    if (ortho) {
        p[0] = (float)(2.0 / (r - l));
        p[12] = (float)(-(r + l) / (r - l));
        p[5] = (float)(2.0 / (t - b));
        p[13] = (float)(-(t + b) / (t - b));
        p[10] = (float)(-2.0 / (f - n));
        p[14] = (float)(-(f + n) / (f - n));
        p[15] = 1.0f;
        return;
    }
    p[0] = (float)(2.0 / (r - l));
    p[8] = (float)((r + l) / (r - l));
    p[5] = (float)(2.0 / (t - b));
    p[9] = (float)((t + b) / (t - b));
    p[11] = -1.0f;
    if (f > 0.0) {
        p[10] = (float)(-(f + n) / (f - n));
        p[14] = (float)(-2.0 * f * n / (f - n));
    } else { /* infinite far plane */
        p[10] = -1.0f;
        p[14] = (float)(-2.0 * n);
    }
}

static void count_buffer(sy_gl_device *dev, bool uniform, size_t bytes)
{
    if (uniform) {
        dev->counts.uniform_buffer_uploads++;
        dev->counts.uniform_bytes += bytes;
    } else {
        dev->counts.vertex_buffer_uploads++;
        dev->counts.vertex_bytes += bytes;
    }
}

static sy_gl_result gl_check(sy_gl_device *dev, const char *where, char *err, size_t len)
{
    GLenum e = dev->gl->GetError();
    if (e == GL_NO_ERROR) return SY_GL_OK;
    while (dev->gl->GetError() != GL_NO_ERROR) {
    }
    return fail(err, len, e == GL_OUT_OF_MEMORY ? SY_GL_ERROR_OUT_OF_MEMORY : SY_GL_ERROR_GL,
                "%s: OpenGL error 0x%04x (%s)", where, (unsigned)e, sy_gl_provider_name(sy_gl_context_provider(dev->ctx)));
}

static sy_gl_result current(sy_gl_device *dev, char *err, size_t len)
{
    if (!sy_gl_context_make_current(dev->ctx))
        return fail(err, len, SY_GL_ERROR_NO_CONTEXT, "%s: cannot make the GL context current",
                    sy_gl_provider_name(sy_gl_context_provider(dev->ctx)));
    return SY_GL_OK;
}

/* >>device */
/* A material's stand-in for a texture it does not have in one unit (bind_material): a constant 2x2
 * texture with a mipmap, in the unit's format (sRGB for colours) and the sampling of an uploaded
 * texture by default (repeat, trilinear). llvmpipe compiles a fragment shader per state of what it
 * samples (format, filters, wraps, whether there are mip levels), so a stand-in that samples like the
 * real textures lets materials with and without a texture in that unit share one compiled shader
 * (issue 32: the first frame's compile time). A constant texture filters to its value exactly. */
static GLuint make_standin(const sy_gl_fns *gl, const unsigned char rgba[4], bool srgb)
{
    unsigned char px[16];
    for (int i = 0; i < 16; ++i) px[i] = rgba[i & 3];
    GLuint t;
    gl->GenTextures(1, &t);
    gl->BindTexture(GL_TEXTURE_2D, t);
    gl->TexImage2D(GL_TEXTURE_2D, 0, srgb ? GL_SRGB8_ALPHA8 : GL_RGBA8, 2, 2, 0, GL_RGBA, GL_UNSIGNED_BYTE, px);
    gl->TexImage2D(GL_TEXTURE_2D, 1, srgb ? GL_SRGB8_ALPHA8 : GL_RGBA8, 1, 1, 0, GL_RGBA, GL_UNSIGNED_BYTE, px);
    gl->TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    gl->TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    return t;
}

typedef struct mat_block {
    float base[4], emissive[4], mrna[4], oist[4];
    int32_t modes[4], tex[4], tex2[4];
    float xf[10][4]; /* per texture slot (base, mr, nrm, occ, emis) two rows of its uv transform */
} mat_block;

static void material_block(const sy_gl_device *dev, const sy_gl_material_desc *d, mat_block *b)
{
    memset(b, 0, sizeof *b);
    memcpy(b->base, d->base_color, sizeof b->base);
    memcpy(b->emissive, d->emissive, sizeof d->emissive);
    b->mrna[0] = d->metallic;
    b->mrna[1] = d->roughness;
    b->mrna[2] = d->normal_scale;
    b->mrna[3] = d->alpha_cutoff;
    b->oist[0] = d->occlusion_strength;
    b->oist[1] = d->ior >= 1.0f ? d->ior : 1.5f;
    b->oist[2] = d->specular;
    b->oist[3] = d->transmission;
    b->modes[0] = (int32_t)d->alpha_mode;
    b->modes[1] = d->unlit;
    b->modes[2] = d->double_sided;
    b->modes[3] = d->emissive[0] > 0.0f || d->emissive[1] > 0.0f || d->emissive[2] > 0.0f;
    const sy_gl_texture_ref *refs[5] = {&d->base_color_texture, &d->metallic_roughness_texture, &d->normal_texture,
                                        &d->occlusion_texture, &d->emissive_texture};
    for (int i = 0; i < 5; ++i) {
        int32_t v = pool_get(&dev->textures, refs[i]->texture.id) ? (int32_t)(refs[i]->texcoord & 1u) : -1;
        if (i < 4) b->tex[i] = v;
        else b->tex2[0] = v;
        const float id[6] = {1, 0, 0, 0, 1, 0}, *m = refs[i]->transformed ? refs[i]->transform : id;
        memcpy(b->xf[2 * i], m, 3 * sizeof(float));
        memcpy(b->xf[2 * i + 1], m + 3, 3 * sizeof(float));
    }
}

static void bind_samplers(const sy_gl_fns *gl, GLuint prog)
{
    static const char *names[UNIT_COUNT] = {"t_base", "t_mr",       "t_nrm",     "t_occ",  "t_emis", "t_shadow",
                                            "t_env_spec", "t_env_irr", "t_brdf", "t_ltc1", "t_ltc2", "t_cshadow0",
                                            "t_cshadow1", "t_probe"};
    gl->UseProgram(prog);
    for (int i = 0; i < UNIT_COUNT; ++i) {
        GLint loc = gl->GetUniformLocation(prog, names[i]);
        if (loc >= 0) gl->Uniform1i(loc, i);
    }
    GLuint b = gl->GetUniformBlockIndex(prog, "Material");
    if (b != GL_INVALID_INDEX) gl->UniformBlockBinding(prog, b, BIND_MATERIAL);
    b = gl->GetUniformBlockIndex(prog, "Lights");
    if (b != GL_INVALID_INDEX) gl->UniformBlockBinding(prog, b, BIND_LIGHTS);
    b = gl->GetUniformBlockIndex(prog, "Areas");
    if (b != GL_INVALID_INDEX) gl->UniformBlockBinding(prog, b, BIND_AREAS);
}

static void probes_free(sy_gl_device *dev);

/* Drops variant bits that cannot matter, so that equivalent draws share one program. */
static int variant_normalize(int v)
{
    if (!(v & (VAR_LIGHTS | VAR_ENV | VAR_AREA | VAR_PROBE)) || !(v & VAR_TEX)) v &= ~VAR_NMAP;
    if (!(v & VAR_LIGHTS)) v &= ~(7 << VAR_NL_SHIFT);
    if (!(v & VAR_LIGHTS)) v &= ~VAR_SHADOW;
    if (!(v & VAR_AREA)) v &= ~VAR_ASHADOW;
    if (!(v & (VAR_ENV | VAR_PROBE))) v &= ~VAR_TRANS;
    return v;
}

/* The part of the lights' signature (light_sig) a program of variant bits v depends on. The
 * shaders call each punctual light (constant light count) with its shadow fixed (sy_gl_shaders.c,
 * shade_light): straight-line code that makes only the look-ups the frame needs (llvmpipe runs
 * every branch for every pixel). Emissive polygons run in two loops whose bounds are uniforms (the
 * Areas block, lights_upload), so no program depends on them: loops of constant bounds were
 * unrolled, sixteen inlined copies took LLVM many seconds to compile (issue 32). */
static uint64_t variant_sig(const sy_gl_device *dev, int v)
{
    uint64_t s = 0;
    if ((v & VAR_SHADOW) && ((v >> VAR_NL_SHIFT) & 7)) s |= dev->light_sig & 0x3FFFu;
    if ((v & VAR_LIGHTS) && ((v >> VAR_NL_SHIFT) & 7)) s |= dev->light_sig & (0x3FFFull << 48);
    return s;
}

/* The #defines of variant bits v and the lights' signature sig (variant_sig) (sy_gl_shaders.c)
 * into defs and their names after name's text. */
static void variant_defines(int v, uint64_t sig, char *defs, size_t defs_len, char *name, size_t name_len)
{
    static const char *const names[7] = {"LEAN", "MASK", "TEX", "NMAP", "LIGHTS", "ENV", "SHADOW"};
    static const struct {
        int bit;
        const char *name;
    } more[4] = {{VAR_AREA, "AREA"}, {VAR_TRANS, "TRANS"}, {VAR_ASHADOW, "ASHADOW"}, {VAR_PROBE, "PROBE"}};
    size_t dl = strlen(defs), nl = strlen(name);
    for (int b = 0; b < 7; ++b) {
        if (!(v & (1 << b))) continue;
        dl += (size_t)snprintf(defs + dl, defs_len - dl, "#define SY_%s 1\n", names[b]);
        nl += (size_t)snprintf(name + nl, name_len - nl, " %s", names[b]);
    }
    for (int k = 0; k < 4; ++k) {
        if (!(v & more[k].bit)) continue;
        dl += (size_t)snprintf(defs + dl, defs_len - dl, "#define SY_%s 1\n", more[k].name);
        nl += (size_t)snprintf(name + nl, name_len - nl, " %s", more[k].name);
    }
    int nlights = (v >> VAR_NL_SHIFT) & 7;
    if (nlights) {
        dl += (size_t)snprintf(defs + dl, defs_len - dl, "#define SY_NLIGHTS %d\n", nlights);
        nl += (size_t)snprintf(name + nl, name_len - nl, " (%d lights", nlights);
        for (int i = 0; i < nlights; ++i) {
            int kind = (int)((sig >> (2 * i)) & 3u); /* 0 none, 1 2D map, 2 + s cube slot s */
            int type = (int)((sig >> (48 + 2 * i)) & 3u); /* 0 point, 1 point with range, 2 spot, 3 directional */
            dl += (size_t)snprintf(defs + dl, defs_len - dl, "#define SY_LK%d %d\n#define SY_LT%d %d\n", i, kind, i, type);
            nl += (size_t)snprintf(name + nl, name_len - nl, "%s", i ? ", " : ": ");
            nl += (size_t)snprintf(name + nl, name_len - nl, "%s %s", (const char *[]){"point", "point+range", "spot", "sun"}[type],
                                   (const char *[]){"-", "map", "cube0", "cube1"}[kind]);
        }
        nl += (size_t)snprintf(name + nl, name_len - nl, ")");
    }
}

/* The main program for variant bits v, built and cached on first use; 0 with err set when the
 * driver rejects it. */
static GLuint main_program(sy_gl_device *dev, int v, char *err, size_t err_len)
{
    v = variant_normalize(v);
    uint64_t sig = variant_sig(dev, v);
    const sy_gl_fns *gl = dev->gl;
    if (dev->pm[v].prog) {
        if (dev->pm[v].sig == sig) return dev->pm[v].prog;
        /* the lights' shadows or polygon count changed: one built for them earlier, or a new one;
         * this one is kept aside */
        struct main_prog cur = dev->pm[v];
        cur.var = v;
        dev->pm[v].prog = 0;
        for (uint32_t i = 0; i < PM_SPARE; ++i)
            if (dev->pm_spare[i].prog && dev->pm_spare[i].var == v && dev->pm_spare[i].sig == sig) {
                dev->pm[v] = dev->pm_spare[i];
                dev->pm[v].frame = 0; /* its view uniforms are an older frame's */
                dev->pm_spare[i] = cur;
                return dev->pm[v].prog;
            }
        uint32_t slot = dev->pm_spare_next++ % PM_SPARE;
        if (dev->pm_spare[slot].prog) gl->DeleteProgram(dev->pm_spare[slot].prog);
        dev->pm_spare[slot] = cur;
    }
    char defs[1024] = "", name[256] = "main";
    variant_defines(v, sig, defs, sizeof defs, name, sizeof name);
    GLuint p = 0;
    if (sy_gl_program_build(gl, name, sy_gl_main_vs, sy_gl_main_fs, defs, &p, err, err_len) != SY_GL_OK) return 0;
    dev->pm[v].prog = p;
    dev->pm[v].sig = sig;
    dev->pm[v].model = gl->GetUniformLocation(p, "u_model");
    dev->pm[v].normal_mat = gl->GetUniformLocation(p, "u_normal_mat");
    dev->pm[v].mvp = gl->GetUniformLocation(p, "u_mvp");
    dev->pm[v].cam_pos = gl->GetUniformLocation(p, "u_cam_pos");
    dev->pm[v].cam_fwd = gl->GetUniformLocation(p, "u_cam_fwd");
    dev->pm[v].ortho = gl->GetUniformLocation(p, "u_ortho");
    dev->pm[v].ortho_z = gl->GetUniformLocation(p, "u_ortho_z");
    dev->pm[v].mirror = gl->GetUniformLocation(p, "u_mirror");
    dev->pm[v].has_normals = gl->GetUniformLocation(p, "u_has_normals");
    dev->pm[v].probe_lod = gl->GetUniformLocation(p, "u_probe_lod");
    dev->pm[v].frame = 0;
    bind_samplers(gl, p);
    return p;
}

/* The deferred shading pass for the frame's lighting variant bits v (only the lighting bits
 * count) and light signature, built and kept on first use: its index in dev->dp, or -1 with err
 * set when the driver rejects it. */
static int deferred_program(sy_gl_device *dev, int v, char *err, size_t err_len)
{
    v = variant_normalize(v & (VAR_LIGHTS | VAR_ENV | VAR_SHADOW | VAR_AREA | VAR_ASHADOW | (7 << VAR_NL_SHIFT)));
    uint64_t sig = variant_sig(dev, v);
    for (uint32_t i = 0; i < dev->dp_count; ++i)
        if (dev->dp[i].var == v && dev->dp[i].sig == sig) return (int)i;
    char defs[1024] = "", name[256] = "deferred";
    snprintf(defs, sizeof defs, "#define SY_SAMPLES %u\n", dev->msaa);
    variant_defines(v, sig, defs, sizeof defs, name, sizeof name);
    const sy_gl_fns *gl = dev->gl;
    GLuint p = 0;
    if (sy_gl_program_build(gl, name, sy_gl_rect_vs, sy_gl_deferred_fs, defs, &p, err, err_len) != SY_GL_OK) return -1;
    uint32_t i = dev->dp_count;
    if (i == DEFERRED_PROGS) { /* all kept: the new one takes the slots in turn (one is used per frame) */
        i = dev->dp_next++ % DEFERRED_PROGS;
        gl->DeleteProgram(dev->dp[i].prog);
    } else
        dev->dp_count++;
    dev->dp[i].var = v;
    dev->dp[i].sig = sig;
    dev->dp[i].prog = p;
    dev->dp[i].unproj = gl->GetUniformLocation(p, "u_unproj");
    dev->dp[i].inv_view = gl->GetUniformLocation(p, "u_inv_view");
    dev->dp[i].px = gl->GetUniformLocation(p, "u_px");
    dev->dp[i].cam_pos = gl->GetUniformLocation(p, "u_cam_pos");
    dev->dp[i].cam_fwd = gl->GetUniformLocation(p, "u_cam_fwd");
    dev->dp[i].ortho = gl->GetUniformLocation(p, "u_ortho");
    dev->dp[i].rects = gl->GetUniformLocation(p, "u_rects");
    bind_samplers(gl, p); /* the light and environment units and blocks; then its own three */
    gl->Uniform1i(gl->GetUniformLocation(p, "t_gcol"), UNIT_GCOL);
    gl->Uniform1i(gl->GetUniformLocation(p, "t_gdepth"), UNIT_GDEPTH);
    gl->Uniform1i(gl->GetUniformLocation(p, "t_mtab"), UNIT_MTAB);
    return (int)i;
}

/* >>material table: what the deferred pass knows of a material, one row per material pool index
 * (row 0: the default material), kept on the CPU and uploaded before a deferred pass when rows
 * changed. */
static void mtab_row(const sy_gl_device *dev, const sy_gl_material_desc *d, float *row)
{
    mat_block b;
    material_block(dev, d, &b);
    /* (base colour, metallic), (emission, roughness), (ior, specular, transmission, flags) */
    memcpy(row, b.base, 3 * sizeof *b.base);
    row[3] = b.mrna[0];
    memcpy(row + 4, b.emissive, 3 * sizeof *b.emissive);
    row[7] = b.mrna[1];
    memcpy(row + 8, b.oist + 1, 3 * sizeof *b.oist);
    row[11] = (float)((b.modes[1] ? 1 : 0) + (b.modes[2] ? 2 : 0) + (b.modes[3] ? 4 : 0)); /* unlit, two-sided, emissive */
}

/* Writes material d into row `row`; false (the material is then shaded forward) when the table
 * cannot hold it. */
static bool mtab_set(sy_gl_device *dev, uint32_t row, const sy_gl_material_desc *d)
{
    if (row >= dev->mtab_limit) return false;
    if (row >= dev->mtab_cpu_rows) {
        uint32_t n = dev->mtab_cpu_rows ? dev->mtab_cpu_rows : 64u;
        while (n <= row) n *= 2u;
        if (n > dev->mtab_limit) n = dev->mtab_limit;
        float *t = realloc(dev->mtab_cpu, (size_t)n * MTAB_TEXELS * 4u * sizeof *t);
        if (!t) return false;
        memset(t + (size_t)dev->mtab_cpu_rows * MTAB_TEXELS * 4u, 0,
               (size_t)(n - dev->mtab_cpu_rows) * MTAB_TEXELS * 4u * sizeof *t);
        dev->mtab_cpu = t;
        dev->mtab_cpu_rows = n;
    }
    mtab_row(dev, d, dev->mtab_cpu + (size_t)row * MTAB_TEXELS * 4u);
    if (dev->mtab_dirty_lo >= dev->mtab_dirty_hi) dev->mtab_dirty_lo = row, dev->mtab_dirty_hi = row + 1u;
    if (row < dev->mtab_dirty_lo) dev->mtab_dirty_lo = row;
    if (row + 1u > dev->mtab_dirty_hi) dev->mtab_dirty_hi = row + 1u;
    return true;
}

/* Brings the table's texture up to date (bound on UNIT_MTAB); counted as one texture upload. */
static void mtab_upload(sy_gl_device *dev)
{
    const sy_gl_fns *gl = dev->gl;
    gl->ActiveTexture(GL_TEXTURE0 + UNIT_MTAB);
    if (!dev->mtab) {
        gl->GenTextures(1, &dev->mtab);
        gl->BindTexture(GL_TEXTURE_2D, dev->mtab);
        gl->TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        gl->TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        gl->TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, 0);
    } else gl->BindTexture(GL_TEXTURE_2D, dev->mtab);
    if (dev->mtab_rows != dev->mtab_cpu_rows) {
        gl->TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, (GLsizei)MTAB_TEXELS, (GLsizei)dev->mtab_cpu_rows, 0, GL_RGBA, GL_FLOAT,
                       dev->mtab_cpu);
        dev->mtab_rows = dev->mtab_cpu_rows;
    } else if (dev->mtab_dirty_lo < dev->mtab_dirty_hi) {
        gl->TexSubImage2D(GL_TEXTURE_2D, 0, 0, (GLint)dev->mtab_dirty_lo, (GLsizei)MTAB_TEXELS,
                          (GLsizei)(dev->mtab_dirty_hi - dev->mtab_dirty_lo), GL_RGBA, GL_FLOAT,
                          dev->mtab_cpu + (size_t)dev->mtab_dirty_lo * MTAB_TEXELS * 4u);
    } else return;
    dev->mtab_dirty_lo = dev->mtab_dirty_hi = 0;
    dev->counts.texture_uploads++;
}

/* std140 Lights block: 16 + 16 + 4*64 + 4*16 + 32*64 bytes, then the cube shadows' parameters
 * (SY_GL_MAX_CUBE_SHADOWS x 16 bytes) */
#define LIGHTS_CUBE_PAR 600
#define LIGHTS_FLOATS (LIGHTS_CUBE_PAR + 4 * SY_GL_MAX_CUBE_SHADOWS)
#define AREAS_FLOATS (8 + SY_GL_MAX_AREA_LIGHTS * 6 * 4) /* std140 Areas block: ivec4 + vec4 + vec4[16 * 6] */

sy_gl_result sy_gl_device_create(const sy_gl_device_desc *desc, sy_gl_device **out, char *err, size_t err_len)
{
    *out = NULL;
    sy_gl_device_desc dd = {0};
    if (desc) dd = *desc;
    sy_gl_device *dev = calloc(1, sizeof *dev);
    if (!dev) return fail(err, err_len, SY_GL_ERROR_OUT_OF_MEMORY, "GL device: out of memory");
    dev->log = dd.log;
    dev->log_user = dd.log_user;
    dev->meshes.elem = sizeof(mesh_o);
    dev->textures.elem = sizeof(tex_o);
    dev->materials.elem = sizeof(mat_o);
    dev->instances.elem = sizeof(inst_o);
    dev->lights.elem = sizeof(light_o);
    sy_gl_result r = sy_gl_context_create(dd.provider, dd.window_width, dd.window_height, &dev->ctx, err, err_len);
    if (r != SY_GL_OK) {
        free(dev);
        return r;
    }
    const sy_gl_fns *gl = dev->gl = sy_gl_context_fns(dev->ctx);
    snprintf(dev->info, sizeof dev->info, "OpenGL %s on %s (%s)", (const char *)gl->GetString(GL_VERSION),
             (const char *)gl->GetString(GL_RENDERER), sy_gl_provider_name(dd.provider));
    GLint max_samples = 1, max_tex = 2048;
    gl->GetIntegerv(GL_MAX_SAMPLES, &max_samples);
    gl->GetIntegerv(GL_MAX_TEXTURE_SIZE, &max_tex);
    dev->msaa = dd.msaa > 1 ? dd.msaa : 1;
    if (dev->msaa > (uint32_t)max_samples) {
        warn(dev, "raster: %u MSAA samples requested, the GL context allows %d; using %d", dev->msaa, max_samples,
             max_samples);
        dev->msaa = (uint32_t)(max_samples > 1 ? max_samples : 1);
    }
    dev->max_tex = (uint32_t)max_tex;
    if (dd.max_texture_size && dd.max_texture_size < dev->max_tex) dev->max_tex = dd.max_texture_size;
    dev->shadow_size = dd.shadow_map_size ? dd.shadow_map_size : SHADOW_SIZE_DEFAULT;
    dev->lod_pixels = SY_GL_LOD_PIXELS_DEFAULT;
    if (dev->shadow_size > (uint32_t)max_tex) {
        warn(dev, "raster: shadow_map_size %u is above the GL context's texture limit; using %d", dev->shadow_size, max_tex);
        dev->shadow_size = (uint32_t)max_tex;
    }
    static const char *const defs[4] = {NULL, "#define SY_LEAN 1\n", "#define SY_MASK 1\n",
                                        "#define SY_MASK 1\n#define SY_LEAN 1\n"};
    /* the fullest main variant now, so that a shader the driver rejects fails here */
    if (!main_program(dev, VAR_TEX | VAR_NMAP | VAR_LIGHTS | VAR_ENV | VAR_AREA | VAR_SHADOW | VAR_ASHADOW | VAR_TRANS | VAR_MASK | VAR_PROBE, err, err_len))
        r = SY_GL_ERROR_GL;
    for (int v = 0; v < 2 && r == SY_GL_OK; ++v)
        r = sy_gl_program_build(gl, v ? "shadow (alpha mask)" : "shadow", sy_gl_shadow_vs, sy_gl_shadow_fs, defs[2 * v],
                                &dev->ps[v].prog, err, err_len);
    char rdefs[40];
    snprintf(rdefs, sizeof rdefs, "#define SY_SAMPLES %u\n", dev->msaa);
    if (r == SY_GL_OK) r = sy_gl_program_build(gl, "resolve", sy_gl_rect_vs, sy_gl_resolve_fs, rdefs, &dev->prog_resolve, err, err_len);
    if (r == SY_GL_OK) r = sy_gl_program_build(gl, "floor", sy_gl_floor_vs, sy_gl_floor_fs, NULL, &dev->prog_floor, err, err_len);
    if (r == SY_GL_OK)
        r = sy_gl_program_build(gl, "floor (trivial lit)", sy_gl_floor_vs, sy_gl_floor_fs, "#define SY_FLOOR_LIT 1\n",
                                &dev->prog_floor_lit, err, err_len);
    if (r == SY_GL_OK) r = sy_gl_program_build(gl, "sky", sy_gl_fullscreen_vs, sy_gl_sky_fs, NULL, &dev->prog_sky, err, err_len);
    dev->forward = dd.forward || dev->msaa < 2; /* the deferred pass is the MSAA resolve */
    for (int k = 0; k < 2 && r == SY_GL_OK && !dev->forward; ++k)
        r = sy_gl_program_build(gl, k ? "G-buffer (orthographic)" : "G-buffer", sy_gl_gbuf_vs, sy_gl_gbuf_fs,
                                k ? "#define SY_ORTHO 1\n" : NULL, &dev->ug[k].prog, err, err_len);
    if (r == SY_GL_OK && !dev->forward) { /* the fullest shading pass now, so that a driver's rejection fails here */
        if (deferred_program(dev, VAR_LIGHTS | VAR_ENV | VAR_AREA | VAR_SHADOW | VAR_ASHADOW, err, err_len) < 0)
            r = SY_GL_ERROR_GL;
    }
    if (r != SY_GL_OK) {
        sy_gl_device_destroy(dev);
        return r;
    }
    for (int v = 0; v < 2; ++v) {
        dev->ps[v].model = gl->GetUniformLocation(dev->ps[v].prog, "u_model");
        dev->ps[v].lightvp = gl->GetUniformLocation(dev->ps[v].prog, "u_lightvp");
        bind_samplers(gl, dev->ps[v].prog);
    }
    gl->UseProgram(dev->prog_resolve);
    gl->Uniform1i(gl->GetUniformLocation(dev->prog_resolve, "t_color"), 0);
    gl->Uniform1i(gl->GetUniformLocation(dev->prog_resolve, "t_depth"), 1);
    dev->resolve_rects = gl->GetUniformLocation(dev->prog_resolve, "u_rects");
    for (int k = 0; k < 2; ++k) {
        GLuint fp = k ? dev->prog_floor_lit : dev->prog_floor;
        dev->uf[k].model = gl->GetUniformLocation(fp, "u_model");
        dev->uf[k].view = gl->GetUniformLocation(fp, "u_view");
        dev->uf[k].proj = gl->GetUniformLocation(fp, "u_proj");
    }
    for (int k = 0; k < 2; ++k) {
        GLuint g = dev->ug[k].prog;
        if (!g) continue;
        dev->ug[k].normal_mat = gl->GetUniformLocation(g, "u_normal_mat");
        dev->ug[k].mvp = gl->GetUniformLocation(g, "u_mvp");
        dev->ug[k].ppu = gl->GetUniformLocation(g, "u_ppu");
        dev->ug[k].ortho_z = gl->GetUniformLocation(g, "u_ortho_z");
        dev->ug[k].has_normals = gl->GetUniformLocation(g, "u_has_normals");
        dev->ug[k].keys = gl->GetUniformLocation(g, "u_keys");
    }
    gl->UseProgram(dev->prog_sky);
    gl->Uniform1i(gl->GetUniformLocation(dev->prog_sky, "t_bg"), 0);
    dev->sky_inv_vp = gl->GetUniformLocation(dev->prog_sky, "u_inv_vp");
    dev->sky_size_int = gl->GetUniformLocation(dev->prog_sky, "u_size_int");

    static const unsigned char white[4] = {255, 255, 255, 255}, flat[4] = {128, 128, 255, 255};
    for (int i = 0; i < 5; ++i)
        dev->standin[i] = make_standin(gl, i == UNIT_NRM ? flat : white, i == UNIT_BASE || i == UNIT_EMIS);
    sy_gl_material_desc md;
    sy_gl_material_desc_init(&md);
    mat_block mb;
    material_block(dev, &md, &mb);
    dev->mtab_limit = (uint32_t)max_tex < MTAB_MAX_ROWS ? (uint32_t)max_tex : MTAB_MAX_ROWS;
    if (!dev->forward && !mtab_set(dev, 0, &md)) {
        sy_gl_device_destroy(dev);
        return fail(err, err_len, SY_GL_ERROR_OUT_OF_MEMORY, "GL device: out of memory");
    }
    gl->GenBuffers(1, &dev->default_ubo);
    gl->BindBuffer(GL_UNIFORM_BUFFER, dev->default_ubo);
    gl->BufferData(GL_UNIFORM_BUFFER, sizeof mb, &mb, GL_STATIC_DRAW);
    gl->GenBuffers(1, &dev->lights_ubo);
    gl->BindBuffer(GL_UNIFORM_BUFFER, dev->lights_ubo);
    gl->BufferData(GL_UNIFORM_BUFFER, LIGHTS_FLOATS * sizeof(float), NULL, GL_DYNAMIC_DRAW);
    gl->GenBuffers(1, &dev->areas_ubo);
    gl->BindBuffer(GL_UNIFORM_BUFFER, dev->areas_ubo);
    gl->BufferData(GL_UNIFORM_BUFFER, AREAS_FLOATS * sizeof(float), NULL, GL_DYNAMIC_DRAW);
    gl->GenVertexArrays(1, &dev->empty_vao);
    /* the shadow maps are made on the first frame with a shadowed light (shadow_maps_make) */
    dev->cube_size = dev->shadow_size / 2u > 16u ? dev->shadow_size / 2u : 16u;
    gl->Enable(GL_TEXTURE_CUBE_MAP_SEAMLESS); /* cube shadows and probes filter across faces */
    gl->GenFramebuffers(1, &dev->shadow_fbo);
    dev->lights_dirty = true;
    if ((r = gl_check(dev, "GL device setup", err, err_len)) != SY_GL_OK) {
        sy_gl_device_destroy(dev);
        return r;
    }
    *out = dev;
    return SY_GL_OK;
}

static void targets_free(sy_gl_device *dev, targets *t)
{
    const sy_gl_fns *gl = dev->gl;
    GLuint fb[2] = {t->fbo, t->rfbo}, tx[4] = {t->color, t->depthlin, t->rcolor, t->rdepthlin};
    gl->DeleteFramebuffers(2, fb);
    gl->DeleteTextures(4, tx);
    gl->DeleteRenderbuffers(1, &t->depth_rb);
    memset(t, 0, sizeof *t);
}

void sy_gl_device_destroy(sy_gl_device *dev)
{
    if (!dev) return;
    if (dev->ctx && sy_gl_context_make_current(dev->ctx) && dev->gl) {
        const sy_gl_fns *gl = dev->gl;
        for (uint32_t i = 0; i < dev->meshes.count; ++i) {
            mesh_o *m = pool_at(&dev->meshes, i);
            if (!m->h.id) continue;
            gl->DeleteBuffers(1, m->vbo);
            gl->DeleteBuffers(1, &m->ibo);
            gl->DeleteVertexArrays(1, &m->vao);
        }
        for (uint32_t i = 0; i < dev->textures.count; ++i) {
            tex_o *t = pool_at(&dev->textures, i);
            if (t->h.id) gl->DeleteTextures(1, &t->tex);
        }
        for (uint32_t i = 0; i < dev->materials.count; ++i) {
            mat_o *m = pool_at(&dev->materials, i);
            if (m->h.id) gl->DeleteBuffers(1, &m->ubo);
        }
        targets_free(dev, &dev->t);
        for (int v = 0; v < VAR_COUNT; ++v)
            if (dev->pm[v].prog) gl->DeleteProgram(dev->pm[v].prog);
        for (uint32_t i = 0; i < PM_SPARE; ++i)
            if (dev->pm_spare[i].prog) gl->DeleteProgram(dev->pm_spare[i].prog);
        GLuint progs[7] = {dev->ps[0].prog, dev->ps[1].prog, dev->prog_resolve, dev->prog_floor, dev->prog_sky,
                           dev->prog_floor_lit, dev->ug[0].prog};
        for (int i = 0; i < 7; ++i)
            if (progs[i]) gl->DeleteProgram(progs[i]);
        for (uint32_t i = 0; i < dev->dp_count; ++i) gl->DeleteProgram(dev->dp[i].prog);
        if (dev->ug[1].prog) gl->DeleteProgram(dev->ug[1].prog);
        if (dev->mtab) gl->DeleteTextures(1, &dev->mtab);
        sy_gl_ibl_free(gl, &dev->ibl);
        GLuint bufs[3] = {dev->default_ubo, dev->lights_ubo, dev->areas_ubo};
        gl->DeleteBuffers(3, bufs);
        gl->DeleteTextures(5, dev->standin);
        gl->DeleteTextures(1, &dev->shadow_tex);
        for (uint32_t c = 0; c < SY_GL_MAX_CUBE_SHADOWS; ++c)
            if (dev->cube_tex[c]) gl->DeleteTextures(1, &dev->cube_tex[c]);
        probes_free(dev);
        gl->DeleteFramebuffers(1, &dev->shadow_fbo);
        gl->DeleteVertexArrays(1, &dev->empty_vao);
    }
    sy_gl_context_destroy(dev->ctx);
    free(dev->meshes.items);
    free(dev->textures.items);
    free(dev->materials.items);
    free(dev->instances.items);
    free(dev->lights.items);
    free(dev->scratch);
    free(dev->mtab_cpu);
    free(dev->rects);
    free(dev->tiles);
    free(dev->spans);
    free(dev->runs);
    free(dev);
}

const char *sy_gl_device_info(const sy_gl_device *dev) { return dev->info; }

void sy_gl_device_stats(const sy_gl_device *dev, sy_gl_stats *out)
{
    memset(out, 0, sizeof *out);
    out->meshes = dev->meshes.live;
    out->textures = dev->textures.live;
    out->materials = dev->materials.live;
    out->instances = dev->instances.live;
    out->lights = dev->lights.live;
    out->msaa_samples = dev->msaa;
    out->shadow_maps = dev->shadow_maps;
    out->triangles_drawn = dev->tris;
    out->draw_calls = dev->draws;
    out->instances_culled = dev->culled;
    out->deferred_draws = dev->deferred_draws;
    out->deferred_pixels = dev->deferred_pixels;
    out->frame = dev->frame;
    out->total = dev->counts;
}

/* Geometry moved, appeared or vanished: shadow maps (and their frusta, fitted to the scene bounds)
 * must be redrawn, which happens with the lights-block update at the next frame. Without
 * shadow-casting lights nothing needs to be redone. */
static void geometry_changed(sy_gl_device *dev)
{
    if (dev->shadow_maps > 0) dev->lights_dirty = true;
    dev->probes_dirty = true;
}

/* >>mesh */

/* The levels of detail of an indexed mesh of at least SY_GL_LOD_MIN_TRIANGLES: into *out (malloc'd,
 * level 0 first) the mesh's indices followed by each simplified level; m->lod_* describe them.
 * Without memory, or when a level would not shrink the one before by a fifth, the chain stops
 * there (level 0 alone is a valid chain). */
static void build_lods(const sy_gl_mesh_desc *d, mesh_o *m, uint32_t **out, size_t *count_out)
{
    size_t n0 = 3u * (size_t)d->triangle_count;
    m->lod_count = 1;
    m->lod_first[0] = 0;
    m->lod_tris[0] = d->triangle_count;
    m->lod_error[0] = 0.0f;
    *out = NULL;
    *count_out = n0;
    if (!d->indices || d->triangle_count < SY_GL_LOD_MIN_TRIANGLES) return;
    /* the chain: at most n0 * (1 + 4/5 + (4/5)^2 + ...) = 5 n0 indices, 4/3 n0 in practice; each
     * level first into scratch (meshopt_simplify may need index_count entries) */
    size_t cap = n0 + n0 / 2u;
    uint32_t *all = malloc(cap * sizeof *all), *scratch = malloc(n0 * sizeof *scratch);
    if (!all || !scratch) {
        free(all), free(scratch);
        return;
    }
    memcpy(all, d->indices, n0 * sizeof *all);
    size_t used = n0;
    float scale = meshopt_simplifyScale(d->positions, d->vertex_count, 3 * sizeof(float)), err_sum = 0.0f;
    while (m->lod_count < LOD_MAX) {
        uint32_t k = m->lod_count;
        size_t prev_n = 3u * (size_t)m->lod_tris[k - 1], target = prev_n / 4u / 3u * 3u;
        if (target < 3u * 32u) break;
        float rel = 0.0f;
        size_t n = meshopt_simplify(scratch, all + m->lod_first[k - 1], prev_n, d->positions, d->vertex_count,
                                    3 * sizeof(float), target, 1.0f, 0, &rel);
        if (n == 0 || n * 5u > prev_n * 4u) break;
        if (used + n > cap) {
            size_t ncap = used + n + n0 / 4u;
            uint32_t *grown = realloc(all, ncap * sizeof *all);
            if (!grown) break;
            all = grown;
            cap = ncap;
        }
        memcpy(all + used, scratch, n * sizeof *all);
        err_sum += rel * scale; /* deviation from the level before, relative to the mesh extent */
        m->lod_first[k] = (uint32_t)used;
        m->lod_tris[k] = (uint32_t)(n / 3u);
        m->lod_error[k] = err_sum;
        m->lod_count++;
        used += n;
    }
    free(scratch);
    *out = all;
    *count_out = used;
}

sy_gl_result sy_gl_mesh_create(sy_gl_device *dev, const sy_gl_mesh_desc *d, sy_gl_mesh *out, char *err,
                               size_t err_len)
{
    out->id = 0;
    if (!d || !d->positions || d->vertex_count == 0 || d->triangle_count == 0)
        return fail(err, err_len, SY_GL_ERROR_INVALID_ARGUMENT, "mesh: positions and a non-zero vertex and triangle count are required");
    if (d->triangle_count > UINT32_MAX / 3u)
        return fail(err, err_len, SY_GL_ERROR_LIMIT, "mesh: %u triangles exceed the index range", d->triangle_count);
    if (!d->indices && d->vertex_count != 3u * d->triangle_count)
        return fail(err, err_len, SY_GL_ERROR_INVALID_ARGUMENT,
                    "mesh: without indices vertex_count (%u) must be 3 x triangle_count (%u)", d->vertex_count,
                    d->triangle_count);
    float bmin[3] = {INFINITY, INFINITY, INFINITY}, bmax[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t i = 0; i < d->vertex_count; ++i)
        for (int k = 0; k < 3; ++k) {
            float v = d->positions[3u * i + k];
            if (!isfinite(v)) return fail(err, err_len, SY_GL_ERROR_INVALID_ARGUMENT, "mesh: position %u is not finite", i);
            bmin[k] = fminf(bmin[k], v);
            bmax[k] = fmaxf(bmax[k], v);
        }
    if (d->indices)
        for (uint32_t i = 0; i < 3u * d->triangle_count; ++i)
            if (d->indices[i] >= d->vertex_count)
                return fail(err, err_len, SY_GL_ERROR_INVALID_ARGUMENT, "mesh: index %u = %u is out of range (%u vertices)",
                            i, d->indices[i], d->vertex_count);
    sy_gl_result r = current(dev, err, err_len);
    if (r != SY_GL_OK) return r;
    mesh_o *m = pool_alloc(&dev->meshes);
    if (!m) return fail(err, err_len, SY_GL_ERROR_OUT_OF_MEMORY, "mesh: out of memory");
    const sy_gl_fns *gl = dev->gl;
    m->vertex_count = d->vertex_count;
    m->triangle_count = d->triangle_count;
    memcpy(m->bmin, bmin, sizeof bmin);
    memcpy(m->bmax, bmax, sizeof bmax);
    float r2 = 0.0f;
    for (int k = 0; k < 3; ++k) {
        m->centre[k] = 0.5f * (bmin[k] + bmax[k]);
        r2 += 0.25f * (bmax[k] - bmin[k]) * (bmax[k] - bmin[k]);
    }
    m->radius = sqrtf(r2);
    uint32_t *lods = NULL;
    size_t index_count = 0;
    build_lods(d, m, &lods, &index_count);
    gl->GenVertexArrays(1, &m->vao);
    gl->BindVertexArray(m->vao);
    /* one interleaved vertex buffer (present attributes only) + one index buffer */
    const float *arrays[5] = {d->positions, d->normals, d->uv[0], d->uv[1], d->colors};
    static const int comps[5] = {3, 3, 2, 2, 4};
    int stride = 0, offs[5];
    for (int a = 0; a < 5; ++a) {
        offs[a] = stride;
        if (arrays[a]) stride += comps[a];
    }
    size_t bytes = (size_t)d->vertex_count * (size_t)stride * sizeof(float);
    float *vb = malloc(bytes);
    if (!vb) {
        pool_free(&dev->meshes, m);
        return fail(err, err_len, SY_GL_ERROR_OUT_OF_MEMORY, "mesh: out of memory (%u vertices)", d->vertex_count);
    }
    for (uint32_t i = 0; i < d->vertex_count; ++i)
        for (int a = 0; a < 5; ++a)
            if (arrays[a]) memcpy(vb + (size_t)i * stride + offs[a], arrays[a] + (size_t)i * comps[a], comps[a] * sizeof(float));
    gl->GenBuffers(1, &m->vbo[0]);
    gl->BindBuffer(GL_ARRAY_BUFFER, m->vbo[0]);
    gl->BufferData(GL_ARRAY_BUFFER, (GLsizeiptr)bytes, vb, GL_STATIC_DRAW);
    count_buffer(dev, false, bytes);
    free(vb);
    for (int a = 0; a < 5; ++a) {
        m->has_attr[a] = arrays[a] != NULL;
        if (!arrays[a]) continue;
        gl->EnableVertexAttribArray((GLuint)a);
        gl->VertexAttribPointer((GLuint)a, comps[a], GL_FLOAT, GL_FALSE, stride * (GLsizei)sizeof(float),
                                (const void *)(uintptr_t)(offs[a] * sizeof(float)));
    }
    m->has_normals = d->normals != NULL;
    if (d->indices) {
        size_t bytes = index_count * sizeof(uint32_t);
        gl->GenBuffers(1, &m->ibo);
        gl->BindBuffer(GL_ELEMENT_ARRAY_BUFFER, m->ibo);
        gl->BufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)bytes, lods ? lods : d->indices, GL_STATIC_DRAW);
        free(lods);
        count_buffer(dev, false, bytes);
        m->indexed = true;
    }
    gl->BindVertexArray(0);
    r = gl_check(dev, "mesh upload", err, err_len);
    if (r != SY_GL_OK) {
        sy_gl_mesh h = {m->h.id};
        sy_gl_mesh_destroy(dev, h);
        return r;
    }
    out->id = m->h.id;
    return SY_GL_OK;
}

sy_gl_result sy_gl_mesh_destroy(sy_gl_device *dev, sy_gl_mesh mesh)
{
    mesh_o *m = pool_get(&dev->meshes, mesh.id);
    if (!m) return SY_GL_ERROR_INVALID_HANDLE;
    if (current(dev, NULL, 0) == SY_GL_OK) {
        dev->gl->DeleteBuffers(1, m->vbo);
        dev->gl->DeleteBuffers(1, &m->ibo);
        dev->gl->DeleteVertexArrays(1, &m->vao);
    }
    pool_free(&dev->meshes, m);
    geometry_changed(dev);
    return SY_GL_OK;
}

/* >>texture */
/* Halves an RGBA float image (box filter; odd edges clamp). */
static void halve(const float *src, uint32_t w, uint32_t h, float *dst, uint32_t *ow, uint32_t *oh)
{
    uint32_t nw = w > 1 ? w / 2 : 1, nh = h > 1 ? h / 2 : 1;
    for (uint32_t y = 0; y < nh; ++y)
        for (uint32_t x = 0; x < nw; ++x)
            for (int c = 0; c < 4; ++c) {
                uint32_t x0 = x * 2 < w ? x * 2 : w - 1, x1 = x * 2 + 1 < w ? x * 2 + 1 : w - 1;
                uint32_t y0 = y * 2 < h ? y * 2 : h - 1, y1 = y * 2 + 1 < h ? y * 2 + 1 : h - 1;
                dst[((size_t)y * nw + x) * 4 + c] =
                    0.25f * (src[((size_t)y0 * w + x0) * 4 + c] + src[((size_t)y0 * w + x1) * 4 + c] +
                             src[((size_t)y1 * w + x0) * 4 + c] + src[((size_t)y1 * w + x1) * 4 + c]);
            }
    *ow = nw;
    *oh = nh;
}

static float srgb_to_linear(float c) { return c <= 0.04045f ? c / 12.92f : powf((c + 0.055f) / 1.055f, 2.4f); }
static float linear_to_srgb(float c) { return c <= 0.0031308f ? c * 12.92f : 1.055f * powf(c, 1.0f / 2.4f) - 0.055f; }

sy_gl_result sy_gl_texture_create(sy_gl_device *dev, const sy_gl_texture_desc *d, sy_gl_texture *out, char *err,
                                  size_t err_len)
{
    out->id = 0;
    if (!d || !d->pixels || d->width == 0 || d->height == 0 || d->channels < 1 || d->channels > 4)
        return fail(err, err_len, SY_GL_ERROR_INVALID_ARGUMENT, "texture: needs pixels, a non-zero size and 1..4 channels");
    if (d->format != SY_GL_TEXEL_UNORM8 && d->format != SY_GL_TEXEL_UNORM8_SRGB && d->format != SY_GL_TEXEL_FLOAT32)
        return fail(err, err_len, SY_GL_ERROR_INVALID_ARGUMENT, "texture: unknown texel format %d", (int)d->format);
    size_t n = (size_t)d->width * d->height;
    if (n / d->width != d->height || n > ((size_t)1 << 32))
        return fail(err, err_len, SY_GL_ERROR_LIMIT, "texture: %ux%u is too large", d->width, d->height);
    bool is_float = d->format == SY_GL_TEXEL_FLOAT32, srgb = d->format == SY_GL_TEXEL_UNORM8_SRGB;
    bool downscale = d->width > dev->max_tex || d->height > dev->max_tex;
    const unsigned char *u8 = d->pixels;
    const float *f32 = d->pixels;
    uint32_t ch = d->channels, w = d->width, h = d->height;
    float *img = NULL;          /* RGBA float: float textures, and 8-bit ones that need downscaling */
    unsigned char *img8 = NULL; /* RGBA8: 8-bit textures within the limit (no conversion) */
    if (!is_float && !downscale) {
        img8 = malloc(n * 4);
        if (!img8) return fail(err, err_len, SY_GL_ERROR_OUT_OF_MEMORY, "texture: out of memory (%ux%u)", d->width, d->height);
        for (size_t i = 0; i < n; ++i) {
            const unsigned char *s = u8 + i * ch;
            unsigned char *o = img8 + i * 4;
            if (ch <= 2) o[0] = o[1] = o[2] = s[0], o[3] = ch == 2 ? s[1] : 255;
            else o[0] = s[0], o[1] = s[1], o[2] = s[2], o[3] = ch == 4 ? s[3] : 255;
        }
    } else {
        /* expand to RGBA (grey -> rgb, grey+alpha -> rgb+a) in float, filter in linear space */
        img = malloc(n * 4 * sizeof *img);
        if (!img) return fail(err, err_len, SY_GL_ERROR_OUT_OF_MEMORY, "texture: out of memory (%ux%u)", d->width, d->height);
        for (size_t i = 0; i < n; ++i) {
            float v[4] = {0, 0, 0, 1};
            for (uint32_t c = 0; c < ch; ++c) v[c] = is_float ? f32[i * ch + c] : (float)u8[i * ch + c] / 255.0f;
            if (ch <= 2) {
                if (ch == 2) v[3] = v[1];
                v[1] = v[2] = v[0];
            }
            if (srgb)
                for (int c = 0; c < 3; ++c) v[c] = srgb_to_linear(v[c]);
            memcpy(img + i * 4, v, sizeof v);
        }
    }
    if (downscale) {
        uint32_t ow = w, oh = h;
        while (w > dev->max_tex || h > dev->max_tex) {
            float *nimg = malloc((size_t)(w > 1 ? w / 2 : 1) * (h > 1 ? h / 2 : 1) * 4 * sizeof *nimg);
            if (!nimg) {
                free(img);
                return fail(err, err_len, SY_GL_ERROR_OUT_OF_MEMORY, "texture: out of memory while downscaling");
            }
            halve(img, w, h, nimg, &w, &h);
            free(img);
            img = nimg;
        }
        warn(dev, "raster: texture %ux%u exceeds the GL limit of %u texels per side; downscaled to %ux%u", ow, oh,
             dev->max_tex, w, h);
    }
    sy_gl_result r = current(dev, err, err_len);
    tex_o *t = r == SY_GL_OK ? pool_alloc(&dev->textures) : NULL;
    if (r == SY_GL_OK && !t) r = fail(err, err_len, SY_GL_ERROR_OUT_OF_MEMORY, "texture: out of memory");
    size_t count = (size_t)w * h;
    if (r == SY_GL_OK && !is_float && !img8) { /* downscaled 8-bit: back to bytes */
        img8 = malloc(count * 4);
        if (!img8) r = fail(err, err_len, SY_GL_ERROR_OUT_OF_MEMORY, "texture: out of memory");
        for (size_t i = 0; img8 && i < count * 4; ++i) {
            float v = img[i];
            if (srgb && (i & 3u) != 3u) v = linear_to_srgb(v);
            v = v < 0.0f ? 0.0f : v > 1.0f ? 1.0f : v;
            img8[i] = (unsigned char)lrintf(v * 255.0f);
        }
    }
    if (r != SY_GL_OK) {
        if (t) pool_free(&dev->textures, t);
        free(img);
        free(img8);
        return r;
    }
    const sy_gl_fns *gl = dev->gl;
    t->width = w;
    t->height = h;
    gl->GenTextures(1, &t->tex);
    gl->BindTexture(GL_TEXTURE_2D, t->tex);
    gl->PixelStorei(GL_UNPACK_ALIGNMENT, 1);
    if (is_float) {
        gl->TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, (GLsizei)w, (GLsizei)h, 0, GL_RGBA, GL_FLOAT, img);
        dev->counts.texture_bytes += count * 16;
    } else {
        gl->TexImage2D(GL_TEXTURE_2D, 0, srgb ? GL_SRGB8_ALPHA8 : GL_RGBA8, (GLsizei)w, (GLsizei)h, 0, GL_RGBA,
                       GL_UNSIGNED_BYTE, img8);
        dev->counts.texture_bytes += count * 4;
    }
    free(img);
    free(img8);
    dev->counts.texture_uploads++;
    gl->GenerateMipmap(GL_TEXTURE_2D);
    static const GLint wraps[3] = {GL_REPEAT, GL_CLAMP_TO_EDGE, GL_MIRRORED_REPEAT};
    gl->TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, wraps[(unsigned)d->wrap_s < 3u ? d->wrap_s : 0]);
    gl->TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, wraps[(unsigned)d->wrap_t < 3u ? d->wrap_t : 0]);
    gl->TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, d->nearest ? GL_NEAREST : GL_LINEAR);
    gl->TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, d->nearest ? GL_NEAREST_MIPMAP_LINEAR : GL_LINEAR_MIPMAP_LINEAR);
    r = gl_check(dev, "texture upload", err, err_len);
    if (r != SY_GL_OK) {
        sy_gl_texture_destroy(dev, (sy_gl_texture){t->h.id});
        return r;
    }
    out->id = t->h.id;
    return SY_GL_OK;
}

sy_gl_result sy_gl_texture_destroy(sy_gl_device *dev, sy_gl_texture tex)
{
    tex_o *t = pool_get(&dev->textures, tex.id);
    if (!t) return SY_GL_ERROR_INVALID_HANDLE;
    if (current(dev, NULL, 0) == SY_GL_OK) dev->gl->DeleteTextures(1, &t->tex);
    pool_free(&dev->textures, t);
    if (tex.id == dev->env_tex.id) { /* the environment is gone: no environment light */
        dev->env_tex.id = 0;
        dev->env_dirty = true;
    }
    return SY_GL_OK;
}

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
}

static sy_gl_result material_check(const sy_gl_material_desc *d, char *err, size_t len)
{
    const float *v[] = {d->base_color, d->base_color + 1, d->base_color + 2, d->base_color + 3, &d->metallic,
                        &d->roughness, d->emissive, d->emissive + 1, d->emissive + 2, &d->normal_scale,
                        &d->occlusion_strength, &d->specular, &d->transmission, &d->ior, &d->alpha_cutoff};
    for (size_t i = 0; i < sizeof v / sizeof v[0]; ++i)
        if (!isfinite(*v[i])) return fail(err, len, SY_GL_ERROR_INVALID_ARGUMENT, "material: parameter %zu is not finite", i);
    if ((unsigned)d->alpha_mode > 2u)
        return fail(err, len, SY_GL_ERROR_INVALID_ARGUMENT, "material: unknown alpha mode %d", (int)d->alpha_mode);
    const sy_gl_texture_ref *refs[5] = {&d->base_color_texture, &d->metallic_roughness_texture, &d->normal_texture,
                                        &d->occlusion_texture, &d->emissive_texture};
    for (int i = 0; i < 5; ++i)
        for (int k = 0; refs[i]->transformed && k < 6; ++k)
            if (!isfinite(refs[i]->transform[k]))
                return fail(err, len, SY_GL_ERROR_INVALID_ARGUMENT, "material: texture %d transform[%d] is not finite", i, k);
    return SY_GL_OK;
}

static void material_upload(sy_gl_device *dev, mat_o *m, bool create)
{
    mat_block b;
    material_block(dev, &m->d, &b);
    const sy_gl_fns *gl = dev->gl;
    gl->BindBuffer(GL_UNIFORM_BUFFER, m->ubo);
    if (create) gl->BufferData(GL_UNIFORM_BUFFER, sizeof b, &b, GL_DYNAMIC_DRAW);
    else gl->BufferSubData(GL_UNIFORM_BUFFER, 0, sizeof b, &b);
    count_buffer(dev, true, sizeof b);
    if (!dev->forward) mtab_set(dev, m->h.id & IDX_MASK, &m->d); /* beyond the table: shaded forward */
}

sy_gl_result sy_gl_material_create(sy_gl_device *dev, const sy_gl_material_desc *d, sy_gl_material *out, char *err,
                                   size_t err_len)
{
    out->id = 0;
    sy_gl_result r = material_check(d, err, err_len);
    if (r == SY_GL_OK) r = current(dev, err, err_len);
    if (r != SY_GL_OK) return r;
    mat_o *m = pool_alloc(&dev->materials);
    if (!m) return fail(err, err_len, SY_GL_ERROR_OUT_OF_MEMORY, "material: out of memory");
    m->d = *d;
    dev->gl->GenBuffers(1, &m->ubo);
    material_upload(dev, m, true);
    out->id = m->h.id;
    return SY_GL_OK;
}

sy_gl_result sy_gl_material_update(sy_gl_device *dev, sy_gl_material mat, const sy_gl_material_desc *d, char *err,
                                   size_t err_len)
{
    mat_o *m = pool_get(&dev->materials, mat.id);
    if (!m) return fail(err, err_len, SY_GL_ERROR_INVALID_HANDLE, "material update: stale handle %u", mat.id);
    sy_gl_result r = material_check(d, err, err_len);
    if (r == SY_GL_OK) r = current(dev, err, err_len);
    if (r != SY_GL_OK) return r;
    bool shadows = caster_kind(&m->d) != caster_kind(d) || m->d.alpha_mode != SY_GL_ALPHA_OPAQUE ||
                   memcmp(m->d.emissive, d->emissive, sizeof d->emissive) != 0;
    m->d = *d;
    material_upload(dev, m, false);
    if (shadows) geometry_changed(dev); /* shadow casters changed */
    dev->probes_dirty = true;              /* what the probes see changed */
    return SY_GL_OK;
}

sy_gl_result sy_gl_material_destroy(sy_gl_device *dev, sy_gl_material mat)
{
    mat_o *m = pool_get(&dev->materials, mat.id);
    if (!m) return SY_GL_ERROR_INVALID_HANDLE;
    if (current(dev, NULL, 0) == SY_GL_OK) dev->gl->DeleteBuffers(1, &m->ubo);
    pool_free(&dev->materials, m);
    return SY_GL_OK;
}

/* >>instance/light */
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
    if (!m4_invert(t, inv)) {
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

sy_gl_result sy_gl_instance_create(sy_gl_device *dev, const sy_gl_instance_desc *d, sy_gl_instance *out, char *err,
                                   size_t err_len)
{
    out->id = 0;
    if (!pool_get(&dev->meshes, d->mesh.id))
        return fail(err, err_len, SY_GL_ERROR_INVALID_HANDLE, "instance: mesh handle %u is stale", d->mesh.id);
    inst_o tmp;
    if (!set_model(&tmp, d->transform))
        return fail(err, err_len, SY_GL_ERROR_INVALID_ARGUMENT, "instance: transform is not finite and invertible");
    inst_o *in = pool_alloc(&dev->instances);
    if (!in) return fail(err, err_len, SY_GL_ERROR_OUT_OF_MEMORY, "instance: out of memory");
    set_model(in, d->transform);
    in->mesh = d->mesh;
    in->material = d->material;
    in->visible = !d->hidden;
    dev->counts.model_matrix_updates++;
    geometry_changed(dev);
    out->id = in->h.id;
    return SY_GL_OK;
}

sy_gl_result sy_gl_instance_set_transform(sy_gl_device *dev, sy_gl_instance inst, const float t[16], char *err,
                                          size_t err_len)
{
    inst_o *in = pool_get(&dev->instances, inst.id);
    if (!in) return fail(err, err_len, SY_GL_ERROR_INVALID_HANDLE, "instance transform: stale handle %u", inst.id);
    if (!set_model(in, t))
        return fail(err, err_len, SY_GL_ERROR_INVALID_ARGUMENT, "instance transform: not finite and invertible");
    dev->counts.model_matrix_updates++;
    geometry_changed(dev);
    return SY_GL_OK;
}

sy_gl_result sy_gl_instance_set_material(sy_gl_device *dev, sy_gl_instance inst, sy_gl_material mat)
{
    inst_o *in = pool_get(&dev->instances, inst.id);
    if (!in) return SY_GL_ERROR_INVALID_HANDLE;
    if (in->material.id != mat.id) geometry_changed(dev); /* shadow casters and probes */
    in->material = mat;
    return SY_GL_OK;
}

sy_gl_result sy_gl_instance_set_visible(sy_gl_device *dev, sy_gl_instance inst, bool visible)
{
    inst_o *in = pool_get(&dev->instances, inst.id);
    if (!in) return SY_GL_ERROR_INVALID_HANDLE;
    if (in->visible != visible) geometry_changed(dev);
    in->visible = visible;
    return SY_GL_OK;
}

sy_gl_result sy_gl_instance_destroy(sy_gl_device *dev, sy_gl_instance inst)
{
    inst_o *in = pool_get(&dev->instances, inst.id);
    if (!in) return SY_GL_ERROR_INVALID_HANDLE;
    pool_free(&dev->instances, in);
    geometry_changed(dev);
    return SY_GL_OK;
}

static sy_gl_result light_check(const sy_gl_light_desc *d, char *err, size_t len)
{
    if (d->type != SY_GL_LIGHT_POINT && d->type != SY_GL_LIGHT_SPOT && d->type != SY_GL_LIGHT_DIRECTIONAL)
        return fail(err, len, SY_GL_ERROR_INVALID_ARGUMENT, "light: unknown type %d", (int)d->type);
    const float *v[] = {d->color, d->color + 1, d->color + 2, &d->intensity, d->position, d->position + 1,
                        d->position + 2, d->direction, d->direction + 1, d->direction + 2, &d->range,
                        &d->inner_cone_angle, &d->outer_cone_angle};
    for (size_t i = 0; i < sizeof v / sizeof v[0]; ++i)
        if (!isfinite(*v[i])) return fail(err, len, SY_GL_ERROR_INVALID_ARGUMENT, "light: parameter %zu is not finite", i);
    if (d->type != SY_GL_LIGHT_POINT && !(fabsf(d->direction[0]) + fabsf(d->direction[1]) + fabsf(d->direction[2]) > 0.0f))
        return fail(err, len, SY_GL_ERROR_INVALID_ARGUMENT, "light: zero direction");
    return SY_GL_OK;
}

sy_gl_result sy_gl_light_create(sy_gl_device *dev, const sy_gl_light_desc *d, sy_gl_light *out, char *err,
                                size_t err_len)
{
    out->id = 0;
    sy_gl_result r = light_check(d, err, err_len);
    if (r != SY_GL_OK) return r;
    light_o *l = pool_alloc(&dev->lights);
    if (!l) return fail(err, err_len, SY_GL_ERROR_OUT_OF_MEMORY, "light: out of memory");
    l->d = *d;
    dev->lights_dirty = true;
    out->id = l->h.id;
    return SY_GL_OK;
}

sy_gl_result sy_gl_light_update(sy_gl_device *dev, sy_gl_light light, const sy_gl_light_desc *d, char *err,
                                size_t err_len)
{
    light_o *l = pool_get(&dev->lights, light.id);
    if (!l) return fail(err, err_len, SY_GL_ERROR_INVALID_HANDLE, "light update: stale handle %u", light.id);
    sy_gl_result r = light_check(d, err, err_len);
    if (r != SY_GL_OK) return r;
    l->d = *d;
    dev->lights_dirty = true;
    return SY_GL_OK;
}

sy_gl_result sy_gl_light_destroy(sy_gl_device *dev, sy_gl_light light)
{
    light_o *l = pool_get(&dev->lights, light.id);
    if (!l) return SY_GL_ERROR_INVALID_HANDLE;
    pool_free(&dev->lights, l);
    dev->lights_dirty = true;
    return SY_GL_OK;
}

void sy_gl_set_background(sy_gl_device *dev, sy_gl_background_mode mode, const float color[4], sy_gl_texture texture,
                          float intensity)
{
    if ((unsigned)mode > (unsigned)SY_GL_BACKGROUND_TEXTURE) {
        warn(dev, "raster: unknown background mode %d; using a transparent background", (int)mode);
        mode = SY_GL_BACKGROUND_NONE;
    }
    float c[4] = {0, 0, 0, 0};
    if (mode == SY_GL_BACKGROUND_COLOR && color)
        for (int i = 0; i < 4; ++i) {
            c[i] = color[i];
            if (!isfinite(c[i]) || c[i] < 0.0f) {
                warn(dev, "raster: background colour component %d (%g) is not a finite non-negative value; using 0", i,
                     (double)c[i]);
                c[i] = 0.0f;
            }
        }
    if (!isfinite(intensity) || intensity < 0.0f) {
        warn(dev, "raster: background intensity %g is not a finite non-negative value; using 0", (double)intensity);
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
        warn(dev, "raster: environment intensity %g is not a finite non-negative value; using 0", (double)intensity);
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
            warn(dev, "raster: ambient radiance[%d] = %g is not a finite non-negative value; using 0", c, (double)a[c]);
            a[c] = 0.0f;
        }
    }
    if (memcmp(a, dev->ambient, sizeof a)) {
        memcpy(dev->ambient, a, sizeof a);
        dev->lights_dirty = true;
    }
}

sy_gl_result sy_gl_set_area_lights(sy_gl_device *dev, const sy_gl_area_light *lights, uint32_t count, char *err,
                                   size_t err_len)
{
    if (count > SY_GL_MAX_AREA_LIGHTS)
        return fail(err, err_len, SY_GL_ERROR_LIMIT, "area lights: %u exceed the limit of %d", count, SY_GL_MAX_AREA_LIGHTS);
    if (count && !lights) return fail(err, err_len, SY_GL_ERROR_INVALID_ARGUMENT, "area lights: NULL array");
    for (uint32_t i = 0; i < count; ++i) {
        const sy_gl_area_light *a = &lights[i];
        if (a->vertex_count != 3 && a->vertex_count != 4)
            return fail(err, err_len, SY_GL_ERROR_INVALID_ARGUMENT, "area light %u: %u vertices (3 or 4 expected)", i,
                        a->vertex_count);
        for (uint32_t k = 0; k < a->vertex_count; ++k)
            for (int c = 0; c < 3; ++c)
                if (!isfinite(a->vertices[k][c]))
                    return fail(err, err_len, SY_GL_ERROR_INVALID_ARGUMENT, "area light %u: vertex %u is not finite", i, k);
        for (int c = 0; c < 3; ++c)
            if (!isfinite(a->radiance[c]) || a->radiance[c] < 0.0f)
                return fail(err, err_len, SY_GL_ERROR_INVALID_ARGUMENT,
                            "area light %u: radiance[%d] = %g is not a finite non-negative value", i, c, (double)a->radiance[c]);
    }
    if (count == dev->area_count && (!count || !memcmp(dev->areas, lights, count * sizeof *lights))) return SY_GL_OK;
    if (count) memcpy(dev->areas, lights, count * sizeof *lights);
    dev->area_count = count;
    dev->areas_dirty = true;
    dev->lights_dirty = true;
    return SY_GL_OK;
}

bool sy_gl_window_should_close(sy_gl_device *dev) { return sy_gl_context_should_close(dev->ctx); }

/* >>render */
static void scene_bounds(const sy_gl_device *dev, float *c, float *radius)
{
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t i = 0; i < dev->instances.count; ++i) {
        const inst_o *in = pool_at(&dev->instances, i);
        if (!in->h.id || !in->visible) continue;
        const mesh_o *m = pool_get(&dev->meshes, in->mesh.id);
        if (!m) continue;
        for (int k = 0; k < 8; ++k) {
            float p[3] = {k & 1 ? m->bmax[0] : m->bmin[0], k & 2 ? m->bmax[1] : m->bmin[1], k & 4 ? m->bmax[2] : m->bmin[2]};
            for (int a = 0; a < 3; ++a) {
                float v = in->model[a] * p[0] + in->model[4 + a] * p[1] + in->model[8 + a] * p[2] + in->model[12 + a];
                lo[a] = fminf(lo[a], v);
                hi[a] = fmaxf(hi[a], v);
            }
        }
    }
    if (!(lo[0] <= hi[0])) {
        c[0] = c[1] = c[2] = 0.0f;
        *radius = 1.0f;
        return;
    }
    float r2 = 0.0f;
    for (int a = 0; a < 3; ++a) {
        c[a] = 0.5f * (lo[a] + hi[a]);
        r2 += 0.25f * (hi[a] - lo[a]) * (hi[a] - lo[a]);
    }
    *radius = fmaxf(sqrtf(r2), 1e-3f);
}

typedef struct frame_state {
    float shadow_vp[SY_GL_MAX_SHADOW_MAPS][16];
    uint32_t shadow_count;
    float cube_pos[SY_GL_MAX_CUBE_SHADOWS][3], cube_near[SY_GL_MAX_CUBE_SHADOWS], cube_far[SY_GL_MAX_CUBE_SHADOWS];
    uint32_t cube_count; /* point lights with a cube shadow */
} frame_state;

/* Lights UBO (+ shadow matrices from the scene bounds). One upload. */
static void lights_upload(sy_gl_device *dev, frame_state *fs)
{
    float blk[LIGHTS_FLOATS];
    memset(blk, 0, sizeof blk);
    int32_t *ib = (int32_t *)(void *)blk;
    float c[3], R;
    scene_bounds(dev, c, &R);
    uint32_t n = 0, ns = 0;
    for (uint32_t i = 0; i < dev->lights.count; ++i) {
        const light_o *l = pool_at(&dev->lights, i);
        if (!l->h.id) continue;
        if (n == SY_GL_MAX_LIGHTS) {
            if (!dev->warned_lights)
                warn(dev, "raster: more than %d lights; the rest are ignored", SY_GL_MAX_LIGHTS);
            dev->warned_lights = true;
            break;
        }
        const sy_gl_light_desc *d = &l->d;
        float *o = blk + 88 + 16 * n;
        float dir[3] = {d->direction[0], d->direction[1], d->direction[2]};
        v3_norm(dir);
        memcpy(o, d->position, 3 * sizeof(float));
        o[3] = (float)d->type;
        memcpy(o + 4, dir, sizeof dir);
        o[7] = d->range;
        for (int k = 0; k < 3; ++k) o[8 + k] = d->color[k] * d->intensity;
        float ci = cosf(d->inner_cone_angle), co = cosf(d->outer_cone_angle);
        o[12] = 1.0f / fmaxf(0.001f, ci - co);
        o[13] = -co * o[12];
        o[14] = -1.0f;
        o[15] = -1.0f;
        if (d->type == SY_GL_LIGHT_POINT && !d->no_shadow && fs->cube_count < SY_GL_MAX_CUBE_SHADOWS) {
            /* a depth cube map around the light (GL's face order and orientation, seamless
             * filtering); the shader compares the window depth of the major axis */
            uint32_t slot = fs->cube_count++;
            float dc = sqrtf((d->position[0] - c[0]) * (d->position[0] - c[0]) +
                             (d->position[1] - c[1]) * (d->position[1] - c[1]) +
                             (d->position[2] - c[2]) * (d->position[2] - c[2]));
            float far = dc + R, nearp = fmaxf(1e-3f * far, 1e-4f);
            memcpy(fs->cube_pos[slot], d->position, sizeof fs->cube_pos[slot]);
            fs->cube_near[slot] = nearp;
            fs->cube_far[slot] = far;
            blk[LIGHTS_CUBE_PAR + 4 * slot] = nearp;
            blk[LIGHTS_CUBE_PAR + 4 * slot + 1] = far;
            blk[LIGHTS_CUBE_PAR + 4 * slot + 2] = 1.5f * 2.0f / (float)dev->cube_size; /* normal offset per unit distance */
            o[15] = (float)slot;
        }
        if (d->type != SY_GL_LIGHT_POINT && !d->no_shadow && ns < SY_GL_MAX_SHADOW_MAPS) {
            float view[16], proj[16];
            float S = (float)dev->shadow_size;
            if (d->type == SY_GL_LIGHT_DIRECTIONAL) {
                float eye[3] = {c[0] - dir[0] * 2.0f * R, c[1] - dir[1] * 2.0f * R, c[2] - dir[2] * 2.0f * R};
                look_along(eye, dir, view);
                projection(true, -R, R, -R, R, 0.5 * R, 3.5 * R, proj);
                blk[72 + 4 * ns] = 1.5f * 2.0f * R / S;
                blk[72 + 4 * ns + 1] = 0.0f;
            } else {
                float half = fminf(d->outer_cone_angle + 0.01f, 1.48f), t = tanf(half);
                float dc = sqrtf((d->position[0] - c[0]) * (d->position[0] - c[0]) +
                                 (d->position[1] - c[1]) * (d->position[1] - c[1]) +
                                 (d->position[2] - c[2]) * (d->position[2] - c[2]));
                double far = dc + R, nearp = fmax(1e-3 * far, 1e-4);
                look_along(d->position, dir, view);
                projection(false, -t, t, -t, t, nearp, far, proj);
                blk[72 + 4 * ns] = 1.5f * 2.0f * t / S;
                blk[72 + 4 * ns + 1] = 1.0f;
            }
            m4_mul(proj, view, fs->shadow_vp[ns]);
            memcpy(blk + 8 + 16 * ns, fs->shadow_vp[ns], 16 * sizeof(float));
            o[14] = (float)ns;
            ns++;
        }
        n++;
    }
    ib[0] = (int32_t)n;
    blk[4] = (float)(SY_GL_IBL_SPEC_LEVELS - 1); /* l_env.x: the roughness-1 mip of the specular cube */
    memcpy(blk + 5, dev->ambient, sizeof dev->ambient); /* l_env.yzw: the area lights' indirect radiance */
    /* emissive polygons: one shadow map each from its centre along its emitting normal (a 150 degree
     * frustum) while maps are left; penumbrae widen with the polygon's size (sy_gl.h) */
    float ab[AREAS_FLOATS];
    memset(ab, 0, sizeof ab);
    int32_t *aib = (int32_t *)(void *)ab;
    uint32_t ns_punctual = ns;
    aib[0] = (int32_t)dev->area_count;
    for (uint32_t i = 0; i < dev->area_count; ++i) {
        const sy_gl_area_light *a = &dev->areas[i];
        float *o = ab + 8 + 24 * i, cen[3] = {0, 0, 0}, e1[3], e2[3], nrm[3];
        for (uint32_t k = 0; k < 4; ++k) {
            const float *v = a->vertices[k < a->vertex_count ? k : a->vertex_count - 1];
            memcpy(o + 4 * k, v, 3 * sizeof(float));
            if (k < a->vertex_count)
                for (int c = 0; c < 3; ++c) cen[c] += v[c] / (float)a->vertex_count;
        }
        o[3] = (float)a->vertex_count;
        memcpy(o + 16, a->radiance, 3 * sizeof(float));
        o[19] = a->double_sided ? 1.0f : 0.0f;
        memcpy(o + 20, cen, sizeof cen);
        o[23] = -1.0f;
        for (int c = 0; c < 3; ++c) {
            e1[c] = a->vertices[1][c] - a->vertices[0][c];
            e2[c] = a->vertices[2][c] - a->vertices[0][c];
        }
        cross3(e1, e2, nrm);
        float area2 = sqrtf(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]) * (a->vertex_count == 4 ? 1.0f : 0.5f);
        if (!a->double_sided) { /* a_dir: flux-weighted mean emission direction (two-sided: none) */
            float flux = (0.2126f * a->radiance[0] + 0.7152f * a->radiance[1] + 0.0722f * a->radiance[2]) * area2, l = sqrtf(dot3f(nrm, nrm));
            for (int c = 0; c < 3 && l > 0.0f; ++c) ab[4 + c] += flux * nrm[c] / l;
            ab[7] += flux;
        } else
            ab[7] += 2.0f * (0.2126f * a->radiance[0] + 0.7152f * a->radiance[1] + 0.0722f * a->radiance[2]) * area2;
        if (!(area2 > 0.0f) || ns >= SY_GL_MAX_SHADOW_MAPS) continue;
        v3_norm(nrm);
        float view[16], proj[16], t = tanf(75.0f * 3.14159265f / 180.0f), S = (float)dev->shadow_size;
        float dc = sqrtf((cen[0] - c[0]) * (cen[0] - c[0]) + (cen[1] - c[1]) * (cen[1] - c[1]) + (cen[2] - c[2]) * (cen[2] - c[2]));
        double far = dc + R, nearp = fmax(1e-3 * far, 1e-4);
        look_along(cen, nrm, view);
        projection(false, -t, t, -t, t, nearp, far, proj);
        m4_mul(proj, view, fs->shadow_vp[ns]);
        memcpy(blk + 8 + 16 * ns, fs->shadow_vp[ns], 16 * sizeof(float));
        blk[72 + 4 * ns] = 1.5f * 2.0f * t / S;
        blk[72 + 4 * ns + 1] = 1.0f;
        blk[72 + 4 * ns + 2] = 0.15f * sqrtf(area2) / t; /* penumbra radius (uv) x distance */
        blk[72 + 4 * ns + 3] = 2.0f * t;
        o[23] = (float)ns;
        ns++;
    }
    for (int c = 0; c < 3; ++c) ab[4 + c] = ab[7] > 0.0f ? ab[4 + c] / ab[7] : 0.0f;
    ab[7] = 0.0f;
    fs->shadow_count = ns;
    dev->light_count = n;
    dev->light_sig = 0;
    for (uint32_t i = 0; i < n && i < VAR_NL_MAX; ++i) { /* 0 none, 1 a 2D map, 2 + s cube slot s */
        const float *o = blk + 88 + 16 * i;
        uint64_t kind = o[14] >= 0.0f ? 1u : o[15] >= 0.0f ? 2u + (uint64_t)o[15] : 0u;
        /* 0 point, 1 point with a range, 2 spot, 3 directional (shade_light's lt) */
        uint64_t type = o[3] == (float)SY_GL_LIGHT_DIRECTIONAL ? 3u : o[3] == (float)SY_GL_LIGHT_SPOT ? 2u : o[7] > 0.0f ? 1u : 0u;
        dev->light_sig |= kind << (2 * i) | type << (48 + 2 * i);
    }
    /* a_count.y: the polygons up to the last with a shadow map (the shaders' first loop); z: the
     * shadow taps per polygon (shadow_area's loop bound, a uniform so that it is not unrolled) */
    aib[1] = 0;
    for (uint32_t i = 0; i < dev->area_count; ++i)
        if (ab[8 + 24 * i + 23] >= 0.0f) aib[1] = (int32_t)i + 1;
    aib[2] = 8;
    dev->shadow_count = ns_punctual + fs->cube_count;
    dev->area_shadow_count = ns - ns_punctual;
    dev->gl->BindBuffer(GL_UNIFORM_BUFFER, dev->lights_ubo);
    dev->gl->BufferSubData(GL_UNIFORM_BUFFER, 0, sizeof blk, blk);
    count_buffer(dev, true, sizeof blk);
    if (dev->area_count || dev->areas_dirty) {
        dev->gl->BindBuffer(GL_UNIFORM_BUFFER, dev->areas_ubo);
        dev->gl->BufferSubData(GL_UNIFORM_BUFFER, 0, sizeof ab, ab);
        count_buffer(dev, true, sizeof ab);
        dev->areas_dirty = false;
    }
}

/* Draws level `lod` of the mesh (0 or out of range = the mesh itself); returns the triangles drawn. */
static uint32_t draw_mesh_lod(sy_gl_device *dev, const mesh_o *m, uint32_t lod)
{
    const sy_gl_fns *gl = dev->gl;
    gl->BindVertexArray(m->vao);
    if (!m->has_attr[1]) gl->VertexAttrib4f(1, 0, 0, 1, 0);
    if (!m->has_attr[2]) gl->VertexAttrib4f(2, 0, 0, 0, 0);
    if (!m->has_attr[3]) gl->VertexAttrib4f(3, 0, 0, 0, 0);
    if (!m->has_attr[4]) gl->VertexAttrib4f(4, 1, 1, 1, 1);
    if (lod >= m->lod_count) lod = 0;
    uint32_t tris = m->lod_tris[lod];
    if (m->indexed)
        gl->DrawElements(GL_TRIANGLES, (GLsizei)(3u * tris), GL_UNSIGNED_INT,
                         (const void *)((uintptr_t)m->lod_first[lod] * sizeof(uint32_t)));
    else gl->DrawArrays(GL_TRIANGLES, 0, (GLsizei)(3u * tris));
    dev->draws++;
    return tris;
}

static const mat_o *bind_material(sy_gl_device *dev, sy_gl_material id, bool all_textures)
{
    const sy_gl_fns *gl = dev->gl;
    const mat_o *m = pool_get(&dev->materials, id.id);
    gl->BindBufferBase(GL_UNIFORM_BUFFER, BIND_MATERIAL, m ? m->ubo : dev->default_ubo);
    if (!m) return NULL;
    const sy_gl_texture_ref *refs[5] = {&m->d.base_color_texture, &m->d.metallic_roughness_texture,
                                        &m->d.normal_texture, &m->d.occlusion_texture, &m->d.emissive_texture};
    for (int i = 0; i < (all_textures ? 5 : 1); ++i) {
        const tex_o *t = pool_get(&dev->textures, refs[i]->texture.id);
        gl->ActiveTexture(GL_TEXTURE0 + (GLenum)i);
        gl->BindTexture(GL_TEXTURE_2D, t ? t->tex : dev->standin[i]);
    }
    return m;
}

/* Depth of every shadow caster into the attached depth target, seen through vp. Casters
 * as the ray tracers' shadow rays see them (backends/rt/sy_rt_shadow.c): opaque ones block;
 * alpha-masked ones block where the mask keeps them; alpha-blended ones let 1 - alpha through,
 * which a depth map can only threshold (opacity >= the cutoff, 0.5 unless set, blocks);
 * transmissive ones (transmission x (1 - metallic) >= 0.5) let their tinted transmittance through
 * and cast none; emitters are the lights and cast none either. */
static void draw_casters(sy_gl_device *dev, const float *vp)
{
    const sy_gl_fns *gl = dev->gl;
    gl->Clear(GL_DEPTH_BUFFER_BIT);
    for (int v = 0; v < 2; ++v) {
        gl->UseProgram(dev->ps[v].prog);
        gl->UniformMatrix4fv(dev->ps[v].lightvp, 1, GL_FALSE, vp);
        for (uint32_t i = 0; i < dev->instances.count; ++i) {
            const inst_o *in = pool_at(&dev->instances, i);
            if (!in->h.id || !in->visible) continue;
            const mesh_o *m = pool_get(&dev->meshes, in->mesh.id);
            const mat_o *mt = pool_get(&dev->materials, in->material.id);
            int kind = mt ? caster_kind(&mt->d) : CASTER_OPAQUE;
            if (!m || kind == CASTER_NONE || (kind == CASTER_MASKED) != (v == 1)) continue;
            bind_material(dev, in->material, false);
            gl->UniformMatrix4fv(dev->ps[v].model, 1, GL_FALSE, in->model);
            draw_mesh_lod(dev, m, in->lod); /* the level of the last camera view */
        }
    }
}

/* The shadow maps' depth array, made on the first frame with a shadowed light: a scene without one
 * never allocates it (64 MiB zeroed by llvmpipe at the default 2048 texels, 0.2 s of a small first
 * frame). Its side is halved while the GL cannot hold it (the array of SY_GL_MAX_SHADOW_MAPS and a
 * point light's cube, made later, tried here): at 16384 texels the array alone is 4 GiB, and
 * llvmpipe refuses textures of 1 GiB and more with GL_OUT_OF_MEMORY. */
static sy_gl_result shadow_maps_make(sy_gl_device *dev, char *err, size_t err_len)
{
    const sy_gl_fns *gl = dev->gl;
    sy_gl_result r = gl_check(dev, "before the shadow maps", err, err_len);
    if (r != SY_GL_OK || dev->shadow_tex) return r;
    uint32_t asked = dev->shadow_size;
    for (;;) {
        dev->cube_size = dev->shadow_size / 2u > 16u ? dev->shadow_size / 2u : 16u;
        dev->shadow_tex = shadow_array(gl, dev->shadow_size, SY_GL_MAX_SHADOW_MAPS);
        GLenum e = gl->GetError();
        if (e == GL_NO_ERROR) {
            GLuint cube = shadow_cube(gl, dev->cube_size);
            e = gl->GetError();
            gl->DeleteTextures(1, &cube);
        }
        if (e != GL_OUT_OF_MEMORY || dev->shadow_size <= 16u) {
            if (e != GL_NO_ERROR) {
                gl->DeleteTextures(1, &dev->shadow_tex);
                dev->shadow_tex = 0;
                dev->shadow_size = asked;
                return fail(err, err_len, e == GL_OUT_OF_MEMORY ? SY_GL_ERROR_OUT_OF_MEMORY : SY_GL_ERROR_GL,
                            "shadow maps of %u texels: OpenGL error 0x%04x", asked, (unsigned)e);
            }
            break;
        }
        gl->DeleteTextures(1, &dev->shadow_tex);
        dev->shadow_tex = 0;
        dev->shadow_size /= 2u;
    }
    if (dev->shadow_size != asked)
        warn(dev, "raster: shadow_map_size %u: the GL context cannot hold %d maps of that size; using %u", asked,
             SY_GL_MAX_SHADOW_MAPS, dev->shadow_size);
    return SY_GL_OK;
}

static void render_shadows(sy_gl_device *dev, const frame_state *fs)
{
    const sy_gl_fns *gl = dev->gl;
    gl->BindFramebuffer(GL_FRAMEBUFFER, dev->shadow_fbo);
    gl->DrawBuffer(GL_NONE);
    gl->ReadBuffer(GL_NONE);
    gl->Enable(GL_DEPTH_TEST);
    gl->DepthFunc(GL_LESS);
    gl->DepthMask(GL_TRUE);
    gl->Disable(GL_BLEND);
    gl->Enable(GL_POLYGON_OFFSET_FILL);
    gl->PolygonOffset(1.5f, 4.0f);
    gl->Viewport(0, 0, (GLsizei)dev->shadow_size, (GLsizei)dev->shadow_size);
    for (uint32_t s = 0; s < fs->shadow_count; ++s) {
        gl->FramebufferTextureLayer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, dev->shadow_tex, 0, (GLint)s);
        draw_casters(dev, fs->shadow_vp[s]);
    }
    if (fs->cube_count) gl->Viewport(0, 0, (GLsizei)dev->cube_size, (GLsizei)dev->cube_size);
    for (uint32_t c = 0; c < fs->cube_count; ++c) {
        if (!dev->cube_tex[c]) dev->cube_tex[c] = shadow_cube(gl, dev->cube_size);
        float proj[16], view[16], vp[16];
        projection(false, -1.0, 1.0, -1.0, 1.0, fs->cube_near[c], fs->cube_far[c], proj);
        for (int f = 0; f < 6; ++f) {
            cube_face_view(fs->cube_pos[c], f, view);
            m4_mul(proj, view, vp);
            gl->FramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_CUBE_MAP_POSITIVE_X + (GLenum)f,
                                     dev->cube_tex[c], 0);
            draw_casters(dev, vp);
        }
    }
    gl->Disable(GL_POLYGON_OFFSET_FILL);
    dev->shadow_maps = fs->shadow_count + 6u * fs->cube_count;
}

static void frame_end(sy_gl_device *dev)
{
    const uint64_t *now = (const uint64_t *)&dev->counts, *mark = (const uint64_t *)&dev->mark;
    uint64_t *fr = (uint64_t *)&dev->frame;
    for (size_t i = 0; i < sizeof dev->counts / sizeof(uint64_t); ++i) fr[i] = now[i] - mark[i];
    dev->mark = dev->counts;
}

static sy_gl_result targets_ensure(sy_gl_device *dev, uint32_t w, uint32_t h, char *err, size_t len)
{
    targets *t = &dev->t;
    if (t->fbo && t->w == w && t->h == h && t->samples == dev->msaa) return SY_GL_OK;
    targets_free(dev, t);
    const sy_gl_fns *gl = dev->gl;
    t->w = w;
    t->h = h;
    t->samples = dev->msaa;
    GLenum target = t->samples > 1 ? GL_TEXTURE_2D_MULTISAMPLE : GL_TEXTURE_2D;
    gl->GenFramebuffers(1, &t->fbo);
    gl->BindFramebuffer(GL_FRAMEBUFFER, t->fbo);
    GLuint *texs[2] = {&t->color, &t->depthlin};
    GLenum fmts[2] = {GL_RGBA32F, GL_R32F};
    for (int i = 0; i < 2; ++i) {
        gl->GenTextures(1, texs[i]);
        gl->BindTexture(target, *texs[i]);
        if (t->samples > 1)
            gl->TexImage2DMultisample(target, (GLsizei)t->samples, fmts[i], (GLsizei)w, (GLsizei)h, GL_TRUE);
        else {
            gl->TexImage2D(target, 0, (GLint)fmts[i], (GLsizei)w, (GLsizei)h, 0, i ? GL_RED : GL_RGBA, GL_FLOAT, NULL);
            gl->TexParameteri(target, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
            gl->TexParameteri(target, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        }
        gl->FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0 + (GLenum)i, target, *texs[i], 0);
    }
    gl->GenRenderbuffers(1, &t->depth_rb);
    gl->BindRenderbuffer(GL_RENDERBUFFER, t->depth_rb);
    gl->RenderbufferStorageMultisample(GL_RENDERBUFFER, t->samples > 1 ? (GLsizei)t->samples : 0, GL_DEPTH_COMPONENT32F,
                                       (GLsizei)w, (GLsizei)h);
    gl->FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, t->depth_rb);
    GLenum st = gl->CheckFramebufferStatus(GL_FRAMEBUFFER);
    if (st != GL_FRAMEBUFFER_COMPLETE)
        return fail(err, len, SY_GL_ERROR_GL, "render target %ux%u (%u samples): framebuffer incomplete (0x%04x)", w, h,
                    t->samples, (unsigned)st);
    if (t->samples > 1) {
        gl->GenFramebuffers(1, &t->rfbo);
        gl->BindFramebuffer(GL_FRAMEBUFFER, t->rfbo);
        GLuint *rt[2] = {&t->rcolor, &t->rdepthlin};
        for (int i = 0; i < 2; ++i) {
            gl->GenTextures(1, rt[i]);
            gl->BindTexture(GL_TEXTURE_2D, *rt[i]);
            gl->TexImage2D(GL_TEXTURE_2D, 0, (GLint)fmts[i], (GLsizei)w, (GLsizei)h, 0, i ? GL_RED : GL_RGBA, GL_FLOAT, NULL);
            gl->TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
            gl->TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
            gl->FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0 + (GLenum)i, GL_TEXTURE_2D, *rt[i], 0);
        }
        st = gl->CheckFramebufferStatus(GL_FRAMEBUFFER);
        if (st != GL_FRAMEBUFFER_COMPLETE)
            return fail(err, len, SY_GL_ERROR_GL, "resolve target %ux%u: framebuffer incomplete (0x%04x)", w, h, (unsigned)st);
    }
    return gl_check(dev, "render targets", err, len);
}

typedef struct view_setup {
    float view[16], proj[16], cam_pos[3], cam_fwd[3];
    bool ortho;
    float ppu; /* pixels per unit of the image plane at distance 1 (perspective) or per metre (ortho); 0 =
                * unknown (levels of detail off) */
} view_setup;

static sy_gl_result view_make(sy_gl_device *dev, const sy_gl_camera *cam, const sy_gl_render_desc *d, view_setup *v,
                              char *err, size_t len)
{
    const float *w = cam->window;
    for (int i = 0; i < 4; ++i)
        if (!isfinite(w[i])) return fail(err, len, SY_GL_ERROR_INVALID_ARGUMENT, "render: camera window[%d] is not finite", i);
    if (!(w[0] < w[1]) || !(w[2] < w[3]))
        return fail(err, len, SY_GL_ERROR_INVALID_ARGUMENT, "render: camera window needs left < right and bottom < top");
    if (!isfinite(cam->near_clip) || cam->near_clip < 0.0f || !isfinite(cam->far_clip) || cam->far_clip < 0.0f ||
        (cam->far_clip > 0.0f && cam->far_clip <= cam->near_clip))
        return fail(err, len, SY_GL_ERROR_INVALID_ARGUMENT, "render: clip range near %g far %g is invalid",
                    (double)cam->near_clip, (double)cam->far_clip);
    if (d->image_width == 0 || d->image_height == 0 || d->width == 0 || d->height == 0 ||
        d->x > d->image_width || d->width > d->image_width - d->x || d->y > d->image_height ||
        d->height > d->image_height - d->y)
        return fail(err, len, SY_GL_ERROR_INVALID_ARGUMENT, "render: rectangle %u,%u %ux%u is outside the %ux%u image",
                    d->x, d->y, d->width, d->height, d->image_width, d->image_height);
    if (!m4_invert(cam->camera_to_world, v->view))
        return fail(err, len, SY_GL_ERROR_INVALID_ARGUMENT, "render: camera matrix is not invertible");
    memcpy(v->cam_pos, cam->camera_to_world + 12, sizeof v->cam_pos);
    for (int i = 0; i < 3; ++i) v->cam_fwd[i] = -cam->camera_to_world[8 + i];
    v3_norm(v->cam_fwd);
    v->ortho = cam->orthographic;
    /* the sub-rectangle's own window of the full-image plane: pixel centres stay where they are */
    double l = w[0], r = w[1], b = w[2], t = w[3], W = d->image_width, H = d->image_height;
    double l2 = l + (r - l) * d->x / W, r2 = l + (r - l) * (d->x + d->width) / W;
    double t2 = t - (t - b) * d->y / H, b2 = t - (t - b) * (d->y + d->height) / H;
    float c[3], R;
    scene_bounds(dev, c, &R);
    double dist = 0.0;
    for (int i = 0; i < 3; ++i) dist += (double)(c[i] - v->cam_pos[i]) * v->cam_fwd[i];
    double n = cam->near_clip, f = cam->far_clip;
    if (!v->ortho && n <= 0.0) n = fmax(1e-5 * (fabs(dist) + R), 1e-6);
    if (v->ortho && f <= 0.0) f = fmax(dist + 2.0 * R, n + 1.0);
    projection(v->ortho, l2, r2, b2, t2, n, f, v->proj);
    v->ppu = (float)((double)d->height / (t2 - b2));
    return SY_GL_OK;
}

/* >>culling and levels of detail */

/* The six planes (inside: dot(p.xyz, x) + p.w >= 0) of a column-major view-projection matrix. */
static void frustum_planes(const float *m, float planes[6][4])
{
    for (int i = 0; i < 3; ++i)
        for (int s = 0; s < 2; ++s) {
            float *p = planes[2 * i + s];
            for (int c = 0; c < 4; ++c) p[c] = m[4 * c + 3] + (s ? -m[4 * c + i] : m[4 * c + i]);
            float len = sqrtf(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]); /* unit normals: distances in metres */
            if (len > 0.0f)
                for (int c = 0; c < 4; ++c) p[c] /= len;
        }
}

/* World-space bounding sphere of an instance: centre into c, radius returned; *scale = the largest
 * axis scale of its model matrix. */
static float world_sphere(const inst_o *in, const mesh_o *m, float c[3], float *scale)
{
    float s2 = 0.0f;
    for (int a = 0; a < 3; ++a) {
        c[a] = in->model[12 + a];
        for (int k = 0; k < 3; ++k) c[a] += in->model[4 * k + a] * m->centre[k];
        float l2 = in->model[4 * a] * in->model[4 * a] + in->model[4 * a + 1] * in->model[4 * a + 1] +
                   in->model[4 * a + 2] * in->model[4 * a + 2];
        s2 = fmaxf(s2, l2);
    }
    *scale = sqrtf(s2);
    return m->radius * *scale;
}

static bool sphere_outside(const float planes[6][4], const float c[3], float r)
{
    for (int i = 0; i < 6; ++i) {
        const float *p = planes[i]; /* unit normal (frustum_planes) */
        if (p[0] * c[0] + p[1] * c[1] + p[2] * c[2] + p[3] < -r) return true;
    }
    return false;
}

static uint32_t choose_lod(const sy_gl_device *dev, const mesh_o *m, const view_setup *v, const float c[3], float r,
                           float scale);

/* Every visible instance's level for view v (before the shadow maps, which reuse them). */
static void choose_lods(sy_gl_device *dev, const view_setup *v)
{
    for (uint32_t i = 0; i < dev->instances.count; ++i) {
        inst_o *in = pool_at(&dev->instances, i);
        const mesh_o *m = in->h.id ? pool_get(&dev->meshes, in->mesh.id) : NULL;
        if (!m) continue;
        float c[3], scale, r = world_sphere(in, m, c, &scale);
        in->lod = choose_lod(dev, m, v, c, r, scale);
    }
}

void sy_gl_set_lod(sy_gl_device *dev, float pixels)
{
    if (dev) dev->lod_pixels = isfinite(pixels) && pixels > 0.0f ? pixels : 0.0f;
}

/* The coarsest level whose deviation, projected at the sphere's nearest distance, stays within
 * dev->lod_pixels pixels (0 when the view's scale is unknown or the view is inside the sphere). */
static uint32_t choose_lod(const sy_gl_device *dev, const mesh_o *m, const view_setup *v, const float c[3], float r,
                           float scale)
{
    if (m->lod_count < 2 || dev->lod_pixels <= 0.0f || v->ppu <= 0.0f) return 0;
    float px_per_m = v->ppu;
    if (!v->ortho) {
        float d = (c[0] - v->cam_pos[0]) * v->cam_fwd[0] + (c[1] - v->cam_pos[1]) * v->cam_fwd[1] +
                  (c[2] - v->cam_pos[2]) * v->cam_fwd[2] - r;
        if (!(d > 1e-6f)) return 0;
        px_per_m /= d;
    }
    uint32_t lod = 0;
    while (lod + 1 < m->lod_count && m->lod_error[lod + 1] * scale * px_per_m <= dev->lod_pixels) ++lod;
    return lod;
}

/* An instance's projected bounding-sphere area (at most the target's) over the triangles of level
 * lod: how many pixels its forward shading would run on per triangle. Deferred shading pays off on
 * small triangles (DEFERRED_MAX_PX_PER_TRI). */
static float pixels_per_triangle(const sy_gl_device *dev, const mesh_o *m, uint32_t lod, const view_setup *v,
                                 const float c[3], float r)
{
    float screen = (float)dev->t.w * (float)dev->t.h, px_per_m = v->ppu;
    if (!(px_per_m > 0.0f)) return screen;
    if (!v->ortho) {
        float d = (c[0] - v->cam_pos[0]) * v->cam_fwd[0] + (c[1] - v->cam_pos[1]) * v->cam_fwd[1] +
                  (c[2] - v->cam_pos[2]) * v->cam_fwd[2] - r;
        if (!(d > 1e-6f)) return screen;
        px_per_m /= d;
    }
    float rp = r * px_per_m, area = 3.14159265f * rp * rp;
    if (!(area < screen)) area = screen;
    uint32_t tris = m->lod_tris[lod < m->lod_count ? lod : 0];
    return tris ? area / (float)tris : screen;
}

static int cmp_far_first(const void *a, const void *b)
{
    const float *x = a, *y = b;
    return x[0] < y[0] ? 1 : x[0] > y[0] ? -1 : 0;
}

/* Fills the bound w x h target with a lat-long texture x intensity along each pixel's ray through
 * view v (depth test and writes off while it draws, depth writes on after). */
static void draw_latlong(sy_gl_device *dev, const view_setup *v, const tex_o *tex, float intensity, uint32_t w,
                         uint32_t h)
{
    const sy_gl_fns *gl = dev->gl;
    float vp[16], inv[16];
    m4_mul(v->proj, v->view, vp);
    if (!m4_invert(vp, inv)) return;
    gl->Disable(GL_DEPTH_TEST);
    gl->DepthMask(GL_FALSE);
    gl->UseProgram(dev->prog_sky);
    gl->UniformMatrix4fv(dev->sky_inv_vp, 1, GL_FALSE, inv);
    const float si[4] = {(float)w, (float)h, intensity, 0.0f};
    gl->Uniform4fv(dev->sky_size_int, 1, si);
    gl->ActiveTexture(GL_TEXTURE0);
    gl->BindTexture(GL_TEXTURE_2D, tex->tex);
    gl->BindVertexArray(dev->empty_vao);
    gl->DrawArrays(GL_TRIANGLES, 0, 3);
    gl->DepthMask(GL_TRUE);
}

static void begin_target(sy_gl_device *dev, const view_setup *v)
{
    const sy_gl_fns *gl = dev->gl;
    gl->BindFramebuffer(GL_FRAMEBUFFER, dev->t.fbo);
    static const GLenum bufs[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    gl->DrawBuffers(2, bufs);
    gl->Viewport(0, 0, (GLsizei)dev->t.w, (GLsizei)dev->t.h);
    gl->ColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    gl->DepthMask(GL_TRUE);
    float bg[4] = {0, 0, 0, 0};
    if (dev->bg_mode == SY_GL_BACKGROUND_COLOR) memcpy(bg, dev->bg_color, sizeof bg);
    const float inf[4] = {INFINITY, 0, 0, 0}, one = 1.0f;
    gl->ClearBufferfv(GL_COLOR, 0, bg);
    gl->ClearBufferfv(GL_COLOR, 1, inf);
    gl->ClearBufferfv(GL_DEPTH, 0, &one);
    const tex_o *sky = dev->bg_mode == SY_GL_BACKGROUND_TEXTURE ? pool_get(&dev->textures, dev->bg_tex.id) : NULL;
    if (sky && v) /* the sky: camera rays that hit nothing see the texture */
        draw_latlong(dev, v, sky, dev->bg_intensity, dev->t.w, dev->t.h);
    gl->Enable(GL_DEPTH_TEST);
    gl->DepthFunc(GL_LESS);
    gl->Disable(GL_CULL_FACE); /* the ray tracers see both sides of every triangle */
    gl->Disable(GL_BLEND);
    if (dev->t.samples > 1) gl->Enable(GL_MULTISAMPLE);
}

/* What takes a w x h target's window position and view depth back to view space (sy_gl_gbuf_fs):
 * proj[0], proj[5] and the offsets that undo the projection's x and y; 2 / size. */
static void view_unproject(const view_setup *v, uint32_t w, uint32_t h, float unproj[4], float px[2])
{
    const float *p = v->proj;
    unproj[0] = p[0], unproj[1] = p[5];
    unproj[2] = v->ortho ? -p[12] : p[8], unproj[3] = v->ortho ? -p[13] : p[9];
    px[0] = 2.0f / (float)w, px[1] = 2.0f / (float)h;
}

static int frame_lighting(const sy_gl_device *dev);
static void bind_frame_resources(sy_gl_device *dev);

/* Draws rectangles (NDC) with the bound program (sy_gl_rect_vs; loc: its u_rects), in batches. */
static void draw_rects(sy_gl_device *dev, GLint loc, const float (*r)[4], uint32_t n)
{
    const sy_gl_fns *gl = dev->gl;
    gl->BindVertexArray(dev->empty_vao);
    for (uint32_t i = 0; i < n; i += SY_GL_MAX_RECTS) {
        const uint32_t b = n - i < SY_GL_MAX_RECTS ? n - i : SY_GL_MAX_RECTS;
        gl->Uniform4fv(loc, (GLsizei)b, r[i]);
        gl->DrawArrays(GL_TRIANGLES, 0, (GLsizei)(6 * b));
    }
}

/* The whole target as one rectangle (sy_gl_rect_vs). */
static const float FULL_TARGET[1][4] = {{-1.0f, -1.0f, 1.0f, 1.0f}};

/* The plain MSAA resolve (sy_gl_resolve_fs) of the target's samples in rectangles r[0, n) into the
 * bound resolve target. */
static void resolve_pass(sy_gl_device *dev, const float (*r)[4], uint32_t n)
{
    const sy_gl_fns *gl = dev->gl;
    gl->UseProgram(dev->prog_resolve);
    gl->ActiveTexture(GL_TEXTURE0);
    gl->BindTexture(GL_TEXTURE_2D_MULTISAMPLE, dev->t.color);
    gl->ActiveTexture(GL_TEXTURE1);
    gl->BindTexture(GL_TEXTURE_2D_MULTISAMPLE, dev->t.depthlin);
    draw_rects(dev, dev->resolve_rects, r, n);
}

/* Splits the target into the tiles (RECT_TILE pixels square) that the rectangles of rect_add touch
 * and the rest, each as rectangles in NDC (runs of tiles along a row, each extending an equal run
 * of the row below): dev->spans[0, *n_shade) and [*n_shade, *n_shade + *n_rest). Together they
 * cover every pixel once; *shade_px: the pixels of the first list. False without memory. */
static bool rect_tiles(sy_gl_device *dev, uint32_t *n_shade, uint32_t *n_rest, uint64_t *shade_px)
{
    const uint32_t tw = (dev->t.w + RECT_TILE - 1) / RECT_TILE, th = (dev->t.h + RECT_TILE - 1) / RECT_TILE;
    const size_t n = (size_t)tw * th;
    if (dev->tiles_cap < n) {
        free(dev->tiles);
        free(dev->spans);
        free(dev->runs);
        dev->tiles = malloc(n);
        dev->spans = malloc(sizeof *dev->spans * n); /* at most one rectangle per tile */
        dev->runs = malloc(sizeof *dev->runs * 2 * n); /* n >= tw, whatever the shape */
        dev->tiles_cap = dev->tiles && dev->spans && dev->runs ? n : 0;
        if (!dev->tiles_cap) return false;
    }
    memset(dev->tiles, 0, n);
    for (uint32_t i = 0; i < dev->rect_count; ++i) {
        const uint32_t *r = dev->rects[i], x0 = r[0] / RECT_TILE, x1 = (r[2] + RECT_TILE - 1) / RECT_TILE;
        for (uint32_t y = r[1] / RECT_TILE; y < (r[3] + RECT_TILE - 1) / RECT_TILE; ++y)
            memset(dev->tiles + (size_t)y * tw + x0, 1, x1 - x0);
    }
    const float sx = 2.0f / (float)dev->t.w, sy = 2.0f / (float)dev->t.h;
    /* runs[x]: 1 + the rectangle whose run starts at tile column x, runs[tw + x] its end column */
    uint32_t *start = dev->runs, *end = dev->runs + tw, count = 0;
    *shade_px = 0;
    for (int want = 1; want >= 0; --want) {
        const uint32_t first = count;
        memset(start, 0, sizeof *start * tw);
        for (uint32_t y = 0; y < th; ++y) {
            const uint8_t *row = dev->tiles + (size_t)y * tw;
            const uint32_t py1 = (y + 1) * RECT_TILE < dev->t.h ? (y + 1) * RECT_TILE : dev->t.h;
            const float y0 = (float)(y * RECT_TILE) * sy - 1.0f, y1 = (float)py1 * sy - 1.0f;
            for (uint32_t x = 0, e; x < tw; x = e) {
                for (e = x + 1; e < tw && row[e] == row[x]; ++e) {}
                if (row[x] != want) continue;
                const uint32_t px1 = e * RECT_TILE < dev->t.w ? e * RECT_TILE : dev->t.w;
                if (want) *shade_px += (uint64_t)(px1 - x * RECT_TILE) * (py1 - y * RECT_TILE);
                float *o = start[x] ? dev->spans[start[x] - 1] : NULL;
                if (o && end[x] == e && o[3] == y0) o[3] = y1; /* the same run on the row below: taller */
                else {
                    o = dev->spans[count++];
                    o[0] = (float)(x * RECT_TILE) * sx - 1.0f, o[1] = y0;
                    o[2] = (float)px1 * sx - 1.0f, o[3] = y1;
                    start[x] = count, end[x] = e;
                }
            }
        }
        if (want) *n_shade = count - first;
        else *n_rest = count - first;
    }
    return true;
}

/* The deferred shading pass (sy_gl_deferred_fs) into the bound resolve target. It runs only on the
 * tiles that the rectangles of rect_add touch (no G-buffer sample lies outside them), the plain
 * resolve on the others. On llvmpipe a pixel vector of the deferred pass costs nearly as much
 * where it has nothing to shade as where it has (a loop body runs at least once, masked; an if
 * runs both sides): over the whole target it cost the generated bench scene (14 % of its pixels
 * covered) about 0.1x of its frame in pixels with nothing to shade (issue 19). */
static sy_gl_result deferred_pass(sy_gl_device *dev, const view_setup *v, char *err, size_t len)
{
    const sy_gl_fns *gl = dev->gl;
    const targets *t = &dev->t;
    int k = deferred_program(dev, frame_lighting(dev), err, len);
    if (k < 0) return SY_GL_ERROR_GL;
    float inv_view[16];
    if (!m4_invert(v->view, inv_view)) return fail(err, len, SY_GL_ERROR_INVALID_ARGUMENT, "render: view not invertible");
    float unproj[4], px[2];
    view_unproject(v, t->w, t->h, unproj, px);
    uint32_t n_shade = 1, n_rest = 0;
    const float(*shade)[4] = FULL_TARGET;
    if (!dev->rect_all && rect_tiles(dev, &n_shade, &n_rest, &dev->deferred_pixels)) shade = dev->spans;
    else n_shade = 1, n_rest = 0, dev->deferred_pixels = (uint64_t)t->w * t->h;
    if (n_shade) {
        gl->UseProgram(dev->dp[k].prog);
        gl->Uniform4fv(dev->dp[k].unproj, 1, unproj);
        gl->UniformMatrix4fv(dev->dp[k].inv_view, 1, GL_FALSE, inv_view);
        gl->Uniform2fv(dev->dp[k].px, 1, px);
        gl->Uniform3fv(dev->dp[k].cam_pos, 1, v->cam_pos);
        gl->Uniform3fv(dev->dp[k].cam_fwd, 1, v->cam_fwd);
        gl->Uniform1i(dev->dp[k].ortho, v->ortho);
        bind_frame_resources(dev);
        mtab_upload(dev);
        gl->ActiveTexture(GL_TEXTURE0 + UNIT_GCOL);
        gl->BindTexture(GL_TEXTURE_2D_MULTISAMPLE, t->color);
        gl->ActiveTexture(GL_TEXTURE0 + UNIT_GDEPTH);
        gl->BindTexture(GL_TEXTURE_2D_MULTISAMPLE, t->depthlin);
        draw_rects(dev, dev->dp[k].rects, shade, n_shade);
    }
    if (n_rest) resolve_pass(dev, dev->spans + n_shade, n_rest);
    return SY_GL_OK;
}

/* Resolves (MSAA; shading the G-buffer when the main pass of view v drew into it) and reads the
 * target back into the caller's arrays, flipping rows. */
static sy_gl_result finish_target(sy_gl_device *dev, const view_setup *v, float *rgba, float *depth, char *err,
                                  size_t len)
{
    const sy_gl_fns *gl = dev->gl;
    targets *t = &dev->t;
    GLuint read_fbo = t->fbo;
    if (t->samples > 1 && v && dev->deferred_draws) {
        gl->BindFramebuffer(GL_FRAMEBUFFER, t->rfbo);
        static const GLenum bufs[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
        gl->DrawBuffers(2, bufs);
        gl->Disable(GL_DEPTH_TEST);
        gl->Disable(GL_BLEND);
        sy_gl_result r = deferred_pass(dev, v, err, len);
        if (r != SY_GL_OK) return r;
        read_fbo = t->rfbo;
    } else if (t->samples > 1) {
        gl->BindFramebuffer(GL_FRAMEBUFFER, t->rfbo);
        static const GLenum bufs[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
        gl->DrawBuffers(2, bufs);
        gl->Disable(GL_DEPTH_TEST);
        gl->Disable(GL_BLEND);
        resolve_pass(dev, FULL_TARGET, 1);
        read_fbo = t->rfbo;
    }
    size_t n = (size_t)t->w * t->h;
    if (dev->scratch_len < n * 4) {
        float *s = realloc(dev->scratch, n * 4 * sizeof *s);
        if (!s) return fail(err, len, SY_GL_ERROR_OUT_OF_MEMORY, "render: out of memory for read-back");
        dev->scratch = s;
        dev->scratch_len = n * 4;
    }
    gl->BindFramebuffer(GL_FRAMEBUFFER, read_fbo);
    gl->PixelStorei(GL_PACK_ALIGNMENT, 4);
    gl->ReadBuffer(GL_COLOR_ATTACHMENT0);
    gl->ReadPixels(0, 0, (GLsizei)t->w, (GLsizei)t->h, GL_RGBA, GL_FLOAT, dev->scratch);
    size_t row = (size_t)t->w * 4;
    for (uint32_t y = 0; y < t->h; ++y) memcpy(rgba + row * y, dev->scratch + row * (t->h - 1 - y), row * sizeof(float));
    if (depth) {
        gl->ReadBuffer(GL_COLOR_ATTACHMENT1);
        gl->ReadPixels(0, 0, (GLsizei)t->w, (GLsizei)t->h, GL_RED, GL_FLOAT, dev->scratch);
        for (uint32_t y = 0; y < t->h; ++y)
            memcpy(depth + (size_t)t->w * y, dev->scratch + (size_t)t->w * (t->h - 1 - y), t->w * sizeof(float));
    }
    sy_gl_result r = gl_check(dev, "render read-back", err, len);
    if (r != SY_GL_OK) return r;
    sy_gl_context_present(dev->ctx, read_fbo, t->w, t->h);
    return SY_GL_OK;
}

static int mesh_lean(const mesh_o *m) { return !m->has_attr[3] && !m->has_attr[4]; }

/* The variant bits of this frame's lighting. */
static int frame_lighting(const sy_gl_device *dev)
{
    int v = 0;
    if (dev->light_count) v |= VAR_LIGHTS;
    if (dev->light_count && dev->light_count <= VAR_NL_MAX) v |= (int)dev->light_count << VAR_NL_SHIFT;
    if (dev->env_ready) v |= VAR_ENV;
    if (dev->area_count) v |= VAR_AREA;
    if (dev->shadow_count) v |= VAR_SHADOW;
    if (dev->area_shadow_count) v |= VAR_ASHADOW;
    return v;
}

/* The material's variant bits that the shaders turn on and off per draw by the material's own
 * uniforms (m_tex, m_tex2, the transmission factor): textures, normal map, transmission. */
static int material_features(const sy_gl_device *dev, const mat_o *mt)
{
    int v = 0;
    const sy_gl_texture_ref *refs[5] = {&mt->d.base_color_texture, &mt->d.metallic_roughness_texture,
                                        &mt->d.normal_texture, &mt->d.occlusion_texture, &mt->d.emissive_texture};
    for (int i = 0; i < 5; ++i)
        if (pool_get(&dev->textures, refs[i]->texture.id)) v |= i == UNIT_NRM ? VAR_TEX | VAR_NMAP : VAR_TEX;
    /* a metallic-roughness texture scales metallic per texel: a metal factor of 1 still transmits
     * where the texture says dielectric (TransmissionTest's striped "Metal" spheres) */
    bool mr_tex = pool_get(&dev->textures, mt->d.metallic_roughness_texture.texture.id) != NULL;
    if (mt->d.transmission > 0.0f && (mt->d.metallic < 1.0f || mr_tex)) v |= VAR_TRANS;
    return v;
}

/* The variant bits for one draw: mesh attributes, material textures and mode, frame lighting,
 * whether the instance has a scene probe. */
static int draw_variant(const sy_gl_device *dev, const mesh_o *m, const mat_o *mt, bool probe)
{
    int v = frame_lighting(dev) | (mesh_lean(m) ? VAR_LEAN : 0);
    if (probe) v |= VAR_PROBE;
    if (!mt) return variant_normalize(v);
    if (mt->d.alpha_mode == SY_GL_ALPHA_MASK) v |= VAR_MASK;
    return variant_normalize(v | material_features(dev, mt));
}


typedef struct draw_ctx {
    const view_setup *v;
    float viewproj[16], ortho_z[3]; /* orthographic proj[10], proj[14] (and 0) */
    int bound;                      /* the variant whose program is bound, BOUND_GBUF, or -1 */
    int shared;                     /* material_features of every visible instance: forward draws use
                                     * them all (draw_instance) */
    bool deferred, gbuf_view_set;   /* opaque draws may go to the G-buffer; its view uniforms are set */
} draw_ctx;
#define BOUND_GBUF (-2)

/* Binds the variant's program (building it on first use) and, once per frame, its view uniforms. */
static sy_gl_result use_variant(sy_gl_device *dev, draw_ctx *dc, int pv, char *err, size_t err_len)
{
    if (pv == dc->bound) return SY_GL_OK;
    const sy_gl_fns *gl = dev->gl;
    GLuint p = main_program(dev, pv, err, err_len);
    if (!p) return SY_GL_ERROR_GL;
    gl->UseProgram(p);
    dc->bound = pv;
    if (dev->pm[pv].frame != dev->frame_no) {
        dev->pm[pv].frame = dev->frame_no;
        gl->Uniform3fv(dev->pm[pv].cam_pos, 1, dc->v->cam_pos);
        gl->Uniform3fv(dev->pm[pv].cam_fwd, 1, dc->v->cam_fwd);
        gl->Uniform1i(dev->pm[pv].ortho, dc->v->ortho);
        gl->Uniform3fv(dev->pm[pv].ortho_z, 1, dc->ortho_z);
    }
    return SY_GL_OK;
}

/* The probe of instance pool index i, or -1 (none, or while the probes themselves are drawn). */
static int probe_of(const sy_gl_device *dev, uint32_t i)
{
    if (dev->in_probe_pass) return -1;
    for (uint32_t p = 0; p < dev->probe_count; ++p)
        if (dev->probes[p].inst == i) return (int)p;
    return -1;
}

/* Whether a draw of variant pv with material mt (NULL: the default) can be shaded deferred: an
 * opaque, untextured, non-transmissive material in the table, on a mesh without colours or a
 * second uv set, without a scene probe. */
static bool deferrable(const sy_gl_device *dev, const inst_o *in, int pv, const mat_o *mt)
{
    if (!(in->px_per_tri <= DEFERRED_MAX_PX_PER_TRI)) return false;
    if ((pv & (VAR_TEX | VAR_MASK | VAR_TRANS | VAR_PROBE)) || !(pv & VAR_LEAN)) return false;
    if (mt && mt->d.alpha_mode != SY_GL_ALPHA_OPAQUE) return false;
    return (mt ? mt->h.id & IDX_MASK : 0u) < dev->mtab_cpu_rows;
}

/* Records where an instance drawn into the G-buffer with clip matrix mvp can have samples: the
 * pixels its mesh's bounding box touches (every level of detail lies within it), grown by one
 * pixel against rounding (GL transforms in single precision). The projection of a box whose
 * corners are all in front of the eye (w > 0) lies within the projected corners' bounds. A box
 * reaching behind the eye (which the deferred choice already sends forward: its bounding sphere
 * reaches the eye, see pixels_per_triangle), a non-finite corner, or no memory for the list:
 * everywhere. */
static void rect_add(sy_gl_device *dev, const float mvp[16], const mesh_o *m)
{
    if (dev->rect_all) return;
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (int k = 0; k < 8; ++k) {
        const double p[3] = {k & 1 ? m->bmax[0] : m->bmin[0], k & 2 ? m->bmax[1] : m->bmin[1],
                             k & 4 ? m->bmax[2] : m->bmin[2]};
        double c[4];
        for (int a = 0; a < 4; ++a) c[a] = mvp[a] * p[0] + mvp[4 + a] * p[1] + mvp[8 + a] * p[2] + mvp[12 + a];
        if (!(c[3] > 0.0)) {
            dev->rect_all = true;
            return;
        }
        for (int a = 0; a < 2; ++a) {
            double x = c[a] / c[3];
            lo[a] = fmin(lo[a], x), hi[a] = fmax(hi[a], x);
        }
    }
    const double size[2] = {dev->t.w, dev->t.h};
    uint32_t r[4];
    for (int a = 0; a < 2; ++a) { /* to pixels, grown by one, clamped to the target */
        if (!isfinite(lo[a]) || !isfinite(hi[a])) {
            dev->rect_all = true;
            return;
        }
        double x0 = floor((lo[a] * 0.5 + 0.5) * size[a]) - 1.0, x1 = ceil((hi[a] * 0.5 + 0.5) * size[a]) + 1.0;
        x0 = fmax(x0, 0.0), x1 = fmin(x1, size[a]);
        if (!(x0 < x1)) return; /* off the target */
        r[a] = (uint32_t)x0, r[2 + a] = (uint32_t)x1;
    }
    if (dev->rect_count == dev->rect_cap) {
        uint32_t cap = dev->rect_cap ? 2 * dev->rect_cap : 64;
        void *n = cap > dev->rect_cap ? realloc(dev->rects, sizeof *dev->rects * cap) : NULL;
        if (!n) {
            dev->rect_all = true;
            return;
        }
        dev->rects = n;
        dev->rect_cap = cap;
    }
    memcpy(dev->rects[dev->rect_count++], r, sizeof r);
}

/* One instance into the G-buffer (sy_gl_gbuf_fs). */
static void draw_gbuf(sy_gl_device *dev, draw_ctx *dc, const inst_o *in, const mesh_o *m, const mat_o *mt)
{
    const sy_gl_fns *gl = dev->gl;
    const int k = dc->v->ortho ? 1 : 0;
    if (dc->bound != BOUND_GBUF) {
        gl->UseProgram(dev->ug[k].prog);
        dc->bound = BOUND_GBUF;
        if (!dc->gbuf_view_set) {
            float unproj[4], px[2];
            view_unproject(dc->v, dev->t.w, dev->t.h, unproj, px);
            /* the view plane's X = (gl_FragCoord.xy px - 1 + unproj.zw) / unproj.xy: pixels per unit */
            const float ppu[2] = {unproj[0] / px[0], unproj[1] / px[1]};
            gl->Uniform2fv(dev->ug[k].ppu, 1, ppu);
            gl->Uniform3fv(dev->ug[k].ortho_z, 1, dc->ortho_z);
            dc->gbuf_view_set = true;
        }
    }
    float mvp[16];
    m4_mul(dc->viewproj, in->model, mvp);
    gl->UniformMatrix4fv(dev->ug[k].mvp, 1, GL_FALSE, mvp);
    gl->UniformMatrix3fv(dev->ug[k].normal_mat, 1, GL_FALSE, in->normal_mat);
    gl->Uniform1i(dev->ug[k].has_normals, m->has_normals);
    /* the key without geo (sy_gl_gbuf_fs): 4 x material row + front, plus 1 */
    const float key = (float)(1u + 4u * (mt ? mt->h.id & IDX_MASK : 0u)), keys[2] = {key + !in->mirror, key + in->mirror};
    gl->Uniform2fv(dev->ug[k].keys, 1, keys);
    dev->tris += draw_mesh_lod(dev, m, in->lod);
    dev->deferred_draws++;
    rect_add(dev, mvp, m);
}

static sy_gl_result draw_instance(sy_gl_device *dev, draw_ctx *dc, uint32_t index, const inst_o *in, const mesh_o *m,
                                  const mat_o *mt, char *err, size_t err_len)
{
    const sy_gl_fns *gl = dev->gl;
    int probe = probe_of(dev, index);
    int pv = draw_variant(dev, m, mt, probe >= 0);
    if (dc->deferred && deferrable(dev, in, pv, mt)) {
        draw_gbuf(dev, dc, in, m, mt);
        return SY_GL_OK;
    }
    /* Every forward draw of the frame takes the features any visible material has: llvmpipe
     * compiles each program on its first draw in each pipeline state (about 0.2-0.5 s of LLVM for a
     * lit one), and a program that samples textures, maps normals or transmits only where the
     * material's uniforms say so draws the others as they were. TransmissionTest's first frame
     * compiled 11 main-pass shaders before, 6 now (issue 32). */
    pv = variant_normalize(pv | dc->shared);
    sy_gl_result r = use_variant(dev, dc, pv, err, err_len);
    if (r != SY_GL_OK) return r;
    if (probe >= 0) {
        gl->ActiveTexture(GL_TEXTURE0 + UNIT_PROBE);
        gl->BindTexture(GL_TEXTURE_CUBE_MAP, dev->probes[probe].cube);
        gl->Uniform1f(dev->pm[pv].probe_lod, log2f((float)dev->probe_size)); /* the 1-texel mip */
    }
    bind_material(dev, in->material, (pv & VAR_TEX) != 0);
    float mvp[16];
    m4_mul(dc->viewproj, in->model, mvp);
    gl->UniformMatrix4fv(dev->pm[pv].mvp, 1, GL_FALSE, mvp);
    if (pv & (VAR_LIGHTS | VAR_ENV | VAR_AREA | VAR_PROBE)) {
        gl->UniformMatrix4fv(dev->pm[pv].model, 1, GL_FALSE, in->model);
        gl->UniformMatrix3fv(dev->pm[pv].normal_mat, 1, GL_FALSE, in->normal_mat);
        gl->Uniform1i(dev->pm[pv].has_normals, m->has_normals);
    }
    gl->Uniform1i(dev->pm[pv].mirror, in->mirror);
    dev->tris += draw_mesh_lod(dev, m, in->lod);
    return SY_GL_OK;
}

/* Distance of an instance's bounding-box centre along the view direction. */
static float view_distance(const inst_o *in, const mesh_o *m, const view_setup *v)
{
    float z = 0.0f;
    for (int a = 0; a < 3; ++a) {
        float wv = in->model[12 + a];
        for (int k = 0; k < 3; ++k) wv += in->model[4 * k + a] * 0.5f * (m->bmin[k] + m->bmax[k]);
        z += (wv - v->cam_pos[a]) * v->cam_fwd[a];
    }
    return z;
}

static int cmp_near_first(const void *a, const void *b) { return -cmp_far_first(a, b); }

/* The textures and uniform blocks every main-pass variant reads. */
static void bind_frame_resources(sy_gl_device *dev)
{
    const sy_gl_fns *gl = dev->gl;
    gl->BindBufferBase(GL_UNIFORM_BUFFER, BIND_LIGHTS, dev->lights_ubo);
    gl->BindBufferBase(GL_UNIFORM_BUFFER, BIND_AREAS, dev->areas_ubo);
    gl->ActiveTexture(GL_TEXTURE0 + UNIT_SHADOW);
    gl->BindTexture(GL_TEXTURE_2D_ARRAY, dev->shadow_tex);
    for (uint32_t c = 0; c < SY_GL_MAX_CUBE_SHADOWS; ++c) {
        gl->ActiveTexture(GL_TEXTURE0 + UNIT_CUBE_SHADOW0 + (GLenum)c);
        gl->BindTexture(GL_TEXTURE_CUBE_MAP, dev->cube_tex[c]);
    }
    gl->ActiveTexture(GL_TEXTURE0 + UNIT_ENV_SPEC);
    gl->BindTexture(GL_TEXTURE_CUBE_MAP, dev->ibl.spec_cube);
    gl->ActiveTexture(GL_TEXTURE0 + UNIT_ENV_IRR);
    gl->BindTexture(GL_TEXTURE_CUBE_MAP, dev->ibl.irr_cube);
    GLuint tables[3] = {dev->ibl.brdf_lut, dev->ibl.ltc1, dev->ibl.ltc2};
    for (int i = 0; i < 3; ++i) {
        gl->ActiveTexture(GL_TEXTURE0 + UNIT_BRDF + (GLenum)i);
        gl->BindTexture(GL_TEXTURE_2D, tables[i]);
    }
}

/* Draws every visible instance but `skip` (a pool index, UINT32_MAX for none) into the bound
 * target: opaque near to far (early depth tests reject hidden fragments before shading), then
 * alpha-masked (the discard variant) near to far, then blended far to near with depth writes off.
 * Each list holds (view distance, instance index) pairs. */
static sy_gl_result draw_scene(sy_gl_device *dev, const view_setup *v, uint32_t skip, char *err, size_t err_len)
{
    const sy_gl_fns *gl = dev->gl;
    sy_gl_result r = SY_GL_OK;
    draw_ctx dc = {.v = v, .ortho_z = {v->proj[10], v->proj[14], 0.0f}, .bound = -1};
    m4_mul(v->proj, v->view, dc.viewproj);
    uint32_t cap = dev->instances.count ? dev->instances.count : 1, nl[3] = {0, 0, 0};
    float *lists = malloc(sizeof(float) * 2 * 3 * cap);
    if (!lists) return fail(err, err_len, SY_GL_ERROR_OUT_OF_MEMORY, "render: out of memory");
    float planes[6][4];
    frustum_planes(dc.viewproj, planes);
    if (skip == UINT32_MAX) {
        dev->culled = dev->deferred_draws = dev->deferred_pixels = 0;
        dev->rect_count = 0;
        dev->rect_all = false;
    }
    const mat_o *last = NULL;
    for (uint32_t i = 0; i < dev->instances.count; ++i) {
        inst_o *in = pool_at(&dev->instances, i);
        if (!in->h.id || !in->visible) continue;
        const mesh_o *m = pool_get(&dev->meshes, in->mesh.id);
        if (!m) continue;
        const mat_o *mt = pool_get(&dev->materials, in->material.id);
        if (mt && mt != last) dc.shared |= material_features(dev, last = mt); /* the same in every pass */
        if (i == skip) continue;
        float c[3], scale, r = world_sphere(in, m, c, &scale);
        if (sphere_outside(planes, c, r)) { /* outside the view: not drawn */
            if (skip == UINT32_MAX) dev->culled++;
            continue;
        }
        in->lod = choose_lod(dev, m, v, c, r, scale);
        in->px_per_tri = pixels_per_triangle(dev, m, in->lod, v, c, r);
        sy_gl_alpha_mode mode = mt ? mt->d.alpha_mode : SY_GL_ALPHA_OPAQUE;
        int li = mode == SY_GL_ALPHA_BLEND ? 2 : mode == SY_GL_ALPHA_MASK ? 1 : 0;
        float *e = lists + 2 * ((size_t)li * cap + nl[li]++);
        e[0] = view_distance(in, m, v);
        memcpy(&e[1], &i, sizeof i);
    }
    /* deferred shading in the main pass of a frame without blended instances (they would blend
     * over G-buffer samples) */
    dc.deferred = !dev->forward && !dev->in_probe_pass && skip == UINT32_MAX && nl[2] == 0;
    for (int li = 0; li < 3 && r == SY_GL_OK; ++li) {
        float *list = lists + 2 * (size_t)li * cap;
        qsort(list, nl[li], 2 * sizeof(float), li == 2 ? cmp_far_first : cmp_near_first);
        if (li == 2 && nl[li]) {
            gl->Enable(GL_BLEND);
            gl->Disablei(GL_BLEND, 1); /* linear depth: the last (nearest) blended surface wins */
            gl->BlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA); /* premultiplied over */
            gl->DepthMask(GL_FALSE);
        }
        for (uint32_t k = 0; k < nl[li] && r == SY_GL_OK; ++k) {
            uint32_t i;
            memcpy(&i, &list[2 * k + 1], sizeof i);
            const inst_o *in = pool_at(&dev->instances, i);
            r = draw_instance(dev, &dc, i, in, pool_get(&dev->meshes, in->mesh.id),
                              pool_get(&dev->materials, in->material.id), err, err_len);
        }
        if (li == 2 && nl[li]) {
            gl->DepthMask(GL_TRUE);
            gl->Disable(GL_BLEND);
        }
    }
    free(lists);
    return r;
}

/* Whether an instance's material is mirror-like or glass enough to need the scene around it. */
static bool wants_probe(const mat_o *mt)
{
    if (!mt || mt->d.roughness > PROBE_MAX_ROUGHNESS) return false;
    return mt->d.metallic >= 0.5f || mt->d.transmission * (1.0f - mt->d.metallic) >= 0.5f;
}

/* The probes' side for a frame of w x h: the power of two at or above half the larger side, within
 * [PROBE_SIZE_MIN, PROBE_SIZE_MAX], and never below the side they have (see SY_GL_MAX_PROBES). */
static uint32_t probe_size_for(const sy_gl_device *dev, uint32_t w, uint32_t h)
{
    uint32_t half = (w > h ? w : h) / 2u, s = PROBE_SIZE_MIN;
    while (s < half && s < PROBE_SIZE_MAX) s *= 2u;
    return s > dev->probe_size ? s : dev->probe_size;
}

/* Frees the probes' cube maps and depth buffer (made again at the next render_probes). */
static void probes_free(sy_gl_device *dev)
{
    const sy_gl_fns *gl = dev->gl;
    for (uint32_t p = 0; p < SY_GL_MAX_PROBES; ++p)
        if (dev->probes[p].cube) {
            gl->DeleteTextures(1, &dev->probes[p].cube);
            dev->probes[p].cube = 0;
        }
    if (dev->probe_fbo) gl->DeleteFramebuffers(1, &dev->probe_fbo);
    if (dev->probe_depth) gl->DeleteRenderbuffers(1, &dev->probe_depth);
    dev->probe_fbo = dev->probe_depth = 0;
}

/* (Re)renders the scene probes (see SY_GL_MAX_PROBES). */
static sy_gl_result render_probes(sy_gl_device *dev, char *err, size_t err_len)
{
    const sy_gl_fns *gl = dev->gl;
    dev->probe_count = 0;
    float centres[SY_GL_MAX_PROBES][3];
    for (uint32_t i = 0; i < dev->instances.count && dev->probe_count < SY_GL_MAX_PROBES; ++i) {
        const inst_o *in = pool_at(&dev->instances, i);
        if (!in->h.id || !in->visible) continue;
        const mesh_o *m = pool_get(&dev->meshes, in->mesh.id);
        if (!m || !wants_probe(pool_get(&dev->materials, in->material.id))) continue;
        float *c = centres[dev->probe_count];
        for (int a = 0; a < 3; ++a) {
            c[a] = in->model[12 + a];
            for (int k = 0; k < 3; ++k) c[a] += in->model[4 * k + a] * 0.5f * (m->bmin[k] + m->bmax[k]);
        }
        dev->probes[dev->probe_count++].inst = i;
    }
    if (!dev->probe_count) return SY_GL_OK;
    const GLsizei ps = (GLsizei)dev->probe_size;
    if (!dev->probe_fbo) {
        gl->GenFramebuffers(1, &dev->probe_fbo);
        gl->GenRenderbuffers(1, &dev->probe_depth);
        gl->BindRenderbuffer(GL_RENDERBUFFER, dev->probe_depth);
        gl->RenderbufferStorageMultisample(GL_RENDERBUFFER, 0, GL_DEPTH_COMPONENT32F, ps, ps);
    }
    float sc[3], R;
    scene_bounds(dev, sc, &R);
    const tex_o *env = dev->env_ready ? pool_get(&dev->textures, dev->env_tex.id) : NULL;
    bind_frame_resources(dev);
    dev->in_probe_pass = true;
    sy_gl_result r = SY_GL_OK;
    for (uint32_t p = 0; p < dev->probe_count && r == SY_GL_OK; ++p) {
        if (!dev->probes[p].cube) {
            gl->GenTextures(1, &dev->probes[p].cube);
            gl->BindTexture(GL_TEXTURE_CUBE_MAP, dev->probes[p].cube);
            for (int f = 0; f < 6; ++f)
                gl->TexImage2D(GL_TEXTURE_CUBE_MAP_POSITIVE_X + (GLenum)f, 0, GL_RGBA16F, ps, ps, 0, GL_RGBA,
                               GL_FLOAT, NULL);
            gl->TexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
            gl->TexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
            gl->TexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
            gl->TexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
            gl->TexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
        }
        const float *c = centres[p];
        float dc = sqrtf((c[0] - sc[0]) * (c[0] - sc[0]) + (c[1] - sc[1]) * (c[1] - sc[1]) + (c[2] - sc[2]) * (c[2] - sc[2]));
        double far = dc + R, nearp = fmax(1e-4 * far, 1e-5);
        for (int f = 0; f < 6 && r == SY_GL_OK; ++f) {
            view_setup v;
            memset(&v, 0, sizeof v);
            cube_face_view(c, f, v.view);
            projection(false, -1.0, 1.0, -1.0, 1.0, nearp, far, v.proj);
            memcpy(v.cam_pos, c, sizeof v.cam_pos);
            memcpy(v.cam_fwd, cube_faces[f][2], sizeof v.cam_fwd);
            gl->BindFramebuffer(GL_FRAMEBUFFER, dev->probe_fbo);
            gl->FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_CUBE_MAP_POSITIVE_X + (GLenum)f,
                                     dev->probes[p].cube, 0);
            gl->FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, dev->probe_depth);
            static const GLenum bufs[2] = {GL_COLOR_ATTACHMENT0, GL_NONE};
            gl->DrawBuffers(2, bufs);
            gl->Viewport(0, 0, ps, ps);
            gl->ColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
            gl->DepthMask(GL_TRUE);
            const float black[4] = {0, 0, 0, 1}, one = 1.0f;
            gl->ClearBufferfv(GL_COLOR, 0, black);
            gl->ClearBufferfv(GL_DEPTH, 0, &one);
            gl->Disable(GL_CULL_FACE);
            gl->Disable(GL_BLEND);
            if (env) /* rays that leave the scene see the environment (a light) */
                draw_latlong(dev, &v, env, dev->env_intensity, (uint32_t)ps, (uint32_t)ps);
            gl->Enable(GL_DEPTH_TEST);
            gl->DepthFunc(GL_LESS);
            dev->frame_no++; /* the variants take this face's camera */
            r = draw_scene(dev, &v, dev->probes[p].inst, err, err_len);
        }
        gl->BindTexture(GL_TEXTURE_CUBE_MAP, dev->probes[p].cube);
        gl->GenerateMipmap(GL_TEXTURE_CUBE_MAP);
    }
    dev->in_probe_pass = false;
    dev->frame_no++;
    if (r == SY_GL_OK) r = gl_check(dev, "scene probes", err, err_len);
    return r;
}

/* What every frame starts with: the context current, the view, the targets, zeroed counters. */
static sy_gl_result frame_setup(sy_gl_device *dev, const sy_gl_camera *cam, const sy_gl_render_desc *d, view_setup *v,
                                char *err, size_t err_len)
{
    sy_gl_result r = current(dev, err, err_len);
    if (r == SY_GL_OK) r = view_make(dev, cam, d, v, err, err_len);
    if (r == SY_GL_OK) r = targets_ensure(dev, d->width, d->height, err, err_len);
    dev->tris = dev->draws = 0;
    return r;
}

sy_gl_result sy_gl_render(sy_gl_device *dev, const sy_gl_camera *cam, const sy_gl_render_desc *d, float *rgba,
                          float *depth, char *err, size_t err_len)
{
    view_setup v;
    sy_gl_result r = frame_setup(dev, cam, d, &v, err, err_len);
    if (r != SY_GL_OK) return r;
    const sy_gl_fns *gl = dev->gl;
    dev->frame_no++;
    static frame_state fs_zero;
    frame_state fs = fs_zero;
    if (dev->env_dirty) {
        const tex_o *et = pool_get(&dev->textures, dev->env_tex.id);
        dev->env_ready = false;
        if (et) {
            r = sy_gl_ibl_tables(gl, &dev->ibl, err, err_len);
            if (r == SY_GL_OK)
                r = sy_gl_ibl_prefilter(gl, &dev->ibl, et->tex, et->width, et->height, dev->env_intensity, err, err_len);
            if (r != SY_GL_OK) return r;
            dev->env_ready = true;
        }
        dev->env_dirty = false;
        dev->probes_dirty = true;
    }
    if (dev->area_count && (r = sy_gl_ibl_tables(gl, &dev->ibl, err, err_len)) != SY_GL_OK) return r;
    if (dev->lights_dirty) {
        choose_lods(dev, &v); /* shadow maps draw the levels this view picks */
        lights_upload(dev, &fs);
        if ((fs.shadow_count || fs.cube_count) && !dev->shadow_tex) { /* the maps' size is known now */
            if ((r = shadow_maps_make(dev, err, err_len)) != SY_GL_OK) return r;
            fs = fs_zero;
            lights_upload(dev, &fs);
        }
        if (fs.shadow_count || fs.cube_count) render_shadows(dev, &fs);
        else dev->shadow_maps = 0;
        dev->lights_dirty = false;
        dev->probes_dirty = true;
    }
    uint32_t psize = probe_size_for(dev, d->width, d->height);
    if (psize != dev->probe_size) { /* a larger frame than any before: sharper probes */
        probes_free(dev);
        dev->probe_size = psize;
        dev->probes_dirty = true;
    }
    if (dev->probes_dirty) {
        if ((r = render_probes(dev, err, err_len)) != SY_GL_OK) return r;
        dev->probes_dirty = false;
    }
    begin_target(dev, &v);
    bind_frame_resources(dev);
    r = draw_scene(dev, &v, UINT32_MAX, err, err_len);
    if (r == SY_GL_OK) r = finish_target(dev, &v, rgba, depth, err, err_len);
    frame_end(dev);
    return r;
}

sy_gl_result sy_gl_render_floor(sy_gl_device *dev, const sy_gl_camera *cam, const sy_gl_render_desc *d, bool lit,
                                float *rgba, float *depth, char *err, size_t err_len)
{
    view_setup v;
    sy_gl_result r = frame_setup(dev, cam, d, &v, err, err_len);
    if (r != SY_GL_OK) return r;
    const sy_gl_fns *gl = dev->gl;
    begin_target(dev, NULL);
    const int k = lit ? 1 : 0;
    gl->UseProgram(lit ? dev->prog_floor_lit : dev->prog_floor);
    gl->UniformMatrix4fv(dev->uf[k].view, 1, GL_FALSE, v.view);
    gl->UniformMatrix4fv(dev->uf[k].proj, 1, GL_FALSE, v.proj);
    float vp[16], planes[6][4];
    m4_mul(v.proj, v.view, vp);
    frustum_planes(vp, planes);
    for (uint32_t i = 0; i < dev->instances.count; ++i) { /* the same culling and levels as sy_gl_render */
        inst_o *in = pool_at(&dev->instances, i);
        if (!in->h.id || !in->visible) continue;
        const mesh_o *m = pool_get(&dev->meshes, in->mesh.id);
        if (!m) continue;
        float c[3], scale, r = world_sphere(in, m, c, &scale);
        if (sphere_outside(planes, c, r)) continue;
        in->lod = choose_lod(dev, m, &v, c, r, scale);
        gl->UniformMatrix4fv(dev->uf[k].model, 1, GL_FALSE, in->model);
        dev->tris += draw_mesh_lod(dev, m, in->lod);
    }
    r = finish_target(dev, NULL, rgba, depth, err, err_len);
    frame_end(dev);
    return r;
}
