/* sy_rt_scene.c — meshes (one Embree BLAS each), instances (Embree instances or baked world-space
 * geometry in the top-level scene), materials, punctual lights, and sy_rt_commit, which publishes
 * staged changes: alpha filters, top-level BVH, area-light list and punctual-light array. */
#include "sy_rt_scene.h"
#include "sy_rt_lights.h"
#include "sy_rt_shadow.h"
#include "sy_rt_surface.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#define FAIL(r, ...) sy_rt_fail(dev, (r), __VA_ARGS__)

/* Stores a new object (from malloc) in pool, *id its handle; when the pool is full or out of
 * memory, frees it and reports "WHAT: pool full or out of memory". */
static sy_rt_result pool_add(sy_rt_device *dev, sy_rt_pool *pool, void *item, uint32_t *id, const char *what)
{
    if (sy_rt_pool_insert(pool, item, id)) return SY_RT_OK;
    free(item);
    return FAIL(SY_RT_ERROR_LIMIT, "%s: pool full or out of memory", what);
}

/* >>mesh */

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

static void mesh_unref(sy_rt_device *dev, sy_rt_mesh_data *m)
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

/* The mesh's BLAS, built on first use by an Embree instance (a mesh used only by baked instances
 * never needs one). Large meshes build with a compact layout and medium quality: a high-quality
 * build (spatial splits) of 10^7 triangles needs several times the memory of the finished BVH. */
static sy_rt_result mesh_blas(sy_rt_device *dev, sy_rt_mesh_data *m)
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
    mesh_unref(dev, m); /* instances keep it alive until they go */
    dev->dirty = true;
    return SY_RT_OK;
}

/* >>material */

void sy_rt_material_desc_init(sy_rt_material_desc *d)
{
    memset(d, 0, sizeof *d);
    d->base_color[0] = d->base_color[1] = d->base_color[2] = d->base_color[3] = 1.0f;
    d->metallic = 1.0f;
    d->roughness = 1.0f;
    d->normal_scale = 1.0f;
    d->specular = 1.0f;
    d->ior = 1.5f;
    d->alpha_mode = SY_RT_ALPHA_OPAQUE;
    d->alpha_cutoff = 0.5f;
    for (int k = 0; k < 3; ++k) d->specular_color[k] = d->attenuation_color[k] = 1.0f;
    d->iridescence_ior = 1.3f;
    d->clearcoat_normal_scale = 1.0f;
    d->iridescence_thickness[0] = 100.0f;
    d->iridescence_thickness[1] = 400.0f;
}

static sy_rt_result validate_texref(const sy_rt_device *dev, sy_rt_texture_ref t, const char *name)
{
    if (t.texture.id != 0 && !sy_rt_pool_get(&dev->textures, t.texture.id))
        return FAIL(SY_RT_ERROR_INVALID_HANDLE, "material: %s handle 0x%08x is stale", name, t.texture.id);
    if (t.texcoord > 1) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "material: %s.texcoord = %u, expected 0 or 1", name, t.texcoord);
    if (t.transformed)
        for (int k = 0; k < 6; ++k)
            if (!isfinite(t.transform[k]))
                return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "material: %s.transform[%d] is not finite", name, k);
    return SY_RT_OK;
}

static sy_rt_result validate_material(const sy_rt_device *dev, const sy_rt_material_desc *d)
{
    const struct { const char *name; float v, lo, hi; } ranges[] = {
        {"base_color[0]", d->base_color[0], 0.0f, INFINITY}, {"base_color[1]", d->base_color[1], 0.0f, INFINITY},
        {"base_color[2]", d->base_color[2], 0.0f, INFINITY}, {"base_color[3]", d->base_color[3], 0.0f, 1.0f},
        {"metallic", d->metallic, 0.0f, 1.0f}, {"roughness", d->roughness, 0.0f, 1.0f},
        {"emissive[0]", d->emissive[0], 0.0f, INFINITY}, {"emissive[1]", d->emissive[1], 0.0f, INFINITY},
        {"emissive[2]", d->emissive[2], 0.0f, INFINITY}, {"normal_scale", d->normal_scale, -INFINITY, INFINITY},
        {"specular", d->specular, 0.0f, 1.0f}, {"transmission", d->transmission, 0.0f, 1.0f},
        {"ior", d->ior, 1.0f, INFINITY}, {"alpha_cutoff", d->alpha_cutoff, 0.0f, 1.0f},
        {"specular_color[0]", d->specular_color[0], 0.0f, INFINITY}, {"specular_color[1]", d->specular_color[1], 0.0f, INFINITY},
        {"specular_color[2]", d->specular_color[2], 0.0f, INFINITY}, {"thickness", d->thickness, 0.0f, INFINITY},
        {"attenuation_distance", d->attenuation_distance, 0.0f, INFINITY},
        {"attenuation_color[0]", d->attenuation_color[0], 0.0f, 1.0f}, {"attenuation_color[1]", d->attenuation_color[1], 0.0f, 1.0f},
        {"attenuation_color[2]", d->attenuation_color[2], 0.0f, 1.0f}, {"clearcoat", d->clearcoat, 0.0f, 1.0f},
        {"clearcoat_roughness", d->clearcoat_roughness, 0.0f, 1.0f},
        {"sheen_color[0]", d->sheen_color[0], 0.0f, 1.0f}, {"sheen_color[1]", d->sheen_color[1], 0.0f, 1.0f},
        {"sheen_color[2]", d->sheen_color[2], 0.0f, 1.0f}, {"sheen_roughness", d->sheen_roughness, 0.0f, 1.0f},
        {"iridescence", d->iridescence, 0.0f, 1.0f}, {"iridescence_ior", d->iridescence_ior, 1.0f, INFINITY},
        {"iridescence_thickness[0]", d->iridescence_thickness[0], 0.0f, INFINITY},
        {"iridescence_thickness[1]", d->iridescence_thickness[1], 0.0f, INFINITY},
        {"clearcoat_normal_scale", d->clearcoat_normal_scale, -INFINITY, INFINITY}, {"anisotropy", d->anisotropy, 0.0f, 1.0f}, {"anisotropy_rotation", d->anisotropy_rotation, -1.0e6f, 1.0e6f},
    };
    for (size_t i = 0; i < sizeof ranges / sizeof ranges[0]; ++i)
        if (!isfinite(ranges[i].v) || ranges[i].v < ranges[i].lo || ranges[i].v > ranges[i].hi)
            return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "material: %s = %g is outside [%g, %g]", ranges[i].name,
                        (double)ranges[i].v, (double)ranges[i].lo, (double)ranges[i].hi);
    if ((unsigned)d->alpha_mode > SY_RT_ALPHA_BLEND)
        return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "material: unknown alpha_mode %d", (int)d->alpha_mode);
    sy_rt_result r;
    if ((r = validate_texref(dev, d->base_color_texture, "base_color_texture")) != SY_RT_OK) return r;
    if ((r = validate_texref(dev, d->metallic_roughness_texture, "metallic_roughness_texture")) != SY_RT_OK) return r;
    if ((r = validate_texref(dev, d->emissive_texture, "emissive_texture")) != SY_RT_OK) return r;
    if ((r = validate_texref(dev, d->transmission_texture, "transmission_texture")) != SY_RT_OK) return r;
    if ((r = validate_texref(dev, d->specular_texture, "specular_texture")) != SY_RT_OK) return r;
    if ((r = validate_texref(dev, d->specular_color_texture, "specular_color_texture")) != SY_RT_OK) return r;
    if ((r = validate_texref(dev, d->clearcoat_texture, "clearcoat_texture")) != SY_RT_OK) return r;
    if ((r = validate_texref(dev, d->clearcoat_roughness_texture, "clearcoat_roughness_texture")) != SY_RT_OK) return r;
    if ((r = validate_texref(dev, d->sheen_color_texture, "sheen_color_texture")) != SY_RT_OK) return r;
    if ((r = validate_texref(dev, d->sheen_roughness_texture, "sheen_roughness_texture")) != SY_RT_OK) return r;
    if ((r = validate_texref(dev, d->iridescence_texture, "iridescence_texture")) != SY_RT_OK) return r;
    if ((r = validate_texref(dev, d->iridescence_thickness_texture, "iridescence_thickness_texture")) != SY_RT_OK) return r;
    if ((r = validate_texref(dev, d->anisotropy_texture, "anisotropy_texture")) != SY_RT_OK) return r;
    if ((r = validate_texref(dev, d->clearcoat_normal_texture, "clearcoat_normal_texture")) != SY_RT_OK) return r;
    return validate_texref(dev, d->normal_texture, "normal_texture");
}

static void material_set(sy_rt_material_data *m, const sy_rt_material_desc *d)
{
    m->desc = *d;
    m->emissive = d->emissive[0] > 0.0f || d->emissive[1] > 0.0f || d->emissive[2] > 0.0f;
    m->masked = d->alpha_mode == SY_RT_ALPHA_MASK;
    m->textured = d->base_color_texture.texture.id || d->normal_texture.texture.id ||
                  d->metallic_roughness_texture.texture.id || d->emissive_texture.texture.id ||
                  d->transmission_texture.texture.id || d->specular_texture.texture.id ||
                  d->specular_color_texture.texture.id || d->clearcoat_texture.texture.id ||
                  d->clearcoat_roughness_texture.texture.id || d->sheen_color_texture.texture.id ||
                  d->sheen_roughness_texture.texture.id || d->iridescence_texture.texture.id ||
                  d->iridescence_thickness_texture.texture.id || d->anisotropy_texture.texture.id ||
                  d->clearcoat_normal_texture.texture.id;
    /* KHR_materials_volume: Beer-Lambert absorption inside a closed volume (thickness > 0) */
    m->volume = d->thickness > 0.0f && d->attenuation_distance > 0.0f && isfinite(d->attenuation_distance);
    for (int k = 0; k < 3; ++k)
        m->sigma[k] = m->volume ? -logf(sy_rt_maxf(d->attenuation_color[k], 1e-6f)) / d->attenuation_distance : 0.0f;
    m->volume = m->volume && (m->sigma[0] > 0.0f || m->sigma[1] > 0.0f || m->sigma[2] > 0.0f);
}

sy_rt_result sy_rt_material_create(sy_rt_device *dev, const sy_rt_material_desc *d, sy_rt_material *out)
{
    if (!dev || !d || !out) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "material: NULL argument");
    out->id = 0;
    sy_rt_result r = validate_material(dev, d);
    if (r != SY_RT_OK) return r;
    sy_rt_material_data *m = calloc(1, sizeof *m);
    if (!m) return FAIL(SY_RT_ERROR_OUT_OF_MEMORY, "material: out of memory");
    material_set(m, d);
    if ((r = pool_add(dev, &dev->materials, m, &out->id, "material")) != SY_RT_OK) return r;
    dev->dirty = dev->shadow_dirty = true;
    return SY_RT_OK;
}

sy_rt_result sy_rt_material_update(sy_rt_device *dev, sy_rt_material mat, const sy_rt_material_desc *d)
{
    if (!dev || !d) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "material update: NULL argument");
    sy_rt_material_data *m = sy_rt_pool_find(dev, &dev->materials, mat.id, "material update");
    if (!m) return SY_RT_ERROR_INVALID_HANDLE;
    sy_rt_result r = validate_material(dev, d);
    if (r != SY_RT_OK) return r;
    bool was_emissive = m->emissive, was_masked = m->masked;
    bool emission_changed = memcmp(m->desc.emissive, d->emissive, sizeof d->emissive) != 0 ||
                            m->desc.double_sided != d->double_sided;
    material_set(m, d);
    if (was_emissive != m->emissive || (m->emissive && emission_changed)) dev->area_dirty = true;
    if (was_masked != m->masked) dev->filters_dirty = true;
    dev->dirty = dev->shadow_dirty = true;
    return SY_RT_OK;
}

sy_rt_result sy_rt_material_destroy(sy_rt_device *dev, sy_rt_material mat)
{
    if (!dev) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "material destroy: NULL device");
    sy_rt_material_data *m = sy_rt_pool_take(dev, &dev->materials, mat.id, "material destroy");
    if (!m) return SY_RT_ERROR_INVALID_HANDLE;
    /* Instances using it fall back to the default material, which is neither emissive nor masked. */
    if (m->emissive) dev->area_dirty = true;
    if (m->masked) dev->filters_dirty = true;
    free(m);
    dev->dirty = dev->shadow_dirty = true;
    return SY_RT_OK;
}

/* >>instance */

/* Checks that xf is finite and invertible and computes the normal matrix (inverse transpose of
 * the upper 3x3, row-major) and *gain, the row-sum norm of the inverse (how much the inverse
 * magnifies a ray's coordinates). */
static sy_rt_result normal_matrix(const sy_rt_device *dev, const float *xf, float nrm[9], double *gain)
{
    for (int i = 0; i < 16; ++i)
        if (!isfinite(xf[i])) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "instance: transform[%d] = %g is not finite", i, (double)xf[i]);
    double a[3][3];
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) a[r][c] = xf[c * 4 + r];
    double C[3][3] = {
        {a[1][1] * a[2][2] - a[1][2] * a[2][1], -(a[1][0] * a[2][2] - a[1][2] * a[2][0]), a[1][0] * a[2][1] - a[1][1] * a[2][0]},
        {-(a[0][1] * a[2][2] - a[0][2] * a[2][1]), a[0][0] * a[2][2] - a[0][2] * a[2][0], -(a[0][0] * a[2][1] - a[0][1] * a[2][0])},
        {a[0][1] * a[1][2] - a[0][2] * a[1][1], -(a[0][0] * a[1][2] - a[0][2] * a[1][0]), a[0][0] * a[1][1] - a[0][1] * a[1][0]},
    };
    double det = a[0][0] * C[0][0] + a[0][1] * C[0][1] + a[0][2] * C[0][2];
    double scale = 0.0;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) scale = fmax(scale, fabs(a[r][c]));
    if (!(fabs(det) > 1e-30 * scale * scale * scale) || scale == 0.0)
        return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "instance: transform is singular (det %g)", det);
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) nrm[r * 3 + c] = (float)(C[r][c] / det);
    *gain = 0.0; /* the inverse is C^T / det: its rows are C's columns */
    for (int c = 0; c < 3; ++c) *gain = fmax(*gain, (fabs(C[0][c]) + fabs(C[1][c]) + fabs(C[2][c])) / fabs(det));
    return SY_RT_OK;
}

/* SY_RT_COORD_MAX for an instance of mesh m placed by xf: its translation and its world extent. */
static sy_rt_result instance_in_range(const sy_rt_device *dev, const sy_rt_mesh_data *m, const float *xf)
{
    double lin = 0.0, t = fmax(fabs(xf[12]), fmax(fabs(xf[13]), fabs(xf[14])));
    for (int r = 0; r < 3; ++r)
        lin = fmax(lin, fabs(xf[r]) + fabs(xf[4 + r]) + fabs(xf[8 + r]));
    double reach = lin * m->extent + t;
    if (!(reach <= SY_RT_COORD_MAX))
        return FAIL(SY_RT_ERROR_INVALID_ARGUMENT,
                    "instance: placed beyond SY_RT_COORD_MAX (translation (%g %g %g), world extent up to %g; at most %g)",
                    (double)xf[12], (double)xf[13], (double)xf[14], reach, (double)SY_RT_COORD_MAX);
    return SY_RT_OK;
}

static bool instance_emissive(const sy_rt_device *dev, const sy_rt_instance_data *in)
{
    return !(in->flags & SY_RT_INSTANCE_HIDDEN) && sy_rt_material_lookup(dev, in->material)->emissive;
}

static bool instance_masked(const sy_rt_device *dev, const sy_rt_instance_data *in)
{
    return sy_rt_material_lookup(dev, in->material)->masked;
}

/* Writes the world-space positions of a baked instance. */
static void bake_positions(sy_rt_instance_data *in)
{
    const sy_rt_mesh_data *m = in->mesh;
    for (uint32_t i = 0; i < m->vertex_count; ++i) {
        sy_rt_v3 p = m4_point(in->xf, v3_load(m->positions + 3u * i));
        in->baked_positions[3u * i + 0] = p.x;
        in->baked_positions[3u * i + 1] = p.y;
        in->baked_positions[3u * i + 2] = p.z;
    }
}

/* Geometry id -> instance maps (dev->top_map, dev->dyn_map): grows *map to hold id. */
static bool id_map_set(sy_rt_instance_data ***map_io, uint32_t *cap_io, unsigned id, sy_rt_instance_data *in)
{
    if (id >= *cap_io) {
        uint32_t ncap = *cap_io ? *cap_io : 64u;
        while (ncap <= id) {
            if (ncap > UINT32_MAX / 2u) return false;
            ncap *= 2u;
        }
        sy_rt_instance_data **map = realloc(*map_io, (size_t)ncap * sizeof *map);
        if (!map) return false;
        memset(map + *cap_io, 0, (size_t)(ncap - *cap_io) * sizeof *map);
        *map_io = map;
        *cap_io = ncap;
    }
    (*map_io)[id] = in;
    return true;
}

static bool top_map_set(sy_rt_device *dev, unsigned id, sy_rt_instance_data *in)
{
    return id_map_set(&dev->top_map, &dev->top_map_cap, id, in);
}

/* >>moved instances (sy_rt_device.h): a moved instance's top-level copy keeps its old transform
 * until the next full rebuild of the top scene; until then it is filtered out and a twin in the
 * small scene dev->dyn shows it. */

/* Stale instances the fast path accepts before it rebuilds the top scene instead: each one costs
 * every ray a little (a filtered leaf in the top scene, a twin in dyn). */
static uint32_t stale_limit(const sy_rt_device *dev) { return 64u + dev->instances.live / 64u; }

/* The world point of a hit at barycentrics (u, v) of triangle prim of instance in. */
static void hit_world_point(const sy_rt_instance_data *in, unsigned prim, float u, float v, float p[3])
{
    const sy_rt_mesh_data *m = in->mesh;
    if (!m || prim >= m->triangle_count) {
        p[0] = p[1] = p[2] = 0.0f;
        return;
    }
    const uint32_t *ix = m->indices + 3u * prim;
    const bool baked = (in->flags & SY_RT_INSTANCE_BAKED) && in->baked_positions;
    const float *pos = baked ? in->baked_positions : m->positions;
    const float w = 1.0f - u - v;
    float q[3];
    for (int k = 0; k < 3; ++k) q[k] = w * pos[3u * ix[0] + k] + u * pos[3u * ix[1] + k] + v * pos[3u * ix[2] + k];
    if (baked) {
        memcpy(p, q, sizeof q);
        return;
    }
    const float *x = in->xf; /* column-major object-to-world */
    for (int k = 0; k < 3; ++k) p[k] = x[k] * q[0] + x[4 + k] * q[1] + x[8 + k] * q[2] + x[12 + k];
}

bool sy_rt_clip_cap(const sy_rt_device *dev, const sy_rt_instance_data *in, unsigned prim, sy_rt_v3 org, sy_rt_v3 dir,
                    float tnear, float thit, float *t_cap)
{
    if (!dev->clip_cap || !dev->clip_count || !in || !in->mesh || !in->mesh->closed || prim >= in->mesh->triangle_count)
        return false;
    float t_enter = -INFINITY;
    for (uint32_t c = 0; c < dev->clip_count; ++c) {
        const float *q = dev->clip_planes[c];
        float s0 = q[0] * org.x + q[1] * org.y + q[2] * org.z + q[3], ds = q[0] * dir.x + q[1] * dir.y + q[2] * dir.z;
        if (ds > 0.0f) t_enter = fmaxf(t_enter, -s0 / ds); /* crosses from the cut side into the kept one */
    }
    if (!(t_enter > tnear && t_enter < thit)) return false;
    /* back face: the world triangle's winding normal (counter-clockwise front; a mirroring placement
     * turns the winding) along the ray */
    const sy_rt_mesh_data *m = in->mesh;
    const uint32_t *ix = m->indices + 3u * prim;
    const bool baked = (in->flags & SY_RT_INSTANCE_BAKED) && in->baked_positions;
    const float *pos = baked ? in->baked_positions : m->positions;
    sy_rt_v3 p[3];
    for (int k = 0; k < 3; ++k) p[k] = v3_load(pos + 3u * ix[k]);
    sy_rt_v3 n = v3_cross(v3_sub(p[1], p[0]), v3_sub(p[2], p[0]));
    if (!baked) { /* the outward normal to world: the inverse transpose, as the cofactor matrix times the
                   * determinant's sign (a mirroring placement turns the winding, glTF's rule) */
        const float *x = in->xf;
        sy_rt_v3 c0 = v3(x[0], x[1], x[2]), c1 = v3(x[4], x[5], x[6]), c2 = v3(x[8], x[9], x[10]);
        sy_rt_v3 r0 = v3_cross(c1, c2), r1 = v3_cross(c2, c0), r2 = v3_cross(c0, c1);
        n = v3_add(v3_add(v3_scale(r0, n.x), v3_scale(r1, n.y)), v3_scale(r2, n.z));
        if (v3_dot(c0, r0) < 0.0f) n = v3_scale(n, -1.0f);
    }
    if (m->closed < 0) n = v3_scale(n, -1.0f); /* wound clockwise seen from outside */
    if (v3_dot(n, dir) <= 0.0f) return false;
    *t_cap = t_enter;
    return true;
}

void sy_rt_context_filter(const struct RTCFilterFunctionNArguments *args)
{
    const sy_rt_device *dev = args->geometryUserPtr;
    const sy_rt_ictx *ctx = (const sy_rt_ictx *)args->context;
    const unsigned N = args->N;
    const unsigned *hu = (const unsigned *)args->hit;
    const float *hf = (const float *)args->hit;
    for (unsigned i = 0; i < N; ++i) {
        if (args->valid[i] != -1) continue;
        const sy_rt_instance_data *in = sy_rt_filter_instance(dev, args->context, hu[6 * N + i], hu[7 * N + i]);
        if (!in) continue;
        if (!ctx->in_dyn && in->stale) { /* the top scene's stale copy: its twin in dyn shows it */
            args->valid[i] = 0;
            continue;
        }
        if (!dev->clip_count) continue;
        float p[3];
        hit_world_point(in, hu[5 * N + i], hf[3 * N + i], hf[4 * N + i], p);
        if (sy_rt_clip_removes(dev, p[0], p[1], p[2])) args->valid[i] = 0;
    }
}

static void twin_drop(sy_rt_device *dev, sy_rt_instance_data *in)
{
    if (!in->twin) return;
    rtcDetachGeometry(dev->dyn, in->twin_id);
    if (in->twin_id < dev->dyn_map_cap) dev->dyn_map[in->twin_id] = NULL;
    rtcReleaseGeometry(in->twin);
    in->twin = NULL;
    dev->dyn_count--;
    dev->dyn_dirty = true;
}

static void pending_remove(sy_rt_device *dev, sy_rt_instance_data *in)
{
    if (in->stale) dev->stale_count--;
    in->stale = false;
    twin_drop(dev, in);
    if (!in->xf_pending) return;
    in->xf_pending = false;
    /* from the end: commit_moved's full rebuild drains the list from its last entry, which this
     * finds at once (scanning from the front made draining n moved instances O(n^2): 10^4 nodes
     * moved each frame spent most of the top-level commit here) */
    for (uint32_t i = dev->pending_count; i-- > 0;)
        if (dev->pending[i] == in) {
            dev->pending[i] = dev->pending[--dev->pending_count];
            break;
        }
}

/* Sets an instance geometry's transforms (the top-level one or the twin): one time step, or with
 * motion two (shutter open and close; Embree interpolates between them by the ray's time). */
static void set_instance_transforms(RTCGeometry g, const sy_rt_instance_data *in)
{
    rtcSetGeometryTimeStepCount(g, in->motion ? 2u : 1u);
    rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT4X4_COLUMN_MAJOR, in->xf);
    if (in->motion) rtcSetGeometryTransform(g, 1, RTC_FORMAT_FLOAT4X4_COLUMN_MAJOR, in->xf1);
}

/* A baked instance's world-space vertices of time step 1 (motion), or none (one time step; Embree
 * drops the buffer with the step). */
static void bake_motion(sy_rt_instance_data *in)
{
    if (!in->motion) {
        rtcSetGeometryTimeStepCount(in->geom, 1u);
        in->baked_positions1 = NULL;
        return;
    }
    const sy_rt_mesh_data *m = in->mesh;
    rtcSetGeometryTimeStepCount(in->geom, 2u);
    if (!in->baked_positions1)
        in->baked_positions1 = rtcSetNewGeometryBuffer(in->geom, RTC_BUFFER_TYPE_VERTEX, 1, RTC_FORMAT_FLOAT3,
                                                       3 * sizeof(float), m->vertex_count);
    if (!in->baked_positions1) { /* out of memory (Embree reported it): shown at the open time */
        rtcSetGeometryTimeStepCount(in->geom, 1u);
        return;
    }
    for (uint32_t i = 0; i < m->vertex_count; ++i) {
        sy_rt_v3 p = m4_point(in->xf1, v3_load(m->positions + 3u * i));
        in->baked_positions1[3u * i + 0] = p.x;
        in->baked_positions1[3u * i + 1] = p.y;
        in->baked_positions1[3u * i + 2] = p.z;
    }
    rtcUpdateGeometryBuffer(in->geom, RTC_BUFFER_TYPE_VERTEX, 1);
}

/* Writes the instance's current transform into its top-level geometry (a full rebuild follows). */
static void apply_top_transform(sy_rt_instance_data *in)
{
    if (in->flags & SY_RT_INSTANCE_BAKED) {
        bake_positions(in);
        rtcUpdateGeometryBuffer(in->geom, RTC_BUFFER_TYPE_VERTEX, 0);
        if (in->motion || in->baked_positions1) bake_motion(in);
    } else {
        set_instance_transforms(in->geom, in);
    }
    rtcCommitGeometry(in->geom);
}

/* Shows a moved instance through its twin in dyn (created on its first move). */
static sy_rt_result twin_place(sy_rt_device *dev, sy_rt_instance_data *in)
{
    if (!in->twin) {
        sy_rt_result r = mesh_blas(dev, in->mesh); /* baked meshes have none yet */
        if (r != SY_RT_OK) return r;
        in->twin = rtcNewGeometry(dev->rtc, RTC_GEOMETRY_TYPE_INSTANCE);
        if (!in->twin) return sy_rt_check_embree(dev, "commit: twin of a moved instance");
        rtcSetGeometryInstancedScene(in->twin, in->mesh->scene);
        in->twin_id = rtcAttachGeometry(dev->dyn, in->twin);
        dev->dyn_count++;
        if (in->twin_id == RTC_INVALID_GEOMETRY_ID) {
            rtcReleaseGeometry(in->twin);
            in->twin = NULL;
            dev->dyn_count--;
            return sy_rt_check_embree(dev, "commit: attaching the twin of a moved instance");
        }
        if (!id_map_set(&dev->dyn_map, &dev->dyn_map_cap, in->twin_id, in)) {
            twin_drop(dev, in);
            return FAIL(SY_RT_ERROR_OUT_OF_MEMORY, "commit: twin of a moved instance: out of memory");
        }
    }
    set_instance_transforms(in->twin, in);
    rtcCommitGeometry(in->twin);
    if (!in->stale) {
        in->stale = true;
        dev->stale_count++;
    }
    dev->dyn_dirty = true;
    return sy_rt_check_embree(dev, "commit: twin of a moved instance");
}

/* Commit, moved instances: the fast path (twins) when nothing structural changed and few are
 * stale; otherwise every pending transform goes into the top scene, which is rebuilt. */
static sy_rt_result commit_moved(sy_rt_device *dev)
{
    if (dev->settle && dev->pending_count) dev->top_dirty = true; /* sy_rt_settle: no twins this commit */
    dev->settle = false;
    if (!dev->top_dirty && dev->pending_count) {
        uint32_t stale = dev->stale_count;
        for (uint32_t i = 0; i < dev->pending_count && !dev->top_dirty; ++i) {
            const sy_rt_instance_data *in = dev->pending[i];
            if (in->flags & SY_RT_INSTANCE_HIDDEN) continue; /* applied when it is shown again */
            if (!in->stale) stale++;
            /* a baked masked instance's BLAS has no alpha filter (update_filters) */
            if ((in->flags & SY_RT_INSTANCE_BAKED) && instance_masked(dev, in)) dev->top_dirty = true;
        }
        if (stale > stale_limit(dev)) dev->top_dirty = true;
        for (uint32_t i = 0; i < dev->pending_count && !dev->top_dirty; ++i) {
            sy_rt_instance_data *in = dev->pending[i];
            if (in->flags & SY_RT_INSTANCE_HIDDEN) continue;
            sy_rt_result r = twin_place(dev, in);
            if (r != SY_RT_OK) dev->top_dirty = true; /* the full path still shows it right */
        }
    }
    if (dev->top_dirty) {
        while (dev->pending_count) {
            sy_rt_instance_data *in = dev->pending[dev->pending_count - 1];
            apply_top_transform(in);
            pending_remove(dev, in);
        }
    }
    return sy_rt_check_embree(dev, "commit: moved instances");
}

static void instance_free(sy_rt_device *dev, sy_rt_instance_data *in)
{
    if (in->motion) dev->motion_count--;
    pending_remove(dev, in);
    if (in->geom) {
        if (in->top_id != RTC_INVALID_GEOMETRY_ID) {
            rtcDetachGeometry(dev->top, in->top_id);
            if (in->top_id < dev->top_map_cap) dev->top_map[in->top_id] = NULL;
        }
        rtcReleaseGeometry(in->geom);
    }
    mesh_unref(dev, in->mesh);
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
    sy_rt_result r = normal_matrix(dev, d->transform, nrm, &gain);
    if (r != SY_RT_OK || (r = instance_in_range(dev, mesh, d->transform)) != SY_RT_OK) return r;
    uint32_t flags = d->flags;
    if (gain > SY_RT_INSTANCE_GAIN_MAX) flags |= SY_RT_INSTANCE_BAKED; /* Embree never sees its inverse */
    if (!(flags & SY_RT_INSTANCE_BAKED) && (r = mesh_blas(dev, mesh)) != SY_RT_OK) return r;

    sy_rt_instance_data *in = calloc(1, sizeof *in);
    if (!in) return FAIL(SY_RT_ERROR_OUT_OF_MEMORY, "instance: out of memory");
    in->mesh = mesh;
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
            if (in->baked_positions) bake_positions(in);
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
    if (instance_emissive(dev, in)) dev->area_dirty = true;
    if (instance_masked(dev, in)) dev->filters_dirty = true;
    dev->dirty = dev->top_dirty = dev->shadow_dirty = true;
    return SY_RT_OK;
fail:
    instance_free(dev, in);
    dev->dirty = dev->top_dirty = dev->shadow_dirty = true;
    return r;
}

/* Puts a moved instance on the pending list (once); Embree sees the move at sy_rt_commit
 * (commit_moved). False when out of memory. */
static bool pending_add(sy_rt_device *dev, sy_rt_instance_data *in)
{
    if (in->xf_pending) return true;
    if (dev->pending_count == dev->pending_cap) {
        uint32_t ncap = dev->pending_cap ? dev->pending_cap * 2u : 64u;
        sy_rt_instance_data **p = ncap > dev->pending_cap ? realloc(dev->pending, (size_t)ncap * sizeof *p) : NULL;
        if (!p) return false;
        dev->pending = p;
        dev->pending_cap = ncap;
    }
    dev->pending[dev->pending_count++] = in;
    in->xf_pending = true;
    return true;
}

sy_rt_result sy_rt_settle(sy_rt_device *dev)
{
    if (!dev) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "settle: NULL device");
    /* every instance shown through a twin goes back into the top scene (commit_moved's full path) */
    for (uint32_t i = 0; i < dev->instances.count; ++i) {
        sy_rt_instance_data *in = dev->instances.items[i];
        if (in && in->stale && !pending_add(dev, in)) return FAIL(SY_RT_ERROR_OUT_OF_MEMORY, "settle: out of memory");
    }
    if (dev->pending_count || dev->stale_count) {
        dev->top_dirty = true;
        dev->dirty = true;
    }
    dev->settle = true;
    return SY_RT_OK;
}

sy_rt_result sy_rt_instance_set_transform(sy_rt_device *dev, sy_rt_instance inst, const float transform[16])
{
    if (!dev || !transform) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "instance set_transform: NULL argument");
    sy_rt_instance_data *in = sy_rt_pool_find(dev, &dev->instances, inst.id, "instance set_transform");
    if (!in) return SY_RT_ERROR_INVALID_HANDLE;
    float nrm[9];
    double gain;
    sy_rt_result r = normal_matrix(dev, transform, nrm, &gain);
    if (r != SY_RT_OK || (r = instance_in_range(dev, in->mesh, transform)) != SY_RT_OK) return r;
    if (gain > SY_RT_INSTANCE_GAIN_MAX && !(in->flags & SY_RT_INSTANCE_BAKED))
        return FAIL(SY_RT_ERROR_INVALID_ARGUMENT,
                    "instance set_transform: the transform shrinks by %g (more than SY_RT_INSTANCE_GAIN_MAX %g allows "
                    "for an instance created unbaked); create it again",
                    1.0 / gain, (double)SY_RT_INSTANCE_GAIN_MAX);
    if (!pending_add(dev, in)) return FAIL(SY_RT_ERROR_OUT_OF_MEMORY, "instance set_transform: out of memory");
    memcpy(in->xf, transform, sizeof in->xf);
    memcpy(in->nrm, nrm, sizeof in->nrm);
    if (instance_emissive(dev, in)) dev->area_dirty = true;
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
    bool was_emissive = instance_emissive(dev, in), was_masked = instance_masked(dev, in);
    in->material = material;
    if (was_emissive || instance_emissive(dev, in)) dev->area_dirty = true;
    if (was_masked != instance_masked(dev, in)) dev->filters_dirty = true;
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
    if (instance_masked(dev, in)) dev->filters_dirty = true;
    dev->dirty = dev->top_dirty = dev->shadow_dirty = true;
    return sy_rt_check_embree(dev, "instance set_visible");
}

sy_rt_result sy_rt_instance_destroy(sy_rt_device *dev, sy_rt_instance inst)
{
    if (!dev) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "instance destroy: NULL device");
    sy_rt_instance_data *in = sy_rt_pool_take(dev, &dev->instances, inst.id, "instance destroy");
    if (!in) return SY_RT_ERROR_INVALID_HANDLE;
    if (instance_emissive(dev, in)) dev->area_dirty = true;
    if (instance_masked(dev, in)) dev->filters_dirty = true;
    instance_free(dev, in);
    dev->dirty = dev->top_dirty = dev->shadow_dirty = true;
    return sy_rt_check_embree(dev, "instance destroy");
}

/* >>motion blur: an instance's placement at shutter close (ray time 1) beside its transform (time 0) */

sy_rt_result sy_rt_instance_get_transform(const sy_rt_device *dev, sy_rt_instance inst, float transform[16])
{
    if (!dev || !transform) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "instance get_transform: NULL argument");
    const sy_rt_instance_data *in = sy_rt_pool_get(&dev->instances, inst.id);
    if (!in) return FAIL(SY_RT_ERROR_INVALID_HANDLE, "instance get_transform: stale handle 0x%08x", inst.id);
    memcpy(transform, in->xf, sizeof in->xf);
    return SY_RT_OK;
}

sy_rt_result sy_rt_instance_set_motion(sy_rt_device *dev, sy_rt_instance inst, const float close[16])
{
    if (!dev) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "instance set_motion: NULL device");
    sy_rt_instance_data *in = sy_rt_pool_get(&dev->instances, inst.id);
    if (!in) return FAIL(SY_RT_ERROR_INVALID_HANDLE, "instance set_motion: stale handle 0x%08x", inst.id);
    if (close && memcmp(close, in->xf, sizeof in->xf) == 0) close = NULL; /* no motion */
    if (!close && !in->motion) return SY_RT_OK;
    if (close) {
        float nrm[9];
        double gain;
        sy_rt_result r = normal_matrix(dev, close, nrm, &gain);
        if (r != SY_RT_OK || (r = instance_in_range(dev, in->mesh, close)) != SY_RT_OK) return r;
        if (gain > SY_RT_INSTANCE_GAIN_MAX && !(in->flags & SY_RT_INSTANCE_BAKED))
            return FAIL(SY_RT_ERROR_INVALID_ARGUMENT,
                        "instance set_motion: the close transform shrinks by %g (more than SY_RT_INSTANCE_GAIN_MAX %g "
                        "allows for an instance created unbaked)", 1.0 / gain, (double)SY_RT_INSTANCE_GAIN_MAX);
    }
    if (!pending_add(dev, in)) return FAIL(SY_RT_ERROR_OUT_OF_MEMORY, "instance set_motion: out of memory");
    if (close && !in->motion) dev->motion_count++;
    if (!close && in->motion) dev->motion_count--;
    in->motion = close != NULL;
    if (close) memcpy(in->xf1, close, sizeof in->xf1);
    if (instance_emissive(dev, in)) dev->area_dirty = true;
    dev->dirty = true;
    return SY_RT_OK;
}

/* Ends a mesh's motion: one time step again, its time-0 pose kept (Embree drops the slot-1 buffer). */
static void mesh_motion_off(sy_rt_device *dev, sy_rt_mesh_data *m)
{
    if (!m->motion) return;
    rtcSetGeometryTimeStepCount(m->geom, 1);
    rtcCommitGeometry(m->geom);
    if (m->scene) rtcCommitScene(m->scene);
    size_t bytes = (size_t)m->vertex_count * 3u * sizeof(float) * (m->normals1 ? 2u : 1u);
    m->own_bytes -= bytes;
    dev->mesh_bytes -= bytes;
    free(m->normals1);
    m->normals1 = NULL;
    m->positions1 = NULL;
    m->motion = false;
    dev->motion_count--;
    dev->dirty = dev->top_dirty = dev->shadow_dirty = dev->area_dirty = true;
}

sy_rt_result sy_rt_mesh_update_motion(sy_rt_device *dev, sy_rt_mesh mesh, const float *positions, const float *normals)
{
    if (!dev || !positions) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "mesh update_motion: NULL argument");
    sy_rt_mesh_data *m = sy_rt_pool_get(&dev->meshes, mesh.id);
    if (!m) return FAIL(SY_RT_ERROR_INVALID_HANDLE, "mesh update_motion: mesh handle 0x%08x is stale", mesh.id);
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

sy_rt_result sy_rt_motion_clear(sy_rt_device *dev)
{
    if (!dev) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "motion clear: NULL device");
    for (uint32_t i = 0; dev->motion_count && i < dev->meshes.count; ++i) {
        sy_rt_mesh_data *m = dev->meshes.items[i];
        if (m && m->motion) mesh_motion_off(dev, m);
    }
    for (uint32_t i = 0; dev->motion_count && i < dev->instances.count; ++i) {
        sy_rt_instance_data *in = dev->instances.items[i];
        if (in && in->motion) {
            sy_rt_result r = sy_rt_instance_set_motion(dev, (sy_rt_instance){in->handle}, NULL);
            if (r != SY_RT_OK) return r;
        }
    }
    return SY_RT_OK;
}

/* >>light */

static sy_rt_result validate_light(const sy_rt_device *dev, const sy_rt_light_desc *d)
{
    if (d->type != SY_RT_LIGHT_POINT && d->type != SY_RT_LIGHT_SPOT && d->type != SY_RT_LIGHT_DIRECTIONAL)
        return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "light: unknown type %d", (int)d->type);
    const float *vals[] = {d->color, d->position, d->direction};
    const char *names[] = {"color", "position", "direction"};
    for (int a = 0; a < 3; ++a)
        for (int k = 0; k < 3; ++k)
            if (!isfinite(vals[a][k]))
                return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "light: %s[%d] is not finite", names[a], k);
    for (int k = 0; k < 3; ++k)
        if (d->color[k] < 0.0f) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "light: color[%d] is negative", k);
    for (int k = 0; k < 3; ++k)
        if (fabsf(d->position[k]) > SY_RT_COORD_MAX)
            return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "light: position[%d] = %g is beyond SY_RT_COORD_MAX (%g)", k,
                        (double)d->position[k], (double)SY_RT_COORD_MAX);
    if (!isfinite(d->intensity) || d->intensity < 0.0f)
        return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "light: intensity %g is not a finite non-negative value", (double)d->intensity);
    if (!isfinite(d->range) || d->range < 0.0f)
        return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "light: range %g is not finite and >= 0", (double)d->range);
    if (d->type != SY_RT_LIGHT_POINT && v3_is_zero(v3_load(d->direction)))
        return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "light: direction is zero");
    if (d->type == SY_RT_LIGHT_SPOT &&
        !(d->inner_cone_angle >= 0.0f && d->inner_cone_angle <= d->outer_cone_angle && d->outer_cone_angle <= 1.5707964f))
        return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "light: spot cone angles need 0 <= inner (%g) <= outer (%g) <= pi/2",
                    (double)d->inner_cone_angle, (double)d->outer_cone_angle);
    return SY_RT_OK;
}

sy_rt_result sy_rt_light_create(sy_rt_device *dev, const sy_rt_light_desc *d, sy_rt_light *out)
{
    if (!dev || !d || !out) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "light: NULL argument");
    out->id = 0;
    sy_rt_result r = validate_light(dev, d);
    if (r != SY_RT_OK) return r;
    sy_rt_light_data *l = calloc(1, sizeof *l);
    if (!l) return FAIL(SY_RT_ERROR_OUT_OF_MEMORY, "light: out of memory");
    l->desc = *d;
    if ((r = pool_add(dev, &dev->lights, l, &out->id, "light")) != SY_RT_OK) return r;
    dev->dirty = dev->punctual_dirty = true;
    return SY_RT_OK;
}

sy_rt_result sy_rt_light_update(sy_rt_device *dev, sy_rt_light light, const sy_rt_light_desc *d)
{
    if (!dev || !d) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "light update: NULL argument");
    sy_rt_light_data *l = sy_rt_pool_find(dev, &dev->lights, light.id, "light update");
    if (!l) return SY_RT_ERROR_INVALID_HANDLE;
    sy_rt_result r = validate_light(dev, d);
    if (r != SY_RT_OK) return r;
    l->desc = *d;
    dev->dirty = dev->punctual_dirty = true;
    return SY_RT_OK;
}

sy_rt_result sy_rt_light_destroy(sy_rt_device *dev, sy_rt_light light)
{
    if (!dev) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "light destroy: NULL device");
    sy_rt_light_data *l = sy_rt_pool_take(dev, &dev->lights, light.id, "light destroy");
    if (!l) return SY_RT_ERROR_INVALID_HANDLE;
    free(l);
    dev->dirty = dev->punctual_dirty = true;
    return SY_RT_OK;
}

/* >>commit */

static double sy_rt_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void set_filter(RTCGeometry g, bool on)
{
    rtcSetGeometryIntersectFilterFunction(g, on ? sy_rt_alpha_filter : NULL);
    rtcSetGeometryOccludedFilterFunction(g, on ? sy_rt_alpha_filter : NULL);
    rtcCommitGeometry(g);
}

/* Installs the alpha-mask filter exactly where a visible masked material needs it, so opaque
 * geometry never pays for a filter call. A mesh's BLAS is shared by its instances, so it gets the
 * filter when any of its instances is masked (the filter then checks the hit's instance). */
static void update_filters(sy_rt_device *dev)
{
    for (uint32_t i = 0; i < dev->meshes.count; ++i)
        if (dev->meshes.items[i]) ((sy_rt_mesh_data *)dev->meshes.items[i])->want_filter = false;
    /* Meshes whose handle was destroyed but that instances still hold are reached via instances. */
    for (uint32_t i = 0; i < dev->instances.count; ++i) {
        sy_rt_instance_data *in = dev->instances.items[i];
        if (in) in->mesh->want_filter = false;
    }
    for (uint32_t i = 0; i < dev->instances.count; ++i) {
        sy_rt_instance_data *in = dev->instances.items[i];
        if (!in) continue;
        bool want = instance_masked(dev, in);
        if (in->flags & SY_RT_INSTANCE_BAKED) {
            if (want != in->filter_on) {
                set_filter(in->geom, want);
                in->filter_on = want;
                dev->top_dirty = true;
            }
        } else if (want) {
            in->mesh->want_filter = true;
        }
    }
    for (uint32_t pass = 0; pass < 2; ++pass) {
        const sy_rt_pool *pool = pass == 0 ? &dev->meshes : &dev->instances;
        for (uint32_t i = 0; i < pool->count; ++i) {
            if (!pool->items[i]) continue;
            sy_rt_mesh_data *m = pass == 0 ? pool->items[i] : ((sy_rt_instance_data *)pool->items[i])->mesh;
            if (m->want_filter == m->filter_on) continue;
            set_filter(m->geom, m->want_filter);
            if (m->scene) rtcCommitScene(m->scene);
            m->filter_on = m->want_filter;
            dev->top_dirty = true;
        }
    }
}

/* An emitter left out of light sampling: counted, and the message kept (sy_rt_stats). */
static void light_warn(sy_rt_device *dev, uint32_t count, const char *what)
{
    if (!count) return;
    dev->light_warnings += count;
    snprintf(dev->light_warning, sizeof dev->light_warning, "%s%s", what,
             count > 1u ? " (and others: see light_warnings)" : "");
}

static sy_rt_result rebuild_area_lights(sy_rt_device *dev)
{
    size_t n = 0;
    for (uint32_t i = 0; i < dev->instances.count; ++i) {
        sy_rt_instance_data *in = dev->instances.items[i];
        if (in) in->area_base = UINT32_MAX;
        if (in && instance_emissive(dev, in)) n += in->mesh->triangle_count;
    }
    free(dev->area);
    free(dev->area_cdf);
    free(dev->area_map);
    dev->area = NULL;
    dev->area_cdf = NULL;
    dev->area_map = NULL;
    dev->area_count = 0;
    dev->area_power = 0.0f;
    dev->light_tree_dirty = true;
    (void)sy_rt_alias_build(dev, NULL, 0); /* frees the old table */
    if (n == 0) return SY_RT_OK;
    if (n > UINT32_MAX - 1u) return FAIL(SY_RT_ERROR_LIMIT, "commit: %zu emissive triangles exceed the limit", n);
    dev->area = malloc(n * sizeof *dev->area);
    double *cdf = malloc((n + 1u) * sizeof *cdf);
    dev->area_cdf = malloc((n + 1u) * sizeof *dev->area_cdf);
    dev->area_map = malloc(n * sizeof *dev->area_map);
    if (!dev->area || !cdf || !dev->area_cdf || !dev->area_map) {
        free(cdf);
        free(dev->area);
        free(dev->area_cdf);
        free(dev->area_map);
        dev->area = NULL;
        dev->area_cdf = NULL;
        dev->area_map = NULL;
        return FAIL(SY_RT_ERROR_OUT_OF_MEMORY, "commit: cannot allocate the area-light list (%zu triangles)", n);
    }
    uint32_t count = 0, base = 0, degenerate = 0;
    char first[200] = "";
    cdf[0] = 0.0;
    for (uint32_t i = 0; i < dev->instances.count; ++i) {
        sy_rt_instance_data *in = dev->instances.items[i];
        if (!in || !instance_emissive(dev, in)) continue;
        in->area_base = base;
        const sy_rt_material_data *mat = sy_rt_material_lookup(dev, in->material);
        float lum = v3_luminance(v3_load(mat->desc.emissive));
        if (!(lum > 0.0f)) lum = fmaxf(mat->desc.emissive[0], fmaxf(mat->desc.emissive[1], mat->desc.emissive[2]));
        const sy_rt_mesh_data *m = in->mesh;
        for (uint32_t t = 0; t < m->triangle_count; ++t) {
            dev->area_map[base + t] = UINT32_MAX;
            const uint32_t *ix = m->indices + 3u * t;
            sy_rt_v3 o0 = v3_load(m->positions + 3u * ix[0]), o1 = v3_load(m->positions + 3u * ix[1]),
                     o2 = v3_load(m->positions + 3u * ix[2]);
            sy_rt_v3 p0 = m4_point(in->xf, o0), p1 = m4_point(in->xf, o1), p2 = m4_point(in->xf, o2);
            sy_rt_area_tri *a = &dev->area[count];
            a->p0 = p0;
            a->e1 = v3_sub(p1, p0);
            a->e2 = v3_sub(p2, p0);
            a->area = 0.5f * v3_length(v3_cross(a->e1, a->e2));
            /* glTF front side: object-space winding normal through the normal matrix. */
            a->normal = v3_normalize(m3_mul(in->nrm, v3_cross(v3_sub(o1, o0), v3_sub(o2, o0))));
            if (!(a->area > 0.0f) || v3_is_zero(a->normal)) { /* degenerate: emits nothing */
                if (degenerate++ == 0)
                    snprintf(first, sizeof first, "light sampling: emissive triangle %u of instance 0x%08x has zero area: "
                             "left out", t, in->handle);
                continue;
            }
            a->inst = in;
            a->prim = t;
            a->double_sided = mat->desc.double_sided;
            a->emission = v3_load(mat->desc.emissive);
            a->textured = mat->desc.emissive_texture.texture.id != 0;
            cdf[count + 1] = cdf[count] + (double)lum * a->area * (a->double_sided ? 2.0 : 1.0);
            dev->area_map[base + t] = count;
            count++;
        }
        base += m->triangle_count;
    }
    light_warn(dev, degenerate, first);
    double total = cdf[count];
    if (count == 0 || !(total > 0.0)) {
        free(cdf);
        free(dev->area);
        free(dev->area_cdf);
        free(dev->area_map);
        dev->area = NULL;
        dev->area_cdf = NULL;
        dev->area_map = NULL;
        return SY_RT_OK;
    }
    for (uint32_t i = 0; i <= count; ++i) dev->area_cdf[i] = (float)(cdf[i] / total);
    dev->area_cdf[count] = 1.0f;
    /* path tracer: alias table over the same weights (cdf[] becomes the weights in place) */
    for (uint32_t i = 0; i < count; ++i) cdf[i] = cdf[i + 1] - cdf[i];
    bool alias_ok = sy_rt_alias_build(dev, cdf, count);
    free(cdf);
    if (!alias_ok) {
        free(dev->area);
        free(dev->area_cdf);
        free(dev->area_map);
        dev->area = NULL;
        dev->area_cdf = NULL;
        dev->area_map = NULL;
        return FAIL(SY_RT_ERROR_OUT_OF_MEMORY, "commit: cannot allocate the area-light alias table (%u triangles)", count);
    }
    dev->area_count = count;
    dev->area_power = (float)total;
    for (uint32_t i = 0; i < count; ++i) dev->area[i].pdf_select = sy_rt_area_pdf(dev, dev->area[i].inst);
    return SY_RT_OK;
}

static sy_rt_result rebuild_punctual(sy_rt_device *dev)
{
    free(dev->punctual);
    dev->punctual = NULL;
    dev->punctual_count = 0;
    dev->light_tree_dirty = true;
    uint32_t n = dev->lights.live;
    if (n == 0) return SY_RT_OK;
    dev->punctual = malloc((size_t)n * sizeof *dev->punctual);
    if (!dev->punctual) return FAIL(SY_RT_ERROR_OUT_OF_MEMORY, "commit: cannot allocate %u lights", n);
    for (uint32_t i = 0; i < dev->lights.count; ++i) {
        const sy_rt_light_data *l = dev->lights.items[i];
        if (!l) continue;
        const sy_rt_light_desc *d = &l->desc;
        sy_rt_punctual *p = &dev->punctual[dev->punctual_count++];
        p->handle = (dev->lights.gens[i] << SY_RT_INDEX_BITS) | (i + 1u);
        p->type = d->type;
        p->radiant = v3_scale(v3_load(d->color), d->intensity);
        p->position = v3_load(d->position);
        p->direction = v3_normalize(v3_load(d->direction));
        p->range = d->range;
        /* KHR_lights_punctual reference falloff between the outer and inner cone. */
        float cos_outer = cosf(d->outer_cone_angle), cos_inner = cosf(d->inner_cone_angle);
        p->cone_scale = 1.0f / fmaxf(0.001f, cos_inner - cos_outer);
        p->cone_offset = -cos_outer * p->cone_scale;
    }
    return SY_RT_OK;
}

sy_rt_result sy_rt_commit(sy_rt_device *dev)
{
    if (!dev) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "commit: NULL device");
    if (!dev->dirty) return SY_RT_OK;
    sy_rt_result r;
    if (dev->filters_dirty) {
        update_filters(dev);
        if ((r = sy_rt_check_embree(dev, "commit: alpha filters")) != SY_RT_OK) return r;
        dev->filters_dirty = false;
    }
    double t0 = sy_rt_seconds();
    if ((r = commit_moved(dev)) != SY_RT_OK) return r;
    if (dev->dyn_dirty) {
        rtcCommitScene(dev->dyn);
        if ((r = sy_rt_check_embree(dev, "commit: moved instances' scene")) != SY_RT_OK) return r;
        dev->dyn_dirty = false;
    }
    dev->last_top_commit_seconds = sy_rt_seconds() - t0;
    if (dev->top_dirty) {
        rtcCommitScene(dev->top);
        dev->top_builds++;
        dev->last_top_commit_seconds = sy_rt_seconds() - t0;
        if ((r = sy_rt_check_embree(dev, "commit: top-level scene")) != SY_RT_OK) {
            if (dev->max_memory > 0 && (double)atomic_load(&dev->embree_peak) * 1.25 > (double)dev->max_memory)
                r = FAIL(SY_RT_ERROR_OUT_OF_MEMORY, "commit: the top-level BVH went past the device's memory limit of "
                         "%.1f MB (Embree held %.1f MB at its peak)", (double)dev->max_memory / 1048576.0,
                         (double)atomic_load(&dev->embree_peak) / 1048576.0);
            return r;
        }
        dev->top_dirty = false;
    }
    if (dev->area_dirty) {
        if ((r = rebuild_area_lights(dev)) != SY_RT_OK) return r;
        dev->area_dirty = false;
    }
    if (dev->punctual_dirty) {
        if ((r = rebuild_punctual(dev)) != SY_RT_OK) return r;
        dev->punctual_dirty = false;
    }
    dev->background = dev->background_staged;
    if (dev->shadow_dirty) { /* O(instances): only when a material, visibility or instance set changed */
        sy_rt_shadow_flags_update(dev);
        dev->shadow_dirty = false;
    }
    if (dev->env_dirty) {
        if ((r = sy_rt_env_rebuild(dev)) != SY_RT_OK) return r;
        dev->env_dirty = false;
    }
    dev->dirty = false;
    dev->version++;
    return SY_RT_OK;
}

void sy_rt_scene_release_all(sy_rt_device *dev)
{
    for (uint32_t i = 0; i < dev->instances.count; ++i)
        if (dev->instances.items[i]) instance_free(dev, dev->instances.items[i]);
    for (uint32_t i = 0; i < dev->meshes.count; ++i)
        if (dev->meshes.items[i]) mesh_unref(dev, dev->meshes.items[i]);
    for (uint32_t i = 0; i < dev->materials.count; ++i) free(dev->materials.items[i]);
    for (uint32_t i = 0; i < dev->lights.count; ++i) free(dev->lights.items[i]);
    sy_rt_pool_free(&dev->instances);
    sy_rt_pool_free(&dev->meshes);
    sy_rt_pool_free(&dev->materials);
    sy_rt_pool_free(&dev->lights);
    free(dev->top_map);
    free(dev->dyn_map);
    dev->dyn_map = NULL;
    dev->dyn_map_cap = 0;
    free(dev->pending);
    dev->pending = NULL;
    dev->pending_count = dev->pending_cap = 0;
    free(dev->punctual);
    free(dev->area);
    free(dev->area_cdf);
    free(dev->area_alias_prob);
    free(dev->area_alias_idx);
    free(dev->area_map);
    dev->area_map = NULL;
    dev->area_alias_prob = NULL;
    dev->area_alias_idx = NULL;
    sy_rt_light_tree_free(dev);
    sy_rt_env_free(dev);
    dev->top_map = NULL;
    dev->punctual = NULL;
    dev->area = NULL;
    dev->area_cdf = NULL;
}
