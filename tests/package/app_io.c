/* A host that reads and writes mesh files (rsmooth_io.h, with rsmooth.h's filter): an OBJ from
 * memory, smoothed on the reference path, written back as OBJ. Built by test_package.sh with the
 * README's own lines (pkg-config rsmooth-io, CMake rsmooth::io). */
#include <rsmooth_io.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int main(void) {
    static const char obj[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                              "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
    rsmooth_error err;
    rsmooth_mesh *mesh = NULL;
    rsmooth_status st =
        rsmooth_mesh_read_memory(obj, strlen(obj), RSMOOTH_FORMAT_AUTO, &mesh, &err);
    if (st != RSMOOTH_OK) {
        fprintf(stderr, "app_io: read: %s\n", err.message);
        return 1;
    }
    double *out = malloc(3 * mesh->vertex_count * sizeof *out);
    st = out ? rsmooth_smooth(NULL, RSMOOTH_FLOAT64, mesh->positions, mesh->vertex_count,
                              mesh->triangles, mesh->triangle_count, NULL, out, NULL, &err)
             : RSMOOTH_ERROR_OUT_OF_MEMORY;
    if (st == RSMOOTH_OK) {
        memcpy(mesh->positions, out, 3 * mesh->vertex_count * sizeof *out);
        FILE *f = tmpfile();
        st = f ? rsmooth_mesh_write_stream(mesh, f, rsmooth_format_from_path("out.obj"), &err)
               : RSMOOTH_ERROR_IO;
        long size = f ? ftell(f) : -1;
        if (f)
            fclose(f);
        printf("app_io: %zu vertices read, smoothed, %ld bytes of OBJ written: %s\n",
               mesh->vertex_count, size, rsmooth_status_str(st));
    }
    free(out);
    rsmooth_mesh_destroy(mesh);
    return st == RSMOOTH_OK ? 0 : 1;
}
