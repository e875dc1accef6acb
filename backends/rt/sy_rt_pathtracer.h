/* sy_rt_pathtracer.h — the PATHTRACER integrator: unidirectional path tracing with next-event
 * estimation and multiple importance sampling (power heuristic) for emissive triangles (alias
 * table by power), punctual lights and the environment; Russian roulette from the fifth bounce;
 * progressive accumulation into a sy_rt_accum with feature buffers. Internal to backends/rt. */
#ifndef SY_RT_PATHTRACER_H
#define SY_RT_PATHTRACER_H

#include "sy_rt_frame.h"

/* Adds desc->samples (0 = 1) samples per pixel of the frame's rectangle to desc->accum, then
 * resolves colour into f->rgba and depth into f->depth when they are non-NULL. */
sy_rt_result sy_rt_pathtracer_render(const sy_rt_frame *f, const sy_rt_render_desc *desc);

#endif /* SY_RT_PATHTRACER_H */
