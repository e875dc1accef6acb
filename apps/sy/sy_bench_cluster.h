/* sy_bench_cluster.h — what the files of `sy bench cluster` share (the command, sy_cmd_bench_cluster,
 * is in sy_cluster_cli.h; its options and default measurements in sy_bench_cluster.c): the
 * benchmark's `sy serve` child processes and the client rig that talks to them
 * (sy_bench_cluster_servers.c) and its other measurements,
 * one file each: the cooperative speed-up (sy_bench_cluster_coop.c), hostile peers
 * (sy_bench_cluster_hostile.c), the soak (sy_bench_cluster_soak.c) and the scaling model
 * (sy_bench_cluster_scale.c). Built with the cluster only (SY_WITH_CLUSTER). They print what they
 * measure (never pass/fail on time, except the soak's growth). Thread-safety: the main thread. */
#ifndef SY_BENCH_CLUSTER_H
#define SY_BENCH_CLUSTER_H

#include "sy_cluster.h"
#include "sy_demo.h"
#include "sy_viewport.h"

#include <stdbool.h>
#include <stdint.h>
#include <sys/types.h>

/* A `sy serve` started by the benchmark (this executable, on a free loopback port). */
typedef struct sy_bench_cluster_server {
    pid_t pid;
    char url[64];
} sy_bench_cluster_server;

/* Starts `sy serve` on a free loopback port, pinned to cpu (or unpinned when cpu < 0), for at most
 * lifetime_s seconds; one_core: llvmpipe draws on one thread (LP_NUM_THREADS=1). */
sy_result sy_bench_cluster_spawn_ex(int cpu, int lifetime_s, bool one_core, sy_bench_cluster_server *out,
                                    sy_error *err);
/* The same for at most 600 s, llvmpipe's threads as they come. */
sy_result sy_bench_cluster_spawn(int cpu, sy_bench_cluster_server *out, sy_error *err);
/* SIGTERM and wait; nothing when not started (pid 0). */
void sy_bench_cluster_stop(sy_bench_cluster_server *s);

/* A client of the benchmark's servers with what its frames need: a window holding a viewport of vd
 * (its camera's view at w x h), the client (opts co) and a w x h output layer. */
typedef struct sy_bench_cluster_rig {
    sy_window *win;
    sy_viewport *vp;
    sy_camera_view view;
    sy_cluster_client *client;
    sy_layer img;
} sy_bench_cluster_rig;
/* Opens all of it in that order; on failure what was opened stays in *rig for
 * sy_bench_cluster_rig_close. */
sy_result sy_bench_cluster_rig_open(sy_scene *scene, const sy_viewport_desc *vd, const sy_cluster_client_opts *co,
                                    uint32_t w, uint32_t h, sy_bench_cluster_rig *rig, sy_error *err);
/* Destroys what rig_open opened (the layer, the client, the window) and zeroes *rig. */
void sy_bench_cluster_rig_close(sy_bench_cluster_rig *rig);

/* Cooperative path tracing, 2 servers (srv[0], srv[1]; pinned: to cores 0 and 1) vs 1 in `rounds`
 * interleaved rounds, frames of about frame_s seconds on one server; pipe: pipelined, not, or both
 * alternating (sy_bench_cluster_coop.c). */
enum { SY_BENCH_COOP_PIPELINED = 0, SY_BENCH_COOP_NOT_PIPELINED = 1, SY_BENCH_COOP_AB = 2 };
sy_result sy_bench_cluster_coop(sy_scene *scene, const sy_viewport_desc *vd, const sy_bench_cluster_server *srv,
                                uint32_t rounds, bool pinned, double frame_s, int pipe, sy_error *err);
/* Server srv's memory and a client's frame time under 64 tricklers + 8 flooders that never
 * authenticate (sy_bench_cluster_hostile.c). */
sy_result sy_bench_cluster_hostile(sy_scene *scene, const sy_demo_info *d, const char *backend,
                                   const sy_bench_cluster_server *srv, sy_error *err);
/* --soak: a server of its own and a client moving the camera every frame for `seconds`, growth
 * measured after `warmup`; *passed as described in sy_bench_cluster_soak.c. */
sy_result sy_bench_cluster_soak(sy_scene *scene, const sy_demo_info *d, const char *backend, double seconds,
                                double warmup, uint32_t w, uint32_t h, bool *passed, sy_error *err);
/* --scale: 3 servers of its own, protocol cost and bytes per frame against the scaling model
 * (medians of `frames` frames; sy_bench_cluster_scale.c). */
sy_result sy_bench_cluster_scale(sy_scene *scene, const sy_demo_info *d, uint32_t frames, sy_error *err);

#endif /* SY_BENCH_CLUSTER_H */
