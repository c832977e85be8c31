/* PLY range grids (lib/io/ply_range_grid.c) read through rsmooth_io.h: a generated scan of a
 * sheared plane with a step of depth half-way and missing cells, in ascii and binary little- and
 * big-endian, against a brute-force count of its blocks; the malformed variants' errors; the
 * Stanford bunny scan when ../shared holds it.
 *
 * `test_ply_range_grid write DIR` writes the files test_range_grid_command.sh gives the command:
 * grid.ply (ascii), grid_le.ply, grid_be.ply, bad_*.ply with bad_*.txt (the message expected) and
 * expected.txt (the triangle count, cols, rows, samples). */
#define _GNU_SOURCE /* open_memstream, mkstemp (test_io_util.h) */
#include "test_io_util.h"

#include <sys/stat.h>

#define COLS 20
#define ROWS 15
#define STEP_COL 10 /* columns from here on lie `step` deeper */

/* Cell (c, r) holds no sample: a scattered pattern, and one cell beside the step. */
static bool missing(int c, int r) {
    return (r * 7 + c * 3) % 11 == 0 || (c == 4 && r == 9) || (c == STEP_COL && r == 2);
}

/* The sample of cell (c, r): a plane sheared along x (so one diagonal of each block is shorter:
 * (c + 1, r) - (c, r + 1)), with a ripple and the step. */
static void sample(int c, int r, double step, double p[3]) {
    p[0] = c + 0.3 * r;
    p[1] = r;
    p[2] = (c >= STEP_COL ? step : 0.0) + 0.01 * sin(c + 2.0 * r);
}

typedef enum variant {
    GOOD,
    TWO_INDICES,  /* a cell lists 2 indices */
    OUT_OF_RANGE, /* a cell's index >= the vertex count */
    TWICE,        /* two cells list the same vertex */
    WRONG_COUNT,  /* num_rows one too few */
    NO_COLS,      /* no num_cols line */
    TEXT_ROWS,    /* num_rows not a number */
    WITH_FACES,   /* a face element as well */
    TWO_GRIDS,    /* a second range_grid element, the same cells again */
    VARIANT_COUNT
} variant;

static const char *const expected_message[VARIANT_COUNT] = {
    "",
    "range grid cell 21 (row 1, column 1) lists 2 vertex indices",
    "range grid cell 21 (row 1, column 1): vertex index 100000 out of range",
    "is already the sample of cell",
    "range grid of 300 cells, but num_cols x num_rows is 20 x 14",
    "range grid without an 'obj_info num_cols' line",
    "'obj_info num_rows 1five' is not one 'obj_info num_rows N' line",
    "range grid together with a face element",
    "a second 'range_grid' element"};

static const char *const variant_name[VARIANT_COUNT] = {"good",      "two_indices", "out_of_range",
                                                        "twice",     "wrong_count", "no_cols",
                                                        "text_rows", "with_faces",  "two_grids"};

/* Vertex ids: the samples in reverse cell order (the vertex order need not follow the grid). */
static int sample_count(void) {
    int n = 0;
    for (int r = 0; r < ROWS; r++)
        for (int c = 0; c < COLS; c++)
            n += !missing(c, r);
    return n;
}

static int vertex_of(int c, int r) {
    if (missing(c, r))
        return -1;
    int before = 0; /* samples in cells before (c, r) */
    for (int k = 0; k < r * COLS + c; k++)
        before += !missing(k % COLS, k / COLS);
    return sample_count() - 1 - before;
}

/* The file, in `format` (PLY_ASCII, PLY_BINARY: little-endian, PLY_BINARY_BE). */
static bytes grid_file(rsmooth_format format, variant v, double step) {
    bytes b = {0};
    b.big_endian = format == RSMOOTH_FORMAT_PLY_BINARY_BE;
    const bool ascii = format == RSMOOTH_FORMAT_PLY_ASCII;
    const int n = sample_count();
    char line[256];
    put_text(&b, "ply\n");
    put_text(&b, ascii          ? "format ascii 1.0\n"
                 : b.big_endian ? "format binary_big_endian 1.0\n"
                                : "format binary_little_endian 1.0\n");
    put_text(&b, "obj_info is_cyberware_data 1\nobj_info is_mesh 0\n");
    if (v != NO_COLS)
        put_text(&b, "obj_info num_cols 20\n");
    put_text(&b, v == TEXT_ROWS     ? "obj_info num_rows 1five\n"
                 : v == WRONG_COUNT ? "obj_info num_rows 14\n"
                                    : "obj_info num_rows 15\n");
    put_text(&b, "obj_info echo_lgincr 0.000500\n");
    snprintf(line, sizeof line,
             "element vertex %d\nproperty float x\nproperty float y\n"
             "property float z\n",
             n);
    put_text(&b, line);
    snprintf(line, sizeof line, "element range_grid %d\nproperty list uchar int vertex_indices\n",
             COLS * ROWS);
    for (int g = 0; g < (v == TWO_GRIDS ? 2 : 1); g++)
        put_text(&b, line);
    if (v == WITH_FACES)
        put_text(&b, "element face 1\nproperty list uchar int vertex_indices\n");
    put_text(&b, "end_header\n");
    for (int id = 0; id < n; id++) /* vertex `id` is the sample of the cell found by search */
        for (int k = 0; k < COLS * ROWS; k++)
            if (vertex_of(k % COLS, k / COLS) == id) {
                double p[3];
                sample(k % COLS, k / COLS, step, p);
                if (ascii) {
                    snprintf(line, sizeof line, "%.9g %.9g %.9g\n", (double)(float)p[0],
                             (double)(float)p[1], (double)(float)p[2]);
                    put_text(&b, line);
                } else
                    for (int a = 0; a < 3; a++)
                        put_f32(&b, (float)p[a]);
            }
    for (int k = 0; k < (v == TWO_GRIDS ? 2 : 1) * COLS * ROWS; k++) {
        int cell = k % (COLS * ROWS); /* a second grid: the same cells again */
        int id = vertex_of(cell % COLS, cell / COLS), extra = -1;
        if (k == 21 && v == TWO_INDICES)
            extra = 0;
        if (k == 21 && v == OUT_OF_RANGE)
            id = 100000;
        if (k == 22 && v == TWICE)
            id = vertex_of(1, 1);
        int count = id < 0 ? 0 : extra < 0 ? 1 : 2;
        if (ascii) {
            snprintf(line, sizeof line,
                     count == 0   ? "0\n"
                     : count == 1 ? "1 %d\n"
                                  : "2 %d %d\n",
                     id, extra);
            put_text(&b, line);
        } else {
            put_u8(&b, (unsigned)count);
            if (count >= 1)
                put_i32(&b, id);
            if (count == 2)
                put_i32(&b, extra);
        }
    }
    if (v == WITH_FACES) {
        if (ascii)
            put_text(&b, "3 0 1 2\n");
        else {
            put_u8(&b, 3);
            for (int i = 0; i < 3; i++)
                put_i32(&b, i);
        }
    }
    return b;
}

/* The brute-force count: a block of four samples gives 2 triangles, of three 1; none in a block
 * across the step when it is a depth jump (every triangle there has a corner on either side). */
static size_t expected_triangles(bool step_is_jump) {
    size_t n = 0;
    for (int r = 0; r + 1 < ROWS; r++)
        for (int c = 0; c + 1 < COLS; c++) {
            int present =
                !missing(c, r) + !missing(c + 1, r) + !missing(c, r + 1) + !missing(c + 1, r + 1);
            if (step_is_jump && c + 1 == STEP_COL)
                continue;
            n += present == 4 ? 2 : present == 3 ? 1 : 0;
        }
    return n;
}

static rsmooth_mesh *read_good(rsmooth_format format, double step) {
    bytes b = grid_file(format, GOOD, step);
    rsmooth_mesh *m = NULL;
    rsmooth_error err;
    rsmooth_status s = rsmooth_mesh_read_memory(b.data, b.size, RSMOOTH_FORMAT_AUTO, &m, &err);
    if (s != RSMOOTH_OK)
        fprintf(stderr, "range grid: %s (line %lld)\n", err.message, (long long)err.line);
    CHECK_EQ_INT(s, RSMOOTH_OK);
    bytes_free(&b);
    return m;
}

static int compare_u64(const void *a, const void *b) {
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* Consistently oriented: no directed edge in two triangles (two triangles sharing an edge run it
 * in opposite directions). */
static void check_orientation(const rsmooth_mesh *m) {
    size_t n = 3 * m->triangle_count;
    uint64_t *edges = malloc((n + 1) * sizeof *edges);
    CHECK(edges != NULL);
    for (size_t t = 0; t < m->triangle_count; t++)
        for (size_t e = 0; e < 3; e++)
            edges[3 * t + e] =
                (uint64_t)m->triangles[3 * t + e] << 32 | m->triangles[3 * t + (e + 1) % 3];
    qsort(edges, n, sizeof *edges, compare_u64);
    size_t shared_same_way = 0;
    for (size_t i = 1; i < n; i++)
        shared_same_way += edges[i] == edges[i - 1];
    CHECK_EQ_INT(shared_same_way, 0);
    free(edges);
}

static void check_good(rsmooth_format format) {
    for (int jump = 1; jump >= 0; jump--) {
        const double step = jump ? 40.0 : 5.0; /* 40 > 10 x the spacing of about 1; 5 below */
        rsmooth_mesh *m = read_good(format, step);
        size_t cols = 0, rows = 0, samples = 0;
        CHECK_EQ_INT(rsmooth_mesh_range_grid(m, &cols, &rows, &samples), 1);
        CHECK_EQ_INT(cols, COLS);
        CHECK_EQ_INT(rows, ROWS);
        CHECK_EQ_INT(samples, sample_count());
        CHECK_EQ_INT(m->vertex_count, sample_count());
        CHECK_EQ_INT(m->triangle_count, expected_triangles(jump));
        double normal_z = 0;
        for (size_t t = 0; t < m->triangle_count; t++) {
            const uint32_t *v = m->triangles + 3 * t;
            const double *p[3] = {m->positions + 3 * v[0], m->positions + 3 * v[1],
                                  m->positions + 3 * v[2]};
            bool deep[3];
            for (int k = 0; k < 3; k++)
                deep[k] = p[k][2] > step / 2;
            if (jump) /* no triangle spans the step */
                CHECK(deep[0] == deep[1] && deep[1] == deep[2]);
            /* in a block of four samples never the longer diagonal (its corners' x differ by
             * 1.3, y by 1) */
            int r0 = (int)lround(fmin(p[0][1], fmin(p[1][1], p[2][1])));
            int c0 = (int)lround(fmin(p[0][0] - 0.3 * p[0][1],
                                      fmin(p[1][0] - 0.3 * p[1][1], p[2][0] - 0.3 * p[2][1])));
            bool full = !missing(c0, r0) && !missing(c0 + 1, r0) && !missing(c0, r0 + 1) &&
                        !missing(c0 + 1, r0 + 1);
            for (int k = 0; full && k < 3; k++) {
                const double *a = p[k], *b = p[(k + 1) % 3];
                CHECK(
                    !(fabs(fabs(a[0] - b[0]) - 1.3) < 1e-4 && fabs(fabs(a[1] - b[1]) - 1) < 1e-4));
            }
            double ux = p[1][0] - p[0][0], uy = p[1][1] - p[0][1];
            double vx = p[2][0] - p[0][0], vy = p[2][1] - p[0][1];
            double z = ux * vy - uy * vx; /* the normal's z: one sign for all */
            CHECK(z != 0);
            if (t == 0)
                normal_z = z;
            CHECK(z * normal_z > 0);
        }
        check_orientation(m);
        rsmooth_mesh_destroy(m);
    }
}

/* ascii and both binary byte orders: the same positions and triangles. */
static void check_encodings_agree(void) {
    rsmooth_mesh *a = read_good(RSMOOTH_FORMAT_PLY_ASCII, 40);
    const rsmooth_format binary[2] = {RSMOOTH_FORMAT_PLY_BINARY, RSMOOTH_FORMAT_PLY_BINARY_BE};
    for (int k = 0; k < 2; k++) {
        rsmooth_mesh *b = read_good(binary[k], 40);
        CHECK_EQ_INT(a->vertex_count, b->vertex_count);
        CHECK_EQ_INT(a->triangle_count, b->triangle_count);
        CHECK(!memcmp(a->positions, b->positions, 3 * a->vertex_count * sizeof(double)));
        CHECK(!memcmp(a->triangles, b->triangles, 3 * a->triangle_count * sizeof(uint32_t)));
        rsmooth_mesh_destroy(b);
    }
    rsmooth_mesh_destroy(a);
}

/* Written back: a mesh PLY (vertex and face elements), without the grid's obj_info lines. */
static void check_written_back(void) {
    rsmooth_mesh *m = read_good(RSMOOTH_FORMAT_PLY_BINARY_BE, 40);
    size_t size;
    char *text = mesh_to_memory(m, RSMOOTH_FORMAT_PLY_ASCII, &size);
    char header[1024];
    size_t at = 0; /* the header, up to "end_header" */
    while (at + 10 <= size && memcmp(text + at, "end_header", 10) != 0)
        at++;
    CHECK(at + 10 <= size && at < sizeof header);
    memcpy(header, text, at);
    header[at] = '\0';
    char face[96];
    snprintf(face, sizeof face, "element face %zu\nproperty list uchar int vertex_indices\n",
             expected_triangles(true));
    CHECK(strstr(header, face) != NULL);
    CHECK(strstr(header, "range_grid") == NULL);
    CHECK(strstr(header, "num_cols") == NULL && strstr(header, "num_rows") == NULL);
    CHECK(strstr(header, "is_mesh") == NULL);
    CHECK(strstr(header, "obj_info is_cyberware_data 1\n") != NULL);
    CHECK(strstr(header, "obj_info echo_lgincr 0.000500\n") != NULL);
    rsmooth_mesh *back = NULL;
    rsmooth_error err;
    CHECK_STATUS(rsmooth_mesh_read_memory(text, size, RSMOOTH_FORMAT_AUTO, &back, &err),
                 RSMOOTH_OK);
    CHECK_EQ_INT(rsmooth_mesh_range_grid(back, NULL, NULL, NULL), 0); /* a mesh now */
    CHECK_EQ_INT(back->triangle_count, m->triangle_count);
    CHECK(!memcmp(back->triangles, m->triangles, 3 * m->triangle_count * sizeof(uint32_t)));
    rsmooth_mesh_destroy(back);
    free(text);
    rsmooth_mesh_destroy(m);
}

/* `b` without the header line `line` (which it holds once). */
static void drop_line(bytes *b, const char *line) {
    size_t n = strlen(line), at = 0;
    while (at + n <= b->size && memcmp(b->data + at, line, n) != 0)
        at++;
    CHECK(at + n <= b->size);
    memmove(b->data + at, b->data + at + n, b->size - at - n);
    b->size -= n;
}

/* Written, read back and written again: the same bytes, each encoding written in ascii and
 * binary, from a grid with the scanner's obj_info lines and from one whose obj_info lines all
 * describe the grid (num_cols, num_rows, is_mesh: all dropped on reading, which leaves a header
 * with nothing of the input's own). */
static void check_rewrite_stable(void) {
    const rsmooth_format formats[3] = {RSMOOTH_FORMAT_PLY_ASCII, RSMOOTH_FORMAT_PLY_BINARY,
                                       RSMOOTH_FORMAT_PLY_BINARY_BE};
    const rsmooth_format out[2] = {RSMOOTH_FORMAT_PLY_ASCII, RSMOOTH_FORMAT_PLY_BINARY};
    for (int only_grid = 0; only_grid < 2; only_grid++)
        for (int f = 0; f < 3; f++)
            for (int o = 0; o < 2; o++) {
                bytes b = grid_file(formats[f], GOOD, 40);
                if (only_grid) {
                    drop_line(&b, "obj_info is_cyberware_data 1\n");
                    drop_line(&b, "obj_info echo_lgincr 0.000500\n");
                }
                rsmooth_mesh *m = NULL, *back = NULL;
                rsmooth_error err;
                CHECK_STATUS(
                    rsmooth_mesh_read_memory(b.data, b.size, RSMOOTH_FORMAT_AUTO, &m, &err),
                    RSMOOTH_OK);
                size_t size1, size2;
                char *first = mesh_to_memory(m, out[o], &size1);
                CHECK_STATUS(
                    rsmooth_mesh_read_memory(first, size1, RSMOOTH_FORMAT_AUTO, &back, &err),
                    RSMOOTH_OK);
                char *second = mesh_to_memory(back, out[o], &size2);
                if (size1 != size2 || memcmp(first, second, size1) != 0) {
                    fprintf(stderr, "%s grid, encoding %d written as %d: %zu bytes, then %zu\n",
                            only_grid ? "obj_info-only" : "scanner's", (int)formats[f], (int)out[o],
                            size1, size2);
                    CHECK(0);
                }
                free(first);
                free(second);
                rsmooth_mesh_destroy(back);
                rsmooth_mesh_destroy(m);
                bytes_free(&b);
            }
}

/* The header lines of grid_file's output, so that an ascii cell's line can be told. */
static int header_lines(variant v) {
    return 14 - (v == NO_COLS) + 2 * (v == WITH_FACES || v == TWO_GRIDS);
}

static void check_malformed(void) {
    const rsmooth_format formats[3] = {RSMOOTH_FORMAT_PLY_ASCII, RSMOOTH_FORMAT_PLY_BINARY,
                                       RSMOOTH_FORMAT_PLY_BINARY_BE};
    for (int v = TWO_INDICES; v < VARIANT_COUNT; v++)
        for (int f = 0; f < 3; f++) {
            bytes b = grid_file(formats[f], (variant)v, 40);
            rsmooth_mesh *m = NULL;
            rsmooth_error err;
            CHECK_STATUS(rsmooth_mesh_read_memory(b.data, b.size, RSMOOTH_FORMAT_AUTO, &m, &err),
                         RSMOOTH_ERROR_PARSE);
            CHECK(m == NULL);
            if (!strstr(err.message, expected_message[v])) {
                fprintf(stderr, "%s: '%s' lacks '%s'\n", variant_name[v], err.message,
                        expected_message[v]);
                CHECK(0);
            }
            /* cell 21's line in ascii: after the header and the vertices */
            if (formats[f] == RSMOOTH_FORMAT_PLY_ASCII && (v == TWO_INDICES || v == OUT_OF_RANGE))
                CHECK_EQ_INT(err.line, header_lines((variant)v) + sample_count() + 21 + 1);
            if (formats[f] != RSMOOTH_FORMAT_PLY_ASCII && (v == TWO_INDICES || v == OUT_OF_RANGE))
                CHECK(err.byte_offset > 0);
            if (v == TWO_GRIDS) /* the second 'element range_grid' line: 2 before end_header */
                CHECK_EQ_INT(err.line, header_lines(TWO_GRIDS) - 2);
            bytes_free(&b);
        }
}

/* The Stanford bunny's bun000 (a Cyberware scan) when ../shared holds it: its samples all read,
 * and no triangle longer than the rule allows (10 x the median grid-neighbour edge, which the
 * triangles' shorter edges bound from above: the median of all their edges is at least it). */
static int check_bunny_scan(void) {
    char path[1024];
    snprintf(path, sizeof path, "%s/data/scans/stanford-bunny/bun000.ply", RSMOOTH_SHARED_DIR);
    struct stat st;
    if (RSMOOTH_SHARED_DIR[0] == '\0' || stat(path, &st) != 0) {
        printf("ply_range_grid: no %s: the bunny scan check skipped\n", path);
        return 0;
    }
    rsmooth_mesh *m = NULL;
    rsmooth_error err;
    CHECK_STATUS(rsmooth_mesh_read_file(path, &m, &err), RSMOOTH_OK);
    size_t cols, rows, samples;
    CHECK_EQ_INT(rsmooth_mesh_range_grid(m, &cols, &rows, &samples), 1);
    CHECK_EQ_INT(cols, 512);
    CHECK_EQ_INT(rows, 400);
    CHECK_EQ_INT(samples, 40256);
    CHECK_EQ_INT(m->vertex_count, 40256);
    /* at most two per block of the grid holding samples; about two per sample */
    CHECK(m->triangle_count > 78000 && m->triangle_count < 2 * samples);
    double longest = 0, shortest_sum = 0;
    for (size_t t = 0; t < m->triangle_count; t++) {
        double e[3];
        for (int k = 0; k < 3; k++) {
            const double *a = m->positions + 3 * m->triangles[3 * t + (size_t)k];
            const double *b = m->positions + 3 * m->triangles[3 * t + (size_t)(k + 1) % 3];
            e[k] = sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                        (a[2] - b[2]) * (a[2] - b[2]));
        }
        double lo = fmin(e[0], fmin(e[1], e[2])), hi = fmax(e[0], fmax(e[1], e[2]));
        longest = fmax(longest, hi);
        shortest_sum += lo;
    }
    /* grid spacing about 0.75 mm: nothing near a depth jump's 15 mm and more */
    CHECK_LE(longest, 10 * 0.00076);
    CHECK_LE(shortest_sum / (double)m->triangle_count, 0.0008);
    check_orientation(m);
    printf("ply_range_grid: bun000: %zu triangles, longest edge %.6g\n", m->triangle_count,
           longest);
    rsmooth_mesh_destroy(m);
    return 0;
}

static void write_file(const char *dir, const char *name, const void *data, size_t size) {
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "wb");
    CHECK(f != NULL);
    CHECK(fwrite(data, 1, size, f) == size);
    CHECK(fclose(f) == 0);
}

static int write_files(const char *dir) {
    const rsmooth_format formats[3] = {RSMOOTH_FORMAT_PLY_ASCII, RSMOOTH_FORMAT_PLY_BINARY,
                                       RSMOOTH_FORMAT_PLY_BINARY_BE};
    const char *const suffix[3] = {"", "_le", "_be"};
    for (int v = GOOD; v < VARIANT_COUNT; v++)
        for (int f = 0; f < 3; f++) {
            char name[64];
            snprintf(name, sizeof name, "%s%s.ply", v == GOOD ? "grid" : "bad_", suffix[f]);
            if (v != GOOD)
                snprintf(name, sizeof name, "bad_%s%s.ply", variant_name[v], suffix[f]);
            bytes b = grid_file(formats[f], (variant)v, 40);
            write_file(dir, name, b.data, b.size);
            bytes_free(&b);
            if (v != GOOD) {
                snprintf(name, sizeof name, "bad_%s%s.txt", variant_name[v], suffix[f]);
                write_file(dir, name, expected_message[v], strlen(expected_message[v]));
            }
        }
    char expected[128];
    int n = snprintf(expected, sizeof expected, "%zu %d %d %d\n", expected_triangles(true), COLS,
                     ROWS, sample_count());
    write_file(dir, "expected.txt", expected, (size_t)n);
    return 0;
}

int main(int argc, char **argv) {
    if (argc == 3 && !strcmp(argv[1], "write"))
        return write_files(argv[2]);
    check_good(RSMOOTH_FORMAT_PLY_ASCII);
    check_good(RSMOOTH_FORMAT_PLY_BINARY);
    check_good(RSMOOTH_FORMAT_PLY_BINARY_BE);
    check_encodings_agree();
    check_written_back();
    check_rewrite_stable();
    check_malformed();
    check_bunny_scan();
    printf("ply_range_grid: all checks passed\n");
    return 0;
}
