/* sy_gltf_shim.h — C view of a glTF 2.0 document parsed by tinygltf (the only C++ in formats/).
 *
 * The shim does the parsing only: JSON -> plain C structs, external and data: URI buffers/images
 * loaded, images decoded (stb_image) into 8-bit pixels. It does NOT validate cross references or
 * accessor ranges: every index in these structs is untrusted and must be range-checked by the
 * caller (formats/sy_gltf_validate.c does, in one pass, before it creates anything).
 *
 * The GLB container must be validated by the caller before sy_gltf_shim_parse is called with
 * binary = true (tinygltf 2.7 does not check every chunk bound itself).
 *
 * External files are looked up relative to base_dir only (never the working directory) and are
 * read through sy_file_read_all with limits->max_file_bytes. Images are refused before decoding
 * when width*height exceeds limits->max_image_pixels.
 *
 * Ownership: sy_gltf_shim_parse returns a document owned by the caller, released with
 * sy_gltf_shim_free (NULL-safe). Every pointer inside (names, arrays, buffer bytes, pixels) is
 * borrowed from the document and valid until it is freed.
 * Thread-safety: no shared state; distinct documents may be parsed and read on distinct threads.
 * Exceptions never cross this interface (everything is caught and turned into a sy_result).
 *
 * Compressed meshes (KHR_draco_mesh_compression) are decoded here, after tinygltf's parse: their
 * accessors are given bufferViews of new buffers holding the decoded floats (attributes) and uint32
 * values (indices), so the caller reads them like any accessor. A stream that does not decode, or
 * decodes to counts other than its accessors declare, fails the parse naming
 * meshes[i].primitives[j]. EXT_meshopt_compression bufferViews are decoded likewise into new
 * buffers the views point at (failures name bufferViews[i]). */
#ifndef SY_GLTF_SHIM_H
#define SY_GLTF_SHIM_H

#include "sy_common.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct sy_gltf_shim_limits {
    size_t max_file_bytes;     /* external buffer / image files */
    uint64_t max_image_pixels; /* width * height of one decoded image */
    const char *const *allowed_roots; /* folders besides base_dir that external files may lie in */
    size_t allowed_root_count;
    /* NULL-terminated extensions the caller reads (NULL = not checked here). When tinygltf refuses
     * a file whose extensionsRequired names one not in this list (a Draco-compressed mesh has no
     * bufferView, say), the failure is SY_ERR_UNSUPPORTED naming that extension, not tinygltf's
     * complaint about what the extension changed. */
    const char *const *supported_extensions;
    /* decoded bytes of all images together (the load's budget, sy_budget.h); an image that would
     * pass it is refused before decoding, like one over max_image_pixels; 0 = no limit */
    uint64_t max_image_bytes;
    /* decoded bytes of all compressed meshes together (KHR_draco_mesh_compression, sized from the
     * glTF's accessor counts; EXT_meshopt_compression, from the views' lengths) before decoding;
     * 0 = no limit */
    uint64_t max_mesh_bytes;
} sy_gltf_shim_limits;

typedef struct sy_gltf_shim_buffer {
    const uint8_t *data;
    size_t size;
} sy_gltf_shim_buffer;

typedef struct sy_gltf_shim_view {
    int32_t buffer; /* untrusted index */
    size_t byte_offset;
    size_t byte_length;
    size_t byte_stride; /* 0 = tightly packed */
} sy_gltf_shim_view;

typedef struct sy_gltf_shim_accessor {
    const char *name;
    int32_t buffer_view; /* -1: all zeros (sparse may override) */
    size_t byte_offset;
    int32_t component_type; /* 5120..5126 (5130 = tinygltf's double, not glTF) */
    int32_t components;     /* 1, 2, 3, 4, 4 (MAT2), 9, 16; 0 unknown */
    int32_t is_matrix;
    int32_t normalized;
    size_t count;
    int32_t sparse;           /* 0/1 */
    int32_t sparse_count;     /* untrusted */
    int32_t sparse_indices_view;
    int32_t sparse_indices_offset;
    int32_t sparse_indices_type;
    int32_t sparse_values_view;
    int32_t sparse_values_offset;
} sy_gltf_shim_accessor;

typedef struct sy_gltf_shim_primitive {
    int32_t mode; /* 0..6 (default 4) */
    int32_t indices;
    int32_t material;
    int32_t position, normal, tangent, texcoord0, texcoord1, color0; /* accessor index or -1 */
    int32_t has_targets; /* morph targets present */
    int32_t joints0, weights0, joints1, weights1; /* skin attributes: accessor index or -1 */
    const int32_t *targets; /* target_count x {POSITION, NORMAL, TANGENT} accessor indices (-1: absent) */
    size_t target_count;
} sy_gltf_shim_primitive;

typedef struct sy_gltf_shim_mesh {
    const char *name;
    const sy_gltf_shim_primitive *primitives;
    size_t primitive_count;
    const double *weights; size_t weight_count; /* default morph weights (mesh.weights) */
} sy_gltf_shim_mesh;

typedef struct sy_gltf_shim_skin {
    const char *name;
    int32_t inverse_bind_matrices; /* accessor index or -1 (identity) */
    int32_t skeleton;              /* node index or -1 */
    const int32_t *joints; size_t joint_count; /* node indices (untrusted) */
} sy_gltf_shim_skin;

typedef struct sy_gltf_shim_texinfo {
    int32_t index;    /* texture index or -1 */
    int32_t texcoord;
    double scale;     /* normal scale / occlusion strength; 1 otherwise */
    int32_t has_transform; /* KHR_texture_transform */
    double offset[2];
    double rotation;
    double uv_scale[2];
    int32_t transform_texcoord; /* -1 when the extension does not override texCoord */
} sy_gltf_shim_texinfo;

typedef struct sy_gltf_shim_material {
    const char *name;
    double base_color[4];
    double metallic, roughness;
    sy_gltf_shim_texinfo base_color_texture, metallic_roughness_texture;
    sy_gltf_shim_texinfo normal_texture, occlusion_texture, emissive_texture;
    double emissive[3];
    const char *alpha_mode; /* "OPAQUE", "MASK", "BLEND" or anything from the file */
    double alpha_cutoff;
    int32_t double_sided;
    double emissive_strength; /* 1 when the extension is absent */
    double transmission;
    sy_gltf_shim_texinfo transmission_texture;
    double ior; /* 1.5 when absent */
    int32_t unlit;
    /* KHR_materials_specular (1, 1 1 1 when absent) */
    double specular, specular_color[3];
    sy_gltf_shim_texinfo specular_texture, specular_color_texture;
    /* KHR_materials_clearcoat */
    double clearcoat, clearcoat_roughness;
    sy_gltf_shim_texinfo clearcoat_texture, clearcoat_roughness_texture, clearcoat_normal_texture;
    /* KHR_materials_sheen */
    double sheen_color[3], sheen_roughness;
    sy_gltf_shim_texinfo sheen_color_texture, sheen_roughness_texture;
    /* KHR_materials_volume (attenuation_distance: 0 when absent, meaning infinite) */
    double thickness, attenuation_distance, attenuation_color[3];
    sy_gltf_shim_texinfo thickness_texture;
    /* KHR_materials_iridescence (ior 1.3, thickness 100 to 400 nm when absent) */
    double iridescence, iridescence_ior, iridescence_thickness[2];
    sy_gltf_shim_texinfo iridescence_texture, iridescence_thickness_texture;
    /* KHR_materials_anisotropy */
    double anisotropy, anisotropy_rotation;
    sy_gltf_shim_texinfo anisotropy_texture;
    int32_t base_color_count, emissive_count; /* array lengths found in the file */
} sy_gltf_shim_material;

typedef struct sy_gltf_shim_texture {
    const char *name;
    int32_t source;  /* image index or -1 */
    int32_t sampler; /* sampler index or -1 */
} sy_gltf_shim_texture;

typedef struct sy_gltf_shim_sampler {
    int32_t min_filter, mag_filter; /* -1: unspecified */
    int32_t wrap_s, wrap_t;
} sy_gltf_shim_sampler;

typedef struct sy_gltf_shim_image {
    const char *name;
    const char *uri; /* "" for data: URIs and bufferView images */
    /* Decoded 8-bit pixels, rows top to bottom; channels 3 (RGB) or 4 (RGBA): grey and grey+alpha
     * images are expanded to RGBA, 16-bit images rounded to 8 bits. NULL when the image could not be
     * loaded (then `problem` says why). */
    const uint8_t *pixels;
    uint32_t width, height, channels;
    uint32_t source_bits; /* 8 or 16 */
    const char *problem;
} sy_gltf_shim_image;

typedef struct sy_gltf_shim_camera {
    const char *name;
    const char *type; /* "perspective", "orthographic" or anything from the file */
    double yfov, aspect, znear, zfar; /* perspective */
    double xmag, ymag, oznear, ozfar; /* orthographic */
} sy_gltf_shim_camera;

typedef struct sy_gltf_shim_light {
    const char *name;
    const char *type; /* "point", "spot", "directional" or anything from the file */
    double color[3];
    int32_t color_count;
    double intensity, range;
    double inner_cone, outer_cone;
} sy_gltf_shim_light;

typedef struct sy_gltf_shim_node {
    const char *name;
    int32_t mesh, camera, light, skin; /* -1: none */
    const int32_t *children;
    size_t child_count;
    const double *matrix;      size_t matrix_count;      /* 0 or 16 expected */
    const double *translation; size_t translation_count; /* 0 or 3 */
    const double *rotation;    size_t rotation_count;    /* 0 or 4 */
    const double *scale;       size_t scale_count;       /* 0 or 3 */
    int32_t has_weights;
    const double *weights; size_t weight_count; /* morph weights (node.weights) */
    /* EXT_mesh_gpu_instancing: accessor indices or -1 */
    int32_t instancing; /* extension present */
    int32_t inst_translation, inst_rotation, inst_scale;
} sy_gltf_shim_node;

typedef struct sy_gltf_shim_scene {
    const char *name;
    const int32_t *nodes;
    size_t node_count;
} sy_gltf_shim_scene;

/* One channel of animations[0] (the first frame of the first animation is what a static load
 * shows). Indices are untrusted. */
typedef struct sy_gltf_shim_channel {
    int32_t node;   /* target node, -1 none */
    int32_t path;   /* 0 translation, 1 rotation, 2 scale, -1 anything else (weights) */
    int32_t output; /* sampler output accessor, -1 when the sampler index is invalid */
    int32_t cubic;  /* CUBICSPLINE: outputs are (in-tangent, value, out-tangent) triples */
} sy_gltf_shim_channel;

/* Every animation (all clips): samplers and channels as the file gives them. Indices untrusted. */
typedef struct sy_gltf_shim_anim_sampler {
    int32_t input, output;  /* accessor indices */
    int32_t interpolation;  /* 0 LINEAR (the default), 1 STEP, 2 CUBICSPLINE, -1 anything else */
} sy_gltf_shim_anim_sampler;
typedef struct sy_gltf_shim_anim_channel {
    int32_t node;    /* target node, -1 none */
    int32_t path;    /* 0 translation, 1 rotation, 2 scale, 3 weights, 4 "pointer", -1 anything else */
    int32_t sampler; /* index into the animation's samplers */
    const char *pointer; /* path "pointer": its KHR_animation_pointer JSON pointer (untrusted), else NULL */
} sy_gltf_shim_anim_channel;
typedef struct sy_gltf_shim_animation {
    const char *name;
    const sy_gltf_shim_anim_sampler *samplers; size_t sampler_count;
    const sy_gltf_shim_anim_channel *channels; size_t channel_count;
} sy_gltf_shim_animation;

/* KHR_materials_variants: primitive `primitive` of mesh `mesh` takes material `material` in variant
 * `variant` (one entry per variant of each mapping, in mesh then primitive order). Indices are
 * untrusted. */
typedef struct sy_gltf_shim_variant_use {
    int32_t mesh, primitive, material, variant;
} sy_gltf_shim_variant_use;

typedef struct sy_gltf_doc {
    const sy_gltf_shim_buffer *buffers;     size_t buffer_count;
    const sy_gltf_shim_view *views;         size_t view_count;
    const sy_gltf_shim_accessor *accessors; size_t accessor_count;
    const sy_gltf_shim_mesh *meshes;        size_t mesh_count;
    const sy_gltf_shim_material *materials; size_t material_count;
    const sy_gltf_shim_texture *textures;   size_t texture_count;
    const sy_gltf_shim_sampler *samplers;   size_t sampler_count;
    const sy_gltf_shim_image *images;       size_t image_count;
    const sy_gltf_shim_camera *cameras;     size_t camera_count;
    const sy_gltf_shim_light *lights;       size_t light_count;
    const sy_gltf_shim_node *nodes;         size_t node_count;
    const sy_gltf_shim_scene *scenes;       size_t scene_count;
    int32_t default_scene; /* -1: none given */
    const char *const *extensions_required; size_t extensions_required_count;
    const char *const *extensions_used;     size_t extensions_used_count; /* the file's extensionsUsed */
    size_t skin_count, animation_count;
    const sy_gltf_shim_skin *skins; /* skin_count of them */
    const sy_gltf_shim_channel *channels;   size_t channel_count; /* of animations[0] */
    const sy_gltf_shim_animation *animations; /* animation_count of them */
    const char *const *variant_names;       size_t variant_count; /* KHR_materials_variants ("" unnamed) */
    const sy_gltf_shim_variant_use *variant_uses; size_t variant_use_count;
    const char *warnings; /* tinygltf's warning text, "" when none */
    void *internal;       /* private to the shim */
} sy_gltf_doc;

/* Parses `size` bytes: glTF JSON (binary = false) or a validated GLB container (binary = true).
 * base_dir: directory that external URIs are relative to ("" = current directory).
 * On failure: SY_ERR_PARSE (invalid JSON / glTF), SY_ERR_NOT_FOUND or SY_ERR_IO (external files),
 * SY_ERR_LIMIT, SY_ERR_OUT_OF_MEMORY; err holds tinygltf's reason without the file name (the caller
 * prefixes it). *out is NULL then. */
sy_result sy_gltf_shim_parse(const uint8_t *bytes, size_t size, bool binary, const char *base_dir,
                             const sy_gltf_shim_limits *limits, sy_gltf_doc **out, sy_error *err);

void sy_gltf_shim_free(sy_gltf_doc *doc);

/* Benchmark aid (`sy bench load`): runs tinygltf's parser exactly as sy_gltf_shim_parse does
 * (same file callbacks, buffers loaded, images decoded under the same limits) and discards the
 * result without building the C view, so callers can time tinygltf alone. Same result codes. */
sy_result sy_gltf_shim_parse_only(const uint8_t *bytes, size_t size, bool binary, const char *base_dir,
                                  const sy_gltf_shim_limits *limits, sy_error *err);

/* >>writing (GLB). A plain description of what to write: the shim builds a tinygltf model from it
 * and serialises it with tinygltf's GLB writer. Everything here is trusted (the caller's own
 * scene data, checked by formats/sy_gltf_write.c): counts match the arrays. */
typedef struct sy_gltf_shim_wprimitive {
    int32_t mode;                /* glTF mode: 0 points, 1 lines, 4 triangles */
    int32_t material;            /* index into materials, -1: none (glTF's default material) */
    uint32_t vertex_count;
    const float *positions;      /* float[3] per vertex (required) */
    const float *normals;        /* float[3] per vertex or NULL */
    const float *texcoords0;     /* float[2] per vertex or NULL */
    const float *colors;         /* float[4] per vertex or NULL */
    const uint32_t *indices;     /* NULL: non-indexed */
    uint32_t index_count;
    const float *tangents;       /* float[4] per vertex or NULL */
    const float *texcoords1;     /* float[2] per vertex or NULL */
} sy_gltf_shim_wprimitive;

typedef struct sy_gltf_shim_wmesh {
    const char *name; /* may be NULL */
    const sy_gltf_shim_wprimitive *primitives;
    uint32_t primitive_count;
} sy_gltf_shim_wmesh;

/* A material's texture reference: texture is an index into the doc's textures + 1 (0: none). */
typedef struct sy_gltf_shim_wtexref {
    int32_t texture;
    uint32_t texcoord;
    double scale; /* normal scale / occlusion strength (written for those two only) */
    double offset[2], rotation, uv_scale[2]; /* KHR_texture_transform, written unless the identity */
} sy_gltf_shim_wtexref;

typedef struct sy_gltf_shim_wmaterial {
    const char *name; /* may be NULL */
    double base_color[4], metallic, roughness, emissive[3], emissive_strength; /* strength 1: no extension */
    const char *alpha_mode; /* "OPAQUE", "MASK", "BLEND" */
    double alpha_cutoff;
    int32_t double_sided, unlit;
    /* Textures and the other KHR_materials_* extensions (sy convert); written only when `full` is
     * set, each extension only when it differs from the specification's defaults. */
    int32_t full;
    sy_gltf_shim_wtexref base_color_tex, metallic_roughness_tex, normal_tex, occlusion_tex, emissive_tex;
    double transmission; sy_gltf_shim_wtexref transmission_tex;
    double ior;
    double specular, specular_color[3]; sy_gltf_shim_wtexref specular_tex, specular_color_tex;
    double clearcoat, clearcoat_roughness;
    sy_gltf_shim_wtexref clearcoat_tex, clearcoat_roughness_tex, clearcoat_normal_tex;
    double sheen_color[3], sheen_roughness; sy_gltf_shim_wtexref sheen_color_tex, sheen_roughness_tex;
    double thickness, attenuation_distance, attenuation_color[3]; sy_gltf_shim_wtexref thickness_tex;
    double iridescence, iridescence_ior, iridescence_thickness[2];
    sy_gltf_shim_wtexref iridescence_tex, iridescence_thickness_tex;
    double anisotropy, anisotropy_rotation; sy_gltf_shim_wtexref anisotropy_tex;
} sy_gltf_shim_wmaterial;

/* >>material extensions: the members of the KHR_materials_* extensions beyond the core material
 * (transmission, ior, specular, clearcoat, sheen, volume, iridescence, anisotropy), one row each,
 * the rows of one extension together; both halves of the shim go by it: the reader fills
 * sy_gltf_shim_material (a member or extension that is absent: the row's default), the writer writes
 * an extension of a full sy_gltf_shim_wmaterial when one of its SY_GLTF_EXT_KEY members is off its
 * default (a texture: present), with every member but textures absent and SY_GLTF_EXT_ABOVE ones at
 * their default. */
typedef enum sy_gltf_ext_kind { SY_GLTF_EXT_NUMBER, SY_GLTF_EXT_VEC3, SY_GLTF_EXT_TEXTURE } sy_gltf_ext_kind;
enum {
    SY_GLTF_EXT_KEY = 1,   /* off its default, the extension is written */
    SY_GLTF_EXT_ABOVE = 2, /* written only above its default (attenuationDistance: 0 is infinite) */
    SY_GLTF_EXT_SCALE = 4  /* a texture with a "scale" (a normal texture) */
};
typedef struct sy_gltf_shim_ext_member {
    const char *extension, *key; /* "KHR_materials_clearcoat", "clearcoatFactor" */
    sy_gltf_ext_kind kind;
    unsigned flags;
    double def[3];
    size_t read;  /* offset in sy_gltf_shim_material of a double or double[3] or sy_gltf_shim_texinfo */
    size_t write; /* offset in sy_gltf_shim_wmaterial of a double or double[3] or sy_gltf_shim_wtexref */
} sy_gltf_shim_ext_member;
extern const sy_gltf_shim_ext_member sy_gltf_shim_ext_members[];
extern const size_t sy_gltf_shim_ext_member_count;

/* One texture: its PNG bytes (one glTF image, in the buffer) and its sampler (glTF codes). */
typedef struct sy_gltf_shim_wtexture {
    const char *name; /* may be NULL */
    const uint8_t *png; size_t png_size;
    int32_t wrap_s, wrap_t, min_filter, mag_filter;
} sy_gltf_shim_wtexture;

typedef struct sy_gltf_shim_wcamera {
    const char *name; /* may be NULL */
    int32_t orthographic;
    double yfov, aspect, znear, zfar, xmag, ymag; /* aspect 0, zfar 0: not written */
} sy_gltf_shim_wcamera;

typedef struct sy_gltf_shim_wlight { /* KHR_lights_punctual */
    const char *name; /* may be NULL */
    const char *type; /* "point", "spot", "directional" */
    double color[3], intensity, range, inner_cone, outer_cone; /* range 0: not written */
} sy_gltf_shim_wlight;

typedef struct sy_gltf_shim_wnode {
    const char *name; /* may be NULL */
    int32_t mesh;     /* index into meshes, -1: none */
    double matrix[16]; /* column-major; the identity is not written */
    int64_t id;        /* >= 0: written as the node's extras {"id": id} */
    int32_t trs;       /* 1: translation / rotation / scale below instead of the matrix */
    double translation[3], rotation[4], scale[3];
    int32_t camera, light; /* index into cameras / lights + 1; 0: none */
    const int32_t *children; uint32_t child_count; /* indices into nodes */
} sy_gltf_shim_wnode;

typedef struct sy_gltf_shim_wdoc {
    const char *generator;
    const sy_gltf_shim_wmaterial *materials; uint32_t material_count;
    const sy_gltf_shim_wmesh *meshes;        uint32_t mesh_count;
    const sy_gltf_shim_wnode *nodes;         uint32_t node_count;
    const int32_t *roots; uint32_t root_count; /* scene 0's nodes; NULL: every node is a root */
    const sy_gltf_shim_wtexture *textures;   uint32_t texture_count;
    const sy_gltf_shim_wcamera *cameras;     uint32_t camera_count;
    const sy_gltf_shim_wlight *lights;       uint32_t light_count;
} sy_gltf_shim_wdoc;

/* Writes doc as GLB into a malloc()ed buffer (*glb_out, *len_out; the caller frees it). Buffers:
 * one binary chunk, one bufferView per attribute / index array, accessors with min / max of
 * positions; indices as uint16 where the primitive has at most 65536 vertices (every index value
 * is below its vertex_count: sy_gltf_write.c checks), uint32 otherwise. SY_ERR_LIMIT when the
 * GLB would exceed 4 GiB - 1 (its 32-bit length), SY_ERR_OUT_OF_MEMORY, SY_ERR_IO when tinygltf
 * reports a failure. EXT_meshopt_compression is not written: tinygltf 2.8's writer serialises
 * every buffer after the first as a data: URI of its bytes and no buffer extensions, so the
 * extension's fallback buffer (a byteLength without data) cannot be expressed. */
sy_result sy_gltf_shim_write_glb(const sy_gltf_shim_wdoc *doc, uint8_t **glb_out, size_t *len_out, sy_error *err);

/* The same document as GLB (binary) or as glTF JSON whose one buffer (geometry and PNG images) is
 * a data: URI (binary false). Same result codes. */
sy_result sy_gltf_shim_write(const sy_gltf_shim_wdoc *doc, bool binary, uint8_t **out, size_t *len_out, sy_error *err);

#ifdef __cplusplus
}
#endif
#endif /* SY_GLTF_SHIM_H */
