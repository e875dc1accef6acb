/* sy_rt_mesh.c — meshes of the ray-tracing back-end: sy_rt_mesh_create / update / destroy (checked,
 * copied or shared vertex data in an Embree triangle geometry) and each mesh's BLAS, built on first
 * use by an Embree instance or a moved instance's twin (sy_rt_mesh_blas); a deforming mesh's two
 * poses over a shutter (sy_rt_mesh_update_motion, sy_rt_mesh_motion_off). Calls only sy_rt_base. */
#include "sy_rt_scene.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define FAIL(r, ...) sy_rt_fail(dev, (r), __VA_ARGS__)

/* Bytes this process could still allocate without swapping (MemAvailable of /proc/meminfo, else
 * the free physical pages); -1 when unknown. */
static double sy_rt_memory_available(void)
{
    FILE *f = fopen("/proc/meminfo", "r");
    char line[128];
    double kib = -1;
    while (f && fgets(line, sizeof line, f)) {
        unsigned long long v;
        if (sscanf(line, "MemAvailable: %llu kB", &v) == 1) {
            kib = (double)v;
            break;
        }
    }
    if (f) fclose(f);
    if (kib >= 0) return kib * 1024.0;
#ifdef _SC_AVPHYS_PAGES
    long pages = sysconf(_SC_AVPHYS_PAGES), size = sysconf(_SC_PAGESIZE);
    if (pages > 0 && size > 0) return (double)pages * (double)size;
#endif
    return -1.0;
}

static void mesh_free(sy_rt_device *dev, sy_rt_mesh_data *m)
{
    if (!m) return;
    if (m->geom) rtcReleaseGeometry(m->geom);
    if (m->scene) rtcReleaseScene(m->scene);
    free(m->updated_normals);
    free(m->normals1);
    for (uint32_t k = 0; k < SY_RT_MOTION_STEPS_MAX; ++k) free(m->nrm_mid[k]);
    if (m->motion) dev->motion_count--;
    if (m->shared) {
        if (m->release) m->release(m->release_user);
    } else {
        free((void *)m->normals);
        free((void *)m->uv[0]);
        free((void *)m->uv[1]);
        free((void *)m->colors);
    }
    dev->mesh_bytes -= m->own_bytes;
    dev->shared_bytes -= m->shared_bytes;
    free(m);
}

void sy_rt_mesh_unref(sy_rt_device *dev, sy_rt_mesh_data *m)
{
    if (m && --m->refs == 0) mesh_free(dev, m);
}

/* Checks n floats for non-finite values, then copies them (m->own_bytes) or, for a shared mesh,
 * points at them (m->shared_bytes). */
static sy_rt_result take_finite(const sy_rt_device *dev, sy_rt_mesh_data *m, const float *src, size_t n, const float **dst, const char *what)
{
    for (size_t i = 0; i < n; ++i)
        if (!isfinite(src[i]))
            return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "mesh: %s[%zu] = %g is not finite", what, i, (double)src[i]);
    size_t bytes;
    if (!sy_rt_size_mul(n, sizeof(float), &bytes)) return FAIL(SY_RT_ERROR_LIMIT, "mesh: %s too large", what);
    if (m->shared) {
        *dst = src;
        m->shared_bytes += bytes;
        return SY_RT_OK;
    }
    float *copy = malloc(bytes ? bytes : 1);
    if (!copy) return FAIL(SY_RT_ERROR_OUT_OF_MEMORY, "mesh: cannot allocate %s (%zu bytes)", what, bytes);
    memcpy(copy, src, bytes);
    *dst = copy;
    m->own_bytes += bytes;
    return SY_RT_OK;
}

/* All structural checks of a mesh desc, before anything is allocated. */
static sy_rt_result validate_mesh_desc(const sy_rt_device *dev, const sy_rt_mesh_desc *d)
{
    if (!d->positions) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "mesh: positions is NULL");
    if (d->vertex_count == 0 || d->triangle_count == 0)
        return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "mesh: empty (vertex_count %u, triangle_count %u)",
                    d->vertex_count, d->triangle_count);
    if (d->triangle_count > UINT32_MAX / 3u)
        return FAIL(SY_RT_ERROR_LIMIT, "mesh: triangle_count %u exceeds %u", d->triangle_count, UINT32_MAX / 3u);
    size_t corners = (size_t)d->triangle_count * 3u;
    if (!d->indices && d->vertex_count != corners)
        return FAIL(SY_RT_ERROR_INVALID_ARGUMENT,
                    "mesh: non-indexed mesh needs vertex_count == 3 * triangle_count (%u != %zu)",
                    d->vertex_count, corners);
    if (d->indices)
        for (size_t i = 0; i < corners; ++i)
            if (d->indices[i] >= d->vertex_count)
                return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "mesh: indices[%zu] = %u is not < vertex_count %u",
                            i, d->indices[i], d->vertex_count);
    size_t n3 = (size_t)d->vertex_count * 3u;
    for (size_t i = 0; i < n3; ++i)
        if (!(fabsf(d->positions[i]) <= SY_RT_COORD_MAX))
            return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "mesh: positions[%zu] (vertex %zu) = %g is %s",
                        i, i / 3u, (double)d->positions[i],
                        isfinite(d->positions[i]) ? "beyond SY_RT_COORD_MAX (1e13)" : "not finite");
    return SY_RT_OK;
}

sy_rt_result sy_rt_mesh_create(sy_rt_device *dev, const sy_rt_mesh_desc *d, sy_rt_mesh *out)
{
    if (!dev || !d || !out) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "mesh: NULL argument");
    out->id = 0;
    sy_rt_result r = validate_mesh_desc(dev, d);
    if (r != SY_RT_OK) return r;

    sy_rt_mesh_data *m = calloc(1, sizeof *m);
    if (!m) return FAIL(SY_RT_ERROR_OUT_OF_MEMORY, "mesh: out of memory");
    m->refs = 1;
    m->shared = d->release != NULL;
    m->vertex_count = d->vertex_count;
    for (size_t i = 0; i < (size_t)d->vertex_count * 3u; ++i) m->extent = fmaxf(m->extent, fabsf(d->positions[i]));
    m->triangle_count = d->triangle_count;
    m->closed = d->closed > 0 ? 1 : d->closed < 0 ? -1 : 0;
    size_t vc = d->vertex_count, corners = (size_t)d->triangle_count * 3u;
    if (d->normals && (r = take_finite(dev, m, d->normals, vc * 3u, &m->normals, "normals")) != SY_RT_OK) goto fail;
    if (d->uv[0] && (r = take_finite(dev, m, d->uv[0], vc * 2u, &m->uv[0], "uv[0]")) != SY_RT_OK) goto fail;
    if (d->uv[1] && (r = take_finite(dev, m, d->uv[1], vc * 2u, &m->uv[1], "uv[1]")) != SY_RT_OK) goto fail;
    if (d->colors && (r = take_finite(dev, m, d->colors, vc * 4u, &m->colors, "colors")) != SY_RT_OK) goto fail;

    m->geom = rtcNewGeometry(dev->rtc, RTC_GEOMETRY_TYPE_TRIANGLE);
    if (!m->geom) { r = sy_rt_check_embree(dev, "mesh: rtcNewGeometry"); goto fail; }
    const float *pos = NULL;
    const uint32_t *idx = NULL;
    if (m->shared) {
        /* Embree reads the caller's arrays in place (the caller guarantees the padding). */
        rtcSetSharedGeometryBuffer(m->geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, d->positions, 0,
                                   3 * sizeof(float), d->vertex_count);
        pos = d->positions;
        m->shared_bytes += vc * 3u * sizeof(float);
        if (d->indices) {
            rtcSetSharedGeometryBuffer(m->geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, d->indices, 0,
                                       3 * sizeof(uint32_t), d->triangle_count);
            idx = d->indices;
            m->shared_bytes += corners * sizeof(uint32_t);
        }
    } else {
        /* rtcSetNewGeometryBuffer pads vertex buffers as Embree's SIMD loads require. */
        float *p = rtcSetNewGeometryBuffer(m->geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                           d->vertex_count);
        if (p) memcpy(p, d->positions, vc * 3u * sizeof(float));
        pos = p;
    }
    if (!idx) {
        uint32_t *ix = rtcSetNewGeometryBuffer(m->geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                               3 * sizeof(uint32_t), d->triangle_count);
        if (ix) {
            if (d->indices) memcpy(ix, d->indices, corners * sizeof(uint32_t));
            else for (size_t i = 0; i < corners; ++i) ix[i] = (uint32_t)i;
        }
        idx = ix;
    }
    if (!pos || !idx) {
        r = sy_rt_check_embree(dev, "mesh: allocating Embree buffers");
        if (r == SY_RT_OK) r = FAIL(SY_RT_ERROR_OUT_OF_MEMORY, "mesh: allocating Embree buffers failed");
        goto fail;
    }
    m->positions = pos;
    m->own_positions = !m->shared;
    m->indices = idx;
    rtcSetGeometryUserData(m->geom, dev);
    rtcCommitGeometry(m->geom);
    if ((r = sy_rt_check_embree(dev, "mesh: creating geometry")) != SY_RT_OK) goto fail;
    if (!sy_rt_pool_insert(&dev->meshes, m, &out->id)) { r = FAIL(SY_RT_ERROR_LIMIT, "mesh: pool full or out of memory"); goto fail; }
    m->release = d->release;
    m->release_user = d->release_user;
    dev->mesh_bytes += m->own_bytes;
    dev->shared_bytes += m->shared_bytes;
    dev->dirty = true;
    return SY_RT_OK;
fail:
    m->own_bytes = m->shared_bytes = 0; /* not yet counted in dev */
    mesh_free(dev, m); /* m->release is still NULL: the caller keeps its arrays */
    return r;
}

sy_rt_result sy_rt_mesh_update(sy_rt_device *dev, sy_rt_mesh mesh, const float *positions, const float *normals)
{
    if (!dev || !positions) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "mesh update: NULL argument");
    sy_rt_mesh_data *m = sy_rt_pool_get(&dev->meshes, mesh.id);
    if (!m) return FAIL(SY_RT_ERROR_INVALID_HANDLE, "mesh update: mesh handle 0x%08x is stale", mesh.id);
    if (!normals != !m->normals)
        return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "mesh update: normals %s, the mesh was made %s them",
                    normals ? "given" : "missing", m->normals ? "with" : "without");
    size_t vc = m->vertex_count;
    float extent = 0.0f;
    for (size_t i = 0; i < vc * 3u; ++i) {
        if (!isfinite(positions[i]) || (normals && !isfinite(normals[i])))
            return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "mesh update: %s[%zu] is not finite", isfinite(positions[i]) ? "normals" : "positions", i);
        extent = fmaxf(extent, fabsf(positions[i]));
    }
    if (!(extent <= SY_RT_COORD_MAX))
        return FAIL(SY_RT_ERROR_LIMIT, "mesh update: a position of %g is beyond SY_RT_COORD_MAX (1e13)", (double)extent);
    if (!m->own_positions) { /* a shared mesh's first update: a vertex buffer of its own, padded by Embree */
        float *p = rtcSetNewGeometryBuffer(m->geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), m->vertex_count);
        if (!p) {
            sy_rt_result r = sy_rt_check_embree(dev, "mesh update: vertex buffer");
            return r != SY_RT_OK ? r : FAIL(SY_RT_ERROR_OUT_OF_MEMORY, "mesh update: vertex buffer: out of memory");
        }
        m->positions = p;
        m->own_positions = true;
        m->own_bytes += vc * 3u * sizeof(float);
        dev->mesh_bytes += vc * 3u * sizeof(float);
    }
    if (normals && m->shared && !m->updated_normals) {
        if (!(m->updated_normals = malloc(vc * 3u * sizeof(float) + 1)))
            return FAIL(SY_RT_ERROR_OUT_OF_MEMORY, "mesh update: normals: out of memory");
        m->normals = m->updated_normals;
        m->own_bytes += vc * 3u * sizeof(float);
        dev->mesh_bytes += vc * 3u * sizeof(float);
    }
    memcpy((float *)m->positions, positions, vc * 3u * sizeof(float));
    if (normals) memcpy((float *)m->normals, normals, vc * 3u * sizeof(float));
    m->extent = extent;
    rtcUpdateGeometryBuffer(m->geom, RTC_BUFFER_TYPE_VERTEX, 0);
    rtcSetGeometryBuildQuality(m->geom, RTC_BUILD_QUALITY_REFIT);
    rtcCommitGeometry(m->geom);
    if (m->scene) {
        /* Embree honours a geometry's REFIT only in a dynamic scene of quality LOW (its two-level
         * structure gives each geometry a BVH of its own; without RTC_SCENE_FLAG_DYNAMIC it
         * rebuilt every time, 130-200 ms for 2 x 10^5 triangles against 13-24 ms refitted): the
         * first update switches the BLAS to it (one rebuild), every later one refits */
        if (!m->refitting) {
            rtcSetSceneFlags(m->scene, rtcGetSceneFlags(m->scene) | RTC_SCENE_FLAG_DYNAMIC);
            rtcSetSceneBuildQuality(m->scene, RTC_BUILD_QUALITY_LOW);
        }
        rtcCommitScene(m->scene);
    }
    m->refitting = true;
    /* the top level (instance bounds), shadows and area lights follow at the next commit */
    dev->dirty = dev->top_dirty = dev->shadow_dirty = dev->area_dirty = true;
    return sy_rt_check_embree(dev, "mesh update");
}

sy_rt_result sy_rt_mesh_get_view(const sy_rt_device *dev, sy_rt_mesh mesh, sy_rt_mesh_view *out)
{
    if (!dev || !out) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "mesh get_view: NULL argument");
    memset(out, 0, sizeof *out);
    const sy_rt_mesh_data *m = sy_rt_pool_get(&dev->meshes, mesh.id);
    if (!m) return FAIL(SY_RT_ERROR_INVALID_HANDLE, "mesh get_view: mesh handle 0x%08x is stale", mesh.id);
    *out = (sy_rt_mesh_view){m->positions, m->indices, m->vertex_count, m->triangle_count};
    return SY_RT_OK;
}

/* The mesh's BLAS, built on first use by an Embree instance (a mesh used only by baked instances
 * never needs one). Large meshes build with a compact layout and medium quality: a high-quality
 * build (spatial splits) of 10^7 triangles needs several times the memory of the finished BVH. */
sy_rt_result sy_rt_mesh_blas(sy_rt_device *dev, sy_rt_mesh_data *m)
{
    if (m->scene) return SY_RT_OK;
    bool large = m->triangle_count >= SY_RT_LARGE_MESH_TRIANGLES;
    /* Too big for the machine (or the device's limit): refused with the sizes, before Embree
     * allocates anything (an out-of-memory kill would come without a word). Peak bytes per
     * triangle of a build, measured (sy bench memory): about 56 compact / medium, 120 high. */
    double need = (double)m->triangle_count * (large ? 64.0 : 128.0);
    double avail = sy_rt_memory_available();
    const char *what = "available memory";
    if (dev->max_memory > 0) {
        double left = (double)(dev->max_memory - atomic_load(&dev->embree_bytes));
        if (avail < 0 || left < avail) avail = left < 0 ? 0 : left, what = "left under the device's memory limit";
    }
    if (avail >= 0 && need > avail)
        return FAIL(SY_RT_ERROR_OUT_OF_MEMORY, "mesh: the BVH of %u triangles needs about %.1f MB; %.1f MB %s",
                    m->triangle_count, need / 1048576.0, avail / 1048576.0, what);
    m->scene = rtcNewScene(dev->rtc);
    if (m->scene) {
        /* the context flag: moved instances' stale copies are filtered (sy_rt_device.h) */
        rtcSetSceneFlags(m->scene, RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION | (large ? RTC_SCENE_FLAG_COMPACT : 0) |
                                       (m->refitting ? RTC_SCENE_FLAG_DYNAMIC : 0));
        rtcSetSceneBuildQuality(m->scene, m->refitting ? RTC_BUILD_QUALITY_LOW : large ? RTC_BUILD_QUALITY_MEDIUM : RTC_BUILD_QUALITY_HIGH);
        rtcAttachGeometryByID(m->scene, m->geom, 0);
        rtcCommitScene(m->scene);
    }
    sy_rt_result r = sy_rt_check_embree(dev, "mesh: building BLAS");
    if (r == SY_RT_OK && !m->scene) r = FAIL(SY_RT_ERROR_EMBREE, "mesh: rtcNewScene failed");
    if (r != SY_RT_OK && dev->max_memory > 0 &&
        (double)atomic_load(&dev->embree_peak) + need > (double)dev->max_memory) /* the monitor refused it */
        r = FAIL(SY_RT_ERROR_OUT_OF_MEMORY, "mesh: building the BVH of %u triangles went past the device's memory limit "
                 "of %.1f MB (Embree held %.1f MB at its peak)", m->triangle_count, (double)dev->max_memory / 1048576.0,
                 (double)atomic_load(&dev->embree_peak) / 1048576.0);
    if (r != SY_RT_OK && m->scene) {
        rtcReleaseScene(m->scene);
        m->scene = NULL;
    }
    return r;
}

sy_rt_result sy_rt_mesh_destroy(sy_rt_device *dev, sy_rt_mesh mesh)
{
    if (!dev) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "mesh destroy: NULL device");
    sy_rt_mesh_data *m = sy_rt_pool_take(dev, &dev->meshes, mesh.id, "mesh destroy");
    if (!m) return SY_RT_ERROR_INVALID_HANDLE;
    sy_rt_mesh_unref(dev, m); /* instances keep it alive until they go */
    dev->dirty = true;
    return SY_RT_OK;
}

/* >>mesh motion: a deforming mesh's two poses over the shutter (time steps 0 and 1) */
void sy_rt_mesh_motion_off(sy_rt_device *dev, sy_rt_mesh_data *m)
{
    if (!m->motion) return;
    rtcSetGeometryTimeStepCount(m->geom, 1);
    rtcCommitGeometry(m->geom);
    if (m->scene) rtcCommitScene(m->scene);
    size_t bytes = (size_t)m->vertex_count * 3u * sizeof(float) * (m->normals1 ? 2u : 1u) * (m->motion_steps - 1u);
    m->own_bytes -= bytes;
    dev->mesh_bytes -= bytes;
    free(m->normals1);
    m->normals1 = NULL;
    m->positions1 = NULL;
    for (uint32_t k = 0; k < SY_RT_MOTION_STEPS_MAX; ++k) free(m->nrm_mid[k]), m->nrm_mid[k] = NULL, m->pos_mid[k] = NULL;
    m->motion_steps = 0;
    m->motion = false;
    dev->motion_count--;
    dev->dirty = dev->top_dirty = dev->shadow_dirty = dev->area_dirty = true;
}

sy_rt_result sy_rt_mesh_update_steps(sy_rt_device *dev, sy_rt_mesh mesh, uint32_t steps, uint32_t k, const float *positions,
                                     const float *normals)
{
    if (!dev || !positions) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "mesh update_steps: NULL argument");
    sy_rt_mesh_data *m = sy_rt_pool_get(&dev->meshes, mesh.id);
    if (!m) return FAIL(SY_RT_ERROR_INVALID_HANDLE, "mesh update_steps: mesh handle 0x%08x is stale", mesh.id);
    if (steps < 3u || steps > SY_RT_MOTION_STEPS_MAX || k + 2u > steps)
        return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "mesh update_steps: step %u of %u (3 .. %u steps, step < steps - 1)", k, steps,
                    SY_RT_MOTION_STEPS_MAX);
    size_t vc = m->vertex_count, n3 = vc * 3u * sizeof(float);
    if (m->motion && m->motion_steps != steps) sy_rt_mesh_motion_off(dev, m); /* another shutter: start over */
    if (!m->motion) { /* its first deformation since the close: the pose it has is every later step's */
        float *buf[SY_RT_MOTION_STEPS_MAX] = {0}, *nrm[SY_RT_MOTION_STEPS_MAX] = {0};
        bool ok = true;
        for (uint32_t s = 1; s < steps && ok; ++s) ok = !m->normals || (nrm[s] = malloc(n3 + 1)) != NULL;
        if (ok) rtcSetGeometryTimeStepCount(m->geom, steps);
        for (uint32_t s = 1; s < steps && ok; ++s)
            ok = (buf[s] = rtcSetNewGeometryBuffer(m->geom, RTC_BUFFER_TYPE_VERTEX, s, RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                                   m->vertex_count)) != NULL;
        if (!ok) {
            rtcSetGeometryTimeStepCount(m->geom, 1);
            for (uint32_t s = 1; s < steps; ++s) free(nrm[s]);
            sy_rt_result r = sy_rt_check_embree(dev, "mesh update_steps: vertex buffers");
            return r != SY_RT_OK ? r : FAIL(SY_RT_ERROR_OUT_OF_MEMORY, "mesh update_steps: out of memory for %u steps", steps);
        }
        for (uint32_t s = 1; s < steps; ++s) {
            memcpy(buf[s], m->positions, n3);
            if (nrm[s]) memcpy(nrm[s], m->normals, n3);
            rtcUpdateGeometryBuffer(m->geom, RTC_BUFFER_TYPE_VERTEX, s);
            if (s + 1u < steps) m->pos_mid[s] = buf[s], m->nrm_mid[s] = nrm[s];
        }
        m->positions1 = buf[steps - 1u];
        m->normals1 = nrm[steps - 1u];
        m->motion = true;
        m->motion_steps = steps;
        dev->motion_count++;
        size_t bytes = n3 * (m->normals ? 2u : 1u) * (steps - 1u);
        m->own_bytes += bytes;
        dev->mesh_bytes += bytes;
    }
    sy_rt_result r = sy_rt_mesh_update(dev, mesh, positions, normals); /* time 0; checks the arguments */
    if (r != SY_RT_OK) return r;
    for (uint32_t s = 1; s <= k; ++s) { /* steps 1 .. k: this pose until an earlier step moves it on */
        memcpy((float *)m->pos_mid[s], positions, n3);
        if (m->nrm_mid[s] && normals) memcpy(m->nrm_mid[s], normals, n3);
        rtcUpdateGeometryBuffer(m->geom, RTC_BUFFER_TYPE_VERTEX, s);
    }
    float extent = m->extent;
    for (uint32_t s = 1; s < steps; ++s) {
        const float *p = s + 1u < steps ? m->pos_mid[s] : m->positions1;
        for (size_t i = 0; i < vc * 3u; ++i) extent = fmaxf(extent, fabsf(p[i]));
    }
    m->extent = extent;
    rtcCommitGeometry(m->geom);
    if (m->scene) rtcCommitScene(m->scene);
    dev->dirty = dev->top_dirty = dev->shadow_dirty = dev->area_dirty = true;
    return sy_rt_check_embree(dev, "mesh update_steps");
}

sy_rt_result sy_rt_mesh_update_motion(sy_rt_device *dev, sy_rt_mesh mesh, const float *positions, const float *normals)
{
    if (!dev || !positions) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "mesh update_motion: NULL argument");
    sy_rt_mesh_data *m = sy_rt_pool_get(&dev->meshes, mesh.id);
    if (!m) return FAIL(SY_RT_ERROR_INVALID_HANDLE, "mesh update_motion: mesh handle 0x%08x is stale", mesh.id);
    if (m->motion && m->motion_steps > 2u) sy_rt_mesh_motion_off(dev, m); /* from curved motion: two steps anew */
    size_t vc = m->vertex_count;
    /* the pose it has now, kept for time 1 (before the update overwrites it) */
    float *close = malloc(vc * 3u * sizeof(float) + 1), *close_n = m->normals ? malloc(vc * 3u * sizeof(float) + 1) : NULL;
    if (!close || (m->normals && !close_n)) {
        free(close), free(close_n);
        return FAIL(SY_RT_ERROR_OUT_OF_MEMORY, "mesh update_motion: out of memory");
    }
    memcpy(close, m->positions, vc * 3u * sizeof(float));
    if (close_n) memcpy(close_n, m->normals, vc * 3u * sizeof(float));
    sy_rt_result r = sy_rt_mesh_update(dev, mesh, positions, normals); /* time 0; checks the arguments */
    if (r != SY_RT_OK) {
        free(close), free(close_n);
        return r;
    }
    if (!m->motion) {
        rtcSetGeometryTimeStepCount(m->geom, 2);
        float *p1 = rtcSetNewGeometryBuffer(m->geom, RTC_BUFFER_TYPE_VERTEX, 1, RTC_FORMAT_FLOAT3, 3 * sizeof(float), m->vertex_count);
        if (!p1) {
            rtcSetGeometryTimeStepCount(m->geom, 1);
            free(close), free(close_n);
            r = sy_rt_check_embree(dev, "mesh update_motion: vertex buffer");
            return r != SY_RT_OK ? r : FAIL(SY_RT_ERROR_OUT_OF_MEMORY, "mesh update_motion: vertex buffer: out of memory");
        }
        m->positions1 = p1;
        m->motion = true;
        m->motion_steps = 2;
        dev->motion_count++;
        size_t bytes = vc * 3u * sizeof(float) * (close_n ? 2u : 1u);
        m->own_bytes += bytes;
        dev->mesh_bytes += bytes;
    } else {
        free(m->normals1);
    }
    memcpy((float *)m->positions1, close, vc * 3u * sizeof(float));
    free(close);
    m->normals1 = close_n;
    float extent = m->extent;
    for (size_t i = 0; i < vc * 3u; ++i) extent = fmaxf(extent, fabsf(m->positions1[i]));
    m->extent = extent;
    rtcUpdateGeometryBuffer(m->geom, RTC_BUFFER_TYPE_VERTEX, 1);
    rtcCommitGeometry(m->geom);
    if (m->scene) rtcCommitScene(m->scene);
    dev->dirty = dev->top_dirty = dev->shadow_dirty = dev->area_dirty = true;
    return sy_rt_check_embree(dev, "mesh update_motion");
}
