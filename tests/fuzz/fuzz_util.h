/* fuzz_util.h — shared by the libFuzzer targets in tests/fuzz. Test-only, header-only.
 *
 * fuzz_resource_dir(): the directory the loaders resolve external URIs (glTF buffers and images,
 * X3D Inline and ImageTexture) in: $SY_FUZZ_RESOURCES when set (tests/fuzz/fuzz.sh points it at a
 * directory of copies of the seeds' companion files, so seeds with external .bin files load
 * fully), else a path that does not exist (every external file is then "missing"). Inputs are
 * always loaded from memory: nothing is written per execution. */
#ifndef SY_FUZZ_UTIL_H
#define SY_FUZZ_UTIL_H

#include <stdio.h>
#include <stdlib.h>

static const char *fuzz_resource_dir(void)
{
    static char dir[1024];
    if (!dir[0]) {
        const char *e = getenv("SY_FUZZ_RESOURCES");
        snprintf(dir, sizeof dir, "%s/", e && *e ? e : "/nonexistent-sy-fuzz");
    }
    return dir;
}

/* The small limits every loader target runs under, set on its options o (the loaders' options
 * share these field names): 1 MiB files, 2^18 vertices and image pixels, a 64 MiB scene (the file
 * budget). */
#define FUZZ_LIMITS(o)                                                                              \
    ((o).max_file_bytes = 1u << 20, (o).max_vertices = 1u << 18, (o).max_image_pixels = 1u << 18,   \
     (o).max_scene_bytes = (uint64_t)64 << 20)

/* The end of a loader target: a scene that loaded is committed (its change list built, as an
 * application's would be), then the scene is destroyed. */
#define FUZZ_COMMIT_AND_DESTROY(s, loaded)                                                          \
    do {                                                                                            \
        if ((loaded) == SY_OK) sy_scene_commit((s), NULL, NULL);                                    \
        sy_scene_destroy(s);                                                                        \
    } while (0)

#ifdef SY_FUZZ_GLTF
#include "sy_gltf.h"

/* The glTF and GLB targets' load: from memory into a fresh scene, small limits; `name` (".gltf" or
 * ".glb") picks the container as a file name would. Any result code is fine. */
static void fuzz_load_gltf(const unsigned char *data, size_t size, const char *name)
{
    sy_scene *s;
    if (sy_scene_create(&s, NULL) != SY_OK) return;
    sy_gltf_options o = {0};
    FUZZ_LIMITS(o);
    o.max_indices = 1u << 19;
    o.max_instances = 1u << 12;
    sy_gltf_info info = {0};
    sy_error err = {0};
    sy_result r = sy_gltf_load_memory(data, size, name, fuzz_resource_dir(), s, &o, &info, &err);
    sy_gltf_info_free(&info);
    FUZZ_COMMIT_AND_DESTROY(s, r);
}
#endif

#endif /* SY_FUZZ_UTIL_H */
