/* sy_rt_device.h — internal state of the ray-tracing back-end: the device, the handle pools and
 * the per-object structs shared by the scene, texture, render and integrator modules, plus the
 * error helpers every entry point uses. Not part of the public API (see sy_rt.h). */
#ifndef SY_RT_DEVICE_H
#define SY_RT_DEVICE_H

#include "sy_rt.h"
#include "sy_rt_math.h"
#include "sy_rt_sampler.h"

#include <embree3/rtcore.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdarg.h>
#include <string.h>

#include "sy_rt_base.h"

/* >>objects */

/* Meshes of at least this many triangles get a compact, medium-quality BLAS (sy_rt_mesh.c). */
#define SY_RT_LARGE_MESH_TRIANGLES (1u << 20)

typedef struct sy_rt_mesh_data {
    RTCScene scene;       /* BLAS holding geom as geometry 0; NULL until a non-baked instance needs it */
    RTCGeometry geom;
    const float *positions;  /* vertex buffer, float3: Embree's own, or the caller's (shared) */
    const uint32_t *indices; /* index buffer, 3 per triangle: Embree's own, or the caller's (shared) */
    const float *normals, *uv[2], *colors; /* own copies, the caller's arrays (shared), or NULL */
    void (*release)(void *);  /* shared: gives the caller's arrays back (mesh_free) */
    void *release_user;
    bool shared;              /* the arrays are the caller's (not freed here) */
    bool own_positions;       /* positions is an Embree buffer of its own (a copy, or rewritten by sy_rt_mesh_update) */
    float *updated_normals;   /* a shared mesh's normals rewritten by sy_rt_mesh_update (own; freed with it) */
    bool refitting;           /* updated by sy_rt_mesh_update: its BLAS is built LOW, its geometry REFIT */
    /* Motion blur of a deforming mesh (sy_rt_mesh_update_motion): positions / normals are its pose at
     * ray time 0 (the shutter's open), positions1 / normals1 at time 1 (its close); Embree
     * interpolates the vertices linearly (two time steps on geom), shading likewise
     * (sy_rt_surface_fetch_at). */
    bool motion;
    const float *positions1;  /* Embree's vertex buffer of time step 1 while motion (the last step: the close) */
    float *normals1;          /* own, while motion with normals */
    /* more than two steps (sy_rt_mesh_update_steps): step k at time k / (motion_steps - 1); steps 1 ..
     * motion_steps - 2 in pos_mid[k] (Embree's vertex buffers) and nrm_mid[k] (own, with normals) */
    uint32_t motion_steps;    /* with motion: 2 .. SY_RT_MOTION_STEPS_MAX */
    const float *pos_mid[SY_RT_MOTION_STEPS_MAX];
    float *nrm_mid[SY_RT_MOTION_STEPS_MAX];
    uint64_t own_bytes, shared_bytes; /* accounting (sy_rt_device_stats) */
    uint32_t vertex_count, triangle_count;
    int closed;           /* sy_rt_mesh_desc.closed: section caps fill its cut faces (1, -1: its winding) */
    float extent;         /* largest |coordinate| of its positions */
    uint32_t refs;        /* 1 for the live handle + 1 per instance */
    bool filter_on;       /* alpha filter installed on geom */
    bool want_filter;     /* scratch for sy_rt_commit: some instance needs the filter */
} sy_rt_mesh_data;

typedef struct sy_rt_material_data {
    sy_rt_material_desc desc;
    bool emissive;  /* emissive factor non-zero */
    bool masked;    /* alpha mode MASK: needs the Embree alpha filter */
    bool textured;  /* some texture slot is set: hits need texture coordinates */
    bool volume;    /* KHR_materials_volume absorbs: thickness > 0 and a finite attenuation distance */
    float sigma[3]; /* absorption coefficient per unit length: -ln(attenuation_color) / distance */
} sy_rt_material_data;

typedef struct sy_rt_instance_data {
    sy_rt_mesh_data *mesh;     /* holds a reference */
    sy_rt_material material;   /* resolved at render time */
    uint32_t flags;
    float xf[16];              /* object-to-world */
    float nrm[9];              /* inverse transpose of the upper 3x3, row-major */
    RTCGeometry geom;          /* instance geometry or baked triangle geometry in the top scene */
    unsigned top_id;           /* geometry id in the top scene */
    float *baked_positions;    /* baked: Embree vertex buffer (world space) */
    bool filter_on;            /* baked: alpha filter installed */
    uint32_t handle;           /* this instance's own handle id (coverage output) */
    uint32_t mesh_handle;      /* the handle id of the mesh it was made with (sy_rt_instance_get_mesh) */
    /* Moves without rebuilding the top-level BVH (sy_rt_moved.c): */
    bool xf_pending;           /* geom in the top scene still holds an older transform (in dev->pending) */
    bool stale;                /* the top scene's copy is filtered out; `twin` in dev->dyn shows the instance */
    RTCGeometry twin;          /* instance of the mesh's BLAS in dev->dyn, or NULL */
    unsigned twin_id;          /* its geometry id in dev->dyn */
    uint32_t area_base;        /* committed emissive instance: its triangles' entries in dev->area_map
                                * start here (UINT32_MAX: none) */
    /* Motion blur (sy_rt_instance_set_motion, _set_motion_steps): xf is the placement at ray time 0
     * (shutter open), xf1 at time 1 (shutter close), xf_mid the steps between (motion_steps > 2:
     * step k at time k / (motion_steps - 1)); Embree interpolates the matrices linearly between
     * consecutive steps (time steps on geom, its twin, or a baked instance's further vertex buffers)
     * and shading does the same (sy_rt_instance_at). */
    bool motion;
    uint32_t motion_steps;     /* with motion: 2 .. SY_RT_MOTION_STEPS_MAX */
    float xf1[16];
    float *xf_mid;             /* own: (motion_steps - 2) matrices, steps 1 .. motion_steps - 2; or NULL */
    uint32_t baked_steps;      /* baked with motion: the time steps baked_pos holds buffers for */
    float *baked_pos[SY_RT_MOTION_STEPS_MAX]; /* baked with motion: Embree vertex buffers of steps 1 ..
                                               * baked_steps - 1 (world space; [0] unused) */
} sy_rt_instance_data;

/* Step k (0 .. motion_steps - 1) of a moving instance's placement. */
static inline const float *sy_rt_instance_step(const sy_rt_instance_data *in, uint32_t k)
{
    return k == 0 ? in->xf : k + 1u >= in->motion_steps ? in->xf1 : in->xf_mid + 16u * (k - 1u);
}

typedef struct sy_rt_light_data {
    sy_rt_light_desc desc;
} sy_rt_light_data;

/* A committed punctual light, precomputed for shading. */
typedef struct sy_rt_punctual {
    uint32_t handle;    /* its sy_rt_light id (messages) */
    sy_rt_light_type type;
    sy_rt_v3 radiant;   /* color * intensity */
    sy_rt_v3 position;
    sy_rt_v3 direction; /* unit, direction of travel */
    float range;
    float cone_scale, cone_offset; /* spot: attenuation = clamp(cos*scale + offset)^2 */
} sy_rt_punctual;

/* One emissive world-space triangle of the area-light list. */
typedef struct sy_rt_area_tri {
    sy_rt_v3 p0, e1, e2;        /* world position of vertex 0 and edges to vertices 1, 2 */
    sy_rt_v3 normal;            /* unit geometric normal, front side (glTF winding) */
    float area;
    float pdf_select;           /* sy_rt_area_pdf of its instance: selection pdf per unit area */
    sy_rt_v3 emission;          /* the material's emissive factor (x strength) */
    const sy_rt_instance_data *inst; /* for the emissive texture lookup */
    uint32_t prim;
    bool double_sided;
    bool textured;              /* the emission is textured: sy_rt_surface_emission at the point */
} sy_rt_area_tri;

struct sy_rt_device {
    sy_rt_sobol sobol; /* the integrators' sampler tables: built once, read-only after create */
    RTCDevice rtc;
    RTCScene top;
    /* Instances moved since the top-level BVH was last built: rebuilding the top scene costs
     * O(instances) (about 5 ms at 10^4), so a moved instance's copy in `top` is filtered out (the
     * context filter sy_rt_context_filter, installed only while stale_count > 0) and a twin instance
     * in the small scene `dyn`, attached under the same geometry id, shows it where it is now. Every
     * ray cast traces `top`, then `dyn` when dyn_count > 0 (sy_rt_frame.h). The next full rebuild
     * (anything structural, or more than sy_rt_stale_limit stale instances) folds them back. */
    RTCScene dyn;
    uint32_t dyn_count;    /* twins attached to dyn */
    sy_rt_instance_data **dyn_map; /* dyn geometry id -> instance (ids are dense: Embree's commit
                                    * walks every id up to the largest) */
    uint32_t dyn_map_cap;
    uint32_t stale_count;  /* instances with stale set */
    uint32_t motion_count; /* instances and meshes with motion (sy_rt_instance_set_motion, sy_rt_mesh_update_motion): rays get times */
    /* Section planes of the call in progress (sy_rt_clip_begin: the camera's), read by the context
     * filter sy_rt_context_filter on every hit. */
    uint32_t clip_count;
    float clip_planes[SY_RT_CLIP_PLANES_MAX][4];
    uint32_t clip_cap;        /* caps on closed meshes (sy_rt_camera.clip_cap), with clip_count > 0 */
    float clip_cap_color[3];
    sy_rt_instance_data **pending; /* instances with xf_pending */
    uint32_t pending_count, pending_cap;
    bool dyn_dirty;        /* dyn needs rtcCommitScene */
    uint64_t top_builds;   /* rtcCommitScene(top) calls (sy_rt_stats) */
    uint64_t top_fast_builds; /* of them with top_fast */
    bool top_fast_on;      /* sy_rt_set_top_fast(dev, true): top_fast when most instances move */
    uint32_t thread_count; /* render threads asked for (sy_rt_device_desc); 0 = OpenMP default */

    /* Embree error callback output; read back by the call that triggered it. */
    pthread_mutex_t rtc_err_lock;
    char rtc_msg[256];
    /* the error report (sy_rt_device_desc.error and the last message, sy_rt_device_error): reached
     * through a pointer, so that calls given a const device (rendering) report too; the device is
     * used by one thread at a time */
    sy_rt_report report_store;
    sy_rt_report *report; /* &report_store */

    sy_rt_pool meshes, instances, materials, textures, lights;

    /* top-scene geometry id -> instance (for hit lookup); NULL where unused */
    sy_rt_instance_data **top_map;
    uint32_t top_map_cap;

    sy_rt_background background_staged, background;

    bool dirty;          /* anything changed since the last commit */
    uint64_t version;    /* commits that published a change */
    bool top_dirty;      /* top scene needs rtcCommitScene */
    bool settle;         /* sy_rt_settle: the next commit moves instances through the top scene, no twins */
    bool top_fast;       /* the top scene is built for frequent updates (RTC_SCENE_FLAG_DYNAMIC, quality
                          * LOW): top_fast_on and most instances moved in its last build
                          * (sy_rt_commit_moved); a fresh build (and sy_rt_settle) gives the usual
                          * MEDIUM one */
    bool area_dirty;     /* area-light list needs a rebuild */
    bool filters_dirty;  /* alpha filters may need (un)installing */
    bool punctual_dirty; /* punctual light array needs a rebuild */
    bool shadow_dirty;   /* shadow_blend / shadow_transmission need a recount (an instance's material,
                          * visibility or existence, or a material changed; never a transform) */
    double last_top_commit_seconds; /* rtcCommitScene of the top-level scene in the last commit */

    /* committed light data used while rendering */
    sy_rt_punctual *punctual;
    uint32_t punctual_count;
    sy_rt_area_tri *area;
    float *area_cdf;     /* area_count + 1 entries, cdf[0] = 0, cdf[n] = 1 */
    uint32_t area_count;
    float area_power;    /* total emitted power proxy (luminance * area * sides) */
    /* Vose alias table over the same triangles and weights (path tracer: O(1) selection) */
    float *area_alias_prob;
    uint32_t *area_alias_idx;
    /* emissive instance triangle -> its index in area (UINT32_MAX: degenerate, left out), from
     * instance->area_base; what a BSDF ray's emitter hit needs for the light tree's pdf */
    uint32_t *area_map;
    /* the light tree (sy_rt_lighttree.h) over area (indices 0 .. area_count - 1) then punctual
     * (area_count + i): built by sy_rt_light_tree_ensure when a render uses it; light_tree_dirty
     * after the lights changed (refit when the set is the same) */
    struct sy_rt_lighttree *light_tree;
    bool light_tree_dirty;
    double light_tree_build_seconds, light_tree_refit_seconds;
    uint32_t light_tree_refit_changed;
    uint64_t light_tree_builds, light_tree_refits;
    uint32_t light_warnings;     /* emitters left out (sy_rt_stats) */
    char light_warning[256];

    /* committed: some visible instance's material lets shadow rays through in part (alpha blend;
     * transmission); without one, shadow rays are plain occlusion queries (sy_rt_shadow.h) */
    bool shadow_blend, shadow_transmission;

    /* environment (sy_rt_set_environment): staged values and the committed importance-sampling
     * distribution (sy_rt_lights.h) */
    sy_rt_texture env_texture_staged, env_texture;
    float env_intensity_staged, env_intensity;
    bool env_dirty;
    struct sy_rt_env_dist *env_dist;
    /* Whitted's prefiltered environment (sy_rt_envfilter.h): built on its first render, freed with
     * env_dist */
    struct sy_rt_envfilter *env_filter;

    sy_rt_material_data default_material;
    float srgb_lut[256]; /* sRGB 8-bit -> linear */

    /* memory accounting: mesh arrays (own copies, shared), Embree's allocations (memory monitor) */
    uint64_t mesh_bytes, shared_bytes;
    _Atomic int64_t embree_bytes, embree_peak;
    int64_t max_memory; /* sy_rt_device_desc.max_memory_bytes (0 = none) */
};

/* Checked size arithmetic: false on overflow. */
static inline bool sy_rt_size_mul(size_t a, size_t b, size_t *out)
{
    if (a != 0 && b > SIZE_MAX / a) return false;
    *out = a * b;
    return true;
}

/* Threads a render runs on: thread_count, or where that is 0 the OpenMP default team size of the
 * calling thread (OMP_NUM_THREADS, else the cores this process may run on). Also Embree's. */
int sy_rt_render_threads(const sy_rt_device *dev);

/* Lookups used at render time; NULL for invalid handles. */
static inline const sy_rt_material_data *sy_rt_material_lookup(const sy_rt_device *dev, sy_rt_material m)
{
    const sy_rt_material_data *d = (const sy_rt_material_data *)sy_rt_pool_get(&dev->materials, m.id);
    return d ? d : &dev->default_material;
}

/* The instance a hit belongs to (instance id for Embree instances, geometry id for baked). */
/* The context filter of every trace while some instance is stale or the call cuts with section
 * planes (sy_rt_clip.c): it hides the top scene's stale copies of moved instances and rejects hits
 * whose world point is on the cut side of a section plane (the exact rule for closed meshes: a ray
 * leaving the kept part across a plane goes on to what is behind). */
void sy_rt_context_filter(const struct RTCFilterFunctionNArguments *args);
/* Takes the camera's section planes for the call that begins (render, pick, coverage, benchmarks). */
static inline void sy_rt_clip_begin(sy_rt_device *dev, const sy_rt_camera *cam)
{
    uint32_t n = cam->clip_count < SY_RT_CLIP_PLANES_MAX ? cam->clip_count : SY_RT_CLIP_PLANES_MAX;
    dev->clip_count = n;
    if (n) memcpy(dev->clip_planes, cam->clip_planes, n * sizeof dev->clip_planes[0]);
    dev->clip_cap = n && cam->clip_cap;
    memcpy(dev->clip_cap_color, cam->clip_cap_color, sizeof dev->clip_cap_color);
}

/* Section caps (sy_rt_camera.clip_cap): true when the nearest kept hit of org + t*dir at t = thit,
 * triangle prim of instance in, is a back face of a closed mesh and the ray entered the kept region
 * (inside every plane) at t_enter with tnear < t_enter < thit: between the two nothing is hit, so
 * the ray is inside the solid where it crosses the plane, and the cut face is there. *t_cap gets
 * t_enter. false when the call does not cap. Every integrator asks it of every hit it shades. */
bool sy_rt_clip_cap(const sy_rt_device *dev, const sy_rt_instance_data *in, unsigned prim, sy_rt_v3 org, sy_rt_v3 dir,
                    float tnear, float thit, float *t_cap);

/* True when the point (x, y, z) (world) lies on a removed side of the call's section planes (a x + b y + c z
 * + d < 0 for some plane): the context filter drops such hits, and the lights' sampling treats an
 * emitter point there as unseen (an emitter in a removed part lights nothing). */
static inline bool sy_rt_clip_removes(const sy_rt_device *dev, float x, float y, float z)
{
    for (uint32_t c = 0; c < dev->clip_count; ++c) {
        const float *q = dev->clip_planes[c];
        if (q[0] * x + q[1] * y + q[2] * z + q[3] < 0.0f) return true;
    }
    return false;
}

/* Every intersection context of the back-end: Embree's, then which scene is being traced. Filter
 * functions receive &rtc and read the rest (every context comes from sy_rt_context_init). */
typedef struct sy_rt_ictx {
    struct RTCIntersectContext rtc; /* first member */
    int in_dyn;                     /* tracing dev->dyn: instance ids are dyn ids (dev->dyn_map) */
    float time;                     /* the time in [0, 1) of the rays cast with it (motion blur: 0 =
                                     * shutter open, 1 = close; sy_rt_intersect, sy_rt_segment_clear) */
    RTCFilterFunctionN saved;       /* the filter while tracing dev->dyn */
    RTCFilterFunctionN dyn_filter;  /* the filter while tracing dev->dyn: the context filter when the call
                                       cuts with section planes, else none (set by sy_rt_context_init, so
                                       that a module tracing dyn needs no reference to the filter) */
} sy_rt_ictx;

/* Every intersection context starts here: the stale filter is on exactly while some instance's
 * top-level copy is stale. */
static inline void sy_rt_context_init(const sy_rt_device *dev, sy_rt_ictx *ctx, enum RTCIntersectContextFlags flags)
{
    rtcInitIntersectContext(&ctx->rtc);
    ctx->rtc.flags = flags;
    ctx->in_dyn = 0;
    ctx->time = 0.0f;
    ctx->saved = NULL;
    ctx->dyn_filter = dev->clip_count ? sy_rt_context_filter : NULL;
    if (dev->stale_count || dev->clip_count) ctx->rtc.filter = sy_rt_context_filter;
}

/* Around a trace of dev->dyn: no stale copies there (the filter only cuts), ids read through
 * dev->dyn_map. */
static inline void sy_rt_ictx_enter_dyn(sy_rt_ictx *ctx)
{
    ctx->saved = ctx->rtc.filter;
    ctx->rtc.filter = ctx->dyn_filter;
    ctx->in_dyn = 1;
}
static inline void sy_rt_ictx_leave_dyn(sy_rt_ictx *ctx)
{
    ctx->in_dyn = 0;
    ctx->rtc.filter = ctx->saved;
}

/* The instance of a hit seen by a filter function (geometry ids as Embree reports them). */
static inline const sy_rt_instance_data *sy_rt_filter_instance(const sy_rt_device *dev,
                                                               const struct RTCIntersectContext *ctx, unsigned geom_id,
                                                               unsigned inst_id);

/* The top-scene id of the instance whose twin has dyn geometry id `id`. */
static inline unsigned sy_rt_dyn_to_top(const sy_rt_device *dev, unsigned id)
{
    return id < dev->dyn_map_cap && dev->dyn_map[id] ? dev->dyn_map[id]->top_id : RTC_INVALID_GEOMETRY_ID;
}

static inline const sy_rt_instance_data *sy_rt_hit_instance(const sy_rt_device *dev, unsigned geom_id,
                                                            unsigned inst_id)
{
    unsigned top = inst_id != RTC_INVALID_GEOMETRY_ID ? inst_id : geom_id;
    return top < dev->top_map_cap ? dev->top_map[top] : NULL;
}

static inline const sy_rt_instance_data *sy_rt_filter_instance(const sy_rt_device *dev,
                                                               const struct RTCIntersectContext *ctx, unsigned geom_id,
                                                               unsigned inst_id)
{
    if (((const sy_rt_ictx *)ctx)->in_dyn) inst_id = sy_rt_dyn_to_top(dev, inst_id);
    return sy_rt_hit_instance(dev, geom_id, inst_id);
}

/* The instance as placed at ray time `time` (motion blur): in itself when it does not move, else
 * *scratch, a copy with the object-to-world matrix interpolated linearly between xf (time 0) and xf1
 * (time 1), or between the two steps around the time (motion_steps > 2), as Embree interpolates it, and its normal matrix (the inverse transpose of the upper
 * 3x3; a singular interpolated matrix keeps xf's). Shading reads the returned instance. */
static inline const sy_rt_instance_data *sy_rt_instance_at(const sy_rt_instance_data *in, float time,
                                                           sy_rt_instance_data *scratch)
{
    if (!in || !in->motion) return in;
    *scratch = *in;
    if (in->motion_steps <= 2u) {
        for (int i = 0; i < 16; ++i) scratch->xf[i] = (1.0f - time) * in->xf[i] + time * in->xf1[i];
    } else { /* the segment the time falls in, as Embree finds it */
        float s = time * (float)(in->motion_steps - 1u);
        uint32_t k = s > 0.0f ? (uint32_t)s : 0u;
        if (k > in->motion_steps - 2u) k = in->motion_steps - 2u;
        float f = s - (float)k;
        const float *a = sy_rt_instance_step(in, k), *b = sy_rt_instance_step(in, k + 1u);
        for (int i = 0; i < 16; ++i) scratch->xf[i] = (1.0f - f) * a[i] + f * b[i];
    }
    const float *x = scratch->xf; /* column-major: a[r][c] = x[c * 4 + r] */
    float c00 = x[5] * x[10] - x[9] * x[6], c01 = -(x[1] * x[10] - x[9] * x[2]), c02 = x[1] * x[6] - x[5] * x[2];
    float c10 = -(x[4] * x[10] - x[8] * x[6]), c11 = x[0] * x[10] - x[8] * x[2], c12 = -(x[0] * x[6] - x[4] * x[2]);
    float c20 = x[4] * x[9] - x[8] * x[5], c21 = -(x[0] * x[9] - x[8] * x[1]), c22 = x[0] * x[5] - x[4] * x[1];
    float det = x[0] * c00 + x[4] * c01 + x[8] * c02;
    if (!(det != 0.0f) || !isfinite(det)) return in;
    float inv = 1.0f / det;
    /* row-major inverse transpose: the cofactor matrix / det (sy_rt_placement_check in sy_rt_placement.c) */
    float n[9] = {c00, c01, c02, c10, c11, c12, c20, c21, c22};
    for (int i = 0; i < 9; ++i) scratch->nrm[i] = n[i] * inv;
    return scratch;
}

#endif /* SY_RT_DEVICE_H */
