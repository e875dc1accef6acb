// sy_gltf_shim_write.cpp — the writer half of the glTF shim: builds a tinygltf model from the plain
// description of sy_gltf_shim.h (>>writing) and serialises it with tinygltf's GLB writer. Every entry
// point catches every exception; nothing C++ leaks through the C interface.
#include "sy_gltf_shim.h"

#include <tiny_gltf.h>

#include <climits>
#include <cstdlib>
#include <cstring>
#include <new>
#include <sstream>
#include <string>
#include <vector>

// >>GLB writing: a tinygltf model built from the plain description, serialised by tinygltf.
namespace {

// Appends n bytes to the one buffer (4-byte aligned) and adds a bufferView; returns its index.
int add_view(tinygltf::Model &m, const void *data, size_t n, int target)
{
    std::vector<unsigned char> &b = m.buffers[0].data;
    while (b.size() % 4) b.push_back(0);
    tinygltf::BufferView v;
    v.buffer = 0;
    v.byteOffset = b.size();
    v.byteLength = n;
    v.target = target;
    const unsigned char *p = static_cast<const unsigned char *>(data);
    b.insert(b.end(), p, p + n);
    m.bufferViews.push_back(v);
    return int(m.bufferViews.size() - 1);
}

int add_accessor(tinygltf::Model &m, const void *data, size_t count, int type, int components, int ctype, int target,
                 bool minmax)
{
    size_t elem = ctype == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ? 2 : 4; // float, uint32 or uint16
    tinygltf::Accessor a;
    a.bufferView = add_view(m, data, count * elem * size_t(components), target);
    a.byteOffset = 0;
    a.componentType = ctype;
    a.count = count;
    a.type = type;
    if (minmax && count) {
        const float *f = static_cast<const float *>(data);
        a.minValues.assign(f, f + components);
        a.maxValues.assign(f, f + components);
        for (size_t i = 1; i < count; ++i)
            for (int c = 0; c < components; ++c) {
                double v = f[i * size_t(components) + size_t(c)];
                if (v < a.minValues[size_t(c)]) a.minValues[size_t(c)] = v;
                if (v > a.maxValues[size_t(c)]) a.maxValues[size_t(c)] = v;
            }
    }
    m.accessors.push_back(a);
    return int(m.accessors.size() - 1);
}

std::string str_or_empty(const char *s) { return s ? std::string(s) : std::string(); }

void build_model(const sy_gltf_shim_wdoc *d, tinygltf::Model &m)
{
    m.asset.version = "2.0";
    m.asset.generator = str_or_empty(d->generator);
    m.buffers.resize(1);
    bool emissive_strength = false, unlit = false;
    for (uint32_t i = 0; i < d->material_count; ++i) {
        const sy_gltf_shim_wmaterial &w = d->materials[i];
        tinygltf::Material mt;
        mt.name = str_or_empty(w.name);
        mt.pbrMetallicRoughness.baseColorFactor.assign(w.base_color, w.base_color + 4);
        mt.pbrMetallicRoughness.metallicFactor = w.metallic;
        mt.pbrMetallicRoughness.roughnessFactor = w.roughness;
        mt.emissiveFactor.assign(w.emissive, w.emissive + 3);
        mt.alphaMode = w.alpha_mode ? w.alpha_mode : "OPAQUE";
        mt.alphaCutoff = w.alpha_cutoff;
        mt.doubleSided = w.double_sided != 0;
        if (w.emissive_strength != 1.0) {
            tinygltf::Value::Object o;
            o["emissiveStrength"] = tinygltf::Value(w.emissive_strength);
            mt.extensions["KHR_materials_emissive_strength"] = tinygltf::Value(o);
            emissive_strength = true;
        }
        if (w.unlit) {
            mt.extensions["KHR_materials_unlit"] = tinygltf::Value(tinygltf::Value::Object());
            unlit = true;
        }
        m.materials.push_back(mt);
    }
    if (emissive_strength) m.extensionsUsed.push_back("KHR_materials_emissive_strength");
    if (unlit) m.extensionsUsed.push_back("KHR_materials_unlit");
    for (uint32_t i = 0; i < d->mesh_count; ++i) {
        const sy_gltf_shim_wmesh &w = d->meshes[i];
        tinygltf::Mesh mesh;
        mesh.name = str_or_empty(w.name);
        for (uint32_t k = 0; k < w.primitive_count; ++k) {
            const sy_gltf_shim_wprimitive &p = w.primitives[k];
            tinygltf::Primitive pr;
            pr.mode = p.mode;
            pr.material = p.material;
            const int vt = TINYGLTF_TARGET_ARRAY_BUFFER;
            pr.attributes["POSITION"] = add_accessor(m, p.positions, p.vertex_count, TINYGLTF_TYPE_VEC3, 3,
                                                     TINYGLTF_COMPONENT_TYPE_FLOAT, vt, true);
            if (p.normals)
                pr.attributes["NORMAL"] = add_accessor(m, p.normals, p.vertex_count, TINYGLTF_TYPE_VEC3, 3,
                                                       TINYGLTF_COMPONENT_TYPE_FLOAT, vt, false);
            if (p.texcoords0)
                pr.attributes["TEXCOORD_0"] = add_accessor(m, p.texcoords0, p.vertex_count, TINYGLTF_TYPE_VEC2, 2,
                                                           TINYGLTF_COMPONENT_TYPE_FLOAT, vt, false);
            if (p.colors)
                pr.attributes["COLOR_0"] = add_accessor(m, p.colors, p.vertex_count, TINYGLTF_TYPE_VEC4, 4,
                                                        TINYGLTF_COMPONENT_TYPE_FLOAT, vt, false);
            if (p.indices && p.vertex_count <= 65536) { // 16-bit indices where they reach every vertex
                std::vector<uint16_t> small(p.indices, p.indices + p.index_count);
                pr.indices = add_accessor(m, small.data(), small.size(), TINYGLTF_TYPE_SCALAR, 1,
                                          TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER, false);
            } else if (p.indices) {
                pr.indices = add_accessor(m, p.indices, p.index_count, TINYGLTF_TYPE_SCALAR, 1,
                                          TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER, false);
            }
            mesh.primitives.push_back(pr);
        }
        m.meshes.push_back(mesh);
    }
    tinygltf::Scene scene;
    for (uint32_t i = 0; i < d->node_count; ++i) {
        const sy_gltf_shim_wnode &w = d->nodes[i];
        tinygltf::Node n;
        n.name = str_or_empty(w.name);
        n.mesh = w.mesh;
        static const double identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
        if (memcmp(w.matrix, identity, sizeof identity) != 0) n.matrix.assign(w.matrix, w.matrix + 16);
        if (w.id >= 0) {
            tinygltf::Value::Object o;
            o["id"] = tinygltf::Value(double(w.id));
            n.extras = tinygltf::Value(o);
        }
        m.nodes.push_back(n);
        scene.nodes.push_back(int(i));
    }
    m.scenes.push_back(scene);
    m.defaultScene = 0;
}

} // namespace

extern "C" sy_result sy_gltf_shim_write_glb(const sy_gltf_shim_wdoc *doc, uint8_t **glb_out, size_t *len_out, sy_error *err)
{
    *glb_out = nullptr;
    *len_out = 0;
    if (!doc) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "write GLB: no document");
    try {
        tinygltf::Model model;
        build_model(doc, model);
        // 12 header + 8 JSON chunk header + JSON + 8 BIN chunk header + BIN + padding: refuse what
        // the 32-bit length field cannot hold before tinygltf writes a wrapped length.
        if (model.buffers[0].data.size() > size_t(UINT32_MAX) - (size_t(64) << 20))
            return sy_error_set(err, SY_ERR_LIMIT, "write GLB: %zu bytes of buffers exceed the GLB limit of 4 GiB",
                                model.buffers[0].data.size());
        if (model.buffers[0].data.empty()) model.buffers.clear();
        std::ostringstream os(std::ios::binary);
        tinygltf::TinyGLTF writer;
        if (!writer.WriteGltfSceneToStream(&model, os, false, true) || !os)
            return sy_error_set(err, SY_ERR_IO, "write GLB: tinygltf could not serialise the model");
        const std::string bytes = os.str();
        if (bytes.size() > size_t(UINT32_MAX))
            return sy_error_set(err, SY_ERR_LIMIT, "write GLB: %zu bytes exceed the GLB limit of 4 GiB", bytes.size());
        uint8_t *out = static_cast<uint8_t *>(malloc(bytes.size()));
        if (!out) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "write GLB: out of memory for %zu bytes", bytes.size());
        memcpy(out, bytes.data(), bytes.size());
        *glb_out = out;
        *len_out = bytes.size();
        return SY_OK;
    } catch (const std::bad_alloc &) {
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "write GLB: out of memory");
    } catch (const std::exception &e) {
        return sy_error_set(err, SY_ERR_IO, "write GLB: %s", e.what());
    } catch (...) {
        return sy_error_set(err, SY_ERR_IO, "write GLB: unknown exception");
    }
}
