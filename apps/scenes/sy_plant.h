/** @file
 * sy_plant.h — a generated "plant" for the remote culling service (issue 18): tanks, horizontal
 * vessels, pipe racks, support columns, buildings, pumps and valve wheels laid out unit by unit on
 * a square grid, with a lot of mutual occlusion, parameterised by its triangle and object counts.
 *
 * Layout: object i lies in unit i / 25 (slot i % 25), units on a G x G grid (G = ceil(sqrt(units)))
 * of 24 m cells centred on the origin, Y up, the ground at y = 0 (no ground object). Every unit has
 * 2 tanks (7..16 m tall), 2 horizontal vessels, 4 boxes (a building, pumps, a shed), 10 pipes
 * running the full cell length (continuous racks across units), 4 columns and 3 valve wheels.
 * Objects are direct children of one root node (identity transform), one node per object
 * (SY_NODE_VISIBLE) with a prototype mesh: meshes are shared between objects of the same kind,
 * variant (4 tessellation levels per kind) and material, as standard parts are in CAD models, so the
 * scene's memory stays small while every object counts its full triangles. The tessellation is
 * chosen (bisection on one detail factor) so that the sum over objects comes closest to the
 * requested triangles; the exact count is returned. Deterministic for a given desc (seeded hash).
 *
 * Ownership: objects are created in the caller's scene (which owns them); nothing is committed.
 * Thread-safety: writes to the scene, so as any scene modification (one thread at a time). */
#ifndef SY_PLANT_H
#define SY_PLANT_H

#include "sy_scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/** What to generate. Zero-initialise ({0}) for the defaults given per field. */
typedef struct sy_plant_desc {
    uint64_t triangles; /**< target total (the result is the closest reachable); 0 = 10 000 000 */
    uint32_t objects;   /**< objects (exact); 0 = 10 000; at most 1 << 22 */
    uint32_t seed;      /**< jitter of sizes and heights */
} sy_plant_desc;

/** What was generated. */
typedef struct sy_plant_info {
    sy_node root;        /**< parent of every object (identity transform) */
    uint32_t objects;    /**< objects (nodes with a mesh) */
    uint64_t triangles;  /**< triangles of all objects together */
    uint32_t meshes;     /**< distinct prototype meshes */
    uint32_t grid;       /**< units per side of the grid */
    float cell;          /**< unit size in metres (24) */
    sy_bounds bounds;    /**< world bounds of the objects */
    float corridor_x;    /**< x of a free corridor along z nearest the centre (a camera path): every
                          * cell column has one at x = its centre - 11.1 m, 1.8 m wide, where only
                          * pipe racks (up to 7.8 m high) cross it at the cells' edges */
} sy_plant_info;

/** Generates the plant into scene s (see the file comment). On failure the objects created so far
 * stay in the scene (unreferenced by any committed root: the caller discards the scene). */
sy_result sy_plant_generate(sy_scene *s, const sy_plant_desc *desc, sy_plant_info *out, sy_error *err);

#ifdef __cplusplus
}
#endif
#endif /* SY_PLANT_H */
