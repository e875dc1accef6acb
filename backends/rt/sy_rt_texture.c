/* sy_rt_texture.c — texture creation (validated, copied) and sampling with wrap modes and
 * nearest/bilinear filtering. */
#include "sy_rt_texture.h"

#include <stdlib.h>
#include <string.h>

sy_rt_result sy_rt_texture_create(sy_rt_device *dev, const sy_rt_texture_desc *d, sy_rt_texture *out)
{
    if (!dev || !d || !out) return sy_rt_fail(dev, SY_RT_ERROR_INVALID_ARGUMENT, "texture: NULL argument");
    out->id = 0;
    if (d->width == 0 || d->height == 0)
        return sy_rt_fail(dev, SY_RT_ERROR_INVALID_ARGUMENT, "texture: size %ux%u is empty", d->width, d->height);
    if (d->channels < 1 || d->channels > 4)
        return sy_rt_fail(dev, SY_RT_ERROR_INVALID_ARGUMENT, "texture: channels = %u, expected 1..4", d->channels);
    if (!d->pixels) return sy_rt_fail(dev, SY_RT_ERROR_INVALID_ARGUMENT, "texture: pixels is NULL");
    size_t elem;
    switch (d->format) {
    case SY_RT_TEXEL_UNORM8: case SY_RT_TEXEL_UNORM8_SRGB: elem = 1; break;
    case SY_RT_TEXEL_FLOAT32: elem = sizeof(float); break;
    default: return sy_rt_fail(dev, SY_RT_ERROR_INVALID_ARGUMENT, "texture: unknown texel format %d", (int)d->format);
    }
    if ((unsigned)d->wrap_s > SY_RT_WRAP_MIRROR || (unsigned)d->wrap_t > SY_RT_WRAP_MIRROR)
        return sy_rt_fail(dev, SY_RT_ERROR_INVALID_ARGUMENT, "texture: unknown wrap mode");
    if ((unsigned)d->filter > SY_RT_FILTER_NEAREST)
        return sy_rt_fail(dev, SY_RT_ERROR_INVALID_ARGUMENT, "texture: unknown filter");
    size_t bytes;
    if (!sy_rt_size_mul(d->width, d->height, &bytes) || !sy_rt_size_mul(bytes, d->channels, &bytes) ||
        !sy_rt_size_mul(bytes, elem, &bytes))
        return sy_rt_fail(dev, SY_RT_ERROR_LIMIT, "texture: %ux%ux%u texels overflow size_t", d->width, d->height, d->channels);

    sy_rt_texture_data *t = calloc(1, sizeof *t);
    void *px = t ? malloc(bytes) : NULL;
    if (!px) {
        free(t);
        return sy_rt_fail(dev, SY_RT_ERROR_OUT_OF_MEMORY, "texture: cannot allocate %zu bytes", bytes);
    }
    memcpy(px, d->pixels, bytes);
    t->width = d->width; t->height = d->height; t->channels = d->channels;
    t->format = d->format; t->pixels = px;
    t->srgb_lut = d->format == SY_RT_TEXEL_UNORM8_SRGB ? dev->srgb_lut : NULL;
    t->wrap_s = d->wrap_s; t->wrap_t = d->wrap_t; t->filter = d->filter;
    if (!sy_rt_pool_insert(&dev->textures, t, &out->id)) {
        sy_rt_texture_free(t);
        return sy_rt_fail(dev, SY_RT_ERROR_LIMIT, "texture: pool full or out of memory");
    }
    dev->dirty = true;
    return SY_RT_OK;
}

sy_rt_result sy_rt_texture_destroy(sy_rt_device *dev, sy_rt_texture tex)
{
    if (!dev) return sy_rt_fail(dev, SY_RT_ERROR_INVALID_ARGUMENT, "texture destroy: NULL device");
    sy_rt_texture_data *t = sy_rt_pool_take(dev, &dev->textures, tex.id, "texture destroy");
    if (!t) return SY_RT_ERROR_INVALID_HANDLE;
    sy_rt_texture_free(t);
    /* Emissive textures shape the area lights at sample time, and the light tree, which leaves
     * out triangles over black texels: its next use builds it again (a material still naming the
     * texture reads its plain emissive factor). */
    dev->dirty = true;
    dev->light_tree_dirty = true;
    return SY_RT_OK;
}

void sy_rt_texture_free(sy_rt_texture_data *tex)
{
    if (!tex) return;
    free(tex->zero_sat);
    free(tex->pixels);
    free(tex);
}

/* Maps an integer texel coordinate into [0, n) by the wrap mode. */
static uint32_t wrap_index(int64_t i, uint32_t n, sy_rt_wrap mode)
{
    int64_t nn = (int64_t)n;
    switch (mode) {
    case SY_RT_WRAP_CLAMP:
        return (uint32_t)(i < 0 ? 0 : (i >= nn ? nn - 1 : i));
    case SY_RT_WRAP_MIRROR: {
        int64_t m = i % (2 * nn);
        if (m < 0) m += 2 * nn;
        return (uint32_t)(m < nn ? m : 2 * nn - 1 - m);
    }
    default: {
        int64_t m = i % nn;
        return (uint32_t)(m < 0 ? m + nn : m);
    }
    }
}

/* The wrapped index of i + 1 from w, the wrapped index of i: repeat and clamp without a second
 * division (bilinear taps are neighbours). */
static uint32_t wrap_next(int64_t i, uint32_t w, uint32_t n, sy_rt_wrap mode)
{
    if (mode == SY_RT_WRAP_REPEAT) return w + 1u == n ? 0u : w + 1u;
    if (mode == SY_RT_WRAP_CLAMP) return i + 1 < 0 ? 0u : (i + 1 >= (int64_t)n ? n - 1u : (uint32_t)(i + 1));
    return wrap_index(i + 1, n, mode);
}

static void fetch(const sy_rt_texture_data *t, uint32_t x, uint32_t y, float out[4])
{
    size_t base = ((size_t)y * t->width + x) * t->channels;
    if (t->format != SY_RT_TEXEL_FLOAT32 && t->channels >= 3) { /* RGB(A) 8-bit, the common case: no per-channel tests */
        const uint8_t *b = (const uint8_t *)t->pixels + base;
        const float *lut = t->srgb_lut;
        out[0] = lut ? lut[b[0]] : (float)b[0] * (1.0f / 255.0f);
        out[1] = lut ? lut[b[1]] : (float)b[1] * (1.0f / 255.0f);
        out[2] = lut ? lut[b[2]] : (float)b[2] * (1.0f / 255.0f);
        out[3] = t->channels == 4 ? (float)b[3] * (1.0f / 255.0f) : 1.0f; /* alpha is linear */
        return;
    }
    if (t->format == SY_RT_TEXEL_FLOAT32 && t->channels >= 3) { /* RGB(A) float: environments, HDR images */
        /* loads written out: the loop below, for floats a copy of `channels` values, is what GCC
         * turns into a memcpy call per texel (4 a bilinear sample) */
        const float *p = (const float *)t->pixels + base;
        out[0] = p[0], out[1] = p[1], out[2] = p[2];
        out[3] = t->channels == 4 ? p[3] : 1.0f;
        return;
    }
    float c[4] = {0.0f, 0.0f, 0.0f, 1.0f};
    for (uint32_t k = 0; k < t->channels; ++k) {
        if (t->format == SY_RT_TEXEL_FLOAT32) {
            c[k] = ((const float *)t->pixels)[base + k];
        } else {
            uint8_t b = ((const uint8_t *)t->pixels)[base + k];
            bool is_alpha = (t->channels == 2 && k == 1) || k == 3;
            c[k] = (t->srgb_lut && !is_alpha) ? t->srgb_lut[b] : (float)b * (1.0f / 255.0f);
        }
    }
    switch (t->channels) {
    case 1: out[0] = out[1] = out[2] = c[0]; out[3] = 1.0f; break;
    case 2: out[0] = out[1] = out[2] = c[0]; out[3] = c[1]; break;
    default: out[0] = c[0]; out[1] = c[1]; out[2] = c[2]; out[3] = c[3]; break;
    }
}

/* Texel-space coordinate, kept within a range where int64 conversion is exact and safe. */
static double texel_coord(float u, uint32_t n)
{
    if (!isfinite(u)) return 0.0;
    double x = (double)u * (double)n;
    if (x > 1e15) x = 1e15;
    if (x < -1e15) x = -1e15;
    return x;
}

void sy_rt_texture_sample(const sy_rt_texture_data *t, float u, float v, float out[4])
{
    double x = texel_coord(u, t->width), y = texel_coord(v, t->height);
    if (t->filter == SY_RT_FILTER_NEAREST) {
        fetch(t, wrap_index((int64_t)floor(x), t->width, t->wrap_s),
              wrap_index((int64_t)floor(y), t->height, t->wrap_t), out);
        return;
    }
    x -= 0.5; y -= 0.5; /* texel centres sit at half-integer coordinates */
    double fx0 = floor(x), fy0 = floor(y);
    float fx = (float)(x - fx0), fy = (float)(y - fy0);
    int64_t ix = (int64_t)fx0, iy = (int64_t)fy0;
    uint32_t x0 = wrap_index(ix, t->width, t->wrap_s), x1 = wrap_next(ix, x0, t->width, t->wrap_s);
    uint32_t y0 = wrap_index(iy, t->height, t->wrap_t), y1 = wrap_next(iy, y0, t->height, t->wrap_t);
    float a[4], b[4], c[4], d[4];
    fetch(t, x0, y0, a); fetch(t, x1, y0, b); fetch(t, x0, y1, c); fetch(t, x1, y1, d);
    for (int k = 0; k < 4; ++k) {
        float top = a[k] + (b[k] - a[k]) * fx;
        float bot = c[k] + (d[k] - c[k]) * fx;
        out[k] = top + (bot - top) * fy;
    }
}

void sy_rt_texture_ref_uv(const sy_rt_texture_ref *ref, const float uv[2][2], float out[2])
{
    const float *c = uv[ref->texcoord & 1u];
    if (!ref->transformed) {
        out[0] = c[0];
        out[1] = c[1];
        return;
    }
    const float *m = ref->transform;
    out[0] = m[0] * c[0] + m[1] * c[1] + m[2];
    out[1] = m[3] * c[0] + m[4] * c[1] + m[5];
}

/* >>regions that read only zero texels (the light tree leaves such emitter triangles out) */

/* Whether texel (x, y) has a non-zero colour channel (NaN counts as non-zero). */
static bool texel_nonzero(const sy_rt_texture_data *t, uint32_t x, uint32_t y)
{
    size_t base = ((size_t)y * t->width + x) * t->channels;
    uint32_t n = t->channels >= 3u ? 3u : 1u; /* grey(-alpha) textures: the grey channel */
    for (uint32_t k = 0; k < n; ++k) {
        if (t->format == SY_RT_TEXEL_FLOAT32) {
            if (!(((const float *)t->pixels)[base + k] == 0.0f)) return true;
        } else if (((const uint8_t *)t->pixels)[base + k] != 0u) { /* 0 decodes to 0 (sRGB too), any other code above */
            return true;
        }
    }
    return false;
}

static bool zero_table(sy_rt_texture_data *t)
{
    if (t->zero_sat) return true;
    if (t->zero_failed) return false;
    uint32_t s = 3u; /* 8 x 8 blocks, larger for textures past 4096 texels a side */
    while (((t->width - 1u) >> s) + 1u > 512u || ((t->height - 1u) >> s) + 1u > 512u) ++s;
    uint32_t bw = ((t->width - 1u) >> s) + 1u, bh = ((t->height - 1u) >> s) + 1u, stride = bw + 1u;
    uint32_t *sat = calloc((size_t)stride * (bh + 1u), sizeof *sat);
    if (!sat) {
        t->zero_failed = true;
        return false;
    }
    for (uint32_t y = 0; y < t->height; ++y) {
        uint32_t *row = sat + (size_t)((y >> s) + 1u) * stride + 1u;
        for (uint32_t x = 0; x < t->width; ++x)
            if (!row[x >> s] && texel_nonzero(t, x, y)) row[x >> s] = 1u;
    }
    for (uint32_t by = 1; by <= bh; ++by) /* prefix sums: sat[by][bx] = lit blocks above and left of (bx, by) */
        for (uint32_t bx = 1; bx <= bw; ++bx)
            sat[(size_t)by * stride + bx] += sat[(size_t)(by - 1u) * stride + bx] + sat[(size_t)by * stride + bx - 1u] -
                                             sat[(size_t)(by - 1u) * stride + bx - 1u];
    t->zero_sat = sat, t->zero_shift = s, t->zero_bw = bw, t->zero_bh = bh;
    return true;
}

/* The texel indices along one axis that lookups at texel coordinates in [lo, hi] can read (the
 * bilinear taps around them; nearest's texel is among them), as up to two ranges of [0, n):
 * the span is cut where the wrap mode's map turns (multiples of n), monotonic in each piece. */
static int axis_ranges(double lo, double hi, uint32_t n, sy_rt_wrap mode, uint32_t out[2][2])
{
    int64_t a = (int64_t)floor(lo - 0.5), b = (int64_t)floor(hi - 0.5) + 1;
    int64_t nn = (int64_t)n;
    if (b - a + 1 >= nn) {
        out[0][0] = 0, out[0][1] = n - 1u;
        return 1;
    }
    int64_t q = a >= 0 ? a / nn : -((-a + nn - 1) / nn); /* floor(a / n) */
    int64_t cut = (q + 1) * nn;
    int64_t piece[2][2] = {{a, b < cut - 1 ? b : cut - 1}, {cut, b}};
    int k = b >= cut ? 2 : 1;
    for (int i = 0; i < k; ++i) {
        uint32_t u = wrap_index(piece[i][0], n, mode), v = wrap_index(piece[i][1], n, mode);
        out[i][0] = u < v ? u : v, out[i][1] = u < v ? v : u;
    }
    return k;
}

bool sy_rt_texture_region_zero(sy_rt_texture_data *t, const float uv[3][2])
{
    float lo[2] = {uv[0][0], uv[0][1]}, hi[2] = {uv[0][0], uv[0][1]};
    for (int c = 0; c < 3; ++c)
        for (int k = 0; k < 2; ++k) {
            if (!isfinite(uv[c][k]) || fabsf(uv[c][k]) > 1e6f) return false;
            lo[k] = fminf(lo[k], uv[c][k]), hi[k] = fmaxf(hi[k], uv[c][k]);
        }
    if (!zero_table(t)) return false;
    /* a thousandth of a texel more each side: interpolated coordinates round past the corners' */
    uint32_t rx[2][2], ry[2][2];
    int nx = axis_ranges((double)lo[0] * t->width - 1e-3, (double)hi[0] * t->width + 1e-3, t->width, t->wrap_s, rx);
    int ny = axis_ranges((double)lo[1] * t->height - 1e-3, (double)hi[1] * t->height + 1e-3, t->height, t->wrap_t, ry);
    const uint32_t *sat = t->zero_sat, s = t->zero_shift, stride = t->zero_bw + 1u;
    for (int i = 0; i < nx; ++i)
        for (int j = 0; j < ny; ++j) {
            size_t x0 = rx[i][0] >> s, x1 = (rx[i][1] >> s) + 1u, y0 = ry[j][0] >> s, y1 = (ry[j][1] >> s) + 1u;
            uint32_t lit = sat[y1 * stride + x1] - sat[y0 * stride + x1] - sat[y1 * stride + x0] + sat[y0 * stride + x0];
            if (lit) return false;
        }
    return true;
}

bool sy_rt_texture_sample_set_ref(const sy_rt_device *dev, const sy_rt_texture_ref *ref, const float uv[2][2],
                                  float out[4])
{
    const sy_rt_texture_data *t = sy_rt_pool_get(&dev->textures, ref->texture.id);
    if (!t) return false;
    float c[2];
    sy_rt_texture_ref_uv(ref, uv, c);
    sy_rt_texture_sample(t, c[0], c[1], out);
    return true;
}
