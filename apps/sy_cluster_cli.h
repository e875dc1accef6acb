/* sy_cluster_cli.h — the cluster parts of the `sy` tool: `sy serve` (a render server),
 * the `--cluster ...` options of `sy render` and `sy view`, and `sy bench cluster`. Built on core/sy_cluster.h.
 * Thread-safety: command-line entry points, single-threaded callers. */
#ifndef SY_CLUSTER_CLI_H
#define SY_CLUSTER_CLI_H

#include "sy_cluster.h"
#include "sy_viewport.h"

/* sy serve [--listen URL] [--secret-file F] [--output PATH] [--port-file F] [--tls-cert F --tls-key F]
 *          [--max-sessions N] [--max-lifetime S] [--name NAME] [--blob-cache-mb N] [--max-objects N]
 *          [--auth-backoff-ms MS] [--max-peer-memory-mb N] [--max-frame-kb N] [--max-message-mb N]
 *          [--max-unauthenticated N] [--handshake-timeout-ms MS] */
int sy_cmd_serve(int argc, char **argv);

/* Options of `sy render` that select cluster rendering. Zero-initialise. */
typedef struct sy_cluster_cli_opts {
    const char *cluster;     /* "tcp://h:p[,tcp://h:p...]"; NULL = local rendering */
    const char *mode;        /* sort-first (default), balanced, cooperative, multi-display, stereo */
    const char *secret_file; /* NULL = $SY_CLUSTER_SECRET */
    const char *tls_ca;
    uint32_t timeout_ms, frames, samples;
    uint32_t connect_timeout_ms; /* handshake deadline; 0 = the client's default */
    bool half_pixels;            /* --cluster-pixels half: binary16 tiles (default float: bit-exact) */
    sy_cluster_log_fn log;       /* client log lines; NULL = stderr */
    void *log_user;
} sy_cluster_cli_opts;

/* true when argv holds --cluster (the render goes to the cluster whatever the back-end). */
bool sy_cluster_cli_requested(int argc, char **argv);

/* If argv[*i] is a cluster option, consumes it (and its value: *i advances) and returns true.
 * Returns false for other options; sets *bad when the value is missing or invalid. */
bool sy_cluster_cli_option(int argc, char **argv, int *i, sy_cluster_cli_opts *o, bool *bad);

/* A cluster client made from the options: the URL list or configuration file, the mode (option,
 * else the file's, else sort-first), the secret, per-server back-ends and wall tiles. */
typedef struct sy_cluster_cli_client {
    sy_cluster_client *client; /* owned: sy_cluster_client_destroy */
    uint32_t mode;             /* sy_cluster_mode */
    uint32_t servers;          /* servers configured */
    sy_cluster_rect viewer_tile; /* configuration 'viewer tile X Y W H'; w == 0: 'viewer full' (default) */
} sy_cluster_cli_client;

/* Parses the options and connects (sy_cluster_client_create). Ownership: out->client is the
 * caller's; it borrows the scene. Used by `sy render --cluster` and `sy view --cluster`. */
sy_result sy_cluster_cli_connect(const sy_cluster_cli_opts *o, sy_scene *scene, sy_cluster_cli_client *out,
                                 sy_error *err);

/* Renders the viewport (scene, root, camera, background, back-end) on the cluster; creates *out
 * (w x h, or 2w x h side by side in stereo; untouched / empty in multi-display). */
sy_result sy_cluster_cli_render(const sy_cluster_cli_opts *o, sy_scene *scene, const sy_viewport_desc *vd,
                                uint32_t w, uint32_t h, sy_layer *out, double *seconds, sy_error *err);

/* sy bench cluster [-w W] [-h H] [--repeats ROUNDS] [--hostile-only]: sizes, overhead, latency, codec,
 * a server's memory and a client's frame time under 72 hostile unauthenticated connections,
 * cooperative speed-up (--hostile-only: the hostile measurement alone) */
int sy_cmd_bench_cluster(int argc, char **argv);

#endif /* SY_CLUSTER_CLI_H */
