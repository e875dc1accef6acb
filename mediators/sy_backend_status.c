/* sy_backend_status.c — a back-end's result code and message as core's sy_result and sy_error, its
 * warnings into sy_log (see sy_backend_status.h). */
#include "sy_backend_status.h"

#include "sy_log.h"

sy_result sy_backend_fail(sy_error *err, int code, const char *module, const char *what, const char *message)
{
    sy_result r = code > SY_OK && code <= SY_ERR_SYSTEM ? (sy_result)code : SY_ERR_BACKEND; /* SY_ERR_SYSTEM: core's last */
    return sy_error_set(err, r, "%s%s%s%s%s", module ? module : "", module ? ": " : "", what ? what : "", what ? ": " : "",
                        message ? message : "");
}

void sy_backend_warn(const char *module, const char *message)
{
    sy_log(SY_LOG_WARNING, module, NULL, "%s", message);
}
