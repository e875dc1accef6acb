/* sy_cluster_cli_off.c — the cluster parts of `sy` in a build without the cluster
 * (-DSY_WITH_CLUSTER=OFF): the same entry points as sy_cluster_cli.c, so the commands (sy_cmd_*.c) and sy_view.c
 * need no conditional code; each one that would start cluster work says that this build does not
 * have it (exit status 1, or SY_ERR_UNSUPPORTED). Only the cluster's headers are used (types). */
#include "sy_cluster_cli.h"

#include "sy_log.h"

#include <stdio.h>

#define SY_NO_CLUSTER "this sy was built without cluster rendering (SY_WITH_CLUSTER=OFF)"

int sy_cmd_serve(int argc, char **argv)
{
    (void)argc, (void)argv;
    sy_log(SY_LOG_ERROR, "sy", "serve", SY_NO_CLUSTER);
    return 1;
}

int sy_cmd_bench_cluster(int argc, char **argv)
{
    (void)argc, (void)argv;
    sy_log(SY_LOG_ERROR, "sy", "bench cluster", SY_NO_CLUSTER);
    return 1;
}

bool sy_cluster_cli_getopt(int c, const char *value, sy_cluster_cli_opts *o)
{
    if (c == SY_CLUSTER_OPT_CLUSTER) o->cluster = value; /* refused by sy_cluster_cli_setup */
    return c >= SY_CLUSTER_OPT_CLUSTER && c <= SY_CLUSTER_OPT_PIXELS;
}

sy_result sy_cluster_cli_mpi_start(sy_cluster_cli_opts *o, bool *served, sy_error *err)
{
    (void)o;
    *served = false;
    return sy_error_set(err, SY_ERR_UNSUPPORTED, "--cluster mpi: %s", SY_NO_CLUSTER);
}

void sy_cluster_cli_mpi_end(void) {}

sy_result sy_cluster_cli_setup(const sy_cluster_cli_opts *o, const char *backend, const char *params, char *params_out,
                               size_t len, uint32_t *mode_out, uint32_t *servers_out, sy_cluster_rect *viewer_tile,
                               sy_error *err)
{
    (void)backend, (void)params, (void)params_out, (void)len, (void)mode_out, (void)servers_out, (void)viewer_tile;
    return sy_error_set(err, SY_ERR_UNSUPPORTED, "--cluster %s: %s", o->cluster ? o->cluster : "", SY_NO_CLUSTER);
}

sy_result sy_cluster_cli_params(const sy_cluster_cli_opts *o, const char *backend, uint32_t mode, const char *params,
                                char *out, size_t len, sy_error *err)
{
    (void)o, (void)backend, (void)mode, (void)params, (void)out, (void)len;
    return sy_error_set(err, SY_ERR_UNSUPPORTED, "%s", SY_NO_CLUSTER);
}

void sy_cluster_cli_last_frame(const sy_context *ctx, sy_cluster_frame_stats *stats, uint32_t *mode)
{
    (void)ctx;
    *stats = (sy_cluster_frame_stats){0};
    if (mode) *mode = 0;
}

const char *sy_cluster_cli_mode_name(uint32_t mode)
{
    (void)mode;
    return "none";
}

sy_result sy_cluster_cli_render_frames(const sy_cluster_cli_opts *o, sy_scene *scene, const sy_cluster_frames_job *job,
                                       sy_cluster_frames_stats *stats, uint32_t *servers_out, sy_error *err)
{
    (void)o, (void)scene, (void)job, (void)stats;
    *servers_out = 0;
    return sy_error_set(err, SY_ERR_UNSUPPORTED, "--cluster-mode frames: %s", SY_NO_CLUSTER);
}
