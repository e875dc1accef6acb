/* sy_file.c — whole-file reading with a size limit and atomic temp-then-rename output (see sy_file.h). */
#include "sy_file.h"

#include <errno.h>
#include <fcntl.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

/* ---- reading ---- */

sy_result sy_file_read_all(const char *path, size_t max_bytes, void **data_out, size_t *size_out,
                           sy_error *err)
{
    if (data_out) *data_out = NULL;
    if (size_out) *size_out = 0;
    if (!path || !data_out || !size_out)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "sy_file_read_all: path, data_out and size_out are required");

    if (max_bytes == SIZE_MAX) max_bytes = SIZE_MAX - 1; /* room for the terminating '\0' */

    int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0) {
        int e = errno;
        return sy_error_set(err, e == ENOENT ? SY_ERR_NOT_FOUND : SY_ERR_IO, "%s: cannot open: %s", path,
                            strerror(e));
    }

    sy_result rc = SY_OK;
    unsigned char *buf = NULL;
    size_t cap = 0, len = 0;

    struct stat st;
    if (fstat(fd, &st) != 0) {
        rc = sy_error_set(err, SY_ERR_IO, "%s: cannot stat: %s", path, strerror(errno));
        goto fail;
    }
    if (S_ISDIR(st.st_mode)) {
        rc = sy_error_set(err, SY_ERR_IO, "%s: is a directory, not a file", path);
        goto fail;
    }
    if (S_ISREG(st.st_mode)) {
        if (st.st_size < 0 || (uintmax_t)st.st_size > (uintmax_t)max_bytes) {
            rc = sy_error_set(err, SY_ERR_LIMIT, "%s: file is %jd bytes, more than the limit of %zu bytes", path,
                              (intmax_t)st.st_size, max_bytes);
            goto fail;
        }
        cap = (size_t)st.st_size;
    }
    if (cap < 4096) cap = max_bytes < 4096 ? max_bytes : 4096;

    size_t alloc = cap + 1; /* cap <= max_bytes < SIZE_MAX */
    buf = malloc(alloc);
    if (!buf) {
        rc = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s: cannot allocate %zu bytes", path, alloc);
        goto fail;
    }

    for (;;) {
        if (len == cap) {
            /* The file grew past its stat size or is not a regular file: grow up to the limit. */
            if (cap >= max_bytes) {
                /* Probe one more byte to tell "exactly at the limit" from "over the limit". */
                unsigned char probe;
                ssize_t n = read(fd, &probe, 1);
                if (n < 0 && errno == EINTR) continue;
                if (n < 0) {
                    rc = sy_error_set(err, SY_ERR_IO, "%s: read failed: %s", path, strerror(errno));
                    goto fail;
                }
                if (n == 0) break;
                rc = sy_error_set(err, SY_ERR_LIMIT, "%s: file is larger than the limit of %zu bytes", path,
                                  max_bytes);
                goto fail;
            }
            size_t ncap = cap > max_bytes / 2 ? max_bytes : cap * 2;
            if (ncap == 0) ncap = max_bytes < 4096 ? max_bytes : 4096;
            unsigned char *nbuf = realloc(buf, ncap + 1);
            if (!nbuf) {
                rc = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s: cannot allocate %zu bytes", path, ncap + 1);
                goto fail;
            }
            buf = nbuf;
            cap = ncap;
        }
        ssize_t n = read(fd, buf + len, cap - len);
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) {
            rc = sy_error_set(err, SY_ERR_IO, "%s: read failed: %s", path, strerror(errno));
            goto fail;
        }
        if (n == 0) break;
        len += (size_t)n;
    }
    close(fd);
    buf[len] = '\0';
    *data_out = buf;
    *size_out = len;
    return SY_OK;

fail:
    free(buf);
    close(fd);
    return rc;
}

/* ---- atomic output ---- */

static uint64_t splitmix64(uint64_t *state)
{
    uint64_t z = (*state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

/* Directory part of path ("." when there is none), newly allocated. */
static char *dir_of(const char *path)
{
    const char *slash = strrchr(path, '/');
    if (!slash) {
        char *d = malloc(2);
        if (d) memcpy(d, ".", 2);
        return d;
    }
    size_t n = (size_t)(slash - path);
    if (n == 0) n = 1; /* "/file" -> "/" */
    char *d = malloc(n + 1);
    if (!d) return NULL;
    memcpy(d, path, n);
    d[n] = '\0';
    return d;
}

sy_result sy_atomic_file_begin(const char *path, sy_atomic_file *af, sy_error *err)
{
    if (af) memset(af, 0, sizeof *af);
    if (!path || !af || !*path)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "sy_atomic_file_begin: path and handle are required");

    static const char suffix_chars[] = "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789";
    static const char tag[] = ".tmp-";
    enum { RANDOM_CHARS = 6, MAX_TRIES = 100 };

    size_t plen = strlen(path);
    size_t tlen = plen + sizeof tag - 1 + RANDOM_CHARS;
    char *tmp = malloc(tlen + 1);
    char *final_path = malloc(plen + 1);
    if (!tmp || !final_path) {
        free(tmp);
        free(final_path);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s: cannot allocate the temporary file name", path);
    }
    memcpy(final_path, path, plen + 1);
    memcpy(tmp, path, plen);
    memcpy(tmp + plen, tag, sizeof tag - 1);
    tmp[tlen] = '\0';

    /* Name entropy: time, pid and the handle's address; O_EXCL makes collisions harmless. Unlike
     * mkstemp (mode 0600), open() with 0666 lets the umask decide the final file's permissions. */
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    uint64_t state = (uint64_t)ts.tv_nsec ^ ((uint64_t)ts.tv_sec << 30) ^ ((uint64_t)getpid() << 12) ^
                     (uint64_t)(uintptr_t)af;
    int fd = -1;
    int e = 0;
    for (int attempt = 0; attempt < MAX_TRIES; ++attempt) {
        uint64_t r = splitmix64(&state);
        for (int i = 0; i < RANDOM_CHARS; ++i) {
            tmp[plen + sizeof tag - 1 + (size_t)i] = suffix_chars[r % (sizeof suffix_chars - 1)];
            r /= sizeof suffix_chars - 1;
        }
        fd = open(tmp, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (fd >= 0) break;
        e = errno;
        if (e != EEXIST && e != EINTR) break;
    }
    if (fd < 0) {
        free(tmp);
        free(final_path);
        if (e == EEXIST)
            return sy_error_set(err, SY_ERR_IO, "%s: cannot create a unique temporary file after %d tries", path,
                                (int)MAX_TRIES);
        return sy_error_set(err, e == ENOENT ? SY_ERR_NOT_FOUND : SY_ERR_IO,
                            "%s: cannot create the temporary output file: %s", path, strerror(e));
    }
    FILE *fp = fdopen(fd, "wb");
    if (!fp) {
        e = errno;
        close(fd);
        unlink(tmp);
        free(tmp);
        free(final_path);
        return sy_error_set(err, SY_ERR_IO, "%s: cannot open a stream on the temporary file: %s", path, strerror(e));
    }
    af->fp = fp;
    af->fd = fd;
    af->path = final_path;
    af->tmp_path = tmp;
    return SY_OK;
}

void sy_atomic_file_abort(sy_atomic_file *af)
{
    if (!af) return;
    if (af->fp) fclose(af->fp);
    if (af->tmp_path) unlink(af->tmp_path);
    free(af->tmp_path);
    free(af->path);
    memset(af, 0, sizeof *af);
}

sy_result sy_atomic_file_commit(sy_atomic_file *af, sy_error *err)
{
    if (!af || !af->fp || !af->tmp_path || !af->path) {
        sy_atomic_file_abort(af);
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "sy_atomic_file_commit: handle is not open");
    }
    sy_result rc = SY_OK;
    const char *path = af->path;

    if (fflush(af->fp) != 0 || ferror(af->fp)) {
        rc = sy_error_set(err, SY_ERR_IO, "%s: writing the temporary file %s failed: %s", path, af->tmp_path,
                          strerror(errno));
        goto fail;
    }
    if (fsync(af->fd) != 0) {
        rc = sy_error_set(err, SY_ERR_IO, "%s: fsync of the temporary file %s failed: %s", path, af->tmp_path,
                          strerror(errno));
        goto fail;
    }
    FILE *fp = af->fp;
    af->fp = NULL; /* fclose releases the stream even when it reports an error */
    if (fclose(fp) != 0) {
        rc = sy_error_set(err, SY_ERR_IO, "%s: closing the temporary file %s failed: %s", path, af->tmp_path,
                          strerror(errno));
        goto fail;
    }
    if (rename(af->tmp_path, path) != 0) {
        rc = sy_error_set(err, SY_ERR_IO, "%s: cannot rename the temporary file %s over it: %s", path, af->tmp_path,
                          strerror(errno));
        goto fail;
    }
    /* The content is durable; make the rename durable too. Best effort: some file systems refuse
     * fsync on directories, and the file is already complete and in place either way. */
    char *dir = dir_of(path);
    if (dir) {
        int dfd = open(dir, O_RDONLY | O_CLOEXEC);
        if (dfd >= 0) {
            (void)fsync(dfd);
            close(dfd);
        }
        free(dir);
    }
    free(af->tmp_path);
    free(af->path);
    memset(af, 0, sizeof *af);
    return SY_OK;

fail:
    sy_atomic_file_abort(af);
    return rc;
}
