/** @file
 * sy_cluster_proto.h — the cluster wire protocol: message encoder and decoder, pure (no sockets,
 * no crypto, no compression), so that it can be fuzzed and tested alone. The transport
 * (sy_cluster_wire.c on a transport of sy_cluster_transport.h, libsodium, zstd) frames, authenticates and
 * compresses around it.
 * Every message is documented in docs/PROTOCOL.md.
 *
 * Frame: a 24-byte little-endian header {magic "SYCP", version, type, flags, body size, sequence},
 * the body, then (flag SY_CLUSTER_FLAG_TAGGED) a 32-byte authentication tag computed by the
 * transport over header + body. A message is one frame, or several frames of the same type whose
 * bodies are concatenated (flag SY_CLUSTER_FLAG_MORE on every frame but the last): on a byte
 * stream the receiver reads the fixed header first and checks the announced size against its
 * current budget (sy_cluster_frame_check) before it reads or allocates anything for the body. The
 * decoder checks the magic, the version, the type, that the body size matches the frame exactly,
 * and every field of the body (lengths against what remains, counts against the bytes that carry
 * them and against limits, rectangles inside the image, floats finite) before anything is
 * allocated or used.
 *
 * Ownership: encoders append to a caller-owned sy_cluster_buf (free with sy_cluster_buf_free).
 * A decoded sy_cluster_msg borrows byte ranges of the input buffer (changes payload, tile data),
 * so the input must outlive it; arrays it allocates are freed by sy_cluster_msg_free.
 * Thread-safety: pure functions on caller-owned memory. */
#ifndef SY_CLUSTER_PROTO_H
#define SY_CLUSTER_PROTO_H

#include "sy_mediator.h"

#ifdef __cplusplus
extern "C" {
#endif

#define SY_CLUSTER_MAGIC 0x50435953u /**< "SYCP" little endian */
#define SY_CLUSTER_VERSION 6u /**< protocol version this build speaks (4: RENDER carries section planes; 5: RENDER
                                  carries a scene time and a restart flag, for frames mode; 6: RENDER carries
                                  the section caps) */
#define SY_CLUSTER_HEADER_SIZE 24u /**< bytes of a frame header */
#define SY_CLUSTER_TAG_SIZE 32u /**< bytes of a frame's authentication tag */
#define SY_CLUSTER_NONCE_SIZE 32u /**< bytes of a handshake nonce */
#define SY_CLUSTER_NAME_MAX 64u      /**< peer names, incl. NUL */
#define SY_CLUSTER_BACKEND_MAX 32u   /**< back-end names, incl. NUL */
#define SY_CLUSTER_PARAMS_MAX 1024u  /**< "k=v,..." parameter text, incl. NUL */
#define SY_CLUSTER_REASON_MAX 256u   /**< error reasons, incl. NUL */
#define SY_CLUSTER_MAX_TILES 4096u   /**< tiles per render request / reply */
#define SY_CLUSTER_MAX_IMAGE 16384u  /**< image width / height */
#define SY_CLUSTER_MAX_SAMPLES (1u << 20) /**< samples per pixel of one render request */
#define SY_CLUSTER_MAX_BLOBS (1u << 20)   /**< blob references per BLOB_REQUEST / BLOBS */
#define SY_CLUSTER_DEFAULT_MAX_MESSAGE ((size_t)1 << 30) /**< a reassembled message body */
#define SY_CLUSTER_HANDSHAKE_MAX_FRAME 1024u               /**< any frame before the session is open */
#define SY_CLUSTER_DEFAULT_MAX_FRAME ((size_t)8 << 20)    /**< one frame once the session is open */
#define SY_CLUSTER_MIN_FRAME ((size_t)64 << 10)           /**< the smallest frame limit a peer may announce */
#define SY_CLUSTER_MAX_FRAME_LIMIT ((size_t)1 << 30)      /**< the largest */
#define SY_CLUSTER_MAX_MESSAGE_LIMIT ((uint64_t)1 << 40)  /**< the largest message limit a peer may announce */

/** Message types (docs/PROTOCOL.md). */
typedef enum sy_cluster_msg_type {
    SY_CLUSTER_HELLO = 1,     /**< client -> server: nonce, name */
    SY_CLUSTER_CHALLENGE = 2, /**< server -> client: nonce, auth required, name */
    SY_CLUSTER_AUTH = 3,      /**< client -> server: proof (HMAC over both nonces) */
    SY_CLUSTER_WELCOME = 4,   /**< server -> client: server proof */
    SY_CLUSTER_SCENE = 5,     /**< client -> server: serialised change list for a frame */
    SY_CLUSTER_SCENE_ACK = 6, /**< server -> client: applied */
    SY_CLUSTER_RENDER = 7,    /**< client -> server: render request with tiles */
    SY_CLUSTER_TILES = 8,     /**< server -> client: compressed tiles + timings */
    SY_CLUSTER_SWAP = 9,      /**< client -> server: swap barrier (multi-display) */
    SY_CLUSTER_SWAP_ACK = 10, /**< server -> client: presented */
    SY_CLUSTER_BYE = 11,      /**< either way: end of session */
    SY_CLUSTER_ERROR = 12,    /**< server -> client: request rejected, with reason */
    SY_CLUSTER_BLOB_REQUEST = 13, /**< server -> client: the blobs (by hash) a SCENE needs that the server lacks */
    SY_CLUSTER_BLOBS = 14,    /**< client -> server: requested blob payloads (each checked against its hash) */
    SY_CLUSTER_MSG_TYPE_MAX = 14
} sy_cluster_msg_type;

/** Frame header flags. */
typedef enum sy_cluster_frame_flags {
    SY_CLUSTER_FLAG_TAGGED = 1u << 0, /**< a 32-byte authentication tag follows the body */
    SY_CLUSTER_FLAG_MORE = 1u << 1,   /**< the message goes on in the next frame (same type) */
} sy_cluster_frame_flags;

/** SCENE flags. */
typedef enum sy_cluster_scene_flags {
    SY_CLUSTER_SCENE_SNAPSHOT = 1u << 0, /**< replace the replica: start from an empty scene */
} sy_cluster_scene_flags;

/** RENDER flags. */
typedef enum sy_cluster_render_flags {
    SY_CLUSTER_RENDER_DEPTH = 1u << 0,   /**< send the depth channel too */
    SY_CLUSTER_RENDER_PRESENT = 1u << 1, /**< keep the tiles on the server for SWAP (multi-display) */
    SY_CLUSTER_RENDER_HALF = 1u << 2,    /**< send tiles as binary16 planes (SY_CLUSTER_ENC_F16_SHUFFLE_ZSTD) */
    SY_CLUSTER_RENDER_RESTART = 1u << 3, /**< progressive back-ends start a new accumulation (sy_context_restart) */
    SY_CLUSTER_RENDER_TIME = 1u << 4,    /**< set the replica's scene clock to `time` (clip `clip_id`) first */
} sy_cluster_render_flags;
#define SY_CLUSTER_MAX_TIME 1e9 /**< RENDER time: seconds in [0, this] (as sy render --at) */

/** Tile encodings. */
typedef enum sy_cluster_encoding {
    SY_CLUSTER_ENC_F32_SHUFFLE_ZSTD = 1, /**< float32 planes, byte-shuffled, zstd (lossless) */
    SY_CLUSTER_ENC_F16_SHUFFLE_ZSTD = 2, /**< IEEE binary16 planes (round to nearest even), byte-shuffled, zstd */
} sy_cluster_encoding;

/** Bytes per channel value of a tile encoding (4 or 2); 0 for an unknown encoding. */
uint32_t sy_cluster_encoding_bytes(uint32_t encoding);

/** IEEE 754 binary32 <-> binary16. To half: round to nearest, ties to even; overflow (|x| >= 65520)
 * gives +-inf, values below half the smallest subnormal give +-0, NaN stays NaN (sign and the top
 * payload bits kept). To float: exact (every half is a float). Imath's C conversions (half.h).
 * Pure; any thread. */
uint16_t sy_cluster_half_from_float(float f);
/** binary16 -> binary32 (exact). */
float sy_cluster_half_to_float(uint16_t h);

/** A pixel rectangle (row 0 = top). */
typedef struct sy_cluster_rect {
    /** @{ position and size */
    uint32_t x, y, w, h; /** @} */
} sy_cluster_rect;

/** A decoded frame header (docs/PROTOCOL.md, "Frame"). */
typedef struct sy_cluster_header {
    uint32_t magic; /**< SY_CLUSTER_MAGIC */
    /** @{ protocol version; sy_cluster_msg_type */
    uint16_t version, type; /** @} */
    uint32_t flags;     /**< sy_cluster_frame_flags */
    uint32_t body_size; /**< bytes of the body (without the tag) */
    uint64_t seq;       /**< per direction, starts at 1, strictly increasing */
} sy_cluster_header;

/** One encoded tile of a TILES message. */
typedef struct sy_cluster_tile {
    sy_cluster_rect rect; /**< where the tile goes in the image */
    uint32_t encoding; /**< sy_cluster_encoding */
    uint32_t channels; /**< 4 (RGBA) or 5 (RGBA + depth) */
    uint64_t raw_size; /**< rect.w * rect.h * channels * 4, checked */
    const uint8_t *data; /**< compressed bytes (borrowed from the input / caller) */
    uint32_t data_size; /**< bytes at data */
} sy_cluster_tile;

/** One blob in BLOB_REQUEST (data NULL) or BLOBS (data = size payload bytes, borrowed). */
typedef struct sy_cluster_blob_ref {
    sy_hash128 hash; /**< XXH3-128 of the payload (sy_hash_bytes) */
    uint64_t size; /**< payload bytes */
    const uint8_t *data; /**< the payload (BLOBS), NULL in BLOB_REQUEST */
} sy_cluster_blob_ref;

/** One decoded or to-be-encoded message: its header and the body of its type. */
typedef struct sy_cluster_msg {
    sy_cluster_header header; /**< the frame header */
    union {
        struct { /**< HELLO, CHALLENGE */
            uint8_t nonce[SY_CLUSTER_NONCE_SIZE];
            uint32_t flags;       /**< CHALLENGE: bit 0 = authentication required */
            uint32_t max_frame;   /**< largest frame the sender accepts once the session is open */
            uint64_t max_message; /**< largest message body it accepts (frames reassembled) */
            char name[SY_CLUSTER_NAME_MAX];
        } hello;
        struct { /**< AUTH, WELCOME */
            uint8_t mac[SY_CLUSTER_TAG_SIZE];
        } auth;
        struct { /**< SCENE */
            uint64_t frame;
            uint32_t flags; /**< sy_cluster_scene_flags */
            const uint8_t *changes; /**< sy_changes wire format (borrowed) */
            uint32_t changes_size;
        } scene;
        struct { /**< SCENE_ACK, SWAP, SWAP_ACK */
            uint64_t frame;
            uint32_t objects; /**< SCENE_ACK: live objects in the replica */
        } ack;
        struct { /**< RENDER */
            uint64_t frame;
            uint32_t job;
            uint32_t flags; /**< sy_cluster_render_flags */
            char backend[SY_CLUSTER_BACKEND_MAX];
            char params[SY_CLUSTER_PARAMS_MAX];
            uint32_t root_id, background_id, seed, eye;
            uint32_t sample_first, sample_count;
            uint32_t full_width, full_height;
            sy_camera_view camera;
            double time;      /**< SY_CLUSTER_RENDER_TIME: the scene time, seconds in [0, SY_CLUSTER_MAX_TIME] (else 0) */
            uint32_t clip_id; /**< SY_CLUSTER_RENDER_TIME: the animation's core id (0 = every clip; else 0) */
            uint32_t tile_count;
            sy_cluster_rect *tiles; /**< allocated by the decoder; caller's array when encoding */
        } render;
        struct { /**< TILES */
            uint64_t frame;
            uint32_t job;
            double sync_seconds, render_seconds;
            uint64_t samples; /**< per-pixel samples accumulated in what is sent (progressive) */
            uint32_t tile_count;
            sy_cluster_tile *tiles; /**< allocated by the decoder; caller's array when encoding */
        } tiles;
        struct { /**< ERROR */
            uint32_t code; /**< sy_result */
            char reason[SY_CLUSTER_REASON_MAX];
        } error;
        struct { /**< BLOB_REQUEST, BLOBS */
            uint64_t frame; /**< the SCENE's frame */
            uint32_t count; /**< BLOB_REQUEST: 1..SY_CLUSTER_MAX_BLOBS; BLOBS: 1..SY_CLUSTER_MAX_BLOBS */
            sy_cluster_blob_ref *blobs; /**< allocated by the decoder; caller's array when encoding */
        } blobs;
    } u; /**< the body, by header.type */
} sy_cluster_msg;

/** Growable output buffer. Zero-initialise ({0}). */
typedef struct sy_cluster_buf {
    uint8_t *data; /**< the bytes */
    /** @{ bytes used and allocated */
    size_t size, cap; /** @} */
} sy_cluster_buf;
/** Frees the buffer's memory and zeroes it. */
void sy_cluster_buf_free(sy_cluster_buf *b);

/** Appends one complete frame (header + body) for msg (its header.type and header.seq are used;
 * magic, version and body size are filled in). flags may contain SY_CLUSTER_FLAG_TAGGED: the caller
 * then appends the tag itself (SY_CLUSTER_TAG_SIZE bytes) after computing it over the frame.
 * Strings longer than their limits and out-of-range values are rejected, never truncated. */
sy_result sy_cluster_encode(const sy_cluster_msg *msg, uint32_t flags, sy_cluster_buf *out, sy_error *err);

/** Receiver limits of sy_cluster_decode. */
typedef struct sy_cluster_limits {
    size_t max_message; /**< 0 = SY_CLUSTER_DEFAULT_MAX_MESSAGE */
} sy_cluster_limits;

/** Writes a frame header (magic and version filled in). */
void sy_cluster_header_write(uint8_t out[SY_CLUSTER_HEADER_SIZE], uint32_t type, uint32_t flags, uint32_t body_size,
                             uint64_t seq);

/** Parses and checks the fixed header alone (the first SY_CLUSTER_HEADER_SIZE bytes of a frame):
 * magic, version, known type, known flags. Nothing about the body is read. */
sy_result sy_cluster_parse_header(const uint8_t data[SY_CLUSTER_HEADER_SIZE], sy_cluster_header *out, sy_error *err);

/** What a stream receiver accepts next: checked against every header before a byte of its body is
 * read or allocated. */
typedef struct sy_cluster_budget {
    size_t max_frame;   /**< largest frame (header + body + tag) */
    size_t max_message; /**< largest message body (its frames' bodies together) */
    bool chunks;        /**< SY_CLUSTER_FLAG_MORE allowed (not before the session is open) */
    bool tagged;        /**< frames must carry a tag (true) or must not (false) */
} sy_cluster_budget;

/** Checks the header h of the next frame on a stream: the tag flag as the session requires, the
 * frame within max_frame, MORE only where chunks are allowed, a continuation frame (so_far > 0 or
 * msg_type != 0: the message's earlier frames held so_far body bytes) of the same type as the
 * message, and the message within max_message. *follow_out = the bytes that follow the header
 * (body + tag). Errors name the type, the announced size and the limit. */
sy_result sy_cluster_frame_check(const sy_cluster_header *h, const sy_cluster_budget *b, size_t so_far,
                                 uint32_t msg_type, size_t *follow_out, sy_error *err);

/** Parses and checks only the header of an untrusted complete frame: magic, version, known type,
 * body size consistent with size (including the tag when flagged), size within the limit. */
sy_result sy_cluster_decode_header(const void *data, size_t size, const sy_cluster_limits *limits,
                                   sy_cluster_header *out, sy_error *err);

/** Decodes an untrusted message body of type h->type (size bytes: the body of one frame, or the
 * reassembled bodies of a chunked message; h->body_size is not used). *out borrows ranges of body.
 * On success the caller releases *out with sy_cluster_msg_free. Errors name the message type, the
 * byte offset and the reason. Allocations: at most 2 bytes per body byte (RENDER tiles, TILES
 * tiles, blob lists), each count checked against the bytes that carry it first. */
sy_result sy_cluster_decode_body(const sy_cluster_header *h, const void *body, size_t size,
                                 const sy_cluster_limits *limits, sy_cluster_msg *out, sy_error *err);

/** Decodes an untrusted single frame completely (header + body; the tag, if any, is not verified
 * here; MORE is refused: chunked messages are reassembled by the transport and decoded with
 * sy_cluster_decode_body). On success the caller releases *out with sy_cluster_msg_free. */
sy_result sy_cluster_decode(const void *data, size_t size, const sy_cluster_limits *limits, sy_cluster_msg *out,
                            sy_error *err);
void sy_cluster_msg_free(sy_cluster_msg *m); /**< frees decoder allocations; NULL-safe */

const char *sy_cluster_msg_type_name(uint32_t type); /**< "HELLO", ..., "?" */

/** SY_OK when a RENDER may carry this camera view: the core rule first (sy_camera_view_check:
 * finite, the position and every matrix element within SY_COORD_MAX, an orthographic window too),
 * then a known projection, a non-empty window and a clip range >= 0; else SY_ERR_INVALID_ARGUMENT
 * saying which value. The encoder and the decoder apply it (a peer's camera beyond the range never
 * reaches a back-end); the client checks each frame's camera with it before talking to any server. */
sy_result sy_cluster_camera_check(const sy_camera_view *c, sy_error *err);

#ifdef __cplusplus
}
#endif

#endif /* SY_CLUSTER_PROTO_H */
