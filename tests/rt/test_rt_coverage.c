/* test_rt_coverage.c — the coverage integrator (sy_rt_coverage): per-pixel ids of the nearest
 * visible instance. Expected ids are computed independently by intersecting each pixel-centre
 * ray with the two axis-aligned quads analytically (nearer quad wins). The pick of one pixel
 * (sy_rt_pick) names the same instance at every pixel, with the coverage depth, and a triangle,
 * barycentrics, vertices and transform that put the hit on the pixel-centre ray; bad pixels and
 * uncommitted devices are refused. sy_rt_coverage_hits gives every pixel the pick's instance,
 * triangle and barycentrics bit for bit; sy_rt_mesh_get_view and sy_rt_instance_get_mesh give
 * the vertices the pick read, and after sy_rt_mesh_update the new ones. */
#include "rt_test.h"

#define W 100
#define H 80

/* Pixel-centre ray of rt_camera(z=5, t) for image W x H (window aspect scaled on x). */
static uint32_t expected_id(int px, int py, float t, uint32_t id_far, uint32_t id_near, bool near_visible)
{
    float sx = t * (float)W / (float)H;
    float u = -sx + 2.0f * sx * ((float)px + 0.5f) / (float)W;
    float v = t - 2.0f * t * ((float)py + 0.5f) / (float)H;
    /* near quad: h = 0.25 at z = 1 centred at (0.503, 0.0037) (distance 4); far: h = 0.5 at z = 0 */
    float xn = 4.0f * u, yn = 4.0f * v;
    if (near_visible && fabsf(xn - 0.503f) < 0.25f && fabsf(yn - 0.0037f) < 0.25f) return id_near;
    float xf = 5.0f * u, yf = 5.0f * v;
    if (fabsf(xf) < 0.5f && fabsf(yf) < 0.5f) return id_far;
    return 0;
}

int main(void)
{
    sy_rt_device *dev = rt_device();
    sy_rt_mesh big = rt_quad(dev, 0.5f), small = rt_quad(dev, 0.25f);
    sy_rt_material m = rt_lambert(dev, 0.5f, 0.5f, 0.5f);
    float xf[16];
    rt_translation(xf, 0, 0, 0);
    sy_rt_instance far_q = rt_place(dev, big, xf, m, 0);
    rt_translation(xf, 0.503f, 0.0037f, 1); /* edges off the pixel centres */
    sy_rt_instance near_q = rt_place(dev, small, xf, m, SY_RT_INSTANCE_BAKED);
    MUST(sy_rt_commit(dev));
    float t = 0.2f;
    sy_rt_camera cam = rt_camera(5.0f, t);
    cam.window[0] = -t * (float)W / (float)H;
    cam.window[1] = t * (float)W / (float)H;
    sy_rt_render_desc d = rt_desc(SY_RT_INTEGRATOR_WHITTED, W, H); /* integrator is ignored */
    uint32_t ids[W * H], part[W * H];
    float depth[W * H];
    MUST(sy_rt_coverage(dev, &cam, &d, ids, depth));
    int wrong = 0, n_far = 0, n_near = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            uint32_t want = expected_id(x, y, t, far_q.id, near_q.id, true), got = ids[y * W + x];
            if (got != want) wrong++;
            n_far += got == far_q.id, n_near += got == near_q.id;
            if (got == near_q.id) EXPECT_MSG(fabsf(depth[y * W + x] - 4.0f) < 1e-4f, "near depth %g", depth[y * W + x]);
            if (got == 0) EXPECT_MSG(isinf(depth[y * W + x]), "miss depth %g", depth[y * W + x]);
        }
    EXPECT_MSG(wrong == 0, "%d pixels with the wrong id", wrong);
    EXPECT_MSG(n_far > 0 && n_near > 0, "both objects covered: far %d near %d", n_far, n_near);
    printf("coverage: far quad %d px, near quad %d px\n", n_far, n_near);

    /* sy_rt_pick: the same instance and depth at every pixel; its triangle, barycentrics, vertices
     * and transform put the point on the pixel-centre ray at that depth */
    int pick_wrong = 0, off_ray = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            sy_rt_pick_hit ph;
            MUST(sy_rt_pick(dev, &cam, W, H, (uint32_t)x, (uint32_t)y, &ph));
            pick_wrong += ph.instance.id != ids[y * W + x];
            if (!ph.instance.id) continue;
            pick_wrong += fabsf(ph.depth - depth[y * W + x]) > 1e-5f || ph.triangle > 1;
            float b[3] = {1.0f - ph.u - ph.v, ph.u, ph.v}, o[3] = {0, 0, 0}, wp[3];
            for (int k = 0; k < 3; ++k)
                for (int i = 0; i < 3; ++i) o[i] += b[k] * ph.vertices[k][i];
            for (int i = 0; i < 3; ++i)
                wp[i] = ph.transform[i] * o[0] + ph.transform[4 + i] * o[1] + ph.transform[8 + i] * o[2] + ph.transform[12 + i];
            float sx = t * (float)W / (float)H, ur = -sx + 2.0f * sx * ((float)x + 0.5f) / (float)W,
                  vr = t - 2.0f * t * ((float)y + 0.5f) / (float)H, dd = ph.depth;
            off_ray += fabsf(wp[0] - ur * dd) > 1e-5f || fabsf(wp[1] - vr * dd) > 1e-5f || fabsf(wp[2] - (5.0f - dd)) > 1e-5f;
        }
    EXPECT_MSG(pick_wrong == 0, "%d picks differ from the coverage ids or depths", pick_wrong);
    EXPECT_MSG(off_ray == 0, "%d picked points are off their pixel's ray", off_ray);
    sy_rt_pick_hit ph;
    EXPECT_MSG(sy_rt_pick(dev, &cam, W, H, W, 0, &ph) == SY_RT_ERROR_INVALID_ARGUMENT && ph.instance.id == 0 &&
                   strstr(rt_test_msg, "(100, 0)"),
               "pick outside the image: %s", rt_test_msg);

    /* sy_rt_coverage_hits: the pick's instance, triangle and barycentrics at every pixel; the
     * instance's mesh and that mesh's view give the vertices the pick read */
    static sy_rt_coverage_hit hits[W * H];
    MUST(sy_rt_coverage_hits(dev, &cam, &d, hits));
    int hit_wrong = 0, view_wrong = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            const sy_rt_coverage_hit *h = &hits[y * W + x];
            MUST(sy_rt_pick(dev, &cam, W, H, (uint32_t)x, (uint32_t)y, &ph));
            hit_wrong += h->instance != ph.instance.id || h->instance != ids[y * W + x];
            if (!h->instance) {
                hit_wrong += h->triangle != 0 || h->u != 0.0f || h->v != 0.0f;
                continue;
            }
            hit_wrong += h->triangle != ph.triangle || h->u != ph.u || h->v != ph.v;
            sy_rt_mesh mesh;
            sy_rt_mesh_view mv;
            MUST(sy_rt_instance_get_mesh(dev, ph.instance, &mesh));
            MUST(sy_rt_mesh_get_view(dev, mesh, &mv));
            view_wrong += mesh.id != (h->instance == far_q.id ? big.id : small.id) || h->triangle >= mv.triangle_count;
            for (int k = 0; k < 3 && h->triangle < mv.triangle_count; ++k)
                view_wrong += memcmp(mv.positions + 3u * mv.indices[3u * h->triangle + k], ph.vertices[k], 3 * sizeof(float)) != 0;
        }
    EXPECT_MSG(hit_wrong == 0, "%d coverage hits differ from the picks", hit_wrong);
    EXPECT_MSG(view_wrong == 0, "%d pixels whose mesh view differs from the pick's vertices", view_wrong);
    {
        sy_rt_mesh_view mv;
        MUST(sy_rt_mesh_get_view(dev, big, &mv));
        const float nrm[12] = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}; /* rt_quad's */
        float moved[12];
        for (uint32_t i = 0; i < mv.vertex_count * 3u && i < 12u; ++i) moved[i] = mv.positions[i] * 1.5f;
        EXPECT(mv.vertex_count == 4 && mv.triangle_count == 2);
        MUST(sy_rt_mesh_update(dev, big, moved, nrm));
        MUST(sy_rt_mesh_get_view(dev, big, &mv));
        EXPECT_MSG(!memcmp(mv.positions, moved, sizeof moved), "the view after an update is not the update's vertices");
        for (uint32_t i = 0; i < 12u; ++i) moved[i] /= 1.5f;
        MUST(sy_rt_mesh_update(dev, big, moved, nrm));
        MUST(sy_rt_commit(dev));
        sy_rt_mesh none;
        EXPECT(sy_rt_mesh_get_view(dev, (sy_rt_mesh){0}, &mv) == SY_RT_ERROR_INVALID_HANDLE && mv.positions == NULL);
        EXPECT(sy_rt_instance_get_mesh(dev, (sy_rt_instance){0}, &none) == SY_RT_ERROR_INVALID_HANDLE);
        EXPECT(sy_rt_coverage_hits(dev, &cam, &d, NULL) == SY_RT_ERROR_INVALID_ARGUMENT);
    }

    /* a sub-rectangle equals the crop of the full image */
    sy_rt_render_desc sub = d;
    sub.x = 37, sub.y = 21, sub.width = 41, sub.height = 33;
    MUST(sy_rt_coverage(dev, &cam, &sub, part, NULL));
    int diff = 0;
    for (uint32_t y = 0; y < sub.height; ++y)
        for (uint32_t x = 0; x < sub.width; ++x) diff += part[y * sub.width + x] != ids[(y + sub.y) * W + x + sub.x];
    EXPECT_MSG(diff == 0, "%d sub-rectangle pixels differ from the full image", diff);

    /* hiding the near quad uncovers the far one behind it */
    MUST(sy_rt_instance_set_visible(dev, near_q, false));
    MUST(sy_rt_commit(dev));
    MUST(sy_rt_coverage(dev, &cam, &d, ids, NULL));
    wrong = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) wrong += ids[y * W + x] != expected_id(x, y, t, far_q.id, near_q.id, false);
    EXPECT_MSG(wrong == 0, "%d pixels wrong with the near quad hidden", wrong);

    /* uncommitted changes and NULL output are refused with a message */
    MUST(sy_rt_instance_set_visible(dev, near_q, true));
    EXPECT_MSG(sy_rt_coverage(dev, &cam, &d, ids, NULL) == SY_RT_ERROR_INVALID_OPERATION, "%s", sy_rt_device_error(dev));
    EXPECT_MSG(sy_rt_pick(dev, &cam, W, H, 1, 1, &ph) == SY_RT_ERROR_INVALID_OPERATION, "%s", sy_rt_device_error(dev));
    MUST(sy_rt_commit(dev));
    EXPECT_MSG(sy_rt_coverage(dev, &cam, &d, NULL, NULL) == SY_RT_ERROR_INVALID_ARGUMENT, "%s", sy_rt_device_error(dev));
    sy_rt_device_destroy(dev);
    return sy_check_finish("rt_coverage");
}
