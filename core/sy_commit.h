/** @file
 * sy_commit.h — the scene's change lists: commit seals the dirty fields into one change list (a
 * frame); consumers (mediator contexts, cluster connections) pull everything since their own
 * cursor, merged; the log is compacted once every consumer has passed it; a replica applies change
 * lists (local or deserialised) to its own scene. Reading a change list: sy_changes.h.
 * Ownership: a pulled change list belongs to the caller (sy_changes_release). Change lists are
 * immutable and self-contained and may be read from any thread while the application edits the
 * scene for the next frame. Thread-safety of the calls: as the scene (sy_scene.h). */
#ifndef SY_COMMIT_H
#define SY_COMMIT_H

#include "sy_objects.h"

#ifdef __cplusplus
extern "C" {
#endif

/** A sealed change list (sy_changes.h). */
typedef struct sy_changes sy_changes;

/** Seals the changes since the last commit into one change list and recomputes world matrices
 * and bounds of dirty subtrees. Returns the new frame number (first commit: 1) in *frame_out. */
sy_result sy_scene_commit(sy_scene *s, uint64_t *frame_out, sy_error *err);
uint64_t sy_scene_frame(const sy_scene *s); /**< last committed frame (0 before the first) */
bool sy_scene_has_pending(const sy_scene *s); /**< uncommitted changes exist */

/** Adds a consumer. Its first pull returns a snapshot (a change list creating every live object
 * with all fields) of the last committed state, merged with anything after. If uncommitted
 * changes exist when it is added, the snapshot is taken at the next commit (pulls before then
 * return empty lists). */
sy_result sy_scene_consumer_add(sy_scene *s, uint32_t *consumer_out, sy_error *err);
/** Removes a consumer. */
void sy_scene_consumer_remove(sy_scene *s, uint32_t consumer);
/** Everything committed since this consumer's last pull, merged into one change list (one entry
 * per object). Ownership: the caller owns *out and releases it with sy_changes_release. */
sy_result sy_scene_consumer_pull(sy_scene *s, uint32_t consumer, sy_changes **out, sy_error *err);
/** Number of sealed change lists still held in the log (for tests of compaction). */
uint32_t sy_scene_log_length(const sy_scene *s);
/** Bytes held by the change log (entry structs and copied values, not shared blob payloads). */
size_t sy_scene_log_bytes(const sy_scene *s);

/** A change list creating every live (committed) object with all its fields. Caller owns *out. */
sy_result sy_scene_snapshot(sy_scene *s, sy_changes **out, sy_error *err);

/** Replica side: apply a change list (local or deserialised) to this scene. Objects are created
 * with the exact handle ids of the change list; the applied changes are recorded like local ones,
 * so this scene's own consumers see them after its next commit. */
sy_result sy_scene_apply(sy_scene *s, const sy_changes *changes, sy_error *err);
/** Replica policy for untrusted change lists: sy_scene_apply refuses (SY_ERR_LIMIT, naming the
 * type, the index and the limit) to create an object whose slot index is max_slots or more, so a
 * message cannot make a pool grow to millions of slots. 0 (the default) = no limit beyond the
 * handle format's SY_HANDLE_INDEX_MASK. Objects created locally are not affected. */
void sy_scene_set_apply_limit(sy_scene *s, uint32_t max_slots);
/** sy_scene_apply with a bound on the pool slots this one change list may add, all object types
 * together (0 = no bound). A slot costs the replica about SY_SCENE_SLOT_BYTES whether or not an
 * object lives in it, so a list creating slot index I makes a pool of I + 1 slots: the bound keeps
 * what an untrusted list makes a replica allocate proportional to the list's size (the cluster
 * server passes SY_CLUSTER_APPLY_SLACK_SLOTS + the list's bytes / SY_CLUSTER_APPLY_BYTES_PER_SLOT).
 * The bound and the slot limit are checked for every creation before anything is applied
 * (SY_ERR_LIMIT naming the type, the id, the growth and the bound; the scene is then untouched);
 * each pool then grows once, to exactly the slots the list needs. */
sy_result sy_scene_apply_bounded(sy_scene *s, const sy_changes *changes, uint64_t max_new_slots, sy_error *err);
/** Bytes one pool slot costs (the slot record and its free-list entry), for the bound above. */
#define SY_SCENE_SLOT_BYTES 104u

/** Deep comparison of every live object, field and attachment (blobs by content hash). Returns
 * true when equal; otherwise false and a description of the first difference in err->message. */
bool sy_scene_equal(const sy_scene *a, const sy_scene *b, sy_error *diff);

#ifdef __cplusplus
}
#endif
#endif /* SY_COMMIT_H */
