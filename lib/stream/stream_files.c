/* Files of the streaming path: buffered sequential reads, positioned writes, unnamed temporaries
 * and the per-region writers the pieces' lists are written through. */
#define _GNU_SOURCE /* O_TMPFILE, syscall */
#include "stream/stream_internal.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

/* copy_file_range(2) through syscall(2): glibc's wrapper arrived in 2.27, and the Python wheels
 * are built against glibc 2.17 (make wheels). Where the kernel lacks it (ENOSYS, before Linux 4.5)
 * or refuses the pair of files (EXDEV, EINVAL...), the copy goes through a buffer instead. */
static ssize_t copy_range(int from, loff_t *in, int to, loff_t *out, size_t len) {
#ifdef SYS_copy_file_range
    return (ssize_t)syscall(SYS_copy_file_range, from, in, to, out, len, 0u);
#else
    (void)from, (void)in, (void)to, (void)out, (void)len;
    errno = ENOSYS;
    return -1;
#endif
}

bool rs_stream_reader_open(rs_stream_reader *r, int fd, const char *name, uint64_t pos,
                           uint64_t end, size_t cap) {
    memset(r, 0, sizeof *r);
    r->fd = fd;
    r->name = name;
    r->pos = pos;
    r->end = end;
    r->cap = cap;
    r->buf = rs_alloc_array(cap, 1);
    return r->buf != NULL;
}

void rs_stream_reader_close(rs_stream_reader *r) {
    rs_free(r->buf);
    r->buf = NULL;
}

const unsigned char *rs_stream_read(rs_stream_reader *r, size_t n) {
    if (r->len - r->at < n) {
        if (n > r->cap)
            return NULL;
        size_t keep = r->len - r->at; /* move the unread tail to the front, then refill */
        memmove(r->buf, r->buf + r->at, keep);
        r->at = 0;
        r->len = keep;
        while (r->len < n && r->pos < r->end) {
            size_t want = r->cap - r->len;
            if ((uint64_t)want > r->end - r->pos)
                want = (size_t)(r->end - r->pos);
            ssize_t got = pread(r->fd, r->buf + r->len, want, (off_t)r->pos);
            if (got < 0 && errno == EINTR)
                continue;
            if (got <= 0)
                return NULL;
            r->len += (size_t)got;
            r->pos += (uint64_t)got;
        }
        if (r->len < n)
            return NULL;
    }
    const unsigned char *p = r->buf + r->at;
    r->at += n;
    return p;
}

bool rs_stream_triangles_open_range(rs_stream_reader *r, int fd, size_t id_bytes, uint64_t first,
                                    uint64_t end) {
    return rs_stream_reader_open(r, fd, "triangles", first * 3 * id_bytes, end * 3 * id_bytes,
                                 1u << 20);
}

rsmooth_status rs_stream_unwritten(const char *dir, int errnum, rsmooth_error *error) {
    return rs_fail(error, RSMOOTH_ERROR_IO, RS_STREAM_WHERE,
                   "cannot write a temporary file in %s (disk full?)%s%s", dir, errnum ? ": " : "",
                   errnum ? strerror(errnum) : "");
}

int rs_stream_temporary(const char *dir) {
#ifdef O_TMPFILE
    int unnamed = open(dir, O_TMPFILE | O_RDWR | O_CLOEXEC, 0600);
    if (unnamed >= 0)
        return unnamed;
#endif
    size_t n = strlen(dir) + 32;
    char *name = rs_alloc_array(n, 1);
    if (!name) {
        errno = ENOMEM;
        return -1;
    }
    snprintf(name, n, "%s/.rsmooth-XXXXXX", dir);
    int fd = mkstemp(name);
    if (fd >= 0)
        unlink(name); /* unnamed from here on: it goes when the descriptor closes */
    rs_free(name);
    return fd;
}

bool rs_stream_copy(int from, uint64_t from_offset, int to, uint64_t to_offset, uint64_t size) {
    uint64_t done = 0;
    loff_t in = (loff_t)from_offset, out = (loff_t)to_offset;
    while (done < size) { /* in the kernel, without passing through this process's memory */
        size_t want = size - done > (1u << 30) ? (1u << 30) : (size_t)(size - done);
        ssize_t n = copy_range(from, &in, to, &out, want);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0)
            break;
        done += (uint64_t)n;
    }
    if (done == size)
        return true;
    enum { CHUNK = 1 << 20 }; /* where copy_file_range does not work: through a buffer */
    char *buf = rs_alloc_array(CHUNK, 1);
    if (!buf)
        return false;
    bool ok = true;
    while (ok && done < size) {
        size_t n = size - done > CHUNK ? CHUNK : (size_t)(size - done);
        ok = rs_pread_all(from, buf, n, from_offset + done) &&
             rs_pwrite_all(to, buf, n, to_offset + done);
        done += n;
    }
    rs_free(buf);
    return ok;
}

bool rs_region_writer_init(rs_region_writer *w, int fd, size_t regions, size_t record,
                           const uint64_t *starts, size_t memory) {
    memset(w, 0, sizeof *w);
    w->fd = fd;
    w->regions = regions;
    w->record = record;
    size_t per = regions ? memory / (regions * record) : 1;
    w->per_buffer = per < 16 ? 16 : per > 4096 ? 4096 : per;
    w->next = rs_alloc_array(regions ? regions : 1, sizeof *w->next);
    w->filled = rs_calloc_array(regions ? regions : 1, sizeof *w->filled);
    w->buffers = rs_alloc_array(regions ? regions : 1, w->per_buffer * record);
    if (!w->next || !w->filled || !w->buffers) {
        rs_region_writer_free(w);
        return false;
    }
    for (size_t i = 0; i < regions; i++)
        w->next[i] = starts[i] * record;
    return true;
}

static bool flush_region(rs_region_writer *w, size_t i) {
    size_t bytes = (size_t)w->filled[i] * w->record;
    if (bytes == 0)
        return true;
    if (!rs_pwrite_all(w->fd, w->buffers + i * w->per_buffer * w->record, bytes, w->next[i]))
        return false;
    w->next[i] += bytes;
    w->filled[i] = 0;
    return true;
}

bool rs_region_append(rs_region_writer *w, size_t region, const void *record) {
    if (w->filled[region] == w->per_buffer && !flush_region(w, region))
        return false;
    memcpy(w->buffers + (region * w->per_buffer + w->filled[region]) * w->record, record,
           w->record);
    w->filled[region]++;
    return true;
}

bool rs_region_writer_finish(rs_region_writer *w) {
    bool ok = true;
    for (size_t i = 0; ok && i < w->regions; i++)
        ok = flush_region(w, i);
    rs_region_writer_free(w);
    return ok;
}

void rs_region_writer_free(rs_region_writer *w) {
    rs_free(w->next);
    rs_free(w->filled);
    rs_free(w->buffers);
    w->next = NULL;
    w->filled = NULL;
    w->buffers = NULL;
}
