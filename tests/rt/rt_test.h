/* rt_test.h — helpers shared by the backends/rt tests: the check kit (tests/support/sy_check.h;
 * the tests use its counted EXPECT form and end with sy_check_finish), MUST, and small builders
 * for quads, UV spheres, materials, instances, transforms, cameras and renders using only the
 * public sy_rt API. */
#ifndef RT_TEST_H
#define RT_TEST_H

#include "../support/sy_check.h"
#include "sy_rt.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define RT_SKIP 77
#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* The message of the last failure any test device reported (rt_test_on_error, the error callback
 * of every device the tests create: rt_device and rt_test_device_desc). Test programs are
 * single-threaded outside sy_rt_render. */
static char rt_test_msg[512];
static inline void rt_test_on_error(void *user, sy_rt_result code, const char *message)
{
    (void)user, (void)code;
    snprintf(rt_test_msg, sizeof rt_test_msg, "%s", message);
}
static inline sy_rt_device_desc rt_test_device_desc(void)
{
    sy_rt_device_desc dd = {.error = rt_test_on_error};
    return dd;
}

/* A call that must succeed; aborts the test (returns 1 from main's helper chain) otherwise. */
#define MUST(call)                                                                                 \
    do {                                                                                           \
        sy_rt_result must_r_ = (call);                                                             \
        if (must_r_ != SY_RT_OK) {                                                                 \
            fprintf(stderr, "%s:%d: %s failed: %s: %s\n", __FILE__, __LINE__, #call,             \
                    sy_rt_result_str(must_r_), rt_test_msg);                                       \
            exit(1);                                                                               \
        }                                                                                          \
    } while (0)

static inline bool rt_near(double a, double b, double rel)
{
    return fabs(a - b) <= rel * fmax(fabs(a), fabs(b)) + 1e-12;
}

static inline void rt_identity(float m[16])
{
    memset(m, 0, 16 * sizeof(float));
    m[0] = m[5] = m[10] = m[15] = 1.0f;
}

static inline void rt_translation(float m[16], float x, float y, float z)
{
    rt_identity(m);
    m[12] = x;
    m[13] = y;
    m[14] = z;
}

/* Rotation by angle (radians) about the Y axis, then translation. */
static inline void rt_rot_y(float m[16], float angle, float tx, float ty, float tz)
{
    rt_identity(m);
    m[0] = cosf(angle);
    m[2] = -sinf(angle);
    m[8] = sinf(angle);
    m[10] = cosf(angle);
    m[12] = tx;
    m[13] = ty;
    m[14] = tz;
}

/* A quad [-h, h]^2 in the XY plane at z = 0, facing +Z (counter-clockwise), with normals and uv
 * (uv (0,0) at the top-left corner (-h, +h)). */
static inline sy_rt_mesh rt_quad(sy_rt_device *dev, float h)
{
    const float pos[] = {-h, -h, 0, h, -h, 0, h, h, 0, -h, h, 0};
    const float nrm[] = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
    const float uv[] = {0, 1, 1, 1, 1, 0, 0, 0};
    const uint32_t idx[] = {0, 1, 2, 0, 2, 3};
    sy_rt_mesh_desc d = {.positions = pos, .normals = nrm, .uv = {uv, NULL}, .indices = idx,
                         .vertex_count = 4, .triangle_count = 2};
    sy_rt_mesh m;
    MUST(sy_rt_mesh_create(dev, &d, &m));
    return m;
}

/* An instance of mesh with material mat; xf is its object-to-world matrix, NULL for the identity. */
static inline sy_rt_instance rt_place(sy_rt_device *dev, sy_rt_mesh mesh, const float xf[16], sy_rt_material mat,
                                      uint32_t flags)
{
    sy_rt_instance_desc d = {.mesh = mesh, .material = mat, .flags = flags};
    if (xf)
        memcpy(d.transform, xf, sizeof d.transform);
    else
        rt_identity(d.transform);
    sy_rt_instance inst;
    MUST(sy_rt_instance_create(dev, &d, &inst));
    return inst;
}

/* A mesh of positions and indices only, from arrays the caller malloc'd; frees both. */
static inline sy_rt_mesh rt_mesh_take(sy_rt_device *dev, float *pos, uint32_t *idx, uint32_t nv, uint32_t nt)
{
    sy_rt_mesh_desc d = {.positions = pos, .indices = idx, .vertex_count = nv, .triangle_count = nt};
    sy_rt_mesh m;
    MUST(sy_rt_mesh_create(dev, &d, &m));
    free(pos);
    free(idx);
    return m;
}

/* A UV sphere of radius r at the origin: (n + 1)^2 vertices, 2 n^2 triangles; with vertex normals
 * (the unit directions) when normals is true. */
static inline sy_rt_mesh rt_uv_sphere(sy_rt_device *dev, float r, uint32_t n, bool normals)
{
    uint32_t nv = (n + 1) * (n + 1), nt = 2 * n * n, t = 0;
    float *pos = malloc(3 * sizeof(float) * nv), *nrm = malloc(3 * sizeof(float) * nv);
    uint32_t *idx = malloc(3 * sizeof(uint32_t) * nt);
    if (!pos || !nrm || !idx) exit(1);
    for (uint32_t i = 0, k = 0; i <= n; ++i)
        for (uint32_t j = 0; j <= n; ++j, ++k) {
            double th = M_PI * i / n, ph = 2 * M_PI * j / n;
            float *q = nrm + 3 * k;
            q[0] = (float)(sin(th) * cos(ph)), q[1] = (float)cos(th), q[2] = (float)(sin(th) * sin(ph));
            for (int c = 0; c < 3; ++c) pos[3 * k + c] = r * q[c];
        }
    for (uint32_t i = 0; i < n; ++i)
        for (uint32_t j = 0; j < n; ++j) {
            uint32_t a = i * (n + 1) + j, b = a + 1, c = a + n + 1, d = c + 1;
            idx[t++] = a, idx[t++] = c, idx[t++] = b;
            idx[t++] = b, idx[t++] = c, idx[t++] = d;
        }
    sy_rt_mesh_desc md = {.positions = pos, .normals = normals ? nrm : NULL, .indices = idx, .vertex_count = nv,
                          .triangle_count = nt};
    sy_rt_mesh m;
    MUST(sy_rt_mesh_create(dev, &md, &m));
    free(pos);
    free(nrm);
    free(idx);
    return m;
}

/* The material of d (which must be valid). */
static inline sy_rt_material rt_material(sy_rt_device *dev, const sy_rt_material_desc *d)
{
    sy_rt_material m;
    MUST(sy_rt_material_create(dev, d, &m));
    return m;
}

static inline void rt_set3(float v[3], float x, float y, float z)
{
    v[0] = x, v[1] = y, v[2] = z;
}

static inline sy_rt_material rt_emitter(sy_rt_device *dev, float r, float g, float b)
{
    sy_rt_material_desc d;
    sy_rt_material_desc_init(&d);
    rt_set3(d.emissive, r, g, b);
    return rt_material(dev, &d);
}

/* Pure Lambert material (no specular lobe). */
static inline sy_rt_material rt_lambert(sy_rt_device *dev, float r, float g, float b)
{
    sy_rt_material_desc d;
    sy_rt_material_desc_init(&d);
    rt_set3(d.base_color, r, g, b);
    d.metallic = 0.0f;
    d.specular = 0.0f;
    return rt_material(dev, &d);
}

/* A metal (metallic 1) of base colour (r, g, b) and the given roughness. */
static inline sy_rt_material rt_metal(sy_rt_device *dev, float r, float g, float b, float roughness)
{
    sy_rt_material_desc d;
    sy_rt_material_desc_init(&d);
    rt_set3(d.base_color, r, g, b);
    d.metallic = 1.0f;
    d.roughness = roughness;
    return rt_material(dev, &d);
}

/* Perspective camera at (0, 0, z) looking down -Z with a symmetric window of half-tangent t. */
static inline sy_rt_camera rt_camera(float z, float t)
{
    sy_rt_camera c;
    memset(&c, 0, sizeof c);
    rt_translation(c.camera_to_world, 0.0f, 0.0f, z);
    c.projection = SY_RT_PROJECTION_PERSPECTIVE;
    c.window[0] = -t;
    c.window[1] = t;
    c.window[2] = -t;
    c.window[3] = t;
    c.near_clip = 0.01f;
    return c;
}

static inline sy_rt_render_desc rt_desc(sy_rt_integrator integ, uint32_t w, uint32_t h)
{
    sy_rt_render_desc d = {.integrator = integ, .image_width = w, .image_height = h, .width = w, .height = h};
    return d;
}

/* Renders the desc's rectangle into freshly allocated buffers (the caller frees both: rt_image_free). */
static inline void rt_render(sy_rt_device *dev, const sy_rt_camera *cam, const sy_rt_render_desc *d, float **rgba,
                             float **depth)
{
    size_t n = (size_t)d->width * d->height;
    *rgba = malloc(n * 4 * sizeof(float));
    *depth = malloc(n * sizeof(float));
    if (!*rgba || !*depth) {
        fprintf(stderr, "out of memory\n");
        exit(1);
    }
    MUST(sy_rt_render(dev, cam, d, *rgba, *depth));
}

/* Frees rt_render's buffers. */
static inline void rt_image_free(float *rgba, float *depth)
{
    free(rgba);
    free(depth);
}

/* Irradiance at a floor point (normal +Z) from a Lambertian square of radiance le, half-size s,
 * parallel to the floor at height h and facing it, its centre d away along X: the integral of
 * le cos cos / r^2 = le h^2 / r^4 over the square, midpoint rule on 200 x 200 cells. */
static inline double rt_square_irradiance_at(double le, double s, double h, double d)
{
    const int n = 200;
    const double cell = 2.0 * s / n;
    double e = 0.0;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            double x = -s + (i + 0.5) * cell, y = -s + (j + 0.5) * cell, r2 = (d - x) * (d - x) + y * y + h * h;
            e += le * h * h / (r2 * r2) * cell * cell;
        }
    return e;
}

static inline sy_rt_device *rt_device(void)
{
    sy_rt_device *dev = NULL;
    sy_rt_device_desc dd = rt_test_device_desc();
    MUST(sy_rt_device_create(&dd, &dev));
    return dev;
}

/* The grazing-emitter scene of rt_whitted and rt_pathtracer: a Lambertian floor (albedo 0.8, z = 0,
 * half-size 20) and a small emitter (half-size 0.1, radiance 100) at height 1 facing down, seen
 * from the floor point (8, 0, 0) at cos 0.12, where the floor's normal faces away from the
 * emitter's. Commits; returns a camera at height 0.5 looking down at that point (half-tangent
 * 0.02) and in *expect the radiance there: albedo / pi x rt_square_irradiance_at. */
static inline sy_rt_camera rt_grazing_emitter_scene(sy_rt_device *dev, double *expect)
{
    const float albedo = 0.8f, le = 100.0f, s = 0.1f, d = 8.0f;
    float xf[16], em[16];
    rt_identity(xf);
    rt_place(dev, rt_quad(dev, 20.0f), xf, rt_lambert(dev, albedo, albedo, albedo), 0);
    rt_rot_y(em, (float)M_PI, 0.0f, 0.0f, 1.0f);
    rt_place(dev, rt_quad(dev, s), em, rt_emitter(dev, le, le, le), 0);
    MUST(sy_rt_commit(dev));
    sy_rt_camera cam = rt_camera(0.5f, 0.02f);
    cam.camera_to_world[12] = d;
    *expect = albedo / M_PI * rt_square_irradiance_at(le, s, 1.0, d);
    return cam;
}

#endif /* RT_TEST_H */
