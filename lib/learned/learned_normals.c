/* The cascade on the host: every stage of the model on every facet, each stage reading the one
 * before's normals over the input's geometry, in double on every core. */
#include "learned/learned.h"

#include <string.h>

typedef struct stage_job {
    const rs_learned_stage *stage;
    const rs_learned_input *in; /* in->normal: the stage's input normals */
    double *out;                /* 3 per facet */
} stage_job;

static void run_stage(void *ctx, size_t begin, size_t end, size_t chunk) {
    (void)chunk;
    stage_job *job = ctx;
    double descriptor[RS_LEARNED_INPUTS], frame[3][3], residual[3];
    for (size_t f = begin; f < end; f++) {
        rs_learned_descriptor(job->in, f, descriptor, frame);
        rs_learned_network(job->stage, descriptor, residual);
        /* the facet's own normal in the frame is its patch's first entry */
        rs_learned_normal_from_residual(frame, descriptor, residual, job->out + 3 * f);
    }
}

bool rs_learned_normals(const rs_learned_model *model, int stages, const rs_learned_input *in,
                        double *normals) {
    size_t n = in->facet_count;
    double *current = rs_alloc_array(n ? 3 * n : 1, sizeof(double));
    if (!current)
        return false;
    memcpy(current, in->normal, 3 * n * sizeof(double));
    rs_learned_input step = *in;
    if (stages > (int)model->stage_count)
        stages = (int)model->stage_count;
    for (int s = 0; s < stages; s++) {
        step.normal = current;
        stage_job job = {&model->stage[s], &step, normals};
        rs_parallel_for(n, 64, run_stage, &job);
        memcpy(current, normals, 3 * n * sizeof(double));
    }
    memcpy(normals, current, 3 * n * sizeof(double));
    rs_free(current);
    return true;
}
