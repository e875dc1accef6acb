/* sy_bench_hostile.h — hostile cluster peers (issue 14), shared by `sy bench cluster` and the test
 * cluster_hostile_rss (header-only over sy_cluster.h, pthreads and sy_bench_os.h, so the test
 * includes it without linking the sy program): connections to a server on 127.0.0.1 that never
 * authenticate. Tricklers announce a 256 MiB message and send 64 KiB every 100 ms; flooders
 * announce 8 MiB and send it as fast as they can; both reconnect whenever the server closes them.
 * Thread-safety: sy_bench_hostile_start and sy_bench_hostile_stop on one thread; each peer runs on
 * a thread of its own and is read only after sy_bench_hostile_stop. */
#ifndef SY_BENCH_HOSTILE_H
#define SY_BENCH_HOSTILE_H

#include "sy_bench_os.h"
#include "sy_cluster.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdint.h>
#include <string.h>
#include <time.h>

/* The start of a message of `size` bytes as the server's transport reads it; false when the
 * connection failed. */
typedef bool (*sy_bench_hostile_announce_fn)(int fd, uint64_t size);

typedef struct sy_bench_hostile {
    int port;
    bool flood;                            /* false: a trickler */
    atomic_int *stop;                      /* the peers end when it is set */
    sy_bench_hostile_announce_fn announce; /* NULL: sy_bench_hostile_hello */
    uint64_t bytes;                        /* sent after the announcements */
    uint32_t conns;                        /* connections made */
} sy_bench_hostile;

static inline void sy_bench_sleep_ms(int ms)
{
    struct timespec ts = {ms / 1000, (long)(ms % 1000) * 1000000L};
    nanosleep(&ts, NULL);
}

/* All n bytes sent; false when the peer closed or the send timed out first. */
static inline bool sy_bench_send_all(int fd, const void *p, size_t n)
{
    while (n) {
        ssize_t k = send(fd, p, n, MSG_NOSIGNAL);
        if (k <= 0) return false;
        p = (const uint8_t *)p + k;
        n -= (size_t)k;
    }
    return true;
}

/* The announcement of the cluster's protocol: a HELLO header of `size` bytes. */
static inline bool sy_bench_hostile_hello(int fd, uint64_t size)
{
    uint8_t hdr[SY_CLUSTER_HEADER_SIZE];
    sy_cluster_header_write(hdr, SY_CLUSTER_HELLO, 0, (uint32_t)size, 1);
    return sy_bench_send_all(fd, hdr, sizeof hdr);
}

/* The bytes every peer sends ('A's; written by sy_bench_hostile_start alone). */
static inline uint8_t *sy_bench_hostile_chunk_(void)
{
    static uint8_t chunk[256 << 10];
    return chunk;
}

/* A peer's thread (arg: its sy_bench_hostile). */
static inline void *sy_bench_hostile_main(void *arg)
{
    sy_bench_hostile *h = arg;
    const uint8_t *chunk = sy_bench_hostile_chunk_();
    const uint32_t chunk_size = 256u << 10;
    sy_bench_hostile_announce_fn announce = h->announce ? h->announce : sy_bench_hostile_hello;
    while (!atomic_load(h->stop)) {
        int fd = sy_bench_loopback_connect(NULL, h->port, 2000);
        if (fd < 0) {
            sy_bench_sleep_ms(50);
            continue;
        }
        h->conns++;
        if (announce(fd, h->flood ? (8u << 20) : (256u << 20))) {
            for (uint32_t left = 8u << 20; h->flood && left && !atomic_load(h->stop);) {
                uint32_t n = left < chunk_size ? left : chunk_size;
                if (!sy_bench_send_all(fd, chunk, n)) break;
                h->bytes += n;
                left -= n;
            }
            while (!h->flood && !atomic_load(h->stop) && sy_bench_send_all(fd, chunk, 64 << 10)) {
                h->bytes += 64 << 10;
                sy_bench_sleep_ms(100);
            }
        }
        close(fd);
        sy_bench_sleep_ms(h->flood ? 20 : 50);
    }
    return NULL;
}

/* Starts n peers of port on threads of 256 KiB stacks, the first `tricklers` trickling, the rest
 * flooding, all ending when *stop is set; their threads in th[0 .. the count returned). */
static inline int sy_bench_hostile_start(sy_bench_hostile *peers, pthread_t *th, int n, int tricklers, int port,
                                         atomic_int *stop, sy_bench_hostile_announce_fn announce)
{
    memset(sy_bench_hostile_chunk_(), 'A', 256u << 10);
    int started = 0;
    for (int i = 0; i < n; ++i) {
        peers[started] = (sy_bench_hostile){port, i >= tricklers, stop, announce, 0, 0};
        pthread_attr_t at;
        pthread_attr_init(&at);
        pthread_attr_setstacksize(&at, 256 << 10);
        if (pthread_create(&th[started], &at, sy_bench_hostile_main, &peers[started]) == 0) started++;
        pthread_attr_destroy(&at);
    }
    return started;
}

/* Sets *stop and joins the started peers' threads. */
static inline void sy_bench_hostile_stop(pthread_t *th, int started, atomic_int *stop)
{
    atomic_store(stop, 1);
    for (int i = 0; i < started; ++i) pthread_join(th[i], NULL);
}

#endif /* SY_BENCH_HOSTILE_H */
