/* sy_compose.c — command-line windows: overlay layers and stereo layouts (see sy_compose.h). */
#include "sy_compose.h"

#include <math.h>
#include <string.h>

sy_result sy_stereo_mode_parse(const char *s, uint32_t *out, sy_error *err)
{
    static const char *names[] = {"none", "sbs", "tb", "anaglyph", "separate"};
    for (uint32_t i = 0; i < sizeof names / sizeof names[0]; ++i)
        if (strcmp(s, names[i]) == 0) {
            *out = i;
            return SY_OK;
        }
    return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "--stereo %s: expected sbs, tb, anaglyph or separate", s);
}

sy_result sy_compose_validate(const sy_scene *scene, const sy_compose_spec *spec, sy_error *err)
{
    if (spec->stereo == SY_STEREO_NONE) return SY_OK;
    if (!(spec->eye_separation > 0.0f) || !isfinite(spec->eye_separation))
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "--eye-sep %g: must be a positive distance in metres",
                            (double)spec->eye_separation);
    if (!(spec->zero_parallax > 0.0f) || !isfinite(spec->zero_parallax))
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "--zero-parallax %g: must be a positive distance in metres",
                            (double)spec->zero_parallax);
    const sy_node_data *n = spec->camera.id ? sy_node_get(scene, spec->camera) : NULL;
    const sy_camera_data *c = n ? sy_camera_get(scene, n->camera) : NULL;
    if (c && c->zfar > 0.0f && spec->zero_parallax >= c->zfar)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                            "--zero-parallax %g: behind the camera's far plane (%g); choose a distance inside the view",
                            (double)spec->zero_parallax, (double)c->zfar);
    if (c && spec->zero_parallax <= c->znear)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "--zero-parallax %g: in front of the near plane (%g)",
                            (double)spec->zero_parallax, (double)c->znear);
    return SY_OK;
}

/* Adds the main (and overlay) viewport for one eye at (x, y) of size w x h. */
static sy_result add_eye(sy_window *win, const sy_compose_spec *spec, uint32_t eye, uint32_t x, uint32_t y,
                         uint32_t w, uint32_t h, sy_error *err)
{
    sy_viewport *vp;
    sy_viewport_desc d = {.x = x,
                          .y = y,
                          .width = w,
                          .height = h,
                          .root = spec->root,
                          .camera = spec->camera,
                          .background = spec->background,
                          .backend = spec->backend,
                          .params = spec->params,
                          .eye = eye,
                          .eye_separation = spec->eye_separation,
                          .zero_parallax = spec->zero_parallax,
                          .composite = SY_COMPOSITE_REPLACE};
    sy_result r = sy_window_add_viewport(win, &d, &vp, err);
    if (r == SY_OK) sy_viewport_set_view(vp, spec->view); /* NULL: the camera node's matrix */
    if (r == SY_OK && spec->clip_count)
        r = sy_viewport_set_clip_planes(vp, (const float(*)[4])spec->clip_planes, spec->clip_count, err);
    if (r == SY_OK && spec->clip_cap) r = sy_viewport_set_clip_cap(vp, spec->clip_cap_color, err);
    if (r != SY_OK || !spec->has_overlay) return r;
    d.root = spec->overlay_root;
    d.background.id = 0; /* transparent around the overlay's geometry */
    d.backend = spec->overlay_backend;
    d.params = spec->overlay_params;
    d.composite = spec->overlay_composite;
    r = sy_window_add_viewport(win, &d, &vp, err);
    if (r == SY_OK) sy_viewport_set_view(vp, spec->view);
    return r;
}

static sy_result render_window(sy_scene *scene, sy_context_pool *pool, const sy_compose_spec *spec, uint32_t eye,
                               uint32_t layout, uint32_t w, uint32_t h, const sy_window_render_opts *opts,
                               sy_layer *out, sy_error *err)
{
    uint32_t ww = layout == SY_STEREO_SBS ? 2 * w : w, wh = layout == SY_STEREO_TB ? 2 * h : h;
    sy_window *win = NULL;
    sy_result r = sy_window_create(ww, wh, &win, err);
    if (r == SY_OK) {
        if (layout == SY_STEREO_SBS || layout == SY_STEREO_TB) {
            r = add_eye(win, spec, SY_EYE_LEFT, 0, 0, w, h, err);
            if (r == SY_OK)
                r = add_eye(win, spec, SY_EYE_RIGHT, layout == SY_STEREO_SBS ? w : 0, layout == SY_STEREO_TB ? h : 0, w,
                            h, err);
        } else {
            r = add_eye(win, spec, eye, 0, 0, w, h, err);
        }
    }
    if (r == SY_OK) r = sy_layer_create(ww, wh, out, err);
    if (r == SY_OK) r = sy_window_render(win, scene, pool, opts, out, err);
    if (r != SY_OK) sy_layer_destroy(out);
    sy_window_destroy(win);
    return r;
}

sy_result sy_compose_render(sy_scene *scene, sy_context_pool *pool, const sy_compose_spec *spec, uint32_t w,
                            uint32_t h, const sy_window_render_opts *opts, sy_layer *out, sy_layer *out_right,
                            sy_error *err)
{
    memset(out, 0, sizeof *out);
    sy_result r = sy_compose_validate(scene, spec, err);
    if (r != SY_OK) return r;
    switch (spec->stereo) {
    case SY_STEREO_SBS:
    case SY_STEREO_TB: return render_window(scene, pool, spec, SY_EYE_MONO, spec->stereo, w, h, opts, out, err);
    case SY_STEREO_ANAGLYPH:
    case SY_STEREO_SEPARATE: {
        sy_layer left = {0}, right = {0};
        r = render_window(scene, pool, spec, SY_EYE_LEFT, SY_STEREO_NONE, w, h, opts, &left, err);
        if (r == SY_OK) r = render_window(scene, pool, spec, SY_EYE_RIGHT, SY_STEREO_NONE, w, h, opts, &right, err);
        if (r == SY_OK && spec->stereo == SY_STEREO_SEPARATE) {
            *out = left;
            *out_right = right;
            return SY_OK;
        }
        if (r == SY_OK) r = sy_layer_create(w, h, out, err);
        if (r == SY_OK) r = sy_layer_anaglyph(&left, &right, out, err);
        sy_layer_destroy(&left);
        sy_layer_destroy(&right);
        return r;
    }
    default: return render_window(scene, pool, spec, SY_EYE_MONO, SY_STEREO_NONE, w, h, opts, out, err);
    }
}

sy_result sy_compose_camera_view(const sy_scene *scene, const sy_compose_spec *spec, uint32_t w, uint32_t h,
                                 sy_camera_view *out, sy_error *err)
{
    return sy_compose_eye_view(scene, spec, SY_EYE_MONO, w, h, out, err);
}

sy_result sy_compose_eye_view(const sy_scene *scene, const sy_compose_spec *spec, uint32_t eye, uint32_t w, uint32_t h,
                              sy_camera_view *out, sy_error *err)
{
    sy_window *win = NULL;
    sy_compose_spec mono = *spec;
    mono.has_overlay = false;
    sy_result r = sy_window_create(w, h, &win, err);
    if (r == SY_OK) r = add_eye(win, &mono, eye, 0, 0, w, h, err);
    if (r == SY_OK) r = sy_viewport_camera_view(sy_window_viewport(win, 0), scene, w, h, out, err);
    sy_window_destroy(win);
    return r;
}
