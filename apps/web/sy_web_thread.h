/** @file
 * sy_web_thread.h — sy_web_run (sy_web.h) on a thread of its own, for a program whose own thread
 * goes on while the server serves (`sy bench web`'s client, the web tests, the Python package's
 * serve()): start it, then stop and join it, which answers what sy_web_run returned.
 *
 * Ownership: sy_web_thread_start allocates the handle, sy_web_thread_join frees it; the server stays
 * the caller's (destroy it after the join).
 * Thread-safety: start and join from one thread; the server's own rules (sy_web.h) otherwise: while
 * the thread runs, only it touches the scene. */
#ifndef SY_WEB_THREAD_H
#define SY_WEB_THREAD_H

#include "sy_web.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The thread that runs one server (opaque). */
typedef struct sy_web_thread sy_web_thread;

/** Starts a thread that calls sy_web_run(w, NULL, ...). Fails with SY_ERR_SYSTEM when the thread
 * cannot be created, SY_ERR_OUT_OF_MEMORY without memory for the handle. */
sy_result sy_web_thread_start(sy_web *w, sy_web_thread **out, sy_error *err);

/** Stops the server (sy_web_stop), waits for the thread to end, frees t and returns what
 * sy_web_run returned (its message in err). NULL-safe: SY_OK. */
sy_result sy_web_thread_join(sy_web_thread *t, sy_error *err);

#ifdef __cplusplus
}
#endif
#endif /* SY_WEB_THREAD_H */
