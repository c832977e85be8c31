/* OBJ reading and writing: index forms, errors and their lines, round trips, truncation. */
#define _POSIX_C_SOURCE 200809L
#include "rsmooth_io.h"
#include "test_io_util.h"

#include <stdbool.h>
#include <stdint.h>
#include <string.h>
#include <unistd.h>

/* Parses `size` bytes of `text` from a buffer of exactly that size (ASan catches any over-read). */
static rsmooth_status parse_n(const char *text, size_t size, rsmooth_mesh **mesh,
                              rsmooth_error *err) {
    char *copy = malloc(size ? size : 1);
    CHECK(copy != NULL);
    memcpy(copy, text, size);
    rsmooth_status s = rsmooth_mesh_read_memory(copy, size, RSMOOTH_FORMAT_OBJ, mesh, err);
    free(copy);
    return s;
}

static rsmooth_mesh *parse_ok(const char *text) {
    rsmooth_mesh *mesh = NULL;
    rsmooth_error err;
    rsmooth_status s = parse_n(text, strlen(text), &mesh, &err);
    if (s != RSMOOTH_OK)
        fprintf(stderr, "unexpected failure: %s (line %lld)\n", err.message, (long long)err.line);
    CHECK_EQ_INT(s, RSMOOTH_OK);
    CHECK(mesh != NULL);
    CHECK_EQ_INT(mesh->source_format, RSMOOTH_FORMAT_OBJ);
    CHECK_EQ_INT(mesh->precision, RSMOOTH_FLOAT64);
    return mesh;
}

static rsmooth_mesh *parse_n_ok(const char *text, size_t size) {
    rsmooth_mesh *mesh = NULL;
    rsmooth_error err;
    rsmooth_status s = parse_n(text, size, &mesh, &err);
    if (s != RSMOOTH_OK)
        fprintf(stderr, "unexpected failure: %s (line %lld)\n", err.message, (long long)err.line);
    CHECK_EQ_INT(s, RSMOOTH_OK);
    return mesh;
}

/* Expects a parse error at `line` whose message contains `needle`. */
#define EXPECT_PARSE_ERROR(text, line, needle) expect_parse_error(__LINE__, text, line, needle)
static void expect_parse_error(int at, const char *text, long long line, const char *needle) {
    rsmooth_mesh *mesh = (rsmooth_mesh *)&mesh; /* must be reset to NULL */
    rsmooth_error err;
    rsmooth_status s = parse_n(text, strlen(text), &mesh, &err);
    if (s != RSMOOTH_ERROR_PARSE || err.line != line || !strstr(err.message, needle)) {
        fprintf(stderr,
                "test_obj_io.c:%d: status %d line %lld message '%s'; expected status %d "
                "line %lld message with '%s'\n",
                at, (int)s, (long long)err.line, err.message, (int)RSMOOTH_ERROR_PARSE, line,
                needle);
        exit(1);
    }
    CHECK(mesh == NULL);
    CHECK_EQ_INT(err.status, RSMOOTH_ERROR_PARSE);
}

static void test_index_forms(void) {
    const char *text = "# a comment\n"
                       "mtllib things.mtl\n"
                       "o thing\n"
                       "g group one\n"
                       "\n"
                       "v 0 0 0\n"
                       "v 1.5 -2 3e2\n"
                       "   v\t1 1 0   \n"
                       "v 0 1 0 1.0\n"        /* w */
                       "v 2 2 2 0.5 0.25 1\n" /* r g b */
                       "vt 0 0\n"
                       "vn 0 0 1\n"
                       "usemtl stone\n"
                       "s off\n"
                       "f 1 2 3\n"
                       "f 1/1 3/1 4/1\n"
                       "f 1//1 2//1 4//1 # trailing comment\n"
                       "f 1/1/1 2/1/1 3/1/1 4/1/1\n"
                       "f -5 -4 -1\n"
                       "l 1 2\n"
                       "p 1\n"
                       "unknownstatement 1 2 3\n"
                       "f 5 4 3"; /* no final newline */
    rsmooth_mesh *m = parse_ok(text);
    CHECK_EQ_INT(m->vertex_count, 5);
    CHECK_NEAR(m->positions[3], 1.5, 0);
    CHECK_NEAR(m->positions[4], -2, 0);
    CHECK_NEAR(m->positions[5], 300, 0);
    CHECK_NEAR(m->positions[12], 2, 0);
    CHECK_EQ_INT(m->face_count, 6);
    check_face(m, 0, (const uint32_t[]){0, 1, 2}, 3);
    check_face(m, 1, (const uint32_t[]){0, 2, 3}, 3);
    check_face(m, 2, (const uint32_t[]){0, 1, 3}, 3);
    check_face(m, 3, (const uint32_t[]){0, 1, 2, 3}, 4);
    check_face(m, 4, (const uint32_t[]){0, 1, 4}, 3);
    check_face(m, 5, (const uint32_t[]){4, 3, 2}, 3);
    /* the quad fans into two triangles */
    CHECK_EQ_INT(m->triangle_count, 7);
    const uint32_t quad[6] = {0, 1, 2, 0, 2, 3};
    for (int i = 0; i < 6; i++)
        CHECK_EQ_INT(m->triangles[9 + i], quad[i]);
    /* "v x y z r g b" colours the vertex; the others show white */
    CHECK(m->vertex_colors != NULL && m->vertex_quality == NULL);
    const uint8_t colors[15] = {255, 255, 255, 255, 255, 255, 255, 255,
                                255, 255, 255, 255, 128, 64,  255};
    for (int i = 0; i < 15; i++)
        CHECK_EQ_INT(m->vertex_colors[i], colors[i]);
    CHECK(m->has_vertex_normals);
    CHECK(m->extras != NULL);
    rsmooth_mesh_destroy(m);

    /* Nothing beyond v and f: no extras, no colours, no normals. */
    m = parse_ok("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    CHECK(m->extras == NULL && m->vertex_colors == NULL && !m->has_vertex_normals);
    rsmooth_mesh_destroy(m);
}

static void test_crlf_and_forward_references(void) {
    rsmooth_mesh *m = parse_ok("f 1 2 3 4\r\nv 0 0 0\r\nv 1 0 0\r\nv 1 1 0\r\n# c\r\nv 0 1 0\r\n");
    CHECK_EQ_INT(m->vertex_count, 4);
    CHECK_NEAR(m->positions[11], 0, 0);
    CHECK_NEAR(m->positions[10], 1, 0);
    check_face(m, 0, (const uint32_t[]){0, 1, 2, 3}, 4);
    CHECK_EQ_INT(m->triangle_count, 2);
    rsmooth_mesh_destroy(m);

    /* Vertices and no faces: a valid (point) mesh. */
    m = parse_ok("v 1 2 3\nv 4 5 6\n");
    CHECK_EQ_INT(m->vertex_count, 2);
    CHECK_EQ_INT(m->face_count, 0);
    CHECK_EQ_INT(m->triangle_count, 0);
    CHECK(m->face_offsets != NULL && m->face_offsets[0] == 0);
    rsmooth_mesh_destroy(m);

    /* Exact decimal conversion: the fast path must agree with strtod. */
    const char *numbers[] = {"0.1",
                             "-0.30000000000000004",
                             "123456789012345678901234",
                             "1e-300",
                             "4.9406564584124654e-324",
                             "1e150", /* the largest supported magnitude */
                             "-9.9999999999999991e149",
                             ".5",
                             "5.",
                             "+2.5E+3",
                             "0.000000000000000000000000123",
                             "9007199254740993",
                             "-0"};
    for (size_t i = 0; i < sizeof numbers / sizeof numbers[0]; i++) {
        char text[200];
        snprintf(text, sizeof text, "v %s 0 0\n", numbers[i]);
        m = parse_ok(text);
        double expected = strtod(numbers[i], NULL);
        if (memcmp(&m->positions[0], &expected, sizeof expected) != 0) {
            fprintf(stderr, "test_obj_io.c:%d: '%s' parsed as %.17g, strtod gives %.17g\n",
                    __LINE__, numbers[i], m->positions[0], expected);
            exit(1);
        }
        rsmooth_mesh_destroy(m);
    }
}

static void test_errors(void) {
    /* No vertex: blamed on the end, or on the first statement OBJ does not know. */
    EXPECT_PARSE_ERROR("", 1, "no vertices");
    EXPECT_PARSE_ERROR("# only a comment\n\ng x\n", 3, "no vertices: the file ends (line 3)");
    EXPECT_PARSE_ERROR("# c\nsolidus 1 2\nvertex 1 2 3\n", 2,
                       "no vertices (no 'v x y z' line), and 'solidus' is not an OBJ statement");
    EXPECT_PARSE_ERROR("v 0 0 0\nv 1 nan 0\nv 0 0 0\n", 2, "vertex 2 has a non-finite coordinate");
    EXPECT_PARSE_ERROR("v 0 0 0\nv 1 1 1\nv 0 0 inf\n", 3, "vertex 3 has a non-finite");
    EXPECT_PARSE_ERROR("v 0 0 0\n\nv 1 1e999 1\n", 3, "vertex 2 has a non-finite");
    EXPECT_PARSE_ERROR("v 0 0 0\nv 1 x 0\n", 2, "malformed number 'x'");
    EXPECT_PARSE_ERROR("v 0 0 0\nv 1 1.5.2 0\n", 2, "malformed number");
    EXPECT_PARSE_ERROR("v 0 0 0\nv 1 1\n", 2, "3 needed");
    EXPECT_PARSE_ERROR("v 0 0 0\nv 1 1 1\nv 2 2 2\nf 1 0 2\n", 4, "face index 0");
    /* forward references: the final count decides, the face's line is reported */
    EXPECT_PARSE_ERROR("v 0 0 0\nf 1 2 3\nf 1 2 9\nv 1 1 1\nv 2 2 2\nv 3 3 3\n", 3,
                       "face index 9 out of range (4 vertices)");
    EXPECT_PARSE_ERROR("v 0 0 0\nv 1 1 1\nv 2 2 2\nf 1 2 3\nf -1 -2 -4\n", 5,
                       "face index -4 out of range (3 vertices)");
    EXPECT_PARSE_ERROR("v 0 0 0\nv 1 1 1\nf 1 2\nv 2 2 2\n", 3, "face has 2 vertices");
    EXPECT_PARSE_ERROR("v 0 0 0\nv 1 1 1\nv 2 2 2\nf\n", 4, "face has 0 vertices");
    EXPECT_PARSE_ERROR("v 0 0 0\nv 1 1 1\nv 2 2 2\nf 1 2 3x\n", 4, "malformed face index '3x'");
    EXPECT_PARSE_ERROR("v 0 0 0\nv 1 1 1\nv 2 2 2\nf 1 2 3/1/1/1\n", 4, "malformed face index");
    EXPECT_PARSE_ERROR("v 0 0 0\r\nv 1 1 1\r\nv 2 2 2\r\nf 1 2 99999999999999999999\r\n", 4,
                       "out of range");
    EXPECT_PARSE_ERROR("v 0 0 0\nv 1 1 1\nv 2 2 2\nvt 0 0\nf 1/1 2/-1 3/-2\n", 5,
                       "texture index -2 out of range (1 texture coordinates)");
    EXPECT_PARSE_ERROR("v 0 0 0\nv 1 1 1\nv 2 2 2\nf 1/0 2/1 3/1\n", 4, "malformed face index");

    /* The byte offset points at the offending token. */
    const char *text = "v 0 0 0\nv 1 1 1\nv 2 2 2\nf 1 2 7\n";
    rsmooth_mesh *mesh = NULL;
    rsmooth_error err;
    CHECK_EQ_INT(parse_n(text, strlen(text), &mesh, &err), RSMOOTH_ERROR_PARSE);
    CHECK_EQ_INT(err.byte_offset, strstr(text, "7\n") - text);
    CHECK_EQ_INT(err.line, 4);
    CHECK(mesh == NULL);

    /* A NULL error pointer is fine. */
    CHECK_EQ_INT(parse_n("", 0, &mesh, NULL), RSMOOTH_ERROR_PARSE);
    CHECK_EQ_INT(rsmooth_mesh_read_memory(NULL, 0, RSMOOTH_FORMAT_OBJ, NULL, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
}

/* Same counts, faces and triangles; positions bit-identical (as floats when `as_float`). */
static bool meshes_equal(const rsmooth_mesh *a, const rsmooth_mesh *b, bool as_float) {
    if (a->vertex_count != b->vertex_count || a->face_count != b->face_count ||
        a->triangle_count != b->triangle_count)
        return false;
    for (size_t i = 0; i < 3 * a->vertex_count; i++) {
        bool same = as_float ? (float)a->positions[i] == (float)b->positions[i]
                             : memcmp(&a->positions[i], &b->positions[i], sizeof(double)) == 0;
        if (!same) {
            fprintf(stderr, "position %zu: %.17g written, %.17g read\n", i, a->positions[i],
                    b->positions[i]);
            return false;
        }
    }
    if (memcmp(a->face_offsets, b->face_offsets, (a->face_count + 1) * sizeof(uint32_t)) != 0)
        return false;
    return memcmp(a->face_indices, b->face_indices,
                  a->face_offsets[a->face_count] * sizeof(uint32_t)) == 0 &&
           memcmp(a->triangles, b->triangles, 3 * a->triangle_count * sizeof(uint32_t)) == 0;
}

/* 10^e without libm (the test links only rsmooth::io). */
static double power_of_ten(int e) {
    double v = 1;
    for (int i = 0; i < (e < 0 ? -e : e); i++)
        v *= 10;
    return e < 0 ? 1 / v : v;
}

static uint32_t lcg_state = 12345;
static uint32_t lcg(void) {
    lcg_state = lcg_state * 1664525u + 1013904223u;
    return lcg_state >> 8;
}

/* A mesh with awkward coordinates and faces of 3..6 vertices. */
static rsmooth_mesh *make_mesh(size_t nv, size_t nf) {
    rsmooth_mesh *m = NULL;
    rsmooth_error err;
    CHECK_EQ_INT(rsmooth_mesh_create(nv, nf, 6 * nf, &m, &err), RSMOOTH_OK);
    for (size_t i = 0; i < 3 * nv; i++) {
        double v = ((double)lcg() / (1 << 24) - 0.5) * power_of_ten((int)(lcg() % 40) - 20);
        m->positions[i] = i % 7 == 0 ? 1.0 / 3.0 : v;
    }
    m->positions[0] = -0.0;
    m->positions[1] = 1e-300;
    m->positions[2] = -1e150; /* the supported magnitude */
    uint32_t k = 0;
    for (size_t f = 0; f < nf; f++) {
        uint32_t n = 3 + lcg() % 4;
        for (uint32_t i = 0; i < n; i++)
            m->face_indices[k++] = lcg() % (uint32_t)nv;
        m->face_offsets[f + 1] = k;
    }
    CHECK_EQ_INT(rsmooth_mesh_triangulate(m, &err), RSMOOTH_OK);
    return m;
}

static rsmooth_mesh *read_stream_back(FILE *f) {
    long size = ftell(f);
    CHECK(size > 0);
    rewind(f);
    char *data = malloc((size_t)size);
    CHECK(data != NULL);
    CHECK_EQ_INT(fread(data, 1, (size_t)size, f), size);
    rsmooth_mesh *m = NULL;
    rsmooth_error err;
    rsmooth_status s = rsmooth_mesh_read_memory(data, (size_t)size, RSMOOTH_FORMAT_AUTO, &m, &err);
    if (s != RSMOOTH_OK)
        fprintf(stderr, "read back: %s (line %lld)\n", err.message, (long long)err.line);
    CHECK_EQ_INT(s, RSMOOTH_OK);
    free(data);
    return m;
}

static void test_round_trip(void) {
    rsmooth_mesh *m = make_mesh(50, 80);
    rsmooth_error err;
    FILE *f = tmpfile();
    CHECK(f != NULL);
    CHECK_EQ_INT(rsmooth_mesh_write_stream(m, f, RSMOOTH_FORMAT_OBJ, &err), RSMOOTH_OK);
    rsmooth_mesh *back = read_stream_back(f);
    fclose(f);
    CHECK(meshes_equal(m, back, false));
    rsmooth_mesh_destroy(back);

    /* float32 precision and colours: every float comes back exactly, and so does every colour
     * byte (4 significant digits of c / 255 are within 0.013 of c after scaling back). */
    for (size_t i = 0; i < 3 * m->vertex_count; i++)
        m->positions[i] = (float)m->positions[i];
    m->positions[2] = 1e30;
    m->precision = RSMOOTH_FLOAT32;
    m->vertex_colors = calloc(3 * m->vertex_count, 1);
    CHECK(m->vertex_colors != NULL);
    m->vertex_colors[4] = 255;
    m->vertex_colors[5] = 17;

    char path[] = "/tmp/rsmooth_test_obj_XXXXXX";
    int fd = mkstemp(path);
    CHECK(fd >= 0);
    close(fd);
    CHECK_EQ_INT(rsmooth_mesh_write_file(m, path, RSMOOTH_FORMAT_OBJ, &err), RSMOOTH_OK);
    CHECK_EQ_INT(rsmooth_mesh_read_file(path, &back, &err), RSMOOTH_OK);
    CHECK(meshes_equal(m, back, true));
    CHECK(back->vertex_colors != NULL);
    CHECK(memcmp(back->vertex_colors, m->vertex_colors, 3 * m->vertex_count) == 0);
    CHECK_EQ_INT(back->precision, RSMOOTH_FLOAT64); /* text is read as double */
    rsmooth_mesh_destroy(back);
    FILE *text = fopen(path, "rb");
    CHECK(text != NULL);
    char line[256];
    CHECK(fgets(line, sizeof line, text) != NULL);
    CHECK(strcmp(line, "# written by rsmooth\n") == 0);
    CHECK(fgets(line, sizeof line, text) != NULL);
    CHECK(fgets(line, sizeof line, text) != NULL); /* first vertex, black */
    CHECK(strstr(line, " 0 0 0\n") != NULL);
    CHECK(fgets(line, sizeof line, text) != NULL); /* second vertex: 0 1 0.06667 */
    CHECK(strstr(line, " 0 1 0.06667\n") != NULL);
    fclose(text);
    remove(path);

    /* AUTO picks the format from the extension; unknown extensions are refused. */
    CHECK_EQ_INT(rsmooth_mesh_write_file(m, "/tmp/rsmooth_test_noext", RSMOOTH_FORMAT_AUTO, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    CHECK_EQ_INT(rsmooth_mesh_write_file(m, "/nonexistent-dir/x.obj", RSMOOTH_FORMAT_AUTO, &err),
                 RSMOOTH_ERROR_IO);
    CHECK(strstr(err.message, "/nonexistent-dir/x.obj") != NULL);
    rsmooth_mesh_destroy(m);
}

static const char small_obj[] = "# cube corner\r\n"
                                "v 0 0 0\n"
                                "v 1.25 0 0\n"
                                "v 1 1 -0.5\n"
                                "v 0 1 0 \n"
                                "vn 0 0 1\n"
                                "f 1//1 2//1 3//1 4//1\n"
                                "f -4 -2 -1\n"
                                "f 1/1 3/1 4/1\n";

static void test_truncated_prefixes(void) {
    size_t n = strlen(small_obj);
    for (size_t len = 0; len < n; len++) {
        rsmooth_mesh *m = NULL;
        rsmooth_error err;
        rsmooth_status s = parse_n(small_obj, len, &m, &err);
        if (s != RSMOOTH_OK && s != RSMOOTH_ERROR_PARSE) {
            fprintf(stderr, "test_obj_io.c:%d: prefix %zu: status %d\n", __LINE__, len, (int)s);
            exit(1);
        }
        CHECK((s == RSMOOTH_OK) == (m != NULL));
        rsmooth_mesh_destroy(m);
    }
}

static void test_garbage(void) {
    static const char *const words[] = {"v",   "f",    "vt",  "#",   "1",  "-1",   "0",
                                        "2/3", "1//2", "nan", "1e5", "\n", "\r\n", " ",
                                        "\t",  "/",    "-",   ".",   "9",  "e"};
    lcg_state = 2024;
    for (int round = 0; round < 3000; round++) {
        size_t len = lcg() % 400;
        char *buf = malloc(len ? len : 1);
        CHECK(buf != NULL);
        if (round % 2 == 0) {
            for (size_t i = 0; i < len; i++)
                buf[i] = (char)(lcg() & 0xff);
        } else { /* plausible tokens in random order reach deeper into the parser */
            size_t i = 0;
            while (i < len) {
                const char *w = words[lcg() % (sizeof words / sizeof words[0])];
                for (size_t j = 0; w[j] && i < len; j++)
                    buf[i++] = w[j];
                if (i < len && lcg() % 2)
                    buf[i++] = ' ';
            }
        }
        rsmooth_mesh *m = NULL;
        rsmooth_error err;
        rsmooth_status s = rsmooth_mesh_read_memory(buf, len, RSMOOTH_FORMAT_OBJ, &m, &err);
        CHECK(s == RSMOOTH_OK || s == RSMOOTH_ERROR_PARSE);
        if (s == RSMOOTH_OK) {
            CHECK(m->vertex_count > 0);
            for (size_t t = 0; t < 3 * m->triangle_count; t++)
                CHECK(m->triangles[t] < m->vertex_count);
        }
        rsmooth_mesh_destroy(m);
        free(buf);
    }
}

static void test_files(void) {
    rsmooth_mesh *m = (rsmooth_mesh *)&m;
    rsmooth_error err;
    CHECK_EQ_INT(rsmooth_mesh_read_file("/tmp", &m, &err), RSMOOTH_ERROR_IO);
    CHECK(m == NULL);
    CHECK(strstr(err.message, "'/tmp'") != NULL);
    CHECK_EQ_INT(rsmooth_mesh_read_file("/nonexistent/mesh.obj", &m, &err), RSMOOTH_ERROR_IO);
    CHECK(strstr(err.message, "/nonexistent/mesh.obj") != NULL);
    CHECK(strstr(err.message, "No such file") != NULL);

    CHECK_EQ_INT(rsmooth_format_from_path("a/b/Scan.OBJ"), RSMOOTH_FORMAT_OBJ);
    CHECK_EQ_INT(rsmooth_format_from_path("x.ply"), RSMOOTH_FORMAT_PLY_BINARY);
    CHECK_EQ_INT(rsmooth_format_from_path("x.stl"), RSMOOTH_FORMAT_STL_BINARY);
    CHECK_EQ_INT(rsmooth_format_from_path("x.Off"), RSMOOTH_FORMAT_OFF);
    CHECK_EQ_INT(rsmooth_format_from_path("x.xyz"), RSMOOTH_FORMAT_AUTO);
    CHECK_EQ_INT(rsmooth_format_from_path("obj"), RSMOOTH_FORMAT_AUTO);
    CHECK_EQ_INT(rsmooth_format_from_path(NULL), RSMOOTH_FORMAT_AUTO);
}

static void test_create_and_triangulate(void) {
    rsmooth_mesh *m = NULL;
    rsmooth_error err;
    CHECK_EQ_INT(rsmooth_mesh_create(5, 2, 8, &m, &err), RSMOOTH_OK);
    CHECK_EQ_INT(m->face_offsets[0], 0);
    const uint32_t faces[8] = {0, 1, 2, 3, 4, 1, 2, 3};
    memcpy(m->face_indices, faces, sizeof faces);
    m->face_offsets[1] = 5;
    m->face_offsets[2] = 8;
    CHECK_EQ_INT(rsmooth_mesh_triangulate(m, &err), RSMOOTH_OK);
    CHECK_EQ_INT(m->triangle_count, 4);
    const uint32_t fan[12] = {0, 1, 2, 0, 2, 3, 0, 3, 4, 1, 2, 3};
    for (int i = 0; i < 12; i++)
        CHECK_EQ_INT(m->triangles[i], fan[i]);
    m->face_indices[7] = 5; /* out of range */
    CHECK_EQ_INT(rsmooth_mesh_triangulate(m, &err), RSMOOTH_ERROR_INVALID_ARGUMENT);
    m->face_indices[7] = 4;
    m->face_offsets[1] = 6; /* leaves a face of 2 */
    CHECK_EQ_INT(rsmooth_mesh_triangulate(m, &err), RSMOOTH_ERROR_INVALID_ARGUMENT);
    FILE *f = tmpfile();
    CHECK(f != NULL);
    CHECK_EQ_INT(rsmooth_mesh_write_stream(m, f, RSMOOTH_FORMAT_OBJ, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    fclose(f);
    rsmooth_mesh_destroy(m);
    rsmooth_mesh_destroy(NULL);
    CHECK_EQ_INT(rsmooth_mesh_create(SIZE_MAX, 0, 0, &m, &err), RSMOOTH_ERROR_INVALID_ARGUMENT);
    CHECK(m == NULL);
}

/* ---- lossless OBJ: the faithful writer --------------------------------------------------------
 */

static const char rich_obj[] = "# exported by hand\n"
                               "mtllib scene.mtl\n"
                               "o thing\n"
                               "v 0 0 0 1 0 0\n"
                               "v 1 0 0 0 1 0\n"
                               "v 1 1 0 0 0 1 # blue\n"
                               "v 0 1 0 0.5 0.5 0.5\n"
                               "v 0.5 0.5 1 1 1 1\n"
                               "vt 0 0\n"
                               "vt 1 0\n"
                               "vt 1 1\n"
                               "vt 0 1\n"
                               "vn 0 0 1\n"
                               "vn 0 0 -1\n"
                               "g side\n"
                               "usemtl red\n"
                               "s 1\n"
                               "f 1/1/1 2/2/1 3/3/1 4/4/1\n"
                               "\n"
                               "f 1 2 5\n"
                               "s off\n"
                               "g top\n"
                               "usemtl blue\n"
                               "f -4/-3 -3/-2 -1/-1\n"
                               "f 3//2 4//2 5//2\n"
                               "# a polyline\n"
                               "l 1 2 3\n"
                               "f -2/1/2 -1/2/1 1/3/2 # trailing\n";

/* What the test reads of an OBJ text by itself: the lines other than v, vn and f (in order), the
 * vt and vn lines' values, and per face corner the vt and vn indices (absolute, 0-based, -1 none).
 */
typedef struct obj_text {
    char other[64][128];
    size_t other_count;
    double vt[64][3];
    size_t vt_count;
    double vn[64][3];
    size_t vn_count;
    long corner_vt[256], corner_vn[256];
    size_t corner_count;
} obj_text;

static long resolve(long index, size_t count) {
    return index < 0 ? (long)count + index : index - 1;
}

static void scan_obj(const char *text, obj_text *out) {
    memset(out, 0, sizeof *out);
    const char *p = text;
    while (*p) {
        size_t len = strcspn(p, "\n");
        char line[256];
        CHECK(len < sizeof line);
        memcpy(line, p, len);
        line[len] = '\0';
        p += len + (p[len] == '\n');
        if (len && line[len - 1] == '\r')
            line[len - 1] = '\0';
        char *save = NULL;
        char copy[256];
        strcpy(copy, line);
        char *kw = strtok_r(copy, " \t", &save);
        if (kw && (strcmp(kw, "vt") == 0 || strcmp(kw, "vn") == 0)) {
            bool vt = kw[1] == 't';
            double *dst = vt ? out->vt[out->vt_count++] : out->vn[out->vn_count++];
            CHECK(out->vt_count <= 64 && out->vn_count <= 64);
            for (int k = 0; k < 3; k++) {
                char *t = strtok_r(NULL, " \t", &save);
                dst[k] = t ? strtod(t, NULL) : 0;
            }
            if (vt) { /* vt lines are kept verbatim: list them with the others */
                CHECK(out->other_count < 64);
                strcpy(out->other[out->other_count++], line);
            }
        } else if (kw && strcmp(kw, "f") == 0) {
            char *t;
            while ((t = strtok_r(NULL, " \t", &save)) != NULL && t[0] != '#') {
                CHECK(out->corner_count < 256);
                long vt = -1, vn = -1;
                char *slash = strchr(t, '/');
                if (slash) {
                    if (slash[1] != '/')
                        vt = resolve(strtol(slash + 1, NULL, 10), out->vt_count);
                    char *second = strchr(slash + 1, '/');
                    if (second)
                        vn = resolve(strtol(second + 1, NULL, 10), out->vn_count);
                }
                out->corner_vt[out->corner_count] = vt;
                out->corner_vn[out->corner_count++] = vn;
            }
        } else if (!kw || strcmp(kw, "v") != 0) {
            CHECK(out->other_count < 64);
            strcpy(out->other[out->other_count++], line);
        }
    }
}

/* The text of every v line after its three coordinates. */
static size_t vertex_tails(const char *text, char tails[][64], size_t max) {
    size_t n = 0;
    for (const char *p = text; *p; p += strcspn(p, "\n"), p += *p == '\n') {
        if (p[0] != 'v' || p[1] != ' ')
            continue;
        const char *q = p + 1;
        for (int k = 0; k < 3; k++) {
            q += strspn(q, " \t");
            q += strcspn(q, " \t\r\n");
        }
        size_t len = strcspn(q, "\r\n");
        CHECK(n < max && len < 64);
        memcpy(tails[n], q, len);
        tails[n++][len] = '\0';
    }
    return n;
}

static void check_faithful_round_trip(const char *input) {
    rsmooth_mesh *m = parse_ok(input);
    CHECK(m->extras != NULL && m->has_vertex_normals && m->vertex_colors != NULL);
    for (size_t i = 0; i < 3 * m->vertex_count; i++) /* digits that need all 17 to round-trip */
        m->positions[i] += (double)(i + 1) / 3.0;
    m->positions[4] = 0.1; /* and a short one */
    rsmooth_error err;
    CHECK_EQ_INT(rsmooth_mesh_triangulate(m, &err), RSMOOTH_OK);
    size_t size;
    char *out = mesh_to_memory(m, RSMOOTH_FORMAT_OBJ, &size);
    CHECK(strstr(out, "written by rsmooth") == NULL); /* not the generic path */
    CHECK(strstr(out, " 0.1 ") != NULL);

    /* Every line other than v, vn and f (vt included) comes back identical and in order. */
    static obj_text a, b;
    scan_obj(input, &a);
    scan_obj(out, &b);
    CHECK_EQ_INT(a.other_count, b.other_count);
    for (size_t i = 0; i < a.other_count; i++)
        if (strcmp(a.other[i], b.other[i]) != 0) {
            fprintf(stderr, "line '%s' written as '%s'\n", a.other[i], b.other[i]);
            exit(1);
        }
    /* CRLF input gives CRLF output. */
    CHECK((strstr(input, "\r\n") != NULL) == (strstr(out, "\r\n") != NULL));

    /* Read back: the new positions, the same faces, each corner on the same vt coordinates. */
    rsmooth_mesh *back = parse_n_ok(out, size);
    CHECK(meshes_equal(m, back, false));
    CHECK_EQ_INT(a.corner_count, b.corner_count);
    CHECK_EQ_INT(a.corner_count, m->face_offsets[m->face_count]);
    for (size_t k = 0; k < a.corner_count; k++) {
        CHECK_EQ_INT(a.corner_vt[k] < 0, b.corner_vt[k] < 0);
        if (a.corner_vt[k] >= 0)
            for (int c = 0; c < 3; c++)
                CHECK_NEAR(a.vt[a.corner_vt[k]][c], b.vt[b.corner_vt[k]][c], 0);
        CHECK_EQ_INT(b.corner_vn[k], m->face_indices[k]); /* the vertex's own normal */
    }
    /* One recomputed normal per vertex. */
    CHECK_EQ_INT(b.vn_count, m->vertex_count);
    double normals[3 * 64];
    CHECK(m->vertex_count <= 64);
    CHECK_EQ_INT(rsmooth_mesh_vertex_normals(m, normals, &err), RSMOOTH_OK);
    for (size_t i = 0; i < 3 * m->vertex_count; i++)
        CHECK_NEAR(b.vn[i / 3][i % 3], normals[i], 1e-8);
    /* Colours: the same bytes, and the v lines' trailing fields verbatim. */
    CHECK(back->vertex_colors != NULL);
    CHECK(memcmp(back->vertex_colors, m->vertex_colors, 3 * m->vertex_count) == 0);
    char tails_a[64][64], tails_b[64][64];
    size_t na = vertex_tails(input, tails_a, 64);
    CHECK_EQ_INT(na, vertex_tails(out, tails_b, 64));
    for (size_t i = 0; i < na; i++)
        CHECK(strcmp(tails_a[i], tails_b[i]) == 0);

    /* Writing the read-back mesh again changes nothing: the output is a fixed point. */
    size_t size2;
    char *out2 = mesh_to_memory(back, RSMOOTH_FORMAT_OBJ, &size2);
    CHECK(size2 == size && memcmp(out, out2, size) == 0);
    free(out2);

    /* Conversion losses name the OBJ-only content, not colours or normals (PLY holds them). */
    char losses[512];
    size_t lost =
        rsmooth_mesh_conversion_losses(m, RSMOOTH_FORMAT_PLY_BINARY, losses, sizeof losses);
    CHECK_EQ_INT(lost, 6);
    CHECK(strstr(losses, "OBJ texture coordinates") != NULL);
    CHECK(strstr(losses, "OBJ groups and objects") != NULL);
    CHECK(strstr(losses, "OBJ materials") != NULL);
    CHECK(strstr(losses, "OBJ smoothing groups") != NULL);
    CHECK(strstr(losses, "OBJ lines and points") != NULL);
    CHECK(strstr(losses, "OBJ comments") != NULL);
    CHECK(strstr(losses, "colour") == NULL && strstr(losses, "normal") == NULL);
    CHECK_EQ_INT(rsmooth_mesh_conversion_losses(m, RSMOOTH_FORMAT_OBJ, losses, sizeof losses), 0);
    CHECK_EQ_INT(losses[0], '\0');

    /* A changed face structure falls back to the generic writer: positions, colours, normals. */
    m->face_count--;
    char *generic = mesh_to_memory(m, RSMOOTH_FORMAT_OBJ, &size2);
    m->face_count++;
    CHECK(strncmp(generic, "# written by rsmooth\n", 21) == 0);
    CHECK(strstr(generic, "usemtl") == NULL && strstr(generic, "vt ") == NULL);
    CHECK(strstr(generic, "\nvn ") != NULL && strstr(generic, "\nf 1//1 ") != NULL);
    rsmooth_mesh *g = parse_n_ok(generic, size2);
    CHECK_EQ_INT(g->face_count, m->face_count - 1);
    CHECK(memcmp(g->vertex_colors, m->vertex_colors, 3 * m->vertex_count) == 0);
    CHECK(g->has_vertex_normals);
    rsmooth_mesh_destroy(g);
    free(generic);

    rsmooth_mesh_destroy(back);
    free(out);
    rsmooth_mesh_destroy(m);
}

/* A vn line that ends the file without a newline, or with a lone '\r' (fuzz_obj in CI): its
 * recomputed normals are written one per line, read back, and writing what was read back gives the
 * same bytes. Before, the normals shared the replaced line's ending: "vn 0 0 0vn ..." on one line,
 * or one '\r' between them, and the file did not read back. */
static void test_last_line_normals(void) {
    static const char *const inputs[] = {
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\nvn 0 0 1",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\nvn 0 0 1\r",
        "v 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nv 0 0 1\r\nf 1 2 3\r\nf 1 3 4\r\nvn 0 0 1\r",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\r\nv 0 0 1\nf 1 2 3\nvn 0 0 1\r\nf 1 3 4\nvn 1 0 0\r",
    };
    for (size_t i = 0; i < sizeof inputs / sizeof inputs[0]; i++) {
        rsmooth_mesh *m = parse_ok(inputs[i]);
        size_t size, size2;
        char *out = mesh_to_memory(m, RSMOOTH_FORMAT_OBJ, &size);
        rsmooth_mesh *back = parse_n_ok(out, size);
        CHECK(meshes_equal(m, back, false));
        static obj_text b;
        scan_obj(out, &b);
        CHECK_EQ_INT(b.vn_count, m->vertex_count);
        char *out2 = mesh_to_memory(back, RSMOOTH_FORMAT_OBJ, &size2);
        CHECK(size2 == size && memcmp(out, out2, size) == 0);
        free(out2);
        rsmooth_mesh_destroy(back);
        free(out);
        rsmooth_mesh_destroy(m);
    }
}

static void test_faithful(void) {
    check_faithful_round_trip(rich_obj);
    /* The same with CRLF line ends. */
    char crlf[sizeof rich_obj * 2];
    size_t n = 0;
    for (const char *p = rich_obj; *p; p++) {
        if (*p == '\n')
            crlf[n++] = '\r';
        crlf[n++] = *p;
    }
    crlf[n] = '\0';
    check_faithful_round_trip(crlf);

    /* Without vn lines: faces keep their vt, gain no vn; no vn lines appear. */
    rsmooth_mesh *m = parse_ok("g a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 1\n"
                               "f 1/1 2/-1 3\nf 3 2 1/2\n");
    CHECK(!m->has_vertex_normals);
    size_t size;
    char *out = mesh_to_memory(m, RSMOOTH_FORMAT_OBJ, &size);
    CHECK(strstr(out, "f 1/1 2/2 3\nf 3 2 1/2\n") != NULL);
    CHECK(strstr(out, "vn") == NULL);
    free(out);
    rsmooth_mesh_destroy(m);
}

/* ---- writers refuse what cannot be read back; byte-order marks; located errors */

static void test_write_refusals_and_extremes(void) {
    check_writer_refuses_unreadable(RSMOOTH_FORMAT_OBJ);
    check_extremes_round_trip(RSMOOTH_FORMAT_OBJ, RSMOOTH_FLOAT64);
    check_float32_scale(RSMOOTH_FORMAT_OBJ);

    /* The query: what the writers refuse, without writing; the arguments a writer refuses too. */
    {
        rsmooth_mesh *t = tetrahedron(RSMOOTH_FLOAT64);
        rsmooth_error e;
        const rsmooth_format all[] = {RSMOOTH_FORMAT_OBJ,        RSMOOTH_FORMAT_PLY_ASCII,
                                      RSMOOTH_FORMAT_PLY_BINARY, RSMOOTH_FORMAT_OFF,
                                      RSMOOTH_FORMAT_STL_ASCII,  RSMOOTH_FORMAT_STL_BINARY};
        for (size_t f = 0; f < sizeof all / sizeof all[0]; f++)
            CHECK_EQ_INT(rsmooth_mesh_check_writable(t, all[f], &e), RSMOOTH_OK);
        CHECK_EQ_INT(rsmooth_mesh_check_writable(t, RSMOOTH_FORMAT_OBJ, NULL), RSMOOTH_OK);
        CHECK_EQ_INT(rsmooth_mesh_check_writable(NULL, RSMOOTH_FORMAT_OBJ, &e),
                     RSMOOTH_ERROR_INVALID_ARGUMENT);
        CHECK_EQ_INT(rsmooth_mesh_check_writable(t, RSMOOTH_FORMAT_AUTO, &e),
                     RSMOOTH_ERROR_INVALID_ARGUMENT);
        CHECK_EQ_INT(rsmooth_mesh_check_writable(t, (rsmooth_format)99, &e),
                     RSMOOTH_ERROR_INVALID_ARGUMENT);
        CHECK_EQ_INT(rsmooth_mesh_check_writable(t, RSMOOTH_FORMAT_PLY_BINARY_BE, &e),
                     RSMOOTH_ERROR_UNSUPPORTED);
        /* a face index out of range, a triangle list that no longer matches: as the writers say */
        t->face_indices[4] = 9;
        for (size_t f = 0; f < sizeof all / sizeof all[0]; f++) {
            rsmooth_status s;
            CHECK(write_checked(t, all[f], &s, &e) == NULL);
            CHECK_EQ_INT(s, RSMOOTH_ERROR_INVALID_ARGUMENT);
        }
        t->face_indices[4] = 1;
        t->triangles[4] = 9;
        t->has_vertex_normals = 1;
        for (size_t f = 0; f < sizeof all / sizeof all[0]; f++) {
            rsmooth_status s;
            rsmooth_mesh_destroy(write_checked(t, all[f], &s, &e));
        }
        rsmooth_mesh_destroy(t);
    }

    /* A float32 mesh holding a value beyond float range: written as the double it is, not "inf". */
    rsmooth_mesh *m = tetrahedron(RSMOOTH_FLOAT32);
    m->positions[5] = 1e100;
    size_t size;
    char *text = mesh_to_memory(m, RSMOOTH_FORMAT_OBJ, &size);
    CHECK(strstr(text, "inf") == NULL);
    rsmooth_mesh *back = parse_n_ok(text, size);
    CHECK_NEAR(back->positions[5], 1e100, 0);
    rsmooth_mesh_destroy(back);
    free(text);

    /* A point cloud's own normals are written, exactly, and refused when non-finite. */
    m->face_count = m->triangle_count = 0;
    m->precision = RSMOOTH_FLOAT64;
    m->positions[5] = 0;
    m->has_vertex_normals = 1;
    m->vertex_normals = calloc(12, sizeof(double));
    CHECK(m->vertex_normals != NULL);
    m->vertex_normals[2] = 1.0 / 3.0;
    text = mesh_to_memory(m, RSMOOTH_FORMAT_OBJ, &size);
    back = parse_n_ok(text, size);
    CHECK(back->vertex_normals != NULL);
    CHECK(memcmp(back->vertex_normals, m->vertex_normals, 12 * sizeof(double)) == 0);
    rsmooth_mesh_destroy(back);
    free(text);
    m->vertex_normals[7] = NAN;
    rsmooth_error err;
    char *data;
    CHECK_EQ_INT(write_to_memory(m, RSMOOTH_FORMAT_OBJ, &data, &size, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    CHECK(size == 0 && strstr(err.message, "vertex 2 has a non-finite normal") != NULL);
    free(data);
    rsmooth_mesh_destroy(m);
}

/* A file read with and without a leading byte-order mark: the same mesh. */
static void check_same_mesh(const rsmooth_mesh *a, const rsmooth_mesh *b) {
    CHECK(meshes_equal(a, b, false));
}

static void test_byte_order_mark(void) {
    static const char tet[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                              "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
    char marked[sizeof tet + 3] = "\xEF\xBB\xBF";
    memcpy(marked + 3, tet, sizeof tet);
    rsmooth_mesh *plain = parse_ok(tet);
    for (int auto_format = 0; auto_format < 2; auto_format++) {
        rsmooth_mesh *m = NULL;
        rsmooth_error err;
        CHECK_EQ_INT(read_exact_copy(marked, strlen(marked),
                                     auto_format ? RSMOOTH_FORMAT_AUTO : RSMOOTH_FORMAT_OBJ, &m,
                                     &err),
                     RSMOOTH_OK);
        check_same_mesh(m, plain); /* the first vertex is not lost to the mark */
        CHECK_EQ_INT(m->source_format, RSMOOTH_FORMAT_OBJ);

        /* Written back as OBJ: the mark, then what the unmarked file writes. */
        size_t size, plain_size;
        char *out = mesh_to_memory(m, RSMOOTH_FORMAT_OBJ, &size);
        char *plain_out = mesh_to_memory(plain, RSMOOTH_FORMAT_OBJ, &plain_size);
        CHECK_EQ_INT(size, plain_size + 3);
        CHECK(memcmp(out, "\xEF\xBB\xBF", 3) == 0 && memcmp(out + 3, plain_out, plain_size) == 0);
        free(out);
        free(plain_out);

        /* Converting drops it and says so, as for other losses. */
        char losses[256];
        CHECK_EQ_INT(rsmooth_mesh_conversion_losses(m, RSMOOTH_FORMAT_OBJ, losses, sizeof losses),
                     0);
        CHECK_EQ_INT(rsmooth_mesh_conversion_losses(m, RSMOOTH_FORMAT_OFF, losses, sizeof losses),
                     1);
        CHECK(strcmp(losses, "UTF-8 byte-order mark") == 0);
        CHECK_EQ_INT(
            rsmooth_mesh_conversion_losses(plain, RSMOOTH_FORMAT_OFF, losses, sizeof losses), 0);
        out = mesh_to_memory(m, RSMOOTH_FORMAT_OFF, &size);
        CHECK(strncmp(out, "OFF\n", 4) == 0);
        free(out);
        rsmooth_mesh_destroy(m);
    }
    rsmooth_mesh_destroy(plain);

    /* Error locations count the mark's bytes: the offset is in the file. */
    const char *bad = "\xEF\xBB\xBFv 0 0 0\nv 1 x 0\n";
    rsmooth_mesh *m = NULL;
    rsmooth_error err;
    CHECK_EQ_INT(read_exact_copy(bad, strlen(bad), RSMOOTH_FORMAT_AUTO, &m, &err),
                 RSMOOTH_ERROR_PARSE);
    CHECK_EQ_INT(err.line, 2);
    CHECK_EQ_INT(err.byte_offset, strchr(bad, 'x') - bad);
}

/* Expects automatic detection to fail on `size` bytes with a parse error at `line` and `offset`
 * whose message holds `needle`. */
static void expect_auto_error(int at, const void *data, size_t size, long long line,
                              long long offset, const char *needle) {
    rsmooth_mesh *m = NULL;
    rsmooth_error err;
    rsmooth_status s = read_exact_copy(data, size, RSMOOTH_FORMAT_AUTO, &m, &err);
    if (s != RSMOOTH_ERROR_PARSE || err.line != line || err.byte_offset != offset ||
        !strstr(err.message, needle)) {
        fprintf(stderr,
                "test_obj_io.c:%d: status %d line %lld byte %lld '%s'; expected line %lld byte "
                "%lld '%s'\n",
                at, (int)s, (long long)err.line, (long long)err.byte_offset, err.message, line,
                offset, needle);
        exit(1);
    }
    CHECK(m == NULL);
}

static void test_detection_errors(void) {
    expect_auto_error(__LINE__, "", 0, 1, 0, "the file is empty");
    expect_auto_error(__LINE__, "\n# nothing\n\n", 12, 4, 12, "only blanks and comments");
    expect_auto_error(__LINE__, "\xEF\xBB\xBF", 3, 1, 3, "only blanks and comments");
    /* text that is no mesh: blamed on its first word */
    expect_auto_error(__LINE__, "hello world\n", 12, 1, 0, "'hello' is not an OBJ statement");
    /* binary content of no format: taken for a binary STL, whose size is then wrong */
    unsigned char binary[150];
    for (size_t i = 0; i < sizeof binary; i++)
        binary[i] = (unsigned char)(i * 37 + 11);
    binary[5] = 0;
    expect_auto_error(__LINE__, binary, sizeof binary, -1, 150, "binary content (byte 5 is 0x00)");
    expect_auto_error(__LINE__, binary, 60, -1, 60, "at least 84 bytes expected");
    /* an OBJ with a stray control byte (a DOS end-of-file mark) is still an OBJ */
    const char dos[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n\x1a";
    rsmooth_mesh *m = NULL;
    rsmooth_error err;
    CHECK_EQ_INT(read_exact_copy(dos, sizeof dos - 1, RSMOOTH_FORMAT_AUTO, &m, &err), RSMOOTH_OK);
    CHECK_EQ_INT(m->vertex_count, 3);
    rsmooth_mesh_destroy(m);
    /* every prefix of an OBJ file fails with a location, or reads */
    check_prefixes_located("OBJ", small_obj, strlen(small_obj));
}

static void test_attribute_indices(void) {
    const char *v3 = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    char text[256];
    /* vt / vn indices beyond their lines are refused where they stand, forward ones too */
    snprintf(text, sizeof text, "%svt 0 0\nf 1/1 2/2 3/1\n", v3);
    EXPECT_PARSE_ERROR(text, 5, "texture index 2 out of range (1 texture coordinates)");
    snprintf(text, sizeof text, "%svn 0 0 1\nf 1//1 2//1 3//2\nvn 1 0 0\nf 1//3 2//1 3//1\n", v3);
    EXPECT_PARSE_ERROR(text, 7, "normal index 3 out of range (2 normals)");
    snprintf(text, sizeof text, "%svn 0 0 1\nf 1//-2 2//1 3//1\n", v3);
    EXPECT_PARSE_ERROR(text, 5, "normal index -2 out of range (1 normals)");
    snprintf(text, sizeof text, "%sf 1//1 2//1 3//1\n", v3);
    EXPECT_PARSE_ERROR(text, 4, "normal index 1 out of range (0 normals)");
    snprintf(text, sizeof text, "%sf 1/1/1 2/1/1 3/1/1\nvn 0 0 1\n", v3);
    EXPECT_PARSE_ERROR(text, 4, "texture index 1 out of range (0 texture coordinates)");
    /* forward references within the final counts read */
    snprintf(text, sizeof text, "%sf 1/1/1 2/2/1 3/1/1\nvt 0 0\nvt 1 0\nvn 0 0 1\n", v3);
    rsmooth_mesh *m = parse_ok(text);
    CHECK_EQ_INT(m->face_count, 1);
    rsmooth_mesh_destroy(m);
    /* vn lines hold three finite numbers */
    snprintf(text, sizeof text, "%svn 0 x 1\n", v3);
    EXPECT_PARSE_ERROR(text, 4, "malformed number 'x'");
    snprintf(text, sizeof text, "%svn 0 0\n", v3);
    EXPECT_PARSE_ERROR(text, 4, "'vn' takes 3 numbers");
    snprintf(text, sizeof text, "%svn 0 nan 1\n", v3);
    EXPECT_PARSE_ERROR(text, 4, "normal 1 has a non-finite component");
    /* coordinates beyond the supported magnitude are refused where they stand */
    /* with the digits that tell the value from the limit (%g printed both as 1e+150) */
    EXPECT_PARSE_ERROR("v 0 0 0\nv 0 -1.0000000000000002e150 0\n", 2,
                       "vertex 2 has coordinate -1.0000000000000002e+150 beyond the supported "
                       "magnitude 1e+150");
    EXPECT_PARSE_ERROR("v 0 0 0\nv 1.0000001e150 0 0\n", 2,
                       "vertex 2 has coordinate 1.0000001e+150 beyond the supported magnitude "
                       "1e+150");
    EXPECT_PARSE_ERROR("v 0 0 0\n\nv 0 0 1e300\n", 3, "vertex 2 has coordinate 1e+300 beyond");
    /* colours too must be numbers (they were read as black) */
    EXPECT_PARSE_ERROR("v 0 0 0 1 0 0\nv 1 0 0 0.5 nan 0\n", 2, "vertex 2 has a non-finite colour");
}

int main(void) {
    test_index_forms();
    test_crlf_and_forward_references();
    test_errors();
    test_round_trip();
    test_truncated_prefixes();
    test_garbage();
    test_files();
    test_create_and_triangulate();
    test_faithful();
    test_last_line_normals();
    test_write_refusals_and_extremes();
    test_byte_order_mark();
    test_detection_errors();
    test_attribute_indices();
    printf("obj_io: all checks passed\n");
    return 0;
}
