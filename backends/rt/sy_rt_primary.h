/* sy_rt_primary.h — SY_RT_INTEGRATOR_PRIMARY: primary rays only with eye-light shading
 * (base colour * |cos| between the shading normal and the view ray; emitters show their
 * emission). For benchmarks and debugging. Internal to backends/rt. */
#ifndef SY_RT_PRIMARY_H
#define SY_RT_PRIMARY_H

#include "sy_rt_frame.h"

/* sy_rt_tile_fn for the primary integrator (user is unused). */
void sy_rt_primary_tile(const sy_rt_frame *f, void *user, uint32_t x0, uint32_t y0, uint32_t x1, uint32_t y1);

#endif /* SY_RT_PRIMARY_H */
