/* PLY reading and writing: all encodings, skipped data, errors, round trips, truncation. */
#define _POSIX_C_SOURCE 200809L
#include "rsmooth_io.h"
#include "test_io_util.h"

#include <stdbool.h>
#include <stdint.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

/* ---- parsing helpers */

/* Parses from a buffer of exactly `size` bytes (ASan catches any over-read). */
static rsmooth_status parse_n(const void *data, size_t size, rsmooth_mesh **mesh,
                              rsmooth_error *err) {
    void *copy = malloc(size ? size : 1);
    CHECK(copy != NULL);
    memcpy(copy, data, size);
    rsmooth_status s = rsmooth_mesh_read_memory(copy, size, RSMOOTH_FORMAT_AUTO, mesh, err);
    free(copy);
    return s;
}

static rsmooth_mesh *parse_ok(const bytes *b) {
    rsmooth_mesh *mesh = NULL;
    rsmooth_error err;
    rsmooth_status s = parse_n(b->data, b->size, &mesh, &err);
    if (s != RSMOOTH_OK)
        fprintf(stderr, "unexpected failure: %s (line %lld, byte %lld)\n", err.message,
                (long long)err.line, (long long)err.byte_offset);
    CHECK_EQ_INT(s, RSMOOTH_OK);
    CHECK(mesh != NULL);
    return mesh;
}

#define EXPECT_PARSE_ERROR(data, size, needle) expect_parse_error(__LINE__, data, size, needle)
static rsmooth_error expect_parse_error(int at, const void *data, size_t size, const char *needle) {
    rsmooth_mesh *mesh = (rsmooth_mesh *)&mesh;
    rsmooth_error err;
    rsmooth_status s = parse_n(data, size, &mesh, &err);
    if (s != RSMOOTH_ERROR_PARSE || !strstr(err.message, needle)) {
        fprintf(stderr, "test_ply_io.c:%d: status %d message '%s'; expected status %d, '%s'\n", at,
                (int)s, err.message, (int)RSMOOTH_ERROR_PARSE, needle);
        exit(1);
    }
    CHECK(mesh == NULL);
    return err;
}

/* The square 0-1-2-3 (a quad) plus the triangle 0 1 4, as every test file below stores it. */
static const double square[5][3] = {
    {0, 0, 0}, {1.5, 0, 0}, {1.5, 1.25, 0}, {0, 1.25, -0.5}, {0.25, -1, 3}};

static void check_square(const rsmooth_mesh *m) {
    CHECK_EQ_INT(m->vertex_count, 5);
    for (int i = 0; i < 5; i++)
        for (int c = 0; c < 3; c++)
            CHECK_NEAR(m->positions[3 * i + c], square[i][c], 0);
    CHECK_EQ_INT(m->face_count, 2);
    check_face(m, 0, (const uint32_t[]){0, 1, 2, 3}, 4);
    check_face(m, 1, (const uint32_t[]){0, 1, 4}, 3);
    CHECK_EQ_INT(m->triangle_count, 3);
    const uint32_t tris[9] = {0, 1, 2, 0, 2, 3, 0, 1, 4};
    for (int i = 0; i < 9; i++)
        CHECK_EQ_INT(m->triangles[i], tris[i]);
    CHECK(m->vertex_colors == NULL && m->vertex_quality == NULL);
}

/* ---- reading the three encodings */

static bytes ascii_square(void) {
    bytes b = {0};
    put_text(&b, "ply\r\n"
                 "format ascii 1.0\r\n"
                 "comment made by hand\r\n"
                 "obj_info anything\r\n"
                 "element vertex 5\r\n"
                 "property float nx\r\n"
                 "property float x\r\n"
                 "property float y\r\n"
                 "property float ny\r\n"
                 "property float z\r\n"
                 "property float nz\r\n"
                 "property uchar red\r\n"
                 "element tristrips 1\r\n"
                 "property list int int vertex_indices\r\n" /* not the face list */
                 "element face 2\r\n"
                 "property uchar flags\r\n"
                 "property list uchar int vertex_indices\r\n"
                 "property list uchar float texcoord\r\n"
                 "element material 1\r\n"
                 "property list uchar uchar name\r\n"
                 "property float shine\r\n"
                 "end_header\r\n");
    for (int i = 0; i < 5; i++) {
        char line[160];
        snprintf(line, sizeof line, "0.5 %.17g %.17g -1 %.17g 0 %d\r\n", square[i][0], square[i][1],
                 square[i][2], 10 * i);
        put_text(&b, line);
    }
    put_text(&b, "6 0 1 2 -1 3 4\r\n"
                 "7 4 0 1 2 3 2 0.5 0.5\r\n"
                 "1  3 0 1 4 0\n"
                 "3 65 66 67 0.5\n");
    return b;
}

static void test_ascii(void) {
    bytes b = ascii_square();
    rsmooth_mesh *m = parse_ok(&b);
    check_square(m);
    CHECK_EQ_INT(m->precision, RSMOOTH_FLOAT32);
    CHECK_EQ_INT(m->source_format, RSMOOTH_FORMAT_PLY_ASCII);
    rsmooth_mesh_destroy(m);
    bytes_free(&b);
}

/* Faces first, double coordinates, uint indices, an extra element with a list before them. */
static bytes binary_square(bool big_endian, bool doubles) {
    bytes b = {.big_endian = big_endian};
    put_text(&b, "ply\n");
    put_text(&b,
             big_endian ? "format binary_big_endian 1.0\n" : "format binary_little_endian 1.0\n");
    put_text(&b, "comment binary test\n"
                 "element edge 2\n"
                 "property int vertex1\n"
                 "property list uchar int corners\n"
                 "element face 2\n"
                 "property list int uint vertex_index\n"
                 "property uchar intensity\n"
                 "element vertex 5\n");
    put_text(&b, doubles ? "property double x\nproperty double y\nproperty double z\n"
                         : "property float32 x\nproperty float32 y\nproperty float32 z\n");
    put_text(&b, "property short nx\n"
                 "property uchar red\n"
                 "end_header\n");
    /* edges */
    put_i32(&b, 7);
    put_u8(&b, 2);
    put_i32(&b, 0);
    put_i32(&b, 1);
    put_i32(&b, 8);
    put_u8(&b, 0);
    /* faces */
    put_i32(&b, 4);
    for (uint32_t v = 0; v < 4; v++)
        put_i32(&b, (int32_t)v);
    put_u8(&b, 200);
    put_i32(&b, 3);
    put_i32(&b, 0);
    put_i32(&b, 1);
    put_i32(&b, 4);
    put_u8(&b, 201);
    /* vertices */
    for (int i = 0; i < 5; i++) {
        for (int c = 0; c < 3; c++) {
            if (doubles)
                put_f64(&b, square[i][c]);
            else
                put_f32(&b, (float)square[i][c]);
        }
        put_uint(&b, 0xfffe, 2);
        put_u8(&b, 255);
    }
    return b;
}

/* float x y z only, then "list uchar int" faces: what most tools write. */
static bytes common_square(bool big_endian) {
    bytes b = {.big_endian = big_endian};
    put_text(&b, "ply\n");
    put_text(&b,
             big_endian ? "format binary_big_endian 1.0\n" : "format binary_little_endian 1.0\n");
    put_text(&b, "element vertex 5\nproperty float x\n"
                 "property float y\nproperty float z\nelement face 2\n"
                 "property list uchar int vertex_indices\nend_header\n");
    for (int i = 0; i < 5; i++)
        for (int c = 0; c < 3; c++)
            put_f32(&b, (float)square[i][c]);
    put_u8(&b, 4);
    for (int v = 0; v < 4; v++)
        put_i32(&b, v);
    put_u8(&b, 3);
    put_i32(&b, 0);
    put_i32(&b, 1);
    put_i32(&b, 4);
    return b;
}

static void set_f32_le(unsigned char *p, float f) {
    uint32_t u;
    memcpy(&u, &f, 4);
    for (int i = 0; i < 4; i++)
        p[i] = (unsigned char)(u >> (8 * i));
}

static void test_binary(void) {
    for (int be = 0; be < 2; be++) {
        for (int dbl = 0; dbl < 2; dbl++) {
            bytes b = binary_square(be, dbl);
            rsmooth_mesh *m = parse_ok(&b);
            check_square(m);
            CHECK_EQ_INT(m->precision, dbl ? RSMOOTH_FLOAT64 : RSMOOTH_FLOAT32);
            CHECK_EQ_INT(m->source_format,
                         be ? RSMOOTH_FORMAT_PLY_BINARY_BE : RSMOOTH_FORMAT_PLY_BINARY);
            rsmooth_mesh_destroy(m);
            bytes_free(&b);
        }
    }

    /* The common layout (the direct path), in both byte orders. */
    bytes b = common_square(true);
    rsmooth_mesh *m = parse_ok(&b);
    check_square(m);
    rsmooth_mesh_destroy(m);
    bytes_free(&b);
    b = common_square(false);
    m = parse_ok(&b);
    check_square(m);
    rsmooth_mesh_destroy(m);

    /* A face index out of range, and a negative one. */
    size_t index_at = b.size - 4;
    b.data[index_at] = 5;
    rsmooth_error err =
        EXPECT_PARSE_ERROR(b.data, b.size, "face index 5 out of range (5 vertices)");
    CHECK_EQ_INT(err.byte_offset, index_at);
    CHECK_EQ_INT(err.line, -1);
    memset(b.data + index_at, 0xff, 4);
    EXPECT_PARSE_ERROR(b.data, b.size, "face index -1 out of range");
    b.data[index_at] = 4;
    memset(b.data + index_at + 1, 0, 3);
    /* A face of 2 vertices. */
    size_t count_at = b.size - 1 - 3 * 4;
    b.data[count_at] = 2;
    EXPECT_PARSE_ERROR(b.data, b.size, "face 1 has 2 vertices");
    b.data[count_at] = 3;
    /* A NaN coordinate in vertex 3. */
    size_t y3 = b.size - (1 + 12) - (1 + 16) - 12 * 2 + 4;
    set_f32_le(b.data + y3, NAN);
    err = EXPECT_PARSE_ERROR(b.data, b.size, "vertex 3 has a non-finite coordinate");
    CHECK_EQ_INT(err.byte_offset, y3 - 4);
    set_f32_le(b.data + y3, -INFINITY);
    EXPECT_PARSE_ERROR(b.data, b.size, "vertex 3 has a non-finite coordinate");
    bytes_free(&b);
}

/* ---- errors */

static void expect_header_error(int at, const char *header, const char *needle) {
    bytes b = {0};
    put_text(&b, header);
    put_text(&b, "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
    expect_parse_error(at, b.data, b.size, needle);
    bytes_free(&b);
}
#define EXPECT_HEADER_ERROR(header, needle) expect_header_error(__LINE__, header, needle)

#define VERTEX_XYZ "property float x\nproperty float y\nproperty float z\n"
#define FACE_LIST "property list uchar int vertex_indices\n"

static void test_errors(void) {
    rsmooth_error err;
    /* Not "ply" as first line: read as OBJ by AUTO, which finds no vertices; as PLY it is refused.
     */
    const char *not_ply = "plx\nformat ascii 1.0\nend_header\n";
    rsmooth_mesh *m = NULL;
    CHECK_EQ_INT(
        rsmooth_mesh_read_memory(not_ply, strlen(not_ply), RSMOOTH_FORMAT_PLY_ASCII, &m, &err),
        RSMOOTH_ERROR_PARSE);
    CHECK(strstr(err.message, "not a PLY file") != NULL);
    CHECK(m == NULL);
    CHECK_EQ_INT(rsmooth_mesh_read_memory("ply", 3, RSMOOTH_FORMAT_PLY_BINARY, &m, &err),
                 RSMOOTH_ERROR_PARSE);
    CHECK_EQ_INT(rsmooth_mesh_read_memory("plyx\n", 5, RSMOOTH_FORMAT_PLY_BINARY, &m, &err),
                 RSMOOTH_ERROR_PARSE);

    EXPECT_HEADER_ERROR("ply\nformat binary_middle_endian 1.0\nelement vertex 3\n" VERTEX_XYZ
                        "end_header\n",
                        "unknown PLY format 'binary_middle_endian'");
    EXPECT_HEADER_ERROR("ply\nformat ascii 2.0\nelement vertex 3\n" VERTEX_XYZ "end_header\n",
                        "unsupported PLY version");
    EXPECT_HEADER_ERROR("ply\nelement vertex 3\n" VERTEX_XYZ "end_header\n", "no 'format' line");
    EXPECT_HEADER_ERROR("ply\nformat ascii 1.0\nelement vertex 3\n" VERTEX_XYZ,
                        "bad header line: '0'");
    const char *no_end = "ply\nformat ascii 1.0\nelement vertex 3\n" VERTEX_XYZ "comment x\n";
    EXPECT_PARSE_ERROR(no_end, strlen(no_end), "header ends without 'end_header'");
    EXPECT_PARSE_ERROR(no_end, strlen(no_end) - 1, "header ends without 'end_header'");
    EXPECT_HEADER_ERROR("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                        "property float y\nproperty float128 z\nend_header\n",
                        "unknown type 'float128'");
    EXPECT_HEADER_ERROR("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                        "property float y\nend_header\n",
                        "no 'z' property");
    EXPECT_HEADER_ERROR("ply\nformat ascii 1.0\nproperty float x\nend_header\n",
                        "property before any element");
    EXPECT_HEADER_ERROR("ply\nformat ascii 1.0\nelement vertex -3\n" VERTEX_XYZ "end_header\n",
                        "bad element count");
    EXPECT_HEADER_ERROR("ply\nformat ascii 1.0\nelement vertex 99999999999999999999999\n" VERTEX_XYZ
                        "end_header\n",
                        "element count");
    EXPECT_HEADER_ERROR("ply\nformat ascii 1.0\nelement vertex 3\n" VERTEX_XYZ "bogus line\n"
                        "end_header\n",
                        "bad header line");
    EXPECT_HEADER_ERROR("ply\nformat ascii 1.0\nelement vertex 3\n" VERTEX_XYZ
                        "element face 1\nproperty list uchar int verts\nend_header\n",
                        "no 'vertex_indices'");
    EXPECT_HEADER_ERROR("ply\nformat ascii 1.0\nelement vertex 0\n" VERTEX_XYZ "end_header\n",
                        "no vertices");
    EXPECT_HEADER_ERROR("ply\nformat ascii 1.0\nelement face 0\n" FACE_LIST "end_header\n",
                        "no vertices");
    EXPECT_HEADER_ERROR(
        "ply\nformat ascii 1.0\nelement vertex 5000000000\n" VERTEX_XYZ "end_header\n", "too many");

    /* ascii data errors, with their line */
    const char *header = "ply\nformat ascii 1.0\nelement vertex 3\n" VERTEX_XYZ
                         "element face 1\n" FACE_LIST "end_header\n";
    char text[512];
    snprintf(text, sizeof text, "%s0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n", header);
    err = EXPECT_PARSE_ERROR(text, strlen(text), "vertex 1 has a non-finite coordinate");
    CHECK_EQ_INT(err.line, 11);
    snprintf(text, sizeof text, "%s0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", header);
    err = EXPECT_PARSE_ERROR(text, strlen(text), "face index 3 out of range (3 vertices)");
    CHECK_EQ_INT(err.line, 13);
    CHECK_EQ_INT(err.byte_offset, strlen(text) - 2);
    snprintf(text, sizeof text, "%s0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n", header);
    EXPECT_PARSE_ERROR(text, strlen(text), "face index -1 out of range");
    snprintf(text, sizeof text, "%s0 0 0\n1 0 0\n0 1 0\n2 0 1\n", header);
    EXPECT_PARSE_ERROR(text, strlen(text), "face 0 has 2 vertices");
    snprintf(text, sizeof text, "%s0 0 0\n1 0 0\n0 1 0\n3 0 1\n", header);
    err = EXPECT_PARSE_ERROR(text, strlen(text), "data ends inside element 'face' item 0");
    snprintf(text, sizeof text, "%s0 0 0\n1 0 0\n0 1 0\n3 0 1 2.5\n", header);
    EXPECT_PARSE_ERROR(text, strlen(text), "value 2.5 does not fit the type 'int'");
    snprintf(text, sizeof text, "%s0 0 0\n1 0 0\n0 1 zero\n3 0 1 2\n", header);
    err = EXPECT_PARSE_ERROR(text, strlen(text), "malformed number 'zero'");
    CHECK_EQ_INT(err.line, 12);

    /* binary truncated: the byte offset where the data ran out */
    bytes b = binary_square(false, false);
    err = EXPECT_PARSE_ERROR(b.data, b.size - 1, "only");
    CHECK(err.byte_offset > 0);
    bytes_free(&b);
}

/* Declared counts far beyond the data are refused before anything that size is allocated. */
static void test_huge_counts(void) {
    const char *cases[] = {
        "ply\nformat ascii 1.0\nelement vertex 4000000000\n" VERTEX_XYZ "end_header\n0 0 0\n",
        "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\n" VERTEX_XYZ
        "end_header\n\1\2\3\4\5\6\7\10\11\12\13\14",
        "ply\nformat binary_big_endian 1.0\nelement vertex 3\n" VERTEX_XYZ
        "element face 18446744073709551615\n" FACE_LIST "end_header\n",
        "ply\nformat ascii 1.0\nelement vertex 3\n" VERTEX_XYZ "element face 3000000000\n" FACE_LIST
        "end_header\n0 0 0\n0 0 0\n0 0 0\n3 0 1 2\n",
        "ply\nformat ascii 1.0\nelement vertex 3\n" VERTEX_XYZ "element face 1\n" FACE_LIST
        "end_header\n0 0 0\n0 0 0\n0 0 0\n4000000000 0 1 2\n",
        "ply\nformat binary_little_endian 1.0\nelement vertex 1\n" VERTEX_XYZ
        "element face 1\nproperty list uint int vertex_indices\n"
        "end_header\n\0\0\0\0\0\0\0\0\0\0\0\0\377\377\377\377\0\0\0\0",
        "ply\nformat binary_little_endian 1.0\nelement vertex 1\n" VERTEX_XYZ
        "element junk 4000000000\nproperty list uint int "
        "stuff\nend_header\n\0\0\0\0\0\0\0\0\0\0\0\0",
    };
    size_t sizes[] = {0, 0, 0, 0, 0, 0, 0};
    sizes[1] = strlen(cases[1]);
    sizes[5] = strlen(cases[5]) + 20; /* the data holds NULs */
    sizes[6] = strlen(cases[6]) + 12;
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        size_t size = sizes[i] ? sizes[i] : strlen(cases[i]);
        clock_t start = clock();
        rsmooth_mesh *m = NULL;
        rsmooth_error err;
        rsmooth_status s = parse_n(cases[i], size, &m, &err);
        double seconds = (double)(clock() - start) / CLOCKS_PER_SEC;
        if (s != RSMOOTH_ERROR_PARSE || seconds > 0.5) {
            fprintf(stderr, "test_ply_io.c:%d: case %zu: status %d (%s) in %.3f s\n", __LINE__, i,
                    (int)s, err.message, seconds);
            exit(1);
        }
        CHECK(m == NULL);
    }
}

/* ---- round trips */

/* 10^e without libm (the test links only rsmooth::io). */
static double power_of_ten(int e) {
    double v = 1;
    for (int i = 0; i < (e < 0 ? -e : e); i++)
        v *= 10;
    return e < 0 ? 1 / v : v;
}

static uint32_t lcg_state = 99;
static uint32_t lcg(void) {
    lcg_state = lcg_state * 1664525u + 1013904223u;
    return lcg_state >> 8;
}

static rsmooth_mesh *make_mesh(size_t nv, size_t nf, bool big_face) {
    rsmooth_mesh *m = NULL;
    rsmooth_error err;
    size_t extra = big_face ? 300 : 0;
    CHECK_EQ_INT(rsmooth_mesh_create(nv, nf + big_face, 6 * nf + extra, &m, &err), RSMOOTH_OK);
    for (size_t i = 0; i < 3 * nv; i++)
        m->positions[i] = ((double)lcg() / (1 << 24) - 0.5) * power_of_ten((int)(lcg() % 30) - 15);
    m->positions[4] = -0.0;
    uint32_t k = 0;
    for (size_t f = 0; f < nf; f++) {
        uint32_t n = 3 + lcg() % 4;
        for (uint32_t i = 0; i < n; i++)
            m->face_indices[k++] = lcg() % (uint32_t)nv;
        m->face_offsets[f + 1] = k;
    }
    if (big_face) {
        for (uint32_t i = 0; i < 300; i++)
            m->face_indices[k++] = i % (uint32_t)nv;
        m->face_offsets[nf + 1] = k;
    }
    CHECK_EQ_INT(rsmooth_mesh_triangulate(m, &err), RSMOOTH_OK);
    return m;
}

static void check_same(const rsmooth_mesh *a, const rsmooth_mesh *b) {
    CHECK_EQ_INT(a->vertex_count, b->vertex_count);
    CHECK_EQ_INT(a->face_count, b->face_count);
    CHECK_EQ_INT(a->triangle_count, b->triangle_count);
    CHECK_EQ_INT(a->precision, b->precision);
    for (size_t i = 0; i < 3 * a->vertex_count; i++) {
        double expected =
            a->precision == RSMOOTH_FLOAT32 ? (double)(float)a->positions[i] : a->positions[i];
        if (memcmp(&expected, &b->positions[i], sizeof expected) != 0) {
            fprintf(stderr, "test_ply_io.c:%d: position %zu: %.17g written, %.17g read\n", __LINE__,
                    i, expected, b->positions[i]);
            exit(1);
        }
    }
    for (size_t f = 0; f <= a->face_count; f++)
        CHECK_EQ_INT(a->face_offsets[f], b->face_offsets[f]);
    for (size_t i = 0; i < a->face_offsets[a->face_count]; i++)
        CHECK_EQ_INT(a->face_indices[i], b->face_indices[i]);
    for (size_t i = 0; i < 3 * a->triangle_count; i++)
        CHECK_EQ_INT(a->triangles[i], b->triangles[i]);
}

static rsmooth_mesh *write_and_read(const rsmooth_mesh *m, rsmooth_format format) {
    rsmooth_error err;
    FILE *f = tmpfile();
    CHECK(f != NULL);
    CHECK_EQ_INT(rsmooth_mesh_write_stream(m, f, format, &err), RSMOOTH_OK);
    long size = ftell(f);
    CHECK(size > 0);
    rewind(f);
    void *data = malloc((size_t)size);
    CHECK(data != NULL);
    CHECK_EQ_INT(fread(data, 1, (size_t)size, f), size);
    fclose(f);
    rsmooth_mesh *back = NULL;
    rsmooth_status s =
        rsmooth_mesh_read_memory(data, (size_t)size, RSMOOTH_FORMAT_AUTO, &back, &err);
    if (s != RSMOOTH_OK)
        fprintf(stderr, "read back: %s (line %lld byte %lld)\n", err.message, (long long)err.line,
                (long long)err.byte_offset);
    CHECK_EQ_INT(s, RSMOOTH_OK);
    CHECK_EQ_INT(back->source_format, format);
    free(data);
    return back;
}

static void test_round_trip(void) {
    const rsmooth_format formats[2] = {RSMOOTH_FORMAT_PLY_ASCII, RSMOOTH_FORMAT_PLY_BINARY};
    for (int fi = 0; fi < 2; fi++) {
        for (int precision = 0; precision < 2; precision++) {
            for (int extras = 0; extras < 2; extras++) {
                rsmooth_mesh *m = make_mesh(40, 70, extras);
                m->precision = precision ? RSMOOTH_FLOAT64 : RSMOOTH_FLOAT32;
                if (extras) { /* written, then read back (colours) and kept (quality) */
                    m->vertex_quality = calloc(m->vertex_count, sizeof(float));
                    m->vertex_colors = calloc(3 * m->vertex_count, 1);
                    CHECK(m->vertex_quality != NULL && m->vertex_colors != NULL);
                    m->vertex_quality[3] = 0.125f;
                    m->vertex_colors[7] = 200;
                }
                rsmooth_mesh *back = write_and_read(m, formats[fi]);
                check_same(m, back);
                CHECK((back->vertex_colors != NULL) == extras);
                if (extras)
                    CHECK(memcmp(back->vertex_colors, m->vertex_colors, 3 * m->vertex_count) == 0);
                CHECK((back->extras != NULL) == extras); /* a plain file keeps no extras */
                rsmooth_mesh_destroy(back);
                rsmooth_mesh_destroy(m);
            }
        }
    }

    /* Through a file: AUTO picks binary PLY from the extension. */
    rsmooth_mesh *m = make_mesh(10, 12, false);
    char path[64];
    snprintf(path, sizeof path, "/tmp/rsmooth_test_ply_%ld.ply", (long)getpid());
    rsmooth_error err;
    CHECK_EQ_INT(rsmooth_mesh_write_file(m, path, RSMOOTH_FORMAT_AUTO, &err), RSMOOTH_OK);
    rsmooth_mesh *back = NULL;
    CHECK_EQ_INT(rsmooth_mesh_read_file(path, &back, &err), RSMOOTH_OK);
    CHECK_EQ_INT(back->source_format, RSMOOTH_FORMAT_PLY_BINARY);
    check_same(m, back);
    rsmooth_mesh_destroy(back);
    CHECK_EQ_INT(rsmooth_mesh_write_file(m, path, RSMOOTH_FORMAT_PLY_BINARY_BE, &err),
                 RSMOOTH_ERROR_UNSUPPORTED);
    remove(path);
    rsmooth_mesh_destroy(m);
}

/* ---- truncation */

static void check_prefixes(const bytes *b) {
    check_prefixes_located("PLY", b->data, b->size);
    for (size_t len = 0; len < b->size; len++) {
        rsmooth_mesh *m = NULL;
        rsmooth_error err;
        rsmooth_status s = parse_n(b->data, len, &m, &err);
        if (s != RSMOOTH_OK && s != RSMOOTH_ERROR_PARSE) {
            fprintf(stderr, "test_ply_io.c:%d: prefix %zu: status %d\n", __LINE__, len, (int)s);
            exit(1);
        }
        CHECK((s == RSMOOTH_OK) == (m != NULL));
        rsmooth_mesh_destroy(m);
    }
}

static void test_truncated_prefixes(void) {
    bytes b = binary_square(false, true);
    check_prefixes(&b);
    bytes_free(&b);
    b = binary_square(true, false);
    check_prefixes(&b);
    bytes_free(&b);
    b = common_square(true);
    check_prefixes(&b);
    bytes_free(&b);
    b = ascii_square();
    check_prefixes(&b);
    bytes_free(&b);
}

/* Random corruption of a valid binary file: an error or a valid mesh, never a crash. */
static void test_corruption(void) {
    bytes goods[2] = {binary_square(false, false), common_square(true)};
    lcg_state = 7;
    for (int round = 0; round < 4000; round++) {
        const bytes good = goods[round % 2];
        bytes b = {0};
        put(&b, good.data, good.size);
        int flips = 1 + (int)(lcg() % 4);
        for (int i = 0; i < flips; i++)
            b.data[lcg() % b.size] = (unsigned char)lcg();
        rsmooth_mesh *m = NULL;
        rsmooth_error err;
        rsmooth_status s = parse_n(b.data, b.size, &m, &err);
        CHECK(s == RSMOOTH_OK || s == RSMOOTH_ERROR_PARSE);
        if (s == RSMOOTH_OK)
            for (size_t t = 0; t < 3 * m->triangle_count; t++)
                CHECK(m->triangles[t] < m->vertex_count);
        rsmooth_mesh_destroy(m);
        bytes_free(&b);
    }
    bytes_free(&goods[0]);
    bytes_free(&goods[1]);
}

/* ---- writers refuse what cannot be read back; byte-order marks; located errors;
 * values the declared types cannot hold */

/* Expects a parse error (any format family, read by AUTO) at `line` holding `needle`. */
static rsmooth_error expect_line(int at, const char *text, long long line, const char *needle) {
    rsmooth_error err = expect_parse_error(at, text, strlen(text), needle);
    if (err.line != line) {
        fprintf(stderr, "test_ply_io.c:%d: '%s' at line %lld, expected line %lld\n", at,
                err.message, (long long)err.line, line);
        exit(1);
    }
    return err;
}
#define EXPECT_LINE(text, line, needle) expect_line(__LINE__, text, line, needle)

static void test_write_refusals_and_extremes(void) {
    const rsmooth_format formats[2] = {RSMOOTH_FORMAT_PLY_ASCII, RSMOOTH_FORMAT_PLY_BINARY};
    for (int i = 0; i < 2; i++) {
        check_writer_refuses_unreadable(formats[i]);
        check_extremes_round_trip(formats[i], RSMOOTH_FLOAT64);
        check_extremes_round_trip(formats[i], RSMOOTH_FLOAT32);
        check_float32_scale(formats[i]);

        /* a non-finite quality is refused before anything is written */
        rsmooth_mesh *m = tetrahedron(RSMOOTH_FLOAT32);
        m->vertex_quality = calloc(4, sizeof(float));
        CHECK(m->vertex_quality != NULL);
        m->vertex_quality[1] = NAN;
        char *data;
        size_t size;
        rsmooth_error err;
        CHECK_EQ_INT(write_to_memory(m, formats[i], &data, &size, &err),
                     RSMOOTH_ERROR_INVALID_ARGUMENT);
        CHECK(size == 0 && strstr(err.message, "vertex 1 has a non-finite quality") != NULL);
        free(data);

        /* a float32 mesh holding a value beyond float range is written as double, not as inf */
        m->vertex_quality[1] = 0.5f;
        m->positions[5] = -1e100;
        rsmooth_mesh *back = write_and_read(m, formats[i]);
        CHECK_EQ_INT(back->precision, RSMOOTH_FLOAT64);
        CHECK(back->positions[5] == -1e100);
        rsmooth_mesh_destroy(back);
        rsmooth_mesh_destroy(m);
    }

    /* Written faithfully, a value the file's own float type cannot hold is refused, unwritten. */
    bytes b = ascii_square();
    rsmooth_mesh *m = parse_ok(&b);
    m->positions[3] = 1e60;
    char *data;
    size_t size;
    rsmooth_error err;
    CHECK_EQ_INT(write_to_memory(m, RSMOOTH_FORMAT_PLY_BINARY, &data, &size, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    CHECK(size == 0 && strstr(err.message, "vertex 1: x = ") != NULL &&
          strstr(err.message, "does not fit the file's 'float' type") != NULL);
    free(data);
    rsmooth_mesh_destroy(m);

    /* ... nor one it holds only below float32's precision at the mesh's scale: the square moved to
     * 1e-150 (it was written as zeros, exit 0), with the query saying the same without writing */
    m = parse_ok(&b);
    for (size_t k = 0; k < 3 * m->vertex_count; k++)
        m->positions[k] *= 1e-150;
    for (int binary = 0; binary < 2; binary++) {
        rsmooth_format format = binary ? RSMOOTH_FORMAT_PLY_BINARY : RSMOOTH_FORMAT_PLY_ASCII;
        CHECK_EQ_INT(write_to_memory(m, format, &data, &size, &err),
                     RSMOOTH_ERROR_INVALID_ARGUMENT);
        CHECK(size == 0 && strstr(err.message, "vertex 1: x = 1.5e-150") != NULL &&
              strstr(err.message, "the file's 'float' type") != NULL &&
              strstr(err.message, "a PLY with double") != NULL);
        free(data);
        rsmooth_error query;
        CHECK_EQ_INT(rsmooth_mesh_check_writable(m, format, &query),
                     RSMOOTH_ERROR_INVALID_ARGUMENT);
        CHECK(strcmp(query.message, err.message) == 0);
    }
    /* without the file's header (extras NULL) rsmooth picks double: written exactly */
    struct rsmooth_mesh_extras *extras = m->extras;
    m->extras = NULL;
    rsmooth_mesh *back = write_and_read(m, RSMOOTH_FORMAT_PLY_BINARY);
    CHECK(memcmp(back->positions, m->positions, 15 * sizeof(double)) == 0);
    rsmooth_mesh_destroy(back);
    m->extras = extras;
    rsmooth_mesh_destroy(m);
    /* a stray subnormal in a mesh at 1 is no such mesh */
    m = parse_ok(&b);
    m->positions[2] = 1e-40;
    CHECK_EQ_INT(rsmooth_mesh_check_writable(m, RSMOOTH_FORMAT_PLY_BINARY, &err), RSMOOTH_OK);
    back = write_and_read(m, RSMOOTH_FORMAT_PLY_BINARY);
    CHECK(back->positions[2] == (double)1e-40f);
    rsmooth_mesh_destroy(back);
    rsmooth_mesh_destroy(m);
    bytes_free(&b);
}

static void test_byte_order_mark(void) {
    bytes plain_file = ascii_square();
    bytes b = {0};
    put_text(&b, "\xEF\xBB\xBF");
    put(&b, plain_file.data, plain_file.size);
    rsmooth_mesh *m = parse_ok(&b);
    check_square(m);
    rsmooth_mesh *plain = parse_ok(&plain_file);
    for (int binary = 0; binary < 2; binary++) {
        /* Both encodings open with a text header: the mark goes back before it. */
        rsmooth_format format = binary ? RSMOOTH_FORMAT_PLY_BINARY : RSMOOTH_FORMAT_PLY_ASCII;
        size_t size, plain_size;
        char *out = mesh_to_memory(m, format, &size);
        char *plain_out = mesh_to_memory(plain, format, &plain_size);
        CHECK_EQ_INT(size, plain_size + 3);
        CHECK(memcmp(out, "\xEF\xBB\xBF", 3) == 0 && memcmp(out + 3, plain_out, plain_size) == 0);
        rsmooth_mesh *back = NULL;
        rsmooth_error err;
        CHECK_EQ_INT(read_exact_copy(out, size, RSMOOTH_FORMAT_AUTO, &back, &err), RSMOOTH_OK);
        check_square(back);
        CHECK(back->extras != NULL && back->extras != plain->extras);
        CHECK_EQ_INT(rsmooth_mesh_conversion_losses(back, RSMOOTH_FORMAT_PLY_ASCII, NULL, 0), 0);
        rsmooth_mesh_destroy(back);
        free(out);
        free(plain_out);
    }
    char losses[512];
    rsmooth_mesh_conversion_losses(m, RSMOOTH_FORMAT_OBJ, losses, sizeof losses);
    CHECK(strstr(losses, "UTF-8 byte-order mark") != NULL);
    rsmooth_mesh_conversion_losses(plain, RSMOOTH_FORMAT_OBJ, losses, sizeof losses);
    CHECK(strstr(losses, "byte-order") == NULL);
    rsmooth_mesh_destroy(plain);
    rsmooth_mesh_destroy(m);

    /* A binary PLY with a mark reads too; errors count the mark's bytes. */
    bytes binary = common_square(false);
    bytes marked = {0};
    put_text(&marked, "\xEF\xBB\xBF");
    put(&marked, binary.data, binary.size);
    m = parse_ok(&marked);
    check_square(m);
    rsmooth_mesh_destroy(m);
    size_t index_at = marked.size - 4;
    marked.data[index_at] = 9;
    rsmooth_error err = EXPECT_PARSE_ERROR(marked.data, marked.size, "face index 9 out of range");
    CHECK_EQ_INT(err.byte_offset, index_at);
    bytes_free(&marked);
    bytes_free(&binary);
    bytes_free(&b);
    bytes_free(&plain_file);
}

#define SQUARE_HEADER(vertex_props, face_list)                                                     \
    "ply\nformat ascii 1.0\nelement vertex 3\n" vertex_props "element face 1\n" face_list          \
    "end_header\n"

/* Bytes after the last element: blanks (the line end some writers append) read, anything else is
 * refused where it starts, since a header that counts fewer items than the data holds would drop
 * the rest (it was read, and the rest silently dropped). */
static void test_trailing_data(void) {
    bytes goods[3] = {binary_square(false, false), binary_square(true, true), common_square(false)};
    for (int g = 0; g < 3; g++) {
        const bytes *good = &goods[g];
        const char *blanks[] = {"\n", "\r\n", " \n\n\t"};
        for (size_t k = 0; k < sizeof blanks / sizeof blanks[0]; k++) {
            bytes b = {0};
            put(&b, good->data, good->size);
            put_text(&b, blanks[k]);
            rsmooth_mesh *m = parse_ok(&b);
            check_square(m);
            rsmooth_mesh_destroy(m);
            bytes_free(&b);
        }
        /* one face more than the header declares, after a line end */
        bytes b = {0};
        put(&b, good->data, good->size);
        put_text(&b, "\n");
        put_u8(&b, 3);
        put_i32(&b, 0);
        put_i32(&b, 1);
        put_i32(&b, 2);
        rsmooth_error err = EXPECT_PARSE_ERROR(b.data, b.size,
                                               "13 bytes after the data the header "
                                               "declares");
        CHECK_EQ_INT(err.byte_offset, good->size + 1);
        CHECK(strstr(err.message, "0x03") != NULL);
        bytes_free(&b);
        /* a NUL is no blank */
        put(&b, good->data, good->size);
        put(&b, "\n\0", 2);
        err = EXPECT_PARSE_ERROR(b.data, b.size, "1 bytes after the data");
        CHECK_EQ_INT(err.byte_offset, good->size + 1);
        bytes_free(&b);
    }
    /* A face count one short of the data: the second face is refused where it starts. */
    bytes b = common_square(false);
    unsigned char *count = NULL;
    for (size_t i = 0; !count && i + 14 <= b.size; i++)
        if (memcmp(b.data + i, "element face 2", 14) == 0)
            count = b.data + i;
    CHECK(count != NULL);
    count[13] = '1';
    rsmooth_error err = EXPECT_PARSE_ERROR(b.data, b.size,
                                           "13 bytes after the data the header "
                                           "declares");
    CHECK_EQ_INT(err.byte_offset, b.size - 13);
    bytes_free(&b);
    for (int g = 0; g < 3; g++)
        bytes_free(&goods[g]);

    /* ascii: blank lines may follow, a line of values may not */
    const char *text = "ply\nformat ascii 1.0\nelement vertex 3\n" VERTEX_XYZ
                       "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                       "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    char longer[512];
    snprintf(longer, sizeof longer, "%s\n  \r\n\t", text);
    bytes ok = {0};
    put_text(&ok, longer);
    rsmooth_mesh_destroy(parse_ok(&ok));
    bytes_free(&ok);
    snprintf(longer, sizeof longer, "%s\n3 0 2 1\n", text);
    err = EXPECT_LINE(longer, 15, "'3' after the data the header declares");
    CHECK_EQ_INT(err.byte_offset, strlen(text) + 1);
    snprintf(longer, sizeof longer, "%send\n", text);
    EXPECT_LINE(longer, 14, "'end' after the data the header declares");
}

static void test_detection_and_lenience(void) {
    /* Leading blanks or lines before "ply": a located error, not the OBJ fallback. */
    const char *indented =
        " ply\nformat ascii 1.0\nelement vertex 1\n" VERTEX_XYZ "end_header\n0 0 0\n";
    rsmooth_error err = EXPECT_LINE(indented, 1, "a PLY file must start with the line 'ply'");
    CHECK_EQ_INT(err.byte_offset, 1);
    err = EXPECT_LINE("\r\n\nply\nformat ascii 1.0\n", 3, "after 3 bytes of blanks");
    CHECK_EQ_INT(err.byte_offset, 3);
    EXPECT_LINE("PLY\nformat ascii 1.0\n", 1, "must start with the line 'ply' (lowercase)");
    EXPECT_LINE("ply", 1, "the file ends after 'ply'");
    EXPECT_LINE("plyx\nformat ascii 1.0\n", 1, "the first line is 'plyx', not 'ply' alone");
    /* a header cut short (a truncated binary PLY): located where it ends */
    bytes b = common_square(false);
    err = EXPECT_PARSE_ERROR(b.data, 60, "header ends without 'end_header'");
    CHECK(err.line > 1 && err.byte_offset > 0 && err.byte_offset <= 60);
    bytes_free(&b);
    EXPECT_LINE("ply\nformat ascii 1.0\nelement face 0\n" FACE_LIST "end_header\n", 5,
                "the header declares no 'element vertex'");

    /* A property named twice in one element. */
    EXPECT_LINE("ply\nformat ascii 1.0\nelement vertex 3\n" VERTEX_XYZ "property float y\n"
                "end_header\n0 0 0 0\n",
                7, "a second property of the same name in one element: 'y'");

    /* An extra or missing value is blamed on its own row, not on a later one. */
    const char *header = SQUARE_HEADER(VERTEX_XYZ, FACE_LIST);
    char text[512];
    snprintf(text, sizeof text, "%s0 0 0\n1 0 0 7\n0 1 0\n3 0 1 2\n", header);
    err = EXPECT_LINE(text, 11, "extra value '7' on the line of element 'vertex' item 1");
    CHECK_EQ_INT(err.byte_offset, strstr(text, " 7\n") + 1 - text);
    snprintf(text, sizeof text, "%s0 0 0\n1 0\n0 1 0\n3 0 1 2\n", header);
    EXPECT_LINE(text, 11, "element 'vertex' item 1 ends with its line");
    snprintf(text, sizeof text, "%s0 0 0\n1 0 0\n0 1 0\n3 0 1 2 0\n", header);
    EXPECT_LINE(text, 13, "extra value '0' on the line of element 'face' item 0");

    /* Values their declared types cannot hold, refused at read time with their line. */
    static const struct {
        const char *x_type, *x, *needle;
    } misfits[] = {{"uchar", "300", "value 300 does not fit the type 'uchar' of property 'x'"},
                   {"char", "-200", "value -200 does not fit the type 'char'"},
                   {"int", "2.5", "value 2.5 does not fit the type 'int'"},
                   {"ushort", "-1", "value -1 does not fit the type 'ushort'"},
                   {"float", "1e39", "does not fit the type 'float' of property 'x'"},
                   {"double", "1e151", "vertex 1 has coordinate 1e+151 beyond the supported"},
                   {"float", "nan", "vertex 1 has a non-finite coordinate"}};
    for (size_t i = 0; i < sizeof misfits / sizeof misfits[0]; i++) {
        snprintf(text, sizeof text,
                 "ply\nformat ascii 1.0\nelement vertex 3\nproperty %s x\nproperty float y\n"
                 "property float z\nend_header\n0 0 0\n%s 0 0\n0 1 0\n",
                 misfits[i].x_type, misfits[i].x);
        expect_line(__LINE__, text, 9, misfits[i].needle);
    }
    snprintf(text, sizeof text, "%s0 0 0\n1 0 0\n0 1 0\n3 0 1 256\n",
             SQUARE_HEADER(VERTEX_XYZ, "property list uchar uchar vertex_indices\n"));
    EXPECT_LINE(text, 13, "value 256 does not fit the type 'uchar' of property 'vertex_indices'");
    snprintf(text, sizeof text, "%s0 0 0\n1 0 0\n0 1 0\n256 0 1 2\n", header);
    EXPECT_LINE(text, 13, "value 256 does not fit the type 'uchar'");
    snprintf(text, sizeof text, "%s0 0 0 0 0 1\n1 0 0 0 nan 1\n0 1 0 0 0 1\n3 0 1 2\n",
             SQUARE_HEADER(VERTEX_XYZ "property float nx\nproperty float ny\nproperty float nz\n",
                           FACE_LIST));
    EXPECT_LINE(text, 14, "vertex 1 has a non-finite normal");
    snprintf(text, sizeof text, "%s0 0 0 1 0 0\n1 0 0 0 nan 0\n0 1 0 0 0 1\n3 0 1 2\n",
             SQUARE_HEADER(VERTEX_XYZ "property float red\nproperty float green\n"
                                      "property float blue\n",
                           FACE_LIST));
    EXPECT_LINE(text, 14, "vertex 1 has a non-finite colour ('green')");
    /* the same in binary (both vertex layouts), located by the vertex's first byte */
    for (int with_list = 0; with_list < 2; with_list++) {
        bytes c = {0};
        put_text(&c, "ply\nformat binary_little_endian 1.0\nelement vertex 2\n" VERTEX_XYZ
                     "property double red\nproperty double green\nproperty double blue\n");
        if (with_list)
            put_text(&c, "property list uchar int ids\n");
        put_text(&c, "end_header\n");
        size_t vertex1 = 0;
        for (int v = 0; v < 2; v++) {
            if (v == 1)
                vertex1 = c.size;
            for (int k = 0; k < 3; k++)
                put_f32(&c, (float)(v + k));
            put_f64(&c, 0.5);
            put_f64(&c, v == 1 ? INFINITY : 0.25);
            put_f64(&c, 1);
            if (with_list)
                put_u8(&c, 0);
        }
        err = EXPECT_PARSE_ERROR(c.data, c.size, "vertex 1 has a non-finite colour ('green')");
        CHECK_EQ_INT(err.byte_offset, vertex1);
        bytes_free(&c);
    }

    /* Binary: the byte offset of the vertex beyond the supported magnitude. */
    b = binary_square(false, true);
    size_t y2 = b.size - 3 * 27 + 8; /* vertex 2's y: each vertex is 3 doubles, a short, a byte */
    double huge = -2e150;
    memcpy(b.data + y2, &huge, 8);
    err = EXPECT_PARSE_ERROR(b.data, b.size, "vertex 2 has coordinate -2e+150 beyond");
    CHECK_EQ_INT(err.byte_offset, y2 - 8);
    CHECK_EQ_INT(err.line, -1);
    bytes_free(&b);
}

/* "-0" in an integer property is the integer 0: read as +0, as a binary file would hold it, so
 * writing it back (as "0", or 0 in binary) reads back the same (found by fuzz_ply). */
static void test_integer_negative_zero(void) {
    static const char text[] = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                               "property float y\nproperty uint z\nelement face 1\n"
                               "property list uchar int vertex_indices\nend_header\n"
                               "-0 0 -0\n1 0 0\n0 1 0\n3 0 1 -0\n";
    bytes b = {0};
    put_text(&b, text);
    rsmooth_mesh *m = parse_ok(&b);
    CHECK(signbit(m->positions[0])); /* a float keeps its sign */
    CHECK(m->positions[2] == 0 && !signbit(m->positions[2]));
    for (int f = 0; f < 2; f++) {
        rsmooth_format format = f ? RSMOOTH_FORMAT_PLY_BINARY : RSMOOTH_FORMAT_PLY_ASCII;
        rsmooth_mesh *back = write_and_read(m, format);
        CHECK(memcmp(back->positions, m->positions, 9 * sizeof(double)) == 0);
        rsmooth_mesh_destroy(back);
    }
    rsmooth_mesh_destroy(m);
    bytes_free(&b);
}

int main(void) {
    test_integer_negative_zero();
    test_ascii();
    test_binary();
    test_errors();
    test_huge_counts();
    test_round_trip();
    test_truncated_prefixes();
    test_corruption();
    test_write_refusals_and_extremes();
    test_byte_order_mark();
    test_detection_and_lenience();
    test_trailing_data();
    printf("ply_io: all checks passed\n");
    return 0;
}
