/* Every kernel under Oclgrind, an OpenCL simulator that runs work-items with real work-group and
 * barrier semantics, as a GPU does (PoCL's CPU device checks none of it), with its checks on:
 * memory accesses out of bounds, API misuse (OCLGRIND_CHECK_API), data races
 * (OCLGRIND_DATA_RACES) and uses of uninitialised values (OCLGRIND_UNINITIALIZED). Each kernel
 * variant (lib/opencl/cl_variant.c: vertex blocks 4 and 16 wide, and the GPU's work-groups) runs in
 * a child process of its own, on a small noisy cylinder: the paper's filter, the bilateral normal
 * filter from lists and searching, every influence function, both predictors, the underflow rescue
 * with and without colour, the normal-update stage, the learned normals' networks. Each case must
 * agree with the double-precision reference path, Oclgrind must report nothing (OCLGRIND_LOG),
 * and every __kernel in kernels/ must have run (Oclgrind's
 * OCLGRIND_INST_COUNTS names each kernel it ran). Skipped (77) where Oclgrind's runtime library
 * is not installed (Debian's oclgrind package; RSMOOTH_TEST_OCLGRIND names another one), unless
 * RSMOOTH_REQUIRE_OPENCL=1.
 *
 * Oclgrind's own errors (21.10, Debian 12), each shown by a few lines; the kernels and the host
 * avoid what sets them off, at no cost, and the test works around the sixth:
 * 1. A buffer created with CL_MEM_USE_HOST_PTR counts as never written, so every read of it is
 *    "uninitialized": `__kernel void k(__global const uchar *in, __global int *out)
 *    { out[in[get_global_id(0)]] = 1; }` on a USE_HOST_PTR buffer of ones gives "Uninitialized
 *    address used to write to global memory address 0x1000000000004". rsmooth copies its
 *    inputs at creation on a device that does not share the host's memory (rs_cl_input_flags in
 *    cl_device.c), as Oclgrind's does not; PoCL's CPU device, which does, still reads them in
 *    place.
 * 2. A vector built from scalars and stored whole is written by LLVM as a vector with those
 *    lanes undefined, then lane by lane, and the first store is reported: `__local float4 s[64];
 *    s[l] = (float4)(p[3 * l], p[3 * l + 1], p[3 * l + 2], 0.0f);` in a kernel that then reads
 *    s[63 - l].x gives "Uninitialized value written to local memory address 0x1000000000000 ...
 *    store <4 x float> <float poison, float poison, float poison, float 0.000000e+00>". The
 *    kernels store such vectors with vstore4 (common.cl's DECLARE_STAGE, bilateral.cl).
 * 3. A shuffle with an undefined lane (a float3 in four lanes) crashes the uninitialised-value
 *    check (segmentation fault in Uninitialized::instructionExecuted): `float3 l = p[0].xyz; if
 *    (p[1].x > 0.0f) l = fmin(l, p[1].xyz); o[0] = (float4)(l, 0.0f);` (p, o: float4 buffers).
 *    The group variant forms its box in float4.
 * 4. A boolean vector chosen between an all-true constant and another is computed as all false
 *    (a wrong result, no report): `int4 c = p[0] <= r; if (flag) c = c && p[0] < 5.0f; o[0] =
 *    convert_int4(select((float4)0.0f, (float4)1.0f, c));` with p[0] = (1, 2, 3, 4), r = 2.5 and
 *    flag 0 gives 0 0 0 0 (PoCL: 1 1 0 0). The rescue's smallest_exponent (estimate.cl) used it,
 *    and left the block variant's rescue undone (0.35 mean edges off the reference here).
 * 5. A map for reading and writing (CL_MAP_READ | CL_MAP_WRITE) does not mark what the host
 *    wrote through it as defined: a count written so, then read by `for (uint i = 0; i < n[8];
 *    i++)`, gives "Controlflow depends on uninitialized value". The bilateral lists' offsets
 *    (cl_bilateral.c) are read and written back with clEnqueueReadBuffer / WriteBuffer.
 * 6. A buffer created in a released buffer's slot keeps what Oclgrind knew of the old one's
 *    contents, and its size: the kernels' writes past it are lost, and reading them is
 *    "uninitialized" (the same report, after a 4-byte buffer was written and released and a
 *    64-byte one filled by a kernel). Each case has a context of its own.
 * 7. A lane that a shuffle takes from element 11 of a vector counts as undefined (it seems to
 *    compare shuffle indices with an unrelated LLVM constant, and to read an index that is really
 *    undefined, -1, as an index: error 3): `float16 v = vload16(0, p); o[0] =
 *    convert_int4(v.sbbbb);` on a buffer of defined floats gives "Controlflow depends on
 *    uninitialized value" (v.saaaa and v.scccc do not). The 16-lane blocks' lane_min and lane_max
 *    (common.cl) split their vector through a private array.
 * Oclgrind also writes a context's log only when the context is released, over the last one, and
 * stops reporting after 1000 reports in a process (OCLGRIND_MAX_ERRORS). */
#define _POSIX_C_SOURCE 200809L
#include "mesh_shapes.h"
#include "rsmooth.h"
#include "test_model.h"
#include "test_util.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#ifndef RSMOOTH_KERNEL_SOURCE_DIR
#define RSMOOTH_KERNEL_SOURCE_DIR "kernels"
#endif

/* Oclgrind's float32 kernels against the double-precision reference, in mean edge lengths: a few
 * float ulps of the cell-local coordinates (PoCL's runs are held to 1e-3 by cl_vs_reference). */
#define MAX_DEVIATION 1e-5
#define MAX_CONFIDENCE_DIFF 1e-4

#define MAX_KERNELS 32

/* The whole of a (small) text file, or NULL. */
static char *read_file(const char *path) {
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    size_t size = 0, cap = 4096;
    char *text = malloc(cap);
    CHECK(text);
    for (size_t n; (n = fread(text + size, 1, cap - size - 1, f)) > 0;) {
        size += n;
        if (size + 1 == cap) {
            cap *= 2;
            text = realloc(text, cap);
            CHECK(text);
        }
    }
    fclose(f);
    text[size] = '\0';
    return text;
}

/* ---- What runs in the child: the cases, each against the reference path ---------------------- */

typedef struct test_mesh {
    shape_mesh shape;
    float *colors;
} test_mesh;

/* The kernel variants run, each in a child of its own: "cpu" (vertex blocks as wide as Oclgrind's
 * preferred vector width, 4), "cpu16" (blocks of 16, as on AVX-512, most of their lanes padding
 * here) and "gpu" (one vertex per work-item, work-groups staging facets in local memory). */
static const char *const variants[] = {"cpu", "cpu16", "gpu"};

/* RSMOOTH_KERNEL_VARIANT and RSMOOTH_LANES ("": the device's own width) for a variant. */
static const char *variant_kind(const char *variant) {
    return strncmp(variant, "gpu", 3) == 0 ? "gpu" : "cpu";
}
static const char *variant_lanes(const char *variant) {
    return variant + 3;
}

/* A context on Oclgrind's device, with the kernel variant that `variant` names. */
static rsmooth_context *oclgrind_context(const char *variant) {
    rsmooth_context *ctx = NULL;
    rsmooth_error err;
    rsmooth_status st = rsmooth_context_create(NULL, &ctx, &err);
    if (st != RSMOOTH_OK) {
        fprintf(stderr, "no context on Oclgrind: %s: %s\n%s\n", rsmooth_status_str(st), err.message,
                err.build_log);
        exit(1);
    }
    rsmooth_context_info info = {.struct_size = sizeof info};
    CHECK_STATUS(rsmooth_context_get_info(ctx, &info), RSMOOTH_OK);
    unsigned lanes = info.lanes;
    CHECK(strstr(info.device_name, "Oclgrind") != NULL);
    if (strcmp(variant_kind(variant), "gpu") == 0)
        CHECK_EQ_INT(lanes, 1);
    else if (*variant_lanes(variant))
        CHECK_EQ_INT(lanes, atoi(variant_lanes(variant)));
    else
        CHECK(lanes > 1);
    CHECK(strcmp(info.program_cache, "off") == 0); /* built from source */
    return ctx;
}

/* Cases whose context Oclgrind reported on. */
static int reported_cases = 0;

/* What Oclgrind wrote to `log` (OCLGRIND_LOG) for the context just destroyed, which closed it:
 * its first lines on standard output, all of it added to `kept`. */
static void take_reports(const char *name, const char *log, const char *kept) {
    char *text = read_file(log);
    if (!text || text[strspn(text, " \t\n")] == '\0') {
        free(text);
        return;
    }
    reported_cases++;
    printf("%s: Oclgrind reported (all of it in %s):\n", name, kept);
    const char *line = text + strspn(text, "\n");
    for (int shown = 0; *line && shown < 40; shown++) {
        size_t len = strcspn(line, "\n");
        printf("| %.*s\n", (int)len, line);
        line += len + (line[len] == '\n');
    }
    FILE *f = fopen(kept, "a");
    CHECK(f);
    fprintf(f, "==== %s\n%s", name, text);
    fclose(f);
    free(text);
}

/* Runs one case on both paths, with the confidence or without (two copies of robust_block's
 * loop), takes what Oclgrind reported, checks that the paths agree and returns the facets the
 * device's robust pass read. Each case has a context, and so a log, of its own: no case's
 * released buffers can then look uninitialised to the next (Oclgrind's error 6 above). */
static uint64_t run_case(const char *variant, const char *name, const test_mesh *m,
                         const rsmooth_params *p, bool confidence) {
    char log[64], kept[64];
    snprintf(log, sizeof log, "oclgrind-%s-case.log", variant);
    snprintf(kept, sizeof kept, "oclgrind-%s.log", variant);
    remove(log);
    setenv("OCLGRIND_LOG", log, 1); /* every diagnostic goes there */
    rsmooth_context *ctx = oclgrind_context(variant);
    size_t nv = m->shape.vertex_count, nt = m->shape.triangle_count;
    double *ref = malloc(3 * nv * sizeof *ref), *cl = malloc(3 * nv * sizeof *cl);
    float *ref_conf = malloc(nv * sizeof *ref_conf), *cl_conf = malloc(nv * sizeof *cl_conf);
    CHECK(ref && cl && ref_conf && cl_conf);
    rsmooth_report report, cl_report;
    rsmooth_report_init(&cl_report);
    rsmooth_error err;
    CHECK_STATUS(rsmooth_smooth(NULL, RSMOOTH_FLOAT64, m->shape.xyz, nv, m->shape.indices, nt, p,
                                ref, OUTPUTS(NULL, ref_conf, &report), &err),
                 RSMOOTH_OK);
    rsmooth_status st =
        rsmooth_smooth(ctx, RSMOOTH_FLOAT64, m->shape.xyz, nv, m->shape.indices, nt, p, cl,
                       OUTPUTS(NULL, confidence ? cl_conf : NULL, &cl_report), &err);
    rsmooth_context_destroy(ctx);
    take_reports(name, log, kept);
    if (st != RSMOOTH_OK)
        fprintf(stderr, "%s: %s: %s\n", name, rsmooth_status_str(st), err.message);
    CHECK_STATUS(st, RSMOOTH_OK);
    double max_dev = 0, max_conf = 0, moved = 0;
    for (size_t v = 0; v < nv; v++) {
        double d2 = 0, m2 = 0;
        for (int k = 0; k < 3; k++) {
            double d = cl[3 * v + k] - ref[3 * v + k], s = ref[3 * v + k] - m->shape.xyz[3 * v + k];
            d2 += d * d;
            m2 += s * s;
        }
        max_dev = fmax(max_dev, sqrt(d2) / report.mean_edge_length);
        moved = fmax(moved, sqrt(m2) / report.mean_edge_length);
        if (confidence)
            max_conf = fmax(max_conf, fabs((double)cl_conf[v] - ref_conf[v]));
    }
    printf("case %-44s moved up to %.3f, off the reference by %.2g, %llu pairs", name, moved,
           max_dev, (unsigned long long)cl_report.pairs_robust);
    if (confidence)
        printf(" (confidence %.2g)", max_conf);
    printf("\n");
    fflush(stdout);
    CHECK(moved > 1e-3); /* the filter did something to compare */
    CHECK_LE(max_dev, MAX_DEVIATION);
    CHECK_LE(max_conf, MAX_CONFIDENCE_DIFF);
    free(ref);
    free(cl);
    free(ref_conf);
    free(cl_conf);
    return cl_report.pairs_robust;
}

/* Defaults, but half the spatial width: the searches reach 2 mean edges, a quarter of the
 * mesh's length, and skip the cells beyond. */
static void case_params(rsmooth_params *p) {
    rsmooth_params_init(p);
    p->sigma_f = 1;
}

/* The cases: together they launch every kernel, and robust_block with every combination of
 * flags it has a copy of its loop for (kernels/estimate.cl). */
static void run_cases(const char *variant, const test_mesh *m) {
    rsmooth_params p;
    case_params(&p);
    run_case(variant, "paper filter (mollified normals)", m, &p, true);
    p.normal_filter = RSMOOTH_NORMALS_BILATERAL;
    p.normal_iterations = 2;
    run_case(variant, "bilateral normals, 2 rounds from lists", m, &p, false);
    p.normal_sigma_n = 0.1; /* narrow: the rounds' difference form */
    run_case(variant, "bilateral normals, narrow, from lists", m, &p, false);
    case_params(&p);
    p.normal_filter = RSMOOTH_NORMALS_BILATERAL;
    p.normal_iterations = 1; /* one round searches instead */
    run_case(variant, "bilateral normals, 1 round searching", m, &p, false);
    case_params(&p);
    p.mollify = 0;
    p.influence = RSMOOTH_INFLUENCE_TUKEY;
    uint64_t pairs = run_case(variant, "Tukey, input normals", m, &p, true);
    p.influence = RSMOOTH_INFLUENCE_LORENTZIAN;
    run_case(variant, "Lorentzian, input normals", m, &p, true);
    p.influence = RSMOOTH_INFLUENCE_HUBER;
    run_case(variant, "Huber, input normals", m, &p, true);
    p.predictor = RSMOOTH_PREDICT_CENTROID;
    run_case(variant, "Huber, centroid predictor", m, &p, true);
    case_params(&p);
    p.mollify = 0;
    p.predictor = RSMOOTH_PREDICT_CENTROID;
    p.sigma_g = INFINITY;
    run_case(variant, "isotropic Gaussian (centroids)", m, &p, true);
    /* The rescues read more facets than Tukey's pass (which has none) over the same reach: the
     * facets of their second sums. */
    case_params(&p);
    p.sigma_g = 0.01; /* a vertex off every mollified plane: its weights all underflow float32 */
    CHECK(run_case(variant, "narrow influence: the rescue", m, &p, true) > pairs);
    case_params(&p);
    p.mollify = 0;
    p.colors = m->colors;
    p.sigma_c = 0.02; /* colours 1 apart: the colour factor underflows float32 */
    CHECK(run_case(variant, "colour factor: the rescue with colour", m, &p, true) > pairs);
    /* the best mode's normal-update stage on the device (stage.cl), both precisions, alone:
     * with the robust pass after it in the same call, Oclgrind 21.10's uninitialised-value
     * checker flags the bilateral lists' rows wherever their buffers reuse the addresses of the
     * stage's freed ones (with the stage's buffers kept alive it reports nothing, and so it does
     * for the same pass after the host's stage) */
    rsmooth_params_init_best(&p);
    p.passes = 0;
    p.stage_repeats = 2;
    p.vertex_updates = 2;
    p.guided_rounds = 2;
    setenv("RSMOOTH_STAGE", "device", 1);
    run_case(variant, "normal-update stage, double", m, &p, true);
    setenv("RSMOOTH_STAGE_PRECISION", "float", 1);
    run_case(variant, "normal-update stage, float", m, &p, true);
    unsetenv("RSMOOTH_STAGE_PRECISION");
    unsetenv("RSMOOTH_STAGE");
    /* the learned stage: its networks on the device (learned.cl), the cycles on the host; a
     * small random model (the built-in one's weights may be all 0), its widths not multiples of
     * the CPU kernel's 8 lanes or 4 rows, so that their tails run too */
    static const uint32_t hidden[] = {13, 6};
    model_bytes model = random_model(2, hidden, 2, 5);
    p.stage_normals = RSMOOTH_STAGE_NORMALS_LEARNED;
    p.model = model.at;
    p.model_size = model.size;
    run_case(variant, "learned normals (networks on the device)", m, &p, true);
    free(model.at);
}

/* The child's work for one variant: its output goes to the parent's file. Fails when a case
 * fails or Oclgrind reported on one. */
static int run_variant(const char *variant, const char *runtime) {
    setenv("RSMOOTH_OPENCL_LIBRARY", runtime, 1);
    setenv("RSMOOTH_KERNEL_VARIANT", variant_kind(variant), 1);
    if (*variant_lanes(variant))
        setenv("RSMOOTH_LANES", variant_lanes(variant), 1);
    else
        unsetenv("RSMOOTH_LANES");
    unsetenv("RSMOOTH_DEVICE");            /* Oclgrind's is the only device */
    unsetenv("RSMOOTH_MEMORY_BUDGET");     /* one run per case: no tiles */
    setenv("RSMOOTH_CACHE_DIR", "off", 1); /* every run compiles the source through Oclgrind */
    setenv("OCLGRIND_CHECK_API", "1", 1);
    setenv("OCLGRIND_DATA_RACES", "1", 1);
    setenv("OCLGRIND_UNINITIALIZED", "1", 1);
    setenv("OCLGRIND_INST_COUNTS", "1", 1); /* names each kernel it ran, on standard output */
    /* work-groups of 16 (the device's largest), so that the group variant's few vertices fill
     * several, each staging facets in several rounds */
    setenv("OCLGRIND_MAX_WGSIZE", "16", 1);

    /* A capped cylinder of 62 vertices and 120 triangles, 8 mean edges long, along x: the
     * searches, 2 mean edges wide (case_params), skip the columns of cells beyond */
    test_mesh m;
    CHECK(shape_capped_cylinder(&m.shape, 0.5, 4.0, 120) == 0);
    for (size_t v = 0; v < m.shape.vertex_count; v++) { /* (x, y, z) <- (z, x, y) */
        double *p = m.shape.xyz + 3 * v, z = p[2];
        p[2] = p[1];
        p[1] = p[0];
        p[0] = z;
    }
    CHECK(shape_add_normal_noise(&m.shape, 0.3, 5) == 0);
    m.colors = malloc(3 * m.shape.vertex_count * sizeof *m.colors);
    CHECK(m.colors);
    for (size_t v = 0; v < m.shape.vertex_count; v++) /* one of the 8 corners of the RGB cube */
        for (int k = 0; k < 3; k++)
            m.colors[3 * v + k] = (float)((v * 2654435761u >> (k + 7)) & 1);

    setenv("OCLGRIND_LOG", "/dev/null", 1); /* this context runs nothing */
    rsmooth_context *ctx = oclgrind_context(variant);
    rsmooth_context_info info = {.struct_size = sizeof info};
    CHECK_STATUS(rsmooth_context_get_info(ctx, &info), RSMOOTH_OK);
    printf("case device %s, %u lanes, work-groups of %zu, kernels built from source\n",
           info.device_name, info.lanes, info.group);
    fflush(stdout);
    rsmooth_context_destroy(ctx);
    run_cases(variant, &m);
    shape_free(&m.shape);
    free(m.colors);
    if (reported_cases > 0)
        printf("Oclgrind reported on %d cases\n", reported_cases);
    return reported_cases > 0;
}

/* ---- The parent: each variant in a child, then what it printed ------------------------------- */

/* The names after `marker` up to the next `end` in `text`, each once, added to names[]. */
static size_t collect_names(const char *text, const char *marker, char end, char names[][64],
                            size_t count) {
    for (const char *at = text; (at = strstr(at, marker)) != NULL;) {
        at += strlen(marker);
        size_t len = strcspn(at, (char[]){end, '\n', '\0'});
        if (len == 0 || len >= 64)
            continue;
        bool known = false;
        for (size_t i = 0; i < count && !known; i++)
            known = strlen(names[i]) == len && strncmp(names[i], at, len) == 0;
        if (!known && count < MAX_KERNELS) {
            memcpy(names[count], at, len);
            names[count++][len] = '\0';
        }
    }
    return count;
}

/* Every __kernel the sources define. */
static size_t source_kernels(char names[][64]) {
    static const char *const files[] = {"common.cl", "mollify.cl", "bilateral.cl", "estimate.cl",
                                        "stage.cl",  "grid.cl",    "learned.cl"};
    size_t count = 0;
    for (size_t i = 0; i < sizeof files / sizeof *files; i++) {
        char path[4096];
        snprintf(path, sizeof path, "%s/%s", RSMOOTH_KERNEL_SOURCE_DIR, files[i]);
        char *text = read_file(path);
        if (!text) {
            fprintf(stderr, "cannot read %s\n", path);
            exit(1);
        }
        count = collect_names(text, "__kernel void ", '(', names, count);
        /* stage.cl's kernels are named through STAGE_NAME, once per precision */
        char staged[MAX_KERNELS][64];
        size_t stage_count = collect_names(text, "__kernel void STAGE_NAME(", ')', staged, 0);
        for (size_t k = 0; k < stage_count; k++)
            for (int precision = 0; precision < 2 && count < MAX_KERNELS; precision++)
                snprintf(names[count++], 64, "%.60s_%c", staged[k], precision ? 'd' : 'f');
        free(text);
    }
    size_t kept = 0; /* without the macro's own name */
    for (size_t k = 0; k < count; k++)
        if (strcmp(names[k], "STAGE_NAME") != 0)
            memmove(names[kept++], names[k], 64);
    return kept;
}

/* Runs `variant` in a child; prints its cases, checks that it passed (so that Oclgrind reported
 * nothing) and that every kernel in `kernels` ran. Returns whether all did. */
static bool check_variant(const char *variant, const char *runtime, char kernels[][64],
                          size_t kernel_count) {
    char out_path[64], log_path[64];
    snprintf(out_path, sizeof out_path, "oclgrind-%s.out", variant);
    snprintf(log_path, sizeof log_path, "oclgrind-%s.log", variant);
    remove(log_path); /* the cases' reports, if any */
    fflush(stdout);
    pid_t pid = fork();
    CHECK(pid >= 0);
    if (pid == 0) {
        int fd = open(out_path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (fd < 0 || dup2(fd, 1) < 0 || dup2(fd, 2) < 0)
            _exit(1);
        close(fd);
        exit(run_variant(variant, runtime)); /* exit: LeakSanitizer checks the child too */
    }
    int status = 0;
    while (waitpid(pid, &status, 0) < 0)
        CHECK(errno == EINTR);
    char *out = read_file(out_path);
    CHECK(out);
    printf("%s variant:\n", variant);
    for (const char *line = out; *line;) { /* the cases' lines, reports and the child's errors */
        size_t len = strcspn(line, "\n");
        bool is_case = strncmp(line, "case ", 5) == 0;
        if (is_case || (len > 0 && line[0] != ' ' && strncmp(line, "Instructions", 12) != 0))
            printf("  %.*s\n", (int)(len - (is_case ? 5 : 0)), line + (is_case ? 5 : 0));
        line += len + (line[len] == '\n');
    }
    bool failed = false;
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        if (WIFSIGNALED(status))
            printf("  the %s variant's run died of signal %d (output: %s)\n", variant,
                   WTERMSIG(status), out_path);
        else
            printf("  the %s variant's run failed (output: %s)\n", variant, out_path);
        failed = true;
    }
    char ran[MAX_KERNELS][64];
    size_t ran_count = collect_names(out, "Instructions executed for kernel '", '\'', ran, 0);
    for (size_t k = 0; k < kernel_count; k++) {
        bool found = false;
        for (size_t r = 0; r < ran_count && !found; r++)
            found = strcmp(kernels[k], ran[r]) == 0;
        if (!found) {
            printf("  kernel %s never ran\n", kernels[k]);
            failed = true;
        }
    }
    printf("  %zu kernels ran, all cases passed, Oclgrind reported nothing: %s\n", ran_count,
           failed ? "NO" : "yes");
    free(out);
    return !failed;
}

#if defined(__SANITIZE_ADDRESS__)
/* The sanitizer build runs this test too: it is the only one where the library's host code takes
 * the path of a device that does not share the host's memory (inputs copied, list offsets read and
 * written back). Oclgrind's instruction counter never frees what it records per work-group. */
__attribute__((visibility("default"))) const char *__lsan_default_suppressions(void);
const char *__lsan_default_suppressions(void) {
    return "leak:liboclgrind\n";
}
#endif

static const char *find_runtime(void) {
    const char *chosen = getenv("RSMOOTH_TEST_OCLGRIND");
    if (chosen && *chosen)
        return chosen;
    static const char *const places[] = {"/usr/lib/oclgrind/liboclgrind-rt.so", /* Debian, Ubuntu */
                                         "/usr/local/lib/liboclgrind-rt.so", /* built from source */
                                         "/usr/lib64/liboclgrind-rt.so",
                                         "/usr/lib/liboclgrind-rt.so"};
    for (size_t i = 0; i < sizeof places / sizeof *places; i++)
        if (access(places[i], R_OK) == 0)
            return places[i];
    return NULL;
}

int main(void) {
    const char *runtime = find_runtime();
    if (!runtime) {
        /* CI sets RSMOOTH_REQUIRE_OPENCL=1 and installs it (.ci/install-deps.sh): a missing
         * simulator must not pass as green there */
        const char *require = getenv("RSMOOTH_REQUIRE_OPENCL");
        bool required = require && strcmp(require, "1") == 0;
        printf("%s: Oclgrind's runtime library liboclgrind-rt.so is not installed (Debian: "
               "apt-get install oclgrind; or name it in RSMOOTH_TEST_OCLGRIND)%s\n",
               required ? "failing" : "skipping", required ? ", and RSMOOTH_REQUIRE_OPENCL=1" : "");
        return required ? 1 : TEST_SKIP;
    }
    printf("Oclgrind: %s\n", runtime);
    char kernels[MAX_KERNELS][64];
    size_t kernel_count = source_kernels(kernels);
    CHECK(kernel_count >= 7);
    printf("kernels in %s:", RSMOOTH_KERNEL_SOURCE_DIR);
    for (size_t k = 0; k < kernel_count; k++)
        printf(" %s", kernels[k]);
    printf("\n");
    bool passed = true;
    for (size_t v = 0; v < sizeof variants / sizeof *variants; v++)
        passed = check_variant(variants[v], runtime, kernels, kernel_count) && passed;
    printf("%s\n", passed ? "ok" : "FAILED");
    return passed ? 0 : 1;
}
