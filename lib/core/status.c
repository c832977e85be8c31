/* Status text and the error-detail record every fallible call can fill. */
#include "core/rsmooth_internal.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

const char *rs_status_str(rsmooth_status status) {
    switch (status) {
    case RSMOOTH_OK:
        return "success";
    case RSMOOTH_ERROR_INVALID_ARGUMENT:
        return "invalid argument";
    case RSMOOTH_ERROR_OUT_OF_MEMORY:
        return "out of memory";
    case RSMOOTH_ERROR_IO:
        return "input/output error";
    case RSMOOTH_ERROR_PARSE:
        return "malformed mesh file";
    case RSMOOTH_ERROR_NO_DEVICE:
        return "no OpenCL device";
    case RSMOOTH_ERROR_KERNEL_BUILD:
        return "OpenCL program build failed";
    case RSMOOTH_ERROR_OPENCL:
        return "OpenCL runtime error";
    case RSMOOTH_ERROR_UNSUPPORTED:
        return "unsupported";
    case RSMOOTH_ERROR_NUMERICAL:
        return "result not representable";
    case RSMOOTH_ERROR_CANCELLED:
        return "cancelled";
    }
    return "unknown status";
}

void rs_error_init(rsmooth_error *error) {
    if (!error)
        return;
    memset(error, 0, sizeof *error);
    error->struct_size = sizeof *error;
    error->line = -1;
    error->byte_offset = -1;
}

void rs_error_clear(rsmooth_error *error) {
    if (!error)
        return;
    size_t caller_size = error->struct_size; /* the caller's, never the library's to change */
    memset(error, 0, sizeof *error);
    error->struct_size = caller_size;
    error->line = -1;
    error->byte_offset = -1;
}

static rsmooth_status record(rsmooth_error *error, rsmooth_status status, const char *where,
                             const char *format, va_list args) {
    if (!error)
        return status;
    rs_error_clear(error);
    error->status = status;
    snprintf(error->where, sizeof error->where, "%s", where ? where : "");
    vsnprintf(error->message, sizeof error->message, format, args);
    return status;
}

rsmooth_status rs_fail(rsmooth_error *error, rsmooth_status status, const char *where,
                       const char *format, ...) {
    va_list args;
    va_start(args, format);
    record(error, status, where, format, args);
    va_end(args);
    return status;
}

rsmooth_status rs_cancelled(rsmooth_error *error, const char *where) {
    return rs_fail(error, RSMOOTH_ERROR_CANCELLED, where,
                   "cancelled: the progress_cancel callback asked to stop");
}

rsmooth_status rs_fail_parse(rsmooth_error *error, int64_t line, int64_t byte_offset,
                             const char *where, const char *format, ...) {
    va_list args;
    va_start(args, format);
    record(error, RSMOOTH_ERROR_PARSE, where, format, args);
    va_end(args);
    if (error) {
        error->line = line;
        error->byte_offset = byte_offset;
    }
    return RSMOOTH_ERROR_PARSE;
}
