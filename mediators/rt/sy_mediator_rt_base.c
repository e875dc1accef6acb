/* sy_mediator_rt_base.c — the rt adapter's shared ground (sy_mediator_rt_internal.h):
 * the declared parameter tables of its classes (whitted, pathtracer, coverage), the translation of
 * back-end errors and of the core camera into the back-end's. */
#define SY_RTI_DEFINING_PARAMS /* the tables take their size from their initialisers, checked below */
#include "sy_mediator_rt_internal.h"

#include <stdio.h>
#include <string.h>

/* Whitted's default anti-aliasing (spp, default 4 in sy_rti_whitted_params): 4 stratified camera rays per
 * pixel (one per quadrant, Sobol jittered), sharing the pixel's area-light budget (light_samples);
 * colour and alpha average them, a pixel is covered where any of them hits and its depth is the
 * mean of those hits, as in the path tracer and the raster's MSAA. spp=1 traces the pixel centre
 * alone. */

/* >>parameters: the classes' declared tables (sy_params.h), the one source of their names, ranges,
 * defaults and help; core checks given parameters against them before create. The path tracer's
 * display-filter options are SY_PARAM_LIVE (sy_context_set_filter). Enum orders: "filter" is
 * pt_filter_kind, "rf_kernel" sy_filter_rf_kernel, "filter_kernel" separable, brute. */
#define RT_COMMON_PARAMS(depth_default, depth_max, depth_help)                                                      \
    {"max_depth", SY_PARAM_INT, 1, depth_max, depth_default, NULL, depth_help, 0},                                  \
    {"light_samples", SY_PARAM_INT, 0, 1024, "0", NULL, "area-light samples per pixel, shared by its pixel samples " \
     "(0: 8 where they sample only the visibility of the closed-form light, else 16)", 0},                           \
    {"threads", SY_PARAM_INT, 0, 1024, "0", NULL, "worker threads (0 = OpenMP's default: OMP_NUM_THREADS, else all cores)", 0},                             \
    {"specular", SY_PARAM_FLOAT, 0, 1, "1", NULL,                                                                   \
     "KHR_materials_specular factor of every material (0: dielectrics purely Lambertian)", 0},                       \
    {"max_memory_mb", SY_PARAM_INT, 0, 1 << 30, "0", NULL,                                                          \
     "MB Embree may hold (0: no limit of its own); a mesh whose BVH needs more than is left, or than the machine "  \
     "has available, is refused with both sizes", 0}
/* light_tree: enum order is sy_rt_light_tree_mode's (auto, on, off) */
#define RT_LIGHT_TREE_PARAM                                                                                         \
    {"light_tree", SY_PARAM_ENUM, 0, 0, "auto", "auto|on|off",                                                     \
     "light selection: on = the light tree (many lights), off = by power (alias table), auto = the tree from 64 "   \
     "lights (emissive triangles + punctual lights)", 0}
const sy_param_decl sy_rti_whitted_params[] = {
    {"spp", SY_PARAM_INT, 1, 256, "4", NULL, "camera rays per pixel (stratified, jittered; 1 = the pixel centre)", 0},
    {"env_samples", SY_PARAM_INT, 1, 256, "4", NULL, "environment-light samples per shading point and pixel sample", 0},
    RT_COMMON_PARAMS("8", 64, "longest ray path: depth of mirror and glass recursion"),
    RT_LIGHT_TREE_PARAM,
};
const sy_param_decl sy_rti_coverage_params[] = {
    RT_COMMON_PARAMS("8", 64, "longest ray path: depth of mirror and glass recursion"),
};
#define LIVE SY_PARAM_LIVE
const sy_param_decl sy_rti_pathtracer_params[] = {
    RT_COMMON_PARAMS("64", 1024, "bounces per path"),
    RT_LIGHT_TREE_PARAM,
    {"filter", SY_PARAM_ENUM, 0, 0, "none", "none|pixel|atrous|jbu|adaptive|radiance", "display noise filter", LIVE},
    {"threshold", SY_PARAM_FLOAT, 0, 1e6, "0.01", NULL,
     "perceived-variance threshold of the pixel filter's blend, the adaptive preview and radiance's T_u", LIVE},
    {"sigma_s", SY_PARAM_FLOAT, 0, 1000, "8", NULL, "pixel filter: spatial sigma (pixels, > 0)", LIVE},
    {"sigma_c", SY_PARAM_FLOAT, 0, 1e6, "0.02", NULL, "pixel filter: virtual-flash colour sigma (> 0)", LIVE},
    {"sigma_d", SY_PARAM_FLOAT, 0, 1e9, "2", NULL, "pixel filter: depth sigma (scene units, > 0)", LIVE},
    {"filter_kernel", SY_PARAM_ENUM, 0, 0, "separable", "separable|brute", "pixel filter: kernel evaluation", LIVE},
    {"filter_iterations", SY_PARAM_INT, 1, 8, "3", NULL, "pixel filter: iterations", LIVE},
    {"filter_start", SY_PARAM_INT, 1, 1 << 30, "4", NULL,
     "pixel filter: first pass at this sample count (a power of two), then at every power of two", LIVE},
    {"atrous_iterations", SY_PARAM_INT, 1, 10, "5", NULL, "a-trous filter: iterations", LIVE},
    {"jbu_factor", SY_PARAM_INT, 1, 64, "4", NULL, "joint bilateral upsampling: downsampling factor", LIVE},
    {"rf_warmup_frames", SY_PARAM_INT, 0, 64, "4", NULL, "radiance filter: warm-up frames", LIVE},
    {"rf_warmup_radius", SY_PARAM_FLOAT, 0, 128, "8", NULL, "radiance filter: warm-up radius (pixels, > 0)", LIVE},
    {"rf_max_radius", SY_PARAM_FLOAT, 1, 128, "24", NULL, "radiance filter: largest radius (pixels)", LIVE},
    {"rf_kernel", SY_PARAM_ENUM, 0, 0, "epanechnikov", "epanechnikov|silverman|uniform|gaussian",
     "radiance filter: kernel", LIVE},
    {"rf_ao", SY_PARAM_BOOL, 0, 0, "1", NULL, "radiance filter: ambient-occlusion term", LIVE},
    {"rf_prism_thickness", SY_PARAM_FLOAT, 0, 100, "0.25", NULL,
     "radiance filter: prism half thickness / tangent extent (> 0)", LIVE},
    {"rf_grazing_epsilon", SY_PARAM_FLOAT, 0, 1, "0.1", NULL, "radiance filter: grazing-angle epsilon (> 0)", LIVE},
    {"rf_glossy_limit", SY_PARAM_FLOAT, 0, 1e9, "128", NULL, "radiance filter: glossy limit", LIVE},
    {"rf_specular_limit", SY_PARAM_FLOAT, 0, 1e9, "4096", NULL, "radiance filter: specular limit", LIVE},
    {"rf_unbiased", SY_PARAM_BOOL, 0, 0, "0", NULL,
     "radiance filter: show the plain path-traced mean in the correction phase", LIVE},
    {"temporal", SY_PARAM_BOOL, 0, 0, "0", NULL,
     "temporal reuse while the camera moves (sy_filter_temporal.h): a frame whose camera moved since the last "
     "one shows the reprojected history blended with its samples and a-trous filtered; a still camera shows the "
     "accumulation unchanged (sy view and sy web turn it on)", LIVE},
    {"temporal_motion", SY_PARAM_BOOL, 0, 0, "1", NULL,
     "temporal reuse: follow moving instances (per-pixel object motion from their transforms at the last "
     "render; 0 = camera motion only, the comparison's baseline); with it, a still camera whose scene changed "
     "only by moves also reuses the history", LIVE},
    {"temporal_deform", SY_PARAM_BOOL, 0, 0, "1", NULL,
     "temporal reuse: follow deforming (skinned, morphed) meshes too (per-vertex motion: the hit point at the "
     "mesh's pose of the last render; 0 = their pixels get no object motion, the comparison's baseline); "
     "with temporal_motion=1", LIVE},
};
#undef LIVE
const sy_param_table sy_rti_whitted_table = SY_PARAM_TABLE(sy_rti_whitted_params);
const sy_param_table sy_rti_coverage_table = SY_PARAM_TABLE(sy_rti_coverage_params);
const sy_param_table sy_rti_pt_table = SY_PARAM_TABLE(sy_rti_pathtracer_params);
#define SY_RTI_COUNT_OF(a) (sizeof(a) / sizeof((a)[0]))
_Static_assert(SY_RTI_COUNT_OF(sy_rti_whitted_params) == SY_RTI_WHITTED_PARAM_COUNT, "SY_RTI_WHITTED_PARAM_COUNT");
_Static_assert(SY_RTI_COUNT_OF(sy_rti_coverage_params) == SY_RTI_COVERAGE_PARAM_COUNT, "SY_RTI_COVERAGE_PARAM_COUNT");
_Static_assert(SY_RTI_COUNT_OF(sy_rti_pathtracer_params) == SY_RTI_PATHTRACER_PARAM_COUNT,
               "SY_RTI_PATHTRACER_PARAM_COUNT");

/* Every code the device returns has core's number (the cast in sy_backend_fail). */
SY_BACKEND_SAME_CODE(SY_RT_ERROR_INVALID_ARGUMENT, SY_ERR_INVALID_ARGUMENT);
SY_BACKEND_SAME_CODE(SY_RT_ERROR_INVALID_HANDLE, SY_ERR_INVALID_HANDLE);
SY_BACKEND_SAME_CODE(SY_RT_ERROR_OUT_OF_MEMORY, SY_ERR_OUT_OF_MEMORY);
SY_BACKEND_SAME_CODE(SY_RT_ERROR_UNSUPPORTED, SY_ERR_UNSUPPORTED);
SY_BACKEND_SAME_CODE(SY_RT_ERROR_LIMIT, SY_ERR_LIMIT);
SY_BACKEND_SAME_CODE(SY_RT_ERROR_EMBREE, SY_ERR_BACKEND);
SY_BACKEND_SAME_CODE(SY_RT_ERROR_INVALID_OPERATION, SY_ERR_INVALID_OPERATION);
SY_BACKEND_SAME_CODE(SY_RT_ERROR_CANCELLED, SY_ERR_CANCELLED);
SY_BACKEND_SAME_CODE(SY_RT_ERROR_SYSTEM, SY_ERR_SYSTEM);

sy_result sy_rti_fail(const rt_state *st, sy_error *err, sy_rt_result r, const char *what)
{
    return sy_backend_fail(err, (int)r, NULL, what, st->rt_msg);
}

static void rt_error(void *user, sy_rt_result code, const char *message)
{
    (void)code;
    rt_state *st = user;
    snprintf(st->rt_msg, sizeof st->rt_msg, "%s", message);
}

sy_rt_device_desc sy_rti_device_desc(rt_state *st, uint32_t threads, uint64_t max_memory_bytes)
{
    sy_rt_device_desc d = {threads, max_memory_bytes, rt_error, st};
    return d;
}

void sy_rti_camera_of(const sy_camera_view *v, sy_rt_camera *cam)
{
    SY_MIRROR_FLAT_VIEW_COPY(cam, v, SY_RT);
    cam->projection = v->projection == SY_PROJECTION_ORTHOGRAPHIC ? SY_RT_PROJECTION_ORTHOGRAPHIC
                                                                  : SY_RT_PROJECTION_PERSPECTIVE;
}
