/* Point clouds in files: vertex normals read as values (PLY nx ny nz, NOFF, OBJ vn), files with no
 * faces, and normals written back as the mesh holds them (a cloud has no faces to recompute them
 * from): exactly through ascii PLY, within float through float binary PLY. */
#define _POSIX_C_SOURCE 200809L
#include "rsmooth_io.h"
#include "test_io_util.h"

#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <string.h>

enum { N = 50 };

/* Positions and normals of the cloud, with digits no float holds exactly. */
static void cloud_values(double xyz[3 * N], double nrm[3 * N]) {
    for (int i = 0; i < N; i++) {
        double t = 0.1234567890123 * (i + 1);
        xyz[3 * i] = cos(t), xyz[3 * i + 1] = sin(t), xyz[3 * i + 2] = 0.001 * i;
        nrm[3 * i] = cos(t) * 0.987654321, nrm[3 * i + 1] = sin(t) * 0.987654321;
        nrm[3 * i + 2] = 0.156434465040231 + 1e-12 * i;
    }
}

static rsmooth_mesh *read_ok(const void *data, size_t size) {
    rsmooth_mesh *mesh = NULL;
    rsmooth_error err;
    rsmooth_status s = rsmooth_mesh_read_memory(data, size, RSMOOTH_FORMAT_AUTO, &mesh, &err);
    if (s != RSMOOTH_OK)
        fprintf(stderr, "read: %s (line %lld, byte %lld)\n", err.message, (long long)err.line,
                (long long)err.byte_offset);
    CHECK_EQ_INT(s, RSMOOTH_OK);
    return mesh;
}

static rsmooth_mesh *write_and_read(const rsmooth_mesh *mesh, rsmooth_format format) {
    size_t size = 0;
    void *data = mesh_to_memory(mesh, format, &size);
    rsmooth_mesh *back = read_ok(data, size);
    free(data);
    return back;
}

/* Every normal of `m` equals `want` (converted to float first when `as_float`). */
static void check_normals(const rsmooth_mesh *m, const double *want, bool as_float) {
    CHECK(m->vertex_normals != NULL);
    CHECK(m->has_vertex_normals);
    for (size_t i = 0; i < 3 * m->vertex_count; i++) {
        double w = as_float ? (double)(float)want[i] : want[i];
        if (m->vertex_normals[i] != w) {
            fprintf(stderr, "normal value %zu: %.17g, expected %.17g\n", i, m->vertex_normals[i],
                    w);
            exit(1);
        }
    }
}

/* A PLY cloud as scanners write it: x y z nx ny nz and a colour, no face element (or, with
 * `empty_faces`, a face element of 0 faces); `type` float or double. */
static bytes ply_cloud(const char *type, bool binary, bool empty_faces, const double *xyz,
                       const double *nrm) {
    bytes b = {0};
    char line[256];
    put_text(&b, binary ? "ply\nformat binary_little_endian 1.0\n" : "ply\nformat ascii 1.0\n");
    snprintf(line, sizeof line,
             "comment a scan\nelement vertex %d\nproperty %s x\nproperty %s y\nproperty %s z\n"
             "property %s nx\nproperty %s ny\nproperty %s nz\nproperty uchar red\n"
             "property uchar green\nproperty uchar blue\n",
             N, type, type, type, type, type, type);
    put_text(&b, line);
    if (empty_faces)
        put_text(&b, "element face 0\nproperty list uchar int vertex_indices\n");
    put_text(&b, "end_header\n");
    bool f32 = !strcmp(type, "float");
    for (int i = 0; i < N; i++) {
        for (int set = 0; set < 2; set++)
            for (int k = 0; k < 3; k++) {
                double v = (set ? nrm : xyz)[3 * i + k];
                if (binary && f32)
                    put_f32(&b, (float)v);
                else if (binary)
                    put_f64(&b, v);
                else {
                    snprintf(line, sizeof line, "%.17g ", v);
                    put_text(&b, line);
                }
            }
        if (binary) {
            put_u8(&b, (unsigned)i), put_u8(&b, 7), put_u8(&b, 200);
        } else {
            snprintf(line, sizeof line, "%d 7 200\n", i);
            put_text(&b, line);
        }
    }
    return b;
}

static void test_ply(void) {
    double xyz[3 * N], nrm[3 * N];
    cloud_values(xyz, nrm);
    for (int variant = 0; variant < 8; variant++) {
        bool binary = variant & 1, f32 = variant & 2, empty_faces = variant & 4;
        bytes b = ply_cloud(f32 ? "float" : "double", binary, empty_faces, xyz, nrm);
        rsmooth_mesh *m = read_ok(b.data, b.size);
        CHECK_EQ_INT(m->vertex_count, N);
        CHECK_EQ_INT(m->face_count, 0);
        CHECK_EQ_INT(m->triangle_count, 0);
        check_normals(m, nrm, f32);
        CHECK(m->vertex_colors && m->vertex_colors[3 * 5] == 5);
        /* Written back in the input's layout and types: exactly what was read, both encodings. */
        for (int out = 0; out < 2; out++) {
            rsmooth_mesh *back =
                write_and_read(m, out ? RSMOOTH_FORMAT_PLY_BINARY : RSMOOTH_FORMAT_PLY_ASCII);
            CHECK_EQ_INT(back->face_count, 0);
            check_normals(back, m->vertex_normals, false);
            CHECK(back->vertex_colors && back->vertex_colors[3 * 9 + 2] == 200);
            rsmooth_mesh_destroy(back);
        }
        /* Filtered normals replace the read ones (the command does this). */
        for (int i = 0; i < 3 * N; i++)
            m->vertex_normals[i] = -m->vertex_normals[i];
        rsmooth_mesh *back = write_and_read(m, RSMOOTH_FORMAT_PLY_ASCII);
        check_normals(back, m->vertex_normals, false);
        rsmooth_mesh_destroy(back);
        rsmooth_mesh_destroy(m);
        bytes_free(&b);
    }
    /* Big-endian input reads the same values. */
    bytes be = {.big_endian = true};
    put_text(&be, "ply\nformat binary_big_endian 1.0\nelement vertex 2\nproperty float x\n"
                  "property float y\nproperty float z\nproperty double nx\nproperty double ny\n"
                  "property double nz\nend_header\n");
    for (int i = 0; i < 2; i++) {
        for (int k = 0; k < 3; k++)
            put_f32(&be, (float)xyz[3 * i + k]);
        for (int k = 0; k < 3; k++)
            put_f64(&be, nrm[3 * i + k]);
    }
    rsmooth_mesh *m = read_ok(be.data, be.size);
    CHECK_EQ_INT(m->vertex_count, 2);
    for (int i = 0; i < 6; i++)
        CHECK(m->vertex_normals[i] == nrm[i]);
    rsmooth_mesh_destroy(m);
    bytes_free(&be);
}

/* A cloud built by a caller (the generic writer): double precision is exact, float within float. */
static void test_generic(void) {
    double xyz[3 * N], nrm[3 * N];
    cloud_values(xyz, nrm);
    for (int precision = 0; precision < 2; precision++)
        for (int out = 0; out < 2; out++) {
            rsmooth_mesh *m = NULL;
            CHECK_EQ_INT(rsmooth_mesh_create(N, 0, 0, &m, NULL), RSMOOTH_OK);
            memcpy(m->positions, xyz, sizeof xyz);
            m->precision = precision ? RSMOOTH_FLOAT32 : RSMOOTH_FLOAT64;
            m->has_vertex_normals = 1;
            m->vertex_normals = malloc(sizeof nrm);
            CHECK(m->vertex_normals);
            memcpy(m->vertex_normals, nrm, sizeof nrm);
            rsmooth_mesh *back =
                write_and_read(m, out ? RSMOOTH_FORMAT_PLY_BINARY : RSMOOTH_FORMAT_PLY_ASCII);
            CHECK_EQ_INT(back->vertex_count, N);
            check_normals(back, nrm, precision == 1);
            rsmooth_mesh_destroy(back);
            /* OFF (NOFF) and OBJ (vn, no faces) carry them too, as decimal text. */
            back = write_and_read(m, RSMOOTH_FORMAT_OFF);
            CHECK_EQ_INT(back->face_count, 0);
            for (int i = 0; i < 3 * N; i++)
                CHECK_NEAR(back->vertex_normals[i], nrm[i], 1e-6);
            rsmooth_mesh_destroy(back);
            back = write_and_read(m, RSMOOTH_FORMAT_OBJ);
            CHECK_EQ_INT(back->face_count, 0);
            for (int i = 0; i < 3 * N; i++)
                CHECK_NEAR(back->vertex_normals[i], nrm[i], 1e-6);
            rsmooth_mesh_destroy(back);
            rsmooth_mesh_destroy(m);
        }
}

/* A mesh with faces still writes normals recomputed from its positions; its read normals are
 * there to read. */
static void test_mesh_normals_recomputed(void) {
    const char *text =
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nproperty float nx\nproperty float ny\nproperty float nz\n"
        "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
        "0 0 0 1 0 0\n1 0 0 1 0 0\n0 1 0 1 0 0\n3 0 1 2\n";
    rsmooth_mesh *m = read_ok(text, strlen(text));
    CHECK_EQ_INT(m->triangle_count, 1);
    CHECK(m->vertex_normals && m->vertex_normals[0] == 1 && m->vertex_normals[2] == 0);
    rsmooth_mesh *back = write_and_read(m, RSMOOTH_FORMAT_PLY_ASCII);
    for (int v = 0; v < 3; v++) /* the triangle's normal, +z: not the file's +x */
        CHECK(back->vertex_normals[3 * v] == 0 && back->vertex_normals[3 * v + 2] == 1);
    rsmooth_mesh_destroy(back);
    rsmooth_mesh_destroy(m);
}

/* OFF's NOFF and OBJ's vn, read as values. An OBJ with faces, or with a vn count unlike the v
 * count, has no per-vertex normals to give. */
static void test_off_obj(void) {
    const char *noff = "NOFF\n3 0 0\n0 0 0 0.6 0 0.8\n1 0 0 0 1 0\n0 1 0 0 0 -1\n";
    rsmooth_mesh *m = read_ok(noff, strlen(noff));
    CHECK_EQ_INT(m->vertex_count, 3);
    CHECK(m->vertex_normals && m->vertex_normals[0] == 0.6 && m->vertex_normals[2] == 0.8 &&
          m->vertex_normals[8] == -1);
    rsmooth_mesh_destroy(m);
    const char *obj = "# cloud\nv 0 0 0\nvn 0 0 1\nv 1 0 0\nvn 0.6 0.8 0\nv 2 0 0\nvn 0 -1 0\n";
    m = read_ok(obj, strlen(obj));
    CHECK_EQ_INT(m->vertex_count, 3);
    CHECK(m->vertex_normals && m->vertex_normals[2] == 1 && m->vertex_normals[3] == 0.6 &&
          m->vertex_normals[7] == -1);
    rsmooth_mesh_destroy(m);
    const char *fewer = "v 0 0 0\nv 1 0 0\nvn 0 0 1\n";
    m = read_ok(fewer, strlen(fewer));
    CHECK(m->has_vertex_normals && m->vertex_normals == NULL);
    /* Normals that match no vertex are no normals to write: OBJ keeps the lines as they were,
     * other formats invent none (they read back without normals) and say they drop them. */
    size_t size;
    char *out = mesh_to_memory(m, RSMOOTH_FORMAT_OBJ, &size);
    CHECK_EQ_INT(size, strlen(fewer));
    CHECK(memcmp(out, fewer, size) == 0);
    free(out);
    const rsmooth_format others[] = {RSMOOTH_FORMAT_PLY_ASCII, RSMOOTH_FORMAT_PLY_BINARY,
                                     RSMOOTH_FORMAT_OFF};
    for (size_t i = 0; i < sizeof others / sizeof others[0]; i++) {
        char lost[128];
        CHECK_EQ_INT(rsmooth_mesh_conversion_losses(m, others[i], lost, sizeof lost), 1);
        CHECK(strcmp(lost, "vertex normals") == 0);
        out = mesh_to_memory(m, others[i], &size);
        rsmooth_mesh *back = read_ok(out, size);
        CHECK(!back->has_vertex_normals && back->vertex_normals == NULL);
        rsmooth_mesh_destroy(back);
        free(out);
    }
    CHECK_EQ_INT(rsmooth_mesh_conversion_losses(m, RSMOOTH_FORMAT_OBJ, NULL, 0), 0);
    rsmooth_mesh_destroy(m);
    const char *faces = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1\n";
    m = read_ok(faces, strlen(faces));
    CHECK(m->vertex_normals == NULL);
    rsmooth_mesh_destroy(m);
}

int main(void) {
    test_ply();
    test_generic();
    test_mesh_normals_recomputed();
    test_off_obj();
    printf("points_io: all checks passed\n");
    return 0;
}
