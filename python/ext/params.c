/* rsmooth_params to and from a dict of its fields by name: the Python layer speaks in keywords,
 * the library in the struct. The defaults come from the library (rsmooth_params_init and
 * rsmooth_params_init_best), never from a copy here. */
#include "ext.h"

#include <stddef.h>
#include <string.h>

typedef enum field_type { FIELD_DOUBLE, FIELD_INT } field_type;

typedef struct field {
    const char *name;
    size_t offset;
    field_type type;
    int min, max; /* FIELD_INT's range */
} field;

#define DOUBLE_FIELD(f)                                                                            \
    { #f, offsetof(rsmooth_params, f), FIELD_DOUBLE, 0, 0 }
#define INT_FIELD(f, min, max)                                                                     \
    { #f, offsetof(rsmooth_params, f), FIELD_INT, min, max }

/* The ranges of the int fields are the command's (host/cli_options.c) and the library's
 * (RS_MAX_ROUNDS 100 and RS_MAX_UPDATES 1000, lib/core/params.c): checked here too, so that a
 * Python int beyond a C int is refused by name and range instead of wrapping. The doubles'
 * ranges (NaN and infinities included) are the library's to check. */
static const field fields[] = {
    DOUBLE_FIELD(sigma_f),
    DOUBLE_FIELD(sigma_g),
    INT_FIELD(absolute, 0, 1),
    DOUBLE_FIELD(cutoff),
    DOUBLE_FIELD(mollify_cutoff),
    INT_FIELD(mollify, 0, 1),
    INT_FIELD(predictor, RSMOOTH_PREDICT_PROJECTION, RSMOOTH_PREDICT_CENTROID),
    INT_FIELD(normal_filter, RSMOOTH_NORMALS_MOLLIFY, RSMOOTH_NORMALS_BILATERAL),
    DOUBLE_FIELD(normal_sigma_s),
    DOUBLE_FIELD(normal_sigma_n),
    INT_FIELD(normal_iterations, 1, 100),
    INT_FIELD(influence, RSMOOTH_INFLUENCE_GAUSSIAN, RSMOOTH_INFLUENCE_HUBER),
    INT_FIELD(passes, 0, 100), /* 0: the stage alone, or (without it) nothing */
    DOUBLE_FIELD(pass_confidence),
    DOUBLE_FIELD(sigma_c),
    INT_FIELD(vertex_updates, 0, 1000),
    DOUBLE_FIELD(guided_sigma_s),
    DOUBLE_FIELD(guided_sigma_n),
    INT_FIELD(guided_rounds, 1, 100),
    INT_FIELD(stage_repeats, 1, 1000),
    DOUBLE_FIELD(discrepancy_level),
    DOUBLE_FIELD(guided_radius),
    DOUBLE_FIELD(discrepancy_gain),
    INT_FIELD(guard, 0, 1),
    INT_FIELD(stage_normals, RSMOOTH_STAGE_NORMALS_GUIDED, RSMOOTH_STAGE_NORMALS_LEARNED),
};
#define FIELD_COUNT (sizeof fields / sizeof fields[0])

int ext_whole_arg(PyObject *value, const char *name, long min, long max, long *out) {
    int overflow = 0;
    long v = -1;
    int whole = !PyBool_Check(value) && PyIndex_Check(value); /* (a float has no __index__) */
    if (whole) {
        v = PyLong_AsLongAndOverflow(value, &overflow);
        if (v == -1 && !overflow && PyErr_Occurred()) {
            if (!PyErr_ExceptionMatches(PyExc_TypeError))
                return -1;
            PyErr_Clear(); /* an __index__ that refuses: numpy's bool */
            whole = 0;
        }
    }
    if (!whole) {
        PyErr_Format(PyExc_TypeError, "%s must be a whole number in [%ld, %ld] (got %R)", name, min,
                     max, value);
        return -1;
    }
    if (overflow) { /* (no repr: past 4300 digits Python refuses to write one) */
        PyErr_Format(PyExc_ValueError, "%s must be in [%ld, %ld] (got a number %s)", name, min, max,
                     overflow > 0 ? "beyond a C long" : "below a C long");
        return -1;
    }
    if (v < min || v > max) {
        PyErr_Format(PyExc_ValueError, "%s must be in [%ld, %ld] (got %ld)", name, min, max, v);
        return -1;
    }
    *out = v;
    return 0;
}

int ext_real_arg(PyObject *value, const char *name, double *out) {
    if (!PyBool_Check(value)) {
        double v = PyFloat_AsDouble(value);
        if (!(v == -1.0 && PyErr_Occurred())) {
            *out = v;
            return 0;
        }
        if (PyErr_ExceptionMatches(PyExc_OverflowError)) { /* an int past 1.8e308 */
            PyErr_Clear();
            PyErr_Format(PyExc_ValueError, "%s: the number given is beyond a double's range", name);
            return -1;
        }
        if (!PyErr_ExceptionMatches(PyExc_TypeError))
            return -1;
        PyErr_Clear();
    }
    PyErr_Format(PyExc_TypeError, "%s must be a number (got %R)", name, value);
    return -1;
}

static int set_field(rsmooth_params *p, const field *f, PyObject *value) {
    char *at = (char *)p + f->offset;
    if (f->type == FIELD_DOUBLE) {
        double v;
        if (ext_real_arg(value, f->name, &v) != 0)
            return -1;
        memcpy(at, &v, sizeof v);
        return 0;
    }
    long v;
    if (ext_whole_arg(value, f->name, f->min, f->max, &v) != 0)
        return -1;
    int iv = (int)v;
    memcpy(at, &iv, sizeof iv);
    return 0;
}

/* Holds the array `value` under `name` in *a and returns its buffer; NULL with an exception set
 * on a wrong type or shape (or for None: the field's default, no exception). */
static const void *hold(PyObject *value, const char *name, ext_kind kind, Py_ssize_t cols,
                        Py_ssize_t rows, ext_array *a) {
    ext_array_release(a);
    if (ext_array_get(value, name, kind, cols, 0, 1, a) != 0 || !a->held)
        return NULL;
    if (a->rows != rows) {
        PyErr_Format(PyExc_ValueError, "%s: %zd rows for %zd vertices", name, a->rows, rows);
        return NULL;
    }
    return ext_array_own(a, 0) == 0 ? a->data : NULL;
}

int ext_params_from_dict(PyObject *dict, Py_ssize_t vertex_count, rsmooth_params *p,
                         ext_param_arrays *held) {
    rsmooth_params_init(p);
    memset(held, 0, sizeof *held);
    if (dict == Py_None)
        return 0;
    if (!PyDict_Check(dict)) {
        PyErr_SetString(PyExc_TypeError, "params: expected a dict");
        return -1;
    }
    PyObject *key, *value;
    Py_ssize_t pos = 0;
    while (PyDict_Next(dict, &pos, &key, &value)) {
        const char *name = PyUnicode_Check(key) ? PyUnicode_AsUTF8AndSize(key, NULL) : NULL;
        if (!name) {
            if (!PyErr_Occurred())
                PyErr_SetString(PyExc_TypeError, "params: keys must be strings");
            return -1;
        }
        if (strcmp(name, "colors") == 0) {
            p->colors = hold(value, name, EXT_FLOAT32, 3, vertex_count, &held->colors);
            if (PyErr_Occurred())
                return -1;
            continue;
        }
        if (strcmp(name, "model") == 0) { /* bytes: immutable, so a reference is enough */
            if (!PyBytes_Check(value)) {
                PyErr_Format(PyExc_TypeError, "model: expected bytes (got %R)", value);
                return -1;
            }
            char *bytes;
            Py_ssize_t size;
            if (PyBytes_AsStringAndSize(value, &bytes, &size) != 0) /* (the limited API's) */
                return -1;
            Py_XDECREF(held->model);
            Py_INCREF(value);
            held->model = value;
            p->model = bytes;
            p->model_size = (size_t)size;
            continue;
        }
        if (strcmp(name, "move_mask") == 0) {
            p->move_mask = hold(value, name, EXT_UINT8, 0, vertex_count, &held->mask);
            if (PyErr_Occurred())
                return -1;
            continue;
        }
        size_t i = 0;
        while (i < FIELD_COUNT && strcmp(fields[i].name, name) != 0)
            i++;
        if (i == FIELD_COUNT) {
            PyErr_Format(PyExc_ValueError, "params: unknown field '%s'", name);
            return -1;
        }
        if (set_field(p, fields + i, value) != 0)
            return -1;
    }
    return 0;
}

void ext_param_arrays_release(ext_param_arrays *held) {
    ext_array_release(&held->colors);
    ext_array_release(&held->mask);
    Py_XDECREF(held->model);
    held->model = NULL;
}

PyObject *ext_params_to_dict(const rsmooth_params *p) {
    PyObject *dict = PyDict_New();
    for (size_t i = 0; dict && i < FIELD_COUNT; i++) {
        const char *at = (const char *)p + fields[i].offset;
        PyObject *value;
        if (fields[i].type == FIELD_DOUBLE) {
            double v;
            memcpy(&v, at, sizeof v);
            value = PyFloat_FromDouble(v);
        } else {
            int v;
            memcpy(&v, at, sizeof v);
            value = PyLong_FromLong(v);
        }
        if (!value || PyDict_SetItemString(dict, fields[i].name, value) != 0) {
            Py_XDECREF(value);
            Py_DECREF(dict);
            return NULL;
        }
        Py_DECREF(value);
    }
    return dict;
}

/* _default_params(best) -> dict: rsmooth_params_init's fields, or rsmooth_params_init_best's. */
PyObject *ext_default_params(PyObject *self, PyObject *args) {
    (void)self;
    int best = 0;
    if (!PyArg_ParseTuple(args, "p", &best))
        return NULL;
    rsmooth_params p;
    if (best)
        rsmooth_params_init_best(&p);
    else
        rsmooth_params_init(&p);
    return ext_params_to_dict(&p);
}

/* The noise report as a dict: level, kind ("none": nothing to remove, "gaussian" or
 * "impulsive"), impulsive_fraction, tangential_level (NaN when not measured), mean_edge_length,
 * preset, reason, correlated_level, correlation_length, shape_correlation, parts, outliers. */
static PyObject *noise_report_to_dict(const rsmooth_noise_report *r) {
    const char *kind = r->kind == RSMOOTH_NOISE_GAUSSIAN    ? "gaussian"
                       : r->kind == RSMOOTH_NOISE_IMPULSIVE ? "impulsive"
                                                            : "none";
    return Py_BuildValue("{sd,ss,sd,sd,sd,ss,ss,sd,sd,sd,sn,sn}", "level", r->level, "kind", kind,
                         "impulsive_fraction", r->impulsive_fraction, "tangential_level",
                         r->tangential_level, "mean_edge_length", r->mean_edge_length, "preset",
                         r->preset, "reason", r->reason, "correlated_level", r->correlated_level,
                         "correlation_length", r->correlation_length, "shape_correlation",
                         r->shape_correlation, "parts", (Py_ssize_t)r->parts, "outliers",
                         (Py_ssize_t)r->outliers);
}

/* _params_auto(vertices, faces, params) -> (params, report): rsmooth_params_auto's rule
 * for the mesh, starting from `params` (whose normal_filter and vertex_updates pick the rule),
 * and what it read and chose (noise_report_to_dict). */
PyObject *ext_params_auto(PyObject *self, PyObject *args) {
    (void)self;
    PyObject *vobj, *fobj, *pobj;
    if (!PyArg_ParseTuple(args, "OOO", &vobj, &fobj, &pobj))
        return NULL;
    ext_array v, f;
    ext_param_arrays held;
    if (ext_array_get(vobj, "vertices", EXT_REAL, 3, 0, 0, &v) != 0)
        return NULL;
    if (ext_array_get(fobj, "faces", EXT_UINT32, 3, 0, 0, &f) != 0) {
        ext_array_release(&v);
        return NULL;
    }
    PyObject *result = NULL;
    rsmooth_params p;
    if (ext_params_from_dict(pobj, v.rows, &p, &held) == 0 && ext_array_own(&v, 0) == 0 &&
        ext_array_own(&f, 0) == 0) {
        rsmooth_noise_report report;
        report.struct_size = sizeof report;
        rsmooth_error err;
        rsmooth_status st;
        Py_BEGIN_ALLOW_THREADS st = rsmooth_params_auto(v.scalar, v.data, (size_t)v.rows, f.data,
                                                        (size_t)f.rows, &p, &report, &err);
        Py_END_ALLOW_THREADS if (st != RSMOOTH_OK) {
            ext_raise(st, &err);
        }
        else {
            PyObject *dict = ext_params_to_dict(&p);
            PyObject *said = dict ? noise_report_to_dict(&report) : NULL;
            if (said)
                result = Py_BuildValue("(NN)", dict, said);
            else
                Py_XDECREF(dict);
        }
    }
    ext_param_arrays_release(&held);
    ext_array_release(&f);
    ext_array_release(&v);
    return result;
}
