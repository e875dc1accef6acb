/* sy_testpoint.c — announced phases and test-only pause points (see sy_testpoint.h). */
#include "sy_testpoint.h"

#include "sy_file.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

static const char *g_phases; /* SY_TEST_PHASES, NULL when unset (set once at start) */
static const char *g_pause;  /* SY_TEST_PAUSE */
static long g_pause_seconds = 120;

static void announce(const char *phase)
{
    int fd = open(g_phases, O_WRONLY | O_APPEND | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0) {
        fprintf(stderr, "sy: warning: SY_TEST_PHASES=%s: %s\n", g_phases, strerror(errno));
        return;
    }
    char line[128];
    int n = snprintf(line, sizeof line, "%s\n", phase);
    if (n > 0 && (size_t)n < sizeof line && write(fd, line, (size_t)n) != n)
        fprintf(stderr, "sy: warning: SY_TEST_PHASES=%s: %s\n", g_phases, strerror(errno));
    close(fd);
}

void sy_testpoint(const char *phase)
{
    if (g_phases) announce(phase);
    if (!g_pause || strcmp(g_pause, phase) != 0) return;
    /* stopped: the signal-waiting thread (sy_signals.c) ends the process; this thread only waits,
     * in steps of 10 ms so that the hang guard needs no other clock */
    for (long i = 0; i < g_pause_seconds * 100; ++i) nanosleep(&(struct timespec){0, 10 * 1000 * 1000}, NULL);
    fprintf(stderr, "sy: warning: SY_TEST_PAUSE=%s: no signal came in %ld s; going on\n", phase, g_pause_seconds);
}

static void commit_hook(const char *path, const char *tmp_path)
{
    (void)path;
    (void)tmp_path;
    sy_testpoint("commit");
}

void sy_testpoint_start(void)
{
    const char *p = getenv("SY_TEST_PHASES"), *s = getenv("SY_TEST_PAUSE"), *t = getenv("SY_TEST_PAUSE_SECONDS");
    g_phases = p && *p ? p : NULL;
    g_pause = s && *s ? s : NULL;
    if (t && *t) {
        char *end;
        long v = strtol(t, &end, 10);
        if (*end == '\0' && v > 0 && v <= 86400) g_pause_seconds = v;
    }
    if (g_phases || g_pause) sy_atomic_file_set_commit_hook(commit_hook);
}
