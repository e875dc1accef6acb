/* sy_rt_coverage.c — per-pixel object ids for culling services (with the hit triangle and its
 * barycentrics for temporal reuse's deforming meshes) and the pick of one pixel (see sy_rt.h,
 * >>coverage and >>pick). */
#include "sy_rt_coverage.h"

#include <math.h>
#include <string.h>

#define FAIL(code, ...) sy_rt_fail(dev, code, __VA_ARGS__)

static void coverage_hit(const sy_rt_frame *f, void *user, size_t o, const struct RTCRayHit *rh, float axial)
{
    const sy_rt_instance_data *in = rh->hit.geomID == RTC_INVALID_GEOMETRY_ID
                                        ? NULL
                                        : sy_rt_hit_instance(f->dev, rh->hit.geomID, rh->hit.instID[0]);
    ((uint32_t *)user)[o] = in ? in->handle : 0;
    if (f->depth) f->depth[o] = in ? rh->ray.tfar * axial : INFINITY;
}

void sy_rt_coverage_tile(const sy_rt_frame *f, void *user, uint32_t x0, uint32_t y0, uint32_t x1, uint32_t y1)
{
    sy_rt_frame_tile_hits(f, x0, y0, x1, y1, coverage_hit, user);
}

/* sy_rt_coverage_hits: the instance, triangle and barycentrics of each pixel's hit */
static void coverage_full_hit(const sy_rt_frame *f, void *user, size_t o, const struct RTCRayHit *rh, float axial)
{
    (void)axial;
    const sy_rt_instance_data *in = rh->hit.geomID == RTC_INVALID_GEOMETRY_ID
                                        ? NULL
                                        : sy_rt_hit_instance(f->dev, rh->hit.geomID, rh->hit.instID[0]);
    sy_rt_coverage_hit *h = (sy_rt_coverage_hit *)user + o;
    if (in && rh->hit.primID < in->mesh->triangle_count) *h = (sy_rt_coverage_hit){in->handle, rh->hit.primID, rh->hit.u, rh->hit.v};
    else *h = (sy_rt_coverage_hit){0, 0, 0.0f, 0.0f};
}

static void coverage_hits_tile(const sy_rt_frame *f, void *user, uint32_t x0, uint32_t y0, uint32_t x1, uint32_t y1)
{
    sy_rt_frame_tile_hits(f, x0, y0, x1, y1, coverage_full_hit, user);
}

/* One coverage pass (what: "coverage" or "coverage hits", for messages): tile_fn over every tile
 * with out (ids or hits); depth as sy_rt_coverage's */
static sy_rt_result coverage_run(sy_rt_device *dev, const sy_rt_camera *camera, const sy_rt_render_desc *desc,
                                 const char *what, void (*tile_fn)(const sy_rt_frame *, void *, uint32_t, uint32_t, uint32_t, uint32_t),
                                 void *out, float *depth)
{
    if (dev && camera) sy_rt_clip_begin(dev, camera);
    if (!dev || !camera || !desc || !out) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "%s: NULL argument", what);
    if (dev->dirty)
        return FAIL(SY_RT_ERROR_INVALID_OPERATION, "%s: the device has uncommitted changes; call sy_rt_commit first", what);
    sy_rt_render_desc d = *desc;
    d.integrator = SY_RT_INTEGRATOR_COVERAGE;
    sy_rt_frame f;
    sy_rt_result r = sy_rt_frame_init(&f, dev, camera, &d, NULL, depth);
    if (r != SY_RT_OK) return r;
    return sy_rt_run_tiles(&f, tile_fn, out, desc->progress, desc->progress_user_data);
}

sy_rt_result sy_rt_coverage_hits(sy_rt_device *dev, const sy_rt_camera *camera, const sy_rt_render_desc *desc,
                                  sy_rt_coverage_hit *hits)
{
    return coverage_run(dev, camera, desc, "coverage hits", coverage_hits_tile, hits, NULL);
}

sy_rt_result sy_rt_coverage(sy_rt_device *dev, const sy_rt_camera *camera, const sy_rt_render_desc *desc,
                            uint32_t *ids, float *depth)
{
    return coverage_run(dev, camera, desc, "coverage", sy_rt_coverage_tile, ids, depth);
}

sy_rt_result sy_rt_pick(sy_rt_device *dev, const sy_rt_camera *camera, uint32_t image_width, uint32_t image_height,
                        uint32_t x, uint32_t y, sy_rt_pick_hit *out)
{
    if (dev && camera) sy_rt_clip_begin(dev, camera);
    if (!dev || !camera || !out) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "pick: NULL argument");
    memset(out, 0, sizeof *out);
    if (x >= image_width || y >= image_height)
        return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "pick: pixel (%u, %u) is outside the %ux%u image", x, y, image_width,
                    image_height);
    if (dev->dirty)
        return FAIL(SY_RT_ERROR_INVALID_OPERATION, "pick: the device has uncommitted changes; call sy_rt_commit first");
    sy_rt_render_desc d = {.integrator = SY_RT_INTEGRATOR_COVERAGE, .image_width = image_width,
                           .image_height = image_height, .x = x, .y = y, .width = 1, .height = 1};
    sy_rt_frame f;
    sy_rt_result r = sy_rt_frame_init(&f, dev, camera, &d, NULL, NULL);
    if (r != SY_RT_OK) return r;
    sy_rt_ictx ctx;
    sy_rt_context_init(dev, &ctx, RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT);
    struct RTCRayHit rh;
    float axial;
    sy_rt_frame_hit(&f, &ctx.rtc, x, y, &rh, &axial);
    const sy_rt_instance_data *in =
        rh.hit.geomID == RTC_INVALID_GEOMETRY_ID ? NULL : sy_rt_hit_instance(dev, rh.hit.geomID, rh.hit.instID[0]);
    if (!in || rh.hit.primID >= in->mesh->triangle_count) return SY_RT_OK;
    out->instance.id = in->handle;
    out->triangle = rh.hit.primID;
    out->u = rh.hit.u;
    out->v = rh.hit.v;
    out->depth = rh.ray.tfar * axial;
    const uint32_t *ix = in->mesh->indices + 3u * rh.hit.primID;
    for (int k = 0; k < 3; ++k) memcpy(out->vertices[k], in->mesh->positions + 3u * ix[k], 3 * sizeof(float));
    memcpy(out->transform, in->xf, sizeof out->transform);
    return SY_RT_OK;
}
