/* sy_mirror.c — the scene mirror shared by the mediators (see sy_mirror.h).
 *
 * Sections: >>tables (id-indexed mirrors)  >>textures/materials/meshes  >>nodes and placements
 * >>entries  >>sync  >>lifetime */
#include "sy_mirror.h"
#include "sy_deform_cache.h"
#include "sy_log.h"
#include "sy_strokes.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define IDX(id) ((id) & SY_HANDLE_INDEX_MASK)

/* >>tables: every mirror is an array indexed by the handle's slot index, holding the full id so
 * a stale id never matches. */
typedef struct tex_m {
    uint32_t id;
    sy_image_info info;
    sy_sampler sampler;
    sy_blob *pixels;
    uint32_t handle;
} tex_m;

typedef struct mat_m {
    uint32_t id;
    sy_material_data d; /* POD fields only (name not kept) */
    uint32_t handle;
} mat_m;

typedef struct prim_m {
    uint32_t handle;
    uint32_t material; /* core material id */
} prim_m;

typedef struct mesh_m {
    uint32_t id;
    prim_m *prims;
    uint32_t prim_count;
    sy_bounds bounds; /* of the drawn triangles, strokes' tubes included (placements are checked with it) */
    uint32_t *users; /* node ids */
    uint32_t user_count, user_capacity;
    sy_primitive *src;  /* the primitives (blobs retained) when one has morph targets or joints; else NULL */
    uint32_t src_count;
    sy_blob *weights;   /* default morph weights (retained) */
    bool has_joints;    /* some primitive has joints and weights */
} mesh_m;

typedef struct light_m {
    uint32_t id;
    sy_light_data d;
    uint32_t *users;
    uint32_t user_count, user_capacity;
} light_m;

typedef struct placement {
    sy_placement place; /* world matrix and visibility along this path (sy_placement_child, sy_graph.h) */
    uint32_t *inst; /* one per primitive of the node's mesh */
    uint32_t inst_count;
    uint32_t light;
} placement;

typedef struct node_m {
    uint32_t id;
    sy_mat4 local;
    uint32_t *children;
    uint32_t child_count;
    uint32_t mesh, light, flags;
    uint32_t *parents;
    uint32_t parent_count, parent_capacity;
    placement *pl;
    uint32_t pl_count;
    uint32_t visit;   /* sync epoch: re-placed in this sync */
    uint32_t pending; /* parents in the set being re-placed that are not done yet */
    uint32_t dry_pending; /* the same, for the counting pass */
    uint64_t paths;       /* the counting pass: placements it will have (saturating) */
    /* deformation (sy_deform.h): a node whose mesh has morph targets or joints */
    sy_blob *weights, *skin; /* SY_NODE_WEIGHTS, SY_NODE_SKIN (retained) */
    uint32_t *dprims;        /* its own back-end primitives, deformed (one per mesh primitive; NULL: not made) */
    uint32_t dprim_count;
    sy_bounds dbounds;       /* of the deformed positions (world space when skinned) */
    bool deformer;           /* listed in the mirror's deformers */
    bool deform_dirty;       /* weights, skin or mesh changed: deform in this sync */
    bool skinned;            /* deformed by a skin: its instances take the identity, not the placement */
} node_m;

struct sy_mirror {
    const char *name;
    uint32_t root;
    const sy_mirror_callbacks *cb;
    void *user;
    tex_m *tex;
    uint32_t tex_cap;
    mat_m *mat;
    uint32_t mat_cap;
    mesh_m *mesh;
    uint32_t mesh_cap;
    light_m *light;
    uint32_t light_cap;
    sy_mirror_background *bg;
    uint32_t bg_cap;
    node_m *node;
    uint32_t node_cap;
    uint32_t *dirty; /* node ids to re-place */
    uint32_t dirty_count, dirty_capacity;
    uint32_t epoch;
    sy_mirror_sync_stats *stats; /* of the running sync */
    uint32_t light_placements;   /* placements holding a back-end light (visible ones) */
    uint32_t emissive_materials; /* mirrored materials whose emission lights the scene (radiance > 1) */
    uint32_t default_material;   /* back-end handle of glTF's default material (0 = not made yet) */
    uint32_t placements;         /* placements of every node */
    uint32_t placements_max;     /* SY_MIRROR_PLACEMENTS_MAX */
    uint32_t *deformers;         /* node ids whose mesh has morph targets or joints */
    uint32_t deformer_count, deformer_cap;
    sy_mat4 *joint_scratch;      /* composed joint matrices of the node being deformed */
    uint32_t joint_scratch_cap;
    uint32_t cache_slot;         /* this mirror's taker slot in the shared poses (sy_deform_cache.h) */
};

static const sy_mat4 identity_world = {{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}};

/* An emitter that lights the scene (sy_look.h): emitted radiance above 1 in some channel. */
static bool material_emits(const sy_material_data *d)
{
    float m = d->emissive[0] > d->emissive[1] ? d->emissive[0] : d->emissive[1];
    m = m > d->emissive[2] ? m : d->emissive[2];
    return m * d->emissive_strength > 1.0f;
}

static bool grow(void **arr, uint32_t *cap, size_t elem, uint32_t index)
{
    if (index < *cap) return true;
    uint32_t nc = *cap ? *cap : 64;
    while (nc <= index) nc *= 2;
    void *n = realloc(*arr, elem * nc);
    if (!n) return false;
    memset((char *)n + elem * *cap, 0, elem * (nc - *cap));
    *arr = n;
    *cap = nc;
    return true;
}

/* The record of id in an array of records indexed by IDX(id), grown (zeroed) to hold it and cleared;
 * NULL when out of memory. */
static void *slot_new(void **arr, uint32_t *cap, size_t elem, uint32_t id)
{
    if (!grow(arr, cap, elem, IDX(id))) return NULL;
    return memset((char *)*arr + elem * IDX(id), 0, elem);
}
#define SLOT_NEW(st_, arr_, cap_, id_) slot_new((void **)&(st_)->arr_, &(st_)->cap_, sizeof *(st_)->arr_, (id_))
#define LOOKUP(st_, arr_, cap_, id_) ((id_) && IDX(id_) < (st_)->cap_ && (st_)->arr_[IDX(id_)].id == (id_) ? &(st_)->arr_[IDX(id_)] : NULL)

static void remove_u32(uint32_t *items, uint32_t *count, uint32_t v)
{
    for (uint32_t i = 0; i < *count; ++i)
        if (items[i] == v) {
            items[i] = items[--*count];
            return;
        }
}

static void mark_node_dirty(sy_mirror *st, uint32_t id)
{
    sy_u32_push(&st->dirty, &st->dirty_count, &st->dirty_capacity, id);
}

static void release(sy_mirror *st, sy_mirror_kind kind, uint32_t handle)
{
    sy_mirror_release_args a = {kind, handle};
    st->cb->release(st->user, &a);
}

static void notify(sy_mirror *st, sy_object_type type, uint32_t id, bool destroyed)
{
    sy_mirror_object_args a = {type, id, destroyed};
    if (st->cb->object_changed) st->cb->object_changed(st->user, &a);
}

static sy_result oom(const sy_mirror *st, sy_error *err)
{
    return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", st->name);
}

/* >>textures */
static uint32_t texture_handle_of(const void *st, uint32_t texture_id) { return sy_mirror_texture_handle(st, texture_id); }

static sy_result material_set(sy_mirror *st, uint32_t id, const sy_material_data *d, uint32_t *handle, sy_error *err)
{
    if (!st->cb->material_set) return SY_OK; /* no materials: the handle stays 0 */
    sy_mirror_flat_material flat;
    sy_mirror_flat_material_of(d, texture_handle_of, st, &flat);
    sy_mirror_material_args a = {id, d, handle, &flat};
    return st->cb->material_set(st->user, &a, err);
}

static sy_result material_upload(sy_mirror *st, mat_m *m, sy_error *err) { return material_set(st, m->id, &m->d, &m->handle, err); }

static sy_result texture_upload(sy_mirror *st, tex_m *t, sy_error *err)
{
    if (t->handle) release(st, SY_MIRROR_TEXTURE, t->handle);
    t->handle = 0;
    size_t elem = t->info.format == SY_PIXEL_F32 ? 4 : 1, need;
    if (!t->pixels || t->info.width == 0 || t->info.height == 0 ||
        !sy_size_mul((size_t)t->info.width * t->info.height, (size_t)t->info.channels * elem, &need) ||
        sy_blob_size(t->pixels) != need)
        return SY_OK; /* incomplete texture: materials render without it */
    if (!st->cb->texture_set) return SY_OK; /* no textures: the handle stays 0 */
    sy_mirror_flat_texture flat;
    sy_mirror_flat_texture_of(&t->info, &t->sampler, sy_blob_data(t->pixels), &flat);
    sy_mirror_texture_args a = {t->id, &t->info, &t->sampler, flat.pixels, &t->handle, &flat};
    sy_result r = st->cb->texture_set(st->user, &a, err);
    if (r != SY_OK) return r;
    notify(st, SY_TYPE_TEXTURE, t->id, false);
    /* materials referring to this texture get the new back-end handle */
    for (uint32_t i = 0; i < st->mat_cap; ++i) {
        mat_m *m = &st->mat[i];
        if (m->id && m->handle && sy_material_uses_texture(&m->d, t->id)) {
            sy_result rr = material_upload(st, m, err);
            if (rr != SY_OK) return rr;
        }
    }
    return SY_OK;
}

/* >>meshes */
static void mesh_free_src(mesh_m *m)
{
    for (uint32_t i = 0; i < m->src_count; ++i) sy_primitive_release(&m->src[i]);
    free(m->src);
    m->src = NULL;
    m->src_count = 0;
    m->has_joints = false;
}

/* Keeps the primitives (their blobs retained) of a mesh with something to deform. */
static bool mesh_keep_src(mesh_m *m, const sy_primitive_list *pl)
{
    mesh_free_src(m);
    bool any = false;
    for (uint32_t i = 0; i < pl->count; ++i) {
        any = any || sy_deform_has_data(&pl->items[i]);
        m->has_joints = m->has_joints || sy_primitive_influences(&pl->items[i]) > 0;
    }
    if (!any) return true;
    m->src = calloc(pl->count, sizeof *m->src);
    if (!m->src) return false;
    m->src_count = pl->count;
    for (uint32_t i = 0; i < pl->count; ++i) {
        sy_primitive *q = &m->src[i];
        *q = pl->items[i];
        sy_blob *bl[13] = {q->positions, q->normals, q->tangents, q->texcoords0, q->texcoords1, q->colors,
                           q->indices,   q->joints,  q->weights,  q->target_positions, q->target_normals, q->target_tangents,
                           q->target_texcoords0};
        for (int k = 0; k < 13; ++k) sy_blob_retain(bl[k]);
    }
    return true;
}

static void mesh_free_prims(sy_mirror *st, mesh_m *m)
{
    for (uint32_t i = 0; i < m->prim_count; ++i)
        if (m->prims[i].handle) release(st, SY_MIRROR_PRIMITIVE, m->prims[i].handle);
    free(m->prims);
    m->prims = NULL;
    m->prim_count = 0;
}

static sy_result mesh_upload(sy_mirror *st, mesh_m *m, const sy_primitive_list *pl, sy_error *err)
{
    mesh_free_prims(st, m);
    m->bounds = sy_bounds_empty();
    if (pl->count == 0) return SY_OK;
    m->prims = calloc(pl->count, sizeof *m->prims);
    if (!m->prims) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s: mesh: out of memory", st->name);
    m->prim_count = pl->count;
    for (uint32_t i = 0; i < pl->count; ++i) {
        const sy_primitive *p = &pl->items[i];
        m->prims[i].material = p->material.id;
        if (p->topology != SY_TOPOLOGY_TRIANGLES) {
            /* strokes: the same tubes and balls for every back-end (sy_strokes.h) */
            if (sy_primitive_element_count(p) == 0) continue;
            char what[96];
            snprintf(what, sizeof what, "%s: mesh %#x primitive %u", st->name, m->id, i);
            sy_bounds b = sy_primitive_position_bounds(p);
            float width = sy_primitive_stroke_width(p, &b);
            if (!sy_bounds_is_empty(&b))
                for (int k = 0; k < 3; ++k) b.min[k] -= width, b.max[k] += width;
            sy_bounds_add_bounds(&m->bounds, &b);
            sy_primitive tri;
            sy_result r = sy_strokes_tessellate(p, width, what, &tri, err);
            if (r != SY_OK) return r;
            sy_mirror_flat_mesh flat;
            sy_mirror_flat_mesh_of(&tri, &flat);
            sy_mirror_primitive_args a = {m->id, i, &tri, &m->prims[i].handle, &flat};
            r = st->cb->primitive_set(st->user, &a, err);
            sy_primitive_release(&tri); /* back-ends copy what they keep */
            if (r != SY_OK) return r;
            continue;
        }
        if (sy_primitive_triangle_count(p) == 0) continue;
        sy_bounds b = sy_primitive_position_bounds(p);
        sy_bounds_add_bounds(&m->bounds, &b);
        sy_mirror_flat_mesh flat;
        sy_mirror_flat_mesh_of(p, &flat);
        sy_mirror_primitive_args a = {m->id, i, p, &m->prims[i].handle, &flat};
        sy_result r = st->cb->primitive_set(st->user, &a, err);
        if (r != SY_OK) return r;
    }
    return SY_OK;
}

/* >>nodes and placements */
static void drop_instances(sy_mirror *st, placement *p)
{
    for (uint32_t i = 0; i < p->inst_count; ++i)
        if (p->inst[i]) release(st, SY_MIRROR_INSTANCE, p->inst[i]);
    free(p->inst);
    p->inst = NULL;
    p->inst_count = 0;
}

static void placement_clear(sy_mirror *st, placement *p)
{
    drop_instances(st, p);
    if (p->light) {
        release(st, SY_MIRROR_LIGHT, p->light);
        st->light_placements--;
    }
    p->light = 0;
}

/* The back-end material for primitives without one: glTF 2.0's default material, made once. */
static sy_result default_material(sy_mirror *st, uint32_t *handle, sy_error *err)
{
    if (!st->default_material) {
        sy_material_data d = *(const sy_material_data *)sy_object_defaults(SY_TYPE_MATERIAL);
        d.name = NULL;
        sy_result r = material_set(st, 0, &d, &st->default_material, err);
        if (r != SY_OK) return r;
    }
    *handle = st->default_material;
    return SY_OK;
}

/* Whether a placement can be drawn (docs/FORMATS.md, "Numbers in range"): its world transform
 * must keep the node's origin and its mesh within SY_COORD_MAX, and must not collapse space (a
 * zero or vanishing scale: glTF's way of hiding a part; no back-end can invert it). An undrawn
 * placement keeps its place in the graph and comes back when the transform does. */
static bool placement_drawable(sy_mirror *st, const node_m *n, const placement *p, const mesh_m *m)
{
    if (sy_mat4_is_degenerate(&p->place.world)) return false; /* hidden, as the file meant */
    bool in_range = sy_coords_in_range(&p->place.world.m[12], 3);
    const sy_bounds *mb = m ? (n->dprims ? &n->dbounds : &m->bounds) : NULL;
    if (in_range && mb && !sy_bounds_is_empty(mb)) {
        sy_bounds wb = sy_bounds_transform(mb, n->skinned && n->dprims ? &identity_world : &p->place.world);
        in_range = sy_coords_in_range(wb.min, 3) && sy_coords_in_range(wb.max, 3);
    }
    if (!in_range) {
        char item[32];
        snprintf(item, sizeof item, "node %#x", n->id);
        sy_log(SY_LOG_WARNING, st->name, item,
               "placed beyond the coordinate range (origin at %g %g %g; at most %g): not drawn", (double)p->place.world.m[12],
               (double)p->place.world.m[13], (double)p->place.world.m[14], (double)SY_COORD_MAX);
    }
    return in_range;
}

/* Brings a placement's instances and light in line with the node's mesh/light and the world
 * matrix; only what changed is touched. */
static sy_result placement_sync(sy_mirror *st, node_m *n, uint32_t index, bool mesh_changed, sy_error *err)
{
    placement *p = &n->pl[index];
    const mesh_m *m = LOOKUP(st, mesh, mesh_cap, n->mesh);
    const light_m *l = LOOKUP(st, light, light_cap, n->light);
    if ((m || l) && !placement_drawable(st, n, p, m)) {
        placement_clear(st, p); /* its instances and light go; they come back with a drawable transform */
        return SY_OK;
    }
    /* a deformer draws its own deformed primitives, once they are made (the deform pass, after the
     * placements: its joints' placements drive it); skinned ones in world space */
    uint32_t want = m && (!n->deformer || n->dprims) ? m->prim_count : 0;
    const uint32_t *prim_handles = NULL;
    const sy_mat4 *world = n->skinned && n->dprims ? &identity_world : &p->place.world;
    bool visible = p->place.visible;
    if (mesh_changed || want != p->inst_count) {
        drop_instances(st, p);
        if (want) {
            p->inst = calloc(want, sizeof *p->inst);
            if (!p->inst) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s: instances: out of memory", st->name);
            p->inst_count = want;
            bool bake = (n->flags & SY_NODE_STATIC) && m->user_count == 1 && n->pl_count == 1;
            for (uint32_t i = 0; i < want; ++i) {
                prim_handles = n->dprims && i < n->dprim_count ? n->dprims : NULL;
                uint32_t ph = prim_handles ? prim_handles[i] : m->prims[i].handle;
                if (!ph) continue;
                const mat_m *mm = LOOKUP(st, mat, mat_cap, m->prims[i].material);
                uint32_t mh = mm ? mm->handle : 0u;
                sy_result r = mh ? SY_OK : default_material(st, &mh, err);
                if (r != SY_OK) return r;
                sy_mirror_instance_args a = {n->id, index, ph, mh, world, visible, bake && !n->deformer, &p->inst[i],
                                              p->place.selected};
                r = st->cb->instance_set(st->user, &a, err);
                if (r != SY_OK) return r;
            }
        }
    } else {
        for (uint32_t i = 0; i < p->inst_count; ++i) {
            if (!p->inst[i]) continue;
            sy_mirror_instance_args a = {n->id, index, 0, 0, world, visible, false, &p->inst[i], p->place.selected};
            sy_result r = st->cb->instance_set(st->user, &a, err);
            if (r != SY_OK) return r;
        }
    }
    if (l && visible && st->cb->light_set) {
        /* one reading of a spot cone for every back-end: inner >= outer is a hard edge */
        sy_light_data ld = l->d;
        if (ld.type == SY_LIGHT_SPOT && ld.inner_cone >= ld.outer_cone) ld.inner_cone = ld.outer_cone * 0.999f;
        sy_mirror_light_args a = {.node = n->id, .placement = index, .light = &ld, .handle = &p->light};
        float o[3] = {0, 0, 0}, z[3] = {0, 0, -1};
        sy_mat4_transform_point(&p->place.world, o, a.position);
        sy_mat4_transform_dir(&p->place.world, z, a.direction);
        sy_mirror_flat_light flat;
        sy_mirror_flat_light_of(&ld, a.position, a.direction, &flat);
        a.flat = &flat;
        bool had = p->light != 0;
        sy_result r = st->cb->light_set(st->user, &a, err);
        if (!had && p->light) st->light_placements++;
        if (r != SY_OK) return r;
    } else if (p->light) {
        release(st, SY_MIRROR_LIGHT, p->light);
        p->light = 0;
        st->light_placements--;
    }
    return SY_OK;
}

/* Recomputes the placements of every dirty node and of their subtrees, each node once: the nodes
 * reachable from the dirty ones are collected, then placed in topological order (a node after all
 * of its parents in the set), so a DAG of k paths costs its nodes plus its k placements, not one
 * walk per path. A node's placements are its parents' placements times its local matrix; their
 * total is capped (SY_MIRROR_PLACEMENTS_MAX) before anything is allocated. */
static sy_result replace_dirty(sy_mirror *st, sy_error *err)
{
    uint32_t *set = NULL, count = 0, cap = 0;
    sy_result r = SY_OK;
    /* collect: visit = epoch marks membership */
    for (uint32_t i = 0; i < st->dirty_count && r == SY_OK; ++i) {
        node_m *n = LOOKUP(st, node, node_cap, st->dirty[i]);
        if (!n || n->visit == st->epoch) continue;
        n->visit = st->epoch;
        if (!sy_u32_push(&set, &count, &cap, n->id)) r = oom(st, err);
    }
    for (uint32_t i = 0; i < count && r == SY_OK; ++i) {
        node_m *n = LOOKUP(st, node, node_cap, set[i]);
        for (uint32_t c = 0; c < n->child_count && r == SY_OK; ++c) {
            node_m *cn = LOOKUP(st, node, node_cap, n->children[c]);
            if (!cn || cn->visit == st->epoch) continue;
            cn->visit = st->epoch;
            if (!sy_u32_push(&set, &count, &cap, cn->id)) r = oom(st, err);
        }
    }
    /* parents in the set each node waits for */
    uint32_t *ready = NULL, nready = 0, ready_cap = 0;
    for (uint32_t i = 0; i < count && r == SY_OK; ++i) {
        node_m *n = LOOKUP(st, node, node_cap, set[i]);
        n->pending = 0;
        for (uint32_t k = 0; k < n->parent_count; ++k) {
            node_m *pn = LOOKUP(st, node, node_cap, n->parents[k]);
            if (pn && pn->visit == st->epoch) n->pending++;
        }
    }
    /* counting pass, nothing allocated: the placements the set will have, against the cap */
    uint64_t others = st->placements, total = 0, limit = st->placements_max;
    for (uint32_t i = 0; i < count && r == SY_OK; ++i) {
        node_m *n = LOOKUP(st, node, node_cap, set[i]);
        others -= n->pl_count;
        n->dry_pending = n->pending;
        if (!n->pending && !sy_u32_push(&ready, &nready, &ready_cap, n->id)) r = oom(st, err);
    }
    while (nready && r == SY_OK) {
        uint32_t nid = ready[--nready];
        node_m *n = LOOKUP(st, node, node_cap, nid);
        bool is_root = st->root ? n->id == st->root : n->parent_count == 0;
        uint64_t want = is_root ? 1u : 0u;
        if (!is_root)
            for (uint32_t i = 0; i < n->parent_count; ++i) {
                node_m *pn = LOOKUP(st, node, node_cap, n->parents[i]);
                if (pn) want += pn->visit == st->epoch ? pn->paths : pn->pl_count;
                if (want > limit) want = limit + 1u; /* saturates: the sum of two stays far below 2^64 */
            }
        n->paths = want;
        total += want;
        if (others + total > limit) {
            r = sy_error_set(err, SY_ERR_LIMIT,
                             "%s: node %#x is reached along %s%llu paths, past the %u placements a scene may have "
                             "(SY_MIRROR_PLACEMENTS_MAX)",
                             st->name, n->id, want > limit ? "more than " : "", (unsigned long long)(want > limit ? limit : want),
                             st->placements_max);
            break;
        }
        for (uint32_t c = 0; c < n->child_count && r == SY_OK; ++c) {
            node_m *cn = LOOKUP(st, node, node_cap, n->children[c]);
            if (cn && cn->visit == st->epoch && cn->dry_pending && --cn->dry_pending == 0 &&
                !sy_u32_push(&ready, &nready, &ready_cap, cn->id))
                r = oom(st, err);
        }
    }
    nready = 0;
    for (uint32_t i = 0; i < count && r == SY_OK; ++i) {
        node_m *n = LOOKUP(st, node, node_cap, set[i]);
        if (!n->pending && !sy_u32_push(&ready, &nready, &ready_cap, n->id)) r = oom(st, err);
    }
    while (nready && r == SY_OK) {
        uint32_t nid = ready[--nready];
        node_m *n = LOOKUP(st, node, node_cap, nid);
        bool is_root = st->root ? n->id == st->root : n->parent_count == 0;
        uint64_t want = n->paths; /* the counting pass's, within the cap */
        if (want != n->pl_count) {
            for (uint32_t i = (uint32_t)want; i < n->pl_count; ++i) placement_clear(st, &n->pl[i]);
            placement *np = realloc(n->pl, sizeof *np * (want ? want : 1));
            if (!np) {
                r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s: node %#x: %llu placements: out of memory", st->name,
                                 n->id, (unsigned long long)want);
                break;
            }
            for (uint32_t i = n->pl_count; i < want; ++i) memset(&np[i], 0, sizeof np[i]);
            st->placements = st->placements - n->pl_count + (uint32_t)want;
            n->pl = np;
            n->pl_count = (uint32_t)want;
        }
        uint32_t k = 0;
        if (is_root) {
            n->pl[0].place = sy_placement_child(NULL, &n->local, n->flags);
        } else {
            for (uint32_t i = 0; i < n->parent_count; ++i) {
                node_m *pn = LOOKUP(st, node, node_cap, n->parents[i]);
                if (!pn) continue;
                for (uint32_t j = 0; j < pn->pl_count; ++j, ++k)
                    n->pl[k].place = sy_placement_child(&pn->pl[j].place, &n->local, n->flags);
            }
        }
        for (uint32_t i = 0; i < n->pl_count && r == SY_OK; ++i) r = placement_sync(st, n, i, false, err);
        st->stats->placements += n->pl_count;
        for (uint32_t c = 0; c < n->child_count && r == SY_OK; ++c) {
            node_m *cn = LOOKUP(st, node, node_cap, n->children[c]);
            if (cn && cn->visit == st->epoch && cn->pending && --cn->pending == 0 &&
                !sy_u32_push(&ready, &nready, &ready_cap, cn->id))
                r = oom(st, err);
        }
    }
    free(ready);
    free(set);
    return r;
}


/* >>deformation: nodes whose mesh has morph targets or joints get their own back-end primitives,
 * deformed on the CPU (sy_deform.h) whenever their weights, skin, mesh or a joint's placement
 * changed, after the placements of the sync (a joint's world matrix is its first placement's). A
 * back-end with primitive_update rewrites the vertices of the primitive it has (the ray tracers
 * refit, the rasterizer re-uploads); without it the primitive is made anew and the node's instances
 * with it. */
static void dprims_free(sy_mirror *st, node_m *n)
{
    for (uint32_t k = 0; k < n->pl_count; ++k) drop_instances(st, &n->pl[k]); /* they use the primitives */
    for (uint32_t i = 0; i < n->dprim_count; ++i)
        if (n->dprims[i]) release(st, SY_MIRROR_PRIMITIVE, n->dprims[i]);
    free(n->dprims);
    n->dprims = NULL;
    n->dprim_count = 0;
    n->skinned = false;
}

/* After n's mesh (or the mesh's primitives) changed: its deformed primitives go; it is listed as a
 * deformer, to deform in this sync, when the mesh has something to deform. */
static sy_result deform_refresh(sy_mirror *st, node_m *n, sy_error *err)
{
    dprims_free(st, n);
    const mesh_m *m = LOOKUP(st, mesh, mesh_cap, n->mesh);
    bool want = m && m->src;
    if (want && !n->deformer && !sy_u32_push(&st->deformers, &st->deformer_count, &st->deformer_cap, n->id)) return oom(st, err);
    if (!want && n->deformer) remove_u32(st->deformers, &st->deformer_count, n->id);
    n->deformer = want;
    n->deform_dirty = want;
    mark_node_dirty(st, n->id);
    return SY_OK;
}

static sy_result deform_node(sy_mirror *st, node_m *n, sy_error *err)
{
    mesh_m *m = LOOKUP(st, mesh, mesh_cap, n->mesh);
    n->deform_dirty = false;
    if (!m || !m->src) return SY_OK;
    /* the skin's matrices: joint world x inverse bind (a joint not placed counts as the identity) */
    uint32_t nj = 0;
    const sy_skin_joint *sj = NULL;
    if (n->skin && m->has_joints) {
        nj = (uint32_t)(sy_blob_size(n->skin) / sizeof(sy_skin_joint));
        sj = sy_blob_data(n->skin);
    }
    if (nj > st->joint_scratch_cap) {
        sy_mat4 *js = realloc(st->joint_scratch, sizeof *js * nj);
        if (!js) return oom(st, err);
        st->joint_scratch = js;
        st->joint_scratch_cap = nj;
    }
    for (uint32_t j = 0; j < nj; ++j) {
        const node_m *jn = LOOKUP(st, node, node_cap, sj[j].node);
        const sy_mat4 *w = jn && jn->pl_count ? &jn->pl[0].place.world : &identity_world;
        st->joint_scratch[j] = sy_mat4_mul(w, &sj[j].inverse_bind);
    }
    const sy_blob *wb = n->weights ? n->weights : m->weights;
    sy_deform_input in = {.weights = wb ? sy_blob_data(wb) : NULL,
                          .weight_count = wb ? (uint32_t)(sy_blob_size(wb) / 4) : 0u,
                          .joints = nj ? st->joint_scratch : NULL,
                          .joint_count = nj};
    bool skinned = nj > 0;
    uint32_t count = m->src_count < m->prim_count ? m->src_count : m->prim_count;
    bool in_place = st->cb->primitive_update && n->dprims && n->dprim_count == count && skinned == n->skinned;
    /* triangles only, each made (a pose out of range made none); moving texture coordinates are set
     * anew (primitive_update rewrites positions and normals only) */
    for (uint32_t i = 0; i < count && in_place; ++i)
        in_place = m->src[i].topology == SY_TOPOLOGY_TRIANGLES && (n->dprims[i] || !m->prims[i].handle) &&
                   !m->src[i].target_texcoords0;
    if (!in_place) {
        dprims_free(st, n);
        n->dprims = calloc(count ? count : 1, sizeof *n->dprims);
        if (!n->dprims) return oom(st, err);
        n->dprim_count = count;
    }
    n->skinned = skinned;
    n->dbounds = sy_bounds_empty();
    sy_result r = SY_OK;
    for (uint32_t i = 0; i < count && r == SY_OK; ++i) {
        const sy_primitive *src = &m->src[i];
        if (!m->prims[i].handle) continue; /* nothing the mesh draws either */
        in.primitive = src;
        sy_deform_pose pose;
        r = sy_deform_cache_take(&in, st->cache_slot, &pose, err); /* deformed once for every mirror */
        if (r != SY_OK) return r;
        st->stats->deform_seconds += pose.seconds;
        if (!pose.ok) {
            char item[48];
            snprintf(item, sizeof item, "node %#x primitive %u", n->id, i);
            sy_log(SY_LOG_WARNING, st->name, item, "deformed beyond the coordinate range: not updated");
            continue;
        }
        if (pose.shared) st->stats->deform_shared++;
        sy_bounds b = pose.bounds;
        sy_bounds_add_bounds(&n->dbounds, &b);
        sy_blob *bp = pose.positions, *bn = pose.normals, *bt = pose.tangents; /* the pose's references */
        sy_blob *buv = NULL; /* texture coordinates (set 0) morphed: uv + sum_t w_t duv_t (this mirror's own) */
        if (src->target_texcoords0 && src->texcoords0) {
            size_t nv = sy_blob_size(src->texcoords0) / (2 * sizeof(float));
            float *uv = malloc(sizeof(float) * 2 * nv + 1);
            if (!uv || (r = sy_blob_create_take(uv, sizeof(float) * 2 * nv, &buv, err))) {
                if (!buv) free(uv);
                sy_blob_release(bp), sy_blob_release(bn), sy_blob_release(bt);
                return uv ? r : oom(st, err);
            }
            sy_deform_texcoords(&in, (float *)sy_blob_data(buv));
        }
        sy_primitive q = *src; /* borrowed blobs, the deformed ones replaced */
        q.positions = bp;
        if (bn) q.normals = bn;
        if (bt) q.tangents = bt;
        if (buv) q.texcoords0 = buv;
        q.joints = q.weights = q.target_positions = q.target_normals = q.target_tangents = q.target_texcoords0 = NULL;
        sy_mirror_flat_mesh flat;
        double t_update = sy_time_now();
        if (q.topology != SY_TOPOLOGY_TRIANGLES) {
            char what[96];
            snprintf(what, sizeof what, "%s: node %#x primitive %u", st->name, n->id, i);
            sy_primitive tri;
            float width = sy_primitive_stroke_width(&q, &b);
            if ((r = sy_strokes_tessellate(&q, width, what, &tri, err)) == SY_OK) {
                sy_mirror_flat_mesh_of(&tri, &flat);
                sy_mirror_primitive_args a = {m->id, i, &tri, &n->dprims[i], &flat};
                r = st->cb->primitive_set(st->user, &a, err);
                sy_primitive_release(&tri);
            }
        } else {
            sy_mirror_flat_mesh_of(&q, &flat);
            sy_mirror_primitive_args a = {m->id, i, &q, &n->dprims[i], &flat};
            r = in_place ? st->cb->primitive_update(st->user, &a, err) : st->cb->primitive_set(st->user, &a, err);
        }
        st->stats->update_seconds += sy_time_now() - t_update;
        sy_blob_release(bp), sy_blob_release(bn), sy_blob_release(bt), sy_blob_release(buv); /* back-ends copy what they keep */
        if (r == SY_OK) st->stats->deformed++;
    }
    if (r == SY_OK && !in_place)
        for (uint32_t k = 0; k < n->pl_count && r == SY_OK; ++k) r = placement_sync(st, n, k, true, err);
    return r;
}

/* Deforms every listed node whose weights, skin or mesh changed or one of whose joints was
 * re-placed in this sync (visit == epoch). Cost: the listed nodes' joints, plus the vertices of
 * those that move. */
static sy_result deform_pass(sy_mirror *st, sy_error *err)
{
    sy_result r = SY_OK;
    for (uint32_t i = 0; i < st->deformer_count && r == SY_OK; ++i) {
        node_m *n = LOOKUP(st, node, node_cap, st->deformers[i]);
        if (!n || n->pl_count == 0) continue; /* not drawn: deformed when it is placed */
        bool need = n->deform_dirty || !n->dprims;
        if (!need && n->skin) {
            uint32_t nj = (uint32_t)(sy_blob_size(n->skin) / sizeof(sy_skin_joint));
            const sy_skin_joint *sj = sy_blob_data(n->skin);
            for (uint32_t j = 0; j < nj && !need; ++j) {
                const node_m *jn = LOOKUP(st, node, node_cap, sj[j].node);
                need = jn && jn->visit == st->epoch;
            }
        }
        if (need) r = deform_node(st, n, err);
    }
    return r;
}

static void node_free(sy_mirror *st, node_m *n)
{
    dprims_free(st, n);
    if (n->deformer) remove_u32(st->deformers, &st->deformer_count, n->id);
    sy_blob_release(n->weights);
    sy_blob_release(n->skin);
    for (uint32_t i = 0; i < n->pl_count; ++i) placement_clear(st, &n->pl[i]);
    st->placements -= n->pl_count;
    free(n->pl);
    free(n->children);
    free(n->parents);
    memset(n, 0, sizeof *n);
}

static void set_children(sy_mirror *st, node_m *n, const uint32_t *ch, uint32_t count)
{
    for (uint32_t i = 0; i < n->child_count; ++i) {
        node_m *c = LOOKUP(st, node, node_cap, n->children[i]);
        if (c) {
            remove_u32(c->parents, &c->parent_count, n->id);
            mark_node_dirty(st, c->id);
        }
    }
    free(n->children);
    n->children = NULL;
    n->child_count = 0;
    if (count) {
        n->children = malloc(sizeof *n->children * count);
        if (n->children) {
            memcpy(n->children, ch, sizeof *ch * count);
            n->child_count = count;
        }
    }
    for (uint32_t i = 0; i < n->child_count; ++i) {
        node_m *c = LOOKUP(st, node, node_cap, n->children[i]);
        if (c) {
            sy_u32_push(&c->parents, &c->parent_count, &c->parent_capacity, n->id);
            mark_node_dirty(st, c->id);
        }
    }
}

static node_m *node_add(sy_mirror *st, uint32_t id)
{
    node_m *n = SLOT_NEW(st, node, node_cap, id);
    if (!n) return NULL;
    n->id = id;
    n->local = sy_mat4_identity();
    n->flags = SY_NODE_VISIBLE;
    return n;
}

/* >>entries */
static sy_result apply_texture(sy_mirror *st, const sy_change *e, bool destroyed, sy_error *err)
{
    tex_m *t = LOOKUP(st, tex, tex_cap, e->id);
    if (destroyed) {
        if (t) {
            if (t->handle) release(st, SY_MIRROR_TEXTURE, t->handle);
            sy_blob_release(t->pixels);
            memset(t, 0, sizeof *t);
        }
        return SY_OK;
    }
    if (!t) {
        if (!(t = SLOT_NEW(st, tex, tex_cap, e->id))) return oom(st, err);
        t->id = e->id;
    }
    const sy_texture_data *d = e->data;
    if (e->mask & SY_BIT(SY_TEXTURE_INFO)) t->info = d->info;
    if (e->mask & SY_BIT(SY_TEXTURE_SAMPLER)) t->sampler = d->sampler;
    if (e->mask & SY_BIT(SY_TEXTURE_PIXELS)) {
        sy_blob_release(t->pixels);
        t->pixels = sy_blob_retain(d->pixels);
    }
    if (e->mask & (SY_BIT(SY_TEXTURE_INFO) | SY_BIT(SY_TEXTURE_SAMPLER) | SY_BIT(SY_TEXTURE_PIXELS)))
        return texture_upload(st, t, err);
    return SY_OK;
}

static sy_result apply_material(sy_mirror *st, const sy_change *e, bool destroyed, sy_error *err)
{
    mat_m *m = LOOKUP(st, mat, mat_cap, e->id);
    if (destroyed) {
        if (m) {
            if (m->handle) release(st, SY_MIRROR_MATERIAL, m->handle);
            if (material_emits(&m->d)) st->emissive_materials--;
            memset(m, 0, sizeof *m);
            notify(st, SY_TYPE_MATERIAL, e->id, true);
        }
        return SY_OK;
    }
    if (m && !(e->flags & SY_CHANGE_CREATED)) {
        /* partial material update: merge masked fields into the mirror */
        const sy_material_data *d = e->data;
        sy_material_data merged = m->d;
        sy_object_data_merge(SY_TYPE_MATERIAL, &merged, d, e->mask);
        st->emissive_materials += (uint32_t)material_emits(&merged) - (uint32_t)material_emits(&m->d);
        m->d = merged;
        if (e->mask & ~(SY_BIT(SY_MATERIAL_NAME) | SY_BIT(SY_FIELD_ATTACHMENTS))) return material_upload(st, m, err);
        return SY_OK;
    }
    if (!m) {
        if (!(m = SLOT_NEW(st, mat, mat_cap, e->id))) return oom(st, err);
        m->id = e->id;
    } else if (material_emits(&m->d)) {
        st->emissive_materials--;
    }
    /* a creation (or the first sight of a material) carries every field */
    m->d = *(const sy_material_data *)e->data;
    if (material_emits(&m->d)) st->emissive_materials++;
    m->d.name = NULL; /* not owned by the mirror */
    if (e->mask == SY_BIT(SY_MATERIAL_NAME) || e->mask == SY_BIT(SY_FIELD_ATTACHMENTS)) return SY_OK;
    return material_upload(st, m, err);
}

static sy_result apply_mesh(sy_mirror *st, const sy_change *e, bool destroyed, sy_error *err)
{
    mesh_m *m = LOOKUP(st, mesh, mesh_cap, e->id);
    if (destroyed) {
        if (m) {
            for (uint32_t i = 0; i < m->user_count; ++i) {
                node_m *n = LOOKUP(st, node, node_cap, m->users[i]);
                if (n) dprims_free(st, n); /* before the mesh's own primitives go */
                mark_node_dirty(st, m->users[i]);
            }
            mesh_free_prims(st, m);
            mesh_free_src(m);
            sy_blob_release(m->weights);
            uint32_t *users = m->users, nu = m->user_count;
            memset(m, 0, sizeof *m);
            for (uint32_t i = 0; i < nu; ++i) {
                node_m *n = LOOKUP(st, node, node_cap, users[i]);
                sy_result r = n ? deform_refresh(st, n, err) : SY_OK;
                if (r != SY_OK) {
                    free(users);
                    return r;
                }
            }
            free(users);
        }
        return SY_OK;
    }
    if (!m) {
        if (!(m = SLOT_NEW(st, mesh, mesh_cap, e->id))) return oom(st, err);
        m->id = e->id;
    }
    if (e->mask & SY_BIT(SY_MESH_WEIGHTS)) {
        sy_blob_release(m->weights);
        m->weights = sy_blob_retain(((const sy_mesh_data *)e->data)->weights);
        for (uint32_t i = 0; i < m->user_count; ++i) {
            node_m *n = LOOKUP(st, node, node_cap, m->users[i]);
            if (n && n->deformer) n->deform_dirty = true;
        }
    }
    if (e->mask & SY_BIT(SY_MESH_PRIMITIVES)) {
        for (uint32_t i = 0; i < m->user_count; ++i) { /* deformed copies go before the primitives they copy */
            node_m *n = LOOKUP(st, node, node_cap, m->users[i]);
            if (n) dprims_free(st, n);
        }
        sy_result r = mesh_upload(st, m, &((const sy_mesh_data *)e->data)->primitives, err);
        if (r != SY_OK) return r;
        if (!mesh_keep_src(m, &((const sy_mesh_data *)e->data)->primitives)) return oom(st, err);
        /* users need new instances: drop the old ones, then re-place the users */
        for (uint32_t i = 0; i < m->user_count; ++i) {
            node_m *n = LOOKUP(st, node, node_cap, m->users[i]);
            if (n) {
                for (uint32_t k = 0; k < n->pl_count; ++k) drop_instances(st, &n->pl[k]);
                if ((r = deform_refresh(st, n, err)) != SY_OK) return r;
            }
            mark_node_dirty(st, m->users[i]);
        }
    }
    return SY_OK;
}

static sy_result apply_light(sy_mirror *st, const sy_change *e, bool destroyed, sy_error *err)
{
    light_m *l = LOOKUP(st, light, light_cap, e->id);
    if (destroyed) {
        if (l) {
            for (uint32_t i = 0; i < l->user_count; ++i) mark_node_dirty(st, l->users[i]);
            free(l->users);
            memset(l, 0, sizeof *l);
        }
        return SY_OK;
    }
    if (!l) {
        if (!(l = SLOT_NEW(st, light, light_cap, e->id))) return oom(st, err);
        l->id = e->id;
        l->d = *(const sy_light_data *)sy_object_defaults(SY_TYPE_LIGHT);
    }
    const sy_light_data *d = e->data;
    if (e->mask & SY_BIT(SY_LIGHT_TYPE)) l->d.type = d->type;
    if (e->mask & SY_BIT(SY_LIGHT_COLOR)) memcpy(l->d.color, d->color, sizeof d->color);
    if (e->mask & SY_BIT(SY_LIGHT_INTENSITY)) l->d.intensity = d->intensity;
    if (e->mask & SY_BIT(SY_LIGHT_RANGE)) l->d.range = d->range;
    if (e->mask & SY_BIT(SY_LIGHT_INNER_CONE)) l->d.inner_cone = d->inner_cone;
    if (e->mask & SY_BIT(SY_LIGHT_OUTER_CONE)) l->d.outer_cone = d->outer_cone;
    for (uint32_t i = 0; i < l->user_count; ++i) mark_node_dirty(st, l->users[i]);
    return SY_OK;
}

static sy_result apply_background(sy_mirror *st, const sy_change *e, bool destroyed, sy_error *err)
{
    sy_mirror_background *b = LOOKUP(st, bg, bg_cap, e->id);
    if (destroyed) {
        if (b) memset(b, 0, sizeof *b);
        notify(st, SY_TYPE_BACKGROUND, e->id, true);
        return SY_OK;
    }
    if (!b) {
        if (!(b = SLOT_NEW(st, bg, bg_cap, e->id))) return oom(st, err);
        b->id = e->id;
        b->world = *(const sy_background_data *)sy_object_defaults(SY_TYPE_BACKGROUND);
        b->world.name = NULL;
    }
    const sy_background_data *bd = e->data;
    sy_background_data *w = &b->world;
    if (e->mask & SY_BIT(SY_BACKGROUND_COLOR)) memcpy(w->color, bd->color, sizeof w->color);
    if (e->mask & SY_BIT(SY_BACKGROUND_ENVIRONMENT)) w->environment = bd->environment;
    if (e->mask & SY_BIT(SY_BACKGROUND_INTENSITY)) w->intensity = bd->intensity;
    if (e->mask & SY_BIT(SY_BACKGROUND_ENVIRONMENT_VISIBLE)) w->environment_visible = bd->environment_visible;
    if (e->mask & SY_BIT(SY_BACKGROUND_GRADIENT)) w->gradient = bd->gradient;
    if (e->mask & SY_BIT(SY_BACKGROUND_DEFAULT_LIGHTING)) w->default_lighting = bd->default_lighting;
    memcpy(b->color, w->color, sizeof b->color);
    b->environment = w->environment.id;
    b->intensity = w->intensity;
    if (e->mask & ~(SY_BIT(SY_BACKGROUND_NAME) | SY_BIT(SY_FIELD_ATTACHMENTS)))
        notify(st, SY_TYPE_BACKGROUND, e->id, false); /* not for name or attachments: nothing visible */
    return SY_OK;
}

static sy_result apply_node(sy_mirror *st, const sy_change *e, bool destroyed, sy_error *err)
{
    node_m *n = LOOKUP(st, node, node_cap, e->id);
    if (destroyed) {
        if (n) {
            for (uint32_t i = 0; i < n->child_count; ++i) {
                node_m *c = LOOKUP(st, node, node_cap, n->children[i]);
                if (c) {
                    remove_u32(c->parents, &c->parent_count, n->id);
                    mark_node_dirty(st, c->id);
                }
            }
            mesh_m *m = LOOKUP(st, mesh, mesh_cap, n->mesh);
            if (m) remove_u32(m->users, &m->user_count, n->id);
            light_m *l = LOOKUP(st, light, light_cap, n->light);
            if (l) remove_u32(l->users, &l->user_count, n->id);
            node_free(st, n);
            st->stats->nodes_destroyed++;
        }
        return SY_OK;
    }
    if (!n && !(n = node_add(st, e->id))) return oom(st, err);
    const sy_node_data *d = e->data;
    bool dirty = (e->flags & SY_CHANGE_CREATED) != 0;
    if (e->mask & SY_BIT(SY_NODE_TRANSFORM)) {
        n->local = d->transform.matrix;
        dirty = true;
    }
    if (e->mask & SY_BIT(SY_NODE_FLAGS)) {
        n->flags = d->flags;
        dirty = true;
    }
    if (e->mask & SY_BIT(SY_NODE_MESH)) {
        mesh_m *om = LOOKUP(st, mesh, mesh_cap, n->mesh), *nm = LOOKUP(st, mesh, mesh_cap, d->mesh.id);
        if (om) remove_u32(om->users, &om->user_count, n->id);
        if (nm) sy_u32_push(&nm->users, &nm->user_count, &nm->user_capacity, n->id);
        n->mesh = d->mesh.id;
        for (uint32_t k = 0; k < n->pl_count; ++k) drop_instances(st, &n->pl[k]); /* force new instances */
        sy_result r = deform_refresh(st, n, err);
        if (r != SY_OK) return r;
        dirty = true;
    }
    if (e->mask & SY_BIT(SY_NODE_WEIGHTS)) {
        sy_blob_release(n->weights);
        n->weights = sy_blob_retain(d->weights);
        if (n->deformer) n->deform_dirty = true;
    }
    if (e->mask & SY_BIT(SY_NODE_SKIN)) {
        sy_blob_release(n->skin);
        n->skin = sy_blob_retain(d->skin);
        if (n->deformer) n->deform_dirty = true;
    }
    if (e->mask & SY_BIT(SY_NODE_LIGHT)) {
        light_m *ol = LOOKUP(st, light, light_cap, n->light), *nl = LOOKUP(st, light, light_cap, d->light.id);
        if (ol) remove_u32(ol->users, &ol->user_count, n->id);
        if (nl) sy_u32_push(&nl->users, &nl->user_count, &nl->user_capacity, n->id);
        n->light = d->light.id;
        dirty = true;
    }
    if (e->mask & SY_BIT(SY_NODE_CHILDREN)) {
        uint32_t nc;
        const uint32_t *ch = sy_node_children(d, &nc);
        set_children(st, n, ch, nc);
        dirty = true;
    }
    if (dirty) mark_node_dirty(st, n->id);
    return SY_OK;
}

static sy_result apply_entry(sy_mirror *st, const sy_change *e, sy_error *err)
{
    bool destroyed = (e->flags & SY_CHANGE_DESTROYED) != 0;
    switch (e->type) {
    case SY_TYPE_TEXTURE: return apply_texture(st, e, destroyed, err);
    case SY_TYPE_MATERIAL: return apply_material(st, e, destroyed, err);
    case SY_TYPE_MESH: return apply_mesh(st, e, destroyed, err);
    case SY_TYPE_LIGHT: return apply_light(st, e, destroyed, err);
    case SY_TYPE_BACKGROUND: return apply_background(st, e, destroyed, err);
    case SY_TYPE_NODE: return apply_node(st, e, destroyed, err);
    case SY_TYPE_ANIMATION: return SY_OK; /* nothing visible by itself: the clock (sy_anim.h) sets node fields */
    default: return SY_OK;
    }
}

/* >>sync */
sy_result sy_mirror_sync(sy_mirror *st, const sy_changes *changes, sy_mirror_sync_stats *stats, sy_error *err)
{
    sy_mirror_sync_stats local;
    if (!stats) stats = &local;
    memset(stats, 0, sizeof *stats);
    stats->entries = sy_changes_count(changes);
    st->stats = stats;
    sy_result r = SY_OK;
    /* Entries come ordered: destructions, then textures, materials, meshes, lights, cameras,
     * backgrounds, nodes; so every reference is resolvable when a node is placed. Nodes are
     * first all mirrored (children may precede parents), then re-placed. */
    for (uint32_t i = 0; i < sy_changes_count(changes); ++i) {
        const sy_change *e = sy_changes_get(changes, i);
        if (e->type != SY_TYPE_NODE || !(e->flags & SY_CHANGE_CREATED)) continue;
        if (LOOKUP(st, node, node_cap, e->id)) continue;
        if (!node_add(st, e->id)) {
            st->stats = NULL;
            return oom(st, err);
        }
    }
    for (uint32_t i = 0; i < sy_changes_count(changes) && r == SY_OK; ++i) r = apply_entry(st, sy_changes_get(changes, i), err);
    st->epoch++;
    if (r == SY_OK) r = replace_dirty(st, err);
    if (r == SY_OK) r = deform_pass(st, err);
    st->dirty_count = 0;
    st->stats = NULL;
    return r;
}

bool sy_mirror_instance_find(const sy_mirror *st, uint32_t node_id, uint32_t handle, sy_mirror_instance_info *out)
{
    memset(out, 0, sizeof *out);
    const node_m *n = LOOKUP(st, node, node_cap, node_id);
    const mesh_m *m = n ? LOOKUP(st, mesh, mesh_cap, n->mesh) : NULL;
    if (!m || !handle) return false;
    for (uint32_t p = 0; p < n->pl_count; ++p)
        for (uint32_t i = 0; i < n->pl[p].inst_count; ++i)
            if (n->pl[p].inst[i] == handle) {
                out->node = n->id;
                out->placement = p;
                out->mesh = m->id;
                out->primitive = i;
                const mat_m *mm = i < m->prim_count ? LOOKUP(st, mat, mat_cap, m->prims[i].material) : NULL;
                out->material = mm ? mm->id : 0u; /* 0: the default material */
                out->world = n->skinned && n->dprims ? identity_world : n->pl[p].place.world; /* skinned: world-space vertices */
                return true;
            }
    return false;
}

uint32_t sy_mirror_texture_handle(const sy_mirror *st, uint32_t texture_id)
{
    const tex_m *t = LOOKUP(st, tex, tex_cap, texture_id);
    return t ? t->handle : 0u;
}

void sy_mirror_look(const sy_mirror *st, uint32_t background_id, sy_look *out)
{
    const sy_mirror_background *b = LOOKUP(st, bg, bg_cap, background_id);
    sy_look_inputs in = {
        .world = b ? &b->world : NULL,
        .world_env_ready = b && b->environment && sy_mirror_texture_handle(st, b->environment) != 0,
        .light_count = st->light_placements,
        .emitter_count = st->emissive_materials,
    };
    sy_look_resolve(&in, out);
}

const sy_mirror_background *sy_mirror_background_get(const sy_mirror *st, uint32_t background_id)
{
    return LOOKUP(st, bg, bg_cap, background_id);
}

/* >>lifetime */
sy_result sy_mirror_create(const sy_mirror_desc *desc, sy_mirror **out, sy_error *err)
{
    *out = NULL;
    sy_mirror *st = calloc(1, sizeof *st);
    if (!st) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", desc->name ? desc->name : "mirror");
    st->name = desc->name ? desc->name : "mirror";
    st->root = desc->root_node_id;
    st->cb = desc->callbacks;
    st->user = desc->user;
    st->placements_max = SY_MIRROR_PLACEMENTS_MAX;
    sy_deform_cache_attach(&st->cache_slot);
    *out = st;
    return SY_OK;
}

void sy_mirror_destroy(sy_mirror *st)
{
    if (!st) return;
    for (uint32_t i = 0; i < st->node_cap; ++i)
        if (st->node[i].id) node_free(st, &st->node[i]);
    for (uint32_t i = 0; i < st->mesh_cap; ++i) {
        mesh_free_prims(st, &st->mesh[i]);
        mesh_free_src(&st->mesh[i]);
        sy_blob_release(st->mesh[i].weights);
        free(st->mesh[i].users);
    }
    free(st->deformers);
    free(st->joint_scratch);
    sy_deform_cache_detach(st->cache_slot);
    for (uint32_t i = 0; i < st->light_cap; ++i) free(st->light[i].users);
    for (uint32_t i = 0; i < st->tex_cap; ++i) sy_blob_release(st->tex[i].pixels);
    free(st->tex);
    free(st->mat);
    free(st->mesh);
    free(st->light);
    free(st->bg);
    free(st->node);
    free(st->dirty);
    free(st);
}
