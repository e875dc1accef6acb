/* test_png.c — sy_png: sRGB OETF values, tone mapping, alpha un-premultiplying, clamping,
 * orientation, the sRGB chunk, atomic output and damaged input. Expected bytes are computed here
 * independently (double precision formula), not with the functions under test. */
#include "sy_png.h"

#include "test_util.h"

#include <math.h>

static double ref_oetf(double v)
{
    if (v <= 0) return 0;
    if (v >= 1) return 1;
    return v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1.0 / 2.4) - 0.055;
}

static int ref_byte(double v01) { return (int)floor(v01 * 255.0 + 0.5); }

static void test_helpers(void)
{
    EXPECT_MSG(sy_srgb_encode(0.0f) == 0.0f && sy_srgb_encode(1.0f) == 1.0f, "end points");
    EXPECT_MSG(sy_srgb_encode(-1.0f) == 0.0f && sy_srgb_encode(7.0f) == 1.0f && sy_srgb_encode(NAN) == 0.0f, "clamping");
    EXPECT_MSG(fabsf(sy_srgb_encode(0.5f) - 0.735357f) < 2e-6f, "0.5 -> %.7f", (double)sy_srgb_encode(0.5f));
    EXPECT_MSG(ref_byte(sy_srgb_encode(0.5f)) == 188, "0.5 must encode to byte 188");
    /* The two pieces meet at 0.0031308 -> 0.04045 (continuous to ~1e-7). */
    float lo = sy_srgb_encode(0.0031308f), hi = sy_srgb_encode(nextafterf(0.0031308f, 1.0f));
    EXPECT_MSG(fabsf(lo - 0.04045f) < 1e-6f && fabsf(hi - lo) < 1e-6f, "boundary %.8f %.8f", (double)lo, (double)hi);
    EXPECT_MSG(fabsf(sy_srgb_encode(0.001f) - 0.01292f) < 1e-7f, "linear segment");
    for (float v = 0.0f; v <= 1.0f; v += 0.001f) {
        float rt = sy_srgb_decode(sy_srgb_encode(v));
        if (fabsf(rt - v) > 1e-5f) {
            EXPECT_MSG(0, "decode(encode(%g)) = %g", (double)v, (double)rt);
            break;
        }
        if (fabsf(sy_srgb_encode(v) - (float)ref_oetf(v)) > 2e-6f) {
            EXPECT_MSG(0, "encode(%g) = %.8f, reference %.8f", (double)v, (double)sy_srgb_encode(v), ref_oetf(v));
            break;
        }
    }
    EXPECT_MSG(fabsf(sy_srgb_decode(0.04045f) - 0.0031308f) < 1e-7f, "decode boundary");

    EXPECT_MSG(sy_tonemap_apply(SY_TONEMAP_CLAMP, 2.0f) == 1.0f, "clamp >1");
    EXPECT_MSG(sy_tonemap_apply(SY_TONEMAP_CLAMP, 0.3f) == 0.3f, "clamp passes through");
    EXPECT_MSG(sy_tonemap_apply(SY_TONEMAP_CLAMP, -0.3f) == 0.0f, "clamp negative");
    EXPECT_MSG(sy_tonemap_apply(SY_TONEMAP_REINHARD, 1.0f) == 0.5f, "reinhard 1 -> 0.5");
    EXPECT_MSG(sy_tonemap_apply(SY_TONEMAP_REINHARD, INFINITY) == 1.0f, "reinhard inf");
    double x = 0.8, aces = (x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14);
    EXPECT_MSG(fabs(sy_tonemap_apply(SY_TONEMAP_ACES, 0.8f) - aces) < 1e-6, "aces 0.8");
    EXPECT_MSG(sy_tonemap_apply(SY_TONEMAP_ACES, 1000.0f) == 1.0f, "aces saturates at 1");
    EXPECT_MSG(sy_tonemap_apply(SY_TONEMAP_ACES, NAN) == 0.0f, "aces NaN");
}

typedef struct px_case {
    float in[4];      /* premultiplied linear */
    sy_png_options o; /* options for this pixel's image */
    int want[4];      /* -1: compute from want_lin */
    double want_lin[4];
} px_case;

/* Writes a 1xN image per option set and reads it back. */
static void check_pixels(const char *dir, const px_case *cases, int n, const char *label)
{
    char p[4096];
    PATHF(p, "%s/%s.png", dir, label);
    float *img = malloc(sizeof(float) * 4 * (size_t)n);
    for (int i = 0; i < n; ++i) memcpy(img + 4 * i, cases[i].in, sizeof cases[i].in);
    sy_error err = {0};
    EXPECT_MSG(sy_png_write(p, n, 1, img, &cases[0].o, &err) == SY_OK, "%s: %s", label, err.message);
    int w = 0, h = 0;
    uint8_t *px = NULL;
    EXPECT_MSG(sy_png_read_rgba8(p, &w, &h, &px, &err) == SY_OK, "%s: %s", label, err.message);
    EXPECT_MSG(w == n && h == 1, "%s: size %dx%d", label, w, h);
    for (int i = 0; px && i < n; ++i) {
        for (int c = 0; c < 4; ++c) {
            int want = cases[i].want[c] >= 0 ? cases[i].want[c] : ref_byte(ref_oetf(cases[i].want_lin[c]));
            EXPECT_MSG(px[4 * i + c] == want, "%s pixel %d channel %d: got %d want %d", label, i, c, px[4 * i + c], want);
        }
        uint8_t direct[4];
        sy_png_encode_pixel(cases[i].in, &cases[i].o, direct);
        EXPECT_MSG(memcmp(direct, px + 4 * i, 4) == 0, "%s pixel %d: sy_png_encode_pixel differs from the file", label, i);
    }
    free(px);
    free(img);
}

static void test_values(const char *dir)
{
    const px_case plain[] = {
        {{0.5f, 0.5f, 0.5f, 1.0f}, {.tonemap = SY_TONEMAP_CLAMP}, {188, 188, 188, 255}, {0}},
        {{0.0f, 1.0f, 2.5f, 1.0f}, {.tonemap = SY_TONEMAP_CLAMP}, {0, 255, 255, 255}, {0}}, /* >1 clamps */
        {{-1.0f, NAN, 0.0031308f, 1.0f}, {.tonemap = SY_TONEMAP_CLAMP}, {0, 0, 10, 255}, {0}}, /* negative, NaN, boundary */
        {{0.0031f, 0.0032f, 0.2140f, 1.0f}, {.tonemap = SY_TONEMAP_CLAMP}, {-1, -1, -1, 255}, {0.0031, 0.0032, 0.2140}},
        {{0.25f, 0.25f, 0.25f, 0.5f}, {.tonemap = SY_TONEMAP_CLAMP}, {188, 188, 188, 128}, {0}}, /* un-premultiply: 0.5 straight */
        {{0.1f, 0.05f, 0.0f, 0.2f}, {.tonemap = SY_TONEMAP_CLAMP}, {-1, -1, 0, 51}, {0.5, 0.25, 0}},
        {{0.3f, 0.3f, 0.3f, 0.0f}, {.tonemap = SY_TONEMAP_CLAMP}, {0, 0, 0, 0}, {0}},   /* alpha 0 */
        {{0.9f, 0.9f, 0.9f, 0.6f}, {.tonemap = SY_TONEMAP_CLAMP}, {255, 255, 255, 153}, {0}}, /* straight 1.5 clamps */
        {{0.5f, 0.5f, 0.5f, 1.7f}, {.tonemap = SY_TONEMAP_CLAMP}, {-1, -1, -1, 255}, {0.5 / 1.7, 0.5 / 1.7, 0.5 / 1.7}}, /* alpha > 1 */
    };
    check_pixels(dir, plain, (int)(sizeof plain / sizeof plain[0]), "plain");

    const sy_png_options up1 = {.exposure_stops = 1.0f};
    const px_case exposed[] = {
        {{0.25f, 0.125f, 0.6f, 1.0f}, up1, {188, -1, 255, 255}, {0.5, 0.25, 1.2}},
        {{0.125f, 0.125f, 0.125f, 0.5f}, up1, {188, 188, 188, 128}, {0}},
    };
    check_pixels(dir, exposed, 2, "exposure");

    const sy_png_options rh = {.tonemap = SY_TONEMAP_REINHARD};
    const px_case reinhard[] = {
        {{1.0f, 3.0f, 0.25f, 1.0f}, rh, {188, -1, -1, 255}, {0.5, 0.75, 0.2}},
        {{1000.0f, 0.0f, 0.5f, 0.5f}, rh, {-1, 0, 188, 128}, {2000.0 / 2001.0, 0, 0.5}},
    };
    check_pixels(dir, reinhard, 2, "reinhard");

    const sy_png_options ac = {.tonemap = SY_TONEMAP_ACES, .exposure_stops = -1.0f};
    double a1 = 0.4, a2 = 0.05;
    double t1 = (a1 * (2.51 * a1 + 0.03)) / (a1 * (2.43 * a1 + 0.59) + 0.14);
    double t2 = (a2 * (2.51 * a2 + 0.03)) / (a2 * (2.43 * a2 + 0.59) + 0.14);
    const px_case aces[] = {
        {{0.8f, 0.1f, 100.0f, 1.0f}, ac, {-1, -1, 255, 255}, {t1, t2, 1.0}},
    };
    check_pixels(dir, aces, 1, "aces");
}

static void test_file_properties(const char *dir)
{
    /* Orientation: a 3x4 image whose red encodes the row; row 0 must come first in the file. */
    const int w = 3, h = 4;
    float img[3 * 4 * 4];
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float *p = img + 4 * (y * w + x);
            p[0] = (float)y / 3.0f;
            p[1] = (float)x / 2.0f;
            p[2] = 0.0f;
            p[3] = 1.0f;
        }
    char p[4096];
    PATHF(p, "%s/orient.png", dir);
    sy_error err = {0};
    EXPECT_MSG(sy_png_write(p, w, h, img, NULL, &err) == SY_OK, "%s", err.message);
    int rw = 0, rh = 0;
    uint8_t *px = NULL;
    EXPECT_MSG(sy_png_read_rgba8(p, &rw, &rh, &px, &err) == SY_OK, "%s", err.message);
    EXPECT_MSG(rw == w && rh == h, "size %dx%d", rw, rh);
    for (int y = 0; px && y < h; ++y)
        for (int x = 0; x < w; ++x) {
            EXPECT_MSG(px[4 * (y * w + x)] == ref_byte(ref_oetf(y / 3.0)), "row %d red", y);
            EXPECT_MSG(px[4 * (y * w + x) + 1] == ref_byte(ref_oetf(x / 2.0)), "column %d green", x);
        }
    free(px);

    /* The file is an RGBA8 PNG with an sRGB chunk. */
    size_t n = 0;
    unsigned char *bytes = slurp(p, &n);
    EXPECT_MSG(bytes && n > 33 && memcmp(bytes, "\x89PNG\r\n\x1a\n", 8) == 0, "PNG signature");
    bool has_srgb = false;
    for (size_t i = 0; bytes && i + 4 <= n; ++i)
        if (memcmp(bytes + i, "sRGB", 4) == 0) has_srgb = true;
    EXPECT_MSG(has_srgb, "no sRGB chunk");
    EXPECT_MSG(bytes && bytes[24] == 8 && bytes[25] == 6, "IHDR: bit depth %d colour type %d", bytes ? bytes[24] : -1,
               bytes ? bytes[25] : -1);
    EXPECT_MSG(count_entries_containing(dir, ".tmp-") == 0, "temporary file left behind");

    /* Truncated and garbage input give errors naming the file, never a crash. */
    char q[4096];
    PATHF(q, "%s/cut.png", dir);
    /* Every cut before the final 12-byte IEND chunk loses image data; libpng (rightly) still
     * decodes a file whose pixels are complete but whose IEND is missing. */
    for (size_t len = 0; bytes && len + 12 < n; ++len) {
        write_bytes(q, bytes, len);
        uint8_t *out = NULL;
        int a = 0, b = 0;
        sy_result r = sy_png_read_rgba8(q, &a, &b, &out, &err);
        if (r == SY_OK || out) {
            EXPECT_MSG(0, "PNG cut at %zu of %zu accepted", len, n);
            free(out);
            break;
        }
        if (!strstr(err.message, q)) {
            EXPECT_MSG(0, "message does not name the file: %s", err.message);
            break;
        }
    }
    free(bytes);
    unsigned char junk[300];
    uint32_t s = 5;
    for (size_t i = 0; i < sizeof junk; ++i) junk[i] = (unsigned char)((s = s * 1103515245u + 12345u) >> 16);
    write_bytes(q, junk, sizeof junk);
    uint8_t *out = NULL;
    int a = 0, b = 0;
    EXPECT_MSG(sy_png_read_rgba8(q, &a, &b, &out, &err) == SY_ERR_PARSE && out == NULL, "garbage accepted");
    PATHF(q, "%s/missing.png", dir);
    EXPECT_MSG(sy_png_read_rgba8(q, &a, &b, &out, &err) == SY_ERR_NOT_FOUND, "missing file: %s", err.message);

    /* Failed writes: missing directory (nothing created), invalid arguments (target untouched). */
    PATHF(q, "%s/no_such_dir/x.png", dir);
    sy_result r = sy_png_write(q, w, h, img, NULL, &err);
    EXPECT_MSG(r != SY_OK && strstr(err.message, q) != NULL, "missing directory: %d %s", (int)r, err.message);
    EXPECT_MSG(!path_exists(q), "file created in a missing directory");
    sy_png_options bad = {.exposure_stops = NAN};
    EXPECT_MSG(sy_png_write(p, w, h, img, &bad, &err) == SY_ERR_INVALID_ARGUMENT, "NaN exposure accepted");
    bad = (sy_png_options){.tonemap = (sy_tonemap)42};
    EXPECT_MSG(sy_png_write(p, w, h, img, &bad, &err) == SY_ERR_INVALID_ARGUMENT, "unknown tone map accepted");
    EXPECT_MSG(sy_png_write(p, 0, h, img, NULL, &err) == SY_ERR_INVALID_ARGUMENT, "zero width accepted");
    EXPECT_MSG(sy_png_read_rgba8(p, &rw, &rh, &px, &err) == SY_OK && rw == w && rh == h, "target damaged");
    free(px);
}

/* sy_png_read_info: the text chunks sy_png_write wrote come back with the size, pixels not decoded;
 * a cut or garbage file is an error naming it (sy info IMAGE.png, issue 32) */
static void test_metadata(const char *dir)
{
    const int w = 5, h = 3;
    float img[5 * 3 * 4] = {0};
    const sy_png_text texts[] = {{"sy:backend", "whitted"}, {"sy:samples", "7"}, {"sy:source", ""}};
    sy_png_options o = {.text = texts, .text_count = 3};
    char p[4096], q[4096];
    PATHF(p, "%s/meta.png", dir);
    sy_error err = {0};
    EXPECT_MSG(sy_png_write(p, w, h, img, &o, &err) == SY_OK, "%s", err.message);
    sy_png_info pi;
    EXPECT_MSG(sy_png_read_info(p, &pi, &err) == SY_OK, "%s", err.message);
    EXPECT_MSG(pi.width == w && pi.height == h && pi.text_count == 3, "%dx%d, %d texts", pi.width, pi.height, pi.text_count);
    for (int i = 0; i < pi.text_count && i < 3; ++i)
        EXPECT_MSG(!strcmp(pi.keys[i], texts[i].key) && !strcmp(pi.values[i], texts[i].value), "text %d: %s=%s", i,
                   pi.keys[i], pi.values[i]);
    sy_png_info_free(&pi);
    sy_png_info_free(&pi); /* twice: safe */
    size_t n = 0;
    unsigned char *bytes = slurp(p, &n);
    PATHF(q, "%s/meta_cut.png", dir);
    for (size_t len = 0; bytes && len < 40; ++len) { /* inside the signature, IHDR or a text chunk */
        write_bytes(q, bytes, len);
        if (sy_png_read_info(q, &pi, &err) == SY_OK) {
            EXPECT_MSG(0, "PNG cut at %zu accepted", len);
            sy_png_info_free(&pi);
            break;
        }
        EXPECT_MSG(strstr(err.message, q) != NULL && pi.text_count == 0, "cut at %zu: %s", len, err.message);
    }
    free(bytes);
    EXPECT_MSG(sy_png_read_info(p + 0, &pi, &err) == SY_OK, "%s", err.message);
    sy_png_info_free(&pi);
    PATHF(q, "%s/missing.png", dir);
    EXPECT_MSG(sy_png_read_info(q, &pi, &err) == SY_ERR_NOT_FOUND, "missing file: %s", err.message);
}

int main(void)
{
    char dir[4096];
    make_scratch_dir(dir, sizeof dir, "png");
    test_helpers();
    test_values(dir);
    test_file_properties(dir);
    test_metadata(dir);
    remove_scratch_dir(dir);
    return sy_check_finish("test_png");
}
