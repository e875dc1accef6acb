/** @file
 * sy_strokes.h — line and point primitives as triangle geometry, for every back-end alike.
 *
 * Why: a stroke must cover the same pixels whichever back-end draws it. GL lines and points have a
 * width in pixels (and a driver-dependent maximum); Embree's curve and point primitives have a
 * world width but their own shapes and intersection rules; each would give its own coverage and
 * shading. So the shared scene mirror (sy_mirror.c) turns every SY_TOPOLOGY_LINES and
 * SY_TOPOLOGY_POINTS primitive into ordinary triangles here, in the primitive's own coordinates,
 * before any back-end sees it: the rasterizer and the ray tracers then draw the same tubes and
 * balls, lit by the same normals, and the node transforms place them like any other mesh.
 *
 * Shapes (width w = sy_primitive_stroke_width, the rule in sy_scene.h):
 *  - a line segment a-b is an open 6-sided prism (tube) of circumradius w/2 along a-b:
 *    12 vertices, 12 triangles, smooth radial normals; a zero-length segment has no tube;
 *  - a point, and every distinct vertex a line segment touches (the joints and ends, so polylines
 *    bend without gaps and ends are round), is an icosahedron of circumradius w/2: 12 vertices,
 *    20 triangles, radial normals.
 * So a line primitive of S segments (Z of them zero-length) over J distinct vertices gives
 * 12 (S - Z) + 20 J triangles; a point primitive of P points gives 20 P (repeated indices repeat).
 * Texcoords (both sets) and colours of a stroke vertex are copied to every tessellated vertex that
 * stems from it; tangents and the source normals are not used (see sy_scene.h).
 * The result is indexed, triangles, same material, width 0.
 *
 * Limits: more than SY_STROKES_MAX_TRIANGLES output triangles gives SY_ERR_LIMIT (message names
 * the counts); the arithmetic is checked.
 * Ownership: *out's blobs are new references owned by the caller (sy_primitive_release).
 * Thread-safety: pure function over its arguments. */
#ifndef SY_STROKES_H
#define SY_STROKES_H

#include "sy_scene.h"

#ifdef __cplusplus
extern "C" {
#endif

#define SY_STROKES_TUBE_SIDES 6u /**< sides of a tube around a segment */
#define SY_STROKES_TUBE_TRIANGLES (2u * SY_STROKES_TUBE_SIDES) /**< triangles of a tube segment */
#define SY_STROKES_BALL_VERTICES 12u /**< vertices of a ball (icosahedron) */
#define SY_STROKES_BALL_TRIANGLES 20u /**< triangles of a ball */
#define SY_STROKES_MAX_TRIANGLES (1u << 28) /**< most output triangles of one primitive */

/** Number of triangles the tessellation of p will have (0 for triangles; UINT64_MAX when p is
 * malformed, e.g. an index past the vertices). */
uint64_t sy_strokes_triangle_count(const sy_primitive *p);

/** Tessellates a line or point primitive (validated as sy_mesh_set_primitives does) into *out, a
 * triangle primitive. width: the diameter (> 0; sy_primitive_stroke_width). what: prefix for
 * messages (e.g. "mesh 0x401 primitive 2"). */
sy_result sy_strokes_tessellate(const sy_primitive *p, float width, const char *what, sy_primitive *out,
                                sy_error *err);

#ifdef __cplusplus
}
#endif
#endif /* SY_STROKES_H */
