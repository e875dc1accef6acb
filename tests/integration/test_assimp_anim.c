/* test_assimp_anim.c — Assimp's animations, skins and morph targets (issue 35, formats/sy_assimp_anim.c)
 * against the glTF loader's: Assimp reads glTF 2.0 too, so each sample is loaded twice, by
 * sy_gltf_load and by sy_assimp_load, into two scenes. At four times across the clip both scenes
 * are set to the time (every clip, sy_scene_set_time with clip {0}) and committed; then
 *   - their world bounds (sy_node_world_bounds: node motion; a skinned mesh's bounds do not follow its
 *     pose, measured: CesiumMan's stay the same at every time) agree within 0.5 % of the bounds'
 *     diagonal (both evaluate the same keys with the same clock and deformer; what may differ is
 *     float rounding: Assimp's key times are milliseconds as doubles, its skin weights renormalised);
 *   - whitted's silhouettes (coverage, 128 x 128, 16 samples per pixel, the view framing the glTF
 *     scene's bounds) agree with IoU >= 0.97 (an edge pixel may flip with that rounding; measured 1.0);
 *   - at the last time the other back-ends (raster where built, pathtracer) draw the Assimp scene's
 *     pose as whitted does (IoU >= 0.97, integration_skin's bound: the deformer is shared);
 * and at some time the Assimp scene's bounds (by more than 2 % of the diagonal) or its silhouette
 * (IoU < 0.95) differ from its pose as loaded (the bind pose: joints at their static transforms,
 * the mesh's weights; loaded into a third scene), so a loader that dropped the animation fails
 * (measured: IoU 0.41 to 0.89 with the bind pose). Samples:
 * Assimp's own simple_skin and AnimatedMorphCube (Debian assimp-testmodels), and CesiumMan,
 * SimpleSkin, BoxAnimated and SimpleMorph from ../shared/testdata; each is skipped with the reason
 * when absent. */
#include "it_util.h"
#include "sy_anim.h"
#include "sy_assimp.h"
#include "sy_request.h"

#define W 128
#define H 128

/* The whole image by one back-end; 16 samples per pixel for a progressive one (its 1-sample edges
 * are jittered). */
static sy_result render_with(const char *backend, sy_scene *s, uint32_t root, const sy_camera_view *view, sy_layer *img,
                             sy_error *err)
{
    sy_context *ctx = NULL;
    sy_result r = sy_context_create(s, backend, NULL, root, &ctx, err);
    if (r == SY_OK) r = sy_context_sync(ctx, err);
    if (r == SY_OK) r = it_render_full(ctx, view, W, H, 16, img, err);
    sy_context_release(ctx);
    return r;
}

static sy_result render(sy_scene *s, uint32_t root, const sy_camera_view *view, sy_layer *img, sy_error *err)
{
    return render_with("whitted", s, root, view, img, err);
}

static float diag_of(const sy_bounds *b)
{
    float d = 0;
    for (int k = 0; k < 3; ++k) d += (b->max[k] - b->min[k]) * (b->max[k] - b->min[k]);
    return sqrtf(d);
}

static float bounds_diff(const sy_bounds *a, const sy_bounds *b)
{
    float d = 0;
    for (int k = 0; k < 3; ++k) d = fmaxf(d, fmaxf(fabsf(a->min[k] - b->min[k]), fabsf(a->max[k] - b->max[k])));
    return d;
}

static int g_compared;

static void compare(const char *path)
{
    if (access(path, R_OK) != 0) {
        printf("SKIP %s: not found\n", path);
        return;
    }
    sy_gltf_info gi;
    sy_scene *sg = it_load_gltf(path, &gi);
    sy_scene *sa = it_scene();
    sy_assimp_info ai;
    MUST(sy_assimp_load(path, sa, NULL, &ai, err));
    printf("%s: Assimp: %u animations, %u skinned meshes (%u bones), %u morph targets, %u warnings\n", path, ai.counts.animations,
           ai.counts.skinned_meshes, ai.counts.bones, ai.counts.morph_targets, ai.warning_count);
    for (uint32_t k = 0; k < ai.stored_warning_count; ++k) printf("  warning: %s\n", ai.warnings[k]);
    EXPECT_MSG(sy_scene_count(sa, SY_TYPE_ANIMATION) == sy_scene_count(sg, SY_TYPE_ANIMATION), "%s: %u clips by Assimp, %u by glTF",
               path, sy_scene_count(sa, SY_TYPE_ANIMATION), sy_scene_count(sg, SY_TYPE_ANIMATION));
    double g0, g1, a0, a1;
    MUST(sy_scene_time_range(sg, (sy_animation){0}, &g0, &g1, err));
    MUST(sy_scene_time_range(sa, (sy_animation){0}, &a0, &a1, err));
    printf("  time range: glTF %.4f .. %.4f s, Assimp %.4f .. %.4f s\n", g0, g1, a0, a1);
    EXPECT_MSG(fabs(g0 - a0) < 1e-3 && fabs(g1 - a1) < 1e-3, "%s: time ranges differ", path);
    /* the pose as loaded (the bind pose), in a third scene that no time is set on */
    sy_scene *sb = it_scene();
    sy_assimp_info bi;
    MUST(sy_assimp_load(path, sb, NULL, &bi, err));
    MUST(sy_scene_commit(sb, NULL, err));
    sy_bounds bind;
    MUST(sy_node_world_bounds(sb, bi.root, &bind, err));
    bool moved = false;
    for (int i = 0; i < 4; ++i) {
        double t = g0 + (g1 - g0) * (0.15 + 0.25 * i);
        MUST(sy_scene_set_time(sg, (sy_animation){0}, t, err));
        MUST(sy_scene_set_time(sa, (sy_animation){0}, t, err));
        MUST(sy_scene_commit(sg, NULL, err));
        MUST(sy_scene_commit(sa, NULL, err));
        sy_bounds bg, ba;
        MUST(sy_node_world_bounds(sg, gi.root, &bg, err));
        MUST(sy_node_world_bounds(sa, ai.root, &ba, err));
        float dg = diag_of(&bg), d = bounds_diff(&bg, &ba), db = bounds_diff(&bind, &ba);
        sy_camera_view view = sy_camera_view_frame_bounds(&bg, 1.0f);
        sy_layer ig, ia, ib;
        MUST(render(sg, gi.root.id, &view, &ig, err));
        MUST(render(sa, ai.root.id, &view, &ia, err));
        MUST(render(sb, bi.root.id, &view, &ib, err));
        double iou = it_coverage_iou(&ig, &ia), iou_bind = it_coverage_iou(&ib, &ia);
        printf("  t=%.3f: bounds glTF (%.3f %.3f %.3f)..(%.3f %.3f %.3f), Assimp differs by %.5f (%.3f %% of the diagonal "
               "%.3f); from the bind pose by %.4f; silhouette IoU %.4f (with the bind pose's %.4f)\n",
               t, (double)bg.min[0], (double)bg.min[1], (double)bg.min[2], (double)bg.max[0], (double)bg.max[1],
               (double)bg.max[2], (double)d, 100.0 * d / dg, (double)dg, (double)db, iou, iou_bind);
        EXPECT_MSG(d <= 0.005f * dg, "%s at t=%.3f: bounds differ by %.5f (diagonal %.3f)", path, t, (double)d, (double)dg);
        EXPECT_MSG(iou >= 0.97, "%s at t=%.3f: silhouettes differ (IoU %.4f)", path, t, iou);
        if (db > 0.02f * dg || iou_bind < 0.95) moved = true;
        if (i == 3) /* the last time: every back-end draws the Assimp scene's pose alike (the shared deformer) */
            for (size_t b = 0; b < IT_NBACKENDS; ++b) {
                if (!strcmp(it_backends[b], "whitted")) continue;
                sy_layer ix;
                MUST(render_with(it_backends[b], sa, ai.root.id, &view, &ix, err));
                double ib = it_coverage_iou(&ia, &ix);
                printf("  t=%.3f: %s / whitted silhouettes of the Assimp scene: IoU %.4f\n", t, it_backends[b], ib);
                EXPECT_MSG(ib >= 0.97, "%s at t=%.3f: %s and whitted disagree (IoU %.4f)", path, t, it_backends[b], ib);
                sy_layer_destroy(&ix);
            }
        sy_layer_destroy(&ig);
        sy_layer_destroy(&ia);
        sy_layer_destroy(&ib);
    }
    EXPECT_MSG(moved, "%s: the Assimp scene's bounds and silhouette never left the bind pose's (the animation did nothing)",
               path);
    sy_assimp_info_free(&bi);
    sy_scene_destroy(sb);
    g_compared++;
    sy_assimp_info_free(&ai);
    sy_gltf_info_free(&gi);
    sy_scene_destroy(sa);
    sy_scene_destroy(sg);
}

int main(void)
{
    it_register();
    compare("/usr/share/assimp/models/glTF2/simple_skin/simple_skin.gltf");
    compare("/usr/share/assimp/models/glTF2/glTF-Sample-Models/AnimatedMorphCube-glTF/AnimatedMorphCube.gltf");
    static const char *const shared[] = {"gltf/CesiumMan/glTF/CesiumMan.gltf", "gltf/SimpleSkin/glTF/SimpleSkin.gltf",
                                         "gltf/BoxAnimated/glTF/BoxAnimated.gltf", "gltf/SimpleMorph/glTF/SimpleMorph.gltf"};
    for (size_t k = 0; k < sizeof shared / sizeof shared[0]; ++k) {
        char p[1024];
        snprintf(p, sizeof p, "%s/%s", SY_TESTDATA_DIR, shared[k]);
        compare(p);
    }
    if (!g_compared) {
        printf("SKIP: none of the samples found\n");
        return 77;
    }
    return sy_check_finish("integration_assimp_anim");
}
