/* test_web.c — test_web's parts and its main: the sy_web server (apps/web/sy_web.h) in this
 * process on a free loopback port, with the demo scene and the Whitted back-end; HTTP requests
 * through plain sockets (so malformed and hostile ones can be sent as they are), WebSockets through
 * apps/web/sy_web_client.h.
 *
 *   web_page      the page is served (the canvas id and the test hook are in it); unknown paths 404;
 *                 a foreign Host is refused (DNS rebinding)
 *   web_still     /api/frame.jpg?w=&h= is a JPEG of that size that is not uniform; bad sizes get 400
 *                 with the reason; without Origin only Sec-Fetch-Site: same-origin gets it (403 else)
 *   web_latest    /api/latest.jpg before any viewer: the render thread's warm-up frame (the shape of
 *                 the largest display), 204 until it is made; cross-site or no Origin: 403
 *   web_routes    a GET route and a POST route run on the render thread (the body arrives whole);
 *                 a body over the limit gets 413; garbage, huge headers and cut-off requests
 *                 leave the server serving
 *   web_stream    a viewer receives JPEG frames; a drag message gives a frame tagged with its id that
 *                 differs from the one before; malformed messages are ignored and serving goes on;
 *                 a message over the limit closes that connection only; foreign Origin and missing
 *                 subprotocol upgrades are refused; a viewer whose socket URL carries its size
 *                 (/ws?w=120&h=90&v=3) gets frames without a size message, the first no larger,
 *                 of that aspect; a viewer beyond max_clients is refused
 *   web_encodecost  the frame-time governor counts the encoders' time (sy_web_cost.h): a slow
 *                 encoder stub makes it pick a smaller moving frame that fits the budget with the
 *                 encode (simulated clock); --quality's video quantizer
 *   web_warpfloor moving frames keep half the display's side while every viewer's page warps ("warp":
 *                 true in its size message), the governor's eighth while one does not (a budget every
 *                 frame overruns puts the governor at its floor); a "warp" that is no boolean is refused
 *   web_ahead     frames rendered ahead: a drag's "lead" renders its frame that much further on (the
 *                 header's orbit the drag's, the camera led on); a lead of [0, 0] brings the exact view
 *                 back, a lead message alone leads, a wheel ends the lead, and so does its viewer leaving; not
 *                 while a viewer does not warp
 *   web_progressive  the path tracer refines while the view rests and restarts when it moves;
 *                 the refinements leave the depth channel out (SAME_DEPTH) and it decodes as before
 *   web_token     listening on 0.0.0.0: without the token 401 with the page saying it is missing,
 *                 a wrong one 403 (one of 200 characters too), the right one 200 plus a cookie
 *                 that works alone; WebSocket upgrades need it too
 *   web_hostile   issue 32's findings: Hosts that only look like loopback (DNS rebinding), for
 *                 pages and upgrades; upgrades off /ws; cross-site POSTs (text/plain, foreign or
 *                 no Origin); stills without Origin, past the side cap, past the pixel budget; a
 *                 one-character header name (400 at once); two pipelined GETs (the first answered,
 *                 then a clean close); paths of 256+ bytes (414); a binary message announcing
 *                 50 MB (close 1009 before its payload)
 *   web_slowloris 100 reconnecting slowloris connections; an honest client's 20 GETs all answered
 *   web_stillbudget  stills queue behind a held render thread: the per-client pixel budget (429),
 *                 another client's own budget, a still whose requester left is not rendered
 *   web_clientfiles  /client/ serves client.html, client.js and vendor/ only, not npm/; /api/view's
 *                 "look" names no environment for the demo (it brings lights; /api/environment:
 *                 404), the studio's float texture once the menu chose it (/api/environment: its
 *                 256 x 128 float RGB, the sky row brighter than the floor's)
 *   web_messages  the page's scene messages (pick, visible, select, isolate, clip, tree, exposure,
 *                 filter, time, play) are parsed as documented; picks outside the canvas, NaN, zero-normal and
 *                 infinite planes, 7 planes, node ids that are no whole number, bad names, times
 *                 that are no finite number: refused
 *   web_scene     a viewer asks for the tree (the demo's nodes, their kinds), picks the pixel nearest
 *                 the centre that the first frame's depth says is covered (the node, its mesh, its
 *                 distance that of the depth) and selects it (every viewer is told "scene");
 *                 hides that node: the next frame's depth there changes and a new pick no longer
 *                 names it; shows it again: the depth comes back; an unknown node is refused with
 *                 the reason; a plane that keeps nothing empties the pixel and no plane brings it
 *                 back; bad planes and picks outside are ignored and the stream goes on; exposure
 *                 +2 stops brightens the frame (mean > 1.15 x that at 0); 80 pages
 *                 that ask for the tree and leave at once leave no answers behind
 *   web_readonly  read_only: visibility, selection, isolation, planes and back-end keys are refused
 *                 (the tree unchanged, no "scene" message), a pick answers without selecting, the
 *                 camera moves
 *   web_timeline  the scene clock on a read-only server whose demo has a 2 s clip (every mesh
 *                 shrinks): the "clock" message gives its range, paused; times outside it or null
 *                 are refused (no clock message); a time of 2 s changes the depth at a covered
 *                 pixel; play is answered by clock messages whose time advances, pause stops it; a
 *                 scene without clips sends no clock and refuses times
 *   web_tree      the tree of a scene of 18,000 nodes more than the demo, a page at a time: the
 *                 first answer lists at most 4,096 nodes, "flat" (12,000 children) closed with its
 *                 count, "deep" open, its groups of 300 open until the answer is full, the rest
 *                 closed; "flat"'s children in pages of 512 (offset 11,776: the last 224), every
 *                 child once over the 24 pages; a page past the end is empty; an unknown node and
 *                 a node or offset that is no whole number are refused
 *   web_views     saved views: a server whose views' file holds view 2 lists it ("views"); a page
 *                 saves the view as 5 (listed, written to the file with the camera's field of
 *                 view; the same again sends nothing), drags away, recalls 5 (the frame's eye within 1e-3 of the saved one, the
 *                 same direction) and 2 (the file's eye and 30 degree field of view); an empty slot
 *                 moves nothing; a read-only server recalls and refuses saves (no list, the file
 *                 unchanged); an unreadable file is left as it is, saves kept by the server and said so
 *   web_frame     the binary frame (sy_web_frame.h) round-trips: header fields, the depth channel
 *                 (the grid of every second pixel) within its 16-bit log step, "nothing" kept; a
 *                 tilted plane codes to under a quarter of its grid's 2 bytes per value; a frame
 *                 without its depth (SAME_DEPTH) parses; truncated, foreign, format-2 and
 *                 mismatched frames are refused with the reason; the stream's frames carry the
 *                 orbit's camera and a depth channel of the frame's size (web_stream)
 *   web_videostream  a viewer listing ["vp10", "VP9", 5, "vp9", "vp8"] is sent VP9 (the bad names
 *                 ignored): its first VP9 frame is a keyframe, decodes at the asked size with the
 *                 depth channel beside it and matches a JPEG viewer's picture of the same view
 *                 (mean abs diff < 6 of 255); {"t":"keyframe"} gets a keyframe; a drag's frames
 *                 decode in order up to the one answering it; "codecs" that is no array, or names
 *                 only the server does not know: JPEG (skipped without libvpx)
 *
 * The parts live in test_web_http.c (page, still, routes, clientfiles), test_web_stream.c (stream,
 * progressive, frame, videostream, encodecost), test_web_guard.c (token, hostile, slowloris,
 * stillbudget), test_web_scene.c (messages, scene, readonly, timeline) and test_web_views.c (views);
 * web_test.c holds what they share (web_test.h). */
#include "web_test.h"

int main(int argc, char **argv)
{
    const char *which = argc > 1 ? argv[1] : "all";
    sy_error err = {0};
    if (sy_mediators_register_builtin(&err) != SY_OK) {
        fprintf(stderr, "%s\n", err.message);
        return 1;
    }
    /* the parts that start their own server, or need none */
    static const struct {
        const char *name;
        int (*run)(void);
    } alone[] = {{"messages", test_messages},   {"timeline", test_timeline},       {"frame", test_frame},
                 {"encodecost", test_encode_cost}, {"clientfiles", test_client_files}, {"token", test_token},
                 {"progressive", test_progressive}, {"views", test_views}, {"warpfloor", test_warp_floor}, {"ahead", test_ahead}};
    for (size_t i = 0; i < sizeof alone / sizeof alone[0]; ++i)
        if (!strcmp(which, alone[i].name)) {
            int f = alone[i].run();
            if (!f) printf("web %s: ok\n", which);
            return f;
        }
    /* the parts given a viewer of a server of their own (read-only, or with the big tree) */
    static const struct {
        const char *name;
        int (*run)(sy_web_client *c);
        bool read_only, big_tree;
    } viewed[] = {{"readonly", test_readonly, true, false}, {"tree", test_tree, false, true}};
    for (size_t i = 0; i < sizeof viewed / sizeof viewed[0]; ++i)
        if (!strcmp(which, viewed[i].name)) {
            web_read_only = viewed[i].read_only;
            web_big_tree = viewed[i].big_tree;
            server s;
            sy_web_client *c = NULL;
            if (web_start_viewer(&s, &c, &err)) return 1;
            int f = viewed[i].run(c);
            sy_web_client_close(c);
            f |= web_stop(&s);
            if (!f) printf("web %s: ok\n", which);
            return f;
        }
    if (!strcmp(which, "videostream") && !sy_web_codec_available(SY_WEB_CODEC_VP9)) {
        printf("skipped: this build has no libvpx (libvpx-dev)\n");
        return 77;
    }
    server s;
    if (web_start(&s, "127.0.0.1:0", "whitted", &err)) return 1;
    uint16_t port = sy_web_port(s.web);
    int failed = 0;
    if (!strcmp(which, "page") || !strcmp(which, "all")) failed |= test_page(port);
    if (!strcmp(which, "latest") || !strcmp(which, "all")) failed |= test_latest(port); /* before any viewer */
    if (!strcmp(which, "still") || !strcmp(which, "all")) failed |= test_still(port);
    if (!strcmp(which, "routes") || !strcmp(which, "all")) failed |= test_routes(port);
    if (!strcmp(which, "stream") || !strcmp(which, "all")) failed |= test_stream(port);
    if (!strcmp(which, "videostream") || !strcmp(which, "all")) failed |= test_video_stream(port);
    if (!strcmp(which, "hostile") || !strcmp(which, "all")) failed |= test_hostile(port);
    if (!strcmp(which, "slowloris") || !strcmp(which, "all")) failed |= test_slowloris(&s, port);
    if (!strcmp(which, "stillbudget") || !strcmp(which, "all")) failed |= test_still_budget(&s, port);
    if (!strcmp(which, "scene") || !strcmp(which, "all")) failed |= test_scene(port);
    failed |= web_stop(&s);
    if (!failed) printf("web %s: ok\n", which);
    return failed;
}
