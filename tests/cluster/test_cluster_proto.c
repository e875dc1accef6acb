/* test_cluster_proto.c — the cluster message encoder/decoder and the tile codec: round trips of
 * every message type, every truncation, wrong magic / version / type / flags, announced sizes that
 * lie, out-of-range fields, and a few thousand random mutations of valid frames (the decoder must
 * reject or accept cleanly, never crash, and whatever it accepts must be in range). Runs in every
 * build (the libFuzzer target in fuzz_cluster_decode.c covers the same decoder under SY_FUZZ). */
#include "../core/check.h"
#include "sy_cluster.h"

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
        m.u.render.flags = SY_CLUSTER_RENDER_DEPTH;
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
        if (t == SY_CLUSTER_AUTH) CHECK(d.u.auth.mac[0] == 255 && d.u.auth.mac[31] == 224);
        if (t == SY_CLUSTER_SCENE) CHECK(d.u.scene.frame == 42 && d.u.scene.changes_size == 100 && d.u.scene.flags == 1);
        if (t == SY_CLUSTER_SWAP) CHECK(d.u.ack.frame == 99 && d.u.ack.objects == 5);
        if (t == SY_CLUSTER_RENDER) {
            CHECK(!strcmp(d.u.render.backend, "whitted") && !strcmp(d.u.render.params, "max_depth=4"));
            CHECK(d.u.render.tile_count == 3 && d.u.render.tiles[2].x == 10 && d.u.render.tiles[2].h == 2);
            CHECK(d.u.render.sample_first == 16 && d.u.render.sample_count == 8 && d.u.render.root_id == 0x10001);
            CHECK(d.u.render.camera.window[2] == -0.5f && d.u.render.camera.camera_to_world.m[15] == 1.0f);
        }
        if (t == SY_CLUSTER_TILES) {
            CHECK(d.u.tiles.tile_count == 2 && d.u.tiles.tiles[1].channels == 5 && d.u.tiles.tiles[1].data_size == 5);
            CHECK(d.u.tiles.render_seconds == 1.5 && d.u.tiles.samples == 24);
            CHECK(d.u.tiles.tiles[1].data == b.data + (b.size - 5));
        }
        if (t == SY_CLUSTER_ERROR) CHECK(!strcmp(d.u.error.reason, "nope") && d.u.error.code == SY_ERR_PROTOCOL);
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
    c[4] = 2;
    CHECK_ERR(sy_cluster_decode(c, b.size, NULL, &d, &e), SY_ERR_UNSUPPORTED, e);
    CHECK(strstr(e.message, "version 2"));
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
    /* NaN in the camera */
    m.u.render.camera.znear = NAN;
    CHECK(sy_cluster_encode(&m, 0, &b, &e) != SY_OK);
    /* a tile's raw size that does not match its rectangle */
    sy_cluster_msg tm = sample(SY_CLUSTER_TILES);
    g_rtiles[0].raw_size = 63;
    b.size = 0;
    CHECK_OK(sy_cluster_encode(&tm, 0, &b, &e), e);
    CHECK_ERR(sy_cluster_decode(b.data, b.size, NULL, &d, &e), SY_ERR_PARSE, e);
    free(c);
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
            CHECK(t->raw_size == (uint64_t)t->rect.w * t->rect.h * t->channels * 4);
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

static int test_tile_codec(void)
{
    sy_error e = {0};
    sy_layer a = {0}, b = {0};
    CHECK_OK(sy_layer_create(13, 7, &a, &e), e);
    CHECK_OK(sy_layer_create(20, 10, &b, &e), e);
    for (size_t i = 0; i < 13 * 7; ++i) {
        for (int c = 0; c < 4; ++c) a.rgba[i * 4 + c] = (float)(rnd() % 1000) / 7.0f - 3.0f;
        a.depth[i] = (i % 5) ? (float)i * 0.25f : INFINITY;
    }
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

int main(void)
{
    int failed = 0;
    failed += test_round_trip();
    failed += test_bad_headers();
    failed += test_mutations();
    failed += test_tile_codec();
    if (failed) fprintf(stderr, "test_cluster_proto: %d test(s) failed\n", failed);
    else printf("test_cluster_proto: all passed\n");
    return failed ? 1 : 0;
}
