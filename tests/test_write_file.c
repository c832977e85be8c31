/* Files written whole or not at all through rsmooth_io.h: rsmooth_mesh_write_file replaces an
 * existing file only with complete content. A write that fails midway (the process's file size
 * limit, RLIMIT_FSIZE, below the mesh's size: every write past it fails with EFBIG) leaves the
 * old file's bytes and mode as they were and nothing else in its folder, with the unnamed
 * temporary and the named one (RSMOOTH_NAMED_TEMPORARY=1); a write that succeeds gives the bytes
 * rsmooth_mesh_write_stream writes and keeps the old file's mode. rsmooth_file_write, the same
 * with the caller's content: its checks alone, a refused existing name, a failing writer, a
 * new file (its mode the umask's), and the warning for a file with another hard link. */
#define _GNU_SOURCE /* open_memstream, mkdtemp */
#include "rsmooth_io.h"
#include "test_util.h"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#define SIDE 40 /* vertices along each side of the grid: about 40 KB of OBJ */

static const char old_content[] = "the old file\n";

/* A SIDE x SIDE grid of vertices, two triangles per cell. */
static rsmooth_mesh *grid_mesh(void) {
    char *text = NULL;
    size_t size = 0;
    FILE *f = open_memstream(&text, &size);
    CHECK(f != NULL);
    for (int y = 0; y < SIDE; y++)
        for (int x = 0; x < SIDE; x++)
            fprintf(f, "v %d %d %.6f\n", x, y, 0.01 * ((x * 7 + y * 3) % 5));
    for (int y = 0; y + 1 < SIDE; y++)
        for (int x = 0; x + 1 < SIDE; x++) {
            int a = 1 + y * SIDE + x; /* OBJ counts from 1 */
            fprintf(f, "f %d %d %d\nf %d %d %d\n", a, a + 1, a + SIDE + 1, a, a + SIDE + 1,
                    a + SIDE);
        }
    CHECK(fclose(f) == 0);
    rsmooth_mesh *m = NULL;
    rsmooth_error err;
    CHECK_STATUS(rsmooth_mesh_read_memory(text, size, RSMOOTH_FORMAT_AUTO, &m, &err), RSMOOTH_OK);
    free(text);
    return m;
}

static char *read_whole(const char *path, size_t *size) {
    FILE *f = fopen(path, "rb");
    CHECK(f != NULL);
    char *data = NULL;
    size_t n = 0;
    FILE *out = open_memstream(&data, &n);
    CHECK(out != NULL);
    char buffer[4096];
    size_t got;
    while ((got = fread(buffer, 1, sizeof buffer, f)) > 0)
        CHECK(fwrite(buffer, 1, got, out) == got);
    CHECK(fclose(f) == 0);
    CHECK(fclose(out) == 0);
    *size = n;
    return data;
}

static void put_file(const char *path, const char *content, mode_t mode) {
    FILE *f = fopen(path, "wb");
    CHECK(f != NULL);
    CHECK(fputs(content, f) >= 0);
    CHECK(fclose(f) == 0);
    CHECK(chmod(path, mode) == 0);
}

/* The folder holds `name` and nothing else. */
static void check_alone(const char *dir, const char *name) {
    DIR *d = opendir(dir);
    CHECK(d != NULL);
    int others = 0, found = 0;
    for (struct dirent *e; (e = readdir(d)) != NULL;) {
        if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, ".."))
            continue;
        if (!strcmp(e->d_name, name))
            found++;
        else {
            printf("left behind: %s\n", e->d_name);
            others++;
        }
    }
    closedir(d);
    CHECK_EQ_INT(found, 1);
    CHECK_EQ_INT(others, 0);
}

static void check_file(const char *path, const char *content, size_t size, mode_t mode) {
    size_t got_size;
    char *got = read_whole(path, &got_size);
    CHECK_EQ_INT(got_size, size);
    CHECK(memcmp(got, content, size) == 0);
    free(got);
    struct stat st;
    CHECK(stat(path, &st) == 0);
    CHECK_EQ_INT(st.st_mode & 07777, mode);
}

static void check_failed_write_keeps_old(const rsmooth_mesh *m, const char *dir, bool named) {
    char path[4200];
    snprintf(path, sizeof path, "%s/out.obj", dir);
    put_file(path, old_content, 0640);
    if (named)
        CHECK(setenv("RSMOOTH_NAMED_TEMPORARY", "1", 1) == 0);
    struct rlimit saved, small;
    CHECK(getrlimit(RLIMIT_FSIZE, &saved) == 0);
    small = saved;
    small.rlim_cur = 4096; /* far below the mesh's OBJ: the write fails midway */
    CHECK(setrlimit(RLIMIT_FSIZE, &small) == 0);
    rsmooth_error err;
    rsmooth_status st = rsmooth_mesh_write_file(m, path, RSMOOTH_FORMAT_OBJ, &err);
    CHECK(setrlimit(RLIMIT_FSIZE, &saved) == 0);
    CHECK(unsetenv("RSMOOTH_NAMED_TEMPORARY") == 0);
    printf("%s temporary, a write past the size limit: %s: %s\n", named ? "named" : "unnamed",
           rsmooth_status_str(st), err.message);
    CHECK_STATUS(st, RSMOOTH_ERROR_IO);
    CHECK(strstr(err.message, path) != NULL);
    check_file(path, old_content, strlen(old_content), 0640);
    check_alone(dir, "out.obj");
}

static void check_write_replaces(const rsmooth_mesh *m, const char *dir, bool named) {
    char path[4200];
    snprintf(path, sizeof path, "%s/out.obj", dir);
    put_file(path, old_content, 0604);
    if (named)
        CHECK(setenv("RSMOOTH_NAMED_TEMPORARY", "1", 1) == 0);
    rsmooth_error err;
    CHECK_STATUS(rsmooth_mesh_write_file(m, path, RSMOOTH_FORMAT_OBJ, &err), RSMOOTH_OK);
    CHECK(unsetenv("RSMOOTH_NAMED_TEMPORARY") == 0);
    CHECK_EQ_INT(err.message[0], '\0'); /* no warning: one link, our own file */
    char *expected = NULL;
    size_t size = 0;
    FILE *f = open_memstream(&expected, &size);
    CHECK(f != NULL);
    CHECK_STATUS(rsmooth_mesh_write_stream(m, f, RSMOOTH_FORMAT_OBJ, &err), RSMOOTH_OK);
    CHECK(fclose(f) == 0);
    CHECK(size > 4096);
    check_file(path, expected, size, 0604);
    check_alone(dir, "out.obj");
    free(expected);
    printf("%s temporary, a write that succeeds: the stream's %zu bytes, mode 0604 kept\n",
           named ? "named" : "unnamed", size);
}

/* rsmooth_file_write's content: `user` as text, or a failure after part of it. */
static int write_text(FILE *stream, void *user, char *message, size_t size) {
    const char *text = user;
    if (fputs(text, stream) < 0)
        return -1;
    if (!strcmp(text, "half")) {
        snprintf(message, size, "gave up half-way");
        return -1;
    }
    return 0;
}

static void check_file_write(const char *dir) {
    char path[4200], link[4200];
    snprintf(path, sizeof path, "%s/note.txt", dir);
    snprintf(link, sizeof link, "%s/other-name.txt", dir);
    rsmooth_error err;
    /* the checks alone: a new name may be written, and nothing is */
    CHECK_STATUS(rsmooth_file_write(path, 0, "use --force", NULL, NULL, &err), RSMOOTH_OK);
    CHECK(access(path, F_OK) != 0);
    CHECK_STATUS(rsmooth_file_write(dir, 1, NULL, NULL, NULL, &err), RSMOOTH_ERROR_IO);
    CHECK(strstr(err.message, "is a directory") != NULL);
    CHECK_STATUS(rsmooth_file_write(NULL, 1, NULL, NULL, NULL, &err),
                 RSMOOTH_ERROR_INVALID_ARGUMENT);
    /* a new file */
    CHECK_STATUS(rsmooth_file_write(path, 0, "use --force", write_text, "first\n", &err),
                 RSMOOTH_OK);
    check_file(path, "first\n", 6, 0644); /* 0666 less main's umask */
    /* an existing name without replace: refused with the caller's hint, whether checked alone
     * or written */
    CHECK_STATUS(rsmooth_file_write(path, 0, "use --force", NULL, NULL, &err), RSMOOTH_ERROR_IO);
    CHECK(strstr(err.message, "already exists (use --force to replace it)") != NULL);
    CHECK_STATUS(rsmooth_file_write(path, 0, NULL, write_text, "second\n", &err), RSMOOTH_ERROR_IO);
    CHECK(strstr(err.message, "already exists (set replace to replace it)") != NULL);
    /* a writer that fails: its message, the file as it was, no temporary */
    CHECK_STATUS(rsmooth_file_write(path, 1, NULL, write_text, "half", &err), RSMOOTH_ERROR_IO);
    printf("a failing writer: %s\n", err.message);
    CHECK(strstr(err.message, path) == err.message);
    CHECK(strstr(err.message, "cannot write: gave up half-way") != NULL);
    check_file(path, "first\n", 6, 0644);
    check_alone(dir, "note.txt");
    /* replaced while another hard link holds the old content: a warning on success */
    CHECK(chmod(path, 0600) == 0);
    CHECK(linkat(AT_FDCWD, path, AT_FDCWD, link, 0) == 0);
    CHECK_STATUS(rsmooth_file_write(path, 1, NULL, write_text, "second\n", &err), RSMOOTH_OK);
    printf("another hard link: warning '%s'\n", err.message);
    CHECK(strstr(err.message, "the file has 2 hard links") != NULL);
    check_file(path, "second\n", 7, 0600);
    check_file(link, "first\n", 6, 0600);
    CHECK(remove(link) == 0);
    CHECK(remove(path) == 0);
    /* a new file's mode: the umask's, which is left as it was (a named temporary is made 0600) */
    umask(027);
    CHECK(setenv("RSMOOTH_NAMED_TEMPORARY", "1", 1) == 0);
    CHECK_STATUS(rsmooth_file_write(path, 0, NULL, write_text, "third\n", &err), RSMOOTH_OK);
    CHECK(unsetenv("RSMOOTH_NAMED_TEMPORARY") == 0);
    CHECK_EQ_INT(umask(022), 027);
    check_file(path, "third\n", 6, 0640);
    CHECK(remove(path) == 0);
}

int main(void) {
    umask(022);
    signal(SIGXFSZ, SIG_IGN); /* a write past RLIMIT_FSIZE fails with EFBIG instead */
    char dir[] = "/tmp/rsmooth_test_write_file_XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    rsmooth_mesh *m = grid_mesh();
    for (int named = 0; named < 2; named++) {
        check_failed_write_keeps_old(m, dir, named);
        check_write_replaces(m, dir, named);
    }
    char path[4200];
    snprintf(path, sizeof path, "%s/out.obj", dir);
    CHECK(remove(path) == 0);
    check_file_write(dir);
    CHECK(rmdir(dir) == 0);
    rsmooth_mesh_destroy(m);
    printf("write_file: all checks passed\n");
    return 0;
}
