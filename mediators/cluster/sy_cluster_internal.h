/* sy_cluster_internal.h — INTERNAL to mediators/cluster (not installed): what the modules of the
 * render server and the cluster client (sy_cluster.h) share: the wire state, the server's and the
 * client's structs, and the functions one module calls in another (prefix sy_clu_; none of them is
 * API). The modules, bottom-up (each calls only those before it; tests/core/layers_test.sh checks
 * it), under the wire format (sy_cluster_proto.c) and the transports (sy_cluster_transport.c):
 *   sy_cluster_tile.c        tile codec: channel planes, byte shuffle, zstd (API only)
 *   sy_cluster_secret.c      the shared secret and PEM files
 *   sy_cluster_wire.c        frames over a transport's byte stream: sequence numbers, tags, MACs
 *   sy_cluster_log.c         log lines of the client and the server (rate-limited noise)
 *   sy_cluster_blob_cache.c  the server's blob cache (hash table + LRU under a byte budget)
 *   sy_cluster_peer_mem.c    the server's ceiling on peers' messages in flight
 *   sy_cluster_serve.c       the serving thread: sessions, SCENE / BLOBS / RENDER / SWAP
 *   sy_cluster_handshake.c   HELLO / AUTH on a connection's reader thread, authentication back-off
 *   sy_cluster_server.c      the server: create, destroy, run; connections and their reader threads
 *   sy_cluster_client.c      the client's connections: handshake, request / reply, create, destroy
 *   sy_cluster_frame.c       modes and one frame: work items, rounds, reassignment, merge, swap
 *   sy_cluster_frames.c      frames mode: a sequence's whole frames from a work queue, re-queued on failure
 * The cluster mediator (sy_mediator_cluster.c) sits on top and uses only sy_cluster.h. */
#ifndef SY_CLUSTER_INTERNAL_H
#define SY_CLUSTER_INTERNAL_H

#include "sy_cluster.h"
#include "sy_cluster_transport.h"

#include <pthread.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "sy_log.h"
#include "sy_viewport.h"

/* strlcpy: copies what fits, always terminates */
static inline void sy_clu_copy_str(char *dst, size_t cap, const char *src)
{
    size_t n = strlen(src);
    if (n >= cap) n = cap - 1;
    memcpy(dst, src, n);
    dst[n] = 0;
}

/* >>wire: one end of a connection's frames (sy_cluster_wire.c: how a message travels as frames,
 * sequence numbers, tags). */
typedef struct wire {
    sy_cluster_stream *st;       /* the transport's byte stream (sy_cluster_transport.h); NULL = none */
    uint64_t send_seq, recv_seq; /* last sequence number sent / received */
    uint8_t key[32];
    bool tagged;                 /* frames carry tags under key (both directions) */
    int last_rv;                 /* sy_stream_status of the last failed operation (0: a protocol error) */
} wire;

/* Memory for reassembled messages: reserve() may wait (back-pressure) and returns false when the
 * bytes cannot be had; NULL = plain malloc (the client). */
typedef struct wire_mem {
    bool (*reserve)(void *user, size_t bytes, sy_error *err);
    void (*release)(void *user, size_t bytes);
    void *user;
} wire_mem;

/* A received message: the first frame's header (body_size = the reassembled size, clamped to
 * UINT32_MAX) and the body, in the caller's fixed buffer or malloc()ed (charged bytes in
 * `charged`; free with sy_clu_rx_release). */
typedef struct rx_msg {
    sy_cluster_header h;
    uint8_t *body;
    size_t size, cap, charged;
    bool fixed;
} rx_msg;

/* sy_cluster_wire.c */
bool sy_clu_crypto_ready(void); /* libsodium initialised */
/* HMAC-SHA512-256(key, label || a || b) over two nonces: the handshake's proofs and the session key */
void sy_clu_mac3(uint8_t out[32], const uint8_t *key, size_t key_len, const char *label, const uint8_t *a,
                 const uint8_t *b);
void sy_clu_rx_release(rx_msg *m, const wire_mem *mem);
static inline bool sy_clu_wire_closed(const wire *w) { return w->last_rv == SY_STREAM_CLOSED; }
sy_result sy_clu_wire_io(wire *w, bool sending, sy_cluster_iov *iov, unsigned n, double deadline, const char *who,
                         sy_error *err);
sy_result sy_clu_wire_send(wire *w, const uint8_t *frame, size_t size, size_t max_frame, double deadline,
                           double progress_s, const char *who, sy_error *err);
sy_result sy_clu_wire_recv(wire *w, const sy_cluster_budget *b, uint8_t *fixed, size_t fixed_cap, const wire_mem *mem,
                           double deadline, double progress_s, rx_msg *out, const char *who, sy_error *err);

/* sy_cluster_secret.c: a PEM file (certificate or key) as a string, at most 1 MiB */
sy_result sy_clu_read_pem(const char *path, char **out, sy_error *err);

/* ======================================================================== server */
/* Blob cache shared by every session (and outliving them): hash -> blob, least recently used
 * evicted first once the payload bytes exceed the budget. A replica keeps its own references, so
 * eviction never takes data from a live scene; it only means a later SCENE naming the blob makes
 * the server ask for it again. */
typedef struct cache_entry {
    sy_blob *blob;
    sy_hash128 hash;
    struct cache_entry *chain, *older, *newer;
} cache_entry;

typedef struct blob_cache {
    cache_entry **buckets;
    size_t nbuckets, count, bytes, budget;
    cache_entry *newest, *oldest;
    uint64_t evictions;
} blob_cache;

/* Failed authentications per address (host, without the port): a bounded table. After the n-th
 * failure in a row the address is refused (HELLO answered with ERROR) for backoff * 2^(n-1), at
 * most max(60 s, backoff); a success forgets the address; a full table reuses the entry whose
 * refusal ended longest ago. */
typedef struct auth_fail {
    char host[48];
    uint32_t failures;
    double until, last;
} auth_fail;

/* A client's session: the replica and what the serving thread keeps for it. Serving thread only. */
typedef struct session {
    char peer[80];
    double last_active;
    sy_scene *scene;
    sy_context_pool *pool;
    uint64_t frame;
    sy_layer present; /* multi-display: the tile held for the swap barrier */
    uint32_t present_x, present_y, present_fw, present_fh;
    uint64_t present_frame;
    bool has_present;
    /* a SCENE waiting for the blobs the server asked for (BLOB_REQUEST -> BLOBS) */
    uint8_t *pending;
    uint32_t pending_size, pending_flags;
    uint64_t pending_frame;
    size_t pending_charged;        /* bytes of pending charged to the peer memory ceiling */
    sy_blob_store *pending_blobs;  /* every blob the pending SCENE names, as found or received */
    sy_cluster_blob_ref *missing;  /* requested and not yet received (data unused) */
    uint32_t missing_count;
} session;

/* One connection, from accept to close. Its reader thread (peer_main) owns the stream and the
 * wire state: it runs the handshake itself (HELLO / AUTH touch only this record and the
 * back-off table, so a busy serving thread never delays a handshake), then reads each message,
 * hands it to the serving thread (the job fields, under qlock), waits for the reply and sends it.
 * Before the session is open nothing is allocated for the connection beyond this record (the
 * handshake frame buffer is inside it), its transport stream, and the thread's stack. The
 * record is freed by the serving thread (reap_peers) after the thread has ended. */
typedef struct peer {
    sy_cluster_server *s;
    struct peer *next;  /* all connections (s->lock) */
    struct peer *qnext; /* job queue (s->qlock) */
    pthread_t thread;
    wire w;
    char addr[80], host[48];
    bool loopback;
    int state;          /* handshake: 0 expects HELLO, 1 expects AUTH, 2 open (reader thread) */
    uint8_t cnonce[32], snonce[32];
    size_t peer_max_frame;    /* what the client accepts (from its HELLO) */
    double accepted;
    bool counted_unauth;      /* counted in s->unauth (s->lock) */
    bool displaced;           /* closed to make room for a newer connection; counted in s->displacing (s->lock) */
    bool counted_open;        /* counted in s->open_sessions (s->lock) */
    bool dead;                /* the reader thread has finished (s->lock) */
    /* the job handed to the serving thread (qlock) */
    rx_msg in;
    sy_cluster_buf reply;     /* encoded untagged reply; size 0 = none */
    size_t reply_charged;
    bool done, close_after;
    /* serving thread only */
    session se;
    bool registered, evicted;
    uint8_t hbuf[SY_CLUSTER_HANDSHAKE_MAX_FRAME]; /* handshake frames: no allocation before authentication */
} peer;

struct sy_cluster_server {
    sy_cluster_server_opts o;
    uint8_t *secret;
    sy_cluster_listener *listener;
    int port;
    size_t max_frame, max_message, max_peer_memory;
    uint32_t max_sessions, max_unauth, handshake_ms;
    char name[SY_CLUSTER_NAME_MAX];
    blob_cache cache;             /* serving thread */
    uint32_t session_count;       /* registered sessions (serving thread) */
    pthread_mutex_t auth_lock;    /* guards auth[] (reader threads) */
    auth_fail auth[SY_CLUSTER_AUTH_TABLE];
    pthread_mutex_t lock;         /* guards peers, unauth, dead flags, the noise log limiter */
    peer *peers;
    uint32_t unauth, npeers;
    uint32_t displacing;          /* displaced connections whose reader thread has not ended yet */
    peer **unauth_scratch;        /* max_unauth entries: the victim search (s->lock) */
    uint32_t open_sessions;       /* connections past the handshake (at most 2 x max_sessions) */
    double noise_window;          /* start of the current second of rate-limited log lines */
    uint32_t noise_lines, noise_dropped;
    pthread_mutex_t qlock;        /* the job queue */
    pthread_cond_t qcond, dcond;
    peer *qhead, *qtail;
    bool stopping;
    pthread_mutex_t mem_lock;     /* peer memory ceiling */
    pthread_cond_t mem_cond;
    size_t mem_used, mem_peak;
    bool mem_stopping;
    pthread_mutex_t log_lock;
    pthread_t acceptor;
    bool acceptor_started;
    bool sync_ok;                 /* mutexes and conditions initialised */
};

/* sy_cluster_log.c: one log line to the options' callback as "PREFIX: text" when there is one, else
 * to sy_log (module "cluster.server" / "cluster.client", sy_log.h) with its level */
void sy_clu_log_line(sy_cluster_log_fn fn, void *user, sy_log_level level, const char *module, const char *prefix,
                     const char *fmt, ...) __attribute__((format(printf, 6, 7)));
void sy_clu_slog(sy_cluster_server *s, sy_log_level level, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
#define SLOG(s, ...) sy_clu_slog((s), SY_LOG_NOTE, __VA_ARGS__)
#define SWARN(s, ...) sy_clu_slog((s), SY_LOG_WARNING, __VA_ARGS__)
/* events unauthenticated peers can cause at any rate: at most 20 lines a second */
void sy_clu_slog_noise(sy_cluster_server *s, sy_log_level level, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* sy_cluster_blob_cache.c */
sy_blob *sy_clu_cache_get(blob_cache *c, sy_hash128 h); /* borrowed blob (marked most recently used) or NULL */
void sy_clu_cache_put(blob_cache *c, sy_blob *b);       /* caches a reference (not one larger than the budget) */
void sy_clu_cache_free(blob_cache *c);

/* sy_cluster_peer_mem.c: bytes charged to max_peer_memory (sy_clu_mem_release and sy_clu_mem_reserve_wait are a
 * wire_mem's reserve / release with the server as user) */
bool sy_clu_mem_try(sy_cluster_server *s, size_t n);
void sy_clu_mem_release(void *user, size_t n);
bool sy_clu_mem_reserve_wait(void *user, size_t n, sy_error *err);

/* sy_cluster_serve.c (serving thread) */
void sy_clu_session_reset(sy_cluster_server *s, session *se); /* drops the replica, keeps the peer's name */
void sy_clu_serve_job(sy_cluster_server *s, peer *p);         /* serves p->in; the encoded reply in p->reply */

/* sy_cluster_handshake.c (a connection's reader thread) */
void sy_clu_peer_refuse(peer *p, sy_result code, const char *reason); /* sends ERROR; the caller closes */
bool sy_clu_peer_handshake(peer *p);                                  /* true: the session is open */

/* ======================================================================== client */
typedef struct conn {
    char url[256];
    wire w;                      /* w.st != NULL: connected */
    bool live, fresh;            /* fresh: connected during this frame (needs a snapshot) */
    bool session_open;           /* past the handshake: the session's budget applies */
    size_t srv_max_frame;        /* the server's limits (from CHALLENGE) */
    uint64_t srv_max_message;
    bool has_consumer;
    uint32_t consumer;
    char backend[SY_CLUSTER_BACKEND_MAX]; /* "" = the frame's back-end */
    sy_cluster_rect wall;        /* multi-display tile; w == 0: column i of n */
    sy_blob_store *offered;      /* the blobs this frame's SCENE names (by hash), for the server's BLOB_REQUEST */
    sy_cluster_buf scene_msg;    /* encoded (untagged) SCENE for this frame (0 size = none) */
    bool offer_failed;           /* out of memory while keeping a blob */
    uint64_t blob_frames_bytes, blob_payload_bytes; /* BLOBS sent (frames / payloads), cumulative */
    double last_seconds;         /* last render time, for balanced mode */
    uint32_t last_rows;
    uint64_t bytes_sent, bytes_received;
    char error[SY_ERROR_MESSAGE_MAX];
    /* cooperative pipelining (sy_cluster_frame.c): at most one RENDER sent ahead, for the next
     * frame, right after this frame's (the server has it queued when it finishes this one); its
     * answer is owed after this frame's and used when the next frame asks the same, else received
     * and dropped before anything else is sent (sy_clu_conn_drain) */
    sy_cluster_buf ahead;        /* its encoding (untagged); size 0 = none in flight */
    uint64_t ahead_frame;        /* the frame and job it names: its answer must name the same */
    uint32_t ahead_job;
    uint64_t ahead_used, ahead_dropped; /* answers to requests sent ahead: used / dropped, cumulative */
    sy_cluster_buf last_req;     /* the last frame's RENDER with frame and sample_first cleared (size 0 =
                                    none): a frame that asks the same again is sent ahead */
    uint64_t last_req_frame;
} conn;

struct sy_cluster_client {
    sy_cluster_client_opts o;
    sy_scene *scene;
    uint8_t *secret;
    conn *conns;
    uint32_t n;
    uint64_t frame;
    uint32_t coop_next; /* cooperative: first sample index of the next frame (ranges never repeat) */
    uint32_t coop_ahead_end; /* one past the last sample index a request sent ahead asked for */
    size_t max_frame, max_message;
    uint32_t timeout_ms, connect_timeout_ms;
    char *tls_ca; /* owned copy of the CA file path */
};

#define CLOG(c, ...) sy_clu_log_line((c)->o.log, (c)->o.log_user, SY_LOG_NOTE, "cluster.client", "sy cluster", __VA_ARGS__)
#define CWARN(c, ...) sy_clu_log_line((c)->o.log, (c)->o.log_user, SY_LOG_WARNING, "cluster.client", "sy cluster", __VA_ARGS__)

/* sy_cluster_client.c */
void sy_clu_conn_close(conn *k);
/* Warns "URL: WHAT: WHY", closes k and forgets its scene consumer (a snapshot when it comes back). */
void sy_clu_conn_drop(sy_cluster_client *c, conn *k, const char *what, const char *why);
/* One request/reply exchange within timeout_ms (the handshake's deadline before the session is
 * open). *reply borrows *raw (free it with free() after sy_cluster_msg_free). */
sy_result sy_clu_conn_call(sy_cluster_client *c, conn *k, sy_cluster_msg *req, const sy_cluster_buf *preencoded,
                           uint32_t expect, sy_cluster_msg *reply, uint8_t **raw, sy_error *err);
/* Sends req without waiting for its answer (an answer owed to a request sent ahead is received and
 * dropped first); the answer comes with sy_clu_conn_recv. */
sy_result sy_clu_conn_request(sy_cluster_client *c, conn *k, const sy_cluster_msg *req, sy_error *err);
/* The reply to a request already sent: within timeout_ms from now / by the deadline (sy_time_now
 * seconds); an ERROR or a type other than expect is an error. *reply borrows *raw as above. */
sy_result sy_clu_conn_recv(sy_cluster_client *c, conn *k, uint32_t expect, sy_cluster_msg *reply, uint8_t **raw,
                           sy_error *err);
sy_result sy_clu_conn_recv_until(sy_cluster_client *c, conn *k, uint32_t expect, double deadline, sy_cluster_msg *reply,
                                 uint8_t **raw, sy_error *err);
/* Sends k->ahead (an encoded RENDER of `frame`, job `job`) without waiting for its answer; on
 * failure k->ahead is cleared and the caller drops the connection. */
sy_result sy_clu_conn_send_ahead(sy_cluster_client *c, conn *k, uint64_t frame, uint32_t job, sy_error *err);
/* Receives and drops the answer owed to a request sent ahead (none: SY_OK at once). An answer that
 * is not TILES for that frame and job is a protocol error (the caller drops the connection). */
sy_result sy_clu_conn_drain(sy_cluster_client *c, conn *k, sy_error *err);
sy_result sy_clu_conn_connect(sy_cluster_client *c, conn *k, sy_error *err); /* dial + handshake */

/* sy_cluster_frame.c */
/* A frame's start: redials the servers that are down (they get a snapshot), and encodes each live
 * connection's SCENE (k->scene_msg; size 0 = nothing to send) from its consumer; adds the bytes
 * to *scene_bytes. */
sy_result sy_clu_sync_servers(sy_cluster_client *c, uint64_t *scene_bytes, sy_error *err);
/* Sends k->scene_msg and the blobs the server asks for, until SCENE_ACK. */
sy_result sy_clu_send_scene(sy_cluster_client *c, conn *k, sy_error *err);

#endif
