// sy_gltf_shim.cpp — parses glTF with tinygltf and exposes the result as the plain C structs of
// sy_gltf_shim.h. Parsing only: all cross-reference and range validation happens in sy_gltf_validate.c.
// Every entry point catches every exception; nothing C++ leaks through the C interface.
#include "sy_gltf_shim.h"

#include "sy_cpp_error.h"
#include "sy_file.h"
#include "sy_gltf_draco.h"
#include "sy_gltf_meshopt.h"
#include "sy_sniff.h"

#include <nlohmann/json.hpp>
#include <tiny_gltf.h>

#include <stb_image.h>
#include <webp/decode.h>

#include <sys/stat.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <new>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace {

struct LoadContext {
    std::string prefix;            // the model's folder: external files are joined to it
    const char *const *roots = nullptr; // further folders external files may lie in
    size_t root_count = 0;
    std::string refused;           // the first URI refused by the confinement (fails the load)
    size_t max_file_bytes = 0;
    uint64_t max_image_pixels = 0;
    uint64_t max_image_bytes = 0;  // all decoded images together (0 = no limit)
    uint64_t image_bytes = 0;      // decoded so far
    tinygltf::Model *model = nullptr;
    sy_result fs_result = SY_OK;   // first file-system failure category
    std::string fs_message;
    std::map<int, std::string> image_problems; // images that failed to decode (local: missing texture)
    std::set<int> webp_images;     // images an EXT_texture_webp source names (the only WebP decoded)
};

// >>file-system callbacks: files confined to the glTF's folder (sy_path_confine: after symbolic
// links and "..", absolute paths and file: URIs only inside allowed_roots), reads size-limited.
// A refusal is remembered (fs_result) and fails the whole load with its message.
// Resolves path (tinygltf joined it to the prefix) to the real file to read; "" when refused or absent.
std::string confine(LoadContext *ctx, const std::string &path)
{
    std::string uri = ctx->prefix.empty() || path.compare(0, ctx->prefix.size(), ctx->prefix) != 0
                          ? path
                          : path.substr(ctx->prefix.size());
    char *real = nullptr;
    sy_error e = {};
    sy_result r = sy_path_confine("URI", uri.c_str(), path.c_str(), ctx->prefix.c_str(), ctx->roots, ctx->root_count,
                                  &real, &e);
    if (r != SY_OK) {
        if (r != SY_ERR_NOT_FOUND && ctx->refused.empty()) ctx->refused = e.message;
        return std::string();
    }
    std::string out = real;
    free(real);
    return out;
}

bool fs_file_exists(const std::string &path, void *user)
{
    LoadContext *ctx = static_cast<LoadContext *>(user);
    std::string real = confine(ctx, path);
    struct stat st;
    return !real.empty() && stat(real.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

std::string fs_expand(const std::string &path, void *) { return path; } // no shell expansion

bool fs_read(std::vector<unsigned char> *out, std::string *err, const std::string &path, void *user)
{
    LoadContext *ctx = static_cast<LoadContext *>(user);
    std::string real = confine(ctx, path);
    if (real.empty()) {
        if (err) *err = ctx->refused.empty() ? "file not found" : ctx->refused;
        return false;
    }
    void *data = nullptr;
    size_t size = 0;
    sy_error e = {};
    sy_result r = sy_file_read_all(real.c_str(), ctx->max_file_bytes, &data, &size, &e);
    if (r != SY_OK) {
        if (ctx->fs_result == SY_OK) {
            ctx->fs_result = r;
            ctx->fs_message = e.message;
        }
        if (err) *err = e.message;
        return false;
    }
    try {
        const unsigned char *p = static_cast<const unsigned char *>(data);
        out->assign(p, p + size);
    } catch (...) {
        free(data);
        throw;
    }
    free(data);
    return true;
}

bool fs_write(std::string *err, const std::string &, const std::vector<unsigned char> &, void *)
{
    if (err) *err = "writing is not supported";
    return false;
}

// >>image decoding: dimensions checked against the limit before stb allocates anything.
bool load_image(tinygltf::Image *image, const int image_idx, std::string *err, std::string *, int, int,
                const unsigned char *bytes, int size, void *user)
{
    LoadContext *ctx = static_cast<LoadContext *>(user);
    const std::string where = "images[" + std::to_string(image_idx) + "]";
    size_t len = size > 0 ? size_t(size) : 0;
    if (image->bufferView >= 0) {
        // tinygltf computed `bytes` from the bufferView without checking it against its buffer.
        const tinygltf::Model &m = *ctx->model;
        if (size_t(image->bufferView) >= m.bufferViews.size()) {
            if (err) *err += where + ": bufferView " + std::to_string(image->bufferView) + " out of range\n";
            return false;
        }
        const tinygltf::BufferView &bv = m.bufferViews[size_t(image->bufferView)];
        if (bv.buffer < 0 || size_t(bv.buffer) >= m.buffers.size()) {
            if (err) *err += where + ": bufferView buffer index out of range\n";
            return false;
        }
        const std::vector<unsigned char> &data = m.buffers[size_t(bv.buffer)].data;
        if (bv.byteOffset > data.size() || bv.byteLength > data.size() - bv.byteOffset) {
            if (err)
                *err += where + ": bufferView " + std::to_string(image->bufferView) + " (offset " +
                        std::to_string(bv.byteOffset) + ", length " + std::to_string(bv.byteLength) +
                        ") exceeds buffer " + std::to_string(bv.buffer) + " length " + std::to_string(data.size()) +
                        "\n";
            return false;
        }
        bytes = data.data() + bv.byteOffset;
        len = bv.byteLength;
    }
    if (len == 0 || len > size_t(INT_MAX)) {
        if (err) *err += where + ": image data is empty or larger than 2 GiB\n";
        return false;
    }
    const sy_file_format kind = sy_sniff_bytes(bytes, len);
    // WebP only where EXT_texture_webp references the image (libwebp decodes it; stb_image never sees it)
    const bool webp = kind == SY_FORMAT_WEBP && ctx->webp_images.count(image_idx) != 0;
    if (!webp && !sy_file_format_is_texture_image(kind, false)) { // stb_image would take HDR, PSD, TGA... too
        ctx->image_problems[image_idx] = std::string(sy_file_format_name(kind)) +
                                         (kind == SY_FORMAT_WEBP ? " content outside EXT_texture_webp" : " content, not a PNG or JPEG image");
        image->image.clear();
        return true;
    }
    int w = 0, h = 0, comp = 4;
    if (webp ? !WebPGetInfo(bytes, len, &w, &h) || w < 1 || h < 1
             : !stbi_info_from_memory(bytes, int(len), &w, &h, &comp) || w < 1 || h < 1 || comp < 1 || comp > 4) {
        const char *why = webp ? "not a decodable WebP image" : stbi_failure_reason();
        ctx->image_problems[image_idx] = "cannot decode image (" + std::string(why ? why : "unknown format") + ")";
        image->image.clear();
        return true; // a bad image is local: the texture goes missing with a warning
    }
    if (uint64_t(w) * uint64_t(h) > ctx->max_image_pixels) { // refused before decoding; local like a bad image
        ctx->image_problems[image_idx] = "image " + std::to_string(w) + "x" + std::to_string(h) +
                                         " exceeds the limit of " + std::to_string(ctx->max_image_pixels) + " pixels";
        image->image.clear();
        return true;
    }
    const int req = comp <= 2 ? 4 : comp; // grey / grey+alpha become RGBA
    const size_t n = size_t(w) * size_t(h) * size_t(req);
    if (ctx->max_image_bytes && n > ctx->max_image_bytes - std::min(ctx->image_bytes, ctx->max_image_bytes)) {
        ctx->image_problems[image_idx] = "image " + std::to_string(w) + "x" + std::to_string(h) + " (" +
                                         std::to_string(n >> 20) + " MiB decoded) exceeds what is left of the scene budget (" +
                                         std::to_string((ctx->max_image_bytes - ctx->image_bytes) >> 20) + " MiB)";
        image->image.clear();
        return true;
    }
    ctx->image_bytes += n;
    int w2 = 0, h2 = 0, c2 = 0;
    bool is16 = !webp && stbi_is_16_bit_from_memory(bytes, int(len)) != 0;
    image->image.resize(n);
    // decode (16-bit sources are rounded to 8 bits); a size that differs from the header is a failure
    bool ok = false;
    if (webp) {
        ok = WebPDecodeRGBAInto(bytes, len, image->image.data(), n, w * 4) != nullptr;
    } else if (is16) {
        stbi_us *p = stbi_load_16_from_memory(bytes, int(len), &w2, &h2, &c2, req);
        ok = p && w2 == w && h2 == h;
        if (ok)
            for (size_t i = 0; i < n; i++) image->image[i] = (unsigned char)((uint32_t(p[i]) * 255u + 32767u) / 65535u);
        stbi_image_free(p);
    } else {
        stbi_uc *p = stbi_load_from_memory(bytes, int(len), &w2, &h2, &c2, req);
        ok = p && w2 == w && h2 == h;
        if (ok) memcpy(image->image.data(), p, n);
        stbi_image_free(p);
    }
    if (!ok) {
        image->image.clear();
        const char *why = webp ? "WebP data does not decode" : stbi_failure_reason();
        ctx->image_problems[image_idx] = "cannot decode image (" + std::string(why ? why : "unknown") + ")";
        return true;
    }
    image->width = w;
    image->height = h;
    image->component = req;
    image->bits = is16 ? 16 : 8; // source depth; the pixels are always 8-bit
    image->pixel_type = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
    return true;
}

// >>JSON value helpers (tinygltf::Value asserts on type misuse: check before every Get)
const tinygltf::Value *member(const tinygltf::Value &v, const char *key)
{
    if (!v.IsObject() || !v.Has(key)) return nullptr;
    return &v.Get(key);
}

double number(const tinygltf::Value &v, const char *key, double def)
{
    const tinygltf::Value *m = member(v, key);
    return (m && m->IsNumber()) ? m->GetNumberAsDouble() : def;
}

/* The numbers of a fixed-length array member (def when absent or of another length). */
void numbers(const tinygltf::Value &v, const char *key, double *out, size_t n, const double *def)
{
    const tinygltf::Value *m = member(v, key);
    bool ok = m && m->IsArray() && m->ArrayLen() == n;
    for (size_t i = 0; ok && i < n; i++) ok = m->Get(int(i)).IsNumber();
    for (size_t i = 0; i < n; i++) out[i] = ok ? m->Get(int(i)).GetNumberAsDouble() : def[i];
}

int32_t integer(const tinygltf::Value &v, const char *key, int32_t def)
{
    const tinygltf::Value *m = member(v, key);
    if (!m || !m->IsNumber()) return def;
    double d = m->GetNumberAsDouble();
    if (!(d >= double(INT32_MIN) && d <= double(INT32_MAX))) return INT32_MIN; // out of range: caught later
    return int32_t(d);
}

const tinygltf::Value *extension(const tinygltf::ExtensionMap &ext, const char *name)
{
    auto it = ext.find(name);
    return it == ext.end() ? nullptr : &it->second;
}

void read_transform(const tinygltf::ExtensionMap &ext, sy_gltf_shim_texinfo *t)
{
    t->offset[0] = t->offset[1] = 0.0;
    t->rotation = 0.0;
    t->uv_scale[0] = t->uv_scale[1] = 1.0;
    t->transform_texcoord = -1;
    const tinygltf::Value *tt = extension(ext, "KHR_texture_transform");
    if (!tt || !tt->IsObject()) return;
    t->has_transform = 1;
    const tinygltf::Value *off = member(*tt, "offset");
    if (off && off->IsArray() && off->ArrayLen() == 2 && off->Get(0).IsNumber() && off->Get(1).IsNumber()) {
        t->offset[0] = off->Get(0).GetNumberAsDouble();
        t->offset[1] = off->Get(1).GetNumberAsDouble();
    }
    const tinygltf::Value *sc = member(*tt, "scale");
    if (sc && sc->IsArray() && sc->ArrayLen() == 2 && sc->Get(0).IsNumber() && sc->Get(1).IsNumber()) {
        t->uv_scale[0] = sc->Get(0).GetNumberAsDouble();
        t->uv_scale[1] = sc->Get(1).GetNumberAsDouble();
    }
    t->rotation = number(*tt, "rotation", 0.0);
    t->transform_texcoord = integer(*tt, "texCoord", -1);
}

template <typename Info> sy_gltf_shim_texinfo texinfo(const Info &in, double scale)
{
    sy_gltf_shim_texinfo t = {};
    t.index = in.index;
    t.texcoord = in.texCoord;
    t.scale = scale;
    read_transform(in.extensions, &t);
    return t;
}

// Texture info given as a raw JSON value (inside material extensions).
sy_gltf_shim_texinfo texinfo_value(const tinygltf::Value *v)
{
    sy_gltf_shim_texinfo t = {};
    t.index = -1;
    t.scale = 1.0;
    t.offset[0] = t.offset[1] = 0.0;
    t.uv_scale[0] = t.uv_scale[1] = 1.0;
    t.transform_texcoord = -1;
    if (!v || !v->IsObject()) return t;
    t.index = integer(*v, "index", -1);
    t.texcoord = integer(*v, "texCoord", 0);
    const tinygltf::Value *ext = member(*v, "extensions");
    if (ext && ext->IsObject()) {
        tinygltf::ExtensionMap map;
        for (const std::string &k : ext->Keys()) map[k] = ext->Get(k);
        read_transform(map, &t);
    }
    return t;
}

/* A primitive's KHR_materials_variants mappings, one use per (mapping, variant); a malformed
 * index is kept as INT32_MIN or -1 for validation to name. */
void read_variant_uses(const tinygltf::ExtensionMap &ext, int32_t mesh, int32_t prim,
                       std::vector<sy_gltf_shim_variant_use> *out)
{
    const tinygltf::Value *e = extension(ext, "KHR_materials_variants");
    const tinygltf::Value *ms = e ? member(*e, "mappings") : nullptr;
    for (size_t i = 0; ms && ms->IsArray() && i < ms->ArrayLen(); i++) {
        const tinygltf::Value &mp = ms->Get(int(i));
        int32_t material = integer(mp, "material", -1);
        const tinygltf::Value *vs = member(mp, "variants");
        for (size_t k = 0; vs && vs->IsArray() && k < vs->ArrayLen(); k++) {
            const tinygltf::Value &v = vs->Get(int(k));
            double x = v.IsNumber() ? v.GetNumberAsDouble() : -1.0;
            out->push_back({mesh, prim, material, x >= 0.0 && x <= double(INT32_MAX) ? int32_t(x) : -1});
        }
    }
}

/* The material extensions' members (sy_gltf_shim_ext_members) into c. */
void read_material_extensions(const tinygltf::ExtensionMap &ext, sy_gltf_shim_material *c)
{
    const tinygltf::Value none;
    for (size_t i = 0; i < sy_gltf_shim_ext_member_count; i++) {
        const sy_gltf_shim_ext_member &f = sy_gltf_shim_ext_members[i];
        const tinygltf::Value *e = extension(ext, f.extension);
        const tinygltf::Value &v = e ? *e : none;
        char *to = reinterpret_cast<char *>(c) + f.read;
        if (f.kind == SY_GLTF_EXT_NUMBER) {
            *reinterpret_cast<double *>(to) = number(v, f.key, f.def[0]);
        } else if (f.kind == SY_GLTF_EXT_VEC3) {
            numbers(v, f.key, reinterpret_cast<double *>(to), 3, f.def);
        } else {
            sy_gltf_shim_texinfo &t = *reinterpret_cast<sy_gltf_shim_texinfo *>(to);
            t = texinfo_value(member(v, f.key));
            if (const tinygltf::Value *n = (f.flags & SY_GLTF_EXT_SCALE) ? member(v, f.key) : nullptr) t.scale = number(*n, "scale", 1.0);
        }
    }
}

int32_t components_of(int type)
{
    switch (type) {
    case TINYGLTF_TYPE_SCALAR: return 1;
    case TINYGLTF_TYPE_VEC2: return 2;
    case TINYGLTF_TYPE_VEC3: return 3;
    case TINYGLTF_TYPE_VEC4: return 4;
    case TINYGLTF_TYPE_MAT2: return 4;
    case TINYGLTF_TYPE_MAT3: return 9;
    case TINYGLTF_TYPE_MAT4: return 16;
    default: return 0;
    }
}

std::string one_line(std::string s)
{
    while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
    for (char &c : s)
        if (c == '\n') c = ';';
    return s;
}

} // namespace

// The document: the C view plus the C++ storage it points into (doc.internal points back here).
struct sy_gltf_shim_impl {
    sy_gltf_doc doc = {};
    std::map<int, std::string> image_problems;
    tinygltf::Model model;
    std::vector<sy_gltf_shim_buffer> buffers;
    std::vector<sy_gltf_shim_view> views;
    std::vector<sy_gltf_shim_accessor> accessors;
    std::vector<std::vector<sy_gltf_shim_primitive>> prims;
    std::vector<sy_gltf_shim_mesh> meshes;
    std::vector<sy_gltf_shim_material> materials;
    std::vector<sy_gltf_shim_texture> textures;
    std::vector<sy_gltf_shim_sampler> samplers;
    std::vector<sy_gltf_shim_image> images;
    std::vector<sy_gltf_shim_camera> cameras;
    std::vector<sy_gltf_shim_light> lights;
    std::vector<std::vector<int32_t>> node_children;
    std::vector<sy_gltf_shim_node> nodes;
    std::vector<std::vector<int32_t>> scene_nodes;
    std::vector<sy_gltf_shim_scene> scenes;
    std::vector<sy_gltf_shim_channel> channels;
    std::vector<std::vector<sy_gltf_shim_anim_sampler>> anim_samplers;
    std::vector<std::vector<sy_gltf_shim_anim_channel>> anim_channels;
    std::vector<sy_gltf_shim_animation> animations;
    std::vector<int32_t> targets; // every primitive's morph target accessors, 3 per target
    std::vector<std::vector<int32_t>> skin_joints;
    std::vector<sy_gltf_shim_skin> skins;
    std::vector<const char *> ext_required;
    std::vector<const char *> ext_used;
    std::vector<const char *> variant_names;
    std::vector<sy_gltf_shim_variant_use> variant_uses;
    std::string warnings;
    std::vector<std::vector<uint8_t>> decoded; // buffers made by decoding compressed meshes
};

// The C view of a vector: its elements and their count.
template <typename T> static void expose(const std::vector<T> &v, const T *&items, size_t &count)
{
    items = v.data();
    count = v.size();
}

static void fill_doc(sy_gltf_shim_impl *d)
{
    const tinygltf::Model &m = d->model;
    for (const tinygltf::Buffer &b : m.buffers) d->buffers.push_back({b.data.data(), b.data.size()});
    for (const tinygltf::BufferView &v : m.bufferViews)
        d->views.push_back({int32_t(v.buffer), v.byteOffset, v.byteLength, v.byteStride});
    for (const tinygltf::Accessor &a : m.accessors) {
        sy_gltf_shim_accessor c = {};
        c.name = a.name.c_str();
        c.buffer_view = a.bufferView;
        c.byte_offset = a.byteOffset;
        c.component_type = a.componentType;
        c.components = components_of(a.type);
        c.is_matrix = a.type == TINYGLTF_TYPE_MAT2 || a.type == TINYGLTF_TYPE_MAT3 || a.type == TINYGLTF_TYPE_MAT4;
        c.normalized = a.normalized;
        c.count = a.count;
        c.sparse = a.sparse.isSparse;
        if (a.sparse.isSparse) {
            c.sparse_count = a.sparse.count;
            c.sparse_indices_view = a.sparse.indices.bufferView;
            c.sparse_indices_offset = a.sparse.indices.byteOffset;
            c.sparse_indices_type = a.sparse.indices.componentType;
            c.sparse_values_view = a.sparse.values.bufferView;
            c.sparse_values_offset = a.sparse.values.byteOffset;
        }
        d->accessors.push_back(c);
    }
    for (const tinygltf::Mesh &mesh : m.meshes) {
        std::vector<sy_gltf_shim_primitive> ps;
        for (const tinygltf::Primitive &p : mesh.primitives) {
            sy_gltf_shim_primitive c = {};
            c.mode = p.mode < 0 ? TINYGLTF_MODE_TRIANGLES : p.mode;
            c.indices = p.indices;
            c.material = p.material;
            auto attr = [&](const char *name) {
                auto it = p.attributes.find(name);
                return it == p.attributes.end() ? -1 : int32_t(it->second);
            };
            c.position = attr("POSITION");
            c.normal = attr("NORMAL");
            c.tangent = attr("TANGENT");
            c.texcoord0 = attr("TEXCOORD_0");
            c.texcoord1 = attr("TEXCOORD_1");
            c.color0 = attr("COLOR_0");
            c.has_targets = !p.targets.empty();
            c.joints0 = attr("JOINTS_0");
            c.weights0 = attr("WEIGHTS_0");
            c.joints1 = attr("JOINTS_1");
            c.weights1 = attr("WEIGHTS_1");
            // offset into d->targets for now; made a pointer once the vector stops growing
            c.targets = reinterpret_cast<const int32_t *>(uintptr_t(d->targets.size()));
            c.target_count = p.targets.size();
            for (const std::map<std::string, int> &t : p.targets)
                for (const char *k : {"POSITION", "NORMAL", "TANGENT"}) {
                    auto it = t.find(k);
                    d->targets.push_back(it == t.end() ? -1 : int32_t(it->second));
                }
            read_variant_uses(p.extensions, int32_t(d->prims.size()), int32_t(ps.size()), &d->variant_uses);
            ps.push_back(c);
        }
        d->prims.push_back(std::move(ps));
    }
    for (std::vector<sy_gltf_shim_primitive> &ps : d->prims)
        for (sy_gltf_shim_primitive &c : ps)
            c.targets = c.target_count ? d->targets.data() + uintptr_t(c.targets) : nullptr;
    for (size_t i = 0; i < m.meshes.size(); i++)
        d->meshes.push_back({m.meshes[i].name.c_str(), d->prims[i].data(), d->prims[i].size(), m.meshes[i].weights.data(),
                             m.meshes[i].weights.size()});
    for (const tinygltf::Skin &sk : m.skins) d->skin_joints.emplace_back(sk.joints.begin(), sk.joints.end());
    for (size_t i = 0; i < m.skins.size(); i++)
        d->skins.push_back({m.skins[i].name.c_str(), int32_t(m.skins[i].inverseBindMatrices), int32_t(m.skins[i].skeleton),
                            d->skin_joints[i].data(), d->skin_joints[i].size()});
    for (const tinygltf::Material &mat : m.materials) {
        sy_gltf_shim_material c = {};
        c.name = mat.name.c_str();
        const tinygltf::PbrMetallicRoughness &pbr = mat.pbrMetallicRoughness;
        c.base_color_count = int32_t(pbr.baseColorFactor.size());
        for (size_t k = 0; k < 4; k++) c.base_color[k] = k < pbr.baseColorFactor.size() ? pbr.baseColorFactor[k] : 1.0;
        c.metallic = pbr.metallicFactor;
        c.roughness = pbr.roughnessFactor;
        c.base_color_texture = texinfo(pbr.baseColorTexture, 1.0);
        c.metallic_roughness_texture = texinfo(pbr.metallicRoughnessTexture, 1.0);
        c.normal_texture = texinfo(mat.normalTexture, mat.normalTexture.scale);
        c.occlusion_texture = texinfo(mat.occlusionTexture, mat.occlusionTexture.strength);
        c.emissive_texture = texinfo(mat.emissiveTexture, 1.0);
        c.emissive_count = int32_t(mat.emissiveFactor.size());
        for (size_t k = 0; k < 3; k++) c.emissive[k] = k < mat.emissiveFactor.size() ? mat.emissiveFactor[k] : 0.0;
        c.alpha_mode = mat.alphaMode.c_str();
        c.alpha_cutoff = mat.alphaCutoff;
        c.double_sided = mat.doubleSided;
        c.emissive_strength = 1.0;
        if (const tinygltf::Value *e = extension(mat.extensions, "KHR_materials_emissive_strength"))
            c.emissive_strength = number(*e, "emissiveStrength", 1.0);
        c.unlit = extension(mat.extensions, "KHR_materials_unlit") != nullptr;
        read_material_extensions(mat.extensions, &c);
        d->materials.push_back(c);
    }
    for (const tinygltf::Texture &t : m.textures) { // EXT_texture_webp's source before the fallback
        const tinygltf::Value *w = extension(t.extensions, "EXT_texture_webp");
        d->textures.push_back({t.name.c_str(), w ? integer(*w, "source", -1) : t.source, t.sampler});
    }
    for (const tinygltf::Sampler &s : m.samplers) d->samplers.push_back({s.minFilter, s.magFilter, s.wrapS, s.wrapT});
    for (const tinygltf::Image &im : m.images) {
        sy_gltf_shim_image c = {};
        auto problem = d->image_problems.find(int(d->images.size()));
        c.name = im.name.c_str();
        c.uri = im.uri.c_str();
        if (!im.image.empty() && im.width > 0 && im.height > 0 && (im.component == 3 || im.component == 4) &&
            im.image.size() == size_t(im.width) * size_t(im.height) * size_t(im.component)) {
            c.pixels = im.image.data();
            c.width = uint32_t(im.width);
            c.height = uint32_t(im.height);
            c.channels = uint32_t(im.component);
            c.source_bits = uint32_t(im.bits);
            c.problem = "";
        } else {
            c.problem = problem != d->image_problems.end() ? problem->second.c_str()
                        : im.uri.empty()                  ? "image data could not be loaded"
                                                          : "external image file not found or unreadable";
        }
        d->images.push_back(c);
    }
    for (const tinygltf::Camera &cam : m.cameras) {
        sy_gltf_shim_camera c = {};
        c.name = cam.name.c_str();
        c.type = cam.type.c_str();
        c.yfov = cam.perspective.yfov;
        c.aspect = cam.perspective.aspectRatio;
        c.znear = cam.perspective.znear;
        c.zfar = cam.perspective.zfar;
        c.xmag = cam.orthographic.xmag;
        c.ymag = cam.orthographic.ymag;
        c.oznear = cam.orthographic.znear;
        c.ozfar = cam.orthographic.zfar;
        d->cameras.push_back(c);
    }
    for (const tinygltf::Light &l : m.lights) {
        sy_gltf_shim_light c = {};
        c.name = l.name.c_str();
        c.type = l.type.c_str();
        c.color_count = int32_t(l.color.size());
        for (size_t k = 0; k < 3; k++) c.color[k] = k < l.color.size() ? l.color[k] : 1.0;
        c.intensity = l.intensity;
        c.range = l.range;
        c.inner_cone = l.spot.innerConeAngle;
        c.outer_cone = l.spot.outerConeAngle;
        d->lights.push_back(c);
    }
    for (const tinygltf::Node &n : m.nodes) d->node_children.emplace_back(n.children.begin(), n.children.end());
    for (size_t i = 0; i < m.nodes.size(); i++) {
        const tinygltf::Node &n = m.nodes[i];
        sy_gltf_shim_node c = {};
        c.name = n.name.c_str();
        c.mesh = n.mesh;
        c.camera = n.camera;
        c.skin = n.skin;
        c.light = -1;
        if (const tinygltf::Value *e = extension(n.extensions, "KHR_lights_punctual")) c.light = integer(*e, "light", -1);
        c.inst_translation = c.inst_rotation = c.inst_scale = -1;
        if (const tinygltf::Value *e = extension(n.extensions, "EXT_mesh_gpu_instancing")) {
            c.instancing = 1;
            if (const tinygltf::Value *a = member(*e, "attributes")) {
                c.inst_translation = integer(*a, "TRANSLATION", -1);
                c.inst_rotation = integer(*a, "ROTATION", -1);
                c.inst_scale = integer(*a, "SCALE", -1);
            }
        }
        c.children = d->node_children[i].data();
        c.child_count = d->node_children[i].size();
        c.matrix = n.matrix.data();
        c.matrix_count = n.matrix.size();
        c.translation = n.translation.data();
        c.translation_count = n.translation.size();
        c.rotation = n.rotation.data();
        c.rotation_count = n.rotation.size();
        c.scale = n.scale.data();
        c.scale_count = n.scale.size();
        c.has_weights = !n.weights.empty();
        c.weights = n.weights.data();
        c.weight_count = n.weights.size();
        d->nodes.push_back(c);
    }
    for (const tinygltf::Scene &s : m.scenes) d->scene_nodes.emplace_back(s.nodes.begin(), s.nodes.end());
    for (size_t i = 0; i < m.scenes.size(); i++)
        d->scenes.push_back({m.scenes[i].name.c_str(), d->scene_nodes[i].data(), d->scene_nodes[i].size()});
    for (const std::string &s : m.extensionsRequired) d->ext_required.push_back(s.c_str());
    for (const std::string &s : m.extensionsUsed) d->ext_used.push_back(s.c_str());
    if (const tinygltf::Value *e = extension(m.extensions, "KHR_materials_variants")) {
        const tinygltf::Value *vs = member(*e, "variants");
        for (size_t i = 0; vs && vs->IsArray() && i < vs->ArrayLen(); i++) {
            const tinygltf::Value *nm = member(vs->Get(int(i)), "name");
            d->variant_names.push_back(nm && nm->IsString() ? nm->Get<std::string>().c_str() : "");
        }
    }

    sy_gltf_doc &c = d->doc;
    expose(d->buffers, c.buffers, c.buffer_count);       expose(d->views, c.views, c.view_count);
    expose(d->accessors, c.accessors, c.accessor_count); expose(d->meshes, c.meshes, c.mesh_count);
    expose(d->materials, c.materials, c.material_count); expose(d->textures, c.textures, c.texture_count);
    expose(d->samplers, c.samplers, c.sampler_count);    expose(d->images, c.images, c.image_count);
    expose(d->cameras, c.cameras, c.camera_count);       expose(d->lights, c.lights, c.light_count);
    expose(d->nodes, c.nodes, c.node_count);             expose(d->scenes, c.scenes, c.scene_count);
    c.default_scene = m.defaultScene;
    expose(d->ext_required, c.extensions_required, c.extensions_required_count);
    expose(d->ext_used, c.extensions_used, c.extensions_used_count);
    expose(d->variant_names, c.variant_names, c.variant_count);
    expose(d->variant_uses, c.variant_uses, c.variant_use_count);
    c.skin_count = m.skins.size();
    c.skins = d->skins.data();
    c.animation_count = m.animations.size();
    if (!m.animations.empty()) {
        const tinygltf::Animation &a = m.animations[0];
        for (const tinygltf::AnimationChannel &ch : a.channels) {
            sy_gltf_shim_channel k = {};
            k.node = ch.target_node;
            k.path = ch.target_path == "translation" ? 0 : ch.target_path == "rotation" ? 1 : ch.target_path == "scale" ? 2 : -1;
            k.output = -1;
            if (ch.sampler >= 0 && size_t(ch.sampler) < a.samplers.size()) {
                k.output = a.samplers[size_t(ch.sampler)].output;
                k.cubic = a.samplers[size_t(ch.sampler)].interpolation == "CUBICSPLINE";
            }
            d->channels.push_back(k);
        }
    }
    c.channels = d->channels.data();
    c.channel_count = d->channels.size();
    d->anim_samplers.resize(m.animations.size());
    d->anim_channels.resize(m.animations.size());
    for (size_t i = 0; i < m.animations.size(); i++) {
        const tinygltf::Animation &a = m.animations[i];
        for (const tinygltf::AnimationSampler &sm : a.samplers) {
            const std::string &ip = sm.interpolation;
            int32_t interp = ip.empty() || ip == "LINEAR" ? 0 : ip == "STEP" ? 1 : ip == "CUBICSPLINE" ? 2 : -1;
            d->anim_samplers[i].push_back({int32_t(sm.input), int32_t(sm.output), interp});
        }
        for (const tinygltf::AnimationChannel &ch : a.channels) {
            const std::string &tp = ch.target_path;
            int32_t path = tp == "translation" ? 0 : tp == "rotation" ? 1 : tp == "scale" ? 2 : tp == "weights" ? 3
                           : tp == "pointer"   ? 4 : -1;
            const char *pointer = nullptr;
            if (path == 4) { // KHR_animation_pointer (patch_for_tinygltf gave the target a placeholder node)
                auto e = ch.target_extensions.find("KHR_animation_pointer");
                if (e != ch.target_extensions.end() && e->second.IsObject() && e->second.Has("pointer") &&
                    e->second.Get("pointer").IsString())
                    pointer = e->second.Get("pointer").Get<std::string>().c_str();
            }
            d->anim_channels[i].push_back({path == 4 ? -1 : int32_t(ch.target_node), path, int32_t(ch.sampler), pointer});
        }
        d->animations.push_back({a.name.c_str(), d->anim_samplers[i].data(), d->anim_samplers[i].size(),
                                 d->anim_channels[i].data(), d->anim_channels[i].size()});
    }
    c.animations = d->animations.data();
    c.warnings = d->warnings.c_str();
    c.internal = d;
}

// >>KHR_draco_mesh_compression: each Draco primitive is decoded (sy_gltf_draco.cpp) into a new
// buffer with one bufferView per accessor; its accessors are pointed at them (float attributes,
// uint16 joint indices, uint32 indices), so the loader reads them as plain accessors. The outputs are sized from the
// glTF's accessor counts, within max_mesh_bytes for all primitives together, before decoding.
static const uint8_t *data_at(const sy_gltf_shim_impl *d, const sy_gltf_shim_view &v)
{
    return d->buffers[size_t(v.buffer)].data + v.byte_offset;
}

static sy_result draco_primitive(sy_gltf_shim_impl *d, size_t mi, size_t pj, const tinygltf::Value &ext,
                                 std::vector<bool> *rewritten, uint64_t *bytes_used, uint64_t max_bytes, sy_error *err)
{
    sy_gltf_shim_primitive &pr = d->prims[mi][pj];
    const int32_t view = integer(ext, "bufferView", -1);
    if (view < 0 || size_t(view) >= d->views.size())
        return sy_error_set(err, SY_ERR_PARSE, "bufferView %d out of range (%zu bufferViews)", (int)view, d->views.size());
    const sy_gltf_shim_view v = d->views[size_t(view)];
    if (v.buffer < 0 || size_t(v.buffer) >= d->buffers.size() || v.byte_offset > d->buffers[size_t(v.buffer)].size ||
        v.byte_length > d->buffers[size_t(v.buffer)].size - v.byte_offset)
        return sy_error_set(err, SY_ERR_PARSE, "bufferView %d lies outside its buffer", (int)view);
    if (pr.mode != 4) return sy_error_set(err, SY_ERR_UNSUPPORTED, "mode %d (only triangles are read)", (int)pr.mode);
    if (pr.indices < 0 || size_t(pr.indices) >= d->accessors.size())
        return sy_error_set(err, SY_ERR_PARSE, "indices accessor %d out of range", (int)pr.indices);
    const tinygltf::Value *attrs = member(ext, "attributes");
    if (!attrs || !attrs->IsObject()) return sy_error_set(err, SY_ERR_PARSE, "no attributes object");
    // the attributes the loader reads (morph targets cannot be Draco-compressed: the extension keeps
    // them in plain accessors)
    struct slot { const char *name; int32_t *acc; } slots[] = {{"POSITION", &pr.position}, {"NORMAL", &pr.normal},
        {"TANGENT", &pr.tangent}, {"TEXCOORD_0", &pr.texcoord0}, {"TEXCOORD_1", &pr.texcoord1}, {"COLOR_0", &pr.color0},
        {"JOINTS_0", &pr.joints0}, {"WEIGHTS_0", &pr.weights0}, {"JOINTS_1", &pr.joints1}, {"WEIGHTS_1", &pr.weights1}};
    std::vector<sy_gltf_draco_attr> req_attrs;
    std::vector<int32_t *> req_acc;
    size_t vertices = 0;
    uint64_t need = 0;
    for (const slot &s : slots) {
        if (*s.acc < 0 || !member(*attrs, s.name)) continue;
        if (size_t(*s.acc) >= d->accessors.size())
            return sy_error_set(err, SY_ERR_PARSE, "attribute %s: accessor %d out of range", s.name, (int)*s.acc);
        const sy_gltf_shim_accessor &a = d->accessors[size_t(*s.acc)];
        if (a.components < 1 || a.components > 4 || a.is_matrix)
            return sy_error_set(err, SY_ERR_PARSE, "attribute %s: accessor type is not SCALAR or VEC2..4", s.name);
        if (req_attrs.empty()) vertices = a.count;
        if (a.count != vertices)
            return sy_error_set(err, SY_ERR_PARSE, "attribute %s: accessor count %zu differs from %zu", s.name, a.count, vertices);
        int32_t id = integer(*attrs, s.name, -1);
        req_attrs.push_back({s.name, id, uint32_t(a.components), nullptr});
        req_acc.push_back(s.acc);
        need += uint64_t(a.count) * uint64_t(a.components) * 4u;
    }
    if (req_attrs.empty()) return sy_error_set(err, SY_ERR_PARSE, "no POSITION attribute in the extension");
    const size_t indices = d->accessors[size_t(pr.indices)].count;
    need += uint64_t(indices) * 4u;
    if (vertices > UINT32_MAX || indices > (size_t(1) << 40) || (max_bytes && need > max_bytes - std::min(*bytes_used, max_bytes)))
        return sy_error_set(err, SY_ERR_LIMIT, "%zu vertices and %zu indices (%llu MiB decoded) exceed what is left of the scene budget",
                            vertices, indices, (unsigned long long)(need >> 20));
    *bytes_used += need;
    d->decoded.emplace_back(size_t(need));
    std::vector<uint8_t> &out = d->decoded.back();
    uint8_t *base = out.data();
    size_t off = indices * 4;
    for (sy_gltf_draco_attr &a : req_attrs) {
        a.out = reinterpret_cast<float *>(base + off);
        off += vertices * a.components * 4;
    }
    sy_gltf_draco_request req = {vertices, indices, reinterpret_cast<uint32_t *>(base), req_attrs.data(), req_attrs.size()};
    sy_result r = sy_gltf_draco_decode(data_at(d, v), v.byte_length, &req, err);
    if (r != SY_OK) return r;
    // the new buffer, its views and the accessors that read them
    const int32_t buffer = int32_t(d->buffers.size());
    d->buffers.push_back({base, out.size()});
    auto point = [&](int32_t *acc, size_t at, size_t len, int32_t ctype) {
        sy_gltf_shim_accessor a = d->accessors[size_t(*acc)];
        d->views.push_back({buffer, at, len, 0});
        a.buffer_view = int32_t(d->views.size() - 1);
        a.byte_offset = 0;
        a.component_type = ctype;
        a.normalized = 0;
        a.sparse = 0;
        if ((*rewritten)[size_t(*acc)]) { // shared with another Draco primitive: a copy for this one
            d->accessors.push_back(a);
            rewritten->push_back(true);
            *acc = int32_t(d->accessors.size() - 1);
        } else {
            d->accessors[size_t(*acc)] = a;
            (*rewritten)[size_t(*acc)] = true;
        }
    };
    point(&pr.indices, 0, indices * 4, 5125);
    off = indices * 4;
    for (size_t k = 0; k < req_attrs.size(); k++) {
        const size_t n = vertices * req_attrs[k].components;
        if (std::strncmp(req_attrs[k].name, "JOINTS_", 7) == 0) { // joint indices as unsigned shorts, in place
            const float *f = req_attrs[k].out;
            uint16_t *u = reinterpret_cast<uint16_t *>(base + off); // u[i] overwrites only floats before f[i]
            for (size_t i = 0; i < n; i++) {
                const float j = f[i];
                if (!(j >= 0.0f && j <= 65535.0f) || j != std::floor(j))
                    return sy_error_set(err, SY_ERR_PARSE, "attribute %s: vertex %zu: joint index %g is not a whole number in 0..65535",
                                        req_attrs[k].name, i / req_attrs[k].components, double(j));
                u[i] = uint16_t(j);
            }
            point(req_acc[k], off, n * 2, 5123);
        } else {
            point(req_acc[k], off, n * 4, 5126);
        }
        off += n * 4;
    }
    return SY_OK;
}

// >>EXT_meshopt_compression: each compressed bufferView is decoded (sy_gltf_meshopt.c) into a new
// buffer and the view points at it (offset 0, its own byteStride), within max_mesh_bytes.
static sy_result meshopt_view(sy_gltf_shim_impl *d, size_t vi, const tinygltf::Value &ext, uint64_t *bytes_used,
                              uint64_t max_bytes, sy_error *err)
{
    const int32_t buf = integer(ext, "buffer", -1);
    const double off = number(ext, "byteOffset", 0), len = number(ext, "byteLength", -1);
    const double stride = number(ext, "byteStride", -1), count = number(ext, "count", -1);
    if (buf < 0 || size_t(buf) >= d->buffers.size())
        return sy_error_set(err, SY_ERR_PARSE, "buffer %d out of range (%zu buffers)", (int)buf, d->buffers.size());
    const size_t bsize = d->buffers[size_t(buf)].size;
    if (!(off >= 0 && len >= 0 && off + len <= double(bsize)) || off != std::floor(off) || len != std::floor(len))
        return sy_error_set(err, SY_ERR_PARSE, "byteOffset %g + byteLength %g exceeds buffer %d length %zu", off, len, (int)buf, bsize);
    if (!(stride >= 1 && stride <= 256 && count >= 1 && count <= 4294967295.0) || stride != std::floor(stride) ||
        count != std::floor(count))
        return sy_error_set(err, SY_ERR_PARSE, "byteStride %g / count %g not valid", stride, count);
    const tinygltf::Value *mv = member(ext, "mode"), *fv = member(ext, "filter");
    const std::string mode = mv && mv->IsString() ? mv->Get<std::string>() : "";
    const std::string filter = fv && fv->IsString() ? fv->Get<std::string>() : "NONE";
    sy_gltf_meshopt_mode m = mode == "ATTRIBUTES" ? SY_MESHOPT_ATTRIBUTES : mode == "TRIANGLES" ? SY_MESHOPT_TRIANGLES
                           : SY_MESHOPT_INDICES;
    if (mode != "ATTRIBUTES" && mode != "TRIANGLES" && mode != "INDICES")
        return sy_error_set(err, SY_ERR_PARSE, "mode '%s' is not ATTRIBUTES, TRIANGLES or INDICES", mode.c_str());
    sy_gltf_meshopt_filter f = filter == "OCTAHEDRAL" ? SY_MESHOPT_OCTAHEDRAL : filter == "QUATERNION" ? SY_MESHOPT_QUATERNION
                             : filter == "EXPONENTIAL" ? SY_MESHOPT_EXPONENTIAL : SY_MESHOPT_NONE;
    if (f == SY_MESHOPT_NONE && filter != "NONE")
        return sy_error_set(err, SY_ERR_PARSE, "filter '%s' is not NONE, OCTAHEDRAL, QUATERNION or EXPONENTIAL", filter.c_str());
    const size_t n = d->views[vi].byte_length;
    if (double(n) != stride * count)
        return sy_error_set(err, SY_ERR_PARSE, "count %g * byteStride %g is not the bufferView's byteLength %zu", count, stride, n);
    // meshoptimizer's codecs produce at most 64 bytes per byte read (a vertex block's byte column
    // of 16-vertex groups: 2 header bits per 16 zero bytes; indices: at least a byte per triangle
    // or index), so a count beyond that is refused before anything is allocated
    if (double(n) > 64.0 * len)
        return sy_error_set(err, SY_ERR_PARSE, "count %g * byteStride %g = %zu bytes cannot come from %g compressed bytes",
                            count, stride, n, len);
    if (max_bytes && n > max_bytes - std::min(*bytes_used, max_bytes))
        return sy_error_set(err, SY_ERR_LIMIT, "%zu decoded bytes exceed what is left of the scene budget", n);
    *bytes_used += n;
    d->decoded.emplace_back(n);
    std::vector<uint8_t> &out = d->decoded.back();
    sy_result r = sy_gltf_meshopt_decode(d->buffers[size_t(buf)].data + size_t(off), size_t(len), size_t(count),
                                         size_t(stride), m, f, out.data(), n, err);
    if (r != SY_OK) return r;
    d->buffers.push_back({out.data(), n});
    d->views[vi].buffer = int32_t(d->buffers.size() - 1);
    d->views[vi].byte_offset = 0;
    return SY_OK;
}

// Decodes every compressed primitive (see above); on failure err names meshes[i].primitives[j].
static sy_result decode_compressed(sy_gltf_shim_impl *d, const sy_gltf_shim_limits *limits, sy_error *err)
{
    const tinygltf::Model &m = d->model;
    std::vector<bool> rewritten(d->accessors.size(), false);
    uint64_t used = 0;
    for (size_t vi = 0; vi < m.bufferViews.size(); vi++) {
        const tinygltf::Value *e = extension(m.bufferViews[vi].extensions, "EXT_meshopt_compression");
        if (!e) continue;
        sy_result r = e->IsObject() ? meshopt_view(d, vi, *e, &used, limits->max_mesh_bytes, err)
                                    : sy_error_set(err, SY_ERR_PARSE, "not an object");
        if (r != SY_OK) {
            sy_error_prefix(err, "bufferViews[%zu]: EXT_meshopt_compression", vi);
            return r;
        }
    }
    for (size_t mi = 0; mi < m.meshes.size(); mi++)
        for (size_t pj = 0; pj < m.meshes[mi].primitives.size(); pj++) {
            const tinygltf::Value *e = extension(m.meshes[mi].primitives[pj].extensions, "KHR_draco_mesh_compression");
            if (!e) continue;
            sy_result r = e->IsObject() ? draco_primitive(d, mi, pj, *e, &rewritten, &used, limits->max_mesh_bytes, err)
                                        : sy_error_set(err, SY_ERR_PARSE, "not an object");
            if (r != SY_OK) {
                sy_error_prefix(err, "meshes[%zu].primitives[%zu]: KHR_draco_mesh_compression", mi, pj);
                return r;
            }
        }
    sy_gltf_doc &c = d->doc; // the vectors may have grown
    expose(d->buffers, c.buffers, c.buffer_count);
    expose(d->views, c.views, c.view_count);
    expose(d->accessors, c.accessors, c.accessor_count);
    return SY_OK;
}

// The document's JSON (a discarded value when it does not parse: tinygltf then says why). For GLB
// the JSON chunk is read within the container the caller validated (header 12 bytes, chunk length
// and type 8).
static nlohmann::json json_of(const uint8_t *bytes, size_t size, bool binary)
{
    const uint8_t *json_begin = bytes;
    size_t json_size = size;
    if (binary) {
        if (size < 20) return nlohmann::json::value_t::discarded;
        uint32_t len = uint32_t(bytes[12]) | uint32_t(bytes[13]) << 8 | uint32_t(bytes[14]) << 16 | uint32_t(bytes[15]) << 24;
        if (len > size - 20) return nlohmann::json::value_t::discarded;
        json_begin = bytes + 20;
        json_size = len;
    }
    return nlohmann::json::parse(json_begin, json_begin + json_size, nullptr, false);
}

// tinygltf reads every index into an int: a larger number wraps ("mesh": 2^40 became mesh 0). The
// first index property (glTF 2.0's names) that is not an integer in [0, 2^31 - 1], with its JSON
// path in *where; false when there is none.
static bool bad_index(const nlohmann::json &j, std::string *where, const std::string &path = "")
{
    static const char *const keys[] = {"mesh", "camera", "skin", "scene", "node", "source", "sampler", "index",
                                       "bufferView", "buffer", "material", "indices", "light", "texCoord",
                                       "input", "output", "inverseBindMatrices", "skeleton", nullptr};
    static const char *const lists[] = {"children", "nodes", "joints", nullptr}; // arrays of indices
    auto is_index = [](const nlohmann::json &v) {
        if (v.is_number_unsigned()) return v.get<uint64_t>() <= uint64_t(INT32_MAX);
        if (v.is_number_integer()) return v.get<int64_t>() >= 0 && v.get<int64_t>() <= INT32_MAX;
        return !v.is_number(); // a float or another type: tinygltf's own checks refuse it
    };
    if (j.is_object()) {
        for (auto it = j.begin(); it != j.end(); ++it) {
            const std::string &k = it.key();
            std::string here = path.empty() ? k : path + "." + k;
            bool key = false, list = false;
            for (size_t i = 0; keys[i] && !key; i++) key = k == keys[i];
            for (size_t i = 0; lists[i] && !list; i++) list = k == lists[i];
            if (key && !is_index(*it)) return *where = here, true;
            if (list && it->is_array())
                for (size_t i = 0; i < it->size(); i++)
                    if ((*it)[i].is_number() && !is_index((*it)[i])) return *where = here + "[" + std::to_string(i) + "]", true;
            if (k == "attributes" && it->is_object()) // accessor indices by attribute name
                for (auto a = it->begin(); a != it->end(); ++a)
                    if (!is_index(*a)) return *where = here + "." + a.key(), true;
            if (it->is_structured() && bad_index(*it, where, here)) return true;
        }
    } else if (j.is_array()) {
        for (size_t i = 0; i < j.size(); i++)
            if (j[i].is_structured() && bad_index(j[i], where, path + "[" + std::to_string(i) + "]")) return true;
    }
    return false;
}

// The first entry of the document's extensionsRequired that is not in supported (NULL-terminated),
// or "" (also when the JSON does not parse or supported is NULL).
static std::string unsupported_required(const nlohmann::json &doc, const char *const *supported)
{
    if (!supported) return "";
    if (!doc.is_object()) return "";
    auto it = doc.find("extensionsRequired");
    if (it == doc.end() || !it->is_array()) return "";
    for (const auto &e : *it) {
        if (!e.is_string()) continue;
        const std::string &name = e.get_ref<const std::string &>();
        bool known = false;
        for (size_t k = 0; supported[k] && !known; k++) known = name == supported[k];
        if (!known) return name;
    }
    return "";
}

// What tinygltf 2.8 refuses in valid files with these extensions, patched in a copy of the JSON (GLB
// containers, validated by the caller, rebuilt around the new JSON chunk; false: nothing to do). A
// primitive whose indices accessor has no bufferView, which is how KHR_draco_mesh_compression writes
// them (the indices are in the Draco data): the accessor gets the extension's bufferView as a
// placeholder (decode_compressed replaces the accessor's view with the decoded indices).
static bool patch_for_tinygltf(const uint8_t *bytes, size_t size, bool binary, std::vector<uint8_t> *out)
{
    nlohmann::json j = json_of(bytes, size, binary);
    if (!j.is_object()) return false;
    bool changed = false;
    nlohmann::json no_meshes = nlohmann::json::array(), no_accessors = nlohmann::json::array();
    const bool lists = j.contains("meshes") && j["meshes"].is_array() && j.contains("accessors") && j["accessors"].is_array();
    nlohmann::json &acc = lists ? j["accessors"] : no_accessors;
    for (nlohmann::json &mesh : lists ? j["meshes"] : no_meshes) {
        if (!mesh.is_object() || !mesh.contains("primitives") || !mesh["primitives"].is_array()) continue;
        for (nlohmann::json &p : mesh["primitives"]) {
            if (!p.is_object() || !p.contains("indices") || !p["indices"].is_number_unsigned() || !p.contains("extensions"))
                continue;
            const nlohmann::json &ext = p["extensions"];
            if (!ext.is_object() || !ext.contains("KHR_draco_mesh_compression")) continue;
            const nlohmann::json &dr = ext["KHR_draco_mesh_compression"];
            if (!dr.is_object() || !dr.contains("bufferView") || !dr["bufferView"].is_number_unsigned()) continue;
            const uint64_t ai = p["indices"].get<uint64_t>();
            if (ai >= acc.size() || !acc[size_t(ai)].is_object() || acc[size_t(ai)].contains("bufferView")) continue;
            // an extension bufferView out of range is reported by draco_primitive, not by tinygltf
            const bool in_range = j.contains("bufferViews") && j["bufferViews"].is_array() &&
                                  dr["bufferView"].get<uint64_t>() < j["bufferViews"].size();
            acc[size_t(ai)]["bufferView"] = in_range ? dr["bufferView"] : nlohmann::json(0);
            changed = true;
        }
    }
    // EXT_meshopt_compression: a fallback buffer may have no data (no uri, not the GLB chunk), which
    // tinygltf refuses; it gets a 1-byte data: URI (the compressed views that name it are replaced by
    // their decoded data; any other view that names it fails validation as out of range)
    if (j.contains("buffers") && j["buffers"].is_array()) {
        nlohmann::json &bufs = j["buffers"];
        for (size_t i = 0; i < bufs.size(); i++) {
            nlohmann::json &b = bufs[i];
            if (!b.is_object() || b.contains("uri") || (binary && i == 0) || !b.contains("extensions")) continue;
            const nlohmann::json &ext = b["extensions"];
            if (!ext.is_object() || !ext.contains("EXT_meshopt_compression")) continue;
            b["uri"] = "data:application/octet-stream;base64,AA==";
            b["byteLength"] = 1;
            changed = true;
        }
    }
    // KHR_animation_pointer: a channel's target has no node, which tinygltf 2.7 requires (it drops
    // the channel, and the channels after it move up one index): a placeholder node 0 keeps it (the
    // shim reports its node as -1 and its pointer)
    if (j.contains("animations") && j["animations"].is_array())
        for (nlohmann::json &an : j["animations"]) {
            if (!an.is_object() || !an.contains("channels") || !an["channels"].is_array()) continue;
            for (nlohmann::json &ch : an["channels"]) {
                if (!ch.is_object() || !ch.contains("target") || !ch["target"].is_object()) continue;
                nlohmann::json &t = ch["target"];
                if (t.contains("node") || !t.contains("path") || t["path"] != "pointer") continue;
                t["node"] = 0;
                changed = true;
            }
        }
    // EXT_texture_webp: tinygltf does not take data:image/webp URIs as data URIs
    if (j.contains("images") && j["images"].is_array())
        for (nlohmann::json &im : j["images"]) {
            static const std::string webp = "data:image/webp;base64,";
            if (!im.is_object() || !im.contains("uri") || !im["uri"].is_string()) continue;
            const std::string &u = im["uri"].get_ref<const std::string &>();
            if (u.compare(0, webp.size(), webp) != 0) continue;
            im["uri"] = "data:application/octet-stream;base64," + u.substr(webp.size());
            changed = true;
        }
    if (!changed) return false;
    std::string text = j.dump();
    if (!binary) {
        out->assign(text.begin(), text.end());
        return true;
    }
    while (text.size() % 4) text.push_back(' ');
    const uint32_t old_len = uint32_t(bytes[12]) | uint32_t(bytes[13]) << 8 | uint32_t(bytes[14]) << 16 | uint32_t(bytes[15]) << 24;
    const size_t rest = size - 20 - old_len; // the chunks after the JSON chunk, as they were
    const uint64_t total = 20 + uint64_t(text.size()) + rest;
    if (total > UINT32_MAX) return false;
    auto put32 = [out](size_t at, uint32_t v) {
        for (int k = 0; k < 4; k++) (*out)[at + size_t(k)] = uint8_t(v >> (8 * k));
    };
    out->assign(size_t(total), 0);
    memcpy(out->data(), bytes, 12);
    put32(8, uint32_t(total));
    put32(12, uint32_t(text.size()));
    memcpy(out->data() + 16, bytes + 16, 4); // chunk type JSON
    memcpy(out->data() + 20, text.data(), text.size());
    if (rest) memcpy(out->data() + 20 + text.size(), bytes + 20 + old_len, rest);
    return true;
}

// Runs tinygltf on the bytes with our file-system and image callbacks (confined, size-limited).
// On success *model is filled and twarn holds tinygltf's warnings. C++ exceptions propagate to the
// caller's catch blocks; tinygltf failures are classified into a sy_result with its message.
static sy_result run_tinygltf(const uint8_t *bytes, size_t size, bool binary, const char *base_dir,
                              const sy_gltf_shim_limits *limits, tinygltf::Model *model, LoadContext *ctx,
                              std::string *twarn, sy_error *err)
{
    ctx->max_file_bytes = limits->max_file_bytes;
    ctx->max_image_pixels = limits->max_image_pixels;
    ctx->max_image_bytes = limits->max_image_bytes;
    ctx->model = model;
    ctx->roots = limits->allowed_roots;
    ctx->root_count = limits->allowed_root_count;
    std::string base = base_dir;
    if (!base.empty()) ctx->prefix = base.back() == '/' ? base : base + "/";
    tinygltf::TinyGLTF loader;
    tinygltf::FsCallbacks fs = {};
    fs.FileExists = fs_file_exists;
    fs.ExpandFilePath = fs_expand;
    fs.ReadWholeFile = fs_read;
    fs.WriteWholeFile = fs_write;
    fs.user_data = ctx;
    loader.SetFsCallbacks(fs);
    loader.SetImageLoader(load_image, ctx);
    {
        std::string where;
        if (bad_index(json_of(bytes, size, binary), &where))
            return sy_error_set(err, SY_ERR_PARSE, "%s is not an index (an integer from 0 to 2^31 - 1)", where.c_str());
    }
    { // the images EXT_texture_webp sources name: the image callback decodes WebP for those only
        nlohmann::json j = json_of(bytes, size, binary);
        if (j.is_object() && j.contains("textures") && j["textures"].is_array())
            for (const nlohmann::json &t : j["textures"]) {
                const nlohmann::json *e = t.is_object() && t.contains("extensions") ? &t["extensions"] : nullptr;
                if (!e || !e->is_object() || !e->contains("EXT_texture_webp")) continue;
                const nlohmann::json &w = (*e)["EXT_texture_webp"];
                if (w.is_object() && w.contains("source") && w["source"].is_number_unsigned() &&
                    w["source"].get<uint64_t>() <= uint64_t(INT32_MAX))
                    ctx->webp_images.insert(int(w["source"].get<uint64_t>()));
            }
    }
    std::vector<uint8_t> patched;
    if (patch_for_tinygltf(bytes, size, binary, &patched)) {
        bytes = patched.data();
        size = patched.size();
    }
    std::string terr;
    bool ok = binary ? loader.LoadBinaryFromMemory(model, &terr, twarn, bytes, unsigned(size), base)
                     : loader.LoadASCIIFromString(model, &terr, twarn, reinterpret_cast<const char *>(bytes),
                                                  unsigned(size), base);
    // a refused file fails the load, also where tinygltf would go on without it (an image)
    if (!ctx->refused.empty()) return sy_error_set(err, SY_ERR_LIMIT, "%s", ctx->refused.c_str());
    if (ok) return SY_OK;
    std::string ext = unsupported_required(json_of(bytes, size, binary), limits->supported_extensions);
    if (!ext.empty())
        return sy_error_set(err, SY_ERR_UNSUPPORTED, "extensionsRequired: '%s' is not supported (tinygltf: %s)",
                            ext.c_str(), one_line(terr).c_str());
    sy_result code = SY_ERR_PARSE;
    if (ctx->fs_result != SY_OK) code = ctx->fs_result;
    else if (terr.find("File not found") != std::string::npos) code = SY_ERR_NOT_FOUND;
    else if (terr.find("exceeds the limit") != std::string::npos) code = SY_ERR_LIMIT;
    std::string msg = one_line(terr);
    if (msg.empty()) msg = "tinygltf failed without a message";
    // an extension the file requires explains most failures of valid files (a meshopt mesh's
    // buffer has no data): name it (sy_gltf_validate.c refuses the unsupported ones by name when the
    // parse gets that far)
    for (const std::string &e : model->extensionsRequired)
        if (e.rfind("EXT_meshopt", 0) == 0)
            return sy_error_set(err, SY_ERR_UNSUPPORTED, "extensionsRequired: '%s' is not supported (%s)", e.c_str(),
                                msg.c_str());
    return sy_error_set(err, code, "%s", msg.c_str());
}

extern "C" sy_result sy_gltf_shim_parse(const uint8_t *bytes, size_t size, bool binary, const char *base_dir,
                                        const sy_gltf_shim_limits *limits, sy_gltf_doc **out, sy_error *err)
{
    if (out) *out = nullptr;
    if (!bytes || !out || !limits || !base_dir) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "invalid argument");
    if (size > UINT_MAX) return sy_error_set(err, SY_ERR_LIMIT, "file larger than 4 GiB");
    sy_gltf_shim_impl *d = nullptr;
    try {
        d = new sy_gltf_shim_impl();
        LoadContext ctx;
        std::string twarn;
        sy_result r = run_tinygltf(bytes, size, binary, base_dir, limits, &d->model, &ctx, &twarn, err);
        if (r != SY_OK) {
            delete d;
            return r;
        }
        d->warnings = one_line(twarn);
        d->image_problems = std::move(ctx.image_problems);
        fill_doc(d);
        if ((r = decode_compressed(d, limits, err)) != SY_OK) {
            delete d;
            return r;
        }
        *out = &d->doc;
        return SY_OK;
    } catch (...) {
        delete d;
        return sy_error_from_exception(err, SY_ERR_PARSE, "out of memory while parsing glTF", "",
                                       "unknown exception while parsing glTF");
    }
}

extern "C" void sy_gltf_shim_free(sy_gltf_doc *doc)
{
    if (doc) delete static_cast<sy_gltf_shim_impl *>(doc->internal);
}

extern "C" sy_result sy_gltf_shim_parse_only(const uint8_t *bytes, size_t size, bool binary, const char *base_dir,
                                             const sy_gltf_shim_limits *limits, sy_error *err)
{
    if (!bytes || !limits || !base_dir) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "invalid argument");
    if (size > UINT_MAX) return sy_error_set(err, SY_ERR_LIMIT, "file larger than 4 GiB");
    try {
        tinygltf::Model model;
        LoadContext ctx;
        std::string twarn;
        sy_result r = run_tinygltf(bytes, size, binary, base_dir, limits, &model, &ctx, &twarn, err);
        if (r != SY_OK) return r;
        return SY_OK;
    } catch (...) {
        return sy_error_from_exception(err, SY_ERR_PARSE, "out of memory while parsing glTF", "",
                                       "unknown exception while parsing glTF");
    }
}
