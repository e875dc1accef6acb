/* test_flat_normals.c — a mesh without normals is shaded flat by every back-end while it keeps
 * its index buffer (issue 39): glTF 2.0 asks for flat normals where a primitive has no NORMAL, and
 * the loader leaves such a primitive indexed, with its shared vertices and no normals, for the
 * back-ends to shade from each triangle's geometric normal (the rasterizer from the screen-space
 * derivatives of the position, the ray tracers from the hit triangle).
 *
 * The scene: a GLB written here, a unit cube of 8 shared corners and 36 indices without NORMAL
 * (rough white dielectric, single-sided), lit by one KHR_lights_punctual directional light, once
 * plain and once under a mirroring node (scale -1 in x: the same cube in space, its winding
 * reversed, which glTF's determinant rule turns back). Checked:
 *   - the loaded primitive keeps its 8 vertices and 36 indices, and has no normals;
 *   - raster and whitted images: each of the 3 faces the camera sees is uniformly lit (9 points
 *     over the face within 4 % of their mean; smooth corner normals would vary by far more), the
 *     faces differ and are ordered by their outward normal's cosine to the light (so the normal
 *     faces outwards, as the counter-clockwise winding says);
 *   - the mirrored cube looks like the plain one (each face within 3 %). */
#include "it_util.h"
#include "sy_gltf.h"

#define W 160
#define H 120

static const float k_light_dir[3] = {-0.35f, -0.8f, -0.5f}; /* direction the light travels (normalised below) */

/* The cube: corner v at (+-0.5, +-0.5, +-0.5) by its bits; face f (axis f / 2, + side when f is
 * odd) as two counter-clockwise triangles seen from outside. */
static void cube(float pos[24], uint16_t idx[36])
{
    for (int v = 0; v < 8; v++)
        for (int a = 0; a < 3; a++) pos[3 * v + a] = (v >> a & 1) ? 0.5f : -0.5f;
    for (int f = 0; f < 6; f++) {
        int a = f / 2, u = (a + 1) % 3, w = (a + 2) % 3, side = f % 2, c[4];
        const int cu[4] = {0, 1, 1, 0}, cw[4] = {0, 0, 1, 1}, ccw[6] = {0, 1, 2, 0, 2, 3}, cw6[6] = {0, 2, 1, 0, 3, 2};
        for (int k = 0; k < 4; k++) c[k] = side << a | cu[k] << u | cw[k] << w;
        for (int k = 0; k < 6; k++) idx[6 * f + k] = (uint16_t)c[side ? ccw[k] : cw6[k]];
    }
}

/* Writes the GLB: the cube under one node (scale -1 in x when mirrored), the light on another. */
static void write_glb(const char *path, bool mirrored)
{
    struct {
        float pos[24];
        uint16_t idx[36];
    } bin;
    cube(bin.pos, bin.idx);
    float d[3] = {k_light_dir[0], k_light_dir[1], k_light_dir[2]}, l = sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    for (int k = 0; k < 3; k++) d[k] /= l;
    /* rotation taking the light's -Z to d: axis (0, 0, -1) x d, half-angle quaternion */
    float q[4] = {d[1], -d[0], 0.0f, 1.0f - d[2]}, ql = sqrtf(q[0] * q[0] + q[1] * q[1] + q[3] * q[3]);
    for (int k = 0; k < 4; k++) q[k] /= ql;
    char json[2048];
    int n = snprintf(json, sizeof json,
                     "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"KHR_lights_punctual\"],"
                     "\"extensions\":{\"KHR_lights_punctual\":{\"lights\":[{\"type\":\"directional\",\"intensity\":3}]}},"
                     "\"scene\":0,\"scenes\":[{\"nodes\":[0,1]}],"
                     "\"nodes\":[{\"mesh\":0%s},{\"rotation\":[%.9g,%.9g,%.9g,%.9g],\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}}],"
                     "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1,\"material\":0}]}],"
                     "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.8,0.8,0.8,1],\"metallicFactor\":0,\"roughnessFactor\":1}}],"
                     "\"buffers\":[{\"byteLength\":%zu}],"
                     "\"bufferViews\":[{\"buffer\":0,\"byteLength\":96},{\"buffer\":0,\"byteOffset\":96,\"byteLength\":72}],"
                     "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":8,\"type\":\"VEC3\","
                     "\"min\":[-0.5,-0.5,-0.5],\"max\":[0.5,0.5,0.5]},"
                     "{\"bufferView\":1,\"componentType\":5123,\"count\":36,\"type\":\"SCALAR\"}]}",
                     mirrored ? ",\"scale\":[-1,1,1]" : "", (double)q[0], (double)q[1], (double)q[2], (double)q[3], sizeof bin);
    while (n % 4) json[n++] = ' ';
    FILE *f = fopen(path, "wb");
    if (!f) {
        perror(path);
        exit(1);
    }
    uint32_t hdr[5] = {0x46546C67u, 2, (uint32_t)(12 + 8 + n + 8 + sizeof bin), (uint32_t)n, 0x4E4F534Au};
    uint32_t bh[2] = {(uint32_t)sizeof bin, 0x004E4942u};
    bool ok = fwrite(hdr, 4, 5, f) == 5 && fwrite(json, 1, (size_t)n, f) == (size_t)n && fwrite(bh, 4, 2, f) == 2 &&
              fwrite(&bin, sizeof bin, 1, f) == 1;
    if (fclose(f) != 0 || !ok) {
        fprintf(stderr, "%s: write failed\n", path);
        exit(1);
    }
}

/* A view from eye towards the origin, +Y up, symmetric window of half-height tan_half (W:H). */
static sy_camera_view look_at(const float eye[3], float tan_half)
{
    float z[3] = {eye[0], eye[1], eye[2]}, zl = sqrtf(z[0] * z[0] + z[1] * z[1] + z[2] * z[2]);
    for (int k = 0; k < 3; k++) z[k] /= zl;
    float x[3] = {z[2], 0.0f, -z[0]}, xl = sqrtf(x[0] * x[0] + x[2] * x[2]); /* up x z */
    x[0] /= xl, x[2] /= xl;
    float y[3] = {z[1] * x[2] - z[2] * x[1], z[2] * x[0] - z[0] * x[2], z[0] * x[1] - z[1] * x[0]};
    sy_camera_view v = it_view_down_z(1.0f, tan_half);
    for (int k = 0; k < 3; k++) {
        v.camera_to_world.m[k] = x[k];
        v.camera_to_world.m[4 + k] = y[k];
        v.camera_to_world.m[8 + k] = z[k];
        v.camera_to_world.m[12 + k] = eye[k];
    }
    v.window[0] = -tan_half * (float)W / (float)H, v.window[1] = tan_half * (float)W / (float)H;
    return v;
}

static float lum(const float *p) { return 0.2126f * p[0] + 0.7152f * p[1] + 0.0722f * p[2]; }

/* Renders the cube of `path` with `backend`; means[a]: the mean luminance of the + face of axis a
 * (the three the camera sees), after checking each is uniform. */
static void render_faces(const char *path, const char *backend, float means[3])
{
    sy_gltf_info info;
    sy_scene *s = it_load_gltf(path, &info);
    const sy_mesh_data *md = sy_mesh_get(s, (sy_mesh){sy_scene_next(s, SY_TYPE_MESH, 0)});
    const sy_primitive *p = md && md->primitives.count == 1 ? &md->primitives.items[0] : NULL;
    EXPECT_MSG(p && sy_primitive_vertex_count(p) == 8 && p->indices && sy_blob_size(p->indices) == 36 * sizeof(uint32_t) && !p->normals,
               "%s: the cube keeps its 8 shared vertices and 36 indices, without normals (%u vertices)", path,
               p ? (unsigned)sy_primitive_vertex_count(p) : 0u);
    MUST(sy_scene_commit(s, NULL, err));
    sy_context *ctx;
    MUST(sy_context_create(s, backend, NULL, info.root.id, &ctx, err));
    MUST(sy_context_sync(ctx, err));
    const float eye[3] = {2.6f, 2.2f, 3.4f};
    sy_camera_view view = look_at(eye, 0.32f);
    sy_layer img;
    MUST(it_render_full(ctx, &view, W, H, 0, &img, err));
    for (int a = 0; a < 3; a++) {
        int u = (a + 1) % 3, w = (a + 2) % 3;
        float lo = INFINITY, hi = -INFINITY, sum = 0.0f;
        for (int i = -1; i <= 1; i++)
            for (int j = -1; j <= 1; j++) {
                float pt[3] = {0, 0, 0}, px, py;
                pt[a] = 0.5f, pt[u] = 0.3f * (float)i, pt[w] = 0.3f * (float)j;
                EXPECT(it_project(&view, pt, W, H, &px, &py) && px >= 0 && py >= 0 && px < W && py < H);
                float y = lum(it_px(&img, (uint32_t)fminf(fmaxf(px, 0.0f), W - 1), (uint32_t)fminf(fmaxf(py, 0.0f), H - 1)));
                lo = fminf(lo, y), hi = fmaxf(hi, y), sum += y;
            }
        means[a] = sum / 9.0f;
        printf("%s %s: face +%c: mean %.4f, min %.4f, max %.4f\n", backend, path, "XYZ"[a], (double)means[a], (double)lo,
               (double)hi);
        EXPECT_MSG(means[a] > 0.01f && hi - lo <= 0.04f * means[a], "%s %s: face +%c is not uniformly lit: %.4f .. %.4f", backend,
                   path, "XYZ"[a], (double)lo, (double)hi);
    }
    /* cosines to the light: +X 0.35, +Y 0.8, +Z 0.5 (unnormalised): +Y brightest, then +Z, then +X */
    EXPECT_MSG(means[1] > 1.2f * means[2] && means[2] > 1.2f * means[0], "%s %s: faces not ordered by their cosine to the light: "
               "+X %.4f, +Y %.4f, +Z %.4f", backend, path, (double)means[0], (double)means[1], (double)means[2]);
    sy_layer_destroy(&img);
    sy_context_release(ctx);
    sy_gltf_info_free(&info);
    sy_scene_destroy(s);
}

static void check_backend(const char *plain, const char *mirrored, const char *backend)
{
    float a[3], b[3];
    render_faces(plain, backend, a);
    render_faces(mirrored, backend, b);
    for (int k = 0; k < 3; k++)
        EXPECT_MSG(fabsf(a[k] - b[k]) <= 0.03f * a[k], "%s: face +%c of the mirrored cube %.4f, of the plain one %.4f", backend,
                   "XYZ"[k], (double)b[k], (double)a[k]);
}

int main(void)
{
    it_register();
    char dir[] = "/tmp/sy_flat_normals_XXXXXX", plain[64], mirrored[64];
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return 1;
    }
    snprintf(plain, sizeof plain, "%s/cube.glb", dir);
    snprintf(mirrored, sizeof mirrored, "%s/cube_mirrored.glb", dir);
    write_glb(plain, false);
    write_glb(mirrored, true);

    check_backend(plain, mirrored, "whitted");
#ifdef SY_HAVE_RASTER
    check_backend(plain, mirrored, "raster");
#else
    printf("skip: the raster half (this build has no rasterizer: SY_WITH_RASTER=OFF)\n");
#endif
    remove(plain);
    remove(mirrored);
    rmdir(dir);
    return sy_check_finish("integration_flat_normals");
}
