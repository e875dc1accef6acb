/* test_rt_camera.c — camera and image conventions: off-axis windows shift the image by the
 * expected number of pixels, depth is the distance along the viewing axis (also off-axis, rotated
 * and orthographic), sub-rectangles stitch bit-identically to a full render, and renders are
 * deterministic. */
#include "rt_test.h"

/* Pixel of the red emitter (the grey floor has equal red and green). */
static bool is_red(const float *c) { return c[0] > 0.5f && c[1] < 0.01f; }

/* First and last columns of row y showing the red emitter (-1 if none). */
static void row_extent(const float *rgba, int w, int y, int *first, int *last)
{
    *first = *last = -1;
    for (int x = 0; x < w; ++x)
        if (is_red(rgba + 4 * (y * w + x))) {
            if (*first < 0) *first = x;
            *last = x;
        }
}

static void col_extent(const float *rgba, int w, int h, int x, int *first, int *last)
{
    *first = *last = -1;
    for (int y = 0; y < h; ++y)
        if (is_red(rgba + 4 * (y * w + x))) {
            if (*first < 0) *first = y;
            *last = y;
        }
}

static void test_off_axis_shift(sy_rt_device *dev)
{
    const int w = 40, h = 40;
    sy_rt_camera cam = rt_camera(5.0f, 0.5f);
    sy_rt_render_desc rd = rt_desc(SY_RT_INTEGRATOR_PRIMARY, w, h);
    float *a, *ad, *b, *bd;
    rt_render(dev, &cam, &rd, &a, &ad);
    /* Shift the window right by 3 pixels and up by 5: the image moves left by 3 and down by 5. */
    float px = 1.0f / w;
    cam.window[0] += 3 * px;
    cam.window[1] += 3 * px;
    cam.window[2] += 5 * px;
    cam.window[3] += 5 * px;
    rt_render(dev, &cam, &rd, &b, &bd);
    int f0, l0, f1, l1;
    row_extent(a, w, 20, &f0, &l0);
    row_extent(b, w, 25, &f1, &l1);
    EXPECT_MSG(f0 == 12 && l0 == 27, "reference quad spans columns %d..%d, expected 12..27", f0, l0);
    EXPECT_MSG(f1 == f0 - 3 && l1 == l0 - 3, "shifted window: columns %d..%d, expected %d..%d", f1, l1, f0 - 3, l0 - 3);
    col_extent(a, w, h, 20, &f0, &l0);
    col_extent(b, w, h, 17, &f1, &l1);
    EXPECT_MSG(f1 == f0 + 5 && l1 == l0 + 5, "shifted window: rows %d..%d, expected %d..%d", f1, l1, f0 + 5, l0 + 5);
    free(a);
    free(ad);
    free(b);
    free(bd);

    /* Pixel centres sit at +0.5: moving the window left (down) by s pixels moves the square's
     * left (top) edge from pixel boundary 12 to 12 + s, so pixel 12 (centre 12.5) is still covered
     * for s = 0.45 and no longer for s = 0.55. */
    const float shifts[2] = {0.45f, 0.55f};
    const int expect_first[2] = {12, 13};
    for (int i = 0; i < 2; ++i) {
        sy_rt_camera c2 = rt_camera(5.0f, 0.5f);
        c2.window[0] -= shifts[i] * px;
        c2.window[1] -= shifts[i] * px;
        c2.window[2] += shifts[i] * px; /* window up: content moves down */
        c2.window[3] += shifts[i] * px;
        rt_render(dev, &c2, &rd, &b, &bd);
        row_extent(b, w, 20, &f1, &l1);
        EXPECT_MSG(f1 == expect_first[i], "edge moved %.2f px: first column %d, expected %d", shifts[i], f1, expect_first[i]);
        col_extent(b, w, h, 20, &f1, &l1);
        EXPECT_MSG(f1 == expect_first[i], "edge moved %.2f px: first row %d, expected %d", shifts[i], f1, expect_first[i]);
        free(b);
        free(bd);
    }
}

static void test_depth(void)
{
    /* Own scene: one plane through the origin, rotated 30 degrees about Y like the camera. */
    sy_rt_device *dev = rt_device();
    float pxf[16];
    rt_rot_y(pxf, 0.5235988f, 0.0f, 0.0f, 0.0f);
    rt_place(dev, rt_quad(dev, 50.0f), pxf, rt_lambert(dev, 0.7f, 0.7f, 0.7f), SY_RT_INSTANCE_BAKED);
    MUST(sy_rt_commit(dev));
    const int w = 24, h = 16;
    sy_rt_render_desc rd = rt_desc(SY_RT_INTEGRATOR_WHITTED, w, h);
    /* Off-axis window, camera rotated 30 degrees about Y looking at a plane perpendicular to its axis. */
    for (int ortho = 0; ortho < 2; ++ortho) {
        sy_rt_camera cam;
        memset(&cam, 0, sizeof cam);
        const float ang = 0.5235988f, dist = 7.0f;
        /* Camera at plane_centre + dist * (camera +Z axis); the background plane is rotated the same way. */
        rt_rot_y(cam.camera_to_world, ang, dist * sinf(ang), 0.0f, dist * cosf(ang));
        cam.projection = ortho ? SY_RT_PROJECTION_ORTHOGRAPHIC : SY_RT_PROJECTION_PERSPECTIVE;
        float win[4] = {0.1f, 0.6f, -0.2f, 0.15f};
        for (int k = 0; k < 4; ++k) cam.window[k] = ortho ? win[k] * 4 : win[k];
        cam.near_clip = 0.1f;
        float *rgba, *depth;
        rt_render(dev, &cam, &rd, &rgba, &depth);
        int bad = 0;
        for (int i = 0; i < w * h; ++i)
            if (!(fabsf(depth[i] - dist) < 2e-5f * dist)) bad++;
        EXPECT_MSG(bad == 0, "%s: %d pixels with depth != %g (first %g)", ortho ? "ortho" : "persp", bad, dist, depth[0]);
        rt_image_free(rgba, depth);
        /* Near clip beyond the plane: nothing is seen. */
        cam.near_clip = dist + 0.5f;
        rt_render(dev, &cam, &rd, &rgba, &depth);
        EXPECT_MSG(isinf(depth[0]) && rgba[3] == 0.0f, "near clip: depth %g alpha %g", depth[0], rgba[3]);
        rt_image_free(rgba, depth);
    }
    sy_rt_device_destroy(dev);
}

static void test_stitch_and_determinism(sy_rt_device *dev)
{
    const int w = 45, h = 31;
    sy_rt_camera cam = rt_camera(5.0f, 0.6f);
    cam.window[0] = -0.7f; /* asymmetric on purpose */
    sy_rt_render_desc rd = rt_desc(SY_RT_INTEGRATOR_WHITTED, w, h);
    rd.seed = 7;
    float *full, *fd;
    rt_render(dev, &cam, &rd, &full, &fd);
    /* Four sub-rectangles with cuts that are not tile-aligned. */
    const int cx = 13, cy = 7;
    const int rects[4][4] = {{0, 0, cx, cy}, {cx, 0, w - cx, cy}, {0, cy, cx, h - cy}, {cx, cy, w - cx, h - cy}};
    int mismatches = 0;
    for (int r = 0; r < 4; ++r) {
        sy_rt_render_desc sd = rd;
        sd.x = (uint32_t)rects[r][0];
        sd.y = (uint32_t)rects[r][1];
        sd.width = (uint32_t)rects[r][2];
        sd.height = (uint32_t)rects[r][3];
        float *sub, *subd;
        rt_render(dev, &cam, &sd, &sub, &subd);
        for (int y = 0; y < rects[r][3]; ++y) {
            int fy = rects[r][1] + y;
            if (memcmp(sub + 4 * y * rects[r][2], full + 4 * (fy * w + rects[r][0]), 4 * sizeof(float) * rects[r][2]) != 0 ||
                memcmp(subd + y * rects[r][2], fd + fy * w + rects[r][0], sizeof(float) * rects[r][2]) != 0)
                mismatches++;
        }
        free(sub);
        free(subd);
    }
    EXPECT_MSG(mismatches == 0, "%d stitched rows differ from the full render", mismatches);
    float *again, *ad;
    rt_render(dev, &cam, &rd, &again, &ad);
    EXPECT_MSG(memcmp(again, full, sizeof(float) * 4 * w * h) == 0, "two renders with the same seed differ");
    /* The scene has soft shadows: a lit, not-black image with partially shadowed pixels. */
    double sum = 0;
    for (int i = 0; i < w * h; ++i) sum += full[4 * i];
    EXPECT_MSG(sum > 1.0, "image is black (sum %g)", sum);
    free(again);
    free(ad);
    free(full);
    free(fd);
}

int main(void)
{
    sy_rt_device *dev = rt_device();
    float xf[16];
    rt_identity(xf);
    /* Emissive red square (for edges), a grey floor, an area light
     * and a blocker (for soft shadows in the stitch test). */
    rt_place(dev, rt_quad(dev, 1.0f), xf, rt_emitter(dev, 1.0f, 0.0f, 0.0f), 0);
    float floor_xf[16];
    rt_translation(floor_xf, 0.0f, 0.0f, -0.01f); /* just behind the red square */
    rt_place(dev, rt_quad(dev, 50.0f), floor_xf, rt_lambert(dev, 0.7f, 0.7f, 0.7f), SY_RT_INSTANCE_BAKED);
    float lamp[16];
    rt_rot_y(lamp, (float)M_PI, 2.0f, 1.0f, 3.0f);
    rt_place(dev, rt_quad(dev, 0.4f), lamp, rt_emitter(dev, 20.0f, 20.0f, 20.0f), 0);
    float blk[16];
    rt_translation(blk, 1.5f, 0.5f, 1.5f);
    rt_place(dev, rt_quad(dev, 0.3f), blk, rt_lambert(dev, 0.2f, 0.9f, 0.2f), 0);
    MUST(sy_rt_commit(dev));

    test_off_axis_shift(dev);
    test_depth();
    test_stitch_and_determinism(dev);
    sy_rt_device_destroy(dev);
    return sy_check_finish("test_rt_camera");
}
