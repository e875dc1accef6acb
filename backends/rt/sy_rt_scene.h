/* sy_rt_scene.h — internal side of the scene objects (meshes, instances, materials, lights) and
 * of sy_rt_commit: what the device needs to tear everything down. The public functions are
 * declared in sy_rt.h. */
#ifndef SY_RT_SCENE_H
#define SY_RT_SCENE_H

#include "sy_rt_device.h"

/* Destroys every mesh, instance, material and light and the committed light lists (device
 * teardown). Textures are the device's to free. */
void sy_rt_scene_release_all(sy_rt_device *dev);

#endif /* SY_RT_SCENE_H */
