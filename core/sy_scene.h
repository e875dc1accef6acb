/** @file
 * sy_scene.h — the application-side scene graph: typed object pools with generation-checked
 * handles, field setters that record changes, attachments, node DAG with world matrices and
 * bounds, and commit into change lists (sy_changes.h reads them). This header creates and
 * destroys a scene and includes the one header of each of its concepts:
 *   sy_objects.h  handles, the eight object types and their fields, object calls, attachments;
 *   sy_graph.h    parents, world matrices and bounds;
 *   sy_commit.h   commit, consumers, snapshots and replica apply.
 *
 * Ownership: the scene owns every object and everything stored in fields (strings are copied,
 * blobs retained). Getters return borrowed pointers valid until the next modification of that
 * object or the destruction of the scene.
 * Thread-safety: a scene is single-writer: all calls on one scene must be serialised by the
 * caller. Change lists pulled from it (sy_changes) are immutable and self-contained and may be
 * read from any thread while the application edits the scene for the next frame. */
#ifndef SY_SCENE_H
#define SY_SCENE_H

#include "sy_commit.h"
#include "sy_graph.h"
#include "sy_objects.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Creates an empty scene. */
sy_result sy_scene_create(sy_scene **out, sy_error *err);
void sy_scene_destroy(sy_scene *s); /**< NULL-safe; releases everything */

#ifdef __cplusplus
}
#endif
#endif /* SY_SCENE_H */
