/** @file
 * sy_graph.h — the scene as a graph: parents, world matrices and bounds of nodes, mesh bounds,
 * and the one world-matrix walk (sy_placement_child, sy_scene_walk).
 * The queries are valid as of the last commit (sy_commit.h): world matrices and bounds are
 * recomputed incrementally for dirty subtrees, each node's once per commit. The walk reads the
 * current fields.
 * Ownership: a walk step's pointers are borrowed for the duration of the callback.
 * Thread-safety: as the scene (sy_scene.h). */
#ifndef SY_GRAPH_H
#define SY_GRAPH_H

#include "sy_objects.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- graph queries (valid as of the last commit; recomputed incrementally for dirty subtrees) ----
 * In a DAG a node reached along several paths has several world placements; these queries follow
 * each node's primary parent (its first parent), which is the only placement in a tree. */
/** Number of parents of a node (more than one in a DAG). */
uint32_t sy_node_parent_count(const sy_scene *s, sy_node n);
/** The i-th parent of a node (i < sy_node_parent_count). */
sy_node sy_node_parent(const sy_scene *s, sy_node n, uint32_t i);
/** World matrix of the node along its primary path. */
sy_result sy_node_world_matrix(const sy_scene *s, sy_node n, sy_mat4 *out, sy_error *err);
/** World-space bounds of the node's subtree (its mesh and all descendants), primary path. A skinned
 *  mesh counts where its joints put it (each joint's bind-pose vertices placed by joint world x
 *  inverse bind: a box around the deformed mesh, not the bind pose's), updated when a joint moves;
 *  morph targets are not counted (the base shape's bounds). */
sy_result sy_node_world_bounds(const sy_scene *s, sy_node n, sy_bounds *out, sy_error *err);
/** Local bounds of a mesh (all primitives). */
sy_result sy_mesh_bounds(const sy_scene *s, sy_mesh m, sy_bounds *out, sy_error *err);
/** World bounds of every root (nodes without parents) together. */
sy_bounds sy_scene_world_bounds(const sy_scene *s);

/* ---- the world-matrix walk: one rule for every path through the graph ----
 * A node's placement along one path from a root: world = the local matrices multiplied from the
 * root down (the node's own last); visible = the node and every node above it on the path have
 * SY_NODE_VISIBLE; selected = one of them has SY_NODE_SELECTED. The committed queries above (primary paths), sy_scene_walk below (every path of
 * the current fields), the scene mirror of the mediators (every path, from change lists) and the
 * glTF writer all place nodes by sy_placement_child. */
/** A node's world matrix and visibility along one path. */
typedef struct sy_placement {
    sy_mat4 world; /**< the node's world matrix along the path */
    bool visible;  /**< the node and all its ancestors on the path are visible */
    bool selected; /**< the node or one of its ancestors on the path is selected (SY_NODE_SELECTED) */
} sy_placement;

/** The placement of a node with this local matrix and these flags (sy_node_flags) under its
 * parent's placement; parent NULL: the node starts the path (world = local, no product). */
sy_placement sy_placement_child(const sy_placement *parent, const sy_mat4 *local, uint32_t flags);

/** One node as sy_scene_walk reaches it. */
typedef struct sy_walk_step {
    sy_node node;             /**< the node */
    const sy_node_data *data; /**< its fields; NULL: a stale id (a destroyed child still listed) */
    sy_placement place;       /**< its placement along this path (unset when data is NULL) */
    uint32_t depth;           /**< 0 for the walk's root */
} sy_walk_step;

/** Called once per node and path. SY_OK goes on (into the node's children, unless data is NULL);
 * anything else stops the walk, which returns it. It must not modify the scene. */
typedef sy_result (*sy_walk_fn)(void *user, const sy_walk_step *step, sy_error *err);

/** sy_scene_walk flags. */
#define SY_WALK_VISIBLE_ONLY 1u /**< skip nodes that are not visible along their path, and their subtrees */

/** Walks root and everything below it depth first in child order, once per path (a node reached
 * along k paths is met k times), reading the current fields (not the committed state the queries
 * above answer from). above: the placement root hangs under (NULL: root starts the path). Stale
 * child ids are passed with data NULL. The walk keeps its own stack (no recursion: any depth), but
 * paths multiply in a DAG: bound them in fn (step->depth, a count) where the graph is untrusted. */
sy_result sy_scene_walk(const sy_scene *s, sy_node root, const sy_placement *above, uint32_t flags, sy_walk_fn fn,
                        void *user, sy_error *err);

/** Statistic: nodes whose world matrix was recomputed by the last commit. */
uint32_t sy_scene_last_commit_world_updates(const sy_scene *s);

#ifdef __cplusplus
}
#endif
#endif /* SY_GRAPH_H */
