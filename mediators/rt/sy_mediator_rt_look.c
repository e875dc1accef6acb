/* sy_mediator_rt_look.c — the resolved look (sy_look.h) of a request's world on the
 * Embree device: background, environment, the studio and gradient textures
 * (sy_mediator_rt_internal.h). */
#include "sy_mediator_rt_internal.h"

#include <stdlib.h>
#include <string.h>

/* >>look: the resolved look (sy_look.h) of the request's world, applied to the device when it (or
 * the back-end texture it resolves to) changed. The device's commit bumps its version, so
 * progressive accumulations restart. */
#define GRADIENT_W 4u
#define GRADIENT_H 256u

static sy_result studio_texture(rt_state *st, uint32_t *handle, sy_error *err)
{
    if (!st->studio.id) {
        const size_t n = (size_t)SY_LOOK_STUDIO_WIDTH * SY_LOOK_STUDIO_HEIGHT * 3u;
        float *px = malloc(n * sizeof *px);
        if (!px) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "studio environment: out of memory");
        sy_look_studio_pixels(SY_LOOK_STUDIO_WIDTH, SY_LOOK_STUDIO_HEIGHT, px);
        sy_rt_texture_desc d = {.width = SY_LOOK_STUDIO_WIDTH, .height = SY_LOOK_STUDIO_HEIGHT, .channels = 3,
                                .format = SY_RT_TEXEL_FLOAT32, .pixels = px, .wrap_s = SY_RT_WRAP_REPEAT,
                                .wrap_t = SY_RT_WRAP_CLAMP, .filter = SY_RT_FILTER_LINEAR};
        sy_rt_result r = sy_rt_texture_create(st->dev, &d, &st->studio);
        free(px);
        if (r != SY_RT_OK) return sy_rti_fail(st, err, r, "studio environment");
    }
    *handle = st->studio.id;
    return SY_OK;
}

static sy_result gradient_texture(rt_state *st, const sy_gradient *g, uint32_t *handle, sy_error *err)
{
    if (!st->gradient.id || memcmp(&st->gradient_baked, g, sizeof *g)) {
        float *px = malloc((size_t)GRADIENT_W * GRADIENT_H * 3u * sizeof *px);
        if (!px) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "background gradient: out of memory");
        sy_look_gradient_pixels(g, GRADIENT_W, GRADIENT_H, px);
        sy_rt_texture_desc d = {.width = GRADIENT_W, .height = GRADIENT_H, .channels = 3, .format = SY_RT_TEXEL_FLOAT32,
                                .pixels = px, .wrap_s = SY_RT_WRAP_REPEAT, .wrap_t = SY_RT_WRAP_CLAMP,
                                .filter = SY_RT_FILTER_LINEAR};
        sy_rt_texture t = {0};
        sy_rt_result r = sy_rt_texture_create(st->dev, &d, &t);
        free(px);
        if (r != SY_RT_OK) return sy_rti_fail(st, err, r, "background gradient");
        /* the device's background still names the old one until the look is applied (it stays
         * valid: a destroyed background texture draws black, and the new look replaces it now) */
        if (st->gradient.id) sy_rt_texture_destroy(st->dev, st->gradient);
        st->gradient = t;
        st->gradient_baked = *g;
    }
    *handle = st->gradient.id;
    return SY_OK;
}

sy_result sy_rti_apply_look(rt_state *st, uint32_t background_id, sy_error *err)
{
    sy_look look;
    sy_mirror_look(st->mirror, background_id, &look);
    uint32_t env_tex = 0, bg_tex = 0;
    sy_result r = SY_OK;
    if (look.env == SY_LOOK_ENV_TEXTURE) env_tex = sy_mirror_texture_handle(st->mirror, look.env_texture);
    else if (look.env == SY_LOOK_ENV_STUDIO) r = studio_texture(st, &env_tex, err);
    if (r != SY_OK) return r;
    if (look.background == SY_LOOK_BG_ENVIRONMENT) bg_tex = env_tex;
    else if (look.background == SY_LOOK_BG_GRADIENT && (r = gradient_texture(st, &look.gradient, &bg_tex, err)) != SY_OK)
        return r;
    if (st->look_applied && sy_look_equal(&st->look, &look) && st->look_env_tex == env_tex && st->look_bg_tex == bg_tex)
        return SY_OK;
    sy_rt_background bg = {.mode = SY_RT_BACKGROUND_NONE};
    if (look.background == SY_LOOK_BG_COLOR) {
        /* premultiplied; the device's colour background is opaque (alpha 1) */
        bg.mode = SY_RT_BACKGROUND_COLOR;
        memcpy(bg.color, look.bg_color, sizeof bg.color);
    } else if (bg_tex) {
        bg.mode = SY_RT_BACKGROUND_TEXTURE;
        bg.texture.id = bg_tex;
        bg.intensity = look.background == SY_LOOK_BG_ENVIRONMENT ? look.env_intensity : 1.0f;
    }
    sy_rt_result rr = sy_rt_set_background(st->dev, &bg);
    if (rr == SY_RT_OK) rr = sy_rt_set_environment(st->dev, (sy_rt_texture){env_tex}, look.env_intensity);
    if (rr == SY_RT_OK) rr = sy_rt_commit(st->dev);
    if (rr != SY_RT_OK) {
        st->look_applied = false;
        return sy_rti_fail(st, err, rr, "look (background, environment)");
    }
    st->look = look;
    st->look_env_tex = env_tex;
    st->look_bg_tex = bg_tex;
    st->look_applied = true;
    return SY_OK;
}
