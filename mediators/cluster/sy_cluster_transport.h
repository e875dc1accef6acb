/** @file
 * sy_cluster_transport.h — the byte streams the cluster protocol runs on, behind one small
 * interface: a transport listens and dials by URL scheme and yields streams that move bytes with
 * deadlines. Built in: nng (tcp://, tls+tcp://, ipc://). Registered by the application: MPI
 * (mpi://RANK, sy_cluster_mpi.h). The protocol above (framing, authentication, tags, budgets:
 * sy_cluster_wire.c, sy_cluster_handshake.c) is the same on every transport.
 *
 * Ownership: streams and listeners belong to whoever got them (free them). Transports are static
 * tables registered for the life of the process (the registry is the only global state).
 * Thread-safety: a stream runs one operation at a time; close() may be called from any thread and
 * makes the pending and every later operation fail with SY_STREAM_CLOSED. The registry is
 * thread-safe. */
#ifndef SY_CLUSTER_TRANSPORT_H
#define SY_CLUSTER_TRANSPORT_H

#include "sy_common.h"

#include <stdbool.h>
#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/** One buffer of a scatter / gather transfer. */
typedef struct sy_cluster_iov {
    void *buf; /**< the bytes */
    size_t len; /**< their count */
} sy_cluster_iov;

/** Outcome of a stream operation. */
typedef enum sy_stream_status {
    SY_STREAM_OK = 0,
    SY_STREAM_TIMEDOUT = 1, /**< the deadline passed */
    SY_STREAM_CLOSED = 2,   /**< the peer or this side closed the stream */
    SY_STREAM_FAILED = 3,   /**< anything else (the message says what) */
} sy_stream_status;

typedef struct sy_cluster_stream sy_cluster_stream;
/** The operations of a stream (a transport's table). */
typedef struct sy_cluster_stream_ops {
    /** Moves at least one byte of iov[0..n) (as many as are ready, up to all) in one direction by
     * deadline (absolute sy_time_now() seconds; 0 = none); *moved = the bytes moved. On failure a
     * message for the log in msg. */
    sy_stream_status (*io)(sy_cluster_stream *s, bool send, const sy_cluster_iov *iov, unsigned n, double deadline,
                           size_t *moved, char *msg, size_t msg_len);
    void (*close)(sy_cluster_stream *s); /**< makes the pending and every later operation fail with SY_STREAM_CLOSED; any thread */
    void (*free)(sy_cluster_stream *s); /**< closes first when needed */
} sy_cluster_stream_ops;

/** Every stream starts with this header (the transport's own state follows). */
struct sy_cluster_stream {
    const sy_cluster_stream_ops *ops; /**< the transport's operations */
    char peer[80];  /**< "1.2.3.4:5678", "[::1]:5678", "mpi rank 0": for the log */
    char host[64];  /**< the peer without its port: the key of the authentication back-off */
    bool loopback;  /**< the peer is this machine (nng: a loopback address) */
};

typedef struct sy_cluster_listener sy_cluster_listener;
/** The operations of a listener (a transport's table). */
typedef struct sy_cluster_listener_ops {
    /** Waits for the next connection: SY_STREAM_OK with *out, SY_STREAM_CLOSED once the listener was
     * closed, SY_STREAM_FAILED for a failure worth logging (the caller goes on accepting). */
    sy_stream_status (*accept)(sy_cluster_listener *l, sy_cluster_stream **out, char *msg, size_t msg_len);
    void (*close)(sy_cluster_listener *l); /**< any thread: ends a pending accept */
    void (*free)(sy_cluster_listener *l); /**< frees the listener (closes first when needed) */
} sy_cluster_listener_ops;

/** Every listener starts with this header (the transport's own state follows). */
struct sy_cluster_listener {
    const sy_cluster_listener_ops *ops; /**< the transport's operations */
    int port;       /**< the TCP port bound, 0 where none */
    bool loopback;  /**< bound to a loopback address only (or a transport that never leaves the job) */
    bool trusted;   /**< peers are vouched for by the launcher (MPI): no shared secret needed to listen */
};

/** Listener options. */
typedef struct sy_cluster_listen_opts {
    /** @{ tls+tcp://: the certificate chain and key (PEM text) */
    const char *tls_cert_pem, *tls_key_pem; /** @} */
} sy_cluster_listen_opts;

/** Dial options. */
typedef struct sy_cluster_dial_opts {
    const char *tls_ca_file; /**< tls+tcp://: the CA that signed the server's certificate */
    uint32_t timeout_ms;     /**< connection set-up */
} sy_cluster_dial_opts;

/** A transport: a URL scheme with its listen and dial functions (a static table). */
typedef struct sy_cluster_transport {
    const char *scheme; /**< the URL prefix before "://" ("mpi"); a transport may take several via matches */
    bool (*matches)(const char *url); /**< optional: true when it handles url (default: the scheme) */
    sy_result (*listen)(const char *url, const sy_cluster_listen_opts *o, sy_cluster_listener **out, sy_error *err); /**< listens on url */
    sy_result (*dial)(const char *url, const sy_cluster_dial_opts *o, sy_cluster_stream **out, sy_error *err); /**< connects to url */
} sy_cluster_transport;

/** Adds a transport (a static table); a scheme registered twice fails. */
sy_result sy_cluster_transport_register(const sy_cluster_transport *t, sy_error *err);
/** The transport for url: a registered one whose scheme / matches() takes it, else nng's. */
const sy_cluster_transport *sy_cluster_transport_for(const char *url);

/** Listens / dials url through its transport. */
sy_result sy_cluster_listen(const char *url, const sy_cluster_listen_opts *o, sy_cluster_listener **out, sy_error *err);
/** Dials url through its transport. */
sy_result sy_cluster_dial(const char *url, const sy_cluster_dial_opts *o, sy_cluster_stream **out, sy_error *err);

#ifdef __cplusplus
}
#endif
#endif /* SY_CLUSTER_TRANSPORT_H */
