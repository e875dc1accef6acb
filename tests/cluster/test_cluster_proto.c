/* test_cluster_proto.c — the cluster message encoder/decoder and the tile codec: round trips of
 * every message type, every truncation, wrong magic / version / type / flags, announced sizes that
 * lie, out-of-range fields, and a few thousand random mutations of valid frames (the decoder must
 * reject or accept cleanly, never crash, and whatever it accepts must be in range). Runs in every
 * build (the libFuzzer target in fuzz_cluster_decode.c covers the same decoder under SY_FUZZ). */
#include "../support/sy_check.h"
#include "frame_join.h"
#include "scene_msg.h"
#include "sy_cluster.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static uint64_t rng_state = 0x9E3779B97F4A7C15ull;
static uint32_t rnd(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return (uint32_t)(rng_state >> 11);
}

static sy_cluster_rect g_tiles[3] = {{0, 0, 64, 10}, {0, 10, 64, 20}, {10, 30, 5, 2}};
static uint8_t g_payload[100];
static sy_cluster_tile g_rtiles[2];
static sy_cluster_blob_ref g_blobs[2];

/* A valid message of each type. */
static sy_cluster_msg sample(uint32_t type)
{
    sy_cluster_msg m;
    memset(&m, 0, sizeof m);
    m.header.type = (uint16_t)type;
    m.header.seq = 7;
    switch (type) {
    case SY_CLUSTER_HELLO:
    case SY_CLUSTER_CHALLENGE:
        for (int i = 0; i < 32; ++i) m.u.hello.nonce[i] = (uint8_t)(i * 7);
        m.u.hello.flags = 1;
        m.u.hello.max_frame = 1u << 20;
        m.u.hello.max_message = (uint64_t)3 << 30;
        strcpy(m.u.hello.name, "node-1");
        break;
    case SY_CLUSTER_AUTH:
    case SY_CLUSTER_WELCOME:
        for (int i = 0; i < 32; ++i) m.u.auth.mac[i] = (uint8_t)(255 - i);
        break;
    case SY_CLUSTER_SCENE:
        m.u.scene.frame = 42;
        m.u.scene.flags = SY_CLUSTER_SCENE_SNAPSHOT;
        m.u.scene.changes = g_payload;
        m.u.scene.changes_size = sizeof g_payload;
        break;
    case SY_CLUSTER_SCENE_ACK:
    case SY_CLUSTER_SWAP:
    case SY_CLUSTER_SWAP_ACK:
        m.u.ack.frame = 99;
        m.u.ack.objects = 5;
        break;
    case SY_CLUSTER_RENDER:
        m.u.render.frame = 3;
        m.u.render.job = 2;
        m.u.render.flags = SY_CLUSTER_RENDER_DEPTH | SY_CLUSTER_RENDER_RESTART | SY_CLUSTER_RENDER_TIME;
        m.u.render.time = 2.5; /* the scene clock (protocol 5, frames mode) */
        m.u.render.clip_id = 0x20003;
        strcpy(m.u.render.backend, "whitted");
        strcpy(m.u.render.params, "max_depth=4");
        m.u.render.root_id = 0x10001;
        m.u.render.sample_first = 16;
        m.u.render.sample_count = 8;
        m.u.render.full_width = 64;
        m.u.render.full_height = 32;
        m.u.render.camera.camera_to_world = sy_mat4_identity();
        m.u.render.camera.window[0] = -1;
        m.u.render.camera.window[1] = 1;
        m.u.render.camera.window[2] = -0.5f;
        m.u.render.camera.window[3] = 0.5f;
        m.u.render.camera.znear = 0.1f;
        m.u.render.camera.clip_count = 2; /* section planes (protocol 4) */
        const float planes[2][4] = {{1, 0, 0, -0.25f}, {0, -0.5f, 0.5f, 2}};
        memcpy(m.u.render.camera.clip_planes, planes, sizeof planes);
        m.u.render.tile_count = 3;
        m.u.render.tiles = g_tiles;
        break;
    case SY_CLUSTER_TILES:
        m.u.tiles.frame = 3;
        m.u.tiles.job = 2;
        m.u.tiles.sync_seconds = 0.25;
        m.u.tiles.render_seconds = 1.5;
        m.u.tiles.samples = 24;
        m.u.tiles.tile_count = 2;
        g_rtiles[0] = (sy_cluster_tile){{0, 0, 2, 2}, SY_CLUSTER_ENC_F32_SHUFFLE_ZSTD, 4, 64, g_payload, 10};
        g_rtiles[1] = (sy_cluster_tile){{2, 0, 1, 1}, SY_CLUSTER_ENC_F32_SHUFFLE_ZSTD, 5, 20, g_payload + 10, 5};
        m.u.tiles.tiles = g_rtiles;
        break;
    case SY_CLUSTER_ERROR:
        m.u.error.code = SY_ERR_PROTOCOL;
        strcpy(m.u.error.reason, "nope");
        break;
    case SY_CLUSTER_BLOB_REQUEST:
    case SY_CLUSTER_BLOBS:
        m.u.blobs.frame = 11;
        m.u.blobs.count = 2;
        g_blobs[0] = (sy_cluster_blob_ref){sy_hash_bytes(g_payload, 30), 30, g_payload};
        g_blobs[1] = (sy_cluster_blob_ref){sy_hash_bytes(g_payload + 30, 0), 0, g_payload + 30};
        m.u.blobs.blobs = g_blobs;
        break;
    default: break;
    }
    return m;
}

static int test_round_trip(void)
{
    for (uint32_t t = 1; t <= SY_CLUSTER_MSG_TYPE_MAX; ++t) {
        sy_error e = {0};
        sy_cluster_msg m = sample(t), d;
        sy_cluster_buf b = {0};
        CHECK_OK(sy_cluster_encode(&m, 0, &b, &e), e);
        CHECK_OK(sy_cluster_decode(b.data, b.size, NULL, &d, &e), e);
        CHECK(d.header.type == t && d.header.seq == 7 && d.header.version == SY_CLUSTER_VERSION);
        if (t == SY_CLUSTER_HELLO) CHECK(!strcmp(d.u.hello.name, "node-1") && d.u.hello.nonce[3] == 21 && d.u.hello.flags == 1);
        if (t == SY_CLUSTER_CHALLENGE) CHECK(d.u.hello.max_frame == 1u << 20 && d.u.hello.max_message == (uint64_t)3 << 30);
        if (t == SY_CLUSTER_AUTH) CHECK(d.u.auth.mac[0] == 255 && d.u.auth.mac[31] == 224);
        if (t == SY_CLUSTER_SCENE) CHECK(d.u.scene.frame == 42 && d.u.scene.changes_size == 100 && d.u.scene.flags == 1);
        if (t == SY_CLUSTER_SWAP) CHECK(d.u.ack.frame == 99 && d.u.ack.objects == 5);
        if (t == SY_CLUSTER_RENDER) {
            CHECK(!strcmp(d.u.render.backend, "whitted") && !strcmp(d.u.render.params, "max_depth=4"));
            CHECK(d.u.render.tile_count == 3 && d.u.render.tiles[2].x == 10 && d.u.render.tiles[2].h == 2);
            CHECK(d.u.render.sample_first == 16 && d.u.render.sample_count == 8 && d.u.render.root_id == 0x10001);
            CHECK(d.u.render.camera.window[2] == -0.5f && d.u.render.camera.camera_to_world.m[15] == 1.0f);
            CHECK(d.u.render.time == 2.5 && d.u.render.clip_id == 0x20003 &&
                  d.u.render.flags == (SY_CLUSTER_RENDER_DEPTH | SY_CLUSTER_RENDER_RESTART | SY_CLUSTER_RENDER_TIME));
        }
        if (t == SY_CLUSTER_TILES) {
            CHECK(d.u.tiles.tile_count == 2 && d.u.tiles.tiles[1].channels == 5 && d.u.tiles.tiles[1].data_size == 5);
            CHECK(d.u.tiles.render_seconds == 1.5 && d.u.tiles.samples == 24);
            CHECK(d.u.tiles.tiles[1].data == b.data + (b.size - 5));
        }
        if (t == SY_CLUSTER_ERROR) CHECK(!strcmp(d.u.error.reason, "nope") && d.u.error.code == SY_ERR_PROTOCOL);
        if (t == SY_CLUSTER_BLOB_REQUEST || t == SY_CLUSTER_BLOBS) {
            CHECK(d.u.blobs.frame == 11 && d.u.blobs.count == 2 && d.u.blobs.blobs[0].size == 30);
            CHECK(sy_hash_equal(d.u.blobs.blobs[0].hash, g_blobs[0].hash) && d.u.blobs.blobs[1].size == 0);
            if (t == SY_CLUSTER_BLOBS) CHECK(memcmp(d.u.blobs.blobs[0].data, g_payload, 30) == 0);
            else CHECK(d.u.blobs.blobs[0].data == NULL && b.size == SY_CLUSTER_HEADER_SIZE + 12 + 2 * 24);
        }
        sy_cluster_msg_free(&d);
        /* every truncation is rejected */
        for (size_t n = 0; n < b.size; ++n) {
            CHECK_MSG(sy_cluster_decode(b.data, n, NULL, &d, &e) != SY_OK, "type %u truncated to %zu accepted", t, n);
        }
        sy_cluster_buf_free(&b);
    }
    return 0;
}

static void put32(uint8_t *p, uint32_t v)
{
    for (int i = 0; i < 4; ++i) p[i] = (uint8_t)(v >> (8 * i));
}

static int test_bad_headers(void)
{
    sy_error e = {0};
    sy_cluster_msg m = sample(SY_CLUSTER_RENDER), d;
    sy_cluster_buf b = {0};
    CHECK_OK(sy_cluster_encode(&m, 0, &b, &e), e);
    uint8_t *c = malloc(b.size + 64);
    CHECK(c != NULL);
    /* wrong magic */
    memcpy(c, b.data, b.size);
    c[0] ^= 1;
    CHECK_ERR(sy_cluster_decode(c, b.size, NULL, &d, &e), SY_ERR_PARSE, e);
    CHECK(strstr(e.message, "magic"));
    /* wrong version */
    memcpy(c, b.data, b.size);
    c[4] = 5; /* a version-5 peer (RENDER without the section caps) */
    CHECK_ERR(sy_cluster_decode(c, b.size, NULL, &d, &e), SY_ERR_UNSUPPORTED, e);
    CHECK(strstr(e.message, "version 5, this peer speaks 6"));
    /* unknown type, unknown flags */
    memcpy(c, b.data, b.size);
    c[6] = 200;
    CHECK_ERR(sy_cluster_decode(c, b.size, NULL, &d, &e), SY_ERR_PARSE, e);
    memcpy(c, b.data, b.size);
    c[8] = 0x80;
    CHECK_ERR(sy_cluster_decode(c, b.size, NULL, &d, &e), SY_ERR_PARSE, e);
    /* oversized announced body, undersized announced body, trailing bytes */
    memcpy(c, b.data, b.size);
    put32(c + 12, 0xFFFFFFF0u);
    CHECK_ERR(sy_cluster_decode(c, b.size, NULL, &d, &e), SY_ERR_PARSE, e);
    memcpy(c, b.data, b.size);
    put32(c + 12, (uint32_t)(b.size - SY_CLUSTER_HEADER_SIZE - 4));
    CHECK_ERR(sy_cluster_decode(c, b.size - 4, NULL, &d, &e), SY_ERR_PARSE, e);
    /* a message over the receiver's limit */
    sy_cluster_limits lim = {64};
    CHECK_ERR(sy_cluster_decode(b.data, b.size, &lim, &d, &e), SY_ERR_LIMIT, e);
    /* tile outside the image: x = 60 with w = 64 on a 64-wide image */
    g_tiles[0].x = 60;
    CHECK_ERR(sy_cluster_encode(&m, 0, &b, &e), SY_ERR_INVALID_ARGUMENT, e);
    g_tiles[0].x = 0;
    /* the same, forged on the wire: find the first tile (last 48 bytes) and move it */
    memcpy(c, b.data, b.size);
    put32(c + b.size - 48, 60);
    CHECK_ERR(sy_cluster_decode(c, b.size, NULL, &d, &e), SY_ERR_PARSE, e);
    CHECK(strstr(e.message, "tile"));
    /* a string length beyond its limit (backend: u16 after frame, job, flags at body offset 16) */
    memcpy(c, b.data, b.size);
    c[SY_CLUSTER_HEADER_SIZE + 16] = 0xFF;
    c[SY_CLUSTER_HEADER_SIZE + 17] = 0x7F;
    CHECK(sy_cluster_decode(c, b.size, NULL, &d, &e) != SY_OK);
    /* cameras beyond SY_COORD_MAX (issue 32: Embree aborts the server on ray origins beyond
     * 1.844e18): refused by the encoder, and by the decoder when forged on the wire (the value is
     * put in place of a marker after encoding) */
    {
        static const struct {
            int index; /* 0..15 matrix, 16..19 window */
            float value;
            const char *reason;
            bool ortho;
        } far[] = {{12, 1e19f, "camera at (1e+19 0 0) is beyond the coordinate range", false},
                   {14, -2e12f, "is beyond the coordinate range", false},
                   {0, 1e13f, "is beyond the coordinate range", false},
                   {17, 1e19f, "camera window[1] = 1e+19 is not finite or beyond", true},
                   {16, -INFINITY, "camera window[0] = -inf is not finite", false}};
        for (size_t k = 0; k < sizeof far / sizeof far[0]; ++k) {
            const float marker = far[k].value < 0 ? -4242.25f : 4242.25f; /* keeps the window ordered */
            sy_cluster_msg q = m;
            float *slot = far[k].index < 16 ? &q.u.render.camera.camera_to_world.m[far[k].index]
                                            : &q.u.render.camera.window[far[k].index - 16];
            if (far[k].ortho) q.u.render.camera.projection = SY_PROJECTION_ORTHOGRAPHIC;
            *slot = far[k].value;
            b.size = 0;
            CHECK_ERR(sy_cluster_encode(&q, 0, &b, &e), SY_ERR_INVALID_ARGUMENT, e);
            CHECK_MSG(strstr(e.message, far[k].reason), "%s", e.message);
            *slot = marker;
            b.size = 0;
            CHECK_OK(sy_cluster_encode(&q, 0, &b, &e), e);
            memcpy(c, b.data, b.size);
            int patched = 0;
            for (size_t i = 0; i + 4 <= b.size; ++i)
                if (!memcmp(c + i, &marker, 4)) memcpy(c + i, &far[k].value, 4), patched++;
            CHECK(patched == 1);
            CHECK_ERR(sy_cluster_decode(c, b.size, NULL, &d, &e), SY_ERR_PARSE, e);
            CHECK_MSG(strstr(e.message, "cluster RENDER") && strstr(e.message, far[k].reason), "%s", e.message);
        }
        /* at the bound itself: accepted */
        sy_cluster_msg q = m;
        q.u.render.camera.camera_to_world.m[12] = SY_COORD_MAX;
        q.u.render.camera.window[0] = -SY_COORD_MAX;
        b.size = 0;
        CHECK_OK(sy_cluster_encode(&q, 0, &b, &e), e);
        CHECK_OK(sy_cluster_decode(b.data, b.size, NULL, &d, &e), e);
        sy_cluster_msg_free(&d);
    }
    /* section planes forged on the wire: NaN, a zero normal, 7 planes: refused by the decoder */
    {
        const float marker = 4343.5f;
        static const struct { int k; float value; const char *reason; } bad[] = {
            {0, NAN, "section plane 1"}, {3, INFINITY, "section plane 1"}, {-1, 0.0f, "the normal (a, b, c) is zero"}};
        for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
            sy_cluster_msg q = m;
            if (bad[i].k >= 0) {
                q.u.render.camera.clip_planes[1][bad[i].k] = marker;
            } else { /* the normal (0, -0.5, 0.5) of plane 1 zeroed on the wire: b and c */
                q.u.render.camera.clip_planes[1][1] = marker, q.u.render.camera.clip_planes[1][2] = -marker;
            }
            b.size = 0;
            CHECK_OK(sy_cluster_encode(&q, 0, &b, &e), e);
            memcpy(c, b.data, b.size);
            const float neg = -marker;
            for (size_t j = 0; j + 4 <= b.size; ++j)
                if (!memcmp(c + j, &marker, 4) || !memcmp(c + j, &neg, 4)) memcpy(c + j, &bad[i].value, 4);
            CHECK_ERR(sy_cluster_decode(c, b.size, NULL, &d, &e), SY_ERR_PARSE, e);
            CHECK_MSG(strstr(e.message, "cluster RENDER") && strstr(e.message, bad[i].reason), "%s", e.message);
        }
        sy_cluster_msg q = m;
        b.size = 0;
        CHECK_OK(sy_cluster_encode(&q, 0, &b, &e), e);
        CHECK_OK(sy_cluster_decode(b.data, b.size, NULL, &d, &e), e);
        CHECK(d.u.render.camera.clip_count == 2 &&
              !memcmp(d.u.render.camera.clip_planes, m.u.render.camera.clip_planes, 2 * sizeof(float[4])));
        sy_cluster_msg_free(&d);
        /* the count itself: 7 on the wire */
        memcpy(c, b.data, b.size);
        const uint32_t two = 2, seven = 7;
        int found = 0;
        for (size_t j = 0; j + 4 <= b.size && !found; ++j)
            if (!memcmp(c + j, &two, 4) && j + 4 + 32 <= b.size && !memcmp(c + j + 4, m.u.render.camera.clip_planes, 32))
                memcpy(c + j, &seven, 4), found = 1;
        CHECK(found);
        CHECK_ERR(sy_cluster_decode(c, b.size, NULL, &d, &e), SY_ERR_LIMIT, e);
        CHECK_MSG(strstr(e.message, "more than 6 section planes"), "%s", e.message);
        /* the encoder refuses bad planes too */
        q.u.render.camera.clip_planes[0][0] = NAN;
        b.size = 0;
        CHECK_ERR(sy_cluster_encode(&q, 0, &b, &e), SY_ERR_INVALID_ARGUMENT, e);
    }
    /* NaN in the camera */
    m.u.render.camera.znear = NAN;
    CHECK(sy_cluster_encode(&m, 0, &b, &e) != SY_OK);
    /* a tile's raw size that does not match its rectangle */
    sy_cluster_msg tm = sample(SY_CLUSTER_TILES);
    g_rtiles[0].raw_size = 63;
    b.size = 0;
    CHECK_OK(sy_cluster_encode(&tm, 0, &b, &e), e);
    CHECK_ERR(sy_cluster_decode(b.data, b.size, NULL, &d, &e), SY_ERR_PARSE, e);
    g_rtiles[0].raw_size = 64;
    /* a half tile's raw size is w * h * channels * 2; an unknown encoding is refused */
    g_rtiles[0].encoding = SY_CLUSTER_ENC_F16_SHUFFLE_ZSTD;
    b.size = 0;
    CHECK_OK(sy_cluster_encode(&tm, 0, &b, &e), e);
    CHECK_ERR(sy_cluster_decode(b.data, b.size, NULL, &d, &e), SY_ERR_PARSE, e);
    g_rtiles[0].raw_size = 32;
    b.size = 0;
    CHECK_OK(sy_cluster_encode(&tm, 0, &b, &e), e);
    CHECK_OK(sy_cluster_decode(b.data, b.size, NULL, &d, &e), e);
    sy_cluster_msg_free(&d);
    g_rtiles[0].encoding = 3;
    b.size = 0;
    CHECK_OK(sy_cluster_encode(&tm, 0, &b, &e), e);
    CHECK_ERR(sy_cluster_decode(b.data, b.size, NULL, &d, &e), SY_ERR_UNSUPPORTED, e);
    g_rtiles[0] = (sy_cluster_tile){{0, 0, 2, 2}, SY_CLUSTER_ENC_F32_SHUFFLE_ZSTD, 4, 64, g_payload, 10};
    /* blob lists: count 0, a count the body cannot hold, a payload that runs past the end */
    sy_cluster_msg bm = sample(SY_CLUSTER_BLOBS);
    bm.u.blobs.count = 0;
    CHECK(sy_cluster_encode(&bm, 0, &b, &e) != SY_OK);
    bm.u.blobs.count = 2;
    b.size = 0;
    CHECK_OK(sy_cluster_encode(&bm, 0, &b, &e), e);
    memcpy(c, b.data, b.size < 200 ? b.size : 200);
    put32(c + SY_CLUSTER_HEADER_SIZE + 8, 5000);
    CHECK_ERR(sy_cluster_decode(c, b.size, NULL, &d, &e), SY_ERR_PARSE, e);
    CHECK(strstr(e.message, "truncated blob list"));
    memcpy(c, b.data, b.size);
    put32(c + SY_CLUSTER_HEADER_SIZE + 12 + 16, 31); /* first blob claims 31 bytes: the rest shifts */
    CHECK(sy_cluster_decode(c, b.size, NULL, &d, &e) != SY_OK);
    memcpy(c, b.data, b.size);
    put32(c + SY_CLUSTER_HEADER_SIZE + 12 + 16, 0xFFFFFF00u);
    CHECK_ERR(sy_cluster_decode(c, b.size, NULL, &d, &e), SY_ERR_PARSE, e);
    CHECK(strstr(e.message, "runs past"));
    free(c);
    sy_cluster_buf_free(&b);
    return 0;
}

/* Reads buf as a stream of frames the way a receiver does (the first message under the
 * handshake budget, the rest under an open, untagged session's), decoding every complete message
 * into out[*count] (at most cap; the caller frees them). Returns 0 when the whole stream was
 * consumed, 1 on the first refused frame (err says why). */
static int stream_messages(const uint8_t *buf, size_t n, sy_cluster_msg *out, uint32_t cap, uint32_t *count,
                           uint8_t **bodies, sy_error *err)
{
    frame_join j = frame_join_start(1u << 16, 1u << 20, false);
    size_t pos = 0;
    *count = 0;
    while (pos < n) {
        int got = frame_join_take(&j, buf, n, &pos, err);
        if (got == 0) continue;
        if (got < 0 || *count == cap || sy_cluster_decode_body(&j.first, j.body, j.size, NULL, &out[*count], err) != SY_OK) {
            free(j.body);
            return 1;
        }
        bodies[(*count)++] = j.body;
        j.body = NULL;
        frame_join_next(&j);
    }
    free(j.body);
    return j.type ? (sy_error_set(err, SY_ERR_PARSE, "stream ends inside a chunked message"), 1) : 0;
}

/* Appends msg to out as frames of at most chunk body bytes (untagged, sequence numbers from *seq). */
static int append_chunked(const sy_cluster_msg *msg, size_t chunk, uint64_t *seq, sy_cluster_buf *out)
{
    sy_error e = {0};
    sy_cluster_buf one = {0};
    CHECK_OK(sy_cluster_encode(msg, 0, &one, &e), e);
    const uint8_t *body = one.data + SY_CLUSTER_HEADER_SIZE;
    size_t n = one.size - SY_CLUSTER_HEADER_SIZE, off = 0;
    do {
        size_t c = n - off < chunk ? n - off : chunk;
        uint8_t hdr[SY_CLUSTER_HEADER_SIZE];
        sy_cluster_header_write(hdr, msg->header.type, off + c < n ? SY_CLUSTER_FLAG_MORE : 0u, (uint32_t)c, ++*seq);
        size_t need = out->size + sizeof hdr + c;
        if (need > out->cap) {
            uint8_t *d = realloc(out->data, need);
            CHECK(d != NULL);
            out->data = d;
            out->cap = need;
        }
        memcpy(out->data + out->size, hdr, sizeof hdr);
        memcpy(out->data + out->size + sizeof hdr, body + off, c);
        out->size = need;
        off += c;
    } while (off < n);
    sy_cluster_buf_free(&one);
    return 0;
}

/* Stream framing (protocol 3): a header is judged against the receiver's budget before a byte of
 * its body is read or allocated; a message split into frames reassembles to the same message. */
static int test_framing(void)
{
    sy_error e = {0};
    sy_cluster_header h;
    size_t follow = 0;
    uint8_t hdr[SY_CLUSTER_HEADER_SIZE];
    const sy_cluster_budget hs = {SY_CLUSTER_HANDSHAKE_MAX_FRAME, SY_CLUSTER_HANDSHAKE_MAX_FRAME, false, false};
    const sy_cluster_budget open = {1u << 16, 1u << 20, true, true};
    /* a HELLO announcing 256 MiB: refused from its header alone */
    sy_cluster_header_write(hdr, SY_CLUSTER_HELLO, 0, 256u << 20, 1);
    CHECK_OK(sy_cluster_parse_header(hdr, &h, &e), e);
    CHECK_ERR(sy_cluster_frame_check(&h, &hs, 0, 0, &follow, &e), SY_ERR_LIMIT, e);
    CHECK_MSG(strstr(e.message, "HELLO: frame announces 268435480 bytes, this connection accepts at most 1024"), "%s",
              e.message);
    /* chunks before the session is open; a tag before there is a key; no tag once there is */
    sy_cluster_header_write(hdr, SY_CLUSTER_HELLO, SY_CLUSTER_FLAG_MORE, 10, 1);
    CHECK_OK(sy_cluster_parse_header(hdr, &h, &e), e);
    CHECK_ERR(sy_cluster_frame_check(&h, &hs, 0, 0, &follow, &e), SY_ERR_PROTOCOL, e);
    sy_cluster_header_write(hdr, SY_CLUSTER_AUTH, SY_CLUSTER_FLAG_TAGGED, 32, 2);
    CHECK_OK(sy_cluster_parse_header(hdr, &h, &e), e);
    CHECK_ERR(sy_cluster_frame_check(&h, &hs, 0, 0, &follow, &e), SY_ERR_PROTOCOL, e);
    sy_cluster_header_write(hdr, SY_CLUSTER_SCENE, 0, 100, 3);
    CHECK_OK(sy_cluster_parse_header(hdr, &h, &e), e);
    CHECK_ERR(sy_cluster_frame_check(&h, &open, 0, 0, &follow, &e), SY_ERR_PROTOCOL, e);
    /* within the budget: the body and the tag follow */
    sy_cluster_header_write(hdr, SY_CLUSTER_SCENE, SY_CLUSTER_FLAG_TAGGED | SY_CLUSTER_FLAG_MORE, 1000, 3);
    CHECK_OK(sy_cluster_parse_header(hdr, &h, &e), e);
    CHECK_OK(sy_cluster_frame_check(&h, &open, 0, 0, &follow, &e), e);
    CHECK(follow == 1000 + SY_CLUSTER_TAG_SIZE);
    /* over the frame limit (header + body + tag); a continuation of another type; the message limit */
    sy_cluster_header_write(hdr, SY_CLUSTER_SCENE, SY_CLUSTER_FLAG_TAGGED, (1u << 16) - 56 + 1, 4);
    CHECK_OK(sy_cluster_parse_header(hdr, &h, &e), e);
    CHECK_ERR(sy_cluster_frame_check(&h, &open, 0, 0, &follow, &e), SY_ERR_LIMIT, e);
    sy_cluster_header_write(hdr, SY_CLUSTER_SCENE, SY_CLUSTER_FLAG_TAGGED, (1u << 16) - 56, 4);
    CHECK_OK(sy_cluster_parse_header(hdr, &h, &e), e);
    CHECK_OK(sy_cluster_frame_check(&h, &open, 0, 0, &follow, &e), e);
    sy_cluster_header_write(hdr, SY_CLUSTER_RENDER, SY_CLUSTER_FLAG_TAGGED, 100, 5);
    CHECK_OK(sy_cluster_parse_header(hdr, &h, &e), e);
    CHECK_ERR(sy_cluster_frame_check(&h, &open, 1000, SY_CLUSTER_SCENE, &follow, &e), SY_ERR_PROTOCOL, e);
    sy_cluster_header_write(hdr, SY_CLUSTER_SCENE, SY_CLUSTER_FLAG_TAGGED, 100, 5);
    CHECK_OK(sy_cluster_parse_header(hdr, &h, &e), e);
    CHECK_ERR(sy_cluster_frame_check(&h, &open, (1u << 20) - 99, SY_CLUSTER_SCENE, &follow, &e), SY_ERR_LIMIT, e);
    CHECK(strstr(e.message, "exceeds the limit of 1048576"));
    CHECK_OK(sy_cluster_frame_check(&h, &open, (1u << 20) - 100, SY_CLUSTER_SCENE, &follow, &e), e);
    /* an unknown flag bit */
    sy_cluster_header_write(hdr, SY_CLUSTER_SCENE, 4, 100, 5);
    CHECK_ERR(sy_cluster_parse_header(hdr, &h, &e), SY_ERR_PARSE, e);
    /* one frame of a chunked message is not a message */
    sy_cluster_msg m = sample(SY_CLUSTER_BLOBS), d[4];
    sy_cluster_buf b = {0};
    CHECK_OK(sy_cluster_encode(&m, 0, &b, &e), e);
    b.data[8] |= SY_CLUSTER_FLAG_MORE;
    CHECK_ERR(sy_cluster_decode(b.data, b.size, NULL, &d[0], &e), SY_ERR_PARSE, e);
    /* HELLO, then RENDER and BLOBS in frames of 17 and 40 body bytes: the same messages */
    b.size = 0;
    uint64_t seq = 0;
    sy_cluster_msg hello = sample(SY_CLUSTER_HELLO), render = sample(SY_CLUSTER_RENDER);
    if (append_chunked(&hello, 1000, &seq, &b) || append_chunked(&render, 17, &seq, &b) ||
        append_chunked(&m, 40, &seq, &b))
        return 1;
    uint32_t count = 0;
    uint8_t *bodies[4] = {0};
    CHECK_MSG(stream_messages(b.data, b.size, d, 4, &count, bodies, &e) == 0, "%s", e.message);
    CHECK(count == 3 && d[1].header.type == SY_CLUSTER_RENDER && d[2].header.type == SY_CLUSTER_BLOBS);
    CHECK(d[1].u.render.tile_count == 3 && d[1].u.render.tiles[2].x == 10 && !strcmp(d[1].u.render.params, "max_depth=4"));
    CHECK(d[2].u.blobs.count == 2 && memcmp(d[2].u.blobs.blobs[0].data, g_payload, 30) == 0);
    for (uint32_t i = 0; i < count; ++i) {
        sy_cluster_msg_free(&d[i]);
        free(bodies[i]);
    }
    /* a chunked HELLO (before the session is open) is refused */
    b.size = 0;
    seq = 0;
    if (append_chunked(&hello, 20, &seq, &b)) return 1;
    CHECK(stream_messages(b.data, b.size, d, 4, &count, bodies, &e) == 1 && count == 0);
    sy_cluster_buf_free(&b);
    return 0;
}

/* Whatever the decoder accepts must satisfy the documented ranges. */
static int check_accepted(const sy_cluster_msg *d, const uint8_t *buf, size_t size)
{
    if (d->header.type == SY_CLUSTER_RENDER) {
        CHECK(d->u.render.tile_count >= 1 && d->u.render.tile_count <= SY_CLUSTER_MAX_TILES);
        for (uint32_t i = 0; i < d->u.render.tile_count; ++i) {
            const sy_cluster_rect *r = &d->u.render.tiles[i];
            CHECK(r->w && r->h && (uint64_t)r->x + r->w <= d->u.render.full_width &&
                  (uint64_t)r->y + r->h <= d->u.render.full_height);
        }
        CHECK(strlen(d->u.render.backend) < SY_CLUSTER_BACKEND_MAX);
    }
    if (d->header.type == SY_CLUSTER_TILES)
        for (uint32_t i = 0; i < d->u.tiles.tile_count; ++i) {
            const sy_cluster_tile *t = &d->u.tiles.tiles[i];
            CHECK(t->data >= buf && t->data + t->data_size <= buf + size);
            CHECK(t->raw_size == (uint64_t)t->rect.w * t->rect.h * t->channels * sy_cluster_encoding_bytes(t->encoding));
        }
    if (d->header.type == SY_CLUSTER_BLOBS || d->header.type == SY_CLUSTER_BLOB_REQUEST) {
        CHECK(d->u.blobs.count >= 1 && d->u.blobs.count <= SY_CLUSTER_MAX_BLOBS);
        for (uint32_t i = 0; i < d->u.blobs.count && d->header.type == SY_CLUSTER_BLOBS; ++i)
            CHECK(d->u.blobs.blobs[i].data >= buf && d->u.blobs.blobs[i].data + d->u.blobs.blobs[i].size <= buf + size);
    }
    if (d->header.type == SY_CLUSTER_SCENE)
        CHECK(d->u.scene.changes >= buf && d->u.scene.changes + d->u.scene.changes_size <= buf + size);
    return 0;
}

static int test_mutations(void)
{
    uint32_t accepted = 0, rejected = 0;
    for (int iter = 0; iter < 6000; ++iter) {
        uint32_t t = 1 + rnd() % SY_CLUSTER_MSG_TYPE_MAX;
        sy_error e = {0};
        sy_cluster_msg m = sample(t), d;
        sy_cluster_buf b = {0};
        CHECK_OK(sy_cluster_encode(&m, 0, &b, &e), e);
        uint32_t nmut = 1 + rnd() % 4;
        for (uint32_t k = 0; k < nmut; ++k) {
            size_t pos = rnd() % b.size;
            switch (rnd() % 3) {
            case 0: b.data[pos] ^= (uint8_t)(1u << (rnd() % 8)); break;
            case 1: b.data[pos] = (uint8_t)rnd(); break;
            default: b.data[pos] = (rnd() & 1) ? 0xFF : 0x00; break;
            }
        }
        size_t size = b.size;
        if (rnd() % 8 == 0) size = rnd() % (b.size + 1); /* also truncate sometimes */
        /* decode from an exactly-sized heap copy so ASan sees any overread */
        uint8_t *exact = malloc(size ? size : 1);
        CHECK(exact != NULL);
        memcpy(exact, b.data, size);
        if (sy_cluster_decode(exact, size, NULL, &d, &e) == SY_OK) {
            accepted++;
            if (check_accepted(&d, exact, size)) return 1;
            sy_cluster_msg_free(&d);
        } else {
            rejected++;
            CHECK(e.message[0] != 0);
        }
        free(exact);
        sy_cluster_buf_free(&b);
    }
    printf("mutations: %u accepted (harmless bytes changed), %u rejected\n", accepted, rejected);
    CHECK(rejected > 1000 && accepted > 0);
    return 0;
}

/* Layer a (aw x ah) of random colours, (rnd() % mod) / div + off, and depths d0 + i * step but
 * infinite at every inf_every-th pixel; layer b (bw x bh) to decode into. 0, or 1 after a failed
 * check. */
static int tile_layers(uint32_t aw, uint32_t ah, uint32_t bw, uint32_t bh, uint32_t mod, float div, float off,
                       size_t inf_every, float d0, float step, sy_layer *a, sy_layer *b)
{
    sy_error e = {0};
    CHECK_OK(sy_layer_create(aw, ah, a, &e), e);
    CHECK_OK(sy_layer_create(bw, bh, b, &e), e);
    for (size_t i = 0; i < (size_t)aw * ah; ++i) {
        for (int c = 0; c < 4; ++c) a->rgba[i * 4 + c] = (float)(rnd() % mod) / div + off;
        a->depth[i] = (i % inf_every) ? d0 + (float)i * step : INFINITY;
    }
    return 0;
}

static int test_tile_codec(void)
{
    sy_error e = {0};
    sy_layer a = {0}, b = {0};
    if (tile_layers(13, 7, 20, 10, 1000, 7.0f, -3.0f, 5, 0.0f, 0.25f, &a, &b)) return 1;
    sy_cluster_buf enc = {0};
    CHECK_OK(sy_cluster_tile_encode(&a, true, &enc, &e), e);
    sy_cluster_tile t = {{0, 0, 13, 7}, SY_CLUSTER_ENC_F32_SHUFFLE_ZSTD, 5, 13 * 7 * 5 * 4, enc.data, (uint32_t)enc.size};
    CHECK_OK(sy_cluster_tile_decode(&t, &b, 5, 2, &e), e);
    for (uint32_t y = 0; y < 7; ++y)
        for (uint32_t x = 0; x < 13; ++x) {
            size_t i = (size_t)y * 13 + x, o = (size_t)(y + 2) * 20 + x + 5;
            CHECK(memcmp(&a.rgba[i * 4], &b.rgba[o * 4], 16) == 0); /* bit-exact */
            CHECK(memcmp(&a.depth[i], &b.depth[o], 4) == 0);
        }
    /* does not fit, corrupt data, lying raw size */
    CHECK_ERR(sy_cluster_tile_decode(&t, &b, 10, 5, &e), SY_ERR_PROTOCOL, e);
    uint8_t *bad = malloc(enc.size);
    CHECK(bad != NULL);
    memcpy(bad, enc.data, enc.size);
    for (size_t i = enc.size / 2; i < enc.size; ++i) bad[i] ^= 0x5A;
    t.data = bad;
    CHECK(sy_cluster_tile_decode(&t, &b, 0, 0, &e) != SY_OK);
    t.data = enc.data;
    t.data_size = (uint32_t)enc.size / 2;
    CHECK(sy_cluster_tile_decode(&t, &b, 0, 0, &e) != SY_OK);
    free(bad);
    sy_cluster_buf_free(&enc);
    sy_layer_destroy(&a);
    sy_layer_destroy(&b);
    return 0;
}

static float f_bits(uint32_t u)
{
    float f;
    memcpy(&f, &u, 4);
    return f;
}

/* binary16 (Imath's conversions): every half survives half -> float -> half exactly, NaNs with
 * their sign and payload; float -> half rounds to nearest even at every boundary; overflow, underflow,
 * infinities; and (gcc, x86-64) agreement with the compiler's _Float16 conversion on 4M floats. */
static int test_half(void)
{
    uint32_t nans = 0;
    for (uint32_t h = 0; h < 65536; ++h) {
        float f = sy_cluster_half_to_float((uint16_t)h);
        uint16_t back = sy_cluster_half_from_float(f);
        bool nan = (h & 0x7c00u) == 0x7c00u && (h & 0x3ffu);
        if (nan) {
            nans++;
            CHECK_MSG(isnan(f) && back == h, "NaN %04x -> %04x", h, back);
        } else {
            CHECK_MSG(back == h, "half %04x -> %g -> %04x", h, (double)f, back);
        }
        /* the float value is exact: compare with the formula */
        uint32_t ex = (h >> 10) & 31u, m = h & 0x3ffu;
        if (ex != 31) {
            double v = ex ? ldexp(1.0 + m / 1024.0, (int)ex - 15) : ldexp((double)m, -24);
            if (h & 0x8000u) v = -v;
            CHECK_MSG((double)f == v && !!signbit(f) == !!(h & 0x8000u), "half %04x = %g, expected %g", h, (double)f, v);
        }
    }
    CHECK(nans == 2 * 1023);
    /* rounding: ties to even, just above / below the ties, normal and subnormal */
    CHECK(sy_cluster_half_from_float(1.0f) == 0x3c00);
    CHECK(sy_cluster_half_from_float(1.0f + 0x1p-11f) == 0x3c00);          /* tie, even stays */
    CHECK(sy_cluster_half_from_float(1.0f + 3 * 0x1p-11f) == 0x3c02);      /* tie, odd rounds up */
    CHECK(sy_cluster_half_from_float(nextafterf(1.0f + 0x1p-11f, 2)) == 0x3c01);
    CHECK(sy_cluster_half_from_float(nextafterf(1.0f + 3 * 0x1p-11f, 0)) == 0x3c01);
    CHECK(sy_cluster_half_from_float(2047.0f / 1024.0f * 1.0f + 0x1p-11f) == 0x4000); /* carry into the exponent */
    CHECK(sy_cluster_half_from_float(65504.0f) == 0x7bff);
    CHECK(sy_cluster_half_from_float(65519.996f) == 0x7bff);
    CHECK(sy_cluster_half_from_float(65520.0f) == 0x7c00); /* the tie above the largest half is inf */
    CHECK(sy_cluster_half_from_float(-1e10f) == 0xfc00);
    CHECK(sy_cluster_half_from_float(INFINITY) == 0x7c00 && sy_cluster_half_from_float(-INFINITY) == 0xfc00);
    CHECK((sy_cluster_half_from_float(NAN) & 0x7e00) == 0x7e00);
    CHECK(sy_cluster_half_from_float(-0.0f) == 0x8000 && sy_cluster_half_from_float(0.0f) == 0);
    CHECK(sy_cluster_half_from_float(0x1p-24f) == 0x0001);               /* smallest subnormal */
    CHECK(sy_cluster_half_from_float(0x1p-25f) == 0x0000);               /* tie to even: zero */
    CHECK(sy_cluster_half_from_float(nextafterf(0x1p-25f, 1)) == 0x0001);
    CHECK(sy_cluster_half_from_float(3 * 0x1p-25f) == 0x0002);           /* tie 1.5 -> 2 */
    CHECK(sy_cluster_half_from_float(5 * 0x1p-25f) == 0x0002);           /* tie 2.5 -> 2 */
    CHECK(sy_cluster_half_from_float(-0x1p-26f) == 0x8000);
    CHECK(sy_cluster_half_from_float(f_bits(1)) == 0);                    /* float subnormal */
    CHECK(sy_cluster_half_from_float(nextafterf(0x1p-14f, 0)) == 0x0400); /* rounds up to the smallest normal */
    CHECK(sy_cluster_half_from_float(0x1p-14f - 0x1p-25f) == 0x0400);    /* tie between 0x3ff and 0x400: even */
    CHECK(sy_cluster_half_from_float(0x1p-14f - 3 * 0x1p-25f) == 0x03fe); /* tie between 0x3fe and 0x3ff: even */
#if defined(__FLT16_MAX__) && defined(__x86_64__) && !defined(__clang__)
    uint32_t checked = 0;
    for (uint64_t u = 0; u < 0x100000000ull; u += 1021) {
        float f = f_bits((uint32_t)u);
        _Float16 ref = (_Float16)f;
        uint16_t rb;
        memcpy(&rb, &ref, 2);
        uint16_t ours = sy_cluster_half_from_float(f);
        if (isnan(f)) /* NaN stays NaN with its sign (_Float16 also quiets it; Imath keeps the payload) */
            CHECK_MSG((ours & 0x7c00) == 0x7c00 && (ours & 0x3ff) && (ours & 0x8000) == (rb & 0x8000), "NaN %08x", (uint32_t)u);
        else CHECK_MSG(ours == rb, "float %08x: ours %04x, _Float16 %04x", (uint32_t)u, ours, rb);
        checked++;
    }
    printf("half: %u floats agree with _Float16\n", checked);
#else
    printf("half: no _Float16 reference in this compiler (checked against the formula and the edge cases)\n");
#endif
    return 0;
}

/* A half tile decodes to the half-rounded values (inf depth stays inf) and is smaller. */
static int test_half_tile(void)
{
    sy_error e = {0};
    sy_layer a = {0}, b = {0};
    if (tile_layers(31, 9, 31, 9, 100000, 3000.0f, 0.0f, 7, 0.5f, 0.01f, &a, &b)) return 1;
    sy_cluster_buf f32 = {0}, f16 = {0};
    CHECK_OK(sy_cluster_tile_encode(&a, true, &f32, &e), e);
    CHECK_OK(sy_cluster_tile_encode_as(&a, true, SY_CLUSTER_ENC_F16_SHUFFLE_ZSTD, &f16, &e), e);
    CHECK_MSG(f16.size < f32.size, "half tile %zu bytes, float %zu", f16.size, f32.size);
    sy_cluster_tile t = {{0, 0, 31, 9}, SY_CLUSTER_ENC_F16_SHUFFLE_ZSTD, 5, 31 * 9 * 5 * 2, f16.data, (uint32_t)f16.size};
    CHECK_OK(sy_cluster_tile_decode(&t, &b, 0, 0, &e), e);
    for (size_t i = 0; i < 31 * 9; ++i) {
        for (int c = 0; c < 4; ++c) {
            float want = sy_cluster_half_to_float(sy_cluster_half_from_float(a.rgba[i * 4 + c]));
            CHECK(b.rgba[i * 4 + c] == want && fabsf(want - a.rgba[i * 4 + c]) <= a.rgba[i * 4 + c] * 0x1p-11f);
        }
        CHECK(b.depth[i] == sy_cluster_half_to_float(sy_cluster_half_from_float(a.depth[i])));
        if (isinf(a.depth[i])) CHECK(isinf(b.depth[i]));
    }
    /* the float32 raw size under the half encoding is refused */
    t.raw_size = 31 * 9 * 5 * 4;
    CHECK(sy_cluster_tile_decode(&t, &b, 0, 0, &e) != SY_OK);
    sy_cluster_buf_free(&f32);
    sy_cluster_buf_free(&f16);
    sy_layer_destroy(&a);
    sy_layer_destroy(&b);
    return 0;
}

/* The fuzz seed corpus (tests/cluster/fuzz_seeds): one valid frame of every message type, as
 * sample() makes them. `--write-seeds DIR` (re)generates it; given DIR, every seed must still
 * decode, so the corpus follows the protocol version. */
/* Seeds 15 and 16: a SCENE carrying a real change list (a texture, its blob by hash) and a TILES
 * carrying a real binary16 tile, so the fuzzer starts inside the nested decoders. */
static int real_seed(uint32_t which, sy_cluster_buf *b)
{
    sy_error e = {0};
    sy_cluster_msg m;
    memset(&m, 0, sizeof m);
    m.header.seq = 3;
    if (which == 15) {
        void *data = NULL;
        size_t size = 0;
        if (texture_snapshot("seed", g_payload, 16, 2, 2, &data, &size, NULL)) return 1;
        m = scene_msg(3, SY_CLUSTER_SCENE_SNAPSHOT, data, size);
        CHECK_OK(sy_cluster_encode(&m, 0, b, &e), e);
        free(data);
        return 0;
    }
    sy_layer l = {0};
    sy_cluster_buf enc = {0};
    CHECK_OK(sy_layer_create(4, 3, &l, &e), e);
    for (int i = 0; i < 12; ++i) {
        for (int c = 0; c < 4; ++c) l.rgba[i * 4 + c] = (float)(i * 4 + c) / 8.0f;
        l.depth[i] = i % 3 ? (float)i : INFINITY;
    }
    CHECK_OK(sy_cluster_tile_encode_as(&l, true, SY_CLUSTER_ENC_F16_SHUFFLE_ZSTD, &enc, &e), e);
    sy_cluster_tile tl = {{1, 2, 4, 3}, SY_CLUSTER_ENC_F16_SHUFFLE_ZSTD, 5, 4 * 3 * 5 * 2, enc.data, (uint32_t)enc.size};
    m.header.type = SY_CLUSTER_TILES;
    m.u.tiles.samples = 1;
    m.u.tiles.tile_count = 1;
    m.u.tiles.tiles = &tl;
    CHECK_OK(sy_cluster_encode(&m, 0, b, &e), e);
    sy_cluster_buf_free(&enc);
    sy_layer_destroy(&l);
    return 0;
}

/* Seed 18: the RENDER of issue 32 (a camera at 1e19, which aborted the server in Embree), as
 * forged on the wire: the decoder refuses it, so the fuzzer starts at that check. */
static int far_camera_seed(sy_cluster_buf *b)
{
    sy_error e = {0};
    sy_cluster_msg m = sample(SY_CLUSTER_RENDER);
    const float marker = 4242.25f, far = 1e19f;
    m.u.render.camera.camera_to_world.m[12] = marker;
    CHECK_OK(sy_cluster_encode(&m, 0, b, &e), e);
    int patched = 0;
    for (size_t i = 0; i + 4 <= b->size; ++i)
        if (!memcmp(b->data + i, &marker, 4)) memcpy(b->data + i, &far, 4), patched++;
    CHECK(patched == 1);
    return 0;
}

static int seeds(const char *dir, bool write)
{
    char path[4096];
    for (uint32_t t = 1; t <= SY_CLUSTER_MSG_TYPE_MAX + 4; ++t) {
        sy_error e = {0};
        sy_cluster_msg m = sample(t), d;
        sy_cluster_buf b = {0};
        if (t == SY_CLUSTER_MSG_TYPE_MAX + 3) { /* a stream: HELLO, then a SCENE in frames of 40 body bytes */
            sy_cluster_msg hello = sample(SY_CLUSTER_HELLO), scene = sample(SY_CLUSTER_SCENE);
            uint64_t seq = 0;
            if (append_chunked(&hello, 1000, &seq, &b) || append_chunked(&scene, 40, &seq, &b)) return 1;
        } else if (t == SY_CLUSTER_MSG_TYPE_MAX + 4) {
            if (far_camera_seed(&b)) return 1;
        } else if (t > SY_CLUSTER_MSG_TYPE_MAX) {
            if (real_seed(t, &b)) return 1;
        } else {
            CHECK_OK(sy_cluster_encode(&m, 0, &b, &e), e);
        }
        snprintf(path, sizeof path, "%s/%02u_%s.bin", dir, t,
                 t <= SY_CLUSTER_MSG_TYPE_MAX ? sy_cluster_msg_type_name(t)
                 : t == 15                    ? "SCENE_real"
                 : t == 16                    ? "TILES_half"
                 : t == 17                    ? "stream_HELLO_SCENE_chunked"
                                              : "RENDER_camera_1e19");
        if (write) {
            FILE *f = fopen(path, "wb");
            CHECK_MSG(f && fwrite(b.data, 1, b.size, f) == b.size && fclose(f) == 0, "cannot write %s", path);
        } else {
            FILE *f = fopen(path, "rb");
            CHECK_MSG(f != NULL, "%s is missing (regenerate: test_cluster_proto --write-seeds DIR)", path);
            uint8_t buf[4096];
            size_t n = fread(buf, 1, sizeof buf, f);
            fclose(f);
            CHECK_MSG(n == b.size && memcmp(buf, b.data, n) == 0, "%s is stale (regenerate: test_cluster_proto "
                      "--write-seeds DIR)", path);
            if (t == SY_CLUSTER_MSG_TYPE_MAX + 3) {
                sy_cluster_msg ms[2];
                uint8_t *bodies[2];
                uint32_t count = 0;
                CHECK_MSG(stream_messages(buf, n, ms, 2, &count, bodies, &e) == 0 && count == 2, "%s: %s", path, e.message);
                for (uint32_t i = 0; i < count; ++i) {
                    sy_cluster_msg_free(&ms[i]);
                    free(bodies[i]);
                }
            } else if (t == SY_CLUSTER_MSG_TYPE_MAX + 4) { /* refused, for its reason */
                CHECK_ERR(sy_cluster_decode(buf, n, NULL, &d, &e), SY_ERR_PARSE, e);
                CHECK_MSG(strstr(e.message, "camera at (1e+19 0 0) is beyond the coordinate range"), "%s: %s", path,
                          e.message);
            } else {
                CHECK_OK(sy_cluster_decode(buf, n, NULL, &d, &e), e);
                sy_cluster_msg_free(&d);
            }
        }
        sy_cluster_buf_free(&b);
    }
    return 0;
}

/* RENDER's scene time (protocol 5): the encoder refuses what the decoder refuses; a decoder given a
 * NaN, negative or too large time, or a time without the time flag, refuses the message naming it. */
static int test_render_time(void)
{
    sy_error e = {0};
    sy_cluster_msg m = sample(SY_CLUSTER_RENDER), d;
    sy_cluster_buf b = {0};
    const double bad[] = {NAN, -1.0, 2e9, INFINITY};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        m.u.render.time = bad[i];
        CHECK(sy_cluster_encode(&m, 0, &b, &e) == SY_ERR_INVALID_ARGUMENT && b.size == 0);
        CHECK_SAYS(e, "scene time");
    }
    m.u.render.time = 2.5;
    m.u.render.flags &= ~(uint32_t)SY_CLUSTER_RENDER_TIME;
    CHECK(sy_cluster_encode(&m, 0, &b, &e) == SY_ERR_INVALID_ARGUMENT && b.size == 0);
    m.u.render.flags |= SY_CLUSTER_RENDER_TIME;
    CHECK_OK(sy_cluster_encode(&m, 0, &b, &e), e);
    size_t at = 0; /* where the time's 8 bytes lie (the only 2.5 in the message) */
    const double good = 2.5;
    for (size_t i = SY_CLUSTER_HEADER_SIZE; i + 8 <= b.size && !at; ++i)
        if (!memcmp(b.data + i, &good, 8)) at = i;
    CHECK(at > 0);
    uint8_t *c = malloc(b.size);
    CHECK(c != NULL);
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        memcpy(c, b.data, b.size);
        memcpy(c + at, &bad[i], 8);
        CHECK(sy_cluster_decode(c, b.size, NULL, &d, &e) == SY_ERR_PARSE);
        CHECK_SAYS(e, "scene time outside 0..1e9 seconds");
    }
    memcpy(c, b.data, b.size);
    c[SY_CLUSTER_HEADER_SIZE + 12] &= (uint8_t)~SY_CLUSTER_RENDER_TIME; /* flags: after frame (8) and job (4) */
    CHECK(sy_cluster_decode(c, b.size, NULL, &d, &e) == SY_ERR_PARSE);
    CHECK_SAYS(e, "without the time flag");
    c[SY_CLUSTER_HEADER_SIZE + 12] |= 1u << 7; /* an unknown flag */
    CHECK(sy_cluster_decode(c, b.size, NULL, &d, &e) == SY_ERR_PARSE);
    CHECK_SAYS(e, "unknown render flags");
    free(c);
    sy_cluster_buf_free(&b);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc == 3 && !strcmp(argv[1], "--write-seeds")) return seeds(argv[2], true);
    if (argc == 2) EXPECT(seeds(argv[1], false) == 0);
    RUN(test_round_trip);
    RUN(test_render_time);
    RUN(test_bad_headers);
    RUN(test_framing);
    RUN(test_mutations);
    RUN(test_tile_codec);
    RUN(test_half);
    RUN(test_half_tile);
    return sy_check_finish("test_cluster_proto");
}
