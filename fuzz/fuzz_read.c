/* libFuzzer target for one reader (FUZZ_FORMAT; RSMOOTH_FORMAT_AUTO: automatic detection, what the
 * command does). What it reads is written back in its own format and in one other, read again,
 * and compared value by value, so the writers are fuzzed too and a write-and-read-back that
 * changes a number fails:
 *   - positions bit for bit, as doubles, or as floats where the file holds floats (a float32 mesh
 *     in any format, binary STL): every writer writes digits or bits that read back exactly;
 *   - faces and triangles exactly (STL: a soup, so each corner's position instead);
 *   - vertex colours byte for byte, where the target holds colours (not STL);
 *   - a point cloud's normals (its data) bit for bit as positions are; a mesh's normals are
 *     recomputed by the writers, to 9 digits in text (float precision), so they are compared with
 *     the mesh's recomputed normals within 1e-6;
 *   - the writer of the mesh's own format must accept it, and writing what it read back again
 *     gives the same bytes (nothing drifts between round trips);
 *   - rsmooth_mesh_check_writable agrees with every writer: OK where it writes, the writer's own
 *     status and message where it refuses. */
#define _POSIX_C_SOURCE 200809L
#include "rsmooth_io.h"

#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef FUZZ_FORMAT
#error "compile with -DFUZZ_FORMAT=RSMOOTH_FORMAT_<X>"
#endif

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void fail(const char *what, rsmooth_format format, const char *detail) {
    fprintf(stderr, "fuzz_read: %s (written as format %d)%s%s\n", what, (int)format,
            detail ? ": " : "", detail ? detail : "");
    abort();
}

/* The writer of a mesh's own format (big-endian PLY is written little-endian). */
static rsmooth_format own_format(const rsmooth_mesh *mesh) {
    return mesh->source_format == RSMOOTH_FORMAT_PLY_BINARY_BE ? RSMOOTH_FORMAT_PLY_BINARY
                                                               : mesh->source_format;
}

static bool is_stl(rsmooth_format f) {
    return f == RSMOOTH_FORMAT_STL_ASCII || f == RSMOOTH_FORMAT_STL_BINARY;
}

/* a and b are the same number as written: bit for bit as doubles, or as floats when the file
 * holds floats (a value beyond float range is written as the double it is). */
static bool same_value(double a, double b, bool as_float) {
    if (as_float && isfinite((float)a)) {
        float fa = (float)a, fb = (float)b;
        return memcmp(&fa, &fb, sizeof fa) == 0;
    }
    return memcmp(&a, &b, sizeof a) == 0;
}

static void compare_values(const rsmooth_mesh *mesh, const rsmooth_mesh *back,
                           rsmooth_format format) {
    char detail[160];
    bool stl = is_stl(format);
    bool as_float = mesh->precision == RSMOOTH_FLOAT32 || format == RSMOOTH_FORMAT_STL_BINARY;
    size_t vertices = stl ? 3 * mesh->triangle_count : mesh->vertex_count;
    if (back->vertex_count != vertices || back->triangle_count != mesh->triangle_count ||
        (!stl && back->face_count != mesh->face_count)) {
        snprintf(detail, sizeof detail, "%zu vertices, %zu triangles written; %zu, %zu read back",
                 vertices, mesh->triangle_count, back->vertex_count, back->triangle_count);
        fail("the counts changed", format, detail);
    }
    for (size_t v = 0; v < vertices; v++) {
        size_t source = stl ? mesh->triangles[v] : v; /* STL: corner v of the soup */
        for (int k = 0; k < 3; k++) {
            double a = mesh->positions[3 * source + (size_t)k];
            double b = back->positions[3 * v + (size_t)k];
            if (!same_value(a, b, as_float)) {
                snprintf(detail, sizeof detail, "vertex %zu: %.17g written, %.17g read", v, a, b);
                fail("a coordinate changed", format, detail);
            }
        }
    }
    if (stl)
        return; /* no faces but the soup's, no colours, no normals */
    size_t index_count = mesh->face_offsets[mesh->face_count];
    if (memcmp(back->face_offsets, mesh->face_offsets, (mesh->face_count + 1) * sizeof(uint32_t)) !=
            0 ||
        memcmp(back->face_indices, mesh->face_indices, index_count * sizeof(uint32_t)) != 0)
        fail("the faces changed", format, NULL);
    if ((mesh->vertex_colors == NULL) != (back->vertex_colors == NULL) ||
        (mesh->vertex_colors &&
         memcmp(mesh->vertex_colors, back->vertex_colors, 3 * mesh->vertex_count) != 0))
        fail("the vertex colours changed", format, NULL);
    if (!back->vertex_normals)
        return;
    double *expected = NULL;
    bool data = mesh->triangle_count == 0; /* a point cloud: its own normals */
    if (data && !mesh->vertex_normals)
        fail("normals appeared", format, NULL);
    if (!data) {
        expected = malloc(3 * mesh->vertex_count * sizeof(double) + 1);
        rsmooth_error err;
        if (!expected || rsmooth_mesh_vertex_normals(mesh, expected, &err) != RSMOOTH_OK) {
            free(expected);
            return; /* out of memory: nothing to learn */
        }
    }
    for (size_t i = 0; i < 3 * mesh->vertex_count; i++) {
        double b = back->vertex_normals[i];
        bool same =
            data ? same_value(mesh->vertex_normals[i], b, as_float) : fabs(expected[i] - b) <= 1e-6;
        if (!same) {
            snprintf(detail, sizeof detail, "vertex %zu: %.17g expected, %.17g read", i / 3,
                     data ? mesh->vertex_normals[i] : expected[i], b);
            free(expected);
            fail("a normal changed", format, detail);
        }
    }
    free(expected);
}

/* Writes `mesh` as `format` into a new buffer; the status. */
static rsmooth_status write_memory(const rsmooth_mesh *mesh, rsmooth_format format, char **text,
                                   size_t *length, rsmooth_error *err) {
    *text = NULL;
    *length = 0;
    FILE *stream = open_memstream(text, length);
    if (!stream)
        return RSMOOTH_ERROR_OUT_OF_MEMORY;
    rsmooth_status status = rsmooth_mesh_write_stream(mesh, stream, format, err);
    if (fclose(stream) != 0 && status == RSMOOTH_OK)
        status = RSMOOTH_ERROR_OUT_OF_MEMORY;
    return status;
}

/* Writes `mesh` as `format`, reads it back and compares the values. Another format may refuse
 * what it cannot hold (INVALID_ARGUMENT: STL without triangles, a double beyond float32 for binary
 * STL); the mesh's own format may not. */
static void round_trip(const rsmooth_mesh *mesh, rsmooth_format format) {
    char *text;
    size_t length;
    rsmooth_error err, query;
    rsmooth_status expected = rsmooth_mesh_check_writable(mesh, format, &query);
    rsmooth_status status = write_memory(mesh, format, &text, &length, &err);
    bool refused = status == RSMOOTH_ERROR_INVALID_ARGUMENT || status == RSMOOTH_ERROR_UNSUPPORTED;
    if ((refused || status == RSMOOTH_OK) &&
        (expected != status || (refused && strcmp(query.message, err.message) != 0))) {
        char detail[600];
        snprintf(detail, sizeof detail, "rsmooth_mesh_check_writable %d '%s', writer %d '%s'",
                 (int)expected, query.message, (int)status, err.message);
        fail("the query and the writer disagree", format, detail);
    }
    bool own = format == own_format(mesh);
    if (status == RSMOOTH_ERROR_OUT_OF_MEMORY ||
        (status == RSMOOTH_ERROR_INVALID_ARGUMENT && !own)) {
        free(text);
        return;
    }
    if (status != RSMOOTH_OK)
        fail("writing failed", format, err.message);
    rsmooth_mesh *back = NULL;
    status = rsmooth_mesh_read_memory(text, length, format, &back, &err);
    if (status == RSMOOTH_ERROR_OUT_OF_MEMORY) {
        free(text);
        return;
    }
    if (status != RSMOOTH_OK) {
        fprintf(stderr, "fuzz_read: written file:\n%.*s\n", (int)(length > 2000 ? 2000 : length),
                text);
        fail("what was written does not read back", format, err.message);
    }
    compare_values(mesh, back, format);
    if (own) { /* the same bytes again from what was read back */
        char *again;
        size_t again_length;
        status = write_memory(back, format, &again, &again_length, &err);
        if (status == RSMOOTH_OK && (again_length != length || memcmp(again, text, length) != 0)) {
            fprintf(stderr, "fuzz_read: first write:\n%.*s\nsecond write:\n%.*s\n",
                    (int)(length > 1000 ? 1000 : length), text,
                    (int)(again_length > 1000 ? 1000 : again_length), again);
            fail("writing what was read back gives other bytes", format, NULL);
        }
        if (status != RSMOOTH_OK && status != RSMOOTH_ERROR_OUT_OF_MEMORY)
            fail("what was read back does not write", format, err.message);
        free(again);
    }
    rsmooth_mesh_destroy(back);
    free(text);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    rsmooth_mesh *mesh = NULL;
    rsmooth_error err;
    rsmooth_status status = rsmooth_mesh_read_memory(data, size, FUZZ_FORMAT, &mesh, &err);
    if (status != RSMOOTH_OK) {
        if (mesh)
            fail("mesh set on failure", FUZZ_FORMAT, err.message);
        if (status == RSMOOTH_ERROR_PARSE && err.line < 1 && err.byte_offset < 0)
            fail("a parse error without a location", FUZZ_FORMAT, err.message);
        return 0;
    }
    /* Its own format, then one other (picked by the input's size, so each input always takes the
     * same path). */
    static const rsmooth_format others[] = {RSMOOTH_FORMAT_OBJ,        RSMOOTH_FORMAT_PLY_ASCII,
                                            RSMOOTH_FORMAT_PLY_BINARY, RSMOOTH_FORMAT_OFF,
                                            RSMOOTH_FORMAT_STL_ASCII,  RSMOOTH_FORMAT_STL_BINARY};
    round_trip(mesh, own_format(mesh));
    rsmooth_format other = others[size % (sizeof others / sizeof others[0])];
    if (other != own_format(mesh))
        round_trip(mesh, other);
    rsmooth_mesh_destroy(mesh);
    return 0;
}
