/* sy_gl_programs.c — the main pass's shader programs: stand-in textures, material uniform blocks,
 * the variants (built on first use, one per feature set and light signature), the deferred
 * shading programs and the material table the deferred pass reads. */
#include "sy_gl_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A material's stand-in for a texture it does not have in one unit (sy_gli_bind_material): a constant
 * texture with a mipmap, sampled as key says (sy_gli_standin_key; the unit's default: the format of
 * the slot, repeat, trilinear, sides powers of two). llvmpipe compiles a fragment shader per state of
 * what it samples (format, filters, wraps, whether the sides are powers of two, whether there are
 * mip levels), so a stand-in that samples like the real textures of its unit lets materials with and
 * without a texture in that unit share one compiled shader (issue 32: the first frame's compile
 * time). The shaders never read a stand-in (a material's m_tex says which units hold its textures);
 * its constant texels filter to their value exactly all the same. */
GLuint sy_gli_make_standin(const sy_gl_fns *gl, const unsigned char rgba[4], uint32_t key)
{
    static const GLint wraps[3] = {GL_REPEAT, GL_CLAMP_TO_EDGE, GL_MIRRORED_REPEAT};
    const uint32_t fmt = key & 3u, w = (key & STANDIN_NPOT_S) ? 3u : 2u, h = (key & STANDIN_NPOT_T) ? 3u : 2u;
    float pxf[36];
    unsigned char px[36];
    for (int i = 0; i < 36; ++i) px[i] = rgba[i & 3], pxf[i] = (float)rgba[i & 3] / 255.0f;
    const GLint internal = fmt == 2u ? GL_RGBA32F : fmt == 1u ? GL_SRGB8_ALPHA8 : GL_RGBA8;
    const GLenum type = fmt == 2u ? GL_FLOAT : GL_UNSIGNED_BYTE;
    const void *data = fmt == 2u ? (const void *)pxf : (const void *)px;
    GLuint t;
    gl->GenTextures(1, &t);
    gl->BindTexture(GL_TEXTURE_2D, t);
    gl->PixelStorei(GL_UNPACK_ALIGNMENT, 1);
    gl->TexImage2D(GL_TEXTURE_2D, 0, internal, (GLsizei)w, (GLsizei)h, 0, GL_RGBA, type, data);
    gl->TexImage2D(GL_TEXTURE_2D, 1, internal, 1, 1, 0, GL_RGBA, type, data);
    gl->TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, wraps[(key >> 2) & 3u]);
    gl->TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, wraps[(key >> 4) & 3u]);
    const bool nearest = (key & STANDIN_NEAREST) != 0;
    gl->TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, nearest ? GL_NEAREST_MIPMAP_LINEAR : GL_LINEAR_MIPMAP_LINEAR);
    gl->TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, nearest ? GL_NEAREST : GL_LINEAR);
    return t;
}

uint32_t sy_gli_standin_key(const tex_o *t)
{
    uint32_t key = t->is_float ? 2u : t->srgb ? 1u : 0u;
    key |= (uint32_t)(t->wrap_s % 3u) << 2 | (uint32_t)(t->wrap_t % 3u) << 4;
    if (t->nearest) key |= STANDIN_NEAREST;
    if (t->width & (t->width - 1u)) key |= STANDIN_NPOT_S;
    if (t->height & (t->height - 1u)) key |= STANDIN_NPOT_T;
    return key;
}

/* Slot i's stand-in texel: a flat normal for the normal maps (the base normal and the coat's),
 * else white; its default key: sRGB for the colours (base, emission, the layers' slots 1 and 5). */
static uint32_t standin_default(int i, unsigned char rgba[4])
{
    static const unsigned char white[4] = {255, 255, 255, 255}, flat[4] = {128, 128, 255, 255};
    memcpy(rgba, i == UNIT_NRM || i == 5 + 4 ? flat : white, 4);
    return i == UNIT_BASE || i == UNIT_EMIS || i == 5 + 1 || i == 5 + 5 ? 1u : 0u;
}

void sy_gli_standins_make(sy_gl_device *dev)
{
    for (int i = 0; i < STANDINS; ++i) {
        unsigned char rgba[4];
        dev->standin_key[i] = standin_default(i, rgba);
        dev->standin[i] = sy_gli_make_standin(dev->gl, rgba, dev->standin_key[i]);
    }
}

void sy_gli_standins_want(const sy_gl_device *dev, const mat_o *m, uint32_t want[STANDINS])
{
    const sy_gl_texture_ref *refs[STANDINS];
    sy_gli_material_refs(&m->d, refs);
    for (int i = 0; i < (dev->layer_units ? STANDINS : 5); ++i) {
        if (want[i] != STANDIN_ANY) continue;
        const tex_o *t = sy_gli_pool_get(&dev->textures, refs[i]->texture.id);
        if (t) want[i] = sy_gli_standin_key(t);
    }
}

void sy_gli_standins_follow(sy_gl_device *dev, const uint32_t want[STANDINS])
{
    for (int i = 0; i < STANDINS; ++i) {
        unsigned char rgba[4];
        uint32_t def = standin_default(i, rgba), key = want[i] != STANDIN_ANY ? want[i] : def;
        if (key == dev->standin_key[i]) continue;
        dev->gl->DeleteTextures(1, &dev->standin[i]);
        dev->standin[i] = sy_gli_make_standin(dev->gl, rgba, key);
        dev->standin_key[i] = key;
    }
}

uint32_t sy_gli_material_textures(const sy_gl_device *dev, const mat_o *mt)
{
    const sy_gl_texture_ref *refs[STANDINS];
    sy_gli_material_refs(&mt->d, refs);
    uint32_t s = 0;
    for (int i = 0; i < (dev->layer_units ? STANDINS : 5); ++i)
        if (sy_gli_pool_get(&dev->textures, refs[i]->texture.id)) s |= i < 5 ? 1u << (MSIG_BASE_SHIFT + i) : 1u << (i - 5);
    return s;
}

void sy_gli_material_block(const sy_gl_device *dev, const sy_gl_material_desc *d, mat_block *b)
{
    memset(b, 0, sizeof *b);
    memcpy(b->base, d->base_color, sizeof b->base);
    memcpy(b->emissive, d->emissive, sizeof d->emissive);
    b->mrna[0] = d->metallic;
    b->mrna[1] = d->roughness;
    b->mrna[2] = d->normal_scale;
    b->mrna[3] = d->alpha_cutoff; /* masked: coverage; blended: the shadow maps' threshold */
    b->oist[0] = d->occlusion_strength;
    b->oist[1] = d->ior >= 1.0f ? d->ior : 1.5f;
    b->oist[2] = d->specular;
    b->oist[3] = d->transmission;
    b->modes[0] = (int32_t)d->alpha_mode;
    b->modes[1] = d->unlit;
    b->modes[2] = d->double_sided;
    b->modes[3] = d->emissive[0] > 0.0f || d->emissive[1] > 0.0f || d->emissive[2] > 0.0f;
    for (int i = 0; i < 3; ++i) {
        b->layers[0][i] = d->specular_color[i] > 0.0f ? d->specular_color[i] : 0.0f;
        b->layers[2][i] = fminf(fmaxf(d->sheen_color[i], 0.0f), 1.0f);
        b->layers[3][i] = fminf(fmaxf(d->attenuation_color[i], 0.0f), 1.0f);
    }
    b->layers[0][3] = fminf(fmaxf(d->clearcoat, 0.0f), 1.0f);
    b->layers[1][0] = fminf(fmaxf(d->clearcoat_roughness, 0.0f), 1.0f);
    b->layers[1][1] = fminf(fmaxf(d->sheen_roughness, 0.0f), 1.0f);
    b->layers[1][2] = d->thickness > 0.0f ? d->thickness : 0.0f;
    b->layers[1][3] = d->attenuation_distance > 0.0f ? d->attenuation_distance : 0.0f;
    b->layers[2][3] = d->clearcoat_normal_scale;
    b->layers[4][0] = cosf(d->anisotropy_rotation);
    b->layers[4][1] = sinf(d->anisotropy_rotation);
    b->layers[4][2] = fminf(fmaxf(d->anisotropy, 0.0f), 1.0f);
    b->layers[5][0] = fminf(fmaxf(d->iridescence, 0.0f), 1.0f);
    b->layers[5][1] = d->iridescence_ior >= 1.0f ? d->iridescence_ior : 1.0f;
    b->layers[5][2] = fmaxf(d->iridescence_thickness[0], 0.0f);
    b->layers[5][3] = fmaxf(d->iridescence_thickness[1], 0.0f);
    const sy_gl_texture_ref *lr[LAYER_TEXTURES];
    sy_gli_layer_refs(d, lr);
    for (int i = 0; i < LAYER_TEXTURES; ++i) {
        bool has = dev->layer_units && sy_gli_pool_get(&dev->textures, lr[i]->texture.id);
        b->ltex[i / 4][i % 4] = has ? (int32_t)(lr[i]->texcoord & 1u) : -1;
        const float id[6] = {1, 0, 0, 0, 1, 0}, *m = lr[i]->transformed ? lr[i]->transform : id;
        memcpy(b->lxf[2 * i], m, 3 * sizeof(float));
        memcpy(b->lxf[2 * i + 1], m + 3, 3 * sizeof(float));
    }
    const sy_gl_texture_ref *refs[5] = {&d->base_color_texture, &d->metallic_roughness_texture, &d->normal_texture,
                                        &d->occlusion_texture, &d->emissive_texture};
    for (int i = 0; i < 5; ++i) {
        int32_t v = sy_gli_pool_get(&dev->textures, refs[i]->texture.id) ? (int32_t)(refs[i]->texcoord & 1u) : -1;
        if (i < 4) b->tex[i] = v;
        else b->tex2[0] = v;
        const float id[6] = {1, 0, 0, 0, 1, 0}, *m = refs[i]->transformed ? refs[i]->transform : id;
        memcpy(b->xf[2 * i], m, 3 * sizeof(float));
        memcpy(b->xf[2 * i + 1], m + 3, 3 * sizeof(float));
    }
}

bool sy_gli_material_layered(const sy_gl_device *dev, const sy_gl_material_desc *d)
{
    bool l = d->clearcoat > 0.0f || (d->attenuation_distance > 0.0f && d->thickness > 0.0f && d->transmission > 0.0f) ||
             d->anisotropy > 0.0f || d->iridescence > 0.0f;
    for (int i = 0; i < 3; ++i) l = l || d->specular_color[i] != 1.0f || d->sheen_color[i] > 0.0f;
    /* a texture on the specular factor or colour changes a material without other extensions */
    l = l || (dev->layer_units && (sy_gli_pool_get(&dev->textures, d->specular_texture.texture.id) ||
                                   sy_gli_pool_get(&dev->textures, d->specular_color_texture.texture.id)));
    return l && !d->unlit;
}

void sy_gli_bind_samplers(const sy_gl_fns *gl, GLuint prog)
{
    static const char *names[UNIT_COUNT] = {"t_base", "t_mr",       "t_nrm",     "t_occ",  "t_emis", "t_shadow",
                                            "t_env_spec", "t_env_irr", "t_brdf", "t_ltc1", "t_ltc2", "t_cshadow0",
                                            "t_cshadow1", "t_probe", "t_l0", "t_l1", "t_l2", "t_l3", "t_l4",
                                            "t_l5", "t_l6", "t_l7", "t_l8", "t_l9", "t_l10", "t_l11"};
    GLint max_units = 0;
    gl->GetIntegerv(GL_MAX_TEXTURE_IMAGE_UNITS, &max_units);
    gl->UseProgram(prog);
    for (int i = 0; i < UNIT_COUNT && i < max_units; ++i) {
        GLint loc = gl->GetUniformLocation(prog, names[i]);
        if (loc >= 0) gl->Uniform1i(loc, i);
    }
    GLuint b = gl->GetUniformBlockIndex(prog, "Material");
    if (b != GL_INVALID_INDEX) gl->UniformBlockBinding(prog, b, BIND_MATERIAL);
    b = gl->GetUniformBlockIndex(prog, "Lights");
    if (b != GL_INVALID_INDEX) gl->UniformBlockBinding(prog, b, BIND_LIGHTS);
    b = gl->GetUniformBlockIndex(prog, "Areas");
    if (b != GL_INVALID_INDEX) gl->UniformBlockBinding(prog, b, BIND_AREAS);
    sy_gli_bind_clip_block(gl, prog);
}

void sy_gli_bind_clip_block(const sy_gl_fns *gl, GLuint prog)
{
    GLuint b = gl->GetUniformBlockIndex(prog, "Clip");
    if (b != GL_INVALID_INDEX) gl->UniformBlockBinding(prog, b, BIND_CLIP);
}

void sy_gli_clip_set(sy_gl_device *dev, const sy_gl_camera *cam)
{
    const sy_gl_fns *gl = dev->gl;
    uint32_t n = cam->clip_count < SY_GL_CLIP_PLANES_MAX ? cam->clip_count : SY_GL_CLIP_PLANES_MAX;
    bool changed = n != dev->clip_count || (n && memcmp(dev->clip_planes, cam->clip_planes, n * sizeof dev->clip_planes[0]));
    if (!dev->clip_ubo) {
        gl->GenBuffers(1, &dev->clip_ubo);
        changed = true;
    }
    if (changed) {
        float block[SY_GL_CLIP_PLANES_MAX][4];
        for (uint32_t i = 0; i < SY_GL_CLIP_PLANES_MAX; ++i) {
            static const float keep_all[4] = {0.0f, 0.0f, 0.0f, 1.0f};
            memcpy(block[i], i < n ? cam->clip_planes[i] : keep_all, sizeof block[i]);
        }
        gl->BindBuffer(GL_UNIFORM_BUFFER, dev->clip_ubo);
        gl->BufferData(GL_UNIFORM_BUFFER, sizeof block, block, GL_DYNAMIC_DRAW);
        gl->BindBuffer(GL_UNIFORM_BUFFER, 0);
        if (n != dev->clip_count || n) dev->lights_dirty = true; /* the shadow maps and probes see the cut */
        dev->clip_count = n;
        if (n) memcpy(dev->clip_planes, cam->clip_planes, n * sizeof dev->clip_planes[0]);
    }
    gl->BindBufferBase(GL_UNIFORM_BUFFER, BIND_CLIP, dev->clip_ubo);
    dev->clip_cap = n && cam->clip_cap;
    memcpy(dev->clip_cap_color, cam->clip_cap_color, sizeof dev->clip_cap_color);
}

void sy_gli_clip_enable(sy_gl_device *dev, bool on)
{
    const sy_gl_fns *gl = dev->gl;
    for (uint32_t i = 0; i < dev->clip_count; ++i) {
        if (on) gl->Enable(GL_CLIP_DISTANCE0 + i);
        else gl->Disable(GL_CLIP_DISTANCE0 + i);
    }
}

/* Drops variant bits that cannot matter, so that equivalent draws share one program. */
int sy_gli_variant_normalize(int v)
{
    if (!(v & (VAR_LIGHTS | VAR_ENV | VAR_AREA | VAR_PROBE)) || !(v & VAR_TEX)) v &= ~VAR_NMAP;
    if (!(v & VAR_LIGHTS)) v &= ~(7 << VAR_NL_SHIFT);
    if (!(v & VAR_LIGHTS)) v &= ~VAR_SHADOW;
    if (!(v & VAR_AREA)) v &= ~VAR_ASHADOW;
    if (!(v & (VAR_ENV | VAR_PROBE))) v &= ~VAR_TRANS;
    if (!(v & (VAR_LIGHTS | VAR_ENV | VAR_AREA | VAR_PROBE))) v &= ~VAR_LAYERS;
    return v;
}

/* The part of the lights' signature (light_sig) a program of variant bits v depends on. The
 * shaders call each punctual light (constant light count) with its shadow fixed (sy_gl_shaders.c,
 * shade_light): straight-line code that makes only the look-ups the frame needs (llvmpipe runs
 * every branch for every pixel). Emissive polygons run in two loops whose bounds are uniforms (the
 * Areas block, sy_gli_lights_upload), so no program depends on them: loops of constant bounds were
 * unrolled, sixteen inlined copies took LLVM many seconds to compile (issue 32). */
static uint64_t variant_sig(const sy_gl_device *dev, int v)
{
    uint64_t s = 0;
    if ((v & VAR_SHADOW) && ((v >> VAR_NL_SHIFT) & 7)) s |= dev->light_sig & 0x3FFFu;
    if ((v & VAR_LIGHTS) && ((v >> VAR_NL_SHIFT) & 7)) s |= dev->light_sig & (0x3FFFull << 48);
    /* bits MSIG_SHIFT ..: the material features of the frame (dev->material_sig) where the program
     * reads them: the base slots and the layers' texture slots 0 .. 10 (SY_TEX; the layers' with
     * SY_LAYERS), iridescence and anisotropy (SY_LAYERS), the transmission texture, layer slot 11
     * (SY_TRANS with SY_TEX). llvmpipe compiles every texture look-up of a program whether a
     * material takes its branch or not: the layered programs' eleven look-ups were about 0.2 s of
     * their 0.6-0.7 s compile (issue 32) */
    const uint32_t ms = dev->material_sig, base = 31u << MSIG_BASE_SHIFT;
    uint32_t l = 0;
    if (v & VAR_TEX) l |= ms & base;
    if ((v & VAR_LAYERS) && (v & VAR_TEX)) l |= ms & ((1u << 11) - 1u);
    if (v & VAR_LAYERS) l |= ms & (MSIG_IRID | MSIG_ANISO);
    if ((v & VAR_TRANS) && (v & VAR_TEX)) l |= ms & (1u << 11);
    return s | (uint64_t)l << MSIG_SHIFT;
}

/* The #defines of variant bits v and the lights' signature sig (variant_sig) (sy_gl_shaders.c)
 * into defs and their names after name's text. */
static void variant_defines(int v, uint64_t sig, char *defs, size_t defs_len, char *name, size_t name_len)
{
    static const char *const names[7] = {"LEAN", "MASK", "TEX", "NMAP", "LIGHTS", "ENV", "SHADOW"};
    static const struct {
        int bit;
        const char *name;
    } more[5] = {{VAR_AREA, "AREA"}, {VAR_TRANS, "TRANS"}, {VAR_ASHADOW, "ASHADOW"}, {VAR_PROBE, "PROBE"},
                 {VAR_LAYERS, "LAYERS"}};
    size_t dl = strlen(defs), nl = strlen(name);
    for (int b = 0; b < 7; ++b) {
        if (!(v & (1 << b))) continue;
        dl += (size_t)snprintf(defs + dl, defs_len - dl, "#define SY_%s 1\n", names[b]);
        nl += (size_t)snprintf(name + nl, name_len - nl, " %s", names[b]);
    }
    for (int k = 0; k < 5; ++k) {
        if (!(v & more[k].bit)) continue;
        dl += (size_t)snprintf(defs + dl, defs_len - dl, "#define SY_%s 1\n", more[k].name);
        nl += (size_t)snprintf(name + nl, name_len - nl, " %s", more[k].name);
    }
    const uint32_t ms = (uint32_t)(sig >> MSIG_SHIFT);
    static const char *const base_names[5] = {"base", "mr", "nrm", "occ", "emis"};
    for (int k = 0; k < 5; ++k)
        if (ms & (1u << (MSIG_BASE_SHIFT + k))) {
            dl += (size_t)snprintf(defs + dl, defs_len - dl, "#define SY_TX%d 1\n", k);
            nl += (size_t)snprintf(name + nl, name_len - nl, " %s", base_names[k]);
        }
    for (int k = 0; k < LAYER_TEXTURES; ++k)
        if (ms & (1u << k)) {
            dl += (size_t)snprintf(defs + dl, defs_len - dl, "#define SY_LX%d 1\n", k);
            nl += (size_t)snprintf(name + nl, name_len - nl, " l%d", k);
        }
    if (ms & MSIG_IRID) {
        dl += (size_t)snprintf(defs + dl, defs_len - dl, "#define SY_IRID 1\n");
        nl += (size_t)snprintf(name + nl, name_len - nl, " IRID");
    }
    if (ms & MSIG_ANISO) {
        dl += (size_t)snprintf(defs + dl, defs_len - dl, "#define SY_ANISO 1\n");
        nl += (size_t)snprintf(name + nl, name_len - nl, " ANISO");
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

/* A uniform a program's struct keeps: where its location goes and its name in the shaders ("u_"
 * and the field's name). */
typedef struct uniform_loc {
    GLint *at;
    const char *name;
} uniform_loc;
#define UNIFORM(s, field) {&(s)->field, "u_" #field}

/* Looks up the n uniforms u of program p. */
static void uniforms_locate(const sy_gl_fns *gl, GLuint p, const uniform_loc *u, size_t n)
{
    for (size_t i = 0; i < n; ++i) *u[i].at = gl->GetUniformLocation(p, u[i].name);
}

void sy_gli_variant_name(const sy_gl_device *dev, int v, char *name, size_t len)
{
    char defs[1024] = "";
    snprintf(name, len, "main");
    variant_defines(v, variant_sig(dev, v), defs, sizeof defs, name, len);
}

/* A draw that took the GL thread over 20 ms of CPU since t0 (a shader compile): its program and
 * what the material's texture units sample, on stderr (SY_GL_PROFILE). */
void sy_gli_profile_draw(const sy_gl_device *dev, double t0, const char *what)
{
    if (!dev->profile) return;
    double dt = sy_gli_profile_thread(dev) - t0;
    if (dt <= 0.02) return;
    char name[256] = "another program";
    if (dev->profile_var >= 0) sy_gli_variant_name(dev, dev->profile_var, name, sizeof name);
    char tex[512] = "";
    const mat_o *m = dev->profile_var >= 0 ? sy_gli_pool_get(&dev->materials, dev->profile_mat) : NULL;
    if (m) { /* what the material's texture units sample: llvmpipe's shader key holds their sampling */
        const sy_gl_texture_ref *refs[STANDINS];
        sy_gli_material_refs(&m->d, refs);
        size_t n = 0;
        for (int i = 0; i < 5 + LAYER_TEXTURES && n < sizeof tex; ++i) {
            const tex_o *t = sy_gli_pool_get(&dev->textures, refs[i]->texture.id);
            if (t)
                n += (size_t)snprintf(tex + n, sizeof tex - n, " %s%d:%ux%u%s%s wrap %u,%u", i < 5 ? "t" : "l", i < 5 ? i : i - 5,
                                      t->width, t->height, t->is_float ? " float" : t->srgb ? " srgb" : "",
                                      t->nearest ? " nearest" : "", t->wrap_s, t->wrap_t);
        }
    }
    fprintf(stderr, "raster profile: %s draw took %.3f s of the GL thread's CPU (a shader compile): %s;%s%s\n", what, dt, name,
            tex[0] ? tex : " no textures", m && m->d.alpha_mode == SY_GL_ALPHA_BLEND ? "; blended" : "");
}

/* The main program for variant bits v, built and cached on first use; 0 (the failure reported to rep) when the
 * driver rejects it. */
GLuint sy_gli_main_program(sy_gl_device *dev, int v, sy_gl_report *rep)
{
    v = sy_gli_variant_normalize(v);
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
    if (sy_gl_program_build_tail(gl, name, sy_gl_main_vs, sy_gl_main_fs, defs, (v & VAR_LAYERS) ? sy_gl_layers_fs : NULL,
                                 &p, rep) != SY_GL_OK)
        return 0;
    dev->programs_built++;
    dev->pm[v].prog = p;
    dev->pm[v].sig = sig;
    struct main_prog *m = &dev->pm[v];
    const uniform_loc u[] = {UNIFORM(m, model),   UNIFORM(m, normal_mat), UNIFORM(m, mvp),         UNIFORM(m, cam_pos),
                             UNIFORM(m, cam_fwd), UNIFORM(m, ortho),      UNIFORM(m, ortho_z),     UNIFORM(m, mirror),
                             UNIFORM(m, has_normals), UNIFORM(m, probe_lod)};
    uniforms_locate(gl, p, u, sizeof u / sizeof u[0]);
    dev->pm[v].frame = 0;
    sy_gli_bind_samplers(gl, p);
    return p;
}

/* The deferred shading pass for the frame's lighting variant bits v (only the lighting bits
 * count) and light signature, built and kept on first use: its index in dev->dp, or -1
 * (the failure reported to rep) when the driver rejects it. */
int sy_gli_deferred_program(sy_gl_device *dev, int v, sy_gl_report *rep)
{
    v = sy_gli_variant_normalize(v & (VAR_LIGHTS | VAR_ENV | VAR_SHADOW | VAR_AREA | VAR_ASHADOW | (7 << VAR_NL_SHIFT)));
    uint64_t sig = variant_sig(dev, v);
    for (uint32_t i = 0; i < dev->dp_count; ++i)
        if (dev->dp[i].var == v && dev->dp[i].sig == sig) return (int)i;
    char defs[1024] = "", name[256] = "deferred";
    snprintf(defs, sizeof defs, "#define SY_SAMPLES %u\n", dev->msaa);
    variant_defines(v, sig, defs, sizeof defs, name, sizeof name);
    const sy_gl_fns *gl = dev->gl;
    GLuint p = 0;
    if (sy_gl_program_build(gl, name, sy_gl_rect_vs, sy_gl_deferred_fs, defs, &p, rep) != SY_GL_OK) return -1;
    uint32_t i = dev->dp_count;
    if (i == DEFERRED_PROGS) { /* all kept: the new one takes the slots in turn (one is used per frame) */
        i = dev->dp_next++ % DEFERRED_PROGS;
        gl->DeleteProgram(dev->dp[i].prog);
    } else
        dev->dp_count++;
    dev->dp[i].var = v;
    dev->dp[i].sig = sig;
    dev->dp[i].prog = p;
    const uniform_loc u[] = {UNIFORM(&dev->dp[i], unproj),  UNIFORM(&dev->dp[i], inv_view), UNIFORM(&dev->dp[i], px),
                             UNIFORM(&dev->dp[i], cam_pos), UNIFORM(&dev->dp[i], cam_fwd),  UNIFORM(&dev->dp[i], ortho),
                             UNIFORM(&dev->dp[i], rects)};
    uniforms_locate(gl, p, u, sizeof u / sizeof u[0]);
    sy_gli_bind_samplers(gl, p); /* the light and environment units and blocks; then its own three */
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
    sy_gli_material_block(dev, d, &b);
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
bool sy_gli_mtab_set(sy_gl_device *dev, uint32_t row, const sy_gl_material_desc *d)
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
void sy_gli_mtab_upload(sy_gl_device *dev)
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
