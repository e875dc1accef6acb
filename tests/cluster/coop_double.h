/* coop_double.h — a recording test double of a progressive mediator ("coop_test"), used only by the
 * cluster tests to check the cooperative merge exactly while no path tracer is available in the
 * process (or to keep the check independent of one). Sample s of pixel (x, y) has the value
 * coop_double_sample(x, y, s) in [0, 1); a render call adds the requested sample range to the
 * context's per-pixel accumulation and writes the mean of everything accumulated; stats report the
 * number of samples per pixel. With $COOP_DOUBLE_TRACE set, every render call first appends a line
 * "SAMPLE_FIRST SAMPLE_COUNT" to that file (tests see which requests a server got). Thread-safety: like every mediator, one context per thread. */
#ifndef COOP_DOUBLE_H
#define COOP_DOUBLE_H

#include "sy_mediator.h"

float coop_double_sample(uint32_t x, uint32_t y, uint32_t s);
/* Registers "coop_test" (idempotent within a process: a second call fails, ignore it). */
sy_result coop_double_register(sy_error *err);

#endif
