/* scene_msg.h — scenes as the cluster tests put them into SCENE messages (header-only): a serialized
 * snapshot of a scene built for one message, that of a one-texture scene whose pixels go by hash
 * only, and the SCENE message carrying such bytes. Thread-safety: any thread, one scene each. */
#ifndef SY_TEST_SCENE_MSG_H
#define SY_TEST_SCENE_MSG_H

#include "../support/sy_check.h"
#include "sy_cluster.h"

#include <string.h>

/* sy_changes_serialize's filter that sends no payload: blobs go by hash only */
static inline bool no_payloads(void *user, const sy_blob *b)
{
    (void)user, (void)b;
    return false;
}

/* The serialized snapshot of a scene built for one message (payloads sent as send says; NULL: all)
 * into *data (free()) and *size: commits sc, then destroys it, whatever happened. */
static inline sy_result scene_bytes(sy_scene *sc, sy_blob_send_fn send, void **data, size_t *size, sy_error *e)
{
    sy_changes *ch = NULL;
    sy_result r = sy_scene_commit(sc, NULL, e);
    if (r == SY_OK) r = sy_scene_snapshot(sc, &ch, e);
    if (r == SY_OK) r = sy_changes_serialize(ch, send, NULL, data, size, e);
    sy_changes_release(ch);
    sy_scene_destroy(sc);
    return r;
}

/* A SCENE of frame 1 carrying the serialized change list data (size bytes, the caller's), sequence
 * seq, flags SY_CLUSTER_SCENE_SNAPSHOT or 0. */
static inline sy_cluster_msg scene_msg(uint32_t seq, uint32_t flags, void *data, size_t size)
{
    sy_cluster_msg m;
    memset(&m, 0, sizeof m);
    m.header.type = SY_CLUSTER_SCENE;
    m.header.seq = seq;
    m.u.scene.frame = 1;
    m.u.scene.flags = flags;
    m.u.scene.changes = data;
    m.u.scene.changes_size = (uint32_t)size;
    return m;
}

/* The snapshot of a new scene holding one texture (name; w x h RGBA8 pixels px, n = 4 w h bytes)
 * with its blob by hash only, into *data (free()) and *size; *hash (unless NULL): the blob's. 0, or 1
 * after a failed check. */
static inline int texture_snapshot(const char *name, const uint8_t *px, size_t n, uint32_t w, uint32_t h, void **data,
                                   size_t *size, sy_hash128 *hash)
{
    sy_error e = {0};
    sy_scene *sc = NULL;
    sy_texture t;
    sy_blob *b = NULL;
    CHECK_OK(sy_scene_create(&sc, &e), e);
    CHECK_OK(sy_texture_create(sc, name, &t, &e), e);
    CHECK_OK(sy_blob_create_copy(px, n, &b, &e), e);
    if (hash) *hash = sy_blob_hash(b);
    sy_image_info ii = {w, h, 4, SY_PIXEL_U8_LINEAR};
    CHECK_OK(sy_texture_set_image(sc, t, &ii, b, &e), e);
    sy_blob_release(b);
    CHECK_OK(scene_bytes(sc, no_payloads, data, size, &e), e);
    return 0;
}

#endif /* SY_TEST_SCENE_MSG_H */
