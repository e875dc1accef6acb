/* sy_rt_moved.c — moved instances and motion blur. A moved instance goes on the pending list; at
 * sy_rt_commit (sy_rt_commit_moved) it is shown through a twin in the small scene dev->dyn while
 * its top-level copy is stale, or, when too many are stale or something structural changed, every
 * pending transform goes into the top scene, which is rebuilt. sy_rt_settle puts every twin back;
 * motion blur gives an instance a second transform at shutter close. Called by sy_rt_instance.c
 * and sy_rt_scene.c; calls sy_rt_placement.c and sy_rt_mesh.c (never back). */
#include "sy_rt_scene.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define FAIL(r, ...) sy_rt_fail(dev, (r), __VA_ARGS__)

/* >>moved instances (sy_rt_device.h): a moved instance's top-level copy keeps its old transform
 * until the next full rebuild of the top scene; until then it is filtered out and a twin in the
 * small scene dev->dyn shows it. */

/* Stale instances the fast path accepts before it rebuilds the top scene instead: each one costs
 * every ray a little (a filtered leaf in the top scene, a twin in dyn). */
static uint32_t stale_limit(const sy_rt_device *dev) { return 64u + dev->instances.live / 64u; }

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

void sy_rt_pending_remove(sy_rt_device *dev, sy_rt_instance_data *in)
{
    if (in->stale) dev->stale_count--;
    in->stale = false;
    twin_drop(dev, in);
    if (!in->xf_pending) return;
    in->xf_pending = false;
    /* from the end: sy_rt_commit_moved's full rebuild drains the list from its last entry, which this
     * finds at once (scanning from the front made draining n moved instances O(n^2): 10^4 nodes
     * moved each frame spent most of the top-level commit here) */
    for (uint32_t i = dev->pending_count; i-- > 0;)
        if (dev->pending[i] == in) {
            dev->pending[i] = dev->pending[--dev->pending_count];
            break;
        }
}

/* Sets an instance geometry's transforms (the top-level one or the twin): one time step, or with
 * motion its steps (shutter open .. close; Embree interpolates between them by the ray's time). */
static void set_instance_transforms(RTCGeometry g, const sy_rt_instance_data *in)
{
    uint32_t n = in->motion ? in->motion_steps : 1u;
    rtcSetGeometryTimeStepCount(g, n);
    rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT4X4_COLUMN_MAJOR, in->xf);
    for (uint32_t k = 1; k < n; ++k) rtcSetGeometryTransform(g, k, RTC_FORMAT_FLOAT4X4_COLUMN_MAJOR, sy_rt_instance_step(in, k));
}

/* A baked instance's world-space vertices of time steps 1 .. motion_steps - 1 (motion), or none (one
 * time step; Embree drops the buffers with the steps). */
static void bake_motion(sy_rt_instance_data *in)
{
    if (!in->motion || in->baked_steps != in->motion_steps) { /* the steps' buffers made anew below */
        rtcSetGeometryTimeStepCount(in->geom, 1u);
        memset(in->baked_pos, 0, sizeof in->baked_pos);
        in->baked_steps = 0;
    }
    if (!in->motion) return;
    const sy_rt_mesh_data *m = in->mesh;
    uint32_t n = in->motion_steps;
    rtcSetGeometryTimeStepCount(in->geom, n);
    for (uint32_t k = 1; k < n; ++k) {
        if (!in->baked_pos[k])
            in->baked_pos[k] = rtcSetNewGeometryBuffer(in->geom, RTC_BUFFER_TYPE_VERTEX, k, RTC_FORMAT_FLOAT3,
                                                       3 * sizeof(float), m->vertex_count);
        if (!in->baked_pos[k]) { /* out of memory (Embree reported it): shown at the open time */
            rtcSetGeometryTimeStepCount(in->geom, 1u);
            memset(in->baked_pos, 0, sizeof in->baked_pos);
            in->baked_steps = 0;
            return;
        }
    }
    in->baked_steps = n;
    for (uint32_t k = 1; k < n; ++k) {
        const float *xf = sy_rt_instance_step(in, k);
        float *out = in->baked_pos[k];
        for (uint32_t i = 0; i < m->vertex_count; ++i) {
            sy_rt_v3 p = m4_point(xf, v3_load(m->positions + 3u * i));
            out[3u * i + 0] = p.x;
            out[3u * i + 1] = p.y;
            out[3u * i + 2] = p.z;
        }
        rtcUpdateGeometryBuffer(in->geom, RTC_BUFFER_TYPE_VERTEX, k);
    }
}

/* Writes the instance's current transform into its top-level geometry (a full rebuild follows). */
static void apply_top_transform(sy_rt_instance_data *in)
{
    if (in->flags & SY_RT_INSTANCE_BAKED) {
        sy_rt_bake_positions(in);
        rtcUpdateGeometryBuffer(in->geom, RTC_BUFFER_TYPE_VERTEX, 0);
        if (in->motion || in->baked_steps) bake_motion(in);
    } else {
        set_instance_transforms(in->geom, in);
    }
    rtcCommitGeometry(in->geom);
}

/* Shows a moved instance through its twin in dyn (created on its first move). */
static sy_rt_result twin_place(sy_rt_device *dev, sy_rt_instance_data *in)
{
    if (!in->twin) {
        sy_rt_result r = sy_rt_mesh_blas(dev, in->mesh); /* baked meshes have none yet */
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
        if (!sy_rt_id_map_set(&dev->dyn_map, &dev->dyn_map_cap, in->twin_id, in)) {
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
sy_rt_result sy_rt_commit_moved(sy_rt_device *dev)
{
    bool fresh = dev->settle;
    if (dev->settle && (dev->pending_count || dev->top_fast)) dev->top_dirty = true; /* sy_rt_settle: no twins this commit */
    dev->settle = false;
    if (!dev->top_dirty && dev->pending_count) {
        uint32_t stale = dev->stale_count;
        for (uint32_t i = 0; i < dev->pending_count && !dev->top_dirty; ++i) {
            const sy_rt_instance_data *in = dev->pending[i];
            if (in->flags & SY_RT_INSTANCE_HIDDEN) continue; /* applied when it is shown again */
            if (!in->stale) stale++;
            /* a baked masked instance's BLAS has no alpha filter (update_filters) */
            if ((in->flags & SY_RT_INSTANCE_BAKED) && sy_rt_instance_masked(dev, in)) dev->top_dirty = true;
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
        /* the top scene's builder (sy_rt_set_top_fast, off by default: slower with Embree 3.13): when
         * most instances moved (an animation playing: 10^4 nodes each frame) one for frequent
         * updates (Embree's dynamic scene, LOW quality; Embree 3 cannot refit a scene of
         * instances); otherwise, and for a fresh build (sy_rt_settle: what a new device would
         * build), the usual MEDIUM one */
        bool fast = !fresh && dev->top_fast_on && dev->pending_count > 64u && dev->pending_count > dev->instances.live / 2u;
        if (fast != dev->top_fast) {
            rtcSetSceneFlags(dev->top, RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION | (fast ? RTC_SCENE_FLAG_DYNAMIC : 0));
            rtcSetSceneBuildQuality(dev->top, fast ? RTC_BUILD_QUALITY_LOW : RTC_BUILD_QUALITY_MEDIUM);
            dev->top_fast = fast;
        }
        while (dev->pending_count) {
            sy_rt_instance_data *in = dev->pending[dev->pending_count - 1];
            apply_top_transform(in);
            sy_rt_pending_remove(dev, in);
        }
    }
    return sy_rt_check_embree(dev, "commit: moved instances");
}

/* Puts a moved instance on the pending list (once); Embree sees the move at sy_rt_commit
 * (sy_rt_commit_moved). False when out of memory. */
bool sy_rt_pending_add(sy_rt_device *dev, sy_rt_instance_data *in)
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

void sy_rt_set_top_fast(sy_rt_device *dev, bool on)
{
    if (dev) dev->top_fast_on = on;
}

sy_rt_result sy_rt_settle(sy_rt_device *dev)
{
    if (!dev) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "settle: NULL device");
    /* every instance shown through a twin goes back into the top scene (sy_rt_commit_moved's full path) */
    for (uint32_t i = 0; i < dev->instances.count; ++i) {
        sy_rt_instance_data *in = dev->instances.items[i];
        if (in && in->stale && !sy_rt_pending_add(dev, in)) return FAIL(SY_RT_ERROR_OUT_OF_MEMORY, "settle: out of memory");
    }
    if (dev->pending_count || dev->stale_count || dev->top_fast) { /* top_fast: rebuilt as a fresh device builds it */
        dev->top_dirty = true;
        dev->dirty = true;
    }
    dev->settle = true;
    return SY_RT_OK;
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

sy_rt_result sy_rt_instance_get_mesh(const sy_rt_device *dev, sy_rt_instance inst, sy_rt_mesh *mesh)
{
    if (!dev || !mesh) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "instance get_mesh: NULL argument");
    const sy_rt_instance_data *in = sy_rt_pool_get(&dev->instances, inst.id);
    if (!in) return FAIL(SY_RT_ERROR_INVALID_HANDLE, "instance get_mesh: stale handle 0x%08x", inst.id);
    mesh->id = in->mesh_handle;
    return SY_RT_OK;
}

sy_rt_result sy_rt_instance_set_motion(sy_rt_device *dev, sy_rt_instance inst, const float close[16])
{
    return sy_rt_instance_set_motion_steps(dev, inst, 2u, close);
}

sy_rt_result sy_rt_instance_set_motion_steps(sy_rt_device *dev, sy_rt_instance inst, uint32_t steps, const float *later)
{
    if (!dev) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "instance set_motion: NULL device");
    sy_rt_instance_data *in = sy_rt_pool_get(&dev->instances, inst.id);
    if (!in) return FAIL(SY_RT_ERROR_INVALID_HANDLE, "instance set_motion: stale handle 0x%08x", inst.id);
    if (later && (steps < 2u || steps > SY_RT_MOTION_STEPS_MAX))
        return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "instance set_motion: %u time steps (2 .. %u)", steps, SY_RT_MOTION_STEPS_MAX);
    bool moves = false;
    for (uint32_t k = 0; later && k + 1u < steps && !moves; ++k) moves = memcmp(later + 16u * k, in->xf, sizeof in->xf) != 0;
    if (!moves) later = NULL; /* no motion */
    if (!later && !in->motion) return SY_RT_OK;
    float *mid = NULL;
    if (later) {
        for (uint32_t k = 0; k + 1u < steps; ++k) {
            float nrm[9];
            char what[64];
            snprintf(what, sizeof what, k + 2u == steps ? "instance set_motion: the close transform"
                                                        : "instance set_motion: the transform of step %u", k + 1u);
            for (int i = 0; i < 16; ++i)
                if (!isfinite(later[16u * k + (uint32_t)i]))
                    return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "%s: [%d] = %g is not finite", what, i,
                                (double)later[16u * k + (uint32_t)i]);
            sy_rt_result r = sy_rt_placement_recheck(dev, in, later + 16u * k, nrm, what, "");
            if (r != SY_RT_OK) return r;
        }
        if (steps > 2u && !(mid = malloc((size_t)(steps - 2u) * 16u * sizeof(float))))
            return FAIL(SY_RT_ERROR_OUT_OF_MEMORY, "instance set_motion: out of memory");
    }
    if (!sy_rt_pending_add(dev, in)) {
        free(mid);
        return FAIL(SY_RT_ERROR_OUT_OF_MEMORY, "instance set_motion: out of memory");
    }
    const float *close = later ? later + 16u * (steps - 2u) : NULL;
    if (close && !in->motion) dev->motion_count++;
    if (!close && in->motion) dev->motion_count--;
    in->motion = close != NULL;
    free(in->xf_mid);
    in->xf_mid = mid;
    if (mid) memcpy(mid, later, (size_t)(steps - 2u) * 16u * sizeof(float));
    in->motion_steps = close ? steps : 0u;
    if (close) memcpy(in->xf1, close, sizeof in->xf1);
    if (sy_rt_instance_emissive(dev, in)) dev->area_dirty = true;
    dev->dirty = true;
    return SY_RT_OK;
}

sy_rt_result sy_rt_motion_clear(sy_rt_device *dev)
{
    if (!dev) return FAIL(SY_RT_ERROR_INVALID_ARGUMENT, "motion clear: NULL device");
    for (uint32_t i = 0; dev->motion_count && i < dev->meshes.count; ++i) {
        sy_rt_mesh_data *m = dev->meshes.items[i];
        if (m && m->motion) sy_rt_mesh_motion_off(dev, m);
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
