/* sy_py_module.c — errors, the log callback, the registry, EXR and the module itself (part of
 * switchyard._switchyard: sy_py.h). */
#include "sy_py.h"

/* ------------------------------------------------------------------ errors */
/* switchyard.Error subclasses by sy_result code, handed over by __init__.py (_set_errors). */
PyObject *sy_py_errors[SY_ERR_SYSTEM + 1];
static PyObject *g_error_base;

PyObject *sy_py_raise(sy_result r, const sy_error *e)
{
    PyObject *cls = (r > 0 && r <= SY_ERR_SYSTEM && sy_py_errors[r]) ? sy_py_errors[r] : g_error_base;
    if (!cls) cls = PyExc_RuntimeError;
    const char *msg = e && e->message[0] ? e->message : sy_result_str(r);
    PyObject *args = Py_BuildValue("(si)", msg, (int)r);
    if (args) {
        PyErr_SetObject(cls, args);
        Py_DECREF(args);
    }
    return NULL;
}

PyObject *sy_py_none_or_raise(sy_result r, const sy_error *e)
{
    if (r != SY_OK) return sy_py_raise(r, e);
    Py_RETURN_NONE;
}

PyObject *sy_py_set_errors(PyObject *self, PyObject *args)
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
        Py_XDECREF(sy_py_errors[r]);
        sy_py_errors[r] = cls ? Py_NewRef(cls) : NULL;
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

PyObject *sy_py_set_log(PyObject *self, PyObject *args)
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
void sy_py_object_free(PyObject *self)
{
    PyTypeObject *tp = Py_TYPE(self);
    freefunc f = (freefunc)PyType_GetSlot(tp, Py_tp_free);
    f(self);
    Py_DECREF(tp);
}

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
    if (r != SY_OK) return sy_py_raise(r, &err);
    PyObject *d = PyDict_New();
    for (int i = 0; d && i < img->channel_count; ++i) {
        PyObject *b = sy_py_buffer_take(img->channels[i].data, (uint32_t)img->height, (uint32_t)img->width, 1);
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
    PyObject *argerr = sy_py_errors[SY_ERR_INVALID_ARGUMENT] ? sy_py_errors[SY_ERR_INVALID_ARGUMENT] : PyExc_ValueError;
    Py_buffer cv, dv;
    Py_ssize_t n = 0, nd = 0;
    PyObject *res = NULL;
    if (sy_py_get_array(rgba, "rgba", 'f', 4, 3, &cv, &n)) goto out0;
    if (cv.ndim != 3 || cv.shape[2] != 4) {
        PyErr_Format(argerr, "rgba: expected an H x W x 4 array");
        goto out1;
    }
    if (depth != Py_None) {
        if (sy_py_get_array(depth, "depth", 'f', 1, 2, &dv, &nd)) goto out1;
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
    res = r == SY_OK ? Py_NewRef(Py_None) : sy_py_raise(r, &err);
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
    {"load", (PyCFunction)(void (*)(void))sy_py_load, METH_VARARGS | METH_KEYWORDS, NULL},
    {"backends", py_backends, METH_NOARGS, NULL},
    {"read_exr", py_read_exr, METH_VARARGS, NULL},
    {"write_exr", (PyCFunction)(void (*)(void))py_write_exr, METH_VARARGS | METH_KEYWORDS, NULL},
    {"version", py_version, METH_NOARGS, NULL},
    {"blob_live_count", py_blob_live_count, METH_NOARGS, NULL},
    {"_bench_trs", sy_py_bench_trs, METH_VARARGS, NULL},
    {"_set_errors", sy_py_set_errors, METH_VARARGS, NULL},
    {"_set_log", sy_py_set_log, METH_VARARGS, NULL},
    {NULL, NULL, 0, NULL}};

static struct PyModuleDef module_def = {PyModuleDef_HEAD_INIT, "switchyard._switchyard",
                                        "The C half of switchyard (apps/python/src/sy_py_*.c).", -1, module_methods,
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
    sy_py_buffer_type = (PyTypeObject *)PyType_FromSpec(&sy_py_buffer_spec);
    sy_py_blobview_type = (PyTypeObject *)PyType_FromSpec(&sy_py_blobview_spec);
    sy_py_scene_type = (PyTypeObject *)PyType_FromSpec(&sy_py_scene_spec);
    PyObject *window_type = PyType_FromSpec(&sy_py_window_spec);
    PyObject *node_type = PyType_FromSpec(&sy_py_node_spec);
    if (!sy_py_buffer_type || !sy_py_scene_type || !window_type || !node_type || !sy_py_blobview_type ||
        PyModule_AddObjectRef(m, "_BlobView", (PyObject *)sy_py_blobview_type) || PyModule_AddObjectRef(m, "_Node", node_type) ||
        PyModule_AddObjectRef(m, "_Buffer", (PyObject *)sy_py_buffer_type) ||
        PyModule_AddObjectRef(m, "_Scene", (PyObject *)sy_py_scene_type) || PyModule_AddObjectRef(m, "_Window", window_type) ||
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
    PyObject *web_type = PyType_FromSpec(&sy_py_web_spec);
    if (!web_type || PyModule_AddObjectRef(m, "_Web", web_type)) {
        Py_XDECREF(web_type);
        Py_DECREF(m);
        return NULL;
    }
    Py_DECREF(web_type);
#endif
    return m;
}
