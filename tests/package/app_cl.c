/* A host that uses OpenCL 2.0 itself and hands rsmooth its own queue (rsmooth_cl.h): the OpenCL
 * version is this file's choice, not the library's. Built with -Werror, so a version forced by the
 * package (a second definition, or 1.2 hiding clCreateCommandQueueWithProperties) fails to compile.
 * With an OpenCL platform it smooths a tetrahedron on the queue it made; without one it has only
 * shown that it compiles and links. */
#define CL_TARGET_OPENCL_VERSION 200
#include <rsmooth_cl.h>

#include <stdio.h>

int main(void) {
    cl_platform_id platform;
    cl_uint platforms = 0;
    if (clGetPlatformIDs(1, &platform, &platforms) != CL_SUCCESS || platforms == 0) {
        printf("app_cl: no OpenCL platform here (compiled and linked only)\n");
        return 0;
    }
    cl_device_id device;
    cl_int cl_err = clGetDeviceIDs(platform, CL_DEVICE_TYPE_ALL, 1, &device, NULL);
    if (cl_err != CL_SUCCESS) {
        printf("app_cl: no OpenCL device here (compiled and linked only)\n");
        return 0;
    }
    cl_context context = clCreateContext(NULL, 1, &device, NULL, NULL, &cl_err);
    if (cl_err != CL_SUCCESS)
        return 1;
    const cl_queue_properties props[] = {0};
    cl_command_queue queue = clCreateCommandQueueWithProperties(context, device, props, &cl_err);
    if (cl_err != CL_SUCCESS) {
        fprintf(stderr, "app_cl: clCreateCommandQueueWithProperties: %d\n", (int)cl_err);
        return 1;
    }
    const float xyz[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    const uint32_t idx[] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
    float out[12];
    rsmooth_error err;
    rsmooth_context *ctx = NULL;
    rsmooth_status st = rsmooth_context_create_from_queue(queue, NULL, &ctx, &err);
    if (st == RSMOOTH_OK) {
        st = rsmooth_smooth(ctx, RSMOOTH_FLOAT32, xyz, 4, idx, 4, NULL, out, NULL, &err);
        rsmooth_context_destroy(ctx);
    }
    clReleaseCommandQueue(queue);
    clReleaseContext(context);
    printf("app_cl: OpenCL 2.0 queue, rsmooth_smooth on it: %s%s%s\n", rsmooth_status_str(st),
           st == RSMOOTH_OK ? "" : ": ", st == RSMOOTH_OK ? "" : err.message);
    return st == RSMOOTH_OK ? 0 : 1;
}
