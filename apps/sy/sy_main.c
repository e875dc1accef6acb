/* sy_main.c — the `sy` command line tool: info, render, demo, compare, coverage, view, bench, backends, serve.
 *
 *   sy [-q | -v] [--version | --help] COMMAND ...   -q: errors only, -v: debug messages (sy_log.h)
 *   sy help [COMMAND], sy COMMAND --help            usage on stdout, exit status 0
 *   sy info SCENE | IMAGE.exr | .png    JSON summary (counts, bounds, warnings; an image's metadata)
 *   sy render SCENE -b BACKEND -o OUT.exr|png [-w W] [-h H] [--camera NAME|INDEX]
 *             [--params k=v,...] [--half] [--exposure EV] [--tonemap clamp|reinhard|aces]
 *             [--max-memory MB]   (ray tracers: max_memory_mb, a scene whose BVHs need more is refused)
 *             with -b pathtracer: [--spp N | --time SECONDS] [--aov]
 *             [--filter none|pixel|atrous|jbu|adaptive|radiance [--threshold T]]
 *   world options of every command: [--env MAP.exr | --env-color R,G,B] [--env-intensity X] [--env-hidden]
 *             [--background R,G,B[,A]] [--no-default-light]   (see sy_world.h and sy_look.h)
 *             [--gl osmesa|egl|glfw]  (raster back-end's GL context provider)
 *   sy demo [-o DIR] [-w W] [-h H]      render the built-in demo scene with every back-end
 *   sy compare SCENE [-w W] [-h H] [--spp N] [-o SHEET.png]   every back-end side by side (sy_compare.h)
 *   sy bench sync [--nodes N] [--tris T] [--repeats R]
 *   sy bench rays [SCENE] [-w W] [-h H] [--repeats R]
 *   sy bench raster [SCENE] [-w W] [-h H] [--repeats R] [--params k=v,...]
 *   sy bench load [GLTF_SAMPLE_DIR] [--tris T] [--repeats R]
 *   sy bench limit [SCENE] [-w W] [-h H] [--spp N] [--repeats N]   (sy_bench_limit.c)
 *   sy bench memory [--tris T] [-b whitted|pathtracer] [--glb] [-w W] [-h H]   peak RSS per triangle (sy_bench.h)
 *   sy bench filters [SCENE --reference REF.exr] [SHEET.png] [-w W] [-h H] [--repeats R]
 *   sy backends [--params] [--json]     list registered back-ends (--params: their parameters)
 *   sy serve [--listen URL] [--secret-file F] [--output OUT]   render server (apps/sy/sy_cluster_cli.c)
 *   sy render ... --cluster URL[,URL...]|FILE.conf [--cluster-mode MODE]   render on servers
 *   sy view ... --cluster URL[,URL...]|FILE.conf [--cluster-mode MODE]     the viewer on servers
 *   sy bench cluster [-w W] [-h H] [--repeats ROUNDS]
 *   sy bench cluster --soak SECONDS [--warmup S] [-b BACKEND]                  the sy serve soak
 *
 * SCENE is a .gltf / .glb / .x3d file or the word "demo" (the built-in scene). Options are parsed with
 * getopt_long (GNU ordering: options and operands in any order; --name=value; "--" ends the options);
 * -q / -v and the world and loader flags are accepted before and after the command. JSON output is
 * written with cJSON. Warnings, notes and errors go to stderr through the library's log (sy_log.h) with
 * the file and the reason. Exit status: 0 success, 1 failure, 2 usage error (the bad option or value
 * is named), 130 interrupted. Bash completion: apps/sy/sy-completion.bash. */
#include "sy_bench.h"
#include "sy_bench_governor.h"
#ifdef SY_HAVE_EMBREE
#include "sy_bench_cull.h" /* sy bench cull: the culling service needs the coverage back-end */
#define SY_BENCH_CULL sy_cmd_bench_cull
#else
#define SY_BENCH_CULL(argc, argv) ((void)(argc), (void)(argv), fprintf(stderr, "sy bench cull: error: this sy was built without the Embree back-ends (SY_WITH_EMBREE=OFF)\n"), 1)
#endif
#include "sy_cluster_cli.h"
#include "sy_mediator_cluster.h"
#include "sy_compare.h"
#include "sy_compose.h"
#ifdef SY_HAVE_GLFW
#include "sy_view.h"
#ifdef SY_HAVE_WEB
#include "sy_bench_web.h"
#include "sy_web.h"
#ifdef SY_WEB_HAVE_CULL
#include "sy_web_cull.h"
#endif
#endif
#endif
#include "sy_demo.h"
#include "sy_exr.h"
#include "sy_file.h"
#include "sy_world.h"
#include "sy_gltf.h"
#include "sy_jpeg.h"
#include "sy_log.h"
#ifdef SY_HAVE_EMBREE
#endif
#include "sy_mediators.h"
#include "sy_png.h"
#include "sy_sniff.h"
#include "sy_signals.h"
#include "sy_testpoint.h"
#include "sy_options.h"
#include "sy_viewport.h"
#include "sy_x3d.h"

#include <cJSON.h>
#include <dirent.h>
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

/* >>loading */
typedef struct loaded {
    sy_scene *scene;
    sy_node root;
    sy_node camera; /* {0}: frame the bounds */
    sy_background background;
    sy_gltf_info gltf;
    bool is_gltf;
    sy_x3d_info x3d; /* .x3d files (is_x3d) */
    bool is_x3d;
} loaded;

static void loaded_free(loaded *l)
{
    sy_gltf_info_free(&l->gltf);
    sy_x3d_info_free(&l->x3d);
    sy_scene_destroy(l->scene);
    memset(l, 0, sizeof *l);
}

/* A file without a camera gets one framing its bounds (as a real camera node, so every back-end
 * sees the same view); a file with neither punctual lights nor emissive materials gets a
 * directional headlight from that camera, so that it is not black. The headlight is reported on
 * stderr. */
static sy_result add_defaults(loaded *ld, sy_error *err)
{
    sy_scene *s = ld->scene;
    sy_result r = SY_OK;
    sy_mat4 cam_world;
    if (!ld->camera.id) {
        sy_bounds b;
        if ((r = sy_node_world_bounds(s, ld->root, &b, err))) return r;
        sy_camera_view v = sy_camera_view_frame_bounds(&b, 1.0f);
        sy_camera cam;
        sy_camera_data cd = *(const sy_camera_data *)sy_object_defaults(SY_TYPE_CAMERA);
        cd.yfov = 2.0f * atanf(v.window[3]);
        cd.znear = v.znear;
        if ((r = sy_camera_create(s, "default camera", &cam, err)) || (r = sy_camera_set(s, cam, &cd, err)) ||
            (r = sy_node_create(s, "default camera", &ld->camera, err)) ||
            (r = sy_node_set_matrix(s, ld->camera, &v.camera_to_world, err)) ||
            (r = sy_node_set_camera(s, ld->camera, cam, err)))
            return r;
        cam_world = v.camera_to_world;
    } else if ((r = sy_node_world_matrix(s, ld->camera, &cam_world, err))) {
        return r;
    }
    (void)cam_world;
    return sy_scene_commit(s, NULL, err);
}

/* Loader options every command shares, taken out of the arguments in main: --allow-path DIR
 * (repeatable: more folders that a model's external files may lie in), --strict (whatever a
 * loader skips or repairs is an error) and --max-scene-mb N (the budget per file, sy_budget.h). */
#define SY_MAX_ALLOW_PATHS 16
static struct {
    const char *roots[SY_MAX_ALLOW_PATHS];
    size_t root_count;
    bool strict;
    uint64_t max_scene_bytes; /* --max-scene-mb: the loaders' budget per file (sy_budget.h); 0 = default */
    sy_world_options world; /* --env, --env-color, --env-intensity, --env-hidden, --background, --no-default-light */
} g_load;

/* The world flags every command shares (taken out of the arguments in main): --env MAP.exr,
 * --env-color R,G,B, --env-intensity X, --env-hidden, --background R,G,B[,A], --no-default-light.
 * *used = arguments consumed (0: not a world flag). Only maps text onto sy_world_options; the
 * meaning is the library's (sy_look.h, sy_world.h). */
static bool parse_floats(const char *text, float *out, int min_n, int max_n, int *n_out)
{
    int n = 0;
    const char *p = text;
    while (n < max_n) {
        char *end = NULL;
        out[n] = strtof(p, &end);
        if (end == p || !isfinite(out[n])) return false;
        ++n;
        if (*end == '\0') break;
        if (*end != ',') return false;
        p = end + 1;
    }
    *n_out = n;
    return n >= min_n && *p && p[strlen(p) - 1] != ',';
}

/* >>options: every command parses its options with getopt_long (GNU ordering: options and operands
 * in any order, "--" ends the options, --name=value) through sy_getopt, which refuses abbreviated
 * long options (sy_options.h: "--frame" is no "--frames"). The
 * options every command takes (the world and loader flags, -q / -v, --help) are applied by
 * next_option; a command's own ones come back to it. */
enum {
    OPT_STOP = -2, /* next_option: the command ends with *status (after --help or a usage error) */
    OPT_HELP = 0x100, OPT_VERSION, OPT_ENV, OPT_ENV_COLOR, OPT_ENV_INTENSITY, OPT_ENV_HIDDEN, OPT_BACKGROUND,
    OPT_NO_DEFAULT_LIGHT, OPT_ALLOW_PATH, OPT_STRICT, OPT_MAX_SCENE_MB,
    /* the commands' own long options (cluster ones: SY_CLUSTER_OPT_*, sy_cluster_cli.h) */
    OPT_SPP, OPT_TIME, OPT_AOV, OPT_CAMERA, OPT_PARAMS, OPT_GL, OPT_FILTER, OPT_THRESHOLD, OPT_HALF, OPT_EXPOSURE,
    OPT_TONEMAP, OPT_STEREO, OPT_EYE_SEP, OPT_ZERO_PARALLAX, OPT_OVERLAY, OPT_COMPOSITE, OPT_FRAMES, OPT_BACKENDS,
    OPT_SCREENSHOT, OPT_KEYS, OPT_TOP, OPT_REPEATS, OPT_REFERENCE, OPT_NODES, OPT_TRIS, OPT_JSON, OPT_GLB, OPT_MAX_MEMORY,
    OPT_BUDGET
};
/* getopt_long entries of the options of every command, with the table's terminator: the end of
 * every command's table */
#define COMMON_OPTIONS                                                                                     \
    {"help", no_argument, NULL, OPT_HELP}, {"quiet", no_argument, NULL, 'q'},                              \
    {"verbose", no_argument, NULL, 'v'}, {"env", required_argument, NULL, OPT_ENV},                        \
    {"env-color", required_argument, NULL, OPT_ENV_COLOR},                                                 \
    {"env-intensity", required_argument, NULL, OPT_ENV_INTENSITY},                                         \
    {"env-hidden", no_argument, NULL, OPT_ENV_HIDDEN}, {"background", required_argument, NULL, OPT_BACKGROUND}, \
    {"no-default-light", no_argument, NULL, OPT_NO_DEFAULT_LIGHT},                                         \
    {"allow-path", required_argument, NULL, OPT_ALLOW_PATH}, {"strict", no_argument, NULL, OPT_STRICT},    \
    {"max-scene-mb", required_argument, NULL, OPT_MAX_SCENE_MB},                                           \
    {NULL, 0, NULL, 0}
/* short options: ':' first (a missing value is told apart from an unknown option), then -q and -v */
#define SHORT_OPTIONS(own) ":" own "qv"

static void usage_to(FILE *f, const char *cmd);

/* The world flags (only maps text onto sy_world_options; the meaning is the library's: sy_look.h,
 * sy_world.h). */
static sy_result apply_world_option(int c, const char *v, sy_world_options *w, sy_error *err)
{
    int n = 0;
    switch (c) {
    case OPT_ENV_HIDDEN: w->env_hidden = true; break;
    case OPT_NO_DEFAULT_LIGHT: w->no_default_light = true; break;
    case OPT_ENV: w->env_path = v; break;
    case OPT_ENV_COLOR:
        if (!parse_floats(v, w->env_color, 3, 3, &n))
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "--env-color %s: expected R,G,B", v);
        w->has_env_color = true;
        break;
    case OPT_ENV_INTENSITY:
        if (!parse_floats(v, &w->env_intensity, 1, 1, &n))
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "--env-intensity %s: expected a number", v);
        w->env_intensity_set = true;
        break;
    default: /* OPT_BACKGROUND */
        if (!parse_floats(v, w->background, 3, 4, &n))
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "--background %s: expected R,G,B or R,G,B,A", v);
        if (n == 3) w->background[3] = 1.0f;
        w->has_background = true;
    }
    return SY_OK;
}

/* The next option of a command's arguments (argv[0]: the command's name, for messages; cmd: the
 * command as `sy help` names it, NULL for sy's own options). Call with optind = 0 first (glibc's way
 * to start over with new arguments and a new ordering). Returns the option's code, -1 after the last
 * option (the operands are argv[optind..argc-1]), or OPT_STOP with *status: 0 after --help (the
 * command's usage on stdout), 2 after a usage error (named on stderr). */
static int next_option(const char *cmd, int argc, char **argv, const char *shortopts, const struct option *longopts,
                       int *status)
{
    opterr = 0; /* the messages are ours */
    const char *who = cmd ? cmd : "sy";
    char prefix[64];
    snprintf(prefix, sizeof prefix, "sy%s%s", cmd ? " " : "", cmd ? cmd : "");
    for (;;) {
        int c = sy_getopt(argc, argv, shortopts, longopts, prefix);
        const char *bad = optind > 0 && optind <= argc ? argv[optind - 1] : "";
        sy_error e = {0};
        switch (c) {
        case SY_GETOPT_ERROR: /* an abbreviated long option (named on stderr) */
            *status = 2;
            return OPT_STOP;
        case '?':
            if (optopt >= 0x100) fprintf(stderr, "sy %s: error: option '%s' takes no value", who, bad);
            else if (optopt) fprintf(stderr, "sy %s: error: unknown option '-%c'", who, optopt);
            else fprintf(stderr, "sy %s: error: unknown option '%s'", who, bad);
            fprintf(stderr, " (sy %s%s--help lists the options)\n", cmd ? cmd : "", cmd ? " " : "");
            *status = 2;
            return OPT_STOP;
        case ':':
            fprintf(stderr, "sy %s: error: option '%s' needs a value\n", who, bad);
            *status = 2;
            return OPT_STOP;
        case OPT_HELP:
            usage_to(stdout, cmd);
            *status = 0;
            return OPT_STOP;
        case 'q': sy_log_set_level(SY_LOG_ERROR); break;
        case 'v': sy_log_set_level(SY_LOG_DEBUG); break;
        case OPT_STRICT: g_load.strict = true; break;
        case OPT_MAX_SCENE_MB: { /* the loaders' budget per file, in MiB (sy_budget.h) */
            char *end = NULL;
            errno = 0;
            unsigned long long mb = strtoull(optarg, &end, 10);
            if (!*optarg || *end || errno || mb < 1 || mb > (1ull << 30)) {
                fprintf(stderr, "sy: error: --max-scene-mb %s: expected a whole number of MiB from 1 to 2^30\n", optarg);
                *status = 2;
                return OPT_STOP;
            }
            g_load.max_scene_bytes = (uint64_t)mb << 20;
            break;
        }
        case OPT_ALLOW_PATH: { /* repeatable: more folders that a model's external files may lie in */
            struct stat st;
            if (stat(optarg, &st) != 0 || !S_ISDIR(st.st_mode)) {
                fprintf(stderr, "sy: error: --allow-path %s: expected an existing folder\n", optarg);
                *status = 2;
                return OPT_STOP;
            }
            if (g_load.root_count == SY_MAX_ALLOW_PATHS) {
                fprintf(stderr, "sy: error: --allow-path: at most %d folders\n", SY_MAX_ALLOW_PATHS);
                *status = 2;
                return OPT_STOP;
            }
            g_load.roots[g_load.root_count++] = optarg;
            break;
        }
        case OPT_ENV: case OPT_ENV_COLOR: case OPT_ENV_INTENSITY: case OPT_ENV_HIDDEN: case OPT_BACKGROUND:
        case OPT_NO_DEFAULT_LIGHT:
            if (apply_world_option(c, optarg, &g_load.world, &e) != SY_OK) {
                fprintf(stderr, "sy: error: %s\n", e.message);
                *status = 2;
                return OPT_STOP;
            }
            break;
        default: return c;
        }
    }
}

/* What the loader skipped or repaired is on the log already (the loaders report it through sy_log:
 * sy: warning: FILE: item: what); with --strict any of it fails the load. */
static sy_result report_warnings(const char *path, uint32_t total, sy_error *err)
{
    if (g_load.strict && total)
        return sy_error_set(err, SY_ERR_PARSE, "%s: %u warning%s and --strict given; nothing rendered", path, total,
                            total == 1 ? "" : "s");
    return SY_OK;
}

/* The scene format of path, from its content (sy_sniff.h): a file of another kind is refused,
 * named for what it is; one that is not recognised goes to the loader its name suggests (which
 * then says what is wrong with it). */
static sy_result recognise(const char *path, sy_file_format *fmt, sy_error *err)
{
    *fmt = SY_FORMAT_UNKNOWN;
    sy_error ignore = {0};
    if (sy_sniff_file(path, fmt, &ignore) != SY_OK) return SY_OK; /* the loader reports a missing file */
    if (*fmt == SY_FORMAT_UNKNOWN || sy_file_format_is_scene(*fmt)) return SY_OK;
    return sy_error_set(err, SY_ERR_UNSUPPORTED,
                        "%s: %s content, which sy does not read as a scene (it reads glTF 2.0 .gltf / .glb and X3D in XML "
                        "encoding)",
                        path, sy_file_format_name(*fmt));
}

static sy_result load(const char *path, const char *camera_sel, bool defaults, loaded *out, sy_error *err)
{
    memset(out, 0, sizeof *out);
    sy_file_format fmt = SY_FORMAT_UNKNOWN;
    double t0 = sy_time_now();
    sy_result r = sy_scene_create(&out->scene, err);
    if (r != SY_OK) return r;
    if (strcmp(path, "demo") == 0) {
        sy_demo_info d;
        r = sy_demo_build(out->scene, &d, err);
        if (r == SY_OK) {
            out->root = d.root;
            out->camera = d.camera;
            out->background = d.background;
            if (camera_sel && strcmp(camera_sel, "0") != 0 && strcmp(camera_sel, "camera") != 0)
                r = sy_error_set(err, SY_ERR_NOT_FOUND, "demo: no camera '%s' (available: 0 \"camera\")", camera_sel);
        }
    } else if ((r = recognise(path, &fmt, err)) != SY_OK) {
        /* named for what it is: not a scene format the loaders read */
    } else if (fmt == SY_FORMAT_X3D || (fmt == SY_FORMAT_UNKNOWN && strlen(path) > 4 &&
                                        !strcasecmp(path + strlen(path) - 4, ".x3d"))) {
        out->is_x3d = true;
        sy_x3d_options xo = {.allowed_roots = g_load.roots, .allowed_root_count = g_load.root_count,
                             .max_scene_bytes = g_load.max_scene_bytes};
        r = sy_x3d_load(path, out->scene, &xo, &out->x3d, err);
        if (r == SY_OK)
            r = report_warnings(path, out->x3d.warning_count, err);
        if (r == SY_OK) {
            out->root = out->x3d.root;
            out->background = out->x3d.background;
            if (camera_sel) r = sy_x3d_find_camera(out->scene, &out->x3d, camera_sel, &out->camera, err);
            else if (out->x3d.camera_node_count) out->camera = out->x3d.camera_nodes[0];
            if (r != SY_OK) sy_error_prefix(err, "%s", path);
        }
    } else {
        out->is_gltf = true;
        sy_gltf_options go = {.allowed_roots = g_load.roots, .allowed_root_count = g_load.root_count,
                          .max_scene_bytes = g_load.max_scene_bytes};
        r = sy_gltf_load(path, out->scene, &go, &out->gltf, err);
        if (r == SY_OK)
            r = report_warnings(path, out->gltf.warning_count, err);
        if (r == SY_OK) {
            out->root = out->gltf.root;
            if (camera_sel) r = sy_gltf_find_camera(out->scene, &out->gltf, camera_sel, &out->camera, err);
            else if (out->gltf.camera_node_count) out->camera = out->gltf.camera_nodes[0];
            if (r != SY_OK) sy_error_prefix(err, "%s", path);
        }
    }
    if (r == SY_OK) r = sy_scene_commit(out->scene, NULL, err);
    if (r == SY_OK && (out->is_gltf || out->is_x3d) && defaults) r = add_defaults(out, err);
    /* the user's world choices: sy_world (formats) maps them onto the world object */
    if (r == SY_OK && !sy_world_options_empty(&g_load.world) &&
        (r = sy_world_apply(out->scene, &out->background, &g_load.world, err)) == SY_OK)
        r = sy_scene_commit(out->scene, NULL, err);
    if (r != SY_OK) loaded_free(out);
    else
        sy_log(SY_LOG_DEBUG, "sy", path, "loaded in %.3f s: %u nodes, %u meshes, %u materials, %u lights, %u cameras",
               sy_time_now() - t0, sy_scene_count(out->scene, SY_TYPE_NODE), sy_scene_count(out->scene, SY_TYPE_MESH),
               sy_scene_count(out->scene, SY_TYPE_MATERIAL), sy_scene_count(out->scene, SY_TYPE_LIGHT),
               sy_scene_count(out->scene, SY_TYPE_CAMERA));
    return r;
}

/* X3D Viewpoint fieldOfView covers the smaller image side: adapt yfov to the output size. */
static void fit_x3d_cameras(loaded *ld, uint32_t w, uint32_t h)
{
    sy_error e = {0};
    if (sy_x3d_fit_cameras(ld->scene, &ld->x3d, (float)w / (float)h, &e) != SY_OK ||
        sy_scene_commit(ld->scene, NULL, &e) != SY_OK)
        sy_log(SY_LOG_WARNING, "sy", NULL, "viewpoint field of view not adapted: %s", e.message);
}

/* >>progress (terminal only) */
typedef struct progress_state {
    const char *label;
    double start, last_print;
    bool tty;
    bool announced; /* the "tiles" phase (sy_testpoint.h) was announced for this render */
} progress_state;

static void progress_cb(void *user, const sy_progress *p)
{
    progress_state *ps = user;
    if (!ps->announced && p->done < p->total) { /* a render is in progress (tests wait for it) */
        ps->announced = true;
        sy_testpoint("tiles");
    }
    if (!ps->tty || p->total == 0) return;
    double now = sy_time_now();
    if (p->done != p->total && now - ps->last_print < 0.1) return;
    ps->last_print = now;
    double el = now - ps->start, frac = (double)p->done / (double)p->total;
    double eta = frac > 0 ? el / frac - el : 0;
    fprintf(stderr, "\r%s: %llu/%llu tiles (%3.0f%%) %.1f s, ETA %.1f s   ", ps->label, (unsigned long long)p->done,
            (unsigned long long)p->total, frac * 100.0, el, eta);
    if (p->done == p->total) fprintf(stderr, "\r%*s\r", 70, "");
    fflush(stderr);
}

/* >>output */
static bool ends_with(const char *s, const char *suffix)
{
    size_t n = strlen(s), m = strlen(suffix);
    return n >= m && strcasecmp(s + n - m, suffix) == 0;
}

typedef struct out_opts {
    bool half;
    sy_png_options png;
    const sy_exr_attribute *attrs; /* extra EXR header attributes (sy:samples, sy:interrupted, ...) */
    int attr_count;
} out_opts;

#define OUTPUT_KINDS ".exr, .png, .jpg or .jpeg"
#define JPEG_QUALITY 92

static bool is_output_path(const char *path)
{
    return ends_with(path, ".exr") || ends_with(path, ".png") || ends_with(path, ".jpg") || ends_with(path, ".jpeg");
}

static sy_result write_image(const char *path, const sy_layer *l, const out_opts *o, sy_error *err)
{
    if (ends_with(path, ".exr"))
        return sy_exr_write_rgba_attrs(path, (int)l->width, (int)l->height, l->rgba, l->depth,
                                       o->half ? SY_EXR_PIXEL_HALF : SY_EXR_PIXEL_FLOAT, o->attrs, o->attr_count, err);
    if (ends_with(path, ".png")) return sy_png_write(path, (int)l->width, (int)l->height, l->rgba, &o->png, err);
    if (ends_with(path, ".jpg") || ends_with(path, ".jpeg"))
        return sy_jpeg_write(path, (int)l->width, (int)l->height, l->rgba, &o->png, JPEG_QUALITY, err);
    return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: output must end in " OUTPUT_KINDS, path);
}

/* The back-end a command uses without -b: the registry's default (sy_mediator_default). */
static const char *default_backend(sy_error *err)
{
    const char *name = sy_mediator_default_name();
    if (!*name) sy_error_set(err, SY_ERR_NOT_FOUND, "no back-end offers itself as the default; name one with -b (sy backends)");
    return *name ? name : NULL;
}

/* A scene file's extension, as the loaders' names suggest (the content decides later). */
static bool is_scene_name(const char *name)
{
    return ends_with(name, ".gltf") || ends_with(name, ".glb") || ends_with(name, ".x3d");
}

static int cmp_names(const void *a, const void *b) { return strcmp(*(char *const *)a, *(char *const *)b); }

/* `sy render DIR`: the one scene file in dir (into out), looked for directly in it and, when there
 * is none, one folder down (a Khronos sample's glTF/, glTF-Binary/ ...); several: an error that
 * lists them. */
static sy_result scene_in_folder(const char *dir, char *out, size_t out_len, sy_error *err)
{
    enum { MAX_LISTED = 12 };
    char *found[64];
    uint32_t n = 0, total = 0;
    for (int depth = 0; depth < 2 && total == 0; ++depth) {
        DIR *d = opendir(dir);
        if (!d) return sy_error_set(err, SY_ERR_IO, "%s: cannot read the folder: %s", dir, strerror(errno));
        struct dirent *de;
        while ((de = readdir(d))) {
            if (de->d_name[0] == '.') continue;
            char path[4096];
            snprintf(path, sizeof path, "%s%s%s", dir, ends_with(dir, "/") ? "" : "/", de->d_name);
            struct stat st;
            if (stat(path, &st) != 0) continue;
            if (depth == 0 && S_ISREG(st.st_mode) && is_scene_name(de->d_name)) {
                if (n < 64) found[n++] = strdup(path);
                total++;
            } else if (depth == 1 && S_ISDIR(st.st_mode)) {
                DIR *sd = opendir(path);
                struct dirent *se;
                while (sd && (se = readdir(sd))) {
                    char sub[4096 + 256];
                    snprintf(sub, sizeof sub, "%s/%s", path, se->d_name);
                    if (se->d_name[0] == '.' || !is_scene_name(se->d_name) || stat(sub, &st) != 0 || !S_ISREG(st.st_mode))
                        continue;
                    if (n < 64) found[n++] = strdup(sub);
                    total++;
                }
                if (sd) closedir(sd);
            }
        }
        closedir(d);
    }
    for (uint32_t i = 0; i < n; ++i)
        if (!found[i]) { /* strdup failed */
            for (uint32_t k = 0; k < n; ++k) free(found[k]);
            return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", dir);
        }
    qsort(found, n, sizeof *found, cmp_names);
    sy_result r = SY_OK;
    if (total == 1) {
        if (snprintf(out, out_len, "%s", found[0]) >= (int)out_len)
            r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: path too long", found[0]);
    } else if (total == 0) {
        r = sy_error_set(err, SY_ERR_NOT_FOUND, "%s: no scene file (.gltf, .glb, .x3d) in the folder or one folder down", dir);
    } else {
        char list[2048] = "";
        size_t used = 0;
        for (uint32_t i = 0; i < n && i < MAX_LISTED && used < sizeof list; ++i)
            used += (size_t)snprintf(list + used, sizeof list - used, "\n  %s", found[i]);
        r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: %u scene files; name one:%s%s", dir, total, list,
                         total > MAX_LISTED ? "\n  ..." : "");
    }
    for (uint32_t i = 0; i < n; ++i) free(found[i]);
    return r;
}

/* `sy render SCENE` without -o: STEM.png in the current folder (STEM: the file's name without its
 * extension; "demo" for the built-in scene). */
static void default_output(const char *scene, char *out, size_t out_len)
{
    const char *base = strrchr(scene, '/');
    base = base ? base + 1 : scene;
    const char *dot = strrchr(base, '.');
    int n = dot && dot != base ? (int)(dot - base) : (int)strlen(base);
    snprintf(out, out_len, "%.*s.png", n, base);
}

/* Renders one mono viewport of the whole window with the given back-end. */
/* Renders one mono viewport of the whole window with the given back-end; samples: samples per
 * pixel for a progressive back-end (0 = its default pass). */
static sy_result render_scene(loaded *ld, const char *backend, const char *params, uint32_t w, uint32_t h,
                              uint32_t samples, sy_context_pool *pool, sy_layer *out, double *seconds, sy_error *err)
{
    sy_window *win = NULL;
    sy_viewport *vp;
    sy_result r = sy_window_create(w, h, &win, err);
    sy_viewport_desc vd = {
        .root = ld->root, .camera = ld->camera, .background = ld->background, .backend = backend, .params = params};
    if (r == SY_OK) r = sy_window_add_viewport(win, &vd, &vp, err);
    if (r == SY_OK) r = sy_layer_create(w, h, out, err);
    progress_state ps = {backend, sy_time_now(), 0, sy_is_terminal(2), false};
    sy_window_render_opts ro = {.progress = progress_cb, .progress_user = &ps, .sample_count = samples};
    double t0 = sy_time_now();
    if (r == SY_OK) r = sy_window_render(win, ld->scene, pool, &ro, out, err);
    *seconds = sy_time_now() - t0;
    sy_window_destroy(win);
    return r;
}

/* >>progressive (path tracer): sample budget, environment, feature buffers */
typedef struct pt_opts {
    uint32_t spp;         /* 0 = default (64 unless a time budget is given) */
    double time_budget;   /* seconds, 0 = none */
    bool aov;             /* write feature buffers as extra EXR channels */
} pt_opts;

typedef struct pt_progress {
    double start;
    uint64_t done, total; /* samples per pixel; total 0 = time budget */
    double budget;
} pt_progress;

static void pt_progress_print(const pt_progress *p, bool final)
{
    double el = sy_time_now() - p->start, rate = el > 0 ? (double)p->done / el : 0;
    if (final) {
        fprintf(stderr, "\r%*s\r", 78, "");
    } else if (p->total) {
        double eta = rate > 0 ? (double)(p->total - p->done) / rate : 0;
        fprintf(stderr, "\rpathtracer: %llu/%llu samples, %.2f samples/s, %.1f s, ETA %.1f s   ",
                (unsigned long long)p->done, (unsigned long long)p->total, rate, el, eta);
    } else {
        fprintf(stderr, "\rpathtracer: %llu samples, %.2f samples/s, %.1f s, ETA %.1f s   ", (unsigned long long)p->done,
                rate, el, fmax(0.0, p->budget - el));
    }
    fflush(stderr);
}

/* Renders a progressive back-end in passes until the sample count or the time budget is reached,
 * through the same window composition as a single-pass render (overlays and stereo included).
 * *out / *out_right get the final images; *samples_out the samples per pixel accumulated by the
 * main back-end; *ctx_out its (pool-owned) context. */
static sy_result render_progressive(loaded *ld, const sy_compose_spec *spec, uint32_t w, uint32_t h, const pt_opts *po,
                                    sy_context_pool *pool, sy_layer *out, sy_layer *out_right, double *seconds,
                                    uint64_t *samples_out, sy_context **ctx_out, sy_error *err)
{
    sy_params pp;
    sy_result r = sy_params_parse(spec->params, &pp, err);
    uint64_t target = po->spp ? po->spp : (po->time_budget > 0 ? 0 : 64);
    pt_progress pr = {sy_time_now(), 0, target, po->time_budget};
    bool tty = sy_is_terminal(2);
    double t0 = sy_time_now(), last_print = 0;
    uint32_t chunk = 1;
    while (r == SY_OK) {
        uint64_t left = target ? target - pr.done : UINT32_MAX;
        uint32_t n = (uint32_t)(left < chunk ? left : chunk);
        double p0 = sy_time_now();
        sy_window_render_opts ro = {.sample_count = n};
        sy_layer_destroy(out);
        sy_layer_destroy(out_right);
        r = sy_compose_render(ld->scene, pool, spec, w, h, &ro, out, out_right, err);
        if (r != SY_OK) break;
        pr.done += n;
        /* the samples the back-end actually holds (a cooperative cluster adds them in multiples of its
         * server count) */
        sy_context *mc = NULL;
        sy_mediator_stats ms = {0};
        if (sy_context_pool_get(pool, ld->scene, spec->backend, &pp, ld->root.id, &mc, err) == SY_OK) {
            sy_context_stats(mc, &ms);
            if (ms.samples > pr.done) pr.done = ms.samples;
        }
        double now = sy_time_now(), pass = (now - p0) / n;
        if (tty && now - last_print > 0.1) {
            pt_progress_print(&pr, false);
            last_print = now;
        }
        if (target && pr.done >= target) break;
        if (po->time_budget > 0 && now - t0 + pass > po->time_budget) break;
        sy_testpoint("pass"); /* a pass is done and the graceful interrupt armed (tests wait for it) */
        if (sy_signals_interrupted()) break; /* first Ctrl-C: keep what the finished passes gave */
        /* passes of about a quarter of a second: responsive progress, little overhead */
        double want = pass > 0 ? 0.25 / pass : 64;
        chunk = want < 1 ? 1 : want > 1024 ? 1024 : (uint32_t)want;
        if (po->time_budget > 0) {
            double rest = (po->time_budget - (now - t0)) / (pass > 0 ? pass : 1e-3);
            if (rest < chunk) chunk = rest < 1 ? 1 : (uint32_t)rest;
        }
    }
    *seconds = sy_time_now() - t0;
    if (tty) pt_progress_print(&pr, true);
    sy_context *ctx = NULL;
    if (r == SY_OK) r = sy_context_pool_get(pool, ld->scene, spec->backend, &pp, ld->root.id, &ctx, err);
    if (r == SY_OK) {
        sy_mediator_stats st = {0};
        sy_context_stats(ctx, &st);
        *samples_out = st.samples;
        *ctx_out = ctx;
    }
    return r;
}

/* Writes the back-end's feature buffers (SY_CAP_AOVS) as channels of one EXR: colour and depth
 * as R G B A Z, every other plane as NAME.{R,G,B} (normal: NAME.{X,Y,Z}), e.g. variance.R. */
static sy_result write_aov_exr(const char *path, sy_context *ctx, const out_opts *o, sy_error *err)
{
    sy_aovs a;
    sy_result r = sy_context_aovs(ctx, &a, err);
    if (r != SY_OK) return r;
    sy_exr_channel_desc ch[4 * SY_AOVS_MAX];
    int n = 0;
    static const char *const rgba[4] = {"R", "G", "B", "A"}, *const rgb[4] = {"R", "G", "B", "A"},
                             *const xyz[3] = {"X", "Y", "Z"};
    char names[SY_AOVS_MAX][4][48];
    sy_exr_pixel_type ct = o->half ? SY_EXR_PIXEL_HALF : SY_EXR_PIXEL_FLOAT;
    for (uint32_t k = 0; k < a.count; ++k) {
        const sy_aov_plane *p = &a.planes[k];
        if (!strcmp(p->name, "color")) {
            for (uint32_t i = 0; i < 4 && i < p->channels; ++i) ch[n++] = (sy_exr_channel_desc){rgba[i], p->data, p->channels, i, ct};
        } else if (!strcmp(p->name, "depth")) {
            ch[n++] = (sy_exr_channel_desc){"Z", p->data, p->channels, 0, SY_EXR_PIXEL_FLOAT};
        } else {
            bool normal = !strcmp(p->name, "normal");
            for (uint32_t i = 0; i < p->channels && i < (normal ? 3u : 4u); ++i) {
                snprintf(names[k][i], sizeof names[k][i], "%s.%s", p->name, normal ? xyz[i] : rgb[i]);
                ch[n++] = (sy_exr_channel_desc){names[k][i], p->data, p->channels, i, ct};
            }
        }
    }
    sy_exr_write_desc wd = {.width = (int)a.width, .height = (int)a.height, .channels = ch, .channel_count = n,
                            .attributes = o->attrs, .attribute_count = o->attr_count};
    r = sy_exr_write(path, &wd, err);
    sy_aovs_free(&a);
    return r;
}

/* >>commands */
static int fail(const sy_error *e)
{
    sy_log(SY_LOG_ERROR, "sy", NULL, "%s", e->message);
    return 1;
}

/* The command summary, to stdout for --help (exit 0) or stderr after a usage error (exit 2). An entry
 * is a line "  sy COMMAND ..." and the deeper-indented lines after it; the lines from "SCENE:" on
 * are for every command. */
static const char usage_text[] =
            "usage:\n"
            "  sy [-q | -v] COMMAND [ARGS]          -q (--quiet): errors only; -v (--verbose): debug messages too\n"
            "                                       (also accepted after COMMAND)\n"
            "  sy --version | sy version            the Switchyard version\n"
            "  sy --help | sy help [COMMAND]        this summary (on stdout); sy COMMAND --help: the command's\n"
            "  sy info SCENE | IMAGE.exr | IMAGE.png  JSON summary: counts, bounds, warnings; an image's size and\n"
            "                                       metadata (EXR channels and header attributes, PNG text chunks)\n"
            "  sy render SCENE|DIR [-b BACKEND] [-o OUT.exr|png|jpg] [-w W] [-h H] [--camera NAME|INDEX]\n"
            "            (-b: the default back-end, sy backends marks it; -o: STEM.png in the current folder;\n"
            "             DIR: the one scene file in the folder, or one folder down)\n"
            "            [--params k=v,...] [--half] [--exposure EV] [--tonemap clamp|reinhard|aces]  (PNG, JPEG; default aces)\n"
            "            [--max-memory MB]   (ray tracers: refuse a scene whose BVHs need more)\n"
            "            [--gl osmesa|egl|glfw]   (-b raster: the GL context provider)\n"
            "            [--stereo sbs|tb|anaglyph|separate] [--eye-sep M] [--zero-parallax M]\n"
            "            [--overlay FILE[:BACKEND]] [--composite depth|over|replace]\n"
            "  sy render SCENE -b pathtracer [-o OUT.exr|png|jpg] [--spp N | --time SECONDS] [--aov]\n"
            "            (+ the options above)\n"
            "            [--filter none|pixel|atrous|jbu|adaptive|radiance] [--threshold T]   (display filter)\n"
            "  sy demo [-o DIR] [-w W] [-h H] [--filter pixel|none|...]   (the progressive back-end's display filter)\n"
            "  sy compare SCENE [-w W] [-h H] [--spp N] [-o SHEET.png] [--camera C] [--backends a,b,...]\n"
            "            (every back-end side by side: contact sheet + mean luminance, ratio and IoU table)\n"
            "  sy view SCENE [-b BACKEND] [-w W] [-h H] [--camera C] [--overlay FILE[:BACKEND]]\n"
            "          [--frames N --screenshot OUT.png] [--filter none|pixel|atrous|jbu|adaptive|radiance] [--threshold T]\n"
            "          [--keys KEYS]   (automated runs: press these keys one frame after another, e.g. F]F[)\n"
            "          [--budget MS]   (frame time while the view moves: the resolution follows it; default 33)\n"
            "          [--cluster URL[,URL...]|FILE.conf [--cluster-mode MODE] [--secret-file F] [--timeout-ms MS]\n"
            "           [--spp SAMPLES_PER_SERVER_AND_FRAME]]   (the same cluster options as sy render)\n"
            "  sy web SCENE [-b BACKEND] [--listen HOST:PORT] [--camera C] [-w MAX_W] [-h MAX_H] [--quality Q]\n"
            "          [--filter none|pixel|...] [--threshold T] [--budget MS] [--client-render]   (the view in a browser:\n"
            "           open the URL it prints; another address than loopback needs the printed token)\n"
            "  sy bench web [SCENE] [-b BACKEND] [-w W] [-h H] [--repeats N]   (input-to-frame latency, loopback)\n"
            "  sy bench sync [--nodes N] [--tris T] [--repeats R]\n"
            "  sy bench rays [SCENE] [-w W] [-h H] [--repeats R]\n"
            "  sy bench pathtracer [SCENE] [-w W] [-h H] [--repeats PASSES]\n"
            "  sy bench limit [SCENE] [-w W] [-h H] [--spp N] [--repeats N]   (path tracer vs raw Embree, same rays)\n"
            "  sy bench filters [SCENE --reference REF.exr] [SHEET.png] [-w W] [-h H] [--repeats R]\n"
            "  sy bench raster [SCENE] [-w W] [-h H] [--repeats R] [--params gl=egl,msaa=4]\n"
            "  sy bench viewports [-w W] [-h H] [--repeats R]\n"
            "  sy bench load [GLTF_SAMPLE_DIR] [--tris T] [--repeats R]\n"
            "  sy bench memory [--tris T] [-b whitted|pathtracer] [--glb] [-w W] [-h H]   (peak RSS per triangle)\n"
            "  sy bench instances [--nodes INSTANCES] [--tris PER_MESH] [-w W] [-h H] [--repeats FRAMES] [-b BACKEND]\n"
            "            (one mesh instanced: 10^3 x 10^6 triangles by default, every picture back-end)\n"
            "  sy bench governor [SCENE] [--budget MS] [--frames N] [-w W] [-h H]   (frame-time governor, orbiting camera)\n"
            "  sy bench cull [--tris N] [--objects N] [--budget T] [-w W] [-h H] [--frames N] [--write PLANT.glb]\n"
            "  sy coverage SCENE [--camera C] [-w W] [-h H] [--top N]\n"
            "  sy backends [--params] [--json]\n"
            "  sy serve [--listen tcp://HOST:PORT] [--secret-file F] [--output OUT.exr|png] (sy serve --help)\n"
            "  sy render SCENE -b BACKEND -o OUT --cluster URL[,URL...]|FILE.conf\n"
            "            [--cluster-mode sort-first|balanced|cooperative|multi-display|stereo] [--secret-file F]\n"
            "            [--tls-ca PEM] [--timeout-ms MS] [--frames N] [--spp N] [--cluster-pixels float|half]\n"
            "  sy bench cluster [-w W] [-h H] [--repeats ROUNDS]\n"
            "  sy bench cluster --soak SECONDS [--warmup S] [-b BACKEND] [-w W] [-h H]   (sy serve soak: RSS, fds, threads)\n"
            "SCENE: a glTF (.gltf, .glb) or X3D (XML) file, recognised by its content, or 'demo' (the built-in scene)\n"
            "world options (every command): [--env MAP.exr | --env-color R,G,B] [--env-intensity X] [--env-hidden]\n"
            "  [--background R,G,B[,A]] [--no-default-light]: the environment is a light; the background is what\n"
            "  the camera sees where nothing is hit; a scene with no light of its own is lit by a neutral studio\n"
            "  environment unless --no-default-light is given\n"
            "loading (every command): [--allow-path DIR] (more folders a model's files may lie in) [--strict]\n"
            "  (a skipped or repaired item fails the load) [--max-scene-mb N] (budget per file: vertices, indices,\n"
            "  images and placements together; default an eighth of the physical memory)\n"
            "exit status: 0 success, 1 failure (the error names the file, peer or value), 2 usage error,\n"
            "  130 interrupted\n"
            "bash completion: source apps/sy/sy-completion.bash\n";

/* The summary (cmd NULL) or the entries of one command ("render", "bench", "bench sync") and the
 * common part. */
static void usage_to(FILE *f, const char *cmd)
{
    if (!cmd) {
        fputs(usage_text, f);
        return;
    }
    char want[64];
    snprintf(want, sizeof want, "  sy %s ", cmd);
    bool in = false, footer = false;
    for (const char *l = usage_text; *l;) {
        const char *nl = strchr(l, '\n');
        size_t n = nl ? (size_t)(nl - l) + 1 : strlen(l);
        if (!strncmp(l, "usage:", 6)) in = true;                          /* the heading */
        else if (!strncmp(l, "  sy ", 5)) in = !strncmp(l, want, strlen(want)); /* an entry */
        else if (strncmp(l, "   ", 3) != 0 && strncmp(l, "  ", 2) != 0) footer = true; /* SCENE:, world options... */
        if (in || footer) fwrite(l, 1, n, f);
        l += n;
    }
}

/* A usage error without a named option (an operand missing): the command's usage on stderr, 2. */
static int usage_of(const char *cmd, const char *what)
{
    if (what) fprintf(stderr, "sy %s: error: %s\n", cmd, what);
    usage_to(stderr, cmd);
    return 2;
}

/* "--name" of a long option's code in a getopt_long table (for messages). */
static const char *option_name(const struct option *lo, int c)
{
    static char buf[64];
    for (; lo->name; ++lo)
        if (lo->val == c && !lo->flag) {
            snprintf(buf, sizeof buf, "--%s", lo->name);
            return buf;
        }
    return "an option";
}

/* A usage error naming the option and the value it did not accept. */
static int bad_value(const char *opt, const char *value)
{
    fprintf(stderr, "sy: error: %s: '%s' is not an accepted value\n", opt, value);
    return 2;
}

static bool parse_u32(const char *s, uint32_t lo, uint32_t hi, uint32_t *out)
{
    char *end;
    errno = 0;
    unsigned long v = strtoul(s, &end, 10);
    if (errno || end == s || *end || v < lo || v > hi) return false;
    *out = (uint32_t)v;
    return true;
}

/* -w W / -h H of every command that renders: 1..16384 pixels; false names nothing (the caller does). */
static bool size_option(int c, const char *value, uint32_t *w, uint32_t *h)
{
    return parse_u32(value, 1, 16384, c == 'w' ? w : h);
}

/* >>json: the JSON that commands print is built and written by cJSON. jadd adds an item to an object
 * (key) or an array (key NULL); a failed allocation is remembered and reported by print_json. */
static bool g_json_failed;

static cJSON *jadd(cJSON *parent, const char *key, cJSON *item)
{
    if (item && parent && (key ? cJSON_AddItemToObject(parent, key, item) : cJSON_AddItemToArray(parent, item)))
        return item;
    cJSON_Delete(item);
    g_json_failed = true;
    return NULL;
}

/* a float as its shortest decimal that reads back as the same float (not the double's 17 digits) */
static cJSON *jfloat(double v)
{
    char t[32];
    snprintf(t, sizeof t, "%.9g", v);
    return cJSON_CreateNumber(strtod(t, NULL));
}

static cJSON *jstr(const char *s) { return cJSON_CreateString(s ? s : ""); }

/* The layout of sy's JSON (for people and grep; cJSON writes every key and value): the top level's
 * members one per line, a nested value on one line ("key": value, ", " between items) unless it
 * holds objects or is longer than JSON_LINE characters; then its members one per line. */
#define JSON_LINE 160

static bool json_write(FILE *f, const cJSON *v, int depth);

static bool json_leaf(FILE *f, const cJSON *v) /* a string, number, bool or null: cJSON's text */
{
    char *t = cJSON_PrintUnformatted(v);
    if (!t) return false;
    fputs(t, f);
    cJSON_free(t);
    return true;
}

static bool json_members(FILE *f, const cJSON *v, int depth, bool broken)
{
    bool obj = cJSON_IsObject(v), ok = true;
    fputc(obj ? '{' : '[', f);
    for (const cJSON *c = v->child; c && ok; c = c->next) {
        if (broken) fprintf(f, "%s\n%*s", c == v->child ? "" : ",", 2 * (depth + 1), "");
        else if (c != v->child) fputs(", ", f);
        if (obj) {
            cJSON *key = cJSON_CreateString(c->string);
            ok = key && json_leaf(f, key);
            cJSON_Delete(key);
            fputs(": ", f);
        }
        ok = ok && json_write(f, c, depth + 1);
    }
    if (broken && v->child) fprintf(f, "\n%*s", 2 * depth, "");
    fputc(obj ? '}' : ']', f);
    return ok;
}

static bool json_write(FILE *f, const cJSON *v, int depth)
{
    if (!cJSON_IsObject(v) && !cJSON_IsArray(v)) return json_leaf(f, v);
    bool broken = depth == 0;
    for (const cJSON *c = v->child; c && !broken; c = c->next) broken = cJSON_IsObject(c);
    if (!broken) { /* one line if it is short */
        char *line = NULL;
        size_t len = 0;
        FILE *m = open_memstream(&line, &len);
        bool ok = m && json_members(m, v, depth, false);
        if (m) fclose(m);
        if (ok && len <= JSON_LINE) fputs(line, f);
        free(line);
        if (!ok) return false;
        if (len <= JSON_LINE) return true;
    }
    return json_members(f, v, depth, true);
}

/* Writes doc to stdout and frees it; 1 when something failed (out of memory). */
static int print_json(cJSON *doc)
{
    bool ok = doc && !g_json_failed && json_write(stdout, doc, 0);
    cJSON_Delete(doc);
    if (!ok) {
        sy_log(SY_LOG_ERROR, "sy", NULL, "out of memory while writing JSON");
        return 1;
    }
    fputc('\n', stdout);
    return 0;
}

/* sy info IMAGE.exr: size, channels and the header's string attributes (what sy render records) as JSON. */
static int info_exr(const char *path)
{
    sy_error err = {0};
    sy_exr_image *img = NULL;
    if (sy_exr_read(path, &img, &err) != SY_OK) return fail(&err);
    cJSON *doc = cJSON_CreateObject();
    jadd(doc, "file", jstr(path));
    jadd(doc, "width", cJSON_CreateNumber(img->width));
    jadd(doc, "height", cJSON_CreateNumber(img->height));
    cJSON *ch = jadd(doc, "channels", cJSON_CreateArray());
    for (int i = 0; i < img->channel_count; ++i) jadd(ch, NULL, jstr(img->channels[i].name));
    cJSON *at = jadd(doc, "attributes", cJSON_CreateObject());
    for (int i = 0; i < img->attribute_count; ++i) jadd(at, img->attributes[i].name, jstr(img->attributes[i].value));
    sy_exr_image_free(img);
    return print_json(doc);
}

/* sy info IMAGE.png: the size and the text chunks (sy render writes its metadata there: sy:renderer,
 * sy:backend, ...), in the same shape as an EXR's (attributes) */
static int info_png(const char *path)
{
    sy_error err = {0};
    sy_png_info pi;
    if (sy_png_read_info(path, &pi, &err) != SY_OK) return fail(&err);
    cJSON *doc = cJSON_CreateObject();
    jadd(doc, "file", jstr(path));
    jadd(doc, "width", cJSON_CreateNumber(pi.width));
    jadd(doc, "height", cJSON_CreateNumber(pi.height));
    cJSON *at = jadd(doc, "attributes", cJSON_CreateObject());
    for (int i = 0; i < pi.text_count; ++i) jadd(at, pi.keys[i], jstr(pi.values[i]));
    sy_png_info_free(&pi);
    return print_json(doc);
}

/* counts of one kind of object in an info object */
static void jcounts(cJSON *o, const char *const *names, const uint32_t *values, size_t n)
{
    for (size_t i = 0; i < n; ++i) jadd(o, names[i], cJSON_CreateNumber(values[i]));
}

/* sy info's log while it loads: warnings are part of its JSON output, everything else goes to stderr. */
static void info_log(void *user, sy_log_level level, const char *module, const char *item, const char *message)
{
    if (level != SY_LOG_WARNING) sy_log_stderr(user, level, module, item, message);
}

static int cmd_info(int argc, char **argv)
{
    static const struct option lo[] = {{"json", no_argument, NULL, OPT_JSON}, COMMON_OPTIONS};
    int c, status = 0;
    optind = 0;
    while ((c = next_option("info", argc, argv, SHORT_OPTIONS(""), lo, &status)) != -1)
        if (c == OPT_STOP) return status; /* --json: the output is JSON anyway */
    if (argc - optind != 1) return usage_of("info", argc == optind ? "a SCENE, IMAGE.exr or IMAGE.png is required" : "one file at a time");
    const char *path = argv[optind];
    sy_file_format fmt = SY_FORMAT_UNKNOWN;
    sy_error err = {0}, ignore = {0};
    if (sy_sniff_file(path, &fmt, &ignore) != SY_OK) fmt = SY_FORMAT_UNKNOWN; /* the loader names a missing file */
    if (fmt == SY_FORMAT_PNG) return info_png(path); /* by content, as scenes are recognised */
    if (ends_with(path, ".exr")) return info_exr(path);
    loaded ld;
    sy_log_set_callback(info_log, NULL); /* the load's warnings go into the JSON, not also to stderr */
    sy_result lr = load(path, NULL, false, &ld, &err);
    sy_log_set_callback(NULL, NULL);
    if (lr != SY_OK) return fail(&err);
    sy_bounds b;
    sy_node_world_bounds(ld.scene, ld.root, &b, NULL);
    /* counts of what was loaded into the scene (less the synthetic root node) */
    uint32_t prims = 0, tris = 0;
    for (uint32_t id = sy_scene_next(ld.scene, SY_TYPE_MESH, 0); id; id = sy_scene_next(ld.scene, SY_TYPE_MESH, id)) {
        const sy_mesh_data *m = sy_object_get(ld.scene, SY_TYPE_MESH, id);
        prims += m->primitives.count;
        for (uint32_t i = 0; i < m->primitives.count; ++i) tris += sy_primitive_triangle_count(&m->primitives.items[i]);
    }
    /* One layout for every format: format, the file's own counts (file_counts: what it declares,
     * skipped items included), what was loaded into the scene (loaded), bounds, warnings. */
    cJSON *doc = cJSON_CreateObject();
    jadd(doc, "file", jstr(path));
    jadd(doc, "format", jstr(ld.is_gltf ? "gltf" : ld.is_x3d ? "x3d" : "demo"));
    static const char *const names[] = {"nodes",  "meshes", "primitives", "triangles", "materials",     "textures",
                                        "images", "lights", "cameras",    "points",    "line_segments", "skipped"};
    uint32_t v[12] = {0};
    if (ld.is_gltf) {
        const sy_gltf_counts *gc = &ld.gltf.counts;
        const uint32_t g[12] = {gc->nodes,   gc->meshes,  gc->primitives, gc->triangles,     gc->materials,
                                gc->textures, gc->images, gc->lights,     gc->cameras,       gc->points,
                                gc->line_segments, gc->skipped_primitives};
        memcpy(v, g, sizeof v);
    } else if (ld.is_x3d) { /* X3D declares no totals: what its nodes made (an ImageTexture is one image) */
        const sy_x3d_counts *xc = &ld.x3d.counts;
        const uint32_t x[12] = {xc->nodes,    xc->meshes,   xc->primitives, xc->triangles, xc->materials,
                                xc->textures, xc->textures, xc->lights,     xc->cameras,   xc->points,
                                xc->line_segments, xc->skipped_geometry};
        memcpy(v, x, sizeof v);
    }
    if (ld.is_gltf || ld.is_x3d) jcounts(jadd(doc, "file_counts", cJSON_CreateObject()), names, v, 12);
    else jadd(doc, "file_counts", cJSON_CreateNull()); /* the built-in scene: no file */
    static const char *const lnames[] = {"nodes", "meshes", "primitives", "triangles", "materials",
                                         "textures", "lights", "cameras"};
    const uint32_t lv[] = {sy_scene_count(ld.scene, SY_TYPE_NODE) - 1, sy_scene_count(ld.scene, SY_TYPE_MESH), prims,
                           tris, sy_scene_count(ld.scene, SY_TYPE_MATERIAL), sy_scene_count(ld.scene, SY_TYPE_TEXTURE),
                           sy_scene_count(ld.scene, SY_TYPE_LIGHT), sy_scene_count(ld.scene, SY_TYPE_CAMERA)};
    jcounts(jadd(doc, "loaded", cJSON_CreateObject()), lnames, lv, 8);
    if (sy_bounds_is_empty(&b)) {
        jadd(doc, "bounds", cJSON_CreateNull());
    } else {
        cJSON *bo = jadd(doc, "bounds", cJSON_CreateObject());
        cJSON *mn = jadd(bo, "min", cJSON_CreateArray()), *mx = jadd(bo, "max", cJSON_CreateArray());
        for (int k = 0; k < 3; ++k) {
            jadd(mn, NULL, jfloat((double)b.min[k]));
            jadd(mx, NULL, jfloat((double)b.max[k]));
        }
    }
    jadd(doc, "warning_count", cJSON_CreateNumber(ld.gltf.warning_count + ld.x3d.warning_count)); /* all, stored or not */
    cJSON *wa = jadd(doc, "warnings", cJSON_CreateArray());
    for (uint32_t i = 0; i < ld.gltf.stored_warning_count; ++i) jadd(wa, NULL, jstr(ld.gltf.warnings[i]));
    for (uint32_t i = 0; i < ld.x3d.stored_warning_count; ++i) jadd(wa, NULL, jstr(ld.x3d.warnings[i]));
    loaded_free(&ld);
    return print_json(doc);
}

/* NAME.EXT -> NAME_left.EXT and NAME_right.EXT */
static sy_result eye_paths(const char *outp, char *lp, char *rp, size_t n, sy_error *err)
{
    const char *dot = strrchr(outp, '.');
    size_t stem = dot ? (size_t)(dot - outp) : strlen(outp);
    if ((size_t)snprintf(lp, n, "%.*s_left%s", (int)stem, outp, dot ? dot : "") >= n ||
        (size_t)snprintf(rp, n, "%.*s_right%s", (int)stem, outp, dot ? dot : "") >= n)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: path too long", outp);
    return SY_OK;
}

/* --overlay FILE[:BACKEND]: loads FILE into the same scene under its own root and layers it over
 * the main viewport with the --composite mode (depth, over, replace). */
static sy_result add_overlay(loaded *ld, const char *arg, const char *composite, sy_compose_spec *spec, sy_error *err)
{
    char path[4096];
    const char *colon = strrchr(arg, ':');
    const char *backend = colon && colon[1] && !strchr(colon, '/') ? colon + 1 : NULL;
    size_t n = backend ? (size_t)(colon - arg) : strlen(arg);
    if (n >= sizeof path) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "--overlay: path too long");
    memcpy(path, arg, n);
    path[n] = '\0';
    if (!strcmp(composite, "depth")) spec->overlay_composite = SY_COMPOSITE_DEPTH;
    else if (!strcmp(composite, "over")) spec->overlay_composite = SY_COMPOSITE_ALPHA_OVER;
    else if (!strcmp(composite, "replace")) spec->overlay_composite = SY_COMPOSITE_REPLACE;
    else return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "--composite %s: expected depth, over or replace", composite);
    if (!backend) backend = sy_mediator_find("raster") ? "raster" : spec->backend;
    if (!sy_mediator_find(backend)) return sy_error_set(err, SY_ERR_NOT_FOUND, "--overlay %s: back-end '%s' is not registered", arg, backend);
    sy_gltf_info info = {0};
    sy_gltf_options go = {.allowed_roots = g_load.roots, .allowed_root_count = g_load.root_count,
                          .max_scene_bytes = g_load.max_scene_bytes};
    sy_result r = sy_gltf_load(path, ld->scene, &go, &info, err);
    if (r == SY_OK) r = report_warnings(path, info.warning_count, err);
    if (r == SY_OK) r = sy_scene_commit(ld->scene, NULL, err);
    if (r != SY_OK) {
        sy_gltf_info_free(&info);
        sy_error_prefix(err, "overlay");
        return r;
    }
    spec->has_overlay = true;
    spec->overlay_root = info.root;
    spec->overlay_backend = backend;
    sy_gltf_info_free(&info);
    return SY_OK;
}

/* `--gl PROVIDER` (raster back-end): appended to the back-end parameters as gl=PROVIDER. */
static const char *render_gl_params(const char *params, const char *provider, char *buf, size_t len)
{
    snprintf(buf, len, "%s%sgl=%s", params ? params : "", params && *params ? "," : "", provider);
    return buf;
}

/* `--filter NAME [--threshold T]` (path tracer display filter): appended to the back-end
 * parameters as filter=NAME,threshold=T; the mediator validates them (sy_mediator_rt.h). */
static const char *render_filter_params(const char *params, const char *filter, const char *threshold, char *buf,
                                        size_t len)
{
    snprintf(buf, len, "%s%s%s%s%s%s", params ? params : "", params && *params ? "," : "", filter ? "filter=" : "",
             filter ? filter : "", filter && threshold ? "," : "", threshold ? "threshold=" : "");
    if (threshold) strncat(buf, threshold, len - strlen(buf) - 1);
    return buf;
}

/* One line per cluster frame on stderr: servers, failures, bytes (the cluster mediator's statistics). */
static void cluster_report(sy_scene *scene, sy_context_pool *pool, const sy_compose_spec *spec, uint32_t frame,
                           uint32_t servers)
{
    sy_params pp;
    sy_context *ctx = NULL;
    sy_error e = {0};
    if (sy_params_parse(spec->params, &pp, &e) != SY_OK ||
        sy_context_pool_get(pool, scene, spec->backend, &pp, spec->root.id, &ctx, &e) != SY_OK ||
        !(sy_context_caps(ctx) & SY_CAP_REMOTE))
        return;
    sy_cluster_frame_stats st;
    uint32_t mode = 0;
    sy_cluster_cli_last_frame(ctx, &st, &mode);
    sy_log(SY_LOG_NOTE, "sy", NULL,
           "cluster frame %u (%s): %u/%u servers, %u failed, %u reassigned, %.3f s, "
           "%llu bytes sent (%llu scene), %llu received",
           frame + 1, sy_cluster_cli_mode_name(mode), st.servers_live, servers, st.servers_failed, st.reassigned,
           st.seconds, (unsigned long long)st.bytes_sent, (unsigned long long)st.scene_bytes,
           (unsigned long long)st.bytes_received);
    if (mode == SY_CLUSTER_COOPERATIVE)
        sy_log(SY_LOG_NOTE, "sy", NULL, "cluster: merged %llu samples per pixel", (unsigned long long)st.samples);
}

static int cmd_render(int argc, char **argv)
{
    const char *scene = NULL, *backend = NULL, *outp = NULL, *camera = NULL, *params = NULL;
    const char *gl_provider = NULL;
    const char *filter = NULL, *threshold = NULL; /* --filter / --threshold (path tracer) */
    const char *overlay = NULL, *composite = "depth";
    uint32_t w = 0, h = 0;
    out_opts oo = {.png = {.tonemap = SY_TONEMAP_DISPLAY}}; /* the library's display tone map */
    sy_compose_spec spec = {.eye_separation = 0.065f, .zero_parallax = 2.0f};
    sy_error perr = {0};
    sy_cluster_cli_opts clo = {0};
    pt_opts po = {0};
    bool progressive_opts = false; /* --spp / --time / --aov given */
    static const struct option lo[] = {
        {"spp", required_argument, NULL, OPT_SPP}, {"time", required_argument, NULL, OPT_TIME},
        {"aov", no_argument, NULL, OPT_AOV}, {"camera", required_argument, NULL, OPT_CAMERA},
        {"params", required_argument, NULL, OPT_PARAMS}, {"gl", required_argument, NULL, OPT_GL},
        {"filter", required_argument, NULL, OPT_FILTER}, {"threshold", required_argument, NULL, OPT_THRESHOLD},
        {"half", no_argument, NULL, OPT_HALF}, {"exposure", required_argument, NULL, OPT_EXPOSURE},
        {"tonemap", required_argument, NULL, OPT_TONEMAP}, {"stereo", required_argument, NULL, OPT_STEREO},
        {"eye-sep", required_argument, NULL, OPT_EYE_SEP}, {"zero-parallax", required_argument, NULL, OPT_ZERO_PARALLAX},
        {"overlay", required_argument, NULL, OPT_OVERLAY}, {"composite", required_argument, NULL, OPT_COMPOSITE},
        {"frames", required_argument, NULL, OPT_FRAMES}, /* cluster: frames through the same window */
        {"max-memory", required_argument, NULL, OPT_MAX_MEMORY},
        SY_CLUSTER_CLI_OPTIONS, COMMON_OPTIONS};
    uint32_t max_memory_mb = 0;
    int c, status = 0;
    optind = 0;
    while ((c = next_option("render", argc, argv, SHORT_OPTIONS("b:o:w:h:"), lo, &status)) != -1) {
        char *end = NULL;
        switch (c) {
        case OPT_STOP: return status;
        case 'b': backend = optarg; break;
        case OPT_SPP:
            if (!parse_u32(optarg, 1, 1u << 24, &po.spp)) return bad_value("--spp", optarg);
            progressive_opts = true;
            break;
        case OPT_TIME:
            po.time_budget = strtod(optarg, &end);
            if (end == optarg || *end || !(po.time_budget > 0) || !isfinite(po.time_budget)) return bad_value("--time", optarg);
            progressive_opts = true;
            break;
        case OPT_AOV: po.aov = progressive_opts = true; break;
        case 'o': outp = optarg; break;
        case 'w':
        case 'h':
            if (!size_option(c, optarg, &w, &h)) return bad_value(c == 'w' ? "-w" : "-h", optarg);
            break;
        case OPT_CAMERA: camera = optarg; break;
        case OPT_PARAMS: params = optarg; break;
        case OPT_GL: gl_provider = optarg; break;          /* raster: gl=... parameter */
        case OPT_FILTER: filter = optarg; break;           /* pathtracer: filter=... */
        case OPT_THRESHOLD: threshold = optarg; break;     /* pathtracer: threshold=... */
        case OPT_HALF: oo.half = true; break;
        case OPT_EXPOSURE:
            oo.png.exposure_stops = strtof(optarg, &end);
            if (end == optarg || *end || !isfinite(oo.png.exposure_stops)) return bad_value("--exposure", optarg);
            break;
        case OPT_TONEMAP:
            if (!strcmp(optarg, "aces")) oo.png.tonemap = SY_TONEMAP_ACES;
            else if (!strcmp(optarg, "reinhard")) oo.png.tonemap = SY_TONEMAP_REINHARD;
            else if (!strcmp(optarg, "clamp")) oo.png.tonemap = SY_TONEMAP_CLAMP;
            else return bad_value("--tonemap", optarg);
            break;
        case OPT_STEREO:
            if (sy_stereo_mode_parse(optarg, &spec.stereo, &perr) != SY_OK) return fail(&perr);
            break;
        case OPT_EYE_SEP: /* the range: sy_compose says why */
            spec.eye_separation = strtof(optarg, &end);
            if (end == optarg || *end) return bad_value("--eye-sep", optarg);
            break;
        case OPT_ZERO_PARALLAX:
            spec.zero_parallax = strtof(optarg, &end);
            if (end == optarg || *end) return bad_value("--zero-parallax", optarg);
            break;
        case OPT_OVERLAY: overlay = optarg; break;
        case OPT_COMPOSITE: composite = optarg; break;
        case OPT_FRAMES:
            if (!parse_u32(optarg, 1, 100000000u, &clo.frames)) return bad_value("--frames", optarg);
            break;
        case OPT_MAX_MEMORY:
            if (!parse_u32(optarg, 1, 1u << 30, &max_memory_mb)) return bad_value("--max-memory", optarg);
            break;
        default: /* --cluster ... (sy_cluster_cli.c) */
            if (!sy_cluster_cli_getopt(c, optarg, &clo)) return bad_value(option_name(lo, c), optarg);
        }
    }
    for (; optind < argc; ++optind) {
        if (scene) return usage_of("render", "one SCENE at a time");
        scene = argv[optind];
    }
    if (clo.cluster && !strcmp(clo.cluster, "mpi")) { /* mpirun -np N sy render ... --cluster mpi */
        bool served = false;
        sy_error merr = {0};
        sy_result mr = sy_cluster_cli_mpi_start(&clo, &served, &merr);
        if (served) return mr == SY_OK ? 0 : fail(&merr); /* a server rank: rank 0 is done */
        if (mr != SY_OK) return fail(&merr);
    }
    if (!scene) return usage_of("render", "a SCENE is required");
    sy_error err = {0};
    char in_folder[4096], auto_out[1024];
    struct stat sst;
    if (stat(scene, &sst) == 0 && S_ISDIR(sst.st_mode)) { /* sy render DIR: its one scene file */
        if (scene_in_folder(scene, in_folder, sizeof in_folder, &err) != SY_OK) return fail(&err);
        scene = in_folder;
    }
    if (!backend && !(backend = default_backend(&err))) return fail(&err);
    if (!outp) { /* STEM.png here; the line that reports the render names it */
        default_output(scene, auto_out, sizeof auto_out);
        outp = auto_out;
    }
    char gl_params[256];
    if (gl_provider) params = render_gl_params(params, gl_provider, gl_params, sizeof gl_params);
    char filter_params[512];
    if (filter || threshold) params = render_filter_params(params, filter, threshold, filter_params, sizeof filter_params);
    char memory_params[600];
    if (max_memory_mb) { /* --max-memory MB: the back-end's declared memory limit (max_memory_mb) */
        const sy_mediator_class *mc = sy_mediator_find(backend);
        if (mc && !sy_param_find(&mc->param_table, "max_memory_mb")) {
            sy_error_set(&err, SY_ERR_INVALID_ARGUMENT, "--max-memory: back-end '%s' has no memory limit (no max_memory_mb "
                         "parameter)", backend);
            return fail(&err);
        }
        snprintf(memory_params, sizeof memory_params, "%s%smax_memory_mb=%u", params ? params : "",
                 params && *params ? "," : "", max_memory_mb);
        params = memory_params;
    }
    /* the output's folder must take a file before anything is loaded or rendered (an unwritable
     * one was found only after the render): a temporary file is created there and removed */
    sy_atomic_file probe = {0};
    if (sy_atomic_file_begin(outp, &probe, &err) != SY_OK) return fail(&err);
    sy_atomic_file_abort(&probe);
    sy_params given = {0};
    if (sy_params_parse(params, &given, &err) != SY_OK) { /* a key twice ("spp=1,spp=2"): a usage error */
        sy_log(SY_LOG_ERROR, "sy", NULL, "%s", err.message);
        return 2;
    }
    if (!is_output_path(outp)) { /* before any loading or rendering */
        sy_error_set(&err, SY_ERR_INVALID_ARGUMENT, "%s: output must end in " OUTPUT_KINDS, outp);
        return fail(&err);
    }
    /* --cluster: the main viewport's back-end becomes the cluster mediator (the servers render with
     * -b BACKEND); everything below is the same render path as a local one */
    const char *remote = backend;
    char cluster_params[1400];
    uint32_t cluster_mode = 0, cluster_servers = 0;
    if (clo.cluster) {
        if (sy_cluster_cli_setup(&clo, backend, params, cluster_params, sizeof cluster_params, &cluster_mode,
                                 &cluster_servers, NULL, &err) != SY_OK)
            return fail(&err);
        if (cluster_mode == SY_CLUSTER_STEREO && spec.stereo == SY_STEREO_NONE) spec.stereo = SY_STEREO_SBS;
        backend = SY_MEDIATOR_CLUSTER_NAME;
        params = cluster_params;
    }
    char shown[96]; /* the back-end as reported: "whitted", or "whitted on 2 servers (sort-first)" */
    if (clo.cluster)
        snprintf(shown, sizeof shown, "%s on %u server%s (%s)", remote, cluster_servers, cluster_servers == 1 ? "" : "s",
                 sy_cluster_cli_mode_name(cluster_mode));
    else snprintf(shown, sizeof shown, "%s", remote);
    const sy_mediator_class *bcls = sy_mediator_find(backend);
    sy_params bparams = {0};
    if (!bcls) {
        sy_context *none = NULL;
        sy_context_create(NULL, backend, NULL, 0, &none, &err); /* the error that lists the back-ends */
        return fail(&err);
    }
    if (sy_params_parse(params, &bparams, &err) != SY_OK) return fail(&err);
    if (sy_mediator_class_check_params(bcls, &bparams, &err) != SY_OK) { /* unknown key, bad value: usage */
        sy_log(SY_LOG_ERROR, "sy", NULL, "%s", err.message); /* --params, --filter, --threshold, --gl */
        return 2;
    }
    uint32_t caps = sy_mediator_class_caps(bcls, &bparams);
    const sy_mediator_class *rcls = sy_mediator_find(remote);
    if ((filter || threshold) && !(caps & SY_CAP_FILTERS)) {
        sy_error_set(&err, SY_ERR_INVALID_ARGUMENT, "--filter and --threshold need a back-end with display filters, "
                     "such as a local -b pathtracer (got -b %s%s)",
                     remote, clo.cluster ? " with --cluster: its strips would be filtered apart" : "");
        return fail(&err);
    }
    bool progressive = (caps & SY_CAP_PROGRESSIVE) != 0;
    /* a cluster in sort-first / balanced mode over a progressive back-end: --spp is the samples of each request */
    bool remote_spp = clo.cluster && !progressive && rcls && (rcls->caps & SY_CAP_PROGRESSIVE) && po.spp && !po.aov &&
                      !(po.time_budget > 0);
    if (progressive_opts && !progressive && !remote_spp) {
        sy_error_set(&err, SY_ERR_INVALID_ARGUMENT, "--spp, --time and --aov need a progressive back-end; '%s'%s is not",
                     remote, clo.cluster ? " on the cluster in this mode (cooperative is)" : "");
        return fail(&err);
    }
    if (po.aov && !(caps & SY_CAP_AOVS)) {
        sy_error_set(&err, SY_ERR_INVALID_ARGUMENT, "--aov: back-end %s%s keeps no feature buffers", remote,
                     clo.cluster ? " on the cluster" : "");
        return fail(&err);
    }
    if (po.aov && (!ends_with(outp, ".exr") || spec.stereo != SY_STEREO_NONE || overlay)) {
        sy_error_set(&err, SY_ERR_INVALID_ARGUMENT, "%s: --aov needs an .exr output of a local mono render without overlay",
                     outp);
        return fail(&err);
    }
    loaded ld;
    if (load(scene, camera, true, &ld, &err) != SY_OK) return fail(&err);
    /* default size: 512 high, width from the camera's aspect ratio when it has one */
    float aspect = 1.0f;
    const sy_node_data *cn = ld.camera.id ? sy_node_get(ld.scene, ld.camera) : NULL;
    const sy_camera_data *cd = cn ? sy_camera_get(ld.scene, cn->camera) : NULL;
    if (cd && cd->aspect > 0) aspect = cd->aspect;
    if (ld.camera.id == 0 && !ld.is_gltf) aspect = 1.0f;
    if (!w && !h) h = 512, w = (uint32_t)lroundf(512 * aspect);
    else if (!w) w = (uint32_t)lroundf((float)h * aspect);
    else if (!h) h = (uint32_t)lroundf((float)w / aspect);
    if (!w) w = 1;
    if (!h) h = 1;
    if (ld.is_x3d) fit_x3d_cameras(&ld, w, h); /* X3D fieldOfView is the smaller side's angle */
    sy_context_pool *pool = NULL;
    sy_layer img = {0}, img_right = {0};
    double secs = 0;
    spec.backend = backend;
    spec.params = params;
    spec.root = ld.root;
    spec.camera = ld.camera;
    spec.background = ld.background;
    sy_result r = overlay ? add_overlay(&ld, overlay, composite, &spec, &err) : SY_OK;
    if (r == SY_OK) r = sy_context_pool_create(&pool, &err);
    progress_state ps = {shown, sy_time_now(), 0, sy_is_terminal(2), false};
    sy_window_render_opts ro = {.progress = progress_cb, .progress_user = &ps};
    double t0 = sy_time_now();
    uint64_t samples = 0;
    sy_context *pctx = NULL;
    bool interrupted = false;
    char samples_str[32], secs_str[32];
    if (r == SY_OK && progressive) {
        /* the first Ctrl-C ends the render after the pass in progress and keeps its image */
        sy_signals_set_graceful("finishing the current pass, then writing the image accumulated so far");
        r = render_progressive(&ld, &spec, w, h, &po, pool, &img, &img_right, &secs, &samples, &pctx, &err);
        t0 = sy_time_now() - secs;
        interrupted = sy_signals_interrupted();
    } else if (r == SY_OK && clo.cluster) {
        /* --frames N: N frames through the same window (balanced strips adapt from frame to frame) */
        if (remote_spp) ro.sample_count = po.spp;
        uint32_t frames = clo.frames ? clo.frames : 1;
        for (uint32_t i = 0; i < frames && r == SY_OK; ++i) {
            sy_layer_destroy(&img);
            sy_layer_destroy(&img_right);
            r = sy_compose_render(ld.scene, pool, &spec, w, h, &ro, &img, &img_right, &err);
            if (r == SY_OK) cluster_report(ld.scene, pool, &spec, i, cluster_servers);
        }
    } else if (r == SY_OK) r = sy_compose_render(ld.scene, pool, &spec, w, h, &ro, &img, &img_right, &err);
    secs = sy_time_now() - t0;
    /* the image's metadata (EXR header attributes, PNG text chunks): what made it and how */
    sy_exr_attribute attrs[12];
    sy_png_text texts[12];
    char renderer[64], size_str[48], camera_str[256];
    if (r == SY_OK) {
        if (!progressive) { /* what the main back-end accumulated (a single pass: 1) */
            sy_params mp;
            sy_context *mc = NULL;
            sy_mediator_stats ms = {0};
            sy_error ignore = {0};
            if (sy_params_parse(spec.params, &mp, &ignore) == SY_OK &&
                sy_context_pool_get(pool, ld.scene, spec.backend, &mp, ld.root.id, &mc, &ignore) == SY_OK)
                sy_context_stats(mc, &ms);
            samples = ms.samples;
        }
        snprintf(renderer, sizeof renderer, "Switchyard %s", sy_version());
        snprintf(samples_str, sizeof samples_str, "%llu", (unsigned long long)samples);
        snprintf(secs_str, sizeof secs_str, "%.3f", secs);
        snprintf(size_str, sizeof size_str, "%ux%u%s", w, h,
                 spec.stereo == SY_STEREO_NONE ? "" : spec.stereo == SY_STEREO_SEPARATE ? " per eye" : " per eye, stereo");
        sy_mat4 cm = sy_mat4_identity();
        bool has_cam = ld.camera.id && sy_node_world_matrix(ld.scene, ld.camera, &cm, NULL) == SY_OK;
        if (has_cam)
            snprintf(camera_str, sizeof camera_str, "%s at (%g, %g, %g) looking along (%g, %g, %g)",
                     camera ? camera : "the scene's first camera", (double)cm.m[12], (double)cm.m[13], (double)cm.m[14],
                     (double)-cm.m[8], (double)-cm.m[9], (double)-cm.m[10]);
        else snprintf(camera_str, sizeof camera_str, "a view framing the scene's bounds");
        const char *kv[][2] = {{"sy:renderer", renderer}, {"sy:backend", shown}, {"sy:params", params},
                               {"sy:camera", camera_str}, {"sy:size", size_str}, {"sy:samples", samples_str},
                               {"sy:seconds", secs_str}, {"sy:source", scene},
                               {"sy:interrupted", interrupted ? "1" : NULL}};
        for (size_t k = 0; k < sizeof kv / sizeof kv[0]; ++k) {
            if (!kv[k][1] || !kv[k][1][0]) continue;
            attrs[oo.attr_count] = (sy_exr_attribute){kv[k][0], kv[k][1]};
            texts[oo.attr_count] = (sy_png_text){kv[k][0], kv[k][1]};
            oo.attr_count++;
        }
        oo.attrs = attrs;
        oo.png.text = texts;
        oo.png.text_count = oo.attr_count;
    }
    if (r == SY_OK && clo.cluster && cluster_mode == SY_CLUSTER_MULTI_DISPLAY) {
        printf("multi-display: %ux%u wall presented by the servers, %s, %.3f s\n", w, h, remote, secs);
    } else if (r == SY_OK) {
        size_t bad = sy_layer_count_nonfinite(&img) + (img_right.rgba ? sy_layer_count_nonfinite(&img_right) : 0);
        if (bad) sy_log(SY_LOG_WARNING, "sy", outp, "%zu pixels are not finite", bad);
        if (spec.stereo == SY_STEREO_SEPARATE) {
            char lp[4096], rp[4096];
            r = eye_paths(outp, lp, rp, sizeof lp, &err);
            if (r == SY_OK) r = write_image(lp, &img, &oo, &err);
            if (r == SY_OK) r = write_image(rp, &img_right, &oo, &err);
            if (r == SY_OK) printf("%s, %s: %ux%u per eye, %s, %.3f s\n", lp, rp, w, h, shown, secs);
        } else {
            r = po.aov ? write_aov_exr(outp, pctx, &oo, &err) : write_image(outp, &img, &oo, &err);
            if (r == SY_OK && progressive)
                printf("%s: %ux%u, %s, %llu samples per pixel, %.3f s (%.2f samples/s)%s\n", outp, img.width,
                       img.height, shown, (unsigned long long)samples, secs,
                       secs > 0 ? (double)samples / secs : 0.0, interrupted ? ", interrupted" : "");
            else if (r == SY_OK) printf("%s: %ux%u, %s, %.3f s\n", outp, img.width, img.height, shown, secs);
            if (r == SY_OK && progressive && filter && pctx) { /* the display filter's report (issue 7) */
                sy_filter_info fi;
                sy_context_filter_info(pctx, &fi);
                printf("filter %s: threshold %g, last filter %.1f ms, last pass at %u spp, mean blend %.3f, "
                       "NaN/Inf: %llu pixels, %llu samples\n",
                       fi.name, (double)fi.threshold, fi.seconds * 1e3, fi.last_pass_samples, fi.mean_blend,
                       (unsigned long long)fi.nonfinite_pixels, (unsigned long long)fi.nonfinite_samples);
            }
        }
    }
    sy_layer_destroy(&img);
    sy_layer_destroy(&img_right);
    sy_context_pool_destroy(pool);
    loaded_free(&ld);
    interrupted = interrupted || (progressive && sy_signals_interrupted()); /* also while writing */
    if (r == SY_OK && interrupted) {
        fprintf(stderr, "sy render: interrupted: wrote the image of %llu samples per pixel (sy:samples in the EXR "
                        "header); exit status 130\n", (unsigned long long)samples);
        return 130;
    }
    return r == SY_OK ? 0 : fail(&err);
}

/* sy compare SCENE [-w W] [-h H] [--spp N] [-o SHEET.png] [--camera C] [--backends a,b]:
 * every picture back-end side by side (sy_compare.h). */
static int cmd_compare(int argc, char **argv)
{
    const char *scene = NULL, *camera = NULL, *sheet = "compare.png", *only = NULL;
    uint32_t w = 200, h = 150, spp = 256;
    static const struct option lo[] = {{"spp", required_argument, NULL, OPT_SPP},
                                       {"camera", required_argument, NULL, OPT_CAMERA},
                                       {"backends", required_argument, NULL, OPT_BACKENDS}, COMMON_OPTIONS};
    int c, status = 0;
    optind = 0;
    while ((c = next_option("compare", argc, argv, SHORT_OPTIONS("w:h:o:"), lo, &status)) != -1) {
        switch (c) {
        case OPT_STOP: return status;
        case 'w':
        case 'h':
            if (!size_option(c, optarg, &w, &h)) return bad_value(c == 'w' ? "-w" : "-h", optarg);
            break;
        case OPT_SPP:
            if (!parse_u32(optarg, 1, 1u << 20, &spp)) return bad_value("--spp", optarg);
            break;
        case 'o': sheet = optarg; break;
        case OPT_CAMERA: camera = optarg; break;
        case OPT_BACKENDS: only = optarg; break;
        }
    }
    if (argc - optind != 1) return usage_of("compare", argc == optind ? "a SCENE is required" : "one SCENE at a time");
    scene = argv[optind];
    if (!ends_with(sheet, ".png")) {
        fprintf(stderr, "sy compare: %s: the contact sheet must end in .png\n", sheet);
        return 2;
    }
    sy_error err = {0};
    loaded ld;
    if (load(scene, camera, true, &ld, &err) != SY_OK) return fail(&err);
    if (ld.is_x3d) fit_x3d_cameras(&ld, w, h);
    sy_context_pool *pool = NULL;
    sy_result r = sy_context_pool_create(&pool, &err);
    sy_viewport_desc vd = {.root = ld.root, .camera = ld.camera, .background = ld.background};
    sy_compare_opts co = {.width = w, .height = h, .spp = spp, .sheet_path = sheet, .title = scene, .only = only};
    sy_compare_row rows[16];
    uint32_t n = 0;
    printf("%s, %ux%u\n", scene, w, h);
    if (r == SY_OK) r = sy_compare_run(ld.scene, &vd, &co, pool, stdout, rows, 16, &n, &err);
    if (r == SY_OK) printf("contact sheet: %s\n", sheet);
    sy_context_pool_destroy(pool);
    loaded_free(&ld);
    return r == SY_OK ? 0 : fail(&err);
}

static int cmd_demo(int argc, char **argv)
{
    const char *dir = "out", *filter = "pixel";
    uint32_t w = 800, h = 450;
    static const struct option lo[] = {{"filter", required_argument, NULL, OPT_FILTER}, COMMON_OPTIONS};
    int c, status = 0;
    optind = 0;
    while ((c = next_option("demo", argc, argv, SHORT_OPTIONS("o:w:h:"), lo, &status)) != -1) {
        switch (c) {
        case OPT_STOP: return status;
        case 'o': dir = optarg; break;
        case OPT_FILTER: filter = optarg; break;
        case 'w':
        case 'h':
            if (!size_option(c, optarg, &w, &h)) return bad_value(c == 'w' ? "-w" : "-h", optarg);
            break;
        }
    }
    if (optind < argc) return usage_of("demo", "sy demo takes no operand (-o DIR names the folder)");
    if (mkdir(dir, 0777) != 0 && errno != EEXIST) {
        fprintf(stderr, "sy: error: %s: cannot create directory: %s\n", dir, strerror(errno));
        return 2;
    }
    sy_error err = {0};
    loaded ld;
    if (load("demo", NULL, true, &ld, &err) != SY_OK) return fail(&err);
    sy_context_pool *pool = NULL;
    sy_result r = sy_context_pool_create(&pool, &err);
    printf("demo scene: %u nodes, %u meshes, %u materials, %ux%u\n", sy_scene_count(ld.scene, SY_TYPE_NODE),
           sy_scene_count(ld.scene, SY_TYPE_MESH), sy_scene_count(ld.scene, SY_TYPE_MATERIAL), w, h);
    for (uint32_t i = 0; i < sy_mediator_count() && r == SY_OK; ++i) {
        const char *name = sy_mediator_at(i)->name;
        sy_layer img = {0};
        double secs = 0;
        /* a progressive back-end gets 32 samples per pixel and its display filter (pixel filtering,
         * which also withholds fireflies; --filter none shows the raw samples): a clean image in a
         * few seconds */
        bool progressive = (sy_mediator_at(i)->caps & SY_CAP_PROGRESSIVE) != 0;
        if (sy_mediator_at(i)->caps & SY_CAP_ANALYSIS) continue;
        uint32_t spp = progressive ? 32 : 0;
        char params[64];
        snprintf(params, sizeof params, "filter=%s", filter);
        r = render_scene(&ld, name, progressive ? params : NULL, w, h, spp, pool, &img, &secs, &err);
        char png[1024], exr[1024];
        snprintf(png, sizeof png, "%s/demo_%s.png", dir, name);
        snprintf(exr, sizeof exr, "%s/demo_%s.exr", dir, name);
        out_opts oo = {.png = {.tonemap = SY_TONEMAP_DISPLAY}};
        if (r == SY_OK) r = write_image(png, &img, &oo, &err);
        if (r == SY_OK) r = write_image(exr, &img, &oo, &err);
        if (r == SY_OK && spp)
            printf("  %-12s %8.3f s  %s  %s  (%u samples per pixel, filter %s)\n", name, secs, png, exr, spp, filter);
        else if (r == SY_OK) printf("  %-12s %8.3f s  %s  %s\n", name, secs, png, exr);
        sy_layer_destroy(&img);
    }
    sy_context_pool_destroy(pool);
    loaded_free(&ld);
    return r == SY_OK ? 0 : fail(&err);
}

#ifdef SY_HAVE_GLFW
static int cmd_view(int argc, char **argv)
{
    const char *scene = NULL, *backend = NULL, *camera = NULL, *overlay = NULL, *composite = "depth",
               *shot = NULL;
    const char *view_filter = NULL; /* --filter: initial path tracer display filter */
    float view_threshold = 0.0f;    /* --threshold (0 = default) */
    const char *view_keys = NULL;   /* --keys: scripted key presses (tests) */
    uint32_t w = 960, h = 540, frames = 0;
    sy_cluster_cli_opts clo = {0}; /* --cluster ... (sy_cluster_cli.c; --frames is the viewer's own) */
    static const struct option lo[] = {
        {"camera", required_argument, NULL, OPT_CAMERA}, {"overlay", required_argument, NULL, OPT_OVERLAY},
        {"composite", required_argument, NULL, OPT_COMPOSITE}, {"frames", required_argument, NULL, OPT_FRAMES},
        {"screenshot", required_argument, NULL, OPT_SCREENSHOT}, {"filter", required_argument, NULL, OPT_FILTER},
        {"threshold", required_argument, NULL, OPT_THRESHOLD}, {"keys", required_argument, NULL, OPT_KEYS},
        {"spp", required_argument, NULL, OPT_SPP}, /* cluster: samples per server and frame */
        {"budget", required_argument, NULL, OPT_BUDGET}, /* the frame-time governor's budget (ms) */
        SY_CLUSTER_CLI_OPTIONS, COMMON_OPTIONS};
    double budget = 0.0;
    int c, status = 0;
    optind = 0;
    while ((c = next_option("view", argc, argv, SHORT_OPTIONS("b:w:h:"), lo, &status)) != -1) {
        char *end = NULL;
        switch (c) {
        case OPT_STOP: return status;
        case 'b': backend = optarg; break;
        case 'w':
            if (!parse_u32(optarg, 16, 16384, &w)) return bad_value("-w", optarg);
            break;
        case 'h':
            if (!parse_u32(optarg, 16, 16384, &h)) return bad_value("-h", optarg);
            break;
        case OPT_CAMERA: camera = optarg; break;
        case OPT_OVERLAY: overlay = optarg; break;
        case OPT_COMPOSITE: composite = optarg; break;
        case OPT_FRAMES:
            if (!parse_u32(optarg, 1, 1000000, &frames)) return bad_value("--frames", optarg);
            break;
        case OPT_SCREENSHOT: shot = optarg; break;
        case OPT_FILTER: view_filter = optarg; break;
        case OPT_THRESHOLD: /* the range: sy_view_run says why */
            view_threshold = strtof(optarg, &end);
            if (end == optarg || *end) return bad_value("--threshold", optarg);
            break;
        case OPT_KEYS: view_keys = optarg; break;
        case OPT_BUDGET:
            budget = strtod(optarg, &end);
            if (end == optarg || *end || !(budget >= 1.0 && budget <= 10000.0)) return bad_value("--budget", optarg);
            break;
        case OPT_SPP:
            if (!parse_u32(optarg, 1, 100000000u, &clo.samples)) return bad_value("--spp", optarg);
            break;
        default:
            if (!sy_cluster_cli_getopt(c, optarg, &clo)) return bad_value(option_name(lo, c), optarg);
        }
    }
    if (argc - optind != 1) return usage_of("view", argc == optind ? "a SCENE is required" : "one SCENE at a time");
    scene = argv[optind];
    sy_error err = {0};
    if (!backend && !(backend = default_backend(&err))) return fail(&err);
    if (!sy_mediator_find(backend)) {
        sy_error_set(&err, SY_ERR_NOT_FOUND, "back-end '%s' is not registered (see sy backends)", backend);
        return fail(&err);
    }
    loaded ld;
    if (load(scene, camera, true, &ld, &err) != SY_OK) return fail(&err);
    sy_view_args va = {.scene = ld.scene, .backend = backend, .width = w, .height = h, .frames = frames, .screenshot = shot};
    va.filter = view_filter;
    va.threshold = view_threshold;
    va.keys = view_keys;
    va.budget_ms = budget;
    va.cluster = clo.cluster ? &clo : NULL;
    va.spec.root = ld.root;
    va.spec.camera = ld.camera;
    va.spec.background = ld.background;
    va.spec.eye_separation = 0.065f;
    va.spec.zero_parallax = 2.0f;
    va.spec.backend = backend;
    sy_result r = overlay ? add_overlay(&ld, overlay, composite, &va.spec, &err) : SY_OK;
    if (r == SY_OK) r = sy_view_run(&va, &err);
    loaded_free(&ld);
    return r == SY_OK ? 0 : fail(&err);
}
#endif

#ifdef SY_HAVE_WEB
/* `sy web SCENE`: the view in a web browser (apps/web/sy_web.h, docs/WEB.md). */
enum { OPT_WEB_LISTEN = 0x300, OPT_WEB_QUALITY, OPT_WEB_CLIENT_RENDER };
static int cmd_web(int argc, char **argv)
{
    const char *backend = NULL, *camera = NULL, *listen = NULL, *filter = NULL;
    uint32_t w = 1920, h = 1200, quality = 80;
    float threshold = 0.0f;
    double budget = 0; /* 0: the governor's default (33 ms) */
    bool client_render = false;
    static const struct option lo[] = {
        {"camera", required_argument, NULL, OPT_CAMERA}, {"listen", required_argument, NULL, OPT_WEB_LISTEN},
        {"quality", required_argument, NULL, OPT_WEB_QUALITY}, {"filter", required_argument, NULL, OPT_FILTER},
        {"threshold", required_argument, NULL, OPT_THRESHOLD}, {"budget", required_argument, NULL, OPT_BUDGET},
        {"client-render", no_argument, NULL, OPT_WEB_CLIENT_RENDER}, COMMON_OPTIONS};
    int c, status = 0;
    optind = 0;
    while ((c = next_option("web", argc, argv, SHORT_OPTIONS("b:w:h:"), lo, &status)) != -1) {
        char *end = NULL;
        switch (c) {
        case OPT_STOP: return status;
        case 'b': backend = optarg; break;
        case 'w':
        case 'h':
            if (!size_option(c, optarg, &w, &h)) return bad_value(c == 'w' ? "-w" : "-h", optarg);
            break;
        case OPT_CAMERA: camera = optarg; break;
        case OPT_WEB_LISTEN: listen = optarg; break;
        case OPT_WEB_QUALITY:
            if (!parse_u32(optarg, 1, 100, &quality)) return bad_value("--quality", optarg);
            break;
        case OPT_FILTER: filter = optarg; break;
        case OPT_THRESHOLD:
            threshold = strtof(optarg, &end);
            if (end == optarg || *end || !(threshold >= 0.0f) || !isfinite(threshold)) return bad_value("--threshold", optarg);
            break;
        case OPT_BUDGET: /* the frame-time governor's budget (ms) */
            budget = strtod(optarg, &end);
            if (end == optarg || *end || !(budget >= 1.0 && budget <= 10000.0)) return bad_value("--budget", optarg);
            break;
        case OPT_WEB_CLIENT_RENDER: client_render = true; break;
        }
    }
    if (argc - optind != 1) return usage_of("web", argc == optind ? "a SCENE is required" : "one SCENE at a time");
    sy_error err = {0};
    if (!backend && !(backend = default_backend(&err))) return fail(&err);
    loaded ld;
    if (load(argv[optind], camera, true, &ld, &err) != SY_OK) return fail(&err);
    sy_web_desc d = {.scene = ld.scene, .root = ld.root, .camera = ld.camera, .background = ld.background,
                     .backend = backend, .listen = listen, .max_width = w, .max_height = h, .quality = (int)quality,
                     .filter = filter, .threshold = threshold, .budget_ms = budget};
    sy_web *web = NULL;
    sy_result r = SY_OK;
#ifdef SY_WEB_HAVE_CULL
    /* remote culling: /api/cull, /api/object/ID, /api/view; --client-render: the three.js page */
    sy_web_cull *cull = NULL;
    sy_web_route routes[SY_WEB_CULL_MAX_ROUTES];
    r = sy_web_cull_create(ld.scene, ld.root, client_render ? sy_web_cull_client_dir_default() : NULL, &cull, routes,
                           &d.route_count, &err);
    d.routes = routes;
#else
    if (client_render)
        r = sy_error_set(&err, SY_ERR_UNSUPPORTED, "sy web --client-render: this sy was built without the culling "
                         "service (it needs the Embree back-ends)");
#endif
    if (r == SY_OK) r = sy_web_create(&d, &web, &err);
#ifdef SY_WEB_HAVE_CULL
    if (r == SY_OK) sy_web_cull_attach(cull, web);
#endif
    if (r == SY_OK) {
        const char *url = sy_web_url(web), *q = strchr(url, '?');
        int host_len = q ? (int)(q - url) : (int)strlen(url);
        printf("sy web: serving %s with %s; open %.*s%s%s%s\n", argv[optind], backend, host_len, url,
               client_render ? "client/client.html" : "", q ? q : "",
               strstr(url, "//0.0.0.0:") || strstr(url, "//[::]:") ? " (with this machine's name or address for the host)" : "");
        fflush(stdout);
        sy_signals_set_graceful("closing the server");
        r = sy_web_run(web, sy_signals_stop_flag(), &err);
        sy_signals_set_graceful(NULL);
    }
    sy_web_destroy(web);
#ifdef SY_WEB_HAVE_CULL
    sy_web_cull_destroy(cull);
#endif
    loaded_free(&ld);
    return r == SY_OK ? 0 : fail(&err);
}
#endif

/* `sy coverage SCENE`: which objects the camera sees and how many pixels each covers (occlusion
 * included), most first, as JSON: a culling service for clients that load only what is visible. */
static int cmd_coverage(int argc, char **argv)
{
    const char *scene = NULL, *camera = NULL;
    uint32_t w = 512, h = 512, top = 0;
    static const struct option lo[] = {{"camera", required_argument, NULL, OPT_CAMERA},
                                       {"top", required_argument, NULL, OPT_TOP},
                                       {"json", no_argument, NULL, OPT_JSON}, COMMON_OPTIONS};
    int c, status = 0;
    optind = 0;
    while ((c = next_option("coverage", argc, argv, SHORT_OPTIONS("w:h:"), lo, &status)) != -1) {
        switch (c) {
        case OPT_STOP: return status;
        case 'w':
        case 'h':
            if (!size_option(c, optarg, &w, &h)) return bad_value(c == 'w' ? "-w" : "-h", optarg);
            break;
        case OPT_CAMERA: camera = optarg; break;
        case OPT_TOP:
            if (!parse_u32(optarg, 1, 1u << 30, &top)) return bad_value("--top", optarg);
            break;
        case OPT_JSON: break; /* the output is JSON anyway */
        }
    }
    if (argc - optind != 1) return usage_of("coverage", argc == optind ? "a SCENE is required" : "one SCENE at a time");
    scene = argv[optind];
    sy_error err = {0};
#ifndef SY_HAVE_EMBREE /* the coverage back-end is one of the Embree ones */
    (void)scene, (void)camera, (void)w, (void)h, (void)top;
    sy_error_set(&err, SY_ERR_UNSUPPORTED, "sy coverage: this sy was built without the Embree back-ends (SY_WITH_EMBREE=OFF)");
    return fail(&err);
#else
    loaded ld;
    if (load(scene, camera, true, &ld, &err) != SY_OK) return fail(&err);
    if (ld.is_x3d) fit_x3d_cameras(&ld, w, h);
    sy_window *win = NULL;
    sy_viewport *vp = NULL;
    sy_context *ctx = NULL;
    sy_camera_view view;
    sy_coverage_entry *e = NULL;
    uint32_t n = 0;
    /* the first registered class that counts per-node coverage (the Embree back-ends' "coverage") */
    const sy_mediator_class *cls = sy_mediator_with_caps(SY_CAP_COVERAGE);
    sy_viewport_desc vd = {.root = ld.root, .camera = ld.camera, .backend = cls ? cls->name : ""};
    sy_result r = cls ? SY_OK : sy_error_set(&err, SY_ERR_UNSUPPORTED, "sy coverage: no registered back-end counts per-node coverage");
    if (r == SY_OK) r = sy_window_create(w, h, &win, &err);
    if (r == SY_OK) r = sy_window_add_viewport(win, &vd, &vp, &err);
    if (r == SY_OK) r = sy_viewport_camera_view(vp, ld.scene, w, h, &view, &err);
    if (r == SY_OK) r = sy_context_create(ld.scene, cls->name, NULL, ld.root.id, &ctx, &err);
    if (r == SY_OK) r = sy_context_sync(ctx, &err);
    if (r == SY_OK) r = sy_context_coverage(ctx, &view, w, h, &e, &n, &err);
    cJSON *doc = NULL;
    if (r == SY_OK) {
        uint64_t covered = 0;
        for (uint32_t i = 0; i < n; ++i) covered += e[i].pixels;
        doc = cJSON_CreateObject();
        jadd(doc, "file", jstr(scene));
        jadd(doc, "width", cJSON_CreateNumber(w));
        jadd(doc, "height", cJSON_CreateNumber(h));
        jadd(doc, "covered_pixels", cJSON_CreateNumber((double)covered));
        cJSON *objs = jadd(doc, "objects", cJSON_CreateArray());
        uint32_t shown = top && top < n ? top : n;
        for (uint32_t i = 0; i < shown; ++i) {
            const sy_node_data *nd = sy_object_get(ld.scene, SY_TYPE_NODE, e[i].node_id);
            cJSON *o = jadd(objs, NULL, cJSON_CreateObject());
            jadd(o, "node", cJSON_CreateNumber(e[i].node_id));
            jadd(o, "name", jstr(nd ? nd->name : NULL));
            jadd(o, "pixels", cJSON_CreateNumber(e[i].pixels));
            jadd(o, "fraction", cJSON_CreateNumber(round((double)e[i].pixels / ((double)w * h) * 1e6) / 1e6));
        }
    }
    free(e);
    sy_context_release(ctx);
    sy_window_destroy(win);
    loaded_free(&ld);
    return r == SY_OK ? print_json(doc) : fail(&err);
#endif
}

/* --params --json: a class's declared parameters (sy_params.h) */
static void jparams(cJSON *o, const sy_mediator_class *m)
{
    cJSON *a = jadd(o, "params", cJSON_CreateArray());
    for (uint32_t i = 0; a && i < m->param_table.count; ++i) {
        const sy_param_decl *d = &m->param_table.decls[i];
        cJSON *p = jadd(a, NULL, cJSON_CreateObject());
        if (!p) return;
        jadd(p, "name", jstr(d->name));
        jadd(p, "type", jstr(sy_param_type_name(d->type)));
        if (d->min != 0.0 || d->max != 0.0) jadd(p, "min", cJSON_CreateNumber(d->min)), jadd(p, "max", cJSON_CreateNumber(d->max));
        if (d->enum_values) jadd(p, "values", jstr(d->enum_values));
        jadd(p, "default", d->default_value ? jstr(d->default_value) : cJSON_CreateNull());
        jadd(p, "help", jstr(d->help));
    }
}

/* sy backends [--params] [--json]: one line per registered back-end, its name and capability words;
 * --params: then its parameter table (sy_mediator_class_format_params) (--json: an array of
 * {"name", "caps"[, "params"]}). */
static int cmd_backends(int argc, char **argv)
{
    bool json = false, params = false;
    static const struct option lo[] = {{"json", no_argument, NULL, OPT_JSON}, {"params", no_argument, NULL, OPT_PARAMS},
                                       COMMON_OPTIONS};
    int c, status = 0;
    optind = 0;
    while ((c = next_option("backends", argc, argv, SHORT_OPTIONS(""), lo, &status)) != -1) {
        if (c == OPT_STOP) return status;
        if (c == OPT_JSON) json = true;
        if (c == OPT_PARAMS) params = true;
    }
    if (optind < argc) return usage_of("backends", "sy backends takes no operand");
    static const struct { uint32_t bit; const char *word; } caps[] = {
        {SY_CAP_DEPTH, "depth"}, {SY_CAP_PROGRESSIVE, "progressive"}, {SY_CAP_TILES, "tiles"},
        {SY_CAP_SAMPLE_RANGES, "sample-ranges"}, {SY_CAP_AOVS, "aovs"}, {SY_CAP_FILTERS, "filters"},
        {SY_CAP_ANALYSIS, "analysis"}, {SY_CAP_REMOTE, "remote"}, {SY_CAP_PREVIEW, "preview"},
        {SY_CAP_COVERAGE, "coverage"}};
    cJSON *doc = json ? cJSON_CreateArray() : NULL;
    for (uint32_t i = 0; i < sy_mediator_count(); ++i) {
        const sy_mediator_class *m = sy_mediator_at(i);
        cJSON *o = json ? jadd(doc, NULL, cJSON_CreateObject()) : NULL, *cj = NULL;
        if (json) {
            jadd(o, "name", jstr(m->name));
            cj = jadd(o, "caps", cJSON_CreateArray());
        } else {
            printf("%s", m->name);
        }
        for (size_t k = 0; k < sizeof caps / sizeof caps[0]; ++k) {
            if (!(m->caps & caps[k].bit)) continue;
            if (json) jadd(cj, NULL, jstr(caps[k].word));
            else printf(" %s", caps[k].word);
        }
        bool is_default = m == sy_mediator_default(); /* what sy render, view and web use without -b */
        if (json) jadd(o, "default", cJSON_CreateBool(is_default));
        else printf(is_default ? "  (default)\n" : "\n");
        size_t n = params && !json ? sy_mediator_class_format_params(m, "  ", NULL, 0) : 0;
        char *t = n ? malloc(n + 1) : NULL; /* --params: the class's table, from the library */
        if (t) sy_mediator_class_format_params(m, "  ", t, n + 1), fputs(t, stdout), free(t);
        if (params && json) jparams(o, m);
    }
    return json ? print_json(doc) : 0;
}

/* sy bench raster [SCENE] [-w W -h H] [--repeats R] [--params k=v]: default 1280x720 on OSMesa. */
static int cmd_bench_raster(const char *scene, uint32_t w, uint32_t h, uint32_t repeats, const char *params)
{
    sy_error err = {0};
    loaded ld;
    if (load(scene ? scene : "demo", NULL, true, &ld, &err) != SY_OK) return fail(&err);
    sy_viewport_desc vd = {.root = ld.root, .camera = ld.camera, .background = ld.background, .backend = "raster",
                           .params = params};
    sy_result r = sy_bench_raster(ld.scene, &vd, scene ? scene : "demo", w == 512 ? 1280 : w, h == 512 ? 720 : h,
                                  repeats ? repeats : 10, &err);
    loaded_free(&ld);
    return r == SY_OK ? 0 : fail(&err);
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
        if (load(list[i], NULL, true, &ld, &err) != SY_OK) return fail(&err);
        /* the helmet under a uniform grey environment light (a 1x1 lat-long map) */
        sy_world_options wo = {.has_env_color = i == 1, .env_color = {0.8f, 0.8f, 0.8f}};
        sy_result r = sy_world_apply(ld.scene, &ld.background, &wo, &err);
        if (r == SY_OK) r = sy_scene_commit(ld.scene, NULL, &err);
        sy_viewport_desc vd = {.root = ld.root, .camera = ld.camera, .background = ld.background};
        if (r == SY_OK) r = sy_bench_pathtracer(ld.scene, &vd, list[i], w, h, passes ? passes : 8, &err);
        loaded_free(&ld);
        if (r != SY_OK) return fail(&err);
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
    static const struct option lo[] = {{"repeats", required_argument, NULL, OPT_REPEATS},
                                       {"reference", required_argument, NULL, OPT_REFERENCE}, COMMON_OPTIONS};
    int c, status = 0;
    optind = 0;
    while ((c = next_option("bench filters", argc, argv, SHORT_OPTIONS("w:h:"), lo, &status)) != -1) {
        switch (c) {
        case OPT_STOP: return status;
        case 'w':
            if (!parse_u32(optarg, 8, 16384, &w)) return bad_value("-w", optarg);
            break;
        case 'h':
            if (!parse_u32(optarg, 8, 16384, &h)) return bad_value("-h", optarg);
            break;
        case OPT_REPEATS:
            if (!parse_u32(optarg, 1, 1000, &repeats)) return bad_value("--repeats", optarg);
            break;
        case OPT_REFERENCE: reference = optarg; break;
        }
    }
    for (; optind < argc; ++optind) { /* [SCENE] [SHEET.png] */
        const char *a = argv[optind];
        if (ends_with(a, ".png") && !sheet) sheet = a;
        else if (!scene) scene = a;
        else return usage_of("bench filters", "at most one SCENE and one SHEET.png");
    }
    sy_error err = {0};
    if (!scene) return sy_bench_filters(w ? w : 640, h ? h : 480, repeats, sheet, &err) == SY_OK ? 0 : fail(&err);
    if (!reference) {
        fprintf(stderr, "sy bench filters %s: --reference REF.exr (the converged image) is required\n", scene);
        return 2;
    }
    loaded ld;
    if (load(scene, NULL, true, &ld, &err) != SY_OK) return fail(&err);
    sy_viewport_desc vd = {.root = ld.root, .camera = ld.camera, .backend = "pathtracer"};
    sy_result r = sy_bench_filters_scene(ld.scene, &vd, scene, w ? w : 256, h ? h : 256, reference, sheet, &err);
    loaded_free(&ld);
    return r == SY_OK ? 0 : fail(&err);
}

/* sy bench KIND ...: argv[0] is "bench", argv[1] the kind. */
static int cmd_bench(int argc, char **argv)
{
    static const char *const kinds[] = {"sync",      "rays", "pathtracer", "filters", "raster",
                                        "viewports", "load", "cluster",    "memory", "instances", "governor",
                                        "limit",     "cull", "web"};
    bool known = false;
    for (size_t k = 0; argc >= 2 && k < sizeof kinds / sizeof kinds[0]; ++k) known = known || !strcmp(argv[1], kinds[k]);
    if (argc >= 2 && !strcmp(argv[1], "--help")) {
        usage_to(stdout, "bench");
        return 0;
    }
    if (!known) {
        if (argc >= 2) fprintf(stderr, "sy bench: error: unknown benchmark '%s'\n", argv[1]);
        return usage_of("bench", argc < 2 ? "which benchmark?" : NULL);
    }
    const char *cmd = argv[1]; /* the benchmark */
    argc -= 1, argv += 1; /* argv[0]: the kind */
    if (!strcmp(cmd, "filters")) return cmd_bench_filters(argc, argv);
    if (!strcmp(cmd, "cluster")) return sy_cmd_bench_cluster(argc, argv);
    if (!strcmp(cmd, "governor")) return sy_cmd_bench_governor(argc, argv); /* sy_bench_governor.c */
    if (!strcmp(cmd, "limit")) return sy_cmd_bench_limit(argc, argv); /* apps/sy/sy_bench_limit.c */
    if (!strcmp(cmd, "cull")) return SY_BENCH_CULL(argc, argv); /* apps/sy/sy_bench_cull.c */
    uint32_t nodes = 10000, tris = 100, repeats = 0, w = 512, h = 512;
    const char *scene = NULL, *params = NULL, *backend = NULL;
    bool memory = !strcmp(cmd, "memory"), instanced = !strcmp(cmd, "instances"), web = !strcmp(cmd, "web");
    static const struct option lo[] = {{"params", required_argument, NULL, OPT_PARAMS},
                                       {"nodes", required_argument, NULL, OPT_NODES},
                                       {"tris", required_argument, NULL, OPT_TRIS},
                                       {"glb", no_argument, NULL, OPT_GLB},
                                       {"repeats", required_argument, NULL, OPT_REPEATS}, COMMON_OPTIONS};
    char who[32];
    snprintf(who, sizeof who, "bench %s", cmd);
    bool glb = false;
    int c, status = 0;
    optind = 0;
    while ((c = next_option(who, argc, argv, memory || instanced || web ? SHORT_OPTIONS("w:h:b:") : SHORT_OPTIONS("w:h:"), lo,
                            &status)) != -1) {
        switch (c) {
        case OPT_STOP: return status;
        case OPT_PARAMS: params = optarg; break; /* bench raster */
        case 'b': backend = optarg; break; /* bench memory, bench instances, bench web */
        case OPT_GLB:
            if (!memory) return usage_of(who, "--glb is an option of sy bench memory");
            glb = true;
            break;
        case OPT_NODES: /* bench sync: nodes; bench instances: instances */
            if (!parse_u32(optarg, 1, 1u << 22, &nodes)) return bad_value("--nodes", optarg);
            break;
        case OPT_TRIS:
            if (!parse_u32(optarg, 12, memory || instanced ? 1u << 30 : 1u << 20, &tris)) return bad_value("--tris", optarg);
            break;
        case OPT_REPEATS:
            if (!parse_u32(optarg, 1, 100000, &repeats)) return bad_value("--repeats", optarg);
            break;
        case 'w':
        case 'h':
            if (!size_option(c, optarg, &w, &h)) return bad_value(c == 'w' ? "-w" : "-h", optarg);
            break;
        }
    }
    if (argc - optind > 1) return usage_of(who, "at most one SCENE");
    if (optind < argc) scene = argv[optind];
    sy_error err = {0};
    if (!strcmp(cmd, "sync")) return sy_bench_sync(nodes, tris, repeats ? repeats : 50, &err) == SY_OK ? 0 : fail(&err);
    if (!strcmp(cmd, "viewports"))
        return sy_bench_viewports(w == 512 ? 480 : w, h == 512 ? 270 : h, repeats ? repeats : 5, &err) == SY_OK
                   ? 0
                   : fail(&err);
    if (!strcmp(cmd, "raster")) return cmd_bench_raster(scene, w, h, repeats, params);
    if (!strcmp(cmd, "pathtracer")) return cmd_bench_pathtracer(scene, w, h, repeats);
    if (memory) {
        if (optind < argc) return usage_of(who, "no SCENE: the height field is generated");
        return sy_bench_memory(tris == 100 ? 1000000 : tris, backend, glb, w == 512 ? 256 : w, h == 512 ? 256 : h, &err) == SY_OK
                   ? 0
                   : fail(&err);
    }
    if (instanced) {
        if (optind < argc) return usage_of(who, "no SCENE: the instanced height field is generated");
#ifdef SY_HAVE_EMBREE
        return sy_bench_instances(nodes == 10000 ? 1000 : nodes, tris == 100 ? 1000000 : tris, w == 512 ? 320 : w,
                                  h == 512 ? 240 : h, repeats ? repeats : 10, backend, &err) == SY_OK ? 0 : fail(&err);
#else
        sy_error_set(&err, SY_ERR_UNSUPPORTED, "sy bench instances: this sy was built without the Embree back-ends");
        return fail(&err);
#endif
    }
    if (!strcmp(cmd, "load")) /* SCENE = the glTF sample directory; --tris: generated model (default 1M) */
        return sy_bench_load(scene ? scene : "../shared/testdata/gltf", tris == 100 ? 1000000 : tris,
                             repeats ? repeats : 3, &err) == SY_OK ? 0 : fail(&err);
#ifdef SY_HAVE_WEB
    if (web) { /* input-to-frame latency of sy web on loopback (apps/sy/sy_bench_web.c) */
        loaded ld;
        if (load(scene ? scene : "demo", NULL, true, &ld, &err) != SY_OK) return fail(&err);
        sy_web_desc d = {.scene = ld.scene, .root = ld.root, .camera = ld.camera, .background = ld.background,
                         .backend = backend}; /* NULL: the default back-end */
        sy_result r = sy_bench_web(&d, w == 512 ? 640 : w, h == 512 ? 360 : h, repeats ? repeats : 50, &err);
        loaded_free(&ld);
        return r == SY_OK ? 0 : fail(&err);
    }
#endif
    if (!strcmp(cmd, "rays")) {
        loaded ld;
        if (load(scene ? scene : "demo", NULL, true, &ld, &err) != SY_OK) return fail(&err);
        sy_viewport_desc vd = {.root = ld.root, .camera = ld.camera, .backend = "whitted"};
        sy_result r = sy_bench_rays(ld.scene, &vd, w, h, repeats ? repeats : 5, &err);
        loaded_free(&ld);
        return r == SY_OK ? 0 : fail(&err);
    }
    return usage_of("bench", NULL);
}

int main(int argc, char **argv)
{
    sy_error err = {0};
    /* before any thread: interrupts are taken on a thread of their own, output files in progress
     * are removed when one ends the process */
    sy_signals_start();
    sy_testpoint_start(); /* SY_TEST_PHASES / SY_TEST_PAUSE: tests wait for phases (sy_testpoint.h) */
    if (sy_mediators_register_builtin(&err) != SY_OK) return fail(&err);
    /* sy's own options before the command (stops at the first operand, the command): --version,
     * --help / -h, -q / -v and the options of every command (world and loader flags) */
    static const struct option lo[] = {{"version", no_argument, NULL, OPT_VERSION}, COMMON_OPTIONS};
    int c, status = 0;
    optind = 0;
    while ((c = next_option(NULL, argc, argv, "+" SHORT_OPTIONS("h"), lo, &status)) != -1) {
        if (c == OPT_STOP) return status;
        if (c == OPT_VERSION) {
            printf("sy (Switchyard) %s\n", sy_version());
            return 0;
        }
        if (c == 'h') {
            usage_to(stdout, NULL);
            return 0;
        }
    }
    if (optind >= argc) {
        fprintf(stderr, "sy: error: no command given\n");
        usage_to(stderr, NULL);
        return 2;
    }
    argc -= optind, argv += optind; /* argv[0]: the command; each command parses the rest itself */
    const char *cmd = argv[0];
    if (!strcmp(cmd, "version")) {
        printf("sy (Switchyard) %s\n", sy_version());
        return 0;
    }
    static const char *const commands[] = {"info", "render", "demo", "compare", "bench", "backends", "coverage",
                                           "serve", "view", "web", "version", "help"};
    if (!strcmp(cmd, "help")) { /* sy help [COMMAND] */
        bool known = argc < 2;
        for (size_t k = 0; !known && k < sizeof commands / sizeof commands[0]; ++k) known = !strcmp(argv[1], commands[k]);
        if (!known) {
            fprintf(stderr, "sy help: error: unknown command '%s' (sy --help lists them)\n", argv[1]);
            return 2;
        }
        usage_to(stdout, argc < 2 || !strcmp(argv[1], "help") || !strcmp(argv[1], "version") ? NULL : argv[1]);
        return 0;
    }
    if (!strcmp(cmd, "info")) return cmd_info(argc, argv);
    if (!strcmp(cmd, "render")) {
        int rc = cmd_render(argc, argv);
        sy_cluster_cli_mpi_end(); /* --cluster mpi on rank 0: release the server ranks */
        return rc;
    }
    if (!strcmp(cmd, "demo")) return cmd_demo(argc, argv);
    if (!strcmp(cmd, "compare")) return cmd_compare(argc, argv);
    if (!strcmp(cmd, "bench")) return cmd_bench(argc, argv);
    if (!strcmp(cmd, "backends")) return cmd_backends(argc, argv);
    if (!strcmp(cmd, "coverage")) return cmd_coverage(argc, argv);
    if (!strcmp(cmd, "serve")) return sy_cmd_serve(argc, argv);
#ifdef SY_HAVE_GLFW
    if (!strcmp(cmd, "view")) return cmd_view(argc, argv);
#endif
#ifdef SY_HAVE_WEB
    if (!strcmp(cmd, "web")) return cmd_web(argc, argv);
#endif
    fprintf(stderr, "sy: error: unknown command '%s' (sy --help lists them)\n", cmd);
    return 2;
}
