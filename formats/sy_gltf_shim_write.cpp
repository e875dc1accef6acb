// sy_gltf_shim_write.cpp — the writer half of the glTF shim: builds a tinygltf model from the plain
// description of sy_gltf_shim.h (>>writing) and serialises it with tinygltf's GLB writer. Every entry
// point catches every exception; nothing C++ leaks through the C interface.
#include "sy_gltf_shim.h"

#include "sy_cpp_error.h"

#include <tiny_gltf.h>

#include <climits>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <new>
#include <set>
#include <sstream>
#include <string>
#include <vector>

// >>material extensions: the table both halves of the shim go by (sy_gltf_shim.h)
#define SY_EXT_(ext, key, kind, flags, d0, d1, d2, rd, wr)                                                                 \
    {ext, key, kind, flags, {d0, d1, d2}, offsetof(sy_gltf_shim_material, rd), offsetof(sy_gltf_shim_wmaterial, wr)}
#define SY_EXT_NUM(ext, key, flags, def, rd, wr) SY_EXT_(ext, key, SY_GLTF_EXT_NUMBER, flags, def, 0, 0, rd, wr)
#define SY_EXT_VEC3(ext, key, flags, def, rd, wr) SY_EXT_(ext, key, SY_GLTF_EXT_VEC3, flags, def, def, def, rd, wr)
#define SY_EXT_TEX(ext, key, flags, rd, wr) SY_EXT_(ext, key, SY_GLTF_EXT_TEXTURE, flags, 0, 0, 0, rd, wr)
#define KEY SY_GLTF_EXT_KEY
const sy_gltf_shim_ext_member sy_gltf_shim_ext_members[] = {
    SY_EXT_NUM("KHR_materials_transmission", "transmissionFactor", KEY, 0.0, transmission, transmission),
    SY_EXT_TEX("KHR_materials_transmission", "transmissionTexture", KEY, transmission_texture, transmission_tex),
    SY_EXT_NUM("KHR_materials_ior", "ior", KEY, 1.5, ior, ior),
    SY_EXT_NUM("KHR_materials_specular", "specularFactor", KEY, 1.0, specular, specular),
    SY_EXT_VEC3("KHR_materials_specular", "specularColorFactor", KEY, 1.0, specular_color, specular_color),
    SY_EXT_TEX("KHR_materials_specular", "specularTexture", KEY, specular_texture, specular_tex),
    SY_EXT_TEX("KHR_materials_specular", "specularColorTexture", KEY, specular_color_texture, specular_color_tex),
    SY_EXT_NUM("KHR_materials_clearcoat", "clearcoatFactor", KEY, 0.0, clearcoat, clearcoat),
    SY_EXT_NUM("KHR_materials_clearcoat", "clearcoatRoughnessFactor", 0, 0.0, clearcoat_roughness, clearcoat_roughness),
    SY_EXT_TEX("KHR_materials_clearcoat", "clearcoatTexture", KEY, clearcoat_texture, clearcoat_tex),
    SY_EXT_TEX("KHR_materials_clearcoat", "clearcoatRoughnessTexture", 0, clearcoat_roughness_texture, clearcoat_roughness_tex),
    SY_EXT_TEX("KHR_materials_clearcoat", "clearcoatNormalTexture", SY_GLTF_EXT_SCALE, clearcoat_normal_texture,
               clearcoat_normal_tex),
    SY_EXT_VEC3("KHR_materials_sheen", "sheenColorFactor", KEY, 0.0, sheen_color, sheen_color),
    SY_EXT_NUM("KHR_materials_sheen", "sheenRoughnessFactor", 0, 0.0, sheen_roughness, sheen_roughness),
    SY_EXT_TEX("KHR_materials_sheen", "sheenColorTexture", KEY, sheen_color_texture, sheen_color_tex),
    SY_EXT_TEX("KHR_materials_sheen", "sheenRoughnessTexture", 0, sheen_roughness_texture, sheen_roughness_tex),
    SY_EXT_NUM("KHR_materials_volume", "thicknessFactor", KEY, 0.0, thickness, thickness),
    SY_EXT_NUM("KHR_materials_volume", "attenuationDistance", KEY | SY_GLTF_EXT_ABOVE, 0.0, attenuation_distance,
               attenuation_distance),
    SY_EXT_VEC3("KHR_materials_volume", "attenuationColor", KEY, 1.0, attenuation_color, attenuation_color),
    SY_EXT_TEX("KHR_materials_volume", "thicknessTexture", KEY, thickness_texture, thickness_tex),
    SY_EXT_NUM("KHR_materials_iridescence", "iridescenceFactor", KEY, 0.0, iridescence, iridescence),
    SY_EXT_NUM("KHR_materials_iridescence", "iridescenceIor", 0, 1.3, iridescence_ior, iridescence_ior),
    SY_EXT_NUM("KHR_materials_iridescence", "iridescenceThicknessMinimum", 0, 100.0, iridescence_thickness[0],
               iridescence_thickness[0]),
    SY_EXT_NUM("KHR_materials_iridescence", "iridescenceThicknessMaximum", 0, 400.0, iridescence_thickness[1],
               iridescence_thickness[1]),
    SY_EXT_TEX("KHR_materials_iridescence", "iridescenceTexture", KEY, iridescence_texture, iridescence_tex),
    SY_EXT_TEX("KHR_materials_iridescence", "iridescenceThicknessTexture", 0, iridescence_thickness_texture,
               iridescence_thickness_tex),
    SY_EXT_NUM("KHR_materials_anisotropy", "anisotropyStrength", KEY, 0.0, anisotropy, anisotropy),
    SY_EXT_NUM("KHR_materials_anisotropy", "anisotropyRotation", 0, 0.0, anisotropy_rotation, anisotropy_rotation),
    SY_EXT_TEX("KHR_materials_anisotropy", "anisotropyTexture", KEY, anisotropy_texture, anisotropy_tex),
};
const size_t sy_gltf_shim_ext_member_count = sizeof sy_gltf_shim_ext_members / sizeof sy_gltf_shim_ext_members[0];
#undef KEY
#undef SY_EXT_TEX
#undef SY_EXT_VEC3
#undef SY_EXT_NUM
#undef SY_EXT_

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

using Obj = tinygltf::Value::Object;

tinygltf::Value num(double v) { return tinygltf::Value(v); }

tinygltf::Value vec(const double *v, int n)
{
    tinygltf::Value::Array a;
    for (int i = 0; i < n; ++i) a.push_back(num(v[i]));
    return tinygltf::Value(a);
}

// KHR_texture_transform of a reference, unless it is the identity (then nothing is added).
void add_transform(const sy_gltf_shim_wtexref &r, tinygltf::ExtensionMap &ext, std::set<std::string> &used)
{
    if (r.offset[0] == 0 && r.offset[1] == 0 && r.rotation == 0 && r.uv_scale[0] == 1 && r.uv_scale[1] == 1) return;
    Obj o;
    if (r.offset[0] != 0 || r.offset[1] != 0) o["offset"] = vec(r.offset, 2);
    if (r.rotation != 0) o["rotation"] = num(r.rotation);
    if (r.uv_scale[0] != 1 || r.uv_scale[1] != 1) o["scale"] = vec(r.uv_scale, 2);
    ext["KHR_texture_transform"] = tinygltf::Value(o);
    used.insert("KHR_texture_transform");
}

template <typename Info> void set_info(Info &info, const sy_gltf_shim_wtexref &r, std::set<std::string> &used)
{
    info.index = r.texture - 1;
    info.texCoord = int(r.texcoord);
    add_transform(r, info.extensions, used);
}

// A textureInfo inside a material extension (index, texCoord, KHR_texture_transform).
void put_tex(Obj &o, const char *key, const sy_gltf_shim_wtexref &r, std::set<std::string> &used)
{
    if (r.texture <= 0) return;
    Obj t;
    t["index"] = tinygltf::Value(r.texture - 1);
    if (r.texcoord) t["texCoord"] = tinygltf::Value(int(r.texcoord));
    tinygltf::ExtensionMap ext;
    add_transform(r, ext, used);
    if (!ext.empty()) t["extensions"] = tinygltf::Value(Obj(ext.begin(), ext.end()));
    o[key] = tinygltf::Value(t);
}

void put_ext(tinygltf::Material &mt, const char *name, Obj o, std::set<std::string> &used)
{
    mt.extensions[name] = tinygltf::Value(o);
    used.insert(name);
}

bool same3(const double *a, double v) { return a[0] == v && a[1] == v && a[2] == v; }

// The KHR_materials_* extensions of a full material (sy_gltf_shim_ext_members), each written when
// one of its key members is off its default.
void material_extensions(const sy_gltf_shim_wmaterial &w, tinygltf::Material &mt, std::set<std::string> &used)
{
    const char *base = reinterpret_cast<const char *>(&w);
    for (size_t i = 0, end; i < sy_gltf_shim_ext_member_count; i = end) {
        const char *name = sy_gltf_shim_ext_members[i].extension;
        bool write = false;
        for (end = i; end < sy_gltf_shim_ext_member_count && !strcmp(sy_gltf_shim_ext_members[end].extension, name); ++end) {
            const sy_gltf_shim_ext_member &f = sy_gltf_shim_ext_members[end];
            const double *v = reinterpret_cast<const double *>(base + f.write);
            if (!(f.flags & SY_GLTF_EXT_KEY)) continue;
            if (f.kind == SY_GLTF_EXT_TEXTURE) write = write || reinterpret_cast<const sy_gltf_shim_wtexref *>(v)->texture;
            else for (int k = 0; k < (f.kind == SY_GLTF_EXT_VEC3 ? 3 : 1); ++k) write = write || v[k] != f.def[k];
        }
        if (!write) continue;
        Obj o;
        for (size_t k = i; k < end; ++k) {
            const sy_gltf_shim_ext_member &f = sy_gltf_shim_ext_members[k];
            const double *v = reinterpret_cast<const double *>(base + f.write);
            if (f.kind == SY_GLTF_EXT_VEC3) o[f.key] = vec(v, 3);
            else if (f.kind == SY_GLTF_EXT_NUMBER && (!(f.flags & SY_GLTF_EXT_ABOVE) || *v > f.def[0])) o[f.key] = num(*v);
            if (f.kind != SY_GLTF_EXT_TEXTURE) continue;
            const sy_gltf_shim_wtexref &t = *reinterpret_cast<const sy_gltf_shim_wtexref *>(v);
            put_tex(o, f.key, t, used);
            if ((f.flags & SY_GLTF_EXT_SCALE) && t.texture && t.scale != 1) o[f.key].Get<Obj>()["scale"] = num(t.scale);
        }
        put_ext(mt, name, o, used);
    }
}

void build_model(const sy_gltf_shim_wdoc *d, tinygltf::Model &m)
{
    m.asset.version = "2.0";
    m.asset.generator = str_or_empty(d->generator);
    m.buffers.resize(1);
    std::set<std::string> used;
    for (uint32_t i = 0; i < d->texture_count; ++i) { // one image, sampler and texture each
        const sy_gltf_shim_wtexture &w = d->textures[i];
        tinygltf::Image im;
        im.name = str_or_empty(w.name);
        im.mimeType = "image/png";
        im.bufferView = add_view(m, w.png, w.png_size, 0);
        m.images.push_back(im);
        tinygltf::Sampler sm;
        sm.wrapS = w.wrap_s, sm.wrapT = w.wrap_t, sm.minFilter = w.min_filter, sm.magFilter = w.mag_filter;
        m.samplers.push_back(sm);
        tinygltf::Texture tx;
        tx.name = im.name;
        tx.source = int(i), tx.sampler = int(i);
        m.textures.push_back(tx);
    }
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
            Obj o;
            o["emissiveStrength"] = tinygltf::Value(w.emissive_strength);
            put_ext(mt, "KHR_materials_emissive_strength", o, used);
        }
        if (w.unlit) put_ext(mt, "KHR_materials_unlit", Obj(), used);
        if (w.full) {
            if (w.base_color_tex.texture) set_info(mt.pbrMetallicRoughness.baseColorTexture, w.base_color_tex, used);
            if (w.metallic_roughness_tex.texture)
                set_info(mt.pbrMetallicRoughness.metallicRoughnessTexture, w.metallic_roughness_tex, used);
            if (w.normal_tex.texture) set_info(mt.normalTexture, w.normal_tex, used), mt.normalTexture.scale = w.normal_tex.scale;
            if (w.occlusion_tex.texture)
                set_info(mt.occlusionTexture, w.occlusion_tex, used), mt.occlusionTexture.strength = w.occlusion_tex.scale;
            if (w.emissive_tex.texture) set_info(mt.emissiveTexture, w.emissive_tex, used);
            material_extensions(w, mt, used);
        }
        m.materials.push_back(mt);
    }
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
            const struct { const char *name; const float *data; int type, components; } attrs[] = {
                {"NORMAL", p.normals, TINYGLTF_TYPE_VEC3, 3},        {"TEXCOORD_0", p.texcoords0, TINYGLTF_TYPE_VEC2, 2},
                {"TANGENT", p.tangents, TINYGLTF_TYPE_VEC4, 4},      {"TEXCOORD_1", p.texcoords1, TINYGLTF_TYPE_VEC2, 2},
                {"COLOR_0", p.colors, TINYGLTF_TYPE_VEC4, 4}};
            for (const auto &a : attrs)
                if (a.data)
                    pr.attributes[a.name] = add_accessor(m, a.data, p.vertex_count, a.type, a.components,
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
    for (uint32_t i = 0; i < d->camera_count; ++i) {
        const sy_gltf_shim_wcamera &w = d->cameras[i];
        tinygltf::Camera c;
        c.name = str_or_empty(w.name);
        if (w.orthographic) {
            c.type = "orthographic";
            c.orthographic.xmag = w.xmag, c.orthographic.ymag = w.ymag;
            c.orthographic.znear = w.znear, c.orthographic.zfar = w.zfar;
        } else {
            c.type = "perspective";
            c.perspective.yfov = w.yfov, c.perspective.aspectRatio = w.aspect;
            c.perspective.znear = w.znear, c.perspective.zfar = w.zfar;
        }
        m.cameras.push_back(c);
    }
    for (uint32_t i = 0; i < d->light_count; ++i) {
        const sy_gltf_shim_wlight &w = d->lights[i];
        tinygltf::Light l;
        l.name = str_or_empty(w.name);
        l.type = w.type;
        l.color.assign(w.color, w.color + 3);
        l.intensity = w.intensity;
        l.range = w.range;
        if (!strcmp(w.type, "spot")) l.spot.innerConeAngle = w.inner_cone, l.spot.outerConeAngle = w.outer_cone;
        m.lights.push_back(l);
        used.insert("KHR_lights_punctual");
    }
    tinygltf::Scene scene;
    for (uint32_t i = 0; i < d->node_count; ++i) {
        const sy_gltf_shim_wnode &w = d->nodes[i];
        tinygltf::Node n;
        n.name = str_or_empty(w.name);
        n.mesh = w.mesh;
        if (w.trs) {
            if (!same3(w.translation, 0)) n.translation.assign(w.translation, w.translation + 3);
            if (w.rotation[0] != 0 || w.rotation[1] != 0 || w.rotation[2] != 0 || w.rotation[3] != 1)
                n.rotation.assign(w.rotation, w.rotation + 4);
            if (!same3(w.scale, 1)) n.scale.assign(w.scale, w.scale + 3);
        } else {
            static const double identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
            if (memcmp(w.matrix, identity, sizeof identity) != 0) n.matrix.assign(w.matrix, w.matrix + 16);
        }
        if (w.camera > 0) n.camera = w.camera - 1;
        if (w.light > 0) n.extensions["KHR_lights_punctual"] = tinygltf::Value(Obj{{"light", tinygltf::Value(w.light - 1)}});
        n.children.assign(w.children, w.children + w.child_count);
        if (w.id >= 0) {
            tinygltf::Value::Object o;
            o["id"] = tinygltf::Value(double(w.id));
            n.extras = tinygltf::Value(o);
        }
        // tinygltf serialises a node without any property as null, which no reader takes: such a
        // node gets its (identity) matrix written
        if (n.name.empty() && n.mesh < 0 && n.camera < 0 && n.children.empty() && n.extensions.empty() &&
            n.matrix.empty() && n.translation.empty() && n.rotation.empty() && n.scale.empty() &&
            n.extras.Type() == tinygltf::NULL_TYPE)
            n.matrix = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
        m.nodes.push_back(n);
        if (!d->roots) scene.nodes.push_back(int(i));
    }
    if (d->roots) scene.nodes.assign(d->roots, d->roots + d->root_count);
    m.scenes.push_back(scene);
    m.defaultScene = 0;
    m.extensionsUsed.assign(used.begin(), used.end());
}

} // namespace

extern "C" sy_result sy_gltf_shim_write_glb(const sy_gltf_shim_wdoc *doc, uint8_t **glb_out, size_t *len_out, sy_error *err)
{
    return sy_gltf_shim_write(doc, true, glb_out, len_out, err);
}

extern "C" sy_result sy_gltf_shim_write(const sy_gltf_shim_wdoc *doc, bool binary, uint8_t **glb_out, size_t *len_out,
                                        sy_error *err)
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
        if (!writer.WriteGltfSceneToStream(&model, os, !binary, binary) || !os)
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
    } catch (...) {
        return sy_error_from_exception(err, SY_ERR_IO, "write GLB: out of memory", "write GLB: ",
                                       "write GLB: unknown exception");
    }
}
