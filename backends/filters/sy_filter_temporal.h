/** @file
 * sy_filter_temporal.h — temporal reuse for moving progressive frames (in the spirit of SVGF,
 * Schied et al. 2017): each call takes the new samples of one frame (a few samples per pixel, the
 * path tracer's accumulation right after a camera move restarted it) with their feature buffers,
 * reprojects the history kept from the previous call to this frame's camera, rejects history that
 * does not belong to the same surface or no longer fits the new samples, blends, and filters the
 * result with a variance-guided edge-avoiding a-trous filter. A pixel without a normal (0, 0, 0:
 * a specular chain that reached no diffuse surface) is reprojected onto and filtered with such
 * pixels only. The output is an estimate for display
 * while the view moves; once the camera rests, the caller shows its own accumulation instead
 * (the path tracer's mediator does), so a still, converged image is never changed.
 *
 * Per call, for pixel i with world position p_i (frame.position), all on illumination (colour
 * demodulated by the albedo, as the a-trous filter does; misses pass through unchanged):
 *   1. reprojection: the point's previous position q_i = p_i + motion_i (frame.motion, the object
 *      motion since the previous frame; q_i = p_i without it; a non-finite motion finds no
 *      history, and is not counted as a bad pixel; the path tracer's mediator gives it for the
 *      instances moved since its previous render and, per vertex, for the hits on skinned or
 *      morphed meshes that deformed: temporal_motion, temporal_deform in sy_mediator_rt.h) through the
 *      previous camera (prev world_to_pixel), bilinear over its 4 nearest pixel centres; a tap counts only when its stored
 *      world position lies within depth_tolerance x depth_i of q_i and its normal within
 *      normal_tolerance (cosine) of n_i (a surface that turned further in one frame starts anew). No
 *      valid tap: disocclusion, history length 0. Without motion only the camera moves points: a
 *      node the scene clock moved is not followed (its history is rejected where its surface left
 *      the tolerance, or clamped: the moving object ghosts).
 *   2. neighbourhood clamping: the reprojected history is clamped to the box mean +- clamp_gamma x
 *      standard deviation of the new samples' 3x3 neighbourhood in YCoCg (0 = no clamping).
 *   3. exponential moving average: weight max(alpha, 1 / (history length + 1)) for the new samples
 *      (history length up to max_history), the same for the first and second moments of luminance;
 *      their difference is the temporal variance, replaced by the 3x3 spatial variance while the
 *      history is shorter than 4 frames.
 *   4. a-trous: atrous_iterations passes of a 3x3 B-spline kernel with taps 2^k apart, weights
 *      exp(-|l_i - l_j| / (sigma_luminance sqrt(blurred variance_i)) - |z_i - z_j| / (sigma_depth
 *      step |grad z_i|) - sigma_normal (1 - n_i.n_j)) (exp(-x) as 2^(-x log2 e) linear between
 *      integer powers of 2: within -0.0003 % and +6.2 % of exp, monotone, exact at x = 0), the
 *      variance filtered with the squared weights; the output of the first pass becomes the next
 *      frame's history (as SVGF; not for the direct part, below).
 * The result is remodulated by the albedo. NaN/Inf inputs are neither read by neighbours nor kept
 * in the history (the pixel shows its own colour, or 0).
 *
 * Inputs (sy_filter_frame): color (3 or 4 channels; alpha passed through), albedo, normal, depth,
 * position (required: world positions as sy_filter_position_from_depth gives them); motion
 * (optional: per-pixel object motion, 3 floats, as sy_filter.h describes); direct and
 * indirect (optional, both or neither): then the two parts go through steps 1-4 separately (each
 * with its own moments and variance, as SVGF's direct and indirect illumination), except that the
 * direct part's history is its unfiltered blend (step 3), not its first a-trous pass: fed back,
 * the filtered direct part let an emitter's light creep over its edge frame after frame; without
 * the split the whole colour is one part. variance is not used (the moments are the filter's). world_to_pixel: the frame's camera as a 4x4 column-major matrix taking a
 * homogeneous world point to (x w, y w, *, w), where (x, y) are continuous pixel coordinates of this
 * frame (pixel (x, y) covers [x, x+1) x [y, y+1), row 0 at the top) and w > 0 in front of the
 * camera (perspective: the camera-axis distance; orthographic: 1). Frames may change size from call
 * to call (an interactive view's resolution scale): the history is read at its own size.
 *
 * Ownership: a sy_filter_temporal is the caller's (create / destroy); it holds two frames of history
 * and its working planes (about 345 bytes per pixel). Thread-safety: one thread at a time per object; the passes run on the
 * process's OpenMP team (sy_filter_parallel_rows); results do not depend on the thread count, nor on
 * the instruction set (the row loops' AVX-512, AVX2 and SSE2 clones and the reprojection's AVX2 and
 * scalar versions do the same operations per pixel). */
#ifndef SY_FILTER_TEMPORAL_H
#define SY_FILTER_TEMPORAL_H

#include "sy_filter.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Temporal reuse options (sy_filter_temporal_params_default gives the defaults). */
typedef struct sy_filter_temporal_params {
    float alpha;            /**< smallest EMA weight of the new samples, (0, 1]; default 0.1 */
    float alpha_moments;    /**< smallest EMA weight of the luminance moments, (0, 1]; default 0.2 */
    uint32_t max_history;   /**< longest history counted (frames, 1..1024); default 32 */
    float clamp_gamma;      /**< YCoCg box half width in standard deviations (0 = no clamping, <= 100); default 2 */
    float depth_tolerance;  /**< reprojection: largest world distance / depth (> 0); default 0.03 */
    float normal_tolerance; /**< reprojection: smallest normal cosine [-1, 1]; default 0.8 */
    uint32_t atrous_iterations; /**< a-trous passes (0..8; 0 = the blended image unfiltered); default 4 */
    float sigma_luminance;  /**< a-trous luminance edge stop (> 0); default 4 (SVGF) */
    float sigma_normal;     /**< a-trous normal edge stop (>= 0); default 64 */
    float sigma_depth;      /**< a-trous depth edge stop (> 0); default 1 (SVGF) */
    uint32_t threads;       /**< OpenMP team size; 0 = the OpenMP default (sy_filter_parallel_rows) */
    uint32_t rest_samples;  /**< sy_filter_temporal_rest: accumulated samples from which the accumulation
                                 shows alone (0..2^20; 0 = at once); default 64 */
} sy_filter_temporal_params;

/** Per-call statistics (any pointer may be NULL). */
typedef struct sy_filter_temporal_stats {
    uint64_t pixels;         /**< pixels of the frame */
    uint64_t reprojected;    /**< pixels with a valid reprojected history */
    uint64_t disoccluded;    /**< hits without one (new surface, outside the previous view, rejected) */
    uint64_t nonfinite;      /**< NaN/Inf input pixels */
    double mean_history;     /**< mean history length (frames) over the hits after this frame */
    double seconds;          /**< wall time of the call */
    double cpu_seconds;      /**< CPU time of the process during the call (all its threads) */
    /** wall time of the call's phases (SY_FILTER_TEMPORAL_PHASE_*; they add up to about seconds) */
    double phase_seconds[4];
} sy_filter_temporal_stats;

/** The phases of sy_filter_temporal_stats.phase_seconds. */
enum {
    SY_FILTER_TEMPORAL_PHASE_PLANES = 0,  /**< the frame's planes: validity, demodulation */
    SY_FILTER_TEMPORAL_PHASE_REPROJECT,   /**< 3x3 statistics, reprojection, clamping, moving averages */
    SY_FILTER_TEMPORAL_PHASE_ATROUS,      /**< variance blurs and a-trous passes */
    SY_FILTER_TEMPORAL_PHASE_OUTPUT       /**< remodulation, the output and the statistics */
};

/** A temporal reuse state (opaque). */
typedef struct sy_filter_temporal sy_filter_temporal;

/** Fills p with the defaults. */
void sy_filter_temporal_params_default(sy_filter_temporal_params *p);
/** Checks every field; the message names the field and the bound. */
sy_filter_status sy_filter_temporal_params_check(const sy_filter_temporal_params *p, sy_filter_report *err);

/** Creates a state with no history; p NULL = the defaults. */
sy_filter_status sy_filter_temporal_create(const sy_filter_temporal_params *p, sy_filter_temporal **out,
                                           sy_filter_report *err);
/** NULL-safe. */
void sy_filter_temporal_destroy(sy_filter_temporal *t);
/** Forgets the history (the next frame starts from its own samples); NULL-safe. */
void sy_filter_temporal_reset(sy_filter_temporal *t);
/** New options (checked); the history is kept. */
sy_filter_status sy_filter_temporal_set_params(sy_filter_temporal *t, const sy_filter_temporal_params *p,
                                               sy_filter_report *err);

/** One frame: out_rgba (width*height*4 floats) receives the estimate, and the history becomes this
 * frame's. world_to_pixel as described above (finite). Fails on a bad frame, matrix or memory; the
 * history is then reset. */
sy_filter_status sy_filter_temporal_run(sy_filter_temporal *t, const sy_filter_frame *in, const float world_to_pixel[16],
                                        float *out_rgba, sy_filter_temporal_stats *stats, sy_filter_report *err);

/** When the camera rests after moving frames (the caller accumulates samples of one view again):
 * out_rgba = the accumulation accum_rgba (`samples` samples per pixel, width x height x 4 floats)
 * blended with the last estimate sy_filter_temporal_run returned, whose pixel i counts as
 * h_i = len_i x g_i x (1 - samples / rest_samples)^2 samples: len_i its history length in frames,
 * g_i the a-trous passes' variance reduction there (the blended variance over the filtered one, of
 * the indirect part or the colour, within [1, 64]): out = (h_i estimate + samples accumulation) /
 * (h_i + samples); alpha from the accumulation. So the first still frames show no pop (the
 * estimate's noise is about that of len_i g_i samples of one frame each, the accumulation's that of
 * `samples`: the blend's noise does not jump), and from samples >= rest_samples
 * on out_rgba is the accumulation exactly (a still, converged image is never changed; the estimate
 * is then dropped). Returns true when it blended; false (out_rgba = the accumulation) without an
 * estimate of this size, after sy_filter_temporal_reset, or once converged. out_rgba may be
 * accum_rgba. The caller calls it only for the view of the last estimate (same camera, scene
 * unchanged since), and resets the state when the scene changes under a still camera. NULL-safe. */
bool sy_filter_temporal_rest(sy_filter_temporal *t, uint32_t width, uint32_t height, const float *accum_rgba,
                             uint32_t samples, float *out_rgba);

#ifdef __cplusplus
}
#endif

#endif /* SY_FILTER_TEMPORAL_H */
