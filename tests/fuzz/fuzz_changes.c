/* fuzz_changes.c — libFuzzer target for the change-list wire decoder (sy_changes_deserialize):
 * untrusted network input in the cluster. Decoded lists are applied to a scratch scene too, under
 * the render server's replica policy (slot limit, and pool growth bounded by the list's size:
 * sy_scene_apply_bounded with SY_CLUSTER_APPLY_SLACK_SLOTS + size / SY_CLUSTER_APPLY_BYTES_PER_SLOT),
 * so what the decoder accepts is exercised downstream and no input can make the replica allocate
 * pools for millions of slots (which an unbounded apply would: one entry naming slot 4M). */
#include "sy_changes.h"
#include "sy_cluster.h"
#include "sy_scene.h"

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size);

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size)
{
    sy_blob_store *store;
    if (sy_blob_store_create(&store, NULL) != SY_OK) return 0;
    sy_changes_limits lim = {1u << 16, 1u << 24, 1u << 16};
    sy_changes *c = NULL;
    if (sy_changes_deserialize(data, size, store, &lim, &c, NULL) == SY_OK) {
        sy_scene *s;
        if (sy_scene_create(&s, NULL) == SY_OK) {
            sy_scene_set_apply_limit(s, SY_CLUSTER_DEFAULT_MAX_OBJECTS);
            sy_scene_apply_bounded(s, c, SY_CLUSTER_APPLY_SLACK_SLOTS + size / SY_CLUSTER_APPLY_BYTES_PER_SLOT, NULL);
            sy_scene_commit(s, NULL, NULL);
            sy_scene_destroy(s);
        }
        sy_changes_release(c);
    }
    sy_blob_store_destroy(store);
    return 0;
}
