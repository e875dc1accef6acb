/** @file
 * sy_mirror_flat.h — flat descriptions: what a mirrored texture, material, primitive and light
 * mean to a back-end, decided once for every back-end.
 *
 * The scene mirror (sy_mirror.h) hands each callback the object's core fields and, beside them,
 * its flat description: plain numbers, array pointers and back-end handles, with the reading every
 * back-end must share already applied (texel format and filter chosen from the pixel format and
 * sampler; texture references resolved to back-end handles with their uv transform as a matrix;
 * emission = factor x strength; an ior below 1 read as 1.5; the blobs of a primitive as arrays
 * with their counts; a light's type as a back-end light type). A mediator then only copies the
 * fields into its back-end's own descriptor; what its device cannot take (ranges, clamps) stays
 * the mediator's. The enumerations are numbered like the back-ends' own (sy_rt.h, sy_gl.h), so a
 * cast translates them; a mediator that casts checks the numbers with SY_MIRROR_FLAT_SAME_NUMBERS.
 *
 * Ownership: a description borrows every pointer from the mirror for the duration of the callback
 * that receives it (pixels, vertex and index arrays); copy or retain what outlives the call.
 * Thread-safety: the functions are pure (they read their arguments only) and reentrant. */
#ifndef SY_MIRROR_FLAT_H
#define SY_MIRROR_FLAT_H

#include "sy_objects.h"

#include <stdbool.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/** Texel formats, numbered like sy_rt_texel_format and sy_gl_texel_format. */
typedef enum sy_mirror_flat_texel {
    SY_MIRROR_FLAT_UNORM8 = 1,      /**< 8-bit linear data */
    SY_MIRROR_FLAT_UNORM8_SRGB = 2, /**< 8-bit, RGB sRGB-encoded, alpha linear */
    SY_MIRROR_FLAT_FLOAT32 = 3,     /**< 32-bit float, linear */
} sy_mirror_flat_texel;

/** A complete texture. */
typedef struct sy_mirror_flat_texture {
    /** @{ size in pixels */
    uint32_t width, height; /** @} */
    uint32_t channels; /**< 1 grey, 2 grey + alpha, 3 RGB, 4 RGBA */
    sy_mirror_flat_texel format; /**< texel format */
    const void *pixels; /**< width x height x channels texels, rows top first (borrowed) */
    /** @{ sy_wrap (repeat 0, clamp 1, mirror 2: numbered like sy_rt_wrap and sy_gl_wrap) */
    uint32_t wrap_s, wrap_t; /** @} */
    bool nearest; /**< magnification filter nearest (else linear) */
} sy_mirror_flat_texture;

/** A material's use of a texture. */
typedef struct sy_mirror_flat_texture_ref {
    uint32_t id;       /**< core texture id, 0 = none */
    uint32_t handle;   /**< back-end texture, 0 = none (no texture, or not complete) */
    uint32_t texcoord; /**< texture-coordinate set, 0 or 1 */
    bool transformed;  /**< false: identity */
    float transform[6]; /**< KHR_texture_transform as a row-major 2x3 affine matrix (sy_texture_ref_matrix) */
} sy_mirror_flat_texture_ref;

/** A glTF 2.0 metallic-roughness material as a back-end reads it. */
typedef struct sy_mirror_flat_material {
    float base_color[4]; /**< linear RGBA factor */
    sy_mirror_flat_texture_ref base_color_texture; /**< sRGB */
    /** @{ factors */
    float metallic, roughness; /** @} */
    sy_mirror_flat_texture_ref metallic_roughness_texture; /**< B metallic, G roughness */
    float emissive[3]; /**< emitted radiance factor: emissive factor x emissive strength */
    sy_mirror_flat_texture_ref emissive_texture; /**< sRGB */
    sy_mirror_flat_texture_ref normal_texture; /**< tangent space */
    float normal_scale; /**< the normal texture's scale */
    sy_mirror_flat_texture_ref occlusion_texture; /**< R */
    float occlusion_strength; /**< the occlusion texture's strength */
    float transmission; /**< KHR_materials_transmission factor, [0, 1] */
    sy_mirror_flat_texture_ref transmission_texture; /**< R x transmission */
    float ior; /**< index of refraction; a value below 1 reads as glTF's 1.5 */
    uint32_t alpha_mode; /**< sy_alpha_mode (opaque 0, mask 1, blend 2: numbered like the back-ends') */
    float alpha_cutoff; /**< cutoff of the mask mode */
    bool double_sided; /**< both faces are front faces */
    bool unlit; /**< KHR_materials_unlit */
    /* The material extensions (docs/MATERIALS.md says how each back-end reads them). Factors the
     * specifications bound to [0, 1] arrive clamped there. */
    float specular; /**< KHR_materials_specular factor, [0, 1] (1 without the extension) */
    sy_mirror_flat_texture_ref specular_texture; /**< A x specular */
    float specular_color[3]; /**< dielectric F0 colour, >= 0 (1 without the extension) */
    sy_mirror_flat_texture_ref specular_color_texture; /**< sRGB RGB x specular_color */
    float clearcoat; /**< KHR_materials_clearcoat weight, [0, 1]; 0 = no coat */
    sy_mirror_flat_texture_ref clearcoat_texture; /**< R x clearcoat */
    float clearcoat_roughness; /**< [0, 1] */
    sy_mirror_flat_texture_ref clearcoat_roughness_texture; /**< G x clearcoat_roughness */
    sy_mirror_flat_texture_ref clearcoat_normal_texture; /**< the coat's normal map */
    float clearcoat_normal_scale; /**< its scale */
    float sheen_color[3]; /**< KHR_materials_sheen colour, [0, 1]; 0 = no sheen */
    sy_mirror_flat_texture_ref sheen_color_texture; /**< sRGB RGB x sheen_color */
    float sheen_roughness; /**< [0, 1] */
    sy_mirror_flat_texture_ref sheen_roughness_texture; /**< A x sheen_roughness */
    float thickness; /**< KHR_materials_volume thickness (mesh units); 0 = thin-walled */
    sy_mirror_flat_texture_ref thickness_texture; /**< G x thickness */
    float attenuation_distance; /**< 0 = infinite (no absorption) */
    float attenuation_color[3]; /**< [0, 1] */
    float iridescence; /**< KHR_materials_iridescence weight, [0, 1]; 0 = none */
    sy_mirror_flat_texture_ref iridescence_texture; /**< R x iridescence */
    float iridescence_ior; /**< the film's index, >= 1 */
    float iridescence_thickness[2]; /**< film thickness in nm: minimum, maximum */
    sy_mirror_flat_texture_ref iridescence_thickness_texture; /**< G: minimum to maximum */
    float anisotropy; /**< KHR_materials_anisotropy strength, [0, 1]; 0 = isotropic */
    float anisotropy_rotation; /**< radians from the tangent, counter-clockwise */
    sy_mirror_flat_texture_ref anisotropy_texture; /**< RG direction, B x strength */
} sy_mirror_flat_material;

/** One triangle primitive's arrays (every per-vertex array has vertex_count entries). */
typedef struct sy_mirror_flat_mesh {
    const float *positions; /**< float3 */
    const float *normals;   /**< float3 or NULL */
    const float *uv[2];     /**< float2 per texture-coordinate set, or NULL */
    const float *colors;    /**< float4 linear RGBA or NULL */
    const uint32_t *indices; /**< 3 x triangle_count, or NULL: the vertices in order */
    /** @{ counts */
    uint32_t vertex_count, triangle_count; /** @} */
} sy_mirror_flat_mesh;

/** Light types, numbered like sy_rt_light_type and sy_gl_light_type. */
typedef enum sy_mirror_flat_light_type {
    SY_MIRROR_FLAT_POINT = 1,
    SY_MIRROR_FLAT_SPOT = 2,
    SY_MIRROR_FLAT_DIRECTIONAL = 3,
} sy_mirror_flat_light_type;

/** A punctual light of one placement, in world space. */
typedef struct sy_mirror_flat_light {
    sy_mirror_flat_light_type type; /**< point (also for an unknown type), spot or directional */
    float color[3]; /**< linear RGB */
    float intensity; /**< candela (point, spot) or lux (directional) */
    float range; /**< 0 = infinite */
    /** @{ spot cone angles, radians (inner < outer: the mirror reads inner >= outer as a hard edge) */
    float inner_cone, outer_cone; /** @} */
    float position[3]; /**< world position (point, spot) */
    float direction[3]; /**< world direction the light travels: the node's -Z (spot, directional) */
} sy_mirror_flat_light;

/** Checks at compile time that back-end PREFIX (SY_RT, SY_GL) numbers its texel formats
 * (PREFIX_TEXEL_UNORM8, ...) and light types (PREFIX_LIGHT_POINT, ...) like this header, so that
 * a cast translates them. */
#define SY_MIRROR_FLAT_SAME_NUMBERS(PREFIX)                                                                   \
    _Static_assert(SY_MIRROR_FLAT_UNORM8 == (int)PREFIX##_TEXEL_UNORM8 &&                                     \
                       SY_MIRROR_FLAT_UNORM8_SRGB == (int)PREFIX##_TEXEL_UNORM8_SRGB &&                        \
                       SY_MIRROR_FLAT_FLOAT32 == (int)PREFIX##_TEXEL_FLOAT32 &&                                \
                       SY_MIRROR_FLAT_POINT == (int)PREFIX##_LIGHT_POINT &&                                    \
                       SY_MIRROR_FLAT_SPOT == (int)PREFIX##_LIGHT_SPOT &&                                      \
                       SY_MIRROR_FLAT_DIRECTIONAL == (int)PREFIX##_LIGHT_DIRECTIONAL,                          \
                   #PREFIX " numbers texel formats and light types like sy_mirror_flat.h")

/** The material fields both back-ends' descriptions (sy_rt_material_desc, sy_gl_material_desc)
 * name and type like sy_mirror_flat_material and take unchanged, as tables: X(field, ...) for each,
 * the rest of the arguments passed on. The fields a mediator maps (clamps, scales) or only one
 * back-end has are not listed. This table: the plain values (copied by assignment). */
#define SY_MIRROR_FLAT_MATERIAL_VALUES(X, ...)                                                                 \
    X(normal_scale, __VA_ARGS__) X(ior, __VA_ARGS__) X(double_sided, __VA_ARGS__) X(unlit, __VA_ARGS__)        \
    X(clearcoat, __VA_ARGS__) X(clearcoat_roughness, __VA_ARGS__) X(clearcoat_normal_scale, __VA_ARGS__)       \
    X(sheen_roughness, __VA_ARGS__) X(thickness, __VA_ARGS__) X(attenuation_distance, __VA_ARGS__)             \
    X(iridescence, __VA_ARGS__) X(iridescence_ior, __VA_ARGS__) X(anisotropy, __VA_ARGS__)                     \
    X(anisotropy_rotation, __VA_ARGS__)
/** The arrays among them (copied with memcpy; the lengths are checked to be the same). */
#define SY_MIRROR_FLAT_MATERIAL_ARRAYS(X, ...)                                                                 \
    X(specular_color, __VA_ARGS__) X(attenuation_color, __VA_ARGS__) X(sheen_color, __VA_ARGS__)               \
    X(iridescence_thickness, __VA_ARGS__)
/** The texture references among them (copied through the mediator's texture-reference copy). */
#define SY_MIRROR_FLAT_MATERIAL_TEXTURES(X, ...)                                                               \
    X(base_color_texture, __VA_ARGS__) X(metallic_roughness_texture, __VA_ARGS__)                              \
    X(emissive_texture, __VA_ARGS__) X(normal_texture, __VA_ARGS__) X(specular_texture, __VA_ARGS__)           \
    X(specular_color_texture, __VA_ARGS__) X(transmission_texture, __VA_ARGS__)                                \
    X(clearcoat_texture, __VA_ARGS__) X(clearcoat_roughness_texture, __VA_ARGS__)                              \
    X(clearcoat_normal_texture, __VA_ARGS__) X(sheen_color_texture, __VA_ARGS__)                               \
    X(sheen_roughness_texture, __VA_ARGS__) X(iridescence_texture, __VA_ARGS__)                                \
    X(iridescence_thickness_texture, __VA_ARGS__) X(anisotropy_texture, __VA_ARGS__)
/** Copies the listed fields of the flat material m (a pointer) into the back-end description d (a
 * pointer), the texture references through TEXREF (a function of const sy_mirror_flat_texture_ref *);
 * needs <string.h>. */
#define SY_MIRROR_FLAT_MATERIAL_COPY(d, m, TEXREF)                                                            \
    do {                                                                                                       \
        SY_MIRROR_FLAT_MATERIAL_VALUES(SY_MIRROR_FLAT_COPY_VALUE_, d, m, TEXREF)                              \
        SY_MIRROR_FLAT_MATERIAL_ARRAYS(SY_MIRROR_FLAT_COPY_ARRAY_, d, m, TEXREF)                              \
        SY_MIRROR_FLAT_MATERIAL_TEXTURES(SY_MIRROR_FLAT_COPY_TEXTURE_, d, m, TEXREF)                          \
    } while (0)
/** SY_MIRROR_FLAT_MATERIAL_COPY's step for one value. */
#define SY_MIRROR_FLAT_COPY_VALUE_(f, d, m, TEXREF) (d)->f = (m)->f;
/** SY_MIRROR_FLAT_MATERIAL_COPY's step for one array. */
#define SY_MIRROR_FLAT_COPY_ARRAY_(f, d, m, TEXREF)                                                            \
    _Static_assert(sizeof (d)->f == sizeof (m)->f, #f " has the flat material's length");                     \
    memcpy((d)->f, (m)->f, sizeof (d)->f);
/** SY_MIRROR_FLAT_MATERIAL_COPY's step for one texture reference. */
#define SY_MIRROR_FLAT_COPY_TEXTURE_(f, d, m, TEXREF) (d)->f = TEXREF(&(m)->f);

/** Defines `static TYPE NAME(const sy_mirror_flat_texture_ref *r)`: the back-end's texture reference
 * (TYPE: sy_rt_texture_ref, sy_gl_texture_ref; laid out as {handle, texcoord, transformed,
 * transform[6]}) of a flat one. */
#define SY_MIRROR_FLAT_TEXREF_FN(NAME, TYPE)                                                                  \
    static TYPE NAME(const sy_mirror_flat_texture_ref *r)                                                     \
    {                                                                                                          \
        TYPE o = {{r->handle}, r->texcoord, r->transformed, {0}};                                              \
        _Static_assert(sizeof o.transform == sizeof r->transform, #TYPE " has the flat transform's length");    \
        memcpy(o.transform, r->transform, sizeof o.transform);                                                 \
        return o;                                                                                              \
    }

/** Copies the view v (const sy_camera_view *) into the back-end camera cam (sy_rt_camera *,
 * sy_gl_camera *: camera_to_world, window, near_clip, far_clip, clip_count, clip_planes); PREFIX
 * (SY_RT, SY_GL) names the back-end's section-plane bound, checked to be core's. The projection
 * is the mediator's to set (the back-ends name it differently). Needs <string.h>. */
#define SY_MIRROR_FLAT_VIEW_COPY(cam, v, PREFIX)                                                              \
    do {                                                                                                       \
        _Static_assert(PREFIX##_CLIP_PLANES_MAX == SY_CLIP_PLANES_MAX, "one section plane array");            \
        memcpy((cam)->camera_to_world, (v)->camera_to_world.m, sizeof (cam)->camera_to_world);                \
        memcpy((cam)->window, (v)->window, sizeof (cam)->window);                                             \
        (cam)->near_clip = (v)->znear;                                                                         \
        (cam)->far_clip = (v)->zfar;                                                                           \
        (cam)->clip_count = (v)->clip_count < SY_CLIP_PLANES_MAX ? (v)->clip_count : SY_CLIP_PLANES_MAX;      \
        memcpy((cam)->clip_planes, (v)->clip_planes, sizeof (cam)->clip_planes);                              \
        (cam)->clip_cap = (v)->clip_count && (v)->clip_cap;                                                    \
        memcpy((cam)->clip_cap_color, (v)->clip_cap_color, sizeof (cam)->clip_cap_color);                     \
    } while (0)

/** Describes a texture whose pixels match info. */
void sy_mirror_flat_texture_of(const sy_image_info *info, const sy_sampler *sampler, const void *pixels,
                               sy_mirror_flat_texture *out);

/** The mean linear RGB of a texture (sRGB decoded; grey read as R = G = B; non-finite texels
 * skipped; 0 for an empty one) into mean, and of each block of a gw x gh partition into blocks
 * (blocks[3 (j gw + i) ..] for block (i, j): texel columns [i w / gw, (i + 1) w / gw), rows likewise,
 * row 0 at the top), in one pass over the pixels; 1 <= gw <= width, 1 <= gh <= height unless the
 * texture is empty. The raster mediator's albedo estimate takes the mean, its textured emitters
 * light with their triangles' own blocks. False without memory. */
bool sy_mirror_flat_texture_means(const sy_mirror_flat_texture *t, uint32_t gw, uint32_t gh, float mean[3], float *blocks);

/** Back-end handle of a core texture id (0 = none), as the caller's mirror knows it. */
typedef uint32_t (*sy_mirror_flat_handle_fn)(const void *user, uint32_t texture_id);

/** Describes a material; handle_of resolves its texture ids (called only for ids != 0). */
void sy_mirror_flat_material_of(const sy_material_data *d, sy_mirror_flat_handle_fn handle_of, const void *user,
                                sy_mirror_flat_material *out);

/** Describes a triangle primitive (its blobs as arrays, its counts). */
void sy_mirror_flat_mesh_of(const sy_primitive *p, sy_mirror_flat_mesh *out);

/** sy_mesh_closed (core/sy_math.h) of a flat mesh: 1 closed and wound outward, -1 inward, 0 not closed. */
int sy_mirror_flat_mesh_closed(const sy_mirror_flat_mesh *m);

/** Describes a light at a world position and direction. */
void sy_mirror_flat_light_of(const sy_light_data *l, const float position[3], const float direction[3],
                             sy_mirror_flat_light *out);

#ifdef __cplusplus
}
#endif
#endif /* SY_MIRROR_FLAT_H */
