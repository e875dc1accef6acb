/* sy_render_passes.h — how `sy render` makes one frame's image with a back-end that needs more
 * than one render: a progressive back-end's passes up to a sample count or a time budget (progress
 * with an ETA on a terminal), and motion blur over a shutter (sub-frames, or one render where the
 * back-ends move instances, the camera and deformed meshes over time). Used by sy_cmd_render.c.
 * Thread-safety: one call at a time per scene and pool. Ownership: images are the caller's; a
 * context returned is the pool's. */
#ifndef SY_RENDER_PASSES_H
#define SY_RENDER_PASSES_H

#include "sy_compose.h"
#include "sy_load.h"

#include "sy_anim.h"
#include "sy_viewport.h"

/* A progressive back-end's budget and outputs. */
typedef struct sy_cli_pt_opts {
    uint32_t spp;         /* 0 = default (64 unless a time budget is given) */
    double time_budget;   /* seconds, 0 = none */
    bool aov;             /* write feature buffers as extra EXR channels */
    uint32_t seed;        /* the back-ends' sampling seed (motion blur: one per time sample) */
} sy_cli_pt_opts;

/* Renders a progressive back-end in passes until the sample count or the time budget is reached,
 * through the same window composition as a single-pass render (overlays and stereo included).
 * *out / *out_right get the final images; *samples_out the samples per pixel accumulated by the
 * main back-end; *ctx_out its (pool-owned) context. A sequence restarts the accumulation before each
 * frame (sy_context_restart), so the passes are counted from 0. */
sy_result sy_cli_render_progressive(loaded *ld, const sy_compose_spec *spec, uint32_t w, uint32_t h, const sy_cli_pt_opts *po,
                                    sy_context_pool *pool, sy_layer *out, sy_layer *out_right, double *seconds,
                                    uint64_t *samples_out, sy_context **ctx_out, sy_error *err);

/* One frame (at frame_time of clip) blurred over the shutter sh: sub-frames (sub_frames, or where a
 * back-end cannot move what moves) or one native render with steps time steps (0: chosen from the
 * motion); po non-NULL for a progressive back-end. *native_out says which was done; the rest as
 * sy_cli_render_progressive. The scene is left at the frame's time. */
sy_result sy_cli_render_blurred(loaded *ld, const char *clip, double frame_time, sy_shutter *sh,
                                const sy_compose_spec *spec, uint32_t w, uint32_t h, const sy_cli_pt_opts *po,
                                sy_context_pool *pool, const sy_window_render_opts *ro, sy_layer *out,
                                sy_layer *out_right, double *seconds, uint64_t *samples_out, sy_context **ctx_out,
                                bool sub_frames, uint32_t steps, bool *native_out, sy_error *err);

#endif
