/* Guided normal filtering (Zhang, Deng, Zhang, Bouaziz & Liu, "Guided Mesh Normal Filtering",
 * Pacific Graphics 2015).
 *
 * A joint bilateral filter on the facet normals whose range weight compares guidance normals
 * instead of the noisy normals themselves. Facet i's guidance is the mean normal of the most
 * consistent patch that contains it: under heavy noise a crease survives, because the patches on
 * either side of it are each consistent while a patch across it is not. Each round:
 *
 *  1. Patch of facet j: j and the facets sharing a vertex with it (welded: facet_adjacency.c). Its
 *     area-weighted mean normal m_j and its score H_j = Phi_j R_j: Phi_j the largest difference
 *     |n_k - n_l| between two of its facets; R_j = max phi / (eps + sum phi) over the patch's
 *     interior edges (pairs of its facets sharing two vertices), phi = |n_k - n_l| across the edge.
 *     Phi is small on a patch without a crease; R is small where the variation is spread over
 *     many edges (noise) rather than concentrated on a few (a crease).
 *  2. Guidance g_i = m_j of the patch with the smallest H_j among the patches holding i (those of
 *     i and the facets sharing a vertex with it; ties to the lowest index).
 *  3. n_i <- normalise(sum_k a_k exp(-|c_i - c_k|^2 / 2 s^2) exp(-|g_i - g_k|^2 / 2 t^2) n_k) over
 *     the facets whose centroid lies within `radius` times the mean distance between the
 *     centroids of edge-adjacent facets (the paper's geometric neighbourhood, 2 in its runs),
 *     found through the grid: the range of the filter is fixed by the mesh, s only shapes its
 *     weights.
 *
 * The authors' program runs the filter in cycles (fresh facet normals, areas and centroids from
 * the current vertices; one guided step; a few vertex updates), and builds everything that
 * depends only on connectivity, and the neighbour sets, once on the input: so does rs_guided
 * (init once, then one step per cycle, which re-reads the facets' areas and centroids for the
 * weights). Each facet's result depends only on the previous round's arrays, so any thread count
 * gives the same bytes. */
#include "core/spatial.h"
#include "stages/normal_update.h"

#include <math.h>
#include <string.h>

#define PATCH_MAX                                                                                  \
    128                 /* facets of a patch looked at, at most (a vertex of very high valence     \
                         * keeps its first ones in facet order: the score only needs a sample) */
#define TV_EPSILON 1e-9 /* the paper's epsilon in R */
#define GRAIN 512       /* facets per chunk below which a thread does not pay */

/* What does not change between rounds: each facet's patch and the patch's interior edges, and
 * each facet's neighbours within the filter's reach on the input (their spatial exponents follow
 * the geometry each cycle). CSR lists: the entries of facet f are [start[f], start[f + 1]). */
typedef struct guided_lists {
    size_t *patch_start;
    uint32_t *patch; /* the patch's facets, f first */
    size_t *edge_start;
    uint32_t *edge; /* 2 per interior edge: the facets on either side */
    size_t *near_start;
    uint32_t *near;
    double *near_exponent; /* each neighbour's spatial exponent: weight_range */
} guided_lists;

typedef struct guided_job {
    const rs_facets *facets; /* the current geometry: areas and centroids for the weights */
    const rs_adjacency *adj;
    const uint32_t *indices;
    const rs_grid *grid;
    double reach, inv_2s2, inv_2t2;
    guided_lists lists;
    const double *normal; /* this round's input normals, 3 per facet */
    double *patch_mean;   /* 3 per facet */
    double *patch_score;  /* per facet */
    double *guidance;     /* 3 per facet */
    double *out;          /* 3 per facet */
} guided_job;

static double gap2(const double *a, const double *b) {
    double d[3];
    rs_sub3(a, b, d);
    return rs_dot3(d, d);
}

/* The patch of facet f: f first, then the facets at its welded corners, each once. */
static size_t patch_of(const guided_job *job, size_t f, uint32_t member[PATCH_MAX]) {
    size_t m = 0;
    member[m++] = (uint32_t)f;
    const uint32_t *t = job->indices + 3 * (size_t)job->facets->triangle[f];
    for (int c = 0; c < 3; c++) {
        uint32_t r = job->adj->rep[t[c]];
        for (size_t i = job->adj->start[r]; i < job->adj->start[r + 1] && m < PATCH_MAX; i++) {
            uint32_t q = job->adj->facet[i];
            bool seen = false;
            for (size_t k = 0; k < m && !seen; k++)
                seen = member[k] == q;
            if (!seen)
                member[m++] = q;
        }
    }
    return m;
}

/* The welded vertices of facet f's corners. */
static void corners_of(const guided_job *job, uint32_t f, uint32_t out[3]) {
    const uint32_t *t = job->indices + 3 * (size_t)job->facets->triangle[f];
    for (int c = 0; c < 3; c++)
        out[c] = job->adj->rep[t[c]];
}

/* Whether two facets' welded corners hold two in common (an edge). */
static bool share_edge(const uint32_t a[3], const uint32_t b[3]) {
    int shared = 0;
    for (int i = 0; i < 3; i++)
        shared += (a[i] == b[0]) + (a[i] == b[1]) + (a[i] == b[2]);
    return shared >= 2;
}

/* A growing list of one chunk of facets (the lists are built a chunk per thread, then joined in
 * chunk order: the same lists for any thread count). */
typedef struct chunk_list {
    uint32_t *item;
    size_t count, capacity;
    size_t first; /* the chunk's first facet */
    bool failed;  /* out of memory */
} chunk_list;

static void chunk_push(chunk_list *c, uint32_t item) {
    if (c->failed)
        return;
    if (c->count == c->capacity) {
        size_t cap = c->capacity ? 2 * c->capacity : 1024;
        uint32_t *grown = rs_realloc_array(c->item, cap, sizeof *grown);
        if (!grown) {
            c->failed = true;
            return;
        }
        c->item = grown;
        c->capacity = cap;
    }
    c->item[c->count++] = item;
}

/* Per-chunk lists and per-facet counts, joined into one CSR list (start: count + 1 entries;
 * `per` items per counted entry), the chunks' arrays freed. false when out of memory. */
static bool join_chunks(chunk_list *chunks, size_t chunk_count, const size_t *counts, size_t count,
                        size_t per, size_t *start, uint32_t **list) {
    bool ok = true;
    start[0] = 0;
    for (size_t f = 0; f < count; f++)
        start[f + 1] = start[f] + counts[f];
    for (size_t c = 0; c < chunk_count; c++)
        ok = ok && !chunks[c].failed;
    size_t total = per * start[count];
    *list = ok ? rs_alloc_array(total ? total : 1, sizeof **list) : NULL;
    for (size_t c = 0; *list && c < chunk_count; c++)
        if (chunks[c].count)
            memcpy(*list + per * start[chunks[c].first], chunks[c].item,
                   chunks[c].count * sizeof **list);
    for (size_t c = 0; c < chunk_count; c++)
        rs_free(chunks[c].item);
    return *list != NULL;
}

static void lists_free(guided_lists *l) {
    rs_free(l->patch_start);
    rs_free(l->patch);
    rs_free(l->edge_start);
    rs_free(l->edge);
    rs_free(l->near_start);
    rs_free(l->near);
    rs_free(l->near_exponent);
    memset(l, 0, sizeof *l);
}

/* Each facet's patch and the patch's interior edges, a chunk of facets per thread (each facet's
 * entries in the order one facet after another gives them: deterministic). */
typedef struct patch_job {
    guided_job *job;
    chunk_list *patch, *edge;         /* per chunk */
    size_t *patch_count, *edge_count; /* per facet */
} patch_job;

static void patch_lists_range(void *ctx, size_t begin, size_t end, size_t chunk) {
    patch_job *pj = ctx;
    chunk_list *patch = &pj->patch[chunk], *edge = &pj->edge[chunk];
    patch->first = edge->first = begin;
    uint32_t member[PATCH_MAX], corners[PATCH_MAX][3];
    for (size_t f = begin; f < end; f++) {
        size_t m = patch_of(pj->job, f, member), edges = 0;
        for (size_t a = 0; a < m; a++)
            corners_of(pj->job, member[a], corners[a]);
        for (size_t a = 0; a < m; a++) {
            chunk_push(patch, member[a]);
            for (size_t b = a + 1; b < m; b++)
                if (share_edge(corners[a], corners[b])) {
                    chunk_push(edge, member[a]);
                    chunk_push(edge, member[b]);
                    edges++;
                }
        }
        pj->patch_count[f] = m;
        pj->edge_count[f] = edges;
    }
}

static bool patch_lists_build(guided_job *job) {
    guided_lists *l = &job->lists;
    size_t nf = job->facets->count, chunks = rs_parallel_chunks(nf, GRAIN);
    l->patch_start = rs_alloc_array(nf + 1, sizeof(size_t));
    l->edge_start = rs_alloc_array(nf + 1, sizeof(size_t));
    patch_job pj = {job, rs_calloc_array(chunks ? chunks : 1, sizeof(chunk_list)),
                    rs_calloc_array(chunks ? chunks : 1, sizeof(chunk_list)),
                    rs_alloc_array(nf ? nf : 1, sizeof(size_t)),
                    rs_alloc_array(nf ? nf : 1, sizeof(size_t))};
    bool ok =
        l->patch_start && l->edge_start && pj.patch && pj.edge && pj.patch_count && pj.edge_count;
    if (ok) { /* both joined, so both chunks' arrays are freed */
        rs_parallel_for(nf, GRAIN, patch_lists_range, &pj);
        bool patches =
            join_chunks(pj.patch, chunks, pj.patch_count, nf, 1, l->patch_start, &l->patch);
        ok = join_chunks(pj.edge, chunks, pj.edge_count, nf, 2, l->edge_start, &l->edge) && patches;
    }
    rs_free(pj.patch);
    rs_free(pj.edge);
    rs_free(pj.patch_count);
    rs_free(pj.edge_count);
    return ok;
}

/* Facet f's share of the mean distance between the centroids of edge-adjacent facets: its
 * distances to those of higher index (the edges of its patch with f on one side, listed first,
 * f being its patch's first facet), summed in the patch's order; *pairs receives how many. */
static double adjacent_share(const guided_job *job, size_t f, size_t *pairs) {
    const guided_lists *l = &job->lists;
    double share = 0;
    *pairs = 0;
    for (size_t e = l->edge_start[f]; e < l->edge_start[f + 1] && l->edge[2 * e] == f; e++)
        if (l->edge[2 * e + 1] > f) {
            share += sqrt(gap2(job->facets->centroid + 3 * f,
                               job->facets->centroid + 3 * (size_t)l->edge[2 * e + 1]));
            ++*pairs;
        }
    return share;
}

/* The mean over every pair once: the facets' shares summed in facet order, so that pieces of a
 * larger mesh, each giving the shares of its facets, give the same bits (stage_piece.c). */
static double adjacent_distance(const guided_job *job) {
    double sum = 0;
    size_t pairs = 0;
    for (size_t f = 0; f < job->facets->count; f++) {
        size_t n;
        sum += adjacent_share(job, f, &n);
        pairs += n;
    }
    return pairs ? sum / (double)pairs : 0;
}

/* Each facet's neighbours within the filter's reach on the input, through the grid, a chunk of
 * facets per thread (the sets stay for every cycle, as in the authors' program; their weights
 * follow the geometry: weight_range). */
typedef struct near_job {
    guided_job *job;
    chunk_list *near; /* per chunk */
    size_t *count;    /* per facet */
} near_job;

static void near_lists_range(void *ctx, size_t begin, size_t end, size_t chunk) {
    near_job *nj = ctx;
    const guided_job *job = nj->job;
    const rs_grid *grid = job->grid;
    chunk_list *near = &nj->near[chunk];
    near->first = begin;
    for (size_t f = begin; f < end; f++) {
        size_t before = near->count;
        const double *cf = job->facets->centroid + 3 * f;
        int32_t cc[3];
        rs_grid_cell_of(grid, cf, cc);
        for (int dx = -1; dx <= 1; dx++)
            for (int dy = -1; dy <= 1; dy++)
                for (int dz = -1; dz <= 1; dz++) {
                    int32_t cell = rs_grid_find(grid, cc[0] + dx, cc[1] + dy, cc[2] + dz);
                    for (uint32_t s = cell < 0 ? 0 : grid->cell_start[cell];
                         cell >= 0 && s < grid->cell_start[cell + 1]; s++) {
                        uint32_t q = grid->facet_order[s];
                        if (gap2(job->facets->centroid + 3 * (size_t)q, cf) <=
                            job->reach * job->reach)
                            chunk_push(near, q);
                    }
                }
        nj->count[f] = near->count - before;
    }
}

static bool near_lists_build(guided_job *job) {
    guided_lists *l = &job->lists;
    size_t nf = job->facets->count, chunks = rs_parallel_chunks(nf, GRAIN);
    l->near_start = rs_alloc_array(nf + 1, sizeof(size_t));
    near_job nj = {job, rs_calloc_array(chunks ? chunks : 1, sizeof(chunk_list)),
                   rs_alloc_array(nf ? nf : 1, sizeof(size_t))};
    bool ok = l->near_start && nj.near && nj.count;
    if (ok) {
        rs_parallel_for(nf, GRAIN, near_lists_range, &nj);
        ok = join_chunks(nj.near, chunks, nj.count, nf, 1, l->near_start, &l->near);
    }
    rs_free(nj.near);
    rs_free(nj.count);
    if (!ok)
        return false;
    size_t nn = l->near_start[nf];
    l->near_exponent = rs_alloc_array(nn ? nn : 1, sizeof *l->near_exponent);
    return l->near_exponent != NULL;
}

/* The spatial exponents |c_i - c_k|^2 / 2 s^2 of facets [begin, end) from the current centroids
 * (the filter adds the guidance's and takes one exp per pair: exp is most of its time). */
static void weight_range(void *ctx, size_t begin, size_t end, size_t chunk) {
    const guided_job *job = ctx;
    const guided_lists *l = &job->lists;
    (void)chunk;
    for (size_t i = begin; i < end; i++)
        for (size_t k = l->near_start[i]; k < l->near_start[i + 1]; k++) {
            size_t q = l->near[k];
            double d2 = gap2(job->facets->centroid + 3 * q, job->facets->centroid + 3 * i);
            l->near_exponent[k] = d2 * job->inv_2s2;
        }
}

/* Step 1 for facets [begin, end). */
static void patch_range(void *ctx, size_t begin, size_t end, size_t chunk) {
    const guided_job *job = ctx;
    const guided_lists *l = &job->lists;
    (void)chunk;
    for (size_t j = begin; j < end; j++) {
        const uint32_t *member = l->patch + l->patch_start[j];
        size_t m = l->patch_start[j + 1] - l->patch_start[j];
        double mean[3] = {0, 0, 0}, phi2 = 0, edge_max = 0, edge_sum = 0;
        for (size_t a = 0; a < m; a++) {
            const double *na = job->normal + 3 * (size_t)member[a];
            for (int k = 0; k < 3; k++)
                mean[k] += job->facets->area[member[a]] * na[k];
            for (size_t b = a + 1; b < m; b++) { /* (a comparison: fmax is a call here) */
                double g2 = gap2(na, job->normal + 3 * (size_t)member[b]);
                phi2 = g2 > phi2 ? g2 : phi2;
            }
        }
        for (size_t e = l->edge_start[j]; e < l->edge_start[j + 1]; e++) {
            double gap = sqrt(gap2(job->normal + 3 * (size_t)l->edge[2 * e],
                                   job->normal + 3 * (size_t)l->edge[2 * e + 1]));
            edge_max = gap > edge_max ? gap : edge_max;
            edge_sum += gap;
        }
        double len = sqrt(rs_dot3(mean, mean));
        for (int k = 0; k < 3; k++)
            job->patch_mean[3 * j + k] = len > 0 ? mean[k] / len : job->normal[3 * j + k];
        job->patch_score[j] = sqrt(phi2) * edge_max / (TV_EPSILON + edge_sum);
    }
}

/* Step 2 for facets [begin, end). */
static void guidance_range(void *ctx, size_t begin, size_t end, size_t chunk) {
    const guided_job *job = ctx;
    const guided_lists *l = &job->lists;
    (void)chunk;
    for (size_t i = begin; i < end; i++) {
        size_t best = i;
        for (size_t k = l->patch_start[i] + 1; k < l->patch_start[i + 1]; k++) {
            size_t q = l->patch[k];
            double s = job->patch_score[q], b = job->patch_score[best];
            if (s < b || (s == b && q < best))
                best = q;
        }
        memcpy(job->guidance + 3 * i, job->patch_mean + 3 * best, 3 * sizeof(double));
    }
}

/* Step 3 for facets [begin, end). */
static void filter_range(void *ctx, size_t begin, size_t end, size_t chunk) {
    const guided_job *job = ctx;
    const guided_lists *l = &job->lists;
    (void)chunk;
    for (size_t i = begin; i < end; i++) {
        const double *gi = job->guidance + 3 * i;
        double acc[3] = {0, 0, 0};
        for (size_t k = l->near_start[i]; k < l->near_start[i + 1]; k++) {
            size_t q = l->near[k];
            double w = job->facets->area[q] *
                       exp(-(l->near_exponent[k] + gap2(job->guidance + 3 * q, gi) * job->inv_2t2));
            const double *nq = job->normal + 3 * q;
            for (int c = 0; c < 3; c++)
                acc[c] += w * nq[c];
        }
        double len = sqrt(rs_dot3(acc, acc));
        for (int c = 0; c < 3; c++)
            job->out[3 * i + c] = len > 0 ? acc[c] / len : job->normal[3 * i + c];
    }
}

/* The filter's state across cycles: the lists, the grid they were found with, the work arrays. */
struct rs_guided {
    guided_job job;
    rs_grid grid;
    bool filter;  /* false when no two facets share an edge: the normals stay the facets' own */
    double *prev; /* the round's input normals */
};

void rs_guided_destroy(rs_guided *g) {
    if (!g)
        return;
    lists_free(&g->job.lists);
    rs_grid_free(&g->grid);
    rs_free(g->prev);
    rs_free(g->job.patch_mean);
    rs_free(g->job.patch_score);
    rs_free(g->job.guidance);
    rs_free(g);
}

/* The lists and work arrays; the reach `radius` times the facets' own mean adjacent-centroid
 * distance, or (radius < 0) `reach` itself. */
static rs_guided *guided_create(const rs_facets *facets, const rs_adjacency *adj,
                                const uint32_t *indices, double sigma_s, double sigma_n,
                                double radius, double reach) {
    rs_guided *g = rs_calloc_array(1, sizeof *g);
    if (!g)
        return NULL;
    size_t nf = facets->count ? facets->count : 1;
    guided_job *job = &g->job;
    job->facets = facets;
    job->adj = adj;
    job->indices = indices;
    job->inv_2s2 = 1 / (2 * sigma_s * sigma_s);
    job->inv_2t2 = 1 / (2 * sigma_n * sigma_n);
    job->grid = &g->grid;
    g->prev = rs_alloc_array(nf, 3 * sizeof(double));
    job->patch_mean = rs_alloc_array(nf, 3 * sizeof(double));
    job->patch_score = rs_alloc_array(nf, sizeof(double));
    job->guidance = rs_alloc_array(nf, 3 * sizeof(double));
    bool ok =
        g->prev && job->patch_mean && job->patch_score && job->guidance && patch_lists_build(job);
    job->reach = !ok ? 0 : radius < 0 ? reach : radius * adjacent_distance(job);
    g->filter = job->reach > 0;
    if (ok && g->filter)
        ok = rs_grid_build(&g->grid, facets->centroid, facets->count, job->reach, NULL) ==
                 RSMOOTH_OK &&
             near_lists_build(job);
    if (!ok) {
        rs_guided_destroy(g);
        return NULL;
    }
    return g;
}

rs_guided *rs_guided_create(const rs_facets *facets, const rs_adjacency *adj,
                            const uint32_t *indices, double sigma_s, double sigma_n,
                            double radius) {
    return guided_create(facets, adj, indices, sigma_s, sigma_n, radius, 0);
}

rs_guided *rs_guided_create_reach(const rs_facets *facets, const rs_adjacency *adj,
                                  const uint32_t *indices, double sigma_s, double sigma_n,
                                  double reach) {
    return guided_create(facets, adj, indices, sigma_s, sigma_n, -1, reach);
}

double rs_guided_adjacent_share(const rs_guided *g, size_t f, size_t *pairs) {
    return adjacent_share(&g->job, f, pairs);
}

double rs_guided_reach(const rs_guided *g) {
    return g->job.reach;
}

void rs_guided_step(rs_guided *g, const rs_facets *facets, int rounds, double *normals) {
    size_t nf = facets->count;
    guided_job *job = &g->job;
    memcpy(normals, facets->normal, nf * 3 * sizeof(double));
    if (nf == 0 || rounds < 1 || !g->filter)
        return;
    job->facets = facets;
    rs_parallel_for(nf, GRAIN, weight_range, job);
    for (int round = 0; round < rounds; round++) {
        memcpy(g->prev, normals, nf * 3 * sizeof(double));
        job->normal = g->prev;
        job->out = normals;
        rs_parallel_for(nf, GRAIN, patch_range, job);
        rs_parallel_for(nf, GRAIN, guidance_range, job);
        rs_parallel_for(nf, GRAIN, filter_range, job);
    }
}

bool rs_guided_normals(const rs_facets *facets, const rs_adjacency *adj, const uint32_t *indices,
                       double sigma_s, double sigma_n, int rounds, double *normals) {
    rs_guided *g =
        rs_guided_create(facets, adj, indices, sigma_s, sigma_n, RS_GUIDED_RADIUS_DEFAULT);
    if (!g)
        return false;
    rs_guided_step(g, facets, rounds, normals);
    rs_guided_destroy(g);
    return true;
}

void rs_guided_describe(const rs_guided *g, rs_stage_plan *plan) {
    const guided_lists *l = &g->job.lists;
    plan->patch_start = l->patch_start;
    plan->patch = l->patch;
    plan->edge_start = l->edge_start;
    plan->edge = l->edge;
    plan->near_start = l->near_start;
    plan->near = l->near;
    plan->filter = g->filter;
    plan->inv_2s2 = g->job.inv_2s2;
    plan->inv_2t2 = g->job.inv_2t2;
}
