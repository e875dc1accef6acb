/* gltf_files.h — the glTF tests' files: the test-data folder they are given, scratch folders
 * (tests/support/sy_scratch.h), whole-file reading and writing for the tests that write variants of
 * sample files (Draco, meshopt). Test-only;
 * header-only on purpose. */
#ifndef SY_TEST_GLTF_FILES_H
#define SY_TEST_GLTF_FILES_H

#include "../support/sy_scratch.h"
#include "sy_file.h"

#include <stdio.h>
#include <stdlib.h>

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
