/* sy_py_node.c — _Node (the C base of switchyard.Node) and the field tables of materials, lights
 * and cameras (part of switchyard._switchyard: sy_py.h). */
#include "sy_py.h"

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
    if (!impl || !PyObject_TypeCheck(impl, sy_py_scene_type)) {
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
    sy_py_object_free(self);
}

/* A 3- or 4-number value: a tuple or list read in place, anything else through float_seq. */
static int node_values(PyObject *v, const char *what, float *out, Py_ssize_t n)
{
    PyObject *(*item)(PyObject *, Py_ssize_t) = NULL;
    Py_ssize_t size = -1;
    if (PyTuple_Check(v)) item = PyTuple_GetItem, size = PyTuple_Size(v);
    else if (PyList_Check(v)) item = PyList_GetItem, size = PyList_Size(v);
    if (!item || size != n) return sy_py_float_seq(v, what, out, n);
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
    sy_scene *sc = sy_py_scene_use(n->impl);
    if (!sc) return NULL;
    const sy_node_data *d = sy_node_get(sc, (sy_node){n->id});
    if (!d) return sy_py_stale("node", n->id);
    return which == 0 ? sy_py_tuple_of(d->transform.translation, 3)
                      : which == 1 ? sy_py_tuple_of(d->transform.rotation, 4) : sy_py_tuple_of(d->transform.scale, 3);
}

static int node_set_trs(PyObject *self, PyObject *v, void *which_p)
{
    NodeObject *n = (NodeObject *)self;
    int which = (int)(intptr_t)which_p;
    if (!v) {
        PyErr_Format(PyExc_AttributeError, "Node.%s cannot be deleted", g_trs_names[which]);
        return -1;
    }
    sy_scene *sc = sy_py_scene_use(n->impl);
    if (!sc) return -1;
    float val[4];
    if (node_values(v, g_trs_names[which], val, which == 1 ? 4 : 3)) return -1;
    sy_node node = {n->id};
    const sy_node_data *d = sy_node_get(sc, node);
    if (!d) {
        sy_py_stale("node", n->id);
        return -1;
    }
    const float *t = which == 0 ? val : d->transform.translation, *r = which == 1 ? val : d->transform.rotation,
                *s = which == 2 ? val : d->transform.scale;
    sy_error err = {0};
    sy_result res = sy_node_set_trs(sc, node, t, r, s, &err);
    if (res != SY_OK) {
        sy_py_raise(res, &err);
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

SY_PY_TYPE_SPEC(sy_py_node_spec, "_Node", NodeObject, Py_TPFLAGS_DEFAULT | Py_TPFLAGS_BASETYPE | Py_TPFLAGS_HAVE_GC,
                {Py_tp_dealloc, node_dealloc},
                {Py_tp_new, node_new},
                {Py_tp_traverse, node_traverse},
                {Py_tp_clear, node_clear},
                {Py_tp_getset, node_getset},
                {Py_tp_doc, "the C base of switchyard.Node (scene, id, the TRS fields)"});

/* _bench_trs(scene_c, id, n) -> (wall seconds, thread CPU seconds): n calls of sy_node_set_trs from C (translation x = i), the
 * C side of the call-overhead comparison (apps/python/bench_overhead.py); not a public name. */
PyObject *sy_py_bench_trs(PyObject *self, PyObject *args)
{
    (void)self;
    PyObject *impl;
    unsigned long id, count;
    if (!PyArg_ParseTuple(args, "O!kk", sy_py_scene_type, &impl, &id, &count)) return NULL;
    sy_scene *sc = sy_py_scene_use((SceneObject *)impl);
    if (!sc) return NULL;
    sy_node node = {(uint32_t)id};
    const sy_node_data *d = sy_node_get(sc, node);
    if (!d) return sy_py_stale("node", (unsigned)id);
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
        if (res != SY_OK) return sy_py_raise(res, &err);
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

/* The data of a material, light or camera. */
typedef union object_data {
    sy_material_data material;
    sy_light_data light;
    sy_camera_data camera;
} object_data;

/* An object that a call names: its scene, type, id and a copy of its data */
typedef struct object_ref {
    sy_scene *sc;
    int type;
    unsigned int id;
    object_data d;
} object_ref;

/* The field table of the material, light or camera that args (type, id) name, with its scene,
 * type, id and a copy of its current values in *o; NULL with an exception for bad arguments, a
 * closed scene, another type or a stale id. Nodes and meshes (o->type) have no table: NULL, no
 * exception, o->sc set. */
static const field_desc *object_fields(PyObject *self, PyObject *args, object_ref *o)
{
    o->sc = NULL;
    if (!PyArg_ParseTuple(args, "iI", &o->type, &o->id)) return NULL;
    sy_scene *sc = sy_py_scene_use((SceneObject *)self);
    if (!sc) return NULL;
    if (o->type == SY_TYPE_NODE || o->type == SY_TYPE_MESH) return o->sc = sc, NULL;
    o->sc = sc;
    int type = o->type;
    unsigned int id = o->id;
    object_data *data = &o->d;
    const void *cur = NULL;
    size_t size = 0;
    const field_desc *t = NULL;
    switch (type) {
    case SY_TYPE_MATERIAL: cur = id ? sy_material_get(sc, (sy_material){id}) : NULL, size = sizeof data->material, t = material_fields; break;
    case SY_TYPE_LIGHT: cur = sy_light_get(sc, (sy_light){id}), size = sizeof data->light, t = light_fields; break;
    case SY_TYPE_CAMERA: cur = sy_camera_get(sc, (sy_camera){id}), size = sizeof data->camera, t = camera_fields; break;
    default: return PyErr_Format(PyExc_ValueError, "object type %d has no field table", type), NULL;
    }
    if (!cur) return sy_py_stale(sy_object_type_name((sy_object_type)type), id), NULL;
    memcpy(data, cur, size);
    return t;
}

/* _get(type, id) -> dict of the fields (and "name"): every scene object's fields read one way
 * (switchyard's objects call it with their type) */
PyObject *sy_py_scene_get_fields(PyObject *self, PyObject *args)
{
    object_ref o;
    const field_desc *t = object_fields(self, args, &o);
    if (!t && !PyErr_Occurred() && o.type == SY_TYPE_NODE) return sy_py_node_fields(o.sc, o.id);
    if (!t && !PyErr_Occurred() && o.type == SY_TYPE_MESH) return sy_py_mesh_fields(o.sc, o.id);
    if (!t) return NULL;
    const object_data d = o.d;
    PyObject *dict = Py_BuildValue("{s:z}", "name", *(char *const *)&d); /* every struct starts with its name */
    for (; dict && t->name; ++t) {
        const char *p = (const char *)&d + t->offset;
        PyObject *v = t->kind == 'u' ? PyLong_FromUnsignedLong(*(const uint32_t *)p)
                      : t->n == 1    ? PyFloat_FromDouble(*(const float *)p)
                                     : sy_py_tuple_of((const float *)p, t->n);
        if (!v || PyDict_SetItemString(dict, t->name, v)) Py_CLEAR(dict);
        Py_XDECREF(v);
    }
    return dict;
}

/* _set(type, id, **fields): the named fields changed, the rest kept, through the type's setter
 * (which validates: a NaN roughness or a zfar before znear raises InvalidArgumentError) */
PyObject *sy_py_scene_set_fields(PyObject *self, PyObject *args, PyObject *kw)
{
    object_ref o;
    const field_desc *table = object_fields(self, args, &o);
    if (!table && !PyErr_Occurred())
        return PyErr_Format(PyExc_ValueError, "%s fields are set through their own calls", sy_object_type_name((sy_object_type)o.type));
    if (!table) return NULL;
    object_data d = o.d;
    sy_scene *sc = o.sc;
    int type = o.type;
    unsigned int id = o.id;
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
        } else if (sy_py_float_seq(value, t->name, (float *)p, t->n)) {
            return NULL;
        }
    }
    sy_error err = {0};
    sy_result r = type == SY_TYPE_MATERIAL ? sy_material_set(sc, (sy_material){id}, &d.material, &err)
                  : type == SY_TYPE_LIGHT  ? sy_light_set(sc, (sy_light){id}, &d.light, &err)
                                           : sy_camera_set(sc, (sy_camera){id}, &d.camera, &err);
    return sy_py_none_or_raise(r, &err);
}

/* _info() -> dict(root, camera, background, counts) */
PyObject *sy_py_scene_info(PyObject *self, PyObject *unused)
{
    (void)unused;
    SceneObject *s = (SceneObject *)self;
    sy_scene *sc = sy_py_scene_use(s);
    if (!sc) return NULL;
    return Py_BuildValue("{s:I,s:I,s:I,s:I,s:I,s:I,s:I,s:I}", "root", s->ld.root.id, "camera", s->ld.camera.id,
                         "background", s->ld.background.id, "nodes", sy_scene_count(sc, SY_TYPE_NODE), "meshes",
                         sy_scene_count(sc, SY_TYPE_MESH), "materials", sy_scene_count(sc, SY_TYPE_MATERIAL), "lights",
                         sy_scene_count(sc, SY_TYPE_LIGHT), "cameras", sy_scene_count(sc, SY_TYPE_CAMERA));
}

PyObject *sy_py_scene_set_camera(PyObject *self, PyObject *args)
{
    unsigned int id;
    SceneObject *s = (SceneObject *)self;
    sy_scene *sc = sy_py_scene_id_arg(self, args, &id);
    if (!sc) return NULL;
    const sy_node_data *d = id ? sy_node_get(sc, (sy_node){id}) : NULL;
    if (id && !d) return sy_py_stale("node", id);
    if (d && !d->camera.id)
        return sy_py_raise(SY_ERR_INVALID_ARGUMENT,
                        &(sy_error){SY_ERR_INVALID_ARGUMENT, "camera: the node carries no camera (Node.camera)"});
    s->ld.camera.id = id;
    Py_RETURN_NONE;
}

PyObject *sy_py_scene_commit(PyObject *self, PyObject *unused)
{
    (void)unused;
    sy_scene *sc = sy_py_scene_use((SceneObject *)self);
    if (!sc) return NULL;
    sy_error err = {0};
    sy_result r = sy_scene_commit(sc, NULL, &err);
    return sy_py_none_or_raise(r, &err);
}
