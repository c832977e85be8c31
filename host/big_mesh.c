/* rsmooth-big-mesh: streams a very large noisy terrain mesh (and optionally its noise-free truth)
 * to binary PLY, to benchmark smoothing meshes too large to hold in memory. Each vertex and face
 * is computed from its grid position and written at once: memory does not grow with the mesh.
 * Needs only libc and libm. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#define EXIT_IO 1
#define EXIT_USAGE 2
#define BUFFER_BYTES (1u << 20)

static const char usage_text[] =
    "usage: rsmooth-big-mesh OUT.ply --triangles N [--noise S] [--seed K] [--truth TRUTH.ply]\n"
    "                        [--force]\n"
    "\n"
    "Writes a noisy terrain of about N triangles to OUT.ply (binary little-endian PLY, float\n"
    "positions, 32-bit indices) in constant memory, for benchmarking out-of-core smoothing.\n"
    "\n"
    "The surface is a height field over a square grid of (n+1) x (m+1) vertices, spacing 1,\n"
    "two triangles per square (2*n*m >= N, the smallest near-square grid). Its height is\n"
    "piecewise planar with sharp creases on mesh edges: terraces with steep 4-cell ramps every\n"
    "128 diagonals, tilted roofs between rows 150 apart and folds between columns 200 apart.\n"
    "Vertices and faces are written row by row.\n"
    "\n"
    "  --triangles N   triangle count to reach (a positive integer; 1e8 style accepted); at\n"
    "                  most 2^32-1 vertices, so N up to about 8.59e9\n"
    "  --noise S       Gaussian noise added to the heights, in grid spacings (default 0.3)\n"
    "  --seed K        seed of the noise (default 1): the same arguments give the same bytes\n"
    "  --truth T.ply   also write the noise-free mesh (same vertices and faces) to T.ply\n"
    "  --force         replace OUT.ply (and T.ply) if they exist\n"
    "\n"
    "Each file is written to NAME.tmp-PID and renamed when complete; on an error or an\n"
    "interrupt the temporary is removed. Exit status: 0 done, 1 I/O error, 2 bad arguments.\n"
    "At the end one line on stderr gives vertices, triangles, bytes written and seconds.\n";

/* --- deterministic randomness --------------------------------------------------------------- */

static uint64_t mix64(uint64_t z) { /* splitmix64's finaliser */
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* A value in [0, 1) fixed by an integer: the terrain's per-terrace and per-band choices. */
static double hash_unit(int64_t key, uint64_t salt) {
    return (double)(mix64((uint64_t)key * 0x9E3779B97F4A7C15ull + salt) >> 11) * 0x1p-53;
}

/* splitmix64 + Box-Muller: both normals of each pair are used, so one log/sqrt per two. */
typedef struct gauss {
    uint64_t state;
    double spare;
    int have_spare;
} gauss;

static double gauss_next(gauss *g) {
    if (g->have_spare) {
        g->have_spare = 0;
        return g->spare;
    }
    g->state += 0x9E3779B97F4A7C15ull;
    double u1 = (double)((mix64(g->state) >> 11) + 1) * 0x1p-53; /* (0, 1]: log is finite */
    g->state += 0x9E3779B97F4A7C15ull;
    double u2 = (double)(mix64(g->state) >> 11) * 0x1p-53;
    double r = sqrt(-2.0 * log(u1)), a = 6.283185307179586 * u2;
    g->spare = r * sin(a);
    g->have_spare = 1;
    return r * cos(a);
}

/* --- the terrain ------------------------------------------------------------------------------ */
/* Every crease lies on a line i = c, j = c or i - j = c with integer c, i.e. on mesh edges (the
 * split diagonal of each square runs along i - j = const), so the truth is exactly piecewise
 * planar and its sharp edges are edges of the mesh, as in CAD-like test shapes. */

#define TERRACE_PERIOD 128 /* diagonals per terrace, ramp included */
#define TERRACE_RAMP 4     /* the steep part: 1.5 to 4.5 units over 4 cells */
#define ROOF_PERIOD 150    /* rows per roof band: valley, ridge at the middle, valley */
#define FOLD_PERIOD 200    /* columns per fold band */

static int64_t floor_div(int64_t a, int64_t b) {
    int64_t q = a / b;
    return (a % b != 0 && (a < 0) != (b < 0)) ? q - 1 : q;
}

/* Height of terrace L: steps of 1.5 to 4.5, each drawn from L, so it never needs a running sum. */
static double terrace_level(int64_t level) {
    return 3.0 * (double)level + 1.5 * hash_unit(level, 0x7465727261636521ull);
}

static double terrace(int64_t u) {
    int64_t level = floor_div(u, TERRACE_PERIOD);
    int64_t r = u - level * TERRACE_PERIOD;
    double low = terrace_level(level);
    if (r < TERRACE_PERIOD - TERRACE_RAMP)
        return low;
    double t = (double)(r - (TERRACE_PERIOD - TERRACE_RAMP)) / TERRACE_RAMP;
    return low + t * (terrace_level(level + 1) - low);
}

/* A tent of slope `slope` over each band, zero at its ends so neighbouring bands join. */
static double tent(int64_t c, int64_t period, double slope) {
    int64_t d = c - floor_div(c, period) * period;
    return slope * (double)(d < period - d ? d : period - d);
}

/* Slopes drawn per band: flat, gentle or steep, up or down. */
static double band_slope(int64_t band, uint64_t salt, double steepest) {
    static const double choice[5] = {0.0, 0.5, 1.0, -0.5, -1.0};
    return steepest * choice[(int)(hash_unit(band, salt) * 5.0)];
}

static double roof_of_row(int64_t j) {
    return tent(j, ROOF_PERIOD, band_slope(floor_div(j, ROOF_PERIOD), 0x726F6F66ull, 0.3));
}

static double fold_of_column(int64_t i) {
    return tent(i, FOLD_PERIOD, band_slope(floor_div(i, FOLD_PERIOD), 0x666F6C64ull, 0.2));
}

/* --- buffered little-endian output ------------------------------------------------------------ */

typedef struct sink {
    const char *path; /* the final name, for messages */
    char *temporary;  /* where the bytes go until complete */
    FILE *file;
    unsigned char *buffer;
    size_t used;
    uint64_t bytes;
    int failed; /* errno of the first failure, or 0 */
} sink;

/* The temporaries, for the signal handler: removed if an interrupt stops the program. */
static char *volatile pending[2];

static void remove_pending_and_exit(int signal_number) {
    for (int k = 0; k < 2; k++)
        if (pending[k])
            unlink(pending[k]);
    signal(signal_number, SIG_DFL);
    raise(signal_number);
}

static void sink_flush(sink *s) {
    if (s->used && !s->failed && fwrite(s->buffer, 1, s->used, s->file) != s->used)
        s->failed = errno ? errno : EIO;
    s->bytes += s->used;
    s->used = 0;
}

/* Room for one record (at most 16 bytes) in the buffer. */
static unsigned char *sink_reserve(sink *s, size_t size) {
    if (s->used + size > BUFFER_BYTES)
        sink_flush(s);
    unsigned char *p = s->buffer + s->used;
    s->used += size;
    return p;
}

/* Byte by byte, so the file is little-endian on any host. */
static void put_u32(unsigned char *p, uint32_t v) {
    p[0] = (unsigned char)v;
    p[1] = (unsigned char)(v >> 8);
    p[2] = (unsigned char)(v >> 16);
    p[3] = (unsigned char)(v >> 24);
}

static void put_vertex(sink *s, float x, float y, float z) {
    unsigned char *p = sink_reserve(s, 12);
    float xyz[3] = {x, y, z};
    for (int c = 0; c < 3; c++) {
        uint32_t bits;
        memcpy(&bits, &xyz[c], 4);
        put_u32(p + 4 * c, bits);
    }
}

static void put_triangle(sink *s, uint32_t a, uint32_t b, uint32_t c) {
    unsigned char *p = sink_reserve(s, 13);
    p[0] = 3;
    put_u32(p + 1, a);
    put_u32(p + 5, b);
    put_u32(p + 9, c);
}

static int sink_open(sink *s, const char *path, unsigned char *buffer) {
    memset(s, 0, sizeof *s);
    s->path = path;
    s->buffer = buffer;
    size_t size = strlen(path) + 32;
    s->temporary = malloc(size);
    if (!s->temporary) {
        fprintf(stderr, "rsmooth-big-mesh: out of memory\n");
        return -1;
    }
    snprintf(s->temporary, size, "%s.tmp-%ld", path, (long)getpid());
    s->file = fopen(s->temporary, "wbx"); /* x: never clobber a file of that name */
    if (!s->file) {
        fprintf(stderr, "rsmooth-big-mesh: %s: cannot create %s: %s\n", path, s->temporary,
                strerror(errno));
        return -1;
    }
    setvbuf(s->file, NULL, _IONBF, 0); /* our 1 MB buffer already batches the writes */
    return 0;
}

/* Closes the temporary and reports the first failure; 0 when every byte reached the file. */
static int sink_close(sink *s) {
    sink_flush(s);
    if (s->file && fclose(s->file) != 0 && !s->failed)
        s->failed = errno ? errno : EIO;
    s->file = NULL;
    if (s->failed) {
        fprintf(stderr, "rsmooth-big-mesh: %s: write failed: %s\n", s->path, strerror(s->failed));
        return -1;
    }
    return 0;
}

/* Moves the complete temporary to its name. Without --force, link() refuses atomically a name
 * that appeared meanwhile; where hard links are not supported, a check and rename() instead. */
static int sink_commit(sink *s, int force) {
    int ok, error = 0;
    if (force) {
        ok = rename(s->temporary, s->path) == 0;
    } else if (link(s->temporary, s->path) == 0) {
        unlink(s->temporary); /* the file is in place either way */
        ok = 1;
    } else if (errno == EEXIST || access(s->path, F_OK) == 0) {
        ok = 0;
        error = EEXIST;
    } else {
        ok = rename(s->temporary, s->path) == 0;
    }
    if (!ok) {
        if (!error)
            error = errno;
        fprintf(stderr, "rsmooth-big-mesh: %s: %s\n", s->path,
                error == EEXIST ? "appeared while writing (use --force to replace it)"
                                : strerror(error));
        return -1;
    }
    return 0;
}

static void sink_discard(sink *s) {
    if (s->file)
        fclose(s->file);
    s->file = NULL;
    if (s->temporary)
        unlink(s->temporary);
}

/* --- the mesh --------------------------------------------------------------------------------- */

typedef struct grid {
    uint64_t requested, n, m; /* n columns and m rows of squares */
    uint64_t vertices, triangles;
    double noise;
    uint64_t seed;
} grid;

static void write_header(sink *s, const grid *g, int truth) {
    char text[1024];
    int length = snprintf(
        text, sizeof text,
        "ply\nformat binary_little_endian 1.0\n"
        "comment rsmooth-big-mesh%s --triangles %llu --noise %.15g --seed %llu (grid %llu x %llu "
        "squares, spacing 1)\n"
        "element vertex %llu\nproperty float x\nproperty float y\nproperty float z\n"
        "element face %llu\nproperty list uchar %s vertex_indices\nend_header\n",
        truth ? " truth of" : "", (unsigned long long)g->requested, g->noise,
        (unsigned long long)g->seed, (unsigned long long)g->n, (unsigned long long)g->m,
        (unsigned long long)g->vertices, (unsigned long long)g->triangles,
        g->vertices - 1 > INT32_MAX ? "uint" : "int"); /* "int" as most tools expect, if it fits */
    memcpy(sink_reserve(s, (size_t)length), text, (size_t)length);
}

/* Streams the vertices and then the faces to `out` (noisy) and `truth` (if not NULL). */
static void write_mesh(const grid *g, sink *out, sink *truth) {
    write_header(out, g, 0);
    if (truth)
        write_header(truth, g, 1);
    gauss noise = {mix64(g->seed), 0.0, 0};
    /* Centred, so float keeps the most precision in x and y. */
    const double x0 = -0.5 * (double)g->n, y0 = -0.5 * (double)g->m;
    for (uint64_t j = 0; j <= g->m && !out->failed && !(truth && truth->failed); j++) {
        double roof = roof_of_row((int64_t)j);
        float y = (float)(y0 + (double)j);
        for (uint64_t i = 0; i <= g->n; i++) {
            double z = terrace((int64_t)i - (int64_t)j) + roof + fold_of_column((int64_t)i);
            float x = (float)(x0 + (double)i);
            double dz = g->noise > 0 ? g->noise * gauss_next(&noise) : 0.0;
            put_vertex(out, x, y, (float)(z + dz));
            if (truth)
                put_vertex(truth, x, y, (float)z);
        }
    }
    /* Square (i, j) has corners a b (row j) and c d (row j+1); both triangles are counter-
     * clockwise seen from above and share the diagonal a-d, which runs along i - j = const. */
    const uint64_t row = g->n + 1;
    for (uint64_t j = 0; j < g->m && !out->failed && !(truth && truth->failed); j++) {
        for (uint64_t i = 0; i < g->n; i++) {
            uint32_t a = (uint32_t)(j * row + i), b = a + 1;
            uint32_t c = (uint32_t)(a + row), d = c + 1;
            put_triangle(out, a, b, d);
            put_triangle(out, a, d, c);
            if (truth) {
                put_triangle(truth, a, b, d);
                put_triangle(truth, a, d, c);
            }
        }
    }
}

/* The smallest near-square grid with 2*n*m >= N: n = ceil(sqrt(N/2)), m = ceil(N / 2n) <= n. */
static void choose_grid(grid *g) {
    uint64_t N = g->requested, n = (uint64_t)ceil(sqrt((double)N / 2.0));
    while (2 * n * n < N)
        n++;
    while (n > 1 && 2 * (n - 1) * (n - 1) >= N)
        n--;
    g->n = n;
    g->m = (N + 2 * n - 1) / (2 * n);
    g->vertices = (g->n + 1) * (g->m + 1);
    g->triangles = 2 * g->n * g->m;
}

/* --- arguments -------------------------------------------------------------------------------- */

/* A positive integer, as digits or as 1e8 / 2.5e7 when that is a whole number. */
static int parse_count(const char *text, uint64_t *value) {
    char *end;
    errno = 0;
    if (text[0] >= '0' && text[0] <= '9') {
        unsigned long long v = strtoull(text, &end, 10);
        if (*end == '\0' && errno == 0) {
            *value = v;
            return v > 0 ? 0 : -1;
        }
        errno = 0;
        double d = strtod(text, &end);
        if (*end == '\0' && errno == 0 && d >= 1 && d <= 0x1p63 && d == floor(d)) {
            *value = (uint64_t)d;
            return 0;
        }
    }
    return -1;
}

static int parse_seed(const char *text, uint64_t *value) {
    char *end;
    errno = 0;
    unsigned long long v = strtoull(text, &end, 10);
    if (text[0] < '0' || text[0] > '9' || *end != '\0' || errno != 0)
        return -1;
    *value = v;
    return 0;
}

static int parse_noise(const char *text, double *value) {
    char *end;
    errno = 0;
    double v = strtod(text, &end);
    if (end == text || *end != '\0' || errno != 0 || !(v >= 0) || !isfinite(v))
        return -1;
    *value = v;
    return 0;
}

static int usage_error(const char *what, const char *arg) {
    fprintf(stderr, "rsmooth-big-mesh: %s%s%s\n(rsmooth-big-mesh --help for usage)\n", what,
            arg ? ": " : "", arg ? arg : "");
    return EXIT_USAGE;
}

/* Refused before the work, not after minutes of writing. */
static int check_output(const char *path, int force) {
    struct stat st;
    if (stat(path, &st) == 0) {
        if (S_ISDIR(st.st_mode))
            return usage_error("is a directory", path);
        if (!force) {
            fprintf(stderr, "rsmooth-big-mesh: %s: already exists (use --force to replace it)\n",
                    path);
            return EXIT_USAGE;
        }
    }
    return 0;
}

static double seconds_now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

int main(int argc, char **argv) {
    const char *out_path = NULL, *truth_path = NULL;
    grid g = {0, 0, 0, 0, 0, 0.3, 1};
    int force = 0, have_count = 0;
    for (int k = 1; k < argc; k++) {
        const char *a = argv[k];
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            fputs(usage_text, stdout);
            return 0;
        }
        if (!strcmp(a, "--force")) {
            force = 1;
            continue;
        }
        int takes_value = !strcmp(a, "--triangles") || !strcmp(a, "--noise") ||
                          !strcmp(a, "--seed") || !strcmp(a, "--truth");
        if (takes_value && k + 1 >= argc)
            return usage_error("needs a value", a);
        if (!strcmp(a, "--triangles")) {
            if (parse_count(argv[++k], &g.requested) != 0)
                return usage_error("--triangles needs a positive integer, not", argv[k]);
            have_count = 1;
        } else if (!strcmp(a, "--noise")) {
            if (parse_noise(argv[++k], &g.noise) != 0)
                return usage_error("--noise needs a finite number >= 0, not", argv[k]);
        } else if (!strcmp(a, "--seed")) {
            if (parse_seed(argv[++k], &g.seed) != 0)
                return usage_error("--seed needs an integer from 0 to 2^64-1, not", argv[k]);
        } else if (!strcmp(a, "--truth")) {
            truth_path = argv[++k];
        } else if (a[0] == '-' && a[1] != '\0') {
            return usage_error("unknown option", a);
        } else if (out_path) {
            return usage_error("only one output file, but also", a);
        } else {
            out_path = a;
        }
    }
    if (!out_path)
        return usage_error("no output file given", NULL);
    if (!have_count)
        return usage_error("--triangles N is required", NULL);
    if (truth_path && !strcmp(truth_path, out_path))
        return usage_error("--truth must name another file than the output", truth_path);
    /* Beyond 2^34 the grid alone needs far more than 2^32 vertices; below, count exactly. */
    if (g.requested <= (1ull << 34))
        choose_grid(&g);
    if (g.requested > (1ull << 34) || g.vertices > UINT32_MAX) {
        fprintf(stderr,
                "rsmooth-big-mesh: %llu triangles need more than 2^32-1 vertices, which PLY's "
                "32-bit indices cannot number\n",
                (unsigned long long)g.requested);
        return EXIT_USAGE;
    }
    int code = check_output(out_path, force);
    if (code == 0 && truth_path)
        code = check_output(truth_path, force);
    if (code != 0)
        return code;

    /* The only buffers: fixed, whatever N. */
    static unsigned char buffers[2][BUFFER_BYTES];
    sink out, truth;
    memset(&truth, 0, sizeof truth);
    double start = seconds_now();
    signal(SIGINT, remove_pending_and_exit);
    signal(SIGTERM, remove_pending_and_exit);
    signal(SIGHUP, remove_pending_and_exit);
    int ok = sink_open(&out, out_path, buffers[0]) == 0;
    pending[0] = out.file ? out.temporary : NULL;
    if (ok && truth_path) {
        ok = sink_open(&truth, truth_path, buffers[1]) == 0;
        pending[1] = truth.file ? truth.temporary : NULL;
    }
    if (ok)
        write_mesh(&g, &out, truth_path ? &truth : NULL);
    ok = ok && sink_close(&out) == 0 && (!truth_path || sink_close(&truth) == 0);
    ok = ok && (!truth_path || sink_commit(&truth, force) == 0) && sink_commit(&out, force) == 0;
    if (!ok) {
        sink_discard(&out);
        sink_discard(&truth);
        return EXIT_IO;
    }
    pending[0] = pending[1] = NULL;
    free(out.temporary);
    free(truth.temporary);
    fprintf(stderr,
            "rsmooth-big-mesh: %llu vertices, %llu triangles, %llu bytes written%s, %.2f s\n",
            (unsigned long long)g.vertices, (unsigned long long)g.triangles,
            (unsigned long long)(out.bytes + truth.bytes), truth_path ? " (2 files)" : "",
            seconds_now() - start);
    return 0;
}
