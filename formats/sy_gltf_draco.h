/* sy_gltf_draco.h — decoding one KHR_draco_mesh_compression primitive with Debian's libdraco
 * (draco::Decoder), for the glTF shim (sy_gltf_shim.cpp). Internal to the glTF loader.
 *
 * The caller sizes every output from the counts the glTF accessors declare (and charges them to
 * its budget) before calling; the decoder checks Draco's own counts against them before it copies
 * anything: a stream that decodes to other counts, to fewer components, to indices or attribute
 * values out of range, or that does not decode, is an error (SY_ERR_PARSE, message without the file
 * name: the caller prefixes the file and the primitive). Exceptions never cross this interface.
 * Thread-safety: no shared state. Ownership: every pointer is the caller's. */
#ifndef SY_GLTF_DRACO_H
#define SY_GLTF_DRACO_H

#include "sy_common.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct sy_gltf_draco_attr {
    const char *name;   /* glTF attribute name, for messages */
    int32_t unique_id;  /* the extension's attributes[name] */
    uint32_t components; /* 1..4: floats per vertex written to out */
    float *out;         /* vertex_count * components floats */
} sy_gltf_draco_attr;

typedef struct sy_gltf_draco_request {
    size_t vertex_count;    /* the glTF attribute accessors' count (all equal) */
    size_t index_count;     /* the glTF indices accessor's count (3 per triangle) */
    uint32_t *indices;      /* index_count values */
    sy_gltf_draco_attr *attrs;
    size_t attr_count;
} sy_gltf_draco_request;

/* Decodes size bytes of Draco mesh data into req's outputs (see above). */
sy_result sy_gltf_draco_decode(const uint8_t *data, size_t size, const sy_gltf_draco_request *req, sy_error *err);

#ifdef __cplusplus
}
#endif
#endif /* SY_GLTF_DRACO_H */
