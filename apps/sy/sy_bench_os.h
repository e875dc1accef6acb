/* sy_bench_os.h — the operating-system measurements and connections that the benchmarks of
 * `sy bench` and the tests measuring the same things share (header-only, libc and POSIX alone, so a
 * test includes it without linking the sy program): a process's memory from /proc, a TCP connection
 * on the loopback interface, the port a server wrote to its --port-file. Every function may be called from any thread; nothing is kept between
 * calls. */
#ifndef SY_BENCH_OS_H
#define SY_BENCH_OS_H

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <sys/types.h>
#include <unistd.h>

/* A "Field:" line of /proc/PID/status in KiB (VmRSS, VmHWM, Threads, ...); -1 when unreadable. */
static inline long sy_bench_proc_status_kb(pid_t pid, const char *field)
{
    char path[64], line[256];
    snprintf(path, sizeof path, "/proc/%d/status", (int)pid);
    FILE *f = fopen(path, "r");
    if (!f) return -1;
    long kb = -1;
    size_t fl = strlen(field);
    while (fgets(line, sizeof line, f))
        if (!strncmp(line, field, fl) && line[fl] == ':') {
            kb = strtol(line + fl + 1, NULL, 10);
            break;
        }
    fclose(f);
    return kb;
}

/* Resident set of this process in KiB (/proc/self/statm), 0 when unknown. */
static inline long sy_bench_rss_now_kib(void)
{
    FILE *f = fopen("/proc/self/statm", "r");
    long size = 0, res = 0;
    if (f) {
        if (fscanf(f, "%ld %ld", &size, &res) != 2) res = 0;
        fclose(f);
    }
    return res * (sysconf(_SC_PAGESIZE) / 1024);
}

/* A TCP connection from the loopback address `from` (NULL: the kernel's choice, 127.0.0.1) to
 * 127.0.0.1:port with send / receive timeouts; -1 on failure. Linux routes all of 127/8 to the
 * loopback interface, so "127.0.0.2" is a second peer address on one machine. */
static inline int sy_bench_loopback_connect(const char *from, int port, int timeout_ms)
{
    int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (fd < 0) return -1;
    struct timeval tv = {timeout_ms / 1000, (timeout_ms % 1000) * 1000};
    setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &tv, sizeof tv);
    int one = 1;
    setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    if (from) {
        struct sockaddr_in la = {.sin_family = AF_INET, .sin_port = 0};
        if (inet_pton(AF_INET, from, &la.sin_addr) != 1 || bind(fd, (struct sockaddr *)&la, sizeof la) != 0) {
            close(fd);
            return -1;
        }
    }
    struct sockaddr_in sa = {.sin_family = AF_INET, .sin_port = htons((uint16_t)port)};
    sa.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (connect(fd, (struct sockaddr *)&sa, sizeof sa) != 0) {
        close(fd);
        return -1;
    }
    return fd;
}

/* The port number a server wrote to the file at path (sy serve --port-file); 0 while the file is
 * absent or holds no number yet. */
static inline int sy_bench_read_port_file(const char *path)
{
    FILE *f = fopen(path, "r");
    int port = 0;
    if (f) {
        if (fscanf(f, "%d", &port) != 1) port = 0;
        fclose(f);
    }
    return port;
}

#endif /* SY_BENCH_OS_H */
