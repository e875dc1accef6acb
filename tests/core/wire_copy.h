/* wire_copy.h — the core tests' change-list round trip: a scene's snapshot serialised, decoded
 * with a fresh blob store and applied to a replica, as a cluster client receives a scene.
 * Include after ../support/sy_check.h (each step is a CHECK_OK). */
#ifndef SY_TEST_WIRE_COPY_H
#define SY_TEST_WIRE_COPY_H

#include "sy_changes.h"
#include "sy_scene.h"

#include <stdlib.h>
#include <string.h>

typedef struct wire_copy {
    sy_changes *snap;     /* the origin's snapshot */
    void *wire;           /* its bytes (size of them) */
    size_t size;
    sy_blob_store *store; /* the decoder's */
    sy_changes *back;     /* the list decoded from the bytes */
} wire_copy;

/* Sends from's snapshot to `to`; 0 when every step succeeded, 1 (a failed check) otherwise. Free
 * with wire_copy_free in either case. */
static inline int wire_copy_send(wire_copy *c, sy_scene *from, sy_scene *to)
{
    sy_error e = {0};
    memset(c, 0, sizeof *c);
    CHECK_OK(sy_scene_snapshot(from, &c->snap, &e), e);
    CHECK_OK(sy_changes_serialize(c->snap, NULL, NULL, &c->wire, &c->size, &e), e);
    CHECK_OK(sy_blob_store_create(&c->store, &e), e);
    CHECK_OK(sy_changes_deserialize(c->wire, c->size, c->store, NULL, &c->back, &e), e);
    CHECK_OK(sy_scene_apply(to, c->back, &e), e);
    return 0;
}

static inline void wire_copy_free(wire_copy *c)
{
    free(c->wire);
    sy_changes_release(c->snap);
    sy_changes_release(c->back);
    sy_blob_store_destroy(c->store);
}

#endif /* SY_TEST_WIRE_COPY_H */
