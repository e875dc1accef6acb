/* sy_scene_test.h — the scene fixture of the core tests, on top of sy_check.h. Header-only; include
 * it after sy_check.h in one translation unit.
 *
 *   SY_SCENE_TEST(test_x)
 *   {
 *       ... uses `sy_scene *s` and `sy_error e` ...
 *       return 0;
 *   }
 *
 * defines `int test_x(void)` for RUN / SY_CHECK_MAIN: it records the blobs alive, creates a scene,
 * runs the body with it as `s` and a cleared sy_error as `e` (the body's own, passed by value),
 * destroys the scene (also when the body failed, so a failed check leaks nothing) and checks that
 * every blob created since was released. The body must not destroy `s`; other scenes it creates
 * are its own.
 *
 * sy_test_blob(data, size) copies bytes into a new blob the caller releases; a test cannot go on
 * without it, so a failure (out of memory) prints the reason and aborts. */
#ifndef SY_TEST_SY_SCENE_TEST_H
#define SY_TEST_SY_SCENE_TEST_H

#include <stdio.h>
#include <stdlib.h>

#include "sy_blob.h"
#include "sy_scene.h"

static inline sy_blob *sy_test_blob(const void *data, size_t size)
{
    sy_blob *b = NULL;
    sy_error e = {0};
    if (sy_blob_create_copy(data, size, &b, &e) != SY_OK) {
        fprintf(stderr, "blob: %s\n", e.message);
        abort();
    }
    return b;
}

/* Runs body on a new scene; see SY_SCENE_TEST. */
static inline int sy_scene_test_run(int (*body)(sy_scene *s, sy_error e))
{
    sy_error e = {0};
    long live0 = sy_blob_live_count();
    sy_scene *s;
    CHECK_OK(sy_scene_create(&s, &e), e);
    int rc = body(s, (sy_error){0});
    sy_scene_destroy(s);
    if (rc != 0) return rc;
    CHECK_MSG(sy_blob_live_count() == live0, "%ld blob(s) alive after the scene, %ld before",
              sy_blob_live_count(), live0);
    return 0;
}

#define SY_SCENE_TEST(name)                                                                         \
    static int name##_body(sy_scene *s, sy_error e);                                                \
    static int name(void) { return sy_scene_test_run(name##_body); }                                \
    static int name##_body(sy_scene *s, sy_error e)

#endif /* SY_TEST_SY_SCENE_TEST_H */
