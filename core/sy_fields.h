/* sy_fields.h — INTERNAL to core: the field tables of every object type and the generic
 * operations driven by them (deep copy, free, compare), plus the layout of a change list.
 * One table per type drives setters' dirty marking, change entries, serialisation and deep
 * equality, so adding a field means adding one table row. Not installed, not for other layers. */
#ifndef SY_FIELDS_H
#define SY_FIELDS_H

#include "sy_changes.h"

#include <stdatomic.h>

typedef enum sy_field_kind {
    SY_FK_POD = 1,    /* plain bytes (floats, ints, handles, small structs) */
    SY_FK_STRING = 2, /* char *, owned copy, may be NULL */
    SY_FK_BLOB = 3,   /* sy_blob *, retained, may be NULL */
    SY_FK_PRIMS = 4,  /* sy_primitive_list, owned array, blobs retained */
} sy_field_kind;

typedef struct sy_field_desc {
    const char *name;
    uint16_t offset;
    uint16_t size;
    uint8_t kind; /* sy_field_kind */
} sy_field_desc;

typedef struct sy_type_desc {
    const char *name;
    size_t data_size;
    const sy_field_desc *fields;
    uint32_t field_count;
    const void *defaults;
} sy_type_desc;

/* NULL for an unknown type. */
const sy_type_desc *sy__type_desc(uint32_t type);
/* Mask of every defined field of a type, attachments included. */
uint64_t sy__type_full_mask(uint32_t type);

/* Releases a primitive's blobs and zeroes it (sy_primitive_release, scene API, is this). */
void sy__primitive_release(sy_primitive *p);
/* Allocates a data struct holding the type's defaults (strings NULL, no blobs). */
void *sy__data_new(uint32_t type);
/* Frees everything a data struct owns, then the struct itself. NULL-safe. */
void sy__data_free(uint32_t type, void *data);
/* Deep-copies field f of src into dst, freeing dst's old value. Returns false on out of memory
 * (dst then holds the type default for that field). */
bool sy__field_copy(uint32_t type, uint32_t f, void *dst, const void *src);
bool sy__field_equal(uint32_t type, uint32_t f, const void *a, const void *b);
/* Bytes a field owns outside its struct (strings, primitive arrays; blob payloads not counted). */
size_t sy__field_heap_bytes(uint32_t type, uint32_t f, const void *data);

/* Attachment arrays: deep copy / free / compare (order-sensitive: keys are kept sorted). */
bool sy__attachments_copy(const sy_attachment *src, uint32_t n, sy_attachment **dst_out);
void sy__attachments_free(sy_attachment *a, uint32_t n);
bool sy__attachments_equal(const sy_attachment *a, uint32_t na, const sy_attachment *b, uint32_t nb);

/* ---- change list layout ---- */
struct sy_changes {
    atomic_int refs;
    uint64_t first_frame, last_frame;
    bool snapshot;
    sy_change *entries; /* entries[i].data / .attachments are owned by the list */
    uint32_t count, capacity;
    size_t bytes; /* approximate heap bytes held (entries + copied values) */
};

/* Change lists (defined in sy_changes.c, which builds on the field operations above; this file's
 * functions never call back into change lists or the scene). */
sy_changes *sy__changes_new(uint64_t first_frame, uint64_t last_frame, bool snapshot);
/* Appends an entry copying the fields in mask from src_data (and the attachments when mask has
 * SY_FIELD_ATTACHMENTS). src_data may be NULL when mask is 0. */
sy_result sy__changes_push(sy_changes *c, uint32_t type, uint32_t id, uint32_t flags, uint64_t mask,
                           const void *src_data, const sy_attachment *att, uint32_t natt, sy_error *err);
/* Sorts into the documented order: destructions, then type dependency order, then id. */
void sy__changes_sort(sy_changes *c);
/* Merges consecutive change lists (oldest first) into one list, one entry per object. */
sy_result sy__changes_merge(sy_changes *const *lists, uint32_t n, sy_changes **out, sy_error *err);

#endif /* SY_FIELDS_H */
