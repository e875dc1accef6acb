/* sy_jpeg.c — RGBA8 <-> JPEG through libjpeg-turbo's TurboJPEG API, and JPEG files of rendered
 * images (see sy_jpeg.h). */
#include "sy_jpeg.h"

#include "sy_file.h"

#include <stdlib.h>
#include <string.h>
#include <turbojpeg.h>

sy_result sy_jpeg_encode_rgba8(const uint8_t *rgba, uint32_t w, uint32_t h, int quality, uint8_t **out,
                               size_t *out_len, sy_error *err)
{
    *out = NULL, *out_len = 0;
    if (!rgba || w == 0 || h == 0 || w > SY_JPEG_MAX_SIDE || h > SY_JPEG_MAX_SIDE)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "jpeg: encode: size %ux%u outside 1..%u", w, h, SY_JPEG_MAX_SIDE);
    if (quality < 1 || quality > 100)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "jpeg: encode: quality %d outside 1..100", quality);
    int sub = quality >= 90 ? TJSAMP_444 : TJSAMP_420;
    unsigned long cap = tjBufSize((int)w, (int)h, sub);
    if (cap == (unsigned long)-1) return sy_error_set(err, SY_ERR_LIMIT, "jpeg: encode: %ux%u is too large", w, h);
    unsigned char *buf = malloc(cap);
    if (!buf) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "jpeg: encode: out of memory (%lu bytes)", cap);
    tjhandle tj = tjInitCompress();
    if (!tj) {
        free(buf);
        return sy_error_set(err, SY_ERR_BACKEND, "jpeg: encode: TurboJPEG: %s", tjGetErrorStr2(NULL));
    }
    unsigned long len = cap;
    int rc = tjCompress2(tj, rgba, (int)w, (int)w * 4, (int)h, TJPF_RGBX, &buf, &len, sub, quality,
                         TJFLAG_NOREALLOC | TJFLAG_FASTDCT);
    sy_result r = SY_OK;
    if (rc != 0) r = sy_error_set(err, SY_ERR_BACKEND, "jpeg: encode %ux%u: TurboJPEG: %s", w, h, tjGetErrorStr2(tj));
    tjDestroy(tj);
    if (r != SY_OK) {
        free(buf);
        return r;
    }
    *out = buf, *out_len = len;
    return SY_OK;
}

sy_result sy_jpeg_decode_rgba8(const uint8_t *jpeg, size_t len, size_t max_pixels, uint8_t **out, uint32_t *w,
                               uint32_t *h, sy_error *err)
{
    *out = NULL, *w = 0, *h = 0;
    if (!jpeg || len == 0) return sy_error_set(err, SY_ERR_PARSE, "jpeg: decode: no data");
    if (len > 0x7fffffffu) return sy_error_set(err, SY_ERR_LIMIT, "jpeg: decode: %zu bytes is too large", len);
    if (!max_pixels) max_pixels = (size_t)SY_JPEG_MAX_SIDE * SY_JPEG_MAX_SIDE;
    tjhandle tj = tjInitDecompress();
    if (!tj) return sy_error_set(err, SY_ERR_BACKEND, "jpeg: decode: TurboJPEG: %s", tjGetErrorStr2(NULL));
    int iw = 0, ih = 0, sub = 0, cs = 0;
    sy_result r = SY_OK;
    size_t bytes = 0;
    uint8_t *px = NULL;
    if (tjDecompressHeader3(tj, jpeg, (unsigned long)len, &iw, &ih, &sub, &cs) != 0)
        r = sy_error_set(err, SY_ERR_PARSE, "jpeg: decode: bad header: %s", tjGetErrorStr2(tj));
    else if (iw <= 0 || ih <= 0)
        r = sy_error_set(err, SY_ERR_PARSE, "jpeg: decode: the header gives the size %dx%d", iw, ih);
    else if ((uint32_t)iw > SY_JPEG_MAX_SIDE || (uint32_t)ih > SY_JPEG_MAX_SIDE ||
             (size_t)iw * (size_t)ih > max_pixels)
        r = sy_error_set(err, SY_ERR_LIMIT, "jpeg: decode: %dx%d exceeds the limit (%zu pixels, side %u)", iw, ih,
                         max_pixels, SY_JPEG_MAX_SIDE);
    else if (!sy_size_mad((size_t)iw * 4, (size_t)ih, 0, &bytes) || !(px = malloc(bytes)))
        r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "jpeg: decode: out of memory for %dx%d", iw, ih);
    else if (tjDecompress2(tj, jpeg, (unsigned long)len, px, iw, iw * 4, ih, TJPF_RGBA, 0) != 0 &&
             tjGetErrorCode(tj) == TJERR_FATAL)
        r = sy_error_set(err, SY_ERR_PARSE, "jpeg: decode: %s", tjGetErrorStr2(tj));
    tjDestroy(tj);
    if (r != SY_OK) {
        free(px);
        return r;
    }
    *out = px, *w = (uint32_t)iw, *h = (uint32_t)ih;
    return SY_OK;
}

sy_result sy_jpeg_write(const char *path, int width, int height, const float *rgba, const sy_png_options *opts,
                        int quality, sy_error *err)
{
    if (!path || !rgba)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "sy_jpeg_write: path and pixel data are required");
    if (width < 1 || height < 1 || (uint32_t)width > SY_JPEG_MAX_SIDE || (uint32_t)height > SY_JPEG_MAX_SIDE)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: image size %dx%d outside 1..%u per side", path, width,
                            height, SY_JPEG_MAX_SIDE);
    size_t n = (size_t)width * (size_t)height;
    uint8_t *px = malloc(n * 4);
    if (!px) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory (%dx%d)", path, width, height);
    sy_png_encode_over_black(rgba, n, opts, px);
    uint8_t *jpeg = NULL;
    size_t len = 0;
    sy_result r = sy_jpeg_encode_rgba8(px, (uint32_t)width, (uint32_t)height, quality, &jpeg, &len, err);
    free(px);
    if (r != SY_OK) {
        sy_error_prefix(err, "%s", path);
        return r;
    }
    sy_atomic_file af = {0};
    r = sy_atomic_file_begin(path, &af, err);
    if (r == SY_OK && fwrite(jpeg, 1, len, af.fp) != len) {
        sy_atomic_file_abort(&af);
        r = sy_error_set(err, SY_ERR_IO, "%s: write failed", path);
    } else if (r == SY_OK) {
        r = sy_atomic_file_commit(&af, err);
    }
    free(jpeg);
    return r;
}
