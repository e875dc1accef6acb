/** @file
 * sy_anim.h — the scene clock: evaluates animations (sy_objects.h, SY_TYPE_ANIMATION) at a time
 * into the fields of the nodes they target (transforms and morph weights), and a small play state for interactive tools.
 *
 * Where it sits: the application (or `sy render --at`, a viewer's play loop, a cluster client)
 * calls sy_scene_set_time on the scene it owns; the evaluated values are stored with the ordinary
 * node setters, so they are dirty fields like any edit and travel in the next change list to every
 * mediator and every cluster replica. Nothing downstream has animation code: a replica that applies
 * the list shows the same pose (it holds the animations too, so it could also evaluate them itself
 * and get the same node fields: the evaluation is deterministic).
 *
 * Evaluation follows glTF 2.0 exactly (its "Animations" section and appendix C, "Interpolation"):
 *   - times before a sampler's first key take the first key's value, times after the last key the
 *     last key's value (clamping); a sampler with one key is constant; a looping clip (its loop
 *     field, X3D's TimeSensor.loop) first maps scene time t to t mod its period (its cycle field,
 *     else its keys' range) from its start;
 *   - STEP: the value of the last key at or before t;
 *   - LINEAR: component-wise linear; rotations by spherical linear interpolation along the shorter
 *     arc (the second quaternion negated when the dot product is negative), normalised;
 *   - CUBICSPLINE: the cubic Hermite spline with key k's out-tangent b_k and key k+1's in-tangent
 *     a_{k+1} scaled by the key interval t_d = t_{k+1} - t_k:
 *       p(s) = (2s^3 - 3s^2 + 1) v_k + t_d (s^3 - 2s^2 + s) b_k + (-2s^3 + 3s^2) v_{k+1}
 *              + t_d (s^3 - s^2) a_{k+1},  s = (t - t_k) / t_d;
 *     rotations are normalised afterwards.
 * The key interval is found by binary search in the sampler's times: a call costs
 * O(channels x log keys), independent of the scene's size.
 *
 * What a channel does to its node: translation, rotation and scale channels replace that part of a
 * TRS node's transform; the parts no channel drives keep the node's current value (the last one
 * set: its static value, or what an earlier call with another clip left there). Channels whose
 * node is gone are skipped; channels targeting a node whose transform is a matrix are skipped too
 * (glTF forbids animating such nodes; the glTF loader drops those channels with a warning). Morph
 * weight channels set the node's whole weights field (SY_NODE_WEIGHTS, one value per target, with
 * sy_node_set_weights), whatever its transform; the mirror deforms the mesh from them
 * (sy_objects.h, "Skins and morph targets"). Material, light and camera channels (sy_anim_path
 * from SY_ANIM_BASE_COLOR on: glTF KHR_animation_pointer, X3D Color- and ScalarInterpolators) set
 * that field of their object with its setter (base colour, or its RGB or alpha alone; emissive;
 * metallic; roughness; light colour and intensity; camera yfov), so every mediator sees an ordinary
 * material / light / camera change. A camera or light moves with its node: an animated node carries
 * it, and the back-ends read its world matrix at each sync. Each skip is counted in sy_anim_stats.
 *
 * Thread-safety: as the scene (sy_scene.h): calls that take a scene are serialised by the caller
 * with every other write to it. The sampler and clock functions are reentrant. */
#ifndef SY_ANIM_H
#define SY_ANIM_H

#include "sy_scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/** What one sy_scene_set_time_ex call did. */
typedef struct sy_anim_stats {
    uint32_t clips;          /**< animations evaluated */
    uint32_t channels;       /**< channels evaluated into a node */
    uint32_t skipped_stale;  /**< channels whose target node (material, light, camera) is gone */
    uint32_t skipped_matrix; /**< channels whose target node has a matrix transform */
    uint32_t weights;        /**< morph weight channels evaluated into a node's weights */
    uint32_t properties;     /**< material, light and camera channels evaluated into their object */
    uint32_t failed;         /**< channels whose value a node setter refused (a spline beyond SY_COORD_MAX) */
} sy_anim_stats;

/** Sets the scene's time: evaluates clip (or, with clip {0}, every animation of the scene in slot
 * order: a property several clips drive takes the last one's value) at `seconds` into the target
 * nodes' transforms with the node setters (see above); commit the scene as after any edit. seconds
 * must be finite (SY_ERR_INVALID_ARGUMENT otherwise); times outside a clip clamp to its ends. A
 * stale clip handle is SY_ERR_INVALID_HANDLE. When a setter refuses a value the other channels are
 * still evaluated and the first error is returned, naming the animation and channel. */
sy_result sy_scene_set_time(sy_scene *s, sy_animation clip, double seconds, sy_error *err);
/** sy_scene_set_time with the counts of what it did (stats may be NULL). */
sy_result sy_scene_set_time_ex(sy_scene *s, sy_animation clip, double seconds, sy_anim_stats *stats, sy_error *err);

/** Evaluates sampler `sampler` of an animation's data at time t into out[0 .. components-1]
 * (out_count must be at least the sampler's components). quaternion: treat values as rotations
 * (slerp, normalised). Never reads outside the blobs, whatever the data holds (a replica's data
 * are checked when applied; this checks the bounds again, O(1)): SY_ERR_INVALID_ARGUMENT when the
 * sampler does not fit them. */
sy_result sy_animation_sample(const sy_animation_data *d, uint32_t sampler, bool quaternion, double t, float *out,
                              uint32_t out_count, sy_error *err);

/** The time range of clip (or, with clip {0}, of every animation together): *start_out, *end_out
 * (0, 0 without animations). SY_ERR_INVALID_HANDLE for a stale clip. */
sy_result sy_scene_time_range(const sy_scene *s, sy_animation clip, double *start_out, double *end_out, sy_error *err);

/** Finds an animation by selector: a decimal index (the n-th live animation in slot order, which
 * for a freshly loaded glTF file is its animations[] order) or a name. SY_ERR_NOT_FOUND names the
 * selector and lists the available clips. */
sy_result sy_animation_find(const sy_scene *s, const char *selector, sy_animation *out, sy_error *err);

/** A camera shutter on the scene clock (motion blur): the interval [frame time + open, frame time +
 * close] in seconds of scene time, 0 <= open <= close (both finite, at most SY_SHUTTER_MAX), sampled at
 * `samples` stratified times (sy_shutter_time). close == open is an instant: no blur. A renderer shows
 * the mean of the scene over the interval; `sy render --shutter` accumulates one render per time
 * (docs/CLI.md "Motion blur"). Plain data. */
typedef struct sy_shutter {
    double open;        /**< shutter opens: seconds after the frame's time */
    double close;       /**< shutter closes: seconds after the frame's time (>= open) */
    uint32_t samples;   /**< time samples across the interval (>= 1) */
} sy_shutter;

#define SY_SHUTTER_MAX 1e6 /**< the largest open / close accepted, seconds */
#define SY_SHUTTER_SAMPLES_MAX 4096u /**< the most time samples of one shutter */

/** Parses "OPEN,CLOSE" or "S" (= "0,S") in seconds into out->open / out->close (out->samples is left
 * alone). Refuses (SY_ERR_INVALID_ARGUMENT, naming the text and the rule) anything but one or two
 * finite decimal numbers with 0 <= open <= close <= SY_SHUTTER_MAX: a negative, NaN or infinite value,
 * open > close, trailing text. */
sy_result sy_shutter_parse(const char *text, sy_shutter *out, sy_error *err);
/** True when the shutter spans time (close > open): a render blurs. */
bool sy_shutter_blurs(const sy_shutter *s);
/** The scene time of time sample i (0 <= i < samples) of a frame at frame_time: the midpoint of the
 * i-th of `samples` equal strata of [open, close] (stratified, deterministic):
 * frame_time + open + (i + 0.5) / samples x (close - open). */
double sy_shutter_time(const sy_shutter *s, double frame_time, uint32_t i);

/** Play state for interactive tools: a time that advances with wall time while playing. */
typedef struct sy_clock {
    double time;  /**< current time, seconds */
    double start; /**< range start (a clip's first key) */
    double end;   /**< range end (a clip's last key) */
    double speed; /**< time per wall second (1 = real time; negative plays backwards) */
    bool playing; /**< advancing */
    bool loop;    /**< wrap at the ends (else stop there) */
} sy_clock;

/** A clock over [start, end] at start, playing, looping, speed 1 (end < start is taken as start). */
sy_clock sy_clock_make(double start, double end);
/** Advances a playing clock by dt wall seconds x speed: wraps into [start, end] when looping, else
 * stops at the end it reached (playing false). A paused clock stays. Non-finite dt is ignored.
 * Returns the new time. */
double sy_clock_advance(sy_clock *c, double dt);

#ifdef __cplusplus
}
#endif
#endif /* SY_ANIM_H */
