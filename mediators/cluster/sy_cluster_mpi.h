/** @file
 * sy_cluster_mpi.h — the MPI transport of the cluster (Open MPI; mpirun, or Slurm's srun with
 * PMIx): rank 0 is the client, every other rank a render server. Streams are MPI point-to-point
 * messages between two ranks under a tag of their own (a connection request on a control tag
 * first); the cluster protocol above is unchanged. Authentication relies on the launcher's trust:
 * rank 0 draws a random job secret and broadcasts it, so the protocol's HMAC handshake and frame
 * tags run as on sockets without a secret file.
 *
 * URLs: "mpi://R" dials rank R; "mpi://" listens for connections from any rank.
 *
 * Typical use (sy render ... --cluster mpi does this):
 *   sy_cluster_mpi_init(&rank, &size, &err);       every rank, before anything else uses MPI
 *   sy_cluster_mpi_job_secret(secret, &err);       every rank (a collective)
 *   rank > 0: sy_cluster_mpi_serve(&server_opts, secret, 32, &err);   returns when rank 0 releases
 *   rank 0:   render with URLs sy_cluster_mpi_urls(), then sy_cluster_mpi_release()
 *   every rank: sy_cluster_mpi_finalize()
 *
 * Ownership: plain values. Thread-safety: MPI runs with MPI_THREAD_MULTIPLE (init fails where the
 * library cannot provide it); init, release and finalize are called from the main thread. */
#ifndef SY_CLUSTER_MPI_H
#define SY_CLUSTER_MPI_H

#include "sy_cluster.h"

#ifdef __cplusplus
extern "C" {
#endif

/** True when this process was started by an MPI launcher (mpirun / mpiexec / srun): its
 * environment names a rank. Safe before init. */
bool sy_cluster_mpi_launched(void);

/** Initialises MPI (MPI_THREAD_MULTIPLE) and registers the "mpi" transport. Fails with the reason
 * when MPI cannot start or offers less than MPI_THREAD_MULTIPLE. */
sy_result sy_cluster_mpi_init(int *rank, int *size, sy_error *err);

/** Collective: rank 0 draws 32 random bytes and every rank receives them. */
sy_result sy_cluster_mpi_job_secret(uint8_t secret[32], sy_error *err);

/** A server rank: serves rank 0 (listen URL "mpi://", the given secret, the rest of opts as given)
 * until rank 0 calls sy_cluster_mpi_release. */
sy_result sy_cluster_mpi_serve(const sy_cluster_server_opts *opts, const uint8_t *secret, size_t secret_len,
                               sy_error *err);

/** Rank 0: "mpi://1,mpi://2,...,mpi://N-1" into buf (false when it does not fit). */
bool sy_cluster_mpi_urls(char *buf, size_t len);

/** Rank 0, after its clients are gone: lets the server ranks' sy_cluster_mpi_serve return. */
void sy_cluster_mpi_release(void);

/** Calls MPI_Finalize if MPI was initialised and is not finalised yet. */
void sy_cluster_mpi_finalize(void);

#ifdef __cplusplus
}
#endif
#endif /* SY_CLUSTER_MPI_H */
