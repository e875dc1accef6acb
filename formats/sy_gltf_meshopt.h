/* sy_gltf_meshopt.h — decoding one EXT_meshopt_compression bufferView with meshoptimizer's decoders
 * (meshopt_decodeVertexBuffer / IndexBuffer / IndexSequence and the Oct / Quat / Exp filters), for
 * the glTF shim (sy_gltf_shim.cpp). Internal to the glTF loader.
 *
 * Every parameter comes from the file and is checked here before meshoptimizer sees it (its own
 * checks are assertions): the mode's and filter's byteStride rules of the extension, count * stride
 * equal to the caller's output size. A stream that does not decode is SY_ERR_PARSE with a message
 * without the file name (the caller prefixes file and bufferView). No allocation; thread-safe. */
#ifndef SY_GLTF_MESHOPT_H
#define SY_GLTF_MESHOPT_H

#include "sy_common.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum sy_gltf_meshopt_mode { SY_MESHOPT_ATTRIBUTES, SY_MESHOPT_TRIANGLES, SY_MESHOPT_INDICES } sy_gltf_meshopt_mode;
typedef enum sy_gltf_meshopt_filter {
    SY_MESHOPT_NONE,
    SY_MESHOPT_OCTAHEDRAL,
    SY_MESHOPT_QUATERNION,
    SY_MESHOPT_EXPONENTIAL
} sy_gltf_meshopt_filter;

/* Decodes src (len bytes) into dst (count * stride bytes, dst_size must equal it). */
sy_result sy_gltf_meshopt_decode(const uint8_t *src, size_t len, size_t count, size_t stride, sy_gltf_meshopt_mode mode,
                                 sy_gltf_meshopt_filter filter, uint8_t *dst, size_t dst_size, sy_error *err);

#ifdef __cplusplus
}
#endif
#endif /* SY_GLTF_MESHOPT_H */
