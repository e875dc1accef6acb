/* sy_mediator_cluster.c — the cluster mediator class (see sy_mediator_cluster.h): a replica scene
 * fed by the context's change lists, a cluster client on it, and the translation of a render
 * request into a cluster frame. Picks (SY_CAP_PICK) are answered on the replica by a local context
 * of the servers' back-end class, made on the first pick (see cluster_pick). */
#include "sy_mediator_cluster.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A registered configuration: deep copies of what sy_cluster_client_opts points to. */
typedef struct cluster_config {
    sy_mediator_class cls;
    char name[32];
    sy_cluster_client_opts opts;
    char *urls[SY_CLUSTER_MAX_SERVERS];
    char *backends[SY_CLUSTER_MAX_SERVERS];
    sy_cluster_rect tiles[SY_CLUSTER_MAX_SERVERS];
    uint8_t *secret;
    char *tls_ca;
} cluster_config;

typedef struct cluster_state {
    const cluster_config *cfg;
    sy_scene *replica;
    sy_cluster_client *client;
    uint32_t root_id;
    uint32_t mode;
    bool half;
    uint32_t samples;   /* cooperative default per render (0 = 16 per server) */
    uint32_t caps;
    char backend[SY_CLUSTER_BACKEND_MAX];
    char params[SY_CLUSTER_PARAMS_MAX]; /* forwarded to the servers' back-end */
    sy_cluster_frame_stats last;
    uint64_t merged_samples;
    sy_layer full; /* a request for a sub-rectangle renders the whole image here */
    uint32_t timeout_ms; /* adaptive deadline (the configuration gave none) */
    uint32_t servers;    /* the servers this viewport uses (servers=) */
    sy_context *pick;    /* picks: a local context of the servers' back-end on the replica (first pick) */
    bool restart;        /* sy_context_restart: the next frame's requests restart the servers' accumulations */
} cluster_state;

/* Caps the servers' back-end `name` has, as registered in this process (same binary); unknown
 * here: depth only (the servers may know it). */
static uint32_t remote_caps(const char *name)
{
    const sy_mediator_class *c = sy_mediator_find(name);
    return c ? c->caps : SY_CAP_DEPTH;
}

/* servers=LIST: 1-based server numbers and ranges joined by '+' ("1", "2-4", "1+3"); absent = all.
 * *mask gets bit i for server i + 1. */
static sy_result parse_servers(const cluster_config *cfg, const char *list, uint64_t *mask, sy_error *err)
{
    uint32_t n = cfg->opts.url_count;
    *mask = n >= 64 ? ~0ull : ((1ull << n) - 1);
    if (!list) return SY_OK;
    *mask = 0;
    const char *p = list;
    while (*p) {
        char *end = NULL;
        unsigned long a = strtoul(p, &end, 10), b = a;
        if (end == p) break;
        if (*end == '-') {
            const char *q = end + 1;
            b = strtoul(q, &end, 10);
            if (end == q) break;
        }
        if (a < 1 || b < a || b > n)
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: servers=%s: server numbers are 1..%u", cfg->name, list, n);
        for (unsigned long i = a; i <= b; ++i) *mask |= 1ull << (i - 1);
        p = end;
        if (*p == '+') p++;
        else if (*p) break;
    }
    if (*p || !*mask)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                            "%s: servers=%s: expected server numbers and ranges joined by '+' (e.g. 1+3, 2-4)", cfg->name,
                            list);
    return SY_OK;
}

/* What an instance with these parameters can do: what every node's back-end has, as the mode
 * delivers it (cooperative accumulates: progressive). */
static uint32_t cluster_caps_of(const sy_params *p, const void *class_user)
{
    const cluster_config *cfg = class_user;
    const char *backend = sy_params_get(p, "backend"), *m = sy_params_get(p, "mode");
    uint32_t mode = SY_CLUSTER_SORT_FIRST;
    if (m && !sy_cluster_mode_parse(m, &mode)) mode = SY_CLUSTER_SORT_FIRST;
    uint32_t common = SY_CAP_DEPTH | SY_CAP_ANALYSIS | SY_CAP_SAMPLE_RANGES | SY_CAP_PICK | SY_CAP_CLIP;
    uint64_t mask = 0;
    if (parse_servers(cfg, sy_params_get(p, "servers"), &mask, NULL) != SY_OK) mask = 0;
    for (uint32_t i = 0; i < cfg->opts.url_count; ++i) {
        if (!(mask >> i & 1)) continue;
        const char *b = cfg->backends[i] ? cfg->backends[i] : backend;
        common &= b ? remote_caps(b) : 0;
    }
    uint32_t caps = SY_CAP_REMOTE | SY_CAP_TILES | (common & (SY_CAP_DEPTH | SY_CAP_ANALYSIS));
    if (mode == SY_CLUSTER_COOPERATIVE && (common & SY_CAP_SAMPLE_RANGES)) caps |= SY_CAP_PROGRESSIVE;
    /* picks: answered here by the viewport's back-end class (cluster_pick), so it must be registered
     * in this process and pick, as must every server's */
    if ((common & SY_CAP_PICK) && backend && (remote_caps(backend) & SY_CAP_PICK)) caps |= SY_CAP_PICK;
    /* section planes travel in the RENDER's camera view (protocol 4) to servers whose back-end cuts */
    if (common & SY_CAP_CLIP) caps |= SY_CAP_CLIP;
    return caps;
}

/* >>parameters: the cluster's own keys (sy_params.h); every other key is forwarded to the servers'
 * back-end. Core checks the own keys against this table; cluster_check_params checks the forwarded
 * ones against the table of each used server's back-end when that class is registered in this
 * process (the same binary as the servers, usually); a back-end unknown here is left to the
 * servers, which check the keys when they create their context. */
static const sy_param_decl cluster_params[] = {
    {"backend", SY_PARAM_STRING, 0, 0, NULL, NULL,
     "the servers' back-end (required; a server configured with its own uses that); keys not listed here go to it", 0},
    {"mode", SY_PARAM_ENUM, 0, 0, "sort-first", "sort-first|balanced|cooperative|multi-display",
     "how the servers share a frame (for stereo give the window stereo viewports: sy render --stereo sbs)", 0},
    {"samples", SY_PARAM_INT, 0, SY_CLUSTER_MAX_SAMPLES, "0", NULL,
     "cooperative: samples per render when the request gives none (0 = 16 per server)", 0},
    {"pixels", SY_PARAM_ENUM, 0, 0, "float", "float|half", "tiles on the wire: float32 (bit-exact) or binary16", 0},
    {"servers", SY_PARAM_STRING, 0, 0, NULL, NULL,
     "the configured servers this viewport uses: 1-based numbers and ranges joined by '+' (2-4, 1+3); absent = all", 0},
};
static const sy_param_table cluster_table = SY_PARAM_TABLE(cluster_params);

static sy_result cluster_check_params(const sy_params *all, const sy_params *forwarded, const void *class_user,
                                      sy_error *err)
{
    const cluster_config *cfg = class_user;
    const char *backend = sy_params_get(all, "backend");
    uint64_t mask = 0;
    if (parse_servers(cfg, sy_params_get(all, "servers"), &mask, NULL) != SY_OK) return SY_OK; /* create says why */
    const sy_mediator_class *checked[SY_CLUSTER_MAX_SERVERS];
    uint32_t n = 0;
    for (uint32_t i = 0; i < cfg->opts.url_count; ++i) {
        const char *b = cfg->backends[i] ? cfg->backends[i] : backend;
        const sy_mediator_class *c = (mask >> i & 1) && b ? sy_mediator_find(b) : NULL;
        if (!c || (c->caps & SY_CAP_REMOTE)) continue; /* unknown here: the servers check */
        bool seen = false;
        for (uint32_t k = 0; k < n; ++k) seen = seen || checked[k] == c;
        if (seen) continue;
        checked[n++] = c;
        sy_result r = sy_mediator_class_check_params(c, forwarded, err);
        if (r != SY_OK) {
            sy_error_prefix(err, "%s, forwarded to server %u", cfg->name, i + 1);
            return r;
        }
    }
    return SY_OK;
}

static sy_result check_node(const cluster_config *cfg, uint32_t i, const char *backend, uint32_t mode, sy_error *err)
{
    uint32_t caps = remote_caps(backend);
    if (mode == SY_CLUSTER_COOPERATIVE && !(caps & SY_CAP_SAMPLE_RANGES))
        return sy_error_set(err, SY_ERR_UNSUPPORTED,
                            "%s: server %u (%s) renders with %s, whose samples cannot be split across servers: "
                            "mode cooperative needs a back-end with sample ranges (e.g. pathtracer)",
                            cfg->name, i + 1, cfg->urls[i], backend);
    return SY_OK;
}

static void cluster_destroy(void *state)
{
    cluster_state *st = state;
    if (!st) return;
    sy_context_release(st->pick); /* its consumer is on the replica */
    sy_cluster_client_destroy(st->client);
    sy_scene_destroy(st->replica);
    sy_layer_destroy(&st->full);
    free(st);
}

static sy_result cluster_create(const sy_mediator_create_args *args, void **state_out, sy_error *err)
{
    *state_out = NULL;
    const cluster_config *cfg = args->class_user;
    const sy_params *p = args->params;
    const char *backend = NULL, *m = NULL, *px = NULL; /* mode, pixels: declared defaults */
    long samples = 0;
    sy_result r;
    if ((r = sy_param_string(&cluster_table, p, "backend", &backend, err)) ||
        (r = sy_param_string(&cluster_table, p, "mode", &m, err)) ||
        (r = sy_param_string(&cluster_table, p, "pixels", &px, err)) ||
        (r = sy_param_int(&cluster_table, p, "samples", &samples, err)))
        return r;
    if (!backend || !backend[0])
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT,
                            "%s: parameter backend=NAME (the servers' back-end) is required", cfg->name);
    if (strlen(backend) >= SY_CLUSTER_BACKEND_MAX)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: back-end name '%s' is too long", cfg->name, backend);
    const sy_mediator_class *own = sy_mediator_find(backend);
    if (own && (own->caps & SY_CAP_REMOTE))
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: backend=%s is itself a cluster", cfg->name, backend);
    uint32_t mode = SY_CLUSTER_SORT_FIRST;
    if (!sy_cluster_mode_parse(m, &mode) || mode == SY_CLUSTER_STEREO) /* the table's enum has the others */
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: mode=%s is not a mode of a cluster viewport", cfg->name, m);
    uint64_t mask = 0;
    r = parse_servers(cfg, sy_params_get(p, "servers"), &mask, err);
    if (r) return r;
    /* set-up checks: every node this viewport uses can do what the mode asks */
    for (uint32_t i = 0; i < cfg->opts.url_count; ++i) {
        if (!(mask >> i & 1)) continue;
        r = check_node(cfg, i, cfg->backends[i] ? cfg->backends[i] : backend, mode, err);
        if (r) return r;
    }
    cluster_state *st = calloc(1, sizeof *st);
    if (!st) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "%s: out of memory", cfg->name);
    st->cfg = cfg;
    st->root_id = args->root_node_id;
    st->mode = mode;
    st->half = !strcmp(px, "half");
    st->samples = (uint32_t)samples;
    st->timeout_ms = 60000; /* adaptive (no timeout configured): the first frame sends a snapshot */
    snprintf(st->backend, sizeof st->backend, "%s", backend);
    /* the rest goes to the servers' back-end */
    size_t len = 0;
    for (uint32_t i = 0; i < p->count && r == SY_OK; ++i) {
        const char *k = p->items[i].key;
        if (sy_param_find(&cluster_table, k)) continue; /* the cluster's own */
        int n = snprintf(st->params + len, sizeof st->params - len, "%s%s=%s", len ? "," : "", k, p->items[i].value);
        if (n < 0 || (size_t)n >= sizeof st->params - len)
            r = sy_error_set(err, SY_ERR_LIMIT, "%s: back-end parameters longer than %u bytes", cfg->name,
                             SY_CLUSTER_PARAMS_MAX - 1);
        else len += (size_t)n;
    }
    st->caps = cluster_caps_of(p, cfg);
    if (r == SY_OK) r = sy_scene_create(&st->replica, err);
    /* the client of this viewport: the servers it uses, in their configured order */
    const char *urls[SY_CLUSTER_MAX_SERVERS], *backends[SY_CLUSTER_MAX_SERVERS];
    sy_cluster_rect tiles[SY_CLUSTER_MAX_SERVERS];
    sy_cluster_client_opts co = cfg->opts;
    co.url_count = 0;
    for (uint32_t i = 0; i < cfg->opts.url_count; ++i)
        if (mask >> i & 1) {
            urls[co.url_count] = cfg->urls[i], backends[co.url_count] = cfg->backends[i], tiles[co.url_count] = cfg->tiles[i];
            co.url_count++;
        }
    co.urls = urls, co.backends = backends, co.wall_tiles = tiles;
    st->servers = co.url_count;
    if (r == SY_OK) r = sy_cluster_client_create(st->replica, &co, &st->client, err);
    if (r) {
        cluster_destroy(st);
        return r;
    }
    *state_out = st;
    return SY_OK;
}

static sy_result cluster_sync(void *state, const sy_changes *changes, sy_error *err)
{
    cluster_state *st = state;
    sy_result r = sy_scene_apply(st->replica, changes, err);
    if (r == SY_OK) r = sy_scene_commit(st->replica, NULL, err);
    /* the pick context follows every frame, so the replica's change log never waits for it */
    if (r == SY_OK && st->pick) r = sy_context_sync(st->pick, err);
    return r;
}

/* SY_CAP_PICK: the servers render the same replica with the same back-end class, so what is under
 * a pixel is what a local context of that class answers on the replica; it is made on the first
 * pick (the class's translation of the scene, on this machine) and synced with every frame after.
 * The servers are not asked (the protocol has no pick message). */
static sy_result cluster_pick(void *state, const sy_camera_view *view, uint32_t width, uint32_t height, uint32_t x,
                              uint32_t y, sy_pick_result *out, sy_error *err)
{
    cluster_state *st = state;
    sy_result r = SY_OK;
    if (!st->pick) {
        sy_params bp;
        r = sy_params_parse(st->params[0] ? st->params : NULL, &bp, err);
        if (r == SY_OK) r = sy_context_create(st->replica, st->backend, &bp, st->root_id, &st->pick, err);
        if (r != SY_OK) {
            sy_error_prefix(err, "%s: pick", st->cfg->name);
            return r;
        }
    }
    r = sy_context_sync(st->pick, err);
    return r == SY_OK ? sy_context_pick(st->pick, view, width, height, x, y, out, err) : r;
}

/* n samples in multiples of the live servers (0: the servers' default) */
static uint32_t coop_total(uint32_t n, uint32_t live)
{
    if (!n || !live) return n;
    uint64_t t = ((uint64_t)n + live - 1) / live * live;
    return t > SY_CLUSTER_MAX_SAMPLES ? n : (uint32_t)t;
}

static void cluster_restart(void *state) { ((cluster_state *)state)->restart = true; }

static sy_result cluster_render(void *state, const sy_render_request *req, sy_layer *layer, sy_error *err)
{
    cluster_state *st = state;
    uint32_t live = sy_cluster_client_live(st->client);
    sy_cluster_frame f = {.mode = st->mode,
                          .backend = st->backend,
                          .params = st->params[0] ? st->params : NULL,
                          .root_id = st->root_id,
                          .background_id = req->background_id,
                          .camera = req->camera,
                          .width = req->full_width,
                          .height = req->full_height,
                          .samples = st->mode == SY_CLUSTER_COOPERATIVE ? st->samples : req->sample_count,
                          /* cooperative: the request's samples, split across the live servers, rounded up to
                           * a multiple of their number: a server left without samples in a frame would
                           * leave its accumulation out of the merged image */
                          .samples_total = st->mode == SY_CLUSTER_COOPERATIVE ? coop_total(req->sample_count, live) : 0,
                          .seed = req->seed,
                          .depth = true,
                          .half = st->half,
                          .restart = st->restart};
    bool whole = req->rect_x == 0 && req->rect_y == 0 && req->rect_w == req->full_width && req->rect_h == req->full_height;
    sy_layer *out = layer;
    sy_result r = SY_OK;
    if (!whole) {
        if (st->full.width != req->full_width || st->full.height != req->full_height) {
            sy_layer_destroy(&st->full);
            r = sy_layer_create(req->full_width, req->full_height, &st->full, err);
        }
        out = &st->full;
    }
    if (r == SY_OK) sy_layer_clear(out);
    bool adaptive = st->cfg->opts.timeout_ms == 0;
    if (adaptive) sy_cluster_client_set_timeout(st->client, st->timeout_ms);
    if (r == SY_OK) r = sy_cluster_client_render(st->client, &f, out, &st->last, err);
    if (adaptive) {
        /* the next deadline: generous next to this frame's time (1 s + 4x), doubled after a failure (a
         * server that rejoins needs a snapshot and a first translation), within 1..60 s */
        double next = r != SY_OK || st->last.servers_failed ? 2.0 * st->timeout_ms : 1000.0 + 4000.0 * st->last.seconds;
        st->timeout_ms = next > 60000.0 ? 60000u : next < 1000.0 ? 1000u : (uint32_t)next;
    }
    if (r == SY_OK) st->restart = false;
    if (r == SY_OK && st->mode == SY_CLUSTER_COOPERATIVE) st->merged_samples = st->last.samples;
    if (r == SY_OK && !whole)
        for (uint32_t y = 0; y < req->rect_h; ++y) {
            size_t src = (size_t)(req->rect_y + y) * req->full_width + req->rect_x, dst = (size_t)y * req->rect_w;
            memcpy(layer->rgba + dst * 4, out->rgba + src * 4, (size_t)req->rect_w * 4 * sizeof(float));
            memcpy(layer->depth + dst, out->depth + src, (size_t)req->rect_w * sizeof(float));
        }
    if (req->progress && r == SY_OK) {
        sy_progress pr = {1, 1};
        req->progress(req->progress_user, &pr);
    }
    return r;
}

static void cluster_stats(void *state, sy_mediator_stats *out)
{
    cluster_state *st = state;
    out->samples = st->mode == SY_CLUSTER_COOPERATIVE ? st->merged_samples : (st->last.seconds > 0 ? 1 : 0);
}


void sy_mediator_cluster_last_frame(void *state, sy_cluster_frame_stats *out)
{
    memset(out, 0, sizeof *out);
    if (state) *out = ((cluster_state *)state)->last;
}

void sy_mediator_cluster_describe(void *state, uint32_t *mode, uint32_t *servers)
{
    const cluster_state *st = state;
    if (mode) *mode = st ? st->mode : 0;
    if (servers) *servers = st ? st->servers : 0;
}

static void config_free(cluster_config *c)
{
    if (!c) return;
    for (uint32_t i = 0; i < SY_CLUSTER_MAX_SERVERS; ++i) free(c->urls[i]), free(c->backends[i]);
    free(c->secret);
    free(c->tls_ca);
    free(c);
}

sy_result sy_mediator_cluster_register(const char *name, const sy_cluster_client_opts *opts, sy_error *err)
{
    if (!name || !name[0] || strlen(name) >= 32)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cluster register: a name of 1..31 characters is needed");
    if (!opts || !opts->url_count || opts->url_count > SY_CLUSTER_MAX_SERVERS)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "cluster register: between 1 and %u server URLs needed",
                            SY_CLUSTER_MAX_SERVERS);
    cluster_config *c = calloc(1, sizeof *c);
    if (!c) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "cluster register: out of memory");
    bool oom = false;
    snprintf(c->name, sizeof c->name, "%s", name);
    c->opts = *opts;
    for (uint32_t i = 0; i < opts->url_count; ++i) {
        c->urls[i] = strdup(opts->urls[i] ? opts->urls[i] : "");
        oom = oom || !c->urls[i];
        if (opts->backends && opts->backends[i]) oom = oom || !(c->backends[i] = strdup(opts->backends[i]));
        if (opts->wall_tiles) c->tiles[i] = opts->wall_tiles[i];
    }
    if (opts->secret_len) {
        c->secret = malloc(opts->secret_len);
        if (c->secret) memcpy(c->secret, opts->secret, opts->secret_len);
        else oom = true;
    }
    if (opts->tls_ca_file) oom = oom || !(c->tls_ca = strdup(opts->tls_ca_file));
    if (oom) {
        config_free(c);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "cluster register: out of memory");
    }
    c->opts.urls = (const char *const *)c->urls;
    c->opts.backends = (const char *const *)c->backends;
    c->opts.wall_tiles = c->tiles;
    c->opts.secret = c->secret;
    c->opts.tls_ca_file = c->tls_ca;
    c->cls = (sy_mediator_class){.name = c->name,
                                 .caps = SY_CAP_REMOTE | SY_CAP_TILES,
                                 .create = cluster_create,
                                 .destroy = cluster_destroy,
                                 .sync = cluster_sync,
                                 .render = cluster_render,
                                 .stats = cluster_stats,
                                 .caps_of = cluster_caps_of,
                                 .pick = cluster_pick,
                                 .restart = cluster_restart,
                                 .user = c,
                                 .param_table = cluster_table,
                                 .check_params = cluster_check_params};
    sy_result r = sy_mediator_register(&c->cls, err);
    if (r) config_free(c); /* the registry keeps a registered class (and so its configuration) for good */
    return r;
}
