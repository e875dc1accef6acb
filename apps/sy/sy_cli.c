/* sy_cli.c — what every sy command shares on its command line (sy_cli.h): the declared options
 * read by sy_cli_parse, the options of every command (-q / -v, --help, the world and loader flags)
 * taken on the way, the usage text and its errors (exit status 2), the number parsers, the error
 * exit (status 1), the default back-end. */
#include "sy_cli.h"
#include "sy_cluster_cli.h"
#include "sy_load.h"
#include "sy_options.h"

#include "sy_log.h"
#include "sy_mediators.h"
#include "sy_viewport.h"

#include <ctype.h>
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

/* getopt_long entries of the camera placement and node visibility options (sy render, pick, view,
 * web), taken by next_option into sy_cli_load_opts.view and .nodes (sy_load.h) */
#define VIEW_OPTIONS                                                                                       \
    {"look-at", required_argument, NULL, OPT_LOOK_AT}, {"fov", required_argument, NULL, OPT_FOV},        \
    {"orbit", required_argument, NULL, OPT_ORBIT}, {"hide", required_argument, NULL, OPT_HIDE},          \
    {"isolate", required_argument, NULL, OPT_ISOLATE}, {"select", required_argument, NULL, OPT_SELECT},       \
    {"bookmark", required_argument, NULL, OPT_BOOKMARK}
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
    {"variant", required_argument, NULL, OPT_VARIANT},                                                     \
    {NULL, 0, NULL, 0}

bool sy_cli_parse_floats(const char *text, size_t len, int min_n, int max_n, float *out, int *n_out)
{
    const char *p = text, *stop = text + len;
    int n = 0;
    for (;;) {
        char *end = NULL;
        if (n == max_n || p >= stop || *p == ',' || isspace((unsigned char)*p)) return false;
        out[n] = strtof(p, &end);
        if (end == p || end > stop || !isfinite(out[n])) return false;
        ++n, p = end;
        if (p == stop) break;
        if (*p++ != ',') return false;
    }
    *n_out = n;
    return n >= min_n;
}

/* The world flags (only maps text onto sy_world_options; the meaning is the library's: sy_look.h,
 * sy_world.h). */
static sy_result apply_world_option(int c, const char *v, sy_world_options *w, sy_error *err)
{
    int n = 0;
    size_t len = v ? strlen(v) : 0;
    switch (c) {
    case OPT_ENV_HIDDEN: w->env_hidden = true; break;
    case OPT_NO_DEFAULT_LIGHT: w->no_default_light = true; break;
    case OPT_ENV: w->env_path = v; break;
    case OPT_ENV_COLOR:
        if (!sy_cli_parse_floats(v, len, 3, 3, w->env_color, &n))
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "--env-color %s: expected R,G,B", v);
        w->has_env_color = true;
        break;
    case OPT_ENV_INTENSITY:
        if (!sy_cli_parse_floats(v, len, 1, 1, &w->env_intensity, &n))
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "--env-intensity %s: expected a number", v);
        w->env_intensity_set = true;
        break;
    default: /* OPT_BACKGROUND */
        if (!sy_cli_parse_floats(v, len, 3, 4, w->background, &n))
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "--background %s: expected R,G,B or R,G,B,A", v);
        if (n == 3) w->background[3] = 1.0f;
        w->has_background = true;
    }
    return SY_OK;
}

/* The next option of a command's arguments (argv[0]: the command's name, for messages; cmd: the
 * command as `sy help` names it, NULL for sy's own options), the options of every command applied on
 * the way. Call with optind = 0 first (glibc's way to start over with new arguments and a new
 * ordering). Returns the option's code, -1 after the last option (the operands are
 * argv[optind..argc-1]), or OPT_STOP with *status: 0 after --help (the command's usage on stdout), 2
 * after a usage error (named on stderr). */
static int next_option(const char *cmd, int argc, char **argv, const char *shortopts, const struct option *longopts,
                       int *status)
{
    opterr = 0; /* the messages are ours */
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
            if (optopt >= 0x100) fprintf(stderr, "%s: error: option '%s' takes no value", prefix, bad);
            else if (optopt) fprintf(stderr, "%s: error: unknown option '-%c'", prefix, optopt);
            else fprintf(stderr, "%s: error: unknown option '%s'", prefix, bad);
            fprintf(stderr, " (sy %s%s--help lists the options)\n", cmd ? cmd : "", cmd ? " " : "");
            *status = 2;
            return OPT_STOP;
        case ':':
            fprintf(stderr, "%s: error: option '%s' needs a value\n", prefix, bad);
            *status = 2;
            return OPT_STOP;
        case OPT_HELP:
            sy_cli_usage_to(stdout, cmd);
            *status = 0;
            return OPT_STOP;
        case 'q': sy_log_set_level(SY_LOG_ERROR); break;
        case 'v': sy_log_set_level(SY_LOG_DEBUG); break;
        case OPT_STRICT: sy_cli_load_opts.strict = true; break;
        case OPT_MAX_SCENE_MB: { /* the loaders' budget per file, in MiB (sy_budget.h) */
            uint64_t mb = 0;
            if (!sy_cli_parse_uint(optarg, 1, 1ull << 30, &mb)) {
                fprintf(stderr, "sy: error: --max-scene-mb %s: expected a whole number of MiB from 1 to 2^30\n", optarg);
                *status = 2;
                return OPT_STOP;
            }
            sy_cli_load_opts.max_scene_bytes = sy_cli_load_opts.world.max_scene_bytes = mb << 20;
            break;
        }
        case OPT_VARIANT: sy_cli_load_opts.variant = optarg; break; /* glTF KHR_materials_variants */
        case OPT_LOOK_AT: case OPT_FOV: case OPT_ORBIT: case OPT_BOOKMARK: /* the camera's placement (sy_load.h) */
            if ((*status = sy_cli_view_option(c, optarg)) != 0) return OPT_STOP;
            break;
        case OPT_HIDE: case OPT_ISOLATE: case OPT_SELECT: /* node visibility and selection (sy_load.h) */
            if ((*status = sy_cli_node_option(c, optarg)) != 0) return OPT_STOP;
            break;
        case OPT_ALLOW_PATH: { /* repeatable: more folders that a model's external files may lie in */
            struct stat st;
            if (stat(optarg, &st) != 0 || !S_ISDIR(st.st_mode)) {
                fprintf(stderr, "sy: error: --allow-path %s: expected an existing folder\n", optarg);
                *status = 2;
                return OPT_STOP;
            }
            if (sy_cli_load_opts.root_count == SY_MAX_ALLOW_PATHS) {
                fprintf(stderr, "sy: error: --allow-path: at most %d folders\n", SY_MAX_ALLOW_PATHS);
                *status = 2;
                return OPT_STOP;
            }
            sy_cli_load_opts.roots[sy_cli_load_opts.root_count++] = optarg;
            break;
        }
        case OPT_ENV: case OPT_ENV_COLOR: case OPT_ENV_INTENSITY: case OPT_ENV_HIDDEN: case OPT_BACKGROUND:
        case OPT_NO_DEFAULT_LIGHT:
            if (apply_world_option(c, optarg, &sy_cli_load_opts.world, &e) != SY_OK) {
                fprintf(stderr, "sy: error: %s\n", e.message);
                *status = 2;
                return OPT_STOP;
            }
            break;
        default: return c;
        }
    }
}

int sy_cli_fail(const sy_error *e)
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
            "                                       metadata (EXR channels and header attributes, PNG text chunks);\n"
            "                                       a scene's cameras (what --camera takes) and animation clips\n"
            "  sy render SCENE|DIR [-b BACKEND] [-o OUT.exr|png|jpg] [-w W] [-h H] [--camera NAME|INDEX]\n"
            "            (-b: the default back-end, sy backends marks it; -o: STEM.png in the current folder;\n"
            "             DIR: the one scene file in the folder, or one folder down)\n"
            "            [--look-at EYE:TARGET[:UP] | --orbit AZ,EL[,DIST]] [--fov DEG]   (place the camera: EYE, TARGET,\n"
            "             UP each x,y,z, UP default 0,1,0; --orbit: AZ degrees about +y from +z, EL degrees above the\n"
            "             horizon (-90..90), around the bounds' centre, DIST default: the bounds fill the view; --fov:\n"
            "             the vertical field of view in degrees (0..180) of whichever camera is used)\n"
            "            [--bookmark FILE:N]   (the view sy view saved in slot N of FILE with Ctrl+N; instead of --look-at)\n"
            "            [--hide NODE] [--isolate NODE] [--select NODE]   (repeatable; NODE: a node name, the node id sy\n"
            "             pick prints, or an index in creation order; --isolate hides every other mesh node; --select\n"
            "             highlights it: pixels tinted orange and outlined, in every back-end)\n"
            "            [--params k=v,...] [--half] [--exposure EV] [--tonemap clamp|reinhard|aces]  (PNG, JPEG; default aces)\n"
            "            [--seed N]   (the ray tracers' sampling seed, default 0: another N, independent noise)\n"
            "            [--max-memory MB]   (ray tracers: refuse a scene whose BVHs need more)\n"
            "            [--gl osmesa|egl|glfw]   (-b raster: the GL context provider)\n"
            "            [--stereo sbs|tb|anaglyph|separate] [--eye-sep M] [--zero-parallax M]\n"
            "            [--overlay FILE[:BACKEND]] [--composite depth|over|replace]\n"
            "            [--at SECONDS] [--clip NAME|INDEX]   (the scene at a time: every clip, or one; sy info lists clips)\n"
            "            [--shutter OPEN,CLOSE|S | --motion-blur] [--shutter-samples N] [--sub-frames]   (motion blur: the\n"
            "             mean of the scene over seconds OPEN..CLOSE after the frame's time, 0 <= OPEN <= CLOSE;\n"
            "             --motion-blur: 0,0.5/FPS; whitted/pathtracer: one render, each pixel sample at its own time\n"
            "             (whitted: at least N samples per pixel, default 16); others or --sub-frames: N time samples,\n"
            "             each a render accumulated (path tracer: the samples split))\n"
            "            [--shutter-steps N]   (whitted/pathtracer: the motion sampled at N equally spaced times of the\n"
            "             shutter, 2..9, default from the largest turn over it, a step per 12 degrees: a turn\n"
            "             blurs along N - 1 chords of its arc)\n"
            "            [--clip A,B,C,D ...]   (section planes, up to 6: keeps A*x + B*y + C*z + D >= 0, world units)\n"
            "            [--clip-cap RRGGBB]   (fill the cut faces of closed meshes in this sRGB colour, e.g. ff8000)\n"
            "            [--frames A:B[:STEP] [--fps F] [--resume] -o OUT_####.exr|png]   (an image sequence: frames A..B\n"
            "             inclusive at time frame/F, F default 24; #### the zero-padded frame number; --resume skips\n"
            "             frames whose file exists; -o anim.mp4|anim.webm: one H.264 / VP9 video of the frames)\n"
            "  sy render SCENE -b pathtracer [-o OUT.exr|png|jpg] [--spp N | --time SECONDS] [--aov]\n"
            "            (+ the options above; --aov: one EXR of the feature buffers, object_id and instance_id\n"
            "             included: the node id and placement sy pick reports at each pixel centre)\n"
            "            [--filter none|pixel|atrous|jbu|adaptive|radiance] [--threshold T]   (display filter)\n"
            "  sy demo [-o DIR] [-w W] [-h H] [--filter pixel|none|...]   (the progressive back-end's display filter)\n"
            "  sy compare SCENE [-w W] [-h H] [--spp N] [-o SHEET.png] [--camera C] [--backends a,b,...]\n"
            "            (every back-end side by side: contact sheet + mean luminance, ratio and IoU table)\n"
            "  sy convert SCENE -o OUT.glb|OUT.gltf   (any scene sy reads written as glTF 2.0: hierarchy, meshes,\n"
            "            materials and their extensions, PNG textures, cameras, lights; the rest named as warnings)\n"
            "  sy view SCENE [-b BACKEND] [-w W] [-h H] [--camera C] [--overlay FILE[:BACKEND]]\n"
            "          [--look-at EYE:TARGET[:UP] | --orbit AZ,EL[,DIST]] [--fov DEG]   (the start view; as sy render)\n"
            "          [--frames N --screenshot OUT.png] [--filter none|pixel|atrous|jbu|adaptive|radiance] [--threshold T]\n"
            "          [--hide NODE] [--isolate NODE] [--select NODE]   (as sy render)\n"
            "          [--keys KEYS]   (automated runs: press these keys one frame after another, e.g. F]F[; * clicks\n"
            "           the window's centre)\n"
            "          (click: pick and select the node, shift-click: add or remove it, click on nothing: clear;\n"
            "           H hides the selection, I isolates it, U shows every node again; the title shows the picked\n"
            "           point, its distance from the previous pick and from the last section plane, in metres)\n"
            "          [--clip A,B,C,D ...] [--clip-cap RRGGBB]   (start section planes; keys: C adds a plane facing\n"
            "           the view through the last picked point or the orbit's centre, X removes the last, J / L or\n"
            "           Page Down / Page Up or Ctrl+wheel move it, N flips it, K turns the caps on and off)\n"
            "          [--bookmarks FILE]   (saved views: Ctrl+1..9 saves the view, Shift+1..9 recalls it; default\n"
            "           SCENE.bookmarks beside the scene; sy render --bookmark FILE:N renders one)\n"
            "          [--budget MS]   (frame time while the view moves: the resolution follows it; default 33)\n"
            "          [--cluster URL[,URL...]|FILE.conf [--cluster-mode MODE] [--secret-file F] [--timeout-ms MS]\n"
            "           [--spp SAMPLES_PER_SERVER_AND_FRAME]]   (the same cluster options as sy render)\n"
            "  sy web SCENE [-b BACKEND] [--listen HOST:PORT] [--camera C] [-w MAX_W] [-h MAX_H] [--quality Q]\n"
            "          [--look-at EYE:TARGET[:UP] | --orbit AZ,EL[,DIST]] [--fov DEG]   (the start view; as sy render)\n"
            "          [--hide NODE] [--isolate NODE] [--select NODE]   (the start state; as sy render)\n"
            "          [--filter none|pixel|...] [--threshold T] [--budget MS] [--min-scale S] [--client-render]   (the view in a browser:\n"
            "           open the URL it prints; another address than loopback needs the printed token)\n"
            "          [--read-only]   (viewers move the camera, pick and take stills, but change no visibility,\n"
            "           selection, section plane, exposure, filter or back-end)\n"
            "          [--delay-ms N]   (tests only: N ms of added network delay each way)\n"
            "          [--clip NAME|INDEX]   (the clip the page's timeline plays; default: as sy render --at)\n"
            "          [--bookmarks FILE]   (the saved views pages share: the panel's Saved views, Shift+1..9 recalls;\n"
            "           default SCENE.bookmarks beside the scene, the file sy view keeps)\n"
            "  sy bench web [SCENE] [-b BACKEND] [-w W] [-h H] [--repeats N]   (input-to-frame latency, loopback)\n"
            "  sy bench stream [SCENE] [-b BACKEND] [-w W] [-h H] [--repeats FPS]   (sy web's JPEG vs VP8 / VP9: bytes at equal SSIM, 10 s orbit)\n"
            "  sy bench sync [--nodes N] [--tris T] [--repeats R]\n"
            "  sy bench rays [SCENE] [-w W] [-h H] [--repeats R]\n"
            "  sy bench pathtracer [SCENE] [-w W] [-h H] [--repeats PASSES]\n"
            "  sy bench limit [SCENE] [-w W] [-h H] [--spp N] [--repeats N]   (path tracer vs raw Embree, same rays)\n"
            "  sy bench lights [DIR] [--nodes QUADS] [--tris POINT_LIGHTS] [-w W] [-h H] [--repeats SECONDS]\n"
            "            (many lights: the light tree vs the alias table at equal time, 10^4 + 10^3 by default;\n"
            "            the scene and the images in DIR, an existing folder, or a new one in /tmp)\n"
            "  sy bench filters [SCENE --reference REF.exr] [SHEET.png] [-w W] [-h H] [--repeats R]\n"
            "  sy bench temporal [SCENE...] [-w W] [-h H] [--frames N] [--spp REF] [--cost-frames N] [--png PREFIX]   (temporal reuse, moving camera)\n"
            "  sy bench raster [SCENE] [-w W] [-h H] [--repeats R] [--params gl=egl,msaa=4]\n"
            "  sy bench viewports [-w W] [-h H] [--repeats R]\n"
            "  sy bench load [GLTF_SAMPLE_DIR] [--tris T] [--repeats R]\n"
            "  sy bench memory [--tris T] [-b whitted|pathtracer] [--glb] [-w W] [-h H]   (peak RSS per triangle;\n"
            "            generated and from a .glb, --glb: the .glb alone)\n"
            "  sy bench instances [DIR] [--nodes INSTANCES] [--tris PER_MESH] [-w W] [-h H] [--repeats FRAMES] [-b BACKEND]\n"
            "            (one mesh instanced: 10^3 x 10^6 triangles by default, every picture back-end; generated,\n"
            "            then through a .glb with normals and one without, kept in DIR when given)\n"
            "  sy bench governor [SCENE] [--budget MS] [--frames N] [-w W] [-h H]   (frame-time governor, orbiting camera)\n"
            "  sy bench deform [--tris VERTICES] [--repeats FRAMES]   (a skinned frame: deform, refit, re-upload)\n"
            "  sy bench anim [--tris VERTICES] [--nodes NODES] [--repeats FRAMES]   (an animated frame from a .glb, step by\n"
            "            step: clock, commit, change list, deformation, sync, refit / upload, against from scratch)\n"
            "  sy bench cull [--tris N] [--objects N] [--budget T] [-w W] [-h H] [--frames N] [--write PLANT.glb]\n"
            "  sy coverage SCENE [--camera C] [-w W] [-h H] [--top N]\n"
            "  sy pick SCENE X Y [X Y ...] [-b BACKEND] [-w W] [-h H] [--camera NAME|INDEX] [--params k=v,...]\n"
            "            [--look-at EYE:TARGET[:UP] | --orbit AZ,EL[,DIST]] [--fov DEG]   (the view; as sy render)\n"
            "            [--clip A,B,C,D ...] [--hide NODE] [--isolate NODE] [--select NODE]   (as sy render)\n"
            "            (what is under pixel (X, Y) of the view sy render draws, as JSON: node, mesh, primitive,\n"
            "             triangle, barycentrics, position, normal, material, distance; \"hit\": false on a miss)\n"
            "            [--measure]   (two points X1 Y1 X2 Y2: {\"picks\", \"distance\", \"delta\", \"unit\": \"m\"}, scene units)\n"
            "            [--plane A,B,C,D]   (each hit's signed distance from the plane: \"plane_distance\")\n"
            "            [--clip-cap RRGGBB]   (with --clip: a pick through a cut closed mesh lands on its cap, \"cap\": N)\n"
            "  sy backends [--params] [--json]\n"
            "  sy serve [--listen tcp://HOST:PORT] [--secret-file F] [--output OUT.exr|png] (sy serve --help)\n"
            "  sy render SCENE -b BACKEND -o OUT --cluster URL[,URL...]|FILE.conf\n"
            "            [--cluster-mode sort-first|balanced|cooperative|multi-display|stereo|frames] [--secret-file F]\n"
            "            [--tls-ca PEM] [--timeout-ms MS] [--repeat N] [--spp N] [--cluster-pixels float|half]\n"
            "            (frames: --frames A:B [--resume] -o out_####.exr, whole frames to servers from a work queue)\n"
            "  sy bench cluster [-w W] [-h H] [--repeats ROUNDS]\n"
            "  sy bench cluster --soak SECONDS [--warmup S] [-b BACKEND] [-w W] [-h H]   (sy serve soak: RSS, fds, threads)\n"
            "SCENE: a glTF (.gltf, .glb) or X3D (XML) file, recognised by its content, or 'demo' (the built-in scene)\n"
            "world options (every command): [--env MAP.exr|MAP.hdr | --env-color R,G,B] [--env-intensity X] [--env-hidden]\n"
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
void sy_cli_usage_to(FILE *f, const char *cmd)
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
int sy_cli_usage_of(const char *cmd, const char *what)
{
    if (what) fprintf(stderr, "sy %s: error: %s\n", cmd, what);
    sy_cli_usage_to(stderr, cmd);
    return 2;
}

/* "--name" of a long option's code in a getopt_long table (for messages). */
const char *sy_cli_option_name(const struct option *lo, int c)
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
int sy_cli_bad_value(const char *opt, const char *value)
{
    fprintf(stderr, "sy: error: %s: '%s' is not an accepted value\n", opt, value);
    return 2;
}

bool sy_cli_is_clip_plane(const char *value) { return strchr(value, ',') != NULL; }

int sy_cli_parse_cap_color(const char *value, float rgb[3])
{
    const char *s = value[0] == '#' ? value + 1 : value;
    bool ok = strlen(s) == 6;
    for (int i = 0; ok && i < 6; ++i) ok = isxdigit((unsigned char)s[i]) != 0;
    if (!ok) {
        fprintf(stderr, "sy: error: --clip-cap: '%s' is not a colour RRGGBB (six hexadecimal digits, sRGB, e.g. "
                        "ff8000)\n", value);
        return 2;
    }
    for (int k = 0; k < 3; ++k) {
        char hex[3] = {s[2 * k], s[2 * k + 1], 0};
        float c = (float)strtol(hex, NULL, 16) / 255.0f; /* sRGB to linear */
        rgb[k] = c <= 0.04045f ? c / 12.92f : powf((c + 0.055f) / 1.055f, 2.4f);
    }
    return 0;
}

int sy_cli_add_clip_plane(const char *value, float (*planes)[4], uint32_t *count)
{
    if (*count >= SY_CLIP_PLANES_MAX) {
        fprintf(stderr, "sy: error: --clip: '%s' is one section plane too many (at most %d)\n", value,
                SY_CLIP_PLANES_MAX);
        return 2;
    }
    float q[4];
    if (sy_cli_parse_plane("--clip", value, q)) return 2;
    memcpy(planes[(*count)++], q, sizeof q);
    return 0;
}

int sy_cli_parse_plane(const char *opt, const char *value, float q[4])
{
    int n = 0;
    if (!sy_cli_parse_floats(value, strlen(value), 4, 4, q, &n) || !sy_coords_in_range(q, 4)) {
        fprintf(stderr, "sy: error: %s: '%s' is not a %splane A,B,C,D (four finite numbers: "
                        "A*x + B*y + C*z + D >= 0 is its kept side)\n", opt, value, strcmp(opt, "--clip") ? "" : "section ");
        return 2;
    }
    sy_error e = {0};
    if (sy_clip_planes_check((const float(*)[4])q, 1, &e) != SY_OK) {
        fprintf(stderr, "sy: error: %s: '%s': %s\n", opt, value, e.message);
        return 2;
    }
    return 0;
}

/* s as a whole number in lo..hi; si: k (thousand) or M (million) may follow the digits. */
static bool parse_whole(const char *s, uint64_t lo, uint64_t hi, bool si, uint64_t *out)
{
    char *end = NULL;
    if (!isdigit((unsigned char)*s)) return false; /* strtoull would take a sign or spaces */
    errno = 0;
    unsigned long long v = strtoull(s, &end, 10);
    uint64_t scale = !si ? 1 : *end == 'k' || *end == 'K' ? 1000 : *end == 'M' ? 1000000 : 1;
    if (scale > 1) {
        if (v > UINT64_MAX / scale) return false;
        v *= scale, end++;
    }
    if (errno || *end || v < lo || v > hi) return false;
    *out = v;
    return true;
}

bool sy_cli_parse_uint(const char *s, uint64_t lo, uint64_t hi, uint64_t *out) { return parse_whole(s, lo, hi, false, out); }

bool sy_cli_parse_double(const char *s, double lo, double hi, double *out)
{
    char *end = NULL;
    double v = strtod(s, &end);
    if (end == s || *end || (lo <= hi && !(v >= lo && v <= hi))) return false; /* the range refuses NaN and infinities */
    *out = v;
    return true;
}

/* A usage error naming the option and the range its value is not in (a number's); returns 2. */
static int bad_number(const char *opt, const char *value, double lo, double hi, bool whole)
{
    if (whole) fprintf(stderr, "sy: error: %s: '%s' is not in %llu..%llu\n", opt, value, (unsigned long long)lo, (unsigned long long)hi);
    else if (hi >= DBL_MAX && lo <= DBL_MIN && lo > 0) fprintf(stderr, "sy: error: %s: '%s' is not a number above 0\n", opt, value);
    else if (lo > hi || hi >= FLT_MAX || lo <= -FLT_MAX) return sy_cli_bad_value(opt, value); /* any number, or unbounded */
    else fprintf(stderr, "sy: error: %s: '%s' is not in %.10g..%.10g\n", opt, value, lo, hi);
    return 2;
}

/* next_option plus -w W / -h H: min_size..16384 pixels. */
static int next_sized_option(const char *cmd, int argc, char **argv, const char *shortopts,
                             const struct option *longopts, uint32_t min_size, uint32_t *w, uint32_t *h, int *status)
{
    for (;;) {
        int c = next_option(cmd, argc, argv, shortopts, longopts, status);
        if (c != 'w' && c != 'h') return c;
        uint64_t v = 0;
        if (!sy_cli_parse_uint(optarg, min_size, 16384, &v)) {
            *status = bad_number(c == 'w' ? "-w" : "-h", optarg, min_size, 16384, true);
            return OPT_STOP;
        }
        *(c == 'w' ? w : h) = (uint32_t)v;
    }
}

/* The getopt tables of p (the command's options, then the cluster's, the view options, the common ones)
 * and its short options; false (a usage error, p->status 2) when they do not fit (a programming
 * error, named). */
static bool parser_build(sy_cli_parser *p)
{
    static const struct option cluster[] = {SY_CLUSTER_CLI_OPTIONS}, view[] = {VIEW_OPTIONS}, all[] = {COMMON_OPTIONS},
                               own[] = {{"help", no_argument, NULL, OPT_OWN_HELP}, {"quiet", no_argument, NULL, 'q'},
                                        {"verbose", no_argument, NULL, 'v'}, {NULL, 0, NULL, 0}};
    const struct option *common = p->usage ? own : all;
    size_t common_count = p->usage ? sizeof own / sizeof own[0] : sizeof all / sizeof all[0];
    size_t n = 0, cap = sizeof p->lo / sizeof p->lo[0], k = 0;
    char *so = p->shortopts;
    if (!p->cmd) so[k++] = '+'; /* sy's own options end at the command */
    so[k++] = ':';
    for (size_t i = 0; i < p->count; ++i) {
        const sy_cli_opt *o = &p->opts[i];
        if (o->name && n < cap) p->lo[n++] = (struct option){o->name, o->value ? required_argument : no_argument, NULL, o->code};
        if (!o->name && k + 3 < sizeof p->shortopts) {
            so[k++] = (char)o->code;
            if (o->value) so[k++] = ':';
        }
    }
    if (p->w && k + 5 < sizeof p->shortopts) memcpy(so + k, "w:h:", 4), k += 4;
    for (size_t i = 0; p->cluster && i < sizeof cluster / sizeof cluster[0] && n < cap; ++i) p->lo[n++] = cluster[i];
    for (size_t i = 0; p->view && i < sizeof view / sizeof view[0] && n < cap; ++i) p->lo[n++] = view[i];
    for (size_t i = 0; i < common_count && n < cap; ++i) p->lo[n++] = common[i];
    if (n == cap || k + 3 > sizeof p->shortopts) {
        fprintf(stderr, "sy%s%s: error: too many options for the parser's table\n", p->cmd ? " " : "", p->cmd ? p->cmd : "");
        p->status = 2;
        return false;
    }
    memcpy(so + k, "qv", 3);
    return true;
}

/* "--name" or "-c" of a declared option, for messages (a static buffer). */
static const char *opt_label(const sy_cli_opt *o)
{
    static char b[64];
    if (o->name) snprintf(b, sizeof b, "--%s", o->name);
    else snprintf(b, sizeof b, "-%c", o->code);
    return b;
}

int sy_cli_parse(sy_cli_parser *p)
{
    if (!p->started) {
        if (!parser_build(p)) return OPT_STOP;
        p->started = true;
        optind = 0; /* glibc: start over (new arguments, GNU ordering) */
    }
    for (;;) {
        int c = p->w ? next_sized_option(p->cmd, p->argc, p->argv, p->shortopts, p->lo, p->min_size, p->w, p->h, &p->status)
                     : next_option(p->cmd, p->argc, p->argv, p->shortopts, p->lo, &p->status);
        if (c == OPT_OWN_HELP) {
            fputs(p->usage, stdout);
            p->status = 0;
            return OPT_STOP;
        }
        const sy_cli_opt *o = NULL;
        for (size_t i = 0; i < p->count && !o; ++i)
            if (p->opts[i].code == c) o = &p->opts[i];
        if (!o || o->kind == SY_CLI_CODE) return c; /* -1, OPT_STOP, the command's own, the cluster's */
        bool ok = true;
        uint64_t u = 0;
        double d = 0;
        switch (o->kind) {
        case SY_CLI_TEXT: *(const char **)o->to = optarg; break;
        case SY_CLI_FLAG:
            if (o->to) *(bool *)o->to = true;
            break;
        case SY_CLI_UINT: /* hi <= UINT32_MAX */
        case SY_CLI_COUNT:
            if ((ok = parse_whole(optarg, (uint64_t)o->lo, (uint64_t)o->hi, o->kind == SY_CLI_COUNT, &u))) {
                if (o->kind == SY_CLI_UINT) *(uint32_t *)o->to = (uint32_t)u;
                else *(uint64_t *)o->to = u;
            }
            break;
        case SY_CLI_REAL:
        case SY_CLI_FLOAT:
            if ((ok = sy_cli_parse_double(optarg, o->lo, o->hi, &d))) {
                if (o->kind == SY_CLI_REAL) *(double *)o->to = d;
                else *(float *)o->to = (float)d;
            }
            break;
        case SY_CLI_CODE: break;
        }
        if (!ok) {
            p->status = o->kind == SY_CLI_TEXT ? sy_cli_bad_value(opt_label(o), optarg) : bad_number(opt_label(o), optarg, o->lo, o->hi, o->kind == SY_CLI_UINT || o->kind == SY_CLI_COUNT);
            return OPT_STOP;
        }
    }
}

/* The one SCENE operand after the options. */
int sy_cli_scene_operand(const char *cmd, int argc, char **argv, const char **scene)
{
    if (argc - optind != 1) return sy_cli_usage_of(cmd, argc == optind ? "a SCENE is required" : "one SCENE at a time");
    *scene = argv[optind];
    return 0;
}

bool sy_cli_ends_with(const char *s, const char *suffix)
{
    size_t n = strlen(s), m = strlen(suffix);
    return n >= m && strcasecmp(s + n - m, suffix) == 0;
}

/* The back-end a command uses without -b: the registry's default (sy_mediator_default). */
const char *sy_cli_default_backend(sy_error *err)
{
    const char *name = sy_mediator_default_name();
    if (!*name) sy_error_set(err, SY_ERR_NOT_FOUND, "no back-end offers itself as the default; name one with -b (sy backends)");
    return *name ? name : NULL;
}
