/* OFF reading and writing: the variants, errors and their lines, round trips, truncation. */
#define _POSIX_C_SOURCE 200809L
#include "rsmooth_io.h"
#include "test_io_util.h"

#include <stdbool.h>
#include <stdint.h>
#include <string.h>

/* Parses `size` bytes of `text` from a buffer of exactly that size (ASan catches any over-read). */
static rsmooth_status parse_n(const char *text, size_t size, rsmooth_format format,
                              rsmooth_mesh **mesh, rsmooth_error *err) {
    char *copy = malloc(size ? size : 1);
    CHECK(copy != NULL);
    memcpy(copy, text, size);
    rsmooth_status s = rsmooth_mesh_read_memory(copy, size, format, mesh, err);
    free(copy);
    return s;
}

static rsmooth_mesh *parse_size_ok(const char *text, size_t size) {
    rsmooth_mesh *mesh = NULL;
    rsmooth_error err;
    rsmooth_status s = parse_n(text, size, RSMOOTH_FORMAT_AUTO, &mesh, &err);
    if (s != RSMOOTH_OK)
        fprintf(stderr, "unexpected failure: %s (line %lld)\n", err.message, (long long)err.line);
    CHECK_EQ_INT(s, RSMOOTH_OK);
    CHECK(mesh != NULL);
    CHECK_EQ_INT(mesh->source_format, RSMOOTH_FORMAT_OFF);
    CHECK_EQ_INT(mesh->precision, RSMOOTH_FLOAT64);
    return mesh;
}

static rsmooth_mesh *parse_ok(const char *text) {
    return parse_size_ok(text, strlen(text));
}

/* Expects `status` at `line` (-1: any) with a message containing `needle`. */
#define EXPECT_ERROR(text, status, line, needle) expect_error(__LINE__, text, status, line, needle)
static rsmooth_error expect_error(int at, const char *text, rsmooth_status status, long long line,
                                  const char *needle) {
    rsmooth_mesh *mesh = (rsmooth_mesh *)&mesh; /* must be reset to NULL */
    rsmooth_error err;
    rsmooth_status s = parse_n(text, strlen(text), RSMOOTH_FORMAT_OFF, &mesh, &err);
    if (s != status || (line >= 0 && err.line != line) || !strstr(err.message, needle)) {
        fprintf(stderr,
                "test_off_io.c:%d: status %d line %lld message '%s'; expected status %d "
                "line %lld message with '%s'\n",
                at, (int)s, (long long)err.line, err.message, (int)status, line, needle);
        exit(1);
    }
    CHECK(mesh == NULL);
    CHECK_EQ_INT(err.status, status);
    return err;
}

static void check_color(const rsmooth_mesh *m, size_t v, int r, int g, int b) {
    CHECK(m->vertex_colors != NULL);
    CHECK_EQ_INT(m->vertex_colors[3 * v], r);
    CHECK_EQ_INT(m->vertex_colors[3 * v + 1], g);
    CHECK_EQ_INT(m->vertex_colors[3 * v + 2], b);
}

static void test_variants(void) {
    /* Plain OFF: comments and blank lines anywhere, a quad, a pentagon, comments after the faces.
     */
    rsmooth_mesh *m = parse_ok("OFF\n"
                               "# a comment\n"
                               "\n"
                               "5 3 0  # counts\n"
                               "0 0 0\n"
                               "1 0 0\n"
                               "  1 1 0\t\n"
                               "# between vertices\n"
                               "0 1 0\r\n"
                               "0.5 0.5 1e0\n"
                               "3 0 1 4\n"
                               "4 0 1 2 3\n"
                               "5 0 1 2 3 4\n"
                               "# the end\n\n");
    CHECK_EQ_INT(m->vertex_count, 5);
    CHECK_EQ_INT(m->face_count, 3);
    CHECK_NEAR(m->positions[14], 1, 0);
    check_face(m, 0, (const uint32_t[]){0, 1, 4}, 3);
    check_face(m, 1, (const uint32_t[]){0, 1, 2, 3}, 4);
    check_face(m, 2, (const uint32_t[]){0, 1, 2, 3, 4}, 5);
    CHECK_EQ_INT(m->triangle_count, 1 + 2 + 3);
    CHECK(m->vertex_colors == NULL && !m->has_vertex_normals && m->extras == NULL);
    rsmooth_mesh_destroy(m);

    /* Counts on the keyword's line, no edge count, no final newline. */
    m = parse_ok("OFF 3 1\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2");
    CHECK_EQ_INT(m->vertex_count, 3);
    CHECK_EQ_INT(m->face_count, 1);
    rsmooth_mesh_destroy(m);

    /* COFF with float colours (with and without alpha) and a face colour. */
    m = parse_ok("COFF\n3 1 0\n"
                 "0 0 0 1.0 0.5 0 1\n"
                 "1 0 0 0 0 1\n"
                 "0 1 0 0.2 0.4 0.6 0.5\n"
                 "3 0 1 2 1 0 0\n");
    check_color(m, 0, 255, 128, 0);
    check_color(m, 1, 0, 0, 255);
    check_color(m, 2, 51, 102, 153);
    CHECK(m->extras != NULL);
    char losses[256];
    CHECK_EQ_INT(
        rsmooth_mesh_conversion_losses(m, RSMOOTH_FORMAT_PLY_BINARY, losses, sizeof losses), 2);
    CHECK(strstr(losses, "OFF face colours") && strstr(losses, "OFF colour alpha"));
    CHECK_EQ_INT(rsmooth_mesh_conversion_losses(m, RSMOOTH_FORMAT_OFF, losses, sizeof losses), 0);
    rsmooth_mesh_destroy(m);

    /* Integer colours 0..255. */
    m = parse_ok("COFF\n3 1 0\n0 0 0 255 128 0 255\n1 0 0 0 0 1 255\n0 1 0 10 20 30 255\n"
                 "3 0 1 2\n");
    check_color(m, 0, 255, 128, 0);
    check_color(m, 1, 0, 0, 1);
    check_color(m, 2, 10, 20, 30);
    rsmooth_mesh_destroy(m);

    /* NOFF: normals read (and recomputed on output), not kept. */
    m = parse_ok("NOFF\n3 1 0\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n");
    CHECK(m->has_vertex_normals && m->vertex_colors == NULL);
    CHECK_NEAR(m->positions[3], 1, 0);
    rsmooth_mesh_destroy(m);

    /* CNOFF: position, normal, colour. */
    m = parse_ok("CNOFF\n3 1 0\n0 0 0 0 0 1 255 0 0 255\n1 0 0 0 0 1 0 255 0 255\n"
                 "0 1 0 0 0 1 0 0 255 255\n3 0 1 2\n");
    CHECK(m->has_vertex_normals);
    check_color(m, 1, 0, 255, 0);
    CHECK_NEAR(m->positions[4], 0, 0);
    rsmooth_mesh_destroy(m);

    /* STOFF and STCOFF: texture coordinates last. */
    m = parse_ok("STOFF\n3 1 0\n0 0 0 0.25 0.75\n1 0 0 1 0\n0 1 0 0 1\n3 0 1 2\n");
    CHECK(m->vertex_colors == NULL && m->extras != NULL);
    CHECK_EQ_INT(rsmooth_mesh_conversion_losses(m, RSMOOTH_FORMAT_OBJ, losses, sizeof losses), 1);
    CHECK(strstr(losses, "OFF texture coordinates") != NULL);
    rsmooth_mesh_destroy(m);
    m = parse_ok("STCOFF 3 1 0\n0 0 0 1 0 0 0.25 0.75\n1 0 0 0 1 0 1 0\n0 1 0 0 0 1 0 1\n"
                 "3 0 1 2\n");
    check_color(m, 1, 0, 255, 0);
    rsmooth_mesh_destroy(m);
}

/* Same counts, faces and positions (bit for bit). */
static void check_same_geometry(const rsmooth_mesh *a, const rsmooth_mesh *b) {
    CHECK_EQ_INT(a->vertex_count, b->vertex_count);
    CHECK_EQ_INT(a->face_count, b->face_count);
    CHECK(memcmp(a->positions, b->positions, 3 * a->vertex_count * sizeof(double)) == 0);
    CHECK(memcmp(a->face_offsets, b->face_offsets, (a->face_count + 1) * sizeof(uint32_t)) == 0);
    CHECK(memcmp(a->face_indices, b->face_indices,
                 a->face_offsets[a->face_count] * sizeof(uint32_t)) == 0);
}

static const char rich_off[] = "STCNOFF\n"
                               "# colours, normals and texture coordinates\n"
                               "5 3 9\n"
                               "0 0 0  0 0 1  1.0 0.5 0 0.25  0 0\n"
                               "1 0 0  0 0 1  0 1 0 1  1 0\n"
                               "1 1 0  0 0 1  0 0 1 1  1 1\n"
                               "0 1 0  0 0 1  0.5 0.5 0.5 1  0 1\n"
                               "0.5 0.5 1  0 0 1  1 1 1 1  0.5 0.5\n"
                               "4 0 1 2 3  0.9 0.1 0.1 1\n"
                               "3 0 1 4  7\n"
                               "3 2 3 4\n";

static void test_round_trips(void) {
    rsmooth_mesh *m = parse_ok(rich_off);
    CHECK(m->has_vertex_normals && m->extras != NULL);
    check_color(m, 0, 255, 128, 0);
    for (size_t i = 0; i < 3 * m->vertex_count; i++)
        m->positions[i] += (double)(i + 1) / 7.0;
    rsmooth_error err;
    CHECK_EQ_INT(rsmooth_mesh_triangulate(m, &err), RSMOOTH_OK);

    /* Faithful: keyword, vertex extras and face colours verbatim, normals recomputed. */
    size_t size;
    char *out = mesh_to_memory(m, RSMOOTH_FORMAT_OFF, &size);
    CHECK(strncmp(out, "STCNOFF\n5 3 9\n", 14) == 0);
    CHECK(strstr(out, " 1.0 0.5 0 0.25  0 0\n") != NULL);
    CHECK(strstr(out, "\n4 0 1 2 3 0.9 0.1 0.1 1\n") != NULL);
    CHECK(strstr(out, "\n3 0 1 4 7\n") != NULL);
    CHECK(strstr(out, "\n3 2 3 4\n") != NULL);
    rsmooth_mesh *back = parse_size_ok(out, size);
    check_same_geometry(m, back);
    CHECK(memcmp(m->vertex_colors, back->vertex_colors, 3 * m->vertex_count) == 0);
    double normals[15], read_normals[15];
    CHECK_EQ_INT(rsmooth_mesh_vertex_normals(m, normals, &err), RSMOOTH_OK);
    /* the normals on the written lines are the recomputed ones */
    const char *line = strchr(strchr(out, '\n') + 1, '\n') + 1;
    for (size_t v = 0; v < 5; v++) {
        double x, y, z;
        CHECK_EQ_INT(sscanf(line, "%lf %lf %lf %lf %lf %lf", &x, &y, &z, &read_normals[3 * v],
                            &read_normals[3 * v + 1], &read_normals[3 * v + 2]),
                     6);
        line = strchr(line, '\n') + 1;
    }
    for (int i = 0; i < 15; i++)
        CHECK_NEAR(read_normals[i], normals[i], 1e-8);
    /* Writing what was read back gives the same bytes. */
    size_t size2;
    char *out2 = mesh_to_memory(back, RSMOOTH_FORMAT_OFF, &size2);
    CHECK(size == size2 && memcmp(out, out2, size) == 0);
    free(out2);
    rsmooth_mesh_destroy(back);
    free(out);

    /* Generic: CNOFF with integer colours, "nv nf 0", then positions, normals, colours. */
    struct rsmooth_mesh_extras *extras = m->extras;
    m->extras = NULL;
    out = mesh_to_memory(m, RSMOOTH_FORMAT_OFF, &size);
    m->extras = extras;
    CHECK(strncmp(out, "CNOFF\n5 3 0\n", 12) == 0);
    CHECK(strstr(out, " 255 128 0 255\n") != NULL);
    CHECK(strstr(out, "\n4 0 1 2 3\n3 0 1 4\n3 2 3 4\n") != NULL);
    back = parse_size_ok(out, size);
    check_same_geometry(m, back);
    CHECK(memcmp(m->vertex_colors, back->vertex_colors, 3 * m->vertex_count) == 0);
    CHECK(back->has_vertex_normals);
    rsmooth_mesh_destroy(back);
    free(out);

    /* A changed count falls back to the generic writer. */
    m->face_count--;
    out = mesh_to_memory(m, RSMOOTH_FORMAT_OFF, &size);
    m->face_count++;
    CHECK(strncmp(out, "CNOFF\n5 2 0\n", 12) == 0);
    free(out);

    /* Plain OFF with no colours or normals; and OBJ -> OFF -> OBJ keeps the geometry. */
    free(m->vertex_colors);
    m->vertex_colors = NULL;
    m->has_vertex_normals = 0;
    m->extras = NULL;
    out = mesh_to_memory(m, RSMOOTH_FORMAT_OFF, &size);
    m->extras = extras;
    CHECK(strncmp(out, "OFF\n5 3 0\n", 10) == 0);
    back = parse_size_ok(out, size);
    check_same_geometry(m, back);
    CHECK(back->extras == NULL);
    rsmooth_mesh_destroy(back);
    free(out);
    rsmooth_mesh_destroy(m);

    rsmooth_mesh *obj = NULL;
    const char *obj_text = "v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0 0 0 1\nvn 0 0 1\nf 1 2 3\n";
    CHECK_EQ_INT(parse_n(obj_text, strlen(obj_text), RSMOOTH_FORMAT_OBJ, &obj, &err), RSMOOTH_OK);
    out = mesh_to_memory(obj, RSMOOTH_FORMAT_OFF, &size);
    CHECK(strncmp(out, "CNOFF\n3 1 0\n", 12) == 0);
    back = parse_size_ok(out, size);
    check_same_geometry(obj, back);
    CHECK(memcmp(obj->vertex_colors, back->vertex_colors, 9) == 0);
    rsmooth_mesh_destroy(back);
    rsmooth_mesh_destroy(obj);
    free(out);
}

static void test_errors(void) {
    const rsmooth_status P = RSMOOTH_ERROR_PARSE, U = RSMOOTH_ERROR_UNSUPPORTED;
    /* wrong or missing header */
    EXPECT_ERROR("", P, 1, "missing OFF header");
    EXPECT_ERROR("# just a comment\n", P, 2, "missing OFF header");
    EXPECT_ERROR("PLY\n3 1 0\n", P, 1, "missing OFF header");
    EXPECT_ERROR("OFFX\n3 1 0\n", P, 1, "'OFFX'");
    EXPECT_ERROR("CSTOFF\n3 1 0\n", P, 1, "missing OFF header");
    EXPECT_ERROR("OFF\n", P, 2, "ends before the vertex and face counts");
    EXPECT_ERROR("OFF\n3\n", P, 2, "expected the vertex and face counts");
    EXPECT_ERROR("OFF\n3 x 0\n", P, 2, "malformed count 'x'");
    EXPECT_ERROR("OFF\n3 -1 0\n", P, 2, "malformed count '-1'");
    EXPECT_ERROR("OFF\n3 1 0 7\n", P, 2, "unexpected '7'");
    EXPECT_ERROR("4OFF\n3 1 0\n", U, -1, "4-dimensional");
    EXPECT_ERROR("nOFF\n4\n3 1 0\n", U, -1, "n-dimensional");
    EXPECT_ERROR("C4nOFF\n", U, -1, "not supported");
    EXPECT_ERROR("OFF BINARY\n", U, -1, "binary OFF");
    /* an empty mesh; counts larger than the data; huge counts refused before allocating */
    EXPECT_ERROR("OFF\n0 0 0\n", P, 2, "no vertices");
    EXPECT_ERROR("OFF\n3 1 0\n0 0 0\n1 0 0\n", P, 2, "more than the remaining 12 bytes");
    /* (comments pad the files past that check) */
    EXPECT_ERROR("OFF\n3 1 0\n0 0 0\n1 0 0\n# padding padding\n", P, 6, "after 2 of 3 vertices");
    EXPECT_ERROR("OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2\n# padding\n", P, 9,
                 "after 1 of 2 faces");
    EXPECT_ERROR("OFF\n4000000000 1 0\n0 0 0\n", P, 2, "more than the remaining");
    EXPECT_ERROR("OFF 18446744073709551615 18446744073709551615 0\n0 0 0\n", P, 1,
                 "more than the remaining");
    EXPECT_ERROR("OFF\n3 99999999999 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", P, 2,
                 "more than the remaining");
    /* vertex lines */
    EXPECT_ERROR("OFF\n3 1 0\n0 0 0\n1 0\n0 1 0\n3 0 1 2\n# pad\n", P, 4, "vertex 1 has 2 values");
    EXPECT_ERROR("COFF\n3 1 0\n0 0 0 1 1 1\n1 0 0 1 1\n0 1 0 1 1 1\n3 0 1 2\n# pad\n", P, 4,
                 "vertex 1 has 5 values (COFF declares 6 or 7: x y z r g b [a])");
    EXPECT_ERROR("OFF\n3 1 0\n0 0 0\n1 0 x\n0 1 0\n3 0 1 2\n# pad\n", P, 4, "malformed number 'x'");
    EXPECT_ERROR("OFF\n3 1 0\n0 0 0\n1 0 0\n0 nan 0\n3 0 1 2\n# pad\n", P, 5,
                 "vertex 2 has a non-finite coordinate");
    EXPECT_ERROR("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 -inf\n3 0 1 2\n# pad\n", P, 5,
                 "vertex 2 has a non-finite coordinate");
    EXPECT_ERROR("OFF\n3 1 0\n0 0 0\n1 1e999 0\n0 1 0\n3 0 1 2\n# pad\n", P, 4,
                 "vertex 1 has a non-finite coordinate");
    /* face lines */
    const char *head = "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    struct {
        const char *face;
        const char *needle;
    } faces[] = {
        {"2 0 1\n", "face 1 has 2 vertices (at least 3 needed)"},
        {"0\n", "face 1 has 0 vertices"},
        {"-3 0 1 2\n", "face 1 has -3 vertices"},
        {"3 0 1 3\n", "face 1: index 3 out of range (3 vertices)"},
        {"3 0 -1 2\n", "face 1: index -1 out of range"},
        {"3 0 1 99999999999999999999\n", "out of range"},
        {"4 0 1 2\n", "face 1 lists 3 of its 4 vertices"},
        {"3 0 1.5 2\n", "face 1: malformed index '1.5'"},
        {"x 0 1 2\n", "face 1: malformed vertex count 'x'"},
    };
    for (size_t i = 0; i < sizeof faces / sizeof faces[0]; i++) {
        char text[256];
        snprintf(text, sizeof text, "%s%s# pad\n", head, faces[i].face);
        expect_error(__LINE__, text, P, 7, faces[i].needle);
    }

    /* The byte offset points at the offending token; a NULL error pointer is fine. */
    const char *text = "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n";
    rsmooth_mesh *mesh = NULL;
    rsmooth_error err;
    CHECK_EQ_INT(parse_n(text, strlen(text), RSMOOTH_FORMAT_OFF, &mesh, &err), P);
    CHECK_EQ_INT(err.byte_offset, strstr(text, "7\n") - text);
    CHECK_EQ_INT(parse_n(text, strlen(text), RSMOOTH_FORMAT_OFF, &mesh, NULL), P);
    CHECK(mesh == NULL);
}

static const char small_off[] = "COFF\n"
                                "# a comment\r\n"
                                "4 2 5\n"
                                "0 0 0 255 0 0 255\n"
                                "1.25 0 0 0 255 0 255\n"
                                "1 1 -0.5 0 0 255 255\n"
                                "0 1 0 9 9 9 255 \n"
                                "4 0 1 2 3 1 0 0\n"
                                "3 0 2 3\n";

static void test_truncated_prefixes(void) {
    size_t n = strlen(small_off);
    rsmooth_mesh *full = parse_size_ok(small_off, n);
    rsmooth_mesh_destroy(full);
    size_t ok_count = 0;
    for (size_t len = 0; len < n; len++) {
        rsmooth_mesh *m = NULL;
        rsmooth_error err;
        rsmooth_status s = parse_n(small_off, len, RSMOOTH_FORMAT_OFF, &m, &err);
        if (s != RSMOOTH_OK && s != RSMOOTH_ERROR_PARSE) {
            fprintf(stderr, "test_off_io.c:%d: prefix %zu: status %d\n", __LINE__, len, (int)s);
            exit(1);
        }
        CHECK((s == RSMOOTH_OK) == (m != NULL));
        if (s != RSMOOTH_OK)
            CHECK(err.line >= 1 && err.message[0] != '\0');
        ok_count += s == RSMOOTH_OK;
        rsmooth_mesh_destroy(m);
    }
    /* Only prefixes cut inside the last face's last index or its line end can still parse. */
    CHECK(ok_count <= 2);
    /* Read as the command reads it (detection first): every failure located too. */
    check_prefixes_located("OFF", small_off, n);
}

static uint32_t lcg_state = 777;
static uint32_t lcg(void) {
    lcg_state = lcg_state * 1664525u + 1013904223u;
    return lcg_state >> 8;
}

static void test_garbage(void) {
    static const char *const words[] = {"OFF", "COFF", "NOFF", "3",   "0",    "1",          "2",
                                        "-1",  "4",    "#",    "nan", "\n",   " ",          "\t",
                                        "0.5", "255",  "1e9",  "x",   "\r\n", "99999999999"};
    for (int round = 0; round < 4000; round++) {
        size_t len = lcg() % 300;
        char *buf = malloc(len ? len : 1);
        CHECK(buf != NULL);
        size_t i = 0;
        if (round % 3 == 0) {
            for (; i < len; i++)
                buf[i] = (char)(lcg() & 0xff);
        } else { /* a valid header then plausible tokens reaches the vertex and face parsers */
            const char *start = round % 3 == 1 ? "OFF\n" : "CNOFF 4 3 0\n";
            for (size_t j = 0; start[j] && i < len; j++)
                buf[i++] = start[j];
            while (i < len) {
                const char *w = words[lcg() % (sizeof words / sizeof words[0])];
                for (size_t j = 0; w[j] && i < len; j++)
                    buf[i++] = w[j];
                if (i < len)
                    buf[i++] = lcg() % 4 ? ' ' : '\n';
            }
        }
        rsmooth_mesh *m = NULL;
        rsmooth_error err;
        rsmooth_status s = rsmooth_mesh_read_memory(buf, len, RSMOOTH_FORMAT_OFF, &m, &err);
        CHECK(s == RSMOOTH_OK || s == RSMOOTH_ERROR_PARSE || s == RSMOOTH_ERROR_UNSUPPORTED);
        if (s == RSMOOTH_OK) {
            CHECK(m->vertex_count > 0);
            for (size_t t = 0; t < 3 * m->triangle_count; t++)
                CHECK(m->triangles[t] < m->vertex_count);
        }
        rsmooth_mesh_destroy(m);
        free(buf);
    }
}

/* Expects automatic detection to fail with `status` at `line` holding `needle`. */
static void expect_auto_error(int at, const char *text, rsmooth_status status, long long line,
                              const char *needle) {
    rsmooth_mesh *m = NULL;
    rsmooth_error err;
    rsmooth_status s = parse_n(text, strlen(text), RSMOOTH_FORMAT_AUTO, &m, &err);
    if (s != status || err.line != line || err.byte_offset < 0 || !strstr(err.message, needle)) {
        fprintf(stderr,
                "test_off_io.c:%d: status %d line %lld byte %lld '%s'; expected %d, %lld, "
                "'%s'\n",
                at, (int)s, (long long)err.line, (long long)err.byte_offset, err.message,
                (int)status, line, needle);
        exit(1);
    }
    CHECK(m == NULL);
}

static void test_detection(void) {
    /* AUTO reads OFF by its keyword; the extension picks it for writing. */
    rsmooth_mesh *m = parse_ok("NOFF 3 1 0\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n");
    rsmooth_mesh_destroy(m);
    CHECK_EQ_INT(rsmooth_format_from_path("a.off"), RSMOOTH_FORMAT_OFF);

    /* What may come before the keyword, and its lowercase spelling: read as the same mesh. */
    static const char body[] = "3 1 0\n0 0 0\n1 0 0\n0 1 0.5\n3 0 1 2\n";
    static const char *const openings[] = {
        "# made by hand\nOFF\n", "\nOFF\n", "  \tOFF\n", "off\n", "# c\n\n  off\n",
        "\xEF\xBB\xBF# c\nOFF\n"};
    char text[256];
    snprintf(text, sizeof text, "OFF\n%s", body);
    rsmooth_mesh *reference = parse_ok(text);
    for (size_t i = 0; i < sizeof openings / sizeof openings[0]; i++) {
        snprintf(text, sizeof text, "%s%s", openings[i], body);
        m = parse_ok(text);
        check_same_geometry(m, reference);
        rsmooth_mesh_destroy(m);
    }
    rsmooth_mesh_destroy(reference);

    /* Variants this reader does not read: "not supported", with their line and byte. */
    expect_auto_error(__LINE__, "# c\n4OFF\n3 1 0\n", RSMOOTH_ERROR_UNSUPPORTED, 2,
                      "4OFF: 4-dimensional vertices are not supported");
    expect_auto_error(__LINE__, "nOFF\n4\n3 1 0\n", RSMOOTH_ERROR_UNSUPPORTED, 1,
                      "n-dimensional vertices are not supported");
    expect_auto_error(__LINE__, "OFF BINARY\n", RSMOOTH_ERROR_UNSUPPORTED, 1,
                      "binary OFF is not supported");
    expect_auto_error(__LINE__, "XOFF\n3 1 0\n", RSMOOTH_ERROR_PARSE, 1,
                      "the file starts with 'XOFF'");
}

static void test_write_refusals_and_extremes(void) {
    check_writer_refuses_unreadable(RSMOOTH_FORMAT_OFF);
    check_extremes_round_trip(RSMOOTH_FORMAT_OFF, RSMOOTH_FLOAT64);
    check_float32_scale(RSMOOTH_FORMAT_OFF);

    /* Coordinates beyond the supported magnitude and non-finite normals: refused where they are. */
    EXPECT_ERROR("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1e151 0\n3 0 1 2\n", RSMOOTH_ERROR_PARSE, 5,
                 "vertex 2 has coordinate 1e+151 beyond the supported magnitude 1e+150");
    EXPECT_ERROR("NOFF\n3 1 0\n0 0 0 0 0 1\n1 0 0 inf 0 1\n0 1 0 0 0 1\n3 0 1 2\n",
                 RSMOOTH_ERROR_PARSE, 4, "vertex 1 has a non-finite normal");
    EXPECT_ERROR("COFF\n3 1 0\n0 0 0 1 0 0\n1 0 0 0 1 0\n0 1 0 0 -inf 1\n3 0 1 2\n",
                 RSMOOTH_ERROR_PARSE, 5, "vertex 2 has a non-finite colour");

    /* A point cloud's own normals (NOFF, no faces) are written exactly. */
    rsmooth_mesh *m = parse_ok("NOFF\n2 0 0\n0 0 0 0.1 0.2 0.97467943448089633\n"
                               "1 0 0 0.3333333333333333 0 -0.94280904158206336\n");
    CHECK(m->vertex_normals != NULL);
    size_t size;
    char *text = mesh_to_memory(m, RSMOOTH_FORMAT_OFF, &size);
    rsmooth_mesh *back = parse_size_ok(text, size);
    CHECK(back->vertex_normals != NULL);
    CHECK(memcmp(back->vertex_normals, m->vertex_normals, 6 * sizeof(double)) == 0);
    rsmooth_mesh_destroy(back);
    free(text);
    rsmooth_mesh_destroy(m);
}

/* A line holds exactly the values its variant declares (the hostile-input campaign: '0 1 0 7' read
 * as 0 1 0 and written back with its ' 7'; a stray CR running two COFF lines together): refused at
 * the first value too many, or at the line when too few; face colours are a colormap index or r g b
 * [a]; nothing but comments after the declared faces. */
static void test_values_per_line(void) {
    const rsmooth_status P = RSMOOTH_ERROR_PARSE;
    struct {
        const char *keyword, *line, *needle;
    } vertices[] = {
        {"OFF", "0 1 0 7", "vertex 1 has 4 values (OFF declares 3: x y z)"},
        {"NOFF", "0 1 0 0 0 1 7", "vertex 1 has 7 values (NOFF declares 6: x y z nx ny nz)"},
        {"COFF", "0 1 -0.0\r54441 3 125 115 255",
         "vertex 1 has 8 values (COFF declares 6 or 7: x y z r g b [a])"},
        {"COFF", "0 1 0 1 1", "vertex 1 has 5 values (COFF declares 6 or 7"},
        {"CNOFF", "0 1 0 0 0 1 1 1 1 1 1", "vertex 1 has 11 values (CNOFF declares 9 or 10"},
        {"STOFF", "0 1 0 0.5", "vertex 1 has 4 values (STOFF declares 5: x y z s t)"},
        {"STCNOFF", "0 1 0 0 0 1 1 1 1 1 0 0 0",
         "vertex 1 has more than 12 values (STCNOFF declares 11 or 12: x y z nx ny nz r g b [a] "
         "s t)"},
        {"COFF", "0 1 0 256 0 0", "vertex 1: colour component '256' outside 0 to 255"},
        {"COFF", "0 1 0 1 -0.5 0 1", "vertex 1: colour component '-0.5' outside 0 to 255"},
        {"STOFF", "0 1 0 0.5 nan", "vertex 1 has a non-finite texture coordinate"},
    };
    const char *good[] = {"OFF",   "0 0 0",       "NOFF",    "0 0 0 0 0 1",
                          "COFF",  "0 0 0 1 0 0", "CNOFF",   "0 0 0 0 0 1 1 0 0 1",
                          "STOFF", "0 0 0 0 0",   "STCNOFF", "0 0 0 0 0 1 1 1 1 1 0 0"};
    for (size_t i = 0; i < sizeof vertices / sizeof vertices[0]; i++) {
        const char *first = NULL;
        for (size_t g = 0; g < sizeof good / sizeof good[0]; g += 2)
            if (!strcmp(good[g], vertices[i].keyword))
                first = good[g + 1];
        CHECK(first != NULL);
        char text[512];
        snprintf(text, sizeof text, "%s\n3 1 0\n%s\n%s\n%s\n3 0 1 2\n", vertices[i].keyword, first,
                 vertices[i].line, first);
        rsmooth_error err = expect_error(__LINE__, text, P, 4, vertices[i].needle);
        /* too many: at the first value too many; else within the line */
        const char *line = strstr(text, vertices[i].line);
        CHECK(err.byte_offset >= line - text &&
              err.byte_offset < line - text + (long long)strlen(vertices[i].line));
        if (i == 0)
            CHECK_EQ_INT(err.byte_offset, line - text + 6);
        if (i == 1)
            CHECK_EQ_INT(err.byte_offset, line - text + 12);
        /* the same line is good with the values its keyword declares */
        snprintf(text, sizeof text, "%s\n3 1 0\n%s\n%s\n%s\n3 0 1 2\n", vertices[i].keyword, first,
                 first, first);
        rsmooth_mesh_destroy(parse_ok(text));
    }

    /* Face lines: the indices, then nothing, a colormap index, or a colour of 3 or 4 components. */
    const char *head = "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n";
    const char *faces_ok[] = {"3 0 1 2", "3 0 1 2 7", "3 0 1 2 1 0 0", "3 0 1 2 0.5 0.5 0.5 1",
                              "3 0 1 2 255 0 0 255"};
    for (size_t i = 0; i < sizeof faces_ok / sizeof faces_ok[0]; i++) {
        char text[256];
        snprintf(text, sizeof text, "%s%s\n", head, faces_ok[i]);
        rsmooth_mesh *m = parse_ok(text);
        /* and written back as read */
        size_t size;
        char *out = mesh_to_memory(m, RSMOOTH_FORMAT_OFF, &size);
        CHECK(strstr(out, faces_ok[i]) != NULL);
        free(out);
        rsmooth_mesh_destroy(m);
    }
    struct {
        const char *face, *needle;
    } faces_bad[] = {
        {"3 0 1 2 1 0", "face 0 has 2 values after its indices (a face colour is a colormap "
                        "index, or r g b [a])"},
        {"3 0 1 2 1 0 0 1 1", "face 0 has 5 values after its indices"},
        {"3 0 1 2 0.5", "face 0: colormap index '0.5' is not a whole number >= 0"},
        {"3 0 1 2 -1", "face 0: colormap index '-1'"},
        {"3 0 1 2 300 0 0", "face 0: colour component '300' outside 0 to 255"},
        {"3 0 1 2 1 x 0", "face 0: malformed colour 'x'"},
        {"3 0 1 2 1 inf 0", "face 0 has a non-finite colour"},
    };
    for (size_t i = 0; i < sizeof faces_bad / sizeof faces_bad[0]; i++) {
        char text[256];
        snprintf(text, sizeof text, "%s%s\n", head, faces_bad[i].face);
        expect_error(__LINE__, text, P, 6, faces_bad[i].needle);
    }

    /* After the declared faces: comments and blanks, nothing else (it was ignored). */
    rsmooth_mesh_destroy(parse_ok("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n\n# end\n  \n"));
    const char *more = "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n# c\n3 0 2 1\n";
    rsmooth_error err = expect_error(__LINE__, more, P, 8,
                                     "'3' after the 3 vertices and 1 faces the header declares");
    CHECK_EQ_INT(err.byte_offset, strstr(more, "3 0 2 1") - more);
    expect_error(__LINE__, "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\nextra trailing data\n", P, 7,
                 "'extra' after the 3 vertices");
}

static void test_byte_order_mark(void) {
    static const char colored[] = "COFF\n3 1 0\n0 0 0 1 0 0 1\n1 0 0 0 1 0 1\n"
                                  "0 1 0 0 0 1 1\n3 0 1 2 0.5 0.5 0.5\n";
    char marked[sizeof colored + 3] = "\xEF\xBB\xBF";
    memcpy(marked + 3, colored, sizeof colored);
    rsmooth_mesh *m = parse_ok(marked);
    rsmooth_mesh *plain = parse_ok(colored);
    check_same_geometry(m, plain);
    size_t size, plain_size;
    char *out = mesh_to_memory(m, RSMOOTH_FORMAT_OFF, &size);
    char *plain_out = mesh_to_memory(plain, RSMOOTH_FORMAT_OFF, &plain_size);
    CHECK_EQ_INT(size, plain_size + 3);
    CHECK(memcmp(out, "\xEF\xBB\xBF", 3) == 0 && memcmp(out + 3, plain_out, plain_size) == 0);
    char losses[256];
    rsmooth_mesh_conversion_losses(m, RSMOOTH_FORMAT_STL_ASCII, losses, sizeof losses);
    CHECK(strstr(losses, "UTF-8 byte-order mark") != NULL);
    CHECK_EQ_INT(rsmooth_mesh_conversion_losses(m, RSMOOTH_FORMAT_OFF, NULL, 0), 0);
    free(out);
    free(plain_out);
    rsmooth_mesh_destroy(plain);
    rsmooth_mesh_destroy(m);
    /* explicitly as OFF too, with errors located in the file's bytes */
    const char *bad = "\xEF\xBB\xBFOFF\n3 1 0\n0 0 0\n1 y 0\n0 1 0\n3 0 1 2\n";
    m = NULL;
    rsmooth_error err;
    CHECK_EQ_INT(parse_n(bad, strlen(bad), RSMOOTH_FORMAT_OFF, &m, &err), RSMOOTH_ERROR_PARSE);
    CHECK_EQ_INT(err.line, 4);
    CHECK_EQ_INT(err.byte_offset, strchr(bad, 'y') - bad);
}

int main(void) {
    test_variants();
    test_round_trips();
    test_errors();
    test_truncated_prefixes();
    test_garbage();
    test_detection();
    test_write_refusals_and_extremes();
    test_byte_order_mark();
    test_values_per_line();
    printf("off_io: all checks passed\n");
    return 0;
}
