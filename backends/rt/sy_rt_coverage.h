/* sy_rt_coverage.h — the coverage integrator's tile function (internal to backends/rt): one
 * primary ray per pixel centre, the id of the nearest visible instance. Public entry:
 * sy_rt_coverage() in sy_rt.h. */
#ifndef SY_RT_COVERAGE_H
#define SY_RT_COVERAGE_H

#include "sy_rt_frame.h"

/* user: uint32_t *ids of the frame's rectangle. */
void sy_rt_coverage_tile(const sy_rt_frame *f, void *user, uint32_t x0, uint32_t y0, uint32_t x1, uint32_t y1);

#endif /* SY_RT_COVERAGE_H */
