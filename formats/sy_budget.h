/** @file
 * sy_budget.h — one memory budget per loaded file, shared by every loader (glTF, X3D, and the
 * formats to come).
 *
 * Limits per primitive or per image do not stop a small file from asking for a lot: 64 primitives
 * sharing one 2^24-vertex accessor, an Extrusion of 4000 x 4000, a USE graph of 2^30 paths, a small
 * PNG that decodes to hundreds of megabytes. A loader therefore charges, before allocating, what the
 * file makes the scene and the back-ends hold to one budget:
 *   - every vertex attribute and index it decodes (bytes as the scene stores them), for each
 *     primitive that uses them (back-ends copy per primitive, even when blobs are shared);
 *   - every decoded texture (bytes of its pixels);
 *   - every placement (a node along one path of the graph: what the mirror and a back-end hold for
 *     it, SY_BUDGET_PLACEMENT_BYTES each), counted once per path, so instancing and X3D USE / Inline
 *     fan-out pay for what they multiply.
 * A charge past the limit fails with SY_ERR_LIMIT, naming the file, the item and both sizes. The
 * default limit is an eighth of the machine's physical memory (3 GiB of 24: the back-ends hold up to
 * about three times the scene's bytes again, one copy each, plus their acceleration structures),
 * settable per load (loader options' max_scene_bytes; `sy --max-scene-mb N` for every command).
 *
 * Ownership: a sy_budget is a plain value the loader keeps for one load; `file` is borrowed.
 * Thread-safety: none (one budget per load, on one thread); sy_budget_default_bytes is thread-safe. */
#ifndef SY_BUDGET_H
#define SY_BUDGET_H

#include "sy_scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/** What one placement costs: the mirror's placement, a back-end instance and its share of the
 * top-level acceleration structure. */
#define SY_BUDGET_PLACEMENT_BYTES 256u

/** A load's budget. */
typedef struct sy_budget {
    const char *file; /**< named in errors (borrowed) */
    uint64_t limit;   /**< bytes the load may charge */
    uint64_t used;    /**< bytes charged so far */
} sy_budget;

/** An eighth of the physical memory, at least 256 MiB (256 MiB when it cannot be read). */
uint64_t sy_budget_default_bytes(void);

/** A budget of limit bytes for file (limit 0: sy_budget_default_bytes). */
sy_budget sy_budget_make(const char *file, uint64_t limit);

/** Charges count x unit bytes for `what` (printf-style, e.g. "meshes[3].primitives[0]: 2^24
 * vertices"): SY_OK, or SY_ERR_LIMIT naming the file, the item and the sizes (nothing charged). */
sy_result sy_budget_charge(sy_budget *b, uint64_t count, uint64_t unit, sy_error *err, const char *what, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 5, 6)))
#endif
    ;

/** true when count x unit bytes fit what is left (nothing charged): for checks where arrays are
 * sized, before the charge where the data is made (a failing check then calls sy_budget_charge
 * for its message). */
bool sy_budget_fits(const sy_budget *b, uint64_t count, uint64_t unit);

/** Charges the placements of the graph below root (the number of paths from root to each node,
 * SY_BUDGET_PLACEMENT_BYTES each), counted once per node by dynamic programming over the DAG, with
 * the count saturating at the budget: a graph of 2^40 paths costs microseconds to refuse. */
sy_result sy_budget_charge_placements(sy_budget *b, const sy_scene *scene, sy_node root, sy_error *err);

#ifdef __cplusplus
}
#endif
#endif /* SY_BUDGET_H */
