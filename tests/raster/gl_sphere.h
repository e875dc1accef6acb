/* gl_sphere.h — the GL back-end tests' sphere: radius 1 (times 1 + wave sin(7 theta) cos(5 phi),
 * so that it is not trivially smooth when wave > 0), 2 seg (seg - 1) triangles, outward normals
 * (smooth) or none (faceted), optionally uv and either winding. Include after gl_test.h (MUST). */
#ifndef SY_TEST_GL_SPHERE_H
#define SY_TEST_GL_SPHERE_H

#include "sy_gl.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>

enum {
    GL_SPHERE_NORMALS = 1, /* smooth outward normals (else none: faceted) */
    GL_SPHERE_UV = 2,      /* uv = (longitude, colatitude) / (2 pi, pi): the u tangent is horizontal */
    GL_SPHERE_CCW = 4,     /* wound counter-clockwise seen from outside (by default the other way,
                            * so that its outside shows its back face) */
};

/* The sphere with the GL_SPHERE_* flags; *tris (when not NULL) its triangle count. */
static inline sy_gl_mesh gl_test_sphere_mesh(sy_gl_device *d, uint32_t seg, float wave, unsigned flags, uint32_t *tris)
{
    uint32_t nv = (seg + 1) * (seg + 1), nt = 0;
    float *p = malloc(nv * 3 * sizeof *p), *n = malloc(nv * 3 * sizeof *n), *uv = malloc(nv * 2 * sizeof *uv);
    uint32_t *ix = malloc((size_t)seg * seg * 6 * sizeof *ix);
    if (!p || !n || !uv || !ix) exit(1);
    for (uint32_t i = 0; i <= seg; ++i)
        for (uint32_t j = 0; j <= seg; ++j) {
            float th = 3.14159265f * (float)i / (float)seg, ph = 6.2831853f * (float)j / (float)seg;
            float r = 1.0f + wave * sinf(7.0f * th) * cosf(5.0f * ph);
            float *v = p + 3 * (i * (seg + 1) + j), *nn = n + 3 * (i * (seg + 1) + j);
            nn[0] = sinf(th) * cosf(ph), nn[1] = cosf(th), nn[2] = sinf(th) * sinf(ph);
            v[0] = r * nn[0], v[1] = r * nn[1], v[2] = r * nn[2];
            uv[2 * (i * (seg + 1) + j)] = (float)j / (float)seg, uv[2 * (i * (seg + 1) + j) + 1] = (float)i / (float)seg;
        }
    const bool ccw = flags & GL_SPHERE_CCW;
    for (uint32_t i = 0; i < seg; ++i)
        for (uint32_t j = 0; j < seg; ++j) {
            uint32_t a = i * (seg + 1) + j, b = a + seg + 1, *t;
            if (i > 0) {
                t = ix + 3 * nt++;
                if (ccw) t[0] = a, t[1] = a + 1, t[2] = b;
                else t[0] = a, t[1] = b, t[2] = a + 1;
            }
            if (i + 1 < seg) {
                t = ix + 3 * nt++;
                if (ccw) t[0] = a + 1, t[1] = b + 1, t[2] = b;
                else t[0] = a + 1, t[1] = b, t[2] = b + 1;
            }
        }
    sy_gl_mesh_desc md = {.positions = p, .normals = (flags & GL_SPHERE_NORMALS) ? n : NULL,
                          .uv = {(flags & GL_SPHERE_UV) ? uv : NULL}, .indices = ix, .vertex_count = nv, .triangle_count = nt};
    sy_gl_mesh m;
    MUST(sy_gl_mesh_create(d, &md, &m));
    free(p), free(n), free(uv), free(ix);
    if (tris) *tris = nt;
    return m;
}

/* The default winding, no uv; with normals or without. */
static inline sy_gl_mesh gl_test_sphere(sy_gl_device *d, uint32_t seg, float wave, bool normals, uint32_t *tris)
{
    return gl_test_sphere_mesh(d, seg, wave, normals ? GL_SPHERE_NORMALS : 0u, tris);
}

#endif /* SY_TEST_GL_SPHERE_H */
