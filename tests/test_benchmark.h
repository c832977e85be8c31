/* The benchmark meshes of ../shared (RSMOOTH_SHARED_DIR, which tests/CMakeLists.txt sets when the
 * folder exists): tests use them when they are there and skip those parts when they are not. */
#ifndef RSMOOTH_TEST_BENCHMARK_H
#define RSMOOTH_TEST_BENCHMARK_H

#include "rsmooth_io.h"

#include <stdbool.h>
#include <stdio.h>
#include <sys/stat.h>

/* Writes the benchmark folder's path to `dir`; false, after saying it is skipped, when absent. */
static inline bool benchmark_dir(char *dir, size_t size) {
    struct stat st;
    snprintf(dir, size, "%s/data/benchmark", RSMOOTH_SHARED_DIR);
    if (RSMOOTH_SHARED_DIR[0] == '\0' || stat(dir, &st) != 0) {
        printf("benchmark meshes: %s absent, skipped\n", dir);
        return false;
    }
    return true;
}

/* Reads dir/model/file (e.g. "Noisy.obj"); NULL, after saying why it is skipped, when it cannot. */
static inline rsmooth_mesh *benchmark_read(const char *dir, const char *model, const char *file) {
    char path[4200];
    snprintf(path, sizeof path, "%s/%s/%s", dir, model, file);
    rsmooth_mesh *mesh = NULL;
    rsmooth_error err;
    if (rsmooth_mesh_read_file(path, &mesh, &err) != RSMOOTH_OK) {
        printf("%s: %s, skipped\n", path, err.message);
        return NULL;
    }
    return mesh;
}

#endif /* RSMOOTH_TEST_BENCHMARK_H */
