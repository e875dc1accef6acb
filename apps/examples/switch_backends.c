/* switch_backends.c — one scene, every registered back-end: load a glTF file, render it with each
 * back-end, turn the model, and render again. The second render of each back-end only syncs the
 * one changed transform (its mediator applies the change list), so its sync time is a small
 * fraction of the first one's, which translated the whole scene.
 *   switch_backends SCENE.gltf|.glb OUT_PREFIX     writes OUT_PREFIX-BACKEND.exr per back-end */
#include "sy_exr.h"
#include "sy_gltf.h"
#include "sy_mediators.h"
#include "sy_viewport.h"

#include <math.h>
#include <stdio.h>

#define W 320
#define H 240

int main(int argc, char **argv)
{
    if (argc < 3) return fprintf(stderr, "usage: %s SCENE.gltf OUT_PREFIX\n", argv[0]), 2;
    sy_error err = {0};
    sy_scene *scene = NULL;
    sy_context_pool *pool = NULL;
    sy_window *win = NULL;
    sy_viewport *vp = NULL;
    sy_layer image = {0};
    sy_gltf_info info = {0};
    sy_result r = sy_mediators_register_builtin(&err); /* every back-end this library was built with */
    if (r == SY_OK) r = sy_scene_create(&scene, &err);
    if (r == SY_OK) r = sy_gltf_load(argv[1], scene, NULL, &info, &err);
    if (r == SY_OK) r = sy_scene_commit(scene, NULL, &err);
    if (r == SY_OK) r = sy_context_pool_create(&pool, &err);
    if (r == SY_OK) r = sy_window_create(W, H, &win, &err);
    if (r == SY_OK) r = sy_window_add_viewport(win, &(sy_viewport_desc){.backend = "whitted"}, &vp, &err);
    if (r == SY_OK) r = sy_layer_create(W, H, &image, &err);
    sy_window_render_opts opts = {.sample_count = 16}; /* progressive back-ends: 16 samples a render */
    for (uint32_t i = 0; r == SY_OK && i < sy_mediator_count(); ++i) {
        const sy_mediator_class *cls = sy_mediator_at(i);
        if (cls->caps & SY_CAP_ANALYSIS) continue; /* analysis back-ends (coverage) draw no picture */
        r = sy_viewport_set_backend(vp, cls->name, NULL, &err); /* a cached context per back-end */
        sy_context *ctx = NULL;
        double first_sync = 0;
        for (int pass = 0; r == SY_OK && pass < 2; ++pass) {
            { /* pass 0: the model as loaded; pass 1: turned by 30 degrees about +Y (one changed node) */
                float angle = pass * 0.5235988f;
                const float t[3] = {0, 0, 0}, q[4] = {0, sinf(angle / 2), 0, cosf(angle / 2)}, s[3] = {1, 1, 1};
                r = sy_node_set_trs(scene, info.root, t, q, s, &err);
                if (r == SY_OK) r = sy_scene_commit(scene, NULL, &err);
            }
            if (r == SY_OK) r = sy_window_render(win, scene, pool, &opts, &image, &err);
            if (r == SY_OK) r = sy_context_pool_get(pool, scene, cls->name, NULL, 0, &ctx, &err);
            if (r != SY_OK) break;
            sy_mediator_stats st;
            sy_context_stats(ctx, &st);
            if (pass == 0) first_sync = st.last_sync_seconds;
            else
                printf("%-12s first sync %8.3f ms, after one transform change %8.3f ms, render %8.1f ms\n", cls->name,
                       first_sync * 1e3, st.last_sync_seconds * 1e3, st.last_render_seconds * 1e3);
        }
        char path[1024];
        snprintf(path, sizeof path, "%s-%s.exr", argv[2], cls->name);
        if (r == SY_OK) r = sy_exr_write_rgba(path, W, H, image.rgba, image.depth, SY_EXR_PIXEL_HALF, &err);
    }
    if (r != SY_OK) fprintf(stderr, "switch_backends: %s\n", err.message);
    sy_gltf_info_free(&info);
    sy_layer_destroy(&image);
    sy_window_destroy(win);
    sy_context_pool_destroy(pool);
    sy_scene_destroy(scene);
    return r == SY_OK ? 0 : 1;
}
