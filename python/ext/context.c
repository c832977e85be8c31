/* OpenCL devices and contexts. A context lives in a capsule that destroys it when the last
 * reference goes; the library serialises calls on one context, so threads may share it. */
#include "ext.h"

#ifndef CL_TARGET_OPENCL_VERSION
#define CL_TARGET_OPENCL_VERSION 120 /* as the library's sources; only its types are used */
#endif
#include "rsmooth_cl.h"

#include <stdlib.h>
#include <string.h>

static const char capsule_name[] = "rsmooth.context";

static void destroy_capsule(PyObject *capsule) {
    rsmooth_context_destroy(PyCapsule_GetPointer(capsule, capsule_name));
}

rsmooth_context *ext_context_from(PyObject *obj) {
    if (!PyCapsule_IsValid(obj, capsule_name)) {
        PyErr_SetString(PyExc_TypeError, "context: expected an rsmooth context capsule");
        return NULL;
    }
    return PyCapsule_GetPointer(obj, capsule_name);
}

/* A created context in a capsule that destroys it, or the creation's error raised. */
static PyObject *capsule_for(rsmooth_status st, rsmooth_context *ctx, const rsmooth_error *err) {
    if (st != RSMOOTH_OK)
        return ext_raise(st, err);
    PyObject *capsule = PyCapsule_New(ctx, capsule_name, destroy_capsule);
    if (!capsule)
        rsmooth_context_destroy(ctx);
    return capsule;
}

/* _context_create(device or None) -> capsule. Builds the kernels (seconds on a cold cache) with
 * the GIL released. */
PyObject *ext_context_create(PyObject *self, PyObject *args) {
    (void)self;
    const char *device = NULL;
    if (!PyArg_ParseTuple(args, "z", &device) ||
        ext_refuse_inside_context_call("Context() made") != 0) /* (before seconds of build) */
        return NULL;
    rsmooth_context *ctx = NULL;
    rsmooth_error err;
    rsmooth_status st;
    rsmooth_context_options options = {.struct_size = sizeof options, .device = device};
    Py_BEGIN_ALLOW_THREADS st = rsmooth_context_create(&options, &ctx, &err);
    Py_END_ALLOW_THREADS return capsule_for(st, ctx, &err);
}

/* An OpenCL handle passed as an int (PyOpenCL's int_ptr): 0 and *out, or -1 with TypeError. */
static int handle_arg(PyObject *obj, const char *name, void **out) {
    if (!PyLong_Check(obj)) {
        PyErr_Format(PyExc_TypeError, "%s: expected an int (an OpenCL handle's int_ptr), got %R",
                     name, obj);
        return -1;
    }
    *out = PyLong_AsVoidPtr(obj);
    return *out == NULL && PyErr_Occurred() ? -1 : 0;
}

/* _context_from_queue(int_ptr) -> capsule: rsmooth_context_create_from_queue on the caller's
 * cl_command_queue (retained by the context), kernels built with the GIL released. */
PyObject *ext_context_from_queue(PyObject *self, PyObject *args) {
    (void)self;
    PyObject *handle;
    void *queue;
    if (!PyArg_ParseTuple(args, "O", &handle) || handle_arg(handle, "queue", &queue) != 0 ||
        ext_refuse_inside_context_call("Context() made") != 0)
        return NULL;
    if (!queue) {
        PyErr_SetString(PyExc_ValueError, "queue: its int_ptr is 0 (a released queue?)");
        return NULL;
    }
    rsmooth_context *ctx = NULL;
    rsmooth_error err;
    rsmooth_status st;
    Py_BEGIN_ALLOW_THREADS st =
        rsmooth_context_create_from_queue((cl_command_queue)queue, NULL, &ctx, &err);
    Py_END_ALLOW_THREADS return capsule_for(st, ctx, &err);
}

/* _smooth_cl(context, double, positions, vertex_count, faces, out, params, progress) -> report
 * dict: rsmooth_smooth_cl. positions and out: cl_mem int_ptrs of vertex_count x 3 floats (double
 * True: doubles) on the context's OpenCL context (the library checks sizes and context); faces
 * (m, 3) uint32 on the host. */
PyObject *ext_smooth_cl(PyObject *self, PyObject *args, PyObject *kwargs) {
    (void)self;
    static char *keywords[] = {"context", "double",   "positions", "vertex_count", "faces", "out",
                               "params",  "progress", NULL};
    PyObject *cobj, *dobj, *pobj_in, *nobj, *fobj, *oobj, *pobj, *progress;
    if (!PyArg_ParseTupleAndKeywords(args, kwargs, "OOOOOOOO", keywords, &cobj, &dobj, &pobj_in,
                                     &nobj, &fobj, &oobj, &pobj, &progress))
        return NULL;
    rsmooth_context *ctx = ext_context_from(cobj);
    if (!ctx || ext_refuse_inside_context_call("smooth() on an OpenCL context") != 0)
        return NULL;
    int is_double = PyObject_IsTrue(dobj);
    void *in_mem, *out_mem;
    long count;
    if (is_double < 0 || handle_arg(pobj_in, "positions", &in_mem) != 0 ||
        handle_arg(oobj, "out", &out_mem) != 0 ||
        ext_whole_arg(nobj, "vertex_count", 0, 0x7fffffffL, &count) != 0)
        return NULL;
    ext_array f;
    ext_param_arrays held;
    memset(&held, 0, sizeof held);
    PyObject *result = NULL;
    if (ext_array_get(fobj, "faces", EXT_UINT32, 3, 0, 0, &f) != 0)
        return NULL;
    rsmooth_params p;
    if (ext_params_from_dict(pobj, (Py_ssize_t)count, &p, &held) != 0 || ext_array_own(&f, 0) != 0)
        goto done;
    call_state call;
    rsmooth_report rep;
    rsmooth_report_init(&rep);
    rsmooth_error err;
    ext_start_call(&call, progress, &p, 1);
    rsmooth_status st =
        rsmooth_smooth_cl(ctx, is_double ? RSMOOTH_FLOAT64 : RSMOOTH_FLOAT32, (cl_mem)in_mem,
                          (size_t)count, f.data, (size_t)f.rows, &p, (cl_mem)out_mem, &rep, &err);
    result = ext_finish_call(&call, st, &rep, &err);
done:
    ext_param_arrays_release(&held);
    ext_array_release(&f);
    return result;
}

/* _context_info(capsule) -> (device name, build ms, memory budget bytes). */
PyObject *ext_context_info(PyObject *self, PyObject *args) {
    (void)self;
    PyObject *capsule;
    if (!PyArg_ParseTuple(args, "O", &capsule))
        return NULL;
    rsmooth_context *ctx = ext_context_from(capsule);
    if (!ctx || ext_refuse_inside_context_call("a Context's figures read") != 0)
        return NULL;
    /* the budget is read under the context's lock, which a call on another thread may hold
     * until its progress callable has had the GIL */
    rsmooth_context_info info = {.struct_size = sizeof info};
    Py_BEGIN_ALLOW_THREADS rsmooth_context_get_info(ctx, &info);
    Py_END_ALLOW_THREADS return Py_BuildValue("(sdK)", info.device_name, info.build_ms,
                                              (unsigned long long)info.memory_budget);
}

/* _devices() -> list of dicts, one per OpenCL device ([] without OpenCL). */
PyObject *ext_devices(PyObject *self, PyObject *args) {
    (void)self;
    (void)args;
    size_t count;
    Py_BEGIN_ALLOW_THREADS count = rsmooth_list_devices(NULL, 0);
    Py_END_ALLOW_THREADS rsmooth_device_info *info = count ? calloc(count, sizeof *info) : NULL;
    if (count && !info)
        return PyErr_NoMemory();
    if (count) {
        Py_BEGIN_ALLOW_THREADS size_t again = rsmooth_list_devices(info, count);
        count = again < count ? again : count;
        Py_END_ALLOW_THREADS
    }
    PyObject *list = PyList_New(0);
    for (size_t i = 0; list && i < count; i++) {
        const rsmooth_device_info *d = info + i;
        PyObject *item = Py_BuildValue("{s:s,s:i,s:i,s:s,s:s,s:I,s:K}", "id", "", "platform",
                                       d->platform_index, "device", d->device_index, "name",
                                       d->name, "type", d->type, "compute_units", d->compute_units,
                                       "global_memory", (unsigned long long)d->global_memory);
        PyObject *id =
            item ? PyUnicode_FromFormat("%d:%d", d->platform_index, d->device_index) : NULL;
        char whole[1024]; /* d->version holds 63 bytes of it */
        const char *v =
            rsmooth_device_version(d->platform_index, d->device_index, whole, sizeof whole) > 0
                ? whole
                : d->version;
        PyObject *version = item ? PyUnicode_FromString(v) : NULL;
        if (!id || !version || PyDict_SetItemString(item, "id", id) != 0 ||
            PyDict_SetItemString(item, "version", version) != 0 || PyList_Append(list, item) != 0) {
            Py_CLEAR(list);
        }
        Py_XDECREF(id);
        Py_XDECREF(version);
        Py_XDECREF(item);
    }
    free(info);
    return list;
}
