/* sy_cluster_peer_mem.c — the render server's ceiling on peers' messages in flight
 * (--max-peer-memory-mb): reassembly buffers, encoded replies and SCENEs waiting for blobs are
 * charged here; a reader thread waits a while for room (TCP pushes back on the sender), then
 * refuses. */
#include "sy_cluster_internal.h"

#include <time.h>

/* >>peer memory: everything the server holds for peers' messages in flight (reassembly buffers,
 * encoded replies, SCENEs waiting for blobs) stays under max_peer_memory. */
bool sy_clu_mem_try(sy_cluster_server *s, size_t n)
{
    pthread_mutex_lock(&s->mem_lock);
    bool ok = n <= s->max_peer_memory - s->mem_used;
    if (ok) {
        s->mem_used += n;
        if (s->mem_used > s->mem_peak) s->mem_peak = s->mem_used;
    }
    pthread_mutex_unlock(&s->mem_lock);
    return ok;
}

void sy_clu_mem_release(void *user, size_t n)
{
    sy_cluster_server *s = user;
    if (!n) return;
    pthread_mutex_lock(&s->mem_lock);
    s->mem_used -= n <= s->mem_used ? n : s->mem_used;
    pthread_cond_broadcast(&s->mem_cond);
    pthread_mutex_unlock(&s->mem_lock);
}

/* Receive side: waits up to SY_CLUSTER_MEMORY_WAIT_MS for other peers' messages to finish (the
 * reader stops reading meanwhile, so TCP pushes back on the sender), then refuses. */
bool sy_clu_mem_reserve_wait(void *user, size_t n, sy_error *err)
{
    sy_cluster_server *s = user;
    double until = sy_time_now() + SY_CLUSTER_MEMORY_WAIT_MS / 1000.0;
    pthread_mutex_lock(&s->mem_lock);
    bool ok;
    while (!(ok = n <= s->max_peer_memory - s->mem_used) && !s->mem_stopping && n <= s->max_peer_memory) {
        double now = sy_time_now();
        if (now >= until) break;
        struct timespec ts;
        clock_gettime(CLOCK_REALTIME, &ts);
        double wait = until - now < 0.1 ? until - now : 0.1;
        long ns = ts.tv_nsec + (long)(wait * 1e9);
        ts.tv_sec += ns / 1000000000L;
        ts.tv_nsec = ns % 1000000000L;
        pthread_cond_timedwait(&s->mem_cond, &s->mem_lock, &ts);
    }
    if (ok) {
        s->mem_used += n;
        if (s->mem_used > s->mem_peak) s->mem_peak = s->mem_used;
    }
    size_t used = s->mem_used;
    pthread_mutex_unlock(&s->mem_lock);
    if (!ok)
        sy_error_set(err, SY_ERR_LIMIT,
                     "server busy: peers' messages in flight hold %zu KiB of the %zu KiB this server allows "
                     "(--max-peer-memory-mb); %zu more bytes were not free within %u ms",
                     used >> 10, s->max_peer_memory >> 10, n, (unsigned)SY_CLUSTER_MEMORY_WAIT_MS);
    return ok;
}
