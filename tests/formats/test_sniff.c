/* test_sniff.c — sy_sniff: every format recognised from its first bytes (signatures, leading
 * whitespace and byte order marks, OBJ after comments), look-alikes left unknown (plain text, an
 * XML file that is not X3D, a word starting with "v"), the formats read through Assimp (binary STL
 * by its size rule, 3DS, 3MF, ASCII FBX, glTF 1.0), and files: a missing one and a folder are
 * errors naming them. */
#include "sy_sniff.h"

#include "test_util.h"

#include <stdio.h>
#include <string.h>

static sy_file_format of(const char *s) { return sy_sniff_bytes(s, strlen(s)); }

int main(void)
{
    static const struct {
        const char *bytes;
        sy_file_format want;
    } cases[] = {
        {"{\"asset\": {\"version\": \"2.0\"}}", SY_FORMAT_GLTF},
        {"\xef\xbb\xbf  \n{\"asset\":{}}", SY_FORMAT_GLTF},
        {"glTF\x02\x00\x00\x00", SY_FORMAT_GLB},
        {"<?xml version=\"1.0\"?>\n<!DOCTYPE X3D PUBLIC \"ISO//Web3D//DTD X3D 3.3//EN\" \"x\">\n<X3D>", SY_FORMAT_X3D},
        {"<X3D profile='Interchange' version='4.0'><Scene/></X3D>", SY_FORMAT_X3D},
        {"<?xml version=\"1.0\"?><COLLADA xmlns=\"x\">", SY_FORMAT_COLLADA},
        {"#VRML V2.0 utf8\nShape {}", SY_FORMAT_VRML},
        {"#X3D V3.3 utf8\nPROFILE Interchange", SY_FORMAT_VRML},
        {"# Blender OBJ\n# comment\n\nmtllib a.mtl\no Cube\nv 1 1 1\n", SY_FORMAT_OBJ},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", SY_FORMAT_OBJ},
        {"ply\nformat ascii 1.0\n", SY_FORMAT_PLY},
        {"solid cube\n  facet normal 0 0 1\n", SY_FORMAT_STL},
        {"Kaydara FBX Binary  \x00", SY_FORMAT_FBX},
        {"; FBX 7.4.0 project file\n; ----\n", SY_FORMAT_FBX},
        {"PK\x03\x04\x14\x01\x01\x01 (a local file header) 3D/3dmodel.model", SY_FORMAT_3MF},
        {"PK\x03\x04\x14\x01\x01\x01 (a local file header) word/document.xml", SY_FORMAT_UNKNOWN},
        {"{\"accessors\": {\"a\": {\"count\": 3}}}", SY_FORMAT_GLTF1},
        {"{\"asset\": {\"version\": \"1.0\"}}", SY_FORMAT_GLTF1},
        {"{\"asset\": {\"version\": \"2.0\"}, \"accessors\": []}", SY_FORMAT_GLTF},
        {"{\"accessors\": [{\"count\": 3}]}", SY_FORMAT_GLTF},
        {"\x89PNG\r\n\x1a\n\x00\x00", SY_FORMAT_PNG},
        {"\x76\x2f\x31\x01\x02", SY_FORMAT_EXR},
        {"\xff\xd8\xff\xe0", SY_FORMAT_JPEG},
        {"GIF89a\x01\x00", SY_FORMAT_GIF},
        {"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n", SY_FORMAT_RADIANCE},
        {"#?RGBE\n", SY_FORMAT_RADIANCE},
        {"RIFF\x1a\x01\x02\x03WEBPVP8L", SY_FORMAT_WEBP},
        /* look-alikes */
        {"hello world\n", SY_FORMAT_UNKNOWN},
        {"<?xml version=\"1.0\"?><svg/>", SY_FORMAT_UNKNOWN},
        {"very nice\n", SY_FORMAT_UNKNOWN},
        {"v\n", SY_FORMAT_UNKNOWN},
        {"solid but no facets", SY_FORMAT_UNKNOWN},
        {"RIFF\x1a\x01\x02\x03WAVEfmt ", SY_FORMAT_UNKNOWN},
        {"", SY_FORMAT_UNKNOWN},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        sy_file_format got = of(cases[i].bytes);
        EXPECT_MSG(got == cases[i].want, "case %zu: %s, expected %s", i, sy_file_format_name(got), sy_file_format_name(cases[i].want));
    }
    EXPECT_MSG(!strcmp(sy_file_format_name(SY_FORMAT_OBJ), "Wavefront OBJ"), "OBJ's name");
    EXPECT_MSG(sy_file_format_is_texture_image(SY_FORMAT_PNG, false) && sy_file_format_is_texture_image(SY_FORMAT_JPEG, false) &&
                   !sy_file_format_is_texture_image(SY_FORMAT_GIF, false) && sy_file_format_is_texture_image(SY_FORMAT_GIF, true) &&
                   !sy_file_format_is_texture_image(SY_FORMAT_RADIANCE, true) && !sy_file_format_is_texture_image(SY_FORMAT_UNKNOWN, true) &&
                   !sy_file_format_is_texture_image(SY_FORMAT_WEBP, true),
               "texture image formats: PNG, JPEG (and GIF for X3D), nothing else (WebP: only glTF's EXT_texture_webp)");
    EXPECT_MSG(sy_file_format_is_scene(SY_FORMAT_GLB) && sy_file_format_is_scene(SY_FORMAT_OBJ) &&
                   !sy_file_format_is_scene(SY_FORMAT_VRML) && !sy_file_format_is_scene(SY_FORMAT_PNG),
               "scene formats");
    EXPECT_MSG(sy_file_format_is_assimp(SY_FORMAT_STL) && sy_file_format_is_assimp(SY_FORMAT_GLTF1) &&
                   !sy_file_format_is_assimp(SY_FORMAT_GLTF) && !sy_file_format_is_assimp(SY_FORMAT_X3D),
               "Assimp formats");
    /* binary STL by its size rule: 80-byte header (here starting with "solid", as some exporters
     * write), facet count 2, 100 bytes of facets; one byte more or less is not STL */
    unsigned char stl[184] = "solid but binary";
    stl[80] = 2;
    EXPECT_MSG(sy_sniff_bytes(stl, sizeof stl) == SY_FORMAT_STL, "binary STL: %s", sy_file_format_name(sy_sniff_bytes(stl, sizeof stl)));
    EXPECT_MSG(sy_sniff_bytes(stl, sizeof stl - 1) == SY_FORMAT_UNKNOWN, "binary STL one byte short");
    EXPECT_MSG(sy_sniff_bytes_sized(stl, 100, sizeof stl) == SY_FORMAT_STL, "binary STL from its first bytes and size");
    static const unsigned char glb1[12] = {'g', 'l', 'T', 'F', 1, 0, 0, 0, 12, 0, 0, 0};
    EXPECT_MSG(sy_sniff_bytes(glb1, sizeof glb1) == SY_FORMAT_GLTF1, "binary glTF 1");
    /* 3DS: main chunk 0x4D4D, its length within the file, then the version chunk 0x0002 */
    unsigned char tds[32] = {0x4d, 0x4d, 32, 0, 0, 0, 0x02, 0x00, 10, 0, 0, 0, 3, 0, 0, 0};
    EXPECT_MSG(sy_sniff_bytes(tds, sizeof tds) == SY_FORMAT_3DS, "3DS");
    tds[2] = 33; /* longer than the file */
    EXPECT_MSG(sy_sniff_bytes(tds, sizeof tds) == SY_FORMAT_UNKNOWN, "3DS chunk past the file");

    char dir[4096], p[4200];
    make_scratch_dir(dir, sizeof dir, "sniff");
    snprintf(p, sizeof p, "%s/model.gltf", dir); /* an OBJ under a glTF name */
    const char obj[] = "v 0 0 0\nf 1 1 1\n";
    EXPECT_MSG(write_bytes(p, obj, sizeof obj - 1) == 0, "cannot write %s", p);
    sy_file_format got = SY_FORMAT_UNKNOWN;
    sy_error e = {0};
    EXPECT_MSG(sy_sniff_file(p, &got, &e) == SY_OK && got == SY_FORMAT_OBJ, "model.gltf holding OBJ: %s", sy_file_format_name(got));
    snprintf(p, sizeof p, "%s/missing.glb", dir);
    EXPECT_MSG(sy_sniff_file(p, &got, &e) == SY_ERR_NOT_FOUND && strstr(e.message, "missing.glb"), "missing: %s", e.message);
    EXPECT_MSG(sy_sniff_file(dir, &got, &e) != SY_OK && strstr(e.message, "folder"), "a folder: %s", e.message);
    remove_scratch_dir(dir);
    return sy_check_finish("test_sniff");
}
