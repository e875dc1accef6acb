/* sy_bench_governor.h — `sy bench governor [SCENE] [--budget MS] [--frames N] [-w W -h H]
 * [--tris T]`: the frame-time governor (core/sy_governor.h) on a scripted camera path (an orbit
 * around the scene, one step per frame, so the view moves every frame) with every picture back-end
 * of the registry (no analysis or remote class), rendered through sy_compose at the governed size.
 * Per back-end it prints the first frame (the scene's translation, left out), the full-size frame
 * time without the governor (median of 5 frames on the same path), then over N governed frames the
 * p50 / p95 / max frame interval against the budget, p95 / budget, the share of frames over the
 * budget, the mean resolution scale, the share of the cores the process had (a loaded machine
 * shows) and the fitted cost model. Default scenes: the glTF Duck of
 * ../shared/testdata (skipped with a note when absent) and a generated height field of --tris
 * triangles (default 1M). Timings only (never pass/fail); progress on a terminal only.
 * Thread-safety: call from the main thread. */
#ifndef SY_BENCH_GOVERNOR_H
#define SY_BENCH_GOVERNOR_H

/* argv[0] is "governor"; returns the process exit status (0, 1 failure, 2 usage). */
int sy_cmd_bench_governor(int argc, char **argv);

#endif /* SY_BENCH_GOVERNOR_H */
