/* STL writer (ascii and binary): the mesh's triangles as a soup, facet normals recomputed, and the
 * file's header, solid names and attributes back when the mesh came from an STL file. */
#include "io/stl_format.h"

#include <errno.h>
#include <float.h>
#include <math.h>
#include <string.h>

static const char where[] = "rsmooth_mesh_write (STL)";
static const char default_name[] = "rsmooth";

/* Unit normal of the triangle; 0 0 0 when degenerate. The edges are scaled first so neither huge
 * nor tiny coordinates overflow or underflow the cross product. */
static void facet_normal(const double *a, const double *b, const double *c, double n[3]) {
    double e1[3], e2[3];
    rs_sub3(b, a, e1);
    rs_sub3(c, a, e2);
    double scale = 0;
    for (int k = 0; k < 3; k++)
        scale = fmax(scale, fmax(fabs(e1[k]), fabs(e2[k])));
    n[0] = n[1] = n[2] = 0;
    if (!(scale > 0) || !isfinite(scale))
        return;
    for (int k = 0; k < 3; k++) {
        e1[k] /= scale;
        e2[k] /= scale;
    }
    double m[3];
    rs_cross3(e1, e2, m);
    double len = sqrt(rs_dot3(m, m));
    if (!(len > 0) || !isfinite(len))
        return;
    for (int k = 0; k < 3; k++)
        n[k] = m[k] / len;
}

/* The triangles must index the positions, and binary STL's float32 must hold every coordinate
 * they use at the mesh's scale (rs_io_float32_misfit_find): checked before anything is written. */
rsmooth_status rs_io_stl_check(const rsmooth_mesh *mesh, bool binary, rsmooth_error *error) {
    size_t t = mesh->triangle_count;
    if (t == 0)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "the mesh has no triangles (STL holds triangles only)");
    if (!mesh->triangles)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "%zu triangles but triangles is NULL", t);
    if (binary && (uint64_t)t > UINT32_MAX)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "%zu triangles: binary STL holds at most 2^32 - 1", t);
    for (size_t i = 0; i < 3 * t; i++)
        if (mesh->triangles[i] >= mesh->vertex_count)
            return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                           "triangle %zu: index %lu >= vertex count %zu", i / 3,
                           (unsigned long)mesh->triangles[i], mesh->vertex_count);
    rs_io_float32_misfit misfit;
    if (!binary || !rs_io_float32_misfit_find(mesh->positions, mesh->vertex_count, mesh->triangles,
                                              3 * t, 7, &misfit))
        return RSMOOTH_OK;
    if (!isfinite(misfit.rounded))
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "vertex %zu has coordinate %s beyond the largest float32 %s: binary STL "
                       "cannot hold it; ascii STL, OBJ or a PLY with double can",
                       misfit.vertex, rs_io_shortest(misfit.value).text,
                       rs_io_shortest(FLT_MAX).text);
    return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, /* 256 bytes: say it briefly */
                   "vertex %zu: float32 rounds coordinate %s to %s, beyond its precision at the "
                   "mesh's scale (largest %s): binary STL cannot hold this mesh; ascii STL, OBJ or "
                   "a PLY with double can",
                   misfit.vertex, rs_io_shortest(misfit.value).text,
                   rs_io_shortest(misfit.rounded).text, rs_io_shortest(misfit.largest).text);
}

/* The STL record of the mesh, when it still describes these triangles. */
static const rs_stl_extras *usable_extras(const rsmooth_mesh *mesh) {
    const rs_stl_extras *x = mesh->extras ? mesh->extras->stl : NULL;
    if (!x || x->triangle_count != mesh->triangle_count)
        return NULL;
    if (!x->binary) {
        size_t sum = 0;
        for (size_t i = 0; i < x->solid_count; i++)
            sum += x->solids[i].facet_count;
        if (sum != x->triangle_count)
            return NULL;
    }
    return x;
}

/* ---- binary */

static void put_u32(unsigned char *p, uint32_t v) {
    p[0] = (unsigned char)v;
    p[1] = (unsigned char)(v >> 8);
    p[2] = (unsigned char)(v >> 16);
    p[3] = (unsigned char)(v >> 24);
}

static void put_f32(unsigned char *p, double d) {
    float f = (float)d;
    uint32_t bits;
    memcpy(&bits, &f, sizeof bits);
    put_u32(p, bits);
}

static void binary_header(const rs_stl_extras *x, unsigned char header[RS_STL_HEADER_SIZE]) {
    if (x && x->binary) {
        memcpy(header, x->header, RS_STL_HEADER_SIZE);
        return;
    }
    const char *name = default_name;
    size_t len = strlen(default_name);
    for (size_t i = 0; x && i < x->solid_count; i++) {
        if (x->solids[i].name_len > 0) {
            name = x->solids[i].name;
            len = x->solids[i].name_len;
            break;
        }
    }
    if (len > RS_STL_HEADER_SIZE)
        len = RS_STL_HEADER_SIZE;
    memset(header, ' ', RS_STL_HEADER_SIZE);
    memcpy(header, name, len);
}

#define RECORDS_PER_CHUNK 1024

static bool write_binary(const rsmooth_mesh *mesh, const rs_stl_extras *x, FILE *stream) {
    unsigned char head[RS_STL_HEADER_SIZE + 4];
    binary_header(x, head);
    put_u32(head + RS_STL_HEADER_SIZE, (uint32_t)mesh->triangle_count); /* checked to fit */
    if (fwrite(head, 1, sizeof head, stream) != sizeof head)
        return false;
    unsigned char *chunk = rs_alloc_array(RECORDS_PER_CHUNK, RS_STL_RECORD_SIZE);
    if (!chunk)
        return false;
    bool ok = true;
    size_t used = 0;
    for (size_t i = 0; ok && i < mesh->triangle_count; i++) {
        const uint32_t *tri = mesh->triangles + 3 * i;
        const double *v[3];
        for (int c = 0; c < 3; c++)
            v[c] = mesh->positions + 3 * (size_t)tri[c];
        double n[3];
        facet_normal(v[0], v[1], v[2], n);
        unsigned char *p = chunk + RS_STL_RECORD_SIZE * used;
        for (int k = 0; k < 3; k++)
            put_f32(p + 4 * k, n[k]);
        for (int c = 0; c < 3; c++)
            for (int k = 0; k < 3; k++)
                put_f32(p + 12 + 12 * c + 4 * k, v[c][k]);
        uint16_t attribute = x && x->attributes ? x->attributes[i] : 0;
        p[48] = (unsigned char)attribute;
        p[49] = (unsigned char)(attribute >> 8);
        if (++used == RECORDS_PER_CHUNK || i + 1 == mesh->triangle_count) {
            ok = fwrite(chunk, RS_STL_RECORD_SIZE, used, stream) == used;
            used = 0;
        }
    }
    rs_free(chunk);
    return ok;
}

/* ---- ascii */

/* A name on the "solid" line: one line of text, so control characters become '_'. */
static bool write_name(FILE *stream, const char *keyword, const char *name, size_t len) {
    if (fputs(keyword, stream) == EOF)
        return false;
    if (len > 0 && putc(' ', stream) == EOF)
        return false;
    for (size_t i = 0; i < len; i++) {
        unsigned char c = (unsigned char)name[i];
        if ((c < 0x20 && c != '\t') || c == 0x7f)
            c = '_';
        if (putc(c, stream) == EOF)
            return false;
    }
    return putc('\n', stream) != EOF;
}

/* `f32`: float32 data that float32 holds at its scale (rs_io_float32_holds), written at float
 * precision; else every value as the double it is. */
static bool write_facets(const rsmooth_mesh *mesh, size_t first, size_t count, bool f32,
                         FILE *stream) {
    for (size_t i = first; i < first + count; i++) {
        const uint32_t *tri = mesh->triangles + 3 * i;
        const double *v[3];
        for (int c = 0; c < 3; c++)
            v[c] = mesh->positions + 3 * (size_t)tri[c];
        double n[3];
        facet_normal(v[0], v[1], v[2], n);
        if (fprintf(stream, "  facet normal %.9g %.9g %.9g\n    outer loop\n", n[0], n[1], n[2]) <
            0)
            return false;
        for (int c = 0; c < 3; c++) {
            int written;
            if (f32)
                written = fprintf(stream, "      vertex %.9g %.9g %.9g\n", (double)(float)v[c][0],
                                  (double)(float)v[c][1], (double)(float)v[c][2]);
            else
                written =
                    fprintf(stream, "      vertex %.17g %.17g %.17g\n", v[c][0], v[c][1], v[c][2]);
            if (written < 0)
                return false;
        }
        if (fputs("    endloop\n  endfacet\n", stream) == EOF)
            return false;
    }
    return true;
}

static bool write_solid(const rsmooth_mesh *mesh, const char *name, size_t len, size_t first,
                        size_t count, bool f32, FILE *stream) {
    return write_name(stream, "solid", name, len) &&
           write_facets(mesh, first, count, f32, stream) &&
           write_name(stream, "endsolid", name, len);
}

/* The name an ascii file gets for a binary header: its printable start, blanks trimmed, without
 * the "solid" many binary headers open with (no "solid solid"); empty when nothing is left. */
static size_t header_name(const unsigned char *header, const char **name) {
    size_t begin = 0, end = 0;
    while (end < RS_STL_HEADER_SIZE && header[end] >= 0x20 && header[end] < 0x7f)
        end++;
    while (end > begin && header[end - 1] == ' ')
        end--;
    while (begin < end && header[begin] == ' ')
        begin++;
    static const char solid[] = "solid";
    const size_t n = sizeof solid - 1;
    bool keyword = end - begin >= n && (end - begin == n || header[begin + n] == ' ');
    for (size_t i = 0; keyword && i < n; i++)
        keyword = (header[begin + i] | 0x20) == solid[i];
    if (keyword)
        for (begin += n; begin < end && header[begin] == ' ';)
            begin++;
    *name = (const char *)header + begin;
    return end - begin;
}

static bool write_ascii(const rsmooth_mesh *mesh, const rs_stl_extras *x, FILE *stream) {
    const bool f32 = rs_io_float32_holds(mesh);
    if (x && !x->binary) {
        size_t first = 0;
        for (size_t s = 0; s < x->solid_count; s++) {
            const rs_stl_solid *solid = &x->solids[s];
            if (!write_solid(mesh, solid->name, solid->name_len, first, solid->facet_count, f32,
                             stream))
                return false;
            first += solid->facet_count;
        }
        return true;
    }
    const char *name = default_name;
    size_t len = strlen(default_name);
    const char *from_header;
    size_t header_len = x ? header_name(x->header, &from_header) : 0;
    if (header_len > 0) {
        name = from_header;
        len = header_len;
    }
    return write_solid(mesh, name, len, 0, mesh->triangle_count, f32, stream);
}

rsmooth_status rs_io_stl_write(const rsmooth_mesh *mesh, FILE *stream, bool binary,
                               rsmooth_error *error) {
    const rs_stl_extras *x = usable_extras(mesh);
    errno = 0;
    bool ok = binary ? write_binary(mesh, x, stream)
                     : rs_io_put_bom(mesh, RSMOOTH_FORMAT_STL_ASCII, stream) &&
                           write_ascii(mesh, x, stream);
    ok = ok && fflush(stream) == 0 && !ferror(stream);
    if (!ok)
        return rs_fail(error, RSMOOTH_ERROR_IO, "rsmooth_mesh_write_stream", "writing STL: %s",
                       errno ? strerror(errno) : "stream error or out of memory");
    return RSMOOTH_OK;
}
