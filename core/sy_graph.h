/** @file
 * sy_graph.h — the scene as a graph: parents, world matrices and bounds of nodes, mesh bounds.
 * Valid as of the last commit (sy_commit.h): world matrices and bounds are recomputed
 * incrementally for dirty subtrees, each node's once per commit.
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
/** World-space bounds of the node's subtree (its mesh and all descendants), primary path. */
sy_result sy_node_world_bounds(const sy_scene *s, sy_node n, sy_bounds *out, sy_error *err);
/** Local bounds of a mesh (all primitives). */
sy_result sy_mesh_bounds(const sy_scene *s, sy_mesh m, sy_bounds *out, sy_error *err);
/** World bounds of every root (nodes without parents) together. */
sy_bounds sy_scene_world_bounds(const sy_scene *s);

/** Statistic: nodes whose world matrix was recomputed by the last commit. */
uint32_t sy_scene_last_commit_world_updates(const sy_scene *s);

#ifdef __cplusplus
}
#endif
#endif /* SY_GRAPH_H */
