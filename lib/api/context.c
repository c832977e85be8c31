/* The public context and device calls (rsmooth.h, rsmooth_cl.h): opencl/cl_device.c makes and
 * describes them. */
#include "opencl/cl_internal.h"
#include "rsmooth_cl.h"

rsmooth_status rsmooth_context_create(const rsmooth_context_options *options, rsmooth_context **out,
                                      rsmooth_error *error) {
    return rs_cl_context_create(options, out, error);
}

rsmooth_status rsmooth_context_create_from_queue(cl_command_queue queue,
                                                 const rsmooth_context_options *options,
                                                 rsmooth_context **out, rsmooth_error *error) {
    return rs_cl_context_create_from_queue(queue, options, out, error);
}

void rsmooth_context_destroy(rsmooth_context *ctx) {
    rs_cl_context_destroy(ctx);
}

rsmooth_status rsmooth_context_get_info(const rsmooth_context *ctx, rsmooth_context_info *info) {
    return rs_cl_context_get_info(ctx, info);
}

cl_command_queue rsmooth_context_queue(const rsmooth_context *ctx) {
    return rs_cl_context_queue(ctx);
}

size_t rsmooth_list_devices(rsmooth_device_info *devices, size_t capacity) {
    return rs_cl_list_devices(devices, capacity);
}

void rsmooth_device_info_init(rsmooth_device_info *info) {
    rs_cl_device_info_init(info);
}

size_t rsmooth_device_version(int platform_index, int device_index, char *out, size_t size) {
    return rs_cl_device_version(platform_index, device_index, out, size);
}
