/* sy_assimp_materials.c — Assimp materials onto the core's metallic-roughness model (the rule in
 * sy_assimp.h and docs/FORMATS.md; classic shading through sy_classic.h) and their textures: files
 * named by the material (confined to the model's folder, decoded by sy_image.h) and textures
 * embedded in the file (compressed: decoded the same way; raw BGRA texels: taken as they are),
 * one sy_texture per (image, colour role). */
#include "sy_assimp_internal.h"

#include "sy_classic.h"
#include "sy_image.h"

#include <assimp/material.h>

#include <dirent.h>
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

/* The texture for path in a colour (srgb) or data role; {0} with a warning when it cannot be made. */
static sy_result get_texture(asp_loader *L, const char *path, bool srgb, const char *where, sy_texture *out,
                             uint32_t *channels)
{
    *out = (sy_texture){0};
    *channels = 0;
    for (size_t k = 0; k < L->texture_count; ++k)
        if (L->textures[k].srgb == srgb && !strcmp(L->textures[k].key, path)) {
            *out = L->textures[k].tex;
            *channels = L->textures[k].channels;
            return SY_OK;
        }
    if (L->texture_count == L->texture_cap) {
        size_t cap = L->texture_cap ? L->texture_cap * 2 : 16;
        asp_texture *n = realloc(L->textures, cap * sizeof *n);
        if (!n) return asp_fail(L, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", where);
        L->textures = n;
        L->texture_cap = cap;
    }
    asp_texture *slot = &L->textures[L->texture_count];
    if (!(slot->key = strdup(path))) return asp_fail(L, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", where);
    slot->srgb = srgb;
    slot->tex = (sy_texture){0};
    slot->channels = 0;
    L->texture_count++;

    sy_image_pixels img = {0};
    sy_error e = {0};
    sy_result r;
    const struct aiTexture *t = embedded(L, path);
    if (t) {
        r = decode_embedded(L, t, &img, &e);
    } else if (path[0] == '*') {
        r = sy_error_set(&e, SY_ERR_PARSE, "no embedded texture %s", path);
    } else {
        void *data = NULL;
        size_t size = 0;
        r = read_texture_file(L, path, where, &data, &size, &e);
        if (r == SY_ERR_LIMIT && !strstr(e.message, "scene budget")) return sy_error_set(&L->err, r, "%s", e.message); /* refused path */
        if (r == SY_OK) r = sy_image_decode(data, size, L->opt.max_image_pixels, &L->budget, &img, &e);
        free(data);
    }
    if (r == SY_ERR_NOT_FOUND) {
        asp_warn(L, "%s: texture '%s' not found in the model's folder; no texture", where, path);
        L->info->counts.skipped++;
        return SY_OK;
    }
    if (r) {
        asp_warn(L, "%s: texture '%s': %s; no texture", where, path, e.message);
        L->info->counts.skipped++;
        return SY_OK;
    }
    sy_blob *blob = NULL;
    r = sy_blob_create_take(img.pixels, (size_t)img.width * img.height * img.channels, &blob, &L->err);
    if (r) {
        sy_image_pixels_free(&img);
        return r;
    }
    uint32_t id = 0;
    sy_image_info ii = {img.width, img.height, img.channels, srgb ? SY_PIXEL_U8_SRGB : SY_PIXEL_U8_LINEAR};
    if (!(r = asp_new(L, SY_TYPE_TEXTURE, base_name(path), where, &id)))
        r = sy_texture_set_image(L->scene, (sy_texture){id}, &ii, blob, &L->err);
    sy_blob_release(blob);
    if (r) return r;
    slot->tex = (sy_texture){id};
    slot->channels = img.channels;
    L->info->counts.textures++;
    *out = slot->tex;
    *channels = img.channels;
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
    static const struct {
        enum aiTextureType type;
        const char *name;
    } skipped[] = {{aiTextureType_SPECULAR, "specular"},     {aiTextureType_SHININESS, "shininess"},
                   {aiTextureType_OPACITY, "opacity"},       {aiTextureType_HEIGHT, "height (bump)"},
                   {aiTextureType_DISPLACEMENT, "displacement"}, {aiTextureType_LIGHTMAP, "light map"},
                   {aiTextureType_REFLECTION, "reflection"}, {aiTextureType_METALNESS, "metalness"},
                   {aiTextureType_DIFFUSE_ROUGHNESS, "roughness"}, {aiTextureType_SHEEN, "sheen"},
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
