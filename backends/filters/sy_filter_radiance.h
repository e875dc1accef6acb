/** @file
 * sy_filter_radiance.h — radiance filtering (Schwenk 2013, chapter 4; ../shared/notes/
 * filters-spec.md §2): each pixel stores the indirect incident-radiance sample of its path at the
 * first non-specular vertex ("image-space photon map"); every frame each pixel re-shades its
 * neighbours' samples with its OWN BSDF, normal and outgoing direction (Eq. 4.10), inside a
 * world-space kernel (image-space footprint projected to a prism on the tangent plane, §2.6)
 * whose radius follows the target-variance schedule T_k = (2k - 1) T_u (Eq. 4.14), so textures
 * and geometry stay sharp and only illumination is blurred. Once the radius drops below one pixel
 * the pixel switches to plain path tracing (correction phase); the running mean then converges
 * with bias O(1/N). Optional unbiased buffer (§2.7): show the pure path-traced mean instead once a
 * pixel is in the correction phase.
 *
 * INTEGRATOR HOOK (what the path tracer fills per pixel and frame, 1 path per pixel):
 *   sy_filter_rf_shading  the pixel's first non-specular hit P0 reached through perfect specular
 *                         surfaces (chosen stochastically: reflect OR refract), its material and
 *                         this frame's direct part and plain PT indirect estimate;
 *   sy_filter_rf_sample   the radiance sample leaving P0: direction wi sampled from P0's BSDF and
 *                         the radiance arriving along it (every contribution after P0: NEE at later
 *                         vertices + emitter hits, times the throughput AFTER the first bounce),
 *                         NOT multiplied by P0's BSDF*cos and NOT divided by its pdf.
 * So for the pixel's own sample: pt_indirect = throughput * f(wi, wo) cos / pdf(wi) * radiance.
 * The Embree path tracer provides this hook as per-pixel path records (backends/rt sy_rt.h
 * ">>path records"); mediators/rt/sy_radiance_hook.c converts them and passes its BSDF.
 *
 * Ownership: sy_filter_radiance owns its accumulation state; inputs are borrowed per call.
 * Thread-safety: one object per thread at a time; runs multithreaded internally on the process's
 * OpenMP thread team with params.threads threads (sy_filter_parallel_rows; the object owns none).
 *
 * Cost (exact; results equal the plain per-neighbour loop bit for bit): the frame first copies the
 * neighbours' data into compact per-frame arrays (position, wi, radiance, 1/hit distance, variance;
 * invalid samples get a NaN position so the prism test rejects them without a branch); per owner
 * pixel the kernel frame is built once, each window row is tested in one vectorisable loop (prism
 * thickness, tangent-plane ellipse) and only the neighbours inside go to the BSDF, in batches. */
#ifndef SY_FILTER_RADIANCE_H
#define SY_FILTER_RADIANCE_H

#include "sy_filter.h"

#ifdef __cplusplus
extern "C" {
#endif

enum {
    SY_FILTER_RF_VALID = 1u << 0,     /**< sample/shading present and finite */
    SY_FILTER_RF_NO_FILTER = 1u << 1  /**< shading: never filter this pixel (e.g. too glossy, mixed
                                         reflect+refract chain: hybrid §2.10) */
};

/** One stored incident-radiance sample of a pixel (at its first non-specular vertex x_j). */
typedef struct sy_filter_rf_sample {
    float position[3]; /**< x_j, world */
    float normal[3];   /**< n_j, unit shading normal at x_j */
    float wi[3];       /**< unit direction from x_j toward the incoming light */
    float radiance[3]; /**< incident radiance estimate along wi (not divided by the pdf) */
    float hit_distance; /**< length of the ray along wi (+INF if it escaped): AO factor */
    uint32_t flags; /**< SY_FILTER_RF_VALID */
} sy_filter_rf_sample;

/** The shading point of a pixel (P0) and what the path tracer saw there this frame. */
typedef struct sy_filter_rf_shading {
    float position[3];   /**< P0 */
    float normal[3];     /**< unit shading normal at P0 (facing wo) */
    float wo[3];         /**< unit direction from P0 toward the previous path vertex */
    float ray_dir[3];    /**< D: unit direction of the ray that reached P0 (kernel projection, Eq. 4.19) */
    float path_length;   /**< d_P0: distance camera -> P0 along the specular chain */
    float throughput[3]; /**< specular-chain throughput camera -> P0 (1 without specular bounces) */
    float diffuse[3];    /**< Lambert reflectance of P0 */
    float specular[3];   /**< glossy reflectance (normalised Blinn-Phong lobe); 0 = none */
    float exponent;      /**< Blinn-Phong exponent e of the glossy lobe (>= 0) */
    float direct[3];     /**< this frame's low-variance part seen by the camera: emission + NEE at P0,
                            throughput included */
    float pt_indirect[3]; /**< this frame's plain path-traced indirect estimate, throughput included */
    float variance;      /**< running variance of the pixel's indirect estimate per sample (luminance,
                            absolute units; Welford M2/(n-1), 0 until two samples) */
    uint32_t flags;      /**< SY_FILTER_RF_VALID (else: background, direct only), SY_FILTER_RF_NO_FILTER */
} sy_filter_rf_shading;

/** BSDF of the owner pixel: f(wi, wo) * |n . wi| (RGB) and the pdf with which the integrator
 * samples wi at this shading point. The default (NULL) is Lambert + normalised Blinn-Phong with a
 * luminance-weighted lobe mixture pdf (cosine / Phong-half-vector sampling). */
typedef void (*sy_filter_rf_bsdf_fn)(const sy_filter_rf_shading *s, const float wi[3], float f_cos[3], float *pdf,
                                     void *user);
/** The default BSDF: Lambert + normalised Blinn-Phong (see above). */
void sy_filter_rf_bsdf_default(const sy_filter_rf_shading *s, const float wi[3], float f_cos[3], float *pdf,
                               void *user);
/** Batched form (the filter's hot path: one call per owner pixel and batch of neighbours instead
 * of one indirect call per neighbour; owner constants are computed once per call). Structure of
 * arrays: direction m is (wi[0][m], wi[1][m], wi[2][m]) (unit), its result f_cos[c][m] and pdf[m],
 * m < count (outputs never alias inputs). Must give exactly what count calls of the single form
 * would. Called concurrently
 * from the filter's threads (must be pure). */
typedef void (*sy_filter_rf_bsdf_batch_fn)(const sy_filter_rf_shading *s, uint32_t count, const float *const wi[3],
                                           float *const f_cos[3], float *pdf, void *user);
/** The default BSDF, batched. */
void sy_filter_rf_bsdf_default_batch(const sy_filter_rf_shading *s, uint32_t count, const float *const wi[3],
                                     float *const f_cos[3], float *pdf, void *user);

/** Kernel profiles of the radiance filter (t = distance / radius). */
typedef enum sy_filter_rf_kernel {
    SY_FILTER_RF_EPANECHNIKOV = 0, /**< 1 - t^2 (default) */
    SY_FILTER_RF_SILVERMAN = 1,    /**< (1 - t^2)^2 */
    SY_FILTER_RF_UNIFORM = 2,
    SY_FILTER_RF_GAUSSIAN = 3      /**< exp(-4.5 t^2), cut at t = 1 */
} sy_filter_rf_kernel;

/** Radiance filter options (sy_filter_radiance_params_default gives the defaults). */
typedef struct sy_filter_radiance_params {
    float threshold;        /**< T_u, perceived variance of the accumulated result; default 0.01 (> 0) */
    uint32_t warmup_frames; /**< frames using the fixed warm-up radius; default 4 (0..64) */
    float warmup_radius;    /**< r_w1 in pixels; default 8 (> 0) */
    float max_radius;       /**< cap in pixels (cost bound); default 24 (>= 1, <= 128) */
    sy_filter_rf_kernel kernel; /**< kernel profile; default Epanechnikov */
    bool ambient_occlusion; /**< AO factor alpha on the radius; default true */
    float prism_thickness;  /**< delta as a fraction of the tangent extent r_S; default 0.25 (> 0) */
    float grazing_epsilon;  /**< eps of Eq. 4.21; default 0.1 (> 0) */
    float glossy_limit;     /**< exponents above: nu = max(0, n_j . n)^e; default 128 */
    float specular_limit;   /**< exponents above: no filtering (plain PT); default 4096 */
    bool unbiased_switch;   /**< keep the pure-PT mean and show it in the correction phase; default false */
    uint32_t threads; /**< OpenMP team size; 0 = the OpenMP default (sy_filter_parallel_rows) */
} sy_filter_radiance_params;

/** Fills p with the defaults. */
void sy_filter_radiance_params_default(sy_filter_radiance_params *p);
/** The single validation point: every field checked, the message names it. */
sy_filter_status sy_filter_radiance_params_check(const sy_filter_radiance_params *p, sy_filter_report *err);

/** One frame of input: per-pixel shading points and samples, and the BSDF. */
typedef struct sy_filter_radiance_input {
    /** @{ image size in pixels */
    uint32_t width, height; /** @} */
    float pixel_angle; /**< world size of one pixel at unit distance: 2 tan(fov_y / 2) / height (> 0) */
    const sy_filter_rf_shading *shading; /**< width*height */
    const sy_filter_rf_sample *samples;  /**< width*height (one sample per pixel) */
    sy_filter_rf_bsdf_fn bsdf;           /**< NULL = sy_filter_rf_bsdf_default */
    sy_filter_rf_bsdf_batch_fn bsdf_batch; /**< preferred when set (same BSDF as bsdf, batched); both
                                              NULL = sy_filter_rf_bsdf_default_batch */
    void *bsdf_user;                     /**< passed to either */
} sy_filter_radiance_input;

/** A radiance filter with its running state (opaque). */
typedef struct sy_filter_radiance sy_filter_radiance;

/** Creates a filter with options p. */
sy_filter_status sy_filter_radiance_create(const sy_filter_radiance_params *p, sy_filter_radiance **out,
                                           sy_filter_report *err);
/** Destroys the filter (NULL-safe). */
void sy_filter_radiance_destroy(sy_filter_radiance *rf);
/** Restart accumulation (scene/camera change): frame counter k back to 0. */
void sy_filter_radiance_reset(sy_filter_radiance *rf);
/** Filter this frame's samples (frame k = previous k + 1), accumulate, write the running mean to
 * out_rgba (width*height*4, alpha 1). A size change resets. stats->mean_blend = share of pixels in
 * the correction phase. */
sy_filter_status sy_filter_radiance_frame(sy_filter_radiance *rf, const sy_filter_radiance_input *in, float *out_rgba,
                                          sy_filter_stats *stats, sy_filter_report *err);
/** Resume on top of an existing progressive estimate of `frames` (>= 1) samples per pixel, e.g.
 * when the filter is switched on while the path tracer keeps accumulating: the running means
 * (filtered and plain) start at mean (width*height*channels, channels 3 or 4, RGB used), the
 * smoothed per-sample variance at variance (width*height, luminance, absolute units) and the frame
 * counter at k = frames, so the next frame is k + 1 with target variance (2k + 1) T_u. Non-finite
 * inputs are taken as 0. */
sy_filter_status sy_filter_radiance_seed(sy_filter_radiance *rf, uint32_t width, uint32_t height, const float *mean,
                                         uint32_t channels, const float *variance, uint32_t frames,
                                         sy_filter_report *err);
/** Diagnostics of the last frame: kernel radius in pixels per pixel (0 = correction phase). */
const float *sy_filter_radiance_radius(const sy_filter_radiance *rf);
/** Frames filtered since the last reset or seed (k). */
uint32_t sy_filter_radiance_frame_index(const sy_filter_radiance *rf);

#ifdef __cplusplus
}
#endif

#endif /* SY_FILTER_RADIANCE_H */
