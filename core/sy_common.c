/* sy_common.c — result strings, error formatting, clock and terminal checks (see sy_common.h). */
#include "sy_common.h"

#include <stdarg.h>
#include <stdlib.h>
#include <stdio.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

const char *sy_result_str(sy_result r)
{
    switch (r) {
    case SY_OK: return "ok";
    case SY_ERR_INVALID_ARGUMENT: return "invalid argument";
    case SY_ERR_INVALID_HANDLE: return "invalid handle";
    case SY_ERR_OUT_OF_MEMORY: return "out of memory";
    case SY_ERR_IO: return "i/o error";
    case SY_ERR_PARSE: return "malformed input";
    case SY_ERR_UNSUPPORTED: return "unsupported";
    case SY_ERR_LIMIT: return "limit exceeded";
    case SY_ERR_NOT_FOUND: return "not found";
    case SY_ERR_BACKEND: return "back-end failure";
    case SY_ERR_PROTOCOL: return "protocol violation";
    case SY_ERR_INVALID_OPERATION: return "invalid operation";
    case SY_ERR_CANCELLED: return "cancelled";
    case SY_ERR_SYSTEM: return "system error";
    default: return "unknown error";
    }
}

sy_result sy_error_set(sy_error *err, sy_result code, const char *fmt, ...)
{
    if (err) {
        err->code = code;
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err->message, sizeof err->message, fmt, ap);
        va_end(ap);
    }
    return code;
}

void sy_error_prefix(sy_error *err, const char *fmt, ...)
{
    if (!err) return;
    char prefix[SY_ERROR_MESSAGE_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(prefix, sizeof prefix, fmt, ap);
    va_end(ap);
    char old[SY_ERROR_MESSAGE_MAX];
    memcpy(old, err->message, sizeof old);
    old[sizeof old - 1] = '\0';
    size_t n = strlen(prefix);
    if (n > sizeof err->message - 3) n = sizeof err->message - 3;
    memcpy(err->message, prefix, n);
    err->message[n] = ':';
    err->message[n + 1] = ' ';
    size_t room = sizeof err->message - (n + 2) - 1;
    size_t m = strlen(old);
    if (m > room) m = room;
    memcpy(err->message + n + 2, old, m);
    err->message[n + 2 + m] = '\0';
}

bool sy_name_in_list(const char *name, const char *list, char sep)
{
    size_t n = strlen(name);
    for (const char *p = list; *p;) {
        const char *e = strchr(p, sep);
        size_t k = e ? (size_t)(e - p) : strlen(p);
        if (k == n && !strncmp(p, name, n)) return true;
        if (!e) break;
        p = e + 1;
    }
    return false;
}

bool sy_array_reserve(void *items, size_t count, size_t *capacity, size_t elem, size_t first)
{
    if (count < *capacity) return true;
    size_t nc = *capacity ? *capacity * 2 : first, bytes;
    void *p;
    memcpy(&p, items, sizeof p); /* items is a T **: its pointer read and written as bytes */
    if (nc <= *capacity || !sy_size_mul(nc, elem, &bytes) || !(p = realloc(p, bytes))) return false;
    memcpy(items, &p, sizeof p);
    *capacity = nc;
    return true;
}

int sy_u32_pair_cmp(const void *a, const void *b)
{
    const sy_u32_pair *x = a, *y = b;
    if (x->key != y->key) return x->key < y->key ? -1 : 1;
    return x->value < y->value ? -1 : x->value > y->value;
}

bool sy_u32_push(uint32_t **items, uint32_t *count, uint32_t *capacity, uint32_t v)
{
    if (*count == *capacity) {
        uint32_t nc = *capacity ? *capacity * 2 : 4;
        uint32_t *ni = realloc(*items, sizeof *ni * nc);
        if (!ni) return false;
        *items = ni;
        *capacity = nc;
    }
    (*items)[(*count)++] = v;
    return true;
}

double sy_time_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

bool sy_is_terminal(int fd) { return isatty(fd) == 1; }

#ifndef SY_VERSION_STRING
#error "SY_VERSION_STRING comes from the project version (core/CMakeLists.txt)"
#endif
const char *sy_version(void) { return SY_VERSION_STRING; }
