/* Choosing an OpenCL device and owning (or sharing) its context and queue. */
#define _POSIX_C_SOURCE 200809L
#include "opencl/cl_internal.h"
#include "rsmooth_cl.h"

#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_PLATFORMS 16
#define MAX_DEVICES 64

static void lower(char *s) {
    for (; *s; s++)
        *s = (char)tolower((unsigned char)*s);
}

typedef struct candidate {
    cl_platform_id platform;
    cl_device_id device;
    cl_device_type type;
    int platform_index, device_index;
    char name[256]; /* "platform / device" */
} candidate;

/* The head of `text` that fits `size` bytes with its terminator. */
static void copy_cut(const char *text, char *out, size_t size) {
    size_t n = strlen(text);
    if (n >= size)
        n = size - 1;
    memcpy(out, text, n);
    out[n] = '\0';
}

/* A string property of `device` (or of `platform` when device is NULL), its size asked first so
 * a long one (PoCL's 65-character version) is read whole, then cut to `out` (`size` > 0); "" when
 * a query fails. Returns the whole property's length, 0 when it failed. */
static size_t info_string(cl_platform_id platform, cl_device_id device, cl_uint param, char *out,
                          size_t size) {
    size_t need = 0, length = 0;
    out[0] = '\0';
    cl_int err = device ? clGetDeviceInfo(device, param, 0, NULL, &need)
                        : clGetPlatformInfo(platform, param, 0, NULL, &need);
    if (err != CL_SUCCESS || need == 0)
        return 0;
    char *text = malloc(need + 1);
    if (!text)
        return 0;
    err = device ? clGetDeviceInfo(device, param, need, text, NULL)
                 : clGetPlatformInfo(platform, param, need, text, NULL);
    if (err == CL_SUCCESS) {
        text[need] = '\0';
        length = strlen(text);
        copy_cut(text, out, size);
    }
    free(text);
    return length;
}

/* A fixed-size property, `fallback` when the query fails. */
static cl_ulong device_ulong(cl_device_id device, cl_device_info param, cl_ulong fallback) {
    cl_ulong value = 0;
    return clGetDeviceInfo(device, param, sizeof value, &value, NULL) == CL_SUCCESS ? value
                                                                                    : fallback;
}

/* Every device of every platform, in clGetPlatformIDs / clGetDeviceIDs order. */
static int list_devices(candidate *out, int capacity) {
    cl_platform_id platforms[MAX_PLATFORMS];
    cl_uint platform_count = 0;
    if (clGetPlatformIDs(MAX_PLATFORMS, platforms, &platform_count) != CL_SUCCESS)
        return 0;
    int n = 0;
    for (cl_uint p = 0; p < platform_count && p < MAX_PLATFORMS; p++) {
        cl_device_id devices[MAX_DEVICES];
        cl_uint device_count = 0;
        if (clGetDeviceIDs(platforms[p], CL_DEVICE_TYPE_ALL, MAX_DEVICES, devices, &device_count) !=
            CL_SUCCESS)
            continue;
        char platform_name[96];
        info_string(platforms[p], NULL, CL_PLATFORM_NAME, platform_name, sizeof platform_name);
        for (cl_uint d = 0; d < device_count && d < MAX_DEVICES && n < capacity; d++) {
            candidate *c = &out[n++];
            c->platform = platforms[p];
            c->device = devices[d];
            c->platform_index = (int)p;
            c->device_index = (int)d;
            if (clGetDeviceInfo(devices[d], CL_DEVICE_TYPE, sizeof c->type, &c->type, NULL) !=
                CL_SUCCESS)
                c->type = 0;
            char device_name[128];
            info_string(NULL, devices[d], CL_DEVICE_NAME, device_name, sizeof device_name);
            snprintf(c->name, sizeof c->name, "%s / %s", platform_name, device_name);
        }
    }
    return n;
}

void rs_cl_device_info_init(rsmooth_device_info *info) {
    if (!info)
        return;
    memset(info, 0, sizeof *info);
    info->struct_size = sizeof *info;
}

size_t rs_cl_device_version(int platform_index, int device_index, char *out, size_t size) {
    char none[1];
    if (!out || size == 0) { /* only the length asked */
        out = none;
        size = sizeof none;
    }
    out[0] = '\0';
    if (rs_cl_load("rsmooth_device_version", NULL) != RSMOOTH_OK)
        return 0;
    candidate all[MAX_DEVICES];
    int n = list_devices(all, MAX_DEVICES);
    for (int i = 0; i < n; i++)
        if (all[i].platform_index == platform_index && all[i].device_index == device_index)
            return info_string(NULL, all[i].device, CL_DEVICE_VERSION, out, size);
    return 0;
}

size_t rs_cl_list_devices(rsmooth_device_info *devices, size_t capacity) {
    if (rs_cl_load("rsmooth_list_devices", NULL) != RSMOOTH_OK)
        return 0; /* no loader: no platform either */
    candidate all[MAX_DEVICES];
    int n = list_devices(all, MAX_DEVICES);
    for (int i = 0; i < n && devices && (size_t)i < capacity; i++) {
        /* entries of this version's size: the only size with struct_size so far, whatever the
         * first entry says (see rsmooth.h) */
        rsmooth_device_info *d = &devices[i];
        size_t caller_size = d->struct_size;
        memset(d, 0, sizeof *d);
        d->struct_size = caller_size;
        d->platform_index = all[i].platform_index;
        d->device_index = all[i].device_index;
        snprintf(d->name, sizeof d->name, "%s", all[i].name);
        const char *type = (all[i].type & CL_DEVICE_TYPE_GPU)           ? "gpu"
                           : (all[i].type & CL_DEVICE_TYPE_CPU)         ? "cpu"
                           : (all[i].type & CL_DEVICE_TYPE_ACCELERATOR) ? "accel"
                                                                        : "other";
        snprintf(d->type, sizeof d->type, "%s", type);
        info_string(NULL, all[i].device, CL_DEVICE_VERSION, d->version, sizeof d->version);
        cl_uint units = 0;
        if (clGetDeviceInfo(all[i].device, CL_DEVICE_MAX_COMPUTE_UNITS, sizeof units, &units,
                            NULL) != CL_SUCCESS)
            units = 0;
        d->compute_units = units;
        d->global_memory = device_ulong(all[i].device, CL_DEVICE_GLOBAL_MEM_SIZE, 0);
    }
    return (size_t)n;
}

static rsmooth_status pick_device(const char *spec, candidate *chosen, rsmooth_error *error) {
    static const char where[] = "rsmooth_context_create";
    candidate all[MAX_DEVICES];
    int n = list_devices(all, MAX_DEVICES);
    if (n == 0)
        return rs_fail(error, RSMOOTH_ERROR_NO_DEVICE, where,
                       "no OpenCL platform or device found (is an ICD such as pocl-opencl-icd "
                       "installed?)");
    char want[128];
    snprintf(want, sizeof want, "%s", spec);
    lower(want);
    int pi = -1, di = -1;
    char tail;
    if (strcmp(want, "auto") == 0 || want[0] == '\0') {
        for (int pass = 0; pass < 3; pass++)
            for (int i = 0; i < n; i++) {
                bool ok = pass == 0   ? (all[i].type & CL_DEVICE_TYPE_GPU) != 0
                          : pass == 1 ? (all[i].type & CL_DEVICE_TYPE_CPU) != 0
                                      : true;
                if (ok) {
                    *chosen = all[i];
                    return RSMOOTH_OK;
                }
            }
    } else if (strcmp(want, "gpu") == 0 || strcmp(want, "cpu") == 0) {
        cl_device_type t = want[0] == 'g' ? CL_DEVICE_TYPE_GPU : CL_DEVICE_TYPE_CPU;
        for (int i = 0; i < n; i++)
            if (all[i].type & t) {
                *chosen = all[i];
                return RSMOOTH_OK;
            }
        return rs_fail(error, RSMOOTH_ERROR_NO_DEVICE, where, "no OpenCL %s device found",
                       want[0] == 'g' ? "GPU" : "CPU");
    } else if (sscanf(want, "%d:%d%c", &pi, &di, &tail) == 2) {
        for (int i = 0; i < n; i++)
            if (all[i].platform_index == pi && all[i].device_index == di) {
                *chosen = all[i];
                return RSMOOTH_OK;
            }
        return rs_fail(error, RSMOOTH_ERROR_NO_DEVICE, where, "no OpenCL device %d on platform %d",
                       di, pi);
    } else {
        for (int i = 0; i < n; i++) {
            char name[256];
            snprintf(name, sizeof name, "%s", all[i].name);
            lower(name);
            if (strstr(name, want)) {
                *chosen = all[i];
                return RSMOOTH_OK;
            }
        }
        return rs_fail(error, RSMOOTH_ERROR_NO_DEVICE, where,
                       "no OpenCL device name contains \"%s\"", spec);
    }
    return rs_fail(error, RSMOOTH_ERROR_NO_DEVICE, where, "no OpenCL device found");
}

/* Reads a byte count such as "256M", "1.5G", "4096" (suffixes K, M, G, T: powers of 1024), as
 * RSMOOTH_MEMORY_BUDGET holds it; false when `text` is not one. (The command parses its
 * --memory-budget with its own copy, host/cli_args.c: host/ calls only the public API.) */
static bool parse_bytes(const char *text, uint64_t *bytes) {
    char *end = NULL;
    double value = strtod(text, &end);
    if (end == text || !(value >= 0))
        return false;
    static const char suffixes[] = "KMGT";
    double scale = 1;
    if (*end) {
        const char *s = strchr(suffixes, toupper((unsigned char)*end));
        if (!s || !*s)
            return false;
        for (const char *k = suffixes; k <= s; k++)
            scale *= 1024;
        end++;
        if (*end == 'i') /* "MiB" */
            end++;
        if (*end == 'B' || *end == 'b')
            end++;
    }
    if (*end || !(value * scale < 1.8e19))
        return false;
    *bytes = (uint64_t)(value * scale);
    return true;
}

/* Reads the device's memory limits and the budget: the caller's (`given`, unless 0), else
 * RSMOOTH_MEMORY_BUDGET's. */
static rsmooth_status read_memory_limits(rsmooth_context *ctx, uint64_t given,
                                         rsmooth_error *error) {
    cl_ulong global = device_ulong(ctx->device, CL_DEVICE_GLOBAL_MEM_SIZE, 0);
    cl_ulong max_alloc = device_ulong(ctx->device, CL_DEVICE_MAX_MEM_ALLOC_SIZE, 0);
    ctx->global_memory = global ? global : (uint64_t)1 << 30;
    ctx->max_allocation = max_alloc ? max_alloc : ctx->global_memory / 4;
    cl_bool unified = CL_FALSE;
    if (clGetDeviceInfo(ctx->device, CL_DEVICE_HOST_UNIFIED_MEMORY, sizeof unified, &unified,
                        NULL) != CL_SUCCESS)
        unified = CL_FALSE;
    ctx->host_unified = unified == CL_TRUE;
    /* the caller's budget wins: the variable is then not read at all, as if unset */
    const char *budget = given ? NULL : ctx->env.value[RS_ENV_MEMORY_BUDGET];
    if (budget && *budget && !parse_bytes(budget, &ctx->memory_budget))
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, "rsmooth_context_create",
                       "RSMOOTH_MEMORY_BUDGET='%s' is not a byte count (examples: 268435456, "
                       "256M, 1.5G; unset it for the device's own limit)",
                       budget);
    if (budget && *budget && ctx->memory_budget == 0) /* as the command's --memory-budget 0 */
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, "rsmooth_context_create",
                       "RSMOOTH_MEMORY_BUDGET='%s' leaves no memory: unset it for the device's "
                       "own limit",
                       budget);
    if (given)
        ctx->memory_budget = given;
    return RSMOOTH_OK;
}

uint64_t rs_cl_usable_memory(const rsmooth_context *ctx) {
    /* most of the device: the driver and other programs keep some */
    uint64_t device = ctx->global_memory / 4 * 3;
    return ctx->memory_budget && ctx->memory_budget < device ? ctx->memory_budget : device;
}

cl_mem_flags rs_cl_input_flags(const rsmooth_context *ctx) {
    /* Copying also keeps the buffer's contents defined for the OpenCL implementation itself: a
     * checker such as Oclgrind's uninitialised-value check sees CL_MEM_USE_HOST_PTR buffers as
     * never written (error 1 in tests/test_oclgrind.c). */
    return ctx->host_unified ? CL_MEM_USE_HOST_PTR : CL_MEM_COPY_HOST_PTR;
}

/* A context's calls hold its lock while they use it: threads sharing one run one at a time
 * (rs_context_unlock releases it). */
static void rs_context_lock(rsmooth_context *ctx) {
    pthread_mutex_lock(&ctx->lock);
    ctx->owner = pthread_self();
    atomic_store(&ctx->busy, 1);
}

/* Whether the calling thread holds ctx's lock: it is inside a call on ctx, in one of the call's
 * callbacks (progress, progress_cancel). */
static bool rs_context_held_here(const rsmooth_context *ctx) {
    /* only the holder sets `owner` to itself, so another thread's holding never reads as ours */
    return atomic_load(&ctx->busy) && pthread_equal(ctx->owner, pthread_self());
}

void rs_context_unlock(rsmooth_context *ctx) {
    atomic_store(&ctx->busy, 0);
    pthread_mutex_unlock(&ctx->lock);
}

rsmooth_status rs_context_enter(rsmooth_context *ctx, const char *where, rsmooth_error *error) {
    if (rs_context_held_here(ctx))
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "called on a context from a callback of a call still running on it (the "
                       "context serves one call at a time): use another context, or the "
                       "reference path");
    rs_context_lock(ctx);
    return RSMOOTH_OK;
}

static rsmooth_context *new_context(void) {
    rsmooth_context *ctx = rs_calloc_array(1, sizeof *ctx);
    if (ctx && pthread_mutex_init(&ctx->lock, NULL) != 0) {
        rs_free(ctx);
        return NULL;
    }
    return ctx;
}

/* The context's copy of the environment, then the caller's options over it: its host threads
 * (its memory budget after read_memory_limits, which reads the device's). */
static void set_environment(rsmooth_context *ctx, const rs_environment *env,
                            const rsmooth_context_options *options) {
    ctx->env = *env;
    for (int i = 0; i < RS_ENV_COUNT; i++) /* into the context's own copy of the text */
        if (env->value[i])
            ctx->env.value[i] = ctx->env.text + (env->value[i] - env->text);
    ctx->host_threads = options->host_threads
                            ? options->host_threads
                            : (unsigned)rs_environment_integer(env, RS_ENV_HOST_THREADS, 1, 64, 0);
}

/* The context's environment and options, read and checked: the start of both creations. */
static rsmooth_status begin_creation(const rsmooth_context_options *options,
                                     rsmooth_context_options *opts, rs_environment *env,
                                     rsmooth_error *error, const char *where) {
    if (!rs_read_sized(options, opts, sizeof *opts))
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "options->struct_size is %zu: set it to sizeof(rsmooth_context_options)",
                       options->struct_size);
    rs_environment_read(env);
    return rs_environment_check(env, error, where);
}

rsmooth_status rs_cl_context_create(const rsmooth_context_options *options, rsmooth_context **out,
                                    rsmooth_error *error) {
    static const char where[] = "rsmooth_context_create";
    rs_error_clear(error);
    if (!out)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "ctx is NULL");
    *out = NULL;
    rsmooth_context_options opts;
    rs_environment env;
    rsmooth_status st = begin_creation(options, &opts, &env, error, where);
    if (st != RSMOOTH_OK)
        return st;
    const char *device = opts.device ? opts.device : env.value[RS_ENV_DEVICE];
    if (!device)
        device = "auto";
    st = rs_cl_load(where, error);
    if (st != RSMOOTH_OK)
        return st;
    candidate chosen;
    st = pick_device(device, &chosen, error);
    if (st != RSMOOTH_OK)
        return st;
    rsmooth_context *ctx = new_context();
    if (!ctx)
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "no memory for the context");
    set_environment(ctx, &env, &opts);
    ctx->device = chosen.device;
    snprintf(ctx->device_name, sizeof ctx->device_name, "%s", chosen.name);
    st = rs_cl_choose_variant(ctx, error);
    if (st != RSMOOTH_OK)
        goto fail;
    cl_context_properties props[] = {CL_CONTEXT_PLATFORM, (cl_context_properties)chosen.platform,
                                     0};
    cl_int err = CL_SUCCESS;
    ctx->context = clCreateContext(props, 1, &chosen.device, NULL, NULL, &err);
    if (err != CL_SUCCESS) {
        st = rs_cl_fail(error, err, "clCreateContext", chosen.name);
        goto fail;
    }
    ctx->queue = clCreateCommandQueue(ctx->context, chosen.device, 0, &err);
    if (err != CL_SUCCESS) {
        st = rs_cl_fail(error, err, "clCreateCommandQueue", chosen.name);
        goto fail;
    }
    st = read_memory_limits(ctx, opts.memory_budget, error);
    if (st == RSMOOTH_OK)
        st = rs_cl_build_program(ctx, error);
    if (st != RSMOOTH_OK)
        goto fail;
    *out = ctx;
    return RSMOOTH_OK;
fail:
    rs_cl_context_destroy(ctx);
    return st;
}

rsmooth_status rs_cl_context_create_from_queue(cl_command_queue queue,
                                               const rsmooth_context_options *options,
                                               rsmooth_context **out, rsmooth_error *error) {
    static const char where[] = "rsmooth_context_create_from_queue";
    rs_error_clear(error);
    if (!out)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "ctx is NULL");
    *out = NULL;
    if (!queue)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "queue is NULL");
    rsmooth_context_options opts;
    rs_environment env;
    rsmooth_status st = begin_creation(options, &opts, &env, error, where);
    if (st != RSMOOTH_OK)
        return st;
    /* the caller's queue came from a loader it linked: the same library, opened once more */
    st = rs_cl_load(where, error);
    if (st != RSMOOTH_OK)
        return st;
    cl_context context = NULL;
    cl_device_id device = NULL;
    cl_int err = clGetCommandQueueInfo(queue, CL_QUEUE_CONTEXT, sizeof context, &context, NULL);
    if (err == CL_SUCCESS)
        err = clGetCommandQueueInfo(queue, CL_QUEUE_DEVICE, sizeof device, &device, NULL);
    if (err != CL_SUCCESS) {
        rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                "queue is not a valid OpenCL command queue (%s)", rs_cl_error_name(err));
        if (error)
            error->cl_error = err;
        return RSMOOTH_ERROR_INVALID_ARGUMENT;
    }
    rsmooth_context *ctx = new_context();
    if (!ctx)
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "no memory for the context");
    set_environment(ctx, &env, &opts);
    clRetainCommandQueue(queue);
    clRetainContext(context);
    ctx->queue = queue;
    ctx->context = context;
    ctx->device = device;
    cl_platform_id platform = NULL;
    char platform_name[96] = "", device_name[128];
    if (clGetDeviceInfo(device, CL_DEVICE_PLATFORM, sizeof platform, &platform, NULL) == CL_SUCCESS)
        info_string(platform, NULL, CL_PLATFORM_NAME, platform_name, sizeof platform_name);
    info_string(NULL, device, CL_DEVICE_NAME, device_name, sizeof device_name);
    snprintf(ctx->device_name, sizeof ctx->device_name, "%s / %s", platform_name, device_name);
    st = rs_cl_choose_variant(ctx, error);
    if (st == RSMOOTH_OK)
        st = read_memory_limits(ctx, opts.memory_budget, error);
    if (st == RSMOOTH_OK)
        st = rs_cl_build_program(ctx, error);
    if (st != RSMOOTH_OK) {
        rs_cl_context_destroy(ctx);
        return st;
    }
    *out = ctx;
    return RSMOOTH_OK;
}

void rs_cl_context_destroy(rsmooth_context *ctx) {
    /* from a callback of a call still running on it: the call would go on with freed objects */
    if (!ctx || rs_context_held_here(ctx))
        return;
    for (int k = 0; k < RS_KERNEL_COUNT; k++)
        if (ctx->kernels[k])
            clReleaseKernel(ctx->kernels[k]);
    if (ctx->program)
        clReleaseProgram(ctx->program);
    for (int k = 0; k < 2; k++)
        if (ctx->store_kernels[k])
            clReleaseKernel(ctx->store_kernels[k]);
    if (ctx->store_program)
        clReleaseProgram(ctx->store_program);
    if (ctx->queue)
        clReleaseCommandQueue(ctx->queue);
    if (ctx->context)
        clReleaseContext(ctx->context);
    pthread_mutex_destroy(&ctx->lock);
    rs_free(ctx);
}

cl_command_queue rs_cl_context_queue(const rsmooth_context *ctx) {
    return ctx ? ctx->queue : NULL;
}

rsmooth_status rs_cl_context_get_info(const rsmooth_context *ctx, rsmooth_context_info *info) {
    static const char where[] = "rsmooth_context_get_info";
    if (!ctx || !info)
        return rs_fail(NULL, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "%s is NULL",
                       ctx ? "info" : "ctx");
    size_t size = info->struct_size;
    if (size < offsetof(rsmooth_context_info, program_cache_note))
        return RSMOOTH_ERROR_INVALID_ARGUMENT; /* set struct_size */
    rsmooth_context_info full = {.struct_size = sizeof full};
    rsmooth_context *shared = (rsmooth_context *)ctx; /* the lock is the one mutable part */
    bool mine = rs_context_held_here(ctx);            /* from a callback of a call on ctx */
    if (!mine)
        rs_context_lock(shared);
    full.device_name = ctx->device_name;
    full.build_ms = ctx->build_ms;
    full.program_cache = rs_program_cache_name(ctx->program_cache);
    full.program_cache_note = ctx->program_cache_note;
    full.lanes = ctx->lanes;
    full.group = ctx->local_size;
    full.memory_budget = rs_cl_usable_memory(ctx);
    full.host_threads = ctx->host_threads;
    if (!mine)
        rs_context_unlock(shared);
    memcpy(info, &full, size < sizeof full ? size : sizeof full);
    info->struct_size = size;
    return RSMOOTH_OK;
}
