/* sy_world.c — a view's world from user choices (see sy_world.h). */
#include "sy_world.h"

#include "sy_budget.h"
#include "sy_exr.h"
#include "sy_file.h"
#include "sy_sniff.h"

#include <stb_image.h>

#include <math.h>
#include <stdio.h>
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

/* Walks the texel data of a Radiance file (after the header's size line) without decoding it, so
 * that stb_image only ever sees whole scanlines: it loops for ever on a truncated run-length
 * scanline (a count of 0 read past the end) and reads missing flat texels as zeros. Each scanline is
 * either new-style run-length coded (2, 2, width; then per channel runs of 1..127 equal bytes, count
 * + 128, or 1..128 literal bytes) or, from the first that is not, flat: 4 bytes per texel to the end
 * of the image, as stb_image reads it. */
static sy_result radiance_check(const unsigned char *d, size_t size, const char *path, sy_error *err)
{
    int iw = 0, ih = 0;
    size_t p = 0;
    for (bool nl = false; p < size; ++p) { /* the header ends with an empty line, then the size line */
        if (d[p] == '\n' && nl) break;
        nl = d[p] == '\n';
    }
    const char *line = (const char *)d + p + 1;
    size_t left = p < size ? size - p - 1 : 0;
    const char *eol = memchr(line, '\n', left);
    if (!eol || sscanf(line, "-Y %d +X %d", &ih, &iw) != 2 || iw < 1 || ih < 1)
        return sy_error_set(err, SY_ERR_PARSE, "%s: no \"-Y height +X width\" line after the header", path);
    p = (size_t)(eol + 1 - (const char *)d);
    uint64_t w = (uint64_t)iw;
    for (int y = 0; y < ih; ++y) {
        bool rle = w >= 8 && w < 32768 && size - p >= 4 && d[p] == 2 && d[p + 1] == 2 && !(d[p + 2] & 0x80);
        if (rle && (((uint64_t)d[p + 2] << 8) | d[p + 3]) != w)
            return sy_error_set(err, SY_ERR_PARSE, "%s: scanline %d is %u texels wide, the header says %d", path, y,
                                (unsigned)((d[p + 2] << 8) | d[p + 3]), iw);
        if (!rle) { /* flat from here to the end */
            uint64_t need = (uint64_t)(ih - y) * w * 4u;
            if (size - p < need)
                return sy_error_set(err, SY_ERR_PARSE, "%s: truncated at scanline %d (%llu bytes of texels, %zu left)",
                                    path, y, (unsigned long long)need, size - p);
            return SY_OK;
        }
        p += 4;
        for (int c = 0; c < 4; ++c)
            for (uint64_t x = 0; x < w;) {
                if (p >= size) return sy_error_set(err, SY_ERR_PARSE, "%s: truncated in scanline %d", path, y);
                unsigned n = d[p++], run = n > 128;
                if (run) n -= 128;
                if (n == 0 || x + n > w || size - p < (run ? 1u : n))
                    return sy_error_set(err, SY_ERR_PARSE, "%s: scanline %d: a run of %u %s at texel %llu of %d", path, y,
                                        n, size - p < (run ? 1u : n) ? "past the end of the file" : "texels out of the line",
                                        (unsigned long long)x, iw);
                p += run ? 1u : n;
                x += n;
            }
    }
    return SY_OK;
}

/* Radiance RGBE (.hdr, "#?RADIANCE" or "#?RGBE" first) decoded by stb_image into float RGB. Before
 * anything is decoded, the header's size is checked against the bytes present (the new-style run
 * length coding packs at most 127 bytes into 2: a 4-byte texel takes at least 1/16 byte) and the
 * budget is charged for the float image. */
static sy_result load_radiance(const char *path, uint64_t max_bytes, float **px, uint32_t *w, uint32_t *h, sy_error *err)
{
    sy_budget budget = sy_budget_make(path, max_bytes);
    void *data = NULL;
    size_t size = 0;
    sy_result r = sy_file_read_all(path, budget.limit < SIZE_MAX ? (size_t)budget.limit : SIZE_MAX, &data, &size, err);
    if (r != SY_OK) return r;
    int iw = 0, ih = 0, comp = 0;
    if (size > INT32_MAX || !stbi_info_from_memory(data, (int)size, &iw, &ih, &comp) || iw < 1 || ih < 1) {
        r = sy_error_set(err, SY_ERR_PARSE, "%s: not a readable Radiance HDR header (%s)", path,
                         size > INT32_MAX ? "over 2 GiB" : stbi_failure_reason());
    } else if ((uint64_t)iw * (uint64_t)ih > (uint64_t)size * 16u) {
        r = sy_error_set(err, SY_ERR_PARSE, "%s: truncated: %d x %d texels cannot be coded in %zu bytes", path, iw, ih, size);
    } else if ((r = sy_budget_charge(&budget, (uint64_t)iw * (uint64_t)ih, 3 * sizeof(float), err, "environment %d x %d",
                                     iw, ih)) == SY_OK &&
               (r = radiance_check(data, size, path, err)) == SY_OK) {
        *px = stbi_loadf_from_memory(data, (int)size, &iw, &ih, &comp, 3);
        if (!*px) r = sy_error_set(err, SY_ERR_PARSE, "%s: Radiance HDR: %s", path, stbi_failure_reason());
        *w = (uint32_t)iw, *h = (uint32_t)ih;
    }
    free(data);
    return r;
}

/* EXR with R, G, B (or Y) channels into float RGB. */
static sy_result load_exr(const char *path, float **out, uint32_t *ow, uint32_t *oh, sy_error *err)
{
    sy_exr_image *img = NULL;
    sy_result r = sy_exr_read(path, &img, err);
    if (r != SY_OK) return r;
    const float *ch[3] = {sy_exr_image_channel(img, "R"), sy_exr_image_channel(img, "G"), sy_exr_image_channel(img, "B")};
    const float *y = sy_exr_image_channel(img, "Y");
    if (!ch[0] || !ch[1] || !ch[2]) {
        if (!y) {
            sy_exr_image_free(img);
            return sy_error_set(err, SY_ERR_PARSE, "%s: no R, G, B (or Y) channels", path);
        }
        ch[0] = ch[1] = ch[2] = y;
    }
    uint32_t w = (uint32_t)img->width, h = (uint32_t)img->height;
    size_t n = (size_t)w * h;
    float *px = malloc(n * 3 * sizeof *px);
    if (!px) {
        sy_exr_image_free(img);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", path);
    }
    for (size_t i = 0; i < n; ++i)
        for (int k = 0; k < 3; ++k) px[i * 3 + (size_t)k] = ch[k][i];
    sy_exr_image_free(img);
    *out = px, *ow = w, *oh = h;
    return SY_OK;
}

sy_result sy_world_load_environment(sy_scene *s, const char *path, uint64_t max_bytes, sy_texture *out, sy_error *err)
{
    sy_file_format format = SY_FORMAT_UNKNOWN;
    sy_result r = sy_sniff_file(path, &format, err);
    if (r != SY_OK) return r;
    bool radiance = format == SY_FORMAT_RADIANCE;
    float *px = NULL;
    uint32_t w = 0, h = 0;
    r = radiance ? load_radiance(path, max_bytes, &px, &w, &h, err) : load_exr(path, &px, &w, &h, err);
    if (r != SY_OK) {
        sy_error_prefix(err, "environment");
        return r;
    }
    /* lat-long: 360 x 180 degrees, so twice as wide as high (one pixel of rounding allowed) */
    if (h < 2 || (w > 2 * h ? w - 2 * h : 2 * h - w) > 1) {
        free(px);
        return sy_error_set(err, SY_ERR_PARSE, "environment %s: %u x %u is not a lat-long map (expected 2:1)", path, w, h);
    }
    for (size_t i = 0; i < (size_t)w * h; ++i)
        for (int k = 0; k < 3; ++k) {
            float v = px[i * 3 + (size_t)k];
            if (!isfinite(v) || v < 0.0f) {
                free(px);
                return sy_error_set(err, SY_ERR_PARSE, "environment %s: pixel (%zu, %zu) has a %s value %g", path, i % w,
                                    i / w, isfinite(v) ? "negative" : "non-finite", (double)v);
            }
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
        if ((r = sy_world_load_environment(s, o->env_path, o->max_scene_bytes, &bd.environment, err))) return r;
    } else if (o->has_env_color) {
        float *px = malloc(3 * sizeof *px);
        if (!px) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "environment colour: out of memory");
        memcpy(px, o->env_color, 3 * sizeof *px);
        if ((r = sy_world_texture_take(s, "environment colour", px, 1, 1, &bd.environment, err))) return r;
    }
    if (o->env_intensity_set) bd.intensity = o->env_intensity;
    if (o->env_hidden) bd.environment_visible = 0;
    if (o->has_background) { /* the user's colour replaces a file's sky / ground gradient too (X3D Background) */
        memcpy(bd.color, o->background, sizeof bd.color);
        bd.gradient.sky_count = bd.gradient.ground_count = 0;
    }
    if (o->no_default_light) bd.default_lighting = 0;
    if (!world->id && (r = sy_background_create(s, "world", world, err)) != SY_OK) return r;
    return sy_background_set(s, *world, &bd, err);
}
