/** @file
 * sy_changes.h — change lists: what changed in a scene between two points, with the values.
 *
 * A change list holds one entry per object: type, handle id, created/destroyed flags, the mask of
 * changed fields and the values of exactly those fields (blobs by reference). Entries are ordered:
 * destructions first, then by type in dependency order (textures, materials, meshes, lights,
 * cameras, backgrounds, nodes, animations), then by id. A consumer applies them in order.
 *
 * Versioned binary serialisation: blobs are referenced by 128-bit content hash; the blob payloads
 * that the receiver lacks travel in the same message (the sender decides with a callback). The
 * decoder treats its input as untrusted: every length and count is checked before use.
 *
 * Ownership: a sy_changes is reference counted (retain/release) and immutable after creation; it
 * owns copies of every value and a reference to every blob it names.
 * Thread-safety: immutable, so any number of threads may read one concurrently; retain/release
 * are atomic. */
#ifndef SY_CHANGES_H
#define SY_CHANGES_H

#include "sy_scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/** What happened to an object in a change list entry. */
typedef enum sy_change_flags {
    SY_CHANGE_CREATED = 1u << 0,
    SY_CHANGE_DESTROYED = 1u << 1,
} sy_change_flags;

/** One entry of a change list: an object, what happened to it, and the values of its changed fields. */
typedef struct sy_change {
    uint32_t type;  /**< sy_object_type */
    uint32_t id;    /**< handle id */
    uint32_t flags; /**< sy_change_flags */
    uint64_t mask;  /**< SY_BIT(field) of every field whose value is in data */
    /** The type's data struct (const sy_node_data* for nodes, ...); only fields in mask are
     * meaningful, the others hold defaults. NULL for a pure destruction. */
    const void *data;
    const sy_attachment *attachments; /**< the full attachment set when mask has SY_FIELD_ATTACHMENTS */
    uint32_t attachment_count; /**< entries of attachments */
} sy_change;

/** Number of entries. */
uint32_t sy_changes_count(const sy_changes *c);
const sy_change *sy_changes_get(const sy_changes *c, uint32_t i); /**< borrowed */
/** Frame range covered: changes committed in frames (first, last]; a snapshot has first == 0. */
void sy_changes_frames(const sy_changes *c, uint64_t *first_out, uint64_t *last_out);
/** true when the list creates every live object (a consumer's first pull). */
bool sy_changes_is_snapshot(const sy_changes *c);
/** Adds a reference; returns c. */
sy_changes *sy_changes_retain(sy_changes *c);
void sy_changes_release(sy_changes *c); /**< NULL-safe */

/** Counts of entries per kind (for statistics / benchmarks). */
typedef struct sy_changes_stats {
    /** @{ entries that create, destroy and only update an object */
    uint32_t created, destroyed, updated; /** @} */
    uint32_t fields; /**< total set bits over all masks */
} sy_changes_stats;
/** Counts of the list's entries. */
sy_changes_stats sy_changes_get_stats(const sy_changes *c);

/* ---- serialisation ---- */
#define SY_CHANGES_WIRE_MAGIC 0x4C435953u /**< "SYCL" little endian */
#define SY_CHANGES_WIRE_VERSION 7u /**< version of the serialised format */

/** Return true to send the payload of this blob inline (the receiver does not have it yet). */
typedef bool (*sy_blob_send_fn)(void *user, const sy_blob *b);

/** Serialises into a malloc()ed buffer owned by the caller (*data_out; free with free()).
 * send_blob NULL = send every payload. */
sy_result sy_changes_serialize(const sy_changes *c, sy_blob_send_fn send_blob, void *user, void **data_out,
                               size_t *size_out, sy_error *err);

/** Limits of sy_changes_deserialize for untrusted input. */
typedef struct sy_changes_limits {
    size_t max_entries;     /**< 0 = default 1<<22 */
    size_t max_blob_bytes;  /**< 0 = default 1 GiB per blob */
    size_t max_string_bytes; /**< 0 = default 1 MiB per string */
} sy_changes_limits;

/** Decodes an untrusted buffer. Blob payloads found in the message are added to store (which then
 * holds them); blobs referenced only by hash must already be in store, else SY_ERR_NOT_FOUND
 * naming the hash. Errors name the byte offset and the reason. Caller owns *out. */
sy_result sy_changes_deserialize(const void *data, size_t size, sy_blob_store *store, const sy_changes_limits *limits,
                                 sy_changes **out, sy_error *err);

/** Lists the blobs an untrusted serialised change list names by hash only (payload not inline):
 * fn(user, hash, size) per blob table record. Checks the header and the blob table (not the
 * entries), so a receiver can find the blobs it lacks before decoding the list. */
typedef void (*sy_blob_ref_fn)(void *user, sy_hash128 hash, uint64_t size);
/** Calls fn for every blob the list names by hash only (see above). */
sy_result sy_changes_blob_refs(const void *data, size_t size, const sy_changes_limits *limits, sy_blob_ref_fn fn,
                               void *user, sy_error *err);

#ifdef __cplusplus
}
#endif
#endif /* SY_CHANGES_H */
