/* sy_rt_scene.c — sy_rt_commit, which publishes the staged changes of the scene modules (sy_rt_mesh.c,
 * sy_rt_material.c, sy_rt_instance.c, sy_rt_moved.c, sy_rt_punctual.c): alpha filters, moved
 * instances, the top-level BVH, the area-light list and the punctual-light array; and the teardown
 * of every scene object (sy_rt_scene_release_all). The top of the scene modules: it calls them,
 * none calls it. */
#include "sy_rt_scene.h"
#include "sy_rt_lights.h"
#include "sy_rt_shadow.h"
#include "sy_rt_surface.h"

#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#define FAIL(r, ...) sy_rt_fail(dev, (r), __VA_ARGS__)

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
        bool want = sy_rt_instance_masked(dev, in);
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

/* Frees the area-light triangles, their CDF and the triangle map (the alias table is
 * sy_rt_alias_build's). */
static void area_free(sy_rt_device *dev)
{
    free(dev->area);
    free(dev->area_cdf);
    free(dev->area_map);
    dev->area = NULL;
    dev->area_cdf = NULL;
    dev->area_map = NULL;
}

static sy_rt_result rebuild_area_lights(sy_rt_device *dev)
{
    size_t n = 0;
    for (uint32_t i = 0; i < dev->instances.count; ++i) {
        sy_rt_instance_data *in = dev->instances.items[i];
        if (in) in->area_base = UINT32_MAX;
        if (in && sy_rt_instance_emissive(dev, in)) n += in->mesh->triangle_count;
    }
    area_free(dev);
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
        area_free(dev);
        return FAIL(SY_RT_ERROR_OUT_OF_MEMORY, "commit: cannot allocate the area-light list (%zu triangles)", n);
    }
    uint32_t count = 0, base = 0, degenerate = 0;
    char first[200] = "";
    cdf[0] = 0.0;
    for (uint32_t i = 0; i < dev->instances.count; ++i) {
        sy_rt_instance_data *in = dev->instances.items[i];
        if (!in || !sy_rt_instance_emissive(dev, in)) continue;
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
        area_free(dev);
        return SY_RT_OK;
    }
    for (uint32_t i = 0; i <= count; ++i) dev->area_cdf[i] = (float)(cdf[i] / total);
    dev->area_cdf[count] = 1.0f;
    /* path tracer: alias table over the same weights (cdf[] becomes the weights in place) */
    for (uint32_t i = 0; i < count; ++i) cdf[i] = cdf[i + 1] - cdf[i];
    bool alias_ok = sy_rt_alias_build(dev, cdf, count);
    free(cdf);
    if (!alias_ok) {
        area_free(dev);
        return FAIL(SY_RT_ERROR_OUT_OF_MEMORY, "commit: cannot allocate the area-light alias table (%u triangles)", count);
    }
    dev->area_count = count;
    dev->area_power = (float)total;
    for (uint32_t i = 0; i < count; ++i) dev->area[i].pdf_select = sy_rt_area_pdf(dev, dev->area[i].inst);
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
    if ((r = sy_rt_commit_moved(dev)) != SY_RT_OK) return r;
    if (dev->dyn_dirty) {
        rtcCommitScene(dev->dyn);
        if ((r = sy_rt_check_embree(dev, "commit: moved instances' scene")) != SY_RT_OK) return r;
        dev->dyn_dirty = false;
    }
    dev->last_top_commit_seconds = sy_rt_seconds() - t0;
    if (dev->top_dirty) {
        rtcCommitScene(dev->top);
        dev->top_builds++;
        if (dev->top_fast) dev->top_fast_builds++;
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
        if ((r = sy_rt_punctual_rebuild(dev)) != SY_RT_OK) return r;
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
        if (dev->instances.items[i]) sy_rt_instance_free(dev, dev->instances.items[i]);
    for (uint32_t i = 0; i < dev->meshes.count; ++i)
        if (dev->meshes.items[i]) sy_rt_mesh_unref(dev, dev->meshes.items[i]);
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
    area_free(dev);
    free(dev->area_alias_prob);
    free(dev->area_alias_idx);
    dev->area_alias_prob = NULL;
    dev->area_alias_idx = NULL;
    sy_rt_light_tree_free(dev);
    sy_rt_env_free(dev);
    dev->top_map = NULL;
    dev->punctual = NULL;
}

