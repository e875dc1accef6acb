/* sy_py_buffer.c — _Buffer and _BlobView: library memory exported to NumPy through the buffer
 * protocol (part of switchyard._switchyard: sy_py.h). */
#include "sy_py.h"

/* ------------------------------------------------------------------ _Buffer */
/* A float32 array of 1 to 3 dimensions owning malloc()ed memory, exported through the buffer
 * protocol (numpy.asarray keeps the _Buffer alive as the array's base). */
typedef struct {
    PyObject_HEAD
    float *data;
    int ndim;
    Py_ssize_t shape[3], strides[3];
} BufferObject;

PyTypeObject *sy_py_buffer_type;

static void buffer_dealloc(PyObject *self)
{
    BufferObject *b = (BufferObject *)self;
    free(b->data);
    sy_py_object_free(self);
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

SY_PY_TYPE_SPEC(sy_py_buffer_spec, "_Buffer", BufferObject, Py_TPFLAGS_DEFAULT, {Py_tp_dealloc, buffer_dealloc},
                {Py_bf_getbuffer, buffer_get},
                {Py_tp_doc, "float32 pixels owned by the library's allocation (numpy.asarray views it without a copy)"});

/* Takes ownership of data (free()d with the object, or here on failure): rows x cols x channels
 * (channels 1: a 2-D array). */
PyObject *sy_py_buffer_take(float *data, uint32_t rows, uint32_t cols, uint32_t channels)
{
    BufferObject *b = (BufferObject *)PyType_GenericNew(sy_py_buffer_type, NULL, NULL);
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

PyTypeObject *sy_py_blobview_type;

static void blobview_dealloc(PyObject *self)
{
    sy_blob_release(((BlobViewObject *)self)->blob);
    sy_py_object_free(self);
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

SY_PY_TYPE_SPEC(sy_py_blobview_spec, "_BlobView", BlobViewObject, Py_TPFLAGS_DEFAULT, {Py_tp_dealloc, blobview_dealloc},
                {Py_bf_getbuffer, blobview_get},
                {Py_tp_doc, "a read-only view of a mesh's blob (numpy.asarray views it without a copy)"});

/* A view of blob as rows of cols 4-byte values (code 'f' or 'I'; cols 1: flat); None for NULL. */
static PyObject *blobview_of(sy_blob *blob, char code, Py_ssize_t cols)
{
    if (!blob) Py_RETURN_NONE;
    BlobViewObject *b = (BlobViewObject *)PyType_GenericNew(sy_py_blobview_type, NULL, NULL);
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

/* _get(SY_TYPE_MESH, id): {"name": str or None, "primitives": [dict of views, material id, topology]} */
PyObject *sy_py_mesh_fields(sy_scene *sc, unsigned int id)
{
    const sy_mesh_data *d = sy_mesh_get(sc, (sy_mesh){id});
    if (!d) return sy_py_stale("mesh", id);
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
