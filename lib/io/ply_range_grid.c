/* A scanner's range grid read as a triangle mesh. Stanford / Cyberware range scans are PLY files
 * with no faces: "obj_info num_cols C" and "obj_info num_rows R" give the grid, "element
 * range_grid R*C" lists, cell by cell (row-major), 0 or 1 vertex index (the sample seen there).
 * Neighbouring samples form the surface: each 2x2 block of cells gives two triangles when all
 * four samples exist (split along the shorter diagonal) and one when exactly three do, wound the
 * same way in every block (the normals face the scanner), and no triangle bridges a depth jump
 * (DEPTH_JUMP below). Called by the data readers (ply_ascii.c, ply_binary.c) cell by cell and by
 * ply_read.c before and after the data; calls nothing above this file. */
#include "io/ply_reader.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const char where[] = RS_PLY_READ_WHERE;

/* A triangle whose longest edge exceeds DEPTH_JUMP x the scan's median grid-neighbour edge (the
 * distance between samples of horizontally or vertically adjacent cells) bridges a depth jump
 * and is dropped. Chosen from the two Stanford bunny scans (bun000, bun045; docs/file-formats.md
 * has the histogram): their neighbour edges, in medians, fall off steadily from 1 to about 9
 * (surfaces seen at ever more grazing angles: 8 medians is about 83 degrees), are rarest between
 * 9.5 and 11.3 (8 and 13 of about 79500 pairs per scan, against 29 and 46 in 8 to 9.5), and rise
 * again to a second mode at 20 to 50 medians: the jumps between parts of the model at different
 * depths. */
#define DEPTH_JUMP 10.0

rs_ply_element *rs_ply_range_grid_element(const rs_ply_extras *x) {
    for (size_t ei = 0; ei < x->element_count; ei++)
        if (!strcmp(x->elements[ei].name, "range_grid"))
            return &x->elements[ei];
    return NULL;
}

/* The value of "obj_info <key> N": N > 0 whole in *value; 0 when absent; -1 when malformed or
 * repeated (`bad` then holds the line). */
static int grid_size(const rs_ply_extras *x, const char *key, uint64_t *value, const char **bad) {
    size_t key_len = strlen(key);
    int found = 0;
    for (size_t c = 0; c < x->comment_count; c++) {
        const char *t = x->comments[c].text;
        if (strncmp(t, "obj_info", 8) != 0 || !rs_ply_is_space(t[8]))
            continue;
        t += 8;
        while (rs_ply_is_space(*t))
            t++;
        if (strncmp(t, key, key_len) != 0 || !(rs_ply_is_space(t[key_len]) || !t[key_len]))
            continue;
        *bad = x->comments[c].text;
        if (found)
            return -1;
        found = 1;
        t += key_len;
        while (rs_ply_is_space(*t))
            t++;
        uint64_t v = 0;
        const char *digits = t;
        for (; *t >= '0' && *t <= '9'; t++) {
            if (v > (UINT64_MAX - 9) / 10)
                return -1;
            v = 10 * v + (uint64_t)(*t - '0');
        }
        while (rs_ply_is_space(*t))
            t++;
        if (t == digits || *t || v == 0)
            return -1;
        *value = v;
    }
    return found;
}

rsmooth_status rs_ply_range_grid_header(rs_ply_reader *r, rsmooth_error *error) {
    rs_ply_element *g = rs_ply_range_grid_element(r->x);
    if (!g)
        return RSMOOTH_OK;
    int64_t line = g->header_line;
    if (r->face_element) /* which would be the surface? Refused rather than guessed. */
        return rs_fail_parse(error, line, -1, where,
                             "range grid together with a face element: a file is one or the "
                             "other (remove one of them)");
    uint64_t size[2] = {0, 0};
    static const char *const key[2] = {"num_cols", "num_rows"};
    for (int d = 0; d < 2; d++) {
        const char *bad = NULL;
        int found = grid_size(r->x, key[d], &size[d], &bad);
        if (found == 0)
            return rs_fail_parse(error, line, -1, where,
                                 "range grid without an 'obj_info %s' line: its %s is unknown",
                                 key[d], d == 0 ? "width" : "height");
        if (found < 0)
            return rs_fail_parse(error, line, -1, where,
                                 "range grid: '%.60s' is not one 'obj_info %s N' line with N a "
                                 "positive whole number",
                                 bad, key[d]);
    }
    if (size[0] > UINT64_MAX / size[1] || size[0] * size[1] != g->count)
        return rs_fail_parse(error, line, -1, where,
                             "range grid of %llu cells, but num_cols x num_rows is %llu x %llu",
                             (unsigned long long)g->count, (unsigned long long)size[0],
                             (unsigned long long)size[1]);
    rs_ply_property *list = NULL;
    for (size_t k = 0; k < g->property_count; k++)
        if (g->properties[k].count_type != RS_PLY_NONE &&
            (!strcmp(g->properties[k].name, "vertex_indices") ||
             !strcmp(g->properties[k].name, "vertex_index")))
            list = &g->properties[k];
    if (!list || rs_ply_type_is_float(list->type))
        return rs_fail_parse(error, line, -1, where,
                             "range grid without an integer 'vertex_indices' list property");
    list->role = RS_PLY_GRID_LIST;
    r->grid_element = g;
    r->grid_cols = size[0];
    r->grid_rows = size[1];
    return RSMOOTH_OK;
}

/* Cell `item` as "cell I (row R, column C)" for messages. */
#define CELL_FMT "range grid cell %llu (row %llu, column %llu)"
#define CELL_ARGS(r, item)                                                                         \
    (unsigned long long)(item), (unsigned long long)((item) / (r)->grid_cols),                     \
        (unsigned long long)((item) % (r)->grid_cols)

rsmooth_status rs_ply_grid_cell(rs_ply_reader *r, uint64_t n, uint64_t item, int64_t line,
                                int64_t offset, rsmooth_error *error) {
    if (n > 1)
        return rs_fail_parse(error, line, offset, where,
                             CELL_FMT " lists %llu vertex indices (0 or 1: the sample seen there)",
                             CELL_ARGS(r, item), (unsigned long long)n);
    return RSMOOTH_OK;
}

rsmooth_status rs_ply_grid_index(rs_ply_reader *r, double v, uint64_t item, int64_t line,
                                 int64_t offset, rsmooth_error *error) {
    if (!(v >= 0 && v < (double)r->vertex_count && v == floor(v)))
        return rs_fail_parse(error, line, offset, where,
                             CELL_FMT ": vertex index %.17g out of range (%zu vertices)",
                             CELL_ARGS(r, item), v, r->vertex_count);
    size_t i = (size_t)v;
    if (r->grid_owner[i])
        return rs_fail_parse(error, line, offset, where,
                             CELL_FMT ": vertex %zu is already the sample of cell %llu",
                             CELL_ARGS(r, item), i, (unsigned long long)(r->grid_owner[i] - 1));
    r->grid_owner[i] = item + 1;
    r->grid_cells[item] = (uint32_t)i;
    return RSMOOTH_OK;
}

static int compare_doubles(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double distance(const double *p, uint32_t a, uint32_t b) {
    const double *u = p + 3 * (size_t)a, *v = p + 3 * (size_t)b;
    return sqrt((u[0] - v[0]) * (u[0] - v[0]) + (u[1] - v[1]) * (u[1] - v[1]) +
                (u[2] - v[2]) * (u[2] - v[2]));
}

/* The median distance between the samples of horizontally or vertically adjacent cells (0 when
 * no two samples are adjacent); -1 when out of memory. */
static double median_neighbour_edge(const rs_ply_reader *r) {
    const uint64_t cols = r->grid_cols, rows = r->grid_rows;
    const uint32_t *cell = r->grid_cells;
    size_t count = 0;
    double *lengths = rs_alloc_array(2 * r->vertex_count + 1, sizeof *lengths);
    if (!lengths)
        return -1;
    for (uint64_t y = 0; y < rows; y++)
        for (uint64_t x = 0; x < cols; x++) {
            uint32_t a = cell[y * cols + x];
            if (a == UINT32_MAX)
                continue;
            if (x + 1 < cols && cell[y * cols + x + 1] != UINT32_MAX)
                lengths[count++] = distance(r->positions, a, cell[y * cols + x + 1]);
            if (y + 1 < rows && cell[(y + 1) * cols + x] != UINT32_MAX)
                lengths[count++] = distance(r->positions, a, cell[(y + 1) * cols + x]);
        }
    double median = 0;
    if (count > 0) {
        qsort(lengths, count, sizeof *lengths, compare_doubles);
        median =
            count % 2 ? lengths[count / 2] : 0.5 * (lengths[count / 2 - 1] + lengths[count / 2]);
    }
    rs_free(lengths);
    return median;
}

/* Appends triangle (a, b, c) unless an edge is longer than `limit`; false when out of memory. */
static bool add_triangle(rs_ply_reader *r, uint32_t a, uint32_t b, uint32_t c, double limit) {
    const double *p = r->positions;
    if (distance(p, a, b) > limit || distance(p, b, c) > limit || distance(p, c, a) > limit)
        return true;
    if (!rs_io_u32vec_reserve(&r->indices, 3))
        return false;
    uint32_t *t = r->indices.data + r->indices.count;
    t[0] = a;
    t[1] = b;
    t[2] = c;
    r->indices.count += 3;
    return true;
}

/* The triangles of the block of cells (x, y) to (x + 1, y + 1). Its corners in cycle order,
 * (x, y), (x + 1, y), (x + 1, y + 1), (x, y + 1) (x the column, y the row), wind every triangle
 * the same way: towards the scanner in the Stanford scans (the scans study: 99.96% of the
 * triangles of bun000 and bun045 face the way of the reconstruction's nearest triangle; the other
 * cycle gave 0.04%). */
static bool block_triangles(rs_ply_reader *r, uint64_t x, uint64_t y, double limit) {
    const uint64_t cols = r->grid_cols;
    const uint32_t *cell = r->grid_cells;
    uint32_t q[4] = {cell[y * cols + x], cell[y * cols + x + 1], cell[(y + 1) * cols + x + 1],
                     cell[(y + 1) * cols + x]};
    int present = 0, missing = -1;
    for (int k = 0; k < 4; k++) {
        if (q[k] != UINT32_MAX)
            present++;
        else
            missing = k;
    }
    if (present == 3) {
        uint32_t t[3];
        for (int k = 1, n = 0; k <= 3; k++) /* the three others, from the one after the gap */
            t[n++] = q[(missing + k) % 4];
        return add_triangle(r, t[0], t[1], t[2], limit);
    }
    if (present < 4)
        return true;
    if (distance(r->positions, q[0], q[2]) <= distance(r->positions, q[1], q[3]))
        return add_triangle(r, q[0], q[1], q[2], limit) && add_triangle(r, q[0], q[2], q[3], limit);
    return add_triangle(r, q[0], q[1], q[3], limit) && add_triangle(r, q[1], q[2], q[3], limit);
}

/* "obj_info num_cols ...", "obj_info num_rows ..." or "obj_info is_mesh ...". */
static bool describes_grid(const char *t) {
    if (strncmp(t, "obj_info", 8) != 0 || !rs_ply_is_space(t[8]))
        return false;
    for (t += 8; rs_ply_is_space(*t);)
        t++;
    static const char *const keys[3] = {"num_cols", "num_rows", "is_mesh"};
    for (int k = 0; k < 3; k++) {
        size_t n = strlen(keys[k]);
        if (!strncmp(t, keys[k], n) && (!t[n] || rs_ply_is_space(t[n])))
            return true;
    }
    return false;
}

/* The extras as a mesh's: the range_grid element becomes the face element (its own values,
 * cell by cell, are gone: an output of faces has no cells), and the obj_info lines that describe
 * the grid (num_cols, num_rows, is_mesh) are dropped; other obj_info lines (the scanner's
 * calibration) stay, true of the samples still. false when out of memory. */
static bool grid_to_faces(rs_ply_reader *r) {
    rs_ply_extras *x = r->x;
    rs_ply_element *g = r->grid_element;
    rs_ply_property *list = rs_calloc_array(1, sizeof *list);
    char *name = rs_alloc_array(sizeof "vertex_indices", 1), *face = rs_alloc_array(5, 1);
    if (!list || !name || !face) {
        rs_free(list);
        rs_free(name);
        rs_free(face);
        return false;
    }
    memcpy(name, "vertex_indices", sizeof "vertex_indices");
    memcpy(face, "face", 5);
    for (size_t k = 0; k < g->property_count; k++)
        rs_free(g->properties[k].name);
    rs_free(g->properties);
    rs_free(g->rows);
    rs_free(g->list_items);
    rs_free(g->name);
    *list = (rs_ply_property){.name = name,
                              .type = RS_PLY_INT32,
                              .count_type = RS_PLY_UINT8,
                              .spelling = rs_ply_canonical_spelling(RS_PLY_INT32),
                              .count_spelling = rs_ply_canonical_spelling(RS_PLY_UINT8),
                              .role = RS_PLY_FACE_LIST};
    *g = (rs_ply_element){.name = face,
                          .count = r->face_count,
                          .header_line = g->header_line,
                          .properties = list,
                          .property_count = 1,
                          .property_capacity = 1};
    r->face_element = g;
    x->face_element = (size_t)(g - x->elements);
    size_t kept = 0;
    for (size_t c = 0; c < x->comment_count; c++) {
        if (describes_grid(x->comments[c].text))
            rs_free(x->comments[c].text);
        else
            x->comments[kept++] = x->comments[c];
    }
    x->comment_count = kept;
    return true;
}

rsmooth_status rs_ply_range_grid_triangulate(rs_ply_reader *r, rsmooth_error *error) {
    double median = median_neighbour_edge(r);
    if (median < 0)
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "range grid edges");
    const double limit = DEPTH_JUMP * median;
    for (uint64_t y = 0; y + 1 < r->grid_rows; y++)
        for (uint64_t x = 0; x + 1 < r->grid_cols; x++) {
            if (r->indices.count >= RS_IO_MAX_FACE_INDICES - 6)
                return rs_fail_parse(error, r->grid_element->header_line, -1, where,
                                     "range grid: too many triangles (32-bit offsets)");
            if (!block_triangles(r, x, y, limit))
                return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "range grid triangles");
        }
    r->face_count = r->indices.count / 3;
    r->face_offsets = rs_alloc_array(r->face_count + 1, sizeof(uint32_t));
    if (!r->face_offsets)
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "%zu faces", r->face_count);
    for (size_t f = 0; f <= r->face_count; f++)
        r->face_offsets[f] = (uint32_t)(3 * f);
    size_t samples = 0;
    for (uint64_t c = 0; c < r->grid_element->count; c++)
        samples += r->grid_cells[c] != UINT32_MAX;
    r->x->grid_cols = r->grid_cols;
    r->x->grid_rows = r->grid_rows;
    r->x->grid_samples = samples;
    if (!grid_to_faces(r))
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "range grid's face element");
    return RSMOOTH_OK;
}

int rsmooth_mesh_range_grid(const rsmooth_mesh *mesh, size_t *cols, size_t *rows, size_t *samples) {
    const rs_ply_extras *x = mesh && mesh->extras ? mesh->extras->ply : NULL;
    if (!x || x->grid_cols == 0)
        return 0;
    if (cols)
        *cols = (size_t)x->grid_cols;
    if (rows)
        *rows = (size_t)x->grid_rows;
    if (samples)
        *samples = (size_t)x->grid_samples;
    return 1;
}
