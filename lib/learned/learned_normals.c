/* The cascade: every stage of the model on every facet, each stage reading the one before's
 * normals over the input's geometry. Descriptors are made on the host's cores in double; each
 * stage's network runs there too, or on the device a chunk of facets at a time (the chunk bounds
 * the descriptors' memory: 1 KB per facet). */
#include "learned/learned.h"

#include <string.h>

/* Facets per chunk: 16 MB of float descriptors. */
#define CHUNK 16384

typedef struct chunk_job {
    const rs_learned_stage *stage;
    const rs_learned_input *in; /* in->normal: the stage's input normals */
    size_t first;
    double *frames;     /* 9 per facet of the chunk */
    float *descriptors; /* RS_LEARNED_INPUTS per facet of the chunk; NULL: the host's network */
    double *out;        /* 3 per facet of the mesh */
} chunk_job;

/* Facets per batch of the host's network: its widest layer for 64 facets stays in the cache. */
#define BATCH 64

/* The host's network on facets first + [begin, end), a batch at a time (rs_learned_network_batch,
 * the same bits as one by one). */
static void host_range(chunk_job *job, size_t begin, size_t end) {
    size_t width = RS_LEARNED_INPUTS;
    for (uint32_t l = 0; l < job->stage->layer_count; l++)
        width = job->stage->layer[l].out > width ? job->stage->layer[l].out : width;
    double *a = rs_alloc_array(width * BATCH, sizeof(double));
    double *b = rs_alloc_array(width * BATCH, sizeof(double));
    double(*frames)[3][3] = rs_alloc_array(BATCH, sizeof *frames);
    double descriptor[RS_LEARNED_INPUTS];
    for (size_t at = begin; a && b && frames && at < end; at += BATCH) {
        size_t count = end - at < BATCH ? end - at : BATCH;
        for (size_t j = 0; j < count; j++) {
            rs_learned_descriptor(job->in, job->first + at + j, descriptor, frames[j]);
            for (int k = 0; k < RS_LEARNED_INPUTS; k++)
                a[(size_t)k * count + j] = descriptor[k];
        }
        double own[BATCH][3];
        for (size_t j = 0; j < count; j++)
            for (int k = 0; k < 3; k++)
                own[j][k] = a[(size_t)k * count + j];
        rs_learned_network_batch(job->stage, count, a, b);
        for (size_t j = 0; j < count; j++) {
            double r[3] = {a[j], a[count + j], a[2 * count + j]};
            rs_learned_normal_from_residual(frames[j], own[j], r,
                                            job->out + 3 * (job->first + at + j));
        }
    }
    if (!a || !b || !frames) /* no memory for a batch: one facet at a time */
        for (size_t i = begin; i < end; i++) {
            double frame[3][3], residual[3];
            size_t f = job->first + i;
            rs_learned_descriptor(job->in, f, descriptor, frame);
            rs_learned_network(job->stage, descriptor, residual);
            rs_learned_normal_from_residual(frame, descriptor, residual, job->out + 3 * f);
        }
    rs_free(a);
    rs_free(b);
    rs_free(frames);
}

/* Descriptors of facets first + [begin, end) for the device (float), or the host's network. */
static void describe_range(void *ctx, size_t begin, size_t end, size_t chunk) {
    (void)chunk;
    chunk_job *job = ctx;
    if (!job->descriptors) {
        host_range(job, begin, end);
        return;
    }
    double descriptor[RS_LEARNED_INPUTS], frame[3][3];
    for (size_t i = begin; i < end; i++) {
        rs_learned_descriptor(job->in, job->first + i, descriptor, frame);
        for (int k = 0; k < RS_LEARNED_INPUTS; k++)
            job->descriptors[i * RS_LEARNED_INPUTS + k] = (float)descriptor[k];
        memcpy(job->frames + 9 * i, frame, sizeof frame);
    }
}

/* One chunk of one stage: the device's residuals, or (no runner, or it refused) the host's. */
static void run_chunk(chunk_job *job, size_t count, const rs_network_place *place,
                      float *residuals) {
    if (job->descriptors) {
        rs_parallel_for(count, 64, describe_range, job);
        if (place->runner(place->ctx, job->stage, job->descriptors, count, residuals) ==
            RSMOOTH_OK) {
            for (size_t i = 0; i < count; i++) {
                double own[3], r[3], frame[3][3];
                memcpy(frame, job->frames + 9 * i, sizeof frame);
                /* own from the frame in double, not the float copy: as the host computes it */
                for (int k = 0; k < 3; k++) {
                    own[k] = rs_dot3(frame[k], job->in->normal + 3 * (job->first + i));
                    r[k] = residuals[3 * i + k];
                }
                rs_learned_normal_from_residual(frame, own, r, job->out + 3 * (job->first + i));
            }
            return;
        }
    }
    chunk_job host = *job;
    host.descriptors = NULL;
    rs_parallel_for(count, 64, describe_range, &host);
}

bool rs_learned_normals(const rs_learned_model *model, int stages, const rs_learned_input *in,
                        const rs_network_place *place, double *normals) {
    size_t n = in->facet_count;
    bool device = place && place->runner;
    size_t chunk = n < CHUNK ? (n ? n : 1) : CHUNK;
    double *current = rs_alloc_array(n ? 3 * n : 1, sizeof(double));
    double *frames = device ? rs_alloc_array(chunk, 9 * sizeof(double)) : NULL;
    float *descriptors = device ? rs_alloc_array(chunk, RS_LEARNED_INPUTS * sizeof(float)) : NULL;
    float *residuals = device ? rs_alloc_array(chunk, 3 * sizeof(float)) : NULL;
    bool ok = current && (!device || (frames && descriptors && residuals));
    if (ok) {
        memcpy(current, in->normal, 3 * n * sizeof(double));
        rs_learned_input step = *in;
        step.normal = current;
        if (stages > (int)model->stage_count)
            stages = (int)model->stage_count;
        for (int s = 0; s < stages; s++) {
            for (size_t first = 0; first < n; first += chunk) {
                chunk_job job = {&model->stage[s], &step, first, frames, descriptors, normals};
                run_chunk(&job, n - first < chunk ? n - first : chunk, place, residuals);
            }
            memcpy(current, normals, 3 * n * sizeof(double));
        }
        memcpy(normals, current, 3 * n * sizeof(double));
    }
    rs_free(current);
    rs_free(frames);
    rs_free(descriptors);
    rs_free(residuals);
    return ok;
}
