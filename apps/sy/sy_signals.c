/* sy_signals.c — interrupts of the sy tool (see sy_signals.h). */
#include "sy_signals.h"

#include "sy_file.h"
#include "sy_testpoint.h"

#include <pthread.h>
#include <sched.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

static volatile int g_stop;
static _Atomic(const char *) g_graceful;
static atomic_int g_count;

static sigset_t g_set; /* the signals taken: SIGINT, SIGTERM, SIGHUP, less those ignored at start */
static atomic_int g_running; /* the waiter has started (sy_signals_start returns only then) */

static void sig_set(sigset_t *set)
{
    sigemptyset(set);
    static const int sigs[] = {SIGINT, SIGTERM, SIGHUP};
    for (size_t i = 0; i < sizeof sigs / sizeof sigs[0]; ++i) {
        /* a signal the parent ignores stays ignored (a shell's background job ignores SIGINT) */
        struct sigaction old;
        if (sigaction(sigs[i], NULL, &old) == 0 && old.sa_handler == SIG_IGN) continue;
        sigaddset(set, sigs[i]);
    }
}

static void *waiter(void *arg)
{
    (void)arg;
    atomic_store(&g_running, 1);
    for (;;) {
        int sig = 0;
        if (sigwait(&g_set, &sig) != 0) continue;
        const char *what = atomic_load(&g_graceful);
        if (atomic_fetch_add(&g_count, 1) == 0 && what) {
            g_stop = 1;
            fprintf(stderr, "\nsy: %s: %s (interrupt again to abort)\n", strsignal(sig), what);
            sy_testpoint("interrupted"); /* tests wait for it before a second interrupt */
            continue;
        }
        size_t removed = sy_atomic_file_cancel_all();
        fprintf(stderr, "\nsy: %s: aborted%s\n", strsignal(sig),
                removed ? "; the unfinished output file was removed" : "");
        /* end by the signal itself, so the parent sees how the process ended */
        signal(sig, SIG_DFL);
        sigset_t one;
        sigemptyset(&one);
        sigaddset(&one, sig);
        pthread_sigmask(SIG_UNBLOCK, &one, NULL);
        raise(sig);
        _exit(128 + sig);
    }
    return NULL;
}

bool sy_signals_start(void)
{
    sig_set(&g_set);
    sigset_t set = g_set;
    if (pthread_sigmask(SIG_BLOCK, &set, NULL) != 0) return false;
    pthread_attr_t attr;
    pthread_t th;
    bool ok = pthread_attr_init(&attr) == 0;
    if (ok) {
        pthread_attr_setdetachstate(&attr, PTHREAD_CREATE_DETACHED);
        pthread_attr_setstacksize(&attr, 64 * 1024);
        ok = pthread_create(&th, &attr, waiter, NULL) == 0;
        pthread_attr_destroy(&attr);
    }
    if (!ok) pthread_sigmask(SIG_UNBLOCK, &set, NULL);
    /* wait until the waiter runs: a thread still starting may hold the allocator's lock (the
     * sanitizers' allocator takes one to set the thread up), and a fork at that moment (sy bench
     * memory, sy bench load, the Assimp loader's isolation) copies the lock held into a child that
     * has no thread to release it: the child hung in its first allocation (3 of 30 runs of
     * `sy bench memory --tris 2000` under ASan) */
    while (ok && !atomic_load(&g_running)) sched_yield();
    return ok;
}

void sy_signals_set_graceful(const char *what)
{
    atomic_store(&g_graceful, what);
}

bool sy_signals_interrupted(void)
{
    return g_stop != 0;
}

volatile int *sy_signals_stop_flag(void)
{
    return &g_stop;
}
