/* gl_sphere.h — the GL back-end tests' sphere: radius 1 (times 1 + wave sin(7 theta) cos(5 phi),
 * so that it is not trivially smooth when wave > 0), 2 seg (seg - 1) triangles, outward normals
 * (smooth) or none (faceted). Include after gl_test.h (MUST) with a char buffer `e` in scope. */
#ifndef SY_TEST_GL_SPHERE_H
#define SY_TEST_GL_SPHERE_H

#include "sy_gl.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>

static sy_gl_mesh gl_test_sphere(sy_gl_device *d, uint32_t seg, float wave, bool normals, uint32_t *tris)
{
    uint32_t nv = (seg + 1) * (seg + 1), nt = 0;
    float *p = malloc(nv * 3 * sizeof *p), *n = malloc(nv * 3 * sizeof *n);
    uint32_t *ix = malloc((size_t)seg * seg * 6 * sizeof *ix);
    if (!p || !n || !ix) exit(1);
    for (uint32_t i = 0; i <= seg; ++i)
        for (uint32_t j = 0; j <= seg; ++j) {
            float th = 3.14159265f * (float)i / (float)seg, ph = 6.2831853f * (float)j / (float)seg;
            float r = 1.0f + wave * sinf(7.0f * th) * cosf(5.0f * ph);
            float *v = p + 3 * (i * (seg + 1) + j), *nn = n + 3 * (i * (seg + 1) + j);
            nn[0] = sinf(th) * cosf(ph), nn[1] = cosf(th), nn[2] = sinf(th) * sinf(ph);
            v[0] = r * nn[0], v[1] = r * nn[1], v[2] = r * nn[2];
        }
    for (uint32_t i = 0; i < seg; ++i)
        for (uint32_t j = 0; j < seg; ++j) {
            uint32_t a = i * (seg + 1) + j, b = a + seg + 1;
            if (i > 0) ix[3 * nt] = a, ix[3 * nt + 1] = b, ix[3 * nt + 2] = a + 1, nt++;
            if (i + 1 < seg) ix[3 * nt] = a + 1, ix[3 * nt + 1] = b, ix[3 * nt + 2] = b + 1, nt++;
        }
    sy_gl_mesh_desc md = {.positions = p, .normals = normals ? n : NULL, .indices = ix, .vertex_count = nv,
                          .triangle_count = nt};
    sy_gl_mesh m;
    MUST(sy_gl_mesh_create(d, &md, &m));
    free(p), free(n), free(ix);
    if (tris) *tris = nt;
    return m;
}

#endif /* SY_TEST_GL_SPHERE_H */
