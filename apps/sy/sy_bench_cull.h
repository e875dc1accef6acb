/* sy_bench_cull.h — `sy bench cull` (issue 18, docs/CULLING.md): the remote culling service on
 * the generated plant along a camera path: per view, cull with the budget, rasterise only the
 * returned objects and the full scene, coverage IoU of the two, triangles drawn against the
 * budget; over the path, triangles fetched and GLB bytes (objects cached once fetched) against
 * JPEG frames of the full render at the same size (streaming video). `--write FILE.glb` writes the
 * plant as GLB instead (to serve it with `sy web FILE.glb --client-render`). Prints ratios
 * measured in one run. Thread-safety: single-threaded caller. */
#ifndef SY_BENCH_CULL_H
#define SY_BENCH_CULL_H

/* sy bench cull [--tris N] [--objects N] [--budget T] [-w W] [-h H] [--frames N] [--seed S]
 *               [--write FILE.glb]; argv[0] is "cull". Returns the exit status (0, 1 failure,
 * 2 usage). */
int sy_cmd_bench_cull(int argc, char **argv);

#endif /* SY_BENCH_CULL_H */
