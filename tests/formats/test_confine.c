/* test_confine.c — model files stay in their folder (issue 14, finding 4): sy_path_confine alone,
 * then the glTF and X3D loaders on files this test writes into a scratch tree:
 *
 *   T/outside.bin, T/outside.png, T/outside.x3d      files outside the model's folder
 *   T/model/in.bin, T/model/sub/in.bin               files inside it
 *   T/model/link.bin -> ../outside.bin               a symbolic link that leaves the tree
 *   T/model/NAME.gltf, T/model/NAME.x3d              models naming them
 *
 * Each escape ("..", an absolute path, a file: URI, a symbolic link; in a buffer URI, an image URI,
 * an X3D Inline and an ImageTexture url) is refused with SY_ERR_LIMIT and a message naming the
 * model, the uri and --allow-path; in-tree files load; allowed_roots admits the outside folder. */
#include "sy_file.h"
#include "sy_gltf.h"
#include "sy_x3d.h"
#include "test_util.h"

static char g_root[512];

/* a glTF whose only buffer is `buffer_uri` (36 bytes: one triangle), plus an image `image_uri`
 * when not NULL */
static void write_gltf(const char *name, const char *buffer_uri, const char *image_uri)
{
    char path[1024], json[2048];
    PATHF(path, "%s/model/%s", g_root, name);
    char images[256] = "";
    if (image_uri) PATHF(images, ",\"images\":[{\"uri\":\"%s\"}]", image_uri);
    PATHF(json,
          "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"uri\":\"%s\",\"byteLength\":36}],"
          "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
          "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\","
          "\"min\":[0,0,0],\"max\":[1,1,0]}],"
          "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
          "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}],\"scene\":0%s}",
          buffer_uri, images);
    EXPECT_MSG(write_bytes(path, json, strlen(json)) == 0, "cannot write %s", path);
}

static sy_result load_gltf(const char *name, const char *const *roots, size_t nroots, sy_error *err)
{
    char path[1024];
    PATHF(path, "%s/model/%s", g_root, name);
    sy_scene *s = NULL;
    if (sy_scene_create(&s, err) != SY_OK) return SY_ERR_OUT_OF_MEMORY;
    sy_gltf_options o = {.allowed_roots = roots, .allowed_root_count = nroots};
    sy_gltf_info info = {0};
    sy_result r = sy_gltf_load(path, s, &o, &info, err);
    sy_gltf_info_free(&info);
    sy_scene_destroy(s);
    return r;
}

static sy_result load_x3d(const char *name, const char *const *roots, size_t nroots, sy_x3d_info *info, sy_error *err)
{
    char path[1024];
    PATHF(path, "%s/model/%s", g_root, name);
    sy_scene *s = NULL;
    if (sy_scene_create(&s, err) != SY_OK) return SY_ERR_OUT_OF_MEMORY;
    sy_x3d_options o = {.allowed_roots = roots, .allowed_root_count = nroots};
    sy_result r = sy_x3d_load(path, s, &o, info, err);
    sy_scene_destroy(s);
    return r;
}

/* the refusal names the model file, the uri and the option that admits more folders */
static void expect_refused(const char *what, sy_result r, const sy_error *e, const char *model, const char *uri)
{
    EXPECT_MSG(r == SY_ERR_LIMIT, "%s: result %d, want SY_ERR_LIMIT (%s)", what, (int)r, e->message);
    EXPECT_MSG(strstr(e->message, model) != NULL, "%s: message does not name %s: %s", what, model, e->message);
    EXPECT_MSG(strstr(e->message, uri) != NULL, "%s: message does not name %s: %s", what, uri, e->message);
    EXPECT_MSG(strstr(e->message, "--allow-path") != NULL, "%s: message does not name --allow-path: %s", what, e->message);
}

static void write_file(const char *rel, const void *data, size_t n)
{
    char path[1024];
    PATHF(path, "%s/%s", g_root, rel);
    EXPECT_MSG(write_bytes(path, data, n) == 0, "cannot write %s", path);
}

int main(void)
{
    make_scratch_dir(g_root, sizeof g_root, "confine");
    char dir[1024], link[1024];
    PATHF(dir, "%s/model", g_root);
    EXPECT_MSG(mkdir(dir, 0777) == 0, "mkdir model");
    PATHF(link, "%s/model/sub", g_root);
    EXPECT_MSG(mkdir(link, 0777) == 0, "mkdir model/sub");
    float tri[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    write_file("outside.bin", tri, sizeof tri);
    write_file("model/in.bin", tri, sizeof tri);
    write_file("model/sub/in.bin", tri, sizeof tri);
    write_file("outside.png", "not a png", 9);
    const char *x3d_out = "<X3D><Scene><Shape><Box/></Shape></Scene></X3D>";
    write_file("outside.x3d", x3d_out, strlen(x3d_out));
    PATHF(link, "%s/model/link.bin", g_root);
    EXPECT_MSG(symlink("../outside.bin", link) == 0, "symlink: %s", strerror(errno));

    /* sy_path_confine alone */
    char joined[1024], *real = NULL;
    sy_error e = {0};
    PATHF(joined, "%s/sub/../in.bin", dir);
    EXPECT_MSG(sy_path_confine("m.gltf", "sub/../in.bin", joined, dir, NULL, 0, &real, &e) == SY_OK, "%s", e.message);
    EXPECT_MSG(real && strstr(real, "/model/in.bin"), "real path %s", real ? real : "(null)");
    free(real);
    PATHF(joined, "%s/../outside.bin", dir);
    expect_refused("confine ..", sy_path_confine("m.gltf", "../outside.bin", joined, dir, NULL, 0, &real, &e), &e,
                   "m.gltf", "../outside.bin");
    EXPECT_MSG(!real, "no path on refusal");
    PATHF(joined, "%s/nope.bin", dir);
    EXPECT_MSG(sy_path_confine("m.gltf", "nope.bin", joined, dir, NULL, 0, &real, &e) == SY_ERR_NOT_FOUND, "missing file");
    const char *roots[1] = {g_root};
    PATHF(joined, "%s/../outside.bin", dir);
    EXPECT_MSG(sy_path_confine("m.gltf", "../outside.bin", joined, dir, roots, 1, &real, &e) == SY_OK, "allowed root: %s",
               e.message);
    free(real);
    /* a folder whose name merely starts like the model's is not inside it */
    char sibling[1024];
    PATHF(sibling, "%s/model2", g_root);
    EXPECT_MSG(mkdir(sibling, 0777) == 0, "mkdir model2");
    write_file("model2/x.bin", tri, sizeof tri);
    PATHF(joined, "%s/../model2/x.bin", dir);
    expect_refused("confine sibling", sy_path_confine("m.gltf", "../model2/x.bin", joined, dir, NULL, 0, &real, &e),
                   &e, "m.gltf", "../model2/x.bin");

    /* glTF: buffers */
    char abs_uri[1024], file_uri[1100];
    PATHF(abs_uri, "%s/outside.bin", g_root);
    PATHF(file_uri, "file://%s/outside.bin", g_root);
    write_gltf("ok.gltf", "sub/../in.bin", NULL);
    write_gltf("dotdot.gltf", "../outside.bin", NULL);
    write_gltf("abs.gltf", abs_uri, NULL);
    write_gltf("fileuri.gltf", file_uri, NULL);
    write_gltf("link.gltf", "link.bin", NULL);
    write_gltf("image.gltf", "in.bin", "../outside.png");
    EXPECT_MSG(load_gltf("ok.gltf", NULL, 0, &e) == SY_OK, "in-tree buffer: %s", e.message);
    expect_refused("glTF ..", load_gltf("dotdot.gltf", NULL, 0, &e), &e, "dotdot.gltf", "../outside.bin");
    expect_refused("glTF absolute", load_gltf("abs.gltf", NULL, 0, &e), &e, "abs.gltf", abs_uri);
    expect_refused("glTF file:", load_gltf("fileuri.gltf", NULL, 0, &e), &e, "fileuri.gltf", file_uri);
    expect_refused("glTF symlink", load_gltf("link.gltf", NULL, 0, &e), &e, "link.gltf", "link.bin");
    expect_refused("glTF image", load_gltf("image.gltf", NULL, 0, &e), &e, "image.gltf", "../outside.png");
    EXPECT_MSG(load_gltf("dotdot.gltf", roots, 1, &e) == SY_OK, "allowed_roots admits ..: %s", e.message);
    EXPECT_MSG(load_gltf("abs.gltf", roots, 1, &e) == SY_OK, "allowed_roots admits an absolute path: %s", e.message);
    EXPECT_MSG(load_gltf("link.gltf", roots, 1, &e) == SY_OK, "allowed_roots admits the link: %s", e.message);

    /* X3D: Inline and ImageTexture */
    const char *inl = "<X3D><Scene><Inline url='\"../outside.x3d\"'/></Scene></X3D>";
    write_file("model/inline.x3d", inl, strlen(inl));
    char tex[1200];
    PATHF(tex,
          "<X3D><Scene><Shape><Appearance><ImageTexture url='\"%s/outside.png\"'/></Appearance><Box/></Shape>"
          "</Scene></X3D>",
          g_root);
    write_file("model/texture.x3d", tex, strlen(tex));
    const char *inl_ok = "<X3D><Scene><Inline url='\"sub/../in.x3d\"'/></Scene></X3D>";
    write_file("model/inline_ok.x3d", inl_ok, strlen(inl_ok));
    write_file("model/in.x3d", x3d_out, strlen(x3d_out));
    sy_x3d_info xi = {0};
    expect_refused("X3D Inline", load_x3d("inline.x3d", NULL, 0, &xi, &e), &e, "inline.x3d", "../outside.x3d");
    sy_x3d_info_free(&xi);
    char abs_png[1024];
    PATHF(abs_png, "%s/outside.png", g_root);
    expect_refused("X3D ImageTexture", load_x3d("texture.x3d", NULL, 0, &xi, &e), &e, "texture.x3d", abs_png);
    sy_x3d_info_free(&xi);
    EXPECT_MSG(load_x3d("inline_ok.x3d", NULL, 0, &xi, &e) == SY_OK && xi.counts.inlines == 1, "in-tree Inline: %s",
               e.message);
    sy_x3d_info_free(&xi);
    EXPECT_MSG(load_x3d("inline.x3d", roots, 1, &xi, &e) == SY_OK && xi.counts.inlines == 1,
               "allowed_roots admits the Inline: %s (inlines %u)", e.message, xi.counts.inlines);
    sy_x3d_info_free(&xi);

    const char *sub[] = {"model/sub", "model", "model2"}; /* remove_scratch_dir takes flat folders */
    for (size_t i = 0; i < sizeof sub / sizeof sub[0]; ++i) {
        PATHF(dir, "%s/%s", g_root, sub[i]);
        remove_scratch_dir(dir);
    }
    remove_scratch_dir(g_root);
    return sy_check_finish("formats_confine");
}
