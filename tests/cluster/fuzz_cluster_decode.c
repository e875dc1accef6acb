/* fuzz_cluster_decode.c — libFuzzer target for the cluster message decoder (sy_cluster_decode) and
 * the tile decoder behind it (sy_cluster_tile_decode): any byte string must be rejected with an
 * error or decoded into in-range fields, never crash, overread or hang. Built only with
 * -DSY_FUZZ=ON (clang); the plain test test_cluster_proto runs random mutations in every build. */
#include "sy_cluster.h"

#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

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
    }
    sy_cluster_msg_free(&m);
    return 0;
}
