/* Positioned reads and writes of whole buffers: the loops every file reader and writer of both
 * libraries needs (a short count or EINTR is not an error, only a real one or the file's end). */
#define _POSIX_C_SOURCE 200809L
#include "core/rsmooth_internal.h"

#include <errno.h>
#include <unistd.h>

bool rs_pwrite_all(int fd, const void *data, size_t n, uint64_t offset) {
    const char *p = data;
    while (n > 0) {
        ssize_t put = pwrite(fd, p, n, (off_t)offset);
        if (put < 0 && errno == EINTR)
            continue;
        if (put <= 0)
            return false;
        p += put;
        n -= (size_t)put;
        offset += (uint64_t)put;
    }
    return true;
}

bool rs_pread_all(int fd, void *data, size_t n, uint64_t offset) {
    char *p = data;
    while (n > 0) {
        ssize_t got = pread(fd, p, n, (off_t)offset);
        if (got < 0 && errno == EINTR)
            continue;
        if (got <= 0) {
            if (got == 0)
                errno = EIO; /* the file is shorter than it was */
            return false;
        }
        p += got;
        n -= (size_t)got;
        offset += (uint64_t)got;
    }
    return true;
}
