/* sy_rt_surface.c — hit-point evaluation shared by every integrator: attribute interpolation
 * from the mesh's own arrays, normal transforms (the instance's inverse transpose), tangent frames
 * from uv derivatives for normal maps, texture lookups, and the alpha-mask filter. */
#include "sy_rt_surface.h"
#include "sy_rt_texture.h"

/* Barycentric interpolation of an attribute with `n` floats per vertex. */
static void interp(const float *a, uint32_t n, const uint32_t *ix, float w0, float w1, float w2, float *out)
{
    for (uint32_t k = 0; k < n; ++k)
        out[k] = a[n * ix[0] + k] * w0 + a[n * ix[1] + k] * w1 + a[n * ix[2] + k] * w2;
}

/* Texture coordinates of both sets (zeros for an absent set). */
static void fetch_uv(const sy_rt_mesh_data *m, const uint32_t *ix, float w0, float w1, float w2, float uv[2][2])
{
    for (int s = 0; s < 2; ++s) {
        if (m->uv[s]) interp(m->uv[s], 2, ix, w0, w1, w2, uv[s]);
        else uv[s][0] = uv[s][1] = 0.0f;
    }
}

static inline float base_alpha(const sy_rt_device *dev, const sy_rt_material_data *mat, const sy_rt_mesh_data *m,
                        const uint32_t *ix, float w0, float w1, float w2, float uv[2][2], sy_rt_v3 *rgb)
{
    const sy_rt_material_desc *d = &mat->desc;
    float c[4] = {d->base_color[0], d->base_color[1], d->base_color[2], d->base_color[3]};
    float t[4];
    if (sy_rt_texture_sample_ref(dev, &d->base_color_texture, (const float(*)[2])uv, t))
        for (int k = 0; k < 4; ++k) c[k] *= t[k];
    if (m->colors) {
        float vc[4];
        interp(m->colors, 4, ix, w0, w1, w2, vc);
        for (int k = 0; k < 4; ++k) c[k] *= vc[k];
    }
    if (rgb) *rgb = v3(c[0], c[1], c[2]);
    return c[3];
}

float sy_rt_surface_alpha(const sy_rt_device *dev, const sy_rt_instance_data *inst, uint32_t prim, float u, float v)
{
    const sy_rt_mesh_data *m = inst->mesh;
    const uint32_t *ix = m->indices + 3u * prim;
    float w0 = 1.0f - u - v, uv[2][2];
    fetch_uv(m, ix, w0, u, v, uv);
    return base_alpha(dev, sy_rt_material_lookup(dev, inst->material), m, ix, w0, u, v, uv, NULL);
}

sy_rt_v3 sy_rt_surface_emission(const sy_rt_device *dev, const sy_rt_instance_data *inst, uint32_t prim, float u, float v)
{
    const sy_rt_material_desc *d = &sy_rt_material_lookup(dev, inst->material)->desc;
    sy_rt_v3 e = v3_load(d->emissive);
    if (d->emissive_texture.texture.id == 0) return e;
    const sy_rt_mesh_data *m = inst->mesh;
    const uint32_t *ix = m->indices + 3u * prim;
    float uv[2][2], t[4];
    fetch_uv(m, ix, 1.0f - u - v, u, v, uv);
    if (sy_rt_texture_sample_ref(dev, &d->emissive_texture, (const float(*)[2])uv, t)) e = v3_mul(e, v3(t[0], t[1], t[2]));
    return e;
}

/* The tangent frame of a triangle at front-side normal n from the uv derivatives of texture
 * coordinate set `set` (through the linear part of `xf`, a 2x3 uv transform, when given), as glTF
 * viewers do without stored tangents: tg along increasing u, bt = n x tg turned so that texture
 * "up" (+Y) points to decreasing v. False when the set is absent or degenerate here. */
static bool uv_frame(const sy_rt_instance_data *inst, const uint32_t *ix, uint32_t set, const float *xf, sy_rt_v3 n,
                     sy_rt_v3 *tg_out, sy_rt_v3 *bt_out)
{
    const sy_rt_mesh_data *m = inst->mesh;
    if (!m->uv[set]) return false;
    const float *uv = m->uv[set];
    sy_rt_v3 p0 = v3_load(m->positions + 3u * ix[0]);
    sy_rt_v3 dp1 = v3_sub(v3_load(m->positions + 3u * ix[1]), p0), dp2 = v3_sub(v3_load(m->positions + 3u * ix[2]), p0);
    float du1 = uv[2 * ix[1]] - uv[2 * ix[0]], dv1 = uv[2 * ix[1] + 1] - uv[2 * ix[0] + 1];
    float du2 = uv[2 * ix[2]] - uv[2 * ix[0]], dv2 = uv[2 * ix[2] + 1] - uv[2 * ix[0] + 1];
    if (xf) { /* derivatives of the transformed coordinates (linear part) */
        const float *x = xf;
        float a1 = x[0] * du1 + x[1] * dv1, b1 = x[3] * du1 + x[4] * dv1;
        float a2 = x[0] * du2 + x[1] * dv2, b2 = x[3] * du2 + x[4] * dv2;
        du1 = a1, dv1 = b1, du2 = a2, dv2 = b2;
    }
    float det = du1 * dv2 - du2 * dv1;
    if (!(fabsf(det) > 1e-20f)) return false;
    float inv = 1.0f / det;
    sy_rt_v3 dpdu = m4_dir(inst->xf, v3_scale(v3_sub(v3_scale(dp1, dv2), v3_scale(dp2, dv1)), inv));
    sy_rt_v3 dpdv = m4_dir(inst->xf, v3_scale(v3_sub(v3_scale(dp2, du1), v3_scale(dp1, du2)), inv));
    sy_rt_v3 tg = v3_normalize(v3_sub(dpdu, v3_scale(n, v3_dot(n, dpdu))));
    if (v3_is_zero(tg)) return false;
    sy_rt_v3 bt = v3_cross(n, tg);
    /* Texture "up" (+Y) points to decreasing v in glTF; flip for mirrored uv layouts. */
    if (v3_dot(bt, dpdv) > 0.0f) bt = v3_scale(bt, -1.0f);
    *tg_out = tg, *bt_out = bt;
    return true;
}

/* Perturbs the (front-side) shading normal n with normal map `ref` of scale `scale` (the
 * material's, or its clear coat's). */
static sy_rt_v3 apply_normal_map(const sy_rt_device *dev, const sy_rt_instance_data *inst, const uint32_t *ix,
                                 const float uv_set[2][2], sy_rt_v3 n, const sy_rt_texture_ref *ref, float scale)
{
    if (!inst->mesh->uv[ref->texcoord]) return n;
    float t[4];
    if (!sy_rt_texture_sample_ref(dev, ref, uv_set, t)) return n;
    sy_rt_v3 tg, bt;
    if (!uv_frame(inst, ix, ref->texcoord, ref->transformed ? ref->transform : NULL, n, &tg, &bt)) return n;
    float x = (t[0] * 2.0f - 1.0f) * scale, y = (t[1] * 2.0f - 1.0f) * scale, z = t[2] * 2.0f - 1.0f;
    sy_rt_v3 r = v3_normalize(v3_add(v3_add(v3_scale(tg, x), v3_scale(bt, y)), v3_scale(n, z)));
    return v3_is_zero(r) ? n : r;
}

/* KHR_materials_anisotropy: the strength and world direction at the point (front-side normal n):
 * the texture's RG direction (else +X of tangent space) rotated counter-clockwise by the rotation,
 * in the tangent frame of the anisotropy texture's coordinate set (else set 0; no frame there: no
 * anisotropy). */
static float anisotropy_at(const sy_rt_device *dev, const sy_rt_instance_data *inst, const uint32_t *ix,
                           const float uv_set[2][2], sy_rt_v3 n, sy_rt_v3 *dir)
{
    const sy_rt_material_desc *d = &sy_rt_material_lookup(dev, inst->material)->desc;
    float dx = 1.0f, dy = 0.0f, strength = d->anisotropy, t[4];
    if (sy_rt_texture_sample_ref(dev, &d->anisotropy_texture, uv_set, t)) {
        dx = t[0] * 2.0f - 1.0f, dy = t[1] * 2.0f - 1.0f;
        strength *= t[2];
    }
    float c = cosf(d->anisotropy_rotation), sn = sinf(d->anisotropy_rotation);
    float rx = c * dx - sn * dy, ry = sn * dx + c * dy;
    sy_rt_v3 tg, bt;
    uint32_t set = d->anisotropy_texture.texture.id ? d->anisotropy_texture.texcoord : 0u;
    if (!(strength > 0.0f) || !uv_frame(inst, ix, set, NULL, n, &tg, &bt)) return 0.0f;
    sy_rt_v3 w = v3_normalize(v3_add(v3_scale(tg, rx), v3_scale(bt, ry)));
    if (v3_is_zero(w)) return 0.0f;
    *dir = w;
    return sy_rt_clampf(strength, 0.0f, 1.0f);
}

void sy_rt_surface_fetch(const sy_rt_device *dev, const sy_rt_instance_data *inst, uint32_t prim, float u, float v,
                         sy_rt_v3 dir, sy_rt_surface *s)
{
    const sy_rt_mesh_data *m = inst->mesh;
    const sy_rt_material_data *mat = sy_rt_material_lookup(dev, inst->material);
    const sy_rt_material_desc *d = &mat->desc;
    const uint32_t *ix = m->indices + 3u * prim;
    float w0 = 1.0f - u - v, w1 = u, w2 = v;
    s->inst = inst;
    s->mat = mat;

    sy_rt_v3 o0 = v3_load(m->positions + 3u * ix[0]), o1 = v3_load(m->positions + 3u * ix[1]),
             o2 = v3_load(m->positions + 3u * ix[2]);
    sy_rt_v3 po = v3_add(v3_add(v3_scale(o0, w0), v3_scale(o1, w1)), v3_scale(o2, w2));
    s->p = m4_point(inst->xf, po);
    s->ng = v3_normalize(m3_mul(inst->nrm, v3_cross(v3_sub(o1, o0), v3_sub(o2, o0))));
    s->front = v3_dot(s->ng, dir) < 0.0f;
    s->ng_facing = s->front ? s->ng : v3_scale(s->ng, -1.0f);

    sy_rt_v3 n = s->ng;
    if (m->normals) {
        float nn[3];
        interp(m->normals, 3, ix, w0, w1, w2, nn);
        sy_rt_v3 ns = v3_normalize(m3_mul(inst->nrm, v3_load(nn)));
        if (!v3_is_zero(ns)) n = ns;
    }
    float uv[2][2] = {{0.0f, 0.0f}, {0.0f, 0.0f}};
    if (mat->textured) fetch_uv(m, ix, w0, w1, w2, uv);
    sy_rt_v3 n_vertex = n;
    if (d->normal_texture.texture.id != 0)
        n = apply_normal_map(dev, inst, ix, (const float(*)[2])uv, n, &d->normal_texture, d->normal_scale);
    /* Shade the side the ray sees (double-sided, or interiors seen through openings). */
    s->ns = s->front ? n : v3_scale(n, -1.0f);
    /* KHR_materials_clearcoat: the coat's normal is the vertex normal with the coat's own normal map
     * (never the base's) */
    s->ns_coat = s->ns;
    s->coat_normal = false;
    if (d->clearcoat > 0.0f) {
        sy_rt_v3 nc = n_vertex;
        if (d->clearcoat_normal_texture.texture.id != 0)
            nc = apply_normal_map(dev, inst, ix, (const float(*)[2])uv, nc, &d->clearcoat_normal_texture, d->clearcoat_normal_scale);
        if (nc.x != n.x || nc.y != n.y || nc.z != n.z) {
            s->ns_coat = s->front ? nc : v3_scale(nc, -1.0f);
            s->coat_normal = true;
        }
    }
    s->anisotropy = 0.0f;
    if (d->anisotropy > 0.0f) s->anisotropy = anisotropy_at(dev, inst, ix, (const float(*)[2])uv, n, &s->aniso_dir);

    s->alpha = base_alpha(dev, mat, m, ix, w0, w1, w2, uv, &s->base);
    s->metallic = d->metallic;
    s->roughness = d->roughness;
    float t[4];
    const sy_rt_texture_ref *mr = &d->metallic_roughness_texture;
    if (sy_rt_texture_sample_ref(dev, mr, (const float(*)[2])uv, t)) {
        s->roughness *= t[1];
        s->metallic *= t[2];
    }
    s->transmission = d->transmission;
    if (s->transmission > 0.0f && sy_rt_texture_sample_ref(dev, &d->transmission_texture, (const float(*)[2])uv, t))
        s->transmission *= t[0];
    s->specular = d->specular;
    if (sy_rt_texture_sample_ref(dev, &d->specular_texture, (const float(*)[2])uv, t)) s->specular *= t[3];
    s->specular_color = v3_load(d->specular_color);
    if (sy_rt_texture_sample_ref(dev, &d->specular_color_texture, (const float(*)[2])uv, t))
        s->specular_color = v3_mul(s->specular_color, v3(t[0], t[1], t[2]));
    s->clearcoat = d->clearcoat;
    s->clearcoat_roughness = d->clearcoat_roughness;
    if (s->clearcoat > 0.0f) {
        if (sy_rt_texture_sample_ref(dev, &d->clearcoat_texture, (const float(*)[2])uv, t)) s->clearcoat *= t[0];
        if (sy_rt_texture_sample_ref(dev, &d->clearcoat_roughness_texture, (const float(*)[2])uv, t))
            s->clearcoat_roughness *= t[1];
    }
    s->sheen_color = v3_load(d->sheen_color);
    s->sheen_roughness = d->sheen_roughness;
    if (!v3_is_zero(s->sheen_color)) {
        if (sy_rt_texture_sample_ref(dev, &d->sheen_color_texture, (const float(*)[2])uv, t))
            s->sheen_color = v3_mul(s->sheen_color, v3(t[0], t[1], t[2]));
        if (sy_rt_texture_sample_ref(dev, &d->sheen_roughness_texture, (const float(*)[2])uv, t)) s->sheen_roughness *= t[3];
    }
    s->iridescence = d->iridescence;
    s->iridescence_thickness = d->iridescence_thickness[1];
    if (s->iridescence > 0.0f) {
        if (sy_rt_texture_sample_ref(dev, &d->iridescence_texture, (const float(*)[2])uv, t)) s->iridescence *= t[0];
        if (sy_rt_texture_sample_ref(dev, &d->iridescence_thickness_texture, (const float(*)[2])uv, t))
            s->iridescence_thickness = d->iridescence_thickness[0] + t[1] * (d->iridescence_thickness[1] - d->iridescence_thickness[0]);
    }
    s->emission = v3_load(d->emissive);
    const sy_rt_texture_ref *em = &d->emissive_texture;
    if (mat->emissive && sy_rt_texture_sample_ref(dev, em, (const float(*)[2])uv, t))
        s->emission = v3_mul(s->emission, v3(t[0], t[1], t[2]));
}

void sy_rt_alpha_filter(const struct RTCFilterFunctionNArguments *args)
{
    const sy_rt_device *dev = args->geometryUserPtr;
    const unsigned N = args->N;
    const float *hf = (const float *)args->hit;
    const unsigned *hu = (const unsigned *)args->hit;
    for (unsigned i = 0; i < N; ++i) {
        if (args->valid[i] != -1) continue;
        float u = hf[3 * N + i], v = hf[4 * N + i];
        unsigned prim = hu[5 * N + i], geom = hu[6 * N + i], inst_id = hu[7 * N + i];
        const sy_rt_instance_data *in = sy_rt_filter_instance(dev, args->context, geom, inst_id);
        if (!in) continue;
        const sy_rt_material_data *mat = sy_rt_material_lookup(dev, in->material);
        if (!mat->masked) continue;
        if (sy_rt_surface_alpha(dev, in, prim, u, v) < mat->desc.alpha_cutoff) args->valid[i] = 0;
    }
}

void sy_rt_surface_fetch_at(const sy_rt_device *dev, const sy_rt_instance_data *inst, float time, uint32_t prim, float u,
                            float v, sy_rt_v3 dir, sy_rt_surface *s)
{
    sy_rt_instance_data posed;
    const sy_rt_instance_data *at = sy_rt_instance_at(inst, time, &posed);
    const sy_rt_mesh_data *m = inst->mesh;
    if (!m->motion || !(time > 0.0f)) {
        sy_rt_surface_fetch(dev, at, prim, u, v, dir, s);
        s->inst = inst;
        return;
    }
    /* a deforming mesh in motion: the hit triangle alone, its corners at the ray's time (as Embree
     * interpolates them), in a mesh of one triangle that the fetch reads like any other */
    sy_rt_mesh_data tri = *m;
    const uint32_t *ix = m->indices + 3u * prim;
    static const uint32_t idx[3] = {0, 1, 2};
    float pos[9], nrm[9], uv[2][6], col[12];
    /* the two steps around the time, as Embree finds them (two steps: open and close) */
    const float *p0 = m->positions, *p1 = m->positions1, *n0 = m->normals, *n1 = m->normals1;
    float f = time;
    if (m->motion_steps > 2u) {
        float st = time * (float)(m->motion_steps - 1u);
        uint32_t seg = st > 0.0f ? (uint32_t)st : 0u;
        if (seg > m->motion_steps - 2u) seg = m->motion_steps - 2u;
        f = st - (float)seg;
        if (seg > 0u) p0 = m->pos_mid[seg], n0 = m->nrm_mid[seg];
        if (seg + 2u < m->motion_steps) p1 = m->pos_mid[seg + 1u], n1 = m->nrm_mid[seg + 1u];
    }
    for (int c = 0; c < 3; ++c) {
        size_t k = ix[c];
        for (int a = 0; a < 3; ++a) {
            pos[3 * c + a] = (1.0f - f) * p0[3 * k + a] + f * p1[3 * k + a];
            if (m->normals) nrm[3 * c + a] = (1.0f - f) * (n0 ? n0 : m->normals)[3 * k + a] + f * (n1 ? n1 : m->normals)[3 * k + a];
        }
        for (int set = 0; set < 2; ++set)
            if (m->uv[set]) uv[set][2 * c] = m->uv[set][2 * k], uv[set][2 * c + 1] = m->uv[set][2 * k + 1];
        if (m->colors)
            for (int a = 0; a < 4; ++a) col[4 * c + a] = m->colors[4 * k + a];
    }
    tri.positions = pos;
    tri.indices = idx;
    tri.normals = m->normals ? nrm : NULL;
    tri.uv[0] = m->uv[0] ? uv[0] : NULL;
    tri.uv[1] = m->uv[1] ? uv[1] : NULL;
    tri.colors = m->colors ? col : NULL;
    tri.vertex_count = 3, tri.triangle_count = 1;
    if (at != &posed) posed = *inst;
    posed.mesh = &tri;
    sy_rt_surface_fetch(dev, &posed, 0, u, v, dir, s);
    s->inst = inst;
}

sy_rt_v3 sy_rt_surface_eyelight(const sy_rt_device *dev, const sy_rt_instance_data *inst, uint32_t prim, float u,
                                float v, sy_rt_v3 dir)
{
    const sy_rt_mesh_data *m = inst->mesh;
    const sy_rt_material_data *mat = sy_rt_material_lookup(dev, inst->material);
    const sy_rt_material_desc *d = &mat->desc;
    const uint32_t *ix = m->indices + 3u * prim;
    float w0 = 1.0f - u - v, w1 = u, w2 = v;
    float uv[2][2];
    if (mat->emissive) {
        sy_rt_v3 e = v3_load(d->emissive);
        const sy_rt_texture_ref *em = &d->emissive_texture;
        if (em->texture.id != 0) {
            float t[4];
            fetch_uv(m, ix, w0, w1, w2, uv);
            if (sy_rt_texture_sample_ref(dev, em, (const float(*)[2])uv, t))
                e = v3_mul(e, v3(t[0], t[1], t[2]));
        }
        return e;
    }
    /* Only the texture-coordinate sets a texture of this material reads (same arithmetic as fetch_uv). */
    bool need[2] = {false, false};
    if (d->base_color_texture.texture.id != 0) need[d->base_color_texture.texcoord & 1u] = true;
    if (!d->unlit && d->normal_texture.texture.id != 0) need[d->normal_texture.texcoord & 1u] = true;
    for (int k = 0; k < 2; ++k) {
        if (need[k] && m->uv[k]) interp(m->uv[k], 2, ix, w0, w1, w2, uv[k]);
        else uv[k][0] = uv[k][1] = 0.0f;
    }
    sy_rt_v3 base;
    (void)base_alpha(dev, mat, m, ix, w0, w1, w2, uv, &base);
    if (d->unlit) return base;

    sy_rt_v3 o0 = v3_load(m->positions + 3u * ix[0]), o1 = v3_load(m->positions + 3u * ix[1]),
             o2 = v3_load(m->positions + 3u * ix[2]);
    sy_rt_v3 ng = v3_normalize(m3_mul(inst->nrm, v3_cross(v3_sub(o1, o0), v3_sub(o2, o0))));
    bool front = v3_dot(ng, dir) < 0.0f;
    sy_rt_v3 n = ng;
    if (m->normals) {
        float nn[3];
        interp(m->normals, 3, ix, w0, w1, w2, nn);
        sy_rt_v3 ns = v3_normalize(m3_mul(inst->nrm, v3_load(nn)));
        if (!v3_is_zero(ns)) n = ns;
    }
    if (d->normal_texture.texture.id != 0)
        n = apply_normal_map(dev, inst, ix, (const float(*)[2])uv, n, &d->normal_texture, d->normal_scale);
    sy_rt_v3 ns = front ? n : v3_scale(n, -1.0f);
    return v3_scale(base, fabsf(v3_dot(ns, v3_normalize(dir))));
}
