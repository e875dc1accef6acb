/* sy_demo.c — procedural demo and benchmark scenes (see sy_demo.h). */
#include "sy_demo.h"

#include "sy_look.h"
#include "sy_world.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

sy_result sy_demo_sphere(sy_scene *s, float radius, uint32_t slices, uint32_t stacks, sy_material mat, sy_mesh *out,
                         sy_error *err)
{
    if (slices < 3 || stacks < 2) return sy_error_set(err, SY_ERR_INVALID_ARGUMENT, "sphere: too few segments");
    uint32_t nv = (slices + 1) * (stacks + 1);
    uint32_t nt = 2 * slices * (stacks - 1);
    float *pos = malloc(sizeof(float) * 3 * nv), *nrm = malloc(sizeof(float) * 3 * nv);
    float *uv = malloc(sizeof(float) * 2 * nv);
    uint32_t *idx = malloc(sizeof(uint32_t) * 3 * nt);
    sy_blob *bp = NULL, *bn = NULL, *bu = NULL, *bi = NULL;
    sy_result r = SY_OK;
    if (!pos || !nrm || !uv || !idx) {
        r = sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "sphere: out of memory");
        goto done;
    }
    for (uint32_t j = 0; j <= stacks; ++j) {
        float v = (float)j / (float)stacks, th = v * 3.14159265f;
        for (uint32_t i = 0; i <= slices; ++i) {
            float u = (float)i / (float)slices, ph = u * 6.2831853f;
            uint32_t k = j * (slices + 1) + i;
            float n[3] = {sinf(th) * cosf(ph), cosf(th), -sinf(th) * sinf(ph)};
            memcpy(nrm + 3 * k, n, sizeof n);
            for (int c = 0; c < 3; ++c) pos[3 * k + c] = n[c] * radius;
            uv[2 * k] = u;
            uv[2 * k + 1] = v;
        }
    }
    uint32_t t = 0;
    for (uint32_t j = 0; j < stacks; ++j)
        for (uint32_t i = 0; i < slices; ++i) {
            uint32_t a = j * (slices + 1) + i, b = a + slices + 1;
            if (j != 0) {
                idx[3 * t] = a, idx[3 * t + 1] = b, idx[3 * t + 2] = a + 1;
                t++;
            }
            if (j != stacks - 1) {
                idx[3 * t] = a + 1, idx[3 * t + 1] = b, idx[3 * t + 2] = b + 1;
                t++;
            }
        }
    if ((r = sy_blob_create_take(pos, sizeof(float) * 3 * nv, &bp, err)) != SY_OK) goto done;
    pos = NULL;
    if ((r = sy_blob_create_take(nrm, sizeof(float) * 3 * nv, &bn, err)) != SY_OK) goto done;
    nrm = NULL;
    if ((r = sy_blob_create_take(uv, sizeof(float) * 2 * nv, &bu, err)) != SY_OK) goto done;
    uv = NULL;
    if ((r = sy_blob_create_take(idx, sizeof(uint32_t) * 3 * t, &bi, err)) != SY_OK) goto done;
    idx = NULL;
    sy_primitive p = {.positions = bp, .normals = bn, .texcoords0 = bu, .indices = bi, .material = mat};
    if ((r = sy_mesh_create(s, "sphere", out, err)) == SY_OK) r = sy_mesh_set_primitives(s, *out, &p, 1, err);
done:
    free(pos);
    free(nrm);
    free(uv);
    free(idx);
    sy_blob_release(bp);
    sy_blob_release(bn);
    sy_blob_release(bu);
    sy_blob_release(bi);
    return r;
}

/* A quad in the XZ plane at y = 0, normal +Y (or -Y when down), size sx x sz centred at origin. */
static sy_result quad(sy_scene *s, const char *name, float sx, float sz, bool down, sy_material mat, sy_mesh *out,
                      sy_error *err)
{
    float hx = sx * 0.5f, hz = sz * 0.5f, ny = down ? -1.0f : 1.0f;
    float pos[12] = {-hx, 0, -hz, hx, 0, -hz, hx, 0, hz, -hx, 0, hz};
    float nrm[12] = {0, ny, 0, 0, ny, 0, 0, ny, 0, 0, ny, 0};
    float uv[8] = {0, 0, 1, 0, 1, 1, 0, 1};
    uint32_t up_idx[6] = {0, 2, 1, 0, 3, 2}, down_idx[6] = {0, 1, 2, 0, 2, 3};
    sy_blob *bp = NULL, *bn = NULL, *bu = NULL, *bi = NULL;
    sy_result r;
    if ((r = sy_blob_create_copy(pos, sizeof pos, &bp, err)) || (r = sy_blob_create_copy(nrm, sizeof nrm, &bn, err)) ||
        (r = sy_blob_create_copy(uv, sizeof uv, &bu, err)) ||
        (r = sy_blob_create_copy(down ? down_idx : up_idx, sizeof up_idx, &bi, err)))
        goto done;
    sy_primitive p = {.positions = bp, .normals = bn, .texcoords0 = bu, .indices = bi, .material = mat};
    if ((r = sy_mesh_create(s, name, out, err)) == SY_OK) r = sy_mesh_set_primitives(s, *out, &p, 1, err);
done:
    sy_blob_release(bp);
    sy_blob_release(bn);
    sy_blob_release(bu);
    sy_blob_release(bi);
    return r;
}

static sy_result box(sy_scene *s, float h, sy_material mat, sy_mesh *out, sy_error *err)
{
    /* 6 faces x 4 vertices with flat normals */
    static const float n[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    float pos[72], nrm[72];
    uint32_t idx[36];
    for (int f = 0; f < 6; ++f) {
        const float *N = n[f];
        float u[3] = {N[1] != 0 ? 1.0f : 0.0f, 0, 0}, v[3];
        if (N[1] == 0) u[0] = 0, u[1] = 1;
        /* v = N x u, u = v x N: an orthonormal frame on the face */
        v[0] = N[1] * u[2] - N[2] * u[1], v[1] = N[2] * u[0] - N[0] * u[2], v[2] = N[0] * u[1] - N[1] * u[0];
        static const float cs[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
        for (int k = 0; k < 4; ++k)
            for (int c = 0; c < 3; ++c) {
                pos[(f * 4 + k) * 3 + c] = h * (N[c] + cs[k][0] * u[c] + cs[k][1] * v[c]);
                nrm[(f * 4 + k) * 3 + c] = N[c];
            }
        /* counter-clockwise seen from outside: (u, v, N) right-handed, so 0-1-2 is CCW about N */
        uint32_t b = (uint32_t)f * 4;
        uint32_t tri[6] = {b, b + 1, b + 2, b, b + 2, b + 3};
        memcpy(idx + f * 6, tri, sizeof tri);
    }
    sy_blob *bp = NULL, *bn = NULL, *bi = NULL;
    sy_result r;
    if ((r = sy_blob_create_copy(pos, sizeof pos, &bp, err)) || (r = sy_blob_create_copy(nrm, sizeof nrm, &bn, err)) ||
        (r = sy_blob_create_copy(idx, sizeof idx, &bi, err)))
        goto done;
    sy_primitive p = {.positions = bp, .normals = bn, .indices = bi, .material = mat};
    if ((r = sy_mesh_create(s, "box", out, err)) == SY_OK) r = sy_mesh_set_primitives(s, *out, &p, 1, err);
done:
    sy_blob_release(bp);
    sy_blob_release(bn);
    sy_blob_release(bi);
    return r;
}

static sy_result material(sy_scene *s, const char *name, float r, float g, float b, float metallic, float roughness,
                          float transmission, const float *emissive, sy_material *out, sy_error *err)
{
    sy_material_data d = *(const sy_material_data *)sy_object_defaults(SY_TYPE_MATERIAL);
    d.name = (char *)name;
    d.base_color[0] = r, d.base_color[1] = g, d.base_color[2] = b;
    d.metallic = metallic;
    d.roughness = roughness;
    d.transmission = transmission;
    if (emissive) memcpy(d.emissive, emissive, sizeof d.emissive);
    sy_result res = sy_material_create(s, name, out, err);
    if (res == SY_OK) res = sy_material_set(s, *out, &d, err);
    return res;
}

static sy_result place(sy_scene *s, sy_node parent, const char *name, sy_mesh mesh, float x, float y, float z,
                       sy_node *out, sy_error *err)
{
    static const float q[4] = {0, 0, 0, 1}, one[3] = {1, 1, 1};
    float t[3] = {x, y, z};
    sy_node n;
    sy_result r;
    if ((r = sy_node_create(s, name, &n, err)) || (r = sy_node_set_trs(s, n, t, q, one, err)) ||
        (mesh.id && (r = sy_node_set_mesh(s, n, mesh, err))) ||
        (r = sy_node_set_flags(s, n, SY_NODE_VISIBLE | SY_NODE_STATIC, err)) ||
        (r = sy_node_add_child(s, parent, n, err)))
        return r;
    if (out) *out = n;
    return SY_OK;
}

/* A clear-sky lat-long environment (row 0 = up, sy_look.h's convention): deep blue at the zenith,
 * pale haze at the horizon, a soft warm glow towards the sun (no disc: the demo has its own
 * lights and a disc would only add noise), a dark ground below. Linear radiance. */
static sy_result sky_texture(sy_scene *s, sy_texture *out, sy_error *err)
{
    enum { W = 256, H = 128 };
    float *px = malloc(sizeof(float) * 3 * W * H);
    if (!px) return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "demo sky: out of memory");
    static const float zenith[3] = {0.10f, 0.20f, 0.50f}, horizon[3] = {0.55f, 0.62f, 0.72f},
                       ground[3] = {0.12f, 0.11f, 0.10f}, sun_dir[3] = {0.48f, 0.60f, 0.64f};
    for (int j = 0; j < H; ++j)
        for (int i = 0; i < W; ++i) {
            float d[3];
            sy_look_latlong_dir(((float)i + 0.5f) / W, ((float)j + 0.5f) / H, d);
            float *p = px + 3 * (j * W + i);
            float up = d[1];
            float t = up > 0.0f ? powf(up, 0.5f) : 0.0f;
            float cs = d[0] * sun_dir[0] + d[1] * sun_dir[1] + d[2] * sun_dir[2];
            float glow = cs > 0.0f ? 0.8f * powf(cs, 8.0f) : 0.0f;
            for (int k = 0; k < 3; ++k) {
                float skyc = horizon[k] + (zenith[k] - horizon[k]) * t + glow * (k == 0 ? 1.0f : k == 1 ? 0.85f : 0.6f);
                float b = up < -0.02f ? 0.0f : up > 0.02f ? 1.0f : (up + 0.02f) / 0.04f;
                p[k] = ground[k] + (skyc - ground[k]) * b;
            }
        }
    return sy_world_texture_take(s, "sky", px, W, H, out, err);
}

sy_result sy_demo_build(sy_scene *s, sy_demo_info *out, sy_error *err)
{
    sy_result r;
    sy_material m_floor, m_red, m_mirror, m_glass, m_gold, m_light;
    static const float light_e[3] = {12.0f, 11.0f, 9.5f};
    if ((r = material(s, "floor", 0.7f, 0.7f, 0.68f, 0, 0.9f, 0, NULL, &m_floor, err)) ||
        (r = material(s, "red", 0.75f, 0.12f, 0.1f, 0, 0.8f, 0, NULL, &m_red, err)) ||
        (r = material(s, "mirror", 0.95f, 0.95f, 0.95f, 1, 0, 0, NULL, &m_mirror, err)) ||
        (r = material(s, "glass", 1, 1, 1, 0, 0, 1, NULL, &m_glass, err)) ||
        (r = material(s, "gold", 1.0f, 0.76f, 0.33f, 1, 0, 0, NULL, &m_gold, err)) ||
        (r = material(s, "panel", 0, 0, 0, 0, 1, 0, light_e, &m_light, err)))
        return r;
    sy_mesh floor_m, panel_m, s_red, s_mirror, s_glass, box_m;
    if ((r = quad(s, "floor", 12, 12, false, m_floor, &floor_m, err)) ||
        (r = quad(s, "panel", 1.6f, 1.0f, true, m_light, &panel_m, err)) ||
        (r = sy_demo_sphere(s, 0.5f, 64, 32, m_red, &s_red, err)) ||
        (r = sy_demo_sphere(s, 0.5f, 64, 32, m_mirror, &s_mirror, err)) ||
        (r = sy_demo_sphere(s, 0.5f, 64, 32, m_glass, &s_glass, err)) || (r = box(s, 0.3f, m_gold, &box_m, err)))
        return r;
    sy_node root;
    if ((r = sy_node_create(s, "demo", &root, err))) return r;
    if ((r = place(s, root, "floor", floor_m, 0, 0, 0, NULL, err)) ||
        (r = place(s, root, "panel", panel_m, 0, 3.2f, 0.2f, NULL, err)) ||
        (r = place(s, root, "red sphere", s_red, -1.25f, 0.5f, 0.1f, NULL, err)) ||
        (r = place(s, root, "mirror sphere", s_mirror, 0.0f, 0.5f, -0.5f, NULL, err)) ||
        (r = place(s, root, "glass sphere", s_glass, 1.2f, 0.5f, 0.5f, NULL, err)) ||
        (r = place(s, root, "gold box", box_m, -0.2f, 0.3f, 1.0f, NULL, err)))
        return r;
    /* a warm point light */
    sy_light lamp;
    sy_light_data ld = *(const sy_light_data *)sy_object_defaults(SY_TYPE_LIGHT);
    ld.color[0] = 1.0f, ld.color[1] = 0.85f, ld.color[2] = 0.6f;
    ld.intensity = 6.0f;
    sy_node lamp_node;
    if ((r = sy_light_create(s, "lamp", &lamp, err)) || (r = sy_light_set(s, lamp, &ld, err)) ||
        (r = place(s, root, "lamp", (sy_mesh){0}, 2.5f, 2.5f, 2.0f, &lamp_node, err)) ||
        (r = sy_node_set_light(s, lamp_node, lamp, err)))
        return r;
    /* camera at (0, 1.6, 5.2) looking slightly down at the spheres */
    sy_camera cam;
    sy_camera_data cd = *(const sy_camera_data *)sy_object_defaults(SY_TYPE_CAMERA);
    cd.yfov = 0.70f;
    cd.znear = 0.05f;
    sy_node cam_node;
    float pitch = -0.2f;
    float q[4] = {sinf(pitch * 0.5f), 0, 0, cosf(pitch * 0.5f)}, t[3] = {0, 1.6f, 5.2f}, one[3] = {1, 1, 1};
    if ((r = sy_camera_create(s, "camera", &cam, err)) || (r = sy_camera_set(s, cam, &cd, err)) ||
        (r = sy_node_create(s, "camera", &cam_node, err)) || (r = sy_node_set_trs(s, cam_node, t, q, one, err)) ||
        (r = sy_node_set_camera(s, cam_node, cam, err)) || (r = sy_node_add_child(s, root, cam_node, err)))
        return r;
    /* the world: a clear sky as the environment light, seen behind the scene */
    sy_background bg;
    sy_texture sky;
    sy_background_data bd = *(const sy_background_data *)sy_object_defaults(SY_TYPE_BACKGROUND);
    if ((r = sky_texture(s, &sky, err))) return r;
    bd.environment = sky;
    bd.intensity = 1.0f;
    if ((r = sy_background_create(s, "sky", &bg, err)) || (r = sy_background_set(s, bg, &bd, err))) return r;
    out->root = root;
    out->camera = cam_node;
    out->background = bg;
    return SY_OK;
}

sy_result sy_demo_bench_scene(sy_scene *s, uint32_t groups, uint32_t per_group, uint32_t tris, sy_node *root_out,
                              sy_node *first_leaf_out, sy_error *err)
{
    sy_result r;
    sy_node root;
    sy_material mat;
    if ((r = sy_node_create(s, "bench", &root, err)) ||
        (r = material(s, "grey", 0.6f, 0.6f, 0.6f, 0, 0.8f, 0, NULL, &mat, err)))
        return r;
    /* slices x stacks with 2*slices*(stacks-1) ~= tris */
    uint32_t stacks = 6, slices = tris / (2 * (stacks - 1));
    if (slices < 3) slices = 3;
    sy_node *groups_n = malloc(sizeof *groups_n * groups);
    sy_node *leaves = malloc(sizeof *leaves * per_group);
    if (!groups_n || !leaves) {
        free(groups_n);
        free(leaves);
        return sy_error_set(err, SY_ERR_OUT_OF_MEMORY, "bench scene: out of memory");
    }
    static const float q[4] = {0, 0, 0, 1}, one[3] = {1, 1, 1};
    for (uint32_t g = 0; g < groups && r == SY_OK; ++g) {
        float tg[3] = {(float)(g % 32) * 3.0f, 0.0f, (float)(g / 32) * 3.0f};
        if ((r = sy_node_create(s, NULL, &groups_n[g], err)) || (r = sy_node_set_trs(s, groups_n[g], tg, q, one, err)))
            break;
        for (uint32_t i = 0; i < per_group && r == SY_OK; ++i) {
            sy_mesh m;
            float tl[3] = {(float)(i % 10) * 0.25f, 0.1f * (float)(i / 10), 0.0f};
            if ((r = sy_demo_sphere(s, 0.1f + 0.001f * (float)i, slices, stacks, mat, &m, err)) ||
                (r = sy_node_create(s, NULL, &leaves[i], err)) || (r = sy_node_set_trs(s, leaves[i], tl, q, one, err)) ||
                (r = sy_node_set_mesh(s, leaves[i], m, err)) ||
                (r = sy_node_set_flags(s, leaves[i], SY_NODE_VISIBLE | SY_NODE_ANIMATED, err)))
                break;
            if (g == 0 && i == 0) *first_leaf_out = leaves[0];
        }
        if (r == SY_OK) r = sy_node_set_children(s, groups_n[g], leaves, per_group, err);
    }
    if (r == SY_OK) r = sy_node_set_children(s, root, groups_n, groups, err);
    free(groups_n);
    free(leaves);
    *root_out = root;
    return r;
}
