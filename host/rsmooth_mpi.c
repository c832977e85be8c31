/* rsmooth-mpi: the streaming filter (rsmooth --max-memory) with its pieces shared among MPI
 * ranks, each on its own device, all writing their vertices' rows into one output file.
 *
 *     mpirun -n N rsmooth-mpi IN.ply -o OUT.ply [--max-memory SIZE] [--device D] [options]
 *
 * Every rank reads the input (a shared file system), computes the same plan, and filters the
 * pieces the plan gives it (by facet count, the largest first to the least loaded rank); rank 0
 * makes the output's copy and names it when every rank is done. The result is the single-process
 * streaming result, bit for bit: the same pieces, filtered by the same code. "%l" in --device is
 * replaced by the rank's index on its node (e.g. --device 0:%l, one GPU per local rank).
 *
 * Before any work the ranks compare digests of what they were given (mpi_agree.c): a rank with
 * another input, other parameters, another cap or another output would write garbage into the
 * shared file, so the run is refused, naming the rank. */
#define _POSIX_C_SOURCE 200809L
#include "cli_args.h"
#include "cli_device.h"
#include "cli_files.h"
#include "cli_options.h"
#include "cli_stream.h"
#include "mpi_agree.h"
#include "rsmooth_io.h"

#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define DEFAULT_MAX_MEMORY (1ull << 30)

/* rsmooth_stream_options.sync: every rank's worst status. */
static int all_reduce(void *user, int status) {
    (void)user;
    int worst = status;
    MPI_Allreduce(&status, &worst, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    return worst;
}

static int worst_code(int code) {
    int worst = code;
    MPI_Allreduce(&code, &worst, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    return worst;
}

/* --device with "%l" replaced by the local rank. */
static const char *device_for_rank(const char *device, int local_rank, char *buf, size_t size) {
    const char *mark = device ? strstr(device, "%l") : NULL;
    if (!mark)
        return device;
    snprintf(buf, size, "%.*s%d%s", (int)(mark - device), device, local_rank, mark + 2);
    return buf;
}

/* The host stages' threads (reading, statistics, cutting, each piece's host work): the node's
 * cores shared among the ranks on it, unless RSMOOTH_HOST_THREADS says otherwise; every rank on
 * every core would run the node's cores times over. */
static void share_cores(int local_ranks) {
    if (getenv("RSMOOTH_HOST_THREADS") || local_ranks < 1)
        return;
    long cores = sysconf(_SC_NPROCESSORS_ONLN), share = cores / local_ranks;
    char threads[24];
    snprintf(threads, sizeof threads, "%ld", share < 1 ? 1 : share);
    setenv("RSMOOTH_HOST_THREADS", threads, 1);
}

/* What every rank finds alike (a usage error, --help, a bad --mask) printed once: the other
 * ranks' standard error and output go to /dev/null until speak_again. */
static void quiet_others(int rank, int saved[2]) {
    saved[0] = saved[1] = -1;
    if (rank == 0)
        return;
    fflush(stderr);
    fflush(stdout);
    saved[0] = dup(STDERR_FILENO);
    saved[1] = dup(STDOUT_FILENO);
    FILE *null = fopen("/dev/null", "w");
    if (null) {
        dup2(fileno(null), STDERR_FILENO);
        dup2(fileno(null), STDOUT_FILENO);
        fclose(null);
    }
}

static void speak_again(int saved[2]) {
    if (saved[0] < 0)
        return;
    fflush(stderr);
    fflush(stdout);
    dup2(saved[0], STDERR_FILENO);
    dup2(saved[1], STDOUT_FILENO);
    close(saved[0]);
    close(saved[1]);
}

/* Parses the command line (only rank 0 prints what is wrong with it). */
static int parse(int argc, char **argv, int rank, options *opt) {
    int saved[2];
    quiet_others(rank, saved);
    for (int i = 1; i < argc && strcmp(argv[i], "--") != 0; i++)
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            printf(
                "usage: mpirun -n N rsmooth-mpi IN.ply -o OUT.ply [options]\n\n"
                "rsmooth --max-memory (a binary PLY streamed in pieces) with the pieces shared\n"
                "among MPI ranks: every rank reads the input (a shared file system), makes the\n"
                "same plan and filters its share on its own device; the output is the single\n"
                "process's byte for byte. --max-memory is each rank's cap (default 1G); '%%l' in\n"
                "--device is the rank's index on its node (--device 0:%%l: one GPU per rank).\n"
                "Each rank's host threads are its share of the node's cores\n"
                "(RSMOOTH_HOST_THREADS, if set, instead).\n"
                "The options are rsmooth's:\n\n");
            break;
        }
    int code = cli_options_parse(argc, argv, opt);
    if (code < 0 && (opt->input_count != 1 || !(opt->output_option || opt->in_place) ||
                     opt->output_dir || opt->suffix || opt->list_devices)) {
        code = cli_usage_error(NULL, "rsmooth-mpi smooths one input into one output: "
                                     "rsmooth-mpi IN.ply -o OUT.ply (or --in-place) [options]");
        cli_options_free(opt);
    }
    if (code < 0 && !opt->max_memory) {
        opt->max_memory = DEFAULT_MAX_MEMORY; /* each rank streams: the cap always holds */
        code = cli_stream_check(opt);
        if (code >= 0)
            cli_options_free(opt);
    }
    speak_again(saved);
    return code;
}

int main(int argc, char **argv) {
    MPI_Init(&argc, &argv);
    int rank = 0, ranks = 1, local_rank = 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &ranks);
    MPI_Comm node;
    MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, rank, MPI_INFO_NULL, &node);
    MPI_Comm_rank(node, &local_rank);
    int local_ranks = 1;
    MPI_Comm_size(node, &local_ranks);
    MPI_Comm_free(&node);
    share_cores(local_ranks);

    options opt;
    int code = parse(argc, argv, rank, &opt);
    if (code >= 0) { /* --help, --version or a usage error: the same on every rank */
        MPI_Finalize();
        return code;
    }
    opt.input = opt.inputs[0];
    opt.output = opt.output_option;
    if (opt.in_place)
        opt.output = opt.input;
    code = -1;
    if (rank == 0)
        code = cli_check_output(opt.output, opt.input, opt.force, opt.in_place,
                                opt.format != RSMOOTH_FORMAT_AUTO);
    MPI_Bcast(&code, 1, MPI_INT, 0, MPI_COMM_WORLD);
    if (code < 0)
        code = mpi_agree(&opt, rank, ranks);
    if (code >= 0) {
        cli_options_free(&opt);
        MPI_Finalize();
        return code;
    }
    char device[256];
    opt.device = device_for_rank(opt.device ? opt.device : getenv("RSMOOTH_DEVICE"), local_rank,
                                 device, sizeof device);
    bool quiet = opt.quiet;
    if (rank != 0)
        opt.quiet = true; /* one warning about a missing device, not one per rank */
    cli_progress bar;
    cli_progress_init(&bar, true, false);
    rsmooth_context *ctx = NULL;
    double ms_setup = 0;
    code = worst_code(cli_open_device(&opt, &bar, &ctx, &ms_setup));
    uint8_t *mask = NULL; /* every rank reads --mask (the same file: mpi_agree) */
    if (code < 0) {
        int saved[2];
        quiet_others(rank, saved);
        code = worst_code(cli_stream_mask(&opt, opt.input, &mask));
        speak_again(saved);
    }
    opt.params.move_mask = mask;
    if (code >= 0) {
        free(mask);
        rsmooth_context_destroy(ctx);
        cli_options_free(&opt);
        MPI_Finalize();
        return code;
    }
    rsmooth_stream_options so;
    rsmooth_stream_options_init(&so);
    so.max_memory = opt.max_memory;
    so.tmpdir = opt.tmpdir;
    so.replace = opt.force || opt.in_place;
    so.rank = rank;
    so.ranks = ranks;
    so.sync = all_reduce;
    rsmooth_stream_report rep;
    rsmooth_stream_report_init(&rep);
    rsmooth_error err;
    rsmooth_status st =
        rsmooth_stream_smooth(ctx, opt.input, opt.output, &opt.params, &so, &rep, &err);
    /* a rank that failed says why; the others only that they stopped with it */
    bool own = st != RSMOOTH_OK && strstr(err.message, "another rank failed") == NULL;
    char program[48];
    snprintf(program, sizeof program, "rsmooth-mpi: rank %d", rank);
    if (own)
        cli_stream_print_error(program, err.message);
    code = st == RSMOOTH_OK ? EXIT_OK : cli_stream_exit_code(st);
    if (st == RSMOOTH_OK && !quiet)
        fprintf(stderr,
                "rsmooth-mpi: rank %d of %d on %s: %zu pieces, %llu facets with halos, "
                "%.1f MB of the input read; assemble %.1f s, filter %.1f s, write %.1f s\n",
                rank, ranks, rep.device[0] ? rep.device : "no device (no pieces)", rep.pieces_here,
                (unsigned long long)rep.facets_filtered, (double)rep.input_bytes_read / 1e6,
                rep.ms_assemble / 1000, rep.ms_filter / 1000, rep.ms_write / 1000);
    MPI_Barrier(MPI_COMM_WORLD); /* the ranks' lines before the summary */
    if (st == RSMOOTH_OK && rank == 0) {
        if (rep.notes[0] && !quiet)
            fprintf(stderr, "rsmooth-mpi: %s: warning: %s\n", opt.output, rep.notes);
        if (opt.json)
            cli_stream_print_json(&rep, &opt, ranks);
        if (!quiet)
            fprintf(stderr,
                    "rsmooth-mpi: %s: %llu vertices, %llu triangles, mean edge %.6g; %zu pieces "
                    "over %d ranks under --max-memory %llu MB each: read %.1f s, statistics "
                    "%.1f s, cut %.1f s, copy %.1f s, total %.1f s; wrote %s\n",
                    opt.input, (unsigned long long)rep.vertex_count,
                    (unsigned long long)rep.triangle_count, rep.mean_edge_length, rep.pieces, ranks,
                    (unsigned long long)(opt.max_memory >> 20), rep.ms_read / 1000,
                    rep.ms_statistics / 1000, rep.ms_buckets / 1000, rep.ms_copy / 1000,
                    rep.ms_total / 1000, opt.output);
    }
    rsmooth_context_destroy(ctx);
    cli_options_free(&opt);
    MPI_Finalize();
    return code;
}
