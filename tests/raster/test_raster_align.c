/* test_raster_align.c — the pixel alignment contract between the rasterizer and the ray tracers:
 * the same scene and camera give the same silhouettes. For sample models (Box, Duck, the Cornell
 * box, DamagedHelmet, SimpleInstancing) at 256x256 the object masks (alpha > 0) of raster (single sample per pixel,
 * at the pixel centre) and whitted (spp=1: the centre ray alone) renders overlap with IoU >= 0.99, and where
 * both see a surface their linear depths agree; with each back-end's default anti-aliasing the
 * coverage (finite depth, core/sy_stats.h) still overlaps with IoU >= 0.99; levels of detail at
 * their default leave the raster silhouette as the full meshes draw it (IoU >= 0.99). */
#include "it_util.h"
#include "sy_gltf.h"
#include "sy_stats.h"

#define S 256

typedef struct model {
    const char *path, *camera; /* camera NULL = the viewport frames the scene's bounds */
} model;

static void render(sy_scene *scene, const sy_gltf_info *info, sy_node cam, const char *backend, const char *params,
                   sy_layer *img)
{
    sy_context_pool *pool;
    sy_window *win;
    sy_viewport *vp;
    MUST(sy_context_pool_create(&pool, err));
    MUST(sy_window_create(S, S, &win, err));
    sy_viewport_desc vd = {.root = info->root, .camera = cam, .backend = backend, .params = params};
    MUST(sy_window_add_viewport(win, &vd, &vp, err));
    MUST(sy_layer_create(S, S, img, err));
    MUST(sy_window_render(win, scene, pool, NULL, img, err));
    sy_window_destroy(win);
    sy_context_pool_destroy(pool);
}

/* The coverage IoU of a and b is at least 0.99; printed as "PATH IoU x WHAT", a failure says FAILS. */
static void expect_same_coverage(const char *path, const sy_layer *a, const sy_layer *b, const char *what,
                                 const char *fails)
{
    double iou = 0.0;
    MUST(sy_layer_coverage_iou(a, b, &iou, err));
    printf("%-40s IoU %.5f %s\n", path, iou, what);
    EXPECT_MSG(iou >= 0.99, "%s: %s: IoU %.5f < 0.99", path, fails, iou);
}

static void check_model(const model *m)
{
    char buf[1024];
    const char *path = it_testdata(m->path, buf, sizeof buf);
    sy_scene *scene;
    MUST(sy_scene_create(&scene, err));
    sy_gltf_info info;
    MUST(sy_gltf_load(path, scene, NULL, &info, err));
    sy_node cam = {0};
    if (m->camera) MUST(sy_gltf_find_camera(scene, &info, m->camera, &cam, err));
    MUST(sy_scene_commit(scene, NULL, err));
    sy_layer a, b;
    render(scene, &info, cam, "raster", "msaa=1,shadow_map_size=256", &a);
    render(scene, &info, cam, "whitted", "spp=1,light_samples=1,max_depth=1", &b);
    uint32_t inter = 0, uni = 0, depth_bad = 0;
    for (uint32_t i = 0; i < S * S; ++i) {
        bool ma = a.rgba[4 * i + 3] > 0.0f, mb = b.rgba[4 * i + 3] > 0.0f;
        inter += ma && mb;
        uni += ma || mb;
        if (ma && mb) {
            float da = a.depth[i], db = b.depth[i];
            if (!(fabsf(da - db) <= 2e-3f * db)) depth_bad++;
        }
    }
    double iou = uni ? (double)inter / uni : 1.0;
    printf("%-40s IoU %.5f (%u / %u pixels), depth mismatches %u\n", m->path, iou, inter, uni, depth_bad);
    EXPECT_MSG(uni > 1000, "%s: only %u covered pixels", m->path, uni);
    EXPECT_MSG(iou >= 0.99, "%s: silhouette IoU %.5f < 0.99", m->path, iou);
    EXPECT_MSG(depth_bad <= inter / 100, "%s: %u of %u shared pixels differ in depth by more than 0.2%%", m->path, depth_bad, inter);
    EXPECT(sy_layer_count_nonfinite(&a) == 0);
    /* levels of detail at their default (half a pixel) against the full meshes (lod=0): the same
     * silhouette (issue 32) */
    sy_layer full;
    render(scene, &info, cam, "raster", "msaa=1,shadow_map_size=256,lod=0", &full);
    expect_same_coverage(m->path, &a, &full, "levels of detail against full meshes", "levels of detail change the silhouette");
    sy_layer_destroy(&full);
    sy_layer_destroy(&a);
    sy_layer_destroy(&b);
    /* default anti-aliasing on both sides (raster MSAA 4, Whitted 4 strata): a pixel is covered
     * where any sample hits, so the silhouettes still agree */
    render(scene, &info, cam, "raster", "shadow_map_size=256", &a);
    render(scene, &info, cam, "whitted", "light_samples=4,max_depth=1", &b);
    expect_same_coverage(m->path, &a, &b, "with default anti-aliasing", "anti-aliased silhouette");
    sy_layer_destroy(&a);
    sy_layer_destroy(&b);
    sy_gltf_info_free(&info);
    sy_scene_destroy(scene);
}

int main(void)
{
    it_register();
    static const model models[] = {
        {"gltf/Box/glTF/Box.gltf", NULL},
        {"gltf/Duck/glTF/Duck.gltf", NULL},
        {"cornell/cornell_box.gltf", "camera"},
        {"gltf/DamagedHelmet/glTF/DamagedHelmet.gltf", NULL},
        {"gltf/SimpleInstancing/glTF/SimpleInstancing.gltf", NULL}, /* 125 instances, many edges */
    };
    for (size_t i = 0; i < sizeof models / sizeof models[0]; ++i) check_model(&models[i]);
    return sy_check_finish("raster_align");
}
