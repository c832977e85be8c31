/* The fold guard: no triangle comes out reversed. A triangle is reversed by the filter when its
 * normal turns by more than 90 degrees from the input's, unless the input's own triangle was
 * folded against its neighbourhood and the mesh reads noisy (noise folds triangles, and the filter
 * may unfold them; a clean mesh's folds, a fin or a sliver in a crease, are its shape). The
 * neighbourhood's normal is the sum of the unit normals of the triangles at its corners; the mesh
 * reads noisy when its bends are not correlated (core/shape_correlation.h), which is measured
 * only when such a triangle would turn.
 *
 * Each round halves the move of every vertex of a reversed triangle (the result slides back
 * toward the input, where no triangle is reversed); after HALVINGS rounds the vertices of a
 * triangle still reversed go back to the input exactly. Host code, double precision, one thread,
 * in index order: the same bytes on every run and for both paths. */
#include "core/shape_correlation.h"
#include "stages/fold_guard.h"

#include <math.h>
#include <string.h>

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

typedef struct guard {
    size_t vertex_count, triangle_count;
    const uint32_t *indices;
    double *in, *out;  /* 3 per vertex */
    double *reference; /* 3 per triangle: the input's neighbourhood normal */
    uint8_t *may_flip; /* per triangle: 2 degenerate in the input, 1 folded against its
                        * neighbourhood (may unfold when the mesh reads noisy), 0 neither */
    bool noisy;        /* folded triangles may unfold */
    uint8_t *halved;   /* per vertex, this round */
    uint8_t *pulled;   /* per vertex: pulled back at least once */
} guard;

static bool reversed(const guard *g, size_t t) {
    if (g->may_flip[t] == 2 || (g->may_flip[t] == 1 && g->noisy))
        return false;
    double n_in[3], n_out[3];
    const uint32_t *tri = g->indices + 3 * t;
    if (!unit_normal(g->in, tri, n_in) || !unit_normal(g->out, tri, n_out))
        return false;
    return rs_dot3(n_out, n_in) < 0;
}

/* The input's unit normals summed at each vertex, then at each triangle's corners. */
static bool reference_normals(guard *g) {
    double *at_vertex = rs_calloc_array(g->vertex_count ? g->vertex_count : 1, 3 * sizeof(double));
    if (!at_vertex)
        return false;
    double n[3];
    for (size_t t = 0; t < g->triangle_count; t++)
        if (unit_normal(g->in, g->indices + 3 * t, n))
            for (int c = 0; c < 3; c++)
                for (int k = 0; k < 3; k++)
                    at_vertex[3 * (size_t)g->indices[3 * t + c] + (size_t)k] += n[k];
    for (size_t t = 0; t < g->triangle_count; t++) {
        double *r = g->reference + 3 * t;
        const uint32_t *tri = g->indices + 3 * t;
        for (int k = 0; k < 3; k++)
            r[k] = at_vertex[3 * (size_t)tri[0] + (size_t)k] +
                   at_vertex[3 * (size_t)tri[1] + (size_t)k] +
                   at_vertex[3 * (size_t)tri[2] + (size_t)k];
        g->may_flip[t] = !unit_normal(g->in, tri, n) ? 2 : !(rs_dot3(n, r) > 0);
    }
    rs_free(at_vertex);
    return true;
}

/* One round over the triangles: moves the vertices of each reversed one back (halfway, or to the
 * input when `snap`). Returns how many triangles were reversed. */
static size_t pull_back(guard *g, bool snap) {
    size_t found = 0;
    memset(g->halved, 0, g->vertex_count);
    for (size_t t = 0; t < g->triangle_count; t++) {
        if (!reversed(g, t))
            continue;
        found++;
        for (int c = 0; c < 3; c++) {
            size_t v = g->indices[3 * t + c];
            if (g->halved[v])
                continue;
            g->halved[v] = 1;
            for (int k = 0; k < 3; k++) {
                double *o = g->out + 3 * v + k;
                double i = g->in[3 * v + k];
                *o = snap ? i : i + (*o - i) / 2;
            }
            if (memcmp(g->out + 3 * v, g->in + 3 * v, 3 * sizeof(double)) != 0 || snap)
                g->pulled[v] = 1;
        }
    }
    return found;
}

/* Whether an input triangle folded against its neighbourhood turns over. */
static bool folded_turns(guard *g) {
    for (size_t t = 0; t < g->triangle_count; t++)
        if (g->may_flip[t] == 1) {
            g->may_flip[t] = 0;
            bool turns = reversed(g, t);
            g->may_flip[t] = 1;
            if (turns)
                return true;
        }
    return false;
}

/* Whether folded triangles may unfold: only where one would, is it measured whether the mesh
 * reads noisy. false when out of memory. */
static bool decide_noisy(guard *g, rsmooth_scalar scalar, const void *positions) {
    g->noisy = false;
    if (!folded_turns(g))
        return true;
    /* internal units for the correlation's rounding floor (scale.c): a power of two */
    int e = 0;
    frexp(rs_typical_edge(scalar, positions, g->indices, g->triangle_count), &e);
    double *xyz = rs_alloc_array(g->vertex_count, 3 * sizeof *xyz);
    double correlation = 1;
    bool ok = xyz != NULL;
    if (ok) {
        for (size_t i = 0; i < 3 * g->vertex_count; i++)
            xyz[i] = ldexp(g->in[i], -e);
        ok = rs_shape_correlation(xyz, g->vertex_count, g->indices, g->triangle_count,
                                  &correlation);
    }
    rs_free(xyz);
    g->noisy = correlation < RS_CLEAN_SHAPE_CORRELATION;
    return ok;
}

long rs_fold_guard(rsmooth_scalar scalar, const void *positions, void *out_positions,
                   size_t vertex_count, const uint32_t *indices, size_t triangle_count) {
    if (triangle_count == 0 || vertex_count == 0)
        return 0;
    guard g = {vertex_count, triangle_count, indices, NULL, NULL, NULL, NULL, false, NULL, NULL};
    g.in = rs_alloc_array(vertex_count, 3 * sizeof(double));
    g.out = rs_alloc_array(vertex_count, 3 * sizeof(double));
    g.reference = rs_alloc_array(triangle_count, 3 * sizeof(double));
    g.may_flip = rs_alloc_array(triangle_count, 1);
    g.halved = rs_alloc_array(vertex_count, 1);
    g.pulled = rs_calloc_array(vertex_count, 1);
    long pulled = -1;
    if (!g.in || !g.out || !g.reference || !g.may_flip || !g.halved || !g.pulled)
        goto done;
    for (size_t i = 0; i < 3 * vertex_count; i++) {
        g.in[i] = rs_coordinate(scalar, positions, i);
        g.out[i] = rs_coordinate(scalar, out_positions, i);
    }
    if (!reference_normals(&g) || !decide_noisy(&g, scalar, positions))
        goto done;
    pulled = 0;
    for (int round = 0;; round++)
        if (pull_back(&g, round >= HALVINGS) == 0)
            break;
    for (size_t v = 0; v < vertex_count; v++)
        if (g.pulled[v]) {
            pulled++;
            rs_store_position(scalar, out_positions, v, g.out + 3 * v, 1);
        }
done:
    rs_free(g.in);
    rs_free(g.out);
    rs_free(g.reference);
    rs_free(g.may_flip);
    rs_free(g.halved);
    rs_free(g.pulled);
    return pulled;
}
