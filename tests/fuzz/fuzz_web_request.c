/* fuzz_web_request.c — libFuzzer target for sy web's request handling without a socket: each input
 * is the bytes a connection sends. They go through the gate's raw-head check (sy_web_head_scan, on
 * the whole input and on its first half, as a head arriving in pieces), and a complete head is
 * split into its request line and headers as libwebsockets would and decided by
 * sy_web_check_request under two policies (loopback without a token; a token); a request that
 * reaches a route has its path and body parsed as the route does (/api/object/ID:
 * sy_cull_parse_id; /api/cull: sy_cull_parse_query, where sy web has the culling service). Any
 * verdict is fine; crashes, sanitizer reports, hangs and big allocations are not. */
#include "sy_web_check.h"
#ifdef SY_WEB_HAVE_CULL
#include "sy_cull.h"
#endif

#include <stdlib.h>
#include <string.h>
#include <strings.h>

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size);

static sy_result no_handler(void *u, sy_scene *s, const sy_web_request *q, sy_web_response *r, sy_error *e)
{
    (void)u, (void)s, (void)q, (void)r, (void)e;
    return SY_OK;
}

static const sy_web_route routes[] = {{"POST", "/api/cull", no_handler, NULL},
                                      {"GET", "/api/object/", no_handler, NULL},
                                      {"GET", "/api/view", no_handler, NULL},
                                      {"GET", "/api/pose", no_handler, NULL},
                                      {"GET", "/api/environment", no_handler, NULL},
                                      {"GET", "/client/", no_handler, NULL}};

/* the value of header name in the head (a copy in out), NULL when absent */
static const char *header(const char *head, const char *name, char *out, size_t len)
{
    size_t n = strlen(name);
    for (const char *l = strstr(head, "\r\n"); l && l[2] && !(l[2] == '\r'); l = strstr(l + 2, "\r\n")) {
        const char *p = l + 2;
        if (strncasecmp(p, name, n) || p[n] != ':') continue;
        p += n + 1;
        while (*p == ' ' || *p == '\t') p++;
        size_t k = strcspn(p, "\r");
        if (k >= len) k = len - 1;
        memcpy(out, p, k);
        out[k] = 0;
        return out;
    }
    return NULL;
}

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size)
{
    sy_web_head_info info;
    sy_web_head_scan((const char *)data, size / 2, &info);
    if (sy_web_head_scan((const char *)data, size, &info) != SY_WEB_SCAN_COMPLETE) return 0;
    char *head = malloc(info.head_len + 1);
    if (!head) return 0;
    memcpy(head, data, info.head_len);
    head[info.head_len] = 0;
    /* the request line: METHOD SP PATH[?QUERY] SP HTTP/1.x (the scan checked its shape) */
    char method[16] = "", path[SY_WEB_MAX_PATH + 8] = "", query[512] = "";
    size_t m = strcspn(head, " ");
    if (m < sizeof method) memcpy(method, head, m), method[m] = 0;
    const char *t = head + m + 1;
    size_t tn = strcspn(t, " "), pn = strcspn(t, "? ");
    size_t path_len = pn;
    if (pn >= sizeof path) pn = sizeof path - 1;
    memcpy(path, t, pn);
    path[pn] = 0;
    if (t[path_len] == '?') {
        size_t qn = tn - path_len - 1;
        if (qn >= sizeof query) qn = sizeof query - 1;
        memcpy(query, t + path_len + 1, qn);
        query[qn] = 0;
    }
    char host[256], origin[256], ctype[128], cookie[1024], upgrade[64];
    sy_web_head h = {.method = method, .path = path, .path_len = path_len, .query = query,
                     .host = header(head, "host", host, sizeof host), .origin = header(head, "origin", origin, sizeof origin),
                     .content_type = header(head, "content-type", ctype, sizeof ctype),
                     .cookie = header(head, "cookie", cookie, sizeof cookie),
                     .upgrade = header(head, "upgrade", upgrade, sizeof upgrade) != NULL,
                     .has_length = info.has_length, .content_length = info.content_length};
    const char *tokens[2] = {"", "0123456789abcdef0123456789abcdef"};
    for (int k = 0; k < 2; ++k) {
        sy_web_policy p = {.token = tokens[k], .routes = routes, .route_count = 4, .max_body = 1u << 16,
                           .still_max_w = 3840, .still_max_h = 2400, .still_max_pixels = 2048u * 2048u};
        sy_web_verdict v;
        sy_web_check_request(&p, &h, &v);
#ifdef SY_WEB_HAVE_CULL
        if (v.target == SY_WEB_TARGET_ROUTE && v.route == &routes[0]) {
            size_t body = size - info.head_len;
            if (info.content_length < body) body = (size_t)info.content_length;
            sy_cull_view view;
            uint64_t budget;
            sy_cull_parse_query((const char *)data + info.head_len, body, &view, &budget, NULL);
        } else if (v.target == SY_WEB_TARGET_ROUTE && v.route == &routes[1]) {
            uint32_t id;
            const char *s = path + strlen("/api/object/");
            sy_cull_parse_id(s, strlen(s), &id, NULL);
        }
#endif
    }
    free(head);
    return 0;
}
