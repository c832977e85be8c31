/* Learned facet normals (beyond the paper): a small cascaded regressor, after Wang, Liu and Tong's
 * cascaded normal regression (SIGGRAPH Asia 2016), that maps each facet's patch of noisy normals
 * to its clean normal. Each stage reads a descriptor per facet (descriptor.c: its 32 nearest
 * facets' normals and offsets in a local frame, filtered normals, the patch's shape and the noise
 * level) and predicts the normal as a residual in that frame with a small perceptron
 * (network.c); the next stage reads the previous stage's normals. The model is data
 * (model_file.c: docs/model.md, the format). Internal, not installed. */
#ifndef RSMOOTH_LEARNED_H
#define RSMOOTH_LEARNED_H

#include "core/rsmooth_internal.h"

/* The descriptor's layout (format field `layout`): 7 numbers per patch facet (its normal and
 * its centroid's offset in the frame, offsets in mean edge lengths, then its area in squared mean
 * edge lengths), nearest first; RS_LEARNED_FILTERED filtered normals in the frame; the patch's
 * normal-tensor eigenvalues over their sum, largest first; the noise level in mean edges. */
#define RS_LEARNED_LAYOUT 1
#define RS_LEARNED_NEIGHBOURS 32
#define RS_LEARNED_PER_NEIGHBOUR 7
#define RS_LEARNED_FILTERED 4
#define RS_LEARNED_INPUTS                                                                          \
    (RS_LEARNED_NEIGHBOURS * RS_LEARNED_PER_NEIGHBOUR + 3 * RS_LEARNED_FILTERED + 3 + 1)

/* The widest layer the model format allows (model_file.c checks it; network.c and the device's
 * kernels size their activations by it). */
#define RS_LEARNED_MAX_WIDTH 1024

/* One dense layer: out = activation(weight . in + bias), weight row-major (out rows of in). */
typedef struct rs_learned_layer {
    uint32_t in, out;
    uint32_t activation; /* 0: none, 1: rectifier (max(0, x)) */
    const float *weight;
    const float *bias;
} rs_learned_layer;

/* One cascade stage: its layers, the first reading RS_LEARNED_INPUTS numbers, the last giving 3
 * (the residual in the frame). */
typedef struct rs_learned_stage {
    uint32_t layer_count;
    rs_learned_layer *layer;
} rs_learned_stage;

typedef struct rs_learned_model {
    uint32_t format_version, layout, neighbours, inputs;
    uint8_t manifest[32]; /* BLAKE2b-256 of the training manifest (train/) */
    uint32_t stage_count;
    rs_learned_stage *stage;
    size_t parameters; /* weights and biases, all stages */
    void *storage;     /* owns every array above */
} rs_learned_model;

/* Reads a model from its bytes (model_file.c); errors name `name` (a file, or "the built-in
 * model") and what is wrong: not a model, another format version or descriptor layout, truncated,
 * a checksum that does not match, sizes that do not chain. */
rsmooth_status rs_learned_model_read(const void *bytes, size_t size, rs_learned_model *model,
                                     rsmooth_error *error, const char *name);
void rs_learned_model_free(rs_learned_model *model);
/* The model built into the library (models/learned-normals.rsnn, embedded). */
rsmooth_status rs_learned_model_builtin(rs_learned_model *model, rsmooth_error *error);

/* Each facet's patch: its RS_LEARNED_NEIGHBOURS nearest facets by centroid, itself first, then
 * nearest first (ties by index), built once per mesh (descriptor.c). */
typedef struct rs_learned_patches {
    size_t facet_count;
    uint32_t *neighbour; /* RS_LEARNED_NEIGHBOURS per facet; fewer facets: the facet repeated */
} rs_learned_patches;

/* false when out of memory. centroids: 3 per facet. */
bool rs_learned_patches_build(rs_learned_patches *patches, const double *centroid,
                              size_t facet_count);
void rs_learned_patches_free(rs_learned_patches *patches);

/* What a descriptor is made from: the facets' geometry (the input's, for every stage), the
 * current normals (the input's for the first stage, the previous stage's after), the mean edge
 * length and the noise level in mean edge lengths. */
typedef struct rs_learned_input {
    size_t facet_count;
    const double *centroid, *area; /* 3 per facet, 1 per facet */
    const double *normal;          /* 3 per facet, unit */
    const rs_learned_patches *patches;
    double mean_edge, noise_level;
} rs_learned_input;

/* Facet f's descriptor (RS_LEARNED_INPUTS numbers) and its frame: rows x, y, z (z the patch's
 * dominant normal direction), so that frame . v gives v in the frame. */
void rs_learned_descriptor(const rs_learned_input *in, size_t f, double *descriptor,
                           double frame[3][3]);

/* One stage's network on one descriptor: the residual (3 numbers), in double. */
void rs_learned_network(const rs_learned_stage *stage, const double *descriptor, double out[3]);

/* The same on `count` descriptors at once, their numbers interleaved: a holds input i of facet f
 * at a[i * count + f] (RS_LEARNED_INPUTS * count doubles; at least as many as the widest layer
 * times count); b is scratch of the widest layer times count. The residuals end in a (3 * count:
 * a[k * count + f]), equal bit for bit to rs_learned_network's. */
void rs_learned_network_batch(const rs_learned_stage *stage, size_t count, double *a, double *b);

/* The predicted normal from the facet's own normal in the frame and the residual: unit, back in
 * mesh coordinates. */
void rs_learned_normal_from_residual(const double frame[3][3], const double own[3],
                                     const double residual[3], double normal[3]);

/* Runs one stage's network elsewhere (the device: opencl/cl_learned.c) on `count` descriptors
 * (RS_LEARNED_INPUTS floats each, row after row), writing 3 residuals per descriptor. Any status
 * but RSMOOTH_OK has the host run that chunk, in double (the runner's refusal is no error). */
typedef rsmooth_status (*rs_network_runner)(void *ctx, const rs_learned_stage *stage,
                                            const float *descriptors, size_t count,
                                            float *residuals);
typedef struct rs_network_place {
    rs_network_runner runner; /* NULL: the host */
    void *ctx;
} rs_network_place;

/* Every stage of `model` on every facet: normals (3 per facet) start as the facets' own and end
 * as the last stage's; `stages` stages only (at most the model's). The descriptors are made on
 * the host's cores in double; the networks run there too, in double, or at `place` (may be
 * NULL) in float, a chunk of facets at a time. false when out of memory (normals unchanged). */
bool rs_learned_normals(const rs_learned_model *model, int stages, const rs_learned_input *in,
                        const rs_network_place *place, double *normals);

#endif /* RSMOOTH_LEARNED_H */
