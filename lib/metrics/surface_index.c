/* Exact closest points on a triangle surface (surface_index.h): Ericson's closest point on a
 * triangle, and a uniform grid of cubic cells over the triangles searched in shells of cells
 * around the query point until no unvisited cell can hold a nearer point. */
#include "metrics/surface_index.h"
#include "core/rsmooth_internal.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

/* ---- closest point on a triangle ------------------------------------------------------------- */

static double dist2_3(const double a[3], const double b[3]) {
    double d[3];
    rs_sub3(a, b, d);
    return rs_dot3(d, d);
}
/* Closest point of segment [a, b] to p; a zero-length segment is the point a. */
static double closest_on_segment(const double p[3], const double a[3], const double b[3],
                                 double out[3]) {
    double ab[3], ap[3];
    rs_sub3(b, a, ab);
    rs_sub3(p, a, ap);
    double len2 = rs_dot3(ab, ab), t = 0;
    if (len2 > 0) {
        t = rs_dot3(ap, ab) / len2;
        t = t < 0 ? 0 : t > 1 ? 1 : t;
    }
    for (int k = 0; k < 3; k++)
        out[k] = a[k] + t * ab[k];
    return dist2_3(p, out);
}

double rs_closest_on_triangle(const double p[3], const double a[3], const double b[3],
                              const double c[3], double closest[3]) {
    double ab[3], ac[3], n[3], q[3];
    rs_sub3(b, a, ab);
    rs_sub3(c, a, ac);
    rs_cross3(ab, ac, n);
    double ab2 = rs_dot3(ab, ab), ac2 = rs_dot3(ac, ac);
    /* Ericson's region tests divide by squared edge lengths and |n|^2, which vanish for collinear
     * or coincident corners (0/0 would poison every minimum taken over it); such a triangle is the
     * union of its edges, and a nearly degenerate one is that up to rounding. */
    if (!(rs_dot3(n, n) > 1e-24 * ab2 * ac2)) {
        double best = closest_on_segment(p, a, b, q), tmp[3];
        double d = closest_on_segment(p, b, c, tmp);
        if (d < best) {
            best = d;
            memcpy(q, tmp, sizeof q);
        }
        d = closest_on_segment(p, c, a, tmp);
        if (d < best) {
            best = d;
            memcpy(q, tmp, sizeof q);
        }
        if (closest)
            memcpy(closest, q, sizeof q);
        return best;
    }
    double ap[3], bp[3], cp[3];
    rs_sub3(p, a, ap);
    double d1 = rs_dot3(ab, ap), d2 = rs_dot3(ac, ap);
    if (d1 <= 0 && d2 <= 0) {
        memcpy(q, a, sizeof q);
        goto done;
    }
    rs_sub3(p, b, bp);
    double d3 = rs_dot3(ab, bp), d4 = rs_dot3(ac, bp);
    if (d3 >= 0 && d4 <= d3) {
        memcpy(q, b, sizeof q);
        goto done;
    }
    double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) {
        double t = d1 / (d1 - d3);
        for (int k = 0; k < 3; k++)
            q[k] = a[k] + t * ab[k];
        goto done;
    }
    rs_sub3(p, c, cp);
    double d5 = rs_dot3(ab, cp), d6 = rs_dot3(ac, cp);
    if (d6 >= 0 && d5 <= d6) {
        memcpy(q, c, sizeof q);
        goto done;
    }
    double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) {
        double t = d2 / (d2 - d6);
        for (int k = 0; k < 3; k++)
            q[k] = a[k] + t * ac[k];
        goto done;
    }
    double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
        double t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        for (int k = 0; k < 3; k++)
            q[k] = b[k] + t * (c[k] - b[k]);
        goto done;
    }
    {
        /* Inside: the projection onto the plane. Ericson's a + v ab + w ac loses digits on slivers
         * (v and w are ratios of cancelling products), which would put q off the plane. */
        double s = rs_dot3(ap, n) / rs_dot3(n, n);
        for (int k = 0; k < 3; k++)
            q[k] = p[k] - s * n[k];
    }
done:
    if (closest)
        memcpy(closest, q, sizeof q);
    return dist2_3(p, q);
}

/* ---- the grid -------------------------------------------------------------------------------- */

struct rs_surface_index {
    size_t triangle_count;
    double *corners;          /* 9 per triangle: copies, so queries touch one cache line run */
    double origin[3];         /* lower corner of the grid (the bounding box of all corners) */
    double upper[3];          /* upper corner of the bounding box */
    double cell;              /* edge of the cubic cells */
    long dims[3];             /* cells along each axis, >= 1 */
    size_t *cell_start;       /* dims[0]*dims[1]*dims[2] + 1 offsets into cell_triangles */
    uint32_t *cell_triangles; /* triangles whose bounding box meets the cell, cell by cell */
};

/* Cell of coordinate x along an axis, clamped into the grid; the same rule for insertion and
 * queries, so a point of a triangle always lies in a cell that lists the triangle. */
static long cell_of(const rs_surface_index *ix, int axis, double x) {
    double t = (x - ix->origin[axis]) / ix->cell;
    if (!(t >= 0))
        return 0;
    if (t >= (double)(ix->dims[axis] - 1))
        return ix->dims[axis] - 1;
    return (long)t;
}

static void triangle_bounds(const double *tri, double lo[3], double hi[3]) {
    for (int k = 0; k < 3; k++) {
        lo[k] = fmin(tri[k], fmin(tri[3 + k], tri[6 + k]));
        hi[k] = fmax(tri[k], fmax(tri[3 + k], tri[6 + k]));
    }
}

/* Dimensions for cell size `cell`; false when they exceed `max_cells` in all. */
static bool set_dims(rs_surface_index *ix, double cell, size_t max_cells) {
    ix->cell = cell;
    size_t total = 1;
    for (int k = 0; k < 3; k++) {
        double n = floor((ix->upper[k] - ix->origin[k]) / cell) + 1;
        if (!(n <= (double)max_cells))
            return false;
        ix->dims[k] = (long)n;
        total *= (size_t)n;
        if (total > max_cells)
            return false;
    }
    return true;
}

/* Triangle-to-cell references for the current cell size, or SIZE_MAX beyond `limit`. */
static size_t count_references(const rs_surface_index *ix, size_t limit) {
    size_t total = 0;
    for (size_t t = 0; t < ix->triangle_count; t++) {
        double lo[3], hi[3];
        triangle_bounds(ix->corners + 9 * t, lo, hi);
        size_t n = 1;
        for (int k = 0; k < 3; k++)
            n *= (size_t)(cell_of(ix, k, hi[k]) - cell_of(ix, k, lo[k]) + 1);
        total += n;
        if (total > limit)
            return SIZE_MAX;
    }
    return total;
}

rs_surface_index *rs_surface_index_build(const double *xyz, size_t vertex_count,
                                         const uint32_t *triangles, size_t triangle_count) {
    if ((triangle_count > 0 && (!xyz || !triangles)) || triangle_count > UINT32_MAX ||
        triangle_count > SIZE_MAX / (9 * sizeof(double)))
        return NULL;
    rs_surface_index *ix = rs_calloc_array(1, sizeof *ix);
    if (!ix)
        return NULL;
    ix->triangle_count = triangle_count;
    if (triangle_count == 0)
        return ix;
    ix->corners = rs_alloc_array(triangle_count, 9 * sizeof *ix->corners);
    if (!ix->corners)
        goto fail;
    double extent_sum = 0;
    for (int k = 0; k < 3; k++) {
        ix->origin[k] = INFINITY;
        ix->upper[k] = -INFINITY;
    }
    for (size_t t = 0; t < triangle_count; t++) {
        for (int c = 0; c < 3; c++) {
            uint32_t v = triangles[3 * t + c];
            if (v >= vertex_count)
                goto fail;
            for (int k = 0; k < 3; k++) {
                double x = xyz[3 * (size_t)v + k];
                if (!isfinite(x))
                    goto fail;
                ix->corners[9 * t + 3 * c + k] = x;
            }
        }
        double lo[3], hi[3];
        triangle_bounds(ix->corners + 9 * t, lo, hi);
        double e = 0;
        for (int k = 0; k < 3; k++) {
            e = fmax(e, hi[k] - lo[k]);
            ix->origin[k] = fmin(ix->origin[k], lo[k]);
            ix->upper[k] = fmax(ix->upper[k], hi[k]);
        }
        extent_sum += e;
    }
    double diag = sqrt(dist2_3(ix->origin, ix->upper));
    if (!isfinite(diag))
        goto fail; /* coordinates near DBL_MAX: extents overflow */
    /* Cells about the size of a triangle keep a query to a few dozen triangles; a surface fills few
     * cells of its bounding box, so the cell count is capped near the triangle count (larger cells
     * then hold more triangles each), and a few huge triangles must not list themselves in
     * millions of cells. */
    double cell = extent_sum / (double)triangle_count;
    if (!(cell > 0))
        cell = diag > 0 ? diag / cbrt((double)triangle_count) : 1.0;
    size_t max_cells = 4 * triangle_count + 64;
    size_t max_refs = 32 * triangle_count + 1024;
    size_t refs;
    for (;;) {
        if (set_dims(ix, cell, max_cells) && (refs = count_references(ix, max_refs)) != SIZE_MAX)
            break;
        cell *= 1.25;
    }
    size_t cell_count = (size_t)ix->dims[0] * (size_t)ix->dims[1] * (size_t)ix->dims[2];
    ix->cell_start = rs_calloc_array(cell_count + 1, sizeof *ix->cell_start);
    ix->cell_triangles = rs_alloc_array(refs ? refs : 1, sizeof *ix->cell_triangles);
    if (!ix->cell_start || !ix->cell_triangles)
        goto fail;
    /* Two passes (count, then fill) give compact per-cell lists without per-cell allocations. */
    for (int pass = 0; pass < 2; pass++) {
        for (size_t t = 0; t < triangle_count; t++) {
            double lo[3], hi[3];
            triangle_bounds(ix->corners + 9 * t, lo, hi);
            long c0[3], c1[3];
            for (int k = 0; k < 3; k++) {
                c0[k] = cell_of(ix, k, lo[k]);
                c1[k] = cell_of(ix, k, hi[k]);
            }
            for (long z = c0[2]; z <= c1[2]; z++)
                for (long y = c0[1]; y <= c1[1]; y++)
                    for (long x = c0[0]; x <= c1[0]; x++) {
                        size_t cidx =
                            ((size_t)z * (size_t)ix->dims[1] + (size_t)y) * (size_t)ix->dims[0] +
                            (size_t)x;
                        if (pass == 0)
                            ix->cell_start[cidx + 1]++;
                        else
                            ix->cell_triangles[ix->cell_start[cidx]++] = (uint32_t)t;
                    }
        }
        if (pass == 0) {
            for (size_t i = 0; i < cell_count; i++)
                ix->cell_start[i + 1] += ix->cell_start[i];
        } else {
            /* Filling advanced each start to the next cell's start: shift back. */
            memmove(ix->cell_start + 1, ix->cell_start, cell_count * sizeof *ix->cell_start);
            ix->cell_start[0] = 0;
        }
    }
    return ix;
fail:
    rs_surface_index_free(ix);
    return NULL;
}

void rs_surface_index_free(rs_surface_index *index) {
    if (!index)
        return;
    rs_free(index->corners);
    rs_free(index->cell_start);
    rs_free(index->cell_triangles);
    rs_free(index);
}

typedef struct query_state {
    const double *p;
    double best; /* squared distance */
    double closest[3];
    size_t triangle;
} query_state;

static void visit_cell(const rs_surface_index *ix, long x, long y, long z, query_state *q) {
    size_t cidx = ((size_t)z * (size_t)ix->dims[1] + (size_t)y) * (size_t)ix->dims[0] + (size_t)x;
    for (size_t i = ix->cell_start[cidx]; i < ix->cell_start[cidx + 1]; i++) {
        uint32_t t = ix->cell_triangles[i];
        const double *tri = ix->corners + 9 * (size_t)t;
        double c[3];
        double d = rs_closest_on_triangle(q->p, tri, tri + 3, tri + 6, c);
        /* Ties go to the lower triangle number, so the answer does not depend on visiting order. */
        if (d < q->best || (d == q->best && t < q->triangle)) {
            q->best = d;
            q->triangle = t;
            memcpy(q->closest, c, sizeof c);
        }
    }
}

/* A lower bound on the squared distance from p to every cell outside the box of cells within
 * Chebyshev distance r of c0 (all of them already visited); -1 when that box is the whole grid. A
 * point of such a cell lies beyond one face of the box along some axis and inside the grid along
 * the others. */
static double unvisited_bound2(const rs_surface_index *ix, const double p[3], const long c0[3],
                               long r, const double outside2[3]) {
    double total_out2 = outside2[0] + outside2[1] + outside2[2], bound2 = -1;
    for (int k = 0; k < 3; k++) {
        double others = total_out2 - outside2[k], face = -1;
        /* Rounding in cell_of() may put p a hair across a cell face; the slack covers it. */
        double slack = 1e-12 * (fabs(p[k]) + fabs(ix->origin[k])) + 1e-9 * ix->cell;
        if (c0[k] - r > 0) {
            face = p[k] - (ix->origin[k] + (double)(c0[k] - r) * ix->cell) - slack;
            face = face > 0 ? face : 0;
            double b = face * face + others;
            bound2 = bound2 < 0 ? b : fmin(bound2, b);
        }
        if (c0[k] + r < ix->dims[k] - 1) {
            face = (ix->origin[k] + (double)(c0[k] + r + 1) * ix->cell) - p[k] - slack;
            face = face > 0 ? face : 0;
            double b = face * face + others;
            bound2 = bound2 < 0 ? b : fmin(bound2, b);
        }
    }
    return bound2;
}

double rs_surface_index_query(const rs_surface_index *index, const double point[3],
                              double closest[3], size_t *triangle) {
    if (!index || index->triangle_count == 0 || !isfinite(point[0]) || !isfinite(point[1]) ||
        !isfinite(point[2]))
        return INFINITY;
    const rs_surface_index *ix = index;
    query_state q = {point, INFINITY, {0, 0, 0}, SIZE_MAX};
    long c0[3];
    double outside2[3];
    for (int k = 0; k < 3; k++) {
        c0[k] = cell_of(ix, k, point[k]);
        double o = point[k] < ix->origin[k]  ? ix->origin[k] - point[k]
                   : point[k] > ix->upper[k] ? point[k] - ix->upper[k]
                                             : 0;
        outside2[k] = o * o;
    }
    /* Shells of cells around p's cell, nearest first, until no unvisited cell can be nearer. */
    for (long r = 0;; r++) {
        if (r > 0) {
            double bound2 = unvisited_bound2(ix, point, c0, r - 1, outside2);
            if (bound2 < 0 || bound2 > q.best)
                break;
        }
        long lo[3], hi[3];
        for (int k = 0; k < 3; k++) {
            lo[k] = c0[k] - r > 0 ? c0[k] - r : 0;
            hi[k] = c0[k] + r < ix->dims[k] - 1 ? c0[k] + r : ix->dims[k] - 1;
        }
        for (long x = lo[0]; x <= hi[0]; x++) {
            for (long y = lo[1]; y <= hi[1]; y++) {
                if (labs(x - c0[0]) == r || labs(y - c0[1]) == r) {
                    for (long z = lo[2]; z <= hi[2]; z++)
                        visit_cell(ix, x, y, z, &q);
                } else {
                    /* Inside the shell in x and y: only its two z faces are new. */
                    if (c0[2] - r >= 0)
                        visit_cell(ix, x, y, c0[2] - r, &q);
                    if (r > 0 && c0[2] + r < ix->dims[2])
                        visit_cell(ix, x, y, c0[2] + r, &q);
                }
            }
        }
    }
    if (q.triangle == SIZE_MAX)
        return INFINITY; /* unreachable: the shells end only after covering the grid */
    if (closest)
        memcpy(closest, q.closest, sizeof q.closest);
    if (triangle)
        *triangle = q.triangle;
    return sqrt(q.best);
}
