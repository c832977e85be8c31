/* Every environment variable the library reads, in one table, and the only getenv calls of the
 * library. A context copies them all once, at its creation (rs_environment_read), and checks the
 * values that have a fixed form there, so a misspelt value fails the creation with the variable's
 * name instead of being ignored; its calls then read the copy. */
#include "core/environment.h"
#include "core/rsmooth_internal.h"

#include <stdlib.h>
#include <string.h>

/* accepted: "a|b|c" (one of these words), "low..high" (an integer in the range), or NULL (any
 * text: the place that reads it says what is wrong with it). Keep in step with rs_env's order and
 * with docs/environment.md (the test environment_docs compares them). */
static const rs_environment_entry table[RS_ENV_COUNT] = {
    [RS_ENV_DEVICE] = {"RSMOOTH_DEVICE",
                       "the device of a context created without naming one: auto, gpu, cpu, "
                       "P:D (platform and device) or part of the device's name",
                       "auto (the first GPU, else the first CPU device)", NULL},
    [RS_ENV_MEMORY_BUDGET] = {"RSMOOTH_MEMORY_BUDGET",
                              "device memory one call may hold, a byte count (256M, 1.5G); a "
                              "mesh that needs more is cut into tiles",
                              "most of the device's memory", NULL},
    [RS_ENV_HOST_THREADS] = {"RSMOOTH_HOST_THREADS",
                             "threads of the host's stages (grid, facet data, noise estimate, "
                             "the normal-update stage on CPU devices; streaming's reading, "
                             "figures and cutting)",
                             "every online core", "1..64"},
    [RS_ENV_CACHE_DIR] = {"RSMOOTH_CACHE_DIR",
                          "the folder of the compiled-program cache; empty or off: no cache",
                          "$XDG_CACHE_HOME/rsmooth, else $HOME/.cache/rsmooth", NULL},
    [RS_ENV_XDG_CACHE_HOME] = {"XDG_CACHE_HOME", "where the program cache goes by default", "unset",
                               NULL},
    [RS_ENV_HOME] = {"HOME", "where the program cache goes when XDG_CACHE_HOME is unset", "unset",
                     NULL},
    [RS_ENV_STAGE] = {"RSMOOTH_STAGE",
                      "where the best mode's normal-update stage runs: on the device or on the "
                      "host's cores (in double)",
                      "device on GPUs, host on CPU devices", "host|device"},
    [RS_ENV_STAGE_PRECISION] = {"RSMOOTH_STAGE_PRECISION",
                                "the floating type of the stage on the device",
                                "double where the device has it", "double|float"},
    [RS_ENV_KERNEL_VARIANT] = {"RSMOOTH_KERNEL_VARIANT",
                               "the kernels' shape: gpu (one vertex per work-item) or cpu "
                               "(vector blocks of vertices)",
                               "gpu on GPUs, cpu elsewhere", "cpu|gpu"},
    [RS_ENV_LANES] = {"RSMOOTH_LANES", "vertices per block of the cpu kernels",
                      "the device's preferred float vector width", "4|8|16"},
    [RS_ENV_DEVICE_GRID] = {"RSMOOTH_DEVICE_GRID",
                            "1: the facet grid is sorted on the device; 0: on the host",
                            "1 on GPUs with double precision, else 0", "0|1"},
    [RS_ENV_BILATERAL_LISTS] = {"RSMOOTH_BILATERAL_LISTS",
                                "0: the bilateral rounds search the grid in every round instead "
                                "of listing each cell's facet pairs once",
                                "1 (lists, for 2 rounds or more)", "0|1"},
    [RS_ENV_CELLS_PER_REACH] = {"RSMOOTH_CELLS_PER_REACH",
                                "grid cells across the filter's reach (for measurements)",
                                "1 to 3, from the widths", "1..8"},
    [RS_ENV_KERNEL_DIR] = {"RSMOOTH_KERNEL_DIR",
                           "a folder to read kernels/*.cl from instead of the embedded copies "
                           "(for kernel development)",
                           "the embedded kernels", NULL},
    [RS_ENV_BUILD_OPTIONS] = {"RSMOOTH_BUILD_OPTIONS", "appended to the OpenCL build options",
                              "none", NULL},
    [RS_ENV_OPENCL_LIBRARY] = {"RSMOOTH_OPENCL_LIBRARY", "the OpenCL loader's file",
                               "libOpenCL.so.1", NULL},
    [RS_ENV_NAMED_TEMPORARY] = {"RSMOOTH_NAMED_TEMPORARY",
                                "1: output files are written through a named temporary beside "
                                "the target instead of an unnamed one",
                                "unnamed where the file system has them", NULL},
    [RS_ENV_STREAM_WIDE_IDS] = {"RSMOOTH_STREAM_WIDE_IDS",
                                "1: streaming (--max-memory, rsmooth-mpi) writes 64-bit vertex ids "
                                "to its temporary files whatever the vertex count (for tests)",
                                "64-bit from 2^32 - 1 vertices on", NULL},
};

const rs_environment_entry *rs_environment_table(void) {
    return table;
}

const char *rs_environment_now(rs_env name) {
    return name < RS_ENV_COUNT ? getenv(table[name].name) : NULL;
}

void rs_environment_read(rs_environment *env) {
    size_t used = 0;
    for (int i = 0; i < RS_ENV_COUNT; i++) {
        const char *v = getenv(table[i].name);
        size_t n = v ? strlen(v) + 1 : 0;
        if (!v || n > sizeof env->text - used) {
            env->value[i] = NULL;
            continue;
        }
        memcpy(env->text + used, v, n);
        env->value[i] = env->text + used;
        used += n;
    }
}

bool rs_environment_is(const rs_environment *env, rs_env name, const char *word) {
    return env->value[name] && strcmp(env->value[name], word) == 0;
}

/* The integer `text` is, whole; false when it is none. */
static bool read_integer(const char *text, long *out) {
    char *end = NULL;
    long v = strtol(text, &end, 10);
    if (!*text || *end)
        return false;
    *out = v;
    return true;
}

long rs_environment_integer(const rs_environment *env, rs_env name, long low, long high,
                            long fallback) {
    long v = 0;
    const char *text = env->value[name];
    return text && read_integer(text, &v) && v >= low && v <= high ? v : fallback;
}

/* Whether `value` is one of the '|'-separated words of `accepted`. */
static bool one_of(const char *value, const char *accepted) {
    size_t n = strlen(value);
    for (const char *p = accepted; *p;) {
        const char *bar = strchr(p, '|');
        size_t len = bar ? (size_t)(bar - p) : strlen(p);
        if (len == n && strncmp(p, value, n) == 0)
            return true;
        p += len + (bar ? 1 : 0);
    }
    return false;
}

rsmooth_status rs_environment_check(const rs_environment *env, rsmooth_error *error,
                                    const char *where) {
    for (int i = 0; i < RS_ENV_COUNT; i++) {
        const char *v = env->value[i], *accepted = table[i].accepted;
        if (!v || !*v || !accepted) /* empty: as unset */
            continue;
        const char *dots = strstr(accepted, "..");
        long low = 0, high = 0, n = 0;
        bool ok = dots ? read_integer(v, &n) &&
                             (low = atol(accepted), high = atol(dots + 2), n >= low && n <= high)
                       : one_of(v, accepted);
        if (!ok)
            return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                           "%s is \"%s\": it takes %s%s (%s); unset it for the default (%s)",
                           table[i].name, v, dots ? "an integer in " : "one of ", accepted,
                           table[i].meaning, table[i].fallback);
    }
    return RSMOOTH_OK;
}
