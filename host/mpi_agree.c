/* What a rank was given, compared across ranks (see mpi_agree.h): each part's bytes, rank 0's
 * broadcast to every rank and compared in full (about 130 KiB in all, once per run). */
#define _POSIX_C_SOURCE 200809L
#include "mpi_agree.h"
#include "cli_files.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <mpi.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

enum { PART_INPUT, PART_PARAMETERS, PART_CAP, PART_OUTPUT, PART_MASK, PARTS };
static const char *const part_names[PARTS] = {
    "the input file (its size, time or content)", "the parameters (or the rsmooth version)",
    "--max-memory", "the output (-o, --force, --in-place)",
    "--mask (given or not, the file's size, time or content)"};

#define HEAD_BYTES (64 * 1024)
#define SAMPLES 16
#define SAMPLE_BYTES 4096

/* One part's bytes. */
typedef struct part {
    unsigned char *data;
    size_t size, capacity;
} part;

static void append(part *p, const void *data, size_t size) {
    if (size > p->capacity - p->size) {
        size_t capacity = 2 * (p->size + size) + 256;
        unsigned char *grown = realloc(p->data, capacity);
        if (!grown)
            MPI_Abort(MPI_COMM_WORLD, EXIT_OTHER);
        p->data = grown;
        p->capacity = capacity;
    }
    if (size > 0)
        memcpy(p->data + p->size, data, size);
    p->size += size;
}

/* A value into a part, its size first, so no two sequences of values give the same bytes. */
static void add(part *s, const void *data, size_t size) {
    uint64_t n = size;
    append(s, &n, sizeof n);
    append(s, data, size);
}

static void add_text(part *s, const char *text) {
    add(s, text ? text : "", text ? strlen(text) + 1 : 0); /* NULL differs from "" */
}

/* The input's fingerprint: what stat says and bytes from its head and throughout. A file that
 * cannot be read digests its error, so it differs from one that can. */
static void add_input(part *s, const char *path) {
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    struct stat st;
    if (fd < 0 || fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        int e = fd < 0 ? errno : EINVAL;
        add_text(s, "unreadable");
        add(s, &e, sizeof e);
        if (fd >= 0)
            close(fd);
        return;
    }
    int64_t facts[3] = {(int64_t)st.st_size, (int64_t)st.st_mtim.tv_sec,
                        (int64_t)st.st_mtim.tv_nsec};
    add(s, facts, sizeof facts);
    unsigned char *buffer = malloc(HEAD_BYTES);
    if (buffer) {
        ssize_t got = pread(fd, buffer, HEAD_BYTES, 0);
        add(s, buffer, got > 0 ? (size_t)got : 0);
        for (int i = 1; i <= SAMPLES && st.st_size > HEAD_BYTES; i++) {
            off_t at = (off_t)((double)(st.st_size - SAMPLE_BYTES) * i / SAMPLES);
            got = pread(fd, buffer, SAMPLE_BYTES, at < 0 ? 0 : at);
            add(s, buffer, got > 0 ? (size_t)got : 0);
        }
        free(buffer);
    }
    close(fd);
}

static void fingerprint_parts(const options *opt, part d[PARTS]) {
    add_input(&d[PART_INPUT], opt->input);
    /* the parameters as bytes (rsmooth_params_init zeroes the struct, padding included), the
     * per-process pointers cleared */
    rsmooth_params params;
    memcpy(&params, &opt->params, sizeof params);
    params.progress = NULL;
    params.progress_user = NULL;
    params.progress_cancel = NULL;
    params.colors = NULL;
    params.move_mask = NULL;
    add(&d[PART_PARAMETERS], &params, sizeof params);
    add_text(&d[PART_PARAMETERS], rsmooth_version(NULL, NULL, NULL));
    add(&d[PART_CAP], &opt->max_memory, sizeof opt->max_memory);
    add_text(&d[PART_OUTPUT], opt->output);
    const int flags[3] = {opt->force, opt->in_place, (int)opt->format};
    add(&d[PART_OUTPUT], flags, sizeof flags);
    /* each rank reads it: the same file's bytes (by whatever name), or none on every rank */
    add_text(&d[PART_MASK], opt->mask ? "--mask" : NULL);
    if (opt->mask)
        add_input(&d[PART_MASK], opt->mask);
}

int mpi_agree(const options *opt, int rank, int ranks) {
    part mine[PARTS];
    memset(mine, 0, sizeof mine);
    fingerprint_parts(opt, mine);
    uint64_t sizes[PARTS];
    for (int p = 0; p < PARTS; p++)
        sizes[p] = mine[p].size;
    MPI_Bcast(sizes, PARTS, MPI_UINT64_T, 0, MPI_COMM_WORLD);
    int differs = 0; /* a bit per part */
    for (int p = 0; p < PARTS; p++) {
        if (sizes[p] > INT_MAX)
            MPI_Abort(MPI_COMM_WORLD, EXIT_OTHER); /* never: a part is some 130 KiB at most */
        unsigned char *first = rank == 0 ? mine[p].data : malloc(sizes[p] ? sizes[p] : 1);
        if (!first)
            MPI_Abort(MPI_COMM_WORLD, EXIT_OTHER);
        MPI_Bcast(first, (int)sizes[p], MPI_BYTE, 0, MPI_COMM_WORLD);
        if (sizes[p] != mine[p].size || memcmp(first, mine[p].data, mine[p].size) != 0)
            differs |= 1 << p;
        if (rank != 0)
            free(first);
        free(mine[p].data);
    }
    int *all = malloc((size_t)ranks * sizeof *all);
    if (!all)
        MPI_Abort(MPI_COMM_WORLD, EXIT_OTHER);
    MPI_Allgather(&differs, 1, MPI_INT, all, 1, MPI_INT, MPI_COMM_WORLD);
    int code = -1;
    for (int r = 0; r < ranks; r++) {
        if (!all[r])
            continue;
        code = EXIT_USAGE;
        if (rank != 0)
            continue;
        fprintf(stderr, "rsmooth-mpi: rank %d was not given what rank 0 was: it differs in", r);
        for (int p = 0, said = 0; p < PARTS; p++)
            if (all[r] & (1 << p))
                fprintf(stderr, "%s %s", said++ ? "," : "", part_names[p]);
        fprintf(stderr, "\n");
    }
    if (code >= 0 && rank == 0)
        fprintf(stderr, "rsmooth-mpi: every rank must run the same command on the same file "
                        "(only --device may differ): nothing was written\n");
    free(all);
    return code;
}
