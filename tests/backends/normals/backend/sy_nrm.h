/* sy_nrm.h — a tiny "normals" back-end (issue 16: a back-end added through its own folders and one
 * line of the build): Embree ray casting that shades each pixel with the world-space geometric
 * normal of the nearest surface, (n + 1) / 2 as RGB. Its own small API, like a third-party
 * renderer: triangle meshes, instances with a column-major 4x4 world matrix, one camera window.
 * No core header is included here.
 * Errors (the convention of every Switchyard back-end): result codes numbered like Switchyard's
 * sy_result; the message of a failure goes once to the error callback of the device's desc, on the
 * calling thread before the call returns.
 * Ownership: the device owns meshes and instances (released by handle or with the device).
 * Thread-safety: a device is used from one thread at a time. */
#ifndef SY_NRM_H
#define SY_NRM_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

typedef struct sy_nrm_device sy_nrm_device;

/* Result codes (the numbers of sy_result). */
typedef enum sy_nrm_result {
    SY_NRM_OK = 0,
    SY_NRM_ERROR_INVALID_ARGUMENT = 1,
    SY_NRM_ERROR_OUT_OF_MEMORY = 3,
    SY_NRM_ERROR_EMBREE = 9
} sy_nrm_result;

/* Receives the code and message of a failed call (message valid during the call only). */
typedef void (*sy_nrm_error_fn)(void *user, sy_nrm_result code, const char *message);

typedef struct sy_nrm_device_desc {
    sy_nrm_error_fn error; /* NULL = none */
    void *error_user;
} sy_nrm_device_desc;

/* SY_NRM_OK, or the code of the failure (reported to desc->error). desc may be NULL. */
sy_nrm_result sy_nrm_device_create(const sy_nrm_device_desc *desc, sy_nrm_device **out);
void sy_nrm_device_destroy(sy_nrm_device *d); /* NULL-safe */

/* A mesh of ntris triangles (indices into nverts xyz positions; copied). Returns a handle > 0, or 0
 * after reporting the failure (an index out of range, Embree failed). */
uint32_t sy_nrm_mesh_create(sy_nrm_device *d, const float *xyz, uint32_t nverts, const uint32_t *idx, uint32_t ntris);
void sy_nrm_mesh_release(sy_nrm_device *d, uint32_t mesh);

/* handle 0: creates an instance of mesh; otherwise updates that instance's matrix and visibility.
 * Returns the handle (0 after reporting a failure). */
uint32_t sy_nrm_instance_set(sy_nrm_device *d, uint32_t handle, uint32_t mesh, const float world[16], bool visible);
void sy_nrm_instance_release(sy_nrm_device *d, uint32_t instance);

typedef struct sy_nrm_view {
    float camera_to_world[16]; /* column-major; the camera looks down its -Z, +Y up */
    bool orthographic;
    float window[4];           /* image-plane window {left, right, bottom, top} (tangents / camera units) */
    uint32_t full_width, full_height;
    uint32_t rect_x, rect_y, rect_w, rect_h; /* the rectangle to fill, row 0 = top */
} sy_nrm_view;

/* Fills rgba (rect_w*rect_h*4, premultiplied, alpha 1 where hit) and depth (distance along the view
 * axis, +INFINITY where nothing is hit). SY_NRM_OK on success. */
sy_nrm_result sy_nrm_render(sy_nrm_device *d, const sy_nrm_view *v, float *rgba, float *depth);

#endif /* SY_NRM_H */
