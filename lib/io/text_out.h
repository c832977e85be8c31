/* A buffered text writer for the mesh writers (not installed): bytes gather in one large buffer
 * that goes to the stream with fwrite when full, instead of a stdio call per number. Prefix
 * rs_io_text_. */
#ifndef RSMOOTH_IO_TEXT_OUT_H
#define RSMOOTH_IO_TEXT_OUT_H

#include "io/float_print.h"

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

/* The largest item rs_io_text_reserve grants room for at once. */
#define RS_IO_TEXT_ITEM_MAX 4096

typedef struct rs_io_text_out {
    FILE *stream;
    char *bytes; /* 1 MiB, or `fallback` when that cannot be allocated */
    size_t capacity, used;
    bool ok; /* false once a write failed: nothing more is written */
    char fallback[RS_IO_TEXT_ITEM_MAX];
} rs_io_text_out;

/* Starts writing to `stream` (written after what the stream already holds). Never fails. */
void rs_io_text_open(rs_io_text_out *out, FILE *stream);

/* Writes what is buffered and frees the buffer; false when any write failed (errno as fwrite
 * left it). The stream itself is not flushed. */
bool rs_io_text_close(rs_io_text_out *out);

/* Writes the buffered bytes to the stream; false when that (or an earlier write) failed. */
bool rs_io_text_flush(rs_io_text_out *out);

/* Room for `n` (at most RS_IO_TEXT_ITEM_MAX) more bytes at the returned pointer; the caller then
 * advances out->used by what it wrote. After a failure the room is scratch, written nowhere. */
static inline char *rs_io_text_reserve(rs_io_text_out *out, size_t n) {
    if (out->capacity - out->used < n)
        rs_io_text_flush(out);
    return out->bytes + out->used;
}

/* Appends `size` bytes (any size). */
void rs_io_text_bytes(rs_io_text_out *out, const void *data, size_t size);

/* Appends printf's text. */
void rs_io_text_printf(rs_io_text_out *out, const char *format, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

static inline void rs_io_text_char(rs_io_text_out *out, char c) {
    *rs_io_text_reserve(out, 1) = c;
    out->used++;
}

static inline void rs_io_text_u64(rs_io_text_out *out, uint64_t v) {
    char *p = rs_io_text_reserve(out, 20);
    out->used += rs_io_print_u64(p, v);
}

/* rs_io_print_double / rs_io_print_float / rs_io_print_g9 of v. */
static inline void rs_io_text_double(rs_io_text_out *out, double v) {
    char *p = rs_io_text_reserve(out, RS_IO_PRINT_MAX);
    out->used += rs_io_print_double(p, v);
}
static inline void rs_io_text_float(rs_io_text_out *out, float v) {
    char *p = rs_io_text_reserve(out, RS_IO_PRINT_MAX);
    out->used += rs_io_print_float(p, v);
}
static inline void rs_io_text_g9(rs_io_text_out *out, double v) {
    char *p = rs_io_text_reserve(out, RS_IO_PRINT_MAX);
    out->used += rs_io_print_g9(p, v);
}

#endif /* RSMOOTH_IO_TEXT_OUT_H */
