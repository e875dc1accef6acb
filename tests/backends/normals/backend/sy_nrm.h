/* sy_nrm.h — a tiny "normals" back-end (issue 16: a back-end added through its own folders and one
 * line of the build): Embree ray casting that shades each pixel with the world-space geometric
 * normal of the nearest surface, (n + 1) / 2 as RGB. Its own small API, like a third-party
 * renderer: triangle meshes, instances with a column-major 4x4 world matrix, one camera window.
 * No core header is included here.
 * Ownership: the device owns meshes and instances (released by handle or with the device).
 * Thread-safety: a device is used from one thread at a time. */
#ifndef SY_NRM_H
#define SY_NRM_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

typedef struct sy_nrm_device sy_nrm_device;

/* 0 on success; otherwise -1 with a message in err. */
int sy_nrm_device_create(sy_nrm_device **out, char *err, size_t err_len);
void sy_nrm_device_destroy(sy_nrm_device *d); /* NULL-safe */

/* A mesh of ntris triangles (indices into nverts xyz positions; copied). Returns a handle > 0, or 0
 * with a message in err (an index out of range, Embree failed). */
uint32_t sy_nrm_mesh_create(sy_nrm_device *d, const float *xyz, uint32_t nverts, const uint32_t *idx, uint32_t ntris,
                            char *err, size_t err_len);
void sy_nrm_mesh_release(sy_nrm_device *d, uint32_t mesh);

/* handle 0: creates an instance of mesh; otherwise updates that instance's matrix and visibility.
 * Returns the handle (0 with a message in err on failure). */
uint32_t sy_nrm_instance_set(sy_nrm_device *d, uint32_t handle, uint32_t mesh, const float world[16], bool visible,
                             char *err, size_t err_len);
void sy_nrm_instance_release(sy_nrm_device *d, uint32_t instance);

typedef struct sy_nrm_view {
    float camera_to_world[16]; /* column-major; the camera looks down its -Z, +Y up */
    bool orthographic;
    float window[4];           /* image-plane window {left, right, bottom, top} (tangents / camera units) */
    uint32_t full_width, full_height;
    uint32_t rect_x, rect_y, rect_w, rect_h; /* the rectangle to fill, row 0 = top */
} sy_nrm_view;

/* Fills rgba (rect_w*rect_h*4, premultiplied, alpha 1 where hit) and depth (distance along the view
 * axis, +INFINITY where nothing is hit). 0 on success. */
int sy_nrm_render(sy_nrm_device *d, const sy_nrm_view *v, float *rgba, float *depth, char *err, size_t err_len);

#endif /* SY_NRM_H */
