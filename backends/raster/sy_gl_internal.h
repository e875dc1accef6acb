/* sy_gl_internal.h — INTERNAL to backends/raster (not installed): what the rasterizer's modules
 * share: limits and texture units, the object pools and object structs, the device struct, the
 * per-frame structs, and the functions one module calls in another (prefix sy_gli_). The modules,
 * bottom-up (each calls only those before it; tests/core/layers_test.sh checks it):
 *   (sy_gl_context.c, below them all: the GL context and the error report, sy_gli_fail)
 *   sy_gl_base.c     pools, warnings, math, frustum tests, GL checks
 *   sy_gl_programs.c stand-in textures, material blocks, shader variants, the material table
 *   sy_gl_lod.c      levels of detail: their deviation measured, the level chosen per view, its draw
 *   sy_gl_objects.c  meshes (levels of detail), textures, materials, instances, lights, environment
 *   sy_gl_shadows.c  the lights' uniform blocks and shadow maps
 *   sy_gl_draw.c     targets, views, the forward and deferred passes, culling, MSAA resolve
 *   sy_gl_render.c   scene probes and the frame (sy_gl_render, sy_gl_render_floor)
 *   sy_gl_pick.c     what is under one pixel: the ID pass (sy_gl_pick); ID images (sy_gl_ids)
 *   sy_gl_device.c   the device: create, destroy, statistics
 * Not thread-safe: one device is used by one thread at a time (sy_gl.h). */
#ifndef SY_GL_INTERNAL_H
#define SY_GL_INTERNAL_H

#include "sy_gl.h"
#include "sy_gl_context.h"
#include "sy_gl_ibl.h"
#include "sy_gl_shaders.h"

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define PICK_UNIFORMS 11 /* the pick program's uniforms (sy_gl_pick.c) */
#define IDX_BITS 20u
#define IDX_MASK ((1u << IDX_BITS) - 1u)
/* shadow_map_size 0 (the default): the maps follow the frame, the power of two at or above twice
 * its larger side, from SHADOW_SIZE_AUTO_MIN to SHADOW_SIZE_DEFAULT (a 200x150 frame renders 512,
 * not 2048: 16 times fewer texels to zero and draw, issue 32); they never shrink */
#define SHADOW_SIZE_DEFAULT 2048u
#define SHADOW_SIZE_AUTO_MIN 256u
enum { UNIT_BASE = 0, UNIT_MR, UNIT_NRM, UNIT_OCC, UNIT_EMIS, UNIT_SHADOW, UNIT_ENV_SPEC, UNIT_ENV_IRR, UNIT_BRDF,
       UNIT_LTC1, UNIT_LTC2, UNIT_CUBE_SHADOW0, UNIT_CUBE_SHADOW1, UNIT_PROBE, UNIT_LAYER0, UNIT_COUNT = UNIT_LAYER0 + 12 };
/* the layers' texture slots (units UNIT_LAYER0 + i, sy_gl_shaders_layers.c): specular, specular
 * colour, clear coat, coat roughness, coat normal, sheen colour, sheen roughness, thickness,
 * anisotropy, iridescence, iridescence thickness, transmission */
#define LAYER_TEXTURES 12
/* dev->material_sig: bits 0 .. LAYER_TEXTURES - 1 the layer slots, then these, then the five base
 * slots (base colour, metal-roughness, normal, occlusion, emission) from MSIG_BASE_SHIFT */
#define MSIG_IRID (1u << LAYER_TEXTURES)
#define MSIG_ANISO (2u << LAYER_TEXTURES)
#define MSIG_BASE_SHIFT (LAYER_TEXTURES + 2)
#define MSIG_SHIFT 16 /* where variant_sig (sy_gl_programs.c) keeps the material features it depends on */
#define STANDINS (5 + LAYER_TEXTURES) /* material units with a stand-in: the five base slots, the layers' */
static inline void sy_gli_layer_refs(const sy_gl_material_desc *d, const sy_gl_texture_ref *r[LAYER_TEXTURES])
{
    r[0] = &d->specular_texture, r[1] = &d->specular_color_texture, r[2] = &d->clearcoat_texture;
    r[3] = &d->clearcoat_roughness_texture, r[4] = &d->clearcoat_normal_texture, r[5] = &d->sheen_color_texture;
    r[6] = &d->sheen_roughness_texture, r[7] = &d->thickness_texture, r[8] = &d->anisotropy_texture;
    r[9] = &d->iridescence_texture, r[10] = &d->iridescence_thickness_texture, r[11] = &d->transmission_texture;
}
/* Every texture slot of a material: the five base ones (UNIT_BASE .. UNIT_EMIS), then the layers'
 * (sy_gli_layer_refs). */
static inline void sy_gli_material_refs(const sy_gl_material_desc *d, const sy_gl_texture_ref *r[STANDINS])
{
    r[0] = &d->base_color_texture, r[1] = &d->metallic_roughness_texture, r[2] = &d->normal_texture;
    r[3] = &d->occlusion_texture, r[4] = &d->emissive_texture;
    sy_gli_layer_refs(d, r + 5);
}
/* Scene probes: mirror-like and glass instances see the scene, not only the environment. Each of
 * the first SY_GL_MAX_PROBES such instances gets a cube map rendered from its bounding-box centre
 * (the instance itself left out, other probed instances showing the environment), with a mip
 * chain for roughness; re-rendered only when geometry, materials, lights or the environment
 * change, and for a camera move only when a probed instance gets larger in view than its probe's
 * side allows. Its side (probe_size_for) follows the largest probed instance in view so far, from
 * PROBE_SIZE_MIN to PROBE_SIZE_MAX texels and at most about half the frame's width: a sphere of
 * radius R pixels needs faces of about R texels (TransmissionTest's small glass objects at 200x150
 * render 16 px faces, not 128: 64 times fewer probe pixels, issue 32), and it never shrinks, so a
 * view whose resolution drops while it moves (sy view, sy web) does not re-render its probes. */
#define SY_GL_MAX_PROBES 4u
#define PROBE_SIZE_MIN 16u
#define PROBE_SIZE_MAX 256u
#define PROBE_MAX_ROUGHNESS 0.4f
enum { BIND_MATERIAL = 0, BIND_LIGHTS = 1, BIND_AREAS = 2, BIND_CLIP = 3 };
/* Deferred shading (see sy_gl_shaders.c, sy_gl_gbuf_fs): the shading pass samples no material
 * texture, so the G-buffer and the material table use the material units. */
enum { UNIT_GCOL = UNIT_BASE, UNIT_GDEPTH = UNIT_MR, UNIT_MTAB = UNIT_NRM };
#define MTAB_TEXELS 3u      /* RGBA32F texels per material row (sy_gl_deferred_fs) */
#define MTAB_MAX_ROWS 256u /* the G-buffer's key holds 8 bits of material row (sy_gl_shaders.c) */
#define DEFERRED_PROGS 16u  /* shading-pass programs kept (one per frame lighting variant) */
#define RECT_TILE 8u        /* the deferred pass shades the RECT_TILE-pixel tiles G-buffer instances touch */
#define PM_SPARE 32u        /* main programs kept for other light signatures than the sy_gli_current one */
/* Instances whose forward shading would run on more pixels per triangle than this stay forward:
 * on big triangles the forward pass already shades about once per pixel, and the G-buffer pass
 * is extra (measured with sy bench raster: the demo's spheres at 24-37 pixels per triangle are
 * faster forward, the 1M-triangle scene's meshes at 2-8 deferred). */
#define DEFERRED_MAX_PX_PER_TRI 16.0f

/* Object pools: every object struct starts with {id, gen}; id 0 = free slot. */
typedef struct slot_head {
    uint32_t id, gen;
} slot_head;

typedef struct pool {
    void *items;
    uint32_t count, cap, live;
    size_t elem;
} pool;

static inline void *sy_gli_pool_at(const pool *p, uint32_t i) { return (char *)p->items + (size_t)i * p->elem; }

/* Levels of detail (meshoptimizer): level 0 is the mesh; each further level is simplified from the
 * one before to about a quarter of its triangles, all levels in one index buffer. */
#define LOD_MAX 12
#define LOD_CACHE_ENTRIES 8u          /* sy_gl_device.lod_cache */
#define LOD_CACHE_MAX_TRIANGLES (1u << 18) /* meshes above it are not kept (their levels' indices) */
/* A software rasterizer's queue of binned triangles (sy_gl_lod.c, throttle): a fence after every
 * THROTTLE_TRIANGLES drawn, at most THROTTLE_FENCES of them pending */
#define THROTTLE_TRIANGLES (1u << 16)
#define THROTTLE_FENCES 2u

typedef struct mesh_o {
    slot_head h;
    GLuint vao, vbo[1], ibo;
    uint32_t vertex_count, triangle_count;
    bool has_normals, indexed, has_attr[5];
    bool packed;  /* the vertex buffer holds packed normals or uvs (sy_gl_objects.c, vertex_layout): not yet updated */
    float bmin[3], bmax[3];
    float centre[3], radius;     /* bounding sphere of the box (object space) */
    uint32_t lod_count;          /* levels, 1 = the mesh only */
    uint32_t lod_first[LOD_MAX], lod_tris[LOD_MAX]; /* first index, triangles */
    float lod_error[LOD_MAX];    /* object-space deviation from level 0 (bound, metres): of its surface
                                  * (and normals, sy_gli_normals_beyond_geometry) */
    float lod_error_uv[LOD_MAX]; /* the same with its uv0's slide: instances of textured materials */
    /* per level: 1 a closed surface (vertices welded by position, every edge in exactly two
     * triangles of opposite direction) wound counter-clockwise seen from outside, -1 wound the other
     * way, 0 not closed or not checked (over CLOSED_MAX_TRIANGLES); see cull_hidden_faces */
    int8_t lod_closed[LOD_MAX];
    int8_t cap_closed; /* sy_gl_mesh_desc.closed: 1, -1 a closed surface section caps fill (its winding), 0 not */
    /* a mesh with levels of at least LOD_REORDER_VERTICES vertices (reordered): the vertex buffer
     * holds the coarsest level's vertices first, then the next level's new ones, ...: order[i] =
     * the mesh vertex at buffer position i (malloc'd, freed with the mesh). Kept only for meshes
     * that are updated: made for the upload, freed after it, made again from the index buffer by
     * the first sy_gl_mesh_update (issue 39: 2 bytes per triangle of a large static mesh). NULL
     * and not reordered: the mesh's order. */
    uint32_t *order;
    bool reordered;
} mesh_o;
/* Meshes with levels and at least this many vertices get the vertex order above: llvmpipe shades
 * every vertex between a draw's smallest and largest index, so a far level of 10^3 triangles of a
 * 5 x 10^6-vertex mesh shaded (and held) them all. */
#define LOD_REORDER_VERTICES 65536u
/* The most triangles a level may have for the closed-surface check (a sort of 3 edges each). */
#define CLOSED_MAX_TRIANGLES 131072u

typedef struct tex_o {
    slot_head h;
    GLuint tex;
    uint32_t width, height; /* level 0 as uploaded */
    uint8_t wrap_s, wrap_t, nearest, is_float, srgb; /* its sampling (SY_GL_PROFILE's compile lines name it) */
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
    uint32_t lod;  /* level chosen for the last view drawn (sy_gli_choose_lod); shadow maps reuse it */
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
    VAR_LAYERS = 16384, /* material extensions: specular colour, clear coat, sheen, volume (sy_gl_shaders_layers.c;
                         * only with lighting) */
    VAR_COUNT = 32768
};

struct sy_gl_device {
    sy_gl_context *ctx;
    const sy_gl_fns *gl;
    char info[256];
    sy_gl_log_fn log;
    void *log_user;
    /* the error report (sy_gl_device_desc.error and the last message, sy_gl_device_error): reached
     * through a pointer, so that calls given a const device report too */
    sy_gl_report report_store;
    sy_gl_report *report; /* &report_store */
    uint32_t msaa, max_tex, shadow_size;
    bool shadow_auto; /* shadow_map_size 0: shadow_size follows the frame (sy_gli_shadow_size_follow) */
    pool meshes, textures, materials, instances, lights;
    GLuint prog_resolve, prog_floor, prog_floor_lit;
    GLint resolve_rects; /* prog_resolve's u_rects (sy_gl_rect_vs: the whole target or the tiles the deferred pass leaves) */
    struct main_prog { /* main-pass variants, built on first use, indexed by VAR_* bits (sy_gli_main_program) */
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
    uint32_t light_count, shadow_count, area_shadow_count; /* as uploaded by sy_gli_lights_upload: they pick the variants */
    /* sy_gli_lights_upload: what the shaders' straight-line light code is built for. Bits 2i, 2i + 1:
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
    struct {
        GLuint prog, fbo, color, depth; /* made on the first pick */
        GLuint ifbo, icolor, idepth;    /* sy_gl_ids' target, iw x ih, made on its first call */
        uint32_t iw, ih;
        GLint u[PICK_UNIFORMS];
    } pick; /* sy_gl_pick.c */
    GLuint default_ubo, lights_ubo, empty_vao;
    GLuint standin[STANDINS]; /* per material texture unit, bound where the material has no texture (sy_gli_make_standin) */
    uint32_t standin_key[STANDINS]; /* how each samples (sy_gli_standin_key; sy_gli_standins_follow) */
    bool layer_units; /* the context has UNIT_COUNT texture units: the layers' textures are read */
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
    /* SY_GL_PROFILE=1 in the environment at sy_gl_device_create: sy_gl_render waits for the GL
     * after each pass (glFinish) and prints the passes' wall and CPU times to stderr (sy_gli_profile_mark) */
    bool profile;
    double profile_t[2]; /* the last mark's wall and CPU time */
    int profile_var;     /* the main variant bound for the next draws (use_variant), -1 another program */
    uint32_t profile_mat; /* the material bound last (sy_gli_bind_material) */
    targets t;
    bool lights_dirty;
    /* section planes (sy_gl_camera.clip_planes) of the last render or pick: the Clip block's buffer
     * (SY_GL_CLIP_VS), made on first use; a change re-renders the shadow maps and probes */
    GLuint clip_ubo;
    uint32_t clip_count;
    float clip_planes[SY_GL_CLIP_PLANES_MAX][4];
    /* section caps (sy_gl_camera.clip_cap) of the last render: on, their colour; the cap program
     * (sy_gl_draw.c, cap_pass), made on first use */
    bool clip_cap;
    float clip_cap_color[3];
    struct {
        GLuint prog;
        GLint model, mvp, viewproj, cam_pos, cam_fwd, ortho, color;
    } cap;
    /* deferred shading */
    bool forward; /* sy_gl_device_desc.forward */
    struct { /* the G-buffer pass: perspective, orthographic */
        GLuint prog;
        GLint normal_mat, mvp, model, ppu, ortho_z, has_normals, keys;
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
    uint64_t programs_built;  /* main-pass programs built since creation (sy_gli_main_program) */
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
    uint32_t env_side; /* the specular cube side the frames so far want (sy_gl_ibl_side; never shrinks) */
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
    /* sy_gl_lod.c, throttle: on a software rasterizer, the draws' triangles since the last fence and
     * a ring of THROTTLE_FENCES fences (0: none) */
    bool throttle;
    uint64_t throttle_tris;
    GLsync fences[THROTTLE_FENCES];
    uint32_t fence_next;
    float lod_pixels;    /* sy_gl_set_lod */
    uint64_t culled;     /* instances outside the view in the last main pass */
    float *scratch;
    size_t scratch_len;
    int shared_features; /* material_features of every visible instance (sy_gli_frame_features) */
    bool shared_full;    /* a visible mesh is not VAR_LEAN: no forward draw is (sy_gli_frame_features) */
    bool shared_masked;  /* a visible instance's material is masked (sy_gli_frame_features) */
    /* sy_gli_frame_features: the texture slots some visible material samples (bit k < LAYER_TEXTURES:
     * layer slot k of sy_gli_layer_refs; bit MSIG_BASE_SHIFT + k: base slot k, UNIT_BASE ..
     * UNIT_EMIS), MSIG_IRID one has iridescence, MSIG_ANISO one anisotropy; the programs that read
     * them compile only those (variant_sig) */
    uint32_t material_sig;
    /* the levels of detail of the last meshes created (sy_gl_objects.c, lod_cache_*): a file that
     * repeats a mesh as separate meshes (MetalRoughSpheresNoTextures' 98 spheres) simplifies and
     * measures it once */
    struct lod_cache_entry {
        uint64_t hash, used; /* xxh3 of the mesh's data; the creation that last used it (0: empty) */
        mesh_o mesh;         /* its counts and lod_* fields: the levels' description */
        uint32_t *levels; /* the levels' indices after level 0 (malloc'd), level_indices of them */
        size_t level_indices;
    } lod_cache[LOD_CACHE_ENTRIES];
    uint64_t lod_cache_clock;
};

static inline float sy_gli_dot3f(const float *a, const float *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

enum { CASTER_NONE, CASTER_OPAQUE, CASTER_MASKED }; /* caster_kind */
extern const float sy_gli_cube_faces[6][3][3]; /* (right, up, forward) per GL cube face (sy_gl_base.c) */

typedef struct mat_block {
    float base[4], emissive[4], mrna[4], oist[4];
    int32_t modes[4], tex[4], tex2[4];
    float xf[10][4]; /* per texture slot (base, mr, nrm, occ, emis) two rows of its uv transform */
    /* the layers (m_l0 .. m_l2): (specular colour, clear coat), (coat roughness, sheen roughness,
     * thickness, attenuation distance), (sheen colour, 0), (attenuation colour, 0) */
    float layers[6][4];  /* ..., (cos, sin of the anisotropy rotation, strength, 0), (iridescence, its ior,
                          * thickness minimum, maximum) */
    int32_t ltex[3][4];  /* the layers' textures' uv sets (-1 none), slots as sy_gli_layer_refs */
    float lxf[2 * LAYER_TEXTURES][4]; /* and their uv transforms, two rows each */
} mat_block;

/* std140 Lights block: 16 + 16 + 4*64 + 4*16 + 32*64 bytes, then the cube shadows' parameters
 * (SY_GL_MAX_CUBE_SHADOWS x 16 bytes) */
#define LIGHTS_CUBE_PAR 600
#define LIGHTS_FLOATS (LIGHTS_CUBE_PAR + 4 * SY_GL_MAX_CUBE_SHADOWS)
#define AREAS_FLOATS (8 + SY_GL_MAX_AREA_LIGHTS * 6 * 4) /* std140 Areas block: ivec4 + vec4 + vec4[16 * 6] */

typedef struct frame_state {
    float shadow_vp[SY_GL_MAX_SHADOW_MAPS][16];
    uint32_t shadow_count;
    float cube_pos[SY_GL_MAX_CUBE_SHADOWS][3], cube_near[SY_GL_MAX_CUBE_SHADOWS], cube_far[SY_GL_MAX_CUBE_SHADOWS];
    uint32_t cube_count; /* point lights with a cube shadow */
} frame_state;

typedef struct view_setup {
    float view[16], proj[16], cam_pos[3], cam_fwd[3];
    bool ortho;
    float ppu; /* pixels per unit of the image plane at distance 1 (perspective) or per metre (ortho); 0 =
                * unknown (levels of detail off) */
    /* sy_gli_view_bounds: the frustum's planes (sy_gli_frustum_planes) and the near plane's corners;
     * bounds_ok false until then, or where proj x view is not invertible */
    float planes[6][4], near_pts[4][3];
    bool bounds_ok;
} view_setup;

typedef struct draw_ctx {
    const view_setup *v;
    float viewproj[16], ortho_z[3]; /* orthographic proj[10], proj[14] (and 0) */
    int bound;                      /* the variant whose program is bound, BOUND_GBUF, or -1 */
    int shared;                     /* the frame's shared_features: forward draws use them all
                                     * (draw_instance) */
    bool deferred, gbuf_view_set;   /* opaque draws may go to the G-buffer; its view uniforms are set */
    float near;                     /* the view's near-plane distance (cull_hidden_faces) */
    unsigned cull;                  /* the faces culled now: 0 none, GL_BACK or GL_FRONT */
} draw_ctx;
#define BOUND_GBUF (-2)

static inline int sy_gli_mesh_lean(const mesh_o *m) { return !m->has_attr[3] && !m->has_attr[4]; }

/* sy_gl_base.c */
void *sy_gli_pool_get(const pool *p, uint32_t id);
void *sy_gli_pool_alloc(pool *p);
void sy_gli_pool_free(pool *p, void *item);
void sy_gli_warn(sy_gl_device *dev, const char *fmt, ...);
void sy_gli_m4_mul(const float *a, const float *b, float *o);
bool sy_gli_m4_invert(const float *m, float *out);
void sy_gli_v3_norm(float *v);
void sy_gli_cross3(const float *a, const float *b, float *o);
int sy_gli_caster_kind(const sy_gl_material_desc *d);
GLuint sy_gli_shadow_array(const sy_gl_fns *gl, uint32_t size, uint32_t layers);
void sy_gli_cube_face_view(const float *eye, int f, float *view);
GLuint sy_gli_shadow_cube(const sy_gl_fns *gl, uint32_t size);
void sy_gli_look_along(const float *eye, const float *dir, float *view);
void sy_gli_projection(bool ortho, double l, double r, double b, double t, double n, double f, float *p);
void sy_gli_count_buffer(sy_gl_device *dev, bool uniform, size_t bytes);
sy_gl_result sy_gli_gl_check(sy_gl_device *dev, const char *where, sy_gl_report *rep);
/* With dev->profile: waits for the GL and sets t to the wall and process CPU (all threads, the
 * GL's included) seconds since the last mark (the first mark of a series passes start = true and
 * gets 0); without it, zeros and no wait. */
void sy_gli_profile_mark(sy_gl_device *dev, bool start, double t[2]);
/* With dev->profile: the calling thread's CPU seconds (0 without), and, after a draw started at t0,
 * a line on stderr when the draw took the calling thread more than 20 ms of CPU: llvmpipe compiles
 * a fragment shader for each program and pipeline state on its first draw, on the thread that draws
 * (issue 32: which variants a cold first frame compiles, and what each costs). `what` names the pass. */
double sy_gli_profile_thread(const sy_gl_device *dev);
void sy_gli_profile_draw(const sy_gl_device *dev, double t0, const char *what);
sy_gl_result sy_gli_current(sy_gl_device *dev, sy_gl_report *rep);
void sy_gli_geometry_changed(sy_gl_device *dev);
void sy_gli_frustum_planes(const float *m, float planes[6][4]);
float sy_gli_world_sphere(const inst_o *in, const mesh_o *m, float c[3], float *scale);
bool sy_gli_sphere_outside(const float planes[6][4], const float c[3], float r);

/* sy_gl_programs.c */
/* The texture slots material mt samples, as bits of dev->material_sig: layer slot k bit k (none
 * without dev->layer_units: the layers' units are not read then), base slot k bit MSIG_BASE_SHIFT + k. */
uint32_t sy_gli_material_textures(const sy_gl_device *dev, const mat_o *mt);
/* The name of main variant v under the lights' current signature ("main TEX LIGHTS ... (2 lights: ...)"). */
void sy_gli_variant_name(const sy_gl_device *dev, int v, char *name, size_t len);
/* A stand-in's sampling, as llvmpipe's shader key sees it: bits 0-1 the texel format (0 RGBA8,
 * 1 sRGB, 2 float), 2-3 and 4-5 the wraps (sy_gl_texture_desc's codes), then the flags below. */
#define STANDIN_NEAREST (1u << 6)
#define STANDIN_NPOT_S (1u << 7) /* a side that is not a power of two */
#define STANDIN_NPOT_T (1u << 8)
/* A constant stand-in texture of texel rgba that samples as key says. */
GLuint sy_gli_make_standin(const sy_gl_fns *gl, const unsigned char rgba[4], uint32_t key);
/* The stand-in key of texture t: a stand-in of that key samples as t does. */
uint32_t sy_gli_standin_key(const tex_o *t);
/* Makes the stand-ins with their slots' default keys (sy_gl_device_create). */
void sy_gli_standins_make(sy_gl_device *dev);
/* Once per frame (sy_gli_frame_features): each stand-in takes the sampling of the first texture in
 * its slot among the visible instances' materials (the default where none has one), so that the
 * draws with and without a texture there run one compiled shader (sy_gli_make_standin).
 * sy_gli_standins_want fills the slots of want still STANDIN_ANY from material m's textures (called
 * for each visible material in turn); sy_gli_standins_follow remakes the stand-ins whose key
 * changed. */
#define STANDIN_ANY UINT32_MAX
void sy_gli_standins_want(const sy_gl_device *dev, const mat_o *m, uint32_t want[STANDINS]);
void sy_gli_standins_follow(sy_gl_device *dev, const uint32_t want[STANDINS]);
void sy_gli_material_block(const sy_gl_device *dev, const sy_gl_material_desc *d, mat_block *b);
/* Whether material d uses a material extension (then it draws with VAR_LAYERS). */
bool sy_gli_material_layered(const sy_gl_device *dev, const sy_gl_material_desc *d);
void sy_gli_bind_samplers(const sy_gl_fns *gl, GLuint prog);
/* Binds prog's Clip block (SY_GL_CLIP_VS), when it has one, to BIND_CLIP (bind_samplers does too). */
void sy_gli_bind_clip_block(const sy_gl_fns *gl, GLuint prog);
/* Takes the camera's section planes for the render or pick that begins: uploads the Clip block and
 * binds it; planes other than the last call's re-render the shadow maps and probes (lights_dirty). */
void sy_gli_clip_set(sy_gl_device *dev, const sy_gl_camera *cam);
/* Enables (on) the clip distances of the planes in use around the passes that draw the scene with
 * SY_GL_CLIP_VS shaders, and disables them after (the other passes' shaders write none). */
void sy_gli_clip_enable(sy_gl_device *dev, bool on);
int sy_gli_variant_normalize(int v);
GLuint sy_gli_main_program(sy_gl_device *dev, int v, sy_gl_report *rep);
int sy_gli_deferred_program(sy_gl_device *dev, int v, sy_gl_report *rep);
bool sy_gli_mtab_set(sy_gl_device *dev, uint32_t row, const sy_gl_material_desc *d);
void sy_gli_mtab_upload(sy_gl_device *dev);

/* sy_gl_objects.c */
void sy_gli_lod_cache_free(sy_gl_device *dev); /* dev->lod_cache emptied */
/* Levels 1.. of cube map `cube` (side x side texels per face, a power of two, RGBA16F) from each
 * face's level 0, read back through framebuffer fbo (its colour attachment 0 is left on the last
 * face): the box filter of 2D textures' mipmaps (upload_levels), on the CPU. glGenerateMipmap on
 * the probes' cube cost llvmpipe a blit-shader compile of 0.07-0.10 s in the first frame. Leaves
 * fbo and the cube bound. */
sy_gl_result sy_gli_cube_mipmaps(sy_gl_device *dev, GLuint cube, GLuint fbo, uint32_t side, sy_gl_report *rep);

/* sy_gl_lod.c */
uint32_t sy_gli_draw_mesh_lod(sy_gl_device *dev, const mesh_o *m, uint32_t lod);
void sy_gli_throttle_free(sy_gl_device *dev); /* the throttle's fences deleted (its context current) */
/* The deviation of a level of detail from its mesh as measured (level: its tris triangles'
 * indices into d's vertices; bmin, bmax d's box; tol: the positional deviation meshoptimizer
 * reports): a length in object space that levels are chosen by (sy_gli_choose_lod). At the
 * centroids of up to LOD_CHECK_SAMPLES of the mesh's triangles (evenly spread over its index list)
 * the level's nearest triangles are found through a grid; of those facing the sample's way and
 * within tol of the nearest of them (both sides of a uv seam or a crease), the one that matches
 * best counts: its distance, the angle a
 * between the normals (vertex normals interpolated, or the faces' without them: the rasterizer's
 * flat normals) times half its longest edge (the shading moves by about a across it), and the
 * distance in uv0 times the metres per uv unit of the sample's triangle (the square root of its
 * area over its uv area: a sphere's uv is dense at its poles). The largest over the samples; INFINITY where a sample finds no level triangle within
 * reach, or without memory (the level is not used). meshoptimizer 0.18 simplifies positions alone:
 * a level half a pixel from the mesh's surface can shade it otherwise (NormalTangentTest's bumped
 * tiles 4.7 % brighter, issue 32). */
float sy_gli_level_shading_error(const sy_gl_mesh_desc *d, const float bmin[3], const float bmax[3], const uint32_t *level,
                                 size_t tris, float tol, bool normals_count, float *with_uv);
/* Whether d's vertex normals say more than its geometry: at more than 1 % of its vertices they
 * turn more than LOD_NORMAL_TURN from the area-weighted normals of the faces around the vertex
 * (normals baked from a finer model, custom normals). Only then does a level's deviation count its
 * normals (normals_count of sy_gli_level_shading_error): where the normals follow the geometry, the
 * measured distance stands for them, and counting both kept a bumped terrain's far levels fine
 * (`sy bench instances`: 3.6 x 10^6 triangles drawn instead of 0.7 x 10^6, 1.1 fps). */
bool sy_gli_normals_beyond_geometry(const sy_gl_mesh_desc *d);
#define LOD_NORMAL_TURN 0.2f /* radians (about 11 degrees) */
#define LOD_CHECK_SAMPLES 1024u
#define LOD_CHECK_CELLS (1u << 18) /* the grid's cells at most */
#define LOD_CHECK_NEAR 32u         /* a sample's nearest level triangles weighed */
#define LOD_CHECK_CELL_REFS 32u /* grid entries per level triangle at most (else no bound: about 7 on the samples) */
const mat_o *sy_gli_bind_material(sy_gl_device *dev, sy_gl_material id, bool all_textures);
/* Pixels per world unit at the nearest point of the sphere (c, r) in view v; 0 when unknown (no
 * scale, or the view inside the sphere). Levels of detail, deferred shading and probe sizes use it. */
float sy_gli_sphere_px_per_unit(const view_setup *v, const float c[3], float r);
/* Fills v's planes and near-plane corners from its proj and view (every view that draws the
 * scene: levels of detail look at the part of each box inside the frustum). */
void sy_gli_view_bounds(view_setup *v);
void sy_gli_choose_lods(sy_gl_device *dev, const view_setup *v);
/* Instance in's level for view v: the coarsest whose deviation, projected at the nearest point of
 * its world box inside v's frustum (at least the nearest point of its sphere (c, r), scale its
 * largest axis scale: sy_gli_world_sphere), stays within dev->lod_pixels pixels. */
uint32_t sy_gli_choose_lod(const sy_gl_device *dev, const inst_o *in, const mesh_o *m, const view_setup *v,
                           const float c[3], float r, float scale);
float sy_gli_pixels_per_triangle(const sy_gl_device *dev, const mesh_o *m, uint32_t lod, const view_setup *v,
                                 const float c[3], float r);

/* sy_gl_shadows.c */
void sy_gli_scene_bounds(const sy_gl_device *dev, float *c, float *radius);
/* The eight corners (k = 0..7: bit 0 x, 1 y, 2 z at the maximum) of instance in's world box: its
 * mesh's box through its model matrix (a parallelepiped). */
static inline void sy_gli_instance_box(const inst_o *in, const mesh_o *m, float box[8][3])
{
    for (int k = 0; k < 8; ++k) {
        float p[3] = {k & 1 ? m->bmax[0] : m->bmin[0], k & 2 ? m->bmax[1] : m->bmin[1], k & 4 ? m->bmax[2] : m->bmin[2]};
        for (int a = 0; a < 3; ++a)
            box[k][a] = in->model[a] * p[0] + in->model[4 + a] * p[1] + in->model[8 + a] * p[2] + in->model[12 + a];
    }
}
/* The eight corners (k = 0..7: bit 0 x, 1 y, 2 z at the maximum) of the world box (its mesh's box
 * transformed) of the next visible instance with a mesh from slot *i on; *i moves past it. False
 * when none is left: `for (uint32_t i = 0; sy_gli_next_box(dev, &i, box);)` visits every one. */
static inline bool sy_gli_next_box(const sy_gl_device *dev, uint32_t *i, float box[8][3])
{
    for (; *i < dev->instances.count; ++*i) {
        const inst_o *in = sy_gli_pool_at(&dev->instances, *i);
        if (!in->h.id || !in->visible) continue;
        const mesh_o *m = sy_gli_pool_get(&dev->meshes, in->mesh.id);
        if (!m) continue;
        sy_gli_instance_box(in, m, box);
        ++*i;
        return true;
    }
    return false;
}
void sy_gli_lights_upload(sy_gl_device *dev, frame_state *fs);
sy_gl_result sy_gli_shadow_maps_make(sy_gl_device *dev, sy_gl_report *rep);
void sy_gli_shadow_size_follow(sy_gl_device *dev, uint32_t w, uint32_t h);
void sy_gli_render_shadows(sy_gl_device *dev, const frame_state *fs);

/* sy_gl_draw.c */
void sy_gli_frame_features(sy_gl_device *dev);
void sy_gli_targets_free(sy_gl_device *dev, targets *t);
void sy_gli_frame_end(sy_gl_device *dev);
sy_gl_result sy_gli_targets_ensure(sy_gl_device *dev, uint32_t w, uint32_t h, sy_gl_report *rep);
sy_gl_result sy_gli_view_make(sy_gl_device *dev, const sy_gl_camera *cam, const sy_gl_render_desc *d, view_setup *v, sy_gl_report *rep);
void sy_gli_draw_latlong(sy_gl_device *dev, const view_setup *v, const tex_o *tex, float intensity, uint32_t w,
                         uint32_t h);
void sy_gli_begin_target(sy_gl_device *dev, const view_setup *v);
sy_gl_result sy_gli_finish_target(sy_gl_device *dev, const view_setup *v, float *rgba, float *depth, sy_gl_report *rep);
void sy_gli_bind_frame_resources(sy_gl_device *dev);
sy_gl_result sy_gli_draw_scene(sy_gl_device *dev, const view_setup *v, uint32_t skip, sy_gl_report *rep);

/* sy_gl_render.c */
void sy_gli_probes_free(sy_gl_device *dev);

/* sy_gl_pick.c */
void sy_gli_pick_free(sy_gl_device *dev);

#endif /* SY_GL_INTERNAL_H */
