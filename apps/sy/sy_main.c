/* sy_main.c — the `sy` command line tool: sy's own options and the dispatch to its commands (info,
 * render, demo, compare, convert, coverage, pick, view, web, bench, backends, serve), one file each (sy_commands.h).
 *
 *   sy [-q | -v] [--version | --help] COMMAND ...   -q: errors only, -v: debug messages (sy_log.h)
 *   sy help [COMMAND], sy COMMAND --help            usage on stdout, exit status 0
 *   sy info SCENE | IMAGE.exr | .png    JSON summary (counts, bounds, warnings; an image's metadata)
 *   sy render SCENE -b BACKEND -o OUT.exr|png [-w W] [-h H] [--camera NAME|INDEX]
 *             [--params k=v,...] [--half] [--exposure EV] [--tonemap clamp|reinhard|aces]
 *             [--max-memory MB]   (ray tracers: max_memory_mb, a scene whose BVHs need more is refused)
 *             [--at SECONDS] [--clip NAME|INDEX]   the scene at a time on its clock (sy_anim.h)
 *             [--shutter OPEN,CLOSE | --motion-blur] [--shutter-samples N] [--shutter-steps N]   motion blur
 *             [--frames A:B[:STEP] [--fps F] [--resume] -o OUT_####.exr]   an image sequence
 *             with -b pathtracer: [--spp N | --time SECONDS] [--aov]
 *             [--filter none|pixel|atrous|jbu|adaptive|radiance [--threshold T]]
 *   world options of every command: [--env MAP.exr|MAP.hdr | --env-color R,G,B] [--env-intensity X] [--env-hidden]
 *             [--background R,G,B[,A]] [--no-default-light]   (see sy_world.h and sy_look.h)
 *             [--gl osmesa|egl|glfw]  (raster back-end's GL context provider)
 *   sy demo [-o DIR] [-w W] [-h H]      render the built-in demo scene with every back-end
 *   sy compare SCENE [-w W] [-h H] [--spp N] [-o SHEET.png]   every back-end side by side (sy_compare.h)
 *   sy convert SCENE -o OUT.glb|OUT.gltf   any readable scene as glTF 2.0 (sy_gltf_write.h)
 *   sy bench sync [--nodes N] [--tris T] [--repeats R]
 *   sy bench rays [SCENE] [-w W] [-h H] [--repeats R]
 *   sy bench raster [SCENE] [-w W] [-h H] [--repeats R] [--params k=v,...]
 *   sy bench load [GLTF_SAMPLE_DIR] [--tris T] [--repeats R]
 *   sy bench limit [SCENE] [-w W] [-h H] [--spp N] [--repeats N]   (sy_bench_limit.c)
 *   sy bench memory [--tris T] [-b whitted|pathtracer] [--glb] [-w W] [-h H]   peak RSS per triangle (sy_bench.h)
 *   sy bench filters [SCENE --reference REF.exr] [SHEET.png] [-w W] [-h H] [--repeats R]
 *   sy backends [--params] [--json]     list registered back-ends (--params: their parameters)
 *   sy serve [--listen URL] [--secret-file F] [--output OUT]   render server (apps/sy/sy_cmd_serve.c)
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
 * is named), 130 interrupted. Bash completion: apps/sy/sy-completion.bash.
 *
 * The files: sy_cmd_COMMAND.c (sy_commands.h), what the commands share: the command line
 * (sy_cli.h: the options of every command, usage, errors), loading a scene (sy_load.h), the images
 * written (sy_output.h), the JSON printed (sy_json.h); the benchmarks (sy_bench.h, sy_bench_*.c),
 * the cluster commands (sy_cluster_cli.h), the viewer (sy_view.h), compositing (sy_compose.h). */
#include "sy_cli.h"
#include "sy_cluster_cli.h"
#include "sy_commands.h"
#include "sy_signals.h"
#include "sy_testpoint.h"

#include "sy_log.h"
#include "sy_mediators.h"
#include "sy_viewport.h"

#include <stdio.h>
#include <string.h>



int main(int argc, char **argv)
{
    sy_error err = {0};
    /* before any thread: interrupts are taken on a thread of their own, output files in progress
     * are removed when one ends the process */
    sy_signals_start();
    sy_testpoint_start(); /* SY_TEST_PHASES / SY_TEST_PAUSE: tests wait for phases (sy_testpoint.h) */
    if (sy_mediators_register_builtin(&err) != SY_OK) return sy_cli_fail(&err);
    /* sy's own options before the command (they end at the first operand, the command): --version,
     * --help / -h, -q / -v and the options of every command (world and loader flags) */
    const sy_cli_opt opts[] = {SY_CLI_OPT_CODE("version", OPT_VERSION, false), SY_CLI_OPT_CODE(NULL, 'h', false)};
    sy_cli_parser p = {SY_CLI_ARGS(NULL, argc, argv, opts)};
    int c;
    while ((c = sy_cli_parse(&p)) != -1) {
        if (c == OPT_STOP) return p.status;
        if (c == OPT_VERSION) {
            printf("sy (Switchyard) %s\n", sy_version());
            return 0;
        }
        sy_cli_usage_to(stdout, NULL); /* -h */
        return 0;
    }
    if (optind >= argc) {
        fprintf(stderr, "sy: error: no command given\n");
        sy_cli_usage_to(stderr, NULL);
        return 2;
    }
    argc -= optind, argv += optind; /* argv[0]: the command; each command parses the rest itself */
    const char *cmd = argv[0];
    if (!strcmp(cmd, "version")) {
        printf("sy (Switchyard) %s\n", sy_version());
        return 0;
    }
    static const char *const commands[] = {"info", "render", "demo", "compare", "convert", "bench", "backends", "coverage", "pick",
                                           "serve", "view", "web", "version", "help"};
    if (!strcmp(cmd, "help")) { /* sy help [COMMAND] */
        bool known = argc < 2;
        for (size_t k = 0; !known && k < sizeof commands / sizeof commands[0]; ++k) known = !strcmp(argv[1], commands[k]);
        if (!known) {
            fprintf(stderr, "sy help: error: unknown command '%s' (sy --help lists them)\n", argv[1]);
            return 2;
        }
        sy_cli_usage_to(stdout, argc < 2 || !strcmp(argv[1], "help") || !strcmp(argv[1], "version") ? NULL : argv[1]);
        return 0;
    }
    if (!strcmp(cmd, "info")) return sy_cmd_info(argc, argv);
    if (!strcmp(cmd, "render")) {
        int rc = sy_cmd_render(argc, argv);
        sy_cluster_cli_mpi_end(); /* --cluster mpi on rank 0: release the server ranks */
        return rc;
    }
    if (!strcmp(cmd, "demo")) return sy_cmd_demo(argc, argv);
    if (!strcmp(cmd, "compare")) return sy_cmd_compare(argc, argv);
    if (!strcmp(cmd, "convert")) return sy_cmd_convert(argc, argv);
    if (!strcmp(cmd, "bench")) return sy_cmd_bench(argc, argv);
    if (!strcmp(cmd, "backends")) return sy_cmd_backends(argc, argv);
    if (!strcmp(cmd, "coverage")) return sy_cmd_coverage(argc, argv);
    if (!strcmp(cmd, "pick")) return sy_cmd_pick(argc, argv);
    if (!strcmp(cmd, "serve")) return sy_cmd_serve(argc, argv);
#ifdef SY_HAVE_GLFW
    if (!strcmp(cmd, "view")) return sy_cmd_view(argc, argv);
#endif
#ifdef SY_HAVE_WEB
    if (!strcmp(cmd, "web")) return sy_cmd_web(argc, argv);
#endif
    fprintf(stderr, "sy: error: unknown command '%s' (sy --help lists them)\n", cmd);
    return 2;
}
