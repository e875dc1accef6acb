/** @file
 * sy_cull.h — the remote culling service as a library (issue 18): for a client's view and triangle
 * budget, the objects that cover the most pixels (with occlusion, as `sy coverage` counts them:
 * sy_context_coverage on a context of the first registered back-end with SY_CAP_COVERAGE, the
 * Embree back-ends' "coverage"), cut at the budget; and any object's geometry and
 * material as GLB (formats/sy_gltf_write.h), so a browser draws only what matters (docs/CULLING.md).
 *
 * Objects: every node under the culler's root that carries a mesh and is visible (it and its
 * ancestors have SY_NODE_VISIBLE). An object's id is its core node handle id (sy_node.id: index +
 * generation), the id the coverage back-end reports; it is stable as long as the node lives, and the
 * same for the same file loaded the same way (loaders create nodes in file order). A node reached
 * along several paths of a DAG is one object with several placements: its pixels are summed over
 * them, its triangles counted per placement, and its GLB holds every placement.
 *
 * Query (JSON, UTF-8, at most SY_CULL_MAX_BODY bytes):
 *   {"position":[x,y,z], "orientation":[qx,qy,qz,qw], "fov":deg, "width":W, "height":H, "budget":T}
 * position: the camera in the root's space; orientation: a quaternion (normalised here; the camera
 * looks down its local -Z with +Y up, the convention of three.js and glTF); fov: vertical field of
 * view in degrees, (0, 180); width, height: the viewport in pixels, 1..16384 each; budget: triangles
 * the client may draw, 0..2^40. Every field is required; unknown fields are refused.
 * Answer:
 *   {"objects":[{"id":N,"pixels":P,"triangles":T},...], "triangles":sum, "budget":T,
 *    "visible_objects":V, "visible_triangles":VT, "total_objects":N, "total_triangles":NT,
 *    "coverage":[cw,ch], "bounds":{"min":[x,y,z],"max":[x,y,z]}}
 * Visible objects (pixels > 0) in the order of their pixels, most first (ties: smaller id first);
 * walking that order, an object is kept when its triangles fit in what remains of the budget and
 * left out otherwise (a big object does not stop smaller ones behind it), so "triangles" <= budget.
 * Coverage is counted at a reduced resolution when W x H exceeds max_coverage_pixels (the same
 * aspect; "coverage" gives the size used and "pixels" are pixels of that grid). "bounds" (absent
 * when there is no object) are the bounds of all objects, so a client can frame the scene.
 *
 * Errors: SY_ERR_LIMIT (body too long), SY_ERR_PARSE (not JSON, not an object),
 * SY_ERR_INVALID_ARGUMENT (a field missing, of the wrong type, not finite or out of range, or
 * unknown: the message names the field and the reason), SY_ERR_NOT_FOUND (an object id that is
 * not an object now). A web server answers the first three with 400 (413 for LIMIT) and the last
 * with 404; anything else is the server's own failure (500).
 *
 * Ownership: the culler borrows scene and pool (both must outlive it) and holds a reference to its
 * coverage context; strings and buffers it returns are malloc()ed and the caller frees them.
 * Thread-safety: none inside; call it from the thread that owns the scene (a server's render thread),
 * between scene modifications: each call syncs the coverage context with what was committed. */
#ifndef SY_CULL_H
#define SY_CULL_H

#include "sy_mediator.h"
#include "sy_scene.h"

#ifdef __cplusplus
extern "C" {
#endif

#define SY_CULL_MAX_BODY 65536u          /**< bytes of a query body */
#define SY_CULL_MAX_SIZE 16384u          /**< width and height */
#define SY_CULL_MAX_BUDGET (1ull << 40)  /**< triangles */

/** A culling service over one scene and root (opaque; sy_culler_create). */
typedef struct sy_culler sy_culler;

/** Options of a culler. Zero-initialise ({0}) for the defaults. */
typedef struct sy_culler_options {
    uint64_t max_coverage_pixels; /**< coverage grid at most this many pixels; 0 = 1 << 20 */
} sy_culler_options;

/** A view of the client (what the JSON carries). */
typedef struct sy_cull_view {
    double position[3];    /**< camera position */
    double orientation[4]; /**< quaternion x, y, z, w (normalised by the culler) */
    double fov_degrees;    /**< vertical field of view */
    /** @{ viewport in pixels */
    uint32_t width, height; /** @} */
} sy_cull_view;

/** One kept object of an answer. */
typedef struct sy_cull_object {
    uint32_t id;        /**< object id (core node id) */
    uint32_t pixels;    /**< pixels covered (coverage grid) */
    uint64_t triangles; /**< triangles of the object (all placements) */
} sy_cull_object;

/** An answer (sy_culler_query). Release with sy_cull_result_free. */
typedef struct sy_cull_result {
    sy_cull_object *objects;  /**< kept objects, most pixels first */
    uint32_t count;           /**< kept objects */
    uint64_t triangles;       /**< triangles of the kept objects (<= budget) */
    uint32_t visible_objects; /**< objects with pixels > 0 */
    uint64_t visible_triangles; /**< their triangles */
    uint32_t total_objects;   /**< objects under the root */
    uint64_t total_triangles; /**< their triangles */
    /** @{ the grid coverage was counted on */
    uint32_t coverage_width, coverage_height; /** @} */
    sy_bounds bounds;         /**< bounds of every object (empty when there is none) */
} sy_cull_result;

/** Creates a culler over the objects under root (a valid node) of scene, with its coverage context
 * (the first registered class with SY_CAP_COVERAGE) from pool (NULL: a context of its own); none
 * registered: SY_ERR_UNSUPPORTED. The scene must have been committed. */
sy_result sy_culler_create(sy_scene *scene, sy_context_pool *pool, sy_node root, const sy_culler_options *opts,
                           sy_culler **out, sy_error *err);
void sy_culler_destroy(sy_culler *c); /**< NULL-safe */

/** Checks a view (finite, ranges above); the message names the field. */
sy_result sy_cull_view_check(const sy_cull_view *v, sy_error *err);
/** The camera view of v for the back-ends (perspective, znear 0.05, infinite far). */
sy_camera_view sy_cull_view_camera(const sy_cull_view *v);

/** Culls: coverage of the view, ranked, cut at budget (see the file comment). */
sy_result sy_culler_query(sy_culler *c, const sy_cull_view *v, uint64_t budget, sy_cull_result *out, sy_error *err);
void sy_cull_result_free(sy_cull_result *r); /**< frees the objects and zeroes r (NULL-safe) */

/** Parses a JSON query body (len bytes, need not be NUL-terminated; see the file comment). */
sy_result sy_cull_parse_query(const char *body, size_t len, sy_cull_view *view_out, uint64_t *budget_out, sy_error *err);
/** The whole service call: parse body, query, answer as JSON (*json_out: malloc()ed, NUL-terminated). */
sy_result sy_culler_query_json(sy_culler *c, const char *body, size_t len, char **json_out, sy_error *err);

/** Triangles of object id; SY_ERR_NOT_FOUND when id is not an object now. */
sy_result sy_culler_object_triangles(sy_culler *c, uint32_t id, uint64_t *triangles_out, sy_error *err);
/** The largest side of a texture in an object's GLB: larger ones are halved until they fit. */
#define SY_CULL_TEXTURE_MAX_SIDE 1024u
/** Object id as GLB (every placement with its matrix from the root down; extras {"id": id}; the
 * materials in full with their textures as PNG, at most SY_CULL_TEXTURE_MAX_SIDE a side); *glb_out
 * is malloc()ed. SY_ERR_NOT_FOUND when id is not an object now. */
sy_result sy_culler_object_glb(sy_culler *c, uint32_t id, uint8_t **glb_out, size_t *len_out, sy_error *err);
/** The objects that moved (the scene clock, an application's change) as JSON, for a client that
 * holds their GLBs: {"frame":F,"objects":[{"id":N,"matrices":[[m0..m15],...]},...]}, each object
 * whose placements are not (or were not, once, since the culler was created) those of the scene as
 * the culler was created, with every placement's world matrix (column-major, the order of its GLB's
 * nodes); F the scene's frame (sy_scene_frame) they are of. Objects that never left the loaded
 * pose are not listed. Morph weights and skins are not (the GLB holds the undeformed mesh).
 * *json_out: malloc()ed. */
sy_result sy_culler_poses_json(sy_culler *c, char **json_out, sy_error *err);

/** Parses an object id from a URL path segment ("123": decimal digits only, 1..2^32-1);
 * SY_ERR_INVALID_ARGUMENT otherwise. */
sy_result sy_cull_parse_id(const char *text, size_t len, uint32_t *id_out, sy_error *err);

#ifdef __cplusplus
}
#endif
#endif /* SY_CULL_H */
