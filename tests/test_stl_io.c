/* STL reading and writing: ascii and binary, soups, extras, errors, round trips, truncation. */
#define _POSIX_C_SOURCE 200809L
#include "rsmooth_io.h"
#include "test_io_util.h"

#include <stdbool.h>
#include <stdint.h>
#include <string.h>

static uint32_t get_u32(const unsigned char *p) {
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static float get_f32(const unsigned char *p) {
    uint32_t u = get_u32(p);
    float f;
    memcpy(&f, &u, 4);
    return f;
}

static void set_f32(unsigned char *p, float f) {
    uint32_t u;
    memcpy(&u, &f, 4);
    for (int i = 0; i < 4; i++)
        p[i] = (unsigned char)(u >> (8 * i));
}

/* Two triangles sharing an edge, then one off to the side: what every sample below stores. */
static const double tri[3][3][3] = {{{0, 0, 0}, {1.5, 0, 0}, {1.5, 1.25, 0}},
                                    {{0, 0, 0}, {1.5, 1.25, 0}, {0, 1.25, -0.5}},
                                    {{0.25, -1, 3}, {2, -1, 3}, {0.25, 1, 3.125}}};

static void check_soup(const rsmooth_mesh *m, size_t triangles, double tol) {
    CHECK_EQ_INT(m->vertex_count, 3 * triangles);
    CHECK_EQ_INT(m->face_count, triangles);
    CHECK_EQ_INT(m->triangle_count, triangles);
    CHECK_EQ_INT(m->has_vertex_normals, 0);
    CHECK(m->vertex_colors == NULL && m->vertex_quality == NULL);
    for (size_t i = 0; i <= triangles; i++)
        CHECK_EQ_INT(m->face_offsets[i], 3 * i);
    for (size_t i = 0; i < 3 * triangles; i++) {
        CHECK_EQ_INT(m->face_indices[i], i);
        CHECK_EQ_INT(m->triangles[i], i);
        for (int c = 0; c < 3; c++)
            CHECK_NEAR(m->positions[3 * i + c], tri[i / 3 % 3][i % 3][c], tol);
    }
}

/* ---- samples */

/* Mixed case, CRLF, tabs, odd spacing and number forms; the facet normals are wrong on purpose
 * (they are recomputed). */
static bytes ascii_sample(void) {
    bytes b = {0};
    put_text(&b, "  solid  part one \r\n");
    for (int t = 0; t < 3; t++) {
        put_text(&b, t == 1 ? "FACET Normal 1e0 0 0\r\n  OUTER\tLOOP\r\n"
                            : "facet normal 0 0 -1\n outer loop\n");
        for (int v = 0; v < 3; v++) {
            char line[160];
            snprintf(line, sizeof line, "%s %.17g\t%.17g  %.17g\r\n", v == 2 ? "VeRtEx" : "vertex",
                     tri[t][v][0], tri[t][v][1], tri[t][v][2]);
            put_text(&b, line);
        }
        put_text(&b, "endloop\nendfacet\n");
    }
    put_text(&b, "endsolid part one\r\n\r\n");
    return b;
}

static bytes binary_sample(const char *header, const uint16_t *attributes) {
    bytes b = {0};
    unsigned char head[80];
    memset(head, 0, sizeof head);
    memcpy(head, header, strlen(header));
    put(&b, head, sizeof head);
    put_u32(&b, 3);
    for (int t = 0; t < 3; t++) {
        put_f32(&b, 0);
        put_f32(&b, 0);
        put_f32(&b, 1);
        for (int v = 0; v < 3; v++)
            for (int c = 0; c < 3; c++)
                put_f32(&b, (float)tri[t][v][c]);
        uint16_t a = attributes ? attributes[t] : 0;
        unsigned char ab[2] = {(unsigned char)a, (unsigned char)(a >> 8)};
        put(&b, ab, 2);
    }
    return b;
}

/* ---- parsing helpers */

/* Parses from a buffer of exactly `size` bytes (ASan catches any over-read). */
static rsmooth_status parse_n(const void *data, size_t size, rsmooth_format format,
                              rsmooth_mesh **mesh, rsmooth_error *err) {
    void *copy = malloc(size ? size : 1);
    CHECK(copy != NULL);
    if (size)
        memcpy(copy, data, size);
    rsmooth_status s = rsmooth_mesh_read_memory(copy, size, format, mesh, err);
    free(copy);
    return s;
}

static rsmooth_mesh *parse_ok(const void *data, size_t size, rsmooth_format format) {
    rsmooth_mesh *mesh = NULL;
    rsmooth_error err;
    rsmooth_status s = parse_n(data, size, format, &mesh, &err);
    if (s != RSMOOTH_OK)
        fprintf(stderr, "unexpected failure: %s (line %lld, byte %lld)\n", err.message,
                (long long)err.line, (long long)err.byte_offset);
    CHECK_EQ_INT(s, RSMOOTH_OK);
    CHECK(mesh != NULL);
    return mesh;
}

#define EXPECT_PARSE_ERROR(data, size, needle)                                                     \
    expect_parse_error(__LINE__, data, size, RSMOOTH_FORMAT_STL_BINARY, needle)
static rsmooth_error expect_parse_error(int at, const void *data, size_t size,
                                        rsmooth_format format, const char *needle) {
    rsmooth_mesh *mesh = (rsmooth_mesh *)&mesh;
    rsmooth_error err;
    rsmooth_status s = parse_n(data, size, format, &mesh, &err);
    if (s != RSMOOTH_ERROR_PARSE || !strstr(err.message, needle)) {
        fprintf(stderr, "test_stl_io.c:%d: status %d message '%s'; expected status %d, '%s'\n", at,
                (int)s, err.message, (int)RSMOOTH_ERROR_PARSE, needle);
        exit(1);
    }
    CHECK(mesh == NULL);
    return err;
}

/* An ascii sample with `body` between "solid t" and "endsolid t". */
static rsmooth_error expect_ascii_error(int at, const char *body, const char *needle) {
    bytes b = {0};
    put_text(&b, "solid t\n");
    put_text(&b, body);
    put_text(&b, "endsolid t\n");
    rsmooth_error err = expect_parse_error(at, b.data, b.size, RSMOOTH_FORMAT_AUTO, needle);
    bytes_free(&b);
    return err;
}
#define EXPECT_ASCII_ERROR(body, needle) expect_ascii_error(__LINE__, body, needle)

#define GOOD_FACET                                                                                 \
    "facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 "                      \
    "0\nendloop\nendfacet\n"

static bool contains(const bytes *b, const char *needle) {
    size_t n = strlen(needle);
    for (size_t i = 0; i + n <= b->size; i++)
        if (memcmp(b->data + i, needle, n) == 0)
            return true;
    return false;
}

/* ---- reading */

static void test_ascii(void) {
    bytes b = ascii_sample();
    rsmooth_mesh *m = parse_ok(b.data, b.size, RSMOOTH_FORMAT_AUTO);
    check_soup(m, 3, 0);
    CHECK_EQ_INT(m->precision, RSMOOTH_FLOAT64);
    CHECK_EQ_INT(m->source_format, RSMOOTH_FORMAT_STL_ASCII);
    char losses[128];
    CHECK_EQ_INT(
        rsmooth_mesh_conversion_losses(m, RSMOOTH_FORMAT_PLY_BINARY, losses, sizeof losses), 1);
    CHECK(strcmp(losses, "STL header") == 0);
    CHECK_EQ_INT(
        rsmooth_mesh_conversion_losses(m, RSMOOTH_FORMAT_STL_BINARY, losses, sizeof losses), 0);
    rsmooth_mesh_destroy(m);
    /* Either STL format reads it: the content decides. */
    m = parse_ok(b.data, b.size, RSMOOTH_FORMAT_STL_BINARY);
    check_soup(m, 3, 0);
    rsmooth_mesh_destroy(m);
    bytes_free(&b);

    /* Unnamed: nothing to keep. */
    const char *plain = "solid\n" GOOD_FACET "endsolid\n";
    m = parse_ok(plain, strlen(plain), RSMOOTH_FORMAT_AUTO);
    CHECK(m->extras == NULL);
    CHECK_EQ_INT(m->vertex_count, 3);
    rsmooth_mesh_destroy(m);

    /* Several solids, one with no facet, no trailing newline. */
    const char *several = "solid a\n" GOOD_FACET GOOD_FACET "endsolid a\nsolid\nendsolid\n"
                          "SOLID c d\n" GOOD_FACET "ENDSOLID";
    m = parse_ok(several, strlen(several), RSMOOTH_FORMAT_AUTO);
    CHECK_EQ_INT(m->triangle_count, 3);
    CHECK_EQ_INT(m->vertex_count, 9);
    CHECK_NEAR(m->positions[3 * 8 + 1], 1, 0);
    bytes out = {0};
    out.data = mesh_to_memory(m, RSMOOTH_FORMAT_STL_ASCII, &out.size);
    CHECK(contains(&out, "solid a\n") && contains(&out, "endsolid a\n"));
    CHECK(contains(&out, "solid\nendsolid\n"));
    CHECK(contains(&out, "solid c d\n") && contains(&out, "endsolid c d\n"));
    rsmooth_mesh *back = parse_ok(out.data, out.size, RSMOOTH_FORMAT_AUTO);
    bytes again = {0};
    again.data = mesh_to_memory(back, RSMOOTH_FORMAT_STL_ASCII, &again.size);
    CHECK(again.size == out.size && memcmp(again.data, out.data, out.size) == 0);
    bytes_free(&again);
    rsmooth_mesh_destroy(back);
    bytes_free(&out);
    /* To binary: the first name is the header. */
    out.data = mesh_to_memory(m, RSMOOTH_FORMAT_STL_BINARY, &out.size);
    CHECK_EQ_INT(out.size, 84 + 3 * 50);
    CHECK(memcmp(out.data, "a ", 2) == 0);
    bytes_free(&out);
    rsmooth_mesh_destroy(m);
}

static void test_binary(void) {
    const uint16_t attributes[3] = {0, 0x7c1f, 1};
    bytes b = binary_sample("made by test_stl_io", attributes);
    rsmooth_mesh *m = parse_ok(b.data, b.size, RSMOOTH_FORMAT_AUTO);
    check_soup(m, 3, 0);
    CHECK_EQ_INT(m->precision, RSMOOTH_FLOAT32);
    CHECK_EQ_INT(m->source_format, RSMOOTH_FORMAT_STL_BINARY);
    char losses[128];
    CHECK_EQ_INT(rsmooth_mesh_conversion_losses(m, RSMOOTH_FORMAT_OBJ, losses, sizeof losses), 2);
    CHECK(strcmp(losses, "STL header, STL facet attributes") == 0);
    CHECK_EQ_INT(rsmooth_mesh_conversion_losses(m, RSMOOTH_FORMAT_STL_ASCII, losses, sizeof losses),
                 1);
    CHECK(strcmp(losses, "STL facet attributes") == 0);
    CHECK_EQ_INT(
        rsmooth_mesh_conversion_losses(m, RSMOOTH_FORMAT_STL_BINARY, losses, sizeof losses), 0);

    /* Written back: the same header and attributes, normals recomputed. */
    bytes out = {0};
    out.data = mesh_to_memory(m, RSMOOTH_FORMAT_STL_BINARY, &out.size);
    CHECK_EQ_INT(out.size, b.size);
    CHECK(memcmp(out.data, b.data, 84) == 0);
    for (size_t t = 0; t < 3; t++) {
        const unsigned char *r = out.data + 84 + 50 * t, *in = b.data + 84 + 50 * t;
        CHECK(memcmp(r + 12, in + 12, 38) == 0); /* vertices and attribute */
    }
    /* Facet 0 lies in z = 0, counter-clockwise seen from +z. */
    CHECK_NEAR(get_f32(out.data + 84), 0, 0);
    CHECK_NEAR(get_f32(out.data + 88), 0, 0);
    CHECK_NEAR(get_f32(out.data + 92), 1, 0);
    /* Facet 1: (1.5, 1.25, 0) x (0, 1.25, -0.5) = (-0.625, 0.75, 1.875), normalised. */
    const double n1[3] = {-0.625, 0.75, 1.875}, len1 = sqrt(4.46875);
    for (int k = 0; k < 3; k++)
        CHECK_NEAR(get_f32(out.data + 84 + 50 + 4 * k), n1[k] / len1, 1e-7);
    bytes_free(&out);

    /* Once the triangles change, the details no longer apply. */
    m->triangle_count = 2;
    out.data = mesh_to_memory(m, RSMOOTH_FORMAT_STL_BINARY, &out.size);
    CHECK_EQ_INT(out.size, 84 + 2 * 50);
    CHECK(memcmp(out.data, "rsmooth ", 8) == 0 && out.data[79] == ' ');
    CHECK_EQ_INT(get_u32(out.data + 80), 2);
    CHECK(out.data[84 + 50 + 48] == 0 && out.data[84 + 50 + 49] == 0);
    bytes_free(&out);
    m->triangle_count = 3;

    /* To ascii: the header as the solid name. */
    out.data = mesh_to_memory(m, RSMOOTH_FORMAT_STL_ASCII, &out.size);
    CHECK(contains(&out, "solid made by test_stl_io\n"));
    CHECK(contains(&out, "endsolid made by test_stl_io\n"));
    rsmooth_mesh_destroy(m);
    bytes_free(&out);
    bytes_free(&b);

    /* Blank header, no attributes: nothing kept; written back with the default header. */
    b = binary_sample("", NULL);
    m = parse_ok(b.data, b.size, RSMOOTH_FORMAT_AUTO);
    CHECK(m->extras == NULL);
    out.data = mesh_to_memory(m, RSMOOTH_FORMAT_STL_ASCII, &out.size);
    CHECK(memcmp(out.data, "solid rsmooth\n", 14) == 0);
    CHECK(contains(&out, "endsolid rsmooth\n"));
    /* float32 data written at float precision */
    CHECK(contains(&out, "vertex 0.25 1 3.125\n"));
    bytes_free(&out);
    rsmooth_mesh_destroy(m);
    bytes_free(&b);

    /* A header that starts with "solid": the exact size makes it binary. */
    b = binary_sample("solid cube exported by a CAD tool", NULL);
    m = parse_ok(b.data, b.size, RSMOOTH_FORMAT_AUTO);
    CHECK_EQ_INT(m->source_format, RSMOOTH_FORMAT_STL_BINARY);
    check_soup(m, 3, 0);
    out.data = mesh_to_memory(m, RSMOOTH_FORMAT_STL_ASCII, &out.size);
    CHECK(memcmp(out.data, "solid cube exported by a CAD tool\n", 34) == 0);
    bytes_free(&out);
    rsmooth_mesh_destroy(m);
    /* The same with one byte more: its size is what is wrong, though it starts like ascii. */
    put(&b, "", 1);
    EXPECT_PARSE_ERROR(b.data, b.size, "84 + 50 × 3 = 234 bytes expected, 235 found");
    bytes_free(&b);
}

static void test_errors(void) {
    rsmooth_error err;
    /* Counts that disagree with the size, zero and too many triangles. */
    bytes b = binary_sample("x", NULL);
    b.data[80] = 4;
    err = EXPECT_PARSE_ERROR(b.data, b.size, "84 + 50 × 4 = 284 bytes expected, 234 found");
    CHECK_EQ_INT(err.line, -1);
    b.data[80] = 2;
    EXPECT_PARSE_ERROR(b.data, b.size, "84 + 50 × 2 = 184 bytes expected, 234 found");
    memset(b.data + 80, 0, 4);
    EXPECT_PARSE_ERROR(b.data, 84, "no triangles");
    EXPECT_PARSE_ERROR(b.data, b.size, "84 + 50 × 0 = 84 bytes expected, 234 found");
    memset(b.data + 80, 0xff, 4);
    EXPECT_PARSE_ERROR(b.data, b.size, "84 + 50 × 4294967295 = 214748364834 bytes expected");
    EXPECT_PARSE_ERROR(b.data, 83, "at least 84 bytes");
    EXPECT_PARSE_ERROR(b.data, 0, "at least 84 bytes");
    b.data[80] = 3;
    memset(b.data + 81, 0, 3);
    /* NaN and infinity, with the byte offset of the vertex. */
    set_f32(b.data + 84 + 50 + 12 + 12 + 4, NAN);
    err = EXPECT_PARSE_ERROR(b.data, b.size, "facet 1 has a non-finite vertex");
    CHECK_EQ_INT(err.byte_offset, 84 + 50 + 24);
    set_f32(b.data + 84 + 50 + 12 + 12 + 4, -INFINITY);
    EXPECT_PARSE_ERROR(b.data, b.size, "facet 1 has a non-finite vertex");
    /* A non-finite normal is no error: normals are recomputed. */
    set_f32(b.data + 84 + 50 + 12 + 12 + 4, 1);
    set_f32(b.data + 84, NAN);
    rsmooth_mesh_destroy(parse_ok(b.data, b.size, RSMOOTH_FORMAT_STL_BINARY));
    bytes_free(&b);

    /* ascii: keywords, vertex counts, numbers, with their line */
    /* a bad coordinate is located at its own vertex line (it was the facet's first line) */
    err = EXPECT_ASCII_ERROR(GOOD_FACET "facet normal 0 0 1\nouter loop\nvertex nan 0 0\n"
                                        "vertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n",
                             "facet 1 has a non-finite vertex");
    CHECK_EQ_INT(err.line, 11);
    CHECK_EQ_INT(err.byte_offset,
                 strlen("solid t\n" GOOD_FACET "facet normal 0 0 1\nouter loop\n"));
    EXPECT_ASCII_ERROR("facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 inf\n"
                       "vertex 0 1 0\nendloop\nendfacet\n",
                       "facet 0 has a non-finite vertex");
    err =
        EXPECT_ASCII_ERROR(GOOD_FACET GOOD_FACET "facet normal 0 0 1\nouter loop\n"
                                                 "vertex 0 0 0\nvertex 1 0 0\nendloop\nendfacet\n",
                           "facet 2 has 2 vertices");
    CHECK_EQ_INT(err.line, 16);
    EXPECT_ASCII_ERROR("facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
                       "vertex 0 1 0\nvertex 1 1 0\nendloop\nendfacet\n",
                       "facet 0 has 4 vertices");
    EXPECT_ASCII_ERROR("facet normal 0 0 1\nouter loop\nendloop\nendfacet\n",
                       "facet 0 has 0 vertices");
    EXPECT_ASCII_ERROR("facet 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
                       "endloop\nendfacet\n",
                       "expected 'normal', found '0'");
    EXPECT_ASCII_ERROR("facet normal 0 0 1\nloop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
                       "endloop\nendfacet\n",
                       "expected 'outer', found 'loop'");
    EXPECT_ASCII_ERROR("facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
                       "endfacet\n",
                       "expected 'endloop', found 'endfacet'");
    EXPECT_ASCII_ERROR("facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
                       "endloop\n",
                       "expected 'endfacet', found 'endsolid'");
    EXPECT_ASCII_ERROR("facet normal 0 0\nouter loop\n", "malformed number 'outer'");
    err = EXPECT_ASCII_ERROR("facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 zero 0\n",
                             "malformed number 'zero'");
    CHECK_EQ_INT(err.line, 5);
    CHECK_EQ_INT(err.byte_offset, strlen("solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n"
                                         "vertex 1 "));
    EXPECT_ASCII_ERROR("vertex 0 0 0\n", "expected 'facet', found 'vertex'");
    EXPECT_ASCII_ERROR("", "no triangles");

    const char *text = "solid t\n" GOOD_FACET;
    expect_parse_error(__LINE__, text, strlen(text), RSMOOTH_FORMAT_AUTO,
                       "data ends where 'endsolid' was expected");
    text = "solid t\n" GOOD_FACET "endsolid t\nfacet";
    err = expect_parse_error(__LINE__, text, strlen(text), RSMOOTH_FORMAT_AUTO,
                             "expected 'solid', found 'facet'");
    CHECK_EQ_INT(err.line, 10);
    text = "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1";
    expect_parse_error(__LINE__, text, strlen(text), RSMOOTH_FORMAT_AUTO,
                       "data ends where a number was expected");

    /* Neither binary (size) nor ascii ("solid"). */
    unsigned char garbage[300];
    uint32_t state = 12345;
    for (int round = 0; round < 200; round++) {
        size_t n = (size_t)round * 3 % sizeof garbage;
        for (size_t i = 0; i < n; i++) {
            state = state * 1664525u + 1013904223u;
            garbage[i] = (unsigned char)(state >> 24);
        }
        rsmooth_mesh *m = NULL;
        rsmooth_status s = parse_n(garbage, n, RSMOOTH_FORMAT_STL_BINARY, &m, &err);
        CHECK(s == RSMOOTH_ERROR_PARSE || s == RSMOOTH_OK);
        CHECK((s == RSMOOTH_OK) == (m != NULL));
        rsmooth_mesh_destroy(m);
    }
    EXPECT_PARSE_ERROR("facet normal", 12, "at least 84 bytes");
}

/* Every prefix parses or fails cleanly, from a buffer of exactly its size. */
static void test_truncated(void) {
    bytes samples[2] = {ascii_sample(), binary_sample("truncated", (const uint16_t[]){1, 2, 3})};
    size_t ascii_end = 0;
    while (memcmp(samples[0].data + ascii_end, "endsolid", 8) != 0)
        ascii_end++;
    ascii_end += 8;
    for (int k = 0; k < 2; k++) {
        const bytes *b = &samples[k];
        check_prefixes_located(k ? "binary STL" : "ascii STL", b->data, b->size);
        for (size_t n = 0; n <= b->size; n++) {
            rsmooth_mesh *m = NULL;
            rsmooth_error err;
            rsmooth_status s = parse_n(b->data, n, RSMOOTH_FORMAT_STL_ASCII, &m, &err);
            if (s != RSMOOTH_OK && s != RSMOOTH_ERROR_PARSE) {
                fprintf(stderr, "prefix %zu of sample %d: status %d (%s)\n", n, k, (int)s,
                        err.message);
                exit(1);
            }
            /* What follows the ascii sample's "endsolid" is optional; a binary prefix is never
             * whole. */
            CHECK((s == RSMOOTH_OK) == (n == b->size || (k == 0 && n >= ascii_end)));
            if (s == RSMOOTH_OK)
                check_soup(m, 3, k == 0 ? 0 : 1e-6);
            rsmooth_mesh_destroy(m);
        }
        free(b->data);
    }
}

/* ---- writing */

static void test_round_trip(void) {
    /* ascii -> binary -> ascii: positions at float precision, the triangle count. */
    bytes b = ascii_sample();
    rsmooth_mesh *m = parse_ok(b.data, b.size, RSMOOTH_FORMAT_AUTO);
    bytes bin = {0};
    bin.data = mesh_to_memory(m, RSMOOTH_FORMAT_STL_BINARY, &bin.size);
    CHECK_EQ_INT(bin.size, 84 + 3 * 50);
    CHECK(memcmp(bin.data, "part one ", 9) == 0);
    rsmooth_mesh *m2 = parse_ok(bin.data, bin.size, RSMOOTH_FORMAT_AUTO);
    CHECK_EQ_INT(m2->precision, RSMOOTH_FLOAT32);
    check_soup(m2, 3, 1e-6);
    for (size_t i = 0; i < 9 * 3; i++)
        CHECK_NEAR(m2->positions[i], (double)(float)m->positions[i], 0);
    bytes text = {0};
    text.data = mesh_to_memory(m2, RSMOOTH_FORMAT_STL_ASCII, &text.size);
    CHECK(contains(&text, "solid part one\n"));
    rsmooth_mesh *m3 = parse_ok(text.data, text.size, RSMOOTH_FORMAT_AUTO);
    CHECK_EQ_INT(m3->triangle_count, 3);
    for (size_t i = 0; i < 9 * 3; i++)
        CHECK_NEAR(m3->positions[i], m2->positions[i], 0);
    rsmooth_mesh_destroy(m3);
    rsmooth_mesh_destroy(m2);
    bytes_free(&text);
    bytes_free(&bin);

    /* double data stays exact through ascii (%.17g). */
    m->positions[4] = 0.1;
    m->positions[5] = -1.0 / 3.0;
    text.data = mesh_to_memory(m, RSMOOTH_FORMAT_STL_ASCII, &text.size);
    m2 = parse_ok(text.data, text.size, RSMOOTH_FORMAT_AUTO);
    for (size_t i = 0; i < 9 * 3; i++)
        CHECK_NEAR(m2->positions[i], m->positions[i], 0);
    rsmooth_mesh_destroy(m2);
    bytes_free(&text);

    /* What cannot be written is refused before anything is. */
    rsmooth_error err;
    FILE *sink = fopen("/dev/null", "wb");
    CHECK(sink != NULL);
    m->positions[0] = 1e100; /* supported, but beyond float32 */
    CHECK_STATUS(rsmooth_mesh_write_stream(m, sink, RSMOOTH_FORMAT_STL_BINARY, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(err.message, "float32") != NULL);
    /* just beyond float32's largest, in digits that tell the two apart (%g printed 3.40282e+38) */
    m->positions[0] = 3.4028236e38;
    CHECK_STATUS(rsmooth_mesh_write_stream(m, sink, RSMOOTH_FORMAT_STL_BINARY, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(err.message, "vertex 0 has coordinate 3.4028236e+38 beyond the largest float32 "
                              "3.4028234663852886e+38") != NULL);
    CHECK(strstr(err.message, "; ascii STL, OBJ or a PLY with double can") != NULL);
    CHECK_STATUS(rsmooth_mesh_write_stream(m, sink, RSMOOTH_FORMAT_STL_ASCII, &err), RSMOOTH_OK);
    m->positions[0] = NAN;
    CHECK_STATUS(rsmooth_mesh_write_stream(m, sink, RSMOOTH_FORMAT_STL_ASCII, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    m->positions[0] = 0;
    m->triangles[7] = 9;
    CHECK_STATUS(rsmooth_mesh_write_stream(m, sink, RSMOOTH_FORMAT_STL_BINARY, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    m->triangles[7] = 7;
    size_t t = m->triangle_count;
    m->triangle_count = 0;
    CHECK_STATUS(rsmooth_mesh_write_stream(m, sink, RSMOOTH_FORMAT_STL_BINARY, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(err.message, "no triangles") != NULL);
    m->triangle_count = t;
    fclose(sink);
    rsmooth_mesh_destroy(m);
    bytes_free(&b);
}

/* An indexed mesh (a quad and a triangle sharing vertices, one degenerate triangle) is written as
 * a soup: 3 vertices per triangle. */
static void test_indexed(void) {
    rsmooth_mesh *m = NULL;
    rsmooth_error err;
    CHECK_STATUS(rsmooth_mesh_create(5, 3, 10, &m, &err), RSMOOTH_OK);
    const double xyz[5][3] = {{0, 0, 0}, {1.5, 0, 0}, {1.5, 1.25, 0}, {0, 1.25, -0.5}, {3, 0, 0}};
    memcpy(m->positions, xyz, sizeof xyz);
    const uint32_t offsets[4] = {0, 4, 7, 10};
    const uint32_t indices[10] = {0, 1, 2, 3, 0, 1, 4, 2, 2, 2};
    memcpy(m->face_offsets, offsets, sizeof offsets);
    memcpy(m->face_indices, indices, sizeof indices);
    CHECK_STATUS(rsmooth_mesh_triangulate(m, &err), RSMOOTH_OK);
    CHECK_EQ_INT(m->triangle_count, 4);
    for (int binary = 0; binary < 2; binary++) {
        bytes out = {0};
        out.data = mesh_to_memory(m, binary ? RSMOOTH_FORMAT_STL_BINARY : RSMOOTH_FORMAT_STL_ASCII,
                                  &out.size);
        rsmooth_mesh *s = parse_ok(out.data, out.size, RSMOOTH_FORMAT_AUTO);
        CHECK_EQ_INT(s->source_format,
                     binary ? RSMOOTH_FORMAT_STL_BINARY : RSMOOTH_FORMAT_STL_ASCII);
        CHECK_EQ_INT(s->triangle_count, 4);
        CHECK_EQ_INT(s->vertex_count, 12);
        for (size_t i = 0; i < 12; i++)
            for (int c = 0; c < 3; c++)
                CHECK_NEAR(s->positions[3 * i + c], xyz[m->triangles[i]][c], 0);
        if (binary) /* the degenerate triangle's normal is 0 0 0 */
            for (int k = 0; k < 3; k++)
                CHECK_NEAR(get_f32(out.data + 84 + 3 * 50 + 4 * k), 0, 0);
        else
            CHECK(contains(&out, "facet normal 0 0 0\n"));
        rsmooth_mesh_destroy(s);
        bytes_free(&out);
    }
    rsmooth_mesh_destroy(m);
}

/* ---- what the hostile-input campaign found */

static void test_write_refusals_and_extremes(void) {
    check_writer_refuses_unreadable(RSMOOTH_FORMAT_STL_ASCII);
    check_writer_refuses_unreadable(RSMOOTH_FORMAT_STL_BINARY);
    check_extremes_round_trip(RSMOOTH_FORMAT_STL_ASCII, RSMOOTH_FLOAT64);
    check_extremes_round_trip(RSMOOTH_FORMAT_STL_BINARY, RSMOOTH_FLOAT32);
    check_float32_scale(RSMOOTH_FORMAT_STL_ASCII);
    check_float32_scale(RSMOOTH_FORMAT_STL_BINARY);
    /* refused by the STL writer itself (no triangles, a value beyond float32): no file either */
    rsmooth_mesh *m = tetrahedron(RSMOOTH_FLOAT64);
    rsmooth_error err0;
    char path[] = "/tmp/rsmooth_test_stl_refused_XXXXXX";
    int fd = mkstemp(path);
    CHECK(fd >= 0);
    close(fd);
    remove(path);
    m->positions[4] = 1e100;
    CHECK_EQ_INT(rsmooth_mesh_write_file(m, path, RSMOOTH_FORMAT_STL_BINARY, NULL),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    CHECK(access(path, F_OK) != 0);
    m->positions[4] = 0;
    m->triangle_count = 0;
    CHECK_EQ_INT(rsmooth_mesh_write_file(m, path, RSMOOTH_FORMAT_STL_ASCII, NULL),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    CHECK(access(path, F_OK) != 0);
    rsmooth_mesh_destroy(m);
    /* the hostile-input campaign's reproducer: the OBJ tetrahedron at 1e-150, written as binary
     * STL, was four vertices at 0 0 0 with exit 0 */
    const char *tiny = "v 0 0 0\nv 1e-150 0 0\nv 0 1e-150 0\nv 0 0 1e-150\n"
                       "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
    m = parse_ok(tiny, strlen(tiny), RSMOOTH_FORMAT_AUTO);
    CHECK_EQ_INT(rsmooth_mesh_write_file(m, path, RSMOOTH_FORMAT_STL_BINARY, &err0),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    CHECK(access(path, F_OK) != 0);
    CHECK(strstr(err0.message,
                 "vertex 2: float32 rounds coordinate 1e-150 to 0, beyond its precision") != NULL);
    CHECK_EQ_INT(rsmooth_mesh_check_writable(m, RSMOOTH_FORMAT_STL_BINARY, &err0),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    CHECK_EQ_INT(rsmooth_mesh_check_writable(m, RSMOOTH_FORMAT_STL_ASCII, &err0), RSMOOTH_OK);
    CHECK_EQ_INT(rsmooth_mesh_write_file(m, path, RSMOOTH_FORMAT_STL_ASCII, &err0), RSMOOTH_OK);
    rsmooth_mesh *back = NULL;
    CHECK_EQ_INT(rsmooth_mesh_read_file(path, &back, &err0), RSMOOTH_OK);
    CHECK(back->positions[6] == 1e-150); /* facet 0's third corner: vertex 1 */
    rsmooth_mesh_destroy(back);
    remove(path);
    rsmooth_mesh_destroy(m);
    /* ascii beyond the supported magnitude: refused at its vertex line, in digits that tell the
     * value from the limit */
    rsmooth_error err = EXPECT_ASCII_ERROR(
        GOOD_FACET "facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 -1.0000001e150\n"
                   "vertex 0 1 0\nendloop\nendfacet\n",
        "facet 1 has coordinate -1.0000001e+150 beyond the supported magnitude 1e+150");
    CHECK_EQ_INT(err.line, 12);
    CHECK_EQ_INT(err.byte_offset,
                 strlen("solid t\n" GOOD_FACET "facet normal 0 0 1\nouter loop\nvertex 0 0 0\n"));
}

/* A binary STL whose size disagrees with its count, read through detection as the command does:
 * the sizes, the count's offset and where the data ends, whatever its header says. */
static void test_detected_sizes(void) {
    const char *headers[] = {"", "solid but binary", "exported by something"};
    for (size_t h = 0; h < sizeof headers / sizeof headers[0]; h++) {
        bytes b = binary_sample(headers[h], NULL);
        if (h == 0)
            memset(b.data, ' ', 80); /* a blank header: text, until the count's bytes */
        for (size_t cut = 1; cut <= 60; cut += 59) {
            size_t size = b.size - cut;
            rsmooth_error err = expect_parse_error(__LINE__, b.data, size, RSMOOTH_FORMAT_AUTO,
                                                   "84 + 50 × 3 = 234 bytes expected");
            char found[32];
            snprintf(found, sizeof found, "%zu found", size);
            CHECK(strstr(err.message, found) != NULL);
            CHECK_EQ_INT(err.byte_offset, size);
        }
        bytes_free(&b);
    }
}

/* A '#' comment line before "solid": detection takes the file for ascii STL (the first word past
 * blanks and comments), and the ascii reader refuses the comment at its line, saying why (it was
 * read as a binary STL of 540090488 triangles). Comments between facets likewise. */
static void test_comments(void) {
    const char *body = "solid t\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n"
                       "   vertex 1 0 0\n   vertex 0 1 0\n  endloop\n endfacet\nendsolid t\n";
    char text[512];
    snprintf(text, sizeof text, "# made by hand\n%s", body);
    const rsmooth_format formats[2] = {RSMOOTH_FORMAT_AUTO, RSMOOTH_FORMAT_STL_ASCII};
    for (int f = 0; f < 2; f++) {
        rsmooth_error err = expect_parse_error(__LINE__, text, strlen(text), formats[f],
                                               "a '#' comment where 'solid' was expected: ascii "
                                               "STL has no comments");
        CHECK_EQ_INT(err.line, 1);
        CHECK_EQ_INT(err.byte_offset, 0);
    }
    /* after blank lines and a byte-order mark: the comment's own line and byte */
    snprintf(text, sizeof text, "\xEF\xBB\xBF\n  \n  #made by hand\n%s", body);
    rsmooth_error err = expect_parse_error(__LINE__, text, strlen(text), RSMOOTH_FORMAT_AUTO,
                                           "ascii STL has no comments");
    CHECK_EQ_INT(err.line, 3);
    CHECK_EQ_INT(err.byte_offset, 3 + 6);
    /* between facets */
    err = EXPECT_ASCII_ERROR(GOOD_FACET "# a comment\n" GOOD_FACET,
                             "a '#' comment where 'facet' was expected: ascii STL has no comments");
    CHECK_EQ_INT(err.line, 9);
    /* without the comment the same text reads */
    rsmooth_mesh_destroy(parse_ok(body, strlen(body), RSMOOTH_FORMAT_AUTO));
}

static void test_byte_order_mark(void) {
    bytes plain = ascii_sample();
    bytes b = {0};
    put_text(&b, "\xEF\xBB\xBF");
    put(&b, plain.data, plain.size);
    for (int explicit_format = 0; explicit_format < 2; explicit_format++) {
        rsmooth_mesh *m = parse_ok(
            b.data, b.size, explicit_format ? RSMOOTH_FORMAT_STL_ASCII : RSMOOTH_FORMAT_AUTO);
        check_soup(m, 3, 0);
        rsmooth_mesh *p = parse_ok(plain.data, plain.size, RSMOOTH_FORMAT_AUTO);
        size_t size, plain_size;
        char *out = mesh_to_memory(m, RSMOOTH_FORMAT_STL_ASCII, &size);
        char *plain_out = mesh_to_memory(p, RSMOOTH_FORMAT_STL_ASCII, &plain_size);
        CHECK_EQ_INT(size, plain_size + 3);
        CHECK(memcmp(out, "\xEF\xBB\xBF", 3) == 0 && memcmp(out + 3, plain_out, plain_size) == 0);
        free(out);
        free(plain_out);
        /* binary STL has no text to mark: dropped, and said so */
        char losses[256];
        rsmooth_mesh_conversion_losses(m, RSMOOTH_FORMAT_STL_BINARY, losses, sizeof losses);
        CHECK(strstr(losses, "UTF-8 byte-order mark") != NULL);
        CHECK_EQ_INT(rsmooth_mesh_conversion_losses(p, RSMOOTH_FORMAT_STL_BINARY, NULL, 0), 0);
        out = mesh_to_memory(m, RSMOOTH_FORMAT_STL_BINARY, &size);
        CHECK(memcmp(out, "\xEF\xBB\xBF", 3) != 0);
        free(out);
        rsmooth_mesh_destroy(p);
        rsmooth_mesh_destroy(m);
    }
    bytes_free(&b);
    bytes_free(&plain);
}

int main(void) {
    test_ascii();
    test_binary();
    test_errors();
    test_truncated();
    test_round_trip();
    test_indexed();
    test_write_refusals_and_extremes();
    test_detected_sizes();
    test_byte_order_mark();
    test_comments();
    printf("stl io: ok\n");
    return 0;
}
