/** @file
 * sy_pick_ray.h — the geometry of a pick, shared by every mediator that answers SY_CAP_PICK: the
 * ray through a pixel's centre of a camera view (the rays the ray tracers cast, in double), and
 * the hit of that ray on one triangle a back-end named (barycentrics, world position, geometric
 * normal, distance, depth). A back-end only has to say which instance and triangle is under the
 * pixel; the numbers every back-end reports then come from the same arithmetic, so two back-ends
 * that name the same triangle report the same point.
 * Thread-safety: pure functions. */
#ifndef SY_PICK_RAY_H
#define SY_PICK_RAY_H

#include "sy_mediator.h"
#include "sy_mirror.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The ray through the centre of pixel (x, y) of view at width x height (row 0 = top): origin,
 * direction (not unit: its component along the viewing axis is 1 for perspective views) and the
 * unit viewing axis. */
void sy_pick_ray(const sy_camera_view *view, uint32_t width, uint32_t height, uint32_t x, uint32_t y, double org[3],
                 double dir[3], double forward[3]);

/** The pick ray's hit on the triangle with object-space vertices p[0..2] placed by world: fills
 * out's barycentrics (the point of the triangle's plane the ray meets, clamped into the triangle
 * when the ray passes just outside it: a back-end's coverage rule and a plane hit can disagree by
 * rounding on an edge), position (world), normal (unit, on the front side as glTF defines it: counter-clockwise in object space, so
 * clockwise in world space under a mirroring world matrix),
 * distance and depth, and sets out->hit. false (out untouched) when the ray is parallel to the
 * triangle's plane, the triangle is degenerate, or the plane lies behind the origin. */
bool sy_pick_triangle(const sy_camera_view *view, uint32_t width, uint32_t height, uint32_t x, uint32_t y,
                      const float world[16], const float p[3][3], sy_pick_result *out);

/** Names what the pick hit in out: node, placement, mesh, primitive and material from the mirror's
 * description of the instance (sy_mirror_instance_find), and the triangle's index. */
void sy_pick_name(sy_pick_result *out, const sy_mirror_instance_info *info, uint32_t triangle);

#ifdef __cplusplus
}
#endif
#endif /* SY_PICK_RAY_H */
