/* sy_sniff.c — file formats from their first bytes (see sy_sniff.h). */
#include "sy_sniff.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#define SNIFF_BYTES 1024

static bool starts(const unsigned char *p, size_t n, const char *sig)
{
    size_t k = strlen(sig);
    return n >= k && memcmp(p, sig, k) == 0;
}

/* Whether the text contains needle within its first n bytes (case-sensitive). */
static bool contains(const unsigned char *p, size_t n, const char *needle)
{
    size_t k = strlen(needle);
    for (size_t i = 0; i + k <= n; ++i)
        if (memcmp(p + i, needle, k) == 0) return true;
    return false;
}

/* A Wavefront OBJ: its first statement (after comments and blank lines) is one of OBJ's keywords. */
static bool looks_obj(const unsigned char *p, size_t n)
{
    static const char *const kw[] = {"v", "vt", "vn", "vp", "f", "o", "g", "s", "l", "p", "mtllib", "usemtl"};
    size_t i = 0;
    while (i < n) {
        while (i < n && (p[i] == ' ' || p[i] == '\t' || p[i] == '\r' || p[i] == '\n')) i++;
        if (i < n && p[i] == '#') { /* a comment line */
            while (i < n && p[i] != '\n') i++;
            continue;
        }
        size_t s = i;
        while (i < n && p[i] > ' ') i++;
        if (i >= n || (p[i] != ' ' && p[i] != '\t')) return false; /* a keyword is followed by its arguments */
        for (size_t k = 0; k < sizeof kw / sizeof kw[0]; ++k)
            if (strlen(kw[k]) == i - s && memcmp(p + s, kw[k], i - s) == 0) return true;
        return false;
    }
    return false;
}

static uint32_t le32(const unsigned char *p) { return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24; }

/* glTF JSON of version 1: the first of its top-level collections ("accessors", "meshes", ...) is an
 * object keyed by id (glTF 2.0: an array), or the asset's "version" is "1.x". */
static bool gltf1_json(const unsigned char *p, size_t n)
{
    static const char *const keys[] = {"\"accessors\"", "\"bufferViews\"", "\"buffers\"", "\"meshes\"",
                                       "\"nodes\"",     "\"materials\"",   "\"scenes\"",  "\"version\""};
    for (size_t i = 0; i < n; ++i) {
        if (p[i] != '"') continue;
        for (size_t k = 0; k < sizeof keys / sizeof keys[0]; ++k) {
            size_t kl = strlen(keys[k]);
            if (i + kl > n || memcmp(p + i, keys[k], kl) != 0) continue;
            size_t j = i + kl;
            while (j < n && (p[j] == ' ' || p[j] == '\t' || p[j] == '\r' || p[j] == '\n' || p[j] == ':')) j++;
            if (j + 1 >= n) return false;
            if (k == sizeof keys / sizeof keys[0] - 1) return p[j] == '"' && p[j + 1] == '1';
            return p[j] == '{';
        }
    }
    return false;
}

sy_file_format sy_sniff_bytes(const void *data, size_t n) { return sy_sniff_bytes_sized(data, n, n); }

sy_file_format sy_sniff_bytes_sized(const void *data, size_t n, uint64_t file_size)
{
    const unsigned char *p = data;
    if (starts(p, n, "glTF")) return n >= 8 && le32(p + 4) == 1 ? SY_FORMAT_GLTF1 : SY_FORMAT_GLB;
    if (n >= 4 && p[0] == 0x76 && p[1] == 0x2f && p[2] == 0x31 && p[3] == 0x01) return SY_FORMAT_EXR;
    if (starts(p, n, "\x89PNG\r\n\x1a\n")) return SY_FORMAT_PNG;
    if (n >= 3 && p[0] == 0xff && p[1] == 0xd8 && p[2] == 0xff) return SY_FORMAT_JPEG;
    if (starts(p, n, "GIF87a") || starts(p, n, "GIF89a")) return SY_FORMAT_GIF;
    if (n >= 12 && starts(p, n, "RIFF") && !memcmp(p + 8, "WEBP", 4)) return SY_FORMAT_WEBP;
    if (starts(p, n, "#?RADIANCE") || starts(p, n, "#?RGBE")) return SY_FORMAT_RADIANCE;
    if (starts(p, n, "Kaydara FBX Binary")) return SY_FORMAT_FBX;
    if (starts(p, n, "ply\n") || starts(p, n, "ply\r")) return SY_FORMAT_PLY;
    /* 3MF: a zip whose parts include the 3D model (its name in a local header within the first bytes) */
    if (starts(p, n, "PK\x03\x04") && contains(p, n, "3D/"))
        return SY_FORMAT_3MF;
    /* 3DS: the main chunk 0x4D4D, its length at least a header and at most the file */
    if (n >= 16 && p[0] == 0x4d && p[1] == 0x4d && le32(p + 2) >= 16 && le32(p + 2) <= file_size &&
        ((p[6] == 0x02 && p[7] == 0x00) || (p[6] == 0x3d && p[7] == 0x3d)))
        return SY_FORMAT_3DS;
    /* binary STL: an 80-byte header, the facet count, 50 bytes per facet, nothing else (the header
     * may start with "solid" too) */
    if (file_size >= 134 && n >= 84 && (uint64_t)le32(p + 80) * 50u + 84u == file_size) return SY_FORMAT_STL;
    size_t i = 0;
    if (starts(p, n, "\xef\xbb\xbf")) i = 3; /* UTF-8 byte order mark */
    while (i < n && (p[i] == ' ' || p[i] == '\t' || p[i] == '\r' || p[i] == '\n')) i++;
    const unsigned char *t = p + i;
    size_t m = n - i;
    if (m && t[0] == '{') return gltf1_json(t, m) ? SY_FORMAT_GLTF1 : SY_FORMAT_GLTF;
    if (starts(t, m, "; FBX")) return SY_FORMAT_FBX;
    if (starts(t, m, "#VRML") || starts(t, m, "#X3D")) return SY_FORMAT_VRML;
    if (m && t[0] == '<') {
        if (contains(t, m, "<X3D") || contains(t, m, "X3D PUBLIC") || contains(t, m, "x3d-3.") || contains(t, m, "x3d-4."))
            return SY_FORMAT_X3D;
        if (contains(t, m, "<COLLADA")) return SY_FORMAT_COLLADA;
        return SY_FORMAT_UNKNOWN;
    }
    if (starts(t, m, "solid") && (contains(t, m, "facet normal") || contains(t, m, "endsolid"))) return SY_FORMAT_STL;
    if (looks_obj(t, m)) return SY_FORMAT_OBJ;
    return SY_FORMAT_UNKNOWN;
}

sy_result sy_sniff_file(const char *path, sy_file_format *out, sy_error *err)
{
    *out = SY_FORMAT_UNKNOWN;
    struct stat st;
    if (stat(path, &st) != 0)
        return sy_error_set(err, errno == ENOENT ? SY_ERR_NOT_FOUND : SY_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    if (S_ISDIR(st.st_mode)) return sy_error_set(err, SY_ERR_IO, "%s: is a folder, not a scene file", path);
    FILE *f = fopen(path, "rb");
    if (!f) return sy_error_set(err, SY_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    unsigned char buf[SNIFF_BYTES];
    size_t n = fread(buf, 1, sizeof buf, f);
    fclose(f);
    *out = sy_sniff_bytes_sized(buf, n, (uint64_t)st.st_size);
    return SY_OK;
}

const char *sy_file_format_name(sy_file_format f)
{
    switch (f) {
    case SY_FORMAT_GLTF: return "glTF";
    case SY_FORMAT_GLB: return "binary glTF (GLB)";
    case SY_FORMAT_X3D: return "X3D";
    case SY_FORMAT_OBJ: return "Wavefront OBJ";
    case SY_FORMAT_PLY: return "PLY";
    case SY_FORMAT_STL: return "STL";
    case SY_FORMAT_FBX: return "FBX";
    case SY_FORMAT_COLLADA: return "COLLADA";
    case SY_FORMAT_VRML: return "VRML / X3D classic encoding";
    case SY_FORMAT_EXR: return "OpenEXR image";
    case SY_FORMAT_PNG: return "PNG image";
    case SY_FORMAT_JPEG: return "JPEG image";
    case SY_FORMAT_GIF: return "GIF image";
    case SY_FORMAT_WEBP: return "WebP image";
    case SY_FORMAT_RADIANCE: return "Radiance HDR image";
    case SY_FORMAT_3MF: return "3MF";
    case SY_FORMAT_3DS: return "3DS";
    case SY_FORMAT_GLTF1: return "glTF 1.0";
    default: return "unknown";
    }
}

bool sy_file_format_is_texture_image(sy_file_format f, bool with_gif)
{
    return f == SY_FORMAT_PNG || f == SY_FORMAT_JPEG || (with_gif && f == SY_FORMAT_GIF);
}

bool sy_file_format_is_assimp(sy_file_format f)
{
    return f == SY_FORMAT_OBJ || f == SY_FORMAT_PLY || f == SY_FORMAT_STL || f == SY_FORMAT_FBX ||
           f == SY_FORMAT_COLLADA || f == SY_FORMAT_3MF || f == SY_FORMAT_3DS || f == SY_FORMAT_GLTF1;
}

bool sy_file_format_is_scene(sy_file_format f)
{
    return f == SY_FORMAT_GLTF || f == SY_FORMAT_GLB || f == SY_FORMAT_X3D || sy_file_format_is_assimp(f);
}
