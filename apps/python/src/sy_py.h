/* sy_py.h — the C half of the Python package switchyard (apps/python; docs/PYTHON.md): the
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
 * One file per object type (sy_py_module.c, sy_py_buffer.c (_Buffer, _BlobView), sy_py_scene.c,
 * sy_py_node.c, sy_py_render.c, sy_py_web.c, sy_py_window.c); this internal header holds what
 * they share. Nothing here is exported from the module but PyInit__switchyard (the target's
 * visibility is hidden).
 *
 * Ownership: a _Scene owns its sy_scene; a _Window owns its sy_window and pool and holds a strong
 * reference to the one _Scene it renders (a scene refuses close() while a window holds it, so no
 * cached context outlives its scene). Mesh data from a buffer-protocol object is copied once,
 * into the library's blob. Thread-safety: loads and renders run without the GIL; a _Scene (and a
 * _Window) in use by one thread refuses calls from another with RuntimeError instead of racing. */
#ifndef SY_PY_H
#define SY_PY_H

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

#define SY_PY_MAX_CLUSTERS 16
#define SY_PY_PARAMS_MAX 1400 /* a back-end's parameter text (a cluster class's names every server) */

/* _Scene (sy_py_scene.c): a loaded or empty scene; the other files take it as their scene */
typedef struct {
    PyObject_HEAD
    loaded ld;       /* the scene, its root, camera, background and what the loader said */
    int busy;        /* a load or render of this scene runs without the GIL */
    int windows;     /* _Window objects holding it (close() waits for them) */
} SceneObject;

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

/* A heap type's spec (spec, a PyType_Spec of the module: switchyard._switchyard.NAME, instances of
 * OBJ, FLAGS) and its slots, the {Py_..., value} pairs that follow (the end marker added). */
#define SY_PY_TYPE_SPEC(spec, name, obj, flags, ...)                                                        \
    static PyType_Slot spec##_slots[] = {__VA_ARGS__, {0, NULL}};                                           \
    PyType_Spec spec = {"switchyard._switchyard." name, sizeof(obj), 0, flags, spec##_slots}

/* sy_py_module.c */
/* sy_result -> the switchyard.Error subclass (None result: NULL with the exception set) */
PyObject *sy_py_raise(sy_result r, const sy_error *e);
/* SY_OK -> None (a new reference), else sy_py_raise */
PyObject *sy_py_none_or_raise(sy_result r, const sy_error *e);
PyObject *sy_py_set_errors(PyObject *self, PyObject *args);
PyObject *sy_py_set_log(PyObject *self, PyObject *args);
/* the end of every dealloc of a heap type: free the object, release the type */
void sy_py_object_free(PyObject *self);
extern PyObject *sy_py_errors[SY_ERR_SYSTEM + 1];

/* sy_py_buffer.c */
PyObject *sy_py_buffer_take(float *data, uint32_t rows, uint32_t cols, uint32_t channels);
/* the fields of mesh id as _get gives them; NULL with an exception for a stale id */
PyObject *sy_py_mesh_fields(sy_scene *sc, unsigned int id);
extern PyTypeObject *sy_py_buffer_type;
extern PyType_Spec sy_py_buffer_spec;
extern PyTypeObject *sy_py_blobview_type;
extern PyType_Spec sy_py_blobview_spec;

/* sy_py_scene.c */
sy_scene *sy_py_scene_use(SceneObject *s);
/* The scene of a call whose one argument is an object id (*id); NULL with an exception for bad
 * arguments or a closed scene */
sy_scene *sy_py_scene_id_arg(PyObject *self, PyObject *args, unsigned int *id);
PyObject *sy_py_load(PyObject *self, PyObject *args, PyObject *kw);
int sy_py_get_array(PyObject *obj, const char *what, char code, Py_ssize_t cols, int max_ndim, Py_buffer *view,
                    Py_ssize_t *count);
int sy_py_float_seq(PyObject *o, const char *what, float *out, Py_ssize_t n);
PyObject *sy_py_tuple_of(const float *v, int n);
PyObject *sy_py_stale(const char *what, unsigned id);
/* the fields of node id as _get gives them; NULL with an exception for a stale id */
PyObject *sy_py_node_fields(sy_scene *sc, unsigned int id);
extern PyTypeObject *sy_py_scene_type;
extern PyType_Spec sy_py_scene_spec;

/* sy_py_node.c */
PyObject *sy_py_bench_trs(PyObject *self, PyObject *args);
PyObject *sy_py_scene_get_fields(PyObject *self, PyObject *args);
PyObject *sy_py_scene_set_fields(PyObject *self, PyObject *args, PyObject *kw);
PyObject *sy_py_scene_info(PyObject *self, PyObject *unused);
PyObject *sy_py_scene_set_camera(PyObject *self, PyObject *args);
PyObject *sy_py_scene_commit(PyObject *self, PyObject *unused);
extern PyType_Spec sy_py_node_spec;

/* sy_py_render.c */
int sy_py_render_run(render_job *job);
PyObject *sy_py_render_result(render_job *job, int want_aovs, sy_context *aov_ctx, uint64_t samples);
int sy_py_check_backend(const char *backend, const char *params, sy_params *pp, const sy_mediator_class **cls,
                        uint32_t *caps);
int sy_py_cluster_setup(const char *servers, const char *mode, const char *secret_file, const char *backend,
                        const char *params, char *cluster_name, size_t name_len, char *cluster_params,
                        size_t params_len, uint64_t *spp_per_request);
PyObject *sy_py_scene_render(PyObject *self, PyObject *args, PyObject *kw);

/* sy_py_web.c */
#ifdef SY_PY_HAVE_WEB
extern PyType_Spec sy_py_web_spec;
#endif

/* sy_py_window.c */
extern PyType_Spec sy_py_window_spec;

#endif
