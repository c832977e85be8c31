/* The rsmooth extension module (rsmooth._rsmooth): shared declarations. The module is built on
 * the stable ABI (Py_LIMITED_API, set by python/CMakeLists.txt) and reads arrays through the
 * buffer protocol, so it needs no numpy headers and one wheel serves every CPython from 3.11.
 * The Python layer (python/rsmooth/__init__.py) converts dtypes, strides and index types and
 * validates faces before it calls in; the functions here still check every buffer they get. */
#ifndef RSMOOTH_EXT_H
#define RSMOOTH_EXT_H

#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include "rsmooth.h"

/* rsmooth.DeviceError (a RuntimeError): the OpenCL device failed or is missing. */
extern PyObject *ext_device_error;

/* Raises the exception a failed call's status calls for, with the library's message; returns
 * NULL. A pending Python exception (the progress callback raised, Ctrl-C) wins. */
PyObject *ext_raise(rsmooth_status status, const rsmooth_error *error);

/* ---- arrays (buffers.c) ---------------------------------------------------------------------- */

typedef enum ext_kind {
    EXT_UINT8,   /* 'B' */
    EXT_FLOAT32, /* 'f' */
    EXT_FLOAT64, /* 'd' */
    EXT_REAL,    /* either of the two (which one goes to ext_array.scalar) */
    EXT_UINT32   /* 'I' (or 'L' where that is 4 bytes) */
} ext_kind;

/* A C-contiguous array of `rows` x `cols` items held through the buffer protocol. */
typedef struct ext_array {
    Py_buffer view;
    int held;
    Py_ssize_t rows;
    rsmooth_scalar scalar; /* EXT_REAL arrays */
    void *data;            /* what the library gets: the view's items, or `copy` */
    void *copy;            /* the call's own copy (ext_array_own), or NULL */
} ext_array;

/* Acquires `obj` as a C-contiguous array of `cols` columns (cols 0: one dimension) of `kind`,
 * writable if asked. None gives an empty array when `optional`. Returns 0, or -1 with TypeError
 * or ValueError naming `name`. */
int ext_array_get(PyObject *obj, const char *name, ext_kind kind, Py_ssize_t cols, int writable,
                  int optional, ext_array *a);

/* Gives the library (a->data) a copy of the items that only this call can reach, and lets go
 * of the view unless `keep` (an output: ext_array_publish writes the result back). While the
 * library runs, Python code runs too (the progress callable, other threads: the GIL is
 * released), and it may rewrite, resize or free the caller's array; the library reads indices
 * and positions again long after checking them, so it must never see memory Python can change.
 * Costs one memcpy of the array, small beside the filter. Returns 0, or -1 with MemoryError. */
int ext_array_own(ext_array *a, int keep);

/* Copies the call's result (a->copy) into the caller's array, the view kept by
 * ext_array_own(a, 1). */
void ext_array_publish(ext_array *a);

/* Releases the buffer (if held) and the copy. */
void ext_array_release(ext_array *a);

/* ---- module functions ------------------------------------------------------------------------ */

PyObject *ext_smooth(PyObject *self, PyObject *args, PyObject *kwargs);        /* filter.c */
PyObject *ext_smooth_points(PyObject *self, PyObject *args, PyObject *kwargs); /* filter.c */
PyObject *ext_taubin(PyObject *self, PyObject *args, PyObject *kwargs);        /* filter.c */
PyObject *ext_default_params(PyObject *self, PyObject *args);                  /* params.c */
PyObject *ext_params_auto(PyObject *self, PyObject *args);                     /* params.c */
PyObject *ext_estimate_noise(PyObject *self, PyObject *args);                  /* measure.c */
PyObject *ext_mean_edge_length(PyObject *self, PyObject *args);                /* measure.c */
PyObject *ext_point_spacing(PyObject *self, PyObject *args);                   /* measure.c */
PyObject *ext_compare(PyObject *self, PyObject *args);                         /* measure.c */
PyObject *ext_devices(PyObject *self, PyObject *args);                         /* context.c */
PyObject *ext_context_create(PyObject *self, PyObject *args);                  /* context.c */
PyObject *ext_context_info(PyObject *self, PyObject *args);                    /* context.c */

PyObject *ext_context_from_queue(PyObject *self, PyObject *args);          /* context.c */
PyObject *ext_smooth_cl(PyObject *self, PyObject *args, PyObject *kwargs); /* context.c */

/* A filter call in progress (filter.c): the GIL let go, progress reports taking it back. */
typedef struct call_state {
    PyThreadState *thread; /* saved while the library runs */
    PyObject *progress;    /* callable(fraction) or NULL */
    int on_context;        /* the call holds an OpenCL context's lock until it returns */
} call_state;

/* Hands the library `progress` through p's progress_cancel and lets go of the GIL: the filter
 * call follows, then ext_finish_call, which takes the GIL back and returns the report dict or
 * raises what the status calls for. */
void ext_start_call(call_state *c, PyObject *progress, rsmooth_params *p, int on_context);
PyObject *ext_finish_call(call_state *c, rsmooth_status st, const rsmooth_report *rep,
                          const rsmooth_error *err);

/* The rsmooth_context a capsule from ext_context_create holds; NULL with TypeError if `obj` is
 * not one. */
rsmooth_context *ext_context_from(PyObject *obj);

/* Returns 0, or -1 with RuntimeError naming `what` when this thread is inside a call on an
 * OpenCL context (its progress callable is running): that call holds its context's lock until
 * it returns, and anything taking a context's lock now could wait for ever (filter.c). */
int ext_refuse_inside_context_call(const char *what);

/* ---- parameters (params.c) ------------------------------------------------------------------- */

/* The most Laplacian or Taubin steps: the command's bound (--iterations, host/cli_options.c). */
#define EXT_MAX_ITERATIONS 1000000

/* A whole number in [min, max] (an int or anything with __index__, not a bool): 0 and *out, or
 * -1 with TypeError or ValueError naming `name` and the range. */
int ext_whole_arg(PyObject *value, const char *name, long min, long max, long *out);

/* A real number (a float, an int, anything with __float__, not a bool): 0 and *out, or -1 with
 * TypeError or ValueError naming `name`. The range is the library's to check (NaN included). */
int ext_real_arg(PyObject *value, const char *name, double *out);

/* The arrays a params dict may hold ("colors": (n, 3) float32, "move_mask": (n,) uint8), held
 * while the call runs. */
typedef struct ext_param_arrays {
    ext_array colors, mask;
    PyObject *model; /* the learned model's bytes (a reference held for the call) */
} ext_param_arrays;

/* Fills `p` from a dict holding rsmooth_params' fields by name (every key must be one; missing
 * keys keep rsmooth_params_init's values). Returns 0, or -1 with ValueError/TypeError. `held`
 * receives the arrays (release them with ext_param_arrays_release, also after a failure). */
int ext_params_from_dict(PyObject *dict, Py_ssize_t vertex_count, rsmooth_params *p,
                         ext_param_arrays *held);
void ext_param_arrays_release(ext_param_arrays *held);

/* The dict of `p`'s fields (colors and callbacks left out). */
PyObject *ext_params_to_dict(const rsmooth_params *p);

#endif
