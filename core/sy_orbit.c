/* sy_orbit.c — the orbit camera of sy view and sy web (see sy_orbit.h). */
#include "sy_orbit.h"

#include <math.h>

/* SY_COORD_MAX: the target and the distance each within half of it, so the camera is within it;
 * a non-finite value (never made here, but a caller may write the struct) goes back to the origin. */
static void orbit_clamp(sy_orbit *o)
{
    const float half = 0.5f * SY_COORD_MAX;
    for (int i = 0; i < 3; ++i)
        o->target[i] = isfinite(o->target[i]) ? fminf(fmaxf(o->target[i], -half), half) : 0.0f;
    o->dist = isfinite(o->dist) ? fminf(fmaxf(o->dist, 1e-3f), half) : 1.0f;
    if (!isfinite(o->yaw)) o->yaw = 0.0f;
    if (!isfinite(o->pitch)) o->pitch = 0.0f;
}

void sy_orbit_matrix(const sy_orbit *o, sy_mat4 *m)
{
    float cp = cosf(o->pitch), back[3] = {cp * sinf(o->yaw), sinf(o->pitch), cp * cosf(o->yaw)};
    float pos[3] = {o->target[0] + back[0] * o->dist, o->target[1] + back[1] * o->dist, o->target[2] + back[2] * o->dist};
    float x[3] = {back[2], 0.0f, -back[0]}; /* up x z */
    float xl = sqrtf(x[0] * x[0] + x[2] * x[2]);
    if (xl < 1e-6f) x[0] = 1.0f, x[2] = 0.0f, xl = 1.0f;
    x[0] /= xl, x[2] /= xl;
    float y[3] = {back[1] * x[2] - back[2] * x[1], back[2] * x[0] - back[0] * x[2], back[0] * x[1] - back[1] * x[0]};
    sy_mat4 r = {{x[0], x[1], x[2], 0, y[0], y[1], y[2], 0, back[0], back[1], back[2], 0, pos[0], pos[1], pos[2], 1}};
    *m = r;
}

void sy_orbit_from_matrix(const sy_mat4 *m, const sy_bounds *b, sy_orbit *o)
{
    float pos[3] = {m->m[12], m->m[13], m->m[14]}, back[3] = {m->m[8], m->m[9], m->m[10]};
    float bl = sqrtf(back[0] * back[0] + back[1] * back[1] + back[2] * back[2]);
    for (int i = 0; i < 3; ++i) back[i] = bl > 0 ? back[i] / bl : (i == 2);
    float d = 1.0f;
    if (b && !sy_bounds_is_empty(b)) {
        float c[3], along = 0;
        for (int i = 0; i < 3; ++i) c[i] = 0.5f * (b->min[i] + b->max[i]), along -= (c[i] - pos[i]) * back[i];
        if (along > 1e-3f) d = along;
    }
    o->dist = d;
    for (int i = 0; i < 3; ++i) o->target[i] = pos[i] - back[i] * d;
    o->pitch = asinf(back[1] < -1 ? -1 : back[1] > 1 ? 1 : back[1]);
    o->yaw = atan2f(back[0], back[2]);
    orbit_clamp(o);
}

void sy_orbit_rotate(sy_orbit *o, float dx, float dy)
{
    if (!isfinite(dx) || !isfinite(dy)) return;
    o->yaw = fmodf(o->yaw - dx * 0.008f, 2.0f * 3.14159265f);
    o->pitch += dy * 0.008f;
    if (o->pitch > 1.55f) o->pitch = 1.55f;
    if (o->pitch < -1.55f) o->pitch = -1.55f;
    orbit_clamp(o);
}

void sy_orbit_pan(sy_orbit *o, float dx, float dy)
{
    if (!isfinite(dx) || !isfinite(dy)) return;
    sy_mat4 m;
    sy_orbit_matrix(o, &m);
    float k = o->dist * 0.0015f;
    for (int i = 0; i < 3; ++i) o->target[i] += (-dx * m.m[i] + dy * m.m[4 + i]) * k;
    orbit_clamp(o);
}

void sy_orbit_zoom(sy_orbit *o, float steps)
{
    if (!isfinite(steps)) return;
    if (steps > 50.0f) steps = 50.0f;
    if (steps < -50.0f) steps = -50.0f;
    o->dist *= powf(0.9f, steps);
    orbit_clamp(o);
}
