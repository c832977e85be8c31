/* The structs a caller allocates and the library fills keep the caller's struct_size: set by
 * their _init functions, untouched by every call that fills them (success or failure, whatever
 * value it holds), so a later library can tell how much of them it may write. */
#include "mesh_shapes.h"
#include "rsmooth.h"
#include "test_util.h"

#include <string.h>

int main(void) {
    rsmooth_error err;
    memset(&err, 0xab, sizeof err);
    rsmooth_error_init(&err);
    CHECK_EQ_INT(err.struct_size, sizeof err);
    CHECK(err.status == RSMOOTH_OK && err.message[0] == '\0' && err.line == -1);
    rsmooth_report report;
    memset(&report, 0xab, sizeof report);
    rsmooth_report_init(&report);
    CHECK_EQ_INT(report.struct_size, sizeof report);
    CHECK(report.vertex_count == 0 && report.ms_total == 0);
    rsmooth_device_info info;
    rsmooth_device_info_init(&info);
    CHECK_EQ_INT(info.struct_size, sizeof info);
    rsmooth_error_init(NULL);
    rsmooth_report_init(NULL);
    rsmooth_device_info_init(NULL);

    shape_mesh m;
    CHECK(shape_cube(&m, 4, 1.0) == 0);
    double *out = malloc(m.vertex_count * 3 * sizeof *out);
    CHECK(out);
    /* a call that fails, then one that succeeds: struct_size as the caller left it, initialised
     * or not */
    const size_t sizes[] = {sizeof err, 12345};
    for (int i = 0; i < 2; i++) {
        err.struct_size = sizes[i];
        report.struct_size = sizes[i] == sizeof err ? sizeof report : sizes[i];
        rsmooth_params p;
        rsmooth_params_init(&p);
        p.sigma_f = -1;
        CHECK_STATUS(rsmooth_smooth(NULL, RSMOOTH_FLOAT64, m.xyz, m.vertex_count, m.indices,
                                    m.triangle_count, &p, out, OUTPUTS(NULL, NULL, &report), &err),
                     RSMOOTH_ERROR_INVALID_ARGUMENT);
        CHECK_EQ_INT(err.struct_size, sizes[i]);
        CHECK(strstr(err.message, "sigma_f") != NULL);
        p.sigma_f = 2;
        p.passes = 1 + i; /* both ways the report is filled: one pass, and the passes' sum */
        CHECK_STATUS(rsmooth_smooth(NULL, RSMOOTH_FLOAT64, m.xyz, m.vertex_count, m.indices,
                                    m.triangle_count, &p, out, OUTPUTS(NULL, NULL, &report), &err),
                     RSMOOTH_OK);
        CHECK_EQ_INT(err.struct_size, sizes[i]);
        CHECK_EQ_INT(report.struct_size, sizes[i] == sizeof err ? sizeof report : sizes[i]);
        CHECK_EQ_INT(report.vertex_count, m.vertex_count);
        double *normals = malloc(m.vertex_count * 3 * sizeof *normals);
        CHECK(normals && shape_vertex_normals(&m, normals) == 0);
        CHECK_STATUS(rsmooth_smooth_points(NULL, RSMOOTH_FLOAT64, m.xyz, normals, m.vertex_count,
                                           &p, out, NULL, OUTPUTS(NULL, NULL, &report), &err),
                     RSMOOTH_OK);
        CHECK_EQ_INT(report.struct_size, sizes[i] == sizeof err ? sizeof report : sizes[i]);
        free(normals);
    }
    /* device entries keep theirs (an empty list where there is no OpenCL is fine too) */
    rsmooth_device_info list[4];
    for (int i = 0; i < 4; i++)
        rsmooth_device_info_init(&list[i]);
    size_t n = rsmooth_list_devices(list, 4);
    for (size_t i = 0; i < n && i < 4; i++)
        CHECK_EQ_INT(list[i].struct_size, sizeof list[i]);
    printf("abi: struct_size set by the _init functions and kept by every call (%zu devices)\n", n);
    free(out);
    shape_free(&m);
    return 0;
}
