/* sy_mediators.c — registration of the built-in mediator classes (see sy_mediators.h). */
#include "sy_mediators.h"

#include "rt/sy_mediator_rt.h"

sy_result sy_mediators_register_builtin(sy_error *err)
{
    return sy_mediator_register(sy_mediator_rt_whitted_class(), err);
}
