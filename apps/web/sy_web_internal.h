/* sy_web_internal.h — INTERNAL to apps/web (not installed): what the modules of the sy_web server
 * (sy_web.h) share: the server's struct, the mailbox between the network and the render thread,
 * and the functions one module calls in another (prefix sy_webi_; none of them is API). The
 * modules, bottom-up (each calls only those before it; tests/core/layers_test.sh checks it), over
 * the request checks (sy_web_check.c), the gate (sy_web_gate.c), the frame format
 * (sy_web_frame.c: header, JPEG, depth; the page's reader mirrors it), the video encoder
 * (sy_web_video.c: VP8 / VP9 through libvpx, one per viewer) and the encoders' cost that the
 * governor is told (sy_web_cost.c):
 *   sy_web_mailbox.c  what the two threads share (under mu): jobs, frames
 *   sy_web_views.c    the saved views every page shares: their file, save, recall, the list
 *   sy_web_http.c     HTTP on the network thread: page, stills, routes, token, body collection
 *   sy_web_ws.c       WebSocket viewers: input messages in, newest frame out; the protocol table
 *                     and the network thread
 *   sy_web_scene.c    pages' picks, visibility, selection, planes and tree on the render thread
 *   sy_web_render.c   the render loop on the thread in sy_web_run (frames, stills, routes)
 *   sy_web.c          create / destroy, the accessors and the counters
 *   sy_web_thread.c   sy_web_run on a thread of its own (sy_web_thread.h) */
#ifndef SY_WEB_INTERNAL_H
#define SY_WEB_INTERNAL_H

#include "sy_web.h"

#include "sy_anim.h"
#include "sy_bookmarks.h"
#include "sy_interactive.h"
#include "sy_viewport.h"
#include "sy_web_check.h"
#include "sy_web_gate.h"

#include <libwebsockets.h>

#include <pthread.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define WEB_TOKEN_BYTES 16u

/* The mailbox: what the two threads share (sy_web_mailbox.c). */
typedef enum job_state { JOB_PENDING, JOB_RUNNING, JOB_FINISHED, JOB_DELIVERING } job_state;

/* A request answered on the render thread: a still or a route. Owned by the mailbox lists while
 * PENDING / RUNNING / FINISHED, by the HTTP connection while DELIVERING; a connection that closes
 * earlier marks it abandoned and whoever holds it next frees it. */
typedef struct web_job {
    struct web_job *next;
    job_state state;
    bool abandoned;
    struct lws *wsi;
    const sy_web_route *route; /* NULL: a still */
    uint32_t w, h;             /* still size */
    uint64_t pixels;           /* w x h */
    double queued_ms;          /* when the still was queued (sy_time_now, ms) */
    char method[8], path[256], query[512], peer[64];
    uint8_t *body;
    size_t body_len;
    sy_web_response resp;
} web_job;

/* The newest frame: LWS_PRE bytes of room, then the frame (sy_web_frame.h: header, JPEG, depth). Reference-counted:
 * the mailbox holds one reference, a connection sending it another (network thread). */
typedef struct web_frame {
    uint32_t refs; /* under mu */
    uint64_t seq, gen; /* gen: the input generation the frame answers */
    uint8_t *buf;
    size_t len; /* header + JPEG + depth */
    /* for the video viewers (docs/WEB.md, "The video stream"): the frame's pixels (RGBA8, NULL
     * when no viewer took video as it was rendered), its size, back-end, and where the depth
     * channel lies in buf (after LWS_PRE + header + jpeg_len) */
    uint8_t *rgba;
    uint32_t width, height, backend;
    size_t jpeg_len, depth_len;
    /* which depth channel the frame carries (0: none): frames with the same key carry the same
     * bytes, so a viewer sent one of them is sent the others without (SY_WEB_FRAME_SAME_DEPTH) */
    uint64_t depth_key;
} web_frame;

typedef struct web_conn web_conn;

/* A page's message that the render thread answers or applies to the scene (pick, visibility,
 * selection, isolate, section planes, tree): queued under mu with the connection's serial. */
typedef struct web_action {
    struct web_action *next;
    uint64_t conn; /* web_conn.serial of the sender */
    sy_web_input in;
    char peer[64];
} web_action;

/* A text answer for one connection (its serial), from the render thread; sent by the network
 * thread when the connection can take it, dropped when it has closed. */
typedef struct web_reply {
    struct web_reply *next;
    uint64_t conn;
    char *text; /* malloc()ed JSON */
} web_reply;

#define WEB_ACTIONS_MAX 256u /* actions queued, all connections (more are dropped with a log line) */
#define WEB_REPLIES_MAX 64u  /* answers waiting, all connections (more: the oldest is dropped, with a log line) */
#define WEB_REPLIES_PER_CONN 16u /* answers waiting for one connection (more: the new one is dropped, logged) */
/* One "tree" answer (sy_web_scene.c): at most WEB_TREE_PAGE of the listed node's children (or of
 * the roots) from the asked offset, each opened (its children listed below it, depth first) while
 * it has at most WEB_TREE_PAGE children and the answer stays within WEB_TREE_MAX nodes; the others
 * are sent closed with their child count, and the page asks for them when it is expanded. */
#define WEB_TREE_MAX 4096u
#define WEB_TREE_PAGE 512u
/* The environments the page's menu offers (sy_web_scene.c): "scene" (the world the server started
 * with: the scene's or the embedding program's), "studio" (the library's neutral studio as the
 * light, the start world's background kept), "none" (no environment light, no default light). */
#define SY_WEB_ENVIRONMENTS 3u
extern const char *const sy_webi_environment_names[SY_WEB_ENVIRONMENTS];

/* A connection the gate (sy_web_gate.h) hands over with its request: adopted by libwebsockets on
 * the network thread. */
typedef struct web_handoff {
    struct web_handoff *next;
    int fd;
    uint8_t *buf;
    size_t len;
} web_handoff;

struct sy_web {
    sy_web_desc d;
    sy_web_route *routes;
    char host[128];
    int port;
    char token[2 * WEB_TOKEN_BYTES + 1]; /* "" = none required */
    char url[300];
    bool loopback;
    sy_mat4 view; /* render thread: the view last set on the viewports (sy_web_view) */
    uint32_t initial_backend;
    struct lws_context *ctx;
    struct lws_vhost *vhost;
    sy_web_gate *gate;
    sy_web_policy policy; /* what sy_web_check_request allows */
    lws_retry_bo_t idle; /* the vhost's ping / hang-up policy (lws keeps a pointer) */
    uint32_t retry_ms;
    pthread_t net_thread;
    bool net_started;
    volatile int net_quit; /* read by the network thread */
    web_conn *conns;       /* WebSocket viewers (network thread only) */
    size_t video_reserved; /* network thread: the encoders' memory budget in use (sy_web_video_encoder_bytes) */

    pthread_mutex_t mu;
    pthread_cond_t cv;
    /* --- under mu: network thread -> render thread --- */
    bool quit;
    sy_interactive_input in; /* the orbit and the display filter the pages steer (sy_interactive.h) */
    float lead[2];           /* the last drag's or lead message's lead (pixels; [0, 0]: none) and its */
    uint32_t lead_button;    /* button: live frames are rendered that much further along (docs/WEB.md); */
    uint64_t lead_conn;      /* the connection that sent it (its leaving ends the lead) */
    uint64_t view_version; /* camera, back-end, filter or size changed */
    uint64_t input_gen;    /* inputs received, all clients */
    uint32_t backend;      /* registry index */
    uint32_t display_w, display_h;
    uint32_t clients;
    uint32_t video_viewers, jpeg_viewers; /* sized viewers by what they are sent: the render thread
                                           * keeps a frame's pixels for the first, JPEG for the second */
    uint32_t plain_viewers; /* sized viewers whose page does not warp: moving frames at the governor's
                             * own floor while there is one, else at d.min_scale */
    double encode_per_px_ms; /* the network thread's encoders, summed over viewers (ms per pixel of a
                              * frame, sy_web_cost.h): the render thread adds it to a frame's cost */
    bool need_pixels; /* a video viewer was sent a frame without pixels: the render thread republishes
                       * the newest frame with them (no new render: a still view keeps its samples) */
    web_job *pending, **pending_tail; /* routes */
    web_job *stills, **stills_tail;   /* stills: one after each live frame */
    web_job *still_running;
    web_handoff *handoffs;            /* gate -> network thread */
    web_action *actions, **actions_tail; /* picks, visibility, selection, planes, tree requests */
    uint32_t action_count;
    float exposure;                   /* stops (the display chain) */
    /* the scene clock the pages steer (docs/WEB.md, "The timeline"): animated when the scene has
     * clips; the render thread advances a playing clock and applies its time (sy_scene_set_time) */
    bool animated;
    sy_clock clock;
    /* the clips a page may choose ("anim"; read at create, touched by no one after): clip_count
     * handles and their ranges, [clip_count] every clip together; clip: the one the clock plays
     * (an index into them, clip_count = every clip), under mu */
    sy_animation *clips;
    double (*clip_range)[2];
    char (*clip_names)[64];           /* their names (cut to 63 bytes; "clip N" when unnamed) */
    uint32_t clip_count, clip;
    uint64_t clock_version;           /* played, paused, moved, stopped at an end, or a playing clock's
                                       * periodic update: sent to every page as a "clock" message */
    /* the saved views every page shares (docs/WEB.md, "Saved views"; sy_bookmarks.h): slots
     * 1..SY_BOOKMARKS_MAX, read from the file at create, saved and recalled by the network thread
     * (the file rewritten there, outside mu); views_version counts saves (every page is sent the
     * list, "views"), views_note the last save's trouble for the pages (""); fov: the camera's
     * vertical field of view now (radians, 0: orthographic), saved with a view; fov_req: a recalled
     * view's for the render thread to set on the camera (0: none) */
    sy_bookmark marks[SY_BOOKMARKS_MAX + 1];
    uint64_t views_version;
    char views_note[200];
    float fov, fov_req;
    char *bookmarks;                  /* the views' file (NULL: memory only); read at create, then the network thread's */
    uint64_t conn_serial;             /* the last web_conn.serial given (network thread) */
    sy_web_stats st;                  /* the still counters */
    /* --- under mu: render thread -> network thread --- */
    web_frame *latest;
    web_job *finished;
    char status[256]; /* the last back-end error or filter line, sent to the pages as JSON */
    uint64_t status_version;
    web_reply *replies, **replies_tail;
    uint32_t reply_count;
    uint64_t scene_version; /* visibility or selection changed: pages ask for the tree again */
    uint64_t look_version;  /* what a frame shows changed beyond the camera (planes, visibility, exposure) */
    uint32_t environment;   /* the environment in use: an index of sy_webi_environment_names */
    sy_background env_made[SY_WEB_ENVIRONMENTS]; /* render thread: the worlds made for the menu ({0}: not yet) */
};

/* The video encoders of all viewers together take at most this much memory (estimated at the
 * largest frame, sy_web_video_encoder_bytes); a viewer beyond it is sent JPEG. */
#define WEB_VIDEO_BUDGET ((size_t)512 << 20)

/* --- sy_web_mailbox.c --- */
void sy_webi_frame_release(sy_web *w, web_frame *f);
/* Frees a frame (its last reference is gone). */
void sy_webi_frame_free(web_frame *f);
void sy_webi_job_free(web_job *j);
/* Render thread -> network thread: wake the service loop (it runs EVENT_WAIT_CANCELLED). */
void sy_webi_wake_network(sy_web *w);
/* Network thread -> render thread: a route's job, a still's job. */
void sy_webi_post_job(sy_web *w, web_job *j);
void sy_webi_post_still(sy_web *w, web_job *j);
bool sy_webi_job_abandoned(sy_web *w, const web_job *j);

/* --- sy_web_views.c: the saved views (docs/WEB.md, "Saved views") --- */
/* At create: the camera's field of view, the views' file read (missing: none yet; unreadable: a
 * warning, views kept in memory only and the file left as it is). */
sy_result sy_webi_views_init(sy_web *w, const sy_web_desc *desc, sy_error *err);
/* What a "view" message did (sy_webi_view_message). */
typedef enum web_view_done { WEB_VIEW_NONE, WEB_VIEW_RECALLED, WEB_VIEW_SAVED } web_view_done;
/* Network thread, mu held: a recall sets the shared orbit (and fov_req when the view was saved
 * with another field of view): RECALLED, an input the next frames answer; a save puts the view now
 * in its slot: SAVED, the caller releases mu and calls sy_webi_views_write (the view the slot
 * holds already: NONE, nothing written); an empty slot is logged: NONE. */
web_view_done sy_webi_view_message(sy_web *w, const sy_web_input *in, const char *peer);
/* Network thread, mu not held: the views rewritten to their file (a failure: logged and told to
 * the pages in the list's "note"), then views_version bumped (the caller tells every page). */
void sy_webi_views_write(sy_web *w, const char *peer);
/* Network thread, mu held: the "views" message (malloc()ed JSON) when views_version is past *sent
 * (updated), else NULL. */
char *sy_webi_views_json(sy_web *w, uint64_t *sent);
/* Render thread, mu not held: a recalled view's field of view set on the camera and committed;
 * false (logged) when it could not be. */
bool sy_webi_views_set_fov(sy_web *w, float fov);

/* --- sy_web_scene.c --- */
/* What the render thread lends to the pages' scene requests. */
typedef struct sy_web_scene_ctx {
    sy_web *w;
    sy_context_pool *pool;
    sy_window *win;          /* the live frames' window (its size: the last frame's) */
    sy_viewport *vp, *still_vp; /* the live and the still viewport (both get the planes) */
    uint32_t backend;        /* the live back-end (registry index) */
} sy_web_scene_ctx;
/* Runs and frees the actions (picks, visibility, selection, isolate, planes, environment, tree);
 * true when what frames show changed (the scene was committed or the planes changed). */
bool sy_webi_scene_actions(const sy_web_scene_ctx *sc, web_action *list);

/* --- sy_web_http.c --- */
/* An HTTP connection's state (the http protocol's per-session data). */
typedef struct http_pss {
    web_job *job;         /* a request answered on the render thread */
    uint8_t *resp;        /* or an immediate response: owned copy */
    size_t resp_len;
    int status;
    const char *ctype;
    const uint8_t *body;  /* what is being sent (resp, a job's body or a static asset) */
    size_t body_len, sent;
    bool headers_done, set_cookie, responding;
    bool close_after;     /* the request said Connection: close (the gate says so for every GET) */
    const sy_web_route *route; /* POST: the route the body is for */
    uint8_t *post;        /* POST: the body so far */
    size_t post_len;
    bool post_too_big;
    char path[256], query[512], peer[64];
} http_pss;

/* The request's head as sy_web_check_request takes it (h points into b). */
typedef struct head_bufs {
    char path[SY_WEB_MAX_PATH], query[512], host[256], origin[256], ctype[128], cookie[1024], cl[32], site[32];
} head_bufs;

void sy_webi_read_head(struct lws *wsi, head_bufs *b, sy_web_head *h);
/* The HTTP status of a failed job's error. */
int sy_webi_http_status_of(sy_result r);
/* The http protocol's callback (every request but the WebSocket's). */
int sy_webi_http_callback(struct lws *wsi, enum lws_callback_reasons reason, void *user, void *in, size_t len);
/* The gate's thread: a connection whose request arrived whole (sy_web_gate_desc.deliver). */
void sy_webi_gate_deliver(void *user, int fd, uint8_t *bytes, size_t len);

/* --- sy_web_ws.c --- */
/* The protocols (http, sy-view) and the mount: the WebSocket at /ws, the rest to http. */
extern const struct lws_protocols sy_webi_protocols[];
extern const struct lws_http_mount sy_webi_mount;
/* The network thread: the libwebsockets service loop until net_quit. */
void *sy_webi_net_main(void *p);

#endif
