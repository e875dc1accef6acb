/* test_math.c — sy_math: TRS composition against hand-computed matrices, inversion, products,
 * point/direction transforms and bounds. */
#include <math.h>
#include <string.h>

#include "../support/sy_check.h"
#include "sy_math.h"

#define EPS 1e-6

static int check_mat(const sy_mat4 *m, const float expect[16], double eps)
{
    for (int i = 0; i < 16; ++i) CHECK_MSG(fabs((double)m->m[i] - (double)expect[i]) <= eps, "element %d: %.9g vs %.9g", i, (double)m->m[i], (double)expect[i]);
    return 0;
}

static int test_identity_and_mul(void)
{
    sy_mat4 id = sy_mat4_identity();
    const float eid[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    CHECK(memcmp(id.m, eid, sizeof eid) == 0);

    /* column-major: a = rows (1 2 3 4 / 5 6 7 8 / 9 10 11 12 / 13 14 15 16) */
    sy_mat4 a = {{1, 5, 9, 13, 2, 6, 10, 14, 3, 7, 11, 15, 4, 8, 12, 16}};
    /* b = rows (2 0 0 1 / 0 1 0 2 / 0 0 3 3 / 0 0 0 1) */
    sy_mat4 b = {{2, 0, 0, 0, 0, 1, 0, 0, 0, 0, 3, 0, 1, 2, 3, 1}};
    sy_mat4 ab = sy_mat4_mul(&a, &b);
    /* a*b by hand, rows: (2 2 9 1+4+9+4=18) (10 6 21 5+12+21+8=46) (18 10 33 9+20+33+12=74)
     * (26 14 45 13+28+45+16=102) */
    const float eab[16] = {2, 10, 18, 26, 2, 6, 10, 14, 9, 21, 33, 45, 18, 46, 74, 102};
    CHECK(check_mat(&ab, eab, 0) == 0);
    sy_mat4 ba = sy_mat4_mul(&b, &a);
    /* b*a rows: (2*r0 + r3) = (15 18 21 24); (r1 + 2 r3) = (31 34 37 40); (3 r2 + 3 r3) = (66 72 78 84); r3 */
    const float eba[16] = {15, 31, 66, 13, 18, 34, 72, 14, 21, 37, 78, 15, 24, 40, 84, 16};
    CHECK(check_mat(&ba, eba, 0) == 0);
    sy_mat4 ia = sy_mat4_mul(&id, &a), ai = sy_mat4_mul(&a, &id);
    CHECK(sy_mat4_equal(&ia, &a) && sy_mat4_equal(&ai, &a));
    return 0;
}

static int test_trs(void)
{
    const float h = (float)(sqrt(0.5));
    {
        /* 90 degrees about +Z: x -> y, y -> -x; scaled (2,3,4), translated (1,2,3) */
        const float t[3] = {1, 2, 3}, q[4] = {0, 0, h, h}, s[3] = {2, 3, 4};
        sy_mat4 m = sy_mat4_from_trs(t, q, s);
        const float e[16] = {0, 2, 0, 0, -3, 0, 0, 0, 0, 0, 4, 0, 1, 2, 3, 1};
        CHECK(check_mat(&m, e, EPS) == 0);
        const float p[3] = {1, 1, 1};
        float o[3];
        sy_mat4_transform_point(&m, p, o);
        CHECK_NEAR(o[0], -2, EPS);
        CHECK_NEAR(o[1], 4, EPS);
        CHECK_NEAR(o[2], 7, EPS);
        sy_mat4_transform_dir(&m, p, o); /* no translation */
        CHECK_NEAR(o[0], -3, EPS);
        CHECK_NEAR(o[1], 2, EPS);
        CHECK_NEAR(o[2], 4, EPS);
    }
    {
        /* 90 degrees about +X: y -> z, z -> -y */
        const float t[3] = {0, 0, 0}, q[4] = {h, 0, 0, h}, s[3] = {1, 1, 1};
        sy_mat4 m = sy_mat4_from_trs(t, q, s);
        const float e[16] = {1, 0, 0, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 0, 0, 1};
        CHECK(check_mat(&m, e, EPS) == 0);
    }
    {
        /* 90 degrees about +Y: z -> x, x -> -z */
        const float t[3] = {0, 0, 0}, q[4] = {0, h, 0, h}, s[3] = {1, 1, 1};
        sy_mat4 m = sy_mat4_from_trs(t, q, s);
        const float e[16] = {0, 0, -1, 0, 0, 1, 0, 0, 1, 0, 0, 0, 0, 0, 0, 1};
        CHECK(check_mat(&m, e, EPS) == 0);
    }
    {
        /* 180 degrees about Y, exact */
        const float t[3] = {5, -6, 7}, q[4] = {0, 1, 0, 0}, s[3] = {1, 2, 1};
        sy_mat4 m = sy_mat4_from_trs(t, q, s);
        const float e[16] = {-1, 0, 0, 0, 0, 2, 0, 0, 0, 0, -1, 0, 5, -6, 7, 1};
        CHECK(check_mat(&m, e, 0) == 0);
    }
    {
        /* identity rotation: T*S exactly; equals mul(T, S) */
        const float t[3] = {1, 2, 3}, q[4] = {0, 0, 0, 1}, s[3] = {4, 5, 6}, one[3] = {1, 1, 1}, zero[3] = {0, 0, 0};
        sy_mat4 m = sy_mat4_from_trs(t, q, s);
        sy_mat4 T = sy_mat4_from_trs(t, q, one), S = sy_mat4_from_trs(zero, q, s);
        sy_mat4 ts = sy_mat4_mul(&T, &S), st = sy_mat4_mul(&S, &T);
        CHECK(sy_mat4_equal(&m, &ts));
        CHECK(!sy_mat4_equal(&m, &st)); /* S*T scales the translation */
        CHECK(st.m[12] == 4 && st.m[13] == 10 && st.m[14] == 18);
    }
    {
        /* composed rotation: TRS(q1) * TRS(q2) == TRS(q1*q2) (30 deg about Z twice = 60 deg) */
        float c = (float)cos(TEST_PI / 12), sn = (float)sin(TEST_PI / 12);
        const float z[3] = {0, 0, 0}, one[3] = {1, 1, 1}, q30[4] = {0, 0, sn, c};
        const float q60[4] = {0, 0, (float)sin(TEST_PI / 6), (float)cos(TEST_PI / 6)};
        sy_mat4 a = sy_mat4_from_trs(z, q30, one), b = sy_mat4_from_trs(z, q60, one);
        sy_mat4 aa = sy_mat4_mul(&a, &a);
        CHECK(check_mat(&aa, b.m, 1e-6) == 0);
        CHECK_NEAR(b.m[0], 0.5, 1e-6);
        CHECK_NEAR(b.m[1], sqrt(3) / 2, 1e-6);
    }
    return 0;
}

static int test_invert(void)
{
    const float t[3] = {1.5f, -2.25f, 3}, s[3] = {2, 0.5f, 3};
    float q[4] = {0.1f, 0.7f, -0.3f, 0.6f};
    float n = sqrtf(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    for (int i = 0; i < 4; ++i) q[i] /= n;
    sy_mat4 m = sy_mat4_from_trs(t, q, s), inv;
    CHECK(sy_mat4_invert(&m, &inv));
    sy_mat4 p1 = sy_mat4_mul(&inv, &m), p2 = sy_mat4_mul(&m, &inv);
    sy_mat4 id = sy_mat4_identity();
    CHECK(check_mat(&p1, id.m, 1e-5) == 0);
    CHECK(check_mat(&p2, id.m, 1e-5) == 0);
    /* a general (non-affine) matrix */
    sy_mat4 g = {{2, 1, 0, 1, 0, 3, 1, 0, 1, 0, 4, 2, 0, 1, 0, 5}};
    CHECK(sy_mat4_invert(&g, &inv));
    p1 = sy_mat4_mul(&inv, &g);
    CHECK(check_mat(&p1, id.m, 1e-5) == 0);
    /* inverse of a pure translation is exactly the negated translation */
    const float q0[4] = {0, 0, 0, 1}, one[3] = {1, 1, 1};
    sy_mat4 tr = sy_mat4_from_trs(t, q0, one);
    CHECK(sy_mat4_invert(&tr, &inv));
    CHECK(inv.m[12] == -1.5f && inv.m[13] == 2.25f && inv.m[14] == -3.0f && inv.m[0] == 1.0f);
    /* singular: false and identity */
    sy_mat4 sing = {{1, 2, 3, 4, 2, 4, 6, 8, 0, 0, 1, 0, 0, 0, 0, 1}};
    inv.m[0] = 42;
    CHECK(!sy_mat4_invert(&sing, &inv));
    CHECK(sy_mat4_equal(&inv, &id));
    sy_mat4 zero = {{0}};
    CHECK(!sy_mat4_invert(&zero, &inv));
    return 0;
}

static int test_finite_equal(void)
{
    sy_mat4 a = sy_mat4_identity(), b = a;
    CHECK(sy_mat4_is_finite(&a));
    CHECK(sy_mat4_equal(&a, &b));
    b.m[7] = NAN;
    CHECK(!sy_mat4_is_finite(&b));
    CHECK(!sy_mat4_equal(&a, &b));
    b.m[7] = 0;
    b.m[12] = INFINITY;
    CHECK(!sy_mat4_is_finite(&b));
    b.m[12] = 1e-30f;
    CHECK(sy_mat4_is_finite(&b) && !sy_mat4_equal(&a, &b));
    return 0;
}

static int test_bounds(void)
{
    sy_bounds e = sy_bounds_empty();
    CHECK(sy_bounds_is_empty(&e));
    sy_mat4 id = sy_mat4_identity();
    sy_bounds et = sy_bounds_transform(&e, &id);
    CHECK(sy_bounds_is_empty(&et));

    sy_bounds b = sy_bounds_empty();
    const float p1[3] = {1, -2, 3}, p2[3] = {-1, 4, 0};
    sy_bounds_add_point(&b, p1);
    CHECK(!sy_bounds_is_empty(&b));
    CHECK(b.min[0] == 1 && b.max[0] == 1 && b.min[1] == -2 && b.max[2] == 3);
    sy_bounds_add_point(&b, p2);
    CHECK(b.min[0] == -1 && b.min[1] == -2 && b.min[2] == 0 && b.max[0] == 1 && b.max[1] == 4 && b.max[2] == 3);
    sy_bounds c = b;
    sy_bounds_add_bounds(&c, &e); /* adding empty changes nothing */
    CHECK(memcmp(&c, &b, sizeof b) == 0);
    sy_bounds far = {{10, 10, 10}, {11, 12, 13}};
    sy_bounds_add_bounds(&c, &far);
    CHECK(c.min[0] == -1 && c.max[0] == 11 && c.max[1] == 12 && c.max[2] == 13 && c.min[2] == 0);

    /* unit cube rotated 45 degrees about Z and translated: x/y extents become sqrt(2) */
    sy_bounds cube = {{-1, -1, -1}, {1, 1, 1}};
    const float t[3] = {10, 0, -5}, s[3] = {1, 1, 2};
    const float q[4] = {0, 0, (float)sin(TEST_PI / 8), (float)cos(TEST_PI / 8)};
    sy_mat4 m = sy_mat4_from_trs(t, q, s);
    sy_bounds r = sy_bounds_transform(&cube, &m);
    CHECK_NEAR(r.min[0], 10 - sqrt(2), 1e-5);
    CHECK_NEAR(r.max[0], 10 + sqrt(2), 1e-5);
    CHECK_NEAR(r.min[1], -sqrt(2), 1e-5);
    CHECK_NEAR(r.max[1], sqrt(2), 1e-5);
    CHECK_NEAR(r.min[2], -7, 1e-6);
    CHECK_NEAR(r.max[2], -3, 1e-6);
    /* a mirroring matrix still gives min <= max */
    sy_mat4 mir = sy_mat4_identity();
    mir.m[0] = -2;
    sy_bounds box = {{1, 0, 0}, {3, 1, 1}};
    sy_bounds rm = sy_bounds_transform(&box, &mir);
    CHECK(rm.min[0] == -6 && rm.max[0] == -2 && rm.min[1] == 0 && rm.max[1] == 1);
    return 0;
}

/* sy_mat4_look_at: an orthonormal basis looking down -z at the target, and the refusals */
static int test_look_at(void)
{
    sy_mat4 m;
    float eye[3] = {0.5f, 0.5f, 3}, tgt[3] = {0.5f, 0.5f, 0}, up[3] = {0, 1, 0};
    CHECK(sy_mat4_look_at(eye, tgt, up, &m));
    sy_mat4 want = {{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0.5f, 0.5f, 3, 1}};
    CHECK(sy_mat4_equal(&m, &want));
    float e2[3] = {3, 4, 0}, t2[3] = {0, 0, 0}, u2[3] = {0, 0, 2};
    CHECK(sy_mat4_look_at(e2, t2, u2, &m));
    float fwd[3] = {-m.m[8], -m.m[9], -m.m[10]};
    CHECK(fabsf(fwd[0] + 0.6f) < 1e-6f && fabsf(fwd[1] + 0.8f) < 1e-6f && fabsf(fwd[2]) < 1e-6f); /* towards the target */
    CHECK(fabsf(m.m[6] - 1.0f) < 1e-6f); /* the image's up is +z */
    CHECK(fabsf(sy_vec3_dot(&m.m[0], &m.m[4])) < 1e-6f && fabsf(sy_vec3_dot(&m.m[0], &m.m[8])) < 1e-6f);
    sy_mat4 keep = m;
    CHECK(!sy_mat4_look_at(e2, e2, up, &m));                 /* eye == target */
    float upx[3] = {3, 4, 0}, zero[3] = {0, 0, 0}, nan3[3] = {NAN, 0, 0};
    CHECK(!sy_mat4_look_at(e2, t2, upx, &m));                /* up along the view */
    CHECK(!sy_mat4_look_at(e2, t2, zero, &m));               /* no up */
    CHECK(!sy_mat4_look_at(nan3, t2, up, &m));               /* not finite */
    CHECK(sy_mat4_equal(&m, &keep));                         /* untouched after a refusal */
    return 0;
}

SY_CHECK_MAIN("test_math", SY_TEST(test_look_at), SY_TEST(test_identity_and_mul), SY_TEST(test_trs),
              SY_TEST(test_invert), SY_TEST(test_finite_equal), SY_TEST(test_bounds))
