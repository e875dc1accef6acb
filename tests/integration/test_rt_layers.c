/* test_rt_layers.c — the glTF material layers end to end through the rt mediator (core material ->
 * mirror's flat description -> sy_mediator_rt_mirror.c -> rt back-end -> "whitted" image): a quad
 * built in code under a point light at the eye, each extension on and off.
 *   - KHR_materials_sheen: a black quad (base colour 0, specular 0) tilted 75 degrees from the view
 *     is black (mean below 0.001); a white sheen (roughness 0.5) lights it (mean above 0.01: the
 *     Charlie lobe near grazing);
 *   - KHR_materials_iridescence: a black dielectric quad facing the eye (roughness 0.3) shows a
 *     grey highlight (channels within 2 %); a 400 nm film (weight 1, IOR 1.3) colours it (largest
 *     channel at least 1.2x the smallest). */
#include "it_util.h"

#define W 64
#define H 64

/* Mean colour of the whitted render of the scene under root. */
static void render_mean(sy_scene *s, sy_node root, double out[3])
{
    sy_context *ctx;
    MUST(sy_context_create(s, "whitted", NULL, root.id, &ctx, err));
    MUST(sy_context_sync(ctx, err));
    sy_render_request req;
    memset(&req, 0, sizeof req);
    req.camera = it_view_down_z(4.0f, 0.3f);
    req.full_width = req.rect_w = W;
    req.full_height = req.rect_h = H;
    sy_layer img;
    MUST(sy_layer_create(W, H, &img, err));
    MUST(sy_context_render(ctx, &req, &img, err));
    out[0] = out[1] = out[2] = 0.0;
    for (uint32_t y = 0; y < H; ++y)
        for (uint32_t x = 0; x < W; ++x)
            for (int c = 0; c < 3; ++c) out[c] += it_px(&img, x, y)[c] / (double)(W * H);
    sy_layer_destroy(&img);
    sy_context_release(ctx);
}

/* A scene of one quad (half-size 1.2 at the origin, tilted by `tilt` radians about X) of material
 * data d and a point light at the eye (0, 0, 4); returns its root. */
static sy_scene *quad_scene(const sy_material_data *d, float tilt, sy_node *root)
{
    sy_scene *s = it_scene();
    sy_material m;
    MUST(sy_material_create(s, "layered", &m, err));
    MUST(sy_material_set(s, m, d, err));
    const float quad[1][3] = {{0.0f, 0.0f, 1.2f}};
    sy_mesh mesh = it_quad_mesh(s, "quad", quad, &m, 1);
    sy_node n, ln;
    MUST(sy_node_create(s, "root", root, err));
    MUST(sy_node_create(s, "quad", &n, err));
    MUST(sy_node_set_mesh(s, n, mesh, err));
    const float t[3] = {0, 0, 0}, q[4] = {sinf(0.5f * tilt), 0, 0, cosf(0.5f * tilt)}, one[3] = {1, 1, 1};
    MUST(sy_node_set_trs(s, n, t, q, one, err));
    MUST(sy_node_add_child(s, *root, n, err));
    sy_light lamp = it_light(s, "eye", SY_LIGHT_POINT, 20.0f);
    MUST(sy_node_create(s, "eye", &ln, err));
    MUST(sy_node_set_light(s, ln, lamp, err));
    it_set_translation(s, ln, 0, 0, 4.0f);
    MUST(sy_node_add_child(s, *root, ln, err));
    MUST(sy_scene_commit(s, NULL, err));
    return s;
}

static sy_material_data black_dielectric(float roughness, float specular)
{
    sy_scene *s = it_scene();
    sy_material_data d = *sy_material_get(s, (sy_material){0}); /* the defaults */
    sy_scene_destroy(s);
    d.base_color[0] = d.base_color[1] = d.base_color[2] = 0.0f;
    d.metallic = 0.0f, d.roughness = roughness, d.specular = specular;
    return d;
}

int main(void)
{
    it_register();
    for (int on = 0; on < 2; ++on) {
        sy_material_data d = black_dielectric(1.0f, 0.0f);
        if (on) d.sheen_color[0] = d.sheen_color[1] = d.sheen_color[2] = 1.0f, d.sheen_roughness = 0.5f;
        sy_node root;
        sy_scene *s = quad_scene(&d, 75.0f * 3.14159265f / 180.0f, &root);
        double m[3];
        render_mean(s, root, m);
        printf("sheen %s: mean %.5f %.5f %.5f\n", on ? "on" : "off", m[0], m[1], m[2]);
        if (on) EXPECT_MSG(m[1] > 0.01, "sheen: the tilted black quad stays dark (%.5f)", m[1]);
        else EXPECT_MSG(m[1] < 0.001, "no sheen: the black quad shows %.5f", m[1]);
        sy_scene_destroy(s);
    }
    for (int on = 0; on < 2; ++on) {
        sy_material_data d = black_dielectric(0.3f, 1.0f);
        if (on) d.iridescence = 1.0f, d.iridescence_ior = 1.3f, d.iridescence_thickness[1] = 400.0f;
        sy_node root;
        sy_scene *s = quad_scene(&d, 0.0f, &root);
        double m[3];
        render_mean(s, root, m);
        double hi = fmax(m[0], fmax(m[1], m[2])), lo = fmin(m[0], fmin(m[1], m[2]));
        printf("iridescence %s: mean %.5f %.5f %.5f\n", on ? "on" : "off", m[0], m[1], m[2]);
        EXPECT_MSG(lo > 0.0, "iridescence %s: no highlight", on ? "on" : "off");
        if (on) EXPECT_MSG(hi > 1.2 * lo, "iridescence: the highlight stays grey (%.5f %.5f %.5f)", m[0], m[1], m[2]);
        else EXPECT_MSG(hi < 1.02 * lo, "no iridescence: the highlight is coloured (%.5f %.5f %.5f)", m[0], m[1], m[2]);
        sy_scene_destroy(s);
    }
    return sy_check_finish("integration_rt_layers");
}
