/* sy_png.c — 8-bit sRGB PNG writer (tone mapping + OETF), simplified-API reader and colour helpers
 * (see sy_png.h). libpng reports errors by longjmp; every setjmp lives in a function whose own
 * locals are not modified after it, and the per-pixel work happens in helpers it calls. */
#include "sy_png.h"

#include "sy_file.h"

#include <png.h>

#include <errno.h>
#include <math.h>
#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- >>colour helpers ---- */

/* Pixel conversion with the exposure scale already computed. */
static void encode_pixel(const float *in, float scale, sy_tonemap op, uint8_t *out)
{
    float a = in[3];
    float inv = a > 0.0f ? 1.0f / a : 0.0f; /* alpha 0 (or NaN): nothing to show, colour 0 */
    for (int c = 0; c < 3; ++c) {
        float v = in[c] * inv * scale;
        out[c] = sy_unorm8(sy_srgb_encode(sy_tonemap_apply(op, v)));
    }
    float ac = a > 0.0f ? (a < 1.0f ? a : 1.0f) : 0.0f;
    out[3] = sy_unorm8(ac);
}

void sy_png_encode_pixel(const float rgba_premultiplied[4], const sy_png_options *opts, uint8_t out[4])
{
    float stops = opts ? opts->exposure_stops : 0.0f;
    sy_tonemap op = opts ? opts->tonemap : SY_TONEMAP_CLAMP;
    encode_pixel(rgba_premultiplied, exp2f(stops), op, out);
}

void sy_png_encode_over_black(const float *rgba_premultiplied, size_t count, const sy_png_options *opts, uint8_t *out)
{
    float scale = exp2f(opts ? opts->exposure_stops : 0.0f);
    sy_tonemap op = opts ? opts->tonemap : SY_TONEMAP_CLAMP;
    for (size_t i = 0; i < count; ++i) {
        const float *p = rgba_premultiplied + 4 * i;
        const float c[4] = {p[0], p[1], p[2], 1.0f};
        encode_pixel(c, scale, op, out + 4 * i);
    }
}

/* ---- >>libpng passes: what the writer and the metadata reader share ---- */

/* The head of every job: the stream, and why the pass failed (the first libpng error, or ours). */
typedef struct png_io {
    FILE *fp;
    char msg[256];
} png_io;

/* libpng's error callback (error pointer: the job's png_io): keeps the first message, longjmps. */
static void on_png_error(png_structp png, png_const_charp msg)
{
    png_io *io = png_get_error_ptr(png);
    if (io && io->msg[0] == '\0') snprintf(io->msg, sizeof io->msg, "%s", msg ? msg : "libpng error");
    png_longjmp(png, 1);
}

static void on_png_warning(png_structp png, png_const_charp msg)
{
    (void)png; /* warnings fail neither a write nor a read; nothing to report */
    (void)msg;
}

/* Everything of a pass that may longjmp; false with io->msg on failure. */
typedef bool (*png_body_fn)(png_structp png, png_infop info, png_io *io);

static void png_pass_end(bool writing, png_structp *png, png_infop *info)
{
    if (writing) png_destroy_write_struct(png, info);
    else png_destroy_read_struct(png, info, NULL);
}

/* One libpng pass (a writer, or a reader): creates the structs, runs body under setjmp (libpng's
 * errors longjmp back here; no local is modified after it), destroys them. False with io->msg. */
static bool png_pass(bool writing, png_io *io, png_body_fn body)
{
    png_structp png = writing ? png_create_write_struct(PNG_LIBPNG_VER_STRING, io, on_png_error, on_png_warning)
                              : png_create_read_struct(PNG_LIBPNG_VER_STRING, io, on_png_error, on_png_warning);
    if (!png) {
        snprintf(io->msg, sizeof io->msg, "cannot create the libpng %s", writing ? "writer" : "reader");
        return false;
    }
    png_infop info = png_create_info_struct(png);
    if (!info) {
        png_pass_end(writing, &png, NULL);
        snprintf(io->msg, sizeof io->msg, "cannot create the libpng info struct");
        return false;
    }
    if (setjmp(png_jmpbuf(png))) {
        png_pass_end(writing, &png, &info);
        return false;
    }
    bool ok = body(png, info, io);
    png_pass_end(writing, &png, &info);
    return ok;
}

/* ---- >>writer ---- */

typedef struct png_write_job {
    png_io io; /* first: the pass sees the job as its png_io */
    int width, height;
    const float *rgba;
    float scale;
    sy_tonemap op;
    uint8_t *row; /* width * 4 bytes */
    const sy_png_text *text;
    int text_count;
} png_write_job;

/* Everything that may longjmp after the header is set up (a png_pass body). */
static bool write_png_body(png_structp png, png_infop info, png_io *io)
{
    png_write_job *job = (png_write_job *)io;
    png_init_io(png, io->fp);
    png_set_IHDR(png, info, (png_uint_32)job->width, (png_uint_32)job->height, 8, PNG_COLOR_TYPE_RGB_ALPHA,
                 PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_set_sRGB_gAMA_and_cHRM(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
    if (job->text_count > 0) {
        png_text t[SY_PNG_MAX_TEXT];
        memset(t, 0, sizeof t);
        for (int i = 0; i < job->text_count; ++i) {
            t[i].compression = PNG_TEXT_COMPRESSION_NONE;
            t[i].key = (png_charp)job->text[i].key;
            t[i].text = (png_charp)job->text[i].value;
            t[i].text_length = strlen(job->text[i].value);
        }
        png_set_text(png, info, t, job->text_count);
    }
    png_write_info(png, info);
    for (int y = 0; y < job->height; ++y) {
        const float *src = job->rgba + (size_t)y * (size_t)job->width * 4u;
        for (int x = 0; x < job->width; ++x) encode_pixel(src + (size_t)x * 4u, job->scale, job->op, job->row + (size_t)x * 4u);
        png_write_row(png, job->row);
    }
    png_write_end(png, NULL);
    return true;
}

sy_result sy_png_write(const char *path, int width, int height, const float *rgba, const sy_png_options *opts,
                       sy_error *err)
{
    if (!path || !rgba)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "sy_png_write: path and pixel data are required");
    if (width < 1 || height < 1 || width > SY_PNG_MAX_SIDE || height > SY_PNG_MAX_SIDE ||
        (size_t)width * (size_t)height > SY_PNG_MAX_PIXELS)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: image size %dx%d outside 1..%d per side / %u pixels",
                            path, width, height, SY_PNG_MAX_SIDE, SY_PNG_MAX_PIXELS);
    sy_png_options o = opts ? *opts : (sy_png_options){0};
    if (!isfinite(o.exposure_stops) || fabsf(o.exposure_stops) > 64.0f)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: exposure %g stops is not a finite value in [-64, 64]",
                            path, (double)o.exposure_stops);
    if (o.tonemap != SY_TONEMAP_CLAMP && o.tonemap != SY_TONEMAP_REINHARD && o.tonemap != SY_TONEMAP_ACES)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: unknown tone-mapping operator %d", path, (int)o.tonemap);
    if (o.text_count < 0 || o.text_count > SY_PNG_MAX_TEXT || (o.text_count && !o.text))
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: %d text chunks (0..%d)", path, o.text_count, SY_PNG_MAX_TEXT);
    for (int i = 0; i < o.text_count; ++i) {
        size_t kl = o.text[i].key ? strlen(o.text[i].key) : 0;
        if (kl < 1 || kl > 79 || !o.text[i].value)
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: text chunk %d: a key of 1..79 bytes and a value are needed",
                                path, i);
    }

    png_write_job job = {
        .width = width,
        .height = height,
        .rgba = rgba,
        .scale = exp2f(o.exposure_stops),
        .op = o.tonemap,
        .text = o.text,
        .text_count = o.text_count,
    };
    job.row = malloc((size_t)width * 4u);
    if (!job.row) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s: cannot allocate a %d-pixel row", path, width);

    sy_atomic_file af = {0};
    sy_result rc = sy_atomic_file_begin(path, &af, err);
    if (rc != SY_OK) {
        free(job.row);
        return rc;
    }
    job.io.fp = af.fp;
    bool ok = png_pass(true, &job.io, write_png_body);
    free(job.row);
    if (!ok) {
        sy_atomic_file_abort(&af);
        return sy_error_set(err, SY_ERR_IO, "%s: PNG encoding failed: %s", path, job.io.msg);
    }
    return sy_atomic_file_commit(&af, err);
}

/* ---- >>reader ---- */

sy_result sy_png_read_rgba8(const char *path, int *width_out, int *height_out, uint8_t **pixels_out, sy_error *err)
{
    if (width_out) *width_out = 0;
    if (height_out) *height_out = 0;
    if (pixels_out) *pixels_out = NULL;
    if (!path || !width_out || !height_out || !pixels_out)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "sy_png_read_rgba8: path and outputs are required");

    FILE *fp = fopen(path, "rb");
    if (!fp) {
        int e = errno;
        return sy_error_set(err, e == ENOENT ? SY_ERR_NOT_FOUND : SY_ERR_IO, "%s: cannot open: %s", path, strerror(e));
    }
    png_image image;
    memset(&image, 0, sizeof image);
    image.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_stdio(&image, fp)) {
        sy_result rc = sy_error_set(err, SY_ERR_PARSE, "%s: not a readable PNG: %s", path, image.message);
        png_image_free(&image);
        fclose(fp);
        return rc;
    }
    if (image.width < 1 || image.height < 1 || image.width > SY_PNG_MAX_SIDE || image.height > SY_PNG_MAX_SIDE ||
        (size_t)image.width * (size_t)image.height > SY_PNG_MAX_PIXELS) {
        sy_result rc = sy_error_set(err, SY_ERR_LIMIT, "%s: PNG of %ux%u exceeds %d per side / %u pixels", path,
                                    (unsigned)image.width, (unsigned)image.height, SY_PNG_MAX_SIDE, SY_PNG_MAX_PIXELS);
        png_image_free(&image);
        fclose(fp);
        return rc;
    }
    image.format = PNG_FORMAT_RGBA;
    size_t bytes = (size_t)image.width * (size_t)image.height * 4u; /* <= 2^30 by the limits above */
    uint8_t *pixels = malloc(bytes);
    if (!pixels) {
        png_image_free(&image);
        fclose(fp);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s: cannot allocate %zu bytes", path, bytes);
    }
    if (!png_image_finish_read(&image, NULL, pixels, 0, NULL)) {
        sy_result rc = sy_error_set(err, SY_ERR_PARSE, "%s: PNG decoding failed: %s", path, image.message);
        png_image_free(&image);
        fclose(fp);
        free(pixels);
        return rc;
    }
    png_image_free(&image);
    fclose(fp);
    *width_out = (int)image.width;
    *height_out = (int)image.height;
    *pixels_out = pixels;
    return SY_OK;
}

/* ---- >>metadata reader ---- */

typedef struct png_info_job {
    png_io io; /* first: the pass sees the job as its png_io */
    sy_png_info *out;
} png_info_job;

/* Everything that may longjmp (a png_pass body). */
static bool read_info_body(png_structp png, png_infop info, png_io *io)
{
    png_info_job *job = (png_info_job *)io;
    png_init_io(png, io->fp);
    png_set_chunk_malloc_max(png, 1u << 20); /* one chunk, zTXt decompressed included */
    png_set_chunk_cache_max(png, 64);        /* ancillary chunks kept */
    png_read_info(png, info);
    job->out->width = (int)png_get_image_width(png, info);
    job->out->height = (int)png_get_image_height(png, info);
    png_textp t = NULL;
    int n = 0;
    png_get_text(png, info, &t, &n);
    for (int i = 0; i < n && job->out->text_count < SY_PNG_MAX_TEXT; ++i) {
        char *k = strdup(t[i].key ? t[i].key : "");
        char *v = malloc(t[i].text_length + 1);
        if (!k || !v) {
            free(k);
            free(v);
            snprintf(io->msg, sizeof io->msg, "out of memory for text chunk '%s'", t[i].key ? t[i].key : "");
            return false;
        }
        if (t[i].text_length) memcpy(v, t[i].text, t[i].text_length);
        v[t[i].text_length] = '\0';
        job->out->keys[job->out->text_count] = k;
        job->out->values[job->out->text_count++] = v;
    }
    return true;
}

sy_result sy_png_read_info(const char *path, sy_png_info *out, sy_error *err)
{
    if (!out) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "sy_png_read_info: out is required");
    memset(out, 0, sizeof *out);
    if (!path) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "sy_png_read_info: path is required");
    FILE *fp = fopen(path, "rb");
    if (!fp) {
        int e = errno;
        return sy_error_set(err, e == ENOENT ? SY_ERR_NOT_FOUND : SY_ERR_IO, "%s: cannot open: %s", path, strerror(e));
    }
    uint8_t sig[8];
    if (fread(sig, 1, sizeof sig, fp) != sizeof sig || png_sig_cmp(sig, 0, sizeof sig) != 0) {
        fclose(fp);
        return sy_error_set(err, SY_ERR_PARSE, "%s: not a PNG (no PNG signature)", path);
    }
    rewind(fp);
    png_info_job job = {.io = {.fp = fp}, .out = out};
    bool ok = png_pass(false, &job.io, read_info_body);
    fclose(fp);
    if (!ok) {
        sy_png_info_free(out);
        return sy_error_set(err, SY_ERR_PARSE, "%s: not a readable PNG: %s", path, job.io.msg);
    }
    return SY_OK;
}

void sy_png_info_free(sy_png_info *info)
{
    if (!info) return;
    for (int i = 0; i < info->text_count; ++i) {
        free(info->keys[i]);
        free(info->values[i]);
    }
    memset(info, 0, sizeof *info);
}
