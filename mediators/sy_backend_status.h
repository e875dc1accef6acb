/** @file
 * sy_backend_status.h — the one place where a back-end's status becomes core's: a back-end's result
 * code and message become a sy_result and sy_error, a back-end's warning becomes a sy_log message.
 *
 * The back-ends (backends/rt, backends/raster, backends/filters) may not include core headers, so
 * each has its own result enum; every one numbers the codes it shares with sy_result exactly like
 * sy_result (INVALID_ARGUMENT = 1, INVALID_HANDLE = 2, OUT_OF_MEMORY = 3, UNSUPPORTED = 6,
 * LIMIT = 7, 9 = the library underneath (Embree, OpenGL) failed, ...). A mediator states each code
 * it receives with SY_BACKEND_SAME_CODE (checked at compile time), so the cast in sy_backend_fail is
 * exact and no code collapses into another. Each back-end reports the message of a failure through
 * its error callback and keeps the last one per device (sy_rt_device_error, sy_gl_device_error); a
 * mediator passes that message here.
 *
 * Thread-safety: sy_backend_fail works on caller-owned memory; sy_backend_warn is sy_log's (any
 * thread). */
#ifndef SY_BACKEND_STATUS_H
#define SY_BACKEND_STATUS_H

#include "sy_common.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Compile-time check that a back-end's code has the number of core's code. */
#define SY_BACKEND_SAME_CODE(backend_code, core_code)                                                         \
    _Static_assert((int)(backend_code) == (int)(core_code), #backend_code " is numbered like " #core_code)

/** Records a back-end's failure in *err (if err is not NULL): the code cast to sy_result (a value
 * sy_result does not know, a back-end's bug, becomes SY_ERR_BACKEND) and the message
 * "MODULE: WHAT: MESSAGE" (module and what may be NULL: left out); returns the sy_result. Call
 * sites read `return sy_backend_fail(err, r, "raster", "material", st->gl_msg);`, the message being
 * what the device reported through its error callback. */
sy_result sy_backend_fail(sy_error *err, int code, const char *module, const char *what, const char *message);

/** Forwards a back-end's warning to sy_log (SY_LOG_WARNING) with module ("rt", "raster",
 * "filters"). Fits a back-end's log callback whose user pointer is the module name. */
void sy_backend_warn(const char *module, const char *message);

#ifdef __cplusplus
}
#endif
#endif /* SY_BACKEND_STATUS_H */
