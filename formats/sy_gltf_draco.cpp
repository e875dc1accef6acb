// sy_gltf_draco.cpp — one KHR_draco_mesh_compression primitive decoded with draco::Decoder into the
// caller's arrays (sy_gltf_draco.h): Draco's counts checked against the glTF's before any copy.
#include "sy_gltf_draco.h"

#include "sy_cpp_error.h"

#include <draco/compression/decode.h>
#include <draco/mesh/mesh.h>

#include <memory>
#include <new>
#include <string>

namespace {

sy_result decode(const uint8_t *data, size_t size, const sy_gltf_draco_request *req, sy_error *err)
{
    draco::DecoderBuffer buf;
    buf.Init(reinterpret_cast<const char *>(data), size);
    auto type = draco::Decoder::GetEncodedGeometryType(&buf);
    if (!type.ok() || type.value() != draco::TRIANGULAR_MESH)
        return sy_error_set(err, SY_ERR_PARSE, "not a Draco triangle mesh (%s)",
                            type.ok() ? "a point cloud" : type.status().error_msg());
    draco::Decoder decoder;
    auto res = decoder.DecodeMeshFromBuffer(&buf);
    if (!res.ok()) return sy_error_set(err, SY_ERR_PARSE, "Draco data does not decode (%s)", res.status().error_msg());
    const std::unique_ptr<draco::Mesh> &mesh = res.value();
    if (!mesh) return sy_error_set(err, SY_ERR_PARSE, "Draco data does not decode (no mesh)");
    const size_t points = mesh->num_points(), faces = mesh->num_faces();
    if (points != req->vertex_count)
        return sy_error_set(err, SY_ERR_PARSE, "Draco data has %zu vertices, the accessors declare %zu", points,
                            req->vertex_count);
    if (faces > SIZE_MAX / 3 || faces * 3 != req->index_count)
        return sy_error_set(err, SY_ERR_PARSE, "Draco data has %zu triangles, the indices accessor declares %zu indices",
                            faces, req->index_count);
    for (size_t i = 0; i < req->attr_count; i++) {
        const sy_gltf_draco_attr &a = req->attrs[i];
        const draco::PointAttribute *pa = a.unique_id >= 0 ? mesh->GetAttributeByUniqueId(uint32_t(a.unique_id)) : nullptr;
        if (!pa) return sy_error_set(err, SY_ERR_PARSE, "attribute %s: Draco data has no attribute %d", a.name, (int)a.unique_id);
        if (pa->num_components() != a.components)
            return sy_error_set(err, SY_ERR_PARSE, "attribute %s: Draco data has %d components, the accessor %u", a.name,
                                (int)pa->num_components(), (unsigned)a.components);
        if (!pa->is_mapping_identity() && pa->indices_map_size() < points)
            return sy_error_set(err, SY_ERR_PARSE, "attribute %s: Draco point map has %zu entries for %zu vertices", a.name,
                                pa->indices_map_size(), points);
        const size_t values = pa->size();
        for (size_t p = 0; p < points; p++) {
            draco::AttributeValueIndex v = pa->mapped_index(draco::PointIndex(uint32_t(p)));
            if (v.value() >= values || !pa->ConvertValue<float>(v, int8_t(a.components), a.out + p * a.components))
                return sy_error_set(err, SY_ERR_PARSE, "attribute %s: vertex %zu has no value in the Draco data", a.name, p);
        }
    }
    for (size_t f = 0; f < faces; f++) {
        const draco::Mesh::Face &face = mesh->face(draco::FaceIndex(uint32_t(f)));
        for (size_t k = 0; k < 3; k++) {
            uint32_t v = face[k].value();
            if (v >= points)
                return sy_error_set(err, SY_ERR_PARSE, "Draco triangle %zu: vertex %u >= %zu vertices", f, (unsigned)v, points);
            req->indices[f * 3 + k] = v;
        }
    }
    return SY_OK;
}

} // namespace

extern "C" sy_result sy_gltf_draco_decode(const uint8_t *data, size_t size, const sy_gltf_draco_request *req, sy_error *err)
{
    if (!data || !req || (req->index_count && !req->indices) || (req->attr_count && !req->attrs))
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "sy_gltf_draco_decode: invalid argument");
    try {
        return decode(data, size, req, err);
    } catch (...) {
        return sy_error_from_exception(err, SY_ERR_PARSE, "out of memory while decoding Draco data", "Draco: ",
                                       "Draco: unknown exception");
    }
}
