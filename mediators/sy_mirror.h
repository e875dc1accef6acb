/** @file
 * sy_mirror.h — the back-end-independent scene mirror shared by the mediators.
 *
 * A mediator never reads the live scene: it keeps a mirror built from change lists. This module
 * is that mirror: id-indexed tables of textures, materials, meshes, lights, backgrounds and nodes
 * (a stale id never matches), the node graph (children and parents; a DAG node reached along k
 * paths gets k placements, each one world matrix and a visibility), the mesh/light user lists and
 * the dirty tracking that re-places only the subtrees a sync touched. It talks to the back-end only
 * through a const table of callbacks on 32-bit back-end handles (0 = none): it creates, updates and
 * releases textures, materials, mesh primitives, one instance per primitive per placement and one
 * light per visible placement of a node with a light, in the same order for every back-end. A node
 * whose mesh has morph targets or joints gets its own primitives, deformed on the CPU once for
 * every back-end (sy_deform.h) after each sync that changed its weights, skin, mesh or a joint's
 * placement, and updated in place through primitive_update where the back-end has it; every mirror
 * of the process takes the poses from one shared cache (sy_deform_cache.h), so the same pose is
 * deformed once however many mirrors (contexts, back-ends) show it. Each
 * callback gets the object's core fields and its flat description (sy_mirror_flat.h: texture
 * handles resolved, emission, texel format, arrays and counts, light type decided once for every
 * back-end), so a mediator only copies fields into its back-end's descriptors. A back-end without
 * textures, materials or lights leaves those callbacks NULL.
 *
 * Ownership: the mirror owns its tables and retains texture pixel blobs; back-end objects belong
 * to the back-end and are released through the release callback (sy_mirror_destroy releases the
 * instances, lights and mesh primitives it still holds, so call it before destroying the device;
 * texture and material handles are left to the device's destruction).
 * Thread-safety: none; one mirror is used by one mediator state at a time (distinct mirrors may sync
 * on different threads at once: the poses they share are behind sy_deform_cache.h's lock). */
#ifndef SY_MIRROR_H
#define SY_MIRROR_H

#include "sy_look.h"
#include "sy_mediator.h"
#include "sy_mirror_flat.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The most placements (node x DAG path) one mirror holds: a sync that would need more fails with
 * SY_ERR_LIMIT naming the node, before allocating them (loaders refuse such files earlier, with
 * their own placement budget). */
#define SY_MIRROR_PLACEMENTS_MAX (1u << 22)

/** The shared scene mirror of a mediator (opaque). */
typedef struct sy_mirror sy_mirror;

/** Complete texture (pixels match the info): create one back-end texture into *handle. */
typedef struct sy_mirror_texture_args {
    uint32_t id; /**< core texture id */
    const sy_image_info *info; /**< size and layout of the pixels */
    const sy_sampler *sampler; /**< wrap and filter */
    const void *pixels; /**< the pixels (borrowed for the call) */
    uint32_t *handle; /**< out */
    const sy_mirror_flat_texture *flat; /**< the same, flat (borrowed for the call) */
} sy_mirror_texture_args;

/** Material data (merged, name NULL): create (*handle == 0) or update the back-end material. */
typedef struct sy_mirror_material_args {
    uint32_t id; /**< core material id */
    const sy_material_data *data; /**< the material's fields */
    uint32_t *handle; /**< in/out */
    const sy_mirror_flat_material *flat; /**< the same, flat, texture handles resolved (borrowed for the call) */
} sy_mirror_material_args;

/** One primitive of a mesh as triangles (line and point primitives arrive tessellated into tubes
 * and small spheres by sy_strokes.h, so every back-end draws the same strokes): create its
 * back-end mesh into *handle. */
typedef struct sy_mirror_primitive_args {
    /** @{ core mesh id and the primitive's index in it */
    uint32_t mesh_id, index; /** @} */
    const sy_primitive *primitive; /**< the primitive (borrowed for the call) */
    uint32_t *handle; /**< out */
    const sy_mirror_flat_mesh *flat; /**< its arrays and counts (borrowed for the call) */
} sy_mirror_primitive_args;

/** One instance of one placement: *handle == 0: create it from mesh/material/world/flags;
 * otherwise update its world matrix, visibility and selection. */
typedef struct sy_mirror_instance_args {
    /** @{ core node id and which of its placements (DAG paths) */
    uint32_t node, placement; /** @} */
    /** @{ back-end handles (material 0 = none) */
    uint32_t mesh, material; /** @} */
    const sy_mat4 *world; /**< world matrix of the placement */
    bool visible; /**< visible along this path */
    bool baked; /**< SY_NODE_STATIC node, mesh used once, one placement: may be baked into the scene */
    uint32_t *handle; /**< in/out */
    bool selected; /**< selected along this path (SY_NODE_SELECTED on the node or above): the back-end
                    * highlights its pixels (sy_highlight.h) */
} sy_mirror_instance_args;

/** The light of one visible placement: create (*handle == 0) or update. */
typedef struct sy_mirror_light_args {
    /** @{ core node id and which of its placements */
    uint32_t node, placement; /** @} */
    const sy_light_data *light; /**< the light's fields */
    /** @{ world space; direction = the node's -Z */
    float position[3], direction[3]; /** @} */
    uint32_t *handle; /**< in/out */
    const sy_mirror_flat_light *flat; /**< all of it, flat (borrowed for the call) */
} sy_mirror_light_args;

/** Kinds of back-end objects the mirror creates. */
typedef enum sy_mirror_kind {
    SY_MIRROR_TEXTURE,
    SY_MIRROR_MATERIAL,
    SY_MIRROR_PRIMITIVE,
    SY_MIRROR_INSTANCE,
    SY_MIRROR_LIGHT,
} sy_mirror_kind;

/** A back-end object the mirror no longer uses (handle != 0). */
typedef struct sy_mirror_release_args {
    sy_mirror_kind kind; /**< what kind of object */
    uint32_t handle; /**< its back-end handle */
} sy_mirror_release_args;

/** Notification: type SY_TYPE_TEXTURE: a new back-end texture was made for id; SY_TYPE_MATERIAL
 * (destroyed): a mirrored material is gone; SY_TYPE_BACKGROUND: a background's colour,
 * environment or intensity changed, or it was destroyed (also when it was never mirrored). */
typedef struct sy_mirror_object_args {
    sy_object_type type; /**< type of the object */
    uint32_t id; /**< its core id */
    bool destroyed; /**< the object was destroyed */
} sy_mirror_object_args;

/** The back-end side. primitive_set, instance_set and release are required. texture_set,
 * material_set and light_set are NULL for a back-end without such objects: then every texture and
 * material handle stays 0 (instances get material 0), no light is made and the look counts none.
 * object_changed is optional. Failing callbacks set err and stop the sync (the mirror stays
 * consistent: a later sync may retry). */
typedef struct sy_mirror_callbacks {
    sy_result (*texture_set)(void *user, const sy_mirror_texture_args *a, sy_error *err); /**< creates a back-end texture, or NULL */
    sy_result (*material_set)(void *user, const sy_mirror_material_args *a, sy_error *err); /**< creates or updates a back-end material, or NULL */
    sy_result (*primitive_set)(void *user, const sy_mirror_primitive_args *a, sy_error *err); /**< creates a back-end mesh for one primitive */
    sy_result (*instance_set)(void *user, const sy_mirror_instance_args *a, sy_error *err); /**< creates or updates an instance */
    sy_result (*light_set)(void *user, const sy_mirror_light_args *a, sy_error *err); /**< creates or updates a light, or NULL */
    void (*release)(void *user, const sy_mirror_release_args *a); /**< releases a back-end object */
    void (*object_changed)(void *user, const sy_mirror_object_args *a); /**< optional */
    /** Optional: rewrites the vertices of back-end primitive *a->handle in place with a deformed
     * version of the primitive it was made from (same vertex count, indices, topology and
     * attributes present; positions, normals and tangents changed): the ray tracers refit its BVH,
     * the rasterizer re-uploads the vertex buffer. NULL: the mirror releases the primitive, makes a
     * new one with primitive_set and new instances for it. */
    sy_result (*primitive_update)(void *user, const sy_mirror_primitive_args *a, sy_error *err);
} sy_mirror_callbacks;

/** How a mediator sets up its mirror. */
typedef struct sy_mirror_desc {
    const char *name;       /**< error prefix, e.g. "raster mediator" */
    uint32_t root_node_id;  /**< 0 = every parentless node is a root */
    const sy_mirror_callbacks *callbacks; /**< static storage */
    void *user; /**< passed to every callback */
} sy_mirror_desc;

/** What one sync did. */
typedef struct sy_mirror_sync_stats {
    uint32_t entries;         /**< change entries handled */
    uint32_t placements;      /**< node placements recomputed */
    uint32_t nodes_destroyed; /**< mirrored nodes removed */
    uint32_t deformed;        /**< primitive instances deformed (skins, morph targets: sy_deform.h) */
    uint32_t deform_shared;   /**< of them, poses taken already deformed (by another mirror, or for another node
                               * in the same pose: sy_deform_cache.h) */
    double deform_seconds;    /**< wall time in sy_deform_primitive (the deformation itself; 0 for shared poses) */
    double update_seconds;    /**< wall time in the back-end's primitive_update / primitive_set for the
                               * deformed primitives (the ray tracers' BVH refit, the rasterizer's upload) */
} sy_mirror_sync_stats;

/** Copies what a sync did (ms, a sy_mirror_sync_stats) into a mediator's counters c (a struct with
 * the fields last_sync_placements, last_sync_entries, last_sync_deform_seconds, last_sync_deformed
 * and last_sync_deform_shared, as the raster and rt mediators' counters name them). */
#define SY_MIRROR_SYNC_COUNTERS(c, ms)                                                                  \
    do {                                                                                                \
        (c).last_sync_placements = (ms).placements;                                                     \
        (c).last_sync_entries = (ms).entries;                                                           \
        (c).last_sync_deform_seconds = (ms).deform_seconds;                                             \
        (c).last_sync_deformed = (ms).deformed;                                                         \
        (c).last_sync_deform_shared = (ms).deform_shared;                                               \
    } while (0)

/** A mirrored background (defaults for fields never set). */
typedef struct sy_mirror_background {
    uint32_t id; /**< core background id */
    float color[4]; /**< background colour, linear RGBA premultiplied */
    uint32_t environment; /**< core texture id, 0 = none */
    float intensity; /**< environment multiplier */
    sy_background_data world; /**< every field (name NULL); color/environment/intensity repeat it */
} sy_mirror_background;

/** Creates a mirror that drives the back-end through desc->callbacks. */
sy_result sy_mirror_create(const sy_mirror_desc *desc, sy_mirror **out, sy_error *err);
/** Destroys the mirror (NULL-safe) without calling release: back-end objects are the mediator's to free. */
void sy_mirror_destroy(sy_mirror *m);
/** Applies a change list (ordered as sy_changes delivers it), then re-places dirty subtrees.
 * stats may be NULL; it is filled also when the sync fails. */
sy_result sy_mirror_sync(sy_mirror *m, const sy_changes *changes, sy_mirror_sync_stats *stats, sy_error *err);
/** Where a back-end instance comes from (sy_mirror_instance_find): what picking reports. */
typedef struct sy_mirror_instance_info {
    uint32_t node;      /**< core node id */
    uint32_t placement; /**< which of its placements (DAG paths) */
    uint32_t mesh;      /**< core mesh id */
    uint32_t primitive; /**< the primitive's index in the mesh */
    uint32_t material;  /**< core material id of the primitive (0: none or not mirrored: the default material) */
    sy_mat4 world;      /**< the placement's world matrix (the identity for a skinned node: its deformed vertices are in world space) */
} sy_mirror_instance_info;
/** Finds the back-end instance `handle` among the instances of node node_id (the node the mediator
 * recorded for it in instance_set): true and *out filled, or false (zeroed) when the node holds no
 * such instance. Cost: the node's placements x its mesh's primitives. */
bool sy_mirror_instance_find(const sy_mirror *m, uint32_t node_id, uint32_t handle, sy_mirror_instance_info *out);
/** Back-end handle of a mirrored texture (0 = unknown or incomplete). */
uint32_t sy_mirror_texture_handle(const sy_mirror *m, uint32_t texture_id);
/** Mirrored background or NULL. Borrowed until the next sync. */
const sy_mirror_background *sy_mirror_background_get(const sy_mirror *m, uint32_t background_id);

/** The resolved look (sy_look.h) of a view of this scene with the given world (background id, 0 =
 * none): environment light, background and default lighting, decided by sy_look_resolve from what
 * the mirror holds. Every mediator asks this and nothing else. Texture ids in it are core ids
 * (sy_mirror_texture_handle gives the back-end handle). */
void sy_mirror_look(const sy_mirror *m, uint32_t background_id, sy_look *out);

#ifdef __cplusplus
}
#endif
#endif /* SY_MIRROR_H */
