/* The filters, with the GIL released while they run. The library reports progress on the calling
 * thread (rsmooth_progress_cancel_fn), so each report takes the GIL back for a moment: it runs
 * Python's signal handlers (Ctrl-C raises KeyboardInterrupt there) and the caller's progress
 * callable, and either raising stops the filter with RSMOOTH_ERROR_CANCELLED. The library reads
 * only the call's own copies of the arrays (ext_array_own): what that Python code does to the
 * caller's arrays cannot reach it. */
#include "ext.h"

#include <string.h>

/* The calls on an OpenCL context this thread is inside: Python code that runs on it meanwhile
 * (the progress callable, a signal handler) is inside them too. */
static _Thread_local int contexts_held;

int ext_refuse_inside_context_call(const char *what) {
    if (contexts_held == 0)
        return 0;
    /* The same context would wait for ever for its own lock, with the GIL held (Ctrl-C could not
     * stop it); another one could wait for a thread that waits for this one. */
    PyErr_Format(PyExc_RuntimeError,
                 "rsmooth: %s from inside a progress callable, while a call on an OpenCL "
                 "context runs: that call holds its context until it returns, so this one could "
                 "wait for ever. Call it after that call returns (device=\"reference\" needs no "
                 "context)",
                 what);
    return -1;
}

static int report(void *user, double fraction) {
    call_state *c = user;
    PyEval_RestoreThread(c->thread);
    int stop = PyErr_CheckSignals() != 0;
    if (!stop && c->progress) {
        PyObject *r = PyObject_CallFunction(c->progress, "d", fraction);
        stop = r == NULL;
        Py_XDECREF(r);
    }
    c->thread = PyEval_SaveThread();
    return stop;
}

/* The normal-update stage's figures: where its cycles ran, in what precision, its parts. */
static PyObject *stage_dict(const rsmooth_report *r) {
    return Py_BuildValue("{s:O,s:i,s:i,s:K,s:K,s:d,s:d,s:d,s:d,s:d}", "on_device",
                         r->stage_on_device ? Py_True : Py_False, "float_bits", r->stage_float_bits,
                         "cycles", r->stage_cycles, "bytes_to_device",
                         (unsigned long long)r->stage_bytes_to_device, "bytes_from_device",
                         (unsigned long long)r->stage_bytes_from_device, "ms", r->ms_stage,
                         "ms_lists", r->ms_stage_lists, "ms_upload", r->ms_stage_upload,
                         "ms_cycles", r->ms_stage_cycles, "ms_download", r->ms_stage_download);
}

static PyObject *report_dict(const rsmooth_report *r) {
    PyObject *stage = stage_dict(r);
    if (!stage)
        return NULL;
    return Py_BuildValue(
        "{s:n,s:n,s:n,s:d,s:d,s:d,s:d,s:s,s:d,s:d,s:d,s:d,s:d,s:d,s:n,s:i,s:d,s:N,s:n,s:n,s:n,s:O}",
        "vertex_count", (Py_ssize_t)r->vertex_count, "triangle_count",
        (Py_ssize_t)r->triangle_count, "facet_count", (Py_ssize_t)r->facet_count,
        "mean_edge_length", r->mean_edge_length, "sigma_f", r->sigma_f, "sigma_g", r->sigma_g,
        "radius", r->radius, "device", r->device, "ms_setup", r->ms_setup, "ms_grid", r->ms_grid,
        "ms_mollify", r->ms_mollify, "ms_robust", r->ms_robust, "ms_download", r->ms_download,
        "ms_total", r->ms_total, "tiles", (Py_ssize_t)r->tiles, "discrepancy_iterations",
        r->discrepancy_iterations, "region_filter_share", r->region_filter_share, "stage", stage,
        "parts", (Py_ssize_t)r->parts, "outliers", (Py_ssize_t)r->outliers, "guarded_vertices",
        (Py_ssize_t)r->guarded_vertices, "stage_skipped", r->stage_skipped ? Py_True : Py_False);
}

/* Hands the library `progress` through p's progress_cancel and lets go of the GIL: the filter
 * call follows, then ext_finish_call. */
void ext_start_call(call_state *c, PyObject *progress, rsmooth_params *p, int on_context) {
    c->progress = progress == Py_None ? NULL : progress;
    c->on_context = on_context;
    contexts_held += on_context;
    p->progress_cancel = report;
    p->progress_user = c;
    c->thread = PyEval_SaveThread();
}

/* Takes the GIL back; the run's report, or the exception its status (or a pending one: a report
 * the library does not act on, the last at 1, may still have raised) calls for. */
PyObject *ext_finish_call(call_state *c, rsmooth_status st, const rsmooth_report *rep,
                          const rsmooth_error *err) {
    PyEval_RestoreThread(c->thread);
    contexts_held -= c->on_context;
    return st == RSMOOTH_OK && !PyErr_Occurred() ? report_dict(rep) : ext_raise(st, err);
}

/* _smooth(context, vertices, faces, out, confidence, params, progress) -> report dict.
 * context: a capsule from _context_create, or None for the reference path. vertices and out:
 * (n, 3) of one float type; faces (m, 3) uint32; confidence (n,) float32 or None. */
PyObject *ext_smooth(PyObject *self, PyObject *args, PyObject *kwargs) {
    (void)self;
    static char *keywords[] = {"context",    "vertices", "faces",    "out",
                               "confidence", "params",   "progress", NULL};
    PyObject *cobj, *vobj, *fobj, *oobj, *kobj, *pobj, *progress;
    if (!PyArg_ParseTupleAndKeywords(args, kwargs, "OOOOOOO", keywords, &cobj, &vobj, &fobj, &oobj,
                                     &kobj, &pobj, &progress))
        return NULL;
    rsmooth_context *ctx = NULL;
    if (cobj != Py_None && (!(ctx = ext_context_from(cobj)) ||
                            ext_refuse_inside_context_call("smooth() on an OpenCL context") != 0))
        return NULL;
    ext_array v, f, out, conf;
    ext_param_arrays held;
    memset(&f, 0, sizeof f);
    memset(&out, 0, sizeof out);
    memset(&conf, 0, sizeof conf);
    memset(&held, 0, sizeof held);
    PyObject *result = NULL;
    if (ext_array_get(vobj, "vertices", EXT_REAL, 3, 0, 0, &v) != 0)
        return NULL;
    rsmooth_params p;
    if (ext_array_get(fobj, "faces", EXT_UINT32, 3, 0, 0, &f) != 0 ||
        ext_array_get(oobj, "out", v.scalar == RSMOOTH_FLOAT32 ? EXT_FLOAT32 : EXT_FLOAT64, 3, 1, 0,
                      &out) != 0 ||
        ext_array_get(kobj, "confidence", EXT_FLOAT32, 0, 1, 1, &conf) != 0 ||
        ext_params_from_dict(pobj, v.rows, &p, &held) != 0)
        goto done;
    if (out.rows != v.rows || (conf.held && conf.rows != v.rows)) {
        PyErr_SetString(PyExc_ValueError, "outputs must have a row per vertex");
        goto done;
    }
    if (ext_array_own(&v, 0) != 0 || ext_array_own(&f, 0) != 0 || ext_array_own(&out, 1) != 0 ||
        ext_array_own(&conf, 1) != 0)
        goto done;
    call_state call;
    rsmooth_report rep;
    rsmooth_report_init(&rep); /* its struct_size says which fields this caller has */
    rsmooth_error err;
    rsmooth_status st;
    ext_start_call(&call, progress, &p, ctx != NULL);
    if (ctx)
        st = rsmooth_smooth(
            ctx, v.scalar, v.data, (size_t)v.rows, f.data, (size_t)f.rows, &p, out.data,
            &(rsmooth_outputs){
                .struct_size = sizeof(rsmooth_outputs), .confidence = conf.data, .report = &rep},
            &err);
    else
        st = rsmooth_smooth(
            NULL, v.scalar, v.data, (size_t)v.rows, f.data, (size_t)f.rows, &p, out.data,
            &(rsmooth_outputs){
                .struct_size = sizeof(rsmooth_outputs), .confidence = conf.data, .report = &rep},
            &err);
    result = ext_finish_call(&call, st, &rep, &err);
    if (result) {
        ext_array_publish(&out);
        ext_array_publish(&conf);
    }
done:
    ext_param_arrays_release(&held);
    ext_array_release(&conf);
    ext_array_release(&out);
    ext_array_release(&f);
    ext_array_release(&v);
    return result;
}

/* _smooth_points(points, normals, out, out_normals, confidence, params, progress) -> report.
 * points, normals, out, out_normals: (n, 3) of one float type; confidence (n,) float32 or None. */
PyObject *ext_smooth_points(PyObject *self, PyObject *args, PyObject *kwargs) {
    (void)self;
    static char *keywords[] = {"points",     "normals", "out",      "out_normals",
                               "confidence", "params",  "progress", NULL};
    PyObject *vobj, *nobj, *oobj, *onobj, *kobj, *pobj, *progress;
    if (!PyArg_ParseTupleAndKeywords(args, kwargs, "OOOOOOO", keywords, &vobj, &nobj, &oobj, &onobj,
                                     &kobj, &pobj, &progress))
        return NULL;
    ext_array v, n, out, out_n, conf;
    ext_param_arrays held;
    memset(&n, 0, sizeof n);
    memset(&out, 0, sizeof out);
    memset(&out_n, 0, sizeof out_n);
    memset(&conf, 0, sizeof conf);
    memset(&held, 0, sizeof held);
    PyObject *result = NULL;
    if (ext_array_get(vobj, "points", EXT_REAL, 3, 0, 0, &v) != 0)
        return NULL;
    ext_kind same = v.scalar == RSMOOTH_FLOAT32 ? EXT_FLOAT32 : EXT_FLOAT64;
    rsmooth_params p;
    if (ext_array_get(nobj, "normals", same, 3, 0, 0, &n) != 0 ||
        ext_array_get(oobj, "out", same, 3, 1, 0, &out) != 0 ||
        ext_array_get(onobj, "out_normals", same, 3, 1, 1, &out_n) != 0 ||
        ext_array_get(kobj, "confidence", EXT_FLOAT32, 0, 1, 1, &conf) != 0 ||
        ext_params_from_dict(pobj, v.rows, &p, &held) != 0)
        goto done;
    if (n.rows != v.rows || out.rows != v.rows || (out_n.held && out_n.rows != v.rows) ||
        (conf.held && conf.rows != v.rows)) {
        PyErr_SetString(PyExc_ValueError, "normals and outputs must have a row per point");
        goto done;
    }
    if (ext_array_own(&v, 0) != 0 || ext_array_own(&n, 0) != 0 || ext_array_own(&out, 1) != 0 ||
        ext_array_own(&out_n, 1) != 0 || ext_array_own(&conf, 1) != 0)
        goto done;
    call_state call;
    rsmooth_report rep;
    rsmooth_report_init(&rep); /* its struct_size says which fields this caller has */
    rsmooth_error err;
    ext_start_call(&call, progress, &p, 0);
    rsmooth_status st = rsmooth_smooth_points(
        NULL, v.scalar, v.data, n.data, (size_t)v.rows, &p, out.data, out_n.data,
        &(rsmooth_outputs){
            .struct_size = sizeof(rsmooth_outputs), .confidence = conf.data, .report = &rep},
        &err);
    result = ext_finish_call(&call, st, &rep, &err);
    if (result) {
        ext_array_publish(&out);
        ext_array_publish(&out_n);
        ext_array_publish(&conf);
    }
done:
    ext_param_arrays_release(&held);
    ext_array_release(&conf);
    ext_array_release(&out_n);
    ext_array_release(&out);
    ext_array_release(&n);
    ext_array_release(&v);
    return result;
}

/* _taubin(vertices, faces, out, lam, mu, iterations) -> None: rsmooth_smooth_taubin. lam in
 * (0, 1], mu in [-1, 0] (0: Laplacian), iterations in [0, EXT_MAX_ITERATIONS]. */
PyObject *ext_taubin(PyObject *self, PyObject *args, PyObject *kwargs) {
    (void)self;
    static char *keywords[] = {"vertices", "faces", "out", "lam", "mu", "iterations", NULL};
    PyObject *vobj, *fobj, *oobj, *lobj, *mobj, *iobj;
    double lam, mu;
    long iterations;
    if (!PyArg_ParseTupleAndKeywords(args, kwargs, "OOOOOO", keywords, &vobj, &fobj, &oobj, &lobj,
                                     &mobj, &iobj) ||
        ext_real_arg(lobj, "lam", &lam) != 0 || ext_real_arg(mobj, "mu", &mu) != 0 ||
        ext_whole_arg(iobj, "iterations", 0, EXT_MAX_ITERATIONS, &iterations) != 0)
        return NULL;
    if (!(lam > 0 && lam <= 1)) {
        PyErr_Format(PyExc_ValueError, "lam must be in (0, 1] (got %R)", lobj);
        return NULL;
    }
    if (!(mu >= -1 && mu <= 0)) {
        PyErr_Format(PyExc_ValueError, "mu must be in [-1, 0], 0 for Laplacian (got %R)", mobj);
        return NULL;
    }
    ext_array v, f, out;
    memset(&f, 0, sizeof f);
    memset(&out, 0, sizeof out);
    PyObject *result = NULL;
    if (ext_array_get(vobj, "vertices", EXT_REAL, 3, 0, 0, &v) != 0)
        return NULL;
    if (ext_array_get(fobj, "faces", EXT_UINT32, 3, 0, 0, &f) != 0 ||
        ext_array_get(oobj, "out", v.scalar == RSMOOTH_FLOAT32 ? EXT_FLOAT32 : EXT_FLOAT64, 3, 1, 0,
                      &out) != 0)
        goto done;
    if (out.rows != v.rows) {
        PyErr_SetString(PyExc_ValueError, "out must have a row per vertex");
        goto done;
    }
    /* no progress callable here, but other threads run while the GIL is released */
    if (ext_array_own(&v, 0) != 0 || ext_array_own(&f, 0) != 0 || ext_array_own(&out, 1) != 0)
        goto done;
    rsmooth_error err;
    rsmooth_status st;
    Py_BEGIN_ALLOW_THREADS st =
        rsmooth_smooth_taubin(v.scalar, v.data, (size_t)v.rows, f.data, (size_t)f.rows, lam, mu,
                              (unsigned)iterations, out.data, &err);
    Py_END_ALLOW_THREADS if (st == RSMOOTH_OK) {
        ext_array_publish(&out);
        Py_INCREF(Py_None);
        result = Py_None;
    }
    else {
        ext_raise(st, &err);
    }
done:
    ext_array_release(&out);
    ext_array_release(&f);
    ext_array_release(&v);
    return result;
}
