/* sy_scene.c — the scene's groundwork: object pools with generation-checked handles, slots, dirty
 * tracking, the scene's lifetime (create, destroy) and reading objects (get, iterate, count). */
#include "sy_scene_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

bool sy_sc_list_push(id_list *l, uint32_t v) { return sy_u32_push(&l->items, &l->count, &l->capacity, v); }

void sy_sc_array_remove(uint32_t *items, uint32_t *count, uint32_t v)
{
    for (uint32_t i = 0; i < *count; ++i)
        if (items[i] == v) {
            memmove(items + i, items + i + 1, sizeof *items * (*count - i - 1));
            (*count)--;
            return;
        }
}

slot *sy_sc_lookup(const sy_scene *s, uint32_t type, uint32_t id)
{
    if (type == SY_TYPE_NONE || type >= SY_TYPE_COUNT || id == 0) return NULL;
    const pool *p = &s->pools[type];
    uint32_t idx = id_index(id);
    if (idx == 0 || idx >= p->count) return NULL;
    slot *sl = &p->slots[idx];
    if (!sl->alive || sl->generation != id_generation(id)) return NULL;
    return sl;
}

node_extra *sy_sc_nx_of(const sy_scene *s, uint32_t node_id)
{
    slot *sl = sy_sc_lookup(s, SY_TYPE_NODE, node_id);
    return sl ? sl->nx : NULL;
}

/* The slot array resized to nc slots (the new ones zeroed); false when out of memory. */
static bool pool_resize(pool *p, uint32_t nc)
{
    slot *ns = realloc(p->slots, sizeof *ns * nc);
    if (!ns) return false;
    memset(ns + p->capacity, 0, sizeof *ns * (nc - p->capacity));
    p->slots = ns;
    p->capacity = nc;
    return true;
}

bool sy_sc_pool_grow(pool *p, uint32_t min_count)
{
    if (min_count <= p->capacity) return true;
    uint32_t nc = p->capacity ? p->capacity : 64;
    while (nc < min_count) nc *= 2;
    if (nc > SY_HANDLE_INDEX_MASK + 1) nc = SY_HANDLE_INDEX_MASK + 1;
    return nc >= min_count && pool_resize(p, nc);
}

/* Replica apply: grows the slot array to exactly min_count slots (no doubling), so the memory a
 * change list makes a replica allocate follows what the list creates (see apply_reserve). */
_Static_assert(sizeof(slot) + sizeof(uint32_t) <= SY_SCENE_SLOT_BYTES,
               "SY_SCENE_SLOT_BYTES is a slot + its free-list entry");

bool sy_sc_pool_reserve_exact(pool *p, uint32_t min_count)
{
    if (min_count <= p->capacity) return true;
    return min_count <= SY_HANDLE_INDEX_MASK + 1 && pool_resize(p, min_count);
}

void sy_sc_free_list_push(pool *p, uint32_t idx)
{
    if (p->slots[idx].in_free_list || p->slots[idx].retired) return;
    uint32_t cnt = p->free_count;
    if (sy_u32_push(&p->free_list, &cnt, &p->free_capacity, idx)) {
        p->free_count = cnt;
        p->slots[idx].in_free_list = 1;
    }
    /* on out of memory the slot is simply not reused */
}

/* Fills a slot for a new object; the caller has chosen index and generation. */
sy_result sy_sc_slot_init(sy_scene *s, uint32_t type, uint32_t idx, uint32_t gen, const char *name, sy_error *err)
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
bool sy_sc_mark_dirty(sy_scene *s, uint32_t type, uint32_t id, slot *sl, uint64_t bits, uint32_t flags)
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

/* >>the scene: create, destroy; reading objects */
sy_result sy_scene_create(sy_scene **out, sy_error *err)
{
    *out = calloc(1, sizeof **out);
    if (!*out) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "scene: out of memory");
    for (int t = 1; t < SY_TYPE_COUNT; ++t) (*out)->pools[t].count = 1; /* index 0 reserved */
    return SY_OK;
}

void sy_sc_slot_release(slot *sl, uint32_t type)
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
            if (p->slots[i].alive) sy_sc_slot_release(&p->slots[i], (uint32_t)t);
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
    free(s->skinned.items);
    for (uint32_t i = 0; i < s->skin_mesh_count; ++i) free(s->skin_meshes[i].bounds);
    free(s->skin_meshes);
    free(s->stack.items);
    free(s);
}

bool sy_object_is_valid(const sy_scene *s, sy_object_type t, uint32_t id) { return sy_sc_lookup(s, t, id) != NULL; }

const void *sy_object_get(const sy_scene *s, sy_object_type t, uint32_t id)
{
    slot *sl = sy_sc_lookup(s, t, id);
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
