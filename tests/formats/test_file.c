/* test_file.c — sy_file: size-limited whole-file reads and atomic temp-then-rename output. */
#include "sy_file.h"

#include "test_util.h"

#include <malloc.h>

static void test_read_all(const char *dir)
{
    char p[4096];
    PATHF(p, "%s/data.bin", dir);
    const char content[] = "switchyard\0binary\x01\x02";
    EXPECT_MSG(write_bytes(p, content, sizeof content) == 0, "cannot write %s", p);

    void *data = NULL;
    size_t n = 0;
    sy_error err = {0};
    EXPECT_MSG(sy_file_read_all(p, 1 << 20, &data, &n, &err) == SY_OK, "%s", err.message);
    EXPECT_MSG(n == sizeof content, "size %zu", n);
    EXPECT_MSG(data && memcmp(data, content, sizeof content) == 0, "content differs");
    EXPECT_MSG(data && ((const char *)data)[n] == '\0', "not NUL-terminated");
    free(data);

    /* A regular file is read into a buffer of its size (+ 1 for the NUL): the buffer was doubled
     * to look for more bytes after the stat size, so a 300 MB file took 600 MB of memory. */
    {
        char bp[4096];
        PATHF(bp, "%s/big.bin", dir);
        enum { BIG = 300000 };
        char *big = calloc(BIG, 1);
        EXPECT_MSG(big && write_bytes(bp, big, BIG) == 0, "cannot write %s", bp);
        free(big);
        EXPECT_MSG(sy_file_read_all(bp, 1 << 20, &data, &n, &err) == SY_OK && n == BIG, "%s", err.message);
        EXPECT_MSG(data && malloc_usable_size(data) < BIG + BIG / 2, "a %d-byte file took a %zu-byte buffer", BIG,
                   data ? malloc_usable_size(data) : 0);
        free(data);
    }

    /* Exactly at the limit is fine; one byte below is refused with SY_ERR_LIMIT, naming the file. */
    EXPECT_MSG(sy_file_read_all(p, sizeof content, &data, &n, &err) == SY_OK, "%s", err.message);
    free(data);
    sy_result r = sy_file_read_all(p, sizeof content - 1, &data, &n, &err);
    EXPECT_MSG(r == SY_ERR_LIMIT, "got %d", (int)r);
    EXPECT_MSG(data == NULL && n == 0, "outputs not cleared");
    EXPECT_MSG(strstr(err.message, p) != NULL, "message does not name the file: %s", err.message);

    /* Empty file: SY_OK, size 0, a valid (freeable, terminated) buffer. */
    PATHF(p, "%s/empty.bin", dir);
    EXPECT_MSG(write_bytes(p, "", 0) == 0, "cannot write %s", p);
    EXPECT_MSG(sy_file_read_all(p, 0, &data, &n, &err) == SY_OK, "%s", err.message);
    EXPECT_MSG(data != NULL && n == 0 && ((const char *)data)[0] == '\0', "empty file handling");
    free(data);

    /* Missing file and directory. */
    PATHF(p, "%s/missing.bin", dir);
    r = sy_file_read_all(p, 100, &data, &n, &err);
    EXPECT_MSG(r == SY_ERR_NOT_FOUND, "got %d", (int)r);
    EXPECT_MSG(strstr(err.message, p) != NULL, "message does not name the file: %s", err.message);
    r = sy_file_read_all(dir, 100, &data, &n, &err);
    EXPECT_MSG(r == SY_ERR_IO && data == NULL, "directory: got %d", (int)r);
    EXPECT_MSG(strstr(err.message, dir) != NULL, "message does not name the directory: %s", err.message);

    /* Non-regular file larger than the limit: the growth path must also stop at the limit. */
    if (path_exists("/dev/zero")) {
        r = sy_file_read_all("/dev/zero", 10000, &data, &n, &err);
        EXPECT_MSG(r == SY_ERR_LIMIT && data == NULL, "/dev/zero: got %d", (int)r);
    }
}

static void test_atomic(const char *dir)
{
    char p[4096];
    sy_error err = {0};
    sy_atomic_file af = {0};

    /* Commit: content in place, no temporary left, mode 0666 & ~umask (umask 022 set in main). */
    PATHF(p, "%s/out.txt", dir);
    EXPECT_MSG(sy_atomic_file_begin(p, &af, &err) == SY_OK, "%s", err.message);
    EXPECT_MSG(af.fp && af.tmp_path && strstr(af.tmp_path, ".tmp-"), "handle not filled");
    EXPECT_MSG(af.tmp_path && strncmp(af.tmp_path, p, strlen(p)) == 0, "temp not beside the target: %s", af.tmp_path);
    EXPECT_MSG(!path_exists(p), "target exists before commit");
    fputs("first", af.fp);
    EXPECT_MSG(sy_atomic_file_commit(&af, &err) == SY_OK, "%s", err.message);
    EXPECT_MSG(af.fp == NULL && af.tmp_path == NULL, "handle not released");
    size_t n = 0;
    unsigned char *b = slurp(p, &n);
    EXPECT_MSG(b && n == 5 && memcmp(b, "first", 5) == 0, "committed content");
    free(b);
    EXPECT_MSG(count_entries_containing(dir, ".tmp-") == 0, "temporary file left behind");
    struct stat st;
    EXPECT_MSG(stat(p, &st) == 0 && (st.st_mode & 0777) == 0644, "mode %o", (unsigned)(st.st_mode & 0777));

    /* Abort: existing target untouched, temporary removed. */
    EXPECT_MSG(sy_atomic_file_begin(p, &af, &err) == SY_OK, "%s", err.message);
    fputs("second, much longer content", af.fp);
    fflush(af.fp);
    EXPECT_MSG(count_entries_containing(dir, ".tmp-") == 1, "temporary file not visible during write");
    sy_atomic_file_abort(&af);
    sy_atomic_file_abort(&af); /* idempotent */
    b = slurp(p, &n);
    EXPECT_MSG(b && n == 5 && memcmp(b, "first", 5) == 0, "target changed by an aborted write");
    free(b);
    EXPECT_MSG(count_entries_containing(dir, ".tmp-") == 0, "temporary file left after abort");

    /* A failing commit (target is a non-empty directory: rename fails) removes the temporary
     * and leaves the target as it was. */
    char sub[4096], inner[4200];
    PATHF(sub, "%s/target_dir", dir);
    EXPECT_MSG(mkdir(sub, 0755) == 0, "mkdir");
    PATHF(inner, "%s/keep", sub);
    EXPECT_MSG(write_bytes(inner, "k", 1) == 0, "write");
    EXPECT_MSG(sy_atomic_file_begin(sub, &af, &err) == SY_OK, "%s", err.message);
    fputs("data", af.fp);
    sy_result r = sy_atomic_file_commit(&af, &err);
    EXPECT_MSG(r == SY_ERR_IO, "commit over a directory: got %d", (int)r);
    EXPECT_MSG(strstr(err.message, sub) != NULL, "message does not name the target: %s", err.message);
    EXPECT_MSG(count_entries_containing(dir, ".tmp-") == 0, "temporary file left after a failed commit");
    EXPECT_MSG(path_exists(inner), "target directory damaged");
    unlink(inner);
    rmdir(sub);

    /* Non-existent directory: error naming the path, nothing created. */
    PATHF(p, "%s/no/such/dir/out.txt", dir);
    r = sy_atomic_file_begin(p, &af, &err);
    EXPECT_MSG(r != SY_OK, "begin in a missing directory succeeded");
    EXPECT_MSG(strstr(err.message, p) != NULL, "message does not name the path: %s", err.message);
    EXPECT_MSG(af.fp == NULL && af.tmp_path == NULL, "handle not zeroed on failure");
    sy_atomic_file_abort(&af); /* harmless on a zeroed handle */
    EXPECT_MSG(sy_atomic_file_commit(&af, &err) == SY_ERR_INVALID_ARGUMENT, "commit on a closed handle");
}

int main(void)
{
    umask(022);
    char dir[4096];
    make_scratch_dir(dir, sizeof dir, "file");
    test_read_all(dir);
    test_atomic(dir);
    remove_scratch_dir(dir);
    return sy_check_finish("test_file");
}
