/** @file
 * rsmooth: feature-preserving, non-iterative smoothing of triangle meshes on OpenCL devices.
 *
 * Implements Jones, Durand and Desbrun, "Non-Iterative, Feature-Preserving Mesh Smoothing",
 * ACM SIGGRAPH 2003. Every vertex p moves to a robust, weighted average of its projections onto the
 * planes of nearby triangles q (Eq. 3 of the paper):
 *
 *     p' = sum_q Pi_q(p) a_q f(|c_q - p|) g(|Pi_q(p) - p|) / k(p),   k(p) = sum_q a_q f g
 *
 * with c_q the centroid, a_q the area, Pi_q(p) the projection of p onto the plane of q (whose
 * normal comes from a "mollified" copy of the mesh, smoothed by a plain Gaussian of width sigma_f /
 * 2), f a spatial Gaussian of width sigma_f and g an influence Gaussian of width sigma_g. Gaussians
 * are exp(-x^2 / (2 sigma^2)). Facets whose centroid lies farther than cutoff * sigma_f are
 * ignored. One pass, no iteration and no connectivity: triangle soups, non-manifold and cracked
 * meshes work.
 *
 * Beyond the paper, each optional (the defaults are the paper's filter, unchanged): bilateral
 * filtering of the facet normals instead of mollification, repeated and confidence-driven passes,
 * Tukey / Lorentzian / Huber influence functions, a colour term in the influence weight
 * (rsmooth_params), automatic parameters from the estimated noise (rsmooth_params_auto), and
 * point clouds with normals (rsmooth_smooth_points). rsmooth_params_init_best is the
 * most accurate preset measured. rsmooth_compare measures a result against its ground truth (the
 * error metrics `rsmooth compare` prints).
 *
 * Usage sketch (arrays in, arrays out; the caller owns every array):
 *
 *     rsmooth_params params;
 *     rsmooth_params_init(&params);             // sigma_f = 2, sigma_g = 0.5 mean edge lengths
 *     params.sigma_f = 1.5;
 *     rsmooth_context *ctx = NULL;   // stays NULL without OpenCL: the reference path
 *     rsmooth_error err;
 *     rsmooth_context_create(NULL, &ctx, &err);   // NULL: default options
 *     rsmooth_smooth(ctx, RSMOOTH_FLOAT32, xyz, vertex_count, indices, triangle_count, &params,
 *                    out_xyz, NULL, &err);        // NULL: no weights, confidence or report
 *     rsmooth_context_destroy(ctx);
 *
 * Interoperation with a caller's own OpenCL queue lives in rsmooth_cl.h, so this header needs no
 * OpenCL headers.
 */
#ifndef RSMOOTH_H
#define RSMOOTH_H

#include <stddef.h>
#include <stdint.h>

/** @def RSMOOTH_VERSION_MAJOR
 * The major version of this header (CMake reads the version from these three lines); compare with
 * rsmooth_version(), the library's. */
/** @def RSMOOTH_VERSION_MINOR
 * The minor version of this header: while the major version is 0, each minor version has its own
 * ABI (soname librsmooth.so.0.MINOR). */
/** @def RSMOOTH_VERSION_PATCH
 * The patch version of this header: fixes within one ABI. */
#define RSMOOTH_VERSION_MAJOR 0
#define RSMOOTH_VERSION_MINOR 11
#define RSMOOTH_VERSION_PATCH 0

/** @def RSMOOTH_API
 * Marks the library's exported functions: default visibility (the library is built with hidden
 * visibility), and on Windows dllexport / dllimport for a shared build (RSMOOTH_SHARED, which the
 * CMake target and rsmooth.pc define for a shared library). */
#if defined(_WIN32)
#if defined(RSMOOTH_BUILDING_LIBRARY) && defined(RSMOOTH_SHARED)
#define RSMOOTH_API __declspec(dllexport)
#elif defined(RSMOOTH_SHARED)
#define RSMOOTH_API __declspec(dllimport)
#else
#define RSMOOTH_API
#endif
#else
#define RSMOOTH_API __attribute__((visibility("default")))
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* ---------------------------------------------------------------------------------------------- */
/* Status and error detail */
/* ---------------------------------------------------------------------------------------------- */

/** Every call that can fail returns one of these; RSMOOTH_OK (0) is success. They name classes of
 * failure; the optional rsmooth_error carries the detail. */
typedef enum rsmooth_status {
    RSMOOTH_OK = 0,                     /**< success */
    RSMOOTH_ERROR_INVALID_ARGUMENT = 1, /**< NULL array, index out of range, bad sigma,
                                         * non-finite... */
    RSMOOTH_ERROR_OUT_OF_MEMORY = 2,    /**< host allocation failed, or a size overflows size_t */
    RSMOOTH_ERROR_IO = 3,               /**< a file could not be opened, read or written */
    RSMOOTH_ERROR_PARSE = 4,            /**< a mesh file is malformed */
    RSMOOTH_ERROR_NO_DEVICE = 5,        /**< no OpenCL loader or platform, or no device matches the
                                         * choice */
    RSMOOTH_ERROR_KERNEL_BUILD = 6,     /**< the OpenCL program failed to build (see build_log) */
    RSMOOTH_ERROR_OPENCL = 7,           /**< an OpenCL call failed (see cl_error and where) */
    RSMOOTH_ERROR_UNSUPPORTED = 8,      /**< valid request this build or device cannot do */
    RSMOOTH_ERROR_NUMERICAL = 9,        /**< a result would not be finite in the output's type (a
                                         * float32 position beyond FLT_MAX, k(p) beyond float's
                                         * range): nothing non-finite is ever returned as OK.
                                         * (Added in 0.4.1) */
    RSMOOTH_ERROR_CANCELLED = 10        /**< the caller's progress_cancel callback asked to stop
                                         * (Added in 0.5) */
} rsmooth_status;

/** Static, human-readable text for a status. Never NULL; thread-safe. */
RSMOOTH_API const char *rsmooth_status_str(rsmooth_status status);

/** The version of the library actually loaded, "MAJOR.MINOR.PATCH" (compare with the
 * RSMOOTH_VERSION_* macros of the header a program was built with: while the major version is 0,
 * a different MINOR means a different ABI). Writes the three numbers to those pointers that are
 * not NULL. Thread-safe. (Added in 0.5) */
RSMOOTH_API const char *rsmooth_version(int *major, int *minor, int *patch);

/** @page struct_size Struct sizes and library versions
 * Structs the caller allocates and the library fills (rsmooth_error, rsmooth_report,
 * rsmooth_device_info) start with struct_size, as rsmooth_params does: set it with the struct's
 * _init function (or to sizeof the struct), and a later version of the library writes only the
 * fields a struct of that size has, so a program built against this header keeps working with a
 * newer library of the same soname. The library never changes struct_size. A value that is no
 * size any version had (a struct never initialised) is taken as this version's layout, 0.5's, the
 * first with struct_size. (Added in 0.5) */

/** Optional detail of a failure, filled by any call given a non-NULL pointer to one. On success it
 * is reset (status RSMOOTH_OK, empty strings). The library never prints: callers show these
 * fields. */
typedef struct rsmooth_error {
    size_t struct_size;    /**< sizeof(rsmooth_error): rsmooth_error_init */
    rsmooth_status status; /**< the status the call returned (RSMOOTH_OK after a success) */
    int cl_error;          /**< raw cl_int of the failing OpenCL call, 0 if none */
    char where[64];        /**< failing function, OpenCL call or kernel, e.g.
                            * "clEnqueueNDRangeKernel" */
    char message[256];     /**< one sentence on what went wrong, e.g. "index 7 >= vertex count 5" */
    int64_t line;          /**< parse errors: 1-based line (text formats), else -1 */
    int64_t byte_offset;   /**< parse errors: byte offset of the offending token, else -1 */
    char build_log[2048];  /**< kernel build failures: the head of the OpenCL build log */
} rsmooth_error;

/** Zeroes `error` and sets its struct_size. Accepts NULL. (Added in 0.5) */
RSMOOTH_API void rsmooth_error_init(rsmooth_error *error);

/* ---------------------------------------------------------------------------------------------- */
/* Parameters */
/* ---------------------------------------------------------------------------------------------- */

/** The type of the coordinates in the caller's position arrays (inputs and outputs alike). */
typedef enum rsmooth_scalar {
    RSMOOTH_FLOAT32 = 0, /**< positions are float[3] per vertex */
    RSMOOTH_FLOAT64 = 1  /**< positions are double[3] per vertex (georeferenced scans, CAD in
                          * mm...) */
} rsmooth_scalar;

/** Progress of a long filter call: `fraction` of the work done, in [0, 1], non-decreasing. Called
 * on the calling thread between pieces of work (the OpenCL path then launches its kernels in
 * slices, which does not change the result). */
typedef void (*rsmooth_progress_fn)(void *user, double fraction);

/** The same report, answered: return 0 to go on, non-zero to stop the call, which then returns
 * RSMOOTH_ERROR_CANCELLED at once (the OpenCL path after the kernel slice under way; reports come
 * every 1/32 of a kernel launch, every 4096 vertices on the reference path). The outputs are
 * then undefined: they may be partly written. This is how a host application offers a Cancel
 * button, or a Python binding lets Ctrl-C through. Called on the calling thread. */
typedef int (*rsmooth_progress_cancel_fn)(void *user, double fraction);

/** What each nearby triangle q predicts for a vertex p. */
typedef enum rsmooth_predictor {
    RSMOOTH_PREDICT_PROJECTION = 0, /**< Pi_q(p), p projected onto q's (mollified) plane: the
                                     * paper */
    RSMOOTH_PREDICT_CENTROID = 1    /**< c_q, q's centroid: with sigma_g = +INFINITY this is plain
                                     * isotropic Gaussian smoothing (the paper's Fig. 4 baseline);
                                     * the influence, if on, weighs |c_q - p| */
} rsmooth_predictor;

/** How the normals of the predictors' planes are made. */
typedef enum rsmooth_normal_filter {
    RSMOOTH_NORMALS_MOLLIFY = 0,  /**< the paper (Sec. 3.2): the normals of a copy of the mesh whose
                                   * vertices moved to the Gaussian average (width sigma_f / 2) of
                                   * nearby centroids */
    RSMOOTH_NORMALS_BILATERAL = 1 /**< bilateral filter on the facet normals themselves, repeated
                                   * normal_iterations times: n_r <- normalise(sum_q a_q
                                   * exp(-|c_q - c_r|^2 / 2 s^2) exp(-|n_q - n_r|^2 / 2 t^2) n_q), s
                                   * = normal_sigma_s, t = normal_sigma_n, facets within cutoff * s
                                   * (Zheng et al. 2011). Keeps creases the Gaussian rounds */
} rsmooth_normal_filter;

/** The robust weight g of a prediction at distance x from the vertex (Black et al. 1998), all
 * scaled by sigma_g so that outliers start being rejected near it. */
typedef enum rsmooth_influence {
    RSMOOTH_INFLUENCE_GAUSSIAN = 0,   /**< exp(-x^2 / 2 sigma_g^2): the paper */
    RSMOOTH_INFLUENCE_TUKEY = 1,      /**< Tukey's biweight (1 - x^2 / c^2)^2 for x < c = sqrt(5)
                                       * sigma_g, else 0: far outliers get no weight at all */
    RSMOOTH_INFLUENCE_LORENTZIAN = 2, /**< 1 / (1 + x^2 / sigma_g^2): heavy tails, never zero */
    RSMOOTH_INFLUENCE_HUBER = 3       /**< min(1, sigma_g / x): least squares near, L1 far */
} rsmooth_influence;

/** Filter parameters. Fill with rsmooth_params_init() first, then change fields: struct_size lets
 * later versions add fields without breaking callers compiled against this one. */
typedef struct rsmooth_params {
    size_t struct_size;    /**< sizeof(rsmooth_params), set by rsmooth_params_init */
    double sigma_f;        /**< spatial width: how far a triangle's influence reaches. In mean edge
                            * lengths unless `absolute`. > 0 and finite. Default 2. */
    double sigma_g;        /**< influence width: how far a predicted position may be from the vertex
                            * before it counts as an outlier (a feature on the other side). Same
                            * units as sigma_f. > 0; +INFINITY turns the influence weight off.
                            * Default 0.5. */
    int absolute;          /**< 0: sigmas in mean edge lengths (default); 1: in the mesh's units */
    double cutoff;         /**< facets farther than cutoff * sigma_f are ignored. (0, 5]. Default
                            * 2 */
    double mollify_cutoff; /**< mollification radius in units of sigma_f, (0, cutoff]; 0 (default)
                            * means the same radius as `cutoff` (the published setting) */
    int mollify;           /**< 1 (default): predict with mollified normals; 0: with the input's own
                            * (the paper's Fig. 4 ablation) */
    rsmooth_progress_fn progress; /**< optional (NULL, default): progress reports */
    void *progress_user;          /**< passed to `progress` unchanged */
    int predictor;                /**< an rsmooth_predictor; default RSMOOTH_PREDICT_PROJECTION.
                                   * (Added in 0.2: callers with an older struct_size get the
                                   * default.) */
    /** @name Beyond the paper
     * Beyond the paper (added in 0.4; callers with an older struct_size get the defaults, which
     * are the paper's filter exactly). @{ */
    int normal_filter;      /**< an rsmooth_normal_filter: how the predictors' normals are
                             * smoothed when `mollify` is 1. Default
                             * RSMOOTH_NORMALS_MOLLIFY */
    double normal_sigma_s;  /**< bilateral: spatial width, units of sigma_f. Default 1 */
    double normal_sigma_n;  /**< bilateral: width on |n_q - n_r| between unit normals, (0, 2].
                             * Default 0.35 */
    int normal_iterations;  /**< bilateral: rounds, [1, 100]. Default 5 */
    int influence;          /**< an rsmooth_influence: the robust weight g. Default
                             * RSMOOTH_INFLUENCE_GAUSSIAN (the paper's) */
    int passes;             /**< the whole filter this many times, [0, 100], each pass from
                             * the previous pass's positions (sigmas stay those of the input).
                             * Default 1. 0: no pass; with vertex_updates > 0 the normal
                             * update stage alone, without it nothing at all (the input
                             * comes back, as rsmooth_params_auto sets on a mesh with
                             * nothing to remove; changed in 0.11). Weights are then 0 and
                             * confidences 1 */
    double pass_confidence; /**< 0 (default): every pass moves every vertex. In (0, 1]: passes
                             * after the first move only the vertices whose confidence in the
                             * previous pass was below this (low confidence: features and
                             * outliers, the paper's Sec. 5 suggestion) */
    /** @} */
    /** @name Colour in the influence weight
     * Colour in the influence weight (the paper's future work; added in 0.4). With a colour C_p
     * per vertex, the robust weight of facet q for vertex p gains the factor
     *     exp(-|C_q - C_p|^2 / (2 sigma_c^2)),   C_q = the mean colour of q's three vertices,
     * so a vertex is pulled mostly by triangles of its own colour: a colour edge (a painted line,
     * a texture seam, a material boundary in a scan) keeps its geometry as a sharp edge does. It
     * applies to the robust estimate (Eq. 3) only; the predictors' normals (mollification or the
     * bilateral filter) ignore colour. The confidence k / sum a f counts the factor in k only,
     * so it drops where neighbouring triangles differ in colour. For point clouds
     * (rsmooth_smooth_points) a point's own colour is its facet's C_q. @{ */
    const float *colors; /**< NULL (default): off. Else 3 * vertex_count floats, a colour
                          * per vertex (e.g. RGB in [0, 1]; any finite values of
                          * magnitude <= 1e15), in the positions' vertex order. Borrowed:
                          * read during the call only. A bad one is an
                          * RSMOOTH_ERROR_INVALID_ARGUMENT naming its vertex */
    double sigma_c;      /**< colour width, in the colours' units, > 0; +INFINITY turns the
                          * colour factor off (the result is then exactly that of colors
                          * = NULL). Default 0.1 */
    /** @} */
    rsmooth_progress_cancel_fn
        progress_cancel;      /**< optional (NULL, default): progress reports that
                               * may stop the call (see the type); called with progress_user,
                               * after `progress` when both are set. (Added in 0.5) */
    const uint8_t *move_mask; /**< NULL (default): every vertex moves. Else vertex_count bytes
                               * (points: point_count): a vertex whose byte is 0 keeps its
                               * input position bit for bit in every pass, while its triangles
                               * still support the others (smoothing a selection). Its weight
                               * and confidence are still computed. Borrowed. (Added in 0.5) */
    /** @name The normal update stage
     * The normal update stage (added in 0.6; off by default, so older callers and the paper's
     * filter are unchanged). With vertex_updates > 0, before the passes: the facet normals are
     * filtered by guided normal filtering (Zhang et al. 2015: a joint bilateral filter whose range
     * weight compares the mean normals of each facet's most consistent nearby patch, so creases
     * survive heavy noise), guided_rounds times, and then the vertices are moved to agree with
     * those normals by Sun et al. 2007's iterative update, vertex_updates times. The passes then
     * start from the updated positions. The filter and the update repeat stage_repeats cycles.
     * Runs on the device on GPUs and on the host's cores, in double, on CPU devices and on the
     * reference path (RSMOOTH_STAGE chooses: docs/environment.md). @{ */
    int vertex_updates;       /**< 0 (default): no stage. [1, 1000]: update iterations */
    double guided_sigma_s;    /**< spatial width of the guided filter's Gaussian, in mean edge
                               * lengths (absolute = 0) or mesh units (absolute = 1), > 0; its
                               * reach is guided_radius times the mean distance between the
                               * centroids of facets sharing an edge, so 2 (default) weighs
                               * the default reach nearly evenly */
    double guided_sigma_n;    /**< width on the difference of guidance normals, (0, 2].
                               * Default 0.2 */
    int guided_rounds;        /**< guided filter rounds, [1, 100]. Default 20 */
    int stage_repeats;        /**< the stage's cycles, [1, 1000]: each cycle reads fresh facet
                               * normals, areas and centroids from the current positions, runs
                               * guided_rounds rounds and then vertex_updates updates (the
                               * guided filter's authors run hundreds of cycles of one round
                               * and a few updates). What depends only on connectivity, and
                               * each facet's neighbour set, is built once on the input.
                               * Default 1 */
    double discrepancy_level; /**< 0 (default): off. > 0: the noise level, in mean edge lengths
                               * of the input (rsmooth_params_auto sets it to the estimate in
                               * the best mode): a choice per region. Taubin's lambda|mu
                               * smoothing (0.5, -0.53) of the input is run until the vertices
                               * moved (RMS) this far (the discrepancy principle, at most 40
                               * iterations), and each vertex's result is a blend of the
                               * filter's and Taubin's, the filter's weight rising with the
                               * share of its neighbourhood's facet pairs that meet within 2
                               * degrees in the filter's result (flat faces and creases: the
                               * filter's; curved at the scale of the triangles, as organic
                               * meshes coarse for their curvature: Taubin's). Boundary
                               * vertices then move at most this level (in their local edge
                               * length) from the input. Changed in 0.11: it swapped the
                               * whole mesh before. Needs connected triangles (a soup keeps
                               * the filter's result) */
    double discrepancy_gain;  /**< 0 (default): Taubin's side of discrepancy_level's choice stops
                               * when the vertices moved that level. > 0: it goes on until one
                               * more iteration adds less than this (mean edge lengths) to
                               * their RMS move: for spatially correlated noise (range
                               * scans), whose low frequencies the level alone stops short
                               * of; rsmooth_params_auto sets it where the noise reads
                               * correlated. (Added in 0.11) */
    double guided_radius;     /**< the guided filter's neighbourhood, in mean distances between
                               * the centroids of facets sharing an edge, [1, 8]. Default 2
                               * (the authors'); 3-4 holds creases better under heavy noise.
                               * (Added in 0.11) */
    /** @} */
    int guard; /**< 1 (default): do no harm. A triangle the filter would turn by
                * more than 90 degrees from the input's (unless the input had it
                * folded against its neighbours already) has its vertices pulled
                * back toward the input until none is reversed
                * (rsmooth_report.guarded_vertices counts them), and the normal
                * update stage does not run on a mesh whose noise estimate finds
                * nothing to remove (rsmooth_report.stage_skipped; not measured
                * when discrepancy_level gives the noise, as
                * rsmooth_params_auto sets it where it found some). 0: the filter
                * exactly as set (the paper's own, for comparisons). Parts and
                * outliers (rsmooth_report.parts) are kept apart either way.
                * (Added in 0.11) */
    /** @name Learned normals
     * What the normal update stage's vertex updates follow (added in 0.11; docs/model.md): the
     * guided filter's normals, or after the guided cycles the facet normals a small network
     * (trained on what those cycles leave of noisy copies of clean meshes) predicts from each
     * facet's 32 nearest facets, as the targets of vertex_updates more updates. Without the
     * stage (vertex_updates 0) there is nothing to follow and the field has no effect. @{ */
    int stage_normals; /**< an rsmooth_stage_normals. Default RSMOOTH_STAGE_NORMALS_GUIDED */
    const void *model; /**< NULL (default): the model built into the library. Else the
                        * bytes of a model file (docs/model.md, "The file"; borrowed, read
                        * during the call only): a file that is not a model, is truncated,
                        * damaged or of another descriptor layout is an
                        * RSMOOTH_ERROR_PARSE saying which */
    size_t model_size; /**< the model's size in bytes */
    /** @} */
} rsmooth_params;

/** What the normal update stage's cycles follow (rsmooth_params.stage_normals). */
typedef enum rsmooth_stage_normals {
    RSMOOTH_STAGE_NORMALS_GUIDED = 0, /**< guided normal filtering (Zhang et al. 2015) */
    RSMOOTH_STAGE_NORMALS_LEARNED = 1 /**< then the learned model's normals of the result, as
                                       * the targets of more vertex updates */
} rsmooth_stage_normals;

/** Fills `params` with the defaults above. Returns RSMOOTH_ERROR_INVALID_ARGUMENT if params is
 * NULL. */
RSMOOTH_API rsmooth_status rsmooth_params_init(rsmooth_params *params);

/** Fills `params` with rsmooth's most accurate mode, beyond the paper: the normal update stage
 * (10 cycles of one guided normal filtering round, radius 3, width 0.2, spatial width 1 mean
 * edge length, then 10 vertex updates), then one robust pass with bilateral normals at sigma_f
 * 0.8, sigma_g 0.3 (chosen on noisy meshes with a ground truth, docs/accuracy.md).
 * rsmooth_params_auto fits the stage to a mesh's noise and adds the choice per region. */
RSMOOTH_API rsmooth_status rsmooth_params_init_best(rsmooth_params *params);

/** Mean length of the mesh's unique undirected edges (an edge shared by two triangles counts once),
 * in the mesh's units: the unit of relative sigmas. Writes 0 when there is no edge of non-zero
 * length. Fails like rsmooth_smooth on bad arrays. Thread-safe. */
RSMOOTH_API rsmooth_status rsmooth_mean_edge_length(rsmooth_scalar scalar, const void *positions,
                                                    size_t vertex_count, const uint32_t *indices,
                                                    size_t triangle_count, double *out_length,
                                                    rsmooth_error *error);

/* ---------------------------------------------------------------------------------------------- */
/* Noise estimate */
/* ---------------------------------------------------------------------------------------------- */

/** What a learned model file holds (rsmooth_model_check; added in 0.11). */
typedef struct rsmooth_model_info {
    size_t struct_size;         /**< sizeof(rsmooth_model_info), set by the caller */
    int stages;                 /**< cascade stages */
    size_t parameters;          /**< weights and biases, every stage */
    unsigned format_version;    /**< the file's format version */
    unsigned layout;            /**< the descriptor layout it was trained on */
    unsigned char manifest[32]; /**< BLAKE2b-256 of the training data's manifest (train/) */
} rsmooth_model_info;

/** Checks that `bytes` (`size` of them) are a learned model this library can run
 * (rsmooth_params.model), filling `info` (may be NULL) when they are. RSMOOTH_ERROR_PARSE with a
 * message saying what is wrong (not a model, another format version or descriptor layout, cut
 * short, a checksum that does not match); RSMOOTH_ERROR_INVALID_ARGUMENT for NULL bytes or an
 * info whose struct_size is too small. NULL bytes with size 0 check the model built into the
 * library. Thread-safe. */
RSMOOTH_API rsmooth_status rsmooth_model_check(const void *bytes, size_t size,
                                               rsmooth_model_info *info, rsmooth_error *error);

/** Estimates the mesh's noise: the standard deviation of its vertices' displacement along the
 * surface normal, in mean edge lengths of the mesh as given (the unit of relative sigmas, as
 * rsmooth_mean_edge_length computes it), from the geometry alone. Each vertex (at most 6000, at a
 * fixed stride) is predicted by a quadric fitted to the other vertices within 2.5 mean edge
 * lengths; vertices whose neighbourhood is no quadric (sharp edges, corners) are screened out by
 * the fit's residual variance, and the noise is a robust scale (1.4826 x median) of the others'
 * standardised prediction errors. Gaussian noise of 0.1 to 0.7 mean edge lengths on smooth or
 * sharp-edged meshes of a few thousand vertices or more reads within about 5% of the truth;
 * impulsive noise (some vertices moved, the rest not) reads as the median vertex sees it, lower
 * than its standard deviation over all vertices. Writes 0 for a mesh with no edge of non-zero
 * length or too few vertices (about 10) to fit. Deterministic: the same result on every run and
 * with any thread count. Fails like rsmooth_mean_edge_length on bad arrays;
 * RSMOOTH_ERROR_OUT_OF_MEMORY. Thread-safe. */
RSMOOTH_API rsmooth_status rsmooth_estimate_noise(rsmooth_scalar scalar, const void *positions,
                                                  size_t vertex_count, const uint32_t *indices,
                                                  size_t triangle_count, double *out_noise,
                                                  rsmooth_error *error);

/** The kind of noise rsmooth_params_auto found in a mesh (added in 0.6). */
typedef enum rsmooth_noise_kind {
    RSMOOTH_NOISE_NONE = 0,     /**< nothing to remove: nothing measurable (too few vertices,
                                 * no edge), or roughness that reads as the mesh's own shape (a
                                 * clean mesh, however coarse; see shape_correlation). Changed in
                                 * 0.11: it meant only the former */
    RSMOOTH_NOISE_GAUSSIAN = 1, /**< every vertex displaced */
    RSMOOTH_NOISE_IMPULSIVE = 2 /**< a share of the vertices thrown, the others (nearly) exact */
} rsmooth_noise_kind;

/** What rsmooth_params_auto read from a mesh and chose (added in 0.6): set struct_size first. */
typedef struct rsmooth_noise_report {
    size_t struct_size;        /**< sizeof(rsmooth_noise_report), set by the caller */
    double level;              /**< rsmooth_estimate_noise's figure: the standard deviation of the
                                * displacement along the surface normal, in mean edge lengths of
                                * the clean mesh (impulsive: of the displaced vertices) */
    int kind;                  /**< an rsmooth_noise_kind */
    double impulsive_fraction; /**< the share of vertices displaced: 1 unless impulsive */
    double tangential_level;   /**< the displacement's standard deviation along one tangent
                                * direction, same unit (about `level` for noise in random
                                * directions, near 0 along the normals); NAN when not measured */
    double mean_edge_length;   /**< the clean mesh's, as estimated, in the mesh's units */
    char preset[32];           /**< the setting the rule chose, e.g. "best: mid" */
    char reason[192];          /**< why, in words, for printing */
    double correlated_level;   /**< the rms displacement along the normal including the noise's
                                * spatially correlated part (real range scans: ridges along the
                                * scan lines, waves of a few edges), which `level` (read over one
                                * or two rings) mostly misses; mean edge lengths of the clean
                                * mesh. Equal to `level` (its rms over all vertices for impulsive
                                * noise) when the noise reads uncorrelated. Read from residuals
                                * at radii 2 to 6 edges: noise correlated over more than about 1.5
                                * edges reads as shape, not noise (docs/accuracy.md). (Added in
                                * 0.11) */
    double correlation_length; /**< the correlated part's correlation length, mean edge lengths
                                * (about L for noise smoothed by a Gaussian of width L); 0 when
                                * the noise reads uncorrelated. (Added in 0.11) */
    double shape_correlation;  /**< how alike neighbouring vertices bend (the correlation of each
                                * vertex's umbrella offset along its normal with its neighbours'
                                * mean): 0.37-0.99 on clean meshes, at most 0.17 on noisy ones.
                                * At 0.3 or more the mesh reads clean: kind RSMOOTH_NOISE_NONE,
                                * nothing to remove. (Added in 0.11) */
    size_t parts;              /**< the mesh's parts (rsmooth_report.parts); the figures above are
                                * the largest's (Added in 0.11) */
    size_t outliers;           /**< vertices left out as outliers (rsmooth_report.outliers)
                                * (Added in 0.11) */
} rsmooth_noise_report;

/** Automatic parameters: estimates the mesh's noise (rsmooth_estimate_noise) and sets the fields
 * of `params` the rules chosen in docs/experiments.md (section 7; cross-validated, whole meshes
 * left out) give for it. `params` must be initialised first; it picks the rule:
 *   the paper's filter (rsmooth_params_init: normal_filter RSMOOTH_NORMALS_MOLLIFY and no
 *     vertex_updates): sigma_f = 0.6 + 1.6 n, sigma_g = 4 n for noise n in mean edge lengths;
 *   otherwise the best mode (rsmooth_params_init_best's setting): the guided filter's rounds by
 *     noise class (gentle, medium, strong; impulsive noise its own);
 *   either way, on a mesh that reads clean (its roughness is its own shape: see
 *     rsmooth_noise_report.shape_correlation), no pass and no stage (passes 0, vertex_updates 0),
 *     so the smoothing call returns the input as it is (added in 0.11).
 * The estimate reads the mesh's largest part, outliers left out (rsmooth_report.parts).
 * Sigmas are relative (absolute = 0 after the call). Other fields are left as they are.
 * `report` (optional, NULL: none) says what it read and chose: set its struct_size first,
 * `rsmooth_noise_report r = {.struct_size = sizeof r};` (its level is the estimate). Fails like
 * rsmooth_estimate_noise, and on invalid params; then `params` is unchanged. Thread-safe.
 * (`report` in 0.11: before, `double *out_noise`, and rsmooth_params_auto_report) */
RSMOOTH_API rsmooth_status rsmooth_params_auto(rsmooth_scalar scalar, const void *positions,
                                               size_t vertex_count, const uint32_t *indices,
                                               size_t triangle_count, rsmooth_params *params,
                                               rsmooth_noise_report *report, rsmooth_error *error);

/** Figures of one filter run, filled when a non-NULL pointer is passed. Times in milliseconds;
 * stages a path does not have are 0. */
typedef struct rsmooth_report {
    size_t struct_size;      /**< sizeof(rsmooth_report): rsmooth_report_init (added in 0.5) */
    size_t vertex_count;     /**< vertices given */
    size_t triangle_count;   /**< triangles given */
    size_t facet_count;      /**< triangles with non-zero area: the ones that carry weight */
    double mean_edge_length; /**< in mesh units */
    double sigma_f;          /**< absolute, mesh units */
    double sigma_g;          /**< absolute, mesh units (+INFINITY when the influence is off) */
    double radius;           /**< cutoff * sigma_f: the reach of a vertex, mesh units */
    size_t grid_cell_count;  /**< occupied grid cells */
    char device[128];        /**< "reference (double, 1 thread)" or the OpenCL device name */
    double ms_setup;         /**< program build / context work done for this call */
    double ms_facets;        /**< facet data and mean edge length */
    double ms_grid;          /**< grid build and vertex ordering */
    double ms_upload;        /**< copying the inputs to the device */
    double ms_mollify;       /**< vertex mollification */
    double ms_normals;       /**< normals of the mollified copy */
    double ms_robust;        /**< robust estimation */
    double ms_download;      /**< copying the results back */
    double ms_total;         /**< the whole filter call */
    /** @name Work counts
     * 0 where a path does not count them; the reference path does not. @{ */
    double mollify_radius;  /**< reach of the mollification pass (of one round of the
                             * bilateral normal filter when it replaces it), mesh units */
    uint64_t pairs_mollify; /**< vertex-facet pairs the mollification pass evaluated */
    uint64_t pairs_robust;  /**< vertex-facet pairs the robust pass evaluated (each of them,
                               within reach or not: the grid's waste is counted) */
    size_t tiles;           /**< spatial tiles the mesh was cut into to fit the device (1 when
                               it fitted whole) */
    /** @} */
    int discrepancy_iterations; /**< params.discrepancy_level's choice per region: the Taubin
                                 * iterations blended with the filter's result, 0 when it was off
                                 * or had nothing to smooth (added in 0.6) */
    double region_filter_share; /**< that choice's mean weight of the filter's result over the
                                 * vertices (1: the filter's result everywhere, 0: Taubin's);
                                 * 0 when discrepancy_iterations is 0 (added in 0.11) */
    /** @name The normal-update stage (the best mode's; added in 0.11)
     * Its whole time is also in ms_normals. 0 when the call ran no stage. @{ */
    double ms_stage;                  /**< the whole stage */
    double ms_stage_lists;            /**< facets, adjacency and the guided filter's lists (host) */
    double ms_stage_upload;           /**< the lists and the input to the device */
    double ms_stage_cycles;           /**< every cycle (on the device, or on the host) */
    double ms_stage_download;         /**< the positions back */
    int stage_cycles;                 /**< cycles run */
    int stage_on_device;              /**< 1: the cycles ran on the call's OpenCL device; 0: host */
    int stage_float_bits;             /**< their precision: 64 (the host; a device with fp64, by
                                       * default), 32 (RSMOOTH_STAGE_PRECISION=float, or a device
                                       * without fp64) */
    uint64_t stage_bytes_to_device;   /**< bytes the stage copied to the device */
    uint64_t stage_bytes_from_device; /**< and back */
    /** @} */
    /** @name Do no harm (added in 0.11)
     * What the call left alone (docs/do-no-harm.md). @{ */
    size_t parts;            /**< parts of the mesh smoothed each in its own unit: triangles
                              * whose sizes (median edge) differ by more than about 8 times,
                              * with no sizes between, are kept apart (1 for most meshes) */
    size_t outliers;         /**< vertices held where they were: every triangle they belong to
                              * is out of scale with the surface around it (a vertex thrown
                              * far off it); their triangles move no other vertex */
    size_t guarded_vertices; /**< vertices rsmooth_params.guard pulled back so that no triangle
                              * came out reversed */
    int stage_skipped;       /**< 1: the normal update stage was asked for but not run, the
                              * noise estimate finding nothing to remove (a clean mesh) */
    /** @} */
} rsmooth_report;

/** Zeroes `report` and sets its struct_size. Accepts NULL. (Added in 0.5) */
RSMOOTH_API void rsmooth_report_init(rsmooth_report *report);

/* ---------------------------------------------------------------------------------------------- */
/* Error metrics */
/* ---------------------------------------------------------------------------------------------- */

/** How far a result (a denoised mesh) is from its ground truth, both made of the same triangles
 * over the same vertices: what `rsmooth compare` prints. Lower is better; 0 for identical meshes.
 * The figures follow ../shared/tools/meshmetrics.py (the independent oracle), except that
 * distances to a surface here are exact (the closest point over all triangles), where the script
 * tries only the 24 triangles with the nearest centroids, so its ev can be slightly larger.
 * (Added in 0.5) */
typedef struct rsmooth_metrics {
    size_t vertex_count;   /**< vertices compared */
    size_t triangle_count; /**< triangles of the meshes */
    double theta;          /**< mean angle between corresponding face normals, degrees, over the
                            * triangles with non-zero area in both meshes (NAN when there is none) */
    size_t theta_count;    /**< how many triangles theta averages */
    double ev;        /**< Sun et al. 2007 E_v: sqrt(sum_v A_v d_v^2 / sum_v A_v), A_v the area of
                       * the result's triangles around v, d_v the distance from result vertex v
                       * to the ground-truth surface (exact), over vertices with A_v > 0; in
                       * thousandths of bbox_diag (NAN when no vertex has A_v > 0) */
    double rms_v;     /**< RMS distance between corresponding vertices (all of them), in
                       * mean_edge (mean edge lengths of the truth) */
    double hausdorff; /**< symmetric Hausdorff distance sampled at the vertices: the larger of the
                       * farthest result vertex from the ground-truth surface and the farthest
                       * ground-truth vertex from the result surface (vertices used by some
                       * triangle); in thousandths of bbox_diag */
    double mean_edge; /**< mean length of the truth's unique undirected edges (an edge shared by
                       * two triangles counts once; a repeated index is no edge), mesh units */
    double bbox_diag; /**< diagonal of the truth's axis-aligned bounding box (all vertices), mesh
                       * units */
} rsmooth_metrics;

/** Compares `result_positions` with `truth_positions` (3 * vertex_count floats or doubles each, as
 * `scalar` says, finite, magnitude <= 1e150), both meshes made of the same `indices`
 * (triangle_count triples, each < vertex_count), and writes the figures to `out`. The arrays are
 * only read. float32 positions give exactly the figures of float64 positions of the same values.
 * Any scale works alike: the figures are ratios and angles, computed after multiplying both meshes
 * by one power of two (exact), so a mesh gives the same figures at every scale. A truth with no
 * edge of non-zero length (mean_edge 0) gives an infinite or NAN rms_v, and one whose vertices all
 * coincide (bbox_diag 0) an infinite or NAN ev and hausdorff, rather than a failure.
 * Deterministic with any thread count.
 *
 * Errors: RSMOOTH_ERROR_INVALID_ARGUMENT, with `out` untouched and a message naming the problem:
 * `out` or an array NULL, an invalid scalar, no vertex, no triangle, an index out of range (naming
 * the triangle and the index), a non-finite or too large coordinate (naming the vertex and whether
 * it is the result's or the truth's), a mesh whose largest coordinate lies more than 1e225 of the
 * truth's typical edges from the origin; RSMOOTH_ERROR_OUT_OF_MEMORY. Thread-safe.
 * (Added in 0.5) */
RSMOOTH_API rsmooth_status rsmooth_compare(rsmooth_scalar scalar, const void *result_positions,
                                           const void *truth_positions, size_t vertex_count,
                                           const uint32_t *indices, size_t triangle_count,
                                           rsmooth_metrics *out, rsmooth_error *error);

/* ---------------------------------------------------------------------------------------------- */
/* Layer 1: arrays in, arrays out */
/* ---------------------------------------------------------------------------------------------- */

/** Owns (or shares) an OpenCL context, device, queue and the built program (Layer 2 below). */
typedef struct rsmooth_context rsmooth_context;

/** The optional per-vertex outputs and the report of a smoothing call (rsmooth_smooth,
 * rsmooth_smooth_points, rsmooth_smooth_view). Zero-initialise it and set struct_size, e.g.
 * `rsmooth_outputs out = {.struct_size = sizeof out, .confidence = conf};`; a call given NULL
 * writes none of them. (Added in 0.11: the three trailing arguments of 0.10's calls) */
typedef struct rsmooth_outputs {
    size_t struct_size; /**< sizeof(rsmooth_outputs); 0 reads as the 0.11 size */
    /** vertex_count floats receiving k(p) = sum a f g (area units; a k beyond FLT_MAX, e.g. on a
     * mesh with edges of 1e20, is RSMOOTH_ERROR_NUMERICAL, one below float's range rounds to 0:
     * the confidence is the scale-free measure). Not for point clouds (must be NULL there). */
    float *weight;
    /** vertex_count floats receiving k(p) / sum a f, in [0, 1]; 0 where no facet is within reach
     * (such vertices keep their position). */
    float *confidence;
    /** Figures of the run; set its struct_size (rsmooth_report_init). */
    rsmooth_report *report;
} rsmooth_outputs;

/** The filter: on the context's OpenCL device, or with ctx NULL on the reference path, in double
 * precision on the host (the oracle of the device path and the fallback when no OpenCL device
 * exists).
 *
 * - ctx: a context (rsmooth_context_create), or NULL for the reference path.
 * - scalar: the type of `positions` and `out_positions`.
 * - positions: 3 * vertex_count floats or doubles (x, y, z per vertex), finite, magnitude
 *   <= 1e150. Borrowed. Any scale works alike, from edges of 1e-300 (float32: 1e-36) to
 *   coordinates of 1e150: both paths work in units of a power of two near the mesh's typical
 *   edge, which is exact. A mesh whose largest coordinate lies more than 1e225 typical edges from
 *   the origin is refused.
 * - vertex_count: >= 1 and < 2^32.
 * - indices: 3 * triangle_count vertex indices, each < vertex_count. May be NULL only when
 *   triangle_count is 0 (then nothing moves). Any soup is fine: duplicated, unreferenced or
 *   disconnected vertices, non-manifold edges, zero-area triangles.
 * - params: NULL means defaults (rsmooth_params_init).
 * - out_positions: 3 * vertex_count values of `scalar`, in the input's vertex order. Must not
 *   overlap `positions`.
 * - outputs: optional (NULL): weights, confidence, report (rsmooth_outputs).
 * - error: optional (NULL): detail on failure.
 *
 * Returns RSMOOTH_OK, RSMOOTH_ERROR_INVALID_ARGUMENT (then no output is written),
 * RSMOOTH_ERROR_OUT_OF_MEMORY or RSMOOTH_ERROR_NUMERICAL (a float32 result beyond FLT_MAX, a
 * weight beyond float's range; outputs undefined), and on a device RSMOOTH_ERROR_OPENCL (outputs
 * undefined) when the device fails. RSMOOTH_OK guarantees every output is finite. The device
 * computes in float32 in cell-local coordinates (meshes far from the origin lose nothing); its
 * result agrees with the reference path's to about 1e-4 mean edge lengths, and two runs on the
 * same device are bit-identical. Thread-safe: the reference path has no shared state; a context's
 * calls run one at a time. (ctx NULL and `outputs` in 0.11: before, rsmooth_smooth_reference and
 * three trailing arguments) */
RSMOOTH_API rsmooth_status rsmooth_smooth(rsmooth_context *ctx, rsmooth_scalar scalar,
                                          const void *positions, size_t vertex_count,
                                          const uint32_t *indices, size_t triangle_count,
                                          const rsmooth_params *params, void *out_positions,
                                          const rsmooth_outputs *outputs, rsmooth_error *error);

/** The isotropic baselines people already use, for comparison only: `iterations` rounds of
 * p += lambda * U(p), each followed, when mu != 0, by p += mu * U(p) (Taubin's lambda|mu smoothing,
 * SIGGRAPH 1995; typical lambda 0.5, mu -0.53). mu = 0 gives plain Laplacian smoothing, which
 * shrinks the mesh. U(p) is the uniform umbrella operator: the mean of p's edge neighbours minus p.
 * Unlike the filter above these need connectivity (vertices without an edge stay) and round sharp
 * edges. lambda in (0, 1], mu in [-1, 0]. Same arrays and argument errors as
 * rsmooth_smooth (RSMOOTH_ERROR_NUMERICAL when a float32 result leaves float's range);
 * double precision, one thread, thread-safe. */
RSMOOTH_API rsmooth_status rsmooth_smooth_taubin(rsmooth_scalar scalar, const void *positions,
                                                 size_t vertex_count, const uint32_t *indices,
                                                 size_t triangle_count, double lambda, double mu,
                                                 unsigned iterations, void *out_positions,
                                                 rsmooth_error *error);

/** Point clouds with normals (beyond the paper; added in 0.4), on a context's device or (ctx
 * NULL) the reference path. A point set has no triangles, so
 * each point p_i is its own facet: its centroid is p_i, its plane the tangent plane through p_i
 * with normal n_i, and its area a_i = (sqrt(3) / 2) s_i^2, where s_i is p_i's mean distance to its
 * 6 nearest other points (the area per point of a regular triangular lattice of spacing s_i), so
 * densely sampled parts do not outweigh sparse ones. Then Eq. 3 as for meshes, confidence too.
 *
 * Relative sigmas are in units of the point spacing: the mean of s_i over the points
 * (rsmooth_point_spacing). On the vertices of a mesh it is within a few percent of the mean edge
 * length (0.92 to 1.00 on the benchmark models), so the same sigmas mean the same.
 * Predictor normals: with params->mollify = 1 (default) the bilateral normal filter of
 * rsmooth_normal_filter with normal_sigma_s, normal_sigma_n and normal_iterations, whatever
 * normal_filter says (the paper's mollification moves triangle corners, which points lack); with
 * mollify = 0 the input normals. params->passes > 1: each pass starts from the previous pass's
 * positions (areas recomputed, sigmas those of the input's spacing) and filters the input's
 * normals anew there, with pass_confidence as for meshes. params->predictor CENTROID averages
 * neighbouring points (plain Gaussian smoothing with sigma_g = +INFINITY).
 *
 * scalar          type of positions, normals, out_positions and out_normals.
 * positions       3 * point_count values, finite, magnitude <= 1e150. Borrowed.
 * normals         3 * point_count values: a normal per point, of any finite non-zero length
 *                 (normalised here), oriented consistently (the bilateral filter compares them
 *                 as vectors; the projections do not care). Borrowed.
 * point_count     >= 1 and < 2^32.
 * params          NULL means defaults (rsmooth_params_init).
 * out_positions   3 * point_count values: the filtered points, in input order.
 * out_normals     optional (NULL): 3 * point_count values receiving the unit normals the last pass
 *                 predicted with (the filtered normals; the input's, normalised, with mollify 0).
 * outputs         optional (NULL): confidence (point_count floats, k(p) / sum a f in [0, 1]) and
 *                 report (triangle_count 0, facet_count the points of non-zero area,
 *                 mean_edge_length the point spacing; ms_mollify the normal filter); its weight
 *                 must be NULL.
 * Every input is read before any output is written: outputs may be the input arrays themselves,
 * but must not overlap each other.
 *
 * Returns RSMOOTH_OK, RSMOOTH_ERROR_INVALID_ARGUMENT (naming the point of a non-finite or zero
 * normal; no output written), RSMOOTH_ERROR_OUT_OF_MEMORY or RSMOOTH_ERROR_NUMERICAL (outputs
 * undefined). With ctx NULL: the reference path, in double precision, thread-safe. On a
 * context's device each pass is one device run with the points as facets (the same grid,
 * bilateral rounds and robust kernels as rsmooth_smooth; spacings and areas on the host); the
 * result agrees with the reference path to about 1e-4 point spacings, two runs on the same device
 * are bit-identical. Point clouds are not cut into tiles: one that does not fit the device (or the
 * context's memory budget) returns RSMOOTH_ERROR_OUT_OF_MEMORY; RSMOOTH_ERROR_OPENCL (outputs
 * undefined) when the device fails. (ctx NULL and `outputs` in 0.11: before,
 * rsmooth_smooth_points_reference and two trailing arguments) */
RSMOOTH_API rsmooth_status rsmooth_smooth_points(rsmooth_context *ctx, rsmooth_scalar scalar,
                                                 const void *positions, const void *normals,
                                                 size_t point_count, const rsmooth_params *params,
                                                 void *out_positions, void *out_normals,
                                                 const rsmooth_outputs *outputs,
                                                 rsmooth_error *error);

/** The point spacing of a point set, as above: the mean over the points of each one's mean distance
 * to its 6 nearest others (fewer when there are fewer points; 0 for one point). Fails like
 * rsmooth_smooth_points on bad positions. Thread-safe. */
RSMOOTH_API rsmooth_status rsmooth_point_spacing(rsmooth_scalar scalar, const void *positions,
                                                 size_t point_count, double *out_spacing,
                                                 rsmooth_error *error);

/* ---------------------------------------------------------------------------------------------- */
/* Layer 2: an OpenCL context object */
/* ---------------------------------------------------------------------------------------------- */

/** How a context is made (rsmooth_context_create). Zero-initialise it and set struct_size, e.g.
 * `rsmooth_context_options o = {.struct_size = sizeof o};`, then the fields wanted: a zero field
 * takes its environment variable when set, else the default. The environment is read once, at the
 * creation (every variable is in docs/environment.md); the context's calls use what it read then.
 * (Added in 0.11) */
typedef struct rsmooth_context_options {
    size_t struct_size; /**< sizeof(rsmooth_context_options); 0 reads as the 0.11 size */
    /** The device: NULL takes RSMOOTH_DEVICE, else "auto"; "auto" the first GPU of any platform,
     * else the first CPU device, else the first device; "gpu"/"cpu" the first device of that
     * type; "P:D" device D of platform P (0-based, in clGetPlatformIDs/clGetDeviceIDs order);
     * other text the first device whose "platform device" name contains it (case-insensitive). */
    const char *device;
    /** Device memory one filter call may hold, bytes: 0 takes RSMOOTH_MEMORY_BUDGET (e.g.
     * "256M"), else most of the device's memory. A mesh that needs more, or a buffer larger than
     * the device's largest allocation, is cut into spatial tiles, each run with the facets within
     * reach of its vertices: results are an untiled run's bit for bit (the grid's cells count
     * from a lattice fixed in space; a mesh spanning more than about a million cells along an
     * axis, where the whole mesh's cells widen, excepted). rsmooth_report.tiles says how many
     * ran. */
    uint64_t memory_budget;
    /** Threads of the host stages of the context's calls (facet data, grid, packing, results, the
     * normal-update stage on CPU devices): 0 takes RSMOOTH_HOST_THREADS, else every online core;
     * at most 64 run. A host application with its own thread pool sets 1, or its share. The
     * result does not depend on it (bit for bit). */
    unsigned host_threads;
} rsmooth_context_options;

/** Creates a context: `options` may be NULL (every field zero: the environment, else the
 * defaults). The program is built here (PoCL caches binaries on disk in POCL_CACHE_DIR; rsmooth
 * keeps its own cache, rsmooth_context_info.program_cache). Developers may set RSMOOTH_KERNEL_DIR
 * to load kernels/ *.cl from a directory instead of the embedded copies, and
 * RSMOOTH_BUILD_OPTIONS to append OpenCL build options.
 * The OpenCL loader is opened on the first call that needs it (the library does not link it):
 * RSMOOTH_OPENCL_LIBRARY names its file when set and non-empty, else libOpenCL.so.1 (OpenCL.dll,
 * the OpenCL framework); where it cannot be opened, this returns RSMOOTH_ERROR_NO_DEVICE saying
 * so and rsmooth_list_devices 0, while the reference path works.
 * Returns RSMOOTH_ERROR_NO_DEVICE, RSMOOTH_ERROR_KERNEL_BUILD, RSMOOTH_ERROR_OPENCL, ... with *ctx
 * set to NULL on failure. An environment variable of rsmooth's set to a value it does not take
 * (RSMOOTH_STAGE=gpu, RSMOOTH_MEMORY_BUDGET=lots) is RSMOOTH_ERROR_INVALID_ARGUMENT naming it.
 * Thread-safe. A context may be shared by threads: its calls are serialised (each holds the
 * context while it runs), so threads sharing one wait for each other; give each thread its own
 * context to filter concurrently. A call on a context from a progress callback of a call still
 * running on it would wait for itself: it returns RSMOOTH_ERROR_INVALID_ARGUMENT at once
 * instead. (`options` in 0.11: before, the device name alone) */
RSMOOTH_API rsmooth_status rsmooth_context_create(const rsmooth_context_options *options,
                                                  rsmooth_context **ctx, rsmooth_error *error);

/** One OpenCL device as rsmooth_list_devices reports it. */
typedef struct rsmooth_device_info {
    size_t struct_size;     /**< sizeof(rsmooth_device_info), rsmooth_device_info_init: the first
                             * entry's says how large every entry of the array is (added in 0.5) */
    int platform_index;     /**< the P of a "P:D" device choice */
    int device_index;       /**< the D */
    char name[256];         /**< "platform name / device name", what a name choice matches */
    char type[8];           /**< "gpu", "cpu", "accel" or "other" */
    char version[64];       /**< CL_DEVICE_VERSION, e.g. "OpenCL 3.0 PoCL ..." */
    unsigned compute_units; /**< CL_DEVICE_MAX_COMPUTE_UNITS */
    uint64_t global_memory; /**< bytes */
} rsmooth_device_info;

/** Zeroes `info` and sets its struct_size. Accepts NULL. (Added in 0.5) */
RSMOOTH_API void rsmooth_device_info_init(rsmooth_device_info *info);

/** Fills up to `capacity` entries of `devices` (may be NULL when capacity is 0) with every OpenCL
 * device of every platform, in the order "P:D" choices count them, and returns how many there are
 * (0 when no OpenCL platform exists). Thread-safe. */
RSMOOTH_API size_t rsmooth_list_devices(rsmooth_device_info *devices, size_t capacity);

/** The whole CL_DEVICE_VERSION of device `device_index` of platform `platform_index` (the
 * numbers of an rsmooth_device_info), which its `version` field holds only the first 63 bytes of.
 * Writes as much as fits `size` bytes, always terminated when `size` > 0 (`out` may be NULL when
 * `size` is 0), and returns the whole version's length without the terminator, as snprintf
 * does; returns 0 and writes "" when there is no such device or no OpenCL platform. Thread-safe.
 * (Added in 0.10) */
RSMOOTH_API size_t rsmooth_device_version(int platform_index, int device_index, char *out,
                                          size_t size);

/** Releases everything the context holds. Accepts NULL. Called from a progress callback of a call
 * still running on ctx, does nothing (the call would go on with freed objects). */
RSMOOTH_API void rsmooth_context_destroy(rsmooth_context *ctx);

/** What a context is and how it was made: rsmooth_context_get_info fills it. Set struct_size first,
 * e.g. `rsmooth_context_info info = {.struct_size = sizeof info};`: only that many bytes are
 * written.
 * (Added in 0.11: the getters of 0.10 in one struct) */
typedef struct rsmooth_context_info {
    size_t struct_size;      /**< sizeof(rsmooth_context_info) */
    const char *device_name; /**< "platform name / device name"; valid while the context lives */
    double build_ms;         /**< milliseconds its creation spent building the OpenCL program */
    /** Where the program came from: "hit" (built from the binary in rsmooth's program cache),
     * "miss" (built from source, its binary then stored), "refused" (built from source: the
     * cache folder or file could have been written by another user, program_cache_note says
     * which and why) or "off" (no cache: RSMOOTH_CACHE_DIR is empty or "off", or neither
     * XDG_CACHE_HOME nor HOME is set). The cache is the folder RSMOOTH_CACHE_DIR, else
     * $XDG_CACHE_HOME/rsmooth, else $HOME/.cache/rsmooth, created (mode 0700) when first written;
     * one file per device, driver, program source and build options. A program binary is native
     * code, so a file is used only when it, its folder and every folder between the home folder
     * and it (or RSMOOTH_CACHE_DIR itself) belong to the effective user and are writable by
     * nobody else. A file that is damaged (its BLAKE2b digest is checked), another key's, not a
     * regular file or fails to build is a miss and is replaced; a folder that cannot be written
     * only means a build from source each time. Static text. */
    const char *program_cache;
    /** Why the cache was refused, a sentence for the user (the library prints nothing); "" when
     * it was not. Valid while the context lives. */
    const char *program_cache_note;
    /** How the kernels spread the work on the device: `lanes` vertices per work-item (the block
     * variant, CPU devices: the device's preferred float vector width, 4, 8 or 16) or 1 (the
     * group variant, GPUs: one vertex per work-item, the work-group's candidate facets staged
     * through local memory), and `group` work-items per work-group. RSMOOTH_KERNEL_VARIANT=cpu|gpu
     * and RSMOOTH_LANES=4|8|16 override the choice; every variant computes the same sums. */
    unsigned lanes;
    size_t group;           /**< work-items per work-group (see lanes) */
    uint64_t memory_budget; /**< bytes one filter call may hold on the device */
    unsigned host_threads;  /**< the host threads its calls use (0: every online core) */
} rsmooth_context_info;

/** Fills `info` (its struct_size bytes) about ctx. RSMOOTH_ERROR_INVALID_ARGUMENT for a NULL ctx
 * or info, or a struct_size below that of 0.11's first fields. Thread-safe: waits for a running
 * call on the context, or reads at once from that call's progress callback. (Added in 0.11) */
RSMOOTH_API rsmooth_status rsmooth_context_get_info(const rsmooth_context *ctx,
                                                    rsmooth_context_info *info);

/* ---------------------------------------------------------------------------------------------- */
/* Meshes as host applications hold them: strided vertices, any index type */
/* ---------------------------------------------------------------------------------------------- */

/** The type of a mesh view's indices. */
typedef enum rsmooth_index_type {
    RSMOOTH_INDEX_UINT32 = 0, /**< rsmooth's own, OpenGL's, meshoptimizer's */
    RSMOOTH_INDEX_INT32 = 1,  /**< Open3D's triangles */
    RSMOOTH_INDEX_INT64 = 2   /**< numpy's default integers (trimesh's faces) */
} rsmooth_index_type;

/** A mesh where the host keeps it: vertex v's x, y, z are the three `scalar`s at byte
 * v * position_stride of `positions` (an interleaved vertex buffer: position, normal, uv...), and
 * triangle t's three indices of `index_type` at byte t * index_stride of `indices`. Strides of 0
 * mean packed. Nothing need be aligned. (Added in 0.5) */
typedef struct rsmooth_mesh_view {
    size_t struct_size;     /**< sizeof(rsmooth_mesh_view): set by rsmooth_mesh_view_init */
    rsmooth_scalar scalar;  /**< float32 or float64 coordinates */
    const void *positions;  /**< vertex 0's x; borrowed, read during the call only */
    size_t position_stride; /**< bytes; 0, or >= 3 * sizeof(scalar) */
    size_t vertex_count;    /**< >= 1 and < 2^32 */
    const void *indices;    /**< may be NULL only when triangle_count is 0 */
    int index_type;         /**< an rsmooth_index_type */
    size_t index_stride;    /**< bytes; 0, or >= 3 * sizeof(index) */
    size_t triangle_count;  /**< triangles (index triples) */
} rsmooth_mesh_view;

/** Sets struct_size and packed float32 with uint32 indices, everything else 0 / NULL. Returns
 * RSMOOTH_ERROR_INVALID_ARGUMENT if view is NULL. */
RSMOOTH_API rsmooth_status rsmooth_mesh_view_init(rsmooth_mesh_view *view);

/** The filter on a mesh view: on `ctx`'s device, or the reference path when ctx is NULL. The view
 * is read whole (into packed arrays; the packed calls above avoid that copy) before any output is
 * written, so out_positions may be the view's own vertex buffer: vertex v's result goes to the
 * three scalars at byte v * out_stride of out_positions (0: packed), the bytes between them
 * untouched. The outputs' weight and confidence are packed floats, as for rsmooth_smooth. Indices
 * are checked first: a negative one, or one >= vertex_count, is RSMOOTH_ERROR_INVALID_ARGUMENT
 * naming the triangle and corner, with nothing written; so are outputs that overlap each other.
 * Otherwise the same arguments, results (bit for bit those of the packed call on the same values),
 * errors and thread-safety as rsmooth_smooth. (Added in 0.5; `outputs` in 0.11) */
RSMOOTH_API rsmooth_status rsmooth_smooth_view(rsmooth_context *ctx, const rsmooth_mesh_view *mesh,
                                               const rsmooth_params *params, void *out_positions,
                                               size_t out_stride, const rsmooth_outputs *outputs,
                                               rsmooth_error *error);

/* ---------------------------------------------------------------------------------------------- */
/* Pieces of a larger mesh (out-of-core and distributed filtering) */
/* ---------------------------------------------------------------------------------------------- */

/** What a piece of a larger mesh is filtered with, besides its own arrays. (Added in 0.7) */
typedef struct rsmooth_piece_info {
    size_t struct_size;      /**< sizeof(rsmooth_piece_info): set by rsmooth_piece_info_init */
    size_t core_count;       /**< the piece's first core_count vertices are solved; <= its vertex
                              * count */
    double mean_edge_length; /**< of the whole mesh, caller's units (as rsmooth_mean_edge_length);
                              * finite and > 0 */
    double mean_area;        /**< of the whole mesh's triangles of non-zero area, caller's units;
                              * finite and > 0 */
    double scale;            /**< the power of two the whole run multiplies coordinates by inside
                              * (one of [2^-500, 2^1000], the scales it chooses); 0: the piece
                              * chooses, which gives the same bits unless a coordinate lies beyond
                              * about 1e75 typical edges from the origin. The two figures times it
                              * (and its square) must be normal doubles: for a mesh whose area
                              * has none in its own units (coordinates near 1e-300), give
                              * positions and figures times the scale, and scale 1 (what
                              * rsmooth_stream_smooth does). A scale that puts the piece's typical
                              * edge beyond 2^+-250 or so, where its facets' areas over- or
                              * underflow, is not the whole mesh's and is refused */
    int keep_memory;         /**< 0: the memory the call freed goes back to the system at its end
                              * (as every call's does); 1: it stays with the process, for a
                              * caller filtering piece after piece, whose next piece would fault
                              * its pages in again (about a tenth of the time at 16M triangles in
                              * 32 pieces). (Added in 0.11; a record of the 0.7 size is read
                              * with 0 here) */
} rsmooth_piece_info;

/** Sets struct_size and zeroes the rest. Returns RSMOOTH_ERROR_INVALID_ARGUMENT if info is NULL. */
RSMOOTH_API rsmooth_status rsmooth_piece_info_init(rsmooth_piece_info *info);

/** How far from a vertex the centroids of the triangles that move it may lie, in the caller's
 * units: the halo a piece must carry around its core vertices. `reach` is the whole mesh's largest
 * distance from a triangle's centroid to its corners. Checks params as the filter does; params
 * that need the whole mesh (passes above 1, the normal update stage, colours, a move mask) are
 * RSMOOTH_ERROR_UNSUPPORTED naming the field; figures that give a halo beyond double range
 * (mean_edge_length 1e308) RSMOOTH_ERROR_INVALID_ARGUMENT. (Added in 0.7) */
RSMOOTH_API rsmooth_status rsmooth_piece_halo(const rsmooth_params *params, double mean_edge_length,
                                              double reach, double *out_halo, rsmooth_error *error);

/** The filter on a piece of a larger mesh: its first info->core_count vertices move as they would
 * in a run on the whole mesh, provided the piece holds every triangle whose centroid lies within
 * rsmooth_piece_halo of them (more do no harm). Positions are double, packed; out_positions
 * receives 3 * core_count values, and outputs (NULL: none) the core's weights and confidences
 * (core_count floats each) and the report. The whole mesh's mean edge length, mean facet area and
 * scale stand in for the piece's own, so results are the whole run's bit for bit, on a device (as
 * tiles are, see rsmooth_context_options.memory_budget) and on the reference path (ctx NULL).
 * Params as rsmooth_piece_halo accepts them. Errors as rsmooth_smooth, and
 * RSMOOTH_ERROR_INVALID_ARGUMENT naming the field of `info` outside its range (see
 * rsmooth_piece_info); nothing written on failure. Thread-safety as rsmooth_smooth. (Added in 0.7;
 * `outputs` in place of 0.10's report in 0.11) */
RSMOOTH_API rsmooth_status rsmooth_smooth_piece(
    rsmooth_context *ctx, const double *positions, size_t vertex_count, const uint32_t *indices,
    size_t triangle_count, const rsmooth_piece_info *info, const rsmooth_params *params,
    double *out_positions, const rsmooth_outputs *outputs, rsmooth_error *error);

#ifdef __cplusplus
}
#endif

#endif /* RSMOOTH_H */
