/** @file
 * sy_deform_cache.h — one deformation for every back-end: the deformed poses (sy_deform.h) that the
 * scene mirrors of a process share, so that three contexts on one scene (whitted, pathtracer,
 * raster; or one per viewport) deform a skinned or morphed mesh once per scene time, not once each.
 *
 * A pose is keyed on its content: the source primitive's blobs (their XXH3-128 hashes: positions,
 * normals, tangents, joints, skin weights and morph-target deltas), the morph weights that count and
 * the composed joint matrices. Two calls with equal keys compute the same vertices bit for bit, so a
 * taken pose is exactly what the taker would have computed: correct whatever scene, node, context or
 * time it comes from (contexts at different times, the two syncs of a motion-blurred render, get
 * different keys; a context on the open and one on the close each find their own). The full key is
 * kept and compared, not only its hash.
 *
 * Lifetime: every mirror attaches on creation and detaches on destruction. While fewer than two
 * mirrors are attached nothing is kept (one mirror has no one to share with: sy_deform_cache_take
 * deforms and hands over, no memory beyond the pose it returns). With two or more, a computed pose
 * stays until every attached mirror took it (each counted once, up to SY_DEFORM_CACHE_SLOTS mirrors;
 * the ones beyond share without being counted), or until the cache is over SY_DEFORM_CACHE_MAX_BYTES
 * (the least recently used go first; a pose bigger than that is not kept), or the last mirror
 * detaches. A pose another thread is computing is waited for, not computed twice.
 *
 * Ownership: the cache holds references to its poses' blobs; sy_deform_cache_take hands the caller
 * references of its own (sy_deform_pose_release gives them back). Thread-safety: every function may
 * be called from any thread (one process-wide mutex around the table; the deformation itself runs
 * outside it, on sy_deform_primitive's threads). */
#ifndef SY_DEFORM_CACHE_H
#define SY_DEFORM_CACHE_H

#include "sy_deform.h"

#ifdef __cplusplus
extern "C" {
#endif

#define SY_DEFORM_CACHE_MAX_BYTES (256u << 20) /**< bytes of vertices the cache keeps at most */
#define SY_DEFORM_CACHE_SLOTS 64u              /**< mirrors counted as takers (the rest share uncounted) */

/** One deformed pose of a primitive: immutable blobs, shared. */
typedef struct sy_deform_pose {
    sy_blob *positions; /**< float[3] x vertices (NULL when !ok) */
    sy_blob *normals;   /**< float[3] x vertices when the source has normals, else NULL */
    sy_blob *tangents;  /**< float[4] x vertices when the source has tangents, else NULL */
    sy_bounds bounds;   /**< of the positions */
    bool ok;            /**< false: a position left the coordinate range (sy_deform_primitive); no blobs */
    bool shared;        /**< taken from the cache: another call computed it */
    double seconds;     /**< wall time this call spent in sy_deform_primitive (0 when shared) */
} sy_deform_pose;

/** Attaches a user (a mirror): *slot receives its taker slot (SY_DEFORM_CACHE_SLOTS: uncounted). */
void sy_deform_cache_attach(uint32_t *slot);
/** Detaches the user of slot; the last one empties the cache. */
void sy_deform_cache_detach(uint32_t slot);
/** The pose of in (in->primitive with its weights and joints): taken from the cache when some call
 * made it, otherwise deformed here (sy_deform_primitive) and kept for the other attached users.
 * slot: the caller's (sy_deform_cache_attach). *out is the caller's (sy_deform_pose_release). Errors:
 * out of memory only (a pose out of range is out->ok false, no error). */
sy_result sy_deform_cache_take(const sy_deform_input *in, uint32_t slot, sy_deform_pose *out, sy_error *err);
/** Releases the pose's references (NULL-safe) and zeroes it. */
void sy_deform_pose_release(sy_deform_pose *p);

/** Turns sharing on (the default) or off for the whole process: off, every call deforms and nothing
 * is kept, as when each mirror deformed its own copy (benchmarks compare the two in one run). */
void sy_deform_cache_set_sharing(bool on);

/** Process-wide counts since the start (tests and benchmarks). */
typedef struct sy_deform_cache_stats {
    uint64_t computed;  /**< poses deformed (sy_deform_primitive called) */
    uint64_t shared;    /**< poses taken from the cache */
    uint32_t entries;   /**< poses kept now */
    uint64_t bytes;     /**< their vertex bytes */
    uint32_t users;     /**< attached users */
} sy_deform_cache_stats;
/** Fills out. */
void sy_deform_cache_stats_get(sy_deform_cache_stats *out);

#ifdef __cplusplus
}
#endif
#endif /* SY_DEFORM_CACHE_H */
