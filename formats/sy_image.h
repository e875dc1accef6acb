/** @file
 * sy_image.h — decoding an encoded texture image (PNG, JPEG, GIF, and the formats without a
 * signature the sniffer knows: TGA, BMP, PSD, PIC, PNM; what stb_image reads) from memory into
 * 8-bit pixels; content sy_sniff identifies as something else (Radiance HDR, EXR, a scene) is refused
 * before stb_image sees it, within a pixel limit and the load's budget
 * (sy_budget.h), both checked from the image's header before anything is decoded. Used by the
 * loaders that decode their own textures (X3D ImageTexture, the Assimp formats' external and
 * embedded textures).
 * Ownership: on success *out holds malloc()ed pixels (sy_image_pixels_free). Thread-safety: no
 * shared state (stb_image's failure reason is thread-local where the compiler offers it). */
#ifndef SY_IMAGE_H
#define SY_IMAGE_H

#include "sy_budget.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Decoded pixels: rows top to bottom, channels interleaved, 8 bits each. */
typedef struct sy_image_pixels {
    uint8_t *pixels;  /**< width x height x channels bytes (malloc()ed) */
    /** @{ size in pixels */
    uint32_t width, height; /** @} */
    uint32_t channels; /**< 1 grey, 2 grey + alpha, 3 RGB, 4 RGBA (as the file has them) */
} sy_image_pixels;

/** Decodes size bytes at data. Refuses, before decoding, an image over max_pixels (width x height)
 * or over what is left of budget (width x height x channels bytes; NULL: no budget), and charges
 * the budget on success. Errors say why without a file name (the caller prefixes its own item):
 * SY_ERR_PARSE (not an image stb_image reads, or a corrupt one; its reason), SY_ERR_LIMIT. */
sy_result sy_image_decode(const void *data, size_t size, uint64_t max_pixels, sy_budget *budget, sy_image_pixels *out,
                          sy_error *err);

/** Frees the pixels and zeroes *img. NULL-safe. */
void sy_image_pixels_free(sy_image_pixels *img);

#ifdef __cplusplus
}
#endif
#endif /* SY_IMAGE_H */
