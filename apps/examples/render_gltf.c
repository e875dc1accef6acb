/* render_gltf.c — the smallest Switchyard program: load a glTF file, render it with one back-end
 * (Whitted ray tracing on Embree) and write an OpenEXR image. It links only the Embree back-end:
 * no GL library (docs/EMBEDDING.md).
 *   render_gltf SCENE.gltf|.glb OUT.exr [BACKEND]      BACKEND: whitted (default), pathtracer */
#include "sy_exr.h"
#include "sy_gltf.h"
#include "sy_mediator_rt.h"
#include "sy_viewport.h"

#include <stdio.h>

int main(int argc, char **argv)
{
    if (argc < 3) return fprintf(stderr, "usage: %s SCENE.gltf OUT.exr [BACKEND]\n", argv[0]), 2;
    sy_error err = {0};
    sy_scene *scene = NULL;
    sy_context_pool *pool = NULL;
    sy_window *win = NULL;
    sy_layer image = {0};
    sy_viewport_desc view = {.backend = argc > 3 ? argv[3] : "whitted"}; /* whole window, framed */
    sy_result r = sy_mediator_rt_register(&err);
    if (r == SY_OK) r = sy_scene_create(&scene, &err);
    if (r == SY_OK) r = sy_gltf_load(argv[1], scene, NULL, NULL, &err);
    if (r == SY_OK) r = sy_scene_commit(scene, NULL, &err);
    if (r == SY_OK) r = sy_context_pool_create(&pool, &err);
    if (r == SY_OK) r = sy_window_create(640, 480, &win, &err);
    if (r == SY_OK) r = sy_window_add_viewport(win, &view, NULL, &err);
    if (r == SY_OK) r = sy_layer_create(640, 480, &image, &err);
    if (r == SY_OK) r = sy_window_render(win, scene, pool, NULL, &image, &err);
    if (r == SY_OK) r = sy_exr_write_rgba(argv[2], 640, 480, image.rgba, image.depth, SY_EXR_PIXEL_HALF, &err);
    if (r != SY_OK) fprintf(stderr, "render_gltf: %s\n", err.message);
    sy_layer_destroy(&image);
    sy_window_destroy(win);
    sy_context_pool_destroy(pool);
    sy_scene_destroy(scene);
    return r == SY_OK ? 0 : 1;
}
