/* sy_scene_graph.c — the scene as a graph: parents of nodes, world matrices and subtree bounds
 * recomputed incrementally for dirty subtrees (each node's once per commit), reachability and
 * cycle checks, and the graph queries of sy_graph.h. */
#include "sy_scene_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* >>graph */
void sy_sc_mark_world_dirty(sy_scene *s, uint32_t node_id)
{
    node_extra *nx = sy_sc_nx_of(s, node_id);
    if (!nx || nx->world_dirty) return;
    nx->world_dirty = 1;
    sy_sc_list_push(&s->world_dirty, node_id);
}

/* Marks node_id and every ancestor (along all parents) as needing new local bounds. */
void sy_sc_mark_bounds_dirty(sy_scene *s, uint32_t node_id)
{
    id_list *st = &s->stack;
    st->count = 0;
    sy_sc_list_push(st, node_id);
    while (st->count) {
        uint32_t id = st->items[--st->count];
        node_extra *nx = sy_sc_nx_of(s, id);
        if (!nx || nx->bounds_dirty) continue;
        nx->bounds_dirty = 1;
        sy_sc_list_push(&s->bounds_dirty, id);
        for (uint32_t i = 0; i < nx->parent_count; ++i) sy_sc_list_push(st, nx->parents[i]);
    }
}

void sy_sc_mark_parents_bounds_dirty(sy_scene *s, uint32_t node_id)
{
    node_extra *nx = sy_sc_nx_of(s, node_id);
    if (!nx) return;
    for (uint32_t i = 0; i < nx->parent_count; ++i) sy_sc_mark_bounds_dirty(s, nx->parents[i]);
}

static uint32_t primary_parent(const sy_scene *s, const node_extra *nx)
{
    for (uint32_t i = 0; i < nx->parent_count; ++i)
        if (sy_sc_lookup(s, SY_TYPE_NODE, nx->parents[i])) return nx->parents[i];
    return 0;
}

const uint32_t *sy_node_children(const sy_node_data *d, uint32_t *count_out)
{
    *count_out = d && d->children ? (uint32_t)(sy_blob_size(d->children) / 4) : 0;
    return *count_out ? (const uint32_t *)sy_blob_data(d->children) : NULL;
}

/* Starts a walk from root on s->stack under a fresh epoch when root is still a node whose world
 * (world: true) or bounds flag is dirty; false: nothing to walk from it. */
static bool walk_from_dirty(sy_scene *s, uint32_t root, bool world)
{
    node_extra *nx = sy_sc_nx_of(s, root);
    if (!nx || !(world ? nx->world_dirty : nx->bounds_dirty)) return false;
    s->stack.count = 0;
    sy_sc_list_push(&s->stack, root);
    s->epoch++;
    return true;
}

/* Recomputes world matrices of every world-dirty node and the part of its subtree placed
 * through it (children whose primary parent it is). Cost: the dirty subtrees only. */
void sy_sc_update_world(sy_scene *s)
{
    uint32_t updates = 0;
    id_list *st = &s->stack;
    if (s->world_dirty.count) s->world_stamp++;
    for (uint32_t i = 0; i < s->world_dirty.count; ++i) {
        if (!walk_from_dirty(s, s->world_dirty.items[i], true)) continue;
        while (st->count) {
            uint32_t id = st->items[--st->count];
            slot *sl = sy_sc_lookup(s, SY_TYPE_NODE, id);
            if (!sl || sl->nx->mark == s->epoch) continue; /* guards against cycles from bad input */
            node_extra *nx = sl->nx;
            nx->mark = s->epoch;
            const sy_node_data *d = sl->data;
            uint32_t pp = primary_parent(s, nx);
            node_extra *pnx = pp ? sy_sc_nx_of(s, pp) : NULL;
            sy_placement above = {.visible = true};
            if (pnx) above.world = pnx->world;
            nx->world = sy_placement_child(pnx ? &above : NULL, &d->transform.matrix, d->flags).world;
            nx->world_dirty = 0;
            nx->world_stamp = s->world_stamp;
            updates++;
            uint32_t nc;
            const uint32_t *ch = sy_node_children(d, &nc);
            for (uint32_t k = 0; k < nc; ++k) {
                node_extra *cnx = sy_sc_nx_of(s, ch[k]);
                if (cnx && primary_parent(s, cnx) == id) sy_sc_list_push(st, ch[k]);
            }
        }
    }
    s->world_dirty.count = 0;
    s->last_world_updates = updates;
}

/* >>skinned bounds
 * A skinned mesh is placed by its joints, not its node (glTF; the deformer, mediators/sy_deform, puts
 * each vertex at sum_k w_k (joint_k world x inverse_bind_k) p in world space). Its bounds are the
 * union over the joint indices of each joint's bind-pose vertex bounds (sy_sc_mesh_joint_bounds,
 * once per mesh's primitives) placed by that joint's matrix: a vertex blended from several joints (weights
 * summing to 1) lies in the hull of its placements, so inside the union. The box is brought into
 * the node's frame (local_bounds) through the inverse of the node's world matrix. Morph targets
 * are not counted (bind-shape bounds). */
static int skin_mesh_cmp(const void *key, const void *e)
{
    uint32_t a = *(const uint32_t *)key, b = ((const skin_mesh *)e)->mesh;
    return a < b ? -1 : a > b;
}

skin_mesh *sy_sc_skin_mesh_find(const sy_scene *s, uint32_t mesh_id)
{
    return s->skin_mesh_count ? bsearch(&mesh_id, s->skin_meshes, s->skin_mesh_count, sizeof *s->skin_meshes, skin_mesh_cmp)
                              : NULL;
}

/* (public, sy_objects.h; here, below the setters' module, for the skinned bounds) */
const sy_skin_joint *sy_node_skin(const sy_node_data *d, uint32_t *count_out)
{
    *count_out = d && d->skin ? (uint32_t)(sy_blob_size(d->skin) / sizeof(sy_skin_joint)) : 0;
    return *count_out ? (const sy_skin_joint *)sy_blob_data(d->skin) : NULL;
}

/* The nodes whose skin places a mesh with joint bounds (rebuilt after a skin or mesh field changed). */
static void skinned_rebuild(sy_scene *s)
{
    s->skinned.count = 0;
    s->skinned_stale = false;
    const pool *p = &s->pools[SY_TYPE_NODE];
    for (uint32_t i = 1; i < p->count; ++i) {
        const slot *sl = &p->slots[i];
        if (!sl->alive) continue;
        const sy_node_data *d = sl->data;
        uint32_t nj = 0;
        if (d->skin && sy_sc_skin_mesh_find(s, d->mesh.id) && sy_node_skin(d, &nj) && nj &&
            !sy_sc_list_push(&s->skinned, make_id(i, sl->generation))) {
            s->skinned_stale = true; /* out of memory: try again next commit */
            return;
        }
    }
}

/* After sy_sc_update_world: a skinned node whose joints (or itself) moved needs new bounds. */
void sy_sc_mark_skins_moved(sy_scene *s)
{
    if (s->skinned_stale) skinned_rebuild(s);
    if (!s->last_world_updates) return;
    for (uint32_t i = 0; i < s->skinned.count; ++i) {
        uint32_t id = s->skinned.items[i];
        slot *sl = sy_sc_lookup(s, SY_TYPE_NODE, id);
        if (!sl) continue;
        bool moved = sl->nx->world_stamp == s->world_stamp;
        uint32_t nj = 0;
        const sy_skin_joint *sj = sy_node_skin(sl->data, &nj);
        for (uint32_t j = 0; j < nj && !moved; ++j) {
            const node_extra *jx = sy_sc_nx_of(s, sj[j].node);
            moved = jx && jx->world_stamp == s->world_stamp;
        }
        if (moved) sy_sc_mark_bounds_dirty(s, id);
    }
}

/* The bounds of a node's own mesh in the node's frame (skinned: above). */
static sy_bounds own_mesh_bounds(const sy_scene *s, const node_extra *nx, const sy_node_data *d, const slot *ms)
{
    uint32_t nj = 0;
    const sy_skin_joint *sj = sy_node_skin(d, &nj);
    const skin_mesh *sm = nj ? sy_sc_skin_mesh_find(s, d->mesh.id) : NULL;
    sy_mat4 inv;
    if (!sm || !sy_mat4_invert(&nx->world, &inv)) return ms->bounds;
    sy_bounds w = sm->bounds[sm->count]; /* the vertices no joint moves stay as they are */
    for (uint32_t j = 0; j < sm->count; ++j) {
        if (sy_bounds_is_empty(&sm->bounds[j])) continue;
        if (j >= nj) { /* past the skin: drawn undeformed */
            sy_bounds_add_bounds(&w, &sm->bounds[j]);
            continue;
        }
        const node_extra *jx = sy_sc_nx_of(s, sj[j].node);
        sy_mat4 m = jx ? sy_mat4_mul(&jx->world, &sj[j].inverse_bind) : sj[j].inverse_bind; /* unplaced: identity */
        sy_bounds pb = sy_bounds_transform(&sm->bounds[j], &m);
        sy_bounds_add_bounds(&w, &pb);
    }
    return sy_bounds_transform(&w, &inv);
}

/* Recomputes local bounds of bounds-dirty nodes in post order (children first). */
void sy_sc_update_bounds(sy_scene *s)
{
    id_list *st = &s->stack;
    for (uint32_t i = 0; i < s->bounds_dirty.count; ++i) {
        if (!walk_from_dirty(s, s->bounds_dirty.items[i], false)) continue;
        while (st->count) {
            uint32_t id = st->items[st->count - 1];
            slot *sl = sy_sc_lookup(s, SY_TYPE_NODE, id);
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
                    node_extra *cnx = sy_sc_nx_of(s, ch[k]);
                    if (cnx && cnx->bounds_dirty && cnx->mark != s->epoch) {
                        sy_sc_list_push(st, ch[k]);
                        pushed = true;
                    }
                }
                if (pushed) continue;
            }
            st->count--;
            sy_bounds b = sy_bounds_empty();
            slot *ms = sy_sc_lookup(s, SY_TYPE_MESH, d->mesh.id);
            if (ms) b = own_mesh_bounds(s, sl->nx, d, ms);
            for (uint32_t k = 0; k < nc; ++k) {
                slot *cs = sy_sc_lookup(s, SY_TYPE_NODE, ch[k]);
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
bool sy_sc_reaches(sy_scene *s, const uint32_t *from, uint32_t n, uint32_t target)
{
    id_list st = {0};
    s->epoch++;
    bool found = false;
    for (uint32_t i = 0; i < n && !found; ++i) found = !sy_sc_list_push(&st, from[i]);
    while (st.count && !found) {
        uint32_t id = st.items[--st.count];
        if (id == target) {
            found = true;
            break;
        }
        slot *sl = sy_sc_lookup(s, SY_TYPE_NODE, id);
        if (!sl || sl->nx->mark == s->epoch) continue;
        sl->nx->mark = s->epoch;
        uint32_t nc;
        const uint32_t *ch = sy_node_children(sl->data, &nc);
        for (uint32_t k = 0; k < nc && !found; ++k) found = !sy_sc_list_push(&st, ch[k]);
    }
    free(st.items);
    return found;
}

/* A cycle through a node whose children a change list set: one depth-first walk from all of them
 * (grey = on the walk's path, black = done; each node visited once, so a snapshot of a large
 * graph costs its size, not its size per changed node). *at names a node on the cycle. An
 * allocation failure answers true. */
bool sy_sc_find_cycle(sy_scene *s, const sy_changes *changes, uint32_t *at)
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
        slot *root = sy_sc_lookup(s, SY_TYPE_NODE, e->id);
        if (!root || root->nx->mark == black) continue;
        depth = 0;
        uint32_t id = e->id;
        for (;;) {
            slot *sl = sy_sc_lookup(s, SY_TYPE_NODE, id);
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
                sy_sc_lookup(s, SY_TYPE_NODE, f->id)->nx->mark = black;
                depth--;
            }
            if (!id) break;
        }
    }
    free(st);
    return found;
}

int sy_sc_cmp_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

/* >>world walk (sy_graph.h): the one rule placing a node under its parent */
sy_placement sy_placement_child(const sy_placement *parent, const sy_mat4 *local, uint32_t flags)
{
    bool own = (flags & SY_NODE_VISIBLE) != 0, sel = (flags & SY_NODE_SELECTED) != 0;
    if (!parent) return (sy_placement){.world = *local, .visible = own, .selected = sel};
    return (sy_placement){.world = sy_mat4_mul(&parent->world, local), .visible = parent->visible && own,
                          .selected = parent->selected || sel};
}

/* Reports one node (reached under `above`, NULL for a path's start) to fn; *place receives its
 * placement and *enter whether its children come next. */
static sy_result walk_visit(const sy_scene *s, uint32_t id, const sy_placement *above, uint32_t depth, uint32_t flags,
                            sy_walk_fn fn, void *user, sy_placement *place, bool *enter, sy_error *err)
{
    *enter = false;
    sy_walk_step st = {.node = {id}, .data = sy_object_get(s, SY_TYPE_NODE, id), .depth = depth};
    if (st.data) {
        st.place = sy_placement_child(above, &st.data->transform.matrix, st.data->flags);
        if ((flags & SY_WALK_VISIBLE_ONLY) && !st.place.visible) return SY_OK;
    }
    sy_result r = fn(user, &st, err);
    *place = st.place;
    *enter = r == SY_OK && st.data != NULL;
    return r;
}

sy_result sy_scene_walk(const sy_scene *s, sy_node root, const sy_placement *above, uint32_t flags, sy_walk_fn fn,
                        void *user, sy_error *err)
{
    typedef struct frame {
        sy_placement place;
        uint32_t id, depth, next; /* next: the next child to visit */
    } frame;
    frame *st = NULL;
    uint32_t depth = 0, cap = 0, id = root.id, level = 0;
    const sy_placement *parent = above;
    sy_result r;
    for (;;) {
        sy_placement place;
        bool enter;
        r = walk_visit(s, id, parent, level, flags, fn, user, &place, &enter, err);
        if (r != SY_OK) break;
        if (enter) { /* its children come next */
            if (depth == cap) {
                uint32_t nc = cap ? cap * 2u : 32u;
                frame *ns = realloc(st, sizeof *ns * nc);
                if (!ns) {
                    r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "scene walk: out of memory");
                    break;
                }
                st = ns, cap = nc;
            }
            st[depth++] = (frame){.place = place, .id = id, .depth = level, .next = 0};
        }
        /* the next node: the next child of the deepest node that has one left */
        bool found = false;
        while (depth && !found) {
            frame *f = &st[depth - 1];
            uint32_t nc;
            const uint32_t *ch = sy_node_children(sy_object_get(s, SY_TYPE_NODE, f->id), &nc);
            if (f->next < nc) {
                id = ch[f->next++], parent = &f->place, level = f->depth + 1u, found = true;
            } else {
                depth--;
            }
        }
        if (!found) break;
    }
    free(st);
    return r;
}

/* >>graph queries */
uint32_t sy_node_parent_count(const sy_scene *s, sy_node n)
{
    node_extra *nx = sy_sc_nx_of(s, n.id);
    return nx ? nx->parent_count : 0;
}

sy_node sy_node_parent(const sy_scene *s, sy_node n, uint32_t i)
{
    node_extra *nx = sy_sc_nx_of(s, n.id);
    sy_node r = {0};
    if (nx && i < nx->parent_count) r.id = nx->parents[i];
    return r;
}

sy_result sy_node_world_matrix(const sy_scene *s, sy_node n, sy_mat4 *out, sy_error *err)
{
    node_extra *nx = sy_sc_nx_of(s, n.id);
    if (!nx) return sy_error_set(err, SY_ERR_INVALID_HANDLE, "world matrix: stale node handle");
    *out = nx->world;
    return SY_OK;
}

sy_result sy_node_world_bounds(const sy_scene *s, sy_node n, sy_bounds *out, sy_error *err)
{
    node_extra *nx = sy_sc_nx_of(s, n.id);
    if (!nx) return sy_error_set(err, SY_ERR_INVALID_HANDLE, "world bounds: stale node handle");
    /* local_bounds are in the node's frame before its own transform; world = parent world * local */
    *out = sy_bounds_transform(&nx->local_bounds, &nx->world);
    return SY_OK;
}

sy_result sy_mesh_bounds(const sy_scene *s, sy_mesh m, sy_bounds *out, sy_error *err)
{
    slot *sl = sy_sc_lookup(s, SY_TYPE_MESH, m.id);
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
