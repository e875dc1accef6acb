/* sy_cmd_serve.c — `sy serve`: a render server of the cluster (sy_cluster_server, mediators/cluster/)
 * with its options, writing the tiles it is shown to --output (see sy_cluster_cli.h). */
#include "sy_cluster_cli.h"
#include "sy_cli.h"
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
    uint32_t blob_cache_mb = 0, peer_memory_mb = 0, frame_kb = 0, message_mb = 0; /* 0: the server's default */
    enum { O_LISTEN = OPT_OWN_FIRST, O_SECRET_FILE, O_OUTPUT, O_PORT_FILE, O_TLS_CERT, O_TLS_KEY, O_NAME, O_MAX_SESSIONS,
           O_MAX_LIFETIME, O_BLOB_CACHE, O_MAX_OBJECTS, O_AUTH_BACKOFF, O_PEER_MEMORY, O_FRAME_KB, O_MESSAGE_MB,
           O_UNAUTH, O_HANDSHAKE };
    const sy_cli_opt opts[] = {
        SY_CLI_OPT_TEXT("listen", O_LISTEN, &o.listen_url),
        SY_CLI_OPT_TEXT("secret-file", O_SECRET_FILE, &secret_file),
        SY_CLI_OPT_TEXT("output", O_OUTPUT, &pc.output),
        SY_CLI_OPT_TEXT("port-file", O_PORT_FILE, &port_file),
        SY_CLI_OPT_TEXT("tls-cert", O_TLS_CERT, &o.tls_cert_file),
        SY_CLI_OPT_TEXT("tls-key", O_TLS_KEY, &o.tls_key_file),
        SY_CLI_OPT_TEXT("name", O_NAME, &o.name),
        SY_CLI_OPT_UINT("max-sessions", O_MAX_SESSIONS, &o.max_sessions, 1, 65536),
        SY_CLI_OPT_REAL("max-lifetime", O_MAX_LIFETIME, &o.max_lifetime_s, DBL_TRUE_MIN, DBL_MAX),
        SY_CLI_OPT_UINT("blob-cache-mb", O_BLOB_CACHE, &blob_cache_mb, 1, 1u << 24),
        SY_CLI_OPT_UINT("max-objects", O_MAX_OBJECTS, &o.max_objects, 1, 1u << 30),
        SY_CLI_OPT_UINT("auth-backoff-ms", O_AUTH_BACKOFF, &o.auth_backoff_ms, 0, 3600000),
        /* budgets against hostile peers (docs/PROTOCOL.md, "Budgets and limits") */
        SY_CLI_OPT_UINT("max-peer-memory-mb", O_PEER_MEMORY, &peer_memory_mb, 1, 1u << 20),
        SY_CLI_OPT_UINT("max-frame-kb", O_FRAME_KB, &frame_kb, 64, 1u << 20),
        SY_CLI_OPT_UINT("max-message-mb", O_MESSAGE_MB, &message_mb, 1, 1u << 20),
        SY_CLI_OPT_UINT("max-unauthenticated", O_UNAUTH, &o.max_unauthenticated, 1, 65536),
        SY_CLI_OPT_UINT("handshake-timeout-ms", O_HANDSHAKE, &o.handshake_timeout_ms, 100, 600000),
    };
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
    sy_cli_parser p = {SY_CLI_ARGS("serve", argc, argv, opts), .usage = usage_text};
    if (sy_cli_parse(&p) != -1) return p.status;
    o.blob_cache_bytes = (size_t)blob_cache_mb << 20;
    o.max_peer_memory = (size_t)peer_memory_mb << 20;
    o.max_frame = (size_t)frame_kb << 10;
    o.max_message = (size_t)message_mb << 20;
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
