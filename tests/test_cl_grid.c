/* The facet grid sorted on the device (lib/opencl/cl_grid.c, kernels/grid.cl) against the host's
 * (rs_grid_build_columns), the oracle: every array bit for bit (cells, their coordinates and
 * starts, the facet order, the columns) on a mesh's centroids at each cells-per-reach, random
 * points, points on cell boundaries and crowded cells (thousands of facets in one); a spread-out
 * grid the device declines; and the whole filter with RSMOOTH_DEVICE_GRID=1 equal to =0 byte for
 * byte. Runs on any OpenCL device with double precision (PoCL's CPU device here). */
#define _POSIX_C_SOURCE 200809L
#include "mesh_shapes.h"
#include "opencl/cl_grid.h"
#include "test_cl_util.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static uint64_t next_u64(uint64_t *s) {
    uint64_t z = (*s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

static double uniform(uint64_t *s, double lo, double hi) {
    return lo + (hi - lo) * ((double)(next_u64(s) >> 11) * 0x1.0p-53);
}

static void box_of(const double *p, size_t n, double lo[3], double hi[3]) {
    for (int k = 0; k < 3; k++) {
        lo[k] = INFINITY;
        hi[k] = -INFINITY;
    }
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) {
            lo[k] = fmin(lo[k], p[3 * i + k]);
            hi[k] = fmax(hi[k], p[3 * i + k]);
        }
}

static bool same(const void *a, const void *b, size_t bytes) {
    return bytes == 0 || (a && b && memcmp(a, b, bytes) == 0);
}

/* Both grids over `points`, compared array by array. */
static void check_grid(rsmooth_context *ctx, const char *name, const double *points, size_t n,
                       double reach, int split) {
    double lo[3], hi[3];
    box_of(points, n, lo, hi);
    rs_grid host, device;
    rsmooth_error err;
    CHECK_STATUS(rs_grid_build_columns(&host, points, n, reach, split, lo, hi, &err), RSMOOTH_OK);
    bool done = false;
    CHECK_STATUS(
        rs_cl_grid_build_columns(ctx, &device, points, n, reach, split, lo, hi, &done, &err),
        RSMOOTH_OK);
    CHECK(done);
    size_t cells = host.cell_count, largest = 0;
    for (size_t c = 0; c < cells; c++) {
        size_t m = host.cell_start[c + 1] - host.cell_start[c];
        largest = m > largest ? m : largest;
    }
    printf("%-22s %7zu facets, split %d: %6zu cells (device %6zu), largest %5zu facets, "
           "%zu columns\n",
           name, n, split, cells, device.cell_count, largest, host.column_count);
    CHECK(device.cell_count == cells);
    CHECK(device.cell_size == host.cell_size);
    CHECK(same(device.dims, host.dims, sizeof host.dims));
    CHECK(same(device.origin_cell, host.origin_cell, sizeof host.origin_cell));
    CHECK(same(device.cell_coord, host.cell_coord, 4 * cells * sizeof(int32_t)));
    CHECK(same(device.cell_start, host.cell_start, (cells + 1) * sizeof(uint32_t)));
    CHECK(same(device.facet_order, host.facet_order, n * sizeof(uint32_t)));
    CHECK(device.column_count == host.column_count);
    CHECK(device.column_mask == host.column_mask);
    CHECK(same(device.column_first, host.column_first, (host.column_count + 1) * sizeof(uint32_t)));
    CHECK(same(device.column_table, host.column_table,
               ((size_t)host.column_mask + 1) * sizeof(int32_t)));
    rs_grid_free(&host);
    rs_grid_free(&device);
}

/* A noisy cylinder's facet centroids, at each cells-per-reach the OpenCL path uses. */
static void mesh_centroids(rsmooth_context *ctx) {
    shape_mesh mesh;
    CHECK(shape_capped_cylinder(&mesh, 1.0, 1.5, 40000) == 0);
    CHECK(shape_add_normal_noise(&mesh, 0.2 * shape_mean_edge_length(&mesh), 3) == 0);
    double edge = shape_mean_edge_length(&mesh);
    size_t n = mesh.triangle_count;
    double *c = malloc(3 * n * sizeof *c);
    CHECK(c != NULL);
    for (size_t t = 0; t < n; t++)
        for (int k = 0; k < 3; k++)
            c[3 * t + k] =
                (mesh.xyz[3 * mesh.indices[3 * t] + k] + mesh.xyz[3 * mesh.indices[3 * t + 1] + k] +
                 mesh.xyz[3 * mesh.indices[3 * t + 2] + k]) /
                3;
    for (int split = 1; split <= 3; split++)
        check_grid(ctx, "cylinder centroids", c, n, 8 * edge, split);
    free(c);
    shape_free(&mesh);
}

static void point_sets(rsmooth_context *ctx) {
    size_t n = 60000;
    double *p = malloc(3 * n * sizeof *p);
    CHECK(p != NULL);
    uint64_t seed = 11;
    for (size_t i = 0; i < 3 * n; i++)
        p[i] = uniform(&seed, -3.0, 5.0);
    check_grid(ctx, "uniform box", p, n, 0.5, 1);
    check_grid(ctx, "uniform box", p, n, 0.5, 2);

    /* points on the cell lattice itself (and a hair either side), where rounding decides the
     * cell: both sides must round alike */
    rs_grid probe;
    double lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1};
    rs_grid_layout(&probe, 0.1, 1, lo, hi);
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) {
            double x = ((double)(next_u64(&seed) % 21) - 10.0) * probe.cell_size;
            int side = (int)(next_u64(&seed) % 3);
            p[3 * i + k] = side == 0   ? x
                           : side == 1 ? nextafter(x, -INFINITY)
                                       : nextafter(x, INFINITY);
        }
    check_grid(ctx, "on cell boundaries", p, n, 0.1, 1);

    /* crowded: a mesh far finer than the reach puts thousands of facets in a cell (the kernel's
     * heapsort, beside its insertion sort for small cells) */
    for (size_t i = 0; i < 3 * n; i++)
        p[i] = uniform(&seed, 0.0, 1.0);
    check_grid(ctx, "crowded cells", p, n, 0.6, 1);
    free(p);

    /* two far-apart points: a box of cells far beyond the facets, which the device declines */
    double far[6] = {0, 0, 0, 1e4, 1e4, 1e4};
    rs_grid grid;
    rsmooth_error err;
    bool done = true;
    box_of(far, 2, lo, hi);
    CHECK_STATUS(rs_cl_grid_build_columns(ctx, &grid, far, 2, 1.0, 1, lo, hi, &done, &err),
                 RSMOOTH_OK);
    printf("spread-out grid: %s\n", done ? "sorted on the device" : "declined (host sorts it)");
    CHECK(!done);
    rs_grid_free(&grid);
}

/* The whole filter, grid sorted on the device or on the host: the same bytes. */
static void whole_filter(rsmooth_context *ctx) {
    shape_mesh mesh;
    CHECK(shape_capped_cylinder(&mesh, 1.0, 1.5, 30000) == 0);
    CHECK(shape_add_normal_noise(&mesh, 0.2 * shape_mean_edge_length(&mesh), 5) == 0);
    size_t nv = mesh.vertex_count;
    double *out[2] = {malloc(3 * nv * sizeof(double)), malloc(3 * nv * sizeof(double))};
    float *weight[2] = {malloc(nv * sizeof(float)), malloc(nv * sizeof(float))};
    CHECK(out[0] && out[1] && weight[0] && weight[1]);
    rsmooth_params params;
    rsmooth_params_init(&params);
    params.sigma_f = 4;
    params.sigma_g = 1;
    (void)ctx;
    for (int device = 0; device < 2; device++) {
        setenv("RSMOOTH_DEVICE_GRID", device ? "1" : "0", 1); /* read when a context is made */
        rsmooth_context *made = open_test_context();
        rsmooth_error err;
        CHECK_STATUS(rsmooth_smooth(made, RSMOOTH_FLOAT64, mesh.xyz, nv, mesh.indices,
                                    mesh.triangle_count, &params, out[device],
                                    OUTPUTS(weight[device], NULL, NULL), &err),
                     RSMOOTH_OK);
        rsmooth_context_destroy(made);
    }
    unsetenv("RSMOOTH_DEVICE_GRID");
    bool equal = memcmp(out[0], out[1], 3 * nv * sizeof(double)) == 0 &&
                 memcmp(weight[0], weight[1], nv * sizeof(float)) == 0;
    printf("whole filter, %zu vertices: device grid %s host grid\n", nv, equal ? "==" : "!=");
    CHECK(equal);
    for (int i = 0; i < 2; i++) {
        free(out[i]);
        free(weight[i]);
    }
    shape_free(&mesh);
}

/* A context reads RSMOOTH_DEVICE_GRID once, at its creation: set afterwards, it changes nothing
 * (a CPU device's program then has no grid kernels to run). */
static void read_at_creation(void) {
    unsetenv("RSMOOTH_DEVICE_GRID");
    rsmooth_context *ctx = open_test_context();
    bool made_with = rs_cl_device_grid(ctx); /* a GPU's program holds them anyway */
    setenv("RSMOOTH_DEVICE_GRID", made_with ? "0" : "1", 1);
    printf("RSMOOTH_DEVICE_GRID set after the creation: %s\n",
           rs_cl_device_grid(ctx) == made_with ? "no change" : "changed");
    CHECK(rs_cl_device_grid(ctx) == made_with);
    unsetenv("RSMOOTH_DEVICE_GRID");
    rsmooth_context_destroy(ctx);
}

int main(void) {
    /* set before the context: its program then holds the grid's kernels (cl_program.c) */
    setenv("RSMOOTH_DEVICE_GRID", "1", 1);
    rsmooth_context *ctx = open_test_context();
    bool usable = rs_cl_device_grid(ctx);
    unsetenv("RSMOOTH_DEVICE_GRID");
    if (!usable) {
        printf("the device has no double precision: no grid on it, skipping\n");
        rsmooth_context_destroy(ctx);
        return TEST_SKIP;
    }
    mesh_centroids(ctx);
    point_sets(ctx);
    whole_filter(ctx);
    rsmooth_context_destroy(ctx);
    read_at_creation();
    printf("device grid == host grid\n");
    return 0;
}
