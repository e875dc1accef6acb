/* sy_rt_lights.h — light support of the integrators: punctual-light incidence (Whitted and path
 * tracer), the Vose alias table over the emissive triangles (selection by power in O(1), whatever
 * their number), the environment light (equirectangular texture x intensity; the background never
 * lights anything) with its importance-sampling distribution, the background seen by camera rays,
 * and the area-light pdf of a hit point. Built at sy_rt_commit; read-only while rendering.
 * Internal to backends/rt. */
#ifndef SY_RT_LIGHTS_H
#define SY_RT_LIGHTS_H

#include "sy_rt_device.h"

/* Piecewise-constant 2D distribution over the texels of an environment map. */
typedef struct sy_rt_env_dist {
    uint32_t width, height;
    float *marginal;    /* height + 1 entries: CDF over rows */
    float *conditional; /* height x (width + 1): CDF over the texels of each row */
    float *texel_pdf;   /* width x height: probability of each texel (sums to 1) */
    /* guide tables (sy_rt_cdf_guide, sy_rt_cdf_find): for each of the n equal steps of [0, 1) of a
     * CDF of n cells, the last cell whose CDF value is <= the step's start; height entries for the
     * marginal, height x width for the rows */
    uint32_t *guide_marginal, *guide_conditional;
    float mean_luminance; /* the texture's luminance averaged over the sphere (solid-angle weights) */
} sy_rt_env_dist;

/* (Re)builds dev->area_alias_* from per-triangle weights (n entries, total > 0). Returns false when
 * out of memory (tables left NULL). */
bool sy_rt_alias_build(sy_rt_device *dev, const double *weights, uint32_t n);
/* Picks an area triangle with probability weight / total from one uniform number in [0, 1). */
uint32_t sy_rt_alias_pick(const sy_rt_device *dev, float u);

/* Rebuilds dev->env_dist for the committed environment (NULL when there is none). */
sy_rt_result sy_rt_env_rebuild(sy_rt_device *dev);
void sy_rt_env_free(sy_rt_device *dev);

/* Environment light as seen by the integrators. mode: 0 none (escaping rays see black), 2 texture
 * (importance sampled). */
typedef struct sy_rt_env {
    int mode;
    const struct sy_rt_texture_data *tex; /* mode 2 */
    float intensity;
    const sy_rt_env_dist *dist;     /* mode 2 */
    const struct sy_rt_envfilter *filter; /* mode 2: Whitted's prefiltered maps, once built (else NULL) */
    float irradiance;               /* mode 2: pi x mean luminance x intensity, what a surface facing
                                     * the unoccluded environment receives (the light tree's split) */
    bool constant;                  /* mode 2 with a 1x1 texture (--env-color): every direction reads */
    sy_rt_v3 constant_radiance;     /* this radiance, the same value the lookup returns bit for bit */
} sy_rt_env;

/* Resolves the committed environment of dev (texture lookups happen once per frame). */
void sy_rt_env_get(const sy_rt_device *dev, sy_rt_env *env);
/* Radiance arriving from direction d (unit). */
sy_rt_v3 sy_rt_env_eval(const sy_rt_env *env, sy_rt_v3 d);
/* The same at lat-long coordinates u, v (sy_rt_latlong_uv of the direction). */
sy_rt_v3 sy_rt_env_eval_uv(const sy_rt_env *env, float u, float v);
/* sy_rt_env_eval and sy_rt_env_pdf of one direction at once (its lat-long coordinates computed once):
 * returns the radiance, *pdf the pdf. */
sy_rt_v3 sy_rt_env_eval_pdf(const sy_rt_env *env, sy_rt_v3 d, float *pdf);
/* The committed background along camera-ray direction *d (any length): radiance in *rgb, returns
 * its alpha (0 for NONE, else 1). (d by address: GCC built a by-value vector's first two
 * components through the stack at the path tracer's call, and the load waited for the stores.) */
float sy_rt_background_eval(const sy_rt_device *dev, const sy_rt_v3 *d, sy_rt_v3 *rgb);
/* Solid-angle pdf of sampling direction d with sy_rt_env_sample. */
float sy_rt_env_pdf(const sy_rt_env *env, sy_rt_v3 d);
/* Samples a direction from two uniform numbers; returns its pdf (0 = failed) and radiance. */
float sy_rt_env_sample(const sy_rt_env *env, float u1, float u2, sy_rt_v3 *d, sy_rt_v3 *radiance);

/* Light arriving at point p from punctual light l: the unit direction wi toward the light, the
 * irradiance-scaled radiance e (KHR_lights_punctual: inverse square, the glTF range window, spot
 * falloff) and the length of the shadow ray (INFINITY for directional lights). Returns false when
 * the light contributes nothing at p. */
bool sy_rt_punctual_incident(const sy_rt_punctual *l, sy_rt_v3 p, sy_rt_v3 *wi, sy_rt_v3 *e, float *tmax);

/* Area-measure pdf with which the alias table + uniform point selection picks a point on an
 * emissive instance (the same value for every point of the instance's non-degenerate triangles). */
float sy_rt_area_pdf(const sy_rt_device *dev, const sy_rt_instance_data *inst);
/* Triangle t of the area-light list (the open's placement: ray time 0) as placed at ray time `time`
 * (motion blur): t itself when its instance neither moves nor deforms, or at time 0; else *scratch,
 * t with p0, e1, e2, normal and area where its moving instance (sy_rt_instance_at) and deforming mesh
 * (its two vertex steps around the time, as Embree interpolates them) put it then, and pdf_select
 * per unit area of that triangle (the selection still weighs the open's area; a rigid motion keeps it). */
const sy_rt_area_tri *sy_rt_area_at(const sy_rt_area_tri *t, float time, sy_rt_area_tri *scratch);
/* The power proxy of an emissive material (luminance of the factor, or its largest channel). */
float sy_rt_emission_weight(const sy_rt_material_data *mat);

/* >>light tree glue (sy_rt_lighttree.h): the device's tree over its area triangles (light i) and
 * punctual lights (light area_count + i). */
/* Whether a render with this mode selects lights with the tree (AUTO: SY_RT_LIGHT_TREE_AUTO_MIN
 * lights or more). */
bool sy_rt_light_tree_wanted(const sy_rt_device *dev, sy_rt_light_tree_mode mode);
/* Builds (or, when the same lights only moved or changed power, refits) the tree when mode wants
 * it and the lights changed since; the memory it needs counts against the device's max_memory.
 * Emitters the tree leaves out are reported in sy_rt_stats (light_warnings). */
sy_rt_result sy_rt_light_tree_ensure(sy_rt_device *dev, sy_rt_light_tree_mode mode);
/* The tree a render with this mode uses, or NULL (OFF, AUTO below the threshold, not built). */
const struct sy_rt_lighttree *sy_rt_light_tree_get(const sy_rt_device *dev, sy_rt_light_tree_mode mode);
void sy_rt_light_tree_free(sy_rt_device *dev);
size_t sy_rt_light_tree_bytes(const sy_rt_device *dev);
/* The area-light index of triangle prim of an emissive instance (UINT32_MAX: none). */
static inline uint32_t sy_rt_area_index(const sy_rt_device *dev, const sy_rt_instance_data *in, uint32_t prim)
{
    return dev->area_map && in->area_base != UINT32_MAX && dev->area_count ? dev->area_map[in->area_base + prim]
                                                                           : UINT32_MAX;
}
/* The normal the tree weighs the surface cosine with: the facing geometric normal, none (zero) for
 * a BSDF that transmits (light from behind counts). */
static inline sy_rt_v3 sy_rt_light_tree_normal(sy_rt_v3 ng_facing, float q_trans)
{
    return q_trans > 0.0f ? v3(0.0f, 0.0f, 0.0f) : ng_facing;
}

#endif /* SY_RT_LIGHTS_H */
