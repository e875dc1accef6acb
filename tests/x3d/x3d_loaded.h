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

/* a stored warning contains a (and b unless NULL) */
static bool has_warning(const loaded *l, const char *a, const char *b)
{
    for (uint32_t k = 0; k < l->info.stored_warning_count; k++)
        if (strstr(l->info.warnings[k], a) && (!b || strstr(l->info.warnings[k], b))) return true;
    return false;
}

#endif /* SY_TEST_X3D_LOADED_H */
