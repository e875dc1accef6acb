/* sy_cmd_bench.c — `sy bench KIND`: the benchmarks' command line; which benchmark, its options and
 * scene (the benchmarks: sy_bench.h, one file each; some parse their own options). */
#include "sy_commands.h"
#include "sy_cli.h"
#include "sy_bench.h"
#include "sy_bench_governor.h"
#ifdef SY_HAVE_EMBREE
#include "sy_bench_cull.h" /* sy bench cull: the culling service needs the coverage back-end */
#define SY_BENCH_CULL sy_cmd_bench_cull
#else
#define SY_BENCH_CULL(argc, argv) ((void)(argc), (void)(argv), fprintf(stderr, "sy bench cull: error: this sy was built without the Embree back-ends (SY_WITH_EMBREE=OFF)\n"), 1)
#endif
#include "sy_cluster_cli.h"
#include "sy_load.h"
#ifdef SY_HAVE_WEB
#include "sy_bench_stream.h"
#include "sy_bench_web.h"
#include "sy_web.h"
#endif

#include "sy_world.h"

#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* sy bench raster [SCENE] [-w W -h H] [--repeats R] [--params k=v]: default 1280x720 on OSMesa. */
static int cmd_bench_raster(const char *scene, uint32_t w, uint32_t h, uint32_t repeats, const char *params)
{
    sy_error err = {0};
    loaded ld;
    if (sy_cli_load(scene ? scene : "demo", NULL, true, &ld, &err) != SY_OK) return sy_cli_fail(&err);
    sy_viewport_desc vd = {.root = ld.root, .camera = ld.camera, .background = ld.background, .backend = "raster",
                           .params = params};
    sy_result r = sy_bench_raster(ld.scene, &vd, scene ? scene : "demo", w == 512 ? 1280 : w, h == 512 ? 720 : h,
                                  repeats ? repeats : 10, &err);
    sy_cli_loaded_free(&ld);
    return r == SY_OK ? 0 : sy_cli_fail(&err);
}

/* sy bench pathtracer [SCENE] [-w W -h H] [--repeats PASSES]: the Cornell box and DamagedHelmet
 * (under a uniform grey environment) from ../shared/testdata unless a scene is given. */
static int cmd_bench_pathtracer(const char *scene, uint32_t w, uint32_t h, uint32_t passes)
{
    static const char *const defaults[2] = {"../shared/testdata/cornell/cornell_box.gltf",
                                            "../shared/testdata/gltf/DamagedHelmet/glTF/DamagedHelmet.gltf"};
    const char *list[2] = {scene ? scene : defaults[0], scene ? NULL : defaults[1]};
    sy_error err = {0};
    printf("sy bench pathtracer: %u threads (all cores), 1 sample per pixel per pass\n", (unsigned)sysconf(_SC_NPROCESSORS_ONLN));
    for (int i = 0; i < 2 && list[i]; ++i) {
        loaded ld;
        if (sy_cli_load(list[i], NULL, true, &ld, &err) != SY_OK) return sy_cli_fail(&err);
        /* the helmet under a uniform grey environment light (a 1x1 lat-long map) */
        sy_world_options wo = {.has_env_color = i == 1, .env_color = {0.8f, 0.8f, 0.8f}};
        sy_result r = sy_world_apply(ld.scene, &ld.background, &wo, &err);
        if (r == SY_OK) r = sy_scene_commit(ld.scene, NULL, &err);
        sy_viewport_desc vd = {.root = ld.root, .camera = ld.camera, .background = ld.background};
        if (r == SY_OK) r = sy_bench_pathtracer(ld.scene, &vd, list[i], w, h, passes ? passes : 8, &err);
        sy_cli_loaded_free(&ld);
        if (r != SY_OK) return sy_cli_fail(&err);
    }
    return 0;
}

/* sy bench filters [SCENE --reference REF.exr] [SHEET.png] [-w W -h H] [--repeats R] (issue 7):
 * without SCENE the analytic surrogate at 640x480; with it the path tracer's buffers at the
 * reference's size (default 256x256). */
static int cmd_bench_filters(int argc, char **argv)
{
    const char *scene = NULL, *sheet = NULL, *reference = NULL;
    uint32_t w = 0, h = 0, repeats = 5;
    const sy_cli_opt opts[] = {SY_CLI_OPT_UINT("repeats", OPT_REPEATS, &repeats, 1, 1000),
                               SY_CLI_OPT_TEXT("reference", OPT_REFERENCE, &reference)};
    sy_cli_parser p = {SY_CLI_ARGS("bench filters", argc, argv, opts), .w = &w, .h = &h, .min_size = 8};
    if (sy_cli_parse(&p) != -1) return p.status;
    for (; optind < argc; ++optind) { /* [SCENE] [SHEET.png] */
        const char *a = argv[optind];
        if (sy_cli_ends_with(a, ".png") && !sheet) sheet = a;
        else if (!scene) scene = a;
        else return sy_cli_usage_of("bench filters", "at most one SCENE and one SHEET.png");
    }
    sy_error err = {0};
    if (!scene) return sy_bench_filters(w ? w : 640, h ? h : 480, repeats, sheet, &err) == SY_OK ? 0 : sy_cli_fail(&err);
    if (!reference) {
        fprintf(stderr, "sy bench filters %s: --reference REF.exr (the converged image) is required\n", scene);
        return 2;
    }
    loaded ld;
    if (sy_cli_load(scene, NULL, true, &ld, &err) != SY_OK) return sy_cli_fail(&err);
    sy_viewport_desc vd = {.root = ld.root, .camera = ld.camera, .backend = "pathtracer"};
    sy_result r = sy_bench_filters_scene(ld.scene, &vd, scene, w ? w : 256, h ? h : 256, reference, sheet, &err);
    sy_cli_loaded_free(&ld);
    return r == SY_OK ? 0 : sy_cli_fail(&err);
}

/* sy bench temporal [SCENE...] [-w W -h H] [--frames N] [--spp REF] [--cost-frames N] [--png PREFIX]
 * (issue 36): default the Cornell box of ../shared/testdata (skipped with a note when absent) and the
 * demo. --cost-frames (1..12, default 12): the moving 640x360 frames the cost is the median of (fewer
 * for a profile under valgrind). */
static int cmd_bench_temporal(int argc, char **argv)
{
    uint32_t w = 0, h = 0, frames = 60, ref = 256, cost_frames = 12;
    const char *png = NULL;
    enum { O_PNG = OPT_OWN_FIRST, O_COST };
    const sy_cli_opt opts[] = {SY_CLI_OPT_UINT("frames", OPT_FRAMES, &frames, 2, 100000),
                               SY_CLI_OPT_UINT("spp", OPT_SPP, &ref, 1, 1u << 20),
                               SY_CLI_OPT_UINT("cost-frames", O_COST, &cost_frames, 1, 12),
                               SY_CLI_OPT_TEXT("png", O_PNG, &png)};
    sy_cli_parser p = {SY_CLI_ARGS("bench temporal", argc, argv, opts), .w = &w, .h = &h, .min_size = 8};
    if (sy_cli_parse(&p) != -1) return p.status;
    static const char *const defaults[] = {"../shared/testdata/cornell/cornell_box.gltf", "demo"};
    const char *const *scenes = optind < argc ? (const char *const *)argv + optind : defaults;
    int count = optind < argc ? argc - optind : 2;
    for (int i = 0; i < count; ++i) {
        struct stat sst;
        if (scenes == defaults && i == 0 && stat(scenes[i], &sst) != 0) {
            printf("%s: absent (../shared/testdata), skipped\n", scenes[i]);
            continue;
        }
        sy_error err = {0};
        loaded ld;
        if (sy_cli_load(scenes[i], NULL, true, &ld, &err) != SY_OK) return sy_cli_fail(&err);
        sy_viewport_desc vd = {.root = ld.root, .camera = ld.camera, .background = ld.background, .backend = "pathtracer"};
        char prefix[1024];
        if (png) snprintf(prefix, sizeof prefix, "%s_%d", png, i);
        sy_result r = sy_bench_temporal(ld.scene, &vd, scenes[i], w ? w : 160, h ? h : 90, frames, ref,
                                        cost_frames, png ? prefix : NULL, &err);
        sy_cli_loaded_free(&ld);
        if (r != SY_OK) return sy_cli_fail(&err);
    }
    return 0;
}

/* sy bench KIND ...: argv[0] is "bench", argv[1] the kind. */
int sy_cmd_bench(int argc, char **argv)
{
    static const char *const kinds[] = {"sync",      "rays", "pathtracer", "filters", "raster",
                                        "viewports", "load", "cluster",    "memory", "instances", "governor",
                                        "limit",     "cull", "web", "deform", "anim", "lights", "temporal", "stream"};
    bool known = false;
    for (size_t k = 0; argc >= 2 && k < sizeof kinds / sizeof kinds[0]; ++k) known = known || !strcmp(argv[1], kinds[k]);
    if (argc >= 2 && !strcmp(argv[1], "--help")) {
        sy_cli_usage_to(stdout, "bench");
        return 0;
    }
    if (!known) {
        if (argc >= 2) fprintf(stderr, "sy bench: error: unknown benchmark '%s'\n", argv[1]);
        return sy_cli_usage_of("bench", argc < 2 ? "which benchmark?" : NULL);
    }
    const char *cmd = argv[1]; /* the benchmark */
    argc -= 1, argv += 1; /* argv[0]: the kind */
    if (!strcmp(cmd, "filters")) return cmd_bench_filters(argc, argv);
    if (!strcmp(cmd, "temporal")) return cmd_bench_temporal(argc, argv);
    if (!strcmp(cmd, "cluster")) return sy_cmd_bench_cluster(argc, argv);
    if (!strcmp(cmd, "governor")) return sy_cmd_bench_governor(argc, argv); /* sy_bench_governor.c */
    if (!strcmp(cmd, "limit")) return sy_cmd_bench_limit(argc, argv); /* apps/sy/sy_bench_limit.c */
    if (!strcmp(cmd, "cull")) return SY_BENCH_CULL(argc, argv); /* apps/sy/sy_bench_cull.c */
    uint32_t nodes = 10000, tris = 100, repeats = 0, w = 512, h = 512;
    const char *scene = NULL, *params = NULL, *backend = NULL;
    bool memory = !strcmp(cmd, "memory"), instanced = !strcmp(cmd, "instances"), web = !strcmp(cmd, "web") || !strcmp(cmd, "stream");
    char who[32];
    snprintf(who, sizeof who, "bench %s", cmd);
    bool glb = false;
    const sy_cli_opt opts[] = {
        SY_CLI_OPT_TEXT("params", OPT_PARAMS, &params), /* bench raster */
        SY_CLI_OPT_UINT("nodes", OPT_NODES, &nodes, 1, 1u << 22), /* bench sync: nodes; bench instances: instances */
        SY_CLI_OPT_UINT("tris", OPT_TRIS, &tris, 12, memory || instanced ? 1u << 30 : 1u << 20),
        SY_CLI_OPT_CODE("glb", OPT_GLB, false), SY_CLI_OPT_UINT("repeats", OPT_REPEATS, &repeats, 1, 100000),
        SY_CLI_OPT_TEXT(NULL, 'b', &backend)}; /* last: only bench memory, bench instances, bench web take -b */
    sy_cli_parser p = {SY_CLI_ARGS(who, argc, argv, opts), .w = &w, .h = &h, .min_size = 1};
    p.count -= !(memory || instanced || web);
    int c;
    while ((c = sy_cli_parse(&p)) != -1) {
        if (c == OPT_STOP) return p.status;
        if (c == OPT_GLB && !memory) return sy_cli_usage_of(who, "--glb is an option of sy bench memory");
        glb = glb || c == OPT_GLB;
    }
    if (argc - optind > 1) return sy_cli_usage_of(who, "at most one SCENE");
    if (optind < argc) scene = argv[optind];
    sy_error err = {0};
    if (!strcmp(cmd, "deform")) { /* --tris: vertices of the skinned tube */
        if (optind < argc) return sy_cli_usage_of(who, "no SCENE: the skinned tube is generated");
        return sy_bench_deform(tris == 100 ? 100000 : tris, repeats ? repeats : 50, &err) == SY_OK ? 0 : sy_cli_fail(&err);
    }
    if (!strcmp(cmd, "anim")) { /* --tris: vertices of the skinned tube; --nodes: animated nodes */
        if (optind < argc) return sy_cli_usage_of(who, "no SCENE: the animated scenes are generated");
        return sy_bench_anim(tris == 100 ? 100000 : tris, nodes, repeats ? repeats : 50, &err) == SY_OK ? 0 : sy_cli_fail(&err);
    }
    if (!strcmp(cmd, "lights")) { /* --nodes: emissive quads, --tris: point lights, --repeats: seconds per method;
                                   * the argument: an existing folder for the scene and the images */
        return sy_bench_lights(nodes, tris == 100 ? 1000 : tris, w == 512 ? 320 : w, h == 512 ? 240 : h,
                               repeats ? repeats : 20, scene, &err) == SY_OK ? 0 : sy_cli_fail(&err);
    }
    if (!strcmp(cmd, "sync")) return sy_bench_sync(nodes, tris, repeats ? repeats : 50, &err) == SY_OK ? 0 : sy_cli_fail(&err);
    if (!strcmp(cmd, "viewports"))
        return sy_bench_viewports(w == 512 ? 480 : w, h == 512 ? 270 : h, repeats ? repeats : 5, &err) == SY_OK
                   ? 0
                   : sy_cli_fail(&err);
    if (!strcmp(cmd, "raster")) return cmd_bench_raster(scene, w, h, repeats, params);
    if (!strcmp(cmd, "pathtracer")) return cmd_bench_pathtracer(scene, w, h, repeats);
    if (memory) {
        if (optind < argc) return sy_cli_usage_of(who, "no SCENE: the height field is generated");
        return sy_bench_memory(tris == 100 ? 1000000 : tris, backend, glb, w == 512 ? 256 : w, h == 512 ? 256 : h, &err) == SY_OK
                   ? 0
                   : sy_cli_fail(&err);
    }
    if (instanced) { /* the argument: an existing folder that keeps the scene's two .glb files */
#ifdef SY_HAVE_EMBREE
        return sy_bench_instances(nodes == 10000 ? 1000 : nodes, tris == 100 ? 1000000 : tris, w == 512 ? 320 : w,
                                  h == 512 ? 240 : h, repeats ? repeats : 10, backend, scene, &err) == SY_OK
                   ? 0
                   : sy_cli_fail(&err);
#else
        sy_error_set(&err, SY_ERR_UNSUPPORTED, "sy bench instances: this sy was built without the Embree back-ends");
        return sy_cli_fail(&err);
#endif
    }
    if (!strcmp(cmd, "load")) /* SCENE = the glTF sample directory; --tris: generated model (default 1M) */
        return sy_bench_load(scene ? scene : "../shared/testdata/gltf", tris == 100 ? 1000000 : tris,
                             repeats ? repeats : 3, &err) == SY_OK ? 0 : sy_cli_fail(&err);
#ifdef SY_HAVE_WEB
    if (!strcmp(cmd, "stream")) { /* sy web's JPEG against its video stream on an orbit (apps/sy/sy_bench_stream.c) */
        loaded ld;
        if (sy_cli_load(scene ? scene : "demo", NULL, true, &ld, &err) != SY_OK) return sy_cli_fail(&err);
        sy_viewport_desc vd = {.root = ld.root, .camera = ld.camera, .background = ld.background,
                               .backend = backend ? backend : sy_mediator_default_name()};
        sy_result r = sy_bench_stream(ld.scene, &vd, scene ? scene : "demo", w == 512 ? 640 : w, h == 512 ? 360 : h,
                                      repeats ? repeats : 30, &err);
        sy_cli_loaded_free(&ld);
        return r == SY_OK ? 0 : sy_cli_fail(&err);
    }
    if (web) { /* input-to-frame latency of sy web on loopback (apps/sy/sy_bench_web.c) */
        loaded ld;
        if (sy_cli_load(scene ? scene : "demo", NULL, true, &ld, &err) != SY_OK) return sy_cli_fail(&err);
        sy_web_desc d = {.scene = ld.scene, .root = ld.root, .camera = ld.camera, .background = ld.background,
                         .backend = backend}; /* NULL: the default back-end */
        sy_result r = sy_bench_web(&d, w == 512 ? 640 : w, h == 512 ? 360 : h, repeats ? repeats : 50, &err);
        sy_cli_loaded_free(&ld);
        return r == SY_OK ? 0 : sy_cli_fail(&err);
    }
#endif
    if (!strcmp(cmd, "rays")) {
        loaded ld;
        if (sy_cli_load(scene ? scene : "demo", NULL, true, &ld, &err) != SY_OK) return sy_cli_fail(&err);
        sy_viewport_desc vd = {.root = ld.root, .camera = ld.camera, .backend = "whitted"};
        sy_result r = sy_bench_rays(ld.scene, &vd, w, h, repeats ? repeats : 5, &err);
        sy_cli_loaded_free(&ld);
        return r == SY_OK ? 0 : sy_cli_fail(&err);
    }
    return sy_cli_usage_of("bench", NULL);
}
