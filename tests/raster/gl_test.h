/* gl_test.h — what the GL back-end's tests share: the check kit (tests/support/sy_check.h; the
 * tests use its counted EXPECT form and end with sy_check_finish), the buffer `e` that holds the
 * message of the last failed call (gl_test_on_error, the error callback every test device gets with
 * GL_TEST_REPORT in its desc), MUST (a sy_gl call that must succeed; exit 1 otherwise) and the
 * scene pieces several tests build: a quad from four corners and an instance at the identity. */
#ifndef SY_TEST_GL_TEST_H
#define SY_TEST_GL_TEST_H

#include "../support/sy_check.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sy_gl.h"

static char e[4096];
static inline void gl_test_on_error(void *user, sy_gl_result code, const char *message)
{
    (void)user, (void)code;
    snprintf(e, sizeof e, "%s", message);
}
/* in a sy_gl_device_desc initialiser: report errors into e */
#define GL_TEST_REPORT .error = gl_test_on_error

#define MUST(call)                                                                                 \
    do {                                                                                           \
        sy_gl_result r_ = (call);                                                                  \
        if (r_ != SY_GL_OK) {                                                                      \
            fprintf(stderr, "%s:%d: %s failed (%d): %s\n", __FILE__, __LINE__, #call, (int)r_, e); \
            exit(1);                                                                               \
        }                                                                                          \
    } while (0)

/* A quad of two triangles (0 1 2, 0 2 3) over the corners p4 (4 x xyz), normal n at every corner;
 * uv (4 x uv) or NULL for none. */
static inline sy_gl_mesh gl_test_quad(sy_gl_device *d, const float *p4, const float n[3], const float *uv)
{
    float nrm[12];
    for (int i = 0; i < 4; ++i) memcpy(nrm + 3 * i, n, 3 * sizeof(float));
    static const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
    sy_gl_mesh_desc md = {.positions = p4, .normals = nrm, .uv = {uv, NULL}, .indices = idx, .vertex_count = 4, .triangle_count = 2};
    sy_gl_mesh m;
    MUST(sy_gl_mesh_create(d, &md, &m));
    return m;
}

/* An instance of mesh m with material mat at the identity transform. */
static inline sy_gl_instance gl_test_place(sy_gl_device *d, sy_gl_mesh m, sy_gl_material mat)
{
    sy_gl_instance_desc id = {.mesh = m, .material = mat, .transform = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}};
    sy_gl_instance in;
    MUST(sy_gl_instance_create(d, &id, &in));
    return in;
}

#endif /* SY_TEST_GL_TEST_H */
