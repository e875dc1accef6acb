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

#endif /* SY_FUZZ_UTIL_H */
