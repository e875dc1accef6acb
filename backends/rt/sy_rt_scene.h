/* sy_rt_scene.h — internal side of the scene modules of the ray-tracing back-end (meshes, materials,
 * instances, moved instances, lights) and of sy_rt_commit. The public functions are declared in
 * sy_rt.h. The modules, bottom-up (each calls only those listed before it, so none calls another in a
 * loop): sy_rt_mesh.c, sy_rt_material.c, sy_rt_punctual.c, sy_rt_placement.c, sy_rt_clip.c ->
 * sy_rt_moved.c -> sy_rt_instance.c -> sy_rt_scene.c (sy_rt_commit, teardown). The functions
 * below change the device: they run on the caller's thread between renders, as sy_rt.h's set-up
 * calls do (not thread-safe). sy_rt_clip.c's context filter and sy_rt_clip_cap (sy_rt_device.h)
 * run on the render threads and only read. */
#ifndef SY_RT_SCENE_H
#define SY_RT_SCENE_H

#include "sy_rt_device.h"

/* >>mesh (sy_rt_mesh.c) */
/* Drops one reference to m; the last frees it (its Embree objects, its copies, or the caller's
 * shared arrays through its release callback). NULL is ignored. */
void sy_rt_mesh_unref(sy_rt_device *dev, sy_rt_mesh_data *m);
/* The mesh's BLAS (m->scene), built on first use; refused with the sizes when it would not fit
 * in memory or under the device's limit. */
sy_rt_result sy_rt_mesh_blas(sy_rt_device *dev, sy_rt_mesh_data *m);
/* Ends a mesh's motion (sy_rt_mesh_update_motion): one time step again, its time-0 pose kept
 * (Embree drops the slot-1 buffer). */
void sy_rt_mesh_motion_off(sy_rt_device *dev, sy_rt_mesh_data *m);

/* >>punctual lights (sy_rt_punctual.c) */
/* Rebuilds dev->punctual, the array of the live lights the integrators read (sy_rt_commit). */
sy_rt_result sy_rt_punctual_rebuild(sy_rt_device *dev);

/* >>placement (sy_rt_placement.c), shared by instances and moved instances */
/* Checks that xf (column-major) places mesh m: finite, invertible and within SY_RT_COORD_MAX.
 * Writes the normal matrix (inverse transpose of the upper 3x3, row-major) to nrm and to *gain the
 * row-sum norm of the inverse (how much the inverse magnifies a ray's coordinates). */
sy_rt_result sy_rt_placement_check(const sy_rt_device *dev, const sy_rt_mesh_data *m, const float *xf, float nrm[9],
                                   double *gain);
/* sy_rt_placement_check of a new transform of instance in (set_transform, set_motion's close one),
 * which also refuses a transform that shrinks by more than SY_RT_INSTANCE_GAIN_MAX allows for an
 * instance created unbaked (Embree would see its inverse): "WHAT shrinks by ... unbaked)TAIL". */
sy_rt_result sy_rt_placement_recheck(const sy_rt_device *dev, const sy_rt_instance_data *in, const float *xf,
                                     float nrm[9], const char *what, const char *tail);
/* Writes the world-space positions of a baked instance (time step 0). */
void sy_rt_bake_positions(sy_rt_instance_data *in);
/* Geometry id -> instance maps (dev->top_map, dev->dyn_map): grows *map_io to hold id and stores
 * in there. False when out of memory. */
bool sy_rt_id_map_set(sy_rt_instance_data ***map_io, uint32_t *cap_io, unsigned id, sy_rt_instance_data *in);
/* An instance's material flags: emissive and shown (an area light), alpha-masked (an alpha filter). */
static inline bool sy_rt_instance_emissive(const sy_rt_device *dev, const sy_rt_instance_data *in)
{
    return !(in->flags & SY_RT_INSTANCE_HIDDEN) && sy_rt_material_lookup(dev, in->material)->emissive;
}
static inline bool sy_rt_instance_masked(const sy_rt_device *dev, const sy_rt_instance_data *in)
{
    return sy_rt_material_lookup(dev, in->material)->masked;
}

/* >>moved instances (sy_rt_moved.c) */
/* Puts a moved instance on the pending list (once); Embree sees the move at sy_rt_commit. False
 * when out of memory. */
bool sy_rt_pending_add(sy_rt_device *dev, sy_rt_instance_data *in);
/* Takes an instance off the pending list and drops its twin (it is destroyed, or its transform
 * went into the top scene). */
void sy_rt_pending_remove(sy_rt_device *dev, sy_rt_instance_data *in);
/* Commit, moved instances: twins when few are stale and nothing structural changed, else every
 * pending transform into the top scene (dev->top_dirty: the caller rebuilds it). */
sy_rt_result sy_rt_commit_moved(sy_rt_device *dev);

/* >>instance (sy_rt_instance.c) */
/* Frees an instance: off the pending list, out of the top scene and its id map, its mesh unref'd. */
void sy_rt_instance_free(sy_rt_device *dev, sy_rt_instance_data *in);

/* >>commit (sy_rt_scene.c) */
/* Destroys every mesh, instance, material and light and the committed light lists (device
 * teardown). Textures are the device's to free. */
void sy_rt_scene_release_all(sy_rt_device *dev);

#endif /* SY_RT_SCENE_H */
