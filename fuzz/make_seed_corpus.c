/* Writes the fuzzers' seed corpus (small valid files of every format and variant) into DIR/obj,
 * DIR/ply, DIR/off and DIR/stl, and all of them mixed into DIR/auto (the automatic detection
 * target's), with byte-order marks, what may come before an OFF keyword, and files detection must
 * refuse with a located error; checks each reads (or is refused) as intended. With no DIR, into a
 * temporary directory that is removed afterwards (the ctest). */
#define _POSIX_C_SOURCE 200809L
#include "rsmooth_io.h"
#include "test_io_util.h"

#include <errno.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* The square 0-1-2-3 (a quad) plus the triangle 0 1 4, as the test files store it. */
static const double square[5][3] = {
    {0, 0, 0}, {1.5, 0, 0}, {1.5, 1.25, 0}, {0, 1.25, -0.5}, {0.25, -1, 3}};

/* ---- writing and checking */

#define MAX_SEEDS 160

typedef struct corpus {
    const char *dir;
    int written, failed;
    char *paths[MAX_SEEDS]; /* what was written, to remove a temporary corpus */
} corpus;

static rsmooth_format format_of(const char *kind) {
    if (strcmp(kind, "ply") == 0)
        return RSMOOTH_FORMAT_PLY_BINARY;
    if (strcmp(kind, "off") == 0)
        return RSMOOTH_FORMAT_OFF;
    if (strcmp(kind, "stl") == 0)
        return RSMOOTH_FORMAT_STL_BINARY;
    return RSMOOTH_FORMAT_OBJ;
}

static void write_seed(corpus *c, const char *kind, const char *name, const bytes *b) {
    char path[4096];
    snprintf(path, sizeof path, "%s/%s/%s", c->dir, kind, name);
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(b->data, 1, b->size, f) != b->size || fclose(f) != 0) {
        fprintf(stderr, "make_seed_corpus: cannot write '%s': %s\n", path, strerror(errno));
        exit(1);
    }
    if (c->written < MAX_SEEDS)
        c->paths[c->written] = strdup(path);
    c->written++;
}

/* Checks that `b` reads as `format` (or, when !readable, is refused with a located parse or
 * unsupported error, as detection must refuse it). */
static void check_seed(corpus *c, const char *kind, const char *name, const bytes *b,
                       rsmooth_format format, bool readable) {
    rsmooth_mesh *mesh = NULL;
    rsmooth_error err;
    rsmooth_status s = rsmooth_mesh_read_memory(b->data, b->size, format, &mesh, &err);
    bool located = err.line >= 1 || err.byte_offset >= 0;
    bool as_intended =
        readable ? s == RSMOOTH_OK
                 : (s == RSMOOTH_ERROR_PARSE || s == RSMOOTH_ERROR_UNSUPPORTED) && located;
    if (!as_intended) {
        fprintf(stderr, "make_seed_corpus: %s/%s %s: status %d, %s (line %lld, byte %lld)\n", kind,
                name, readable ? "does not read" : "is not refused with a location", (int)s,
                err.message, (long long)err.line, (long long)err.byte_offset);
        c->failed++;
    }
    rsmooth_mesh_destroy(mesh);
}

/* Writes DIR/kind/name, read as the fuzzer for `kind` reads it, and DIR/auto/kind_name, read
 * through detection: both must read. */
static void emit(corpus *c, const char *kind, const char *name, const bytes *b) {
    write_seed(c, kind, name, b);
    check_seed(c, kind, name, b, format_of(kind), true);
    char auto_name[256];
    snprintf(auto_name, sizeof auto_name, "%s_%s", kind, name);
    write_seed(c, "auto", auto_name, b);
    check_seed(c, "auto", auto_name, b, RSMOOTH_FORMAT_AUTO, true);
}

/* A seed for the detection target only: `text` (with a UTF-8 byte-order mark first when `bom`),
 * which must read, or be refused with a location when !readable. */
static void emit_auto(corpus *c, const char *name, bool bom, const char *text, bool readable) {
    bytes b = {0};
    if (bom)
        put_text(&b, "\xEF\xBB\xBF");
    put_text(&b, text);
    write_seed(c, "auto", name, &b);
    check_seed(c, "auto", name, &b, RSMOOTH_FORMAT_AUTO, readable);
    bytes_free(&b);
}

static void emit_text(corpus *c, const char *kind, const char *name, const char *text) {
    bytes b = {0};
    put_text(&b, text);
    emit(c, kind, name, &b);
    bytes_free(&b);
}

/* ---- OBJ */

static void obj_seeds(corpus *c) {
    bytes b = {0};
    put_text(&b, "# the square\n");
    for (int i = 0; i < 5; i++) {
        char line[128];
        snprintf(line, sizeof line, "v %.17g %.17g %.17g\n", square[i][0], square[i][1],
                 square[i][2]);
        put_text(&b, line);
    }
    put_text(&b, "f 1 2 3 4\nf 1 2 5\n");
    emit(c, "obj", "plain.obj", &b);
    bytes_free(&b);

    emit_text(c, "obj", "attributes.obj",
              "mtllib square.mtl\r\n"
              "o square\r\n"
              "v 0 0 0\r\nv 1.5 0 0\r\nv 1.5 1.25 0\r\nv 0 1.25 -0.5\r\nv 0.25 -1 3\r\n"
              "vt 0 0\r\nvt 1 0\r\nvt 1 1\r\nvt 0 1 0\r\n"
              "vn 0 0 1\r\nvn 0 -0.948 0.316\r\n"
              "g top\r\nusemtl red\r\ns 1\r\n"
              "f 1/1/1 2/2/1 3/3/1 4/4/1\r\n"
              "g side bottom\r\nusemtl blue\r\ns off\r\n"
              "f -5/-4/-1 -4/-3/-1 -1/-1/-1\r\n");
    emit_text(c, "obj", "colours.obj",
              "v 0 0 0 1 0 0\nv 1.5 0 0 0 1 0\nv 1.5 1.25 0 0 0 1\nv 0 1.25 -0.5 1 1 1\n"
              "v\t0.25\t-1\t3\t0.5 0.5 0.5   # trailing comment\n"
              "vn 0 0 1\n"
              "f 1//1 2//1 3//1\nf 1//1 3//1 4//1\nf 5 1 2\n");
    emit_text(c, "obj", "polygons.obj",
              "v 0 0 0\nv 1 0 0\nv 1.5 1 0\nv 0.5 1.5 0\nv -0.5 1 0\nv 0 0 1.0 1.0\n"
              "f 1 2 3 4 5\n"
              "f 1/1 2/2 6/3\n"
              "vt 0 0\nvt 1 0\nvt 0 1\n"
              "l 1 2\np 3\ncstype bezier\n"
              "f -6 -5 -1\n");
    emit_text(c, "obj", "forward.obj", "f 1 2 3\nf 3 2 4\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n");
    emit_text(c, "obj", "extremes.obj",
              "v 1e150 -1e150 -0\nv 4.9406564584124654e-324 2.2250738585072014e-308 0.1\n"
              "v 0 1 1e-300\nvn 0 0 1\nf 1//1 2//1 3//1\n");
}

/* ---- PLY */

static void ply_ascii_seeds(corpus *c) {
    bytes b = {0};
    put_text(&b, "ply\r\nformat ascii 1.0\r\ncomment made by make_seed_corpus\r\n"
                 "obj_info anything\r\n"
                 "element vertex 5\r\n"
                 "property float nx\r\nproperty float x\r\nproperty float y\r\n"
                 "property float ny\r\nproperty float z\r\nproperty float nz\r\n"
                 "property uchar red\r\n"
                 "element tristrips 1\r\nproperty list int int vertex_indices\r\n"
                 "element face 2\r\nproperty uchar flags\r\n"
                 "property list uchar int vertex_indices\r\n"
                 "property list uchar float texcoord\r\n"
                 "element material 1\r\nproperty list uchar uchar name\r\nproperty float shine\r\n"
                 "end_header\r\n");
    for (int i = 0; i < 5; i++) {
        char line[160];
        snprintf(line, sizeof line, "0.5 %.17g %.17g -1 %.17g 0 %d\r\n", square[i][0], square[i][1],
                 square[i][2], 10 * i);
        put_text(&b, line);
    }
    put_text(&b, "6 0 1 2 -1 3 4\r\n7 4 0 1 2 3 2 0.5 0.5\r\n1  3 0 1 4 0\n3 65 66 67 0.5\n");
    emit(c, "ply", "ascii_extras.ply", &b);
    bytes_free(&b);

    emit_text(c, "ply", "ascii_colours.ply",
              "ply\nformat ascii 1.0\nelement vertex 4\nproperty double x\nproperty double y\n"
              "property double z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n"
              "property float quality\nelement face 2\nproperty list uchar uint vertex_index\n"
              "end_header\n0 0 0 255 0 0 0.5\n1 0 0 0 255 0 1\n1 1 0 0 0 255 0.25\n"
              "0 1 0 9 9 9 0\n3 0 1 2\n3 0 2 3\n");
    emit_text(c, "ply", "ascii_points.ply",
              "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
              "property float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n");
}

/* Faces first with an extra element before them; doubles or floats; extra vertex properties. */
static void ply_binary_seed(corpus *c, const char *name, bool big_endian, bool doubles) {
    bytes b = {.big_endian = big_endian};
    put_text(&b, "ply\n");
    put_text(&b,
             big_endian ? "format binary_big_endian 1.0\n" : "format binary_little_endian 1.0\n");
    put_text(&b, "comment binary seed\n"
                 "element edge 2\nproperty int vertex1\nproperty list uchar int corners\n"
                 "element face 2\nproperty list int uint vertex_index\nproperty uchar intensity\n"
                 "element vertex 5\n");
    put_text(&b, doubles ? "property double x\nproperty double y\nproperty double z\n"
                         : "property float32 x\nproperty float32 y\nproperty float32 z\n");
    put_text(&b, "property short nx\nproperty uchar red\nproperty uchar green\n"
                 "property uchar blue\nend_header\n");
    put_uint(&b, 7, 4); /* edges */
    put_uint(&b, 2, 1);
    put_uint(&b, 0, 4);
    put_uint(&b, 1, 4);
    put_uint(&b, 8, 4);
    put_uint(&b, 0, 1);
    put_uint(&b, 4, 4); /* faces */
    for (uint32_t v = 0; v < 4; v++)
        put_uint(&b, v, 4);
    put_uint(&b, 200, 1);
    put_uint(&b, 3, 4);
    put_uint(&b, 0, 4);
    put_uint(&b, 1, 4);
    put_uint(&b, 4, 4);
    put_uint(&b, 201, 1);
    for (int i = 0; i < 5; i++) { /* vertices */
        for (int k = 0; k < 3; k++) {
            if (doubles)
                put_f64(&b, square[i][k]);
            else
                put_f32(&b, (float)square[i][k]);
        }
        put_uint(&b, 0xfffe, 2);
        put_uint(&b, 255, 1);
        put_uint(&b, (uint64_t)(40 * i), 1);
        put_uint(&b, 7, 1);
    }
    emit(c, "ply", name, &b);
    bytes_free(&b);
}

/* What most tools write: float x y z, "list uchar int" faces. */
static void ply_common_seed(corpus *c, const char *name, bool big_endian) {
    bytes b = {.big_endian = big_endian};
    put_text(&b, "ply\n");
    put_text(&b,
             big_endian ? "format binary_big_endian 1.0\n" : "format binary_little_endian 1.0\n");
    put_text(&b, "element vertex 5\nproperty float x\nproperty float y\nproperty float z\n"
                 "property float quality\nelement face 2\n"
                 "property list uchar int vertex_indices\nend_header\n");
    for (int i = 0; i < 5; i++) {
        for (int k = 0; k < 3; k++)
            put_f32(&b, (float)square[i][k]);
        put_f32(&b, 0.125f * (float)i);
    }
    put_uint(&b, 4, 1);
    for (int v = 0; v < 4; v++)
        put_uint(&b, (uint64_t)v, 4);
    put_uint(&b, 3, 1);
    put_uint(&b, 0, 4);
    put_uint(&b, 1, 4);
    put_uint(&b, 4, 4);
    emit(c, "ply", name, &b);
    bytes_free(&b);
}

/* Scanners' range grids (lib/io/ply_range_grid.c): 3 x 2 cells, one empty, read as three
 * triangles; with the scanner's obj_info lines, and with only those that describe the grid. */
static void ply_range_grid_seeds(corpus *c) {
    static const char *const info[2] = {"obj_info is_cyberware_data 1\n", ""};
    static const char *const name[2] = {"range_grid.ply", "range_grid_plain.ply"};
    for (int k = 0; k < 2; k++) {
        bytes b = {0};
        put_text(&b, "ply\nformat ascii 1.0\n");
        put_text(&b, info[k]);
        put_text(&b, "obj_info num_cols 3\nobj_info num_rows 2\n");
        put_text(&b, k == 0 ? "obj_info echo_lgincr 0.000500\n" : "");
        put_text(&b, "element vertex 5\nproperty float x\nproperty float y\nproperty float z\n"
                     "element range_grid 6\nproperty list uchar int vertex_indices\nend_header\n"
                     "0 0 0\n1 0 0.1\n2 0 0\n0 1 0\n1 1 0.05\n1 0\n1 1\n1 2\n1 3\n1 4\n0\n");
        emit(c, "ply", name[k], &b);
        bytes_free(&b);
    }
}

static void ply_seeds(corpus *c) {
    ply_ascii_seeds(c);
    ply_range_grid_seeds(c);
    ply_binary_seed(c, "binary_le_float.ply", false, false);
    ply_binary_seed(c, "binary_le_double.ply", false, true);
    ply_binary_seed(c, "binary_be_float.ply", true, false);
    ply_binary_seed(c, "binary_be_double.ply", true, true);
    ply_common_seed(c, "common_le.ply", false);
    ply_common_seed(c, "common_be.ply", true);
}

/* ---- OFF */

static void off_seeds(corpus *c) {
    emit_text(c, "off", "plain.off",
              "OFF\n5 2 0\n0 0 0\n1.5 0 0\n1.5 1.25 0\n0 1.25 -0.5\n0.25 -1 3\n"
              "4 0 1 2 3\n3 0 1 4\n");
    emit_text(c, "off", "comments.off",
              "OFF # a comment\n# another\n\n5 2 6\n0 0 0\n1.5 0 0\n1.5 1.25 0 # end of line\n"
              "0 1.25 -0.5\n0.25 -1 3\n4 0 1 2 3 255 0 0\n3 0 1 4 0.5 0.5 0.5 1\n");
    emit_text(c, "off", "colours.coff",
              "COFF\r\n4 2 0\r\n0 0 0 255 0 0 255\r\n1 0 0 0 255 0 255\r\n"
              "1 1 0 0 0 255 128\r\n0 1 0 9 9 9 255\r\n3 0 1 2\r\n3 0 2 3\r\n");
    emit_text(c, "off", "float_colours.coff",
              "COFF\n4 1 0\n0 0 0 1 0 0 1\n1 0 0 0 1 0 1\n1 1 0 0 0 1 1\n0 1 0 0.5 0.5 0.5 1\n"
              "4 0 1 2 3\n");
    emit_text(c, "off", "normals.noff",
              "NOFF\n3 1 0\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n");
    emit_text(c, "off", "both.cnoff",
              "CNOFF\n3 1 0\n0 0 0 0 0 1 255 0 0 255\n1 0 0 0 0 1 0 255 0 255\n"
              "0 1 0 0 0 1 0 0 255 255\n3 0 1 2\n");
}

/* ---- STL */

/* Two triangles sharing an edge, then one off to the side. */
static const double tri[3][3][3] = {{{0, 0, 0}, {1.5, 0, 0}, {1.5, 1.25, 0}},
                                    {{0, 0, 0}, {1.5, 1.25, 0}, {0, 1.25, -0.5}},
                                    {{0.25, -1, 3}, {2, -1, 3}, {0.25, 1, 3.125}}};

static void stl_binary_seed(corpus *c, const char *name, const char *header,
                            const uint16_t *attributes) {
    bytes b = {0};
    unsigned char head[80];
    memset(head, 0, sizeof head);
    memcpy(head, header, strlen(header));
    put(&b, head, sizeof head);
    put_uint(&b, 3, 4);
    for (int t = 0; t < 3; t++) {
        put_f32(&b, 0);
        put_f32(&b, 0);
        put_f32(&b, 1);
        for (int v = 0; v < 3; v++)
            for (int k = 0; k < 3; k++)
                put_f32(&b, (float)tri[t][v][k]);
        put_uint(&b, attributes ? attributes[t] : 0, 2);
    }
    emit(c, "stl", name, &b);
    bytes_free(&b);
}

static void stl_seeds(corpus *c) {
    bytes b = {0};
    put_text(&b, "solid part one\r\n");
    for (int t = 0; t < 3; t++) {
        put_text(&b, t == 1 ? "FACET Normal 1e0 0 0\r\n  OUTER\tLOOP\r\n"
                            : "  facet normal 0 0 -1\n    outer loop\n");
        for (int v = 0; v < 3; v++) {
            char line[160];
            snprintf(line, sizeof line, "      vertex %.9g %.9g %.9g\r\n", tri[t][v][0],
                     tri[t][v][1], tri[t][v][2]);
            put_text(&b, line);
        }
        put_text(&b, "    endloop\n  endfacet\n");
    }
    put_text(&b, "endsolid part one\r\n");
    emit(c, "stl", "ascii.stl", &b);
    bytes_free(&b);

    emit_text(c, "stl", "solids.stl",
              "solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
              "vertex 0 1 0\nendloop\nendfacet\nendsolid a\nsolid\nendsolid\n"
              "SOLID b\nfacet normal 0 0 0\nouter loop\nvertex 0 0 1e-3\nvertex 1 0 1\n"
              "vertex 0 1 -2.5E2\nendloop\nendfacet\nENDSOLID b\n");
    stl_binary_seed(c, "binary.stl", "binary seed", (const uint16_t[]){0, 0x7c1f, 1});
    stl_binary_seed(c, "binary_solid_header.stl", "solid looks like ascii", NULL);
    stl_binary_seed(c, "binary_blank.stl", "", NULL);
}

/* ---- detection only: byte-order marks, what comes before a keyword, what must be refused */

static const char tetrahedron_obj[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                                      "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
static const char triangle_off[] = "3 1 0\n0 0 0\n1 0 0\n0 1 0.5\n3 0 1 2\n";

static void auto_seeds(corpus *c) {
    emit_auto(c, "bom.obj", true, tetrahedron_obj, true);
    emit_auto(c, "bom_ascii.ply", true,
              "ply\nformat ascii 1.0\ncomment marked\nelement vertex 3\nproperty float x\n"
              "property float y\nproperty float z\nelement face 1\n"
              "property list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
              true);
    emit_auto(c, "bom.off", true, "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0.5\n3 0 1 2\n", true);
    emit_auto(c, "bom_ascii.stl", true,
              "solid marked\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
              "vertex 0 1 0\nendloop\nendfacet\nendsolid marked\n",
              true);
    char text[512];
    static const struct {
        const char *name, *opening;
    } off_openings[] = {{"comment_first.off", "# made by hand\nOFF\n"},
                        {"blank_first.off", "\n\nOFF\n"},
                        {"indented.off", "  \tCOFF\n"},
                        {"lowercase.off", "off\n"}};
    for (size_t i = 0; i < sizeof off_openings / sizeof off_openings[0]; i++) {
        const char *body = strstr(off_openings[i].opening, "COFF")
                               ? "3 1 0\n0 0 0 1 0 0\n1 0 0 0 1 0\n0 1 0 0 0 1\n3 0 1 2\n"
                               : triangle_off;
        snprintf(text, sizeof text, "%s%s", off_openings[i].opening, body);
        emit_auto(c, off_openings[i].name, false, text, true);
    }
    /* refused, each with a location: leading blanks before "ply", 4D and nD OFF, a cut binary
     * STL (the size disagrees with the count), text that is no mesh */
    emit_auto(c, "indented.ply", false,
              " ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
              "property float z\nend_header\n0 0 0\n",
              false);
    snprintf(text, sizeof text, "4OFF\n%s", "3 1 0\n0 0 0 1\n1 0 0 1\n0 1 0 1\n3 0 1 2\n");
    emit_auto(c, "four.off", false, text, false);
    emit_auto(c, "dimension.off", false, "nOFF\n4\n3 1 0\n0 0 0 0\n1 0 0 0\n0 1 0 0\n3 0 1 2\n",
              false);
    emit_auto(c, "no_mesh.txt", false, "hello world\n", false);
    /* what the readers refuse since the hostile-input campaign: a comment before an ascii STL's
     * "solid", a value too many on an OFF line, content after the declared faces, data after a
     * PLY file's last element (ascii here, binary below); and what they still read: comments after
     * an OFF file's faces, a face's colormap index, a line end after a PLY file's data */
    emit_auto(c, "comment_first.stl", false,
              "# made by hand\nsolid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n"
              "vertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid t\n",
              false);
    emit_auto(c, "extra_value.off", false, "OFF\n3 1 0\n0 0 0\n0 1 0 7\n1 0 0\n3 0 1 2\n", false);
    emit_auto(c, "more_faces.off", false, "OFF\n3 1 0\n0 0 0\n0 1 0\n1 0 0\n3 0 1 2\n3 0 2 1\n",
              false);
    emit_auto(c, "tail_comment.off", false,
              "OFF\n3 1 0\n0 0 0\n0 1 0\n1 0 0\n3 0 1 2 7\n# the end\n", true);
    emit_auto(c, "more_faces.ply", false,
              "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
              "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
              "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 2 1\n",
              false);
    bytes b = {0};
    unsigned char head[80];
    memset(head, ' ', sizeof head);
    put(&b, head, sizeof head);
    put_uint(&b, 2, 4);
    for (int k = 0; k < 20; k++) /* 80 bytes: short of the 2 * 50 the count needs */
        put_f32(&b, (float)k);
    write_seed(c, "auto", "cut_binary.stl", &b);
    check_seed(c, "auto", "cut_binary.stl", &b, RSMOOTH_FORMAT_AUTO, false);
    bytes_free(&b);
    static const char binary_ply[] = "ply\nformat binary_little_endian 1.0\nelement vertex 3\n"
                                     "property float x\nproperty float y\nproperty float z\n"
                                     "element face 1\nproperty list uchar int vertex_indices\n"
                                     "end_header\n";
    for (int extra = 0; extra < 2; extra++) {
        put_text(&b, binary_ply);
        for (int k = 0; k < 9; k++)
            put_f32(&b, k == 3 || k == 7 ? 1.0f : 0.0f);
        for (int face = 0; face < 1 + extra; face++) { /* the header counts one */
            put_uint(&b, 3, 1);
            for (uint32_t v = 0; v < 3; v++)
                put_uint(&b, face ? 2 - v : v, 4);
        }
        put_text(&b, "\n");
        const char *name = extra ? "more_faces_binary.ply" : "line_end_binary.ply";
        write_seed(c, "auto", name, &b);
        check_seed(c, "auto", name, &b, RSMOOTH_FORMAT_AUTO, !extra);
        bytes_free(&b);
    }
}

/* ---- main */

static void make_dir(const char *path) {
    if (mkdir(path, 0777) != 0 && errno != EEXIST) {
        fprintf(stderr, "make_seed_corpus: cannot create '%s': %s\n", path, strerror(errno));
        exit(1);
    }
}

static const char *const kinds[] = {"obj", "ply", "off", "stl", "auto"};

static void remove_corpus(corpus *c) {
    for (int i = 0; i < c->written && i < MAX_SEEDS; i++)
        if (c->paths[i])
            unlink(c->paths[i]);
    for (size_t k = 0; k < sizeof kinds / sizeof kinds[0]; k++) {
        char sub[4096];
        snprintf(sub, sizeof sub, "%s/%s", c->dir, kinds[k]);
        rmdir(sub);
    }
    rmdir(c->dir);
}

int main(int argc, char **argv) {
    if (argc > 2) {
        fprintf(stderr, "usage: %s [DIR]\n", argv[0]);
        return 2;
    }
    char temp[] = "/tmp/rsmooth-seed-corpus-XXXXXX";
    corpus c = {.dir = argc == 2 ? argv[1] : mkdtemp(temp)};
    if (!c.dir) {
        fprintf(stderr, "make_seed_corpus: cannot create a temporary directory: %s\n",
                strerror(errno));
        return 1;
    }
    make_dir(c.dir);
    for (size_t k = 0; k < sizeof kinds / sizeof kinds[0]; k++) {
        char sub[4096];
        snprintf(sub, sizeof sub, "%s/%s", c.dir, kinds[k]);
        make_dir(sub);
    }
    obj_seeds(&c);
    ply_seeds(&c);
    off_seeds(&c);
    stl_seeds(&c);
    auto_seeds(&c);
    printf("%d seed files in %s, %d failed to parse\n", c.written, c.dir, c.failed);
    if (argc < 2)
        remove_corpus(&c);
    for (int i = 0; i < c.written && i < MAX_SEEDS; i++)
        free(c.paths[i]);
    return c.failed || c.written > MAX_SEEDS ? 1 : 0;
}
