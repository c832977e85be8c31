/* The OFF extras record, shared by the OFF reader (and loss report) and writer (not installed). */
#ifndef RSMOOTH_OFF_FORMAT_H
#define RSMOOTH_OFF_FORMAT_H

#include "io/io_internal.h"

/* Text per element: element i is text[offsets[i] .. offsets[i + 1]). NULL offsets: every element's
 * text is empty (the common case costs nothing). */
typedef struct rs_off_texts {
    char *text;
    size_t size, capacity;
    size_t *offsets; /* count + 1 entries once any element has text */
} rs_off_texts;

/* What an OFF file holds beyond positions, faces, normals and the vertex colours as bytes: kept as
 * the file wrote it (float or integer colours, alpha, texture coordinates, face colours), so the
 * faithful writer can put it back verbatim. */
struct rs_off_extras {
    char keyword[16];    /* "STCNOFF" and its kin, as in the file */
    bool normals;        /* N: each vertex line carries nx ny nz (recomputed on output) */
    bool texcoords;      /* ST */
    bool alpha;          /* some vertex colour has a fourth component */
    size_t vertex_count; /* the mesh's counts at read time: the faithful path needs them */
    size_t face_count;
    uint64_t edge_count; /* as declared (OFF files rarely fill it in) */
    rs_off_texts vertex; /* per vertex: what follows x y z (and the normal): colour, s t */
    rs_off_texts face;   /* per face: what follows the indices (a colour or colormap index) */
};

#endif /* RSMOOTH_OFF_FORMAT_H */
