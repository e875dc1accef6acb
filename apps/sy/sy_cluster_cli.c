/* sy_cluster_cli.c — the `--cluster` options of `sy render` and `sy view` (see sy_cluster_cli.h):
 * the options, the cluster configuration file, the cluster mediator class they register and the
 * viewport parameters that select it. `--cluster mpi`: sy_cluster_cli_mpi.c. The protocol, the
 * modes and the cluster mediator live in mediators/cluster/. */
#include "sy_cluster_cli.h"
#include "sy_cli.h"
#include "sy_mediator_cluster.h"

#include "sy_file.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- sy render --cluster, sy view --cluster ---- */
bool sy_cluster_cli_getopt(int c, const char *v, sy_cluster_cli_opts *o)
{
    uint64_t n = 0;
    uint32_t m;
    switch (c) {
    case SY_CLUSTER_OPT_CLUSTER: o->cluster = v; return true;
    case SY_CLUSTER_OPT_MODE: o->mode = v; return sy_cluster_mode_parse(v, &m);
    case SY_CLUSTER_OPT_SECRET_FILE: o->secret_file = v; return true;
    case SY_CLUSTER_OPT_TLS_CA: o->tls_ca = v; return true;
    case SY_CLUSTER_OPT_TIMEOUT_MS:
        if (!sy_cli_parse_uint(v, 1, 100000000u, &n)) return false;
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
        uint64_t x = 0;
        if (!sy_cli_parse_uint(tok[k], 0, 16384, &x))
            return sy_error_set(err, SY_ERR_PARSE, "%s:%u: tile values must be 0..16384", path, line);
        v[k] = (uint32_t)x;
    }
    if (!v[2] || !v[3]) return sy_error_set(err, SY_ERR_PARSE, "%s:%u: empty tile", path, line);
    *out = (sy_cluster_rect){v[0], v[1], v[2], v[3]};
    return SY_OK;
}

/* A cluster configuration file (`--cluster FILE`), one directive per line, '#' comments:
 *   mode sort-first|balanced|cooperative|multi-display|stereo   (frames: only as --cluster-mode)
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

/* Registers the cluster class `name` for o (the URLs or configuration file, mode, secret, TLS);
 * *mode_out and *servers_out: its mode and server count; viewer_tile (may be NULL): a wall's viewer tile. */
static sy_result cluster_register(const sy_cluster_cli_opts *o, const char *name, uint32_t *mode_out,
                                  uint32_t *servers_out, sy_cluster_rect *viewer_tile, sy_error *err)
{
    cli_client_opts c;
    sy_result r = cli_client_opts_make(o, &c, err);
    if (r == SY_OK) r = sy_mediator_cluster_register(name, &c.co, err); /* copies */
    *mode_out = c.mode;
    *servers_out = c.n;
    if (viewer_tile) *viewer_tile = c.viewer_tile;
    cli_client_opts_free(&c);
    return r;
}

sy_result sy_cluster_cli_register(const sy_cluster_cli_opts *o, const char *name, uint32_t *mode_out,
                                  uint32_t *servers_out, sy_error *err)
{
    return cluster_register(o, name, mode_out, servers_out, NULL, err);
}

sy_result sy_cluster_cli_setup(const sy_cluster_cli_opts *o, const char *backend, const char *params, char *params_out,
                               size_t len, uint32_t *mode_out, uint32_t *servers_out, sy_cluster_rect *viewer_tile,
                               sy_error *err)
{
    sy_result r = cluster_register(o, SY_MEDIATOR_CLUSTER_NAME, mode_out, servers_out, viewer_tile, err);
    if (r == SY_OK && *mode_out == SY_CLUSTER_FRAMES) /* a configuration file's 'mode frames', sy view */
        r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cluster mode frames renders image sequences: sy render "
                         "--frames A:B --cluster-mode frames; a window (sy view, one sy render image) uses another mode");
    if (r == SY_OK) r = sy_cluster_cli_params(o, backend, *mode_out, params, params_out, len, err);
    return r;
}

sy_result sy_cluster_cli_render_frames(const sy_cluster_cli_opts *o, sy_scene *scene, const sy_cluster_frames_job *job,
                                       sy_cluster_frames_stats *stats, uint32_t *servers_out, sy_error *err)
{
    cli_client_opts c;
    sy_cluster_client *client = NULL;
    sy_result r = cli_client_opts_make(o, &c, err);
    *servers_out = c.n;
    if (r == SY_OK) r = sy_cluster_client_create(scene, &c.co, &client, err);
    if (r == SY_OK) r = sy_cluster_client_render_frames(client, job, stats, err);
    sy_cluster_client_destroy(client);
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
