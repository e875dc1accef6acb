/* sy_x3d_appearance.c — an X3D Shape's Appearance as one sy_material: ImageTexture (decoded by
 * sy_image.h within the image and scene budgets, TextureProperties as the sampler), Material,
 * PhysicalMaterial, UnlitMaterial, TwoSidedMaterial and CommonSurfaceShader, with the mappings that
 * sy_x3d.h documents. Materials and textures are cached per element, so a USEd Appearance or
 * ImageTexture stays one object. */
#include "sy_x3d_internal.h"

#include "sy_classic.h"
#include "sy_file.h"

#include "sy_image.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* >>textures ---------------------------------------------------------------------------------- */

static uint32_t map_filter(const char *s)
{
    if (!s) return SY_FILTER_LINEAR;
    if (!strncmp(s, "NEAREST", 7)) return SY_FILTER_NEAREST;
    return SY_FILTER_LINEAR;
}

static uint32_t map_boundary(const char *s, bool repeat)
{
    if (!s) return repeat ? SY_WRAP_REPEAT : SY_WRAP_CLAMP;
    if (!strcmp(s, "MIRRORED_REPEAT")) return SY_WRAP_MIRROR;
    if (!strcmp(s, "REPEAT")) return SY_WRAP_REPEAT;
    return SY_WRAP_CLAMP;
}

/* Decodes the first readable URL of an ImageTexture. Returns the texture id (0 = none, warned). */
static sy_result load_texture(loader *L, xfile *F, const xmlNode *el, bool srgb, uint32_t *tex_out,
                              uint32_t *channels_out)
{
    *tex_out = 0;
    *channels_out = 0;
    if (!el) return SY_OK;
    if (strcmp(x3d_ename(el), "ImageTexture") != 0) {
        x3d_warn(L, "%s:%d: texture node %s not supported; no texture", F->path, x3d_line_of(el), x3d_ename(el));
        return SY_OK;
    }
    created *c = x3d_cache_get(L, F, el, srgb ? "srgb" : "lin", true);
    if (!c) return sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "out of memory");
    if (c->done) {
        *tex_out = c->texture;
        *channels_out = c->tex_channels;
        return SY_OK;
    }
    c->done = true;
    char *urls = x3d_attr(el, "url");
    if (!urls) {
        x3d_warn(L, "%s:%d: ImageTexture without url; no texture", F->path, x3d_line_of(el));
        return SY_OK;
    }
    const char *p = urls;
    char u[2048], path[4096], why[SY_ERROR_MESSAGE_MAX] = "no usable url";
    uint8_t *pixels = NULL;
    int w = 0, h = 0, comp = 0;
    while (!pixels && x3d_next_mfstring(&p, u, sizeof u)) {
        if (!u[0] || x3d_is_remote(u)) continue;
        if (!strncmp(u, "data:", 5)) {
            snprintf(why, sizeof why, "data: URLs are not supported");
            continue;
        }
        char joined[4096];
        if (!x3d_resolve_url(F, u, joined, sizeof joined)) continue;
        sy_result cr = x3d_confine_url(L, F, el, u, joined, path, sizeof path);
        if (cr == SY_ERR_NOT_FOUND) {
            snprintf(why, sizeof why, "%.400s: not found", joined);
            continue;
        }
        if (cr != SY_OK) {
            xmlFree(urls);
            return cr;
        }
        if (!x3d_regular_file(path, why, sizeof why)) continue;
        void *bytes;
        size_t size;
        sy_error ferr = {0};
        if (sy_file_read_all(path, L->opt.max_file_bytes, &bytes, &size, &ferr)) {
            snprintf(why, sizeof why, "%s", ferr.message);
            continue;
        }
        sy_image_pixels img;
        sy_error derr = {0};
        if (sy_image_decode(bytes, size, L->opt.max_image_pixels, &L->budget, &img, &derr) != SY_OK) {
            snprintf(why, sizeof why, "%.300s: %.200s", path, derr.message);
        } else { /* within the limits and charged to the budget (sy_image.h) */
            pixels = img.pixels;
            w = (int)img.width, h = (int)img.height, comp = (int)img.channels;
        }
        free(bytes);
    }
    xmlFree(urls);
    if (!pixels) {
        x3d_warn(L, "%s:%d: ImageTexture: %s; no texture", F->path, x3d_line_of(el), why);
        return SY_OK;
    }
    sy_result r;
    sy_blob *blob = NULL;
    size_t bytes = (size_t)w * (size_t)h * (size_t)comp;
    if ((r = sy_blob_create_copy(pixels, bytes, &blob, &L->err))) {
        free(pixels);
        return r;
    }
    free(pixels);
    char *def = x3d_attr(el, "DEF");
    uint32_t id;
    r = x3d_new_object(L, SY_TYPE_TEXTURE, def ? def : u, &id);
    xmlFree(def);
    sy_image_info ii = {(uint32_t)w, (uint32_t)h, (uint32_t)comp, srgb ? SY_PIXEL_U8_SRGB : SY_PIXEL_U8_LINEAR};
    if (!r) r = sy_texture_set_image(L->scene, (sy_texture){id}, &ii, blob, &L->err);
    sy_blob_release(blob);
    if (r) return r;
    sy_sampler smp = {SY_WRAP_REPEAT, SY_WRAP_REPEAT, SY_FILTER_LINEAR, SY_FILTER_LINEAR};
    bool rs = x3d_get_bool(el, "repeatS", true), rt = x3d_get_bool(el, "repeatT", true);
    smp.wrap_s = rs ? SY_WRAP_REPEAT : SY_WRAP_CLAMP;
    smp.wrap_t = rt ? SY_WRAP_REPEAT : SY_WRAP_CLAMP;
    const xmlNode *tp = x3d_field_child(L, F, el, "TextureProperties", "textureProperties");
    if (tp) {
        char *mag = x3d_attr(tp, "magnificationFilter"), *min = x3d_attr(tp, "minificationFilter");
        char *bs = x3d_attr(tp, "boundaryModeS"), *bt = x3d_attr(tp, "boundaryModeT");
        smp.mag_filter = map_filter(mag);
        smp.min_filter = map_filter(min);
        if (bs) smp.wrap_s = map_boundary(bs, rs);
        if (bt) smp.wrap_t = map_boundary(bt, rt);
        xmlFree(mag); xmlFree(min); xmlFree(bs); xmlFree(bt);
    }
    if ((r = sy_texture_set_sampler(L->scene, (sy_texture){id}, &smp, &L->err))) return r;
    L->info->counts.textures++;
    c->texture = id;
    c->tex_channels = (uint32_t)comp;
    *tex_out = id;
    *channels_out = (uint32_t)comp;
    return SY_OK;
}

/* An ImageTexture or a SurfaceShaderTexture wrapping one (CommonSurfaceShader). */
static const xmlNode *texture_field(loader *L, xfile *F, const xmlNode *el, const char *field)
{
    const xmlNode *t = NULL;
    for (const xmlNode *c = el->children; c; c = c->next) {
        if (c->type != XML_ELEMENT_NODE) continue;
        char *cf = x3d_attr(c, "containerField");
        bool m = cf && !strcmp(cf, field);
        xmlFree(cf);
        if (!m) continue;
        x3d_define(L, F, c);
        t = x3d_resolve(L, F, c);
        break;
    }
    if (t && !strcmp(x3d_ename(t), "SurfaceShaderTexture")) t = x3d_field_child(L, F, t, "ImageTexture", "texture");
    return t;
}

/* >>materials --------------------------------------------------------------------------------- */

/* X3D shininess s in [0, 1] is the Blinn-Phong exponent 128 s (sy_classic.h gives the roughness) */
static float shininess_to_roughness(float shininess, float specular_max)
{
    return sy_classic_roughness(128.0f * fmaxf(0.0f, fminf(1.0f, shininess)), specular_max);
}

static float max3(const float *v) { return fmaxf(v[0], fmaxf(v[1], v[2])); }


static void set_tex(sy_texture_ref *ref, uint32_t id)
{
    ref->texture.id = id;
    ref->scale = 1.0f;
    ref->uv_scale[0] = ref->uv_scale[1] = 1.0f;
}

/* Material for (Appearance, solid, vertex colours). 0 = the default material (never: X3D needs
 * an explicit one); *normal_map tells the geometry to generate tangents. */
sy_result x3d_get_material(loader *L, xfile *F, const xmlNode *app, bool solid, bool vcolors, bool stroke,
                           uint32_t *out, bool *normal_map)
{
    char variant[16];
    snprintf(variant, sizeof variant, "m%d%d%d", solid, vcolors, stroke);
    created *c = x3d_cache_get(L, F, app ? (const void *)app : (const void *)F, variant, true);
    if (!c) return sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "out of memory");
    if (c->done) {
        *out = c->material;
        *normal_map = c->tex_channels != 0;
        return SY_OK;
    }
    sy_material_data md = *(const sy_material_data *)sy_object_defaults(SY_TYPE_MATERIAL);
    md.double_sided = !solid;
    md.metallic = 0.0f;
    sy_result r;
    uint32_t tex, ch, alpha_channels = 0;
    const xmlNode *mat = app ? x3d_field_child(L, F, app, "Material|PhysicalMaterial|UnlitMaterial|TwoSidedMaterial", "material") : NULL;
    const xmlNode *css = NULL;
    if (app) {
        for (const xmlNode *k = app->children; k; k = k->next) {
            if (k->type != XML_ELEMENT_NODE) continue;
            if (!strcmp(x3d_ename(k), "CommonSurfaceShader")) {
                x3d_define(L, F, k);
                css = x3d_resolve(L, F, k);
            } else if (!strcmp(x3d_ename(k), "ComposedShader") || !strcmp(x3d_ename(k), "PackagedShader") ||
                       !strcmp(x3d_ename(k), "ProgramShader")) {
                x3d_warn(L, "%s:%d: %s not supported; the Material is used", F->path, x3d_line_of(k), x3d_ename(k));
            }
        }
    }
    if (css) {
        float diffuse[3] = {0.8f, 0.8f, 0.8f}, spec[3] = {0, 0, 0}, emis[3] = {0, 0, 0}, refl[3] = {0, 0, 0};
        float trans[3] = {0, 0, 0};
        x3d_get_floats(L, F, css, "diffuseFactor", diffuse, 3);
        x3d_get_floats(L, F, css, "specularFactor", spec, 3);
        x3d_get_floats(L, F, css, "emissiveFactor", emis, 3);
        x3d_get_floats(L, F, css, "reflectionFactor", refl, 3);
        x3d_get_floats(L, F, css, "transmissionFactor", trans, 3);
        float shin = x3d_get_float(L, F, css, "shininessFactor", 0.2f);
        float alpha = x3d_get_float(L, F, css, "alphaFactor", 1.0f);
        float rior = x3d_get_float(L, F, css, "relativeIndexOfRefraction", 1.0f);
        x3d_clamp01(diffuse, 3); x3d_clamp01(spec, 3); x3d_clamp01(refl, 3); x3d_clamp01(trans, 3);
        float metal = max3(refl);
        for (int k = 0; k < 3; k++) md.base_color[k] = metal > 0 ? diffuse[k] * (1 - metal) + refl[k] : diffuse[k];
        x3d_clamp01(md.base_color, 3);
        md.base_color[3] = fmaxf(0.0f, fminf(1.0f, alpha));
        md.metallic = metal;
        md.roughness = metal > 0 || max3(trans) > 0 ? shininess_to_roughness(shin, 1.0f) : shininess_to_roughness(shin, max3(spec));
        for (int k = 0; k < 3; k++) md.emissive[k] = fmaxf(0.0f, emis[k]);
        md.transmission = max3(trans);
        if (rior > 0.0f && isfinite(rior)) md.ior = rior >= 1.0f ? rior : 1.0f / rior;
        if ((r = load_texture(L, F, texture_field(L, F, css, "diffuseTexture"), true, &tex, &ch))) return r;
        if (tex) set_tex(&md.base_color_texture, tex), alpha_channels = (ch == 2 || ch == 4);
        if ((r = load_texture(L, F, texture_field(L, F, css, "emissiveTexture"), true, &tex, &ch))) return r;
        if (tex) set_tex(&md.emissive_texture, tex);
        if ((r = load_texture(L, F, texture_field(L, F, css, "normalTexture"), false, &tex, &ch))) return r;
        if (tex) {
            set_tex(&md.normal_texture, tex);
            float ns[3] = {2, 2, 2}, nb[3] = {-1, -1, -1};
            x3d_get_floats(L, F, css, "normalScale", ns, 3);
            x3d_get_floats(L, F, css, "normalBias", nb, 3);
            char *fmt = x3d_attr(css, "normalFormat"), *space = x3d_attr(css, "normalSpace");
            if (ns[0] != 2 || nb[0] != -1 || (fmt && strcmp(fmt, "UNORM")) || (space && strcmp(space, "TANGENT")))
                x3d_warn(L, "%s:%d: CommonSurfaceShader: only UNORM tangent-space normal maps with scale 2 and bias -1 are "
                         "supported; the normal map is read as such", F->path, x3d_line_of(css));
            xmlFree(fmt);
            xmlFree(space);
        }
    } else if (mat && !strcmp(x3d_ename(mat), "PhysicalMaterial")) {
        float base[3] = {1, 1, 1}, emis[3] = {0, 0, 0};
        x3d_get_floats(L, F, mat, "baseColor", base, 3);
        x3d_get_floats(L, F, mat, "emissiveColor", emis, 3);
        x3d_clamp01(base, 3);
        memcpy(md.base_color, base, sizeof base);
        md.base_color[3] = 1.0f - fmaxf(0.0f, fminf(1.0f, x3d_get_float(L, F, mat, "transparency", 0.0f)));
        md.metallic = fmaxf(0.0f, fminf(1.0f, x3d_get_float(L, F, mat, "metallic", 1.0f)));
        md.roughness = fmaxf(0.0f, fminf(1.0f, x3d_get_float(L, F, mat, "roughness", 1.0f)));
        for (int k = 0; k < 3; k++) md.emissive[k] = fmaxf(0.0f, emis[k]);
        if ((r = load_texture(L, F, texture_field(L, F, mat, "baseTexture"), true, &tex, &ch))) return r;
        if (tex) set_tex(&md.base_color_texture, tex), alpha_channels = (ch == 2 || ch == 4);
        if ((r = load_texture(L, F, texture_field(L, F, mat, "metallicRoughnessTexture"), false, &tex, &ch))) return r;
        if (tex) set_tex(&md.metallic_roughness_texture, tex);
        if ((r = load_texture(L, F, texture_field(L, F, mat, "emissiveTexture"), true, &tex, &ch))) return r;
        if (tex) set_tex(&md.emissive_texture, tex);
        if ((r = load_texture(L, F, texture_field(L, F, mat, "occlusionTexture"), false, &tex, &ch))) return r;
        if (tex) set_tex(&md.occlusion_texture, tex);
        if ((r = load_texture(L, F, texture_field(L, F, mat, "normalTexture"), false, &tex, &ch))) return r;
        if (tex) set_tex(&md.normal_texture, tex);
    } else if (mat) { /* Material (X3D 3 / 4), UnlitMaterial, TwoSidedMaterial (front side) */
        bool unlit = !strcmp(x3d_ename(mat), "UnlitMaterial");
        float diffuse[3] = {0.8f, 0.8f, 0.8f}, spec[3] = {0, 0, 0}, emis[3] = {0, 0, 0};
        if (unlit) diffuse[0] = diffuse[1] = diffuse[2] = 0;
        x3d_get_floats(L, F, mat, "diffuseColor", diffuse, 3);
        x3d_get_floats(L, F, mat, "specularColor", spec, 3);
        x3d_get_floats(L, F, mat, "emissiveColor", emis, 3);
        if (unlit) {
            float e[3] = {1, 1, 1};
            x3d_get_floats(L, F, mat, "emissiveColor", e, 3);
            memcpy(diffuse, e, sizeof e);
            md.unlit = 1;
        }
        x3d_clamp01(diffuse, 3);
        x3d_clamp01(spec, 3);
        memcpy(md.base_color, diffuse, sizeof diffuse);
        md.base_color[3] = 1.0f - fmaxf(0.0f, fminf(1.0f, x3d_get_float(L, F, mat, "transparency", 0.0f)));
        md.roughness = shininess_to_roughness(x3d_get_float(L, F, mat, "shininess", 0.2f), max3(spec));
        if (!unlit) for (int k = 0; k < 3; k++) md.emissive[k] = fmaxf(0.0f, emis[k]);
        if ((r = load_texture(L, F, texture_field(L, F, mat, unlit ? "emissiveTexture" : "diffuseTexture"), true, &tex, &ch))) return r;
        if (tex) set_tex(&md.base_color_texture, tex), alpha_channels = (ch == 2 || ch == 4);
        if (!unlit) {
            if ((r = load_texture(L, F, texture_field(L, F, mat, "emissiveTexture"), true, &tex, &ch))) return r;
            if (tex) set_tex(&md.emissive_texture, tex);
            if ((r = load_texture(L, F, texture_field(L, F, mat, "normalTexture"), false, &tex, &ch))) return r;
            if (tex) set_tex(&md.normal_texture, tex);
        }
    } else {
        /* no Material: lighting off, unlit white (X3D) */
        md.unlit = 1;
        md.base_color[0] = md.base_color[1] = md.base_color[2] = 1.0f;
        md.roughness = 1.0f;
    }
    bool rgb_replaced = false; /* the diffuse colour does not show (a texture or vertex colours replace it) */
    /* Appearance-level texture (X3D 3: replaces the diffuse colour for RGB textures) */
    if (app && !md.base_color_texture.texture.id) {
        const xmlNode *t = x3d_field_child(L, F, app, "ImageTexture|MultiTexture|MovieTexture|PixelTexture", "texture");
        if ((r = load_texture(L, F, t, true, &tex, &ch))) return r;
        if (tex) {
            set_tex(&md.base_color_texture, tex);
            alpha_channels = (ch == 2 || ch == 4);
            if (mat && strcmp(x3d_ename(mat), "PhysicalMaterial") != 0 && !css) {
                /* X3D lighting model: an RGB texture replaces the diffuse colour, grey modulates it */
                if (ch >= 3) md.base_color[0] = md.base_color[1] = md.base_color[2] = 1.0f, rgb_replaced = true;
            } else if (!mat && !css) {
                md.base_color[0] = md.base_color[1] = md.base_color[2] = 1.0f;
            }
        }
    }
    if (vcolors && !css && !(mat && !strcmp(x3d_ename(mat), "PhysicalMaterial")))
        md.base_color[0] = md.base_color[1] = md.base_color[2] = 1.0f, rgb_replaced = true; /* X3D: Color replaces diffuseColor */
    if (stroke && !css) {
        /* X3D points and lines are unlit: the Material's emissiveColor (UnlitMaterial: its colour;
         * no Material: white), replaced by the Color node's colours when present */
        if (mat && strcmp(x3d_ename(mat), "UnlitMaterial") != 0) {
            float e[3] = {0, 0, 0};
            x3d_get_floats(L, F, mat, "emissiveColor", e, 3);
            x3d_clamp01(e, 3);
            memcpy(md.base_color, e, sizeof e);
        }
        if (vcolors) md.base_color[0] = md.base_color[1] = md.base_color[2] = 1.0f;
        md.unlit = 1;
        md.emissive[0] = md.emissive[1] = md.emissive[2] = 0.0f;
        memset(&md.normal_texture, 0, sizeof md.normal_texture);
        memset(&md.emissive_texture, 0, sizeof md.emissive_texture);
        md.double_sided = 0;
    }
    /* alpha mode: Appearance.alphaMode (X3D 4) or AUTO */
    char *am = app ? x3d_attr(app, "alphaMode") : NULL;
    if (am && !strcmp(am, "OPAQUE")) md.alpha_mode = SY_ALPHA_OPAQUE;
    else if (am && !strcmp(am, "MASK")) md.alpha_mode = SY_ALPHA_MASK;
    else if (am && !strcmp(am, "BLEND")) md.alpha_mode = SY_ALPHA_BLEND;
    else md.alpha_mode = (md.base_color[3] < 1.0f || alpha_channels) ? SY_ALPHA_BLEND : SY_ALPHA_OPAQUE;
    xmlFree(am);
    if (app) md.alpha_cutoff = x3d_get_float(L, F, app, "alphaCutoff", 0.5f);
    if (md.ior < 1.0f) md.ior = 1.0f;
    char *def = app ? x3d_attr(app, "DEF") : NULL;
    if (!def && mat) def = x3d_attr(mat, "DEF");
    uint32_t id;
    r = x3d_new_object(L, SY_TYPE_MATERIAL, def, &id);
    xmlFree(def);
    md.name = NULL;
    if (!r) {
        const sy_material_data *cur = sy_material_get(L->scene, (sy_material){id});
        md.name = cur ? cur->name : NULL;
        r = sy_material_set(L->scene, (sy_material){id}, &md, &L->err);
    }
    if (r) {
        sy_error_prefix(&L->err, "%s:%d: material", F->path, app ? x3d_line_of(app) : 0);
        return r;
    }
    L->info->counts.materials++;
    if (mat && !css) { /* where ROUTEs to the Material's colours go in this variant (sy_x3d_anim.c) */
        bool unlit = !strcmp(x3d_ename(mat), "UnlitMaterial"), phys = !strcmp(x3d_ename(mat), "PhysicalMaterial");
        mat_link ml = {mat, F->serial, id, X3D_NO_PATH, X3D_NO_PATH};
        if (!unlit && !stroke && !rgb_replaced) ml.diffuse = SY_ANIM_DIFFUSE;
        if ((unlit || stroke) && !(vcolors && !phys)) ml.emissive = SY_ANIM_DIFFUSE; /* unlit: emissive is the colour */
        else if (!unlit && !stroke) ml.emissive = SY_ANIM_EMISSIVE;
        if (!sy_array_reserve(&L->mat_links, L->mat_link_count, &L->mat_link_cap, sizeof *L->mat_links, 16))
            return sy_error_set(&L->err, SY_ERR_OUT_OF_MEMORY, "out of memory");
        L->mat_links[L->mat_link_count++] = ml;
    }
    c->done = true;
    c->material = id;
    c->tex_channels = md.normal_texture.texture.id != 0;
    *out = id;
    *normal_map = c->tex_channels != 0;
    return SY_OK;
}
