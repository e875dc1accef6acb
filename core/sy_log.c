/* sy_log.c — the process-wide log callback and level (see sy_log.h). */
#include "sy_log.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static pthread_mutex_t g_lock = PTHREAD_MUTEX_INITIALIZER; /* guards g_fn / g_user and serialises calls */
static sy_log_fn g_fn;                                      /* NULL: sy_log_stderr */
static void *g_user;
static atomic_int g_level = SY_LOG_NOTE;
static _Thread_local bool t_in_callback; /* this thread is inside the callback: no re-entry, no lock */

const char *sy_log_level_name(sy_log_level level)
{
    switch (level) {
    case SY_LOG_ERROR: return "error";
    case SY_LOG_WARNING: return "warning";
    case SY_LOG_NOTE: return "note";
    case SY_LOG_DEBUG: return "debug";
    default: return "log";
    }
}

void sy_log_set_callback(sy_log_fn fn, void *user)
{
    pthread_mutex_lock(&g_lock); /* waits for a call in progress */
    g_fn = fn;
    g_user = user;
    pthread_mutex_unlock(&g_lock);
}

void sy_log_set_level(sy_log_level level)
{
    int l = (int)level;
    if (l < SY_LOG_ERROR) l = SY_LOG_ERROR;
    if (l > SY_LOG_DEBUG) l = SY_LOG_DEBUG;
    atomic_store(&g_level, l);
}

sy_log_level sy_log_get_level(void) { return (sy_log_level)atomic_load(&g_level); }

bool sy_log_enabled(sy_log_level level) { return level <= SY_LOG_ERROR || (int)level <= atomic_load(&g_level); }

void sy_log_stderr(void *user, sy_log_level level, const char *module, const char *item, const char *message)
{
    (void)user;
    (void)module;
    /* one fputs: stdio locks the stream for it, so concurrent lines do not mix */
    char line[1024];
    const char *lv = sy_log_level_name(level);
    int n = item && *item ? snprintf(line, sizeof line, "sy: %s: %s: %s\n", lv, item, message)
                          : snprintf(line, sizeof line, "sy: %s: %s\n", lv, message);
    if (n >= 0 && (size_t)n < sizeof line) {
        fputs(line, stderr);
        return;
    }
    flockfile(stderr);
    if (item && *item) fprintf(stderr, "sy: %s: %s: %s\n", lv, item, message);
    else fprintf(stderr, "sy: %s: %s\n", lv, message);
    funlockfile(stderr);
}

void sy_logv(sy_log_level level, const char *module, const char *item, const char *fmt, va_list ap)
{
    if (!sy_log_enabled(level)) return;
    if (!module) module = "sy";
    char buf[1024], *msg = buf;
    va_list ap2;
    va_copy(ap2, ap);
    int n = vsnprintf(buf, sizeof buf, fmt, ap);
    if (n < 0) {
        snprintf(buf, sizeof buf, "(unformattable message: %s)", fmt);
    } else if ((size_t)n >= sizeof buf) {
        char *big = malloc((size_t)n + 1);
        if (big) {
            vsnprintf(big, (size_t)n + 1, fmt, ap2);
            msg = big;
        } /* else: the truncated text in buf */
    }
    va_end(ap2);
    if (t_in_callback) { /* logged from inside the callback: straight to stderr, the lock is ours already */
        sy_log_stderr(NULL, level, module, item, msg);
    } else {
        pthread_mutex_lock(&g_lock);
        sy_log_fn fn = g_fn ? g_fn : sy_log_stderr;
        t_in_callback = true;
        fn(g_user, level, module, item, msg);
        t_in_callback = false;
        pthread_mutex_unlock(&g_lock);
    }
    if (msg != buf) free(msg);
}

void sy_log(sy_log_level level, const char *module, const char *item, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    sy_logv(level, module, item, fmt, ap);
    va_end(ap);
}
