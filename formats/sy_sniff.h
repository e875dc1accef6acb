/** @file
 * sy_sniff.h — what a file is, from its first bytes rather than its name: the formats Switchyard
 * reads (glTF JSON, GLB, X3D XML) and the common ones it does not (Wavefront OBJ, PLY, STL, FBX,
 * COLLADA, VRML / X3D classic encoding, images), so that a wrong file is named for what it is
 * instead of failing as a broken glTF.
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
    SY_FORMAT_STL,    /**< ASCII STL (binary STL has no signature) */
    SY_FORMAT_FBX,    /**< binary FBX */
    SY_FORMAT_COLLADA,
    SY_FORMAT_VRML,   /**< VRML 97 / X3D classic (VRML) encoding */
    SY_FORMAT_EXR,
    SY_FORMAT_PNG,
    SY_FORMAT_JPEG,
    SY_FORMAT_GIF,
    SY_FORMAT_RADIANCE, /**< Radiance RGBE (.hdr) */
} sy_file_format;

/** Classifies the first n bytes of a file (a few hundred are enough). */
sy_file_format sy_sniff_bytes(const void *data, size_t n);
/** Reads the first bytes of path and classifies them; errors (a missing file, a directory) name it. */
sy_result sy_sniff_file(const char *path, sy_file_format *out, sy_error *err);
/** "glTF", "Wavefront OBJ", ... ("unknown" for SY_FORMAT_UNKNOWN). */
const char *sy_file_format_name(sy_file_format f);
/** True for the image formats a model's textures may use: PNG and JPEG (glTF 2.0's two), and GIF
 * where with_gif (X3D's ImageTexture). The loaders decode nothing else: stb_image would also take
 * Radiance, PSD, TGA and more, formats no model should carry, and Debian's stb_image loops for ever on
 * a truncated Radiance file. */
bool sy_file_format_is_texture_image(sy_file_format f, bool with_gif);

/** True for the scene formats the loaders read (glTF, GLB, X3D). */
bool sy_file_format_is_scene(sy_file_format f);

#ifdef __cplusplus
}
#endif
#endif /* SY_SNIFF_H */
