/* What every layer of the library shares: core/ only (the layers above declare their own in their
 * folders: passes/passes.h, reference/reference.h, stages/, auto/, opencl/). Not installed; prefix
 * rs_. */
#ifndef RSMOOTH_INTERNAL_H
#define RSMOOTH_INTERNAL_H

#include "rsmooth.h"

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* ---- status.c: error detail --------------------------------------------------------------------
 */

/* Resets `error` (if non-NULL) to success. */
void rs_error_clear(rsmooth_error *error);

/* Records a failure in `error` (if non-NULL) and returns `status`, so call sites read
 * `return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, "rsmooth_smooth", "sigma_f %g <= 0", s);`
 */
rsmooth_status rs_fail(rsmooth_error *error, rsmooth_status status, const char *where,
                       const char *format, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;

/* As rs_fail, for parse errors: also records the line (-1 if unknown) and byte offset (-1). */
rsmooth_status rs_fail_parse(rsmooth_error *error, int64_t line, int64_t byte_offset,
                             const char *where, const char *format, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 5, 6)))
#endif
    ;

/* ---- alloc.c: the one allocation pair (a per-object allocator can replace it later) -----------
 */

/* count * size bytes, NULL on overflow or failure. Never call with both 0 expecting non-NULL use.
 */
void *rs_alloc_array(size_t count, size_t size);
/* Same, zero-filled. */
void *rs_calloc_array(size_t count, size_t size);
void *rs_realloc_array(void *ptr, size_t count, size_t size);
void rs_free(void *ptr);
/* Hands memory freed inside the C library's heap back to the system (glibc keeps what it freed
 * resident otherwise, so a program calling the filter repeatedly would grow by the arrays of its
 * largest call). Called once at the end of each filter call. */
void rs_release_free_memory(void);

/* true when a * b overflows size_t. */
static inline bool rs_mul_overflows(size_t a, size_t b) {
    return b != 0 && a > SIZE_MAX / b;
}

/* Monotonic clock in milliseconds. */
double rs_now_ms(void);

/* ---- file_io.c: whole positioned reads and writes ----------------------------------------------
 */

/* Writes or reads all n bytes at `offset` (EINTR and short counts retried); false with errno on
 * failure (EIO: the file ended first). */
bool rs_pwrite_all(int fd, const void *data, size_t n, uint64_t offset);
bool rs_pread_all(int fd, void *data, size_t n, uint64_t offset);

/* ---- parallel.c: host loops on every core ------------------------------------------------------
 */

/* Elements [begin, end) of a loop, as chunk number `chunk` (chunks are contiguous and in order). */
typedef void (*rs_range_fn)(void *ctx, size_t begin, size_t end, size_t chunk);

/* Threads host loops use: the calling thread's setting (rs_set_call_threads), else
 * RSMOOTH_HOST_THREADS, else the online cores; at most 64. */
size_t rs_host_threads(void);

/* Sets the host threads of the calling thread's rsmooth calls (0: the default above) and returns
 * the setting it replaces: a context's calls run with its options' host_threads
 * (api/device_pass.c). */
size_t rs_set_call_threads(size_t threads);

/* How many chunks rs_parallel_for cuts `count` elements into (at least min_per_chunk each). */
size_t rs_parallel_chunks(size_t count, size_t min_per_chunk);

/* Runs fn over [0, count) in rs_parallel_chunks(count, min_per_chunk) chunks at once and returns
 * when all are done. The split depends only on the count and the thread count, so per-chunk
 * results combined in chunk order are the same on every run. */
void rs_parallel_for(size_t count, size_t min_per_chunk, rs_range_fn fn, void *ctx);

/* ---- sort.c ------------------------------------------------------------------------------------
 */

/* Stable LSD radix sort of `keys` carrying `values` along. Returns false when scratch memory cannot
 * be allocated (arrays unchanged then). */
bool rs_radix_sort_u64(uint64_t *keys, uint32_t *values, size_t count);

/* ---- params.c ----------------------------------------------------------------------------------
 */

/* Most bilateral rounds and filter passes one call may ask for. */
#define RS_MAX_ROUNDS 100
#define RS_MAX_CYCLES 1000 /* the normal update stage's cycles */
/* Most normal-stage vertex updates one call may ask for. */
#define RS_MAX_UPDATES 1000

/* Copies the caller's params (NULL: defaults) into `out`, filling fields newer than the caller's
 * struct_size with defaults, and checks every value. */
rsmooth_status rs_params_resolve(const rsmooth_params *params, rsmooth_params *out,
                                 rsmooth_error *error, const char *where);

/* ---- mesh.c: the validated problem both paths solve -------------------------------------------
 */

/* A facet is a triangle of non-zero area; zero-area triangles carry no weight and are left out.
 * Every length in a problem is in internal units: the caller's times `scale` (scale.c). */
typedef struct rs_problem {
    size_t vertex_count;
    double scale; /* internal units per caller unit: a power of two */
    double *xyz;  /* 3 * vertex_count, the input in double, times `scale` (owned) */
    size_t triangle_count;
    const uint32_t *indices; /* borrowed from the caller */
    size_t facet_count;
    uint32_t *facet_triangle; /* triangle index of each facet */
    /* Kept only when asked (the reference path); the OpenCL path computes them where it needs
     * them (rs_facet_centroid, rs_triangle_normal), which saves 56 bytes per triangle. */
    double *centroid; /* 3 per facet: c_q */
    double *normal;   /* 3 per facet: unit n_q of the input */
    double *area;     /* per facet: a_q > 0 */
    double mean_edge_length;
    double mean_area; /* of the facets (a tile keeps its whole mesh's) */
    /* absolute parameters, mesh units */
    double sigma_f, sigma_g; /* sigma_g is +INFINITY when the influence weight is off */
    double sigma_m;          /* mollification width: sigma_f / 2 */
    double radius;           /* cutoff * sigma_f: reach of the robust pass */
    double mollify_radius;   /* reach of the mollification pass (<= radius) */
    bool mollify;            /* false also when the predictor needs no normals (centroid) */
    bool predict_centroid;   /* predict c_q instead of Pi_q(p) */
    bool bilateral;          /* with `mollify`: bilateral normal filter instead of the paper's */
    double normal_sigma_s;   /* bilateral spatial width, mesh units */
    double normal_sigma_n;   /* bilateral width on normal differences */
    double normal_radius;    /* bilateral reach: cutoff * normal_sigma_s (0 when off) */
    int normal_iterations;
    int influence; /* an rsmooth_influence */
    /* The colour factor of the robust weight (rsmooth_params.colors), NULL when off: */
    const float *colors;          /* 3 per vertex, borrowed (a tile's: its own copy) */
    double *facet_color;          /* 3 per facet, the mean of its corners' colours; kept with the
                                   * facet data (reference path), owned */
    double sigma_c;               /* colour width, finite when colors is not NULL */
    rsmooth_progress_fn progress; /* optional, from the params */
    rsmooth_progress_cancel_fn progress_cancel; /* optional, from the params */
    void *progress_user;
} rs_problem;

/* Reports progress `fraction` to whichever callbacks the caller gave; false when the caller asks
 * to stop (then the path returns rs_cancelled's status). */
static inline bool rs_progress(const rs_problem *problem, double fraction) {
    if (problem->progress)
        problem->progress(problem->progress_user, fraction);
    return !problem->progress_cancel ||
           problem->progress_cancel(problem->progress_user, fraction) == 0;
}

/* RSMOOTH_ERROR_CANCELLED, said so in `error`. */
rsmooth_status rs_cancelled(rsmooth_error *error, const char *where);

/* Given as out_positions to rs_problem_prepare_within by a caller that checked its own outputs (a
 * piece writes fewer vertices than it reads). */
extern const char rs_unchecked_output[1];
#define RS_UNCHECKED_OUTPUT ((const void *)rs_unchecked_output)

/* One pass's problem, for a path's pass function (rs_filter_fn): converts positions to double,
 * finds the facets, computes the mean edge length and area and the absolute parameters, and with
 * keep_facet_data the facets' centroids, normals and areas. The arrays, outputs and colours were
 * checked once, at the call's entry (rs_filter_passes): only the coordinates are read again, for
 * their magnitude (a pass after the first reads the previous pass's). */
rsmooth_status rs_problem_prepare(rs_problem *problem, rsmooth_scalar scalar, const void *positions,
                                  size_t vertex_count, const uint32_t *indices,
                                  size_t triangle_count, const rsmooth_params *params,
                                  bool keep_facet_data, rsmooth_error *error, const char *where);

/* rs_problem_prepare for a piece of a larger mesh, an entry point of its own: checks every
 * argument (nothing is written on failure). The whole mesh's figures stand in for the problem's
 * own (its mean edge length and mean area are not computed), and its scale is used unless it is 0
 * or would put a coordinate beyond 2^500 (then the problem chooses its own, as rs_problem_prepare
 * does; the figures are converted exactly either way). */
rsmooth_status rs_problem_prepare_within(rs_problem *problem, rsmooth_scalar scalar,
                                         const void *positions, size_t vertex_count,
                                         const uint32_t *indices, size_t triangle_count,
                                         const rsmooth_params *params, const void *out_positions,
                                         bool keep_facet_data, const rsmooth_piece_info *whole,
                                         rsmooth_error *error, const char *where);

/* The params-to-problem part of rs_problem_prepare: the absolute widths and radii (relative
 * sigmas times `unit`, the mean edge length or, for point clouds, the point spacing; 1 when
 * params->absolute) and the flags, from resolved params. Sets facet_count to 0 when nothing can
 * move (unit 0). Point clouds (points.c) call it on a problem whose facets are the points.
 * RSMOOTH_ERROR_INVALID_ARGUMENT when a width times the unit overflows (a reach of +inf would
 * leave every vertex where it is, as if nothing could move). */
rsmooth_status rs_problem_apply_params(rs_problem *problem, const rsmooth_params *params,
                                       double unit, rsmooth_error *error, const char *where);

/* Checks rsmooth_params.colors, 3 finite values per vertex of magnitude <= RS_MAX_COLOR, naming
 * the first vertex that fails. NULL passes. */
rsmooth_status rs_check_colors(const float *colors, size_t vertex_count, rsmooth_error *error,
                               const char *where);

/* Mean colour of the triangle with vertex indices tri[0..2]: the C_q of the colour factor. */
static inline void rs_triangle_color(const float *colors, const uint32_t *tri, double out[3]) {
    for (int k = 0; k < 3; k++)
        out[k] = ((double)colors[3 * (size_t)tri[0] + k] + (double)colors[3 * (size_t)tri[1] + k] +
                  (double)colors[3 * (size_t)tri[2] + k]) /
                 3.0;
}

/* Unit normal and area of the triangle with vertex indices tri[0..2] over `xyz`; false (outputs
 * unset) when its area is zero or not finite. rs_triangle_geometry's, for a caller that has the
 * centroid already. */
bool rs_triangle_normal(const double *xyz, const uint32_t *tri, double normal[3], double *area);

/* Centroid, unit normal and area of the triangle with vertex indices tri[0..2] over `xyz`; false
 * (outputs unset) when its area is zero or not finite. The one formula every path uses. */
bool rs_triangle_geometry(const double *xyz, const uint32_t *tri, double centroid[3],
                          double normal[3], double *area);

/* Adds each triangle's cross product (twice its area times its unit normal) to its corners' sums
 * in `normal` (3 per vertex), in triangle order; corner v adds at rep[v] where rep is not NULL
 * (welded vertices). Area-weighted vertex normals, once normalised. */
void rs_add_area_normals(const double *xyz, const uint32_t *indices, size_t triangle_count,
                         const uint32_t *rep, double *normal);

/* The centroid alone, as rs_triangle_geometry computes it. */
static inline void rs_triangle_centroid(const double *xyz, const uint32_t *tri,
                                        double centroid[3]) {
    const double *a = xyz + 3 * (size_t)tri[0], *b = xyz + 3 * (size_t)tri[1];
    const double *c = xyz + 3 * (size_t)tri[2];
    for (int k = 0; k < 3; k++)
        centroid[k] = (a[k] + b[k] + c[k]) / 3.0; /* exact where the coordinates are equal */
}

/* The centroid of facet q of a problem. */
static inline void rs_facet_centroid(const rs_problem *problem, size_t q, double centroid[3]) {
    rs_triangle_centroid(problem->xyz, problem->indices + 3 * (size_t)problem->facet_triangle[q],
                         centroid);
}
void rs_problem_free(rs_problem *problem);

/* Bytes of one vertex's x, y, z in the caller's scalar type. */
static inline size_t rs_vertex_bytes(rsmooth_scalar scalar) {
    return 3 * (scalar == RSMOOTH_FLOAT32 ? sizeof(float) : sizeof(double));
}

/* Whether two byte ranges overlap: neither ends before the other begins (NULL overlaps nothing).
 * Outputs against inputs and each other. */
static inline bool rs_ranges_overlap(const void *a, size_t a_size, const void *b, size_t b_size) {
    const char *pa = a, *pb = b;
    return pa && pb && pa < pb + b_size && pb < pa + a_size;
}

/* Coordinate i (x, y, z of vertex i / 3) of the caller's positions, as a double. */
static inline double rs_coordinate(rsmooth_scalar scalar, const void *positions, size_t i) {
    return scalar == RSMOOTH_FLOAT32 ? (double)((const float *)positions)[i]
                                     : ((const double *)positions)[i];
}

/* Checks the outputs of a smoothing call: out_positions present, and every output (those not
 * NULL) clear of every input (positions, indices, and the params' colours and move mask when
 * params is not NULL) and of each other: none may share a byte, since the filter reads all inputs
 * while writing. */
rsmooth_status rs_check_outputs(rsmooth_scalar scalar, const void *positions, size_t vertex_count,
                                const uint32_t *indices, size_t triangle_count,
                                const rsmooth_params *params, const void *out_positions,
                                const float *out_weight, const float *out_confidence,
                                rsmooth_error *error, const char *where);

/* Checks that the 3 * count coordinates are finite and within RS_MAX_COORDINATE; a failure names
 * the offending `noun` ("vertex", "point") by index. Writes the largest |coordinate| to
 * *magnitude when it is not NULL. */
rsmooth_status rs_check_coordinates(rsmooth_scalar scalar, const void *positions, size_t count,
                                    const char *noun, double *magnitude, rsmooth_error *error,
                                    const char *where);

/* Checks the arrays only (shared with rsmooth_mean_edge_length); *magnitude (optional) as
 * rs_check_coordinates gives it. */
rsmooth_status rs_check_mesh_arrays(rsmooth_scalar scalar, const void *positions,
                                    size_t vertex_count, const uint32_t *indices,
                                    size_t triangle_count, double *magnitude, rsmooth_error *error,
                                    const char *where);

/* rs_check_mesh_arrays without the coordinates: the scalar type, positions present, the counts,
 * indices present and in range. For calls that check several position arrays over one index
 * array (rsmooth_compare), each with rs_check_coordinates naming its own. */
rsmooth_status rs_check_mesh_structure(rsmooth_scalar scalar, const void *positions,
                                       size_t vertex_count, const uint32_t *indices,
                                       size_t triangle_count, rsmooth_error *error,
                                       const char *where);

/* rsmooth_mean_edge_length of arrays whose structure was checked (the coordinates are read:
 * their magnitude sets the scale); errors name `where`. */
rsmooth_status rs_mesh_mean_edge(rsmooth_scalar scalar, const void *positions, size_t vertex_count,
                                 const uint32_t *indices, size_t triangle_count, double *out_length,
                                 rsmooth_error *error, const char *where);

/* Mean length of unique undirected edges over `xyz` (double). false on allocation failure. */
bool rs_mean_edge_length(const double *xyz, size_t vertex_count, const uint32_t *indices,
                         size_t triangle_count, double *out_length);
/* The same over the edges no longer than `limit` (INFINITY: every edge, the same bits). */
bool rs_mean_edge_length_below(const double *xyz, size_t vertex_count, const uint32_t *indices,
                               size_t triangle_count, double limit, double *out_length);

/* Geometry helpers shared by the reference path and the host side of the OpenCL path. */
static inline double rs_dot3(const double a[3], const double b[3]) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
static inline void rs_sub3(const double a[3], const double b[3], double out[3]) {
    out[0] = a[0] - b[0];
    out[1] = a[1] - b[1];
    out[2] = a[2] - b[2];
}
static inline void rs_cross3(const double a[3], const double b[3], double out[3]) {
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}
static inline void rs_scale3(double v[3], double s) {
    v[0] *= s;
    v[1] *= s;
    v[2] *= s;
}

/* A mollified facet is degenerate, and its input normal is used instead, when the sine of its
 * corner angle falls below RS_DEGENERATE_SINE or its area shrank below RS_DEGENERATE_AREA_RATIO of
 * the input facet's (an isolated triangle collapses onto its centroid; what remains of its edges is
 * rounding noise, float32's included). Shared by both paths so they decide alike. */
#define RS_DEGENERATE_SINE 1e-6
#define RS_DEGENERATE_AREA_RATIO 1e-5

/* Coordinates beyond this magnitude are refused: squared distances must not overflow a double. */
#define RS_MAX_COORDINATE 1e150
/* Colour components beyond this are refused: squared colour differences must stay finite in the
 * kernels' float32. */
#define RS_MAX_COLOR 1e15

/* When k(p) falls below this fraction of sum a f, the influence weights have underflowed (float32
 * bottoms out near 1e-38): both paths then recompute the sums with the exponent shifted by its
 * smallest value, so the result is the mathematically defined weighted average. */
#define RS_UNDERFLOW_RATIO 1e-30

/* ---- scale.c: internal units ------------------------------------------------------------------
 */

/* The power of two both paths multiply coordinates by (and divide results by), chosen so a
 * typical edge (of sampled triangles; for points, the distance between consecutive points) is
 * about 1 long while the largest coordinate, `magnitude` (rs_check_coordinates), stays below
 * 2^500. Exact, so results do not depend on it. RSMOOTH_ERROR_INVALID_ARGUMENT when no power of
 * two fits both (a coordinate more than about 1e225 typical edges from the origin). */
rsmooth_status rs_mesh_scale(rsmooth_scalar scalar, const void *positions, const uint32_t *indices,
                             size_t triangle_count, double magnitude, double *scale,
                             rsmooth_error *error, const char *where);
rsmooth_status rs_points_scale(rsmooth_scalar scalar, const void *positions, size_t count,
                               double magnitude, double *scale, rsmooth_error *error,
                               const char *where);

/* Whether `scale` is one rs_mesh_scale can choose: a power of two in [2^-500, 2^1000] (the
 * exponents its choice spans for coordinates within RS_MAX_COORDINATE). */
bool rs_scale_possible(double scale);

/* The typical edge length rs_mesh_scale brings near 1: the geometric mean of the (Chebyshev)
 * lengths of one edge of each sampled triangle, in the caller's units; 0 when all are 0. */
double rs_typical_edge(rsmooth_scalar scalar, const void *positions, const uint32_t *indices,
                       size_t triangle_count);

/* Caller's coordinates -> internal units: out[i] = coordinate i times `scale`, i < 3 count. */
void rs_scale_positions(rsmooth_scalar scalar, const void *positions, size_t count, double scale,
                        double *out);

/* ---- results.c: what a call writes ----------------------------------------------------------- */

/* k(p) (internal area units) as the float out_weight holds, in the caller's area units; NaN
 * when it exceeds FLT_MAX (rs_check_results then fails the call). */
float rs_weight_value(double k, double unscale);

/* Checks a call's outputs before it returns RSMOOTH_OK: every position and weight finite in the
 * caller's type (a float32 result beyond FLT_MAX, or k(p) of a mesh whose areas exceed float's
 * range, is RSMOOTH_ERROR_NUMERICAL naming the vertex) and every confidence in [0, 1]. Any array
 * but out_positions may be NULL. */
rsmooth_status rs_check_results(rsmooth_scalar scalar, const void *out_positions,
                                const float *out_weight, const float *out_confidence, size_t count,
                                const char *noun, rsmooth_error *error, const char *where);

/* Writes the result for vertex v (double xyz, internal units) into the caller's array of type
 * `scalar`, times `unscale` (1 / the problem's scale; 1 for values in the caller's units). */
void rs_store_position(rsmooth_scalar scalar, void *out_positions, size_t v, const double p[3],
                       double unscale);

/* Writes the first `count` vertices unmoved, with zero weight and confidence: the result when no
 * facet carries weight (no triangles, or all of zero area). */
void rs_store_unmoved(const rs_problem *problem, size_t count, rsmooth_scalar scalar,
                      void *out_positions, float *out_weight, float *out_confidence);

/* Copies `full` into a caller's report as far as its struct_size says it holds (a size some
 * version's struct had, else, a struct never initialised, this version's whole struct), and
 * keeps that struct_size. */
void rs_give_report(rsmooth_report *report, size_t struct_size, const rsmooth_report *full);

/* A caller's struct that starts with its struct_size (options, outputs): as much of it as that
 * size holds (0 reads as `full`), the rest zero, into out[full], whose struct_size becomes
 * `full`; `given` NULL: all zero. false, with *out all zero, for a struct_size too small to hold
 * itself. */
bool rs_read_sized(const void *given, void *out, size_t full);

/* The caller's outputs (NULL: none), as much as its struct_size holds, the rest NULL. */
rsmooth_status rs_read_outputs(const rsmooth_outputs *given, rsmooth_outputs *out,
                               rsmooth_error *error, const char *where);

/* `from`'s stage times and pairs added to `to`'s, and the larger tile count: what every sum of
 * reports (passes, parts) adds alike. */
void rs_add_report_times(rsmooth_report *to, const rsmooth_report *from);

/* A part's report into the call's (`first`: the first part, which it replaces): times and work
 * summed, widths, unit and device from the `largest` part (meshes' and point clouds' alike). */
void rs_add_part_report(rsmooth_report *sum, const rsmooth_report *part, bool largest, bool first);

/* Fills the parts of a report both paths share (lengths in the caller's units). */
void rs_report_problem(rsmooth_report *report, const rs_problem *problem, size_t cell_count,
                       const char *device);
/* Multiplies a report's lengths by `unscale`: internal units to the caller's. */
void rs_report_unscale(rsmooth_report *report, double unscale);

/* The public functions' bodies, for api/'s definitions of them (lib/api/): */
/* rsmooth_status_str */
const char *rs_status_str(rsmooth_status status);
/* rsmooth_error_init */
void rs_error_init(rsmooth_error *error);
/* rsmooth_params_init_best */
rsmooth_status rs_params_init_best(rsmooth_params *params);
/* rsmooth_params_init */
rsmooth_status rs_params_init(rsmooth_params *params);
/* rsmooth_report_init */
void rs_report_init(rsmooth_report *report);
/* rsmooth_mean_edge_length */
rsmooth_status rs_mesh_mean_edge_length(rsmooth_scalar scalar, const void *positions,
                                        size_t vertex_count, const uint32_t *indices,
                                        size_t triangle_count, double *out_length,
                                        rsmooth_error *error);

#endif /* RSMOOTH_INTERNAL_H */
