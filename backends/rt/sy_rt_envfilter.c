/* sy_rt_envfilter.c — the prefiltered environment (sy_rt_envfilter.h).
 *
 * The committed map is box-filtered to a base of at most 256 x 128 texels and a mip chain of 2 x 2
 * boxes below it. GGX level k (roughness r = k / 5, alpha = r^2) at 64 x 32 texels for r <= 0.4
 * and 32 x 16 above (those lobes span several such texels): per texel (direction N = V), 64
 * Hammersley half vectors from D, each reflected direction read at the mip whose texel matches its
 * sample's solid angle (Krivanek and Colbert's filtered importance sampling; trilinear), weighted
 * by n . l: the rasterizer's prefiltered cube (sy_gl_ibl.c), deterministic (fewer samples showed
 * as ripples on a rough sphere under a small bright source: rt_whitted's smoothness measure
 * 1.9e-3 with 64, 3.3e-3 with 32). Irradiance: 32 x 16 texels, each the cosine-weighted sum over a
 * 64 x 32 grid of directions read from the mip chain (texel solid angles). Cost: every texel of
 * the map read once, then about 0.4 million chain look-ups and 1 million products, once per
 * environment (tens of milliseconds on one core). */
#include "sy_rt_envfilter.h"
#include "sy_rt_texture.h"

#include <stdlib.h>
#include <string.h>

#define PI_F 3.14159265358979f

#define MAX_MIPS 12
#define N_SAMPLES 64u

typedef struct mip_chain {
    uint32_t n;
    sy_rt_envf_map m[MAX_MIPS];
} mip_chain;

static sy_rt_v3 uv_to_dir(float u, float v)
{
    float st;
    return sy_rt_latlong_dir(u, v, &st);
}

sy_rt_v3 sy_rt_envf_lookup_uv(const sy_rt_envf_map *m, float u, float v)
{
    float x = u * (float)m->w - 0.5f, y = sy_rt_clampf(v * (float)m->h - 0.5f, 0.0f, (float)m->h - 1.0f);
    float fx = floorf(x), fy = floorf(y);
    float tx = x - fx, ty = y - fy;
    int32_t x0 = (int32_t)fx, y0 = (int32_t)fy, w = (int32_t)m->w;
    if (x0 < 0 || x0 >= w) x0 = ((x0 % w) + w) % w; /* u in [0, 1]: only -1 and w get here */
    uint32_t xa = (uint32_t)x0, xb = xa + 1u < m->w ? xa + 1u : 0u;
    uint32_t ya = (uint32_t)y0, yb = ya + 1u < m->h ? ya + 1u : ya;
    const float *a = m->rgb + 3u * ((size_t)ya * m->w + xa), *b = m->rgb + 3u * ((size_t)ya * m->w + xb);
    const float *c = m->rgb + 3u * ((size_t)yb * m->w + xa), *e = m->rgb + 3u * ((size_t)yb * m->w + xb);
    float w00 = (1.0f - tx) * (1.0f - ty), w10 = tx * (1.0f - ty), w01 = (1.0f - tx) * ty, w11 = tx * ty;
    return v3(a[0] * w00 + b[0] * w10 + c[0] * w01 + e[0] * w11, a[1] * w00 + b[1] * w10 + c[1] * w01 + e[1] * w11,
              a[2] * w00 + b[2] * w10 + c[2] * w01 + e[2] * w11);
}

sy_rt_v3 sy_rt_envf_lookup(const sy_rt_envf_map *m, sy_rt_v3 d)
{
    float u, v;
    sy_rt_latlong_uv(d, &u, &v);
    return sy_rt_envf_lookup_uv(m, u, v);
}

static bool map_alloc(sy_rt_envf_map *m, uint32_t w, uint32_t h, size_t *bytes)
{
    m->w = w;
    m->h = h;
    m->rgb = calloc((size_t)w * h * 3u, sizeof *m->rgb);
    *bytes += (size_t)w * h * 3u * sizeof *m->rgb;
    return m->rgb != NULL;
}

static void chain_free(mip_chain *c)
{
    for (uint32_t i = 0; i < c->n; ++i) free(c->m[i].rgb);
    c->n = 0;
}

/* The base (box filter of the texture's texels) and its mips. */
static bool chain_build(const sy_rt_texture_data *t, mip_chain *c)
{
    size_t bytes = 0;
    uint32_t w = t->width, h = t->height;
    uint32_t bw = w < 256u ? w : 256u, bh = h < 128u ? h : 128u;
    if (bw < 1u) bw = 1u;
    if (bh < 1u) bh = 1u;
    c->n = 0;
    if (!map_alloc(&c->m[0], bw, bh, &bytes)) return false;
    c->n = 1;
    float *cnt = calloc((size_t)bw * bh, sizeof *cnt);
    if (!cnt) return false;
    for (uint32_t y = 0; y < h; ++y) {
        uint32_t by = (uint32_t)((uint64_t)y * bh / h);
        for (uint32_t x = 0; x < w; ++x) {
            float s[4];
            sy_rt_texture_sample(t, ((float)x + 0.5f) / (float)w, ((float)y + 0.5f) / (float)h, s);
            if (!(isfinite(s[0]) && isfinite(s[1]) && isfinite(s[2]))) continue;
            size_t o = (size_t)by * bw + (uint32_t)((uint64_t)x * bw / w);
            float *p = c->m[0].rgb + 3u * o;
            p[0] += fmaxf(s[0], 0.0f), p[1] += fmaxf(s[1], 0.0f), p[2] += fmaxf(s[2], 0.0f);
            cnt[o] += 1.0f;
        }
    }
    for (size_t i = 0; i < (size_t)bw * bh; ++i)
        if (cnt[i] > 0.0f)
            for (int k = 0; k < 3; ++k) c->m[0].rgb[3u * i + k] /= cnt[i];
    free(cnt);
    while (c->n < MAX_MIPS && (c->m[c->n - 1u].w > 4u || c->m[c->n - 1u].h > 2u)) {
        const sy_rt_envf_map *s = &c->m[c->n - 1u];
        uint32_t nw = s->w > 1u ? s->w / 2u : 1u, nh = s->h > 1u ? s->h / 2u : 1u;
        sy_rt_envf_map *d = &c->m[c->n];
        if (!map_alloc(d, nw, nh, &bytes)) return false;
        c->n++;
        for (uint32_t y = 0; y < nh; ++y)
            for (uint32_t x = 0; x < nw; ++x) {
                uint32_t x0 = x * s->w / nw, x1 = (x + 1u) * s->w / nw, y0 = y * s->h / nh, y1 = (y + 1u) * s->h / nh;
                float acc[3] = {0, 0, 0}, n = 0.0f;
                for (uint32_t yy = y0; yy < y1; ++yy)
                    for (uint32_t xx = x0; xx < x1; ++xx, n += 1.0f)
                        for (int k = 0; k < 3; ++k) acc[k] += s->rgb[3u * ((size_t)yy * s->w + xx) + k];
                for (int k = 0; k < 3; ++k) d->rgb[3u * ((size_t)y * nw + x) + k] = n > 0.0f ? acc[k] / n : 0.0f;
            }
    }
    return true;
}

static float radinv(uint32_t b)
{
    b = (b << 16u) | (b >> 16u);
    b = ((b & 0x55555555u) << 1u) | ((b & 0xAAAAAAAAu) >> 1u);
    b = ((b & 0x33333333u) << 2u) | ((b & 0xCCCCCCCCu) >> 2u);
    b = ((b & 0x0F0F0F0Fu) << 4u) | ((b & 0xF0F0F0F0u) >> 4u);
    b = ((b & 0x00FF00FFu) << 8u) | ((b & 0xFF00FF00u) >> 8u);
    return (float)b * 2.3283064365386963e-10f;
}

/* The chain read trilinearly at fractional level lod. */
static sy_rt_v3 chain_lookup(const mip_chain *c, sy_rt_v3 d, float lod)
{
    float top = (float)(c->n - 1u);
    lod = sy_rt_clampf(lod, 0.0f, top);
    uint32_t l0 = (uint32_t)lod;
    float t = lod - (float)l0;
    float u, v;
    sy_rt_latlong_uv(d, &u, &v);
    sy_rt_v3 a = sy_rt_envf_lookup_uv(&c->m[l0], u, v);
    if (t <= 0.0f || l0 + 1u >= c->n) return a;
    return v3_add(v3_scale(a, 1.0f - t), v3_scale(sy_rt_envf_lookup_uv(&c->m[l0 + 1u], u, v), t));
}

static void prefilter_ggx(const mip_chain *c, float rough, uint32_t ns, sy_rt_envf_map *out)
{
    float a = rough * rough, a2 = a * a;
    const sy_rt_envf_map *base = &c->m[0];
    float texel0 = (2.0f * PI_F / (float)base->w) * (PI_F / (float)base->h);
#pragma omp parallel for schedule(dynamic, 1)
    for (int32_t y = 0; y < (int32_t)out->h; ++y) {
        for (uint32_t x = 0; x < out->w; ++x) {
            sy_rt_v3 n = uv_to_dir(((float)x + 0.5f) / (float)out->w, ((float)y + 0.5f) / (float)out->h);
            sy_rt_v3 up = fabsf(n.y) < 0.999f ? v3(0.0f, 1.0f, 0.0f) : v3(1.0f, 0.0f, 0.0f);
            sy_rt_v3 tx = v3_normalize(v3_cross(up, n)), ty = v3_cross(n, tx);
            sy_rt_v3 acc = v3(0.0f, 0.0f, 0.0f);
            float wsum = 0.0f;
            for (uint32_t i = 0; i < ns; ++i) {
                float u1 = ((float)i + 0.5f) / (float)ns, u2 = radinv(i);
                float phi = 2.0f * PI_F * u1;
                float ct = sqrtf((1.0f - u2) / (1.0f + (a2 - 1.0f) * u2)), st = sqrtf(fmaxf(0.0f, 1.0f - ct * ct));
                sy_rt_v3 h = v3_add(v3_add(v3_scale(tx, st * cosf(phi)), v3_scale(ty, st * sinf(phi))), v3_scale(n, ct));
                float nh = ct;
                sy_rt_v3 l = v3_sub(v3_scale(h, 2.0f * nh), n);
                float nl = v3_dot(n, l);
                if (nl <= 0.0f) continue;
                float dd = (nh * nh) * (a2 - 1.0f) + 1.0f;
                float D = a2 / (PI_F * dd * dd);
                float pdf = D * 0.25f; /* D nh / (4 vh) with v = n */
                float sa = 1.0f / ((float)ns * fmaxf(pdf, 1e-8f));
                float texel = texel0 * fmaxf(sqrtf(fmaxf(0.0f, 1.0f - l.y * l.y)), 1e-3f);
                float lod = fmaxf(0.5f * log2f(sa / texel) + 1.0f, 0.0f);
                acc = v3_add(acc, v3_scale(chain_lookup(c, l, lod), nl));
                wsum += nl;
            }
            float *p = out->rgb + 3u * ((size_t)y * out->w + x);
            sy_rt_v3 r = wsum > 0.0f ? v3_scale(acc, 1.0f / wsum) : v3(0.0f, 0.0f, 0.0f);
            p[0] = r.x, p[1] = r.y, p[2] = r.z;
        }
    }
}

/* Cosine convolution / pi over a 64 x 32 grid of directions (exact texel solid angles), each read
 * bilinearly from the mip closest to that grid (so a map smaller than the grid is read smoothly). */
static bool irradiance(const mip_chain *c, sy_rt_envf_map *out)
{
    enum { GW = 64, GH = 32 };
    uint32_t li = 0;
    while (li + 1u < c->n && c->m[li + 1u].w >= GW) li++;
    float *grid = malloc((size_t)GW * GH * 7u * sizeof *grid); /* direction, radiance x solid angle */
    if (!grid) return false;
    for (uint32_t y = 0; y < GH; ++y) {
        float v0 = (float)y / GH, v1 = (float)(y + 1u) / GH;
        float dom = (cosf(v0 * PI_F) - cosf(v1 * PI_F)) * (2.0f * PI_F / GW);
        for (uint32_t x = 0; x < GW; ++x) {
            sy_rt_v3 l = uv_to_dir(((float)x + 0.5f) / GW, ((float)y + 0.5f) / GH);
            sy_rt_v3 r = v3_scale(sy_rt_envf_lookup(&c->m[li], l), dom);
            float *g = grid + 7u * (y * GW + x);
            g[0] = l.x, g[1] = l.y, g[2] = l.z, g[3] = r.x, g[4] = r.y, g[5] = r.z;
        }
    }
#pragma omp parallel for schedule(dynamic, 1)
    for (int32_t y = 0; y < (int32_t)out->h; ++y) {
        for (uint32_t x = 0; x < out->w; ++x) {
            sy_rt_v3 n = uv_to_dir(((float)x + 0.5f) / (float)out->w, ((float)y + 0.5f) / (float)out->h);
            double acc[3] = {0, 0, 0};
            for (uint32_t i = 0; i < (uint32_t)(GW * GH); ++i) {
                const float *g = grid + 7u * i;
                float cs = n.x * g[0] + n.y * g[1] + n.z * g[2];
                if (cs <= 0.0f) continue;
                for (int k = 0; k < 3; ++k) acc[k] += (double)(g[3 + k] * cs);
            }
            float *o = out->rgb + 3u * ((size_t)y * out->w + x);
            for (int k = 0; k < 3; ++k) o[k] = (float)(acc[k] / (double)PI_F);
        }
    }
    free(grid);
    return true;
}

void sy_rt_envfilter_free(sy_rt_envfilter *f)
{
    if (!f) return;
    for (int i = 0; i < SY_RT_ENVF_LEVELS; ++i) free(f->spec[i].rgb);
    free(f->irr.rgb);
    free(f);
}

sy_rt_result sy_rt_envfilter_ensure(sy_rt_device *dev)
{
    if (dev->env_filter || !dev->env_dist) return SY_RT_OK;
    const sy_rt_texture_data *t = sy_rt_pool_get(&dev->textures, dev->env_texture.id);
    if (!t) return SY_RT_OK;
    sy_rt_envfilter *f = calloc(1, sizeof *f);
    mip_chain c;
    memset(&c, 0, sizeof c);
    bool ok = f && chain_build(t, &c);
    for (int k = 1; ok && k < SY_RT_ENVF_LEVELS; ++k) {
        uint32_t w = k <= 2 ? 64u : 32u; /* the lobes of roughness >= 0.6 span more than 2 texels of 32 x 16 */
        uint32_t h = w / 2u ? w / 2u : 1u;
        ok = map_alloc(&f->spec[k], w, h, &f->bytes);
        if (ok) prefilter_ggx(&c, (float)k / (float)(SY_RT_ENVF_LEVELS - 1), N_SAMPLES, &f->spec[k]);
    }
    if (ok) ok = map_alloc(&f->irr, 32u, 16u, &f->bytes);
    if (ok) ok = irradiance(&c, &f->irr);
    chain_free(&c);
    if (!ok) {
        sy_rt_envfilter_free(f);
        return sy_rt_fail(dev, SY_RT_ERROR_OUT_OF_MEMORY, "render: prefiltered environment: out of memory");
    }
    dev->env_filter = f;
    return SY_RT_OK;
}
