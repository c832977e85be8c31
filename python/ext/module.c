/* rsmooth._rsmooth: the module table, its exception, and statuses turned into exceptions. */
#include "ext.h"

PyObject *ext_device_error;

#define STR_(x) #x
#define STR(x) STR_(x)
#define VERSION_TEXT                                                                               \
    STR(RSMOOTH_VERSION_MAJOR) "." STR(RSMOOTH_VERSION_MINOR) "." STR(RSMOOTH_VERSION_PATCH)

PyObject *ext_raise(rsmooth_status status, const rsmooth_error *error) {
    if (PyErr_Occurred()) /* the progress callable raised, or Ctrl-C: that is the story */
        return NULL;
    const char *message = error && error->message[0] ? error->message : rsmooth_status_str(status);
    switch (status) {
    case RSMOOTH_ERROR_INVALID_ARGUMENT:
    case RSMOOTH_ERROR_PARSE: /* bytes handed in (a model=) that are not what they should be */
        PyErr_SetString(PyExc_ValueError, message);
        break;
    case RSMOOTH_ERROR_OUT_OF_MEMORY:
        PyErr_SetString(PyExc_MemoryError, message);
        break;
    case RSMOOTH_ERROR_NO_DEVICE:
    case RSMOOTH_ERROR_OPENCL:
        PyErr_SetString(ext_device_error, message);
        break;
    case RSMOOTH_ERROR_KERNEL_BUILD:
        PyErr_Format(ext_device_error, "%s\n%s", message, error ? error->build_log : "");
        break;
    case RSMOOTH_ERROR_NUMERICAL:
        PyErr_SetString(PyExc_FloatingPointError, message);
        break;
    case RSMOOTH_ERROR_CANCELLED:
        PyErr_SetString(PyExc_KeyboardInterrupt, message);
        break;
    case RSMOOTH_ERROR_UNSUPPORTED:
        PyErr_SetString(PyExc_NotImplementedError, message);
        break;
    default:
        PyErr_Format(PyExc_RuntimeError, "%s: %s", rsmooth_status_str(status), message);
        break;
    }
    return NULL;
}

#define KW(f) ((PyCFunction)(void (*)(void))(f))

static PyMethodDef methods[] = {
    {"_smooth", KW(ext_smooth), METH_VARARGS | METH_KEYWORDS, "The mesh filter (internal)."},
    {"_smooth_points", KW(ext_smooth_points), METH_VARARGS | METH_KEYWORDS,
     "The point-cloud filter (internal)."},
    {"_taubin", KW(ext_taubin), METH_VARARGS | METH_KEYWORDS, "Laplacian/Taubin (internal)."},
    {"_default_params", ext_default_params, METH_VARARGS, "Preset parameters (internal)."},
    {"_params_auto", ext_params_auto, METH_VARARGS, "Parameters from the noise (internal)."},
    {"_estimate_noise", ext_estimate_noise, METH_VARARGS, "Noise estimate (internal)."},
    {"_mean_edge_length", ext_mean_edge_length, METH_VARARGS, "Mean edge length (internal)."},
    {"_point_spacing", ext_point_spacing, METH_VARARGS, "Point spacing (internal)."},
    {"_compare", ext_compare, METH_VARARGS, "Error metrics (internal)."},
    {"_devices", ext_devices, METH_NOARGS, "OpenCL devices (internal)."},
    {"_context_create", ext_context_create, METH_VARARGS, "New context (internal)."},
    {"_context_info", ext_context_info, METH_VARARGS, "Context figures (internal)."},
    {"_context_from_queue", ext_context_from_queue, METH_VARARGS,
     "New context on a caller's cl_command_queue (internal)."},
    {"_smooth_cl", KW(ext_smooth_cl), METH_VARARGS | METH_KEYWORDS,
     "The mesh filter on OpenCL buffers (internal)."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT,
    "_rsmooth",
    "rsmooth's C extension: the library behind the rsmooth package (use rsmooth, not this).",
    -1,
    methods,
    NULL,
    NULL,
    NULL,
    NULL,
};

PyMODINIT_FUNC PyInit__rsmooth(void); /* (the only symbol the module exports) */
PyMODINIT_FUNC PyInit__rsmooth(void) {
    PyObject *m = PyModule_Create(&module);
    if (!m)
        return NULL;
    ext_device_error = PyErr_NewExceptionWithDoc(
        "rsmooth.DeviceError",
        "An OpenCL device is missing or failed (no loader, no platform, no device matching the "
        "choice, a kernel build or an OpenCL call that failed). The message names the device and "
        "the OpenCL error.",
        PyExc_RuntimeError, NULL);
    if (!ext_device_error || PyModule_AddObject(m, "DeviceError", ext_device_error) != 0) {
        Py_XDECREF(ext_device_error);
        Py_DECREF(m);
        return NULL;
    }
    Py_INCREF(ext_device_error); /* the module's reference was stolen; keep ours */
    if (PyModule_AddStringConstant(m, "__version__", VERSION_TEXT) != 0) {
        Py_DECREF(m);
        return NULL;
    }
    return m;
}
