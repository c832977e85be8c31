/* Parts of a mesh by scale, and the vertices left out as outliers (parts.c). Internal. */
#ifndef RSMOOTH_PARTS_H
#define RSMOOTH_PARTS_H

#include "core/rsmooth_internal.h"

/* A triangle's scale is the median of its three edge lengths, so one stray corner (two long
 * edges) makes it large, and one short edge of a sliver does not make it small. Triangles whose
 * scales lie within a factor of about 8 of each other, through a chain of scales with no wider
 * gap, form one part; a part's vertices are moved by its own triangles only, with widths in its
 * own unit. RS_PART_GAP_OCTAVES is that gap; bins are quarter octaves. */
#define RS_PART_BINS_PER_OCTAVE 4
#define RS_PART_GAP_OCTAVES 3
/* Edges longer than this many times a part's median triangle scale are left out of its unit (a
 * few long edges cannot move it); no edge of the 28 clean and 12 benchmark meshes here is beyond
 * 19 times. */
#define RS_EDGE_OUT_OF_LINE 32.0
#define RS_NO_PART UINT32_MAX

typedef struct rs_parts {
    size_t count; /* parts (each with at least one triangle) */
    bool whole;   /* one part holds every triangle of non-zero scale and no edge is out
                   * of line: the mesh is smoothed as it is, its unit its mean edge */
    /* The rest is set only when !whole (NULL otherwise). */
    uint32_t *triangle_part; /* per triangle: its part (RS_NO_PART: its corners coincide) */
    uint32_t *vertex_part; /* per vertex: the part that moves it; RS_NO_PART: no triangle uses it */
    uint8_t *outlier;      /* per vertex: 1 when every triangle it belongs to reaches a vertex of
                            * another part (a stray vertex far off the surface): held still */
    size_t outliers;       /* how many */
    double *edge_limit;    /* per part: longer edges are left out of its unit (caller's units) */
    size_t *vertices;      /* per part: the vertices it moves (outliers not counted) */
} rs_parts;

/* Finds the parts of a checked mesh (positions finite). Deterministic for any thread count.
 * RSMOOTH_ERROR_OUT_OF_MEMORY names `where`; free with rs_parts_free either way. */
rsmooth_status rs_parts_find(rs_parts *parts, rsmooth_scalar scalar, const void *positions,
                             size_t vertex_count, const uint32_t *indices, size_t triangle_count,
                             rsmooth_error *error, const char *where);
void rs_parts_free(rs_parts *parts);

/* Part `part` as a mesh of its own: its triangles, the vertices they use (in the caller's scalar
 * type and order), and which of them it moves (vertex_part == part, not an outlier, and the
 * caller's mask, which may be NULL). */
typedef struct rs_submesh {
    size_t vertex_count, triangle_count;
    void *positions;   /* 3 * vertex_count scalars */
    uint32_t *indices; /* 3 * triangle_count, into positions */
    uint32_t *vertex;  /* per sub-vertex: the whole mesh's vertex */
    uint8_t *move;     /* per sub-vertex: 1 when this part moves it */
    size_t moving;     /* how many move */
} rs_submesh;

/* false when out of memory (then nothing needs freeing). */
bool rs_submesh_make(rs_submesh *sub, const rs_parts *parts, uint32_t part, rsmooth_scalar scalar,
                     const void *positions, size_t vertex_count, const uint32_t *indices,
                     size_t triangle_count, const uint8_t *move_mask);
void rs_submesh_free(rs_submesh *sub);

/* The part that moves the most vertices (the lowest numbered of equals), or 0 when whole. */
uint32_t rs_parts_largest(const rs_parts *parts);

/* The same rule for any items with a scale (a point cloud's spacings): the quarter-octave bin of a
 * scale (RS_NO_BIN for 0 or not finite), and the parts of `count` binned items: part[i] per item
 * (RS_NO_PART for RS_NO_BIN) and *limit (allocated, rs_free it) the out-of-line limit of each.
 * Returns the number of parts, SIZE_MAX when out of memory. */
#define RS_NO_BIN INT16_MIN
int16_t rs_scale_bin(double scale);
size_t rs_scale_parts(const int16_t *bin, size_t count, uint32_t *part, double **limit);

/* For meshes read piece by piece (stream/): a triangle's scale (its median edge) and longest
 * edge, and the whole-mesh test of rs_parts_find from the histogram of the scales' bins (bin b
 * counted at histogram[b - RS_PART_BIN_MIN], RS_PART_BIN_COUNT of them) and the longest edge of
 * all: true when the mesh is one part with no edge out of line. (false also when out of
 * memory.) */
#define RS_PART_BIN_MIN (-4400) /* below log2 of the smallest double, in quarter octaves */
#define RS_PART_BIN_COUNT 6800  /* to above log2(4e150)'s */
double rs_triangle_scale(rsmooth_scalar scalar, const void *positions, const uint32_t tri[3],
                         double *longest);
bool rs_scales_whole(const size_t *histogram, double longest);

/* The parts of a histogram as ranges of bins: part_of_bin[b - RS_PART_BIN_MIN] for every occupied
 * bin, and the first `limit_capacity` parts' edge limits into `limit` (may be NULL when 0).
 * Returns the number of parts. (part_scales.c, with the three above and rs_scale_parts.) */
size_t rs_cut_parts(const size_t *histogram, uint32_t *part_of_bin, double *limit,
                    size_t limit_capacity);

#endif /* RSMOOTH_PARTS_H */
