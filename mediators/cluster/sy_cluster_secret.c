/* sy_cluster_secret.c — key material from files: the cluster's shared secret
 * (sy_cluster_secret_load: a file only its owner may read, or $SY_CLUSTER_SECRET) and the PEM
 * certificate and key a TLS server listens with. */
#include "sy_cluster_internal.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

sy_result sy_cluster_secret_load(const char *path, uint8_t **out, size_t *len, sy_error *err)
{
    *out = NULL;
    *len = 0;
    uint8_t *buf = NULL;
    size_t n = 0;
    if (!path) {
        const char *env = getenv("SY_CLUSTER_SECRET");
        if (!env) return SY_OK;
        n = strlen(env);
        buf = malloc(n + 1);
        if (!buf) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "secret: out of memory");
        memcpy(buf, env, n);
        path = "$SY_CLUSTER_SECRET";
    } else {
        FILE *f = fopen(path, "rb");
        if (!f) return sy_error_set(err, SY_ERR_IO, "%s: cannot open secret file: %s", path, strerror(errno));
        struct stat st;
        if (fstat(fileno(f), &st) == 0 && (st.st_mode & 077)) {
            fclose(f);
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                                "%s: secret file is readable by group or others (chmod 600 it)", path);
        }
        buf = malloc(4097);
        if (!buf) {
            fclose(f);
            return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "secret: out of memory");
        }
        n = fread(buf, 1, 4097, f);
        fclose(f);
        if (n > 4096) {
            free(buf);
            return sy_error_set(err, SY_ERR_LIMIT, "%s: secret longer than 4096 bytes", path);
        }
    }
    while (n && (buf[n - 1] == '\n' || buf[n - 1] == '\r')) --n;
    if (n == 0) {
        free(buf);
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: the secret is empty", path);
    }
    *out = buf;
    *len = n;
    return SY_OK;
}

/* A PEM file (certificate or key) as a string, at most 1 MiB. */
sy_result sy_clu_read_pem(const char *path, char **out, sy_error *err)
{
    *out = NULL;
    FILE *f = fopen(path, "rb");
    if (!f) return sy_error_set(err, SY_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    char *buf = malloc((1u << 20) + 1);
    size_t n = buf ? fread(buf, 1, 1u << 20, f) : 0;
    bool more = buf && fgetc(f) != EOF;
    fclose(f);
    if (!buf) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", path);
    if (more || n == 0 || memchr(buf, 0, n)) {
        free(buf);
        return sy_error_set(err, SY_ERR_PARSE, "%s: not a PEM file (empty, binary or over 1 MiB)", path);
    }
    buf[n] = 0;
    *out = buf;
    return SY_OK;
}
