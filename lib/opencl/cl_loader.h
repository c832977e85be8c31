/* The OpenCL ICD loader, opened at run time on first use (cl_loader.c) rather than linked, so the
 * library and the command start where no libOpenCL is installed and the reference path still runs.
 * The cl* calls of the library's OpenCL files go through a table of function pointers: after
 * <CL/cl.h>, each name used is defined to its entry (rs_cl_api.GetPlatformIDs for
 * clGetPlatformIDs). Every entry point that reaches OpenCL calls rs_cl_load first. Internal, not
 * installed: the public headers keep the real prototypes, and a host application that passes its
 * own queue links OpenCL itself; dlopen of the same soname then returns the library already
 * loaded, so both share one loader. */
#ifndef RSMOOTH_CL_LOADER_H
#define RSMOOTH_CL_LOADER_H

#include "core/rsmooth_internal.h"

#ifndef CL_TARGET_OPENCL_VERSION
#define CL_TARGET_OPENCL_VERSION 120
#endif
#ifdef __APPLE__
#include <OpenCL/cl.h>
#else
#include <CL/cl.h>
#endif

/* Every OpenCL function the library calls: X(return type, name without "cl", parameter types).
 * A function added to the library's calls is added here and to the #defines below. */
#define RS_CL_FUNCTIONS(X)                                                                         \
    X(cl_int, BuildProgram,                                                                        \
      (cl_program, cl_uint, const cl_device_id *, const char *,                                    \
       void(CL_CALLBACK *)(cl_program, void *), void *))                                           \
    X(cl_mem, CreateBuffer, (cl_context, cl_mem_flags, size_t, void *, cl_int *))                  \
    X(cl_command_queue, CreateCommandQueue,                                                        \
      (cl_context, cl_device_id, cl_command_queue_properties, cl_int *))                           \
    X(cl_context, CreateContext,                                                                   \
      (const cl_context_properties *, cl_uint, const cl_device_id *,                               \
       void(CL_CALLBACK *)(const char *, const void *, size_t, void *), void *, cl_int *))         \
    X(cl_kernel, CreateKernel, (cl_program, const char *, cl_int *))                               \
    X(cl_program, CreateProgramWithBinary,                                                         \
      (cl_context, cl_uint, const cl_device_id *, const size_t *, const unsigned char **,          \
       cl_int *, cl_int *))                                                                        \
    X(cl_program, CreateProgramWithSource,                                                         \
      (cl_context, cl_uint, const char **, const size_t *, cl_int *))                              \
    X(void *, EnqueueMapBuffer,                                                                    \
      (cl_command_queue, cl_mem, cl_bool, cl_map_flags, size_t, size_t, cl_uint, const cl_event *, \
       cl_event *, cl_int *))                                                                      \
    X(cl_int, EnqueueNDRangeKernel,                                                                \
      (cl_command_queue, cl_kernel, cl_uint, const size_t *, const size_t *, const size_t *,       \
       cl_uint, const cl_event *, cl_event *))                                                     \
    X(cl_int, EnqueueCopyBuffer,                                                                   \
      (cl_command_queue, cl_mem, cl_mem, size_t, size_t, size_t, cl_uint, const cl_event *,        \
       cl_event *))                                                                                \
    X(cl_int, EnqueueReadBuffer,                                                                   \
      (cl_command_queue, cl_mem, cl_bool, size_t, size_t, void *, cl_uint, const cl_event *,       \
       cl_event *))                                                                                \
    X(cl_int, EnqueueUnmapMemObject,                                                               \
      (cl_command_queue, cl_mem, void *, cl_uint, const cl_event *, cl_event *))                   \
    X(cl_int, EnqueueWriteBuffer,                                                                  \
      (cl_command_queue, cl_mem, cl_bool, size_t, size_t, const void *, cl_uint, const cl_event *, \
       cl_event *))                                                                                \
    X(cl_int, Finish, (cl_command_queue))                                                          \
    X(cl_int, Flush, (cl_command_queue))                                                           \
    X(cl_int, GetCommandQueueInfo,                                                                 \
      (cl_command_queue, cl_command_queue_info, size_t, void *, size_t *))                         \
    X(cl_int, GetDeviceIDs, (cl_platform_id, cl_device_type, cl_uint, cl_device_id *, cl_uint *))  \
    X(cl_int, GetDeviceInfo, (cl_device_id, cl_device_info, size_t, void *, size_t *))             \
    X(cl_int, GetKernelWorkGroupInfo,                                                              \
      (cl_kernel, cl_device_id, cl_kernel_work_group_info, size_t, void *, size_t *))              \
    X(cl_int, GetMemObjectInfo, (cl_mem, cl_mem_info, size_t, void *, size_t *))                   \
    X(cl_int, GetPlatformIDs, (cl_uint, cl_platform_id *, cl_uint *))                              \
    X(cl_int, GetPlatformInfo, (cl_platform_id, cl_platform_info, size_t, void *, size_t *))       \
    X(cl_int, GetProgramBuildInfo,                                                                 \
      (cl_program, cl_device_id, cl_program_build_info, size_t, void *, size_t *))                 \
    X(cl_int, GetProgramInfo, (cl_program, cl_program_info, size_t, void *, size_t *))             \
    X(cl_int, ReleaseCommandQueue, (cl_command_queue))                                             \
    X(cl_int, ReleaseContext, (cl_context))                                                        \
    X(cl_int, ReleaseEvent, (cl_event))                                                            \
    X(cl_int, ReleaseKernel, (cl_kernel))                                                          \
    X(cl_int, ReleaseMemObject, (cl_mem))                                                          \
    X(cl_int, ReleaseProgram, (cl_program))                                                        \
    X(cl_int, RetainCommandQueue, (cl_command_queue))                                              \
    X(cl_int, RetainContext, (cl_context))                                                         \
    X(cl_int, SetKernelArg, (cl_kernel, cl_uint, size_t, const void *))                            \
    X(cl_int, WaitForEvents, (cl_uint, const cl_event *))

#define RS_CL_MEMBER(ret, name, params) ret(CL_API_CALL *name) params;
typedef struct rs_cl_functions {
    RS_CL_FUNCTIONS(RS_CL_MEMBER)
} rs_cl_functions;
#undef RS_CL_MEMBER

/* The loader's functions; every entry is set once rs_cl_load has returned RSMOOTH_OK. */
extern rs_cl_functions rs_cl_api;

/* Opens the loader on the first call (thread-safe; later calls return the first one's answer):
 * RSMOOTH_OPENCL_LIBRARY when set and non-empty, else the platform's loader (libOpenCL.so.1,
 * OpenCL.dll, the OpenCL framework). RSMOOTH_ERROR_NO_DEVICE with the reason in `error` (which
 * file, why) when it cannot be opened or lacks a function above. */
rsmooth_status rs_cl_load(const char *where, rsmooth_error *error);

/* cl_loader.c itself checks the table's types against the prototypes, so it keeps the names. */
#ifndef RS_CL_LOADER_KEEP_NAMES
#define clBuildProgram rs_cl_api.BuildProgram
#define clCreateBuffer rs_cl_api.CreateBuffer
#define clCreateCommandQueue rs_cl_api.CreateCommandQueue
#define clCreateContext rs_cl_api.CreateContext
#define clCreateKernel rs_cl_api.CreateKernel
#define clCreateProgramWithBinary rs_cl_api.CreateProgramWithBinary
#define clCreateProgramWithSource rs_cl_api.CreateProgramWithSource
#define clEnqueueMapBuffer rs_cl_api.EnqueueMapBuffer
#define clEnqueueNDRangeKernel rs_cl_api.EnqueueNDRangeKernel
#define clEnqueueCopyBuffer rs_cl_api.EnqueueCopyBuffer
#define clEnqueueReadBuffer rs_cl_api.EnqueueReadBuffer
#define clEnqueueUnmapMemObject rs_cl_api.EnqueueUnmapMemObject
#define clEnqueueWriteBuffer rs_cl_api.EnqueueWriteBuffer
#define clFinish rs_cl_api.Finish
#define clFlush rs_cl_api.Flush
#define clGetCommandQueueInfo rs_cl_api.GetCommandQueueInfo
#define clGetDeviceIDs rs_cl_api.GetDeviceIDs
#define clGetDeviceInfo rs_cl_api.GetDeviceInfo
#define clGetKernelWorkGroupInfo rs_cl_api.GetKernelWorkGroupInfo
#define clGetMemObjectInfo rs_cl_api.GetMemObjectInfo
#define clGetPlatformIDs rs_cl_api.GetPlatformIDs
#define clGetPlatformInfo rs_cl_api.GetPlatformInfo
#define clGetProgramBuildInfo rs_cl_api.GetProgramBuildInfo
#define clGetProgramInfo rs_cl_api.GetProgramInfo
#define clReleaseCommandQueue rs_cl_api.ReleaseCommandQueue
#define clReleaseContext rs_cl_api.ReleaseContext
#define clReleaseEvent rs_cl_api.ReleaseEvent
#define clReleaseKernel rs_cl_api.ReleaseKernel
#define clReleaseMemObject rs_cl_api.ReleaseMemObject
#define clReleaseProgram rs_cl_api.ReleaseProgram
#define clRetainCommandQueue rs_cl_api.RetainCommandQueue
#define clRetainContext rs_cl_api.RetainContext
#define clSetKernelArg rs_cl_api.SetKernelArg
#define clWaitForEvents rs_cl_api.WaitForEvents
#endif

#endif /* RSMOOTH_CL_LOADER_H */
