/* sy_rt_render.c — sy_rt_render (sy_rt.h): the top of the back-end's render path. Validates the
 * request, sets up the frame (sy_rt_frame.c) and hands it to the integrator it names (path tracer,
 * Whitted, primary rays); the integrators build on the frame module and never call back here. */
#include "sy_rt_envfilter.h"
#include "sy_rt_frame.h"
#include "sy_rt_lights.h"
#include "sy_rt_pathtracer.h"
#include "sy_rt_primary.h"
#include "sy_rt_whitted.h"

#define FAIL(r, ...) sy_rt_fail(dev, (r), __VA_ARGS__)

sy_rt_result sy_rt_render(sy_rt_device *dev, const sy_rt_camera *camera, const sy_rt_render_desc *desc, float *rgba,
                          float *depth)
{
    if (dev && camera) sy_rt_clip_begin(dev, camera);
    if (!dev || !camera || !desc) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "render: NULL argument");
    if (dev->dirty)
        return FAIL(SY_RT_ERROR_INVALID_OPERATION, "render: the device has uncommitted changes; call sy_rt_commit first");
    sy_rt_frame f;
    sy_rt_result r = sy_rt_frame_init(&f, dev, camera, desc, rgba, depth);
    if (r != SY_RT_OK) return r;
    if (desc->records && desc->integrator != SY_RT_INTEGRATOR_PATHTRACER)
        return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "render: path records need the PATHTRACER integrator");
    if (desc->ray_log && desc->integrator != SY_RT_INTEGRATOR_PATHTRACER)
        return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "render: a ray log needs the PATHTRACER integrator");
    if (desc->stage_times && desc->integrator != SY_RT_INTEGRATOR_PATHTRACER)
        return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "render: stage timers need the PATHTRACER integrator");
    if ((desc->integrator == SY_RT_INTEGRATOR_PATHTRACER || desc->integrator == SY_RT_INTEGRATOR_WHITTED) &&
        (r = sy_rt_light_tree_ensure(dev, desc->light_tree)) != SY_RT_OK) /* the light tree, when it is used */
        return r;
    if (desc->integrator == SY_RT_INTEGRATOR_PATHTRACER) return sy_rt_pathtracer_render(&f, desc);
    if (desc->integrator == SY_RT_INTEGRATOR_COVERAGE)
        return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "render: the coverage integrator writes ids: use sy_rt_coverage");
    if (desc->integrator == SY_RT_INTEGRATOR_WHITTED) {
        /* its prefiltered environment, once per committed environment */
        if ((r = sy_rt_envfilter_ensure(dev)) != SY_RT_OK) return r;
        return sy_rt_whitted_render(&f, desc);
    }
    return sy_rt_run_tiles(&f, sy_rt_primary_tile, NULL, desc->progress, desc->progress_user_data);
}
