/* sy_gltf_meshopt.c — one EXT_meshopt_compression bufferView decoded with meshoptimizer
 * (sy_gltf_meshopt.h): the extension's stride / count / filter rules checked first. */
#include "sy_gltf_meshopt.h"

#include <meshoptimizer.h>

sy_result sy_gltf_meshopt_decode(const uint8_t *src, size_t len, size_t count, size_t stride, sy_gltf_meshopt_mode mode,
                                 sy_gltf_meshopt_filter filter, uint8_t *dst, size_t dst_size, sy_error *err)
{
    if (!src || !dst) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "sy_gltf_meshopt_decode: invalid argument");
    if (count == 0 || stride == 0 || count > dst_size / stride || count * stride != dst_size)
        return sy_error_set(err, SY_ERR_PARSE, "count %zu * byteStride %zu is not the bufferView's byteLength %zu", count,
                            stride, dst_size);
    int rc;
    switch (mode) {
    case SY_MESHOPT_ATTRIBUTES:
        if (stride % 4 != 0 || stride > 256)
            return sy_error_set(err, SY_ERR_PARSE, "ATTRIBUTES byteStride %zu is not a multiple of 4 up to 256", stride);
        if ((filter == SY_MESHOPT_OCTAHEDRAL && stride != 4 && stride != 8) || (filter == SY_MESHOPT_QUATERNION && stride != 8))
            return sy_error_set(err, SY_ERR_PARSE, "byteStride %zu does not suit the %s filter", stride,
                                filter == SY_MESHOPT_OCTAHEDRAL ? "OCTAHEDRAL" : "QUATERNION");
        rc = meshopt_decodeVertexBuffer(dst, count, stride, src, len);
        break;
    case SY_MESHOPT_TRIANGLES:
    case SY_MESHOPT_INDICES:
        if (stride != 2 && stride != 4)
            return sy_error_set(err, SY_ERR_PARSE, "%s byteStride %zu is not 2 or 4",
                                mode == SY_MESHOPT_TRIANGLES ? "TRIANGLES" : "INDICES", stride);
        if (filter != SY_MESHOPT_NONE) return sy_error_set(err, SY_ERR_PARSE, "a filter on index data");
        if (mode == SY_MESHOPT_TRIANGLES && count % 3 != 0)
            return sy_error_set(err, SY_ERR_PARSE, "TRIANGLES count %zu is not a multiple of 3", count);
        rc = mode == SY_MESHOPT_TRIANGLES ? meshopt_decodeIndexBuffer(dst, count, stride, src, len)
                                          : meshopt_decodeIndexSequence(dst, count, stride, src, len);
        break;
    default:
        return sy_error_set(err, SY_ERR_PARSE, "unknown mode");
    }
    if (rc != 0)
        return sy_error_set(err, SY_ERR_PARSE, "the compressed data (%zu bytes) does not decode to %zu x %zu bytes (meshoptimizer: %d)",
                            len, count, stride, rc);
    switch (filter) {
    case SY_MESHOPT_OCTAHEDRAL: meshopt_decodeFilterOct(dst, count, stride); break;
    case SY_MESHOPT_QUATERNION: meshopt_decodeFilterQuat(dst, count, stride); break;
    case SY_MESHOPT_EXPONENTIAL: meshopt_decodeFilterExp(dst, count, stride); break;
    default: break;
    }
    return SY_OK;
}
