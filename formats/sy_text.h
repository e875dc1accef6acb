/** @file
 * sy_text.h — flat text geometry from a TrueType / OpenType font (FreeType), for X3D Text.
 *
 * Each string is one line; glyph outlines (font units, unscaled) are flattened (quadratic
 * segments split in SY_TEXT_CONIC_STEPS, cubic in SY_TEXT_CUBIC_STEPS straight pieces) and
 * triangulated with their holes (contours nested an odd number of times are holes of the
 * contour around them; each hole is bridged into its outer contour and the polygon ear-clipped,
 * the earcut method). The text lies in the local XY plane, z = 0, facing +Z: every triangle is
 * counter-clockwise seen from +Z and every normal is (0, 0, 1).
 *
 * Layout (X3D Text / FontStyle, horizontal, left to right, top to bottom): the font's em square is
 * `size` units high; line i's baseline is at y = -i * size * spacing; horizontal justification
 * (major) BEGIN puts a line's start at x = 0, MIDDLE its centre, END its end; vertical (minor)
 * FIRST puts the first baseline at y = 0, BEGIN the top of the first line (the font's ascender),
 * MIDDLE the middle between that top and the bottom of the last line (its baseline + the font's
 * descender), END that bottom. Advances include the font's kerning.
 *
 * Untrusted strings: UTF-8 is decoded strictly (a bad byte becomes U+FFFD); characters without a
 * glyph render the font's .notdef glyph. Limits: max_triangles (SY_ERR_LIMIT naming the count).
 * The font file itself is trusted (a system font).
 * Ownership: *out's blobs belong to the caller. Thread-safety: one FreeType library per call. */
#ifndef SY_TEXT_H
#define SY_TEXT_H

#include "sy_common.h"
#include "sy_scene.h"

#ifdef __cplusplus
extern "C" {
#endif

#define SY_TEXT_CONIC_STEPS 4 /**< line segments per quadratic (conic) outline curve */
#define SY_TEXT_CUBIC_STEPS 6 /**< line segments per cubic outline curve */

/** Justification of text lines (X3D FontStyle justify). */
typedef enum sy_text_justify {
    SY_TEXT_FIRST = 0, /**< minor only */
    SY_TEXT_BEGIN = 1,
    SY_TEXT_MIDDLE = 2,
    SY_TEXT_END = 3,
} sy_text_justify;

/** A text to build (X3D Text + FontStyle). */
typedef struct sy_text_desc {
    const char *const *lines; /**< UTF-8 strings, one per line */
    size_t line_count; /**< entries of lines */
    const char *font_path;    /**< a font file FreeType reads */
    float size;               /**< em height (> 0) */
    float spacing;            /**< line distance in sizes (>= 0) */
    /** @{ sy_text_justify (major: BEGIN, MIDDLE or END) */
    uint32_t major, minor; /** @} */
    size_t max_triangles;     /**< 0 = 1 << 24 */
} sy_text_desc;

/** What sy_text_build laid out. */
typedef struct sy_text_stats {
    uint32_t glyphs;    /**< characters laid out */
    uint32_t triangles; /**< in the primitive */
} sy_text_stats;

/** Builds an indexed triangle primitive (positions, normals, indices; material {0}) into *out.
 * A text with no visible glyph (empty strings, spaces only) gives SY_OK and an empty *out (no
 * positions). Errors: SY_ERR_NOT_FOUND (font missing or unreadable: the message names it),
 * SY_ERR_INVALID_ARGUMENT, SY_ERR_LIMIT, SY_ERR_OUT_OF_MEMORY. stats may be NULL. */
sy_result sy_text_build(const sy_text_desc *d, sy_primitive *out, sy_text_stats *stats, sy_error *err);

/** Triangulates one polygon with holes in 2D (the earcut method). xy: n points; ring_start: ring
 * k is [ring_start[k], ring_start[k+1]) (ring_start[rings] = n), ring 0 the outer contour, the
 * others holes; any orientation. tris must hold 3 * SY_TEXT_TRIANGULATE_CAPACITY(n, rings) indices;
 * returns the triangle count (zero-area ones dropped), every triangle counter-clockwise. */
#define SY_TEXT_TRIANGULATE_CAPACITY(n, rings) (3 * (size_t)(n) + 4 * (size_t)(rings) + 8)
/** Triangulates one polygon with holes (see above). */
size_t sy_text_triangulate(const double *xy, size_t n, const size_t *ring_start, size_t rings, uint32_t *tris);

#ifdef __cplusplus
}
#endif
#endif /* SY_TEXT_H */
