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
 *    (the surface's normal without the base's normal map), for punctual lights and the environment
 *    (split sum), and everything under it x (1 - clearcoat x Schlick(0.04, n_c.v));
 *  - KHR_materials_sheen: sheen_color x Charlie D (alpha = roughness^2) x Neubelt visibility for
 *    punctual lights; for the environment sheen_color x E(n.v) x the irradiance cube's mean
 *    radiance (the lobe is wide; the Sample Viewer prefilters a Charlie cube instead); the base x
 *    (1 - max(sheen_color) E(n.v)), E from the BRDF table's third channel (sy_gl_ibl.c);
 *  - KHR_materials_volume: the refracted environment x attenuation_color^(d / attenuation_distance),
 *    d = thickness x the instance's mean axis scale (Beer-Lambert over the thickness as the Sample
 *    Viewer takes it; thickness 0 or distance 0 = none).
 * Material uniforms: m_l0 (specular colour, clearcoat), m_l1 (coat roughness, sheen roughness,
 * thickness, attenuation distance), m_l2 (sheen colour, coat normal scale), m_l3 (attenuation
 * colour); the textures (units t_l0 .. t_l7, uv sets m_lt0, m_lt1, transforms m_lxf) scale them
 * as glTF says (layer_init: specular A, specular colour RGB, clearcoat R, coat roughness G, coat
 * normal, sheen colour RGB, sheen roughness A, thickness G) into g_l0 .. g_l3. */
#include "sy_gl_shaders.h"

const char *const sy_gl_layers_fs =
    "\n"
    "uniform mat4 u_model;\n" /* the vertex stage's: the instance's scale for the volume */
    "uniform sampler2D t_l0, t_l1, t_l2, t_l3, t_l4, t_l5, t_l6, t_l7;\n"
    "vec4 g_l0, g_l1, g_l2, g_l3;\n" /* m_l0 .. m_l3 times the textures (layer_init) */
    "vec2 ltuv(int k, vec2 t) { vec3 h = vec3(t, 1.0); return vec2(dot(m_lxf[2*k].xyz, h), dot(m_lxf[2*k+1].xyz, h)); }\n"
    /* the factors times their textures (slots: sy_gli_layer_refs; uv sets in m_lt0, m_lt1, -1 = none)
     * and the coat's normal (the vertex normal n, bent by its own map, flipped to the side seen);
     * returns the specular texture's factor */
    "float layer_init(vec3 n, bool front, vec3 dpx, vec3 dpy) {\n"
    "  g_l0 = m_l0; g_l1 = m_l1; g_l2 = m_l2; g_l3 = m_l3; float s = 1.0; vec3 nc = n;\n"
    "#ifdef SY_TEX\n"
    "  if (m_lt0.x >= 0) s = texture(t_l0, ltuv(0, UVSET(m_lt0.x))).a;\n"
    "  if (m_lt0.y >= 0) g_l0.rgb *= texture(t_l1, ltuv(1, UVSET(m_lt0.y))).rgb;\n"
    "  if (m_lt0.z >= 0) g_l0.w *= texture(t_l2, ltuv(2, UVSET(m_lt0.z))).r;\n"
    "  if (m_lt0.w >= 0) g_l1.x *= texture(t_l3, ltuv(3, UVSET(m_lt0.w))).g;\n"
    "  if (m_lt1.x >= 0) nc = map_normal(t_l4, ltuv(4, UVSET(m_lt1.x)), m_l2.w, n, dpx, dpy);\n"
    "  if (m_lt1.y >= 0) g_l2.rgb *= texture(t_l5, ltuv(5, UVSET(m_lt1.y))).rgb;\n"
    "  if (m_lt1.z >= 0) g_l1.y *= texture(t_l6, ltuv(6, UVSET(m_lt1.z))).a;\n"
    "  if (m_lt1.w >= 0) g_l1.z *= texture(t_l7, ltuv(7, UVSET(m_lt1.w))).g;\n"
    "#endif\n"
    "  g_nc = front ? nc : -nc; return s; }\n"
    "float layer_max3(vec3 c) { return max(c.r, max(c.g, c.b)); }\n"
    "vec3 layer_f0(float f0) { return min(f0 * g_l0.rgb, vec3(1.0)); }\n"
    "float layer_sheen_e(float nv, float r) {\n"
    "  return textureLod(t_brdf, vec2(nv, r) * (31.0 / 32.0) + 0.5 / 32.0, 0.0).b; }\n"
    /* what lies under the coat and the sheen keeps this much of its light */
    "float layer_scale(vec3 ns, vec3 wo) {\n"
    "  float s = 1.0 - g_l0.w * schlick1(0.04, max(dot(g_nc, wo), 0.0));\n"
    "  return s * (1.0 - layer_max3(g_l2.rgb) * layer_sheen_e(max(dot(ns, wo), 0.0), g_l1.y)); }\n"
    /* f: the base's BRDF for light from wi (ns.wi = nl > 0); the caller multiplies by nl */
    "vec3 layer_light(vec3 wi, vec3 wo, vec3 ns, float nl, vec3 f) {\n"
    "  vec3 h = normalize(wi + wo); vec3 r = f * layer_scale(ns, wo);\n"
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
    "  vec3 r = env * layer_scale(ns, wo) + g_l2.rgb * layer_sheen_e(nv, g_l1.y) * irr;\n"
    "  if (g_l0.w > 0.0) {\n"
    "    float cv = max(dot(g_nc, wo), 1e-4), cr = g_l1.x, ga = cr * cr;\n"
    "    vec2 ab = textureLod(t_brdf, vec2(cv, cr) * (31.0 / 32.0) + 0.5 / 32.0, 0.0).rg;\n"
    "    vec3 R = reflect(-wo, g_nc), Rd = normalize(mix(g_nc, R, (1.0 - ga) * (sqrt(1.0 - ga) + ga)));\n"
    "    r += g_l0.w * (0.04 * ab.x + ab.y) * env_spec(Rd, cr);\n"
    "  }\n"
    "  return r; }\n"
    "#endif\n"
    "vec3 layer_transmittance() {\n"
    "  if (!(g_l1.z > 0.0 && g_l1.w > 0.0)) return vec3(1.0);\n"
    "  float s = (length(u_model[0].xyz) + length(u_model[1].xyz) + length(u_model[2].xyz)) / 3.0;\n"
    "  return pow(clamp(g_l3.rgb, 0.0, 1.0), vec3(g_l1.z * s / g_l1.w)); }\n";
