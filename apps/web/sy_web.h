/** @file
 * sy_web.h — the viewport in a web browser: an HTTP + WebSocket server (libwebsockets) that serves
 * one page whose canvas shows a back-end's view of a scene, streamed as JPEG frames; the page's
 * drags, wheel and keys steer the view. Stills (GET /api/frame.jpg?w=W&h=H) and routes added by the
 * embedding program (e.g. remote culling) are answered on the thread that owns the scene.
 * docs/WEB.md describes the protocol, the routes, the security model and the threads.
 *
 * One view for every client: all connected pages share one camera, back-end and display filter
 * (a desktop viewport mirrored on a tablet); the render size is the size the most recent page asked
 * for (capped at max_width x max_height), each page scales the frame to its canvas.
 *
 * Pages may also pick (sy_viewport_pick), show, hide, select and isolate nodes, set section planes
 * and the exposure, read the scene's hierarchy (docs/WEB.md, "The WebSocket protocol"), and play,
 * pause and scrub the scene clock when the scene has animations (the server then sets the scene's
 * time with sy_scene_set_time and commits, on the render thread; "The timeline"), and save and
 * recall views (bookmarks, sy_bookmarks.h: up to 9 that every page shares, kept in the file
 * sy_web_desc.bookmarks names as sy view keeps them; "Saved views"); a read_only server refuses
 * every change but the camera's and the clock's (view changes; recalling a saved view is one).
 *
 * Threads: sy_web_create starts the network thread (the libwebsockets service loop); the thread
 * that calls sy_web_run renders, and is the only one that touches the scene while it runs. The two
 * talk through a mutex-protected mailbox; the render thread wakes the service loop with
 * lws_cancel_service. A slow client never holds up the others: each connection is sent only the
 * newest frame when its socket can take one, older frames are dropped.
 *
 * Security (docs/WEB.md; the checks are the pure functions of sy_web_check.h): a gate thread
 * (sy_web_gate.h) holds each connection until its request head is whole (a budget per address, a
 * head deadline, malformed heads answered at once); a loopback address (the default 127.0.0.1) is
 * served to anyone on this machine whose Host header is a loopback host (127.0.0.0/8, [::1],
 * localhost); any other address needs a random access token (generated, printed in the URL) on
 * every request (?token=... or the cookie set by the first good request); POSTs, stills and
 * WebSocket upgrades need a same-origin Origin (or the token), POSTs a JSON Content-Type; stills
 * have a pixel budget per request and per client, wait behind the live view with a deadline and
 * are cancelled when the requester leaves; bodies, messages, connections and idle time are
 * limited.
 *
 * Ownership: the server borrows the scene (it must outlive the server). Responses of route
 * handlers are malloc()ed by the handler and freed by the server.
 * Thread-safety: sy_web_stop, sy_web_port and sy_web_url may be called from any thread; sy_web_run
 * from one thread at a time; sy_web_destroy after sy_web_run returned. */
#ifndef SY_WEB_H
#define SY_WEB_H

#include "sy_scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The default smallest resolution of a moving frame while every viewer's page warps
 * (sy_web_desc.min_scale, sy web --min-scale): half the display's side, not the governor's eighth.
 * Such a page answers every input itself by warping the last frames, so a frame's detail counts for
 * more than the server's frame rate (docs/WEB.md, "The estimate during an orbit": DamagedHelmet's
 * estimate SSIM 0.80-0.82 with the governor's 60 x 45 moving frames, 0.89 with 240 x 180, at the
 * same 2.5 frames a second on the 2-core machine). Viewers that do not warp (a page without
 * WebGL2, ?warp=0, other clients) keep the governor's floor for all. */
#define SY_WEB_MIN_SCALE 0.5f

/** A request given to a route handler (valid during the call). */
typedef struct sy_web_request {
    const char *method;   /**< "GET" or "POST" */
    const char *path;     /**< the URL path, e.g. "/api/object/12" (no query) */
    const char *query;    /**< the decoded query arguments, '&'-separated ("" if none) */
    const uint8_t *body;  /**< POST: the whole body (at most sy_web_desc.max_body bytes), else NULL */
    size_t body_len;      /**< its length */
    const char *peer;     /**< the client's address (for log messages) */
} sy_web_request;

/** A route handler's answer. The handler fills it; body is malloc()ed and taken by the server. */
typedef struct sy_web_response {
    int status;              /**< HTTP status (0 = 200) */
    char content_type[64];   /**< e.g. "application/json" ("" = application/octet-stream) */
    uint8_t *body;           /**< malloc()ed bytes (may be NULL when body_len is 0) */
    size_t body_len;         /**< their count */
} sy_web_response;

/** A route handler, called on the render thread (the scene's owner) between frames. A failure
 * (non-SY_OK) is answered with 400 (invalid argument, parse), 404 (not found), 413 (limit) or 500
 * and err's message as text; the response's body is freed then. */
typedef sy_result (*sy_web_handler)(void *user, sy_scene *scene, const sy_web_request *req, sy_web_response *resp,
                                    sy_error *err);

/** A route: requests whose method and path match go to fn on the render thread. */
typedef struct sy_web_route {
    const char *method; /**< "GET" or "POST" */
    const char *path;   /**< the exact path, or a prefix when it ends with '/' ("/api/object/") */
    sy_web_handler fn;  /**< the handler */
    void *user;         /**< passed to fn */
} sy_web_route;

/** What the server serves. Zero fields take the defaults named. Its strings are read during
 * sy_web_create only (the routes' strings excepted). */
typedef struct sy_web_desc {
    sy_scene *scene;          /**< borrowed; touched only by the thread in sy_web_run */
    sy_node root;             /**< {0}: every root */
    sy_node camera;           /**< a node carrying a camera: the view starts there (required) */
    sy_background background; /**< what the camera sees where nothing is hit ({0}: black, as sy_viewport_desc) */
    const char *backend;      /**< the initial back-end (a registered name; NULL: sy_mediator_default) */
    const char *listen;       /**< "HOST:PORT" (NULL: "127.0.0.1:8080"); port 0 = a free one */
    const char *token;        /**< access token (hex, >= 16 characters); NULL: generated when HOST is
                                   not a loopback address, none otherwise */
    uint32_t max_width;       /**< largest frame (default 1920) */
    uint32_t max_height;      /**< (default 1200) */
    uint32_t max_clients;     /**< WebSocket viewers at once (default 8) */
    size_t max_body;          /**< largest request body (default 1 MiB): 413 beyond */
    size_t max_message;       /**< largest WebSocket message (default 4096): the connection is closed */
    int quality;              /**< quality of streamed frames, 1..100 (default 80; stills: JPEG 95): JPEG's, and
                               *   the video stream's quantizer through sy_web_video_quantizer (80: 36) */
    double budget_ms;         /**< frame-time budget of the governor while the view moves (default 33) */
    float min_scale;          /**< smallest resolution of a moving frame while every viewer warps, a share of the
                               *   display's side (0, 1]; 0: SY_WEB_MIN_SCALE */
    uint32_t still_samples;   /**< samples per pixel of a progressive back-end's still (default 16) */
    uint32_t idle_timeout_s;  /**< a silent WebSocket is pinged, then closed after twice this (default 30) */
    const char *filter;       /**< initial display filter of a back-end with SY_CAP_FILTERS (NULL: none) */
    float threshold;          /**< its threshold (0: 0.01) */
    bool no_temporal;         /**< no temporal reuse on moving frames (sy_interactive_set_temporal) */
    uint64_t still_max_pixels; /**< a still's W x H at most (default 4194304, 2048 x 2048), per request
                                    and per client address (its queued and rendering stills together) */
    uint32_t still_deadline_ms; /**< a still not started within this (it waits behind the live view) is
                                    answered 503 (default 10000) */
    uint32_t head_timeout_ms;   /**< a connection's request head must arrive within (default 5000) */
    uint32_t max_pending;       /**< connections waiting for their head (default 128; 32 per address) */
    uint32_t delay_ms;          /**< TESTS ONLY (sy web --delay-ms): every input message is applied and
                                     every frame sent this much later (0..10000; 0 = none), an added
                                     network delay in both directions for measuring the page */
    bool read_only;           /**< viewers look (camera, scene clock, pick, tree, stills) but cannot change visibility,
                                   selection, section planes, exposure, display filter or back-end: those
                                   messages are refused with a log line (sy web --read-only) */
    const char *bookmarks;    /**< the saved views' file (sy_bookmarks.h; sy view's, sy web: SCENE.bookmarks or
                                   --bookmarks): read at create (missing: no views yet; unreadable: a warning, and
                                   views are then kept in memory only, the file left as it is), rewritten on each
                                   save; NULL: views last as long as the server */
    sy_animation clip;        /**< the clip the timeline plays ({0}: every clip together, as sy_scene_set_time;
                                   sy web: sy_cli_default_clip or --clip); a page may choose another ("anim") */
    const sy_web_route *routes; /**< extra routes (the array is copied; its strings and user pointers must outlive the server) */
    uint32_t route_count;     /**< how many */
} sy_web_desc;

/** The server (opaque). */
typedef struct sy_web sy_web;

/** Binds the address (apps/web/sy_web_gate.h takes the connections until their request is whole)
 * and starts the network thread. The server adds nothing to the scene; it changes only node flags
 * a page asks for (visibility, selection, isolation; not with read_only), once a page moves the
 * scene clock the animated fields (sy_scene_set_time), and the camera's field of view when a page
 * recalls a view saved with another one, and then commits the scene, on the render thread between
 * frames (the application commits its own changes).
 * Fails with a message naming the address when it cannot be bound, the back-end when it is not
 * registered, the option when a limit is out of range. */
sy_result sy_web_create(const sy_web_desc *desc, sy_web **out, sy_error *err);

/** The port the server listens on (useful with port 0). */
uint16_t sy_web_port(const sy_web *w);

/** The URL to open: "http://HOST:PORT/" plus "?token=..." when a token is required. Static in w. */
const char *sy_web_url(const sy_web *w);

/** Renders for the connected pages and answers stills and routes until sy_web_stop is called or
 * *stop (may be NULL) becomes non-zero (polled ten times a second). Returns the first error that
 * ends serving (a back-end that fails is reported to the pages and serving goes on). */
sy_result sy_web_run(sy_web *w, volatile int *stop, sy_error *err);

/** The view every page shares, as last rendered (a frame or a still; before the first, the
 * camera's pose): its camera-to-world matrix, and (camera, may be NULL) the application's camera
 * node whose camera gives the projection. The server sets the view on its viewports directly
 * (core/sy_interactive.h): it adds no node to the scene. Call on the render
 * thread (a route handler). */
void sy_web_view(const sy_web *w, sy_mat4 *camera_to_world, sy_node *camera);
/** What the view is lit and shown with beyond the scene: world, the background object the
 * server's viewports use now (the environment menu's choice: the start world, or the one the
 * server made for "studio" / "none"; {0}: none), and exposure_stops, the display chain's exposure
 * (before ACES tone mapping and sRGB). Call on the render thread (a route handler). */
void sy_web_look(const sy_web *w, sy_background *world, float *exposure_stops);
/** The server's counters (any thread): connections (sy_web_gate.h) and stills. */
typedef struct sy_web_stats {
    /** @{ connections accepted, handed to the HTTP server, refused, evicted and expired while
     * waiting for their head (sy_web_gate_stats) */
    uint64_t accepted, delivered, refused, evicted, expired; /** @} */
    uint32_t pending;          /**< connections waiting for their head now */
    uint64_t stills_done;      /**< stills answered with a JPEG */
    uint64_t stills_refused;   /**< over the per-client budget or the queue (429 / 503) */
    uint64_t stills_expired;   /**< not started within still_deadline_ms (503) */
    uint64_t stills_cancelled; /**< the requester left before or while it rendered */
    uint64_t requests_abandoned; /**< connections closed while their still or route was queued or running */
    uint32_t stills_queued;    /**< stills waiting now (the one rendering not counted) */
} sy_web_stats;
/** Fills *out with the server's counters now (any thread). */
void sy_web_stats_get(sy_web *w, sy_web_stats *out);

/** Makes sy_web_run return (any thread). */
void sy_web_stop(sy_web *w);

/** Stops the network thread, closes every connection, frees w (NULL-safe). */
void sy_web_destroy(sy_web *w);

#ifdef __cplusplus
}
#endif
#endif /* SY_WEB_H */
