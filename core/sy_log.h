/** @file
 * sy_log.h — the one log callback of Switchyard: every warning, note and error that a layer above
 * the back-ends reports (core, formats, mediators, the cluster, the sy tool) goes through sy_log().
 * Back-ends (backends/) keep their own small callbacks; their mediators forward into sy_log().
 *
 * A message carries a level, the module that raised it ("gltf", "x3d", "rt", "raster",
 * "cluster.server", "cluster.client", "sy", ...), an optional item (the file, peer or object it is
 * about: "scene.gltf", "tcp://10.0.0.2:5791", "light 3"; NULL when there is none) and the text.
 *
 * The default callback (sy_log_stderr) writes one line to stderr:
 *     sy: warning: [item: ]message
 * with the level word "error", "warning", "note" or "debug". An application installs its own with
 * sy_log_set_callback() and chooses how much it receives with sy_log_set_level() (default
 * SY_LOG_NOTE: errors, warnings and notes; `sy -q` sets SY_LOG_ERROR, `sy -v` SY_LOG_DEBUG).
 *
 * Ownership: module, item and message passed to a callback are valid only during the call.
 * Thread-safety: every function here may be called from any thread at any time. The level is an
 * atomic (a filtered message costs one load and is never formatted). Calls of the callback are
 * serialised by a lock: a callback needs no lock of its own, lines never interleave, and once
 * sy_log_set_callback() returns no call of the previous callback is in progress. A callback may call
 * sy_log() (that message goes to sy_log_stderr, not back into the callback) but must not call
 * sy_log_set_callback(). This is process-wide state, like the mediator registry. */
#ifndef SY_LOG_H
#define SY_LOG_H

#include <stdarg.h>
#include <stdbool.h>

#ifdef __cplusplus
extern "C" {
#endif

/** Severity of a log message; a lower value is more severe. */
typedef enum sy_log_level {
    SY_LOG_ERROR = 0,   /**< an operation failed */
    SY_LOG_WARNING = 1, /**< something was skipped, repaired or clamped; the result may differ from the input */
    SY_LOG_NOTE = 2,    /**< what happened that a user may want to know (default level) */
    SY_LOG_INFO = SY_LOG_NOTE,
    SY_LOG_DEBUG = 3    /**< details for finding a problem */
} sy_log_level;

/** Receives one message (no trailing newline). item may be NULL; module is never NULL. */
typedef void (*sy_log_fn)(void *user, sy_log_level level, const char *module, const char *item /* file, peer or object, may be NULL */,
                          const char *message);

/** Installs fn (NULL: the default, sy_log_stderr) with its user pointer for the whole process. */
void sy_log_set_callback(sy_log_fn fn, void *user);

/** Messages above level (less severe) are dropped before formatting. Errors are always delivered;
 * a level beyond SY_LOG_DEBUG is taken as SY_LOG_DEBUG. */
void sy_log_set_level(sy_log_level level);
/** The current level. */
sy_log_level sy_log_get_level(void);

/** true when a message of this level would be delivered (to skip expensive preparation). */
bool sy_log_enabled(sy_log_level level);

/** Formats the message (printf-style) and hands it to the callback if the level passes. module NULL
 * is taken as "sy". */
void sy_log(sy_log_level level, const char *module, const char *item, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;
/** sy_log with a va_list. */
void sy_logv(sy_log_level level, const char *module, const char *item, const char *fmt, va_list ap);

/** The default callback: "sy: LEVEL: [item: ]message\n" on stderr in one write (user is unused).
 * Public so that an application's callback can pass some messages on to it. */
void sy_log_stderr(void *user, sy_log_level level, const char *module, const char *item, const char *message);

/** "error", "warning", "note", "debug" (static storage). */
const char *sy_log_level_name(sy_log_level level);

#ifdef __cplusplus
}
#endif
#endif /* SY_LOG_H */
