/* sy_gl_base.c — the rasterizer's groundwork: object pools, warnings, the 4x4 math
 * (column-major) of views, lights and shadow cameras, GL error checks and the current context. */
#include "sy_gl_internal.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

void *sy_gli_pool_get(const pool *p, uint32_t id)
{
    uint32_t i = id & IDX_MASK;
    if (!id || i >= p->count) return NULL;
    slot_head *h = sy_gli_pool_at(p, i);
    return h->id == id ? h : NULL;
}

void *sy_gli_pool_alloc(pool *p)
{
    uint32_t i = 1; /* slot 0 unused, so ids are never 0 */
    if (p->count && p->live + 1u >= p->count)
        i = p->count; /* no free slot below count (the usual case while a scene is built): append, O(1);
                       * searching made building n instances O(n^2): 17 s for 3 x 10^4 nodes */
    else
        for (; i < p->count; ++i)
            if (((slot_head *)sy_gli_pool_at(p, i))->id == 0) break;
    if (i >= IDX_MASK) return NULL;
    if (i >= p->count) {
        if (i >= p->cap) {
            uint32_t nc = p->cap ? p->cap * 2 : 64;
            void *n = realloc(p->items, p->elem * nc);
            if (!n) return NULL;
            memset((char *)n + p->elem * p->cap, 0, p->elem * (nc - p->cap));
            p->items = n;
            p->cap = nc;
        }
        p->count = i + 1;
    }
    slot_head *h = sy_gli_pool_at(p, i);
    uint32_t gen = (h->gen + 1u) & ((1u << (32 - IDX_BITS)) - 1u);
    if (!gen) gen = 1;
    memset(h, 0, p->elem);
    h->gen = gen;
    h->id = (gen << IDX_BITS) | i;
    p->live++;
    return h;
}

void sy_gli_pool_free(pool *p, void *item)
{
    slot_head *h = item;
    uint32_t gen = h->gen;
    memset(h, 0, p->elem);
    h->gen = gen;
    p->live--;
}

void sy_gli_warn(sy_gl_device *dev, const char *fmt, ...)
{
    if (!dev->log) return;
    char msg[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    dev->log(dev->log_user, msg);
}

/* >>math (column-major 4x4) */
void sy_gli_m4_mul(const float *a, const float *b, float *o)
{
    float r[16];
    for (int c = 0; c < 4; ++c)
        for (int row = 0; row < 4; ++row) {
            float s = 0.0f;
            for (int k = 0; k < 4; ++k) s += a[k * 4 + row] * b[c * 4 + k];
            r[c * 4 + row] = s;
        }
    memcpy(o, r, sizeof r);
}

bool sy_gli_m4_invert(const float *m, float *out)
{
    double inv[16], det;
    inv[0] = m[5] * m[10] * m[15] - m[5] * m[11] * m[14] - m[9] * m[6] * m[15] + m[9] * m[7] * m[14] + m[13] * m[6] * m[11] - m[13] * m[7] * m[10];
    inv[4] = -m[4] * m[10] * m[15] + m[4] * m[11] * m[14] + m[8] * m[6] * m[15] - m[8] * m[7] * m[14] - m[12] * m[6] * m[11] + m[12] * m[7] * m[10];
    inv[8] = m[4] * m[9] * m[15] - m[4] * m[11] * m[13] - m[8] * m[5] * m[15] + m[8] * m[7] * m[13] + m[12] * m[5] * m[11] - m[12] * m[7] * m[9];
    inv[12] = -m[4] * m[9] * m[14] + m[4] * m[10] * m[13] + m[8] * m[5] * m[14] - m[8] * m[6] * m[13] - m[12] * m[5] * m[10] + m[12] * m[6] * m[9];
    inv[1] = -m[1] * m[10] * m[15] + m[1] * m[11] * m[14] + m[9] * m[2] * m[15] - m[9] * m[3] * m[14] - m[13] * m[2] * m[11] + m[13] * m[3] * m[10];
    inv[5] = m[0] * m[10] * m[15] - m[0] * m[11] * m[14] - m[8] * m[2] * m[15] + m[8] * m[3] * m[14] + m[12] * m[2] * m[11] - m[12] * m[3] * m[10];
    inv[9] = -m[0] * m[9] * m[15] + m[0] * m[11] * m[13] + m[8] * m[1] * m[15] - m[8] * m[3] * m[13] - m[12] * m[1] * m[11] + m[12] * m[3] * m[9];
    inv[13] = m[0] * m[9] * m[14] - m[0] * m[10] * m[13] - m[8] * m[1] * m[14] + m[8] * m[2] * m[13] + m[12] * m[1] * m[10] - m[12] * m[2] * m[9];
    inv[2] = m[1] * m[6] * m[15] - m[1] * m[7] * m[14] - m[5] * m[2] * m[15] + m[5] * m[3] * m[14] + m[13] * m[2] * m[7] - m[13] * m[3] * m[6];
    inv[6] = -m[0] * m[6] * m[15] + m[0] * m[7] * m[14] + m[4] * m[2] * m[15] - m[4] * m[3] * m[14] - m[12] * m[2] * m[7] + m[12] * m[3] * m[6];
    inv[10] = m[0] * m[5] * m[15] - m[0] * m[7] * m[13] - m[4] * m[1] * m[15] + m[4] * m[3] * m[13] + m[12] * m[1] * m[7] - m[12] * m[3] * m[5];
    inv[14] = -m[0] * m[5] * m[14] + m[0] * m[6] * m[13] + m[4] * m[1] * m[14] - m[4] * m[2] * m[13] - m[12] * m[1] * m[6] + m[12] * m[2] * m[5];
    inv[3] = -m[1] * m[6] * m[11] + m[1] * m[7] * m[10] + m[5] * m[2] * m[11] - m[5] * m[3] * m[10] - m[9] * m[2] * m[7] + m[9] * m[3] * m[6];
    inv[7] = m[0] * m[6] * m[11] - m[0] * m[7] * m[10] - m[4] * m[2] * m[11] + m[4] * m[3] * m[10] + m[8] * m[2] * m[7] - m[8] * m[3] * m[6];
    inv[11] = -m[0] * m[5] * m[11] + m[0] * m[7] * m[9] + m[4] * m[1] * m[11] - m[4] * m[3] * m[9] - m[8] * m[1] * m[7] + m[8] * m[3] * m[5];
    inv[15] = m[0] * m[5] * m[10] - m[0] * m[6] * m[9] - m[4] * m[1] * m[10] + m[4] * m[2] * m[9] + m[8] * m[1] * m[6] - m[8] * m[2] * m[5];
    det = m[0] * inv[0] + m[1] * inv[4] + m[2] * inv[8] + m[3] * inv[12];
    if (!(fabs(det) > 1e-30) || !isfinite(det)) return false;
    for (int i = 0; i < 16; ++i) out[i] = (float)(inv[i] / det);
    return true;
}

void sy_gli_v3_norm(float *v)
{
    float l = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (l > 0.0f)
        for (int i = 0; i < 3; ++i) v[i] /= l;
}

void sy_gli_cross3(const float *a, const float *b, float *o)
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

/* How a material casts shadows in the shadow maps (render_shadow_layer). */
int sy_gli_caster_kind(const sy_gl_material_desc *d)
{
    if (d->emissive[0] > 0.0f || d->emissive[1] > 0.0f || d->emissive[2] > 0.0f) return CASTER_NONE;
    if (d->transmission * (1.0f - d->metallic) >= 0.5f) return CASTER_NONE;
    return d->alpha_mode == SY_GL_ALPHA_OPAQUE ? CASTER_OPAQUE : CASTER_MASKED;
}

/* A depth texture array compared in the shader (hardware PCF); outside it reads as lit. */
GLuint sy_gli_shadow_array(const sy_gl_fns *gl, uint32_t size, uint32_t layers)
{
    GLuint t = 0;
    gl->GenTextures(1, &t);
    gl->BindTexture(GL_TEXTURE_2D_ARRAY, t);
    gl->TexImage3D(GL_TEXTURE_2D_ARRAY, 0, GL_DEPTH_COMPONENT32F, (GLsizei)size, (GLsizei)size, (GLsizei)layers, 0,
                   GL_DEPTH_COMPONENT, GL_FLOAT, NULL);
    gl->TexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    gl->TexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    gl->TexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_BORDER);
    gl->TexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_BORDER);
    static const float border[4] = {1, 1, 1, 1};
    gl->TexParameterfv(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_BORDER_COLOR, border);
    gl->TexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    gl->TexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
    return t;
}

void sy_gli_cube_face_view(const float *eye, int f, float *view)
{
    const float(*b)[3] = sy_gli_cube_faces[f];
    float m[16] = {b[0][0], b[1][0], -b[2][0], 0, b[0][1], b[1][1], -b[2][1], 0, b[0][2], b[1][2], -b[2][2], 0, 0, 0, 0, 1};
    for (int i = 0; i < 3; ++i) m[12 + i] = -(m[i] * eye[0] + m[4 + i] * eye[1] + m[8 + i] * eye[2]);
    memcpy(view, m, sizeof m);
}

/* A depth cube map compared in the shader (hardware PCF, seamless across faces). */
GLuint sy_gli_shadow_cube(const sy_gl_fns *gl, uint32_t size)
{
    GLuint t = 0;
    gl->GenTextures(1, &t);
    gl->BindTexture(GL_TEXTURE_CUBE_MAP, t);
    for (int f = 0; f < 6; ++f)
        gl->TexImage2D(GL_TEXTURE_CUBE_MAP_POSITIVE_X + (GLenum)f, 0, GL_DEPTH_COMPONENT32F, (GLsizei)size, (GLsizei)size, 0,
                       GL_DEPTH_COMPONENT, GL_FLOAT, NULL);
    gl->TexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    gl->TexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    gl->TexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    gl->TexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    gl->TexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
    gl->TexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    gl->TexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
    return t;
}

void sy_gli_look_along(const float *eye, const float *dir, float *view)
{
    float z[3] = {-dir[0], -dir[1], -dir[2]}, up[3] = {0, 1, 0}, x[3], y[3];
    sy_gli_v3_norm(z);
    if (fabsf(z[1]) > 0.99f) {
        up[1] = 0;
        up[2] = 1;
    }
    sy_gli_cross3(up, z, x);
    sy_gli_v3_norm(x);
    sy_gli_cross3(z, x, y);
    float m[16] = {x[0], y[0], z[0], 0, x[1], y[1], z[1], 0, x[2], y[2], z[2], 0, 0, 0, 0, 1};
    for (int i = 0; i < 3; ++i) m[12 + i] = -(m[i] * eye[0] + m[4 + i] * eye[1] + m[8 + i] * eye[2]);
    memcpy(view, m, sizeof m);
}

/* Projection from an image-plane window (tangent space at distance 1, or camera units for ortho). */
void sy_gli_projection(bool ortho, double l, double r, double b, double t, double n, double f, float *p)
{
    memset(p, 0, 16 * sizeof *p);
    if (ortho) {
        p[0] = (float)(2.0 / (r - l));
        p[12] = (float)(-(r + l) / (r - l));
        p[5] = (float)(2.0 / (t - b));
        p[13] = (float)(-(t + b) / (t - b));
        p[10] = (float)(-2.0 / (f - n));
        p[14] = (float)(-(f + n) / (f - n));
        p[15] = 1.0f;
        return;
    }
    p[0] = (float)(2.0 / (r - l));
    p[8] = (float)((r + l) / (r - l));
    p[5] = (float)(2.0 / (t - b));
    p[9] = (float)((t + b) / (t - b));
    p[11] = -1.0f;
    if (f > 0.0) {
        p[10] = (float)(-(f + n) / (f - n));
        p[14] = (float)(-2.0 * f * n / (f - n));
    } else { /* infinite far plane */
        p[10] = -1.0f;
        p[14] = (float)(-2.0 * n);
    }
}

void sy_gli_count_buffer(sy_gl_device *dev, bool uniform, size_t bytes)
{
    if (uniform) {
        dev->counts.uniform_buffer_uploads++;
        dev->counts.uniform_bytes += bytes;
    } else {
        dev->counts.vertex_buffer_uploads++;
        dev->counts.vertex_bytes += bytes;
    }
}

sy_gl_result sy_gli_gl_check(sy_gl_device *dev, const char *where, sy_gl_report *rep)
{
    GLenum e = dev->gl->GetError();
    if (e == GL_NO_ERROR) return SY_GL_OK;
    while (dev->gl->GetError() != GL_NO_ERROR) {
    }
    return sy_gli_fail(rep, e == GL_OUT_OF_MEMORY ? SY_GL_ERROR_OUT_OF_MEMORY : SY_GL_ERROR_GL,
                "%s: OpenGL error 0x%04x (%s)", where, (unsigned)e, sy_gl_provider_name(sy_gl_context_provider(dev->ctx)));
}

static double seconds(clockid_t clock)
{
    struct timespec ts;
    clock_gettime(clock, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void sy_gli_profile_mark(sy_gl_device *dev, bool start, double t[2])
{
    t[0] = t[1] = 0.0;
    if (!dev->profile) return;
    dev->gl->Finish();
    double now[2] = {seconds(CLOCK_MONOTONIC), seconds(CLOCK_PROCESS_CPUTIME_ID)};
    for (int k = 0; k < 2; ++k) {
        if (!start) t[k] = now[k] - dev->profile_t[k];
        dev->profile_t[k] = now[k];
    }
}

double sy_gli_profile_thread(const sy_gl_device *dev)
{
    return dev->profile ? seconds(CLOCK_THREAD_CPUTIME_ID) : 0.0;
}

sy_gl_result sy_gli_current(sy_gl_device *dev, sy_gl_report *rep)
{
    if (!sy_gl_context_make_current(dev->ctx))
        return sy_gli_fail(rep, SY_GL_ERROR_NO_CONTEXT, "%s: cannot make the GL context sy_gli_current",
                    sy_gl_provider_name(sy_gl_context_provider(dev->ctx)));
    return SY_GL_OK;
}

/* Geometry moved, appeared or vanished: shadow maps (and their frusta, fitted to the scene bounds)
 * must be redrawn, which happens with the lights-block update at the next frame. Without
 * shadow-casting lights nothing needs to be redone. */
void sy_gli_geometry_changed(sy_gl_device *dev)
{
    if (dev->shadow_maps > 0) dev->lights_dirty = true;
    dev->probes_dirty = true;
}

/* The six planes (inside: dot(p.xyz, x) + p.w >= 0) of a column-major view-sy_gli_projection matrix. */
void sy_gli_frustum_planes(const float *m, float planes[6][4])
{
    for (int i = 0; i < 3; ++i)
        for (int s = 0; s < 2; ++s) {
            float *p = planes[2 * i + s];
            for (int c = 0; c < 4; ++c) p[c] = m[4 * c + 3] + (s ? -m[4 * c + i] : m[4 * c + i]);
            float len = sqrtf(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]); /* unit normals: distances in metres */
            if (len > 0.0f)
                for (int c = 0; c < 4; ++c) p[c] /= len;
        }
}

/* World-space bounding sphere of an instance: centre into c, radius returned; *scale = the largest
 * axis scale of its model matrix. */
float sy_gli_world_sphere(const inst_o *in, const mesh_o *m, float c[3], float *scale)
{
    float s2 = 0.0f;
    for (int a = 0; a < 3; ++a) {
        c[a] = in->model[12 + a];
        for (int k = 0; k < 3; ++k) c[a] += in->model[4 * k + a] * m->centre[k];
        float l2 = in->model[4 * a] * in->model[4 * a] + in->model[4 * a + 1] * in->model[4 * a + 1] +
                   in->model[4 * a + 2] * in->model[4 * a + 2];
        s2 = fmaxf(s2, l2);
    }
    *scale = sqrtf(s2);
    return m->radius * *scale;
}

bool sy_gli_sphere_outside(const float planes[6][4], const float c[3], float r)
{
    for (int i = 0; i < 6; ++i) {
        const float *p = planes[i]; /* unit normal (sy_gli_frustum_planes) */
        if (p[0] * c[0] + p[1] * c[1] + p[2] * c[2] + p[3] < -r) return true;
    }
    return false;
}

const float sy_gli_cube_faces[6][3][3] = {
    {{0, 0, -1}, {0, -1, 0}, {1, 0, 0}},  {{0, 0, 1}, {0, -1, 0}, {-1, 0, 0}}, {{1, 0, 0}, {0, 0, 1}, {0, 1, 0}},
    {{1, 0, 0}, {0, 0, -1}, {0, -1, 0}}, {{1, 0, 0}, {0, -1, 0}, {0, 0, 1}},  {{-1, 0, 0}, {0, -1, 0}, {0, 0, -1}}};
