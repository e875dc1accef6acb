/* sy_py_window.c — _Window: a sy_window with its own context pool and viewports (layers, stereo,
 * live back-end switches) (part of switchyard._switchyard: sy_py.h). */
#include "sy_py.h"

/* ------------------------------------------------------------------ _Window */
#define SY_PY_MAX_VIEWPORTS 64
typedef struct {
    PyObject_HEAD
    sy_window *win;
    sy_context_pool *pool;
    SceneObject *scene; /* strong reference */
    sy_viewport *vps[SY_PY_MAX_VIEWPORTS];
    char backends[SY_PY_MAX_VIEWPORTS][64];
    char params[SY_PY_MAX_VIEWPORTS][SY_PY_PARAMS_MAX];
    uint32_t roots[SY_PY_MAX_VIEWPORTS];
    uint32_t count;
    int busy;
} WindowObject;

static void window_free(WindowObject *w)
{
    sy_window_destroy(w->win);
    sy_context_pool_destroy(w->pool); /* before the scene can go: its contexts are the scene's consumers */
    w->win = NULL;
    w->pool = NULL;
    w->count = 0;
    if (w->scene) {
        w->scene->windows--;
        Py_CLEAR(w->scene);
    }
}

static void window_dealloc(PyObject *self)
{
    window_free((WindowObject *)self);
    sy_py_object_free(self);
}

static PyObject *window_new(PyTypeObject *type, PyObject *args, PyObject *kw)
{
    static char *kwlist[] = {"scene", "width", "height", NULL};
    PyObject *scene;
    unsigned int width, height;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "OII", kwlist, &scene, &width, &height)) return NULL;
    if (!PyObject_TypeCheck(scene, sy_py_scene_type)) return PyErr_Format(PyExc_TypeError, "scene must be a switchyard Scene");
    if (!sy_py_scene_use((SceneObject *)scene)) return NULL;
    if (!width || !height || width > 16384 || height > 16384)
        return sy_py_raise(SY_ERR_INVALID_ARGUMENT,
                        &(sy_error){SY_ERR_INVALID_ARGUMENT, "Window: width and height must be 1 to 16384"});
    WindowObject *w = (WindowObject *)PyType_GenericNew(type, NULL, NULL);
    if (!w) return NULL;
    sy_error err = {0};
    sy_result r = sy_window_create(width, height, &w->win, &err);
    if (r == SY_OK) r = sy_context_pool_create(&w->pool, &err);
    if (r != SY_OK) {
        Py_DECREF(w);
        return sy_py_raise(r, &err);
    }
    w->scene = (SceneObject *)Py_NewRef(scene);
    w->scene->windows++;
    return (PyObject *)w;
}

static int window_use(WindowObject *w)
{
    if (w->busy) return PyErr_SetString(PyExc_RuntimeError, "switchyard: the window is rendering in another thread"), -1;
    if (!w->win) {
        sy_error e = {SY_ERR_INVALID_OPERATION, "switchyard: the window is closed"};
        return sy_py_raise(e.code, &e), -1;
    }
    return sy_py_scene_use(w->scene) ? 0 : -1;
}

static PyObject *window_close(PyObject *self, PyObject *unused)
{
    (void)unused;
    WindowObject *w = (WindowObject *)self;
    if (w->busy) return PyErr_Format(PyExc_RuntimeError, "switchyard: the window is rendering in another thread");
    window_free(w);
    Py_RETURN_NONE;
}

/* _add_viewport(backend=None, params=None, x=0, y=0, width=0, height=0, root=-1, camera=-1,
 * background=-1, eye=0, eye_separation=0, zero_parallax=0, composite=0, active=True) -> index.
 * root / camera / background -1: the scene's own (as loaded). */
/* The back-end and params of a viewport: with servers= they become a cluster class over them
 * (cluster_setup, as Scene.render's servers=; the buffers hold the result); either must fit the
 * window's records (w->backends, w->params). 0, or -1 with an exception. */
static int viewport_backend(const WindowObject *w, const char *servers, const char *mode, const char *secret_file,
                            const char **backend, const char **params, char *name, size_t name_len, char *cparams,
                            size_t cparams_len)
{
    if (servers) {
        uint64_t unused = 0;
        const sy_mediator_class *cls;
        sy_params pp;
        uint32_t caps;
        if (sy_py_check_backend(*backend, *params, &pp, &cls, &caps) || /* the back-end the servers run */
            sy_py_cluster_setup(servers, mode, secret_file, *backend, *params, name, name_len, cparams, cparams_len,
                                &unused))
            return -1;
        *backend = name;
        *params = cparams;
    }
    if (strlen(*backend) >= sizeof w->backends[0] || (*params && strlen(*params) >= sizeof w->params[0]))
        return PyErr_Format(PyExc_ValueError, "backend or params too long"), -1;
    return 0;
}

static PyObject *window_add_viewport(PyObject *self, PyObject *args, PyObject *kw)
{
    static char *kwlist[] = {"backend", "params", "x", "y", "width", "height", "root", "camera", "background",
                             "eye", "eye_separation", "zero_parallax", "composite", "active", "servers",
                             "cluster_mode", "secret_file", NULL};
    WindowObject *w = (WindowObject *)self;
    const char *backend = NULL, *params = NULL, *servers = NULL, *cluster_mode = NULL, *secret_file = NULL;
    unsigned int x = 0, y = 0, vw = 0, vh = 0, eye = 0, composite = 0;
    long long root = -1, camera = -1, background = -1;
    float sep = 0, zp = 0;
    int active = 1;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "|zzIIIILLLIffIpzzz", kwlist, &backend, &params, &x, &y, &vw, &vh, &root,
                                     &camera, &background, &eye, &sep, &zp, &composite, &active, &servers,
                                     &cluster_mode, &secret_file))
        return NULL;
    if (window_use(w)) return NULL;
    if (w->count >= SY_PY_MAX_VIEWPORTS) return PyErr_Format(PyExc_ValueError, "at most %d viewports", SY_PY_MAX_VIEWPORTS);
    if (!backend) backend = sy_mediator_default_name();
    char cname[32], cparams[SY_PY_PARAMS_MAX];
    if (viewport_backend(w, servers, cluster_mode, secret_file, &backend, &params, cname, sizeof cname, cparams,
                         sizeof cparams))
        return NULL;
    loaded *ld = &w->scene->ld;
    sy_viewport_desc d = {.x = x, .y = y, .width = vw, .height = vh,
                          .root = {root < 0 ? ld->root.id : (uint32_t)root},
                          .camera = {camera < 0 ? ld->camera.id : (uint32_t)camera},
                          .background = {background < 0 ? ld->background.id : (uint32_t)background},
                          .backend = backend, .params = params, .eye = eye, .eye_separation = sep,
                          .zero_parallax = zp, .composite = composite, .inactive = !active};
    sy_error err = {0};
    sy_viewport *vp = NULL;
    sy_result r = sy_window_add_viewport(w->win, &d, &vp, &err);
    if (r != SY_OK) return sy_py_raise(r, &err);
    snprintf(w->backends[w->count], sizeof w->backends[0], "%s", backend);
    snprintf(w->params[w->count], sizeof w->params[0], "%s", params ? params : "");
    w->roots[w->count] = d.root.id;
    w->vps[w->count] = vp;
    return PyLong_FromUnsignedLong(w->count++);
}

static sy_viewport *window_vp(WindowObject *w, unsigned int i)
{
    if (window_use(w)) return NULL;
    if (i >= w->count) return PyErr_Format(PyExc_IndexError, "viewport %u: the window has %u", i, w->count), NULL;
    return w->vps[i];
}

/* The viewport named by a call's one argument (index); *index_out its index. NULL with the
 * exception set. */
static sy_viewport *window_vp_arg(PyObject *self, PyObject *args, unsigned int *index_out)
{
    unsigned int i;
    if (!PyArg_ParseTuple(args, "I", &i)) return NULL;
    *index_out = i;
    return window_vp((WindowObject *)self, i);
}

/* The viewport and the value of a setter's call (index, value): *value borrowed. NULL with the
 * exception set. */
static sy_viewport *window_vp_value(PyObject *self, PyObject *args, PyObject **value)
{
    unsigned int i;
    if (!PyArg_ParseTuple(args, "IO", &i, value)) return NULL;
    return window_vp((WindowObject *)self, i);
}

/* _set_backend(index, backend, params=None): switches a live viewport (its old context stays cached) */
static PyObject *window_set_backend(PyObject *self, PyObject *args)
{
    WindowObject *w = (WindowObject *)self;
    unsigned int i;
    const char *backend, *params = NULL, *servers = NULL, *cluster_mode = NULL, *secret_file = NULL;
    if (!PyArg_ParseTuple(args, "Is|zzzz", &i, &backend, &params, &servers, &cluster_mode, &secret_file)) return NULL;
    sy_viewport *vp = window_vp(w, i);
    if (!vp) return NULL;
    char cname[32], cparams[SY_PY_PARAMS_MAX];
    if (viewport_backend(w, servers, cluster_mode, secret_file, &backend, &params, cname, sizeof cname, cparams,
                         sizeof cparams))
        return NULL;
    sy_error err = {0};
    sy_result r = sy_viewport_set_backend(vp, backend, params, &err);
    if (r != SY_OK) return sy_py_raise(r, &err);
    snprintf(w->backends[i], sizeof w->backends[0], "%s", backend);
    snprintf(w->params[i], sizeof w->params[0], "%s", params ? params : "");
    Py_RETURN_NONE;
}

static PyObject *window_viewport(PyObject *self, PyObject *args)
{
    WindowObject *w = (WindowObject *)self;
    unsigned int i;
    sy_viewport *vp = window_vp_arg(self, args, &i);
    if (!vp) return NULL;
    return Py_BuildValue("{s:s,s:s,s:N}", "backend", sy_viewport_backend(vp), "params", w->params[i], "active",
                         PyBool_FromLong(sy_viewport_active(vp)));
}

static PyObject *window_set_active(PyObject *self, PyObject *args)
{
    WindowObject *w = (WindowObject *)self;
    unsigned int i;
    int active;
    if (!PyArg_ParseTuple(args, "Ip", &i, &active)) return NULL;
    sy_viewport *vp = window_vp(w, i);
    if (!vp) return NULL;
    sy_viewport_set_active(vp, active != 0);
    Py_RETURN_NONE;
}

/* _set_clip_planes(index, planes): planes a sequence of up to 6 (a, b, c, d); [] removes them.
 * The library checks them (sy_viewport_set_clip_planes): NaN, infinite, a zero normal, a seventh
 * plane raise its InvalidArgument error naming the plane; the planes before stay. */
static PyObject *window_set_clip_planes(PyObject *self, PyObject *args)
{
    PyObject *seq;
    sy_viewport *vp = window_vp_value(self, args, &seq);
    if (!vp) return NULL;
    Py_ssize_t total = PySequence_Check(seq) ? PySequence_Size(seq) : -1;
    if (total < 0) {
        PyErr_Clear();
        return PyErr_Format(PyExc_TypeError, "clip planes: a sequence of (a, b, c, d) expected");
    }
    float planes[SY_CLIP_PLANES_MAX + 1][4];
    Py_ssize_t n = total > SY_CLIP_PLANES_MAX + 1 ? SY_CLIP_PLANES_MAX + 1 : total; /* the library names the count */
    for (Py_ssize_t k = 0; k < n; ++k) {
        char what[32];
        snprintf(what, sizeof what, "clip plane %zd", k);
        PyObject *item = PySequence_GetItem(seq, k);
        int bad = !item || sy_py_float_seq(item, what, planes[k], 4);
        Py_XDECREF(item);
        if (bad) return NULL;
    }
    sy_error err = {0};
    sy_result r = total > SY_CLIP_PLANES_MAX
                      ? sy_clip_planes_check((const float(*)[4])planes, (uint32_t)total, &err)
                      : sy_viewport_set_clip_planes(vp, (const float(*)[4])planes, (uint32_t)n, &err);
    return sy_py_none_or_raise(r, &err);
}

/* _clip_planes(index) -> list of (a, b, c, d) */
static PyObject *window_clip_planes(PyObject *self, PyObject *args)
{
    unsigned int i;
    sy_viewport *vp = window_vp_arg(self, args, &i);
    if (!vp) return NULL;
    float planes[SY_CLIP_PLANES_MAX][4];
    uint32_t n = sy_viewport_clip_planes(vp, planes);
    PyObject *list = PyList_New((Py_ssize_t)n);
    for (uint32_t k = 0; list && k < n; ++k) {
        PyObject *t = sy_py_tuple_of(planes[k], 4);
        if (!t || PyList_SetItem(list, k, t)) {
            Py_DECREF(list);
            return NULL;
        }
    }
    return list;
}

/* _set_clip_cap(index, rgb or None): the section caps' linear RGB colour, or off */
static PyObject *window_set_clip_cap(PyObject *self, PyObject *args)
{
    PyObject *rgb;
    sy_viewport *vp = window_vp_value(self, args, &rgb);
    if (!vp) return NULL;
    float c[3];
    if (rgb != Py_None && sy_py_float_seq(rgb, "clip cap colour", c, 3)) return NULL;
    sy_error err = {0};
    sy_result r = sy_viewport_set_clip_cap(vp, rgb == Py_None ? NULL : c, &err);
    return sy_py_none_or_raise(r, &err);
}

/* _clip_cap(index) -> (r, g, b) or None */
static PyObject *window_clip_cap(PyObject *self, PyObject *args)
{
    unsigned int i;
    sy_viewport *vp = window_vp_arg(self, args, &i);
    if (!vp) return NULL;
    float c[3];
    if (!sy_viewport_clip_cap(vp, c)) Py_RETURN_NONE;
    return sy_py_tuple_of(c, 3);
}

/* _render(spp=0, seed=0, aovs=False, progress=None) -> (rgba, aovs or None, samples of viewport 0).
 * The pool persists: a progressive viewport keeps accumulating while nothing changes. */
static PyObject *window_render(PyObject *self, PyObject *args, PyObject *kw)
{
    static char *kwlist[] = {"spp", "seed", "aovs", "progress", NULL};
    WindowObject *w = (WindowObject *)self;
    unsigned long long spp = 0;
    unsigned int seed = 0;
    int want_aovs = 0;
    PyObject *progress = Py_None;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "|KIpO", kwlist, &spp, &seed, &want_aovs, &progress)) return NULL;
    if (window_use(w)) return NULL;
    if (progress != Py_None && !PyCallable_Check(progress)) return PyErr_Format(PyExc_TypeError, "progress must be callable");
    if (spp > (1u << 24)) return PyErr_Format(PyExc_ValueError, "spp=%llu: at most 16777216", spp);
    sy_scene *sc = w->scene->ld.scene;
    sy_error err = {0};
    sy_result r = sy_scene_commit(sc, NULL, &err);
    if (r != SY_OK) return sy_py_raise(r, &err);
    render_job job = {.win = w->win, .pool = w->pool, .scene = sc, .seed = seed, .spp = spp,
                      .progress = progress == Py_None ? NULL : progress};
    w->busy = w->scene->busy = 1;
    int rc = sy_py_render_run(&job);
    w->busy = w->scene->busy = 0;
    if (rc) {
        sy_layer_destroy(&job.out);
        return NULL;
    }
    sy_context *ctx = NULL;
    sy_mediator_stats st = {0};
    uint32_t caps = 0;
    sy_params pp;
    if (w->count && sy_params_parse(w->params[0], &pp, &err) == SY_OK &&
        sy_context_pool_get(w->pool, sc, w->backends[0], &pp, w->roots[0], &ctx, &err) == SY_OK) {
        sy_context_stats(ctx, &st);
        caps = sy_context_caps(ctx);
    }
    return sy_py_render_result(&job, want_aovs, (caps & SY_CAP_AOVS) && w->count == 1 ? ctx : NULL, st.samples);
}

static PyMethodDef window_methods[] = {
    {"close", window_close, METH_NOARGS, "Frees the window, its viewports and its cached back-end contexts now."},
    {"_add_viewport", (PyCFunction)(void (*)(void))window_add_viewport, METH_VARARGS | METH_KEYWORDS, NULL},
    {"_set_backend", window_set_backend, METH_VARARGS, NULL},
    {"_set_active", window_set_active, METH_VARARGS, NULL},
    {"_viewport", window_viewport, METH_VARARGS, NULL},
    {"_set_clip_planes", window_set_clip_planes, METH_VARARGS, NULL},
    {"_clip_planes", window_clip_planes, METH_VARARGS, NULL},
    {"_set_clip_cap", window_set_clip_cap, METH_VARARGS, NULL},
    {"_clip_cap", window_clip_cap, METH_VARARGS, NULL},
    {"_render", (PyCFunction)(void (*)(void))window_render, METH_VARARGS | METH_KEYWORDS, NULL},
    {NULL, NULL, 0, NULL}};

SY_PY_TYPE_SPEC(sy_py_window_spec, "_Window", WindowObject, Py_TPFLAGS_DEFAULT | Py_TPFLAGS_BASETYPE,
                {Py_tp_dealloc, window_dealloc},
                {Py_tp_new, window_new},
                {Py_tp_methods, window_methods},
                {Py_tp_doc, "the library's sy_window with its own context pool"});
