/* test_skin.c — skins and morph targets in every back-end (issue 35 item 2): the Khronos CesiumMan
 * (a 19-joint skin) at t = 0 and, after sy_scene_set_time, at t = 1 s, rendered by raster, whitted
 * and pathtracer contexts that were synced at t = 0 first, so the second pose reaches them as an
 * update of the deformed vertices (the ray tracers refit, the rasterizer re-uploads). Their
 * silhouettes (alpha coverage) agree at t = 1 (IoU >= 0.97), and differ from their own t = 0 pose
 * (IoU < 0.95: the walk moved the legs and arms); a pick names the skinned node at the depth the
 * t = 1 image has there, in every back-end. The t = 1 pose is deformed once for the three contexts
 * (sy_deform_cache.h): one deformation per primitive, the other contexts take it. Then the view sy render makes without a camera frames
 * CesiumMan and the Fox whole at five times each (framed_whole). Skipped when a sample is absent. */
#include "it_util.h"
#include "sy_anim.h"
#include "sy_deform_cache.h"
#include "sy_stats.h"

#define W 160
#define H 200


/* The view sy render makes without a camera (sy_camera_view_frame_bounds of the root's world bounds,
 * as core/sy_viewport.c) frames the skinned model whole at each time: whitted's image of it covers
 * no pixel of the image's border, and some pixel. A framing from bounds that ignored the pose (or
 * that placed the skinned vertices by the mesh node's own transform, which glTF skins ignore) would
 * cut a limb off at some time. */
static void framed_whole(const char *path, const double *times, int n)
{
    sy_gltf_info info;
    sy_scene *s = it_load_gltf(path, &info);
    sy_context *ctx = NULL;
    MUST(sy_scene_set_time(s, (sy_animation){0}, times[0], err));
    MUST(sy_scene_commit(s, NULL, err));
    MUST(sy_context_create(s, "whitted", NULL, info.root.id, &ctx, err));
    for (int i = 0; i < n; ++i) {
        MUST(sy_scene_set_time(s, (sy_animation){0}, times[i], err));
        MUST(sy_scene_commit(s, NULL, err));
        MUST(sy_context_sync(ctx, err));
        sy_bounds b;
        MUST(sy_node_world_bounds(s, info.root, &b, err));
        sy_camera_view view = sy_camera_view_frame_bounds(&b, (float)W / (float)H);
        sy_layer img;
        MUST(it_render_full(ctx, &view, W, H, 16, &img, err));
        uint32_t x0 = W, x1 = 0, y0 = H, y1 = 0, edge = 0;
        for (uint32_t y = 0; y < H; ++y)
            for (uint32_t x = 0; x < W; ++x) {
                if (!isfinite(img.depth[(size_t)y * W + x])) continue;
                x0 = x < x0 ? x : x0, x1 = x > x1 ? x : x1, y0 = y < y0 ? y : y0, y1 = y > y1 ? y : y1;
                edge += x == 0 || y == 0 || x == W - 1 || y == H - 1;
            }
        printf("%s at t=%.2f, default framing: covered x %u..%u, y %u..%u of %ux%u, %u on the border\n", path, times[i],
               x0, x1, y0, y1, W, H, edge);
        EXPECT_MSG(x0 <= x1, "%s at t=%.2f: nothing in the default view", path, times[i]);
        EXPECT_MSG(edge == 0, "%s at t=%.2f: the default view cuts the model (%u pixels on the border)", path, times[i],
                   edge);
        sy_layer_destroy(&img);
    }
    sy_context_release(ctx);
    sy_gltf_info_free(&info);
    sy_scene_destroy(s);
}

int main(void)
{
    char path[1024];
    it_testdata("gltf/CesiumMan/glTF/CesiumMan.gltf", path, sizeof path);
    it_register();
    sy_gltf_info info;
    sy_scene *s = it_load_gltf(path, &info);
    MUST(sy_scene_set_time(s, (sy_animation){0}, 0.0, err));
    MUST(sy_scene_commit(s, NULL, err));
    /* from the side, the figure (1.45 m tall, Y up) filling the height */
    sy_camera_view view = it_view_down_z(3.2f, 0.27f);
    view.camera_to_world.m[13] = 0.72f;
    view.window[0] = -0.27f * (float)W / (float)H, view.window[1] = 0.27f * (float)W / (float)H;
    sy_context *ctx[IT_NBACKENDS];
    sy_layer t0[IT_NBACKENDS], t1[IT_NBACKENDS];
    for (size_t b = 0; b < IT_NBACKENDS; ++b) {
        MUST(sy_context_create(s, it_backends[b], NULL, info.root.id, &ctx[b], err));
        MUST(sy_context_sync(ctx[b], err));
        MUST(it_render_full(ctx[b], &view, W, H, 16, &t0[b], err));
    }
    MUST(sy_scene_set_time(s, (sy_animation){0}, 1.0, err));
    MUST(sy_scene_commit(s, NULL, err));
    sy_deform_cache_stats dc0, dc1;
    sy_deform_cache_stats_get(&dc0);
    for (size_t b = 0; b < IT_NBACKENDS; ++b) {
        MUST(sy_context_sync(ctx[b], err));
        if (b + 1 == IT_NBACKENDS) sy_deform_cache_stats_get(&dc1);
        MUST(it_render_full(ctx[b], &view, W, H, 16, &t1[b], err));
        double iou;
        MUST(sy_layer_coverage_iou(&t0[b], &t1[b], &iou, err));
        printf("%s: IoU of t=0 and t=1: %.4f\n", it_backends[b], iou);
        EXPECT_MSG(iou < 0.95, "%s: the pose at t=1 looks like t=0 (IoU %.4f)", it_backends[b], iou);
    }
    {
        unsigned long long made = dc1.computed - dc0.computed, taken = dc1.shared - dc0.shared;
        printf("t=1 pose: %llu primitives deformed, %llu taken by the other contexts\n", made, taken);
        EXPECT_MSG(made >= 1 && taken == made * (IT_NBACKENDS - 1),
                   "%zu contexts: %llu deformations, %llu shared (want one per primitive, the rest shared)",
                   (size_t)IT_NBACKENDS, made, taken);
    }
    /* a pick at the chest names the skinned node and the same deformed point in every back-end (the
     * depth of that pixel in the t = 1 layer, whose vertices were updated in place) */
    sy_pick_result pk[IT_NBACKENDS];
    for (size_t b = 0; b < IT_NBACKENDS; ++b) {
        MUST(sy_context_pick(ctx[b], &view, W, H, W / 2, (uint32_t)(0.4 * H), &pk[b], err));
        float d = t1[b].depth[(size_t)(0.4 * H) * W + W / 2];
        printf("%s: pick node %#x, position (%.4f %.4f %.4f), depth %.4f (layer %.4f)\n", it_backends[b], pk[b].node_id,
               (double)pk[b].position[0], (double)pk[b].position[1], (double)pk[b].position[2], (double)pk[b].depth, (double)d);
        EXPECT_MSG(pk[b].hit && pk[b].node_id == pk[0].node_id, "%s: the pick missed the figure", it_backends[b]);
        EXPECT_MSG(fabsf(pk[b].depth - d) < 2e-3f, "%s: pick depth %.4f, the layer's %.4f", it_backends[b], (double)pk[b].depth,
                   (double)d);
        EXPECT_MSG(fabsf(pk[b].depth - pk[0].depth) < 5e-3f, "%s: pick depth %.4f, %s's %.4f", it_backends[b], (double)pk[b].depth,
                   it_backends[0], (double)pk[0].depth);
    }
    for (size_t b = 1; b < IT_NBACKENDS; ++b)
        for (int t = 0; t < 2; ++t) {
            double iou;
            MUST(sy_layer_coverage_iou(t ? &t1[0] : &t0[0], t ? &t1[b] : &t0[b], &iou, err));
            printf("t=%d: IoU %s / %s: %.4f\n", t, it_backends[0], it_backends[b], iou);
            EXPECT_MSG(iou >= 0.97, "t=%d: %s and %s disagree (IoU %.4f)", t, it_backends[0], it_backends[b], iou);
        }
    for (size_t b = 0; b < IT_NBACKENDS; ++b) {
        sy_layer_destroy(&t0[b]);
        sy_layer_destroy(&t1[b]);
        sy_context_release(ctx[b]);
    }
    sy_gltf_info_free(&info);
    sy_scene_destroy(s);
    /* item 3 of issue 35: sy render --at T without a camera frames CesiumMan and the Fox whole */
    static const double man_t[] = {0.0, 0.5, 1.0, 1.5, 2.0}, fox_t[] = {0.0, 0.4, 0.8, 1.6, 3.0};
    framed_whole(path, man_t, 5);
    char fox[1024];
    it_testdata("gltf/Fox/glTF/Fox.gltf", fox, sizeof fox);
    framed_whole(fox, fox_t, 5);
    return sy_check_finish("integration_skin");
}
