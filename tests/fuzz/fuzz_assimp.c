/* fuzz_assimp.c — libFuzzer targets for the formats read through Assimp (formats/sy_assimp.h), from
 * memory: one binary per format (assimp_obj, assimp_ply, assimp_stl, assimp_fbx, assimp_dae), built
 * from this file with FUZZ_ASSIMP_NAME naming the input ("fuzz.obj", ...) so that Assimp's importer
 * for that extension reads it (the content can still pick another one). Files the input names
 * resolve in fuzz_resource_dir(), confined there.
 * The load runs in this process (sy_assimp_options.in_process) so that libFuzzer sees Assimp's
 * and the loader's code run; with SY_FUZZ_ISOLATED=1 in the environment it runs in the import
 * process as applications load, which fuzz.sh uses to check that an input crashing inside
 * Assimp only fails the load. A loaded scene's clips are played at two times before it is committed. */
#include "fuzz_util.h"
#include "sy_anim.h"
#include "sy_assimp.h"
#include "sy_log.h"

#include <stddef.h>
#include <stdlib.h>

#ifndef FUZZ_ASSIMP_NAME
#define FUZZ_ASSIMP_NAME "fuzz.obj"
#endif

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size);

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size)
{
    sy_log_set_level(SY_LOG_ERROR); /* Assimp's notes on every input would dominate the time */
    sy_scene *s;
    if (sy_scene_create(&s, NULL) != SY_OK) return 0;
    sy_assimp_options o = {0};
    FUZZ_LIMITS(o);
    const char *iso = getenv("SY_FUZZ_ISOLATED");
    o.in_process = !(iso && iso[0] == '1');
    sy_assimp_info info = {0};
    sy_error err = {0};
    sy_result r = sy_assimp_load_memory(data, size, FUZZ_ASSIMP_NAME, fuzz_resource_dir(), s, &o, &info, &err);
    sy_assimp_info_free(&info);
    if (r == SY_OK) { /* the clips it made (sy_assimp_anim.c) played at two times */
        sy_scene_set_time(s, (sy_animation){0}, 0.5, NULL);
        sy_scene_set_time(s, (sy_animation){0}, 1e3, NULL);
    }
    FUZZ_COMMIT_AND_DESTROY(s, r);
    return 0;
}
