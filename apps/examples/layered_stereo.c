/* layered_stereo.c — layering and stereo, which no back-end knows about: a model ray traced by
 * Whitted, a second model drawn by another back-end (the rasterizer when the library has it, else
 * the path tracer) and depth-composited into the same picture, once per eye, side by side.
 *   layered_stereo BASE.gltf OVERLAY.gltf OUT.exr      OUT is 2W x H: left eye | right eye */
#include "sy_exr.h"
#include "sy_gltf.h"
#include "sy_mediators.h"
#include "sy_viewport.h"

#include <math.h>
#include <stdio.h>

#define W 320 /* per eye */
#define H 240

int main(int argc, char **argv)
{
    if (argc < 4) return fprintf(stderr, "usage: %s BASE.gltf OVERLAY.gltf OUT.exr\n", argv[0]), 2;
    sy_error err = {0};
    sy_scene *scene = NULL;
    sy_context_pool *pool = NULL;
    sy_window *win = NULL;
    sy_layer image = {0};
    sy_gltf_info base = {0}, overlay = {0};
    sy_camera cam;
    sy_node cam_node;
    sy_bounds b;
    float dist = 1.0f; /* camera to the base model's centre */
    sy_result r = sy_mediators_register_builtin(&err);
    const char *overlay_backend = sy_mediator_find("raster") ? "raster" : "pathtracer";
    if (r == SY_OK) r = sy_scene_create(&scene, &err);
    if (r == SY_OK) r = sy_gltf_load(argv[1], scene, NULL, &base, &err); /* two models, two roots */
    if (r == SY_OK) r = sy_gltf_load(argv[2], scene, NULL, &overlay, &err);
    if (r == SY_OK) r = sy_scene_commit(scene, NULL, &err); /* world bounds are those of a commit */
    /* one camera for both layers: 45 degrees, looking down -Z at the base model from in front */
    if (r == SY_OK) r = sy_node_world_bounds(scene, base.root, &b, &err);
    if (r == SY_OK) r = sy_camera_create(scene, "view", &cam, &err);
    if (r == SY_OK) r = sy_camera_set(scene, cam, &(sy_camera_data){.yfov = 0.7853982f, .znear = 0.01f}, &err);
    if (r == SY_OK) r = sy_node_create(scene, "view", &cam_node, &err);
    if (r == SY_OK) r = sy_node_set_camera(scene, cam_node, cam, &err);
    if (r == SY_OK) {
        float c[3], radius = 0;
        for (int k = 0; k < 3; ++k) {
            c[k] = 0.5f * (b.min[k] + b.max[k]);
            radius = fmaxf(radius, 0.5f * (b.max[k] - b.min[k]));
        }
        dist = 3.0f * radius;
        const float t[3] = {c[0], c[1], c[2] + dist}, q[4] = {0, 0, 0, 1}, s[3] = {1, 1, 1};
        r = sy_node_set_trs(scene, cam_node, t, q, s, &err);
    }
    if (r == SY_OK) r = sy_scene_commit(scene, NULL, &err);
    if (r == SY_OK) r = sy_context_pool_create(&pool, &err);
    if (r == SY_OK) r = sy_window_create(2 * W, H, &win, &err);
    for (uint32_t eye = SY_EYE_LEFT; r == SY_OK && eye <= SY_EYE_RIGHT; ++eye) {
        uint32_t x = eye == SY_EYE_LEFT ? 0 : W;
        /* both layers see through the same camera: the overlay stands where it is relative to the
         * base, hidden by it where the base is nearer */
        sy_viewport_desc back = {.x = x, .width = W, .height = H, .root = base.root, .camera = cam_node,
                                 .backend = "whitted", .eye = eye, .eye_separation = dist / 30, .zero_parallax = dist};
        sy_viewport_desc front = back;
        front.root = overlay.root;
        front.backend = overlay_backend;
        front.composite = SY_COMPOSITE_DEPTH;
        r = sy_window_add_viewport(win, &back, NULL, &err);
        if (r == SY_OK) r = sy_window_add_viewport(win, &front, NULL, &err);
    }
    if (r == SY_OK) r = sy_layer_create(2 * W, H, &image, &err);
    if (r == SY_OK) r = sy_window_render(win, scene, pool, NULL, &image, &err);
    if (r == SY_OK) r = sy_exr_write_rgba(argv[3], 2 * W, H, image.rgba, image.depth, SY_EXR_PIXEL_HALF, &err);
    if (r == SY_OK) printf("%s: base by whitted, overlay by %s, stereo side by side\n", argv[3], overlay_backend);
    if (r != SY_OK) fprintf(stderr, "layered_stereo: %s\n", err.message);
    sy_gltf_info_free(&base);
    sy_gltf_info_free(&overlay);
    sy_layer_destroy(&image);
    sy_window_destroy(win);
    sy_context_pool_destroy(pool);
    sy_scene_destroy(scene);
    return r == SY_OK ? 0 : 1;
}
