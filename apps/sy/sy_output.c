/* sy_output.c — images that sy writes (.exr, .png, .jpg; sy_output.h), the terminal's progress line
 * of a tiled render, and one mono render of a whole window (sy demo). */
#include "sy_output.h"
#include "sy_cli.h"

#include "sy_jpeg.h"
#include "sy_testpoint.h"

#include <stdio.h>
#include <string.h>
#include <strings.h>

#define JPEG_QUALITY 92

/* >>progress (terminal only) */
void sy_cli_progress_cb(void *user, const sy_progress *p)
{
    progress_state *ps = user;
    if (!ps->announced && p->done < p->total) { /* a render is in progress (tests wait for it) */
        ps->announced = true;
        sy_testpoint("tiles");
    }
    if (!ps->tty || p->total == 0) return;
    double now = sy_time_now();
    if (p->done != p->total && now - ps->last_print < 0.1) return;
    ps->last_print = now;
    double el = now - ps->start, frac = (double)p->done / (double)p->total;
    double eta = frac > 0 ? el / frac - el : 0;
    fprintf(stderr, "\r%s: %llu/%llu tiles (%3.0f%%) %.1f s, ETA %.1f s   ", ps->label, (unsigned long long)p->done,
            (unsigned long long)p->total, frac * 100.0, el, eta);
    if (p->done == p->total) fprintf(stderr, "\r%*s\r", 70, "");
    fflush(stderr);
}

void sy_cli_out_metadata(out_opts *o, const char *(*kv)[2], size_t n, sy_exr_attribute *attrs, sy_png_text *texts)
{
    o->attr_count = 0;
    for (size_t k = 0; k < n; ++k) {
        if (!kv[k][1] || !kv[k][1][0]) continue;
        attrs[o->attr_count] = (sy_exr_attribute){kv[k][0], kv[k][1]};
        texts[o->attr_count] = (sy_png_text){kv[k][0], kv[k][1]};
        o->attr_count++;
    }
    o->attrs = attrs;
    o->png.text = texts;
    o->png.text_count = o->attr_count;
}

bool sy_cli_is_output_path(const char *path)
{
    return sy_cli_ends_with(path, ".exr") || sy_cli_ends_with(path, ".png") || sy_cli_ends_with(path, ".jpg") || sy_cli_ends_with(path, ".jpeg");
}

sy_result sy_cli_write_image(const char *path, const sy_layer *l, const out_opts *o, sy_error *err)
{
    if (sy_cli_ends_with(path, ".exr"))
        return sy_exr_write_rgba_attrs(path, (int)l->width, (int)l->height, l->rgba, l->depth,
                                       o->half ? SY_EXR_PIXEL_HALF : SY_EXR_PIXEL_FLOAT, o->attrs, o->attr_count, err);
    if (sy_cli_ends_with(path, ".png")) return sy_png_write(path, (int)l->width, (int)l->height, l->rgba, &o->png, err);
    if (sy_cli_ends_with(path, ".jpg") || sy_cli_ends_with(path, ".jpeg"))
        return sy_jpeg_write(path, (int)l->width, (int)l->height, l->rgba, &o->png, JPEG_QUALITY, err);
    return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: output must end in " OUTPUT_KINDS, path);
}

/* Renders one mono viewport of the whole window with the given back-end. */
/* Renders one mono viewport of the whole window with the given back-end; samples: samples per
 * pixel for a progressive back-end (0 = its default pass). */
sy_result sy_cli_render_scene(loaded *ld, const char *backend, const char *params, uint32_t w, uint32_t h,
                              uint32_t samples, sy_context_pool *pool, sy_layer *out, double *seconds, sy_error *err)
{
    sy_window *win = NULL;
    sy_viewport *vp;
    sy_result r = sy_window_create(w, h, &win, err);
    sy_viewport_desc vd = {
        .root = ld->root, .camera = ld->camera, .background = ld->background, .backend = backend, .params = params};
    if (r == SY_OK) r = sy_window_add_viewport(win, &vd, &vp, err);
    if (r == SY_OK) r = sy_layer_create(w, h, out, err);
    progress_state ps = {backend, sy_time_now(), 0, sy_is_terminal(2), false};
    sy_window_render_opts ro = {.progress = sy_cli_progress_cb, .progress_user = &ps, .sample_count = samples};
    double t0 = sy_time_now();
    if (r == SY_OK) r = sy_window_render(win, ld->scene, pool, &ro, out, err);
    *seconds = sy_time_now() - t0;
    sy_window_destroy(win);
    return r;
}
