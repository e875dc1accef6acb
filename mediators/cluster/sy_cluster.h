/** @file
 * sy_cluster.h — cluster rendering: the render server (`sy serve`) and the client that drives a
 * set of servers from a scene. Transports (sy_cluster_transport.h): nng byte streams over TCP
 * (optionally TLS via nng's mbedTLS) and MPI (sy_cluster_mpi.h), carrying length-prefixed frames (a
 * large message travels as several frames); authentication: HMAC-SHA512-256 challenge-response
 * with a shared secret (libsodium), then every frame tagged with a per-session key; tiles
 * compressed with zstd. The wire format is in sy_cluster_proto.h and docs/PROTOCOL.md.
 * Applications usually render through the cluster mediator (sy_mediator_cluster.h), a viewport
 * back-end like any other; this API is the layer under it.
 *
 * Built, with the mediator and the transports, as the library sy_cluster (mediators/cluster/), so
 * that sy_core stays free of nng, libsodium and zstd; it uses only core headers (scene, change
 * lists, mediator contexts).
 *
 * Server: holds one session per connected client (replica scene fed by change lists, context
 * pool) and a blob cache shared by all sessions (keyed by content hash, LRU under a byte budget,
 * outliving sessions), and renders with the mediators registered in the process. Every connection
 * has its own reader thread (small stack) that runs the handshake and reads and sends that peer's
 * frames, so a slow, stalled or garbage-sending peer holds only its own thread; requests are served
 * one at a time on the thread that calls sy_cluster_server_run (renders use every core through the
 * back-ends; mediators stay on one thread). Budgets: before a connection has authenticated it
 * gets a fixed record (a 1 KiB frame buffer inside), at most max_unauthenticated such
 * connections exist (a newer one closes the oldest of the address holding the most), and each must
 * finish HELLO / AUTH within handshake_timeout_ms; after, frames are at most max_frame bytes, messages max_message, and all
 * peers' messages in flight together at most max_peer_memory (a reader waits for room, then
 * refuses). A bad message or a failed authentication is answered with ERROR, logged with the
 * peer's address, the place and the reason, and the server keeps serving; failed authentications
 * refuse the address for an exponentially growing time; replicas refuse change lists naming slot
 * indices beyond max_objects or growing the replica by more than the list's size allows.
 *
 * Client: one connection per server URL; each connection is a scene consumer (its first sync is a
 * snapshot), names blobs by hash and sends only those the server asks for (BLOB_REQUEST), and
 * renders its share of each frame (float32 tiles, or binary16 with sy_cluster_frame.half). A server that fails or misses the deadline is disconnected and its work is given to the
 * others within the same frame; it is retried at the next frame and then starts from a snapshot.
 * Every socket operation has a timeout, so no call blocks forever.
 *
 * Ownership: the server and client own everything they allocate; the client borrows the scene
 * (which must outlive it). Thread-safety: a server or client object is used from one thread at a
 * time (the client runs internal threads per frame and joins them before returning). */
#ifndef SY_CLUSTER_H
#define SY_CLUSTER_H

#include "sy_cluster_proto.h"

#ifdef __cplusplus
extern "C" {
#endif

#define SY_CLUSTER_DEFAULT_URL "tcp://127.0.0.1:5750" /**< where sy serve listens by default */
#define SY_CLUSTER_MAX_SERVERS 64u /**< servers of one client */
#define SY_CLUSTER_MAX_REQUEST_PIXELS (1u << 26) /**< tile pixels per RENDER (an 8192^2 image) */
#define SY_CLUSTER_DEFAULT_BLOB_CACHE ((size_t)1024 << 20) /**< 1 GiB of blob payloads per server */
#define SY_CLUSTER_DEFAULT_MAX_OBJECTS (1u << 20) /**< replica slots per object type */
#define SY_CLUSTER_AUTH_TABLE 256u /**< addresses remembered for authentication back-off */
#define SY_CLUSTER_DEFAULT_MAX_PEER_MEMORY ((size_t)1024 << 20) /**< all peers' messages in flight */
#define SY_CLUSTER_DEFAULT_MAX_UNAUTHENTICATED 32u /**< connections before HELLO / AUTH completed */
#define SY_CLUSTER_DEFAULT_HANDSHAKE_MS 3000u      /**< from accept to an open session */
#define SY_CLUSTER_MEMORY_WAIT_MS 5000u            /**< a reader waits this long for peer memory, then refuses */
#define SY_CLUSTER_PROGRESS_MS 60000u              /**< once a message has begun, each read must finish in this */
#define SY_CLUSTER_SEND_MS 10000u                  /**< each write of a reply must finish in this */
#define SY_CLUSTER_WATCHDOG_MS 250u                /**< a stream operation past its deadline by this: stream closed */
#define SY_CLUSTER_BLOBS_BATCH ((uint64_t)64 << 20) /**< the client's BLOBS messages (at least one blob each) */
/** A change list of N bytes may add at most SY_CLUSTER_APPLY_SLACK_SLOTS + N / 8 pool slots to a
 * replica (sy_scene_apply_bounded; a slot costs SY_SCENE_SLOT_BYTES = 104 bytes, so at most 13 bytes
 * per byte of the list + 416 KiB). docs/PROTOCOL.md, "Budgets and limits". */
#define SY_CLUSTER_APPLY_SLACK_SLOTS 4096u
#define SY_CLUSTER_APPLY_BYTES_PER_SLOT 8u /**< list bytes per replica pool slot it may add (see above) */

/** Receives one log line, "sy serve: TEXT" / "sy cluster: TEXT" (no trailing newline). NULL = the
 * lines go to sy_log (sy_log.h: module "cluster.server" / "cluster.client", a note or a warning). */
typedef void (*sy_cluster_log_fn)(void *user, const char *line);

/** Multi-display: shows / writes the server's tile of frame `frame` (layer = the tile, placed at
 * (x, y) of a full_width x full_height wall). Called at the swap barrier. */
typedef sy_result (*sy_cluster_present_fn)(void *user, uint64_t frame, const sy_layer *tile, uint32_t x, uint32_t y,
                                           uint32_t full_width, uint32_t full_height, sy_error *err);

/* ---- server ---- */
/** Render server options (sy_cluster_server_create). */
typedef struct sy_cluster_server_opts {
    const char *listen_url;   /**< NULL = SY_CLUSTER_DEFAULT_URL; "tcp://127.0.0.1:0" = any free port */
    const uint8_t *secret;    /**< shared secret; NULL / 0 bytes = no authentication, loopback only */
    size_t secret_len; /**< bytes of secret */
    /** @{ both for tls+tcp:// URLs (PEM) */
    const char *tls_cert_file, *tls_key_file; /** @} */
    const char *name;         /**< reported to clients; NULL = "sy serve" */
    uint32_t max_sessions;    /**< sessions; a request beyond ends the longest idle one; more than twice this
                                 many open at once are refused (0 = 16) */
    size_t max_frame;         /**< largest frame accepted after authentication (0 = SY_CLUSTER_DEFAULT_MAX_FRAME, 8 MiB) */
    size_t max_message;       /**< largest message body, frames reassembled (0 = SY_CLUSTER_DEFAULT_MAX_MESSAGE;
                                 at most max_peer_memory) */
    size_t max_peer_memory;   /**< all peers' messages in flight together: reassembly buffers, replies, SCENEs
                                 waiting for blobs (0 = SY_CLUSTER_DEFAULT_MAX_PEER_MEMORY) */
    uint32_t max_unauthenticated; /**< connections not yet authenticated; a newer one closes the oldest of the
                                     address holding the most (0 = 32) */
    uint32_t handshake_timeout_ms; /**< HELLO (/ AUTH) must complete this long after accept (0 = 3000) */
    sy_cluster_log_fn log; /**< log lines; NULL = sy_log */
    void *log_user; /**< passed to log */
    sy_cluster_present_fn present; /**< NULL: SWAP only acknowledges */
    void *present_user; /**< passed to present */
    volatile int *stop;       /**< polled every 100 ms; non-zero ends sy_cluster_server_run */
    double max_lifetime_s;    /**< > 0: run returns after this many seconds (tests) */
    size_t blob_cache_bytes;  /**< blob cache shared by all sessions, LRU (0 = SY_CLUSTER_DEFAULT_BLOB_CACHE) */
    uint32_t max_objects;     /**< replica policy: slot index limit per object type (0 = SY_CLUSTER_DEFAULT_MAX_OBJECTS) */
    uint32_t auth_backoff_ms; /**< refusal window after a failed authentication from an address, doubled per
                                 further failure up to 60 s or this value (0 = 250) */
} sy_cluster_server_opts;

/** A render server (opaque). */
typedef struct sy_cluster_server sy_cluster_server;

/** Listens. Refuses a non-loopback address without a secret, and TLS URLs without cert + key. */
sy_result sy_cluster_server_create(const sy_cluster_server_opts *opts, sy_cluster_server **out, sy_error *err);
/** The TCP port actually bound (useful with port 0). */
int sy_cluster_server_port(const sy_cluster_server *s);
/** Bytes now held for peers' messages in flight (and the most ever, *peak_out); any thread. */
size_t sy_cluster_server_peer_memory(const sy_cluster_server *s, size_t *peak_out);
/** Serves until *opts.stop becomes non-zero or max_lifetime_s passes. */
sy_result sy_cluster_server_run(sy_cluster_server *s, sy_error *err);
void sy_cluster_server_destroy(sy_cluster_server *s); /**< NULL-safe */

/* ---- client ---- */
/** Client options (sy_cluster_client_create). */
typedef struct sy_cluster_client_opts {
    const char *const *urls; /**< one per server, at most SY_CLUSTER_MAX_SERVERS */
    uint32_t url_count; /**< number of urls */
    const uint8_t *secret;   /**< must match the servers'; NULL = servers without a secret only */
    size_t secret_len; /**< bytes of secret */
    const char *tls_ca_file; /**< CA for tls+tcp:// servers (verified); NULL = no TLS */
    uint32_t timeout_ms;     /**< deadline per request (render, scene); 0 = 60000 */
    uint32_t connect_timeout_ms; /**< handshake; 0 = 5000 */
    size_t max_frame;        /**< largest frame accepted from a server (0 = SY_CLUSTER_DEFAULT_MAX_FRAME) */
    size_t max_message;      /**< largest reply body (0 = SY_CLUSTER_DEFAULT_MAX_MESSAGE) */
    sy_cluster_log_fn log; /**< log lines; NULL = sy_log */
    void *log_user; /**< passed to log */
    /** Optional, url_count entries each: a back-end per server (NULL entry = the frame's; e.g. a
     * raster preview node beside path tracers), and the wall tile each server owns in
     * multi-display mode ({0} entry = column i of n). */
    const char *const *backends;
    const sy_cluster_rect *wall_tiles; /**< optional, see above */
    /** Cooperative frames are pipelined by default: once a server's RENDER of a frame is the same as
     * the one of the frame before (no SCENE or RESTART, same view, samples, parameters), the next
     * frame's RENDER goes to it right after this frame's, so it has the next round queued and
     * renders it while the client receives and merges; a next frame that asks otherwise receives
     * and drops that answer first (at most one round per server; docs/CLUSTER.md).
     * true = never send ahead (each frame's requests only once it is asked for). */
    bool no_pipeline;
} sy_cluster_client_opts;

/** A cluster client: connections to the servers and their scene consumers (opaque). */
typedef struct sy_cluster_client sy_cluster_client;

/** How a frame's work is split across the servers. */
typedef enum sy_cluster_mode {
    SY_CLUSTER_SORT_FIRST = 0,    /**< servers render horizontal strips of one image, client composites */
    SY_CLUSTER_BALANCED = 1,      /**< strip heights follow each server's last render speed */
    SY_CLUSTER_COOPERATIVE = 2,   /**< servers render disjoint sample ranges of every pixel; merged */
    SY_CLUSTER_MULTI_DISPLAY = 3, /**< each server renders and presents its column of a wall; swap barrier */
    SY_CLUSTER_STEREO = 4,        /**< left eye on even servers, right eye on odd ones; side by side */
    SY_CLUSTER_FRAMES = 5,        /**< sequences: whole frames to servers from a work queue
                                     (sy_cluster_client_render_frames; sy_cluster_client_render refuses it) */
} sy_cluster_mode;

/** "sort-first" -> SY_CLUSTER_SORT_FIRST, ...; false when unknown. */
bool sy_cluster_mode_parse(const char *name, uint32_t *out);
/** "sort-first", ... for a mode; static storage. */
const char *sy_cluster_mode_name(uint32_t mode);

/** One frame to render on the cluster (sy_cluster_client_render). */
typedef struct sy_cluster_frame {
    uint32_t mode;           /**< sy_cluster_mode */
    const char *backend;     /**< registered on the servers */
    const char *params;      /**< "k=v,..." or NULL */
    /** @{ core ids of the root node (0 = every root) and the background (0 = none) */
    uint32_t root_id, background_id; /** @} */
    sy_camera_view camera;   /**< mono view; stereo derives both eyes from it */
    /** @{ per eye */
    uint32_t width, height; /** @} */
    uint32_t samples;        /**< cooperative: samples per server per frame (0 = 16); others: per request */
    uint32_t samples_total;  /**< cooperative, when > 0: this frame's samples, split across the live servers */
    uint32_t seed; /**< seed for the back-ends' sampling */
    bool depth;              /**< fetch depth too */
    bool half;               /**< tiles as binary16 (display walls, previews); false = float32, bit-exact */
    bool restart;            /**< progressive back-ends start new accumulations (sy_context_restart) on the servers */
    /** @{ stereo (0 = defaults 0.065 / 2) */
    float eye_separation, zero_parallax; /** @} */
} sy_cluster_frame;

/** What a frame cost (sy_cluster_client_render). */
typedef struct sy_cluster_frame_stats {
    uint32_t servers_live;   /**< connected after the frame */
    uint32_t servers_failed; /**< failed or missed the deadline during this frame */
    uint32_t reassigned;     /**< work items given to another server */
    uint64_t scene_bytes;    /**< SCENE and BLOBS frames sent this frame (all servers) */
    uint64_t blob_bytes;     /**< blob payload bytes among them (only blobs a server asked for) */
    /** @{ everything on the wire this frame */
    uint64_t bytes_sent, bytes_received; /** @} */
    uint64_t samples;        /**< cooperative: merged samples per pixel */
    uint32_t pipelined;      /**< cooperative: answers used that were requested ahead, before this frame's call */
    uint32_t stale;          /**< answers to requests sent ahead that this frame dropped (it asked otherwise) */
    double seconds;          /**< whole frame on the client */
    double max_server_seconds; /**< slowest server's sync + render time */
} sy_cluster_frame_stats;

/** Creates the client and connects to every server it can reach (unreachable ones are retried at
 * each frame). Fails only on bad options or when no server could be reached. */
sy_result sy_cluster_client_create(sy_scene *scene, const sy_cluster_client_opts *opts, sy_cluster_client **out,
                                   sy_error *err);
/** Renders one frame: syncs the scene's committed changes to every live server, renders the
 * frame's work and merges it into out (width x height, or 2*width x height side by side in stereo;
 * created by the caller with sy_layer_create). Multi-display leaves out untouched. */
sy_result sy_cluster_client_render(sy_cluster_client *c, const sy_cluster_frame *f, sy_layer *out,
                                   sy_cluster_frame_stats *stats, sy_error *err);
/** Receives a finished frame of sy_cluster_client_render_frames: `index` into the job's frames, the
 * whole image (borrowed for the call), the server (index into the URLs) that rendered it. Called on
 * the client's threads, one call at a time. Non-SY_OK (with err set) ends the job with that error. */
typedef sy_result (*sy_cluster_frame_done_fn)(void *user, uint32_t index, const sy_layer *image, uint32_t server,
                                              sy_error *err);

/** A sequence for sy_cluster_client_render_frames. */
typedef struct sy_cluster_frames_job {
    sy_cluster_frame frame;        /**< what every frame shares: back-end, params, root, background, size, samples
                                      (progressive: per frame), seed, depth, half; mode, camera, restart ignored */
    uint32_t count;                /**< frames */
    const double *times;           /**< count scene times in seconds, [0, SY_CLUSTER_MAX_TIME]; NULL = no clock
                                      (the replica renders as synced) */
    const sy_camera_view *cameras; /**< count views, one per frame (an animated camera moves) */
    uint32_t clip_id;              /**< with times: the animation's core id (0 = every clip), as sy_scene_set_time */
    sy_cluster_frame_done_fn done; /**< receives each frame once */
    void *done_user;               /**< passed to done */
} sy_cluster_frames_job;

/** What a sequence cost (sy_cluster_client_render_frames). */
typedef struct sy_cluster_frames_stats {
    uint32_t frames;         /**< frames delivered */
    uint32_t requeued;       /**< frames given back to the queue by a server that failed on them */
    uint32_t servers_failed; /**< server failures (a server that fails is redialled between rounds) */
    uint32_t rounds;         /**< rounds of the queue (1 when no server failed) */
    uint32_t per_server[SY_CLUSTER_MAX_SERVERS]; /**< frames each server rendered */
    /** @{ everything on the wire */
    uint64_t bytes_sent, bytes_received; /** @} */
    double seconds;          /**< the whole sequence */
} sy_cluster_frames_stats;

/** Frames mode: renders a sequence with whole frames on servers from a work queue. The scene's
 * committed changes go to every live server first (a new one: a snapshot); then one thread per
 * server takes the next frame as soon as its last one is back (no static split), and the server sets
 * its replica's scene clock to the frame's time (RENDER with SY_CLUSTER_RENDER_TIME, clip_id),
 * restarts progressive accumulation (SY_CLUSTER_RENDER_RESTART) and renders the whole image, so a
 * frame is bit for bit what a local context renders at that time. A server that fails or misses the
 * deadline mid-frame is disconnected and its frame goes back to the queue for the others; when the
 * queue stalls with frames left, the servers down are redialled (a snapshot) and the queue runs
 * again, while a round delivers frames; SY_ERR_IO when one delivers none. Frames are delivered
 * through job->done in completion order. stats may be NULL. */
sy_result sy_cluster_client_render_frames(sy_cluster_client *c, const sy_cluster_frames_job *job,
                                          sy_cluster_frames_stats *stats, sy_error *err);
/** Number of servers connected now. */
uint32_t sy_cluster_client_live(const sy_cluster_client *c);
/** Changes the per-request deadline (0 = 60000 ms) for the following frames. */
void sy_cluster_client_set_timeout(sy_cluster_client *c, uint32_t timeout_ms);
void sy_cluster_client_destroy(sy_cluster_client *c); /**< says BYE to live servers; NULL-safe */

/** Reads a shared secret: the file's bytes less trailing newlines (or $SY_CLUSTER_SECRET when path
 * is NULL). *out is malloc()ed (NULL with *len 0 when there is none). Refuses empty secrets and
 * files readable by group or others. */
sy_result sy_cluster_secret_load(const char *path, uint8_t **out, size_t *len, sy_error *err);

/** Tile codec (exposed for tests and benchmarks): encodes a tile-sized layer (RGBA [+ depth]) into
 * planes of the encoding's values (SY_CLUSTER_ENC_F32_SHUFFLE_ZSTD: float32, lossless;
 * SY_CLUSTER_ENC_F16_SHUFFLE_ZSTD: binary16, round to nearest even), byte-shuffled, zstd level 1.
 * sy_cluster_tile_encode = the float32 encoding. */
sy_result sy_cluster_tile_encode_as(const sy_layer *tile, bool depth, uint32_t encoding, sy_cluster_buf *out,
                                    sy_error *err);
/** The float32 encoding (as sy_cluster_tile_encode_as). */
sy_result sy_cluster_tile_encode(const sy_layer *tile, bool depth, sy_cluster_buf *out, sy_error *err);
/** Decodes an untrusted tile into dst at (dx, dy) (dst must contain the rectangle). */
sy_result sy_cluster_tile_decode(const sy_cluster_tile *t, sy_layer *dst, uint32_t dx, uint32_t dy, sy_error *err);

#ifdef __cplusplus
}
#endif

#endif /* SY_CLUSTER_H */
