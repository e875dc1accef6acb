/* sy_demo.h — the project's own demo scene, generated in code (no external data): a floor, a
 * diffuse, a mirror and a glass sphere, a golden box, an emissive ceiling panel (area light), a
 * warm point light, a sky-blue background and a camera. Also generators for benchmark scenes.
 * Ownership: objects are created in the caller's scene. Thread-safety: as the scene. */
#ifndef SY_DEMO_H
#define SY_DEMO_H

#include "sy_scene.h"

typedef struct sy_demo_info {
    sy_node root;
    sy_node camera;
    sy_background background;
} sy_demo_info;

sy_result sy_demo_build(sy_scene *s, sy_demo_info *out, sy_error *err);

/* UV sphere mesh primitive with normals and texcoords: 2*slices*(stacks-1) triangles. */
sy_result sy_demo_sphere(sy_scene *s, float radius, uint32_t slices, uint32_t stacks, sy_material mat, sy_mesh *out,
                         sy_error *err);

/* Benchmark scene: `groups` group nodes under one root, each with `per_group` leaf nodes carrying
 * their own mesh of about `tris` triangles, leaves flagged SY_NODE_ANIMATED. */
sy_result sy_demo_bench_scene(sy_scene *s, uint32_t groups, uint32_t per_group, uint32_t tris, sy_node *root_out,
                              sy_node *first_leaf_out, sy_error *err);

#endif /* SY_DEMO_H */
