/* sy_web_frame.c — sy web's binary frame, format 3: packing (the server) and reading (clients,
 * tests); the depth channel's grid, 12-bit log quantisation, interpolation, prediction and deflate (see
 * sy_web_frame.h). */
#include "sy_web_frame.h"

#include <zlib.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Offsets of the header's fields (docs/WEB.md). */
enum {
    OFF_MAGIC = 0, OFF_W = 4, OFF_H = 8, OFF_BACKEND = 12, OFF_SAMPLES = 16, OFF_MS = 20, OFF_SEQ = 24, OFF_INPUT = 32,
    OFF_HEADER = 40, OFF_JPEG = 44, OFF_DEPTH = 48, OFF_CODING = 52, OFF_DMIN = 56, OFF_DMAX = 60, OFF_C2W = 64,
    OFF_WINDOW = 128, OFF_PROJ = 144, OFF_ZNEAR = 148, OFF_ZFAR = 152, OFF_TARGET = 156, OFF_YAW = 168,
    OFF_PITCH = 172, OFF_DIST = 176, OFF_FLAGS = 180, OFF_CODEC = 184, OFF_QUALITY = 188
};

/* The largest frame a reader accepts (pixels): the server's frame cap is 3840 x 2400 by default. */
#define MAX_PIXELS (8192u * 8192u)

static void put32(uint8_t *p, uint32_t v) { memcpy(p, &v, 4); } /* little-endian hosts (x86-64, arm64) */
static void putf(uint8_t *p, float v) { memcpy(p, &v, 4); }
static uint32_t get32(const uint8_t *p)
{
    uint32_t v;
    memcpy(&v, p, 4);
    return v;
}
static float getf(const uint8_t *p)
{
    float v;
    memcpy(&v, p, 4);
    return v;
}

static bool hit(float d) { return isfinite(d) && d > 0.0f; }

/* The depth grid of a w x h frame: every SY_WEB_DEPTH_STEP-th pixel in x and y, plus the last
 * column and row (docs/WEB.md, depth coding 2): column i holds pixel min(4 i, w - 1), row j pixel
 * min(4 j, h - 1); ceil((n - 1) / 4) + 1 of them. */
#define STEP SY_WEB_DEPTH_STEP
#define QMAX 4095u /* 12-bit values: 0 = nothing, 1..4095 the log scale */
static uint32_t grid_n(uint32_t n) { return (n - 1 + STEP - 1) / STEP + 1; }
static uint32_t grid_src(uint32_t i, uint32_t n) { return STEP * i < n - 1 ? STEP * i : n - 1; }

/* The MED predictor (LOCO-I) of a grid value from its left (a), upper (b) and upper-left (c)
 * neighbours; the first row predicts from the left, the first column from above. */
static uint16_t med(uint32_t i, uint32_t j, const uint16_t *q, uint32_t gw)
{
    if (!j) return i ? q[i - 1] : 0;
    if (!i) return q[(size_t)(j - 1) * gw];
    int a = q[(size_t)j * gw + i - 1], b = q[(size_t)(j - 1) * gw + i], c = q[(size_t)(j - 1) * gw + i - 1];
    int mx = a > b ? a : b, mn = a < b ? a : b;
    return (uint16_t)(c >= mx ? mn : c <= mn ? mx : a + b - c);
}

/* The depth channel (coding 2): on the depth grid, q = 0 where nothing was hit, else 1 +
 * round(4094 x log(d / dmin) / log(dmax / dmin)) with dmin, dmax over the grid; each value minus
 * its MED prediction (mod 65536), the low bytes of the whole grid, then the high bytes; deflated
 * (zlib format, level 6). */
static sy_result pack_depth(const float *depth, uint32_t w, uint32_t h, uint8_t **out, size_t *len, float *dmin,
                            float *dmax, sy_error *err)
{
    uint32_t gw = grid_n(w), gh = grid_n(h);
    size_t n = (size_t)gw * gh;
    float lo = INFINITY, hi = 0.0f;
    for (uint32_t j = 0; j < gh; ++j)
        for (uint32_t i = 0; i < gw; ++i) {
            float d = depth[(size_t)grid_src(j, h) * w + grid_src(i, w)];
            if (hit(d)) lo = fminf(lo, d), hi = fmaxf(hi, d);
        }
    if (!(lo <= hi)) lo = hi = 1.0f; /* nothing hit */
    *dmin = lo, *dmax = hi;
    double span = log((double)hi / lo), k = span > 0 ? (QMAX - 1) / span : 0.0;
    uint16_t *q = malloc(n * sizeof *q);
    uint8_t *planes = malloc(2 * n);
    uLongf cap = compressBound((uLong)(2 * n));
    uint8_t *z = malloc(cap);
    if (!q || !planes || !z) {
        free(q);
        free(planes);
        free(z);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "web: out of memory for a depth channel of %ux%u", w, h);
    }
    for (uint32_t j = 0; j < gh; ++j)
        for (uint32_t i = 0; i < gw; ++i) {
            float d = depth[(size_t)grid_src(j, h) * w + grid_src(i, w)];
            uint16_t v16 = 0;
            if (hit(d)) {
                double v = 1.0 + floor(log((double)d / lo) * k + 0.5);
                v16 = (uint16_t)(v < 1 ? 1 : v > QMAX ? QMAX : v);
            }
            q[(size_t)j * gw + i] = v16;
        }
    for (uint32_t j = 0; j < gh; ++j)
        for (uint32_t i = 0; i < gw; ++i) {
            size_t x = (size_t)j * gw + i;
            uint16_t e = (uint16_t)(q[x] - med(i, j, q, gw));
            planes[x] = (uint8_t)(e & 0xff), planes[n + x] = (uint8_t)(e >> 8);
        }
    free(q);
    int zr = compress2(z, &cap, planes, (uLong)(2 * n), 6);
    free(planes);
    if (zr != Z_OK) {
        free(z);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "web: deflating a depth channel of %ux%u failed (zlib %d)", w, h, zr);
    }
    *out = z, *len = cap;
    return SY_OK;
}

sy_result sy_web_frame_depth_code(const float *depth, uint32_t width, uint32_t height, uint8_t **out, size_t *len,
                                  float *dmin, float *dmax, sy_error *err)
{
    *out = NULL, *len = 0;
    if (!width || !height || (uint64_t)width * height > MAX_PIXELS)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "web: a depth channel of %ux%u", width, height);
    return pack_depth(depth, width, height, out, len, dmin, dmax, err);
}

sy_result sy_web_frame_pack(sy_web_frame_info *fi, const uint8_t *jpeg, size_t jpeg_len, const float *depth,
                            size_t prefix, uint8_t **out, size_t *len, sy_error *err)
{
    *out = NULL, *len = 0;
    uint8_t *z = NULL;
    size_t zlen = 0;
    float lo = 0.0f, hi = 0.0f;
    if (depth) {
        sy_result r = sy_web_frame_depth_code(depth, fi->width, fi->height, &z, &zlen, &lo, &hi, err);
        if (r != SY_OK) return r;
    }
    sy_result r = sy_web_frame_pack_coded(fi, jpeg, jpeg_len, z, zlen, lo, hi, prefix, out, len, err);
    free(z);
    return r;
}

sy_result sy_web_frame_pack_coded(sy_web_frame_info *fi, const uint8_t *jpeg, size_t jpeg_len, const uint8_t *z,
                                  size_t zlen, float dmin, float dmax, size_t prefix, uint8_t **out, size_t *len,
                                  sy_error *err)
{
    *out = NULL, *len = 0;
    fi->depth_coding = zlen ? SY_WEB_DEPTH_GRID_LOG12 : 0;
    fi->depth_min = zlen ? dmin : 0.0f, fi->depth_max = zlen ? dmax : 0.0f;
    if (jpeg_len > UINT32_MAX || zlen > UINT32_MAX) {
        return sy_error_set(err, SY_ERR_LIMIT, "web: a frame of %zu + %zu bytes is too large", jpeg_len, zlen);
    }
    fi->jpeg_len = (uint32_t)jpeg_len, fi->depth_len = (uint32_t)zlen;
    size_t total = SY_WEB_FRAME_HEADER + jpeg_len + zlen;
    uint8_t *buf = calloc(1, prefix + total);
    if (!buf) {
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "web: out of memory for a frame of %zu bytes", total);
    }
    uint8_t *h = buf + prefix;
    put32(h + OFF_MAGIC, SY_WEB_FRAME_MAGIC);
    put32(h + OFF_W, fi->width), put32(h + OFF_H, fi->height), put32(h + OFF_BACKEND, fi->backend);
    put32(h + OFF_SAMPLES, fi->samples), putf(h + OFF_MS, fi->render_ms);
    memcpy(h + OFF_SEQ, &fi->seq, 8), memcpy(h + OFF_INPUT, &fi->input_id, 8);
    put32(h + OFF_HEADER, SY_WEB_FRAME_HEADER), put32(h + OFF_JPEG, fi->jpeg_len), put32(h + OFF_DEPTH, fi->depth_len);
    put32(h + OFF_CODING, fi->depth_coding), putf(h + OFF_DMIN, fi->depth_min), putf(h + OFF_DMAX, fi->depth_max);
    for (int i = 0; i < 16; ++i) putf(h + OFF_C2W + 4 * i, fi->view.camera_to_world.m[i]);
    for (int i = 0; i < 4; ++i) putf(h + OFF_WINDOW + 4 * i, fi->view.window[i]);
    put32(h + OFF_PROJ, fi->view.projection), putf(h + OFF_ZNEAR, fi->view.znear), putf(h + OFF_ZFAR, fi->view.zfar);
    for (int i = 0; i < 3; ++i) putf(h + OFF_TARGET + 4 * i, fi->orbit.target[i]);
    putf(h + OFF_YAW, fi->orbit.yaw), putf(h + OFF_PITCH, fi->orbit.pitch), putf(h + OFF_DIST, fi->orbit.dist);
    put32(h + OFF_FLAGS, fi->flags);
    put32(h + OFF_CODEC, (uint32_t)fi->codec), putf(h + OFF_QUALITY, fi->quality);
    if (jpeg_len) memcpy(h + SY_WEB_FRAME_HEADER, jpeg, jpeg_len);
    if (zlen) memcpy(h + SY_WEB_FRAME_HEADER + jpeg_len, z, zlen);
    *out = buf, *len = total;
    return SY_OK;
}

void sy_web_frame_set_payload(uint8_t *h, const sy_web_frame_info *fi)
{
    put32(h + OFF_JPEG, fi->jpeg_len);
    put32(h + OFF_CODEC, (uint32_t)fi->codec), putf(h + OFF_QUALITY, fi->quality);
    put32(h + OFF_FLAGS, get32(h + OFF_FLAGS) | fi->flags);
}

/* One axis of the grid: the columns i0, i1 around pixel x and the weight t of i1. */
static void grid_axis(uint32_t x, uint32_t n, uint32_t gn, uint32_t *i0, uint32_t *i1, float *t)
{
    *i0 = x / STEP < gn - 1 ? x / STEP : gn - 1;
    uint32_t p0 = grid_src(*i0, n);
    *i1 = *i0, *t = 0.0f;
    if (p0 == x || *i0 == gn - 1) return;
    *i1 = *i0 + 1;
    *t = (float)(x - p0) / (float)(grid_src(*i1, n) - p0);
}

float sy_web_depth_grid_at(const float *g, uint32_t gw, uint32_t gh, uint32_t width, uint32_t height, uint32_t x, uint32_t y)
{
    uint32_t i0, i1, j0, j1;
    float tx, ty;
    grid_axis(x, width, gw, &i0, &i1, &tx);
    grid_axis(y, height, gh, &j0, &j1, &ty);
    float c[4] = {g[(size_t)j0 * gw + i0], g[(size_t)j0 * gw + i1], g[(size_t)j1 * gw + i0], g[(size_t)j1 * gw + i1]};
    float w[4] = {(1 - tx) * (1 - ty), tx * (1 - ty), (1 - tx) * ty, tx * ty};
    float inv = 0.0f;
    int near = 0;
    for (int k = 0; k < 4; ++k) {
        if (w[k] > w[near]) near = k;
        if (w[k] > 0 && !(c[k] > 0)) inv = -1.0f; /* a corner without a hit: the nearest corner's value */
        else if (inv >= 0 && w[k] > 0) inv += w[k] / c[k];
    }
    return inv > 0 ? 1.0f / inv : c[near];
}

void sy_web_frame_drop_depth(uint8_t *h)
{
    put32(h + OFF_DEPTH, 0);
    put32(h + OFF_FLAGS, get32(h + OFF_FLAGS) | SY_WEB_FRAME_SAME_DEPTH);
}

sy_result sy_web_frame_parse(const uint8_t *data, size_t len, sy_web_frame_info *fi, const uint8_t **jpeg,
                             const uint8_t **depth, sy_error *err)
{
    memset(fi, 0, sizeof *fi);
    if (len < 8 || (get32(data) & 0xffffffu) != (SY_WEB_FRAME_MAGIC & 0xffffffu))
        return sy_error_set(err, SY_ERR_PROTOCOL, "web frame: a binary message of %zu bytes is no frame (magic)", len);
    if (get32(data) != SY_WEB_FRAME_MAGIC)
        return sy_error_set(err, SY_ERR_PROTOCOL, "web frame: format %c, this client reads format %u", (char)data[3],
                            SY_WEB_FRAME_VERSION);
    if (len < SY_WEB_FRAME_HEADER || get32(data + OFF_HEADER) != SY_WEB_FRAME_HEADER)
        return sy_error_set(err, SY_ERR_PROTOCOL, "web frame: a header of %zu bytes, not %u", len, SY_WEB_FRAME_HEADER);
    fi->width = get32(data + OFF_W), fi->height = get32(data + OFF_H), fi->backend = get32(data + OFF_BACKEND);
    fi->samples = get32(data + OFF_SAMPLES), fi->render_ms = getf(data + OFF_MS);
    memcpy(&fi->seq, data + OFF_SEQ, 8), memcpy(&fi->input_id, data + OFF_INPUT, 8);
    fi->jpeg_len = get32(data + OFF_JPEG), fi->depth_len = get32(data + OFF_DEPTH);
    fi->depth_coding = get32(data + OFF_CODING), fi->depth_min = getf(data + OFF_DMIN), fi->depth_max = getf(data + OFF_DMAX);
    for (int i = 0; i < 16; ++i) fi->view.camera_to_world.m[i] = getf(data + OFF_C2W + 4 * i);
    for (int i = 0; i < 4; ++i) fi->view.window[i] = getf(data + OFF_WINDOW + 4 * i);
    fi->view.projection = get32(data + OFF_PROJ), fi->view.znear = getf(data + OFF_ZNEAR), fi->view.zfar = getf(data + OFF_ZFAR);
    for (int i = 0; i < 3; ++i) fi->orbit.target[i] = getf(data + OFF_TARGET + 4 * i);
    fi->orbit.yaw = getf(data + OFF_YAW), fi->orbit.pitch = getf(data + OFF_PITCH), fi->orbit.dist = getf(data + OFF_DIST);
    fi->flags = get32(data + OFF_FLAGS);
    uint32_t codec = get32(data + OFF_CODEC);
    fi->codec = codec < SY_WEB_CODEC_COUNT ? (sy_web_codec)codec : SY_WEB_CODEC_JPEG;
    fi->quality = getf(data + OFF_QUALITY);
    if (codec >= SY_WEB_CODEC_COUNT)
        return sy_error_set(err, SY_ERR_PROTOCOL, "web frame: unknown payload codec %u", codec);
    if (!fi->width || !fi->height || (uint64_t)fi->width * fi->height > MAX_PIXELS)
        return sy_error_set(err, SY_ERR_PROTOCOL, "web frame: size %ux%u out of range", fi->width, fi->height);
    if ((uint64_t)SY_WEB_FRAME_HEADER + fi->jpeg_len + fi->depth_len != len)
        return sy_error_set(err, SY_ERR_PROTOCOL, "web frame: header %u + JPEG %u + depth %u bytes != the message's %zu",
                            SY_WEB_FRAME_HEADER, fi->jpeg_len, fi->depth_len, len);
    if (fi->depth_len && (fi->flags & SY_WEB_FRAME_SAME_DEPTH))
        return sy_error_set(err, SY_ERR_PROTOCOL, "web frame: %u depth bytes in a frame that says it has the last one's",
                            fi->depth_len);
    if (fi->depth_len && fi->depth_coding != SY_WEB_DEPTH_GRID_LOG12)
        return sy_error_set(err, SY_ERR_PROTOCOL, "web frame: unknown depth coding %u", fi->depth_coding);
    if (fi->depth_len && !(isfinite(fi->depth_min) && isfinite(fi->depth_max) && fi->depth_min > 0 && fi->depth_max >= fi->depth_min))
        return sy_error_set(err, SY_ERR_PROTOCOL, "web frame: depth range %g..%g is not 0 < min <= max", (double)fi->depth_min,
                            (double)fi->depth_max);
    if (jpeg) *jpeg = data + SY_WEB_FRAME_HEADER;
    if (depth) *depth = fi->depth_len ? data + SY_WEB_FRAME_HEADER + fi->jpeg_len : NULL;
    return SY_OK;
}

sy_result sy_web_frame_depth(const sy_web_frame_info *fi, const uint8_t *depth, float **out, sy_error *err)
{
    *out = NULL;
    size_t n = (size_t)fi->width * fi->height;
    if (!depth || !fi->depth_len || !n || n > MAX_PIXELS)
        return sy_error_set(err, SY_ERR_PROTOCOL, "web frame: no depth channel");
    uint32_t gw = grid_n(fi->width), gh = grid_n(fi->height);
    size_t gn = (size_t)gw * gh;
    /* deflate expands at most ~1032:1: a size the input cannot reach is refused before allocating */
    if (2 * (uint64_t)gn > 1040ull * fi->depth_len + 64)
        return sy_error_set(err, SY_ERR_PROTOCOL, "web frame: %u depth bytes cannot hold %ux%u pixels", fi->depth_len,
                            fi->width, fi->height);
    uint8_t *planes = malloc(2 * gn + 1);
    uint16_t *q = malloc(gn * sizeof *q);
    float *d = malloc(n * sizeof *d);
    uLongf got = (uLongf)(2 * gn + 1);
    int zr = planes && q && d ? uncompress(planes, &got, depth, fi->depth_len) : Z_MEM_ERROR;
    if (zr != Z_OK || got != 2 * gn) {
        free(planes);
        free(q);
        free(d);
        return sy_error_set(err, zr == Z_MEM_ERROR ? SY_ERR_OUT_OF_MEMORY : SY_ERR_PROTOCOL,
                            "web frame: the depth channel does not inflate to %zu bytes (zlib %d, %lu bytes)", 2 * gn, zr,
                            (unsigned long)got);
    }
    for (uint32_t j = 0; j < gh; ++j)
        for (uint32_t i = 0; i < gw; ++i) {
            size_t x = (size_t)j * gw + i;
            q[x] = (uint16_t)(med(i, j, q, gw) + (uint16_t)(planes[x] | planes[gn + x] << 8));
        }
    free(planes);
    double lo = fi->depth_min, span = fi->depth_max > fi->depth_min ? log((double)fi->depth_max / lo) : 0.0;
    float *g = malloc(gn * sizeof *g); /* the grid's depths (0: nothing) */
    if (!g) {
        free(q);
        free(d);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "web frame: out of memory for a depth channel");
    }
    for (size_t k = 0; k < gn; ++k) {
        if (q[k] > QMAX) { /* no value of the scale */
            unsigned v = q[k];
            free(q), free(g), free(d);
            return sy_error_set(err, SY_ERR_PROTOCOL, "web frame: depth value %u beyond the 12-bit scale", v);
        }
        g[k] = q[k] ? (float)(lo * exp((q[k] - 1) / (double)(QMAX - 1) * span)) : 0.0f;
    }
    free(q);
    for (uint32_t y = 0; y < fi->height; ++y)
        for (uint32_t x = 0; x < fi->width; ++x) {
            float v = sy_web_depth_grid_at(g, gw, gh, fi->width, fi->height, x, y);
            d[(size_t)y * fi->width + x] = v > 0 ? v : INFINITY;
        }
    free(g);
    *out = d;
    return SY_OK;
}
