/* sy_assimp_materials.c — Assimp materials onto the core's metallic-roughness model (the rule in
 * sy_assimp.h and docs/FORMATS.md; classic shading through sy_classic.h) and their textures: files
 * named by the material (confined to the model's folder, decoded by sy_image.h) and textures
 * embedded in the file (compressed: decoded the same way; raw BGRA texels: taken as they are),
 * one sy_texture per (image, colour role); separate metalness and roughness maps combined into one
 * metallic-roughness texture (resampled with stb_image_resize where their sizes differ). */
#include "sy_assimp_internal.h"

#include "sy_classic.h"
#include "sy_image.h"

#include <assimp/material.h>

#include <dirent.h>
#include <stb_image_resize.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

/* >>textures ---------------------------------------------------------------------------------- */

void asp_free_textures(asp_loader *L)
{
    for (size_t k = 0; k < L->texture_count; ++k) free(L->textures[k].key);
    free(L->textures);
    L->textures = NULL;
    L->texture_count = L->texture_cap = 0;
}

static const char *base_name(const char *p)
{
    const char *s = strrchr(p, '/');
    return s ? s + 1 : p;
}

/* The embedded texture a path names: "*N", or an embedded texture whose file name (or its last
 * part) matches the path's. NULL: none. */
static const struct aiTexture *embedded(const asp_loader *L, const char *path)
{
    const struct aiScene *s = L->ai;
    if (path[0] == '*') {
        char *end = NULL;
        unsigned long k = strtoul(path + 1, &end, 10);
        return end && *end == '\0' && k < s->mNumTextures ? s->mTextures[k] : NULL;
    }
    for (unsigned k = 0; k < s->mNumTextures; ++k) {
        const char *f = asp_str(&s->mTextures[k]->mFilename);
        if (f[0] && (!strcmp(f, path) || !strcmp(base_name(f), base_name(path)))) return s->mTextures[k];
    }
    return NULL;
}

/* Pixels of an embedded texture: compressed (mHeight 0: mWidth bytes of a PNG, JPEG, ...) decoded,
 * raw BGRA texels converted to RGBA. */
static sy_result decode_embedded(asp_loader *L, const struct aiTexture *t, sy_image_pixels *img, sy_error *e)
{
    if (t->mHeight == 0) return sy_image_decode(t->pcData, t->mWidth, L->opt.max_image_pixels, &L->budget, img, e);
    uint64_t px = (uint64_t)t->mWidth * t->mHeight;
    if (!t->pcData || px > L->opt.max_image_pixels)
        return sy_error_set(e, SY_ERR_LIMIT, "%ux%u pixels exceed the limit", t->mWidth, t->mHeight);
    if (!sy_budget_fits(&L->budget, px, 4))
        return sy_error_set(e, SY_ERR_LIMIT, "%ux%u pixels exceed what is left of the scene budget", t->mWidth, t->mHeight);
    uint8_t *p = malloc((size_t)px * 4);
    if (!p) return sy_error_set(e, SY_ERR_OUT_OF_MEMORY, "out of memory for %ux%u pixels", t->mWidth, t->mHeight);
    for (uint64_t k = 0; k < px; ++k) {
        const struct aiTexel *x = &t->pcData[k];
        p[4 * k] = x->r, p[4 * k + 1] = x->g, p[4 * k + 2] = x->b, p[4 * k + 3] = x->a;
    }
    (void)sy_budget_charge(&L->budget, px, 4, NULL, "texture");
    *img = (sy_image_pixels){p, t->mWidth, t->mHeight, 4};
    return SY_OK;
}

/* A file the material names: as given (backslashes read as slashes) relative to the folder of the
 * OBJ's MTL library (the first of them where it is found; a relative name in an MTL is relative to
 * the MTL, as Blender and three.js read it: Assimp keeps the name as written), else in the model's
 * folder, else its last part there (files made on another machine name their author's folders).
 * Every one confined (asp_read_named). */
static sy_result read_texture_file(asp_loader *L, const char *path, const char *where, void **data, size_t *size,
                                   sy_error *e)
{
    char uri[1024];
    snprintf(uri, sizeof uri, "%s", path);
    for (char *c = uri; *c; ++c)
        if (*c == '\\') *c = '/';
    if (!strncmp(uri, "./", 2)) memmove(uri, uri + 2, strlen(uri + 2) + 1);
    sy_result r = SY_ERR_NOT_FOUND;
    for (size_t k = 0; k < L->mtl_dir_count && uri[0] != '/' && r == SY_ERR_NOT_FOUND; ++k) {
        if (!L->mtl_dirs[k][0]) continue; /* the model's folder: below */
        char rel[1200];
        snprintf(rel, sizeof rel, "%s%s", L->mtl_dirs[k], uri);
        r = asp_read_named(L, rel, data, size, e);
    }
    if (r == SY_ERR_NOT_FOUND) r = asp_read_named(L, uri, data, size, e);
    if (r == SY_ERR_NOT_FOUND || (r == SY_ERR_LIMIT && (uri[0] == '/' || (uri[0] && uri[1] == ':')))) {
        const char *b = base_name(uri);
        sy_error e2 = {0};
        if (b != uri && asp_read_named(L, b, data, size, &e2) == SY_OK) {
            asp_warn(L, "%s: texture '%s' read as '%s' from the model's folder", where, path, b);
            return SY_OK;
        }
        /* names written on a case-insensitive file system (3DS: TEST.PNG for test.png) */
        DIR *d = opendir(L->model_dir[0] ? L->model_dir : ".");
        struct dirent *de;
        char found[256] = "";
        while (d && (de = readdir(d)))
            if (!strcasecmp(de->d_name, b) && strlen(de->d_name) < sizeof found) {
                snprintf(found, sizeof found, "%s", de->d_name);
                break;
            }
        if (d) closedir(d);
        if (found[0] && asp_read_named(L, found, data, size, &e2) == SY_OK) {
            asp_warn(L, "%s: texture '%s' read as '%s' (the name in another case) from the model's folder", where, path, found);
            return SY_OK;
        }
    }
    return r;
}

/* The decoded pixels of the image at path (embedded or a file). SY_OK with img->pixels NULL: it
 * cannot be made (warned, counted as skipped); an error fails the load (a refused path). */
static sy_result image_pixels(asp_loader *L, const char *path, const char *where, sy_image_pixels *img)
{
    *img = (sy_image_pixels){0};
    sy_error e = {0};
    sy_result r;
    const struct aiTexture *t = embedded(L, path);
    if (t) {
        r = decode_embedded(L, t, img, &e);
    } else if (path[0] == '*') {
        r = sy_error_set(&e, SY_ERR_PARSE, "no embedded texture %s", path);
    } else {
        void *data = NULL;
        size_t size = 0;
        r = read_texture_file(L, path, where, &data, &size, &e);
        if (r == SY_ERR_LIMIT && !strstr(e.message, "scene budget")) return sy_error_set(&L->err, r, "%s", e.message); /* refused path */
        if (r == SY_OK) r = sy_image_decode(data, size, L->opt.max_image_pixels, &L->budget, img, &e);
        free(data);
    }
    if (r == SY_OK) return SY_OK;
    if (r == SY_ERR_NOT_FOUND) asp_warn(L, "%s: texture '%s' not found in the model's folder; no texture", where, path);
    else asp_warn(L, "%s: texture '%s': %s; no texture", where, path, e.message);
    L->info->counts.skipped++;
    *img = (sy_image_pixels){0};
    return SY_OK;
}

/* A cache slot for (key, srgb): *found when the texture was made (or failed) before. */
static sy_result texture_slot_for(asp_loader *L, const char *key, bool srgb, const char *where, asp_texture **slot,
                                  bool *found)
{
    *found = false;
    for (size_t k = 0; k < L->texture_count; ++k)
        if (L->textures[k].srgb == srgb && !strcmp(L->textures[k].key, key)) {
            *slot = &L->textures[k];
            *found = true;
            return SY_OK;
        }
    if (!sy_array_reserve(&L->textures, L->texture_count, &L->texture_cap, sizeof *L->textures, 16))
        return asp_fail(L, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", where);
    asp_texture *sl = &L->textures[L->texture_count];
    if (!(sl->key = strdup(key))) return asp_fail(L, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", where);
    sl->srgb = srgb;
    sl->tex = (sy_texture){0};
    sl->channels = 0;
    sl->mr_used = 0;
    L->texture_count++;
    *slot = sl;
    return SY_OK;
}

/* A texture of the pixels (taken: freed on every path) into slot. */
static sy_result make_texture(asp_loader *L, sy_image_pixels *img, const char *name, const char *where, asp_texture *slot)
{
    sy_blob *blob = NULL;
    sy_result r = sy_blob_create_take(img->pixels, (size_t)img->width * img->height * img->channels, &blob, &L->err);
    if (r) {
        sy_image_pixels_free(img);
        return r;
    }
    img->pixels = NULL;
    uint32_t id = 0;
    sy_image_info ii = {img->width, img->height, img->channels, slot->srgb ? SY_PIXEL_U8_SRGB : SY_PIXEL_U8_LINEAR};
    if (!(r = asp_new(L, SY_TYPE_TEXTURE, name, where, &id))) r = sy_texture_set_image(L->scene, (sy_texture){id}, &ii, blob, &L->err);
    sy_blob_release(blob);
    if (r) return r;
    slot->tex = (sy_texture){id};
    slot->channels = img->channels;
    L->info->counts.textures++;
    return SY_OK;
}

/* The texture for path in a colour (srgb) or data role; {0} with a warning when it cannot be made. */
static sy_result get_texture(asp_loader *L, const char *path, bool srgb, const char *where, sy_texture *out,
                             uint32_t *channels)
{
    *out = (sy_texture){0};
    *channels = 0;
    asp_texture *slot = NULL;
    bool found;
    sy_result r = texture_slot_for(L, path, srgb, where, &slot, &found);
    if (r == SY_OK && !found) {
        sy_image_pixels img;
        if ((r = image_pixels(L, path, where, &img)) == SY_OK && img.pixels) r = make_texture(L, &img, base_name(path), where, slot);
    }
    if (r) return r;
    *out = slot->tex;
    *channels = slot->channels;
    return SY_OK;
}

static uint32_t map_wrap(enum aiTextureMapMode m)
{
    return m == aiTextureMapMode_Clamp || m == aiTextureMapMode_Decal ? SY_WRAP_CLAMP
           : m == aiTextureMapMode_Mirror                            ? SY_WRAP_MIRROR
                                                                     : SY_WRAP_REPEAT;
}

/* Slot `type` of material i into ref (the first texture of the slot). */
static sy_result texture_slot(asp_loader *L, unsigned i, enum aiTextureType type, bool srgb, const char *slot,
                              sy_texture_ref *ref, uint32_t *channels)
{
    *channels = 0;
    const struct aiMaterial *m = L->ai->mMaterials[i];
    if (aiGetMaterialTextureCount(m, type) == 0) return SY_OK;
    struct aiString path;
    enum aiTextureMapping mapping = aiTextureMapping_UV;
    unsigned uv = 0;
    enum aiTextureMapMode mm[2] = {aiTextureMapMode_Wrap, aiTextureMapMode_Wrap};
    if (aiGetMaterialTexture(m, type, 0, &path, &mapping, &uv, NULL, NULL, mm, NULL) != aiReturn_SUCCESS) return SY_OK;
    char where[96];
    snprintf(where, sizeof where, "materials[%u].%s", i, slot);
    if (mapping != aiTextureMapping_UV) {
        asp_warn(L, "%s: texture '%s' uses a projection (%d), not texture coordinates; no texture", where, asp_str(&path),
                 (int)mapping);
        L->info->counts.skipped++;
        return SY_OK;
    }
    if (uv > 1) {
        asp_warn(L, "%s: texture coordinate set %u not kept; set 0 used", where, uv);
        uv = 0;
    }
    sy_texture t;
    sy_result r = get_texture(L, asp_str(&path), srgb, where, &t, channels);
    if (r || !t.id) return r;
    sy_sampler smp = {map_wrap(mm[0]), map_wrap(mm[1]), SY_FILTER_LINEAR, SY_FILTER_LINEAR};
    if ((r = sy_texture_set_sampler(L->scene, t, &smp, &L->err))) return r;
    ref->texture = t;
    ref->texcoord = uv;
    ref->scale = 1.0f;
    ref->uv_scale[0] = ref->uv_scale[1] = 1.0f;
    return SY_OK;
}

/* >>metallic-roughness ------------------------------------------------------------------------ */

/* A single-channel map of material i: its path, texture coordinate set and wrap modes. */
typedef struct asp_map {
    struct aiString path;
    unsigned uv;
    enum aiTextureMapMode mm[2];
    sy_image_pixels img;
} asp_map;

static bool get_map(asp_loader *L, unsigned i, enum aiTextureType type, const char *slot, asp_map *out)
{
    const struct aiMaterial *m = L->ai->mMaterials[i];
    memset(out, 0, sizeof *out);
    out->mm[0] = out->mm[1] = aiTextureMapMode_Wrap;
    enum aiTextureMapping mapping = aiTextureMapping_UV;
    if (!aiGetMaterialTextureCount(m, type) ||
        aiGetMaterialTexture(m, type, 0, &out->path, &mapping, &out->uv, NULL, NULL, out->mm, NULL) != aiReturn_SUCCESS)
        return false;
    if (mapping != aiTextureMapping_UV) {
        asp_warn(L, "materials[%u].%s: texture '%s' uses a projection (%d), not texture coordinates; no texture", i, slot,
                 asp_str(&out->path), (int)mapping);
        L->info->counts.skipped++;
        return false;
    }
    if (out->uv > 1) {
        asp_warn(L, "materials[%u].%s: texture coordinate set %u not kept; set 0 used", i, slot, out->uv);
        out->uv = 0;
    }
    return true;
}

/* Resamples *img (the first channel kept) to w x h with stb_image_resize; false: out of memory
 * or budget (warned). */
static bool resample_first_channel(asp_loader *L, const char *where, const char *what, sy_image_pixels *img, uint32_t w,
                                   uint32_t h)
{
    if (!sy_budget_fits(&L->budget, (uint64_t)w * h, 1)) {
        asp_warn(L, "%s: resampling the %s map to %ux%u exceeds what is left of the scene budget; no texture", where, what, w, h);
        return false;
    }
    uint8_t *grey = malloc((size_t)img->width * img->height), *out = malloc((size_t)w * h);
    if (!grey || !out) {
        free(grey);
        free(out);
        asp_warn(L, "%s: out of memory resampling the %s map; no texture", where, what);
        return false;
    }
    for (size_t k = 0, n = (size_t)img->width * img->height; k < n; ++k) grey[k] = img->pixels[k * img->channels];
    int ok = stbir_resize_uint8(grey, (int)img->width, (int)img->height, 0, out, (int)w, (int)h, 0, 1);
    free(grey);
    if (!ok) {
        free(out);
        asp_warn(L, "%s: stb_image_resize failed on the %s map; no texture", where, what);
        return false;
    }
    (void)sy_budget_charge(&L->budget, (uint64_t)w * h, 1, NULL, "texture");
    sy_image_pixels_free(img);
    *img = (sy_image_pixels){out, w, h, 1};
    return true;
}

/* Separate metalness and roughness maps (aiTextureType_METALNESS, _DIFFUSE_ROUGHNESS: FBX PBR,
 * MTL map_Pm / map_Pr) into the core's one metallic-roughness texture (the rule in sy_assimp.h):
 * G = the roughness map's first channel, B = the metalness map's, R 255; a missing map leaves
 * its channel 255 (the factor alone). Maps of different sizes: the smaller resampled to the
 * larger's size (stb_image_resize), with a warning. Both slots naming one image: a packed glTF
 * texture, taken as it is. Where the file gives no factor for a mapped channel, the factor is 1
 * (the map decides). Made once per pair of images. */
static sy_result metallic_roughness_maps(asp_loader *L, unsigned i, const char *name, bool has_metallic,
                                         bool has_roughness, sy_material_data *md)
{
    asp_map mt, rg;
    bool hm = get_map(L, i, aiTextureType_METALNESS, "metalness", &mt);
    bool hr = get_map(L, i, aiTextureType_DIFFUSE_ROUGHNESS, "roughness", &rg);
    if (!hm && !hr) return SY_OK;
    char where[96];
    snprintf(where, sizeof where, "materials[%u] '%.40s' metallic-roughness", i, name);
    const asp_map *first = hm ? &mt : &rg;
    if (hm && hr && mt.uv != rg.uv)
        asp_warn(L, "%s: metalness and roughness maps use texture coordinate sets %u and %u; set %u used for both", where,
                 mt.uv, rg.uv, mt.uv);
    sy_texture tex = {0};
    uint32_t ch = 0;
    unsigned used = 3; /* the maps the texture holds */
    sy_result r;
    if (hm && hr && !strcmp(asp_str(&mt.path), asp_str(&rg.path))) { /* one packed image */
        if ((r = get_texture(L, asp_str(&mt.path), false, where, &tex, &ch))) return r;
    } else {
        char key[2 * MAXLEN + 8];
        snprintf(key, sizeof key, "\001mr\n%s\n%s", hm ? asp_str(&mt.path) : "", hr ? asp_str(&rg.path) : "");
        asp_texture *slot = NULL;
        bool found;
        if ((r = texture_slot_for(L, key, false, where, &slot, &found))) return r;
        if (!found) {
            if (hm && (r = image_pixels(L, asp_str(&mt.path), where, &mt.img))) return r;
            if (hr && (r = image_pixels(L, asp_str(&rg.path), where, &rg.img))) {
                sy_image_pixels_free(&mt.img);
                return r;
            }
            sy_image_pixels *a = mt.img.pixels ? &mt.img : NULL, *b = rg.img.pixels ? &rg.img : NULL;
            uint32_t w = a ? a->width : b ? b->width : 0, h = a ? a->height : b ? b->height : 0;
            bool ok = a || b;
            if (a && b && (a->width != b->width || a->height != b->height)) {
                bool grow_b = (uint64_t)a->width * a->height >= (uint64_t)b->width * b->height;
                sy_image_pixels *small = grow_b ? b : a, *big = grow_b ? a : b;
                w = big->width;
                h = big->height;
                asp_warn(L, "%s: metalness map '%s' is %ux%u, roughness map '%s' %ux%u: the %s map resampled to %ux%u", where,
                         asp_str(&mt.path), a->width, a->height, asp_str(&rg.path), b->width, b->height,
                         grow_b ? "roughness" : "metalness", w, h);
                ok = resample_first_channel(L, where, grow_b ? "roughness" : "metalness", small, w, h);
            }
            uint8_t *px = NULL;
            if (ok && !sy_budget_fits(&L->budget, (uint64_t)w * h, 3)) {
                asp_warn(L, "%s: %ux%u pixels exceed what is left of the scene budget; no texture", where, w, h);
                ok = false;
            }
            if (ok && !(px = malloc((size_t)w * h * 3))) {
                sy_image_pixels_free(&mt.img);
                sy_image_pixels_free(&rg.img);
                return asp_fail(L, SY_ERR_OUT_OF_MEMORY, "%s: out of memory for %ux%u pixels", where, w, h);
            }
            for (size_t k = 0, n = ok ? (size_t)w * h : 0; k < n; ++k) {
                px[3 * k] = 255;
                px[3 * k + 1] = b ? b->pixels[k * b->channels] : 255;
                px[3 * k + 2] = a ? a->pixels[k * a->channels] : 255;
            }
            sy_image_pixels_free(&mt.img);
            sy_image_pixels_free(&rg.img);
            slot->mr_used = (a ? 1u : 0u) | (b ? 2u : 0u);
            if (ok) {
                (void)sy_budget_charge(&L->budget, (uint64_t)w * h, 3, NULL, "texture");
                sy_image_pixels img = {px, w, h, 3};
                if ((r = make_texture(L, &img, base_name(asp_str(&first->path)), where, slot))) return r;
            } else if (a || b) {
                L->info->counts.skipped++;
            }
        }
        tex = slot->tex;
        used = slot->mr_used;
    }
    if (!tex.id) return SY_OK;
    sy_sampler smp = {map_wrap(first->mm[0]), map_wrap(first->mm[1]), SY_FILTER_LINEAR, SY_FILTER_LINEAR};
    if ((r = sy_texture_set_sampler(L->scene, tex, &smp, &L->err))) return r;
    md->metallic_roughness_texture = (sy_texture_ref){.texture = tex, .texcoord = first->uv, .scale = 1.0f,
                                                      .uv_scale = {1.0f, 1.0f}};
    if ((used & 1u) && !has_metallic) md->metallic = 1.0f; /* a map that could not be read leaves its factor */
    if ((used & 2u) && !has_roughness) md->roughness = 1.0f;
    return SY_OK;
}

/* >>materials --------------------------------------------------------------------------------- */

static float max3(const float *v) { return fmaxf(v[0], fmaxf(v[1], v[2])); }
static float clamp01(float v) { return isfinite(v) ? fmaxf(0.0f, fminf(1.0f, v)) : 0.0f; }

static bool get_float(const struct aiMaterial *m, const char *key, float *out)
{
    ai_real v;
    if (aiGetMaterialFloatArray(m, key, 0, 0, &v, NULL) != aiReturn_SUCCESS || !isfinite(v)) return false;
    *out = (float)v;
    return true;
}

static bool get_color(const struct aiMaterial *m, const char *key, float out[4])
{
    struct aiColor4D c;
    if (aiGetMaterialColor(m, key, 0, 0, &c) != aiReturn_SUCCESS) return false;
    float v[4] = {c.r, c.g, c.b, c.a};
    for (int k = 0; k < 4; ++k)
        if (!isfinite(v[k])) return false;
    memcpy(out, v, sizeof v);
    return true;
}

/* a value out of range: clamped, with a warning naming it */
static float clamped(asp_loader *L, unsigned i, const char *what, float v, float lo, float hi)
{
    if (v >= lo && v <= hi) return v;
    float c = fmaxf(lo, fminf(hi, v));
    asp_warn(L, "materials[%u]: %s %g out of [%g, %g]; clamped to %g", i, what, (double)v, (double)lo, (double)hi, (double)c);
    return c;
}

sy_result asp_create_material(asp_loader *L, unsigned i)
{
    const struct aiMaterial *m = L->ai->mMaterials[i];
    sy_material_data md = *(const sy_material_data *)sy_object_defaults(SY_TYPE_MATERIAL);
    struct aiString name = {0};
    aiGetMaterialString(m, "?mat.name", 0, 0, &name);
    int shading = 0, two = 0;
    aiGetMaterialIntegerArray(m, "$mat.shadingm", 0, 0, &shading, NULL);
    aiGetMaterialIntegerArray(m, "$mat.twosided", 0, 0, &two, NULL);
    float base[4] = {0.8f, 0.8f, 0.8f, 1.0f}, spec[4] = {0, 0, 0, 1}, emis[4] = {0, 0, 0, 1}, v;
    float metallic = 0, rough = 1;
    bool has_metallic = get_float(m, "$mat.metallicFactor", &metallic);
    bool has_roughness = get_float(m, "$mat.roughnessFactor", &rough);
    bool has_base = get_color(m, "$clr.base", base);
    /* Assimp 5.2's FBX reader gives every material with a shininess exponent n a roughness factor
     * 1 - sqrt(n) / 10 ("Blender's", negative past n = 100) and nothing else PBR: that one is not the
     * file's, and the material stays classic (the rule below) */
    float n_exp;
    if (has_roughness && !has_metallic && !has_base && get_float(m, "$mat.shininess", &n_exp) && n_exp >= 0.0f &&
        fabsf(rough - (1.0f - sqrtf(n_exp) / 10.0f)) < 1e-5f)
        has_roughness = false, rough = 1.0f;
    bool pbr = has_metallic || has_roughness || has_base;
    if (!has_base) get_color(m, "$clr.diffuse", base);
    for (int k = 0; k < 3; ++k) md.base_color[k] = clamped(L, i, "base colour", base[k], 0, 1);
    md.base_color[3] = pbr ? clamped(L, i, "base colour alpha", base[3], 0, 1) : 1.0f;
    if (get_float(m, "$mat.opacity", &v)) md.base_color[3] *= clamped(L, i, "opacity", v, 0, 1);
    if (pbr) {
        md.metallic = clamped(L, i, "metallic", metallic, 0, 1);
        md.roughness = clamped(L, i, "roughness", rough, 0, 1);
    } else { /* classic: the highlight's exponent and strength (sy_classic.h) */
        float exponent = 0, strength = 1;
        get_color(m, "$clr.specular", spec);
        get_float(m, "$mat.shininess", &exponent);
        get_float(m, "$mat.shinpercent", &strength);
        bool highlight = shading != aiShadingMode_Gouraud && shading != aiShadingMode_Flat;
        md.metallic = 0.0f;
        md.roughness = sy_classic_roughness(exponent, highlight ? max3(spec) * strength : 0.0f);
    }
    if (get_color(m, "$clr.emissive", emis))
        for (int k = 0; k < 3; ++k) md.emissive[k] = isfinite(emis[k]) ? fmaxf(0.0f, emis[k]) : 0.0f;
    if (get_float(m, "$mat.emissiveIntensity", &v)) md.emissive_strength = fmaxf(0.0f, v);
    if (get_float(m, "$mat.transmission.factor", &v)) md.transmission = clamped(L, i, "transmission", v, 0, 1);
    if ((md.transmission > 0 || pbr) && get_float(m, "$mat.refracti", &v) && v >= 1.0f && v <= 5.0f) md.ior = v;
    md.double_sided = two ? 1u : 0u;
    md.unlit = shading == aiShadingMode_NoShading ? 1u : 0u;
    if (get_float(m, "$mat.gltf.alphaCutoff", &v)) md.alpha_cutoff = clamp01(v);

    uint32_t ch = 0, alpha_ch = 0;
    sy_result r;
    if ((r = texture_slot(L, i, aiTextureType_BASE_COLOR, true, "base colour", &md.base_color_texture, &alpha_ch)))
        return r;
    if (!md.base_color_texture.texture.id &&
        (r = texture_slot(L, i, aiTextureType_DIFFUSE, true, "diffuse", &md.base_color_texture, &alpha_ch)))
        return r;
    if ((r = texture_slot(L, i, aiTextureType_EMISSION_COLOR, true, "emission", &md.emissive_texture, &ch))) return r;
    if (!md.emissive_texture.texture.id &&
        (r = texture_slot(L, i, aiTextureType_EMISSIVE, true, "emissive", &md.emissive_texture, &ch)))
        return r;
    if (md.emissive_texture.texture.id && max3(md.emissive) <= 0.0f) md.emissive[0] = md.emissive[1] = md.emissive[2] = 1.0f;
    if ((r = texture_slot(L, i, aiTextureType_NORMALS, false, "normals", &md.normal_texture, &ch))) return r;
    if (!md.normal_texture.texture.id &&
        (r = texture_slot(L, i, aiTextureType_NORMAL_CAMERA, false, "normal", &md.normal_texture, &ch)))
        return r;
    if ((r = texture_slot(L, i, aiTextureType_AMBIENT_OCCLUSION, false, "occlusion", &md.occlusion_texture, &ch))) return r;
    if (aiGetMaterialTextureCount(m, aiTextureType_UNKNOWN) && pbr) /* glTF 1 / 2 through Assimp: metallic-roughness */
        if ((r = texture_slot(L, i, aiTextureType_UNKNOWN, false, "metallic-roughness", &md.metallic_roughness_texture, &ch)))
            return r;
    bool separate = aiGetMaterialTextureCount(m, aiTextureType_METALNESS) || aiGetMaterialTextureCount(m, aiTextureType_DIFFUSE_ROUGHNESS);
    if (separate && md.metallic_roughness_texture.texture.id) {
        asp_warn(L, "materials[%u] '%s': separate metalness / roughness maps besides a combined metallic-roughness texture; "
                    "the combined one used", i, asp_str(&name));
        L->info->counts.skipped++;
    } else if (separate && (r = metallic_roughness_maps(L, i, asp_str(&name), has_metallic, has_roughness, &md))) {
        return r;
    }
    static const struct {
        enum aiTextureType type;
        const char *name;
    } skipped[] = {{aiTextureType_SPECULAR, "specular"},     {aiTextureType_SHININESS, "shininess"},
                   {aiTextureType_OPACITY, "opacity"},       {aiTextureType_HEIGHT, "height (bump)"},
                   {aiTextureType_DISPLACEMENT, "displacement"}, {aiTextureType_LIGHTMAP, "light map"},
                   {aiTextureType_REFLECTION, "reflection"}, {aiTextureType_SHEEN, "sheen"},
                   {aiTextureType_CLEARCOAT, "clearcoat"},   {aiTextureType_TRANSMISSION, "transmission"}};
    for (size_t k = 0; k < sizeof skipped / sizeof skipped[0]; ++k) {
        if (!aiGetMaterialTextureCount(m, skipped[k].type)) continue;
        struct aiString p = {0};
        aiGetMaterialTexture(m, skipped[k].type, 0, &p, NULL, NULL, NULL, NULL, NULL, NULL);
        asp_warn(L, "materials[%u] '%s': %s texture '%s' not supported; skipped", i, asp_str(&name), skipped[k].name,
                 asp_str(&p));
        L->info->counts.skipped++;
    }
    md.alpha_mode = md.base_color[3] < 1.0f || alpha_ch == 2 || alpha_ch == 4 ? SY_ALPHA_BLEND : SY_ALPHA_OPAQUE;
    struct aiString am = {0};
    if (aiGetMaterialString(m, "$mat.gltf.alphaMode", 0, 0, &am) == aiReturn_SUCCESS)
        md.alpha_mode = !strcmp(asp_str(&am), "MASK") ? SY_ALPHA_MASK : !strcmp(asp_str(&am), "BLEND") ? SY_ALPHA_BLEND
                                                                                                       : SY_ALPHA_OPAQUE;
    L->normal_mapped[i] = md.normal_texture.texture.id != 0;
    char where[48];
    snprintf(where, sizeof where, "materials[%u]", i);
    uint32_t id;
    md.name = (char *)asp_str(&name);
    if ((r = asp_new(L, SY_TYPE_MATERIAL, md.name, where, &id))) return r;
    if ((r = sy_material_set(L->scene, (sy_material){id}, &md, &L->err))) {
        sy_error_prefix(&L->err, "%s: %s", L->path, where);
        return r;
    }
    L->materials[i] = (sy_material){id};
    L->info->counts.materials++;
    return SY_OK;
}
