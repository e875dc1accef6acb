/** @file
 * sy_blob.h — immutable, reference-counted, content-hashed byte arrays for bulk scene data
 * (vertex and index arrays, texture pixels, child lists), and a hash-keyed blob store.
 *
 * A blob never changes after creation; replacing data means creating a new blob. Its hash is the
 * 128-bit XXH3 of its bytes, so change lists can refer to blobs by hash and a remote peer that has
 * a blob already never receives it again.
 *
 * Ownership: create functions return a blob with one reference owned by the caller; every
 * container that stores a blob holds its own reference. Release the caller's reference with
 * sy_blob_release when done.
 * Thread-safety: retain/release/read are safe from any thread (atomic reference count; contents
 * immutable). A sy_blob_store is NOT thread-safe; guard it externally if shared. */
#ifndef SY_BLOB_H
#define SY_BLOB_H

#include "sy_common.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Every blob's data is followed by at least this many readable bytes (zero for a copied blob), so
 * a consumer may hand the data to a library that reads past the last element in place, as
 * Embree's SIMD loads do on vertex buffers (mediators/rt shares blobs with Embree). */
#define SY_BLOB_PADDING 16u

/** An immutable, reference-counted, content-hashed byte array (opaque). */
typedef struct sy_blob sy_blob;

/** A 128-bit content hash (XXH3-128). */
typedef struct sy_hash128 {
    /** @{ low and high 64 bits */
    uint64_t lo, hi; /** @} */
} sy_hash128;

/** Copies size bytes from data. size may be 0 (data may then be NULL). */
sy_result sy_blob_create_copy(const void *data, size_t size, sy_blob **out, sy_error *err);
/** Takes ownership of malloc()ed data on success only (on failure the caller still owns it). The
 * allocation is grown by SY_BLOB_PADDING bytes (realloc: the pointer may change). */
sy_result sy_blob_create_take(void *data, size_t size, sy_blob **out, sy_error *err);

sy_blob *sy_blob_retain(sy_blob *b); /**< returns b; NULL-safe */
void sy_blob_release(sy_blob *b);    /**< NULL-safe; frees at zero */

const void *sy_blob_data(const sy_blob *b); /**< borrowed, valid while a reference is held */
/** Bytes in the blob. */
size_t sy_blob_size(const sy_blob *b);
/** The blob's content hash. */
sy_hash128 sy_blob_hash(const sy_blob *b);
/** Content hash of any bytes (as sy_blob_hash). */
sy_hash128 sy_hash_bytes(const void *data, size_t size);
/** true when the hashes are equal. */
bool sy_hash_equal(sy_hash128 a, sy_hash128 b);

/** Number of live blobs in this process (leak diagnostics in tests). */
long sy_blob_live_count(void);

/* ---- blob store: hash -> blob ---- */
/** A set of blobs keyed by their hash (opaque). */
typedef struct sy_blob_store sy_blob_store;
/** Creates an empty store. */
sy_result sy_blob_store_create(sy_blob_store **out, sy_error *err);
void sy_blob_store_destroy(sy_blob_store *s); /**< releases every stored blob */
/** Stores a reference (retains). Storing a blob whose hash is present is a no-op. */
sy_result sy_blob_store_put(sy_blob_store *s, sy_blob *b, sy_error *err);
/** Borrowed pointer or NULL; retain it to keep it beyond the store's lifetime. */
sy_blob *sy_blob_store_get(const sy_blob_store *s, sy_hash128 h);
/** Number of stored blobs. */
size_t sy_blob_store_count(const sy_blob_store *s);
/** Payload bytes of the stored blobs. */
size_t sy_blob_store_bytes(const sy_blob_store *s);

#ifdef __cplusplus
}
#endif
#endif /* SY_BLOB_H */
