/** @file
 * sy_orbit.h — the orbit camera of the interactive front-ends (sy view's window, sy web's page):
 * a target point, yaw and pitch around it and a distance, turned into a camera-to-world matrix
 * (right-handed, Y up, the camera looks down its local -Z), and recovered from one. Drags, pans and
 * wheel steps change it by the same rules everywhere, so the window and the browser feel alike.
 *
 * Thread-safety: pure functions on caller-owned structs. */
#ifndef SY_ORBIT_H
#define SY_ORBIT_H

#include "sy_math.h"

#ifdef __cplusplus
extern "C" {
#endif

/** An orbit camera: looks at target from dist away, from the direction given by yaw (around +Y,
 * 0 = from +Z) and pitch (up from the horizon, radians). */
typedef struct sy_orbit {
    float target[3]; /**< the point looked at (world) */
    float yaw;       /**< radians around +Y; 0 looks from +Z towards -Z */
    float pitch;     /**< radians above the horizon, kept within +-1.55 by sy_orbit_rotate */
    float dist;      /**< distance from the target, > 0 */
} sy_orbit;

/** The camera-to-world matrix of the orbit (rotation orthonormal, translation = camera position). */
void sy_orbit_matrix(const sy_orbit *o, sy_mat4 *m);

/** The orbit of a camera-to-world matrix: its viewing axis is kept, the target is placed on it at
 * the distance of the centre of b along the axis (1 when b is empty or behind the camera), so
 * sy_orbit_matrix gives back the same position and viewing direction (roll is dropped). */
void sy_orbit_from_matrix(const sy_mat4 *m, const sy_bounds *b, sy_orbit *o);

/** A drag of dx, dy pixels (x right, y down): turns around the target, 0.008 radians per pixel,
 * the pitch clamped to +-1.55. Non-finite input is ignored. */
void sy_orbit_rotate(sy_orbit *o, float dx, float dy);

/** A pan of dx, dy pixels: moves the target in the image plane, 0.0015 x dist per pixel.
 * Every call here keeps the orbit within the coordinate range: the target's coordinates and the
 * distance within SY_COORD_MAX / 2 (so the camera is within SY_COORD_MAX, sy_math.h), the
 * distance >= 1e-3; however many pans and zooms an input sends. */
void sy_orbit_pan(sy_orbit *o, float dx, float dy);

/** steps wheel notches (positive = closer): the distance is scaled by 0.9^steps, kept within
 * [1e-3, SY_COORD_MAX / 2].
 * Non-finite input is ignored. */
void sy_orbit_zoom(sy_orbit *o, float steps);

#ifdef __cplusplus
}
#endif
#endif /* SY_ORBIT_H */
