/** @file
 * sy_highlight.h — the selection highlight every back-end draws the same way (SY_NODE_SELECTED,
 * core/sy_objects.h): from an ID image of the pixel centres (the nearest visible surface through
 * each pixel's centre, the ray of a pick, whether it belongs to a selected placement), the
 * selected pixels are blended SY_HIGHLIGHT_TINT of the way toward SY_HIGHLIGHT_COLOR (alpha kept,
 * colours premultiplied), and the unselected pixels with a selected 4-neighbour become an outline
 * of that colour (alpha 1). The colour is linear radiance added before exposure and tone mapping,
 * like the rest of the layer. Depth, picks and coverage are unchanged.
 * A back-end computes the flags over sy_highlight_margin (its rectangle grown by one pixel, within
 * the full image) so that tiles stitch into the same image as a full frame.
 * Thread-safety: pure functions on caller-owned buffers. */
#ifndef SY_HIGHLIGHT_H
#define SY_HIGHLIGHT_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define SY_HIGHLIGHT_TINT 0.5f /**< share of the selection colour in a selected pixel */
/** The selection colour, linear RGB: orange (1, 0.45, 0). */
#define SY_HIGHLIGHT_COLOR {1.0f, 0.45f, 0.0f}

/** A rectangle of a full image (row 0 = top). */
typedef struct sy_highlight_rect {
    /** @{ position and size in pixels */
    uint32_t x, y, w, h; /** @} */
} sy_highlight_rect;

/** The rectangle (x, y, w, h) of a full_w x full_h image grown by one pixel on every side, clipped
 * to the image: where a back-end evaluates the selection flags. */
sy_highlight_rect sy_highlight_margin(uint32_t full_w, uint32_t full_h, uint32_t x, uint32_t y, uint32_t w, uint32_t h);

/** Applies the highlight to rgba (w x h RGBA floats of the rectangle at (x, y) of the full image)
 * from sel (m.w x m.h flags over m = sy_highlight_margin of that rectangle, nonzero = selected).
 * Returns the number of selected pixels in the rectangle. */
uint64_t sy_highlight_apply(float *rgba, uint32_t x, uint32_t y, uint32_t w, uint32_t h, const uint8_t *sel,
                            sy_highlight_rect m);

#ifdef __cplusplus
}
#endif
#endif /* SY_HIGHLIGHT_H */
