/* sy_cluster_cli_mpi.c — `--cluster mpi` of `sy render` under mpirun / srun (see sy_cluster_cli.h):
 * rank 0 is the client, every other rank a server (mediators/cluster/sy_cluster_mpi.h); a build
 * without MPI (no SY_HAVE_MPI) says so. */
#include "sy_cluster_cli.h"
#ifdef SY_HAVE_MPI
#include "sy_cluster_mpi.h"
#include <sodium.h>
#endif

#ifdef SY_HAVE_MPI
static int g_mpi_role; /* 0: MPI not started, 1: rank 0 (client), 2: a server rank that has served */
static uint8_t g_mpi_secret[32];
static char g_mpi_urls[SY_CLUSTER_MAX_SERVERS * 16];

sy_result sy_cluster_cli_mpi_start(sy_cluster_cli_opts *o, bool *served, sy_error *err)
{
    *served = false;
    if (!sy_cluster_mpi_launched())
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                            "--cluster mpi: start sy under an MPI launcher (mpirun -np N sy render ... or srun)");
    int rank = 0, size = 0;
    sy_result r = sy_cluster_mpi_init(&rank, &size, err);
    if (r == SY_OK) r = sy_cluster_mpi_job_secret(g_mpi_secret, err); /* collective: before any refusal */
    if (r == SY_OK && (size < 2 || size - 1 > (int)SY_CLUSTER_MAX_SERVERS))
        r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "--cluster mpi: %d ranks; 2..%u are needed (rank 0 + servers)",
                         size, SY_CLUSTER_MAX_SERVERS + 1);
    if (r != SY_OK) {
        g_mpi_role = 1; /* the other ranks wait for the release */
        return r;
    }
    if (rank > 0) {
        sy_cluster_server_opts so = {.name = "sy render --cluster mpi"};
        r = sy_cluster_mpi_serve(&so, g_mpi_secret, sizeof g_mpi_secret, err);
        sodium_memzero(g_mpi_secret, sizeof g_mpi_secret);
        sy_cluster_mpi_finalize();
        g_mpi_role = 2;
        *served = true;
        return r;
    }
    g_mpi_role = 1;
    sy_cluster_mpi_urls(g_mpi_urls, sizeof g_mpi_urls);
    o->cluster = g_mpi_urls;
    o->secret = g_mpi_secret;
    o->secret_len = sizeof g_mpi_secret;
    return SY_OK;
}

void sy_cluster_cli_mpi_end(void)
{
    if (g_mpi_role != 1) return;
    sy_cluster_mpi_release();
    sy_cluster_mpi_finalize();
    sodium_memzero(g_mpi_secret, sizeof g_mpi_secret);
    g_mpi_role = 0;
}
#else
sy_result sy_cluster_cli_mpi_start(sy_cluster_cli_opts *o, bool *served, sy_error *err)
{
    (void)o;
    *served = false;
    return sy_error_set(err, SY_ERR_UNSUPPORTED, "--cluster mpi: this sy was built without MPI (libopenmpi-dev)");
}
void sy_cluster_cli_mpi_end(void) {}
#endif
