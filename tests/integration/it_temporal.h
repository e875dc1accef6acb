/* it_temporal.h — the rig of the path tracer's temporal-reuse tests (test_pathtracer_motion,
 * test_pathtracer_deform): one window of w x h with one path-tracer viewport and three context
 * pools rendering the same scene: 0 with a temporal parameter on, 1 with it off, 2 the reference;
 * relMSE per pixel class. Both tests' sequence: W x H pixels, FRAMES frames of 1 sample, the first
 * FIRST building the history, references of REF_SPP samples. */
#ifndef SY_IT_TEMPORAL_H
#define SY_IT_TEMPORAL_H

#include "it_util.h"

#define W 64
#define H 48
#define FRAMES 16
#define FIRST 6
#define REF_SPP 256

typedef struct it_temporal_rig {
    sy_scene *s;
    sy_node root;
    sy_viewport *vp;
    sy_window *win;
    sy_context_pool *pool[3]; /* 0: the parameter on, 1: off, 2: reference */
    sy_layer img[3];
} it_temporal_rig;

/* The rig's scene (r->s, r->root): Lambert light and dark grey (grey) and red and green (rg), and
 * the wall: a checkerboard of 4 x 2 unit squares in the two greys at z = 0.5 (returned, on no node). */
static inline sy_mesh it_rig_scene(it_temporal_rig *r, sy_material grey[2], sy_material rg[2])
{
    MUST(sy_scene_create(&r->s, err));
    sy_scene *s = r->s;
    MUST(sy_node_create(s, "root", &r->root, err));
    grey[0] = it_lambert(s, "light grey", 0.8f, 0.8f, 0.8f), grey[1] = it_lambert(s, "dark grey", 0.3f, 0.3f, 0.3f);
    rg[0] = it_lambert(s, "red", 0.9f, 0.15f, 0.1f), rg[1] = it_lambert(s, "green", 0.1f, 0.8f, 0.2f);
    float wq[8][3];
    sy_material wm[8];
    for (int i = 0; i < 8; ++i) {
        wq[i][0] = -1.5f + (float)(i % 4), wq[i][1] = i < 4 ? -0.5f : 0.5f, wq[i][2] = 0.5f;
        wm[i] = grey[(i + i / 4) % 2];
    }
    return it_quad_mesh(s, "wall", (const float(*)[3])wq, wm, 8);
}

/* Pool k's path-tracer context of the rig's scene. */
static inline sy_context *it_rig_ctx(it_temporal_rig *r, int k)
{
    sy_context *ctx;
    MUST(sy_context_pool_get(r->pool[k], r->s, "pathtracer", NULL, r->root.id, &ctx, err));
    return ctx;
}

/* The window (camera cam under r->root, which the caller set with r->s), the pools and images;
 * pools 0 and 1 get temporal=1 and param=1 / param=0. */
static inline void it_rig_init(it_temporal_rig *r, uint32_t w, uint32_t h, sy_node cam, const char *param)
{
    sy_viewport_desc vd = {.root = r->root, .camera = cam, .backend = "pathtracer"};
    r->win = it_window(w, h, &vd, &r->vp);
    for (int k = 0; k < 3; ++k) {
        MUST(sy_context_pool_create(&r->pool[k], err));
        MUST(sy_layer_create(w, h, &r->img[k], err));
    }
    const char *on[2] = {"1", "0"};
    for (int k = 0; k < 2; ++k) {
        sy_params p = {0};
        MUST(sy_params_set(&p, "temporal", "1", err));
        MUST(sy_params_set(&p, param, on[k], err));
        MUST(sy_context_set_filter(it_rig_ctx(r, k), "none", &p, err));
    }
}

static inline void it_rig_destroy(it_temporal_rig *r)
{
    for (int k = 0; k < 3; ++k) {
        sy_layer_destroy(&r->img[k]);
        sy_context_pool_destroy(r->pool[k]);
    }
    sy_window_destroy(r->win);
    sy_scene_destroy(r->s);
}

/* Pool k renders the window into img[k] at spp samples (seed 5). */
static inline void it_rig_render(it_temporal_rig *r, int k, uint32_t spp)
{
    sy_window_render_opts ro = {.sample_count = spp, .seed = 5};
    MUST(sy_window_render(r->win, r->s, r->pool[k], &ro, &r->img[k], err));
}

/* relMSE of a against ref over the pixels of class c < classes (mask[i] == c; others skipped),
 * summed into sum[c] / cnt[c]: mean (x - r)^2 / (r^2 + 0.01) over RGB. */
static inline void it_rel_mse_classes(const sy_layer *a, const sy_layer *ref, const uint8_t *mask, int classes,
                                      double *sum, double *cnt)
{
    for (size_t i = 0; i < (size_t)a->width * a->height; ++i)
        for (int c = 0; c < 3; ++c) {
            double r = ref->rgba[4 * i + c], d = a->rgba[4 * i + c] - r;
            if (mask[i] >= classes) continue;
            sum[mask[i]] += d * d / (r * r + 0.01);
            cnt[mask[i]] += 1.0;
        }
}

#endif
