/* sy_scene.c — object pools with generation-checked handles, validated field setters with dirty
 * tracking, incremental world matrices and bounds, commit into change lists, consumers with
 * cursors, log compaction, snapshots, replica apply and deep equality. See sy_scene.h.
 *
 * Sections: >>pools  >>dirty  >>graph  >>validation  >>setters  >>commit  >>apply  >>equal */
#include "sy_fields.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct node_extra {
    uint32_t *parents; /* parent node ids in attach order; [0] is the primary parent */
    uint32_t parent_count, parent_capacity;
    sy_mat4 world;
    sy_bounds local_bounds; /* subtree bounds in the node's own frame (before its transform) */
    uint8_t world_dirty, bounds_dirty;
    uint32_t mark; /* traversal epoch */
} node_extra;

typedef struct slot {
    uint32_t generation;
    uint8_t alive, retired, in_free_list;
    void *data;
    sy_attachment *att;
    uint32_t natt;
    uint64_t dirty_mask;
    uint32_t dirty_pos; /* 1 + index into scene->dirty for the live generation, 0 = none */
    node_extra *nx;     /* nodes only */
    sy_bounds bounds;   /* meshes only: local bounds */
    uint32_t *users;    /* meshes only: node ids using this mesh */
    uint32_t user_count, user_capacity;
} slot;

typedef struct pool {
    slot *slots; /* slot 0 is never used */
    uint32_t count, capacity;
    uint32_t *free_list;
    uint32_t free_count, free_capacity;
    uint32_t live;
} pool;

#define DIRTY_DROPPED 0x80000000u

typedef struct dirty_rec {
    uint32_t type;
    uint32_t id;
    uint32_t flags; /* SY_CHANGE_CREATED / DESTROYED / DIRTY_DROPPED */
} dirty_rec;

typedef struct consumer {
    bool used;
    bool needs_snapshot; /* snapshot to be taken at the next commit */
    sy_changes *snapshot;
    uint64_t cursor; /* frames <= cursor have been delivered */
} consumer;

typedef struct id_list {
    uint32_t *items;
    uint32_t count, capacity;
} id_list;

struct sy_scene {
    pool pools[SY_TYPE_COUNT];
    dirty_rec *dirty;
    uint32_t dirty_count, dirty_capacity;
    uint32_t dirty_dropped; /* records of objects created and destroyed in this frame (no change) */
    uint64_t frame;
    sy_changes **log; /* sealed lists, oldest first */
    uint32_t log_count, log_capacity;
    consumer *consumers;
    uint32_t consumer_capacity;
    id_list world_dirty, bounds_dirty, stack;
    uint32_t epoch;
    uint32_t last_world_updates;
    bool applying; /* replica apply: references may be stale, cycles checked afterwards */
    uint32_t apply_max_slots; /* replica policy: highest slot index + 1 a change list may create (0 = none) */
};

static bool list_push(id_list *l, uint32_t v)
{
    if (l->count == l->capacity) {
        uint32_t nc = l->capacity ? l->capacity * 2 : 64;
        uint32_t *ni = realloc(l->items, sizeof *ni * nc);
        if (!ni) return false;
        l->items = ni;
        l->capacity = nc;
    }
    l->items[l->count++] = v;
    return true;
}

static bool array_push(uint32_t **items, uint32_t *count, uint32_t *capacity, uint32_t v)
{
    if (*count == *capacity) {
        uint32_t nc = *capacity ? *capacity * 2 : 4;
        uint32_t *ni = realloc(*items, sizeof *ni * nc);
        if (!ni) return false;
        *items = ni;
        *capacity = nc;
    }
    (*items)[(*count)++] = v;
    return true;
}

static void array_remove(uint32_t *items, uint32_t *count, uint32_t v)
{
    for (uint32_t i = 0; i < *count; ++i)
        if (items[i] == v) {
            memmove(items + i, items + i + 1, sizeof *items * (*count - i - 1));
            (*count)--;
            return;
        }
}

/* >>pools */
static inline uint32_t id_index(uint32_t id) { return id & SY_HANDLE_INDEX_MASK; }
static inline uint32_t id_generation(uint32_t id) { return id >> SY_HANDLE_INDEX_BITS; }
static inline uint32_t make_id(uint32_t index, uint32_t gen) { return (gen << SY_HANDLE_INDEX_BITS) | index; }

static slot *lookup(const sy_scene *s, uint32_t type, uint32_t id)
{
    if (type == SY_TYPE_NONE || type >= SY_TYPE_COUNT || id == 0) return NULL;
    const pool *p = &s->pools[type];
    uint32_t idx = id_index(id);
    if (idx == 0 || idx >= p->count) return NULL;
    slot *sl = &p->slots[idx];
    if (!sl->alive || sl->generation != id_generation(id)) return NULL;
    return sl;
}

static node_extra *nx_of(const sy_scene *s, uint32_t node_id)
{
    slot *sl = lookup(s, SY_TYPE_NODE, node_id);
    return sl ? sl->nx : NULL;
}

static bool pool_grow(pool *p, uint32_t min_count)
{
    if (min_count <= p->capacity) return true;
    uint32_t nc = p->capacity ? p->capacity : 64;
    while (nc < min_count) nc *= 2;
    if (nc > SY_HANDLE_INDEX_MASK + 1) nc = SY_HANDLE_INDEX_MASK + 1;
    if (nc < min_count) return false;
    slot *ns = realloc(p->slots, sizeof *ns * nc);
    if (!ns) return false;
    memset(ns + p->capacity, 0, sizeof *ns * (nc - p->capacity));
    p->slots = ns;
    p->capacity = nc;
    return true;
}

/* Replica apply: grows the slot array to exactly min_count slots (no doubling), so the memory a
 * change list makes a replica allocate follows what the list creates (see apply_reserve). */
_Static_assert(sizeof(slot) + sizeof(uint32_t) <= SY_SCENE_SLOT_BYTES,
               "SY_SCENE_SLOT_BYTES is a slot + its free-list entry");

static bool pool_reserve_exact(pool *p, uint32_t min_count)
{
    if (min_count <= p->capacity) return true;
    if (min_count > SY_HANDLE_INDEX_MASK + 1) return false;
    slot *ns = realloc(p->slots, sizeof *ns * min_count);
    if (!ns) return false;
    memset(ns + p->capacity, 0, sizeof *ns * (min_count - p->capacity));
    p->slots = ns;
    p->capacity = min_count;
    return true;
}

static void free_list_push(pool *p, uint32_t idx)
{
    if (p->slots[idx].in_free_list || p->slots[idx].retired) return;
    uint32_t cnt = p->free_count;
    if (array_push(&p->free_list, &cnt, &p->free_capacity, idx)) {
        p->free_count = cnt;
        p->slots[idx].in_free_list = 1;
    }
    /* on out of memory the slot is simply not reused */
}

/* Fills a slot for a new object; the caller has chosen index and generation. */
static sy_result slot_init(sy_scene *s, uint32_t type, uint32_t idx, uint32_t gen, const char *name, sy_error *err)
{
    pool *p = &s->pools[type];
    slot *sl = &p->slots[idx];
    void *data = sy__data_new(type);
    node_extra *nx = NULL;
    char *name_copy = NULL;
    if (name) name_copy = strdup(name);
    if (type == SY_TYPE_NODE) nx = calloc(1, sizeof *nx);
    if (!data || (name && !name_copy) || (type == SY_TYPE_NODE && !nx)) {
        free(data);
        free(nx);
        free(name_copy);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "create %s: out of memory", sy__type_desc(type)->name);
    }
    *(char **)data = name_copy; /* name is the first member of every data struct */
    sl->generation = gen;
    sl->alive = 1;
    sl->data = data;
    sl->att = NULL;
    sl->natt = 0;
    sl->dirty_mask = 0;
    sl->dirty_pos = 0;
    sl->nx = nx;
    if (nx) {
        nx->world = sy_mat4_identity();
        nx->local_bounds = sy_bounds_empty();
    }
    sl->bounds = sy_bounds_empty();
    sl->users = NULL;
    sl->user_count = sl->user_capacity = 0;
    p->live++;
    return SY_OK;
}

/* >>dirty */
static bool mark_dirty(sy_scene *s, uint32_t type, uint32_t id, slot *sl, uint64_t bits, uint32_t flags)
{
    if (sl->dirty_pos == 0) {
        if (s->dirty_count == s->dirty_capacity) {
            uint32_t nc = s->dirty_capacity ? s->dirty_capacity * 2 : 256;
            dirty_rec *nd = realloc(s->dirty, sizeof *nd * nc);
            if (!nd) return false;
            s->dirty = nd;
            s->dirty_capacity = nc;
        }
        s->dirty[s->dirty_count] = (dirty_rec){type, id, flags};
        sl->dirty_pos = ++s->dirty_count;
    } else {
        s->dirty[sl->dirty_pos - 1].flags |= flags;
    }
    sl->dirty_mask |= bits;
    return true;
}

/* >>graph */
static void mark_world_dirty(sy_scene *s, uint32_t node_id)
{
    node_extra *nx = nx_of(s, node_id);
    if (!nx || nx->world_dirty) return;
    nx->world_dirty = 1;
    list_push(&s->world_dirty, node_id);
}

/* Marks node_id and every ancestor (along all parents) as needing new local bounds. */
static void mark_bounds_dirty(sy_scene *s, uint32_t node_id)
{
    id_list *st = &s->stack;
    st->count = 0;
    list_push(st, node_id);
    while (st->count) {
        uint32_t id = st->items[--st->count];
        node_extra *nx = nx_of(s, id);
        if (!nx || nx->bounds_dirty) continue;
        nx->bounds_dirty = 1;
        list_push(&s->bounds_dirty, id);
        for (uint32_t i = 0; i < nx->parent_count; ++i) list_push(st, nx->parents[i]);
    }
}

static void mark_parents_bounds_dirty(sy_scene *s, uint32_t node_id)
{
    node_extra *nx = nx_of(s, node_id);
    if (!nx) return;
    for (uint32_t i = 0; i < nx->parent_count; ++i) mark_bounds_dirty(s, nx->parents[i]);
}

static uint32_t primary_parent(const sy_scene *s, const node_extra *nx)
{
    for (uint32_t i = 0; i < nx->parent_count; ++i)
        if (lookup(s, SY_TYPE_NODE, nx->parents[i])) return nx->parents[i];
    return 0;
}

const uint32_t *sy_node_children(const sy_node_data *d, uint32_t *count_out)
{
    *count_out = d && d->children ? (uint32_t)(sy_blob_size(d->children) / 4) : 0;
    return *count_out ? (const uint32_t *)sy_blob_data(d->children) : NULL;
}

/* Recomputes world matrices of every world-dirty node and the part of its subtree placed
 * through it (children whose primary parent it is). Cost: the dirty subtrees only. */
static void update_world(sy_scene *s)
{
    uint32_t updates = 0;
    id_list *st = &s->stack;
    for (uint32_t i = 0; i < s->world_dirty.count; ++i) {
        uint32_t root = s->world_dirty.items[i];
        node_extra *rnx = nx_of(s, root);
        if (!rnx || !rnx->world_dirty) continue;
        st->count = 0;
        list_push(st, root);
        s->epoch++;
        while (st->count) {
            uint32_t id = st->items[--st->count];
            slot *sl = lookup(s, SY_TYPE_NODE, id);
            if (!sl || sl->nx->mark == s->epoch) continue; /* guards against cycles from bad input */
            node_extra *nx = sl->nx;
            nx->mark = s->epoch;
            const sy_node_data *d = sl->data;
            uint32_t pp = primary_parent(s, nx);
            node_extra *pnx = pp ? nx_of(s, pp) : NULL;
            nx->world = pnx ? sy_mat4_mul(&pnx->world, &d->transform.matrix) : d->transform.matrix;
            nx->world_dirty = 0;
            updates++;
            uint32_t nc;
            const uint32_t *ch = sy_node_children(d, &nc);
            for (uint32_t k = 0; k < nc; ++k) {
                node_extra *cnx = nx_of(s, ch[k]);
                if (cnx && primary_parent(s, cnx) == id) list_push(st, ch[k]);
            }
        }
    }
    s->world_dirty.count = 0;
    s->last_world_updates = updates;
}

/* Recomputes local bounds of bounds-dirty nodes in post order (children first). */
static void update_bounds(sy_scene *s)
{
    id_list *st = &s->stack;
    for (uint32_t i = 0; i < s->bounds_dirty.count; ++i) {
        uint32_t root = s->bounds_dirty.items[i];
        node_extra *rnx = nx_of(s, root);
        if (!rnx || !rnx->bounds_dirty) continue;
        st->count = 0;
        list_push(st, root);
        s->epoch++;
        while (st->count) {
            uint32_t id = st->items[st->count - 1];
            slot *sl = lookup(s, SY_TYPE_NODE, id);
            if (!sl || !sl->nx->bounds_dirty) {
                st->count--;
                continue;
            }
            const sy_node_data *d = sl->data;
            uint32_t nc;
            const uint32_t *ch = sy_node_children(d, &nc);
            if (sl->nx->mark != s->epoch) { /* first visit: push dirty children */
                sl->nx->mark = s->epoch;
                bool pushed = false;
                for (uint32_t k = 0; k < nc; ++k) {
                    node_extra *cnx = nx_of(s, ch[k]);
                    if (cnx && cnx->bounds_dirty && cnx->mark != s->epoch) {
                        list_push(st, ch[k]);
                        pushed = true;
                    }
                }
                if (pushed) continue;
            }
            st->count--;
            sy_bounds b = sy_bounds_empty();
            slot *ms = lookup(s, SY_TYPE_MESH, d->mesh.id);
            if (ms) b = ms->bounds;
            for (uint32_t k = 0; k < nc; ++k) {
                slot *cs = lookup(s, SY_TYPE_NODE, ch[k]);
                if (!cs || cs->nx->bounds_dirty) continue; /* a cycle from bad input: ignore */
                const sy_node_data *cd = cs->data;
                sy_bounds cb = sy_bounds_transform(&cs->nx->local_bounds, &cd->transform.matrix);
                sy_bounds_add_bounds(&b, &cb);
            }
            sl->nx->local_bounds = b;
            sl->nx->bounds_dirty = 0;
        }
    }
    s->bounds_dirty.count = 0;
}

/* true if `target` is reachable downwards from any of the n nodes `from` (used to refuse cycles):
 * one walk that visits each node once, however many of them share subtrees. An allocation failure
 * answers true (the change is refused rather than risking a cycle). */
static bool reaches(sy_scene *s, const uint32_t *from, uint32_t n, uint32_t target)
{
    id_list st = {0};
    s->epoch++;
    bool found = false;
    for (uint32_t i = 0; i < n && !found; ++i) found = !list_push(&st, from[i]);
    while (st.count && !found) {
        uint32_t id = st.items[--st.count];
        if (id == target) {
            found = true;
            break;
        }
        slot *sl = lookup(s, SY_TYPE_NODE, id);
        if (!sl || sl->nx->mark == s->epoch) continue;
        sl->nx->mark = s->epoch;
        uint32_t nc;
        const uint32_t *ch = sy_node_children(sl->data, &nc);
        for (uint32_t k = 0; k < nc && !found; ++k) found = !list_push(&st, ch[k]);
    }
    free(st.items);
    return found;
}

/* A cycle through a node whose children a change list set: one depth-first walk from all of them
 * (grey = on the walk's path, black = done; each node visited once, so a snapshot of a large
 * graph costs its size, not its size per changed node). *at names a node on the cycle. An
 * allocation failure answers true. */
static bool find_cycle(sy_scene *s, const sy_changes *changes, uint32_t *at)
{
    typedef struct frame {
        uint32_t id, next;
    } frame;
    frame *st = NULL;
    uint32_t depth = 0, cap = 0;
    uint32_t grey = s->epoch + 1u, black = s->epoch + 2u;
    s->epoch += 2u;
    bool found = false;
    uint32_t n = sy_changes_count(changes);
    for (uint32_t i = 0; i < n && !found; ++i) {
        const sy_change *e = sy_changes_get(changes, i);
        if (e->type != SY_TYPE_NODE || !(e->mask & SY_BIT(SY_NODE_CHILDREN))) continue;
        slot *root = lookup(s, SY_TYPE_NODE, e->id);
        if (!root || root->nx->mark == black) continue;
        depth = 0;
        uint32_t id = e->id;
        for (;;) {
            slot *sl = lookup(s, SY_TYPE_NODE, id);
            if (sl && sl->nx->mark == grey) {
                found = true;
                *at = id;
                break;
            }
            if (sl && sl->nx->mark != black) { /* enter */
                if (depth == cap) {
                    uint32_t nc = cap ? cap * 2u : 64u;
                    frame *ns = nc > cap ? realloc(st, sizeof *ns * nc) : NULL;
                    if (!ns) {
                        found = true;
                        *at = id;
                        break;
                    }
                    st = ns;
                    cap = nc;
                }
                sl->nx->mark = grey;
                st[depth++] = (frame){id, 0};
            }
            /* next child of the deepest frame, popping finished frames */
            id = 0;
            while (depth) {
                frame *f = &st[depth - 1];
                uint32_t nc;
                const uint32_t *ch = sy_node_children(sy_object_get(s, SY_TYPE_NODE, f->id), &nc);
                if (f->next < nc) {
                    id = ch[f->next++];
                    break;
                }
                lookup(s, SY_TYPE_NODE, f->id)->nx->mark = black;
                depth--;
            }
            if (!id) break;
        }
    }
    free(st);
    return found;
}

static int cmp_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

/* >>validation (one place for every field of every type) */
static bool finite_n(const float *v, int n)
{
    for (int i = 0; i < n; ++i)
        if (!isfinite(v[i])) return false;
    return true;
}

static bool ref_ok(const sy_scene *s, uint32_t type, uint32_t id)
{
    return id == 0 || s->applying || lookup(s, type, id) != NULL;
}

static sy_result check_texref(const sy_scene *s, const sy_texture_ref *t, const char *what, sy_error *err)
{
    if (!ref_ok(s, SY_TYPE_TEXTURE, t->texture.id))
        return sy_error_set(err, SY_ERR_INVALID_HANDLE, "material %s: stale texture handle %#x", what, t->texture.id);
    if (t->texcoord > 1)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "material %s: texcoord set %u (0 or 1 supported)", what,
                            t->texcoord);
    if (!isfinite(t->scale) || !finite_n(t->offset, 2) || !isfinite(t->rotation) || !finite_n(t->uv_scale, 2))
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "material %s: non-finite texture transform", what);
    return SY_OK;
}

static sy_result check_blob_elems(const sy_blob *b, size_t elem, uint32_t count, const char *what, uint32_t prim,
                                  sy_error *err)
{
    if (!b) return SY_OK;
    size_t need;
    if (!sy_size_mul(elem, count, &need) || sy_blob_size(b) != need)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                            "mesh primitive %u: %s holds %zu bytes, expected %u vertices x %zu bytes", prim, what,
                            sy_blob_size(b), count, elem);
    return SY_OK;
}

/* An X3D gradient: counts within SY_GRADIENT_MAX, finite non-negative colours, angles increasing
 * within (0, pi] (sky) and (0, pi/2] (ground), one angle fewer than colours. */
static sy_result check_gradient(const sy_gradient *g, sy_error *err)
{
    if (g->sky_count > SY_GRADIENT_MAX || g->ground_count > SY_GRADIENT_MAX)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "background: gradient has more than %u colours", SY_GRADIENT_MAX);
    if (g->ground_count && !g->sky_count)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "background: ground gradient without a sky colour");
    for (int part = 0; part < 2; ++part) {
        uint32_t n = part ? g->ground_count : g->sky_count;
        const float(*c)[3] = part ? g->ground_color : g->sky_color;
        const float *a = part ? g->ground_angle : g->sky_angle;
        float lim = part ? 1.5707964f : 3.1415927f, prev = 0.0f;
        const char *what = part ? "ground" : "sky";
        for (uint32_t i = 0; i < n; ++i)
            for (int k = 0; k < 3; ++k)
                if (!isfinite(c[i][k]) || c[i][k] < 0.0f)
                    return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "background: %s colour %u is not finite and >= 0",
                                        what, i);
        for (uint32_t i = 0; i + 1 < n; ++i) {
            if (!isfinite(a[i]) || a[i] <= prev || a[i] > lim)
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                                    "background: %s angle %u = %g must increase within (0, %g]", what, i, (double)a[i],
                                    (double)lim);
            prev = a[i];
        }
    }
    return SY_OK;
}

static sy_result check_primitive(const sy_scene *s, const sy_primitive *p, uint32_t i, sy_error *err)
{
    if (!p->positions) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "mesh primitive %u: no positions", i);
    size_t psize = sy_blob_size(p->positions);
    if (psize % 12 != 0 || psize / 12 > UINT32_MAX)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "mesh primitive %u: positions size %zu not a multiple of 12",
                            i, psize);
    uint32_t nv = (uint32_t)(psize / 12);
    const float *pos = sy_blob_data(p->positions);
    for (uint32_t v = 0; v < nv * 3; ++v)
        if (!(fabsf(pos[v]) <= SY_COORD_MAX))
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                                "mesh primitive %u: vertex %u has a position %s (%g; at most %g in size)", i, v / 3,
                                isfinite(pos[v]) ? "beyond the coordinate range" : "that is not finite",
                                (double)pos[v], (double)SY_COORD_MAX);
    sy_result r;
    if ((r = check_blob_elems(p->normals, 12, nv, "normals", i, err)) ||
        (r = check_blob_elems(p->tangents, 16, nv, "tangents", i, err)) ||
        (r = check_blob_elems(p->texcoords0, 8, nv, "texcoords0", i, err)) ||
        (r = check_blob_elems(p->texcoords1, 8, nv, "texcoords1", i, err)) ||
        (r = check_blob_elems(p->colors, 16, nv, "colors", i, err)))
        return r;
    if (p->topology >= SY_TOPOLOGY_COUNT)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "mesh primitive %u: unknown topology %u", i, p->topology);
    if (!isfinite(p->width) || p->width < 0.0f)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "mesh primitive %u: stroke width %g is not finite and >= 0", i,
                            (double)p->width);
    /* elements: triangles take index triples, lines pairs, points any count */
    uint32_t per = p->topology == SY_TOPOLOGY_TRIANGLES ? 3u : p->topology == SY_TOPOLOGY_LINES ? 2u : 1u;
    const char *whole = per == 3 ? "whole triangles" : "whole line segments (index pairs)";
    if (p->indices) {
        size_t isize = sy_blob_size(p->indices);
        if (isize % (4u * per) != 0)
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "mesh primitive %u: index data %zu bytes is not %s", i,
                                isize, per == 1 ? "whole uint32 indices" : whole);
        const uint32_t *idx = sy_blob_data(p->indices);
        for (size_t k = 0; k < isize / 4; ++k)
            if (idx[k] >= nv)
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                                    "mesh primitive %u: index %zu = %u is past the vertex count %u", i, k, idx[k], nv);
    } else if (nv % per != 0) {
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "mesh primitive %u: %u vertices without indices is not %s", i,
                            nv, whole);
    }
    if (!ref_ok(s, SY_TYPE_MATERIAL, p->material.id))
        return sy_error_set(err, SY_ERR_INVALID_HANDLE, "mesh primitive %u: stale material handle", i);
    return SY_OK;
}

static sy_result validate_field(sy_scene *s, uint32_t type, uint32_t id, uint32_t f, const void *v, sy_error *err)
{
    switch (type) {
    case SY_TYPE_NODE:
        switch (f) {
        case SY_NODE_TRANSFORM: {
            const sy_transform *t = v;
            if (t->mode > SY_TRANSFORM_MATRIX)
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "node: unknown transform mode %u", t->mode);
            if (!finite_n(t->translation, 3) || !finite_n(t->rotation, 4) || !finite_n(t->scale, 3) ||
                !sy_mat4_is_finite(&t->matrix))
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "node: non-finite transform");
            /* SY_COORD_MAX (sy_math.h): translations, scales and every matrix element */
            if (!sy_coords_in_range(t->translation, 3) || !sy_coords_in_range(t->scale, 3) ||
                !sy_coords_in_range(t->matrix.m, 16))
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                                    "node: transform beyond the coordinate range (translation (%g %g %g), scale "
                                    "(%g %g %g); at most %g in size)",
                                    (double)t->matrix.m[12], (double)t->matrix.m[13], (double)t->matrix.m[14],
                                    (double)t->scale[0], (double)t->scale[1], (double)t->scale[2],
                                    (double)SY_COORD_MAX);
            return SY_OK;
        }
        case SY_NODE_CHILDREN: {
            const sy_blob *b = *(sy_blob *const *)v;
            if (!b) return SY_OK;
            if (sy_blob_size(b) % 4 != 0)
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "node: child list of %zu bytes", sy_blob_size(b));
            uint32_t n = (uint32_t)(sy_blob_size(b) / 4);
            const uint32_t *ch = sy_blob_data(b);
            for (uint32_t i = 0; i < n; ++i) {
                if (ch[i] == 0 || (!s->applying && !lookup(s, SY_TYPE_NODE, ch[i])))
                    return sy_error_set(err, SY_ERR_INVALID_HANDLE, "node: child %u is a stale handle %#x", i, ch[i]);
                if (ch[i] == id)
                    return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "node: child %u is the node itself", i);
            }
            /* duplicates by sorting a copy (n log n: child lists of a million instances stay cheap) */
            if (n > 1) {
                uint32_t *sorted = malloc(sizeof *sorted * n);
                if (!sorted) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "node: %u children: out of memory", n);
                memcpy(sorted, ch, sizeof *sorted * n);
                qsort(sorted, n, sizeof *sorted, cmp_u32);
                uint32_t dup = 0;
                for (uint32_t i = 1; i < n && !dup; ++i)
                    if (sorted[i] == sorted[i - 1]) dup = sorted[i];
                free(sorted);
                if (dup) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "node: child %#x listed twice", dup);
            }
            if (!s->applying && reaches(s, ch, n, id))
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                                    "node: a child is the node's ancestor (the graph would have a cycle)");
            return SY_OK;
        }
        case SY_NODE_MESH:
            return ref_ok(s, SY_TYPE_MESH, ((const sy_mesh *)v)->id)
                       ? SY_OK
                       : sy_error_set(err, SY_ERR_INVALID_HANDLE, "node: stale mesh handle");
        case SY_NODE_LIGHT:
            return ref_ok(s, SY_TYPE_LIGHT, ((const sy_light *)v)->id)
                       ? SY_OK
                       : sy_error_set(err, SY_ERR_INVALID_HANDLE, "node: stale light handle");
        case SY_NODE_CAMERA:
            return ref_ok(s, SY_TYPE_CAMERA, ((const sy_camera *)v)->id)
                       ? SY_OK
                       : sy_error_set(err, SY_ERR_INVALID_HANDLE, "node: stale camera handle");
        case SY_NODE_FLAGS:
            if (*(const uint32_t *)v & ~(uint32_t)(SY_NODE_VISIBLE | SY_NODE_STATIC | SY_NODE_ANIMATED))
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "node: unknown flags %#x", *(const uint32_t *)v);
            return SY_OK;
        default: return SY_OK;
        }
    case SY_TYPE_MESH:
        if (f == SY_MESH_PRIMITIVES) {
            const sy_primitive_list *l = v;
            if (l->count && !l->items) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "mesh: NULL primitives");
            for (uint32_t i = 0; i < l->count; ++i) {
                sy_result r = check_primitive(s, &l->items[i], i, err);
                if (r) return r;
            }
        }
        return SY_OK;
    case SY_TYPE_MATERIAL: {
        const sy_field_desc *fd = &sy__type_desc(type)->fields[f];
        switch (f) {
        case SY_MATERIAL_NAME: return SY_OK;
        case SY_MATERIAL_BASE_COLOR_TEXTURE:
        case SY_MATERIAL_METALLIC_ROUGHNESS_TEXTURE:
        case SY_MATERIAL_NORMAL_TEXTURE:
        case SY_MATERIAL_OCCLUSION_TEXTURE:
        case SY_MATERIAL_EMISSIVE_TEXTURE:
        case SY_MATERIAL_TRANSMISSION_TEXTURE: return check_texref(s, v, fd->name, err);
        case SY_MATERIAL_ALPHA_MODE:
            return *(const uint32_t *)v <= SY_ALPHA_BLEND
                       ? SY_OK
                       : sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "material: unknown alpha mode %u",
                                      *(const uint32_t *)v);
        case SY_MATERIAL_DOUBLE_SIDED:
        case SY_MATERIAL_UNLIT:
            return *(const uint32_t *)v <= 1
                       ? SY_OK
                       : sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "material: %s must be 0 or 1", fd->name);
        default: {
            const float *fv = v;
            int n = (int)(fd->size / sizeof(float));
            for (int i = 0; i < n; ++i) {
                if (!isfinite(fv[i]))
                    return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "material: %s is not finite", fd->name);
                if (fv[i] < 0.0f)
                    return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "material: %s is negative (%g)", fd->name,
                                        (double)fv[i]);
            }
            if (f == SY_MATERIAL_IOR && fv[0] < 1.0f && fv[0] != 0.0f)
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "material: ior %g below 1", (double)fv[0]);
            return SY_OK;
        }
        }
    }
    case SY_TYPE_TEXTURE:
        if (f == SY_TEXTURE_INFO) {
            const sy_image_info *in = v;
            if (in->channels > 4 || in->format > SY_PIXEL_F32)
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "texture: %u channels, format %u", in->channels,
                                    in->format);
        } else if (f == SY_TEXTURE_SAMPLER) {
            const sy_sampler *sm = v;
            if (sm->wrap_s > SY_WRAP_MIRROR || sm->wrap_t > SY_WRAP_MIRROR || sm->min_filter > SY_FILTER_NEAREST ||
                sm->mag_filter > SY_FILTER_NEAREST)
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "texture: unknown sampler mode");
        }
        return SY_OK;
    case SY_TYPE_LIGHT:
        if (f == SY_LIGHT_NAME) return SY_OK;
        if (f == SY_LIGHT_TYPE)
            return *(const uint32_t *)v <= SY_LIGHT_DIRECTIONAL
                       ? SY_OK
                       : sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "light: unknown type %u", *(const uint32_t *)v);
        {
            const float *fv = v;
            int n = f == SY_LIGHT_COLOR ? 3 : 1;
            for (int i = 0; i < n; ++i)
                if (!isfinite(fv[i]) || fv[i] < 0.0f)
                    return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "light: %s must be finite and >= 0",
                                        sy__type_desc(type)->fields[f].name);
            if (f == SY_LIGHT_RANGE && !sy_coords_in_range(fv, 1))
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "light: range %g is beyond the coordinate range (%g)",
                                    (double)fv[0], (double)SY_COORD_MAX);
            /* KHR_lights_punctual: 0 <= inner < outer <= pi/2 (inner >= outer is read as a hard edge:
             * every back-end gets the light through the mirror, which orders them) */
            if ((f == SY_LIGHT_INNER_CONE || f == SY_LIGHT_OUTER_CONE) && fv[0] > 1.5707964f)
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "light: %s %g is beyond pi/2",
                                    sy__type_desc(type)->fields[f].name, (double)fv[0]);
        }
        return SY_OK;
    case SY_TYPE_CAMERA:
        if (f == SY_CAMERA_NAME) return SY_OK;
        if (f == SY_CAMERA_PROJECTION)
            return *(const uint32_t *)v <= SY_PROJECTION_ORTHOGRAPHIC
                       ? SY_OK
                       : sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "camera: unknown projection %u",
                                      *(const uint32_t *)v);
        {
            float x = *(const float *)v;
            const char *fn = sy__type_desc(type)->fields[f].name;
            if (!isfinite(x) || x < 0.0f)
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "camera: %s must be finite and >= 0", fn);
            if (f == SY_CAMERA_YFOV && (x <= 0.0f || x >= 3.14159f))
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "camera: yfov %g outside (0, pi)", (double)x);
            if (f == SY_CAMERA_ZNEAR && x <= 0.0f)
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "camera: znear must be > 0");
            if ((f == SY_CAMERA_ZNEAR || f == SY_CAMERA_ZFAR || f == SY_CAMERA_XMAG || f == SY_CAMERA_YMAG) &&
                x > SY_COORD_MAX)
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "camera: %s %g is beyond the coordinate range (%g)",
                                    fn, (double)x, (double)SY_COORD_MAX);
        }
        return SY_OK;
    case SY_TYPE_BACKGROUND:
        if (f == SY_BACKGROUND_COLOR && !finite_n(v, 4))
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "background: non-finite colour");
        if (f == SY_BACKGROUND_INTENSITY && (!isfinite(*(const float *)v) || *(const float *)v < 0.0f))
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "background: intensity must be finite and >= 0");
        if (f == SY_BACKGROUND_ENVIRONMENT && !ref_ok(s, SY_TYPE_TEXTURE, ((const sy_texture *)v)->id))
            return sy_error_set(err, SY_ERR_INVALID_HANDLE, "background: stale environment texture");
        if ((f == SY_BACKGROUND_ENVIRONMENT_VISIBLE || f == SY_BACKGROUND_DEFAULT_LIGHTING) && *(const uint32_t *)v > 1)
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "background: %s must be 0 or 1",
                                sy__type_desc(type)->fields[f].name);
        if (f == SY_BACKGROUND_GRADIENT) return check_gradient(v, err);
        return SY_OK;
    default: return SY_OK;
    }
}

/* >>setters */
sy_result sy_scene_create(sy_scene **out, sy_error *err)
{
    *out = calloc(1, sizeof **out);
    if (!*out) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "scene: out of memory");
    for (int t = 1; t < SY_TYPE_COUNT; ++t) (*out)->pools[t].count = 1; /* index 0 reserved */
    return SY_OK;
}

static void slot_release(slot *sl, uint32_t type)
{
    sy__data_free(type, sl->data);
    sy__attachments_free(sl->att, sl->natt);
    if (sl->nx) free(sl->nx->parents);
    free(sl->nx);
    free(sl->users);
    sl->data = NULL;
    sl->att = NULL;
    sl->natt = 0;
    sl->nx = NULL;
    sl->users = NULL;
    sl->user_count = sl->user_capacity = 0;
    sl->alive = 0;
}

void sy_scene_destroy(sy_scene *s)
{
    if (!s) return;
    for (int t = 1; t < SY_TYPE_COUNT; ++t) {
        pool *p = &s->pools[t];
        for (uint32_t i = 1; i < p->count; ++i)
            if (p->slots[i].alive) slot_release(&p->slots[i], (uint32_t)t);
        free(p->slots);
        free(p->free_list);
    }
    for (uint32_t i = 0; i < s->log_count; ++i) sy_changes_release(s->log[i]);
    for (uint32_t i = 0; i < s->consumer_capacity; ++i) sy_changes_release(s->consumers[i].snapshot);
    free(s->log);
    free(s->consumers);
    free(s->dirty);
    free(s->world_dirty.items);
    free(s->bounds_dirty.items);
    free(s->stack.items);
    free(s);
}

sy_result sy_object_create(sy_scene *s, sy_object_type t, const char *name, uint32_t *id_out, sy_error *err)
{
    *id_out = 0;
    const sy_type_desc *td = sy__type_desc(t);
    if (!td) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "create: unknown object type %d", (int)t);
    pool *p = &s->pools[t];
    uint32_t idx = 0;
    while (p->free_count) {
        uint32_t cand = p->free_list[--p->free_count];
        p->slots[cand].in_free_list = 0;
        if (!p->slots[cand].alive && !p->slots[cand].retired) {
            idx = cand;
            break;
        }
    }
    if (!idx) {
        if (p->count > SY_HANDLE_INDEX_MASK)
            return sy_error_set(err, SY_ERR_LIMIT, "create %s: more than %u objects", td->name, SY_HANDLE_INDEX_MASK);
        if (!pool_grow(p, p->count + 1)) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "create %s: out of memory", td->name);
        idx = p->count++;
    }
    uint32_t gen = p->slots[idx].generation + 1; /* a fresh slot starts at generation 1 */
    sy_result r = slot_init(s, t, idx, gen, name, err);
    if (r != SY_OK) {
        free_list_push(p, idx);
        return r;
    }
    uint32_t id = make_id(idx, gen);
    slot *sl = &p->slots[idx];
    if (!mark_dirty(s, t, id, sl, 0, SY_CHANGE_CREATED)) {
        slot_release(sl, t);
        p->live--;
        free_list_push(p, idx);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "create %s: out of memory", td->name);
    }
    *id_out = id;
    return SY_OK;
}

/* Replica: create exactly this id. */
static sy_result object_create_at(sy_scene *s, uint32_t t, uint32_t id, sy_error *err)
{
    const sy_type_desc *td = sy__type_desc(t);
    pool *p = &s->pools[t];
    uint32_t idx = id_index(id), gen = id_generation(id);
    if (idx == 0 || gen == 0) return sy_error_set(err, SY_ERR_INVALID_HANDLE, "create %s %#x: invalid id", td->name, id);
    if (s->applying && s->apply_max_slots && idx >= s->apply_max_slots)
        return sy_error_set(err, SY_ERR_LIMIT, "create %s %#x: slot index %u exceeds this replica's limit of %u", td->name,
                            id, idx, s->apply_max_slots);
    if (idx >= p->count) {
        if (!pool_grow(p, idx + 1)) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "create %s: out of memory", td->name);
        for (uint32_t i = p->count; i < idx; ++i) free_list_push(p, i);
        p->count = idx + 1;
    }
    slot *sl = &p->slots[idx];
    if (sl->alive)
        return sy_error_set(err, SY_ERR_INVALID_HANDLE, "create %s %#x: slot holds a live object", td->name, id);
    if (gen <= sl->generation && sl->generation != 0)
        return sy_error_set(err, SY_ERR_INVALID_HANDLE, "create %s %#x: generation goes backwards", td->name, id);
    sy_result r = slot_init(s, t, idx, gen, NULL, err);
    if (r != SY_OK) return r;
    if (!mark_dirty(s, t, id, sl, 0, SY_CHANGE_CREATED)) {
        slot_release(sl, t);
        p->live--;
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "create %s: out of memory", td->name);
    }
    return SY_OK;
}

#define TYPED_CREATE(fn, T, type)                                                                       \
    sy_result fn(sy_scene *s, const char *name, T *out, sy_error *err)                                  \
    {                                                                                                   \
        return sy_object_create(s, type, name, &out->id, err);                                          \
    }
TYPED_CREATE(sy_node_create, sy_node, SY_TYPE_NODE)
TYPED_CREATE(sy_mesh_create, sy_mesh, SY_TYPE_MESH)
TYPED_CREATE(sy_material_create, sy_material, SY_TYPE_MATERIAL)
TYPED_CREATE(sy_texture_create, sy_texture, SY_TYPE_TEXTURE)
TYPED_CREATE(sy_light_create, sy_light, SY_TYPE_LIGHT)
TYPED_CREATE(sy_camera_create, sy_camera, SY_TYPE_CAMERA)
TYPED_CREATE(sy_background_create, sy_background, SY_TYPE_BACKGROUND)
#undef TYPED_CREATE

/* Updates parent lists and dirty marks of a node whose child list goes from old to new. */
static void children_changed(sy_scene *s, uint32_t id, const sy_blob *oldb, const sy_blob *newb)
{
    uint32_t no = oldb ? (uint32_t)(sy_blob_size(oldb) / 4) : 0, nn = newb ? (uint32_t)(sy_blob_size(newb) / 4) : 0;
    const uint32_t *o = oldb ? sy_blob_data(oldb) : NULL, *n = newb ? sy_blob_data(newb) : NULL;
    for (uint32_t i = 0; i < no; ++i) {
        bool kept = false;
        for (uint32_t j = 0; j < nn && !kept; ++j) kept = n[j] == o[i];
        node_extra *cnx = nx_of(s, o[i]);
        if (kept || !cnx) continue;
        array_remove(cnx->parents, &cnx->parent_count, id);
        mark_world_dirty(s, o[i]);
    }
    for (uint32_t j = 0; j < nn; ++j) {
        bool existed = false;
        for (uint32_t i = 0; i < no && !existed; ++i) existed = o[i] == n[j];
        node_extra *cnx = nx_of(s, n[j]);
        if (existed || !cnx) continue;
        array_push(&cnx->parents, &cnx->parent_count, &cnx->parent_capacity, id);
        mark_world_dirty(s, n[j]);
    }
    mark_bounds_dirty(s, id);
}

static void mesh_users_changed(sy_scene *s, uint32_t node_id, uint32_t old_mesh, uint32_t new_mesh)
{
    slot *om = lookup(s, SY_TYPE_MESH, old_mesh), *nm = lookup(s, SY_TYPE_MESH, new_mesh);
    if (om) array_remove(om->users, &om->user_count, node_id);
    if (nm) array_push(&nm->users, &nm->user_count, &nm->user_capacity, node_id);
    mark_bounds_dirty(s, node_id);
}

static void mesh_bounds_update(sy_scene *s, slot *sl)
{
    const sy_mesh_data *d = sl->data;
    sy_bounds b = sy_bounds_empty();
    for (uint32_t i = 0; i < d->primitives.count; ++i) {
        const sy_primitive *pr = &d->primitives.items[i];
        sy_bounds pb = sy_primitive_position_bounds(pr);
        if (pr->topology != SY_TOPOLOGY_TRIANGLES && !sy_bounds_is_empty(&pb)) {
            float r = 0.5f * sy_primitive_stroke_width(pr, &pb); /* strokes reach half a width out */
            for (int k = 0; k < 3; ++k) {
                pb.min[k] -= r;
                pb.max[k] += r;
            }
        }
        sy_bounds_add_bounds(&b, &pb);
    }
    sl->bounds = b;
    for (uint32_t i = 0; i < sl->user_count; ++i) mark_bounds_dirty(s, sl->users[i]);
}

sy_result sy_object_set_field(sy_scene *s, sy_object_type t, uint32_t id, uint32_t field, const void *value,
                              sy_error *err)
{
    slot *sl = lookup(s, t, id);
    if (!sl) return sy_error_set(err, SY_ERR_INVALID_HANDLE, "set: stale or invalid %s handle %#x", sy_object_type_name(t), id);
    const sy_type_desc *td = sy__type_desc(t);
    if (field >= td->field_count)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "set: %s has no field %u", td->name, field);
    sy_transform trs_fixed;
    if (t == SY_TYPE_NODE && field == SY_NODE_TRANSFORM) {
        trs_fixed = *(const sy_transform *)value;
        if (trs_fixed.mode == SY_TRANSFORM_TRS)
            trs_fixed.matrix = sy_mat4_from_trs(trs_fixed.translation, trs_fixed.rotation, trs_fixed.scale);
        value = &trs_fixed;
    }
    if (t == SY_TYPE_MESH && field == SY_MESH_PRIMITIVES && ((const sy_primitive_list *)value)->count &&
        !((const sy_primitive_list *)value)->items)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "mesh: NULL primitives");
    /* Build a source struct holding the value at the field's offset (the generic copy reads it there). */
#define SY_MAX2_(a, b) ((a) > (b) ? (a) : (b))
    _Alignas(16) unsigned char src[SY_MAX2_(sizeof(sy_background_data), SY_MAX2_(sizeof(sy_material_data), sizeof(sy_node_data)))];
#undef SY_MAX2_
    _Static_assert(sizeof(sy_texture_data) <= sizeof src && sizeof(sy_mesh_data) <= sizeof src &&
                       sizeof(sy_light_data) <= sizeof src && sizeof(sy_camera_data) <= sizeof src &&
                       sizeof(sy_background_data) <= sizeof src,
                   "scratch buffer too small");
    const sy_field_desc *fd = &td->fields[field];
    memcpy(src + fd->offset, value, fd->size);
    /* The no-op test comes before validation: re-setting the value a field already holds succeeds
     * even when it names an object destroyed since (stale references are kept, read as absent). */
    if (sy__field_equal(t, field, sl->data, src)) return SY_OK;
    sy_result r = validate_field(s, t, id, field, value, err);
    if (r != SY_OK) return r;

    sy_blob *old_children = NULL;
    uint32_t old_mesh = 0;
    if (t == SY_TYPE_NODE && field == SY_NODE_CHILDREN)
        old_children = sy_blob_retain(((sy_node_data *)sl->data)->children);
    if (t == SY_TYPE_NODE && field == SY_NODE_MESH) old_mesh = ((sy_node_data *)sl->data)->mesh.id;
    if (!sy__field_copy(t, field, sl->data, src)) {
        sy_blob_release(old_children);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "set %s.%s: out of memory", td->name, fd->name);
    }
    if (!mark_dirty(s, t, id, sl, SY_BIT(field), 0)) {
        sy_blob_release(old_children);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "set %s.%s: out of memory", td->name, fd->name);
    }
    if (t == SY_TYPE_NODE) {
        const sy_node_data *d = sl->data;
        switch (field) {
        case SY_NODE_TRANSFORM:
            mark_world_dirty(s, id);
            mark_parents_bounds_dirty(s, id);
            break;
        case SY_NODE_CHILDREN: children_changed(s, id, old_children, d->children); break;
        case SY_NODE_MESH: mesh_users_changed(s, id, old_mesh, d->mesh.id); break;
        default: break;
        }
    } else if (t == SY_TYPE_MESH && field == SY_MESH_PRIMITIVES) {
        mesh_bounds_update(s, sl);
    }
    sy_blob_release(old_children);
    return SY_OK;
}

sy_result sy_object_destroy(sy_scene *s, sy_object_type t, uint32_t id, sy_error *err)
{
    slot *sl = lookup(s, t, id);
    if (!sl) return sy_error_set(err, SY_ERR_INVALID_HANDLE, "destroy: stale or invalid %s handle %#x", sy_object_type_name(t), id);
    pool *p = &s->pools[t];
    /* record the destruction (or drop a creation nobody has seen) */
    if (sl->dirty_pos) {
        dirty_rec *rec = &s->dirty[sl->dirty_pos - 1];
        if (rec->flags & SY_CHANGE_CREATED) s->dirty_dropped++;
        rec->flags = (rec->flags & SY_CHANGE_CREATED) ? DIRTY_DROPPED : SY_CHANGE_DESTROYED;
    } else if (!mark_dirty(s, t, id, sl, 0, SY_CHANGE_DESTROYED)) {
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "destroy: out of memory");
    }
    sl->dirty_pos = 0;
    sl->dirty_mask = 0;
    if (t == SY_TYPE_NODE) {
        const sy_node_data *d = sl->data;
        mark_parents_bounds_dirty(s, id);
        /* parents keep the stale child id in their lists; readers skip it */
        uint32_t nc;
        const uint32_t *ch = sy_node_children(d, &nc);
        for (uint32_t k = 0; k < nc; ++k) {
            node_extra *cnx = nx_of(s, ch[k]);
            if (!cnx) continue;
            array_remove(cnx->parents, &cnx->parent_count, id);
            mark_world_dirty(s, ch[k]);
        }
        slot *ms = lookup(s, SY_TYPE_MESH, d->mesh.id);
        if (ms) array_remove(ms->users, &ms->user_count, id);
    } else if (t == SY_TYPE_MESH) {
        for (uint32_t i = 0; i < sl->user_count; ++i) mark_bounds_dirty(s, sl->users[i]);
    }
    slot_release(sl, t);
    p->live--;
    if (sl->generation >= SY_HANDLE_MAX_GENERATION) sl->retired = 1; /* never reuse: ids stay unique */
    free_list_push(p, id_index(id));
    return SY_OK;
}

bool sy_object_is_valid(const sy_scene *s, sy_object_type t, uint32_t id) { return lookup(s, t, id) != NULL; }

const void *sy_object_get(const sy_scene *s, sy_object_type t, uint32_t id)
{
    slot *sl = lookup(s, t, id);
    return sl ? sl->data : NULL;
}

uint32_t sy_scene_next(const sy_scene *s, sy_object_type t, uint32_t prev_id)
{
    if (t == SY_TYPE_NONE || t >= SY_TYPE_COUNT) return 0;
    const pool *p = &s->pools[t];
    for (uint32_t i = prev_id ? id_index(prev_id) + 1 : 1; i < p->count; ++i)
        if (p->slots[i].alive) return make_id(i, p->slots[i].generation);
    return 0;
}

uint32_t sy_scene_count(const sy_scene *s, sy_object_type t)
{
    return (t == SY_TYPE_NONE || t >= SY_TYPE_COUNT) ? 0 : s->pools[t].live;
}

sy_result sy_node_set_trs(sy_scene *s, sy_node n, const float t[3], const float r[4], const float sc[3], sy_error *err)
{
    sy_transform tr = {.mode = SY_TRANSFORM_TRS};
    memcpy(tr.translation, t, sizeof tr.translation);
    memcpy(tr.rotation, r, sizeof tr.rotation);
    memcpy(tr.scale, sc, sizeof tr.scale);
    tr.matrix = sy_mat4_from_trs(t, r, sc);
    return sy_object_set_field(s, SY_TYPE_NODE, n.id, SY_NODE_TRANSFORM, &tr, err);
}

sy_result sy_node_set_matrix(sy_scene *s, sy_node n, const sy_mat4 *m, sy_error *err)
{
    sy_transform tr = {.mode = SY_TRANSFORM_MATRIX, .rotation = {0, 0, 0, 1}, .scale = {1, 1, 1}, .matrix = *m};
    return sy_object_set_field(s, SY_TYPE_NODE, n.id, SY_NODE_TRANSFORM, &tr, err);
}

sy_result sy_node_set_children(sy_scene *s, sy_node n, const sy_node *children, uint32_t count, sy_error *err)
{
    sy_blob *b = NULL;
    if (count) {
        _Static_assert(sizeof(sy_node) == sizeof(uint32_t), "sy_node is one uint32");
        sy_result r = sy_blob_create_copy(children, sizeof(uint32_t) * (size_t)count, &b, err);
        if (r != SY_OK) return r;
    }
    sy_result r = sy_object_set_field(s, SY_TYPE_NODE, n.id, SY_NODE_CHILDREN, &b, err);
    sy_blob_release(b);
    return r;
}

sy_result sy_node_add_child(sy_scene *s, sy_node parent, sy_node child, sy_error *err)
{
    const sy_node_data *d = sy_node_get(s, parent);
    if (!d) return sy_error_set(err, SY_ERR_INVALID_HANDLE, "add child: stale parent handle");
    uint32_t nc;
    const uint32_t *ch = sy_node_children(d, &nc);
    sy_node *list = malloc(sizeof *list * ((size_t)nc + 1));
    if (!list) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "add child: out of memory");
    /* children destroyed since stay in the list as stale ids (readers skip them); drop them here,
     * or the new list would be refused for holding a stale child */
    uint32_t n = 0;
    for (uint32_t i = 0; i < nc; ++i)
        if (lookup(s, SY_TYPE_NODE, ch[i])) list[n++].id = ch[i];
    list[n] = child;
    sy_result r = sy_node_set_children(s, parent, list, n + 1, err);
    free(list);
    return r;
}

sy_result sy_node_set_mesh(sy_scene *s, sy_node n, sy_mesh m, sy_error *err)
{
    return sy_object_set_field(s, SY_TYPE_NODE, n.id, SY_NODE_MESH, &m, err);
}
sy_result sy_node_set_light(sy_scene *s, sy_node n, sy_light l, sy_error *err)
{
    return sy_object_set_field(s, SY_TYPE_NODE, n.id, SY_NODE_LIGHT, &l, err);
}
sy_result sy_node_set_camera(sy_scene *s, sy_node n, sy_camera c, sy_error *err)
{
    return sy_object_set_field(s, SY_TYPE_NODE, n.id, SY_NODE_CAMERA, &c, err);
}
sy_result sy_node_set_flags(sy_scene *s, sy_node n, uint32_t flags, sy_error *err)
{
    return sy_object_set_field(s, SY_TYPE_NODE, n.id, SY_NODE_FLAGS, &flags, err);
}

sy_result sy_mesh_set_primitives(sy_scene *s, sy_mesh m, const sy_primitive *prims, uint32_t count, sy_error *err)
{
    sy_primitive_list l = {(sy_primitive *)prims, count};
    return sy_object_set_field(s, SY_TYPE_MESH, m.id, SY_MESH_PRIMITIVES, &l, err);
}

/* Sets every field of a whole data struct; validation of all fields first, so a bad value leaves
 * the object unchanged. */
static sy_result set_all(sy_scene *s, uint32_t t, uint32_t id, const void *d, sy_error *err)
{
    const sy_type_desc *td = sy__type_desc(t);
    slot *sl = lookup(s, t, id);
    if (!sl) return sy_error_set(err, SY_ERR_INVALID_HANDLE, "set: stale or invalid %s handle %#x", td->name, id);
    for (uint32_t f = 0; f < td->field_count; ++f) {
        if (sy__field_equal(t, f, sl->data, d)) continue; /* unchanged: may hold a stale reference */
        sy_result r = validate_field(s, t, id, f, (const char *)d + td->fields[f].offset, err);
        if (r != SY_OK) return r;
    }
    for (uint32_t f = 0; f < td->field_count; ++f) {
        sy_result r = sy_object_set_field(s, t, id, f, (const char *)d + td->fields[f].offset, err);
        if (r != SY_OK) return r;
    }
    return SY_OK;
}

sy_result sy_material_set(sy_scene *s, sy_material m, const sy_material_data *d, sy_error *err)
{
    return set_all(s, SY_TYPE_MATERIAL, m.id, d, err);
}
sy_result sy_light_set(sy_scene *s, sy_light l, const sy_light_data *d, sy_error *err)
{
    return set_all(s, SY_TYPE_LIGHT, l.id, d, err);
}
sy_result sy_camera_set(sy_scene *s, sy_camera c, const sy_camera_data *d, sy_error *err)
{
    return set_all(s, SY_TYPE_CAMERA, c.id, d, err);
}
sy_result sy_background_set(sy_scene *s, sy_background b, const sy_background_data *d, sy_error *err)
{
    return set_all(s, SY_TYPE_BACKGROUND, b.id, d, err);
}

sy_result sy_texture_set_image(sy_scene *s, sy_texture t, const sy_image_info *info, sy_blob *pixels, sy_error *err)
{
    if (!lookup(s, SY_TYPE_TEXTURE, t.id)) return sy_error_set(err, SY_ERR_INVALID_HANDLE, "texture: stale handle");
    if (info->channels < 1 || info->channels > 4 || info->format < SY_PIXEL_U8_SRGB || info->format > SY_PIXEL_F32 ||
        info->width == 0 || info->height == 0)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "texture: bad image %ux%u, %u channels, format %u",
                            info->width, info->height, info->channels, info->format);
    size_t need, elem = info->format == SY_PIXEL_F32 ? 4 : 1;
    if (!sy_size_mul(info->width, info->height, &need) || !sy_size_mul(need, info->channels, &need) ||
        !sy_size_mul(need, elem, &need) || !pixels || sy_blob_size(pixels) != need)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "texture: %ux%ux%u image needs %zu bytes, blob has %zu",
                            info->width, info->height, info->channels, need, sy_blob_size(pixels));
    sy_result r = sy_object_set_field(s, SY_TYPE_TEXTURE, t.id, SY_TEXTURE_INFO, info, err);
    if (r == SY_OK) r = sy_object_set_field(s, SY_TYPE_TEXTURE, t.id, SY_TEXTURE_PIXELS, &pixels, err);
    return r;
}

sy_result sy_texture_set_sampler(sy_scene *s, sy_texture t, const sy_sampler *smp, sy_error *err)
{
    return sy_object_set_field(s, SY_TYPE_TEXTURE, t.id, SY_TEXTURE_SAMPLER, smp, err);
}

const sy_node_data *sy_node_get(const sy_scene *s, sy_node n) { return sy_object_get(s, SY_TYPE_NODE, n.id); }
const sy_mesh_data *sy_mesh_get(const sy_scene *s, sy_mesh m) { return sy_object_get(s, SY_TYPE_MESH, m.id); }
const sy_material_data *sy_material_get(const sy_scene *s, sy_material m)
{
    if (m.id == 0) return sy_object_defaults(SY_TYPE_MATERIAL);
    return sy_object_get(s, SY_TYPE_MATERIAL, m.id);
}
const sy_texture_data *sy_texture_get(const sy_scene *s, sy_texture t) { return sy_object_get(s, SY_TYPE_TEXTURE, t.id); }
const sy_light_data *sy_light_get(const sy_scene *s, sy_light l) { return sy_object_get(s, SY_TYPE_LIGHT, l.id); }
const sy_camera_data *sy_camera_get(const sy_scene *s, sy_camera c) { return sy_object_get(s, SY_TYPE_CAMERA, c.id); }
const sy_background_data *sy_background_get(const sy_scene *s, sy_background b)
{
    return sy_object_get(s, SY_TYPE_BACKGROUND, b.id);
}

uint32_t sy_primitive_vertex_count(const sy_primitive *p) { return (uint32_t)(sy_blob_size(p->positions) / 12); }
uint32_t sy_primitive_triangle_count(const sy_primitive *p)
{
    return p->topology == SY_TOPOLOGY_TRIANGLES ? sy_primitive_element_count(p) : 0u;
}

uint32_t sy_primitive_element_count(const sy_primitive *p)
{
    uint32_t per = p->topology == SY_TOPOLOGY_TRIANGLES ? 3u : p->topology == SY_TOPOLOGY_LINES ? 2u : 1u;
    return p->indices ? (uint32_t)(sy_blob_size(p->indices) / (4u * per)) : sy_primitive_vertex_count(p) / per;
}

sy_bounds sy_primitive_position_bounds(const sy_primitive *p)
{
    sy_bounds b = sy_bounds_empty();
    const float *v = sy_blob_data(p->positions);
    size_t n = sy_blob_size(p->positions) / 12;
    for (size_t k = 0; v && k < n; ++k) sy_bounds_add_point(&b, v + 3 * k);
    return b;
}

float sy_primitive_stroke_width(const sy_primitive *p, const sy_bounds *primitive_bounds)
{
    if (p->topology == SY_TOPOLOGY_TRIANGLES) return 0.0f;
    if (p->width > 0.0f && isfinite(p->width)) return p->width;
    sy_bounds own;
    if (!primitive_bounds) {
        own = sy_primitive_position_bounds(p);
        primitive_bounds = &own;
    }
    float diag = 0.0f;
    if (!sy_bounds_is_empty(primitive_bounds)) {
        float d[3];
        for (int k = 0; k < 3; ++k) d[k] = primitive_bounds->max[k] - primitive_bounds->min[k];
        diag = sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    }
    float f = p->topology == SY_TOPOLOGY_POINTS ? SY_STROKE_POINT_FRACTION : SY_STROKE_LINE_FRACTION;
    float w = f * diag;
    return isfinite(w) && w > SY_STROKE_MIN_WIDTH ? w : SY_STROKE_MIN_WIDTH;
}

void sy_primitive_release(sy_primitive *p) { sy__primitive_release(p); }

bool sy_texture_ref_matrix(const sy_texture_ref *r, float m[6])
{
    /* KHR_texture_transform (ratified): uv' = offset + R (uv_scale * uv), R = [cos sin; -sin cos]
     * (GLSL mat3(cos, -sin, 0, sin, cos, 0, 0, 0, 1)); the Khronos TextureTransformTest model's
     * markers confirm the direction (tests/integration/test_texture_transform.c). */
    float c = cosf(r->rotation), s = sinf(r->rotation);
    m[0] = c * r->uv_scale[0], m[1] = s * r->uv_scale[1], m[2] = r->offset[0];
    m[3] = -s * r->uv_scale[0], m[4] = c * r->uv_scale[1], m[5] = r->offset[1];
    return r->offset[0] != 0.0f || r->offset[1] != 0.0f || r->rotation != 0.0f || r->uv_scale[0] != 1.0f ||
           r->uv_scale[1] != 1.0f;
}

/* >>attachments */
static sy_result set_attachments(sy_scene *s, uint32_t t, uint32_t id, slot *sl, sy_attachment *a, uint32_t n,
                                 sy_error *err)
{
    if (!mark_dirty(s, t, id, sl, SY_BIT(SY_FIELD_ATTACHMENTS), 0)) {
        sy__attachments_free(a, n);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "attachment: out of memory");
    }
    sy__attachments_free(sl->att, sl->natt);
    sl->att = a;
    sl->natt = n;
    return SY_OK;
}

sy_result sy_object_set_attachment(sy_scene *s, sy_object_type t, uint32_t id, const sy_attachment *a, sy_error *err)
{
    slot *sl = lookup(s, t, id);
    if (!sl) return sy_error_set(err, SY_ERR_INVALID_HANDLE, "attachment: stale or invalid %s handle", sy_object_type_name(t));
    if (!a->key || !a->key[0]) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "attachment: empty key");
    if (a->kind < SY_ATTACH_INT || a->kind > SY_ATTACH_BLOB)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "attachment '%s': unknown kind %u", a->key, a->kind);
    if (a->kind == SY_ATTACH_STRING && !a->value.s)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "attachment '%s': NULL string", a->key);
    /* keep keys sorted: find the position */
    uint32_t pos = 0;
    while (pos < sl->natt && strcmp(sl->att[pos].key, a->key) < 0) pos++;
    bool replace = pos < sl->natt && strcmp(sl->att[pos].key, a->key) == 0;
    if (replace && sy__attachments_equal(&sl->att[pos], 1, a, 1)) return SY_OK;
    uint32_t n = sl->natt + (replace ? 0 : 1);
    sy_attachment *na = calloc(n, sizeof *na);
    if (!na) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "attachment: out of memory");
    /* build the new array as copies: old entries before/after pos plus the new one */
    sy_attachment *tmp = NULL;
    bool ok = true;
    uint32_t w = 0;
    for (uint32_t i = 0; i < sl->natt && ok; ++i) {
        if (i == pos) {
            ok = sy__attachments_copy(a, 1, &tmp);
            if (ok) na[w++] = *tmp, free(tmp);
            if (replace) continue;
        }
        ok = ok && sy__attachments_copy(&sl->att[i], 1, &tmp);
        if (ok) na[w++] = *tmp, free(tmp);
    }
    if (ok && pos == sl->natt) {
        ok = sy__attachments_copy(a, 1, &tmp);
        if (ok) na[w++] = *tmp, free(tmp);
    }
    if (!ok) {
        sy__attachments_free(na, w);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "attachment: out of memory");
    }
    return set_attachments(s, t, id, sl, na, w, err);
}

sy_result sy_object_remove_attachment(sy_scene *s, sy_object_type t, uint32_t id, const char *key, sy_error *err)
{
    slot *sl = lookup(s, t, id);
    if (!sl) return sy_error_set(err, SY_ERR_INVALID_HANDLE, "attachment: stale or invalid %s handle", sy_object_type_name(t));
    uint32_t pos = 0;
    while (pos < sl->natt && strcmp(sl->att[pos].key, key) != 0) pos++;
    if (pos == sl->natt) return sy_error_set(err, SY_ERR_NOT_FOUND, "attachment '%s' not found", key);
    sy_attachment *na = NULL;
    uint32_t n = sl->natt - 1;
    if (n) {
        sy_attachment *before = NULL, *after = NULL;
        na = calloc(n, sizeof *na);
        bool ok = na && sy__attachments_copy(sl->att, pos, &before) &&
                  sy__attachments_copy(sl->att + pos + 1, sl->natt - pos - 1, &after);
        if (!ok) {
            sy__attachments_free(before, pos);
            free(na);
            return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "attachment: out of memory");
        }
        if (pos) memcpy(na, before, sizeof *na * pos);
        if (n - pos) memcpy(na + pos, after, sizeof *na * (n - pos));
        free(before);
        free(after);
    }
    return set_attachments(s, t, id, sl, na, n, err);
}

const sy_attachment *sy_object_attachments(const sy_scene *s, sy_object_type t, uint32_t id, uint32_t *count_out)
{
    slot *sl = lookup(s, t, id);
    *count_out = sl ? sl->natt : 0;
    return sl ? sl->att : NULL;
}

const sy_attachment *sy_object_find_attachment(const sy_scene *s, sy_object_type t, uint32_t id, const char *key)
{
    uint32_t n;
    const sy_attachment *a = sy_object_attachments(s, t, id, &n);
    for (uint32_t i = 0; i < n; ++i)
        if (strcmp(a[i].key, key) == 0) return &a[i];
    return NULL;
}

/* >>graph queries */
uint32_t sy_node_parent_count(const sy_scene *s, sy_node n)
{
    node_extra *nx = nx_of(s, n.id);
    return nx ? nx->parent_count : 0;
}

sy_node sy_node_parent(const sy_scene *s, sy_node n, uint32_t i)
{
    node_extra *nx = nx_of(s, n.id);
    sy_node r = {0};
    if (nx && i < nx->parent_count) r.id = nx->parents[i];
    return r;
}

sy_result sy_node_world_matrix(const sy_scene *s, sy_node n, sy_mat4 *out, sy_error *err)
{
    node_extra *nx = nx_of(s, n.id);
    if (!nx) return sy_error_set(err, SY_ERR_INVALID_HANDLE, "world matrix: stale node handle");
    *out = nx->world;
    return SY_OK;
}

sy_result sy_node_world_bounds(const sy_scene *s, sy_node n, sy_bounds *out, sy_error *err)
{
    node_extra *nx = nx_of(s, n.id);
    if (!nx) return sy_error_set(err, SY_ERR_INVALID_HANDLE, "world bounds: stale node handle");
    /* local_bounds are in the node's frame before its own transform; world = parent world * local */
    *out = sy_bounds_transform(&nx->local_bounds, &nx->world);
    return SY_OK;
}

sy_result sy_mesh_bounds(const sy_scene *s, sy_mesh m, sy_bounds *out, sy_error *err)
{
    slot *sl = lookup(s, SY_TYPE_MESH, m.id);
    if (!sl) return sy_error_set(err, SY_ERR_INVALID_HANDLE, "mesh bounds: stale mesh handle");
    *out = sl->bounds;
    return SY_OK;
}

sy_bounds sy_scene_world_bounds(const sy_scene *s)
{
    sy_bounds b = sy_bounds_empty();
    const pool *p = &s->pools[SY_TYPE_NODE];
    for (uint32_t i = 1; i < p->count; ++i) {
        const slot *sl = &p->slots[i];
        if (!sl->alive || primary_parent(s, sl->nx)) continue;
        sy_bounds wb = sy_bounds_transform(&sl->nx->local_bounds, &sl->nx->world);
        sy_bounds_add_bounds(&b, &wb);
    }
    return b;
}

uint32_t sy_scene_last_commit_world_updates(const sy_scene *s) { return s->last_world_updates; }

/* >>commit */
static bool any_consumer(const sy_scene *s)
{
    for (uint32_t i = 0; i < s->consumer_capacity; ++i)
        if (s->consumers[i].used) return true;
    return false;
}

static sy_result build_snapshot(sy_scene *s, sy_changes **out, sy_error *err)
{
    sy_changes *c = sy__changes_new(0, s->frame, true);
    if (!c) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "snapshot: out of memory");
    for (uint32_t t = 1; t < SY_TYPE_COUNT; ++t) {
        pool *p = &s->pools[t];
        for (uint32_t i = 1; i < p->count; ++i) {
            slot *sl = &p->slots[i];
            if (!sl->alive) continue;
            sy_result r = sy__changes_push(c, t, make_id(i, sl->generation), SY_CHANGE_CREATED, sy__type_full_mask(t),
                                           sl->data, sl->att, sl->natt, err);
            if (r != SY_OK) {
                sy_changes_release(c);
                return r;
            }
        }
    }
    sy__changes_sort(c);
    *out = c;
    return SY_OK;
}

sy_result sy_scene_snapshot(sy_scene *s, sy_changes **out, sy_error *err)
{
    *out = NULL;
    if (sy_scene_has_pending(s))
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "snapshot: the scene has uncommitted changes; commit first");
    return build_snapshot(s, out, err);
}

static void compact(sy_scene *s)
{
    uint64_t min_cursor = UINT64_MAX;
    for (uint32_t i = 0; i < s->consumer_capacity; ++i)
        if (s->consumers[i].used && !s->consumers[i].needs_snapshot && s->consumers[i].cursor < min_cursor)
            min_cursor = s->consumers[i].cursor;
    uint32_t drop = 0;
    while (drop < s->log_count && s->log[drop]->last_frame <= min_cursor) sy_changes_release(s->log[drop++]);
    if (drop) {
        memmove(s->log, s->log + drop, sizeof *s->log * (s->log_count - drop));
        s->log_count -= drop;
    }
}

sy_result sy_scene_commit(sy_scene *s, uint64_t *frame_out, sy_error *err)
{
    update_world(s);
    update_bounds(s);
    bool record = any_consumer(s);
    sy_changes *c = NULL;
    sy_result r = SY_OK;
    if (record && s->dirty_count) {
        c = sy__changes_new(s->frame, s->frame + 1, false);
        if (!c) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "commit: out of memory");
    }
    for (uint32_t i = 0; i < s->dirty_count; ++i) {
        const dirty_rec *d = &s->dirty[i];
        if (d->flags & DIRTY_DROPPED) continue;
        if (d->flags & SY_CHANGE_DESTROYED) {
            if (c && r == SY_OK) r = sy__changes_push(c, d->type, d->id, SY_CHANGE_DESTROYED, 0, NULL, NULL, 0, err);
            continue;
        }
        slot *sl = lookup(s, d->type, d->id);
        if (!sl) continue;
        if (c && r == SY_OK) {
            uint64_t mask = (d->flags & SY_CHANGE_CREATED) ? sy__type_full_mask(d->type) : sl->dirty_mask;
            r = sy__changes_push(c, d->type, d->id, d->flags & SY_CHANGE_CREATED, mask, sl->data, sl->att, sl->natt,
                                 err);
        }
        sl->dirty_mask = 0;
        sl->dirty_pos = 0;
    }
    s->dirty_count = 0;
    s->dirty_dropped = 0;
    if (r != SY_OK) {
        /* The frame's changes cannot be delivered: consumers must resynchronise from a snapshot. */
        sy_changes_release(c);
        c = NULL;
        for (uint32_t i = 0; i < s->consumer_capacity; ++i)
            if (s->consumers[i].used) s->consumers[i].needs_snapshot = true;
    }
    s->frame++;
    if (c) {
        sy__changes_sort(c);
        if (s->log_count == s->log_capacity) {
            uint32_t nc = s->log_capacity ? s->log_capacity * 2 : 16;
            sy_changes **nl = realloc(s->log, sizeof *nl * nc);
            if (!nl) {
                sy_changes_release(c);
                for (uint32_t i = 0; i < s->consumer_capacity; ++i)
                    if (s->consumers[i].used) s->consumers[i].needs_snapshot = true;
                c = NULL;
                r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "commit: out of memory");
            } else {
                s->log = nl;
                s->log_capacity = nc;
            }
        }
        if (c) s->log[s->log_count++] = c;
    }
    for (uint32_t i = 0; i < s->consumer_capacity; ++i) {
        consumer *cs = &s->consumers[i];
        if (!cs->used || !cs->needs_snapshot) continue;
        sy_changes_release(cs->snapshot);
        cs->snapshot = NULL;
        sy_error e2 = {0};
        if (build_snapshot(s, &cs->snapshot, &e2) == SY_OK) {
            cs->needs_snapshot = false;
            cs->cursor = s->frame;
        } else if (r == SY_OK) {
            r = sy_error_set(err, e2.code, "commit: %s", e2.message);
        }
    }
    compact(s);
    if (frame_out) *frame_out = s->frame;
    return r;
}

uint64_t sy_scene_frame(const sy_scene *s) { return s->frame; }
bool sy_scene_has_pending(const sy_scene *s) { return s->dirty_count > s->dirty_dropped; }

sy_result sy_scene_consumer_add(sy_scene *s, uint32_t *consumer_out, sy_error *err)
{
    uint32_t i = 0;
    while (i < s->consumer_capacity && s->consumers[i].used) i++;
    if (i == s->consumer_capacity) {
        uint32_t nc = s->consumer_capacity ? s->consumer_capacity * 2 : 4;
        consumer *ncs = realloc(s->consumers, sizeof *ncs * nc);
        if (!ncs) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "consumer: out of memory");
        memset(ncs + s->consumer_capacity, 0, sizeof *ncs * (nc - s->consumer_capacity));
        s->consumers = ncs;
        s->consumer_capacity = nc;
    }
    consumer *c = &s->consumers[i];
    memset(c, 0, sizeof *c);
    c->used = true;
    if (sy_scene_has_pending(s)) {
        c->needs_snapshot = true;
    } else {
        sy_result r = build_snapshot(s, &c->snapshot, err);
        if (r != SY_OK) {
            c->used = false;
            return r;
        }
        c->cursor = s->frame;
    }
    *consumer_out = i + 1;
    return SY_OK;
}

void sy_scene_consumer_remove(sy_scene *s, uint32_t consumer_id)
{
    if (consumer_id == 0 || consumer_id > s->consumer_capacity) return;
    consumer *c = &s->consumers[consumer_id - 1];
    sy_changes_release(c->snapshot);
    memset(c, 0, sizeof *c);
    compact(s);
}

sy_result sy_scene_consumer_pull(sy_scene *s, uint32_t consumer_id, sy_changes **out, sy_error *err)
{
    *out = NULL;
    if (consumer_id == 0 || consumer_id > s->consumer_capacity || !s->consumers[consumer_id - 1].used)
        return sy_error_set(err, SY_ERR_INVALID_HANDLE, "pull: unknown consumer %u", consumer_id);
    consumer *c = &s->consumers[consumer_id - 1];
    if (c->needs_snapshot) {
        *out = sy__changes_new(s->frame, s->frame, false);
        return *out ? SY_OK : sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "pull: out of memory");
    }
    sy_changes *stack_lists[16];
    sy_changes **lists = stack_lists;
    uint32_t n = 0, cap = 16;
    uint32_t first = 0;
    while (first < s->log_count && s->log[first]->last_frame <= c->cursor) first++;
    uint32_t total = (c->snapshot ? 1 : 0) + (s->log_count - first);
    if (total > cap) {
        lists = malloc(sizeof *lists * total);
        if (!lists) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "pull: out of memory");
    }
    if (c->snapshot) lists[n++] = c->snapshot;
    for (uint32_t i = first; i < s->log_count; ++i) lists[n++] = s->log[i];
    sy_result r = SY_OK;
    if (n == 0) {
        *out = sy__changes_new(c->cursor, s->frame, false);
        if (!*out) r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "pull: out of memory");
    } else if (n == 1) {
        *out = sy_changes_retain(lists[0]); /* immutable: share it */
    } else {
        r = sy__changes_merge(lists, n, out, err);
    }
    if (lists != stack_lists) free(lists);
    if (r != SY_OK) return r;
    sy_changes_release(c->snapshot);
    c->snapshot = NULL;
    c->cursor = s->frame;
    compact(s);
    return SY_OK;
}

uint32_t sy_scene_log_length(const sy_scene *s) { return s->log_count; }
size_t sy_scene_log_bytes(const sy_scene *s)
{
    size_t b = 0;
    for (uint32_t i = 0; i < s->log_count; ++i) b += s->log[i]->bytes;
    return b;
}

/* >>apply (replica) */
static int key_order(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

/* A snapshot lists every object of the source: on a replica that already holds state (a
 * consumer resynchronising), destroy what the snapshot does not list with exactly that id. */
static sy_result resync_destroy_unlisted(sy_scene *s, const sy_changes *changes, sy_error *err)
{
    uint32_t n = sy_changes_count(changes);
    uint64_t *keys = malloc(sizeof *keys * (n ? n : 1));
    if (!keys) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "apply snapshot: out of memory");
    uint32_t nk = 0;
    for (uint32_t i = 0; i < n; ++i) {
        const sy_change *e = sy_changes_get(changes, i);
        if (!(e->flags & SY_CHANGE_DESTROYED)) keys[nk++] = ((uint64_t)e->type << 32) | e->id;
    }
    qsort(keys, nk, sizeof *keys, key_order);
    sy_result r = SY_OK;
    for (uint32_t t = 1; t < SY_TYPE_COUNT && r == SY_OK; ++t) {
        uint32_t id = sy_scene_next(s, t, 0);
        while (id && r == SY_OK) {
            uint32_t next = sy_scene_next(s, t, id);
            uint64_t key = ((uint64_t)t << 32) | id;
            if (!bsearch(&key, keys, nk, sizeof *keys, key_order)) r = sy_object_destroy(s, t, id, err);
            id = next;
        }
    }
    free(keys);
    return r;
}

void sy_scene_set_apply_limit(sy_scene *s, uint32_t max_slots)
{
    s->apply_max_slots = max_slots;
}

/* Before anything of a change list is applied: every slot index it creates is checked against the
 * replica's slot limit, and the pool slots it would add (all types together) against max_new_slots;
 * then each pool is grown once, to exactly what the list needs. A list that fails either check
 * leaves the scene untouched. */
static sy_result apply_reserve(sy_scene *s, const sy_changes *changes, uint64_t max_new_slots, sy_error *err)
{
    uint32_t need[SY_TYPE_COUNT] = {0}, which[SY_TYPE_COUNT] = {0};
    uint32_t n = sy_changes_count(changes);
    for (uint32_t i = 0; i < n; ++i) {
        const sy_change *e = sy_changes_get(changes, i);
        if (!(e->flags & SY_CHANGE_CREATED) || (e->flags & SY_CHANGE_DESTROYED) || e->type == SY_TYPE_NONE ||
            e->type >= SY_TYPE_COUNT)
            continue;
        uint32_t idx = id_index(e->id);
        if (idx == 0 || id_generation(e->id) == 0) continue; /* refused by object_create_at, naming the id */
        if (s->apply_max_slots && idx >= s->apply_max_slots)
            return sy_error_set(err, SY_ERR_LIMIT, "create %s %#x: slot index %u exceeds this replica's limit of %u",
                                sy__type_desc(e->type)->name, e->id, idx, s->apply_max_slots);
        if (idx + 1 > need[e->type]) need[e->type] = idx + 1, which[e->type] = e->id;
    }
    uint64_t growth = 0;
    uint32_t worst = 0;
    uint64_t worst_growth = 0;
    for (uint32_t t = 1; t < SY_TYPE_COUNT; ++t) {
        uint64_t g = need[t] > s->pools[t].count ? (uint64_t)need[t] - s->pools[t].count : 0;
        growth += g;
        if (g > worst_growth) worst_growth = g, worst = t;
    }
    if (max_new_slots && growth > max_new_slots)
        return sy_error_set(err, SY_ERR_LIMIT,
                            "create %s %#x: slot index %u would add %llu slots to this replica's pools, more than the "
                            "%llu this change list may add (replica policy: slots follow the size of the message)",
                            sy__type_desc(worst)->name, which[worst], id_index(which[worst]),
                            (unsigned long long)growth, (unsigned long long)max_new_slots);
    for (uint32_t t = 1; t < SY_TYPE_COUNT; ++t)
        if (need[t] > s->pools[t].count && !pool_reserve_exact(&s->pools[t], need[t]))
            return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "create %s: out of memory for %u slots",
                                sy__type_desc(t)->name, need[t]);
    return SY_OK;
}

sy_result sy_scene_apply(sy_scene *s, const sy_changes *changes, sy_error *err)
{
    return sy_scene_apply_bounded(s, changes, 0, err);
}

sy_result sy_scene_apply_bounded(sy_scene *s, const sy_changes *changes, uint64_t max_new_slots, sy_error *err)
{
    sy_result r = apply_reserve(s, changes, max_new_slots, err);
    if (r != SY_OK) return r;
    uint32_t n = sy_changes_count(changes);
    s->applying = true;
    if (sy_changes_is_snapshot(changes)) r = resync_destroy_unlisted(s, changes, err);
    /* pass 1: destructions; pass 2: creations; pass 3: field values (references may point at
     * objects created later in the list, hence the separate passes) */
    for (uint32_t i = 0; i < n && r == SY_OK; ++i) {
        const sy_change *e = sy_changes_get(changes, i);
        if (!(e->flags & SY_CHANGE_DESTROYED)) continue;
        r = sy_object_destroy(s, e->type, e->id, err);
    }
    for (uint32_t i = 0; i < n && r == SY_OK; ++i) {
        const sy_change *e = sy_changes_get(changes, i);
        if (!(e->flags & SY_CHANGE_CREATED)) continue;
        if (lookup(s, e->type, e->id) && sy_changes_is_snapshot(changes)) continue; /* resync: update in place */
        r = object_create_at(s, e->type, e->id, err);
    }
    for (uint32_t i = 0; i < n && r == SY_OK; ++i) {
        const sy_change *e = sy_changes_get(changes, i);
        if (e->flags & SY_CHANGE_DESTROYED) continue;
        const sy_type_desc *td = sy__type_desc(e->type);
        for (uint32_t f = 0; f < td->field_count && r == SY_OK; ++f)
            if (e->mask & SY_BIT(f))
                r = sy_object_set_field(s, e->type, e->id, f, (const char *)e->data + td->fields[f].offset, err);
        if (r == SY_OK && (e->mask & SY_BIT(SY_FIELD_ATTACHMENTS))) {
            slot *sl = lookup(s, e->type, e->id);
            sy_attachment *a;
            if (!sl) r = sy_error_set(err, SY_ERR_INVALID_HANDLE, "apply: attachments for a missing object");
            else if (!sy__attachments_copy(e->attachments, e->attachment_count, &a))
                r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "apply: out of memory");
            else if (!sy__attachments_equal(sl->att, sl->natt, a, e->attachment_count))
                r = set_attachments(s, e->type, e->id, sl, a, e->attachment_count, err);
            else
                sy__attachments_free(a, e->attachment_count);
        }
        if (r != SY_OK) sy_error_prefix(err, "apply %s %#x", sy_object_type_name(e->type), e->id);
    }
    s->applying = false;
    /* the origin never has cycles; a change list that creates one is corrupt */
    if (r == SY_OK) {
        uint32_t at = 0;
        if (find_cycle(s, changes, &at))
            r = sy_error_set(err, SY_ERR_PARSE, "apply: node %#x would be its own ancestor (cycle)", at);
    }
    return r;
}

/* >>equal */
bool sy_scene_equal(const sy_scene *a, const sy_scene *b, sy_error *diff)
{
    for (uint32_t t = 1; t < SY_TYPE_COUNT; ++t) {
        const sy_type_desc *td = sy__type_desc(t);
        if (a->pools[t].live != b->pools[t].live) {
            sy_error_set(diff, SY_ERR_INVALID_ARGUMENT, "%s count differs: %u vs %u", td->name, a->pools[t].live,
                         b->pools[t].live);
            return false;
        }
        for (uint32_t id = sy_scene_next(a, t, 0); id; id = sy_scene_next(a, t, id)) {
            slot *sa = lookup(a, t, id), *sb = lookup(b, t, id);
            if (!sb) {
                sy_error_set(diff, SY_ERR_INVALID_ARGUMENT, "%s %#x missing in the second scene", td->name, id);
                return false;
            }
            for (uint32_t f = 0; f < td->field_count; ++f)
                if (!sy__field_equal(t, f, sa->data, sb->data)) {
                    sy_error_set(diff, SY_ERR_INVALID_ARGUMENT, "%s %#x field %s differs", td->name, id,
                                 td->fields[f].name);
                    return false;
                }
            if (!sy__attachments_equal(sa->att, sa->natt, sb->att, sb->natt)) {
                sy_error_set(diff, SY_ERR_INVALID_ARGUMENT, "%s %#x attachments differ", td->name, id);
                return false;
            }
        }
    }
    return true;
}
