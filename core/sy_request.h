/** @file
 * sy_request.h — what a render asks of a back-end: the camera view (sy_camera_view, checked by
 * sy_camera_view_check), progress reports and the render request (the rectangle, samples,
 * cancellation). Plain data; the caller owns what it passes. */
#ifndef SY_REQUEST_H
#define SY_REQUEST_H

#include "sy_common.h"
#include "sy_math.h"

#ifdef __cplusplus
extern "C" {
#endif

#define SY_CLIP_PLANES_MAX 6 /**< most section planes in a view (sy_camera_view.clip_planes) */

/** What a back-end renders: camera placement, projection and image-plane window, and the section
 * planes that cut the scene open (back-ends with SY_CAP_CLIP). */
typedef struct sy_camera_view {
    sy_mat4 camera_to_world; /**< the camera looks down its local -Z, +Y up */
    uint32_t projection;     /**< sy_projection */
    /** Image-plane window {left, right, bottom, top}: for perspective in tangent space at distance 1
     * (symmetric and off-axis frusta alike), for orthographic in camera units. The full image maps
     * onto this window; pixel (x, y) has its centre at (x + 0.5, y + 0.5), row 0 at the top. */
    float window[4];
    /** @{ zfar 0 = infinite */
    float znear, zfar; /** @} */
    uint32_t clip_count; /**< section planes in use (0..SY_CLIP_PLANES_MAX); 0 = nothing cut */
    /** Section planes {a, b, c, d} in world coordinates: a surface point p is drawn (and hit by every
     * ray: primary, reflected, refracted, shadow) only where a*p.x + b*p.y + c*p.z + d >= 0 for every
     * plane in use. Checked by sy_clip_planes_check. */
    float clip_planes[SY_CLIP_PLANES_MAX][4];
    /** Capping (with clip_count > 0): 1 = the cut faces of closed meshes are filled in clip_cap_color,
     * 0 = a cut closed mesh shows its inside. A closed mesh is a primitive whose triangles, welded by
     * position, share every edge with exactly one other triangle in opposite direction. Where a ray
     * from outside meets such a mesh's back face first and entered the kept region (where every
     * plane keeps) after its start, it sees the cap: the point where it entered, on the plane it
     * crossed, in the flat, unlit cap colour (a CAD section fill), facing the ray. */
    uint32_t clip_cap;
    float clip_cap_color[3]; /**< linear RGB, each in [0, 1]; checked by sy_clip_cap_check */
} sy_camera_view;

/** SY_OK when rgb (linear RGB) is finite and each channel within [0, 1]; otherwise
 * SY_ERR_INVALID_ARGUMENT naming the channel and value. */
sy_result sy_clip_cap_check(const float rgb[3], sy_error *err);

/** SY_OK when count <= SY_CLIP_PLANES_MAX and every plane's a, b, c, d is finite, within
 * SY_COORD_MAX, with a non-zero normal (a, b, c); otherwise SY_ERR_INVALID_ARGUMENT naming the plane
 * and the value. */
sy_result sy_clip_planes_check(const float (*planes)[4], uint32_t count, sy_error *err);
/** true when world point p is on the kept side of every section plane of v (or v has none). */
static inline bool sy_camera_view_clip_keeps(const sy_camera_view *v, const float p[3])
{
    for (uint32_t i = 0; i < v->clip_count && i < SY_CLIP_PLANES_MAX; ++i) {
        const float *q = v->clip_planes[i];
        if (q[0] * p[0] + q[1] * p[1] + q[2] * p[2] + q[3] < 0.0f) return false;
    }
    return true;
}

/** SY_OK when the view is one every back-end can render: finite, the camera's position and every
 * element of its matrix within SY_COORD_MAX (sy_math.h), an orthographic window within it too;
 * its section planes pass sy_clip_planes_check; otherwise SY_ERR_INVALID_ARGUMENT saying which value is out of range. sy_context_render checks
 * every request with it, so no back-end is given a camera beyond the range. */
sy_result sy_camera_view_check(const sy_camera_view *v, sy_error *err);

/** Camera view for a camera object at a world matrix, for an image of the given aspect
 * (width / height). The image aspect wins over the camera's own aspect, keeping yfov / ymag. */
sy_camera_view sy_camera_view_make(const sy_camera_data *cam, const sy_mat4 *world, float image_aspect);
/** A perspective view (yfov 45 degrees) looking at the bounds from +Z/+Y, framing all of it. */
sy_camera_view sy_camera_view_frame_bounds(const sy_bounds *b, float image_aspect);

/** Progress of a long render. */
typedef struct sy_progress {
    /** @{ units of work (tiles, samples) */
    uint64_t done, total; /** @} */
} sy_progress;
/** Receives progress reports. */
typedef void (*sy_progress_fn)(void *user, const sy_progress *p);

/** What to render: the camera view, the full image, the rectangle to fill, samples, background. */
typedef struct sy_render_request {
    sy_camera_view camera; /**< the camera */
    /** @{ the whole image */
    uint32_t full_width, full_height; /** @} */
    /** @{ sub-rectangle to fill; the layer is rect_w x rect_h */
    uint32_t rect_x, rect_y, rect_w, rect_h; /** @} */
    /** @{ progressive back-ends: samples to add; 0 count = default */
    uint32_t sample_first, sample_count; /** @} */
    uint32_t background_id; /**< sy_background handle id, 0 = the back-end's default (black) */
    uint32_t seed; /**< seed for the back-end's sampling (same seed = same image) */
    /** Interactive preview (back-ends with SY_CAP_PREVIEW): in (0, 1), the share of its full per-pixel
     * work the back-end may spend on this frame (a frame-time governor's choice while the view
     * moves); 0 or 1 (or anything else) = full quality. */
    float preview;
    sy_progress_fn progress; /**< optional, called from the rendering thread(s) serially */
    void *progress_user; /**< passed to progress */
} sy_render_request;

/* ---- parameters: "key=value" pairs given to a back-end (sy_params) and each class's declared
 * table of them (sy_param_table): sy_params.h ---- */

#ifdef __cplusplus
}
#endif
#endif /* SY_REQUEST_H */
