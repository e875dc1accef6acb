/* sy_gl_context.h — internal: GL context providers (OSMesa, EGL, GLFW) and the table of GL 3.3
 * entry points loaded through the provider's GetProcAddress. No GL library is linked directly, so
 * the renderer code (sy_gl_device.c and the modules of sy_gl_internal.h) is identical on every provider.
 *
 * Ownership: sy_gl_context_destroy releases everything sy_gl_context_create made. Thread-safety:
 * a context is current on one thread at a time (sy_gl_context_make_current). */
#ifndef SY_GL_CONTEXT_H
#define SY_GL_CONTEXT_H

#include "sy_gl.h"

#include <GL/glcorearb.h>

/* X-list of every GL function the renderer calls: X(type, name). */
#define SY_GL_FUNCS(X)                                                                                             \
    X(PFNGLGETSTRINGPROC, GetString) X(PFNGLGETINTEGERVPROC, GetIntegerv) X(PFNGLGETERRORPROC, GetError)         \
    X(PFNGLENABLEPROC, Enable) X(PFNGLDISABLEPROC, Disable) X(PFNGLENABLEIPROC, Enablei)                         \
    X(PFNGLDISABLEIPROC, Disablei) X(PFNGLVIEWPORTPROC, Viewport) X(PFNGLCLEARPROC, Clear)                       \
    X(PFNGLCLEARBUFFERFVPROC, ClearBufferfv) X(PFNGLCLEARDEPTHPROC, ClearDepth) X(PFNGLDEPTHFUNCPROC, DepthFunc) \
    X(PFNGLCULLFACEPROC, CullFace)                                                                               \
    X(PFNGLDEPTHMASKPROC, DepthMask) X(PFNGLCOLORMASKPROC, ColorMask) X(PFNGLCOLORMASKIPROC, ColorMaski)          \
    X(PFNGLBLENDFUNCPROC, BlendFunc) X(PFNGLPOLYGONOFFSETPROC, PolygonOffset) X(PFNGLPIXELSTOREIPROC, PixelStorei) \
    X(PFNGLREADPIXELSPROC, ReadPixels) X(PFNGLREADBUFFERPROC, ReadBuffer) X(PFNGLDRAWBUFFERSPROC, DrawBuffers)   \
    X(PFNGLDRAWBUFFERPROC, DrawBuffer) X(PFNGLFINISHPROC, Finish) X(PFNGLGENBUFFERSPROC, GenBuffers)             \
    X(PFNGLDELETEBUFFERSPROC, DeleteBuffers) X(PFNGLBINDBUFFERPROC, BindBuffer) X(PFNGLBUFFERDATAPROC, BufferData) \
    X(PFNGLBUFFERSUBDATAPROC, BufferSubData) X(PFNGLBINDBUFFERBASEPROC, BindBufferBase)                          \
    X(PFNGLGENVERTEXARRAYSPROC, GenVertexArrays) X(PFNGLDELETEVERTEXARRAYSPROC, DeleteVertexArrays)              \
    X(PFNGLBINDVERTEXARRAYPROC, BindVertexArray) X(PFNGLENABLEVERTEXATTRIBARRAYPROC, EnableVertexAttribArray)    \
    X(PFNGLVERTEXATTRIBPOINTERPROC, VertexAttribPointer) X(PFNGLVERTEXATTRIB4FPROC, VertexAttrib4f)              \
    X(PFNGLDRAWELEMENTSPROC, DrawElements) X(PFNGLDRAWARRAYSPROC, DrawArrays)                                     \
    X(PFNGLCREATESHADERPROC, CreateShader) X(PFNGLSHADERSOURCEPROC, ShaderSource)                                 \
    X(PFNGLCOMPILESHADERPROC, CompileShader) X(PFNGLGETSHADERIVPROC, GetShaderiv)                                 \
    X(PFNGLGETSHADERINFOLOGPROC, GetShaderInfoLog) X(PFNGLDELETESHADERPROC, DeleteShader)                         \
    X(PFNGLCREATEPROGRAMPROC, CreateProgram) X(PFNGLATTACHSHADERPROC, AttachShader)                               \
    X(PFNGLLINKPROGRAMPROC, LinkProgram) X(PFNGLGETPROGRAMIVPROC, GetProgramiv)                                   \
    X(PFNGLGETPROGRAMINFOLOGPROC, GetProgramInfoLog) X(PFNGLDELETEPROGRAMPROC, DeleteProgram)                     \
    X(PFNGLUSEPROGRAMPROC, UseProgram) X(PFNGLGETUNIFORMLOCATIONPROC, GetUniformLocation)                         \
    X(PFNGLGETUNIFORMBLOCKINDEXPROC, GetUniformBlockIndex) X(PFNGLUNIFORMBLOCKBINDINGPROC, UniformBlockBinding)  \
    X(PFNGLUNIFORM1IPROC, Uniform1i) X(PFNGLUNIFORM1FPROC, Uniform1f) X(PFNGLUNIFORM3FVPROC, Uniform3fv)         \
    X(PFNGLUNIFORM2FVPROC, Uniform2fv) X(PFNGLTEXSUBIMAGE2DPROC, TexSubImage2D)                                   \
    X(PFNGLUNIFORM4FVPROC, Uniform4fv) X(PFNGLUNIFORMMATRIX4FVPROC, UniformMatrix4fv)                            \
    X(PFNGLUNIFORMMATRIX3FVPROC, UniformMatrix3fv) X(PFNGLGENTEXTURESPROC, GenTextures)                          \
    X(PFNGLDELETETEXTURESPROC, DeleteTextures) X(PFNGLBINDTEXTUREPROC, BindTexture)                               \
    X(PFNGLACTIVETEXTUREPROC, ActiveTexture) X(PFNGLTEXIMAGE2DPROC, TexImage2D) X(PFNGLTEXIMAGE3DPROC, TexImage3D) \
    X(PFNGLTEXPARAMETERIPROC, TexParameteri) X(PFNGLTEXPARAMETERFVPROC, TexParameterfv)                          \
    X(PFNGLGENERATEMIPMAPPROC, GenerateMipmap) X(PFNGLTEXIMAGE2DMULTISAMPLEPROC, TexImage2DMultisample)          \
    X(PFNGLGENFRAMEBUFFERSPROC, GenFramebuffers) X(PFNGLDELETEFRAMEBUFFERSPROC, DeleteFramebuffers)              \
    X(PFNGLBINDFRAMEBUFFERPROC, BindFramebuffer) X(PFNGLFRAMEBUFFERTEXTURE2DPROC, FramebufferTexture2D)          \
    X(PFNGLFRAMEBUFFERTEXTURELAYERPROC, FramebufferTextureLayer)                                                  \
    X(PFNGLCHECKFRAMEBUFFERSTATUSPROC, CheckFramebufferStatus) X(PFNGLBLITFRAMEBUFFERPROC, BlitFramebuffer)      \
    X(PFNGLGENRENDERBUFFERSPROC, GenRenderbuffers) X(PFNGLDELETERENDERBUFFERSPROC, DeleteRenderbuffers)          \
    X(PFNGLBINDRENDERBUFFERPROC, BindRenderbuffer)                                                                \
    X(PFNGLRENDERBUFFERSTORAGEMULTISAMPLEPROC, RenderbufferStorageMultisample)                                    \
    X(PFNGLFRAMEBUFFERRENDERBUFFERPROC, FramebufferRenderbuffer)                                                  \
    X(PFNGLFENCESYNCPROC, FenceSync) X(PFNGLCLIENTWAITSYNCPROC, ClientWaitSync) X(PFNGLDELETESYNCPROC, DeleteSync) \
    X(PFNGLGETBUFFERSUBDATAPROC, GetBufferSubData)

typedef struct sy_gl_fns {
#define SY_GL_MEMBER(type, name) type name;
    SY_GL_FUNCS(SY_GL_MEMBER)
#undef SY_GL_MEMBER
} sy_gl_fns;

typedef struct sy_gl_context sy_gl_context;

/* The error report every failing call of the rasterizer goes through (a device's, or the desc's
 * while sy_gl_device_create has no device yet): the callback and the last message. */
#define SY_GL_ERROR_MAX 512 /* bytes of a reported message, NUL included (as core's sy_error) */
typedef struct sy_gl_report {
    sy_gl_error_fn fn;
    void *user;
    char message[SY_GL_ERROR_MAX];
} sy_gl_report;
/* Formats the printf-style message into rep->message and hands it to rep->fn (rep may be NULL:
 * nothing is reported); returns r. Here, in the lowest module, as every other module reports. */
sy_gl_result sy_gli_fail(sy_gl_report *rep, sy_gl_result r, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* Creates a GL 3.3 core context with the provider and loads the table. window_w/h: GLFW only. */
sy_gl_result sy_gl_context_create(sy_gl_provider provider, uint32_t window_w, uint32_t window_h,
                                  sy_gl_context **out, sy_gl_report *rep);
void sy_gl_context_destroy(sy_gl_context *c);
bool sy_gl_context_make_current(sy_gl_context *c);
const sy_gl_fns *sy_gl_context_fns(const sy_gl_context *c);
sy_gl_provider sy_gl_context_provider(const sy_gl_context *c);
/* GLFW: shows the read framebuffer's colour (w x h) in the window and polls events. Else no-op. */
void sy_gl_context_present(sy_gl_context *c, uint32_t fbo, uint32_t w, uint32_t h);
bool sy_gl_context_should_close(sy_gl_context *c);

#endif /* SY_GL_CONTEXT_H */
