/* Arrays through the buffer protocol: shape, type and contiguity checked before any pointer is
 * handed to the library. */
#include "ext.h"

#include <stdlib.h>
#include <string.h>

/* The struct-module type character of a format string ("<d", "=f", "I"...); 0 when the format
 * is not native-order or little-endian on this machine, or not a single item. */
static char format_char(const char *format) {
    if (!format)
        return 'B';
    if (format[0] == '@' || format[0] == '=' || format[0] == '<') {
        uint16_t probe = 1;
        int little = *(const uint8_t *)&probe == 1;
        if (format[0] == '<' && !little)
            return 0;
        format++;
    }
    return format[0] && !format[1] ? format[0] : 0;
}

static int kind_matches(ext_kind kind, char c, Py_ssize_t itemsize, rsmooth_scalar *scalar) {
    switch (kind) {
    case EXT_UINT8:
        return (c == 'B' || c == '?') && itemsize == 1;
    case EXT_FLOAT32:
        return c == 'f' && itemsize == 4;
    case EXT_FLOAT64:
        return c == 'd' && itemsize == 8;
    case EXT_REAL:
        if (c == 'f' && itemsize == 4)
            *scalar = RSMOOTH_FLOAT32;
        else if (c == 'd' && itemsize == 8)
            *scalar = RSMOOTH_FLOAT64;
        else
            return 0;
        return 1;
    case EXT_UINT32:
        return (c == 'I' || c == 'L') && itemsize == 4;
    }
    return 0;
}

static const char *kind_name(ext_kind kind) {
    switch (kind) {
    case EXT_UINT8:
        return "uint8";
    case EXT_FLOAT32:
        return "float32";
    case EXT_FLOAT64:
        return "float64";
    case EXT_REAL:
        return "float32 or float64";
    case EXT_UINT32:
        return "uint32";
    }
    return "?";
}

int ext_array_get(PyObject *obj, const char *name, ext_kind kind, Py_ssize_t cols, int writable,
                  int optional, ext_array *a) {
    memset(a, 0, sizeof *a);
    a->scalar = RSMOOTH_FLOAT64;
    if (obj == Py_None && optional)
        return 0;
    int flags = PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | (writable ? PyBUF_WRITABLE : 0);
    if (PyObject_GetBuffer(obj, &a->view, flags) != 0) {
        PyErr_Clear();
        PyErr_Format(PyExc_TypeError, "%s: expected a %sC-contiguous %s array", name,
                     writable ? "writable " : "", kind_name(kind));
        return -1;
    }
    a->held = 1;
    char c = format_char(a->view.format);
    if (!kind_matches(kind, c, a->view.itemsize, &a->scalar)) {
        PyErr_Format(PyExc_TypeError, "%s: expected %s items, got format '%s'", name,
                     kind_name(kind), a->view.format ? a->view.format : "B");
        ext_array_release(a);
        return -1;
    }
    int ndim = cols ? 2 : 1;
    if (a->view.ndim != ndim || (cols && a->view.shape[1] != cols)) {
        if (cols)
            PyErr_Format(PyExc_ValueError, "%s: expected shape (n, %zd)", name, cols);
        else
            PyErr_Format(PyExc_ValueError, "%s: expected one dimension", name);
        ext_array_release(a);
        return -1;
    }
    a->rows = a->view.shape[0];
    a->data = a->view.buf;
    return 0;
}

int ext_array_own(ext_array *a, int keep) {
    if (!a->held)
        return 0; /* an optional array left out */
    size_t bytes = (size_t)a->view.len;
    a->copy = malloc(bytes ? bytes : 1);
    if (!a->copy) {
        PyErr_NoMemory();
        return -1;
    }
    memcpy(a->copy, a->view.buf, bytes);
    a->data = a->copy;
    if (!keep) {
        PyBuffer_Release(&a->view);
        a->held = 0;
    }
    return 0;
}

void ext_array_publish(ext_array *a) {
    if (a->held && a->copy)
        memcpy(a->view.buf, a->copy, (size_t)a->view.len);
}

void ext_array_release(ext_array *a) {
    if (a->held)
        PyBuffer_Release(&a->view);
    a->held = 0;
    free(a->copy);
    a->copy = NULL;
    a->data = NULL;
}
