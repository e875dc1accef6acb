/** @file
 * sy_gltf_write.h — writes scene geometry as glTF 2.0 binary (GLB) through tinygltf (the shim in
 * sy_gltf_shim_write.cpp; no glTF JSON or GLB container is written by hand here).
 *
 * What is written: placements — a mesh at a world matrix — as one glTF node each (a root of scene
 * 0, its matrix unless the identity, its name, and the caller's id as extras {"id": N}); each
 * distinct sy_mesh once (placements of one mesh share it), with every primitive's POSITION (with
 * min / max), NORMAL, TEXCOORD_0 and COLOR_0 when present, uint16 or uint32 indices, the mode (triangles,
 * lines, points); each material used once as a glTF metallic-roughness material: base colour,
 * metallic, roughness, emissive (+ KHR_materials_emissive_strength), alpha mode / cutoff, double
 * sided, KHR_materials_unlit; with sy_gltf_write_options.textures every material field and texture
 * (as sy_gltf_write_scene). Not written by default: textures (and texture coordinate set 1, tangents),
 * lights, cameras, the node hierarchy (placements are flattened to world matrices), stroke widths,
 * animations (sy_gltf_write_scene warns for each; nodes are written in their current pose).
 * sy_gltf_load reads the result back (tests/cull: round trip).
 *
 * Ownership: *glb_out is malloc()ed, the caller frees it; *placements_out likewise.
 * Thread-safety: reads the scene (the committed state of the graph queries is not used: matrices come
 * from each node's local transform), so calls must not overlap modifications of that scene. */
#ifndef SY_GLTF_WRITE_H
#define SY_GLTF_WRITE_H

#include "sy_common.h"
#include "sy_scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/** A mesh at a world matrix (one glTF node). */
typedef struct sy_gltf_placement {
    uint32_t node_id; /**< the core node it comes from (its name is written; 0: none) */
    sy_mesh mesh;     /**< the mesh placed */
    sy_mat4 world;    /**< its world matrix */
    int64_t id;       /**< >= 0: written as the node's extras {"id": id}; -1: none */
} sy_gltf_placement;

/** Options of the writers. Zero-initialise ({0}) for the defaults. */
typedef struct sy_gltf_write_options {
    const char *generator; /**< asset.generator; NULL = "Switchyard" */
    /** sy_gltf_write_placements: the materials in full as sy_gltf_write_scene writes them (every
     * texture slot as an embedded PNG with its sampler and transform, every extension; tangents and
     * TEXCOORD_1 of the primitives); false: the factors of the file comment only. */
    bool textures;
    /** Textures wider or taller than this are halved (2 x 2 box) until they fit; 0: written as they
     * are. Bounds what a GLB of textured objects costs (the culling service's /api/object). */
    uint32_t texture_max_side;
} sy_gltf_write_options;

/** Limits of sy_gltf_placements_collect: paths through a DAG multiply. */
#define SY_GLTF_MAX_PLACEMENTS (1u << 24)
#define SY_GLTF_MAX_DEPTH 256u /**< deepest node path followed */

/** Every visible placement of a mesh under root (root included), depth first in child order: a node
 * is visible when it and all its ancestors on the path have SY_NODE_VISIBLE; a node reached along k
 * paths gives k placements; world = product of the local matrices from root (root's own included:
 * sy_scene_walk, sy_graph.h, under an identity).
 * id = the node's id. SY_ERR_INVALID_HANDLE for a stale root, SY_ERR_LIMIT past the limits above. */
sy_result sy_gltf_placements_collect(const sy_scene *s, sy_node root, sy_gltf_placement **placements_out,
                                     uint32_t *count_out, sy_error *err);

/** GLB of the placements (see the file comment). SY_ERR_INVALID_HANDLE names a stale mesh,
 * SY_ERR_LIMIT a primitive whose arrays do not fit glTF's 32-bit counts or a GLB over 4 GiB. */
sy_result sy_gltf_write_placements(const sy_scene *s, const sy_gltf_placement *placements, uint32_t count,
                                   const sy_gltf_write_options *opts, uint8_t **glb_out, size_t *len_out, sy_error *err);

/** GLB of every visible placement under root (sy_gltf_placements_collect + sy_gltf_write_placements). */
sy_result sy_gltf_write_subtree(const sy_scene *s, sy_node root, const sy_gltf_write_options *opts, uint8_t **glb_out,
                                size_t *len_out, sy_error *err);

/** Writes the subtree's GLB to path (a temporary file renamed into place: sy_file.h). */
sy_result sy_gltf_write_subtree_file(const sy_scene *s, sy_node root, const sy_gltf_write_options *opts,
                                     const char *path, sy_error *err);

/** The whole scene under root as glTF 2.0 (sy convert): GLB (binary) or glTF JSON with one embedded
 * data: URI buffer. Root's children are scene 0's nodes when root is plain (identity, nothing
 * attached), else root itself is. Written: the node hierarchy (TRS or matrix as each node has it;
 * a node reached along several paths once per path; hidden nodes left out with a warning), meshes
 * with POSITION, NORMAL, TANGENT, TEXCOORD_0/1, COLOR_0 and indices as present (a primitive without
 * normals, flat-shaded, gets neither NORMAL nor TANGENT, so a reader shades it flat too), every sy_material_data field
 * (metallic-roughness, normal / occlusion / emissive, KHR_materials_emissive_strength,
 * _transmission, _ior, _unlit, _specular, _clearcoat, _sheen, _volume, _iridescence, _anisotropy,
 * each omitted at its defaults; KHR_texture_transform and texCoord on every texture slot), one
 * PNG image + sampler + texture per core texture, cameras, KHR_lights_punctual lights. Logged as
 * warnings (sy_log, module "gltf") and left out: backgrounds (the world) and float textures.
 * Same result codes as sy_gltf_write_placements. */
sy_result sy_gltf_write_scene(const sy_scene *s, sy_node root, const sy_gltf_write_options *opts, bool binary,
                              uint8_t **out, size_t *len_out, sy_error *err);

/** sy_gltf_write_scene to path: GLB for ".glb", glTF JSON for ".gltf" (else SY_ERR_INVALID_ARGUMENT),
 * through a temporary file renamed into place (sy_file.h): nothing is left on failure. */
sy_result sy_gltf_write_scene_file(const sy_scene *s, sy_node root, const sy_gltf_write_options *opts, const char *path,
                                   sy_error *err);

#ifdef __cplusplus
}
#endif
#endif /* SY_GLTF_WRITE_H */
