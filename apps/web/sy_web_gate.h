/** @file
 * sy_web_gate.h — sy web's front door: the listening socket and every connection until its request
 * head has arrived whole, on a thread of its own. Only complete, well-formed heads reach
 * libwebsockets (the socket is peeked until then; a GET is handed over as its rewritten head,
 * lws_adopt_socket_vhost_readbuf, a POST untouched so libwebsockets reads its head and body), so
 * connections that send their head slowly (slowloris) never hold the server's slots:
 *
 *   - a connection budget: at most max_pending connections wait for their head, at most
 *     max_pending_per_address of them from one address; a new connection beyond either evicts the
 *     oldest waiting one (of that address first), so a client that sends its request at once is
 *     always served;
 *   - a head deadline: the head must arrive within head_timeout_ms of the accept, else the
 *     connection is answered 408 and closed (a body is read by libwebsockets, under its timeout);
 *   - the raw head is checked (sy_web_head_scan): malformed heads get their status at once (400,
 *     405, 411, 413, 414, 431, 501);
 *   - a GET but a WebSocket upgrade is handed over with "Connection: close" (its own Connection
 *     header removed): one request per connection; pipelined requests after the first are dropped
 *     and the connection closes after the first answer, as HTTP/1.1 allows (RFC 9112 9.3.2, 9.6:
 *     the client retries them).
 *
 * deliver gets bytes NULL and len 0 for a POST (adopt the socket as it is).
 *
 * Ownership: the gate owns the listening socket and the waiting connections; deliver takes the
 * socket and the bytes (malloc()ed) it is given. Thread-safety: deliver runs on the gate's thread;
 * sy_web_gate_stats from any thread; create and destroy from one thread. */
#ifndef SY_WEB_GATE_H
#define SY_WEB_GATE_H

#include "sy_common.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Takes a connection whose request has arrived: fd and bytes (malloc()ed, len) are the taker's. */
typedef void (*sy_web_gate_deliver)(void *user, int fd, uint8_t *bytes, size_t len);

typedef struct sy_web_gate_desc {
    const char *host;                  /**< the address to listen on (IPv4, IPv6 or a name) */
    int port;                          /**< 0: a free one */
    uint32_t max_pending;              /**< connections waiting for their head (default 128) */
    uint32_t max_pending_per_address;  /**< of one address (default 32) */
    uint32_t head_timeout_ms;          /**< the head must arrive within (default 5000) */
    size_t max_body;                   /**< a larger Content-Length is answered 413 at once */
    sy_web_gate_deliver deliver;       /**< required */
    void *user;                        /**< passed to deliver */
} sy_web_gate_desc;

/** Counters since the start. */
typedef struct sy_web_gate_stats {
    uint64_t accepted;  /**< connections accepted */
    uint64_t delivered; /**< requests handed over */
    uint64_t refused;   /**< answered with an error by the gate (malformed heads) */
    uint64_t evicted;   /**< closed for a newer connection (budget) */
    uint64_t expired;   /**< closed at the head deadline (408) */
    uint32_t pending;   /**< waiting now */
} sy_web_gate_stats;

typedef struct sy_web_gate sy_web_gate;

/** Binds host:port, starts the gate's thread. Fails with a message naming the address. */
sy_result sy_web_gate_create(const sy_web_gate_desc *d, sy_web_gate **out, sy_error *err);
/** The port listened on. */
uint16_t sy_web_gate_port(const sy_web_gate *g);
/** The counters (any thread). */
void sy_web_gate_stats_get(sy_web_gate *g, sy_web_gate_stats *out);
/** Stops the thread, closes the waiting connections and the listening socket (NULL-safe). */
void sy_web_gate_destroy(sy_web_gate *g);

#ifdef __cplusplus
}
#endif
#endif /* SY_WEB_GATE_H */
