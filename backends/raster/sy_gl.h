/** @file
 * sy_gl.h — public API of the OpenGL 3.3 core rasterizer back-end (backends/raster).
 *
 * A standalone renderer library with its own small scene API (meshes, textures, materials,
 * instances, punctual lights, background), like a third-party renderer: it knows nothing about
 * the Switchyard scene graph. A mediator (mediators/raster) translates the core scene into these
 * objects and keeps them in sync incrementally.
 *
 * Context providers (chosen per device): OSMesa (headless software rendering through Mesa's
 * llvmpipe; the default that always works), EGL (headless: an EGL device when a GPU driver
 * offers one, else Mesa's surfaceless platform) and GLFW (a real window; rendering goes to an
 * offscreen framebuffer and is also shown in the window). The same renderer code runs on all
 * three: GL entry points are loaded through the provider's GetProcAddress into a table (no
 * GL library is linked, so OSMesa, EGL and GLX never fight over the global gl* symbols).
 *
 * Object model
 *   sy_gl_device    owns the GL context and every object; one per thread at a time.
 *   sy_gl_mesh      vertex + index buffers (VBO/IBO), uploaded once at creation.
 *   sy_gl_texture   RGBA8 / sRGB8_ALPHA8 / RGBA32F texture with mipmaps and its sampler state.
 *   sy_gl_material  glTF metallic-roughness material; one uniform buffer (UBO) per material (and a
 *                   row of the deferred shading pass's material table, see sy_gl_device_desc.forward).
 *   sy_gl_instance  a mesh placed with a model matrix and a material.
 *   sy_gl_light     point / spot / directional light (KHR_lights_punctual units); directional and
 *                   spot lights cast shadow-mapped shadows.
 *   area lights     up to SY_GL_MAX_AREA_LIGHTS emissive polygons (triangles or quads, world space),
 *                   set as one list (sy_gl_set_area_lights): the mediator's emissive meshes.
 *   environment     a lat-long texture x intensity that lights the scene (sy_gl_set_environment).
 *   background      what camera rays that hit nothing see (sy_gl_set_background); never a light.
 *
 * Handles are one-field structs holding index + generation; id 0 is never valid; stale handles
 * give SY_GL_ERROR_INVALID_HANDLE. References between objects are resolved at render time: an
 * instance whose material is stale renders with the default material.
 *
 * Shading (the BSDF of backends/rt's path tracer): metal GGX with Schlick Fresnel on the base
 * colour (weight metallic), dielectric GGX with spec x Schlick(((ior-1)/(ior+1))^2) (weight
 * (1-metallic)(1-transmission)), Lambert base (1 - that Fresnel)/pi with the same weight, and
 * transmission (weight (1-metallic) transmission); height-correlated Smith visibility.
 *  - punctual lights exactly: point/spot intensity in candela (I/d^2 times the glTF range window),
 *    directional in lux, spot cone falloff clamp((cos - cos_outer)/(cos_inner - cos_outer))^2;
 *  - area lights with linearly transformed cosines (Heitz et al. 2016, clipless form with the
 *    horizon-clipped sphere table; GGX and Lambert); a polygon emits from its front face
 *    (counter-clockwise) only unless double-sided; it does not light points in its own plane;
 *  - the environment with the split-sum approximation: a prefiltered GGX cube (one roughness per
 *    mip) x (F0 A + B) from the BRDF table plus an irradiance cube (E/pi) x diffuse weight, both
 *    times the occlusion texture; transmissive surfaces add Fresnel-weighted reflection and the
 *    environment refracted in and out of a sphere tangent at the point (exact for a glass ball,
 *    base colour tinted);
 *  - scene probes: the first 4 mirror-like or glass instances (roughness <= 0.4; metallic >= 0.5
 *    or transmission >= 0.5) reflect and refract a cube map of the scene rendered from their
 *    bounding-box centre (themselves left out, the environment beyond) instead of the
 *    environment alone; re-rendered when geometry, materials, lights or the environment change;
 *  - emission (a visible front side, both when double-sided) adds to the reflected light; unlit
 *    materials show their base colour (+ emission).
 * Layers (the glTF material extensions; the Khronos glTF Sample Viewer's model, one shader
 * variant for all of them): KHR_materials_specular colours the dielectric F0
 * (min(((ior-1)/(ior+1))^2 x specular_color, 1) x specular) and the diffuse keeps 1 - that
 * Fresnel; a clear coat adds a GGX lobe (F0 0.04, its own roughness, the surface's normal without
 * its normal map) for punctual lights and the environment and scales what lies under it by
 * 1 - clearcoat x Fresnel(n.v); sheen adds sheen_color x Charlie distribution x Neubelt visibility
 * for punctual lights and sheen_color x E x the irradiance for the environment, and scales the
 * base by 1 - max(sheen_color) E(n.v, sheen_roughness), E the sheen lobe's directional albedo
 * (a table the BRDF table's third channel holds, integrated at start-up); volume attenuates the
 * transmitted environment by attenuation_color^(thickness x the instance's scale /
 * attenuation_distance) (Beer-Lambert over the thickness, as the Sample Viewer); anisotropy
 * stretches the GGX lobe along its direction (in the uv tangent frame) for punctual lights and
 * bends the normal for the environment; iridescence replaces the lobes' F0 by the thin film's
 * (mixed by its weight). The extensions' textures, and the transmission texture (read by the
 * transmissive variant, not this one), scale their factors as glTF says where the context has 26
 * texture units (else the factors alone). Emissive polygons see the base scaled by
 * the coat and sheen, the coat's lobe (LTC) and the sheen as a wide lobe of albedo E; no anisotropy.
 * Shadows: directional and spot lights and area lights (from the polygon's centre along its
 * normal, a 150-degree frustum; a Poisson PCF over a penumbra of fixed world radius, 0.3 x the
 * square root of the polygon's area, an approximation without a blocker search) share
 * SY_GL_MAX_SHADOW_MAPS maps, punctual lights first; the first SY_GL_MAX_CUBE_SHADOWS point lights
 * get depth cube maps (half the map size per face); punctual shadows are hard (one bilinear PCF
 * tap), as in the ray tracers. Alpha-masked
 * casters honour the mask; alpha-blended casters block where their opacity reaches the cutoff (the
 * ray tracers let 1 - alpha through; a depth map can only threshold it); transmissive casters
 * (transmission x (1 - metallic) >= 0.5) and emitters cast none, as in the ray tracers, whose
 * shadow rays pass glass with its transmittance and treat emitters as the lights.
 *
 * Output: sy_gl_render fills RGBA float (linear, premultiplied, row 0 = top) and depth (linear
 * distance along the viewing axis, +INFINITY where nothing was drawn) for a sub-rectangle of the
 * full image; pixel (x, y) has its centre at (x + 0.5, y + 0.5) like the ray tracers. With MSAA,
 * colour is the average of the samples and depth the nearest covered sample.
 *
 * Errors (the convention of every Switchyard back-end): every fallible call returns sy_gl_result
 * (SY_GL_OK == 0), numbered like Switchyard's sy_result for every code they share, and reports the
 * message (naming the object, the provider or the GL call, and the reason) once through the
 * device's error callback (sy_gl_device_desc.error), on the calling thread before the call
 * returns; sy_gl_device_error() returns the device's last message. A call given no device (NULL)
 * returns its code only. Warnings (a texture downscaled to the GL limit, a clamped MSAA count) go
 * to the desc's log
 * callback. Thread-safety: a device is used by one thread at a time (its context is made current
 * on that thread by every call); a GLFW device must be created, used and destroyed on the main
 * thread (GLFW's rule for windows and events). OSMesa and EGL devices work from any thread. Conventions: column-major float[16] matrices (glTF), right-handed,
 * Y up, cameras look down local -Z. */
#ifndef SY_GL_H
#define SY_GL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/** Result codes of every fallible sy_gl call: the numbers of Switchyard's sy_result (core/sy_common.h),
 * which a mediator checks at compile time, so it maps a code with a cast. */
typedef enum sy_gl_result {
    SY_GL_OK = 0,
    SY_GL_ERROR_INVALID_ARGUMENT = 1,
    SY_GL_ERROR_INVALID_HANDLE = 2,
    SY_GL_ERROR_OUT_OF_MEMORY = 3,
    SY_GL_ERROR_NO_CONTEXT = 6, /**< the provider could not give a GL 3.3 core context (unsupported here) */
    SY_GL_ERROR_LIMIT = 7,
    SY_GL_ERROR_GL = 9,         /**< a GL call or shader compile failed (log included) */
    SY_GL_RESULT_MAX_ENUM = 0x7fffffff
} sy_gl_result;

/** OpenGL context providers. */
typedef enum sy_gl_provider {
    SY_GL_PROVIDER_OSMESA = 0,
    SY_GL_PROVIDER_EGL = 1,
    SY_GL_PROVIDER_GLFW = 2,
    SY_GL_PROVIDER_MAX_ENUM = 0x7fffffff
} sy_gl_provider;

/** "osmesa", "egl", "glfw". Static storage. */
const char *sy_gl_provider_name(sy_gl_provider p);
/** Parses a provider name; false when unknown. */
bool sy_gl_provider_parse(const char *name, sy_gl_provider *out);

/** An OpenGL renderer with its context (opaque). */
typedef struct sy_gl_device sy_gl_device;
/** Handle of a mesh. */
typedef struct sy_gl_mesh { uint32_t id; /**< index + generation; 0 = none */ } sy_gl_mesh;
/** Handle of a texture. */
typedef struct sy_gl_texture { uint32_t id; /**< index + generation; 0 = none */ } sy_gl_texture;
/** Handle of a material. */
typedef struct sy_gl_material { uint32_t id; /**< index + generation; 0 = none */ } sy_gl_material;
/** Handle of an instance. */
typedef struct sy_gl_instance { uint32_t id; /**< index + generation; 0 = none */ } sy_gl_instance;
/** Handle of a punctual light. */
typedef struct sy_gl_light { uint32_t id; /**< index + generation; 0 = none */ } sy_gl_light;

/** Receives one warning message. */
typedef void (*sy_gl_log_fn)(void *user, const char *message);
/** Receives the message of a failed call (no trailing newline; valid during the call only), on the
 * thread that made the call, before the call returns with code. */
typedef void (*sy_gl_error_fn)(void *user, sy_gl_result code, const char *message);

/** Device options (sy_gl_device_create). */
typedef struct sy_gl_device_desc {
    sy_gl_provider provider; /**< OSMesa, EGL or GLFW */
    uint32_t msaa;             /**< samples per pixel: 0/1 = none, else clamped to GL_MAX_SAMPLES (warning) */
    uint32_t shadow_map_size;  /**< texels per side; 0 = follow the frame: the power of two at or above twice its
                                    larger side, 256 to 2048, never shrinking */
    uint32_t max_texture_size; /**< 0 = GL_MAX_TEXTURE_SIZE; smaller values force downscaling */
    /** @{ GLFW window size; 0 = 640 x 480 */
    uint32_t window_width, window_height; /** @} */
    sy_gl_log_fn log;          /**< warnings; NULL = silent */
    void *log_user; /**< passed to log */
    sy_gl_error_fn error;      /**< every failure of a call on this device (also sy_gl_device_create's); NULL = none */
    void *error_user; /**< passed to error */
    /** Shade every surface in the geometry pass. Default (false): with MSAA, instances of opaque,
     * untextured, non-transmissive materials (at most 256 of them) on meshes without vertex
     * colours, without a scene probe and with small triangles on screen (about 16 pixels or
     * fewer each, where forward shading runs many times per pixel) write a G-buffer, and one
     * pass shades each surface of a pixel once (deferred), in frames without alpha-blended
     * instances. The images agree with forward shading but where the stored geometric normal
     * (14 bits) moves a shadow-map edge, or samples of one surface within 1.8 degrees and
     * 0.1 % depth are shaded once (tests/raster/test_raster_deferred.c). */
    bool forward;
} sy_gl_device_desc;

/** Creates the context and the renderer. On a missing provider (no EGL device/display, no X
 * display for GLFW) fails with SY_GL_ERROR_NO_CONTEXT and a message naming the provider and
 * suggesting the OSMesa fallback. *out is owned by the caller (sy_gl_device_destroy). */
sy_gl_result sy_gl_device_create(const sy_gl_device_desc *desc, sy_gl_device **out);
void sy_gl_device_destroy(sy_gl_device *dev); /**< destroys every object; NULL is a no-op */
/** The message of the last failed call on dev ("" when none failed yet): the error callback's
 * text. Borrowed, valid until the next call on dev. */
const char *sy_gl_device_error(const sy_gl_device *dev);
/** "OpenGL 4.5 (Core Profile) Mesa 22.3.6 on llvmpipe (...)". Borrowed, valid while dev lives. */
const char *sy_gl_device_info(const sy_gl_device *dev);

/** Upload counters. Every call that sends data to GL counts: buffer uploads (glBufferData /
 * glBufferSubData of vertex, index and uniform buffers) and texture uploads (glTexImage2D per
 * level). `frame` holds what happened between the end of the previous sy_gl_render and the end of
 * the last one (object updates + the frame itself); `total` everything since creation. */
typedef struct sy_gl_upload_counts {
    /** @{ VBO + IBO */
    uint64_t vertex_buffer_uploads, vertex_bytes; /** @} */
    /** @{ material and light UBOs */
    uint64_t uniform_buffer_uploads, uniform_bytes; /** @} */
    /** @{ texture uploads (per level) and their bytes */
    uint64_t texture_uploads, texture_bytes; /** @} */
    uint64_t model_matrix_updates; /**< instance transforms set (no GL upload until drawn) */
} sy_gl_upload_counts;
/** Live objects and per-frame counters of a device. */
typedef struct sy_gl_stats {
    /** @{ live objects of each kind */
    uint32_t meshes, textures, materials, instances, lights; /** @} */
    uint32_t msaa_samples;       /**< effective */
    uint32_t shadow_maps;        /**< rendered in the last frame */
    uint64_t triangles_drawn;    /**< last frame, main pass */
    uint64_t draw_calls;         /**< last frame, all passes */
    uint64_t instances_culled;   /**< last frame, main pass: instances outside the view, not drawn */
    uint64_t deferred_draws;     /**< last frame, main pass: instances drawn into the G-buffer (deferred) */
    uint64_t deferred_pixels;    /**< last frame: pixels the deferred pass shaded (the tiles those instances touch) */
    uint64_t programs_built;     /**< main-pass shader programs built since creation (the driver compiles each on
                                      its first draw: most of a first frame's time on llvmpipe) */
    /** @{ uploads of the last frame and since creation */
    sy_gl_upload_counts frame, total; /** @} */
} sy_gl_stats;
/** Fills *out with the device's counters. */
void sy_gl_device_stats(const sy_gl_device *dev, sy_gl_stats *out);

/* >>mesh: arrays are uploaded to GL at creation (one VBO per attribute + one IBO) and not kept. */
/** Triangle mesh (arrays uploaded, not kept). */
typedef struct sy_gl_mesh_desc {
    const float *positions;  /**< float3 x vertex_count (required, finite) */
    const float *normals;    /**< float3 or NULL (flat normals) */
    const float *uv[2];      /**< float2 or NULL */
    const float *colors;     /**< float4 linear RGBA or NULL (white) */
    const uint32_t *indices; /**< 3 x triangle_count or NULL (then vertex_count == 3 x triangle_count) */
    /** @{ vertex and triangle counts */
    uint32_t vertex_count, triangle_count; /** @} */
    int closed; /**< section caps fill its cut faces: 1 a closed surface wound counter-clockwise seen from outside, -1 the other way, 0 not closed */
} sy_gl_mesh_desc;
/** Creates a mesh from desc (uploaded at once). */
sy_gl_result sy_gl_mesh_create(sy_gl_device *dev, const sy_gl_mesh_desc *desc, sy_gl_mesh *out);
/** Destroys a mesh. */
sy_gl_result sy_gl_mesh_destroy(sy_gl_device *dev, sy_gl_mesh mesh);
/** Re-uploads a mesh's vertices (a skinned or morphed mesh's next pose) with one glBufferSubData of
 * its vertex buffer: desc has the mesh's vertex and triangle counts and the same attributes present
 * (positions and normals change; texture coordinates and colours are sent again as given, as the
 * buffer interleaves them); indices are not read (the mesh keeps its own and its levels of detail).
 * Bounds follow. */
sy_gl_result sy_gl_mesh_update(sy_gl_device *dev, sy_gl_mesh mesh, const sy_gl_mesh_desc *desc);

/** Levels of detail: an indexed mesh of at least this many triangles gets, at creation, a chain of
 * simplified levels (meshoptimizer's meshopt_simplify, each about a quarter of the one before, all
 * in its index buffer, each with a bound on its deviation from the mesh). */
#define SY_GL_LOD_MIN_TRIANGLES 8192u
/** Default of sy_gl_set_lod: half a pixel. */
#define SY_GL_LOD_PIXELS_DEFAULT 0.5f
/** Each frame, every instance is drawn with the coarsest level whose deviation, projected at the
 * instance's nearest distance from the camera, stays within `pixels` pixels (0 = always the mesh
 * itself); instances whose bounding sphere is outside the view are not drawn. Shadow maps draw the
 * levels the camera view picked. */
void sy_gl_set_lod(sy_gl_device *dev, float pixels);

/* >>texture: row 0 = top (glTF uv (0,0)); 1 = grey, 2 = grey+alpha, 3 = RGB, 4 = RGBA. Copied
 * to GL (with mipmaps); sizes beyond the GL limit are box-downscaled with a warning. */
/** Texel formats of a texture. */
typedef enum sy_gl_texel_format {
    SY_GL_TEXEL_UNORM8 = 1,
    SY_GL_TEXEL_UNORM8_SRGB = 2, /**< RGB sRGB-encoded, alpha linear (GL_SRGB8_ALPHA8) */
    SY_GL_TEXEL_FLOAT32 = 3,
    SY_GL_TEXEL_FORMAT_MAX_ENUM = 0x7fffffff
} sy_gl_texel_format;
/** Texture wrap modes. */
typedef enum sy_gl_wrap { SY_GL_WRAP_REPEAT = 0, SY_GL_WRAP_CLAMP = 1, SY_GL_WRAP_MIRROR = 2 } sy_gl_wrap;
/** Texture: row 0 = top; 1 = grey, 2 = grey+alpha, 3 = RGB, 4 = RGBA; copied to GL with mipmaps. */
typedef struct sy_gl_texture_desc {
    /** @{ size in pixels and channels (1..4) */
    uint32_t width, height, channels; /** @} */
    sy_gl_texel_format format; /**< 8-bit linear, 8-bit sRGB or float */
    const void *pixels; /**< width * height * channels elements of the format (copied) */
    /** @{ wrap mode in u and v */
    sy_gl_wrap wrap_s, wrap_t; /** @} */
    bool nearest; /**< nearest magnification (else linear); minification is always mipmapped */
} sy_gl_texture_desc;
/** Creates a texture from desc. */
sy_gl_result sy_gl_texture_create(sy_gl_device *dev, const sy_gl_texture_desc *desc, sy_gl_texture *out);
/** Destroys a texture. */
sy_gl_result sy_gl_texture_destroy(sy_gl_device *dev, sy_gl_texture tex);

/* >>material */
/** Alpha modes (glTF). */
typedef enum sy_gl_alpha_mode { SY_GL_ALPHA_OPAQUE = 0, SY_GL_ALPHA_MASK = 1, SY_GL_ALPHA_BLEND = 2 } sy_gl_alpha_mode;
/** A material's reference to a texture. */
typedef struct sy_gl_texture_ref {
    sy_gl_texture texture; /**< zero = none */
    uint32_t texcoord;     /**< 0 or 1 */
    bool transformed;      /**< false: identity; true: uv' = transform (row-major 2x3 affine) x (uv, 1) */
    float transform[6];    /**< KHR_texture_transform; finite */
} sy_gl_texture_ref;
/** glTF 2.0 metallic-roughness material (fill with sy_gl_material_desc_init). */
typedef struct sy_gl_material_desc {
    float base_color[4]; /**< linear RGBA factor */
    sy_gl_texture_ref base_color_texture; /**< base colour texture (sRGB) */
    /** @{ metallic and roughness factors */
    float metallic, roughness; /** @} */
    sy_gl_texture_ref metallic_roughness_texture; /**< G = roughness, B = metallic */
    float emissive[3]; /**< radiance: emissiveFactor * emissiveStrength */
    sy_gl_texture_ref emissive_texture; /**< emissive texture (sRGB) */
    sy_gl_texture_ref normal_texture; /**< tangent-space normal map */
    float normal_scale; /**< normal map scale */
    sy_gl_texture_ref occlusion_texture; /**< R channel, ambient term only */
    float occlusion_strength; /**< occlusion strength */
    /** @{ specular factor, transmission factor, index of refraction */
    float specular, transmission, ior; /** @} */
    sy_gl_alpha_mode alpha_mode; /**< opaque, mask or blend */
    float alpha_cutoff; /**< alpha cutoff of SY_GL_ALPHA_MASK */
    /** @{ both faces are front faces; unlit (pixel = base colour) */
    bool double_sided, unlit; /** @} */
    /* Material extensions. A material whose values are all the defaults below (and without their
     * textures) shades exactly as without them; the others draw with the layered shader variant
     * (see "Layers" in the file comment). Their textures scale the factors as glTF says. */
    float specular_color[3];  /**< KHR_materials_specular: dielectric F0 colour (1, 1, 1 = none), >= 0 */
    float clearcoat;          /**< KHR_materials_clearcoat weight, [0, 1] (0 = no coat) */
    float clearcoat_roughness; /**< [0, 1] */
    float sheen_color[3];     /**< KHR_materials_sheen colour, [0, 1] (0 = no sheen) */
    float sheen_roughness;    /**< [0, 1] */
    float thickness;          /**< KHR_materials_volume thickness, mesh units (0 = thin-walled) */
    float attenuation_distance; /**< world distance light travels in the volume before attenuation_color remains; 0 = infinite */
    float attenuation_color[3]; /**< [0, 1] */
    sy_gl_texture_ref specular_texture;       /**< A x specular */
    sy_gl_texture_ref specular_color_texture; /**< sRGB RGB x specular_color */
    sy_gl_texture_ref clearcoat_texture;      /**< R x clearcoat */
    sy_gl_texture_ref clearcoat_roughness_texture; /**< G x clearcoat_roughness */
    sy_gl_texture_ref clearcoat_normal_texture; /**< the coat's tangent-space normal map */
    float clearcoat_normal_scale;             /**< its scale */
    sy_gl_texture_ref sheen_color_texture;    /**< sRGB RGB x sheen_color */
    sy_gl_texture_ref sheen_roughness_texture; /**< A x sheen_roughness */
    sy_gl_texture_ref thickness_texture;      /**< G x thickness */
    float anisotropy;          /**< KHR_materials_anisotropy strength, [0, 1] (0 = isotropic) */
    float anisotropy_rotation; /**< radians from the uv tangent, counter-clockwise */
    sy_gl_texture_ref anisotropy_texture; /**< RG direction in tangent space ([-1, 1] as [0, 1]), B x strength */
    float iridescence;         /**< KHR_materials_iridescence thin-film weight, [0, 1] (0 = none) */
    float iridescence_ior;     /**< the film's index of refraction (default 1.3) */
    float iridescence_thickness[2]; /**< film thickness in nm: minimum, maximum (default 100, 400) */
    sy_gl_texture_ref iridescence_texture; /**< R x iridescence */
    sy_gl_texture_ref iridescence_thickness_texture; /**< G: minimum to maximum (none: maximum) */
    sy_gl_texture_ref transmission_texture; /**< R x transmission (KHR_materials_transmission) */
} sy_gl_material_desc;
void sy_gl_material_desc_init(sy_gl_material_desc *desc); /**< glTF defaults */
/** Creates a material from desc (one UBO). */
sy_gl_result sy_gl_material_create(sy_gl_device *dev, const sy_gl_material_desc *desc, sy_gl_material *out);
/** One UBO update. */
sy_gl_result sy_gl_material_update(sy_gl_device *dev, sy_gl_material mat, const sy_gl_material_desc *desc);
/** Destroys a material. */
sy_gl_result sy_gl_material_destroy(sy_gl_device *dev, sy_gl_material mat);

/* >>instance */
/** An instance: a mesh placed with a material and a transform. */
typedef struct sy_gl_instance_desc {
    sy_gl_mesh mesh; /**< the mesh it draws */
    sy_gl_material material; /**< its material */
    float transform[16]; /**< object-to-world, finite and invertible */
    bool hidden; /**< not drawn, casts no shadow */
} sy_gl_instance_desc;
/** Creates an instance from desc. */
sy_gl_result sy_gl_instance_create(sy_gl_device *dev, const sy_gl_instance_desc *desc, sy_gl_instance *out);
/** Updates the model matrix only (no GL upload). */
sy_gl_result sy_gl_instance_set_transform(sy_gl_device *dev, sy_gl_instance inst, const float transform[16]);
/** Changes an instance's material. */
sy_gl_result sy_gl_instance_set_material(sy_gl_device *dev, sy_gl_instance inst, sy_gl_material mat);
/** Shows or hides an instance. */
sy_gl_result sy_gl_instance_set_visible(sy_gl_device *dev, sy_gl_instance inst, bool visible);
/** Destroys an instance. */
sy_gl_result sy_gl_instance_destroy(sy_gl_device *dev, sy_gl_instance inst);

/* >>light (world space; direction = where the light travels, need not be normalised) */
/** Punctual light types (KHR_lights_punctual). */
typedef enum sy_gl_light_type { SY_GL_LIGHT_POINT = 1, SY_GL_LIGHT_SPOT = 2, SY_GL_LIGHT_DIRECTIONAL = 3 } sy_gl_light_type;
/** A punctual light (KHR_lights_punctual units, world space). */
typedef struct sy_gl_light_desc {
    sy_gl_light_type type; /**< point, spot or directional */
    /** @{ linear RGB colour; candela (point, spot) or lux (directional) */
    float color[3], intensity; /** @} */
    /** @{ position (point, spot); direction the light travels (spot, directional) */
    float position[3], direction[3]; /** @} */
    float range; /**< 0 = infinite */
    /** @{ spot cone angles, radians */
    float inner_cone_angle, outer_cone_angle; /** @} */
    bool no_shadow; /**< casts no shadow */
} sy_gl_light_desc;
#define SY_GL_MAX_LIGHTS 32 /**< most punctual lights drawn */
#define SY_GL_MAX_SHADOW_MAPS 4 /**< the first spot/directional lights, then area lights, get shadow maps */
#define SY_GL_MAX_CUBE_SHADOWS 2 /**< the first point lights get cube shadow maps (6 faces, half the map size) */
/** Creates a light from desc. */
sy_gl_result sy_gl_light_create(sy_gl_device *dev, const sy_gl_light_desc *desc, sy_gl_light *out);
/** Replaces every field of a light with desc. */
sy_gl_result sy_gl_light_update(sy_gl_device *dev, sy_gl_light light, const sy_gl_light_desc *desc);
/** Destroys a light. */
sy_gl_result sy_gl_light_destroy(sy_gl_device *dev, sy_gl_light light);

/** Background: what camera rays that hit nothing see; it lights nothing. NONE: RGBA 0 (alpha 0);
 * COLOR: color (premultiplied linear RGBA); TEXTURE: the lat-long texture x intensity along each
 * pixel's camera ray (u = 0.5 + atan2(d.x, -d.z) / (2 pi), v = acos(d.y) / pi, row 0 up), alpha 1;
 * a stale texture draws as NONE. Non-finite or negative values are replaced by 0 with a warning. */
typedef enum sy_gl_background_mode {
    SY_GL_BACKGROUND_NONE = 0,
    SY_GL_BACKGROUND_COLOR = 1,
    SY_GL_BACKGROUND_TEXTURE = 2
} sy_gl_background_mode;
/** Sets the background (see sy_gl_background_mode). */
void sy_gl_set_background(sy_gl_device *dev, sy_gl_background_mode mode, const float color[4], sy_gl_texture texture,
                          float intensity);

/** Environment light: a lat-long texture (same convention; texels are radiance) x intensity, or none
 * (texture 0 or intensity 0). When it changes, the next render prefilters it on the GPU (one
 * specular and one irradiance cube map; see sy_gl_ibl.h). Destroying the texture removes the light. */
void sy_gl_set_environment(sy_gl_device *dev, sy_gl_texture texture, float intensity);

/** Emissive polygons as area lights (replaces the previous list; an unchanged list costs nothing).
 * Vertices in world space, convex and planar; the front face is counter-clockwise. */
typedef struct sy_gl_area_light {
    float vertices[4][3]; /**< corners, world space (vertex_count used) */
    uint32_t vertex_count; /**< 3 or 4 */
    float radiance[3];     /**< finite, >= 0 */
    bool double_sided; /**< emits from both faces */
} sy_gl_area_light;
#define SY_GL_MAX_AREA_LIGHTS 16 /**< most area lights drawn */
/** The indirect light of the area lights as one radiance (the mediator's estimate): wherever area
 * lights are set, non-emissive surfaces add (diffuse + specular weight) x ambient x occlusion x
 * (1 + 0.75 n.d), d = the lights' flux-weighted mean emission direction (surfaces facing the way the
 * lights shine see the directly lit ones). Non-finite or negative components are replaced by 0
 * with a warning. */
void sy_gl_set_ambient(sy_gl_device *dev, const float radiance[3]);
/** Sets the area lights (at most SY_GL_MAX_AREA_LIGHTS). */
sy_gl_result sy_gl_set_area_lights(sy_gl_device *dev, const sy_gl_area_light *lights, uint32_t count);

/* >>render */
/** Camera (same convention as the ray tracers). */
typedef struct sy_gl_camera {
    float camera_to_world[16]; /**< column-major; the camera looks down local -Z, +Y up */
    bool orthographic; /**< orthographic projection (else perspective) */
    float window[4]; /**< {left, right, bottom, top}: tangent space at distance 1 (perspective) or camera units */
    /** @{ far 0 = infinite */
    float near_clip, far_clip; /** @} */
    /** Section planes {a, b, c, d} in world coordinates (the caller checks them: finite, non-zero
     * normal): only surface points with a*x + b*y + c*z + d >= 0 for each plane are drawn, in the
     * main (forward and deferred), shadow-map, probe and pick passes alike (gl_ClipDistance). */
    uint32_t clip_count; /**< 0..SY_GL_CLIP_PLANES_MAX; 0 = nothing cut */
    float clip_planes[6][4]; /**< the planes {a, b, c, d}, world coordinates */
    /** Capping (with clip_count > 0): nonzero fills the cut faces of closed meshes
     * (sy_gl_mesh_desc.closed) in clip_cap_color (linear RGB, flat, unlit): their back faces seen
     * through the cut are drawn at the point where the pixel's ray enters the kept region (depth
     * written there), like the ray tracers' caps. */
    uint32_t clip_cap;
    float clip_cap_color[3]; /**< the caps' linear RGB */
} sy_gl_camera;
#define SY_GL_CLIP_PLANES_MAX 6 /**< most section planes in a sy_gl_camera */
/** What to render: the full image and the rectangle to fill. */
typedef struct sy_gl_render_desc {
    /** @{ the full image the camera window maps onto */
    uint32_t image_width, image_height; /** @} */
    /** @{ sub-rectangle, row 0 = top */
    uint32_t x, y, width, height; /** @} */
} sy_gl_render_desc;
/** Renders and reads back: rgba (width*height*4 floats) and depth (width*height, may be NULL). */
sy_gl_result sy_gl_render(sy_gl_device *dev, const sy_gl_camera *cam, const sy_gl_render_desc *desc, float *rgba,
                          float *depth);
/** What is under one pixel (sy_gl_pick). Plain data. */
typedef struct sy_gl_pick_hit {
    sy_gl_instance instance; /**< the nearest visible instance drawn at the pixel's centre; {0}: none */
    uint32_t triangle;       /**< the triangle's index in its mesh (the mesh as given, never a coarser level) */
} sy_gl_pick_hit;
/** Names the instance and triangle drawn at the centre of pixel (x, y) of an image_width x
 * image_height image with cam: an ID pass over a 1x1 target (a window of the image plane 64 times
 * narrower than the pixel, centred on its centre, no MSAA: the sample at the pixel's centre with
 * the rasterizer's sub-pixel snapping 64 times finer, so that a centre near an edge two triangles
 * share goes to the one the ray meets), every visible instance at its full level of
 * detail, no face culling, alpha-masked materials cut out (base colour factor x base texture alpha
 * at full resolution, as the ray tracers read it, x vertex alpha against the cutoff), alpha-blended
 * ones drawn as opaque (the ray tracers' camera rays stop at them too).
 * Nothing there: SY_GL_OK with out->instance {0}. A pixel outside the image:
 * SY_GL_ERROR_INVALID_ARGUMENT. Costs one pass over the instances the pixel's frustum keeps. */
sy_gl_result sy_gl_pick(sy_gl_device *dev, const sy_gl_camera *cam, uint32_t image_width, uint32_t image_height,
                        uint32_t x, uint32_t y, sy_gl_pick_hit *out);
/** An ID image: for every pixel centre of desc's rectangle (row 0 = top), the handle id of the
 * nearest visible instance drawn there (0: none), by the pick's ID pass (every visible instance at
 * full detail, no culling, alpha-masked materials cut out) over a width x height target with one
 * sample per pixel at its centre. ids: desc->width * desc->height. Costs one pass over the
 * instances in the rectangle's frustum and one read-back. */
sy_gl_result sy_gl_ids(sy_gl_device *dev, const sy_gl_camera *cam, const sy_gl_render_desc *desc, uint32_t *ids);
/** GLFW provider: true once the user asked to close the window (false for other providers). */
bool sy_gl_window_should_close(sy_gl_device *dev);

/* >>bench: the floor — draws every visible instance's buffers with a trivial shader into the same
 * targets (MSAA included), then resolves and reads back colour and depth like sy_gl_render.
 * Unlit: one constant colour, position only. lit ("trivial lit"): one directional light, Lambert
 * on the interpolated vertex normal, plus a constant ambient; no shadows, no environment. */
/** Benchmark floor: every visible instance drawn with a trivial shader (lit: one directional
 * Lambert light) into the same targets, read back into rgba and depth (NULL: not read) as
 * sy_gl_render does. */
sy_gl_result sy_gl_render_floor(sy_gl_device *dev, const sy_gl_camera *cam, const sy_gl_render_desc *desc, bool lit,
                                float *rgba, float *depth);

#ifdef __cplusplus
}
#endif
#endif /* SY_GL_H */
