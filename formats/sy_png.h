/** @file
 * sy_png.h — display-referred 8-bit PNG output of a linear render layer (exposure, tone mapping,
 * sRGB encoding), an 8-bit RGBA PNG reader for tests and tools, and the small colour helpers
 * (sRGB OETF / EOTF, tone-mapping operators) other modules reuse.
 *
 * Input layers are sy_layer's (sy_mediator.h): w*h interleaved RGBA floats, linear scene-referred,
 * alpha PREMULTIPLIED, row 0 at the TOP. The writer un-premultiplies, applies exposure and the
 * tone-mapping operator per channel, clamps to [0, 1], encodes with the exact piecewise sRGB OETF
 * and rounds to 8 bits; alpha is stored linearly (straight, not premultiplied, as PNG requires).
 * The file carries sRGB, gAMA and cHRM chunks and is written through sy_atomic_file (temp file,
 * fsync, rename), so a failure leaves no partial file.
 *
 * Thread-safety: no shared mutable state; every function may be called concurrently. */
#ifndef SY_PNG_H
#define SY_PNG_H

#include "sy_common.h"
#include "sy_post.h"

#ifdef __cplusplus
extern "C" {
#endif

#define SY_PNG_MAX_SIDE 65536            /**< pixels per side, both directions */
#define SY_PNG_MAX_PIXELS (1u << 28)     /**< width * height */

/* sy_tonemap, sy_srgb_encode/decode and sy_tonemap_apply live in core/sy_post.h. */

/** A text chunk (tEXt: Latin-1 key of 1..79 bytes; the value is written as given). */
typedef struct sy_png_text {
    /** @{ key and value (see above) */
    const char *key, *value; /** @} */
} sy_png_text;
#define SY_PNG_MAX_TEXT 32 /**< text chunks per file */

/** PNG output options; zero-initialised ({0}): exposure 0 stops, SY_TONEMAP_CLAMP. */
typedef struct sy_png_options {
    float exposure_stops; /**< colour is multiplied by 2^exposure_stops before tone mapping */
    sy_tonemap tonemap; /**< tone-mapping operator (core/sy_post.h) */
    const sy_png_text *text; /**< metadata chunks (e.g. the renderer, back-end, samples), borrowed */
    int text_count;          /**< 0..SY_PNG_MAX_TEXT */
} sy_png_options;

/** Converts one premultiplied linear RGBA pixel to 8-bit straight-alpha sRGB exactly as
 * sy_png_write does (opts may be NULL for the defaults). */
void sy_png_encode_pixel(const float rgba_premultiplied[4], const sy_png_options *opts, uint8_t out[4]);
/** Converts count premultiplied linear RGBA pixels composited over black (opaque: the
 * premultiplied colour, alpha 1) as sy_png_encode_pixel does: the 8-bit frames of JPEG files and
 * streams. out holds count * 4 bytes. */
void sy_png_encode_over_black(const float *rgba_premultiplied, size_t count, const sy_png_options *opts, uint8_t *out);

/** Writes w x h pixels (rgba: w*h*4 floats, premultiplied linear, row 0 on top) as an 8-bit RGBA
 * sRGB PNG at path. opts may be NULL (defaults). Errors name the file and the reason.
 * Ownership: borrows rgba and opts for the duration of the call. */
sy_result sy_png_write(const char *path, int width, int height, const float *rgba, const sy_png_options *opts,
                       sy_error *err);

/** Reads any PNG as 8-bit straight-alpha RGBA (sRGB-encoded bytes as stored, row 0 on top) through
 * libpng's simplified API. Sizes beyond SY_PNG_MAX_* give SY_ERR_LIMIT; malformed files SY_ERR_PARSE.
 * Ownership: on success the caller owns *pixels_out (w*h*4 bytes) and frees it with free(); on
 * failure *pixels_out is NULL and the sizes are 0. */
sy_result sy_png_read_rgba8(const char *path, int *width_out, int *height_out, uint8_t **pixels_out,
                            sy_error *err);

/** A PNG's header and the text chunks that come before its image data (where sy_png_write puts
 * its metadata: sy:renderer, sy:backend, ...). */
typedef struct sy_png_info {
    int width;                      /**< pixels, from the header */
    int height;                     /**< pixels, from the header */
    int text_count;                 /**< keys / values used (at most SY_PNG_MAX_TEXT; later ones are dropped) */
    char *keys[SY_PNG_MAX_TEXT];    /**< the chunks' keys (owned copies, sy_png_info_free) */
    char *values[SY_PNG_MAX_TEXT];  /**< the chunks' values (owned copies, sy_png_info_free) */
} sy_png_info;

/** Reads the header and the text chunks (tEXt, zTXt, iTXt) before the image data of the PNG at
 * path, without decoding pixels. Untrusted input: a chunk over 1 MiB (zTXt decompressed
 * included), more than 64 ancillary chunks or a malformed file is an error naming the file.
 * Ownership: on success the caller frees *out with sy_png_info_free; on failure *out is zeroed. */
sy_result sy_png_read_info(const char *path, sy_png_info *out, sy_error *err);

/** Frees what sy_png_read_info allocated; safe on a zeroed or freed info. */
void sy_png_info_free(sy_png_info *info);

#ifdef __cplusplus
}
#endif
#endif /* SY_PNG_H */
