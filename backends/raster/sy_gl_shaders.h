/* sy_gl_shaders.h — internal: GLSL 3.30 core sources of the rasterizer's programs (main PBR
 * pass, shadow pass, sky, MSAA resolve, benchmark floor) and the compile/link helper that returns the
 * driver's info log on failure. */
#ifndef SY_GL_SHADERS_H
#define SY_GL_SHADERS_H

#include "sy_gl_context.h"

/* Section planes in the vertex shaders that draw the scene (main, G-buffer, shadow and pick passes):
 * the Clip block (binding BIND_CLIP, sy_gli_clip_set) holds 6 planes in world space, the unused ones
 * {0, 0, 0, 1}; sy_clip(world position) writes gl_ClipDistance[0..5], and the passes enable
 * GL_CLIP_DISTANCE0 + i for the planes in use only while they draw the scene (sy_gli_clip_enable). */
#define SY_GL_CLIP_VS                                                                                    \
    "layout(std140) uniform Clip { vec4 c_planes[6]; };\n"                                                \
    "out float gl_ClipDistance[6];\n"                                                                     \
    "void sy_clip(vec3 w) { vec4 h = vec4(w, 1.0);\n"                                                     \
    "  gl_ClipDistance[0] = dot(c_planes[0], h); gl_ClipDistance[1] = dot(c_planes[1], h);\n"            \
    "  gl_ClipDistance[2] = dot(c_planes[2], h); gl_ClipDistance[3] = dot(c_planes[3], h);\n"            \
    "  gl_ClipDistance[4] = dot(c_planes[4], h); gl_ClipDistance[5] = dot(c_planes[5], h); }\n"

extern const char *const sy_gl_main_vs, *const sy_gl_main_fs;
extern const char *const sy_gl_shadow_vs, *const sy_gl_shadow_fs;
extern const char *const sy_gl_fullscreen_vs; /* a full-screen triangle (the sky, the IBL tables) */
extern const char *const sy_gl_resolve_fs;    /* the MSAA resolve, with sy_gl_rect_vs */
extern const char *const sy_gl_sky_fs; /* with sy_gl_fullscreen_vs */
extern const char *const sy_gl_floor_vs, *const sy_gl_floor_fs;
extern const char *const sy_gl_gbuf_vs, *const sy_gl_gbuf_fs; /* deferred shading: the geometry pass */
extern const char *const sy_gl_deferred_fs; /* ... its shading and resolve pass, with sy_gl_rect_vs */
/* rectangles (the deferred pass and the resolve beside it): uniform vec4 u_rects[SY_GL_MAX_RECTS]
 * (NDC x0, y0, x1, y1), 6 vertices each */
extern const char *const sy_gl_rect_vs;
#define SY_GL_MAX_RECTS 16

/* Compiles and links; fs_defines (NULL = none, e.g. "#define SY_MASK 1\n") is inserted after the
 * #version line of both stages. On failure returns SY_GL_ERROR_GL with "<name> shader: <stage> compile
 * failed: <log>" (or link log) reported to rep. */
sy_gl_result sy_gl_program_build(const sy_gl_fns *gl, const char *name, const char *vs, const char *fs,
                                 const char *fs_defines, GLuint *out, sy_gl_report *rep);

/* The same with fs_tail (NULL = none) appended to the fragment source: more functions, which the
 * source declares. */
sy_gl_result sy_gl_program_build_tail(const sy_gl_fns *gl, const char *name, const char *vs, const char *fs,
                                      const char *fs_defines, const char *fs_tail, GLuint *out, sy_gl_report *rep);

/* sy_gl_shaders_layers.c: the material extensions' functions of the main fragment shader's
 * SY_LAYERS variants (layer_f0, layer_light, layer_scale, layer_env, layer_transmittance), the
 * tail of sy_gl_main_fs. */
extern const char *const sy_gl_layers_fs;

#endif /* SY_GL_SHADERS_H */
