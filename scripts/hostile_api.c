/* Issue 23's hostile campaign, items 7, 8 and 9: the piece and stream C API given hostile fields.
 * Built and run by scripts/hostile23/api.py against a build's static libraries (also the sanitizer
 * build's). One line of JSON per case on stdout, each preceded by a "begin" line, so that the
 * campaign knows which case a crash ended and starts again after it.
 *
 *   hostile_api piece SEED FIRST COUNT [DEVICE]   rsmooth_smooth_piece with seeded hostile info
 *       fields, params, buffers (NULL, overlapping) and contexts (the reference path, and DEVICE
 *       every fourth case). Oracle: the whole mesh filtered in memory by the same path with the
 *       same sigmas in absolute units; an OK result must be finite and match it (bit for bit is
 *       promised; beyond 1e-9 mean edges on the reference path, or 1e-3 on a device, is a wrong
 *       answer); a refusal must say why and write nothing (outputs and inputs unchanged).
 *   hostile_api reentry SEED FIRST COUNT DEVICE     a progress callback calls rsmooth again from
 *       inside a call on DEVICE (the same context, another, the reference path, destroy, getters):
 *       a nested call on the same context is refused at once, never a deadlock (a hang here), and
 *       the outer result is the plain call's.
 *   hostile_api halo SEED FIRST COUNT               rsmooth_piece_halo with hostile figures: an OK
 *       halo is finite and covers the filter's reach (cutoff * sigma_f), plus `reach` where the
 *       predictors' normals are mollified.
 *   hostile_api stream IN OUT REPLACE RANK RANKS SYNC TMPDIR MAX_MEMORY
 *       one rsmooth_stream_smooth on the reference path; SYNC none, or fork: two processes, ranks 0
 *       and 1, with an all-reduce over pipes. TMPDIR '-' is NULL. The campaign judges the files. */
#define _GNU_SOURCE
#include "rsmooth.h"
#include "rsmooth_io.h"

#include <float.h>
#include <limits.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

/* ---- a small seeded generator ------------------------------------------------------------- */

static uint64_t state;

static uint64_t next(void) {
    state ^= state << 13;
    state ^= state >> 7;
    state ^= state << 17;
    return state;
}

static int below(int n) {
    return (int)(next() % (uint64_t)n);
}
static double uniform(double a, double b) {
    return a + (b - a) * (double)(next() >> 11) / 9007199254740992.0;
}
static int chance(int percent) {
    return below(100) < percent;
}

/* A double from a pool of hostile values around `usual`. */
static double hostile_double(double usual) {
    switch (below(14)) {
    case 0:
        return 0;
    case 1:
        return -usual;
    case 2:
        return NAN;
    case 3:
        return INFINITY;
    case 4:
        return -INFINITY;
    case 5:
        return DBL_MIN / 4; /* subnormal */
    case 6:
        return DBL_MAX;
    case 7:
        return 1e-300;
    case 8:
        return 1e300;
    case 9:
        return ldexp(usual, below(2200) - 1100);
    case 10:
        return usual * uniform(0.25, 4);
    default:
        return usual;
    }
}

static int hostile_int(int usual, int high) {
    switch (below(8)) {
    case 0:
        return -1;
    case 1:
        return high + 1;
    case 2:
        return INT_MAX;
    case 3:
        return INT_MIN;
    case 4:
        return below(high + 2);
    default:
        return usual;
    }
}

/* ---- the mesh and its figures -------------------------------------------------------------- */

enum { SIDE = 24 };

typedef struct mesh {
    size_t v, t;
    double *arena;     /* 9 v doubles: positions at arena + 3 v, room to overlap on both sides */
    double *positions; /* arena + 3 v */
    double *original;
    uint32_t *indices;
    uint32_t *indices_original;
    double mean_edge, mean_area;
} mesh;

static void make_mesh(mesh *m) {
    m->v = SIDE * SIDE;
    m->t = 2 * (SIDE - 1) * (SIDE - 1);
    m->arena = calloc(9 * m->v, sizeof *m->arena);
    m->original = malloc(3 * m->v * sizeof *m->original);
    /* room for 3 v doubles: out may be pointed at the indices */
    m->indices = malloc(3 * m->v * sizeof(double) > 3 * m->t * sizeof *m->indices
                            ? 3 * m->v * sizeof(double)
                            : 3 * m->t * sizeof *m->indices);
    m->indices_original = malloc(3 * m->t * sizeof *m->indices);
    if (!m->arena || !m->original || !m->indices || !m->indices_original)
        exit(3);
    m->positions = m->arena + 3 * m->v;
    uint64_t keep = state;
    state = 0x9e3779b97f4a7c15u;
    for (size_t j = 0, k = 0; j < SIDE; j++)
        for (size_t i = 0; i < SIDE; i++, k++) {
            m->original[3 * k] = (double)i + uniform(-0.2, 0.2);
            m->original[3 * k + 1] = (double)j + uniform(-0.2, 0.2);
            m->original[3 * k + 2] = uniform(-0.15, 0.15) + 0.02 * (double)(i * j % 7);
        }
    state = keep;
    size_t n = 0;
    for (uint32_t j = 0; j + 1 < SIDE; j++)
        for (uint32_t i = 0; i + 1 < SIDE; i++) {
            uint32_t a = j * SIDE + i;
            uint32_t tri[6] = {a, a + 1, a + SIDE + 1, a, a + SIDE + 1, a + SIDE};
            memcpy(m->indices_original + n, tri, sizeof tri);
            n += 6;
        }
    memcpy(m->positions, m->original, 3 * m->v * sizeof *m->positions);
    memcpy(m->indices, m->indices_original, 3 * m->t * sizeof *m->indices);
    rsmooth_error err;
    if (rsmooth_mean_edge_length(RSMOOTH_FLOAT64, m->positions, m->v, m->indices, m->t,
                                 &m->mean_edge, &err) != RSMOOTH_OK)
        exit(3);
    double sum = 0;
    for (size_t f = 0; f < m->t; f++) {
        const double *p[3];
        for (int c = 0; c < 3; c++)
            p[c] = m->original + 3 * (size_t)m->indices[3 * f + (size_t)c];
        double e1[3], e2[3];
        for (int c = 0; c < 3; c++) {
            e1[c] = p[1][c] - p[0][c];
            e2[c] = p[2][c] - p[0][c];
        }
        double x = e1[1] * e2[2] - e1[2] * e2[1], y = e1[2] * e2[0] - e1[0] * e2[2],
               z = e1[0] * e2[1] - e1[1] * e2[0];
        sum += sqrt(x * x + y * y + z * z) / 2;
    }
    m->mean_area = sum / (double)m->t;
}

/* ---- output --------------------------------------------------------------------------------- */

/* Prints a JSON string: quotes, backslashes and control characters escaped. */
static void json_string(const char *s) {
    putchar('"');
    for (; *s; s++) {
        unsigned char ch = (unsigned char)*s;
        if (ch == '"' || ch == '\\')
            printf("\\%c", ch);
        else if (ch < 0x20)
            printf("\\u%04x", ch);
        else
            putchar(ch);
    }
    putchar('"');
}

static void verdict(int index, const char *what, rsmooth_status st, const char *message,
                    const char *kind, const char *detail) {
    printf("{\"case\": %d, \"what\": ", index);
    json_string(what);
    printf(", \"status\": ");
    json_string(rsmooth_status_str(st));
    printf(", \"message\": ");
    json_string(message);
    printf(", \"verdict\": ");
    json_string(kind);
    printf(", \"detail\": ");
    json_string(detail);
    printf("}\n");
    fflush(stdout);
}

/* ---- rsmooth_smooth_piece ------------------------------------------------------------------- */

typedef struct piece_case {
    rsmooth_piece_info info;
    rsmooth_params params;
    const rsmooth_params *params_arg; /* &params, or NULL */
    const double *positions;
    const uint32_t *indices;
    size_t v, t;
    double *out;
    rsmooth_context *ctx;
    char what[600];
} piece_case;

#define SAY(...) (used += (size_t)snprintf(pc->what + used, sizeof pc->what - used, __VA_ARGS__))

static void hostile_info(piece_case *pc, const mesh *m, size_t *used_ptr) {
    size_t used = *used_ptr;
    rsmooth_piece_info_init(&pc->info);
    pc->info.core_count = m->v;
    pc->info.mean_edge_length = m->mean_edge;
    pc->info.mean_area = m->mean_area;
    if (chance(30)) {
        const size_t sizes[] = {0, 1, sizeof pc->info - 8, sizeof pc->info + 8, SIZE_MAX};
        pc->info.struct_size = sizes[below(5)];
        SAY("info.struct_size %zu; ", pc->info.struct_size);
    }
    if (chance(30)) {
        const size_t counts[] = {0, 1, m->v / 2, m->v - 1, m->v + 1, SIZE_MAX};
        pc->info.core_count = counts[below(6)];
        SAY("core_count %zu; ", pc->info.core_count);
    }
    if (chance(40)) {
        pc->info.mean_edge_length = hostile_double(m->mean_edge);
        SAY("mean_edge_length %a; ", pc->info.mean_edge_length);
    }
    if (chance(25)) {
        pc->info.mean_area = chance(50) ? hostile_double(m->mean_area) : m->mean_area * 1e-300;
        SAY("mean_area %a; ", pc->info.mean_area);
    }
    if (chance(50)) {
        const double specials[] = {3, -1, NAN, INFINITY, 1.5, DBL_MIN / 4, 0};
        pc->info.scale = chance(70) ? ldexp(1, below(2200) - 1100) : specials[below(7)];
        SAY("scale %a; ", pc->info.scale);
    }
    *used_ptr = used;
}

/* The fields of rsmooth_params a case may spoil, with their usual values. */
static const struct {
    const char *name;
    size_t offset;
    double usual;
} double_fields[] = {
    {"sigma_f", offsetof(rsmooth_params, sigma_f), 2},
    {"sigma_g", offsetof(rsmooth_params, sigma_g), 0.5},
    {"cutoff", offsetof(rsmooth_params, cutoff), 2},
    {"mollify_cutoff", offsetof(rsmooth_params, mollify_cutoff), 1},
    {"normal_sigma_s", offsetof(rsmooth_params, normal_sigma_s), 1},
    {"normal_sigma_n", offsetof(rsmooth_params, normal_sigma_n), 0.35},
    {"pass_confidence", offsetof(rsmooth_params, pass_confidence), 0.5},
    {"discrepancy_level", offsetof(rsmooth_params, discrepancy_level), 0.3},
    {"sigma_c", offsetof(rsmooth_params, sigma_c), 0.1},
};
static const struct {
    const char *name;
    size_t offset;
    int usual, high;
} int_fields[] = {
    {"absolute", offsetof(rsmooth_params, absolute), 1, 1},
    {"mollify", offsetof(rsmooth_params, mollify), 0, 1},
    {"predictor", offsetof(rsmooth_params, predictor), 1, 1},
    {"normal_filter", offsetof(rsmooth_params, normal_filter), 1, 1},
    {"normal_iterations", offsetof(rsmooth_params, normal_iterations), 3, 100},
    {"influence", offsetof(rsmooth_params, influence), 2, 3},
    {"passes", offsetof(rsmooth_params, passes), 2, 100},
    {"vertex_updates", offsetof(rsmooth_params, vertex_updates), 1, 1000},
};
enum {
    DOUBLE_FIELDS = sizeof double_fields / sizeof *double_fields,
    INT_FIELDS = sizeof int_fields / sizeof *int_fields
};

static void hostile_params(piece_case *pc, const mesh *m, size_t *used_ptr) {
    size_t used = *used_ptr;
    rsmooth_params *p = &pc->params;
    rsmooth_params_init(p);
    pc->params_arg = chance(20) ? NULL : p;
    if (!pc->params_arg) {
        SAY("params NULL; ");
        *used_ptr = used;
        return;
    }
    static float colors[3 * SIDE * SIDE];
    static uint8_t mask[SIDE * SIDE];
    for (int k = below(4); k > 0; k--) {
        int pick = below(DOUBLE_FIELDS + INT_FIELDS + 3);
        if (pick < DOUBLE_FIELDS) {
            double *field = (double *)(void *)((char *)p + double_fields[pick].offset);
            *field = hostile_double(double_fields[pick].usual);
            SAY("%s %a; ", double_fields[pick].name, *field);
        } else if ((pick -= DOUBLE_FIELDS) < INT_FIELDS) {
            int *field = (int *)(void *)((char *)p + int_fields[pick].offset);
            *field = hostile_int(int_fields[pick].usual, int_fields[pick].high);
            SAY("%s %d; ", int_fields[pick].name, *field);
        } else if (pick == INT_FIELDS) {
            p->colors = colors;
            SAY("colors set; ");
        } else if (pick == INT_FIELDS + 1) {
            p->move_mask = mask;
            SAY("move_mask set; ");
        } else {
            const size_t sizes[] = {0, 8, 64, sizeof *p + 64, SIZE_MAX};
            p->struct_size = sizes[below(5)];
            SAY("params.struct_size %zu; ", p->struct_size);
        }
    }
    if (p->absolute == 1 && chance(50)) { /* absolute widths in the mesh's units */
        p->sigma_f *= m->mean_edge;
        p->sigma_g *= m->mean_edge;
        p->normal_sigma_s *= m->mean_edge;
    }
    *used_ptr = used;
}

static void hostile_buffers(piece_case *pc, mesh *m, double *out_area, size_t *used_ptr) {
    size_t used = *used_ptr;
    pc->positions = m->positions;
    pc->indices = m->indices;
    pc->v = m->v;
    pc->t = m->t;
    pc->out = out_area;
    switch (chance(35) ? below(11) : -1) {
    case 0:
        pc->out = NULL;
        SAY("out NULL; ");
        break;
    case 1:
        pc->out = m->positions;
        SAY("out = positions; ");
        break;
    case 2:
        pc->out = m->positions + 3 * (1 + (size_t)below((int)m->v - 1));
        SAY("out inside positions; ");
        break;
    case 3:
        pc->out = m->positions - 3 * (1 + (size_t)below((int)m->v - 1));
        SAY("out before positions, overlapping; ");
        break;
    case 4:
        pc->out = (double *)(void *)m->indices;
        SAY("out = indices; ");
        break;
    case 5:
        pc->positions = NULL;
        SAY("positions NULL; ");
        break;
    case 6:
        pc->indices = NULL;
        SAY("indices NULL; ");
        break;
    case 7:
        pc->v = 0;
        SAY("vertex_count 0; ");
        break;
    case 8:
        pc->t = 0;
        SAY("triangle_count 0; ");
        break;
    case 9: {
        size_t at = (size_t)below((int)(3 * m->t));
        m->indices[at] = chance(50) ? (uint32_t)m->v : UINT32_MAX;
        SAY("index %zu = %u; ", at, m->indices[at]);
        break;
    }
    case 10:
        m->positions[below((int)(3 * m->v))] = chance(50) ? NAN : 1e300;
        SAY("a position NaN or 1e300; ");
        break;
    default:
        break;
    }
    *used_ptr = used;
}

/* The whole mesh by the same path, from the arrays the piece was given (as they were before the
 * call), sigmas in absolute units from the piece's mean edge: what an OK piece must equal on its
 * core vertices. */
static rsmooth_status oracle(const piece_case *pc, const double *in_pos, const uint32_t *in_idx,
                             double *whole) {
    rsmooth_params p;
    if (pc->params_arg)
        p = pc->params;
    else
        rsmooth_params_init(&p);
    if (p.absolute == 0) { /* every width in mean edge lengths, into the mesh's units */
        p.absolute = 1;
        p.sigma_f *= pc->info.mean_edge_length;
        p.sigma_g *= pc->info.mean_edge_length;
        if (p.normal_filter == RSMOOTH_NORMALS_BILATERAL) /* else unused */
            p.normal_sigma_s *= pc->info.mean_edge_length;
    }
    rsmooth_error err;
    if (pc->ctx)
        return rsmooth_smooth(pc->ctx, RSMOOTH_FLOAT64, in_pos, pc->v, in_idx, pc->t, &p, whole,
                              NULL, NULL, NULL, &err);
    return rsmooth_smooth_reference(RSMOOTH_FLOAT64, in_pos, pc->v, in_idx, pc->t, &p, whole, NULL,
                                    NULL, NULL, &err);
}

/* The arrays as the call was given them, to compare and to feed the oracle. */
typedef struct snapshot {
    double *positions;
    uint32_t *indices;
} snapshot;

static const char *judge_ok(piece_case *pc, const mesh *m, const snapshot *in, double *whole,
                            char *detail, size_t size) {
    size_t core = pc->info.core_count, nonfinite = 0;
    if (!pc->positions || !pc->indices || !pc->out || core > pc->v)
        return snprintf(detail, size,
                        "OK with positions, indices or out NULL, or core_count "
                        "beyond the vertices"),
               "wrong";
    for (size_t i = 0; i < 3 * core; i++)
        nonfinite += !isfinite(pc->out[i]);
    if (nonfinite)
        return snprintf(detail, size, "OK with %zu non-finite outputs", nonfinite), "wrong";
    rsmooth_status os = oracle(pc, in->positions, in->indices, whole);
    if (os != RSMOOTH_OK)
        return snprintf(detail, size, "OK where the whole mesh with these params is %s",
                        rsmooth_status_str(os)),
               "wrong";
    double worst = 0;
    for (size_t i = 0; i < 3 * core; i++)
        worst = fmax(worst, fabs(pc->out[i] - whole[i]) / m->mean_edge);
    if (!(worst <= (pc->ctx ? 1e-3 : 1e-9)))
        return snprintf(detail, size, "OK but %.3g mean edges off the whole-mesh run", worst),
               "wrong";
    const double *lo = pc->out, *hi = pc->out + 3 * core;
    if (lo < pc->positions + 3 * pc->v && pc->positions < hi)
        return snprintf(detail, size,
                        "OK with out overlapping positions (refused, says the "
                        "header)"),
               "other";
    if (worst > 0)
        snprintf(detail, size, "not bit for bit: %.3g mean edges", worst);
    return "ok";
}

static void judge_piece(int index, piece_case *pc, const mesh *m, rsmooth_status st,
                        const rsmooth_error *err, const double *out_area, const snapshot *in,
                        double *whole) {
    char detail[300] = "";
    const char *kind = "ok";
    if (st == RSMOOTH_OK) {
        kind = judge_ok(pc, m, in, whole, detail, sizeof detail);
    } else {
        int written = 0;
        for (size_t i = 0; i < 3 * m->v; i++)
            written += out_area[i] != -12345.0;
        /* argument refusals write nothing; a device or numerical failure leaves the outputs
         * undefined (rsmooth_smooth) */
        int argument = st == RSMOOTH_ERROR_INVALID_ARGUMENT || st == RSMOOTH_ERROR_UNSUPPORTED;
        if (written && argument) {
            kind = "other";
            snprintf(detail, sizeof detail, "refused, yet %d output values written", written);
        } else if (!err->message[0]) {
            kind = "other";
            snprintf(detail, sizeof detail, "refused without a message");
        } else if ((pc->positions &&
                    memcmp(pc->positions, in->positions, 3 * m->v * sizeof *in->positions) != 0) ||
                   (pc->indices &&
                    memcmp(pc->indices, in->indices, 3 * m->t * sizeof *in->indices) != 0)) {
            kind = "lost";
            snprintf(detail, sizeof detail, "a refused call changed its input arrays");
        }
    }
    verdict(index, pc->what, st, err->message, kind, detail);
}

static int run_pieces(int first, int count, const char *device) {
    mesh m;
    make_mesh(&m);
    rsmooth_context *ctx = NULL;
    rsmooth_error err;
    if (device && rsmooth_context_create(device, &ctx, &err) != RSMOOTH_OK) {
        fprintf(stderr, "hostile_api: no device %s: %s\n", device, err.message);
        ctx = NULL;
    }
    double *out_area = malloc(3 * m.v * sizeof *out_area);
    double *whole = malloc(3 * m.v * sizeof *whole);
    snapshot in = {malloc(3 * m.v * sizeof *in.positions), malloc(3 * m.t * sizeof *in.indices)};
    if (!out_area || !whole || !in.positions || !in.indices)
        return 3;
    uint64_t seed = state;
    for (int index = first; index < count; index++) {
        state = seed ^ (0x9e3779b97f4a7c15u * (uint64_t)(index + 1));
        next();
        printf("begin %d\n", index);
        fflush(stdout);
        memcpy(m.positions, m.original, 3 * m.v * sizeof *m.positions);
        memcpy(m.indices, m.indices_original, 3 * m.t * sizeof *m.indices);
        for (size_t i = 0; i < 3 * m.v; i++)
            out_area[i] = -12345.0;
        piece_case pc;
        memset(&pc, 0, sizeof pc);
        size_t used = 0;
        pc.ctx = ctx && index % 4 == 3 ? ctx : NULL;
        used += (size_t)snprintf(pc.what, sizeof pc.what, "%s: ", pc.ctx ? "device" : "reference");
        hostile_info(&pc, &m, &used);
        hostile_params(&pc, &m, &used);
        hostile_buffers(&pc, &m, out_area, &used);
        memcpy(in.positions, m.positions, 3 * m.v * sizeof *in.positions);
        memcpy(in.indices, m.indices, 3 * m.t * sizeof *in.indices);
        rsmooth_report report;
        rsmooth_report_init(&report);
        rsmooth_error e;
        rsmooth_error_init(&e);
        rsmooth_status st = rsmooth_smooth_piece(pc.ctx, pc.positions, pc.v, pc.indices, pc.t,
                                                 chance(3) ? NULL : &pc.info, pc.params_arg, pc.out,
                                                 chance(50) ? &report : NULL, &e);
        judge_piece(index, &pc, &m, st, &e, out_area, &in, whole);
    }
    rsmooth_context_destroy(ctx);
    free(out_area);
    free(whole);
    free(in.positions);
    free(in.indices);
    free(m.arena);
    free(m.original);
    free(m.indices);
    free(m.indices_original);
    return 0;
}

/* ---- rsmooth_piece_halo --------------------------------------------------------------------- */

static int run_halos(int first, int count) {
    uint64_t seed = state;
    for (int index = first; index < count; index++) {
        state = seed ^ (0x9e3779b97f4a7c15u * (uint64_t)(index + 1));
        next();
        printf("begin %d\n", index);
        fflush(stdout);
        piece_case pc;
        memset(&pc, 0, sizeof pc);
        size_t used = 0;
        mesh fake = {.mean_edge = 0.1};
        hostile_params(&pc, &fake, &used);
        double edge = hostile_double(0.1), reach = hostile_double(0.07), halo = -1;
        used += (size_t)snprintf(pc.what + used, sizeof pc.what - used,
                                 "mean_edge_length %a, reach %a", edge, reach);
        rsmooth_error e;
        rsmooth_error_init(&e);
        rsmooth_status st = rsmooth_piece_halo(pc.params_arg, edge, reach, &halo, &e);
        char detail[200] = "";
        const char *kind = "ok";
        if (st == RSMOOTH_OK) {
            rsmooth_params p;
            if (pc.params_arg)
                p = pc.params;
            else
                rsmooth_params_init(&p);
            /* the filter's reach, and the mollified normals' source facets (the predictor's
             * normals) one triangle beyond it */
            double least = p.cutoff * (p.sigma_f * (p.absolute ? 1 : edge));
            if (p.mollify == 1 && p.normal_filter == RSMOOTH_NORMALS_MOLLIFY &&
                p.predictor == RSMOOTH_PREDICT_PROJECTION)
                least += reach;
            if (!isfinite(halo) || halo < 0 || halo < least) {
                kind = "wrong";
                snprintf(detail, sizeof detail, "OK with halo %a (reach %a, cutoff x sigma_f %a)",
                         halo, reach, least);
            }
        } else if (halo != -1) {
            kind = "other";
            snprintf(detail, sizeof detail, "refused, yet out_halo written");
        } else if (!e.message[0]) {
            kind = "other";
            snprintf(detail, sizeof detail, "refused without a message");
        }
        verdict(index, pc.what, st, e.message, kind, detail);
    }
    return 0;
}

/* ---- calls from a progress callback -----------------------------------------------------------
 */

/* What the callback does, once, from inside a call on the context: a nested call on the same
 * context must be refused at once (never wait for the lock its own call holds), destroying it
 * must do nothing, the getters and setters must answer, other paths must work; the outer call's
 * result must be the plain call's. */
typedef struct reentry {
    int action, done;
    rsmooth_context *ctx, *other;
    const mesh *m;
    rsmooth_status inner;
    double *scratch;
} reentry;

static const char *const reentry_actions[] = {
    "rsmooth_smooth on the same context",     "rsmooth_smooth_piece on the same context",
    "rsmooth_context_destroy of the context", "getters and setters of the context",
    "rsmooth_smooth on another context",      "rsmooth_smooth_reference",
    "rsmooth_smooth_view on the same context"};
enum { REENTRY_ACTIONS = sizeof reentry_actions / sizeof *reentry_actions };

static void reentry_progress(void *user, double fraction) {
    reentry *r = user;
    (void)fraction;
    if (r->done++)
        return;
    const mesh *m = r->m;
    rsmooth_error e;
    rsmooth_piece_info info;
    rsmooth_mesh_view view;
    switch (r->action) {
    case 0:
    case 4:
        r->inner =
            rsmooth_smooth(r->action ? r->other : r->ctx, RSMOOTH_FLOAT64, m->original, m->v,
                           m->indices_original, m->t, NULL, r->scratch, NULL, NULL, NULL, &e);
        break;
    case 1:
        rsmooth_piece_info_init(&info);
        info.core_count = m->v;
        info.mean_edge_length = m->mean_edge;
        info.mean_area = m->mean_area;
        r->inner = rsmooth_smooth_piece(r->ctx, m->original, m->v, m->indices_original, m->t, &info,
                                        NULL, r->scratch, NULL, &e);
        break;
    case 2:
        rsmooth_context_destroy(r->ctx);
        r->inner = RSMOOTH_OK;
        break;
    case 3:
        rsmooth_context_set_host_threads(r->ctx, 1);
        rsmooth_context_set_memory_budget(r->ctx, rsmooth_context_memory_budget(r->ctx));
        r->inner = rsmooth_context_device_name(r->ctx) && rsmooth_context_host_threads(r->ctx) &&
                           rsmooth_context_program_cache(r->ctx)
                       ? RSMOOTH_OK
                       : RSMOOTH_ERROR_INVALID_ARGUMENT;
        break;
    case 5:
        r->inner = rsmooth_smooth_reference(RSMOOTH_FLOAT64, m->original, m->v, m->indices_original,
                                            m->t, NULL, r->scratch, NULL, NULL, NULL, &e);
        break;
    default:
        rsmooth_mesh_view_init(&view);
        view.scalar = RSMOOTH_FLOAT64;
        view.positions = m->original;
        view.vertex_count = m->v;
        view.indices = m->indices_original;
        view.triangle_count = m->t;
        r->inner = rsmooth_smooth_view(r->ctx, &view, NULL, r->scratch, 0, NULL, NULL, NULL, &e);
    }
}

static int run_reentry(int first, int count, const char *device) {
    mesh m;
    make_mesh(&m);
    rsmooth_context *ctx = NULL, *other = NULL;
    rsmooth_error err;
    if (rsmooth_context_create(device, &ctx, &err) != RSMOOTH_OK ||
        rsmooth_context_create(device, &other, &err) != RSMOOTH_OK) {
        fprintf(stderr, "hostile_api: no device %s: %s\n", device, err.message);
        return 5;
    }
    double *plain = malloc(3 * m.v * sizeof *plain), *out = malloc(3 * m.v * sizeof *out);
    double *scratch = malloc(3 * m.v * sizeof *scratch);
    if (!plain || !out || !scratch ||
        rsmooth_smooth(ctx, RSMOOTH_FLOAT64, m.original, m.v, m.indices_original, m.t, NULL, plain,
                       NULL, NULL, NULL, &err) != RSMOOTH_OK)
        return 3;
    for (int index = first; index < count; index++) {
        printf("begin %d\n", index);
        fflush(stdout);
        reentry r = {index % REENTRY_ACTIONS, 0, ctx, other, &m, RSMOOTH_OK, scratch};
        rsmooth_params p;
        rsmooth_params_init(&p);
        p.progress = reentry_progress;
        p.progress_user = &r;
        rsmooth_error e;
        rsmooth_error_init(&e);
        rsmooth_status st = rsmooth_smooth(ctx, RSMOOTH_FLOAT64, m.original, m.v,
                                           m.indices_original, m.t, &p, out, NULL, NULL, NULL, &e);
        char what[200], detail[400] = "";
        snprintf(what, sizeof what, "a progress callback calls %s", reentry_actions[r.action]);
        const char *kind = "ok";
        int nested_same = r.action == 0 || r.action == 1 || r.action == 6;
        if (st != RSMOOTH_OK || memcmp(out, plain, 3 * m.v * sizeof *out) != 0) {
            kind = "wrong";
            snprintf(detail, sizeof detail, "the outer call: %s, %s", rsmooth_status_str(st),
                     st == RSMOOTH_OK ? "another result than the plain call's" : e.message);
        } else if (!r.done) {
            snprintf(detail, sizeof detail, "the callback was never called");
        } else if (nested_same && r.inner != RSMOOTH_ERROR_INVALID_ARGUMENT) {
            kind = "other";
            snprintf(detail, sizeof detail, "the nested call on the same context gave %s",
                     rsmooth_status_str(r.inner));
        } else if (!nested_same && r.inner != RSMOOTH_OK) {
            kind = "other";
            snprintf(detail, sizeof detail, "%s gave %s", reentry_actions[r.action],
                     rsmooth_status_str(r.inner));
        }
        verdict(index, what, st, e.message, kind, detail);
    }
    rsmooth_context_destroy(ctx);
    rsmooth_context_destroy(other);
    free(plain);
    free(out);
    free(scratch);
    free(m.arena);
    free(m.original);
    free(m.indices);
    free(m.indices_original);
    return 0;
}

/* ---- rsmooth_stream_smooth ------------------------------------------------------------------- */

/* Two processes' all-reduce over a pair of pipes: each sends its status and takes the larger. */
typedef struct pipe_sync {
    int to_other, from_other;
} pipe_sync;

static int sync_max(void *user, int status) {
    pipe_sync *s = user;
    int other = INT_MAX;
    if (write(s->to_other, &status, sizeof status) != sizeof status ||
        read(s->from_other, &other, sizeof other) != sizeof other)
        return INT_MAX;
    return status > other ? status : other;
}

static rsmooth_status stream_once(char **argv, int rank, int ranks, pipe_sync *sync,
                                  rsmooth_error *e) {
    rsmooth_stream_options o;
    rsmooth_stream_options_init(&o);
    o.replace = atoi(argv[4]);
    o.rank = rank;
    o.ranks = ranks;
    o.tmpdir = strcmp(argv[8], "-") == 0 ? NULL : argv[8];
    o.max_memory = strtoull(argv[9], NULL, 10);
    if (sync) {
        o.sync = sync_max;
        o.sync_user = sync;
    }
    rsmooth_stream_report report;
    rsmooth_stream_report_init(&report);
    rsmooth_error_init(e);
    return rsmooth_stream_smooth(NULL, argv[2], argv[3], NULL, &o, &report, e);
}

static int run_stream(int argc, char **argv) {
    if (argc != 10)
        return 2;
    rsmooth_error e;
    if (strcmp(argv[7], "fork") != 0) {
        rsmooth_status st = stream_once(argv, atoi(argv[5]), atoi(argv[6]), NULL, &e);
        verdict(0, "stream", st, e.message, "", "");
        return 0;
    }
    int a[2], b[2];
    if (pipe(a) != 0 || pipe(b) != 0)
        return 3;
    fflush(stdout);
    pid_t child = fork();
    if (child < 0)
        return 3;
    pipe_sync s = child == 0 ? (pipe_sync){a[1], b[0]} : (pipe_sync){b[1], a[0]};
    rsmooth_status st = stream_once(argv, child == 0 ? 1 : 0, 2, &s, &e);
    verdict(child == 0 ? 1 : 0, "stream rank", st, e.message, "", "");
    if (child == 0)
        _exit(0);
    int ws = 0;
    waitpid(child, &ws, 0);
    if (!WIFEXITED(ws) || WEXITSTATUS(ws) != 0) {
        fprintf(stderr, "hostile_api: rank 1 ended with wait status %d\n", ws);
        return 4;
    }
    return 0;
}

int main(int argc, char **argv) {
    if (argc >= 2 && strcmp(argv[1], "stream") == 0)
        return run_stream(argc, argv);
    if (argc < 5) {
        fprintf(stderr,
                "usage: hostile_api piece|reentry|halo SEED FIRST COUNT [DEVICE] | stream ...\n");
        return 2;
    }
    state = strtoull(argv[2], NULL, 10) * 2654435761u + 1;
    int first = atoi(argv[3]), count = atoi(argv[4]);
    if (strcmp(argv[1], "piece") == 0)
        return run_pieces(first, count, argc > 5 ? argv[5] : NULL);
    if (strcmp(argv[1], "reentry") == 0)
        return run_reentry(first, count, argc > 5 ? argv[5] : "cpu");
    return run_halos(first, count);
}
