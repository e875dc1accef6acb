/* web_soak.c — the `sy web` soak of issue 32 (item 6), outside ctest: one `sy web` server process on
 * loopback, VIEWERS WebSocket viewers dragging the view as fast as it answers (each drag waits for
 * the frame that answers it) and one still image (GET /api/frame.jpg) a second, for SECONDS. Every
 * 10 s the server's resident memory, open descriptors and threads are printed (from /proc). Exit 0
 * when every drag was answered, every still came back (200, a JPEG) and each of the three grew by
 * less than 5 % from the end of the warm-up (60 s, or a tenth of a shorter soak) to the end.
 *
 *   web_soak SY [SECONDS (600)] [VIEWERS (4)] [BACKEND (raster)] [SCENE (demo)] [STILLS (1: one a second, 0: none)]
 *
 * docs/TESTING.md, "Soak". Single file on purpose: a test program, not a library. */
#define _GNU_SOURCE
#include "sy_web_client.h"

#include <arpa/inet.h>
#include <dirent.h>
#include <errno.h>
#include <netinet/in.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

static uint16_t g_port;
static double g_end;
static atomic_ullong g_drags, g_answered, g_drag_failures, g_stills, g_still_failures;

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static void *viewer(void *arg)
{
    unsigned k = (unsigned)(uintptr_t)arg;
    sy_web_client *c = NULL;
    sy_error err = {0};
    char origin[32]; /* as the server's own page sends it */
    snprintf(origin, sizeof origin, "127.0.0.1:%u", (unsigned)g_port);
    sy_web_client_opts o = {.host = "127.0.0.1", .port = g_port, .path = "/ws", .origin = origin};
    if (sy_web_client_connect(&o, 30000, &c, &err) != SY_OK ||
        sy_web_client_send(c, "{\"t\":\"size\",\"w\":480,\"h\":270,\"v\":3}", &err) != SY_OK) {
        fprintf(stderr, "web_soak: viewer %u: %s\n", k, err.message);
        atomic_fetch_add(&g_drag_failures, 1);
        sy_web_client_close(c);
        return NULL;
    }
    for (uint64_t id = 1; now() < g_end; ++id) {
        char m[96];
        snprintf(m, sizeof m, "{\"t\":\"drag\",\"dx\":%d,\"dy\":%d,\"id\":%llu}", (id & 1) ? 7 : -5, (id & 2) ? 2 : -2,
                 (unsigned long long)id);
        atomic_fetch_add(&g_drags, 1);
        sy_result r = sy_web_client_send(c, m, &err);
        sy_web_frame_info fi = {0};
        while (r == SY_OK) { /* the frame answering this drag (earlier frames may come first) */
            r = sy_web_client_next_frame(c, 60000, &fi, NULL, NULL, &err);
            if (r == SY_OK && fi.input_id >= id) break;
        }
        if (r != SY_OK) {
            fprintf(stderr, "web_soak: viewer %u, drag %llu: %s\n", k, (unsigned long long)id, err.message);
            atomic_fetch_add(&g_drag_failures, 1);
            break;
        }
        atomic_fetch_add(&g_answered, 1);
    }
    sy_web_client_close(c);
    return NULL;
}

/* One GET of a still over a fresh connection: true for a 200 with a JPEG body. */
static bool still(void)
{
    int fd = socket(AF_INET, SOCK_STREAM, 0);
    if (fd < 0) return false;
    struct sockaddr_in a = {.sin_family = AF_INET, .sin_port = htons(g_port)};
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    struct timeval tv = {60, 0};
    setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    char req[256];
    int n = snprintf(req, sizeof req,
                     "GET /api/frame.jpg?w=320&h=240 HTTP/1.1\r\nHost: 127.0.0.1:%u\r\nOrigin: http://127.0.0.1:%u\r\n"
                     "Connection: close\r\n\r\n",
                     (unsigned)g_port, (unsigned)g_port);
    bool ok = connect(fd, (struct sockaddr *)&a, sizeof a) == 0 && write(fd, req, (size_t)n) == n;
    static char buf[1 << 20];
    size_t got = 0;
    while (ok && got < sizeof buf) {
        ssize_t k = read(fd, buf + got, sizeof buf - got);
        if (k < 0 && errno == EINTR) continue;
        if (k <= 0) break;
        got += (size_t)k;
    }
    close(fd);
    if (!ok || got < 16 || strncmp(buf, "HTTP/1.1 200", 12) != 0) return false;
    const char *body = memmem(buf, got, "\r\n\r\n", 4);
    return body && (size_t)(body + 4 - buf) + 2 < got && (unsigned char)body[4] == 0xff && (unsigned char)body[5] == 0xd8;
}

static void *stills(void *arg)
{
    (void)arg;
    double next = now();
    while (now() < g_end) {
        atomic_fetch_add(&g_stills, 1);
        if (!still()) {
            atomic_fetch_add(&g_still_failures, 1);
            fprintf(stderr, "web_soak: still %llu failed\n", (unsigned long long)atomic_load(&g_stills));
        }
        next += 1.0;
        double wait = next - now();
        if (wait > 0) {
            struct timespec ts = {(time_t)wait, (long)((wait - (double)(time_t)wait) * 1e9)};
            nanosleep(&ts, NULL); /* the load's own pace (one still a second), not a synchronisation */
        }
    }
    return NULL;
}

typedef struct sample {
    double rss_mb;
    long fds, threads;
} sample;

static bool probe(pid_t pid, sample *s)
{
    char path[64], line[256];
    snprintf(path, sizeof path, "/proc/%d/status", (int)pid);
    FILE *f = fopen(path, "r");
    if (!f) return false;
    s->rss_mb = 0;
    s->threads = 0;
    while (fgets(line, sizeof line, f)) {
        long v;
        if (sscanf(line, "VmRSS: %ld kB", &v) == 1) s->rss_mb = (double)v / 1024.0;
        if (sscanf(line, "Threads: %ld", &v) == 1) s->threads = v;
    }
    fclose(f);
    snprintf(path, sizeof path, "/proc/%d/fd", (int)pid);
    DIR *d = opendir(path);
    if (!d) return false;
    s->fds = 0;
    for (struct dirent *e; (e = readdir(d));)
        if (e->d_name[0] != '.') s->fds++;
    closedir(d);
    return true;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: web_soak SY [SECONDS (600)] [VIEWERS (4)] [BACKEND (raster)] [SCENE (demo)] [STILLS (1)]\n");
        return 2;
    }
    const char *sy = argv[1];
    double seconds = argc > 2 ? atof(argv[2]) : 600.0;
    unsigned viewers = argc > 3 ? (unsigned)atoi(argv[3]) : 4u;
    const char *backend = argc > 4 ? argv[4] : "raster", *scene = argc > 5 ? argv[5] : "demo";
    bool with_stills = argc > 6 ? atoi(argv[6]) != 0 : true;
    if (!(seconds >= 10) || viewers < 1 || viewers > 64) {
        fprintf(stderr, "web_soak: SECONDS >= 10, 1 <= VIEWERS <= 64\n");
        return 2;
    }
    int out[2];
    if (pipe(out) != 0) return perror("web_soak: pipe"), 1;
    pid_t pid = fork();
    if (pid < 0) return perror("web_soak: fork"), 1;
    if (pid == 0) {
        dup2(out[1], 1);
        close(out[0]);
        close(out[1]);
        execl(sy, "sy", "web", scene, "-b", backend, "--listen", "127.0.0.1:0", (char *)NULL);
        perror("web_soak: exec sy");
        _exit(127);
    }
    close(out[1]);
    /* the URL it prints: "... open http://127.0.0.1:PORT/" */
    FILE *so = fdopen(out[0], "r");
    char line[1024];
    while (!g_port && so && fgets(line, sizeof line, so)) {
        const char *u = strstr(line, "http://127.0.0.1:");
        if (u) g_port = (uint16_t)atoi(u + strlen("http://127.0.0.1:"));
    }
    if (!g_port) {
        fprintf(stderr, "web_soak: sy web printed no loopback URL\n");
        kill(pid, SIGKILL);
        waitpid(pid, NULL, 0);
        return 1;
    }
    printf("web_soak: sy web %s -b %s on port %u (pid %d), %u viewers dragging and 1 still/s for %.0f s (load: ",
           scene, backend, (unsigned)g_port, (int)pid, viewers, seconds);
    FILE *la = fopen("/proc/loadavg", "r");
    if (la && fgets(line, sizeof line, la)) printf("%.14s", line);
    if (la) fclose(la);
    printf(")\n");
    fflush(stdout);
    double start = now(), warm = seconds >= 600 ? 60 : seconds / 10;
    g_end = start + seconds;
    pthread_t th[65];
    for (unsigned k = 0; k < viewers; ++k) pthread_create(&th[k], NULL, viewer, (void *)(uintptr_t)k);
    if (with_stills) pthread_create(&th[viewers], NULL, stills, NULL);
    sample base = {0}, last = {0}, peak = {0};
    bool have_base = false, alive = true;
    for (double t = start + 10; alive && t <= g_end - 1.0; t += 10) { /* the last one while the load runs */
        while (now() < t) {
            struct timespec ts = {0, 200 * 1000 * 1000};
            nanosleep(&ts, NULL); /* the sampling pace */
        }
        alive = probe(pid, &last);
        if (!alive) break;
        if (!have_base && now() - start >= warm) base = last, have_base = true;
        if (last.rss_mb > peak.rss_mb) peak.rss_mb = last.rss_mb;
        printf("  %4.0f s  rss %7.1f MB  fds %3ld  threads %3ld  drags answered %llu  stills %llu\n", now() - start,
               last.rss_mb, last.fds, last.threads, (unsigned long long)atomic_load(&g_answered),
               (unsigned long long)atomic_load(&g_stills) - atomic_load(&g_still_failures));
        fflush(stdout);
    }
    for (unsigned k = 0; k < viewers + (with_stills ? 1u : 0u); ++k) pthread_join(th[k], NULL);
    kill(pid, SIGTERM);
    int status = 0;
    waitpid(pid, &status, 0);
    if (so) fclose(so);
    unsigned long long drags = atomic_load(&g_drags), answered = atomic_load(&g_answered),
                       dfail = atomic_load(&g_drag_failures), st = atomic_load(&g_stills),
                       sfail = atomic_load(&g_still_failures);
    double grow_rss = have_base && base.rss_mb > 0 ? last.rss_mb / base.rss_mb - 1 : 1,
           grow_fds = have_base && base.fds > 0 ? (double)last.fds / (double)base.fds - 1 : 1,
           grow_thr = have_base && base.threads > 0 ? (double)last.threads / (double)base.threads - 1 : 1;
    printf("web_soak: %.0f s: drags %llu sent, %llu answered, %llu viewer failures; stills %llu, %llu failed\n",
           now() - start, drags, answered, dfail, st, sfail);
    printf("web_soak: after the %.0f s warm-up: rss %.1f -> %.1f MB (%+.2f %%, peak %.1f), fds %ld -> %ld (%+.2f %%), "
           "threads %ld -> %ld (%+.2f %%); server %s\n",
           warm, base.rss_mb, last.rss_mb, 100 * grow_rss, peak.rss_mb, base.fds, last.fds, 100 * grow_fds,
           base.threads, last.threads, 100 * grow_thr, alive ? "alive until the end" : "GONE");
    bool ok = alive && have_base && dfail == 0 && sfail == 0 && answered > 0 && drags - answered <= viewers &&
              grow_rss < 0.05 && grow_fds < 0.05 && grow_thr < 0.05;
    printf("web_soak: %s\n", ok ? "PASS" : "FAIL");
    return ok ? 0 : 1;
}
