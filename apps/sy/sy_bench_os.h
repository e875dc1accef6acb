/* sy_bench_os.h — the operating-system measurements and connections that the benchmarks of
 * `sy bench` and the tests measuring the same things share (header-only, libc and POSIX alone, so a
 * test includes it without linking the sy program): a process's memory from /proc. Every function
 * may be called from any thread; nothing is kept between calls. */
#ifndef SY_BENCH_OS_H
#define SY_BENCH_OS_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
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

#endif /* SY_BENCH_OS_H */
