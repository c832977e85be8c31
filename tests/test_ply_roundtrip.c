/* PLY round trips that keep everything: comments, every property and element, types, polygons. */
#define _POSIX_C_SOURCE 200809L
#include "rsmooth_io.h"
#include "test_io_util.h"

#include <stdbool.h>
#include <stdint.h>
#include <string.h>

/* ---- a small independent PLY reader: header lines, and every value as a double */

enum { T_ASCII, T_LE, T_BE };

typedef struct tprop {
    char name[64], type[64], count_type[64]; /* count_type empty for a scalar */
} tprop;

typedef struct telem {
    char name[64];
    size_t count, nprops;
    tprop props[32];
    double *values; /* file order; a list is its count then its items */
    size_t nvalues, cap;
} telem;

typedef struct tply {
    char lines[64][128]; /* header lines without line ends */
    size_t nlines;
    int format;
    telem elems[8];
    size_t nelems;
} tply;

static size_t tsize(const char *type, bool *is_signed, bool *is_float) {
    static const struct {
        const char *a, *b;
        size_t size;
        bool sign, flt;
    } t[] = {{"char", "int8", 1, true, false},    {"uchar", "uint8", 1, false, false},
             {"short", "int16", 2, true, false},  {"ushort", "uint16", 2, false, false},
             {"int", "int32", 4, true, false},    {"uint", "uint32", 4, false, false},
             {"float", "float32", 4, true, true}, {"double", "float64", 8, true, true}};
    for (size_t i = 0; i < sizeof t / sizeof t[0]; i++) {
        if (!strcmp(type, t[i].a) || !strcmp(type, t[i].b)) {
            *is_signed = t[i].sign;
            *is_float = t[i].flt;
            return t[i].size;
        }
    }
    fprintf(stderr, "test: unknown type %s\n", type);
    exit(1);
}

static void tpush(telem *e, double v) {
    if (e->nvalues == e->cap) {
        e->cap = 2 * e->cap + 64;
        e->values = realloc(e->values, e->cap * sizeof *e->values);
        CHECK(e->values != NULL);
    }
    e->values[e->nvalues++] = v;
}

static double tread(const unsigned char *data, size_t size, size_t *pos, int format,
                    const char *type) {
    bool sign, flt;
    size_t n = tsize(type, &sign, &flt);
    if (format == T_ASCII) {
        while (*pos < size && strchr(" \t\r\n", data[*pos]))
            (*pos)++;
        CHECK(*pos < size);
        char buf[64];
        size_t len = 0;
        while (*pos < size && !strchr(" \t\r\n", data[*pos]) && len < sizeof buf - 1)
            buf[len++] = (char)data[(*pos)++];
        buf[len] = '\0';
        char *end;
        double v = strtod(buf, &end);
        CHECK(*end == '\0');
        return n == 4 && flt ? (double)(float)v : v;
    }
    CHECK(*pos + n <= size);
    uint64_t u = 0;
    for (size_t i = 0; i < n; i++)
        u |= (uint64_t)data[*pos + (format == T_BE ? n - 1 - i : i)] << (8 * i);
    *pos += n;
    if (flt && n == 4) {
        uint32_t u32 = (uint32_t)u;
        float f;
        memcpy(&f, &u32, 4);
        return f;
    }
    if (flt) {
        double d;
        memcpy(&d, &u, 8);
        return d;
    }
    if (sign && (u >> (8 * n - 1)))
        return (double)(int64_t)(u | ~(uint64_t)0 << (8 * n - 1));
    return (double)u;
}

static tply *tparse(const unsigned char *data, size_t size) {
    tply *p = calloc(1, sizeof *p);
    CHECK(p != NULL);
    size_t pos = 0;
    for (;;) {
        const unsigned char *eol = memchr(data + pos, '\n', size - pos);
        CHECK(eol != NULL);
        size_t len = (size_t)(eol - (data + pos));
        if (len > 0 && data[pos + len - 1] == '\r')
            len--;
        CHECK(len < 128 && p->nlines < 64);
        char *line = p->lines[p->nlines++];
        memcpy(line, data + pos, len);
        line[len] = '\0';
        pos = (size_t)(eol - data) + 1;
        char a[64], b[64], c[64], d[64];
        if (!strcmp(line, "end_header"))
            break;
        if (sscanf(line, "format %63s", a) == 1) {
            p->format = !strcmp(a, "ascii")               ? T_ASCII
                        : !strcmp(a, "binary_big_endian") ? T_BE
                                                          : T_LE;
        } else if (sscanf(line, "element %63s %63s", a, b) == 2) {
            telem *e = &p->elems[p->nelems++];
            snprintf(e->name, sizeof e->name, "%s", a);
            e->count = strtoul(b, NULL, 10);
        } else if (sscanf(line, "property list %63s %63s %63s", a, b, c) == 3) {
            tprop *q = &p->elems[p->nelems - 1].props[p->elems[p->nelems - 1].nprops++];
            snprintf(q->count_type, sizeof q->count_type, "%s", a);
            snprintf(q->type, sizeof q->type, "%s", b);
            snprintf(q->name, sizeof q->name, "%s", c);
        } else if (sscanf(line, "property %63s %63s %63s", a, b, d) == 2) {
            tprop *q = &p->elems[p->nelems - 1].props[p->elems[p->nelems - 1].nprops++];
            snprintf(q->type, sizeof q->type, "%s", a);
            snprintf(q->name, sizeof q->name, "%s", b);
        }
    }
    for (size_t ei = 0; ei < p->nelems; ei++) {
        telem *e = &p->elems[ei];
        for (size_t i = 0; i < e->count; i++) {
            for (size_t k = 0; k < e->nprops; k++) {
                const tprop *q = &e->props[k];
                if (!q->count_type[0]) {
                    tpush(e, tread(data, size, &pos, p->format, q->type));
                    continue;
                }
                double n = tread(data, size, &pos, p->format, q->count_type);
                tpush(e, n);
                for (size_t j = 0; j < (size_t)n; j++)
                    tpush(e, tread(data, size, &pos, p->format, q->type));
            }
        }
    }
    if (p->format == T_ASCII)
        while (pos < size && strchr(" \t\r\n", data[pos]))
            pos++;
    CHECK_EQ_INT(pos, size); /* nothing left over */
    return p;
}

static void tfree(tply *p) {
    for (size_t ei = 0; ei < p->nelems; ei++)
        free(p->elems[ei].values);
    free(p);
}

static size_t tprop_index(const telem *e, const char *name) {
    for (size_t k = 0; k < e->nprops; k++)
        if (!strcmp(e->props[k].name, name))
            return k;
    return SIZE_MAX;
}

/* ---- the rich file */

#define NV 6
#define NF 3

static const float positions[NV][3] = {{0, 0, 0},         {1.5f, 0, 0},   {1.5f, 1.25f, 0},
                                       {0, 1.25f, -0.5f}, {0.25f, -1, 3}, {2, 0.5f, 0.125f}};
static const float quality[NV] = {0.1f, 1e-30f, -3.4e38f, 1.0f / 3, 7, 0};
static const int32_t labels[NV] = {-7, 0, 2147483647, -2147483647 - 1, 12, 99};
static const uint32_t faces[][5] = {{4, 0, 1, 2, 3}, {3, 0, 1, 4}, {3, 1, 5, 2}};
static const unsigned flags[NF] = {1, 128, 255};

/* Writes one value of a type in an encoding. */
static void put_value(bytes *b, int format, const char *type, double v) {
    bool sign, flt;
    size_t n = tsize(type, &sign, &flt);
    if (format == T_ASCII) {
        char text[64];
        if (flt)
            snprintf(text, sizeof text, " %.17g", v);
        else
            snprintf(text, sizeof text, " %lld", (long long)v);
        put_text(b, text);
        return;
    }
    uint64_t u;
    if (flt && n == 4) {
        float f = (float)v;
        uint32_t u32;
        memcpy(&u32, &f, 4);
        u = u32;
    } else if (flt) {
        memcpy(&u, &v, 8);
    } else {
        u = (uint64_t)(int64_t)v;
    }
    unsigned char tmp[8];
    for (size_t i = 0; i < n; i++)
        tmp[format == T_BE ? n - 1 - i : i] = (unsigned char)(u >> (8 * i));
    put(b, tmp, n);
}

static void end_line(bytes *b, int format) {
    if (format == T_ASCII)
        put_text(b, "\n");
}

static bytes rich_file(int format) {
    bytes b = {0};
    put_text(&b, "ply\n");
    put_text(&b, format == T_ASCII ? "format ascii 1.0\n"
                 : format == T_LE  ? "format binary_little_endian 1.0\n"
                                   : "format binary_big_endian 1.0\n");
    put_text(&b, "comment made by test_ply_roundtrip\n"
                 "obj_info scanner 1  (two spaces kept)\n"
                 "element vertex 6\n"
                 "property float x\nproperty float y\nproperty float z\n"
                 "property float nx\nproperty float ny\nproperty float nz\n"
                 "property uchar red\nproperty uchar green\nproperty uchar blue\n"
                 "property uchar alpha\n"
                 "property float quality\n"
                 "property float32 u\nproperty float32 v\n"
                 "property int label\n"
                 "element face 3\n"
                 "property list uchar int vertex_indices\n"
                 "property uchar flags\n"
                 "comment before the material\n"
                 "element material 2\n"
                 "property list uchar ushort ids\n"
                 "property float shininess\n"
                 "end_header\n");
    for (int i = 0; i < NV; i++) {
        for (int c = 0; c < 3; c++)
            put_value(&b, format, "float", positions[i][c]);
        put_value(&b, format, "float", 0.25);
        put_value(&b, format, "float", -0.5);
        put_value(&b, format, "float", 1);
        put_value(&b, format, "uchar", 10 * i);
        put_value(&b, format, "uchar", 255 - i);
        put_value(&b, format, "uchar", 128);
        put_value(&b, format, "uchar", 200 + i);
        put_value(&b, format, "float", quality[i]);
        put_value(&b, format, "float", (float)i / 3);
        put_value(&b, format, "float", 1 - (float)i / 7);
        put_value(&b, format, "int", labels[i]);
        end_line(&b, format);
    }
    for (int f = 0; f < NF; f++) {
        put_value(&b, format, "uchar", faces[f][0]);
        for (uint32_t k = 1; k <= faces[f][0]; k++)
            put_value(&b, format, "int", faces[f][k]);
        put_value(&b, format, "uchar", flags[f]);
        end_line(&b, format);
    }
    put_value(&b, format, "uchar", 3);
    put_value(&b, format, "ushort", 1);
    put_value(&b, format, "ushort", 65535);
    put_value(&b, format, "ushort", 0);
    put_value(&b, format, "float", 0.7);
    end_line(&b, format);
    put_value(&b, format, "uchar", 0);
    put_value(&b, format, "float", -1e-40); /* a subnormal float */
    end_line(&b, format);
    return b;
}

/* ---- helpers */

static rsmooth_mesh *read_ok(const void *data, size_t size) {
    void *copy = malloc(size ? size : 1); /* exactly `size` bytes: ASan catches over-reads */
    CHECK(copy != NULL);
    memcpy(copy, data, size);
    rsmooth_mesh *mesh = NULL;
    rsmooth_error err;
    rsmooth_status s = rsmooth_mesh_read_memory(copy, size, RSMOOTH_FORMAT_AUTO, &mesh, &err);
    if (s != RSMOOTH_OK)
        fprintf(stderr, "read: %s (line %lld byte %lld)\n", err.message, (long long)err.line,
                (long long)err.byte_offset);
    CHECK_EQ_INT(s, RSMOOTH_OK);
    free(copy);
    return mesh;
}

static bool same_bits(double a, double b) {
    return memcmp(&a, &b, sizeof a) == 0;
}

/* `out` holds what `in` held, except positions (the mesh's, as floats) and normals (recomputed). */
static void check_faithful(const tply *in, const tply *out, const rsmooth_mesh *mesh) {
    size_t li = 0, lo = 0;
    for (; li < in->nlines && lo < out->nlines; li++, lo++) {
        if (!strncmp(in->lines[li], "format ", 7)) {
            CHECK(!strncmp(out->lines[lo], "format ", 7));
            continue;
        }
        if (strcmp(in->lines[li], out->lines[lo]) != 0) {
            fprintf(stderr, "header line %zu: '%s' read, '%s' written\n", li, in->lines[li],
                    out->lines[lo]);
            exit(1);
        }
    }
    CHECK_EQ_INT(li, in->nlines);
    CHECK_EQ_INT(lo, out->nlines);
    double *normals = malloc(3 * mesh->vertex_count * sizeof *normals);
    CHECK(normals != NULL);
    rsmooth_error err;
    CHECK_EQ_INT(rsmooth_mesh_vertex_normals(mesh, normals, &err), RSMOOTH_OK);
    CHECK_EQ_INT(in->nelems, out->nelems);
    for (size_t ei = 0; ei < in->nelems; ei++) {
        const telem *a = &in->elems[ei], *b = &out->elems[ei];
        CHECK(!strcmp(a->name, b->name));
        CHECK_EQ_INT(a->count, b->count);
        CHECK_EQ_INT(a->nvalues, b->nvalues);
        bool vertex = !strcmp(a->name, "vertex");
        size_t at = 0;
        for (size_t i = 0; i < a->count; i++) {
            for (size_t k = 0; k < a->nprops; k++) {
                const char *name = a->props[k].name;
                size_t n = 1;
                if (a->props[k].count_type[0]) {
                    CHECK(same_bits(a->values[at], b->values[at]));
                    n += (size_t)a->values[at];
                }
                for (size_t j = 0; j < n; j++, at++) {
                    double expected = a->values[at];
                    bool f32 =
                        !strcmp(a->props[k].type, "float") || !strcmp(a->props[k].type, "float32");
                    if (vertex && strlen(name) == 1 && strchr("xyz", name[0]))
                        expected = mesh->positions[3 * i + (size_t)(name[0] - 'x')];
                    else if (vertex && strlen(name) == 2 && name[0] == 'n' &&
                             strchr("xyz", name[1]))
                        expected = normals[3 * i + (size_t)(name[1] - 'x')];
                    else
                        f32 = false; /* kept values compare as read */
                    if (f32)
                        expected = (float)expected;
                    if (!same_bits(expected, b->values[at])) {
                        fprintf(stderr,
                                "element %s item %zu property %s: %.17g expected, %.17g written\n",
                                a->name, i, name, expected, b->values[at]);
                        exit(1);
                    }
                }
            }
        }
    }
    free(normals);
}

/* ---- tests */

static void test_rich_round_trip(void) {
    for (int format = T_ASCII; format <= T_BE; format++) {
        bytes file = rich_file(format);
        tply *in = tparse(file.data, file.size);
        rsmooth_mesh *m = read_ok(file.data, file.size);
        CHECK_EQ_INT(m->vertex_count, NV);
        CHECK_EQ_INT(m->face_count, NF);
        CHECK_EQ_INT(m->triangle_count, 4);
        CHECK_EQ_INT(m->has_vertex_normals, 1);
        CHECK(m->vertex_colors != NULL);
        for (int i = 0; i < NV; i++) {
            CHECK_EQ_INT(m->vertex_colors[3 * i], 10 * i);
            CHECK_EQ_INT(m->vertex_colors[3 * i + 1], 255 - i);
            CHECK_EQ_INT(m->vertex_colors[3 * i + 2], 128);
        }
        CHECK(m->extras != NULL);

        /* What converting to OBJ drops, and what not. */
        char lost[512];
        size_t n = rsmooth_mesh_conversion_losses(m, RSMOOTH_FORMAT_OBJ, lost, sizeof lost);
        CHECK(n >= 4);
        CHECK(strstr(lost, "'quality'") != NULL);
        CHECK(strstr(lost, "'flags'") != NULL);
        CHECK(strstr(lost, "'material'") != NULL);
        CHECK(strstr(lost, "'alpha'") != NULL);
        CHECK(strstr(lost, "comments") != NULL);
        CHECK(strstr(lost, "red") == NULL && strstr(lost, "'nx'") == NULL);
        CHECK_EQ_INT(
            rsmooth_mesh_conversion_losses(m, RSMOOTH_FORMAT_PLY_BINARY, lost, sizeof lost), 0);

        for (size_t i = 0; i < 3 * m->vertex_count; i++)
            m->positions[i] = (float)(m->positions[i] + 0.5 + 0.001 * (double)i); /* see below */
        const rsmooth_format outputs[2] = {RSMOOTH_FORMAT_PLY_ASCII, RSMOOTH_FORMAT_PLY_BINARY};
        for (int o = 0; o < 2; o++) {
            bytes written = {0};
            written.data = mesh_to_memory(m, outputs[o], &written.size);
            tply *out = tparse(written.data, written.size);
            CHECK_EQ_INT(out->format, o == 0 ? T_ASCII : T_LE);
            check_faithful(in, out, m);
            /* And the library reads its own output back to the same mesh. */
            rsmooth_mesh *back = read_ok(written.data, written.size);
            CHECK_EQ_INT(back->source_format, outputs[o]);
            CHECK_EQ_INT(back->face_count, NF);
            for (size_t f = 0; f <= NF; f++)
                CHECK_EQ_INT(back->face_offsets[f], m->face_offsets[f]);
            for (size_t k = 0; k < m->face_offsets[NF]; k++)
                CHECK_EQ_INT(back->face_indices[k], m->face_indices[k]);
            for (size_t i = 0; i < 3 * m->vertex_count; i++)
                CHECK(same_bits(back->positions[i], (float)m->positions[i]));
            CHECK_EQ_INT(memcmp(back->vertex_colors, m->vertex_colors, 3 * NV), 0);
            /* Writing the re-read mesh again gives the same bytes (the positions were floats, so
             * the normals come out the same). */
            bytes again = {0};
            again.data = mesh_to_memory(back, outputs[o], &again.size);
            CHECK_EQ_INT(again.size, written.size);
            CHECK_EQ_INT(memcmp(again.data, written.data, written.size), 0);
            bytes_free(&again);
            rsmooth_mesh_destroy(back);
            tfree(out);
            bytes_free(&written);
        }

        /* Caller fields do not override the extras; without extras they are written. */
        m->vertex_quality = calloc(NV, sizeof(float));
        CHECK(m->vertex_quality != NULL);
        bytes written = {0};
        written.data = mesh_to_memory(m, RSMOOTH_FORMAT_PLY_BINARY, &written.size);
        tply *out = tparse(written.data, written.size);
        check_faithful(in, out, m);
        tfree(out);
        bytes_free(&written);

        /* Fewer faces than the file had: the generic layout, with recomputed normals. */
        m->face_count--;
        m->triangle_count--;
        written.data = mesh_to_memory(m, RSMOOTH_FORMAT_PLY_ASCII, &written.size);
        out = tparse(written.data, written.size);
        CHECK(!strcmp(out->lines[2], "comment written by rsmooth"));
        const telem *v = &out->elems[0];
        CHECK(tprop_index(v, "nx") != SIZE_MAX && tprop_index(v, "quality") != SIZE_MAX &&
              tprop_index(v, "red") != SIZE_MAX && tprop_index(v, "label") == SIZE_MAX);
        CHECK_EQ_INT(out->elems[1].count, NF - 1);
        tfree(out);
        bytes_free(&written);
        m->face_count++;
        m->triangle_count++;

        rsmooth_mesh_destroy(m);
        tfree(in);
        bytes_free(&file);
    }
}

/* The big-endian file writes as little-endian with the same values as the little-endian file. */
static void test_big_endian_as_little(void) {
    bytes le = rich_file(T_LE), be = rich_file(T_BE);
    rsmooth_mesh *a = read_ok(le.data, le.size), *b = read_ok(be.data, be.size);
    bytes wa = {0}, wb = {0};
    wa.data = mesh_to_memory(a, RSMOOTH_FORMAT_PLY_BINARY, &wa.size);
    wb.data = mesh_to_memory(b, RSMOOTH_FORMAT_PLY_BINARY, &wb.size);
    CHECK_EQ_INT(wa.size, wb.size);
    CHECK_EQ_INT(memcmp(wa.data, wb.data, wa.size), 0);
    /* And that is the little-endian input itself (normals recomputed from these positions). */
    tply *in = tparse(le.data, le.size), *out = tparse(wb.data, wb.size);
    check_faithful(in, out, b);
    tfree(in);
    tfree(out);
    bytes_free(&wa);
    bytes_free(&wb);
    rsmooth_mesh_destroy(a);
    rsmooth_mesh_destroy(b);
    bytes_free(&le);
    bytes_free(&be);
}

static void test_plain(void) {
    const char *text = "ply\nformat ascii 1.0\ncomment written by rsmooth\nelement vertex 3\n"
                       "property float x\nproperty float y\nproperty float z\n"
                       "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                       "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    rsmooth_mesh *m = read_ok(text, strlen(text));
    CHECK(m->extras == NULL);
    CHECK_EQ_INT(m->has_vertex_normals, 0);
    CHECK(m->vertex_colors == NULL);
    char lost[256];
    CHECK_EQ_INT(rsmooth_mesh_conversion_losses(m, RSMOOTH_FORMAT_OBJ, lost, sizeof lost), 0);
    CHECK_EQ_INT(rsmooth_mesh_conversion_losses(m, RSMOOTH_FORMAT_STL_BINARY, lost, sizeof lost),
                 0);
    /* The generic writer reproduces it exactly. */
    bytes w = {0};
    w.data = mesh_to_memory(m, RSMOOTH_FORMAT_PLY_ASCII, &w.size);
    CHECK_EQ_INT(w.size, strlen(text));
    CHECK_EQ_INT(memcmp(w.data, text, w.size), 0);
    bytes_free(&w);
    rsmooth_mesh_destroy(m);
}

/* Many properties: the loss list names a few and counts the rest. */
static void test_many_losses(void) {
    bytes b = {0};
    put_text(&b, "ply\nformat ascii 1.0\nelement vertex 3\n"
                 "property float x\nproperty float y\nproperty float z\n");
    for (int k = 0; k < 11; k++) {
        char line[64];
        snprintf(line, sizeof line, "property uchar p%d\n", k);
        put_text(&b, line);
    }
    put_text(&b, "element face 1\nproperty list uchar int vertex_indices\nend_header\n");
    for (int i = 0; i < 3; i++)
        put_text(&b, "0 0 0 1 2 3 4 5 6 7 8 9 10 11\n");
    put_text(&b, "3 0 1 2\n");
    rsmooth_mesh *m = read_ok(b.data, b.size);
    char lost[512];
    size_t n = rsmooth_mesh_conversion_losses(m, RSMOOTH_FORMAT_OFF, lost, sizeof lost);
    CHECK_EQ_INT(n, 11);
    CHECK(strstr(lost, "'p5'") != NULL && strstr(lost, "'p6'") == NULL);
    CHECK(strstr(lost, "and 5 more PLY properties") != NULL);
    rsmooth_mesh_destroy(m);
    bytes_free(&b);
}

/* Faces that no longer fit the file's list types widen them; integer coordinates round and must
 * fit. */
static void test_widening_and_integer_positions(void) {
    bytes b = {0};
    put_text(&b, "ply\nformat ascii 1.0\nelement vertex 300\n"
                 "property short x\nproperty short y\nproperty short z\n"
                 "element face 1\nproperty list uchar uchar vertex_indices\nend_header\n");
    for (int i = 0; i < 300; i++) {
        char line[64];
        snprintf(line, sizeof line, "%d %d %d\n", i, i % 7, -i);
        put_text(&b, line);
    }
    put_text(&b, "3 0 1 2\n");
    rsmooth_mesh *m = read_ok(b.data, b.size);
    CHECK(m->extras != NULL);
    m->face_indices[2] = 299;
    m->positions[0] = 3.4;
    m->positions[1] = -2.6;
    bytes w = {0};
    w.data = mesh_to_memory(m, RSMOOTH_FORMAT_PLY_BINARY, &w.size);
    tply *out = tparse(w.data, w.size);
    CHECK(!strcmp(out->elems[1].props[0].count_type, "uchar"));
    CHECK(!strcmp(out->elems[1].props[0].type, "int"));
    CHECK(!strcmp(out->elems[0].props[0].type, "short"));
    CHECK_EQ_INT(out->elems[1].values[3], 299);
    CHECK_EQ_INT(out->elems[0].values[0], 3);
    CHECK_EQ_INT(out->elems[0].values[1], -3);
    tfree(out);
    bytes_free(&w);
    m->positions[5] = 40000; /* beyond a short */
    rsmooth_error err;
    FILE *f = tmpfile();
    CHECK(f != NULL);
    CHECK_EQ_INT(rsmooth_mesh_write_stream(m, f, RSMOOTH_FORMAT_PLY_ASCII, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(err.message, "short") != NULL);
    fclose(f);
    rsmooth_mesh_destroy(m);
    bytes_free(&b);
}

/* The generic path with normals: recomputed, in the positions' precision. */
static void test_generic_normals(void) {
    rsmooth_mesh *m = NULL;
    rsmooth_error err;
    CHECK_EQ_INT(rsmooth_mesh_create(4, 1, 4, &m, &err), RSMOOTH_OK);
    const double p[4][3] = {{0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {0, 1, 1}};
    memcpy(m->positions, p, sizeof p);
    for (uint32_t k = 0; k < 4; k++)
        m->face_indices[k] = k;
    m->face_offsets[1] = 4;
    CHECK_EQ_INT(rsmooth_mesh_triangulate(m, &err), RSMOOTH_OK);
    m->has_vertex_normals = 1;
    double normals[12];
    CHECK_EQ_INT(rsmooth_mesh_vertex_normals(m, normals, &err), RSMOOTH_OK);
    for (int o = 0; o < 2; o++) {
        bytes w = {0};
        w.data =
            mesh_to_memory(m, o ? RSMOOTH_FORMAT_PLY_BINARY : RSMOOTH_FORMAT_PLY_ASCII, &w.size);
        tply *out = tparse(w.data, w.size);
        const telem *v = &out->elems[0];
        size_t nx = tprop_index(v, "nx");
        CHECK_EQ_INT(nx, 3);
        CHECK(!strcmp(v->props[nx].type, "double"));
        for (size_t i = 0; i < 4; i++)
            for (size_t c = 0; c < 3; c++)
                CHECK(same_bits(v->values[6 * i + 3 + c], normals[3 * i + c]));
        rsmooth_mesh *back = read_ok(w.data, w.size);
        CHECK_EQ_INT(back->has_vertex_normals, 1);
        CHECK(back->extras != NULL);    /* normals are beyond the plain layout */
        check_faithful(out, out, back); /* its own normals again on a second write */
        rsmooth_mesh_destroy(back);
        tfree(out);
        bytes_free(&w);
    }
    rsmooth_mesh_destroy(m);
}

/* Colour channels of other types fill vertex_colors too. */
static void test_color_types(void) {
    const char *text = "ply\nformat ascii 1.0\nelement vertex 3\n"
                       "property float x\nproperty float y\nproperty float z\n"
                       "property float diffuse_red\nproperty ushort diffuse_green\n"
                       "property int diffuse_blue\n"
                       "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                       "0 0 0 1 65535 300\n1 0 0 0.5 257 -4\n0 1 0 0 0 17\n3 0 1 2\n";
    rsmooth_mesh *m = read_ok(text, strlen(text));
    CHECK(m->vertex_colors != NULL);
    const uint8_t expected[9] = {255, 255, 255, 128, 1, 0, 0, 0, 17};
    CHECK_EQ_INT(memcmp(m->vertex_colors, expected, 9), 0);
    char lost[256];
    CHECK_EQ_INT(rsmooth_mesh_conversion_losses(m, RSMOOTH_FORMAT_OBJ, lost, sizeof lost), 0);
    rsmooth_mesh_destroy(m);
}

/* Values a kept property's type cannot hold, in ascii, are errors (not silently changed). */
static void test_bad_values(void) {
    const char *bad[] = {
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nproperty uchar red\nend_header\n0 0 0 1\n0 0 0 256\n0 0 0 3\n",
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nproperty int label\nend_header\n0 0 0 1\n0 0 0 2.5\n0 0 0 3\n",
        "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
        "property float z\nelement m 1\nproperty list uchar char ids\nend_header\n0 0 0\n"
        "1 200\n",
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        rsmooth_mesh *m = NULL;
        rsmooth_error err;
        CHECK_EQ_INT(
            rsmooth_mesh_read_memory(bad[i], strlen(bad[i]), RSMOOTH_FORMAT_AUTO, &m, &err),
            RSMOOTH_ERROR_PARSE);
        CHECK(strstr(err.message, "does not fit") != NULL);
        CHECK(m == NULL);
    }
}

/* Lists whose first items are empty, and an element with no properties. */
static void test_empty_lists(void) {
    bytes b = {0};
    put_text(&b, "ply\nformat binary_big_endian 1.0\nelement vertex 3\n"
                 "property float x\nproperty float y\nproperty float z\n"
                 "element nothing 5\n"
                 "element m 3\nproperty list uint short ids\nend_header\n");
    for (int i = 0; i < 9; i++)
        put_value(&b, T_BE, "float", i);
    put_value(&b, T_BE, "uint", 0);
    put_value(&b, T_BE, "uint", 0);
    put_value(&b, T_BE, "uint", 2);
    put_value(&b, T_BE, "short", -3);
    put_value(&b, T_BE, "short", 300);
    rsmooth_mesh *m = read_ok(b.data, b.size);
    tply *in = tparse(b.data, b.size);
    for (int o = 0; o < 2; o++) {
        bytes w = {0};
        w.data =
            mesh_to_memory(m, o ? RSMOOTH_FORMAT_PLY_BINARY : RSMOOTH_FORMAT_PLY_ASCII, &w.size);
        tply *out = tparse(w.data, w.size);
        check_faithful(in, out, m);
        tfree(out);
        bytes_free(&w);
    }
    tfree(in);
    rsmooth_mesh_destroy(m);
    bytes_free(&b);
}

/* Every prefix of the rich files: an error or a mesh, never an over-read (exact-size buffers). */
static void test_prefixes(void) {
    for (int format = T_ASCII; format <= T_BE; format++) {
        bytes b = rich_file(format);
        for (size_t len = 0; len <= b.size; len++) {
            void *copy = malloc(len ? len : 1);
            CHECK(copy != NULL);
            memcpy(copy, b.data, len);
            rsmooth_mesh *m = NULL;
            rsmooth_error err;
            rsmooth_status s = rsmooth_mesh_read_memory(copy, len, RSMOOTH_FORMAT_AUTO, &m, &err);
            free(copy);
            CHECK(s == RSMOOTH_OK || s == RSMOOTH_ERROR_PARSE);
            CHECK((s == RSMOOTH_OK) == (m != NULL));
            if (len == b.size)
                CHECK_EQ_INT(s, RSMOOTH_OK);
            rsmooth_mesh_destroy(m);
        }
        check_prefixes_located("rich PLY", b.data, b.size);
        bytes_free(&b);
    }
}

/* Normals recomputed at the ends of the supported range (coordinates near 1e150 and far below
 * 1e-150, where a triangle's cross product overflows or underflows a double) equal those of the
 * same mesh at unit scale, area weights included. */
static void test_normals_at_extreme_scales(void) {
    /* vertex 0 is shared by a small and a large triangle of different planes */
    const double unit[5][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 1}, {-2, 0, 0}, {0, 0, 2}};
    const uint32_t two_faces[6] = {0, 1, 2, 0, 3, 4};
    /* the oracle, by hand at unit scale: the faces' cross products (1,0,0) x (0,1,1) = (0,-1,1)
     * and (-2,0,0) x (0,0,2) = (0,4,0) sum to (0,3,1) at vertex 0 */
    const double n0[3] = {0, 3, 1};
    double len = sqrt(n0[0] * n0[0] + n0[1] * n0[1] + n0[2] * n0[2]);
    const double scales[] = {1, 1e150, 1e-160, 1e-300, 4.9406564584124654e-322 * 1024};
    for (size_t s = 0; s < sizeof scales / sizeof scales[0]; s++) {
        rsmooth_mesh *m = NULL;
        rsmooth_error err;
        CHECK_EQ_INT(rsmooth_mesh_create(5, 2, 6, &m, &err), RSMOOTH_OK);
        for (int i = 0; i < 15; i++)
            m->positions[i] = unit[i / 3][i % 3] * scales[s];
        memcpy(m->face_indices, two_faces, sizeof two_faces);
        m->face_offsets[1] = 3;
        m->face_offsets[2] = 6;
        CHECK_EQ_INT(rsmooth_mesh_triangulate(m, &err), RSMOOTH_OK);
        double normals[15];
        CHECK_EQ_INT(rsmooth_mesh_vertex_normals(m, normals, &err), RSMOOTH_OK);
        printf("scale %g: vertex 0 normal %.17g %.17g %.17g\n", scales[s], normals[0], normals[1],
               normals[2]);
        for (int c = 0; c < 3; c++)
            CHECK_NEAR(normals[c], n0[c] / len, 1e-15);
        const double n1[3] = {0, -1 / sqrt(2), 1 / sqrt(2)}; /* vertex 1: the small face only */
        for (int c = 0; c < 3; c++)
            CHECK_NEAR(normals[3 + c], n1[c], 1e-15);
        rsmooth_mesh_destroy(m);
    }
}

/* Random corruption of the rich binary files: an error or a mesh that writes back. */
static void test_corruption(void) {
    uint32_t state = 11;
    for (int round = 0; round < 3000; round++) {
        bytes good = rich_file(round % 2 ? T_LE : T_BE);
        int flips = 1 + (int)((state = state * 1664525u + 1013904223u) >> 30);
        for (int i = 0; i < flips; i++) {
            state = state * 1664525u + 1013904223u;
            size_t at = (state >> 8) % good.size;
            state = state * 1664525u + 1013904223u;
            good.data[at] = (unsigned char)(state >> 16);
        }
        rsmooth_mesh *m = NULL;
        rsmooth_error err;
        rsmooth_status s =
            rsmooth_mesh_read_memory(good.data, good.size, RSMOOTH_FORMAT_AUTO, &m, &err);
        CHECK(s == RSMOOTH_OK || s == RSMOOTH_ERROR_PARSE);
        if (s == RSMOOTH_OK) {
            FILE *f = tmpfile();
            CHECK(f != NULL);
            s = rsmooth_mesh_write_stream(m, f, RSMOOTH_FORMAT_PLY_ASCII, &err);
            CHECK(s == RSMOOTH_OK || s == RSMOOTH_ERROR_INVALID_ARGUMENT);
            fclose(f);
        }
        rsmooth_mesh_destroy(m);
        bytes_free(&good);
    }
}

int main(void) {
    test_rich_round_trip();
    test_big_endian_as_little();
    test_plain();
    test_many_losses();
    test_widening_and_integer_positions();
    test_generic_normals();
    test_color_types();
    test_bad_values();
    test_empty_lists();
    test_prefixes();
    test_corruption();
    test_normals_at_extreme_scales();
    printf("ply_roundtrip: all checks passed\n");
    return 0;
}
