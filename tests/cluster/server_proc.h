/* server_proc.h — render servers as child processes for the cluster tests (header-only): start
 * test_cluster_server on a free 127.0.0.1 port (it writes the port to a file; --max-lifetime 600 s
 * only for servers a killed test leaves behind), stop it with
 * SIGTERM (SIGKILL after 5 s), search its log, read its memory from /proc/PID/status, wait for
 * the bytes it holds for peers' messages in flight (its --memory-file).
 * The caller sets g_exe (the server executable) and g_dir (a work directory). Every wait is
 * bounded; servers a failed check left running are killed when the test exits. Thread-safety:
 * main thread only. A server's memory: sy_bench_proc_status_kb (apps/sy/sy_bench_os.h, any thread). */
#ifndef SY_TEST_SERVER_PROC_H
#define SY_TEST_SERVER_PROC_H

#include "../../apps/sy/sy_bench_os.h"
#include "../support/sy_check.h"

#include <fcntl.h>
#include <signal.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

static const char *g_exe, *g_dir;
static int g_serial;
static pid_t g_started[256]; /* every server started, killed at exit if a failed check left it running */
static int g_nstarted;

static void kill_leftover_servers(void)
{
    for (int i = 0; i < g_nstarted; ++i)
        if (g_started[i] > 0 && kill(g_started[i], SIGKILL) == 0) waitpid(g_started[i], NULL, 0);
}

typedef struct server {
    pid_t pid;
    int port;
    int serial;
    char url[64];
    char log[512];
    char memory[512]; /* its --memory-file: "USED PEAK" bytes of peer memory (wait_peer_memory) */
} server;

/* The start of a cluster test's main: argv[1] the server executable (g_exe), argv[2] the work
 * directory (g_dir, created), SIGPIPE ignored (a server that went away is an error code, not a
 * signal). Returns 0, or 2 after printing "usage: NAME SERVER_EXE WORK_DIR MORE" when either is
 * missing. */
static inline int server_proc_setup(int argc, char **argv, const char *name, const char *more)
{
    if (argc < 3) {
        fprintf(stderr, "usage: %s SERVER_EXE WORK_DIR%s\n", name, more);
        return 2;
    }
    g_exe = argv[1];
    g_dir = argv[2];
    mkdir(g_dir, 0755);
    signal(SIGPIPE, SIG_IGN);
    return 0;
}

static inline void sleep_ms(int ms)
{
    struct timespec ts = {ms / 1000, (long)(ms % 1000) * 1000000L};
    nanosleep(&ts, NULL);
}

/* port 0 = any free port; extra: NULL or up to 8 more "--option", "value" words, NULL-terminated.
 * *out is set from scratch (pid 0 when no server runs: stop_server is then a no-op). */
static inline int start_server_args(const char *secret, int port, const char *const *extra, server *out)
{
    memset(out, 0, sizeof *out);
    char pf[512], listen[64];
    snprintf(pf, sizeof pf, "%s/port%d", g_dir, ++g_serial);
    snprintf(out->log, sizeof out->log, "%s/server%d.log", g_dir, g_serial);
    snprintf(out->memory, sizeof out->memory, "%s/memory%d", g_dir, g_serial);
    unlink(out->memory);
    snprintf(listen, sizeof listen, "tcp://127.0.0.1:%d", port);
    unlink(pf);
    pid_t pid = fork();
    CHECK(pid >= 0);
    if (pid == 0) {
        int fd = open(out->log, O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (fd >= 0) dup2(fd, 2), dup2(fd, 1); /* never the test's own pipes */
        char present[512];
        snprintf(present, sizeof present, "%s/present%d.raw", g_dir, g_serial);
        /* the lifetime only ends servers a killed test left behind: longer than any cluster test's
         * ctest TIMEOUT (600 s), never a deadline a slow run can reach (at 120 s, cluster_net's
         * servers under ASan on a loaded machine stopped before its last group) */
        const char *args[32] = {g_exe,     "--port-file", pf,      "--listen",      listen,     "--max-lifetime",
                                "900",     "--present",   present, "--memory-file", out->memory};
        int n = 11;
        if (secret) args[n++] = "--secret", args[n++] = secret;
        for (int k = 0; extra && extra[k] && k < 16; ++k) args[n++] = extra[k];
        execv(g_exe, (char *const *)args);
        _exit(127);
    }
    out->pid = pid;
    out->serial = g_serial;
    if (g_nstarted == 0) atexit(kill_leftover_servers);
    if (g_nstarted < (int)(sizeof g_started / sizeof g_started[0])) g_started[g_nstarted++] = pid;
    for (int i = 0; i < 6000; ++i) { /* until the port is written or the server exits; 300 s: a hang guard */
        int p = sy_bench_read_port_file(pf);
        if (p > 0) {
            out->port = p;
            snprintf(out->url, sizeof out->url, "tcp://127.0.0.1:%d", p);
            return 0;
        }
        int st;
        if (waitpid(pid, &st, WNOHANG) == pid) {
            fprintf(stderr, "server exited early, see %s\n", out->log);
            out->pid = 0;
            return 1;
        }
        sleep_ms(50);
    }
    fprintf(stderr, "server did not report its port\n");
    return 1;
}

static inline int start_server(const char *secret, int port, server *out)
{
    return start_server_args(secret, port, NULL, out);
}

static inline void forget_server(pid_t pid);

static inline void stop_server(server *s)
{
    if (s->pid <= 0) return;
    forget_server(s->pid);
    kill(s->pid, SIGCONT);
    kill(s->pid, SIGTERM);
    for (int i = 0; i < 100; ++i) {
        if (waitpid(s->pid, NULL, WNOHANG) == s->pid) {
            s->pid = 0;
            return;
        }
        sleep_ms(50);
    }
    kill(s->pid, SIGKILL);
    waitpid(s->pid, NULL, 0);
    s->pid = 0;
}

/* a stopped server's pid is forgotten by the exit handler (a reused pid is never killed) */
static inline void forget_server(pid_t pid)
{
    for (int i = 0; i < g_nstarted; ++i)
        if (g_started[i] == pid) g_started[i] = 0;
}

/* The server's peer memory from its --memory-file: bytes held now and the most ever; false while
 * the file is not written yet. */
static inline bool read_peer_memory(const server *s, size_t *used, size_t *peak)
{
    FILE *f = fopen(s->memory, "r");
    if (!f) return false;
    size_t u = 0, p = 0;
    bool ok = fscanf(f, "%zu %zu", &u, &p) == 2;
    fclose(f);
    if (ok) *used = u, *peak = p;
    return ok;
}

/* Waits until the server holds at least (at_least) or at most (!at_least) `bytes` for peers'
 * messages in flight (its --memory-file); false after 300 s (a hang guard) or when the server is
 * gone. *used_out: the last value read. The file is written by a thread that polls every 2 ms, so
 * on a loaded machine a value can be stale: a test that waits for new reservations first waits
 * for the old ones to be seen released (wait_peer_memory_at_most), or a stale value passes. */
static inline bool wait_peer_memory_cmp(const server *s, bool at_least, size_t bytes, size_t *used_out)
{
    size_t used = 0, peak = 0;
    bool ok = false;
    for (int i = 0; i < 60000; ++i) {
        ok = read_peer_memory(s, &used, &peak) && (at_least ? used >= bytes : used <= bytes);
        if (ok) break;
        if (s->pid <= 0 || waitpid(s->pid, NULL, WNOHANG) == s->pid) break;
        sleep_ms(5);
    }
    if (used_out) *used_out = used;
    return ok;
}

static inline bool wait_peer_memory(const server *s, size_t bytes, size_t *used_out)
{
    return wait_peer_memory_cmp(s, true, bytes, used_out);
}

static inline bool wait_peer_memory_at_most(const server *s, size_t bytes, size_t *used_out)
{
    return wait_peer_memory_cmp(s, false, bytes, used_out);
}

static inline bool log_contains(const server *s, const char *needle)
{
    for (int i = 0; i < 6000; ++i) { /* the server may still be writing (300 s: a hang guard; 2 s was too
                                        * short on a loaded machine) */
        FILE *f = fopen(s->log, "r");
        if (f) {
            static char buf[1 << 18];
            size_t n = fread(buf, 1, sizeof buf - 1, f);
            fclose(f);
            buf[n] = 0;
            if (strstr(buf, needle)) return true;
        }
        sleep_ms(50);
    }
    return false;
}

#endif /* SY_TEST_SERVER_PROC_H */
