/* sy_cluster_cli.c — `sy serve`, the `--cluster` options of `sy render` and `sy bench cluster`
 * (see sy_cluster_cli.h). The protocol, the modes and the cluster mediator live in mediators/cluster/. */
#define _GNU_SOURCE /* sched_setaffinity for the pinned benchmark servers */
#include "sy_cluster_cli.h"
#include "sy_bench.h"
#include "sy_mediator_cluster.h"
#ifdef SY_HAVE_MPI
#include "sy_cluster_mpi.h"
#include <sodium.h>
#endif
#include "sy_options.h"
#include "sy_signals.h"

#include "sy_demo.h"
#include "sy_exr.h"
#include "sy_file.h"
#include "sy_log.h"
#include "sy_png.h"

#include <arpa/inet.h>
#include <errno.h>
#include <math.h>
#include <dirent.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <time.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

static bool has_suffix(const char *s, const char *suffix)
{
    size_t n = strlen(s), m = strlen(suffix);
    return n >= m && strcasecmp(s + n - m, suffix) == 0;
}

static int cli_fail(const char *cmd, const sy_error *e)
{
    (void)cmd;
    sy_log(SY_LOG_ERROR, "sy", NULL, "%s", e->message);
    return 1; /* a failure; usage errors exit 2 */
}

/* ---- sy serve ---- */
typedef struct present_ctx {
    const char *output;
} present_ctx;

static sy_result present_tile(void *user, uint64_t frame, const sy_layer *tile, uint32_t x, uint32_t y, uint32_t fw,
                              uint32_t fh, sy_error *err)
{
    present_ctx *p = user;
    if (!p->output) {
        printf("frame %llu: tile %ux%u at %u,%u of %ux%u ready (no --output)\n", (unsigned long long)frame, tile->width,
               tile->height, x, y, fw, fh);
        fflush(stdout);
        return SY_OK;
    }
    if (has_suffix(p->output, ".exr"))
        return sy_exr_write_rgba(p->output, (int)tile->width, (int)tile->height, tile->rgba, tile->depth,
                                 SY_EXR_PIXEL_FLOAT, err);
    return sy_png_write(p->output, (int)tile->width, (int)tile->height, tile->rgba, NULL, err);
}

static sy_result write_port_file(const char *path, int port, sy_error *err)
{
    sy_atomic_file af = {0};
    sy_result r = sy_atomic_file_begin(path, &af, err);
    if (r) return r;
    if (fprintf(af.fp, "%d\n", port) < 0) {
        sy_atomic_file_abort(&af);
        return sy_error_set(err, SY_ERR_IO, "%s: write failed", path);
    }
    return sy_atomic_file_commit(&af, err);
}

/* A whole decimal number in [lo, hi] (the option's value); false for anything else. */
static bool uint_arg(const char *s, unsigned long long lo, unsigned long long hi, unsigned long long *out)
{
    char *end = NULL;
    errno = 0;
    unsigned long long v = strtoull(s, &end, 10);
    if (errno || !end || end == s || *end || s[0] == '-' || v < lo || v > hi) return false;
    *out = v;
    return true;
}

/* "-w" or "--name" of option code c in a getopt_long table (for messages). */
static const char *opt_label(const struct option *lo, int c, char name[48])
{
    if (c < 0x100) {
        snprintf(name, 48, "-%c", c);
        return name;
    }
    while (lo->name && lo->val != c) ++lo;
    snprintf(name, 48, "--%s", lo->name ? lo->name : "?");
    return name;
}

int sy_cmd_serve(int argc, char **argv)
{
    sy_cluster_server_opts o = {0};
    const char *secret_file = NULL, *port_file = NULL;
    present_ctx pc = {0};
    unsigned long long v = 0;
    enum { O_LISTEN = 0x100, O_SECRET_FILE, O_OUTPUT, O_PORT_FILE, O_TLS_CERT, O_TLS_KEY, O_NAME, O_MAX_SESSIONS,
           O_MAX_LIFETIME, O_BLOB_CACHE, O_MAX_OBJECTS, O_AUTH_BACKOFF, O_PEER_MEMORY, O_FRAME_KB, O_MESSAGE_MB,
           O_UNAUTH, O_HANDSHAKE, O_HELP };
    static const struct option lo[] = {
        {"listen", required_argument, NULL, O_LISTEN}, {"secret-file", required_argument, NULL, O_SECRET_FILE},
        {"output", required_argument, NULL, O_OUTPUT}, {"port-file", required_argument, NULL, O_PORT_FILE},
        {"tls-cert", required_argument, NULL, O_TLS_CERT}, {"tls-key", required_argument, NULL, O_TLS_KEY},
        {"name", required_argument, NULL, O_NAME}, {"max-sessions", required_argument, NULL, O_MAX_SESSIONS},
        {"max-lifetime", required_argument, NULL, O_MAX_LIFETIME},
        {"blob-cache-mb", required_argument, NULL, O_BLOB_CACHE}, {"max-objects", required_argument, NULL, O_MAX_OBJECTS},
        {"auth-backoff-ms", required_argument, NULL, O_AUTH_BACKOFF},
        /* budgets against hostile peers (docs/PROTOCOL.md, "Budgets and limits") */
        {"max-peer-memory-mb", required_argument, NULL, O_PEER_MEMORY},
        {"max-frame-kb", required_argument, NULL, O_FRAME_KB}, {"max-message-mb", required_argument, NULL, O_MESSAGE_MB},
        {"max-unauthenticated", required_argument, NULL, O_UNAUTH},
        {"handshake-timeout-ms", required_argument, NULL, O_HANDSHAKE}, {"help", no_argument, NULL, O_HELP},
        {"quiet", no_argument, NULL, 'q'}, {"verbose", no_argument, NULL, 'v'}, {NULL, 0, NULL, 0}};
    static const char usage_text[] =
        "usage: sy serve [--listen tcp://HOST:PORT|tls+tcp://HOST:PORT] [--secret-file F] [--output OUT.exr|png]\n"
        "                [--port-file F] [--tls-cert PEM --tls-key PEM] [--name NAME] [--max-sessions N]\n"
        "                [--blob-cache-mb N (1024)] [--max-objects N per type (1048576)]\n"
        "                [--auth-backoff-ms MS (250, doubled per failed authentication)]\n"
        "                [--max-peer-memory-mb N (1024: all peers' messages in flight)]\n"
        "                [--max-frame-kb N (8192, 64..1048576)] [--max-message-mb N (1024)]\n"
        "                [--max-unauthenticated N (32)] [--handshake-timeout-ms MS (3000)]\n"
        "                [--max-lifetime SECONDS] [-q | -v]\n"
        "  the secret comes from --secret-file or $SY_CLUSTER_SECRET; without one only loopback is allowed\n";
    int c;
    optind = 0; /* glibc: start over (new arguments, GNU ordering) */
    opterr = 0;
    while ((c = sy_getopt(argc, argv, ":qv", lo, "sy serve")) != -1) {
        const char *opt = argv[optind - 1];
        bool ok = true;
        switch (c) {
        case SY_GETOPT_ERROR: return 2; /* an abbreviated long option (named on stderr) */
        case O_LISTEN: o.listen_url = optarg; break;
        case O_SECRET_FILE: secret_file = optarg; break;
        case O_OUTPUT: pc.output = optarg; break;
        case O_PORT_FILE: port_file = optarg; break;
        case O_TLS_CERT: o.tls_cert_file = optarg; break;
        case O_TLS_KEY: o.tls_key_file = optarg; break;
        case O_NAME: o.name = optarg; break;
        case O_MAX_SESSIONS: ok = uint_arg(optarg, 1, 65536, &v), o.max_sessions = (uint32_t)v; break;
        case O_MAX_LIFETIME: {
            char *end = NULL;
            o.max_lifetime_s = strtod(optarg, &end);
            ok = end != optarg && !*end && o.max_lifetime_s > 0 && isfinite(o.max_lifetime_s);
            break;
        }
        case O_BLOB_CACHE: ok = uint_arg(optarg, 1, 1u << 24, &v), o.blob_cache_bytes = (size_t)v << 20; break;
        case O_MAX_OBJECTS: ok = uint_arg(optarg, 1, 1u << 30, &v), o.max_objects = (uint32_t)v; break;
        case O_AUTH_BACKOFF: ok = uint_arg(optarg, 0, 3600000, &v), o.auth_backoff_ms = (uint32_t)v; break;
        case O_PEER_MEMORY: ok = uint_arg(optarg, 1, 1u << 20, &v), o.max_peer_memory = (size_t)v << 20; break;
        case O_FRAME_KB: ok = uint_arg(optarg, 64, 1u << 20, &v), o.max_frame = (size_t)v << 10; break;
        case O_MESSAGE_MB: ok = uint_arg(optarg, 1, 1u << 20, &v), o.max_message = (size_t)v << 20; break;
        case O_UNAUTH: ok = uint_arg(optarg, 1, 65536, &v), o.max_unauthenticated = (uint32_t)v; break;
        case O_HANDSHAKE: ok = uint_arg(optarg, 100, 600000, &v), o.handshake_timeout_ms = (uint32_t)v; break;
        case 'q': sy_log_set_level(SY_LOG_ERROR); break;
        case 'v': sy_log_set_level(SY_LOG_DEBUG); break;
        case O_HELP: fputs(usage_text, stdout); return 0;
        case ':': fprintf(stderr, "sy serve: error: option '%s' needs a value\n%s", opt, usage_text); return 2;
        default:
            if (optopt >= 0x100) fprintf(stderr, "sy serve: error: option '%s' takes no value\n%s", opt, usage_text);
            else if (optopt) fprintf(stderr, "sy serve: error: unknown option '-%c'\n%s", optopt, usage_text);
            else fprintf(stderr, "sy serve: error: unknown option '%s'\n%s", opt, usage_text);
            return 2;
        }
        if (!ok) {
            char name[48];
            fprintf(stderr, "sy serve: error: %s: '%s' is not an accepted value\n", opt_label(lo, c, name), optarg);
            return 2;
        }
    }
    if (optind < argc) {
        fprintf(stderr, "sy serve: error: unexpected argument '%s' (sy serve takes options only)\n%s", argv[optind], usage_text);
        return 2;
    }
    if (pc.output && !has_suffix(pc.output, ".exr") && !has_suffix(pc.output, ".png")) {
        fprintf(stderr, "sy serve: error: %s: --output must end in .exr or .png\n", pc.output);
        return 2;
    }
    sy_error err = {0};
    uint8_t *secret = NULL;
    size_t secret_len = 0;
    if (sy_cluster_secret_load(secret_file, &secret, &secret_len, &err) != SY_OK) return cli_fail("serve", &err);
    o.secret = secret;
    o.secret_len = secret_len;
    o.present = present_tile;
    o.present_user = &pc;
    o.stop = sy_signals_stop_flag(); /* SIGINT / SIGTERM: the first stops the server cleanly */
    sy_signals_set_graceful("stopping the server");
    signal(SIGPIPE, SIG_IGN);
    sy_cluster_server *s = NULL;
    sy_result r = sy_cluster_server_create(&o, &s, &err);
    free(secret);
    if (r == SY_OK && port_file) r = write_port_file(port_file, sy_cluster_server_port(s), &err);
    if (r == SY_OK) r = sy_cluster_server_run(s, &err);
    sy_cluster_server_destroy(s);
    return r == SY_OK ? 0 : cli_fail("serve", &err);
}

/* ---- sy render --cluster ---- */
bool sy_cluster_cli_getopt(int c, const char *v, sy_cluster_cli_opts *o)
{
    unsigned long long n = 0;
    uint32_t m;
    switch (c) {
    case SY_CLUSTER_OPT_CLUSTER: o->cluster = v; return true;
    case SY_CLUSTER_OPT_MODE: o->mode = v; return sy_cluster_mode_parse(v, &m);
    case SY_CLUSTER_OPT_SECRET_FILE: o->secret_file = v; return true;
    case SY_CLUSTER_OPT_TLS_CA: o->tls_ca = v; return true;
    case SY_CLUSTER_OPT_TIMEOUT_MS:
        if (!uint_arg(v, 1, 100000000ull, &n)) return false;
        o->timeout_ms = (uint32_t)n;
        return true;
    case SY_CLUSTER_OPT_PIXELS: /* float (bit-exact) | half (binary16 tiles) */
        if (strcmp(v, "float") && strcmp(v, "half")) return false;
        o->half_pixels = !strcmp(v, "half");
        return true;
    default: return false;
    }
}

/* Parses the four values of a configuration line's `tile X Y W H` (tok[0..3]). */
static sy_result parse_conf_tile(char **tok, const char *path, uint32_t line, sy_cluster_rect *out, sy_error *err)
{
    uint32_t v[4];
    for (int k = 0; k < 4; ++k) {
        char *end;
        errno = 0;
        unsigned long x = strtoul(tok[k], &end, 10);
        if (errno || *end || end == tok[k] || x > 16384)
            return sy_error_set(err, SY_ERR_PARSE, "%s:%u: tile values must be 0..16384", path, line);
        v[k] = (uint32_t)x;
    }
    if (!v[2] || !v[3]) return sy_error_set(err, SY_ERR_PARSE, "%s:%u: empty tile", path, line);
    *out = (sy_cluster_rect){v[0], v[1], v[2], v[3]};
    return SY_OK;
}

/* A cluster configuration file (`--cluster FILE`), one directive per line, '#' comments:
 *   mode sort-first|balanced|cooperative|multi-display|stereo
 *   server URL [backend NAME] [tile X Y W H]
 *   viewer full | viewer tile X Y W H     (sy view, multi-display: what the client's window shows)
 * The tokens are stored in *text (owned by the caller) and pointed to from the arrays. */
static sy_result parse_conf(const char *path, char **text, const char **urls, const char **backends,
                            sy_cluster_rect *tiles, uint32_t *n, const char **mode, sy_cluster_rect *viewer,
                            sy_error *err)
{
    void *data = NULL;
    size_t size = 0;
    sy_result r = sy_file_read_all(path, 1u << 20, &data, &size, err);
    if (r) return r;
    char *buf = realloc(data, size + 1);
    if (!buf) {
        free(data);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", path);
    }
    buf[size] = 0;
    *text = buf;
    *n = 0;
    uint32_t line = 0;
    for (char *save = NULL, *ln = strtok_r(buf, "\n", &save); ln; ln = strtok_r(NULL, "\n", &save)) {
        line++;
        char *hash = strchr(ln, '#');
        if (hash) *hash = 0;
        char *tok[12];
        int nt = 0;
        for (char *s2 = NULL, *t = strtok_r(ln, " \t\r", &s2); t && nt < 12; t = strtok_r(NULL, " \t\r", &s2))
            tok[nt++] = t;
        if (nt == 0) continue;
        if (!strcmp(tok[0], "mode") && nt == 2) {
            uint32_t m;
            if (!sy_cluster_mode_parse(tok[1], &m))
                return sy_error_set(err, SY_ERR_PARSE, "%s:%u: unknown mode '%s'", path, line, tok[1]);
            *mode = tok[1];
        } else if (!strcmp(tok[0], "server") && nt >= 2) {
            if (*n == SY_CLUSTER_MAX_SERVERS)
                return sy_error_set(err, SY_ERR_LIMIT, "%s:%u: more than %u servers", path, line, SY_CLUSTER_MAX_SERVERS);
            urls[*n] = tok[1];
            backends[*n] = NULL;
            memset(&tiles[*n], 0, sizeof tiles[*n]);
            for (int i = 2; i < nt;) {
                if (!strcmp(tok[i], "backend") && i + 1 < nt) {
                    backends[*n] = tok[i + 1];
                    i += 2;
                } else if (!strcmp(tok[i], "tile") && i + 4 < nt) {
                    sy_result tr = parse_conf_tile(tok + i + 1, path, line, &tiles[*n], err);
                    if (tr) return tr;
                    i += 5;
                } else {
                    return sy_error_set(err, SY_ERR_PARSE, "%s:%u: unknown server option '%s'", path, line, tok[i]);
                }
            }
            (*n)++;
        } else if (!strcmp(tok[0], "viewer") && nt == 2 && !strcmp(tok[1], "full")) {
            memset(viewer, 0, sizeof *viewer);
        } else if (!strcmp(tok[0], "viewer") && nt == 6 && !strcmp(tok[1], "tile")) {
            sy_result tr = parse_conf_tile(tok + 2, path, line, viewer, err);
            if (tr) return tr;
        } else {
            return sy_error_set(err, SY_ERR_PARSE,
                                "%s:%u: expected 'mode NAME', 'server URL [backend NAME] [tile X Y W H]' or "
                                "'viewer full|tile X Y W H'",
                                path, line);
        }
    }
    if (*n == 0) return sy_error_set(err, SY_ERR_PARSE, "%s: no 'server' line", path);
    return SY_OK;
}

/* The client options the command line describes: URL list or configuration file, mode (option,
 * else the file's, else sort-first), secret, CA, per-server back-ends and wall tiles. The strings
 * live in *list (the caller frees it) and in the arrays of the caller. */
typedef struct cli_client_opts {
    const char *urls[SY_CLUSTER_MAX_SERVERS], *backends[SY_CLUSTER_MAX_SERVERS];
    sy_cluster_rect tiles[SY_CLUSTER_MAX_SERVERS];
    uint32_t n, mode;
    sy_cluster_rect viewer_tile;
    char *list;
    uint8_t *secret;
    size_t secret_len;
    sy_cluster_client_opts co;
} cli_client_opts;

static void cli_client_opts_free(cli_client_opts *c)
{
    free(c->list);
    free(c->secret);
}

static sy_result cli_client_opts_make(const sy_cluster_cli_opts *o, cli_client_opts *out, sy_error *err)
{
    memset(out, 0, sizeof *out);
    const char *conf_mode = NULL;
    if (!strstr(o->cluster, "://")) { /* a configuration file */
        sy_result cr = parse_conf(o->cluster, &out->list, out->urls, out->backends, out->tiles, &out->n, &conf_mode,
                                  &out->viewer_tile, err);
        if (cr) return cr;
    } else { /* a comma-separated URL list */
        out->list = strdup(o->cluster);
        if (!out->list) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "out of memory");
        for (char *save = NULL, *t = strtok_r(out->list, ",", &save); t; t = strtok_r(NULL, ",", &save)) {
            if (out->n == SY_CLUSTER_MAX_SERVERS)
                return sy_error_set(err, SY_ERR_LIMIT, "--cluster: more than %u servers", SY_CLUSTER_MAX_SERVERS);
            out->urls[out->n++] = t;
        }
    }
    out->mode = SY_CLUSTER_SORT_FIRST;
    const char *mode_name = o->mode ? o->mode : conf_mode;
    if (mode_name && !sy_cluster_mode_parse(mode_name, &out->mode))
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "unknown --cluster-mode '%s'", mode_name);
    sy_result r = SY_OK;
    if (o->secret) { /* the MPI job's secret */
        out->secret = malloc(o->secret_len);
        if (!out->secret) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "out of memory");
        memcpy(out->secret, o->secret, o->secret_len);
        out->secret_len = o->secret_len;
    } else r = sy_cluster_secret_load(o->secret_file, &out->secret, &out->secret_len, err);
    out->co = (sy_cluster_client_opts){.urls = out->urls,
                                       .url_count = out->n,
                                       .secret = out->secret,
                                       .secret_len = out->secret_len,
                                       .tls_ca_file = o->tls_ca,
                                       .timeout_ms = o->timeout_ms,
                                       .connect_timeout_ms = o->connect_timeout_ms,
                                       .log = o->log,
                                       .log_user = o->log_user,
                                       .backends = out->backends,
                                       .wall_tiles = out->tiles};
    return r;
}

sy_result sy_cluster_cli_setup(const sy_cluster_cli_opts *o, const char *backend, const char *params, char *params_out,
                               size_t len, uint32_t *mode_out, uint32_t *servers_out, sy_cluster_rect *viewer_tile,
                               sy_error *err)
{
    cli_client_opts c;
    sy_result r = cli_client_opts_make(o, &c, err);
    if (r == SY_OK) r = sy_mediator_cluster_register(SY_MEDIATOR_CLUSTER_NAME, &c.co, err); /* copies */
    if (r == SY_OK) r = sy_cluster_cli_params(o, backend, c.mode, params, params_out, len, err);
    *mode_out = c.mode;
    *servers_out = c.n;
    if (viewer_tile) *viewer_tile = c.viewer_tile;
    cli_client_opts_free(&c);
    return r;
}

void sy_cluster_cli_last_frame(const sy_context *ctx, sy_cluster_frame_stats *stats, uint32_t *mode)
{
    sy_mediator_cluster_last_frame(sy_context_state(ctx), stats);
    if (mode) sy_mediator_cluster_describe(sy_context_state(ctx), mode, NULL);
}

const char *sy_cluster_cli_mode_name(uint32_t mode) { return sy_cluster_mode_name(mode); }

sy_result sy_cluster_cli_params(const sy_cluster_cli_opts *o, const char *backend, uint32_t mode, const char *params,
                                char *out, size_t len, sy_error *err)
{
    if (mode == SY_CLUSTER_STEREO) mode = SY_CLUSTER_SORT_FIRST; /* stereo is the window's business */
    int n = snprintf(out, len, "backend=%s,mode=%s%s", backend, sy_cluster_mode_name(mode),
                     o->half_pixels ? ",pixels=half" : "");
    if (n > 0 && (size_t)n < len && params && *params) n += snprintf(out + n, len - (size_t)n, ",%s", params);
    if (n < 0 || (size_t)n >= len) return sy_error_set(err, SY_ERR_LIMIT, "--cluster: back-end parameters too long");
    return SY_OK;
}

/* ---- --cluster mpi ---- */
#ifdef SY_HAVE_MPI
static int g_mpi_role; /* 0: MPI not started, 1: rank 0 (client), 2: a server rank that has served */
static uint8_t g_mpi_secret[32];
static char g_mpi_urls[SY_CLUSTER_MAX_SERVERS * 16];

sy_result sy_cluster_cli_mpi_start(sy_cluster_cli_opts *o, bool *served, sy_error *err)
{
    *served = false;
    if (!sy_cluster_mpi_launched())
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                            "--cluster mpi: start sy under an MPI launcher (mpirun -np N sy render ... or srun)");
    int rank = 0, size = 0;
    sy_result r = sy_cluster_mpi_init(&rank, &size, err);
    if (r == SY_OK) r = sy_cluster_mpi_job_secret(g_mpi_secret, err); /* collective: before any refusal */
    if (r == SY_OK && (size < 2 || size - 1 > (int)SY_CLUSTER_MAX_SERVERS))
        r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "--cluster mpi: %d ranks; 2..%u are needed (rank 0 + servers)",
                         size, SY_CLUSTER_MAX_SERVERS + 1);
    if (r != SY_OK) {
        g_mpi_role = 1; /* the other ranks wait for the release */
        return r;
    }
    if (rank > 0) {
        sy_cluster_server_opts so = {.name = "sy render --cluster mpi"};
        r = sy_cluster_mpi_serve(&so, g_mpi_secret, sizeof g_mpi_secret, err);
        sodium_memzero(g_mpi_secret, sizeof g_mpi_secret);
        sy_cluster_mpi_finalize();
        g_mpi_role = 2;
        *served = true;
        return r;
    }
    g_mpi_role = 1;
    sy_cluster_mpi_urls(g_mpi_urls, sizeof g_mpi_urls);
    o->cluster = g_mpi_urls;
    o->secret = g_mpi_secret;
    o->secret_len = sizeof g_mpi_secret;
    return SY_OK;
}

void sy_cluster_cli_mpi_end(void)
{
    if (g_mpi_role != 1) return;
    sy_cluster_mpi_release();
    sy_cluster_mpi_finalize();
    sodium_memzero(g_mpi_secret, sizeof g_mpi_secret);
    g_mpi_role = 0;
}
#else
sy_result sy_cluster_cli_mpi_start(sy_cluster_cli_opts *o, bool *served, sy_error *err)
{
    (void)o;
    *served = false;
    return sy_error_set(err, SY_ERR_UNSUPPORTED, "--cluster mpi: this sy was built without MPI (libopenmpi-dev)");
}
void sy_cluster_cli_mpi_end(void) {}
#endif

/* ---- sy bench cluster ---- */
typedef struct child_server {
    pid_t pid;
    char url[64];
} child_server;

/* Starts `sy serve` on a free loopback port, pinned to cpu (or unpinned when cpu < 0). */
/* Starts `sy serve` on a free loopback port, pinned to cpu (or unpinned when cpu < 0), for at most
 * lifetime_s seconds; one_core: llvmpipe draws on one thread (LP_NUM_THREADS=1). */
static sy_result spawn_server_ex(int cpu, int lifetime_s, bool one_core, child_server *out, sy_error *err)
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
        FILE *f = fopen(port_file, "r");
        int port = 0;
        if (f) {
            if (fscanf(f, "%d", &port) != 1) port = 0;
            fclose(f);
        }
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

static sy_result spawn_server(int cpu, child_server *out, sy_error *err)
{
    return spawn_server_ex(cpu, 600, false, out, err);
}

static void stop_server(child_server *s)
{
    if (s->pid > 0) {
        kill(s->pid, SIGTERM);
        waitpid(s->pid, NULL, 0);
        s->pid = 0;
    }
}

static bool count_all(void *user, const sy_blob *b)
{
    (void)user;
    (void)b;
    return true;
}
static bool count_none(void *user, const sy_blob *b)
{
    (void)user;
    (void)b;
    return false;
}

/* CPU seconds (user + system) a process has used so far, from /proc/PID/stat; < 0 when unknown. */
static double proc_cpu_seconds(pid_t pid)
{
    char path[64], buf[1024];
    snprintf(path, sizeof path, "/proc/%d/stat", (int)pid);
    FILE *f = fopen(path, "r");
    if (!f) return -1.0;
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    buf[n] = 0;
    const char *p = strrchr(buf, ')'); /* the command name may hold spaces and parentheses */
    unsigned long ut = 0, st = 0;
    if (!p || sscanf(p + 1, " %*c %*d %*d %*d %*d %*d %*u %*u %*u %*u %*u %lu %lu", &ut, &st) != 2) return -1.0;
    return (double)(ut + st) / (double)sysconf(_SC_CLK_TCK);
}

/* One cooperative measurement: merged samples per pixel per second on the first n servers. */
typedef struct coop_run {
    double rate;       /* merged samples per pixel per second */
    double seconds;    /* wall time measured */
    double cpu[2];     /* each server's CPU seconds in that time (< 0: unknown) */
    uint64_t samples;  /* merged samples per pixel added in that time */
    uint32_t frames;
} coop_run;

/* Cooperative path tracing on the first n servers with a fresh client (snapshot + translation in a
 * warm-up frame that is not counted), spf samples per server and frame, frames until at least
 * min_seconds have passed (and at least 3). *spf == 0: calibrated here from a 4-sample frame so
 * that a frame takes about 0.4 s (the client's per-frame transfer and merge stay small next to
 * the rendering), and returned for the other runs. */
static sy_result coop_measure(sy_scene *scene, const sy_viewport_desc *vd, const child_server *srv, uint32_t n,
                              uint32_t w, uint32_t h, uint32_t *spf, double frame_s, double min_seconds, coop_run *out,
                              sy_error *err)
{
    memset(out, 0, sizeof *out);
    const char *urls[2] = {srv[0].url, n > 1 ? srv[1].url : NULL};
    sy_cluster_client_opts co = {.urls = urls, .url_count = n, .timeout_ms = 120000};
    sy_cluster_client *c = NULL;
    sy_window *win = NULL;
    sy_viewport *vp = NULL;
    sy_camera_view view;
    sy_layer out_img = {0};
    sy_result r = sy_window_create(w, h, &win, err);
    if (r == SY_OK) r = sy_window_add_viewport(win, vd, &vp, err);
    if (r == SY_OK) r = sy_viewport_camera_view(vp, scene, w, h, &view, err);
    if (r == SY_OK) r = sy_cluster_client_create(scene, &co, &c, err);
    if (r == SY_OK) r = sy_layer_create(w, h, &out_img, err);
    sy_cluster_frame f = {.mode = SY_CLUSTER_COOPERATIVE, .backend = "pathtracer", .root_id = vd->root.id,
                          .background_id = vd->background.id, .camera = view, .width = w, .height = h, .samples = 4};
    sy_cluster_frame_stats st = {0};
    if (r == SY_OK) r = sy_cluster_client_render(c, &f, &out_img, &st, err); /* warm-up: snapshot + translation */
    if (r == SY_OK && !*spf) {
        double t = sy_time_now();
        r = sy_cluster_client_render(c, &f, &out_img, &st, err);
        t = sy_time_now() - t;
        double k = t > 0 ? frame_s / t : 256.0;
        *spf = k >= 256.0 ? 1024u : k <= 1.0 ? 4u : (uint32_t)(4.0 * k + 0.5);
    }
    f.samples = *spf;
    uint64_t s0 = st.samples;
    double cpu0[2] = {proc_cpu_seconds(srv[0].pid), n > 1 ? proc_cpu_seconds(srv[1].pid) : -1.0};
    double t0 = sy_time_now();
    while (r == SY_OK && (out->frames < 3 || sy_time_now() - t0 < min_seconds)) {
        r = sy_cluster_client_render(c, &f, &out_img, &st, err);
        out->frames++;
        if (r == SY_OK && st.servers_live != n)
            r = sy_error_set(err, SY_ERR_IO, "bench: a server dropped out of the cooperative measurement");
    }
    out->seconds = sy_time_now() - t0;
    out->samples = st.samples - s0;
    out->rate = out->seconds > 0 ? (double)out->samples / out->seconds : 0;
    for (uint32_t i = 0; i < 2; ++i) {
        double now = i < n ? proc_cpu_seconds(srv[i].pid) : -1.0;
        out->cpu[i] = now >= 0 && cpu0[i] >= 0 ? now - cpu0[i] : -1.0;
    }
    sy_layer_destroy(&out_img);
    sy_cluster_client_destroy(c);
    sy_window_destroy(win);
    return r;
}

/* Cooperative path tracing, 2 servers pinned to one core each vs 1 server: `rounds` interleaved
 * rounds (the order alternates, so a drift in the machine's load hits both sides alike); the
 * speed-up is best 2-server rate / best 1-server rate, each round's ratio printed beside it.
 * Each server's CPU time shows how much of its core it got: on a machine shared with other work
 * the wall-clock ratio drops, while samples per server CPU-second (the cost of cooperating: the
 * sample split, transfers, merging, waiting for the other server) stay comparable. */
static sy_result bench_coop(sy_scene *scene, const sy_viewport_desc *vd, const child_server *srv, uint32_t rounds,
                            bool pinned, double frame_s, sy_error *err)
{
    const uint32_t w = 320, h = 180;
    const double min_seconds = frame_s * 3.75 > 1.5 ? frame_s * 3.75 : 1.5;
    uint32_t spf = 0;
    enum { MAX_ROUNDS = 64 };
    double ratio[MAX_ROUNDS], rate[2][MAX_ROUNDS], eff[2][MAX_ROUNDS]; /* per round: speed-up, spp/s, spp per CPU-s */
    uint32_t nr = 0, ne = 0;
    if (rounds > MAX_ROUNDS) rounds = MAX_ROUNDS;
    sy_result r = SY_OK;
    printf("  cooperative pathtracer %ux%u, servers %s, %u interleaved rounds of >= %.1f s per side, frames of about "
           "%.2f s on one server:\n",
           w, h, pinned ? "pinned to cores 0 and 1" : "not pinned (1 core)", rounds, min_seconds, frame_s);
    for (uint32_t round = 0; round < rounds && r == SY_OK; ++round) {
        coop_run run[2];
        for (uint32_t k = 0; k < 2 && r == SY_OK; ++k) {
            uint32_t n = (round & 1) ? 2 - k : 1 + k; /* 1,2 / 2,1 / 1,2 ... */
            r = coop_measure(scene, vd, srv, n, w, h, &spf, frame_s, min_seconds, &run[n - 1], err);
        }
        if (r != SY_OK) break;
        rate[0][nr] = run[0].rate, rate[1][nr] = run[1].rate;
        ratio[nr++] = run[0].rate > 0 ? run[1].rate / run[0].rate : 0.0;
        double cpu1 = run[0].cpu[0], cpu2 = run[1].cpu[0] + run[1].cpu[1];
        if (run[0].cpu[0] >= 0 && run[1].cpu[0] >= 0 && run[1].cpu[1] >= 0 && cpu1 > 0 && cpu2 > 0) {
            eff[0][ne] = (double)run[0].samples / cpu1, eff[1][ne] = (double)run[1].samples / cpu2;
            ne++;
        }
        printf("    round %u (%u spp per server and frame): 1 server %.1f spp/s (busy %.2f s CPU of %.2f s); "
               "2 servers %.1f spp/s (busy %.2f + %.2f s CPU of %.2f s): %.2fx\n",
               round + 1, spf, run[0].rate, run[0].cpu[0], run[0].seconds, run[1].rate, run[1].cpu[0], run[1].cpu[1],
               run[1].seconds, ratio[nr - 1]);
    }
    if (r == SY_OK && nr) {
        sy_bench_spread sr = sy_bench_spread_of(ratio, nr), s1 = sy_bench_spread_of(rate[0], nr),
                        s2 = sy_bench_spread_of(rate[1], nr);
        printf("  cooperative speed-up (median of %u rounds, min..max): %.2fx (%.2f..%.2f; target >= 1.95x); "
               "1 server %.1f spp/s, 2 servers %.1f spp/s (medians)\n",
               nr, sr.median, sr.min, sr.max, s1.median, s2.median);
    }
    if (r == SY_OK && ne) {
        sy_bench_spread e1 = sy_bench_spread_of(eff[0], ne), e2 = sy_bench_spread_of(eff[1], ne);
        printf("  per server CPU-second (median of %u): 1 server %.1f spp, 2 servers %.1f spp (%.0f%% efficiency): "
               "2 x %.2f = %.2fx with each server's core to itself\n",
               ne, e1.median, e2.median, 100.0 * e2.median / e1.median, e2.median / e1.median, 2.0 * e2.median / e1.median);
    }
    return r;
}

/* Protocol 2 figures: bytes of binary16 tiles vs float32 on the same frame and the half codec's
 * ratio on the frame's pixels; the snapshot a second client with the same model sends (the
 * servers' blob cache answers its hashes) vs the first client's. */
static sy_result bench_half_and_blob_cache(sy_scene *scene, const sy_cluster_client_opts *co, sy_cluster_client *c,
                                           const sy_cluster_frame *f, sy_layer *out,
                                           const sy_cluster_frame_stats *first, sy_error *err)
{
    sy_cluster_frame hf = *f;
    sy_cluster_frame_stats sf = {0}, sh = {0}, s2 = {0};
    sy_result r = sy_cluster_client_render(c, f, out, &sf, err);
    hf.half = true;
    if (r == SY_OK) r = sy_cluster_client_render(c, &hf, out, &sh, err);
    if (r == SY_OK)
        printf("  half tiles (--cluster-pixels half) %ux%u RGBA: %.2f MB back per frame vs %.2f MB float32 (%.2fx fewer)\n",
               f->width, f->height, (double)sh.bytes_received / 1e6, (double)sf.bytes_received / 1e6,
               (double)sf.bytes_received / (double)sh.bytes_received);
    sy_cluster_buf enc = {0};
    double te = sy_time_now();
    if (r == SY_OK) r = sy_cluster_tile_encode_as(out, true, SY_CLUSTER_ENC_F16_SHUFFLE_ZSTD, &enc, err);
    te = sy_time_now() - te;
    uint64_t raw16 = (uint64_t)out->width * out->height * 10;
    sy_cluster_tile t = {{0, 0, out->width, out->height}, SY_CLUSTER_ENC_F16_SHUFFLE_ZSTD, 5, raw16, enc.data,
                         (uint32_t)enc.size};
    double td = sy_time_now();
    if (r == SY_OK) r = sy_cluster_tile_decode(&t, out, 0, 0, err);
    td = sy_time_now() - td;
    if (r == SY_OK)
        printf("  tile codec RGBA+Z half: %.1f MB float32 -> %.1f MB binary16 -> %.2f MB zstd (%.1fx of float32, %.1fx "
               "of the half planes); encode %.0f MB/s, decode %.0f MB/s (float32-equivalent bytes, one core)\n",
               (double)raw16 * 2 / 1e6, (double)raw16 / 1e6, (double)enc.size / 1e6, (double)raw16 * 2 / (double)enc.size,
               (double)raw16 / (double)enc.size, (double)raw16 * 2 / te / 1e6, (double)raw16 * 2 / td / 1e6);
    sy_cluster_buf_free(&enc);
    sy_cluster_client *c2 = NULL;
    if (r == SY_OK) r = sy_cluster_client_create(scene, co, &c2, err);
    if (r == SY_OK) r = sy_cluster_client_render(c2, f, out, &s2, err);
    if (r == SY_OK)
        printf("  snapshot of a second client with the same model (per server): %llu bytes, %llu of them blob payloads; "
               "first client %llu bytes, %llu of them blob payloads (%.0fx less)\n",
               (unsigned long long)(s2.scene_bytes / 2), (unsigned long long)(s2.blob_bytes / 2),
               (unsigned long long)(first->scene_bytes / 2), (unsigned long long)(first->blob_bytes / 2),
               (double)first->scene_bytes / (double)(s2.scene_bytes ? s2.scene_bytes : 1));
    sy_cluster_client_destroy(c2);
    return r;
}

/* >>hostile peers (issue 14): connections that never authenticate. Tricklers announce a 256 MiB
 * message and send 64 KiB every 100 ms; flooders announce 8 MiB and send it as fast as they can;
 * both reconnect whenever the server closes them. Plain sockets, 127.0.0.1 only. */
typedef struct hostile_peer {
    int port;
    bool flood;
    atomic_int *stop;
    uint64_t bytes;
    uint32_t conns;
} hostile_peer;

static int hostile_connect(int port)
{
    int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (fd < 0) return -1;
    struct timeval tv = {2, 0};
    setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &tv, sizeof tv);
    struct sockaddr_in sa = {.sin_family = AF_INET, .sin_port = htons((uint16_t)port)};
    sa.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (connect(fd, (struct sockaddr *)&sa, sizeof sa) != 0) {
        close(fd);
        return -1;
    }
    return fd;
}

static bool hostile_send(int fd, const void *p, size_t n)
{
    while (n) {
        ssize_t k = send(fd, p, n, MSG_NOSIGNAL);
        if (k <= 0) return false;
        p = (const uint8_t *)p + k;
        n -= (size_t)k;
    }
    return true;
}

static void hostile_sleep_ms(int ms)
{
    struct timespec ts = {ms / 1000, (long)(ms % 1000) * 1000000L};
    nanosleep(&ts, NULL);
}

static void *hostile_main(void *arg)
{
    hostile_peer *h = arg;
    static uint8_t chunk[256 << 10]; /* only ever read: shared by every peer */
    while (!atomic_load(h->stop)) {
        int fd = hostile_connect(h->port);
        if (fd < 0) {
            hostile_sleep_ms(50);
            continue;
        }
        h->conns++;
        uint8_t hdr[SY_CLUSTER_HEADER_SIZE];
        sy_cluster_header_write(hdr, SY_CLUSTER_HELLO, 0, h->flood ? 8u << 20 : 256u << 20, 1);
        if (hostile_send(fd, hdr, sizeof hdr)) {
            for (uint32_t left = 8u << 20; h->flood && left && !atomic_load(h->stop);) {
                uint32_t n = left < sizeof chunk ? left : (uint32_t)sizeof chunk;
                if (!hostile_send(fd, chunk, n)) break;
                h->bytes += n;
                left -= n;
            }
            while (!h->flood && !atomic_load(h->stop) && hostile_send(fd, chunk, 64 << 10)) {
                h->bytes += 64 << 10;
                hostile_sleep_ms(100);
            }
        }
        close(fd);
        hostile_sleep_ms(h->flood ? 20 : 50);
    }
    return NULL;
}

/* VmRSS (or another "Vm...:" line) of a process in KiB; -1 when unreadable. */
static long proc_status_kb(pid_t pid, const char *field)
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

/* Server srv's resident memory before, at the peak of and after 64 tricklers + 8 flooders (5 s),
 * and the frame time of a client of that server alone (320x180 sort-first) before and during. */
static sy_result bench_hostile(sy_scene *scene, const sy_demo_info *d, const char *backend, const child_server *srv,
                               sy_error *err)
{
    enum { TRICKLERS = 64, FLOODERS = 8, W = 320, H = 180 };
    const char *urls[1] = {srv->url};
    sy_cluster_client_opts co = {.urls = urls, .url_count = 1, .timeout_ms = 60000};
    sy_cluster_client *c = NULL;
    sy_layer out = {0};
    sy_camera_view view = sy_camera_view_frame_bounds(&(sy_bounds){{-3, -1, -3}, {3, 3, 3}}, (float)W / H);
    sy_cluster_frame f = {.mode = SY_CLUSTER_SORT_FIRST, .backend = backend, .root_id = d->root.id,
                          .background_id = d->background.id, .camera = view, .width = W, .height = H};
    sy_result r = sy_cluster_client_create(scene, &co, &c, err);
    if (r == SY_OK) r = sy_layer_create(W, H, &out, err);
    if (r == SY_OK) r = sy_cluster_client_render(c, &f, &out, NULL, err); /* snapshot + translation */
    double quiet = 0;
    const int quiet_n = 20;
    for (int i = 0; i < quiet_n && r == SY_OK; ++i) {
        double t0 = sy_time_now();
        r = sy_cluster_client_render(c, &f, &out, NULL, err);
        quiet += sy_time_now() - t0;
    }
    const char *colon = strrchr(srv->url, ':');
    int port = colon ? atoi(colon + 1) : 0;
    long rss0 = proc_status_kb(srv->pid, "VmRSS"), peak = rss0;
    atomic_int stop = 0;
    hostile_peer hp[TRICKLERS + FLOODERS];
    pthread_t th[TRICKLERS + FLOODERS];
    int started = 0;
    for (int i = 0; i < TRICKLERS + FLOODERS && r == SY_OK; ++i) {
        hp[i] = (hostile_peer){port, i >= TRICKLERS, &stop, 0, 0};
        pthread_attr_t at;
        pthread_attr_init(&at);
        pthread_attr_setstacksize(&at, 256 << 10);
        if (pthread_create(&th[started], &at, hostile_main, &hp[i]) == 0) started++;
        pthread_attr_destroy(&at);
    }
    double t_start = sy_time_now(), busy = 0, worst = 0;
    int frames = 0;
    while (r == SY_OK && sy_time_now() - t_start < 5.0) {
        double t0 = sy_time_now();
        r = sy_cluster_client_render(c, &f, &out, NULL, err);
        double dt = sy_time_now() - t0;
        busy += dt;
        worst = dt > worst ? dt : worst;
        frames++;
        long kb = proc_status_kb(srv->pid, "VmRSS");
        if (kb > peak) peak = kb;
    }
    atomic_store(&stop, 1);
    for (int i = 0; i < started; ++i) pthread_join(th[i], NULL);
    hostile_sleep_ms(300);
    long rss1 = proc_status_kb(srv->pid, "VmRSS");
    uint64_t trickled = 0, flooded = 0;
    uint32_t conns = 0;
    for (int i = 0; i < started; ++i) {
        conns += hp[i].conns;
        if (hp[i].flood) flooded += hp[i].bytes;
        else trickled += hp[i].bytes;
    }
    if (r == SY_OK) {
        printf("  hostile peers on server 0 (%d announce 256 MiB and trickle 64 KiB / 100 ms, %d flood 8 MiB; none "
               "authenticates; %u connections, %.0f MiB trickled, %.0f MiB flooded in 5 s):\n",
               TRICKLERS, FLOODERS, conns, (double)trickled / 1048576.0, (double)flooded / 1048576.0);
        printf("    server VmRSS %.1f MiB before, %.1f MiB peak, %.1f MiB after (+%.1f MiB at the peak); client frame "
               "%ux%u %s: %.2f ms before, %.2f ms mean / %.2f ms worst during (%d frames)\n",
               rss0 / 1024.0, peak / 1024.0, rss1 / 1024.0, (peak - rss0) / 1024.0, W, H, backend,
               quiet / quiet_n * 1e3, frames ? busy / frames * 1e3 : 0.0, worst * 1e3, frames);
    }
    sy_layer_destroy(&out);
    sy_cluster_client_destroy(c);
    return r;
}


/* >>soak: one `sy serve` and one client that moves the camera every frame for a given time
 * (issue 32, item 6): the camera node orbits the scene (a change list per frame, as `sy view
 * --cluster` sends) and each frame is rendered from the moved camera. Every 10 s the server's
 * VmRSS, open descriptors (/proc/PID/fd) and threads are sampled; growth is measured from the
 * sample at the end of the warm-up (caches, context pool, render threads) to the end. Passes when
 * every frame sent came back (no error, no failed server) and each of the three grew by less
 * than 5 %. Not part of ctest (it runs for minutes): tests/soak/serve_soak.sh, docs/TESTING.md. */
typedef struct soak_sample {
    double t;
    long rss_kb, fds, threads, client_rss_kb;
} soak_sample;

static long proc_fd_count(pid_t pid)
{
    char path[64];
    snprintf(path, sizeof path, "/proc/%d/fd", (int)pid);
    DIR *d = opendir(path);
    if (!d) return -1;
    long n = 0;
    for (struct dirent *e; (e = readdir(d));)
        if (e->d_name[0] != '.') n++;
    closedir(d);
    return n;
}

static soak_sample soak_take(pid_t server, double t)
{
    soak_sample s = {t, proc_status_kb(server, "VmRSS"), proc_fd_count(server), proc_status_kb(server, "Threads"),
                     proc_status_kb(getpid(), "VmRSS")};
    return s;
}

static double growth_pct(long a, long b)
{
    return a > 0 ? 100.0 * (double)(b - a) / (double)a : 0.0;
}

static sy_result bench_soak(sy_scene *scene, const sy_demo_info *d, const char *backend, double seconds,
                            double warmup, uint32_t w, uint32_t h, bool *passed, sy_error *err)
{
    *passed = false;
    child_server srv = {0};
    sy_window *win = NULL;
    sy_viewport *vp = NULL;
    sy_cluster_client *c = NULL;
    sy_layer out = {0};
    sy_mat4 m0;
    sy_result r = spawn_server_ex(-1, (int)seconds + 300, false, &srv, err);
    sy_viewport_desc vd = {.root = d->root, .camera = d->camera, .background = d->background, .backend = backend};
    const char *urls[1] = {srv.url};
    sy_cluster_client_opts co = {.urls = urls, .url_count = 1, .timeout_ms = 120000};
    if (r == SY_OK) r = sy_window_create(w, h, &win, err);
    if (r == SY_OK) r = sy_window_add_viewport(win, &vd, &vp, err);
    if (r == SY_OK) r = sy_node_world_matrix(scene, d->camera, &m0, err); /* under an identity root: = local */
    if (r == SY_OK) r = sy_cluster_client_create(scene, &co, &c, err);
    if (r == SY_OK) r = sy_layer_create(w, h, &out, err);
    if (r != SY_OK) {
        sy_cluster_client_destroy(c);
        sy_window_destroy(win);
        stop_server(&srv);
        return r;
    }
    printf("sy bench cluster --soak: `sy serve` (pid %d, %s) and one client on loopback, demo scene, %ux%u %s, the "
           "camera orbiting one step per frame (a change list + a RENDER each), %.0f s, warm-up %.0f s\n",
           (int)srv.pid, srv.url, w, h, backend, seconds, warmup);
    printf("  %8s %8s %12s %6s %8s %14s %14s\n", "t (s)", "frames", "server RSS", "fds", "threads", "client RSS",
           "frame ms mean");
    fflush(stdout);
    uint64_t sent = 0, received = 0, failed = 0, bytes_out = 0, bytes_in = 0;
    char first_error[SY_ERROR_MESSAGE_MAX + 32] = "";
    double t0 = sy_time_now(), next_sample = 0, busy = 0, worst = 0;
    uint64_t frames_at_sample = 0;
    double busy_at_sample = 0;
    soak_sample first = {0}, base = {0}, last = {0}, peak = {0};
    bool have_base = false;
    for (uint64_t i = 0;; ++i) {
        double t = sy_time_now() - t0;
        if (t >= next_sample || t >= seconds) {
            last = soak_take(srv.pid, t);
            if (i == 0) first = last;
            if (!have_base && t >= warmup) base = last, have_base = true;
            if (have_base) {
                if (last.rss_kb > peak.rss_kb) peak.rss_kb = last.rss_kb;
                if (last.fds > peak.fds) peak.fds = last.fds;
                if (last.threads > peak.threads) peak.threads = last.threads;
            }
            uint64_t nf = received - frames_at_sample;
            printf("  %8.0f %8llu %9.1f MiB %6ld %8ld %10.1f MiB %14.2f\n", t, (unsigned long long)received,
                   last.rss_kb / 1024.0, last.fds, last.threads, last.client_rss_kb / 1024.0,
                   nf ? (busy - busy_at_sample) / (double)nf * 1e3 : 0.0);
            fflush(stdout);
            frames_at_sample = received;
            busy_at_sample = busy;
            next_sample += 10.0;
            if (last.rss_kb < 0) {
                r = sy_error_set(err, SY_ERR_IO, "soak: the server (pid %d) is gone", (int)srv.pid);
                break;
            }
            if (t >= seconds) break;
        }
        /* the camera orbits the scene's vertical axis, 0.5 degree per frame */
        double a = (double)(i % 720) * (M_PI / 360.0);
        float q[4] = {0, (float)sin(a / 2), 0, (float)cos(a / 2)}, t3[3] = {0, 0, 0}, s3[3] = {1, 1, 1};
        sy_mat4 rot = sy_mat4_from_trs(t3, q, s3), m = sy_mat4_mul(&rot, &m0);
        sy_camera_view view;
        r = sy_node_set_matrix(scene, d->camera, &m, err);
        if (r == SY_OK) r = sy_scene_commit(scene, NULL, err);
        if (r == SY_OK) r = sy_viewport_camera_view(vp, scene, w, h, &view, err);
        if (r != SY_OK) break;
        sy_cluster_frame f = {.mode = SY_CLUSTER_SORT_FIRST, .backend = backend, .root_id = d->root.id,
                              .background_id = d->background.id, .camera = view, .width = w, .height = h};
        sy_cluster_frame_stats st = {0};
        sy_error fe = {0};
        double ft = sy_time_now();
        sent++;
        sy_result fr = sy_cluster_client_render(c, &f, &out, &st, &fe);
        ft = sy_time_now() - ft;
        if (fr == SY_OK && st.servers_failed == 0 && st.bytes_received > 0) {
            received++;
            busy += ft;
            if (ft > worst) worst = ft;
        } else {
            failed++;
            if (!first_error[0])
                snprintf(first_error, sizeof first_error, "frame %llu: %s", (unsigned long long)sent,
                         fr ? fe.message : "a server failed during the frame");
        }
        bytes_out += st.bytes_sent;
        bytes_in += st.bytes_received;
    }
    sy_cluster_client_destroy(c);
    sy_layer_destroy(&out);
    sy_window_destroy(win);
    stop_server(&srv);
    if (r != SY_OK) return r;
    double g_rss = growth_pct(base.rss_kb, last.rss_kb), g_fds = growth_pct(base.fds, last.fds),
           g_thr = growth_pct(base.threads, last.threads);
    printf("  frames: %llu sent, %llu received, %llu failed%s%s; %.1f MiB sent, %.1f MiB received; frame %.2f ms mean, "
           "%.2f ms worst\n",
           (unsigned long long)sent, (unsigned long long)received, (unsigned long long)failed,
           first_error[0] ? " (first: " : "", first_error[0] ? first_error : "", bytes_out / 1048576.0,
           bytes_in / 1048576.0, received ? busy / (double)received * 1e3 : 0.0, worst * 1e3);
    if (first_error[0]) printf(")\n");
    printf("  server at t=0 (client connected, before the first frame): RSS %.1f MiB, %ld fds, %ld threads\n", first.rss_kb / 1024.0,
           first.fds, first.threads);
    printf("  server after the warm-up (t=%.0f s) -> end (t=%.0f s), peak between: RSS %.1f -> %.1f MiB (%+.2f %%, peak "
           "%.1f), fds %ld -> %ld (%+.2f %%, peak %ld), threads %ld -> %ld (%+.2f %%, peak %ld)\n",
           base.t, last.t, base.rss_kb / 1024.0, last.rss_kb / 1024.0, g_rss, peak.rss_kb / 1024.0, base.fds, last.fds,
           g_fds, peak.fds, base.threads, last.threads, g_thr, peak.threads);
    *passed = have_base && failed == 0 && sent == received && g_rss < 5.0 && g_fds < 5.0 && g_thr < 5.0;
    printf("  %s: every frame delivered %s, growth under 5 %% %s\n", *passed ? "PASS" : "FAIL",
           failed == 0 && sent == received ? "yes" : "NO", g_rss < 5.0 && g_fds < 5.0 && g_thr < 5.0 ? "yes" : "NO");
    return SY_OK;
}

/* >>scale: per-frame protocol cost and bytes on the wire, 1-3 servers, sort-first / balanced /
 * cooperative at 1080p and 4K, against the scaling model of docs/CLUSTER.md ("Scaling model").
 * Every server renders on one core (raster: LP_NUM_THREADS=1; path tracer: threads=1), so 2
 * servers use this machine's 2 cores and 3 are oversubscribed (stated in the output). The protocol
 * cost of a frame is the client's time beyond the slowest server's sync + render:
 *   sort-first, balanced:  overhead(N) = L + ceil(N/C) * (P/N) * r / D,  bytes back = P * c
 *     (the strips decode on their own threads while the slowest one still renders: the last
 *     strip's decode is what remains)
 *   cooperative:           overhead(N) = L + ceil(N/C) * P * r / D + N * P * m,  bytes back = N * P * c
 *     (every server returns the whole image; the merge costs m per pixel and server)
 * L from tiny frames, c and D from the 1-server frame of each mode and size (its image encoded and
 * decoded here), m calibrated on the 1-server cooperative frame; N = 2 and 3 check the model. The
 * loopback's bandwidth is taken as infinite (P * c / B adds on a real network). */
typedef struct scale_point {
    double frame, overhead, server; /* medians, seconds */
    double bytes_back, bytes_out;   /* per frame */
} scale_point;

static sy_result scale_measure(sy_scene *scene, const sy_demo_info *d, const child_server *srv, uint32_t n, uint32_t mode,
                               uint32_t w, uint32_t h, uint32_t frames, scale_point *out, sy_layer *img_out, sy_error *err)
{
    const char *urls[3] = {srv[0].url, srv[1].url, srv[2].url};
    sy_cluster_client_opts co = {.urls = urls, .url_count = n, .timeout_ms = 600000};
    sy_cluster_client *c = NULL;
    sy_window *win = NULL;
    sy_viewport *vp = NULL;
    sy_camera_view view;
    sy_layer img = {0};
    bool coop = mode == SY_CLUSTER_COOPERATIVE;
    bool raster = sy_mediator_find("raster") != NULL; /* the picture back-ends measured: raster, else whitted */
    const char *backend = coop ? "pathtracer" : raster ? "raster" : "whitted";
    const char *params = coop ? "threads=1" : raster ? NULL : "spp=1,threads=1"; /* one core per server */
    sy_viewport_desc vd = {.root = d->root, .camera = d->camera, .background = d->background, .backend = backend};
    sy_result r = sy_window_create(w, h, &win, err);
    if (r == SY_OK) r = sy_window_add_viewport(win, &vd, &vp, err);
    if (r == SY_OK) r = sy_viewport_camera_view(vp, scene, w, h, &view, err);
    if (r == SY_OK) r = sy_cluster_client_create(scene, &co, &c, err);
    if (r == SY_OK) r = sy_layer_create(w, h, &img, err);
    sy_cluster_frame f = {.mode = mode, .backend = backend, .params = params,
                          .root_id = d->root.id, .background_id = d->background.id, .camera = view, .width = w,
                          .height = h, .samples = 1, .samples_total = coop ? n : 0, .depth = true};
    sy_cluster_frame_stats st;
    if (r == SY_OK) r = sy_cluster_client_render(c, &f, &img, &st, err); /* warm-up: snapshot + translation */
    double fr[16], ov[16], sv[16], back[16], sent[16];
    if (frames > 16) frames = 16;
    for (uint32_t i = 0; i < frames && r == SY_OK; ++i) {
        r = sy_cluster_client_render(c, &f, &img, &st, err);
        fr[i] = st.seconds, sv[i] = st.max_server_seconds, ov[i] = st.seconds - st.max_server_seconds;
        back[i] = (double)st.bytes_received, sent[i] = (double)st.bytes_sent;
        if (r == SY_OK && st.servers_live != n) r = sy_error_set(err, SY_ERR_IO, "bench: a server dropped out");
    }
    if (r == SY_OK) {
        out->frame = sy_bench_spread_of(fr, frames).median;
        out->overhead = sy_bench_spread_of(ov, frames).median;
        out->server = sy_bench_spread_of(sv, frames).median;
        out->bytes_back = sy_bench_spread_of(back, frames).median;
        out->bytes_out = sy_bench_spread_of(sent, frames).median;
    }
    if (r == SY_OK && img_out) {
        *img_out = img;
        img = (sy_layer){0};
    }
    sy_layer_destroy(&img);
    sy_cluster_client_destroy(c);
    sy_window_destroy(win);
    return r;
}

/* Decode rate (raw bytes per second, one core) and wire bytes per pixel of an image's tile. */
static sy_result codec_of(const sy_layer *img, double *D, double *c, sy_error *err)
{
    sy_cluster_buf enc = {0};
    sy_layer back = {0};
    sy_result r = sy_cluster_tile_encode(img, true, &enc, err);
    if (r == SY_OK) r = sy_layer_create(img->width, img->height, &back, err);
    double P = (double)img->width * img->height, best = 1e30;
    for (int k = 0; k < 3 && r == SY_OK; ++k) {
        sy_cluster_tile t = {{0, 0, img->width, img->height}, SY_CLUSTER_ENC_F32_SHUFFLE_ZSTD, 5, (uint64_t)P * 20,
                             enc.data, (uint32_t)enc.size};
        double t0 = sy_time_now();
        r = sy_cluster_tile_decode(&t, &back, 0, 0, err);
        double dt = sy_time_now() - t0;
        if (dt < best) best = dt;
    }
    *D = P * 20.0 / best;
    *c = (double)enc.size / P;
    sy_cluster_buf_free(&enc);
    sy_layer_destroy(&back);
    return r;
}

static sy_result bench_scale(sy_scene *scene, const sy_demo_info *d, uint32_t frames, sy_error *err)
{
    long ncpu = sysconf(_SC_NPROCESSORS_ONLN);
    double C = ncpu > 0 ? (double)ncpu : 1.0;
    child_server srv[3] = {{0}};
    sy_result r = SY_OK;
    for (int i = 0; i < 3 && r == SY_OK; ++i) r = spawn_server_ex(-1, 7200, true, &srv[i], err);
    printf("sy bench cluster --scale: demo scene, 1-3 servers on loopback, each rendering on one core (%ld cores here: "
           "3 servers are oversubscribed); raster (sort-first, balanced) and pathtracer 1 spp per frame in all "
           "(cooperative); medians of %u frames after a warm-up\n", ncpu, frames);
    double L = 0;
    if (r == SY_OK) {
        scale_point tiny;
        r = scale_measure(scene, d, srv, 1, SY_CLUSTER_SORT_FIRST, 64, 36, 15, &tiny, NULL, err);
        L = tiny.overhead;
        if (r == SY_OK) printf("  L = %.2f ms (request latency: 64x36 frames, time beyond the server)\n", L * 1e3);
    }
    static const uint32_t sizes[2][2] = {{1920, 1080}, {3840, 2160}};
    static const uint32_t modes[3] = {SY_CLUSTER_SORT_FIRST, SY_CLUSTER_BALANCED, SY_CLUSTER_COOPERATIVE};
    for (int si = 0; si < 2 && r == SY_OK; ++si) {
        uint32_t w = sizes[si][0], h = sizes[si][1];
        double P = (double)w * h, rb = 20.0; /* RGBA + depth float32 */
        printf("  %ux%u (P = %.2f Mpx, r = 20 bytes per pixel raw):\n", w, h, P / 1e6);
        double D = 0, c = 0, m = 0;
        for (int mi = 0; mi < 3 && r == SY_OK; ++mi)
            for (uint32_t n = 1; n <= 3 && r == SY_OK; ++n) {
                scale_point pt;
                sy_layer img = {0};
                bool coop = modes[mi] == SY_CLUSTER_COOPERATIVE;
                r = scale_measure(scene, d, srv, n, modes[mi], w, h, frames, &pt, n == 1 ? &img : NULL, err);
                if (r == SY_OK && n == 1 && mi != 1) { /* constants of this mode's images */
                    r = codec_of(&img, &D, &c, err);
                    if (r == SY_OK)
                        printf("    %s images: c = %.2f bytes per pixel on the wire, D = %.0f MB/s decode (one core)\n",
                               sy_cluster_mode_name(modes[mi]), c, D / 1e6);
                    if (r == SY_OK && coop) m = fmax(0.0, (pt.overhead - L - P * rb / D) / P);
                }
                sy_layer_destroy(&img);
                if (r != SY_OK) break;
                double per_core = ceil((double)n / C);
                double model = coop ? L + per_core * P * rb / D + n * P * m : L + per_core * (P / n) * rb / D;
                double bytes_model = (coop ? n : 1) * P * c;
                printf("    %-11s N=%u%s: frame %7.3f s, slowest server %7.3f s, protocol %6.1f ms (model %6.1f ms%s), "
                       "back %6.2f MB (model %6.2f MB), out %4.1f KB\n",
                       sy_cluster_mode_name(modes[mi]), n, n > C ? " (oversubscribed)" : "", pt.frame, pt.server,
                       pt.overhead * 1e3, model * 1e3, coop && n == 1 ? ": calibrates m" : "", pt.bytes_back / 1e6,
                       bytes_model / 1e6, pt.bytes_out / 1e3);
            }
        if (r == SY_OK && m > 0) printf("    m = %.1f ns per pixel and server (merge, calibrated at N=1)\n", m * 1e9);
    }
    for (int i = 0; i < 3; ++i)
        if (srv[i].pid) stop_server(&srv[i]);
    return r;
}

int sy_cmd_bench_cluster(int argc, char **argv)
{
    uint32_t w = 1920, h = 1080, rounds = 3;
    bool hostile_only = false, coop_only = false, scale = false; /* one measurement alone */
    double coop_frame = 1.6; /* cooperative: seconds per frame on one server (each frame costs ~15 ms of sync + merge) */
    double soak = 0, warmup = -1; /* --soak: seconds of camera changes against one server */
    const char *soak_backend = NULL;
    bool size_given = false;
    static const char usage_text[] = "usage: sy bench cluster [-w W] [-h H] [--repeats ROUNDS] [--hostile-only | --coop-only] "
                                     "[--coop-frame SECONDS] | --scale\n"
                                     "       sy bench cluster --soak SECONDS [--warmup SECONDS] [-b BACKEND] [-w W] [-h H]"
                                     "   (exit 1 unless every frame came back and the server's RSS, fds and threads grew < 5 %)\n";
    enum { O_REPEATS = 0x100, O_HOSTILE, O_COOP, O_SCALE, O_COOP_FRAME, O_SOAK, O_WARMUP, O_HELP };
    static const struct option lo[] = {
        {"repeats", required_argument, NULL, O_REPEATS}, {"hostile-only", no_argument, NULL, O_HOSTILE},
        {"coop-only", no_argument, NULL, O_COOP}, {"scale", no_argument, NULL, O_SCALE},
        {"soak", required_argument, NULL, O_SOAK}, {"warmup", required_argument, NULL, O_WARMUP},
        {"backend", required_argument, NULL, 'b'},
        {"coop-frame", required_argument, NULL, O_COOP_FRAME}, {"help", no_argument, NULL, O_HELP},
        {"quiet", no_argument, NULL, 'q'}, {"verbose", no_argument, NULL, 'v'}, {NULL, 0, NULL, 0}};
    int opt;
    unsigned long long v = 0;
    optind = 0; /* glibc: start over (new arguments, GNU ordering) */
    opterr = 0;
    while ((opt = sy_getopt(argc, argv, ":w:h:b:qv", lo, "sy bench cluster")) != -1) {
        bool ok = true;
        char *end = NULL;
        switch (opt) {
        case SY_GETOPT_ERROR: return 2; /* an abbreviated long option (named on stderr) */
        case 'w': ok = uint_arg(optarg, 1, 16384, &v), w = (uint32_t)v, size_given = true; break;
        case 'h': ok = uint_arg(optarg, 1, 16384, &v), h = (uint32_t)v, size_given = true; break;
        case 'b': soak_backend = optarg; break;
        case O_SOAK: ok = uint_arg(optarg, 1, 86400, &v), soak = (double)v; break;
        case O_WARMUP: ok = uint_arg(optarg, 0, 86400, &v), warmup = (double)v; break;
        case O_REPEATS: ok = uint_arg(optarg, 1, 100, &v), rounds = (uint32_t)v; break;
        case O_HOSTILE: hostile_only = true; break;
        case O_COOP: coop_only = true; break;
        case O_SCALE: scale = true; break;
        case O_COOP_FRAME: coop_frame = strtod(optarg, &end), ok = end != optarg && !*end; break;
        case 'q': sy_log_set_level(SY_LOG_ERROR); break;
        case 'v': sy_log_set_level(SY_LOG_DEBUG); break;
        case O_HELP: fputs(usage_text, stdout); return 0;
        case ':': fprintf(stderr, "sy bench cluster: error: option '%s' needs a value\n%s", argv[optind - 1], usage_text); return 2;
        default:
            fprintf(stderr, "sy bench cluster: error: unknown option '%s'\n%s", argv[optind - 1], usage_text);
            return 2;
        }
        if (!ok) {
            char name[48];
            fprintf(stderr, "sy bench cluster: error: %s: '%s' is not an accepted value\n", opt_label(lo, opt, name), optarg);
            return 2;
        }
    }
    if (optind < argc) {
        fprintf(stderr, "sy bench cluster: error: unexpected argument '%s'\n%s", argv[optind], usage_text);
        return 2;
    }
    if (w < 1 || h < 1 || w > 16384 || h > 16384 || rounds < 1 || rounds > 100 || !(coop_frame >= 0.05 && coop_frame <= 60)) {
        fprintf(stderr, "sy bench cluster: error: sizes 1..16384, --repeats 1..100, --coop-frame 0.05..60\n");
        return 2;
    }
    signal(SIGPIPE, SIG_IGN);
    sy_error err = {0};
    sy_scene *scene = NULL;
    sy_demo_info d;
    child_server srv[2] = {{0}};
    sy_cluster_client *c = NULL;
    sy_window *win = NULL;
    sy_viewport *vp = NULL;
    sy_layer out = {0};
    sy_changes *snap = NULL;
    long ncpu = sysconf(_SC_NPROCESSORS_ONLN);
    sy_result r = sy_scene_create(&scene, &err);
    if (r == SY_OK) r = sy_demo_build(scene, &d, &err);
    if (r == SY_OK) r = sy_scene_commit(scene, NULL, &err);
    /* snapshot size vs the scene's own data */
    void *buf = NULL;
    size_t with_blobs = 0, without = 0;
    if (r == SY_OK) r = sy_scene_snapshot(scene, &snap, &err);
    if (r == SY_OK) r = sy_changes_serialize(snap, count_all, NULL, &buf, &with_blobs, &err);
    free(buf);
    buf = NULL;
    if (r == SY_OK) r = sy_changes_serialize(snap, count_none, NULL, &buf, &without, &err);
    free(buf);
    sy_changes_release(snap);
    if (r == SY_OK && soak > 0) {
        const char *backend = soak_backend ? soak_backend : sy_mediator_default_name();
        bool passed = false;
        if (warmup < 0) warmup = soak / 10 < 60 ? soak / 10 : 60;
        if (warmup >= soak) {
            sy_scene_destroy(scene);
            fprintf(stderr, "sy bench cluster: error: --warmup must be shorter than --soak\n");
            return 2;
        }
        if (!sy_mediator_find(backend)) {
            sy_scene_destroy(scene);
            fprintf(stderr, "sy bench cluster: error: -b: no back-end '%s' in this build\n", backend);
            return 2;
        }
        r = bench_soak(scene, &d, backend, soak, warmup, size_given ? w : 320, size_given ? h : 180, &passed, &err);
        sy_scene_destroy(scene);
        return r == SY_OK ? (passed ? 0 : 1) : cli_fail("bench cluster", &err);
    }
    if (soak_backend || warmup >= 0) {
        sy_scene_destroy(scene);
        fprintf(stderr, "sy bench cluster: error: -b and --warmup go with --soak\n%s", usage_text);
        return 2;
    }
    if (r == SY_OK && scale) {
        r = bench_scale(scene, &d, rounds < 3 ? 3 : rounds, &err);
        sy_scene_destroy(scene);
        return r == SY_OK ? 0 : cli_fail("bench cluster", &err);
    }
    if (r == SY_OK) r = spawn_server(ncpu >= 2 ? 0 : -1, &srv[0], &err);
    if (r == SY_OK && hostile_only) {
        printf("sy bench cluster --hostile-only: demo scene, one server on loopback\n");
        r = bench_hostile(scene, &d, sy_mediator_default_name(), &srv[0], &err);
        stop_server(&srv[0]);
        sy_scene_destroy(scene);
        return r == SY_OK ? 0 : cli_fail("bench cluster", &err);
    }
    if (r == SY_OK) r = spawn_server(ncpu >= 2 ? 1 : -1, &srv[1], &err);
    if (r == SY_OK && ncpu >= 3) { /* the client keeps off the servers' cores where it can */
        cpu_set_t set;
        CPU_ZERO(&set);
        for (long i = 2; i < ncpu && i < CPU_SETSIZE; ++i) CPU_SET((int)i, &set);
        sched_setaffinity(0, sizeof set, &set);
    }
    const char *urls[2] = {srv[0].url, srv[1].url};
    sy_cluster_client_opts co = {.urls = urls, .url_count = 2, .timeout_ms = 120000};
    const char *backend = sy_mediator_default_name();
    sy_viewport_desc vd = {.root = d.root, .camera = d.camera, .background = d.background, .backend = backend};
    if (r == SY_OK && coop_only) {
        printf("sy bench cluster --coop-only: demo scene, 2 servers on loopback\n");
        r = bench_coop(scene, &vd, srv, rounds, ncpu >= 2, coop_frame, &err);
        stop_server(&srv[0]);
        stop_server(&srv[1]);
        sy_scene_destroy(scene);
        return r == SY_OK ? 0 : cli_fail("bench cluster", &err);
    }
    sy_camera_view view;
    if (r == SY_OK) r = sy_window_create(w, h, &win, &err);
    if (r == SY_OK) r = sy_window_add_viewport(win, &vd, &vp, &err);
    if (r == SY_OK) r = sy_viewport_camera_view(vp, scene, w, h, &view, &err);
    if (r == SY_OK) r = sy_cluster_client_create(scene, &co, &c, &err);
    if (r == SY_OK) r = sy_layer_create(w, h, &out, &err);
    sy_cluster_frame f = {.mode = SY_CLUSTER_SORT_FIRST, .backend = backend, .root_id = d.root.id,
                          .background_id = d.background.id, .camera = view, .width = w, .height = h};
    sy_cluster_frame_stats s1 = {0}, s2 = {0};
    if (r == SY_OK) r = sy_cluster_client_render(c, &f, &out, &s1, &err);
    /* one transform change */
    if (r == SY_OK) {
        sy_mat4 m;
        r = sy_node_world_matrix(scene, d.camera, &m, &err);
        m.m[12] += 0.01f; /* the demo camera hangs under an identity root: world = local */
        if (r == SY_OK) r = sy_node_set_matrix(scene, d.camera, &m, &err);
    }
    if (r == SY_OK) r = sy_scene_commit(scene, NULL, &err);
    if (r == SY_OK) r = sy_cluster_client_render(c, &f, &out, &s2, &err);
    /* steady state: frames without changes */
    double over = 0, frame = 0, bytes = 0;
    const int reps = 5;
    for (int i = 0; i < reps && r == SY_OK; ++i) {
        sy_cluster_frame_stats s;
        r = sy_cluster_client_render(c, &f, &out, &s, &err);
        over += s.seconds - s.max_server_seconds;
        frame += s.seconds;
        bytes += (double)(s.bytes_sent + s.bytes_received);
    }
    if (r == SY_OK) {
        printf("sy bench cluster: demo scene, 2 servers on loopback (pinned to cores 0 and 1: %s; client on %s)\n",
               ncpu >= 2 ? "yes" : "no, 1 core", ncpu >= 3 ? "the other cores" : "any core");
        printf("  snapshot on the wire (first frame, per server): %llu bytes; serialised scene %zu bytes "
               "(%zu structure + %zu blob payload)\n",
               (unsigned long long)(s1.scene_bytes / 2), with_blobs, without, with_blobs - without);
        printf("  one-transform change on the wire (per server):  %llu bytes (target < 256)\n",
               (unsigned long long)(s2.scene_bytes / 2));
        printf("  sort-first %s %ux%u: frame %.4f s, protocol overhead %.4f s/frame (%.1f%% of the frame), "
               "%.2f MB on the wire per frame (zstd float tiles)\n",
               backend, w, h, frame / reps, over / reps, 100.0 * over / frame, bytes / reps / 1e6);
    }
    /* per-request latency L of the scaling model: tiny sort-first frames, where rendering and
     * pixels cost next to nothing; what the client spends beyond the slowest server */
    if (r == SY_OK) {
        sy_layer tiny = {0};
        sy_cluster_frame tf = f;
        tf.width = 64, tf.height = 36;
        double lat_min = 1e30, lat_sum = 0, frame_sum = 0;
        const int lat_n = 30;
        r = sy_layer_create(tf.width, tf.height, &tiny, &err);
        for (int i = -1; i < lat_n && r == SY_OK; ++i) { /* i = -1: warm-up (a new image size) */
            sy_cluster_frame_stats s;
            r = sy_cluster_client_render(c, &tf, &tiny, &s, &err);
            double l = s.seconds - s.max_server_seconds;
            if (r == SY_OK && i >= 0) {
                lat_sum += l, frame_sum += s.seconds;
                if (l < lat_min) lat_min = l;
            }
        }
        if (r == SY_OK)
            printf("  request latency (64x36 sort-first frames, 2 servers in parallel, %d frames): L = %.2f ms min, %.2f ms "
                   "mean beyond the slowest server (whole frame %.2f ms mean)\n",
                   lat_n, lat_min * 1e3, lat_sum / lat_n * 1e3, frame_sum / lat_n * 1e3);
        sy_layer_destroy(&tiny);
    }
    /* codec constants for the scaling model (docs/CLUSTER.md): compression and decompression
     * throughput of the final frame's pixels (RGBA + depth float32) on this core */
    if (r == SY_OK) {
        sy_cluster_buf enc = {0};
        double te = sy_time_now();
        r = sy_cluster_tile_encode(&out, true, &enc, &err);
        te = sy_time_now() - te;
        sy_cluster_tile t = {{0, 0, w, h}, SY_CLUSTER_ENC_F32_SHUFFLE_ZSTD, 5, (uint64_t)w * h * 20, enc.data,
                             (uint32_t)enc.size};
        double td = sy_time_now();
        if (r == SY_OK) r = sy_cluster_tile_decode(&t, &out, 0, 0, &err);
        td = sy_time_now() - td;
        double raw = (double)w * h * 20;
        if (r == SY_OK)
            printf("  tile codec %ux%u RGBA+Z float: %.1f MB raw -> %.2f MB (%.1fx); encode %.0f MB/s, decode %.0f MB/s "
                   "(raw bytes, one core)\n",
                   w, h, raw / 1e6, (double)enc.size / 1e6, raw / (double)enc.size, raw / te / 1e6, raw / td / 1e6);
        sy_cluster_buf_free(&enc);
    }
    if (r == SY_OK) r = bench_half_and_blob_cache(scene, &co, c, &f, &out, &s1, &err);
    if (r == SY_OK) r = bench_hostile(scene, &d, backend, &srv[0], &err);
    sy_layer_destroy(&out);
    sy_cluster_client_destroy(c);
    c = NULL;
    /* cooperative path tracing: 2 pinned servers vs 1 */
    if (r == SY_OK && sy_mediator_find("pathtracer")) {
        r = bench_coop(scene, &vd, srv, rounds, ncpu >= 2, coop_frame, &err);
    } else if (r == SY_OK) {
        printf("  cooperative: skipped (no 'pathtracer' back-end registered in this build)\n");
    }
    stop_server(&srv[0]);
    stop_server(&srv[1]);
    sy_window_destroy(win);
    sy_scene_destroy(scene);
    return r == SY_OK ? 0 : cli_fail("bench cluster", &err);
}
