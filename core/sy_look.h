/** @file
 * sy_look.h — what a scene means, defined once for every back-end: the environment light, the
 * background, the default lighting of a scene that brings none, and the shared lat-long convention.
 *
 * The rules (docs/BACKENDS.md, "One scene, one look"):
 *  - The background is what camera rays see where they hit nothing: transparent, a colour, the
 *    environment texture, or an X3D sky/ground gradient. It never lights anything.
 *  - The environment is a light: a lat-long texture times an intensity. Every ray other than a
 *    camera ray that leaves the scene sees it (reflections, refractions, diffuse bounces, shadow
 *    rays towards it). Without an environment such rays see black.
 *  - A scene "brings light" when it has a visible punctual light, an environment, or an emitter
 *    that lights: a material whose emitted radiance (emissiveFactor x emissiveStrength) exceeds 1 in
 *    some channel. glTF caps emissiveFactor at 1, so emission within [0, 1] is glow (decals, LEDs,
 *    the DamagedHelmet's lamps); an author who wants a surface to light a scene raises it with
 *    KHR_materials_emissive_strength (the Cornell box's panel: 17). Every emitter is an area light
 *    in every back-end either way; the rule only decides whether the studio is added. A scene that brings none is lit by the built-in neutral studio environment
 *    (sy_look_studio_pixels), unless its world (sy_background_data.default_lighting = 0) or the
 *    user switches that off. The studio lights the scene but is not seen by camera rays. A scene
 *    lit only by emissive surfaces (the Cornell box) keeps exactly that lighting.
 *  - Emission is radiance and adds to reflected light; materials without a material use glTF 2.0's
 *    default material (sy_object_defaults(SY_TYPE_MATERIAL)).
 *
 * Lat-long convention (environment and background textures): direction d (unit, world) maps to
 * u = 0.5 + atan2(d.x, -d.z) / (2 pi), v = acos(d.y) / pi; the image centre is seen looking down
 * -Z, row 0 is straight up (+Y).
 *
 * Ownership: plain values; sy_look_*_pixels write into caller-owned arrays.
 * Thread-safety: every function is pure and reentrant. */
#ifndef SY_LOOK_H
#define SY_LOOK_H

#include "sy_scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/** What lights the view from outside the scene. */
typedef enum sy_look_env {
    SY_LOOK_ENV_NONE = 0,    /**< no environment light: escaping rays see black */
    SY_LOOK_ENV_TEXTURE = 1, /**< the world's environment texture (env_texture) x env_intensity */
    SY_LOOK_ENV_STUDIO = 2,  /**< the built-in neutral studio (sy_look_studio_pixels) x env_intensity */
} sy_look_env;

/** What camera rays see where they hit nothing. */
typedef enum sy_look_background {
    SY_LOOK_BG_NONE = 0,        /**< transparent: RGBA 0 (alpha 0), so layers composite over it */
    SY_LOOK_BG_COLOR = 1,       /**< bg_color (premultiplied linear RGBA) */
    SY_LOOK_BG_ENVIRONMENT = 2, /**< the environment texture x env_intensity, alpha 1 */
    SY_LOOK_BG_GRADIENT = 3,    /**< the world's sky/ground gradient (sy_look_gradient_pixels), alpha 1 */
} sy_look_background;

/** The resolved look of one view: what every mediator must draw. */
typedef struct sy_look {
    uint32_t env;          /**< sy_look_env */
    uint32_t env_texture;  /**< core texture id when env == SY_LOOK_ENV_TEXTURE, else 0 */
    float env_intensity;   /**< multiplier for the environment's texels (finite, >= 0) */
    uint32_t background;   /**< sy_look_background */
    float bg_color[4];     /**< SY_LOOK_BG_COLOR: premultiplied linear RGBA */
    sy_gradient gradient;  /**< SY_LOOK_BG_GRADIENT: the world's gradient */
    bool default_lighting; /**< env == SY_LOOK_ENV_STUDIO because the scene brings no light */
} sy_look;

/** What the look depends on besides the world: counted by the mediator's scene mirror. */
typedef struct sy_look_inputs {
    const sy_background_data *world; /**< the viewport's world (background object); NULL = none */
    bool world_env_ready;            /**< the world's environment texture is complete (has pixels) */
    uint32_t light_count;            /**< visible punctual light placements */
    uint32_t emitter_count;          /**< materials whose emission lights (radiance > 1) */
} sy_look_inputs;

/** The one place that decides. Never fails. */
void sy_look_resolve(const sy_look_inputs *in, sy_look *out);

/** True when two looks draw the same (progressive back-ends restart when it changes). */
bool sy_look_equal(const sy_look *a, const sy_look *b);

/** The built-in neutral studio environment: a soft grey dome (brighter above, darker below the
 * horizon) with three large soft boxes (key, fill, rim), deterministic and smooth enough that a
 * few samples per pixel converge. Recommended size SY_LOOK_STUDIO_WIDTH x SY_LOOK_STUDIO_HEIGHT;
 * rgb holds width*height*3 linear floats, row 0 = up. width >= 4, height >= 2. */
#define SY_LOOK_STUDIO_WIDTH 256u
#define SY_LOOK_STUDIO_HEIGHT 128u /**< recommended height of the studio map */
/** Fills rgb with the studio environment (see above). */
void sy_look_studio_pixels(uint32_t width, uint32_t height, float *rgb);

/** Bakes an X3D-style gradient into a lat-long image (rgb: width*height*3 floats). The gradient only
 * varies with the polar angle, so a narrow image (e.g. 4 x 256) is exact enough. */
void sy_look_gradient_pixels(const sy_gradient *g, uint32_t width, uint32_t height, float *rgb);
/** The gradient's colour seen along a unit direction (world, +Y up). */
void sy_look_gradient_eval(const sy_gradient *g, const float dir[3], float rgb[3]);

/** Lat-long helpers for the convention above. */
void sy_look_latlong_uv(const float dir[3], float *u, float *v);
/** Unit direction of lat-long coordinates (u, v) (inverse of sy_look_latlong_uv). */
void sy_look_latlong_dir(float u, float v, float dir[3]);

#ifdef __cplusplus
}
#endif
#endif /* SY_LOOK_H */
