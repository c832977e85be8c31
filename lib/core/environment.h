/* The environment variables the library reads, all in environment.c: their table (name, meaning,
 * default: docs/environment.md is the same table, and the test environment_docs compares them),
 * a context's copy of them taken once at its creation, and the check of their values. Internal,
 * not installed. */
#ifndef RSMOOTH_ENVIRONMENT_H
#define RSMOOTH_ENVIRONMENT_H

#include "rsmooth.h"

#include <stdbool.h>
#include <stddef.h>

typedef enum rs_env {
    RS_ENV_DEVICE,          /* the device of a context created without one */
    RS_ENV_MEMORY_BUDGET,   /* a context's device memory budget, a byte count */
    RS_ENV_HOST_THREADS,    /* threads of the host stages */
    RS_ENV_CACHE_DIR,       /* the program cache's folder; "" or "off": none */
    RS_ENV_XDG_CACHE_HOME,  /* ... else $XDG_CACHE_HOME/rsmooth */
    RS_ENV_HOME,            /* ... else $HOME/.cache/rsmooth */
    RS_ENV_STAGE,           /* where the normal-update stage runs: host or device */
    RS_ENV_STAGE_PRECISION, /* the device stage's type: double or float */
    RS_ENV_KERNEL_VARIANT,  /* cpu or gpu kernels */
    RS_ENV_LANES,           /* vertices per block of the cpu kernels: 4, 8 or 16 */
    RS_ENV_DEVICE_GRID,     /* 1: sort the grid on the device; 0: on the host */
    RS_ENV_BILATERAL_LISTS, /* 0: the bilateral rounds search the grid every round */
    RS_ENV_CELLS_PER_REACH, /* grid cells per reach, 1 to 8 */
    RS_ENV_KERNEL_DIR,      /* kernels/ *.cl read from this folder instead of the embedded ones */
    RS_ENV_BUILD_OPTIONS,   /* appended to the OpenCL build options */
    RS_ENV_OPENCL_LIBRARY,  /* the OpenCL loader's file */
    RS_ENV_NAMED_TEMPORARY, /* 1: output files go through a named temporary */
    RS_ENV_STREAM_WIDE_IDS, /* 1: streaming writes 64-bit vertex ids for any mesh (tests) */
    RS_ENV_COUNT
} rs_env;

/* A copy of every variable of the table, taken at one moment. */
typedef struct rs_environment {
    const char *value[RS_ENV_COUNT]; /* NULL: unset; else into `text` */
    char text[8192];
} rs_environment;

/* Copies every variable of the table into *env (a value that does not fit reads as unset: none
 * of them is that long). A context does this once, at its creation; its calls read the copy. */
void rs_environment_read(rs_environment *env);

/* One variable, read now: for what lives outside any context (the OpenCL loader, opened once per
 * process; the host threads of reference-path calls; io's output files). */
const char *rs_environment_now(rs_env name);

/* Checks each value in *env that has a fixed form (one of a few words, a count in a range); the
 * first that does not is RSMOOTH_ERROR_INVALID_ARGUMENT, naming the variable and what it takes. */
rsmooth_status rs_environment_check(const rs_environment *env, rsmooth_error *error,
                                    const char *where);

/* Whether the variable is set to exactly `word`. */
bool rs_environment_is(const rs_environment *env, rs_env name, const char *word);

/* The variable as an integer in [low, high], else `fallback` (unset, or not such a number). */
long rs_environment_integer(const rs_environment *env, rs_env name, long low, long high,
                            long fallback);

/* The table itself, for the docs test: name, meaning and default of entry i < RS_ENV_COUNT. */
typedef struct rs_environment_entry {
    const char *name, *meaning, *fallback, *accepted;
} rs_environment_entry;
const rs_environment_entry *rs_environment_table(void);

#endif /* RSMOOTH_ENVIRONMENT_H */
