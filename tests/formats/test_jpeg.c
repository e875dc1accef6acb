/* test_jpeg.c — formats/sy_jpeg.h: an encoded gradient decodes back to the same size and close to
 * the same pixels (quality 95 and 50: the lower quality is smaller and less exact), bad arguments
 * and malformed or truncated bytes get errors, and the decode limit is enforced; sy_jpeg_write
 * (sy render -o X.jpg) writes what sy_png_write would show, composited over black, and leaves no
 * file behind when it fails. */
#include "../support/sy_check.h"
#include "sy_jpeg.h"

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static uint8_t *gradient(uint32_t w, uint32_t h)
{
    uint8_t *px = malloc((size_t)w * h * 4);
    for (uint32_t y = 0; y < h && px; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            uint8_t *p = px + ((size_t)y * w + x) * 4;
            p[0] = (uint8_t)(x * 255 / (w - 1)), p[1] = (uint8_t)(y * 255 / (h - 1)), p[2] = (uint8_t)((x + y) & 255);
            p[3] = 255;
        }
    return px;
}

/* mean absolute difference of the colour channels */
static double mad(const uint8_t *a, const uint8_t *b, size_t n)
{
    double s = 0;
    for (size_t i = 0; i < n * 4; ++i)
        if ((i & 3) != 3) s += abs((int)a[i] - (int)b[i]);
    return s / (double)(n * 3);
}

static int test_round_trip(void)
{
    sy_error e = {0};
    uint32_t w = 97, h = 61; /* not multiples of the 8x8 / 16x16 blocks */
    uint8_t *px = gradient(w, h), *j95 = NULL, *j50 = NULL, *back = NULL;
    size_t n95 = 0, n50 = 0;
    CHECK(px);
    CHECK_OK(sy_jpeg_encode_rgba8(px, w, h, 95, &j95, &n95, &e), e);
    CHECK_OK(sy_jpeg_encode_rgba8(px, w, h, 50, &j50, &n50, &e), e);
    CHECK(n95 > 100 && j95[0] == 0xFF && j95[1] == 0xD8); /* SOI */
    CHECK(j95[n95 - 2] == 0xFF && j95[n95 - 1] == 0xD9);  /* EOI */
    CHECK_MSG(n50 < n95, "quality 50: %zu bytes, 95: %zu", n50, n95);
    uint32_t bw = 0, bh = 0;
    CHECK_OK(sy_jpeg_decode_rgba8(j95, n95, 0, &back, &bw, &bh, &e), e);
    CHECK(bw == w && bh == h);
    double d95 = mad(px, back, (size_t)w * h);
    CHECK(back[3] == 255);
    free(back);
    CHECK_OK(sy_jpeg_decode_rgba8(j50, n50, 0, &back, &bw, &bh, &e), e);
    double d50 = mad(px, back, (size_t)w * h);
    free(back);
    CHECK_MSG(d95 < 2.0 && d95 < d50 && d50 < 8.0, "mean abs difference: q95 %.3f, q50 %.3f", d95, d50);
    /* the limit: 97 x 61 pixels > 5000 */
    CHECK_ERR(sy_jpeg_decode_rgba8(j95, n95, 5000, &back, &bw, &bh, &e), SY_ERR_LIMIT, e);
    CHECK(back == NULL && bw == 0);
    /* malformed: garbage, a truncated header, nothing */
    uint8_t junk[64];
    memset(junk, 0x5a, sizeof junk);
    CHECK_ERR(sy_jpeg_decode_rgba8(junk, sizeof junk, 0, &back, &bw, &bh, &e), SY_ERR_PARSE, e);
    CHECK_ERR(sy_jpeg_decode_rgba8(j95, 20, 0, &back, &bw, &bh, &e), SY_ERR_PARSE, e);
    CHECK_ERR(sy_jpeg_decode_rgba8(NULL, 0, 0, &back, &bw, &bh, &e), SY_ERR_PARSE, e);
    /* every truncation decodes or fails cleanly (never crashes) */
    for (size_t cut = 0; cut < n95; cut += 7) {
        sy_result r = sy_jpeg_decode_rgba8(j95, cut, 0, &back, &bw, &bh, &e);
        CHECK(r == SY_OK || r == SY_ERR_PARSE);
        free(back);
    }
    free(j95);
    free(j50);
    free(px);
    return 0;
}

static int test_bad_arguments(void)
{
    sy_error e = {0};
    uint8_t px[16] = {0}, *out = (uint8_t *)1;
    size_t n = 1;
    CHECK_ERR(sy_jpeg_encode_rgba8(px, 0, 2, 80, &out, &n, &e), SY_ERR_INVALID_ARGUMENT, e);
    CHECK(out == NULL && n == 0);
    CHECK_ERR(sy_jpeg_encode_rgba8(px, 2, 2, 0, &out, &n, &e), SY_ERR_INVALID_ARGUMENT, e);
    CHECK_ERR(sy_jpeg_encode_rgba8(px, 2, 2, 101, &out, &n, &e), SY_ERR_INVALID_ARGUMENT, e);
    CHECK_ERR(sy_jpeg_encode_rgba8(px, SY_JPEG_MAX_SIDE + 1, 1, 80, &out, &n, &e), SY_ERR_INVALID_ARGUMENT, e);
    CHECK(strstr(e.message, "size") != NULL);
    return 0;
}

/* sy_jpeg_write: linear premultiplied floats (a ramp over 0..4, alpha 1, 0.5 and 0) come back as
 * sy_png_encode_pixel shows each colour over black (ACES tone map, +1 stop), within JPEG's error */
static int test_write(void)
{
    sy_error e = {0};
    enum { W = 64, H = 40 };
    static float rgba[W * H * 4];
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            float *p = rgba + 4 * (y * W + x), a = y < H / 2 ? 1.0f : x < W / 2 ? 0.5f : 0.0f;
            p[0] = 4.0f * (float)x / (W - 1) * a, p[1] = (float)y / (H - 1) * a, p[2] = 0.25f * a, p[3] = a;
        }
    char dir[] = "/tmp/sy-test-jpeg.XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    char path[256];
    snprintf(path, sizeof path, "%s/out.jpg", dir);
    sy_png_options o = {.tonemap = SY_TONEMAP_ACES, .exposure_stops = 1.0f};
    CHECK_OK(sy_jpeg_write(path, W, H, rgba, &o, 92, &e), e);
    FILE *f = fopen(path, "rb");
    CHECK(f != NULL);
    static uint8_t bytes[1 << 16];
    size_t n = f ? fread(bytes, 1, sizeof bytes, f) : 0;
    if (f) fclose(f);
    uint8_t *back = NULL;
    uint32_t bw = 0, bh = 0;
    CHECK_OK(sy_jpeg_decode_rgba8(bytes, n, 0, &back, &bw, &bh, &e), e);
    CHECK(bw == W && bh == H);
    static uint8_t want[W * H * 4];
    for (int i = 0; i < W * H; ++i) {
        const float c[4] = {rgba[4 * i], rgba[4 * i + 1], rgba[4 * i + 2], 1.0f};
        sy_png_encode_pixel(c, &o, want + 4 * i);
    }
    double d = back ? mad(want, back, (size_t)W * H) : 1e9;
    CHECK_MSG(d < 2.0, "mean abs difference against the PNG encoding over black: %.3f", d);
    /* the transparent corner is black, the half-transparent one darker than the opaque row above */
    CHECK_MSG(back && back[4 * ((H - 1) * W + W - 1)] < 4, "transparent pixel %d", back ? back[4 * ((H - 1) * W + W - 1)] : -1);
    free(back);
    /* a failure (a folder that is not there; an image too large) leaves no file, no temporary */
    char bad[300];
    snprintf(bad, sizeof bad, "%s/missing/out.jpg", dir);
    CHECK(sy_jpeg_write(bad, W, H, rgba, &o, 92, &e) != SY_OK);
    CHECK_ERR(sy_jpeg_write(path, (int)SY_JPEG_MAX_SIDE + 1, 1, rgba, &o, 92, &e), SY_ERR_INVALID_ARGUMENT, e);
    CHECK_ERR(sy_jpeg_write(path, W, H, rgba, &o, 0, &e), SY_ERR_INVALID_ARGUMENT, e);
    DIR *dd = opendir(dir);
    int entries = 0;
    for (struct dirent *de; dd && (de = readdir(dd));)
        if (de->d_name[0] != '.') entries++;
    if (dd) closedir(dd);
    CHECK_MSG(entries == 1, "%d files in the folder (want out.jpg only)", entries);
    unlink(path);
    rmdir(dir);
    return 0;
}

SY_CHECK_MAIN("test_jpeg", SY_TEST(test_round_trip), SY_TEST(test_bad_arguments), SY_TEST(test_write))
