/** @file
 * sy_height_field.h — a generated height field for benchmarks: about a requested number of unique
 * triangles in one mesh (a regular grid, 1 x 1 m in XZ centred on the origin, heights of a few
 * centimetres from a few sines, Y up), its own material ("ground") and one node carrying it. `sy
 * bench memory` measures bytes per triangle on it, `sy bench instances` places it many times and
 * `sy bench governor` orbits it.
 *
 * Ownership: objects are created in the caller's scene (which owns them); nothing is committed.
 * Thread-safety: writes to the scene, so as any scene modification (one thread at a time). */
#ifndef SY_HEIGHT_FIELD_H
#define SY_HEIGHT_FIELD_H

#include "sy_scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Adds a height field of about tris unique triangles (2 g^2 for g = ceil(sqrt(tris / 2))) to s as
 * one mesh under a new node (*node_out, not attached to any parent); *tris_out receives the exact
 * count. SY_ERR_LIMIT when the grid exceeds 32-bit indices. */
sy_result sy_height_field_generate(sy_scene *s, uint32_t tris, sy_node *node_out, uint32_t *tris_out, sy_error *err);

#ifdef __cplusplus
}
#endif
#endif /* SY_HEIGHT_FIELD_H */
