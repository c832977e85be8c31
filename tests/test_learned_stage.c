/* The learned stage through the public API (rsmooth_params.stage_normals, model): on a noisy
 * capped cylinder (sharp rims, curved side, flat caps) it lowers the normal error against the
 * clean shape; a bad model and bad fields are refused by name, even on a mesh that reads clean
 * (where the stage does not run); on a clean mesh nothing moves. */
#include "mesh_shapes.h"
#include "rsmooth.h"
#include "test_util.h"

#include <string.h>

static void smooth(const shape_mesh *m, const rsmooth_params *p, double *out) {
    rsmooth_error err;
    rsmooth_status st = rsmooth_smooth(NULL, RSMOOTH_FLOAT64, m->xyz, m->vertex_count, m->indices,
                                       m->triangle_count, p, out, NULL, &err);
    if (st != RSMOOTH_OK)
        fprintf(stderr, "rsmooth_smooth: %s\n", err.message);
    CHECK(st == RSMOOTH_OK);
}

static void refused(const shape_mesh *m, const rsmooth_params *p, rsmooth_status want,
                    const char *what) {
    double *out = malloc(3 * m->vertex_count * sizeof(double));
    rsmooth_error err;
    rsmooth_status st = rsmooth_smooth(NULL, RSMOOTH_FLOAT64, m->xyz, m->vertex_count, m->indices,
                                       m->triangle_count, p, out, NULL, &err);
    if (st != want || !strstr(err.message, what)) {
        fprintf(stderr, "expected status %d with '%s', got %d: %s\n", (int)want, what, (int)st,
                err.message);
        exit(1);
    }
    printf("refused: %s\n", err.message);
    free(out);
}

int main(void) {
    shape_mesh truth, noisy;
    size_t triangles = test_small() ? 4000 : 12000;
    CHECK(shape_capped_cylinder(&truth, 1.0, 2.0, triangles) == 0);
    CHECK(shape_copy(&truth, &noisy) == 0);
    CHECK(shape_add_normal_noise(&noisy, 0.3, 5) == 0); /* (in mean edge lengths) */
    size_t n = 3 * noisy.vertex_count;
    double *guided = malloc(n * sizeof(double)), *learned = malloc(n * sizeof(double));
    CHECK(guided && learned);
    rsmooth_params p;
    rsmooth_params_init_best(&p);
    smooth(&noisy, &p, guided);
    p.stage_normals = RSMOOTH_STAGE_NORMALS_LEARNED;
    smooth(&noisy, &p, learned);
    double before = shape_face_normal_error_deg(&truth, noisy.xyz);
    double g = shape_face_normal_error_deg(&truth, guided);
    double l = shape_face_normal_error_deg(&truth, learned);
    printf("%zu triangles, noise 0.3 mean edges: normal error input %.2f, guided %.2f, learned "
           "%.2f degrees\n",
           noisy.triangle_count, before, g, l);
    double apart = 0, edge = shape_mean_edge_length(&truth);
    for (size_t i = 0; i < n; i++)
        apart = fmax(apart, fabs(guided[i] - learned[i]));
    printf("largest difference from the guided stage's result: %.3g mean edges\n", apart / edge);
    CHECK(apart > 1e-3 * edge); /* the model's normals moved the vertices */
    CHECK(l < 0.35 * before);

    /* refusals: the field, a model with no size, a bad model (also on a clean mesh) */
    rsmooth_params bad = p;
    bad.stage_normals = 7;
    refused(&noisy, &bad, RSMOOTH_ERROR_INVALID_ARGUMENT, "stage_normals");
    bad = p;
    bad.model = "RSNN\r\n\x1a\n";
    refused(&noisy, &bad, RSMOOTH_ERROR_INVALID_ARGUMENT, "model_size");
    bad.model_size = 8;
    refused(&noisy, &bad, RSMOOTH_ERROR_PARSE, "params.model: truncated");
    refused(&truth, &bad, RSMOOTH_ERROR_PARSE, "params.model");
    bad.model = "a text file, not a model";
    bad.model_size = strlen(bad.model);
    refused(&noisy, &bad, RSMOOTH_ERROR_PARSE, "not an rsmooth model");

    /* clean stays clean: the guard skips the stage, and the pass barely moves a vertex */
    smooth(&truth, &p, learned);
    double largest = 0;
    for (size_t i = 0; i < n; i++)
        largest = fmax(largest, fabs(learned[i] - truth.xyz[i]));
    printf("clean input: largest move %.3g mean edges\n", largest / edge);
    CHECK(largest < 0.05 * edge);
    free(guided), free(learned);
    shape_free(&truth), shape_free(&noisy);
    printf("learned stage: all checks passed\n");
    return 0;
}
