/* sy_cmd_serve.c — `sy serve`: a render server of the cluster (sy_cluster_server, mediators/cluster/)
 * with its options, writing the tiles it is shown to --output (see sy_cluster_cli.h). */
#include "sy_cluster_cli.h"
#include "sy_cli.h"
#include "sy_options.h"
#include "sy_signals.h"

#include "sy_exr.h"
#include "sy_file.h"
#include "sy_log.h"
#include "sy_png.h"

#include <float.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>

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
    if (sy_cli_ends_with(p->output, ".exr"))
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
        case O_MAX_SESSIONS: ok = sy_cluster_cli_uint_arg(optarg, 1, 65536, &v), o.max_sessions = (uint32_t)v; break;
        case O_MAX_LIFETIME: ok = sy_cli_parse_double(optarg, DBL_TRUE_MIN, DBL_MAX, &o.max_lifetime_s); break;
        case O_BLOB_CACHE: ok = sy_cluster_cli_uint_arg(optarg, 1, 1u << 24, &v), o.blob_cache_bytes = (size_t)v << 20; break;
        case O_MAX_OBJECTS: ok = sy_cluster_cli_uint_arg(optarg, 1, 1u << 30, &v), o.max_objects = (uint32_t)v; break;
        case O_AUTH_BACKOFF: ok = sy_cluster_cli_uint_arg(optarg, 0, 3600000, &v), o.auth_backoff_ms = (uint32_t)v; break;
        case O_PEER_MEMORY: ok = sy_cluster_cli_uint_arg(optarg, 1, 1u << 20, &v), o.max_peer_memory = (size_t)v << 20; break;
        case O_FRAME_KB: ok = sy_cluster_cli_uint_arg(optarg, 64, 1u << 20, &v), o.max_frame = (size_t)v << 10; break;
        case O_MESSAGE_MB: ok = sy_cluster_cli_uint_arg(optarg, 1, 1u << 20, &v), o.max_message = (size_t)v << 20; break;
        case O_UNAUTH: ok = sy_cluster_cli_uint_arg(optarg, 1, 65536, &v), o.max_unauthenticated = (uint32_t)v; break;
        case O_HANDSHAKE: ok = sy_cluster_cli_uint_arg(optarg, 100, 600000, &v), o.handshake_timeout_ms = (uint32_t)v; break;
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
            fprintf(stderr, "sy serve: error: %s: '%s' is not an accepted value\n", sy_cluster_cli_opt_label(lo, c, name),
                    optarg);
            return 2;
        }
    }
    if (optind < argc) {
        fprintf(stderr, "sy serve: error: unexpected argument '%s' (sy serve takes options only)\n%s", argv[optind], usage_text);
        return 2;
    }
    if (pc.output && !sy_cli_ends_with(pc.output, ".exr") && !sy_cli_ends_with(pc.output, ".png")) {
        fprintf(stderr, "sy serve: error: %s: --output must end in .exr or .png\n", pc.output);
        return 2;
    }
    sy_error err = {0};
    uint8_t *secret = NULL;
    size_t secret_len = 0;
    if (sy_cluster_secret_load(secret_file, &secret, &secret_len, &err) != SY_OK) return sy_cli_fail(&err);
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
    return r == SY_OK ? 0 : sy_cli_fail(&err);
}
