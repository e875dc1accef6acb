/* test_rt_instances.c — incremental scene updates: set_transform moves an instance in the image
 * (Embree instance and baked), set_visible hides it, destroying it removes it, a shared mesh is
 * instanced twice, material changes are picked up, and the area-light list follows emissive
 * instances (moving an emitter changes what it lights). Moves without a top-level rebuild (twins in
 * the moved instances' scene) render exactly what a device built from scratch renders. Motion blur
 * (sy_rt_instance_set_motion): an emitter moving 2 m over the shutter is drawn as a streak of the
 * same light (its green mass) centred between its ends, through the top scene, a twin and a baked
 * instance alike; dropping the motion renders bit for bit the sharp image again. A deforming mesh
 * (sy_rt_mesh_update_motion: its vertices slid 2 m between the close and the open) streaks the same
 * way, and clearing the motion renders bit for bit what a plain update to the open pose renders. A
 * transform or a close transform that shrinks past SY_RT_INSTANCE_GAIN_MAX is refused with the
 * reason for an instance created unbaked and taken by a baked one. Curved motion
 * (sy_rt_instance_set_motion_steps, 3 steps along a V) streaks along both legs, instance and baked. */
#include "rt_test.h"

#define W 40

/* Mean column of pixels showing the emitter colour (0, 1, 0); -1 when none; count in *n. */
static double green_centroid(const float *rgba, int *n)
{
    double sum = 0;
    *n = 0;
    for (int y = 0; y < W; ++y)
        for (int x = 0; x < W; ++x) {
            const float *c = rgba + 4 * (y * W + x);
            if (c[0] == 0.0f && c[1] == 1.0f && c[2] == 0.0f) {
                sum += x + 0.5;
                ++*n;
            }
        }
    return *n ? sum / *n : -1.0;
}

static double render_centroid(sy_rt_device *dev, int *n)
{
    sy_rt_camera cam = rt_camera(5.0f, 0.5f); /* 40 px over 5 m: 8 px per metre */
    sy_rt_render_desc rd = rt_desc(SY_RT_INTEGRATOR_WHITTED, W, W);
    float *rgba, *depth;
    rt_render(dev, &cam, &rd, &rgba, &depth);
    double c = green_centroid(rgba, n);
    rt_image_free(rgba, depth);
    return c;
}

static void test_move_hide_destroy(uint32_t flags)
{
    sy_rt_device *dev = rt_device();
    sy_rt_mesh q = rt_quad(dev, 0.5f);
    sy_rt_material green = rt_emitter(dev, 0.0f, 1.0f, 0.0f);
    float xf[16];
    rt_translation(xf, -1.0f, 0.0f, 0.0f);
    sy_rt_instance inst = rt_place(dev, q, xf, green, flags);
    MUST(sy_rt_commit(dev));
    int n;
    double c0 = render_centroid(dev, &n);
    EXPECT_MSG(n == 64 && fabs(c0 - 12.0) < 1e-9, "flags %u: emitter at x=-1: %d px centred at column %g (expected 64 at 12)", flags, n, c0);

    rt_translation(xf, 1.0f, 0.0f, 0.0f);
    MUST(sy_rt_instance_set_transform(dev, inst, xf));
    MUST(sy_rt_commit(dev));
    double c1 = render_centroid(dev, &n);
    EXPECT_MSG(n == 64 && fabs(c1 - c0 - 16.0) < 1e-9, "flags %u: moved 2 m = 16 px: centroid %g -> %g", flags, c0, c1);

    MUST(sy_rt_instance_set_visible(dev, inst, false));
    MUST(sy_rt_commit(dev));
    render_centroid(dev, &n);
    EXPECT_MSG(n == 0, "flags %u: hidden instance still visible (%d px)", flags, n);
    MUST(sy_rt_instance_set_visible(dev, inst, true));

    /* A second instance of the same mesh. */
    rt_translation(xf, -1.0f, 0.0f, 0.0f);
    sy_rt_instance second = rt_place(dev, q, xf, green, flags ^ SY_RT_INSTANCE_BAKED);
    MUST(sy_rt_commit(dev));
    double c2 = render_centroid(dev, &n);
    EXPECT_MSG(n == 128 && fabs(c2 - 20.0) < 1e-9, "flags %u: two instances: %d px centred at %g", flags, n, c2);

    MUST(sy_rt_instance_destroy(dev, inst));
    MUST(sy_rt_commit(dev));
    double c3 = render_centroid(dev, &n);
    EXPECT_MSG(n == 64 && fabs(c3 - 12.0) < 1e-9, "flags %u: after destroy: %d px at %g", flags, n, c3);

    /* Material change: the remaining instance turns red. */
    MUST(sy_rt_instance_set_material(dev, second, rt_emitter(dev, 1.0f, 0.0f, 0.0f)));
    MUST(sy_rt_commit(dev));
    render_centroid(dev, &n);
    EXPECT_MSG(n == 0, "flags %u: material change ignored", flags);
    MUST(sy_rt_instance_destroy(dev, second));
    MUST(sy_rt_mesh_destroy(dev, q));
    MUST(sy_rt_commit(dev));
    sy_rt_stats st;
    sy_rt_device_stats(dev, &st);
    EXPECT_MSG(st.instances == 0 && st.meshes == 0 && st.area_light_triangles == 0, "stats %u %u %u", st.instances, st.meshes,
               st.area_light_triangles);
    sy_rt_device_destroy(dev);
}

/* Radiance of the floor's centre pixel under a downward-facing emitter at height h. */
static float floor_centre(sy_rt_device *dev)
{
    sy_rt_camera cam = rt_camera(0.5f, 0.05f);
    sy_rt_render_desc rd = rt_desc(SY_RT_INTEGRATOR_WHITTED, 9, 9);
    float *rgba, *depth;
    rt_render(dev, &cam, &rd, &rgba, &depth);
    float v = rgba[4 * (4 * 9 + 4)];
    rt_image_free(rgba, depth);
    return v;
}

static void test_area_light_follows(void)
{
    sy_rt_device *dev = rt_device();
    rt_place(dev, rt_quad(dev, 10.0f), NULL, rt_lambert(dev, 0.8f, 0.8f, 0.8f), 0);
    sy_rt_material_desc md;
    sy_rt_material_desc_init(&md);
    md.emissive[0] = md.emissive[1] = md.emissive[2] = 5.0f;
    sy_rt_material em = rt_material(dev, &md);
    float lamp[16];
    rt_rot_y(lamp, (float)M_PI, 0.0f, 0.0f, 1.0f);
    sy_rt_instance li = rt_place(dev, rt_quad(dev, 0.2f), lamp, em, 0);
    MUST(sy_rt_commit(dev));
    float v1 = floor_centre(dev);
    /* Irradiance under the centre of a 0.4 x 0.4 square of radiance Le at height 1: Le * pi * F
     * with the point-to-parallel-rectangle form factor, four 0.2 x 0.2 corner rectangles:
     * F = 4 / (2 pi) * 2 * X / sqrt(1 + X^2) * atan(X / sqrt(1 + X^2)), X = 0.2 (F = 0.04836);
     * Lambert * 0.8 / pi. 16 stratified samples per pixel land within 1 %. */
    double X = 0.2, q = X / sqrt(1.0 + X * X), F = 4.0 / (2.0 * M_PI) * 2.0 * q * atan(q);
    double exact1 = 0.8 / M_PI * 5.0 * M_PI * F;
    EXPECT_MSG(rt_near(v1, exact1, 0.01), "lamp at 1 m: %g, expected %g", v1, exact1);
    rt_rot_y(lamp, (float)M_PI, 0.0f, 0.0f, 2.0f);
    MUST(sy_rt_instance_set_transform(dev, li, lamp));
    MUST(sy_rt_commit(dev));
    float v2 = floor_centre(dev);
    EXPECT_MSG(rt_near(v2, v1 / 4.0, 0.05), "lamp moved to 2 m: %g, expected about %g (inverse square)", v2, v1 / 4.0);
    /* Emission doubled through a material update. */
    md.emissive[0] = md.emissive[1] = md.emissive[2] = 10.0f;
    MUST(sy_rt_material_update(dev, em, &md));
    MUST(sy_rt_commit(dev));
    float v3 = floor_centre(dev);
    EXPECT_MSG(rt_near(v3, 2.0 * v2, 1e-5), "emission doubled: %g, expected %g", v3, 2.0 * v2);
    /* Double-sided emitter facing away still lights the floor; single-sided does not. */
    rt_rot_y(lamp, 0.0f, 0.0f, 0.0f, 2.0f);
    MUST(sy_rt_instance_set_transform(dev, li, lamp));
    MUST(sy_rt_commit(dev));
    EXPECT_MSG(floor_centre(dev) == 0.0f, "single-sided emitter facing away lights the floor");
    md.double_sided = true;
    MUST(sy_rt_material_update(dev, em, &md));
    MUST(sy_rt_commit(dev));
    EXPECT_MSG(rt_near(floor_centre(dev), v3, 1e-5), "double-sided emitter: %g, expected %g", floor_centre(dev), v3);
    sy_rt_device_destroy(dev);
}

/* >>moves without a top-level rebuild */
#define GRID 18 /* GRID x GRID instances: 324, so the fast path takes 64 + 324 / 64 = 69 moved ones */
#define MW 64

typedef struct grid_scene {
    sy_rt_device *dev;
    sy_rt_instance inst[GRID * GRID];
} grid_scene;

/* Instance i's transform after `moves` (a deterministic shuffle: rotated about Y, shifted). */
static void grid_xf(int i, int moved, float xf[16])
{
    float x = -2.0f + 4.0f * (float)(i % GRID) / (GRID - 1), y = -2.0f + 4.0f * (float)(i / GRID) / (GRID - 1);
    if (moved) rt_rot_y(xf, 0.3f * (float)(i % 5), y * 0.5f, x * 0.7f, -0.5f - 0.05f * (float)(i % 7));
    else rt_translation(xf, x, y, 0.0f);
}

/* Every other instance baked; a mix of emitters and lit Lambert quads under one point light. */
static void grid_build(grid_scene *g, const unsigned char *moved)
{
    g->dev = rt_device();
    sy_rt_mesh q = rt_quad(g->dev, 0.1f);
    sy_rt_material mats[3] = {rt_emitter(g->dev, 0.0f, 1.0f, 0.0f), rt_lambert(g->dev, 0.8f, 0.2f, 0.2f),
                              rt_lambert(g->dev, 0.2f, 0.2f, 0.8f)};
    sy_rt_light_desc ld = {.type = SY_RT_LIGHT_POINT, .color = {1, 1, 1}, .intensity = 40.0f, .position = {0, 1, 4}};
    sy_rt_light l;
    MUST(sy_rt_light_create(g->dev, &ld, &l));
    for (int i = 0; i < GRID * GRID; ++i) {
        float xf[16];
        grid_xf(i, moved && moved[i], xf);
        g->inst[i] = rt_place(g->dev, q, xf, mats[i % 3], i % 2 ? SY_RT_INSTANCE_BAKED : 0u);
    }
    MUST(sy_rt_commit(g->dev));
}

/* Whitted (shadows) and primary (ray packets) renders must match the from-scratch device bit for bit. */
static void grid_compare(grid_scene *g, const unsigned char *moved, const char *what)
{
    grid_scene ref;
    grid_build(&ref, moved);
    sy_rt_camera cam = rt_camera(5.0f, 0.6f);
    for (int k = 0; k < 2; ++k) {
        sy_rt_render_desc rd = rt_desc(k ? SY_RT_INTEGRATOR_PRIMARY : SY_RT_INTEGRATOR_WHITTED, MW, MW);
        float *a, *ad, *b, *bd;
        rt_render(g->dev, &cam, &rd, &a, &ad);
        rt_render(ref.dev, &cam, &rd, &b, &bd);
        size_t diff = 0;
        for (size_t i = 0; i < (size_t)MW * MW * 4; ++i) diff += a[i] != b[i];
        for (size_t i = 0; i < (size_t)MW * MW; ++i) diff += ad[i] != bd[i];
        EXPECT_MSG(diff == 0, "%s: %s render differs from a device built with the same transforms in %zu values", what,
                   k ? "primary (packets)" : "whitted", diff);
        free(a), free(ad), free(b), free(bd);
    }
    sy_rt_device_destroy(ref.dev);
}

static void test_moves_match_rebuild(void)
{
    unsigned char moved[GRID * GRID] = {0};
    grid_scene g;
    grid_build(&g, NULL);
    sy_rt_stats st;
    sy_rt_device_stats(g.dev, &st);
    uint64_t builds = st.top_builds;

    /* A few moves over several commits (instance 7 twice): no top-level rebuild. */
    const int first[] = {7, 8, 100, 7, 250};
    for (int k = 0; k < 5; ++k) {
        float xf[16];
        moved[first[k]] = 1;
        grid_xf(first[k], 1, xf);
        if (k == 0) rt_translation(xf, 9.0f, 9.0f, 0.0f); /* an intermediate pose, moved again below */
        MUST(sy_rt_instance_set_transform(g.dev, g.inst[first[k]], xf));
        MUST(sy_rt_commit(g.dev));
    }
    sy_rt_device_stats(g.dev, &st);
    EXPECT_MSG(st.top_builds == builds && st.moved_instances == 4, "4 moved instances: %llu full builds (expected %llu), %u "
               "shown by twins (expected 4)", (unsigned long long)st.top_builds, (unsigned long long)builds, st.moved_instances);
    grid_compare(&g, moved, "4 moved instances");

    /* Hiding and showing a moved instance is structural: a full build folds the twins back. */
    MUST(sy_rt_instance_set_visible(g.dev, g.inst[100], false));
    MUST(sy_rt_commit(g.dev));
    MUST(sy_rt_instance_set_visible(g.dev, g.inst[100], true));
    MUST(sy_rt_commit(g.dev));
    sy_rt_device_stats(g.dev, &st);
    EXPECT_MSG(st.top_builds == builds + 2 && st.moved_instances == 0, "hide + show: %llu builds, %u twins",
               (unsigned long long)(st.top_builds - builds), st.moved_instances);
    grid_compare(&g, moved, "after hide + show");

    /* More moves than the fast path takes at once: one full build. */
    builds = st.top_builds;
    for (int i = 0; i < GRID * GRID; i += 3) {
        float xf[16];
        moved[i] = 1;
        grid_xf(i, 1, xf);
        MUST(sy_rt_instance_set_transform(g.dev, g.inst[i], xf));
    }
    MUST(sy_rt_commit(g.dev));
    sy_rt_device_stats(g.dev, &st);
    EXPECT_MSG(st.top_builds == builds + 1 && st.moved_instances == 0, "108 moves in one commit: %llu builds, %u twins",
               (unsigned long long)(st.top_builds - builds), st.moved_instances);
    grid_compare(&g, moved, "108 moved instances");

    /* Destroying a moved instance. */
    float xf[16];
    grid_xf(1, 1, xf);
    moved[1] = 1;
    MUST(sy_rt_instance_set_transform(g.dev, g.inst[1], xf));
    MUST(sy_rt_commit(g.dev));
    sy_rt_device_stats(g.dev, &st);
    EXPECT_MSG(st.moved_instances == 1, "one moved: %u twins", st.moved_instances);
    MUST(sy_rt_instance_destroy(g.dev, g.inst[1]));
    MUST(sy_rt_commit(g.dev));
    sy_rt_device_stats(g.dev, &st);
    EXPECT_MSG(st.moved_instances == 0 && st.instances == GRID * GRID - 1, "destroyed the moved one: %u twins, %u instances",
               st.moved_instances, st.instances);
    sy_rt_device_destroy(g.dev);
}

/* Green mass (sum of G) and its mean column over a W x W render; columns with any green in lo..hi. */
static double green_mass(sy_rt_device *dev, double *centre, int *lo, int *hi)
{
    sy_rt_camera cam = rt_camera(5.0f, 0.5f);
    sy_rt_render_desc rd = rt_desc(SY_RT_INTEGRATOR_WHITTED, W, W);
    float *rgba, *depth;
    rt_render(dev, &cam, &rd, &rgba, &depth);
    double mass = 0.0, sum = 0.0;
    *lo = W, *hi = -1;
    for (int y = 0; y < W; ++y)
        for (int x = 0; x < W; ++x) {
            double g = rgba[4 * (y * W + x) + 1];
            if (g <= 0.0) continue;
            mass += g, sum += g * (x + 0.5);
            if (x < *lo) *lo = x;
            if (x > *hi) *hi = x;
        }
    free(rgba);
    free(depth);
    *centre = mass > 0.0 ? sum / mass : -1.0;
    return mass;
}

/* The quad of rt_quad(dev, 0.5) slid dx along x: its vertices (normals unchanged). */
static void quad_at(float dx, float pos[12], float nrm[12])
{
    const float p[12] = {-0.5f, -0.5f, 0, 0.5f, -0.5f, 0, 0.5f, 0.5f, 0, -0.5f, 0.5f, 0};
    for (int k = 0; k < 12; ++k) pos[k] = p[k] + (k % 3 == 0 ? dx : 0.0f), nrm[k] = k % 3 == 2 ? 1.0f : 0.0f;
}

static void test_mesh_motion(void)
{
    sy_rt_device *dev = rt_device();
    sy_rt_mesh q = rt_quad(dev, 0.5f);
    sy_rt_material green = rt_emitter(dev, 0.0f, 1.0f, 0.0f);
    rt_place(dev, q, NULL, green, 0);
    float open[12], close[12], n[12];
    quad_at(1.0f, close, n);
    MUST(sy_rt_mesh_update(dev, q, close, n)); /* synced at the close */
    MUST(sy_rt_commit(dev));
    quad_at(-1.0f, open, n);
    MUST(sy_rt_mesh_update_motion(dev, q, open, n)); /* then at the open: the close kept for time 1 */
    MUST(sy_rt_commit(dev));
    double c;
    int lo, hi;
    double m1 = green_mass(dev, &c, &lo, &hi);
    printf("mesh motion: mass %g, centre %g, columns %d..%d\n", m1, c, lo, hi);
    EXPECT_MSG(fabs(m1 - 64.0) < 0.05 * 64.0 && fabs(c - 20.0) < 0.5 && lo == 8 && hi == 31,
               "mesh motion: mass %g (sharp 64), centre %g, columns %d..%d (want 8..31)", m1, c, lo, hi);
    /* cleared: the open pose, bit for bit what a plain update to it renders */
    MUST(sy_rt_motion_clear(dev));
    MUST(sy_rt_commit(dev));
    sy_rt_camera cam = rt_camera(5.0f, 0.5f);
    sy_rt_render_desc rd = rt_desc(SY_RT_INTEGRATOR_WHITTED, W, W);
    float *a, *ad, *b, *bd;
    rt_render(dev, &cam, &rd, &a, &ad);
    MUST(sy_rt_mesh_update(dev, q, close, n));
    MUST(sy_rt_mesh_update(dev, q, open, n));
    MUST(sy_rt_commit(dev));
    rt_render(dev, &cam, &rd, &b, &bd);
    EXPECT_MSG(memcmp(a, b, sizeof(float) * 4 * W * W) == 0, "mesh motion cleared: differs from the open pose updated plainly");
    free(a), free(ad), free(b), free(bd);
    /* bad input: refused */
    open[3] = NAN;
    EXPECT(sy_rt_mesh_update_motion(dev, q, open, n) == SY_RT_ERROR_INVALID_ARGUMENT);
    sy_rt_device_destroy(dev);
}

static void test_motion(uint32_t flags)
{
    sy_rt_device *dev = rt_device();
    sy_rt_mesh q = rt_quad(dev, 0.5f);
    sy_rt_material green = rt_emitter(dev, 0.0f, 1.0f, 0.0f);
    float open[16], close[16];
    rt_translation(open, -1.0f, 0.0f, 0.0f);
    rt_translation(close, 1.0f, 0.0f, 0.0f);
    sy_rt_instance inst = rt_place(dev, q, open, green, flags);
    MUST(sy_rt_commit(dev));
    double c;
    int lo, hi;
    double m0 = green_mass(dev, &c, &lo, &hi);
    EXPECT_MSG(fabs(m0 - 64.0) < 1e-3 && fabs(c - 12.0) < 1e-6, "flags %u: sharp: mass %g centred at %g", flags, m0, c);

    /* 2 m = 16 px over the shutter: a streak from column 8 to 31, the same mass, centred at 20 */
    MUST(sy_rt_instance_set_motion(dev, inst, close));
    MUST(sy_rt_commit(dev));
    double m1 = green_mass(dev, &c, &lo, &hi);
    printf("flags %u: motion (top scene): mass %g (sharp %g), centre %g, columns %d..%d\n", flags, m1, m0, c, lo, hi);
    EXPECT_MSG(fabs(m1 - m0) < 0.05 * m0 && fabs(c - 20.0) < 0.5 && lo == 8 && hi == 31,
               "flags %u: motion: mass %g (sharp %g), centre %g, columns %d..%d (want 8..31)", flags, m1, m0, c, lo, hi);

    /* as the mediator gives it: placed at the close, then moved to the open with motion to the close
     * (a move without a rebuild: the twin gets the two time steps) */
    MUST(sy_rt_motion_clear(dev));
    MUST(sy_rt_instance_set_transform(dev, inst, close));
    MUST(sy_rt_commit(dev));
    MUST(sy_rt_instance_set_transform(dev, inst, open));
    MUST(sy_rt_instance_set_motion(dev, inst, close));
    MUST(sy_rt_commit(dev));
    sy_rt_stats st;
    sy_rt_device_stats(dev, &st);
    double m2 = green_mass(dev, &c, &lo, &hi);
    printf("flags %u: motion (%u twins): mass %g, centre %g, columns %d..%d\n", flags, st.moved_instances, m2, c, lo, hi);
    EXPECT_MSG(fabs(m2 - m0) < 0.05 * m0 && fabs(c - 20.0) < 0.5 && lo == 8 && hi == 31,
               "flags %u: motion through a twin: mass %g, centre %g, columns %d..%d", flags, m2, c, lo, hi);

    /* no motion: the sharp image again, bit for bit (no time drawn) */
    MUST(sy_rt_motion_clear(dev));
    MUST(sy_rt_settle(dev));
    MUST(sy_rt_commit(dev));
    int n;
    double cs = render_centroid(dev, &n);
    EXPECT_MSG(n == 64 && fabs(cs - 12.0) < 1e-9, "flags %u: motion cleared: %d px centred at %g (want 64 at 12)", flags, n, cs);

    /* bad input: refused, nothing changed */
    float bad[16];
    memcpy(bad, close, sizeof bad);
    bad[12] = NAN;
    EXPECT(sy_rt_instance_set_motion(dev, inst, bad) == SY_RT_ERROR_INVALID_ARGUMENT);
    EXPECT(sy_rt_instance_set_motion(dev, (sy_rt_instance){0}, close) == SY_RT_ERROR_INVALID_HANDLE);
    EXPECT(sy_rt_instance_set_motion(dev, inst, NULL) == SY_RT_OK);
    EXPECT(sy_rt_instance_set_motion(dev, inst, open) == SY_RT_OK); /* equal to its transform: no motion */
    /* a transform that shrinks by more than SY_RT_INSTANCE_GAIN_MAX allows (1e5 > 1e4): refused, with
     * the reason, for an instance created unbaked (Embree would see its inverse); a baked one takes it */
    float tiny[16];
    memcpy(tiny, open, sizeof tiny);
    tiny[0] = tiny[5] = tiny[10] = 1e-5f;
    bool unbaked = !(flags & SY_RT_INSTANCE_BAKED);
    const char *motion_says = "instance set_motion: the close transform shrinks by";
    const char *move_says = "instance set_transform: the transform shrinks by";
    sy_rt_result rm = sy_rt_instance_set_motion(dev, inst, tiny);
    EXPECT_MSG(unbaked ? rm == SY_RT_ERROR_INVALID_ARGUMENT && strstr(rt_test_msg, motion_says) &&
                             strstr(rt_test_msg, "allows for an instance created unbaked)")
                       : rm == SY_RT_OK,
               "flags %u: set_motion of a 1e-5 scale: %s (%s)", flags, sy_rt_result_str(rm), rt_test_msg);
    sy_rt_result rt = sy_rt_instance_set_transform(dev, inst, tiny);
    EXPECT_MSG(unbaked ? rt == SY_RT_ERROR_INVALID_ARGUMENT && strstr(rt_test_msg, move_says) &&
                             strstr(rt_test_msg, "created unbaked); create it again")
                       : rt == SY_RT_OK,
               "flags %u: set_transform to a 1e-5 scale: %s (%s)", flags, sy_rt_result_str(rt), rt_test_msg);
    if (!unbaked) { /* back to where it was */
        MUST(sy_rt_instance_set_motion(dev, inst, NULL));
        MUST(sy_rt_instance_set_transform(dev, inst, open));
    }
    float got[16];
    MUST(sy_rt_instance_get_transform(dev, inst, got));
    EXPECT(memcmp(got, open, sizeof got) == 0);
    sy_rt_device_destroy(dev);
}

/* Rows of a W x W Whitted render with any green (the emitter): top .. bottom (row 0 the top). */
static void green_rows(sy_rt_device *dev, int *top, int *bottom)
{
    sy_rt_camera cam = rt_camera(5.0f, 0.5f);
    sy_rt_render_desc rd = rt_desc(SY_RT_INTEGRATOR_WHITTED, W, W);
    float *rgba, *depth;
    rt_render(dev, &cam, &rd, &rgba, &depth);
    *top = W, *bottom = -1;
    for (int y = 0; y < W; ++y)
        for (int x = 0; x < W; ++x)
            if (rgba[4 * (y * W + x) + 1] > 0.0f) {
                if (y < *top) *top = y;
                if (y > *bottom) *bottom = y;
            }
    free(rgba);
    free(depth);
}

/* Curved motion (sy_rt_instance_set_motion_steps): an emitter moving from x = -1 up to (0, 1) and down
 * to x = 1 over the shutter (3 steps) streaks along the two legs, 8 rows above its straight path's
 * top (1 m = 8 px), with its mass kept; with the two ends alone it stays in its rows. Bad step counts
 * and transforms are refused, steps all equal to the transform are no motion. */
static void test_motion_steps(uint32_t flags)
{
    sy_rt_device *dev = rt_device();
    sy_rt_mesh q = rt_quad(dev, 0.5f);
    sy_rt_material green = rt_emitter(dev, 0.0f, 1.0f, 0.0f);
    float open[16], later[2][16];
    rt_translation(open, -1.0f, 0.0f, 0.0f);
    rt_translation(later[0], 0.0f, 1.0f, 0.0f);
    rt_translation(later[1], 1.0f, 0.0f, 0.0f);
    sy_rt_instance inst = rt_place(dev, q, open, green, flags);
    MUST(sy_rt_commit(dev));
    int top0, bottom0, top2, bottom2, top3, bottom3;
    green_rows(dev, &top0, &bottom0);
    MUST(sy_rt_instance_set_motion_steps(dev, inst, 2, later[1])); /* = sy_rt_instance_set_motion */
    MUST(sy_rt_commit(dev));
    green_rows(dev, &top2, &bottom2);
    MUST(sy_rt_instance_set_motion_steps(dev, inst, 3, later[0]));
    MUST(sy_rt_commit(dev));
    double c;
    int lo, hi;
    double m3 = green_mass(dev, &c, &lo, &hi);
    green_rows(dev, &top3, &bottom3);
    printf("flags %u: motion steps: rows %d..%d sharp, %d..%d with 2 steps, %d..%d with 3 (mass %g, columns %d..%d)\n",
           flags, top0, bottom0, top2, bottom2, top3, bottom3, m3, lo, hi);
    EXPECT_MSG(top2 == top0 && bottom2 == bottom0, "flags %u: 2 steps: rows %d..%d, not the sharp %d..%d", flags, top2,
               bottom2, top0, bottom0);
    EXPECT_MSG(top3 <= top0 - 7 && top3 >= top0 - 9 && bottom3 == bottom0 && lo == 8 && hi == 31 && fabs(m3 - 64.0) < 0.05 * 64.0,
               "flags %u: 3 steps: rows %d..%d (want %d..%d), columns %d..%d, mass %g", flags, top3, bottom3, top0 - 8,
               bottom0, lo, hi, m3);
    float same[2][16], bad[2][16];
    memcpy(same[0], open, sizeof open), memcpy(same[1], open, sizeof open);
    memcpy(bad, later, sizeof bad);
    bad[0][13] = NAN;
    EXPECT(sy_rt_instance_set_motion_steps(dev, inst, 1, later[0]) == SY_RT_ERROR_INVALID_ARGUMENT);
    EXPECT(sy_rt_instance_set_motion_steps(dev, inst, SY_RT_MOTION_STEPS_MAX + 1, later[0]) == SY_RT_ERROR_INVALID_ARGUMENT);
    EXPECT_MSG(sy_rt_instance_set_motion_steps(dev, inst, 3, bad[0]) == SY_RT_ERROR_INVALID_ARGUMENT &&
                   strstr(rt_test_msg, "step 1"),
               "flags %u: a NaN step: %s", flags, rt_test_msg);
    MUST(sy_rt_instance_set_motion_steps(dev, inst, 3, same[0])); /* every step at its transform: no motion */
    MUST(sy_rt_commit(dev));
    green_rows(dev, &top3, &bottom3);
    EXPECT_MSG(top3 == top0 && bottom3 == bottom0, "flags %u: steps equal to the transform: rows %d..%d", flags, top3, bottom3);
    sy_rt_device_destroy(dev);
}

int main(void)
{
    test_move_hide_destroy(0);
    test_move_hide_destroy(SY_RT_INSTANCE_BAKED);
    test_area_light_follows();
    test_moves_match_rebuild();
    test_motion(0);
    test_motion(SY_RT_INSTANCE_BAKED);
    test_motion_steps(0);
    test_motion_steps(SY_RT_INSTANCE_BAKED);
    test_mesh_motion();
    return sy_check_finish("test_rt_instances");
}
