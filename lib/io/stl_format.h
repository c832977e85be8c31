/* What an STL file keeps beyond its triangles (header, solid names, facet attributes), shared by
 * the STL reader and writer (not installed). */
#ifndef RSMOOTH_STL_FORMAT_H
#define RSMOOTH_STL_FORMAT_H

#include "io/io_internal.h"

#define RS_STL_HEADER_SIZE 80
#define RS_STL_RECORD_SIZE 50

/* A soup of T triangles has 3 T vertices, and vertex indices are uint32 below 2^32. */
#define RS_STL_MAX_TRIANGLES ((size_t)((RS_IO_MAX_VERTICES - 1) / 3))

/* One ascii solid: its name (the rest of the "solid" line) and how many facets it held. */
typedef struct rs_stl_solid {
    char *name; /* name_len bytes, NUL-terminated, may be empty */
    size_t name_len;
    size_t facet_count;
} rs_stl_solid;

struct rs_stl_extras {
    bool binary;           /* what the file was */
    size_t triangle_count; /* the file's facets: details are written back only while unchanged */
    unsigned char header[RS_STL_HEADER_SIZE]; /* binary only */
    rs_stl_solid *solids;                     /* ascii only: solid_count entries, in file order */
    size_t solid_count;
    uint16_t *attributes; /* triangle_count values; NULL when every one is 0 */
};

/* A binary header of spaces and NULs only: nothing worth keeping. */
static inline bool rs_stl_header_is_blank(const unsigned char *header) {
    for (size_t i = 0; i < RS_STL_HEADER_SIZE; i++)
        if (header[i] != ' ' && header[i] != '\0')
            return false;
    return true;
}

#endif /* RSMOOTH_STL_FORMAT_H */
