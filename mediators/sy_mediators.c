/* sy_mediators.c — registration of the built-in mediator classes (see sy_mediators.h). */
#include "sy_mediators.h"

#include "raster/sy_mediator_raster.h"
#include "rt/sy_mediator_rt.h"

sy_result sy_mediators_register_builtin(sy_error *err)
{
    sy_result r = sy_mediator_register(sy_mediator_rt_whitted_class(), err);
    if (r == SY_OK) r = sy_mediator_register(sy_mediator_rt_pathtracer_class(), err);
    if (r == SY_OK) r = sy_mediator_register(sy_mediator_raster_class(), err);
    if (r == SY_OK) r = sy_mediator_register(sy_mediator_rt_coverage_class(), err);
    return r;
}
