/* sy_bench_cluster_servers.c — the `sy serve` child processes of `sy bench cluster` (started from
 * this very executable on loopback, pinned to a core where asked), the client rig its measurements
 * talk to them with (see sy_bench_cluster.h; a process's memory: sy_bench_os.h). */
#define _GNU_SOURCE /* sched_setaffinity for the pinned benchmark servers */
#include "sy_bench_cluster.h"
#include "sy_bench_os.h"

#include <errno.h>
#include <fcntl.h>
#include <sched.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

/* Starts `sy serve` on a free loopback port, pinned to cpu (or unpinned when cpu < 0), for at most
 * lifetime_s seconds; one_core: llvmpipe draws on one thread (LP_NUM_THREADS=1). */
sy_result sy_bench_cluster_spawn_ex(int cpu, int lifetime_s, bool one_core, sy_bench_cluster_server *out,
                                    sy_error *err)
{
    char port_file[] = "/tmp/sy_bench_portXXXXXX";
    int fd = mkstemp(port_file);
    if (fd < 0) return sy_error_set(err, SY_ERR_IO, "bench: mkstemp: %s", strerror(errno));
    close(fd);
    unlink(port_file);
    pid_t pid = fork();
    if (pid < 0) return sy_error_set(err, SY_ERR_IO, "bench: fork: %s", strerror(errno));
    if (pid == 0) {
        if (cpu >= 0) {
            cpu_set_t set;
            CPU_ZERO(&set);
            CPU_SET(cpu, &set);
            sched_setaffinity(0, sizeof set, &set);
        }
        int devnull = open("/dev/null", 1);
        if (devnull >= 0) dup2(devnull, 2);
        if (one_core) setenv("LP_NUM_THREADS", "1", 1);
        char life[32];
        snprintf(life, sizeof life, "%d", lifetime_s);
        execl("/proc/self/exe", "sy", "serve", "--listen", "tcp://127.0.0.1:0", "--port-file", port_file,
              "--max-lifetime", life, (char *)NULL);
        _exit(127);
    }
    for (int tries = 0; tries < 200; ++tries) { /* bounded: 10 s */
        int port = sy_bench_read_port_file(port_file);
        if (port > 0) {
            unlink(port_file);
            out->pid = pid;
            snprintf(out->url, sizeof out->url, "tcp://127.0.0.1:%d", port);
            return SY_OK;
        }
        usleep(50000);
    }
    kill(pid, SIGTERM);
    waitpid(pid, NULL, 0);
    return sy_error_set(err, SY_ERR_IO, "bench: the server did not start within 10 s");
}

sy_result sy_bench_cluster_spawn(int cpu, sy_bench_cluster_server *out, sy_error *err)
{
    return sy_bench_cluster_spawn_ex(cpu, 600, false, out, err);
}

void sy_bench_cluster_stop(sy_bench_cluster_server *s)
{
    if (s->pid > 0) {
        kill(s->pid, SIGTERM);
        waitpid(s->pid, NULL, 0);
        s->pid = 0;
    }
}

sy_result sy_bench_cluster_rig_open(sy_scene *scene, const sy_viewport_desc *vd, const sy_cluster_client_opts *co,
                                    uint32_t w, uint32_t h, sy_bench_cluster_rig *rig, sy_error *err)
{
    memset(rig, 0, sizeof *rig);
    sy_result r = sy_window_create(w, h, &rig->win, err);
    if (r == SY_OK) r = sy_window_add_viewport(rig->win, vd, &rig->vp, err);
    if (r == SY_OK) r = sy_viewport_camera_view(rig->vp, scene, w, h, &rig->view, err);
    if (r == SY_OK) r = sy_cluster_client_create(scene, co, &rig->client, err);
    if (r == SY_OK) r = sy_layer_create(w, h, &rig->img, err);
    return r;
}

void sy_bench_cluster_rig_close(sy_bench_cluster_rig *rig)
{
    sy_layer_destroy(&rig->img);
    sy_cluster_client_destroy(rig->client);
    sy_window_destroy(rig->win);
    memset(rig, 0, sizeof *rig);
}

