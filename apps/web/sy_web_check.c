/* sy_web_check.c — sy web's checks of untrusted requests and messages as pure functions (see
 * sy_web_check.h): the raw head, the request's decision, the WebSocket input messages. */
#include "sy_web_check.h"
#include "sy_web_assets.h"

#include "sy_bookmarks.h"

#include <arpa/inet.h>
#include <cjson/cJSON.h>
#include <math.h>
#include <sodium.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#define WEB_COOKIE "sy_token"

/* >>head */
static bool is_tchar(unsigned char c)
{
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || (c && strchr("!#$%&'*+-.^_`|~", c));
}

static sy_web_scan refuse(sy_web_head_info *info, int status, const char *why)
{
    info->status = status;
    snprintf(info->reason, sizeof info->reason, "%s", why);
    return SY_WEB_SCAN_REFUSE;
}

static bool name_is(const char *name, size_t n, const char *want)
{
    return n == strlen(want) && !strncasecmp(name, want, n);
}

/* The request line: METHOD SP TARGET SP HTTP/1.x; SY_WEB_SCAN_MORE when it is fine. */
static sy_web_scan scan_request_line(const char *l, size_t n, sy_web_head_info *info)
{
    size_t m = 0;
    while (m < n && l[m] >= 'A' && l[m] <= 'Z') m++;
    if (m == 0 || m >= n || l[m] != ' ') return refuse(info, 400, "the request line is not METHOD PATH HTTP/1.x");
    bool get = m == 3 && !memcmp(l, "GET", 3);
    info->post = m == 4 && !memcmp(l, "POST", 4);
    size_t t = m + 1, e = t, path_end = SIZE_MAX;
    while (e < n && l[e] != ' ') {
        unsigned char c = (unsigned char)l[e];
        if (c <= 0x20 || c >= 0x7f) return refuse(info, 400, "the request target holds a control, space or non-ASCII byte");
        if (c == '?' && path_end == SIZE_MAX) path_end = e;
        e++;
    }
    if (path_end == SIZE_MAX) path_end = e;
    if (e == t || l[t] != '/') return refuse(info, 400, "the request target must be a path starting with /");
    if (path_end - t >= SY_WEB_MAX_PATH) {
        snprintf(info->reason, sizeof info->reason, "the path has %zu bytes (at most %u)", path_end - t, SY_WEB_MAX_PATH - 1);
        info->status = 414;
        return SY_WEB_SCAN_REFUSE;
    }
    if (n - e != 9 || memcmp(l + e, " HTTP/1.", 8) || (l[e + 8] != '0' && l[e + 8] != '1'))
        return refuse(info, 400, "the request line must end in HTTP/1.0 or HTTP/1.1");
    if (!get && !info->post) return refuse(info, 405, "only GET and POST are served");
    return SY_WEB_SCAN_MORE;
}

/* One header line (without its CRLF). */
static sy_web_scan scan_header(const char *l, size_t n, sy_web_head_info *info)
{
    if (n && (l[0] == ' ' || l[0] == '\t')) return refuse(info, 400, "folded header lines are not accepted");
    size_t k = 0;
    while (k < n && is_tchar((unsigned char)l[k])) k++;
    if (k == n || l[k] != ':') return refuse(info, 400, "a header line is not NAME: VALUE");
    if (k < 2) return refuse(info, 400, "header names of one character are not accepted");
    for (size_t i = k + 1; i < n; ++i) {
        unsigned char c = (unsigned char)l[i];
        if ((c < 0x20 && c != '\t') || c == 0x7f) return refuse(info, 400, "a header value holds a control byte");
    }
    const char *v = l + k + 1;
    size_t vn = n - k - 1;
    while (vn && (*v == ' ' || *v == '\t')) v++, vn--;
    while (vn && (v[vn - 1] == ' ' || v[vn - 1] == '\t')) vn--;
    if (name_is(l, k, "content-length")) {
        if (info->has_length) return refuse(info, 400, "Content-Length is given twice");
        if (vn == 0 || vn > 18) return refuse(info, 400, "Content-Length is not a number of bytes");
        uint64_t x = 0;
        for (size_t i = 0; i < vn; ++i) {
            if (v[i] < '0' || v[i] > '9') return refuse(info, 400, "Content-Length is not a number of bytes");
            x = x * 10 + (uint64_t)(v[i] - '0');
        }
        info->has_length = true, info->content_length = x;
    } else if (name_is(l, k, "transfer-encoding")) {
        return refuse(info, 501, "Transfer-Encoding is not supported: send a Content-Length");
    } else if (name_is(l, k, "upgrade")) {
        info->upgrade = true;
    }
    return SY_WEB_SCAN_MORE;
}

sy_web_scan sy_web_head_scan(const char *buf, size_t len, sy_web_head_info *info)
{
    memset(info, 0, sizeof *info);
    size_t at = 0;
    for (unsigned line = 0;; ++line) {
        /* the next CRLF; a bare CR or LF, or a NUL, is refused */
        size_t e = at;
        while (e < len && buf[e] != '\r' && buf[e] != '\n' && buf[e] != 0) e++;
        if (e < len && buf[e] == 0) return refuse(info, 400, "the request head holds a NUL byte");
        if (e >= len || e + 1 >= len) { /* no complete line yet */
            if (e < len && buf[e] == '\n') return refuse(info, 400, "a line ends in LF without CR");
            if (len >= SY_WEB_MAX_HEAD) return refuse(info, 431, "the request head exceeds 8192 bytes");
            return SY_WEB_SCAN_MORE;
        }
        if (buf[e] != '\r' || buf[e + 1] != '\n') return refuse(info, 400, "a line does not end in CRLF");
        if (e + 2 > SY_WEB_MAX_HEAD) return refuse(info, 431, "the request head exceeds 8192 bytes");
        sy_web_scan s;
        if (line == 0) s = scan_request_line(buf + at, e - at, info);
        else if (e == at) { /* the blank line: the head is complete */
            info->head_len = e + 2;
            if (info->post && !info->has_length) return refuse(info, 411, "a POST needs a Content-Length");
            return SY_WEB_SCAN_COMPLETE;
        } else s = scan_header(buf + at, e - at, info);
        if (s == SY_WEB_SCAN_REFUSE) return s;
        at = e + 2;
    }
}

/* >>host, origin, content type, token */
bool sy_web_name_is_loopback(const char *name)
{
    if (!strcasecmp(name, "localhost")) return true;
    struct in_addr a4;
    struct in6_addr a6;
    if (inet_pton(AF_INET, name, &a4) == 1) return (ntohl(a4.s_addr) >> 24) == 127;
    if (inet_pton(AF_INET6, name, &a6) == 1) return !memcmp(&a6, &in6addr_loopback, sizeof a6);
    return false;
}

bool sy_web_host_is_loopback(const char *host)
{
    if (!host) return false;
    char name[64];
    const char *port = NULL;
    size_t n;
    if (host[0] == '[') {
        const char *e = strchr(host, ']');
        if (!e) return false;
        n = (size_t)(e - host - 1);
        if (n == 0 || n >= sizeof name) return false;
        memcpy(name, host + 1, n);
        name[n] = 0;
        if (!strchr(name, ':')) return false; /* brackets hold an IPv6 address */
        if (e[1] == ':') port = e + 2;
        else if (e[1]) return false;
    } else {
        const char *c = strchr(host, ':');
        n = c ? (size_t)(c - host) : strlen(host);
        if (n == 0 || n >= sizeof name) return false;
        memcpy(name, host, n);
        name[n] = 0;
        if (c) port = c + 1;
    }
    if (port) {
        size_t d = strlen(port);
        if (d < 1 || d > 5 || strspn(port, "0123456789") != d || atoi(port) > 65535) return false;
    }
    if (host[0] != '[') {
        /* without brackets: 127.x.y.z (four decimal parts) or localhost */
        if (!strcasecmp(name, "localhost")) return true;
        int parts = 1;
        for (const char *p = name; *p; ++p)
            if (*p == '.') parts++;
            else if (*p < '0' || *p > '9') return false;
        if (parts != 4) return false;
    }
    return sy_web_name_is_loopback(name);
}

bool sy_web_origin_is_same(const char *origin, const char *host)
{
    if (!origin || !host || !host[0]) return false;
    const char *o = !strncasecmp(origin, "http://", 7) ? origin + 7 : !strncasecmp(origin, "https://", 8) ? origin + 8 : NULL;
    return o && !strcasecmp(o, host);
}

bool sy_web_content_type_is_json(const char *ct)
{
    if (!ct) return false;
    while (*ct == ' ' || *ct == '\t') ct++;
    size_t n = strlen("application/json");
    if (strncasecmp(ct, "application/json", n)) return false;
    char c = ct[n];
    return c == 0 || c == ';' || c == ' ' || c == '\t';
}

int sy_web_token_verdict(const char *given, size_t len, const char *expected)
{
    if (!expected || !expected[0]) return 1;
    if (!given || len == 0) return 0;
    size_t tl = strlen(expected);
    if (len > SY_WEB_MAX_TOKEN || len != tl) return -1;
    return sodium_memcmp(given, expected, tl) == 0 ? 1 : -1;
}

bool sy_web_query_arg(const char *query, const char *name, const char **value, size_t *len)
{
    size_t nl = strlen(name);
    for (const char *p = query; p && *p;) {
        const char *e = strchr(p, '&');
        size_t n = e ? (size_t)(e - p) : strlen(p);
        if (n > nl && !strncmp(p, name, nl) && p[nl] == '=') {
            *value = p + nl + 1, *len = n - nl - 1;
            return true;
        }
        p = e ? e + 1 : NULL;
    }
    return false;
}

bool sy_web_cookie_token(const char *cookie, const char **value, size_t *len)
{
    const size_t cl = strlen(WEB_COOKIE "=");
    for (const char *p = cookie; p && (p = strstr(p, WEB_COOKIE "=")) != NULL; p += cl) {
        if (p != cookie && p[-1] != ' ' && p[-1] != ';') continue;
        *value = p + cl, *len = strcspn(p + cl, "; ");
        return true;
    }
    return false;
}

/* >>request */
static void refused(sy_web_verdict *v, int status, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static void refused(sy_web_verdict *v, int status, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(v->reason, sizeof v->reason, fmt, ap);
    va_end(ap);
    v->target = SY_WEB_TARGET_REFUSED;
    v->status = status;
}

static const sy_web_route *find_route(const sy_web_policy *p, const char *method, const char *path)
{
    for (uint32_t i = 0; i < p->route_count; ++i) {
        const sy_web_route *r = &p->routes[i];
        size_t n = strlen(r->path);
        if (strcmp(r->method, method) != 0) continue;
        if (n && r->path[n - 1] == '/' ? !strncmp(path, r->path, n) : !strcmp(path, r->path)) return r;
    }
    return NULL;
}

/* The still's side from the query: decimal digits, 1..max. */
static bool still_side(const char *query, const char *name, uint32_t max, uint32_t *out, sy_web_verdict *v)
{
    const char *s;
    size_t n;
    if (!sy_web_query_arg(query, name, &s, &n)) {
        refused(v, 400, "missing %s= (the still's size: /api/frame.jpg?w=W&h=H)", name);
        return false;
    }
    uint64_t x = 0;
    bool ok = n >= 1 && n <= 9;
    for (size_t i = 0; ok && i < n; ++i) {
        ok = s[i] >= '0' && s[i] <= '9';
        x = x * 10 + (uint64_t)(s[i] - '0');
    }
    if (!ok || x < 1 || x > max) {
        refused(v, 400, "%s='%.*s' is not a size in 1..%u", name, (int)(n > 20 ? 20 : n), s, max);
        return false;
    }
    *out = (uint32_t)x;
    return true;
}

const sy_web_asset *sy_web_asset_find(const char *path)
{
    if (!strcmp(path, "/")) path = "/index.html";
    for (size_t i = 0; i < sy_web_asset_count; ++i)
        if (!strcmp(path, sy_web_assets[i].path)) return &sy_web_assets[i];
    return NULL;
}

/* A costly or state-changing request: a same-origin Origin, or no Origin and a right token. */
static bool same_origin_or_token(const sy_web_head *h, const sy_web_verdict *v, bool token_required)
{
    if (h->origin) return sy_web_origin_is_same(h->origin, h->host);
    /* a browser's same-origin GET carries no Origin but says Sec-Fetch-Site (no script can set it) */
    if (h->fetch_site && !strcasecmp(h->fetch_site, "same-origin") && h->method && !strcmp(h->method, "GET") && !h->upgrade)
        return true;
    return token_required && v->token == 1;
}

void sy_web_check_request(const sy_web_policy *p, const sy_web_head *h, sy_web_verdict *v)
{
    memset(v, 0, sizeof *v);
    const char *path = h->path ? h->path : "";
    const char *query = h->query ? h->query : "";
    bool token_required = p->token && p->token[0];
    if (h->path_len >= SY_WEB_MAX_PATH || strlen(path) != h->path_len)
        return refused(v, 414, "the path has %zu bytes (at most %u)", h->path_len, SY_WEB_MAX_PATH - 1);
    if (!token_required && !sy_web_host_is_loopback(h->host))
        return refused(v, 403, "this server answers requests for a loopback host only (Host: %.64s)", h->host ? h->host : "none");
    const char *t = NULL;
    size_t tn = 0;
    v->token_in_query = sy_web_query_arg(query, "token", &t, &tn) && tn > 0;
    if (!v->token_in_query && h->cookie && !sy_web_cookie_token(h->cookie, &t, &tn)) t = NULL, tn = 0;
    v->token = sy_web_token_verdict(t, tn, p->token);
    if (v->token != 1) {
        v->token_page = true;
        return refused(v, v->token == 0 ? 401 : 403, "access token %s", v->token == 0 ? "missing" : "wrong");
    }
    bool get = h->method && !strcmp(h->method, "GET"), post = h->method && !strcmp(h->method, "POST");
    if (!get && !post) return refused(v, 405, "only GET and POST are served");
    if (h->upgrade) {
        if (!get || strcmp(path, "/ws") != 0) return refused(v, 404, "WebSocket upgrades are served at /ws only (not %.64s)", path);
        if (!same_origin_or_token(h, v, token_required))
            return refused(v, 403, h->origin ? "a WebSocket from the foreign origin %.100s" : "a WebSocket without Origin%s",
                           h->origin ? h->origin : " (and no token)");
        v->target = SY_WEB_TARGET_STREAM;
        return;
    }
    if (post) {
        const sy_web_route *r = find_route(p, "POST", path);
        if (!r) return refused(v, 404, "no POST route %.100s", path);
        if (!same_origin_or_token(h, v, token_required))
            return refused(v, 403, h->origin ? "a POST from the foreign origin %.100s" : "a POST without Origin%s",
                           h->origin ? h->origin : " (and no token)");
        if (!sy_web_content_type_is_json(h->content_type))
            return refused(v, 415, "a POST must have Content-Type: application/json (not %.60s)",
                           h->content_type ? h->content_type : "none");
        if (h->has_length && h->content_length > p->max_body)
            return refused(v, 413, "request body of %llu bytes exceeds the limit of %zu bytes",
                           (unsigned long long)h->content_length, p->max_body);
        v->target = SY_WEB_TARGET_ROUTE, v->route = r;
        return;
    }
    if ((v->asset = sy_web_asset_find(path)) != NULL) {
        v->target = SY_WEB_TARGET_ASSET;
        return;
    }
    if (!strcmp(path, "/api/latest.jpg")) { /* costs a copy of bytes already made, but shows the view */
        if (!same_origin_or_token(h, v, token_required))
            return refused(v, 403, h->origin ? "the latest frame for the foreign origin %.100s" : "the latest frame without Origin%s",
                           h->origin ? h->origin : " (and no token)");
        v->target = SY_WEB_TARGET_LATEST;
        return;
    }
    if (!strcmp(path, "/api/frame.jpg")) {
        if (!same_origin_or_token(h, v, token_required))
            return refused(v, 403, h->origin ? "a still for the foreign origin %.100s" : "a still without Origin%s",
                           h->origin ? h->origin : " (and no token)");
        uint32_t w = 0, hh = 0;
        if (!still_side(query, "w", p->still_max_w, &w, v) || !still_side(query, "h", p->still_max_h, &hh, v)) return;
        if ((uint64_t)w * hh > p->still_max_pixels)
            return refused(v, 413, "a still of %ux%u is %llu pixels, more than the budget of %llu per request", w, hh,
                           (unsigned long long)w * hh, (unsigned long long)p->still_max_pixels);
        v->target = SY_WEB_TARGET_STILL, v->still_w = w, v->still_h = hh;
        return;
    }
    const sy_web_route *r = find_route(p, "GET", path);
    if (r) {
        v->target = SY_WEB_TARGET_ROUTE, v->route = r;
        return;
    }
    refused(v, 404, "not found: %.100s", path);
}

/* >>messages */
static bool json_num(const cJSON *o, const char *key, double lo, double hi, double *out)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
    if (!cJSON_IsNumber(v) || !isfinite(v->valuedouble) || v->valuedouble < lo || v->valuedouble > hi) return false;
    *out = v->valuedouble;
    return true;
}

/* An optional boolean (absent: false). */
static bool json_bool(const cJSON *o, const char *key, bool *out)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
    *out = cJSON_IsTrue(v);
    return !v || cJSON_IsBool(v);
}

/* A drag's or lead message's "lead": [DX, DY] within +-SY_WEB_LEAD_MAX (absent: [0, 0] where optional). */
static bool json_lead(const cJSON *o, bool required, double out[2])
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, "lead");
    out[0] = out[1] = 0;
    if (!v) return !required;
    if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != 2) return false;
    for (int k = 0; k < 2; ++k) {
        const cJSON *e = cJSON_GetArrayItem(v, k);
        if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble) || fabs(e->valuedouble) > SY_WEB_LEAD_MAX) return false;
        out[k] = e->valuedouble;
    }
    return true;
}

/* An optional request number "seq" (absent: 0). */
static bool json_seq(const cJSON *o, uint32_t *out)
{
    double s = 0;
    *out = 0;
    if (!cJSON_GetObjectItemCaseSensitive(o, "seq")) return true;
    if (!json_num(o, "seq", 0, 2147483647.0, &s) || s != floor(s)) return false;
    *out = (uint32_t)s;
    return true;
}

/* "planes": an array of at most SY_CLIP_PLANES_MAX arrays of 4 numbers, each plane as
 * sy_clip_planes_check takes it (finite, within SY_COORD_MAX, a non-zero normal). */
static sy_result parse_planes(const cJSON *m, sy_web_input *out, sy_error *err)
{
    const cJSON *ps = cJSON_GetObjectItemCaseSensitive(m, "planes");
    if (!cJSON_IsArray(ps)) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "clip: planes must be an array of [a, b, c, d]");
    int n = cJSON_GetArraySize(ps);
    if (n > SY_CLIP_PLANES_MAX)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "clip: %d planes, at most %d", n, SY_CLIP_PLANES_MAX);
    for (int i = 0; i < n; ++i) {
        const cJSON *p = cJSON_GetArrayItem(ps, i);
        if (!cJSON_IsArray(p) || cJSON_GetArraySize(p) != 4)
            return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "clip: plane %d is not [a, b, c, d]", i);
        for (int k = 0; k < 4; ++k) {
            const cJSON *v = cJSON_GetArrayItem(p, k);
            if (!cJSON_IsNumber(v)) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "clip: plane %d value %d is not a number", i, k);
            double d = v->valuedouble;
            /* NaN and infinities (cJSON reads 1e999 as inf) are caught by sy_clip_planes_check */
            out->planes[i][k] = isfinite(d) && fabs(d) <= 3.4e38 ? (float)d : (float)NAN;
        }
    }
    out->plane_count = (uint32_t)n;
    sy_error ce = {0};
    if (sy_clip_planes_check((const float(*)[4])out->planes, out->plane_count, &ce) != SY_OK)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "clip: %.200s", ce.message);
    return SY_OK;
}

/* "cap" (optional): absent leaves capping as it is; false or null turns it off; [r, g, b] (linear RGB,
 * each in [0, 1], as sy_clip_cap_check takes it) turns it on in that colour. */
static sy_result parse_cap(const cJSON *m, sy_web_input *out, sy_error *err)
{
    const cJSON *c = cJSON_GetObjectItemCaseSensitive(m, "cap");
    out->cap = SY_WEB_CAP_KEEP;
    if (!c) return SY_OK;
    if (cJSON_IsFalse(c) || cJSON_IsNull(c)) {
        out->cap = SY_WEB_CAP_OFF;
        return SY_OK;
    }
    if (!cJSON_IsArray(c) || cJSON_GetArraySize(c) != 3)
        return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "clip: cap must be false or [r, g, b] (linear, 0..1)");
    for (int k = 0; k < 3; ++k) {
        const cJSON *v = cJSON_GetArrayItem(c, k);
        if (!cJSON_IsNumber(v)) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "clip: cap value %d is not a number", k);
        double d = v->valuedouble;
        out->cap_rgb[k] = isfinite(d) && fabs(d) <= 3.4e38 ? (float)d : (float)NAN;
    }
    sy_error ce = {0};
    if (sy_clip_cap_check(out->cap_rgb, &ce) != SY_OK) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "clip: cap: %.200s", ce.message);
    out->cap = SY_WEB_CAP_ON;
    return SY_OK;
}

bool sy_web_input_changes_scene(const sy_web_input *in)
{
    switch (in->type) {
    case SY_WEB_INPUT_VISIBLE:
    case SY_WEB_INPUT_SELECT:
    case SY_WEB_INPUT_ISOLATE:
    case SY_WEB_INPUT_CLIP:
    case SY_WEB_INPUT_EXPOSURE:
    case SY_WEB_INPUT_ENVIRONMENT:
    case SY_WEB_INPUT_FILTER: return true;
    case SY_WEB_INPUT_KEY: return in->key != 'r'; /* back-ends and the filter keys; R is the camera */
    case SY_WEB_INPUT_VIEW: return in->on;        /* a save; a recall is the camera */
    default: return false;
    }
}

/* A size message's "codecs" (sy_web_input): plain short names are kept, anything else counted. */
static void ignore_codec(sy_web_input *out, const char *what)
{
    if (!out->codecs_ignored++) {
        size_t n = 0;
        for (; what[n] && n < sizeof out->codec_ignored - 1; ++n)
            out->codec_ignored[n] = what[n] >= 0x20 && what[n] < 0x7f && what[n] != '"' && what[n] != '\\' ? what[n] : '?';
        out->codec_ignored[n] = 0;
    }
}

static void parse_codecs(const cJSON *c, sy_web_input *out)
{
    if (!c) return;
    if (!cJSON_IsArray(c)) {
        ignore_codec(out, "codecs is no array");
        return;
    }
    const cJSON *e;
    cJSON_ArrayForEach(e, c) {
        const char *s = cJSON_IsString(e) ? e->valuestring : NULL;
        size_t n = s ? strlen(s) : 0;
        bool ok = n >= 1 && n < sizeof out->codecs[0] && out->codec_count < SY_WEB_MAX_CODECS;
        for (size_t i = 0; ok && i < n; ++i) ok = (s[i] >= 'a' && s[i] <= 'z') || (s[i] >= '0' && s[i] <= '9') || s[i] == '.';
        if (ok) memcpy(out->codecs[out->codec_count++], s, n + 1);
        else ignore_codec(out, s ? s : "an entry that is no string");
    }
}

sy_result sy_web_parse_input(const char *text, size_t len, sy_web_input *out, sy_error *err)
{
    memset(out, 0, sizeof *out);
    cJSON *m = cJSON_ParseWithLength(text, len);
    const cJSON *t = m ? cJSON_GetObjectItemCaseSensitive(m, "t") : NULL;
    if (!cJSON_IsObject(m) || !cJSON_IsString(t)) {
        cJSON_Delete(m);
        return sy_error_set(err, SY_ERR_PARSE, "not a JSON object with a string \"t\"");
    }
    double id = 0, btn = 0, ver = 0;
    sy_result r = SY_OK;
    out->has_id = cJSON_GetObjectItemCaseSensitive(m, "id") != NULL;
    const char *type = t->valuestring;
    if (out->has_id && !json_num(m, "id", 0, 9007199254740991.0, &id))
        r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "\"id\" must be a whole number >= 0");
    else if (!strcmp(type, "size")) {
        out->type = SY_WEB_INPUT_SIZE;
        if (!json_num(m, "w", 1, 16384, &out->a) || !json_num(m, "h", 1, 16384, &out->b))
            r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "size: w and h must be 1..16384");
        else if (cJSON_GetObjectItemCaseSensitive(m, "v") && (!json_num(m, "v", 0, 1000, &ver) || ver != floor(ver)))
            r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "size: v must be a whole number 0..1000");
        out->version = (uint32_t)ver;
        const cJSON *wp = cJSON_GetObjectItemCaseSensitive(m, "warp");
        if (r == SY_OK && wp && !cJSON_IsBool(wp)) r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "size: warp must be true or false");
        out->warp = cJSON_IsTrue(wp);
        if (r == SY_OK) parse_codecs(cJSON_GetObjectItemCaseSensitive(m, "codecs"), out);
    } else if (!strcmp(type, "keyframe")) {
        out->type = SY_WEB_INPUT_KEYFRAME;
    } else if (!strcmp(type, "drag") || !strcmp(type, "lead")) {
        bool drag = type[0] == 'd';
        out->type = drag ? SY_WEB_INPUT_DRAG : SY_WEB_INPUT_LEAD;
        if (drag && (!json_num(m, "dx", -1e5, 1e5, &out->a) || !json_num(m, "dy", -1e5, 1e5, &out->b)))
            r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "drag: dx and dy must be numbers within +-1e5");
        else if (cJSON_GetObjectItemCaseSensitive(m, "b") && (!json_num(m, "b", 0, 2, &btn) || btn != floor(btn)))
            r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: b must be 0, 1 or 2", type);
        else if (!json_lead(m, !drag, out->lead))
            r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: lead must be [dx, dy], numbers within +-%g", type, SY_WEB_LEAD_MAX);
        out->button = (uint32_t)btn;
    } else if (!strcmp(type, "wheel")) {
        out->type = SY_WEB_INPUT_WHEEL;
        if (!json_num(m, "steps", -50, 50, &out->a)) r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "wheel: steps must be -50..50");
    } else if (!strcmp(type, "key")) {
        out->type = SY_WEB_INPUT_KEY;
        const cJSON *k = cJSON_GetObjectItemCaseSensitive(m, "k");
        char key = cJSON_IsString(k) && k->valuestring[0] && !k->valuestring[1] ? k->valuestring[0] : 0;
        if (key == 'F' || key == 'R') key = (char)(key - 'A' + 'a');
        if (!((key >= '1' && key <= '9') || key == 'f' || key == '[' || key == ']' || key == 'r'))
            r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "key: k must be one of 1-9, f, [, ], r");
        out->key = key;
    } else if (!strcmp(type, "pick")) {
        out->type = SY_WEB_INPUT_PICK;
        /* the canvas point as fractions of its size: [0, 1) each (a pick outside is refused here) */
        if (!json_num(m, "x", 0, 1, &out->a) || !json_num(m, "y", 0, 1, &out->b) || out->a >= 1 || out->b >= 1)
            r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "pick: x and y must be fractions of the canvas in [0, 1)");
        else if (!json_bool(m, "select", &out->on) || !json_seq(m, &out->seq))
            r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "pick: select must be true or false, seq a whole number 0..2^31");
    } else if (!strcmp(type, "visible") || !strcmp(type, "select") || !strcmp(type, "isolate")) {
        out->type = type[0] == 'v' ? SY_WEB_INPUT_VISIBLE : type[0] == 's' ? SY_WEB_INPUT_SELECT : SY_WEB_INPUT_ISOLATE;
        double node = 0;
        double lo = out->type == SY_WEB_INPUT_VISIBLE ? 1 : 0;
        if (!json_num(m, "node", lo, SY_WEB_NODE_ID_MAX, &node) || node != floor(node))
            r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: node must be a node id (a whole number %s..%u)", type,
                             lo ? "1" : "0", SY_WEB_NODE_ID_MAX);
        else if (out->type != SY_WEB_INPUT_ISOLATE && !json_bool(m, "on", &out->on))
            r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: on must be true or false", type);
        out->node = (uint32_t)node;
        if (out->type == SY_WEB_INPUT_VISIBLE && !cJSON_GetObjectItemCaseSensitive(m, "on") && r == SY_OK)
            r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "visible: on is required");
    } else if (!strcmp(type, "clip")) {
        out->type = SY_WEB_INPUT_CLIP;
        r = parse_planes(m, out, err);
        if (r == SY_OK) r = parse_cap(m, out, err);
    } else if (!strcmp(type, "tree")) {
        out->type = SY_WEB_INPUT_TREE;
        double node = 0, offset = 0; /* both optional: absent, the scene's roots from the first */
        if (!json_seq(m, &out->seq)) r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "tree: seq must be a whole number 0..2^31");
        else if (cJSON_GetObjectItemCaseSensitive(m, "node") &&
                 (!json_num(m, "node", 0, SY_WEB_NODE_ID_MAX, &node) || node != floor(node)))
            r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "tree: node must be a node id (a whole number 0..%u)", SY_WEB_NODE_ID_MAX);
        else if (cJSON_GetObjectItemCaseSensitive(m, "offset") &&
                 (!json_num(m, "offset", 0, 2147483647.0, &offset) || offset != floor(offset)))
            r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "tree: offset must be a whole number 0..2^31");
        out->node = (uint32_t)node, out->offset = (uint32_t)offset;
    } else if (!strcmp(type, "exposure")) {
        out->type = SY_WEB_INPUT_EXPOSURE;
        if (!json_num(m, "stops", -SY_WEB_EXPOSURE_MAX, SY_WEB_EXPOSURE_MAX, &out->a))
            r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "exposure: stops must be a number within +-%g", SY_WEB_EXPOSURE_MAX);
    } else if (!strcmp(type, "time")) {
        out->type = SY_WEB_INPUT_TIME;
        if (!json_num(m, "s", -SY_WEB_TIME_MAX, SY_WEB_TIME_MAX, &out->a))
            r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "time: s must be a finite number of seconds within +-%g",
                             SY_WEB_TIME_MAX);
    } else if (!strcmp(type, "anim")) {
        out->type = SY_WEB_INPUT_ANIM;
        if (!json_num(m, "clip", -1, SY_WEB_CLIP_MAX, &out->a) || out->a != floor(out->a))
            r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "anim: clip must be an integer, -1 (every clip) .. %d", SY_WEB_CLIP_MAX);
    } else if (!strcmp(type, "play")) {
        out->type = SY_WEB_INPUT_PLAY;
        if (!cJSON_GetObjectItemCaseSensitive(m, "on") || !json_bool(m, "on", &out->on))
            r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "play: on must be true or false");
    } else if (!strcmp(type, "view")) {
        out->type = SY_WEB_INPUT_VIEW;
        double n = 0;
        if (!json_num(m, "n", 1, SY_BOOKMARKS_MAX, &n) || n != floor(n))
            r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "view: n must be a saved view's number, 1..%d", SY_BOOKMARKS_MAX);
        else if (!json_bool(m, "save", &out->on))
            r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "view: save must be true or false");
        out->slot = (uint32_t)n;
    } else if (!strcmp(type, "filter") || !strcmp(type, "environment")) {
        out->type = type[0] == 'f' ? SY_WEB_INPUT_FILTER : SY_WEB_INPUT_ENVIRONMENT;
        const cJSON *f = cJSON_GetObjectItemCaseSensitive(m, "name");
        size_t n = cJSON_IsString(f) ? strlen(f->valuestring) : 0;
        bool ok = n >= 1 && n < sizeof out->filter;
        for (size_t i = 0; ok && i < n; ++i) {
            char c = f->valuestring[i];
            ok = (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-' || c == '_';
        }
        if (!ok) r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "%s: name must be 1..31 of a-z, 0-9, '-', '_'", type);
        else memcpy(out->filter, f->valuestring, n + 1);
    } else {
        char tn[40];
        snprintf(tn, sizeof tn, "%.32s", type);
        r = sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "unknown type \"%s\"", tn);
    }
    out->id = (uint64_t)id;
    cJSON_Delete(m);
    return r;
}
