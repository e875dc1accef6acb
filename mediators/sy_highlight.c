/* sy_highlight.c — the selection highlight of every back-end (sy_highlight.h): tint and outline
 * from a rectangle of per-pixel selection flags. */
#include "sy_highlight.h"

#include <stddef.h>

sy_highlight_rect sy_highlight_margin(uint32_t full_w, uint32_t full_h, uint32_t x, uint32_t y, uint32_t w, uint32_t h)
{
    sy_highlight_rect m;
    m.x = x > 0 ? x - 1 : 0;
    m.y = y > 0 ? y - 1 : 0;
    uint64_t x1 = (uint64_t)x + w + 1, y1 = (uint64_t)y + h + 1;
    if (x1 > full_w) x1 = full_w;
    if (y1 > full_h) y1 = full_h;
    m.w = x1 > m.x ? (uint32_t)(x1 - m.x) : 0;
    m.h = y1 > m.y ? (uint32_t)(y1 - m.y) : 0;
    return m;
}

/* The flag of full-image pixel (px, py), 0 outside m. */
static int flag_at(const uint8_t *sel, sy_highlight_rect m, int64_t px, int64_t py)
{
    if (px < (int64_t)m.x || py < (int64_t)m.y || px >= (int64_t)m.x + m.w || py >= (int64_t)m.y + m.h) return 0;
    return sel[(size_t)(py - m.y) * m.w + (size_t)(px - m.x)] != 0;
}

uint64_t sy_highlight_apply(float *rgba, uint32_t x, uint32_t y, uint32_t w, uint32_t h, const uint8_t *sel,
                            sy_highlight_rect m)
{
    static const float col[3] = SY_HIGHLIGHT_COLOR;
    const float t = SY_HIGHLIGHT_TINT;
    uint64_t selected = 0;
    for (uint32_t j = 0; j < h; ++j)
        for (uint32_t i = 0; i < w; ++i) {
            int64_t px = (int64_t)x + i, py = (int64_t)y + j;
            float *c = rgba + 4 * ((size_t)j * w + i);
            if (flag_at(sel, m, px, py)) {
                for (int k = 0; k < 3; ++k) c[k] = c[k] * (1.0f - t) + col[k] * t * c[3];
                selected++;
            } else if (flag_at(sel, m, px - 1, py) || flag_at(sel, m, px + 1, py) || flag_at(sel, m, px, py - 1) ||
                       flag_at(sel, m, px, py + 1)) {
                for (int k = 0; k < 3; ++k) c[k] = col[k];
                c[3] = 1.0f;
            }
        }
    return selected;
}
