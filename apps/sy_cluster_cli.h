/* sy_cluster_cli.h — the cluster parts of the `sy` tool: `sy serve` (a render server),
 * the `--cluster ...` options of `sy render`, and `sy bench cluster`. Built on core/sy_cluster.h.
 * Thread-safety: command-line entry points, single-threaded callers. */
#ifndef SY_CLUSTER_CLI_H
#define SY_CLUSTER_CLI_H

#include "sy_cluster.h"
#include "sy_viewport.h"

/* sy serve [--listen URL] [--secret-file F] [--output PATH] [--port-file F] [--tls-cert F --tls-key F]
 *          [--max-sessions N] [--max-lifetime S] [--name NAME] */
int sy_cmd_serve(int argc, char **argv);

/* Options of `sy render` that select cluster rendering. Zero-initialise. */
typedef struct sy_cluster_cli_opts {
    const char *cluster;     /* "tcp://h:p[,tcp://h:p...]"; NULL = local rendering */
    const char *mode;        /* sort-first (default), balanced, cooperative, multi-display, stereo */
    const char *secret_file; /* NULL = $SY_CLUSTER_SECRET */
    const char *tls_ca;
    uint32_t timeout_ms, frames, samples;
} sy_cluster_cli_opts;

/* true when argv holds --cluster (the render goes to the cluster whatever the back-end). */
bool sy_cluster_cli_requested(int argc, char **argv);

/* If argv[*i] is a cluster option, consumes it (and its value: *i advances) and returns true.
 * Returns false for other options; sets *bad when the value is missing or invalid. */
bool sy_cluster_cli_option(int argc, char **argv, int *i, sy_cluster_cli_opts *o, bool *bad);

/* Renders the viewport (scene, root, camera, background, back-end) on the cluster; creates *out
 * (w x h, or 2w x h side by side in stereo; untouched / empty in multi-display). */
sy_result sy_cluster_cli_render(const sy_cluster_cli_opts *o, sy_scene *scene, const sy_viewport_desc *vd,
                                uint32_t w, uint32_t h, sy_layer *out, double *seconds, sy_error *err);

/* sy bench cluster [-w W] [-h H] */
int sy_cmd_bench_cluster(int argc, char **argv);

#endif /* SY_CLUSTER_CLI_H */
