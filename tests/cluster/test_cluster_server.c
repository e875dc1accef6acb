/* test_cluster_server.c — a render server process for the cluster tests: the built-in mediators
 * plus the "coop_test" double, served through mediators/cluster/sy_cluster_server.c exactly as `sy serve` does.
 *   test_cluster_server --port-file F [--listen URL] [--secret S] [--max-lifetime SECONDS] [--present RAW]
 *                       [--blob-cache-mb N | --blob-cache-bytes N] [--max-objects N] [--auth-backoff-ms MS]
 *                       [--max-unauthenticated N] [--handshake-timeout-ms MS] [--max-peer-memory-mb N]
 *                       [--max-frame-kb N] [--max-message-mb N] [--memory-file F]
 * Stops on SIGTERM / SIGINT or after --max-lifetime (default 120 s), so nothing outlives a test.
 * --memory-file: the bytes held for peers' messages in flight and their peak
 * (sy_cluster_server_peer_memory), "USED PEAK\n", rewritten (by rename) whenever they change, so
 * that a test waits for the server's state instead of sleeping (server_proc.h wait_peer_memory). */
#include "coop_double.h"
#include "sy_cluster.h"
#include "sy_mediators.h"

#include <pthread.h>
#include <signal.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static volatile int g_stop;

/* multi-display: the presented tile as a raw dump (u32 frame, x, y, w, h, then w*h*4 floats) */
static sy_result present_raw(void *user, uint64_t frame, const sy_layer *tile, uint32_t x, uint32_t y, uint32_t fw,
                             uint32_t fh, sy_error *err)
{
    (void)fw, (void)fh;
    const char *path = user;
    char tmp[4200];
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    FILE *f = fopen(tmp, "wb");
    uint32_t hd[5] = {(uint32_t)frame, x, y, tile->width, tile->height};
    size_t n = (size_t)tile->width * tile->height * 4;
    if (!f || fwrite(hd, 4, 5, f) != 5 || fwrite(tile->rgba, 4, n, f) != n || fclose(f) != 0 || rename(tmp, path) != 0)
        return sy_error_set(err, SY_ERR_IO, "%s: cannot write the presented tile", path);
    return SY_OK;
}
typedef struct memory_watch {
    const sy_cluster_server *server;
    const char *path;
} memory_watch;

/* --memory-file: polls the server's peer memory every 2 ms until the server stops */
static void *memory_watch_main(void *arg)
{
    const memory_watch *w = arg;
    size_t last_used = (size_t)-1, last_peak = (size_t)-1;
    char tmp[4200];
    snprintf(tmp, sizeof tmp, "%s.tmp", w->path);
    while (!g_stop) {
        size_t peak = 0, used = sy_cluster_server_peer_memory(w->server, &peak);
        if (used != last_used || peak != last_peak) {
            FILE *f = fopen(tmp, "w");
            if (f && fprintf(f, "%zu %zu\n", used, peak) > 0 && fclose(f) == 0 && rename(tmp, w->path) == 0)
                last_used = used, last_peak = peak;
            else if (f)
                fclose(f);
        }
        nanosleep(&(struct timespec){0, 2 * 1000 * 1000}, NULL);
    }
    return NULL;
}

static void on_signal(int s)
{
    (void)s;
    g_stop = 1;
}

int main(int argc, char **argv)
{
    sy_cluster_server_opts o = {.listen_url = "tcp://127.0.0.1:0", .max_lifetime_s = 120, .stop = &g_stop};
    const char *port_file = NULL, *secret = NULL, *memory_file = NULL;
    for (int i = 1; i + 1 < argc; i += 2) {
        if (!strcmp(argv[i], "--port-file")) port_file = argv[i + 1];
        else if (!strcmp(argv[i], "--listen")) o.listen_url = argv[i + 1];
        else if (!strcmp(argv[i], "--secret")) secret = argv[i + 1];
        else if (!strcmp(argv[i], "--max-lifetime")) o.max_lifetime_s = atof(argv[i + 1]);
        else if (!strcmp(argv[i], "--blob-cache-mb")) o.blob_cache_bytes = (size_t)atol(argv[i + 1]) << 20;
        else if (!strcmp(argv[i], "--blob-cache-bytes")) o.blob_cache_bytes = (size_t)atol(argv[i + 1]);
        else if (!strcmp(argv[i], "--max-objects")) o.max_objects = (uint32_t)atol(argv[i + 1]);
        else if (!strcmp(argv[i], "--auth-backoff-ms")) o.auth_backoff_ms = (uint32_t)atol(argv[i + 1]);
        else if (!strcmp(argv[i], "--max-unauthenticated")) o.max_unauthenticated = (uint32_t)atol(argv[i + 1]);
        else if (!strcmp(argv[i], "--handshake-timeout-ms")) o.handshake_timeout_ms = (uint32_t)atol(argv[i + 1]);
        else if (!strcmp(argv[i], "--max-peer-memory-mb")) o.max_peer_memory = (size_t)atol(argv[i + 1]) << 20;
        else if (!strcmp(argv[i], "--max-frame-kb")) o.max_frame = (size_t)atol(argv[i + 1]) << 10;
        else if (!strcmp(argv[i], "--max-message-mb")) o.max_message = (size_t)atol(argv[i + 1]) << 20;
        else if (!strcmp(argv[i], "--memory-file")) memory_file = argv[i + 1];
        else if (!strcmp(argv[i], "--present")) {
            o.present = present_raw;
            o.present_user = argv[i + 1];
        }
    }
    if (secret) {
        o.secret = (const uint8_t *)secret;
        o.secret_len = strlen(secret);
    }
    signal(SIGTERM, on_signal);
    signal(SIGINT, on_signal);
    signal(SIGPIPE, SIG_IGN);
    sy_error e = {0};
    if (sy_mediators_register_builtin(&e) || coop_double_register(&e)) {
        fprintf(stderr, "test_cluster_server: %s\n", e.message);
        return 2;
    }
    sy_cluster_server *s = NULL;
    if (sy_cluster_server_create(&o, &s, &e)) {
        fprintf(stderr, "test_cluster_server: %s\n", e.message);
        return 2;
    }
    if (port_file) {
        char tmp[4096];
        snprintf(tmp, sizeof tmp, "%s.tmp", port_file);
        FILE *f = fopen(tmp, "w");
        if (!f || fprintf(f, "%d\n", sy_cluster_server_port(s)) < 0 || fclose(f) != 0 || rename(tmp, port_file) != 0) {
            fprintf(stderr, "test_cluster_server: cannot write %s\n", port_file);
            sy_cluster_server_destroy(s);
            return 2;
        }
    }
    memory_watch mw = {s, memory_file};
    pthread_t watcher;
    bool watching = memory_file && pthread_create(&watcher, NULL, memory_watch_main, &mw) == 0;
    if (memory_file && !watching) fprintf(stderr, "test_cluster_server: cannot start the --memory-file thread\n");
    sy_result r = sy_cluster_server_run(s, &e);
    g_stop = 1;
    if (watching) pthread_join(watcher, NULL);
    sy_cluster_server_destroy(s);
    if (r) fprintf(stderr, "test_cluster_server: %s\n", e.message);
    return r ? 2 : 0;
}
