/** @file
 * sy_mesh_util.h — geometry helpers shared by the file loaders (glTF, X3D, Assimp): crease-angle
 * normal generation (X3D), tangent generation for normal mapping, triangulation of convex and concave
 * planar polygons (ear clipping), and tessellation of the X3D primitives (Box, Sphere, Cone,
 * Cylinder) into triangle lists.
 *
 * All functions work on plain arrays (positions float[3], normals float[3], tangents float[4],
 * texcoords float[2], colours float[4], 32-bit indices) or on a sy_primitive whose blobs they
 * replace. Inputs are assumed range-checked by the caller (every index < vertex count) unless a
 * function says otherwise; degenerate input (zero-area triangles, collinear polygons, NaN-free but
 * coincident points) never crashes and produces a usable, documented fallback.
 *
 * Ownership: functions returning arrays malloc() them; the caller frees. Functions taking a
 * sy_primitive release the blobs they replace and retain the new ones in the primitive.
 * Thread-safety: pure functions over caller-owned memory. */
#ifndef SY_MESH_UTIL_H
#define SY_MESH_UTIL_H

#include "sy_common.h"
#include "sy_scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Generates tangents (float[4]: xyz unit tangent orthogonal to the normal, w = +1 or -1 the
 * handedness of the bitangent, glTF convention B = cross(N, T) * w) from positions, normals and the
 * texcoord set `texcoord` (0 or 1). Method: per-triangle tangent/bitangent from the UV gradient,
 * accumulated per vertex weighted by the corner angle (as MikkTSpace does), Gram-Schmidt
 * orthogonalised against the vertex normal; handedness from the accumulated bitangent. Vertices
 * whose UV mapping is degenerate get any unit vector orthogonal to the normal and w = 1.
 * Requires normals and the texcoord set; SY_ERR_INVALID_ARGUMENT otherwise. Replaces p->tangents. */
sy_result sy_prim_generate_tangents(sy_primitive *p, uint32_t texcoord, sy_error *err);

/** Normals of triangle corners with a crease angle (X3D IndexedFaceSet semantics): corner k of
 * triangle t gets the average of the face normals of all triangles that share its position index
 * (pos_index[3t+k]) and whose face normal lies within crease_angle (radians) of triangle t's; 0
 * gives flat normals, >= pi fully smooth. Face normals are weighted by the corner angle (so the
 * result does not depend on how a polygon was split into triangles). A position shared by more
 * than 512 triangles keeps the face normal (bounds the quadratic cost of a huge fan centre). out receives
 * 3 * tri_count float[3] (corner order). Returns SY_ERR_OUT_OF_MEMORY or SY_OK. */
sy_result sy_corner_normals(const float *positions, size_t position_count, const uint32_t *pos_index,
                            size_t tri_count, float crease_angle, float **out, sy_error *err);

/** Triangulates one simple planar polygon given as n indices into positions (n >= 3). Convex and
 * concave polygons (either orientation) are handled by ear clipping in the polygon's best-fit
 * plane (Newell normal); the output keeps the polygon's winding. Writes (n - 2) triangles (3 * (n-2)
 * indices into positions) to tris and returns their count; a self-intersecting polygon where no
 * ear is found falls back to a fan for the remainder. Degenerate (zero-area) polygons give a fan.
 * Convex polygons are fanned directly (linear time); ear clipping of concave ones has a work budget
 * (about 2^26 point tests) after which the remainder is fanned, so hostile input cannot hang it.
 * scratch must hold 4 * n uint32 and 2 * n float (see SY_TRIANGULATE_SCRATCH). */
size_t sy_triangulate_polygon(const float *positions, const uint32_t *poly, size_t n, uint32_t *tris,
                              void *scratch);
#define SY_TRIANGULATE_SCRATCH(n) ((size_t)(n) * (4 * sizeof(uint32_t) + 2 * sizeof(float))) /**< bytes of scratch sy_triangulate_polygon needs for n points */

/** X3D primitives, tessellated into an indexed triangle primitive with normals and texcoords
 * following the X3D texture mapping of each primitive. The blobs in *out are owned by the caller
 * (release with sy_blob_release). Sizes must be > 0 (the X3D loader checks). */
typedef struct sy_prim_tess {
    uint32_t segments; /**< around the axis; 0 = 32 */
    uint32_t rings;    /**< sphere latitude bands; 0 = 16 */
} sy_prim_tess;
/** Box of size x, y, z centred at the origin (X3D Box). */
sy_result sy_tess_box(const float size[3], sy_primitive *out, sy_error *err);
/** Sphere of radius centred at the origin (X3D Sphere). */
sy_result sy_tess_sphere(float radius, const sy_prim_tess *t, sy_primitive *out, sy_error *err);
/** Cone and cylinder along +Y centred at the origin (X3D). Parts may be switched off. */
sy_result sy_tess_cone(float bottom_radius, float height, bool side, bool bottom, const sy_prim_tess *t,
                       sy_primitive *out, sy_error *err);
/** Cylinder along +Y centred at the origin (as sy_tess_cone). */
sy_result sy_tess_cylinder(float radius, float height, bool side, bool top, bool bottom, const sy_prim_tess *t,
                           sy_primitive *out, sy_error *err);

#ifdef __cplusplus
}
#endif
#endif /* SY_MESH_UTIL_H */
