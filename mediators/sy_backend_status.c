/* sy_backend_status.c — a back-end's result code and message as core's sy_result and sy_error, its
 * warnings into sy_log (see sy_backend_status.h). */
#include "sy_backend_status.h"

#include "sy_log.h"

#include <stdarg.h>
#include <stdio.h>

sy_result sy_backend_fail(sy_error *err, int code, const char *fmt, ...)
{
    char msg[SY_ERROR_MESSAGE_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    return sy_error_set(err, code > SY_OK && code <= SY_ERR_SYSTEM ? (sy_result)code : SY_ERR_BACKEND, "%s", msg);
}

void sy_backend_warn(const char *module, const char *message)
{
    sy_log(SY_LOG_WARNING, module, NULL, "%s", message);
}
