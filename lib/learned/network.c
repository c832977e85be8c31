/* A cascade stage's network in double on the host: the reference the device's kernels
 * (kernels/learned.cl) and the training library's own outputs are checked against. */
#include "learned/learned.h"

#include <math.h>
#include <string.h>

void rs_learned_network(const rs_learned_stage *stage, const double *descriptor, double out[3]) {
    double a[RS_LEARNED_MAX_WIDTH], b[RS_LEARNED_MAX_WIDTH];
    const double *in = descriptor;
    for (uint32_t l = 0; l < stage->layer_count; l++) {
        const rs_learned_layer *layer = &stage->layer[l];
        double *to = (l % 2 == 0) ? a : b;
        for (uint32_t o = 0; o < layer->out; o++) {
            const float *w = layer->weight + (size_t)o * layer->in;
            double sum = layer->bias[o];
            for (uint32_t i = 0; i < layer->in; i++)
                sum += (double)w[i] * in[i];
            to[o] = (layer->activation == 1 && sum < 0) ? 0.0 : sum;
        }
        in = to;
    }
    memcpy(out, in, 3 * sizeof(double));
}

void rs_learned_network_batch(const rs_learned_stage *stage, size_t count, double *a, double *b) {
    /* a[i * count + f]: input i of facet f, so that for one weight the loop over the facets is
     * contiguous and vectorises without reordering any sum (each output still adds its bias
     * first, then its inputs in order: the same bits as rs_learned_network) */
    double *in = a, *to = b;
    for (uint32_t l = 0; l < stage->layer_count; l++) {
        const rs_learned_layer *layer = &stage->layer[l];
        for (uint32_t o = 0; o < layer->out; o++) {
            double *row = to + (size_t)o * count;
            const float *w = layer->weight + (size_t)o * layer->in;
            for (size_t f = 0; f < count; f++)
                row[f] = layer->bias[o];
            for (uint32_t i = 0; i < layer->in; i++) {
                const double wi = w[i], *x = in + (size_t)i * count;
                for (size_t f = 0; f < count; f++)
                    row[f] += wi * x[f];
            }
            if (layer->activation == 1)
                for (size_t f = 0; f < count; f++)
                    row[f] = row[f] < 0 ? 0.0 : row[f];
        }
        double *swap = in;
        in = to;
        to = swap;
    }
    if (in != a) /* the residuals end in a */
        memcpy(a, in, 3 * count * sizeof(double));
}

void rs_learned_normal_from_residual(const double frame[3][3], const double own[3],
                                     const double residual[3], double normal[3]) {
    double local[3];
    for (int k = 0; k < 3; k++)
        local[k] = own[k] + residual[k];
    double len = sqrt(rs_dot3(local, local));
    if (!(len > 1e-12)) { /* the residual cancelled the normal: keep the facet's own */
        memcpy(local, own, sizeof local);
        len = 1.0;
    }
    for (int k = 0; k < 3; k++) /* back from the frame: its transpose */
        normal[k] =
            (frame[0][k] * local[0] + frame[1][k] * local[1] + frame[2][k] * local[2]) / len;
}
