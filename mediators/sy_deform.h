/** @file
 * sy_deform.h — skinning and morph targets on the CPU, once for every back-end: the scene mirror
 * (sy_mirror.h) calls it for each primitive instance whose node's morph weights or skin joints
 * moved, and hands the back-ends the deformed vertices as an ordinary primitive.
 *
 * What it computes (glTF 2.0, "Morph Targets" and "Skins"), for each vertex v:
 *   morph:  p = p0 + sum_t w_t dP_t[v]; n = n0 + sum_t w_t dN_t[v]; t.xyz = t0.xyz + sum_t w_t dT_t[v]
 *           (w_t: the weights given; targets beyond them weigh 0); texture coordinates (set 0)
 *           uv = uv0 + sum_t w_t dUV_t[v] (sy_deform_texcoords);
 *   skin:   M = sum_k s_k J[j_k], J[j] = joint j's world matrix x its inverse bind matrix, the s_k
 *           the vertex's skin weights (influences whose joint index is past the joints given are left
 *           out); p' = M p, n' = normalize(M3x3 n), t'.xyz = normalize(M3x3 t.xyz), t'.w = t.w.
 *           A vertex whose weights sum to 0 keeps p (the bind pose). Skinned results are in world
 *           space: the mesh node's own transform is not applied (glTF's rule).
 * Normals use M's upper 3x3 rather than its inverse transpose, as the Khronos sample viewer does:
 * the same for rigid joints and uniform scales, which skins almost always have.
 *
 * Cost: O(vertices x (targets + influences)), spread over up to SY_DEFORM_MAX_THREADS threads of
 * its own (one per SY_DEFORM_VERTICES_PER_THREAD vertices, at most one per online CPU; each a range
 * of vertices), joined before it returns; where a thread cannot be started the caller's does that
 * range. No heap allocation. Thread-safety: reentrant (distinct outputs may be filled at once). */
#define SY_DEFORM_MAX_THREADS 8u               /**< threads one call uses at most */
#define SY_DEFORM_VERTICES_PER_THREAD 32768u   /**< vertices that make one more thread worth starting */
#ifndef SY_DEFORM_H
#define SY_DEFORM_H

#include "sy_objects.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The inputs of one deformation. */
typedef struct sy_deform_input {
    const sy_primitive *primitive; /**< source: positions (+ normals, tangents), targets, joints / weights */
    const float *weights;          /**< morph weights (NULL: none) */
    uint32_t weight_count;         /**< their count */
    const sy_mat4 *joints;         /**< joint world x inverse bind matrices, composed (NULL: not skinned) */
    uint32_t joint_count;          /**< their count */
    uint32_t max_threads;          /**< threads at most (0: SY_DEFORM_MAX_THREADS) */
} sy_deform_input;

/** Deforms in->primitive into positions (float[3] x vertices), normals (float[3], filled when the
 * primitive has normals; may be NULL otherwise) and tangents (float[4], likewise). Returns false
 * when a deformed position is not finite or beyond SY_COORD_MAX (the outputs are then partial); the
 * caller keeps what it had. bounds_out (may be NULL) receives the deformed positions' bounds. */
bool sy_deform_primitive(const sy_deform_input *in, float *positions, float *normals, float *tangents, sy_bounds *bounds_out);

/** Morphs in->primitive's texture coordinates (set 0) into uv (float[2] x vertices): uv0 + sum_t
 * w_t dUV_t (target_texcoords0; the weights as sy_deform_primitive's). The primitive must have
 * texcoords0; without target_texcoords0 or weights uv is a copy of them. O(vertices x targets), on
 * the caller's thread; no allocation. Texture coordinates are not skinned (they do not move with a
 * joint). */
void sy_deform_texcoords(const sy_deform_input *in, float *uv);

/** Whether a primitive has anything to deform (morph targets, or joints and weights). */
bool sy_deform_has_data(const sy_primitive *p);

#ifdef __cplusplus
}
#endif
#endif /* SY_DEFORM_H */
