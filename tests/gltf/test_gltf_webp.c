/* test_gltf_webp.c — EXT_texture_webp: a 5x3 WebP encoded by the test (libwebp's lossless
 * WebPEncodeLosslessRGBA, so the decoded pixels must equal the source exactly) is the base colour
 * texture of a generated one-triangle glTF, named only by the extension's source (as a file and as a
 * data:image/webp URI; and once with a fallback source beside it: the WebP wins). WebP named by a plain texture source (no extension), a
 * corrupt WebP and one over max_image_pixels load with a warning and no texture (stb_image never
 * sees WebP). A file requiring KHR_texture_basisu is refused naming it. Needs no shared data. */
#include "../support/sy_check.h"
#include "../support/sy_scratch.h"
#include "sy_gltf.h"

#include <webp/encode.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

enum { W = 5, H = 3 };
static char g_dir[256];
static uint8_t g_rgba[W * H * 4];

static void write_file(const char *name, const void *data, size_t n)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", g_dir, name);
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(data, 1, n, f) != n) {
        fprintf(stderr, "cannot write %s\n", path);
        exit(1);
    }
    fclose(f);
}

/* "data:image/webp;base64,..." of n bytes (malloc()ed). */
static char *webp_data_uri(const uint8_t *b, size_t n)
{
    static const char tbl[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    char *s = malloc(64 + (n + 2) / 3 * 4), *o = s + sprintf(s, "data:image/webp;base64,");
    for (size_t i = 0; i < n; i += 3) {
        uint32_t v = (uint32_t)b[i] << 16 | (i + 1 < n ? (uint32_t)b[i + 1] << 8 : 0) | (i + 2 < n ? b[i + 2] : 0);
        *o++ = tbl[v >> 18 & 63];
        *o++ = tbl[v >> 12 & 63];
        *o++ = i + 1 < n ? tbl[v >> 6 & 63] : '=';
        *o++ = i + 2 < n ? tbl[v & 63] : '=';
    }
    *o = '\0';
    return s;
}

/* One triangle with TEXCOORD_0 (m.bin), material 0 with baseColorTexture 0; textures / images and
 * extensions from the arguments. */
static void write_doc(const char *name, const char *textures, const char *images, const char *ext)
{
    char json[4096];
    int n = snprintf(json, sizeof json,
                     "{\"asset\":{\"version\":\"2.0\"}%s,\"buffers\":[{\"uri\":\"m.bin\",\"byteLength\":60}],"
                     "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":24}],"
                     "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\",\"min\":[0,0,0],\"max\":[1,1,0]},"
                     "{\"bufferView\":1,\"componentType\":5126,\"count\":3,\"type\":\"VEC2\"}],"
                     "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1},\"material\":0}]}],"
                     "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0}}}],"
                     "\"textures\":[%s],\"images\":[%s],\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}],\"scene\":0}",
                     ext, textures, images);
    write_file(name, json, (size_t)n);
}

/* Loads name expecting result want: with SY_OK a warning containing warn (NULL: none looked for) and
 * the base colour texture present (with the encoded pixels) or missing; otherwise an error naming
 * the file and containing warn. */
static bool load(const char *name, const sy_gltf_options *opt, sy_result want, const char *warn, bool expect_texture)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", g_dir, name);
    sy_scene *s = NULL;
    sy_error e = {0};
    if (sy_scene_create(&s, &e) != SY_OK) exit(1);
    sy_gltf_info info;
    sy_result r = sy_gltf_load(path, s, opt, &info, &e);
    EXPECT_MSG(r == want, "%s: result %d (%s)", name, (int)r, e.message);
    bool warned = warn == NULL;
    if (r == SY_OK) {
        for (uint32_t k = 0; warn && k < info.stored_warning_count; k++) warned |= strstr(info.warnings[k], warn) != NULL;
        EXPECT_MSG(warned, "%s: no warning '%s' (%u warnings%s%s)", name, warn ? warn : "", info.stored_warning_count,
                   info.stored_warning_count ? ": " : "", info.stored_warning_count ? info.warnings[0] : "");
        const sy_material_data *m = sy_material_get(s, (sy_material){sy_scene_next(s, SY_TYPE_MATERIAL, 0)});
        const sy_texture_data *t = m ? sy_texture_get(s, m->base_color_texture.texture) : NULL;
        EXPECT_MSG((t != NULL) == expect_texture, "%s: texture %s", name, t ? "present" : "missing");
        if (t && expect_texture) {
            EXPECT_MSG(t->info.width == W && t->info.height == H && t->info.channels == 4 && t->info.format == SY_PIXEL_U8_SRGB,
                       "%s: %ux%u x %u", name, t->info.width, t->info.height, t->info.channels);
            EXPECT_MSG(t->info.width == W && t->info.height == H && !memcmp(sy_blob_data(t->pixels), g_rgba, sizeof g_rgba),
                       "%s: decoded pixels differ from the encoded ones", name);
        }
        sy_gltf_info_free(&info);
    } else {
        EXPECT_MSG(strstr(e.message, path) && warn && strstr(e.message, warn), "%s: message '%s'", name, e.message);
        warned = true;
    }
    sy_scene_destroy(s);
    printf("ok %s\n", name);
    return warned;
}

int main(void)
{
    make_scratch_dir(g_dir, sizeof g_dir, "gltf_webp");
    const float mesh[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 1};
    write_file("m.bin", mesh, sizeof mesh);
    for (int i = 0; i < W * H; i++) {
        g_rgba[4 * i + 0] = (uint8_t)(i * 17);
        g_rgba[4 * i + 1] = (uint8_t)(255 - i * 13);
        g_rgba[4 * i + 2] = (uint8_t)(i * 5 + 40);
        g_rgba[4 * i + 3] = 255;
    }
    uint8_t *webp = NULL;
    size_t n = WebPEncodeLosslessRGBA(g_rgba, W, H, W * 4, &webp);
    EXPECT_MSG(n > 12 && !memcmp(webp, "RIFF", 4), "WebPEncodeLosslessRGBA: %zu bytes", n);
    write_file("t.webp", webp, n);
    char *uri = webp_data_uri(webp, n), image[512];
    snprintf(image, sizeof image, "{\"uri\":\"%s\"}", uri);
    free(uri);
    uint8_t *bad = malloc(n);
    memcpy(bad, webp, n);
    for (size_t i = 20; i < n; i++) bad[i] ^= 0x5A;
    write_file("bad.webp", bad, n);
    free(bad);
    WebPFree(webp);
    const char *ext = ",\"extensionsUsed\":[\"EXT_texture_webp\"],\"extensionsRequired\":[\"EXT_texture_webp\"]";

    write_doc("webp.gltf", "{\"extensions\":{\"EXT_texture_webp\":{\"source\":0}}}", "{\"uri\":\"t.webp\"}", ext);
    load("webp.gltf", NULL, SY_OK, NULL, true);
    /* as a data:image/webp URI (which tinygltf takes for a file name unless the shim rewrites it) */
    write_doc("data_uri.gltf", "{\"extensions\":{\"EXT_texture_webp\":{\"source\":0}}}", image, ext);
    load("data_uri.gltf", NULL, SY_OK, NULL, true);
    /* a fallback source beside it (a missing PNG: a warning only): the extension's source is used */
    write_doc("fallback.gltf", "{\"source\":1,\"extensions\":{\"EXT_texture_webp\":{\"source\":0}}}",
              "{\"uri\":\"t.webp\"},{\"uri\":\"missing.png\"}", ",\"extensionsUsed\":[\"EXT_texture_webp\"]");
    load("fallback.gltf", NULL, SY_OK, NULL, true);
    /* WebP without the extension: not decoded */
    write_doc("plain_source.gltf", "{\"source\":0}", "{\"uri\":\"t.webp\"}", "");
    load("plain_source.gltf", NULL, SY_OK, "WebP image content outside EXT_texture_webp", false);
    write_doc("corrupt.gltf", "{\"extensions\":{\"EXT_texture_webp\":{\"source\":0}}}", "{\"uri\":\"bad.webp\"}", ext);
    load("corrupt.gltf", NULL, SY_OK, "WebP", false);
    sy_gltf_options opt = {0};
    opt.max_image_pixels = 14;
    load("webp.gltf", &opt, SY_OK, "image 5x3 exceeds the limit of 14 pixels", false);
    /* no Debian package decodes Basis Universal / KTX2 */
    write_doc("basisu.gltf", "{\"extensions\":{\"KHR_texture_basisu\":{\"source\":0}}}", "{\"uri\":\"t.ktx2\"}",
              ",\"extensionsUsed\":[\"KHR_texture_basisu\"],\"extensionsRequired\":[\"KHR_texture_basisu\"]");
    load("basisu.gltf", NULL, SY_ERR_UNSUPPORTED, "'KHR_texture_basisu' is not supported: no Debian package decodes", false);

    const char *files[] = {"m.bin",         "t.webp",        "bad.webp",          "webp.gltf",  "data_uri.gltf",
                           "fallback.gltf", "plain_source.gltf", "corrupt.gltf", "basisu.gltf"};
    for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) {
        char path[512];
        snprintf(path, sizeof path, "%s/%s", g_dir, files[i]);
        unlink(path);
    }
    rmdir(g_dir);
    return sy_check_finish("gltf_webp");
}
