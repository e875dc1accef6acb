/* sy_rt_bsdf.c — glTF metallic-roughness BSDF for the path tracer (see sy_rt_bsdf.h). */
#include "sy_rt_bsdf.h"
#include "sy_rt_iridescence.h"
#include "sy_rt_sheen.h"

#include <string.h>

#define INV_PI 0.31830988618f

static float maxc(sy_rt_v3 v) { return sy_rt_maxf(v.x, sy_rt_maxf(v.y, v.z)); }
static sy_rt_v3 schlick3(sy_rt_v3 f0, float c)
{
    float m = 1.0f - sy_rt_clampf(c, 0.0f, 1.0f), m2 = m * m, m5 = m2 * m2 * m;
    return v3(f0.x + (1.0f - f0.x) * m5, f0.y + (1.0f - f0.y) * m5, f0.z + (1.0f - f0.z) * m5);
}

/* Exact Fresnel reflectance of a dielectric interface; eta = n_incident / n_transmitted. */
static float fresnel_dielectric(float ci, float eta, float *ct_out)
{
    float st2 = eta * eta * (1.0f - ci * ci);
    if (st2 >= 1.0f) {
        *ct_out = 0.0f;
        return 1.0f;
    }
    float ct = sqrtf(1.0f - st2);
    float rs = (eta * ci - ct) / (eta * ci + ct), rp = (ci - eta * ct) / (ci + eta * ct);
    *ct_out = ct;
    return 0.5f * (rs * rs + rp * rp);
}

static float ggx_d(float a2, float nh)
{
    float d = nh * nh * (a2 - 1.0f) + 1.0f;
    return a2 * INV_PI / (d * d);
}
static float ggx_lambda(float a2, float c)
{
    c = fabsf(c);
    if (c >= 1.0f) return 0.0f;
    float t2 = (1.0f - c * c) / sy_rt_maxf(c * c, 1e-12f);
    return 0.5f * (-1.0f + sqrtf(1.0f + a2 * t2));
}

/* Anisotropic GGX (local frame: t = x, b = y, n = z) and its Smith Lambda. */
static float ggx_d_aniso(float ax, float ay, sy_rt_v3 h)
{
    float x = h.x / ax, y = h.y / ay, d = x * x + y * y + h.z * h.z;
    return INV_PI / (ax * ay * d * d);
}
static float ggx_lambda_aniso(float ax, float ay, sy_rt_v3 w)
{
    float z2 = sy_rt_maxf(w.z * w.z, 1e-12f);
    return 0.5f * (-1.0f + sqrtf(1.0f + (ax * ax * w.x * w.x + ay * ay * w.y * w.y) / z2));
}

static sy_rt_v3 to_local(const sy_rt_bsdf *b, sy_rt_v3 v) { return v3(v3_dot(v, b->t), v3_dot(v, b->b), v3_dot(v, b->n)); }
static sy_rt_v3 to_world(const sy_rt_bsdf *b, sy_rt_v3 v)
{
    return v3_add(v3_add(v3_scale(b->t, v.x), v3_scale(b->b, v.y)), v3_scale(b->n, v.z));
}

/* Visible-normal sample of a GGX of alphas ax, ay (Heitz 2018), local frame, wo.z > 0. */
static sy_rt_v3 sample_vndf(float ax, float ay, sy_rt_v3 wo, float u1, float u2)
{
    sy_rt_v3 vh = v3_normalize(v3(ax * wo.x, ay * wo.y, wo.z));
    float l2 = vh.x * vh.x + vh.y * vh.y;
    sy_rt_v3 t1 = l2 > 0.0f ? v3_scale(v3(-vh.y, vh.x, 0.0f), 1.0f / sqrtf(l2)) : v3(1.0f, 0.0f, 0.0f);
    sy_rt_v3 t2 = v3_cross(vh, t1);
    float r = sqrtf(u1), sp, cp;
    sy_rt_sincos_2pi(u2, &sp, &cp);
    float p1 = r * cp, p2 = r * sp;
    float s = 0.5f * (1.0f + vh.z);
    p2 = (1.0f - s) * sy_rt_sin_of_cos(p1) + s * p2;
    sy_rt_v3 nh = v3_add(v3_add(v3_scale(t1, p1), v3_scale(t2, p2)), v3_scale(vh, sqrtf(sy_rt_maxf(1.0f - p1 * p1 - p2 * p2, 0.0f))));
    return v3_normalize(v3(ax * nh.x, ay * nh.y, sy_rt_maxf(nh.z, 1e-7f)));
}

/* An orthonormal basis t, b about n (Duff et al. 2017). */
static void frame(sy_rt_bsdf *b)
{
    sy_rt_v3 n = b->n;
    float sign = copysignf(1.0f, n.z), a = -1.0f / (sign + n.z), bb = n.x * n.y * a;
    b->t = v3(1.0f + sign * n.x * n.x * a, sign * bb, -sign * n.x);
    b->b = v3(bb, sign + n.y * n.y * a, -n.y);
}

/* Whether evaluating b means its diffuse lobe alone: no specular layer (KHR_materials_specular 0),
 * no metal, sheen or glossy coat (transmission and mirrors are not evaluated). */
static bool lambert_only(const sy_rt_bsdf *b)
{
    return b->spec == 0.0f && b->q_metal == 0.0f && b->q_sheen == 0.0f && (b->cc_delta || !(b->q_coat > 0.0f));
}

void sy_rt_bsdf_init(sy_rt_bsdf *b, const sy_rt_surface *s, sy_rt_v3 wo)
{
    const sy_rt_material_desc *d = &s->mat->desc;
    b->ng = s->ng_facing;
    b->n = s->ns;
    if (v3_dot(b->n, wo) <= 1e-6f) b->n = s->ng_facing; /* shading normal facing away from the viewer */
    frame(b);
    b->base = v3(sy_rt_clampf(s->base.x, 0.0f, 1.0f), sy_rt_clampf(s->base.y, 0.0f, 1.0f), sy_rt_clampf(s->base.z, 0.0f, 1.0f));
    b->front = s->front;
    float metallic = sy_rt_clampf(s->metallic, 0.0f, 1.0f), trans = sy_rt_clampf(s->transmission, 0.0f, 1.0f);
    float rough = sy_rt_clampf(s->roughness, 0.0f, 1.0f);
    b->delta = rough < SY_RT_BSDF_DELTA_ROUGHNESS;
    b->alpha = sy_rt_maxf(rough * rough, 1e-4f);
    b->aniso = false;
    b->ax = b->ay = b->alpha;
    float an = sy_rt_clampf(s->anisotropy, 0.0f, 1.0f);
    if (an > 0.0f) { /* the frame's t along the anisotropy direction (projected into the shading plane) */
        sy_rt_v3 t = v3_normalize(v3_sub(s->aniso_dir, v3_scale(b->n, v3_dot(b->n, s->aniso_dir))));
        float at = b->alpha + (1.0f - b->alpha) * an * an;
        if (!v3_is_zero(t) && at > b->alpha) {
            b->t = t;
            b->b = v3_cross(b->n, t);
            b->aniso = true;
            b->ax = at;
            b->ay = sy_rt_maxf(b->alpha, 1e-3f);
            b->delta = false; /* stretched along t: never a mirror */
        }
    }
    b->ior = d->ior >= 1.0f ? d->ior : 1.5f;
    float r = (b->ior - 1.0f) / (b->ior + 1.0f);
    b->f0d = r * r;
    b->f0c = v3(sy_rt_minf(b->f0d * s->specular_color.x, 1.0f), sy_rt_minf(b->f0d * s->specular_color.y, 1.0f),
                sy_rt_minf(b->f0d * s->specular_color.z, 1.0f));
    b->spec = sy_rt_clampf(s->specular, 0.0f, 1.0f);
    float nv = v3_dot(b->n, wo);
    b->cc = sy_rt_clampf(s->clearcoat, 0.0f, 1.0f);
    float ccr = sy_rt_clampf(s->clearcoat_roughness, 0.0f, 1.0f);
    b->cc_delta = ccr < SY_RT_BSDF_DELTA_ROUGHNESS;
    b->cc_alpha = sy_rt_maxf(ccr * ccr, 1e-4f);
    b->cc_n = false;
    b->ncc = b->n;
    if (b->cc > 0.0f && s->coat_normal) {
        sy_rt_v3 nc = v3_dot(s->ns_coat, wo) > 1e-6f ? s->ns_coat : s->ng_facing;
        if (nc.x != b->n.x || nc.y != b->n.y || nc.z != b->n.z) b->cc_n = true, b->ncc = nc;
    }
    float nvc = b->cc_n ? v3_dot(b->ncc, wo) : nv;
    float fc = b->cc > 0.0f ? b->cc * schlick3(v3(0.04f, 0.04f, 0.04f), nvc).x : 0.0f;
    b->base_scale = 1.0f - fc;
    sy_rt_v3 sc = v3(sy_rt_clampf(s->sheen_color.x, 0.0f, 1.0f), sy_rt_clampf(s->sheen_color.y, 0.0f, 1.0f),
                     sy_rt_clampf(s->sheen_color.z, 0.0f, 1.0f));
    float sheen_scale = 1.0f, q_sheen = 0.0f;
    b->sheen_r = sy_rt_clampf(s->sheen_roughness, 0.0f, 1.0f);
    if (maxc(sc) > 0.0f && nv > 0.0f) {
        float e = sy_rt_minf(sy_rt_sheen_albedo(nv, b->sheen_r), 1.0f);
        sheen_scale = 1.0f - maxc(sc) * e;
        b->sheen = v3_scale(sc, b->base_scale);
        q_sheen = maxc(b->sheen) * sy_rt_maxf(e, 0.02f);
    } else {
        b->sheen = v3(0.0f, 0.0f, 0.0f);
    }
    b->irid = sy_rt_clampf(s->iridescence, 0.0f, 1.0f);
    b->irid_ior = s->mat->desc.iridescence_ior;
    b->irid_thick = s->iridescence_thickness;
    float under = b->under = b->base_scale * sheen_scale;
    b->w_metal = metallic * under;
    b->w_diel = (1.0f - metallic) * (1.0f - trans) * under;
    b->w_trans = (1.0f - metallic) * trans * under;
    float fd = b->spec * maxc(schlick3(b->f0c, nv));
    b->q_metal = b->w_metal;
    b->q_spec = b->w_diel * fd;
    b->q_diff = b->w_diel * (1.0f - fd) * maxc(b->base);
    b->q_coat = fc;
    b->q_trans = b->w_trans;
    b->q_sheen = q_sheen;
    float sum = b->q_metal + b->q_spec + b->q_diff + b->q_coat + b->q_trans + b->q_sheen;
    if (sum > 0.0f) {
        b->q_metal /= sum, b->q_spec /= sum, b->q_diff /= sum, b->q_coat /= sum, b->q_trans /= sum, b->q_sheen /= sum;
    } else {
        b->q_metal = b->q_spec = b->q_diff = b->q_coat = b->q_trans = b->q_sheen = 0.0f;
    }
    b->lambert = lambert_only(b);
}

/* The dielectric's Fresnel (x specular) and the metal's at cosine c, with the thin film mixed in
 * (KHR_materials_iridescence). */
static sy_rt_v3 fresnel_diel(const sy_rt_bsdf *b, float c)
{
    sy_rt_v3 f = schlick3(b->f0c, c);
    if (b->irid > 0.0f) {
        sy_rt_v3 fi = sy_rt_iridescence_fresnel(c, b->irid_ior, b->irid_thick, b->f0c);
        f = v3_add(v3_scale(f, 1.0f - b->irid), v3_scale(fi, b->irid));
    }
    return v3_scale(f, b->spec);
}
static sy_rt_v3 fresnel_metal(const sy_rt_bsdf *b, float c)
{
    sy_rt_v3 f = schlick3(b->base, c);
    if (b->irid > 0.0f) {
        sy_rt_v3 fi = sy_rt_iridescence_fresnel(c, b->irid_ior, b->irid_thick, b->base);
        f = v3_add(v3_scale(f, 1.0f - b->irid), v3_scale(fi, b->irid));
    }
    return f;
}

/* The base's GGX lobes are evaluated (not delta, some glossy weight). */
static inline bool bsdf_glossy(const sy_rt_bsdf *b) { return !b->delta && (b->q_metal > 0.0f || b->q_spec > 0.0f); }
/* The coat's GGX lobe is evaluated. */
static inline bool coat_glossy(const sy_rt_bsdf *b) { return !b->cc_delta && b->q_coat > 0.0f; }

/* sy_rt_bsdf_eval with the wo-only terms given: nv = n . wo and lv = Lambda(nv) (< 0: computed
 * here when needed, as a single evaluation does); a batch of directions for one wo computes them
 * once (sy_rt_pt_record_bsdf_batch). */
static inline sy_rt_v3 bsdf_eval_wo(const sy_rt_bsdf *b, sy_rt_v3 wo, float nv, float lv, sy_rt_v3 wi, float *pdf)
{
    *pdf = 0.0f;
    float nl = v3_dot(b->n, wi);
    if (nl <= 0.0f || nv <= 0.0f || v3_dot(b->ng, wi) <= 0.0f) return v3(0.0f, 0.0f, 0.0f);
    if (b->lambert) { /* the diffuse lobe alone: no half vector (the Fresnel below is 0 x Schlick) */
        *pdf = b->q_diff * nl * INV_PI;
        return v3_scale(v3_scale(b->base, b->w_diel * INV_PI), nl);
    }
    sy_rt_v3 h = v3_normalize(v3_add(wo, wi));
    float vh = sy_rt_maxf(v3_dot(wo, h), 0.0f);
    sy_rt_v3 fs = fresnel_diel(b, vh);
    sy_rt_v3 f = v3_scale(b->base, b->w_diel * (1.0f - sy_rt_minf(maxc(fs), 1.0f)) * INV_PI);
    float p = b->q_diff * nl * INV_PI;
    if (b->q_sheen > 0.0f) {
        float nh = sy_rt_maxf(v3_dot(b->n, h), 0.0f);
        f = v3_add(f, v3_scale(b->sheen, sy_rt_sheen_brdf(b->sheen_r, nl, nv, nh)));
        p += b->q_sheen * nl * INV_PI;
    }
    if (bsdf_glossy(b)) {
        float D, ll;
        if (b->aniso) {
            D = ggx_d_aniso(b->ax, b->ay, to_local(b, h));
            ll = ggx_lambda_aniso(b->ax, b->ay, to_local(b, wi));
            lv = ggx_lambda_aniso(b->ax, b->ay, to_local(b, wo));
        } else {
            float a2 = b->alpha * b->alpha, nh = sy_rt_maxf(v3_dot(b->n, h), 0.0f);
            D = ggx_d(a2, nh);
            ll = ggx_lambda(a2, nl);
            if (lv < 0.0f) lv = ggx_lambda(a2, nv);
        }
        float common = D / (1.0f + lv + ll) / (4.0f * nl * nv);
        if (b->w_metal > 0.0f) f = v3_add(f, v3_scale(fresnel_metal(b, vh), b->w_metal * common));
        f = v3_add(f, v3_scale(fs, b->w_diel * common));
        p += (b->q_metal + b->q_spec) * D / (1.0f + lv) / (4.0f * nv);
    }
    float nvc = b->cc_n ? v3_dot(b->ncc, wo) : nv, nlc = b->cc_n ? v3_dot(b->ncc, wi) : nl;
    if (coat_glossy(b) && nvc > 0.0f && nlc > 0.0f) {
        float a2 = b->cc_alpha * b->cc_alpha, nh = sy_rt_maxf(v3_dot(b->ncc, h), 0.0f);
        float D = ggx_d(a2, nh), lc = ggx_lambda(a2, nvc), ll = ggx_lambda(a2, nlc);
        float F = schlick3(v3(0.04f, 0.04f, 0.04f), vh).x;
        float fc = b->cc * F * D / (1.0f + lc + ll) / (4.0f * nlc * nvc);
        if (b->cc_n) fc *= nlc / nl; /* its own cosine (the sum is multiplied by n . wi below) */
        f = v3_add(f, v3(fc, fc, fc));
        p += b->q_coat * D / (1.0f + lc) / (4.0f * nvc);
    }
    *pdf = p;
    return v3_scale(f, nl);
}

sy_rt_v3 sy_rt_bsdf_eval(const sy_rt_bsdf *b, sy_rt_v3 wo, sy_rt_v3 wi, float *pdf)
{
    return bsdf_eval_wo(b, wo, v3_dot(b->n, wo), -1.0f, wi, pdf);
}

bool sy_rt_bsdf_sample_dir(const sy_rt_bsdf *b, sy_rt_v3 wo, const float u[3], sy_rt_bsdf_sample *out)
{
    float u0 = u[0];
    float nv = v3_dot(b->n, wo);
    out->specular = false;
    out->transmit = false;
    out->pdf = 0.0f;
    if (nv <= 0.0f) return false;
    sy_rt_v3 wol = to_local(b, wo);
    int lobe; /* 0 metal, 1 spec, 2 diffuse, 3 transmission, 4 coat, 5 sheen */
    float lo;
    if (u0 < b->q_metal) lobe = 0, lo = 0.0f;
    else if (u0 < b->q_metal + b->q_spec) lobe = 1, lo = b->q_metal;
    else if (u0 < b->q_metal + b->q_spec + b->q_diff) lobe = 2, lo = b->q_metal + b->q_spec;
    else if (u0 < b->q_metal + b->q_spec + b->q_diff + b->q_coat) lobe = 4, lo = b->q_metal + b->q_spec + b->q_diff;
    else if (u0 < b->q_metal + b->q_spec + b->q_diff + b->q_coat + b->q_sheen) lobe = 5, lo = 0.0f;
    else if (b->q_trans > 0.0f) lobe = 3, lo = 1.0f - b->q_trans;
    else return false;
    float nvc = b->cc_n ? v3_dot(b->ncc, wo) : nv;
    if (lobe == 4 && b->cc_delta) { /* a smooth coat: its mirror direction */
        if (nvc <= 0.0f) return false;
        sy_rt_v3 wi = v3_sub(v3_scale(b->ncc, 2.0f * nvc), wo);
        if (v3_dot(b->ng, wi) <= 0.0f) return false;
        out->wi = wi;
        out->specular = true;
        float F = b->cc * schlick3(v3(0.04f, 0.04f, 0.04f), nvc).x / b->q_coat;
        out->weight = v3(F, F, F);
        return true;
    }
    if (lobe == 3) {
        float ut = sy_rt_clampf((u0 - lo) / b->q_trans, 0.0f, 0.99999994f);
        float a2 = b->alpha * b->alpha;
        sy_rt_v3 h = b->delta ? b->n : to_world(b, sample_vndf(b->alpha, b->alpha, wol, u[1], u[2]));
        float ci = v3_dot(wo, h);
        if (ci <= 0.0f) return false;
        float eta = b->front ? 1.0f / b->ior : b->ior, ct;
        float F = fresnel_dielectric(ci, eta, &ct);
        /* KHR_materials_iridescence on the way in: the film's colour mixed into the Fresnel; the
         * split is chosen by the mean and the weights carry the colour */
        sy_rt_v3 fr = v3(1.0f, 1.0f, 1.0f), ft = v3(1.0f, 1.0f, 1.0f);
        if (b->irid > 0.0f && b->front && F < 1.0f) {
            sy_rt_v3 fi = sy_rt_iridescence_fresnel(ci, b->irid_ior, b->irid_thick, v3(b->f0d, b->f0d, b->f0d));
            sy_rt_v3 fm = v3(sy_rt_clampf(F + b->irid * (fi.x - F), 0.0f, 1.0f), sy_rt_clampf(F + b->irid * (fi.y - F), 0.0f, 1.0f),
                             sy_rt_clampf(F + b->irid * (fi.z - F), 0.0f, 1.0f));
            F = sy_rt_clampf((fm.x + fm.y + fm.z) / 3.0f, 1e-3f, 1.0f - 1e-3f);
            fr = v3_scale(fm, 1.0f / F);
            ft = v3_scale(v3(1.0f - fm.x, 1.0f - fm.y, 1.0f - fm.z), 1.0f / (1.0f - F));
        }
        sy_rt_v3 wi;
        if (ut < F) {
            wi = v3_sub(v3_scale(h, 2.0f * ci), wo);
            if (v3_dot(b->ng, wi) <= 0.0f || v3_dot(b->n, wi) <= 0.0f) return false;
            out->weight = fr;
        } else {
            wi = v3_normalize(v3_add(v3_scale(wo, -eta), v3_scale(h, eta * ci - ct)));
            if (v3_dot(b->ng, wi) >= 0.0f) return false;
            out->weight = b->irid > 0.0f ? v3_mul(b->base, ft) : b->base;
            out->transmit = true;
        }
        float g = 1.0f;
        if (!b->delta) {
            float lv = ggx_lambda(a2, nv), ll = ggx_lambda(a2, v3_dot(b->n, wi));
            g = (1.0f + lv) / (1.0f + lv + ll);
        }
        out->weight = v3_scale(out->weight, g * b->w_trans / b->q_trans);
        out->wi = wi;
        out->specular = true;
        return true;
    }
    if (b->delta && lobe != 2 && lobe != 4 && lobe != 5) {
        sy_rt_v3 wi = v3_sub(v3_scale(b->n, 2.0f * nv), wo);
        if (v3_dot(b->ng, wi) <= 0.0f) return false;
        out->wi = wi;
        out->specular = true;
        out->weight = lobe == 0 ? v3_scale(fresnel_metal(b, nv), b->w_metal / b->q_metal)
                     : b->irid > 0.0f ? v3_scale(fresnel_diel(b, nv), b->w_diel / b->q_spec)
                                      : v3_scale(schlick3(b->f0c, nv), b->w_diel * b->spec / b->q_spec);
        return true;
    }
    sy_rt_v3 wi;
    if (lobe == 2 || lobe == 5) {
        float r = sqrtf(u[1]), sp, cp;
        sy_rt_sincos_2pi(u[2], &sp, &cp);
        wi = to_world(b, v3(r * cp, r * sp, sqrtf(sy_rt_maxf(1.0f - u[1], 0.0f))));
    } else if (lobe == 4 && b->cc_n) { /* about the coat's own normal, in a frame of its own */
        if (nvc <= 0.0f) return false;
        sy_rt_bsdf c = *b;
        c.n = b->ncc;
        frame(&c);
        sy_rt_v3 h = to_world(&c, sample_vndf(b->cc_alpha, b->cc_alpha, to_local(&c, wo), u[1], u[2]));
        wi = v3_sub(v3_scale(h, 2.0f * v3_dot(wo, h)), wo);
    } else if (lobe == 4) {
        sy_rt_v3 h = to_world(b, sample_vndf(b->cc_alpha, b->cc_alpha, wol, u[1], u[2]));
        wi = v3_sub(v3_scale(h, 2.0f * v3_dot(wo, h)), wo);
    } else {
        sy_rt_v3 h = to_world(b, sample_vndf(b->ax, b->ay, wol, u[1], u[2]));
        wi = v3_sub(v3_scale(h, 2.0f * v3_dot(wo, h)), wo);
    }
    float pdf;
    sy_rt_v3 f = sy_rt_bsdf_eval(b, wo, wi, &pdf);
    if (!(pdf > 0.0f)) return false;
    out->wi = wi;
    out->weight = v3_scale(f, 1.0f / pdf);
    out->pdf = pdf;
    return true;
}

/* >>path records: the BSDF of P0 travels in the record (sy_rt.h) */
void sy_rt_bsdf_pack(const sy_rt_bsdf *b, float o[SY_RT_RECORD_BSDF_FLOATS])
{
    const float v[SY_RT_RECORD_BSDF_FLOATS] = {b->n.x,   b->n.y,   b->n.z,      b->ng.x,     b->ng.y,     b->ng.z,
                                               b->base.x, b->base.y, b->base.z, b->alpha,    b->delta ? 1.0f : 0.0f,
                                               b->f0d,   b->spec,  b->w_metal,  b->w_diel,   b->q_metal,  b->q_spec,
                                               b->q_diff, b->f0c.x, b->f0c.y, b->f0c.z,
                                               b->cc,    b->cc_alpha, b->cc_delta ? 1.0f : 0.0f, b->q_coat,
                                               b->sheen.x, b->sheen.y, b->sheen.z, b->sheen_r, b->q_sheen,
                                               b->irid,  b->irid_ior, b->irid_thick,
                                               b->aniso ? 1.0f : 0.0f, b->t.x, b->t.y, b->t.z, b->ax, b->ay,
                                               b->cc_n ? 1.0f : 0.0f, b->ncc.x, b->ncc.y, b->ncc.z};
    memcpy(o, v, sizeof v);
}

void sy_rt_pt_record_bsdf_batch(const sy_rt_pt_record *r, uint32_t count, const float *const wi[3],
                                float *const f_cos[3], float *pdf)
{
    if (!(r->flags & SY_RT_RECORD_P0)) {
        for (uint32_t m = 0; m < count; ++m) f_cos[0][m] = f_cos[1][m] = f_cos[2][m] = pdf[m] = 0.0f;
        return;
    }
    /* unpacked once per batch, with the wo-only terms */
    const float *p = r->bsdf;
    sy_rt_bsdf b;
    memset(&b, 0, sizeof b);
    b.n = v3(p[0], p[1], p[2]);
    b.ng = v3(p[3], p[4], p[5]);
    b.base = v3(p[6], p[7], p[8]);
    b.alpha = p[9];
    b.delta = p[10] != 0.0f;
    b.f0d = p[11], b.spec = p[12], b.w_metal = p[13], b.w_diel = p[14];
    b.q_metal = p[15], b.q_spec = p[16], b.q_diff = p[17];
    b.f0c = v3(p[18], p[19], p[20]);
    b.cc = p[21], b.cc_alpha = p[22], b.cc_delta = p[23] != 0.0f, b.q_coat = p[24];
    b.sheen = v3(p[25], p[26], p[27]), b.sheen_r = p[28], b.q_sheen = p[29];
    b.irid = p[30], b.irid_ior = p[31], b.irid_thick = p[32];
    b.aniso = p[33] != 0.0f, b.t = v3(p[34], p[35], p[36]), b.ax = p[37], b.ay = p[38];
    b.b = v3_cross(b.n, b.t);
    b.cc_n = p[39] != 0.0f, b.ncc = v3(p[40], p[41], p[42]);
    b.lambert = lambert_only(&b);
    sy_rt_v3 wo = v3(r->wo[0], r->wo[1], r->wo[2]);
    float nv = v3_dot(b.n, wo), lv = bsdf_glossy(&b) && nv > 0.0f ? ggx_lambda(b.alpha * b.alpha, nv) : -1.0f;
    for (uint32_t m = 0; m < count; ++m) {
        float q;
        sy_rt_v3 f = bsdf_eval_wo(&b, wo, nv, lv, v3(wi[0][m], wi[1][m], wi[2][m]), &q);
        f_cos[0][m] = f.x, f_cos[1][m] = f.y, f_cos[2][m] = f.z;
        pdf[m] = q;
    }
}

void sy_rt_pt_record_bsdf(const sy_rt_pt_record *r, const float wi[3], float f_cos[3], float *pdf)
{
    const float *const w[3] = {wi + 0, wi + 1, wi + 2};
    float *const f[3] = {f_cos + 0, f_cos + 1, f_cos + 2};
    sy_rt_pt_record_bsdf_batch(r, 1, w, f, pdf);
}
