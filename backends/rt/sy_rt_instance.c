/* sy_rt_instance.c — instances of the ray-tracing back-end: sy_rt_instance_create (an Embree instance
 * of the mesh's BLAS, or baked world-space geometry when the transform shrinks too much for Embree's
 * inverse) in the top-level scene, set_transform (a move goes to sy_rt_moved.c's pending list),
 * set_material, set_visible and destroy. Calls sy_rt_moved.c, sy_rt_placement.c and sy_rt_mesh.c. */
#include "sy_rt_scene.h"

#include <stdlib.h>
#include <string.h>

#define FAIL(r, ...) sy_rt_fail(dev, (r), __VA_ARGS__)

static bool top_map_set(sy_rt_device *dev, unsigned id, sy_rt_instance_data *in)
{
    return sy_rt_id_map_set(&dev->top_map, &dev->top_map_cap, id, in);
}

void sy_rt_instance_free(sy_rt_device *dev, sy_rt_instance_data *in)
{
    if (in->motion) dev->motion_count--;
    free(in->xf_mid);
    sy_rt_pending_remove(dev, in);
    if (in->geom) {
        if (in->top_id != RTC_INVALID_GEOMETRY_ID) {
            rtcDetachGeometry(dev->top, in->top_id);
            if (in->top_id < dev->top_map_cap) dev->top_map[in->top_id] = NULL;
        }
        rtcReleaseGeometry(in->geom);
    }
    sy_rt_mesh_unref(dev, in->mesh);
    free(in);
}

sy_rt_result sy_rt_instance_create(sy_rt_device *dev, const sy_rt_instance_desc *d, sy_rt_instance *out)
{
    if (!dev || !d || !out) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "instance: NULL argument");
    out->id = 0;
    sy_rt_mesh_data *mesh = sy_rt_pool_get(&dev->meshes, d->mesh.id);
    if (!mesh) return FAIL(SY_RT_ERROR_INVALID_HANDLE, "instance: mesh handle 0x%08x is stale", d->mesh.id);
    if (d->material.id != 0 && !sy_rt_pool_get(&dev->materials, d->material.id))
        return FAIL(SY_RT_ERROR_INVALID_HANDLE, "instance: material handle 0x%08x is stale", d->material.id);
    if (d->flags & ~(uint32_t)(SY_RT_INSTANCE_BAKED | SY_RT_INSTANCE_HIDDEN))
        return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "instance: unknown flags 0x%x", d->flags);
    float nrm[9];
    double gain;
    sy_rt_result r = sy_rt_placement_check(dev, mesh, d->transform, nrm, &gain);
    if (r != SY_RT_OK) return r;
    uint32_t flags = d->flags;
    if (gain > SY_RT_INSTANCE_GAIN_MAX) flags |= SY_RT_INSTANCE_BAKED; /* Embree never sees its inverse */
    if (!(flags & SY_RT_INSTANCE_BAKED) && (r = sy_rt_mesh_blas(dev, mesh)) != SY_RT_OK) return r;

    sy_rt_instance_data *in = calloc(1, sizeof *in);
    if (!in) return FAIL(SY_RT_ERROR_OUT_OF_MEMORY, "instance: out of memory");
    in->mesh = mesh;
    in->mesh_handle = d->mesh.id;
    mesh->refs++;
    in->material = d->material;
    in->flags = flags;
    in->top_id = RTC_INVALID_GEOMETRY_ID;
    in->area_base = UINT32_MAX; /* not in the area-light list until a commit puts it there */
    memcpy(in->xf, d->transform, sizeof in->xf);
    memcpy(in->nrm, nrm, sizeof in->nrm);

    if (flags & SY_RT_INSTANCE_BAKED) {
        in->geom = rtcNewGeometry(dev->rtc, RTC_GEOMETRY_TYPE_TRIANGLE);
        if (in->geom) {
            in->baked_positions = rtcSetNewGeometryBuffer(in->geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                          3 * sizeof(float), mesh->vertex_count);
            /* The index buffer is shared with the mesh, which this instance keeps alive. */
            rtcSetSharedGeometryBuffer(in->geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, mesh->indices, 0,
                                       3 * sizeof(uint32_t), mesh->triangle_count);
            if (in->baked_positions) sy_rt_bake_positions(in);
            rtcSetGeometryUserData(in->geom, dev);
        }
    } else {
        in->geom = rtcNewGeometry(dev->rtc, RTC_GEOMETRY_TYPE_INSTANCE);
        if (in->geom) {
            rtcSetGeometryInstancedScene(in->geom, mesh->scene);
            rtcSetGeometryTransform(in->geom, 0, RTC_FORMAT_FLOAT4X4_COLUMN_MAJOR, in->xf);
        }
    }
    if (in->geom) {
        if (flags & SY_RT_INSTANCE_HIDDEN) rtcDisableGeometry(in->geom);
        rtcCommitGeometry(in->geom);
        in->top_id = rtcAttachGeometry(dev->top, in->geom);
    }
    if ((r = sy_rt_check_embree(dev, "instance: creating geometry")) != SY_RT_OK) goto fail;
    if (!in->geom || ((flags & SY_RT_INSTANCE_BAKED) && !in->baked_positions) || in->top_id == RTC_INVALID_GEOMETRY_ID) {
        r = FAIL(SY_RT_ERROR_EMBREE, "instance: Embree geometry creation failed");
        goto fail;
    }
    if (!top_map_set(dev, in->top_id, in)) { r = FAIL(SY_RT_ERROR_OUT_OF_MEMORY, "instance: out of memory"); goto fail; }
    if (!sy_rt_pool_insert(&dev->instances, in, &out->id)) { r = FAIL(SY_RT_ERROR_LIMIT, "instance: pool full or out of memory"); goto fail; }
    in->handle = out->id;
    if (sy_rt_instance_emissive(dev, in)) dev->area_dirty = true;
    if (sy_rt_instance_masked(dev, in)) dev->filters_dirty = true;
    dev->dirty = dev->top_dirty = dev->shadow_dirty = true;
    return SY_RT_OK;
fail:
    sy_rt_instance_free(dev, in);
    dev->dirty = dev->top_dirty = dev->shadow_dirty = true;
    return r;
}

sy_rt_result sy_rt_instance_set_transform(sy_rt_device *dev, sy_rt_instance inst, const float transform[16])
{
    if (!dev || !transform) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "instance set_transform: NULL argument");
    sy_rt_instance_data *in = sy_rt_pool_find(dev, &dev->instances, inst.id, "instance set_transform");
    if (!in) return SY_RT_ERROR_INVALID_HANDLE;
    float nrm[9];
    sy_rt_result r = sy_rt_placement_recheck(dev, in, transform, nrm, "instance set_transform: the transform",
                                             "; create it again");
    if (r != SY_RT_OK) return r;
    if (!sy_rt_pending_add(dev, in)) return FAIL(SY_RT_ERROR_OUT_OF_MEMORY, "instance set_transform: out of memory");
    memcpy(in->xf, transform, sizeof in->xf);
    memcpy(in->nrm, nrm, sizeof in->nrm);
    if (sy_rt_instance_emissive(dev, in)) dev->area_dirty = true;
    dev->dirty = true;
    return SY_RT_OK;
}

sy_rt_result sy_rt_instance_set_material(sy_rt_device *dev, sy_rt_instance inst, sy_rt_material material)
{
    if (!dev) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "instance set_material: NULL device");
    sy_rt_instance_data *in = sy_rt_pool_find(dev, &dev->instances, inst.id, "instance set_material");
    if (!in) return SY_RT_ERROR_INVALID_HANDLE;
    if (material.id != 0 && !sy_rt_pool_get(&dev->materials, material.id))
        return FAIL(SY_RT_ERROR_INVALID_HANDLE, "instance set_material: material handle 0x%08x is stale", material.id);
    bool was_emissive = sy_rt_instance_emissive(dev, in), was_masked = sy_rt_instance_masked(dev, in);
    in->material = material;
    if (was_emissive || sy_rt_instance_emissive(dev, in)) dev->area_dirty = true;
    if (was_masked != sy_rt_instance_masked(dev, in)) dev->filters_dirty = true;
    dev->dirty = dev->shadow_dirty = true;
    return SY_RT_OK;
}

sy_rt_result sy_rt_instance_set_visible(sy_rt_device *dev, sy_rt_instance inst, bool visible)
{
    if (!dev) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "instance set_visible: NULL device");
    sy_rt_instance_data *in = sy_rt_pool_find(dev, &dev->instances, inst.id, "instance set_visible");
    if (!in) return SY_RT_ERROR_INVALID_HANDLE;
    bool is_visible = !(in->flags & SY_RT_INSTANCE_HIDDEN);
    if (is_visible == visible) return SY_RT_OK;
    if (visible) {
        in->flags &= ~(uint32_t)SY_RT_INSTANCE_HIDDEN;
        rtcEnableGeometry(in->geom);
    } else {
        in->flags |= SY_RT_INSTANCE_HIDDEN;
        rtcDisableGeometry(in->geom);
    }
    if (sy_rt_material_lookup(dev, in->material)->emissive) dev->area_dirty = true;
    if (sy_rt_instance_masked(dev, in)) dev->filters_dirty = true;
    dev->dirty = dev->top_dirty = dev->shadow_dirty = true;
    return sy_rt_check_embree(dev, "instance set_visible");
}

sy_rt_result sy_rt_instance_destroy(sy_rt_device *dev, sy_rt_instance inst)
{
    if (!dev) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "instance destroy: NULL device");
    sy_rt_instance_data *in = sy_rt_pool_take(dev, &dev->instances, inst.id, "instance destroy");
    if (!in) return SY_RT_ERROR_INVALID_HANDLE;
    if (sy_rt_instance_emissive(dev, in)) dev->area_dirty = true;
    if (sy_rt_instance_masked(dev, in)) dev->filters_dirty = true;
    sy_rt_instance_free(dev, in);
    dev->dirty = dev->top_dirty = dev->shadow_dirty = true;
    return sy_rt_check_embree(dev, "instance destroy");
}
