/* sy_file.c — whole-file reading with a size limit and atomic temp-then-rename output (see sy_file.h). */
#define _DEFAULT_SOURCE /* realpath */
#include "sy_file.h"

#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
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
            /* Full: one more byte tells the end of the file (a regular file's stat size read whole:
             * no growth, the buffer stays the file's size; doubling it first took twice a large
             * file's bytes) from a file that grew past its stat size or is not a regular file, which
             * grows up to the limit ("exactly at the limit" is no error). */
            unsigned char probe;
            ssize_t n = read(fd, &probe, 1);
            if (n < 0 && errno == EINTR) continue;
            if (n < 0) {
                rc = sy_error_set(err, SY_ERR_IO, "%s: read failed: %s", path, strerror(errno));
                goto fail;
            }
            if (n == 0) break;
            if (cap >= max_bytes) {
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
            buf[len++] = probe;
            continue;
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

/* ---- model files stay in their folder ---- */

/* real path of dir ("" = "."), NULL when it does not resolve */
static char *real_dir(const char *dir)
{
    return realpath(dir && dir[0] ? dir : ".", NULL);
}

/* true when real lies inside root (both real paths): root itself or below root + '/' */
static bool path_inside(const char *real, const char *root)
{
    size_t n = strlen(root);
    if (n == 1 && root[0] == '/') return true;
    return strncmp(real, root, n) == 0 && (real[n] == '/' || real[n] == '\0');
}

sy_result sy_path_confine(const char *model, const char *uri, const char *path, const char *model_dir,
                          const char *const *roots, size_t root_count, char **real_out, sy_error *err)
{
    *real_out = NULL;
    bool is_file_uri = strncasecmp(uri, "file:", 5) == 0;
    bool absolute = uri[0] == '/' || is_file_uri;
    const char *target = uri[0] == '/' ? uri : path;
    if (is_file_uri) { /* file:///abs/path, file://localhost/abs/path, file:/abs/path */
        target = uri + 5;
        if (!strncmp(target, "//", 2)) {
            target += 2;
            if (!strncasecmp(target, "localhost/", 10)) target += 9;
        }
    }
    char *real = realpath(target, NULL);
    if (!real)
        return sy_error_set(err, errno == ENOENT ? SY_ERR_NOT_FOUND : SY_ERR_IO, "%s: '%s': cannot open %s: %s", model,
                            uri, target, strerror(errno));
    bool ok = false;
    if (!absolute) {
        char *base = real_dir(model_dir);
        ok = base && path_inside(real, base);
        free(base);
    }
    for (size_t i = 0; i < root_count && !ok; ++i) {
        char *base = real_dir(roots[i]);
        ok = base && path_inside(real, base);
        free(base);
    }
    if (!ok) {
        sy_result r = sy_error_set(err, SY_ERR_LIMIT,
                                   "%s: '%s' %s%s, outside the model's folder %s; refused (allow a folder with "
                                   "--allow-path DIR, or allowed_roots in the loader's options)",
                                   model, uri, absolute ? "is an absolute path or file: URI resolving to " : "resolves to ",
                                   real, model_dir && model_dir[0] ? model_dir : ".");
        free(real);
        return r;
    }
    *real_out = real;
    return SY_OK;
}

/* ---- the registry of temporary files in progress (for sy_atomic_file_cancel_all) ----
 * Every open temporary file's name is listed here from the moment it is created until it is renamed
 * or removed, both under the lock, so a cancel never misses one and never removes a finished file. */
static pthread_mutex_t g_tmp_lock = PTHREAD_MUTEX_INITIALIZER;
static const char **g_tmp;    /* borrowed from the handles' tmp_path */
static size_t g_tmp_n, g_tmp_cap;
static bool g_tmp_cancelled;  /* set once by sy_atomic_file_cancel_all; never cleared */

/* lock held: room for one more entry */
static bool tmp_reserve(void)
{
    if (g_tmp_n < g_tmp_cap) return true;
    size_t cap = g_tmp_cap ? g_tmp_cap * 2 : 8;
    const char **n = realloc(g_tmp, cap * sizeof *n);
    if (!n) return false;
    g_tmp = n;
    g_tmp_cap = cap;
    return true;
}

/* lock held */
static void tmp_unregister(const char *tmp)
{
    for (size_t i = 0; i < g_tmp_n; ++i)
        if (g_tmp[i] == tmp) {
            g_tmp[i] = g_tmp[--g_tmp_n];
            return;
        }
}

size_t sy_atomic_file_cancel_all(void)
{
    pthread_mutex_lock(&g_tmp_lock);
    g_tmp_cancelled = true;
    size_t n = 0;
    for (size_t i = 0; i < g_tmp_n; ++i)
        if (unlink(g_tmp[i]) == 0) n++;
    g_tmp_n = 0;
    pthread_mutex_unlock(&g_tmp_lock);
    return n;
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
    pthread_mutex_lock(&g_tmp_lock);
    if (g_tmp_cancelled || !tmp_reserve()) {
        bool cancelled = g_tmp_cancelled;
        pthread_mutex_unlock(&g_tmp_lock);
        free(tmp);
        free(final_path);
        return cancelled ? sy_error_set(err, SY_ERR_IO, "%s: not written: output was cancelled (interrupted)", path)
                         : sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", path);
    }
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
    if (fd >= 0) g_tmp[g_tmp_n++] = tmp;
    pthread_mutex_unlock(&g_tmp_lock);
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
        pthread_mutex_lock(&g_tmp_lock);
        unlink(tmp);
        tmp_unregister(tmp);
        pthread_mutex_unlock(&g_tmp_lock);
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
    if (af->tmp_path) {
        pthread_mutex_lock(&g_tmp_lock);
        unlink(af->tmp_path);
        tmp_unregister(af->tmp_path);
        pthread_mutex_unlock(&g_tmp_lock);
    }
    free(af->tmp_path);
    free(af->path);
    memset(af, 0, sizeof *af);
}

static _Atomic(sy_atomic_file_hook) g_commit_hook; /* test support: sy_atomic_file_set_commit_hook */

void sy_atomic_file_set_commit_hook(sy_atomic_file_hook hook)
{
    atomic_store(&g_commit_hook, hook);
}

sy_result sy_atomic_file_commit(sy_atomic_file *af, sy_error *err)
{
    if (!af || !af->fp || !af->tmp_path || !af->path) {
        sy_atomic_file_abort(af);
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "sy_atomic_file_commit: handle is not open");
    }
    sy_result rc = SY_OK;
    const char *path = af->path;
    sy_atomic_file_hook hook = atomic_load(&g_commit_hook);
    if (hook) hook(path, af->tmp_path);

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
    pthread_mutex_lock(&g_tmp_lock);
    bool cancelled = g_tmp_cancelled;
    int renamed = cancelled ? -1 : rename(af->tmp_path, path);
    int rename_errno = errno;
    if (renamed == 0) tmp_unregister(af->tmp_path);
    pthread_mutex_unlock(&g_tmp_lock);
    if (cancelled) {
        rc = sy_error_set(err, SY_ERR_IO, "%s: not written: output was cancelled (interrupted)", path);
        goto fail;
    }
    if (renamed != 0) {
        rc = sy_error_set(err, SY_ERR_IO, "%s: cannot rename the temporary file %s over it: %s", path, af->tmp_path,
                          strerror(rename_errno));
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
