/* sy_deform.c — skinning and morph targets on the CPU (see sy_deform.h). */
#include "sy_deform.h"

#include <math.h>
#include <pthread.h>
#include <string.h>
#include <unistd.h>

bool sy_deform_has_data(const sy_primitive *p)
{
    return sy_primitive_target_count(p) > 0 || sy_primitive_influences(p) > 0;
}

static void normalize3(float *v)
{
    float l = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (l > 0.0f && isfinite(l)) v[0] /= l, v[1] /= l, v[2] /= l;
}

/* A direction (normal, tangent) through the 3x3 part of a skinning matrix m (column-major 3x4),
 * normalised. */
static void skin_direction(const float m[12], float *a)
{
    float ax = a[0], ay = a[1], az = a[2];
    a[0] = m[0] * ax + m[3] * ay + m[6] * az;
    a[1] = m[1] * ax + m[4] * ay + m[7] * az;
    a[2] = m[2] * ax + m[5] * ay + m[8] * az;
    normalize3(a);
}

/* One vertex range [v0, v1) of a deformation; false when a position leaves SY_COORD_MAX. */
typedef struct deform_job {
    const sy_deform_input *in;
    float *pos, *nrm, *tan;
    uint32_t v0, v1;
    sy_bounds bounds;
    bool ok;
} deform_job;

static void deform_range(deform_job *j)
{
    const sy_deform_input *in = j->in;
    const sy_primitive *p = in->primitive;
    uint32_t nv = sy_primitive_vertex_count(p), v0 = j->v0, v1 = j->v1;
    float *pos = j->pos, *nrm = j->nrm, *tan = j->tan;
    const float *p0 = sy_blob_data(p->positions), *n0 = p->normals && nrm ? sy_blob_data(p->normals) : NULL;
    const float *t0 = p->tangents && tan ? sy_blob_data(p->tangents) : NULL;
    memcpy(pos + 3 * (size_t)v0, p0 + 3 * (size_t)v0, sizeof(float) * 3 * (size_t)(v1 - v0));
    if (n0) memcpy(nrm + 3 * (size_t)v0, n0 + 3 * (size_t)v0, sizeof(float) * 3 * (size_t)(v1 - v0));
    if (t0) memcpy(tan + 4 * (size_t)v0, t0 + 4 * (size_t)v0, sizeof(float) * 4 * (size_t)(v1 - v0));
    /* morph targets: target after target, so each delta array is read in order */
    uint32_t nt = sy_primitive_target_count(p);
    if (nt && in->weights) {
        uint32_t use = in->weight_count < nt ? in->weight_count : nt;
        const float *dp = p->target_positions ? sy_blob_data(p->target_positions) : NULL;
        const float *dn = n0 && p->target_normals ? sy_blob_data(p->target_normals) : NULL;
        const float *dt = t0 && p->target_tangents ? sy_blob_data(p->target_tangents) : NULL;
        size_t per = 3 * (size_t)nv;
        for (uint32_t t = 0; t < use; ++t) {
            float w = in->weights[t];
            if (w == 0.0f) continue;
            if (dp)
                for (size_t k = 3 * (size_t)v0; k < 3 * (size_t)v1; ++k) pos[k] += w * dp[t * per + k];
            if (dn)
                for (size_t k = 3 * (size_t)v0; k < 3 * (size_t)v1; ++k) nrm[k] += w * dn[t * per + k];
            if (dt)
                for (size_t v = v0; v < v1; ++v)
                    for (int c = 0; c < 3; ++c) tan[4 * v + c] += w * dt[t * per + 3 * v + c];
        }
        if (n0)
            for (uint32_t v = v0; v < v1; ++v) normalize3(&nrm[3 * v]);
        if (t0)
            for (uint32_t v = v0; v < v1; ++v) normalize3(&tan[4 * v]);
    }
    /* skin */
    uint32_t inf = sy_primitive_influences(p);
    if (inf && in->joints && in->joint_count) {
        const uint32_t *jj = sy_blob_data(p->joints);
        const float *ww = sy_blob_data(p->weights);
        for (uint32_t v = v0; v < v1; ++v) {
            float m[12] = {0}; /* the upper 3 rows of sum s_k J[j_k], column-major 3x4 */
            float sum = 0.0f;
            for (uint32_t k = 0; k < inf; ++k) {
                float s = ww[(size_t)inf * v + k];
                uint32_t jn = jj[(size_t)inf * v + k];
                if (s == 0.0f || jn >= in->joint_count) continue;
                const float *J = in->joints[jn].m;
                for (int c = 0; c < 4; ++c)
                    for (int r = 0; r < 3; ++r) m[3 * c + r] += s * J[4 * c + r];
                sum += s;
            }
            if (sum == 0.0f) continue;
            float *q = &pos[3 * v], x = q[0], y = q[1], z = q[2];
            q[0] = m[0] * x + m[3] * y + m[6] * z + m[9];
            q[1] = m[1] * x + m[4] * y + m[7] * z + m[10];
            q[2] = m[2] * x + m[5] * y + m[8] * z + m[11];
            if (n0) skin_direction(m, &nrm[3 * v]);
            if (t0) skin_direction(m, &tan[4 * v]);
        }
    }
    j->bounds = sy_bounds_empty();
    j->ok = true;
    for (uint32_t v = v0; v < v1 && j->ok; ++v) {
        if (!sy_coords_in_range(&pos[3 * v], 3)) j->ok = false;
        else sy_bounds_add_point(&j->bounds, &pos[3 * v]);
    }
    if (n0)
        for (size_t k = 3 * (size_t)v0; k < 3 * (size_t)v1; ++k)
            if (!isfinite(nrm[k])) nrm[k] = 0.0f;
    if (t0)
        for (size_t k = 4 * (size_t)v0; k < 4 * (size_t)v1; ++k)
            if (!isfinite(tan[k])) tan[k] = 0.0f;
}

static void *deform_thread(void *arg)
{
    deform_range(arg);
    return NULL;
}

void sy_deform_texcoords(const sy_deform_input *in, float *uv)
{
    const sy_primitive *p = in->primitive;
    uint32_t nv = sy_primitive_vertex_count(p), nt = sy_primitive_target_count(p);
    if (!p->texcoords0) return;
    memcpy(uv, sy_blob_data(p->texcoords0), sizeof(float) * 2 * (size_t)nv);
    if (!p->target_texcoords0 || !in->weights) return;
    const float *d = sy_blob_data(p->target_texcoords0);
    uint32_t use = in->weight_count < nt ? in->weight_count : nt;
    size_t per = 2 * (size_t)nv;
    for (uint32_t t = 0; t < use; ++t) {
        float w = in->weights[t];
        if (w == 0.0f || !isfinite(w)) continue;
        for (size_t k = 0; k < per; ++k) uv[k] += w * d[t * per + k];
    }
}

bool sy_deform_primitive(const sy_deform_input *in, float *pos, float *nrm, float *tan, sy_bounds *bounds_out)
{
    uint32_t nv = sy_primitive_vertex_count(in->primitive);
    long cpus = sysconf(_SC_NPROCESSORS_ONLN);
    uint32_t n = nv / SY_DEFORM_VERTICES_PER_THREAD;
    if (cpus > 0 && n > (uint32_t)cpus) n = (uint32_t)cpus;
    if (n > SY_DEFORM_MAX_THREADS) n = SY_DEFORM_MAX_THREADS;
    if (in->max_threads && n > in->max_threads) n = in->max_threads;
    if (n < 1) n = 1;
    deform_job jobs[SY_DEFORM_MAX_THREADS];
    pthread_t th[SY_DEFORM_MAX_THREADS];
    bool started[SY_DEFORM_MAX_THREADS] = {false};
    for (uint32_t k = 0; k < n; ++k)
        jobs[k] = (deform_job){in, pos, nrm, tan, (uint32_t)((uint64_t)nv * k / n), (uint32_t)((uint64_t)nv * (k + 1) / n),
                               {{0}, {0}}, false};
    for (uint32_t k = 1; k < n; ++k) started[k] = pthread_create(&th[k], NULL, deform_thread, &jobs[k]) == 0;
    deform_range(&jobs[0]);
    for (uint32_t k = 1; k < n; ++k) {
        if (started[k]) pthread_join(th[k], NULL);
        else deform_range(&jobs[k]); /* no thread: this one does it */
    }
    sy_bounds b = sy_bounds_empty();
    bool ok = true;
    for (uint32_t k = 0; k < n; ++k) {
        ok = ok && jobs[k].ok;
        sy_bounds_add_bounds(&b, &jobs[k].bounds);
    }
    if (ok && bounds_out) *bounds_out = b;
    return ok;
}
