/* sy_image.c — texture images decoded by stb_image within the pixel limit and the budget (see
 * sy_image.h). */
#include "sy_image.h"

#include "sy_sniff.h"

#include <stb_image.h>

#include <limits.h>
#include <stdlib.h>
#include <string.h>

sy_result sy_image_decode(const void *data, size_t size, uint64_t max_pixels, sy_budget *budget, sy_image_pixels *out,
                          sy_error *err)
{
    memset(out, 0, sizeof *out);
    int w = 0, h = 0, comp = 0;
    if (!data || size == 0) return sy_error_set(err, SY_ERR_PARSE, "cannot decode (no data)");
    if (size > INT_MAX) return sy_error_set(err, SY_ERR_LIMIT, "cannot decode (%zu bytes, larger than 2 GiB)", size);
    /* content the sniffer knows that is no 8-bit texture (Radiance HDR above all: Debian's
     * stb_image loops for ever on a truncated run-length file) never reaches stb_image */
    sy_file_format kind = sy_sniff_bytes(data, size);
    if (kind != SY_FORMAT_UNKNOWN && !sy_file_format_is_texture_image(kind, true))
        return sy_error_set(err, SY_ERR_PARSE, "%s content, not a texture image (PNG, JPEG, GIF, BMP, TGA)",
                            sy_file_format_name(kind));
    if (!stbi_info_from_memory(data, (int)size, &w, &h, &comp) || w < 1 || h < 1 || comp < 1 || comp > 4) {
        const char *why = stbi_failure_reason();
        return sy_error_set(err, SY_ERR_PARSE, "cannot decode (%s)", why ? why : "not an image");
    }
    if ((uint64_t)w * (uint64_t)h > max_pixels)
        return sy_error_set(err, SY_ERR_LIMIT, "%dx%d pixels exceed the limit of %llu", w, h, (unsigned long long)max_pixels);
    if (budget && !sy_budget_fits(budget, (uint64_t)w * (uint64_t)h, (uint64_t)comp))
        return sy_error_set(err, SY_ERR_LIMIT, "%dx%d pixels exceed what is left of the scene budget (%.0f MiB)", w, h,
                            (double)(budget->limit - budget->used) / (1024.0 * 1024.0));
    int w2 = 0, h2 = 0, c2 = 0;
    uint8_t *px = stbi_load_from_memory(data, (int)size, &w2, &h2, &c2, comp);
    if (px && (w2 != w || h2 != h)) { /* a size that differs from the header is a failure */
        stbi_image_free(px);
        return sy_error_set(err, SY_ERR_PARSE, "cannot decode (size %dx%d differs from the header's %dx%d)", w2, h2, w, h);
    }
    if (!px) {
        const char *why = stbi_failure_reason();
        return sy_error_set(err, SY_ERR_PARSE, "cannot decode (%s)", why ? why : "unknown");
    }
    if (budget) (void)sy_budget_charge(budget, (uint64_t)w * (uint64_t)h, (uint64_t)comp, NULL, "image"); /* fits */
    out->pixels = px;
    out->width = (uint32_t)w;
    out->height = (uint32_t)h;
    out->channels = (uint32_t)comp;
    return SY_OK;
}

void sy_image_pixels_free(sy_image_pixels *img)
{
    if (!img) return;
    stbi_image_free(img->pixels);
    memset(img, 0, sizeof *img);
}
