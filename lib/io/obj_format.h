/* The OBJ extras record, shared by the OBJ reader, writer and loss report (not installed). */
#ifndef RSMOOTH_OBJ_FORMAT_H
#define RSMOOTH_OBJ_FORMAT_H

#include "io/io_internal.h"

/* Kinds of content an OBJ file held beyond v and f (bits of rs_obj_extras.kinds). */
enum {
    RS_OBJ_TEXCOORDS = 1u << 0, /* vt lines or vt indices in faces */
    RS_OBJ_NORMALS = 1u << 1,   /* vn lines */
    RS_OBJ_GROUPS = 1u << 2,    /* g, o */
    RS_OBJ_MATERIALS = 1u << 3, /* mtllib, usemtl */
    RS_OBJ_SMOOTHING = 1u << 4, /* s */
    RS_OBJ_LINES = 1u << 5,     /* l, p */
    RS_OBJ_COMMENTS = 1u << 6,  /* # lines and trailing comments */
    RS_OBJ_COLORS = 1u << 7,    /* v x y z r g b */
    RS_OBJ_VERTEX_W = 1u << 8,  /* v x y z w (or other trailing fields) */
    RS_OBJ_OTHER = 1u << 9      /* statements this library does not interpret */
};

/* The file as a sequence of runs: of plain v lines ("v x y z", nothing after), of plain f lines
 * (no comment), each with the file's usual line end, which the writer makes from the mesh; and of
 * other lines, kept as text. Scans are mostly one run of each plain kind, so the record stays small
 * where a copy of the file would cost the reader a large allocation. */
enum { RS_OBJ_RUN_V, RS_OBJ_RUN_F, RS_OBJ_RUN_TEXT };

typedef struct rs_obj_run {
    size_t start; /* TEXT: offset in rs_obj_extras.text */
    size_t count; /* V, F: lines; TEXT: bytes (whole lines, line ends included) */
    int kind;
} rs_obj_run;

/* The faithful writer walks the runs; within text it rewrites v lines (position; what follows
 * the coordinates kept), replaces the vn lines by the recomputed normals and rewrites f lines
 * (absolute indices, trailing comment kept); every other line is copied verbatim. */
struct rs_obj_extras {
    char *text; /* the text runs, back to back (owned, not NUL-terminated) */
    size_t size;
    rs_obj_run *runs;
    size_t run_count;
    bool crlf;           /* plain lines end in "\r\n" (else "\n") */
    size_t vertex_count; /* the mesh's counts at read time: the faithful path needs them */
    size_t face_count;
    uint64_t offsets_hash; /* of face_offsets at read time, so vt per corner still lines up */
    uint32_t *corner_vt;   /* per face corner: absolute 0-based vt index or RS_OBJ_NO_VT; NULL
                            * when no face names a vt */
    unsigned kinds;
};

#define RS_OBJ_NO_VT UINT32_MAX

/* FNV-1a over face_offsets[0 .. face_count]. */
static inline uint64_t rs_obj_offsets_hash(const uint32_t *offsets, size_t face_count) {
    uint64_t h = 14695981039346656037ull;
    for (size_t i = 0; i <= face_count; i++) {
        h ^= offsets[i];
        h *= 1099511628211ull;
    }
    return h;
}

#endif /* RSMOOTH_OBJ_FORMAT_H */
