/* test_util.h — tiny helpers shared by the tests in tests/formats: the check kit
 * (tests/support/sy_check.h; counted EXPECT checks, sy_check_finish), a private scratch directory
 * (tests/support/sy_scratch.h), and small file utilities. Test-only; header-only on purpose. */
#ifndef SY_TEST_UTIL_H
#define SY_TEST_UTIL_H

#include "../support/sy_check.h"
#include "../support/sy_scratch.h"
#include <dirent.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* snprintf into a char array, aborting on truncation (test paths must never be cut short). */
#define PATHF(buf, ...)                                                                  \
    do {                                                                                 \
        if (snprintf(buf, sizeof buf, __VA_ARGS__) >= (int)sizeof buf) {                \
            fprintf(stderr, "%s:%d: path too long\n", __FILE__, __LINE__);               \
            abort();                                                                     \
        }                                                                                \
    } while (0)

/* Number of entries in dir whose name contains needle. */
static inline int count_entries_containing(const char *dir, const char *needle)
{
    int n = 0;
    DIR *d = opendir(dir);
    if (!d) return -1;
    struct dirent *e;
    while ((e = readdir(d)) != NULL)
        if (strstr(e->d_name, needle)) ++n;
    closedir(d);
    return n;
}

static inline int path_exists(const char *p)
{
    struct stat st;
    return stat(p, &st) == 0;
}

static int write_bytes(const char *path, const void *data, size_t n)
{
    FILE *f = fopen(path, "wb");
    if (!f) return -1;
    size_t w = n ? fwrite(data, 1, n, f) : 0;
    int rc = (w == n && fclose(f) == 0) ? 0 : -1;
    if (w != n) fclose(f);
    return rc;
}

/* Reads a whole small file; caller frees. NULL on failure. */
static inline unsigned char *slurp(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    size_t cap = 1 << 16, len = 0;
    unsigned char *b = malloc(cap);
    for (;;) {
        if (!b) break;
        if (len == cap) {
            unsigned char *nb = realloc(b, cap * 2);
            if (!nb) {
                free(b);
                b = NULL;
                break;
            }
            b = nb;
            cap *= 2;
        }
        size_t r = fread(b + len, 1, cap - len, f);
        if (r == 0) break;
        len += r;
    }
    fclose(f);
    *n = len;
    return b;
}

#endif /* SY_TEST_UTIL_H */
