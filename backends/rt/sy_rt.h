/** @file
 * sy_rt.h — public API of the Embree ray-tracing back-end (backends/rt).
 *
 * A standalone renderer library with its own small scene API, exactly like a third-party renderer:
 * it knows nothing about the Switchyard scene graph. A mediator (mediators/rt) translates the core
 * scene into these objects and keeps them in sync incrementally.
 *
 * Object model
 *   sy_rt_device   owns everything: Embree device, top-level scene, object pools.
 *   sy_rt_mesh     a prototype triangle mesh (its own Embree scene / BLAS). Data is copied, or
 *                  shared in place when the caller passes a release callback (sy_rt_mesh_desc).
 *   sy_rt_instance a mesh placed in the world with a transform and a material; either an Embree
 *                  instance of the mesh's BLAS, or (SY_RT_INSTANCE_BAKED) world-space triangles
 *                  merged into the top-level BVH.
 *   sy_rt_material glTF 2.0 metallic-roughness material (+ emission, transmission, IOR, alpha).
 *   sy_rt_texture  8-bit (sRGB or linear) or float texture with its sampler.
 *   sy_rt_light    punctual light (point, spot, directional; KHR_lights_punctual units).
 *   Emissive instances become area lights automatically at sy_rt_commit().
 *
 * Handles are one-field structs holding index + generation; id 0 is never valid. A destroyed
 * object's handle becomes stale and every call given it returns SY_RT_ERROR_INVALID_HANDLE.
 * References between objects are by handle and resolved at render time: an instance whose material
 * is stale renders with the default material, a material whose texture is stale ignores it.
 * A mesh stays alive internally until its last instance is destroyed (destroy order is free).
 *
 * Set, then commit, then render: every create/update/destroy stages a change; sy_rt_commit()
 * publishes them (top-level BVH commit, area-light list rebuild when needed). sy_rt_render() on a
 * device with uncommitted changes fails with SY_RT_ERROR_INVALID_OPERATION.
 *
 * Errors (the convention of every Switchyard back-end): every fallible call returns a sy_rt_result
 * (SY_RT_OK == 0), numbered like Switchyard's sy_result for every code they share, and reports the
 * message (naming the object, parameter and reason) once through the device's error callback
 * (sy_rt_device_desc.error, as Embree's rtcSetDeviceErrorFunction), on the calling thread before
 * the call returns; sy_rt_device_error() returns the device's last message. Embree's own errors
 * are captured and reported by the call that caused them. A call given no device (NULL) returns
 * its code only.
 *
 * Thread-safety: one device may be used by one thread at a time (the API does not lock). Several
 * devices are independent. sy_rt_render() itself runs multithreaded over tiles on the process's
 * OpenMP thread team (libgomp), which every Switchyard back-end and filter shares: no device owns
 * threads of its own (Embree keeps its own BVH build threads). OMP_NUM_THREADS sets the default
 * team size and OMP_WAIT_POLICY how idle team threads wait: libgomp's default spins for a while
 * first, best on cores of one's own; where other busy processes share the cores, passive is
 * faster (spinning threads take CPU time from the ones with work). Called from inside an active
 * OpenMP parallel region, a render runs on the calling thread only (unless nesting is enabled).
 *
 * Conventions (shared by every Switchyard back-end): right-handed world, Y up, metres. Cameras look
 * down local -Z with +Y up. Matrices are 4x4 column-major float[16] (glTF): m[12..14] = translation.
 * Image row 0 is the top row; pixel (x, y) covers [x, x+1) x [y, y+1), its centre is (x+0.5, y+0.5).
 * Colour is linear Rec.709 RGB radiance, RGBA premultiplied. Depth is the linear distance along the
 * camera's viewing axis (metres, positive), +INFINITY where nothing was hit.
 */
#ifndef SY_RT_H
#define SY_RT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* >>results */

/** Result codes of every fallible sy_rt call: the numbers of Switchyard's sy_result (core/sy_common.h),
 * which a mediator checks at compile time, so it maps a code with a cast. */
typedef enum sy_rt_result {
    SY_RT_OK = 0,
    SY_RT_ERROR_INVALID_ARGUMENT = 1,   /**< a desc or parameter the API does not accept */
    SY_RT_ERROR_INVALID_HANDLE = 2,     /**< stale, foreign or zero handle */
    SY_RT_ERROR_OUT_OF_MEMORY = 3,
    SY_RT_ERROR_UNSUPPORTED = 6,        /**< well-formed request this back-end does not implement */
    SY_RT_ERROR_LIMIT = 7,              /**< a count or size would overflow or exceeds a pool limit */
    SY_RT_ERROR_EMBREE = 9,             /**< Embree reported an error (message included) */
    SY_RT_ERROR_INVALID_OPERATION = 11, /**< e.g. rendering with uncommitted changes */
    SY_RT_ERROR_CANCELLED = 12,         /**< the progress callback asked to stop */
    SY_RT_ERROR_SYSTEM = 13,            /**< an OS call (creating a mutex) failed */
    SY_RT_RESULT_MAX_ENUM = 0x7fffffff
} sy_rt_result;

/** Short name of a result code ("invalid argument", ...). Static storage. */
const char *sy_rt_result_str(sy_rt_result r);

/* >>handles */

/** A ray-tracing device (opaque): owns every object and the Embree device. */
typedef struct sy_rt_device sy_rt_device;
/** Handle of a triangle mesh. */
typedef struct sy_rt_mesh { uint32_t id; /**< index + generation; 0 = none */ } sy_rt_mesh;
/** Handle of an instance (a mesh placed in the world). */
typedef struct sy_rt_instance { uint32_t id; /**< index + generation; 0 = none */ } sy_rt_instance;
/** Handle of a material. */
typedef struct sy_rt_material { uint32_t id; /**< index + generation; 0 = none */ } sy_rt_material;
/** Handle of a texture. */
typedef struct sy_rt_texture { uint32_t id; /**< index + generation; 0 = none */ } sy_rt_texture;
/** Handle of a punctual light. */
typedef struct sy_rt_light { uint32_t id; /**< index + generation; 0 = none */ } sy_rt_light;

/* >>device */

/** Receives the message of a failed call (no trailing newline; valid during the call only), on the
 * thread that made the call, before the call returns with code. */
typedef void (*sy_rt_error_fn)(void *user, sy_rt_result code, const char *message);

/** Device options (sy_rt_device_create). */
typedef struct sy_rt_device_desc {
    uint32_t thread_count; /**< render and Embree build threads; 0 = the OpenMP default
                            * (OMP_NUM_THREADS, else the cores this process may run on) */
    uint64_t max_memory_bytes; /**< 0: no limit of its own. Else Embree may hold at most this many
                                * bytes (further allocations fail with SY_RT_ERROR_OUT_OF_MEMORY).
                                * Either way a mesh whose BVH would not fit in what is left (or in
                                * the machine's available memory) is refused before it is built,
                                * with the size needed and the size available. */
    sy_rt_error_fn error; /**< every failure of a call on this device (also sy_rt_device_create's); NULL = none */
    void *error_user;     /**< passed to error */
} sy_rt_device_desc;

/** Creates a device. desc may be NULL (defaults). Ownership: *out belongs to the caller, who
 * releases it with sy_rt_device_destroy (which destroys every object it still holds). */
sy_rt_result sy_rt_device_create(const sy_rt_device_desc *desc, sy_rt_device **out);
/** Destroys the device and all its objects. NULL is a no-op. */
void sy_rt_device_destroy(sy_rt_device *dev);
/** The message of the last failed call on dev ("" when none failed yet): the error callback's
 * text. Borrowed, valid until the next call on dev. */
const char *sy_rt_device_error(const sy_rt_device *dev);

/** Publishes all staged changes (BLAS/TLAS commits, area-light list when instances or materials
 * changed). Must be called before sy_rt_render after any change. */
sy_rt_result sy_rt_commit(sy_rt_device *dev);

/** Makes the next sy_rt_commit place every moved instance as a device built from scratch would: in
 * the top-level scene (baked instances re-baked, the top level rebuilt), not through the fast path's
 * twin instances, whose ray transform gives hits that differ from the baked ones in the last bits.
 * Renders after it are bit for bit those of a new device holding the same objects (an image
 * sequence's frame k equals a fresh render at its time); the commit costs a top-level rebuild. */
sy_rt_result sy_rt_settle(sy_rt_device *dev);

/** The top-level scene's builder when most instances move (default off): on, a commit that rebuilds
 * the top level because more than half of the instances (and over 64) moved builds it for frequent
 * updates (Embree's RTC_SCENE_FLAG_DYNAMIC, RTC_BUILD_QUALITY_LOW; Embree 3 cannot refit a scene of
 * instances), every other build (and the one after sy_rt_settle) at the MEDIUM quality a new device
 * builds. Off because it is slower with Embree 3.13: `sy bench anim` (10^4 moving instances) measures
 * both on the same frames, and the dynamic LOW build took 1.5 to 1.8 times as long as MEDIUM.
 * Takes effect at the next top-level build. */
void sy_rt_set_top_fast(sy_rt_device *dev, bool on);

/** Live object counts, for leak diagnostics and tests. */
typedef struct sy_rt_stats {
    /** @{ live objects of each kind */
    uint32_t meshes, instances, materials, textures, lights; /** @} */
    uint32_t area_light_triangles; /**< emissive triangles in the committed area-light list */
    uint64_t version; /**< bumped by every commit that published a change (accumulation restarts) */
    /** Seconds Embree's rtcCommitScene of the top-level scene took in the last sy_rt_commit (0 when
     * that commit did not rebuild it): the part of a commit that is Embree's, not ours. */
    double last_top_commit_seconds;
    /** Full builds of the top-level BVH so far. Moving instances does not rebuild it: a moved
     * instance is shown by a twin in a small second top-level scene until the next full build
     * (anything structural: instances created, destroyed, shown or hidden; or more than about
     * 64 + instances / 64 instances moved since) folds it back. */
    uint64_t top_builds;
    uint64_t top_fast_builds; /**< of them: built for frequent updates (sy_rt_set_top_fast on) */
    uint32_t moved_instances; /**< instances shown by twins now (0 after a full build) */
    /** @{ memory: bytes of mesh arrays the back-end allocated itself (copies: shading normals,
     * texture coordinates, colours; not Embree's), bytes of mesh arrays shared with the caller
     * (sy_rt_mesh_desc.release), and Embree's own allocations now and at their peak (geometry
     * buffers, BVHs, build scratch; counted by rtcSetDeviceMemoryMonitorFunction) */
    uint64_t mesh_bytes, shared_bytes, embree_bytes, embree_peak_bytes; /** @} */
    /** @{ the light tree (sy_rt_render_desc.light_tree), built by the first render that uses it
     * after the lights changed: lights in it (area triangles + punctual lights), bytes it holds
     * (counted with Embree's against max_memory_bytes), seconds of its last full build and of its
     * last refit (lights moved or changed power, the same set), lights that refit changed, full
     * builds and refits so far */
    uint32_t light_tree_lights;
    uint64_t light_tree_bytes;
    double light_tree_build_seconds, light_tree_refit_seconds;
    uint32_t light_tree_refit_changed;
    uint64_t light_tree_builds, light_tree_refits; /** @} */
    /** @{ Emitters the light sampling leaves out (zero-area triangles; lights of zero, negative or
     * non-finite power), counted since the device was created, and the message of the last one
     * (naming the light; "" when none) */
    uint32_t light_warnings;
    char light_warning[256]; /** @} */
} sy_rt_stats;
/** Fills *out with the device's live object counts and version. */
void sy_rt_device_stats(const sy_rt_device *dev, sy_rt_stats *out);

/* >>mesh */

/** Triangle mesh. Ownership: without `release`, every array is COPIED and the caller may free its
 * arrays after the call. With `release`, nothing is copied: the back-end (and Embree, through
 * rtcSetSharedGeometryBuffer) reads the arrays in place until it calls release(release_user) exactly
 * once, when the mesh handle and its last instance are gone; the arrays must not change meanwhile,
 * and positions must stay readable for 16 bytes past its last element (Embree's SIMD loads). When
 * sy_rt_mesh_create fails, release is not called (the caller still owns the arrays).
 * Positions are required and must be finite. Optional arrays are NULL when absent; when present
 * they hold vertex_count elements. Without indices the mesh is a non-indexed triangle list and
 * vertex_count must equal 3 * triangle_count. With indices there are 3 * triangle_count indices
 * and every index must be < vertex_count. */
typedef struct sy_rt_mesh_desc {
    const float *positions;  /**< float3 x vertex_count (required) */
    const float *normals;    /**< float3 x vertex_count or NULL (then geometric normals) */
    const float *uv[2];      /**< float2 x vertex_count per texture-coordinate set, or NULL */
    const float *colors;     /**< float4 RGBA x vertex_count (linear) or NULL (then white) */
    const uint32_t *indices; /**< 3 x triangle_count or NULL */
    uint32_t vertex_count; /**< number of vertices in every per-vertex array */
    uint32_t triangle_count; /**< number of triangles */
    void (*release)(void *release_user); /**< NULL: arrays copied; else shared until this is called */
    void *release_user; /**< argument of release */
    int closed; /**< section caps fill its cut faces: 1 a closed surface wound counter-clockwise seen from outside, -1 the other way, 0 not closed */
} sy_rt_mesh_desc;

/** Creates a mesh from desc (arrays copied or shared, see sy_rt_mesh_desc). Its BLAS is built when
 * its first instance that is not SY_RT_INSTANCE_BAKED is created. */
sy_rt_result sy_rt_mesh_create(sy_rt_device *dev, const sy_rt_mesh_desc *desc, sy_rt_mesh *out);
/** Invalidates the handle; the data is freed once no instance uses it any more. */
sy_rt_result sy_rt_mesh_destroy(sy_rt_device *dev, sy_rt_mesh mesh);
/** Rewrites a mesh's vertices in place (a skinned or morphed mesh's next pose): positions (float3
 * x vertex_count, finite, within the device's coordinate limit) and, exactly when the mesh has
 * normals, normals. Indices, texture coordinates and colours stay. The vertex buffer becomes the
 * device's own (a shared mesh's caller arrays are no longer read for positions and normals) and
 * its BVH is refitted, not rebuilt (Embree RTC_BUILD_QUALITY_REFIT, rtcUpdateGeometryBuffer,
 * rtcCommitGeometry, then the mesh's BLAS and, at the next sy_rt_commit, the top level): the
 * triangles keep their tree, only the boxes grow or shrink, O(triangles). Embree refits only in a
 * dynamic scene (RTC_SCENE_FLAG_DYNAMIC) of build quality LOW, so the first update rebuilds the
 * mesh's BLAS once that way (a tree of lower quality than the static meshes' HIGH); later updates
 * refit. Instances of the mesh see the new shape at the next sy_rt_commit. */
sy_rt_result sy_rt_mesh_update(sy_rt_device *dev, sy_rt_mesh mesh, const float *positions, const float *normals);
/** A mesh's vertices as the device holds them (sy_rt_mesh_get_view). Borrowed from the device: the
 * arrays stay readable until the mesh is next updated (sy_rt_mesh_update and its motion variants
 * rewrite positions in place) or destroyed; they must not be written. */
typedef struct sy_rt_mesh_view {
    const float *positions;  /**< float3 x vertex_count: its pose at ray time 0 (a shared mesh's are the caller's array) */
    const uint32_t *indices; /**< 3 x triangle_count (those of a non-indexed mesh are 0, 1, 2, ...) */
    uint32_t vertex_count;   /**< vertices */
    uint32_t triangle_count; /**< triangles */
} sy_rt_mesh_view;
/** Fills *out with mesh's vertices and indices (a stale handle: SY_RT_ERROR_INVALID_HANDLE, *out
 * zeroed). O(1), no copy: temporal reuse keeps a deforming mesh's previous pose from it before an
 * update (mediators/rt, object motion). */
sy_rt_result sy_rt_mesh_get_view(const sy_rt_device *dev, sy_rt_mesh mesh, sy_rt_mesh_view *out);

/* >>texture */

/** Texel formats of a texture. */
typedef enum sy_rt_texel_format {
    SY_RT_TEXEL_UNORM8 = 1,      /**< 8-bit linear */
    SY_RT_TEXEL_UNORM8_SRGB = 2, /**< 8-bit; RGB channels sRGB-encoded, alpha linear */
    SY_RT_TEXEL_FLOAT32 = 3,     /**< 32-bit float, linear */
    SY_RT_TEXEL_FORMAT_MAX_ENUM = 0x7fffffff
} sy_rt_texel_format;

/** Texture wrap modes. */
typedef enum sy_rt_wrap {
    SY_RT_WRAP_REPEAT = 0,
    SY_RT_WRAP_CLAMP = 1,
    SY_RT_WRAP_MIRROR = 2,
    SY_RT_WRAP_MAX_ENUM = 0x7fffffff
} sy_rt_wrap;

/** Texture filters. */
typedef enum sy_rt_filter {
    SY_RT_FILTER_LINEAR = 0,
    SY_RT_FILTER_NEAREST = 1,
    SY_RT_FILTER_MAX_ENUM = 0x7fffffff
} sy_rt_filter;

/** Texture. Pixels are row-major, row 0 = top row (glTF uv (0,0) is the top-left corner), channels
 * interleaved: 1 = grey, 2 = grey+alpha, 3 = RGB, 4 = RGBA. Ownership: pixels are COPIED. */
typedef struct sy_rt_texture_desc {
    /** @{ channels 1..4 */
    uint32_t width, height, channels; /** @} */
    sy_rt_texel_format format; /**< 8-bit sRGB, 8-bit linear or float texels */
    const void *pixels; /**< uint8_t or float, width*height*channels elements */
    /** @{ wrap mode in u and v */
    sy_rt_wrap wrap_s, wrap_t; /** @} */
    sy_rt_filter filter; /**< texture filter */
} sy_rt_texture_desc;

/** Creates a texture from desc (pixels copied). */
sy_rt_result sy_rt_texture_create(sy_rt_device *dev, const sy_rt_texture_desc *desc,
                                  sy_rt_texture *out);
/** Destroys a texture; references to it become stale (ignored at render time). */
sy_rt_result sy_rt_texture_destroy(sy_rt_device *dev, sy_rt_texture tex);

/* >>material */

/** Alpha modes (glTF). */
typedef enum sy_rt_alpha_mode {
    SY_RT_ALPHA_OPAQUE = 0,
    SY_RT_ALPHA_MASK = 1,  /**< cut out where alpha < alpha_cutoff (also for shadow rays) */
    SY_RT_ALPHA_BLEND = 2, /**< rays blend with what is behind; shadow rays are attenuated by 1 - alpha */
    SY_RT_ALPHA_MODE_MAX_ENUM = 0x7fffffff
} sy_rt_alpha_mode;

/** A texture reference: a zero handle means "no texture". With `transformed` set, the
 * texture-coordinate set is mapped through the 2x3 affine `transform` (row-major:
 * u' = t[0] u + t[1] v + t[2], v' = t[3] u + t[4] v + t[5]; glTF KHR_texture_transform) before the
 * lookup; all entries must be finite. */
typedef struct sy_rt_texture_ref {
    sy_rt_texture texture; /**< {0}: no texture */
    uint32_t texcoord; /**< texture-coordinate set, 0 or 1 */
    bool transformed;  /**< default false: identity */
    float transform[6]; /**< row-major 2x3 affine uv transform (with `transformed`) */
} sy_rt_texture_ref;

/** glTF 2.0 metallic-roughness material. Fill it with sy_rt_material_desc_init (glTF defaults),
 * then set what differs. */
typedef struct sy_rt_material_desc {
    float base_color[4];            /**< linear RGBA factor (default 1,1,1,1) */
    sy_rt_texture_ref base_color_texture; /**< base colour texture (sRGB) */
    /** @{ factors (default 1, 1) */
    float metallic, roughness; /** @} */
    sy_rt_texture_ref metallic_roughness_texture; /**< G = roughness, B = metallic */
    float emissive[3];              /**< radiance: emissiveFactor * emissiveStrength (default 0) */
    sy_rt_texture_ref emissive_texture; /**< emissive texture (sRGB) */
    sy_rt_texture_ref normal_texture; /**< tangent-space normal map */
    float normal_scale;             /**< default 1 */
    float specular;                 /**< KHR_materials_specular factor (default 1; 0 = pure Lambert) */
    float transmission;             /**< KHR_materials_transmission factor (default 0) */
    float ior;                      /**< default 1.5 */
    sy_rt_alpha_mode alpha_mode;    /**< default opaque */
    float alpha_cutoff;             /**< default 0.5 */
    bool double_sided;              /**< default false: emitters emit from the front side only */
    bool unlit;                     /**< KHR_materials_unlit: pixel = base colour */
    sy_rt_texture_ref transmission_texture; /**< R x transmission */
    sy_rt_texture_ref specular_texture;     /**< A x specular */
    float specular_color[3];        /**< KHR_materials_specular colour of the dielectric F0, >= 0 (default 1, 1, 1) */
    sy_rt_texture_ref specular_color_texture; /**< RGB (sRGB) x specular_color */
    float thickness;                /**< KHR_materials_volume: > 0 = a closed volume (default 0: thin-walled) */
    float attenuation_distance;     /**< distance at which light turns attenuation_color; 0 = infinite (default) */
    float attenuation_color[3];     /**< [0, 1], default 1, 1, 1 */
    float clearcoat;                /**< KHR_materials_clearcoat weight, [0, 1] (default 0: no coat) */
    sy_rt_texture_ref clearcoat_texture; /**< R x clearcoat */
    float clearcoat_roughness;      /**< [0, 1] (default 0) */
    sy_rt_texture_ref clearcoat_roughness_texture; /**< G x clearcoat_roughness */
    sy_rt_texture_ref clearcoat_normal_texture; /**< the coat's normal map (else the coat follows the vertex normal) */
    float clearcoat_normal_scale;   /**< its scale (default 1) */
    float sheen_color[3];           /**< KHR_materials_sheen colour, [0, 1] (default 0: no sheen) */
    sy_rt_texture_ref sheen_color_texture; /**< RGB (sRGB) x sheen_color */
    float sheen_roughness;          /**< [0, 1] (default 0; evaluated at 0.07 at least) */
    sy_rt_texture_ref sheen_roughness_texture; /**< A x sheen_roughness */
    float iridescence;              /**< KHR_materials_iridescence weight, [0, 1] (default 0: none) */
    sy_rt_texture_ref iridescence_texture; /**< R x iridescence */
    float iridescence_ior;          /**< the thin film's index, >= 1 (default 1.3) */
    float iridescence_thickness[2]; /**< film thickness in nm, minimum and maximum (default 100, 400) */
    sy_rt_texture_ref iridescence_thickness_texture; /**< G: minimum + G x (maximum - minimum); without it: maximum */
    float anisotropy;               /**< KHR_materials_anisotropy strength, [0, 1] (default 0: isotropic) */
    float anisotropy_rotation;      /**< radians, counter-clockwise from the tangent (+u) (default 0) */
    sy_rt_texture_ref anisotropy_texture; /**< RG direction in tangent space ([-1, 1] as [0, 1]), B x strength */
} sy_rt_material_desc;

/** Fills desc with the glTF 2.0 defaults. */
void sy_rt_material_desc_init(sy_rt_material_desc *desc);
/** Creates a material from desc. */
sy_rt_result sy_rt_material_create(sy_rt_device *dev, const sy_rt_material_desc *desc,
                                   sy_rt_material *out);
/** Replaces every field of a material with desc. */
sy_rt_result sy_rt_material_update(sy_rt_device *dev, sy_rt_material mat,
                                   const sy_rt_material_desc *desc);
/** Destroys a material; instances using it render with the default material. */
sy_rt_result sy_rt_material_destroy(sy_rt_device *dev, sy_rt_material mat);

/* >>instance */

/** The largest coordinate the device accepts, in world units: mesh positions, instance
 * translations, the world bounds of every instance (estimated as |linear| x the mesh's largest
 * coordinate + |translation|), light positions, the camera's position and its orthographic window.
 * Larger ones are refused with SY_RT_ERROR_INVALID_ARGUMENT. With SY_RT_INSTANCE_GAIN_MAX it keeps
 * every ray Embree is given, in world and in instance space, below 3e17, where Embree 3 asserts
 * (aborting the process) beyond 1.844e18. */
#define SY_RT_COORD_MAX 1.0e13f
/** The largest magnification of an instance's inverse transform (the row-sum norm of the inverse of
 * its upper 3x3; 1/s for a uniform scale s) that is instanced: an instance scaled down further is
 * created as if SY_RT_INSTANCE_BAKED (world-space triangles; Embree never transforms a ray into its
 * space). sy_rt_instance_set_transform refuses such a transform for an instance created unbaked. */
#define SY_RT_INSTANCE_GAIN_MAX 1.0e4f

enum {
    /** Static geometry: transformed to world space and merged into the top-level BVH. Moving it
     * re-transforms just its triangles (and rebuilds the top-level BVH at commit). */
    SY_RT_INSTANCE_BAKED = 1u << 0,
    /** Not rendered and casts no shadows (also no area light); toggle with set_visible. */
    SY_RT_INSTANCE_HIDDEN = 1u << 1,
};

/** An instance: a mesh, its object-to-world transform, material and flags. */
typedef struct sy_rt_instance_desc {
    sy_rt_mesh mesh; /**< the mesh it places */
    float transform[16]; /**< object-to-world, column-major; must be finite and invertible, within
                          * SY_RT_COORD_MAX (see there; strong shrinking bakes the instance) */
    sy_rt_material material; /**< zero/stale = default grey material */
    uint32_t flags;          /**< SY_RT_INSTANCE_* */
} sy_rt_instance_desc;

/** Creates an instance from desc. */
sy_rt_result sy_rt_instance_create(sy_rt_device *dev, const sy_rt_instance_desc *desc,
                                   sy_rt_instance *out);
/** Cheap for non-baked instances (rtcSetGeometryTransform + top-level recommit, no BLAS rebuild). */
sy_rt_result sy_rt_instance_set_transform(sy_rt_device *dev, sy_rt_instance inst,
                                          const float transform[16]);
/** Changes an instance's material (zero/stale = default). */
sy_rt_result sy_rt_instance_set_material(sy_rt_device *dev, sy_rt_instance inst,
                                         sy_rt_material material);
/** Shows or hides an instance (hidden: not rendered, casts no shadows, no area light). */
sy_rt_result sy_rt_instance_set_visible(sy_rt_device *dev, sy_rt_instance inst, bool visible);
/** Destroys an instance. */
sy_rt_result sy_rt_instance_destroy(sy_rt_device *dev, sy_rt_instance inst);
/** The instance's transform (time 0) as last set. */
sy_rt_result sy_rt_instance_get_transform(const sy_rt_device *dev, sy_rt_instance inst, float transform[16]);
/** The mesh handle the instance was created with (its data lives while the instance does; the
 * handle itself may be stale once sy_rt_mesh_destroy was called on it). */
sy_rt_result sy_rt_instance_get_mesh(const sy_rt_device *dev, sy_rt_instance inst, sy_rt_mesh *mesh);

/* >>motion blur: each ray has a time in [0, 1): 0 the shutter's open, 1 its close. An instance with
 * motion is placed by its transform at time 0 and by `close` at time 1, the matrix interpolated
 * linearly between them for every ray (Embree's time steps: rtcSetGeometryTimeStepCount 2 on the
 * instance geometry, or on a baked instance's world-space triangles a second vertex buffer; its twin
 * while it moved likewise) and for shading; a deforming mesh likewise gets two vertex time steps
 * (sy_rt_mesh_update_motion). While some instance or mesh has motion, the path tracer gives
 * every pixel sample a stratified time (shadow rays share it) and Whitted takes
 * max(pixel_samples, time_samples) samples per pixel at stratified times and points; without one,
 * every ray has time 0 and renders are bit for bit those without motion. The area lights of
 * emissive moving instances move too: a light sample (path tracer, Whitted) takes the emitter's
 * triangle where it is at the ray's time (Whitted then samples such emitters instead of integrating
 * them in closed form). Not moved over the shutter: the eye-light integrator, picks, coverage, the
 * light tree's bounds (the open's), and section planes' hit test (time 0 placement). */
/** Gives the instance motion to `close` (object-to-world at time 1, checked like a transform; equal
 * to its transform or NULL: no motion). Keeps its transform (time 0); sy_rt_commit publishes it. */
sy_rt_result sy_rt_instance_set_motion(sy_rt_device *dev, sy_rt_instance inst, const float close[16]);
#define SY_RT_MOTION_STEPS_MAX 9 /**< most time steps of a moving instance (sy_rt_instance_set_motion_steps) */
/** Curved motion: the instance placed at `steps` (2 .. SY_RT_MOTION_STEPS_MAX) equally spaced times
 * of the shutter, its transform at time 0 and later[k - 1] (16 floats each, checked like a
 * transform) at time k / (steps - 1), k = 1 .. steps - 1; Embree interpolates the matrix linearly
 * between consecutive steps (rtcSetGeometryTimeStepCount steps; a baked instance: steps vertex
 * buffers), so a turn over the shutter is an arc of steps - 1 chords. Every step equal to the
 * transform: no motion. steps 2 is sy_rt_instance_set_motion(later). sy_rt_commit publishes it. */
sy_rt_result sy_rt_instance_set_motion_steps(sy_rt_device *dev, sy_rt_instance inst, uint32_t steps, const float *later);
/** A deforming mesh's motion: as sy_rt_mesh_update (the same checks), but the vertices (and normals)
 * the mesh has now become its pose at ray time 1 (the shutter's close) and the given ones its pose
 * at time 0 (the open); Embree interpolates each vertex linearly by the ray's time (two time steps
 * on the mesh's geometry, rtcSetGeometryTimeStepCount + vertex buffer slot 1; its BLAS rebuilt as a
 * motion-blur BVH), and so does shading (position, geometric and shading normal of the hit triangle
 * at the ray's time; the normals interpolated linearly, then normalised: the pose between the two is
 * approximated linearly, as Embree does). Texture coordinates and colours do not move; the area
 * lights of an emissive deforming mesh do (light samples on its triangles at the ray's time, as for
 * moving instances above). Not moved: baked instances of the mesh, and what the paragraph above lists. A mesh already in motion moves on: its time-0 pose becomes
 * time 1. sy_rt_commit publishes it. */
sy_rt_result sy_rt_mesh_update_motion(sy_rt_device *dev, sy_rt_mesh mesh, const float *positions, const float *normals);
/** Curved deformation: the mesh's pose at step k (0 = the open .. steps - 2) of a shutter of `steps`
 * (3 .. SY_RT_MOTION_STEPS_MAX) equally spaced times, given from the close towards the open (as
 * sy_rt_instance_set_motion_steps: the syncs of sy_context_motion_begin_steps). The first call on a
 * mesh not in motion keeps the pose it has for every step after k (the close's); each call sets its
 * step and the earlier ones, time 0 (its open pose) last. Embree interpolates the vertices linearly
 * between consecutive steps (steps time steps on the geometry), and so does shading. sy_rt_commit
 * publishes it. */
sy_rt_result sy_rt_mesh_update_steps(sy_rt_device *dev, sy_rt_mesh mesh, uint32_t steps, uint32_t k, const float *positions,
                                     const float *normals);
/** Drops every instance's and mesh's motion (each stays at its transform / time-0 pose);
 * sy_rt_commit publishes it. */
sy_rt_result sy_rt_motion_clear(sy_rt_device *dev);

/* >>light */

/** Punctual light types (KHR_lights_punctual). */
typedef enum sy_rt_light_type {
    SY_RT_LIGHT_POINT = 1,
    SY_RT_LIGHT_SPOT = 2,
    SY_RT_LIGHT_DIRECTIONAL = 3,
    SY_RT_LIGHT_TYPE_MAX_ENUM = 0x7fffffff
} sy_rt_light_type;

/** Punctual light in world space (KHR_lights_punctual units). Point/spot: intensity in candela,
 * irradiance at distance d is color * intensity / d^2 (times the range window when range > 0).
 * Directional: intensity in lux. direction is the direction the light travels (the light node's
 * -Z axis in world space); it need not be normalised. */
typedef struct sy_rt_light_desc {
    sy_rt_light_type type; /**< point, spot or directional */
    float color[3]; /**< linear RGB */
    float intensity; /**< candela (point, spot) or lux (directional) */
    float position[3];  /**< point, spot */
    float direction[3]; /**< spot, directional */
    float range;        /**< point, spot; 0 = infinite */
    /** @{ spot, radians, 0 <= inner < outer <= pi/2 */
    float inner_cone_angle, outer_cone_angle; /** @} */
} sy_rt_light_desc;

/** Creates a punctual light from desc. */
sy_rt_result sy_rt_light_create(sy_rt_device *dev, const sy_rt_light_desc *desc, sy_rt_light *out);
/** Replaces every field of a light with desc. */
sy_rt_result sy_rt_light_update(sy_rt_device *dev, sy_rt_light light, const sy_rt_light_desc *desc);
/** Destroys a light. */
sy_rt_result sy_rt_light_destroy(sy_rt_device *dev, sy_rt_light light);

/* >>background and environment
 *
 * One scene, one look (docs: "One scene, one look"): the BACKGROUND is only what CAMERA rays that
 * hit nothing see (straight through alpha-blended surfaces included); it never lights anything.
 * The ENVIRONMENT (sy_rt_set_environment) is a light: every other ray that leaves the scene
 * (reflection, refraction, diffuse bounce, shadow ray toward it) sees it, and sees black when
 * there is none. Showing the environment behind the scene is a background in TEXTURE mode on the
 * same texture and intensity. */

/** What camera rays see where they hit nothing. */
typedef enum sy_rt_background_mode {
    SY_RT_BACKGROUND_NONE = 0,    /**< transparent: colour 0, alpha 0 */
    SY_RT_BACKGROUND_COLOR = 1,   /**< constant radiance `color`, alpha 1 */
    SY_RT_BACKGROUND_TEXTURE = 2, /**< lat-long `texture` (convention of sy_rt_set_environment) x
                                   * `intensity`, alpha 1; a texture destroyed later shows black */
    SY_RT_BACKGROUND_MODE_MAX_ENUM = 0x7fffffff
} sy_rt_background_mode;

/** The background (sy_rt_set_background). */
typedef struct sy_rt_background {
    sy_rt_background_mode mode; /**< none, colour or texture */
    float color[3];        /**< COLOR: finite, >= 0 */
    sy_rt_texture texture; /**< TEXTURE: a live texture */
    float intensity;       /**< TEXTURE: finite, >= 0 */
} sy_rt_background;

/** Default: SY_RT_BACKGROUND_NONE. Takes effect at the next commit. */
sy_rt_result sy_rt_set_background(sy_rt_device *dev, const sy_rt_background *bg);

/** Environment light: an equirectangular (latitude-longitude) texture times intensity, seen by every
 * ray but camera rays when it leaves the scene. Direction d (unit, world) maps to
 * u = 0.5 + atan2(d.x, -d.z) / (2 pi), v = acos(d.y) / pi, so the image centre is seen looking
 * down -Z and row 0 is straight up (+Y). The PATHTRACER importance-samples it (piecewise-constant
 * distribution over the texels, luminance x sin(theta)) with MIS; WHITTED lights with it in closed
 * form (an irradiance map and GGX maps prefiltered per roughness, built on its first render after
 * the commit) times a visibility ratio from shadow rays toward the same distribution and the BSDF
 * (desc.env_light_samples), and shows it in mirror reflections and refractions. A uniform environment is a 1x1 texture. A zero texture handle removes the
 * environment (escaping rays see black). The texture must stay alive while it is set (a destroyed
 * texture renders as no environment). intensity must be finite and >= 0. Takes effect at the next
 * commit. */
sy_rt_result sy_rt_set_environment(sy_rt_device *dev, sy_rt_texture texture, float intensity);

/* >>render */

/** Camera projections. */
typedef enum sy_rt_projection {
    SY_RT_PROJECTION_PERSPECTIVE = 0,
    SY_RT_PROJECTION_ORTHOGRAPHIC = 1,
    SY_RT_PROJECTION_MAX_ENUM = 0x7fffffff
} sy_rt_projection;

/** Camera. window = {left, right, bottom, top}: for perspective the image-plane window at distance
 * 1 in front of the camera (tangents of the half-angles, so symmetric and off-axis/stereo frusta are
 * the same code), for orthographic the window in camera units. Geometry nearer than near_clip or
 * farther than far_clip (0 = infinite) along the viewing axis is not seen by camera rays. */
typedef struct sy_rt_camera {
    float camera_to_world[16]; /**< column-major; camera looks down local -Z, +Y up */
    sy_rt_projection projection; /**< perspective or orthographic */
    float window[4]; /**< image-plane window {left, right, bottom, top} (see above) */
    /** @{ near and far clip distances along the viewing axis (far 0 = infinite) */
    float near_clip, far_clip; /** @} */
    /** Section planes {a, b, c, d} in world coordinates (at most SY_RT_CLIP_PLANES_MAX; the caller
     * checks them: finite, non-zero normal): a surface point p exists for every ray of the call
     * (camera, reflection, refraction, shadow, pick, coverage) only where a*p.x + b*p.y + c*p.z + d >= 0
     * for each plane. Hits are filtered (an Embree context filter rejects a hit whose point is on a
     * cut side), so a ray that starts in the kept part and crosses a plane still finds what is
     * behind. 0 = nothing cut. */
    uint32_t clip_count;
    float clip_planes[6][4]; /**< the planes {a, b, c, d}, world coordinates */
    /** Capping (with clip_count > 0): nonzero fills the cut faces of closed meshes
     * (sy_rt_mesh_desc.closed). A ray whose first kept hit is a back face of a closed mesh and that
     * entered the kept region (inside every plane) after its start sees, at that entry point on the
     * plane it crossed, the cap: camera rays the flat colour clip_cap_color (linear RGB, unlit),
     * every other ray an opaque black surface (so shadows and reflections see the cap). */
    uint32_t clip_cap;
    float clip_cap_color[3]; /**< the caps' linear RGB */
} sy_rt_camera;
#define SY_RT_CLIP_PLANES_MAX 6 /**< most section planes in a sy_rt_camera */

/** Integrators sy_rt_render can run. */
typedef enum sy_rt_integrator {
    SY_RT_INTEGRATOR_PRIMARY = 1, /**< primary rays only, eye-light shading (benchmarks, debugging) */
    SY_RT_INTEGRATOR_WHITTED = 2, /**< anti-aliased; direct light from punctual, area and environment
                                   * lights (stratified, deterministic) + mirror reflection/refraction */
    SY_RT_INTEGRATOR_PATHTRACER = 3, /**< progressive path tracer (needs a sy_rt_accum, see below) */
    SY_RT_INTEGRATOR_COVERAGE = 4, /**< object ids per pixel, no shading: use sy_rt_coverage() */
    SY_RT_INTEGRATOR_MAX_ENUM = 0x7fffffff
} sy_rt_integrator;

/** Progress report; return false from the callback to cancel the render (tiles not yet started
 * are skipped, those running finish). Called after each finished tile from the render's worker
 * threads (the OpenMP team, the thread that called sy_rt_render among them), serialised (never
 * two calls at once; tiles_done counts up by one per call). */
typedef struct sy_rt_progress {
    /** @{ tiles finished and in all */
    uint32_t tiles_done, tiles_total; /** @} */
} sy_rt_progress;
/** Progress callback: return false to cancel the render (SY_RT_ERROR_CANCELLED). */
typedef bool (*sy_rt_progress_fn)(const sy_rt_progress *progress, void *user_data);

/** Accumulation of a progressive render (opaque; see sy_rt_accum_create). */
typedef struct sy_rt_accum sy_rt_accum;

/** Light selection of the integrators. OFF: the alias table over the emissive triangles by power,
 * punctual lights uniformly (PATHTRACER) or every punctual light at every point (WHITTED). ON: the
 * light tree (backends/rt/sy_rt_lighttree.h), one hierarchy over emissive triangles and punctual
 * lights, each light picked in proportion to its estimated contribution at the shading point
 * (WHITTED then samples punctual lights too, area_light_samples of both per point, instead of the
 * closed-form area light). AUTO: ON from SY_RT_LIGHT_TREE_AUTO_MIN lights (emissive triangles +
 * punctual lights), OFF below. */
typedef enum sy_rt_light_tree_mode {
    SY_RT_LIGHT_TREE_AUTO = 0,
    SY_RT_LIGHT_TREE_ON = 1,
    SY_RT_LIGHT_TREE_OFF = 2
} sy_rt_light_tree_mode;
/** AUTO's threshold (lights). */
#define SY_RT_LIGHT_TREE_AUTO_MIN 64u

/** What to render: integrator, image and rectangle, sampling settings. */
typedef struct sy_rt_render_desc {
    sy_rt_integrator integrator; /**< which integrator runs */
    /** @{ the full image the camera window maps onto */
    uint32_t image_width, image_height; /** @} */
    /** @{ sub-rectangle to fill (row 0 = top) */
    uint32_t x, y, width, height; /** @} */
    uint32_t max_depth;                 /**< WHITTED: recursion depth for reflection/refraction;
                                         * PATHTRACER: most bounces (scattering events) per path;
                                         * 0 = 8 */
    uint32_t area_light_samples;        /**< WHITTED: area-light (emissive triangle) shadow samples per
                                         * pixel, shared among its pixel samples (each shading point
                                         * takes ceil(n / pixel_samples)); they sample only the
                                         * visibility of the closed-form light (up to 64 untextured
                                         * emissive triangles); 0 = 8 there, 16 where they sample
                                         * the light itself (more or textured emitters, the light
                                         * tree) */
    uint32_t seed;                      /**< decorrelates sample patterns; same seed = same image */
    /** WHITTED only: */
    uint32_t pixel_samples;             /**< anti-aliasing: camera rays per pixel through stratified
                                         * jittered points (Owen-scrambled Sobol per pixel), box filter
                                         * over the pixel, twice as many where they disagree (up to
                                         * 64); 0 or 1 = one ray through the pixel centre */
    uint32_t env_light_samples;         /**< environment-light shadow samples (an environment and a
                                         * BSDF direction each) per shading point of each pixel
                                         * sample, for the visibility of the closed-form light;
                                         * 0 = 4 */
    uint32_t time_samples;              /**< while some instance has motion (>>motion blur): the
                                         * fewest samples per pixel, each at its own stratified
                                         * time of the shutter; 0 = 16 */
    sy_rt_progress_fn progress;         /**< optional */
    void *progress_user_data; /**< passed to progress */
    /** PATHTRACER only: */
    sy_rt_accum *accum;                 /**< required: accumulation of this rectangle (width x height) */
    uint32_t samples;                   /**< samples per pixel to add in this call; 0 = 1 */
    struct sy_rt_pt_record *records;    /**< optional: width * height path records (see >>path records);
                                         * NULL = none (no cost) */
    sy_rt_light_tree_mode light_tree;   /**< WHITTED and PATHTRACER: light selection (see
                                         * sy_rt_light_tree_mode); 0 = AUTO */
    struct sy_rt_ray_log *ray_log;      /**< optional: every ray the frame casts (extension and shadow
                                         * rays, with Embree's answers) is appended to this log, for
                                         * the "distance to the limit" benchmark (backends/rt/
                                         * sy_rt_raylog.h); NULL = off (no cost) */
    struct sy_rt_stage_times *stage_times; /**< optional: ticks per stage of the path on a sampled
                                         * subset of the pixels are added here (backends/rt/
                                         * sy_rt_raylog.h >>stage timers); NULL = off */
    /** WHITTED and PATHTRACER, optional (>>motion blur): the camera at ray time 1 (the shutter's
     * close; the camera argument is time 0, the open). Each camera ray is built at its own time: the
     * position, the window (field of view) and the near / far distances interpolated linearly, the
     * orientation by quaternion slerp (a camera matrix whose axes are not orthogonal: its columns
     * linearly); every pixel sample then has its own stratified time as with moving instances
     * (Whitted: at least time_samples samples). Same projection as the camera. NULL, or a camera
     * equal to the camera: a still camera, bit for bit the render without it. */
    const sy_rt_camera *camera_close;
    /** With camera_close, optional (curved camera motion): camera_steps (3 .. SY_RT_MOTION_STEPS_MAX)
     * equally spaced cameras in all, camera_mid the camera_steps - 2 between the open and the close
     * (step k at ray time k / (camera_steps - 1)); each ray interpolates between the two steps around
     * its time as above. 0 or 2: the open and the close alone. */
    const sy_rt_camera *camera_mid;
    /** The cameras in all with camera_mid (3 .. SY_RT_MOTION_STEPS_MAX); 0 or 2: camera_mid unused. */
    uint32_t camera_steps;
} sy_rt_render_desc;

/** Renders the sub-rectangle. rgba: width*height*4 floats (required); depth: width*height floats
 * or NULL (WHITTED: the mean camera-axis distance of the pixel samples that hit, +INFINITY when none
 * did). Row 0 of both buffers is the top row of the sub-rectangle. Deterministic: a pixel's value
 * depends only on the scene, the camera, its full-image coordinates and the render desc's
 * integrator/max_depth/area_light_samples/pixel_samples/env_light_samples/seed, so tiles and
 * sub-rectangles stitch bit-identically.
 *
 * WHITTED: per pixel sample, direct light from punctual lights, emissive triangles and the
 * environment (stratified samples, Owen-scrambled per pixel: no pattern repeats across pixels, no
 * banding, no frame-to-frame change) with shadow rays that pass alpha-masked holes, alpha-blended
 * surfaces (transmittance 1 - alpha) and transmissive surfaces (transmittance base colour x
 * transmission x (1 - F0) per crossing: straight-line, refraction and angular Fresnel ignored);
 * emission adds to the reflected light; recursive perfect mirror reflection and Fresnel refraction. */
sy_rt_result sy_rt_render(sy_rt_device *dev, const sy_rt_camera *camera,
                          const sy_rt_render_desc *desc, float *rgba, float *depth);

/* >>progressive accumulation (PATHTRACER)
 *
 * A sy_rt_accum holds the running per-pixel estimates of one rectangle: colour (RGBA mean),
 * Welford running variance, and the feature buffers (AOVs). sy_rt_render with the PATHTRACER
 * integrator adds desc->samples samples per pixel to desc->accum (sample indices continue from
 * sy_rt_accum_samples), then, when rgba/depth are given, writes the current estimate into them
 * (rgba may be NULL for this integrator). Every sample of pixel (x, y) with index i depends only on
 * the scene, the camera, the full-image coordinates, i, max_depth and seed, and samples are added
 * in index order, so N calls of 1 sample equal 1 call of N samples bit for bit, and sub-rectangles
 * stitch exactly. Restarting (after a visible scene change) is sy_rt_accum_reset.
 *
 * Sampling: Sobol (0,2)-sequence in 4-dimensional padded sets, Owen-scrambled per pixel with the
 * hash-based nested uniform scramble (Burley 2020); pixel samples are uniform over the pixel (box
 * filter of 1 pixel). A sample whose radiance is not finite (NaN/Inf) is dropped and counted; the
 * buffers never receive a non-finite value.
 *
 * Ownership: the caller owns the accum; it is not tied to a device. Thread-safety: an accum is used
 * by one render call at a time. */
/** Creates an accumulation for a width x height rectangle (0 samples). dev (may be NULL) only receives
 * the error report; the accum is not tied to it. */
sy_rt_result sy_rt_accum_create(sy_rt_device *dev, uint32_t width, uint32_t height, sy_rt_accum **out);
void sy_rt_accum_destroy(sy_rt_accum *accum); /**< NULL is a no-op */
void sy_rt_accum_reset(sy_rt_accum *accum);   /**< back to 0 samples */
/** Samples per pixel accumulated since the last reset. */
uint32_t sy_rt_accum_samples(const sy_rt_accum *accum);
/** Size of the accumulation's rectangle. */
void sy_rt_accum_size(const sy_rt_accum *accum, uint32_t *width, uint32_t *height);
/** Samples dropped since the last reset because their radiance was NaN or infinite. */
uint64_t sy_rt_accum_nonfinite(const sy_rt_accum *accum);
/** Rays (closest-hit and shadow) traced by the last render call into this accum (benchmarks). */
uint64_t sy_rt_accum_last_rays(const sy_rt_accum *accum);

/** Feature buffers. Row 0 is the top row of the rectangle; all values are finite except DEPTH
 * (+INFINITY where no sample hit anything). */
typedef enum sy_rt_aov {
    SY_RT_AOV_COLOR = 0,    /**< 4 ch: mean RGBA radiance, premultiplied (alpha = coverage) */
    SY_RT_AOV_VARIANCE = 1, /**< 3 ch: variance of the colour mean per channel, s^2 / n (Welford) */
    SY_RT_AOV_ALBEDO = 2,   /**< 3 ch: base colour at the first non-specular hit (0 on a miss) */
    SY_RT_AOV_NORMAL = 3,   /**< 3 ch: world shading normal there, facing the camera (mean) */
    SY_RT_AOV_DEPTH = 4,    /**< 1 ch: mean camera-axis distance of the first hit */
    SY_RT_AOV_DIRECT = 5,   /**< 3 ch: emission seen directly + light reaching the first hit directly */
    SY_RT_AOV_INDIRECT = 6, /**< 3 ch: the rest; DIRECT + INDIRECT = COLOR (RGB) */
    SY_RT_AOV_COUNT = 7,
    SY_RT_AOV_MAX_ENUM = 0x7fffffff
} sy_rt_aov;
uint32_t sy_rt_aov_channels(sy_rt_aov aov); /**< 0 for an unknown value */
const char *sy_rt_aov_name(sy_rt_aov aov);  /**< "color", "variance", ... ; NULL if unknown */
/** Copies one feature buffer into out (width * height * channels floats, interleaved). dev (may be
 * NULL) only receives the error report. */
sy_rt_result sy_rt_accum_read(sy_rt_device *dev, const sy_rt_accum *accum, sy_rt_aov aov, float *out);
/** Several feature buffers' rows [y0, y1) in one pass over the accumulation (the values
 * sy_rt_accum_read gives): out[k] (NULL = not read) is AOV k's whole buffer (width * height *
 * channels floats), of which only those rows are written. Calls for disjoint rows may run at the
 * same time (a caller's threads split the rows); dev (may be NULL) only receives the error report. */
sy_rt_result sy_rt_accum_read_rows(sy_rt_device *dev, const sy_rt_accum *accum, uint32_t y0, uint32_t y1,
                                   float *const out[SY_RT_AOV_COUNT]);

/* >>path records (PATHTRACER): the stored-sample hook of radiance filtering
 *
 * With desc->records set, the path tracer writes one record per pixel of the rectangle (row 0 =
 * top) describing the LAST sample it traced for that pixel in this call (a radiance filter calls
 * with samples = 1: one path per pixel and frame). A path is split at P0, the first vertex where
 * it sampled a non-specular (finite-density) BSDF lobe; perfect mirrors and refractions before it
 * are followed stochastically (reflect OR refract, as the path tracer always does):
 *   color     = the sample's radiance (what the accumulation received, before any NaN check)
 *             = prefix + throughput * f_cos(wi) / pdf(wi) * incident
 *   prefix    = everything the path gathered before sampling wi at P0: emission seen along the
 *               specular chain and at P0, next-event estimates at the chain's vertices and at P0
 *   incident  = radiance arriving at P0 along wi as estimated by the rest of the path (NEE at
 *               later vertices, emitter and environment hits with their MIS weights, Russian
 *               roulette), NOT multiplied by P0's f * cos / pdf and NOT by the chain throughput.
 * Without SY_RT_RECORD_P0 (a miss, an emitter or unlit surface that ends the path, a path that
 * ended before P0) only color == prefix is meaningful. Values are raw: a NaN/Inf sample shows as
 * such here (the accumulation replaces it by zero and counts it). sy_rt_pt_record_bsdf evaluates
 * P0's BSDF for any direction, so a filter can re-shade a neighbour's incident sample with this
 * pixel's own material, normal and wo. Ownership: caller-owned array; plain data. */
enum { SY_RT_RECORD_P0 = 1u << 0 };
#define SY_RT_RECORD_BSDF_FLOATS 43 /**< floats of the packed BSDF in a record */
/** One path record of the path tracer (see above). */
typedef struct sy_rt_pt_record {
    /** @{ color = the sample's radiance; prefix = what the path gathered before wi (see above) */
    float color[3], prefix[3]; /** @} */
    float position[3];   /**< P0, world */
    float normal[3];     /**< unit shading normal at P0, on the side wo comes from */
    float wo[3];         /**< unit, from P0 toward the previous vertex */
    float ray_dir[3];    /**< unit direction of the ray segment that reached P0 */
    float path_length;   /**< camera -> P0 along the (specular) chain, world units */
    float throughput[3]; /**< camera -> P0 along the chain (1 without specular bounces) */
    float wi[3];         /**< unit direction sampled at P0 (toward the incoming light) */
    float incident[3];   /**< radiance estimate arriving at P0 along wi (see above) */
    float hit_distance;  /**< length of the ray along wi; +INFINITY when it escaped or was not traced */
    float glossy_exponent; /**< Blinn-Phong exponent equivalent to P0's GGX lobes (2 / alpha^2 - 2) when
                              they are sampled with probability >= 1/4, else 0 (diffuse-dominated) */
    uint32_t flags;      /**< SY_RT_RECORD_P0 */
    float bsdf[SY_RT_RECORD_BSDF_FLOATS]; /**< opaque: P0's BSDF for sy_rt_pt_record_bsdf */
} sy_rt_pt_record;

/** f(wo, wi) * |n . wi| of P0's BSDF (RGB, the lobes with a finite density) and the solid-angle pdf
 * with which the path tracer samples wi there (the same mixture it used for the record's own wi).
 * Zero for a record without SY_RT_RECORD_P0. wi is unit, world space. Thread-safe (pure). */
void sy_rt_pt_record_bsdf(const sy_rt_pt_record *record, const float wi[3], float f_cos[3], float *pdf);
/** The same for count directions at once (a filter re-shading many neighbours with one record):
 * structure of arrays, direction m = (wi[0][m], wi[1][m], wi[2][m]) -> f_cos[c][m], pdf[m]; the
 * record is unpacked and its wo-only terms computed once. Results equal count single calls bit
 * for bit. Outputs must not alias inputs. Thread-safe (pure). */
void sy_rt_pt_record_bsdf_batch(const sy_rt_pt_record *record, uint32_t count, const float *const wi[3],
                                float *const f_cos[3], float *pdf);

/* >>coverage
 *
 * Per-pixel visibility for culling services: ids (width * height of the desc's rectangle, row 0 =
 * top) receives, for the ray through each pixel centre, the handle id of the nearest visible
 * (not hidden) instance hit, or 0 where nothing is hit; alpha-masked holes are seen through like
 * in the other integrators. depth may be NULL. The desc's integrator field is ignored (coverage),
 * as are max_depth, area_light_samples and seed. Deterministic and tile-stitchable. */
/** Fills ids (and depth, if not NULL) with the nearest visible instance per pixel centre. */
sy_rt_result sy_rt_coverage(sy_rt_device *dev, const sy_rt_camera *camera, const sy_rt_render_desc *desc,
                            uint32_t *ids, float *depth);
/** One pixel of sy_rt_coverage_hits. Plain data. */
typedef struct sy_rt_coverage_hit {
    uint32_t instance; /**< handle id of the nearest visible instance hit; 0: nothing */
    uint32_t triangle; /**< the hit triangle's index in the instance's mesh (0 on a miss) */
    /** @{ Embree's barycentrics: weights of the triangle's vertices 1 and 2 (0 on a miss) */
    float u, v; /** @} */
} sy_rt_coverage_hit;
/** As sy_rt_coverage, the same rays, with the hit triangle and its barycentrics per pixel (what
 * sy_rt_pick answers for one pixel, for every pixel of the rectangle): temporal reuse follows
 * deforming meshes with them (the hit point at the mesh's previous pose). hits: width * height of the
 * desc's rectangle. */
sy_rt_result sy_rt_coverage_hits(sy_rt_device *dev, const sy_rt_camera *camera, const sy_rt_render_desc *desc,
                                  sy_rt_coverage_hit *hits);

/* >>pick
 *
 * What is under one pixel: the ray through the centre of pixel (x, y) of an image_width x
 * image_height image (the camera ray of sy_rt_coverage and of one-sample renders), its nearest hit
 * on a visible instance (alpha-masked holes seen through, as in every integrator). */
/** A pick's answer (sy_rt_pick). Plain data. */
typedef struct sy_rt_pick_hit {
    sy_rt_instance instance; /**< the instance hit; {0}: nothing */
    uint32_t triangle;       /**< the triangle's index in the instance's mesh */
    /** @{ Embree's barycentrics: weights of the triangle's vertices 1 and 2 */
    float u, v; /** @} */
    float depth;             /**< camera-axis distance of the hit (the depth plane's value) */
    float vertices[3][3];    /**< object-space positions of the triangle's vertices 0, 1, 2 */
    float transform[16];     /**< the instance's object-to-world matrix, column-major */
} sy_rt_pick_hit;
/** Fills *out with what is under pixel (x, y) (x < image_width, y < image_height; else
 * SY_RT_ERROR_INVALID_ARGUMENT). A miss is SY_RT_OK with out->instance {0}. The device must be
 * committed (SY_RT_ERROR_INVALID_OPERATION otherwise). One ray on the calling thread; like every
 * call, not beside another call on the same device. */
sy_rt_result sy_rt_pick(sy_rt_device *dev, const sy_rt_camera *camera, uint32_t image_width, uint32_t image_height,
                        uint32_t x, uint32_t y, sy_rt_pick_hit *out);

#ifdef __cplusplus
}
#endif

#endif /* SY_RT_H */
