/* sy_gl_ibl.c — image-based lighting on the GPU: prefiltered GGX cube, irradiance cube, split-sum
 * BRDF table and the LTC tables (see sy_gl_ibl.h). */
#include "sy_gl_ibl.h"

#include "sy_ltc.h"
#include "sy_gl_shaders.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define IBL_COMMON                                                                                           \
    "const float PI = 3.14159265359;\n"                                                                      \
    "float radinv(uint b) { b = (b << 16u) | (b >> 16u);\n"                                                  \
    "  b = ((b & 0x55555555u) << 1u) | ((b & 0xAAAAAAAAu) >> 1u); b = ((b & 0x33333333u) << 2u) | ((b & 0xCCCCCCCCu) >> 2u);\n" \
    "  b = ((b & 0x0F0F0F0Fu) << 4u) | ((b & 0xF0F0F0F0u) >> 4u); b = ((b & 0x00FF00FFu) << 8u) | ((b & 0xFF00FF00u) >> 8u);\n" \
    "  return float(b) * 2.3283064365386963e-10; }\n"                                                        \
    "mat3 basis(vec3 n) { vec3 up = abs(n.y) < 0.999 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0);\n"         \
    "  vec3 t = normalize(cross(up, n)); return mat3(t, cross(n, t), n); }\n"                                \
    "vec3 ggx_h(vec2 xi, float a2) { float phi = 2.0 * PI * xi.x;\n"                                         \
    "  float c = sqrt((1.0 - xi.y) / (1.0 + (a2 - 1.0) * xi.y)), s = sqrt(max(0.0, 1.0 - c * c));\n"       \
    "  return vec3(s * cos(phi), s * sin(phi), c); }\n"

/* cube faces in GL order; s, t in [-1, 1] from the face texel (row 0 = t -1) */
#define IBL_CUBE                                                                                             \
    "uniform sampler2D t_src; uniform int u_face; uniform vec4 u_size;\n" /* face size, src texel sa, intensity, samples */ \
    "vec3 face_dir(vec2 st) { float s = st.x, t = st.y;\n"                                                   \
    "  if (u_face == 0) return vec3(1.0, -t, -s); if (u_face == 1) return vec3(-1.0, -t, s);\n"            \
    "  if (u_face == 2) return vec3(s, 1.0, t); if (u_face == 3) return vec3(s, -1.0, -t);\n"              \
    "  if (u_face == 4) return vec3(s, -t, 1.0); return vec3(-s, -t, -1.0); }\n"                            \
    "vec2 latlong(vec3 d) { return vec2(0.5 + atan(d.x, -d.z) * (0.5 / PI), acos(clamp(d.y, -1.0, 1.0)) / PI); }\n" \
    "vec3 src_lod(vec3 d, float sa) {\n" /* filtered importance sampling: the source mip for solid angle sa */ \
    "  float texel = u_size.y * max(sqrt(max(0.0, 1.0 - d.y * d.y)), 1e-3);\n"                             \
    "  return textureLod(t_src, latlong(d), max(0.5 * log2(sa / texel) + 1.0, 0.0)).rgb; }\n"

/* Both cubes in one program (u_rough < 0: the irradiance; else the specular mip of that roughness):
 * llvmpipe compiles each program on its first draw, one compile less in every first frame with an
 * environment (issue 32). */
static const char *const prefilter_fs =
    "#version 330 core\n" IBL_COMMON IBL_CUBE
    "uniform float u_rough; out vec4 o;\n"
    "vec4 irradiance(vec3 N) {\n"
    "  mat3 B = basis(N); vec3 sum = vec3(0.0); uint n = uint(u_size.w);\n"
    "  for (uint i = 0u; i < n; ++i) {\n"
    "    float u = (float(i) + 0.5) / float(n), v = radinv(i), r = sqrt(v), phi = 2.0 * PI * u;\n"
    "    vec3 l = vec3(r * cos(phi), r * sin(phi), sqrt(max(0.0, 1.0 - v)));\n"
    "    sum += src_lod(B * l, PI / (float(n) * max(l.z, 1e-3))); }\n"
    "  return vec4(sum / float(n) * u_size.z, 1.0); }\n"
    "void main() { vec3 N = normalize(face_dir(gl_FragCoord.xy / u_size.x * 2.0 - 1.0));\n"
    "  if (u_rough < 0.0) { o = irradiance(N); return; }\n"
    "  if (u_rough <= 0.0) {\n"
    "    float texel = u_size.y * max(sqrt(max(0.0, 1.0 - N.y * N.y)), 1e-3);\n"
    "    float lod = max(0.5 * log2(4.0 / (u_size.x * u_size.x) / texel), 0.0);\n"
    "    o = vec4(textureLod(t_src, latlong(N), lod).rgb * u_size.z, 1.0); return; }\n"
    "  float a = u_rough * u_rough, a2 = a * a; mat3 B = basis(N); vec3 sum = vec3(0.0); float w = 0.0;\n"
    "  uint n = uint(u_size.w);\n"
    "  for (uint i = 0u; i < n; ++i) {\n"
    "    vec3 h = ggx_h(vec2((float(i) + 0.5) / float(n), radinv(i)), a2); vec3 H = B * h;\n"
    "    vec3 L = 2.0 * h.z * H - N; float nl = dot(N, L); if (nl <= 0.0) continue;\n"
    "    float dd = h.z * h.z * (a2 - 1.0) + 1.0; float pdf = a2 / (PI * dd * dd) * 0.25;\n"
    "    sum += src_lod(L, 1.0 / (float(n) * pdf)) * nl; w += nl; }\n"
    "  o = vec4(sum / max(w, 1e-6) * u_size.z, 1.0); }\n";

/* The split-sum BRDF table, on the CPU (it was a fragment shader: llvmpipe compiled it for about
 * 0.07 s of every first frame with an environment, area lights or material layers, issue 32; this
 * costs a few milliseconds). Per texel (x, y) of the SY_GL_IBL_BRDF_SIZE square, n.v = max(x / 31,
 * 1e-3) and roughness r = y / 31, V = (sqrt(1 - nv^2), 0, nv):
 *  R, G: the GGX lobe's scale A and bias B (height-correlated Smith visibility, Schlick Fresnel), from
 *  512 Hammersley half-vectors of the GGX distribution (alpha = max(r^2, 1e-4));
 *  B: the sheen lobe's directional albedo E(n.v, sheen roughness) (KHR_materials_sheen: Charlie
 *  distribution, alpha = max(r^2, 1e-4), Neubelt visibility 1 / (4 (n.l + n.v - n.l n.v))), by uniform
 *  hemisphere sampling (256 Hammersley points), at most 1; sy_gl_shaders_layers.c reads it.
 * The sample directions depend on the sample's index alone: computed once, in float as the shader
 * did. */
/* The radical inverse of i in base 2 (van der Corput), digit by digit: exact in float for the
 * tables' few hundred indices, the same values as the shaders' bit-reversing radinv. */
static float radinv(uint32_t i)
{
    float v = 0.0f;
    for (float f = 0.5f; i; i >>= 1, f *= 0.5f)
        if (i & 1u) v += f;
    return v;
}

#define BRDF_GGX_SAMPLES 512u
#define BRDF_SHEEN_SAMPLES 256u

static void brdf_table(float *out)
{
    const float pi = 3.14159265359f;
    float gcos[BRDF_GGX_SAMPLES], gy[BRDF_GGX_SAMPLES]; /* H.y does not enter: V.y = 0 */
    float scl[BRDF_SHEEN_SAMPLES], ssl[BRDF_SHEEN_SAMPLES], scos[BRDF_SHEEN_SAMPLES], ssin[BRDF_SHEEN_SAMPLES];
    for (uint32_t i = 0; i < BRDF_GGX_SAMPLES; ++i) {
        float phi = 2.0f * pi * (((float)i + 0.5f) / (float)BRDF_GGX_SAMPLES);
        gcos[i] = cosf(phi), gy[i] = radinv(i);
    }
    for (uint32_t i = 0; i < BRDF_SHEEN_SAMPLES; ++i) {
        float cl = ((float)i + 0.5f) / (float)BRDF_SHEEN_SAMPLES, phi = 2.0f * pi * radinv(i);
        scl[i] = cl, ssl[i] = sqrtf(fmaxf(0.0f, 1.0f - cl * cl)), scos[i] = cosf(phi), ssin[i] = sinf(phi);
    }
    const uint32_t n = SY_GL_IBL_BRDF_SIZE;
    for (uint32_t y = 0; y < n; ++y)
        for (uint32_t x = 0; x < n; ++x) {
            float nv = fmaxf((float)x / (float)(n - 1u), 1e-3f), r = (float)y / (float)(n - 1u);
            float a = fmaxf(r * r, 1e-4f), a2 = a * a, vx = sqrtf(1.0f - nv * nv), vz = nv;
            float A = 0.0f, Bv = 0.0f;
            for (uint32_t i = 0; i < BRDF_GGX_SAMPLES; ++i) {
                float c = sqrtf((1.0f - gy[i]) / (1.0f + (a2 - 1.0f) * gy[i])), sn = sqrtf(fmaxf(0.0f, 1.0f - c * c));
                float hx = sn * gcos[i], hz = c;
                float vh = vx * hx + vz * hz, nl = 2.0f * vh * hz - vz;
                if (nl <= 0.0f || vh <= 0.0f) continue;
                float vis = 0.5f / (nl * sqrtf(nv * nv * (1.0f - a2) + a2) + nv * sqrtf(nl * nl * (1.0f - a2) + a2));
                float gv = vis * 4.0f * nl * vh / fmaxf(hz, 1e-6f), m = 1.0f - vh, fc = m * m * m * m * m;
                A += (1.0f - fc) * gv;
                Bv += fc * gv;
            }
            float inv = 1.0f / a, E = 0.0f; /* the sheen's alpha: max(r^2, 1e-4), as the GGX's */
            for (uint32_t i = 0; i < BRDF_SHEEN_SAMPLES; ++i) {
                float lx = ssl[i] * scos[i], ly = ssl[i] * ssin[i], lz = scl[i];
                float hx = vx + lx, hy = ly, hz = vz + lz, len = sqrtf(hx * hx + hy * hy + hz * hz);
                hz /= len;
                float s2 = fmaxf(1.0f - hz * hz, 0.0f), D = (2.0f + inv) * powf(s2, 0.5f * inv) / (2.0f * pi);
                E += D * lz / (4.0f * (lz + nv - lz * nv));
            }
            float *o = out + 4u * (y * n + x);
            o[0] = A / (float)BRDF_GGX_SAMPLES;
            o[1] = Bv / (float)BRDF_GGX_SAMPLES;
            o[2] = fminf(E * 2.0f * pi / (float)BRDF_SHEEN_SAMPLES, 1.0f);
            o[3] = 1.0f;
        }
}

static sy_gl_result build(const sy_gl_fns *gl, sy_gl_ibl *ibl, sy_gl_report *rep)
{
    if (ibl->prog_spec) return SY_GL_OK;
    sy_gl_result r = sy_gl_program_build(gl, "IBL prefilter", sy_gl_fullscreen_vs, prefilter_fs, NULL, &ibl->prog_spec, rep);
    if (r != SY_GL_OK) return r;
    ibl->spec_face = gl->GetUniformLocation(ibl->prog_spec, "u_face");
    ibl->spec_rough = gl->GetUniformLocation(ibl->prog_spec, "u_rough");
    ibl->spec_size = gl->GetUniformLocation(ibl->prog_spec, "u_size");
    ibl->spec_src = gl->GetUniformLocation(ibl->prog_spec, "t_src");
    gl->GenFramebuffers(1, &ibl->fbo);
    gl->GenVertexArrays(1, &ibl->vao);
    return SY_GL_OK;
}

static GLuint table_tex(const sy_gl_fns *gl, GLint internal, GLsizei size, GLenum format, const float *data)
{
    GLuint t;
    gl->GenTextures(1, &t);
    gl->BindTexture(GL_TEXTURE_2D, t);
    gl->PixelStorei(GL_UNPACK_ALIGNMENT, 4);
    gl->TexImage2D(GL_TEXTURE_2D, 0, internal, size, size, 0, format, GL_FLOAT, data);
    gl->TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    gl->TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    gl->TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    gl->TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    return t;
}

static sy_gl_result fb_check(const sy_gl_fns *gl, const char *what, sy_gl_report *rep)
{
    GLenum st = gl->CheckFramebufferStatus(GL_FRAMEBUFFER);
    if (st == GL_FRAMEBUFFER_COMPLETE) return SY_GL_OK;
    return sy_gli_fail(rep, SY_GL_ERROR_GL, "%s: framebuffer incomplete (0x%04x)", what, (unsigned)st);
}

sy_gl_result sy_gl_ibl_tables(const sy_gl_fns *gl, sy_gl_ibl *ibl, sy_gl_report *rep)
{
    if (ibl->brdf_lut) return SY_GL_OK;
    const size_t brdf_floats = 4u * SY_GL_IBL_BRDF_SIZE * SY_GL_IBL_BRDF_SIZE;
    float *ltc = malloc((2 * SY_LTC_FLOATS + brdf_floats) * sizeof *ltc);
    if (!ltc) return sy_gli_fail(rep, SY_GL_ERROR_OUT_OF_MEMORY, "LTC and BRDF tables: out of memory");
    float *brdf = ltc + 2 * SY_LTC_FLOATS;
    sy_ltc_tables(ltc, ltc + SY_LTC_FLOATS);
    brdf_table(brdf);
    ibl->ltc1 = table_tex(gl, GL_RGBA32F, SY_LTC_SIZE, GL_RGBA, ltc);
    ibl->ltc2 = table_tex(gl, GL_RGBA32F, SY_LTC_SIZE, GL_RGBA, ltc + SY_LTC_FLOATS);
    ibl->brdf_lut = table_tex(gl, GL_RGBA32F, SY_GL_IBL_BRDF_SIZE, GL_RGBA, brdf);
    free(ltc);
    return SY_GL_OK;
}

static GLuint cube_tex(const sy_gl_fns *gl, uint32_t size, uint32_t levels)
{
    GLuint t;
    gl->GenTextures(1, &t);
    gl->BindTexture(GL_TEXTURE_CUBE_MAP, t);
    for (uint32_t l = 0; l < levels; ++l)
        for (int f = 0; f < 6; ++f)
            gl->TexImage2D(GL_TEXTURE_CUBE_MAP_POSITIVE_X + (GLenum)f, (GLint)l, GL_RGBA16F, (GLsizei)(size >> l),
                           (GLsizei)(size >> l), 0, GL_RGBA, GL_FLOAT, NULL);
    gl->TexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_BASE_LEVEL, 0);
    gl->TexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MAX_LEVEL, (GLint)levels - 1);
    gl->TexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MIN_FILTER, levels > 1 ? GL_LINEAR_MIPMAP_LINEAR : GL_LINEAR);
    gl->TexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    gl->TexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    gl->TexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    gl->TexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
    return t;
}

uint32_t sy_gl_ibl_side(uint32_t w, uint32_t h)
{
    uint32_t half = (w > h ? w : h) / 2u, s = SY_GL_IBL_SPEC_MIN;
    while (s < half && s < SY_GL_IBL_SPEC_SIZE) s *= 2u;
    return s;
}

sy_gl_result sy_gl_ibl_prefilter(const sy_gl_fns *gl, sy_gl_ibl *ibl, GLuint src, uint32_t src_w, uint32_t src_h,
                                 float intensity, uint32_t side, sy_gl_report *rep)
{
    sy_gl_result r = build(gl, ibl, rep);
    if (r != SY_GL_OK) return r;
    side = side < SY_GL_IBL_SPEC_MIN ? SY_GL_IBL_SPEC_MIN : side > SY_GL_IBL_SPEC_SIZE ? SY_GL_IBL_SPEC_SIZE : side;
    if (ibl->spec_cube && ibl->spec_side != side) {
        gl->DeleteTextures(1, &ibl->spec_cube);
        ibl->spec_cube = 0;
    }
    if (!ibl->spec_cube) ibl->spec_cube = cube_tex(gl, side, SY_GL_IBL_SPEC_LEVELS);
    ibl->spec_side = side;
    if (!ibl->irr_cube) ibl->irr_cube = cube_tex(gl, SY_GL_IBL_IRR_SIZE, 1);
    gl->Enable(GL_TEXTURE_CUBE_MAP_SEAMLESS);
    gl->Disable(GL_DEPTH_TEST);
    gl->Disable(GL_BLEND);
    gl->Disable(GL_MULTISAMPLE);
    gl->BindFramebuffer(GL_FRAMEBUFFER, ibl->fbo);
    gl->DrawBuffer(GL_COLOR_ATTACHMENT0);
    gl->BindVertexArray(ibl->vao);
    gl->ActiveTexture(GL_TEXTURE0);
    gl->BindTexture(GL_TEXTURE_2D, src);
    const float texel_sa = 2.0f * 3.14159265f * 3.14159265f / ((float)src_w * (float)src_h);
    for (int pass = 0; pass < 2 && r == SY_GL_OK; ++pass) {
        GLuint cube = pass ? ibl->irr_cube : ibl->spec_cube;
        uint32_t levels = pass ? 1u : SY_GL_IBL_SPEC_LEVELS, size0 = pass ? SY_GL_IBL_IRR_SIZE : side;
        gl->UseProgram(ibl->prog_spec);
        gl->Uniform1i(ibl->spec_src, 0);
        for (uint32_t l = 0; l < levels && r == SY_GL_OK; ++l) {
            uint32_t size = size0 >> l;
            float rough = pass ? -1.0f : (float)l / (float)(SY_GL_IBL_SPEC_LEVELS - 1); /* -1: the irradiance */
            float samples = pass ? 256.0f : l == 1 ? 64.0f : 128.0f;
            const float u_size[4] = {(float)size, texel_sa, intensity, samples};
            gl->Uniform4fv(ibl->spec_size, 1, u_size);
            gl->Uniform1f(ibl->spec_rough, rough);
            gl->Viewport(0, 0, (GLsizei)size, (GLsizei)size);
            for (int f = 0; f < 6 && r == SY_GL_OK; ++f) {
                gl->FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_CUBE_MAP_POSITIVE_X + (GLenum)f,
                                         cube, (GLint)l);
                if (f == 0 && l == 0) r = fb_check(gl, pass ? "irradiance cube" : "specular cube", rep);
                if (r != SY_GL_OK) break;
                gl->Uniform1i(ibl->spec_face, f);
                gl->DrawArrays(GL_TRIANGLES, 0, 3);
            }
        }
    }
    gl->FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, 0, 0);
    gl->BindFramebuffer(GL_FRAMEBUFFER, 0);
    return r;
}

void sy_gl_ibl_free(const sy_gl_fns *gl, sy_gl_ibl *ibl)
{
    if (ibl->prog_spec) gl->DeleteProgram(ibl->prog_spec);
    GLuint texs[5] = {ibl->brdf_lut, ibl->ltc1, ibl->ltc2, ibl->spec_cube, ibl->irr_cube};
    gl->DeleteTextures(5, texs);
    if (ibl->fbo) gl->DeleteFramebuffers(1, &ibl->fbo);
    if (ibl->vao) gl->DeleteVertexArrays(1, &ibl->vao);
    memset(ibl, 0, sizeof *ibl);
}
