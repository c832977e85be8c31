/* The normal update stage on pieces of a larger mesh, a cycle at a time (stages/stage_piece.c),
 * against the whole mesh's stage, the oracle. A noisy capped cylinder (its rims are creases), and
 * the same cut into a triangle soup (every corner welded back by position), are cut into eight
 * pieces (the octants about its centre) each cycle: a piece holds its core's vertices and every
 * triangle whose centroid lies within rs_stage_cycle_halo of the core's box. Cycle after cycle,
 * the cores give the whole mesh's positions after that cycle bit for bit: the best mode's "mid"
 * setting (1 round, 10 updates, radius 3) and one of 2 rounds, 3 updates and radius 2, a move
 * mask holding every seventh vertex too. A halo of two edges leaves some core vertex off: the
 * comparison can fail. The guided filter's reach (its one figure of the whole mesh) from the
 * pieces' shares, summed in triangle order, is the whole mesh's bit for bit. */
#include "mesh_shapes.h"
#include "stages/normal_update.h"
#include "test_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Longest edge of the triangles over xyz. */
static double longest_edge(const double *xyz, const uint32_t *idx, size_t triangles) {
    double longest = 0;
    for (size_t t = 0; t < triangles; t++)
        for (int c = 0; c < 3; c++) {
            const double *a = xyz + 3 * (size_t)idx[3 * t + (size_t)c];
            const double *b = xyz + 3 * (size_t)idx[3 * t + (size_t)(c + 1) % 3];
            double d[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
            longest = fmax(longest, sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]));
        }
    return longest;
}

/* Distance from p to the box [lo, hi]. */
static double box_distance(const double p[3], const double lo[3], const double hi[3]) {
    double s = 0;
    for (int k = 0; k < 3; k++) {
        double d = p[k] < lo[k] ? lo[k] - p[k] : p[k] > hi[k] ? p[k] - hi[k] : 0;
        s += d * d;
    }
    return sqrt(s);
}

typedef struct whole_run {
    const shape_mesh *m;
    const rs_stage_setting *setting;
    const uint8_t *mask;
    rs_stage_whole figures;
} whole_run;

/* The whole mesh's positions after `cycles` cycles from its input (a fresh n-double array). */
static double *after_cycles(const whole_run *w, int cycles) {
    size_t n = 3 * w->m->vertex_count;
    double *xyz = malloc(n * sizeof *xyz);
    CHECK(xyz != NULL);
    memcpy(xyz, w->m->xyz, n * sizeof *xyz);
    rs_stage_setting s = *w->setting;
    s.cycles = cycles;
    CHECK_STATUS(rs_normal_update_stage(xyz, w->m->vertex_count, w->m->indices,
                                        w->m->triangle_count, &s, w->mask, NULL, NULL, NULL, NULL,
                                        NULL, "test"),
                 RSMOOTH_OK);
    return xyz;
}

/* A piece of the mesh: the vertices of one octant about the middle of `now` (the core, first),
 * then those of every triangle whose centroid lies within `halo` of the octant; the triangles in
 * the whole mesh's order. */
typedef struct piece {
    size_t k, core, t_count;
    uint32_t *global; /* per piece vertex: its index in the mesh */
    uint32_t *tri;    /* 3 per triangle, piece indices */
    uint32_t *tri_global;
    double *input, *xyz; /* per piece vertex: its input and `now` positions */
    uint8_t *mask;
} piece;

static void piece_make(piece *p, const shape_mesh *m, const double *now, const uint8_t *mask,
                       int octant, double halo) {
    size_t nv = m->vertex_count, nt = m->triangle_count;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t v = 0; v < nv; v++)
        for (int a = 0; a < 3; a++) {
            lo[a] = fmin(lo[a], now[3 * v + (size_t)a]);
            hi[a] = fmax(hi[a], now[3 * v + (size_t)a]);
        }
    double mid[3], blo[3], bhi[3];
    for (int a = 0; a < 3; a++) {
        mid[a] = (lo[a] + hi[a]) / 2;
        bool upper = (octant >> a) & 1;
        blo[a] = upper ? mid[a] : -INFINITY;
        bhi[a] = upper ? INFINITY : mid[a];
    }
    uint32_t *local = malloc(nv * sizeof *local);
    p->global = malloc(nv * sizeof *p->global);
    p->tri = malloc(nt * 3 * sizeof *p->tri);
    p->tri_global = malloc(nt * sizeof *p->tri_global);
    CHECK(local && p->global && p->tri && p->tri_global);
    size_t k = 0;
    for (size_t v = 0; v < nv; v++) {
        local[v] = UINT32_MAX;
        bool core = true;
        for (int a = 0; a < 3; a++)
            core = core && ((octant >> a) & 1 ? now[3 * v + (size_t)a] >= mid[a]
                                              : now[3 * v + (size_t)a] < mid[a]);
        if (core) {
            local[v] = (uint32_t)k;
            p->global[k++] = (uint32_t)v;
        }
    }
    p->core = k;
    p->t_count = 0;
    for (size_t t = 0; t < nt; t++) {
        double c[3] = {0, 0, 0};
        for (int q = 0; q < 3; q++)
            for (int a = 0; a < 3; a++)
                c[a] += now[3 * (size_t)m->indices[3 * t + (size_t)q] + (size_t)a] / 3;
        if (box_distance(c, blo, bhi) > halo)
            continue;
        for (int q = 0; q < 3; q++) {
            uint32_t v = m->indices[3 * t + (size_t)q];
            if (local[v] == UINT32_MAX) {
                local[v] = (uint32_t)k;
                p->global[k++] = v;
            }
            p->tri[3 * p->t_count + (size_t)q] = local[v];
        }
        p->tri_global[p->t_count++] = (uint32_t)t;
    }
    p->k = k;
    p->input = malloc(k * 3 * sizeof *p->input);
    p->xyz = malloc(k * 3 * sizeof *p->xyz);
    p->mask = malloc(k ? k : 1);
    CHECK(p->input && p->xyz && p->mask);
    for (size_t i = 0; i < k; i++) {
        memcpy(p->input + 3 * i, m->xyz + 3 * (size_t)p->global[i], 3 * sizeof *p->input);
        memcpy(p->xyz + 3 * i, now + 3 * (size_t)p->global[i], 3 * sizeof *p->xyz);
        p->mask[i] = mask ? mask[p->global[i]] : 1;
    }
    free(local);
}

static void piece_free(piece *p) {
    free(p->global);
    free(p->tri);
    free(p->tri_global);
    free(p->input);
    free(p->xyz);
    free(p->mask);
}

/* One cycle from `now` on the octant pieces with this halo, their cores' results into `out` (the
 * octants' cores hold every vertex once). */
static void cycle_in_pieces(const whole_run *w, const double *now, double halo, double *out) {
    for (int octant = 0; octant < 8; octant++) {
        piece p;
        piece_make(&p, w->m, now, w->mask, octant, halo);
        CHECK_STATUS(rs_stage_cycle_piece(p.input, p.xyz, p.k, p.tri, p.t_count, w->setting,
                                          &w->figures, w->mask ? p.mask : NULL),
                     RSMOOTH_OK);
        for (size_t i = 0; i < p.core; i++)
            memcpy(out + 3 * (size_t)p.global[i], p.xyz + 3 * i, 3 * sizeof *out);
        piece_free(&p);
    }
}

/* The reach from the octant pieces' shares with this halo (each triangle's from the piece holding
 * its first corner in its core), summed in triangle order. */
static double pieces_reach(const shape_mesh *m, const rs_stage_setting *setting,
                           const rs_stage_whole *whole, double halo) {
    size_t nt = m->triangle_count;
    double *share = calloc(nt, sizeof *share);
    uint32_t *pairs = calloc(nt, sizeof *pairs);
    CHECK(share && pairs);
    for (int octant = 0; octant < 8; octant++) {
        piece p;
        piece_make(&p, m, m->xyz, NULL, octant, halo);
        double *s = malloc((p.t_count ? p.t_count : 1) * sizeof *s);
        uint32_t *n = malloc((p.t_count ? p.t_count : 1) * sizeof *n);
        CHECK(s && n);
        CHECK_STATUS(
            rs_stage_piece_shares(p.input, p.k, p.tri, p.t_count, setting, whole->scale, s, n),
            RSMOOTH_OK);
        for (size_t t = 0; t < p.t_count; t++)
            if (p.tri[3 * t] < p.core) {
                share[p.tri_global[t]] = s[t];
                pairs[p.tri_global[t]] = n[t];
            }
        free(s);
        free(n);
        piece_free(&p);
    }
    double sum = 0;
    uint64_t total = 0;
    for (size_t t = 0; t < nt; t++) {
        sum += share[t];
        total += pairs[t];
    }
    free(share);
    free(pairs);
    return rs_stage_reach(setting, sum, total, whole->scale);
}

/* The pieces' reach against the whole mesh's: the same bits; with a halo of a third of an edge,
 * facets at the pieces' edges miss neighbours, and it differs. */
static void check_shares(const char *name, const shape_mesh *m, const rs_stage_setting *setting) {
    rs_stage_whole whole;
    CHECK_STATUS(rs_stage_whole_figures(m->xyz, m->vertex_count, m->indices, m->triangle_count,
                                        setting, &whole),
                 RSMOOTH_OK);
    double longest = longest_edge(m->xyz, m->indices, m->triangle_count);
    double halo = rs_stage_shares_halo(longest);
    double reach = pieces_reach(m, setting, &whole, halo);
    double short_reach = pieces_reach(m, setting, &whole, longest / 3);
    printf("%s: reach from the pieces' shares %.17g, the whole mesh's %.17g (halo %.3g); with a "
           "halo of a third of an edge %.17g\n",
           name, reach, whole.reach, halo, short_reach);
    CHECK(reach == whole.reach);
    CHECK(short_reach != whole.reach);
}

/* Vertices whose position differs. */
static size_t differ(const double *a, const double *b, size_t nv) {
    size_t n = 0;
    for (size_t v = 0; v < nv; v++)
        n += memcmp(a + 3 * v, b + 3 * v, 3 * sizeof *a) != 0;
    return n;
}

static void check_cycles(const char *name, const shape_mesh *m, const rs_stage_setting *setting,
                         const uint8_t *mask, int cycles) {
    whole_run w = {m, setting, mask, {0, 0}};
    CHECK_STATUS(rs_stage_whole_figures(m->xyz, m->vertex_count, m->indices, m->triangle_count,
                                        setting, &w.figures),
                 RSMOOTH_OK);
    size_t nv = m->vertex_count;
    double *now = malloc(3 * nv * sizeof *now), *out = malloc(3 * nv * sizeof *out);
    CHECK(now && out);
    memcpy(now, m->xyz, 3 * nv * sizeof *now);
    for (int c = 0; c < cycles; c++) {
        double *expected = after_cycles(&w, c + 1);
        double longest = fmax(longest_edge(m->xyz, m->indices, m->triangle_count),
                              longest_edge(now, m->indices, m->triangle_count));
        double moved = 0;
        for (size_t i = 0; i < 3 * nv; i++)
            moved = fmax(moved, fabs(now[i] - m->xyz[i]));
        moved *= sqrt(3.0);
        double halo = rs_stage_cycle_halo(setting, longest, w.figures.reach, moved);
        cycle_in_pieces(&w, now, halo, out);
        size_t wrong = differ(out, expected, nv);
        printf("%s, cycle %d: halo %.3g (longest edge %.3g, reach %.3g, moved %.3g): %zu of %zu "
               "vertices differ from the whole mesh's cycle\n",
               name, c + 1, halo, longest, w.figures.reach, moved, wrong, nv);
        CHECK(wrong == 0);
        if (c == 0) { /* too small a halo: the comparison can fail */
            double *short_out = malloc(3 * nv * sizeof *short_out);
            CHECK(short_out != NULL);
            cycle_in_pieces(&w, now, 2 * longest, short_out);
            size_t off = differ(short_out, expected, nv);
            printf("%s, a halo of two edges: %zu vertices differ\n", name, off);
            CHECK(off > 0);
            free(short_out);
        }
        memcpy(now, expected, 3 * nv * sizeof *now);
        free(expected);
    }
    free(now);
    free(out);
}

int main(void) {
    /* a roof: a grid folded along a crease, wide enough that a piece with its halo holds about
     * half of it */
    shape_mesh roof, soup;
    CHECK(shape_plane(&roof, 160, 160, 1.0) == 0);
    double middle = 0;
    for (size_t v = 0; v < roof.vertex_count; v++)
        middle = fmax(middle, roof.xyz[3 * v] / 2);
    for (size_t v = 0; v < roof.vertex_count; v++)
        roof.xyz[3 * v + 2] = 0.4 * fabs(roof.xyz[3 * v] - middle);
    double edge = shape_mean_edge_length(&roof);
    CHECK(shape_add_normal_noise(&roof, 0.35 * edge, 21) == 0);
    CHECK(shape_unindex(&roof, &soup) == 0);
    rs_stage_setting mid = {
        .sigma_s = edge, .sigma_n = 0.2, .radius = 3, .rounds = 1, .updates = 10, .cycles = 1};
    rs_stage_setting other = {
        .sigma_s = 0.7 * edge, .sigma_n = 0.3, .radius = 2, .rounds = 2, .updates = 3, .cycles = 1};
    check_shares("mesh", &roof, &mid);
    check_shares("soup", &soup, &mid);
    check_cycles("mid setting", &roof, &mid, NULL, 2);
    check_cycles("2 rounds, 3 updates", &roof, &other, NULL, 2);
    check_cycles("soup, mid setting", &soup, &mid, NULL, 1);
    uint8_t *mask = malloc(roof.vertex_count);
    CHECK(mask != NULL);
    for (size_t v = 0; v < roof.vertex_count; v++)
        mask[v] = v % 7 != 0;
    check_cycles("mid setting, every 7th vertex held", &roof, &mid, mask, 2);
    free(mask);
    shape_free(&roof);
    shape_free(&soup);
    printf("ok\n");
    return 0;
}
