/** @file
 * sy_mediator_cluster.h — the cluster as a mediator: a viewport whose back-end is a cluster class
 * renders on render servers (`sy serve`) exactly as it would render locally. The application,
 * the window, compositing, stereo, layers and the progress loop never know.
 *
 * A cluster class is registered at run time under a name (e.g. "cluster") with a connection
 * configuration: server URLs, secret, TLS CA, timeouts, a back-end per server (a raster preview
 * node beside path tracers) and wall tiles. A viewport then names it as its back-end and gives its
 * parameters:
 *   backend=NAME     the back-end the servers render with (required; a server configured with its
 *                    own back-end uses that one)
 *   mode=MODE        sort-first (default), balanced, cooperative, multi-display
 *   samples=N        cooperative: samples per render when the request gives none (default 16 per
 *                    server); a request's sample count is split across the live servers, rounded up
 *                    to a multiple of their number (every server adds to every frame, so none of
 *                    their accumulations is left out of a merged image)
 *   pixels=float|half  tiles as float32 (bit-exact, default) or binary16
 *   servers=LIST     the configured servers this viewport uses: 1-based numbers and ranges joined by
 *                    '+' ("2-4", "1+3"); default all. Mixed back-ends per node: one window with a
 *                    raster preview viewport on server 1 (servers=1,backend=raster) beside a
 *                    cooperative path trace on servers 2-4, or a wall with a back-end per display.
 * Every other key=value is handed to the servers' back-end unchanged; core checks the keys above
 * against the class's param_table, and the others against the table of each used server's back-end
 * when that class is registered in this process too (a back-end unknown here: the servers check).
 *
 * An instance: a replica of the scene fed by the change lists its context receives (so a
 * reconnecting server gets a snapshot of exactly what this context has seen) and a cluster client
 * on that replica. render() asks the servers for the request's image (strips, balanced strips,
 * sample ranges or wall tiles) and returns it as the layer; a request for a sub-rectangle renders
 * the whole image and returns the rectangle. Capabilities of an instance are those of the
 * servers' back-end as registered in this process (the same binary), filtered by the mode:
 * cooperative adds progressive accumulation and needs a back-end whose samples merge
 * (SY_CAP_SAMPLE_RANGES); set-up refuses what a node cannot do, naming the node and the reason.
 * Picks (SY_CAP_PICK, when every used server's back-end picks and the viewport's back-end is
 * registered here) are answered on the replica by a local context of the viewport's back-end
 * class, made on the first pick and synced with every frame after: the servers are not asked
 * (docs/CLUSTER.md, "Picking").
 *
 * Deadlines: the configuration's timeout_ms for every request, or, when it is 0, an adaptive one:
 * 60 s for the first frame (snapshot, first translation), then 1 s + 4x the last frame's time,
 * doubled after a failure, within 1..60 s: a dead or stalled server is dropped within about a
 * second of an interactive frame, and its work goes to the others in the same frame.
 *
 * Ownership: registration copies the configuration; the class lives until the process ends (the
 * registry holds it). Thread-safety: registration is safe from any thread; an instance is used like
 * every context (one thread at a time). */
#ifndef SY_MEDIATOR_CLUSTER_H
#define SY_MEDIATOR_CLUSTER_H

#include "sy_cluster.h"

#ifdef __cplusplus
extern "C" {
#endif

#define SY_MEDIATOR_CLUSTER_NAME "cluster" /**< the usual class name */

/** Registers a cluster class named `name` (SY_MEDIATOR_CLUSTER_NAME for the usual one) connecting
 * with opts (copied: URLs, secret, CA path, per-server back-ends and wall tiles; the log callback
 * and its user pointer are kept as given and must stay valid). Fails when the name is taken. */
sy_result sy_mediator_cluster_register(const char *name, const sy_cluster_client_opts *opts, sy_error *err);

/** The last frame's statistics of a cluster instance (sy_context_state of a context whose caps have
 * SY_CAP_REMOTE); zeroes for anything else. */
void sy_mediator_cluster_last_frame(void *state, sy_cluster_frame_stats *out);
/** The instance's mode (sy_cluster_mode) and the number of servers it uses. */
void sy_mediator_cluster_describe(void *state, uint32_t *mode, uint32_t *servers);

#ifdef __cplusplus
}
#endif
#endif /* SY_MEDIATOR_CLUSTER_H */
