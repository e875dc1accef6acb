/* sy_assimp_isolate.c — the public loads of sy_assimp.h, run in the import process: a child forked
 * for one load that runs the whole in-process load (sy_assimp.c) on its copy of the caller's scene
 * and sends back what it created as one change list, with the load's info and log lines. Assimp
 * 5.2 crashes, aborts and loops on malformed files in ways no check before it can foresee (the
 * fuzz targets keep finding new ones in its COLLADA, PLY and FBX readers); here such a file ends
 * the child, never the caller, and the caller's load fails naming the file and the signal.
 *
 * Why the ids match: the child is a copy of the caller at the fork, so the objects it creates take
 * exactly the slots the caller's scene would hand out; the change list (a consumer's pull after a
 * commit, taken in the child) creates them at those ids in the caller's scene through the replica
 * path (sy_scene_apply), which validates every value as it does for a cluster peer. The caller's
 * uncommitted changes stay uncommitted: only the child commits.
 *
 * The child touches nothing that another thread of the caller may have held locked at the fork:
 * no sy_log (its lines are kept, asp_notes, and logged here by the caller), no loader lock. Its
 * limits: CPU seconds (RLIMIT_CPU), address space (RLIMIT_AS: what it has at the fork plus 1 GiB
 * plus 1024 bytes per byte of the model, zlib's largest expansion, and at most 1 GiB plus twice the
 * scene budget: a 4.6 KB COLLADA file found by the fuzzer makes Assimp grow without end), and a
 * wall-clock bound enforced by the caller (SIGKILL). The message it sends is read within bounds derived from the budget. */
#include "sy_assimp_internal.h"

#include "sy_blob.h"
#include "sy_changes.h"
#include "sy_commit.h"
#include "sy_loader_log.h"

#include <errno.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#define ISO_MAGIC 0x49415953u /* "SYAI" */

/* AddressSanitizer (gcc 12's libasan) deadlocks in its allocator in a child forked from a process
 * with more than one thread (seen: `sy info` under ASan, whose signal thread was waiting in
 * sigwait, hung in the child's first malloc every time); glibc's malloc is fork-safe. */
#if defined(__SANITIZE_ADDRESS__)
#define ISO_SANITIZER 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define ISO_SANITIZER 1
#endif
#endif
#ifndef ISO_SANITIZER
#define ISO_SANITIZER 0
#endif
#define ISO_MAX_WARNING_BYTES (1u << 20)
#define ISO_MAX_CAMERAS (1u << 20)

/* What the child sends first; the variable parts follow in this order: camera node ids
 * (camera_count x u32), the kept warnings ([u32 length][text] each, warnings_bytes in all), the
 * log lines (asp_notes records, notes_bytes), the serialised change list (changes_bytes). */
typedef struct iso_head {
    uint32_t magic;
    int32_t result;
    char message[SY_ERROR_MESSAGE_MAX];
    sy_assimp_counts counts;
    char format[64];
    float unit_scale;
    int32_t up_axis;
    uint32_t root;
    uint32_t camera_count;
    uint32_t warning_count, stored_warning_count;
    uint32_t notes_dropped;
    uint64_t warnings_bytes, notes_bytes, changes_bytes;
} iso_head;

typedef struct iso_job {
    const char *path;
    const void *mem;
    size_t mem_size;
    const char *base_dir;
    sy_scene *scene;
    sy_assimp_options opt; /* resolved */
    uint64_t model_bytes;  /* the model's size (0 when unknown) */
    unsigned cpu_seconds, wall_seconds;
} iso_job;

/* >>child -------------------------------------------------------------------------------------- */

static bool write_all(int fd, const void *p, size_t n)
{
    const char *c = p;
    while (n) {
        ssize_t w = write(fd, c, n);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) return false;
        c += w, n -= (size_t)w;
    }
    return true;
}

/* Bytes of the process's address space now (0 when /proc does not say). */
static uint64_t address_space_bytes(void)
{
    FILE *f = fopen("/proc/self/statm", "r");
    unsigned long long pages = 0;
    if (f) {
        if (fscanf(f, "%llu", &pages) != 1) pages = 0;
        fclose(f);
    }
    long ps = sysconf(_SC_PAGESIZE);
    return pages * (uint64_t)(ps > 0 ? ps : 4096);
}

static void child_limits(const iso_job *j, pid_t parent)
{
    /* the child must not outlive a caller killed while it waits (it would hold its limits' worth
     * of memory and CPU for nothing) */
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent) _exit(4);
    static const int deadly[] = {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT, SIGXCPU, SIGPIPE, SIGTERM, SIGTRAP};
    for (size_t k = 0; k < sizeof deadly / sizeof deadly[0]; ++k) signal(deadly[k], SIG_DFL); /* not the caller's handlers */
    struct rlimit cpu = {j->cpu_seconds, (rlim_t)j->cpu_seconds + 5}; /* SIGXCPU, then SIGKILL */
    setrlimit(RLIMIT_CPU, &cpu);
    uint64_t now = address_space_bytes();
    if (now) {
        uint64_t gib = (uint64_t)1 << 30, by_model = gib + 1024 * j->model_bytes, by_budget = gib + 2 * j->opt.max_scene_bytes;
        uint64_t allow = by_model < by_budget ? by_model : by_budget;
        struct rlimit as;
        if (getrlimit(RLIMIT_AS, &as) == 0 && (as.rlim_cur == RLIM_INFINITY || as.rlim_cur > now + allow)) {
            as.rlim_cur = (rlim_t)(now + allow);
            setrlimit(RLIMIT_AS, &as);
        }
    }
}

/* The load on the child's copy of the scene, then the message; never returns. */
static void child_main(int fd, const iso_job *j, pid_t parent)
{
    child_limits(j, parent);
    iso_head h;
    memset(&h, 0, sizeof h);
    h.magic = ISO_MAGIC;
    sy_error e = {0};
    asp_notes notes = {0};
    sy_assimp_info info = {0};
    sy_changes *before = NULL, *made = NULL;
    void *wire = NULL;
    size_t wire_size = 0;
    uint32_t consumer = 0;
    /* everything before the load is sealed and pulled, so the next pull holds the load alone */
    sy_result r = sy_scene_commit(j->scene, NULL, &e);
    if (r == SY_OK) r = sy_scene_consumer_add(j->scene, &consumer, &e);
    if (r == SY_OK) r = sy_scene_consumer_pull(j->scene, consumer, &before, &e);
    if (r == SY_OK) r = asp_load_here(j->path, j->mem, j->mem_size, j->base_dir, j->scene, &j->opt, &info, &notes, &e);
    if (r == SY_OK) r = sy_scene_commit(j->scene, NULL, &e);
    if (r == SY_OK) r = sy_scene_consumer_pull(j->scene, consumer, &made, &e);
    if (r == SY_OK) r = sy_changes_serialize(made, NULL, NULL, &wire, &wire_size, &e);
    h.result = r;
    snprintf(h.message, sizeof h.message, "%s", r == SY_OK ? "" : e.message);
    if (r == SY_OK) {
        h.counts = info.counts;
        memcpy(h.format, info.format, sizeof h.format);
        h.unit_scale = info.unit_scale;
        h.up_axis = info.up_axis;
        h.root = info.root.id;
        h.camera_count = info.camera_node_count;
        h.warning_count = info.warning_count;
        h.stored_warning_count = info.stored_warning_count;
        for (uint32_t k = 0; k < info.stored_warning_count; ++k) h.warnings_bytes += 4 + strlen(info.warnings[k]);
        h.notes_bytes = notes.len;
        h.notes_dropped = notes.dropped;
        h.changes_bytes = wire_size;
    }
    bool ok = write_all(fd, &h, sizeof h);
    for (uint32_t k = 0; ok && r == SY_OK && k < info.camera_node_count; ++k) ok = write_all(fd, &info.camera_nodes[k].id, 4);
    for (uint32_t k = 0; ok && r == SY_OK && k < info.stored_warning_count; ++k) {
        uint32_t n = (uint32_t)strlen(info.warnings[k]);
        ok = write_all(fd, &n, 4) && write_all(fd, info.warnings[k], n);
    }
    if (ok && r == SY_OK && notes.len) ok = write_all(fd, notes.buf, notes.len);
    if (ok && r == SY_OK && wire_size) ok = write_all(fd, wire, wire_size);
    /* the process ends here: nothing is freed, no atexit handler runs (nor the caller's) */
    _exit(ok ? 0 : 3);
}

/* >>caller ------------------------------------------------------------------------------------- */

static double now_seconds(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + (double)t.tv_nsec * 1e-9;
}

typedef struct iso_reader {
    int fd;
    pid_t pid;
    double deadline;
    bool timed_out, eof;
} iso_reader;

/* Reads n bytes, waiting at most until the deadline; false at the end of the stream or past it. */
static bool read_exact(iso_reader *rd, void *p, size_t n)
{
    char *c = p;
    while (n) {
        double left = rd->deadline - now_seconds();
        if (left <= 0) return rd->timed_out = true, false;
        struct pollfd pf = {rd->fd, POLLIN, 0};
        int pr = poll(&pf, 1, left > 0.25 ? 250 : (int)(left * 1000) + 1);
        if (pr < 0 && errno != EINTR) return rd->eof = true, false;
        if (pr <= 0) continue;
        ssize_t got = read(rd->fd, c, n);
        if (got < 0 && (errno == EINTR || errno == EAGAIN)) continue;
        if (got <= 0) return rd->eof = true, false;
        c += got, n -= (size_t)got;
    }
    return true;
}

/* Why the child gave no (complete) message, as the load's error. */
static sy_result child_failed(const iso_job *j, const iso_reader *rd, int status, bool reaped, sy_error *err)
{
    const char *p = j->path;
    if (rd->timed_out)
        return sy_error_set(err, SY_ERR_LIMIT, "%s: the import took longer than %u s and was stopped (Assimp may loop on this file)",
                            p, j->wall_seconds);
    if (reaped && WIFSIGNALED(status)) {
        int sig = WTERMSIG(status);
        if (sig == SIGXCPU || sig == SIGKILL)
            return sy_error_set(err, SY_ERR_LIMIT,
                                "%s: the import was stopped by signal %d (%s): past its limit of %u s of CPU time or "
                                "out of memory",
                                p, sig, strsignal(sig), j->cpu_seconds);
        return sy_error_set(err, SY_ERR_PARSE,
                            "%s: Assimp crashed while importing it (signal %d, %s): the file is malformed or uses a "
                            "part of its format that Assimp mishandles",
                            p, sig, strsignal(sig));
    }
    if (reaped && WIFEXITED(status))
        return sy_error_set(err, SY_ERR_PARSE, "%s: the import process ended (status %d) without a result", p, WEXITSTATUS(status));
    return sy_error_set(err, SY_ERR_IO, "%s: the import process ended without a result", p);
}

/* Destroys what a partly applied change list created (newest first). */
static void undo_creations(sy_scene *s, const sy_changes *c)
{
    for (uint32_t i = sy_changes_count(c); i-- > 0;) {
        const sy_change *e = sy_changes_get(c, i);
        if ((e->flags & SY_CHANGE_CREATED) && sy_object_get(s, e->type, e->id)) sy_object_destroy(s, e->type, e->id, NULL);
    }
}

/* The message after the head: the info's arrays and the change list, applied to the scene. */
static sy_result take_message(const iso_job *j, const iso_head *h, const char *body, sy_assimp_info *info, sy_error *err)
{
    const char *p = j->path;
    info->counts = h->counts;
    memcpy(info->format, h->format, sizeof info->format);
    info->format[sizeof info->format - 1] = '\0';
    info->unit_scale = h->unit_scale;
    info->up_axis = h->up_axis;
    info->root.id = h->root;
    size_t at = 0;
    if (h->camera_count && !(info->camera_nodes = calloc(h->camera_count, sizeof *info->camera_nodes)))
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", p);
    info->camera_node_count = h->camera_count;
    for (uint32_t k = 0; k < h->camera_count; ++k, at += 4) memcpy(&info->camera_nodes[k].id, body + at, 4);
    size_t wend = at + h->warnings_bytes;
    if (h->stored_warning_count && !(info->warnings = calloc(h->stored_warning_count, sizeof *info->warnings)))
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", p);
    info->warning_count = h->warning_count;
    for (uint32_t k = 0; k < h->stored_warning_count; ++k) {
        uint32_t n;
        if (at + 4 > wend) return sy_error_set(err, SY_ERR_PARSE, "%s: the import process sent a short warning list", p);
        memcpy(&n, body + at, 4);
        at += 4;
        if (n > wend - at) return sy_error_set(err, SY_ERR_PARSE, "%s: the import process sent a short warning list", p);
        if (!(info->warnings[k] = malloc((size_t)n + 1))) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", p);
        memcpy(info->warnings[k], body + at, n);
        info->warnings[k][n] = '\0';
        info->stored_warning_count = k + 1;
        at += n;
    }
    at = wend;
    const char *notes = body + at;
    at += h->notes_bytes;
    sy_blob_store *store = NULL;
    sy_changes *ch = NULL;
    sy_result r = sy_blob_store_create(&store, err);
    sy_changes_limits lim = {.max_blob_bytes = (size_t)j->opt.max_scene_bytes};
    if (r == SY_OK) r = sy_changes_deserialize(body + at, h->changes_bytes, store, &lim, &ch, err);
    if (r == SY_OK) {
        r = sy_scene_apply(j->scene, ch, err);
        if (r != SY_OK) undo_creations(j->scene, ch);
    }
    if (r == SY_OK && (!sy_object_get(j->scene, SY_TYPE_NODE, info->root.id)))
        r = sy_error_set(err, SY_ERR_PARSE, "the root node %#x is not among the objects made", info->root.id);
    for (uint32_t k = 0; r == SY_OK && k < info->camera_node_count; ++k)
        if (!sy_object_get(j->scene, SY_TYPE_NODE, info->camera_nodes[k].id))
            r = sy_error_set(err, SY_ERR_PARSE, "camera node %#x is not among the objects made", info->camera_nodes[k].id);
    if (r != SY_OK && ch) undo_creations(j->scene, ch);
    sy_changes_release(ch);
    sy_blob_store_destroy(store);
    if (r != SY_OK) {
        sy_error_prefix(err, "%s: the import process's result", p);
        return r;
    }
    /* the child's log lines, then the warnings, as a load in this process logs them */
    for (size_t o = 0; o + 5 <= h->notes_bytes;) {
        uint32_t n;
        memcpy(&n, notes + o + 1, 4);
        if (n > h->notes_bytes - o - 5) break;
        sy_log((sy_log_level)(unsigned char)notes[o], "assimp", p, "%.*s", (int)n, notes + o + 5);
        o += 5 + (size_t)n;
    }
    if (h->notes_dropped) sy_log(SY_LOG_NOTE, "assimp", p, "%u more log lines of the import not shown", h->notes_dropped);
    sy_loader_warnings_log(asp_warnings(info), "assimp", p, p);
    return SY_OK;
}

static sy_result load_isolated(iso_job *j, sy_assimp_info *info, sy_error *err)
{
    const char *p = j->path;
    uint64_t mib = (j->model_bytes + ((1u << 20) - 1)) >> 20;
    j->cpu_seconds = j->opt.max_import_seconds ? j->opt.max_import_seconds : (unsigned)(60 + 10 * (mib < 100000 ? mib : 100000));
    j->wall_seconds = 2 * j->cpu_seconds + 30;
    int fds[2];
    if (pipe(fds) != 0) return sy_error_set(err, SY_ERR_IO, "%s: cannot start the import process (pipe: %s)", p, strerror(errno));
    pid_t parent = getpid(), pid = fork();
    if (pid < 0) {
        int e = errno;
        close(fds[0]), close(fds[1]);
        return sy_error_set(err, SY_ERR_IO, "%s: cannot start the import process (fork: %s)", p, strerror(e));
    }
    if (pid == 0) {
        close(fds[0]);
        child_main(fds[1], j, parent);
    }
    close(fds[1]);
    iso_reader rd = {fds[0], pid, now_seconds() + j->wall_seconds, false, false};
    iso_head h;
    char *body = NULL;
    sy_result r = SY_OK;
    bool complete = false;
    if (read_exact(&rd, &h, sizeof h)) {
        uint64_t max_changes = 2 * j->opt.max_scene_bytes + ((uint64_t)64 << 20);
        if (h.magic != ISO_MAGIC)
            r = sy_error_set(err, SY_ERR_PARSE, "%s: the import process sent no valid result", p);
        else if (h.result != SY_OK) {
            h.message[sizeof h.message - 1] = '\0';
            bool named = !strncmp(h.message, p, strlen(p)); /* the loader's errors name the file */
            r = sy_error_set(err, (sy_result)h.result, "%s%s%s", named ? "" : p, named ? "" : ": ", h.message);
            complete = true;
        } else if (h.camera_count > ISO_MAX_CAMERAS || h.warnings_bytes > ISO_MAX_WARNING_BYTES ||
                   h.stored_warning_count > SY_ASSIMP_MAX_WARNINGS || h.notes_bytes > SY_ASSIMP_NOTES_MAX ||
                   h.changes_bytes > max_changes)
            r = sy_error_set(err, SY_ERR_LIMIT, "%s: the import process's result is larger than its limits", p);
        else {
            size_t n = (size_t)h.camera_count * 4 + (size_t)h.warnings_bytes + (size_t)h.notes_bytes + (size_t)h.changes_bytes;
            if (!(body = malloc(n ? n : 1))) r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory for %zu bytes", p, n);
            else if (read_exact(&rd, body, n)) complete = true;
        }
    }
    if (rd.timed_out) kill(pid, SIGKILL);
    close(fds[0]);
    int status = 0;
    bool reaped = false;
    while (!reaped) {
        pid_t w = waitpid(pid, &status, 0);
        if (w == pid) reaped = true;
        else if (w < 0 && errno != EINTR) break; /* ECHILD: the caller ignores SIGCHLD */
    }
    if (r == SY_OK && !complete) r = child_failed(j, &rd, status, reaped, err);
    if (r == SY_OK) r = take_message(j, &h, body, info, err);
    free(body);
    return r;
}

/* Threads of this process (0 when /proc does not say). */
static unsigned thread_count(void)
{
    FILE *f = fopen("/proc/self/status", "r");
    char line[256];
    unsigned n = 0;
    while (f && fgets(line, sizeof line, f))
        if (!strncmp(line, "Threads:", 8)) n = (unsigned)strtoul(line + 8, NULL, 10);
    if (f) fclose(f);
    return n;
}

static sy_result load(const char *path, const void *mem, size_t mem_size, const char *base_dir, sy_scene *scene,
                      const sy_assimp_options *opts, sy_assimp_info *info_out, sy_error *err)
{
    bool here = (opts && opts->in_process) || (ISO_SANITIZER && thread_count() != 1);
    if (here) return asp_load_here(path, mem, mem_size, base_dir, scene, opts, info_out, NULL, err);
    sy_assimp_info local;
    sy_assimp_info *info = info_out ? info_out : &local;
    memset(info, 0, sizeof *info);
    iso_job j = {path, mem, mem_size, base_dir, scene, asp_resolve_options(opts), mem_size, 0, 0};
    struct stat st;
    if (!mem && stat(path, &st) == 0 && st.st_size > 0) j.model_bytes = (uint64_t)st.st_size;
    sy_result r = load_isolated(&j, info, err);
    if (r != SY_OK || !info_out) sy_assimp_info_free(info);
    return r;
}

sy_result sy_assimp_load(const char *path, sy_scene *scene, const sy_assimp_options *opts, sy_assimp_info *info_out,
                         sy_error *err)
{
    if (!path || !scene) {
        if (info_out) memset(info_out, 0, sizeof *info_out);
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "sy_assimp_load: path and scene are required");
    }
    return load(path, NULL, 0, NULL, scene, opts, info_out, err);
}

sy_result sy_assimp_load_memory(const void *data, size_t size, const char *name, const char *base_dir, sy_scene *scene,
                                const sy_assimp_options *opts, sy_assimp_info *info_out, sy_error *err)
{
    if (!data || !name || !base_dir || !scene) {
        if (info_out) memset(info_out, 0, sizeof *info_out);
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "sy_assimp_load_memory: data, name, base_dir and scene are required");
    }
    return load(name, data, size, base_dir, scene, opts, info_out, err);
}
