/* sy_scene_objects.c — the object calls of sy_objects.h: create (also at a replica's exact id),
 * destroy, the generic and typed setters that validate and mark fields dirty, typed getters and
 * attachments. */
#include "sy_scene_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

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
        if (!sy_sc_pool_grow(p, p->count + 1)) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "create %s: out of memory", td->name);
        idx = p->count++;
    }
    uint32_t gen = p->slots[idx].generation + 1; /* a fresh slot starts at generation 1 */
    sy_result r = sy_sc_slot_init(s, t, idx, gen, name, err);
    if (r != SY_OK) {
        sy_sc_free_list_push(p, idx);
        return r;
    }
    uint32_t id = make_id(idx, gen);
    slot *sl = &p->slots[idx];
    if (!sy_sc_mark_dirty(s, t, id, sl, 0, SY_CHANGE_CREATED)) {
        sy_sc_slot_release(sl, t);
        p->live--;
        sy_sc_free_list_push(p, idx);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "create %s: out of memory", td->name);
    }
    *id_out = id;
    return SY_OK;
}

/* Replica: create exactly this id. */
sy_result sy_sc_object_create_at(sy_scene *s, uint32_t t, uint32_t id, sy_error *err)
{
    const sy_type_desc *td = sy__type_desc(t);
    pool *p = &s->pools[t];
    uint32_t idx = id_index(id), gen = id_generation(id);
    if (idx == 0 || gen == 0) return sy_error_set(err, SY_ERR_INVALID_HANDLE, "create %s %#x: invalid id", td->name, id);
    if (s->applying && s->apply_max_slots && idx >= s->apply_max_slots)
        return sy_error_set(err, SY_ERR_LIMIT, "create %s %#x: slot index %u exceeds this replica's limit of %u", td->name,
                            id, idx, s->apply_max_slots);
    if (idx >= p->count) {
        if (!sy_sc_pool_grow(p, idx + 1)) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "create %s: out of memory", td->name);
        for (uint32_t i = p->count; i < idx; ++i) sy_sc_free_list_push(p, i);
        p->count = idx + 1;
    }
    slot *sl = &p->slots[idx];
    if (sl->alive)
        return sy_error_set(err, SY_ERR_INVALID_HANDLE, "create %s %#x: slot holds a live object", td->name, id);
    if (gen <= sl->generation && sl->generation != 0)
        return sy_error_set(err, SY_ERR_INVALID_HANDLE, "create %s %#x: generation goes backwards", td->name, id);
    sy_result r = sy_sc_slot_init(s, t, idx, gen, NULL, err);
    if (r != SY_OK) return r;
    if (!sy_sc_mark_dirty(s, t, id, sl, 0, SY_CHANGE_CREATED)) {
        sy_sc_slot_release(sl, t);
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
TYPED_CREATE(sy_animation_create, sy_animation, SY_TYPE_ANIMATION)
#undef TYPED_CREATE

/* Updates parent lists and dirty marks of a node whose child list goes from old to new. */
static void children_changed(sy_scene *s, uint32_t id, const sy_blob *oldb, const sy_blob *newb)
{
    uint32_t no = oldb ? (uint32_t)(sy_blob_size(oldb) / 4) : 0, nn = newb ? (uint32_t)(sy_blob_size(newb) / 4) : 0;
    const uint32_t *o = oldb ? sy_blob_data(oldb) : NULL, *n = newb ? sy_blob_data(newb) : NULL;
    for (uint32_t i = 0; i < no; ++i) {
        bool kept = false;
        for (uint32_t j = 0; j < nn && !kept; ++j) kept = n[j] == o[i];
        node_extra *cnx = sy_sc_nx_of(s, o[i]);
        if (kept || !cnx) continue;
        sy_sc_array_remove(cnx->parents, &cnx->parent_count, id);
        sy_sc_mark_world_dirty(s, o[i]);
    }
    for (uint32_t j = 0; j < nn; ++j) {
        bool existed = false;
        for (uint32_t i = 0; i < no && !existed; ++i) existed = o[i] == n[j];
        node_extra *cnx = sy_sc_nx_of(s, n[j]);
        if (existed || !cnx) continue;
        sy_u32_push(&cnx->parents, &cnx->parent_count, &cnx->parent_capacity, id);
        sy_sc_mark_world_dirty(s, n[j]);
    }
    sy_sc_mark_bounds_dirty(s, id);
}

static void mesh_users_changed(sy_scene *s, uint32_t node_id, uint32_t old_mesh, uint32_t new_mesh)
{
    slot *om = sy_sc_lookup(s, SY_TYPE_MESH, old_mesh), *nm = sy_sc_lookup(s, SY_TYPE_MESH, new_mesh);
    if (om) sy_sc_array_remove(om->users, &om->user_count, node_id);
    if (nm) sy_u32_push(&nm->users, &nm->user_count, &nm->user_capacity, node_id);
    sy_sc_mark_bounds_dirty(s, node_id);
}

static void mesh_bounds_update(sy_scene *s, uint32_t id, slot *sl)
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
    sy_sc_mesh_joint_bounds(s, id, d);
    for (uint32_t i = 0; i < sl->user_count; ++i) sy_sc_mark_bounds_dirty(s, sl->users[i]);
}

/* >>skinned bounds (sy_scene_graph.c): each skinned mesh's per-joint bind-pose bounds */
/* Per joint index, the bind-pose bounds of the vertices it moves; *count the joint indices (0: no
 * skinned triangles, NULL returned); [count] the vertices no joint moves. NULL without memory too
 * (the node keeps the mesh's bind-pose bounds). */
static sy_bounds *joint_bounds(const sy_mesh_data *d, uint32_t *count)
{
    uint32_t nj = 0;
    *count = 0;
    for (uint32_t i = 0; i < d->primitives.count; ++i) {
        const sy_primitive *pr = &d->primitives.items[i];
        uint32_t inf = sy_primitive_influences(pr), nv = sy_primitive_vertex_count(pr);
        if (pr->topology != SY_TOPOLOGY_TRIANGLES || !inf || !pr->joints || !pr->weights) continue;
        const uint32_t *jj = sy_blob_data(pr->joints);
        for (size_t k = 0; k < (size_t)inf * nv; ++k)
            if (jj[k] < SY_SKIN_MAX_JOINTS && jj[k] >= nj) nj = jj[k] + 1u;
    }
    sy_bounds *jb = nj ? malloc(sizeof *jb * (nj + 1u)) : NULL;
    if (!jb) return NULL;
    for (uint32_t j = 0; j <= nj; ++j) jb[j] = sy_bounds_empty();
    for (uint32_t i = 0; i < d->primitives.count; ++i) {
        const sy_primitive *pr = &d->primitives.items[i];
        uint32_t inf = sy_primitive_influences(pr), nv = sy_primitive_vertex_count(pr);
        if (pr->topology != SY_TOPOLOGY_TRIANGLES) continue;
        const float *pos = sy_blob_data(pr->positions);
        const uint32_t *jj = inf && pr->joints && pr->weights ? sy_blob_data(pr->joints) : NULL;
        const float *ww = jj ? sy_blob_data(pr->weights) : NULL;
        for (uint32_t v = 0; v < nv; ++v) {
            bool moved = false;
            for (uint32_t k = 0; jj && k < inf; ++k) {
                uint32_t j = jj[(size_t)inf * v + k];
                if (ww[(size_t)inf * v + k] != 0.0f && j < nj) {
                    sy_bounds_add_point(&jb[j], &pos[3 * (size_t)v]);
                    moved = true;
                }
            }
            if (!moved) sy_bounds_add_point(&jb[nj], &pos[3 * (size_t)v]);
        }
    }
    *count = nj;
    return jb;
}

void sy_sc_mesh_joint_bounds(sy_scene *s, uint32_t mesh_id, const sy_mesh_data *d)
{
    skin_mesh *e = sy_sc_skin_mesh_find(s, mesh_id);
    uint32_t count = 0;
    sy_bounds *jb = d ? joint_bounds(d, &count) : NULL;
    if (e && jb) { /* replaced */
        free(e->bounds);
        e->bounds = jb, e->count = count;
        return;
    }
    if (e) { /* no skinned triangles any more, or the mesh is gone */
        free(e->bounds);
        size_t at = (size_t)(e - s->skin_meshes);
        memmove(e, e + 1, sizeof *e * (s->skin_mesh_count - at - 1u));
        s->skin_mesh_count--;
        s->skinned_stale = true;
        return;
    }
    if (!jb) return;
    if (s->skin_mesh_count == s->skin_mesh_capacity) {
        uint32_t nc = s->skin_mesh_capacity ? 2u * s->skin_mesh_capacity : 8u;
        skin_mesh *g = realloc(s->skin_meshes, sizeof *g * nc);
        if (!g) { /* without memory: bind-pose bounds */
            free(jb);
            return;
        }
        s->skin_meshes = g, s->skin_mesh_capacity = nc;
    }
    uint32_t at = 0;
    while (at < s->skin_mesh_count && s->skin_meshes[at].mesh < mesh_id) at++;
    memmove(&s->skin_meshes[at + 1], &s->skin_meshes[at], sizeof *s->skin_meshes * (s->skin_mesh_count - at));
    s->skin_meshes[at] = (skin_mesh){mesh_id, count, jb};
    s->skin_mesh_count++;
    s->skinned_stale = true;
}

/* Sets one field. whole_checked: the caller checks the rules between fields on the whole object
 * (set_all, a replica's entry); otherwise they are checked here on the object with this field set. */
static sy_result set_field(sy_scene *s, sy_object_type t, uint32_t id, uint32_t field, const void *value,
                           bool whole_checked, sy_error *err)
{
    slot *sl = sy_sc_lookup(s, t, id);
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
                       sizeof(sy_background_data) <= sizeof src && sizeof(sy_animation_data) <= sizeof src,
                   "scratch buffer too small");
    const sy_field_desc *fd = &td->fields[field];
    memcpy(src + fd->offset, value, fd->size);
    /* The no-op test comes before validation: re-setting the value a field already holds succeeds
     * even when it names an object destroyed since (stale references are kept, read as absent). */
    if (sy__field_equal(t, field, sl->data, src)) return SY_OK;
    sy_result r = sy_sc_validate_field(s, t, id, field, value, err);
    if (r != SY_OK) return r;
    if (!whole_checked && (t == SY_TYPE_CAMERA || t == SY_TYPE_ANIMATION)) { /* the types with rules between fields */
        union {
            sy_camera_data camera;
            sy_animation_data animation;
        } merged;
        memcpy(&merged, sl->data, td->data_size);
        memcpy((unsigned char *)&merged + fd->offset, value, fd->size);
        if ((r = sy_sc_validate_object(s, t, id, &merged, err)) != SY_OK) return r;
    }

    sy_blob *old_children = NULL;
    uint32_t old_mesh = 0;
    if (t == SY_TYPE_NODE && field == SY_NODE_CHILDREN)
        old_children = sy_blob_retain(((sy_node_data *)sl->data)->children);
    if (t == SY_TYPE_NODE && field == SY_NODE_MESH) old_mesh = ((sy_node_data *)sl->data)->mesh.id;
    if (!sy__field_copy(t, field, sl->data, src)) {
        sy_blob_release(old_children);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "set %s.%s: out of memory", td->name, fd->name);
    }
    if (!sy_sc_mark_dirty(s, t, id, sl, SY_BIT(field), 0)) {
        sy_blob_release(old_children);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "set %s.%s: out of memory", td->name, fd->name);
    }
    if (t == SY_TYPE_NODE) {
        const sy_node_data *d = sl->data;
        switch (field) {
        case SY_NODE_TRANSFORM:
            sy_sc_mark_world_dirty(s, id);
            sy_sc_mark_parents_bounds_dirty(s, id);
            break;
        case SY_NODE_CHILDREN: children_changed(s, id, old_children, d->children); break;
        case SY_NODE_MESH:
            mesh_users_changed(s, id, old_mesh, d->mesh.id);
            if (d->skin) s->skinned_stale = true;
            break;
        case SY_NODE_SKIN: /* the joints place the mesh now (sy_scene_graph.c, skinned bounds) */
            sy_sc_mark_bounds_dirty(s, id);
            s->skinned_stale = true;
            break;
        default: break;
        }
    } else if (t == SY_TYPE_MESH && field == SY_MESH_PRIMITIVES) {
        mesh_bounds_update(s, id, sl);
    }
    sy_blob_release(old_children);
    return SY_OK;
}

sy_result sy_object_set_field(sy_scene *s, sy_object_type t, uint32_t id, uint32_t field, const void *value,
                              sy_error *err)
{
    return set_field(s, t, id, field, value, s->applying, err); /* a replica checks each entry whole */
}

sy_result sy_object_destroy(sy_scene *s, sy_object_type t, uint32_t id, sy_error *err)
{
    slot *sl = sy_sc_lookup(s, t, id);
    if (!sl) return sy_error_set(err, SY_ERR_INVALID_HANDLE, "destroy: stale or invalid %s handle %#x", sy_object_type_name(t), id);
    pool *p = &s->pools[t];
    /* record the destruction (or drop a creation nobody has seen) */
    if (sl->dirty_pos) {
        dirty_rec *rec = &s->dirty[sl->dirty_pos - 1];
        if (rec->flags & SY_CHANGE_CREATED) s->dirty_dropped++;
        rec->flags = (rec->flags & SY_CHANGE_CREATED) ? DIRTY_DROPPED : SY_CHANGE_DESTROYED;
    } else if (!sy_sc_mark_dirty(s, t, id, sl, 0, SY_CHANGE_DESTROYED)) {
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "destroy: out of memory");
    }
    sl->dirty_pos = 0;
    sl->dirty_mask = 0;
    if (t == SY_TYPE_NODE) {
        const sy_node_data *d = sl->data;
        sy_sc_mark_parents_bounds_dirty(s, id);
        /* parents keep the stale child id in their lists; readers skip it */
        uint32_t nc;
        const uint32_t *ch = sy_node_children(d, &nc);
        for (uint32_t k = 0; k < nc; ++k) {
            node_extra *cnx = sy_sc_nx_of(s, ch[k]);
            if (!cnx) continue;
            sy_sc_array_remove(cnx->parents, &cnx->parent_count, id);
            sy_sc_mark_world_dirty(s, ch[k]);
        }
        slot *ms = sy_sc_lookup(s, SY_TYPE_MESH, d->mesh.id);
        if (ms) sy_sc_array_remove(ms->users, &ms->user_count, id);
    } else if (t == SY_TYPE_MESH) {
        for (uint32_t i = 0; i < sl->user_count; ++i) sy_sc_mark_bounds_dirty(s, sl->users[i]);
        sy_sc_mesh_joint_bounds(s, id, NULL);
    }
    sy_sc_slot_release(sl, t);
    p->live--;
    if (sl->generation >= SY_HANDLE_MAX_GENERATION) sl->retired = 1; /* never reuse: ids stay unique */
    sy_sc_free_list_push(p, id_index(id));
    return SY_OK;
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
        if (sy_sc_lookup(s, SY_TYPE_NODE, ch[i])) list[n++].id = ch[i];
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

/* One flag of a live node set or cleared, the others kept. */
static sy_result node_flag(sy_scene *s, sy_node n, uint32_t flag, bool on, const char *what, sy_error *err)
{
    const sy_node_data *d = sy_node_get(s, n);
    if (!d) return sy_error_set(err, SY_ERR_INVALID_HANDLE, "%s: no node with id %u", what, n.id);
    uint32_t f = on ? d->flags | flag : d->flags & ~flag;
    return f == d->flags ? SY_OK : sy_node_set_flags(s, n, f, err);
}

sy_result sy_node_set_visible(sy_scene *s, sy_node n, bool visible, sy_error *err)
{
    return node_flag(s, n, SY_NODE_VISIBLE, visible, visible ? "show" : "hide", err);
}

sy_result sy_node_set_selected(sy_scene *s, sy_node n, bool selected, sy_error *err)
{
    return node_flag(s, n, SY_NODE_SELECTED, selected, selected ? "select" : "deselect", err);
}

/* >>isolate: the kept nodes are the given ones, everything below them (their subtrees) and
 * everything above them (so that they stay reachable: an ancestor's own mesh stays drawn, since
 * hiding it would hide its whole subtree) */
#define ISO_GIVEN 1u
#define ISO_BELOW 2u
#define ISO_ABOVE 4u
static uint32_t iso_index(const uint32_t *ids, uint32_t n, uint32_t id)
{
    uint32_t lo = 0, hi = n;
    while (lo < hi) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (ids[mid] < id) lo = mid + 1;
        else hi = mid;
    }
    return lo < n && ids[lo] == id ? lo : UINT32_MAX;
}

sy_result sy_scene_isolate(sy_scene *s, const sy_node *nodes, uint32_t count, sy_error *err)
{
    if (count && !nodes) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "isolate: NULL node list");
    for (uint32_t i = 0; i < count; ++i)
        if (!sy_node_get(s, nodes[i])) return sy_error_set(err, SY_ERR_INVALID_HANDLE, "isolate: no node with id %u", nodes[i].id);
    uint32_t n = sy_scene_count(s, SY_TYPE_NODE);
    uint32_t *ids = malloc(((size_t)n + 1) * sizeof *ids);
    uint8_t *mark = calloc((size_t)n + 1, 1);
    uint32_t *stack = malloc(((size_t)n + 1) * sizeof *stack);
    if (!ids || !mark || !stack) {
        free(ids), free(mark), free(stack);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "isolate: out of memory (%u nodes)", n);
    }
    uint32_t m = 0;
    for (uint32_t id = sy_scene_next(s, SY_TYPE_NODE, 0); id && m < n; id = sy_scene_next(s, SY_TYPE_NODE, id)) ids[m++] = id;
    qsort(ids, m, sizeof *ids, sy_sc_cmp_u32);
    /* the given nodes and their subtrees (each node pushed once: cycles from bad input end) */
    uint32_t sp = 0;
    for (uint32_t i = 0; i < count; ++i) {
        uint32_t k = iso_index(ids, m, nodes[i].id);
        if (k == UINT32_MAX || (mark[k] & ISO_GIVEN)) continue;
        mark[k] |= ISO_GIVEN;
        if (!(mark[k] & ISO_BELOW)) mark[k] |= ISO_BELOW, stack[sp++] = k;
    }
    while (sp) {
        uint32_t nc, k = stack[--sp];
        const uint32_t *ch = sy_node_children(sy_node_get(s, (sy_node){ids[k]}), &nc);
        for (uint32_t c = 0; c < nc; ++c) {
            uint32_t j = iso_index(ids, m, ch[c]);
            if (j != UINT32_MAX && !(mark[j] & ISO_BELOW)) mark[j] |= ISO_BELOW, stack[sp++] = j;
        }
    }
    /* their ancestors: a node with a given or above-given child, until nothing changes */
    for (bool grew = count > 0; grew;) {
        grew = false;
        for (uint32_t k = 0; k < m; ++k) {
            if (mark[k] & ISO_ABOVE) continue;
            uint32_t nc;
            const uint32_t *ch = sy_node_children(sy_node_get(s, (sy_node){ids[k]}), &nc);
            for (uint32_t c = 0; c < nc; ++c) {
                uint32_t j = iso_index(ids, m, ch[c]);
                if (j != UINT32_MAX && (mark[j] & (ISO_GIVEN | ISO_ABOVE))) {
                    mark[k] |= ISO_ABOVE;
                    grew = true;
                    break;
                }
            }
        }
    }
    sy_result r = SY_OK;
    for (uint32_t k = 0; k < m && r == SY_OK; ++k) {
        const sy_node_data *d = sy_node_get(s, (sy_node){ids[k]});
        if (count == 0 || mark[k]) r = sy_node_set_visible(s, (sy_node){ids[k]}, true, err);
        else if (d->mesh.id) r = sy_node_set_visible(s, (sy_node){ids[k]}, false, err); /* lights, cameras stay */
    }
    free(ids), free(mark), free(stack);
    return r;
}

/* A float blob field (morph weights) from count floats; count 0 sets NULL. */
static sy_result set_weights(sy_scene *s, sy_object_type t, uint32_t id, uint32_t field, const float *w, uint32_t count,
                             sy_error *err)
{
    sy_blob *b = NULL;
    if (count) {
        if (!w) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: %u weights from NULL", sy_object_type_name(t), count);
        sy_result r = sy_blob_create_copy(w, sizeof(float) * (size_t)count, &b, err);
        if (r != SY_OK) return r;
    }
    sy_result r = sy_object_set_field(s, t, id, field, &b, err);
    sy_blob_release(b);
    return r;
}

sy_result sy_node_set_weights(sy_scene *s, sy_node n, const float *weights, uint32_t count, sy_error *err)
{
    return set_weights(s, SY_TYPE_NODE, n.id, SY_NODE_WEIGHTS, weights, count, err);
}

sy_result sy_mesh_set_weights(sy_scene *s, sy_mesh m, const float *weights, uint32_t count, sy_error *err)
{
    return set_weights(s, SY_TYPE_MESH, m.id, SY_MESH_WEIGHTS, weights, count, err);
}

sy_result sy_node_set_skin(sy_scene *s, sy_node n, const sy_node *joints, const sy_mat4 *inverse_bind, uint32_t count,
                           sy_node skeleton, sy_error *err)
{
    sy_blob *b = NULL;
    if (count) {
        if (!joints) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "node skin: %u joints from NULL", count);
        if (count > SY_SKIN_MAX_JOINTS)
            return sy_error_set(err, SY_ERR_LIMIT, "node skin: %u joints (at most %u)", count, SY_SKIN_MAX_JOINTS);
        sy_skin_joint *list = malloc(sizeof *list * count);
        if (!list) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "node skin: out of memory");
        for (uint32_t i = 0; i < count; ++i) {
            list[i].node = joints[i].id;
            list[i].inverse_bind = inverse_bind ? inverse_bind[i] : sy_mat4_identity();
        }
        sy_result r = sy_blob_create_take(list, sizeof *list * count, &b, err);
        if (r != SY_OK) return r;
    }
    sy_result r = sy_object_set_field(s, SY_TYPE_NODE, n.id, SY_NODE_SKIN, &b, err);
    sy_blob_release(b);
    if (r == SY_OK) r = sy_object_set_field(s, SY_TYPE_NODE, n.id, SY_NODE_SKELETON, &skeleton, err);
    return r;
}

uint32_t sy_primitive_influences(const sy_primitive *p)
{
    uint32_t nv = sy_primitive_vertex_count(p);
    return p->joints && nv ? (uint32_t)(sy_blob_size(p->joints) / 4 / nv) : 0u;
}

uint32_t sy_primitive_target_count(const sy_primitive *p)
{
    uint32_t nv = sy_primitive_vertex_count(p);
    const sy_blob *b = p->target_positions ? p->target_positions : p->target_normals ? p->target_normals : p->target_tangents;
    if (!b && p->target_texcoords0) return nv ? (uint32_t)(sy_blob_size(p->target_texcoords0) / 8 / nv) : 0u;
    return b && nv ? (uint32_t)(sy_blob_size(b) / 12 / nv) : 0u;
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
    slot *sl = sy_sc_lookup(s, t, id);
    if (!sl) return sy_error_set(err, SY_ERR_INVALID_HANDLE, "set: stale or invalid %s handle %#x", td->name, id);
    for (uint32_t f = 0; f < td->field_count; ++f) {
        if (sy__field_equal(t, f, sl->data, d)) continue; /* unchanged: may hold a stale reference */
        sy_result r = sy_sc_validate_field(s, t, id, f, (const char *)d + td->fields[f].offset, err);
        if (r != SY_OK) return r;
    }
    sy_result r = sy_sc_validate_object(s, t, id, d, err);
    if (r != SY_OK) return r;
    for (uint32_t f = 0; f < td->field_count; ++f) {
        r = set_field(s, t, id, f, (const char *)d + td->fields[f].offset, true, err);
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

sy_result sy_animation_set(sy_scene *s, sy_animation a, const sy_animation_data *d, sy_error *err)
{
    return set_all(s, SY_TYPE_ANIMATION, a.id, d, err);
}

sy_result sy_animation_set_timing(sy_scene *s, sy_animation a, float cycle, bool loop, sy_error *err)
{
    const sy_animation_data *cur = sy_animation_get(s, a);
    if (!cur) return sy_error_set(err, SY_ERR_INVALID_HANDLE, "animation: stale handle %#x", a.id);
    sy_animation_data d = *cur;
    d.cycle = cycle;
    d.loop = loop ? 1u : 0u;
    return set_all(s, SY_TYPE_ANIMATION, a.id, &d, err);
}

sy_result sy_animation_set_clip(sy_scene *s, sy_animation a, const sy_anim_sampler_desc *samplers, uint32_t sampler_count,
                                const sy_anim_channel *channels, uint32_t channel_count, sy_error *err)
{
    const sy_animation_data *cur = sy_animation_get(s, a);
    if (!cur) return sy_error_set(err, SY_ERR_INVALID_HANDLE, "animation: stale handle %#x", a.id);
    if (sampler_count > SY_ANIM_MAX_SAMPLERS || channel_count > SY_ANIM_MAX_CHANNELS)
        return sy_error_set(err, SY_ERR_LIMIT, "animation %#x: %u samplers, %u channels (at most %u, %u)", a.id,
                            sampler_count, channel_count, SY_ANIM_MAX_SAMPLERS, SY_ANIM_MAX_CHANNELS);
    if ((sampler_count && !samplers) || (channel_count && !channels))
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "animation %#x: NULL samplers or channels", a.id);
    /* sizes first (checked: the counts are the caller's), then one copy into each blob */
    uint64_t ntimes = 0, nvalues = 0;
    for (uint32_t i = 0; i < sampler_count; ++i) {
        const sy_anim_sampler_desc *sd = &samplers[i];
        if (sd->key_count > SY_ANIM_MAX_KEYS || sd->components > SY_ANIM_MAX_COMPONENTS)
            return sy_error_set(err, SY_ERR_LIMIT, "animation %#x sampler %u: %u keys of %u components (at most %u, %u)",
                                a.id, i, sd->key_count, sd->components, SY_ANIM_MAX_KEYS, SY_ANIM_MAX_COMPONENTS);
        if (sd->key_count && (!sd->times || !sd->values))
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "animation %#x sampler %u: NULL times or values", a.id, i);
        ntimes += sd->key_count;
        nvalues += (uint64_t)sd->key_count * sd->components * (sd->interpolation == SY_INTERP_CUBICSPLINE ? 3u : 1u);
        if (ntimes > UINT32_MAX || nvalues > UINT32_MAX)
            return sy_error_set(err, SY_ERR_LIMIT, "animation %#x: more than 2^32 key times or values", a.id);
    }
    sy_animation_data d = {.name = cur->name, .cycle = cur->cycle, .loop = cur->loop};
    sy_result r = SY_OK;
    sy_anim_sampler *rec = NULL;
    float *times = NULL, *values = NULL;
    if (sampler_count) {
        rec = malloc(sizeof *rec * sampler_count);
        times = malloc(sizeof *times * (ntimes ? ntimes : 1));
        values = malloc(sizeof *values * (nvalues ? nvalues : 1));
        if (!rec || !times || !values) {
            r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "animation %#x: out of memory", a.id);
            goto done;
        }
        uint32_t to = 0, vo = 0;
        for (uint32_t i = 0; i < sampler_count; ++i) {
            const sy_anim_sampler_desc *sd = &samplers[i];
            uint32_t nv = sd->key_count * sd->components * (sd->interpolation == SY_INTERP_CUBICSPLINE ? 3u : 1u);
            rec[i] = (sy_anim_sampler){sd->interpolation, sd->components, sd->key_count, to, vo};
            if (sd->key_count) memcpy(times + to, sd->times, sizeof *times * sd->key_count);
            if (nv) memcpy(values + vo, sd->values, sizeof *values * nv);
            to += sd->key_count;
            vo += nv;
        }
        if ((r = sy_blob_create_copy(rec, sizeof *rec * sampler_count, &d.samplers, err)) ||
            (ntimes && (r = sy_blob_create_copy(times, sizeof *times * ntimes, &d.times, err))) ||
            (nvalues && (r = sy_blob_create_copy(values, sizeof *values * nvalues, &d.values, err))))
            goto done;
    }
    if (channel_count && (r = sy_blob_create_copy(channels, sizeof *channels * channel_count, &d.channels, err)))
        goto done;
    r = set_all(s, SY_TYPE_ANIMATION, a.id, &d, err);
done:
    sy_blob_release(d.samplers);
    sy_blob_release(d.channels);
    sy_blob_release(d.times);
    sy_blob_release(d.values);
    free(rec);
    free(times);
    free(values);
    return r;
}

sy_result sy_texture_set_image(sy_scene *s, sy_texture t, const sy_image_info *info, sy_blob *pixels, sy_error *err)
{
    if (!sy_sc_lookup(s, SY_TYPE_TEXTURE, t.id)) return sy_error_set(err, SY_ERR_INVALID_HANDLE, "texture: stale handle");
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

const sy_animation_data *sy_animation_get(const sy_scene *s, sy_animation a)
{
    return sy_object_get(s, SY_TYPE_ANIMATION, a.id);
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

const uint32_t sy_material_texture_fields[SY_MATERIAL_TEXTURE_SLOTS] = {
    SY_MATERIAL_BASE_COLOR_TEXTURE,          SY_MATERIAL_METALLIC_ROUGHNESS_TEXTURE,
    SY_MATERIAL_NORMAL_TEXTURE,              SY_MATERIAL_OCCLUSION_TEXTURE,
    SY_MATERIAL_EMISSIVE_TEXTURE,            SY_MATERIAL_TRANSMISSION_TEXTURE,
    SY_MATERIAL_SPECULAR_TEXTURE,            SY_MATERIAL_SPECULAR_COLOR_TEXTURE,
    SY_MATERIAL_CLEARCOAT_TEXTURE,           SY_MATERIAL_CLEARCOAT_ROUGHNESS_TEXTURE,
    SY_MATERIAL_CLEARCOAT_NORMAL_TEXTURE,    SY_MATERIAL_SHEEN_COLOR_TEXTURE,
    SY_MATERIAL_SHEEN_ROUGHNESS_TEXTURE,     SY_MATERIAL_THICKNESS_TEXTURE,
    SY_MATERIAL_IRIDESCENCE_TEXTURE,         SY_MATERIAL_IRIDESCENCE_THICKNESS_TEXTURE,
    SY_MATERIAL_ANISOTROPY_TEXTURE,
};

const sy_texture_ref *sy_material_texture(const sy_material_data *d, uint32_t f)
{
    const sy_type_desc *td = sy__type_desc(SY_TYPE_MATERIAL);
    if (!d || f >= td->field_count || td->fields[f].size != sizeof(sy_texture_ref)) return NULL;
    for (uint32_t i = 0; i < SY_MATERIAL_TEXTURE_SLOTS; ++i)
        if (sy_material_texture_fields[i] == f) return (const sy_texture_ref *)((const char *)d + td->fields[f].offset);
    return NULL;
}

bool sy_material_uses_texture(const sy_material_data *d, uint32_t tex)
{
    for (uint32_t i = 0; i < SY_MATERIAL_TEXTURE_SLOTS; ++i)
        if (sy_material_texture(d, sy_material_texture_fields[i])->texture.id == tex) return true;
    return false;
}

void sy_object_data_merge(sy_object_type t, void *dst, const void *src, uint64_t mask)
{
    const sy_type_desc *td = sy__type_desc(t);
    if (!td) return;
    for (uint32_t f = 0; f < td->field_count; ++f)
        if ((mask & SY_BIT(f)) && td->fields[f].kind == SY_FK_POD)
            memcpy((char *)dst + td->fields[f].offset, (const char *)src + td->fields[f].offset, td->fields[f].size);
}

/* >>attachments */
sy_result sy_sc_set_attachments(sy_scene *s, uint32_t t, uint32_t id, slot *sl, sy_attachment *a, uint32_t n,
                                 sy_error *err)
{
    if (!sy_sc_mark_dirty(s, t, id, sl, SY_BIT(SY_FIELD_ATTACHMENTS), 0)) {
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
    slot *sl = sy_sc_lookup(s, t, id);
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
    return sy_sc_set_attachments(s, t, id, sl, na, w, err);
}

sy_result sy_object_remove_attachment(sy_scene *s, sy_object_type t, uint32_t id, const char *key, sy_error *err)
{
    slot *sl = sy_sc_lookup(s, t, id);
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
    return sy_sc_set_attachments(s, t, id, sl, na, n, err);
}

const sy_attachment *sy_object_attachments(const sy_scene *s, sy_object_type t, uint32_t id, uint32_t *count_out)
{
    slot *sl = sy_sc_lookup(s, t, id);
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
