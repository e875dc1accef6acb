/* sy_view.h — `sy view SCENE`: the interactive viewer (GLFW window).
 *
 * Orbit (left drag), pan (right or middle drag), zoom (wheel), fly (W A S D, Q E up/down); keys 1-9
 * pick a registered back-end live, O toggles the overlay layer, T cycles stereo modes (mono,
 * side-by-side, anaglyph), R resets the camera, Esc quits. With the path tracer, F cycles the display
 * filter (none, pixel, atrous, jbu, adaptive) and [ / ] halve / double its threshold (default 0.01),
 * live and without restarting the accumulation; the title shows the filter, threshold and its time.
 * A scene with animations plays on its clock: space plays and pauses it (real time, looping), '.'
 * steps it by 1/24 s; the render thread sets the time and commits, so every back-end (and a
 * cluster's servers) moves through the change lists; the title shows the time.
 * With --frames the last title line is printed to stdout at exit (automated runs); only frames
 * shown after the view settled (full size) count. The window title is the heads-up line: back-end,
 * frame time, the governor's resolution scale ("moving" while reduced), samples per pixel, sync
 * time. Rendering runs on its own thread, which owns the scene (the input thread only changes the
 * orbit and posts switches), so the window stays responsive while a slow back-end renders and always
 * shows the last complete image. Local rendering goes through the frame-time governor
 * (core/sy_governor.h, --budget MS): while the view moves each frame renders at the largest size
 * that fits the budget and the display scales it up, without the display filter; once the view
 * rests for 150 ms it renders at full size, a progressive back-end then adds samples per frame
 * within the budget (restarting when the view moves), and the thread sleeps until input. The orbit,
 * keys F [ ] R, governor, display filter and 8-bit image are core's interactive view, shared with
 * sy web (core/sy_interactive.h): the camera is set on the viewports directly (the scene's camera
 * node gives the projection), so the viewer adds nothing to the scene and never commits it.
 *
 * Cluster (--cluster URL[,URL...]|FILE.conf, --cluster-mode ...): the viewport's back-end is the
 * cluster mediator (sy_mediator_cluster.h), so the viewer renders through the same window path as
 * locally (overlay and stereo included); camera moves reach the servers in the frame requests. Sort-first
 * / balanced are bit-identical to a local render; cooperative merges the servers' sample ranges and
 * refines while the camera rests. Deadlines (--timeout-ms, else adaptive in the mediator) drop a
 * dead or stalled server and give its work to the others; the title shows the mode, the servers
 * alive, the frame time, spp and the last server failure. Multi-display: the servers present the
 * wall (-w x -h) at the swap barrier, and the window shows the whole wall rendered locally with the
 * same back-end, or the configuration's 'viewer tile X Y W H'. The display filter is local only.
 *
 * Thread-safety: runs the whole viewer; call from the main thread (GLFW requires it). */
#ifndef SY_VIEW_H
#define SY_VIEW_H

#include "sy_cluster_cli.h"
#include "sy_compose.h"

typedef struct sy_view_args {
    sy_scene *scene;        /* owned by the caller; used only by the render thread while running */
    sy_animation clip;      /* the clip the scene clock plays (space); {0}: every animation */
    sy_compose_spec spec;   /* root, camera, background, overlay (backend is chosen live) */
    const char *backend;    /* initial back-end */
    uint32_t width, height; /* initial window size */
    uint32_t frames;        /* > 0: quit after this many displayed frames (automated runs) */
    const char *screenshot; /* optional PNG of the window's last frame, written at exit */
    const char *filter;     /* initial path tracer display filter (NULL = "none"): none, pixel, atrous,
                               jbu or adaptive; anything else is refused before a window opens */
    float threshold;        /* its initial threshold (0 = the default 0.01; must be >= 0) */
    bool no_temporal;       /* no temporal reuse on moving frames (sy_interactive_set_temporal) */
    const char *keys;       /* automated runs: keys pressed one at a time through the keyboard handler,
                               each once the frame answering the previous one is shown (letters, digits,
                               [ ], space, ., * a click at the centre; ^ before a key: with Ctrl, ~: with
                               Shift, e.g. ^1 saves view 1, ~1 recalls it); the heads-up line after each is printed; --frames counts after
                               them (settled frames; while the scene clock plays, every frame) */
    const sy_cluster_cli_opts *cluster; /* non-NULL: render on these servers (sy view --cluster) */
    double budget_ms;       /* the frame-time governor's budget while the view moves (0 = 33 ms; --budget) */
    const char *bookmarks;  /* the saved views' file (sy_bookmarks.h; Ctrl+1..9 save, Shift+1..9 recall);
                               NULL: kept in memory only */
} sy_view_args;

sy_result sy_view_run(const sy_view_args *args, sy_error *err);

#endif /* SY_VIEW_H */
