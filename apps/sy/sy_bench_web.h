/* sy_bench_web.h — `sy bench web`: glass-to-glass latency of sy web's stream on loopback.
 * Thread-safety: runs the benchmark on the calling thread plus the server's threads. */
#ifndef SY_BENCH_WEB_H
#define SY_BENCH_WEB_H

#include "sy_web.h"

/* Starts a server (desc: scene, camera, back-end; listens on a free loopback port), connects a
 * WebSocket client that asks for width x height frames, then `repeats` times sends a drag and
 * measures the time until the first frame tagged with that input's id arrives; prints p50 / p95 /
 * min / max of that latency, the server's render time per frame (median) and the overhead of the
 * stream (latency minus the answering frame's render time: input, JPEG, socket, wake-ups). */
sy_result sy_bench_web(const sy_web_desc *desc, uint32_t width, uint32_t height, uint32_t repeats, sy_error *err);

#endif
