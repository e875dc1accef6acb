/* sy_loader_log.c — a loader's error naming the file, its warnings and its input (see sy_loader_log.h). */
#include "sy_loader_log.h"

#include "sy_file.h"
#include "sy_log.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

sy_result sy_loader_fail(sy_error *err, const char *file, sy_result code, const char *fmt, va_list ap)
{
    char msg[SY_ERROR_MESSAGE_MAX];
    vsnprintf(msg, sizeof msg, fmt, ap);
    return sy_error_set(err, code, "%s: %s", file, msg);
}

sy_result sy_loader_failf(sy_error *err, const char *file, sy_result code, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    sy_result r = sy_loader_fail(err, file, code, fmt, ap);
    va_end(ap);
    return r;
}

sy_result sy_loader_input(const char *path, const void *mem, size_t mem_size, size_t max_bytes, void **owned,
                          const void **data, size_t *size, sy_error *err)
{
    *owned = NULL, *data = NULL, *size = 0;
    if (!mem) {
        sy_result r = sy_file_read_all(path, max_bytes, owned, size, err); /* the message names the path */
        *data = *owned;
        return r;
    }
    if (mem_size > max_bytes)
        return sy_loader_failf(err, path, SY_ERR_LIMIT, "%zu bytes exceed the file size limit of %zu", mem_size, max_bytes);
    *data = mem, *size = mem_size;
    return SY_OK;
}

void sy_loader_warn(sy_loader_warnings w, const char *fmt, va_list ap)
{
    (*w.count)++;
    if (*w.stored >= w.max) return;
    if (!*w.list && !(*w.list = calloc(w.max, sizeof(char *)))) return;
    char msg[SY_ERROR_MESSAGE_MAX];
    vsnprintf(msg, sizeof msg, fmt, ap);
    char *copy = strdup(msg);
    if (copy) (*w.list)[(*w.stored)++] = copy;
}

void sy_loader_warnings_log(sy_loader_warnings w, const char *module, const char *item, const char *file)
{
    for (uint32_t i = 0; i < *w.stored; i++) sy_log(SY_LOG_WARNING, module, item, "%s", (*w.list)[i]);
    if (*w.count > *w.stored) sy_log(SY_LOG_WARNING, module, file, "%u more warnings not shown", *w.count - *w.stored);
}

void sy_loader_warnings_free(sy_loader_warnings w)
{
    for (uint32_t i = 0; *w.list && i < *w.stored; i++) free((*w.list)[i]);
    free(*w.list);
    *w.list = NULL;
    *w.stored = 0;
}

void sy_loader_warnf(sy_loader_warnings w, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    sy_loader_warn(w, fmt, ap);
    va_end(ap);
}
