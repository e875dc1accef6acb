/** @file
 * sy_web_cull.h — remote culling over sy_web (docs/CULLING.md, docs/WEB.md): the routes that make a
 * sy_web server a culling service for browser clients that draw only what is visible.
 *
 *   POST /api/cull        the view + budget as JSON -> the visible objects ranked by covered pixels,
 *                         cut at the budget (sy_culler_query_json)
 *   GET  /api/object/ID   one object's geometry and material as GLB (404 for unknown ids)
 *   GET  /api/view        the server's current view as JSON, in the form /api/cull takes
 *                         ({"position", "orientation", "fov", "target"}): the client page starts
 *                         from the view every other back-end starts from; and "look": the
 *                         environment light (studio, texture, none; the image's size), its
 *                         intensity, the exposure and the tone mapping the stream applies
 *   GET  /api/environment that environment as float32 RGB lat-long (row 0 up): the client lights
 *                         with the light the back-ends use (404 when there is none)
 *   GET  /api/pose        the objects that moved since the load (the scene clock: the page's
 *                         timeline), each placement's world matrix (sy_culler_poses_json)
 *   GET  /client/...      the three.js client page (client.html, client.js, vendor/: the vendored
 *                         three.js; nothing else) from the folder the build made (apps/cull/client),
 *                         when one is given
 *
 * Built into sy_web where the culling service is (the Embree back-ends). Every handler runs on the
 * server's render thread (the scene's owner), behind the server's token check like every route.
 *
 * Ownership: sy_web_cull_create borrows the scene (it must outlive the routes' server); the
 * routes' user pointers point into the returned object, which the caller destroys after the server
 * (sy_web_destroy first). Thread-safety: create, attach and destroy on the scene's thread. */
#ifndef SY_WEB_CULL_H
#define SY_WEB_CULL_H

#include "sy_web.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Routes sy_web_cull_create fills at most. */
#define SY_WEB_CULL_MAX_ROUTES 6

/** The culling routes of one server (opaque). */
typedef struct sy_web_cull sy_web_cull;

/** The folder of the client page the build made (the build tree's cull_client), or "" when the
 * build had no npm. Static storage. */
const char *sy_web_cull_client_dir_default(void);

/** Makes the culler for scene/root and writes its routes into routes[0 .. *count) for
 * sy_web_desc.routes. client_dir (may be NULL: no /client/ route) is the folder served under
 * /client/; it must hold client.html (else SY_ERR_NOT_FOUND naming the folder and why it may be
 * missing). */
sy_result sy_web_cull_create(sy_scene *scene, sy_node root, const char *client_dir, sy_web_cull **out,
                             sy_web_route routes[SY_WEB_CULL_MAX_ROUTES], uint32_t *count, sy_error *err);
/** Gives GET /api/view the server whose camera it reports (call after sy_web_create). */
void sy_web_cull_attach(sy_web_cull *c, const sy_web *server);
/** Frees the culler (NULL-safe); after the server is destroyed. */
void sy_web_cull_destroy(sy_web_cull *c);

#ifdef __cplusplus
}
#endif
#endif /* SY_WEB_CULL_H */
