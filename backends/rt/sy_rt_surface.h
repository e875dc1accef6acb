/* sy_rt_surface.h — evaluation of the surface at a ray hit: interpolated vertex attributes,
 * world-space geometric and shading normals (vertex normals, normal map), and the material
 * inputs with their textures applied (base colour * vertex colour, metallic/roughness, emission,
 * alpha). Also the Embree filter that cuts out alpha-masked surfaces. Internal to backends/rt. */
#ifndef SY_RT_SURFACE_H
#define SY_RT_SURFACE_H

#include "sy_rt_device.h"

typedef struct sy_rt_surface {
    const sy_rt_instance_data *inst;
    const sy_rt_material_data *mat;
    sy_rt_v3 p;         /* world-space hit position */
    sy_rt_v3 ng;        /* unit geometric normal on the front side (glTF winding) */
    sy_rt_v3 ns;        /* unit shading normal, turned to the side the ray came from */
    sy_rt_v3 ng_facing; /* ng turned to the side the ray came from */
    sy_rt_v3 ns_coat;   /* the clear coat's shading normal on that side (vertex normal + coat normal map) */
    bool coat_normal;   /* ns_coat differs from ns */
    bool front;         /* the ray hit the front side */
    sy_rt_v3 base;      /* base colour factor * texture * vertex colour (linear RGB) */
    float alpha;
    float metallic, roughness;
    float transmission; /* KHR_materials_transmission factor * texture R */
    float specular;     /* KHR_materials_specular factor * texture A */
    sy_rt_v3 specular_color; /* its colour factor * texture RGB */
    float clearcoat, clearcoat_roughness; /* KHR_materials_clearcoat factors * textures R, G */
    sy_rt_v3 sheen_color; /* KHR_materials_sheen colour factor * texture RGB */
    float sheen_roughness; /* its roughness factor * texture A */
    float iridescence;  /* KHR_materials_iridescence factor * texture R */
    float iridescence_thickness; /* film thickness (nm) at the point */
    float anisotropy;   /* KHR_materials_anisotropy strength * texture B (0: isotropic) */
    sy_rt_v3 aniso_dir; /* its world direction (roughness stretched along it), with anisotropy > 0 */
    sy_rt_v3 emission;  /* radiance */
} sy_rt_surface;

/* Evaluates the surface of triangle prim of instance inst at Embree barycentrics (u, v), hit by
 * a ray with direction dir (any length). */
void sy_rt_surface_fetch(const sy_rt_device *dev, const sy_rt_instance_data *inst, uint32_t prim, float u,
                         float v, sy_rt_v3 dir, sy_rt_surface *s);

/* sy_rt_surface_fetch of the instance as placed at ray time `time` (motion blur, sy_rt_instance_at):
 * the point and normals where the moving instance is at that time, and for a deforming mesh in
 * motion (sy_rt_mesh_update_motion) the hit triangle's vertices and normals interpolated between its
 * two poses at that time; s->inst is inst itself (the stored instance: identity comparisons and
 * lookups stay valid). */
void sy_rt_surface_fetch_at(const sy_rt_device *dev, const sy_rt_instance_data *inst, float time, uint32_t prim, float u,
                            float v, sy_rt_v3 dir, sy_rt_surface *s);

/* Eye-light colour of the PRIMARY integrator at a hit, bit-identical to shading the full
 * sy_rt_surface_fetch result (emission for emitters, base colour for unlit materials, otherwise
 * base colour * |cos(shading normal, ray)|), but evaluating only what that needs. */
sy_rt_v3 sy_rt_surface_eyelight(const sy_rt_device *dev, const sy_rt_instance_data *inst, uint32_t prim, float u,
                                float v, sy_rt_v3 dir);

/* Coverage alpha of a point (factor * texture alpha * vertex alpha). */
float sy_rt_surface_alpha(const sy_rt_device *dev, const sy_rt_instance_data *inst, uint32_t prim, float u, float v);

/* Emission radiance at a point of an emissive instance (factor * emissive texture). */
sy_rt_v3 sy_rt_surface_emission(const sy_rt_device *dev, const sy_rt_instance_data *inst, uint32_t prim, float u, float v);

/* Embree intersect/occluded filter: rejects hits on alpha-masked materials below the cutoff.
 * geometryUserPtr is the device. */
void sy_rt_alpha_filter(const struct RTCFilterFunctionNArguments *args);

#endif /* SY_RT_SURFACE_H */
