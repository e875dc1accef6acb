/* sy_cluster_proto.c — cluster message encoder and decoder (see sy_cluster_proto.h and
 * docs/PROTOCOL.md). All integers little endian; strings are u16 length + bytes (no NUL on the
 * wire, no embedded NUL accepted); floats are IEEE-754 binary32 / binary64 bit patterns. */
#include "sy_cluster_proto.h"

#define IMATH_HALF_NO_LOOKUP_TABLE
#include <half.h> /* Imath (libimath-dev): binary16 conversions */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- writer ---- */
void sy_cluster_buf_free(sy_cluster_buf *b)
{
    if (!b) return;
    free(b->data);
    memset(b, 0, sizeof *b);
}

typedef struct writer {
    sy_cluster_buf *b;
    bool failed;
} writer;

static void w_bytes(writer *w, const void *p, size_t n)
{
    if (w->failed || n == 0) return;
    sy_cluster_buf *b = w->b;
    size_t need;
    if (!sy_size_add(b->size, n, &need)) {
        w->failed = true;
        return;
    }
    if (need > b->cap) {
        size_t cap = b->cap ? b->cap : 256;
        while (cap < need) {
            if (cap > SIZE_MAX / 2) {
                w->failed = true;
                return;
            }
            cap *= 2;
        }
        uint8_t *d = realloc(b->data, cap);
        if (!d) {
            w->failed = true;
            return;
        }
        b->data = d;
        b->cap = cap;
    }
    memcpy(b->data + b->size, p, n);
    b->size = need;
}

static void w_u16(writer *w, uint16_t v)
{
    uint8_t b[2] = {(uint8_t)v, (uint8_t)(v >> 8)};
    w_bytes(w, b, 2);
}
static void w_u32(writer *w, uint32_t v)
{
    uint8_t b[4];
    for (int i = 0; i < 4; ++i) b[i] = (uint8_t)(v >> (8 * i));
    w_bytes(w, b, 4);
}
/* A rectangle on the wire: x, y, w, h. */
static void w_rect(writer *w, const sy_cluster_rect *r)
{
    w_u32(w, r->x);
    w_u32(w, r->y);
    w_u32(w, r->w);
    w_u32(w, r->h);
}
static void w_u64(writer *w, uint64_t v)
{
    uint8_t b[8];
    for (int i = 0; i < 8; ++i) b[i] = (uint8_t)(v >> (8 * i));
    w_bytes(w, b, 8);
}
static void w_f32(writer *w, float f)
{
    uint32_t v;
    memcpy(&v, &f, 4);
    w_u32(w, v);
}
static void w_f64(writer *w, double f)
{
    uint64_t v;
    memcpy(&v, &f, 8);
    w_u64(w, v);
}
static void w_str(writer *w, const char *s)
{
    size_t n = strlen(s);
    w_u16(w, (uint16_t)n);
    w_bytes(w, s, n);
}

static void put_u32_at(uint8_t *p, uint32_t v)
{
    for (int i = 0; i < 4; ++i) p[i] = (uint8_t)(v >> (8 * i));
}

const char *sy_cluster_msg_type_name(uint32_t type)
{
    static const char *names[] = {"?",     "HELLO", "CHALLENGE", "AUTH", "WELCOME",  "SCENE", "SCENE_ACK",
                                  "RENDER", "TILES", "SWAP",      "SWAP_ACK", "BYE", "ERROR", "BLOB_REQUEST",
                                  "BLOBS"};
    return type <= SY_CLUSTER_MSG_TYPE_MAX ? names[type] : "?";
}

static bool str_fits(const char *s, size_t max)
{
    return memchr(s, 0, max) != NULL;
}

static bool rect_ok(const sy_cluster_rect *r, uint32_t fw, uint32_t fh)
{
    return r->w > 0 && r->h > 0 && r->x < fw && r->y < fh && r->w <= fw - r->x && r->h <= fh - r->y;
}

sy_result sy_cluster_camera_check(const sy_camera_view *c, sy_error *err)
{
    sy_result r = sy_camera_view_check(c, err); /* the core rule: finite, within SY_COORD_MAX */
    if (r != SY_OK) return r;
    if (c->projection > 1)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "camera projection %u is unknown", (unsigned)c->projection);
    if (c->znear < 0 || c->zfar < 0)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "camera clip range %g..%g is negative", (double)c->znear,
                            (double)c->zfar);
    if (!(c->window[0] < c->window[1] && c->window[2] < c->window[3]))
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "camera window [%g %g %g %g] is empty", (double)c->window[0],
                            (double)c->window[1], (double)c->window[2], (double)c->window[3]);
    return SY_OK;
}

sy_result sy_cluster_encode(const sy_cluster_msg *msg, uint32_t flags, sy_cluster_buf *out, sy_error *err)
{
    const char *tn = sy_cluster_msg_type_name(msg->header.type);
    if (msg->header.type < 1 || msg->header.type > SY_CLUSTER_MSG_TYPE_MAX)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cluster encode: unknown message type %u",
                            (unsigned)msg->header.type);
    if (flags & ~(uint32_t)SY_CLUSTER_FLAG_TAGGED)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cluster encode %s: unknown frame flags 0x%x", tn, flags);
    size_t start = out->size;
    writer w = {out, false};
    w_u32(&w, SY_CLUSTER_MAGIC);
    w_u16(&w, SY_CLUSTER_VERSION);
    w_u16(&w, msg->header.type);
    w_u32(&w, flags);
    w_u32(&w, 0); /* body size, patched below */
    w_u64(&w, msg->header.seq);
    const uint32_t t = msg->header.type;
    if (t == SY_CLUSTER_HELLO || t == SY_CLUSTER_CHALLENGE) {
        if (!str_fits(msg->u.hello.name, SY_CLUSTER_NAME_MAX))
            return out->size = start, sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cluster encode %s: name too long", tn);
        if (msg->u.hello.max_frame < SY_CLUSTER_MIN_FRAME || msg->u.hello.max_frame > SY_CLUSTER_MAX_FRAME_LIMIT ||
            msg->u.hello.max_message < SY_CLUSTER_MIN_FRAME || msg->u.hello.max_message > SY_CLUSTER_MAX_MESSAGE_LIMIT)
            return out->size = start, sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cluster encode %s: frame or message limit out of range", tn);
        w_bytes(&w, msg->u.hello.nonce, SY_CLUSTER_NONCE_SIZE);
        w_u32(&w, msg->u.hello.flags);
        w_u32(&w, msg->u.hello.max_frame);
        w_u64(&w, msg->u.hello.max_message);
        w_str(&w, msg->u.hello.name);
    } else if (t == SY_CLUSTER_AUTH || t == SY_CLUSTER_WELCOME) {
        w_bytes(&w, msg->u.auth.mac, SY_CLUSTER_TAG_SIZE);
    } else if (t == SY_CLUSTER_SCENE) {
        w_u64(&w, msg->u.scene.frame);
        w_u32(&w, msg->u.scene.flags);
        w_u32(&w, msg->u.scene.changes_size);
        w_bytes(&w, msg->u.scene.changes, msg->u.scene.changes_size);
    } else if (t == SY_CLUSTER_SCENE_ACK || t == SY_CLUSTER_SWAP || t == SY_CLUSTER_SWAP_ACK) {
        w_u64(&w, msg->u.ack.frame);
        w_u32(&w, msg->u.ack.objects);
    } else if (t == SY_CLUSTER_RENDER) {
        const __typeof__(msg->u.render) *r = &msg->u.render;
        if (!str_fits(r->backend, SY_CLUSTER_BACKEND_MAX) || !str_fits(r->params, SY_CLUSTER_PARAMS_MAX))
            return out->size = start, sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cluster encode RENDER: back-end or params too long");
        if (r->full_width < 1 || r->full_width > SY_CLUSTER_MAX_IMAGE || r->full_height < 1 ||
            r->full_height > SY_CLUSTER_MAX_IMAGE || r->tile_count > SY_CLUSTER_MAX_TILES)
            return out->size = start, sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cluster encode RENDER: image size or tiles out of range");
        sy_error ce = {0};
        if (sy_cluster_camera_check(&r->camera, &ce) != SY_OK)
            return out->size = start, sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cluster encode RENDER: %s", ce.message);
        if (!(r->time >= 0.0 && r->time <= SY_CLUSTER_MAX_TIME) ||
            (!(r->flags & SY_CLUSTER_RENDER_TIME) && (r->time != 0.0 || r->clip_id != 0)))
            return out->size = start, sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                                                   "cluster encode RENDER: scene time %g outside 0..1e9 s or without the time flag",
                                                   r->time);
        for (uint32_t i = 0; i < r->tile_count; ++i)
            if (!rect_ok(&r->tiles[i], r->full_width, r->full_height))
                return out->size = start, sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cluster encode RENDER: tile %u outside the image", i);
        w_u64(&w, r->frame);
        w_u32(&w, r->job);
        w_u32(&w, r->flags);
        w_str(&w, r->backend);
        w_str(&w, r->params);
        w_u32(&w, r->root_id);
        w_u32(&w, r->background_id);
        w_u32(&w, r->seed);
        w_u32(&w, r->eye);
        w_u32(&w, r->sample_first);
        w_u32(&w, r->sample_count);
        w_u32(&w, r->full_width);
        w_u32(&w, r->full_height);
        for (int i = 0; i < 16; ++i) w_f32(&w, r->camera.camera_to_world.m[i]);
        w_u32(&w, r->camera.projection);
        for (int i = 0; i < 4; ++i) w_f32(&w, r->camera.window[i]);
        w_f32(&w, r->camera.znear);
        w_f32(&w, r->camera.zfar);
        w_u32(&w, r->camera.clip_count); /* section planes (protocol 4) */
        for (uint32_t i = 0; i < r->camera.clip_count && i < SY_CLIP_PLANES_MAX; ++i)
            for (int k = 0; k < 4; ++k) w_f32(&w, r->camera.clip_planes[i][k]);
        w_u32(&w, r->camera.clip_cap ? 1u : 0u); /* section caps (protocol 6): on, linear RGB */
        for (int k = 0; k < 3; ++k) w_f32(&w, r->camera.clip_cap ? r->camera.clip_cap_color[k] : 0.0f);
        w_f64(&w, r->time); /* the scene clock (protocol 5) */
        w_u32(&w, r->clip_id);
        w_u32(&w, r->tile_count);
        for (uint32_t i = 0; i < r->tile_count; ++i) w_rect(&w, &r->tiles[i]);
    } else if (t == SY_CLUSTER_TILES) {
        const __typeof__(msg->u.tiles) *r = &msg->u.tiles;
        if (r->tile_count > SY_CLUSTER_MAX_TILES)
            return out->size = start, sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cluster encode TILES: too many tiles");
        w_u64(&w, r->frame);
        w_u32(&w, r->job);
        w_f64(&w, r->sync_seconds);
        w_f64(&w, r->render_seconds);
        w_u64(&w, r->samples);
        w_u32(&w, r->tile_count);
        for (uint32_t i = 0; i < r->tile_count; ++i) {
            const sy_cluster_tile *tl = &r->tiles[i];
            w_rect(&w, &tl->rect);
            w_u32(&w, tl->encoding);
            w_u32(&w, tl->channels);
            w_u64(&w, tl->raw_size);
            w_u32(&w, tl->data_size);
            w_bytes(&w, tl->data, tl->data_size);
        }
    } else if (t == SY_CLUSTER_ERROR) {
        if (!str_fits(msg->u.error.reason, SY_CLUSTER_REASON_MAX))
            return out->size = start, sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cluster encode ERROR: reason too long");
        w_u32(&w, msg->u.error.code);
        w_str(&w, msg->u.error.reason);
    } else if (t == SY_CLUSTER_BLOB_REQUEST || t == SY_CLUSTER_BLOBS) {
        const __typeof__(msg->u.blobs) *q = &msg->u.blobs;
        if (q->count < 1 || q->count > SY_CLUSTER_MAX_BLOBS)
            return out->size = start, sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cluster encode %s: %u blobs (1..%u)", tn,
                                                   q->count, SY_CLUSTER_MAX_BLOBS);
        w_u64(&w, q->frame);
        w_u32(&w, q->count);
        for (uint32_t i = 0; i < q->count; ++i) {
            w_u64(&w, q->blobs[i].hash.lo);
            w_u64(&w, q->blobs[i].hash.hi);
            w_u64(&w, q->blobs[i].size);
            if (t == SY_CLUSTER_BLOBS) {
                if (q->blobs[i].size > SIZE_MAX) w.failed = true;
                else w_bytes(&w, q->blobs[i].data, (size_t)q->blobs[i].size);
            }
        }
    } /* BYE: empty body */
    if (w.failed) {
        out->size = start;
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "cluster encode %s: out of memory", tn);
    }
    size_t body = out->size - start - SY_CLUSTER_HEADER_SIZE;
    if (body > UINT32_MAX - SY_CLUSTER_TAG_SIZE - SY_CLUSTER_HEADER_SIZE) {
        out->size = start;
        return sy_error_set(err, SY_ERR_LIMIT, "cluster encode %s: body of %zu bytes is too large", tn, body);
    }
    put_u32_at(out->data + start + 12, (uint32_t)body);
    return SY_OK;
}

void sy_cluster_header_write(uint8_t out[SY_CLUSTER_HEADER_SIZE], uint32_t type, uint32_t flags, uint32_t body_size,
                             uint64_t seq)
{
    put_u32_at(out, SY_CLUSTER_MAGIC);
    out[4] = (uint8_t)SY_CLUSTER_VERSION;
    out[5] = (uint8_t)(SY_CLUSTER_VERSION >> 8);
    out[6] = (uint8_t)type;
    out[7] = (uint8_t)(type >> 8);
    put_u32_at(out + 8, flags);
    put_u32_at(out + 12, body_size);
    put_u32_at(out + 16, (uint32_t)seq);
    put_u32_at(out + 20, (uint32_t)(seq >> 32));
}

/* ---- reader ---- */
typedef struct reader {
    const uint8_t *p;
    size_t size, pos;
    const char *what; /* message type name */
    sy_error *err;
    sy_result r;
} reader;

static bool rd_fail(reader *rd, sy_result code, const char *reason)
{
    if (rd->r == SY_OK) rd->r = sy_error_set(rd->err, code, "cluster %s: body byte %zu: %s", rd->what, rd->pos, reason);
    return false;
}

/* Room for a list of count records (NULL when count is 0 or the reader has failed), zeroed, elem
 * bytes each, after checking that they fit in the rest of the body at wire_bytes each; fails the
 * reader with "truncated LIST" or "out of memory for the LIST". */
static void *rd_list(reader *rd, uint32_t count, size_t wire_bytes, size_t elem, const char *list)
{
    char why[64];
    if (rd->r || !count) return NULL;
    if ((size_t)count * wire_bytes > rd->size - rd->pos) {
        snprintf(why, sizeof why, "truncated %s", list);
        rd_fail(rd, SY_ERR_PARSE, why);
        return NULL;
    }
    void *p = calloc(count, elem);
    if (!p) {
        snprintf(why, sizeof why, "out of memory for the %s", list);
        rd_fail(rd, SY_ERR_OUT_OF_MEMORY, why);
    }
    return p;
}

static bool rd_bytes(reader *rd, void *out, size_t n)
{
    if (rd->r) return false;
    if (n > rd->size - rd->pos) return rd_fail(rd, SY_ERR_PARSE, "truncated message");
    if (out) memcpy(out, rd->p + rd->pos, n);
    rd->pos += n;
    return true;
}
static uint16_t rd_u16(reader *rd)
{
    uint8_t b[2] = {0, 0};
    rd_bytes(rd, b, 2);
    return (uint16_t)(b[0] | (b[1] << 8));
}
static uint32_t rd_u32(reader *rd)
{
    uint8_t b[4] = {0};
    rd_bytes(rd, b, 4);
    return (uint32_t)b[0] | ((uint32_t)b[1] << 8) | ((uint32_t)b[2] << 16) | ((uint32_t)b[3] << 24);
}
static void rd_rect(reader *rd, sy_cluster_rect *r)
{
    r->x = rd_u32(rd);
    r->y = rd_u32(rd);
    r->w = rd_u32(rd);
    r->h = rd_u32(rd);
}
static uint64_t rd_u64(reader *rd)
{
    uint64_t lo = rd_u32(rd), hi = rd_u32(rd);
    return lo | (hi << 32);
}
static float rd_f32(reader *rd)
{
    uint32_t v = rd_u32(rd);
    float f;
    memcpy(&f, &v, 4);
    return f;
}
static double rd_f64(reader *rd)
{
    uint64_t v = rd_u64(rd);
    double f;
    memcpy(&f, &v, 8);
    return f;
}
/* u16 length + bytes into a NUL-terminated buffer of cap bytes */
static bool rd_str(reader *rd, char *out, size_t cap, const char *field)
{
    uint16_t n = rd_u16(rd);
    if (rd->r) return false;
    if ((size_t)n >= cap) {
        char m[96];
        snprintf(m, sizeof m, "%s of %u bytes exceeds the limit of %zu", field, (unsigned)n, cap - 1);
        return rd_fail(rd, SY_ERR_LIMIT, m);
    }
    if (!rd_bytes(rd, out, n)) return false;
    out[n] = 0;
    if (memchr(out, 0, n)) return rd_fail(rd, SY_ERR_PARSE, "string contains a NUL byte");
    return true;
}

sy_result sy_cluster_parse_header(const uint8_t data[SY_CLUSTER_HEADER_SIZE], sy_cluster_header *out, sy_error *err)
{
    reader rd = {data, SY_CLUSTER_HEADER_SIZE, 0, "header", err, SY_OK};
    sy_cluster_header h;
    h.magic = rd_u32(&rd);
    h.version = rd_u16(&rd);
    h.type = rd_u16(&rd);
    h.flags = rd_u32(&rd);
    h.body_size = rd_u32(&rd);
    h.seq = rd_u64(&rd);
    if (h.magic != SY_CLUSTER_MAGIC)
        return sy_error_set(err, SY_ERR_PARSE, "cluster message: bad magic 0x%08x (not a Switchyard cluster peer)",
                            (unsigned)h.magic);
    if (h.version != SY_CLUSTER_VERSION)
        return sy_error_set(err, SY_ERR_UNSUPPORTED, "cluster message: protocol version %u, this peer speaks %u",
                            (unsigned)h.version, SY_CLUSTER_VERSION);
    if (h.type < 1 || h.type > SY_CLUSTER_MSG_TYPE_MAX)
        return sy_error_set(err, SY_ERR_PARSE, "cluster message: unknown type %u", (unsigned)h.type);
    if (h.flags & ~(uint32_t)(SY_CLUSTER_FLAG_TAGGED | SY_CLUSTER_FLAG_MORE))
        return sy_error_set(err, SY_ERR_PARSE, "cluster %s: unknown frame flags 0x%x", sy_cluster_msg_type_name(h.type),
                            (unsigned)h.flags);
    *out = h;
    return SY_OK;
}

sy_result sy_cluster_frame_check(const sy_cluster_header *h, const sy_cluster_budget *b, size_t so_far,
                                 uint32_t msg_type, size_t *follow_out, sy_error *err)
{
    const char *tn = sy_cluster_msg_type_name(h->type);
    bool tagged = (h->flags & SY_CLUSTER_FLAG_TAGGED) != 0, more = (h->flags & SY_CLUSTER_FLAG_MORE) != 0;
    *follow_out = 0;
    if (tagged != b->tagged)
        return sy_error_set(err, SY_ERR_PROTOCOL, "cluster %s: frame %s, the session requires %s", tn,
                            tagged ? "is tagged" : "is not authenticated (no tag)", b->tagged ? "a tag" : "none yet");
    if (more && !b->chunks)
        return sy_error_set(err, SY_ERR_PROTOCOL, "cluster %s: a chunked message before the session is open", tn);
    if ((so_far || msg_type) && h->type != msg_type)
        return sy_error_set(err, SY_ERR_PROTOCOL, "cluster %s: frame continues a %s message", tn,
                            sy_cluster_msg_type_name(msg_type));
    uint64_t frame = (uint64_t)SY_CLUSTER_HEADER_SIZE + h->body_size + (tagged ? SY_CLUSTER_TAG_SIZE : 0);
    if (frame > b->max_frame)
        return sy_error_set(err, SY_ERR_LIMIT, "cluster %s: frame announces %llu bytes, this connection accepts at most %zu",
                            tn, (unsigned long long)frame, b->max_frame);
    if (h->body_size > b->max_message || so_far > b->max_message - h->body_size)
        return sy_error_set(err, SY_ERR_LIMIT, "cluster %s: message of %llu bytes so far exceeds the limit of %zu", tn,
                            (unsigned long long)so_far + h->body_size, b->max_message);
    *follow_out = (size_t)(frame - SY_CLUSTER_HEADER_SIZE);
    return SY_OK;
}

sy_result sy_cluster_decode_header(const void *data, size_t size, const sy_cluster_limits *limits,
                                   sy_cluster_header *out, sy_error *err)
{
    size_t max = limits && limits->max_message ? limits->max_message : SY_CLUSTER_DEFAULT_MAX_MESSAGE;
    if (!data || size < SY_CLUSTER_HEADER_SIZE)
        return sy_error_set(err, SY_ERR_PARSE, "cluster message: %zu bytes is shorter than the %u-byte header", size,
                            SY_CLUSTER_HEADER_SIZE);
    if (size > max)
        return sy_error_set(err, SY_ERR_LIMIT, "cluster message: %zu bytes exceeds the limit of %zu", size, max);
    sy_cluster_header h;
    sy_result r = sy_cluster_parse_header(data, &h, err);
    if (r) return r;
    uint64_t expect = (uint64_t)SY_CLUSTER_HEADER_SIZE + h.body_size + ((h.flags & SY_CLUSTER_FLAG_TAGGED) ? SY_CLUSTER_TAG_SIZE : 0);
    if (expect != size)
        return sy_error_set(err, SY_ERR_PARSE, "cluster %s: header announces %llu bytes, the frame has %zu",
                            sy_cluster_msg_type_name(h.type), (unsigned long long)expect, size);
    *out = h;
    return SY_OK;
}

void sy_cluster_msg_free(sy_cluster_msg *m)
{
    if (!m) return;
    if (m->header.type == SY_CLUSTER_RENDER) free(m->u.render.tiles);
    if (m->header.type == SY_CLUSTER_TILES) free(m->u.tiles.tiles);
    if (m->header.type == SY_CLUSTER_BLOB_REQUEST || m->header.type == SY_CLUSTER_BLOBS) free(m->u.blobs.blobs);
    memset(m, 0, sizeof *m);
}

sy_result sy_cluster_decode(const void *data, size_t size, const sy_cluster_limits *limits, sy_cluster_msg *out,
                            sy_error *err)
{
    memset(out, 0, sizeof *out);
    sy_cluster_header h;
    sy_result r = sy_cluster_decode_header(data, size, limits, &h, err);
    if (r) return r;
    if (h.flags & SY_CLUSTER_FLAG_MORE)
        return sy_error_set(err, SY_ERR_PARSE, "cluster %s: one frame of a chunked message (reassemble it first)",
                            sy_cluster_msg_type_name(h.type));
    return sy_cluster_decode_body(&h, (const uint8_t *)data + SY_CLUSTER_HEADER_SIZE, h.body_size, limits, out, err);
}

sy_result sy_cluster_decode_body(const sy_cluster_header *hp, const void *body, size_t size,
                                 const sy_cluster_limits *limits, sy_cluster_msg *out, sy_error *err)
{
    memset(out, 0, sizeof *out);
    size_t max = limits && limits->max_message ? limits->max_message : SY_CLUSTER_DEFAULT_MAX_MESSAGE;
    sy_cluster_header h = *hp;
    if (h.type < 1 || h.type > SY_CLUSTER_MSG_TYPE_MAX)
        return sy_error_set(err, SY_ERR_PARSE, "cluster message: unknown type %u", (unsigned)h.type);
    if (!body && size) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cluster message: no body");
    if (size > max)
        return sy_error_set(err, SY_ERR_LIMIT, "cluster %s: body of %zu bytes exceeds the limit of %zu",
                            sy_cluster_msg_type_name(h.type), size, max);
    h.body_size = size > UINT32_MAX ? UINT32_MAX : (uint32_t)size;
    static const uint8_t empty[1];
    /* offsets in messages count from the start of the body */
    reader rd = {body ? body : empty, size, 0, sy_cluster_msg_type_name(h.type), err, SY_OK};
    sy_cluster_msg m;
    memset(&m, 0, sizeof m);
    m.header = h;
    const uint32_t t = h.type;
    if (t == SY_CLUSTER_HELLO || t == SY_CLUSTER_CHALLENGE) {
        rd_bytes(&rd, m.u.hello.nonce, SY_CLUSTER_NONCE_SIZE);
        m.u.hello.flags = rd_u32(&rd);
        m.u.hello.max_frame = rd_u32(&rd);
        m.u.hello.max_message = rd_u64(&rd);
        if (!rd.r && (m.u.hello.max_frame < SY_CLUSTER_MIN_FRAME || m.u.hello.max_frame > SY_CLUSTER_MAX_FRAME_LIMIT))
            rd_fail(&rd, SY_ERR_PARSE, "frame limit outside 64 KiB..1 GiB");
        if (!rd.r && (m.u.hello.max_message < SY_CLUSTER_MIN_FRAME || m.u.hello.max_message > SY_CLUSTER_MAX_MESSAGE_LIMIT))
            rd_fail(&rd, SY_ERR_PARSE, "message limit outside 64 KiB..1 TiB");
        rd_str(&rd, m.u.hello.name, SY_CLUSTER_NAME_MAX, "name");
    } else if (t == SY_CLUSTER_AUTH || t == SY_CLUSTER_WELCOME) {
        rd_bytes(&rd, m.u.auth.mac, SY_CLUSTER_TAG_SIZE);
    } else if (t == SY_CLUSTER_SCENE) {
        m.u.scene.frame = rd_u64(&rd);
        m.u.scene.flags = rd_u32(&rd);
        m.u.scene.changes_size = rd_u32(&rd);
        if (!rd.r && (m.u.scene.flags & ~(uint32_t)SY_CLUSTER_SCENE_SNAPSHOT)) rd_fail(&rd, SY_ERR_PARSE, "unknown scene flags");
        if (!rd.r) m.u.scene.changes = rd.p + rd.pos;
        rd_bytes(&rd, NULL, m.u.scene.changes_size);
    } else if (t == SY_CLUSTER_SCENE_ACK || t == SY_CLUSTER_SWAP || t == SY_CLUSTER_SWAP_ACK) {
        m.u.ack.frame = rd_u64(&rd);
        m.u.ack.objects = rd_u32(&rd);
    } else if (t == SY_CLUSTER_RENDER) {
        __typeof__(m.u.render) *q = &m.u.render;
        sy_error ce = {0};
        q->frame = rd_u64(&rd);
        q->job = rd_u32(&rd);
        q->flags = rd_u32(&rd);
        if (!rd.r && (q->flags & ~(uint32_t)(SY_CLUSTER_RENDER_DEPTH | SY_CLUSTER_RENDER_PRESENT | SY_CLUSTER_RENDER_HALF |
                                             SY_CLUSTER_RENDER_RESTART | SY_CLUSTER_RENDER_TIME)))
            rd_fail(&rd, SY_ERR_PARSE, "unknown render flags");
        rd_str(&rd, q->backend, SY_CLUSTER_BACKEND_MAX, "back-end name");
        rd_str(&rd, q->params, SY_CLUSTER_PARAMS_MAX, "parameters");
        q->root_id = rd_u32(&rd);
        q->background_id = rd_u32(&rd);
        q->seed = rd_u32(&rd);
        q->eye = rd_u32(&rd);
        q->sample_first = rd_u32(&rd);
        q->sample_count = rd_u32(&rd);
        q->full_width = rd_u32(&rd);
        q->full_height = rd_u32(&rd);
        for (int i = 0; i < 16; ++i) q->camera.camera_to_world.m[i] = rd_f32(&rd);
        q->camera.projection = rd_u32(&rd);
        for (int i = 0; i < 4; ++i) q->camera.window[i] = rd_f32(&rd);
        q->camera.znear = rd_f32(&rd);
        q->camera.zfar = rd_f32(&rd);
        q->camera.clip_count = rd_u32(&rd);
        if (!rd.r && q->camera.clip_count > SY_CLIP_PLANES_MAX)
            rd_fail(&rd, SY_ERR_LIMIT, "more than 6 section planes");
        for (uint32_t i = 0; !rd.r && i < q->camera.clip_count; ++i)
            for (int k = 0; k < 4; ++k) q->camera.clip_planes[i][k] = rd_f32(&rd);
        q->camera.clip_cap = rd_u32(&rd); /* section caps (protocol 6); the colour: sy_cluster_camera_check */
        if (!rd.r && q->camera.clip_cap > 1) rd_fail(&rd, SY_ERR_PARSE, "section cap flag must be 0 or 1");
        for (int k = 0; k < 3; ++k) q->camera.clip_cap_color[k] = rd_f32(&rd);
        q->time = rd_f64(&rd);
        q->clip_id = rd_u32(&rd);
        if (!rd.r && !(q->time >= 0.0 && q->time <= SY_CLUSTER_MAX_TIME)) /* NaN fails too */
            rd_fail(&rd, SY_ERR_PARSE, "scene time outside 0..1e9 seconds");
        else if (!rd.r && !(q->flags & SY_CLUSTER_RENDER_TIME) && (q->time != 0.0 || q->clip_id != 0))
            rd_fail(&rd, SY_ERR_PARSE, "a scene time or clip without the time flag");
        q->tile_count = rd_u32(&rd);
        if (!rd.r) {
            if (q->eye > 2) rd_fail(&rd, SY_ERR_PARSE, "eye must be 0 (mono), 1 (left) or 2 (right)");
            else if (q->full_width < 1 || q->full_width > SY_CLUSTER_MAX_IMAGE || q->full_height < 1 ||
                     q->full_height > SY_CLUSTER_MAX_IMAGE)
                rd_fail(&rd, SY_ERR_LIMIT, "image size outside 1..16384");
            else if (q->sample_count > SY_CLUSTER_MAX_SAMPLES || q->sample_first > UINT32_MAX - q->sample_count)
                rd_fail(&rd, SY_ERR_LIMIT, "sample range out of bounds");
            else if (sy_cluster_camera_check(&q->camera, &ce) != SY_OK)
                rd_fail(&rd, SY_ERR_PARSE, ce.message);
            else if (q->tile_count < 1 || q->tile_count > SY_CLUSTER_MAX_TILES)
                rd_fail(&rd, SY_ERR_LIMIT, "tile count outside 1..4096");
        }
        q->tiles = rd_list(&rd, q->tile_count, 16, sizeof *q->tiles, "tile list");
        for (uint32_t i = 0; !rd.r && i < q->tile_count; ++i) {
            sy_cluster_rect *tr = &q->tiles[i];
            rd_rect(&rd, tr);
            if (!rd.r && !rect_ok(tr, q->full_width, q->full_height)) rd_fail(&rd, SY_ERR_PARSE, "tile outside the image or empty");
        }
    } else if (t == SY_CLUSTER_TILES) {
        __typeof__(m.u.tiles) *q = &m.u.tiles;
        q->frame = rd_u64(&rd);
        q->job = rd_u32(&rd);
        q->sync_seconds = rd_f64(&rd);
        q->render_seconds = rd_f64(&rd);
        q->samples = rd_u64(&rd);
        q->tile_count = rd_u32(&rd);
        if (!rd.r) {
            if (!isfinite(q->sync_seconds) || !isfinite(q->render_seconds) || q->sync_seconds < 0 || q->render_seconds < 0)
                rd_fail(&rd, SY_ERR_PARSE, "timings must be finite and non-negative");
            else if (q->tile_count > SY_CLUSTER_MAX_TILES) rd_fail(&rd, SY_ERR_LIMIT, "more than 4096 tiles");
        }
        q->tiles = rd_list(&rd, q->tile_count, 36, sizeof *q->tiles, "tile list");
        for (uint32_t i = 0; !rd.r && i < q->tile_count; ++i) {
            sy_cluster_tile *tl = &q->tiles[i];
            rd_rect(&rd, &tl->rect);
            tl->encoding = rd_u32(&rd);
            tl->channels = rd_u32(&rd);
            tl->raw_size = rd_u64(&rd);
            tl->data_size = rd_u32(&rd);
            if (rd.r) break;
            if (!rect_ok(&tl->rect, SY_CLUSTER_MAX_IMAGE, SY_CLUSTER_MAX_IMAGE)) {
                rd_fail(&rd, SY_ERR_PARSE, "tile rectangle empty or outside 16384x16384");
                break;
            }
            uint32_t vb = sy_cluster_encoding_bytes(tl->encoding);
            if (!vb) {
                rd_fail(&rd, SY_ERR_UNSUPPORTED, "unknown tile encoding");
                break;
            }
            if (tl->channels != 4 && tl->channels != 5) {
                rd_fail(&rd, SY_ERR_PARSE, "tile channels must be 4 or 5");
                break;
            }
            if (tl->raw_size != (uint64_t)tl->rect.w * tl->rect.h * tl->channels * vb) {
                rd_fail(&rd, SY_ERR_PARSE, "tile raw size does not match its rectangle");
                break;
            }
            tl->data = rd.p + rd.pos;
            rd_bytes(&rd, NULL, tl->data_size);
        }
    } else if (t == SY_CLUSTER_ERROR) {
        m.u.error.code = rd_u32(&rd);
        rd_str(&rd, m.u.error.reason, SY_CLUSTER_REASON_MAX, "reason");
    } else if (t == SY_CLUSTER_BLOB_REQUEST || t == SY_CLUSTER_BLOBS) {
        __typeof__(m.u.blobs) *q = &m.u.blobs;
        q->frame = rd_u64(&rd);
        q->count = rd_u32(&rd);
        if (!rd.r && (q->count < 1 || q->count > SY_CLUSTER_MAX_BLOBS))
            rd_fail(&rd, SY_ERR_LIMIT, "blob count outside 1..1048576");
        q->blobs = rd_list(&rd, q->count, 24, sizeof *q->blobs, "blob list");
        for (uint32_t i = 0; !rd.r && i < q->count; ++i) {
            sy_cluster_blob_ref *b = &q->blobs[i];
            b->hash.lo = rd_u64(&rd);
            b->hash.hi = rd_u64(&rd);
            b->size = rd_u64(&rd);
            if (rd.r || t != SY_CLUSTER_BLOBS) continue;
            if (b->size > rd.size - rd.pos) {
                rd_fail(&rd, SY_ERR_PARSE, "blob payload runs past the end of the message");
                break;
            }
            b->data = rd.p + rd.pos;
            rd_bytes(&rd, NULL, (size_t)b->size);
        }
    }
    if (!rd.r && rd.pos != rd.size) rd_fail(&rd, SY_ERR_PARSE, "trailing bytes after the body");
    if (rd.r) {
        sy_cluster_msg_free(&m);
        return rd.r;
    }
    *out = m;
    return SY_OK;
}

/* ---- tile encodings and binary16 ---- */
uint32_t sy_cluster_encoding_bytes(uint32_t encoding)
{
    return encoding == SY_CLUSTER_ENC_F32_SHUFFLE_ZSTD ? 4u : encoding == SY_CLUSTER_ENC_F16_SHUFFLE_ZSTD ? 2u : 0u;
}

/* binary16 conversions: Imath's C API (half.h, inline code; IMATH_HALF_NO_LOOKUP_TABLE keeps it from
 * needing libImath's table): round to nearest even, overflow to infinity, NaNs keep sign and payload. */
uint16_t sy_cluster_half_from_float(float f) { return imath_float_to_half(f); }

float sy_cluster_half_to_float(uint16_t h) { return imath_half_to_float(h); }
