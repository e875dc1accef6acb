/** @file
 * sy_demo.h — the project's own demo scene, generated in code (no external data): a floor, a
 * diffuse, a mirror and a glass sphere, a golden box, an emissive ceiling panel (area light), a
 * warm point light, a clear sky as background and environment light, and a camera (`sy demo`,
 * `sy render demo`, and the test suite's scene). Also the sphere it is built from and a benchmark
 * scene of groups of spheres (`sy bench sync`, `sy bench raster`).
 *
 * Ownership: objects are created in the caller's scene (which owns them); nothing is committed.
 * Thread-safety: writes to the scene, so as any scene modification (one thread at a time). */
#ifndef SY_DEMO_H
#define SY_DEMO_H

#include "sy_scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/** What sy_demo_build created. */
typedef struct sy_demo_info {
    sy_node root;             /**< parent of every object of the demo (a root of the scene) */
    sy_node camera;           /**< the camera's node */
    sy_background background; /**< the sky */
} sy_demo_info;

/** Builds the demo scene into s (see the file comment). */
sy_result sy_demo_build(sy_scene *s, sy_demo_info *out, sy_error *err);

/** UV sphere mesh primitive with normals and texcoords: 2*slices*(stacks-1) triangles (slices >= 3,
 * stacks >= 2). */
sy_result sy_demo_sphere(sy_scene *s, float radius, uint32_t slices, uint32_t stacks, sy_material mat, sy_mesh *out,
                         sy_error *err);

/** Benchmark scene: `groups` group nodes under one root, each with `per_group` leaf nodes carrying
 * their own mesh of about `tris` triangles, leaves flagged SY_NODE_ANIMATED. */
sy_result sy_demo_bench_scene(sy_scene *s, uint32_t groups, uint32_t per_group, uint32_t tris, sy_node *root_out,
                              sy_node *first_leaf_out, sy_error *err);

#ifdef __cplusplus
}
#endif
#endif /* SY_DEMO_H */
