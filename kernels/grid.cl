/* The facet grid on the device (lib/opencl/cl_grid.c): a counting sort of the facets by cell, the
 * same arrays core/grid.c's radix sort gives on the host, bit for bit.
 *
 * Cells are numbered densely, x major then y then z over the grid's dims (the host's cell keys
 * order them the same way), and:
 *   grid_zero         the counts cleared (OpenCL 1.2's fill is not among the calls rsmooth
 *                     loads);
 *   grid_count        per facet: its cell, found from its centroid in double exactly as
 *                     rs_grid_facet_cell finds it; the facets of each cell counted (atomics);
 *   grid_chunk_sums   per chunk of dense cells: its facets and occupied cells;
 *   grid_chunk_scan   one work-item: the chunks' sums, exclusive (chunks are few), the count
 *                     of occupied cells and the end of the last one's range;
 *   grid_cells        per chunk: each dense cell's first slot, and the occupied cells' coordinates
 *                     and starts in order;
 *   grid_scatter      per facet: a slot in its cell's range (atomics: in any order);
 *   grid_sort_cells   per occupied cell: its facets sorted by index, which makes the order the
 *                     host's stable sort gives whatever order the atomics took.
 * Cell lookups need double (cl_khr_fp64): without it the kernels are empty and never launched. */

__kernel void grid_zero(uint dense, __global uint *cell_facets) {
    size_t d = get_global_id(0);
    if (d < dense)
        cell_facets[d] = 0;
}

#ifdef cl_khr_fp64
#pragma OPENCL EXTENSION cl_khr_fp64 : enable

__kernel void grid_count(uint count, double inv_h, double origin_x, double origin_y,
                         double origin_z, int dx, int dy, int dz, __global const double *points,
                         __global uint *key, __global volatile uint *cell_facets) {
    size_t i = get_global_id(0);
    if (i >= count)
        return;
    const double origin[3] = {origin_x, origin_y, origin_z};
    const int dims[3] = {dx, dy, dz};
    int c[3];
    for (int k = 0; k < 3; k++) {
        /* rs_grid_cell_of, then clamped within the grid as rs_grid_facet_cell does */
        double x = floor(points[3 * i + k] * inv_h) - origin[k];
        double hi = (double)(dims[k] - 1);
        c[k] = (int)(x < 0.0 ? 0.0 : x > hi ? hi : x);
    }
    uint d = ((uint)c[0] * (uint)dy + (uint)c[1]) * (uint)dz + (uint)c[2];
    key[i] = d;
    atomic_inc(cell_facets + d);
}

#else

__kernel void grid_count(uint count, float inv_h, float origin_x, float origin_y, float origin_z,
                         int dx, int dy, int dz, __global const float *points, __global uint *key,
                         __global volatile uint *cell_facets) {}

#endif

__kernel void grid_chunk_sums(uint dense, uint chunk, __global const uint *cell_facets,
                              __global uint2 *chunk_sum) {
    size_t g = get_global_id(0);
    size_t begin = g * chunk;
    if (begin >= dense)
        return;
    size_t end = min(begin + chunk, (size_t)dense);
    uint2 sum = (uint2)(0, 0); /* facets, occupied cells */
    for (size_t d = begin; d < end; d++) {
        uint n = cell_facets[d];
        sum.x += n;
        sum.y += n > 0;
    }
    chunk_sum[g] = sum;
}

__kernel void grid_chunk_scan(uint chunks, __global uint2 *chunk_sum, __global uint *occupied,
                              __global uint *cell_start) {
    if (get_global_id(0) != 0)
        return;
    uint2 run = (uint2)(0, 0);
    for (uint g = 0; g < chunks; g++) {
        uint2 n = chunk_sum[g];
        chunk_sum[g] = run;
        run += n;
    }
    occupied[0] = run.y;
    cell_start[run.y] = run.x; /* the end of the last cell's range */
}

__kernel void grid_cells(uint dense, uint chunk, int dy, int dz, __global const uint *cell_facets,
                         __global const uint2 *chunk_sum, __global uint *cursor,
                         __global int4 *cell_coord, __global uint *cell_start) {
    size_t g = get_global_id(0);
    size_t begin = g * chunk;
    if (begin >= dense)
        return;
    size_t end = min(begin + chunk, (size_t)dense);
    uint2 run = chunk_sum[g];
    /* the chunk's first cell's coordinates, then stepped along z (divisions once per chunk, and
     * no remainder, whose pairing with a division Oclgrind cannot run) */
    uint yx = (uint)begin / (uint)dz, x = yx / (uint)dy;
    int4 at = (int4)((int)x, (int)(yx - x * (uint)dy), (int)((uint)begin - yx * (uint)dz), 0);
    for (size_t d = begin; d < end; d++) {
        uint n = cell_facets[d];
        cursor[d] = run.x;
        if (n > 0) {
            cell_coord[run.y] = at;
            cell_start[run.y] = run.x;
            run.y++;
        }
        run.x += n;
        if (++at.z == dz) {
            at.z = 0;
            if (++at.y == dy) {
                at.y = 0;
                at.x++;
            }
        }
    }
}

__kernel void grid_scatter(uint count, __global const uint *key, __global volatile uint *cursor,
                           __global uint *order) {
    size_t i = get_global_id(0);
    if (i >= count)
        return;
    order[atomic_inc(cursor + key[i])] = (uint)i;
}

/* Sifts a[root] down the max-heap a[0 .. n). */
inline void sift_down(__global uint *a, uint root, uint n) {
    uint v = a[root];
    for (;;) {
        uint child = 2 * root + 1;
        if (child >= n)
            break;
        if (child + 1 < n && a[child + 1] > a[child])
            child++;
        if (a[child] <= v)
            break;
        a[root] = a[child];
        root = child;
    }
    a[root] = v;
}

/* Cells are mostly a few dozen facets (insertion sort); a mesh far finer than the reach can put
 * thousands in one, which heapsort keeps at n log n without recursion or scratch. */
__kernel void grid_sort_cells(uint cells, __global const uint *cell_start, __global uint *order) {
    size_t c = get_global_id(0);
    if (c >= cells)
        return;
    __global uint *a = order + cell_start[c];
    uint n = cell_start[c + 1] - cell_start[c];
    if (n <= 32) {
        for (uint i = 1; i < n; i++) {
            uint v = a[i], j = i;
            for (; j > 0 && a[j - 1] > v; j--)
                a[j] = a[j - 1];
            a[j] = v;
        }
        return;
    }
    for (uint r = n / 2; r-- > 0;)
        sift_down(a, r, n);
    for (uint end = n - 1; end > 0; end--) {
        uint top = a[0];
        a[0] = a[end];
        a[end] = top;
        sift_down(a, 0, end);
    }
}
