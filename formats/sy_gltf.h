/** @file
 * sy_gltf.h — glTF 2.0 loader: reads .gltf (embedded data: URIs or external files) and .glb and
 * adds its default scene to a sy_scene through the public scene API.
 *
 * What is created: one texture per (glTF texture, role) actually used by a material — colour roles
 * (base colour, emissive) as SY_PIXEL_U8_SRGB, data roles (normal, metallic-roughness, occlusion,
 * transmission) as SY_PIXEL_U8_LINEAR; one material per glTF material; one mesh per glTF mesh (a mesh
 * used by several nodes stays one sy_mesh: instancing); one camera / light per glTF camera /
 * KHR_lights_punctual light; one node per glTF node reached from the loaded glTF scene, plus one
 * new root node (named after the glTF scene, "scene <index>" when unnamed) whose children are the
 * scene's root nodes. Every created node has SY_NODE_VISIBLE. EXT_mesh_gpu_instancing expands into
 * one child node per instance, all referencing the same sy_mesh.
 *
 * Supported: node TRS / matrix; triangle lists, strips and fans (strips and fans become lists);
 * POINTS become SY_TOPOLOGY_POINTS primitives and LINES, LINE_LOOP, LINE_STRIP become
 * SY_TOPOLOGY_LINES primitives (loops and strips expanded to index pairs; width 0 = core's rule,
 * drawn as tubes and balls by every back-end, lit with their own normals); attributes POSITION, NORMAL, TANGENT,
 * TEXCOORD_0/1, COLOR_0 of any glTF component type (normalized integers scaled) including sparse
 * accessors; glTF metallic-roughness materials with KHR_materials_emissive_strength,
 * KHR_materials_transmission, KHR_materials_ior, KHR_materials_unlit, KHR_texture_transform;
 * PNG and JPEG images decoded by stb_image into 8-bit RGB or RGBA (16-bit images are rounded, grey
 * images expanded to RGBA), WebP images of EXT_texture_webp by libwebp into RGBA, with sampler
 * wrap / filter; perspective and orthographic cameras; KHR_lights_punctual; KHR_mesh_quantization;
 * KHR_draco_mesh_compression (libdraco); EXT_meshopt_compression (meshoptimizer);
 * EXT_mesh_gpu_instancing. KHR_texture_basisu is refused when required (no packaged decoder).
 * Animations: every glTF animation becomes one sy_animation (sy_objects.h; file order, its name;
 * info->animations) with its translation, rotation, scale and weights channels that target loaded
 * nodes; sy_scene_set_time (sy_anim.h) plays them. A load without a time shows the nodes at the
 * first keyframe of each channel of animations[0] (the value at time 0 for keys from 0 on, which is
 * what sy_scene_set_time(clip 0, 0) sets; the static load keeps the file's values unnormalised).
 * Samplers with mismatched input / output counts, times that are not finite or do not increase
 * strictly, non-finite outputs (translation / scale beyond the coordinate range, zero quaternions)
 * or an unknown interpolation are dropped with a warning naming animations[i].samplers[j]; channels
 * to unknown nodes, to nodes outside the loaded scene, to matrix nodes (glTF forbids animating
 * them) or with an unknown path are dropped naming animations[i].channels[k]. KHR_animation_pointer
 * channels drive what maps onto the clock's paths (sy_anim_path): /nodes/N/translation, rotation,
 * scale, weights; /materials/N/pbrMetallicRoughness/baseColorFactor, metallicFactor,
 * roughnessFactor and /materials/N/emissiveFactor; /extensions/KHR_lights_punctual/lights/N/color
 * and intensity; /cameras/N/perspective/yfov. Any other pointer (or an index the file does not
 * have) is dropped: the first named with its channel, the rest counted in one warning. Cameras
 * and lights sit on nodes, so an animated node carries its camera or light along.
 * Weight channels set the target node's morph weights. Skins (node.skin: joints, inverse bind
 * matrices, skeleton) become the node's SY_NODE_SKIN, JOINTS_0/WEIGHTS_0 and JOINTS_1/WEIGHTS_1 (up
 * to 8 influences) and morph targets (POSITION / NORMAL / TANGENT deltas) the primitive's, mesh and
 * node weights their SY_MESH_WEIGHTS / SY_NODE_WEIGHTS; the scene mirror deforms them for every
 * back-end. Unusable skin data is dropped with a warning, never read past: a joint index past the
 * skin's joints names skins[i] and the mesh (the node is drawn in its bind pose), joints without
 * weights, a non-finite or negative weight or non-VEC4 accessors name meshes[m].primitives[p]
 * (that primitive unskinned), as does a non-finite morph delta (its targets dropped).
 *
 * Untrusted input: the whole document is validated (indices, accessor / bufferView / buffer ranges
 * with checked arithmetic, GLB container, index values, node graph must be a forest, limits,
 * extensionsRequired) before the first object is created. On any failure nothing the call created
 * remains in the scene (objects created so far are destroyed; the scene's pending change set may
 * still list them as created-and-destroyed) and err names the file, the glTF element and the
 * problem, e.g. "Box.gltf: accessors[3]: count 1000000 * stride 12 exceeds bufferView 2 length 768".
 * An image that is missing, over max_image_pixels or cannot be decoded is local: a warning, and the textures using it are
 * absent (the rest loads). Primitives without NORMAL stay as the file has them, indexed and without
 * normals (their TANGENT ignored): the back-ends shade them flat, as glTF requires (sy_primitive);
 * normal-mapped primitives with NORMAL but without TANGENT get generated tangents (sy_mesh_util.h).
 *
 * Ownership: the scene owns every created object. *info_out (if given) holds malloc()ed arrays the
 * caller releases with sy_gltf_info_free (also after a failed load; it is zeroed then).
 * Thread-safety: no global state. A load writes to `scene`, so calls on one scene must be serialised
 * like any other scene modification; loads into distinct scenes may run in parallel. */
#ifndef SY_GLTF_H
#define SY_GLTF_H

#include "sy_common.h"
#include "sy_scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Limits for untrusted files. Zero-initialise ({0}) for the defaults given per field. */
typedef struct sy_gltf_options {
    size_t max_file_bytes;      /**< .gltf / .glb and every external file; 0 = 2 GiB (max 4 GiB - 1) */
    size_t max_vertices;        /**< per primitive; 0 = 1 << 28 */
    size_t max_indices;         /**< per primitive, after strip / fan conversion; 0 = 1 << 28 */
    uint64_t max_image_pixels;  /**< width * height per image (larger ones: missing, warned); 0 = 1 << 26 */
    size_t max_instances;       /**< EXT_mesh_gpu_instancing instances per node; 0 = 1 << 20 */
    /** The file's budget (sy_budget.h): bytes of vertex data, indices, decoded images and
     * placements together; 0 = sy_budget_default_bytes(). An image past it goes missing with a
     * warning; geometry or placements past it fail the load with SY_ERR_LIMIT naming the item. */
    uint64_t max_scene_bytes;
    uint32_t max_json_depth;    /**< nesting of JSON arrays / objects; 0 = 64 */
    int32_t scene_index;        /**< glTF scene to load; 0 = the file's default (see below) */
    bool use_scene_index;       /**< true: load scenes[scene_index] instead of the default */
    /** Files named by buffer and image URIs must lie in the model file's folder (after symbolic
     * links and ".."; sy_path_confine in sy_file.h) or in one of these folders; absolute paths and
     * file: URIs only in these. A refused URI fails the load (SY_ERR_LIMIT) with a message naming
     * the file and the URI. Borrowed for the call. */
    const char *const *allowed_roots;
    size_t allowed_root_count; /**< entries of allowed_roots */
} sy_gltf_options;

#define SY_GLTF_MAX_WARNINGS 32 /**< messages kept; warning_count counts them all */

/** What the file contains (the whole file, not only the loaded scene). */
typedef struct sy_gltf_counts {
    /** @{ objects of each kind in the file, and triangles */
    uint32_t nodes, meshes, primitives, triangles, materials, textures, images, lights, cameras; /** @} */
    uint32_t skipped_primitives; /**< without POSITION, or without one complete element */
    /** @{ elements of POINTS and of LINES / LINE_LOOP / LINE_STRIP primitives */
    uint32_t points, line_segments; /** @} */
    uint32_t animations; /**< animations in the file (each one a sy_animation: sy_gltf_info.animations) */
} sy_gltf_counts;

/** One KHR_materials_variants mapping: primitive `primitive` (an index into the mesh's sy
 * primitives) of `mesh` takes `material` in variant `variant`; `default_material` is the material
 * the file gives it without a variant. */
typedef struct sy_gltf_variant_use {
    sy_mesh mesh; /**< the mesh of the primitive */
    uint32_t primitive; /**< index into the mesh's primitives */
    uint32_t variant; /**< index into sy_gltf_info.variant_names */
    sy_material material; /**< the primitive's material in that variant */
    sy_material default_material; /**< its material without a variant */
} sy_gltf_variant_use;

/** What a load produced: the root, camera nodes, warnings, counts and material variants
 * (sy_gltf_info_free). */
typedef struct sy_gltf_info {
    sy_node root;              /**< the new node whose children are the glTF scene's root nodes */
    int32_t scene_index;       /**< glTF scene loaded; -1: none given, all parentless nodes used */
    sy_node *camera_nodes;     /**< nodes with a camera, in glTF node order (malloc()ed) */
    uint32_t camera_node_count; /**< entries of camera_nodes */
    char **warnings;           /**< up to SY_GLTF_MAX_WARNINGS messages (malloc()ed); a successful load
                                  also logs them (sy_log.h, module "gltf") */
    uint32_t warning_count;    /**< total number of warnings (may exceed the stored ones) */
    uint32_t stored_warning_count; /**< entries of warnings */
    sy_gltf_counts counts; /**< what the file contains */
    char **variant_names;  /**< KHR_materials_variants names, "" for an unnamed one (malloc()ed) */
    uint32_t variant_count; /**< entries of variant_names */
    sy_gltf_variant_use *variant_uses; /**< every mapping, by mesh then primitive (malloc()ed) */
    uint32_t variant_use_count; /**< entries of variant_uses */
    char **extensions_used; /**< the file's extensionsUsed, in file order (malloc()ed); compare with
                                 sy_gltf_supported_extensions() for what this loader reads */
    uint32_t extensions_used_count; /**< entries of extensions_used */
    sy_animation *animations; /**< one per glTF animation, in file order (malloc()ed) */
    uint32_t animation_count; /**< entries of animations */
} sy_gltf_info;

/** Loads the glTF file at `path` into `scene`. The default glTF scene is `scene` of the file, else
 * scenes[0], else (no scenes) all parentless nodes. opts NULL = defaults; info_out and err may be
 * NULL. Result codes: SY_ERR_NOT_FOUND (file or external file missing), SY_ERR_IO, SY_ERR_PARSE
 * (malformed), SY_ERR_LIMIT (an option's limit or arithmetic overflow), SY_ERR_UNSUPPORTED
 * (extensionsRequired names an unsupported extension), SY_ERR_OUT_OF_MEMORY. */
sy_result sy_gltf_load(const char *path, sy_scene *scene, const sy_gltf_options *opts, sy_gltf_info *info_out,
                       sy_error *err);

/** Same from memory (size bytes at data, borrowed for the call): `name` is used in messages and, by
 * its ".glb" suffix, like the path above (GLB is also recognised by its magic); external URIs
 * resolve in base_dir ("" = the working directory, as for a path without a directory). The same
 * options and limits apply (max_file_bytes to size too). */
sy_result sy_gltf_load_memory(const void *data, size_t size, const char *name, const char *base_dir, sy_scene *scene,
                              const sy_gltf_options *opts, sy_gltf_info *info_out, sy_error *err);

/** Frees the arrays in *info and zeroes it. NULL-safe. */
void sy_gltf_info_free(sy_gltf_info *info);

/** Picks a camera node for a command-line style selector: a decimal index into info->camera_nodes,
 * else the first camera node whose node name or camera name equals `selector`. SY_ERR_NOT_FOUND
 * (message lists the available cameras) when nothing matches. */
sy_result sy_gltf_find_camera(const sy_scene *scene, const sy_gltf_info *info, const char *selector, sy_node *out,
                              sy_error *err);

/** Switches the material variant (KHR_materials_variants) of a loaded file: selector is a variant
 * name or a decimal index into info->variant_names; NULL or "" restores the file's default
 * materials. Every primitive the file maps takes the variant's material (its default where the
 * variant does not map it), set with sy_mesh_set_primitives so that the change reaches every
 * back-end through the change lists. SY_ERR_NOT_FOUND (the message lists the variants) when nothing
 * matches; SY_ERR_INVALID_HANDLE when a mapped mesh is gone. Not thread-safe with other writers of
 * the scene. */
sy_result sy_gltf_select_variant(sy_scene *scene, const sy_gltf_info *info, const char *selector, sy_error *err);

/** Names of the extensions this loader supports (for "extensionsRequired"), NULL-terminated. */
const char *const *sy_gltf_supported_extensions(void);

#ifdef __cplusplus
}
#endif
#endif /* SY_GLTF_H */
