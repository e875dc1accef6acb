/* sy_nrm.c — the normals back-end on Embree 3 (see sy_nrm.h): one Embree scene per mesh, instanced
 * into a top-level scene committed before a render when it changed. */
#include "sy_nrm.h"

#include <embree3/rtcore.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct nrm_mesh {
    RTCScene scene; /* NULL = free slot */
} nrm_mesh;

typedef struct nrm_instance {
    RTCGeometry geom; /* NULL = free slot */
    unsigned geom_id;
    float world[16];
    float normal_m[9]; /* inverse transpose of the upper 3x3, row-major */
} nrm_instance;

struct sy_nrm_device {
    RTCDevice rtc;
    RTCScene top;
    bool dirty;
    nrm_mesh *meshes;
    uint32_t mesh_cap;
    nrm_instance *inst;
    uint32_t inst_cap;
    sy_nrm_error_fn error;
    void *error_user;
};

/* Reports a failure to the callback (fn may be NULL) and returns code. */
static sy_nrm_result report(sy_nrm_error_fn fn, void *user, sy_nrm_result code, const char *fmt, ...)
{
    char msg[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (fn) fn(user, code, msg);
    return code;
}
#define FAIL(d, code, ...) report((d)->error, (d)->error_user, (code), __VA_ARGS__)

sy_nrm_result sy_nrm_device_create(const sy_nrm_device_desc *desc, sy_nrm_device **out)
{
    sy_nrm_device_desc dd = desc ? *desc : (sy_nrm_device_desc){0};
    *out = NULL;
    sy_nrm_device *d = calloc(1, sizeof *d);
    if (!d) return report(dd.error, dd.error_user, SY_NRM_ERROR_OUT_OF_MEMORY, "normals: out of memory");
    d->error = dd.error;
    d->error_user = dd.error_user;
    d->rtc = rtcNewDevice(NULL);
    if (!d->rtc) {
        free(d);
        return report(dd.error, dd.error_user, SY_NRM_ERROR_EMBREE, "normals: rtcNewDevice failed");
    }
    d->top = rtcNewScene(d->rtc);
    rtcCommitScene(d->top);
    *out = d;
    return SY_NRM_OK;
}

void sy_nrm_device_destroy(sy_nrm_device *d)
{
    if (!d) return;
    for (uint32_t i = 0; i < d->inst_cap; ++i)
        if (d->inst[i].geom) rtcReleaseGeometry(d->inst[i].geom);
    for (uint32_t i = 0; i < d->mesh_cap; ++i)
        if (d->meshes[i].scene) rtcReleaseScene(d->meshes[i].scene);
    rtcReleaseScene(d->top);
    rtcReleaseDevice(d->rtc);
    free(d->meshes);
    free(d->inst);
    free(d);
}

/* A free slot index in a growing array of `size`-byte items whose first field is a pointer (NULL = free). */
static int take_slot(void **arr, uint32_t *cap, size_t size, uint32_t *out)
{
    for (uint32_t i = 0; i < *cap; ++i)
        if (*(void **)((char *)*arr + i * size) == NULL) return *out = i, 0;
    uint32_t nc = *cap ? *cap * 2 : 16;
    void *p = realloc(*arr, nc * size);
    if (!p) return -1;
    memset((char *)p + *cap * size, 0, (nc - *cap) * size);
    *arr = p;
    *out = *cap;
    *cap = nc;
    return 0;
}

uint32_t sy_nrm_mesh_create(sy_nrm_device *d, const float *xyz, uint32_t nverts, const uint32_t *idx, uint32_t ntris)
{
    for (size_t i = 0; i < (size_t)ntris * 3; ++i)
        if (idx[i] >= nverts) return FAIL(d, SY_NRM_ERROR_INVALID_ARGUMENT, "normals: index %u of triangle %zu >= %u vertices", idx[i], i / 3, nverts), 0;
    uint32_t slot;
    if (take_slot((void **)&d->meshes, &d->mesh_cap, sizeof *d->meshes, &slot)) return FAIL(d, SY_NRM_ERROR_OUT_OF_MEMORY, "normals: out of memory"), 0;
    RTCScene s = rtcNewScene(d->rtc);
    if (ntris && nverts) {
        RTCGeometry g = rtcNewGeometry(d->rtc, RTC_GEOMETRY_TYPE_TRIANGLE);
        float *v = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), nverts);
        unsigned *t = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), ntris);
        if (!v || !t) {
            rtcReleaseGeometry(g);
            rtcReleaseScene(s);
            return FAIL(d, SY_NRM_ERROR_EMBREE, "normals: Embree could not allocate a mesh of %u triangles", ntris), 0;
        }
        memcpy(v, xyz, (size_t)nverts * 3 * sizeof(float));
        memcpy(t, idx, (size_t)ntris * 3 * sizeof(unsigned));
        rtcCommitGeometry(g);
        rtcAttachGeometry(s, g);
        rtcReleaseGeometry(g);
    }
    rtcCommitScene(s);
    d->meshes[slot].scene = s;
    return slot + 1;
}

void sy_nrm_mesh_release(sy_nrm_device *d, uint32_t mesh)
{
    if (mesh == 0 || mesh > d->mesh_cap || !d->meshes[mesh - 1].scene) return;
    rtcReleaseScene(d->meshes[mesh - 1].scene); /* instances keep their own reference */
    d->meshes[mesh - 1].scene = NULL;
}

/* out = inverse transpose of the upper 3x3 of a column-major 4x4, row-major (0 when singular). */
static void normal_matrix(const float *m, float *out)
{
    float a = m[0], b = m[4], c = m[8], e = m[1], f = m[5], g = m[9], h = m[2], i = m[6], j = m[10];
    float c0 = f * j - g * i, c1 = g * h - e * j, c2 = e * i - f * h;
    float det = a * c0 + b * c1 + c * c2;
    float s = fabsf(det) > 1e-30f ? 1.0f / det : 0.0f;
    /* inverse (row-major) = adj / det; its transpose's rows are the cofactor rows */
    out[0] = c0 * s, out[1] = c1 * s, out[2] = c2 * s;
    out[3] = (c * i - b * j) * s, out[4] = (a * j - c * h) * s, out[5] = (b * h - a * i) * s;
    out[6] = (b * g - c * f) * s, out[7] = (c * e - a * g) * s, out[8] = (a * f - b * e) * s;
}

uint32_t sy_nrm_instance_set(sy_nrm_device *d, uint32_t handle, uint32_t mesh, const float world[16], bool visible)
{
    nrm_instance *in;
    if (handle == 0) {
        if (mesh == 0 || mesh > d->mesh_cap || !d->meshes[mesh - 1].scene)
            return FAIL(d, SY_NRM_ERROR_INVALID_ARGUMENT, "normals: instance of unknown mesh %u", mesh), 0;
        uint32_t slot;
        if (take_slot((void **)&d->inst, &d->inst_cap, sizeof *d->inst, &slot)) return FAIL(d, SY_NRM_ERROR_OUT_OF_MEMORY, "normals: out of memory"), 0;
        in = &d->inst[slot];
        in->geom = rtcNewGeometry(d->rtc, RTC_GEOMETRY_TYPE_INSTANCE);
        rtcSetGeometryInstancedScene(in->geom, d->meshes[mesh - 1].scene);
        in->geom_id = rtcAttachGeometry(d->top, in->geom);
        handle = slot + 1;
    } else {
        if (handle > d->inst_cap || !d->inst[handle - 1].geom) return FAIL(d, SY_NRM_ERROR_INVALID_ARGUMENT, "normals: unknown instance %u", handle), 0;
        in = &d->inst[handle - 1];
    }
    memcpy(in->world, world, sizeof in->world);
    normal_matrix(world, in->normal_m);
    rtcSetGeometryTransform(in->geom, 0, RTC_FORMAT_FLOAT4X4_COLUMN_MAJOR, in->world);
    rtcSetGeometryMask(in->geom, visible ? 0xFFFFFFFFu : 0u);
    rtcCommitGeometry(in->geom);
    d->dirty = true;
    return handle;
}

void sy_nrm_instance_release(sy_nrm_device *d, uint32_t instance)
{
    if (instance == 0 || instance > d->inst_cap || !d->inst[instance - 1].geom) return;
    nrm_instance *in = &d->inst[instance - 1];
    rtcDetachGeometry(d->top, in->geom_id);
    rtcReleaseGeometry(in->geom);
    in->geom = NULL;
    d->dirty = true;
}

/* The instance whose Embree geometry id is id (NULL if none). */
static const nrm_instance *instance_of(const sy_nrm_device *d, unsigned id)
{
    for (uint32_t i = 0; i < d->inst_cap; ++i)
        if (d->inst[i].geom && d->inst[i].geom_id == id) return &d->inst[i];
    return NULL;
}

sy_nrm_result sy_nrm_render(sy_nrm_device *d, const sy_nrm_view *v, float *rgba, float *depth)
{
    if (!v->full_width || !v->full_height || v->rect_x + v->rect_w > v->full_width || v->rect_y + v->rect_h > v->full_height)
        return FAIL(d, SY_NRM_ERROR_INVALID_ARGUMENT, "normals: rectangle outside the image");
    if (d->dirty) {
        rtcCommitScene(d->top);
        d->dirty = false;
    }
    const float *m = v->camera_to_world;
    float ox = m[12], oy = m[13], oz = m[14];
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    for (uint32_t y = 0; y < v->rect_h; ++y)
        for (uint32_t x = 0; x < v->rect_w; ++x) {
            float u = v->window[0] + ((float)(v->rect_x + x) + 0.5f) / (float)v->full_width * (v->window[1] - v->window[0]);
            float w = v->window[3] - ((float)(v->rect_y + y) + 0.5f) / (float)v->full_height * (v->window[3] - v->window[2]);
            float cd[3] = {v->orthographic ? 0.0f : u, v->orthographic ? 0.0f : w, -1.0f};
            float co[3] = {v->orthographic ? u : 0.0f, v->orthographic ? w : 0.0f, 0.0f};
            struct RTCRayHit rh;
            memset(&rh, 0, sizeof rh);
            rh.ray.org_x = ox + m[0] * co[0] + m[4] * co[1];
            rh.ray.org_y = oy + m[1] * co[0] + m[5] * co[1];
            rh.ray.org_z = oz + m[2] * co[0] + m[6] * co[1];
            rh.ray.dir_x = m[0] * cd[0] + m[4] * cd[1] + m[8] * cd[2];
            rh.ray.dir_y = m[1] * cd[0] + m[5] * cd[1] + m[9] * cd[2];
            rh.ray.dir_z = m[2] * cd[0] + m[6] * cd[1] + m[10] * cd[2];
            rh.ray.tfar = INFINITY;
            rh.ray.mask = 0xFFFFFFFFu;
            rh.hit.geomID = rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
            rtcIntersect1(d->top, &ctx, &rh);
            size_t p = (size_t)y * v->rect_w + x;
            const nrm_instance *in = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID ? instance_of(d, rh.hit.instID[0]) : NULL;
            if (!in) {
                memset(rgba + p * 4, 0, 4 * sizeof(float));
                depth[p] = INFINITY;
                continue;
            }
            /* Embree reports Ng in the instanced mesh's space: to world with the normal matrix */
            const float *nm = in->normal_m;
            float n[3] = {nm[0] * rh.hit.Ng_x + nm[1] * rh.hit.Ng_y + nm[2] * rh.hit.Ng_z,
                          nm[3] * rh.hit.Ng_x + nm[4] * rh.hit.Ng_y + nm[5] * rh.hit.Ng_z,
                          nm[6] * rh.hit.Ng_x + nm[7] * rh.hit.Ng_y + nm[8] * rh.hit.Ng_z};
            float len = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
            float dn = n[0] * rh.ray.dir_x + n[1] * rh.ray.dir_y + n[2] * rh.ray.dir_z;
            float s = len > 0 ? (dn > 0 ? -1.0f : 1.0f) / len : 0.0f; /* facing the camera */
            for (int k = 0; k < 3; ++k) rgba[p * 4 + k] = 0.5f * (n[k] * s + 1.0f);
            rgba[p * 4 + 3] = 1.0f;
            depth[p] = rh.ray.tfar; /* the ray's z step in camera space is 1: t is the view depth */
        }
    return SY_NRM_OK;
}
