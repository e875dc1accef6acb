/** @file
 * sy_web_client.h — a small blocking WebSocket client of sy web's stream (libwebsockets' client
 * API): connects to /ws, sends input messages, waits for frames and text answers (pick, tree). Used by `sy bench web` and the
 * tests; also a starting point for a program that watches a sy web server.
 *
 * Ownership: frames returned are malloc()ed and owned by the caller (free()).
 * Thread-safety: one client per thread; each has its own lws context. */
#ifndef SY_WEB_CLIENT_H
#define SY_WEB_CLIENT_H

#include "sy_common.h"
#include "sy_web_frame.h" /* sy_web_frame_info */

#ifdef __cplusplus
extern "C" {
#endif

/** Where to connect. */
typedef struct sy_web_client_opts {
    const char *host;   /**< e.g. "127.0.0.1" */
    uint16_t port;      /**< the server's port */
    const char *path;   /**< "/ws" or "/ws?token=..." (NULL: "/ws") */
    const char *origin; /**< the Origin header's host[:port] (libwebsockets writes http:// before it; NULL: the
                             server's own, host:port, as a page the server served sends it) */
} sy_web_client_opts;

/** A client (opaque). */
typedef struct sy_web_client sy_web_client;

/** Connects and completes the upgrade within timeout_ms; a refused upgrade fails with
 * SY_ERR_PROTOCOL, no answer with SY_ERR_IO. */
sy_result sy_web_client_connect(const sy_web_client_opts *o, uint32_t timeout_ms, sy_web_client **out, sy_error *err);

/** Sends one text message (an input, docs/WEB.md). */
sy_result sy_web_client_send(sy_web_client *c, const char *text, sy_error *err);

/** Waits up to timeout_ms for the next binary frame (text messages are skipped); *jpeg (may be
 * NULL: not returned) receives its JPEG bytes. SY_ERR_IO on timeout or a closed connection,
 * SY_ERR_PROTOCOL for a message that is no format-3 frame (sy_web_frame_parse). */
sy_result sy_web_client_next_frame(sy_web_client *c, uint32_t timeout_ms, sy_web_frame_info *info, uint8_t **jpeg,
                                   size_t *jpeg_len, sy_error *err);

/** As sy_web_client_next_frame, and *depth (malloc, width x height floats, +INFINITY where nothing
 * was hit) receives the frame's decoded depth channel: its own, or for a frame that says it has the
 * last one (SY_WEB_FRAME_SAME_DEPTH) the last one received (SY_ERR_PROTOCOL when there is none). */
sy_result sy_web_client_next_frame_depth(sy_web_client *c, uint32_t timeout_ms, sy_web_frame_info *info,
                                         uint8_t **jpeg, size_t *jpeg_len, float **depth, sy_error *err);

/** Waits up to timeout_ms for the next text message whose "t" is type (NULL: any); older text
 * messages of other types are dropped (the newest 256 are kept while nobody asks). *text: the
 * message, malloc()ed, NUL-terminated, the caller's. SY_ERR_IO on timeout or a closed connection. */
sy_result sy_web_client_next_text(sy_web_client *c, uint32_t timeout_ms, const char *type, char **text, sy_error *err);

/** Closes the connection and frees c (NULL-safe). */
void sy_web_client_close(sy_web_client *c);

#ifdef __cplusplus
}
#endif
#endif /* SY_WEB_CLIENT_H */
