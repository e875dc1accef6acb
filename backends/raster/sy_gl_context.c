/* sy_gl_context.c — GL context providers (see sy_gl_context.h): OSMesa (OSMesaCreateContextAttribs,
 * core profile 3.3, a 1x1 default buffer since rendering goes to framebuffer objects), EGL (an EGL
 * device from EGL_EXT_device_enumeration first, then Mesa's surfaceless platform; configless
 * surfaceless context) and GLFW (a window with a 3.3 core context); the error report every module of
 * the rasterizer fails through (sy_gli_fail). */
#include "sy_gl_context.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/osmesa.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <dlfcn.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* OSMesa is opened privately (dlopen RTLD_LOCAL), never linked: libOSMesa exports every gl*
 * symbol, and a direct link would interpose them on an application that also uses libGL / libOpenGL
 * for its own windows (the `sy view` viewer). */
typedef struct osmesa_api {
    void *lib;
    OSMesaContext (*create)(const int *attribs, OSMesaContext share);
    GLboolean (*make_current)(OSMesaContext, void *, GLenum, GLsizei, GLsizei);
    void (*destroy)(OSMesaContext);
    OSMESAproc (*get_proc)(const char *);
} osmesa_api;

struct sy_gl_context {
    sy_gl_provider provider;
    sy_gl_fns gl;
    osmesa_api om;
    OSMesaContext osmesa;
    unsigned char osmesa_buf[16];
    EGLDisplay egl_display;
    EGLContext egl_context;
    GLFWwindow *window;
};

sy_gl_result sy_gli_fail(sy_gl_report *rep, sy_gl_result r, const char *fmt, ...)
{
    if (!rep) return r;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(rep->message, sizeof rep->message, fmt, ap);
    va_end(ap);
    if (rep->fn) rep->fn(rep->user, r, rep->message);
    return r;
}

typedef void (*proc_fn)(void);

static proc_fn get_proc(const sy_gl_context *c, const char *name)
{
    switch (c->provider) {
    case SY_GL_PROVIDER_OSMESA: return (proc_fn)c->om.get_proc(name);
    case SY_GL_PROVIDER_EGL: return (proc_fn)eglGetProcAddress(name);
    case SY_GL_PROVIDER_GLFW: return (proc_fn)glfwGetProcAddress(name);
    default: return NULL;
    }
}

static sy_gl_result load_fns(sy_gl_context *c, sy_gl_report *rep)
{
#define SY_GL_LOAD(type, name)                                                                                      \
    c->gl.name = (type)get_proc(c, "gl" #name);                                                                     \
    if (!c->gl.name)                                                                                                \
        return sy_gli_fail(rep, SY_GL_ERROR_NO_CONTEXT, "%s: the GL context lacks gl" #name " (OpenGL 3.3 core needed)", \
                    sy_gl_provider_name(c->provider));
    SY_GL_FUNCS(SY_GL_LOAD)
#undef SY_GL_LOAD
    const char *ver = (const char *)c->gl.GetString(GL_VERSION);
    int major = 0, minor = 0;
    if (!ver || sscanf(ver, "%d.%d", &major, &minor) != 2 || major * 10 + minor < 33)
        return sy_gli_fail(rep, SY_GL_ERROR_NO_CONTEXT, "%s: OpenGL 3.3 core needed, the context gives '%s'",
                    sy_gl_provider_name(c->provider), ver ? ver : "(no version)");
    return SY_GL_OK;
}

static sy_gl_result create_osmesa(sy_gl_context *c, sy_gl_report *rep)
{
    static const char *const names[] = {"libOSMesa.so.8", "libOSMesa.so.6", "libOSMesa.so"};
    for (size_t i = 0; i < sizeof names / sizeof names[0] && !c->om.lib; ++i)
        c->om.lib = dlopen(names[i], RTLD_NOW | RTLD_LOCAL);
    if (!c->om.lib)
        return sy_gli_fail(rep, SY_GL_ERROR_NO_CONTEXT, "osmesa: cannot load libOSMesa (%s); install libosmesa6",
                    dlerror());
    *(void **)&c->om.create = dlsym(c->om.lib, "OSMesaCreateContextAttribs");
    *(void **)&c->om.make_current = dlsym(c->om.lib, "OSMesaMakeCurrent");
    *(void **)&c->om.destroy = dlsym(c->om.lib, "OSMesaDestroyContext");
    *(void **)&c->om.get_proc = dlsym(c->om.lib, "OSMesaGetProcAddress");
    if (!c->om.create || !c->om.make_current || !c->om.destroy || !c->om.get_proc)
        return sy_gli_fail(rep, SY_GL_ERROR_NO_CONTEXT,
                    "osmesa: libOSMesa lacks OSMesaCreateContextAttribs (Mesa >= 12 needed for core contexts)");
    const int attrs[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 0, OSMESA_STENCIL_BITS, 0,
                         OSMESA_PROFILE, OSMESA_CORE_PROFILE, OSMESA_CONTEXT_MAJOR_VERSION, 3,
                         OSMESA_CONTEXT_MINOR_VERSION, 3, 0};
    c->osmesa = c->om.create(attrs, NULL);
    if (!c->osmesa)
        return sy_gli_fail(rep, SY_GL_ERROR_NO_CONTEXT,
                    "osmesa: OSMesaCreateContextAttribs could not create an OpenGL 3.3 core context");
    if (!c->om.make_current(c->osmesa, c->osmesa_buf, GL_UNSIGNED_BYTE, 2, 2))
        return sy_gli_fail(rep, SY_GL_ERROR_NO_CONTEXT, "osmesa: OSMesaMakeCurrent failed");
    return SY_GL_OK;
}

static const char *egl_error_str(EGLint e)
{
    switch (e) {
    case EGL_SUCCESS: return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED: return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS: return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC: return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE: return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG: return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT: return "EGL_BAD_CONTEXT";
    case EGL_BAD_DISPLAY: return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH: return "EGL_BAD_MATCH";
    case EGL_BAD_PARAMETER: return "EGL_BAD_PARAMETER";
    default: return "EGL error";
    }
}

/* Tries one EGL display: initialise, bind desktop GL, create a configless 3.3 core context. */
static bool egl_try(sy_gl_context *c, EGLDisplay d, char *why, size_t why_len)
{
    EGLint major, minor;
    if (d == EGL_NO_DISPLAY) {
        snprintf(why, why_len, "no display");
        return false;
    }
    if (!eglInitialize(d, &major, &minor)) {
        snprintf(why, why_len, "eglInitialize: %s", egl_error_str(eglGetError()));
        return false;
    }
    const char *ext = eglQueryString(d, EGL_EXTENSIONS);
    if (!ext || !strstr(ext, "EGL_KHR_surfaceless_context") ||
        (!strstr(ext, "EGL_KHR_no_config_context") && !strstr(ext, "EGL_MESA_configless_context"))) {
        snprintf(why, why_len, "display lacks EGL_KHR_surfaceless_context / configless contexts");
        eglTerminate(d);
        return false;
    }
    if (!eglBindAPI(EGL_OPENGL_API)) {
        snprintf(why, why_len, "eglBindAPI(EGL_OPENGL_API): %s", egl_error_str(eglGetError()));
        eglTerminate(d);
        return false;
    }
    const EGLint ca[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 3, EGL_CONTEXT_OPENGL_PROFILE_MASK,
                         EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    EGLContext ctx = eglCreateContext(d, (EGLConfig)0, EGL_NO_CONTEXT, ca);
    if (ctx == EGL_NO_CONTEXT) {
        snprintf(why, why_len, "eglCreateContext (3.3 core): %s", egl_error_str(eglGetError()));
        eglTerminate(d);
        return false;
    }
    if (!eglMakeCurrent(d, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx)) {
        snprintf(why, why_len, "eglMakeCurrent: %s", egl_error_str(eglGetError()));
        eglDestroyContext(d, ctx);
        eglTerminate(d);
        return false;
    }
    c->egl_display = d;
    c->egl_context = ctx;
    return true;
}

static sy_gl_result create_egl(sy_gl_context *c, sy_gl_report *rep)
{
    const char *cext = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    PFNEGLGETPLATFORMDISPLAYEXTPROC get_display =
        (PFNEGLGETPLATFORMDISPLAYEXTPROC)eglGetProcAddress("eglGetPlatformDisplayEXT");
    char why_dev[160] = "EGL_EXT_device_enumeration not offered", why_sl[160] = "EGL_MESA_platform_surfaceless not offered";
    if (!cext || !get_display)
        return sy_gli_fail(rep, SY_GL_ERROR_NO_CONTEXT,
                    "egl: no EGL client extensions (libEGL without a vendor library?); try --gl osmesa");
    /* 1. an EGL device (a GPU driver, or Mesa's software device) */
    if (strstr(cext, "EGL_EXT_device_enumeration") && strstr(cext, "EGL_EXT_platform_device")) {
        PFNEGLQUERYDEVICESEXTPROC query = (PFNEGLQUERYDEVICESEXTPROC)eglGetProcAddress("eglQueryDevicesEXT");
        EGLDeviceEXT devs[16];
        EGLint n = 0;
        if (query && query(16, devs, &n) && n > 0) {
            for (EGLint i = 0; i < n; ++i)
                if (egl_try(c, get_display(EGL_PLATFORM_DEVICE_EXT, devs[i], NULL), why_dev, sizeof why_dev))
                    return SY_GL_OK;
        } else
            snprintf(why_dev, sizeof why_dev, "no EGL device found");
    }
    /* 2. Mesa's surfaceless platform */
    if (strstr(cext, "EGL_MESA_platform_surfaceless")) {
        if (egl_try(c, get_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL), why_sl, sizeof why_sl))
            return SY_GL_OK;
    }
    return sy_gli_fail(rep, SY_GL_ERROR_NO_CONTEXT,
                "egl: no usable EGL display (device: %s; surfaceless: %s); try --gl osmesa", why_dev, why_sl);
}

static void glfw_error(int code, const char *msg)
{
    (void)code;
    (void)msg; /* reported through glfwGetError at the failing call */
}

static sy_gl_result create_glfw(sy_gl_context *c, uint32_t w, uint32_t h, sy_gl_report *rep)
{
    glfwSetErrorCallback(glfw_error);
    if (!glfwInit()) {
        const char *d = NULL;
        glfwGetError(&d);
        return sy_gli_fail(rep, SY_GL_ERROR_NO_CONTEXT, "glfw: cannot open a window (%s); try --gl osmesa or --gl egl",
                    d ? d : "glfwInit failed");
    }
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    c->window = glfwCreateWindow(w ? (int)w : 640, h ? (int)h : 480, "Switchyard", NULL, NULL);
    if (!c->window) {
        const char *d = NULL;
        glfwGetError(&d);
        return sy_gli_fail(rep, SY_GL_ERROR_NO_CONTEXT, "glfw: cannot create a 3.3 core window (%s); try --gl osmesa",
                    d ? d : "glfwCreateWindow failed");
    }
    glfwMakeContextCurrent(c->window);
    return SY_GL_OK;
}

sy_gl_result sy_gl_context_create(sy_gl_provider provider, uint32_t window_w, uint32_t window_h,
                                  sy_gl_context **out, sy_gl_report *rep)
{
    *out = NULL;
    sy_gl_context *c = calloc(1, sizeof *c);
    if (!c) return sy_gli_fail(rep, SY_GL_ERROR_OUT_OF_MEMORY, "GL context: out of memory");
    c->provider = provider;
    c->egl_display = EGL_NO_DISPLAY;
    c->egl_context = EGL_NO_CONTEXT;
    sy_gl_result r;
    switch (provider) {
    case SY_GL_PROVIDER_OSMESA: r = create_osmesa(c, rep); break;
    case SY_GL_PROVIDER_EGL: r = create_egl(c, rep); break;
    case SY_GL_PROVIDER_GLFW: r = create_glfw(c, window_w, window_h, rep); break;
    default: r = sy_gli_fail(rep, SY_GL_ERROR_INVALID_ARGUMENT, "GL context: unknown provider %d", (int)provider);
    }
    if (r == SY_GL_OK) r = load_fns(c, rep);
    if (r != SY_GL_OK) {
        sy_gl_context_destroy(c);
        return r;
    }
    *out = c;
    return SY_GL_OK;
}

void sy_gl_context_destroy(sy_gl_context *c)
{
    if (!c) return;
    if (c->osmesa) {
        /* release it first: a context destroyed while current keeps its framebuffer referenced
         * by the thread's binding, and Mesa never frees either */
        c->om.make_current(NULL, NULL, 0, 0, 0);
        c->om.destroy(c->osmesa);
    }
    /* libOSMesa stays loaded: Mesa keeps process-wide state (its glapi, llvmpipe threads) */
    if (c->egl_context != EGL_NO_CONTEXT) {
        eglMakeCurrent(c->egl_display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        eglDestroyContext(c->egl_display, c->egl_context);
    }
    /* no eglTerminate: the display is process-wide and shared by every device on the same
     * platform (EGL 1.5 does not count eglInitialize calls); terminating it would pull the
     * contexts of the other devices */
    /* the window only: glfwTerminate would close every other device's window too (GLFW's state
     * is process-wide, like the EGL display) */
    if (c->window) glfwDestroyWindow(c->window);
    free(c);
}

bool sy_gl_context_make_current(sy_gl_context *c)
{
    switch (c->provider) {
    case SY_GL_PROVIDER_OSMESA: return c->om.make_current(c->osmesa, c->osmesa_buf, GL_UNSIGNED_BYTE, 2, 2);
    case SY_GL_PROVIDER_EGL: return eglMakeCurrent(c->egl_display, EGL_NO_SURFACE, EGL_NO_SURFACE, c->egl_context);
    case SY_GL_PROVIDER_GLFW: glfwMakeContextCurrent(c->window); return true;
    default: return false;
    }
}

const sy_gl_fns *sy_gl_context_fns(const sy_gl_context *c) { return &c->gl; }
sy_gl_provider sy_gl_context_provider(const sy_gl_context *c) { return c->provider; }

void sy_gl_context_present(sy_gl_context *c, uint32_t fbo, uint32_t w, uint32_t h)
{
    if (c->provider != SY_GL_PROVIDER_GLFW) return;
    int ww, wh;
    glfwGetFramebufferSize(c->window, &ww, &wh);
    c->gl.BindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
    c->gl.BindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
    c->gl.ReadBuffer(GL_COLOR_ATTACHMENT0);
    c->gl.DrawBuffer(GL_BACK);
    c->gl.BlitFramebuffer(0, 0, (GLint)w, (GLint)h, 0, 0, ww, wh, GL_COLOR_BUFFER_BIT, GL_LINEAR);
    glfwSwapBuffers(c->window);
    glfwPollEvents();
}

bool sy_gl_context_should_close(sy_gl_context *c)
{
    return c->provider == SY_GL_PROVIDER_GLFW && glfwWindowShouldClose(c->window);
}

/* >>provider names (the device and the CLI name providers through these) */
const char *sy_gl_provider_name(sy_gl_provider p)
{
    switch (p) {
    case SY_GL_PROVIDER_OSMESA: return "osmesa";
    case SY_GL_PROVIDER_EGL: return "egl";
    case SY_GL_PROVIDER_GLFW: return "glfw";
    default: return "unknown";
    }
}

bool sy_gl_provider_parse(const char *name, sy_gl_provider *out)
{
    for (int i = 0; i < 3; ++i)
        if (name && !strcmp(name, sy_gl_provider_name((sy_gl_provider)i))) {
            *out = (sy_gl_provider)i;
            return true;
        }
    return false;
}
