/* sy_rt_bsdf.h — the path tracer's BSDF: the glTF 2.0 metallic-roughness model as a physically
 * based, energy-conserving mixture of
 *   - metal:       GGX microfacet reflection (Smith height-correlated masking-shadowing, Schlick
 *                  Fresnel with F0 = base colour), weight metallic;
 *   - dielectric:  GGX specular with F = specular * Schlick(F0 = min(((ior-1)/(ior+1))^2 x
 *                  specular colour, 1)) over Lambert diffuse scaled by (1 - max(F)), weight
 *                  (1 - metallic)(1 - transmission) (KHR_materials_specular as its specification
 *                  layers it);
 *   - transmission: solid dielectric with exact Fresnel, reflection or refraction through a GGX
 *                  microfacet (tinted by the base colour), weight (1 - metallic) transmission;
 *   - clearcoat:   KHR_materials_clearcoat's coat on top of all of them: a GGX lobe with F0 0.04
 *                  and its own roughness, weight clearcoat; the base below is scaled by
 *                  1 - clearcoat x Fresnel(n . wo), the specification's albedo scaling; the coat
 *                  follows its own normal (the vertex normal with the coat's normal map, not the
 *                  base's), where wi is above both;
 *   - sheen:       KHR_materials_sheen's Charlie lobe (sy_rt_sheen.h) between the coat and the base,
 *                  colour sheen colour; the base below is scaled by 1 - max(sheen colour) x
 *                  E_sheen(n . wo) (the specification's albedo scaling, E clamped to 1); sampled
 *                  cosine-weighted;
 *   - iridescence: KHR_materials_iridescence replaces the metal's and the dielectric's Fresnel by
 *                  mix(Schlick, thin film (sy_rt_iridescence.h), iridescence) at the half vector
 *                  (the lobe choice uses Schlick: the estimate stays unbiased);
 *   - anisotropy:  KHR_materials_anisotropy turns the metal's and the dielectric's GGX lobes
 *                  anisotropic (alpha_t = mix(alpha, 1, strength^2) along the anisotropy direction,
 *                  alpha_b = alpha across it, as the specification and the Sample Viewer do), with
 *                  the anisotropic Smith terms and visible-normal sampling; the transmission lobe
 *                  stays isotropic.
 * Roughness below SY_RT_BSDF_DELTA_ROUGHNESS is a perfect mirror / smooth interface (delta lobes).
 * Lobes with a finite density ("evaluable") take part in next-event estimation and MIS; delta lobes
 * and the transmission lobe are sampled only. Sampling picks one lobe by its estimated albedo and
 * GGX directions come from the distribution of visible normals (Heitz 2018).
 * Internal to backends/rt. */
#ifndef SY_RT_BSDF_H
#define SY_RT_BSDF_H

#include "sy_rt_surface.h"

#define SY_RT_BSDF_DELTA_ROUGHNESS 0.03f

typedef struct sy_rt_bsdf {
    sy_rt_v3 n, t, b;   /* shading frame; n faces the incoming ray's side */
    sy_rt_v3 ng;        /* geometric normal on the same side */
    sy_rt_v3 base;
    float alpha;        /* GGX alpha = roughness^2 */
    bool delta;         /* roughness below the delta threshold */
    bool front;         /* the ray arrived on the front side (for the refraction ratio) */
    float ior, f0d;     /* ((ior - 1) / (ior + 1))^2 */
    sy_rt_v3 f0c;       /* dielectric F0: min(f0d x KHR_materials_specular colour, 1) */
    float spec;         /* KHR_materials_specular factor: scales the dielectric Fresnel term */
    bool lambert;       /* only the diffuse lobe is evaluated (spec 0, no metal, sheen or glossy coat) */
    float w_metal, w_diel, w_trans; /* the base's lobes, already x base_scale */
    float cc, cc_alpha; /* KHR_materials_clearcoat: weight and GGX alpha of the coat (F0 0.04) */
    bool cc_delta;      /* the coat is a smooth mirror */
    bool cc_n;          /* the coat has its own shading normal ncc (else ncc = n) */
    sy_rt_v3 ncc;       /* the coat's shading normal (vertex normal + the coat's normal map) */
    float base_scale;   /* 1 - cc x Fresnel_coat(n . wo): what the coat lets through to the base */
    float under;        /* base_scale x the sheen's 1 - max(sheen) x E: what reaches the base lobes */
    sy_rt_v3 sheen;     /* KHR_materials_sheen colour, already x the coat's base_scale (0: none) */
    float sheen_r;      /* its roughness */
    float irid, irid_ior, irid_thick; /* KHR_materials_iridescence weight (0: none), film index, nm */
    bool aniso;         /* KHR_materials_anisotropy: t is its direction, ax/ay the GGX alphas along t/b */
    float ax, ay;
    float q_metal, q_spec, q_diff, q_coat, q_trans, q_sheen; /* lobe selection probabilities (sum 1 or all 0) */
} sy_rt_bsdf;

/* Builds the BSDF of a surface hit seen from direction wo (unit, away from the surface). */
void sy_rt_bsdf_init(sy_rt_bsdf *b, const sy_rt_surface *s, sy_rt_v3 wo);

/* True when some lobe has a finite density (worth a light sample). */
static inline bool sy_rt_bsdf_evaluable(const sy_rt_bsdf *b)
{
    return b->q_diff > 0.0f || (!b->delta && (b->q_metal > 0.0f || b->q_spec > 0.0f)) || (!b->cc_delta && b->q_coat > 0.0f) ||
           b->q_sheen > 0.0f;
}

/* f(wo, wi) * |cos(n, wi)| of the evaluable lobes, and their mixture pdf (solid angle) in *pdf. */
sy_rt_v3 sy_rt_bsdf_eval(const sy_rt_bsdf *b, sy_rt_v3 wo, sy_rt_v3 wi, float *pdf);

typedef struct sy_rt_bsdf_sample {
    sy_rt_v3 wi;
    sy_rt_v3 weight;  /* f * cos / pdf (throughput multiplier) */
    float pdf;        /* mixture pdf of the evaluable lobes for MIS; 0 for delta/transmission */
    bool specular;    /* delta or transmission lobe: no MIS, no next-event estimate possible */
    bool transmit;    /* wi goes to the other side of the surface */
} sy_rt_bsdf_sample;

/* Samples a direction from u[0] (lobe choice, reused), u[1], u[2]. Returns false when the path
 * ends (no lobe, direction below the surface). */
bool sy_rt_bsdf_sample_dir(const sy_rt_bsdf *b, sy_rt_v3 wo, const float u[3], sy_rt_bsdf_sample *out);

/* Packs what sy_rt_bsdf_eval needs into a path record's opaque bsdf floats (sy_rt.h
 * >>path records); sy_rt_pt_record_bsdf unpacks and evaluates it. */
void sy_rt_bsdf_pack(const sy_rt_bsdf *b, float out[SY_RT_RECORD_BSDF_FLOATS]);

#endif /* SY_RT_BSDF_H */
