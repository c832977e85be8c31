/* libFuzzer target for one reader (FUZZ_FORMAT); what it reads is written back and read again, so
 * the writers are fuzzed too. */
#define _POSIX_C_SOURCE 200809L
#include "rsmooth_io.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#ifndef FUZZ_FORMAT
#error "compile with -DFUZZ_FORMAT=RSMOOTH_FORMAT_<X>"
#endif

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* The writer of the reader's own family (PLY and STL are written binary). */
static rsmooth_format same_family(rsmooth_format format) {
    switch (format) {
    case RSMOOTH_FORMAT_PLY_ASCII:
    case RSMOOTH_FORMAT_PLY_BINARY:
    case RSMOOTH_FORMAT_PLY_BINARY_BE:
        return RSMOOTH_FORMAT_PLY_BINARY;
    case RSMOOTH_FORMAT_STL_ASCII:
    case RSMOOTH_FORMAT_STL_BINARY:
        return RSMOOTH_FORMAT_STL_BINARY;
    default:
        return format;
    }
}

static void fail(const char *what, rsmooth_format format, const rsmooth_error *err) {
    fprintf(stderr, "fuzz_read: %s (format %d): %s\n", what, (int)format,
            err ? err->message : "");
    abort();
}

/* Writes `mesh` as `format` and reads it back: the counts must survive. A writer may refuse what its
 * format cannot hold (INVALID_ARGUMENT: e.g. a double beyond float32 for binary STL). */
static void round_trip(const rsmooth_mesh *mesh, rsmooth_format format) {
    char *text = NULL;
    size_t length = 0;
    FILE *stream = open_memstream(&text, &length);
    if (!stream)
        return; /* out of memory: nothing to learn */
    rsmooth_error err;
    rsmooth_status status = rsmooth_mesh_write_stream(mesh, stream, format, &err);
    if (fclose(stream) != 0) {
        free(text);
        return;
    }
    if (status == RSMOOTH_ERROR_INVALID_ARGUMENT) {
        free(text);
        return;
    }
    if (status != RSMOOTH_OK)
        fail("writing failed", format, &err);
    rsmooth_mesh *back = NULL;
    status = rsmooth_mesh_read_memory(text, length, format, &back, &err);
    if (status != RSMOOTH_OK) {
        fprintf(stderr, "fuzz_read: written file:\n%.*s\n", (int)(length > 2000 ? 2000 : length),
                text);
        fail("what was written does not read back", format, &err);
    }
    /* STL is a soup: an indexed mesh comes back with 3 vertices a triangle. */
    size_t vertices = format == RSMOOTH_FORMAT_STL_BINARY || format == RSMOOTH_FORMAT_STL_ASCII
                          ? 3 * mesh->triangle_count
                          : mesh->vertex_count;
    if (back->vertex_count != vertices || back->triangle_count != mesh->triangle_count) {
        fprintf(stderr, "fuzz_read: %zu vertices, %zu triangles written; %zu, %zu read back\n",
                vertices, mesh->triangle_count, back->vertex_count, back->triangle_count);
        fail("the counts changed", format, NULL);
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
            fail("mesh set on failure", FUZZ_FORMAT, &err);
        return 0;
    }
    round_trip(mesh, same_family(FUZZ_FORMAT));
    if (same_family(FUZZ_FORMAT) != RSMOOTH_FORMAT_PLY_BINARY)
        round_trip(mesh, RSMOOTH_FORMAT_PLY_BINARY);
    rsmooth_mesh_destroy(mesh);
    return 0;
}
