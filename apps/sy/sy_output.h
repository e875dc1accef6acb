/* sy_output.h — the images sy writes (sy_output.c): .exr (float or half, with header attributes),
 * .png and .jpg (tone mapped, with text chunks), chosen by the name's extension; the progress line
 * of a tiled render on a terminal; one mono render of a whole window. */
#ifndef SY_OUTPUT_H
#define SY_OUTPUT_H

#include "sy_exr.h"
#include "sy_load.h"
#include "sy_png.h"
#include "sy_viewport.h"

typedef struct out_opts {
    bool half;
    sy_png_options png;
    const sy_exr_attribute *attrs; /* extra EXR header attributes (sy:samples, sy:interrupted, ...) */
    int attr_count;
} out_opts;

#define OUTPUT_KINDS ".exr, .png, .jpg or .jpeg"

/* The pairs kv[0..n-1] {key, value} as o's EXR header attributes and PNG text chunks, stored in attrs
 * and texts (room for n each, the caller's; a pair without a value is left out). */
void sy_cli_out_metadata(out_opts *o, const char *(*kv)[2], size_t n, sy_exr_attribute *attrs, sy_png_text *texts);
/* path ends in one of OUTPUT_KINDS */
bool sy_cli_is_output_path(const char *path);
/* Writes l to path in the format its extension names. */
sy_result sy_cli_write_image(const char *path, const sy_layer *l, const out_opts *o, sy_error *err);

/* The progress of a tiled render (sy_window_render_opts.progress, user: a progress_state): a line
 * on stderr when it is a terminal (tty); announces the "tiles" phase (sy_testpoint.h) once. */
typedef struct progress_state {
    const char *label;
    double start, last_print;
    bool tty;
    bool announced; /* the "tiles" phase (sy_testpoint.h) was announced for this render */
} progress_state;
void sy_cli_progress_cb(void *user, const sy_progress *p);

/* Renders one mono viewport of the whole window with the given back-end; samples: samples per
 * pixel for a progressive back-end (0 = its default pass). */
sy_result sy_cli_render_scene(loaded *ld, const char *backend, const char *params, uint32_t w, uint32_t h,
                              uint32_t samples, sy_context_pool *pool, sy_layer *out, double *seconds, sy_error *err);

#endif /* SY_OUTPUT_H */
