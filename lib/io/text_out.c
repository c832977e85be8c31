/* Buffered text output for the mesh writers: one fwrite per MiB instead of a stdio call per
 * number (most of a text mesh's writing time was spent in fprintf). */
#include "io/text_out.h"

#include "core/rsmooth_internal.h"
#include "io/io_internal.h"

#include <errno.h>
#include <stdarg.h>
#include <string.h>

#define TEXT_BUFFER_SIZE ((size_t)1 << 20)

void rs_io_text_open(rs_io_text_out *out, FILE *stream) {
    out->stream = stream;
    out->used = 0;
    out->ok = true;
    out->bytes = rs_alloc_array(TEXT_BUFFER_SIZE, 1);
    out->capacity = TEXT_BUFFER_SIZE;
    if (!out->bytes) { /* slower, never wrong */
        out->bytes = out->fallback;
        out->capacity = sizeof out->fallback;
    }
}

bool rs_io_text_flush(rs_io_text_out *out) {
    if (out->ok && out->used > 0 && fwrite(out->bytes, 1, out->used, out->stream) != out->used)
        out->ok = false;
    out->used = 0;
    return out->ok;
}

bool rs_io_text_close(rs_io_text_out *out) {
    bool ok = rs_io_text_flush(out);
    if (out->bytes != out->fallback)
        rs_free(out->bytes);
    out->bytes = NULL;
    return ok;
}

void rs_io_text_bytes(rs_io_text_out *out, const void *data, size_t size) {
    if (out->capacity - out->used >= size) {
        memcpy(out->bytes + out->used, data, size);
        out->used += size;
        return;
    }
    if (!rs_io_text_flush(out))
        return;
    if (size <= out->capacity) {
        memcpy(out->bytes, data, size);
        out->used = size;
    } else if (fwrite(data, 1, size, out->stream) != size) {
        out->ok = false;
    }
}

void rs_io_text_printf(rs_io_text_out *out, const char *format, ...) {
    char *p = rs_io_text_reserve(out, RS_IO_TEXT_ITEM_MAX);
    va_list args, again;
    va_start(args, format);
    va_copy(again, args);
    int n = vsnprintf(p, RS_IO_TEXT_ITEM_MAX, format, args);
    if (n >= 0 && n < RS_IO_TEXT_ITEM_MAX)
        out->used += (size_t)n;
    else if (n < 0 || !rs_io_text_flush(out) || vfprintf(out->stream, format, again) != n)
        out->ok = false; /* a long text (a header line) goes straight to the stream */
    va_end(again);
    va_end(args);
}
