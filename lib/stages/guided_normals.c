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
 *     the facets whose centroid lies within REACH_ADJACENT times the mean distance between the
 *     centroids of edge-adjacent facets (the paper's geometric neighbourhood), found through the
 *     grid: the range of the filter is fixed by the mesh, s only shapes its weights.
 *
 * Centroids and areas are those of the input throughout (the paper filters the normals first and
 * moves the vertices afterwards). Each facet's result depends only on the previous round's arrays,
 * so any thread count gives the same bytes. */
#include "stages/normal_update.h"
#include "core/spatial.h"

#include <math.h>
#include <string.h>

#define REACH_ADJACENT 2.0 /* the filter's neighbourhood, in mean adjacent-centroid distances */
#define PATCH_MAX 128      /* facets of a patch looked at, at most (a vertex of very high valence
                            * keeps its first ones in facet order: the score only needs a sample) */
#define TV_EPSILON 1e-9    /* the paper's epsilon in R */
#define GRAIN 512          /* facets per chunk below which a thread does not pay */

/* What does not change between rounds: each facet's patch and the patch's interior edges, and
 * each facet's neighbours within the filter's reach with their fixed weight a_k exp(-d^2 / 2 s^2).
 * CSR lists: the entries of facet f are [start[f], start[f + 1]). */
typedef struct guided_lists {
    size_t *patch_start;
    uint32_t *patch;        /* the patch's facets, f first */
    size_t *edge_start;
    uint32_t *edge;         /* 2 per interior edge: the facets on either side */
    size_t *near_start;
    uint32_t *near;
    double *near_weight;
} guided_lists;

typedef struct guided_job {
    const rs_facets *facets;
    const rs_adjacency *adj;
    const uint32_t *indices;
    const rs_grid *grid;
    double reach, inv_2s2, inv_2t2;
    guided_lists lists;
    const double *normal;   /* this round's input normals, 3 per facet */
    double *patch_mean;     /* 3 per facet */
    double *patch_score;    /* per facet */
    double *guidance;       /* 3 per facet */
    double *out;            /* 3 per facet */
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

/* Whether facets a and b share two welded vertices (an edge). */
static bool share_edge(const guided_job *job, uint32_t a, uint32_t b) {
    const uint32_t *ta = job->indices + 3 * (size_t)job->facets->triangle[a];
    const uint32_t *tb = job->indices + 3 * (size_t)job->facets->triangle[b];
    int shared = 0;
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++)
            shared += job->adj->rep[ta[i]] == job->adj->rep[tb[k]];
    return shared >= 2;
}

/* Appends to a growing array; false when out of memory. */
static bool push(void **array, size_t *capacity, size_t count, size_t size, const void *item) {
    if (count == *capacity) {
        size_t cap = *capacity ? 2 * *capacity : 1024;
        void *grown = rs_realloc_array(*array, cap, size);
        if (!grown)
            return false;
        *array = grown;
        *capacity = cap;
    }
    memcpy((char *)*array + count * size, item, size);
    return true;
}

static void lists_free(guided_lists *l) {
    rs_free(l->patch_start);
    rs_free(l->patch);
    rs_free(l->edge_start);
    rs_free(l->edge);
    rs_free(l->near_start);
    rs_free(l->near);
    rs_free(l->near_weight);
    memset(l, 0, sizeof *l);
}

/* Each facet's patch and the patch's interior edges, one facet after another (their order fixes
 * the sums' order: deterministic). */
static bool patch_lists_build(guided_job *job) {
    guided_lists *l = &job->lists;
    size_t nf = job->facets->count, np = 0, ne = 0, cp = 0, ce = 0;
    l->patch_start = rs_alloc_array(nf + 1, sizeof(size_t));
    l->edge_start = rs_alloc_array(nf + 1, sizeof(size_t));
    if (!l->patch_start || !l->edge_start)
        return false;
    uint32_t member[PATCH_MAX];
    for (size_t f = 0; f < nf; f++) {
        l->patch_start[f] = np;
        l->edge_start[f] = ne;
        size_t m = patch_of(job, f, member);
        for (size_t a = 0; a < m; a++) {
            if (!push((void **)&l->patch, &cp, np++, sizeof *l->patch, &member[a]))
                return false;
            for (size_t b = a + 1; b < m; b++)
                if (share_edge(job, member[a], member[b])) {
                    if (!push((void **)&l->edge, &ce, 2 * ne, sizeof *l->edge, &member[a]) ||
                        !push((void **)&l->edge, &ce, 2 * ne + 1, sizeof *l->edge, &member[b]))
                        return false;
                    ne++;
                }
        }
    }
    l->patch_start[nf] = np;
    l->edge_start[nf] = ne;
    return true;
}

/* Mean distance between the centroids of edge-adjacent facets, each pair once: the edges of
 * facet f's patch that have f on one side (listed first, f being its patch's first facet). */
static double adjacent_distance(const guided_job *job) {
    const guided_lists *l = &job->lists;
    double sum = 0;
    size_t pairs = 0;
    for (size_t f = 0; f < job->facets->count; f++)
        for (size_t e = l->edge_start[f]; e < l->edge_start[f + 1] && l->edge[2 * e] == f; e++)
            if (l->edge[2 * e + 1] > f) {
                sum += sqrt(gap2(job->facets->centroid + 3 * f,
                                 job->facets->centroid + 3 * (size_t)l->edge[2 * e + 1]));
                pairs++;
            }
    return pairs ? sum / (double)pairs : 0;
}

/* Each facet's neighbours within the filter's reach, with their fixed weights, through the grid. */
static bool near_lists_build(guided_job *job) {
    guided_lists *l = &job->lists;
    size_t nf = job->facets->count, nn = 0, cn = 0, cw = 0;
    l->near_start = rs_alloc_array(nf + 1, sizeof(size_t));
    if (!l->near_start)
        return false;
    const rs_grid *grid = job->grid;
    for (size_t f = 0; f < nf; f++) {
        l->near_start[f] = nn;
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
                        double d2 = gap2(job->facets->centroid + 3 * (size_t)q, cf);
                        if (d2 > job->reach * job->reach)
                            continue;
                        double w = job->facets->area[q] * exp(-d2 * job->inv_2s2);
                        if (!push((void **)&l->near, &cn, nn, sizeof *l->near, &q) ||
                            !push((void **)&l->near_weight, &cw, nn, sizeof *l->near_weight, &w))
                            return false;
                        nn++;
                    }
                }
    }
    l->near_start[nf] = nn;
    return true;
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
            for (size_t b = a + 1; b < m; b++)
                phi2 = fmax(phi2, gap2(na, job->normal + 3 * (size_t)member[b]));
        }
        for (size_t e = l->edge_start[j]; e < l->edge_start[j + 1]; e++) {
            double gap = sqrt(gap2(job->normal + 3 * (size_t)l->edge[2 * e],
                                   job->normal + 3 * (size_t)l->edge[2 * e + 1]));
            edge_max = fmax(edge_max, gap);
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
            double w = l->near_weight[k] * exp(-gap2(job->guidance + 3 * q, gi) * job->inv_2t2);
            const double *nq = job->normal + 3 * q;
            for (int c = 0; c < 3; c++)
                acc[c] += w * nq[c];
        }
        double len = sqrt(rs_dot3(acc, acc));
        for (int c = 0; c < 3; c++)
            job->out[3 * i + c] = len > 0 ? acc[c] / len : job->normal[3 * i + c];
    }
}

bool rs_guided_normals(const rs_facets *facets, const rs_adjacency *adj, const uint32_t *indices,
                       double sigma_s, double sigma_n, int rounds, double *normals) {
    size_t nf = facets->count;
    memcpy(normals, facets->normal, nf * 3 * sizeof(double));
    if (nf == 0 || rounds < 1)
        return true;
    guided_job job;
    memset(&job, 0, sizeof job);
    job.facets = facets;
    job.adj = adj;
    job.indices = indices;
    job.inv_2s2 = 1 / (2 * sigma_s * sigma_s);
    job.inv_2t2 = 1 / (2 * sigma_n * sigma_n);
    rs_grid grid;
    memset(&grid, 0, sizeof grid);
    double *prev = rs_alloc_array(nf, 3 * sizeof(double));
    double *mean = rs_alloc_array(nf, 3 * sizeof(double));
    double *score = rs_alloc_array(nf, sizeof(double));
    double *guide = rs_alloc_array(nf, 3 * sizeof(double));
    job.grid = &grid;
    bool ok = prev && mean && score && guide && patch_lists_build(&job);
    job.reach = ok ? REACH_ADJACENT * adjacent_distance(&job) : 0;
    bool filter = job.reach > 0; /* else no two facets share an edge: the input's normals stay */
    if (ok && filter)
        ok = rs_grid_build(&grid, facets->centroid, nf, job.reach, NULL) == RSMOOTH_OK &&
             near_lists_build(&job);
    job.patch_mean = mean;
    job.patch_score = score;
    job.guidance = guide;
    for (int round = 0; ok && filter && round < rounds; round++) {
        memcpy(prev, normals, nf * 3 * sizeof(double));
        job.normal = prev;
        job.out = normals;
        rs_parallel_for(nf, GRAIN, patch_range, &job);
        rs_parallel_for(nf, GRAIN, guidance_range, &job);
        rs_parallel_for(nf, GRAIN, filter_range, &job);
    }
    lists_free(&job.lists);
    rs_grid_free(&grid);
    rs_free(prev);
    rs_free(mean);
    rs_free(score);
    rs_free(guide);
    return ok;
}
