/* Measures of a mesh: its noise, its mean edge length, a point set's spacing, and the error of a
 * result against its ground truth (rsmooth_compare). Each reads its own copies of the arrays
 * (ext_array_own): other threads run while the GIL is released. */
#include "ext.h"

#include <string.h>

typedef rsmooth_status (*mesh_measure)(rsmooth_scalar, const void *, size_t, const uint32_t *,
                                       size_t, double *, rsmooth_error *);

static PyObject *measure_mesh(PyObject *args, mesh_measure measure) {
    PyObject *vobj, *fobj;
    if (!PyArg_ParseTuple(args, "OO", &vobj, &fobj))
        return NULL;
    ext_array v, f;
    if (ext_array_get(vobj, "vertices", EXT_REAL, 3, 0, 0, &v) != 0)
        return NULL;
    if (ext_array_get(fobj, "faces", EXT_UINT32, 3, 0, 0, &f) != 0) {
        ext_array_release(&v);
        return NULL;
    }
    double value = 0;
    rsmooth_error err;
    rsmooth_status st = RSMOOTH_ERROR_OUT_OF_MEMORY;
    if (ext_array_own(&v, 0) == 0 && ext_array_own(&f, 0) == 0) {
        Py_BEGIN_ALLOW_THREADS st =
            measure(v.scalar, v.data, (size_t)v.rows, f.data, (size_t)f.rows, &value, &err);
        Py_END_ALLOW_THREADS
    }
    ext_array_release(&f);
    ext_array_release(&v);
    return st == RSMOOTH_OK ? PyFloat_FromDouble(value) : ext_raise(st, &err);
}

/* _estimate_noise(vertices, faces) -> float, in mean edge lengths. */
PyObject *ext_estimate_noise(PyObject *self, PyObject *args) {
    (void)self;
    return measure_mesh(args, rsmooth_estimate_noise);
}

/* _mean_edge_length(vertices, faces) -> float, in the mesh's units. */
PyObject *ext_mean_edge_length(PyObject *self, PyObject *args) {
    (void)self;
    return measure_mesh(args, rsmooth_mean_edge_length);
}

/* _point_spacing(points) -> float. */
PyObject *ext_point_spacing(PyObject *self, PyObject *args) {
    (void)self;
    PyObject *vobj;
    if (!PyArg_ParseTuple(args, "O", &vobj))
        return NULL;
    ext_array v;
    if (ext_array_get(vobj, "points", EXT_REAL, 3, 0, 0, &v) != 0)
        return NULL;
    double value = 0;
    rsmooth_error err;
    rsmooth_status st = RSMOOTH_ERROR_OUT_OF_MEMORY;
    if (ext_array_own(&v, 0) == 0) {
        Py_BEGIN_ALLOW_THREADS st =
            rsmooth_point_spacing(v.scalar, v.data, (size_t)v.rows, &value, &err);
        Py_END_ALLOW_THREADS
    }
    ext_array_release(&v);
    return st == RSMOOTH_OK ? PyFloat_FromDouble(value) : ext_raise(st, &err);
}

/* _compare(result, truth, faces) -> dict of rsmooth_metrics' figures. */
PyObject *ext_compare(PyObject *self, PyObject *args) {
    (void)self;
    PyObject *robj, *tobj, *fobj;
    if (!PyArg_ParseTuple(args, "OOO", &robj, &tobj, &fobj))
        return NULL;
    ext_array r, t, f;
    memset(&t, 0, sizeof t);
    memset(&f, 0, sizeof f);
    PyObject *result = NULL;
    if (ext_array_get(robj, "result", EXT_REAL, 3, 0, 0, &r) != 0)
        return NULL;
    if (ext_array_get(tobj, "truth", r.scalar == RSMOOTH_FLOAT32 ? EXT_FLOAT32 : EXT_FLOAT64, 3, 0,
                      0, &t) != 0 ||
        ext_array_get(fobj, "faces", EXT_UINT32, 3, 0, 0, &f) != 0)
        goto done;
    if (t.rows != r.rows) {
        PyErr_Format(PyExc_ValueError, "result has %zd vertices, truth %zd", r.rows, t.rows);
        goto done;
    }
    if (ext_array_own(&r, 0) != 0 || ext_array_own(&t, 0) != 0 || ext_array_own(&f, 0) != 0)
        goto done;
    rsmooth_metrics m;
    rsmooth_error err;
    rsmooth_status st;
    Py_BEGIN_ALLOW_THREADS st =
        rsmooth_compare(r.scalar, r.data, t.data, (size_t)r.rows, f.data, (size_t)f.rows, &m, &err);
    Py_END_ALLOW_THREADS if (st != RSMOOTH_OK) ext_raise(st, &err);
    else result = Py_BuildValue("{s:d,s:d,s:d,s:d,s:n,s:d,s:d,s:n,s:n}", "theta", m.theta, "ev",
                                m.ev, "rms_v", m.rms_v, "hausdorff", m.hausdorff, "theta_count",
                                (Py_ssize_t)m.theta_count, "mean_edge", m.mean_edge, "bbox_diag",
                                m.bbox_diag, "vertex_count", (Py_ssize_t)m.vertex_count,
                                "triangle_count", (Py_ssize_t)m.triangle_count);
done:
    ext_array_release(&f);
    ext_array_release(&t);
    ext_array_release(&r);
    return result;
}
