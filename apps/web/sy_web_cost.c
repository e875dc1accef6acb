/* sy_web_cost.c — the encoders' cost per pixel and a frame's whole cost for the governor (see
 * sy_web_cost.h). */
#include "sy_web_cost.h"

#include <math.h>

double sy_web_encode_cost_add(sy_web_encode_cost *c, double ms, uint64_t pixels)
{
    if (!pixels || !isfinite(ms) || ms < 0) return 0.0;
    double v = ms / (double)pixels, old = c->per_px_ms;
    c->per_px_ms = c->frames ? old + SY_WEB_COST_WEIGHT * (v - old) : v;
    c->frames++;
    return c->per_px_ms - old;
}

double sy_web_frame_cost_ms(double render_ms, double encode_per_px_ms, uint32_t width, uint32_t height)
{
    double e = encode_per_px_ms > 0 && isfinite(encode_per_px_ms) ? encode_per_px_ms * (double)width * height : 0.0;
    return render_ms + e;
}
