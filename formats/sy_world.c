/* sy_world.c — a view's world from user choices (see sy_world.h). */
#include "sy_world.h"

#include "sy_exr.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

bool sy_world_options_empty(const sy_world_options *o)
{
    return !o->env_path && !o->has_env_color && !o->env_intensity_set && !o->env_hidden && !o->has_background &&
           !o->no_default_light;
}

sy_result sy_world_texture_take(sy_scene *s, const char *name, float *px, uint32_t w, uint32_t h, sy_texture *out,
                                sy_error *err)
{
    sy_blob *blob = NULL;
    sy_result r = sy_blob_create_take(px, (size_t)w * h * 3 * sizeof *px, &blob, err);
    if (r != SY_OK) {
        free(px);
        return r;
    }
    sy_image_info info = {w, h, 3, SY_PIXEL_F32};
    sy_sampler smp = {SY_WRAP_REPEAT, SY_WRAP_CLAMP, SY_FILTER_LINEAR, SY_FILTER_LINEAR};
    if ((r = sy_texture_create(s, name, out, err)) == SY_OK && (r = sy_texture_set_image(s, *out, &info, blob, err)) == SY_OK)
        r = sy_texture_set_sampler(s, *out, &smp, err);
    sy_blob_release(blob);
    return r;
}

sy_result sy_world_load_environment(sy_scene *s, const char *path, sy_texture *out, sy_error *err)
{
    sy_exr_image *img = NULL;
    sy_result r = sy_exr_read(path, &img, err);
    if (r != SY_OK) {
        sy_error_prefix(err, "environment");
        return r;
    }
    const float *ch[3] = {sy_exr_image_channel(img, "R"), sy_exr_image_channel(img, "G"), sy_exr_image_channel(img, "B")};
    const float *y = sy_exr_image_channel(img, "Y");
    if (!ch[0] || !ch[1] || !ch[2]) {
        if (!y) {
            sy_exr_image_free(img);
            return sy_error_set(err, SY_ERR_PARSE, "environment %s: no R, G, B (or Y) channels", path);
        }
        ch[0] = ch[1] = ch[2] = y;
    }
    uint32_t w = (uint32_t)img->width, h = (uint32_t)img->height;
    /* lat-long: 360 x 180 degrees, so twice as wide as high (one pixel of rounding allowed) */
    if (h < 2 || (w > 2 * h ? w - 2 * h : 2 * h - w) > 1) {
        sy_exr_image_free(img);
        return sy_error_set(err, SY_ERR_PARSE, "environment %s: %u x %u is not a lat-long map (expected 2:1)", path, w, h);
    }
    size_t n = (size_t)w * h;
    float *px = malloc(n * 3 * sizeof *px);
    if (!px) {
        sy_exr_image_free(img);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "environment %s: out of memory", path);
    }
    for (size_t i = 0; i < n && r == SY_OK; ++i)
        for (int k = 0; k < 3; ++k) {
            float v = ch[k][i];
            if (!isfinite(v) || v < 0.0f)
                r = sy_error_set(err, SY_ERR_PARSE, "environment %s: pixel (%zu, %zu) has a %s value %g", path, i % w,
                                 i / w, isfinite(v) ? "negative" : "non-finite", (double)v);
            px[i * 3 + (size_t)k] = v;
        }
    sy_exr_image_free(img);
    if (r != SY_OK) {
        free(px);
        return r;
    }
    return sy_world_texture_take(s, "environment", px, w, h, out, err);
}

static sy_result check_colour(const float *c, int n, const char *what, sy_error *err)
{
    for (int k = 0; k < n; ++k)
        if (!isfinite(c[k]) || c[k] < 0.0f)
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: component %d = %g must be finite and >= 0", what, k,
                                (double)c[k]);
    return SY_OK;
}

sy_result sy_world_apply(sy_scene *s, sy_background *world, const sy_world_options *o, sy_error *err)
{
    if (sy_world_options_empty(o)) return SY_OK;
    sy_result r;
    if (o->has_env_color && (r = check_colour(o->env_color, 3, "environment colour", err))) return r;
    if (o->has_background && (r = check_colour(o->background, 4, "background colour", err))) return r;
    if (o->env_intensity_set && (!isfinite(o->env_intensity) || o->env_intensity < 0.0f))
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "environment intensity %g must be finite and >= 0",
                            (double)o->env_intensity);
    if (o->env_path && o->has_env_color)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "an environment map and an environment colour exclude each other");
    sy_background_data bd = *(const sy_background_data *)sy_object_defaults(SY_TYPE_BACKGROUND);
    if (world->id) {
        const sy_background_data *cur = sy_background_get(s, *world);
        if (!cur) return sy_error_set(err, SY_ERR_INVALID_HANDLE, "world: stale background handle");
        bd = *cur;
    } else {
        bd.color[3] = 0.0f; /* a new world starts transparent, as no world */
    }
    bd.name = NULL;
    if (o->env_path) {
        if ((r = sy_world_load_environment(s, o->env_path, &bd.environment, err))) return r;
    } else if (o->has_env_color) {
        float *px = malloc(3 * sizeof *px);
        if (!px) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "environment colour: out of memory");
        memcpy(px, o->env_color, 3 * sizeof *px);
        if ((r = sy_world_texture_take(s, "environment colour", px, 1, 1, &bd.environment, err))) return r;
    }
    if (o->env_intensity_set) bd.intensity = o->env_intensity;
    if (o->env_hidden) bd.environment_visible = 0;
    if (o->has_background) memcpy(bd.color, o->background, sizeof bd.color);
    if (o->no_default_light) bd.default_lighting = 0;
    if (!world->id && (r = sy_background_create(s, "world", world, err)) != SY_OK) return r;
    return sy_background_set(s, *world, &bd, err);
}
