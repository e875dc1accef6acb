/* sy_x3d_url.c — the url fields of an X3D file (ImageTexture, Inline): MFString values, relative urls
 * joined to the file's folder, and the confinement of what they name (only regular files inside the
 * model's folder or the allowed roots are ever read). */
#define _DEFAULT_SOURCE
#include "sy_x3d_internal.h"

#include "sy_file.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* Next string of an MFString attribute ('"a" "b"' or a bare word); returns false at the end. */
bool x3d_next_mfstring(const char **p, char *out, size_t cap)
{
    const char *s = *p;
    while (*s == ' ' || *s == '\t' || *s == '\n' || *s == '\r' || *s == ',') s++;
    if (!*s) return false;
    size_t n = 0;
    if (*s == '"') {
        s++;
        while (*s && *s != '"') {
            if (*s == '\\' && s[1]) s++;
            if (n + 1 < cap) out[n++] = *s;
            s++;
        }
        if (*s == '"') s++;
    } else {
        while (*s && *s != ' ' && *s != '\t' && *s != '\n' && *s != '\r') {
            if (n + 1 < cap) out[n++] = *s;
            s++;
        }
    }
    out[n] = '\0';
    *p = s;
    return true;
}

bool x3d_is_remote(const char *u) { return strstr(u, "://") != NULL; }

/* URLs in a file are untrusted: only regular files are read (no devices, FIFOs, directories),
 * so a reference cannot block the load or feed it endless data. */
bool x3d_regular_file(const char *path, char *why, size_t cap)
{
    struct stat st;
    if (stat(path, &st) != 0) {
        snprintf(why, cap, "%.400s: cannot open: %s", path, strerror(errno));
        return false;
    }
    if (!S_ISREG(st.st_mode)) {
        snprintf(why, cap, "%.400s: not a regular file", path);
        return false;
    }
    return true;
}

/* Resolves a relative URL against F->dir (percent-escapes and fragments are not interpreted). */
bool x3d_resolve_url(const xfile *F, const char *u, char *out, size_t cap)
{
    if (u[0] == '/' || !F->dir[0]) return (size_t)snprintf(out, cap, "%s", u) < cap;
    return (size_t)snprintf(out, cap, "%s%s", F->dir, u) < cap;
}

/* Model files stay in their folder: the file that url u (joined: path) names must lie in the
 * top-level model's folder or in allowed_roots (sy_path_confine). Returns SY_OK with out = the real
 * path to read, SY_ERR_NOT_FOUND (the caller tries the next url), or the refusal in L->err (the
 * load fails: a file outside the tree is never read). */
sy_result x3d_confine_url(loader *L, const xfile *F, const xmlNode *el, const char *u, const char *path, char *out,
                          size_t cap)
{
    char *real = NULL;
    sy_error e = {0};
    sy_result r = sy_path_confine("url", u, path, L->model_dir, L->opt.allowed_roots, L->opt.allowed_root_count,
                                  &real, &e);
    if (r == SY_OK && strlen(real) >= cap) r = SY_ERR_NOT_FOUND;
    if (r == SY_OK) memcpy(out, real, strlen(real) + 1);
    free(real);
    if (r != SY_OK && r != SY_ERR_NOT_FOUND) {
        L->err = e;
        sy_error_prefix(&L->err, "%s:%d: %s", F->path, x3d_line_of(el), x3d_ename(el));
    }
    return r;
}
