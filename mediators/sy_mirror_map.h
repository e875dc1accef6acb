/** @file
 * sy_mirror_map.h — a mediator's own per-object tables: records of one fixed size keyed by a
 * 32-bit back-end handle or core id (never 0), beside the scene mirror (sy_mirror.h).
 *
 * The mirror keeps the scene; what a mediator derives per back-end object on top of it (the
 * raster's emitters and albedos per material, its blobs per mesh, its instances' matrices; the ray
 * tracer's node per instance) lives in these maps: open addressing with linear probing, a deleted
 * slot kept as a tombstone; the capacity doubles when three quarters are filled. Walking the slots
 * 0 .. cap - 1 with sy_mirror_map_slot visits the live records in a fixed order (the same for the
 * same sequence of puts and deletes).
 *
 * Ownership: the map owns its arrays (sy_mirror_map_free releases them, not what records point
 * to); a record pointer is valid until the next put or free.
 * Thread-safety: none; a map belongs to one mediator state. */
#ifndef SY_MIRROR_MAP_H
#define SY_MIRROR_MAP_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/** A map: set elem (the record size), leave the rest zero (SY_MIRROR_MAP_INIT). */
typedef struct sy_mirror_map {
    uint32_t *keys; /**< per slot: its key (0 when empty or deleted) */
    uint8_t *used;  /**< per slot: 0 empty, 1 live, 2 deleted */
    void *vals;     /**< cap records of elem bytes */
    /** @{ slots, live records, slots ever filled (live + deleted) */
    uint32_t cap, live, filled; /** @} */
    size_t elem; /**< record size in bytes */
} sy_mirror_map;

/** An empty map of records of type T. */
#define SY_MIRROR_MAP_INIT(T) ((sy_mirror_map){NULL, NULL, NULL, 0, 0, 0, sizeof(T)})

/** The record of key, or NULL (also for key 0). */
void *sy_mirror_map_get(const sy_mirror_map *m, uint32_t key);
/** The record of key (non-zero), zeroed when new; NULL when out of memory (the map is unchanged). */
void *sy_mirror_map_put(sy_mirror_map *m, uint32_t key);
/** Deletes key's record, if any. */
void sy_mirror_map_del(sy_mirror_map *m, uint32_t key);
/** The live record at slot (0 .. cap - 1), or NULL: walks the map. */
void *sy_mirror_map_slot(const sy_mirror_map *m, uint32_t slot);
/** Frees the arrays; the map is empty again (elem kept). */
void sy_mirror_map_free(sy_mirror_map *m);

#ifdef __cplusplus
}
#endif
#endif /* SY_MIRROR_MAP_H */
