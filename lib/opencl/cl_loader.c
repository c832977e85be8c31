/* Opening the OpenCL ICD loader at run time and resolving the functions the library calls. */
#define _POSIX_C_SOURCE 200809L
#define RS_CL_LOADER_KEEP_NAMES
#include "opencl/cl_loader.h"
#include "core/environment.h"
#include "opencl/cl_loader_elf.h"

#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef _WIN32
#include <windows.h>
#else
#include <dlfcn.h>
#endif

/* The table's types are the headers' prototypes (a mismatch fails the build here). */
#define RS_CL_CHECK(ret, name, params)                                                             \
    _Static_assert(_Generic(&cl##name, ret(CL_API_CALL *) params : 1, default : 0),                \
                   "rs_cl_functions." #name " differs from cl" #name " in <CL/cl.h>");
RS_CL_FUNCTIONS(RS_CL_CHECK)
#undef RS_CL_CHECK

rs_cl_functions rs_cl_api;

static pthread_once_t load_once = PTHREAD_ONCE_INIT;
static bool loaded;
static char failure[512]; /* why not, when !loaded (rsmooth_error keeps its first 255 bytes) */

typedef void (*any_function)(void);

#if defined(_WIN32)
#define DEFAULT_LOADER "OpenCL.dll"
#define FALLBACK_LOADER NULL
#elif defined(__APPLE__)
#define DEFAULT_LOADER "/System/Library/Frameworks/OpenCL.framework/OpenCL"
#define FALLBACK_LOADER NULL
#else
/* the soname, as the runtime packages install it; the bare name only comes with the -dev ones */
#define DEFAULT_LOADER "libOpenCL.so.1"
#define FALLBACK_LOADER "libOpenCL.so"
#endif

/* The library's handle, or NULL with the system's reason in `why`. */
static void *open_library(const char *path, char *why, size_t size) {
#ifdef _WIN32
    HMODULE module = LoadLibraryA(path);
    if (!module)
        snprintf(why, size, "Windows error %lu", (unsigned long)GetLastError());
    return (void *)module;
#else
    /* RTLD_LOCAL: the loader's names stay out of the process's namespace. Never closed: the
     * OpenCL objects of contexts (and the vendor drivers the loader opened) live until exit. */
    void *handle = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
        const char *text = dlerror();
        snprintf(why, size, "%s", text ? text : "unknown error");
    }
    return handle;
#endif
}

static void close_library(void *library) {
#ifdef _WIN32
    FreeLibrary((HMODULE)library);
#else
    dlclose(library);
#endif
}

static any_function find_function(void *library, const char *name) {
    any_function f = NULL;
#ifdef _WIN32
    FARPROC p = GetProcAddress((HMODULE)library, name);
    memcpy(&f, &p, sizeof f);
#else
    /* POSIX makes data and function pointers the same size for dlsym; copying avoids a cast ISO C
     * leaves undefined */
    _Static_assert(sizeof(void *) == sizeof(any_function), "dlsym needs function-sized pointers");
    void *p = dlsym(library, name);
    memcpy(&f, &p, sizeof f);
#endif
    return f;
}

static void load(void) {
    const char *env = rs_environment_now(RS_ENV_OPENCL_LIBRARY);
    bool named = env && *env;
    const char *path = named ? env : DEFAULT_LOADER;
    char why[200];
    void *library = NULL;
#ifdef RS_CHECK_ELF
    if (!rs_check_shared_library(path, why, sizeof why))
#endif
        library = open_library(path, why, sizeof why);
    if (!library && !named && FALLBACK_LOADER) {
        char ignored[200]; /* the soname's reason is the one to report */
        library = open_library(FALLBACK_LOADER, ignored, sizeof ignored);
        if (library)
            path = FALLBACK_LOADER;
    }
    if (!library) {
        if (named)
            snprintf(failure, sizeof failure,
                     "no OpenCL loader: %.100s (RSMOOTH_OPENCL_LIBRARY) could not be loaded (%s)",
                     path, why);
        else
            snprintf(failure, sizeof failure,
                     "no OpenCL loader: %.100s could not be loaded (%s); install one, e.g. "
                     "ocl-icd-libopencl1, or name it in RSMOOTH_OPENCL_LIBRARY",
                     path, why);
        return;
    }
    const char *missing = NULL;
    rs_cl_functions api;
#define RS_CL_RESOLVE(ret, name, params)                                                           \
    {                                                                                              \
        any_function f = find_function(library, "cl" #name);                                       \
        if (!f && !missing)                                                                        \
            missing = "cl" #name;                                                                  \
        api.name = (ret(CL_API_CALL *) params)f;                                                   \
    }
    RS_CL_FUNCTIONS(RS_CL_RESOLVE)
#undef RS_CL_RESOLVE
    if (missing) {
        close_library(library);
        snprintf(failure, sizeof failure,
                 "no OpenCL loader: %.100s%s lacks %s, so is not an OpenCL loader", path,
                 named ? " (RSMOOTH_OPENCL_LIBRARY)" : "", missing);
        return;
    }
    rs_cl_api = api;
    loaded = true;
}

rsmooth_status rs_cl_load(const char *where, rsmooth_error *error) {
    pthread_once(&load_once, load);
    if (loaded)
        return RSMOOTH_OK;
    return rs_fail(error, RSMOOTH_ERROR_NO_DEVICE, where, "%s", failure);
}
