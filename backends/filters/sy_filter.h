/** @file
 * sy_filter.h — common API of the noise-reduction filter back-end (backends/filters): the input
 * frame description (plain float buffers of a progressive path tracer), errors, parameter
 * validation helpers, the NaN/Inf scan that keeps bad samples out of every neighbourhood, and the
 * row-parallel helper (OpenMP) shared by all filters.
 *
 * The library is standalone: it never includes core/, mediators/, formats/, apps/ or another
 * back-end's headers. Filters: pixel filtering (sy_filter_pixel.h, Schwenk 2013 ch. 3), radiance
 * filtering (sy_filter_radiance.h, ch. 4), edge-avoiding a-trous (sy_filter_atrous.h), joint
 * bilateral upsampling (sy_filter_jbu.h), adaptive-resolution preview (sy_filter_adaptive.h),
 * temporal reuse for moving frames (sy_filter_temporal.h), and image metrics (sy_filter_metrics.h). Implementation notes: ../shared/notes/filters-spec.md.
 *
 * Conventions (as backends/rt): image row 0 is the top row; colour is linear Rec.709 RGB
 * radiance; RGBA colour is premultiplied (filters treat RGB linearly and pass alpha through);
 * depth is the camera-axis distance of the first hit in scene units (metres), +INFINITY on a miss.
 *
 * Errors (the convention of every Switchyard back-end): fallible calls return sy_filter_status,
 * numbered like Switchyard's sy_result, and report the message (the filter, parameter and reason)
 * through the caller's sy_filter_report (its error callback once, and its message). No global
 * state. Thread-safety: a filter object is used by one
 * thread at a time; distinct objects are independent; the filters themselves run multithreaded on
 * the process's OpenMP thread team (sy_filter_parallel_rows). */
#ifndef SY_FILTER_H
#define SY_FILTER_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/** Result of every fallible filter call: the numbers of Switchyard's sy_result (core/sy_common.h),
 * which a mediator checks at compile time, so it maps a code with a cast. */
typedef enum sy_filter_status {
    SY_FILTER_OK = 0,
    SY_FILTER_ERROR_INVALID_ARGUMENT = 1, /**< parameter out of range, missing buffer, bad size */
    SY_FILTER_ERROR_OUT_OF_MEMORY = 3
} sy_filter_status;

/** Receives the message of a failed call (no trailing newline; valid during the call only), on the
 * thread that made the call, before the call returns with code. */
typedef void (*sy_filter_error_fn)(void *user, sy_filter_status code, const char *message);

#define SY_FILTER_ERROR_MAX 512 /**< bytes of a reported message, NUL included (as core's sy_error) */

/** Where a filter call reports its failure. The filters have no device to hold the error callback
 * (the rt and raster back-ends keep it in theirs), so the caller passes this to every fallible
 * call (NULL: the code only): error(user, code, message) is called once per failure when set, and
 * code and message keep the last failure. Zero-initialise before first use ({0}). */
typedef struct sy_filter_report {
    sy_filter_error_fn error; /**< optional callback; NULL = none */
    void *user;               /**< passed to error */
    sy_filter_status code;    /**< the last failure's code */
    char message[SY_FILTER_ERROR_MAX]; /**< the last failure's message (the filter, parameter and reason) */
} sy_filter_report;

/** Largest accepted image side and thread count. */
#define SY_FILTER_MAX_SIDE 32768u
#define SY_FILTER_MAX_THREADS 256u /**< largest accepted thread count */

/** One frame of a progressive renderer's buffers. Every pointer is borrowed for the duration of
 * the call; width*height pixels, row-major, no padding. Which buffers a filter needs is stated in
 * its header; unused ones may be NULL.
 *   color      RGB or premultiplied RGBA (color_channels = 3 or 4): mean radiance of all paths.
 *   variance   variance of the colour MEAN (s^2/n, Welford) with variance_channels = 1 (luminance)
 *              or 3 (per RGB channel, as SY_RT_AOV_VARIANCE).
 *   albedo     3 ch: reflectivity (base colour) of the first non-specular hit, through perfect
 *              specular chains (the chain's throughput multiplied in when the renderer has it).
 *   normal     3 ch: world shading normal at that hit (unit or a mean of unit vectors).
 *   depth      1 ch: camera-axis distance of the FIRST hit (not the first non-specular one).
 *   position   3 ch: world position of the first non-specular hit (a-trous guide, headlight).
 *   direct     3 ch: low-variance part (default split: emission seen directly + direct light at
 *              the first hit). indirect: 3 ch, the high-variance rest; direct + indirect = colour.
 *   spp        per-pixel sample count (float, may be NULL: then spp_uniform for every pixel).
 *   range      RGBA range buffer ("virtual flash" RGB + depth in A), see sy_filter_range_compose;
 *              NULL: pixel filtering composes it from albedo/normal/depth(/position).
 *   motion     3 ch: object motion of the position's surface point since the previous frame (its
 *              world position then minus position; 0 for a still object; NULL = nothing moved but
 *              the camera). Only the temporal filter reads it (sy_filter_temporal.h). */
typedef struct sy_filter_frame {
    /** @{ image size in pixels */
    uint32_t width, height; /** @} */
    /** @{ channels of color (3 or 4) and of variance (1 or 3) */
    uint32_t color_channels, variance_channels; /** @} */
    /** @{ the buffers described above (NULL when unused) */
    const float *color, *variance, *albedo, *normal, *depth, *position, *direct, *indirect, *spp, *range; /** @} */
    const float *motion; /**< object motion (see above; NULL = none) */
    float spp_uniform; /**< samples per pixel when spp is NULL */
    bool has_camera;           /**< camera_position valid: headlight term of the composed range buffer */
    float camera_position[3];  /**< world-space eye position */
} sy_filter_frame;

/** Per-call statistics every filter fills (any pointer may be NULL). */
typedef struct sy_filter_stats {
    uint64_t nonfinite_samples; /**< NaN/Inf pixels found in the inputs, excluded from neighbourhoods */
    uint64_t filtered_pixels;   /**< pixels whose output used a neighbourhood this call */
    double seconds;             /**< wall time of the call */
    bool filter_pass;           /**< pixel filter: a filter pass ran this frame (2^i schedule) */
    double mean_blend;          /**< pixel filter: mean blend factor s; radiance: share in correction phase */
} sy_filter_stats;

/** Short name of a status. Static storage. */
const char *sy_filter_status_name(sy_filter_status s);

/** Reports a failure to err (if non-NULL: code, message, then the callback) and returns status;
 * printf-style message. */
sy_filter_status sy_filter_fail(sy_filter_report *err, sy_filter_status status, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/** Parameter validation, the one place every filter uses: positive finite (sigma-like), non-negative
 * finite (threshold-like), inclusive range. `what` names "filter.parameter" in the message. */
sy_filter_status sy_filter_check_positive(float v, const char *what, sy_filter_report *err);
/** Fails unless v is finite and >= 0. */
sy_filter_status sy_filter_check_nonnegative(float v, const char *what, sy_filter_report *err);
/** Fails unless v is finite and within [lo, hi]. */
sy_filter_status sy_filter_check_range(float v, float lo, float hi, const char *what, sy_filter_report *err);
/** Fails unless threads (a parameter set's thread count; 0 = OpenMP's default) is at most
 * SY_FILTER_MAX_THREADS; `filter` names the filter in the message. */
sy_filter_status sy_filter_check_threads(uint32_t threads, const char *filter, sy_filter_report *err);
/** Seconds on the monotonic clock (CLOCK_MONOTONIC, or CLOCK_PROCESS_CPUTIME_ID when cpu): a filter's
 * sy_filter_stats.seconds is the difference of two readings. */
double sy_filter_clock(bool cpu);
/** Image size and the buffers flagged in `need` (SY_FILTER_NEED_*) present; channel counts valid. */
enum {
    SY_FILTER_NEED_COLOR = 1u << 0,
    SY_FILTER_NEED_VARIANCE = 1u << 1,
    SY_FILTER_NEED_ALBEDO = 1u << 2,
    SY_FILTER_NEED_NORMAL = 1u << 3,
    SY_FILTER_NEED_DEPTH = 1u << 4,
    SY_FILTER_NEED_POSITION = 1u << 5,
    SY_FILTER_NEED_SPLIT = 1u << 6 /**< direct and indirect */
};
/** Fails unless the frame's size and channel counts are valid and every buffer in need is present. */
sy_filter_status sy_filter_check_frame(const sy_filter_frame *f, uint32_t need, const char *filter,
                                       sy_filter_report *err);

/** Mark pixels whose used buffers hold a NaN/Inf (mask[i] = 0, else 1; +INFINITY depth is a valid
 * miss). Returns the number of bad pixels. `need` as above selects the buffers inspected. */
uint64_t sy_filter_scan_finite(const sy_filter_frame *f, uint32_t need, uint8_t *mask);

/** World positions of the first hits from a camera-axis depth buffer (as SY_RT_AOV_DEPTH) for a
 * pinhole camera: camera_to_world is a 4x4 column-major matrix (camera looks down local -Z, +Y up),
 * yfov the vertical field of view in radians, aspect = width / height of the view. Misses (+INF or
 * NaN depth) get the point 1e18 along the pixel's ray, so guides treat them as far away. out:
 * width*height*3. Fails on a bad size or a non-positive yfov. */
sy_filter_status sy_filter_position_from_depth(uint32_t width, uint32_t height, const float camera_to_world[16],
                                               float yfov, const float *depth, float *out, sy_filter_report *err);

/** Rec.709 luminance. */
static inline float sy_filter_luminance(const float *rgb)
{
    return 0.2126f * rgb[0] + 0.7152f * rgb[1] + 0.0722f * rgb[2];
}
/** Scalar variance of the colour mean of pixel i (luminance; 3-channel variances assume fully
 * correlated channels, as path-traced RGB is: sd_Y = sum_c w_c sd_c — spec 1.2 [GAP] colour->scalar). */
float sy_filter_pixel_variance(const sy_filter_frame *f, size_t i);
/** Samples of pixel i (spp buffer, else spp_uniform). */
float sy_filter_pixel_spp(const sy_filter_frame *f, size_t i);

/** exp(-x) for x >= 0, relative error < 2e-4, 0 beyond x = 40: the range-kernel hot path. */
static inline float sy_filter_expneg(float x)
{
    if (!(x < 40.0f)) return 0.0f;
    /* 2^(-x log2 e) = 2^-k * 2^-f, polynomial for 2^-f on [0,1) */
    float y = x * 1.44269504f;
    int k = (int)y;
    float f = y - (float)k;
    float p = 1.0f + f * (-0.69314718f + f * (0.24022651f + f * (-0.05550411f + f * (0.00961813f - f * 0.00133336f))));
    union {
        float fl;
        uint32_t u;
    } s = {.u = (uint32_t)(127 - k) << 23};
    return p * s.fl;
}

/** Row function of sy_filter_parallel_rows: processes rows [y0, y1). */
typedef void (*sy_filter_rows_fn)(void *ctx, uint32_t y0, uint32_t y1);
/** Runs fn(ctx, y0, y1) over rows [0, rows) on the process's OpenMP thread team (libgomp), which
 * every filter and the ray tracers share: no filter object owns threads, and a team's threads stay
 * alive between calls, so the many short phases of an interactive frame start at no thread-creation
 * cost. threads = team size (0 = the OpenMP default: OMP_NUM_THREADS, else the cores this process
 * may run on; at most SY_FILTER_MAX_THREADS); the calling thread is one of them. Chunks of rows
 * are handed out dynamically (a busy core takes fewer); results never depend on the split (fn must
 * treat rows independently). Blocks until every row is done; cannot fail. Called from inside an
 * active OpenMP parallel region it runs on the calling thread only (unless nesting is enabled).
 * Where other busy processes share the cores, set OMP_WAIT_POLICY=passive: libgomp's default
 * spin-waiting between the many short phases of a filter then costs several times the work. */
void sy_filter_parallel_rows(uint32_t threads, uint32_t rows, sy_filter_rows_fn fn, void *ctx);

/** sy_filter_scan_finite for rows [y0, y1) only (the mask is indexed by pixel as there). */
uint64_t sy_filter_scan_finite_rows(const sy_filter_frame *f, uint32_t need, uint8_t *mask, uint32_t y0, uint32_t y1);

#ifdef __cplusplus
}
#endif

#endif /* SY_FILTER_H */
