/* gltf_files.h — the glTF tests' files: the test-data folder they are given, whole-file reading and
 * writing for the tests that write variants of sample files (Draco, meshopt). Test-only;
 * header-only on purpose. */
#ifndef SY_TEST_GLTF_FILES_H
#define SY_TEST_GLTF_FILES_H

#include "sy_file.h"

#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

/* The test-data folder, the test's one argument (ctest passes ../shared/testdata); without it the
 * usage line and exit status 2. */
static inline const char *testdata_arg(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: %s TESTDATA_DIR\n", argv[0]);
        exit(2);
    }
    return argv[1];
}

/* A new scratch folder $TMPDIR/NAME_XXXXXX (/tmp without TMPDIR) into buf, which must hold at least
 * 64 characters more than $TMPDIR; ends the test (exit 1) when it cannot be made. */
static inline void scratch_dir(const char *name, char *buf, size_t size)
{
    snprintf(buf, size, "%s/%s_XXXXXX", getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp", name);
    if (!mkdtemp(buf)) {
        perror("mkdtemp");
        exit(1);
    }
}

/* The whole file (NUL-terminated) through the library's reader (malloc()ed); NULL when it cannot
 * be read. */
static inline void *read_all(const char *path, size_t *n)
{
    void *data = NULL;
    return sy_file_read_all(path, (size_t)1 << 30, &data, n, NULL) == SY_OK ? data : NULL;
}

/* Writes n bytes to path; ends the test (exit 1) when it cannot. */
static inline void write_all(const char *path, const void *data, size_t n)
{
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(data, 1, n, f) != n) {
        fprintf(stderr, "cannot write %s\n", path);
        exit(1);
    }
    fclose(f);
}

#endif /* SY_TEST_GLTF_FILES_H */
