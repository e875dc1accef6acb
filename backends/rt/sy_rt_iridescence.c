/* sy_rt_iridescence.c — thin-film Fresnel of KHR_materials_iridescence (see sy_rt_iridescence.h). */
#include "sy_rt_iridescence.h"

#define IR_PI 3.14159265358979f

static float sq(float x) { return x * x; }
static float schlick1(float f0, float c)
{
    float m = 1.0f - sy_rt_clampf(c, 0.0f, 1.0f), m2 = m * m;
    return f0 + (1.0f - f0) * m2 * m2 * m;
}
/* Exact unpolarised Fresnel reflectance from index n1 into n2 at incidence cosine ci (ct: the
 * refracted cosine). */
static float fresnel_exact(float ci, float ct, float n1, float n2)
{
    float rs = (n1 * ci - n2 * ct) / (n1 * ci + n2 * ct), rp = (n2 * ci - n1 * ct) / (n2 * ci + n1 * ct);
    return 0.5f * (rs * rs + rp * rp);
}
static float ior_to_f0(float t, float i) { return sq((t - i) / (t + i)); }
static float f0_to_ior(float f0)
{
    float s = sqrtf(sy_rt_clampf(f0, 0.0f, 0.9999f));
    return (1.0f + s) / (1.0f - s);
}

/* The CIE XYZ sensitivity of an optical path difference opd (nm) with phase shifts per channel,
 * as Gaussian fits (Belcour and Barla), converted to linear Rec.709. */
static sy_rt_v3 sensitivity(float opd, const float shift[3])
{
    static const float val[3] = {5.4856e-13f, 4.4201e-13f, 5.2481e-13f};
    static const float pos[3] = {1.6810e+06f, 1.7953e+06f, 2.2084e+06f};
    static const float var[3] = {4.3278e+09f, 9.3046e+09f, 6.6121e+09f};
    float phase = 2.0f * IR_PI * opd * 1.0e-9f, xyz[3];
    for (int k = 0; k < 3; ++k)
        xyz[k] = val[k] * sqrtf(2.0f * IR_PI * var[k]) * cosf(pos[k] * phase + shift[k]) * expf(-sq(phase) * var[k]);
    xyz[0] += 9.7470e-14f * sqrtf(2.0f * IR_PI * 4.5282e+09f) * cosf(2.2399e+06f * phase + shift[0]) * expf(-4.5282e+09f * sq(phase));
    for (int k = 0; k < 3; ++k) xyz[k] /= 1.0685e-7f;
    return v3(3.2404542f * xyz[0] - 1.5371385f * xyz[1] - 0.4985314f * xyz[2],
              -0.9692660f * xyz[0] + 1.8760108f * xyz[1] + 0.0415560f * xyz[2],
              0.0556434f * xyz[0] - 0.2040259f * xyz[1] + 1.0572252f * xyz[2]);
}

sy_rt_v3 sy_rt_iridescence_fresnel(float cos_i, float film_ior, float thickness_nm, sy_rt_v3 f0)
{
    const float outside = 1.0f;
    /* a film thinner than 30 nm fades to no film (the Sample Viewer's smoothstep) */
    float x = sy_rt_clampf(thickness_nm / 30.0f, 0.0f, 1.0f), fade = x * x * (3.0f - 2.0f * x);
    float ior = outside + (film_ior - outside) * fade;
    float c1 = sy_rt_clampf(cos_i, 0.0f, 1.0f);
    float st2 = sq(outside / ior) * (1.0f - c1 * c1), ct2 = 1.0f - st2;
    if (ct2 < 0.0f) return v3(1.0f, 1.0f, 1.0f); /* total internal reflection in the film */
    float c2 = sqrtf(ct2);
    /* the air-film interface by exact Fresnel (the Sample Viewer's Schlick with F0 0 reflects at
     * grazing angles where a film of the outside's index is no interface at all) */
    float r12 = fresnel_exact(c1, c2, outside, ior), t121 = 1.0f - r12;
    float phi12 = ior < outside ? IR_PI : 0.0f, phi21 = IR_PI - phi12;
    const float base_f0[3] = {f0.x, f0.y, f0.z};
    float r23[3], phi[3], r123[3], rs[3], cm[3], out[3];
    for (int k = 0; k < 3; ++k) {
        float base_ior = f0_to_ior(base_f0[k]);
        r23[k] = schlick1(ior_to_f0(base_ior, ior), c2);
        phi[k] = phi21 + (base_ior < ior ? IR_PI : 0.0f);
        float r = sy_rt_clampf(r12 * r23[k], 1e-5f, 0.9999f);
        r123[k] = sqrtf(r);
        rs[k] = sq(t121) * r23[k] / (1.0f - r);
        out[k] = r12 + rs[k];
        cm[k] = rs[k] - t121;
    }
    float opd = 2.0f * ior * thickness_nm * c2;
    for (int m = 1; m <= 2; ++m) {
        float sh[3] = {(float)m * phi[0], (float)m * phi[1], (float)m * phi[2]};
        sy_rt_v3 s = sensitivity((float)m * opd, sh);
        const float sv[3] = {s.x, s.y, s.z};
        for (int k = 0; k < 3; ++k) {
            cm[k] *= r123[k];
            out[k] += cm[k] * 2.0f * sv[k];
        }
    }
    return v3(sy_rt_maxf(out[0], 0.0f), sy_rt_maxf(out[1], 0.0f), sy_rt_maxf(out[2], 0.0f));
}
