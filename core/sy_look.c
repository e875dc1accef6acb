/* sy_look.c — the scene's look defined once (see sy_look.h): the resolution rules, the built-in
 * neutral studio environment and X3D sky/ground gradients baked into lat-long images. */
#include "sy_look.h"

#include <math.h>
#include <string.h>

#define PI_F 3.14159265358979f

void sy_look_resolve(const sy_look_inputs *in, sy_look *out)
{
    memset(out, 0, sizeof *out);
    const sy_background_data *w = in->world;
    out->env_intensity = 1.0f;
    if (w && w->environment.id && in->world_env_ready) {
        out->env = SY_LOOK_ENV_TEXTURE;
        out->env_texture = w->environment.id;
        out->env_intensity = w->intensity;
    }
    bool brings_light = in->light_count > 0 || in->emitter_count > 0 || out->env == SY_LOOK_ENV_TEXTURE;
    bool default_allowed = !w || w->default_lighting;
    if (!brings_light && default_allowed) {
        out->env = SY_LOOK_ENV_STUDIO;
        out->env_intensity = 1.0f;
        out->default_lighting = true;
    }
    out->background = SY_LOOK_BG_NONE;
    if (!w) return;
    if (out->env == SY_LOOK_ENV_TEXTURE && w->environment_visible) {
        out->background = SY_LOOK_BG_ENVIRONMENT;
    } else if (w->gradient.sky_count) {
        out->background = SY_LOOK_BG_GRADIENT;
        out->gradient = w->gradient;
    } else if (w->color[3] > 0.0f) {
        out->background = SY_LOOK_BG_COLOR;
        memcpy(out->bg_color, w->color, sizeof out->bg_color);
    }
}

bool sy_look_equal(const sy_look *a, const sy_look *b)
{
    if (a->env != b->env || a->env_texture != b->env_texture || a->env_intensity != b->env_intensity ||
        a->background != b->background || a->default_lighting != b->default_lighting)
        return false;
    if (a->background == SY_LOOK_BG_COLOR && memcmp(a->bg_color, b->bg_color, sizeof a->bg_color)) return false;
    if (a->background == SY_LOOK_BG_GRADIENT && memcmp(&a->gradient, &b->gradient, sizeof a->gradient)) return false;
    return true;
}

void sy_look_latlong_uv(const float d[3], float *u, float *v)
{
    float y = d[1] < -1.0f ? -1.0f : d[1] > 1.0f ? 1.0f : d[1];
    *u = 0.5f + atan2f(d[0], -d[2]) / (2.0f * PI_F);
    *v = acosf(y) / PI_F;
}

void sy_look_latlong_dir(float u, float v, float d[3])
{
    float phi = (u - 0.5f) * 2.0f * PI_F, theta = v * PI_F;
    float st = sinf(theta);
    d[0] = st * sinf(phi);
    d[1] = cosf(theta);
    d[2] = -st * cosf(phi);
}

static float smoothstep(float e0, float e1, float x)
{
    float t = (x - e0) / (e1 - e0);
    t = t < 0.0f ? 0.0f : t > 1.0f ? 1.0f : t;
    return t * t * (3.0f - 2.0f * t);
}

/* A soft box: a rectangle of angular half sizes (hu, hv) around direction c (unit) with soft
 * edges, radiance L inside. up is a reference vector not parallel to c. */
typedef struct softbox {
    float dir[3];
    float half_u, half_v, L;
} softbox;

static float softbox_weight(const softbox *b, const float d[3])
{
    float c[3], len = sqrtf(b->dir[0] * b->dir[0] + b->dir[1] * b->dir[1] + b->dir[2] * b->dir[2]);
    for (int k = 0; k < 3; ++k) c[k] = b->dir[k] / len;
    float cosang = c[0] * d[0] + c[1] * d[1] + c[2] * d[2];
    if (cosang <= 0.2f) return 0.0f;
    /* tangent frame: t = normalize(up x c) with up = +Y, s = c x t */
    float t[3] = {c[2], 0.0f, -c[0]}, tl = sqrtf(t[0] * t[0] + t[2] * t[2]);
    if (tl < 1e-6f) t[0] = 1.0f, t[2] = 0.0f, tl = 1.0f;
    t[0] /= tl, t[2] /= tl;
    float s[3] = {c[1] * t[2] - c[2] * t[1], c[2] * t[0] - c[0] * t[2], c[0] * t[1] - c[1] * t[0]};
    /* gnomonic projection onto the box plane */
    float x = (d[0] * t[0] + d[1] * t[1] + d[2] * t[2]) / cosang;
    float y = (d[0] * s[0] + d[1] * s[1] + d[2] * s[2]) / cosang;
    float fu = tanf(b->half_u), fv = tanf(b->half_v), soft = 0.35f;
    float wu = 1.0f - smoothstep(fu * (1.0f - soft), fu * (1.0f + soft), fabsf(x));
    float wv = 1.0f - smoothstep(fv * (1.0f - soft), fv * (1.0f + soft), fabsf(y));
    return wu * wv;
}

/* The studio: a grey dome, 0.8 at the zenith falling to 0.5 at the horizon, a floor-like 0.22
 * below it (blended over 6 degrees), and three soft boxes: a key light above front right (the
 * side a default camera looks from, +Z), a fill front left and a rim light above behind. Neutral
 * grey throughout, so materials keep their colour. */
void sy_look_studio_pixels(uint32_t width, uint32_t height, float *rgb)
{
    static const softbox boxes[3] = {
        {{0.55f, 0.75f, 0.65f}, 0.30f, 0.22f, 5.0f}, /* key */
        {{-0.75f, 0.35f, 0.55f}, 0.35f, 0.25f, 1.6f}, /* fill */
        {{-0.1f, 0.80f, -0.60f}, 0.40f, 0.18f, 2.5f}, /* rim */
    };
    for (uint32_t j = 0; j < height; ++j) {
        for (uint32_t i = 0; i < width; ++i) {
            float d[3];
            sy_look_latlong_dir(((float)i + 0.5f) / (float)width, ((float)j + 0.5f) / (float)height, d);
            float up = d[1];
            float sky = 0.5f + 0.3f * (up > 0.0f ? up : 0.0f);
            float ground = 0.22f;
            float blend = smoothstep(-0.05f, 0.05f, up);
            float L = ground + (sky - ground) * blend;
            for (int b = 0; b < 3; ++b) {
                float wgt = softbox_weight(&boxes[b], d);
                if (wgt > 0.0f) L += wgt * (boxes[b].L - L);
            }
            float *p = rgb + 3 * ((size_t)j * width + i);
            p[0] = p[1] = p[2] = L;
        }
    }
}

static void ramp(const float (*col)[3], const float *ang, uint32_t n, float a, float out[3])
{
    if (n == 1 || a <= 0.0f) {
        memcpy(out, col[0], 3 * sizeof(float));
        return;
    }
    float prev = 0.0f;
    for (uint32_t i = 0; i + 1 < n; ++i) {
        if (a <= ang[i]) {
            float t = ang[i] > prev ? (a - prev) / (ang[i] - prev) : 1.0f;
            for (int k = 0; k < 3; ++k) out[k] = col[i][k] + (col[i + 1][k] - col[i][k]) * t;
            return;
        }
        prev = ang[i];
    }
    memcpy(out, col[n - 1], 3 * sizeof(float));
}

void sy_look_gradient_eval(const sy_gradient *g, const float d[3], float rgb[3])
{
    if (!g->sky_count) {
        rgb[0] = rgb[1] = rgb[2] = 0.0f;
        return;
    }
    float y = d[1] < -1.0f ? -1.0f : d[1] > 1.0f ? 1.0f : d[1];
    float theta = acosf(y); /* from the zenith */
    if (g->ground_count && theta > 0.5f * PI_F) {
        float from_nadir = PI_F - theta;
        float reach = g->ground_count > 1 ? g->ground_angle[g->ground_count - 2] : 0.5f * PI_F;
        if (from_nadir <= reach + 1e-6f) {
            ramp(g->ground_color, g->ground_angle, g->ground_count, from_nadir, rgb);
            return;
        }
    }
    ramp(g->sky_color, g->sky_angle, g->sky_count, theta, rgb);
}

void sy_look_gradient_pixels(const sy_gradient *g, uint32_t width, uint32_t height, float *rgb)
{
    for (uint32_t j = 0; j < height; ++j) {
        float d[3];
        sy_look_latlong_dir(0.5f, ((float)j + 0.5f) / (float)height, d);
        float c[3];
        sy_look_gradient_eval(g, d, c);
        for (uint32_t i = 0; i < width; ++i) memcpy(rgb + 3 * ((size_t)j * width + i), c, sizeof c);
    }
}
