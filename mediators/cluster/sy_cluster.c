/* sy_cluster.c — render server and cluster client over the transports' byte streams (nng TCP/TLS,
 * MPI: sy_cluster_transport.h; this file never sees which) (see sy_cluster.h, docs/PROTOCOL.md). Sections: >>wire (frames on a stream, shared), tile codec, secrets, server
 * (blob cache, back-off table, peer memory, >>serving, >>connections), client. */
#include "sy_cluster.h"

#include "sy_cluster_transport.h"

#include <sodium.h>
#include <zstd.h>

#include <arpa/inet.h>
#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "sy_log.h"
#include "sy_viewport.h"

/* Each connection's reader thread: 64 KiB of stack reserved (a few KiB touched); sanitizer frames
 * are larger. */
#if defined(__SANITIZE_ADDRESS__)
#define SY__ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define SY__ASAN 1
#endif
#endif
#ifdef SY__ASAN
#define SY_CLUSTER_READER_STACK ((size_t)512 << 10)
#else
#define SY_CLUSTER_READER_STACK ((size_t)64 << 10)
#endif

/* ---- shared helpers ---- */
/* One log line: to the options' callback as "PREFIX: text" when there is one, else to sy_log
 * (module "cluster.server" / "cluster.client", sy_log.h) with its level. */
static void log_line(sy_cluster_log_fn fn, void *user, sy_log_level level, const char *module, const char *prefix,
                     const char *fmt, ...) __attribute__((format(printf, 6, 7)));
static void log_line(sy_cluster_log_fn fn, void *user, sy_log_level level, const char *module, const char *prefix,
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

/* strlcpy: copies what fits, always terminates */
static void copy_str(char *dst, size_t cap, const char *src)
{
    size_t n = strlen(src);
    if (n >= cap) n = cap - 1;
    memcpy(dst, src, n);
    dst[n] = 0;
}

static bool crypto_ready(void)
{
    return sodium_init() >= 0;
}

/* HMAC-SHA512-256(key, label || a || b) */
static void mac3(uint8_t out[32], const uint8_t *key, size_t key_len, const char *label, const uint8_t *a,
                 const uint8_t *b)
{
    crypto_auth_hmacsha512256_state st;
    crypto_auth_hmacsha512256_init(&st, key, key_len);
    crypto_auth_hmacsha512256_update(&st, (const unsigned char *)label, strlen(label));
    crypto_auth_hmacsha512256_update(&st, a, SY_CLUSTER_NONCE_SIZE);
    crypto_auth_hmacsha512256_update(&st, b, SY_CLUSTER_NONCE_SIZE);
    crypto_auth_hmacsha512256_final(&st, out);
}

/* >>wire: frames over a transport's byte stream (shared by the server and the client)
 *
 * A message travels as one frame or, when its body is larger than the receiver's frame limit, as
 * several frames of the same type (SY_CLUSTER_FLAG_MORE on all but the last). Every frame carries
 * its own sequence number and, once the session has a key, its own tag over header + body, so a
 * forged or replayed frame is refused as soon as it has arrived, before the next one is read.
 * The receiver reads the fixed 24-byte header first and checks it against its budget
 * (sy_cluster_frame_check) before it reads or allocates anything for the body. */
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
 * `charged`; free with rx_release). */
typedef struct rx_msg {
    sy_cluster_header h;
    uint8_t *body;
    size_t size, cap, charged;
    bool fixed;
} rx_msg;

static void rx_release(rx_msg *m, const wire_mem *mem)
{
    if (!m->fixed) free(m->body);
    if (m->charged && mem && mem->release) mem->release(mem->user, m->charged);
    memset(m, 0, sizeof *m);
}

/* error prefix: "WHO: " or nothing (the server logs the peer's address itself) */
#define WHO(who) ((who) ? (who) : ""), ((who) ? ": " : "")

static bool wire_closed(const wire *w) { return w->last_rv == SY_STREAM_CLOSED; }

static void frame_tag_parts(uint8_t out[32], const uint8_t key[32], const uint8_t *hdr, const uint8_t *body, size_t n)
{
    crypto_auth_hmacsha512256_state st;
    crypto_auth_hmacsha512256_init(&st, key, 32);
    crypto_auth_hmacsha512256_update(&st, hdr, SY_CLUSTER_HEADER_SIZE);
    if (n) crypto_auth_hmacsha512256_update(&st, body, n);
    crypto_auth_hmacsha512256_final(&st, out);
}

/* Moves all bytes of iov[0..n) in one direction; every operation must finish by deadline
 * (absolute sy_time_now() seconds; 0 = none). */
static sy_result wire_io(wire *w, bool sending, sy_cluster_iov *iov, unsigned n, double deadline, const char *who,
                         sy_error *err)
{
    unsigned first = 0;
    while (first < n && iov[first].len == 0) first++;
    while (first < n) {
        size_t got = 0;
        char msg[160] = "";
        sy_stream_status st = w->st->ops->io(w->st, sending, iov + first, n - first, deadline, &got, msg, sizeof msg);
        if (st == SY_STREAM_OK && got == 0) st = SY_STREAM_CLOSED, snprintf(msg, sizeof msg, "connection shut");
        if (st != SY_STREAM_OK) {
            w->last_rv = (int)st;
            if (st == SY_STREAM_TIMEDOUT)
                return sy_error_set(err, SY_ERR_IO, "%s%s%s", WHO(who),
                                    sending ? "the peer did not take the data before the deadline"
                                            : "no data before the deadline");
            return sy_error_set(err, SY_ERR_IO, "%s%s%s: %s", WHO(who), sending ? "send failed" : "receive failed", msg);
        }
        while (got && first < n) {
            size_t k = got < iov[first].len ? got : iov[first].len;
            iov[first].buf = (uint8_t *)iov[first].buf + k;
            iov[first].len -= k;
            got -= k;
            if (!iov[first].len) first++;
        }
        while (first < n && iov[first].len == 0) first++;
    }
    return SY_OK;
}

/* Sends one message. frame: an untagged frame as sy_cluster_encode writes it (header + body; its
 * sequence number and flags are ignored). The body goes out in frames of at most max_frame bytes;
 * each operation must finish within progress_s seconds (0 = no limit) and by deadline. */
static sy_result wire_send(wire *w, const uint8_t *frame, size_t size, size_t max_frame, double deadline,
                           double progress_s, const char *who, sy_error *err)
{
    if (size < SY_CLUSTER_HEADER_SIZE) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s%sempty frame", WHO(who));
    uint32_t type = (uint32_t)frame[6] | ((uint32_t)frame[7] << 8);
    const uint8_t *body = frame + SY_CLUSTER_HEADER_SIZE;
    size_t n = size - SY_CLUSTER_HEADER_SIZE, tag = w->tagged ? SY_CLUSTER_TAG_SIZE : 0;
    if (max_frame <= SY_CLUSTER_HEADER_SIZE + tag)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s%sframe limit %zu too small", WHO(who), max_frame);
    size_t per = max_frame - SY_CLUSTER_HEADER_SIZE - tag, off = 0;
    if (per > UINT32_MAX) per = UINT32_MAX;
    do {
        size_t c = n - off < per ? n - off : per;
        bool more = off + c < n;
        uint8_t hdr[SY_CLUSTER_HEADER_SIZE], t[SY_CLUSTER_TAG_SIZE];
        sy_cluster_header_write(hdr, type, (w->tagged ? SY_CLUSTER_FLAG_TAGGED : 0u) | (more ? SY_CLUSTER_FLAG_MORE : 0u),
                                (uint32_t)c, ++w->send_seq);
        if (w->tagged) frame_tag_parts(t, w->key, hdr, body + off, c);
        sy_cluster_iov iov[3] = {{hdr, sizeof hdr}, {(void *)(body + off), c}, {t, tag}};
        double d = deadline;
        if (progress_s > 0 && (d <= 0 || sy_time_now() + progress_s < d)) d = sy_time_now() + progress_s;
        sy_result r = wire_io(w, true, iov, 3, d, who, err);
        if (r) return r;
        off += c;
    } while (off < n);
    return SY_OK;
}

/* Receives one message within budget b. fixed (fixed_cap bytes) receives the body when given
 * (the handshake: nothing is allocated); otherwise the body grows frame by frame, each growth
 * reserved from mem first. The first header must arrive by deadline (0 = wait for ever); once it
 * has, every further operation must finish within progress_s (0 = by deadline). Sequence numbers
 * and tags are checked frame by frame. On failure w->last_rv tells a closed connection (sy_stream_status)
 * from a refused frame (0). */
static sy_result wire_recv(wire *w, const sy_cluster_budget *b, uint8_t *fixed, size_t fixed_cap, const wire_mem *mem,
                           double deadline, double progress_s, rx_msg *out, const char *who, sy_error *err)
{
    memset(out, 0, sizeof *out);
    out->fixed = fixed != NULL;
    out->body = fixed;
    out->cap = fixed ? fixed_cap : 0;
    size_t so_far = 0;
    uint32_t type = 0;
    sy_result r = SY_OK;
    w->last_rv = 0;
    for (;;) {
        uint8_t hdr[SY_CLUSTER_HEADER_SIZE];
        double d = deadline;
        if (type && progress_s > 0 && (d <= 0 || sy_time_now() + progress_s < d)) d = sy_time_now() + progress_s;
        sy_cluster_iov iov[2] = {{hdr, sizeof hdr}, {NULL, 0}};
        r = wire_io(w, false, iov, 1, d, who, err);
        if (r) goto fail;
        if (progress_s > 0 && (deadline <= 0 || sy_time_now() + progress_s < deadline))
            d = sy_time_now() + progress_s;
        else d = deadline;
        sy_cluster_header h;
        size_t follow = 0;
        r = sy_cluster_parse_header(hdr, &h, err);
        if (r == SY_OK) r = sy_cluster_frame_check(&h, b, so_far, type, &follow, err);
        if (r == SY_OK && h.seq != w->recv_seq + 1)
            r = sy_error_set(err, SY_ERR_PROTOCOL, "cluster %s: sequence number %llu, expected %llu (replay or loss)",
                             sy_cluster_msg_type_name(h.type), (unsigned long long)h.seq,
                             (unsigned long long)(w->recv_seq + 1));
        if (r) {
            if (who) sy_error_prefix(err, "%s", who);
            goto fail;
        }
        size_t need = so_far + h.body_size; /* <= b->max_message: checked */
        if (need > out->cap) {
            if (out->fixed) { /* cannot happen when the budget fits the buffer */
                r = sy_error_set(err, SY_ERR_LIMIT, "%s%sframe of %u bytes does not fit the %zu-byte buffer", WHO(who),
                                 h.body_size, fixed_cap);
                goto fail;
            }
            size_t ncap = need;
            if (h.flags & SY_CLUSTER_FLAG_MORE) { /* more frames follow: grow geometrically, within the limit */
                size_t dbl = out->cap > b->max_message / 2 ? b->max_message : out->cap * 2;
                if (dbl > ncap) ncap = dbl;
            }
            size_t extra = ncap - out->cap;
            if (mem && mem->reserve && !mem->reserve(mem->user, extra, err)) {
                r = SY_ERR_LIMIT;
                sy_error_prefix(err, "%s%s%s frame of %u bytes", WHO(who), sy_cluster_msg_type_name(h.type), h.body_size);
                goto fail;
            }
            uint8_t *nb = realloc(out->body, ncap ? ncap : 1);
            if (!nb) {
                if (mem && mem->release) mem->release(mem->user, extra);
                r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s%sout of memory for a %zu-byte message", WHO(who), ncap);
                goto fail;
            }
            out->body = nb;
            out->cap = ncap;
            if (mem && mem->reserve) out->charged += extra;
        }
        uint8_t tag[SY_CLUSTER_TAG_SIZE];
        size_t tag_len = follow - h.body_size;
        sy_cluster_iov biov[2] = {{out->body ? out->body + so_far : NULL, h.body_size}, {tag, tag_len}};
        r = wire_io(w, false, biov, 2, d, who, err);
        if (r) goto fail;
        if (tag_len) {
            uint8_t expect[SY_CLUSTER_TAG_SIZE];
            frame_tag_parts(expect, w->key, hdr, out->body ? out->body + so_far : NULL, h.body_size);
            if (crypto_verify_32(expect, tag) != 0) {
                r = sy_error_set(err, SY_ERR_PROTOCOL, "%s%scluster %s: authentication tag does not match", WHO(who),
                                 sy_cluster_msg_type_name(h.type));
                goto fail;
            }
        }
        w->recv_seq = h.seq;
        if (!type) out->h = h;
        type = h.type;
        so_far = need;
        if (!(h.flags & SY_CLUSTER_FLAG_MORE)) break;
    }
    out->size = so_far;
    out->h.body_size = so_far > UINT32_MAX ? UINT32_MAX : (uint32_t)so_far;
    out->h.flags &= ~(uint32_t)SY_CLUSTER_FLAG_MORE;
    return SY_OK;
fail:
    rx_release(out, mem);
    return r;
}

/* ---- tile codec ---- */
sy_result sy_cluster_tile_encode_as(const sy_layer *tile, bool depth, uint32_t encoding, sy_cluster_buf *out,
                                    sy_error *err)
{
    uint32_t vb = sy_cluster_encoding_bytes(encoding);
    if (!vb) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cluster tile: unknown encoding %u", encoding);
    size_t px = (size_t)tile->width * tile->height, ch = depth ? 5 : 4, raw = px * ch * vb;
    uint8_t *shuf = malloc(raw ? raw : 1);
    if (!shuf) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "cluster tile: out of memory (%zu bytes)", raw);
    /* channel planes and byte shuffle in one pass: byte k of value j of the plane sequence goes to
     * shuf[k * nv + j], where j = channel * px + pixel */
    size_t nv = raw / vb;
    uint8_t *b0 = shuf, *b1 = shuf + nv, *b2 = vb == 4 ? shuf + 2 * nv : NULL, *b3 = vb == 4 ? shuf + 3 * nv : NULL;
    for (size_t c = 0; c < ch; ++c) {
        const float *src = c < 4 ? tile->rgba + c : tile->depth;
        size_t stride = c < 4 ? 4 : 1, base = c * px;
        if (vb == 2) {
            for (size_t i = 0; i < px; ++i) {
                uint16_t v = sy_cluster_half_from_float(src[i * stride]);
                b0[base + i] = (uint8_t)v;
                b1[base + i] = (uint8_t)(v >> 8);
            }
            continue;
        }
        for (size_t i = 0; i < px; ++i) {
            uint32_t v;
            memcpy(&v, &src[i * stride], 4);
            b0[base + i] = (uint8_t)v;
            b1[base + i] = (uint8_t)(v >> 8);
            b2[base + i] = (uint8_t)(v >> 16);
            b3[base + i] = (uint8_t)(v >> 24);
        }
    }
    size_t bound = ZSTD_compressBound(raw);
    out->size = 0;
    if (bound > out->cap) {
        uint8_t *d = realloc(out->data, bound);
        if (!d) {
            free(shuf);
            return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "cluster tile: out of memory");
        }
        out->data = d;
        out->cap = bound;
    }
    size_t n = ZSTD_compress(out->data, bound, shuf, raw, 1);
    free(shuf);
    if (ZSTD_isError(n)) return sy_error_set(err, SY_ERR_BACKEND, "cluster tile: zstd: %s", ZSTD_getErrorName(n));
    out->size = n;
    return SY_OK;
}

sy_result sy_cluster_tile_encode(const sy_layer *tile, bool depth, sy_cluster_buf *out, sy_error *err)
{
    return sy_cluster_tile_encode_as(tile, depth, SY_CLUSTER_ENC_F32_SHUFFLE_ZSTD, out, err);
}

sy_result sy_cluster_tile_decode(const sy_cluster_tile *t, sy_layer *dst, uint32_t dx, uint32_t dy, sy_error *err)
{
    const sy_cluster_rect *r = &t->rect;
    uint32_t vb = sy_cluster_encoding_bytes(t->encoding);
    if (!vb) return sy_error_set(err, SY_ERR_UNSUPPORTED, "cluster tile: unknown encoding %u", t->encoding);
    if (dx > dst->width || dy > dst->height || r->w > dst->width - dx || r->h > dst->height - dy)
        return sy_error_set(err, SY_ERR_PROTOCOL, "cluster tile %ux%u at %u,%u does not fit the %ux%u image", r->w,
                            r->h, dx, dy, dst->width, dst->height);
    size_t px = (size_t)r->w * r->h, raw = (size_t)t->raw_size;
    if (raw != px * t->channels * vb) return sy_error_set(err, SY_ERR_PROTOCOL, "cluster tile: raw size mismatch");
    unsigned long long fs = ZSTD_getFrameContentSize(t->data, t->data_size);
    if (fs != raw)
        return sy_error_set(err, SY_ERR_PROTOCOL, "cluster tile %u,%u: compressed frame announces %llu bytes, expected %zu",
                            r->x, r->y, fs, raw);
    uint8_t *shuf = malloc(raw ? raw : 1);
    if (!shuf) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "cluster tile: out of memory");
    size_t n = ZSTD_decompress(shuf, raw, t->data, t->data_size);
    if (ZSTD_isError(n) || n != raw) {
        free(shuf);
        return sy_error_set(err, SY_ERR_PROTOCOL, "cluster tile %u,%u: corrupt compressed data (%s)", r->x, r->y,
                            ZSTD_isError(n) ? ZSTD_getErrorName(n) : "short");
    }
    /* unshuffle straight into the destination rows */
    size_t nv = raw / vb;
    const uint8_t *b0 = shuf, *b1 = shuf + nv, *b2 = vb == 4 ? shuf + 2 * nv : NULL, *b3 = vb == 4 ? shuf + 3 * nv : NULL;
    for (size_t c = 0; c < t->channels; ++c) {
        if (c == 4 && !dst->depth) break;
        size_t base = c * px;
        for (uint32_t y = 0; y < r->h; ++y) {
            size_t row = base + (size_t)y * r->w, o = (size_t)(dy + y) * dst->width + dx;
            float *out = c < 4 ? dst->rgba + o * 4 + c : dst->depth + o;
            size_t stride = c < 4 ? 4 : 1;
            for (uint32_t x = 0; x < r->w; ++x) {
                size_t j = row + x;
                if (vb == 2) {
                    out[x * stride] = sy_cluster_half_to_float((uint16_t)(b0[j] | (b1[j] << 8)));
                    continue;
                }
                uint32_t v = (uint32_t)b0[j] | ((uint32_t)b1[j] << 8) | ((uint32_t)b2[j] << 16) | ((uint32_t)b3[j] << 24);
                memcpy(&out[x * stride], &v, 4);
            }
        }
    }
    free(shuf);
    return SY_OK;
}

/* ---- secrets ---- */
sy_result sy_cluster_secret_load(const char *path, uint8_t **out, size_t *len, sy_error *err)
{
    *out = NULL;
    *len = 0;
    uint8_t *buf = NULL;
    size_t n = 0;
    if (!path) {
        const char *env = getenv("SY_CLUSTER_SECRET");
        if (!env) return SY_OK;
        n = strlen(env);
        buf = malloc(n + 1);
        if (!buf) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "secret: out of memory");
        memcpy(buf, env, n);
        path = "$SY_CLUSTER_SECRET";
    } else {
        FILE *f = fopen(path, "rb");
        if (!f) return sy_error_set(err, SY_ERR_IO, "%s: cannot open secret file: %s", path, strerror(errno));
        struct stat st;
        if (fstat(fileno(f), &st) == 0 && (st.st_mode & 077)) {
            fclose(f);
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                                "%s: secret file is readable by group or others (chmod 600 it)", path);
        }
        buf = malloc(4097);
        if (!buf) {
            fclose(f);
            return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "secret: out of memory");
        }
        n = fread(buf, 1, 4097, f);
        fclose(f);
        if (n > 4096) {
            free(buf);
            return sy_error_set(err, SY_ERR_LIMIT, "%s: secret longer than 4096 bytes", path);
        }
    }
    while (n && (buf[n - 1] == '\n' || buf[n - 1] == '\r')) --n;
    if (n == 0) {
        free(buf);
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: the secret is empty", path);
    }
    *out = buf;
    *len = n;
    return SY_OK;
}

/* A PEM file (certificate or key) as a string, at most 1 MiB. */
static sy_result read_pem(const char *path, char **out, sy_error *err)
{
    *out = NULL;
    FILE *f = fopen(path, "rb");
    if (!f) return sy_error_set(err, SY_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    char *buf = malloc((1u << 20) + 1);
    size_t n = buf ? fread(buf, 1, 1u << 20, f) : 0;
    bool more = buf && fgetc(f) != EOF;
    fclose(f);
    if (!buf) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", path);
    if (more || n == 0 || memchr(buf, 0, n)) {
        free(buf);
        return sy_error_set(err, SY_ERR_PARSE, "%s: not a PEM file (empty, binary or over 1 MiB)", path);
    }
    buf[n] = 0;
    *out = buf;
    return SY_OK;
}

/* ---- modes ---- */
static const char *mode_names[] = {"sort-first", "balanced", "cooperative", "multi-display", "stereo"};

bool sy_cluster_mode_parse(const char *name, uint32_t *out)
{
    for (uint32_t i = 0; i < 5; ++i)
        if (!strcmp(name, mode_names[i])) {
            *out = i;
            return true;
        }
    return false;
}

const char *sy_cluster_mode_name(uint32_t mode)
{
    return mode < 5 ? mode_names[mode] : "?";
}

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

static cache_entry **cache_slot(blob_cache *c, sy_hash128 h)
{
    cache_entry **p = &c->buckets[(size_t)(h.lo ^ h.hi) & (c->nbuckets - 1)];
    while (*p && !sy_hash_equal((*p)->hash, h)) p = &(*p)->chain;
    return p;
}

static void cache_unlink_lru(blob_cache *c, cache_entry *e)
{
    if (e->older) e->older->newer = e->newer;
    else c->oldest = e->newer;
    if (e->newer) e->newer->older = e->older;
    else c->newest = e->older;
    e->older = e->newer = NULL;
}

static void cache_push_newest(blob_cache *c, cache_entry *e)
{
    e->older = c->newest;
    e->newer = NULL;
    if (c->newest) c->newest->newer = e;
    c->newest = e;
    if (!c->oldest) c->oldest = e;
}

/* Borrowed blob (marked most recently used) or NULL. */
static sy_blob *cache_get(blob_cache *c, sy_hash128 h)
{
    if (!c->nbuckets) return NULL;
    cache_entry *e = *cache_slot(c, h);
    if (!e) return NULL;
    cache_unlink_lru(c, e);
    cache_push_newest(c, e);
    return e->blob;
}

static void cache_evict_oldest(blob_cache *c)
{
    cache_entry *e = c->oldest;
    cache_entry **p = cache_slot(c, e->hash);
    *p = e->chain;
    cache_unlink_lru(c, e);
    c->bytes -= sy_blob_size(e->blob);
    c->count--;
    c->evictions++;
    sy_blob_release(e->blob);
    free(e);
}

/* Caches a reference to b (a blob larger than the whole budget is not cached). */
static void cache_put(blob_cache *c, sy_blob *b)
{
    size_t size = sy_blob_size(b);
    if (size > c->budget || cache_get(c, sy_blob_hash(b))) return;
    if (c->count + 1 > c->nbuckets) { /* grow and rehash: load factor <= 1 */
        size_t nb = c->nbuckets ? c->nbuckets * 2 : 256;
        cache_entry **nbk = calloc(nb, sizeof *nbk);
        if (!nbk) return; /* a cache that cannot grow just does not cache */
        for (size_t i = 0; i < c->nbuckets; ++i)
            for (cache_entry *e = c->buckets[i], *next; e; e = next) {
                next = e->chain;
                size_t j = (size_t)(e->hash.lo ^ e->hash.hi) & (nb - 1);
                e->chain = nbk[j];
                nbk[j] = e;
            }
        free(c->buckets);
        c->buckets = nbk;
        c->nbuckets = nb;
    }
    cache_entry *e = calloc(1, sizeof *e);
    if (!e) return;
    e->blob = sy_blob_retain(b);
    e->hash = sy_blob_hash(b);
    cache_entry **p = cache_slot(c, e->hash);
    *p = e;
    cache_push_newest(c, e);
    c->count++;
    c->bytes += size;
    while (c->bytes > c->budget && c->oldest != e) cache_evict_oldest(c);
}

static void cache_free(blob_cache *c)
{
    while (c->oldest) cache_evict_oldest(c);
    free(c->buckets);
    memset(c, 0, sizeof *c);
}

/* Failed authentications per address (host, without the port): a bounded table. After the n-th
 * failure in a row the address is refused (HELLO answered with ERROR) for backoff * 2^(n-1), at
 * most max(60 s, backoff); a success forgets the address; a full table reuses the entry whose
 * refusal ended longest ago. */
typedef struct auth_fail {
    char host[48];
    uint32_t failures;
    double until, last;
} auth_fail;

static auth_fail *auth_find(auth_fail *t, const char *host)
{
    for (uint32_t i = 0; i < SY_CLUSTER_AUTH_TABLE; ++i)
        if (t[i].failures && !strcmp(t[i].host, host)) return &t[i];
    return NULL;
}

/* Seconds the host must still wait (0 = not refused). */
static double auth_refused_for(auth_fail *t, const char *host, double now)
{
    auth_fail *a = auth_find(t, host);
    return a && a->until > now ? a->until - now : 0;
}

/* Records a failure; returns the refusal window in seconds. */
static double auth_failed(auth_fail *t, const char *host, double now, uint32_t backoff_ms)
{
    auth_fail *a = auth_find(t, host);
    if (a && now - a->last > 600) a->failures = 0; /* ten quiet minutes: start over */
    if (!a) {
        a = &t[0];
        for (uint32_t i = 0; i < SY_CLUSTER_AUTH_TABLE; ++i) {
            if (!t[i].failures) {
                a = &t[i];
                break;
            }
            if (t[i].until < a->until) a = &t[i];
        }
        memset(a, 0, sizeof *a);
        copy_str(a->host, sizeof a->host, host);
    }
    a->failures++;
    double base = backoff_ms / 1000.0, cap = base > 60 ? base : 60;
    double wait = base * (double)(1u << (a->failures - 1 < 16 ? a->failures - 1 : 16));
    if (wait > cap) wait = cap;
    a->last = now;
    a->until = now + wait;
    return wait;
}

static void auth_succeeded(auth_fail *t, const char *host)
{
    auth_fail *a = auth_find(t, host);
    if (a) memset(a, 0, sizeof *a);
}

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

static void slog(sy_cluster_server *s, sy_log_level level, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static void slog(sy_cluster_server *s, sy_log_level level, const char *fmt, ...)
{
    char line[768];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    if (s->sync_ok) pthread_mutex_lock(&s->log_lock);
    log_line(s->o.log, s->o.log_user, level, "cluster.server", "sy serve", "%s", line);
    if (s->sync_ok) pthread_mutex_unlock(&s->log_lock);
}
#define SLOG(s, ...) slog((s), SY_LOG_NOTE, __VA_ARGS__)
#define SWARN(s, ...) slog((s), SY_LOG_WARNING, __VA_ARGS__)

/* Events unauthenticated peers can cause at any rate (refused connections, handshake failures):
 * at most 20 lines a second, then one line saying how many were left out. */
static void slog_noise(sy_cluster_server *s, sy_log_level level, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static void slog_noise(sy_cluster_server *s, sy_log_level level, const char *fmt, ...)
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
    slog(s, level, "%s", line);
}

/* >>peer memory: everything the server holds for peers' messages in flight (reassembly buffers,
 * encoded replies, SCENEs waiting for blobs) stays under max_peer_memory. */
static bool mem_try(sy_cluster_server *s, size_t n)
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

static void mem_release(void *user, size_t n)
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
static bool mem_reserve_wait(void *user, size_t n, sy_error *err)
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

static void pending_drop(sy_cluster_server *s, session *se)
{
    free(se->pending);
    free(se->missing);
    sy_blob_store_destroy(se->pending_blobs);
    mem_release(s, se->pending_charged);
    se->pending = NULL;
    se->missing = NULL;
    se->pending_blobs = NULL;
    se->pending_size = se->missing_count = 0;
    se->pending_charged = 0;
}

static void session_reset(sy_cluster_server *s, session *se)
{
    pending_drop(s, se);
    sy_layer_destroy(&se->present);
    sy_context_pool_destroy(se->pool);
    sy_scene_destroy(se->scene);
    char peer[80];
    memcpy(peer, se->peer, sizeof peer);
    memset(se, 0, sizeof *se);
    memcpy(se->peer, peer, sizeof peer);
}

static void *acceptor_main(void *arg);

sy_result sy_cluster_server_create(const sy_cluster_server_opts *opts, sy_cluster_server **out, sy_error *err)
{
    *out = NULL;
    if (!crypto_ready()) return sy_error_set(err, SY_ERR_BACKEND, "sy serve: libsodium failed to initialise");
    sy_cluster_server *s = calloc(1, sizeof *s);
    if (!s) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "sy serve: out of memory");
    s->o = *opts;
    const char *url = opts->listen_url ? opts->listen_url : SY_CLUSTER_DEFAULT_URL;
    copy_str(s->name, sizeof s->name, opts->name ? opts->name : "sy serve");
    s->max_sessions = opts->max_sessions ? opts->max_sessions : 16;
    s->max_frame = opts->max_frame ? opts->max_frame : SY_CLUSTER_DEFAULT_MAX_FRAME;
    s->max_message = opts->max_message ? opts->max_message : SY_CLUSTER_DEFAULT_MAX_MESSAGE;
    s->max_peer_memory = opts->max_peer_memory ? opts->max_peer_memory : SY_CLUSTER_DEFAULT_MAX_PEER_MEMORY;
    s->max_unauth = opts->max_unauthenticated ? opts->max_unauthenticated : SY_CLUSTER_DEFAULT_MAX_UNAUTHENTICATED;
    s->handshake_ms = opts->handshake_timeout_ms ? opts->handshake_timeout_ms : SY_CLUSTER_DEFAULT_HANDSHAKE_MS;
    if (s->max_frame < SY_CLUSTER_MIN_FRAME || s->max_frame > SY_CLUSTER_MAX_FRAME_LIMIT ||
        s->max_message < SY_CLUSTER_MIN_FRAME || s->max_message > SY_CLUSTER_MAX_MESSAGE_LIMIT ||
        s->max_peer_memory < SY_CLUSTER_MIN_FRAME) {
        free(s);
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                            "sy serve: frame limit %zu (64 KiB..1 GiB), message limit %zu (>= 64 KiB) or peer memory %zu "
                            "(>= 64 KiB) out of range",
                            opts->max_frame, opts->max_message, opts->max_peer_memory);
    }
    if (s->max_message > s->max_peer_memory) s->max_message = s->max_peer_memory; /* one message must fit */
    s->cache.budget = opts->blob_cache_bytes ? opts->blob_cache_bytes : SY_CLUSTER_DEFAULT_BLOB_CACHE;
    if (!s->o.max_objects) s->o.max_objects = SY_CLUSTER_DEFAULT_MAX_OBJECTS;
    if (!s->o.auth_backoff_ms) s->o.auth_backoff_ms = 250;
    s->unauth_scratch = calloc(s->max_unauth, sizeof *s->unauth_scratch);
    if (!s->unauth_scratch) {
        free(s);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "sy serve: out of memory");
    }
    pthread_mutex_init(&s->auth_lock, NULL);
    pthread_mutex_init(&s->lock, NULL);
    pthread_mutex_init(&s->qlock, NULL);
    pthread_mutex_init(&s->mem_lock, NULL);
    pthread_mutex_init(&s->log_lock, NULL);
    pthread_cond_init(&s->qcond, NULL);
    pthread_cond_init(&s->dcond, NULL);
    pthread_cond_init(&s->mem_cond, NULL);
    s->sync_ok = true;
    if (opts->secret_len) {
        s->secret = malloc(opts->secret_len);
        if (!s->secret) {
            sy_cluster_server_destroy(s);
            return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "sy serve: out of memory");
        }
        memcpy(s->secret, opts->secret, opts->secret_len);
    }
    s->o.secret = s->secret;
    char *cert = NULL, *key = NULL;
    sy_result lr = SY_OK;
    if (!strncmp(url, "tls+tcp://", 10) && opts->tls_cert_file && opts->tls_key_file) {
        lr = read_pem(opts->tls_cert_file, &cert, err);
        if (lr == SY_OK) lr = read_pem(opts->tls_key_file, &key, err);
    }
    sy_cluster_listen_opts lo = {cert, key};
    if (lr == SY_OK) lr = sy_cluster_listen(url, &lo, &s->listener, err);
    if (key) sodium_memzero(key, strlen(key));
    free(cert);
    free(key);
    if (lr != SY_OK) {
        sy_cluster_server_destroy(s);
        return lr;
    }
    if (!s->secret && !s->listener->loopback && !s->listener->trusted) {
        sy_cluster_server_destroy(s);
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                            "sy serve: %s is not a loopback address; a shared secret (--secret-file or "
                            "SY_CLUSTER_SECRET) is required to listen there",
                            url);
    }
    s->port = s->listener->port;
    *out = s;
    return SY_OK;
}

int sy_cluster_server_port(const sy_cluster_server *s)
{
    return s->port;
}

size_t sy_cluster_server_peer_memory(const sy_cluster_server *s, size_t *peak_out)
{
    pthread_mutex_lock((pthread_mutex_t *)&s->mem_lock);
    size_t used = s->mem_used;
    if (peak_out) *peak_out = s->mem_peak;
    pthread_mutex_unlock((pthread_mutex_t *)&s->mem_lock);
    return used;
}

static void peer_free(sy_cluster_server *s, peer *p);

void sy_cluster_server_destroy(sy_cluster_server *s)
{
    if (!s) return;
    if (s->listener) {
        s->listener->ops->close(s->listener);
        if (s->acceptor_started) pthread_join(s->acceptor, NULL);
        s->listener->ops->free(s->listener);
    }
    /* sy_cluster_server_run has ended every connection; a server that never ran has none */
    while (s->peers) {
        peer *p = s->peers;
        s->peers = p->next;
        peer_free(s, p);
    }
    cache_free(&s->cache);
    free(s->unauth_scratch);
    if (s->secret) sodium_memzero(s->secret, s->o.secret_len);
    free(s->secret);
    if (s->sync_ok) {
        pthread_mutex_destroy(&s->auth_lock);
        pthread_mutex_destroy(&s->lock);
        pthread_mutex_destroy(&s->qlock);
        pthread_mutex_destroy(&s->mem_lock);
        pthread_mutex_destroy(&s->log_lock);
        pthread_cond_destroy(&s->qcond);
        pthread_cond_destroy(&s->dcond);
        pthread_cond_destroy(&s->mem_cond);
    }
    free(s);
}

static sy_result handle_render(sy_cluster_server *s, session *se, const sy_cluster_msg *m, sy_cluster_msg *reply,
                               sy_cluster_buf *payload, sy_error *err)
{
    const __typeof__(m->u.render) *q = &m->u.render;
    if (!se->scene) return sy_error_set(err, SY_ERR_PROTOCOL, "RENDER before any scene was sent");
    if (!sy_mediator_find(q->backend))
        return sy_error_set(err, SY_ERR_NOT_FOUND, "back-end '%s' is not registered on %s", q->backend, s->name);
    if ((q->flags & SY_CLUSTER_RENDER_PRESENT) && q->tile_count != 1)
        return sy_error_set(err, SY_ERR_PROTOCOL, "a present (multi-display) request needs exactly one tile");
    uint64_t pixels = 0;
    for (uint32_t i = 0; i < q->tile_count; ++i) pixels += (uint64_t)q->tiles[i].w * q->tiles[i].h;
    if (pixels > SY_CLUSTER_MAX_REQUEST_PIXELS)
        return sy_error_set(err, SY_ERR_LIMIT, "RENDER asks for %llu pixels, more than the %u a request may hold",
                            (unsigned long long)pixels, SY_CLUSTER_MAX_REQUEST_PIXELS);
    sy_params params;
    sy_result r = sy_params_parse(q->params, &params, err);
    sy_context *ctx = NULL;
    if (r == SY_OK) r = sy_context_pool_get(se->pool, se->scene, q->backend, &params, q->root_id, &ctx, err);
    double t0 = sy_time_now();
    if (r == SY_OK) r = sy_context_sync(ctx, err);
    double t1 = sy_time_now();
    if (r) return r;
    sy_cluster_tile *tiles = calloc(q->tile_count, sizeof *tiles);
    size_t *offsets = calloc(q->tile_count, sizeof *offsets);
    if (!tiles || !offsets) {
        free(tiles);
        free(offsets);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "out of memory");
    }
    bool depth = (q->flags & SY_CLUSTER_RENDER_DEPTH) != 0;
    uint32_t encoding = (q->flags & SY_CLUSTER_RENDER_HALF) ? SY_CLUSTER_ENC_F16_SHUFFLE_ZSTD : SY_CLUSTER_ENC_F32_SHUFFLE_ZSTD;
    uint32_t vb = sy_cluster_encoding_bytes(encoding);
    sy_cluster_buf enc = {0};
    for (uint32_t i = 0; i < q->tile_count && r == SY_OK; ++i) {
        const sy_cluster_rect *tr = &q->tiles[i];
        sy_layer l = {0};
        r = sy_layer_create(tr->w, tr->h, &l, err);
        sy_render_request req = {.camera = q->camera,
                                 .full_width = q->full_width,
                                 .full_height = q->full_height,
                                 .rect_x = tr->x,
                                 .rect_y = tr->y,
                                 .rect_w = tr->w,
                                 .rect_h = tr->h,
                                 .sample_first = q->sample_first,
                                 .sample_count = q->sample_count,
                                 .background_id = q->background_id,
                                 .seed = q->seed};
        if (r == SY_OK) r = sy_context_render(ctx, &req, &l, err);
        if (r == SY_OK && (q->flags & SY_CLUSTER_RENDER_PRESENT)) {
            sy_layer_destroy(&se->present);
            se->present = l;
            memset(&l, 0, sizeof l);
            se->present_x = tr->x;
            se->present_y = tr->y;
            se->present_fw = q->full_width;
            se->present_fh = q->full_height;
            se->present_frame = q->frame;
            se->has_present = true;
        } else if (r == SY_OK) {
            r = sy_cluster_tile_encode_as(&l, depth, encoding, &enc, err);
            if (r == SY_OK) {
                size_t off = payload->size;
                size_t need = payload->size + enc.size;
                if (need > payload->cap) {
                    uint8_t *d = realloc(payload->data, need * 2);
                    if (!d) r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "out of memory");
                    else payload->data = d, payload->cap = need * 2;
                }
                if (r == SY_OK) {
                    memcpy(payload->data + payload->size, enc.data, enc.size);
                    payload->size = need;
                    offsets[i] = off;
                    tiles[i] = (sy_cluster_tile){*tr, encoding, depth ? 5u : 4u,
                                                 (uint64_t)tr->w * tr->h * (depth ? 5u : 4u) * vb, NULL,
                                                 (uint32_t)enc.size};
                }
            }
        }
        sy_layer_destroy(&l);
    }
    sy_cluster_buf_free(&enc);
    double t2 = sy_time_now();
    if (r) {
        free(tiles);
        free(offsets);
        return r;
    }
    uint32_t n = (q->flags & SY_CLUSTER_RENDER_PRESENT) ? 0 : q->tile_count;
    for (uint32_t i = 0; i < n; ++i) tiles[i].data = payload->data + offsets[i];
    free(offsets);
    sy_mediator_stats st = {0};
    sy_context_stats(ctx, &st);
    reply->header.type = SY_CLUSTER_TILES;
    reply->u.tiles.frame = q->frame;
    reply->u.tiles.job = q->job;
    reply->u.tiles.sync_seconds = t1 - t0;
    reply->u.tiles.render_seconds = t2 - t1;
    reply->u.tiles.samples = (sy_context_caps(ctx) & SY_CAP_PROGRESSIVE) && st.samples ? st.samples
                                                                                           : (q->sample_count ? q->sample_count : 1);
    reply->u.tiles.tile_count = n;
    reply->u.tiles.tiles = tiles; /* freed by the caller */
    return SY_OK;
}

/* Applies a complete SCENE (every blob it names is in blobs or inline). A snapshot replaces the
 * replica (and its contexts); a failure drops the replica, so the client must send a snapshot. */
static sy_result apply_scene(sy_cluster_server *s, session *se, const uint8_t *changes, uint32_t size, uint32_t flags,
                             uint64_t frame, sy_blob_store *blobs, sy_cluster_msg *reply, sy_error *err)
{
    sy_result r = SY_OK;
    if ((flags & SY_CLUSTER_SCENE_SNAPSHOT) || !se->scene) {
        sy_layer_destroy(&se->present);
        se->has_present = false;
        sy_context_pool_destroy(se->pool);
        sy_scene_destroy(se->scene);
        se->pool = NULL;
        se->scene = NULL;
        r = sy_scene_create(&se->scene, err);
        if (r == SY_OK) r = sy_context_pool_create(&se->pool, err);
        if (r) return r;
        sy_scene_set_apply_limit(se->scene, s->o.max_objects);
    }
    sy_changes *ch = NULL;
    r = sy_changes_deserialize(changes, size, blobs, NULL, &ch, err);
    /* the replica's pools grow by at most SY_CLUSTER_APPLY_SLACK_SLOTS + one slot per
     * SY_CLUSTER_APPLY_BYTES_PER_SLOT bytes of the list */
    if (r == SY_OK)
        r = sy_scene_apply_bounded(se->scene, ch, SY_CLUSTER_APPLY_SLACK_SLOTS + size / SY_CLUSTER_APPLY_BYTES_PER_SLOT,
                                   err);
    sy_changes_release(ch); /* before the commit copies the changes for the contexts: one copy at a time */
    if (r == SY_OK) r = sy_scene_commit(se->scene, NULL, err);
    if (r) {
        /* the replica may be partly updated: drop it, the client must start from a snapshot */
        sy_context_pool_destroy(se->pool);
        sy_scene_destroy(se->scene);
        se->pool = NULL;
        se->scene = NULL;
        sy_error_prefix(err, "scene for frame %llu rejected (replica dropped, send a snapshot)", (unsigned long long)frame);
        return r;
    }
    se->frame = frame;
    uint32_t objects = 0;
    for (uint32_t t = 0; t < SY_TYPE_COUNT; ++t) objects += sy_scene_count(se->scene, (sy_object_type)t);
    reply->header.type = SY_CLUSTER_SCENE_ACK;
    reply->u.ack.frame = se->frame;
    reply->u.ack.objects = objects;
    return SY_OK;
}

typedef struct ref_scan {
    blob_cache *cache;
    session *se;
    uint32_t cap;
    bool oom;
} ref_scan;

/* sy_changes_blob_refs callback: a blob named by hash is taken from the cache or requested */
static void scan_ref(void *user, sy_hash128 h, uint64_t size)
{
    ref_scan *rs = user;
    session *se = rs->se;
    sy_blob *b = cache_get(rs->cache, h);
    if (b && sy_blob_size(b) == size) {
        sy_error e = {0};
        if (sy_blob_store_put(se->pending_blobs, b, &e) != SY_OK) rs->oom = true;
        return;
    }
    if (se->missing_count == rs->cap) {
        uint32_t nc = rs->cap ? rs->cap * 2 : 64;
        sy_cluster_blob_ref *m = realloc(se->missing, nc * sizeof *m);
        if (!m) {
            rs->oom = true;
            return;
        }
        se->missing = m;
        rs->cap = nc;
    }
    se->missing[se->missing_count++] = (sy_cluster_blob_ref){h, size, NULL};
}

/* Asks for the blobs still missing (at most SY_CLUSTER_MAX_BLOBS per request). */
static void request_missing(session *se, sy_cluster_msg *reply)
{
    reply->header.type = SY_CLUSTER_BLOB_REQUEST;
    reply->u.blobs.frame = se->pending_frame;
    reply->u.blobs.count = se->missing_count < SY_CLUSTER_MAX_BLOBS ? se->missing_count : SY_CLUSTER_MAX_BLOBS;
    reply->u.blobs.blobs = se->missing; /* borrowed: the reply is encoded before the session changes */
}

static sy_result handle_scene(sy_cluster_server *s, session *se, const sy_cluster_msg *m, sy_cluster_msg *reply,
                              sy_error *err)
{
    bool snap = (m->u.scene.flags & SY_CLUSTER_SCENE_SNAPSHOT) != 0;
    pending_drop(s, se); /* a new SCENE replaces one still waiting for blobs */
    if (!snap && !se->scene) return sy_error_set(err, SY_ERR_PROTOCOL, "the first SCENE must be a snapshot");
    sy_result r = sy_blob_store_create(&se->pending_blobs, err);
    ref_scan rs = {&s->cache, se, 0, false};
    if (r == SY_OK) r = sy_changes_blob_refs(m->u.scene.changes, m->u.scene.changes_size, NULL, scan_ref, &rs, err);
    if (r == SY_OK && rs.oom) r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "out of memory for the blob list");
    if (r == SY_OK && se->missing_count) { /* keep the list until the blobs arrive */
        size_t keep = m->u.scene.changes_size ? m->u.scene.changes_size : 1;
        if (!mem_try(s, keep))
            r = sy_error_set(err, SY_ERR_LIMIT,
                             "server busy: no room to keep a %u-byte scene while its blobs arrive (peers' messages "
                             "may hold %zu KiB in all)",
                             m->u.scene.changes_size, s->max_peer_memory >> 10);
        else if (!(se->pending = malloc(keep))) {
            mem_release(s, keep);
            r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "out of memory for a pending scene");
        } else {
            se->pending_charged = keep;
            memcpy(se->pending, m->u.scene.changes, m->u.scene.changes_size);
            se->pending_size = m->u.scene.changes_size;
            se->pending_flags = m->u.scene.flags;
            se->pending_frame = m->u.scene.frame;
            uint64_t bytes = 0;
            for (uint32_t i = 0; i < se->missing_count; ++i) bytes += se->missing[i].size;
            SLOG(s, "%s: frame %llu: asking for %u blob(s), %llu bytes, not in the cache (%zu blobs, %zu bytes cached)",
                 se->peer, (unsigned long long)se->pending_frame, se->missing_count, (unsigned long long)bytes,
                 s->cache.count, s->cache.bytes);
            request_missing(se, reply);
            return SY_OK;
        }
    }
    if (r == SY_OK)
        r = apply_scene(s, se, m->u.scene.changes, m->u.scene.changes_size, m->u.scene.flags, m->u.scene.frame,
                        se->pending_blobs, reply, err);
    else sy_error_prefix(err, "scene for frame %llu rejected", (unsigned long long)m->u.scene.frame);
    pending_drop(s, se);
    return r;
}

/* BLOBS: every payload must be one the server asked for and match its hash; then the pending
 * SCENE applies (or the rest is asked for). Any mismatch drops the pending SCENE. */
static sy_result handle_blobs(sy_cluster_server *s, session *se, const sy_cluster_msg *m, sy_cluster_msg *reply,
                              sy_error *err)
{
    const __typeof__(m->u.blobs) *q = &m->u.blobs;
    sy_result r = SY_OK;
    if (!se->pending) return sy_error_set(err, SY_ERR_PROTOCOL, "BLOBS without a SCENE waiting for them");
    if (q->frame != se->pending_frame)
        r = sy_error_set(err, SY_ERR_PROTOCOL, "BLOBS for frame %llu, the pending scene is for frame %llu",
                         (unsigned long long)q->frame, (unsigned long long)se->pending_frame);
    for (uint32_t i = 0; i < q->count && r == SY_OK; ++i) {
        const sy_cluster_blob_ref *b = &q->blobs[i];
        uint32_t k = 0;
        while (k < se->missing_count && !sy_hash_equal(se->missing[k].hash, b->hash)) k++;
        if (k == se->missing_count)
            r = sy_error_set(err, SY_ERR_PROTOCOL, "blob %016llx%016llx was not requested (or sent twice)",
                             (unsigned long long)b->hash.hi, (unsigned long long)b->hash.lo);
        else if (b->size != se->missing[k].size)
            r = sy_error_set(err, SY_ERR_PROTOCOL, "blob %016llx%016llx has %llu bytes, the scene names %llu",
                             (unsigned long long)b->hash.hi, (unsigned long long)b->hash.lo,
                             (unsigned long long)b->size, (unsigned long long)se->missing[k].size);
        else if (!sy_hash_equal(sy_hash_bytes(b->data, (size_t)b->size), b->hash))
            r = sy_error_set(err, SY_ERR_PROTOCOL, "blob %016llx%016llx: payload does not match its hash",
                             (unsigned long long)b->hash.hi, (unsigned long long)b->hash.lo);
        sy_blob *blob = NULL;
        if (r == SY_OK) r = sy_blob_create_copy(b->data, (size_t)b->size, &blob, err);
        if (r == SY_OK) r = sy_blob_store_put(se->pending_blobs, blob, err);
        if (r == SY_OK) {
            cache_put(&s->cache, blob);
            se->missing[k] = se->missing[--se->missing_count];
        }
        sy_blob_release(blob);
    }
    if (r == SY_OK && se->missing_count) {
        request_missing(se, reply);
        return SY_OK;
    }
    if (r == SY_OK)
        r = apply_scene(s, se, se->pending, se->pending_size, se->pending_flags, se->pending_frame, se->pending_blobs,
                        reply, err);
    else sy_error_prefix(err, "scene for frame %llu rejected", (unsigned long long)se->pending_frame);
    pending_drop(s, se);
    return r;
}

/* Processes one request frame; fills *out with the encoded reply. */

/* >>serving: one request at a time, on the thread that runs sy_cluster_server_run */

/* The first request of an open session registers it; beyond max_sessions the longest idle session
 * is ended (its connection closed, its replica dropped). */
static void session_register(sy_cluster_server *s, peer *p)
{
    if (p->registered) return;
    if (s->session_count >= s->max_sessions) {
        peer *victim = NULL;
        pthread_mutex_lock(&s->lock);
        for (peer *q = s->peers; q; q = q->next)
            if (q != p && q->registered && !q->evicted && (!victim || q->se.last_active < victim->se.last_active))
                victim = q;
        if (victim) victim->w.st->ops->close(victim->w.st); /* its reader thread ends; reap_peers frees it */
        pthread_mutex_unlock(&s->lock);
        if (victim) {
            SLOG(s, "%s: session ended to make room for %s (idle longest; %u sessions max)", victim->se.peer, p->addr,
                 s->max_sessions);
            session_reset(s, &victim->se);
            victim->evicted = true;
            victim->registered = false;
            s->session_count--;
        }
    }
    p->registered = true;
    s->session_count++;
}

/* Serves the message in p->in; leaves the encoded (untagged) reply in p->reply. */
static void serve_job(sy_cluster_server *s, peer *p)
{
    p->reply.size = 0;
    p->close_after = false;
    if (p->evicted) {
        p->close_after = true;
        return;
    }
    session_register(s, p);
    session *se = &p->se;
    se->last_active = sy_time_now();
    sy_error err = {0};
    sy_cluster_msg m, reply;
    memset(&reply, 0, sizeof reply);
    sy_cluster_buf payload = {0};
    sy_cluster_limits lim = {s->max_message};
    sy_result r = sy_cluster_decode_body(&p->in.h, p->in.body, p->in.size, &lim, &m, &err);
    if (r == SY_OK) {
        uint32_t t = m.header.type;
        if (t == SY_CLUSTER_HELLO || t == SY_CLUSTER_AUTH) {
            r = sy_error_set(&err, SY_ERR_PROTOCOL, "%s in the middle of a session", sy_cluster_msg_type_name(t));
            p->close_after = true;
        } else if (t == SY_CLUSTER_SCENE) {
            r = handle_scene(s, se, &m, &reply, &err);
        } else if (t == SY_CLUSTER_BLOBS) {
            r = handle_blobs(s, se, &m, &reply, &err);
        } else if (t == SY_CLUSTER_RENDER) {
            r = handle_render(s, se, &m, &reply, &payload, &err);
        } else if (t == SY_CLUSTER_SWAP) {
            if (!se->has_present || se->present_frame != m.u.ack.frame)
                r = sy_error_set(&err, SY_ERR_PROTOCOL, "SWAP for frame %llu without a rendered tile",
                                 (unsigned long long)m.u.ack.frame);
            else if (s->o.present)
                r = s->o.present(s->o.present_user, se->present_frame, &se->present, se->present_x, se->present_y,
                                 se->present_fw, se->present_fh, &err);
            if (r == SY_OK) {
                reply.header.type = SY_CLUSTER_SWAP_ACK;
                reply.u.ack.frame = m.u.ack.frame;
            }
        } else if (t == SY_CLUSTER_BYE) {
            reply.header.type = SY_CLUSTER_BYE;
            p->close_after = true;
            SLOG(s, "%s: bye", se->peer);
        } else {
            r = sy_error_set(&err, SY_ERR_PROTOCOL, "unexpected %s from a client", sy_cluster_msg_type_name(t));
        }
        sy_cluster_msg_free(&m);
    }
    if (r) {
        SWARN(s, "%s: rejected: %s%s", se->peer, err.message, p->close_after ? " (connection closed)" : "");
        memset(&reply, 0, sizeof reply);
        reply.header.type = SY_CLUSTER_ERROR;
        reply.u.error.code = (uint32_t)r;
        copy_str(reply.u.error.reason, sizeof reply.u.error.reason, err.message);
    }
    sy_error e2 = {0};
    if (sy_cluster_encode(&reply, 0, &p->reply, &e2) != SY_OK) {
        SWARN(s, "%s: cannot encode the reply: %s", se->peer, e2.message);
        p->reply.size = 0;
        p->close_after = true;
    }
    if (reply.header.type == SY_CLUSTER_TILES) free(reply.u.tiles.tiles);
    sy_cluster_buf_free(&payload);
    /* the encoded reply counts against the peer memory ceiling until it has been sent */
    if (p->reply.size && !mem_try(s, p->reply.cap)) {
        size_t want = p->reply.cap;
        sy_cluster_buf_free(&p->reply);
        memset(&reply, 0, sizeof reply);
        reply.header.type = SY_CLUSTER_ERROR;
        reply.u.error.code = SY_ERR_LIMIT;
        snprintf(reply.u.error.reason, sizeof reply.u.error.reason,
                 "server busy: a reply of %zu KiB does not fit the memory left for peers' messages (%zu KiB ceiling)",
                 want >> 10, s->max_peer_memory >> 10);
        SWARN(s, "%s: rejected: %s", se->peer, reply.u.error.reason);
        if (sy_cluster_encode(&reply, 0, &p->reply, &e2) != SY_OK) p->reply.size = 0;
        p->reply_charged = 0; /* a few hundred bytes, not charged */
    } else {
        p->reply_charged = p->reply.size ? p->reply.cap : 0;
    }
}

/* >>connections: reader threads */

/* Sends an ERROR (untagged before the session is open) and ends the connection. An open session's
 * peer may still be sending the rest of a refused message: what it sends within 500 ms is read and
 * dropped first, so that it sees the ERROR instead of a reset connection. */
static void peer_refuse(peer *p, sy_result code, const char *reason)
{
    sy_cluster_msg m;
    memset(&m, 0, sizeof m);
    m.header.type = SY_CLUSTER_ERROR;
    m.u.error.code = (uint32_t)code;
    copy_str(m.u.error.reason, sizeof m.u.error.reason, reason);
    sy_cluster_buf b = {0};
    sy_error e = {0};
    size_t max_frame = p->state == 2 ? p->peer_max_frame : SY_CLUSTER_HANDSHAKE_MAX_FRAME;
    if (sy_cluster_encode(&m, 0, &b, &e) == SY_OK)
        (void)wire_send(&p->w, b.data, b.size, max_frame, sy_time_now() + 1.0, 0, NULL, &e);
    sy_cluster_buf_free(&b);
    if (p->state == 2) {
        double until = sy_time_now() + 0.5;
        for (;;) {
            sy_cluster_iov iov = {p->hbuf, sizeof p->hbuf};
            if (wire_io(&p->w, false, &iov, 1, until, NULL, &e) != SY_OK) break; /* the deadline or the end */
        }
    }
}

/* HELLO (and AUTH when the server has a secret) on the reader thread, under the handshake
 * deadline and budget. Returns true when the session is open. */
static bool peer_handshake(peer *p)
{
    sy_cluster_server *s = p->s;
    double deadline = p->accepted + s->handshake_ms / 1000.0;
    const sy_cluster_budget hb = {SY_CLUSTER_HANDSHAKE_MAX_FRAME, SY_CLUSTER_HANDSHAKE_MAX_FRAME, false, false};
    while (p->state != 2) {
        sy_error err = {0};
        rx_msg in;
        sy_result r = wire_recv(&p->w, &hb, p->hbuf, sizeof p->hbuf, NULL, deadline, 0, &in, NULL, &err);
        if (r) {
            if (p->w.last_rv == SY_STREAM_TIMEDOUT)
                slog_noise(s, SY_LOG_WARNING, "%s: closed: no %s within the %u ms handshake deadline", p->addr,
                           p->state == 0 ? "HELLO" : "AUTH", s->handshake_ms);
            else if (wire_closed(&p->w))
                slog_noise(s, SY_LOG_WARNING, "%s: disconnected during the handshake", p->addr);
            else if (p->w.last_rv) /* the connection failed (e.g. TLS): nothing can be sent */
                slog_noise(s, SY_LOG_WARNING, "%s: connection failed during the handshake: %s", p->addr, err.message);
            else {
                slog_noise(s, SY_LOG_WARNING, "%s: rejected: %s (before authentication; connection closed)", p->addr, err.message);
                peer_refuse(p, r, err.message);
            }
            return false;
        }
        sy_cluster_msg m, reply;
        memset(&reply, 0, sizeof reply);
        sy_cluster_limits lim = {SY_CLUSTER_HANDSHAKE_MAX_FRAME};
        r = sy_cluster_decode_body(&in.h, in.body, in.size, &lim, &m, &err);
        bool refused = r != SY_OK;
        uint32_t t = refused ? 0 : m.header.type;
        if (r == SY_OK) {
            if (t == SY_CLUSTER_HELLO && p->state == 0) {
                double wait = 0;
                if (s->secret) {
                    pthread_mutex_lock(&s->auth_lock);
                    wait = auth_refused_for(s->auth, p->host, sy_time_now());
                    pthread_mutex_unlock(&s->auth_lock);
                }
                if (!s->secret && !p->loopback) {
                    r = sy_error_set(&err, SY_ERR_PROTOCOL, "server has no secret and accepts loopback peers only");
                } else if (wait > 0) {
                    r = sy_error_set(&err, SY_ERR_PROTOCOL,
                                     "throttled: too many failed authentications from %s, retry in %.0f ms", p->host,
                                     ceil(wait * 1000));
                } else {
                    memcpy(p->cnonce, m.u.hello.nonce, 32);
                    randombytes_buf(p->snonce, 32);
                    p->peer_max_frame = m.u.hello.max_frame;
                    reply.header.type = SY_CLUSTER_CHALLENGE;
                    memcpy(reply.u.hello.nonce, p->snonce, 32);
                    reply.u.hello.flags = s->secret ? 1u : 0u;
                    reply.u.hello.max_frame = (uint32_t)s->max_frame;
                    reply.u.hello.max_message = s->max_message;
                    copy_str(reply.u.hello.name, sizeof reply.u.hello.name, s->name);
                    char name[SY_CLUSTER_NAME_MAX]; /* the peer's words in our log: printable only */
                    copy_str(name, sizeof name, m.u.hello.name);
                    for (char *c = name; *c; ++c)
                        if ((unsigned char)*c < 0x20 || (unsigned char)*c == 0x7f) *c = '?';
                    slog_noise(s, SY_LOG_NOTE, "%s: hello from '%s'%s", p->addr, name, s->secret ? "" : " (no secret, loopback)");
                }
            } else if (t == SY_CLUSTER_AUTH && p->state == 1) {
                uint8_t expect[32];
                mac3(expect, s->secret, s->o.secret_len, "SYCP-client", p->snonce, p->cnonce);
                if (crypto_verify_32(expect, m.u.auth.mac) != 0) {
                    pthread_mutex_lock(&s->auth_lock);
                    double wait = auth_failed(s->auth, p->host, sy_time_now(), s->o.auth_backoff_ms);
                    pthread_mutex_unlock(&s->auth_lock);
                    r = sy_error_set(&err, SY_ERR_PROTOCOL, "authentication failed: wrong secret (%s refused for %.0f ms)",
                                     p->host, wait * 1000);
                } else {
                    pthread_mutex_lock(&s->auth_lock);
                    auth_succeeded(s->auth, p->host);
                    pthread_mutex_unlock(&s->auth_lock);
                    reply.header.type = SY_CLUSTER_WELCOME;
                    mac3(reply.u.auth.mac, s->secret, s->o.secret_len, "SYCP-server", p->cnonce, p->snonce);
                }
            } else {
                r = sy_error_set(&err, SY_ERR_PROTOCOL, "%s before authentication", sy_cluster_msg_type_name(t));
            }
            sy_cluster_msg_free(&m);
        }
        if (r) {
            /* a wrong secret is worth every line (the back-off bounds them per address); garbage,
             * out-of-order and throttled HELLOs are rate-limited like any unauthenticated noise */
            if (t == SY_CLUSTER_AUTH) SWARN(s, "%s: rejected: %s (connection closed)", p->addr, err.message);
            else slog_noise(s, SY_LOG_WARNING, "%s: rejected: %s (connection closed)", p->addr, err.message);
            peer_refuse(p, r, err.message);
            return false;
        }
        sy_cluster_buf b = {0};
        r = sy_cluster_encode(&reply, 0, &b, &err);
        if (r == SY_OK) r = wire_send(&p->w, b.data, b.size, SY_CLUSTER_HANDSHAKE_MAX_FRAME, deadline, 0, NULL, &err);
        sy_cluster_buf_free(&b);
        if (r) {
            slog_noise(s, SY_LOG_WARNING, "%s: handshake reply not sent: %s", p->addr, err.message);
            return false;
        }
        if (reply.header.type == SY_CLUSTER_CHALLENGE) p->state = s->secret ? 1 : 2;
        if (reply.header.type == SY_CLUSTER_WELCOME) {
            /* from now on both directions carry tags under the session key */
            mac3(p->w.key, s->secret, s->o.secret_len, "SYCP-session", p->cnonce, p->snonce);
            p->w.tagged = true;
            p->state = 2;
            SLOG(s, "%s: authenticated", p->addr);
        }
    }
    return true;
}

static void *peer_main(void *arg)
{
    peer *p = arg;
    sy_cluster_server *s = p->s;
    bool open = peer_handshake(p);
    if (open) {
        /* sessions that never send a request are not registered (and evicted) by the serving
         * thread: at most twice max_sessions may be open at all */
        pthread_mutex_lock(&s->lock);
        if (p->counted_unauth) s->unauth--;
        p->counted_unauth = false;
        uint32_t n = s->open_sessions;
        open = n < 2 * s->max_sessions;
        if (open) s->open_sessions++, p->counted_open = true;
        pthread_mutex_unlock(&s->lock);
        if (!open) {
            char why[160];
            snprintf(why, sizeof why, "server busy: %u sessions are open (--max-sessions %u)", n, s->max_sessions);
            SWARN(s, "%s: rejected: %s (connection closed)", p->addr, why);
            peer_refuse(p, SY_ERR_LIMIT, why);
        }
    }
    const sy_cluster_budget fb = {s->max_frame, s->max_message, true, p->w.tagged};
    const wire_mem mem = {mem_reserve_wait, mem_release, s};
    while (open) {
        sy_error err = {0};
        sy_result r = wire_recv(&p->w, &fb, NULL, 0, &mem, 0, SY_CLUSTER_PROGRESS_MS / 1000.0, &p->in, NULL, &err);
        if (r) {
            if (wire_closed(&p->w)) SLOG(s, "%s: disconnected", p->addr);
            else if (p->w.last_rv) SWARN(s, "%s: connection failed: %s (connection closed)", p->addr, err.message);
            else {
                SWARN(s, "%s: rejected: %s (connection closed)", p->addr, err.message);
                peer_refuse(p, r, err.message);
            }
            break;
        }
        pthread_mutex_lock(&s->qlock);
        bool stop = s->stopping;
        if (!stop) {
            p->done = false;
            p->qnext = NULL;
            if (s->qtail) s->qtail->qnext = p;
            else s->qhead = p;
            s->qtail = p;
            pthread_cond_signal(&s->qcond);
            while (!p->done) pthread_cond_wait(&s->dcond, &s->qlock);
            stop = s->stopping;
        }
        pthread_mutex_unlock(&s->qlock);
        rx_release(&p->in, &mem);
        if (!stop && p->reply.size) {
            r = wire_send(&p->w, p->reply.data, p->reply.size, p->peer_max_frame, 0, SY_CLUSTER_SEND_MS / 1000.0, NULL,
                          &err);
            if (r) SWARN(s, "%s: reply not sent: %s (connection closed)", p->addr, err.message);
        }
        mem_release(s, p->reply_charged);
        p->reply_charged = 0;
        sy_cluster_buf_free(&p->reply);
        if (stop || r || p->close_after) break;
    }
    p->w.st->ops->close(p->w.st);
    pthread_mutex_lock(&s->lock);
    if (p->counted_unauth) s->unauth--;
    if (p->counted_open) s->open_sessions--;
    if (p->displaced) s->displacing--;
    p->counted_unauth = p->counted_open = p->displaced = false;
    p->dead = true;
    pthread_mutex_unlock(&s->lock);
    pthread_mutex_lock(&s->qlock);
    pthread_cond_signal(&s->qcond); /* the serving thread reaps */
    pthread_mutex_unlock(&s->qlock);
    return NULL;
}

/* Frees a connection whose reader thread has ended (or never started). Serving thread. */
static void peer_free(sy_cluster_server *s, peer *p)
{
    if (p->registered) s->session_count--;
    session_reset(s, &p->se);
    rx_release(&p->in, &(wire_mem){mem_reserve_wait, mem_release, s});
    mem_release(s, p->reply_charged);
    sy_cluster_buf_free(&p->reply);
    if (p->w.st) p->w.st->ops->free(p->w.st);
    sodium_memzero(p->w.key, sizeof p->w.key);
    free(p);
}

/* Joins and frees every connection whose reader thread has finished. Serving thread. */
static void reap_peers(sy_cluster_server *s)
{
    for (;;) {
        peer *dead = NULL;
        pthread_mutex_lock(&s->lock);
        for (peer **pp = &s->peers; *pp; pp = &(*pp)->next)
            if ((*pp)->dead) {
                dead = *pp;
                *pp = dead->next;
                s->npeers--;
                break;
            }
        pthread_mutex_unlock(&s->lock);
        if (!dead) return;
        pthread_join(dead->thread, NULL);
        peer_free(s, dead);
    }
}

/* Orders unauthenticated connections by host, then by age (oldest first). */
static int unauth_order(const void *a, const void *b)
{
    const peer *p = *(peer *const *)a, *q = *(peer *const *)b;
    int c = strcmp(p->host, q->host);
    if (c) return c;
    return (p->accepted > q->accepted) - (p->accepted < q->accepted);
}

/* The table of unauthenticated connections is full: picks the connection to close for a newer
 * one: the oldest connection of the address that holds the most (ties: the address whose oldest
 * is oldest). So a flood from one address displaces only its own connections while another
 * address holds fewer, and a client that completes its handshake promptly is never the oldest
 * for long. NULL when none (the displaced ones have not ended yet). Caller holds s->lock. */
static peer *unauth_victim(sy_cluster_server *s, uint32_t *same_host)
{
    uint32_t n = 0;
    for (peer *p = s->peers; p && n < s->max_unauth; p = p->next)
        if (p->counted_unauth && !p->displaced) s->unauth_scratch[n++] = p;
    if (!n) return NULL;
    qsort(s->unauth_scratch, n, sizeof *s->unauth_scratch, unauth_order);
    peer *best = NULL;
    uint32_t best_run = 0;
    for (uint32_t i = 0; i < n;) {
        uint32_t j = i + 1;
        while (j < n && !strcmp(s->unauth_scratch[j]->host, s->unauth_scratch[i]->host)) ++j;
        peer *oldest = s->unauth_scratch[i];
        if (j - i > best_run || (j - i == best_run && oldest->accepted < best->accepted)) best = oldest, best_run = j - i;
        i = j;
    }
    *same_host = best_run;
    return best;
}

/* A new connection: when max_unauthenticated connections are waiting for their handshake, the
 * oldest of the address holding the most is closed to make room (unauth_victim), so idle
 * connections reopened by one peer cannot lock honest clients out; refused at once only while
 * max_unauthenticated displaced connections are still closing. Then a record and a reader thread
 * with a small stack. */
static void peer_start(sy_cluster_server *s, sy_cluster_stream *st)
{
    pthread_mutex_lock(&s->lock);
    uint32_t unauth = s->unauth, same_host = 0, closing = s->displacing;
    char victim_addr[80] = "";
    bool room = unauth < s->max_unauth;
    if (!room && closing < s->max_unauth) {
        peer *v = unauth_victim(s, &same_host);
        if (v) {
            copy_str(victim_addr, sizeof victim_addr, v->addr);
            v->counted_unauth = false;
            v->displaced = true;
            s->unauth--;
            s->displacing++;
            v->w.st->ops->close(v->w.st); /* its reader thread ends (the record stays listed until then) */
            room = true;
        }
    }
    if (room) s->unauth++;
    pthread_mutex_unlock(&s->lock);
    if (victim_addr[0])
        slog_noise(s, SY_LOG_WARNING, "%s: closed before authentication to make room for %s: the oldest of the %u "
                      "unauthenticated connections from its address (%u open, limit %u, --max-unauthenticated)",
                   victim_addr, st->peer, same_host, unauth, s->max_unauth);
    if (!room) {
        slog_noise(s, SY_LOG_WARNING, "%s: connection refused: %u unauthenticated connections are open (limit %u, "
                      "--max-unauthenticated) and %u more are closing", st->peer, unauth, s->max_unauth, closing);
        st->ops->free(st);
        return;
    }
    peer *p = calloc(1, sizeof *p);
    int rv = p ? 0 : ENOMEM;
    if (rv == 0) {
        p->s = s;
        p->w.st = st;
        p->accepted = sy_time_now();
        p->counted_unauth = true;
        p->loopback = st->loopback;
        copy_str(p->addr, sizeof p->addr, st->peer);
        copy_str(p->se.peer, sizeof p->se.peer, st->peer);
        copy_str(p->host, sizeof p->host, st->host);
        pthread_attr_t at;
        pthread_attr_init(&at);
        pthread_attr_setstacksize(&at, SY_CLUSTER_READER_STACK);
        pthread_mutex_lock(&s->lock); /* listed before it runs: its exit finds itself */
        rv = pthread_create(&p->thread, &at, peer_main, p);
        if (rv == 0) {
            p->next = s->peers;
            s->peers = p;
            s->npeers++;
        }
        pthread_mutex_unlock(&s->lock);
        pthread_attr_destroy(&at);
        if (rv == 0) return;
    }
    slog_noise(s, SY_LOG_WARNING, "%s: connection dropped: %s", st->peer, rv == ENOMEM ? "out of memory" : strerror(rv));
    pthread_mutex_lock(&s->lock);
    s->unauth--;
    pthread_mutex_unlock(&s->lock);
    free(p);
    st->ops->free(st);
}

static void *acceptor_main(void *arg)
{
    sy_cluster_server *s = arg;
    for (;;) {
        sy_cluster_stream *st = NULL;
        char msg[160] = "";
        sy_stream_status rv = s->listener->ops->accept(s->listener, &st, msg, sizeof msg);
        if (rv == SY_STREAM_CLOSED) break;
        if (rv != SY_STREAM_OK) {
            slog_noise(s, SY_LOG_WARNING, "%s", msg);
            struct timespec ts = {0, 20000000L}; /* e.g. out of descriptors: do not spin */
            nanosleep(&ts, NULL);
            continue;
        }
        peer_start(s, st);
    }
    return NULL;
}

sy_result sy_cluster_server_run(sy_cluster_server *s, sy_error *err)
{
    double start = sy_time_now();
    SLOG(s, "listening on %s (port %d)%s; blob cache %zu MiB; frames <= %zu KiB, messages <= %zu MiB, peers' "
            "messages <= %zu MiB in all; <= %u unauthenticated connections, handshake deadline %u ms",
         s->o.listen_url ? s->o.listen_url : SY_CLUSTER_DEFAULT_URL, s->port,
         s->secret ? ", shared-secret authentication" : ", no secret: loopback peers only", s->cache.budget >> 20,
         s->max_frame >> 10, s->max_message >> 20, s->max_peer_memory >> 20, s->max_unauth, s->handshake_ms);
    pthread_mutex_lock(&s->qlock);
    s->stopping = false;
    pthread_mutex_unlock(&s->qlock);
    if (!s->acceptor_started) {
        if (pthread_create(&s->acceptor, NULL, acceptor_main, s) != 0)
            return sy_error_set(err, SY_ERR_IO, "sy serve: cannot start the accepting thread");
        s->acceptor_started = true;
    }
    for (;;) {
        if (s->o.stop && *s->o.stop) break;
        if (s->o.max_lifetime_s > 0 && sy_time_now() - start > s->o.max_lifetime_s) {
            SLOG(s, "maximum lifetime of %.0f s reached, stopping", s->o.max_lifetime_s);
            break;
        }
        reap_peers(s);
        pthread_mutex_lock(&s->qlock);
        if (!s->qhead) {
            struct timespec ts;
            clock_gettime(CLOCK_REALTIME, &ts);
            ts.tv_nsec += 100000000L;
            if (ts.tv_nsec >= 1000000000L) ts.tv_sec++, ts.tv_nsec -= 1000000000L;
            pthread_cond_timedwait(&s->qcond, &s->qlock, &ts);
        }
        peer *job = s->qhead;
        if (job) {
            s->qhead = job->qnext;
            if (!s->qhead) s->qtail = NULL;
        }
        pthread_mutex_unlock(&s->qlock);
        if (!job) continue;
        serve_job(s, job);
        pthread_mutex_lock(&s->qlock);
        job->done = true;
        pthread_cond_broadcast(&s->dcond);
        pthread_mutex_unlock(&s->qlock);
    }
    /* stop: no new connections, every connection closed, every reader thread joined */
    s->listener->ops->close(s->listener);
    if (s->acceptor_started) pthread_join(s->acceptor, NULL);
    s->acceptor_started = false;
    pthread_mutex_lock(&s->qlock);
    s->stopping = true;
    for (peer *j = s->qhead; j; j = j->qnext) {
        j->reply.size = 0;
        j->done = true;
    }
    s->qhead = s->qtail = NULL;
    pthread_cond_broadcast(&s->dcond);
    pthread_mutex_unlock(&s->qlock);
    pthread_mutex_lock(&s->mem_lock);
    s->mem_stopping = true;
    pthread_cond_broadcast(&s->mem_cond);
    pthread_mutex_unlock(&s->mem_lock);
    pthread_mutex_lock(&s->lock);
    for (peer *p = s->peers; p; p = p->next) p->w.st->ops->close(p->w.st);
    pthread_mutex_unlock(&s->lock);
    for (;;) {
        reap_peers(s);
        pthread_mutex_lock(&s->lock);
        bool left = s->peers != NULL;
        pthread_mutex_unlock(&s->lock);
        if (!left) break;
        struct timespec ts = {0, 5000000L};
        nanosleep(&ts, NULL);
    }
    return SY_OK;
}

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
} conn;

struct sy_cluster_client {
    sy_cluster_client_opts o;
    sy_scene *scene;
    uint8_t *secret;
    conn *conns;
    uint32_t n;
    uint64_t frame;
    uint32_t coop_next; /* cooperative: first sample index of the next frame (ranges never repeat) */
    size_t max_frame, max_message;
    uint32_t timeout_ms, connect_timeout_ms;
    char *tls_ca; /* owned copy of the CA file path */
};

#define CLOG(c, ...) log_line((c)->o.log, (c)->o.log_user, SY_LOG_NOTE, "cluster.client", "sy cluster", __VA_ARGS__)
#define CWARN(c, ...) log_line((c)->o.log, (c)->o.log_user, SY_LOG_WARNING, "cluster.client", "sy cluster", __VA_ARGS__)

static void conn_close(conn *k)
{
    if (k->w.st) k->w.st->ops->free(k->w.st);
    sodium_memzero(k->w.key, sizeof k->w.key);
    memset(&k->w, 0, sizeof k->w);
    k->live = k->session_open = false;
}

/* Bytes a message body may have on this connection (what the server accepts). */
static uint64_t conn_body_limit(const conn *k)
{
    return k->session_open ? k->srv_max_message : SY_CLUSTER_HANDSHAKE_MAX_FRAME - SY_CLUSTER_HEADER_SIZE;
}

/* One request/reply exchange within timeout_ms (the handshake's deadline before the session is
 * open). *reply borrows *raw (free it with free() after sy_cluster_msg_free). */
static sy_result conn_call(sy_cluster_client *c, conn *k, sy_cluster_msg *req, const sy_cluster_buf *preencoded,
                           uint32_t expect, sy_cluster_msg *reply, uint8_t **raw, sy_error *err)
{
    *raw = NULL;
    memset(reply, 0, sizeof *reply);
    if (!k->w.st) return sy_error_set(err, SY_ERR_IO, "%s: not connected", k->url);
    double deadline = sy_time_now() + (k->session_open ? c->timeout_ms : c->connect_timeout_ms) / 1000.0;
    sy_cluster_buf buf = {0};
    const sy_cluster_buf *b = preencoded;
    sy_result r = SY_OK;
    if (!b) {
        r = sy_cluster_encode(req, 0, &buf, err);
        b = &buf;
    }
    if (r == SY_OK && b->size - SY_CLUSTER_HEADER_SIZE > conn_body_limit(k))
        r = sy_error_set(err, SY_ERR_LIMIT, "%s: a %s of %zu bytes exceeds the server's message limit of %llu", k->url,
                         sy_cluster_msg_type_name((uint32_t)b->data[6] | ((uint32_t)b->data[7] << 8)),
                         b->size - SY_CLUSTER_HEADER_SIZE, (unsigned long long)conn_body_limit(k));
    if (r == SY_OK) {
        uint64_t seq0 = k->w.send_seq;
        size_t max_frame = k->session_open ? k->srv_max_frame : SY_CLUSTER_HANDSHAKE_MAX_FRAME;
        r = wire_send(&k->w, b->data, b->size, max_frame, deadline, 0, k->url, err);
        uint64_t frames = k->w.send_seq - seq0; /* headers and tags of every frame, plus the body */
        if (frames)
            k->bytes_sent += b->size + (frames - 1) * SY_CLUSTER_HEADER_SIZE + (k->w.tagged ? frames * SY_CLUSTER_TAG_SIZE : 0);
    }
    sy_cluster_buf_free(&buf);
    if (r) return r;
    const sy_cluster_budget budget = k->session_open
                                         ? (sy_cluster_budget){c->max_frame, c->max_message, true, k->w.tagged}
                                         : (sy_cluster_budget){SY_CLUSTER_HANDSHAKE_MAX_FRAME,
                                                               SY_CLUSTER_HANDSHAKE_MAX_FRAME, false, false};
    rx_msg in;
    uint64_t rseq0 = k->w.recv_seq;
    r = wire_recv(&k->w, &budget, NULL, 0, NULL, deadline, 0, &in, k->url, err);
    if (r) {
        if (k->w.last_rv == SY_STREAM_TIMEDOUT) sy_error_set(err, SY_ERR_IO, "%s: no reply before the deadline", k->url);
        return r;
    }
    k->bytes_received += in.size + (k->w.recv_seq - rseq0) * SY_CLUSTER_HEADER_SIZE +
                         (k->w.tagged ? (k->w.recv_seq - rseq0) * SY_CLUSTER_TAG_SIZE : 0);
    sy_cluster_limits lim = {c->max_message};
    r = sy_cluster_decode_body(&in.h, in.body, in.size, &lim, reply, err);
    if (r) {
        sy_error_prefix(err, "%s", k->url);
    } else {
        if (reply->header.type == SY_CLUSTER_ERROR) {
            r = sy_error_set(err, SY_ERR_PROTOCOL, "%s: server rejected the request: %s", k->url, reply->u.error.reason);
        } else if (reply->header.type != expect &&
                   !(expect == SY_CLUSTER_SCENE_ACK && reply->header.type == SY_CLUSTER_BLOB_REQUEST)) {
            r = sy_error_set(err, SY_ERR_PROTOCOL, "%s: expected %s, got %s", k->url, sy_cluster_msg_type_name(expect),
                             sy_cluster_msg_type_name(reply->header.type));
        }
        if (r) sy_cluster_msg_free(reply);
    }
    if (r) free(in.body);
    else *raw = in.body;
    return r;
}

/* Dials (within the connect timeout), then HELLO / CHALLENGE (/ AUTH / WELCOME). */
static sy_result conn_connect(sy_cluster_client *c, conn *k, sy_error *err)
{
    conn_close(k);
    sy_cluster_dial_opts dopts = {c->o.tls_ca_file, c->connect_timeout_ms};
    sy_result dr = sy_cluster_dial(k->url, &dopts, &k->w.st, err);
    if (dr != SY_OK) {
        conn_close(k);
        return dr;
    }
    sy_cluster_msg m, rep;
    memset(&m, 0, sizeof m);
    m.header.type = SY_CLUSTER_HELLO;
    uint8_t cnonce[32];
    randombytes_buf(cnonce, 32);
    memcpy(m.u.hello.nonce, cnonce, 32);
    m.u.hello.max_frame = (uint32_t)c->max_frame;
    m.u.hello.max_message = c->max_message;
    snprintf(m.u.hello.name, sizeof m.u.hello.name, "sy client");
    uint8_t *raw = NULL;
    sy_result r = conn_call(c, k, &m, NULL, SY_CLUSTER_CHALLENGE, &rep, &raw, err);
    if (r == SY_OK) {
        bool need = rep.u.hello.flags & 1u;
        uint8_t snonce[32];
        memcpy(snonce, rep.u.hello.nonce, 32);
        k->srv_max_frame = rep.u.hello.max_frame;
        k->srv_max_message = rep.u.hello.max_message;
        sy_cluster_msg_free(&rep);
        free(raw);
        if (need && !c->secret)
            r = sy_error_set(err, SY_ERR_PROTOCOL, "%s: server requires a shared secret (SY_CLUSTER_SECRET or --secret-file)",
                             k->url);
        else if (!need && c->secret)
            r = sy_error_set(err, SY_ERR_PROTOCOL, "%s: server does not authenticate but a secret was given; refusing",
                             k->url);
        else if (need) {
            memset(&m, 0, sizeof m);
            m.header.type = SY_CLUSTER_AUTH;
            mac3(m.u.auth.mac, c->secret, c->o.secret_len, "SYCP-client", snonce, cnonce);
            r = conn_call(c, k, &m, NULL, SY_CLUSTER_WELCOME, &rep, &raw, err);
            if (r == SY_OK) {
                uint8_t expect[32];
                mac3(expect, c->secret, c->o.secret_len, "SYCP-server", cnonce, snonce);
                if (crypto_verify_32(expect, rep.u.auth.mac) != 0)
                    r = sy_error_set(err, SY_ERR_PROTOCOL, "%s: the server's proof does not match (wrong secret or impostor)",
                                     k->url);
                sy_cluster_msg_free(&rep);
                free(raw);
                mac3(k->w.key, c->secret, c->o.secret_len, "SYCP-session", cnonce, snonce);
                k->w.tagged = true;
            }
        }
    }
    if (r) {
        conn_close(k);
        return r;
    }
    k->session_open = true;
    k->live = true;
    k->fresh = true;
    return SY_OK;
}

sy_result sy_cluster_client_create(sy_scene *scene, const sy_cluster_client_opts *opts, sy_cluster_client **out,
                                   sy_error *err)
{
    *out = NULL;
    if (!crypto_ready()) return sy_error_set(err, SY_ERR_BACKEND, "cluster: libsodium failed to initialise");
    if (!opts->url_count || opts->url_count > SY_CLUSTER_MAX_SERVERS)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cluster: between 1 and %u server URLs needed, got %u",
                            SY_CLUSTER_MAX_SERVERS, opts->url_count);
    size_t max_frame = opts->max_frame ? opts->max_frame : SY_CLUSTER_DEFAULT_MAX_FRAME;
    size_t max_message = opts->max_message ? opts->max_message : SY_CLUSTER_DEFAULT_MAX_MESSAGE;
    if (max_frame < SY_CLUSTER_MIN_FRAME || max_frame > SY_CLUSTER_MAX_FRAME_LIMIT || max_message < SY_CLUSTER_MIN_FRAME ||
        max_message > SY_CLUSTER_MAX_MESSAGE_LIMIT)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                            "cluster: frame limit %zu (64 KiB..1 GiB) or message limit %zu (>= 64 KiB) out of range",
                            max_frame, max_message);
    sy_cluster_client *c = calloc(1, sizeof *c);
    if (!c) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "cluster: out of memory");
    c->o = *opts;
    c->scene = scene;
    c->n = opts->url_count;
    c->timeout_ms = opts->timeout_ms ? opts->timeout_ms : 60000;
    c->connect_timeout_ms = opts->connect_timeout_ms ? opts->connect_timeout_ms : 5000;
    c->max_frame = max_frame;
    c->max_message = max_message;
    c->conns = calloc(c->n, sizeof *c->conns);
    if (opts->secret_len) {
        c->secret = malloc(opts->secret_len);
        if (c->secret) memcpy(c->secret, opts->secret, opts->secret_len);
    }
    if (!c->conns || (opts->secret_len && !c->secret)) {
        sy_cluster_client_destroy(c);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "cluster: out of memory");
    }
    c->o.urls = NULL;
    if (opts->tls_ca_file) {
        c->tls_ca = strdup(opts->tls_ca_file);
        if (!c->tls_ca) {
            sy_cluster_client_destroy(c);
            return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "cluster: out of memory");
        }
    }
    c->o.tls_ca_file = c->tls_ca;
    uint32_t live = 0;
    sy_error first = {0};
    for (uint32_t i = 0; i < c->n; ++i) {
        conn *k = &c->conns[i];
        if (strlen(opts->urls[i]) >= sizeof k->url) {
            sy_cluster_client_destroy(c);
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cluster: URL %u is too long", i);
        }
        copy_str(k->url, sizeof k->url, opts->urls[i]);
        if (opts->backends && opts->backends[i]) {
            if (strlen(opts->backends[i]) >= sizeof k->backend) {
                sy_cluster_client_destroy(c);
                return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cluster: back-end name of server %u is too long", i);
            }
            copy_str(k->backend, sizeof k->backend, opts->backends[i]);
        }
        if (opts->wall_tiles) k->wall = opts->wall_tiles[i];
        sy_error e = {0};
        if (conn_connect(c, k, &e) == SY_OK) live++;
        else {
            CWARN(c, "%s", e.message);
            copy_str(k->error, sizeof k->error, e.message);
            if (!first.code) first = e;
        }
    }
    if (!live) {
        sy_cluster_client_destroy(c);
        return sy_error_set(err, first.code ? first.code : SY_ERR_IO, "cluster: no server reachable: %s", first.message);
    }
    *out = c;
    return SY_OK;
}

uint32_t sy_cluster_client_live(const sy_cluster_client *c)
{
    uint32_t n = 0;
    for (uint32_t i = 0; i < c->n; ++i) n += c->conns[i].live;
    return n;
}

void sy_cluster_client_set_timeout(sy_cluster_client *c, uint32_t timeout_ms)
{
    c->timeout_ms = timeout_ms ? timeout_ms : 60000;
}

void sy_cluster_client_destroy(sy_cluster_client *c)
{
    if (!c) return;
    c->timeout_ms = 1000;
    for (uint32_t i = 0; c->conns && i < c->n; ++i) {
        conn *k = &c->conns[i];
        if (k->live) {
            sy_cluster_msg m, rep;
            memset(&m, 0, sizeof m);
            m.header.type = SY_CLUSTER_BYE;
            uint8_t *raw = NULL;
            sy_error e = {0};
            if (conn_call(c, k, &m, NULL, SY_CLUSTER_BYE, &rep, &raw, &e) == SY_OK) {
                sy_cluster_msg_free(&rep);
                free(raw);
            }
        }
        conn_close(k);
        sy_cluster_buf_free(&k->scene_msg);
        sy_blob_store_destroy(k->offered);
        if (k->has_consumer) sy_scene_consumer_remove(c->scene, k->consumer);
    }
    free(c->tls_ca);
    if (c->secret) sodium_memzero(c->secret, c->o.secret_len);
    free(c->secret);
    free(c->conns);
    free(c);
}

/* ---- per-frame work ---- */
typedef struct work_item {
    uint32_t eye; /* index into the frame's views: 0 mono / left, 1 right */
    sy_cluster_rect rect;
    uint32_t sample_first, sample_count;
    int owner;
    bool done;
} work_item;

typedef struct frame_ctx {
    sy_cluster_client *c;
    const sy_cluster_frame *f;
    sy_camera_view views[2];
    uint32_t eye_ids[2];
    sy_layer *out;
    sy_layer *accum; /* cooperative: one full layer per connection */
    uint64_t *accum_samples;
    work_item *items;
    uint32_t item_count;
    double *server_seconds;
} frame_ctx;

typedef struct thread_arg {
    frame_ctx *fc;
    uint32_t conn;
    bool send_scene;
    bool failed;
} thread_arg;

/* Change lists name every blob by hash only; the blob is kept to answer the server's request.
 * (The store only retains the immutable blob: the cast drops the const of the borrowed pointer.) */
static bool blob_send_cb(void *user, const sy_blob *b)
{
    conn *k = user;
    sy_error e = {0};
    if (sy_blob_store_put(k->offered, (sy_blob *)b, &e) != SY_OK) k->offer_failed = true;
    return false;
}

static sy_result run_item(frame_ctx *fc, conn *k, uint32_t idx, work_item *it, sy_error *err)
{
    sy_cluster_client *c = fc->c;
    const sy_cluster_frame *f = fc->f;
    sy_cluster_msg m, rep;
    memset(&m, 0, sizeof m);
    m.header.type = SY_CLUSTER_RENDER;
    __typeof__(m.u.render) *q = &m.u.render;
    q->frame = c->frame;
    q->job = (uint32_t)(it - fc->items);
    q->flags = (f->depth ? SY_CLUSTER_RENDER_DEPTH : 0) | (f->mode == SY_CLUSTER_MULTI_DISPLAY ? SY_CLUSTER_RENDER_PRESENT : 0) |
               (f->half ? SY_CLUSTER_RENDER_HALF : 0);
    copy_str(q->backend, sizeof q->backend, k->backend[0] ? k->backend : f->backend);
    copy_str(q->params, sizeof q->params, f->params ? f->params : "");
    q->root_id = f->root_id;
    q->background_id = f->background_id;
    q->seed = f->seed;
    /* cooperative: a back-end that numbers samples by its own accumulation (and ignores
     * sample_first) still draws an independent stream per server when each server has its own
     * seed; the seed stays the same across frames, so the server keeps accumulating */
    if (f->mode == SY_CLUSTER_COOPERATIVE) q->seed = f->seed + idx * 2654435761u;
    q->eye = fc->eye_ids[it->eye];
    q->sample_first = it->sample_first;
    q->sample_count = it->sample_count;
    q->full_width = f->width;
    q->full_height = f->height;
    q->camera = fc->views[it->eye];
    q->tile_count = 1;
    q->tiles = &it->rect;
    uint8_t *raw = NULL;
    sy_result r = conn_call(c, k, &m, NULL, SY_CLUSTER_TILES, &rep, &raw, err);
    if (r) return r;
    const __typeof__(rep.u.tiles) *t = &rep.u.tiles;
    uint32_t expect_tiles = f->mode == SY_CLUSTER_MULTI_DISPLAY ? 0 : 1;
    if (t->frame != c->frame || t->job != q->job || t->tile_count != expect_tiles)
        r = sy_error_set(err, SY_ERR_PROTOCOL, "%s: reply for frame %llu job %u with %u tiles does not match the request",
                         k->url, (unsigned long long)t->frame, t->job, t->tile_count);
    if (!r && expect_tiles) {
        const sy_cluster_tile *tl = &t->tiles[0];
        if (memcmp(&tl->rect, &it->rect, sizeof tl->rect) != 0)
            r = sy_error_set(err, SY_ERR_PROTOCOL, "%s: tile rectangle differs from the request", k->url);
        else if (f->mode == SY_CLUSTER_COOPERATIVE) {
            r = sy_cluster_tile_decode(tl, &fc->accum[idx], tl->rect.x, tl->rect.y, err);
            if (!r) fc->accum_samples[idx] = t->samples;
        } else {
            uint32_t ox = it->eye * f->width;
            r = sy_cluster_tile_decode(tl, fc->out, tl->rect.x + ox, tl->rect.y, err);
        }
    }
    if (!r) {
        fc->server_seconds[idx] += t->sync_seconds + t->render_seconds;
        k->last_seconds = t->render_seconds;
        k->last_rows = it->rect.h;
    }
    sy_cluster_msg_free(&rep);
    free(raw);
    return r;
}

/* Sends the frame's SCENE; while the server answers BLOB_REQUEST, sends the blobs it names (BLOBS
 * messages of at most a quarter of the message limit each, at least one blob) until SCENE_ACK. */
static sy_result send_scene(sy_cluster_client *c, conn *k, sy_error *err)
{
    sy_cluster_msg rep;
    uint8_t *raw = NULL;
    sy_result r = conn_call(c, k, NULL, &k->scene_msg, SY_CLUSTER_SCENE_ACK, &rep, &raw, err);
    for (uint32_t rounds = 0; r == SY_OK && rep.header.type == SY_CLUSTER_BLOB_REQUEST; ++rounds) {
        const __typeof__(rep.u.blobs) *q = &rep.u.blobs;
        sy_cluster_blob_ref *refs = calloc(q->count, sizeof *refs);
        sy_cluster_msg m;
        memset(&m, 0, sizeof m);
        m.header.type = SY_CLUSTER_BLOBS;
        m.u.blobs.frame = c->frame;
        m.u.blobs.blobs = refs;
        /* BLOBS messages of at most SY_CLUSTER_BLOBS_BATCH (or half the server's message limit), at
         * least one blob; the transport splits each into frames the server accepts */
        uint64_t bytes = 0, budget = k->srv_max_message / 2 < SY_CLUSTER_BLOBS_BATCH ? k->srv_max_message / 2
                                                                                    : SY_CLUSTER_BLOBS_BATCH;
        if (!refs) r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "cluster: out of memory");
        else if (q->frame != c->frame || rounds > SY_CLUSTER_MAX_BLOBS)
            r = sy_error_set(err, SY_ERR_PROTOCOL, "%s: blob request for frame %llu during frame %llu", k->url,
                             (unsigned long long)q->frame, (unsigned long long)c->frame);
        for (uint32_t i = 0; r == SY_OK && i < q->count; ++i) {
            const sy_blob *b = k->offered ? sy_blob_store_get(k->offered, q->blobs[i].hash) : NULL;
            if (!b || sy_blob_size(b) != q->blobs[i].size) {
                r = sy_error_set(err, SY_ERR_PROTOCOL, "%s: server asked for blob %016llx%016llx, which the scene does not name",
                                 k->url, (unsigned long long)q->blobs[i].hash.hi, (unsigned long long)q->blobs[i].hash.lo);
                break;
            }
            if (m.u.blobs.count && bytes + sy_blob_size(b) > budget) break; /* the rest in the next BLOBS */
            refs[m.u.blobs.count++] = (sy_cluster_blob_ref){q->blobs[i].hash, sy_blob_size(b), sy_blob_data(b)};
            bytes += sy_blob_size(b);
        }
        sy_cluster_msg_free(&rep);
        free(raw);
        raw = NULL;
        if (r == SY_OK) {
            uint64_t before = k->bytes_sent;
            r = conn_call(c, k, &m, NULL, SY_CLUSTER_SCENE_ACK, &rep, &raw, err);
            k->blob_frames_bytes += k->bytes_sent - before;
            k->blob_payload_bytes += bytes;
        }
        free(refs);
    }
    if (r == SY_OK) {
        sy_cluster_msg_free(&rep);
        free(raw);
    }
    return r;
}

static void *conn_thread(void *p)
{
    thread_arg *a = p;
    frame_ctx *fc = a->fc;
    sy_cluster_client *c = fc->c;
    conn *k = &c->conns[a->conn];
    sy_error err = {0};
    sy_result r = SY_OK;
    if (a->send_scene && k->scene_msg.size) r = send_scene(c, k, &err);
    for (uint32_t i = 0; r == SY_OK && i < fc->item_count; ++i) {
        work_item *it = &fc->items[i];
        if (it->owner != (int)a->conn || it->done) continue;
        r = run_item(fc, k, a->conn, it, &err);
        if (r == SY_OK) it->done = true;
    }
    if (r) {
        a->failed = true;
        copy_str(k->error, sizeof k->error, err.message);
    }
    return NULL;
}

/* Runs every live connection's items in parallel; returns the number of connections that failed. */
static uint32_t run_round(frame_ctx *fc, bool send_scene)
{
    sy_cluster_client *c = fc->c;
    thread_arg args[SY_CLUSTER_MAX_SERVERS];
    pthread_t th[SY_CLUSTER_MAX_SERVERS];
    bool started[SY_CLUSTER_MAX_SERVERS] = {0};
    for (uint32_t i = 0; i < c->n; ++i) {
        args[i] = (thread_arg){fc, i, send_scene, false};
        if (!c->conns[i].live) continue;
        bool has_work = send_scene && c->conns[i].scene_msg.size;
        for (uint32_t j = 0; j < fc->item_count && !has_work; ++j)
            has_work = fc->items[j].owner == (int)i && !fc->items[j].done;
        if (!has_work) continue;
        started[i] = pthread_create(&th[i], NULL, conn_thread, &args[i]) == 0;
        if (!started[i]) conn_thread(&args[i]);
    }
    uint32_t failed = 0;
    for (uint32_t i = 0; i < c->n; ++i) {
        if (started[i]) pthread_join(th[i], NULL);
        if (args[i].failed) {
            conn *k = &c->conns[i];
            CWARN(c, "%s: dropped for this frame: %s", k->url, k->error);
            conn_close(k);
            if (k->has_consumer) sy_scene_consumer_remove(c->scene, k->consumer);
            k->has_consumer = false;
            failed++;
        }
    }
    return failed;
}

/* Gives every unfinished item to live connections (splitting strips among them). */
static sy_result reassign(frame_ctx *fc, uint32_t *reassigned, sy_error *err)
{
    sy_cluster_client *c = fc->c;
    uint32_t live[SY_CLUSTER_MAX_SERVERS], nl = 0;
    for (uint32_t i = 0; i < c->n; ++i)
        if (c->conns[i].live) live[nl++] = i;
    uint32_t pending = 0;
    for (uint32_t j = 0; j < fc->item_count; ++j) pending += !fc->items[j].done;
    if (!pending) return SY_OK;
    if (!nl) {
        char why[SY_ERROR_MESSAGE_MAX] = "";
        for (uint32_t i = 0; i < c->n; ++i)
            if (c->conns[i].error[0]) {
                copy_str(why, sizeof why, c->conns[i].error);
                break;
            }
        return sy_error_set(err, SY_ERR_IO, "cluster: every server failed this frame (%s)", why);
    }
    if (fc->f->mode == SY_CLUSTER_MULTI_DISPLAY) {
        /* a wall tile belongs to its display: it cannot be shown elsewhere */
        for (uint32_t j = 0; j < fc->item_count; ++j) fc->items[j].done = true;
        return SY_OK;
    }
    uint32_t cur = fc->item_count;
    work_item *items = realloc(fc->items, (cur + (size_t)pending * nl) * sizeof *items);
    if (!items) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "cluster: out of memory");
    fc->items = items;
    uint32_t rr = 0;
    for (uint32_t j = 0; j < cur; ++j) {
        work_item it = fc->items[j];
        if (it.done) continue;
        fc->items[j].done = true; /* replaced by the new items */
        (*reassigned)++;
        if (fc->f->mode == SY_CLUSTER_COOPERATIVE || it.rect.h < nl) {
            it.owner = (int)live[rr++ % nl];
            fc->items[fc->item_count++] = it;
            continue;
        }
        for (uint32_t s = 0; s < nl; ++s) {
            work_item sub = it;
            uint32_t y0 = it.rect.y + (uint32_t)((uint64_t)it.rect.h * s / nl);
            uint32_t y1 = it.rect.y + (uint32_t)((uint64_t)it.rect.h * (s + 1) / nl);
            sub.rect.y = y0;
            sub.rect.h = y1 - y0;
            sub.owner = (int)live[s];
            fc->items[fc->item_count++] = sub;
        }
    }
    return SY_OK;
}

/* Splits items larger than a request may be (SY_CLUSTER_MAX_REQUEST_PIXELS) into row bands for
 * the same server. Multi-display tiles are presented whole and are never split. */
static sy_result split_large_items(frame_ctx *fc, sy_error *err)
{
    uint32_t extra = 0;
    for (uint32_t j = 0; j < fc->item_count; ++j) {
        uint64_t px = (uint64_t)fc->items[j].rect.w * fc->items[j].rect.h;
        extra += (uint32_t)((px + SY_CLUSTER_MAX_REQUEST_PIXELS - 1) / SY_CLUSTER_MAX_REQUEST_PIXELS) - 1;
    }
    if (!extra) return SY_OK;
    work_item *items = realloc(fc->items, ((size_t)fc->item_count + extra) * sizeof *items);
    if (!items) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "cluster: out of memory");
    fc->items = items;
    uint32_t n = fc->item_count;
    for (uint32_t j = 0; j < n; ++j) {
        work_item it = fc->items[j];
        uint32_t rows = SY_CLUSTER_MAX_REQUEST_PIXELS / it.rect.w; /* w <= 16384, so rows >= 4096 */
        if ((uint64_t)it.rect.w * it.rect.h <= SY_CLUSTER_MAX_REQUEST_PIXELS) continue;
        fc->items[j].rect.h = rows;
        for (uint32_t y = rows; y < it.rect.h; y += rows) {
            work_item band = it;
            band.rect.y = it.rect.y + y;
            band.rect.h = it.rect.h - y < rows ? it.rect.h - y : rows;
            fc->items[fc->item_count++] = band;
        }
    }
    return SY_OK;
}

/* Splits rows [0, h) into n strips with the given weights (each at least one row when h >= n). */
static void split_rows(uint32_t h, uint32_t n, const double *w, uint32_t *starts)
{
    double total = 0;
    for (uint32_t i = 0; i < n; ++i) total += w[i];
    double acc = 0;
    starts[0] = 0;
    for (uint32_t i = 1; i < n; ++i) {
        acc += w[i - 1];
        uint32_t y = (uint32_t)llround((double)h * acc / total);
        if (y < starts[i - 1] + (h >= n ? 1 : 0)) y = starts[i - 1] + (h >= n ? 1 : 0);
        if (h >= n && y > h - (n - i)) y = h - (n - i);
        if (y > h) y = h;
        starts[i] = y;
    }
    starts[n] = h;
}

sy_result sy_cluster_client_render(sy_cluster_client *c, const sy_cluster_frame *f, sy_layer *out,
                                   sy_cluster_frame_stats *stats, sy_error *err)
{
    double t0 = sy_time_now();
    sy_cluster_frame_stats st;
    memset(&st, 0, sizeof st);
    if (f->mode > SY_CLUSTER_STEREO || !f->backend || f->width < 1 || f->height < 1 ||
        f->width > SY_CLUSTER_MAX_IMAGE || f->height > SY_CLUSTER_MAX_IMAGE)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cluster render: bad mode, back-end or image size");
    uint32_t out_w = f->mode == SY_CLUSTER_STEREO ? 2 * f->width : f->width;
    if (f->mode != SY_CLUSTER_MULTI_DISPLAY && (!out || out->width != out_w || out->height != f->height))
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cluster render: output layer must be %ux%u", out_w, f->height);
    sy_result cr = sy_cluster_camera_check(&f->camera, err); /* refused here, before any server is involved */
    if (cr != SY_OK) {
        sy_error_prefix(err, "cluster render");
        return cr;
    }
    c->frame++;
    uint64_t sent0 = 0, recv0 = 0;
    uint64_t blobf0 = 0, blobp0 = 0;
    for (uint32_t i = 0; i < c->n; ++i) {
        sent0 += c->conns[i].bytes_sent, recv0 += c->conns[i].bytes_received;
        blobf0 += c->conns[i].blob_frames_bytes, blobp0 += c->conns[i].blob_payload_bytes;
    }
    /* 1. reconnect servers that are down (they will get a snapshot) */
    for (uint32_t i = 0; i < c->n; ++i) {
        conn *k = &c->conns[i];
        k->fresh = false;
        if (!k->live) {
            sy_error e = {0};
            if (conn_connect(c, k, &e) == SY_OK) CLOG(c, "%s: (re)connected, sending a snapshot", k->url);
            else copy_str(k->error, sizeof k->error, e.message);
        }
    }
    /* 2. change lists: every live connection pulls from its own consumer (a new one = snapshot) */
    sy_result r = SY_OK;
    for (uint32_t i = 0; i < c->n && r == SY_OK; ++i) {
        conn *k = &c->conns[i];
        k->scene_msg.size = 0;
        if (!k->live) continue;
        bool snapshot = false;
        if (!k->has_consumer) {
            r = sy_scene_consumer_add(c->scene, &k->consumer, err);
            if (r) break;
            k->has_consumer = true;
            snapshot = true;
        }
        sy_changes *ch = NULL;
        r = sy_scene_consumer_pull(c->scene, k->consumer, &ch, err);
        if (r) break;
        snapshot = snapshot || sy_changes_is_snapshot(ch);
        sy_blob_store_destroy(k->offered);
        k->offered = NULL;
        k->offer_failed = false;
        if (snapshot || sy_changes_count(ch) > 0) {
            void *data = NULL;
            size_t size = 0;
            r = sy_blob_store_create(&k->offered, err);
            if (r == SY_OK) r = sy_changes_serialize(ch, blob_send_cb, k, &data, &size, err);
            if (r == SY_OK && k->offer_failed) r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "cluster: out of memory");
            if (r == SY_OK && size > UINT32_MAX - 1024)
                r = sy_error_set(err, SY_ERR_LIMIT, "cluster: change list of %zu bytes is too large", size);
            if (r == SY_OK) {
                sy_cluster_msg m;
                memset(&m, 0, sizeof m);
                m.header.type = SY_CLUSTER_SCENE;
                m.u.scene.frame = c->frame;
                m.u.scene.flags = snapshot ? SY_CLUSTER_SCENE_SNAPSHOT : 0;
                m.u.scene.changes = data;
                m.u.scene.changes_size = (uint32_t)size;
                k->scene_msg.size = 0;
                r = sy_cluster_encode(&m, 0, &k->scene_msg, err); /* tagged frame by frame when sent */
                st.scene_bytes += k->scene_msg.size;
            }
            free(data);
        }
        sy_changes_release(ch);
    }
    if (r) return r;
    /* 3. work items */
    uint32_t live[SY_CLUSTER_MAX_SERVERS], nl = 0;
    for (uint32_t i = 0; i < c->n; ++i)
        if (c->conns[i].live) live[nl++] = i;
    if (!nl) return sy_error_set(err, SY_ERR_IO, "cluster: no server is reachable (%s)", c->conns[0].error);
    frame_ctx fc = {.c = c, .f = f, .out = out};
    fc.views[0] = f->camera;
    fc.eye_ids[0] = SY_EYE_MONO;
    if (f->mode == SY_CLUSTER_STEREO) {
        float sep = f->eye_separation > 0 ? f->eye_separation : 0.065f, zp = f->zero_parallax > 0 ? f->zero_parallax : 2.0f;
        fc.views[0] = sy_camera_view_eye(&f->camera, SY_EYE_LEFT, sep, zp);
        fc.views[1] = sy_camera_view_eye(&f->camera, SY_EYE_RIGHT, sep, zp);
        fc.eye_ids[0] = SY_EYE_LEFT;
        fc.eye_ids[1] = SY_EYE_RIGHT;
    }
    fc.items = calloc((size_t)nl * 2 + 2, sizeof *fc.items);
    fc.server_seconds = calloc(c->n, sizeof *fc.server_seconds);
    if (f->mode == SY_CLUSTER_COOPERATIVE) {
        fc.accum = calloc(c->n, sizeof *fc.accum);
        fc.accum_samples = calloc(c->n, sizeof *fc.accum_samples);
    }
    if (!fc.items || !fc.server_seconds || (f->mode == SY_CLUSTER_COOPERATIVE && (!fc.accum || !fc.accum_samples)))
        r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "cluster: out of memory");
    uint32_t spp = f->samples ? f->samples : (f->mode == SY_CLUSTER_COOPERATIVE ? 16 : 0);
    if (r == SY_OK) {
        if (f->mode == SY_CLUSTER_COOPERATIVE) {
            /* samples_total: split across the live servers (the first ones take one more); else spp each */
            uint64_t total = f->samples_total ? f->samples_total : (uint64_t)nl * spp, first = c->coop_next;
            for (uint32_t s = 0; s < nl && r == SY_OK; ++s) {
                uint32_t mine = f->samples_total ? (uint32_t)(total / nl + (s < total % nl)) : spp;
                if (!mine) continue; /* fewer samples than servers */
                r = sy_layer_create(f->width, f->height, &fc.accum[live[s]], err);
                fc.items[fc.item_count++] =
                    (work_item){0, {0, 0, f->width, f->height}, (uint32_t)first, mine, (int)live[s], false};
                first += mine;
            }
            if (first > UINT32_MAX - SY_CLUSTER_MAX_SAMPLES)
                r = sy_error_set(err, SY_ERR_LIMIT, "cluster: the cooperative sample index would overflow");
            c->coop_next = (uint32_t)first;
        } else if (f->mode == SY_CLUSTER_STEREO) {
            uint32_t groups = nl >= 2 ? 2 : 1;
            for (uint32_t eye = 0; eye < 2; ++eye) {
                uint32_t members[SY_CLUSTER_MAX_SERVERS], nm = 0;
                for (uint32_t s = 0; s < nl; ++s)
                    if (groups == 1 || s % 2 == eye) members[nm++] = live[s];
                double w[SY_CLUSTER_MAX_SERVERS];
                uint32_t starts[SY_CLUSTER_MAX_SERVERS + 1];
                for (uint32_t s = 0; s < nm; ++s) w[s] = 1;
                uint32_t parts = nm < f->height ? nm : f->height;
                split_rows(f->height, parts, w, starts);
                for (uint32_t s = 0; s < parts; ++s)
                    fc.items[fc.item_count++] =
                        (work_item){eye, {0, starts[s], f->width, starts[s + 1] - starts[s]}, 0, spp, (int)members[s], false};
            }
        } else if (f->mode == SY_CLUSTER_MULTI_DISPLAY) {
            /* a wall: server i owns its configured tile, else column i of n */
            for (uint32_t i = 0; i < c->n && r == SY_OK; ++i) {
                uint32_t x0 = (uint32_t)((uint64_t)f->width * i / c->n), x1 = (uint32_t)((uint64_t)f->width * (i + 1) / c->n);
                sy_cluster_rect t = {x0, 0, x1 - x0, f->height}, wt = c->conns[i].wall;
                if (wt.w) {
                    if (wt.h == 0 || wt.x >= f->width || wt.y >= f->height || wt.w > f->width - wt.x ||
                        wt.h > f->height - wt.y)
                        r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                                         "cluster: wall tile %ux%u at %u,%u of %s lies outside the %ux%u wall", wt.w, wt.h,
                                         wt.x, wt.y, c->conns[i].url, f->width, f->height);
                    t = wt;
                }
                if (r == SY_OK && t.w > 0 && c->conns[i].live)
                    fc.items[fc.item_count++] = (work_item){0, t, 0, spp, (int)i, false};
            }
        } else {
            double w[SY_CLUSTER_MAX_SERVERS];
            uint32_t starts[SY_CLUSTER_MAX_SERVERS + 1];
            for (uint32_t s = 0; s < nl; ++s) {
                conn *k = &c->conns[live[s]];
                w[s] = 1.0;
                if (f->mode == SY_CLUSTER_BALANCED && k->last_seconds > 0 && k->last_rows > 0)
                    w[s] = (double)k->last_rows / k->last_seconds; /* rows per second */
            }
            if (f->mode == SY_CLUSTER_BALANCED) {
                bool all = true;
                for (uint32_t s = 0; s < nl; ++s) all = all && c->conns[live[s]].last_seconds > 0;
                if (!all)
                    for (uint32_t s = 0; s < nl; ++s) w[s] = 1.0;
            }
            uint32_t parts = nl < f->height ? nl : f->height;
            split_rows(f->height, parts, w, starts);
            for (uint32_t s = 0; s < parts; ++s)
                if (starts[s + 1] > starts[s])
                    fc.items[fc.item_count++] =
                        (work_item){0, {0, starts[s], f->width, starts[s + 1] - starts[s]}, 0, spp, (int)live[s], false};
        }
    }
    if (r == SY_OK && f->mode != SY_CLUSTER_MULTI_DISPLAY) r = split_large_items(&fc, err);
    /* 4. rounds: scene + work, then failed work to the survivors, until done */
    bool first = true;
    for (uint32_t round = 0; r == SY_OK && round <= c->n; ++round) {
        st.servers_failed += run_round(&fc, first);
        first = false;
        r = reassign(&fc, &st.reassigned, err);
        bool left = false;
        for (uint32_t j = 0; j < fc.item_count; ++j) left = left || !fc.items[j].done;
        if (!left) break;
        if (round == c->n) r = sy_error_set(err, SY_ERR_IO, "cluster: work left after %u rounds", round + 1);
    }
    /* 5. cooperative: merge the accumulations weighted by their sample counts */
    if (r == SY_OK && f->mode == SY_CLUSTER_COOPERATIVE) {
        uint64_t total = 0;
        for (uint32_t i = 0; i < c->n; ++i)
            if (fc.accum[i].rgba && fc.accum_samples[i]) total += fc.accum_samples[i];
        if (!total) r = sy_error_set(err, SY_ERR_IO, "cluster: no server returned samples");
        size_t px = (size_t)f->width * f->height;
        for (size_t p = 0; r == SY_OK && p < px; ++p) {
            /* depth as a local render keeps it: the mean over the samples that hit (each server's
             * mean weighted by its samples times its coverage, alpha), +INFINITY where none hit */
            double acc[4] = {0, 0, 0, 0}, dsum = 0, dwgt = 0;
            for (uint32_t i = 0; i < c->n; ++i) {
                if (!fc.accum[i].rgba || !fc.accum_samples[i]) continue;
                double wgt = (double)fc.accum_samples[i];
                for (int ch = 0; ch < 4; ++ch) acc[ch] += wgt * fc.accum[i].rgba[p * 4 + ch];
                float d = fc.accum[i].depth[p];
                if (isfinite(d)) {
                    double a = fc.accum[i].rgba[p * 4 + 3], dw = wgt * (a > 1e-6 ? a : 1e-6);
                    dsum += dw * d, dwgt += dw;
                }
            }
            for (int ch = 0; ch < 4; ++ch) out->rgba[p * 4 + ch] = (float)(acc[ch] / (double)total);
            if (out->depth) out->depth[p] = dwgt > 0 ? (float)(dsum / dwgt) : INFINITY;
        }
        st.samples = total;
    }
    /* 6. multi-display: the swap barrier, once every display holds its tile */
    if (r == SY_OK && f->mode == SY_CLUSTER_MULTI_DISPLAY) {
        for (uint32_t i = 0; i < c->n; ++i) {
            conn *k = &c->conns[i];
            if (!k->live) continue;
            sy_cluster_msg m, rep;
            memset(&m, 0, sizeof m);
            m.header.type = SY_CLUSTER_SWAP;
            m.u.ack.frame = c->frame;
            uint8_t *raw = NULL;
            sy_error e = {0};
            if (conn_call(c, k, &m, NULL, SY_CLUSTER_SWAP_ACK, &rep, &raw, &e) == SY_OK) {
                sy_cluster_msg_free(&rep);
                free(raw);
            } else {
                CWARN(c, "%s: swap failed: %s", k->url, e.message);
                conn_close(k);
                if (k->has_consumer) sy_scene_consumer_remove(c->scene, k->consumer);
                k->has_consumer = false;
                st.servers_failed++;
            }
        }
    }
    for (uint32_t i = 0; i < c->n; ++i) {
        if (fc.server_seconds && fc.server_seconds[i] > st.max_server_seconds) st.max_server_seconds = fc.server_seconds[i];
        if (fc.accum) sy_layer_destroy(&fc.accum[i]);
        st.bytes_sent += c->conns[i].bytes_sent;
        st.bytes_received += c->conns[i].bytes_received;
        st.scene_bytes += c->conns[i].blob_frames_bytes;
        st.blob_bytes += c->conns[i].blob_payload_bytes;
        sy_blob_store_destroy(c->conns[i].offered); /* the frame's blobs are on the servers now */
        c->conns[i].offered = NULL;
    }
    st.bytes_sent -= sent0;
    st.bytes_received -= recv0;
    st.scene_bytes -= blobf0;
    st.blob_bytes -= blobp0;
    free(fc.accum);
    free(fc.accum_samples);
    free(fc.items);
    free(fc.server_seconds);
    st.servers_live = sy_cluster_client_live(c);
    st.seconds = sy_time_now() - t0;
    if (stats) *stats = st;
    return r;
}
