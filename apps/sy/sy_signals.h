/* sy_signals.h — SIGINT, SIGTERM and SIGHUP for the sy tool.
 *
 * sy_signals_start blocks those signals in every thread and waits for them on one thread of its
 * own (sigwait), so no handler ever runs inside library code. What an interrupt does:
 *   - by default it cancels every output file in progress (sy_atomic_file_cancel_all: no
 *     "*.tmp-XXXXXX" is left behind) and ends the process by the same signal (exit status 128+N);
 *   - while a command has asked for a graceful first interrupt (sy_signals_set_graceful: a
 *     progressive render, a server), the first one only raises the stop flag, which the command
 *     polls to finish what it is doing cleanly; a second one cancels and ends the process as above.
 * Thread-safety: every function may be called from any thread; the state is process-wide (one
 * tool, one process). */
#ifndef SY_SIGNALS_H
#define SY_SIGNALS_H

#include <stdbool.h>

/* Call once, first thing in main, before any thread is started (threads inherit the blocked
 * mask). Returns once the waiting thread runs (it then holds no lock, so a later fork is safe),
 * or false when it could not be started (signals then keep their default action). */
bool sy_signals_start(void);

/* what: what the first interrupt lets the command finish, printed when it comes ("finishing the
 * current pass, then writing the image"); NULL turns the graceful first interrupt off again.
 * Borrowed: must stay valid until the next call. */
void sy_signals_set_graceful(const char *what);

/* True once a graceful first interrupt has come. */
bool sy_signals_interrupted(void);

/* The same as a flag for APIs that poll one (sy_cluster_server_opts.stop). Never NULL. */
volatile int *sy_signals_stop_flag(void);

#endif
