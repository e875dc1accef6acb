/* sy_gl_ibl.h — internal: image-based lighting for the rasterizer, computed on the GPU.
 *
 * From a lat-long environment texture (the convention of the shared look: direction d maps to
 * u = 0.5 + atan2(d.x, -d.z) / (2 pi), v = acos(d.y) / pi, row 0 up; texels are radiance) it builds
 *  - a prefiltered specular cube map: `side` texels per side at mip 0 (SY_GL_IBL_SPEC_MIN to
 *    SY_GL_IBL_SPEC_SIZE: the caller sizes it for its frames, see sy_gl_ibl_side) and one GGX
 *    roughness per mip (roughness = mip / (levels - 1)), importance-sampled with filtered
 *    importance sampling (source mip chosen from the sample's pdf), N = V = R as in the split sum;
 *  - an irradiance cube map (SY_GL_IBL_IRR_SIZE per side) holding the cosine-weighted mean radiance
 *    E(n) / pi, so that Lambert is base x texel;
 * and once per device, on the CPU, the split-sum BRDF table (32 x 32, x = n.v, y = roughness; RG = A,
 * B of the height-correlated Smith GGX with Schlick: specular = F0 A + B; B = the sheen lobe's
 * directional albedo, y = sheen roughness) and the LTC tables (backends/ltc/sy_ltc.h).
 *
 * Ownership: the GL objects belong to the sy_gl_ibl struct (sy_gl_ibl_free). Thread-safety: the
 * caller's GL context must be current. */
#ifndef SY_GL_IBL_H
#define SY_GL_IBL_H

#include "sy_gl_context.h"

#define SY_GL_IBL_SPEC_SIZE 256u /* the largest side */
#define SY_GL_IBL_SPEC_MIN 64u
#define SY_GL_IBL_SPEC_LEVELS 6u /* 256 .. 8 (64 .. 2): roughness 0, 0.2, ..., 1 */
#define SY_GL_IBL_IRR_SIZE 16u
#define SY_GL_IBL_BRDF_SIZE 32u

typedef struct sy_gl_ibl {
    GLuint prog_spec; /* both cubes' (u_rough < 0: the irradiance) */
    GLint spec_face, spec_rough, spec_size, spec_src;
    GLuint fbo, vao;
    GLuint brdf_lut, ltc1, ltc2; /* once per device */
    GLuint spec_cube, irr_cube;  /* per environment */
    uint32_t spec_side;          /* spec_cube's side at mip 0 (0: none yet) */
} sy_gl_ibl;

/* The specular cube's side for w x h frames: the power of two at or above half the larger side,
 * within [SY_GL_IBL_SPEC_MIN, SY_GL_IBL_SPEC_SIZE] (a mirror filling the frame shows a face over
 * about that many pixels; a 200x150 frame prefilters 128, not 256: four times fewer samples). */
uint32_t sy_gl_ibl_side(uint32_t w, uint32_t h);

/* Computes the BRDF table and uploads it with the LTC tables (no-op when done). */
sy_gl_result sy_gl_ibl_tables(const sy_gl_fns *gl, sy_gl_ibl *ibl, sy_gl_report *rep);
/* (Re)computes both cube maps from a lat-long RGBA float texture with mipmaps (src_w x src_h at
 * level 0) scaled by intensity, the specular one `side` texels per side (sy_gl_ibl_side). Leaves
 * the framebuffer binding at 0 and the viewport changed. */
sy_gl_result sy_gl_ibl_prefilter(const sy_gl_fns *gl, sy_gl_ibl *ibl, GLuint src, uint32_t src_w, uint32_t src_h,
                                 float intensity, uint32_t side, sy_gl_report *rep);
void sy_gl_ibl_free(const sy_gl_fns *gl, sy_gl_ibl *ibl);

#endif /* SY_GL_IBL_H */
