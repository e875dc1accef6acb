/** @file
 * sy_assimp.h — the formats Switchyard reads through Assimp (Open Asset Import Library, Debian
 * libassimp 5.2): Wavefront OBJ + MTL, FBX, COLLADA, PLY, STL (ASCII and binary), 3MF, 3DS,
 * glTF 1.0 and whatever else Assimp reads (LightWave, AC3D, DirectX .x, OFF, Blender .blend, ...).
 * glTF 2.0 and X3D keep their own loaders (sy_gltf.h, sy_x3d.h). The load adds the file's scene to
 * a sy_scene through the public scene API, as the other loaders do.
 *
 * What is created: one new root node (named after the file) carrying the file's unit scale and up
 * axis (below), one node per Assimp node (its name and matrix; a node holding several meshes gets
 * one child node per mesh); one sy_mesh of one primitive per Assimp mesh (a mesh used by several
 * nodes stays one sy_mesh: instancing) — triangles (polygons triangulated), lines and points
 * (SY_TOPOLOGY_LINES / POINTS, as glTF's), with positions, normals, the first two texture
 * coordinate sets and the first colour set; one sy_material per Assimp material; one sy_texture
 * per (image, colour role); cameras and punctual lights on child nodes of the nodes Assimp names
 * for them. Every created node has SY_NODE_VISIBLE.
 *
 * Geometry goes through Assimp's own post-processing: GenSmoothNormals (normals where the file has
 * none, crease angle 80 degrees), SplitLargeMeshes (more than 10^6 triangles or vertices: several
 * meshes, as `assimp info` makes them), JoinIdenticalVertices, FindInvalidData, TransformUVCoords, FlipUVs
 * (texture v down, the scene's convention) and ValidateDataStructure while reading; Triangulate and
 * SortByPType (one primitive type per mesh) as a second pass once every face is checked to have
 * indices (a face without any is refused: Triangulate aborts the process on it); FindDegenerates
 * (triangles and segments repeating a vertex removed; no area test) as a third (with the others it crashes Assimp 5.2 on some
 * malformed files).
 * Normal-mapped primitives get generated tangents (sy_mesh_util.h, as glTF's).
 *
 * Materials (documented rule, docs/FORMATS.md): Assimp's PBR properties (base colour, metallic,
 * roughness factors, emissive intensity, transmission) are taken as they are. Classic materials
 * (Phong, Blinn, Gouraud, Lambert: OBJ / MTL, 3DS, COLLADA common profile, FBX, whose reader's
 * made-up roughness 1 - sqrt(shininess) / 10 is not taken for a PBR property): base colour =
 * diffuse colour, alpha = opacity (BLEND when below 1), emissive = emissive colour, metallic 0 (a
 * classic specular colour is a highlight strength, not a reflectance: Ks 0.5 is plain plastic),
 * roughness from the shininess exponent and the specular colour x shininess strength
 * (sy_classic.h: Ns 0 or a black specular -> 1, Ns 25.6 -> 0.54, Ns 128 -> 0.35, Ns 1000 -> 0.21);
 * ior from the refraction index only where the material transmits; double-sided from the
 * two-sided flag; shading model "no shading" -> unlit. Textures: diffuse / base colour -> base
 * colour texture (sRGB), emissive -> emissive texture (sRGB), normal map -> normal texture,
 * ambient occlusion -> occlusion texture; separate metalness / roughness maps -> one combined
 * metallic-roughness texture made on load (G = roughness map, B = metalness map, their first
 * channels; a missing map's channel 255; different sizes: the smaller resampled to the larger
 * with stb_image_resize and a warning; a mapped channel without a factor in the file gets factor
 * 1); other slots (specular, shininess, opacity, height / bump, displacement, light map,
 * reflection) are skipped with a warning. Textures are files in the model's folder (an OBJ's relative names first relative to the
 * folder of its MTL library, then to the model's; decoded with stb_image, sy_image.h) or
 * embedded in the file (Assimp's aiTexture: compressed ones decoded the same way, raw ones taken
 * as they are).
 *
 * Cameras: Assimp's horizontal field of view (the full angle, as Assimp 5.2's importers store it,
 * whatever its header says) becomes yfov for the file's aspect (4:3 when it has none); an
 * orthographic width becomes xmag / ymag (clip planes and widths in the camera node's units, as
 * every camera's). Lights (sy_classic.h): directional, point
 * and spot; the colour's largest component i is the classic intensity (the colour is divided by
 * it): directional i * pi lux, point / spot i * pi / q candela with quadratic attenuation q > 0
 * (q per squared file unit, converted to the scene's units),
 * else i * pi * d^2 with d the distance to the centre of the scene's bounds; ambient and area lights
 * are skipped with a warning.
 *
 * Units and up axis: where the file says (FBX "UnitScaleFactor": centimetres per unit; "UpAxis",
 * "FrontAxis", "CoordAxis" with their signs) the root node scales to metres and turns the file's
 * up axis to +Y, front to +Z and right to +X. COLLADA's unit and up axis are applied by Assimp
 * itself. Formats without such metadata (OBJ, STL, PLY, 3MF, 3DS) are taken as they are.
 * Skins, morph targets and animations (sy_assimp_anim.c; docs/FORMATS.md "Assimp formats"): the
 * same core objects as glTF's. Bones become joint indices and weights (at most 8 per vertex, the
 * largest, renormalised) and a skin on each node drawing the mesh (joints: the nodes named by the
 * bones; inverse bind: mOffsetMatrix); anim meshes become morph target deltas (Assimp's absolute
 * positions and normals minus the mesh's), their mWeight the default weights; each aiAnimation one
 * clip (times: ticks / mTicksPerSecond, 25 when 0) with LINEAR translation / rotation / scale
 * channels on the nodes named by its node channels (their matrices turned into TRS) and weights
 * channels for its morph channels; outside its keys a channel holds its end keys (LINEAR and
 * REPEAT pre / post states too, warned). Bad keys drop their channel with a warning.
 *
 * The import process: Assimp 5.2 crashes, aborts or loops on some malformed files (its fuzzers
 * keep finding such bugs), which no check before it can foresee. So each load runs in a child
 * process forked for it (sy_assimp_isolate.c): the child loads into its copy of the scene and sends
 * what it created back as a change list, which the caller applies to its scene at the same ids
 * (validated as a cluster peer's). A crash, an abort or a loop in Assimp ends the child and fails
 * the load with SY_ERR_PARSE naming the file and the signal; the child is held to
 * max_import_seconds of CPU, twice that plus 30 s of wall-clock time, and an address space of what
 * the caller had plus 1 GiB and 1024 bytes per byte of the model (zlib's largest expansion), at
 * most 1 GiB plus twice max_scene_bytes (past it: Assimp's std::bad_alloc, SY_ERR_PARSE, or the
 * signal, SY_ERR_LIMIT). Assimp's OutOfMemory.off test file now fails in 0.05 s; in the caller's
 * process it grew past 4 GB for more than 30 s. The child dies with its caller (PR_SET_PDEATHSIG).
 * A build with AddressSanitizer loads in the caller's process when the caller has other threads
 * (gcc 12's libasan deadlocks in a child forked from a multi-threaded process; glibc's malloc does
 * not). The caller's uncommitted changes stay uncommitted. Cost: the fork and one copy
 * of the created objects' data (sy bench load measures it).
 *
 * Untrusted input: the file itself is read once within max_file_bytes and handed to Assimp from
 * memory; every other file Assimp or the loader opens (MTL libraries, textures, COLLADA / FBX
 * references) goes through sy_path_confine (sy_file.h): it must lie in the model's folder or in an
 * allowed root, and a refused file fails the load naming the file and the way out (--allow-path).
 * Declared counts Assimp would allocate for before reading (PLY element counts, binary STL facet
 * counts) are checked against the bytes that carry them before Assimp sees the file. The scene's
 * budget (sy_budget.h) is charged for every mesh, image and placement before it is made. A file
 * Assimp cannot read fails with Assimp's own reason and the file name. What is skipped or
 * approximated is a warning naming the file and the item. Assimp's own log goes to sy_log at debug
 * level (module "assimp"), never to stdout.
 *
 * Ownership: the scene owns every created object; *info_out holds malloc()ed arrays released with
 * sy_assimp_info_free (also after a failed load). On failure nothing the call created remains.
 * Thread-safety: loads in import processes run in parallel. Assimp's C API keeps its error string
 * and logger in globals, so in_process loads, the reference import and the export are serialised
 * by one process-wide lock (loads of other formats are not affected). Calls on one scene must be
 * serialised as usual. */
#ifndef SY_ASSIMP_H
#define SY_ASSIMP_H

#include "sy_common.h"
#include "sy_scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Limits for untrusted files. Zero-initialise ({0}) for the defaults given per field. */
typedef struct sy_assimp_options {
    size_t max_file_bytes;     /**< the model and every file it names; 0 = 1 GiB */
    size_t max_vertices;       /**< per mesh; 0 = 1 << 28 */
    uint64_t max_image_pixels; /**< width x height per texture (larger ones: missing, warned); 0 = 1 << 26 */
    /** The file's budget (sy_budget.h): vertex data, indices, decoded images, placements; 0 =
     * sy_budget_default_bytes(). An image past it goes missing with a warning; geometry or
     * placements past it fail the load with SY_ERR_LIMIT naming the item. */
    uint64_t max_scene_bytes;
    /** Files the model names must lie in its folder (sy_path_confine) or in one of these folders.
     * Borrowed for the call. */
    const char *const *allowed_roots;
    size_t allowed_root_count; /**< entries of allowed_roots */
    /** CPU seconds the import process may use; 0 = 60 + 10 per MiB of the model. Its wall-clock
     * time is bounded by twice this plus 30 s. */
    unsigned max_import_seconds;
    /** Load in the calling process instead of the import process (see the file comment): a crash,
     * abort or endless loop inside Assimp then ends or blocks the caller. For fuzzing (the fuzzer
     * must see Assimp's code run) and debuggers; never for untrusted files in an application. */
    bool in_process;
} sy_assimp_options;

#define SY_ASSIMP_MAX_WARNINGS 32 /**< messages kept; warning_count counts them all */

/** What the file contains, as Assimp read it (after its post-processing). */
typedef struct sy_assimp_counts {
    /** @{ objects by kind; triangles of the triangle meshes */
    uint32_t nodes, meshes, triangles, materials, textures, embedded_textures, lights, cameras; /** @} */
    /** @{ elements of point and line meshes */
    uint32_t points, line_segments; /** @} */
    uint32_t skipped;    /**< meshes, lights and texture slots skipped (each also a warning) */
    /** @{ animations (clips), meshes with bones, their bones, morph targets (anim meshes), as the file has them */
    uint32_t animations, skinned_meshes, bones, morph_targets; /** @} */
} sy_assimp_counts;

/** What a load produced (sy_assimp_info_free). */
typedef struct sy_assimp_info {
    sy_node root;               /**< the new node above the file's root node */
    sy_node *camera_nodes;      /**< nodes with a camera, in Assimp's camera order (malloc()ed) */
    uint32_t camera_node_count; /**< entries of camera_nodes */
    char format[64];            /**< the importer Assimp chose ("Wavefront Object Importer", ...) */
    float unit_scale;           /**< metres per file unit applied on the root (1 when the file says nothing) */
    int up_axis;                /**< the file's up axis turned to +Y: 0 X, 1 Y, 2 Z; -1 not stated */
    char **warnings;            /**< up to SY_ASSIMP_MAX_WARNINGS messages (malloc()ed); a successful load
                                   also logs them (sy_log.h, module "assimp") */
    uint32_t warning_count;     /**< total number of warnings (may exceed the stored ones) */
    uint32_t stored_warning_count; /**< entries of warnings */
    sy_assimp_counts counts;    /**< what the file contains */
} sy_assimp_info;

/** Loads the file at path. opts NULL = defaults; info_out and err may be NULL. Results:
 * SY_ERR_NOT_FOUND, SY_ERR_IO, SY_ERR_PARSE (Assimp cannot read it: its reason), SY_ERR_LIMIT (a
 * limit, the budget, a refused path), SY_ERR_OUT_OF_MEMORY. */
sy_result sy_assimp_load(const char *path, sy_scene *scene, const sy_assimp_options *opts, sy_assimp_info *info_out,
                         sy_error *err);

/** Same from memory: `name` names the file in messages and tells Assimp the format by its
 * extension (content decides where the extension does not); files it names resolve in base_dir
 * ("" = the working directory) under the same confinement. */
sy_result sy_assimp_load_memory(const void *data, size_t size, const char *name, const char *base_dir, sy_scene *scene,
                                const sy_assimp_options *opts, sy_assimp_info *info_out, sy_error *err);

/** Frees the arrays in *info and zeroes it. NULL-safe. */
void sy_assimp_info_free(sy_assimp_info *info);

/** Assimp's own import of a trusted file, as `assimp info` makes it (Assimp 5.2's tools/assimp_cmd:
 * aiProcessPreset_TargetRealtime_MaxQuality, Assimp's own file system, none of this loader's
 * checks or confinement): the reference `sy bench load` times the loader against. counts_out
 * (may be NULL): meshes, triangles (faces of three indices), materials, embedded textures of
 * what Assimp returned. SY_ERR_PARSE with Assimp's reason. Same lock as the loads. */
sy_result sy_assimp_reference_import(const char *path, sy_assimp_counts *counts_out, sy_error *err);

/** Writes the trusted file `in` (read by Assimp with Triangulate only) to `out` through Assimp's
 * exporter `format_id` ("fbx" binary FBX, "fbxa", "obj", "collada", ...; aiGetExportFormatDescription):
 * how benchmarks and tests make files of formats no library here writes. SY_ERR_PARSE (cannot
 * read), SY_ERR_IO (the exporter failed, with its reason), SY_ERR_UNSUPPORTED (no such exporter). */
sy_result sy_assimp_export(const char *in, const char *format_id, const char *out, sy_error *err);

/** Whether Assimp reads files of this extension (".3ds", "lwo", case-insensitive). */
bool sy_assimp_reads_extension(const char *ext);

#ifdef __cplusplus
}
#endif
#endif /* SY_ASSIMP_H */
