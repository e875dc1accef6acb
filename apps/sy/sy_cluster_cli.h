/* sy_cluster_cli.h — the cluster parts of the `sy` tool: `sy serve` (a render server,
 * sy_cmd_serve.c), the `--cluster ...` options of `sy render` and `sy view` (sy_cluster_cli.c;
 * `--cluster mpi`: sy_cluster_cli_mpi.c), and `sy bench cluster` (sy_bench_cluster*.c). Built on
 * mediators/cluster/ (sy_cluster.h, sy_mediator_cluster.h); a build without the cluster compiles
 * sy_cluster_cli_off.c instead of those files, whose entry points say so.
 * Thread-safety: command-line entry points, single-threaded callers. */
#ifndef SY_CLUSTER_CLI_H
#define SY_CLUSTER_CLI_H

#include "sy_cluster.h"
#include "sy_viewport.h"

#include <getopt.h>

/* sy serve [--listen URL] [--secret-file F] [--output PATH] [--port-file F] [--tls-cert F --tls-key F]
 *          [--max-sessions N] [--max-lifetime S] [--name NAME] [--blob-cache-mb N] [--max-objects N]
 *          [--auth-backoff-ms MS] [--max-peer-memory-mb N] [--max-frame-kb N] [--max-message-mb N]
 *          [--max-unauthenticated N] [--handshake-timeout-ms MS] [-q | -v] [--help]
 * argv[0] is the command's name ("serve"); the options are parsed with getopt_long (a bad option or
 * value: named on stderr, 2). */
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
    sy_cluster_log_fn log;       /* client log lines; NULL = sy_log (sy_log.h) */
    void *log_user;
    const uint8_t *secret;       /* non-NULL: this secret (the MPI job's), not secret_file */
    size_t secret_len;
} sy_cluster_cli_opts;

/* `--cluster mpi` (sy render under mpirun / srun): initialises MPI and shares the job secret.
 * Rank 0 returns SY_OK with o->cluster set to the other ranks' URLs and o->secret to the job
 * secret: it is the client. Every other rank serves rank 0 until it is done, then *served is set
 * (the command ends there). Errors name the reason (no MPI in this build, a single rank). */
sy_result sy_cluster_cli_mpi_start(sy_cluster_cli_opts *o, bool *served, sy_error *err);
/* After the command on rank 0 (its cluster contexts gone): releases the server ranks and ends MPI;
 * nothing when MPI was not started. */
void sy_cluster_cli_mpi_end(void);

/* The cluster options of sy render and sy view as getopt_long entries (their codes are
 * SY_CLUSTER_OPT_*; --frames and --spp are each command's own): --cluster, --cluster-mode,
 * --secret-file, --tls-ca, --timeout-ms, --cluster-pixels. */
enum {
    SY_CLUSTER_OPT_CLUSTER = 0x200, SY_CLUSTER_OPT_MODE, SY_CLUSTER_OPT_SECRET_FILE, SY_CLUSTER_OPT_TLS_CA,
    SY_CLUSTER_OPT_TIMEOUT_MS, SY_CLUSTER_OPT_PIXELS
};
#define SY_CLUSTER_CLI_OPTIONS                                                                                         \
    {"cluster", required_argument, NULL, SY_CLUSTER_OPT_CLUSTER},                                                      \
    {"cluster-mode", required_argument, NULL, SY_CLUSTER_OPT_MODE},                                                    \
    {"secret-file", required_argument, NULL, SY_CLUSTER_OPT_SECRET_FILE},                                              \
    {"tls-ca", required_argument, NULL, SY_CLUSTER_OPT_TLS_CA},                                                        \
    {"timeout-ms", required_argument, NULL, SY_CLUSTER_OPT_TIMEOUT_MS},                                                \
    {"cluster-pixels", required_argument, NULL, SY_CLUSTER_OPT_PIXELS}

/* Applies the cluster option with code c (SY_CLUSTER_OPT_*) and its value to *o; false when the value
 * is not accepted (the caller names it) or c is not a cluster option. */
bool sy_cluster_cli_getopt(int c, const char *value, sy_cluster_cli_opts *o);

/* `sy render --cluster` and `sy view --cluster`: registers the cluster mediator class (SY_MEDIATOR_CLUSTER_NAME) from the
 * options and writes the viewport parameters that select it into params_out:
 * "backend=BACKEND,mode=MODE[,pixels=half][,PARAMS]". The render then goes through the window like
 * any local one. *viewer_tile (may be NULL): the configuration's 'viewer tile' (w 0: none). *mode_out: the configured mode (stereo is the window's business: the parameters
 * say sort-first); *servers_out: the servers configured. */
sy_result sy_cluster_cli_setup(const sy_cluster_cli_opts *o, const char *backend, const char *params, char *params_out,
                               size_t len, uint32_t *mode_out, uint32_t *servers_out, sy_cluster_rect *viewer_tile,
                               sy_error *err);
/* Registers the cluster mediator class `name` for o as sy_cluster_cli_setup does for "cluster" (the
 * Python package registers one per distinct configuration); *mode_out / *servers_out as there. */
sy_result sy_cluster_cli_register(const sy_cluster_cli_opts *o, const char *name, uint32_t *mode_out,
                                  uint32_t *servers_out, sy_error *err);
/* The cluster viewport's parameters for back-end `backend` in `mode` (stereo: sort-first) with the
 * options' pixel format and the back-end's own params (may be NULL). */
sy_result sy_cluster_cli_params(const sy_cluster_cli_opts *o, const char *backend, uint32_t mode, const char *params,
                                char *out, size_t len, sy_error *err);

/* `sy render --frames A:B --cluster-mode frames`: connects to o's servers (URLs or configuration
 * file, secret, TLS) with scene as the client's scene, renders the job (sy_cluster_client_render_frames:
 * a work queue of whole frames, re-queued when a server fails), says BYE. *servers_out: the servers
 * configured. */
sy_result sy_cluster_cli_render_frames(const sy_cluster_cli_opts *o, sy_scene *scene, const sy_cluster_frames_job *job,
                                       sy_cluster_frames_stats *stats, uint32_t *servers_out, sy_error *err);

/* The cluster mediator's statistics of its last frame and its configured mode (mode may be NULL);
 * ctx is a context of the cluster class (caps SY_CAP_REMOTE). */
void sy_cluster_cli_last_frame(const sy_context *ctx, sy_cluster_frame_stats *stats, uint32_t *mode);
/* The name of a cluster mode (sy_cluster_mode_name). */
const char *sy_cluster_cli_mode_name(uint32_t mode);

/* sy bench cluster [-w W] [-h H] [--repeats ROUNDS] [--hostile-only]: sizes, overhead, latency, codec,
 * a server's memory and a client's frame time under 72 hostile unauthenticated connections,
 * cooperative speed-up (--hostile-only: the hostile measurement alone). argv[0] is "cluster". */
int sy_cmd_bench_cluster(int argc, char **argv);

#endif /* SY_CLUSTER_CLI_H */
