// test_gltf_counts.cpp — `sy info` counts of EVERY glTF / GLB file under TESTDATA/gltf checked against
// values computed independently from the file's JSON with nlohmann::json (no tinygltf involved):
// nodes, meshes, primitives, triangles (per mode: lists count / 3, strips and fans count - 2),
// skipped primitives (no POSITION or no complete element), points and line segments (LINES
// pairs, LINE_LOOP n, LINE_STRIP n - 1), materials, textures, images, cameras and
// KHR_lights_punctual lights; and, in the loaded scene, the triangle total, normals on every
// primitive (generated flat when the file has none) and tangents wherever a material with a
// normal map is used with texture coordinates. C++ only because nlohmann::json is; the code under
// test is the C loader. Usage: test_gltf_counts TESTDATA_DIR (exit 77 when the data is absent).
#include "sy_gltf.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using nlohmann::json;

static int g_failures = 0, g_checks = 0, g_refused = 0;

#define CHECK_EQ(what, got, want)                                                                                      \
    do {                                                                                                               \
        g_checks++;                                                                                                    \
        if ((uint64_t)(got) != (uint64_t)(want)) {                                                                     \
            g_failures++;                                                                                              \
            std::fprintf(stderr, "FAIL %s: %s = %llu, expected %llu\n", file.c_str(), what,                           \
                         (unsigned long long)(got), (unsigned long long)(want));                                       \
        }                                                                                                              \
    } while (0)

struct expected {
    uint64_t nodes = 0, meshes = 0, primitives = 0, triangles = 0, skipped = 0, materials = 0, textures = 0,
             images = 0, cameras = 0, lights = 0, points = 0, segments = 0;
};

static bool read_json(const std::string &file, json &doc)
{
    std::ifstream in(file, std::ios::binary);
    std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::string text;
    if (bytes.size() >= 20 && std::memcmp(bytes.data(), "glTF", 4) == 0) { // GLB: first chunk is JSON
        auto u32 = [&](size_t o) {
            return uint32_t(bytes[o]) | uint32_t(bytes[o + 1]) << 8 | uint32_t(bytes[o + 2]) << 16 |
                   uint32_t(bytes[o + 3]) << 24;
        };
        uint32_t len = u32(12);
        if (u32(16) != 0x4E4F534Au || 20ull + len > bytes.size()) return false;
        text.assign(reinterpret_cast<const char *>(bytes.data()) + 20, len);
    } else {
        text.assign(bytes.begin(), bytes.end());
    }
    doc = json::parse(text, nullptr, false);
    return !doc.is_discarded();
}

static size_t arr(const json &d, const char *k) { return d.contains(k) && d[k].is_array() ? d[k].size() : 0; }

static expected compute(const json &d)
{
    expected e;
    e.nodes = arr(d, "nodes");
    e.meshes = arr(d, "meshes");
    e.materials = arr(d, "materials");
    e.textures = arr(d, "textures");
    e.images = arr(d, "images");
    e.cameras = arr(d, "cameras");
    if (d.contains("extensions") && d["extensions"].contains("KHR_lights_punctual"))
        e.lights = arr(d["extensions"]["KHR_lights_punctual"], "lights");
    const json &acc = d.contains("accessors") ? d["accessors"] : json::array();
    for (const auto &m : d.value("meshes", json::array())) {
        for (const auto &p : m.value("primitives", json::array())) {
            e.primitives++;
            int mode = p.value("mode", 4);
            const json &attrs = p["attributes"];
            if (!attrs.contains("POSITION")) {
                e.skipped++;
                continue;
            }
            uint64_t count = acc[attrs["POSITION"].get<size_t>()]["count"].get<uint64_t>();
            if (p.contains("indices")) count = acc[p["indices"].get<size_t>()]["count"].get<uint64_t>();
            if (mode < 4) { // points; lines: pairs, loops: n (n >= 3), strips: n - 1
                uint64_t el = mode == 0 ? count : mode == 1 ? count / 2 : count < 2 ? 0 : mode == 2 && count >= 3 ? count : count - 1;
                if (el == 0) e.skipped++;
                (mode == 0 ? e.points : e.segments) += el;
                continue;
            }
            uint64_t t = mode == 4 ? count / 3 : (count >= 3 ? count - 2 : 0);
            if (t == 0) e.skipped++;
            e.triangles += t;
        }
    }
    return e;
}

static void check_file(const std::string &file, uint32_t *models)
{
    json doc;
    g_checks++;
    if (!read_json(file, doc)) {
        g_failures++;
        std::fprintf(stderr, "FAIL %s: the test's own JSON parse failed\n", file.c_str());
        return;
    }
    expected e = compute(doc);
    sy_scene *scene = nullptr;
    sy_error err{};
    if (sy_scene_create(&scene, &err) != SY_OK) {
        std::fprintf(stderr, "scene: %s\n", err.message);
        std::exit(1);
    }
    sy_gltf_info info{};
    // images are refused before decoding (they become missing textures with a warning): counts do
    // not depend on pixels, and decoding every texture would make this test slow under ASan
    sy_gltf_options opts{};
    opts.max_image_pixels = 1;
    sy_result r = sy_gltf_load(file.c_str(), scene, &opts, &info, &err);
    g_checks++;
    // A file that requires an extension sy does not read must be refused with SY_ERR_UNSUPPORTED
    // naming it (read independently here from the JSON), and only such a file may be refused.
    std::string unsupported;
    if (doc.contains("extensionsRequired") && doc["extensionsRequired"].is_array())
        for (const auto &x : doc["extensionsRequired"]) {
            if (!x.is_string() || !unsupported.empty()) continue;
            bool known = false;
            for (const char *const *k = sy_gltf_supported_extensions(); *k && !known; ++k) known = x.get<std::string>() == *k;
            if (!known) unsupported = x.get<std::string>();
        }
    if (!unsupported.empty()) {
        g_refused++;
        if (r != SY_ERR_UNSUPPORTED || !std::strstr(err.message, ("'" + unsupported + "'").c_str())) {
            g_failures++;
            std::fprintf(stderr, "FAIL %s: requires %s: want SY_ERR_UNSUPPORTED naming it, got %s: %s\n",
                         file.c_str(), unsupported.c_str(), sy_result_str(r), r ? err.message : "loaded");
        } else {
            std::printf("refused as it should be (requires %s, not read by sy): %s\n", unsupported.c_str(), file.c_str());
        }
    } else if (r != SY_OK) {
        g_failures++;
        std::fprintf(stderr, "FAIL %s: load failed: %s\n", file.c_str(), err.message);
    } else {
        (*models)++;
        const sy_gltf_counts &c = info.counts;
        CHECK_EQ("nodes", c.nodes, e.nodes);
        CHECK_EQ("meshes", c.meshes, e.meshes);
        CHECK_EQ("primitives", c.primitives, e.primitives);
        CHECK_EQ("triangles", c.triangles, e.triangles);
        CHECK_EQ("skipped_primitives", c.skipped_primitives, e.skipped);
        CHECK_EQ("points", c.points, e.points);
        CHECK_EQ("line_segments", c.line_segments, e.segments);
        CHECK_EQ("materials", c.materials, e.materials);
        CHECK_EQ("textures", c.textures, e.textures);
        CHECK_EQ("images", c.images, e.images);
        CHECK_EQ("cameras", c.cameras, e.cameras);
        CHECK_EQ("lights", c.lights, e.lights);
        // the scene itself: every mesh is created, whether referenced or not
        uint64_t tris = 0, prims = 0, without_normals = 0, missing_tangents = 0;
        for (uint32_t id = sy_scene_next(scene, SY_TYPE_MESH, 0); id; id = sy_scene_next(scene, SY_TYPE_MESH, id)) {
            auto *m = static_cast<const sy_mesh_data *>(sy_object_get(scene, SY_TYPE_MESH, id));
            for (uint32_t k = 0; k < m->primitives.count; k++) {
                const sy_primitive &p = m->primitives.items[k];
                prims++;
                tris += sy_primitive_triangle_count(&p);
                if (!p.normals && p.topology == SY_TOPOLOGY_TRIANGLES) without_normals++; // strokes: own normals
                const sy_material_data *md = sy_material_get(scene, p.material);
                if (md && md->normal_texture.texture.id && !p.tangents &&
                    (md->normal_texture.texcoord ? p.texcoords1 : p.texcoords0))
                    missing_tangents++;
            }
        }
        CHECK_EQ("scene triangles", tris, e.triangles);
        CHECK_EQ("scene primitives", prims, e.primitives - e.skipped);
        CHECK_EQ("primitives without normals", without_normals, 0);
        CHECK_EQ("normal-mapped primitives without tangents", missing_tangents, 0);
    }
    sy_gltf_info_free(&info);
    sy_scene_destroy(scene);
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        std::fprintf(stderr, "usage: test_gltf_counts TESTDATA_DIR\n");
        return 2;
    }
    fs::path root = fs::path(argv[1]) / "gltf";
    std::error_code ec;
    if (!fs::is_directory(root, ec)) {
        std::printf("SKIP: %s not found (shared test data absent)\n", root.c_str());
        return 77;
    }
    std::vector<std::string> files;
    for (auto it = fs::recursive_directory_iterator(root, ec); it != fs::recursive_directory_iterator(); ++it) {
        std::string ext = it->path().extension().string();
        if (it->is_regular_file() && (ext == ".gltf" || ext == ".glb")) files.push_back(it->path().string());
    }
    std::sort(files.begin(), files.end());
    uint32_t models = 0;
    for (const auto &f : files) check_file(f, &models);
    std::printf("%zu files, %u loaded, %d refused for an unsupported required extension, %d checks, %d failures\n",
                files.size(), models, g_refused, g_checks, g_failures);
    if (files.size() < 30) {
        std::fprintf(stderr, "FAIL: only %zu glTF files found under %s\n", files.size(), root.c_str());
        return 1;
    }
    return g_failures ? 1 : 0;
}
