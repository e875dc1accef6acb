/* sy_python.c — the C half of the Python package switchyard (apps/python; docs/PYTHON.md): the
 * extension module switchyard._switchyard, written against CPython's limited API (3.11 stable ABI)
 * and no NumPy header. The Python half (switchyard/__init__.py) turns what this returns into
 * NumPy arrays and the objects a Python user expects (Scene, Node, Mesh, ...).
 *
 * What it wraps:
 *   - _Scene: a loaded scene (apps/sy/sy_load.c, the `loaded` struct `sy` renders from: the same
 *     loaders, default camera and world as `sy render`) or an empty one; object creation and
 *     setters by handle id; _render: one window with one viewport, as `sy render` composes a
 *     mono render (apps/sy/sy_compose.c), progressive back-ends in passes.
 *   - _Window: a sy_window with its own context pool and viewports, for layering, stereo and
 *     switching back-ends on a live viewport (contexts stay cached in its pool).
 *   - _Node: the C base of switchyard.Node (its TRS fields are getset descriptors: one C call
 *     per `node.translation = v`, the call-overhead target).
 *   - _Web: the web view (apps/web/sy_web.h, as `sy web`) served by a thread of its own.
 *   - _BlobView: a read-only view of a mesh's blob (immutable, reference-counted), so Mesh data
 *     reaches NumPy without a copy.
 *   - _Buffer: a float32 array that owns library memory (a rendered layer's planes) and exports
 *     it through the buffer protocol, so numpy.asarray takes it without a copy.
 *   - the registry (backends), EXR reading and writing, the log callback, sy_result -> exception.
 *
 * Ownership: a _Scene owns its sy_scene; a _Window owns its sy_window and pool and holds a strong
 * reference to the one _Scene it renders (a scene refuses close() while a window holds it, so no
 * cached context outlives its scene). Mesh data from a buffer-protocol object is copied once,
 * into the library's blob. Thread-safety: loads and renders run without the GIL; a _Scene (and a
 * _Window) in use by one thread refuses calls from another with RuntimeError instead of racing. */
#define Py_LIMITED_API 0x030B0000
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include "sy_anim.h"
#include "sy_exr.h"
#include "sy_load.h"
#include "sy_log.h"
#include "sy_mediators.h"
#include "sy_viewport.h"
#ifdef SY_PY_HAVE_CLUSTER
#include "sy_cluster_cli.h"
#endif
#ifdef SY_PY_HAVE_WEB
#include "sy_web.h"
#include "sy_web_thread.h"
#endif

#include <math.h>
#include <pthread.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* ------------------------------------------------------------------ errors */
/* switchyard.Error subclasses by sy_result code, handed over by __init__.py (_set_errors). */
static PyObject *g_errors[SY_ERR_SYSTEM + 1];
static PyObject *g_error_base;

static PyObject *raise_sy(sy_result r, const sy_error *e)
{
    PyObject *cls = (r > 0 && r <= SY_ERR_SYSTEM && g_errors[r]) ? g_errors[r] : g_error_base;
    if (!cls) cls = PyExc_RuntimeError;
    const char *msg = e && e->message[0] ? e->message : sy_result_str(r);
    PyObject *args = Py_BuildValue("(si)", msg, (int)r);
    if (args) {
        PyErr_SetObject(cls, args);
        Py_DECREF(args);
    }
    return NULL;
}

static PyObject *py_set_errors(PyObject *self, PyObject *args)
{
    (void)self;
    PyObject *base, *map;
    if (!PyArg_ParseTuple(args, "OO!", &base, &PyDict_Type, &map)) return NULL;
    Py_XDECREF(g_error_base);
    g_error_base = Py_NewRef(base);
    for (int r = 1; r <= SY_ERR_SYSTEM; ++r) {
        PyObject *key = PyLong_FromLong(r);
        if (!key) return NULL;
        PyObject *cls = PyDict_GetItemWithError(map, key);
        Py_DECREF(key);
        if (!cls && PyErr_Occurred()) return NULL;
        Py_XDECREF(g_errors[r]);
        g_errors[r] = cls ? Py_NewRef(cls) : NULL;
    }
    Py_RETURN_NONE;
}

/* ------------------------------------------------------------------ log */
/* The library's one log callback (sy_log.h) goes to a Python callable (switchyard._log, which
 * hands it to the logging module). Messages may come from any thread: the GIL is taken for the
 * call; before the interpreter is up or after it is finalising they go to stderr. */
static PyObject *g_log_fn;

static void log_to_python(void *user, sy_log_level level, const char *module, const char *item, const char *message)
{
    if (!Py_IsInitialized() || !g_log_fn) {
        sy_log_stderr(user, level, module, item, message);
        return;
    }
    PyGILState_STATE st = PyGILState_Ensure();
    PyObject *res = g_log_fn ? PyObject_CallFunction(g_log_fn, "isss", (int)level, module, item ? item : "", message) : NULL;
    if (!res) {
        if (PyErr_Occurred()) PyErr_Clear(); /* a failing handler must not turn a library call into an error */
        sy_log_stderr(user, level, module, item, message);
    }
    Py_XDECREF(res);
    PyGILState_Release(st);
}

static PyObject *py_set_log(PyObject *self, PyObject *args)
{
    (void)self;
    PyObject *fn;
    int level = SY_LOG_NOTE;
    if (!PyArg_ParseTuple(args, "O|i", &fn, &level)) return NULL;
    if (fn == Py_None) {
        sy_log_set_callback(NULL, NULL); /* back to stderr; no call of ours is in progress after this */
        Py_CLEAR(g_log_fn);
    } else {
        if (!PyCallable_Check(fn)) return PyErr_Format(PyExc_TypeError, "log handler must be callable");
        Py_XDECREF(g_log_fn);
        g_log_fn = Py_NewRef(fn);
        sy_log_set_callback(log_to_python, NULL);
    }
    if (level < 0) level = 0;
    sy_log_set_level((sy_log_level)level);
    Py_RETURN_NONE;
}

/* The end of every dealloc of a heap type: free the object, release the type. */
static void object_free(PyObject *self)
{
    PyTypeObject *tp = Py_TYPE(self);
    freefunc f = (freefunc)PyType_GetSlot(tp, Py_tp_free);
    f(self);
    Py_DECREF(tp);
}

/* ------------------------------------------------------------------ _Buffer */
/* A float32 array of 1 to 3 dimensions owning malloc()ed memory, exported through the buffer
 * protocol (numpy.asarray keeps the _Buffer alive as the array's base). */
typedef struct {
    PyObject_HEAD
    float *data;
    int ndim;
    Py_ssize_t shape[3], strides[3];
} BufferObject;

static PyTypeObject *g_buffer_type;

static void buffer_dealloc(PyObject *self)
{
    BufferObject *b = (BufferObject *)self;
    free(b->data);
    object_free(self);
}

/* Fills view for exporter self: ndim dimensions of 4-byte items (format "f" or "I") at buf, C order
 * as shape and strides say (the exporter keeps both arrays alive); the view holds a reference to self. */
static int export_view(PyObject *self, Py_buffer *view, void *buf, int readonly, const char *format, int ndim,
                       Py_ssize_t *shape, Py_ssize_t *strides)
{
    Py_ssize_t n = 1;
    for (int i = 0; i < ndim; ++i) n *= shape[i];
    view->buf = buf;
    view->obj = Py_NewRef(self);
    view->len = n * 4;
    view->readonly = readonly;
    view->itemsize = 4;
    view->format = (char *)format;
    view->ndim = ndim;
    view->shape = shape;
    view->strides = strides;
    view->suboffsets = NULL;
    view->internal = NULL;
    return 0;
}

static int buffer_get(PyObject *self, Py_buffer *view, int flags)
{
    (void)flags;
    BufferObject *b = (BufferObject *)self;
    return export_view(self, view, b->data, 0, "f", b->ndim, b->shape, b->strides);
}

static PyType_Slot buffer_slots[] = {
    {Py_tp_dealloc, buffer_dealloc},
    {Py_bf_getbuffer, buffer_get},
    {Py_tp_doc, "float32 pixels owned by the library's allocation (numpy.asarray views it without a copy)"},
    {0, NULL}};
static PyType_Spec buffer_spec = {"switchyard._switchyard._Buffer", sizeof(BufferObject), 0, Py_TPFLAGS_DEFAULT,
                                  buffer_slots};

/* Takes ownership of data (free()d with the object, or here on failure): rows x cols x channels
 * (channels 1: a 2-D array). */
static PyObject *buffer_take(float *data, uint32_t rows, uint32_t cols, uint32_t channels)
{
    BufferObject *b = (BufferObject *)PyType_GenericNew(g_buffer_type, NULL, NULL);
    if (!b) {
        free(data);
        return NULL;
    }
    b->data = data;
    b->ndim = channels > 1 ? 3 : 2;
    b->shape[0] = rows;
    b->shape[1] = cols;
    b->shape[2] = channels;
    b->strides[2] = sizeof(float);
    b->strides[1] = (Py_ssize_t)(sizeof(float) * channels);
    b->strides[0] = (Py_ssize_t)(sizeof(float) * channels * cols);
    if (b->ndim == 2) b->strides[1] = sizeof(float), b->strides[0] = (Py_ssize_t)(sizeof(float) * cols);
    return (PyObject *)b;
}

/* ------------------------------------------------------------------ _Scene */
typedef struct {
    PyObject_HEAD
    loaded ld;       /* the scene, its root, camera, background and what the loader said */
    int busy;        /* a load or render of this scene runs without the GIL */
    int windows;     /* _Window objects holding it (close() waits for them) */
} SceneObject;

static PyTypeObject *g_scene_type;

static sy_scene *scene_use(SceneObject *s)
{
    if (s->busy) {
        PyErr_SetString(PyExc_RuntimeError, "switchyard: the scene is in use by another thread (a render, or "
                                            "serve() until stopped); give each thread its own Scene or wait");
        return NULL;
    }
    if (!s->ld.scene) {
        PyErr_SetString(g_errors[SY_ERR_INVALID_OPERATION] ? g_errors[SY_ERR_INVALID_OPERATION] : PyExc_RuntimeError,
                        "switchyard: the scene is closed");
        return NULL;
    }
    return s->ld.scene;
}

static void scene_dealloc(PyObject *self)
{
    SceneObject *s = (SceneObject *)self;
    if (s->ld.scene) sy_cli_loaded_free(&s->ld);
    object_free(self);
}

static PyObject *scene_new(PyTypeObject *type, PyObject *args, PyObject *kw)
{
    if ((args && PyTuple_Size(args)) || (kw && PyDict_Size(kw)))
        return PyErr_Format(PyExc_TypeError, "_Scene() takes no arguments");
    SceneObject *s = (SceneObject *)PyType_GenericNew(type, NULL, NULL);
    if (!s) return NULL;
    sy_error err = {0};
    sy_result r = sy_scene_create(&s->ld.scene, &err);
    if (r != SY_OK) {
        Py_DECREF(s);
        return raise_sy(r, &err);
    }
    return (PyObject *)s;
}

static PyObject *scene_close(PyObject *self, PyObject *unused)
{
    (void)unused;
    SceneObject *s = (SceneObject *)self;
    if (s->busy) return PyErr_Format(PyExc_RuntimeError, "switchyard: the scene is in use by another thread");
    if (s->windows)
        return raise_sy(SY_ERR_INVALID_OPERATION,
                        &(sy_error){SY_ERR_INVALID_OPERATION, "switchyard: the scene is still shown by a Window; close "
                                                              "the Window first"});
    if (s->ld.scene) sy_cli_loaded_free(&s->ld);
    Py_RETURN_NONE;
}

/* The world options of load() (sy's --env, --env-color, --env-intensity, --background; the flags
 * are set by the caller) into *w; *env_bytes keeps the map's path alive. -1 with an exception. */
static int float_seq(PyObject *o, const char *what, float *out, Py_ssize_t n);
static int finite_floats(PyObject *o, const char *what, float *out, Py_ssize_t min_n, Py_ssize_t max_n, Py_ssize_t *n)
{
    PyObject *argerr = g_errors[SY_ERR_INVALID_ARGUMENT] ? g_errors[SY_ERR_INVALID_ARGUMENT] : PyExc_ValueError;
    Py_ssize_t len = PySequence_Check(o) ? PySequence_Size(o) : -1;
    if (len < 0) PyErr_Clear();
    *n = len >= min_n && len <= max_n ? len : max_n;
    if (float_seq(o, what, out, *n)) return -1;
    for (Py_ssize_t i = 0; i < *n; ++i)
        if (!isfinite(out[i])) {
            PyErr_Format(argerr, "%s: value %zd is not finite", what, i);
            return -1;
        }
    return 0;
}

static int world_from_python(PyObject *env, PyObject *env_color, PyObject *env_intensity, PyObject *background,
                             sy_world_options *w, PyObject **env_bytes)
{
    PyObject *argerr = g_errors[SY_ERR_INVALID_ARGUMENT] ? g_errors[SY_ERR_INVALID_ARGUMENT] : PyExc_ValueError;
    Py_ssize_t n = 0;
    if (env != Py_None) {
        if (!PyUnicode_FSConverter(env, env_bytes)) return -1;
        w->env_path = PyBytes_AsString(*env_bytes);
    }
    if (env_color != Py_None) {
        if (finite_floats(env_color, "env_color", w->env_color, 3, 3, &n)) return -1;
        w->has_env_color = true;
    }
    if (env_intensity != Py_None) {
        double v = PyFloat_AsDouble(env_intensity);
        if (v == -1.0 && PyErr_Occurred()) return -1;
        if (!isfinite(v) || v < 0) {
            PyErr_Format(argerr, "env_intensity: %R is not a finite number >= 0", env_intensity);
            return -1;
        }
        w->env_intensity = (float)v;
        w->env_intensity_set = true;
    }
    if (background != Py_None) {
        if (finite_floats(background, "background (R, G, B[, A])", w->background, 3, 4, &n)) return -1;
        if (n == 3) w->background[3] = 1.0f;
        w->has_background = true;
    }
    return 0;
}

static int time_from_python(PyObject *at, double *seconds)
{
    *seconds = PyFloat_AsDouble(at);
    if (*seconds == -1.0 && PyErr_Occurred()) return -1;
    if (!isfinite(*seconds)) {
        PyErr_Format(g_errors[SY_ERR_INVALID_ARGUMENT] ? g_errors[SY_ERR_INVALID_ARGUMENT] : PyExc_ValueError,
                     "at: %R is not a finite number of seconds", at);
        return -1;
    }
    return 0;
}

/* The scene's time (sy render --at / --clip): every clip (clip NULL) or one, evaluated at seconds,
 * committed. A scene without animations is left as it is (a note on the log) unless a clip is
 * named (NotFoundError). 0, or -1 with an exception. */
static int scene_time(sy_scene *sc, const char *clip, double seconds)
{
    sy_error err = {0};
    sy_animation a = {0};
    if (!sy_scene_count(sc, SY_TYPE_ANIMATION)) {
        if (clip) {
            sy_error_set(&err, SY_ERR_NOT_FOUND, "clip %s: the scene has no animations", clip);
            raise_sy(err.code, &err);
            return -1;
        }
        sy_log(SY_LOG_NOTE, "switchyard", NULL, "at=%g: the scene has no animations; it is shown as loaded", seconds);
        return 0;
    }
    sy_result r = clip ? sy_animation_find(sc, clip, &a, &err) : SY_OK;
    sy_anim_stats st;
    if (r == SY_OK) r = sy_scene_set_time_ex(sc, a, seconds, &st, &err);
    if (r == SY_OK) r = sy_scene_commit(sc, NULL, &err);
    if (r != SY_OK) {
        raise_sy(r, &err);
        return -1;
    }
    return 0;
}

/* load(path, camera=None, strict=False, allow_paths=(), max_scene_mb=0, variant=None) -> _Scene.
 * sy_cli_load reads its options from one global (sy_cli_load_opts): loads take turns on g_load_lock
 * while the GIL is released. */
static pthread_mutex_t g_load_lock = PTHREAD_MUTEX_INITIALIZER;

static PyObject *py_load(PyObject *self, PyObject *args, PyObject *kw)
{
    (void)self;
    static char *kwlist[] = {"path", "camera", "strict", "allow_paths", "max_scene_mb", "variant", "env", "env_color",
                             "env_intensity", "env_hidden", "background", "no_default_light", "at", "clip", NULL};
    PyObject *path_obj = NULL, *roots = NULL, *env = Py_None, *env_color = Py_None, *env_intensity = Py_None,
             *background = Py_None, *at = Py_None;
    const char *camera = NULL, *variant = NULL, *clip = NULL;
    int strict = 0, env_hidden = 0, no_default_light = 0;
    unsigned long long max_mb = 0;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "O&|zpOKzOOOpOpOz", kwlist, PyUnicode_FSConverter, &path_obj, &camera,
                                     &strict, &roots, &max_mb, &variant, &env, &env_color, &env_intensity, &env_hidden,
                                     &background, &no_default_light, &at, &clip))
        return NULL;
    PyObject *env_bytes = NULL;
    sy_world_options world = {.env_hidden = env_hidden != 0, .no_default_light = no_default_light != 0};
    double seconds = 0.0;
    if (world_from_python(env, env_color, env_intensity, background, &world, &env_bytes) ||
        (at != Py_None && time_from_python(at, &seconds))) {
        Py_XDECREF(path_obj);
        Py_XDECREF(env_bytes);
        return NULL;
    }
    PyObject *root_bytes[SY_MAX_ALLOW_PATHS] = {0};
    Py_ssize_t nroots = 0;
    PyObject *result = NULL;
    if (roots && roots != Py_None) {
        PyObject *seq = PySequence_Tuple(roots);
        if (!seq) goto done;
        nroots = PyTuple_Size(seq);
        if (nroots > SY_MAX_ALLOW_PATHS) {
            Py_DECREF(seq);
            nroots = 0;
            PyErr_Format(PyExc_ValueError, "allow_paths: at most %d folders", SY_MAX_ALLOW_PATHS);
            goto done;
        }
        for (Py_ssize_t i = 0; i < nroots; ++i)
            if (!PyUnicode_FSConverter(PyTuple_GetItem(seq, i), &root_bytes[i])) {
                Py_DECREF(seq);
                goto done;
            }
        Py_DECREF(seq);
    }
    if (max_mb > UINT64_MAX / (1024 * 1024)) {
        PyErr_Format(PyExc_ValueError, "max_scene_mb %llu: too large", max_mb);
        goto done;
    }
    SceneObject *s = (SceneObject *)PyType_GenericNew(g_scene_type, NULL, NULL);
    if (!s) goto done;
    const char *path = PyBytes_AsString(path_obj);
    sy_error err = {0};
    sy_result r;
    Py_BEGIN_ALLOW_THREADS
    pthread_mutex_lock(&g_load_lock);
    memset(&sy_cli_load_opts, 0, sizeof sy_cli_load_opts);
    for (Py_ssize_t i = 0; i < nroots; ++i) sy_cli_load_opts.roots[i] = PyBytes_AsString(root_bytes[i]);
    sy_cli_load_opts.root_count = (size_t)nroots;
    sy_cli_load_opts.strict = strict != 0;
    sy_cli_load_opts.max_scene_bytes = (uint64_t)max_mb * 1024 * 1024;
    sy_cli_load_opts.variant = variant;
    sy_cli_load_opts.world = world;
    sy_cli_load_opts.world.max_scene_bytes = sy_cli_load_opts.max_scene_bytes;
    r = sy_cli_load(path, camera, true, &s->ld, &err);
    memset(&sy_cli_load_opts, 0, sizeof sy_cli_load_opts);
    pthread_mutex_unlock(&g_load_lock);
    Py_END_ALLOW_THREADS
    if (r != SY_OK) {
        Py_DECREF(s);
        raise_sy(r, &err);
        goto done;
    }
    if ((at != Py_None || clip) && scene_time(s->ld.scene, clip, seconds)) {
        Py_DECREF(s);
        goto done;
    }
    result = (PyObject *)s;
done:
    for (Py_ssize_t i = 0; i < SY_MAX_ALLOW_PATHS; ++i) Py_XDECREF(root_bytes[i]);
    Py_XDECREF(path_obj);
    Py_XDECREF(env_bytes);
    return result;
}

/* ---- arrays in: buffer-protocol objects checked for dtype, shape and layout */
static int format_is(const Py_buffer *v, char code)
{
    const char *f = v->format ? v->format : "B";
    if (*f == '<' || *f == '=' || *f == '@') ++f; /* little-endian / native (this is x86-64 / arm64) */
    if (f[0] == code && f[1] == 0) return 1;
    return code == 'I' && f[0] == 'L' && f[1] == 0 && v->itemsize == 4;
}

/* Gets a C-contiguous float32 (code 'f') or uint32 ('I') array of ... x cols, at most max_ndim
 * dimensions (or flat, a multiple of cols); *count = the values / cols. Raises
 * InvalidArgumentError naming what = the argument on anything else. */
static int get_array(PyObject *obj, const char *what, char code, Py_ssize_t cols, int max_ndim, Py_buffer *view,
                     Py_ssize_t *count)
{
    PyObject *argerr = g_errors[SY_ERR_INVALID_ARGUMENT] ? g_errors[SY_ERR_INVALID_ARGUMENT] : PyExc_ValueError;
    const char *dtype = code == 'f' ? "float32" : "uint32";
    if (PyObject_GetBuffer(obj, view, PyBUF_FORMAT | PyBUF_STRIDES) != 0) {
        PyErr_Clear();
        PyObject *tn = PyType_GetName(Py_TYPE(obj));
        PyErr_Format(argerr, "%s: expected an array of %s (numpy.ndarray or another buffer-protocol object), got %S "
                     "(no buffer protocol)", what, dtype, tn ? tn : Py_None);
        Py_XDECREF(tn);
        return -1;
    }
    if (!format_is(view, code) || view->itemsize != 4) {
        PyErr_Format(argerr, "%s: dtype must be %s (format '%s' given); convert with .astype(numpy.%s)", what, dtype,
                     view->format ? view->format : "B", dtype);
        goto fail;
    }
    if (!PyBuffer_IsContiguous(view, 'C')) {
        PyErr_Format(argerr, "%s: the array is not C-contiguous; pass numpy.ascontiguousarray(%s)", what, what);
        goto fail;
    }
    Py_ssize_t n = view->len / 4;
    if (cols > 1 && view->ndim == 2 && view->shape[1] != cols) {
        PyErr_Format(argerr, "%s: shape (%zd, %zd): expected (N, %zd)", what, view->shape[0], view->shape[1], cols);
        goto fail;
    }
    if (cols > 1 && view->ndim > 2 && view->shape[view->ndim - 1] != cols) {
        PyErr_Format(argerr, "%s: the last dimension is %zd: expected %zd", what, view->shape[view->ndim - 1], cols);
        goto fail;
    }
    if (view->ndim > max_ndim || n % cols) {
        PyErr_Format(argerr, "%s: expected (N, %zd) or a flat array of a multiple of %zd values (%zd values, %d dimensions)",
                     what, cols, cols, n, view->ndim);
        goto fail;
    }
    *count = n / cols;
    return 0;
fail:
    PyBuffer_Release(view);
    return -1;
}

/* _add_mesh(positions, indices=None, normals=None, material=0, name=None, parent=0) -> (mesh id, node id):
 * one triangle primitive from float32 Nx3 positions (normals), uint32 indices; a node instancing
 * it under parent (0: a new root). Checked here: dtype, shape, layout, index range; the scene's
 * setters check the values (finite coordinates within SY_COORD_MAX). */
static PyObject *scene_add_mesh(PyObject *self, PyObject *args, PyObject *kw)
{
    static char *kwlist[] = {"positions", "indices", "normals", "material", "name", "parent", NULL};
    PyObject *pos_obj, *idx_obj = Py_None, *nrm_obj = Py_None;
    unsigned int material = 0, parent = 0;
    const char *name = NULL;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "O|OOIzI", kwlist, &pos_obj, &idx_obj, &nrm_obj, &material, &name, &parent))
        return NULL;
    SceneObject *s = (SceneObject *)self;
    sy_scene *sc = scene_use(s);
    if (!sc) return NULL;
    Py_buffer pv, iv, nv;
    Py_ssize_t nvert = 0, nidx = 0, nnrm = 0;
    int have_idx = idx_obj != Py_None, have_nrm = nrm_obj != Py_None;
    PyObject *argerr = g_errors[SY_ERR_INVALID_ARGUMENT] ? g_errors[SY_ERR_INVALID_ARGUMENT] : PyExc_ValueError;
    if (get_array(pos_obj, "positions", 'f', 3, 2, &pv, &nvert)) return NULL;
    if (have_idx && get_array(idx_obj, "indices", 'I', 3, 2, &iv, &nidx)) {
        PyBuffer_Release(&pv);
        return NULL;
    }
    if (have_nrm && get_array(nrm_obj, "normals", 'f', 3, 2, &nv, &nnrm)) {
        PyBuffer_Release(&pv);
        if (have_idx) PyBuffer_Release(&iv);
        return NULL;
    }
    PyObject *result = NULL;
    if (nvert == 0 || nvert > (Py_ssize_t)UINT32_MAX) {
        PyErr_Format(argerr, "positions: %zd vertices (expected 1 to 2^32-1)", nvert);
        goto out;
    }
    if (have_nrm && nnrm != nvert) {
        PyErr_Format(argerr, "normals: %zd given for %zd vertices (one per vertex)", nnrm, nvert);
        goto out;
    }
    if (have_idx ? nidx == 0 : nvert % 3 != 0) {
        PyErr_Format(argerr, have_idx ? "indices: %zd values; triangles need a positive multiple of 3"
                                      : "positions: %zd vertices without indices; triangles need a multiple of 3",
                     have_idx ? nidx : nvert);
        goto out;
    }
    const float *p = pv.buf;
    for (Py_ssize_t i = 0; i < 3 * nvert; ++i)
        if (!isfinite(p[i])) {
            PyErr_Format(argerr, "positions: vertex %zd has a NaN or infinite coordinate", i / 3);
            goto out;
        }
    if (have_idx) {
        const uint32_t *ix = iv.buf;
        for (Py_ssize_t i = 0; i < 3 * nidx; ++i)
            if (ix[i] >= (uint64_t)nvert) {
                PyErr_Format(argerr, "indices: index %zd is %u, beyond the %zd vertices", i, ix[i], nvert);
                goto out;
            }
    }
    sy_error err = {0};
    sy_result r = SY_OK;
    sy_primitive prim = {.material = {material}, .topology = SY_TOPOLOGY_TRIANGLES};
    sy_mesh mesh = {0};
    sy_node node = {0};
    s->busy = 1; /* the copies into blobs (hashed) run without the GIL */
    Py_BEGIN_ALLOW_THREADS
    r = sy_blob_create_copy(pv.buf, (size_t)pv.len, &prim.positions, &err);
    if (r == SY_OK && have_idx) r = sy_blob_create_copy(iv.buf, (size_t)iv.len, &prim.indices, &err);
    if (r == SY_OK && have_nrm) r = sy_blob_create_copy(nv.buf, (size_t)nv.len, &prim.normals, &err);
    Py_END_ALLOW_THREADS
    s->busy = 0;
    if (r == SY_OK) r = sy_mesh_create(sc, name, &mesh, &err);
    if (r == SY_OK) r = sy_mesh_set_primitives(sc, mesh, &prim, 1, &err);
    if (r == SY_OK) r = sy_node_create(sc, name, &node, &err);
    if (r == SY_OK) r = sy_node_set_mesh(sc, node, mesh, &err);
    if (r == SY_OK && parent) r = sy_node_add_child(sc, (sy_node){parent}, node, &err);
    sy_primitive_release(&prim); /* the mesh holds its own references */
    if (r != SY_OK) {
        sy_error ignore = {0};
        if (node.id) sy_object_destroy(sc, SY_TYPE_NODE, node.id, &ignore);
        if (mesh.id) sy_object_destroy(sc, SY_TYPE_MESH, mesh.id, &ignore);
        raise_sy(r, &err);
        goto out;
    }
    result = Py_BuildValue("(II)", mesh.id, node.id);
out:
    PyBuffer_Release(&pv);
    if (have_idx) PyBuffer_Release(&iv);
    if (have_nrm) PyBuffer_Release(&nv);
    return result;
}

/* ---- objects by id: create, read, set (the Python classes Node, Mesh, ... call these) */
static int float_seq(PyObject *o, const char *what, float *out, Py_ssize_t n)
{
    PyObject *argerr = g_errors[SY_ERR_INVALID_ARGUMENT] ? g_errors[SY_ERR_INVALID_ARGUMENT] : PyExc_ValueError;
    PyObject *t = PySequence_Tuple(o);
    if (!t) {
        PyErr_Clear();
        PyErr_Format(argerr, "%s: expected a sequence of %zd numbers", what, n);
        return -1;
    }
    if (PyTuple_Size(t) != n) {
        PyErr_Format(argerr, "%s: expected %zd numbers, got %zd", what, n, PyTuple_Size(t));
        Py_DECREF(t);
        return -1;
    }
    for (Py_ssize_t i = 0; i < n; ++i) {
        double v = PyFloat_AsDouble(PyTuple_GetItem(t, i));
        if (v == -1.0 && PyErr_Occurred()) {
            Py_DECREF(t);
            return -1;
        }
        out[i] = (float)v;
    }
    Py_DECREF(t);
    return 0;
}

static PyObject *tuple_of(const float *v, int n)
{
    PyObject *t = PyTuple_New(n);
    for (int i = 0; t && i < n; ++i) PyTuple_SetItem(t, i, PyFloat_FromDouble(v[i]));
    return t;
}

/* _create(type, name) -> id */
static PyObject *scene_create(PyObject *self, PyObject *args)
{
    int type;
    const char *name = NULL;
    if (!PyArg_ParseTuple(args, "i|z", &type, &name)) return NULL;
    sy_scene *sc = scene_use((SceneObject *)self);
    if (!sc) return NULL;
    sy_error err = {0};
    uint32_t id = 0;
    sy_result r = type < 0 || type >= SY_TYPE_COUNT ? sy_error_set(&err, SY_ERR_INVALID_ARGUMENT, "object type %d", type)
                                                    : sy_object_create(sc, (sy_object_type)type, name, &id, &err);
    return r == SY_OK ? PyLong_FromUnsignedLong(id) : raise_sy(r, &err);
}

/* _destroy(type, id) */
static PyObject *scene_destroy_object(PyObject *self, PyObject *args)
{
    int type;
    unsigned int id;
    if (!PyArg_ParseTuple(args, "iI", &type, &id)) return NULL;
    sy_scene *sc = scene_use((SceneObject *)self);
    if (!sc) return NULL;
    sy_error err = {0};
    sy_result r = type < 0 || type >= SY_TYPE_COUNT ? sy_error_set(&err, SY_ERR_INVALID_ARGUMENT, "object type %d", type)
                                                    : sy_object_destroy(sc, (sy_object_type)type, id, &err);
    if (r != SY_OK) return raise_sy(r, &err);
    Py_RETURN_NONE;
}

/* _ids(type) -> list of live ids; _valid(type, id) -> bool */
static PyObject *scene_ids(PyObject *self, PyObject *args)
{
    int type;
    if (!PyArg_ParseTuple(args, "i", &type)) return NULL;
    sy_scene *sc = scene_use((SceneObject *)self);
    if (!sc) return NULL;
    if (type < 0 || type >= SY_TYPE_COUNT) return PyErr_Format(PyExc_ValueError, "object type %d", type);
    PyObject *l = PyList_New(0);
    for (uint32_t id = sy_scene_next(sc, (sy_object_type)type, 0); l && id; id = sy_scene_next(sc, (sy_object_type)type, id)) {
        PyObject *v = PyLong_FromUnsignedLong(id);
        if (!v || PyList_Append(l, v)) Py_CLEAR(l);
        Py_XDECREF(v);
    }
    return l;
}

static PyObject *scene_valid(PyObject *self, PyObject *args)
{
    int type;
    unsigned int id;
    if (!PyArg_ParseTuple(args, "iI", &type, &id)) return NULL;
    SceneObject *s = (SceneObject *)self;
    if (!s->ld.scene || type < 0 || type >= SY_TYPE_COUNT) Py_RETURN_FALSE;
    return PyBool_FromLong(sy_object_is_valid(s->ld.scene, (sy_object_type)type, id));
}

static PyObject *stale(const char *what, unsigned id)
{
    sy_error e = {0};
    sy_error_set(&e, SY_ERR_INVALID_HANDLE, "%s %u: stale or foreign handle (destroyed, or of another scene)", what, id);
    return raise_sy(e.code, &e);
}

/* _node(id) -> dict of the node's fields */
static PyObject *scene_node(PyObject *self, PyObject *args)
{
    unsigned int id;
    if (!PyArg_ParseTuple(args, "I", &id)) return NULL;
    sy_scene *sc = scene_use((SceneObject *)self);
    if (!sc) return NULL;
    const sy_node_data *d = sy_node_get(sc, (sy_node){id});
    if (!d) return stale("node", id);
    uint32_t nc = 0;
    const uint32_t *ch = sy_node_children(d, &nc);
    PyObject *children = PyList_New(nc);
    for (uint32_t i = 0; children && i < nc; ++i) PyList_SetItem(children, i, PyLong_FromUnsignedLong(ch[i]));
    const sy_transform *t = &d->transform;
    return Py_BuildValue("{s:z,s:N,s:N,s:N,s:N,s:N,s:I,s:I,s:I,s:I,s:N}", "name", d->name, "matrix",
                         tuple_of(t->matrix.m, 16), "translation", tuple_of(t->translation, 3), "rotation",
                         tuple_of(t->rotation, 4), "scale", tuple_of(t->scale, 3), "trs",
                         PyBool_FromLong(t->mode == SY_TRANSFORM_TRS), "mesh", d->mesh.id, "light", d->light.id,
                         "camera", d->camera.id, "flags", d->flags, "children", children);
}

/* _node_set(id, matrix=None, translation=None, rotation=None, scale=None, mesh=None, light=None,
 * camera=None, flags=None, add_child=None) */
static PyObject *scene_node_set(PyObject *self, PyObject *args, PyObject *kw)
{
    static char *kwlist[] = {"id", "matrix", "translation", "rotation", "scale", "mesh", "light", "camera", "flags",
                             "add_child", NULL};
    unsigned int id;
    PyObject *m = Py_None, *t = Py_None, *rot = Py_None, *sc3 = Py_None, *mesh = Py_None, *light = Py_None,
             *cam = Py_None, *flags = Py_None, *child = Py_None;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "I|OOOOOOOOO", kwlist, &id, &m, &t, &rot, &sc3, &mesh, &light, &cam,
                                     &flags, &child))
        return NULL;
    sy_scene *sc = scene_use((SceneObject *)self);
    if (!sc) return NULL;
    sy_node n = {id};
    const sy_node_data *d = sy_node_get(sc, n);
    if (!d) return stale("node", id);
    sy_error err = {0};
    sy_result r = SY_OK;
    if (m != Py_None) {
        sy_mat4 mm;
        if (float_seq(m, "matrix", mm.m, 16)) return NULL;
        r = sy_node_set_matrix(sc, n, &mm, &err);
    }
    if (r == SY_OK && (t != Py_None || rot != Py_None || sc3 != Py_None)) {
        float tt[3], rr[4], ss[3];
        memcpy(tt, d->transform.translation, sizeof tt);
        memcpy(rr, d->transform.rotation, sizeof rr);
        memcpy(ss, d->transform.scale, sizeof ss);
        if ((t != Py_None && float_seq(t, "translation", tt, 3)) || (rot != Py_None && float_seq(rot, "rotation", rr, 4)) ||
            (sc3 != Py_None && float_seq(sc3, "scale", ss, 3)))
            return NULL;
        r = sy_node_set_trs(sc, n, tt, rr, ss, &err);
    }
    unsigned long v;
#define SY_PY_ID(obj, call)                                                                                            \
    if (r == SY_OK && obj != Py_None) {                                                                                \
        v = PyLong_AsUnsignedLong(obj);                                                                                \
        if (PyErr_Occurred()) return NULL;                                                                             \
        r = call;                                                                                                      \
    }
    SY_PY_ID(mesh, sy_node_set_mesh(sc, n, (sy_mesh){(uint32_t)v}, &err))
    SY_PY_ID(light, sy_node_set_light(sc, n, (sy_light){(uint32_t)v}, &err))
    SY_PY_ID(cam, sy_node_set_camera(sc, n, (sy_camera){(uint32_t)v}, &err))
    SY_PY_ID(flags, sy_node_set_flags(sc, n, (uint32_t)v, &err))
    SY_PY_ID(child, sy_node_add_child(sc, n, (sy_node){(uint32_t)v}, &err))
#undef SY_PY_ID
    if (r != SY_OK) return raise_sy(r, &err);
    Py_RETURN_NONE;
}

/* ------------------------------------------------------------------ _BlobView */
/* A read-only view of a mesh blob (sy_blob.h: immutable, reference-counted), exported through the
 * buffer protocol as float32 or uint32 rows x cols: numpy.asarray views it without a copy. It holds
 * its own reference to the blob, so the array stays valid after the mesh changes, is destroyed or
 * its scene is closed (it keeps the data it was made from). */
typedef struct {
    PyObject_HEAD
    sy_blob *blob;
    char format[2];
    int ndim;
    Py_ssize_t shape[2], strides[2];
} BlobViewObject;

static PyTypeObject *g_blobview_type;

static void blobview_dealloc(PyObject *self)
{
    sy_blob_release(((BlobViewObject *)self)->blob);
    object_free(self);
}

static int blobview_get(PyObject *self, Py_buffer *view, int flags)
{
    BlobViewObject *b = (BlobViewObject *)self;
    if (flags & PyBUF_WRITABLE) {
        PyErr_SetString(PyExc_BufferError, "switchyard: mesh data is read-only (the library's immutable blob); copy it "
                                           "to change it and set it with add_mesh");
        view->obj = NULL;
        return -1;
    }
    return export_view(self, view, (void *)sy_blob_data(b->blob), 1, b->format, b->ndim, b->shape, b->strides);
}

static PyType_Slot blobview_slots[] = {
    {Py_tp_dealloc, blobview_dealloc},
    {Py_bf_getbuffer, blobview_get},
    {Py_tp_doc, "a read-only view of a mesh's blob (numpy.asarray views it without a copy)"},
    {0, NULL}};
static PyType_Spec blobview_spec = {"switchyard._switchyard._BlobView", sizeof(BlobViewObject), 0, Py_TPFLAGS_DEFAULT,
                                    blobview_slots};

/* A view of blob as rows of cols 4-byte values (code 'f' or 'I'; cols 1: flat); None for NULL. */
static PyObject *blobview_of(sy_blob *blob, char code, Py_ssize_t cols)
{
    if (!blob) Py_RETURN_NONE;
    BlobViewObject *b = (BlobViewObject *)PyType_GenericNew(g_blobview_type, NULL, NULL);
    if (!b) return NULL;
    b->blob = sy_blob_retain(blob);
    b->format[0] = code;
    b->ndim = cols > 1 ? 2 : 1;
    b->shape[0] = (Py_ssize_t)(sy_blob_size(blob) / 4 / (size_t)cols);
    b->shape[1] = cols;
    b->strides[0] = 4 * cols;
    b->strides[1] = 4;
    return (PyObject *)b;
}

/* _mesh(id) -> {"name": str or None, "primitives": [dict of views, material id, topology]} */
static PyObject *scene_mesh(PyObject *self, PyObject *args)
{
    unsigned int id;
    if (!PyArg_ParseTuple(args, "I", &id)) return NULL;
    sy_scene *sc = scene_use((SceneObject *)self);
    if (!sc) return NULL;
    const sy_mesh_data *d = sy_mesh_get(sc, (sy_mesh){id});
    if (!d) return stale("mesh", id);
    PyObject *prims = PyList_New(d->primitives.count);
    for (uint32_t i = 0; prims && i < d->primitives.count; ++i) {
        const sy_primitive *p = &d->primitives.items[i];
        Py_ssize_t per = p->topology == SY_TOPOLOGY_TRIANGLES ? 3 : p->topology == SY_TOPOLOGY_LINES ? 2 : 1;
        PyObject *e = Py_BuildValue("{s:N,s:N,s:N,s:N,s:N,s:N,s:N,s:I,s:I}", "positions", blobview_of(p->positions, 'f', 3),
                                    "normals", blobview_of(p->normals, 'f', 3), "tangents", blobview_of(p->tangents, 'f', 4),
                                    "texcoords0", blobview_of(p->texcoords0, 'f', 2), "texcoords1",
                                    blobview_of(p->texcoords1, 'f', 2), "colors", blobview_of(p->colors, 'f', 4),
                                    "indices", blobview_of(p->indices, 'I', per), "material", p->material.id,
                                    "topology", p->topology);
        if (!e) Py_CLEAR(prims);
        else PyList_SetItem(prims, i, e);
    }
    if (!prims) return NULL;
    return Py_BuildValue("{s:z,s:N}", "name", d->name, "primitives", prims);
}

/* ------------------------------------------------------------------ _Node */
/* The base of switchyard.Node: the Python Scene (strong), its _Scene (strong, cached so the hot
 * path needs no attribute lookup) and the node's handle id. translation / rotation / scale are
 * getset descriptors: `node.translation = (x, y, z)` is one C call from the interpreter's STORE_ATTR
 * (no Python-level property, no argument-format parsing), the call-overhead target of issue 38
 * (apps/python/bench_overhead.py measures it). Holds no library pointer: a stale id raises
 * InvalidHandleError through the generation check, a closed scene InvalidOperationError. */
typedef struct {
    PyObject_HEAD
    PyObject *scene;     /* switchyard.Scene */
    SceneObject *impl;   /* scene._c */
    uint32_t id;
} NodeObject;

static PyObject *node_new(PyTypeObject *type, PyObject *args, PyObject *kw)
{
    PyObject *scene;
    unsigned long id;
    if (kw && PyDict_Size(kw)) return PyErr_Format(PyExc_TypeError, "Node(scene, id) takes no keyword arguments");
    if (!PyArg_ParseTuple(args, "Ok", &scene, &id)) return NULL;
    if (id > UINT32_MAX) return PyErr_Format(PyExc_ValueError, "Node: id %lu out of range", id);
    PyObject *impl = PyObject_GetAttrString(scene, "_c");
    if (!impl) PyErr_Clear();
    if (!impl || !PyObject_TypeCheck(impl, g_scene_type)) {
        Py_XDECREF(impl);
        return PyErr_Format(PyExc_TypeError, "Node: the scene must be a switchyard.Scene");
    }
    NodeObject *n = (NodeObject *)((allocfunc)PyType_GetSlot(type, Py_tp_alloc))(type, 0);
    if (!n) {
        Py_DECREF(impl);
        return NULL;
    }
    n->scene = Py_NewRef(scene);
    n->impl = (SceneObject *)impl;
    n->id = (uint32_t)id;
    return (PyObject *)n;
}

static int node_traverse(PyObject *self, visitproc visit, void *arg)
{
    NodeObject *n = (NodeObject *)self;
    Py_VISIT(Py_TYPE(self));
    Py_VISIT(n->scene);
    Py_VISIT((PyObject *)n->impl);
    return 0;
}

static int node_clear(PyObject *self)
{
    NodeObject *n = (NodeObject *)self;
    Py_CLEAR(n->scene);
    Py_CLEAR(n->impl);
    return 0;
}

static void node_dealloc(PyObject *self)
{
    PyObject_GC_UnTrack(self);
    node_clear(self);
    object_free(self);
}

/* A 3- or 4-number value: a tuple or list read in place, anything else through float_seq. */
static int node_values(PyObject *v, const char *what, float *out, Py_ssize_t n)
{
    PyObject *(*item)(PyObject *, Py_ssize_t) = NULL;
    Py_ssize_t size = -1;
    if (PyTuple_Check(v)) item = PyTuple_GetItem, size = PyTuple_Size(v);
    else if (PyList_Check(v)) item = PyList_GetItem, size = PyList_Size(v);
    if (!item || size != n) return float_seq(v, what, out, n);
    for (Py_ssize_t i = 0; i < n; ++i) {
        PyObject *it = item(v, i); /* borrowed: held while a __float__ might change the list */
        if (!it) return -1;
        Py_INCREF(it);
        double d = PyFloat_AsDouble(it);
        Py_DECREF(it);
        if (d == -1.0 && PyErr_Occurred()) return -1;
        out[i] = (float)d;
    }
    return 0;
}

static const char *const g_trs_names[3] = {"translation", "rotation", "scale"};

static PyObject *node_get_trs(PyObject *self, void *which_p)
{
    NodeObject *n = (NodeObject *)self;
    int which = (int)(intptr_t)which_p;
    sy_scene *sc = scene_use(n->impl);
    if (!sc) return NULL;
    const sy_node_data *d = sy_node_get(sc, (sy_node){n->id});
    if (!d) return stale("node", n->id);
    return which == 0 ? tuple_of(d->transform.translation, 3)
                      : which == 1 ? tuple_of(d->transform.rotation, 4) : tuple_of(d->transform.scale, 3);
}

static int node_set_trs(PyObject *self, PyObject *v, void *which_p)
{
    NodeObject *n = (NodeObject *)self;
    int which = (int)(intptr_t)which_p;
    if (!v) {
        PyErr_Format(PyExc_AttributeError, "Node.%s cannot be deleted", g_trs_names[which]);
        return -1;
    }
    sy_scene *sc = scene_use(n->impl);
    if (!sc) return -1;
    float val[4];
    if (node_values(v, g_trs_names[which], val, which == 1 ? 4 : 3)) return -1;
    sy_node node = {n->id};
    const sy_node_data *d = sy_node_get(sc, node);
    if (!d) {
        stale("node", n->id);
        return -1;
    }
    const float *t = which == 0 ? val : d->transform.translation, *r = which == 1 ? val : d->transform.rotation,
                *s = which == 2 ? val : d->transform.scale;
    sy_error err = {0};
    sy_result res = sy_node_set_trs(sc, node, t, r, s, &err);
    if (res != SY_OK) {
        raise_sy(res, &err);
        return -1;
    }
    return 0;
}

static PyObject *node_get_scene(PyObject *self, void *unused)
{
    (void)unused;
    return Py_NewRef(((NodeObject *)self)->scene);
}

static PyObject *node_get_id(PyObject *self, void *unused)
{
    (void)unused;
    return PyLong_FromUnsignedLong(((NodeObject *)self)->id);
}

static PyGetSetDef node_getset[] = {
    {"scene", node_get_scene, NULL, "the Scene the node belongs to", NULL},
    {"id", node_get_id, NULL, "the library's handle id (index and generation)", NULL},
    {"translation", node_get_trs, node_set_trs, "TRS translation (x, y, z)", (void *)0},
    {"rotation", node_get_trs, node_set_trs, "TRS rotation, unit quaternion (x, y, z, w)", (void *)1},
    {"scale", node_get_trs, node_set_trs, "TRS scale (x, y, z)", (void *)2},
    {NULL, NULL, NULL, NULL, NULL}};

static PyType_Slot node_slots[] = {{Py_tp_dealloc, node_dealloc},
                                   {Py_tp_new, node_new},
                                   {Py_tp_traverse, node_traverse},
                                   {Py_tp_clear, node_clear},
                                   {Py_tp_getset, node_getset},
                                   {Py_tp_doc, "the C base of switchyard.Node (scene, id, the TRS fields)"},
                                   {0, NULL}};
static PyType_Spec node_spec = {"switchyard._switchyard._Node", sizeof(NodeObject), 0,
                                Py_TPFLAGS_DEFAULT | Py_TPFLAGS_BASETYPE | Py_TPFLAGS_HAVE_GC, node_slots};

/* _bench_trs(scene_c, id, n) -> (wall seconds, thread CPU seconds): n calls of sy_node_set_trs from C (translation x = i), the
 * C side of the call-overhead comparison (apps/python/bench_overhead.py); not a public name. */
static PyObject *py_bench_trs(PyObject *self, PyObject *args)
{
    (void)self;
    PyObject *impl;
    unsigned long id, count;
    if (!PyArg_ParseTuple(args, "O!kk", g_scene_type, &impl, &id, &count)) return NULL;
    sy_scene *sc = scene_use((SceneObject *)impl);
    if (!sc) return NULL;
    sy_node node = {(uint32_t)id};
    const sy_node_data *d = sy_node_get(sc, node);
    if (!d) return stale("node", (unsigned)id);
    float t[3], r[4], s[3];
    memcpy(t, d->transform.translation, sizeof t);
    memcpy(r, d->transform.rotation, sizeof r);
    memcpy(s, d->transform.scale, sizeof s);
    sy_error err = {0};
    struct timespec a, b, ca, cb;
    clock_gettime(CLOCK_MONOTONIC, &a);
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ca);
    for (unsigned long i = 0; i < count; ++i) {
        t[0] = (float)i;
        sy_result res = sy_node_set_trs(sc, node, t, r, s, &err);
        if (res != SY_OK) return raise_sy(res, &err);
    }
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &cb);
    clock_gettime(CLOCK_MONOTONIC, &b);
    return Py_BuildValue("(dd)", (double)(b.tv_sec - a.tv_sec) + 1e-9 * (double)(b.tv_nsec - a.tv_nsec),
                         (double)(cb.tv_sec - ca.tv_sec) + 1e-9 * (double)(cb.tv_nsec - ca.tv_nsec));
}

/* ---- materials, lights, cameras: their fields by one table each, read and set by name */
typedef struct field_desc {
    const char *name;
    size_t offset;
    char kind; /* 'f': float[n], 'u': uint32 */
    uint8_t n;
} field_desc;

#define SY_PY_FIELD(T, f, k, n) {#f, offsetof(T, f), k, n}
static const field_desc material_fields[] = {
    SY_PY_FIELD(sy_material_data, base_color, 'f', 4), SY_PY_FIELD(sy_material_data, metallic, 'f', 1),
    SY_PY_FIELD(sy_material_data, roughness, 'f', 1), SY_PY_FIELD(sy_material_data, emissive, 'f', 3),
    SY_PY_FIELD(sy_material_data, emissive_strength, 'f', 1), SY_PY_FIELD(sy_material_data, double_sided, 'u', 1),
    SY_PY_FIELD(sy_material_data, alpha_mode, 'u', 1), SY_PY_FIELD(sy_material_data, alpha_cutoff, 'f', 1),
    SY_PY_FIELD(sy_material_data, transmission, 'f', 1), SY_PY_FIELD(sy_material_data, ior, 'f', 1),
    SY_PY_FIELD(sy_material_data, unlit, 'u', 1), {NULL, 0, 0, 0}};
static const field_desc light_fields[] = {
    SY_PY_FIELD(sy_light_data, type, 'u', 1), SY_PY_FIELD(sy_light_data, color, 'f', 3),
    SY_PY_FIELD(sy_light_data, intensity, 'f', 1), SY_PY_FIELD(sy_light_data, range, 'f', 1),
    SY_PY_FIELD(sy_light_data, inner_cone, 'f', 1), SY_PY_FIELD(sy_light_data, outer_cone, 'f', 1),
    {NULL, 0, 0, 0}};
static const field_desc camera_fields[] = {
    SY_PY_FIELD(sy_camera_data, projection, 'u', 1), SY_PY_FIELD(sy_camera_data, yfov, 'f', 1),
    SY_PY_FIELD(sy_camera_data, aspect, 'f', 1), SY_PY_FIELD(sy_camera_data, znear, 'f', 1),
    SY_PY_FIELD(sy_camera_data, zfar, 'f', 1), SY_PY_FIELD(sy_camera_data, xmag, 'f', 1),
    SY_PY_FIELD(sy_camera_data, ymag, 'f', 1), {NULL, 0, 0, 0}};
#undef SY_PY_FIELD

/* The field table and current values (a copy in *data) of a material, light or camera; NULL with an
 * exception for another type or a stale id. */
typedef union object_data {
    sy_material_data material;
    sy_light_data light;
    sy_camera_data camera;
} object_data;

static const field_desc *object_fields(sy_scene *sc, int type, unsigned id, object_data *data)
{
    const void *cur = NULL;
    size_t size = 0;
    const field_desc *t = NULL;
    switch (type) {
    case SY_TYPE_MATERIAL: cur = id ? sy_material_get(sc, (sy_material){id}) : NULL, size = sizeof data->material, t = material_fields; break;
    case SY_TYPE_LIGHT: cur = sy_light_get(sc, (sy_light){id}), size = sizeof data->light, t = light_fields; break;
    case SY_TYPE_CAMERA: cur = sy_camera_get(sc, (sy_camera){id}), size = sizeof data->camera, t = camera_fields; break;
    default: return PyErr_Format(PyExc_ValueError, "object type %d has no field table", type), NULL;
    }
    if (!cur) return stale(sy_object_type_name((sy_object_type)type), id), NULL;
    memcpy(data, cur, size);
    return t;
}

/* _get(type, id) -> dict of the fields (and "name") */
static PyObject *scene_get_fields(PyObject *self, PyObject *args)
{
    int type;
    unsigned int id;
    if (!PyArg_ParseTuple(args, "iI", &type, &id)) return NULL;
    sy_scene *sc = scene_use((SceneObject *)self);
    if (!sc) return NULL;
    object_data d;
    const field_desc *t = object_fields(sc, type, id, &d);
    if (!t) return NULL;
    PyObject *dict = Py_BuildValue("{s:z}", "name", *(char *const *)&d); /* every struct starts with its name */
    for (; dict && t->name; ++t) {
        const char *p = (const char *)&d + t->offset;
        PyObject *v = t->kind == 'u' ? PyLong_FromUnsignedLong(*(const uint32_t *)p)
                      : t->n == 1    ? PyFloat_FromDouble(*(const float *)p)
                                     : tuple_of((const float *)p, t->n);
        if (!v || PyDict_SetItemString(dict, t->name, v)) Py_CLEAR(dict);
        Py_XDECREF(v);
    }
    return dict;
}

/* _set(type, id, **fields): the named fields changed, the rest kept, through the type's setter
 * (which validates: a NaN roughness or a zfar before znear raises InvalidArgumentError) */
static PyObject *scene_set_fields(PyObject *self, PyObject *args, PyObject *kw)
{
    int type;
    unsigned int id;
    if (!PyArg_ParseTuple(args, "iI", &type, &id)) return NULL;
    sy_scene *sc = scene_use((SceneObject *)self);
    if (!sc) return NULL;
    object_data d;
    const field_desc *table = object_fields(sc, type, id, &d);
    if (!table) return NULL;
    PyObject *key, *value;
    Py_ssize_t pos = 0;
    while (kw && PyDict_Next(kw, &pos, &key, &value)) {
        const char *k = PyUnicode_AsUTF8AndSize(key, NULL);
        if (!k) return NULL;
        const field_desc *t = table;
        while (t->name && strcmp(t->name, k) != 0) ++t;
        if (!t->name)
            return PyErr_Format(PyExc_TypeError, "%s has no field '%s'", sy_object_type_name((sy_object_type)type), k);
        char *p = (char *)&d + t->offset;
        if (t->kind == 'u') {
            unsigned long u = PyLong_AsUnsignedLong(value);
            if (PyErr_Occurred()) return NULL;
            *(uint32_t *)p = (uint32_t)u;
        } else if (t->n == 1) {
            double f = PyFloat_AsDouble(value);
            if (f == -1.0 && PyErr_Occurred()) return NULL;
            *(float *)p = (float)f;
        } else if (float_seq(value, t->name, (float *)p, t->n)) {
            return NULL;
        }
    }
    sy_error err = {0};
    sy_result r = type == SY_TYPE_MATERIAL ? sy_material_set(sc, (sy_material){id}, &d.material, &err)
                  : type == SY_TYPE_LIGHT  ? sy_light_set(sc, (sy_light){id}, &d.light, &err)
                                           : sy_camera_set(sc, (sy_camera){id}, &d.camera, &err);
    if (r != SY_OK) return raise_sy(r, &err);
    Py_RETURN_NONE;
}

/* _info() -> dict(root, camera, background, counts) */
static PyObject *scene_info(PyObject *self, PyObject *unused)
{
    (void)unused;
    SceneObject *s = (SceneObject *)self;
    sy_scene *sc = scene_use(s);
    if (!sc) return NULL;
    return Py_BuildValue("{s:I,s:I,s:I,s:I,s:I,s:I,s:I,s:I}", "root", s->ld.root.id, "camera", s->ld.camera.id,
                         "background", s->ld.background.id, "nodes", sy_scene_count(sc, SY_TYPE_NODE), "meshes",
                         sy_scene_count(sc, SY_TYPE_MESH), "materials", sy_scene_count(sc, SY_TYPE_MATERIAL), "lights",
                         sy_scene_count(sc, SY_TYPE_LIGHT), "cameras", sy_scene_count(sc, SY_TYPE_CAMERA));
}

static PyObject *scene_set_camera(PyObject *self, PyObject *args)
{
    unsigned int id;
    if (!PyArg_ParseTuple(args, "I", &id)) return NULL;
    SceneObject *s = (SceneObject *)self;
    sy_scene *sc = scene_use(s);
    if (!sc) return NULL;
    const sy_node_data *d = id ? sy_node_get(sc, (sy_node){id}) : NULL;
    if (id && !d) return stale("node", id);
    if (d && !d->camera.id)
        return raise_sy(SY_ERR_INVALID_ARGUMENT,
                        &(sy_error){SY_ERR_INVALID_ARGUMENT, "camera: the node carries no camera (Node.camera)"});
    s->ld.camera.id = id;
    Py_RETURN_NONE;
}

static PyObject *scene_commit(PyObject *self, PyObject *unused)
{
    (void)unused;
    sy_scene *sc = scene_use((SceneObject *)self);
    if (!sc) return NULL;
    sy_error err = {0};
    sy_result r = sy_scene_commit(sc, NULL, &err);
    if (r != SY_OK) return raise_sy(r, &err);
    Py_RETURN_NONE;
}

/* ------------------------------------------------------------------ rendering */
/* Where a render in passes reports to: progress callable (done, total) between passes, and
 * Ctrl-C (PyErr_CheckSignals) after each pass. */
typedef struct render_job {
    sy_window *win;
    sy_context_pool *pool;
    sy_scene *scene;
    uint32_t seed;
    uint64_t spp;      /* progressive: samples to accumulate; 0: one pass (non-progressive) */
    uint32_t once_samples; /* spp == 0: the sample count of the one pass (a cluster over a progressive back-end) */
    PyObject *progress; /* callable or NULL */
    sy_layer out;
} render_job;

/* Renders job->win into job->out (created here). Called with the GIL held; releases it for the
 * library calls. Returns 0, or -1 with a Python exception (a library error, the progress callable's
 * error, KeyboardInterrupt). Passes as `sy render` takes them: about a quarter of a second each. */
static int render_run(render_job *job)
{
    sy_error err = {0};
    sy_result r;
    uint32_t w = 0, h = 0;
    sy_window_size(job->win, &w, &h);
    PyThreadState *ts = PyEval_SaveThread();
    r = sy_layer_create(w, h, &job->out, &err);
    PyEval_RestoreThread(ts);
    if (r != SY_OK) return raise_sy(r, &err), -1;
    uint64_t done = 0;
    uint32_t chunk = 1;
    for (;;) {
        uint64_t left = job->spp ? job->spp - done : 0;
        uint32_t n = job->spp ? (uint32_t)(left < chunk ? left : chunk) : job->once_samples;
        sy_window_render_opts ro = {.seed = job->seed, .sample_count = n};
        ts = PyEval_SaveThread();
        double p0 = sy_time_now();
        r = sy_window_render(job->win, job->scene, job->pool, &ro, &job->out, &err);
        double pass = (sy_time_now() - p0) / (n ? n : 1);
        PyEval_RestoreThread(ts);
        if (r != SY_OK) return raise_sy(r, &err), -1;
        done += job->spp ? n : 0;
        if (job->progress) {
            PyObject *res = PyObject_CallFunction(job->progress, "KK", (unsigned long long)(job->spp ? done : 1),
                                                  (unsigned long long)(job->spp ? job->spp : 1));
            if (!res) return -1;
            Py_DECREF(res);
        }
        if (!job->spp || done >= job->spp) return 0;
        if (PyErr_CheckSignals()) return -1; /* KeyboardInterrupt after the pass in progress */
        double want = pass > 0 ? 0.25 / pass : 64;
        chunk = want < 1 ? 1 : want > 1024 ? 1024 : (uint32_t)want;
    }
}

/* The image and the planes of a finished render: (rgba buffer, dict of AOV buffers or None, samples).
 * Takes job->out's planes. aovs: "depth" always (the layer's); with SY_CAP_AOVS the back-end's
 * feature buffers too (of the context named by backend/params/root). */
static PyObject *render_result(render_job *job, int want_aovs, sy_context *aov_ctx, uint64_t samples)
{
    uint32_t w = job->out.width, h = job->out.height;
    PyObject *img = buffer_take(job->out.rgba, h, w, 4);
    job->out.rgba = NULL;
    PyObject *aovs = NULL;
    if (img && want_aovs) {
        aovs = PyDict_New();
        PyObject *depth = aovs ? buffer_take(job->out.depth, h, w, 1) : NULL;
        job->out.depth = NULL;
        if (!depth || PyDict_SetItemString(aovs, "depth", depth)) Py_CLEAR(aovs);
        Py_XDECREF(depth);
        if (aovs && aov_ctx) {
            sy_aovs a = {0};
            sy_error err = {0};
            sy_result r = sy_context_aovs(aov_ctx, &a, &err);
            if (r != SY_OK) {
                Py_CLEAR(aovs);
                raise_sy(r, &err);
            }
            for (uint32_t k = 0; aovs && k < a.count; ++k) {
                if (!strcmp(a.planes[k].name, "depth")) continue; /* the layer's depth is the window's */
                PyObject *p = buffer_take(a.planes[k].data, a.height, a.width, a.planes[k].channels);
                a.planes[k].data = NULL;
                if (!p || PyDict_SetItemString(aovs, a.planes[k].name, p)) Py_CLEAR(aovs);
                Py_XDECREF(p);
            }
            sy_aovs_free(&a);
        }
    }
    sy_layer_destroy(&job->out);
    if (!img || (want_aovs && !aovs)) {
        Py_XDECREF(img);
        Py_XDECREF(aovs);
        return NULL;
    }
    return Py_BuildValue("(NNK)", img, want_aovs ? aovs : Py_NewRef(Py_None), (unsigned long long)samples);
}

/* Checks backend + params; *cls and *caps of the class. */
static int check_backend(const char *backend, const char *params, sy_params *pp, const sy_mediator_class **cls,
                         uint32_t *caps)
{
    sy_error err = {0};
    *cls = sy_mediator_require(backend, &err);
    if (!*cls) return raise_sy(err.code, &err), -1;
    sy_result r = sy_params_parse(params, pp, &err);
    if (r == SY_OK) r = sy_mediator_class_check_params(*cls, pp, &err);
    if (r != SY_OK) return raise_sy(r, &err), -1;
    *caps = sy_mediator_class_caps(*cls, pp);
    return 0;
}

/* servers= (the cluster, docs/CLUSTER.md): the back-end runs on `sy serve` servers through a
 * cluster mediator class, set up exactly as `sy render --cluster` sets it up (apps/sy/sy_cluster_cli.c:
 * a comma-separated URL list or a configuration file, --cluster-mode, --secret-file or
 * $SY_CLUSTER_SECRET). A class is registered per distinct (servers, mode, secret file) and reused:
 * the registry holds classes for the process's lifetime and refuses a name twice. Fills
 * cluster_name and cluster_params; 0, or -1 with an exception. */
#define SY_PY_MAX_CLUSTERS 16
#define SY_PY_PARAMS_MAX 1400 /* a back-end's parameter text (a cluster class's names every server) */
static int cluster_setup(const char *servers, const char *mode, const char *secret_file, const char *backend,
                         const char *params, char *cluster_name, size_t name_len, char *cluster_params,
                         size_t params_len, uint64_t *spp_per_request)
{
#ifdef SY_PY_HAVE_CLUSTER
    static struct {
        char key[1024];
        uint32_t mode;
    } known[SY_PY_MAX_CLUSTERS];
    static uint32_t known_count;
    char key[1024];
    int kn = snprintf(key, sizeof key, "%s\n%s\n%s", servers, mode ? mode : "", secret_file ? secret_file : "");
    if (kn < 0 || (size_t)kn >= sizeof key) return PyErr_Format(PyExc_ValueError, "servers: too long"), -1;
    sy_error err = {0};
    sy_result r = SY_OK;
    uint32_t k = 0, cmode = 0, nservers = 0;
    while (k < known_count && strcmp(known[k].key, key) != 0) ++k;
    sy_cluster_cli_opts o = {.cluster = servers, .mode = mode, .secret_file = secret_file};
    if (k == known_count) { /* a new configuration: connect options checked and a class registered */
        if (known_count == SY_PY_MAX_CLUSTERS)
            return raise_sy(SY_ERR_LIMIT, &(sy_error){SY_ERR_LIMIT, "servers: at most 16 distinct cluster "
                                                                    "configurations in one process"}), -1;
        char name[32];
        snprintf(name, sizeof name, "cluster-python-%u", k);
        r = sy_cluster_cli_register(&o, name, &cmode, &nservers, &err);
        if (r != SY_OK) return raise_sy(r, &err), -1;
        snprintf(known[k].key, sizeof known[k].key, "%s", key);
        known[k].mode = cmode;
        known_count++;
    }
    snprintf(cluster_name, name_len, "cluster-python-%u", k);
    r = sy_cluster_cli_params(&o, backend, known[k].mode, params, cluster_params, params_len, &err);
    if (r != SY_OK) return raise_sy(r, &err), -1;
    (void)spp_per_request;
    return 0;
#else
    (void)servers, (void)mode, (void)secret_file, (void)backend, (void)params, (void)cluster_name, (void)name_len;
    (void)cluster_params, (void)params_len, (void)spp_per_request;
    return raise_sy(SY_ERR_UNSUPPORTED, &(sy_error){SY_ERR_UNSUPPORTED, "servers: this build has no cluster "
                                                                        "(SY_WITH_CLUSTER off)"}), -1;
#endif
}

/* _render(backend=None, width=0, height=0, spp=0, seed=0, params=None, aovs=False, progress=None)
 * -> (rgba, aovs or None, samples): one viewport over the whole image with the scene's root,
 * camera and background, the back-end's parameters, as `sy render` composes a mono render. */
static PyObject *scene_render(PyObject *self, PyObject *args, PyObject *kw)
{
    static char *kwlist[] = {"backend", "width", "height", "spp", "seed", "params", "aovs", "progress",
                             "servers", "cluster_mode", "secret_file", NULL};
    const char *backend = NULL, *params = NULL, *servers = NULL, *cluster_mode = NULL, *secret_file = NULL;
    unsigned int width = 0, height = 0, seed = 0;
    unsigned long long spp = 0;
    int want_aovs = 0;
    PyObject *progress = Py_None;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "|zIIKIzpOzzz", kwlist, &backend, &width, &height, &spp, &seed, &params,
                                     &want_aovs, &progress, &servers, &cluster_mode, &secret_file))
        return NULL;
    SceneObject *s = (SceneObject *)self;
    sy_scene *sc = scene_use(s);
    if (!sc) return NULL;
    PyObject *argerr = g_errors[SY_ERR_INVALID_ARGUMENT] ? g_errors[SY_ERR_INVALID_ARGUMENT] : PyExc_ValueError;
    if (!backend) backend = sy_mediator_default_name();
    if (width > 16384 || height > 16384)
        return PyErr_Format(argerr, "image size %ux%u: at most 16384 a side", width, height);
    if (progress != Py_None && !PyCallable_Check(progress)) return PyErr_Format(PyExc_TypeError, "progress must be callable");
    sy_params pp;
    const sy_mediator_class *cls;
    uint32_t caps;
    if (check_backend(backend, params, &pp, &cls, &caps)) return NULL; /* the back-end the servers run */
    /* servers=: the main viewport's back-end becomes a cluster class over `backend`, as sy render --cluster */
    char cluster_name[32], cluster_params[SY_PY_PARAMS_MAX];
    uint64_t spp_per_request = 0;
    const char *shown = backend;
    if (servers) {
        bool remote_progressive = (caps & SY_CAP_PROGRESSIVE) != 0;
        if (cluster_setup(servers, cluster_mode, secret_file, backend, params, cluster_name, sizeof cluster_name,
                          cluster_params, sizeof cluster_params, &spp_per_request))
            return NULL;
        backend = cluster_name;
        params = cluster_params;
        if (check_backend(backend, params, &pp, &cls, &caps)) return NULL;
        /* sort-first / balanced over a progressive back-end: spp is the samples of the one request */
        if (spp && remote_progressive && !(caps & SY_CAP_PROGRESSIVE)) spp_per_request = spp, spp = 0;
    }
    bool progressive = (caps & SY_CAP_PROGRESSIVE) != 0;
    if (spp && !progressive)
        return PyErr_Format(argerr, "spp=%llu: back-end '%s' is not progressive (one pass renders the image)", spp, shown);
    if (spp > (1u << 24)) return PyErr_Format(argerr, "spp=%llu: at most 16777216", spp);
    if (progressive && !spp) spp = 64; /* as sy render */
    uint32_t w = width, h = height;
    sy_cli_default_size(&s->ld, &w, &h);
    sy_error err = {0};
    sy_result r = SY_OK;
    if (s->ld.is_x3d) sy_cli_fit_x3d_cameras(&s->ld, w, h); /* X3D fieldOfView is the smaller side's angle */
    r = sy_scene_commit(sc, NULL, &err);
    if (r != SY_OK) return raise_sy(r, &err);
    render_job job = {.scene = sc, .seed = seed, .spp = progressive ? spp : 0, .once_samples = (uint32_t)spp_per_request,
                      .progress = progress == Py_None ? NULL : progress};
    sy_viewport_desc d = {.root = s->ld.root, .camera = s->ld.camera, .background = s->ld.background,
                          .backend = backend, .params = params, .composite = SY_COMPOSITE_REPLACE};
    if (r == SY_OK) r = sy_context_pool_create(&job.pool, &err);
    if (r == SY_OK) r = sy_window_create(w, h, &job.win, &err);
    if (r == SY_OK) r = sy_window_add_viewport(job.win, &d, NULL, &err);
    PyObject *result = NULL;
    if (r != SY_OK) {
        raise_sy(r, &err);
    } else {
        s->busy = 1;
        int rc = render_run(&job);
        s->busy = 0;
        sy_context *ctx = NULL;
        sy_mediator_stats st = {0};
        if (rc == 0 && sy_context_pool_get(job.pool, sc, backend, &pp, s->ld.root.id, &ctx, &err) == SY_OK)
            sy_context_stats(ctx, &st);
        if (rc == 0)
            result = render_result(&job, want_aovs, (caps & SY_CAP_AOVS) ? ctx : NULL, st.samples);
    }
    sy_layer_destroy(&job.out);
    sy_window_destroy(job.win);
    sy_context_pool_destroy(job.pool);
    return result;
}

/* _set_time(seconds, clip=None): the scene's animation clock (load's at= / clip=) */
static PyObject *scene_set_time(PyObject *self, PyObject *args)
{
    PyObject *at;
    const char *clip = NULL;
    double seconds;
    if (!PyArg_ParseTuple(args, "O|z", &at, &clip) || time_from_python(at, &seconds)) return NULL;
    sy_scene *sc = scene_use((SceneObject *)self);
    if (!sc || scene_time(sc, clip, seconds)) return NULL;
    Py_RETURN_NONE;
}

static PyMethodDef scene_methods[] = {
    {"_set_time", scene_set_time, METH_VARARGS, NULL},
    {"close", scene_close, METH_NOARGS, "Frees the scene now (objects of it become stale)."},
    {"_add_mesh", (PyCFunction)(void (*)(void))scene_add_mesh, METH_VARARGS | METH_KEYWORDS, NULL},
    {"_create", scene_create, METH_VARARGS, NULL},
    {"_destroy", scene_destroy_object, METH_VARARGS, NULL},
    {"_ids", scene_ids, METH_VARARGS, NULL},
    {"_valid", scene_valid, METH_VARARGS, NULL},
    {"_node", scene_node, METH_VARARGS, NULL},
    {"_mesh", scene_mesh, METH_VARARGS, NULL},
    {"_node_set", (PyCFunction)(void (*)(void))scene_node_set, METH_VARARGS | METH_KEYWORDS, NULL},
    {"_get", scene_get_fields, METH_VARARGS, NULL},
    {"_set", (PyCFunction)(void (*)(void))scene_set_fields, METH_VARARGS | METH_KEYWORDS, NULL},
    {"_info", scene_info, METH_NOARGS, NULL},
    {"_set_camera", scene_set_camera, METH_VARARGS, NULL},
    {"commit", scene_commit, METH_NOARGS, "Seals the changes since the last commit (render commits too)."},
    {"_render", (PyCFunction)(void (*)(void))scene_render, METH_VARARGS | METH_KEYWORDS, NULL},
    {NULL, NULL, 0, NULL}};

static PyType_Slot scene_slots[] = {{Py_tp_dealloc, scene_dealloc},
                                    {Py_tp_new, scene_new},
                                    {Py_tp_methods, scene_methods},
                                    {Py_tp_doc, "the library's sy_scene (switchyard.Scene wraps it)"},
                                    {0, NULL}};
static PyType_Spec scene_spec = {"switchyard._switchyard._Scene", sizeof(SceneObject), 0,
                                 Py_TPFLAGS_DEFAULT | Py_TPFLAGS_BASETYPE, scene_slots};

#ifdef SY_PY_HAVE_WEB
/* ------------------------------------------------------------------ _Web */
/* The web view of a _Scene (apps/web/sy_web.h, as `sy web` serves it): sy_web_run on a thread of
 * its own, which never holds the GIL (the log callback takes it for a message). While it serves,
 * the server's render thread owns the scene: the _Scene is marked busy, so Python calls on it
 * raise RuntimeError instead of racing; stop() (or dealloc) stops the server, joins the thread and
 * frees it, and the scene is usable again. Holds a strong reference to the _Scene. */
typedef struct {
    PyObject_HEAD
    SceneObject *scene;
    sy_web *web;
    sy_web_thread *thread; /* started and not joined yet (apps/web/sy_web_thread.h) */
    sy_result result;      /* what sy_web_run returned */
    sy_error err;
} WebObject;

/* Stops the server and frees it; 0, or -1 with an exception when serving had ended with an error. */
static int web_stop(WebObject *w, int report)
{
    if (w->thread) {
        Py_BEGIN_ALLOW_THREADS
        w->result = sy_web_thread_join(w->thread, &w->err);
        Py_END_ALLOW_THREADS
        w->thread = NULL;
    }
    if (w->web) {
        sy_web_destroy(w->web);
        w->web = NULL;
        if (w->scene) w->scene->busy = 0;
    }
    if (report && w->result != SY_OK) {
        sy_result r = w->result;
        w->result = SY_OK;
        raise_sy(r, &w->err);
        return -1;
    }
    return 0;
}

static void web_dealloc(PyObject *self)
{
    WebObject *w = (WebObject *)self;
    web_stop(w, 0);
    Py_CLEAR(w->scene);
    object_free(self);
}

/* _Web(scene, backend=None, listen=None, token=None, max_width=0, max_height=0, quality=0,
 * filter=None, threshold=0, budget_ms=0): serving starts at once */
static PyObject *web_new(PyTypeObject *type, PyObject *args, PyObject *kw)
{
    static char *kwlist[] = {"scene", "backend", "listen", "token", "max_width", "max_height", "quality", "filter",
                             "threshold", "budget_ms", NULL};
    PyObject *scene;
    const char *backend = NULL, *listen = NULL, *token = NULL, *filter = NULL;
    unsigned int mw = 0, mh = 0;
    int quality = 0;
    float threshold = 0.0f;
    double budget = 0.0;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "O!|zzzIIizfd", kwlist, g_scene_type, &scene, &backend, &listen, &token,
                                     &mw, &mh, &quality, &filter, &threshold, &budget))
        return NULL;
    SceneObject *s = (SceneObject *)scene;
    sy_scene *sc = scene_use(s);
    if (!sc) return NULL;
    sy_error err = {0};
    sy_result r = sy_scene_commit(sc, NULL, &err); /* the server never commits: what Python built is sealed now */
    if (r != SY_OK) return raise_sy(r, &err);
    if (!s->ld.camera.id)
        return raise_sy(SY_ERR_INVALID_ARGUMENT,
                        &(sy_error){SY_ERR_INVALID_ARGUMENT, "serve: the scene has no camera (add one: scene.camera = "
                                                             "scene.add_camera(...))"});
    WebObject *w = (WebObject *)PyType_GenericNew(type, NULL, NULL);
    if (!w) return NULL;
    sy_web_desc d = {.scene = sc, .root = s->ld.root, .camera = s->ld.camera, .background = s->ld.background,
                     .backend = backend, .listen = listen, .token = token, .max_width = mw, .max_height = mh,
                     .quality = quality, .filter = filter, .threshold = threshold, .budget_ms = budget};
    s->busy = 1; /* from here the scene belongs to the server (released in web_stop) */
    Py_BEGIN_ALLOW_THREADS
    r = sy_web_create(&d, &w->web, &err);
    Py_END_ALLOW_THREADS
    if (r != SY_OK) {
        s->busy = 0;
        Py_DECREF(w);
        return raise_sy(r, &err);
    }
    w->scene = (SceneObject *)Py_NewRef(scene);
    if (sy_web_thread_start(w->web, &w->thread, &err) != SY_OK) {
        Py_DECREF(w); /* destroys the server, the scene is free again */
        return raise_sy(SY_ERR_SYSTEM, &(sy_error){SY_ERR_SYSTEM, "serve: could not start the server's thread"});
    }
    return (PyObject *)w;
}

static PyObject *web_stop_method(PyObject *self, PyObject *unused)
{
    (void)unused;
    if (web_stop((WebObject *)self, 1)) return NULL;
    Py_RETURN_NONE;
}

static PyObject *web_info(PyObject *self, PyObject *unused)
{
    (void)unused;
    WebObject *w = (WebObject *)self;
    if (!w->web) return Py_BuildValue("{s:O,s:i,s:O}", "url", Py_None, "port", 0, "running", Py_False);
    sy_web_stats st;
    sy_web_stats_get(w->web, &st);
    return Py_BuildValue("{s:s,s:i,s:O,s:K,s:K}", "url", sy_web_url(w->web), "port", (int)sy_web_port(w->web),
                         "running", Py_True, "stills_done", (unsigned long long)st.stills_done, "accepted",
                         (unsigned long long)st.accepted);
}

static PyMethodDef web_methods[] = {
    {"stop", web_stop_method, METH_NOARGS, "Stops serving, joins the server's thread, frees the server."},
    {"_info", web_info, METH_NOARGS, NULL},
    {NULL, NULL, 0, NULL}};
static PyType_Slot web_slots[] = {{Py_tp_dealloc, web_dealloc},
                                  {Py_tp_new, web_new},
                                  {Py_tp_methods, web_methods},
                                  {Py_tp_doc, "the web view of a _Scene (sy_web, served by a thread of its own)"},
                                  {0, NULL}};
static PyType_Spec web_spec = {"switchyard._switchyard._Web", sizeof(WebObject), 0, Py_TPFLAGS_DEFAULT, web_slots};
#endif

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
    object_free(self);
}

static PyObject *window_new(PyTypeObject *type, PyObject *args, PyObject *kw)
{
    static char *kwlist[] = {"scene", "width", "height", NULL};
    PyObject *scene;
    unsigned int width, height;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "OII", kwlist, &scene, &width, &height)) return NULL;
    if (!PyObject_TypeCheck(scene, g_scene_type)) return PyErr_Format(PyExc_TypeError, "scene must be a switchyard Scene");
    if (!scene_use((SceneObject *)scene)) return NULL;
    if (!width || !height || width > 16384 || height > 16384)
        return raise_sy(SY_ERR_INVALID_ARGUMENT,
                        &(sy_error){SY_ERR_INVALID_ARGUMENT, "Window: width and height must be 1 to 16384"});
    WindowObject *w = (WindowObject *)PyType_GenericNew(type, NULL, NULL);
    if (!w) return NULL;
    sy_error err = {0};
    sy_result r = sy_window_create(width, height, &w->win, &err);
    if (r == SY_OK) r = sy_context_pool_create(&w->pool, &err);
    if (r != SY_OK) {
        Py_DECREF(w);
        return raise_sy(r, &err);
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
        return raise_sy(e.code, &e), -1;
    }
    return scene_use(w->scene) ? 0 : -1;
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
/* servers= of a viewport: backend / params become a cluster class over them (cluster_setup, as
 * Scene.render's servers=); the buffers hold the result. 0, or -1 with an exception. */
static int viewport_cluster(const char *servers, const char *mode, const char *secret_file, const char **backend,
                            const char **params, char *name, size_t name_len, char *cparams, size_t cparams_len)
{
    if (!servers) return 0;
    uint64_t unused = 0;
    const sy_mediator_class *cls;
    sy_params pp;
    uint32_t caps;
    if (check_backend(*backend, *params, &pp, &cls, &caps) || /* the back-end the servers run */
        cluster_setup(servers, mode, secret_file, *backend, *params, name, name_len, cparams, cparams_len, &unused))
        return -1;
    *backend = name;
    *params = cparams;
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
    if (viewport_cluster(servers, cluster_mode, secret_file, &backend, &params, cname, sizeof cname, cparams,
                         sizeof cparams))
        return NULL;
    if (strlen(backend) >= sizeof w->backends[0] || (params && strlen(params) >= sizeof w->params[0]))
        return PyErr_Format(PyExc_ValueError, "backend or params too long");
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
    if (r != SY_OK) return raise_sy(r, &err);
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
    if (viewport_cluster(servers, cluster_mode, secret_file, &backend, &params, cname, sizeof cname, cparams,
                         sizeof cparams))
        return NULL;
    if (strlen(backend) >= sizeof w->backends[0] || (params && strlen(params) >= sizeof w->params[0]))
        return PyErr_Format(PyExc_ValueError, "backend or params too long");
    sy_error err = {0};
    sy_result r = sy_viewport_set_backend(vp, backend, params, &err);
    if (r != SY_OK) return raise_sy(r, &err);
    snprintf(w->backends[i], sizeof w->backends[0], "%s", backend);
    snprintf(w->params[i], sizeof w->params[0], "%s", params ? params : "");
    Py_RETURN_NONE;
}

static PyObject *window_viewport(PyObject *self, PyObject *args)
{
    WindowObject *w = (WindowObject *)self;
    unsigned int i;
    if (!PyArg_ParseTuple(args, "I", &i)) return NULL;
    sy_viewport *vp = window_vp(w, i);
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

/* Reads n floats of a sequence into out; a Python error (naming what) and -1 otherwise. */
static int floats_of(PyObject *seq, float *out, Py_ssize_t n, const char *what, Py_ssize_t index)
{
    Py_ssize_t len = PySequence_Check(seq) ? PySequence_Size(seq) : -1;
    if (len < 0) {
        PyErr_Clear();
        PyErr_Format(PyExc_TypeError, "%s %zd: a sequence of %zd numbers expected", what, index, n);
        return -1;
    }
    if (len != n) {
        PyErr_Format(PyExc_ValueError, "%s %zd: %zd numbers expected, got %zd", what, index, n, len);
        return -1;
    }
    for (Py_ssize_t k = 0; k < n; ++k) {
        PyObject *item = PySequence_GetItem(seq, k);
        double d = item ? PyFloat_AsDouble(item) : -1.0;
        Py_XDECREF(item);
        if (d == -1.0 && PyErr_Occurred()) return -1;
        out[k] = (float)d;
    }
    return 0;
}

/* _set_clip_planes(index, planes): planes a sequence of up to 6 (a, b, c, d); [] removes them.
 * The library checks them (sy_viewport_set_clip_planes): NaN, infinite, a zero normal, a seventh
 * plane raise its InvalidArgument error naming the plane; the planes before stay. */
static PyObject *window_set_clip_planes(PyObject *self, PyObject *args)
{
    WindowObject *w = (WindowObject *)self;
    unsigned int i;
    PyObject *seq;
    if (!PyArg_ParseTuple(args, "IO", &i, &seq)) return NULL;
    sy_viewport *vp = window_vp(w, i);
    if (!vp) return NULL;
    Py_ssize_t total = PySequence_Check(seq) ? PySequence_Size(seq) : -1;
    if (total < 0) {
        PyErr_Clear();
        return PyErr_Format(PyExc_TypeError, "clip planes: a sequence of (a, b, c, d) expected");
    }
    float planes[SY_CLIP_PLANES_MAX + 1][4];
    Py_ssize_t n = total > SY_CLIP_PLANES_MAX + 1 ? SY_CLIP_PLANES_MAX + 1 : total; /* the library names the count */
    for (Py_ssize_t k = 0; k < n; ++k) {
        PyObject *item = PySequence_GetItem(seq, k);
        int bad = !item || floats_of(item, planes[k], 4, "clip plane", k);
        Py_XDECREF(item);
        if (bad) return NULL;
    }
    sy_error err = {0};
    sy_result r = total > SY_CLIP_PLANES_MAX
                      ? sy_clip_planes_check((const float(*)[4])planes, (uint32_t)total, &err)
                      : sy_viewport_set_clip_planes(vp, (const float(*)[4])planes, (uint32_t)n, &err);
    if (r != SY_OK) return raise_sy(r, &err);
    Py_RETURN_NONE;
}

/* _clip_planes(index) -> list of (a, b, c, d) */
static PyObject *window_clip_planes(PyObject *self, PyObject *args)
{
    WindowObject *w = (WindowObject *)self;
    unsigned int i;
    if (!PyArg_ParseTuple(args, "I", &i)) return NULL;
    sy_viewport *vp = window_vp(w, i);
    if (!vp) return NULL;
    float planes[SY_CLIP_PLANES_MAX][4];
    uint32_t n = sy_viewport_clip_planes(vp, planes);
    PyObject *list = PyList_New((Py_ssize_t)n);
    for (uint32_t k = 0; list && k < n; ++k) {
        PyObject *t = Py_BuildValue("(dddd)", (double)planes[k][0], (double)planes[k][1], (double)planes[k][2],
                                    (double)planes[k][3]);
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
    WindowObject *w = (WindowObject *)self;
    unsigned int i;
    PyObject *rgb;
    if (!PyArg_ParseTuple(args, "IO", &i, &rgb)) return NULL;
    sy_viewport *vp = window_vp(w, i);
    if (!vp) return NULL;
    float c[3];
    if (rgb != Py_None && floats_of(rgb, c, 3, "clip cap colour", 0)) return NULL;
    sy_error err = {0};
    sy_result r = sy_viewport_set_clip_cap(vp, rgb == Py_None ? NULL : c, &err);
    if (r != SY_OK) return raise_sy(r, &err);
    Py_RETURN_NONE;
}

/* _clip_cap(index) -> (r, g, b) or None */
static PyObject *window_clip_cap(PyObject *self, PyObject *args)
{
    WindowObject *w = (WindowObject *)self;
    unsigned int i;
    if (!PyArg_ParseTuple(args, "I", &i)) return NULL;
    sy_viewport *vp = window_vp(w, i);
    if (!vp) return NULL;
    float c[3];
    if (!sy_viewport_clip_cap(vp, c)) Py_RETURN_NONE;
    return Py_BuildValue("(ddd)", (double)c[0], (double)c[1], (double)c[2]);
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
    if (r != SY_OK) return raise_sy(r, &err);
    render_job job = {.win = w->win, .pool = w->pool, .scene = sc, .seed = seed, .spp = spp,
                      .progress = progress == Py_None ? NULL : progress};
    w->busy = w->scene->busy = 1;
    int rc = render_run(&job);
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
    return render_result(&job, want_aovs, (caps & SY_CAP_AOVS) && w->count == 1 ? ctx : NULL, st.samples);
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

static PyType_Slot window_slots[] = {{Py_tp_dealloc, window_dealloc},
                                     {Py_tp_new, window_new},
                                     {Py_tp_methods, window_methods},
                                     {Py_tp_doc, "the library's sy_window with its own context pool"},
                                     {0, NULL}};
static PyType_Spec window_spec = {"switchyard._switchyard._Window", sizeof(WindowObject), 0,
                                  Py_TPFLAGS_DEFAULT | Py_TPFLAGS_BASETYPE, window_slots};

/* ------------------------------------------------------------------ registry, EXR */
/* backends() -> list of (name, caps, is_default) in registration order */
static PyObject *py_backends(PyObject *self, PyObject *unused)
{
    (void)self, (void)unused;
    const char *def = sy_mediator_default_name();
    PyObject *l = PyList_New(0);
    for (uint32_t i = 0; l && i < sy_mediator_count(); ++i) {
        const sy_mediator_class *c = sy_mediator_at(i);
        PyObject *t = Py_BuildValue("(sIN)", c->name, c->caps, PyBool_FromLong(!strcmp(c->name, def)));
        if (!t || PyList_Append(l, t)) Py_CLEAR(l);
        Py_XDECREF(t);
    }
    return l;
}

/* read_exr(path) -> (width, height, {channel name: buffer}) */
static PyObject *py_read_exr(PyObject *self, PyObject *args)
{
    (void)self;
    PyObject *path_obj;
    if (!PyArg_ParseTuple(args, "O&", PyUnicode_FSConverter, &path_obj)) return NULL;
    sy_exr_image *img = NULL;
    sy_error err = {0};
    sy_result r;
    const char *path = PyBytes_AsString(path_obj);
    Py_BEGIN_ALLOW_THREADS
    r = sy_exr_read(path, &img, &err);
    Py_END_ALLOW_THREADS
    Py_DECREF(path_obj);
    if (r != SY_OK) return raise_sy(r, &err);
    PyObject *d = PyDict_New();
    for (int i = 0; d && i < img->channel_count; ++i) {
        PyObject *b = buffer_take(img->channels[i].data, (uint32_t)img->height, (uint32_t)img->width, 1);
        img->channels[i].data = NULL;
        if (!b || PyDict_SetItemString(d, img->channels[i].name, b)) Py_CLEAR(d);
        Py_XDECREF(b);
    }
    PyObject *res = d ? Py_BuildValue("(iiN)", img->width, img->height, d) : NULL;
    sy_exr_image_free(img);
    return res;
}

/* write_exr(path, rgba, depth=None, half=False): rgba float32 H x W x 4 (C-contiguous), depth H x W */
static PyObject *py_write_exr(PyObject *self, PyObject *args, PyObject *kw)
{
    (void)self;
    static char *kwlist[] = {"path", "rgba", "depth", "half", NULL};
    PyObject *path_obj, *rgba, *depth = Py_None;
    int half = 0;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "O&O|Op", kwlist, PyUnicode_FSConverter, &path_obj, &rgba, &depth, &half))
        return NULL;
    PyObject *argerr = g_errors[SY_ERR_INVALID_ARGUMENT] ? g_errors[SY_ERR_INVALID_ARGUMENT] : PyExc_ValueError;
    Py_buffer cv, dv;
    Py_ssize_t n = 0, nd = 0;
    PyObject *res = NULL;
    if (get_array(rgba, "rgba", 'f', 4, 3, &cv, &n)) goto out0;
    if (cv.ndim != 3 || cv.shape[2] != 4) {
        PyErr_Format(argerr, "rgba: expected an H x W x 4 array");
        goto out1;
    }
    if (depth != Py_None) {
        if (get_array(depth, "depth", 'f', 1, 2, &dv, &nd)) goto out1;
        if (nd != n) {
            PyErr_Format(argerr, "depth: %zd values for %zd pixels", nd, n);
            goto out2;
        }
    }
    sy_error err = {0};
    sy_result r;
    const char *path = PyBytes_AsString(path_obj);
    Py_BEGIN_ALLOW_THREADS
    r = sy_exr_write_rgba(path, (int)cv.shape[1], (int)cv.shape[0], cv.buf, depth != Py_None ? dv.buf : NULL,
                          half ? SY_EXR_PIXEL_HALF : SY_EXR_PIXEL_FLOAT, &err);
    Py_END_ALLOW_THREADS
    res = r == SY_OK ? Py_NewRef(Py_None) : raise_sy(r, &err);
out2:
    if (depth != Py_None) PyBuffer_Release(&dv);
out1:
    PyBuffer_Release(&cv);
out0:
    Py_DECREF(path_obj);
    return res;
}

static PyObject *py_version(PyObject *self, PyObject *unused)
{
    (void)self, (void)unused;
    return PyUnicode_FromString(sy_version());
}

static PyObject *py_blob_live_count(PyObject *self, PyObject *unused)
{
    (void)self, (void)unused;
    return PyLong_FromLong(sy_blob_live_count());
}

static PyMethodDef module_methods[] = {
    {"load", (PyCFunction)(void (*)(void))py_load, METH_VARARGS | METH_KEYWORDS, NULL},
    {"backends", py_backends, METH_NOARGS, NULL},
    {"read_exr", py_read_exr, METH_VARARGS, NULL},
    {"write_exr", (PyCFunction)(void (*)(void))py_write_exr, METH_VARARGS | METH_KEYWORDS, NULL},
    {"version", py_version, METH_NOARGS, NULL},
    {"blob_live_count", py_blob_live_count, METH_NOARGS, NULL},
    {"_bench_trs", py_bench_trs, METH_VARARGS, NULL},
    {"_set_errors", py_set_errors, METH_VARARGS, NULL},
    {"_set_log", py_set_log, METH_VARARGS, NULL},
    {NULL, NULL, 0, NULL}};

static struct PyModuleDef module_def = {PyModuleDef_HEAD_INIT, "switchyard._switchyard",
                                        "The C half of switchyard (apps/python/src/sy_python.c).", -1, module_methods,
                                        NULL, NULL, NULL, NULL};

PyMODINIT_FUNC PyInit__switchyard(void)
{
    sy_error err = {0};
    if (sy_mediators_register_builtin(&err) != SY_OK) {
        PyErr_Format(PyExc_ImportError, "switchyard: registering the back-ends failed: %s", err.message);
        return NULL;
    }
    PyObject *m = PyModule_Create(&module_def);
    if (!m) return NULL;
    g_buffer_type = (PyTypeObject *)PyType_FromSpec(&buffer_spec);
    g_blobview_type = (PyTypeObject *)PyType_FromSpec(&blobview_spec);
    g_scene_type = (PyTypeObject *)PyType_FromSpec(&scene_spec);
    PyObject *window_type = PyType_FromSpec(&window_spec);
    PyObject *node_type = PyType_FromSpec(&node_spec);
    if (!g_buffer_type || !g_scene_type || !window_type || !node_type || !g_blobview_type ||
        PyModule_AddObjectRef(m, "_BlobView", (PyObject *)g_blobview_type) || PyModule_AddObjectRef(m, "_Node", node_type) ||
        PyModule_AddObjectRef(m, "_Buffer", (PyObject *)g_buffer_type) ||
        PyModule_AddObjectRef(m, "_Scene", (PyObject *)g_scene_type) || PyModule_AddObjectRef(m, "_Window", window_type) ||
        PyModule_AddIntConstant(m, "CAP_DEPTH", SY_CAP_DEPTH) ||
        PyModule_AddIntConstant(m, "CAP_PROGRESSIVE", SY_CAP_PROGRESSIVE) ||
        PyModule_AddIntConstant(m, "CAP_AOVS", SY_CAP_AOVS) || PyModule_AddIntConstant(m, "CAP_FILTERS", SY_CAP_FILTERS) ||
        PyModule_AddIntConstant(m, "CAP_REMOTE", SY_CAP_REMOTE) || PyModule_AddIntConstant(m, "CAP_PICK", SY_CAP_PICK) ||
        PyModule_AddIntConstant(m, "CAP_CLIP", SY_CAP_CLIP) || PyModule_AddIntConstant(m, "CAP_MOTION", SY_CAP_MOTION) ||
        PyModule_AddIntConstant(m, "CAP_COVERAGE", SY_CAP_COVERAGE) ||
        PyModule_AddIntConstant(m, "TYPE_NODE", SY_TYPE_NODE) || PyModule_AddIntConstant(m, "TYPE_MESH", SY_TYPE_MESH) ||
        PyModule_AddIntConstant(m, "TYPE_MATERIAL", SY_TYPE_MATERIAL) ||
        PyModule_AddIntConstant(m, "TYPE_LIGHT", SY_TYPE_LIGHT) || PyModule_AddIntConstant(m, "TYPE_CAMERA", SY_TYPE_CAMERA) ||
        PyModule_AddIntConstant(m, "NODE_VISIBLE", SY_NODE_VISIBLE) ||
        PyModule_AddIntConstant(m, "NODE_STATIC", SY_NODE_STATIC) ||
        PyModule_AddIntConstant(m, "NODE_ANIMATED", SY_NODE_ANIMATED) ||
        PyModule_AddIntConstant(m, "NODE_SELECTED", SY_NODE_SELECTED)) {
        Py_XDECREF(window_type);
        Py_XDECREF(node_type);
        Py_DECREF(m);
        return NULL;
    }
    Py_DECREF(window_type);
    Py_DECREF(node_type);
#ifdef SY_PY_HAVE_WEB
    PyObject *web_type = PyType_FromSpec(&web_spec);
    if (!web_type || PyModule_AddObjectRef(m, "_Web", web_type)) {
        Py_XDECREF(web_type);
        Py_DECREF(m);
        return NULL;
    }
    Py_DECREF(web_type);
#endif
    return m;
}
