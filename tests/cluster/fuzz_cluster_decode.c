/* fuzz_cluster_decode.c — libFuzzer target for the cluster wire format as a receiver meets it on
 * a byte stream (protocol 3): the input is read as consecutive frames, each header checked against
 * a receiver's budget before its body is taken (sy_cluster_parse_header, sy_cluster_frame_check:
 * the handshake budget for the first message, an open session's for the rest, frames chunked with
 * MORE reassembled), and every complete message decoded (sy_cluster_decode_body); then what a
 * peer does next with a decoded message: the tile decoder (float32 and binary16 tiles,
 * sy_cluster_tile_decode), the blob table scan of a SCENE's change list (sy_changes_blob_refs, the
 * server's first step before BLOB_REQUEST), and the hash check of BLOBS payloads. The whole input
 * is also tried as one frame (sy_cluster_decode). Any byte string must be rejected with an error
 * or decoded into in-range fields, never crash, overread, hang or allocate more than the budget.
 * Built only with -DSY_FUZZ=ON (clang); the plain test test_cluster_proto runs random mutations in
 * every build. Seeds: tests/cluster/fuzz_seeds (test_cluster_proto --write-seeds DIR). */
#include "frame_join.h"
#include "sy_cluster.h"

#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void count_ref(void *user, sy_hash128 h, uint64_t size)
{
    (void)h;
    *(uint64_t *)user += size;
}

static void after_decode(const sy_cluster_msg *m)
{
    sy_error e = {0};
    if (m->header.type == SY_CLUSTER_TILES) {
        sy_layer l = {0};
        if (sy_layer_create(64, 64, &l, &e) == SY_OK) {
            for (uint32_t i = 0; i < m->u.tiles.tile_count; ++i) {
                const sy_cluster_tile *t = &m->u.tiles.tiles[i];
                if (t->rect.w <= 64 && t->rect.h <= 64) (void)sy_cluster_tile_decode(t, &l, 0, 0, &e);
            }
            sy_layer_destroy(&l);
        }
    } else if (m->header.type == SY_CLUSTER_SCENE) {
        uint64_t named = 0;
        (void)sy_changes_blob_refs(m->u.scene.changes, m->u.scene.changes_size, NULL, count_ref, &named, &e);
    } else if (m->header.type == SY_CLUSTER_BLOBS) {
        uint32_t matching = 0;
        for (uint32_t i = 0; i < m->u.blobs.count; ++i)
            matching += sy_hash_equal(sy_hash_bytes(m->u.blobs.blobs[i].data, (size_t)m->u.blobs.blobs[i].size),
                                      m->u.blobs.blobs[i].hash);
        (void)matching;
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    sy_cluster_msg m;
    sy_error e = {0};
    sy_cluster_limits lim = {1u << 20};
    if (sy_cluster_decode(data, size, &lim, &m, &e) == SY_OK) {
        after_decode(&m);
        sy_cluster_msg_free(&m);
    }
    /* as a stream: the first message under the handshake budget, the rest under a session's
     * (tags are not checked here: a tagged frame's 32 tag bytes are skipped) */
    frame_join j = frame_join_start(1u << 16, 1u << 20, true);
    size_t pos = 0;
    while (size - pos >= SY_CLUSTER_HEADER_SIZE) {
        int got = frame_join_take(&j, data, size, &pos, &e);
        if (got < 0) break;
        if (got == 0) continue;
        /* an exactly-sized copy, so that an overread of the body is caught */
        uint8_t *exact = malloc(j.size ? j.size : 1);
        if (!exact) break;
        memcpy(exact, j.body, j.size);
        if (sy_cluster_decode_body(&j.first, exact, j.size, &lim, &m, &e) == SY_OK) {
            after_decode(&m);
            sy_cluster_msg_free(&m);
        }
        free(exact);
        frame_join_next(&j);
    }
    free(j.body);
    return 0;
}
