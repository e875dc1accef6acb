/** @file
 * sy_layer.h — a rendered rectangle: RGBA float (linear, premultiplied) and depth planes, what
 * every back-end fills (sy_mediator.h).
 * Ownership: a layer is owned by whoever created it (sy_layer_create / sy_layer_destroy).
 * Thread-safety: plain data; one writer at a time. */
#ifndef SY_LAYER_H
#define SY_LAYER_H

#include "sy_common.h"

#ifdef __cplusplus
extern "C" {
#endif

/** A rendered rectangle: RGBA and depth planes (sy_layer_create). */
typedef struct sy_layer {
    /** @{ size in pixels */
    uint32_t width, height; /** @} */
    float *rgba;  /**< width*height*4, linear premultiplied, row 0 = top */
    float *depth; /**< width*height, linear distance along the view axis, +INFINITY = nothing */
} sy_layer;

/** Allocates a layer cleared to transparent black and +INFINITY depth. */
sy_result sy_layer_create(uint32_t width, uint32_t height, sy_layer *out, sy_error *err);
void sy_layer_destroy(sy_layer *l); /**< frees the buffers, zeroes the struct */
/** Clears to transparent black and +INFINITY depth. */
void sy_layer_clear(sy_layer *l);
/** Counts pixels with a non-finite colour component (tests: must be zero). */
size_t sy_layer_count_nonfinite(const sy_layer *l);

#ifdef __cplusplus
}
#endif
#endif /* SY_LAYER_H */
