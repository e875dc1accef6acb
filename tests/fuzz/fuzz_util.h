/* fuzz_util.h — shared by the libFuzzer targets in tests/fuzz: a per-process scratch file that
 * targets whose loader takes a path (glTF, EXR) write each input to. Test-only, header-only. */
#ifndef SY_FUZZ_UTIL_H
#define SY_FUZZ_UTIL_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* Writes data to "<scratch dir>/input<ext>" and returns that path (static storage; the directory
 * is created once per process under $TMPDIR or /tmp and removed at exit). NULL on failure. */
static char fuzz_dir_[512], fuzz_path_[600];

static void fuzz_cleanup_(void)
{
    if (fuzz_path_[0]) unlink(fuzz_path_);
    if (fuzz_dir_[0]) rmdir(fuzz_dir_);
}

static const char *fuzz_write_input(const unsigned char *data, size_t size, const char *ext)
{
    char *dir = fuzz_dir_, *path = fuzz_path_;
    const size_t dir_cap = sizeof fuzz_dir_, path_cap = sizeof fuzz_path_;
    if (!dir[0]) {
        const char *base = getenv("TMPDIR");
        snprintf(dir, dir_cap, "%s/sy_fuzz_XXXXXX", base && *base ? base : "/tmp");
        if (!mkdtemp(dir)) {
            dir[0] = '\0';
            return NULL;
        }
        atexit(fuzz_cleanup_);
    }
    if (path[0] && strcmp(strrchr(path, '/') + 6, ext) != 0) unlink(path); /* other extension */
    snprintf(path, path_cap, "%s/input%s", dir, ext);
    FILE *f = fopen(path, "wb");
    if (!f) return NULL;
    size_t w = size ? fwrite(data, 1, size, f) : 0;
    if (fclose(f) != 0 || w != size) return NULL;
    return path;
}

#endif /* SY_FUZZ_UTIL_H */
