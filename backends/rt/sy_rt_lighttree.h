/* sy_rt_lighttree.h — the light hierarchy of the ray tracers (many lights): a BVH over emissive
 * triangles and punctual lights whose nodes bound position (a box), power and orientation (a cone
 * of normals theta_o plus an emission spread theta_e), after Conty & Kulla 2018 ("Importance
 * Sampling of Many Lights with Adaptive Tree Splitting") and Blender 3.5's light tree.
 *
 * Selection: from a shading point p (and its normal n, or none) a stochastic traversal descends
 * from the root choosing in proportion to their importance at p (power x the cone-bounded
 * emission cosine x the box-bounded surface cosine / the clamped squared distance) among a node's
 * four grandchildren where both its children are inner nodes, else among its two children, and
 * in a leaf (up to SY_RT_LT_LEAF_MAX lights) a light the same way. (Weighing the grandchildren by
 * their own, finer bounds instead of the children's first: relMSE 0.058 -> 0.040 at equal time on
 * `sy bench lights`, the rare picks with huge weights gone; docs/BACKENDS.md "Many lights".)
 * Directional lights have no position: they stand beside the root, each with importance = its
 * irradiance x the bounded surface cosine; local lights the caller marks `top` stand there too,
 * each weighed by its own bounds. The
 * probability of the chosen light is the product of the choices; sy_rt_lighttree_pdf recomputes
 * it for any light (each light keeps its leaf, every node its parent), so that a light hit by a
 * BSDF ray gets its MIS weight. Both run the same float operations: pick's pdf equals pdf's.
 *
 * Lights are numbered by the caller (the device: its area triangles, then its punctual lights).
 * Lights with zero, negative or non-finite power, or non-finite bounds, are left out (never
 * picked, pdf 0) and counted in `skipped`; dark ones (below) are left out too, not counted.
 * Memory: 72 bytes per light (its record and maps) plus 72 per node (about 0.7 nodes per
 * light; 2 n - 1 are allocated during the build), held in `bytes`: about 120 bytes per light.
 * Not thread-safe to build or update; pick and pdf read only and may run on any number of threads.
 * Internal to backends/rt. */
#ifndef SY_RT_LIGHTTREE_H
#define SY_RT_LIGHTTREE_H

#include "sy_rt_math.h"

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define SY_RT_LT_LEAF_MAX 4u
#define SY_RT_LT_NONE UINT32_MAX

/* What a light or a node bounds: its box, orientation cone (unit axis, theta_o: the normals'
 * spread around it, theta_e <= pi / 2: the emission's spread around each normal, radians) and power (the
 * radiant intensity of a point light, emitted radiance x area for a triangle: both give
 * power / d^2 on axis at distance d). */
typedef struct sy_rt_lt_bounds {
    float lo[3], hi[3];
    float axis[3];
    float theta_o, theta_e;
    float power;
    float cos_o, sin_o, cos_e; /* of theta_o and theta_e: filled by the tree (callers leave them 0) */
} sy_rt_lt_bounds;

/* One light given to the build. distant: a directional light (only axis = its direction of travel
 * and power = its irradiance are read); it stands beside the root. top: a local light (a point or
 * spot light) that stands beside the root too, each pick weighing it by its own bounds instead of
 * a node's (the caller's choice for a few punctual lights among many emissive triangles: in the
 * tree, a node they share with triangles bounds both loosely; LightsPunctualLamp, docs/BACKENDS.md).
 * dark: the caller knows it emits nothing anywhere (a textured emitter's triangle over black
 * texels): left out like an invalid light, never picked (pdf 0), but not counted in `skipped`. */
typedef struct sy_rt_lt_light {
    sy_rt_lt_bounds b;
    bool distant;
    bool top;
    bool dark;
} sy_rt_lt_light;

typedef struct sy_rt_lt_node {
    sy_rt_lt_bounds b;
    uint32_t child;  /* inner: left child (the right one is child + 1); leaf: first entry of prims */
    uint32_t count;  /* 0: inner node; else the leaf's lights */
    uint32_t parent; /* SY_RT_LT_NONE at the root */
} sy_rt_lt_node;

typedef struct sy_rt_lighttree {
    uint32_t light_count;   /* the caller's lights (indices 0 .. light_count - 1) */
    sy_rt_lt_node *nodes;   /* nodes[0] is the root (when node_count > 0) */
    uint32_t node_count;
    sy_rt_lt_bounds *prims; /* the tree's lights in leaf order */
    uint32_t *prim_light;   /* leaf order -> light */
    uint32_t *prim_leaf;    /* leaf order -> its leaf node */
    uint32_t prim_count;
    uint32_t *light_prim;   /* light -> leaf order; SY_RT_LT_NONE: skipped or at the top */
    uint32_t *top;          /* the lights beside the root: directional ones and those marked `top` */
    sy_rt_lt_bounds *top_b;
    bool *top_local;        /* top entry -> not directional: weighed by sy_rt_lighttree_importance */
    uint32_t top_count;
    uint32_t *light_top;    /* light -> index in top, SY_RT_LT_NONE otherwise (NULL when none is at the top) */
    uint32_t skipped;        /* lights left out */
    uint32_t first_skipped;  /* the first of them (SY_RT_LT_NONE when none) */
    size_t bytes;            /* held by the tree */
    uint32_t depth;          /* deepest leaf */
} sy_rt_lighttree;

/* Builds *t over lights[0 .. n-1] (t is overwritten; free it first). max_bytes (0 = no limit)
 * bounds what the tree may hold: false with *t empty when it would need more, or when out of
 * memory (*oom says which). */
bool sy_rt_lighttree_build(sy_rt_lighttree *t, const sy_rt_lt_light *lights, uint32_t n, size_t max_bytes, bool *oom);
void sy_rt_lighttree_free(sy_rt_lighttree *t);
/* Refits *t to lights whose bounds or power changed (same count, same distant, top and dark
 * flags, none newly skipped or unskipped, at most n / 64 + 1 changed: else false and *t
 * unchanged, the caller rebuilds). Each changed light updates its leaf and the path to the root: O(changed x depth)
 * plus one pass comparing records. *changed gets how many lights changed. A refitted tree samples
 * differently from a fresh build over the same lights (the same expected image, not the same
 * noise). */
bool sy_rt_lighttree_refit(sy_rt_lighttree *t, const sy_rt_lt_light *lights, uint32_t n, uint32_t *changed);

/* Picks a light for shading point p with normal n (zero vector: none, e.g. a transmissive
 * surface) from one uniform number u in [0, 1). Returns the light, or SY_RT_LT_NONE when no light
 * can reach p; *pdf gets its selection probability. */
uint32_t sy_rt_lighttree_pick(const sy_rt_lighttree *t, sy_rt_v3 p, sy_rt_v3 n, float u, float *pdf);
/* The probability with which sy_rt_lighttree_pick(t, p, n, .) returns light (0 for a skipped one). */
float sy_rt_lighttree_pdf(const sy_rt_lighttree *t, sy_rt_v3 p, sy_rt_v3 n, uint32_t light);
/* The sum of the importances at (p, n) of the top level's entries (the root and the lights beside
 * it), by which pick chooses among them: how much light the whole tree can bring to p, in the units
 * of irradiance (a light of power P on axis at distance d gives P / d^2). 0 for an empty tree. */
float sy_rt_lighttree_total_importance(const sy_rt_lighttree *t, sy_rt_v3 p, sy_rt_v3 n);
/* Importance of bounds b at (p, n), the measure both use (exposed for tests). */
float sy_rt_lighttree_importance(const sy_rt_lt_bounds *b, sy_rt_v3 p, sy_rt_v3 n);
/* sy_rt_lighttree_importance of four bounds at once, into out[0..3], each bit for bit the scalar
 * function's value (the same float operations in the same order, one SIMD lane each; the walk's
 * steps use it, the scalar one the root; exposed for tests). */
void sy_rt_lighttree_importance4(const sy_rt_lt_bounds *const b[4], sy_rt_v3 p, sy_rt_v3 n, float out[4]);

#endif /* SY_RT_LIGHTTREE_H */
