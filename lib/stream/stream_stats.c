/* The whole mesh's figures, from its triangles on disk, summed in the order the in-memory path
 * sums them (lib/core/mesh.c), so that the sigmas and the area scale are the same bits:
 *
 *   - the mean edge length over unique edges: each edge belongs to its lower vertex, vertices in
 *     ascending order, a vertex's edges in the order the triangles first name them (mesh.c's
 *     counting sort), a run of vertices at a time when all of them do not fit in memory;
 *   - the mean area: facets summed per block of 8192 triangles, the blocks' sums in order.
 *
 * Both sum at the in-memory path's own power-of-two scale (scale.c, from the same sampled
 * triangles), so even where squares under- or overflow at other scales the figures agree. */
#include "core/parts.h"
#include "stream/stream_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* mesh.c's constants: the block of the area sums, the bucket size from which edges are sorted */
#define GEOMETRY_BLOCK 8192
#define EDGE_SCAN_LIMIT 32

static int compare_u32(const void *a, const void *b) {
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

static void scaled_position(const rs_stream_positions *p, uint32_t v, double scale, double out[3]) {
    rs_stream_position(p, v, out);
    for (int k = 0; k < 3; k++)
        out[k] *= scale;
}

static rsmooth_status read_fail(rsmooth_error *error) {
    return rs_fail(error, RSMOOTH_ERROR_IO, RS_STREAM_WHERE,
                   "cannot read the temporary triangle file");
}

/* Sum and count of the unique edges whose lower vertex lies in [lo, hi); `capacity` upper ends
 * fit in `upper`. *fits is false (nothing summed) when the range has more edges than that. */
static rsmooth_status edge_range(const rs_stream_positions *pos, int fd, uint64_t triangles,
                                 double scale, uint32_t lo, uint32_t hi, size_t *start,
                                 uint32_t *upper, size_t capacity, double *sum, uint64_t *unique,
                                 bool *fits, rsmooth_error *error) {
    size_t span = (size_t)(hi - lo);
    for (int fill = 0; fill < 2; fill++) { /* count, then place */
        if (fill == 0)
            memset(start, 0, (span + 1) * sizeof *start);
        rs_stream_reader r;
        if (!rs_stream_triangles_open(&r, fd, triangles))
            return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, RS_STREAM_WHERE, "read buffer");
        for (uint64_t t = 0; t < triangles; t++) {
            uint32_t tri[3];
            if (!rs_stream_next_triangle(&r, tri)) {
                rs_stream_reader_close(&r);
                return read_fail(error);
            }
            for (int e = 0; e < 3; e++) {
                uint32_t a = tri[e], b = tri[(e + 1) % 3];
                uint32_t low = a < b ? a : b;
                if (a == b || low < lo || low >= hi)
                    continue;
                if (fill == 0)
                    start[low - lo + 1]++;
                else
                    upper[start[low - lo]++] = a < b ? b : a;
            }
        }
        rs_stream_reader_close(&r);
        if (fill == 0) {
            for (size_t v = 0; v < span; v++)
                start[v + 1] += start[v];
            if (start[span] > capacity) {
                *fits = false;
                return RSMOOTH_OK;
            }
        }
    }
    for (size_t v = span; v > 0; v--) /* the fill moved each start to the next's */
        start[v] = start[v - 1];
    start[0] = 0;
    for (size_t i = 0; i < span; i++) {
        uint32_t *bucket = upper + start[i];
        size_t n = start[i + 1] - start[i];
        if (n > EDGE_SCAN_LIMIT)
            qsort(bucket, n, sizeof *bucket, compare_u32);
        double p[3];
        if (n > 0)
            scaled_position(pos, lo + (uint32_t)i, scale, p);
        for (size_t j = 0; j < n; j++) {
            bool seen = false;
            if (n > EDGE_SCAN_LIMIT)
                seen = j > 0 && bucket[j] == bucket[j - 1];
            else
                for (size_t k = 0; k < j && !seen; k++)
                    seen = bucket[k] == bucket[j];
            if (seen)
                continue;
            double q[3], d[3];
            scaled_position(pos, bucket[j], scale, q);
            for (int k = 0; k < 3; k++)
                d[k] = p[k] - q[k];
            *sum += sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            (*unique)++;
        }
    }
    *fits = true;
    return RSMOOTH_OK;
}

static rsmooth_status mean_edge_length(const rs_stream_positions *pos, int fd, uint64_t triangles,
                                       double scale, uint64_t memory, double *out,
                                       rsmooth_error *error) {
    uint64_t v_count = pos->count;
    /* a first guess at the run of vertices that fits: each holds about 3 T / V upper ends */
    double per_vertex = 8 + 4 * (v_count ? 3.0 * (double)triangles / (double)v_count : 0) * 1.25;
    uint64_t span = (uint64_t)((double)memory / per_vertex);
    if (span < 1024)
        span = 1024;
    if (span > v_count)
        span = v_count;
    double sum = 0;
    uint64_t unique = 0;
    for (uint64_t lo = 0; lo < v_count;) {
        uint64_t hi = lo + span < v_count ? lo + span : v_count;
        size_t *start = rs_alloc_array((size_t)(hi - lo) + 1, sizeof *start);
        uint64_t used = 8 * (hi - lo + 1);
        size_t capacity = memory > used ? (size_t)((memory - used) / 4) : 0;
        if (capacity > 3 * triangles)
            capacity = (size_t)(3 * triangles);
        uint32_t *upper = rs_alloc_array(capacity ? capacity : 1, sizeof *upper);
        if (!start || !upper) {
            rs_free(start);
            rs_free(upper);
            return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, RS_STREAM_WHERE,
                           "no memory for the edges of %llu vertices",
                           (unsigned long long)(hi - lo));
        }
        bool fits = false;
        rsmooth_status st = edge_range(pos, fd, triangles, scale, (uint32_t)lo, (uint32_t)hi, start,
                                       upper, capacity, &sum, &unique, &fits, error);
        rs_free(start);
        rs_free(upper);
        if (st != RSMOOTH_OK)
            return st;
        if (!fits && hi - lo <= 1)
            return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, RS_STREAM_WHERE,
                           "vertex %llu has more edges than the memory cap holds",
                           (unsigned long long)lo);
        if (!fits) {
            span = (hi - lo) / 2; /* denser than guessed: retry this run halved */
            continue;
        }
        lo = hi;
    }
    *out = unique ? sum / (double)unique : 0;
    return RSMOOTH_OK;
}

/* Facet count, mean area and reach, in blocks as mesh.c sums them. */
static rsmooth_status facet_figures(const rs_stream_positions *pos, int fd, uint64_t triangles,
                                    double scale, rs_stream_stats *stats, rsmooth_error *error) {
    rs_stream_reader r;
    if (!rs_stream_triangles_open(&r, fd, triangles))
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, RS_STREAM_WHERE, "read buffer");
    double area_sum = 0, block_sum = 0, reach = 0, longest = 0;
    uint64_t facets = 0;
    size_t *histogram = rs_calloc_array(RS_PART_BIN_COUNT, sizeof *histogram);
    if (!histogram) {
        rs_stream_reader_close(&r);
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, RS_STREAM_WHERE, "scale histogram");
    }
    rsmooth_scalar scalar = pos->f32 ? RSMOOTH_FLOAT32 : RSMOOTH_FLOAT64;
    for (uint64_t t = 0; t < triangles; t++) {
        uint32_t tri[3];
        if (!rs_stream_next_triangle(&r, tri)) {
            rs_stream_reader_close(&r);
            rs_free(histogram);
            return read_fail(error);
        }
        double hi = 0; /* the parts test (core/parts.h), in the caller's units as in memory */
        int16_t bin = rs_scale_bin(rs_triangle_scale(scalar, pos->xyz, tri, &hi));
        if (bin != RS_NO_BIN) {
            histogram[bin - RS_PART_BIN_MIN]++;
            longest = fmax(longest, hi);
        }
        double p[9], centroid[3], area = 0;
        if (rs_stream_facet(pos, tri, scale, p, centroid, &area)) {
            facets++;
            block_sum += area;
            for (int c = 0; c < 3; c++) {
                double d[3];
                rs_sub3(p + 3 * c, centroid, d);
                reach = fmax(reach, sqrt(rs_dot3(d, d)));
            }
        }
        if ((t + 1) % GEOMETRY_BLOCK == 0 || t + 1 == triangles) {
            area_sum += block_sum;
            block_sum = 0;
        }
    }
    rs_stream_reader_close(&r);
    stats->whole = rs_scales_whole(histogram, longest);
    rs_free(histogram);
    stats->facet_count = facets;
    stats->scaled_mean_area = facets ? area_sum / (double)facets : 0;
    stats->mean_area = stats->scaled_mean_area / scale / scale;
    stats->reach = reach / scale;
    return RSMOOTH_OK;
}

/* The in-memory path's scale (scale.c): from the same sampled triangles (one in every
 * T / 4096, as rs_mesh_scale strides), read from the triangle file. */
static rsmooth_status whole_scale(const rs_stream_positions *pos, int fd, uint64_t triangles,
                                  double magnitude, double *scale, rsmooth_error *error) {
    enum { SAMPLES = 4096 }; /* scale.c's SCALE_SAMPLES */
    uint64_t stride = triangles > SAMPLES ? triangles / SAMPLES : 1;
    size_t count = (size_t)((triangles + stride - 1) / stride);
    uint32_t *sampled = rs_alloc_array(count ? count : 1, 3 * sizeof *sampled);
    if (!sampled)
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, RS_STREAM_WHERE, "scale samples");
    for (size_t i = 0; i < count; i++)
        if (!rs_pread_all(fd, sampled + 3 * i, 12, (uint64_t)i * stride * 12)) {
            rs_free(sampled);
            return read_fail(error);
        }
    rsmooth_status st = rs_mesh_scale(pos->f32 ? RSMOOTH_FLOAT32 : RSMOOTH_FLOAT64, pos->xyz,
                                      sampled, count, magnitude, scale, error, RS_STREAM_WHERE);
    rs_free(sampled);
    return st;
}

rsmooth_status rs_stream_statistics(const rs_stream_positions *positions, int triangles_fd,
                                    uint64_t triangle_count, const rs_stream_extent *extent,
                                    uint64_t memory, rs_stream_stats *stats, rsmooth_error *error) {
    memset(stats, 0, sizeof *stats);
    memcpy(stats->lo, extent->lo, sizeof stats->lo);
    memcpy(stats->hi, extent->hi, sizeof stats->hi);
    rsmooth_status st = whole_scale(positions, triangles_fd, triangle_count, extent->magnitude,
                                    &stats->scale, error);
    if (st != RSMOOTH_OK)
        return st;
    st = mean_edge_length(positions, triangles_fd, triangle_count, stats->scale, memory,
                          &stats->scaled_mean_edge_length, error);
    if (st != RSMOOTH_OK)
        return st;
    stats->mean_edge_length = stats->scaled_mean_edge_length / stats->scale;
    return facet_figures(positions, triangles_fd, triangle_count, stats->scale, stats, error);
}
