/* test_rt_mediator_look.c — the rt mediator applies the resolved look (sy_mirror_look) for the
 * "whitted" and "pathtracer" classes, end to end through a window (core -> mediators/rt ->
 * backends/rt). One quad with the glTF default material (base 1, metallic 1, roughness 1) seen
 * from a camera whose corners look past it:
 *   - no world, no light: the built-in studio lights the quad (not black), camera misses are
 *     transparent (the studio is never seen by the camera);
 *   - a world with a colour and default lighting off: the colour is the background (alpha 1) and
 *     lights nothing (the quad is exactly black);
 *   - the same world with default lighting on: studio-lit quad, coloured background;
 *   - a world with a sky/ground gradient: above the horizon the corners show the sky colour, below
 *     the ground colour (baked lat-long texture), and the quad is still studio-lit;
 *   - every look change restarts the path tracer's accumulation. */
#include "../integration/it_util.h"

#define W 32
#define H 24

static float lum(const float *p) { return 0.2126f * p[0] + 0.7152f * p[1] + 0.0722f * p[2]; }

typedef struct fixture {
    sy_scene *s;
    sy_node root, cam;
    sy_background bg;
    sy_window *win[2];
    sy_context_pool *pool;
    sy_layer img;
} fixture;

static const char *const backends[2] = {"whitted", "pathtracer"};

/* Renders with back-end k (path tracer: 16 samples) and returns its sample count. */
static uint64_t render(fixture *fx, int k)
{
    sy_window_render_opts ro = {.sample_count = 16, .seed = 3};
    MUST(sy_window_render(fx->win[k], fx->s, fx->pool, &ro, &fx->img, err));
    sy_context *ctx;
    MUST(sy_context_pool_get(fx->pool, fx->s, backends[k], NULL, fx->root.id, &ctx, err));
    sy_mediator_stats st;
    sy_context_stats(ctx, &st);
    return st.samples;
}

static void set_world(fixture *fx, const float color[4], bool default_lighting, const sy_gradient *g)
{
    sy_background_data bd = *sy_background_get(fx->s, fx->bg);
    bd.name = "world";
    memcpy(bd.color, color, sizeof bd.color);
    bd.default_lighting = default_lighting;
    if (g) bd.gradient = *g;
    else memset(&bd.gradient, 0, sizeof bd.gradient);
    MUST(sy_background_set(fx->s, fx->bg, &bd, err));
    MUST(sy_scene_commit(fx->s, NULL, err));
}

int main(void)
{
    it_register();
    fixture fx;
    memset(&fx, 0, sizeof fx);
    MUST(sy_scene_create(&fx.s, err));
    sy_scene *s = fx.s;
    MUST(sy_node_create(s, "root", &fx.root, err));
    sy_material m;
    MUST(sy_material_create(s, "default", &m, err)); /* glTF defaults: base 1, metallic 1, roughness 1 */
    const float quads[1][3] = {{0, 0, 0.6f}};
    sy_mesh mesh = it_quad_mesh(s, "quad", quads, &m, 1);
    sy_node geo;
    MUST(sy_node_create(s, "geo", &geo, err));
    MUST(sy_node_set_mesh(s, geo, mesh, err));
    fx.cam = it_camera_node(s, "cam", 0, 0, 3.0f, 0.8f);
    MUST(sy_node_add_child(s, fx.root, geo, err));
    MUST(sy_node_add_child(s, fx.root, fx.cam, err));
    MUST(sy_background_create(s, "world", &fx.bg, err));
    MUST(sy_scene_commit(s, NULL, err));
    MUST(sy_context_pool_create(&fx.pool, err));
    MUST(sy_layer_create(W, H, &fx.img, err));
    for (int k = 0; k < 2; ++k) {
        MUST(sy_window_create(W, H, &fx.win[k], err));
        sy_viewport *vp;
        sy_viewport_desc vd = {.root = fx.root, .camera = fx.cam, .backend = backends[k]};
        MUST(sy_window_add_viewport(fx.win[k], &vd, &vp, err));
    }
    const float *centre = it_px(&fx.img, W / 2, H / 2), *top = it_px(&fx.img, 0, 0), *bottom = it_px(&fx.img, 0, H - 1);

    /* 1. no world (the viewports name none): studio lighting, transparent misses */
    for (int k = 0; k < 2; ++k) {
        render(&fx, k);
        EXPECT_MSG(lum(centre) > 0.05f && centre[3] == 1.0f, "%s, no world: quad luminance %g (expected studio-lit)",
                   backends[k], lum(centre));
        EXPECT_MSG(top[0] == 0 && top[1] == 0 && top[2] == 0 && top[3] == 0, "%s, no world: miss %g %g %g %g, expected transparent",
                   backends[k], top[0], top[1], top[2], top[3]);
    }
    /* the viewports now name the world */
    for (int k = 0; k < 2; ++k) {
        sy_window_destroy(fx.win[k]);
        MUST(sy_window_create(W, H, &fx.win[k], err));
        sy_viewport *vp;
        sy_viewport_desc vd = {.root = fx.root, .camera = fx.cam, .background = fx.bg, .backend = backends[k]};
        MUST(sy_window_add_viewport(fx.win[k], &vd, &vp, err));
    }
    const float col[4] = {0.1f, 0.2f, 0.3f, 1.0f};
    /* 2. a coloured world without default lighting: the colour lights nothing */
    set_world(&fx, col, false, NULL);
    for (int k = 0; k < 2; ++k) {
        render(&fx, k);
        EXPECT_MSG(centre[0] == 0 && centre[1] == 0 && centre[2] == 0 && centre[3] == 1.0f,
                   "%s: the background colour lights the quad: %g %g %g %g", backends[k], centre[0], centre[1], centre[2],
                   centre[3]);
        EXPECT_MSG(it_px_is(&fx.img, 0, 0, col[0], col[1], col[2], 1.0f), "%s: background %g %g %g %g, expected the colour",
                   backends[k], top[0], top[1], top[2], top[3]);
    }
    /* 3. default lighting on: studio-lit, coloured background; the path tracer restarts */
    uint64_t before = render(&fx, 1);
    set_world(&fx, col, true, NULL);
    uint64_t after = render(&fx, 1);
    EXPECT_MSG(before == 32 && after == 16, "path tracer samples %llu then %llu: the look change did not restart it",
               (unsigned long long)before, (unsigned long long)after);
    for (int k = 0; k < 2; ++k) {
        render(&fx, k);
        EXPECT_MSG(lum(centre) > 0.05f, "%s, world with default lighting: quad luminance %g", backends[k], lum(centre));
        EXPECT_MSG(it_px_is(&fx.img, 0, 0, col[0], col[1], col[2], 1.0f), "%s: background %g %g %g %g", backends[k], top[0],
                   top[1], top[2], top[3]);
    }
    /* 4. a sky/ground gradient: camera misses above and below the horizon */
    sy_gradient g;
    memset(&g, 0, sizeof g);
    g.sky_count = 1, g.ground_count = 1;
    g.sky_color[0][0] = 0.2f, g.sky_color[0][1] = 0.4f, g.sky_color[0][2] = 0.8f;
    g.ground_color[0][0] = 0.3f, g.ground_color[0][1] = 0.2f, g.ground_color[0][2] = 0.1f;
    set_world(&fx, col, true, &g);
    for (int k = 0; k < 2; ++k) {
        render(&fx, k);
        EXPECT_MSG(fabsf(top[0] - 0.2f) < 1e-3f && fabsf(top[1] - 0.4f) < 1e-3f && fabsf(top[2] - 0.8f) < 1e-3f && top[3] == 1.0f,
                   "%s: sky %g %g %g %g, expected 0.2 0.4 0.8 1", backends[k], top[0], top[1], top[2], top[3]);
        EXPECT_MSG(fabsf(bottom[0] - 0.3f) < 1e-3f && fabsf(bottom[1] - 0.2f) < 1e-3f && fabsf(bottom[2] - 0.1f) < 1e-3f &&
                   bottom[3] == 1.0f,
                   "%s: ground %g %g %g %g, expected 0.3 0.2 0.1 1", backends[k], bottom[0], bottom[1], bottom[2], bottom[3]);
        EXPECT_MSG(lum(centre) > 0.05f, "%s, gradient world: quad luminance %g", backends[k], lum(centre));
    }
    sy_layer_destroy(&fx.img);
    for (int k = 0; k < 2; ++k) sy_window_destroy(fx.win[k]);
    sy_context_pool_destroy(fx.pool);
    sy_scene_destroy(fx.s);
    return sy_check_finish("rt_mediator_look");
}
