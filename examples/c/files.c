/* Files through rsmooth-io (rsmooth_io.h, target rsmooth::io): reads a mesh file (OBJ, PLY, OFF
 * or STL, told by its content), smooths it with the paper's filter and writes it in the format
 * the output's extension names, keeping what the input held besides positions (PLY properties,
 * comments, OBJ groups...) when the format is the same. The output is the rsmooth command's
 * byte for byte: `rsmooth IN -o OUT --device DEVICE` writes the same file.
 *
 *     example_files IN OUT [DEVICE]     (DEVICE: reference (default), auto, cpu, gpu, P:D...)
 *
 * Exit status 77: the device asked for does not exist (no OpenCL platform, or none matches). */
#include <rsmooth_io.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int main(int argc, char **argv) {
    if (argc < 3 || argc > 4) {
        fprintf(stderr, "usage: example_files IN OUT [DEVICE]\n");
        return 2;
    }
    const char *device = argc == 4 ? argv[3] : "reference";
    rsmooth_error err;
    rsmooth_error_init(&err);
    rsmooth_mesh *mesh = NULL;
    rsmooth_context *ctx = NULL;
    double *out = NULL;
    int code = EXIT_FAILURE;
    const char *what = argv[1];

    rsmooth_status st = rsmooth_mesh_read_file(argv[1], &mesh, &err);
    if (st == RSMOOTH_OK && strcmp(device, "reference") != 0) {
        what = device;
        rsmooth_context_options options = {.struct_size = sizeof options, .device = device};
        st = rsmooth_context_create(&options, &ctx, &err);
        if (st == RSMOOTH_ERROR_NO_DEVICE)
            code = 77;
    }
    if (st == RSMOOTH_OK) {
        rsmooth_context_info info = {.struct_size = sizeof info, .device_name = "reference"};
        if (ctx)
            rsmooth_context_get_info(ctx, &info);
        printf("%s: %zu vertices, %zu triangles; device %s\n", argv[1], mesh->vertex_count,
               mesh->triangle_count, info.device_name);
        out = malloc(3 * mesh->vertex_count * sizeof *out);
        if (!out)
            goto done;
        rsmooth_params params;
        rsmooth_params_init(&params); /* sigma_f 2, sigma_g 0.5 mean edge lengths */
        /* The file's positions are doubles whatever it stored (mesh->precision says what). */
        what = argv[1];
        st = ctx ? rsmooth_smooth(ctx, RSMOOTH_FLOAT64, mesh->positions, mesh->vertex_count,
                                  mesh->triangles, mesh->triangle_count, &params, out, NULL, &err)
                 : rsmooth_smooth(NULL, RSMOOTH_FLOAT64, mesh->positions, mesh->vertex_count,
                                  mesh->triangles, mesh->triangle_count, &params, out, NULL, &err);
    }
    if (st == RSMOOTH_OK) {
        memcpy(mesh->positions, out, 3 * mesh->vertex_count * sizeof *out);
        what = argv[2];
        st = rsmooth_mesh_write_file(mesh, argv[2], RSMOOTH_FORMAT_AUTO, &err);
    }
    if (st == RSMOOTH_OK) {
        printf("wrote %s\n", argv[2]);
        code = EXIT_SUCCESS;
    } else {
        fprintf(stderr, "%s: %s: %s\n", what, rsmooth_status_str(st), err.message);
    }
done:
    free(out);
    rsmooth_context_destroy(ctx);
    rsmooth_mesh_destroy(mesh);
    return code;
}
