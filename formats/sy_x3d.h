/** @file
 * sy_x3d.h — X3D loader (XML encoding, .x3d) on libxml2: adds the file's Scene to a sy_scene through
 * the public scene API, as the glTF loader does.
 *
 * Nodes: Scene, Transform (full center / scaleOrientation form), Group, StaticGroup, Collision,
 * Anchor, Billboard (as Group), Switch (whichChoice), LOD (first level), Shape, Appearance,
 * Material, PhysicalMaterial (X3D 4), CommonSurfaceShader (InstantReality / X3DOM extension),
 * ImageTexture (+ TextureProperties), TextureTransform, IndexedFaceSet (convex and concave polygons
 * ear-clipped, per-face / per-vertex normals and colours, creaseAngle, ccw, generated texture
 * coordinates), IndexedTriangleSet, TriangleSet, (Indexed)TriangleStripSet, (Indexed)TriangleFanSet,
 * (Indexed)QuadSet (per-vertex data only), Coordinate, Normal, TextureCoordinate,
 * MultiTextureCoordinate (first set), Color, ColorRGBA, Extrusion (crossSection / spine / scale /
 * orientation / caps, as an IndexedFaceSet), Box, Sphere, Cone, Cylinder (tessellated),
 * DirectionalLight, PointLight, SpotLight, Viewpoint, Background / TextureBackground (skyColor[0]),
 * Inline (relative files; each file is loaded once and shared), DEF / USE. TimeSensors with the
 * Position-, Orientation-, Color-, Scalar-, Coordinate- and NormalInterpolators and ROUTEs they
 * drive become animations (clips) of the scene clock, into Transform, Viewpoint, light and Material
 * fields and (as morph targets and weights) Coordinate points and Normal vectors (sy_x3d_anim.c,
 * docs/FORMATS.md); bad ROUTEs (undefined names, differing field types, loops) are dropped with a
 * warning naming the ROUTE's line. Non-visual nodes (WorldInfo, NavigationInfo, EXPORT, IMPORT,
 * metadata) are ignored silently; any other node type is skipped with one warning per type.
 *
 * Sharing: a USEd Shape (or a Shape whose geometry and appearance are both USEd) stays one sy_mesh
 * referenced by several nodes; a USEd grouping node is the same sy_node under several parents
 * (the scene is a DAG); a USEd Appearance stays one sy_material, a USEd ImageTexture one sy_texture.
 *
 * Mappings (documented choices):
 *   - Colours are taken as linear values (no sRGB decoding), as glTF factors are.
 *   - Material: base colour = diffuseColor, alpha = 1 - transparency (BLEND when < 1), emissive =
 *     emissiveColor, metallic 0. Roughness from the Blinn-Phong exponent n = 128 * shininess via
 *     alpha = sqrt(2 / (n + 2)), roughness = sqrt(alpha) (so shininess 0.2 -> 0.54, 1 -> 0.35);
 *     a black specularColor (the X3D default: no highlight) gives roughness 1. A Shape without
 *     Material is unlit white (X3D: lighting off).
 *   - CommonSurfaceShader: diffuseFactor (x diffuseTexture) -> base colour; emissiveFactor (x
 *     emissiveTexture) -> emissive; specularFactor / shininessFactor -> roughness as for Material;
 *     alphaFactor -> alpha; normalTexture (UNORM, TANGENT space; normalScale / normalBias other than
 *     2 / -1 are warned about) -> normal map with generated tangents; reflectionFactor r -> metallic
 *     = max(r) with base colour blended towards r; transmissionFactor t -> transmission = max(t);
 *     relativeIndexOfRefraction -> ior (values below 1 are inverted, i.e. taken as outside/inside).
 *   - Texture coordinates: X3D t points up the image; they are stored as v = 1 - t (scene
 *     convention). TextureTransform is applied to the coordinates (exactly, center included).
 *   - Lights: X3D intensity i is a fraction of full lighting; directional lights get i * pi lux
 *     (the irradiance that makes a white Lambertian surface reflect i); point and spot lights get
 *     i * pi * d^2 candela where d is the distance from the light to the centre of the scene bounds
 *     (so the scene centre is lit as X3D's unattenuated light would light it); a quadratic
 *     attenuation a2 > 0 instead gives i * pi / a2. Lights are global (X3D scoping is not kept).
 *   - Viewpoint fieldOfView is the angle of the SMALLER image side; the camera stores it as yfov
 *     (right for landscape images) and sy_x3d_fit_cameras adapts yfov for a given aspect.
 *
 * Bad input: malformed XML fails the load with file:line and libxml2's reason. Local problems are
 * warnings naming file:line and the rest loads: USE of an undefined DEF, a DEF/USE or Inline cycle,
 * indices past the coordinate / normal / colour / texcoord lists (that geometry is skipped),
 * non-numeric field values (the field is ignored), a texture that cannot be read or decoded (it
 * becomes no texture), a missing Inline file.
 * Untrusted input: URLs are resolved against the file's directory (absolute paths as given; remote
 * URLs and data: are skipped) and only regular files are read (no devices / FIFOs);
 * no network access, no external entities or DTD loading, XML nesting limited by
 * libxml2's defaults, file sizes / vertex counts / image pixels / Inline depth capped (options).
 *
 * Ownership: the scene owns every created object; *info_out holds malloc()ed arrays released with
 * sy_x3d_info_free (also after a failed load). On failure nothing the call created remains.
 * Thread-safety: no global state of ours; libxml2 is initialised on first use (xmlInitParser is
 * thread-safe). Loads into distinct scenes may run in parallel. */
#ifndef SY_X3D_H
#define SY_X3D_H

#include "sy_common.h"
#include "sy_scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Limits for untrusted files. Zero-initialise ({0}) for the defaults given per field. */
typedef struct sy_x3d_options {
    size_t max_file_bytes;     /**< each .x3d / image file; 0 = 1 GiB */
    size_t max_vertices;       /**< per geometry node, after triangulation; 0 = 1 << 27 */
    uint64_t max_image_pixels; /**< width * height; 0 = 1 << 26 */
    uint32_t max_inline_depth; /**< nesting of Inline files; 0 = 16 */
    /** The load's budget (sy_budget.h), Inline files included: vertices of every geometry node as
     * made, decoded images, and placements (USE and Inline fan-out counted per path); 0 =
     * sy_budget_default_bytes(). An image past it goes missing with a warning; geometry or
     * placements past it fail the load with SY_ERR_LIMIT naming the file, line and node. */
    uint64_t max_scene_bytes;
    /** Files named by Inline and ImageTexture urls must lie in the top-level file's folder (after
     * symbolic links and ".."; sy_path_confine in sy_file.h) or in one of these folders; absolute
     * paths and file: URLs only in these. A refused url fails the load (SY_ERR_LIMIT) with a
     * message naming the file, line and url. Borrowed for the call. */
    const char *const *allowed_roots;
    size_t allowed_root_count; /**< entries of allowed_roots */
} sy_x3d_options;

#define SY_X3D_MAX_WARNINGS 32 /**< messages kept in sy_x3d_info; warning_count counts them all */

/** What was loaded (Inline files included, shared objects counted once). */
typedef struct sy_x3d_counts {
    /** @{ objects created, by kind, and triangles; Inline files loaded */
    uint32_t nodes, meshes, primitives, triangles, materials, textures, lights, cameras, inlines; /** @} */
    uint32_t skipped_geometry; /**< geometry nodes skipped (unsupported type or bad data) */
    /** @{ elements of PointSet and of (Indexed)LineSet primitives */
    uint32_t points, line_segments; /** @} */
    uint32_t texts;                 /**< Text nodes loaded */
    uint32_t animations;            /**< TimeSensors played as clips by the scene clock (sy_x3d_anim.c) */
} sy_x3d_counts;

/** What a load produced: the root, cameras, background, warnings and counts (sy_x3d_info_free). */
typedef struct sy_x3d_info {
    sy_node root;              /**< new node for the Scene element */
    sy_node *camera_nodes;     /**< Viewpoint nodes in document order (malloc()ed); [0] is the bound one */
    float *camera_fovs;        /**< their fieldOfView (radians) */
    uint32_t camera_node_count; /**< entries of camera_nodes and camera_fovs */
    sy_background background;  /**< first Background, {0} when none */
    char **warnings;           /**< up to SY_X3D_MAX_WARNINGS messages (malloc()ed); a successful load
                                  also logs them (sy_log.h, module "x3d") */
    uint32_t warning_count;    /**< total, may exceed the stored ones */
    uint32_t stored_warning_count; /**< entries of warnings */
    sy_x3d_counts counts; /**< what was loaded */
} sy_x3d_info;

/** Loads the .x3d file at path. opts NULL = defaults; info_out and err may be NULL. Results:
 * SY_ERR_NOT_FOUND, SY_ERR_IO, SY_ERR_PARSE (not XML, or no X3D / Scene element), SY_ERR_LIMIT,
 * SY_ERR_OUT_OF_MEMORY. */
sy_result sy_x3d_load(const char *path, sy_scene *scene, const sy_x3d_options *opts, sy_x3d_info *info_out,
                      sy_error *err);

/** Same from memory: `name` is used in messages, base_dir ("" = none: Inline and textures are then
 * looked up relative to the current directory) resolves relative URLs. */
sy_result sy_x3d_load_memory(const void *data, size_t size, const char *name, const char *base_dir,
                             sy_scene *scene, const sy_x3d_options *opts, sy_x3d_info *info_out, sy_error *err);

void sy_x3d_info_free(sy_x3d_info *info); /**< NULL-safe; zeroes *info */

/** The vertical field of view that shows fov across the smaller image side for an image of
 * aspect = width / height. */
float sy_x3d_yfov(float fov, float aspect);

/** Sets the yfov of every Viewpoint camera in info for an image of the given aspect; a camera whose
 * yfov an animation drives (a ROUTE to Viewpoint.fieldOfView) is left to the clock, which sets the
 * routed angle as yfov (right for landscape images). */
sy_result sy_x3d_fit_cameras(sy_scene *scene, const sy_x3d_info *info, float aspect, sy_error *err);

/** Picks a Viewpoint: decimal index into camera_nodes or a node name (the DEF or description). */
sy_result sy_x3d_find_camera(const sy_scene *scene, const sy_x3d_info *info, const char *selector, sy_node *out,
                             sy_error *err);

#ifdef __cplusplus
}
#endif
#endif /* SY_X3D_H */
