/* test_world.c — environment maps read by sy_world_load_environment: a Radiance HDR (.hdr) written
 * by stb_image_write comes back with its texel values (RGBE keeps 8 bits of mantissa); bad files
 * (a header whose size the bytes cannot hold, a map past the budget, not 2:1, no header, negative
 * texels cannot occur in RGBE) get an error naming the file, before anything large is allocated. */
#include "test_util.h"

#include "sy_world.h"

#include <math.h>
#include <stb_image_write.h>

static char dir[512];

/* An 8 x 4 map: texel (x, y) = (x + 1, y + 0.5, 0.25 * (x + y)) x 10^(x - 4), a range of radiances
 * from 10^-4 to 10^3, as real environments have. */
static void texel(int x, int y, float out[3])
{
    float s = powf(10.0f, (float)(x - 4));
    out[0] = (float)(x + 1) * s, out[1] = ((float)y + 0.5f) * s, out[2] = 0.25f * (float)(x + y) * s;
}

static int hdr_round_trip(void)
{
    float px[8 * 4 * 3];
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 8; ++x) texel(x, y, px + (y * 8 + x) * 3);
    char path[600];
    PATHF(path, "%s/sky.hdr", dir);
    CHECK(stbi_write_hdr(path, 8, 4, 3, px) == 1);
    sy_scene *s = NULL;
    sy_error e = {0};
    CHECK_OK(sy_scene_create(&s, &e), e);
    sy_texture t = {0};
    EXPECT_OK(sy_world_load_environment(s, path, 0, &t, &e), e);
    const sy_texture_data *td = sy_texture_get(s, t);
    EXPECT(td && td->info.width == 8 && td->info.height == 4 && td->info.channels == 3 && td->info.format == SY_PIXEL_F32);
    if (td) {
        const float *got = sy_blob_data(td->pixels);
        float worst = 0.0f; /* relative to the texel's largest channel: RGBE's shared exponent */
        for (int i = 0; i < 8 * 4; ++i) {
            float m = fmaxf(px[i * 3], fmaxf(px[i * 3 + 1], px[i * 3 + 2]));
            for (int c = 0; c < 3; ++c) worst = fmaxf(worst, fabsf(got[i * 3 + c] - px[i * 3 + c]) / m);
        }
        EXPECT_MSG(worst < 1.0f / 128.0f, "largest error %g of the texel's largest channel (RGBE: < 1/128)", (double)worst);
        /* row 0 is the top: the texel (7, 0) is brighter than (0, 3) by 10^7 / ... */
        EXPECT_NEAR(got[(0 * 8 + 7) * 3], 8000.0f, 8000.0f / 128.0f);
    }
    /* a budget smaller than the 384 bytes of float RGB: refused, naming the file */
    EXPECT_ERR(sy_world_load_environment(s, path, 256, &t, &e), SY_ERR_LIMIT, e);
    EXPECT_SAYS(e, "sky.hdr");
    sy_scene_destroy(s);
    return 0;
}

/* Writes bytes as dir/name and expects sy_world_load_environment to refuse it (SY_ERR_PARSE) with a
 * message naming the file and saying needle. */
static void refused(sy_scene *s, const char *name, const void *bytes, size_t n, const char *needle)
{
    char path[600];
    PATHF(path, "%s/%s", dir, name);
    EXPECT(write_bytes(path, bytes, n) == 0);
    sy_texture t = {0};
    sy_error e = {0};
    EXPECT_ERR(sy_world_load_environment(s, path, 0, &t, &e), SY_ERR_PARSE, e);
    EXPECT_SAYS(e, name);
    EXPECT_SAYS(e, needle);
}

static int bad_files(void)
{
    sy_scene *s = NULL;
    sy_error e = {0};
    CHECK_OK(sy_scene_create(&s, &e), e);
    sy_texture t = {0};
    char path[600];
    /* 10^5 x 5 x 10^4 texels claimed by a 60-byte file: refused from the header alone (decoding would
     * allocate 60 GB) */
    static const char huge[] = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 50000 +X 100000\n\x02\x02";
    refused(s, "huge.hdr", huge, sizeof huge - 1, "truncated");
    /* a header without its size line */
    static const char headless[] = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\nnot a size\n";
    refused(s, "headless.hdr", headless, sizeof headless - 1, "Radiance HDR header");
    /* a square map is no lat-long map */
    float sq[4 * 4 * 3];
    for (int i = 0; i < 4 * 4 * 3; ++i) sq[i] = 1.0f;
    PATHF(path, "%s/square.hdr", dir);
    CHECK(stbi_write_hdr(path, 4, 4, 3, sq) == 1);
    EXPECT_ERR(sy_world_load_environment(s, path, 0, &t, &e), SY_ERR_PARSE, e);
    EXPECT_SAYS(e, "lat-long");
    /* truncated pixel data: the header says 8 x 4 but the scanlines stop after the first */
    float px[8 * 4 * 3];
    for (int i = 0; i < 8 * 4 * 3; ++i) px[i] = 0.5f;
    PATHF(path, "%s/cut.hdr", dir);
    CHECK(stbi_write_hdr(path, 8, 4, 3, px) == 1);
    struct stat st;
    CHECK(stat(path, &st) == 0 && st.st_size > 40);
    CHECK(truncate(path, st.st_size - 40) == 0);
    EXPECT_ERR(sy_world_load_environment(s, path, 0, &t, &e), SY_ERR_PARSE, e);
    EXPECT_SAYS(e, "cut.hdr");
    sy_scene_destroy(s);
    return 0;
}

int main(void)
{
    make_scratch_dir(dir, sizeof dir, "world");
    RUN(hdr_round_trip);
    RUN(bad_files);
    remove_scratch_dir(dir);
    return sy_check_finish("formats_world");
}
