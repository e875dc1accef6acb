/* test_blob.c — sy_blob: content hashing, reference counting, live count, and the blob store
 * (put / get / dedupe / growth / release). */
#include <stdlib.h>
#include <string.h>

#include "../support/sy_check.h"
#include "sy_blob.h"

static int test_hash(void)
{
    sy_error e = {0};
    long live0 = sy_blob_live_count();
    const char a[] = "switchyard", b[] = "switchyarD";
    sy_blob *x, *y, *z, *empty1, *empty2;
    CHECK_OK(sy_blob_create_copy(a, sizeof a, &x, &e), e);
    CHECK_OK(sy_blob_create_copy(a, sizeof a, &y, &e), e);
    CHECK_OK(sy_blob_create_copy(b, sizeof b, &z, &e), e);
    CHECK_OK(sy_blob_create_copy(NULL, 0, &empty1, &e), e);
    CHECK_OK(sy_blob_create_copy(a, 0, &empty2, &e), e);
    CHECK(sy_blob_live_count() == live0 + 5);
    CHECK(x != y);
    CHECK(sy_blob_data(x) != (const void *)a); /* a copy */
    CHECK(sy_blob_size(x) == sizeof a && memcmp(sy_blob_data(x), a, sizeof a) == 0);
    CHECK(sy_hash_equal(sy_blob_hash(x), sy_blob_hash(y)));
    CHECK(!sy_hash_equal(sy_blob_hash(x), sy_blob_hash(z)));
    CHECK(sy_hash_equal(sy_blob_hash(x), sy_hash_bytes(a, sizeof a)));
    /* a one-byte-shorter prefix hashes differently */
    CHECK(!sy_hash_equal(sy_hash_bytes(a, sizeof a - 1), sy_blob_hash(x)));
    CHECK(sy_blob_size(empty1) == 0 && sy_blob_size(empty2) == 0);
    CHECK(sy_hash_equal(sy_blob_hash(empty1), sy_blob_hash(empty2)));
    CHECK(!sy_hash_equal(sy_blob_hash(empty1), sy_blob_hash(x)));
    /* the hash covers both halves */
    sy_hash128 h = sy_blob_hash(x), h2 = h;
    h2.hi ^= 1;
    CHECK(!sy_hash_equal(h, h2));
    h2 = h;
    h2.lo ^= 1;
    CHECK(!sy_hash_equal(h, h2));
    /* NULL data with a size is refused */
    sy_blob *bad = (sy_blob *)1;
    CHECK_ERR(sy_blob_create_copy(NULL, 4, &bad, &e), SY_ERR_INVALID_ARGUMENT, e);
    CHECK(bad == NULL);
    /* NULL-safe accessors */
    CHECK(sy_blob_size(NULL) == 0 && sy_blob_data(NULL) == NULL);
    sy_blob_release(NULL);
    CHECK(sy_blob_retain(NULL) == NULL);
    sy_blob_release(x);
    sy_blob_release(y);
    sy_blob_release(z);
    sy_blob_release(empty1);
    sy_blob_release(empty2);
    CHECK(sy_blob_live_count() == live0);
    return 0;
}

static int test_refcount_take(void)
{
    long live0 = sy_blob_live_count();
    sy_error e = {0};
    uint32_t *data = malloc(64 * sizeof *data);
    CHECK(data);
    for (uint32_t i = 0; i < 64; ++i) data[i] = i * 2654435761u;
    sy_blob *b;
    CHECK_OK(sy_blob_create_take(data, 64 * sizeof *data, &b, &e), e);
    /* taken, not copied (realloc may move it to add SY_BLOB_PADDING) */
    CHECK(((const uint32_t *)sy_blob_data(b))[0] == 0u && sy_blob_size(b) == 64 * sizeof *data);
    CHECK(sy_blob_live_count() == live0 + 1);
    CHECK(sy_blob_retain(b) == b);
    sy_blob_retain(b);
    sy_blob_release(b);
    sy_blob_release(b);
    CHECK(sy_blob_live_count() == live0 + 1); /* one reference left */
    CHECK(((const uint32_t *)sy_blob_data(b))[63] == 63u * 2654435761u);
    sy_blob_release(b);
    CHECK(sy_blob_live_count() == live0);
    return 0;
}

static int test_store(void)
{
    sy_error e = {0};
    long live0 = sy_blob_live_count();
    sy_blob_store *st;
    CHECK_OK(sy_blob_store_create(&st, &e), e);
    CHECK(sy_blob_store_count(st) == 0 && sy_blob_store_bytes(st) == 0);

    /* 500 distinct blobs (forces several rehashes), each put twice, plus an equal-content copy */
    enum { N = 500 };
    sy_hash128 hashes[N];
    size_t total = 0;
    for (uint32_t i = 0; i < N; ++i) {
        uint32_t buf[3] = {i, i ^ 0xabcdefu, i * 7u};
        size_t size = 4 + (i % 3) * 4;
        sy_blob *b, *dup;
        CHECK_OK(sy_blob_create_copy(buf, size, &b, &e), e);
        CHECK_OK(sy_blob_create_copy(buf, size, &dup, &e), e);
        hashes[i] = sy_blob_hash(b);
        CHECK_OK(sy_blob_store_put(st, b, &e), e);
        CHECK_OK(sy_blob_store_put(st, b, &e), e);
        CHECK_OK(sy_blob_store_put(st, dup, &e), e); /* same hash: no-op */
        CHECK(sy_blob_store_get(st, sy_blob_hash(dup)) == b); /* the first one stays */
        total += size;
        sy_blob_release(b);
        sy_blob_release(dup);
        CHECK(sy_blob_store_count(st) == i + 1);
    }
    CHECK(sy_blob_store_bytes(st) == total);
    CHECK(sy_blob_live_count() == live0 + N); /* the store holds exactly one of each */
    for (uint32_t i = 0; i < N; ++i) {
        sy_blob *b = sy_blob_store_get(st, hashes[i]);
        CHECK(b != NULL);
        CHECK(sy_hash_equal(sy_blob_hash(b), hashes[i]));
        CHECK(((const uint32_t *)sy_blob_data(b))[0] == i);
    }
    sy_hash128 missing = sy_hash_bytes("not stored", 10);
    CHECK(sy_blob_store_get(st, missing) == NULL);
    CHECK_OK(sy_blob_store_put(st, NULL, &e), e); /* NULL is a no-op */
    CHECK(sy_blob_store_count(st) == N);

    /* a blob retained beyond the store's lifetime survives it */
    sy_blob *keep = sy_blob_retain(sy_blob_store_get(st, hashes[7]));
    sy_blob_store_destroy(st);
    CHECK(sy_blob_live_count() == live0 + 1);
    CHECK(((const uint32_t *)sy_blob_data(keep))[0] == 7);
    sy_blob_release(keep);
    CHECK(sy_blob_live_count() == live0);
    sy_blob_store_destroy(NULL);
    return 0;
}

SY_CHECK_MAIN("test_blob", SY_TEST(test_hash), SY_TEST(test_refcount_take), SY_TEST(test_store))
