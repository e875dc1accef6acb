/* sy_loader_log.c — a loader's error naming the file, and its warnings (see sy_loader_log.h). */
#include "sy_loader_log.h"

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
