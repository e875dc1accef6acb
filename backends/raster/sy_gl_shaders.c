/* sy_gl_shaders.c — the rasterizer's GLSL programs (see sy_gl_shaders.h). The main fragment
 * shader implements the same BSDF and light falloffs as backends/rt/sy_rt_whitted.c (see sy_gl.h
 * for the model); the shadow pass honours alpha masks; the resolve pass averages colour and takes
 * the nearest linear depth of the MSAA samples. */
#include "sy_gl_shaders.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Vertex attributes: 0 position, 1 normal, 2 uv0, 3 uv1, 4 colour. Variant defines (see
 * sy_gl_device.c main_program): SY_LEAN (no uv1 / colours), SY_MASK (alpha mask: discard), SY_TEX
 * (the material has a texture: uv varyings), SY_NMAP (normal map), SY_LIGHTS (punctual lights),
 * SY_AMBIENT (background ambient), SY_SHADOW (shadow maps), SY_NLIGHTS (a constant light count:
 * the loop unrolls with constant uniform-block offsets). Every varying costs set-up per
 * triangle and interpolation per fragment in a software rasterizer, so a variant interpolates only
 * what it reads; unlit variants (no lights, no ambient) need no position or normal at all. */
#define SY_GL_VARIANT_PRELUDE                                 \
    "#if defined(SY_LIGHTS) || defined(SY_AMBIENT)\n"         \
    "#define SY_LIT 1\n"                                      \
    "#endif\n"                                                \
    "#if defined(SY_TEX) && !defined(SY_LEAN)\n"              \
    "#define SY_UV1 1\n"                                      \
    "#endif\n"

const char *const sy_gl_main_vs =
    "#version 330 core\n" SY_GL_VARIANT_PRELUDE
    "layout(location=0) in vec3 a_pos; layout(location=1) in vec3 a_nrm; layout(location=2) in vec2 a_uv0;\n"
    "layout(location=3) in vec2 a_uv1; layout(location=4) in vec4 a_col;\n"
    "uniform mat4 u_model; uniform mat3 u_normal_mat; uniform mat4 u_mvp;\n" /* u_mvp = proj * view * model (CPU) */
    "#ifdef SY_LIT\n"
    "out vec3 v_wpos; out vec3 v_nrm;\n"
    "#endif\n"
    "#ifdef SY_TEX\n"
    "out vec2 v_uv0;\n"
    "#endif\n"
    "#ifdef SY_UV1\n"
    "out vec2 v_uv1;\n"
    "#endif\n"
    "#ifndef SY_LEAN\n"
    "out vec4 v_col;\n"
    "#endif\n"
    "void main() {\n"
    "#ifdef SY_LIT\n"
    "  v_wpos = (u_model * vec4(a_pos, 1.0)).xyz; v_nrm = u_normal_mat * a_nrm;\n"
    "#endif\n"
    "#ifdef SY_TEX\n"
    "  v_uv0 = a_uv0;\n"
    "#endif\n"
    "#ifdef SY_UV1\n"
    "  v_uv1 = a_uv1;\n"
    "#endif\n"
    "#ifndef SY_LEAN\n"
    "  v_col = a_col;\n"
    "#endif\n"
    "  gl_Position = u_mvp * vec4(a_pos, 1.0);\n"
    "}\n";

#define SY_GL_MATERIAL_BLOCK                                                                                 \
    "layout(std140) uniform Material {\n"                                                                    \
    "  vec4 m_base; vec4 m_emissive; vec4 m_mrna; vec4 m_oist; ivec4 m_modes; ivec4 m_tex; ivec4 m_tex2;\n" \
    "  vec4 m_xf[10];\n" /* uv transform rows per slot: base, mr, nrm, occ, emis */                          \
    "};\n"                                                                                                   \
    "uniform sampler2D t_base, t_mr, t_nrm, t_occ, t_emis;\n"                                                \
    "vec2 tuv(int k, vec2 t) { vec3 h = vec3(t, 1.0); return vec2(dot(m_xf[2*k].xyz, h), dot(m_xf[2*k+1].xyz, h)); }\n"

const char *const sy_gl_main_fs =
    "#version 330 core\n" SY_GL_VARIANT_PRELUDE SY_GL_MATERIAL_BLOCK
    "struct Light { vec4 pos_type; vec4 dir_range; vec4 radiant; vec4 cone; };\n"
    "layout(std140) uniform Lights { ivec4 l_count; vec4 l_ambient; mat4 l_shadow_mat[4]; vec4 l_shadow[4];\n"
    "  Light l_lights[32]; };\n"
    "uniform sampler2DArrayShadow t_shadow;\n"
    "uniform vec3 u_cam_pos; uniform vec3 u_cam_fwd; uniform bool u_ortho; uniform bool u_mirror;\n"
    "uniform bool u_has_normals; uniform vec3 u_ortho_z;\n" /* orthographic: proj[10], proj[14] */
    "#ifdef SY_LIT\n"
    "in vec3 v_wpos; in vec3 v_nrm;\n"
    "#endif\n"
    "#ifdef SY_TEX\n"
    "in vec2 v_uv0;\n"
    "#else\n"
    "const vec2 v_uv0 = vec2(0.0);\n"
    "#endif\n"
    "#ifdef SY_UV1\n"
    "in vec2 v_uv1;\n"
    "#else\n"
    "const vec2 v_uv1 = vec2(0.0);\n" /* absent sets read as 0, as in backends/rt */
    "#endif\n"
    "#ifdef SY_LEAN\n"
    "const vec4 v_col = vec4(1.0);\n"
    "#else\n"
    "in vec4 v_col;\n"
    "#endif\n"
    "layout(location=0) out vec4 o_color; layout(location=1) out float o_depth;\n"
    "const float INV_PI = 0.31830988618;\n"
    "vec3 schlick(vec3 f0, float c) { float m = 1.0 - clamp(c, 0.0, 1.0); float m5 = m*m*m*m*m;\n"
    "  return f0 + (vec3(1.0) - f0) * m5; }\n"
    "#ifdef SY_SHADOW\n"
    "float shadow_vis(int si, vec3 p, vec3 ngf) {\n"
    "  vec4 sp = l_shadow[si]; vec4 c0 = l_shadow_mat[si] * vec4(p, 1.0); if (c0.w <= 0.0) return 1.0;\n"
    "  float off = sp.x * (sp.y > 0.5 ? c0.w : 1.0);\n"
    "  vec4 c = l_shadow_mat[si] * vec4(p + ngf * off, 1.0); if (c.w <= 0.0) return 1.0;\n"
    "  vec3 q = c.xyz / c.w * 0.5 + 0.5; if (q.z >= 1.0) return 1.0;\n"
    "  float s = 0.0; vec2 ts = 1.0 / vec2(textureSize(t_shadow, 0).xy);\n"
    "  for (int y = -1; y <= 1; ++y) for (int x = -1; x <= 1; ++x)\n"
    "    s += texture(t_shadow, vec4(q.xy + vec2(x, y) * ts, float(si), q.z));\n"
    "  return s / 9.0; }\n"
    "#endif\n"
    "void main() {\n"
    "  vec2 uv[2] = vec2[2](v_uv0, v_uv1);\n"
    "  vec4 base = m_base * v_col;\n"
    "#ifdef SY_TEX\n"
    "  if (m_tex.x >= 0) base *= texture(t_base, tuv(0, uv[m_tex.x]));\n"
    "#endif\n"
    "  float alpha = base.a;\n"
    "#ifdef SY_MASK\n"
    "  if (alpha < m_mrna.w) discard;\n" /* discard only in this variant: it disables early depth tests */
    "#endif\n"
    "  if (m_modes.x != 2) alpha = 1.0;\n"
    "  bool front = gl_FrontFacing != u_mirror;\n"
    "  vec3 L = vec3(0.0);\n"
    "  if (m_modes.w != 0 && (front || m_modes.z != 0)) {\n"
    "    L = m_emissive.rgb;\n"
    "#ifdef SY_TEX\n"
    "    if (m_tex2.x >= 0) L *= texture(t_emis, tuv(4, uv[m_tex2.x])).rgb;\n"
    "#endif\n"
    "  } else if (m_modes.y != 0) {\n"
    "    L = base.rgb;\n"
    "  }\n"
    "#ifdef SY_LIT\n" /* without lights and ambient a surface that is neither emissive nor unlit is black */
    "  else {\n"
    "    vec3 dpx = dFdx(v_wpos), dpy = dFdy(v_wpos);\n"
    "    vec3 wo = u_ortho ? -u_cam_fwd : normalize(u_cam_pos - v_wpos);\n"
    "    vec3 ngf = normalize(cross(dpx, dpy)); if (dot(ngf, wo) < 0.0) ngf = -ngf;\n"
    "    if (any(isnan(ngf))) ngf = wo;\n"
    "    vec3 n = front ? ngf : -ngf;\n"
    "    if (u_has_normals) { vec3 sn = normalize(v_nrm); if (!any(isnan(sn))) n = sn; }\n"
    "#ifdef SY_NMAP\n"
    "    if (m_tex.z >= 0) {\n"
    "      vec2 t = tuv(2, uv[m_tex.z]); vec2 dtx = dFdx(t), dty = dFdy(t);\n"
    "      vec3 pp2 = cross(dpy, n), pp1 = cross(n, dpx);\n"
    "      vec3 dpdu = pp2 * dtx.x + pp1 * dty.x, dpdv = pp2 * dtx.y + pp1 * dty.y;\n"
    "      vec3 tg = dpdu - n * dot(n, dpdu);\n"
    "      if (dot(tg, tg) > 1e-30) {\n"
    "        tg = normalize(tg); vec3 bt = cross(n, tg); if (dot(bt, dpdv) > 0.0) bt = -bt;\n"
    "        vec3 tx = texture(t_nrm, t).xyz * 2.0 - 1.0;\n"
    "        vec3 r = tg * (tx.x * m_mrna.z) + bt * (tx.y * m_mrna.z) + n * tx.z;\n"
    "        if (dot(r, r) > 0.0) n = normalize(r);\n"
    "      }\n"
    "    }\n"
    "#endif\n"
    "    vec3 ns = front ? n : -n;\n"
    "    float metallic = m_mrna.x, rough = m_mrna.y;\n"
    "#ifdef SY_TEX\n"
    "    if (m_tex.y >= 0) { vec4 t = texture(t_mr, tuv(1, uv[m_tex.y])); rough *= t.g; metallic *= t.b; }\n"
    "#endif\n"
    "    float ior = m_oist.y, spec = m_oist.z, trans = m_oist.w;\n"
    "    float r0 = (ior - 1.0) / (ior + 1.0); float f0d = r0 * r0 * spec;\n"
    "    vec3 f0 = vec3(f0d) * (1.0 - metallic) + base.rgb * metallic;\n"
    "    vec3 kd = base.rgb * (1.0 - metallic) * (1.0 - trans);\n"
    "    float a = max(rough * rough, 1e-4), a2 = a * a;\n"
    "    float nv = max(dot(ns, wo), 1e-4);\n"
    "#ifdef SY_LIGHTS\n"
    "#ifndef SY_NLIGHTS\n"
    "#define SY_NLIGHTS l_count.x\n"
    "#endif\n"
    "    for (int i = 0; i < SY_NLIGHTS; ++i) {\n"
    "      Light l = l_lights[i]; int type = int(l.pos_type.w); vec3 wi, e;\n"
    "      if (type == 3) { wi = -l.dir_range.xyz; e = l.radiant.rgb; }\n"
    "      else {\n"
    "        wi = l.pos_type.xyz - v_wpos; float d2 = dot(wi, wi); if (!(d2 > 0.0)) continue;\n"
    "        float d = sqrt(d2); wi /= d; float att = 1.0 / d2;\n"
    "        if (l.dir_range.w > 0.0) { float x = d / l.dir_range.w; float w = clamp(1.0 - x*x*x*x, 0.0, 1.0); att *= w * w; }\n"
    "        if (type == 2) { float cd = -dot(l.dir_range.xyz, wi); float s = clamp(cd * l.cone.x + l.cone.y, 0.0, 1.0); att *= s * s; }\n"
    "        if (!(att > 0.0)) continue; e = l.radiant.rgb * att;\n"
    "      }\n"
    "      float cs = dot(ns, wi); if (cs <= 0.0 || dot(ngf, wi) <= 0.0) continue;\n"
    "#ifdef SY_SHADOW\n"
    "      int si = int(l.cone.z); float vis = si >= 0 ? shadow_vis(si, v_wpos, ngf) : 1.0;\n"
    "      if (vis <= 0.0) continue;\n"
    "#else\n"
    "      float vis = 1.0;\n"
    "#endif\n"
    "      vec3 f = kd * INV_PI;\n"
    "      if (rough > 0.0 && any(greaterThan(f0, vec3(0.0)))) {\n"
    "        vec3 h = normalize(wi + wo); float nl = cs, nh = max(dot(ns, h), 0.0);\n"
    "        float dd = nh * nh * (a2 - 1.0) + 1.0; float D = a2 * INV_PI / (dd * dd);\n"
    "        float V = 0.5 / (nl * sqrt(nv * nv * (1.0 - a2) + a2) + nv * sqrt(nl * nl * (1.0 - a2) + a2));\n"
    "        f += schlick(f0, dot(wi, h)) * (D * V);\n"
    "      }\n"
    "      L += e * f * cs * vis;\n"
    "    }\n"
    "#endif\n"
    "#ifdef SY_AMBIENT\n"
    "    float ao = 1.0;\n"
    "#ifdef SY_TEX\n"
    "    if (m_tex.w >= 0) ao = 1.0 + m_oist.x * (texture(t_occ, tuv(3, uv[m_tex.w])).r - 1.0);\n"
    "#endif\n"
    "    L += l_ambient.rgb * (kd + schlick(f0, nv)) * ao;\n"
    "#endif\n"
    "  }\n"
    "#endif\n"
    "  o_color = vec4(L * alpha, alpha);\n"
    /* linear view depth from the window coordinates: 1/w_clip = 1/z_view in perspective, the
     * inverse depth mapping in orthographic views; one varying less */
    "  o_depth = u_ortho ? -((gl_FragCoord.z * 2.0 - 1.0) - u_ortho_z.y) / u_ortho_z.x : 1.0 / gl_FragCoord.w;\n"
    "}\n";

const char *const sy_gl_shadow_vs =
    "#version 330 core\n"
    "layout(location=0) in vec3 a_pos; layout(location=2) in vec2 a_uv0; layout(location=3) in vec2 a_uv1;\n"
    "layout(location=4) in vec4 a_col;\n"
    "uniform mat4 u_model; uniform mat4 u_lightvp; out vec2 v_uv0; out vec2 v_uv1; out float v_a;\n"
    "void main() { v_uv0 = a_uv0; v_uv1 = a_uv1; v_a = a_col.a; gl_Position = u_lightvp * u_model * vec4(a_pos, 1.0); }\n";

const char *const sy_gl_shadow_fs =
    "#version 330 core\n" SY_GL_MATERIAL_BLOCK
    "in vec2 v_uv0; in vec2 v_uv1; in float v_a;\n"
    "void main() {\n"
    "#ifdef SY_MASK\n"
    "  float a = m_base.a * v_a; vec2 uv[2] = vec2[2](v_uv0, v_uv1);\n"
    "  if (m_tex.x >= 0) a *= texture(t_base, tuv(0, uv[m_tex.x])).a;\n"
    "  if (a < m_mrna.w) discard;\n"
    "#endif\n"
    "}\n";

const char *const sy_gl_resolve_vs =
    "#version 330 core\n"
    "void main() { vec2 p = vec2(float((gl_VertexID & 1) * 4 - 1), float((gl_VertexID & 2) * 2 - 1));\n"
    "  gl_Position = vec4(p, 0.0, 1.0); }\n";

const char *const sy_gl_resolve_fs =
    "#version 330 core\n"
    "uniform sampler2DMS t_color; uniform sampler2DMS t_depth; uniform int u_samples;\n"
    "layout(location=0) out vec4 o_color; layout(location=1) out float o_depth;\n"
    "void main() { ivec2 p = ivec2(gl_FragCoord.xy); vec4 c = vec4(0.0); float d = uintBitsToFloat(0x7F800000u);\n"
    "  for (int i = 0; i < u_samples; ++i) { c += texelFetch(t_color, p, i); d = min(d, texelFetch(t_depth, p, i).r); }\n"
    "  o_color = c / float(u_samples); o_depth = d; }\n";

const char *const sy_gl_floor_vs =
    "#version 330 core\n"
    "layout(location=0) in vec3 a_pos; uniform mat4 u_model; uniform mat4 u_view; uniform mat4 u_proj;\n"
    "out float v_vz;\n"
    "void main() { vec4 e = u_view * u_model * vec4(a_pos, 1.0); v_vz = -e.z; gl_Position = u_proj * e; }\n";

const char *const sy_gl_floor_fs =
    "#version 330 core\n"
    "in float v_vz; layout(location=0) out vec4 o_color; layout(location=1) out float o_depth;\n"
    "void main() { o_color = vec4(0.8, 0.8, 0.8, 1.0); o_depth = v_vz; }\n";

static sy_gl_result compile(const sy_gl_fns *gl, const char *name, GLenum stage, const char *src, const char *defines,
                            GLuint *out, char *err, size_t err_len)
{
    GLuint s = gl->CreateShader(stage);
    /* defines go right after the #version line */
    const char *nl = strchr(src, '\n');
    const char *parts[3] = {src, defines ? defines : "", nl ? nl + 1 : ""};
    GLint lens[3] = {nl ? (GLint)(nl + 1 - src) : -1, -1, -1};
    gl->ShaderSource(s, nl ? 3 : 1, parts, nl ? lens : NULL);
    gl->CompileShader(s);
    GLint ok = 0;
    gl->GetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[2048] = "";
        gl->GetShaderInfoLog(s, sizeof log, NULL, log);
        gl->DeleteShader(s);
        if (err && err_len)
            snprintf(err, err_len, "%s shader: %s compile failed: %s", name,
                     stage == GL_VERTEX_SHADER ? "vertex" : "fragment", log);
        return SY_GL_ERROR_GL;
    }
    *out = s;
    return SY_GL_OK;
}

sy_gl_result sy_gl_program_build(const sy_gl_fns *gl, const char *name, const char *vs, const char *fs,
                                 const char *fs_defines, GLuint *out, char *err, size_t err_len)
{
    GLuint v = 0, f = 0;
    sy_gl_result r = compile(gl, name, GL_VERTEX_SHADER, vs, fs_defines, &v, err, err_len);
    if (r == SY_GL_OK) r = compile(gl, name, GL_FRAGMENT_SHADER, fs, fs_defines, &f, err, err_len);
    if (r != SY_GL_OK) {
        if (v) gl->DeleteShader(v);
        return r;
    }
    GLuint p = gl->CreateProgram();
    gl->AttachShader(p, v);
    gl->AttachShader(p, f);
    gl->LinkProgram(p);
    gl->DeleteShader(v);
    gl->DeleteShader(f);
    GLint ok = 0;
    gl->GetProgramiv(p, GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[2048] = "";
        gl->GetProgramInfoLog(p, sizeof log, NULL, log);
        gl->DeleteProgram(p);
        if (err && err_len) snprintf(err, err_len, "%s shader: link failed: %s", name, log);
        return SY_GL_ERROR_GL;
    }
    *out = p;
    return SY_GL_OK;
}
