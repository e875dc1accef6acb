/* sy_scene_internal.h — INTERNAL to core (not installed): what the scene's modules share: the
 * slot, pool, consumer and log structs, struct sy_scene, and the calls one module makes in another
 * (prefix sy_sc_). The modules, bottom-up (each calls only those before it; core_layers checks it):
 *   sy_scene.c           pools and slots, dirty tracking, the scene's lifetime, object reads
 *   sy_scene_graph.c     parents, world matrices and bounds (incremental), cycle checks, queries
 *   sy_scene_validate.c  validation of every field of every type (one place)
 *   sy_scene_objects.c   create, destroy, setters, typed setters and getters, attachments
 *   sy_scene_commit.c    commit, consumers, log compaction, snapshots, replica apply, equality
 * Thread-safety: as the scene (sy_scene.h). */
#ifndef SY_SCENE_INTERNAL_H
#define SY_SCENE_INTERNAL_H

#include "sy_fields.h"

typedef struct node_extra {
    uint32_t *parents; /* parent node ids in attach order; [0] is the primary parent */
    uint32_t parent_count, parent_capacity;
    sy_mat4 world;
    sy_bounds local_bounds; /* subtree bounds in the node's own frame (before its transform) */
    uint8_t world_dirty, bounds_dirty;
    uint32_t mark; /* traversal epoch */
    uint32_t world_stamp; /* the scene's world_stamp when the world matrix was last recomputed */
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

/* A mesh with skinned triangles: per joint index, the bind-pose bounds of the vertices it moves
 * (weight > 0); bounds[count] the vertices no joint moves (sy_scene_graph.c: skinned bounds). Kept
 * beside the slots (a slot's size is the replica's memory unit, SY_SCENE_SLOT_BYTES). */
typedef struct skin_mesh {
    uint32_t mesh, count;
    sy_bounds *bounds;
} skin_mesh;

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
    uint32_t world_stamp; /* counts sy_sc_update_world calls that recomputed a world matrix */
    id_list skinned;      /* nodes with a skin and a skin_mesh (rebuilt when skinned_stale) */
    bool skinned_stale;
    skin_mesh *skin_meshes; /* by mesh id, ascending */
    uint32_t skin_mesh_count, skin_mesh_capacity;
    bool applying; /* replica apply: references may be stale, cycles checked afterwards */
    uint32_t apply_max_slots; /* replica policy: highest slot index + 1 a change list may create (0 = none) */
};

/* >>pools */
static inline uint32_t id_index(uint32_t id) { return id & SY_HANDLE_INDEX_MASK; }
static inline uint32_t id_generation(uint32_t id) { return id >> SY_HANDLE_INDEX_BITS; }
static inline uint32_t make_id(uint32_t index, uint32_t gen) { return (gen << SY_HANDLE_INDEX_BITS) | index; }

/* sy_scene.c */
bool sy_sc_list_push(id_list *l, uint32_t v);
void sy_sc_array_remove(uint32_t *items, uint32_t *count, uint32_t v);
slot *sy_sc_lookup(const sy_scene *s, uint32_t type, uint32_t id);
node_extra *sy_sc_nx_of(const sy_scene *s, uint32_t node_id);
bool sy_sc_pool_grow(pool *p, uint32_t min_count);
bool sy_sc_pool_reserve_exact(pool *p, uint32_t min_count);
void sy_sc_free_list_push(pool *p, uint32_t idx);
sy_result sy_sc_slot_init(sy_scene *s, uint32_t type, uint32_t idx, uint32_t gen, const char *name, sy_error *err);
bool sy_sc_mark_dirty(sy_scene *s, uint32_t type, uint32_t id, slot *sl, uint64_t bits, uint32_t flags);
void sy_sc_slot_release(slot *sl, uint32_t type);

/* sy_scene_graph.c */
void sy_sc_mark_world_dirty(sy_scene *s, uint32_t node_id);
void sy_sc_mark_bounds_dirty(sy_scene *s, uint32_t node_id);
void sy_sc_mark_parents_bounds_dirty(sy_scene *s, uint32_t node_id);
void sy_sc_update_world(sy_scene *s);
void sy_sc_mark_skins_moved(sy_scene *s);
void sy_sc_update_bounds(sy_scene *s);
skin_mesh *sy_sc_skin_mesh_find(const sy_scene *s, uint32_t mesh_id);
bool sy_sc_reaches(sy_scene *s, const uint32_t *from, uint32_t n, uint32_t target);
bool sy_sc_find_cycle(sy_scene *s, const sy_changes *changes, uint32_t *at);
int sy_sc_cmp_u32(const void *a, const void *b);

/* sy_scene_validate.c */
sy_result sy_sc_validate_field(sy_scene *s, uint32_t type, uint32_t id, uint32_t f, const void *v, sy_error *err);
sy_result sy_sc_validate_object(const sy_scene *s, uint32_t type, uint32_t id, const void *data, sy_error *err);

/* sy_scene_objects.c */
sy_result sy_sc_object_create_at(sy_scene *s, uint32_t t, uint32_t id, sy_error *err);
void sy_sc_mesh_joint_bounds(sy_scene *s, uint32_t mesh_id, const sy_mesh_data *d);
sy_result sy_sc_set_attachments(sy_scene *s, uint32_t t, uint32_t id, slot *sl, sy_attachment *a, uint32_t n,
                                 sy_error *err);

#endif /* SY_SCENE_INTERNAL_H */
