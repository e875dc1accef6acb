/* sy_scratch.h — the tests' private scratch folders: made fresh under $TMPDIR (/tmp without it) as
 * sy_TAG_XXXXXX, removed with all they hold at the end. Test-only, header-only; main thread only. */
#ifndef SY_TEST_SY_SCRATCH_H
#define SY_TEST_SY_SCRATCH_H

#include <dirent.h>
#include <sys/stat.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* Creates a fresh scratch folder $TMPDIR/sy_TAG_XXXXXX; its path in buf (n bytes). Ends the test
 * (exit 1) with the reason when it cannot. */
static inline void make_scratch_dir(char *buf, size_t n, const char *tag)
{
    const char *base = getenv("TMPDIR");
    if (!base || !*base) base = "/tmp";
    if (snprintf(buf, n, "%s/sy_%s_XXXXXX", base, tag) >= (int)n || !mkdtemp(buf)) {
        fprintf(stderr, "cannot create a scratch directory %s: %s\n", buf, strerror(errno));
        exit(1);
    }
}

/* Removes dir and everything under it (the assimp tests nest folders in theirs); symbolic links
 * are removed, not followed. */
static inline void remove_scratch_dir(const char *dir)
{
    DIR *d = opendir(dir);
    if (d) {
        struct dirent *e;
        char p[4096];
        struct stat st;
        while ((e = readdir(d)) != NULL) {
            if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0) continue;
            if (snprintf(p, sizeof p, "%s/%s", dir, e->d_name) >= (int)sizeof p) continue;
            if (lstat(p, &st) == 0 && S_ISDIR(st.st_mode)) remove_scratch_dir(p);
            else unlink(p);
        }
        closedir(d);
    }
    rmdir(dir);
}

#endif /* SY_TEST_SY_SCRATCH_H */
