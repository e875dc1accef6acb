/* sy_compare.c — renders every picture back-end side by side (see sy_compare.h). */
#include "sy_compare.h"

#include "sy_log.h"
#include "sy_png.h"
#include "sy_stats.h"

#include <ft2build.h>
#include FT_FREETYPE_H

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define LABEL_H 34u
#define SY_COMPARE_FONT "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf"

/* Draws text into a linear RGBA image at (x, baseline y) in the given radiance (the sheet is tone
 * mapped afterwards). */
static void draw_text(FT_Face face, float *rgba, uint32_t W, uint32_t H, int x, int y, const char *text, float value)
{
    for (const unsigned char *c = (const unsigned char *)text; *c; ++c) {
        if (FT_Load_Char(face, *c, FT_LOAD_RENDER)) continue;
        FT_GlyphSlot g = face->glyph;
        for (unsigned r = 0; r < g->bitmap.rows; ++r)
            for (unsigned q = 0; q < g->bitmap.width; ++q) {
                int px = x + g->bitmap_left + (int)q, py = y - g->bitmap_top + (int)r;
                if (px < 0 || py < 0 || (uint32_t)px >= W || (uint32_t)py >= H) continue;
                float a = g->bitmap.buffer[r * (unsigned)g->bitmap.pitch + q] / 255.0f;
                float *p = rgba + 4 * ((size_t)py * W + (size_t)px);
                for (int k = 0; k < 3; ++k) p[k] = p[k] * (1.0f - a) + value * a;
                p[3] = 1.0f;
            }
        x += (int)(g->advance.x >> 6);
    }
}

static bool wanted(const char *only, const char *name) { return !only || sy_name_in_list(name, only, ','); }

static sy_result render_one(sy_scene *scene, const sy_viewport_desc *vd, const char *backend, uint32_t w, uint32_t h,
                            uint32_t spp, sy_context_pool *pool, sy_layer *out, double *secs, sy_error *err)
{
    sy_window *win = NULL;
    sy_viewport *vp;
    sy_viewport_desc d = *vd;
    d.backend = backend;
    sy_result r = sy_window_create(w, h, &win, err);
    if (r == SY_OK) r = sy_window_add_viewport(win, &d, &vp, err);
    if (r == SY_OK) r = sy_layer_create(w, h, out, err);
    sy_window_render_opts ro = {.sample_count = spp};
    double t0 = sy_time_now();
    if (r == SY_OK) r = sy_window_render(win, scene, pool, &ro, out, err);
    *secs = sy_time_now() - t0;
    sy_window_destroy(win);
    return r;
}

sy_result sy_compare_run(sy_scene *scene, const sy_viewport_desc *vd, const sy_compare_opts *o, sy_context_pool *pool,
                         FILE *out, sy_compare_row *rows, uint32_t max_rows, uint32_t *count, sy_error *err)
{
    uint32_t w = o->width, h = o->height, spp = o->spp ? o->spp : 256;
    uint32_t n = 0, ref = UINT32_MAX;
    sy_layer layers[16];
    memset(layers, 0, sizeof layers);
    sy_result r = SY_OK;
    if (max_rows > 16) max_rows = 16;
    for (uint32_t i = 0; i < sy_mediator_count() && r == SY_OK; ++i) {
        const sy_mediator_class *mc = sy_mediator_at(i);
        if ((mc->caps & SY_CAP_ANALYSIS) || !wanted(o->only, mc->name)) continue;
        if (n == max_rows) break;
        double secs = 0;
        uint32_t samples = (mc->caps & SY_CAP_PROGRESSIVE) ? spp : 0;
        r = render_one(scene, vd, mc->name, w, h, samples, pool, &layers[n], &secs, err);
        if (r != SY_OK) {
            sy_error_prefix(err, "%s", mc->name);
            break;
        }
        sy_layer_stats st;
        sy_layer_stats_get(&layers[n], &st);
        rows[n] = (sy_compare_row){.backend = mc->name, .seconds = secs, .mean_luminance = st.mean_luminance,
                                   .covered = st.pixels ? (double)st.covered / (double)st.pixels : 0.0};
        if (ref == UINT32_MAX && (mc->caps & SY_CAP_PROGRESSIVE)) ref = n;
        ++n;
    }
    *count = n;
    for (uint32_t i = 0; i < n && r == SY_OK && ref != UINT32_MAX; ++i) {
        rows[i].ratio = rows[ref].mean_luminance > 0 ? rows[i].mean_luminance / rows[ref].mean_luminance : 0.0;
        r = sy_layer_coverage_iou(&layers[i], &layers[ref], &rows[i].iou, err);
    }
    if (r == SY_OK && out) {
        fprintf(out, "%-12s %9s %8s %10s %8s %8s\n", "backend", "seconds", "covered", "mean_lum", "ratio", "iou");
        for (uint32_t i = 0; i < n; ++i)
            fprintf(out, "%-12s %9.3f %7.1f%% %10.4f %8.3f %8.4f\n", rows[i].backend, rows[i].seconds,
                    100.0 * rows[i].covered, rows[i].mean_luminance, rows[i].ratio, rows[i].iou);
        if (ref == UINT32_MAX) fprintf(out, "(no progressive back-end: ratios and IoU left out)\n");
        else fprintf(out, "ratio and iou against %s (%u samples per pixel)\n", rows[ref].backend, spp);
    }
    if (r == SY_OK && o->sheet_path && n) {
        uint32_t gap = 4, top = o->title ? LABEL_H : 0;
        uint32_t W = n * w + (n - 1) * gap, H = top + LABEL_H + h;
        float *img = calloc((size_t)W * H * 4, sizeof *img);
        if (!img) r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "contact sheet: out of memory");
        for (size_t i = 0; img && i < (size_t)W * H; ++i) img[4 * i + 0] = img[4 * i + 1] = img[4 * i + 2] = 0.02f, img[4 * i + 3] = 1.0f;
        for (uint32_t t = 0; img && t < n; ++t)
            for (uint32_t y = 0; y < h; ++y)
                for (uint32_t x = 0; x < w; ++x) {
                    const float *s = layers[t].rgba + 4 * ((size_t)y * w + x);
                    float *d = img + 4 * ((size_t)(top + LABEL_H + y) * W + t * (w + gap) + x);
                    /* transparent background shows as a dark checkerboard, so coverage is visible */
                    float bgv = (((x / 8) + (y / 8)) & 1) ? 0.06f : 0.03f;
                    for (int k = 0; k < 3; ++k) d[k] = s[k] + bgv * (1.0f - s[3]);
                    d[3] = 1.0f;
                }
        FT_Library ft = NULL;
        FT_Face face = NULL;
        if (img && (FT_Init_FreeType(&ft) || FT_New_Face(ft, SY_COMPARE_FONT, 0, &face) || FT_Set_Pixel_Sizes(face, 0, 13))) {
            sy_log(SY_LOG_WARNING, "sy", SY_COMPARE_FONT, "contact sheet without labels: cannot load the font");
            face = NULL;
        }
        if (img && face) {
            if (o->title) draw_text(face, img, W, H, 6, (int)top - 6, o->title, 4.0f);
            for (uint32_t t = 0; t < n; ++t) {
                char label[160];
                int x0 = (int)(t * (w + gap)) + 4;
                snprintf(label, sizeof label, "%s  %.2f s", rows[t].backend, rows[t].seconds);
                draw_text(face, img, W, H, x0, (int)top + 14, label, 4.0f);
                if (ref != UINT32_MAX)
                    snprintf(label, sizeof label, "Y %.3f  x%.2f  IoU %.3f", rows[t].mean_luminance, rows[t].ratio,
                             rows[t].iou);
                else
                    snprintf(label, sizeof label, "Y %.3f", rows[t].mean_luminance);
                draw_text(face, img, W, H, x0, (int)top + 29, label, 4.0f);
            }
        }
        if (face) FT_Done_Face(face);
        if (ft) FT_Done_FreeType(ft);
        if (img) {
            sy_png_options po = {.tonemap = SY_TONEMAP_DISPLAY};
            r = sy_png_write(o->sheet_path, (int)W, (int)H, img, &po, err);
            free(img);
        }
    }
    for (uint32_t i = 0; i < 16; ++i) sy_layer_destroy(&layers[i]);
    return r;
}
