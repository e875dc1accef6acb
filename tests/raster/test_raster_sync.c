/* test_raster_sync.c — the raster mediator through core: incremental sync from change lists
 * (a transform-only change uploads no vertex data, a material change is one uniform-buffer update,
 * a new mesh one upload of its buffers), exact emission of the Cornell light (17 12 4) in the float
 * layer, the Cornell walls and floor lit by that light within 20 % of the path tracer and still
 * lit after the light moves (a transform update keeps its area light), parameter errors, and a
 * textured emitter whose texture glows on one half: its area lights are that half (the floor under
 * it as much brighter than under the dark half as the path tracer says), and frames that do not
 * depend on the smaller frames drawn before them. */
#include "it_util.h"
#include "sy_demo.h"
#include "sy_gltf.h"
#include "sy_mediator_raster.h"

#define W 64
#define H 64

static void render(sy_context *ctx, const sy_camera_view *v, sy_layer *img)
{
    sy_render_request rq = {.camera = *v, .full_width = W, .full_height = H, .rect_w = W, .rect_h = H};
    MUST(sy_context_sync(ctx, err));
    MUST(sy_context_render(ctx, &rq, img, err));
}

static void incremental(void)
{
    sy_scene *s;
    MUST(sy_scene_create(&s, err));
    sy_material lit;
    MUST(sy_material_create(s, "lit", &lit, err));
    sy_material unlit = it_unlit(s, "red", 1, 0, 0);
    const float q[2][3] = {{-0.5f, 0, 0.4f}, {0.6f, 0, 0.3f}};
    sy_material mats[1] = {lit};
    sy_mesh ma = it_quad_mesh(s, "a", &q[0], mats, 1);
    mats[0] = unlit;
    sy_mesh mb = it_quad_mesh(s, "b", &q[1], mats, 1);
    sy_node root, na, nb, nl;
    MUST(sy_node_create(s, "root", &root, err));
    MUST(sy_node_create(s, "a", &na, err));
    MUST(sy_node_create(s, "b", &nb, err));
    MUST(sy_node_create(s, "light", &nl, err));
    MUST(sy_node_set_mesh(s, na, ma, err));
    MUST(sy_node_set_mesh(s, nb, mb, err));
    sy_light l = it_light(s, "sun", SY_LIGHT_DIRECTIONAL, 2.0f);
    MUST(sy_node_set_light(s, nl, l, err));
    MUST(sy_node_add_child(s, root, na, err));
    MUST(sy_node_add_child(s, root, nb, err));
    MUST(sy_node_add_child(s, root, nl, err));
    MUST(sy_scene_commit(s, NULL, err));

    sy_params p;
    MUST(sy_params_parse("msaa=1,shadow_map_size=256", &p, err));
    sy_context *ctx;
    MUST(sy_context_create(s, "raster", &p, root.id, &ctx, err));
    void *st = sy_context_state(ctx);
    sy_camera_view v = it_view_down_z(3.0f, 0.5f);
    sy_layer img, img2;
    MUST(sy_layer_create(W, H, &img, err));
    MUST(sy_layer_create(W, H, &img2, err));
    render(ctx, &v, &img);
    sy_mediator_raster_counters c;
    sy_mediator_raster_counters_get(st, &c);
    EXPECT_MSG(c.meshes == 2 && c.instances == 2 && c.lights == 1, "meshes %u instances %u lights %u", c.meshes, c.instances, c.lights);
    EXPECT_MSG(c.vertex_buffer_uploads == 4, "first frame vertex uploads %llu (2 x vertex + index buffer)",
               (unsigned long long)c.vertex_buffer_uploads);
    float pa[3] = {-0.5f, 0, 0}, x, y;
    it_project(&v, pa, W, H, &x, &y);
    const float *red = it_px(&img, (uint32_t)(0.6f / 0.5f / 3.0f * W / 2 + W / 2), H / 2);
    EXPECT_MSG(red[0] == 1.0f && red[1] == 0.0f && red[3] == 1.0f, "unlit quad %g %g %g %g", red[0], red[1], red[2], red[3]);
    float before = it_px(&img, (uint32_t)x, (uint32_t)y)[0];
    EXPECT_MSG(before > 0.0f, "lit quad is black");

    /* transform only: one model-matrix update per moved instance, no vertex data */
    it_set_translation(s, na, 0, 0.05f, 0);
    MUST(sy_scene_commit(s, NULL, err));
    render(ctx, &v, &img2);
    sy_mediator_raster_counters_get(st, &c);
    EXPECT_MSG(c.vertex_buffer_uploads == 0 && c.vertex_bytes == 0 && c.texture_uploads == 0,
               "transform-only change uploaded %llu vertex buffers (%llu bytes)", (unsigned long long)c.vertex_buffer_uploads,
               (unsigned long long)c.vertex_bytes);
    EXPECT_MSG(c.model_matrix_updates == 1 && c.last_sync_placements == 1, "model matrices %llu, placements %u",
               (unsigned long long)c.model_matrix_updates, c.last_sync_placements);
    EXPECT(!it_layers_identical(&img, &img2));

    /* material change: one uniform-buffer update */
    sy_material_data md = *sy_material_get(s, lit);
    md.base_color[1] = 0.25f;
    MUST(sy_material_set(s, lit, &md, err));
    MUST(sy_scene_commit(s, NULL, err));
    render(ctx, &v, &img2);
    sy_mediator_raster_counters_get(st, &c);
    EXPECT_MSG(c.uniform_buffer_uploads == 1 && c.vertex_buffer_uploads == 0 && c.model_matrix_updates == 0,
               "material change: %llu UBO, %llu VBO, %llu matrices", (unsigned long long)c.uniform_buffer_uploads,
               (unsigned long long)c.vertex_buffer_uploads, (unsigned long long)c.model_matrix_updates);

    /* a new mesh: one upload of its buffers */
    const float q3[1][3] = {{0, 0.7f, 0.1f}};
    mats[0] = unlit;
    sy_mesh mc = it_quad_mesh(s, "c", q3, mats, 1);
    sy_node nc;
    MUST(sy_node_create(s, "c", &nc, err));
    MUST(sy_node_set_mesh(s, nc, mc, err));
    MUST(sy_node_add_child(s, root, nc, err));
    MUST(sy_scene_commit(s, NULL, err));
    render(ctx, &v, &img2);
    sy_mediator_raster_counters_get(st, &c);
    EXPECT_MSG(c.vertex_buffer_uploads == 2 && c.meshes == 3 && c.instances == 3, "new mesh: %llu vertex uploads, %u meshes",
               (unsigned long long)c.vertex_buffer_uploads, c.meshes);

    /* unknown provider / malformed parameters */
    sy_context *bad = NULL;
    sy_params bp;
    MUST(sy_params_parse("gl=vulkan", &bp, err));
    sy_error e = {0};
    EXPECT(sy_context_create(s, "raster", &bp, root.id, &bad, &e) != SY_OK && strstr(e.message, "gl=vulkan"));
    MUST(sy_params_parse("msaa=0", &bp, err));
    EXPECT(sy_context_create(s, "raster", &bp, root.id, &bad, &e) != SY_OK && strstr(e.message, "msaa"));

    sy_layer_destroy(&img);
    sy_layer_destroy(&img2);
    sy_context_release(ctx);
    sy_scene_destroy(s);
}

static void cornell(void)
{
    char buf[1024];
    const char *path = it_testdata("cornell/cornell_box.gltf", buf, sizeof buf);
    sy_scene *scene;
    MUST(sy_scene_create(&scene, err));
    sy_gltf_info info;
    MUST(sy_gltf_load(path, scene, NULL, &info, err));
    sy_node cam;
    MUST(sy_gltf_find_camera(scene, &info, "camera", &cam, err));
    MUST(sy_scene_commit(scene, NULL, err));
    sy_context_pool *pool;
    MUST(sy_context_pool_create(&pool, err));
    sy_viewport_desc vd = {.root = info.root, .camera = cam, .backend = "raster", .params = "msaa=4,shadow_map_size=512"};
    sy_window *win = it_window(W, H, &vd, NULL);
    sy_layer img;
    MUST(sy_layer_create(W, H, &img, err));
    MUST(sy_window_render(win, scene, pool, NULL, &img, err));
    uint32_t exact = 0;
    for (uint32_t i = 0; i < W * H; ++i) {
        const float *p = img.rgba + 4 * i;
        if (p[0] == 17.0f && p[1] == 12.0f && p[2] == 4.0f && p[3] == 1.0f) exact++;
        EXPECT_MSG(p[0] <= 17.0f && p[1] <= 12.0f && p[2] <= 4.0f, "pixel %u brighter than the light: %g %g %g", i, p[0], p[1], p[2]);
        if (!(p[0] <= 17.0f)) break;
    }
    EXPECT_MSG(exact >= 4, "only %u pixels show exactly the light's radiance 17 12 4", exact);
    EXPECT(sy_layer_count_nonfinite(&img) == 0);
    /* lit by its ceiling panel alone (area light, LTC + soft shadow + the indirect estimate): the
     * mean luminance of regions of the back wall, the side walls and the floor within 20 % of the
     * path tracer's (256 spp, 256 x 256, measured with tests/raster/raster_measure) */
    static const struct { const char *name; float x0, y0, x1, y1, want; } regions[] = {
        {"back wall", 0.3f, 0.2f, 0.7f, 0.35f, 0.1214f},
        {"left wall", 0.03f, 0.25f, 0.12f, 0.6f, 0.04367f},
        {"right wall", 0.88f, 0.25f, 0.97f, 0.6f, 0.06796f},
        {"floor", 0.1f, 0.88f, 0.45f, 0.96f, 0.1094f},
    };
    for (size_t k = 0; k < sizeof regions / sizeof regions[0]; ++k) {
        double sum = 0.0;
        uint32_t n = 0;
        for (uint32_t y = (uint32_t)(regions[k].y0 * H); y < (uint32_t)(regions[k].y1 * H); ++y)
            for (uint32_t x = (uint32_t)(regions[k].x0 * W); x < (uint32_t)(regions[k].x1 * W); ++x, ++n) {
                const float *p = it_px(&img, x, y);
                sum += 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
            }
        double mean = n ? sum / n : 0.0, ratio = mean / regions[k].want;
        printf("cornell %-10s mean luminance %.4f, path tracer %.4f, ratio %.3f\n", regions[k].name, mean, regions[k].want, ratio);
        EXPECT_MSG(ratio > 0.8 && ratio < 1.2, "Cornell %s: mean luminance %.4f, the path tracer's %.4f (ratio %.3f)", regions[k].name,
                   mean, regions[k].want, ratio);
    }
    const float *mid = it_px(&img, W / 2, H / 2);
    float dmid = img.depth[(H / 2) * W + W / 2];
    EXPECT_MSG(mid[3] == 1.0f && isfinite(dmid) && dmid > 0.0f, "centre alpha %g depth %g", mid[3], dmid);
    /* the light moved a hair (a transform-only change): the room stays lit. The mediator's instance
     * table used to drop an instance's mesh and material on a transform update, so a moved
     * emitter lost its area light and the walls went dark */
    double before = 0.0, after = 0.0;
    for (uint32_t i = 0; i < W * H; ++i) before += img.rgba[4 * i + 1];
    sy_node light = {0};
    for (uint32_t id = sy_scene_next(scene, SY_TYPE_NODE, 0); id; id = sy_scene_next(scene, SY_TYPE_NODE, id)) {
        const sy_node_data *nd = sy_node_get(scene, (sy_node){id});
        if (nd && nd->name && !strcmp(nd->name, "light")) light.id = id;
    }
    EXPECT(light.id != 0);
    it_set_translation(scene, light, 1e-4f, 0.0f, 0.0f);
    MUST(sy_scene_commit(scene, NULL, err));
    MUST(sy_window_render(win, scene, pool, NULL, &img, err));
    for (uint32_t i = 0; i < W * H; ++i) after += img.rgba[4 * i + 1];
    printf("cornell: green channel sum %.2f before, %.2f after the light moved 0.1 mm\n", before, after);
    EXPECT_MSG(fabs(after - before) < 0.02 * before, "the light moved 0.1 mm: the image's green sum went %.2f -> %.2f",
               before, after);
    sy_layer_destroy(&img);
    sy_window_destroy(win);
    sy_context_pool_destroy(pool);
    sy_gltf_info_free(&info);
    sy_scene_destroy(scene);
}

/* A panel facing down at height 1 over a white Lambert floor, its emission textured: black on its
 * left half (x < 0), white on its right. Seen from between them, looking down at the floor: the
 * ratio of the floor's luminance at x = +0.35 and x = -0.35 against the path tracer's (which
 * evaluates the texture where its light samples land). The area lights took the texture's mean
 * over the whole panel before (a ratio of 1.00 against the path tracer's 1.49). */
static void textured_emitter(void)
{
    sy_scene *s;
    MUST(sy_scene_create(&s, err));
    enum { TW = 64 }; /* wide enough that the filtered step between the halves is a sliver */
    unsigned char px[TW * 3];
    for (int i = 0; i < TW * 3; ++i) px[i] = i < TW * 3 / 2 ? 0 : 255;
    sy_texture tex;
    MUST(sy_texture_create(s, "glow", &tex, err));
    sy_image_info ii = {.width = TW, .height = 1, .channels = 3, .format = SY_PIXEL_U8_LINEAR};
    sy_blob *pb = it_blob(px, sizeof px);
    MUST(sy_texture_set_image(s, tex, &ii, pb, err));
    sy_blob_release(pb);
    sy_material lamp;
    MUST(sy_material_create(s, "lamp", &lamp, err));
    sy_material_data d = *sy_material_get(s, lamp);
    d.name = "lamp";
    d.base_color[0] = d.base_color[1] = d.base_color[2] = 0.0f;
    d.emissive[0] = d.emissive[1] = d.emissive[2] = 1.0f;
    d.emissive_strength = 4.0f;
    d.emissive_texture.texture = tex;
    MUST(sy_material_set(s, lamp, &d, err));
    sy_material floor_m = it_lambert(s, "floor", 0.8f, 0.8f, 0.8f);
    /* the panel: two quads facing -y (counter-clockwise seen from below), u 0 .. 0.5 on the left */
    const float ppos[18] = {-1, 1, -0.5f, 0, 1, -0.5f, 1, 1, -0.5f, -1, 1, 0.5f, 0, 1, 0.5f, 1, 1, 0.5f};
    const float puv[12] = {0, 0, 0.5f, 0, 1, 0, 0, 1, 0.5f, 1, 1, 1};
    const uint32_t pidx[12] = {0, 1, 4, 0, 4, 3, 1, 2, 5, 1, 5, 4};
    const float fpos[12] = {-2, 0, -2, -2, 0, 2, 2, 0, 2, 2, 0, -2}, fnrm[12] = {0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0};
    const uint32_t fidx[6] = {0, 1, 2, 0, 2, 3};
    sy_primitive pp = {0}, fp = {0};
    pp.positions = it_blob(ppos, sizeof ppos), pp.texcoords0 = it_blob(puv, sizeof puv), pp.indices = it_blob(pidx, sizeof pidx);
    pp.material = lamp;
    fp.positions = it_blob(fpos, sizeof fpos), fp.normals = it_blob(fnrm, sizeof fnrm), fp.indices = it_blob(fidx, sizeof fidx);
    fp.material = floor_m;
    sy_mesh mp, mf;
    MUST(sy_mesh_create(s, "panel", &mp, err));
    MUST(sy_mesh_set_primitives(s, mp, &pp, 1, err));
    MUST(sy_mesh_create(s, "floor", &mf, err));
    MUST(sy_mesh_set_primitives(s, mf, &fp, 1, err));
    sy_primitive_release(&pp), sy_primitive_release(&fp);
    sy_node root, np, nf;
    MUST(sy_node_create(s, "root", &root, err));
    MUST(sy_node_create(s, "panel", &np, err));
    MUST(sy_node_create(s, "floor", &nf, err));
    MUST(sy_node_set_mesh(s, np, mp, err));
    MUST(sy_node_set_mesh(s, nf, mf, err));
    MUST(sy_node_add_child(s, root, np, err));
    MUST(sy_node_add_child(s, root, nf, err));
    MUST(sy_scene_commit(s, NULL, err));
    /* from (0, 0.5, 0) looking down -y: camera x = world x, camera y = world -z */
    sy_camera_view v = it_view_down_z(0.0f, 1.0f);
    const float c2w[16] = {1, 0, 0, 0, 0, 0, -1, 0, 0, 1, 0, 0, 0, 0.5f, 0, 1};
    memcpy(v.camera_to_world.m, c2w, sizeof c2w);
    double ratio[2] = {0, 0};
    static const char *const names[2] = {"raster", "pathtracer"};
    for (int b = 0; b < 2; ++b) {
        sy_params prm;
        MUST(sy_params_parse(b == 0 ? "indirect=0" : "", &prm, err)); /* direct light: where it comes from */
        sy_context *ctx;
        MUST(sy_context_create(s, names[b], &prm, root.id, &ctx, err));
        MUST(sy_context_sync(ctx, err));
        sy_layer img;
        MUST(it_render_full(ctx, &v, W, H, b ? 256 : 0, &img, err));
        double side[2] = {0, 0}; /* x = -0.35 and +0.35: columns 0.325 W and 0.675 W, +- 3 pixels */
        for (int k = 0; k < 2; ++k)
            for (int y = H / 2 - 3; y < H / 2 + 3; ++y)
                for (int x = (int)((k ? 0.675 : 0.325) * W) - 3; x < (int)((k ? 0.675 : 0.325) * W) + 3; ++x) {
                    const float *q = it_px(&img, (uint32_t)x, (uint32_t)y);
                    side[k] += 0.2126 * q[0] + 0.7152 * q[1] + 0.0722 * q[2];
                }
        ratio[b] = side[0] > 0.0 ? side[1] / side[0] : 0.0;
        printf("textured emitter, %s: floor under the glowing half / under the dark half = %.3f (%.4f / %.4f)\n", names[b],
               ratio[b], side[1] / 36.0, side[0] / 36.0);
        sy_layer_destroy(&img);
        sy_context_release(ctx);
    }
    EXPECT_MSG(ratio[1] > 1.3, "the path tracer's floor ratio %.3f: the scene does not test what it should", ratio[1]);
    EXPECT_MSG(fabs(ratio[0] / ratio[1] - 1.0) < 0.15,
               "a textured emitter lights as its texture says: the raster's floor ratio %.3f, the path tracer's %.3f", ratio[0],
               ratio[1]);
    sy_scene_destroy(s);
}

/* A frame does not depend on the smaller frames before it: the demo (shadow-casting lights, a mirror
 * sphere's probe, meshes with levels of detail) with its mirror sphere selected, through a window
 * resized to half size and back after each change (as a web view's moving frame before it refines:
 * the selection, the sphere hidden, shown again) is bit for bit a fresh window's frame of the
 * same scene. */
static void history_free(void)
{
    sy_scene *s;
    MUST(sy_scene_create(&s, err));
    sy_demo_info d;
    MUST(sy_demo_build(s, &d, err));
    MUST(sy_scene_commit(s, NULL, err));
    enum { FW = 480, FH = 300 };
    sy_viewport_desc vd = {.root = d.root, .camera = d.camera, .background = d.background, .backend = "raster"};
    /* the mirror sphere (the demo's root's child of that name) selected */
    sy_node mirror = {0};
    uint32_t nc = 0;
    const uint32_t *ch = sy_node_children(sy_node_get(s, d.root), &nc);
    for (uint32_t i = 0; i < nc; ++i) {
        const sy_node_data *nd = sy_node_get(s, (sy_node){ch[i]});
        if (nd && nd->name && !strcmp(nd->name, "mirror sphere")) mirror.id = ch[i];
    }
    EXPECT(mirror.id != 0);
    MUST(sy_node_set_selected(s, mirror, true, err));
    MUST(sy_scene_commit(s, NULL, err));
    sy_layer img[2], small;
    for (int k = 0; k < 2; ++k) {
        sy_context_pool *pool;
        MUST(sy_context_pool_create(&pool, err));
        sy_window *ww = it_window(FW, FH, &vd, NULL);
        /* k = 1: hidden, shown again; each change drawn small first (as a web view's moving frame) */
        for (int step = 0; k == 1 && step < 3; ++step) {
            if (step) {
                MUST(sy_node_set_visible(s, mirror, step == 2, err));
                MUST(sy_scene_commit(s, NULL, err));
            }
            MUST(sy_window_resize(ww, FW / 2, FH / 2, err));
            MUST(sy_layer_create(FW / 2, FH / 2, &small, err));
            MUST(sy_window_render(ww, s, pool, NULL, &small, err));
            sy_layer_destroy(&small);
            MUST(sy_window_resize(ww, FW, FH, err));
            MUST(sy_layer_create(FW, FH, &small, err));
            MUST(sy_window_render(ww, s, pool, NULL, &small, err));
            sy_layer_destroy(&small);
        }
        MUST(sy_layer_create(FW, FH, &img[k], err));
        MUST(sy_window_render(ww, s, pool, NULL, &img[k], err));
        sy_window_destroy(ww);
        sy_context_pool_destroy(pool);
    }
    size_t n = (size_t)FW * FH, diff = 0;
    for (size_t i = 0; i < n; ++i) diff += memcmp(img[0].rgba + 4 * i, img[1].rgba + 4 * i, 4 * sizeof(float)) != 0;
    printf("history: %zu of %zu pixels differ after half-size frames, a hide and a show\n", diff, n);
    EXPECT_MSG(diff == 0, "a frame after a smaller one differs from a fresh one in %zu pixels", diff);
    sy_layer_destroy(&img[0]), sy_layer_destroy(&img[1]);
    sy_scene_destroy(s);
}

int main(void)
{
    it_register();
    history_free();
    incremental();
    cornell();
    textured_emitter();
    return sy_check_finish("raster_sync");
}
