/** @file
 * sy_math.h — small vector / matrix / bounds helpers shared by core, formats and mediators.
 *
 * Matrices are 4x4 float, column-major (glTF convention: m[12], m[13], m[14] are the translation).
 * Quaternions are (x, y, z, w) as in glTF. All functions are pure; thread-safe. */
#ifndef SY_MATH_H
#define SY_MATH_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/** The largest magnitude of any coordinate a back-end is given, in scene units (metres): vertex
 * positions, translations, camera, light and orbit positions, bounds, and the world placements
 * they compose to. One rule for every layer: setters, loaders and the replica refuse larger
 * values (naming the item), interactive cameras are clamped to it, and the scene commit leaves a
 * placement whose world transform exceeds it undrawn (logged). 1e12 m is beyond Saturn's orbit,
 * where float spacing is already 6e4 m; it leaves Embree, which asserts on ray coordinates beyond
 * 1.844e18, a margin of 10^6 for the instance transforms of a ray tracer (docs/FORMATS.md,
 * "Numbers in range"). */
#define SY_COORD_MAX 1.0e12f

/** true when each of the n values is finite and at most SY_COORD_MAX in magnitude. */
bool sy_coords_in_range(const float *v, size_t n);

/** 4x4 matrix, column-major (glTF): m[12..14] = translation. */
typedef struct sy_mat4 {
    float m[16]; /**< the 16 elements, column by column */
} sy_mat4;

/** Axis-aligned bounds. */
typedef struct sy_bounds {
    float min[3]; /**< smallest corner */
    float max[3]; /**< empty bounds have min > max (see sy_bounds_empty) */
} sy_bounds;

/** @{ 3-vectors as float[3]: difference and cross product (out may alias an input), dot
 * product; the one copy of each for core, mediators, formats and apps (back-ends keep their own). */
static inline void sy_vec3_sub(const float a[3], const float b[3], float out[3])
{
    out[0] = a[0] - b[0], out[1] = a[1] - b[1], out[2] = a[2] - b[2];
}
static inline void sy_vec3_cross(const float a[3], const float b[3], float out[3])
{
    float x = a[1] * b[2] - a[2] * b[1], y = a[2] * b[0] - a[0] * b[2], z = a[0] * b[1] - a[1] * b[0];
    out[0] = x, out[1] = y, out[2] = z;
}
static inline float sy_vec3_dot(const float a[3], const float b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
/** @} */

/** The identity matrix. */
sy_mat4 sy_mat4_identity(void);
sy_mat4 sy_mat4_mul(const sy_mat4 *a, const sy_mat4 *b); /**< a * b */
/** T * R * S from translation, unit quaternion (x,y,z,w) and scale. */
sy_mat4 sy_mat4_from_trs(const float t[3], const float q[4], const float s[3]);
/** General inverse; returns false (and identity) for a singular matrix. */
bool sy_mat4_invert(const sy_mat4 *a, sy_mat4 *out);
/** a applied to a point (w = 1). */
void sy_mat4_transform_point(const sy_mat4 *a, const float p[3], float out[3]);
/** a applied to a direction (w = 0). */
void sy_mat4_transform_dir(const sy_mat4 *a, const float d[3], float out[3]);
/** The camera-to-world matrix of a camera at eye looking at target with up as the image's upward
 * direction (the camera looks down its -z, y up, as glTF): columns x, y, z (unit, orthogonal) and eye.
 * Returns false (out untouched) when a value is not finite, eye equals target, or up is zero or
 * parallel to the viewing direction. */
bool sy_mat4_look_at(const float eye[3], const float target[3], const float up[3], sy_mat4 *out);
/** true when the upper 3x3 collapses space: it is singular or so near it that its inverse is
 * meaningless in float (|det| <= 1e-30 s^3, s its largest element; a zero scale on any axis). A
 * placement with such a world matrix is not drawn (glTF hides parts with a zero scale). */
bool sy_mat4_is_degenerate(const sy_mat4 *a);
/** true when every element is finite. */
bool sy_mat4_is_finite(const sy_mat4 *a);
/** true when every element is equal. */
bool sy_mat4_equal(const sy_mat4 *a, const sy_mat4 *b);

/** Empty bounds (min > max). */
sy_bounds sy_bounds_empty(void);
/** true for empty bounds. */
bool sy_bounds_is_empty(const sy_bounds *b);
/** Grows b to contain p. */
void sy_bounds_add_point(sy_bounds *b, const float p[3]);
/** Grows b to contain o. */
void sy_bounds_add_bounds(sy_bounds *b, const sy_bounds *o);
/** Bounds of the 8 transformed corners of b (empty stays empty). */
sy_bounds sy_bounds_transform(const sy_bounds *b, const sy_mat4 *m);

#define SY_MESH_CLOSED_MAX (1u << 20) /**< the most triangles sy_mesh_closed checks */
/** Whether the triangle mesh (positions: float3 x vertex_count; indices: 3 x triangle_count, or NULL
 * for a plain triangle list) is a closed, consistently wound surface (the solids section caps fill): with
 * its vertices welded by exact position, every directed edge (a, b) of a non-degenerate triangle
 * occurs once and its reverse (b, a) once too. 1: closed and wound counter-clockwise seen from
 * outside (its signed volume is positive), -1: closed and wound the other way, 0: open,
 * non-manifold, empty, flat (no volume), above SY_MESH_CLOSED_MAX triangles, or out of
 * memory. O(triangles): hash sets of the welded positions and the directed edges (at most 64 bytes
 * a triangle while it runs); about 0.3 s of CPU per 10^6 triangles (a closed 2 x 10^6-triangle
 * torus: 0.62 s, where sorting the edges took 0.94 s). The mediators call it once per primitive
 * they create (sy_mirror_flat_mesh_closed), sy_viewport_pick on a capped view's back-face hit. */
int sy_mesh_closed(const float *positions, uint32_t vertex_count, const uint32_t *indices, uint32_t triangle_count);

#ifdef __cplusplus
}
#endif
#endif /* SY_MATH_H */
