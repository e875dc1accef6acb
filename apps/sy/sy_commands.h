/* sy_commands.h — the commands of `sy`, one file each (sy_cmd_COMMAND.c), dispatched by main
 * (sy_main.c). Each takes the command's arguments (argv[0]: the command, "bench": argv[1] the
 * benchmark), parses them itself (sy_cli.h) and returns the exit status: 0 success, 1 failure,
 * 2 usage error, 130 interrupted. `sy serve`: sy_cmd_serve (sy_cluster_cli.h, sy_cmd_serve.c). */
#ifndef SY_COMMANDS_H
#define SY_COMMANDS_H

int sy_cmd_info(int argc, char **argv);     /* sy_cmd_info.c */
int sy_cmd_render(int argc, char **argv);   /* sy_cmd_render.c */
int sy_cmd_demo(int argc, char **argv);     /* sy_cmd_demo.c */
int sy_cmd_compare(int argc, char **argv);  /* sy_cmd_compare.c */
int sy_cmd_convert(int argc, char **argv);  /* sy_cmd_convert.c */
int sy_cmd_bench(int argc, char **argv);    /* sy_cmd_bench.c */
int sy_cmd_backends(int argc, char **argv); /* sy_cmd_backends.c */
int sy_cmd_coverage(int argc, char **argv); /* sy_cmd_coverage.c */
int sy_cmd_pick(int argc, char **argv);     /* sy_cmd_pick.c */
int sy_cmd_view(int argc, char **argv);     /* sy_cmd_view.c (built with GLFW: SY_HAVE_GLFW) */
int sy_cmd_web(int argc, char **argv);      /* sy_cmd_web.c (built with sy_web: SY_HAVE_WEB) */

#endif /* SY_COMMANDS_H */
