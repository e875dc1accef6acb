/** @file
 * sy_jpeg.h — JPEG encoding and decoding of 8-bit RGBA pixels (libjpeg-turbo's TurboJPEG API):
 * the frames and stills that sy web streams to a browser, and JPEG files of rendered images
 * (sy_jpeg_write: `sy render -o X.jpg`). Alpha is dropped when encoding (the colour is written as
 * it is: premultiplied pixels come out composited over black) and set to 255 when decoding.
 *
 * Ownership: *out buffers are malloc()ed and owned by the caller (free()).
 * Thread-safety: every call uses its own TurboJPEG handle; calls may run on any thread. */
#ifndef SY_JPEG_H
#define SY_JPEG_H

#include "sy_common.h"
#include "sy_png.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The largest width or height sy_jpeg_encode_rgba8 and sy_jpeg_decode_rgba8 accept. */
#define SY_JPEG_MAX_SIDE 16384u

/** Encodes w x h RGBA8 pixels (rows top first, 4*w bytes each) at quality 1..100 (4:2:0 chroma
 * below 90, 4:4:4 from 90). *out receives the JPEG bytes, *out_len their count. */
sy_result sy_jpeg_encode_rgba8(const uint8_t *rgba, uint32_t w, uint32_t h, int quality, uint8_t **out,
                               size_t *out_len, sy_error *err);

/** Writes width x height premultiplied linear RGBA floats (rows top first) as a JPEG file at
 * quality 1..100, each pixel encoded for display exactly as sy_png_write encodes it
 * (sy_png_encode_pixel: exposure, tone map, sRGB; opts NULL = the defaults; text chunks are not
 * written). Through sy_atomic_file: a failure leaves no partial file. */
sy_result sy_jpeg_write(const char *path, int width, int height, const float *rgba, const sy_png_options *opts,
                        int quality, sy_error *err);

/** Decodes a JPEG (untrusted bytes) into RGBA8: *out holds w x h x 4 bytes; images larger than
 * max_pixels (0 = SY_JPEG_MAX_SIDE squared) or with a side above SY_JPEG_MAX_SIDE are refused
 * (SY_ERR_LIMIT), malformed data fails with SY_ERR_PARSE. */
sy_result sy_jpeg_decode_rgba8(const uint8_t *jpeg, size_t len, size_t max_pixels, uint8_t **out, uint32_t *w,
                               uint32_t *h, sy_error *err);

#ifdef __cplusplus
}
#endif
#endif /* SY_JPEG_H */
