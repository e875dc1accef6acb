/* sy_gl_shaders.c — the rasterizer's GLSL programs (see sy_gl_shaders.h). The main fragment
 * shader implements the same BSDF as backends/rt's path tracer (see sy_gl.h for the model): punctual
 * lights exactly, emissive polygons with linearly transformed cosines, the environment with the
 * split-sum approximation (prefiltered GGX cube + irradiance cube + BRDF LUT); the shadow pass
 * honours alpha masks; the sky pass draws the background; the resolve pass averages colour and
 * takes the nearest linear depth of the MSAA samples; the IBL programs prefilter the environment. */
#include "sy_gl_shaders.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Vertex attributes: 0 position, 1 normal, 2 uv0, 3 uv1, 4 colour. Variant defines (see
 * sy_gl_programs.c main_program): SY_LEAN (no uv1 / colours), SY_MASK (alpha mask: discard), SY_TEX
 * (the material has a texture: uv varyings), SY_NMAP (normal map), SY_LIGHTS (punctual lights),
 * SY_ENV (environment light), SY_AREA (emissive polygons), SY_SHADOW (punctual shadow maps),
 * SY_ASHADOW (area-light shadow maps), SY_PROBE (reflections and refraction see the object's scene
 * probe instead of the environment), SY_TRANS (a transmissive material; llvmpipe runs both sides of a branch, so code that no
 * light of this frame needs is left out of the variant), SY_NLIGHTS (a constant light count, 1 ..
 * 7: one call per light with constant uniform-block offsets) with SY_LK0 .. SY_LK<n-1> (each
 * light's kind of shadow, see shade_light); the emissive polygons run in two loops of uniform
 * bounds (see shade_lit). Every varying costs set-up per
 * triangle and interpolation per fragment in a software rasterizer, so a variant interpolates only
 * what it reads; unlit variants (no lights, no environment) need no position or normal at all. */
#define SY_GL_VARIANT_PRELUDE                                 \
    "#if defined(SY_LIGHTS) || defined(SY_ENV) || defined(SY_AREA) || defined(SY_PROBE)\n" \
    "#define SY_LIT 1\n"                                      \
    "#endif\n"                                                \
    "#if defined(SY_TEX) && !defined(SY_LEAN)\n"              \
    "#define SY_UV1 1\n"                                      \
    "#endif\n"

const char *const sy_gl_main_vs =
    "#version 330 core\n" SY_GL_VARIANT_PRELUDE SY_GL_CLIP_VS
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
    "  vec3 wpos = (u_model * vec4(a_pos, 1.0)).xyz; sy_clip(wpos);\n"
    "#ifdef SY_LIT\n"
    "  v_wpos = wpos; v_nrm = u_normal_mat * a_nrm;\n"
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
    "  vec4 m_l0, m_l1, m_l2, m_l3, m_l4, m_l5; ivec4 m_lt0, m_lt1, m_lt2; vec4 m_lxf[24];\n" /* the layers (mat_block, sy_gl_shaders_layers.c) */ \
    "};\n"                                                                                                   \
    "uniform sampler2D t_base, t_mr, t_nrm, t_occ, t_emis;\n"                                                \
    "#ifdef SY_TRANS\n" "uniform sampler2D t_l11;\n" "#endif\n" /* the transmission texture */             \
    "vec2 tuv(int k, vec2 t) { vec3 h = vec3(t, 1.0); return vec2(dot(m_xf[2*k].xyz, h), dot(m_xf[2*k+1].xyz, h)); }\n" \
    /* the texture coordinate set s (0, 1): a select, not an array indexed at run time (a local \
     * array read with a dynamic index made llvmpipe's LLVM spend seconds per texture look-up) */ \
    "#define UVSET(s) ((s) == 1 ? v_uv1 : v_uv0)\n"

/* What the forward and the deferred shading share: the light, area-light and environment blocks,
 * the view uniforms, the BSDF helpers, shadow look-ups, LTC and environment look-ups. */
#define SY_GL_SHADING_DECLS \
    "struct Light { vec4 pos_type; vec4 dir_range; vec4 radiant; vec4 cone; };\n" \
    "layout(std140) uniform Lights { ivec4 l_count; vec4 l_env; mat4 l_shadow_mat[4]; vec4 l_shadow[4];\n" \
    "  Light l_lights[32]; vec4 l_cube[2]; };\n" /* SY_GL_MAX_CUBE_SHADOWS point lights: near, far, normal offset */ \
    /* area lights: a_count: x polygons, y those up to the last with a shadow map, z shadow taps (8); \
     * per polygon 4 vertices (xyz, w vertex count), radiance (rgb, w = double-sided), centre (xyz, w = shadow map or -1) */ \
    "layout(std140) uniform Areas { ivec4 a_count; vec4 a_dir; vec4 a_data[16 * 6]; };\n" \
    "uniform sampler2DArrayShadow t_shadow; uniform samplerCubeShadow t_cshadow0, t_cshadow1;\n" \
    "uniform samplerCube t_env_spec, t_env_irr, t_probe; uniform sampler2D t_brdf, t_ltc1, t_ltc2;\n" \
    "uniform float u_probe_lod;\n" /* the probe's last mip */ \
    "uniform vec3 u_cam_pos; uniform vec3 u_cam_fwd; uniform bool u_ortho; uniform bool u_mirror;\n" \
    "uniform bool u_has_normals; uniform vec3 u_ortho_z;\n" /* orthographic: proj[10], proj[14] */ \
    "const float INV_PI = 0.31830988618;\n" \
    /* the dielectric Fresnel: a colour where KHR_materials_specular can tint it (SY_LAYERS), else \
     * one value; the layers' functions (sy_gl_layers_fs, linked after this source) */ \
    "#ifdef SY_LAYERS\n" \
    "#define FDT vec3\n#define SCHL_D schlick\n#define F0D f0c\n#define F0M f0m\n" \
    "vec3 g_nc;\n" /* the clear coat's normal: the surface's, without its normal map (main) */ \
    "vec3 layer_light(vec3 wi, vec3 wo, vec3 ns, float nl, vec3 f);\n" \
    "float g_ls;\n" /* layer_f0: what the coat and sheen leave to the base, once per fragment */ \
    "vec3 layer_env(vec3 env, vec3 ns, vec3 wo, float nv, vec3 irr);\n" \
    "void layer_f0(float f0, vec3 bc, float metallic, vec3 ns, vec3 wo, float nv, out vec3 f0c, out vec3 f0m);\n" \
    "void layer_aniso(vec3 wi, vec3 wo, vec3 h, vec3 ns, float nl, float nv, float rough, inout float D, inout float V);\n" \
    "vec3 layer_reflect(vec3 wo, vec3 ns, float rough);\n" \
    "float layer_init(vec3 n, bool front, vec3 dpx, vec3 dpy);\n" \
    "void layer_area(vec3 ns, vec3 wo);\n" \
    "mat3 g_Mc; float g_fc; vec3 g_sh;\n" /* layer_area: the coat's LTC matrix and norm x weight (0: none); the sheen's albedo */ \
    "vec3 layer_transmittance();\n" \
    "#else\n" \
    "#define FDT float\n#define SCHL_D schlick1\n#define F0D f0d\n#define F0M bc\n" \
    "#endif\n" \
    "vec3 schlick(vec3 f0, float c) { float m = 1.0 - clamp(c, 0.0, 1.0); float m5 = m*m*m*m*m;\n" \
    "  return f0 + (vec3(1.0) - f0) * m5; }\n" \
    "float schlick1(float f0, float c) { float m = 1.0 - clamp(c, 0.0, 1.0); return f0 + (1.0 - f0) * m*m*m*m*m; }\n" \
    "#if defined(SY_SHADOW) || defined(SY_ASHADOW)\n" \
    /* sp.x: normal offset (x w in perspective when sp.y > 0.5); sp.z: area-light penumbra scale \
     * (radius in shadow-map uv = sp.z / w); sp.w: 2 tan(half fov). Returns the light-space position. */ \
    "bool proj_coord(mat4 M, vec4 sp, vec3 p, vec3 ngf, out vec3 q, out float r) {\n" \
    "  vec4 c0 = M * vec4(p, 1.0); r = 0.0; q = vec3(0.0); if (c0.w <= 0.0) return false;\n" \
    "  float off = sp.x * (sp.y > 0.5 ? c0.w : 1.0);\n" \
    "  r = sp.z / c0.w;\n" /* penumbra kernel (uv); its world size sp.w r w */ \
    "  off = max(off, r * sp.w * c0.w);\n" /* offset the receiver by the kernel's world radius (r of uv = 2 t r w): no self-shadowing at any slope */ \
    "  vec4 c = M * vec4(p + ngf * off, 1.0); if (c.w <= 0.0) return false;\n" \
    "  q = c.xyz / c.w * 0.5 + 0.5; return q.z < 1.0; }\n" \
    "bool shadow_coord(int si, vec3 p, vec3 ngf, out vec3 q, out float r) {\n" \
    "  return proj_coord(l_shadow_mat[si], l_shadow[si], p, ngf, q, r); }\n" \
    "#endif\n" \
    /* punctual lights cast hard shadows (as in the ray tracers): one hardware-bilinear PCF tap, an \
     * edge one texel wide */ \
    "#ifdef SY_SHADOW\n" \
    "float shadow_vis(int si, vec3 p, vec3 ngf) {\n" \
    "  vec3 q; float r; if (!shadow_coord(si, p, ngf, q, r)) return 1.0;\n" \
    "  return texture(t_shadow, vec4(q.xy, float(si), q.z)); }\n" \
    /* point lights: a depth cube map, compared at the window depth of the major axis of (p - light) \
     * after the normal offset */ \
    "float cube_vis(int slot, vec3 lp, vec3 p, vec3 ngf) {\n" \
    "  vec4 cp = l_cube[slot]; vec3 d0 = p - lp; float m0 = max(abs(d0.x), max(abs(d0.y), abs(d0.z)));\n" \
    "  vec3 d = d0 + ngf * (cp.z * m0); vec3 ad = abs(d); float ma = max(ad.x, max(ad.y, ad.z));\n" \
    "  if (!(ma > cp.x)) return 1.0;\n" \
    "  float z = 0.5 * ((cp.y + cp.x) / (cp.y - cp.x) - 2.0 * cp.y * cp.x / ((cp.y - cp.x) * ma)) + 0.5;\n" \
    "  if (z >= 1.0) return 1.0;\n" \
    "  return slot == 0 ? texture(t_cshadow0, vec4(d, z)) : texture(t_cshadow1, vec4(d, z)); }\n" \
    "#endif\n" \
    "#ifdef SY_ASHADOW\n" /* area lights: 8 Poisson taps (hardware PCF each) over the penumbra */ \
    "const vec2 POISSON[8] = vec2[8](vec2(-0.840,-0.074), vec2(0.962,-0.195), vec2(-0.203,0.621), vec2(0.185,-0.893),\n" \
    "  vec2(-0.326,-0.406), vec2(0.473,-0.480), vec2(0.519,0.767), vec2(-0.696,0.457));\n" \
    /* taps: a_count.z (8, the Areas block) for a polygon with a map, 0 for one without. A bound \
     * that is not a constant keeps the loop a loop (eight unrolled PCF look-ups per shadowed polygon \
     * made LLVM's code generation about 15 % slower), and llvmpipe leaves a loop as soon as no \
     * pixel of its block runs it, so a polygon without a map costs no look-up */ \
    "float shadow_area(int si, int taps, vec3 p, vec3 ngf) {\n" \
    "  vec3 q; float r; if (taps == 0 || !shadow_coord(si, p, ngf, q, r)) return 1.0;\n" \
    "  r = max(r, 1.5 / float(textureSize(t_shadow, 0).x)); float s = 0.0;\n" \
    "  for (int k = 0; k < taps; ++k) s += texture(t_shadow, vec4(q.xy + POISSON[k & 7] * r, float(si), q.z));\n" \
    "  return s * 0.125; }\n" \
    "#endif\n" \
    "#ifdef SY_AREA\n" \
    /* Heitz et al. 2016, clipless form: the vector form factor of the (transformed) polygon, its \
     * horizon clipping looked up as a sphere in ltc_2.w */ \
    "vec3 edge_vec(vec3 v1, vec3 v2) { float x = dot(v1, v2), y = abs(x);\n" \
    "  float a = 0.8543985 + (0.4965155 + 0.0145206 * y) * y, b = 3.4175940 + (4.1616724 + y) * y, v = a / b;\n" \
    "  float ts = x > 0.0 ? v : 0.5 * inversesqrt(max(1.0 - x * x, 1e-7)) - v; return cross(v1, v2) * ts; }\n" \
    "float ltc_eval(mat3 Minv, vec3 P, int li, int nv) {\n" \
    "  vec3 L[4]; vec3 ctr = vec3(0.0);\n" \
    "  for (int k = 0; k < 4; ++k) { L[k] = Minv * (a_data[li * 6 + k].xyz - P); }\n" \
    "  ctr = Minv * (a_data[li * 6 + 5].xyz - P);\n" \
    "  for (int k = 0; k < 4; ++k) L[k] = normalize(L[k]);\n" \
    "  vec3 f = edge_vec(L[0], L[1]) + edge_vec(L[1], L[2]);\n" \
    "  if (nv == 4) f += edge_vec(L[2], L[3]) + edge_vec(L[3], L[0]); else f += edge_vec(L[2], L[0]);\n" \
    "  if (dot(f, ctr) < 0.0) f = -f;\n" \
    "  float len = length(f); if (!(len > 0.0)) return 0.0;\n" \
    "  float z = f.z / len; vec2 uv = vec2(z * 0.5 + 0.5, len) * (63.0 / 64.0) + 0.5 / 64.0;\n" \
    "  return len * textureLod(t_ltc2, uv, 0.0).w; }\n" \
    "#endif\n" \
    "#if defined(SY_ENV) || defined(SY_PROBE)\n" \
    /* what a reflected or refracted ray sees: the scene probe around this object (the scene and, \
     * beyond it, the environment; its mips blur for roughness) or the prefiltered environment */ \
    "vec3 env_spec(vec3 d, float rough) {\n" \
    "#ifdef SY_PROBE\n" \
    "  return textureLod(t_probe, d, rough * u_probe_lod).rgb;\n" \
    "#else\n" \
    "  return textureLod(t_env_spec, d, rough * l_env.x).rgb;\n" \
    "#endif\n" \
    "}\n" \
    "#endif\n" \

/* Call i of a variant's straight-line light code: when the count n (SY_NLIGHTS) is above i, L +=
 * f(i, k<i>, ...), k<i> the item's defines (punctual lights: shadow SY_LK<i> and type SY_LT<i>);
 * see shade_light. */
#define SY_GL_CALL(n, f, k, i) "#if " n " > " #i "\n    L += " f "(" #i ", " k ");\n#endif\n"
#define SY_GL_LIGHT_CALL(i) SY_GL_CALL("SY_NLIGHTS", "SY_LIGHT", "SY_LK" #i ", SY_LT" #i, i)

/* The lighting of one surface point: P (world), ngf (geometric normal facing the viewer), ns
 * (shading normal, flipped to the side seen), wo (towards the eye), the material's clamped base
 * colour, metallic, roughness, ior, specular and transmission, ao (occlusion of the ambient
 * terms), emitter (an emissive surface gets no indirect estimate). Only in lit variants. */
#define SY_GL_SHADE_LIT \
    "#ifdef SY_LIT\n" \
    "#ifdef SY_LIGHTS\n" \
    /* one punctual light i; kind: its shadow (0 none, 1 its 2D map, 2 + s cube slot s, -1 read \
     * from the Lights block); kd: the diffuse albedo, f0d, w_metal, w_diel: the lobes' weights (see \
     * shade_lit), a2: GGX alpha squared, nv = ns . wo. llvmpipe runs both sides of every branch \
     * for the whole SIMD vector of pixels, so a loop over the lights whose body chose the shadow \
     * look-up at run time made all three (2D map, cube 0, cube 1) for every light; and that loop \
     * (kept by the compiler: it has continues) cost as much with its trip count forced to zero as \
     * with the light (measured, issue 19). So a variant with a constant light count calls this \
     * once per light with i and kind constants: straight-line code with the one look-up the light \
     * needs. lt, its type, likewise (0 point, 1 point with a range, 2 spot, 3 directional; -1 \
     * read from the block): a point light runs no spot-cone or range code */ \
    "vec3 shade_light(int i, int kind, int lt, vec3 P, vec3 ngf, vec3 ns, vec3 wo, vec3 bc, vec3 kd, float spec,\n" \
    "                 FDT f0d, float w_metal, float w_diel, float rough, float a2, float nv) {\n" \
    "  Light l = l_lights[i]; int type = lt < 0 ? int(l.pos_type.w) : lt == 3 ? 3 : lt == 2 ? 2 : 1; vec3 wi, e;\n" \
    "  if (type == 3) { wi = -l.dir_range.xyz; e = l.radiant.rgb; }\n" \
    "  else {\n" \
    "    wi = l.pos_type.xyz - P; float d2 = dot(wi, wi); if (!(d2 > 0.0)) return vec3(0.0);\n" \
    "    float d = sqrt(d2); wi /= d; float att = 1.0 / d2;\n" \
    "    if (lt != 0 && l.dir_range.w > 0.0) { float x = d / l.dir_range.w; float w = clamp(1.0 - x*x*x*x, 0.0, 1.0); att *= w * w; }\n" \
    "    if (type == 2) { float cd = -dot(l.dir_range.xyz, wi); float s = clamp(cd * l.cone.x + l.cone.y, 0.0, 1.0); att *= s * s; }\n" \
    "    if (!(att > 0.0)) return vec3(0.0); e = l.radiant.rgb * att;\n" \
    "  }\n" \
    "  float cs = dot(ns, wi); if (cs <= 0.0 || dot(ngf, wi) <= 0.0) return vec3(0.0);\n" \
    "#ifdef SY_SHADOW\n" \
    "  float vis = 1.0;\n" \
    "  if (kind == 1) vis = shadow_vis(int(l.cone.z), P, ngf);\n" \
    "  else if (kind >= 2) vis = cube_vis(kind - 2, l.pos_type.xyz, P, ngf);\n" \
    "  else if (kind < 0) { int si = int(l.cone.z), ci = int(l.cone.w);\n" \
    "    vis = si >= 0 ? shadow_vis(si, P, ngf) : ci >= 0 ? cube_vis(ci, l.pos_type.xyz, P, ngf) : 1.0; }\n" \
    "  if (vis <= 0.0) return vec3(0.0);\n" \
    "#else\n" \
    "  float vis = 1.0;\n" \
    "#endif\n" \
    "  vec3 h = normalize(wi + wo); float vh = max(dot(wo, h), 0.0);\n" \
    "  FDT fd = spec * SCHL_D(f0d, vh);\n" \
    "  vec3 f = kd * (1.0 - fd) * INV_PI;\n" \
    "  if (rough > 0.0) {\n" \
    "    float nl = cs, nh = max(dot(ns, h), 0.0);\n" \
    "    float dd = nh * nh * (a2 - 1.0) + 1.0; float D = a2 * INV_PI / (dd * dd);\n" \
    "    float V = 0.5 / (nl * sqrt(nv * nv * (1.0 - a2) + a2) + nv * sqrt(nl * nl * (1.0 - a2) + a2));\n" \
    "#ifdef SY_LAYERS\n" \
    "    layer_aniso(wi, wo, h, ns, nl, nv, rough, D, V);\n" \
    "#endif\n" \
    "    f += (schlick(bc, vh) * w_metal + vec3(w_diel * fd)) * (D * V);\n" \
    "  }\n" \
    "#ifdef SY_LAYERS\n" \
    "  f = layer_light(wi, wo, ns, cs, f);\n" \
    "#endif\n" \
    "  return e * f * cs * vis;\n" \
    "}\n" \
    "#endif\n" \
    "#ifdef SY_AREA\n" \
    /* one emissive polygon i (linearly transformed cosines: frame for the diffuse lobe, Minv for \
     * the specular one; kdl, fl their weights); shadow: 0 it has no shadow map, else its map's \
     * index is read from the Areas block (none when negative) */ \
    "vec3 shade_area(int i, int shadow, vec3 P, vec3 ngf, mat3 frame, mat3 Minv, vec3 kdl, vec3 fl, float rough) {\n" \
    "  vec4 v0 = a_data[i * 6], rad = a_data[i * 6 + 4], cen = a_data[i * 6 + 5];\n" \
    "  int nvx = int(v0.w);\n" \
    "  vec3 ln = cross(a_data[i * 6 + 1].xyz - v0.xyz, a_data[i * 6 + 2].xyz - v0.xyz);\n" \
    "  float side = dot(P - v0.xyz, ln);\n" \
    "  if (!(abs(side) > 1e-5 * dot(ln, ln) + 1e-9) || (side < 0.0 && rad.w < 0.5)) return vec3(0.0);\n" \
    "  float vis = 1.0;\n" \
    "#ifdef SY_ASHADOW\n" \
    "  int si = int(cen.w);\n" \
    "  vis = shadow_area(max(si, 0), shadow != 0 && si >= 0 ? a_count.z : 0, P, ngf);\n" \
    "  if (vis <= 0.0) return vec3(0.0);\n" \
    "#endif\n" \
    /* the lobes (0 diffuse, 1 specular where rough > 0, 2 the clear coat where it has weight) in \
     * a loop of a bound the compiler cannot see: one inlined copy of ltc_eval, not three (each \
     * copy is four edge integrals and a table look-up: issue 32's compile time) */ \
    "  float d = 0.0, s = 0.0, c = 0.0;\n" \
    "#ifdef SY_LAYERS\n" \
    "  int lobes = g_fc > 0.0 ? 3 : rough > 0.0 ? 2 : 1;\n" \
    "#else\n" \
    "  int lobes = rough > 0.0 ? 2 : 1;\n" \
    "#endif\n" \
    "  for (int k = 0; k < lobes; ++k) {\n" \
    "#ifdef SY_LAYERS\n" \
    "    mat3 M = k == 0 ? frame : k == 1 ? Minv : g_Mc;\n" \
    "#else\n" \
    "    mat3 M = k == 0 ? frame : Minv;\n" \
    "#endif\n" \
    "    float e = ltc_eval(M, P, i, nvx);\n" \
    "    if (k == 0) d = e; else if (k == 1) s = rough > 0.0 ? e : 0.0; else c = e;\n" \
    "  }\n" \
    "#ifdef SY_LAYERS\n" /* the clear coat's lobe */ \
    "  return rad.rgb * ((kdl + g_sh) * d + fl * s + vec3(g_fc * c)) * vis;\n" \
    "#else\n" \
    "  return rad.rgb * (kdl * d + fl * s) * vis;\n" \
    "#endif\n" \
    "}\n" \
    "#endif\n" \
    "vec3 shade_lit(vec3 P, vec3 ngf, vec3 ns, vec3 wo, vec3 bc, float metallic, float rough, float ior, float spec,\n" \
    "               float trans, float ao, bool emitter) {\n" \
    "    vec3 L = vec3(0.0);\n" \
    /* the path tracer's lobes: metal (Schlick on the base colour), dielectric specular \
     * spec x Schlick(f0d), diffuse base (1 - that) / pi, transmission */ \
    "    float r0 = (ior - 1.0) / (ior + 1.0); float f0d = r0 * r0;\n" \
    "    float w_metal = metallic, w_diel = (1.0 - metallic) * (1.0 - trans), w_trans = (1.0 - metallic) * trans;\n" \
    "    vec3 kd = bc * w_diel;\n" \
    "    float a = max(rough * rough, 1e-4), a2 = a * a;\n" \
    "    float nv = max(dot(ns, wo), 1e-4);\n" \
    "#ifdef SY_LAYERS\n" \
    "    vec3 f0c, f0m; layer_f0(f0d, bc, metallic, ns, wo, nv, f0c, f0m);\n" \
    "#endif\n" \
    "#ifdef SY_LIGHTS\n" \
    "#define SY_LIGHT(i, kind, lt) shade_light(i, kind, lt, P, ngf, ns, wo, F0M, kd, spec, F0D, w_metal, w_diel, rough, a2, nv)\n" \
    "#ifdef SY_NLIGHTS\n" /* the variant's light count (1 .. 7) and shadow kinds SY_LK0 ..: straight-line code */ \
    SY_GL_LIGHT_CALL(0) SY_GL_LIGHT_CALL(1) SY_GL_LIGHT_CALL(2) SY_GL_LIGHT_CALL(3) SY_GL_LIGHT_CALL(4) \
    SY_GL_LIGHT_CALL(5) SY_GL_LIGHT_CALL(6) \
    "#else\n" /* more lights than variants count: the Lights block's count */ \
    "    for (int i = 0; i < l_count.x; ++i) L += SY_LIGHT(i, -1, -1);\n" \
    "#endif\n" \
    "#endif\n" \
    "#if defined(SY_AREA) || defined(SY_ENV) || defined(SY_PROBE)\n" \
    /* split-sum terms: A, B of the GGX BRDF for this view and roughness */ \
    "    vec2 ab = textureLod(t_brdf, vec2(nv, rough) * (31.0 / 32.0) + 0.5 / 32.0, 0.0).rg;\n" \
    "    FDT fd_avg = spec * (F0D * ab.x + ab.y);\n" \
    "    vec3 fspec = (F0M * ab.x + ab.y) * w_metal + vec3(w_diel * fd_avg);\n" \
    "#endif\n" \
    "#ifdef SY_AREA\n" \
    "    {\n" \
    "      vec2 luv = vec2(rough, sqrt(1.0 - nv)) * (63.0 / 64.0) + 0.5 / 64.0;\n" \
    "      vec4 t1 = textureLod(t_ltc1, luv, 0.0), t2 = textureLod(t_ltc2, luv, 0.0);\n" \
    "      vec3 T1 = normalize(wo - ns * dot(wo, ns)); vec3 T2 = cross(ns, T1);\n" \
    "      mat3 frame = transpose(mat3(T1, T2, ns));\n" \
    "      mat3 Minv = mat3(vec3(t1.x, 0.0, t1.y), vec3(0.0, 1.0, 0.0), vec3(t1.z, 0.0, t1.w)) * frame;\n" \
    /* the LTC norm replaces A, B for the polygon's specular (F0 t2.x + (1 - F0) t2.y) */ \
    "      vec3 fl = (F0M * t2.x + (1.0 - F0M) * t2.y) * w_metal + vec3(w_diel * spec * (F0D * t2.x + (1.0 - F0D) * t2.y));\n" \
    "      vec3 kdl = kd * (1.0 - fd_avg);\n" \
    "#ifdef SY_LAYERS\n" /* the polygons see the base under the coat and sheen, and the coat's lobe */ \
    "      fl *= g_ls; kdl *= g_ls; layer_area(ns, wo);\n" \
    "#endif\n" \
    "#define SY_AREA_L(i, sh) shade_area(i, sh, P, ngf, frame, Minv, kdl, fl, rough)\n" \
    /* one loop, not one call per polygon: sixteen inlined copies of shade_area took llvmpipe's \
     * LLVM many seconds to compile, and two loops (with and without shadow look-ups) twice the \
     * time of one. The polygons up to the last with a shadow map (a_count.y; maps go to the first \
     * polygons) look theirs up, the rest run no tap (shadow_area). The bound is a uniform, not a \
     * constant: the compiler cannot unroll the loop, so its body is compiled once, and a program \
     * does not depend on the polygon count (issue 32) */ \
    "      for (int i = 0; i < a_count.x; ++i) L += SY_AREA_L(i, i < a_count.y ? 1 : 0);\n" \
    /* the area lights' indirect light (sy_gl_set_ambient), stronger on surfaces facing the way the \
     * emitters shine (they see the directly lit surfaces), weaker on those facing the emitters; not \
     * on emitters (the estimate counts them as sources only) */ \
    "      if (!emitter) L += (kdl + fspec) * l_env.yzw * (ao * (1.0 + 0.75 * dot(ns, a_dir.xyz)));\n" \
    "    }\n" \
    "#endif\n" \
    "#if defined(SY_ENV) || defined(SY_PROBE)\n" \
    "    {\n" \
    "#ifdef SY_LAYERS\n" \
    "      vec3 R = layer_reflect(wo, ns, rough);\n" /* anisotropy bends the normal */ \
    "#else\n" \
    "      vec3 R = reflect(-wo, ns);\n" \
    "#endif\n" \
    "#ifdef SY_ENV\n" \
    "      vec3 irr = textureLod(t_env_irr, ns, 0.0).rgb;\n" /* cosine-weighted mean radiance = E / pi */ \
    "#else\n" \
    "      vec3 irr = vec3(0.0);\n" \
    "#endif\n" \
    /* the GGX lobe's dominant direction leans from R towards N as roughness grows (Lagarde and \
     * de Rousiers 2014, "Moving Frostbite to PBR", eq. 55); looking up R alone lights rough \
     * surfaces from below the horizon */ \
    "      float ga = rough * rough; vec3 Rd = normalize(mix(ns, R, (1.0 - ga) * (sqrt(1.0 - ga) + ga)));\n" \
    "      vec3 env = kd * (1.0 - fd_avg) * irr;\n" \
    "#ifdef SY_TRANS\n" /* glass: Fresnel reflection + refraction of the environment */ \
    "      float F = schlick1(f0d, nv);\n" \
    /* through a solid: refract in, cross a sphere tangent to this point, refract out (exact for \
     * a glass ball: the environment appears inverted as in the path tracer) */ \
    "      float eta = max(ior, 1.0); vec3 T = refract(-wo, ns, 1.0 / eta);\n" \
    "      if (dot(T, T) == 0.0) T = R; else {\n" \
    "        vec3 n2 = ns - 2.0 * dot(ns, T) * T;\n" /* the exit normal (outward) */ \
    "        vec3 T2 = refract(T, -n2, eta); T = dot(T2, T2) > 0.0 ? T2 : reflect(T, -n2);\n" \
    "      }\n" \
    "#ifdef SY_LAYERS\n" \
    "      vec3 wt = (1.0 - F) * bc * layer_transmittance();\n" \
    "#else\n" \
    "      vec3 wt = (1.0 - F) * bc;\n" \
    "#endif\n" \
    /* the look-ups (the lobe's, the glass's reflection and refraction) in a loop of a bound the \
     * compiler cannot see: one inlined cube look-up instead of three (issue 32's compile time), \
     * and a pixel that transmits nothing makes one */ \
    "      vec3 tr = vec3(0.0); int looks = w_trans > 0.0 ? 3 : 1;\n" \
    "      for (int k = 0; k < looks; ++k) {\n" \
    "        vec3 c = env_spec(k == 0 ? Rd : k == 1 ? R : T, rough);\n" \
    "        if (k == 0) env += fspec * c; else if (k == 1) tr += F * c; else tr += wt * c;\n" \
    "      }\n" \
    "      env += w_trans * tr;\n" \
    "#else\n" \
    "      env += fspec * env_spec(Rd, rough);\n" \
    "#endif\n" \
    "#ifdef SY_LAYERS\n" \
    "      env = layer_env(env, ns, wo, nv, irr);\n" \
    "#endif\n" \
    "      L += env * ao;\n" \
    "    }\n" \
    "#endif\n" \
    "    return L;\n" \
    "}\n" \
    "#endif\n" \

const char *const sy_gl_main_fs =
    "#version 330 core\n" SY_GL_VARIANT_PRELUDE SY_GL_MATERIAL_BLOCK SY_GL_SHADING_DECLS
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
    SY_GL_SHADE_LIT
    "#ifdef SY_LIT\n"
    /* the tangent frame (tg, bt) of uv t at the unit normal n from the screen derivatives of t and
     * of the position (dpx, dpy); false where they give none. map_normal: n bent by the
     * tangent-space normal map s at t with scale sc */
    "bool uv_frame(vec2 t, vec3 n, vec3 dpx, vec3 dpy, out vec3 tg, out vec3 bt) {\n"
    "  vec2 dtx = dFdx(t), dty = dFdy(t); vec3 pp2 = cross(dpy, n), pp1 = cross(n, dpx);\n"
    "  vec3 dpdu = pp2 * dtx.x + pp1 * dty.x, dpdv = pp2 * dtx.y + pp1 * dty.y;\n"
    "  tg = dpdu - n * dot(n, dpdu); bt = vec3(0.0);\n"
    "  if (!(dot(tg, tg) > 1e-30)) return false;\n"
    "  tg = normalize(tg); bt = cross(n, tg); if (dot(bt, dpdv) > 0.0) bt = -bt;\n"
    "  return true; }\n"
    "vec3 map_normal(sampler2D s, vec2 t, float sc, vec3 n, vec3 dpx, vec3 dpy) {\n"
    "  vec3 tg, bt;\n"
    "  if (uv_frame(t, n, dpx, dpy, tg, bt)) {\n"
    "    vec3 tx = texture(s, t).xyz * 2.0 - 1.0;\n"
    "    vec3 r = tg * (tx.x * sc) + bt * (tx.y * sc) + n * tx.z;\n"
    "    if (dot(r, r) > 0.0) n = normalize(r);\n"
    "  }\n"
    "  return n; }\n"
    "#endif\n"
    "void main() {\n"
    "  vec4 base = m_base * v_col;\n"
    "#if defined(SY_TEX) && defined(SY_TX0)\n" /* the slots some material of the frame samples (variant_sig) */
    "  if (m_tex.x >= 0) base *= texture(t_base, tuv(0, UVSET(m_tex.x)));\n"
    "#endif\n"
    "  float alpha = base.a;\n"
    /* discard only in this variant: it disables early depth tests. The probe faces draw every
     * material with it in a frame with a masked one (sy_gl_draw.c draw_instance): only a masked
     * material's alpha is coverage */
    "#ifdef SY_MASK\n"
    "  if (m_modes.x == 1 && alpha < m_mrna.w) discard;\n"
    "#endif\n"
    "  if (m_modes.x != 2) alpha = 1.0;\n"
    "  bool front = gl_FrontFacing != u_mirror;\n"
    "  vec3 L = vec3(0.0);\n"
    /* emission is radiance and adds to the reflected light */
    "  if (m_modes.w != 0 && (front || m_modes.z != 0)) {\n"
    "    L = m_emissive.rgb;\n"
    "#if defined(SY_TEX) && defined(SY_TX4)\n"
    "    if (m_tex2.x >= 0) L *= texture(t_emis, tuv(4, UVSET(m_tex2.x))).rgb;\n"
    "#endif\n"
    "  }\n"
    "  if (m_modes.y != 0) {\n"
    "    L += base.rgb;\n"
    "  }\n"
    "#ifdef SY_LIT\n" /* without lights a surface that is neither emissive nor unlit is black */
    "  else {\n"
    "    vec3 dpx = dFdx(v_wpos), dpy = dFdy(v_wpos);\n"
    "    vec3 wo = u_ortho ? -u_cam_fwd : normalize(u_cam_pos - v_wpos);\n"
    "    vec3 ngf = normalize(cross(dpx, dpy)); if (dot(ngf, wo) < 0.0) ngf = -ngf;\n"
    "    if (any(isnan(ngf))) ngf = wo;\n"
    "    vec3 n = front ? ngf : -ngf;\n"
    "    if (u_has_normals) { vec3 sn = normalize(v_nrm); if (!any(isnan(sn))) n = sn; }\n"
    "#ifdef SY_LAYERS\n" /* the coat's normal (its own map or none) and the layers' textures */
    "    float spec_tex = layer_init(n, front, dpx, dpy);\n"
    "#endif\n"
    "#ifdef SY_NMAP\n"
    "    if (m_tex.z >= 0) n = map_normal(t_nrm, tuv(2, UVSET(m_tex.z)), m_mrna.z, n, dpx, dpy);\n"
    "#endif\n"
    "    vec3 ns = front ? n : -n;\n"
    "    float metallic = m_mrna.x, rough = m_mrna.y;\n"
    "#if defined(SY_TEX) && defined(SY_TX1)\n"
    "    if (m_tex.y >= 0) { vec4 t = texture(t_mr, tuv(1, UVSET(m_tex.y))); rough *= t.g; metallic *= t.b; }\n"
    "#endif\n"
    "    metallic = clamp(metallic, 0.0, 1.0); rough = clamp(rough, 0.0, 1.0);\n"
    "    vec3 bc = clamp(base.rgb, 0.0, 1.0);\n"
    "    float ior = m_oist.y, spec = clamp(m_oist.z, 0.0, 1.0), trans = clamp(m_oist.w, 0.0, 1.0);\n"
    "#ifdef SY_LAYERS\n"
    "    spec *= spec_tex;\n"
    "#endif\n"
    /* the transmission texture (R), the layers' slot 11 (its uv set m_lt2.w, transform m_lxf[22..23]):
     * read by the transmissive variant, not the layered one (whose size on every pixel of
     * TransmissionTest's textured glass made its frame 5 times slower on llvmpipe) */
    "#if defined(SY_TRANS) && defined(SY_TEX) && defined(SY_LX11)\n"
    "    if (m_lt2.w >= 0) { vec3 h = vec3(UVSET(m_lt2.w), 1.0);\n"
    "      trans *= texture(t_l11, vec2(dot(m_lxf[22].xyz, h), dot(m_lxf[23].xyz, h))).r; }\n"
    "#endif\n"
    "    float ao = 1.0;\n"
    "#if defined(SY_TEX) && defined(SY_TX3) && (defined(SY_AREA) || defined(SY_ENV) || defined(SY_PROBE))\n"
    "    if (m_tex.w >= 0) ao = 1.0 + m_oist.x * (texture(t_occ, tuv(3, UVSET(m_tex.w))).r - 1.0);\n"
    "#endif\n"
    "    L += shade_lit(v_wpos, ngf, ns, wo, bc, metallic, rough, ior, spec, trans, ao, m_modes.w != 0);\n"
    "  }\n"
    "#endif\n"
    "  o_color = vec4(L * alpha, alpha);\n"
    /* linear view depth from the window coordinates: 1/w_clip = 1/z_view in perspective, the
     * inverse depth mapping in orthographic views; one varying less */
    "  o_depth = u_ortho ? -((gl_FragCoord.z * 2.0 - 1.0) - u_ortho_z.y) / u_ortho_z.x : 1.0 / gl_FragCoord.w;\n"
    "}\n";

/* Deferred shading (sy_gl_draw.c, deferred_pass). Under MSAA a software rasterizer runs a
 * fragment shader once per pixel for every triangle that touches any of the pixel's samples, in
 * blocks of pixels: on meshes of a few pixels per triangle the forward shader runs many times per
 * pixel, and every instruction of it counts. Opaque, untextured surfaces of meshes without colours
 * therefore write only what their shading needs into the multisampled colour target, with as few
 * instructions as possible (the geometry pass below), and one full-screen pass
 * (sy_gl_deferred_fs) shades each distinct surface of a pixel once and resolves.
 *
 * G-buffer sample, where forward-shaded samples hold their colour (alpha >= 0) and depth:
 *   colour (RGBA32F):
 *     x, y  the interpolated vertex normal n (world space, not flipped) as n.xy / |n.z| (the
 *           gnomonic projection: a division, no normalisation or fold; the sign of n.z travels in
 *           the depth's sign bit, |n.z| = 0 is taken as 1e-30); for a mesh without normals or
 *           where they interpolate to zero ("geo"), the slope h itself (below), the geometric
 *           normal being the shading normal there
 *     z     the slope h of the triangle's plane, its x component (exact); from h the shading pass
 *           rebuilds the geometric normal at the pixel centre X (view plane at distance 1, or
 *           metres when orthographic): view-space normal (-h, 1 - h.X) (perspective) or (h, 1)
 *           (orthographic), facing the viewer
 *     w     -(1 + key + 1024 qy), an exact integer: key = front + 2 geo + 4 x material row (< 256);
 *           qy the slope's y component, 8191 (1 + h.y / (1 + |h.y|)) rounded (0 .. 16382; h.y = 0
 *           exact; a step is at most 2.5e-4 radians of normal); negative marks a G-buffer sample
 *   depth (R32F): the view depth at the pixel centre as in the forward pass (never below 1e-30),
 *           negated where n.z < 0.
 * The slope comes from the screen-space derivatives of the one quantity that is affine over a
 * triangle, 1/depth (perspective; divided by 1/depth, so that it is a ratio of the normal's
 * components) or depth (orthographic), instead of from an interpolated position (three varyings
 * fewer). The geometry pass writes what the floor writes (one colour, one depth), and does as
 * little arithmetic as it can: on triangles of a few pixels a software rasterizer runs it on whole
 * blocks of mostly empty pixels, so each instruction costs many times what it costs in the shading
 * pass, which turns the slope into a world-space normal. (Measured: a third target for the slope,
 * or the slope in a wider depth target, costs as much as the arithmetic it saves.) */
const char *const sy_gl_gbuf_vs =
    "#version 330 core\n" SY_GL_CLIP_VS
    "layout(location=0) in vec3 a_pos; layout(location=1) in vec3 a_nrm;\n"
    "uniform mat3 u_normal_mat; uniform mat4 u_mvp; uniform mat4 u_model; uniform bool u_has_normals; out vec3 v_nrm;\n"
    "void main() { v_nrm = u_has_normals ? u_normal_mat * a_nrm : vec3(0.0); gl_Position = u_mvp * vec4(a_pos, 1.0);\n"
    "  sy_clip((u_model * vec4(a_pos, 1.0)).xyz); }\n";

/* u_ppu: pixels per unit of the view plane at distance 1 (perspective) or per metre (SY_ORTHO);
 * u_ortho_z (SY_ORTHO): proj[10], proj[14]; u_keys: 1 + the key without geo for front-facing
 * triangles (x) and back-facing ones (y), the instance's mirroring folded in. Uniform choices are
 * variants (SY_ORTHO) or folded into uniforms, not branches: a software rasterizer pays for both
 * sides. */
const char *const sy_gl_gbuf_fs =
    "#version 330 core\n"
    "uniform vec2 u_ppu; uniform vec3 u_ortho_z; uniform vec2 u_keys;\n"
    "in vec3 v_nrm;\n"
    "layout(location=0) out vec4 o_color; layout(location=1) out float o_depth;\n"
    "void main() {\n"
    "#ifdef SY_ORTHO\n"
    "  float d = max(-((gl_FragCoord.z * 2.0 - 1.0) - u_ortho_z.y) / u_ortho_z.x, 1e-30);\n"
    "  vec2 h = vec2(dFdx(d), dFdy(d)) * u_ppu;\n"
    "#else\n"
    "  float W = gl_FragCoord.w, d = 1.0 / W; vec2 h = vec2(dFdx(W), dFdy(W)) * (u_ppu * d);\n"
    "#endif\n"
    "  vec3 n = v_nrm; bool geo = !(dot(n, n) > 0.0);\n"
    "  vec2 e = n.xy / max(abs(n.z), 1e-30);\n"
    "  float qy = floor(h.y / (1.0 + abs(h.y)) * 8191.0 + 8191.5);\n"
    "  o_color = vec4(geo ? h : e, h.x,\n"
    "                 -((gl_FrontFacing ? u_keys.x : u_keys.y) + (geo ? 2.0 : 0.0) + 1024.0 * qy));\n"
    "  o_depth = n.z < 0.0 ? -d : d;\n"
    "}\n";

/* Rectangles for the deferred pass and the resolve beside it (deferred_pass): u_rects[i] = (x0,
 * y0, x1, y1) in normalised device coordinates, two triangles each (6 vertices per rectangle). */
#define SY_GL_STR_(x) #x
#define SY_GL_STR(x) SY_GL_STR_(x)
const char *const sy_gl_rect_vs =
    "#version 330 core\n"
    "uniform vec4 u_rects[" SY_GL_STR(SY_GL_MAX_RECTS) "];\n"
    "void main() { vec4 r = u_rects[gl_VertexID / 6]; int c = gl_VertexID % 6;\n"
    "  bool right = c == 1 || c == 2 || c == 4, top = c == 2 || c == 4 || c == 5;\n"
    "  gl_Position = vec4(right ? r.z : r.x, top ? r.w : r.y, 0.0, 1.0); }\n";

/* The deferred pass: rectangles (sy_gl_rect_vs) over the multisampled targets. Per
 * pixel it groups the G-buffer samples into surfaces (same material, side and kind of normal,
 * depths within 0.1 %, normals within 1.8 degrees: the triangles of one smooth mesh are one
 * surface, the facets of a faceted one are not), shades each surface once at the pixel centre (where the forward pass shades it too),
 * passes forward-shaded samples through, and averages colour and takes the nearest depth as the
 * resolve does. SY_SAMPLES is the target's sample count; the lighting defines are the frame's, as
 * for the forward variants. The material table (t_mtab, RGBA32F) holds per row three texels:
 * (base colour, metallic), (emission, roughness), (ior, specular, transmission, flags), flags =
 * unlit + 2 double-sided + 4 emissive: the fields the pass reads, in three look-ups. */
const char *const sy_gl_deferred_fs =
    "#version 330 core\n" SY_GL_VARIANT_PRELUDE SY_GL_SHADING_DECLS
    "uniform sampler2DMS t_gcol; uniform sampler2DMS t_gdepth; uniform sampler2D t_mtab;\n"
    "uniform vec4 u_unproj; uniform mat4 u_inv_view; uniform vec2 u_px;\n" /* u_px: 2 / target size */
    "layout(location=0) out vec4 o_color; layout(location=1) out float o_depth;\n"
    SY_GL_SHADE_LIT
    /* the geometric normal (view space, facing the viewer, not normalised) from a slope h at the
     * view-plane position X of the pixel centre; never zero */
    "vec3 geo_normal(vec2 h, vec2 X) {\n"
    "  vec3 n = u_ortho ? vec3(h, 1.0) : vec3(-h, 1.0 - dot(h, X));\n"
    "  return dot(n, n) > 0.0 ? n : vec3(0.0, 0.0, 1.0); }\n"
    /* the shading normal from its projection e and the sign of its z: scaled so that nothing
     * overflows before it is normalised */
    "vec3 normal_dec(vec2 e, bool zneg) { e = clamp(e, -1e30, 1e30); float m = max(max(abs(e.x), abs(e.y)), 1.0);\n"
    "  return normalize(vec3(e, zneg ? -1.0 : 1.0) / m); }\n"
    /* the slope of a sample: x as stored, y from its 14 bits beside the key (the level of 0 exact:
     * the subtraction is of exact integers) */
    "vec2 slope_dec(vec4 g, float key) {\n"
    "  float t = ((-g.w - 1.0 - key) * (1.0 / 1024.0) - 8191.0) * (1.0 / 8191.0);\n"
    "  return vec2(g.z, t / max(1.0 - abs(t), 1e-6)); }\n"
    /* g: the sample, key its key, d its depth, nu its normalised shading normal (world) or, where
     * the key says geo, its geometric normal (view) */
    "vec3 shade_sample(vec4 g, float key, float d, vec3 nu, vec2 X) {\n"
    "  float row = floor(key * 0.25), bits = key - 4.0 * row; bool front = mod(bits, 2.0) > 0.5, geo = bits > 1.5;\n"
    "  int r = int(row);\n"
    "  vec4 base = texelFetch(t_mtab, ivec2(0, r), 0), emis = texelFetch(t_mtab, ivec2(1, r), 0);\n"
    "  vec4 istf = texelFetch(t_mtab, ivec2(2, r), 0);\n" /* ior, specular, transmission, flags */
    "  bool unlit = mod(istf.w, 2.0) > 0.5, two_sided = mod(istf.w, 4.0) > 1.5, emitter = istf.w > 3.5;\n"
    "  vec3 L = emitter && (front || two_sided) ? emis.rgb : vec3(0.0);\n"
    "  if (unlit) return L + base.rgb;\n"
    "#ifdef SY_LIT\n"
    "  vec3 pv = vec3(X * (u_ortho ? 1.0 : d), -d);\n"
    "  vec3 P = (u_inv_view * vec4(pv, 1.0)).xyz;\n"
    "  vec3 wo = u_ortho ? -u_cam_fwd : normalize(u_cam_pos - P);\n"
    "  vec3 ngf = normalize(mat3(u_inv_view) * (geo ? nu : geo_normal(slope_dec(g, key), X)));\n"
    "  vec3 ns = geo ? ngf : (front ? nu : -nu);\n"
    "  L += shade_lit(P, ngf, ns, wo, clamp(base.rgb, 0.0, 1.0), clamp(base.a, 0.0, 1.0), clamp(emis.a, 0.0, 1.0),\n"
    "                 istf.x, clamp(istf.y, 0.0, 1.0), clamp(istf.z, 0.0, 1.0), 1.0, emitter);\n"
    "#endif\n"
    "  return L;\n"
    "}\n"
    "void main() {\n"
    "  ivec2 p = ivec2(gl_FragCoord.xy); vec2 X = (gl_FragCoord.xy * u_px - 1.0 + u_unproj.zw) / u_unproj.xy;\n"
    "  vec4 g[SY_SAMPLES]; float z[SY_SAMPLES], key[SY_SAMPLES]; vec3 nu[SY_SAMPLES];\n"
    "  float dmin = uintBitsToFloat(0x7F800000u); vec4 c = vec4(0.0); int todo = 0;\n"
    "  for (int i = 0; i < SY_SAMPLES; ++i) {\n"
    "    g[i] = texelFetch(t_gcol, p, i); float zr = texelFetch(t_gdepth, p, i).r; z[i] = abs(zr); dmin = min(dmin, z[i]);\n"
    "    key[i] = mod(-g[i].w - 1.0, 1024.0); bool geo = mod(key[i], 4.0) > 1.5;\n"
    "    nu[i] = geo ? normalize(geo_normal(g[i].xy, X)) : normal_dec(g[i].xy, (floatBitsToUint(zr) & 0x80000000u) != 0u);\n"
    "    if (g[i].w >= 0.0) c += g[i]; else todo |= 1 << i;\n"
    "  }\n"
    /* a loop, not an if per sample: a software rasterizer runs both sides of a branch for the whole
     * SIMD vector of pixels, but leaves a loop when no pixel needs another turn. Each turn takes the
     * first sample left and every sample of the same surface (the first one always: no turn can
     * leave todo as it was, whatever a corrupt sample holds) */
    "  while (todo != 0) {\n"
    "    vec4 gi = vec4(0.0); float zi = 0.0, ki = 0.0; vec3 ni = vec3(0.0); int kf = -1;\n"
    "    for (int k = 0; k < SY_SAMPLES; ++k)\n"
    "      if (kf < 0 && (todo & (1 << k)) != 0) { gi = g[k]; zi = z[k]; ki = key[k]; ni = nu[k]; kf = k; }\n"
    "    float n = 0.0;\n"
    "    for (int k = 0; k < SY_SAMPLES; ++k)\n"
    "      if ((todo & (1 << k)) != 0 &&\n"
    "          (k == kf || (key[k] == ki && abs(z[k] - zi) <= 1e-3 * zi && dot(nu[k], ni) > 0.9995))) {\n"
    "        todo &= ~(1 << k); n += 1.0; }\n"
    "    c += vec4(shade_sample(gi, ki, zi, ni, X) * n, n);\n"
    "  }\n"
    "  o_color = c / float(SY_SAMPLES); o_depth = dmin;\n"
    "}\n";

const char *const sy_gl_shadow_vs =
    "#version 330 core\n" SY_GL_CLIP_VS
    "layout(location=0) in vec3 a_pos; layout(location=2) in vec2 a_uv0; layout(location=3) in vec2 a_uv1;\n"
    "layout(location=4) in vec4 a_col;\n"
    "uniform mat4 u_model; uniform mat4 u_lightvp; out vec2 v_uv0; out vec2 v_uv1; out float v_a;\n"
    "void main() { v_uv0 = a_uv0; v_uv1 = a_uv1; v_a = a_col.a; vec4 w = u_model * vec4(a_pos, 1.0); sy_clip(w.xyz);\n"
    "  gl_Position = u_lightvp * w; }\n";

const char *const sy_gl_shadow_fs =
    "#version 330 core\n" SY_GL_MATERIAL_BLOCK
    "in vec2 v_uv0; in vec2 v_uv1; in float v_a;\n"
    "void main() {\n"
    "#ifdef SY_MASK\n"
    "  float a = m_base.a * v_a;\n"
    "  if (m_tex.x >= 0) a *= texture(t_base, tuv(0, UVSET(m_tex.x))).a;\n"
    "  if (a < m_mrna.w) discard;\n"
    "#endif\n"
    "}\n";

/* The background where nothing is drawn: the lat-long texture x intensity along each pixel's
 * camera ray (u_inv_vp: inverse view-projection of this target), alpha 1, depth +infinity. */
const char *const sy_gl_sky_fs =
    "#version 330 core\n"
    "uniform mat4 u_inv_vp; uniform vec4 u_size_int; uniform sampler2D t_bg;\n" /* target w, h, intensity */
    "layout(location=0) out vec4 o_color; layout(location=1) out float o_depth;\n"
    "void main() { vec2 ndc = gl_FragCoord.xy / u_size_int.xy * 2.0 - 1.0;\n"
    "  vec4 a = u_inv_vp * vec4(ndc, -1.0, 1.0), b = u_inv_vp * vec4(ndc, 1.0, 1.0);\n"
    "  vec3 d = normalize(b.xyz * a.w - a.xyz * b.w);\n"
    "  vec2 uv = vec2(0.5 + atan(d.x, -d.z) * 0.15915494309, acos(clamp(d.y, -1.0, 1.0)) * 0.31830988618);\n"
    "  o_color = vec4(textureLod(t_bg, uv, 0.0).rgb * u_size_int.z, 1.0); o_depth = uintBitsToFloat(0x7F800000u); }\n";

/* A triangle covering the whole target (3 vertices, no attributes). */
const char *const sy_gl_fullscreen_vs =
    "#version 330 core\n"
    "void main() { vec2 p = vec2(float((gl_VertexID & 1) * 4 - 1), float((gl_VertexID & 2) * 2 - 1));\n"
    "  gl_Position = vec4(p, 0.0, 1.0); }\n";

/* SY_SAMPLES: the targets' sample count, a constant (a loop over a uniform count stays a loop). */
const char *const sy_gl_resolve_fs =
    "#version 330 core\n"
    "uniform sampler2DMS t_color; uniform sampler2DMS t_depth;\n"
    "layout(location=0) out vec4 o_color; layout(location=1) out float o_depth;\n"
    "void main() { ivec2 p = ivec2(gl_FragCoord.xy); vec4 c = vec4(0.0); float d = uintBitsToFloat(0x7F800000u);\n"
    "  for (int i = 0; i < SY_SAMPLES; ++i) { c += texelFetch(t_color, p, i); d = min(d, texelFetch(t_depth, p, i).r); }\n"
    "  o_color = c / float(SY_SAMPLES); o_depth = d; }\n";

/* The benchmark floors (sy_gl_render_floor): the same buffers, trivially shaded. Unlit: one
 * constant colour. SY_FLOOR_LIT ("trivial lit"): one directional light, Lambert, on the vertex
 * normal (the model matrix's upper 3x3, renormalised per fragment) plus a constant ambient term. */
const char *const sy_gl_floor_vs =
    "#version 330 core\n"
    "layout(location=0) in vec3 a_pos; uniform mat4 u_model; uniform mat4 u_view; uniform mat4 u_proj;\n"
    "#ifdef SY_FLOOR_LIT\n"
    "layout(location=1) in vec3 a_nrm; out vec3 v_nrm;\n"
    "#endif\n"
    "out float v_vz;\n"
    "void main() { vec4 e = u_view * u_model * vec4(a_pos, 1.0); v_vz = -e.z; gl_Position = u_proj * e;\n"
    "#ifdef SY_FLOOR_LIT\n"
    "  v_nrm = mat3(u_model) * a_nrm;\n"
    "#endif\n"
    "}\n";

const char *const sy_gl_floor_fs =
    "#version 330 core\n"
    "in float v_vz; layout(location=0) out vec4 o_color; layout(location=1) out float o_depth;\n"
    "#ifdef SY_FLOOR_LIT\n"
    "in vec3 v_nrm;\n"
    "void main() { float l = max(dot(normalize(v_nrm), vec3(0.48, 0.8, 0.36)), 0.0);\n"
    "  o_color = vec4(vec3(0.8) * (0.2 + 0.8 * l), 1.0); o_depth = v_vz; }\n"
    "#else\n"
    "void main() { o_color = vec4(0.8, 0.8, 0.8, 1.0); o_depth = v_vz; }\n"
    "#endif\n";

/* Whether shader s compiled (program false) or program s linked (program true); when not, the
 * object is deleted and its info log is in log (len bytes). */
static bool built(const sy_gl_fns *gl, GLuint s, bool program, char *log, GLsizei len)
{
    GLint ok = 0;
    if (program) gl->GetProgramiv(s, GL_LINK_STATUS, &ok);
    else gl->GetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (ok) return true;
    log[0] = '\0';
    if (program) gl->GetProgramInfoLog(s, len, NULL, log), gl->DeleteProgram(s);
    else gl->GetShaderInfoLog(s, len, NULL, log), gl->DeleteShader(s);
    return false;
}

static sy_gl_result compile(const sy_gl_fns *gl, const char *name, GLenum stage, const char *src, const char *defines,
                            const char *tail, GLuint *out, sy_gl_report *rep)
{
    GLuint s = gl->CreateShader(stage);
    /* defines go right after the #version line, the tail (more functions) after the source */
    const char *nl = strchr(src, '\n');
    const char *parts[4] = {src, defines ? defines : "", nl ? nl + 1 : "", tail ? tail : ""};
    GLint lens[4] = {nl ? (GLint)(nl + 1 - src) : -1, -1, -1, -1};
    gl->ShaderSource(s, nl ? 4 : 1, parts, nl ? lens : NULL);
    gl->CompileShader(s);
    char log[2048];
    if (!built(gl, s, false, log, sizeof log))
        return sy_gli_fail(rep, SY_GL_ERROR_GL, "%s shader: %s compile failed: %s", name,
                           stage == GL_VERTEX_SHADER ? "vertex" : "fragment", log);
    *out = s;
    return SY_GL_OK;
}

sy_gl_result sy_gl_program_build(const sy_gl_fns *gl, const char *name, const char *vs, const char *fs,
                                 const char *fs_defines, GLuint *out, sy_gl_report *rep)
{
    return sy_gl_program_build_tail(gl, name, vs, fs, fs_defines, NULL, out, rep);
}

sy_gl_result sy_gl_program_build_tail(const sy_gl_fns *gl, const char *name, const char *vs, const char *fs,
                                      const char *fs_defines, const char *fs_tail, GLuint *out, sy_gl_report *rep)
{
    GLuint v = 0, f = 0;
    sy_gl_result r = compile(gl, name, GL_VERTEX_SHADER, vs, fs_defines, NULL, &v, rep);
    if (r == SY_GL_OK) r = compile(gl, name, GL_FRAGMENT_SHADER, fs, fs_defines, fs_tail, &f, rep);
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
    char log[2048];
    if (!built(gl, p, true, log, sizeof log)) return sy_gli_fail(rep, SY_GL_ERROR_GL, "%s shader: link failed: %s", name, log);
    *out = p;
    return SY_GL_OK;
}
