/* test_assimp.c — the Assimp loader (formats/sy_assimp.h) on small files the test writes itself:
 * an OBJ + MTL with a texture (counts, bounds, the classic material's conversion, the texture),
 * ASCII and binary STL (a binary header starting with "solid"), a PLY with vertex colours, one
 * from memory; and bad input: a truncated binary STL, a binary STL whose facet count wraps Assimp's
 * 32-bit size check, a PLY declaring 10^12 vertices in a few bytes, a PLY without end_header (Assimp
 * hangs on it), a PLY declaring an element twice and one with
 * faces of no index (Assimp aborts on both), an ASCII FBX whose embedded base64 Assimp frees twice, a
 * COLLADA index list holding a word (Assimp never returns), an OBJ whose MTL and texture
 * lie outside its folder (refused, then admitted by allowed_roots), a file Assimp cannot read.
 * Every error names the file. Also: an MTL in a subfolder naming its texture relative to itself
 * (found; one leading out of the model's folder refused), separate metalness / roughness maps
 * combined into one metallic-roughness texture (same size, resampled, one map, a missing map), a
 * valid triangle under Assimp's default degenerate-area threshold (kept). Animations (issue 35): a
 * DirectX .x file with three clips, one whose position keys go back in time, one with a key beyond
 * the coordinate range, one channel naming no node: each dropped with a warning naming the
 * animation, the channel and the key, the file still loads, and the good channel plays (the node's
 * matrix turned into TRS; 25 ticks per second). Skins: a .x mesh whose vertex has 10 bone weights keeps
 * the 8 largest, renormalised, with a warning; its node's skin has the 10 bones' nodes as joints. */
#include "sy_anim.h"
#include "sy_assimp.h"
#include "sy_classic.h"
#include "sy_scene.h"

#include "../formats/test_util.h"
#include "assimp_quad.h"

#include <math.h>
#include <stdlib.h>

static sy_scene *g_scene;

static sy_result load(const char *path, const sy_assimp_options *o, sy_assimp_info *info, sy_error *e)
{
    sy_scene_destroy(g_scene);
    g_scene = NULL;
    if (sy_scene_create(&g_scene, e) != SY_OK) return SY_ERR_OUT_OF_MEMORY;
    return sy_assimp_load(path, g_scene, o, info, e);
}

static sy_bounds bounds_of(const sy_assimp_info *info)
{
    sy_bounds b = sy_bounds_empty();
    sy_scene_commit(g_scene, NULL, NULL);
    sy_node_world_bounds(g_scene, info->root, &b, NULL);
    return b;
}

static bool near(float a, float b) { return fabsf(a - b) < 1e-4f; }

/* Writes dir/rel (n bytes), making the folders of rel first; the full path into path. */
static int put_file(const char *dir, const char *rel, const void *data, size_t n, char *path, size_t cap)
{
    snprintf(path, cap, "%s/%s", dir, rel);
    for (char *c = path + strlen(dir) + 1; (c = strchr(c, '/')) != NULL; ++c) {
        *c = '\0';
        mkdir(path, 0755);
        *c = '/';
    }
    return write_bytes(path, data, n);
}

/* Writes dir/name (n bytes) and loads it: refused with code, the message naming the file and
 * saying says. */
static void expect_refused(const char *dir, const char *name, const void *data, size_t n, sy_result code, const char *says)
{
    char path[4300];
    sy_assimp_info info = {0};
    sy_error e = {0};
    PATHF(path, "%s/%s", dir, name);
    EXPECT(write_bytes(path, data, n) == 0);
    EXPECT_MSG(load(path, NULL, &info, &e) == code && strstr(e.message, name) && strstr(e.message, says), "%s: %s", name,
               e.message);
}

static const sy_mesh_data *first_mesh(void)
{
    uint32_t id = sy_scene_next(g_scene, SY_TYPE_MESH, 0);
    return id ? sy_object_get(g_scene, SY_TYPE_MESH, id) : NULL;
}

int main(void)
{
    char dir[4096], p[4300], q[4300];
    make_scratch_dir(dir, sizeof dir, "assimp");
    sy_assimp_info info = {0};
    sy_error e = {0};

    /* OBJ + MTL + a 2x1 PPM texture: a quad (two triangles) of 2 x 1 with material "red" */
    PATHF(q, "%s/model", dir);
    mkdir(q, 0755);
    write_assimp_quad(q, "newmtl red\nKd 0.5 0.25 0.125\nKs 1 1 1\nNs 128\nillum 2\nd 0.5\nKe 0 0 0\nmap_Kd tex.ppm\n", p,
                      sizeof p);
    EXPECT_MSG(load(p, NULL, &info, &e) == SY_OK, "quad.obj: %s", e.message);
    EXPECT_MSG(info.counts.meshes == 1 && info.counts.triangles == 2 && info.counts.materials >= 1 &&
                   info.counts.textures == 1 && info.warning_count == 0,
               "quad.obj counts: %u meshes, %u triangles, %u materials, %u textures, %u warnings", info.counts.meshes,
               info.counts.triangles, info.counts.materials, info.counts.textures, info.warning_count);
    sy_bounds b = bounds_of(&info);
    EXPECT_MSG(near(b.min[0], 0) && near(b.min[1], 0) && near(b.max[0], 2) && near(b.max[1], 1) && near(b.max[2], 0),
               "quad.obj bounds %g %g %g - %g %g %g", b.min[0], b.min[1], b.min[2], b.max[0], b.max[1], b.max[2]);
    const sy_mesh_data *md = first_mesh();
    EXPECT(md && md->primitives.count == 1 && md->primitives.items[0].normals && md->primitives.items[0].texcoords0);
    const sy_material_data *mat = md ? sy_material_get(g_scene, md->primitives.items[0].material) : NULL;
    EXPECT_MSG(mat && near(mat->base_color[0], 0.5f) && near(mat->base_color[1], 0.25f) && near(mat->base_color[2], 0.125f) &&
                   near(mat->base_color[3], 0.5f) && mat->alpha_mode == SY_ALPHA_BLEND && mat->metallic == 0.0f &&
                   near(mat->roughness, sqrtf(sqrtf(2.0f / 130.0f))) && near(mat->roughness, 0.3522f),
               "red: base %g %g %g %g, metallic %g, roughness %g", mat ? mat->base_color[0] : -1, mat ? mat->base_color[1] : -1,
               mat ? mat->base_color[2] : -1, mat ? mat->base_color[3] : -1, mat ? mat->metallic : -1, mat ? mat->roughness : -1);
    const sy_texture_data *tex = mat ? sy_object_get(g_scene, SY_TYPE_TEXTURE, mat->base_color_texture.texture.id) : NULL;
    EXPECT_MSG(tex && tex->info.width == 2 && tex->info.height == 1 && tex->info.channels == 3 &&
                   tex->info.format == SY_PIXEL_U8_SRGB,
               "the base colour texture");
    EXPECT(near(sy_classic_roughness(0, 1), 1.0f) && near(sy_classic_roughness(1000, 1), 0.2114f) &&
           sy_classic_roughness(128, 0) == 1.0f);
    sy_assimp_info_free(&info);

    /* ASCII STL: one facet */
    PATHF(p, "%s/tri.stl", dir);
    const char astl[] = "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 3 0\nendloop\n"
                        "endfacet\nendsolid t\n";
    EXPECT(write_bytes(p, astl, sizeof astl - 1) == 0);
    EXPECT_MSG(load(p, NULL, &info, &e) == SY_OK && info.counts.triangles == 1 && info.counts.meshes == 1, "tri.stl: %s", e.message);
    b = bounds_of(&info);
    EXPECT_MSG(near(b.max[0], 1) && near(b.max[1], 3), "tri.stl bounds");
    sy_assimp_info_free(&info);

    /* binary STL: 2 facets, header starting with "solid" (some exporters write that) */
    unsigned char bstl[84 + 100] = "solid written by a binary exporter";
    bstl[80] = 2;
    float tris[2][12] = {{0, 0, 1, 0, 0, 0, 4, 0, 0, 0, 2, 0}, {0, 0, 1, 4, 0, 0, 4, 2, 0, 0, 2, 0}};
    for (int f = 0; f < 2; ++f) memcpy(bstl + 84 + 50 * f, tris[f], 48);
    PATHF(p, "%s/two.stl", dir);
    EXPECT(write_bytes(p, bstl, sizeof bstl) == 0);
    EXPECT_MSG(load(p, NULL, &info, &e) == SY_OK && info.counts.triangles == 2, "two.stl: %s (%u triangles)", e.message,
               info.counts.triangles);
    b = bounds_of(&info);
    EXPECT_MSG(near(b.max[0], 4) && near(b.max[1], 2) && near(b.min[0], 0), "two.stl bounds");
    sy_assimp_info_free(&info);
    /* the same from memory, under a name without extension: the content decides */
    sy_scene *ms = NULL;
    EXPECT(sy_scene_create(&ms, &e) == SY_OK);
    EXPECT_MSG(sy_assimp_load_memory(bstl, sizeof bstl, "noext", dir, ms, NULL, &info, &e) == SY_OK && info.counts.triangles == 2,
               "binary STL from memory: %s", e.message);
    sy_assimp_info_free(&info);
    sy_scene_destroy(ms);

    /* truncated binary STL: 2 facets declared, 1 present */
    PATHF(p, "%s/cut.stl", dir);
    EXPECT(write_bytes(p, bstl, sizeof bstl - 50) == 0);
    EXPECT_MSG(load(p, NULL, &info, &e) != SY_OK && strstr(e.message, "cut.stl"), "truncated STL: %s", e.message);
    /* a facet count whose 32-bit size wraps to the file's 88 bytes: 85899346 facets */
    unsigned char wrap[88] = {0};
    uint32_t facets = 85899346u;
    memcpy(wrap + 80, &facets, 4);
    expect_refused(dir, "wrap.stl", wrap, sizeof wrap, SY_ERR_PARSE, "85899346 facets");

    /* PLY: 4 coloured vertices, one quad face */
    PATHF(p, "%s/quad.ply", dir);
    const char ply[] = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                       "property uchar red\nproperty uchar green\nproperty uchar blue\nelement face 1\n"
                       "property list uchar int vertex_indices\nend_header\n0 0 0 255 0 0\n1 0 0 0 255 0\n1 0 5 0 0 255\n"
                       "0 0 5 255 255 255\n4 0 1 2 3\n";
    EXPECT(write_bytes(p, ply, sizeof ply - 1) == 0);
    EXPECT_MSG(load(p, NULL, &info, &e) == SY_OK && info.counts.triangles == 2, "quad.ply: %s", e.message);
    md = first_mesh();
    EXPECT_MSG(md && md->primitives.items[0].colors && sy_primitive_vertex_count(&md->primitives.items[0]) == 4,
               "quad.ply: colours and 4 vertices");
    b = bounds_of(&info);
    EXPECT_MSG(near(b.max[0], 1) && near(b.max[2], 5), "quad.ply bounds");
    sy_assimp_info_free(&info);
    /* PLY declaring 10^12 vertices in a few bytes: refused before Assimp allocates */
    const char huge[] = "ply\nformat binary_little_endian 1.0\nelement vertex 1000000000000\nproperty float x\n"
                        "property float y\nproperty float z\nend_header\n\x00\x00\x00\x00";
    expect_refused(dir, "huge.ply", huge, sizeof huge - 1, SY_ERR_PARSE, "1000000000000");
    PATHF(p, "%s/huge.ply", dir);
    /* the same behind a magic that is not alone on its line ("PLY" and more: Assimp still reads it as PLY) */
    char huge2[sizeof huge + 8];
    memcpy(huge2, "PLY[[[[[", 8);
    memcpy(huge2 + 8, huge + 3, sizeof huge - 3);
    EXPECT(write_bytes(p, huge2, sizeof huge2 - 1) == 0);
    EXPECT_MSG(load(p, NULL, &info, &e) == SY_ERR_PARSE && strstr(e.message, "1000000000000"), "huge.ply behind 'PLY[[[[[': %s",
               e.message);

    /* a PLY declaring one element twice (Assimp 5.2 fails an assertion in Triangulate on such a file
     * and aborts the process): refused first */
    const char twice[] = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nelement vertex 3\n"
                         "property float x\nproperty float y\nproperty float z\nelement face 1\n"
                         "property list uchar int vertex_indices\nend_header\n0 0\n1 0\n0 1\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    expect_refused(dir, "twice.ply", twice, sizeof twice - 1, SY_ERR_PARSE, "'vertex' twice");

    /* PLY faces of count 0: Assimp 5.2's validation lets them through and Triangulate fails an
     * assertion on them (abort); refused after reading, before post-processing */
    const char empty_face[] = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                              "element face 2\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n0\n0\n";
    expect_refused(dir, "empty_face.ply", empty_face, sizeof empty_face - 1, SY_ERR_PARSE, "without vertex indices");

    /* a PLY header whose end_header is broken (Assimp 5.2 loops for ever on it): refused first */
    const char noend[] = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                         "element face 1\nproperty list uchar int vertex_index\nend_he<x>ader\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    expect_refused(dir, "noend.ply", noend, sizeof noend - 1, SY_ERR_PARSE, "end_header");

    /* an ASCII FBX embedding 201 base64 characters ending in '=': Assimp 5.2 sizes the buffer for
     * 149 bytes, decodes 150, frees it and frees it again (ASan: double free); refused first */
    PATHF(p, "%s/video.fbx", dir);
    char fbx[1024], b64[202];
    for (int k = 0; k < 200; ++k) b64[k] = "QUFB"[k % 4];
    b64[200] = '=', b64[201] = '\0';
    int fl = snprintf(fbx, sizeof fbx,
                      "; FBX 7.5.0 project file\nFBXHeaderExtension:  {\n\tFBXHeaderVersion: 1003\n\tFBXVersion: 7500\n}\n"
                      "Objects:  {\n\tVideo: 1, \"Video::v\", \"Clip\" {\n\t\tType: \"Clip\"\n\t\tContent: , \"%s\"\n\t}\n"
                      "\tTexture: 2, \"Texture::t\", \"\" {\n\t\tType: \"TextureVideoClip\"\n\t}\n}\n"
                      "Connections:  {\n\tC: \"OO\",1,2\n}\n",
                      b64);
    EXPECT(fl > 0 && write_bytes(p, fbx, (size_t)fl) == 0);
    EXPECT_MSG(load(p, NULL, &info, &e) == SY_ERR_PARSE && strstr(e.message, "video.fbx") && strstr(e.message, "base64"),
               "video.fbx: %s", e.message);

    /* a COLLADA index list holding a word: Assimp 5.2 never returns from it; refused first */
    const char dae[] =
        "<?xml version=\"1.0\"?>\n<COLLADA xmlns=\"http://www.collada.org/2005/11/COLLADASchema\" version=\"1.4.1\">"
        "<library_geometries><geometry id=\"g\"><mesh><source id=\"pos\"><float_array id=\"pa\" count=\"9\">0 0 0 1 0 0 0 1 0"
        "</float_array><technique_common><accessor source=\"#pa\" count=\"3\" stride=\"3\"><param name=\"X\" type=\"float\"/>"
        "<param name=\"Y\" type=\"float\"/><param name=\"Z\" type=\"float\"/></accessor></technique_common></source>"
        "<vertices id=\"v\"><input semantic=\"POSITION\" source=\"#pos\"/></vertices><triangles count=\"1\">"
        "<input semantic=\"VERTEX\" source=\"#v\" offset=\"0\"/><p>0 1 word 2</p></triangles></mesh></geometry>"
        "</library_geometries><library_visual_scenes><visual_scene id=\"s\"><node id=\"n\"><instance_geometry url=\"#g\"/>"
        "</node></visual_scene></library_visual_scenes><scene><instance_visual_scene url=\"#s\"/></scene></COLLADA>\n";
    expect_refused(dir, "word.dae", dae, sizeof dae - 1, SY_ERR_PARSE, "<p>");
    /* the same triangle with a proper list loads */
    PATHF(p, "%s/word.dae", dir);
    char good[sizeof dae];
    memcpy(good, dae, sizeof dae);
    char *w = strstr(good, "0 1 word 2");
    memcpy(w, "0 1 2     ", 10);
    EXPECT(write_bytes(p, good, sizeof good - 1) == 0);
    EXPECT_MSG(load(p, NULL, &info, &e) == SY_OK && info.counts.triangles == 1, "word.dae repaired: %s", e.message);
    sy_assimp_info_free(&info);

    /* an OBJ whose MTL lies outside its folder: refused naming the file; admitted by allowed_roots */
    PATHF(p, "%s/model/sub", dir);
    mkdir(p, 0755);
    PATHF(p, "%s/model/sub/out.obj", dir);
    const char outobj[] = "mtllib ../quad.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n";
    EXPECT(write_bytes(p, outobj, sizeof outobj - 1) == 0);
    EXPECT_MSG(load(p, NULL, &info, &e) == SY_ERR_LIMIT && strstr(e.message, "out.obj") && strstr(e.message, "quad.mtl") &&
                   strstr(e.message, "--allow-path"),
               "MTL outside the folder: %s", e.message);
    PATHF(q, "%s/model", dir);
    const char *roots[] = {q};
    sy_assimp_options ao = {.allowed_roots = roots, .allowed_root_count = 1};
    /* the MTL is read; its texture is looked up relative to the MTL's folder (model/, allowed) */
    EXPECT_MSG(load(p, &ao, &info, &e) == SY_OK && info.counts.textures == 1 && info.warning_count == 0,
               "MTL in an allowed root: %s", info.warning_count ? info.warnings[0] : e.message);
    const sy_material_data *red = NULL;
    for (uint32_t id = sy_scene_next(g_scene, SY_TYPE_MATERIAL, 0); id; id = sy_scene_next(g_scene, SY_TYPE_MATERIAL, id)) {
        const sy_material_data *x = sy_material_get(g_scene, (sy_material){id});
        if (x && x->name && !strcmp(x->name, "red")) red = x;
    }
    EXPECT_MSG(red && near(red->base_color[1], 0.25f), "material red from the MTL in the allowed root");
    sy_assimp_info_free(&info);

    /* an MTL in a subfolder (mtllib mtl/sub.mtl) names its texture relative to itself: tex/t.ppm is
     * mtl/tex/t.ppm (as Blender and three.js read it), found without a warning */
    const char submtl[] = "newmtl m\nKd 1 1 1\nmap_Kd tex/t.ppm\n";
    const char subobj[] = "mtllib mtl/sub.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl m\nf 1/1 2/2 3/3\n";
    EXPECT(put_file(dir, "m2/mtl/tex/t.ppm", assimp_quad_ppm, sizeof assimp_quad_ppm - 1, p, sizeof p) == 0);
    EXPECT(put_file(dir, "m2/mtl/sub.mtl", submtl, sizeof submtl - 1, p, sizeof p) == 0);
    EXPECT(put_file(dir, "m2/scene.obj", subobj, sizeof subobj - 1, p, sizeof p) == 0);
    EXPECT_MSG(load(p, NULL, &info, &e) == SY_OK && info.counts.textures == 1 && info.warning_count == 0,
               "texture relative to an MTL in a subfolder: %s", info.warning_count ? info.warnings[0] : e.message);
    sy_assimp_info_free(&info);
    /* still confined to the model's folder: ../../secret.ppm from m3/mtl/ is outside m3/ (refused,
     * naming the way out), admitted by allowed_roots */
    const char outmtl[] = "newmtl m\nKd 1 1 1\nmap_Kd ../../secret.ppm\n";
    EXPECT(put_file(dir, "secret.ppm", assimp_quad_ppm, sizeof assimp_quad_ppm - 1, p, sizeof p) == 0);
    EXPECT(put_file(dir, "m3/mtl/sub.mtl", outmtl, sizeof outmtl - 1, p, sizeof p) == 0);
    EXPECT(put_file(dir, "m3/scene.obj", subobj, sizeof subobj - 1, p, sizeof p) == 0);
    EXPECT_MSG(load(p, NULL, &info, &e) == SY_ERR_LIMIT && strstr(e.message, "secret.ppm") && strstr(e.message, "--allow-path"),
               "texture outside the model's folder through the MTL's folder: %s", e.message);
    const char *droot[] = {dir};
    sy_assimp_options dao = {.allowed_roots = droot, .allowed_root_count = 1};
    EXPECT_MSG(load(p, &dao, &info, &e) == SY_OK && info.counts.textures == 1 && info.warning_count == 0,
               "texture through the MTL's folder in an allowed root: %s", info.warning_count ? info.warnings[0] : e.message);
    sy_assimp_info_free(&info);

    /* separate metalness and roughness maps (MTL map_Pm / map_Pr: Assimp's METALNESS and
     * DIFFUSE_ROUGHNESS) combine into one metallic-roughness texture: G = roughness, B = metallic */
    const char rough[] = "P5\n2 1\n255\n\x40\x80", metal[] = "P5\n2 1\n255\n\xff\x00", metal1[] = "P5\n1 1\n255\n\xc8";
    EXPECT(put_file(dir, "pbr/rough.pgm", rough, sizeof rough - 1, p, sizeof p) == 0);
    EXPECT(put_file(dir, "pbr/metal.pgm", metal, sizeof metal - 1, p, sizeof p) == 0);
    EXPECT(put_file(dir, "pbr/metal1.pgm", metal1, sizeof metal1 - 1, p, sizeof p) == 0);
    const char pbrmtl[] = "newmtl same\nKd 1 1 1\nPr 0.5\nPm 1\nmap_Pr rough.pgm\nmap_Pm metal.pgm\n"
                          "newmtl resized\nKd 1 1 1\nPr 1\nPm 1\nmap_Pr rough.pgm\nmap_Pm metal1.pgm\n"
                          "newmtl roughonly\nKd 1 1 1\nNs 100\nKs 1 1 1\nillum 2\nmap_Pr rough.pgm\n"
                          "newmtl nometal\nKd 1 1 1\nNs 100\nKs 1 1 1\nillum 2\nmap_Pr rough.pgm\nmap_Pm missing.pgm\n";
    EXPECT(put_file(dir, "pbr/pbr.mtl", pbrmtl, sizeof pbrmtl - 1, p, sizeof p) == 0);
    const char pbrobj[] = "mtllib pbr.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
                          "o a\nusemtl same\nf 1/1 2/2 3/3\no b\nusemtl resized\nf 1/1 2/2 3/3\no c\nusemtl roughonly\nf 1/1 2/2 3/3\n"
                          "o d\nusemtl nometal\nf 1/1 2/2 3/3\n";
    EXPECT(put_file(dir, "pbr/pbr.obj", pbrobj, sizeof pbrobj - 1, p, sizeof p) == 0);
    /* 4 textures: "nometal" has its own pair (rough.pgm, missing.pgm), whose missing map is a warning */
    EXPECT_MSG(load(p, NULL, &info, &e) == SY_OK && info.counts.textures == 4 && info.warning_count == 2 &&
                   strstr(info.warnings[0], "resized") && strstr(info.warnings[0], "resampled") &&
                   strstr(info.warnings[1], "missing.pgm"),
               "pbr.obj: %u textures, %u warnings: %s", info.counts.textures, info.warning_count,
               info.warning_count ? info.warnings[0] : e.message);
    int seen = 0;
    for (uint32_t id = sy_scene_next(g_scene, SY_TYPE_MATERIAL, 0); id; id = sy_scene_next(g_scene, SY_TYPE_MATERIAL, id)) {
        const sy_material_data *x = sy_material_get(g_scene, (sy_material){id});
        if (!x || !x->name) continue;
        const sy_texture_data *t = x->metallic_roughness_texture.texture.id
                                       ? sy_object_get(g_scene, SY_TYPE_TEXTURE, x->metallic_roughness_texture.texture.id)
                                       : NULL;
        const uint8_t *px = t ? sy_blob_data(t->pixels) : NULL;
        uint32_t ch = t ? t->info.channels : 0;
        bool two = t && t->info.width == 2 && t->info.height == 1 && ch >= 3 && t->info.format == SY_PIXEL_U8_LINEAR;
        if (!strcmp(x->name, "same")) {
            seen++;
            EXPECT_MSG(two && px[1] == 0x40 && px[ch + 1] == 0x80 && px[2] == 0xff && px[ch + 2] == 0 &&
                           near(x->roughness, 0.5f) && near(x->metallic, 1.0f),
                       "same: G %d %d B %d %d, roughness %g metallic %g", two ? px[1] : -1, two ? px[ch + 1] : -1,
                       two ? px[2] : -1, two ? px[ch + 2] : -1, x->roughness, x->metallic);
        } else if (!strcmp(x->name, "resized")) {
            seen++;
            EXPECT_MSG(two && px[1] == 0x40 && px[ch + 1] == 0x80 && abs(px[2] - 0xc8) <= 1 && abs(px[ch + 2] - 0xc8) <= 1,
                       "resized: G %d %d B %d %d", two ? px[1] : -1, two ? px[ch + 1] : -1, two ? px[2] : -1, two ? px[ch + 2] : -1);
        } else if (!strcmp(x->name, "roughonly")) {
            seen++; /* a classic material: the map decides roughness (factor 1), metallic stays 0 (B 255 x 0) */
            EXPECT_MSG(two && px[1] == 0x40 && px[2] == 0xff && px[ch + 2] == 0xff && near(x->roughness, 1.0f) && x->metallic == 0.0f,
                       "roughonly: G %d B %d, roughness %g metallic %g", two ? px[1] : -1, two ? px[2] : -1, x->roughness,
                       x->metallic);
        } else if (!strcmp(x->name, "nometal")) {
            seen++; /* the metalness map cannot be read: metallic keeps its factor 0, not 1 */
            EXPECT_MSG(two && px[1] == 0x40 && px[2] == 0xff && near(x->roughness, 1.0f) && x->metallic == 0.0f,
                       "nometal: G %d B %d, roughness %g metallic %g", two ? px[1] : -1, two ? px[2] : -1, x->roughness,
                       x->metallic);
        }
    }
    EXPECT_MSG(seen == 4, "pbr.obj: %d of the 4 materials found", seen);
    sy_assimp_info_free(&info);

    /* a classic FBX material (Phong, Ns 128, white specular: the quad's MTL written as ASCII FBX by
     * Assimp's exporter) follows the classic rule as the OBJ does, although Assimp 5.2's FBX reader
     * adds a roughness factor 1 - sqrt(Ns) / 10 (here -0.13) to every material with a shininess */
    const char phongmtl[] = "newmtl shiny\nKd 0.5 0.5 0.5\nKs 1 1 1\nNs 128\nillum 2\n";
    const char phongobj[] = "mtllib phong.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl shiny\nf 1 2 3\n";
    EXPECT(put_file(dir, "phong/phong.mtl", phongmtl, sizeof phongmtl - 1, p, sizeof p) == 0);
    EXPECT(put_file(dir, "phong/phong.obj", phongobj, sizeof phongobj - 1, p, sizeof p) == 0);
    PATHF(q, "%s/phong/phong.fbx", dir);
    EXPECT_MSG(sy_assimp_export(p, "fbxa", q, &e) == SY_OK, "export to ASCII FBX: %s", e.message);
    EXPECT_MSG(load(q, NULL, &info, &e) == SY_OK && info.counts.triangles == 1 && info.warning_count == 0,
               "phong.fbx: %s", info.warning_count ? info.warnings[0] : e.message);
    const sy_material_data *shiny = NULL;
    for (uint32_t id = sy_scene_next(g_scene, SY_TYPE_MATERIAL, 0); id; id = sy_scene_next(g_scene, SY_TYPE_MATERIAL, id)) {
        const sy_material_data *x = sy_material_get(g_scene, (sy_material){id});
        if (x && x->name && !strcmp(x->name, "shiny")) shiny = x;
    }
    EXPECT_MSG(shiny && near(shiny->roughness, 0.3522f) && shiny->metallic == 0.0f && near(shiny->base_color[0], 0.5f),
               "shiny from FBX: roughness %g (0.3522 as from the MTL), metallic %g", shiny ? shiny->roughness : -1,
               shiny ? shiny->metallic : -1);
    sy_assimp_info_free(&info);

    /* a small but valid triangle (area 5e-7, under Assimp's FindDegenerates area threshold of 1e-6,
     * which Assimp 5.2 applies unless told not to): kept, as in a fine 10^6-triangle grid */
    const char small[] = "v 0 0 0\nv 0.001 0 0\nv 0 0.001 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nf 1 2 3\nf 4 5 6\n";
    EXPECT(put_file(dir, "small.obj", small, sizeof small - 1, p, sizeof p) == 0);
    EXPECT_MSG(load(p, NULL, &info, &e) == SY_OK && info.counts.triangles == 2 && info.warning_count == 0,
               "small.obj: %u triangles: %s", info.counts.triangles, info.warning_count ? info.warnings[0] : e.message);
    sy_assimp_info_free(&info);

    /* animations with bad keys: warned and dropped, the rest plays */
    const char anim_x[] =
        "xof 0302txt 0064\n"
        "Frame Root {\n FrameTransformMatrix { 1.0,0.0,0.0,0.0, 0.0,1.0,0.0,0.0, 0.0,0.0,1.0,0.0, 0.0,0.5,0.0,1.0;; }\n"
        " Mesh { 3; 0.0;0.0;0.0;, 1.0;0.0;0.0;, 0.0;1.0;0.0;; 1; 3;0,1,2;; }\n}\n"
        "AnimationSet Back {\n Animation {\n  {Root}\n"
        "  AnimationKey { 2; 4; 0;3;0.0,0.0,0.0;;, 10;3;1.0,0.0,0.0;;, 5;3;2.0,0.0,0.0;;, 20;3;2.0,0.0,0.0;;; }\n }\n}\n"
        "AnimationSet Huge {\n Animation {\n  {Root}\n"
        "  AnimationKey { 2; 2; 0;3;0.0,0.0,0.0;;, 10;3;1e30,0.0,0.0;;; }\n }\n}\n"
        "AnimationSet Good {\n Animation {\n  {Root}\n"
        "  AnimationKey { 2; 2; 0;3;0.0,0.0,0.0;;, 10;3;4.0,0.0,0.0;;; }\n }\n"
        " Animation {\n  {Nowhere}\n  AnimationKey { 2; 2; 0;3;0.0,0.0,0.0;;, 10;3;1.0,0.0,0.0;;; }\n }\n}\n";
    EXPECT(put_file(dir, "anim.x", anim_x, sizeof anim_x - 1, p, sizeof p) == 0);
    EXPECT_MSG(load(p, NULL, &info, &e) == SY_OK, "anim.x: %s", e.message);
    EXPECT_MSG(sy_scene_count(g_scene, SY_TYPE_ANIMATION) == 3, "anim.x: %u clips", sy_scene_count(g_scene, SY_TYPE_ANIMATION));
    static const char *const anim_says[] = {"animations[0].channels[0] 'Root': position key 2 time (0.2 s) is not after the one before",
                                            "animations[1].channels[0] 'Root': position key 1 value is not finite or beyond the coordinate range",
                                            "animations[2].channels[1]: node 'Nowhere' is not in the tree"};
    for (size_t k = 0; k < 3; ++k) {
        bool found = false;
        for (uint32_t w = 0; w < info.stored_warning_count; ++w) found = found || strstr(info.warnings[w], anim_says[k]);
        EXPECT_MSG(found, "anim.x: no warning '%s' (%u warnings%s%s)", anim_says[k], info.warning_count,
                   info.stored_warning_count ? ", the first: " : "", info.stored_warning_count ? info.warnings[0] : "");
    }
    sy_animation good_clip = {0};
    sy_node root_node = {0};
    EXPECT_MSG(sy_animation_find(g_scene, "Good", &good_clip, &e) == SY_OK, "anim.x: %s", e.message);
    for (uint32_t id = sy_scene_next(g_scene, SY_TYPE_NODE, 0); id; id = sy_scene_next(g_scene, SY_TYPE_NODE, id)) {
        const sy_node_data *nd = sy_node_get(g_scene, (sy_node){id});
        if (nd && nd->name && !strcmp(nd->name, "Root")) root_node = (sy_node){id};
    }
    double t0 = -1, t1 = -1;
    EXPECT(sy_scene_time_range(g_scene, good_clip, &t0, &t1, &e) == SY_OK && near((float)t1, 0.4f)); /* 10 ticks at 25 per second */
    EXPECT_MSG(root_node.id && sy_scene_set_time(g_scene, good_clip, 0.2, &e) == SY_OK, "anim.x: set time: %s", e.message);
    const sy_node_data *rn = root_node.id ? sy_node_get(g_scene, root_node) : NULL;
    EXPECT_MSG(rn && rn->transform.mode == SY_TRANSFORM_TRS && near(rn->transform.translation[0], 2.0f) && near(rn->transform.translation[1], 0.0f) &&
                   near(rn->transform.scale[0], 1.0f) && near(rn->transform.rotation[3], 1.0f),
               "anim.x: Root at t=0.2: mode %d, translation %g %g %g (want TRS, 2 0 0)", rn ? (int)rn->transform.mode : -1,
               rn ? rn->transform.translation[0] : -1, rn ? rn->transform.translation[1] : -1,
               rn ? rn->transform.translation[2] : -1);
    sy_assimp_info_free(&info);

    /* a skin with more than 8 weights on a vertex: the 8 largest kept, renormalised, warned once;
     * vertex 0 weighs 0.1 .. 1.0 on bones b0 .. b9, vertex 1 1.0 on each, vertex 2 none */
    {
        static const char ident[] = "1.0,0.0,0.0,0.0,0.0,1.0,0.0,0.0,0.0,0.0,1.0,0.0,0.0,0.0,0.0,1.0";
        char skin_x[8192];
        int n = snprintf(skin_x, sizeof skin_x,
                         "xof 0302txt 0064\nFrame Root {\n FrameTransformMatrix { %s;; }\n Mesh { 3; 0.0;0.0;0.0;, 1.0;0.0;0.0;, "
                         "0.0;1.0;0.0;; 1; 3;0,1,2;;\n  XSkinMeshHeader { 10; 10; 10; }\n", ident);
        for (int k = 0; k < 10; ++k)
            n += snprintf(skin_x + n, sizeof skin_x - (size_t)n, "  SkinWeights { \"b%d\"; 2; 0,1; %.1f,1.0; %s;; }\n", k,
                          0.1 * (k + 1), ident);
        n += snprintf(skin_x + n, sizeof skin_x - (size_t)n, " }\n");
        for (int k = 0; k < 10; ++k)
            n += snprintf(skin_x + n, sizeof skin_x - (size_t)n, " Frame b%d { FrameTransformMatrix { %s;; } }\n", k, ident);
        n += snprintf(skin_x + n, sizeof skin_x - (size_t)n, "}\n");
        EXPECT(put_file(dir, "skin.x", skin_x, (size_t)n, p, sizeof p) == 0);
        EXPECT_MSG(load(p, NULL, &info, &e) == SY_OK, "skin.x: %s", e.message);
        EXPECT_MSG(info.stored_warning_count >= 1 && strstr(info.warnings[0], "more than 8 bone weights") &&
                       strstr(info.warnings[0], "8 largest kept"),
                   "skin.x: %s", info.stored_warning_count ? info.warnings[0] : "no warning");
        const sy_mesh_data *sm = first_mesh();
        const sy_primitive *pr = sm && sm->primitives.count == 1 ? &sm->primitives.items[0] : NULL;
        EXPECT_MSG(pr && sy_primitive_influences(pr) == 8, "skin.x: %u influences per vertex", pr ? sy_primitive_influences(pr) : 0);
        if (pr && sy_primitive_influences(pr) == 8) {
            const uint32_t *jt = sy_blob_data(pr->joints);
            const float *wt = sy_blob_data(pr->weights);
            float sum0 = 0, sum1 = 0, min0 = 1;
            unsigned seen0 = 0;
            for (int k = 0; k < 8; ++k) {
                sum0 += wt[k], sum1 += wt[8 + k], min0 = fminf(min0, wt[k]);
                seen0 |= 1u << (jt[k] < 10 ? jt[k] : 31);
                EXPECT_MSG(near(wt[8 + k], 0.125f) && wt[16 + k] == 0.0f, "skin.x: vertex 1 / 2 weight %d: %g %g", k,
                           wt[8 + k], wt[16 + k]);
            }
            EXPECT_MSG(near(sum0, 1.0f) && near(sum1, 1.0f) && near(min0, 0.3f / 5.2f) && seen0 == 0x3fcu,
                       "skin.x: vertex 0: sum %g, smallest %g (want 0.3 / 5.2), bones %#x (want b2 .. b9)", sum0, min0, seen0);
        }
        uint32_t nj = 0;
        for (uint32_t id = sy_scene_next(g_scene, SY_TYPE_NODE, 0); id; id = sy_scene_next(g_scene, SY_TYPE_NODE, id)) {
            const sy_node_data *nd = sy_node_get(g_scene, (sy_node){id});
            uint32_t c = 0;
            if (nd && nd->mesh.id && sy_node_skin(nd, &c) && c) nj = c;
        }
        EXPECT_MSG(nj == 10, "skin.x: the mesh's node has a skin of %u joints (want 10)", nj);
        sy_assimp_info_free(&info);
    }

    /* a file Assimp cannot read: Assimp's reason and the file name */
    const char junk[] = "this is not a 3DS file at all, only some text";
    expect_refused(dir, "junk.3ds", junk, sizeof junk - 1, SY_ERR_PARSE, "Assimp cannot read it");
    EXPECT_MSG(sy_scene_count(g_scene, SY_TYPE_NODE) == 0 && sy_scene_count(g_scene, SY_TYPE_MESH) == 0, "nothing left after a failure");

    sy_scene_destroy(g_scene);
    remove_scratch_dir(dir);
    EXPECT_MSG(access(dir, F_OK) != 0, "the scratch folder %s and its nested folders are removed", dir);
    return sy_check_finish("test_assimp");
}
