/** @file
 * sy_world.h — sets up a view's world (the background object: background, environment light,
 * default lighting) from user choices, so that every program (sy's flags, an embedding
 * application) says the same thing the same way. The meaning of each field is core's (sy_look.h);
 * this module only creates and fills the objects, reading environment maps from OpenEXR and
 * Radiance HDR (.hdr, RGBE) files, told apart by content.
 *
 * Ownership: objects are created in the caller's scene (owned by it). Thread-safety: as the scene
 * (single writer). */
#ifndef SY_WORLD_H
#define SY_WORLD_H

#include "sy_scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/** What the user asks of the world (the CLI's world flags); sy_world_apply maps it onto the scene. */
typedef struct sy_world_options {
    const char *env_path;    /**< lat-long (2:1) map, the environment light: an EXR with R, G, B or Y
                                  channels, or a Radiance HDR (.hdr) */
    uint64_t max_scene_bytes; /**< budget for the decoded map (sy_budget.h); 0 = sy_budget_default_bytes() */
    bool has_env_color;      /**< a uniform environment light of this radiance (a 1x1 lat-long map) */
    float env_color[3]; /**< radiance of the uniform environment (with has_env_color) */
    float env_intensity;     /**< multiplier for the environment; 0 is taken as 1 unless env_intensity_set */
    bool env_intensity_set; /**< env_intensity was given (so 0 means 0) */
    bool env_hidden;         /**< camera rays do not see the environment (they see the background) */
    bool has_background;     /**< what camera rays see where nothing is hit (never a light); replaces a file's gradient */
    float background[4];     /**< linear RGBA, premultiplied */
    bool no_default_light;   /**< no studio lighting even when the scene brings no light */
} sy_world_options;

/** True when the options ask for nothing (the world can stay as it is). */
bool sy_world_options_empty(const sy_world_options *o);

/** Applies the options to *world (a background object; {0}: one is created when the options ask for
 * anything), keeping the fields the options do not mention (e.g. an X3D gradient). Commits nothing.
 * Errors name the file and the reason (unreadable, not lat-long, non-finite or negative texels). */
sy_result sy_world_apply(sy_scene *s, sy_background *world, const sy_world_options *o, sy_error *err);

/** Makes a new lat-long float RGB texture of s from px (w x h x 3 floats, row 0 = up), taking
 * ownership of px (freed on failure too): the environment texture an application generates. */
sy_result sy_world_texture_take(sy_scene *s, const char *name, float *px, uint32_t w, uint32_t h, sy_texture *out,
                                sy_error *err);

/** Reads a lat-long environment map (OpenEXR, or Radiance HDR when the file starts with "#?RADIANCE"
 * or "#?RGBE") into a new float RGB texture of s. A Radiance file's size is checked against its
 * bytes and against max_bytes (the decoded float image; 0 = sy_budget_default_bytes()) before it
 * is decoded. Errors name the file and the reason. */
sy_result sy_world_load_environment(sy_scene *s, const char *path, uint64_t max_bytes, sy_texture *out, sy_error *err);

#ifdef __cplusplus
}
#endif
#endif /* SY_WORLD_H */
