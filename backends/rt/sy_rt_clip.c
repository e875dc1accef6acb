/* sy_rt_clip.c — what a trace filters and caps: the context filter of every trace while an instance
 * is stale or section planes cut (it hides the top scene's stale copies of moved instances and hits
 * on a plane's removed side) and the section caps' test (sy_rt_clip_cap), both declared in
 * sy_rt_device.h. Reads the device's instances; calls no other rt module. */
#include "sy_rt_scene.h"

#include <string.h>

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
        if (ds > 0.0f) t_enter = sy_rt_maxf(-s0 / ds, t_enter); /* crosses from the cut side into the kept one */
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
