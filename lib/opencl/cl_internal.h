/* The OpenCL path's shared declarations: the context object, and the run and tiles that filter a
 * prepared problem on its device. Internal, not installed. */
#ifndef RSMOOTH_CL_INTERNAL_H
#define RSMOOTH_CL_INTERNAL_H

#include "core/environment.h"
#include "core/stage_plan.h"

/* ---- cl_device.c / cl_program.c: the OpenCL context object ------------------------------------
 */

#ifndef CL_TARGET_OPENCL_VERSION
#define CL_TARGET_OPENCL_VERSION 120
#endif
#include "opencl/cl_loader.h" /* the cl* calls below go to the loader opened at run time */
#include <CL/cl.h>
#include <pthread.h>
#include <stdatomic.h>

/* The normal-update stage's kernels (stage.cl, cl_stage.c), in this order in each precision. */
enum {
    RS_STAGE_FACETS,
    RS_STAGE_PATCH,
    RS_STAGE_GUIDANCE,
    RS_STAGE_FILTER,
    RS_STAGE_VERTEX,
    RS_STAGE_KERNELS
};

enum {
    RS_KERNEL_MOLLIFY,
    RS_KERNEL_NORMALS,
    RS_KERNEL_BILATERAL,
    RS_KERNEL_ROBUST,
    RS_KERNEL_LEARNED,     /* learned.cl's stage network, in the context's variant */
    RS_KERNEL_STAGE_FLOAT, /* RS_STAGE_KERNELS of them, float */
    RS_KERNEL_STAGE_DOUBLE = RS_KERNEL_STAGE_FLOAT + RS_STAGE_KERNELS, /* double: NULL where the
                                                                        * device has no fp64 */
    RS_KERNEL_COUNT = RS_KERNEL_STAGE_DOUBLE + RS_STAGE_KERNELS
};

struct rsmooth_context {
    rs_environment env;   /* the environment as it was at the creation: every call reads this */
    pthread_mutex_t lock; /* serialises the calls of threads sharing the context */
    pthread_t owner;      /* the thread holding `lock`, while `busy` */
    _Atomic int busy;
    cl_context context;
    cl_device_id device;
    cl_command_queue queue;
    cl_program program;
    cl_kernel kernels[RS_KERNEL_COUNT];
    char device_name[256];
    double build_ms;
    int program_cache; /* RS_PROGRAM_CACHE_: whether the program came from rsmooth's cache */
    char program_cache_note[1024]; /* why the cache was refused, else "" */
    size_t local_size;             /* work-group size used for every kernel */
    unsigned lanes;                /* vertices per block: the kernels' vector width (RS_LANES, see
                                    * cl_variant.c); 1 is the GPU variant, one vertex per work-item */
    uint64_t global_memory;        /* CL_DEVICE_GLOBAL_MEM_SIZE */
    uint64_t max_allocation;       /* CL_DEVICE_MAX_MEM_ALLOC_SIZE: the largest one buffer may be */
    bool host_unified;             /* CL_DEVICE_HOST_UNIFIED_MEMORY: the device reads host arrays in
                                    * place (rs_cl_input_flags) */
    uint64_t memory_budget;        /* caller's or RSMOOTH_MEMORY_BUDGET's limit; 0: the device's */
    unsigned host_threads;         /* threads of the host stages of its calls; 0: every core */
    /* rsmooth_smooth_cl's (cl_store.c): the program storing results into a caller's buffer,
     * built on its first call (NULL before, and where the device has no fp64), and its kernels by
     * rsmooth_scalar */
    cl_program store_program;
    cl_kernel store_kernels[2];
    bool store_tried;
};

/* Picks the kernel variant and vector width for ctx->device (cl_variant.c): sets ctx->lanes and
 * ctx->local_size. RSMOOTH_KERNEL_VARIANT (cpu, gpu) and RSMOOTH_LANES (4, 8, 16) override it. */
rsmooth_status rs_cl_choose_variant(rsmooth_context *ctx, rsmooth_error *error);

/* Releases ctx's lock, which a context's calls hold while they use it (cl_device.c): threads
 * sharing one run one at a time. */
void rs_context_unlock(rsmooth_context *ctx);
/* Takes the lock for a filter call, or refuses (RSMOOTH_ERROR_INVALID_ARGUMENT) a call made from
 * a callback of a call on the same context, which would wait for itself for ever. */
rsmooth_status rs_context_enter(rsmooth_context *ctx, const char *where, rsmooth_error *error);

/* Bytes one run may hold on the device: the caller's budget, else most of the device's memory. */
uint64_t rs_cl_usable_memory(const rsmooth_context *ctx);

/* How a buffer whose contents the host filled before creating it gets them: handed over in place
 * (CL_MEM_USE_HOST_PTR) on a device that shares the host's memory, copied at creation
 * (CL_MEM_COPY_HOST_PTR) on one that does not, which would copy them at its first use anyway. */
cl_mem_flags rs_cl_input_flags(const rsmooth_context *ctx);

/* ---- cl_smooth.c / tiles.c: the OpenCL path ------------------------------------------------- */

/* rsmooth_smooth_cl's destination on the device: a run that solves every vertex in one piece
 * (no tiles) writes the positions into `output` with a kernel instead of the host's array. */
typedef struct rs_device_sink {
    cl_mem input,
        output;       /* the caller's: 3 scalars per vertex, packed; input as the host read it */
    cl_kernel kernel; /* the context's store kernel for the call's scalar */
    bool written;     /* set by the run that wrote every position into output */
    bool bad;         /* ... and found one not finite in the output's type */
} rs_device_sink;

/* Where a run's results go: vertex v < core_count of the problem it solved is written to entry
 * target[v] (v itself when target is NULL) of the caller's arrays; the others are a tile's halo.
 * With `device` set (rsmooth_smooth_cl), a single whole run writes the positions there instead
 * and leaves `positions` untouched. */
typedef struct rs_result_sink {
    rsmooth_scalar scalar;
    void *positions;
    float *weight, *confidence; /* optional */
    const uint32_t *target;
    size_t core_count;
    rs_device_sink *device; /* optional */
} rs_result_sink;

/* rsmooth_smooth_cl's buffer `mem` (named `name` in errors): on ctx's OpenCL context and at least
 * `bytes` long, those of vertex_count vertices (cl_store.c). */
rsmooth_status rs_cl_check_buffer(const rsmooth_context *ctx, cl_mem mem, const char *name,
                                  size_t bytes, size_t vertex_count, rsmooth_error *error);

/* Builds ctx's store program once (cl_store.c); false where it cannot (no fp64): the caller
 * then uploads the host's result. */
bool rs_cl_store_ready(rsmooth_context *ctx);

/* rsmooth_smooth_cl's buffers, once each is known valid, of ctx's context and `bytes` long
 * (cl_buffer_check.c): RSMOOTH_ERROR_INVALID_ARGUMENT, naming the argument, where either is no
 * buffer (an image), `positions` is write-only or `out_positions` read-only (its own flags or its
 * buffer's), or the two are different objects whose `bytes` used share memory (sub-buffers of
 * one buffer, a sub-buffer and its buffer, buffers over one host memory); the same object for
 * both (in place) is allowed. */
rsmooth_status rs_cl_check_buffer_pair(cl_mem positions, cl_mem out_positions, size_t bytes,
                                       rsmooth_error *error);

/* Writes a whole run's positions into sink->output on the device (cl_store.c): vertex v's are
 * (input_v * scale + result_v * h) / scale in double, as store_results computes them on the
 * host, result_v the robust pass's displacement at slot[v] (`lanes` per block); sets
 * sink->written and sink->bad. */
rsmooth_status rs_cl_store_device(rsmooth_context *ctx, rs_device_sink *sink, cl_mem result,
                                  const uint32_t *slot, size_t vertex_count, size_t lanes,
                                  double scale, double h, rsmooth_error *error);

/* Stage times and work, summed over the runs (tiles) of one call. */
typedef struct rs_run_stats {
    double ms_grid, ms_upload, ms_mollify, ms_normals, ms_robust, ms_download;
    uint64_t pairs_mollify, pairs_robust; /* vertex-facet pairs each pass evaluated */
    size_t cells;                         /* occupied grid cells */
    size_t tiles;
} rs_run_stats;

/* Device bytes a run needs at most, estimated before its grid exists (tiles.c plans with it). */
#define RS_DEVICE_BYTES_PER_FACET 64
/* What the bilateral normal filter adds per facet: a second copy of the normals to alternate with,
 * and a per-cell pair count (at most one cell per facet). */
#define RS_DEVICE_BYTES_PER_BILATERAL_FACET 24
/* And what its rounds' lists add where they fit (cl_smooth.c, run_bilateral_lists), per facet of
 * problem `pb`: 20 bytes of group data and 36 a row, with about (1.5 r + 1.5)^2 rows per facet for
 * a reach of r mean edge lengths (measured on the benchmark meshes: 11 to 14 at r = 2, 76 to 96
 * at r = 6), and a spare row. Past 128 rows the estimate stops growing (a run whose lists do not
 * fit searches in every round instead). Uses fmin and pow (math.h). */
#define RS_DEVICE_BYTES_PER_BILATERAL_LIST_FACET(pb)                                               \
    ((uint64_t)(20 + 36 * (1 + fmin(128.0,                                                         \
                                    pow(1.5 * (pb)->normal_radius / (pb)->mean_edge_length + 1.5,  \
                                        2)))))
#define RS_DEVICE_BYTES_PER_VERTEX 72
/* What the colour factor adds: a float4 mean colour per facet, three floats per vertex slot
 * (about 1.5 slots per vertex). */
#define RS_DEVICE_BYTES_PER_COLOR_FACET 16
#define RS_DEVICE_BYTES_PER_COLOR_VERTEX 20

/* One run of the whole pipeline on `problem` (facet_count > 0). A problem without indices is a
 * point cloud's (reference/points.c): facet q is vertex q, with its centroid, normal and area
 * given (problem->centroid, normal, area), and the normal filter the bilateral one or none. When
 * its buffers would exceed rs_cl_usable_memory or the device's largest allocation, returns
 * RSMOOTH_ERROR_OUT_OF_MEMORY with `*needed` set to the bytes it wanted, having run nothing. */
rsmooth_status rs_cl_run(rsmooth_context *ctx, const rs_problem *problem,
                         const rs_result_sink *sink, rs_run_stats *stats, uint64_t *needed,
                         rsmooth_error *error);
/* rs_cl_run that also writes the predictors' unit normals, 3 doubles per facet in the problem's
 * facet order, to out_normals when the run filtered them (mollify on; untouched otherwise). */
rsmooth_status rs_cl_run_normals(rsmooth_context *ctx, const rs_problem *problem,
                                 const rs_result_sink *sink, double *out_normals,
                                 rs_run_stats *stats, uint64_t *needed, rsmooth_error *error);

/* The filter on `problem`: one run when it fits the device, else spatial tiles, each with the
 * facets within reach of its vertices' results (tiles.c). */
rsmooth_status rs_cl_filter(rsmooth_context *ctx, const rs_problem *problem,
                            const rs_result_sink *sink, rs_run_stats *stats, rsmooth_error *error);

/* How far beyond a set of vertices the centroids of the facets their results depend on may lie
 * (tiles.c's top explains it): the robust reach, plus the normals' (the bilateral rounds', or the
 * mollification of facets whose corners lie up to `reach`, the largest centroid-to-corner
 * distance, from their centroids). Tiles and pieces of a larger mesh (piece.c) both use it. */
double rs_halo_radius(const rs_problem *pb, double reach);

/* Fills a report from a run's problem and stats (t_start: the call's start; t_facets: when its
 * facet data was ready). */
void rs_cl_report(rsmooth_report *report, const rs_problem *pb, const rs_run_stats *stats,
                  const char *device, double t_start, double t_facets);

/* The normal-update stage's cycles on ctx's device (cl_stage.c): an rs_stage_runner. */
rsmooth_status rs_cl_stage_run(void *ctx, const rs_stage_plan *plan, double *xyz,
                               rs_cycle_fn cycle_done, void *user, rs_stage_stats *stats,
                               rsmooth_error *error);

/* Facets per work-group in learned.cl's GPU variant (compiled into the program). */
#define RS_LEARNED_TILE 8

struct rs_learned_stage;
/* One learned stage's network on `count` descriptors on ctx's device, in float (cl_learned.c):
 * an rs_network_runner (learned/learned.h). RSMOOTH_OK with every residual written, else a
 * status (RSMOOTH_ERROR_OUT_OF_MEMORY: a chunk or model the device cannot hold;
 * RSMOOTH_ERROR_OPENCL) and nothing to use: the host then runs the chunk. Called inside a call
 * that holds ctx's lock. */
rsmooth_status rs_cl_learned_run(void *ctx, const struct rs_learned_stage *stage,
                                 const float *descriptors, size_t count, float *residuals);

/* Builds the program from the embedded kernels (or RSMOOTH_KERNEL_DIR) and creates the kernels. */
rsmooth_status rs_cl_build_program(rsmooth_context *ctx, rsmooth_error *error);

/* ---- cl_program_cache.c: rsmooth's cache of program binaries ----------------------------------
 */

enum {
    RS_PROGRAM_CACHE_OFF,
    RS_PROGRAM_CACHE_MISS,
    RS_PROGRAM_CACHE_HIT,
    RS_PROGRAM_CACHE_REFUSED
};

/* One program's entry: where its folder is (`top`, then the folders `below` it that must be the
 * user's own), the file's name, and the key the file must hold. */
typedef struct rs_program_cache {
    char top[4096], below[1024], name[48];
    uint64_t key[2], key_bytes, key_fields;
    bool enabled;    /* a folder and key are known */
    bool refused;    /* the folder or file was refused as another user's: `note` says why */
    char note[1024]; /* ... for the context's program_cache_note */
} rs_program_cache;

/* "hit", "miss", "refused" or "off": a context's program_cache state (RS_PROGRAM_CACHE_) as
 * rsmooth_context_info names it. */
const char *rs_program_cache_name(int state);

/* Keys the program of the `count` sources (OpenCL's strings and lengths, as passed to
 * clCreateProgramWithSource) and build `options` for ctx's device, its driver and platform.
 * false (the cache off) when RSMOOTH_CACHE_DIR is empty or "off", or no directory is known. */
bool rs_program_cache_open(rs_program_cache *cache, const rsmooth_context *ctx, cl_uint count,
                           const char *const *sources, const size_t *sizes, const char *options);

/* The program built from the entry's binary with `options`, or NULL (no file, a file that is not
 * whole and this key's, a file or folder another user could have written: cache->refused, or a
 * build that fails): then build from source. */
cl_program rs_program_cache_load(rs_program_cache *cache, const rsmooth_context *ctx,
                                 const char *options);

/* Stores the binary of `program`, built from source, for the entry, unless the entry was refused;
 * failures are silent (the next context builds from source again). Safe against concurrent
 * writers and readers. */
void rs_program_cache_store(const rs_program_cache *cache, const rsmooth_context *ctx,
                            cl_program program);

/* What rs_cl_run_1d returns when the caller's progress_cancel asked to stop: positive, so never
 * an OpenCL code; rs_cl_fail turns it into RSMOOTH_ERROR_CANCELLED. */
#define RS_CL_CANCELLED 1

/* Records an OpenCL failure: status RSMOOTH_ERROR_OPENCL with the raw code and failing call. */
rsmooth_status rs_cl_fail(rsmooth_error *error, cl_int code, const char *call, const char *what);

/* Symbolic name of an OpenCL error code, e.g. "CL_OUT_OF_RESOURCES". */
const char *rs_cl_error_name(cl_int code);

/* The public functions' bodies, for api/'s definitions of them (lib/api/): */
/* rsmooth_context_create */
rsmooth_status rs_cl_context_create(const rsmooth_context_options *options, rsmooth_context **out,
                                    rsmooth_error *error);
/* rsmooth_context_create_from_queue */
rsmooth_status rs_cl_context_create_from_queue(cl_command_queue queue,
                                               const rsmooth_context_options *options,
                                               rsmooth_context **out, rsmooth_error *error);
/* rsmooth_context_destroy */
void rs_cl_context_destroy(rsmooth_context *ctx);
/* rsmooth_context_get_info */
rsmooth_status rs_cl_context_get_info(const rsmooth_context *ctx, rsmooth_context_info *info);
/* rsmooth_context_queue */
cl_command_queue rs_cl_context_queue(const rsmooth_context *ctx);
/* rsmooth_list_devices */
size_t rs_cl_list_devices(rsmooth_device_info *devices, size_t capacity);
/* rsmooth_device_info_init */
void rs_cl_device_info_init(rsmooth_device_info *info);
/* rsmooth_device_version */
size_t rs_cl_device_version(int platform_index, int device_index, char *out, size_t size);

#endif /* RSMOOTH_CL_INTERNAL_H */
