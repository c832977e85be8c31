/* The rsmooth command under --max-memory (see cli_stream.h). */
#include "cli_stream.h"
#include "cli_args.h"
#include "cli_device.h"
#include "cli_files.h"
#include "cli_mask.h"
#include "cli_progress.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The option that needs the whole mesh in memory, or NULL. */
static const char *whole_mesh_option(const options *opt) {
    const rsmooth_params *p = &opt->params;
    return opt->auto_params ? "--auto"
           : p->stage_normals == RSMOOTH_STAGE_NORMALS_LEARNED && p->vertex_updates > 0
               ? "--stage learned"
           : opt->colors                        ? "--sigma-c"
           : opt->confidence                    ? "--confidence"
           : opt->stats                         ? "--stats"
           : cli_method_uses_edges(opt->method) ? "--method"
                                                : NULL;
}

int cli_stream_check(const options *opt) {
    if (!opt->max_memory) {
        if (opt->tmpdir)
            return cli_usage_error(NULL, "--tmpdir holds --max-memory's temporary files: give "
                                         "--max-memory too");
        return -1;
    }
    const char *option = whole_mesh_option(opt);
    if (option)
        return cli_usage_error(NULL,
                               "--max-memory filters each piece of the mesh from the "
                               "pieces around it, pass by pass: %s needs the whole mesh in "
                               "memory (drop one of them)",
                               option);
    bool std_stream = opt->output_option && !strcmp(opt->output_option, "-");
    for (size_t i = 0; i < opt->input_count; i++)
        std_stream = std_stream || !strcmp(opt->inputs[i], "-");
    if (std_stream)
        return cli_usage_error(NULL, "--max-memory reads its input several times and writes "
                                     "its output in place: give files, not '-'");
    if (opt->ascii ||
        (opt->format != RSMOOTH_FORMAT_AUTO && opt->format != RSMOOTH_FORMAT_PLY_BINARY))
        return cli_usage_error(NULL, "--max-memory writes the input's own binary PLY: drop "
                                     "--ascii and --format");
    if (opt->params.guard && !opt->quiet) /* (what the pieces cannot do yet, said once) */
        fprintf(stderr,
                "rsmooth: --max-memory: the fold guard does not run on pieces yet: the "
                "result is the in-memory one with --no-guard (triangles the filter turns "
                "over are not pulled back%s)\n",
                opt->params.vertex_updates > 0
                    ? ", nor is the stage skipped on a mesh that reads clean"
                    : "");
    return -1;
}

int cli_stream_exit_code(rsmooth_status st) {
    switch (st) {
    case RSMOOTH_ERROR_INVALID_ARGUMENT:
    case RSMOOTH_ERROR_UNSUPPORTED:
    case RSMOOTH_ERROR_PARSE:
    case RSMOOTH_ERROR_IO:
        return EXIT_USAGE;
    case RSMOOTH_ERROR_OPENCL:
    case RSMOOTH_ERROR_KERNEL_BUILD:
        return EXIT_DEVICE;
    default:
        return EXIT_OTHER;
    }
}

void cli_stream_print_error(const char *program, const char *message) {
    static const char library_hint[] = "set options->replace";
    const char *hint = strstr(message, library_hint);
    if (hint)
        fprintf(stderr, "%s: %.*suse --force%s\n", program, (int)(hint - message), message,
                hint + sizeof library_hint - 1);
    else
        fprintf(stderr, "%s: %s\n", program, message);
}

void cli_stream_print_json(const rsmooth_stream_report *r, const options *opt, int ranks) {
    printf("{\"input\":");
    cli_print_json_string(opt->input);
    printf(",\"output\":");
    cli_print_json_string(opt->output);
    printf(",\"streamed\":true,\"ranks\":%d,\"max_memory\":%llu,\"memory_planned\":%llu", ranks,
           (unsigned long long)opt->max_memory, (unsigned long long)r->memory_planned);
    printf(",\"vertex_count\":%llu,\"face_count\":%llu,\"triangle_count\":%llu,"
           "\"facet_count\":%llu,\"mean_edge_length\":%.17g,\"halo\":%.17g",
           (unsigned long long)r->vertex_count, (unsigned long long)r->face_count,
           (unsigned long long)r->triangle_count, (unsigned long long)r->facet_count,
           r->mean_edge_length, r->halo);
    printf(",\"stage_cycles\":%d,\"passes\":%d,\"pieces\":%zu,\"pieces_here\":%zu,\"piece_facets_"
           "max\":%llu,"
           "\"facets_filtered\":%llu,\"temporary_bytes\":%llu,\"position_runs\":%llu,"
           "\"input_bytes_read\":%llu,\"device\":",
           r->stage_cycles, r->passes, r->pieces, r->pieces_here,
           (unsigned long long)r->piece_facets_max, (unsigned long long)r->facets_filtered,
           (unsigned long long)r->temporary_bytes, (unsigned long long)r->position_runs,
           (unsigned long long)r->input_bytes_read);
    cli_print_json_string(r->device);
    printf(",\"ms\":{\"read\":%.3f,\"statistics\":%.3f,\"cut\":%.3f,\"copy\":%.3f,"
           "\"assemble\":%.3f,\"filter\":%.3f,\"write\":%.3f,\"total\":%.3f}}\n",
           r->ms_read, r->ms_statistics, r->ms_buckets, r->ms_copy, r->ms_assemble, r->ms_filter,
           r->ms_write, r->ms_total);
}

int cli_stream_mask(const options *opt, const char *path, uint8_t **mask) {
    *mask = NULL;
    if (!opt->mask)
        return -1;
    uint64_t vertex_count = 0;
    rsmooth_error err;
    rsmooth_status st = rsmooth_stream_vertex_count(path, &vertex_count, &err);
    if (st != RSMOOTH_OK) {
        cli_stream_print_error("rsmooth", err.message);
        return cli_stream_exit_code(st);
    }
    if (vertex_count > SIZE_MAX) {
        fprintf(stderr, "rsmooth: %s: %llu vertices: too many for a --mask on this machine\n", path,
                (unsigned long long)vertex_count);
        return EXIT_USAGE;
    }
    int code = cli_read_mask(opt->mask, (size_t)vertex_count, path, mask);
    return code == EXIT_OK ? -1 : code;
}

int cli_stream_file(const options *opt, const char *path) {
    if (cli_result_format(opt, opt->output, RSMOOTH_FORMAT_PLY_BINARY) !=
        RSMOOTH_FORMAT_PLY_BINARY) {
        fprintf(stderr,
                "rsmooth: %s: --max-memory writes the input's own binary PLY: name the "
                "output .ply\n",
                opt->output);
        return EXIT_USAGE;
    }
    uint8_t *mask = NULL; /* one byte a vertex, as in memory */
    int code = cli_stream_mask(opt, path, &mask);
    if (code >= 0)
        return code;
    cli_progress bar;
    cli_progress_init(&bar, opt->quiet, opt->progress);
    cli_progress_stage(&bar, "streaming", 0, 1);
    rsmooth_context *ctx = NULL;
    double ms_setup = 0;
    code = cli_open_device(opt, &bar, &ctx, &ms_setup);
    if (code >= 0) {
        free(mask);
        return code;
    }
    rsmooth_stream_options so;
    rsmooth_stream_options_init(&so);
    so.max_memory = opt->max_memory;
    so.tmpdir = opt->tmpdir;
    so.replace = opt->force || opt->in_place;
    rsmooth_params params = opt->params;
    params.move_mask = mask;
    if (bar.enabled) {
        params.progress = cli_progress_callback;
        params.progress_user = &bar;
    }
    rsmooth_stream_report rep;
    rsmooth_stream_report_init(&rep);
    rsmooth_error err;
    rsmooth_status st = rsmooth_stream_smooth(ctx, path, opt->output, &params, &so, &rep, &err);
    free(mask);
    if (st == RSMOOTH_OK)
        cli_progress_done(&bar);
    cli_progress_clear(&bar);
    rsmooth_context_destroy(ctx);
    if (st != RSMOOTH_OK) {
        cli_stream_print_error("rsmooth", err.message);
        return cli_stream_exit_code(st);
    }
    if (rep.notes[0] && !opt->quiet)
        fprintf(stderr, "rsmooth: %s: warning: %s\n", opt->output, rep.notes);
    if (opt->json)
        cli_stream_print_json(&rep, opt, 1);
    char passes[80] = ""; /* "10 stage cycles and 1 pass, " */
    if (rep.stage_cycles > 0)
        snprintf(passes, sizeof passes, "%d stage cycles and %d pass%s, ", rep.stage_cycles,
                 rep.passes, rep.passes == 1 ? "" : "es");
    else if (rep.passes != 1)
        snprintf(passes, sizeof passes, "%d passes, ", rep.passes);
    if (!opt->quiet)
        fprintf(stderr,
                "rsmooth: %s: %llu vertices, %llu triangles, mean edge %.6g; streamed in %s%zu "
                "piece%s (the largest %llu facets with its halo) under --max-memory %llu MB on "
                "%s: read %.1f s, statistics %.1f s, cut %.1f s, copy %.1f s, assemble %.1f s, "
                "filter %.1f s, write %.1f s; wrote %s\n",
                opt->input, (unsigned long long)rep.vertex_count,
                (unsigned long long)rep.triangle_count, rep.mean_edge_length, passes, rep.pieces,
                rep.pieces == 1 ? "" : "s", (unsigned long long)rep.piece_facets_max,
                (unsigned long long)(opt->max_memory >> 20),
                rep.device[0] ? rep.device : "no device (no facets)", rep.ms_read / 1000,
                rep.ms_statistics / 1000, rep.ms_buckets / 1000, rep.ms_copy / 1000,
                rep.ms_assemble / 1000, rep.ms_filter / 1000, rep.ms_write / 1000, opt->output);
    return EXIT_OK;
}
