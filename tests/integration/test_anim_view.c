/* test_anim_view.c — cameras and lights that animate, animate (issue 35, glTF part), in every
 * back-end: small glTF files written here (no test data needed) are loaded, their clip set to two
 * times, and rendered by raster, whitted and pathtracer contexts that were synced at the first
 * time, so the second reaches them as an update. The view comes from the viewport's camera node
 * (sy_viewport_camera_view: the node's world matrix and the camera's yfov at the scene's time),
 * as `sy render --at` and sequences take it.
 *   - camera: a glTF camera on a node whose translation is animated from x = -1 to x = 1 looks at
 *     an unlit square; the square's coverage centroid in each image is where the camera at that
 *     time projects its centre (computed here from the keys), within 0.75 pixel; KHR_animation_pointer
 *     drives the camera's yfov (0.8 -> 0.6 rad): the square's width in pixels follows 1 / tan(yfov / 2)
 *   - light: a KHR_lights_punctual point light on a node animated from x = -1.5 to x = 1.5, 1 unit
 *     in front of a large diffuse plane (no specular), seen by a still camera: the brightest column
 *     is under the light at each time (its projection computed here), within 2 pixels; a
 *     KHR_animation_pointer intensity channel (10 -> 30 cd) makes the plane's brightness at the
 *     light's foot three times brighter at t = 1 than at t = 0 (within 10 %; the path tracer 20 %)
 *   - pointers the clock does not drive (a material's alphaCutoff, a camera the file does not
 *     have, no pointer): the first warned naming its channel, the rest counted in one warning; the
 *     good /nodes/0/translation pointer channel plays.
 * Usage: test_it_anim_view. */
#include "it_util.h"
#include "sy_anim.h"
#include "sy_gltf.h"

#include <stdint.h>

#define W 96
#define H 64


static char g_dir[256];

static void base64(const uint8_t *in, size_t n, char *out)
{
    static const char k[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    size_t o = 0;
    for (size_t i = 0; i < n; i += 3) {
        uint32_t v = (uint32_t)in[i] << 16 | (i + 1 < n ? (uint32_t)in[i + 1] << 8 : 0) | (i + 2 < n ? in[i + 2] : 0);
        out[o++] = k[v >> 18 & 63];
        out[o++] = k[v >> 12 & 63];
        out[o++] = i + 1 < n ? k[v >> 6 & 63] : '=';
        out[o++] = i + 2 < n ? k[v & 63] : '=';
    }
    out[o] = '\0';
}

/* The buffer both files share: a square of half-size h at z = 0 facing +Z (positions, normals,
 * u16 indices), key times 0 and 1, and two vec3 keys and two scalar pairs. */
typedef struct buf {
    float pos[12], nrm[12];
    uint16_t idx[6];
    float times[2], keys[6], scal_a[2], scal_b[2];
} buf;

/* glTF text the tests share: the camera of the views (perspective, yfov 0.8, znear 0.1) and a channel
 * of sampler S driving the KHR_animation_pointer P */
#define CAMERA_JSON "\"cameras\":[{\"type\":\"perspective\",\"perspective\":{\"yfov\":0.8,\"znear\":0.1}}],\n"
#define POINTER_CHANNEL(S, P)                                                                                          \
    "{\"sampler\":" #S ",\"target\":{\"path\":\"pointer\",\"extensions\":{\"KHR_animation_pointer\":{\"pointer\":\"" P     \
    "\"}}}}"

/* Writes name holding the glTF text; the buffer (make_buf) as a data URI. */
static void write_gltf(const char *name, buf data, const char *rest)
{
    const buf *b = &data;
    char uri[1024], path[512];
    base64((const uint8_t *)b, sizeof *b, uri);
    snprintf(path, sizeof path, "%s/%s", g_dir, name);
    FILE *f = fopen(path, "w");
    if (!f) {
        fprintf(stderr, "cannot write %s\n", path);
        exit(1);
    }
    /* byte offsets into buf: pos 0, nrm 48, idx 96 (12 bytes), times 108, keys 116, scal_a 140, scal_b 148 */
    fprintf(f,
            "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"KHR_materials_unlit\",\"KHR_lights_punctual\","
            "\"KHR_materials_specular\",\"KHR_animation_pointer\"],\n"
            "\"buffers\":[{\"byteLength\":%zu,\"uri\":\"data:application/octet-stream;base64,%s\"}],\n"
            "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":96},{\"buffer\":0,\"byteOffset\":96,"
            "\"byteLength\":12},{\"buffer\":0,\"byteOffset\":108,\"byteLength\":48}],\n"
            "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\",\"min\":[%g,%g,0],"
            "\"max\":[%g,%g,0]},{\"bufferView\":0,\"byteOffset\":48,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"},"
            "{\"bufferView\":1,\"componentType\":5123,\"count\":6,\"type\":\"SCALAR\"},"
            "{\"bufferView\":2,\"componentType\":5126,\"count\":2,\"type\":\"SCALAR\",\"min\":[0],\"max\":[1]},"
            "{\"bufferView\":2,\"byteOffset\":8,\"componentType\":5126,\"count\":2,\"type\":\"VEC3\"},"
            "{\"bufferView\":2,\"byteOffset\":32,\"componentType\":5126,\"count\":2,\"type\":\"SCALAR\"},"
            "{\"bufferView\":2,\"byteOffset\":40,\"componentType\":5126,\"count\":2,\"type\":\"SCALAR\"}],\n"
            "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1},\"indices\":2,\"material\":0}]}],\n"
            "%s}\n",
            sizeof *b, uri, (double)b->pos[0], (double)b->pos[1], (double)b->pos[6], (double)b->pos[7], rest);
    fclose(f);
}

static buf make_buf(float h, const float k0[3], const float k1[3], float a0, float a1, float b0, float b1)
{
    buf b = {{-h, -h, 0, h, -h, 0, h, h, 0, -h, h, 0}, {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}, {0, 1, 2, 0, 2, 3}, {0, 1},
             {k0[0], k0[1], k0[2], k1[0], k1[1], k1[2]}, {a0, a1}, {b0, b1}};
    return b;
}

typedef struct rig {
    sy_scene *s;
    sy_gltf_info info;
    sy_window *win;
    sy_viewport *vp;
    sy_context *ctx[IT_NBACKENDS];
} rig;

static void rig_open(rig *g, const char *name)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", g_dir, name);
    g->s = it_load_gltf(path, &g->info);
    if (g->info.camera_node_count != 1) {
        fprintf(stderr, "%s: %u cameras (want 1)\n", name, g->info.camera_node_count);
        exit(1);
    }
    MUST(sy_scene_set_time(g->s, (sy_animation){0}, 0.0, err));
    MUST(sy_scene_commit(g->s, NULL, err));
    sy_viewport_desc vd = {0};
    vd.camera = g->info.camera_nodes[0];
    vd.root = g->info.root;
    vd.backend = "whitted"; /* the viewport gives the camera view; each back-end renders it from its own context */
    g->win = it_window(W, H, &vd, &g->vp);
    for (size_t b = 0; b < IT_NBACKENDS; ++b) {
        MUST(sy_context_create(g->s, it_backends[b], NULL, g->info.root.id, &g->ctx[b], err));
        MUST(sy_context_sync(g->ctx[b], err));
    }
}

static void rig_close(rig *g)
{
    for (size_t b = 0; b < IT_NBACKENDS; ++b) sy_context_release(g->ctx[b]);
    sy_window_destroy(g->win);
    sy_gltf_info_free(&g->info);
    sy_scene_destroy(g->s);
}

/* The scene at time t, synced into every context; the view of the viewport's camera then. */
static sy_camera_view rig_time(rig *g, double t)
{
    MUST(sy_scene_set_time(g->s, (sy_animation){0}, t, err));
    MUST(sy_scene_commit(g->s, NULL, err));
    for (size_t b = 0; b < IT_NBACKENDS; ++b) MUST(sy_context_sync(g->ctx[b], err));
    sy_camera_view v;
    MUST(sy_viewport_camera_view(g->vp, g->s, W, H, &v, err));
    return v;
}

/* Opens the rig of the file `name`, renders it at t = 0 and t = 1 on every back-end (spp samples
 * a pixel) and hands each image to measure (ti: 0 or 1, bi: the back-end's index); closes the rig. */
typedef void (*rig_measure)(void *arg, int ti, double t, size_t bi, const sy_layer *img);
static void rig_sweep(const char *name, uint32_t spp, rig_measure measure, void *arg)
{
    rig g;
    rig_open(&g, name);
    const double times[2] = {0.0, 1.0};
    for (int ti = 0; ti < 2; ++ti) {
        sy_camera_view v = rig_time(&g, times[ti]);
        for (size_t bi = 0; bi < IT_NBACKENDS; ++bi) {
            sy_layer img;
            MUST(it_render_full(g.ctx[bi], &v, W, H, spp, &img, err));
            measure(arg, ti, times[ti], bi, &img);
            sy_layer_destroy(&img);
        }
    }
    rig_close(&g);
}

/* Pixel column of world x at depth dist in front of a camera at x = cx (yfov, aspect W / H). */
static double column_of(double x, double cx, double dist, double yfov)
{
    double half_w = tan(yfov / 2) * (double)W / (double)H;
    return ((x - cx) / dist / half_w + 1.0) * 0.5 * W;
}

/* The dolly's square: its centroid and side at t against the camera's place and yfov then. */
static void camera_measure(void *arg, int ti, double t, size_t bi, const sy_layer *img)
{
    (void)arg, (void)ti;
    double u = t, cx = -1.0 + 2.0 * u, yfov = 0.8 - 0.2 * u;
    double want = column_of(0.0, cx, 5.0, yfov), want_w = column_of(0.5, cx, 5.0, yfov) - column_of(-0.5, cx, 5.0, yfov);
    double sum = 0, sx = 0, sy = 0;
    for (uint32_t y = 0; y < H; ++y)
        for (uint32_t x = 0; x < W; ++x) {
            double a = img->rgba[((size_t)y * W + x) * 4 + 3];
            sum += a, sx += a * (x + 0.5), sy += a * (y + 0.5);
        }
    double mx = sum > 0 ? sx / sum : -1, my = sum > 0 ? sy / sum : -1;
    double width = sum > 0 ? sqrt(sum) : 0; /* a square's side in pixels */
    printf("camera %s t=%g: centroid (%.2f, %.2f), want (%.2f, %.2f); side %.2f px, want %.2f\n", it_backends[bi], t, mx,
           my, want, 0.5 * H, width, want_w);
    EXPECT_MSG(fabs(mx - want) < 0.75 && fabs(my - 0.5 * H) < 0.75, "camera %s t=%g: centroid (%.2f, %.2f), want (%.2f, %.2f)",
               it_backends[bi], t, mx, my, want, 0.5 * H);
    EXPECT_MSG(fabs(width - want_w) < 1.0, "camera %s t=%g: side %.2f px, want %.2f (yfov %g)", it_backends[bi], t, width,
               want_w, yfov);
}

static void test_camera(void)
{
    write_gltf("camera.gltf", make_buf(0.5f, (const float[3]){-1, 0, 5}, (const float[3]){1, 0, 5}, 0.8f, 0.6f, 0, 0),
               "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorFactor\":[1,1,1,1]},"
               "\"extensions\":{\"KHR_materials_unlit\":{}}}],\n"
               CAMERA_JSON
               "\"nodes\":[{\"mesh\":0},{\"camera\":0,\"translation\":[-1,0,5]}],\"scenes\":[{\"nodes\":[0,1]}],\"scene\":0,\n"
               "\"animations\":[{\"name\":\"dolly\",\"samplers\":[{\"input\":3,\"output\":4},{\"input\":3,\"output\":5}],"
               "\"channels\":[{\"sampler\":0,\"target\":{\"node\":1,\"path\":\"translation\"}},"
               POINTER_CHANNEL(1, "/cameras/0/perspective/yfov") "]}]");
    rig_sweep("camera.gltf", 16, camera_measure, NULL);
}

/* The lamp's pool of light at t: its brightest column against the lamp's place, the brightness at
 * its foot into foot[bi][ti] (arg: double foot[IT_NBACKENDS][2]). */
static void light_measure(void *arg, int ti, double t, size_t bi, const sy_layer *img)
{
    double(*foot)[2] = arg;
    double lx = -1.5 + 3.0 * t, want = column_of(lx, 0.0, 5.0, 0.8);
    /* the brightest column of the middle rows (luminance summed over 9 rows) */
    double best = -1;
    int best_x = -1;
    for (uint32_t x = 0; x < W; ++x) {
        double c = 0;
        for (uint32_t y = H / 2 - 4; y <= H / 2 + 4; ++y) c += img->rgba[((size_t)y * W + x) * 4 + 1];
        if (c > best) best = c, best_x = (int)x;
    }
    /* the brightness at the foot: the 3 x 3 pixels around the predicted column */
    double f = 0;
    int fx = (int)want;
    for (int y = H / 2 - 1; y <= H / 2 + 1; ++y)
        for (int x = fx - 1; x <= fx + 1; ++x)
            if (x >= 0 && x < W) f += img->rgba[((size_t)y * W + (size_t)x) * 4 + 1];
    foot[bi][ti] = f;
    printf("light %s t=%g: brightest column %d (centre %.1f), want %.2f; foot brightness %.4f\n", it_backends[bi], t, best_x,
           best_x + 0.5, want, f);
    EXPECT_MSG(fabs(best_x + 0.5 - want) <= 2.0, "light %s t=%g: brightest column %d, want %.2f", it_backends[bi], t, best_x,
               want);
}

static void test_light(void)
{
    write_gltf("light.gltf", make_buf(4.0f, (const float[3]){-1.5f, 0, 1}, (const float[3]){1.5f, 0, 1}, 10, 30, 0, 0),
               "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorFactor\":[1,1,1,1],\"metallicFactor\":0,"
               "\"roughnessFactor\":1},\"extensions\":{\"KHR_materials_specular\":{\"specularFactor\":0}}}],\n"
               "\"extensions\":{\"KHR_lights_punctual\":{\"lights\":[{\"type\":\"point\",\"intensity\":10}]}},\n"
               CAMERA_JSON
               "\"nodes\":[{\"mesh\":0},{\"camera\":0,\"translation\":[0,0,5]},"
               "{\"translation\":[-1.5,0,1],\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}}],"
               "\"scenes\":[{\"nodes\":[0,1,2]}],\"scene\":0,\n"
               "\"animations\":[{\"name\":\"sweep\",\"samplers\":[{\"input\":3,\"output\":4},{\"input\":3,\"output\":5}],"
               "\"channels\":[{\"sampler\":0,\"target\":{\"node\":2,\"path\":\"translation\"}},"
               POINTER_CHANNEL(1, "/extensions/KHR_lights_punctual/lights/0/intensity") "]}]");
    double foot[IT_NBACKENDS][2];
    rig_sweep("light.gltf", 64, light_measure, foot);
    for (size_t bi = 0; bi < IT_NBACKENDS; ++bi) {
        double ratio = foot[bi][0] > 0 ? foot[bi][1] / foot[bi][0] : 0, tol = strcmp(it_backends[bi], "pathtracer") ? 0.1 : 0.2;
        printf("light %s: foot brightness t=1 / t=0 = %.3f (want 3)\n", it_backends[bi], ratio);
        EXPECT_MSG(fabs(ratio - 3.0) < 3.0 * tol, "light %s: intensity 10 -> 30 made the foot %.3f x brighter", it_backends[bi],
                   ratio);
    }
}

/* Pointers the clock does not drive: the first named with its channel, the rest counted; the
 * file still loads with its good channel. */
static void test_bad_pointers(void)
{
    write_gltf("pointers.gltf", make_buf(0.5f, (const float[3]){0, 0, 0}, (const float[3]){1, 1, 1}, 0.1f, 0.2f, 0, 0),
               "\"materials\":[{}],\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}],\"scene\":0,\n"
               "\"animations\":[{\"samplers\":[{\"input\":3,\"output\":5},{\"input\":3,\"output\":4}],\"channels\":["
               POINTER_CHANNEL(0, "/materials/0/alphaCutoff") ","
               POINTER_CHANNEL(0, "/cameras/3/perspective/yfov") ","
               "{\"sampler\":0,\"target\":{\"path\":\"pointer\"}},"
               POINTER_CHANNEL(1, "/nodes/0/translation") "]}]");
    char path[512];
    snprintf(path, sizeof path, "%s/pointers.gltf", g_dir);
    sy_gltf_info info;
    sy_scene *s = it_load_gltf(path, &info);
    bool named = false, counted = false;
    for (uint32_t k = 0; k < info.stored_warning_count; k++) {
        named = named || strstr(info.warnings[k], "animations[0].channels[0]: KHR_animation_pointer "
                                                  "'/materials/0/alphaCutoff' is not one the scene clock drives");
        counted = counted || strstr(info.warnings[k], "2 more KHR_animation_pointer channels dropped");
    }
    EXPECT_MSG(named && counted, "bad pointers: the first named (%d), the other two counted (%d)", named, counted);
    sy_animation a = info.animation_count ? info.animations[0] : (sy_animation){0};
    uint32_t nc = 0;
    if (a.id) sy_animation_channels(sy_animation_get(s, a), &nc);
    EXPECT_MSG(nc == 1, "bad pointers: %u channels kept (want the node translation)", nc);
    MUST(sy_scene_set_time(s, a, 0.5, err));
    const sy_node_data *nd = sy_node_get(s, info.root);
    for (uint32_t id = sy_scene_next(s, SY_TYPE_NODE, 0); id; id = sy_scene_next(s, SY_TYPE_NODE, id))
        if (sy_node_get(s, (sy_node){id})->mesh.id) nd = sy_node_get(s, (sy_node){id});
    EXPECT_MSG(nd && fabsf(nd->transform.translation[0] - 0.5f) < 1e-6f, "bad pointers: the pointer translation at 0.5: %g",
               nd ? (double)nd->transform.translation[0] : -1.0);
    sy_gltf_info_free(&info);
    sy_scene_destroy(s);
    remove(path);
}

int main(void)
{
    make_scratch_dir(g_dir, sizeof g_dir, "anim_view");
    it_register();
    test_camera();
    test_light();
    test_bad_pointers();
    remove_scratch_dir(g_dir);
    return sy_check_finish("integration_anim_view");
}
