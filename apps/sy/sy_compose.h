/* sy_compose.h — builds and renders the window a `sy render` command line describes: the main
 * viewport, an optional overlay viewport (another root of the same scene, possibly another
 * back-end, composited by depth / alpha-over / replace), and stereo layouts (side-by-side,
 * top-bottom, red-cyan anaglyph, separate eyes) with off-axis frusta from one camera. Both eyes
 * share one context per back-end through the context pool. An interactive view sets its camera on
 * the viewports directly (spec.view), never in the scene.
 * Ownership: layers are created here and owned by the caller (sy_layer_destroy).
 * Thread-safety: single-threaded, like the scene. */
#ifndef SY_COMPOSE_H
#define SY_COMPOSE_H

#include "sy_viewport.h"

typedef enum sy_stereo_mode {
    SY_STEREO_NONE = 0,
    SY_STEREO_SBS = 1,      /* left | right, output 2W x H */
    SY_STEREO_TB = 2,       /* left over right, output W x 2H */
    SY_STEREO_ANAGLYPH = 3, /* red-cyan, output W x H */
    SY_STEREO_SEPARATE = 4, /* two W x H images */
} sy_stereo_mode;

typedef struct sy_compose_spec {
    const char *backend, *params;
    sy_node root, camera;
    const sy_mat4 *view;        /* non-NULL: the camera-to-world matrix set on every viewport directly
                                   (sy_viewport_set_view; camera gives the projection): no commit */
    sy_background background;
    bool has_overlay;
    sy_node overlay_root;
    const char *overlay_backend, *overlay_params;
    uint32_t overlay_composite; /* sy_composite */
    uint32_t stereo;            /* sy_stereo_mode */
    float eye_separation;       /* metres, > 0 (default 0.065) */
    float zero_parallax;        /* metres, > 0 (default 2) */
    uint32_t clip_count;        /* section planes on the main viewports (--clip A,B,C,D; sy_viewport_set_clip_planes) */
    float clip_planes[SY_CLIP_PLANES_MAX][4];
    bool clip_cap;              /* fill the cut faces of closed meshes (--clip-cap; sy_viewport_set_clip_cap) */
    float clip_cap_color[3];    /* linear RGB */
} sy_compose_spec;

/* Parses "sbs", "tb", "anaglyph", "separate" (or "none"). */
sy_result sy_stereo_mode_parse(const char *s, uint32_t *out, sy_error *err);
/* Checks separation / zero-parallax against the camera (far plane). */
sy_result sy_compose_validate(const sy_scene *scene, const sy_compose_spec *spec, sy_error *err);

/* Renders an image of w x h per eye. out receives the image (for SEPARATE: the left eye, and
 * out_right the right eye; out_right is ignored otherwise and may be NULL). */
sy_result sy_compose_render(sy_scene *scene, sy_context_pool *pool, const sy_compose_spec *spec, uint32_t w,
                            uint32_t h, const sy_window_render_opts *opts, sy_layer *out, sy_layer *out_right,
                            sy_error *err);

/* The main viewport's mono camera view at w x h (the camera node as the scene holds it now, the
 * section planes included): what a render of spec would ask its back-end for (sy render
 * --cluster-mode frames sends it with each frame). */
sy_result sy_compose_camera_view(const sy_scene *scene, const sy_compose_spec *spec, uint32_t w, uint32_t h,
                                 sy_camera_view *out, sy_error *err);
/* The main viewport's view for eye (SY_EYE_MONO, _LEFT, _RIGHT: spec's eye separation and zero
 * parallax) at w x h per eye: the camera a stereo render of spec asks its back-end for in that eye's
 * viewport (sy render gives each eye's moving camera to the motion: sy_context_motion_camera). */
sy_result sy_compose_eye_view(const sy_scene *scene, const sy_compose_spec *spec, uint32_t eye, uint32_t w, uint32_t h,
                              sy_camera_view *out, sy_error *err);

#endif /* SY_COMPOSE_H */
