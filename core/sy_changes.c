/* sy_changes.c — change lists: building them (push, sort, merge), their accessors and their
 * versioned binary wire format. Builds on the field tables (sy_fields.c); never calls the scene.
 * The wire format (little endian):
 *
 *   header   u32 magic "SYCL", u16 version, u16 flags (1 = snapshot), u64 first_frame,
 *            u64 last_frame, u32 entry_count, u32 blob_count
 *   blobs    blob_count x { u64 hash_lo, u64 hash_hi, u64 size, u8 has_payload, [size bytes] }
 *   entries  entry_count x { u8 type (sy_object_type: 1 texture .. 8 animation, version 4), u8 flags,
 *            u16 reserved(0), u32 id, u64 mask, fields... }
 *   field    POD: its bytes; string: u32 length (0xffffffff = NULL) + bytes; blob: u32 index into
 *            the blob table (0xffffffff = NULL); primitives: u32 count + count x (12 blob indices:
 *            positions, normals, tangents, texcoords0, texcoords1, colors, indices, joints, weights,
 *            target positions, normals, tangents (version 5; up to version 4 the first 7) +
 *            u32 material id + u32 topology (sy_topology, < SY_TOPOLOGY_COUNT) + f32 width (finite,
 *            >= 0)) (version 2; version 1 had neither); node fields weights, skin, skeleton and mesh
 *            field weights (version 5); attachments (mask bit 63): u32 count + count x {string key, u8 kind,
 *            value: i64 | f64 | 4 x f32 | string | blob index}
 *
 * The decoder never trusts a length: every read is checked against what remains, counts are
 * checked against limits before allocation, payload hashes are verified. */
#include "sy_fields.h"

#include <math.h>
#include <stdio.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#if !defined(__BYTE_ORDER__) || __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "the change list wire format is written for little-endian hosts"
#endif

#define NULL_INDEX 0xffffffffu

uint32_t sy_changes_count(const sy_changes *c) { return c ? c->count : 0; }
const sy_change *sy_changes_get(const sy_changes *c, uint32_t i)
{
    return (c && i < c->count) ? &c->entries[i] : NULL;
}
void sy_changes_frames(const sy_changes *c, uint64_t *first_out, uint64_t *last_out)
{
    if (first_out) *first_out = c->first_frame;
    if (last_out) *last_out = c->last_frame;
}
bool sy_changes_is_snapshot(const sy_changes *c) { return c->snapshot; }

sy_changes *sy_changes_retain(sy_changes *c)
{
    if (c) atomic_fetch_add_explicit(&c->refs, 1, memory_order_relaxed);
    return c;
}

void sy_changes_release(sy_changes *c)
{
    if (!c) return;
    if (atomic_fetch_sub_explicit(&c->refs, 1, memory_order_acq_rel) != 1) return;
    for (uint32_t i = 0; i < c->count; ++i) {
        sy__data_free(c->entries[i].type, (void *)c->entries[i].data);
        sy__attachments_free((sy_attachment *)c->entries[i].attachments, c->entries[i].attachment_count);
    }
    free(c->entries);
    free(c);
}

sy_changes_stats sy_changes_get_stats(const sy_changes *c)
{
    sy_changes_stats s = {0};
    for (uint32_t i = 0; i < c->count; ++i) {
        const sy_change *e = &c->entries[i];
        if (e->flags & SY_CHANGE_DESTROYED) s.destroyed++;
        else if (e->flags & SY_CHANGE_CREATED) s.created++;
        else s.updated++;
        s.fields += (uint32_t)__builtin_popcountll(e->mask);
    }
    return s;
}

/* >>writer */
typedef struct writer {
    unsigned char *data;
    size_t size, capacity;
    bool failed;
} writer;

static void w_bytes(writer *w, const void *p, size_t n)
{
    if (w->failed) return;
    if (n > w->capacity - w->size) {
        size_t cap = w->capacity ? w->capacity : 256;
        while (n > cap - w->size) {
            if (cap > SIZE_MAX / 2) {
                w->failed = true;
                return;
            }
            cap *= 2;
        }
        unsigned char *nd = realloc(w->data, cap);
        if (!nd) {
            w->failed = true;
            return;
        }
        w->data = nd;
        w->capacity = cap;
    }
    if (n) memcpy(w->data + w->size, p, n);
    w->size += n;
}
static void w_u8(writer *w, uint8_t v) { w_bytes(w, &v, 1); }
static void w_u16(writer *w, uint16_t v) { w_bytes(w, &v, 2); }
static void w_u32(writer *w, uint32_t v) { w_bytes(w, &v, 4); }
static void w_u64(writer *w, uint64_t v) { w_bytes(w, &v, 8); }
static void w_str(writer *w, const char *s)
{
    if (!s) {
        w_u32(w, NULL_INDEX);
        return;
    }
    size_t n = strlen(s);
    if (n >= NULL_INDEX) {
        w->failed = true;
        return;
    }
    w_u32(w, (uint32_t)n);
    w_bytes(w, s, n);
}

/* Blob table built while serialising: a linear array plus an index map by hash. */
typedef struct blob_table {
    const sy_blob **items;
    uint32_t count, capacity;
    uint32_t *map; /* index+1, 0 empty */
    size_t map_capacity;
} blob_table;

static bool bt_add(blob_table *t, const sy_blob *b, uint32_t *index_out)
{
    if (!b) {
        *index_out = NULL_INDEX;
        return true;
    }
    sy_hash128 h = sy_blob_hash(b);
    if ((size_t)(t->count + 1) * 2 > t->map_capacity) {
        size_t ncap = t->map_capacity ? t->map_capacity * 2 : 64;
        uint32_t *nm = calloc(ncap, sizeof *nm);
        if (!nm) return false;
        for (uint32_t i = 0; i < t->count; ++i) {
            size_t j = (size_t)sy_blob_hash(t->items[i]).lo & (ncap - 1);
            while (nm[j]) j = (j + 1) & (ncap - 1);
            nm[j] = i + 1;
        }
        free(t->map);
        t->map = nm;
        t->map_capacity = ncap;
    }
    size_t j = (size_t)h.lo & (t->map_capacity - 1);
    while (t->map[j]) {
        if (sy_hash_equal(sy_blob_hash(t->items[t->map[j] - 1]), h)) {
            *index_out = t->map[j] - 1;
            return true;
        }
        j = (j + 1) & (t->map_capacity - 1);
    }
    if (t->count == t->capacity) {
        uint32_t ncap = t->capacity ? t->capacity * 2 : 32;
        const sy_blob **ni = realloc(t->items, sizeof *ni * ncap);
        if (!ni) return false;
        t->items = ni;
        t->capacity = ncap;
    }
    t->items[t->count] = b;
    t->map[j] = t->count + 1;
    *index_out = t->count++;
    return true;
}

static bool collect_blobs(const sy_changes *c, blob_table *t)
{
    uint32_t idx;
    for (uint32_t i = 0; i < c->count; ++i) {
        const sy_change *e = &c->entries[i];
        const sy_type_desc *td = sy__type_desc(e->type);
        for (uint32_t f = 0; f < td->field_count; ++f) {
            if (!(e->mask & SY_BIT(f))) continue;
            const void *p = (const char *)e->data + td->fields[f].offset;
            if (td->fields[f].kind == SY_FK_BLOB && !bt_add(t, *(sy_blob *const *)p, &idx)) return false;
            if (td->fields[f].kind == SY_FK_PRIMS) {
                const sy_primitive_list *l = p;
                for (uint32_t k = 0; k < l->count; ++k) {
                    const sy_primitive *pr = &l->items[k];
                    if (!bt_add(t, pr->positions, &idx) || !bt_add(t, pr->normals, &idx) ||
                        !bt_add(t, pr->tangents, &idx) || !bt_add(t, pr->texcoords0, &idx) ||
                        !bt_add(t, pr->texcoords1, &idx) || !bt_add(t, pr->colors, &idx) ||
                        !bt_add(t, pr->indices, &idx) || !bt_add(t, pr->joints, &idx) ||
                        !bt_add(t, pr->weights, &idx) || !bt_add(t, pr->target_positions, &idx) ||
                        !bt_add(t, pr->target_normals, &idx) || !bt_add(t, pr->target_tangents, &idx) ||
                        !bt_add(t, pr->target_texcoords0, &idx))
                        return false;
                }
            }
        }
        for (uint32_t a = 0; a < e->attachment_count; ++a)
            if (e->attachments[a].kind == SY_ATTACH_BLOB && !bt_add(t, e->attachments[a].value.blob, &idx))
                return false;
    }
    return true;
}

/* A primitive's blobs in their order in the format (positions ... target_tangents), for the writer
 * and the reader. */
static const size_t prim_blobs[] = {
    offsetof(sy_primitive, positions),  offsetof(sy_primitive, normals),          offsetof(sy_primitive, tangents),
    offsetof(sy_primitive, texcoords0), offsetof(sy_primitive, texcoords1),       offsetof(sy_primitive, colors),
    offsetof(sy_primitive, indices),    offsetof(sy_primitive, joints),           offsetof(sy_primitive, weights),
    offsetof(sy_primitive, target_positions), offsetof(sy_primitive, target_normals),
    offsetof(sy_primitive, target_tangents), offsetof(sy_primitive, target_texcoords0)};
#define PRIM_BLOBS (sizeof prim_blobs / sizeof prim_blobs[0])

static void w_blobref(writer *w, blob_table *t, const sy_blob *b)
{
    uint32_t idx = NULL_INDEX;
    if (!bt_add(t, b, &idx)) w->failed = true; /* already present: a lookup */
    w_u32(w, idx);
}

sy_result sy_changes_serialize(const sy_changes *c, sy_blob_send_fn send_blob, void *user, void **data_out,
                               size_t *size_out, sy_error *err)
{
    *data_out = NULL;
    *size_out = 0;
    writer w = {0};
    blob_table t = {0};
    if (!collect_blobs(c, &t)) {
        free(t.items);
        free(t.map);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "serialise change list: out of memory");
    }
    w_u32(&w, SY_CHANGES_WIRE_MAGIC);
    w_u16(&w, SY_CHANGES_WIRE_VERSION);
    w_u16(&w, c->snapshot ? 1 : 0);
    w_u64(&w, c->first_frame);
    w_u64(&w, c->last_frame);
    w_u32(&w, c->count);
    w_u32(&w, t.count);
    for (uint32_t i = 0; i < t.count; ++i) {
        const sy_blob *b = t.items[i];
        sy_hash128 h = sy_blob_hash(b);
        bool send = send_blob ? send_blob(user, b) : true;
        w_u64(&w, h.lo);
        w_u64(&w, h.hi);
        w_u64(&w, (uint64_t)sy_blob_size(b));
        w_u8(&w, send ? 1 : 0);
        if (send) w_bytes(&w, sy_blob_data(b), sy_blob_size(b));
    }
    for (uint32_t i = 0; i < c->count; ++i) {
        const sy_change *e = &c->entries[i];
        const sy_type_desc *td = sy__type_desc(e->type);
        w_u8(&w, (uint8_t)e->type);
        w_u8(&w, (uint8_t)e->flags);
        w_u16(&w, 0);
        w_u32(&w, e->id);
        w_u64(&w, e->mask);
        for (uint32_t f = 0; f < td->field_count; ++f) {
            if (!(e->mask & SY_BIT(f))) continue;
            const void *p = (const char *)e->data + td->fields[f].offset;
            switch (td->fields[f].kind) {
            case SY_FK_STRING: w_str(&w, *(char *const *)p); break;
            case SY_FK_BLOB: w_blobref(&w, &t, *(sy_blob *const *)p); break;
            case SY_FK_PRIMS: {
                const sy_primitive_list *l = p;
                w_u32(&w, l->count);
                for (uint32_t k = 0; k < l->count; ++k) {
                    const sy_primitive *pr = &l->items[k];
                    for (size_t s = 0; s < PRIM_BLOBS; ++s)
                        w_blobref(&w, &t, *(sy_blob *const *)((const char *)pr + prim_blobs[s]));
                    w_u32(&w, pr->material.id);
                    w_u32(&w, pr->topology);
                    w_bytes(&w, &pr->width, sizeof pr->width);
                }
                break;
            }
            default: w_bytes(&w, p, td->fields[f].size); break;
            }
        }
        if (e->mask & SY_BIT(SY_FIELD_ATTACHMENTS)) {
            w_u32(&w, e->attachment_count);
            for (uint32_t a = 0; a < e->attachment_count; ++a) {
                const sy_attachment *at = &e->attachments[a];
                w_str(&w, at->key);
                w_u8(&w, (uint8_t)at->kind);
                switch (at->kind) {
                case SY_ATTACH_INT: w_bytes(&w, &at->value.i, 8); break;
                case SY_ATTACH_FLOAT: w_bytes(&w, &at->value.f, 8); break;
                case SY_ATTACH_VEC4: w_bytes(&w, at->value.v, 16); break;
                case SY_ATTACH_STRING: w_str(&w, at->value.s); break;
                case SY_ATTACH_BLOB: w_blobref(&w, &t, at->value.blob); break;
                default: w.failed = true; break;
                }
            }
        }
    }
    free(t.items);
    free(t.map);
    if (w.failed) {
        free(w.data);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "serialise change list: out of memory");
    }
    *data_out = w.data;
    *size_out = w.size;
    return SY_OK;
}

/* >>reader (untrusted input) */
typedef struct reader {
    const unsigned char *p;
    size_t size, pos;
    sy_error *err;
    sy_result code;
} reader;

static bool r_fail(reader *r, sy_result code, const char *what)
{
    if (r->code == SY_OK) {
        r->code = code;
        sy_error_set(r->err, code, "change list: byte %zu: %s", r->pos, what);
    }
    return false;
}

static bool r_bytes(reader *r, void *dst, size_t n, const char *what)
{
    if (r->code != SY_OK) return false;
    if (n > r->size - r->pos) return r_fail(r, SY_ERR_PARSE, what);
    if (n) memcpy(dst, r->p + r->pos, n);
    r->pos += n;
    return true;
}
static bool r_u8(reader *r, uint8_t *v, const char *what) { return r_bytes(r, v, 1, what); }
static bool r_u16(reader *r, uint16_t *v, const char *what) { return r_bytes(r, v, 2, what); }
static bool r_u32(reader *r, uint32_t *v, const char *what) { return r_bytes(r, v, 4, what); }
static bool r_u64(reader *r, uint64_t *v, const char *what) { return r_bytes(r, v, 8, what); }

static bool r_str(reader *r, size_t max, char **out, const char *what)
{
    *out = NULL;
    uint32_t n;
    if (!r_u32(r, &n, what)) return false;
    if (n == NULL_INDEX) return true;
    if (n > max) return r_fail(r, SY_ERR_LIMIT, "string longer than the limit");
    if (n > r->size - r->pos) return r_fail(r, SY_ERR_PARSE, "string runs past the end of the message");
    if (memchr(r->p + r->pos, 0, n)) return r_fail(r, SY_ERR_PARSE, "string contains a NUL byte");
    char *s = malloc((size_t)n + 1);
    if (!s) return r_fail(r, SY_ERR_OUT_OF_MEMORY, "out of memory for a string");
    memcpy(s, r->p + r->pos, n);
    s[n] = '\0';
    r->pos += n;
    *out = s;
    return true;
}

static bool r_blobref(reader *r, sy_blob *const *blobs, uint32_t nblobs, sy_blob **out)
{
    uint32_t idx;
    *out = NULL;
    if (!r_u32(r, &idx, "blob index")) return false;
    if (idx == NULL_INDEX) return true;
    if (idx >= nblobs) return r_fail(r, SY_ERR_PARSE, "blob index past the blob table");
    *out = blobs[idx]; /* borrowed from the table; the caller retains */
    return true;
}

/* The header: magic, version, flags, counts checked against the limit and the message size. */
static bool r_header(reader *r, size_t max_entries, uint16_t *flags, uint64_t *first, uint64_t *last,
                     uint32_t *nentries, uint32_t *nblobs)
{
    uint32_t magic;
    uint16_t version;
    if (!r_u32(r, &magic, "header") || !r_u16(r, &version, "header") || !r_u16(r, flags, "header") ||
        !r_u64(r, first, "header") || !r_u64(r, last, "header") || !r_u32(r, nentries, "header") ||
        !r_u32(r, nblobs, "header"))
        return false;
    if (magic != SY_CHANGES_WIRE_MAGIC) return r_fail(r, SY_ERR_PARSE, "wrong magic (not a change list)");
    if (version != SY_CHANGES_WIRE_VERSION) {
        r->pos = 4;
        return r_fail(r, SY_ERR_UNSUPPORTED, "unsupported wire version");
    }
    if (*flags & ~1u) return r_fail(r, SY_ERR_PARSE, "unknown header flags");
    if (*nentries > max_entries) return r_fail(r, SY_ERR_LIMIT, "entry count exceeds the limit");
    /* Each blob record takes at least 25 bytes and each entry 16: cheap sanity before allocating. */
    if (*nblobs > (r->size - r->pos) / 25 || *nentries > (r->size - r->pos) / 16)
        return r_fail(r, SY_ERR_PARSE, "counts larger than the message can hold");
    return true;
}

/* One blob table record up to its payload (left unread; checked to lie inside the message). */
static bool r_blob_record(reader *r, size_t max_blob, sy_hash128 *h, uint64_t *bsize, uint8_t *has)
{
    if (!r_u64(r, &h->lo, "blob hash") || !r_u64(r, &h->hi, "blob hash") || !r_u64(r, bsize, "blob size") ||
        !r_u8(r, has, "blob flag"))
        return false;
    if (*bsize > max_blob) return r_fail(r, SY_ERR_LIMIT, "blob larger than the limit");
    if (*has > 1) return r_fail(r, SY_ERR_PARSE, "bad blob payload flag");
    if (*has && *bsize > r->size - r->pos) return r_fail(r, SY_ERR_PARSE, "blob payload runs past the end of the message");
    return true;
}

sy_result sy_changes_blob_refs(const void *data, size_t size, const sy_changes_limits *limits, sy_blob_ref_fn fn,
                               void *user, sy_error *err)
{
    size_t max_entries = (limits && limits->max_entries) ? limits->max_entries : ((size_t)1 << 22);
    size_t max_blob = (limits && limits->max_blob_bytes) ? limits->max_blob_bytes : ((size_t)1 << 30);
    reader r = {data, size, 0, err, SY_OK};
    uint32_t nentries, nblobs;
    uint16_t flags;
    uint64_t first, last;
    if (!r_header(&r, max_entries, &flags, &first, &last, &nentries, &nblobs)) return r.code;
    for (uint32_t i = 0; i < nblobs; ++i) {
        sy_hash128 h;
        uint64_t bsize;
        uint8_t has;
        if (!r_blob_record(&r, max_blob, &h, &bsize, &has)) return r.code;
        if (has) r.pos += (size_t)bsize;
        else fn(user, h, bsize);
    }
    return SY_OK;
}

sy_result sy_changes_deserialize(const void *data, size_t size, sy_blob_store *store, const sy_changes_limits *limits,
                                 sy_changes **out, sy_error *err)
{
    *out = NULL;
    size_t max_entries = (limits && limits->max_entries) ? limits->max_entries : ((size_t)1 << 22);
    size_t max_blob = (limits && limits->max_blob_bytes) ? limits->max_blob_bytes : ((size_t)1 << 30);
    size_t max_str = (limits && limits->max_string_bytes) ? limits->max_string_bytes : ((size_t)1 << 20);
    reader r = {data, size, 0, err, SY_OK};
    sy_blob **blobs = NULL;
    sy_changes *c = NULL;
    void *tmp = NULL; /* entry data being decoded */
    uint32_t tmp_type = 0;
    sy_attachment *atts = NULL;
    uint32_t natts = 0;

    uint32_t nentries, nblobs;
    uint16_t flags;
    uint64_t first, last;
    if (!r_header(&r, max_entries, &flags, &first, &last, &nentries, &nblobs)) goto fail;
    blobs = calloc(nblobs ? nblobs : 1, sizeof *blobs);
    c = sy__changes_new(first, last, flags & 1u);
    if (!blobs || !c) {
        r_fail(&r, SY_ERR_OUT_OF_MEMORY, "out of memory");
        goto fail;
    }
    for (uint32_t i = 0; i < nblobs; ++i) {
        sy_hash128 h;
        uint64_t bsize;
        uint8_t has;
        if (!r_blob_record(&r, max_blob, &h, &bsize, &has)) goto fail;
        if (has) {
            if (!sy_hash_equal(sy_hash_bytes(r.p + r.pos, (size_t)bsize), h)) {
                r_fail(&r, SY_ERR_PROTOCOL, "blob payload does not match its hash");
                goto fail;
            }
            sy_blob *b = sy_blob_store_get(store, h);
            if (!b) {
                sy_error e2 = {0};
                if (sy_blob_create_copy(r.p + r.pos, (size_t)bsize, &b, &e2) != SY_OK ||
                    sy_blob_store_put(store, b, &e2) != SY_OK) {
                    sy_blob_release(b);
                    r_fail(&r, SY_ERR_OUT_OF_MEMORY, "out of memory for a blob");
                    goto fail;
                }
                sy_blob_release(b); /* the store holds it */
            }
            r.pos += (size_t)bsize;
            blobs[i] = b;
        } else {
            sy_blob *b = sy_blob_store_get(store, h);
            if (!b || sy_blob_size(b) != bsize) {
                char what[96];
                snprintf(what, sizeof what, "blob %016llx%016llx is neither in the message nor cached",
                         (unsigned long long)h.hi, (unsigned long long)h.lo);
                r_fail(&r, SY_ERR_NOT_FOUND, what);
                goto fail;
            }
            blobs[i] = b;
        }
    }
    for (uint32_t i = 0; i < nentries; ++i) {
        uint8_t type, eflags;
        uint16_t reserved;
        uint32_t id;
        uint64_t mask;
        if (!r_u8(&r, &type, "entry type") || !r_u8(&r, &eflags, "entry flags") ||
            !r_u16(&r, &reserved, "entry") || !r_u32(&r, &id, "entry id") || !r_u64(&r, &mask, "entry mask"))
            goto fail;
        const sy_type_desc *td = sy__type_desc(type);
        if (!td) {
            r_fail(&r, SY_ERR_PARSE, "unknown object type");
            goto fail;
        }
        if (reserved != 0 || (eflags & ~3u) || id == 0) {
            r_fail(&r, SY_ERR_PARSE, "bad entry header (reserved bits, flags or id 0)");
            goto fail;
        }
        if (mask & ~sy__type_full_mask(type)) {
            r_fail(&r, SY_ERR_PARSE, "field mask names fields the type does not have");
            goto fail;
        }
        if ((eflags & SY_CHANGE_DESTROYED) && (mask || (eflags & SY_CHANGE_CREATED))) {
            r_fail(&r, SY_ERR_PARSE, "a destruction carries fields");
            goto fail;
        }
        /* A creation carries every field (as commits and snapshots write it): so each object a
         * list creates costs the list its serialised record, and a few bytes cannot make a
         * receiver allocate records hundreds of bytes large (docs/PROTOCOL.md, the multiple). */
        if ((eflags & SY_CHANGE_CREATED) && !(eflags & SY_CHANGE_DESTROYED) && mask != sy__type_full_mask(type)) {
            r_fail(&r, SY_ERR_PARSE, "a creation without every field of its type");
            goto fail;
        }
        tmp_type = type;
        tmp = sy__data_new(type);
        if (!tmp) {
            r_fail(&r, SY_ERR_OUT_OF_MEMORY, "out of memory");
            goto fail;
        }
        for (uint32_t f = 0; f < td->field_count; ++f) {
            if (!(mask & SY_BIT(f))) continue;
            void *p = (char *)tmp + td->fields[f].offset;
            switch (td->fields[f].kind) {
            case SY_FK_STRING:
                if (!r_str(&r, max_str, (char **)p, "string")) goto fail;
                break;
            case SY_FK_BLOB: {
                sy_blob *b;
                if (!r_blobref(&r, blobs, nblobs, &b)) goto fail;
                *(sy_blob **)p = sy_blob_retain(b);
                break;
            }
            case SY_FK_PRIMS: {
                uint32_t n;
                if (!r_u32(&r, &n, "primitive count")) goto fail;
                if (n > (r.size - r.pos) / 60) { /* 12 blob indices, material, topology, width */
                    r_fail(&r, SY_ERR_PARSE, "primitive count larger than the message can hold");
                    goto fail;
                }
                sy_primitive_list *l = p;
                l->items = calloc(n ? n : 1, sizeof(sy_primitive));
                if (!l->items) {
                    r_fail(&r, SY_ERR_OUT_OF_MEMORY, "out of memory");
                    goto fail;
                }
                for (uint32_t k = 0; k < n; ++k) {
                    sy_primitive *pr = &l->items[k];
                    l->count = k + 1; /* so a failure frees what was retained */
                    for (size_t s = 0; s < PRIM_BLOBS; ++s) {
                        sy_blob *b;
                        if (!r_blobref(&r, blobs, nblobs, &b)) goto fail;
                        *(sy_blob **)((char *)pr + prim_blobs[s]) = sy_blob_retain(b);
                    }
                    if (!r_u32(&r, &pr->material.id, "primitive material") ||
                        !r_u32(&r, &pr->topology, "primitive topology") ||
                        !r_bytes(&r, &pr->width, sizeof pr->width, "primitive width"))
                        goto fail;
                    if (pr->topology >= SY_TOPOLOGY_COUNT) {
                        r_fail(&r, SY_ERR_PARSE, "unknown primitive topology");
                        goto fail;
                    }
                    if (!isfinite(pr->width) || pr->width < 0.0f) {
                        r_fail(&r, SY_ERR_PARSE, "primitive width not finite and >= 0");
                        goto fail;
                    }
                }
                l->count = n;
                break;
            }
            default:
                if (!r_bytes(&r, p, td->fields[f].size, "field value")) goto fail;
                break;
            }
        }
        if (mask & SY_BIT(SY_FIELD_ATTACHMENTS)) {
            uint32_t n;
            if (!r_u32(&r, &n, "attachment count")) goto fail;
            if (n > (r.size - r.pos) / 9) {
                r_fail(&r, SY_ERR_PARSE, "attachment count larger than the message can hold");
                goto fail;
            }
            atts = calloc(n ? n : 1, sizeof *atts);
            if (!atts) {
                r_fail(&r, SY_ERR_OUT_OF_MEMORY, "out of memory");
                goto fail;
            }
            for (uint32_t a = 0; a < n; ++a) {
                sy_attachment *at = &atts[a];
                natts = a + 1;
                uint8_t kind;
                if (!r_str(&r, max_str, &at->key, "attachment key") || !r_u8(&r, &kind, "attachment kind")) goto fail;
                if (!at->key) {
                    r_fail(&r, SY_ERR_PARSE, "attachment without a key");
                    goto fail;
                }
                at->kind = kind;
                bool ok = true;
                switch (kind) {
                case SY_ATTACH_INT: ok = r_bytes(&r, &at->value.i, 8, "attachment value"); break;
                case SY_ATTACH_FLOAT: ok = r_bytes(&r, &at->value.f, 8, "attachment value"); break;
                case SY_ATTACH_VEC4: ok = r_bytes(&r, at->value.v, 16, "attachment value"); break;
                case SY_ATTACH_STRING:
                    at->value.s = NULL;
                    ok = r_str(&r, max_str, &at->value.s, "attachment value");
                    if (ok && !at->value.s) ok = r_fail(&r, SY_ERR_PARSE, "NULL string attachment");
                    break;
                case SY_ATTACH_BLOB: {
                    sy_blob *b;
                    at->value.blob = NULL;
                    ok = r_blobref(&r, blobs, nblobs, &b);
                    if (ok) at->value.blob = sy_blob_retain(b);
                    break;
                }
                default:
                    at->kind = SY_ATTACH_INT; /* nothing to free */
                    ok = r_fail(&r, SY_ERR_PARSE, "unknown attachment kind");
                    break;
                }
                if (!ok) goto fail;
                if (a > 0 && strcmp(atts[a - 1].key, at->key) >= 0) {
                    r_fail(&r, SY_ERR_PARSE, "attachment keys not strictly sorted");
                    goto fail;
                }
            }
        }
        sy_error e2 = {0};
        if (sy__changes_push(c, type, id, eflags, mask, tmp, atts, natts, &e2) != SY_OK) {
            r_fail(&r, e2.code, e2.message);
            goto fail;
        }
        sy__data_free(tmp_type, tmp);
        tmp = NULL;
        sy__attachments_free(atts, natts);
        atts = NULL;
        natts = 0;
    }
    if (r.pos != r.size) {
        r_fail(&r, SY_ERR_PARSE, "trailing bytes after the last entry");
        goto fail;
    }
    free(blobs);
    *out = c;
    return SY_OK;
fail:
    sy__data_free(tmp_type, tmp);
    sy__attachments_free(atts, natts);
    free(blobs);
    sy_changes_release(c);
    return r.code != SY_OK ? r.code : sy_error_set(err, SY_ERR_PARSE, "change list: malformed");
}

/* >>change lists: building, ordering and merging (the layout is in sy_fields.h) */
sy_changes *sy__changes_new(uint64_t first_frame, uint64_t last_frame, bool snapshot)
{
    sy_changes *c = calloc(1, sizeof *c);
    if (!c) return NULL;
    atomic_init(&c->refs, 1);
    c->first_frame = first_frame;
    c->last_frame = last_frame;
    c->snapshot = snapshot;
    c->bytes = sizeof *c;
    return c;
}

sy_result sy__changes_push(sy_changes *c, uint32_t type, uint32_t id, uint32_t flags, uint64_t mask,
                           const void *src_data, const sy_attachment *att, uint32_t natt, sy_error *err)
{
    const sy_type_desc *td = sy__type_desc(type);
    if (!td) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "change list: unknown object type %u", type);
    if (c->count == c->capacity) {
        uint32_t ncap = c->capacity ? c->capacity * 2 : 16;
        if (ncap <= c->capacity) return sy_error_set(err, SY_ERR_LIMIT, "change list: too many entries");
        sy_change *ne = realloc(c->entries, sizeof(sy_change) * ncap);
        if (!ne) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "change list: out of memory");
        c->entries = ne;
        c->capacity = ncap;
    }
    sy_change *e = &c->entries[c->count];
    memset(e, 0, sizeof *e);
    e->type = type;
    e->id = id;
    e->flags = flags;
    e->mask = mask & sy__type_full_mask(type);
    if (!(flags & SY_CHANGE_DESTROYED)) {
        void *d = sy__data_new(type);
        if (!d) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "change list: out of memory");
        for (uint32_t f = 0; f < td->field_count; ++f) {
            if (!(e->mask & SY_BIT(f))) continue;
            if (!sy__field_copy(type, f, d, src_data)) {
                sy__data_free(type, d);
                return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "change list: out of memory");
            }
            c->bytes += sy__field_heap_bytes(type, f, d);
        }
        if (e->mask & SY_BIT(SY_FIELD_ATTACHMENTS)) {
            sy_attachment *a;
            if (!sy__attachments_copy(att, natt, &a)) {
                sy__data_free(type, d);
                return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "change list: out of memory");
            }
            e->attachments = a;
            e->attachment_count = natt;
            c->bytes += natt * sizeof(sy_attachment);
        }
        e->data = d;
        c->bytes += td->data_size;
    } else {
        e->mask = 0;
    }
    c->bytes += sizeof *e;
    c->count++;
    return SY_OK;
}

static int change_order(const void *pa, const void *pb)
{
    const sy_change *a = pa, *b = pb;
    int da = (a->flags & SY_CHANGE_DESTROYED) ? 0 : 1, db = (b->flags & SY_CHANGE_DESTROYED) ? 0 : 1;
    if (da != db) return da - db;
    if (a->type != b->type) return a->type < b->type ? -1 : 1;
    if (a->id != b->id) return a->id < b->id ? -1 : 1;
    return 0;
}

void sy__changes_sort(sy_changes *c)
{
    if (c->count > 1) qsort(c->entries, c->count, sizeof(sy_change), change_order);
}

/* Merge: an open-addressing map from (type, id) to the output entry index. */
typedef struct merge_map {
    uint64_t *keys; /* 0 = empty (type is never 0) */
    uint32_t *vals;
    size_t capacity;
} merge_map;

static uint64_t mix64(uint64_t x)
{
    x ^= x >> 33;
    x *= 0xff51afd7ed558ccdull;
    x ^= x >> 33;
    return x;
}

sy_result sy__changes_merge(sy_changes *const *lists, uint32_t n, sy_changes **out, sy_error *err)
{
    *out = NULL;
    size_t total = 0;
    for (uint32_t i = 0; i < n; ++i) total += lists[i]->count;
    uint64_t first = n ? lists[0]->first_frame : 0, last = n ? lists[n - 1]->last_frame : 0;
    sy_changes *c = sy__changes_new(first, last, n && lists[0]->snapshot);
    merge_map m = {0};
    m.capacity = 16;
    while (m.capacity < total * 2) m.capacity *= 2;
    m.keys = calloc(m.capacity, sizeof *m.keys);
    m.vals = calloc(m.capacity, sizeof *m.vals);
    sy_result r = SY_OK;
    if (!c || !m.keys || !m.vals) {
        r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "change list merge: out of memory");
        goto fail;
    }
    for (uint32_t li = 0; li < n; ++li) {
        const sy_changes *src = lists[li];
        for (uint32_t ei = 0; ei < src->count; ++ei) {
            const sy_change *s = &src->entries[ei];
            uint64_t key = ((uint64_t)s->type << 32) | s->id;
            size_t h = (size_t)mix64(key) & (m.capacity - 1);
            while (m.keys[h] && m.keys[h] != key) h = (h + 1) & (m.capacity - 1);
            if (!m.keys[h]) {
                r = sy__changes_push(c, s->type, s->id, s->flags, s->mask, s->data, s->attachments,
                                     s->attachment_count, err);
                if (r != SY_OK) goto fail;
                m.keys[h] = key;
                m.vals[h] = c->count - 1;
                continue;
            }
            sy_change *d = &c->entries[m.vals[h]];
            if (s->flags & SY_CHANGE_DESTROYED) {
                /* created and destroyed within the range: the consumer never needs to know */
                bool was_created = (d->flags & SY_CHANGE_CREATED) != 0;
                sy__data_free(d->type, (void *)d->data);
                sy__attachments_free((sy_attachment *)d->attachments, d->attachment_count);
                d->data = NULL;
                d->attachments = NULL;
                d->attachment_count = 0;
                d->mask = 0;
                d->flags = was_created ? 0xffffffffu /* dropped below */ : SY_CHANGE_DESTROYED;
                continue;
            }
            d->flags |= s->flags;
            if (!d->data) {
                d->data = sy__data_new(d->type);
                if (!d->data) {
                    r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "change list merge: out of memory");
                    goto fail;
                }
            }
            const sy_type_desc *td = sy__type_desc(s->type);
            for (uint32_t f = 0; f < td->field_count; ++f)
                if ((s->mask & SY_BIT(f)) && !sy__field_copy(s->type, f, (void *)d->data, s->data)) {
                    r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "change list merge: out of memory");
                    goto fail;
                }
            if (s->mask & SY_BIT(SY_FIELD_ATTACHMENTS)) {
                sy_attachment *a;
                if (!sy__attachments_copy(s->attachments, s->attachment_count, &a)) {
                    r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "change list merge: out of memory");
                    goto fail;
                }
                sy__attachments_free((sy_attachment *)d->attachments, d->attachment_count);
                d->attachments = a;
                d->attachment_count = s->attachment_count;
            }
            d->mask |= s->mask;
        }
    }
    /* drop entries of objects created and destroyed within the range */
    uint32_t w = 0;
    for (uint32_t i = 0; i < c->count; ++i) {
        if (c->entries[i].flags == 0xffffffffu) continue;
        c->entries[w++] = c->entries[i];
    }
    c->count = w;
    sy__changes_sort(c);
    free(m.keys);
    free(m.vals);
    *out = c;
    return SY_OK;
fail:
    free(m.keys);
    free(m.vals);
    sy_changes_release(c);
    return r;
}
