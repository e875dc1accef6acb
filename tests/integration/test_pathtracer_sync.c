/* test_pathtracer_sync.c — accumulation restart semantics of the "pathtracer" mediator class.
 *
 * A scene (emissive quad, grey quad, point light, a camera node in use and one nobody uses, a
 * background) is rendered one sample per call through a window; sy_mediator_stats.samples must
 *   - grow by the request's sample_count on each render (0 = 1);
 *   - restart (back to the new pass's count) after: a transform of a node with geometry, a
 *     material change, a light change, a background change, the request's camera changing
 *     (moving the viewport's camera node), a new mesh;
 *   - NOT restart after: an attachment change, moving the camera no viewport uses.
 * Switching the viewport to whitted and back resumes the accumulation (cached context, nothing
 * changed). The image after a restart equals a fresh context's image of the changed scene bit for bit (no
 * stale samples), AOVs come back for the viewport rectangle, and nothing is non-finite. With
 * temporal=1 a panning view shows the temporal estimate (not the accumulation), a view that rests
 * after it the accumulation blended with the estimate, and from 64 samples on the accumulation bit
 * for bit; temporal=0 shows the plain samples again. */
#include "it_util.h"
#include "sy_mediator_rt.h"

typedef struct fixture {
    sy_scene *s;
    sy_node root, geo, lamp_node, cam_node, spare_cam;
    sy_material grey, glow;
    sy_light lamp;
    sy_background bg;
    sy_window *win;
    sy_context_pool *pool;
    sy_layer img;
} fixture;

static uint64_t render(fixture *fx, uint32_t n)
{
    sy_window_render_opts ro = {.sample_count = n, .seed = 9};
    MUST(sy_window_render(fx->win, fx->s, fx->pool, &ro, &fx->img, err));
    sy_context *ctx;
    MUST(sy_context_pool_get(fx->pool, fx->s, "pathtracer", NULL, fx->root.id, &ctx, err));
    sy_mediator_stats st;
    sy_context_stats(ctx, &st);
    return st.samples;
}

static void commit(fixture *fx) { MUST(sy_scene_commit(fx->s, NULL, err)); }

/* Commits a change the accumulation must restart on: the next render is its first sample, the one
 * after it its second. */
static void expect_restart(fixture *fx, const char *change)
{
    commit(fx);
    EXPECT_MSG(render(fx, 1) == 1, "%s did not restart", change);
    EXPECT_MSG(render(fx, 1) == 2, "%s: no accumulation after the restart", change);
}

static void build(fixture *fx)
{
    memset(fx, 0, sizeof *fx);
    MUST(sy_scene_create(&fx->s, err));
    sy_scene *s = fx->s;
    MUST(sy_node_create(s, "root", &fx->root, err));
    MUST(sy_material_create(s, "grey", &fx->grey, err));
    MUST(sy_material_create(s, "glow", &fx->glow, err));
    sy_material_data md = *sy_material_get(s, fx->glow);
    md.name = "glow";
    md.emissive[0] = md.emissive[1] = md.emissive[2] = 1.0f;
    md.emissive_strength = 3.0f;
    MUST(sy_material_set(s, fx->glow, &md, err));
    const float quads[2][3] = {{0, 0, 1.0f}, {0.6f, 0.6f, 0.2f}};
    const sy_material mats[2] = {fx->grey, fx->glow};
    sy_mesh mesh = it_quad_mesh(s, "quads", quads, mats, 2);
    MUST(sy_node_create(s, "geo", &fx->geo, err));
    MUST(sy_node_set_mesh(s, fx->geo, mesh, err));
    MUST(sy_light_create(s, "lamp", &fx->lamp, err));
    MUST(sy_node_create(s, "lamp", &fx->lamp_node, err));
    MUST(sy_node_set_light(s, fx->lamp_node, fx->lamp, err));
    it_set_translation(s, fx->lamp_node, 0, 0, 1);
    fx->cam_node = it_camera_node(s, "cam", 0, 0, 3.0f, 0.8f);
    fx->spare_cam = it_camera_node(s, "spare", 0, 0, 5.0f, 0.8f);
    MUST(sy_node_add_child(s, fx->root, fx->geo, err));
    MUST(sy_node_add_child(s, fx->root, fx->lamp_node, err));
    MUST(sy_node_add_child(s, fx->root, fx->cam_node, err));
    MUST(sy_node_add_child(s, fx->root, fx->spare_cam, err));
    MUST(sy_background_create(s, "bg", &fx->bg, err));
    sy_background_data bd = *sy_background_get(s, fx->bg);
    bd.name = "bg";
    bd.color[0] = 0.1f, bd.color[1] = 0.2f, bd.color[2] = 0.3f, bd.color[3] = 1.0f;
    MUST(sy_background_set(s, fx->bg, &bd, err));
    commit(fx);
    sy_viewport_desc vd = {.root = fx->root, .camera = fx->cam_node, .background = fx->bg, .backend = "pathtracer"};
    fx->win = it_window(32, 24, &vd, NULL);
    MUST(sy_context_pool_create(&fx->pool, err));
    MUST(sy_layer_create(32, 24, &fx->img, err));
}

static void destroy(fixture *fx)
{
    sy_layer_destroy(&fx->img);
    sy_context_pool_destroy(fx->pool);
    sy_window_destroy(fx->win);
    sy_scene_destroy(fx->s);
}

int main(void)
{
    it_register();
    fixture fx;
    build(&fx);
    sy_scene *s = fx.s;
    EXPECT(render(&fx, 0) == 1);
    EXPECT(render(&fx, 1) == 2);
    EXPECT(render(&fx, 3) == 5);
    EXPECT(sy_layer_count_nonfinite(&fx.img) == 0);

    /* invisible: attachment, name, the unused camera */
    sy_attachment att = {.key = "pt.hint", .kind = SY_ATTACH_INT, .value.i = 3};
    MUST(sy_object_set_attachment(s, SY_TYPE_NODE, fx.geo.id, &att, err));
    commit(&fx);
    EXPECT_MSG(render(&fx, 1) == 6, "an attachment change restarted the accumulation");
    it_set_translation(s, fx.spare_cam, 1, 2, 7);
    commit(&fx);
    EXPECT_MSG(render(&fx, 1) == 7, "moving a camera no viewport uses restarted the accumulation");

    /* visible changes restart */
    it_set_translation(s, fx.geo, 0.1f, 0, 0);
    commit(&fx);
    EXPECT_MSG(render(&fx, 2) == 2, "a transform change did not restart");
    /* the restarted image equals a fresh context's render of the changed scene */
    float *after = malloc(32 * 24 * 4 * sizeof(float));
    memcpy(after, fx.img.rgba, 32 * 24 * 4 * sizeof(float));
    {
        sy_context_pool *p2;
        MUST(sy_context_pool_create(&p2, err));
        sy_layer l2;
        MUST(sy_layer_create(32, 24, &l2, err));
        sy_window_render_opts ro = {.sample_count = 2, .seed = 9};
        MUST(sy_window_render(fx.win, s, p2, &ro, &l2, err));
        EXPECT_MSG(!memcmp(l2.rgba, after, 32 * 24 * 4 * sizeof(float)), "restarted image differs from a fresh render");
        sy_layer_destroy(&l2);
        sy_context_pool_destroy(p2);
    }
    free(after);

    sy_material_data md = *sy_material_get(s, fx.grey);
    md.base_color[0] = 0.3f;
    MUST(sy_material_set(s, fx.grey, &md, err));
    expect_restart(&fx, "a material change");

    sy_light_data ld = *sy_light_get(s, fx.lamp);
    ld.intensity = 5.0f;
    MUST(sy_light_set(s, fx.lamp, &ld, err));
    expect_restart(&fx, "a light change");

    sy_background_data bd = *sy_background_get(s, fx.bg);
    bd.color[1] = 0.7f;
    MUST(sy_background_set(s, fx.bg, &bd, err));
    expect_restart(&fx, "a background change");

    it_set_translation(s, fx.cam_node, 0, 0.2f, 3);
    expect_restart(&fx, "moving the viewport's camera");

    /* runtime switching: away to whitted and back; the cached path tracer context resumes its
     * accumulation because nothing changed meanwhile */
    sy_viewport *vp = sy_window_viewport(fx.win, 0);
    MUST(sy_viewport_set_backend(vp, "whitted", NULL, err));
    {
        sy_window_render_opts ro = {.seed = 9};
        MUST(sy_window_render(fx.win, s, fx.pool, &ro, &fx.img, err));
    }
    MUST(sy_viewport_set_backend(vp, "pathtracer", NULL, err));
    EXPECT_MSG(render(&fx, 1) == 3, "switching back to the path tracer did not resume its accumulation");
    EXPECT_MSG(render(&fx, 1) == 4, "accumulation after switching back");
    it_set_translation(s, fx.cam_node, 0, 0.2f, 3.5f);
    expect_restart(&fx, "moving the viewport's camera again");

    /* AOVs of the viewport rectangle */
    sy_context *ctx;
    MUST(sy_context_pool_get(fx.pool, s, "pathtracer", NULL, fx.root.id, &ctx, err));
    sy_mediator_rt_aovs a;
    MUST(sy_mediator_rt_aovs_get(sy_context_state(ctx), &a, err));
    EXPECT(a.width == 32 && a.height == 24 && a.samples == 2 && a.nonfinite_samples == 0);
    EXPECT(!memcmp(a.planes[0], fx.img.rgba, 32 * 24 * 4 * sizeof(float)));
    sy_mediator_rt_aovs_free(&a);
    sy_mediator_rt_counters cn;
    sy_mediator_rt_counters_get(sy_context_state(ctx), &cn);
    EXPECT_MSG(cn.accum_restarts == 6, "restarts counted: %u", cn.accum_restarts);
    /* the Whitted context rejects the AOV request */
    sy_context *wc;
    MUST(sy_context_pool_get(fx.pool, s, "whitted", NULL, fx.root.id, &wc, err));
    sy_error e = {0};
    EXPECT(sy_mediator_rt_aovs_get(sy_context_state(wc), &a, &e) != SY_OK && e.message[0]);

    /* temporal reuse ("temporal", sy_filter_temporal.h): a frame whose camera moved shows the
     * estimate; a still camera blends the accumulation with it, then shows the accumulation exactly */
    {
        sy_params on = {0}, off = {0};
        MUST(sy_params_set(&on, "temporal", "1", err));
        MUST(sy_params_set(&off, "temporal", "0", err));
        MUST(sy_context_set_filter(ctx, "none", &on, err));
        size_t bytes = 32 * 24 * 4 * sizeof(float);
        sy_mediator_rt_filter_info fi;
        for (int k = 0; k < 4; ++k) { /* a pan: the first frame has nothing to reuse yet */
            sy_mat4 m = sy_mat4_identity();
            m.m[12] = 0.3f + 0.02f * (float)k, m.m[14] = 2.9f;
            sy_viewport_set_view(vp, &m);
            uint64_t got = render(&fx, 1);
            EXPECT_MSG(got == 1, "pan frame %d: %llu samples", k, (unsigned long long)got);
            EXPECT(sy_layer_count_nonfinite(&fx.img) == 0);
            sy_mediator_rt_filter_info_get(sy_context_state(ctx), &fi);
            EXPECT_MSG(fi.temporal && fi.temporal_last == (k > 0) && fi.temporal_frames == (uint64_t)k,
                       "pan frame %d: temporal_last %d, frames %llu", k, fi.temporal_last,
                       (unsigned long long)fi.temporal_frames);
            MUST(sy_mediator_rt_aovs_get(sy_context_state(ctx), &a, err));
            bool same = !memcmp(a.planes[0], fx.img.rgba, bytes);
            EXPECT_MSG(same == (k == 0), "pan frame %d: the layer %s the accumulation", k, same ? "is" : "is not");
            sy_mediator_rt_aovs_free(&a);
        }
        EXPECT(fi.temporal_reused > 0.5);
        /* the camera rests: the accumulation blended with the last estimate (no pop) until it
         * takes over alone at 64 samples, bit for bit from then on */
        for (uint32_t k = 2; k <= 66; ++k) {
            EXPECT(render(&fx, 1) == k);
            MUST(sy_mediator_rt_aovs_get(sy_context_state(ctx), &a, err));
            bool same = !memcmp(a.planes[0], fx.img.rgba, bytes);
            sy_mediator_rt_aovs_free(&a);
            sy_mediator_rt_filter_info_get(sy_context_state(ctx), &fi);
            EXPECT_MSG(same == (k >= 64) && fi.temporal_rest_last == (k < 64),
                       "still frame of %u samples: the layer %s the accumulation, rest %d", k, same ? "is" : "is not",
                       fi.temporal_rest_last);
            EXPECT(!fi.temporal_last && fi.temporal_frames == 3);
        }
        MUST(sy_context_set_filter(ctx, "none", &off, err)); /* off: a moving frame is the plain samples */
        sy_mat4 m = sy_mat4_identity();
        m.m[14] = 3.2f;
        sy_viewport_set_view(vp, &m);
        EXPECT(render(&fx, 1) == 1);
        MUST(sy_mediator_rt_aovs_get(sy_context_state(ctx), &a, err));
        EXPECT(!memcmp(a.planes[0], fx.img.rgba, bytes));
        sy_mediator_rt_aovs_free(&a);
        sy_mediator_rt_filter_info_get(sy_context_state(ctx), &fi);
        EXPECT(!fi.temporal && !fi.temporal_last);
        sy_params bad = {0};
        MUST(sy_params_set(&bad, "temporal", "maybe", err));
        sy_error be = {0};
        EXPECT(sy_context_set_filter(ctx, "none", &bad, &be) != SY_OK && strstr(be.message, "temporal"));
    }
    destroy(&fx);
    return sy_check_finish("integration_pathtracer_sync");
}
