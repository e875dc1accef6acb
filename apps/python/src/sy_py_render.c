/* sy_py_render.c — rendering a _Scene: one window and viewport as sy render composes it, passes,
 * AOVs, the cluster (part of switchyard._switchyard: sy_py.h). */
#include "sy_py.h"

/* ------------------------------------------------------------------ rendering */

/* Renders job->win into job->out (created here). Called with the GIL held; releases it for the
 * library calls. Returns 0, or -1 with a Python exception (a library error, the progress callable's
 * error, KeyboardInterrupt). Passes as `sy render` takes them: about a quarter of a second each. */
int sy_py_render_run(render_job *job)
{
    sy_error err = {0};
    sy_result r;
    uint32_t w = 0, h = 0;
    sy_window_size(job->win, &w, &h);
    PyThreadState *ts = PyEval_SaveThread();
    r = sy_layer_create(w, h, &job->out, &err);
    PyEval_RestoreThread(ts);
    if (r != SY_OK) return sy_py_raise(r, &err), -1;
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
        if (r != SY_OK) return sy_py_raise(r, &err), -1;
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
PyObject *sy_py_render_result(render_job *job, int want_aovs, sy_context *aov_ctx, uint64_t samples)
{
    uint32_t w = job->out.width, h = job->out.height;
    PyObject *img = sy_py_buffer_take(job->out.rgba, h, w, 4);
    job->out.rgba = NULL;
    PyObject *aovs = NULL;
    if (img && want_aovs) {
        aovs = PyDict_New();
        PyObject *depth = aovs ? sy_py_buffer_take(job->out.depth, h, w, 1) : NULL;
        job->out.depth = NULL;
        if (!depth || PyDict_SetItemString(aovs, "depth", depth)) Py_CLEAR(aovs);
        Py_XDECREF(depth);
        if (aovs && aov_ctx) {
            sy_aovs a = {0};
            sy_error err = {0};
            sy_result r = sy_context_aovs(aov_ctx, &a, &err);
            if (r != SY_OK) {
                Py_CLEAR(aovs);
                sy_py_raise(r, &err);
            }
            for (uint32_t k = 0; aovs && k < a.count; ++k) {
                if (!strcmp(a.planes[k].name, "depth")) continue; /* the layer's depth is the window's */
                PyObject *p = sy_py_buffer_take(a.planes[k].data, a.height, a.width, a.planes[k].channels);
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
int sy_py_check_backend(const char *backend, const char *params, sy_params *pp, const sy_mediator_class **cls,
                         uint32_t *caps)
{
    sy_error err = {0};
    *cls = sy_mediator_require(backend, &err);
    if (!*cls) return sy_py_raise(err.code, &err), -1;
    sy_result r = sy_params_parse(params, pp, &err);
    if (r == SY_OK) r = sy_mediator_class_check_params(*cls, pp, &err);
    if (r != SY_OK) return sy_py_raise(r, &err), -1;
    *caps = sy_mediator_class_caps(*cls, pp);
    return 0;
}

/* servers= (the cluster, docs/CLUSTER.md): the back-end runs on `sy serve` servers through a
 * cluster mediator class, set up exactly as `sy render --cluster` sets it up (apps/sy/sy_cluster_cli.c:
 * a comma-separated URL list or a configuration file, --cluster-mode, --secret-file or
 * $SY_CLUSTER_SECRET). A class is registered per distinct (servers, mode, secret file) and reused:
 * the registry holds classes for the process's lifetime and refuses a name twice. Fills
 * cluster_name and cluster_params; 0, or -1 with an exception. */
int sy_py_cluster_setup(const char *servers, const char *mode, const char *secret_file, const char *backend,
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
            return sy_py_raise(SY_ERR_LIMIT, &(sy_error){SY_ERR_LIMIT, "servers: at most 16 distinct cluster "
                                                                    "configurations in one process"}), -1;
        char name[32];
        snprintf(name, sizeof name, "cluster-python-%u", k);
        r = sy_cluster_cli_register(&o, name, &cmode, &nservers, &err);
        if (r != SY_OK) return sy_py_raise(r, &err), -1;
        snprintf(known[k].key, sizeof known[k].key, "%s", key);
        known[k].mode = cmode;
        known_count++;
    }
    snprintf(cluster_name, name_len, "cluster-python-%u", k);
    r = sy_cluster_cli_params(&o, backend, known[k].mode, params, cluster_params, params_len, &err);
    if (r != SY_OK) return sy_py_raise(r, &err), -1;
    (void)spp_per_request;
    return 0;
#else
    (void)servers, (void)mode, (void)secret_file, (void)backend, (void)params, (void)cluster_name, (void)name_len;
    (void)cluster_params, (void)params_len, (void)spp_per_request;
    return sy_py_raise(SY_ERR_UNSUPPORTED, &(sy_error){SY_ERR_UNSUPPORTED, "servers: this build has no cluster "
                                                                        "(SY_WITH_CLUSTER off)"}), -1;
#endif
}

/* _render(backend=None, width=0, height=0, spp=0, seed=0, params=None, aovs=False, progress=None)
 * -> (rgba, aovs or None, samples): one viewport over the whole image with the scene's root,
 * camera and background, the back-end's parameters, as `sy render` composes a mono render. */
PyObject *sy_py_scene_render(PyObject *self, PyObject *args, PyObject *kw)
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
    sy_scene *sc = sy_py_scene_use(s);
    if (!sc) return NULL;
    PyObject *argerr = sy_py_errors[SY_ERR_INVALID_ARGUMENT] ? sy_py_errors[SY_ERR_INVALID_ARGUMENT] : PyExc_ValueError;
    if (!backend) backend = sy_mediator_default_name();
    if (width > 16384 || height > 16384)
        return PyErr_Format(argerr, "image size %ux%u: at most 16384 a side", width, height);
    if (progress != Py_None && !PyCallable_Check(progress)) return PyErr_Format(PyExc_TypeError, "progress must be callable");
    sy_params pp;
    const sy_mediator_class *cls;
    uint32_t caps;
    if (sy_py_check_backend(backend, params, &pp, &cls, &caps)) return NULL; /* the back-end the servers run */
    /* servers=: the main viewport's back-end becomes a cluster class over `backend`, as sy render --cluster */
    char cluster_name[32], cluster_params[SY_PY_PARAMS_MAX];
    uint64_t spp_per_request = 0;
    const char *shown = backend;
    if (servers) {
        bool remote_progressive = (caps & SY_CAP_PROGRESSIVE) != 0;
        if (sy_py_cluster_setup(servers, cluster_mode, secret_file, backend, params, cluster_name, sizeof cluster_name,
                          cluster_params, sizeof cluster_params, &spp_per_request))
            return NULL;
        backend = cluster_name;
        params = cluster_params;
        if (sy_py_check_backend(backend, params, &pp, &cls, &caps)) return NULL;
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
    if (r != SY_OK) return sy_py_raise(r, &err);
    render_job job = {.scene = sc, .seed = seed, .spp = progressive ? spp : 0, .once_samples = (uint32_t)spp_per_request,
                      .progress = progress == Py_None ? NULL : progress};
    sy_viewport_desc d = {.root = s->ld.root, .camera = s->ld.camera, .background = s->ld.background,
                          .backend = backend, .params = params, .composite = SY_COMPOSITE_REPLACE};
    if (r == SY_OK) r = sy_context_pool_create(&job.pool, &err);
    if (r == SY_OK) r = sy_window_create(w, h, &job.win, &err);
    if (r == SY_OK) r = sy_window_add_viewport(job.win, &d, NULL, &err);
    PyObject *result = NULL;
    if (r != SY_OK) {
        sy_py_raise(r, &err);
    } else {
        s->busy = 1;
        int rc = sy_py_render_run(&job);
        s->busy = 0;
        sy_context *ctx = NULL;
        sy_mediator_stats st = {0};
        if (rc == 0 && sy_context_pool_get(job.pool, sc, backend, &pp, s->ld.root.id, &ctx, &err) == SY_OK)
            sy_context_stats(ctx, &st);
        if (rc == 0)
            result = sy_py_render_result(&job, want_aovs, (caps & SY_CAP_AOVS) ? ctx : NULL, st.samples);
    }
    sy_layer_destroy(&job.out);
    sy_window_destroy(job.win);
    sy_context_pool_destroy(job.pool);
    return result;
}

/* _set_time(seconds, clip=None): the scene's animation clock (load's at= / clip=) */
