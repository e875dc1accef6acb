/* sy_py_scene.c — _Scene: loading, arrays in, objects by id, the scene clock, and its method table
 * (part of switchyard._switchyard: sy_py.h). */
#include "sy_py.h"

/* ------------------------------------------------------------------ _Scene */

PyTypeObject *sy_py_scene_type;

sy_scene *sy_py_scene_use(SceneObject *s)
{
    if (s->busy) {
        PyErr_SetString(PyExc_RuntimeError, "switchyard: the scene is in use by another thread (a render, or "
                                            "serve() until stopped); give each thread its own Scene or wait");
        return NULL;
    }
    if (!s->ld.scene) {
        PyErr_SetString(sy_py_errors[SY_ERR_INVALID_OPERATION] ? sy_py_errors[SY_ERR_INVALID_OPERATION] : PyExc_RuntimeError,
                        "switchyard: the scene is closed");
        return NULL;
    }
    return s->ld.scene;
}

sy_scene *sy_py_scene_id_arg(PyObject *self, PyObject *args, unsigned int *id)
{
    return PyArg_ParseTuple(args, "I", id) ? sy_py_scene_use((SceneObject *)self) : NULL;
}

static void scene_dealloc(PyObject *self)
{
    SceneObject *s = (SceneObject *)self;
    if (s->ld.scene) sy_cli_loaded_free(&s->ld);
    sy_py_object_free(self);
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
        return sy_py_raise(r, &err);
    }
    return (PyObject *)s;
}

static PyObject *scene_close(PyObject *self, PyObject *unused)
{
    (void)unused;
    SceneObject *s = (SceneObject *)self;
    if (s->busy) return PyErr_Format(PyExc_RuntimeError, "switchyard: the scene is in use by another thread");
    if (s->windows)
        return sy_py_raise(SY_ERR_INVALID_OPERATION,
                        &(sy_error){SY_ERR_INVALID_OPERATION, "switchyard: the scene is still shown by a Window; close "
                                                              "the Window first"});
    if (s->ld.scene) sy_cli_loaded_free(&s->ld);
    Py_RETURN_NONE;
}

/* The world options of load() (sy's --env, --env-color, --env-intensity, --background; the flags
 * are set by the caller) into *w; *env_bytes keeps the map's path alive. -1 with an exception. */
int sy_py_float_seq(PyObject *o, const char *what, float *out, Py_ssize_t n);
static int finite_floats(PyObject *o, const char *what, float *out, Py_ssize_t min_n, Py_ssize_t max_n, Py_ssize_t *n)
{
    PyObject *argerr = sy_py_errors[SY_ERR_INVALID_ARGUMENT] ? sy_py_errors[SY_ERR_INVALID_ARGUMENT] : PyExc_ValueError;
    Py_ssize_t len = PySequence_Check(o) ? PySequence_Size(o) : -1;
    if (len < 0) PyErr_Clear();
    *n = len >= min_n && len <= max_n ? len : max_n;
    if (sy_py_float_seq(o, what, out, *n)) return -1;
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
    PyObject *argerr = sy_py_errors[SY_ERR_INVALID_ARGUMENT] ? sy_py_errors[SY_ERR_INVALID_ARGUMENT] : PyExc_ValueError;
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
        PyErr_Format(sy_py_errors[SY_ERR_INVALID_ARGUMENT] ? sy_py_errors[SY_ERR_INVALID_ARGUMENT] : PyExc_ValueError,
                     "at: %R is not a finite number of seconds", at);
        return -1;
    }
    return 0;
}

/* The scene's time (sy render --at / --clip): the clip named, or without one the clip sy render
 * plays by default (sy_cli_default_clip: a glTF's first of clips that drive the same objects, else
 * every clip), evaluated at seconds, committed. A scene without animations is left as it is (a
 * note on the log) unless a clip is named (NotFoundError). 0, or -1 with an exception. */
static int scene_time(loaded *ld, const char *clip, double seconds)
{
    sy_error err = {0};
    sy_scene *sc = ld->scene;
    sy_animation a = sy_cli_default_clip(ld);
    if (!sy_scene_count(sc, SY_TYPE_ANIMATION)) {
        if (clip) {
            sy_error_set(&err, SY_ERR_NOT_FOUND, "clip %s: the scene has no animations", clip);
            sy_py_raise(err.code, &err);
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
        sy_py_raise(r, &err);
        return -1;
    }
    return 0;
}

/* load(path, camera=None, strict=False, allow_paths=(), max_scene_mb=0, variant=None) -> _Scene.
 * sy_cli_load reads its options from one global (sy_cli_load_opts): loads take turns on g_load_lock
 * while the GIL is released. */
static pthread_mutex_t g_load_lock = PTHREAD_MUTEX_INITIALIZER;

PyObject *sy_py_load(PyObject *self, PyObject *args, PyObject *kw)
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
    SceneObject *s = (SceneObject *)PyType_GenericNew(sy_py_scene_type, NULL, NULL);
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
        sy_py_raise(r, &err);
        goto done;
    }
    if ((at != Py_None || clip) && scene_time(&s->ld, clip, seconds)) {
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
int sy_py_get_array(PyObject *obj, const char *what, char code, Py_ssize_t cols, int max_ndim, Py_buffer *view,
                     Py_ssize_t *count)
{
    PyObject *argerr = sy_py_errors[SY_ERR_INVALID_ARGUMENT] ? sy_py_errors[SY_ERR_INVALID_ARGUMENT] : PyExc_ValueError;
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
    sy_scene *sc = sy_py_scene_use(s);
    if (!sc) return NULL;
    Py_buffer pv, iv, nv;
    Py_ssize_t nvert = 0, nidx = 0, nnrm = 0;
    int have_idx = idx_obj != Py_None, have_nrm = nrm_obj != Py_None;
    PyObject *argerr = sy_py_errors[SY_ERR_INVALID_ARGUMENT] ? sy_py_errors[SY_ERR_INVALID_ARGUMENT] : PyExc_ValueError;
    if (sy_py_get_array(pos_obj, "positions", 'f', 3, 2, &pv, &nvert)) return NULL;
    if (have_idx && sy_py_get_array(idx_obj, "indices", 'I', 3, 2, &iv, &nidx)) {
        PyBuffer_Release(&pv);
        return NULL;
    }
    if (have_nrm && sy_py_get_array(nrm_obj, "normals", 'f', 3, 2, &nv, &nnrm)) {
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
        sy_py_raise(r, &err);
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
int sy_py_float_seq(PyObject *o, const char *what, float *out, Py_ssize_t n)
{
    PyObject *argerr = sy_py_errors[SY_ERR_INVALID_ARGUMENT] ? sy_py_errors[SY_ERR_INVALID_ARGUMENT] : PyExc_ValueError;
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

PyObject *sy_py_tuple_of(const float *v, int n)
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
    sy_scene *sc = sy_py_scene_use((SceneObject *)self);
    if (!sc) return NULL;
    sy_error err = {0};
    uint32_t id = 0;
    sy_result r = type < 0 || type >= SY_TYPE_COUNT ? sy_error_set(&err, SY_ERR_INVALID_ARGUMENT, "object type %d", type)
                                                    : sy_object_create(sc, (sy_object_type)type, name, &id, &err);
    return r == SY_OK ? PyLong_FromUnsignedLong(id) : sy_py_raise(r, &err);
}

/* _destroy(type, id) */
static PyObject *scene_destroy_object(PyObject *self, PyObject *args)
{
    int type;
    unsigned int id;
    if (!PyArg_ParseTuple(args, "iI", &type, &id)) return NULL;
    sy_scene *sc = sy_py_scene_use((SceneObject *)self);
    if (!sc) return NULL;
    sy_error err = {0};
    sy_result r = type < 0 || type >= SY_TYPE_COUNT ? sy_error_set(&err, SY_ERR_INVALID_ARGUMENT, "object type %d", type)
                                                    : sy_object_destroy(sc, (sy_object_type)type, id, &err);
    return sy_py_none_or_raise(r, &err);
}

/* _ids(type) -> list of live ids; _valid(type, id) -> bool */
static PyObject *scene_ids(PyObject *self, PyObject *args)
{
    int type;
    if (!PyArg_ParseTuple(args, "i", &type)) return NULL;
    sy_scene *sc = sy_py_scene_use((SceneObject *)self);
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

PyObject *sy_py_stale(const char *what, unsigned id)
{
    sy_error e = {0};
    sy_error_set(&e, SY_ERR_INVALID_HANDLE, "%s %u: stale or foreign handle (destroyed, or of another scene)", what, id);
    return sy_py_raise(e.code, &e);
}

/* _get(SY_TYPE_NODE, id): dict of the node's fields */
PyObject *sy_py_node_fields(sy_scene *sc, unsigned int id)
{
    const sy_node_data *d = sy_node_get(sc, (sy_node){id});
    if (!d) return sy_py_stale("node", id);
    uint32_t nc = 0;
    const uint32_t *ch = sy_node_children(d, &nc);
    PyObject *children = PyList_New(nc);
    for (uint32_t i = 0; children && i < nc; ++i) PyList_SetItem(children, i, PyLong_FromUnsignedLong(ch[i]));
    const sy_transform *t = &d->transform;
    return Py_BuildValue("{s:z,s:N,s:N,s:N,s:N,s:N,s:I,s:I,s:I,s:I,s:N}", "name", d->name, "matrix",
                         sy_py_tuple_of(t->matrix.m, 16), "translation", sy_py_tuple_of(t->translation, 3), "rotation",
                         sy_py_tuple_of(t->rotation, 4), "scale", sy_py_tuple_of(t->scale, 3), "trs",
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
    sy_scene *sc = sy_py_scene_use((SceneObject *)self);
    if (!sc) return NULL;
    sy_node n = {id};
    const sy_node_data *d = sy_node_get(sc, n);
    if (!d) return sy_py_stale("node", id);
    sy_error err = {0};
    sy_result r = SY_OK;
    if (m != Py_None) {
        sy_mat4 mm;
        if (sy_py_float_seq(m, "matrix", mm.m, 16)) return NULL;
        r = sy_node_set_matrix(sc, n, &mm, &err);
    }
    if (r == SY_OK && (t != Py_None || rot != Py_None || sc3 != Py_None)) {
        float tt[3], rr[4], ss[3];
        memcpy(tt, d->transform.translation, sizeof tt);
        memcpy(rr, d->transform.rotation, sizeof rr);
        memcpy(ss, d->transform.scale, sizeof ss);
        if ((t != Py_None && sy_py_float_seq(t, "translation", tt, 3)) || (rot != Py_None && sy_py_float_seq(rot, "rotation", rr, 4)) ||
            (sc3 != Py_None && sy_py_float_seq(sc3, "scale", ss, 3)))
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
    return sy_py_none_or_raise(r, &err);
}

static PyObject *scene_set_time(PyObject *self, PyObject *args)
{
    PyObject *at;
    const char *clip = NULL;
    double seconds;
    if (!PyArg_ParseTuple(args, "O|z", &at, &clip) || time_from_python(at, &seconds)) return NULL;
    SceneObject *s = (SceneObject *)self;
    if (!sy_py_scene_use(s) || scene_time(&s->ld, clip, seconds)) return NULL;
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
    {"_node_set", (PyCFunction)(void (*)(void))scene_node_set, METH_VARARGS | METH_KEYWORDS, NULL},
    {"_get", sy_py_scene_get_fields, METH_VARARGS, NULL},
    {"_set", (PyCFunction)(void (*)(void))sy_py_scene_set_fields, METH_VARARGS | METH_KEYWORDS, NULL},
    {"_info", sy_py_scene_info, METH_NOARGS, NULL},
    {"_set_camera", sy_py_scene_set_camera, METH_VARARGS, NULL},
    {"commit", sy_py_scene_commit, METH_NOARGS, "Seals the changes since the last commit (render commits too)."},
    {"_render", (PyCFunction)(void (*)(void))sy_py_scene_render, METH_VARARGS | METH_KEYWORDS, NULL},
    {NULL, NULL, 0, NULL}};

SY_PY_TYPE_SPEC(sy_py_scene_spec, "_Scene", SceneObject, Py_TPFLAGS_DEFAULT | Py_TPFLAGS_BASETYPE,
                {Py_tp_dealloc, scene_dealloc},
                {Py_tp_new, scene_new},
                {Py_tp_methods, scene_methods},
                {Py_tp_doc, "the library's sy_scene (switchyard.Scene wraps it)"});
