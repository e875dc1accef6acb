/* sy_scene_commit.c — the scene's change lists (sy_commit.h): commit, consumers and their
 * cursors, log compaction, snapshots, replica apply (bounded for untrusted lists) and deep equality. */
#include "sy_scene_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

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
    sy_sc_update_world(s);
    sy_sc_mark_skins_moved(s);
    sy_sc_update_bounds(s);
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
        slot *sl = sy_sc_lookup(s, d->type, d->id);
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
        if (idx == 0 || id_generation(e->id) == 0) continue; /* refused by sy_sc_object_create_at, naming the id */
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
        if (need[t] > s->pools[t].count && !sy_sc_pool_reserve_exact(&s->pools[t], need[t]))
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
        if (sy_sc_lookup(s, e->type, e->id) && sy_changes_is_snapshot(changes)) continue; /* resync: update in place */
        r = sy_sc_object_create_at(s, e->type, e->id, err);
    }
    for (uint32_t i = 0; i < n && r == SY_OK; ++i) {
        const sy_change *e = sy_changes_get(changes, i);
        if (e->flags & SY_CHANGE_DESTROYED) continue;
        const sy_type_desc *td = sy__type_desc(e->type);
        for (uint32_t f = 0; f < td->field_count && r == SY_OK; ++f)
            if (e->mask & SY_BIT(f))
                r = sy_object_set_field(s, e->type, e->id, f, (const char *)e->data + td->fields[f].offset, err);
        const void *whole = r == SY_OK ? sy_object_get(s, e->type, e->id) : NULL; /* rules between fields */
        if (whole) r = sy_sc_validate_object(s, e->type, e->id, whole, err);
        if (r == SY_OK && (e->mask & SY_BIT(SY_FIELD_ATTACHMENTS))) {
            slot *sl = sy_sc_lookup(s, e->type, e->id);
            sy_attachment *a;
            if (!sl) r = sy_error_set(err, SY_ERR_INVALID_HANDLE, "apply: attachments for a missing object");
            else if (!sy__attachments_copy(e->attachments, e->attachment_count, &a))
                r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "apply: out of memory");
            else if (!sy__attachments_equal(sl->att, sl->natt, a, e->attachment_count))
                r = sy_sc_set_attachments(s, e->type, e->id, sl, a, e->attachment_count, err);
            else
                sy__attachments_free(a, e->attachment_count);
        }
        if (r != SY_OK) sy_error_prefix(err, "apply %s %#x", sy_object_type_name(e->type), e->id);
    }
    s->applying = false;
    /* the origin never has cycles; a change list that creates one is corrupt */
    if (r == SY_OK) {
        uint32_t at = 0;
        if (sy_sc_find_cycle(s, changes, &at))
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
            slot *sa = sy_sc_lookup(a, t, id), *sb = sy_sc_lookup(b, t, id);
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
