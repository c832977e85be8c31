/* The fold guard: no triangle comes out turned over. What "turned over" means depends on what the
 * input is:
 *  - a clean mesh (its bends correlated, core/shape_correlation.h, or on a mesh of up to
 *    ESTIMATE_VERTICES what the noise estimate reads as nothing to remove): the input is the
 *    shape, and a triangle whose normal turns by more than 90 degrees from the input's is turned
 *    over;
 *  - a noisy mesh: its triangles' normals scatter, and the filter may rightly turn one by more
 *    than 90 degrees (from one side of the true normal to the other, or unfolding one the noise
 *    folded); a triangle is turned over when it comes out facing against its neighbourhood (the
 *    unit normals of the triangles at its corners summed, in the result) and its input did not
 *    face against the input's.
 * Which applies is measured only when a triangle is turned over by either reading.
 *
 * Each round finds every triangle turned over and moves each of their vertices: on a noisy mesh
 * first, for UNTANGLES rounds, to the mean of its neighbours (a fold in a smoothed result is an
 * artefact, and the input there is noise: untangling it smooths, where pulling back would bring
 * the noise back; a boundary vertex along the boundary, no farther from the input than the
 * filter put it, so holes do not open); then halfway back toward the input (where none is turned
 * over), and after HALVINGS such rounds to the input exactly, with two rings of vertices around.
 * Host code, double precision, one thread, in index order: the same bytes on every run and for both
 * paths. tests/python/region_blend.py carries an independent numpy copy (a test compares).
 * (Snapping a triangle's corners and the ring of vertices around them to the input makes its
 * neighbourhood the input's, where it did not face against it: each snapping round snaps some
 * vertex anew, so the rounds end.) */
#include "stages/fold_guard.h"
#include "auto/noise_estimate.h"
#include "core/incidence.h"
#include "core/shape_correlation.h"
#include "core/weld.h"

#include <math.h>
#include <string.h>

/* Up to this many vertices, a mesh whose bends do not correlate is read by the whole noise
 * estimate (auto/noise_estimate.h, 81 ms on the 35k-vertex Bunny0.2): a coarse clean mesh, the
 * decimated knight, reads clean that way. Larger ones are read by the correlation alone (the
 * estimate would cost 0.66 s on 500k vertices, twice the filter's time); clean meshes that large
 * are fine for their shape, and their bends correlate. */
#define ESTIMATE_VERTICES 50000
#define UNTANGLES 8
#define NORMAL_GRAIN 8192 /* triangles per chunk of the threaded normals */
#define HALVINGS 24

/* The unit normal of triangle tri over xyz (double, 3 per vertex), or false when degenerate. The
 * edges are divided by their largest component first, so neither overflows nor underflows. */
static bool unit_normal(const double *xyz, const uint32_t *tri, double n[3]) {
    double e1[3], e2[3];
    rs_sub3(xyz + 3 * (size_t)tri[1], xyz + 3 * (size_t)tri[0], e1);
    rs_sub3(xyz + 3 * (size_t)tri[2], xyz + 3 * (size_t)tri[0], e2);
    double m = 0;
    for (int k = 0; k < 3; k++)
        m = fmax(m, fmax(fabs(e1[k]), fabs(e2[k])));
    if (!(m > 0) || !isfinite(m))
        return false;
    for (int k = 0; k < 3; k++) {
        e1[k] /= m;
        e2[k] /= m;
    }
    rs_cross3(e1, e2, n);
    double len = sqrt(rs_dot3(n, n));
    if (!(len > 0))
        return false;
    for (int k = 0; k < 3; k++)
        n[k] /= len;
    return true;
}

typedef enum reading { UNDECIDED, CLEAN, NOISY } reading;

typedef struct guard {
    size_t vertex_count, triangle_count;
    const uint32_t *indices;
    double *in, *out;    /* 3 per vertex */
    double *n_in;        /* 3 per triangle: the input's unit normal (0 when degenerate) */
    double *n_out;       /* 3 per triangle: the result's, this round */
    double *at_vertex;   /* 3 per vertex: scratch of the sums */
    double *around;      /* 3 per triangle: the result's neighbourhood normal, this round */
    uint8_t *folded_in;  /* per triangle: the input faced against the input's neighbourhood */
    uint8_t *corner;     /* per vertex: a corner of a triangle turned over this round */
    uint8_t *pulled;     /* per vertex: pulled back at least once */
    const uint8_t *held; /* per vertex: 0 where the call holds it still (NULL: none held) */
    uint32_t *rep;       /* per vertex: its welded vertex (a noisy mesh's untangling) */
    uint8_t *boundary;   /* per welded vertex: on an edge of one triangle */
    uint64_t *welded;    /* the welded mesh's edges (low << 32 | high), and how many */
    size_t welded_count;
    uint64_t *edge; /* the boundary's edges among them */
    size_t edge_count;
    double *reach; /* per vertex: its distance from the input in the filter's result */
    double *sum;   /* 3 per vertex, and the count: the neighbours of welded vertices */
    double *count;
    reading mesh;
    /* Each round after the first tests only the triangles near what the round before moved: */
    size_t *first;      /* vertex_count + 1: the triangles at vertex v are triangle[first[v] ..] */
    uint32_t *triangle; /*   in index order (so sums over them run in the full pass's order) */
    uint32_t *moved;    /* the vertices this round moved, and how many */
    size_t moved_count;
    uint32_t *check; /* the triangles the next round tests, and how many */
    size_t check_count;
    uint8_t *listed;  /* per triangle: in `check` (scratch) */
    uint8_t *touched; /* per vertex: its sum redone this round (scratch) */
} guard;

/* The sums at_vertex over triangle t's corners into to[t]. */
static void corner_sum(const guard *g, const double *at_vertex, size_t t, double *to) {
    const uint32_t *tri = g->indices + 3 * t;
    for (int k = 0; k < 3; k++)
        to[3 * t + (size_t)k] = at_vertex[3 * (size_t)tri[0] + (size_t)k] +
                                at_vertex[3 * (size_t)tri[1] + (size_t)k] +
                                at_vertex[3 * (size_t)tri[2] + (size_t)k];
}

/* Sums per-triangle vectors `from` at each triangle's vertices into at_vertex, then those sums
 * over each triangle's corners into `to` (from and to may be one array). */
static void gather_ring(const guard *g, const double *from, double *at_vertex, double *to) {
    memset(at_vertex, 0, 3 * g->vertex_count * sizeof *at_vertex);
    for (size_t t = 0; t < g->triangle_count; t++)
        for (int c = 0; c < 3; c++)
            for (int k = 0; k < 3; k++)
                at_vertex[3 * (size_t)g->indices[3 * t + c] + (size_t)k] += from[3 * t + (size_t)k];
    for (size_t t = 0; t < g->triangle_count; t++)
        corner_sum(g, at_vertex, t, to);
}

/* Unit normals of every triangle over xyz into n (zeros where degenerate), and each triangle's
 * neighbourhood normal into `around`: the unit normals of the triangles sharing a vertex with it,
 * summed. (Two rings read fewer folds under heavy noise but misread thin parts of coarse meshes,
 * a cow's legs, as folded: 13% more E_v on cow-n0.5.) */
typedef struct normal_job {
    const uint32_t *indices;
    const double *xyz;
    double *n;
} normal_job;

static void normal_range(void *ctx, size_t begin, size_t end, size_t chunk) {
    const normal_job *job = ctx;
    (void)chunk;
    for (size_t t = begin; t < end; t++) {
        double *nt = job->n + 3 * t;
        if (!unit_normal(job->xyz, job->indices + 3 * t, nt))
            nt[0] = nt[1] = nt[2] = 0;
    }
}

static void normals(const guard *g, const double *xyz, double *n, double *around) {
    normal_job job = {g->indices, xyz, n}; /* each triangle's own: any split gives the same */
    rs_parallel_for(g->triangle_count, NORMAL_GRAIN, normal_range, &job);
    gather_ring(g, n, g->at_vertex, around);
}

/* n . around: how t faces its neighbourhood. */
static double facing(const double *n, const double *around, size_t t) {
    return rs_dot3(n + 3 * t, around + 3 * t);
}

static bool degenerate(const double *n) {
    return n[0] == 0 && n[1] == 0 && n[2] == 0;
}

/* Turned over by the clean reading (against the input's normal) and by the noisy one. */
static bool turned_clean(const guard *g, size_t t) {
    const double *a = g->n_in + 3 * t, *b = g->n_out + 3 * t;
    return !degenerate(a) && !degenerate(b) && rs_dot3(a, b) < 0;
}

static bool turned_noisy(const guard *g, size_t t) {
    const double *b = g->n_out + 3 * t;
    if (degenerate(g->n_in + 3 * t) || degenerate(b))
        return false;
    return !g->folded_in[t] && facing(g->n_out, g->around, t) < 0;
}

static bool turned(const guard *g, size_t t) {
    return g->mesh == CLEAN ? turned_clean(g, t) : turned_noisy(g, t);
}

/* The weld, its edges and the boundary (welded vertices on an edge one triangle alone has, and
 * those edges). false when out of memory. */
static bool find_boundary(guard *g) {
    g->rep = rs_alloc_array(g->vertex_count, sizeof *g->rep);
    g->boundary = rs_calloc_array(g->vertex_count, 1);
    uint8_t *single = NULL;
    bool ok = g->rep && g->boundary && rs_weld(g->in, g->vertex_count, g->rep) &&
              (g->welded = rs_welded_edges(g->rep, g->indices, g->triangle_count, &g->welded_count,
                                           &single)) != NULL;
    g->edge = ok ? rs_alloc_array(g->welded_count ? g->welded_count : 1, sizeof *g->edge) : NULL;
    ok = ok && g->edge;
    for (size_t i = 0; ok && i < g->welded_count; i++)
        if (single[i]) {
            uint64_t key = g->welded[i];
            g->boundary[key >> 32] = g->boundary[key & 0xffffffffu] = 1;
            g->edge[g->edge_count++] = key;
        }
    rs_free(single);
    return ok;
}

/* Whether the input reads clean; only measured once a triangle is turned over either way. false
 * when out of memory. */
static bool decide(guard *g, rsmooth_scalar scalar, const void *positions) {
    bool any = false;
    for (size_t t = 0; t < g->triangle_count && !any; t++)
        any = turned_clean(g, t) || turned_noisy(g, t);
    if (!any) {
        g->mesh = CLEAN; /* nothing to pull back either way */
        return true;
    }
    /* one weld for the reading and the untangling; internal units for the correlation's
     * rounding floor (scale.c: a power of two) */
    int e = 0;
    frexp(rs_typical_edge(scalar, positions, g->indices, g->triangle_count), &e);
    double *xyz = rs_alloc_array(g->vertex_count, 3 * sizeof *xyz);
    double correlation = 1;
    bool ok = xyz && find_boundary(g);
    for (size_t i = 0; ok && i < 3 * g->vertex_count; i++)
        xyz[i] = ldexp(g->in[i], -e);
    ok = ok && rs_shape_correlation_welded(xyz, g->vertex_count, g->indices, g->triangle_count,
                                           g->rep, g->welded, g->welded_count, &correlation);
    rs_free(xyz);
    g->mesh = correlation >= RS_CLEAN_SHAPE_CORRELATION ? CLEAN : NOISY;
    if (ok && g->mesh == NOISY && g->vertex_count <= ESTIMATE_VERTICES) {
        rs_noise_details noise; /* the same verdict as --auto's */
        ok = rs_estimate_noise_details(scalar, positions, g->vertex_count, g->indices,
                                       g->triangle_count, &noise, NULL,
                                       "rs_fold_guard") == RSMOOTH_OK;
        g->mesh = ok && rs_noise_reads_clean(&noise) ? CLEAN : NOISY;
    }
    if (ok && g->mesh == NOISY) {
        g->sum = rs_alloc_array(g->vertex_count, 3 * sizeof *g->sum);
        g->count = rs_alloc_array(g->vertex_count, sizeof *g->count);
        g->reach = rs_alloc_array(g->vertex_count, sizeof *g->reach);
        ok = g->sum && g->count && g->reach;
        for (size_t v = 0; ok && v < g->vertex_count; v++) {
            double d[3];
            rs_sub3(g->out + 3 * v, g->in + 3 * v, d);
            g->reach[v] = sqrt(rs_dot3(d, d));
        }
    }
    return ok;
}

/* Marks the corners of every triangle that has a marked corner, `rings` times over: a
 * triangle's neighbourhood normal reads the triangles at its corners, whose corners lie a ring
 * of vertices out. */
static void widen(guard *g, int rings) {
    for (uint8_t ring = 1; ring <= rings; ring++)
        for (size_t t = 0; t < g->triangle_count; t++) {
            const uint32_t *tri = g->indices + 3 * t;
            bool seed = false;
            for (int c = 0; c < 3; c++)
                seed = seed || (g->corner[tri[c]] && g->corner[tri[c]] <= ring);
            for (int c = 0; c < 3 && seed; c++)
                if (!g->corner[tri[c]])
                    g->corner[tri[c]] = (uint8_t)(ring + 1);
        }
}

/* Moves every vertex welded to a marked one to the mean of the other corners of the triangles at
 * its welded vertex (each triangle's two, so an edge inside the mesh counts twice). On the
 * boundary that mean lies inside, and a scan's holes would open: there, to the mean of its
 * neighbours along the boundary, and no farther from the input than the filter put it. */
static void untangle(guard *g) {
    memset(g->sum, 0, 3 * g->vertex_count * sizeof *g->sum);
    memset(g->count, 0, g->vertex_count * sizeof *g->count);
    for (size_t v = 0; v < g->vertex_count; v++) /* marks go to the welded vertex */
        if (g->corner[v])
            g->corner[g->rep[v]] = 1;
    for (size_t t = 0; t < g->triangle_count; t++) {
        const uint32_t *tri = g->indices + 3 * t;
        for (int c = 0; c < 3; c++) {
            uint32_t r = g->rep[tri[c]];
            if (!g->corner[r])
                continue;
            for (int o = 1; o < 3; o++)
                for (int k = 0; k < 3; k++)
                    g->sum[3 * (size_t)r + (size_t)k] += g->out[3 * (size_t)tri[(c + o) % 3] + k];
            g->count[r] += 2;
        }
    }
    for (size_t v = 0; v < g->vertex_count; v++) /* the boundary's: along the boundary */
        if (g->corner[v] && g->boundary[v]) {
            memset(g->sum + 3 * v, 0, 3 * sizeof *g->sum);
            g->count[v] = 0;
        }
    for (size_t i = 0; i < g->edge_count; i++) {
        size_t a = (size_t)(g->edge[i] >> 32), b = (size_t)(g->edge[i] & 0xffffffffu);
        for (int end = 0; end < 2; end++) {
            size_t r = end ? b : a, o = end ? a : b;
            if (!g->corner[r])
                continue;
            for (int k = 0; k < 3; k++)
                g->sum[3 * r + (size_t)k] += g->out[3 * o + (size_t)k];
            g->count[r]++;
        }
    }
    for (size_t v = 0; v < g->vertex_count; v++) {
        uint32_t r = g->rep[v];
        if (!g->corner[r] || !(g->count[r] > 0) || (g->held && !g->held[v]))
            continue;
        double *o = g->out + 3 * v, d[3];
        const double *in = g->in + 3 * v;
        for (int k = 0; k < 3; k++) {
            o[k] = g->sum[3 * (size_t)r + (size_t)k] / g->count[r];
            d[k] = o[k] - in[k];
        }
        double length = sqrt(rs_dot3(d, d));
        if (g->boundary[r] && length > g->reach[v])
            for (int k = 0; k < 3; k++)
                o[k] = in[k] + d[k] * (g->reach[v] / length);
        g->pulled[v] = 1;
        g->moved[g->moved_count++] = (uint32_t)v;
    }
}

/* One round: finds every triangle turned over, then moves each of their vertices back once
 * (halfway, or when `snap` to the input, with the vertices of the triangles around: a triangle
 * can face against a neighbourhood that moved, and the input's faced it right), so the round
 * does not depend on the triangles' order. Returns how many triangles were turned over. */
static size_t pull_back(guard *g, int round) {
    bool snap = round >= (g->mesh == NOISY ? UNTANGLES : 0) + HALVINGS;
    size_t found = 0, tested = round == 0 ? g->triangle_count : g->check_count;
    memset(g->corner, 0, g->vertex_count);
    g->moved_count = 0;
    for (size_t i = 0; i < tested; i++) {
        size_t t = round == 0 ? i : g->check[i];
        if (turned(g, t)) {
            g->check[found++] = (uint32_t)t; /* (kept for the next round: i >= found) */
            for (int c = 0; c < 3; c++)
                g->corner[g->indices[3 * t + c]] = 1;
        }
    }
    g->check_count = found;
    if (found && g->mesh == NOISY && round < UNTANGLES) {
        untangle(g);
        return found;
    }
    if (snap && found)
        widen(g, 2);
    for (size_t v = 0; found && v < g->vertex_count; v++) {
        if (!g->corner[v] || (g->held && !g->held[v]))
            continue;
        double *o = g->out + 3 * v;
        const double *i = g->in + 3 * v;
        if (o[0] != i[0] || o[1] != i[1] || o[2] != i[2])
            g->pulled[v] = 1; /* (a vertex the filter left in place is not counted) */
        for (int k = 0; k < 3; k++)
            o[k] = snap ? i[k] : i[k] + (o[k] - i[k]) / 2;
        g->moved[g->moved_count++] = (uint32_t)v;
    }
    return found;
}

/* After a round's moves: the normals of the triangles at the moved vertices, the sums at their
 * corners and the neighbourhood normals that read them, each recomputed as the full pass does
 * (the same sums in the same order); those triangles, and the ones turned this round, are what
 * the next round tests. */
static void refresh(guard *g) {
    size_t listed = g->check_count;
    for (size_t i = 0; i < listed; i++)
        g->listed[g->check[i]] = 1;
    for (size_t m = 0; m < g->moved_count; m++) { /* the moved vertices' triangles */
        uint32_t v = g->moved[m];
        for (size_t i = g->first[v]; i < g->first[v + 1]; i++) {
            uint32_t t = g->triangle[i];
            double *nt = g->n_out + 3 * (size_t)t;
            if (!unit_normal(g->out, g->indices + 3 * (size_t)t, nt))
                nt[0] = nt[1] = nt[2] = 0;
            for (int c = 0; c < 3; c++)
                g->touched[g->indices[3 * (size_t)t + c]] = 1;
        }
    }
    for (size_t m = 0; m < g->moved_count; m++) /* the sums at their corners */
        for (size_t i = g->first[g->moved[m]]; i < g->first[g->moved[m] + 1]; i++)
            for (int c = 0; c < 3; c++) {
                uint32_t v = g->indices[3 * (size_t)g->triangle[i] + c];
                if (g->touched[v] != 1)
                    continue;
                g->touched[v] = 2; /* (done) */
                double *a = g->at_vertex + 3 * (size_t)v;
                a[0] = a[1] = a[2] = 0;
                for (size_t j = g->first[v]; j < g->first[v + 1]; j++)
                    for (int k = 0; k < 3; k++)
                        a[k] += g->n_out[3 * (size_t)g->triangle[j] + (size_t)k];
                for (size_t j = g->first[v]; j < g->first[v + 1]; j++) {
                    uint32_t t = g->triangle[j]; /* the neighbourhoods that read the sum */
                    if (!g->listed[t]) {
                        g->listed[t] = 1;
                        g->check[listed++] = t;
                    }
                }
            }
    for (size_t i = 0; i < listed; i++) {
        corner_sum(g, g->at_vertex, g->check[i], g->around);
        g->listed[g->check[i]] = 0;
    }
    for (size_t m = 0; m < g->moved_count; m++) /* clear the scratch */
        for (size_t i = g->first[g->moved[m]]; i < g->first[g->moved[m] + 1]; i++)
            for (int c = 0; c < 3; c++)
                g->touched[g->indices[3 * (size_t)g->triangle[i] + c]] = 0;
    g->check_count = listed;
}

static void free_guard(guard *g) {
    rs_free(g->in);
    rs_free(g->out);
    rs_free(g->n_in);
    rs_free(g->n_out);
    rs_free(g->at_vertex);
    rs_free(g->around);
    rs_free(g->folded_in);
    rs_free(g->corner);
    rs_free(g->pulled);
    rs_free(g->rep);
    rs_free(g->boundary);
    rs_free(g->edge);
    rs_free(g->welded);
    rs_free(g->reach);
    rs_free(g->first);
    rs_free(g->triangle);
    rs_free(g->moved);
    rs_free(g->check);
    rs_free(g->listed);
    rs_free(g->touched);
    rs_free(g->sum);
    rs_free(g->count);
}

long rs_fold_guard(rsmooth_scalar scalar, const void *positions, void *out_positions,
                   size_t vertex_count, const uint32_t *indices, size_t triangle_count,
                   const uint8_t *movable) {
    if (triangle_count == 0 || vertex_count == 0)
        return 0;
    guard g;
    memset(&g, 0, sizeof g);
    g.vertex_count = vertex_count;
    g.triangle_count = triangle_count;
    g.indices = indices;
    g.held = movable;
    g.in = rs_alloc_array(vertex_count, 3 * sizeof(double));
    g.out = rs_alloc_array(vertex_count, 3 * sizeof(double));
    g.n_in = rs_alloc_array(triangle_count, 3 * sizeof(double));
    g.n_out = rs_alloc_array(triangle_count, 3 * sizeof(double));
    g.at_vertex = rs_alloc_array(vertex_count, 3 * sizeof(double));
    g.around = rs_alloc_array(triangle_count, 3 * sizeof(double));
    g.folded_in = rs_alloc_array(triangle_count, 1);
    g.corner = rs_alloc_array(vertex_count, 1);
    g.pulled = rs_calloc_array(vertex_count, 1);
    long pulled = -1;
    if (!g.in || !g.out || !g.n_in || !g.n_out || !g.at_vertex || !g.around || !g.folded_in ||
        !g.corner || !g.pulled)
        goto done;
    for (size_t i = 0; i < 3 * vertex_count; i++) {
        g.in[i] = rs_coordinate(scalar, positions, i);
        g.out[i] = rs_coordinate(scalar, out_positions, i);
    }
    normals(&g, g.in, g.n_in, g.around);
    for (size_t t = 0; t < triangle_count; t++)
        g.folded_in[t] = facing(g.n_in, g.around, t) <= 0;
    normals(&g, g.out, g.n_out, g.around);
    if (!decide(&g, scalar, positions))
        goto done;
    g.moved = rs_alloc_array(vertex_count, sizeof *g.moved);
    g.check = rs_alloc_array(triangle_count, sizeof *g.check);
    g.listed = rs_calloc_array(triangle_count, 1);
    g.touched = rs_calloc_array(vertex_count, 1);
    if (!g.moved || !g.check || !g.listed || !g.touched)
        goto done;
    for (int round = 0; pull_back(&g, round) > 0; round++) {
        if (!g.first &&
            !rs_vertex_triangles(indices, triangle_count, vertex_count, &g.first, &g.triangle))
            goto done;
        refresh(&g);
    }
    pulled = 0;
    for (size_t v = 0; v < vertex_count; v++)
        if (g.pulled[v]) {
            pulled++;
            rs_store_position(scalar, out_positions, v, g.out + 3 * v, 1);
        }
done:
    free_guard(&g);
    return pulled;
}
