/* sy_cluster_tile.c — the tile codec of the cluster (sy_cluster.h): a layer's channels as planes of
 * float32 or binary16 values, byte-shuffled, compressed with zstd; decoded straight into a
 * destination layer after checking every size the tile announces. No sockets, no state. */
#include "sy_cluster.h"

#include <zstd.h>

#include <stdlib.h>
#include <string.h>

sy_result sy_cluster_tile_encode_as(const sy_layer *tile, bool depth, uint32_t encoding, sy_cluster_buf *out,
                                    sy_error *err)
{
    uint32_t vb = sy_cluster_encoding_bytes(encoding);
    if (!vb) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cluster tile: unknown encoding %u", encoding);
    size_t px = (size_t)tile->width * tile->height, ch = depth ? 5 : 4, raw = px * ch * vb;
    uint8_t *shuf = malloc(raw ? raw : 1);
    if (!shuf) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "cluster tile: out of memory (%zu bytes)", raw);
    /* channel planes and byte shuffle in one pass: byte k of value j of the plane sequence goes to
     * shuf[k * nv + j], where j = channel * px + pixel */
    size_t nv = raw / vb;
    uint8_t *b0 = shuf, *b1 = shuf + nv, *b2 = vb == 4 ? shuf + 2 * nv : NULL, *b3 = vb == 4 ? shuf + 3 * nv : NULL;
    for (size_t c = 0; c < ch; ++c) {
        const float *src = c < 4 ? tile->rgba + c : tile->depth;
        size_t stride = c < 4 ? 4 : 1, base = c * px;
        if (vb == 2) {
            for (size_t i = 0; i < px; ++i) {
                uint16_t v = sy_cluster_half_from_float(src[i * stride]);
                b0[base + i] = (uint8_t)v;
                b1[base + i] = (uint8_t)(v >> 8);
            }
            continue;
        }
        for (size_t i = 0; i < px; ++i) {
            uint32_t v;
            memcpy(&v, &src[i * stride], 4);
            b0[base + i] = (uint8_t)v;
            b1[base + i] = (uint8_t)(v >> 8);
            b2[base + i] = (uint8_t)(v >> 16);
            b3[base + i] = (uint8_t)(v >> 24);
        }
    }
    size_t bound = ZSTD_compressBound(raw);
    out->size = 0;
    if (bound > out->cap) {
        uint8_t *d = realloc(out->data, bound);
        if (!d) {
            free(shuf);
            return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "cluster tile: out of memory");
        }
        out->data = d;
        out->cap = bound;
    }
    size_t n = ZSTD_compress(out->data, bound, shuf, raw, 1);
    free(shuf);
    if (ZSTD_isError(n)) return sy_error_set(err, SY_ERR_BACKEND, "cluster tile: zstd: %s", ZSTD_getErrorName(n));
    out->size = n;
    return SY_OK;
}

sy_result sy_cluster_tile_encode(const sy_layer *tile, bool depth, sy_cluster_buf *out, sy_error *err)
{
    return sy_cluster_tile_encode_as(tile, depth, SY_CLUSTER_ENC_F32_SHUFFLE_ZSTD, out, err);
}

sy_result sy_cluster_tile_decode(const sy_cluster_tile *t, sy_layer *dst, uint32_t dx, uint32_t dy, sy_error *err)
{
    const sy_cluster_rect *r = &t->rect;
    uint32_t vb = sy_cluster_encoding_bytes(t->encoding);
    if (!vb) return sy_error_set(err, SY_ERR_UNSUPPORTED, "cluster tile: unknown encoding %u", t->encoding);
    if (dx > dst->width || dy > dst->height || r->w > dst->width - dx || r->h > dst->height - dy)
        return sy_error_set(err, SY_ERR_PROTOCOL, "cluster tile %ux%u at %u,%u does not fit the %ux%u image", r->w,
                            r->h, dx, dy, dst->width, dst->height);
    size_t px = (size_t)r->w * r->h, raw = (size_t)t->raw_size;
    if (raw != px * t->channels * vb) return sy_error_set(err, SY_ERR_PROTOCOL, "cluster tile: raw size mismatch");
    unsigned long long fs = ZSTD_getFrameContentSize(t->data, t->data_size);
    if (fs != raw)
        return sy_error_set(err, SY_ERR_PROTOCOL, "cluster tile %u,%u: compressed frame announces %llu bytes, expected %zu",
                            r->x, r->y, fs, raw);
    uint8_t *shuf = malloc(raw ? raw : 1);
    if (!shuf) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "cluster tile: out of memory");
    size_t n = ZSTD_decompress(shuf, raw, t->data, t->data_size);
    if (ZSTD_isError(n) || n != raw) {
        free(shuf);
        return sy_error_set(err, SY_ERR_PROTOCOL, "cluster tile %u,%u: corrupt compressed data (%s)", r->x, r->y,
                            ZSTD_isError(n) ? ZSTD_getErrorName(n) : "short");
    }
    /* unshuffle straight into the destination rows */
    size_t nv = raw / vb;
    const uint8_t *b0 = shuf, *b1 = shuf + nv, *b2 = vb == 4 ? shuf + 2 * nv : NULL, *b3 = vb == 4 ? shuf + 3 * nv : NULL;
    for (size_t c = 0; c < t->channels; ++c) {
        if (c == 4 && !dst->depth) break;
        size_t base = c * px;
        for (uint32_t y = 0; y < r->h; ++y) {
            size_t row = base + (size_t)y * r->w, o = (size_t)(dy + y) * dst->width + dx;
            float *out = c < 4 ? dst->rgba + o * 4 + c : dst->depth + o;
            size_t stride = c < 4 ? 4 : 1;
            for (uint32_t x = 0; x < r->w; ++x) {
                size_t j = row + x;
                if (vb == 2) {
                    out[x * stride] = sy_cluster_half_to_float((uint16_t)(b0[j] | (b1[j] << 8)));
                    continue;
                }
                uint32_t v = (uint32_t)b0[j] | ((uint32_t)b1[j] << 8) | ((uint32_t)b2[j] << 16) | ((uint32_t)b3[j] << 24);
                memcpy(&out[x * stride], &v, 4);
            }
        }
    }
    free(shuf);
    return SY_OK;
}
