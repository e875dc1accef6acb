/* fuzz_cluster_decode.c — libFuzzer target for the cluster message decoder (sy_cluster_decode) and
 * what a peer does next with a decoded message: the tile decoder (float32 and binary16 tiles,
 * sy_cluster_tile_decode), the blob table scan of a SCENE's change list (sy_changes_blob_refs, the
 * server's first step before BLOB_REQUEST), and the hash check of BLOBS payloads. Any byte string
 * must be rejected with an error or decoded into in-range fields, never crash, overread or hang.
 * Built only with -DSY_FUZZ=ON (clang); the plain test test_cluster_proto runs random mutations in
 * every build. */
#include "sy_cluster.h"

#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void count_ref(void *user, sy_hash128 h, uint64_t size)
{
    (void)h;
    *(uint64_t *)user += size;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    sy_cluster_msg m;
    sy_error e = {0};
    sy_cluster_limits lim = {1u << 20};
    if (sy_cluster_decode(data, size, &lim, &m, &e) != SY_OK) return 0;
    if (m.header.type == SY_CLUSTER_TILES) {
        sy_layer l = {0};
        if (sy_layer_create(64, 64, &l, &e) == SY_OK) {
            for (uint32_t i = 0; i < m.u.tiles.tile_count; ++i) {
                const sy_cluster_tile *t = &m.u.tiles.tiles[i];
                if (t->rect.w <= 64 && t->rect.h <= 64) (void)sy_cluster_tile_decode(t, &l, 0, 0, &e);
            }
            sy_layer_destroy(&l);
        }
    } else if (m.header.type == SY_CLUSTER_SCENE) {
        uint64_t named = 0;
        (void)sy_changes_blob_refs(m.u.scene.changes, m.u.scene.changes_size, NULL, count_ref, &named, &e);
    } else if (m.header.type == SY_CLUSTER_BLOBS) {
        uint32_t matching = 0;
        for (uint32_t i = 0; i < m.u.blobs.count; ++i)
            matching += sy_hash_equal(sy_hash_bytes(m.u.blobs.blobs[i].data, (size_t)m.u.blobs.blobs[i].size),
                                      m.u.blobs.blobs[i].hash);
        (void)matching;
    }
    sy_cluster_msg_free(&m);
    return 0;
}
