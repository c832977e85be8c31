/* Arrays in, arrays out (rsmooth.h only): builds a flat grid of triangles in code, lifts each
 * vertex off the plane by pseudo-random noise of 0.3 edge lengths, smooths it on the default
 * OpenCL device (or the double-precision reference path when there is none) and prints how far
 * the vertices moved and how far they lie from the plane before and after.
 *
 *     example_arrays            (RSMOOTH_DEVICE picks the device, as for the rsmooth command) */
#include <rsmooth.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#define N 40 /* vertices per side */

/* A reproducible uniform value in [-1, 1). */
static double noise(unsigned long long *state) {
    *state = *state * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(*state >> 11) / 4503599627370496.0 - 1.0;
}

static double rms_height(const float *xyz, size_t n) {
    double sum = 0;
    for (size_t v = 0; v < n; v++)
        sum += (double)xyz[3 * v + 2] * xyz[3 * v + 2];
    return sqrt(sum / (double)n);
}

int main(void) {
    size_t vertex_count = N * N, triangle_count = 2 * (N - 1) * (N - 1);
    float *xyz = malloc(3 * vertex_count * sizeof *xyz);
    float *out = malloc(3 * vertex_count * sizeof *out);
    uint32_t *indices = malloc(3 * triangle_count * sizeof *indices);
    unsigned long long state = 1;
    if (!xyz || !out || !indices)
        return EXIT_FAILURE;
    for (size_t v = 0; v < vertex_count; v++) { /* edges of length 1 on the plane z = 0 */
        xyz[3 * v] = (float)(v % N);
        xyz[3 * v + 1] = (float)(v / N);
        xyz[3 * v + 2] = (float)(0.3 * sqrt(3.0) * noise(&state)); /* standard deviation 0.3 */
    }
    uint32_t *t = indices;
    for (uint32_t y = 0; y + 1 < N; y++)
        for (uint32_t x = 0; x + 1 < N; x++) {
            uint32_t a = y * N + x, b = a + 1, c = a + N, d = c + 1;
            *t++ = a, *t++ = b, *t++ = d, *t++ = a, *t++ = d, *t++ = c;
        }
    rsmooth_params params;
    rsmooth_params_init(&params); /* the paper's filter: sigma_f 2, sigma_g 0.5 edge lengths */
    rsmooth_error err;
    rsmooth_error_init(&err);
    rsmooth_context *ctx = NULL;
    rsmooth_status st = rsmooth_context_create(NULL, &ctx, &err); /* NULL: RSMOOTH_DEVICE or auto */
    if (st == RSMOOTH_OK) {
        rsmooth_context_info info = {.struct_size = sizeof info};
        rsmooth_context_get_info(ctx, &info);
        printf("device: %s\n", info.device_name);
        st = rsmooth_smooth(ctx, RSMOOTH_FLOAT32, xyz, vertex_count, indices, triangle_count,
                            &params, out, NULL, &err);
        rsmooth_context_destroy(ctx);
    } else if (st == RSMOOTH_ERROR_NO_DEVICE) {
        printf("device: reference path (%s)\n", err.message);
        st = rsmooth_smooth(NULL, RSMOOTH_FLOAT32, xyz, vertex_count, indices, triangle_count,
                            &params, out, NULL, &err);
    }
    if (st != RSMOOTH_OK) {
        fprintf(stderr, "example_arrays: %s: %s\n", rsmooth_status_str(st), err.message);
        return EXIT_FAILURE;
    }

    double moved = 0, farthest = 0;
    for (size_t v = 0; v < vertex_count; v++) {
        double dx = out[3 * v] - xyz[3 * v], dy = out[3 * v + 1] - xyz[3 * v + 1];
        double dz = out[3 * v + 2] - xyz[3 * v + 2], d = sqrt(dx * dx + dy * dy + dz * dz);
        moved += d * d;
        farthest = d > farthest ? d : farthest;
    }
    printf("%zu vertices, %zu triangles; vertices moved: RMS %.3f, at most %.3f edge lengths\n",
           vertex_count, triangle_count, sqrt(moved / (double)vertex_count), farthest);
    printf("distance to the plane (RMS): %.3f -> %.3f edge lengths\n",
           rms_height(xyz, vertex_count), rms_height(out, vertex_count));
    free(xyz), free(out), free(indices);
    return EXIT_SUCCESS;
}
