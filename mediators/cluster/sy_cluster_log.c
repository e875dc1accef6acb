/* sy_cluster_log.c — log lines of the cluster client ("sy cluster: ...") and server
 * ("sy serve: ..."): to the options' callback or to sy_log; the server's lines are serialised, and
 * those unauthenticated peers can cause at any rate are limited to 20 a second. */
#include "sy_cluster_internal.h"

#include <stdarg.h>
#include <stdio.h>

/* One log line: to the options' callback as "PREFIX: text" when there is one, else to sy_log
 * (module "cluster.server" / "cluster.client", sy_log.h) with its level. */
void sy_clu_log_line(sy_cluster_log_fn fn, void *user, sy_log_level level, const char *module, const char *prefix,
                     const char *fmt, ...)
{
    if (!fn && !sy_log_enabled(level)) return;
    char line[768];
    int n = snprintf(line, sizeof line, "%s: ", prefix);
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(line + n, sizeof line - (size_t)n, fmt, ap);
    va_end(ap);
    if (fn) fn(user, line);
    else sy_log(level, module, NULL, "%s", line + n);
}

/* One line of the server, serialised with the others. */
void sy_clu_slog(sy_cluster_server *s, sy_log_level level, const char *fmt, ...)
{
    char line[768];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    if (s->sync_ok) pthread_mutex_lock(&s->log_lock);
    sy_clu_log_line(s->o.log, s->o.log_user, level, "cluster.server", "sy serve", "%s", line);
    if (s->sync_ok) pthread_mutex_unlock(&s->log_lock);
}

/* Events unauthenticated peers can cause at any rate (refused connections, handshake failures):
 * at most 20 lines a second, then one line saying how many were left out. */
void sy_clu_slog_noise(sy_cluster_server *s, sy_log_level level, const char *fmt, ...)
{
    double now = sy_time_now();
    uint32_t dropped = 0;
    bool emit;
    pthread_mutex_lock(&s->lock);
    if (now - s->noise_window >= 1.0) {
        dropped = s->noise_dropped;
        s->noise_window = now;
        s->noise_lines = s->noise_dropped = 0;
    }
    emit = s->noise_lines < 20;
    if (emit) s->noise_lines++;
    else s->noise_dropped++;
    pthread_mutex_unlock(&s->lock);
    if (dropped) SWARN(s, "(%u more lines about unauthenticated peers left out in the last second)", dropped);
    if (!emit) return;
    char line[768];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    sy_clu_slog(s, level, "%s", line);
}
