/** @file
 * sy_mediators.h — registers every mediator class built into this library in core's
 * registry: the build generates the list from SY_BACKENDS and each folder's sy_add_mediator(). Applications call it once at start-up.
 * Thread-safety: safe to call repeatedly and from any thread (registration is idempotent). */
#ifndef SY_MEDIATORS_H
#define SY_MEDIATORS_H

#include "sy_common.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Registers every built-in mediator class. */
sy_result sy_mediators_register_builtin(sy_error *err);

#ifdef __cplusplus
}
#endif
#endif /* SY_MEDIATORS_H */
