/* test_orbit.c — the orbit camera (core/sy_orbit.h): matrix for hand-checked poses, the round trip
 * matrix -> orbit -> matrix, drag / pan / zoom rules and their limits; saved views
 * (core/sy_bookmarks.h): orbit -> bookmark -> orbit, the file written and read back, bad files
 * refused naming the line; measurement (sy_pick_distance, sy_plane_distance). */
#include "../support/sy_check.h"
#include "sy_bookmarks.h"
#include "sy_orbit.h"
#include "sy_viewport.h"

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

static int mat_near(const sy_mat4 *a, const sy_mat4 *b, float eps)
{
    for (int i = 0; i < 16; ++i)
        if (fabsf(a->m[i] - b->m[i]) > eps) return 0;
    return 1;
}

static int test_matrix(void)
{
    /* yaw 0, pitch 0: from +Z, 5 away from (1,2,3): the identity rotation at (1,2,8) */
    sy_orbit o = {{1, 2, 3}, 0, 0, 5};
    sy_mat4 m;
    sy_orbit_matrix(&o, &m);
    sy_mat4 want = sy_mat4_identity();
    want.m[12] = 1, want.m[13] = 2, want.m[14] = 8;
    CHECK(mat_near(&m, &want, 1e-6f));
    /* yaw 90 degrees: from +X, looking down -X; the camera's +X is world -Z */
    o.yaw = (float)(TEST_PI / 2);
    sy_orbit_matrix(&o, &m);
    CHECK_NEAR(m.m[12], 6, 1e-5);
    CHECK_NEAR(m.m[14], 3, 1e-5);
    CHECK_NEAR(m.m[8], 1, 1e-6); /* back = +X */
    CHECK_NEAR(m.m[2], -1, 1e-6); /* right = -Z */
    CHECK_NEAR(m.m[5], 1, 1e-6); /* up = +Y */
    /* straight down (pitch 90 degrees): still orthonormal, no NaN */
    o.pitch = (float)(TEST_PI / 2);
    sy_orbit_matrix(&o, &m);
    CHECK(sy_mat4_is_finite(&m));
    CHECK_NEAR(m.m[9], 1, 1e-6);
    return 0;
}

static int test_round_trip(void)
{
    sy_bounds b = {{-1, -1, -1}, {1, 1, 1}};
    sy_orbit o = {{0.5f, -0.25f, 0.1f}, 0.7f, -0.4f, 3.0f}, back;
    sy_mat4 m, m2;
    sy_orbit_matrix(&o, &m);
    sy_orbit_from_matrix(&m, &b, &back);
    sy_orbit_matrix(&back, &m2);
    CHECK(mat_near(&m, &m2, 1e-5f)); /* same position and axes */
    CHECK_NEAR(back.yaw, 0.7, 1e-5);
    CHECK_NEAR(back.pitch, -0.4, 1e-5);
    /* the target lies where the box centre projects onto the viewing axis */
    float c[3] = {0, 0, 0}, d = 0;
    for (int i = 0; i < 3; ++i) d += (back.target[i] - c[i]) * m.m[8 + i];
    CHECK_NEAR(d, 0, 1e-4);
    /* an empty box or one behind the camera: distance 1 */
    sy_bounds empty = {{1, 1, 1}, {-1, -1, -1}};
    sy_orbit_from_matrix(&m, &empty, &back);
    CHECK_NEAR(back.dist, 1, 1e-6);
    sy_orbit_from_matrix(&m, NULL, &back);
    CHECK_NEAR(back.dist, 1, 1e-6);
    return 0;
}

static int test_input(void)
{
    sy_orbit o = {{0, 0, 0}, 0, 0, 2};
    sy_orbit_rotate(&o, 100, 0); /* drag right: yaw decreases */
    CHECK_NEAR(o.yaw, -0.8, 1e-5);
    sy_orbit_rotate(&o, 0, 1000); /* pitch clamped */
    CHECK_NEAR(o.pitch, 1.55, 1e-6);
    sy_orbit_rotate(&o, 0, -100000);
    CHECK_NEAR(o.pitch, -1.55, 1e-6);
    sy_orbit_rotate(&o, NAN, 1); /* ignored */
    CHECK(isfinite(o.yaw) && o.pitch == -1.55f);
    sy_orbit_zoom(&o, 1);
    CHECK_NEAR(o.dist, 1.8, 1e-5);
    sy_orbit_zoom(&o, INFINITY);
    CHECK_NEAR(o.dist, 1.8, 1e-5);
    for (int i = 0; i < 100; ++i) sy_orbit_zoom(&o, 50);
    CHECK_NEAR(o.dist, 1e-3, 1e-9);
    sy_orbit p = {{0, 0, 0}, 0, 0, 1000};
    sy_orbit_pan(&p, 10, 0); /* drag right: the target moves to the camera's left (-X) */
    CHECK_NEAR(p.target[0], -15, 1e-3);
    CHECK_NEAR(p.target[1], 0, 1e-6);
    return 0;
}

static int test_bookmarks(void)
{
    const sy_orbit o = {{0.5f, -1, 2}, 0.7f, -0.4f, 3.5f};
    sy_bookmark b = sy_bookmark_of_orbit(&o);
    sy_orbit back = sy_orbit_of_bookmark(&b);
    sy_mat4 m0, m1, m2;
    sy_orbit_matrix(&o, &m0);
    sy_orbit_matrix(&back, &m1);
    CHECK(mat_near(&m0, &m1, 1e-5f));
    CHECK(sy_bookmark_matrix(&b, &m2) && mat_near(&m0, &m2, 1e-5f)); /* the look-at of the view is the orbit's */
    char path[64];
    snprintf(path, sizeof path, "/tmp/sy_test_bookmarks_%d", (int)getpid());
    sy_bookmark slots[SY_BOOKMARKS_MAX + 1], got[SY_BOOKMARKS_MAX + 1];
    memset(slots, 0, sizeof slots);
    slots[2] = b, slots[9] = b;
    slots[9].up[0] = 0.25f;
    slots[9].fov = 0.5f; /* radians; slot 2 keeps none (the camera's own) */
    sy_error e = {0};
    CHECK(sy_bookmarks_save(path, slots, &e) == SY_OK);
    CHECK(sy_bookmarks_load(path, got, &e) == SY_OK);
    CHECK(!got[1].set && got[2].set && got[9].set && !got[5].set);
    for (int k = 0; k < 3; ++k) {
        CHECK_NEAR(got[9].eye[k], b.eye[k], 1e-6);
        CHECK_NEAR(got[2].target[k], b.target[k], 1e-6);
    }
    CHECK_NEAR(got[9].up[0], 0.25, 1e-7);
    CHECK_NEAR(got[9].fov, 0.5, 1e-6);
    CHECK(got[2].fov == 0.0f);
    /* a file of before the field of view (nine numbers a line) loads, its views without one */
    FILE *old = fopen(path, "w");
    CHECK(old != NULL);
    if (old) {
        fputs("# sy bookmarks: N eye(x y z) target(x y z) up(x y z)\n3 0 0 5 0 0 0 0 1 0\n", old);
        fclose(old);
    }
    CHECK(sy_bookmarks_load(path, got, &e) == SY_OK && got[3].set && got[3].fov == 0.0f && got[3].eye[2] == 5.0f);
    /* 60 degrees read as radians */
    old = fopen(path, "w");
    CHECK(old != NULL);
    if (old) {
        fputs("4 0 0 5 0 0 0 0 1 0 60\n", old);
        fclose(old);
    }
    CHECK(sy_bookmarks_load(path, got, &e) == SY_OK && got[4].set);
    CHECK_NEAR(got[4].fov, 1.0471976, 1e-6);
    sy_bookmark nofov = got[4];
    nofov.fov = 3.2f;
    CHECK(sy_bookmark_check(&nofov, NULL) == SY_ERR_INVALID_ARGUMENT);
    static const struct { const char *text, *want; } bad[] = {
        {"1 0 0 5 0 0 0 0 1\n", ":1: expected"},               /* eight numbers */
        {"# c\n\n10 0 0 5 0 0 0 0 1 0\n", ":3: slot 10"},     /* slot out of range */
        {"1 0 0 5 0 0 0 0 1 0 7 8\n", ":1: expected"},         /* one too many */
        {"1 0 0 5 0 0 0 0 1 0 180\n", "field of view 180"},    /* the field of view: (0, 180) degrees */
        {"1 0 0 5 0 0 0 0 1 0 0\n", "field of view 0"},
        {"1 0 0 5 0 0 0 0 1 0 nan\n", "field of view nan"},
        {"1 0 0 5 0 0 0 0 0 0\n", "up is zero"},               /* zero up */
        {"1 0 0 nan 0 0 0 0 1 0\n", "not finite"},             /* NaN */
        {"1 0 0 5 0 0 0 0 1 0\n2 x\n", ":2: expected"},       /* the second line */
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        FILE *f = fopen(path, "w");
        CHECK(f != NULL);
        if (!f) break;
        fputs(bad[i].text, f);
        fclose(f);
        got[2].set = true;
        sy_result r = sy_bookmarks_load(path, got, &e);
        if (!(r == SY_ERR_PARSE && strstr(e.message, bad[i].want))) fprintf(stderr, "  bad file %zu: %s\n", i, e.message);
        CHECK(r == SY_ERR_PARSE && strstr(e.message, bad[i].want) != NULL && !got[2].set);
    }
    remove(path);
    CHECK(sy_bookmarks_load(path, got, &e) == SY_ERR_NOT_FOUND);
    return 0;
}

static int test_measure(void)
{
    sy_pick_result a = {.hit = true, .position = {1, 2, 3}}, b = {.hit = true, .position = {4, 6, 3}}, miss = {0};
    double d = -1;
    sy_error e = {0};
    CHECK(sy_pick_distance(&a, &b, &d, &e) == SY_OK);
    CHECK_NEAR(d, 5, 1e-12);
    CHECK(sy_pick_distance(&a, &miss, &d, &e) == SY_ERR_INVALID_ARGUMENT && strstr(e.message, "second pick hit nothing"));
    const float plane[4] = {0, 2, 0, -2}; /* y = 1, not unit */
    CHECK(sy_plane_distance(plane, a.position, &d, &e) == SY_OK);
    CHECK_NEAR(d, 1, 1e-12);
    const float zero[4] = {0, 0, 0, 1}, nan_plane[4] = {NAN, 1, 0, 0}, far[3] = {INFINITY, 0, 0};
    CHECK(sy_plane_distance(zero, a.position, &d, &e) == SY_ERR_INVALID_ARGUMENT && strstr(e.message, "normal"));
    CHECK(sy_plane_distance(nan_plane, a.position, &d, &e) == SY_ERR_INVALID_ARGUMENT && strstr(e.message, "not finite"));
    CHECK(sy_plane_distance(plane, far, &d, &e) == SY_ERR_INVALID_ARGUMENT && strstr(e.message, "point"));
    return 0;
}

SY_CHECK_MAIN("test_orbit", SY_TEST(test_matrix), SY_TEST(test_round_trip), SY_TEST(test_input), SY_TEST(test_bookmarks),
              SY_TEST(test_measure))
