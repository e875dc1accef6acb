/* sy_py_web.c — _Web: the web view (apps/web/sy_web.h) served by a thread of its own (part of
 * switchyard._switchyard: sy_py.h). */
#include "sy_py.h"

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
        sy_py_raise(r, &w->err);
        return -1;
    }
    return 0;
}

static void web_dealloc(PyObject *self)
{
    WebObject *w = (WebObject *)self;
    web_stop(w, 0);
    Py_CLEAR(w->scene);
    sy_py_object_free(self);
}

/* _Web(scene, backend=None, listen=None, token=None, max_width=0, max_height=0, quality=0,
 * filter=None, threshold=0, budget_ms=0, clip=None, bookmarks=None): serving starts at once; clip
 * (a name or an index, as sy web --clip: sy_animation_find) is the clip the timeline plays (None:
 * as sy web without --clip, sy_cli_default_clip); bookmarks: the saved views' file (sy web
 * --bookmarks; None: the server keeps the pages' views while it runs) */
static PyObject *web_new(PyTypeObject *type, PyObject *args, PyObject *kw)
{
    static char *kwlist[] = {"scene", "backend", "listen", "token", "max_width", "max_height", "quality", "filter",
                             "threshold", "budget_ms", "clip", "bookmarks", NULL};
    PyObject *scene;
    const char *backend = NULL, *listen = NULL, *token = NULL, *filter = NULL, *clip = NULL, *bookmarks = NULL;
    unsigned int mw = 0, mh = 0;
    int quality = 0;
    float threshold = 0.0f;
    double budget = 0.0;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "O!|zzzIIizfdzz", kwlist, sy_py_scene_type, &scene, &backend, &listen, &token,
                                     &mw, &mh, &quality, &filter, &threshold, &budget, &clip, &bookmarks))
        return NULL;
    SceneObject *s = (SceneObject *)scene;
    sy_scene *sc = sy_py_scene_use(s);
    if (!sc) return NULL;
    sy_error err = {0};
    sy_result r = sy_scene_commit(sc, NULL, &err); /* the server never commits: what Python built is sealed now */
    if (r != SY_OK) return sy_py_raise(r, &err);
    if (!s->ld.camera.id)
        return sy_py_raise(SY_ERR_INVALID_ARGUMENT,
                        &(sy_error){SY_ERR_INVALID_ARGUMENT, "serve: the scene has no camera (add one: scene.camera = "
                                                             "scene.add_camera(...))"});
    sy_animation played = sy_cli_default_clip(&s->ld); /* as sy web: --clip, else its default */
    if (clip && !sy_scene_count(sc, SY_TYPE_ANIMATION))
        return sy_py_raise(sy_error_set(&err, SY_ERR_NOT_FOUND, "serve: clip %s: the scene has no animations", clip), &err);
    if (clip && (r = sy_animation_find(sc, clip, &played, &err)) != SY_OK) {
        sy_error_prefix(&err, "serve: clip %s", clip);
        return sy_py_raise(r, &err);
    }
    WebObject *w = (WebObject *)PyType_GenericNew(type, NULL, NULL);
    if (!w) return NULL;
    sy_web_desc d = {.scene = sc, .root = s->ld.root, .camera = s->ld.camera, .background = s->ld.background,
                     .backend = backend, .listen = listen, .token = token, .max_width = mw, .max_height = mh,
                     .quality = quality, .filter = filter, .threshold = threshold, .budget_ms = budget, .clip = played,
                     .bookmarks = bookmarks};
    s->busy = 1; /* from here the scene belongs to the server (released in web_stop) */
    Py_BEGIN_ALLOW_THREADS
    r = sy_web_create(&d, &w->web, &err);
    Py_END_ALLOW_THREADS
    if (r != SY_OK) {
        s->busy = 0;
        Py_DECREF(w);
        return sy_py_raise(r, &err);
    }
    w->scene = (SceneObject *)Py_NewRef(scene);
    if (sy_web_thread_start(w->web, &w->thread, &err) != SY_OK) {
        Py_DECREF(w); /* destroys the server, the scene is free again */
        return sy_py_raise(SY_ERR_SYSTEM, &(sy_error){SY_ERR_SYSTEM, "serve: could not start the server's thread"});
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
SY_PY_TYPE_SPEC(sy_py_web_spec, "_Web", WebObject, Py_TPFLAGS_DEFAULT,
                {Py_tp_dealloc, web_dealloc},
                {Py_tp_new, web_new},
                {Py_tp_methods, web_methods},
                {Py_tp_doc, "the web view of a _Scene (sy_web, served by a thread of its own)"});
#endif
