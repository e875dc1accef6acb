/* sy_compare.h — `sy compare SCENE`: renders one view of a scene with every picture back-end,
 * writes a labelled contact sheet (PNG, one tile per back-end, side by side) and prints a table:
 * render time, covered pixels, mean luminance over covered pixels, its ratio to the progressive
 * (path tracing) back-end and the coverage IoU against it. The tool to look at before saying an
 * image is right (README). Statistics come from core (sy_stats.h); labels are drawn with FreeType.
 *
 * Ownership: the caller owns the scene and the pool. Thread-safety: single-threaded. */
#ifndef SY_COMPARE_H
#define SY_COMPARE_H

#include "sy_viewport.h"

#include <stdio.h>

typedef struct sy_compare_opts {
    uint32_t width, height;
    uint32_t spp;           /* samples per pixel for progressive back-ends (0 = 256) */
    const char *sheet_path; /* PNG contact sheet; NULL = none */
    const char *title;      /* shown above the tiles (e.g. the scene file), may be NULL */
    const char *only;       /* comma-separated back-end names to render (NULL = every picture back-end) */
} sy_compare_opts;

/* One row of the table. */
typedef struct sy_compare_row {
    const char *backend; /* static storage (the mediator class's name) */
    double seconds, mean_luminance, ratio, iou; /* ratio and iou against the reference; 0 when none */
    double covered;      /* fraction of the image */
} sy_compare_row;

/* Renders vd (its backend field is ignored) with each back-end into rows (at most max_rows; *count
 * set) and prints the table to out (NULL = quiet). */
sy_result sy_compare_run(sy_scene *scene, const sy_viewport_desc *vd, const sy_compare_opts *o, sy_context_pool *pool,
                         FILE *out, sy_compare_row *rows, uint32_t max_rows, uint32_t *count, sy_error *err);

#endif /* SY_COMPARE_H */
