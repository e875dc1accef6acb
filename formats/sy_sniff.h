/** @file
 * sy_sniff.h — what a file is, from its first bytes rather than its name: the scene formats
 * Switchyard reads (glTF 2.0 JSON and GLB, X3D XML by their own loaders; Wavefront OBJ, PLY, STL
 * (ASCII, and binary by its size rule), FBX (binary and ASCII), COLLADA, 3MF, 3DS and glTF 1.0
 * through Assimp, sy_assimp.h) and the ones it does not read as scenes (VRML / X3D classic
 * encoding, images), so that a file is read by the right loader whatever its name, and a wrong
 * file is named for what it is.
 * Ownership: plain values. Thread-safety: pure, apart from reading the file. */
#ifndef SY_SNIFF_H
#define SY_SNIFF_H

#include "sy_common.h"

#ifdef __cplusplus
extern "C" {
#endif

/** What a file is, by its content. */
typedef enum sy_file_format {
    SY_FORMAT_UNKNOWN = 0,
    SY_FORMAT_GLTF,   /**< glTF JSON (.gltf) */
    SY_FORMAT_GLB,    /**< binary glTF (.glb) */
    SY_FORMAT_X3D,    /**< X3D, XML encoding */
    SY_FORMAT_OBJ,    /**< Wavefront OBJ */
    SY_FORMAT_PLY,
    SY_FORMAT_STL,    /**< ASCII STL, or binary STL by its size (84 + 50 x the facet count at byte 80) */
    SY_FORMAT_FBX,    /**< binary ("Kaydara FBX Binary") or ASCII ("; FBX" comment) FBX */
    SY_FORMAT_COLLADA,
    SY_FORMAT_VRML,   /**< VRML 97 / X3D classic (VRML) encoding */
    SY_FORMAT_EXR,
    SY_FORMAT_PNG,
    SY_FORMAT_JPEG,
    SY_FORMAT_GIF,
    SY_FORMAT_RADIANCE, /**< Radiance RGBE (.hdr) */
    SY_FORMAT_3MF,    /**< 3D Manufacturing Format (a zip holding 3D/3dmodel.model) */
    SY_FORMAT_3DS,    /**< Autodesk 3DS (main chunk 0x4D4D whose length fits the file) */
    SY_FORMAT_GLTF1,  /**< glTF 1.0 JSON ("version": "1.0" in its asset), or binary glTF 1 */
    SY_FORMAT_WEBP,   /**< WebP image ("RIFF" size "WEBP"); decoded only for glTF's EXT_texture_webp */
} sy_file_format;

/** Classifies the first n bytes of a file (a few hundred are enough; the whole file for the
 * binary STL size rule). */
sy_file_format sy_sniff_bytes(const void *data, size_t n);
/** The same for the first n bytes of a file of file_size bytes. */
sy_file_format sy_sniff_bytes_sized(const void *data, size_t n, uint64_t file_size);
/** Reads the first bytes of path and classifies them; errors (a missing file, a directory) name it. */
sy_result sy_sniff_file(const char *path, sy_file_format *out, sy_error *err);
/** "glTF", "Wavefront OBJ", ... ("unknown" for SY_FORMAT_UNKNOWN). */
const char *sy_file_format_name(sy_file_format f);
/** True for the image formats a model's textures may use: PNG and JPEG (glTF 2.0's two), and GIF
 * where with_gif (X3D's ImageTexture). The loaders decode nothing else: stb_image would also take
 * Radiance, PSD, TGA and more, formats no model should carry, and Debian's stb_image loops for ever on
 * a truncated Radiance file. */
bool sy_file_format_is_texture_image(sy_file_format f, bool with_gif);

/** True for the formats read through Assimp (sy_assimp.h). */
bool sy_file_format_is_assimp(sy_file_format f);
/** True for the scene formats the loaders read (glTF 2.0, GLB and X3D by their own loaders; OBJ, PLY,
 * STL, FBX, COLLADA, 3MF, 3DS and glTF 1.0 through Assimp). */
bool sy_file_format_is_scene(sy_file_format f);

#ifdef __cplusplus
}
#endif
#endif /* SY_SNIFF_H */
