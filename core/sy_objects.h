/** @file
 * sy_objects.h — the scene's objects: handles, the eight object types (node, mesh, material,
 * texture, light, camera, background, animation) with their data structs and numbered fields, attachments,
 * and the calls that create, change, read and destroy objects of a scene (sy_scene.h).
 *
 * Each type has a plain data struct (sy_node_data, ...) and an enumerated list of fields, one bit
 * each. Setters are the only way to change a field; each validates the value and marks the field
 * dirty when it differs (sy_commit.h seals dirty fields into change lists).
 *
 * Handles: one-field structs {uint32_t id}; id = generation << SY_HANDLE_INDEX_BITS | index.
 * id 0 is never valid. A destroyed object's slot gets a new generation when reused, so a stale
 * handle is detected (SY_ERR_INVALID_HANDLE), never dereferenced. Overflow policy: a slot whose
 * generation reaches its maximum is retired and never reused.
 *
 * Ownership: the scene owns every object and everything stored in fields (strings are copied,
 * blobs retained). Getters return borrowed pointers valid until the next modification of that
 * object or the destruction of the scene.
 * Thread-safety: as the scene (sy_scene.h): all calls on one scene serialised by the caller. */
#ifndef SY_OBJECTS_H
#define SY_OBJECTS_H

#include "sy_blob.h"
#include "sy_common.h"
#include "sy_math.h"

#ifdef __cplusplus
extern "C" {
#endif


#define SY_HANDLE_INDEX_BITS 22u /**< bits of a handle id that hold the slot index */
#define SY_HANDLE_INDEX_MASK ((1u << SY_HANDLE_INDEX_BITS) - 1u) /**< mask of the slot index in a handle id */
#define SY_HANDLE_MAX_GENERATION ((1u << (32u - SY_HANDLE_INDEX_BITS)) - 1u) /**< largest generation; a slot that reaches it is retired */


/** The application-side scene graph (opaque). */
typedef struct sy_scene sy_scene;
/** Handle of a node. */
typedef struct sy_node { uint32_t id; /**< index + generation; 0 = none */ } sy_node;
/** Handle of a mesh. */
typedef struct sy_mesh { uint32_t id; /**< index + generation; 0 = none */ } sy_mesh;
/** Handle of a material. */
typedef struct sy_material { uint32_t id; /**< index + generation; 0 = none */ } sy_material; /**< id 0: the default material */
/** Handle of a texture. */
typedef struct sy_texture { uint32_t id; /**< index + generation; 0 = none */ } sy_texture;
/** Handle of a light. */
typedef struct sy_light { uint32_t id; /**< index + generation; 0 = none */ } sy_light;
/** Handle of a camera. */
typedef struct sy_camera { uint32_t id; /**< index + generation; 0 = none */ } sy_camera;
/** Handle of a background (the world). */
typedef struct sy_background { uint32_t id; /**< index + generation; 0 = none */ } sy_background;
/** Handle of an animation (one clip: samplers and channels; sy_anim.h plays it). */
typedef struct sy_animation { uint32_t id; /**< index + generation; 0 = none */ } sy_animation;

/** Object types; the order is the dependency order (referenced types first). */
typedef enum sy_object_type {
    SY_TYPE_NONE = 0,
    SY_TYPE_TEXTURE = 1, /**< order = dependency order: referenced types first */
    SY_TYPE_MATERIAL = 2,
    SY_TYPE_MESH = 3,
    SY_TYPE_LIGHT = 4,
    SY_TYPE_CAMERA = 5,
    SY_TYPE_BACKGROUND = 6,
    SY_TYPE_NODE = 7,
    SY_TYPE_ANIMATION = 8, /**< after nodes: its channels name nodes */
    SY_TYPE_COUNT = 9
} sy_object_type;

const char *sy_object_type_name(sy_object_type t); /**< "node", "mesh", ... */

#define SY_BIT(field) (1ull << (field)) /**< the dirty-mask bit of a field number */
/** Fields common to every type. */
#define SY_FIELD_NAME 0u         /**< char *name (copied; may be NULL) */
#define SY_FIELD_ATTACHMENTS 63u /**< the attachment set (see below) */

/* ---------------------------------------------------------------- node */
/** How a node's local transform is given. */
typedef enum sy_transform_mode { SY_TRANSFORM_TRS = 0, SY_TRANSFORM_MATRIX = 1 } sy_transform_mode;

/** A node's local transform: TRS or a matrix. */
typedef struct sy_transform {
    uint32_t mode;         /**< sy_transform_mode */
    float translation[3];  /**< TRS (valid when mode == TRS) */
    float rotation[4];     /**< unit quaternion x, y, z, w */
    float scale[3]; /**< scale x, y, z (TRS) */
    sy_mat4 matrix;        /**< always valid: the local matrix (from TRS when mode == TRS) */
} sy_transform;

/** Node flags (SY_NODE_FLAGS field). */
typedef enum sy_node_flags {
    SY_NODE_VISIBLE = 1u << 0,
    SY_NODE_STATIC = 1u << 1,   /**< hint: transform rarely changes (merge into a static BVH) */
    SY_NODE_ANIMATED = 1u << 2, /**< hint: transform or mesh changes often */
    /** Selected: the node and its subtree are highlighted alike by every back-end (mediators/
     * sy_highlight.h: the pixels they cover blended halfway toward the selection colour, and a
     * one-pixel outline of that colour around them). Changes nothing else (shading, shadows,
     * picks, coverage). Change-list version 6. */
    SY_NODE_SELECTED = 1u << 3,
} sy_node_flags;

/** Field numbers of a node. */
enum sy_node_field {
    SY_NODE_NAME = 0,
    SY_NODE_TRANSFORM = 1, /**< sy_transform */
    SY_NODE_CHILDREN = 2,  /**< sy_blob* of uint32 node ids (NULL = none) */
    SY_NODE_MESH = 3,      /**< sy_mesh */
    SY_NODE_LIGHT = 4,     /**< sy_light */
    SY_NODE_CAMERA = 5,    /**< sy_camera */
    SY_NODE_FLAGS = 6,     /**< uint32 sy_node_flags */
    SY_NODE_WEIGHTS = 7,   /**< sy_blob* of float morph weights of the node's mesh (NULL = the mesh's; glTF node.weights) */
    SY_NODE_SKIN = 8,      /**< sy_blob* of sy_skin_joint: the skin of the node's mesh (NULL = none; glTF node.skin) */
    SY_NODE_SKELETON = 9,  /**< sy_node: the skin's skeleton root ({0}: none; informative, glTF skin.skeleton) */
    SY_NODE_FIELD_COUNT = 10
};

/** One joint of a skin (the SY_NODE_SKIN blob; 68 bytes, little endian on the wire like all POD). */
typedef struct sy_skin_joint {
    uint32_t node;     /**< the joint node (sy_node.id) */
    sy_mat4 inverse_bind; /**< its inverse bind matrix (glTF skin.inverseBindMatrices; identity when absent) */
} sy_skin_joint;

/** Field values of a node. */
typedef struct sy_node_data {
    char *name; /**< name (copied; may be NULL) */
    sy_transform transform; /**< local transform */
    sy_blob *children; /**< uint32 node ids; use sy_node_children() to read */
    sy_mesh mesh; /**< mesh instanced here ({0}: none) */
    sy_light light; /**< light attached here ({0}: none) */
    sy_camera camera; /**< camera attached here ({0}: none) */
    uint32_t flags; /**< sy_node_flags */
    sy_blob *weights; /**< float morph weights (NULL = the mesh's) */
    sy_blob *skin; /**< sy_skin_joint[] (NULL = not skinned) */
    sy_node skeleton; /**< skeleton root of the skin ({0}: none) */
} sy_node_data;

/* ---------------------------------------------------------------- mesh */
/** What a primitive's indices (or, without indices, its vertices in order) form. */
typedef enum sy_topology {
    SY_TOPOLOGY_TRIANGLES = 0, /**< triples: indices uint32[3 * n] (default) */
    SY_TOPOLOGY_LINES = 1,     /**< pairs: each pair is one straight segment, indices uint32[2 * n] */
    SY_TOPOLOGY_POINTS = 2,    /**< each index (or vertex) is one point */
    SY_TOPOLOGY_COUNT = 3
} sy_topology;

/** One primitive. Fixed vertex formats; every present attribute has vertex_count elements:
 * positions float[3] (required), normals float[3], tangents float[4], texcoords float[2], colors
 * float[4] (linear RGBA), indices uint32 (NULL: non-indexed). Triangles: indices hold whole
 * triples (without indices vertex_count must be a multiple of 3). Lines: indices hold whole pairs
 * (without indices an even vertex_count). Points: any count.
 *
 * Triangles without normals (normals NULL) are flat-shaded: every back-end shades each triangle
 * with its geometric normal, its front the side from which its corners run counter-clockwise
 * (clockwise under a node transform of negative determinant), as glTF 2.0 specifies for a
 * primitive without NORMAL. Such a primitive keeps its shared vertices and its indices; nobody
 * needs to de-index it to give each face its own normal. Tangents are carried along (file writers)
 * but no back-end reads them: a normal map's tangent frame comes from the uv derivatives across
 * the triangle, with or without normals.
 *
 * Strokes (lines and points) have a width: the diameter of the tube drawn along each segment and
 * of the ball drawn at each point and line joint, in the primitive's own coordinate units (the
 * node transforms scale it with the positions, so it is a world-space width under unscaled
 * transforms). Every back-end draws strokes as the same triangle geometry (the scene mirror
 * tessellates them, mediators/sy_strokes.h), so they cover the same pixels in the rasterizer and
 * the ray tracers. The width rule, sy_primitive_stroke_width:
 *   - width > 0: that width;
 *   - width == 0 (default): SY_STROKE_LINE_FRACTION (lines) or SY_STROKE_POINT_FRACTION (points)
 *     times the diagonal of the primitive's position bounds, at least SY_STROKE_MIN_WIDTH.
 *     (The Khronos MeshPrimitiveModes sample, 1.73 x 2 units per primitive (diagonal 2.65), gets
 *     0.159-unit lines and 0.318-unit points: about 2 and 4 pixels in `sy render -w 200 -h 150`.)
 * Normals, tangents and the material's normal map of a stroke are not used: a stroke is lit as a
 * tube / ball with the tessellation's own normals; texcoords and colours are carried along. */
#define SY_STROKE_LINE_FRACTION 0.06f
#define SY_STROKE_POINT_FRACTION 0.12f /**< default point diameter as a fraction of the bounds diagonal */
#define SY_STROKE_MIN_WIDTH 0.001f /**< smallest default stroke width */
/** One primitive of a mesh: vertex attributes in blobs, a material, a topology (see above). */
typedef struct sy_primitive {
    sy_blob *positions; /**< float[3] per vertex (required) */
    sy_blob *normals; /**< float[3] per vertex, or NULL */
    sy_blob *tangents; /**< float[4] per vertex, or NULL */
    sy_blob *texcoords0; /**< float[2] per vertex (set 0), or NULL */
    sy_blob *texcoords1; /**< float[2] per vertex (set 1), or NULL */
    sy_blob *colors; /**< float[4] linear RGBA per vertex, or NULL */
    sy_blob *indices; /**< uint32 indices, or NULL (non-indexed) */
    sy_material material; /**< {0}: default material */
    uint32_t topology;    /**< sy_topology */
    float width;          /**< strokes: diameter (finite, >= 0; 0 = the default rule above) */
    sy_blob *joints;      /**< skin: uint32 joint indices (into the skin of the node instancing the mesh), influences per vertex, or NULL */
    sy_blob *weights;     /**< skin: float weights, influences per vertex (present exactly when joints is), or NULL */
    sy_blob *target_positions; /**< morph targets: float[3] position deltas, vertex_count per target, target after target, or NULL */
    sy_blob *target_normals;   /**< morph targets: float[3] normal deltas (layout as target_positions), or NULL */
    sy_blob *target_tangents;  /**< morph targets: float[3] tangent xyz deltas (layout as target_positions), or NULL */
    sy_blob *target_texcoords0; /**< morph targets: float[2] texture coordinate (set 0) deltas, vertex_count per
                                     target, target after target, or NULL (X3D's animated TextureTransform and
                                     TextureCoordinate: needs texcoords0) */
} sy_primitive;

/** Skins and morph targets (glTF 2.0 "Skins" and "Morph Targets"). A primitive may carry
 * per-vertex joint indices and weights (joints and weights: `influences` values per vertex, 1 to
 * SY_SKIN_MAX_INFLUENCES: glTF's JOINTS_0/WEIGHTS_0, then JOINTS_1/WEIGHTS_1, interleaved per
 * vertex) and morph target deltas (target_positions / target_normals / target_tangents /
 * target_texcoords0: the same number of targets in each present blob, at most SY_MORPH_MAX_TARGETS). The setters check sizes,
 * finiteness and counts; joint indices are checked against the skin where it is used (a vertex
 * whose joint index is past its node's skin is drawn in its bind pose, undeformed). The values that
 * drive them are node fields: SY_NODE_SKIN (the joints and their inverse bind matrices) and
 * SY_NODE_WEIGHTS (morph weights; NULL = the mesh's SY_MESH_WEIGHTS; missing weights are 0).
 * The scene mirror deforms (mediators/sy_mirror.h): position = sum_j w_j (J_j x IBM_j) (p + sum_t
 * weight_t dp_t), normals likewise with the inverse transpose, texture coordinates (set 0) uv +
 * sum_t weight_t duv_t, so every back-end draws the same pose. A skinned mesh's node transform is ignored, as glTF says: its joints place it. */
#define SY_SKIN_MAX_INFLUENCES 8u   /**< joints per vertex (JOINTS_0 + JOINTS_1) */
#define SY_SKIN_MAX_JOINTS 65536u   /**< joints of one skin */
#define SY_MORPH_MAX_TARGETS 256u   /**< morph targets of one primitive (= SY_ANIM_MAX_COMPONENTS) */
/** Joint influences per vertex of a primitive (0 without joints). */
uint32_t sy_primitive_influences(const sy_primitive *p);
/** Morph targets of a primitive (0 without). */
uint32_t sy_primitive_target_count(const sy_primitive *p);

/** Field numbers of a mesh. */
enum sy_mesh_field {
    SY_MESH_NAME = 0,
    SY_MESH_PRIMITIVES = 1, /**< sy_primitive_list */
    SY_MESH_WEIGHTS = 2,    /**< sy_blob* of float default morph weights (glTF mesh.weights; NULL = all 0) */
    SY_MESH_FIELD_COUNT = 3
};

/** An array of primitives (the SY_MESH_PRIMITIVES field). */
typedef struct sy_primitive_list {
    sy_primitive *items; /**< the primitives */
    uint32_t count; /**< number of primitives */
} sy_primitive_list;

/** Field values of a mesh. */
typedef struct sy_mesh_data {
    char *name; /**< name (copied; may be NULL) */
    sy_primitive_list primitives; /**< the primitives */
    sy_blob *weights; /**< float default morph weights, one per target (NULL = all 0) */
} sy_mesh_data;

/** Vertices of a primitive (elements of its positions blob). */
uint32_t sy_primitive_vertex_count(const sy_primitive *p);
/** Triangles of a triangle primitive; 0 for lines and points (their tessellation is the mirror's). */
uint32_t sy_primitive_triangle_count(const sy_primitive *p);
/** Elements of any topology: triangles, segments or points. */
uint32_t sy_primitive_element_count(const sy_primitive *p);
/** Position bounds of the primitive, without the stroke width (empty when it has no positions). */
sy_bounds sy_primitive_position_bounds(const sy_primitive *p);
/** The stroke width of a line or point primitive by the rule above; primitive_bounds are its
 * position bounds (sy_primitive_position_bounds; NULL = computed here). 0 for triangles. */
float sy_primitive_stroke_width(const sy_primitive *p, const sy_bounds *primitive_bounds);
/** Releases the primitive's blob references (NULL ones are skipped) and zeroes it. */
void sy_primitive_release(sy_primitive *p);

/* ---------------------------------------------------------------- material (glTF 2.0 metallic-roughness) */
/** glTF alpha modes. */
typedef enum sy_alpha_mode { SY_ALPHA_OPAQUE = 0, SY_ALPHA_MASK = 1, SY_ALPHA_BLEND = 2 } sy_alpha_mode;

/** A material's reference to a texture, with its coordinate set and KHR_texture_transform. */
typedef struct sy_texture_ref {
    sy_texture texture; /**< {0}: none */
    uint32_t texcoord;  /**< which texcoord set (0 or 1) */
    float scale;        /**< normal scale / occlusion strength; 1 otherwise */
    float offset[2];    /**< KHR_texture_transform: uv' = T(offset) R(rotation) S(uv_scale) uv */
    float rotation; /**< KHR_texture_transform rotation (radians) */
    float uv_scale[2]; /**< KHR_texture_transform scale */
} sy_texture_ref;
/** The texture-coordinate transform of r as a row-major 2x3 affine matrix (u' = m0 u + m1 v + m2,
 * v' = m3 u + m4 v + m5); returns false when it is the identity. */
bool sy_texture_ref_matrix(const sy_texture_ref *r, float m[6]);

/** Field numbers of a material. */
enum sy_material_field {
    SY_MATERIAL_NAME = 0,
    SY_MATERIAL_BASE_COLOR = 1,          /**< float[4] linear RGBA factor */
    SY_MATERIAL_BASE_COLOR_TEXTURE = 2,  /**< sy_texture_ref */
    SY_MATERIAL_METALLIC = 3,            /**< float */
    SY_MATERIAL_ROUGHNESS = 4,           /**< float */
    SY_MATERIAL_METALLIC_ROUGHNESS_TEXTURE = 5,
    SY_MATERIAL_NORMAL_TEXTURE = 6,
    SY_MATERIAL_OCCLUSION_TEXTURE = 7,
    SY_MATERIAL_EMISSIVE = 8,            /**< float[3] factor */
    SY_MATERIAL_EMISSIVE_STRENGTH = 9,   /**< float (KHR_materials_emissive_strength) */
    SY_MATERIAL_EMISSIVE_TEXTURE = 10,
    SY_MATERIAL_ALPHA_MODE = 11,         /**< uint32 sy_alpha_mode */
    SY_MATERIAL_ALPHA_CUTOFF = 12,       /**< float */
    SY_MATERIAL_DOUBLE_SIDED = 13,       /**< uint32 0/1 */
    SY_MATERIAL_TRANSMISSION = 14,       /**< float (KHR_materials_transmission) */
    SY_MATERIAL_TRANSMISSION_TEXTURE = 15,
    SY_MATERIAL_IOR = 16,                /**< float (KHR_materials_ior) */
    SY_MATERIAL_UNLIT = 17,              /**< uint32 0/1 (KHR_materials_unlit) */
    /* KHR_materials_specular */
    SY_MATERIAL_SPECULAR = 18,                 /**< float specularFactor (default 1) */
    SY_MATERIAL_SPECULAR_TEXTURE = 19,         /**< sy_texture_ref (A) */
    SY_MATERIAL_SPECULAR_COLOR = 20,           /**< float[3] specularColorFactor (default 1, 1, 1) */
    SY_MATERIAL_SPECULAR_COLOR_TEXTURE = 21,   /**< sy_texture_ref (RGB, sRGB) */
    /* KHR_materials_clearcoat */
    SY_MATERIAL_CLEARCOAT = 22,                /**< float clearcoatFactor (default 0: no coat) */
    SY_MATERIAL_CLEARCOAT_TEXTURE = 23,        /**< sy_texture_ref (R) */
    SY_MATERIAL_CLEARCOAT_ROUGHNESS = 24,      /**< float (default 0) */
    SY_MATERIAL_CLEARCOAT_ROUGHNESS_TEXTURE = 25, /**< sy_texture_ref (G) */
    SY_MATERIAL_CLEARCOAT_NORMAL_TEXTURE = 26, /**< sy_texture_ref (tangent space; scale = normal scale) */
    /* KHR_materials_sheen */
    SY_MATERIAL_SHEEN_COLOR = 27,              /**< float[3] sheenColorFactor (default 0: no sheen) */
    SY_MATERIAL_SHEEN_COLOR_TEXTURE = 28,      /**< sy_texture_ref (RGB, sRGB) */
    SY_MATERIAL_SHEEN_ROUGHNESS = 29,          /**< float (default 0) */
    SY_MATERIAL_SHEEN_ROUGHNESS_TEXTURE = 30,  /**< sy_texture_ref (A) */
    /* KHR_materials_volume */
    SY_MATERIAL_THICKNESS = 31,                /**< float thicknessFactor (default 0: thin-walled) */
    SY_MATERIAL_THICKNESS_TEXTURE = 32,        /**< sy_texture_ref (G) */
    SY_MATERIAL_ATTENUATION_DISTANCE = 33,     /**< float (0, the default, = infinite: no absorption) */
    SY_MATERIAL_ATTENUATION_COLOR = 34,        /**< float[3] (default 1, 1, 1) */
    /* KHR_materials_iridescence */
    SY_MATERIAL_IRIDESCENCE = 35,              /**< float iridescenceFactor (default 0) */
    SY_MATERIAL_IRIDESCENCE_TEXTURE = 36,      /**< sy_texture_ref (R) */
    SY_MATERIAL_IRIDESCENCE_IOR = 37,          /**< float (default 1.3) */
    SY_MATERIAL_IRIDESCENCE_THICKNESS = 38,    /**< float[2] film thickness minimum, maximum in nm (100, 400) */
    SY_MATERIAL_IRIDESCENCE_THICKNESS_TEXTURE = 39, /**< sy_texture_ref (G: minimum to maximum) */
    /* KHR_materials_anisotropy */
    SY_MATERIAL_ANISOTROPY = 40,               /**< float anisotropyStrength (default 0) */
    SY_MATERIAL_ANISOTROPY_ROTATION = 41,      /**< float radians, any finite value (default 0) */
    SY_MATERIAL_ANISOTROPY_TEXTURE = 42,       /**< sy_texture_ref (RG direction, B strength) */
    SY_MATERIAL_FIELD_COUNT = 43
};


/** Field values of a material (glTF 2.0 metallic-roughness). */
typedef struct sy_material_data {
    char *name; /**< name (copied; may be NULL) */
    float base_color[4]; /**< linear RGBA factor */
    sy_texture_ref base_color_texture; /**< base colour texture (sRGB) */
    float metallic; /**< metallic factor */
    float roughness; /**< roughness factor */
    sy_texture_ref metallic_roughness_texture; /**< metallic (B) and roughness (G) texture */
    sy_texture_ref normal_texture; /**< tangent-space normal map (scale = normal scale) */
    sy_texture_ref occlusion_texture; /**< occlusion texture (R; scale = strength) */
    float emissive[3]; /**< emissive factor, linear RGB */
    float emissive_strength; /**< KHR_materials_emissive_strength multiplier */
    sy_texture_ref emissive_texture; /**< emissive texture (sRGB) */
    uint32_t alpha_mode; /**< sy_alpha_mode */
    float alpha_cutoff; /**< alpha cutoff of SY_ALPHA_MASK */
    uint32_t double_sided; /**< 1 = both faces are front faces */
    float transmission; /**< KHR_materials_transmission factor */
    sy_texture_ref transmission_texture; /**< transmission texture (R) */
    float ior; /**< index of refraction (KHR_materials_ior) */
    uint32_t unlit; /**< 1 = KHR_materials_unlit */
    float specular; /**< KHR_materials_specular: strength of the dielectric specular layer */
    sy_texture_ref specular_texture; /**< (A) x specular */
    float specular_color[3]; /**< colour of the dielectric F0 (linear) */
    sy_texture_ref specular_color_texture; /**< (RGB, sRGB) x specular_color */
    float clearcoat; /**< KHR_materials_clearcoat: coat layer weight, 0 = none */
    sy_texture_ref clearcoat_texture; /**< (R) x clearcoat */
    float clearcoat_roughness; /**< the coat's roughness */
    sy_texture_ref clearcoat_roughness_texture; /**< (G) x clearcoat_roughness */
    sy_texture_ref clearcoat_normal_texture; /**< the coat's normal map (none: the geometric normal) */
    float sheen_color[3]; /**< KHR_materials_sheen colour (linear), 0 = none */
    sy_texture_ref sheen_color_texture; /**< (RGB, sRGB) x sheen_color */
    float sheen_roughness; /**< sheen roughness */
    sy_texture_ref sheen_roughness_texture; /**< (A) x sheen_roughness */
    float thickness; /**< KHR_materials_volume thickness in the mesh's units; 0 = thin-walled */
    sy_texture_ref thickness_texture; /**< (G) x thickness */
    float attenuation_distance; /**< distance at which light has the attenuation colour; 0 = infinite */
    float attenuation_color[3]; /**< colour white light turns after attenuation_distance (linear) */
    float iridescence; /**< KHR_materials_iridescence thin-film weight, 0 = none */
    sy_texture_ref iridescence_texture; /**< (R) x iridescence */
    float iridescence_ior; /**< the film's index of refraction */
    float iridescence_thickness[2]; /**< film thickness in nm: minimum, maximum */
    sy_texture_ref iridescence_thickness_texture; /**< (G) mixes minimum to maximum; none: maximum */
    float anisotropy; /**< KHR_materials_anisotropy strength, 0 = isotropic */
    float anisotropy_rotation; /**< rotation of the direction from the tangent, radians (counter-clockwise) */
    sy_texture_ref anisotropy_texture; /**< RG direction in tangent space ([-1, 1] as [0, 1]), B x strength */
} sy_material_data;

/** The texture slots of a material: every sy_texture_ref field, in field order. */
#define SY_MATERIAL_TEXTURE_SLOTS 17
/** Field numbers of the SY_MATERIAL_TEXTURE_SLOTS texture references (read-only). */
extern const uint32_t sy_material_texture_fields[SY_MATERIAL_TEXTURE_SLOTS];
/** Texture reference of field f of d (a field of sy_material_texture_fields), else NULL. */
const sy_texture_ref *sy_material_texture(const sy_material_data *d, uint32_t f);
/** Whether any texture slot of d refers to texture id tex (tex != 0). */
bool sy_material_uses_texture(const sy_material_data *d, uint32_t tex);

/* ---------------------------------------------------------------- texture */
/** Pixel formats of a texture. */
typedef enum sy_pixel_format {
    SY_PIXEL_U8_SRGB = 1,   /**< 8-bit, sRGB-encoded colour (alpha linear) */
    SY_PIXEL_U8_LINEAR = 2, /**< 8-bit, linear data (normals, metallic-roughness) */
    SY_PIXEL_F32 = 3,       /**< float, linear */
} sy_pixel_format;

/** Texture wrap modes (glTF sampler). */
typedef enum sy_wrap { SY_WRAP_REPEAT = 0, SY_WRAP_CLAMP = 1, SY_WRAP_MIRROR = 2 } sy_wrap;
/** Texture filters (glTF sampler). */
typedef enum sy_filter { SY_FILTER_LINEAR = 0, SY_FILTER_NEAREST = 1 } sy_filter;

/** Size and layout of a texture's pixels: all zero = no image yet; an image with a size has 1 to 4
 * channels and one of the formats (the setters refuse others). */
typedef struct sy_image_info {
    /** @{ size in pixels */
    uint32_t width, height; /** @} */
    uint32_t channels; /**< 1 = grey (used for R, G and B), 2 = grey + alpha, 3 = RGB, 4 = RGBA */
    uint32_t format;   /**< sy_pixel_format */
} sy_image_info;

/** A texture's sampler. */
typedef struct sy_sampler {
    /** @{ sy_wrap */
    uint32_t wrap_s, wrap_t; /** @} */
    /** @{ sy_filter */
    uint32_t min_filter, mag_filter; /** @} */
} sy_sampler;

/** Field numbers of a texture. */
enum sy_texture_field {
    SY_TEXTURE_NAME = 0,
    SY_TEXTURE_INFO = 1,    /**< sy_image_info */
    SY_TEXTURE_PIXELS = 2,  /**< sy_blob*: rows top to bottom, channels interleaved */
    SY_TEXTURE_SAMPLER = 3, /**< sy_sampler */
    SY_TEXTURE_FIELD_COUNT = 4
};

/** Field values of a texture. */
typedef struct sy_texture_data {
    char *name; /**< name (copied; may be NULL) */
    sy_image_info info; /**< size and layout */
    sy_blob *pixels; /**< pixels: rows top to bottom, channels interleaved */
    sy_sampler sampler; /**< wrap and filter */
} sy_texture_data;

/* ---------------------------------------------------------------- light (KHR_lights_punctual) */
/** Punctual light types (KHR_lights_punctual). */
typedef enum sy_light_type { SY_LIGHT_POINT = 0, SY_LIGHT_SPOT = 1, SY_LIGHT_DIRECTIONAL = 2 } sy_light_type;

/** Field numbers of a light. */
enum sy_light_field {
    SY_LIGHT_NAME = 0,
    SY_LIGHT_TYPE = 1,       /**< uint32 sy_light_type */
    SY_LIGHT_COLOR = 2,      /**< float[3] linear */
    SY_LIGHT_INTENSITY = 3,  /**< float: candela (point, spot), lux (directional) */
    SY_LIGHT_RANGE = 4,      /**< float, 0 = infinite */
    SY_LIGHT_INNER_CONE = 5, /**< float radians */
    SY_LIGHT_OUTER_CONE = 6, /**< float radians */
    SY_LIGHT_FIELD_COUNT = 7
};

/** Field values of a light (KHR_lights_punctual units). */
typedef struct sy_light_data {
    char *name; /**< name (copied; may be NULL) */
    uint32_t type; /**< sy_light_type */
    float color[3]; /**< linear RGB */
    float intensity; /**< candela (point, spot), lux (directional) */
    float range; /**< 0 = infinite */
    float inner_cone; /**< spot inner cone angle (radians) */
    float outer_cone; /**< spot outer cone angle (radians) */
} sy_light_data;

/* ---------------------------------------------------------------- camera */
/** Camera projections. */
typedef enum sy_projection { SY_PROJECTION_PERSPECTIVE = 0, SY_PROJECTION_ORTHOGRAPHIC = 1 } sy_projection;

/** Field numbers of a camera. */
enum sy_camera_field {
    SY_CAMERA_NAME = 0,
    SY_CAMERA_PROJECTION = 1, /**< uint32 sy_projection */
    SY_CAMERA_YFOV = 2,       /**< float radians (perspective) */
    SY_CAMERA_ASPECT = 3,     /**< float width/height; 0 = from the image */
    SY_CAMERA_ZNEAR = 4,      /**< float */
    SY_CAMERA_ZFAR = 5,       /**< float; 0 = infinite, else > znear */
    SY_CAMERA_XMAG = 6,       /**< float half width (orthographic) */
    SY_CAMERA_YMAG = 7,       /**< float half height (orthographic) */
    SY_CAMERA_FIELD_COUNT = 8
};

/** Field values of a camera (glTF camera). */
typedef struct sy_camera_data {
    char *name; /**< name (copied; may be NULL) */
    uint32_t projection; /**< sy_projection */
    float yfov; /**< vertical field of view, radians (perspective) */
    float aspect; /**< width / height; 0 = from the image */
    float znear; /**< near plane distance */
    float zfar; /**< far plane distance; 0 = infinite, else beyond znear (a setter refuses zfar <= znear) */
    float xmag; /**< half width (orthographic) */
    float ymag; /**< half height (orthographic) */
} sy_camera_data;

/* ---------------------------------------------------------------- background (the world) */
/* What the camera sees where nothing is hit, and the environment light (see sy_look.h for the
 * rules every back-end follows). */
#define SY_GRADIENT_MAX 8 /**< at most this many sky and ground colours */
/** X3D Background: sky colours by angle from the zenith (sky_color[0] at the zenith, sky_color[i]
 * at sky_angle[i-1], increasing, in (0, pi]); ground colours by angle from the nadir (ground_color[0]
 * at the nadir, ground_angle increasing, in (0, pi/2]). sky_count 0 = no gradient; ground_count 0 =
 * the sky continues below the horizon. Colours are linear RGB. */
typedef struct sy_gradient {
    /** @{ used entries of the sky and ground arrays */
    uint32_t sky_count, ground_count; /** @} */
    float sky_color[SY_GRADIENT_MAX][3]; /**< linear RGB sky colours */
    float sky_angle[SY_GRADIENT_MAX]; /**< sky angles from the zenith */
    float ground_color[SY_GRADIENT_MAX][3]; /**< linear RGB ground colours */
    float ground_angle[SY_GRADIENT_MAX]; /**< ground angles from the nadir */
} sy_gradient;

/** Field numbers of a background (the world). */
enum sy_background_field {
    SY_BACKGROUND_NAME = 0,
    SY_BACKGROUND_COLOR = 1,       /**< float[4] linear RGBA, premultiplied; alpha 0 = transparent */
    SY_BACKGROUND_ENVIRONMENT = 2, /**< sy_texture (equirectangular), {0} = none: a light */
    SY_BACKGROUND_INTENSITY = 3,   /**< float multiplier for the environment */
    SY_BACKGROUND_ENVIRONMENT_VISIBLE = 4, /**< uint32: 1 (default) = camera rays see the environment */
    SY_BACKGROUND_GRADIENT = 5,    /**< sy_gradient: shown where nothing is hit (unless the environment is) */
    SY_BACKGROUND_DEFAULT_LIGHTING = 6, /**< uint32: 1 (default) = studio light when the scene brings none */
    SY_BACKGROUND_FIELD_COUNT = 7
};

/** Field values of a background (the world); see the field enum. */
typedef struct sy_background_data {
    char *name; /**< name (copied; may be NULL) */
    float color[4]; /**< background colour, linear RGBA premultiplied */
    sy_texture environment; /**< equirectangular environment map ({0}: none) */
    float intensity; /**< environment multiplier */
    uint32_t environment_visible; /**< 1 = camera rays see the environment */
    sy_gradient gradient; /**< X3D sky / ground gradient */
    uint32_t default_lighting; /**< 1 = studio light when the scene brings none */
} sy_background_data;

/* ---------------------------------------------------------------- animation (glTF 2.0 animation) */
/* One clip: keyframe samplers and the channels that drive node properties with them. Nothing of an
 * animation is visible by itself: sy_scene_set_time (sy_anim.h) evaluates it into the target nodes'
 * fields through the ordinary setters, so the result travels in change lists like any other edit.
 *
 * Storage (so an animation serialises like mesh data, in four blobs):
 *   samplers  sy_anim_sampler[n]: interpolation, components per value, key count and where its
 *             keys start in `times` and its values in `values` (element offsets, not bytes);
 *   channels  sy_anim_channel[m]: target node id, path, sampler index;
 *   times     float[]: every sampler's key times (seconds), each sampler's run strictly increasing;
 *   values    float[]: every sampler's output values, key after key; CUBICSPLINE keys hold three
 *             values each (in-tangent, value, out-tangent), as in glTF.
 * The rules between them (checked by the setters and by a replica's apply, so untrusted lists are
 * refused, naming the item): every run lies inside its blob; at least one key per sampler, at most
 * SY_ANIM_MAX_KEYS; times finite and strictly increasing (glTF's rule; equal times are refused, so
 * no interval has zero length); values finite; components 3 for translation and scale, 4 for
 * rotation, 1 to SY_ANIM_MAX_COMPONENTS for weights, sy_anim_path_components for the material,
 * light and camera paths; translation and scale values within SY_COORD_MAX; rotation key values not
 * the zero quaternion; channel targets live objects of the path's type (sy_anim_path_target: nodes,
 * materials, lights, cameras; a replica applying a list accepts references as its origin did) and
 * name a sampler that exists. Material, light and camera values are checked when they are set (the
 * clock's setter refuses an out-of-range colour or field of view and counts the channel failed). Set the
 * whole clip at once (sy_animation_set_clip or sy_animation_set): a single field set on its own is
 * checked with the other fields as they are. */
/** Interpolation of a sampler (glTF animation.sampler.interpolation). */
typedef enum sy_anim_interpolation {
    SY_INTERP_LINEAR = 0,      /**< linear; rotations by spherical linear interpolation (shortest path) */
    SY_INTERP_STEP = 1,        /**< the value of the last key at or before the time */
    SY_INTERP_CUBICSPLINE = 2, /**< cubic Hermite spline with in / out tangents (3 values per key) */
    SY_INTERP_COUNT = 3
} sy_anim_interpolation;

/** What a channel drives (glTF animation.channel.target.path). */
typedef enum sy_anim_path {
    SY_ANIM_TRANSLATION = 0, /**< node translation, 3 components */
    SY_ANIM_ROTATION = 1,    /**< node rotation, unit quaternion x y z w, 4 components */
    SY_ANIM_SCALE = 2,       /**< node scale, 3 components */
    SY_ANIM_WEIGHTS = 3,     /**< morph target weights of the node (SY_NODE_WEIGHTS), one component per target */
    /* paths whose channel targets another object (sy_anim_path_target): the channel's `node` holds its id */
    SY_ANIM_BASE_COLOR = 4,       /**< material base colour RGBA (SY_MATERIAL_BASE_COLOR), 4 components */
    SY_ANIM_DIFFUSE = 5,          /**< material base colour RGB, its alpha kept (X3D Material.diffuseColor), 3 */
    SY_ANIM_OPACITY = 6,          /**< material base colour alpha (X3D 1 - Material.transparency), 1 */
    SY_ANIM_EMISSIVE = 7,         /**< material emissive factor RGB (SY_MATERIAL_EMISSIVE), 3 */
    SY_ANIM_METALLIC = 8,         /**< material metallic factor, 1 */
    SY_ANIM_ROUGHNESS = 9,        /**< material roughness factor, 1 */
    SY_ANIM_LIGHT_COLOR = 10,     /**< light colour RGB (SY_LIGHT_COLOR), 3 */
    SY_ANIM_LIGHT_INTENSITY = 11, /**< light intensity (SY_LIGHT_INTENSITY), 1 */
    SY_ANIM_CAMERA_YFOV = 12,     /**< camera vertical field of view, radians (SY_CAMERA_YFOV), 1 */
    SY_ANIM_PATH_COUNT = 13
} sy_anim_path;

/** The type of object a channel of `path` targets: SY_TYPE_NODE for translation, rotation, scale and
 * weights, SY_TYPE_MATERIAL, SY_TYPE_LIGHT or SY_TYPE_CAMERA for the others; 0 for an unknown path. */
uint32_t sy_anim_path_target(uint32_t path);
/** Components a sampler of a channel of `path` has (weights: 0, any from 1 to SY_ANIM_MAX_COMPONENTS). */
uint32_t sy_anim_path_components(uint32_t path);
/** The path's name ("translation", "base_color", ... ; "unknown" past SY_ANIM_PATH_COUNT). */
const char *sy_anim_path_name(uint32_t path);

#define SY_ANIM_MAX_KEYS (1u << 24)      /**< keys of one sampler */
#define SY_ANIM_MAX_SAMPLERS (1u << 20)  /**< samplers of one animation */
#define SY_ANIM_MAX_CHANNELS (1u << 20)  /**< channels of one animation */
#define SY_ANIM_MAX_COMPONENTS 256u      /**< components of one value (morph weights: one per target) */
#define SY_ANIM_MAX_CYCLE 1.0e9f         /**< longest period of a clip, seconds */

/** One sampler as stored in the samplers blob (20 bytes, little endian on the wire like all POD). */
typedef struct sy_anim_sampler {
    uint32_t interpolation; /**< sy_anim_interpolation */
    uint32_t components;    /**< floats per value */
    uint32_t key_count;     /**< keys (>= 1) */
    uint32_t times_offset;  /**< index of its first time in the times blob (floats) */
    uint32_t values_offset; /**< index of its first value float in the values blob */
} sy_anim_sampler;

/** One channel as stored in the channels blob (12 bytes). */
typedef struct sy_anim_channel {
    uint32_t node;    /**< target id: a node (sy_node.id), or the material, light or camera of the path (sy_anim_path_target) */
    uint32_t path;    /**< sy_anim_path */
    uint32_t sampler; /**< index into the samplers */
} sy_anim_channel;

/** Field numbers of an animation. */
enum sy_animation_field {
    SY_ANIMATION_NAME = 0,
    SY_ANIMATION_SAMPLERS = 1, /**< sy_blob* of sy_anim_sampler (NULL = none) */
    SY_ANIMATION_CHANNELS = 2, /**< sy_blob* of sy_anim_channel (NULL = none) */
    SY_ANIMATION_TIMES = 3,    /**< sy_blob* of float key times */
    SY_ANIMATION_VALUES = 4,   /**< sy_blob* of float output values */
    SY_ANIMATION_CYCLE = 5,    /**< float: the clip's period in seconds (0 = its keys' range; X3D TimeSensor.cycleInterval) */
    SY_ANIMATION_LOOP = 6,     /**< uint32 0 or 1: scene time wraps into [0, period) (X3D TimeSensor.loop) */
    SY_ANIMATION_FIELD_COUNT = 7
};

/** Field values of an animation; read the blobs with sy_animation_samplers & co. */
typedef struct sy_animation_data {
    char *name; /**< clip name (copied; may be NULL) */
    sy_blob *samplers; /**< sy_anim_sampler[] */
    sy_blob *channels; /**< sy_anim_channel[] */
    sy_blob *times; /**< float[] */
    sy_blob *values; /**< float[] */
    float cycle; /**< period, seconds: finite, 0 to SY_ANIM_MAX_CYCLE; 0 = from the first key to the last */
    uint32_t loop; /**< 1: the clip repeats every period (time t plays t mod period), 0: it clamps at its ends */
} sy_animation_data;

/** A sampler to build a clip from (sy_animation_set_clip): key_count times and key_count x
 * components values (x 3 for CUBICSPLINE: in-tangent, value, out-tangent per key). Borrowed. */
typedef struct sy_anim_sampler_desc {
    uint32_t interpolation; /**< sy_anim_interpolation */
    uint32_t components;    /**< floats per value */
    uint32_t key_count;     /**< keys */
    const float *times;     /**< key_count times */
    const float *values;    /**< key_count x components (x 3 for CUBICSPLINE) floats */
} sy_anim_sampler_desc;

/** Samplers of an animation's data (borrowed from its blob); count may be 0. */
const sy_anim_sampler *sy_animation_samplers(const sy_animation_data *d, uint32_t *count_out);
/** Channels of an animation's data (borrowed); count may be 0. */
const sy_anim_channel *sy_animation_channels(const sy_animation_data *d, uint32_t *count_out);
/** The time range of the clip: [0, period] when it has a period of its own (cycle > 0), else the
 * smallest first key time and the largest last key time over its samplers (glTF's duration is
 * *end_out; an animation without samplers gives 0, 0). */
void sy_animation_time_range(const sy_animation_data *d, float *start_out, float *end_out);

/* ---------------------------------------------------------------- attachments */
/** Value types of an attachment. */
typedef enum sy_attachment_kind {
    SY_ATTACH_INT = 1,
    SY_ATTACH_FLOAT = 2,
    SY_ATTACH_VEC4 = 3,
    SY_ATTACH_STRING = 4,
    SY_ATTACH_BLOB = 5,
} sy_attachment_kind;

/** A named, typed value on any object (back-end specific extensions). Mediators that understand
 * a key use it; others ignore it. */
typedef struct sy_attachment {
    char *key; /**< key (copied) */
    uint32_t kind; /**< sy_attachment_kind */
    union {
        int64_t i;
        double f;
        float v[4];
        char *s;
        sy_blob *blob;
    } value; /**< the value, by kind */
} sy_attachment;


/** Default field values of a type (glTF defaults): const sy_node_data* etc. Static storage. */
const void *sy_object_defaults(sy_object_type t);
/** Copies the plain fields in mask (field bits) of src into dst, both data structs of type t: a
 * shallow merge for consumers that keep their own copy of an object's plain fields (the mirror
 * merging a change). Names, blobs and primitive lists are not copied. Reentrant. */
void sy_object_data_merge(sy_object_type t, void *dst, const void *src, uint64_t mask);

/** Create an object with default field values (name copied, may be NULL). */
sy_result sy_node_create(sy_scene *s, const char *name, sy_node *out, sy_error *err);
/** Creates a mesh (as sy_node_create). */
sy_result sy_mesh_create(sy_scene *s, const char *name, sy_mesh *out, sy_error *err);
/** Creates a material (as sy_node_create). */
sy_result sy_material_create(sy_scene *s, const char *name, sy_material *out, sy_error *err);
/** Creates a texture (as sy_node_create). */
sy_result sy_texture_create(sy_scene *s, const char *name, sy_texture *out, sy_error *err);
/** Creates a light (as sy_node_create). */
sy_result sy_light_create(sy_scene *s, const char *name, sy_light *out, sy_error *err);
/** Creates a camera (as sy_node_create). */
sy_result sy_camera_create(sy_scene *s, const char *name, sy_camera *out, sy_error *err);
/** Creates a background (as sy_node_create). */
sy_result sy_background_create(sy_scene *s, const char *name, sy_background *out, sy_error *err);
/** Creates an animation (as sy_node_create). */
sy_result sy_animation_create(sy_scene *s, const char *name, sy_animation *out, sy_error *err);
/** Generic form: *id_out receives the new handle id. */
sy_result sy_object_create(sy_scene *s, sy_object_type t, const char *name, uint32_t *id_out, sy_error *err);

/** Destroys the object. References to it elsewhere (a node's mesh, a child list) are NOT removed:
 * readers treat a stale reference as absent. */
sy_result sy_object_destroy(sy_scene *s, sy_object_type t, uint32_t id, sy_error *err);

/** true when id names a live object of type t. */
bool sy_object_is_valid(const sy_scene *s, sy_object_type t, uint32_t id);
/** Borrowed pointer to the data struct (sy_node_data* for SY_TYPE_NODE, ...) or NULL if stale. */
const void *sy_object_get(const sy_scene *s, sy_object_type t, uint32_t id);
/** Iteration over live objects of a type in slot order: start with prev_id 0; returns 0 at the end. */
uint32_t sy_scene_next(const sy_scene *s, sy_object_type t, uint32_t prev_id);
/** Number of live objects of a type. */
uint32_t sy_scene_count(const sy_scene *s, sy_object_type t);

/** Generic setter: value points to the field's type as listed in the field enums (for strings a
 * `const char *`, for blob fields a `sy_blob *` (retained, may be NULL), for SY_MESH_PRIMITIVES a
 * `sy_primitive_list`). Validates the value; marks the field dirty when it differs. */
sy_result sy_object_set_field(sy_scene *s, sy_object_type t, uint32_t id, uint32_t field, const void *value,
                              sy_error *err);

/** Typed setters (thin wrappers over sy_object_set_field). */
sy_result sy_node_set_trs(sy_scene *s, sy_node n, const float t[3], const float r[4], const float sc[3], sy_error *err);
/** Sets the local transform as a matrix (mode SY_TRANSFORM_MATRIX). */
sy_result sy_node_set_matrix(sy_scene *s, sy_node n, const sy_mat4 *m, sy_error *err);
/** Replaces the child list. Refuses stale children and cycles (a node below itself). */
sy_result sy_node_set_children(sy_scene *s, sy_node n, const sy_node *children, uint32_t count, sy_error *err);
/** Appends a child (same checks as sy_node_set_children). */
sy_result sy_node_add_child(sy_scene *s, sy_node parent, sy_node child, sy_error *err);
/** Instances a mesh on the node ({0}: none). */
sy_result sy_node_set_mesh(sy_scene *s, sy_node n, sy_mesh m, sy_error *err);
/** Attaches a light to the node ({0}: none). */
sy_result sy_node_set_light(sy_scene *s, sy_node n, sy_light l, sy_error *err);
/** Attaches a camera to the node ({0}: none). */
sy_result sy_node_set_camera(sy_scene *s, sy_node n, sy_camera c, sy_error *err);
/** Sets the node's sy_node_flags. */
sy_result sy_node_set_flags(sy_scene *s, sy_node n, uint32_t flags, sy_error *err);
/** Shows (SY_NODE_VISIBLE set) or hides the node: a hidden node and its subtree are not drawn, hit,
 * picked or counted by coverage, cast no shadow and light nothing. The other flags are kept. An
 * unknown or destroyed node: SY_ERR_INVALID_HANDLE naming its id. */
sy_result sy_node_set_visible(sy_scene *s, sy_node n, bool visible, sy_error *err);
/** Selects or deselects the node (SY_NODE_SELECTED; the other flags kept); errors as sy_node_set_visible. */
sy_result sy_node_set_selected(sy_scene *s, sy_node n, bool selected, sy_error *err);
/** Isolate: hides every node with a mesh that is neither one of the count nodes, nor above one (an
 * ancestor: its own mesh stays drawn, since hiding it would hide the kept ones), nor below one
 * (their subtrees), and shows those that are; nodes without a mesh that are not kept (lights,
 * cameras, other groups) keep their visibility, so the scene's lights stay. Every id is checked
 * first (nothing changes when one is unknown: SY_ERR_INVALID_HANDLE naming it); count 0 shows
 * every node. */
sy_result sy_scene_isolate(sy_scene *s, const sy_node *nodes, uint32_t count, sy_error *err);
/** Sets the node's morph weights (count 0: NULL, the mesh's apply). Finite, at most SY_MORPH_MAX_TARGETS. */
sy_result sy_node_set_weights(sy_scene *s, sy_node n, const float *weights, uint32_t count, sy_error *err);
/** Sets the node's skin: count joints (live nodes) with their inverse bind matrices (NULL: identity);
 * count 0 removes it. skeleton ({0}: none) is stored as given. */
sy_result sy_node_set_skin(sy_scene *s, sy_node n, const sy_node *joints, const sy_mat4 *inverse_bind, uint32_t count,
                           sy_node skeleton, sy_error *err);
/** Sets a mesh's default morph weights (count 0: NULL). As sy_node_set_weights. */
sy_result sy_mesh_set_weights(sy_scene *s, sy_mesh m, const float *weights, uint32_t count, sy_error *err);
/** Skin joints of a node data struct (borrowed from its blob); count may be 0. */
const sy_skin_joint *sy_node_skin(const sy_node_data *d, uint32_t *count_out);
/** Retains every blob; validates sizes and index ranges of every primitive. */
sy_result sy_mesh_set_primitives(sy_scene *s, sy_mesh m, const sy_primitive *prims, uint32_t count, sy_error *err);
/** Sets every field of the struct (name included); only fields that differ are marked dirty. */
sy_result sy_material_set(sy_scene *s, sy_material m, const sy_material_data *d, sy_error *err);
/** Sets every field of a light (as sy_material_set). */
sy_result sy_light_set(sy_scene *s, sy_light l, const sy_light_data *d, sy_error *err);
/** Sets every field of a camera (as sy_material_set). */
sy_result sy_camera_set(sy_scene *s, sy_camera c, const sy_camera_data *d, sy_error *err);
/** Sets every field of a background (as sy_material_set). */
sy_result sy_background_set(sy_scene *s, sy_background b, const sy_background_data *d, sy_error *err);
/** Sets every field of an animation (as sy_material_set); the rules between its blobs are checked
 * on the whole (see the animation section). */
sy_result sy_animation_set(sy_scene *s, sy_animation a, const sy_animation_data *d, sy_error *err);
/** Builds an animation's blobs from samplers and channels (copied) and sets them at once; the name,
 * period and loop stay. Refuses what sy_animation_set refuses, naming the sampler or channel. */
sy_result sy_animation_set_clip(sy_scene *s, sy_animation a, const sy_anim_sampler_desc *samplers, uint32_t sampler_count,
                                const sy_anim_channel *channels, uint32_t channel_count, sy_error *err);
/** Validates that the blob holds width*height*channels elements of the format. Retains pixels. */
sy_result sy_texture_set_image(sy_scene *s, sy_texture t, const sy_image_info *info, sy_blob *pixels, sy_error *err);
/** Sets the texture's sampler. */
sy_result sy_texture_set_sampler(sy_scene *s, sy_texture t, const sy_sampler *smp, sy_error *err);

/** Typed getters: borrowed, NULL for a stale handle. */
const sy_node_data *sy_node_get(const sy_scene *s, sy_node n);
/** Borrowed mesh data, NULL for a stale handle. */
const sy_mesh_data *sy_mesh_get(const sy_scene *s, sy_mesh m);
const sy_material_data *sy_material_get(const sy_scene *s, sy_material m); /**< {0}: defaults */
/** Borrowed texture data, NULL for a stale handle. */
const sy_texture_data *sy_texture_get(const sy_scene *s, sy_texture t);
/** Borrowed light data, NULL for a stale handle. */
const sy_light_data *sy_light_get(const sy_scene *s, sy_light l);
/** Borrowed camera data, NULL for a stale handle. */
const sy_camera_data *sy_camera_get(const sy_scene *s, sy_camera c);
/** Borrowed background data, NULL for a stale handle. */
const sy_background_data *sy_background_get(const sy_scene *s, sy_background b);

/** Borrowed animation data, NULL for a stale handle. */
const sy_animation_data *sy_animation_get(const sy_scene *s, sy_animation a);
/** Sets a clip's period (seconds, 0 = its keys' range) and whether it loops (the X3D TimeSensor's
 * cycleInterval and loop; glTF clips keep 0 and 0). Refuses a period that is negative, not finite
 * or above SY_ANIM_MAX_CYCLE. */
sy_result sy_animation_set_timing(sy_scene *s, sy_animation a, float cycle, bool loop, sy_error *err);

/** Child ids of a node data struct (borrowed from the children blob); count may be 0. */
const uint32_t *sy_node_children(const sy_node_data *d, uint32_t *count_out);

/** Attachments. set replaces an attachment with the same key (key and strings copied, blob
 * retained); remove returns SY_ERR_NOT_FOUND when absent. get returns a borrowed array. */
sy_result sy_object_set_attachment(sy_scene *s, sy_object_type t, uint32_t id, const sy_attachment *a,
                                   sy_error *err);
/** Removes the attachment named key; SY_ERR_NOT_FOUND when absent. */
sy_result sy_object_remove_attachment(sy_scene *s, sy_object_type t, uint32_t id, const char *key, sy_error *err);
/** The object's attachments (borrowed array of *count_out entries). */
const sy_attachment *sy_object_attachments(const sy_scene *s, sy_object_type t, uint32_t id, uint32_t *count_out);
/** The attachment named key, or NULL. */
const sy_attachment *sy_object_find_attachment(const sy_scene *s, sy_object_type t, uint32_t id, const char *key);

#ifdef __cplusplus
}
#endif
#endif /* SY_OBJECTS_H */
