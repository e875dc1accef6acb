/* sy_gl_shaders_layers.c — the GLSL of the glTF material extensions in the rasterizer's main
 * fragment shader: the functions its SY_LAYERS variants call (declared in sy_gl_main_fs's shading
 * declarations, appended after it by sy_gl_program_build_tail). One variant for every extension:
 * a material whose factors are the defaults (specular colour 1, no coat, no sheen, no
 * attenuation) shades through them exactly as without them, so the frame's other materials share
 * the program (sy_gl_draw.c, material_features). The model follows the Khronos glTF Sample
 * Viewer (source/Renderer/shaders: brdf.glsl, pbr.frag, ibl.glsl), written anew:
 *  - KHR_materials_specular: the dielectric F0 = min(((ior-1)/(ior+1))^2 x specular_color, 1)
 *    (layer_f0; the specular factor already scales it in sy_gl_shaders.c), diffuse x (1 - F);
 *  - KHR_materials_clearcoat: a GGX lobe (F0 0.04, F90 1, its own roughness) on the coat normal g_nc
 *    (the surface's normal without the base's normal map), for punctual lights, the environment
 *    (split sum) and emissive polygons (LTC, layer_area), and everything under it x
 *    (1 - clearcoat x Schlick(0.04, n_c.v));
 *  - KHR_materials_sheen: sheen_color x Charlie D (alpha = roughness^2) x Neubelt visibility for
 *    punctual lights; for the environment sheen_color x E(n.v) x the irradiance cube's mean
 *    radiance (the lobe is wide; the Sample Viewer prefilters a Charlie cube instead), for
 *    emissive polygons sheen_color x E(n.v) x the diffuse form factor; the base x
 *    (1 - max(sheen_color) E(n.v)), E from the BRDF table's third channel (sy_gl_ibl.c);
 *  - KHR_materials_anisotropy: anisotropic GGX (alpha along the direction mix(a, 1, s^2), across a)
 *    for punctual lights, the environment looked up along the bent normal (the Sample Viewer's);
 *    the direction: the rotation (or the texture's RG rotated by it) in the uv tangent frame of
 *    screen derivatives (meshes carry no tangents), strength x the texture's B;
 *  - KHR_materials_iridescence: the thin-film Fresnel (Belcour and Barla 2017, the Sample Viewer's
 *    iridescence.glsl) at n.v over the base's F0 (the dielectric's and the metal's mixed by
 *    metallic), turned into an F0 (Schlick inverted) and mixed into both lobes' by the weight; the film thickness mixes minimum to maximum
 *    by its texture's G (the maximum without one);
 *  - KHR_materials_volume: the refracted environment x attenuation_color^(d / attenuation_distance),
 *    d = thickness x the instance's mean axis scale (Beer-Lambert over the thickness as the Sample
 *    Viewer takes it; thickness 0 or distance 0 = none).
 * Material uniforms: m_l0 (specular colour, clearcoat), m_l1 (coat roughness, sheen roughness,
 * thickness, attenuation distance), m_l2 (sheen colour, coat normal scale), m_l3 (attenuation
 * colour), m_l4 (cos, sin of the anisotropy rotation, strength), m_l5 (iridescence, film ior,
 * thickness minimum, maximum); the textures (units t_l0 .. t_l7, uv sets m_lt0, m_lt1, transforms m_lxf) scale them
 * as glTF says (layer_init: specular A, specular colour RGB, clearcoat R, coat roughness G, coat
 * normal, sheen colour RGB, sheen roughness A, thickness G, anisotropy RGB, iridescence R,
 * iridescence thickness G) into g_l0 .. g_l5. The transmission texture (slot 11) is read by the
 * transmissive variant itself (sy_gl_shaders.c, SY_TRANS). */
#include "sy_gl_shaders.h"

const char *const sy_gl_layers_fs =
    "\n"
    "uniform mat4 u_model;\n" /* the vertex stage's: the instance's scale for the volume */
    "uniform sampler2D t_l0, t_l1, t_l2, t_l3, t_l4, t_l5, t_l6, t_l7, t_l8, t_l9, t_l10;\n"
    "vec4 g_l0, g_l1, g_l2, g_l3, g_l4, g_l5;\n" /* m_l0 .. m_l5 times the textures (layer_init) */
    "vec3 g_at, g_T, g_B;\n" /* the anisotropy direction (world; zero: none); its frame at ns (layer_f0) */
    "bool g_an;\n" /* that frame exists */
    "float g_se;\n" /* the sheen's directional albedo E(n.v) at the sheen roughness (layer_f0) */
    "vec2 ltuv(int k, vec2 t) { vec3 h = vec3(t, 1.0); return vec2(dot(m_lxf[2*k].xyz, h), dot(m_lxf[2*k+1].xyz, h)); }\n"
    /* the factors times their textures (slots: sy_gli_layer_refs; uv sets in m_lt0, m_lt1, -1 = none)
     * and the coat's normal (the vertex normal n, bent by its own map, flipped to the side seen);
     * returns the specular texture's factor */
    "float layer_init(vec3 n, bool front, vec3 dpx, vec3 dpy) {\n"
    "  g_l0 = m_l0; g_l1 = m_l1; g_l2 = m_l2; g_l3 = m_l3; g_l4 = m_l4; g_l5 = m_l5; float s = 1.0; vec3 nc = n;\n"
    "  g_at = vec3(0.0); g_l5.w = m_l5.w;\n"
    "#ifdef SY_TEX\n"
    "#ifdef SY_LX0\n"
    "  if (m_lt0.x >= 0) s = texture(t_l0, ltuv(0, UVSET(m_lt0.x))).a;\n"
    "#endif\n"
    "#ifdef SY_LX1\n"
    "  if (m_lt0.y >= 0) g_l0.rgb *= texture(t_l1, ltuv(1, UVSET(m_lt0.y))).rgb;\n"
    "#endif\n"
    "#ifdef SY_LX2\n"
    "  if (m_lt0.z >= 0) g_l0.w *= texture(t_l2, ltuv(2, UVSET(m_lt0.z))).r;\n"
    "#endif\n"
    "#ifdef SY_LX3\n"
    "  if (m_lt0.w >= 0) g_l1.x *= texture(t_l3, ltuv(3, UVSET(m_lt0.w))).g;\n"
    "#endif\n"
    "#ifdef SY_LX4\n"
    "  if (m_lt1.x >= 0) nc = map_normal(t_l4, ltuv(4, UVSET(m_lt1.x)), m_l2.w, n, dpx, dpy);\n"
    "#endif\n"
    "#ifdef SY_LX5\n"
    "  if (m_lt1.y >= 0) g_l2.rgb *= texture(t_l5, ltuv(5, UVSET(m_lt1.y))).rgb;\n"
    "#endif\n"
    "#ifdef SY_LX6\n"
    "  if (m_lt1.z >= 0) g_l1.y *= texture(t_l6, ltuv(6, UVSET(m_lt1.z))).a;\n"
    "#endif\n"
    "#ifdef SY_LX7\n"
    "  if (m_lt1.w >= 0) g_l1.z *= texture(t_l7, ltuv(7, UVSET(m_lt1.w))).g;\n"
    "#endif\n"
    /* anisotropy: the direction (cos, sin of the rotation) or the texture's RG rotated by it, in the
     * uv tangent frame of the texture's set (uv 0 without one) */
    "#ifdef SY_ANISO\n"
    "  if (m_l4.z > 0.0) {\n"
    "    vec2 t = UVSET(m_lt2.x >= 0 ? m_lt2.x : 0), dir = m_l4.xy; vec3 tg, bt;\n"
    "#ifdef SY_LX8\n"
    "    if (m_lt2.x >= 0) { vec3 a = texture(t_l8, ltuv(8, t)).rgb; vec2 d = a.rg * 2.0 - 1.0;\n"
    "      g_l4.z *= a.b; if (dot(d, d) > 0.0) dir = mat2(m_l4.x, m_l4.y, -m_l4.y, m_l4.x) * normalize(d); }\n"
    "#endif\n"
    "    if (uv_frame(t, n, dpx, dpy, tg, bt)) g_at = tg * dir.x + bt * dir.y;\n"
    "  }\n"
    "#endif\n"
    "#ifdef SY_LX9\n"
    "  if (m_lt2.y >= 0) g_l5.x *= texture(t_l9, ltuv(9, UVSET(m_lt2.y))).r;\n"
    "#endif\n"
    "#ifdef SY_LX10\n"
    "  if (m_lt2.z >= 0) g_l5.w = mix(m_l5.z, m_l5.w, texture(t_l10, ltuv(10, UVSET(m_lt2.z))).g);\n"
    "#endif\n"
    "#endif\n"
    "  g_nc = front ? nc : -nc; return s; }\n"
    "float layer_max3(vec3 c) { return max(c.r, max(c.g, c.b)); }\n"
    /* KHR_materials_iridescence (Belcour and Barla 2017, as the Sample Viewer's iridescence.glsl):
     * the Fresnel of a thin film of index eta2 and thickness d (nm) over a base of F0 f0 at cos c */
    "const mat3 XYZ_TO_REC709 = mat3(3.2404542, -0.9692660, 0.0556434, -1.5371385, 1.8760108, -0.2040259,\n"
    "                                -0.4985314, 0.0415560, 1.0572252);\n"
    "vec3 irid_sensitivity(float opd, vec3 shift) {\n"
    "  float phase = 2.0 * 3.14159265 * opd * 1.0e-9;\n"
    "  vec3 val = vec3(5.4856e-13, 4.4201e-13, 5.2481e-13), pos = vec3(1.6810e+06, 1.7953e+06, 2.2084e+06);\n"
    "  vec3 var = vec3(4.3278e+09, 9.3046e+09, 6.6121e+09);\n"
    "  vec3 xyz = val * sqrt(2.0 * 3.14159265 * var) * cos(pos * phase + shift) * exp(-phase * phase * var);\n"
    "  xyz.x += 9.7470e-14 * sqrt(2.0 * 3.14159265 * 4.5282e+09) * cos(2.2399e+06 * phase + shift.x) * exp(-4.5282e+09 * phase * phase);\n"
    "  return XYZ_TO_REC709 * (xyz / 1.0685e-7); }\n"
    "vec3 irid_fresnel(float eta2, float c, float d, vec3 f0) {\n"
    "  float ior = mix(1.0, eta2, smoothstep(0.0, 0.03, d));\n"
    "  float s2 = (1.0 - c * c) / (ior * ior), c2s = 1.0 - s2; if (c2s < 0.0) return vec3(1.0);\n"
    "  float c2 = sqrt(c2s), r0 = (ior - 1.0) / (ior + 1.0), R12 = schlick1(r0 * r0, c), T121 = 1.0 - R12;\n"
    "  float phi21 = 3.14159265 - (ior < 1.0 ? 3.14159265 : 0.0);\n"
    "  vec3 sf = sqrt(clamp(f0, 0.0, 0.9999)), bior = (1.0 + sf) / (1.0 - sf);\n"
    "  vec3 r1 = (bior - ior) / (bior + ior), R23 = schlick(r1 * r1, c2);\n"
    "  vec3 phi23 = vec3(bior.x < ior ? 3.14159265 : 0.0, bior.y < ior ? 3.14159265 : 0.0, bior.z < ior ? 3.14159265 : 0.0);\n"
    "  float opd = 2.0 * ior * d * c2; vec3 phi = vec3(phi21) + phi23;\n"
    "  vec3 R123 = clamp(R12 * R23, 1e-5, 0.9999), r123 = sqrt(R123), Rs = T121 * T121 * R23 / (1.0 - R123);\n"
    "  vec3 I = R12 + Rs, Cm = Rs - T121;\n"
    /* the first two orders of the series, in a loop whose bound (2 for any film: d >= 0) the \
     * compiler cannot see, so irid_sensitivity is inlined once (issue 32's compile time) */ \
    "  int orders = d >= 0.0 ? 2 : 0;\n"
    "  for (int m = 1; m <= orders; ++m) { Cm *= r123; I += Cm * 2.0 * irid_sensitivity(float(m) * opd, float(m) * phi); }\n"
    "  return max(I, vec3(0.0)); }\n"
    /* the dielectric lobe's F0 f0c (tinted by the specular colour) and the metal's f0m (the base
     * colour), each mixed by the film's weight with the film's F0 seen at n.v (Schlick inverted, as
     * the Sample Viewer). One film over the base mix(f0c, bc, metallic) serves both lobes (exact
     * for metals and dielectrics; the Sample Viewer evaluates two, which doubles the compile) */
    "float layer_scale(vec3 ns, vec3 wo);\n"
    "float layer_sheen_e(float nv, float r);\n"
    "bool layer_frame(vec3 ns, out vec3 T, out vec3 B);\n"
    /* once per fragment: also g_ls and the anisotropy frame (not per light: every light's call is
     * inlined, and llvmpipe compiles each copy) */
    "void layer_f0(float f0, vec3 bc, float metallic, vec3 ns, vec3 wo, float nv, out vec3 f0c, out vec3 f0m) {\n"
    "  g_se = layer_sheen_e(max(dot(ns, wo), 0.0), g_l1.y);\n" /* once: layer_scale and layer_area read it */
    "  g_ls = layer_scale(ns, wo); g_an = layer_frame(ns, g_T, g_B);\n"
    "  f0c = min(f0 * g_l0.rgb, vec3(1.0)); f0m = bc;\n"
    "#ifdef SY_IRID\n"
    "  if (!(g_l5.x > 0.0)) return;\n"
    "  float m = 1.0 - clamp(nv, 0.0, 1.0), m5 = m * m * m * m * m;\n"
    "  vec3 F = irid_fresnel(g_l5.y, nv, g_l5.w, mix(f0c, bc, metallic));\n"
    "  vec3 fi = clamp((F - m5) / max(1.0 - m5, 1e-4), 0.0, 1.0);\n"
    "  f0c = mix(f0c, fi, g_l5.x); f0m = mix(bc, fi, g_l5.x);\n"
    "#endif\n"
    "}\n"
    /* KHR_materials_anisotropy: the GGX lobe stretched along g_at for lights (alpha_t = mix(a, 1,
     * s^2), alpha_b = a) and the bent normal for the environment, as the Sample Viewer */
    "bool layer_frame(vec3 ns, out vec3 T, out vec3 B) {\n"
    "  T = g_at - ns * dot(ns, g_at); B = vec3(0.0);\n"
    "#ifdef SY_ANISO\n"
    "  if (!(g_l4.z > 0.0) || !(dot(T, T) > 1e-20)) return false;\n"
    "  T = normalize(T); B = cross(ns, T); return true;\n"
    "#else\n"
    "  return false;\n"
    "#endif\n"
    "}\n"
    "void layer_aniso(vec3 wi, vec3 wo, vec3 h, vec3 ns, float nl, float nv, float rough, inout float D, inout float V) {\n"
    "  if (!g_an) return; vec3 T = g_T, B = g_B;\n"
    "  float a = max(rough * rough, 1e-4), s = g_l4.z, at = mix(a, 1.0, s * s), ab = clamp(a, 1e-3, 1.0), a2 = at * ab;\n"
    "  vec3 f = vec3(ab * dot(T, h), at * dot(B, h), a2 * dot(ns, h)); float w2 = a2 / dot(f, f);\n"
    "  D = a2 * w2 * w2 * INV_PI;\n"
    "  float gv = nl * length(vec3(at * dot(T, wo), ab * dot(B, wo), nv));\n"
    "  float gl = nv * length(vec3(at * dot(T, wi), ab * dot(B, wi), nl));\n"
    "  V = clamp(0.5 / (gv + gl), 0.0, 1.0); }\n"
    "vec3 layer_reflect(vec3 wo, vec3 ns, float rough) {\n"
    "  if (!g_an) return reflect(-wo, ns); vec3 B = g_B;\n"
    "  vec3 an = cross(cross(B, wo), B); float bf = 1.0 - g_l4.z * (1.0 - rough); bf *= bf; bf *= bf;\n"
    "  vec3 bn = mix(an, ns, bf); bn = dot(bn, bn) > 0.0 ? normalize(bn) : ns;\n"
    "  return reflect(-wo, bn); }\n"
    "float layer_sheen_e(float nv, float r) {\n"
    "  return textureLod(t_brdf, vec2(nv, r) * (31.0 / 32.0) + 0.5 / 32.0, 0.0).b; }\n"
    /* what lies under the coat and the sheen keeps this much of its light */
    "float layer_scale(vec3 ns, vec3 wo) {\n"
    "  float s = 1.0 - g_l0.w * schlick1(0.04, max(dot(g_nc, wo), 0.0));\n"
    "  return s * (1.0 - layer_max3(g_l2.rgb) * g_se); }\n"
    /* f: the base's BRDF for light from wi (ns.wi = nl > 0); the caller multiplies by nl */
    "vec3 layer_light(vec3 wi, vec3 wo, vec3 ns, float nl, vec3 f) {\n"
    "  vec3 h = normalize(wi + wo); vec3 r = f * g_ls;\n"
    "  if (layer_max3(g_l2.rgb) > 0.0) {\n"
    "    float nv = max(dot(ns, wo), 1e-4), sa = max(g_l1.y * g_l1.y, 1e-4), inv = 1.0 / sa;\n"
    "    float nh = dot(ns, h), s2 = max(1.0 - nh * nh, 0.0);\n"
    "    float D = (2.0 + inv) * pow(s2, 0.5 * inv) * (0.5 * INV_PI);\n"
    "    r += g_l2.rgb * (D / (4.0 * (nl + nv - nl * nv)));\n"
    "  }\n"
    "  float cr = g_l1.x, cl = dot(g_nc, wi);\n"
    "  if (g_l0.w > 0.0 && cr > 0.0 && cl > 0.0) {\n" /* roughness 0: a mirror, no punctual highlight (as the base) */
    "    float cv = max(dot(g_nc, wo), 1e-4), a = max(cr * cr, 1e-4), a2 = a * a, nh = max(dot(g_nc, h), 0.0);\n"
    "    float dd = nh * nh * (a2 - 1.0) + 1.0, D = a2 * INV_PI / (dd * dd);\n"
    "    float V = 0.5 / (cl * sqrt(cv * cv * (1.0 - a2) + a2) + cv * sqrt(cl * cl * (1.0 - a2) + a2));\n"
    "    r += vec3(g_l0.w * schlick1(0.04, max(dot(wo, h), 0.0)) * D * V * cl / nl);\n"
    "  }\n"
    "  return r; }\n"
    "#if defined(SY_ENV) || defined(SY_PROBE)\n"
    /* env: the base's environment light; irr: the irradiance cube's mean radiance at ns */
    "vec3 layer_env(vec3 env, vec3 ns, vec3 wo, float nv, vec3 irr) {\n"
    "  vec3 r = env * g_ls + g_l2.rgb * layer_sheen_e(nv, g_l1.y) * irr;\n"
    "  if (g_l0.w > 0.0) {\n"
    "    float cv = max(dot(g_nc, wo), 1e-4), cr = g_l1.x, ga = cr * cr;\n"
    "    vec2 ab = textureLod(t_brdf, vec2(cv, cr) * (31.0 / 32.0) + 0.5 / 32.0, 0.0).rg;\n"
    "    vec3 R = reflect(-wo, g_nc), Rd = normalize(mix(g_nc, R, (1.0 - ga) * (sqrt(1.0 - ga) + ga)));\n"
    "    r += g_l0.w * (0.04 * ab.x + ab.y) * env_spec(Rd, cr);\n"
    "  }\n"
    "  return r; }\n"
    "#endif\n"
    /* emissive polygons: the coat's GGX lobe by linearly transformed cosines (as the base's in
     * sy_gl_shaders.c, shade_lit) about the coat normal, F0 0.04, none at roughness 0 (as the
     * base); the sheen as a wide lobe of albedo sheen colour x E(n.v) on the diffuse form factor
     * (as the environment's irradiance stands in for its prefiltered light) */
    "void layer_area(vec3 ns, vec3 wo) {\n"
    "  g_sh = g_l2.rgb * g_se;\n"
    "  g_fc = g_l1.x > 0.0 ? g_l0.w : 0.0; g_Mc = mat3(1.0); if (!(g_fc > 0.0)) return;\n"
    "  vec3 n = g_nc; float cv = max(dot(n, wo), 1e-4);\n"
    "  vec2 luv = vec2(g_l1.x, sqrt(1.0 - cv)) * (63.0 / 64.0) + 0.5 / 64.0;\n"
    "  vec4 t1 = textureLod(t_ltc1, luv, 0.0), t2 = textureLod(t_ltc2, luv, 0.0);\n"
    "  vec3 T1 = normalize(wo - n * dot(wo, n)), T2 = cross(n, T1);\n"
    "  g_Mc = mat3(vec3(t1.x, 0.0, t1.y), vec3(0.0, 1.0, 0.0), vec3(t1.z, 0.0, t1.w)) * transpose(mat3(T1, T2, n));\n"
    "  g_fc *= 0.04 * t2.x + 0.96 * t2.y; }\n"
    "vec3 layer_transmittance() {\n"
    "  if (!(g_l1.z > 0.0 && g_l1.w > 0.0)) return vec3(1.0);\n"
    "  float s = (length(u_model[0].xyz) + length(u_model[1].xyz) + length(u_model[2].xyz)) / 3.0;\n"
    "  return pow(clamp(g_l3.rgb, 0.0, 1.0), vec3(g_l1.z * s / g_l1.w)); }\n";
