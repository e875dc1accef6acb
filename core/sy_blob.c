/* sy_blob.c — reference-counted immutable blobs hashed with XXH3-128, and the blob store
 * (an open-addressing hash map keyed by content hash). See sy_blob.h. */
#include "sy_blob.h"

#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <xxhash.h>

struct sy_blob {
    atomic_long refs;
    size_t size;
    sy_hash128 hash;
    void *data;
};

static atomic_long g_live_blobs; /* diagnostics only */

sy_hash128 sy_hash_bytes(const void *data, size_t size)
{
    XXH128_hash_t h = XXH3_128bits(data, size);
    sy_hash128 r = {h.low64, h.high64};
    return r;
}

bool sy_hash_equal(sy_hash128 a, sy_hash128 b) { return a.lo == b.lo && a.hi == b.hi; }

sy_result sy_blob_create_take(void *data, size_t size, sy_blob **out, sy_error *err)
{
    *out = NULL;
    if (!data && size) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "blob: NULL data with size %zu", size);
    if (size > SIZE_MAX - SY_BLOB_PADDING) return sy_error_set(err, SY_ERR_LIMIT, "blob: %zu bytes is too large", size);
    sy_blob *b = malloc(sizeof *b);
    if (!b) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "blob: out of memory");
    /* SY_BLOB_PADDING readable bytes after the data: realloc keeps a large (mmapped) block where it
     * is or remaps it, so this costs no copy of bulk data */
    void *padded = realloc(data, size + SY_BLOB_PADDING);
    if (!padded) {
        free(b);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "blob: out of memory for %zu bytes", size + SY_BLOB_PADDING);
    }
    data = padded;
    atomic_init(&b->refs, 1);
    b->size = size;
    b->data = data;
    b->hash = sy_hash_bytes(data, size);
    atomic_fetch_add(&g_live_blobs, 1);
    *out = b;
    return SY_OK;
}

sy_result sy_blob_create_copy(const void *data, size_t size, sy_blob **out, sy_error *err)
{
    *out = NULL;
    if (!data && size) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "blob: NULL data with size %zu", size);
    if (size > SIZE_MAX - SY_BLOB_PADDING) return sy_error_set(err, SY_ERR_LIMIT, "blob: %zu bytes is too large", size);
    char *copy = malloc(size + SY_BLOB_PADDING);
    if (!copy) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "blob: out of memory for %zu bytes", size);
    if (size) memcpy(copy, data, size);
    memset(copy + size, 0, SY_BLOB_PADDING);
    sy_result r = sy_blob_create_take(copy, size, out, err);
    if (r != SY_OK) free(copy);
    return r;
}

sy_blob *sy_blob_retain(sy_blob *b)
{
    if (b) atomic_fetch_add_explicit(&b->refs, 1, memory_order_relaxed);
    return b;
}

void sy_blob_release(sy_blob *b)
{
    if (!b) return;
    if (atomic_fetch_sub_explicit(&b->refs, 1, memory_order_acq_rel) == 1) {
        free(b->data);
        free(b);
        atomic_fetch_sub(&g_live_blobs, 1);
    }
}

const void *sy_blob_data(const sy_blob *b) { return b ? b->data : NULL; }
size_t sy_blob_size(const sy_blob *b) { return b ? b->size : 0; }
sy_hash128 sy_blob_hash(const sy_blob *b)
{
    sy_hash128 z = {0, 0};
    return b ? b->hash : z;
}
long sy_blob_live_count(void) { return atomic_load(&g_live_blobs); }

/* ---- store ---- */
struct sy_blob_store {
    sy_blob **slots; /* capacity entries, NULL = empty */
    size_t capacity; /* power of two */
    size_t count;
    size_t bytes;
};

sy_result sy_blob_store_create(sy_blob_store **out, sy_error *err)
{
    sy_blob_store *s = calloc(1, sizeof *s);
    if (s) s->slots = calloc(64, sizeof *s->slots);
    if (!s || !s->slots) {
        free(s);
        *out = NULL;
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "blob store: out of memory");
    }
    s->capacity = 64;
    *out = s;
    return SY_OK;
}

void sy_blob_store_destroy(sy_blob_store *s)
{
    if (!s) return;
    for (size_t i = 0; i < s->capacity; ++i) sy_blob_release(s->slots[i]);
    free(s->slots);
    free(s);
}

static size_t store_find(sy_blob **slots, size_t capacity, sy_hash128 h)
{
    size_t i = (size_t)h.lo & (capacity - 1);
    while (slots[i] && !sy_hash_equal(slots[i]->hash, h)) i = (i + 1) & (capacity - 1);
    return i;
}

sy_result sy_blob_store_put(sy_blob_store *s, sy_blob *b, sy_error *err)
{
    if (!b) return SY_OK;
    if ((s->count + 1) * 4 > s->capacity * 3) {
        size_t ncap = s->capacity * 2;
        sy_blob **ns = calloc(ncap, sizeof *ns);
        if (!ns) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "blob store: out of memory");
        for (size_t i = 0; i < s->capacity; ++i)
            if (s->slots[i]) ns[store_find(ns, ncap, s->slots[i]->hash)] = s->slots[i];
        free(s->slots);
        s->slots = ns;
        s->capacity = ncap;
    }
    size_t i = store_find(s->slots, s->capacity, b->hash);
    if (s->slots[i]) return SY_OK;
    s->slots[i] = sy_blob_retain(b);
    s->count++;
    s->bytes += b->size;
    return SY_OK;
}

sy_blob *sy_blob_store_get(const sy_blob_store *s, sy_hash128 h)
{
    return s->slots[store_find(s->slots, s->capacity, h)];
}

size_t sy_blob_store_count(const sy_blob_store *s) { return s->count; }
size_t sy_blob_store_bytes(const sy_blob_store *s) { return s->bytes; }
