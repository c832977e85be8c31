/* rsmooth_smooth_cl's two memory objects beyond their context and size (cl_store.c checks those):
 * each must be a buffer (an image's memory is laid out as the device likes, not as packed
 * coordinates), the input one kernels may read and the output one they may write, and the two
 * the same object (in place: the input is read before anything is written) or apart. Apart is
 * not obvious: two sub-buffers of one buffer, or a sub-buffer and its buffer, share memory where
 * their ranges meet, and so do two buffers over the same host memory (CL_MEM_USE_HOST_PTR); the
 * store kernel would then read inputs another work-item has already overwritten, and OpenCL
 * leaves any use of overlapping objects in one command undefined. Calls nothing above opencl/. */
#include "opencl/cl_internal.h"

static const char where[] = "rsmooth_smooth_cl";

/* What the checks need of one memory object. */
typedef struct mem_facts {
    cl_mem_flags flags, root_flags; /* its own, and its buffer's where it is a sub-buffer */
    cl_mem root;                    /* the buffer whose memory it is: itself, or its parent */
    size_t offset;                  /* where it starts in root (0 for a buffer) */
    const char *host; /* its first byte in host memory (CL_MEM_USE_HOST_PTR), or NULL */
} mem_facts;

static rsmooth_status query_failed(cl_int err, const char *name, rsmooth_error *error) {
    rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "%s is not a valid OpenCL buffer (%s)",
            name, rs_cl_error_name(err));
    if (error)
        error->cl_error = err;
    return RSMOOTH_ERROR_INVALID_ARGUMENT;
}

static rsmooth_status facts_of(cl_mem mem, const char *name, mem_facts *f, rsmooth_error *error) {
    cl_mem_object_type type = 0;
    cl_mem parent = NULL;
    void *host = NULL;
    *f = (mem_facts){0, 0, mem, 0, NULL};
    cl_int err = clGetMemObjectInfo(mem, CL_MEM_TYPE, sizeof type, &type, NULL);
    if (err == CL_SUCCESS && type != CL_MEM_OBJECT_BUFFER)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "%s is not a buffer (an image or another memory object: CL_MEM_TYPE "
                       "0x%x); the coordinates must be in a buffer",
                       name, (unsigned)type);
    if (err == CL_SUCCESS)
        err = clGetMemObjectInfo(mem, CL_MEM_FLAGS, sizeof f->flags, &f->flags, NULL);
    if (err == CL_SUCCESS)
        err = clGetMemObjectInfo(mem, CL_MEM_ASSOCIATED_MEMOBJECT, sizeof parent, &parent, NULL);
    if (err == CL_SUCCESS && parent) {
        f->root = parent;
        err = clGetMemObjectInfo(mem, CL_MEM_OFFSET, sizeof f->offset, &f->offset, NULL);
        if (err == CL_SUCCESS)
            err = clGetMemObjectInfo(parent, CL_MEM_FLAGS, sizeof f->root_flags, &f->root_flags,
                                     NULL);
    }
    if (err == CL_SUCCESS && ((f->flags | f->root_flags) & CL_MEM_USE_HOST_PTR))
        err = clGetMemObjectInfo(mem, CL_MEM_HOST_PTR, sizeof host, &host, NULL);
    f->host = host;
    return err == CL_SUCCESS ? RSMOOTH_OK : query_failed(err, name, error);
}

/* [a, a + bytes) and [b, b + bytes) meet. */
static bool ranges_meet(uintptr_t a, uintptr_t b, size_t bytes) {
    return a < b ? b - a < bytes : a - b < bytes;
}

rsmooth_status rs_cl_check_buffer_pair(cl_mem positions, cl_mem out_positions, size_t bytes,
                                       rsmooth_error *error) {
    mem_facts in, out;
    rsmooth_status st = facts_of(positions, "positions", &in, error);
    if (st == RSMOOTH_OK)
        st = facts_of(out_positions, "out_positions", &out, error);
    if (st != RSMOOTH_OK)
        return st;
    if ((in.flags | in.root_flags) & CL_MEM_WRITE_ONLY)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "positions is write-only (CL_MEM_WRITE_ONLY%s): kernels may not read it",
                       in.flags & CL_MEM_WRITE_ONLY ? "" : ", its buffer's");
    if ((out.flags | out.root_flags) & CL_MEM_READ_ONLY)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "out_positions is read-only (CL_MEM_READ_ONLY%s): kernels may not write it",
                       out.flags & CL_MEM_READ_ONLY ? "" : ", its buffer's");
    /* the same object: in place, each vertex's input read (by the host, or by the work-item that
     * writes it) before its output is written */
    if (positions == out_positions || bytes == 0)
        return RSMOOTH_OK;
    if (in.root == out.root && ranges_meet(in.offset, out.offset, bytes))
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "positions and out_positions overlap: two objects over one buffer's memory "
                       "(sub-buffers, or a sub-buffer and its buffer) from byte offsets %zu and "
                       "%zu, %zu bytes used of each; pass one object as both to smooth in place",
                       in.offset, out.offset, bytes);
    if (in.root != out.root && in.host && out.host &&
        ranges_meet((uintptr_t)in.host, (uintptr_t)out.host, bytes))
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "positions and out_positions overlap: two buffers over one host memory "
                       "(CL_MEM_USE_HOST_PTR) less than the %zu bytes used of each apart; pass one "
                       "object as both to smooth in place",
                       bytes);
    return RSMOOTH_OK;
}
