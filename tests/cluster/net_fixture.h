/* net_fixture.h — the fixture of the cluster tests that run render servers as processes
 * (test_cluster_net.c, test_cluster_coop.c; header-only, after server_proc.h): the demo scene and
 * a context pool, local reference renders, pixel-exact region comparison, a client of the first n
 * servers, a frame of the demo's root and camera, and the common main (register the back-ends,
 * build the scene, start the servers, run the named groups, stop everything). Thread-safety: main
 * thread only. */
#ifndef SY_TEST_NET_FIXTURE_H
#define SY_TEST_NET_FIXTURE_H

#include "../support/sy_check.h"
#include "coop_double.h"
#include "server_proc.h"
#include "sy_cluster.h"
#include "sy_demo.h"
#include "sy_mediators.h"
#include "sy_viewport.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- the scene and local references ---- */
typedef struct fixture {
    sy_scene *scene;
    sy_demo_info d;
    sy_context_pool *pool;
    uint32_t w, h;
} fixture;

/* A render of the fixture's scene in this process: backend, eye, spp samples (0: the back-end's
 * default, in the fixture's pool; else a fresh accumulation with that seed) into out (created
 * here); view, when not NULL, receives the camera the render used. */
static inline int local_render_spp(fixture *fx, const char *backend, uint32_t eye, uint32_t spp, uint32_t seed, sy_layer *out,
                            sy_camera_view *view)
{
    sy_error e = {0};
    sy_window *win = NULL;
    sy_viewport *vp = NULL;
    sy_viewport_desc vd = {.root = fx->d.root, .camera = fx->d.camera, .background = fx->d.background,
                           .backend = backend, .eye = eye};
    CHECK_OK(sy_window_create(fx->w, fx->h, &win, &e), e);
    CHECK_OK(sy_window_add_viewport(win, &vd, &vp, &e), e);
    if (view) {
        sy_viewport_desc mono = vd;
        sy_viewport *mv = NULL;
        mono.eye = SY_EYE_MONO;
        mono.inactive = true;
        CHECK_OK(sy_window_add_viewport(win, &mono, &mv, &e), e);
        CHECK_OK(sy_viewport_camera_view(mv, fx->scene, fx->w, fx->h, view, &e), e);
    }
    CHECK_OK(sy_layer_create(fx->w, fx->h, out, &e), e);
    sy_window_render_opts ro = {.sample_count = spp, .seed = seed};
    sy_context_pool *pool = fx->pool;
    if (spp) CHECK_OK(sy_context_pool_create(&pool, &e), e); /* a fresh accumulation */
    CHECK_OK(sy_window_render(win, fx->scene, pool, &ro, out, &e), e);
    if (pool != fx->pool) sy_context_pool_destroy(pool);
    sy_window_destroy(win);
    return 0;
}

static inline int local_render(fixture *fx, const char *backend, uint32_t eye, sy_layer *out, sy_camera_view *view)
{
    return local_render_spp(fx, backend, eye, 0, 0, out, view);
}

/* Destroys the layers given (sy_layer_destroy on each). */
static inline void destroy_layers(sy_layer *const *layers, size_t n)
{
    for (size_t i = 0; i < n; ++i) sy_layer_destroy(layers[i]);
}
#define DESTROY_LAYERS(...)                                                                         \
    destroy_layers((sy_layer *const[]){__VA_ARGS__}, sizeof((sy_layer *const[]){__VA_ARGS__}) / sizeof(sy_layer *))

/* Whether a's columns ax .. ax + w - 1 equal b (w x h) bit for bit, colour and depth (the first
 * difference printed). */
static inline bool same_region(const sy_layer *a, uint32_t ax, const sy_layer *b, uint32_t w, uint32_t h)
{
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            size_t ia = (size_t)y * a->width + ax + x, ib = (size_t)y * b->width + x;
            if (memcmp(&a->rgba[ia * 4], &b->rgba[ib * 4], 16) != 0) {
                fprintf(stderr, "pixel %u,%u differs: %g %g %g %g vs %g %g %g %g\n", x, y, a->rgba[ia * 4],
                        a->rgba[ia * 4 + 1], a->rgba[ia * 4 + 2], a->rgba[ia * 4 + 3], b->rgba[ib * 4],
                        b->rgba[ib * 4 + 1], b->rgba[ib * 4 + 2], b->rgba[ib * 4 + 3]);
                return false;
            }
            if (memcmp(&a->depth[ia], &b->depth[ib], 4) != 0) {
                fprintf(stderr, "depth %u,%u differs\n", x, y);
                return false;
            }
        }
    return true;
}

static inline sy_cluster_client *connect_all(fixture *fx, server *s, uint32_t n, const char *secret, uint32_t timeout_ms,
                                      sy_error *e)
{
    const char *urls[8];
    for (uint32_t i = 0; i < n; ++i) urls[i] = s[i].url;
    sy_cluster_client_opts co = {.urls = urls,
                                 .url_count = n,
                                 .secret = (const uint8_t *)secret,
                                 .secret_len = secret ? strlen(secret) : 0,
                                 .timeout_ms = timeout_ms,
                                 .connect_timeout_ms = 3000};
    sy_cluster_client *c = NULL;
    if (sy_cluster_client_create(fx->scene, &co, &c, e) != SY_OK) return NULL;
    return c;
}

static inline sy_cluster_frame make_frame(fixture *fx, uint32_t mode, const char *backend, const sy_camera_view *view)
{
    sy_cluster_frame f = {.mode = mode, .backend = backend, .root_id = fx->d.root.id,
                          .background_id = fx->d.background.id, .camera = *view, .width = fx->w, .height = fx->h,
                          .depth = true};
    return f;
}

/* A group of checks run against the servers started by the main (0 when it passed). */
typedef struct net_group {
    const char *name;
    int (*run)(fixture *, server *);
} net_group;

/* The main of a servers-as-processes test: argv as server_proc_setup's, argv[3] an optional
 * GROUP (only the groups whose name holds it, e.g. under valgrind); before (may be NULL) runs once
 * the work directory exists and before any server starts (environment the servers inherit);
 * start starts the test's servers into s (up to 4; 0 when all started). Returns the exit code. */
static inline int net_fixture_main(int argc, char **argv, const char *name, void (*before)(void),
                                   int (*start)(server *s), const net_group *groups, size_t ngroups)
{
    if (server_proc_setup(argc, argv, name, " [GROUP]")) return 2;
    sy_error e = {0};
    if (sy_mediators_register_builtin(&e) || coop_double_register(&e)) {
        fprintf(stderr, "%s\n", e.message);
        return 1;
    }
    fixture fx = {.w = 96, .h = 64};
    if (sy_scene_create(&fx.scene, &e) || sy_demo_build(fx.scene, &fx.d, &e) || sy_scene_commit(fx.scene, NULL, &e) ||
        sy_context_pool_create(&fx.pool, &e)) {
        fprintf(stderr, "%s\n", e.message);
        return 1;
    }
    if (before) before();
    server s[4];
    memset(s, 0, sizeof s);
    int failed = 0;
    if (start(s)) {
        failed = 1;
    } else {
        for (size_t i = 0; i < ngroups; ++i) {
            if (argc > 3 && !strstr(groups[i].name, argv[3])) continue;
            int r = groups[i].run(&fx, s);
            failed += r;
            printf("%s: %s\n", groups[i].name, r ? "FAILED" : "ok");
        }
    }
    for (int i = 0; i < 4; ++i) stop_server(&s[i]);
    sy_context_pool_destroy(fx.pool);
    sy_scene_destroy(fx.scene);
    if (failed) fprintf(stderr, "%s: %d group(s) failed (server logs in %s)\n", name, failed, g_dir);
    return failed ? 1 : 0;
}

#endif
