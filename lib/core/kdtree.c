/* A k-d tree over points for the point-cloud filter's spacing: each point's k nearest neighbours.
 * Unlike a uniform grid it needs no cell size, so scans with far outliers or very
 * uneven density cost O(log n) per query all the same. Implicit and balanced: a node is a range of
 * `order` split at its middle, children of node i are 2i + 1 and 2i + 2, and only each node's
 * split axis and value are stored. */
#include "core/spatial.h"

#include <string.h>

/* Points per leaf: below this, scanning beats descending. */
#define LEAF_SIZE 8
/* Levels split on one thread before the subtrees below them are built on every core (16 of
 * them: each is independent, so the tree is the same whatever the thread count). */
#define SERIAL_LEVELS 4
#define SUBTREES (1 << SERIAL_LEVELS)

static double coordinate(const rs_kdtree *tree, uint32_t i, int axis) {
    return tree->xyz[3 * (size_t)i + (size_t)axis];
}

static void swap_u32(uint32_t *a, uint32_t *b) {
    uint32_t t = *a;
    *a = *b;
    *b = t;
}

/* Reorders order[lo, hi) so that order[mid] holds the point that sorted order would put there,
 * the ones before it no larger and the ones after no smaller along `axis`. Three-way partitions,
 * so many equal coordinates (duplicated points, a flat scan) stay linear. */
static void select_middle(const rs_kdtree *tree, uint32_t *order, size_t lo, size_t hi, size_t mid,
                          int axis) {
    while (hi - lo > 1) {
        double a = coordinate(tree, order[lo], axis);
        double b = coordinate(tree, order[lo + (hi - lo) / 2], axis);
        double c = coordinate(tree, order[hi - 1], axis);
        double pivot = a < b ? (b < c ? b : a < c ? c : a) : (a < c ? a : b < c ? c : b);
        size_t lt = lo, i = lo, gt = hi; /* [lo, lt) < pivot, [lt, i) == pivot, [gt, hi) > */
        while (i < gt) {
            double x = coordinate(tree, order[i], axis);
            if (x < pivot)
                swap_u32(&order[lt++], &order[i++]);
            else if (x > pivot)
                swap_u32(&order[i], &order[--gt]);
            else
                i++;
        }
        if (mid < lt)
            hi = lt;
        else if (mid >= gt)
            lo = gt;
        else
            return;
    }
}

/* Splits node `node` over order[lo, hi) along its widest axis (a leaf stays whole): false for
 * a leaf. */
static bool split_node(rs_kdtree *tree, size_t node, size_t lo, size_t hi) {
    if (hi - lo <= LEAF_SIZE)
        return false;
    double min[3], max[3];
    for (int k = 0; k < 3; k++)
        min[k] = max[k] = coordinate(tree, tree->order[lo], k);
    for (size_t i = lo + 1; i < hi; i++)
        for (int k = 0; k < 3; k++) {
            double x = coordinate(tree, tree->order[i], k);
            min[k] = x < min[k] ? x : min[k];
            max[k] = x > max[k] ? x : max[k];
        }
    int axis = 0;
    for (int k = 1; k < 3; k++)
        if (max[k] - min[k] > max[axis] - min[axis])
            axis = k;
    tree->axis[node] = (uint8_t)axis;
    size_t mid = lo + (hi - lo) / 2;
    select_middle(tree, tree->order, lo, hi, mid, axis);
    /* kept: building the right child moves another point to order[mid] */
    tree->split[node] = coordinate(tree, tree->order[mid], axis);
    return true;
}

/* Splits node `node` over order[lo, hi), then its children. */
static void build_node(rs_kdtree *tree, size_t node, size_t lo, size_t hi) {
    if (!split_node(tree, node, lo, hi))
        return;
    size_t mid = lo + (hi - lo) / 2;
    build_node(tree, 2 * node + 1, lo, mid);
    build_node(tree, 2 * node + 2, mid, hi);
}

/* The nodes at depth SERIAL_LEVELS and the ranges they hold (empty below a leaf). */
typedef struct subtrees {
    rs_kdtree *tree;
    size_t lo[SUBTREES], hi[SUBTREES];
} subtrees;

/* The levels above the subtrees, on one thread, recording the subtrees' ranges. */
static void build_top(subtrees *sub, size_t node, size_t depth, size_t lo, size_t hi) {
    if (depth == SERIAL_LEVELS) {
        sub->lo[node - (SUBTREES - 1)] = lo;
        sub->hi[node - (SUBTREES - 1)] = hi;
    } else if (split_node(sub->tree, node, lo, hi)) {
        size_t mid = lo + (hi - lo) / 2;
        build_top(sub, 2 * node + 1, depth + 1, lo, mid);
        build_top(sub, 2 * node + 2, depth + 1, mid, hi);
    }
}

static void build_subtrees(void *ctx, size_t begin, size_t end, size_t chunk) {
    subtrees *sub = ctx;
    (void)chunk;
    for (size_t i = begin; i < end; i++)
        build_node(sub->tree, SUBTREES - 1 + i, sub->lo[i], sub->hi[i]);
}

bool rs_kdtree_build(rs_kdtree *tree, const double *xyz, size_t count) {
    memset(tree, 0, sizeof *tree);
    tree->xyz = xyz;
    tree->count = count;
    /* Ranges halve (rounding up) per level until they fit a leaf: the nodes that takes. */
    size_t levels = 0, size = count;
    while (size > LEAF_SIZE) {
        size = size - size / 2;
        levels++;
    }
    size_t nodes = ((size_t)1 << (levels + 1)) - 1;
    tree->order = rs_alloc_array(count ? count : 1, sizeof *tree->order);
    tree->axis = rs_calloc_array(nodes, sizeof *tree->axis);
    tree->split = rs_calloc_array(nodes, sizeof *tree->split);
    if (!tree->order || !tree->axis || !tree->split) {
        rs_kdtree_free(tree);
        return false;
    }
    for (size_t i = 0; i < count; i++)
        tree->order[i] = (uint32_t)i;
    subtrees sub;
    memset(&sub, 0, sizeof sub);
    sub.tree = tree;
    build_top(&sub, 0, 0, 0, count);
    rs_parallel_for(SUBTREES, 1, build_subtrees, &sub);
    return true;
}

void rs_kdtree_free(rs_kdtree *tree) {
    rs_free(tree->order);
    rs_free(tree->axis);
    rs_free(tree->split);
    memset(tree, 0, sizeof *tree);
}

/* The k best so far, nearest first: dist2[0 .. found), and their points in id when asked for. */
typedef struct knn_state {
    const double *p;
    uint32_t skip;
    size_t k, found;
    double *dist2;
    uint32_t *id; /* NULL: distances only */
} knn_state;

/* Whether (d2, q) comes before entry i: nearer first, then (with ids) the lower id, so points at
 * equal distances are listed the same way whatever order the tree visits them in. */
static bool knn_before(const knn_state *s, double d2, uint32_t q, size_t i) {
    if (d2 != s->dist2[i])
        return d2 < s->dist2[i];
    return s->id && q < s->id[i];
}

static void knn_offer(knn_state *s, double d2, uint32_t q) {
    if (s->found == s->k && !knn_before(s, d2, q, s->k - 1))
        return;
    size_t i = s->found < s->k ? s->found++ : s->k - 1;
    for (; i > 0 && knn_before(s, d2, q, i - 1); i--) { /* insertion: k is small */
        s->dist2[i] = s->dist2[i - 1];
        if (s->id)
            s->id[i] = s->id[i - 1];
    }
    s->dist2[i] = d2;
    if (s->id)
        s->id[i] = q;
}

static void knn_node(const rs_kdtree *tree, knn_state *s, size_t node, size_t lo, size_t hi) {
    if (hi - lo <= LEAF_SIZE) {
        for (size_t i = lo; i < hi; i++) {
            uint32_t q = tree->order[i];
            if (q == s->skip)
                continue;
            double d[3];
            rs_sub3(tree->xyz + 3 * (size_t)q, s->p, d);
            knn_offer(s, rs_dot3(d, d), q);
        }
        return;
    }
    size_t mid = lo + (hi - lo) / 2;
    int axis = tree->axis[node];
    double diff = s->p[axis] - tree->split[node];
    /* the side holding p first; the other only if it can still hold a nearer point */
    bool left_first = diff < 0;
    if (left_first)
        knn_node(tree, s, 2 * node + 1, lo, mid);
    else
        knn_node(tree, s, 2 * node + 2, mid, hi);
    if (s->found < s->k || diff * diff <= s->dist2[s->k - 1]) { /* <=: a tie may win on its id */
        if (left_first)
            knn_node(tree, s, 2 * node + 2, mid, hi);
        else
            knn_node(tree, s, 2 * node + 1, lo, mid);
    }
}

size_t rs_kdtree_nearest(const rs_kdtree *tree, const double p[3], uint32_t skip, size_t k,
                         double *dist2) {
    return rs_kdtree_nearest_ids(tree, p, skip, k, dist2, NULL);
}

size_t rs_kdtree_nearest_ids(const rs_kdtree *tree, const double p[3], uint32_t skip, size_t k,
                             double *dist2, uint32_t *ids) {
    knn_state s = {p, skip, k, 0, dist2, ids};
    if (k > 0 && tree->count > 0)
        knn_node(tree, &s, 0, 0, tree->count);
    return s.found;
}
