/** @file
 * sy_web_check.h — the checks sy web applies to untrusted requests, as pure functions (no socket,
 * no server): the raw request head as it arrives (sy_web_head_scan: request line, header syntax,
 * lengths), the decision on a parsed request (sy_web_check_request: Host, token, Origin, Content-Type,
 * the route, the still's size and pixel budget) and the WebSocket input messages
 * (sy_web_parse_input). The server (sy_web_http.c, sy_web_ws.c) and the fuzz targets
 * (tests/fuzz/fuzz_web_*.c) call the same functions. docs/WEB.md ("Security", "Routes") lists what is checked.
 *
 * Ownership: nothing is allocated; outputs point into the inputs or are copied into the caller's
 * structs. Thread-safety: every function is reentrant. */
#ifndef SY_WEB_CHECK_H
#define SY_WEB_CHECK_H

#include "sy_web.h"

#include "sy_request.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Request paths (without the query) of this many bytes or more are refused with 414. */
#define SY_WEB_MAX_PATH 256u
/** The largest request head (request line and headers) read before a request is refused (431). */
#define SY_WEB_MAX_HEAD 8192u
/** Access tokens are at most this many characters; a longer one is wrong (403), never "missing". */
#define SY_WEB_MAX_TOKEN 127u

/** What sy_web_head_scan found in the bytes received so far. */
typedef enum sy_web_scan {
    SY_WEB_SCAN_MORE,     /**< the head is not complete yet: read more */
    SY_WEB_SCAN_COMPLETE, /**< a whole head (and *head_len bytes of it) */
    SY_WEB_SCAN_REFUSE    /**< refuse with status and reason at once */
} sy_web_scan;

/** The raw head's facts (sy_web_head_scan). */
typedef struct sy_web_head_info {
    size_t head_len;        /**< bytes of the head, its blank line included */
    uint64_t content_length; /**< the Content-Length (0 when absent) */
    bool has_length;        /**< a Content-Length was given */
    bool upgrade;           /**< an Upgrade header was given (a WebSocket handshake) */
    bool post;              /**< the method is POST */
    int status;             /**< SY_WEB_SCAN_REFUSE: the HTTP status (400, 405, 411, 414, 431, 501) */
    char reason[160];       /**< SY_WEB_SCAN_REFUSE: why */
} sy_web_head_info;

/** Scans the first len bytes a connection sent: the request line must be METHOD SP PATH SP
 * HTTP/1.x with a path under SY_WEB_MAX_PATH bytes; header lines must be NAME ":" VALUE with a
 * name of 2 or more token characters (libwebsockets' parser cannot take one-character names: it
 * would wait for the connection's timeout), no folded lines, no NUL or bare CR; at most one
 * Content-Length (digits), no Transfer-Encoding; the head at most SY_WEB_MAX_HEAD bytes. */
sy_web_scan sy_web_head_scan(const char *buf, size_t len, sy_web_head_info *info);

/** True when the Host header value names a loopback host: a literal IPv4 address in 127.0.0.0/8
 * (dotted decimal, four parts), [::1] in brackets, or "localhost" (any case), each with an
 * optional ":PORT" (1 to 5 digits, at most 65535). Nothing else ("127.attacker.example" is not). */
bool sy_web_host_is_loopback(const char *host);
/** True when name (no brackets, no port) is a loopback address or "localhost". */
bool sy_web_name_is_loopback(const char *name);
/** True when origin is "http://" or "https://" followed by exactly host (ASCII case ignored). */
bool sy_web_origin_is_same(const char *origin, const char *host);
/** True when the Content-Type's media type is application/json (parameters allowed). */
bool sy_web_content_type_is_json(const char *content_type);
/** The access token's verdict: 0 none given, 1 right, -1 wrong (a token of more than
 * SY_WEB_MAX_TOKEN characters is wrong). given may be NULL (none). Compared in constant time. */
int sy_web_token_verdict(const char *given, size_t given_len, const char *expected);
/** The value of the argument name ("token") in a decoded '&'-separated query: its start and
 * length; false when absent. */
bool sy_web_query_arg(const char *query, const char *name, const char **value, size_t *len);
/** The sy_token cookie's value in a Cookie header; false when absent. */
bool sy_web_cookie_token(const char *cookie, const char **value, size_t *len);

/** What a request asks for. */
typedef enum sy_web_target {
    SY_WEB_TARGET_REFUSED, /**< answered with verdict.status */
    SY_WEB_TARGET_ASSET,   /**< GET of the page or one of its files (verdict.asset) */
    SY_WEB_TARGET_STILL,   /**< GET /api/frame.jpg (size in the verdict) */
    SY_WEB_TARGET_LATEST,  /**< GET /api/latest.jpg: the newest streamed frame, no rendering */
    SY_WEB_TARGET_STREAM,  /**< the WebSocket upgrade at /ws */
    SY_WEB_TARGET_ROUTE    /**< a route of the embedding program (verdict.route) */
} sy_web_target;

/** A parsed request (header values NULL when absent). */
typedef struct sy_web_head {
    const char *method;       /**< "GET", "POST" or another */
    const char *path;         /**< the path without the query */
    size_t path_len;          /**< its length as sent (the copy may be cut: >= SY_WEB_MAX_PATH is refused) */
    const char *query;        /**< the decoded arguments, '&'-separated ("" none) */
    const char *host, *origin, *content_type, *cookie;
    const char *fetch_site;   /**< Sec-Fetch-Site (a browser's own: "same-origin" stands for a same-origin
                               *   Origin on a GET, which browsers send without Origin) */
    bool upgrade;             /**< a WebSocket upgrade */
    bool has_length;          /**< Content-Length given */
    uint64_t content_length;  /**< its value */
} sy_web_head;

/** What the server allows. */
typedef struct sy_web_policy {
    const char *token;           /**< "" or NULL: none required (a loopback server checks Host instead) */
    const sy_web_route *routes;  /**< the routes of the embedding program */
    uint32_t route_count;
    size_t max_body;             /**< largest POST body */
    uint32_t still_max_w, still_max_h; /**< largest still sides */
    uint64_t still_max_pixels;   /**< largest still (W x H) */
} sy_web_policy;

/** The decision on a request. */
typedef struct sy_web_verdict {
    sy_web_target target;
    int status;               /**< REFUSED: the HTTP status */
    int token;                /**< 0 missing, 1 right (or none required), -1 wrong */
    bool token_page;          /**< REFUSED for the token: answer with the page that says why */
    bool token_in_query;      /**< a right token came as ?token= (the server sets the cookie) */
    const sy_web_route *route; /**< ROUTE: which */
    const struct sy_web_asset *asset; /**< ASSET: which embedded file (sy_web_assets.h) */
    uint32_t still_w, still_h; /**< STILL: the size */
    char reason[200];         /**< REFUSED: why (names the header, argument or limit) */
} sy_web_verdict;

/** Decides a request, in this order: path length (414); Host (a loopback host when no token is
 * required, 403); the token (401 missing, 403 wrong); the method (GET or POST, 405); a WebSocket
 * upgrade only at /ws (404) with a same-origin Origin, or without Origin only with a right token
 * (403); POST: a route (404), a same-origin Origin or a right token (403), a JSON Content-Type
 * (415), a Content-Length within max_body (413); GET / and the page's files (/index.html,
 * /view.js, ...): the asset; GET /api/frame.jpg:
 * a same-origin Origin, Sec-Fetch-Site: same-origin (a page's own fetch) or a right token (403), w and h in 1..still_max_w/h and w x h within
 * still_max_pixels (400, 413); GET routes; else 404. */
void sy_web_check_request(const sy_web_policy *policy, const sy_web_head *head, sy_web_verdict *verdict);

/** A WebSocket input message (docs/WEB.md). */
typedef enum sy_web_input_type {
    SY_WEB_INPUT_SIZE, SY_WEB_INPUT_DRAG, SY_WEB_INPUT_WHEEL, SY_WEB_INPUT_KEY,
    SY_WEB_INPUT_PICK,     /**< what is under the canvas point (a, b) (fractions 0..1 of the canvas); select: select it */
    SY_WEB_INPUT_VISIBLE,  /**< show (on) or hide node */
    SY_WEB_INPUT_SELECT,   /**< select (on) or deselect node; node 0: clear the selection */
    SY_WEB_INPUT_ISOLATE,  /**< show only node (with its ancestors and subtree); node 0: show every node */
    SY_WEB_INPUT_CLIP,     /**< the section planes (plane_count of planes; 0: none) */
    SY_WEB_INPUT_TREE,     /**< asks for the scene's hierarchy below node (0: its roots) from offset, one page
                            * (answered with a "tree" message; docs/WEB.md) */
    SY_WEB_INPUT_EXPOSURE, /**< exposure in stops (a) */
    SY_WEB_INPUT_FILTER,   /**< the display filter by name (filter) */
    SY_WEB_INPUT_KEYFRAME, /**< {"t":"keyframe"}: the page's video decoder lost its place */
    SY_WEB_INPUT_TIME,     /**< {"t":"time","s":SECONDS}: the scene clock to that time (a; the range is the server's check) */
    SY_WEB_INPUT_PLAY,     /**< {"t":"play","on":BOOL}: the scene clock plays (on) or pauses */
    SY_WEB_INPUT_ENVIRONMENT, /**< the environment by name (filter: "scene", "studio", "none"; judged by the server) */
    SY_WEB_INPUT_ANIM,     /**< {"t":"anim","clip":N}: the clip the scene clock plays (a: N, an index of the
                            *   hello's "clips", -1 every clip; the index's range is the server's check) */
    SY_WEB_INPUT_VIEW,     /**< {"t":"view","n":N[,"save":true]}: a saved view (sy_bookmarks.h): slot N
                            *   (1..SY_BOOKMARKS_MAX) recalled, or (on) the view now saved there */
    SY_WEB_INPUT_LEAD      /**< {"t":"lead","lead":[DX,DY],"b":B}: the lead alone (lead, button; [0,0]: the
                            *   page rests), the camera as it is (docs/WEB.md, "Frames rendered ahead") */
} sy_web_input_type;

/** Node ids a page may name: 1..SY_WEB_NODE_ID_MAX (sy_node.id); unknown ones are refused later. */
#define SY_WEB_NODE_ID_MAX 0xFFFFFFFFu
/** The scene times a page may name, seconds (+-; the clip's range is checked by the server). */
#define SY_WEB_TIME_MAX 1e9
/** The clip indices a page may name ("anim": -1 = every clip; unknown ones are refused later). */
#define SY_WEB_CLIP_MAX 65535
/** The lead a page may ask for, pixels of drag each way (+-). */
#define SY_WEB_LEAD_MAX 4096.0
/** Exposure a page may set, in stops (+-). */
#define SY_WEB_EXPOSURE_MAX 16.0
/** The most codec names a size message may list ("codecs"); further ones are ignored. */
#define SY_WEB_MAX_CODECS 4u

/** A clip message's "cap": absent (capping stays as it is), false / null (off), [r, g, b] (on). */
typedef enum sy_web_cap { SY_WEB_CAP_KEEP = 0, SY_WEB_CAP_OFF, SY_WEB_CAP_ON } sy_web_cap;

typedef struct sy_web_input {
    sy_web_input_type type;
    double a, b;     /**< size: w, h; drag: dx, dy; wheel: steps; pick: x, y in [0, 1) of the canvas; exposure: stops;
                      * time: seconds (finite, within +-SY_WEB_TIME_MAX) */
    uint32_t button; /**< drag, lead: 0 orbit, 1 or 2 pan */
    double lead[2];  /**< drag, lead: "lead": [DX, DY], a drag of that many pixels more (same button) that
                      * the frames answering it are rendered ahead by, the camera staying where the drags
                      * put it; within +-SY_WEB_LEAD_MAX each (drag: absent = [0, 0]) */
    char key;        /**< key: '1'..'9', 'f', '[', ']', 'r' (lower case) */
    uint32_t version; /**< size: the frame format the page reads ("v", 0..1000; 0 = absent: a page
                       * older than frame format 3, refused with a status message) */
    bool warp;       /**< size: the page warps its last frames to each input ("warp": true; absent: false) */
    uint32_t node;   /**< visible, select, isolate: the node id (0 only for select / isolate: all);
                      * tree: the node whose children are listed (0 or absent: the scene's roots) */
    uint32_t slot;   /**< view: the saved view's number, 1..SY_BOOKMARKS_MAX */
    uint32_t offset; /**< tree: the first of those children (or roots) listed (0..2^31; absent: 0) */
    bool on;         /**< visible: show; select: select; pick: select what is hit; play: play (else pause);
                      *   view: save (else recall) */
    uint32_t seq;    /**< pick, tree: the page's request number, echoed in the answer (0..2^31) */
    uint32_t plane_count;             /**< clip: planes in use (0..SY_CLIP_PLANES_MAX) */
    float planes[SY_CLIP_PLANES_MAX][4]; /**< clip: {a, b, c, d}, checked by sy_clip_planes_check */
    sy_web_cap cap;                   /**< clip: what "cap" asks (absent: SY_WEB_CAP_KEEP) */
    float cap_rgb[3];                 /**< clip, SY_WEB_CAP_ON: the caps' linear RGB, checked by sy_clip_cap_check */
    char filter[32];                  /**< filter, environment: the name (letters, digits, '-', '_') */
    /** size: the video codecs the page decodes, best first ("codecs": an array of strings of 1..15
     * characters, [a-z0-9.]; the names are not judged here). Entries that are not such strings,
     * beyond SY_WEB_MAX_CODECS, or a "codecs" that is no array are not an error: they are counted
     * in codecs_ignored (the first one's text, cut and made printable, in codec_ignored) */
    char codecs[SY_WEB_MAX_CODECS][16];
    uint32_t codec_count, codecs_ignored;
    char codec_ignored[24];
    bool has_id;
    uint64_t id;
} sy_web_input;

/** True for the messages that change what other viewers see beyond the camera (visibility,
 * selection, section planes, exposure, display filter, environment; keys: back-ends and filter
 * keys; saving a view, which every page shares and the server writes to its file): refused by a
 * read-only server (sy_web_desc.read_only). A pick with select is allowed as a plain pick; the
 * scene clock (time, play) and recalling a saved view are view changes like the camera's: every
 * page may make them. */
bool sy_web_input_changes_scene(const sy_web_input *in);

/** Parses one text message (len bytes, not NUL-terminated); SY_ERR_PARSE / SY_ERR_INVALID_ARGUMENT
 * with the reason for a message that is not JSON, lacks "t", or has a field missing or out of range. */
sy_result sy_web_parse_input(const char *text, size_t len, sy_web_input *out, sy_error *err);

#ifdef __cplusplus
}
#endif
#endif /* SY_WEB_CHECK_H */
