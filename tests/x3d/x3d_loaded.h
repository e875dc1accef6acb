/* x3d_loaded.h — what the X3D tests share (header-only, one test executable per file): the scratch
 * directory g_dir (the test's main creates it with make_scratch_dir), small X3D files written into
 * it, and a file loaded into its own committed scene with the loader's result, error and info
 * (warnings searched by has_warning). Thread-safety: main thread only. */
#ifndef SY_TEST_X3D_LOADED_H
#define SY_TEST_X3D_LOADED_H

#include "sy_x3d.h"
#include "test_util.h"

static char g_dir[1024];

/* name in g_dir holding text; exits the test when it cannot be written. */
static void write_text(const char *name, const char *text)
{
    char p[2048];
    PATHF(p, "%s/%s", g_dir, name);
    if (write_bytes(p, text, strlen(text)) != 0) {
        fprintf(stderr, "cannot write %s\n", p);
        exit(1);
    }
}

typedef struct loaded {
    sy_scene *scene;
    sy_x3d_info info;
    sy_result r;   /* the load's, or SY_ERR_INVALID_ARGUMENT when the loaded scene did not commit */
    sy_error err;
} loaded;

static loaded load_path(const char *p)
{
    loaded l;
    memset(&l, 0, sizeof l);
    if (sy_scene_create(&l.scene, NULL) != SY_OK) exit(1);
    l.r = sy_x3d_load(p, l.scene, NULL, &l.info, &l.err);
    if (l.r == SY_OK && sy_scene_commit(l.scene, NULL, &l.err) != SY_OK) l.r = SY_ERR_INVALID_ARGUMENT;
    return l;
}

/* text written to name in g_dir, then loaded */
static loaded load_text(const char *name, const char *text)
{
    char p[2048];
    write_text(name, text);
    PATHF(p, "%s/%s", g_dir, name);
    return load_path(p);
}

static void unload(loaded *l)
{
    sy_x3d_info_free(&l->info);
    sy_scene_destroy(l->scene);
}

/* The load succeeded: a failed check naming what was loaded and why otherwise. */
static inline bool expect_loaded(const loaded *l, const char *what)
{
    EXPECT_MSG(l->r == SY_OK, "%s: %s", what, l->err.message);
    return l->r == SY_OK;
}

/* The shared test-data file rel below data (the test's TESTDATA_DIR argument, NULL without it) into
 * p; false, with the skip printed, when no folder was given or the file is absent. */
static inline bool sample_path(const char *data, const char *rel, char *p, size_t n)
{
    if (!data) {
        printf("skip: %s: no TESTDATA_DIR given\n", rel);
        return false;
    }
    snprintf(p, n, "%s/%s", data, rel);
    if (access(p, R_OK) != 0) {
        printf("skip: %s is absent\n", p);
        return false;
    }
    return true;
}

/* a stored warning contains a (and b unless NULL) */
static bool has_warning(const loaded *l, const char *a, const char *b)
{
    for (uint32_t k = 0; k < l->info.stored_warning_count; k++)
        if (strstr(l->info.warnings[k], a) && (!b || strstr(l->info.warnings[k], b))) return true;
    return false;
}

/* The main of an X3D test whose sample part may skip (x3d_anim, x3d_strokes): the scratch folder
 * g_dir (tagged name) made, the tests `void fn(void)` run in order, then samples(the TESTDATA_DIR
 * argument, NULL without it), the folder removed, and `return sy_check_finish(name)`. Write it at
 * file scope without a semicolon. */
#define X3D_MAIN(name, samples, ...)                                                                \
    int main(int argc, char **argv)                                                                 \
    {                                                                                               \
        static void (*const x3d_tests_[])(void) = {__VA_ARGS__};                                    \
        make_scratch_dir(g_dir, sizeof g_dir, name);                                                \
        for (size_t i = 0; i < sizeof x3d_tests_ / sizeof x3d_tests_[0]; ++i) x3d_tests_[i]();      \
        (samples)(argc > 1 ? argv[1] : NULL);                                                       \
        remove_scratch_dir(g_dir);                                                                  \
        return sy_check_finish(name);                                                               \
    }

#endif /* SY_TEST_X3D_LOADED_H */
