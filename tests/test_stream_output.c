/* The streaming call's output (rsmooth_stream_smooth): it writes
 * its file as the command writes its own. On the reference path (no device needed), a small mesh
 * written to a plain new file is the oracle; then with options->replace: a FIFO, a folder, a link
 * to nothing and (as root) a device node are refused and left as they were; a link to a file is
 * written through and stays a link; a replaced file keeps its mode (and, as root, its owner and
 * group); other hard links keep the old content and the report says so; a 250-byte name works;
 * without replace an existing file is refused naming options->replace. options->tmpdir "", too
 * long or missing is refused. Nothing is ever left in the folder but what the test made. */
#define _GNU_SOURCE
#include "mesh_shapes.h"
#include "rsmooth.h"
#include "rsmooth_io.h"
#include "test_util.h"

#include <dirent.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

static char dir[64];
static char expected_path[128];

static const char *in_dir(const char *name) {
    static char buf[8][512];
    static int next;
    char *p = buf[next++ % 8];
    snprintf(p, 512, "%s/%s", dir, name);
    return p;
}

static bool same_bytes(const char *a, const char *b) {
    FILE *fa = fopen(a, "rb"), *fb = fopen(b, "rb");
    bool same = fa && fb;
    for (int ca = 0, cb = 0; same && ca != EOF;) {
        ca = fgetc(fa);
        cb = fgetc(fb);
        same = ca == cb;
    }
    if (fa)
        fclose(fa);
    if (fb)
        fclose(fb);
    return same;
}

/* Streams the test mesh into `out` on the reference path; the status, with the report's notes. */
static rsmooth_status stream(const char *out, int replace, const char *tmpdir, char *notes,
                             rsmooth_error *err) {
    rsmooth_stream_options so;
    rsmooth_stream_options_init(&so);
    so.max_memory = 16u << 20;
    so.replace = replace;
    so.tmpdir = tmpdir;
    rsmooth_stream_report rep;
    rsmooth_stream_report_init(&rep);
    rsmooth_status st = rsmooth_stream_smooth(NULL, in_dir("in.ply"), out, NULL, &so, &rep, err);
    if (notes)
        snprintf(notes, 400, "%s", rep.notes);
    return st;
}

static void expect_refused(const char *out, int replace, const char *tmpdir, rsmooth_status want,
                           const char *message) {
    rsmooth_error err;
    rsmooth_status st = stream(out, replace, tmpdir, NULL, &err);
    printf("  %s: %s\n", rsmooth_status_str(st), err.message);
    CHECK_EQ_INT(st, want);
    CHECK(strstr(err.message, message) != NULL);
}

/* A binary little-endian PLY of `m` (this test runs where doubles and ints are little-endian). */
static void write_ply(const char *path, const shape_mesh *m) {
    FILE *f = fopen(path, "wb");
    CHECK(f);
    fprintf(f,
            "ply\nformat binary_little_endian 1.0\nelement vertex %zu\nproperty double x\n"
            "property double y\nproperty double z\nelement face %zu\n"
            "property list uchar int vertex_indices\nend_header\n",
            m->vertex_count, m->triangle_count);
    CHECK(fwrite(m->xyz, 3 * sizeof(double), m->vertex_count, f) == m->vertex_count);
    for (size_t t = 0; t < m->triangle_count; t++) {
        unsigned char three = 3;
        int32_t v[3] = {(int32_t)m->indices[3 * t], (int32_t)m->indices[3 * t + 1],
                        (int32_t)m->indices[3 * t + 2]};
        CHECK(fwrite(&three, 1, 1, f) == 1 && fwrite(v, sizeof v, 1, f) == 1);
    }
    CHECK(fclose(f) == 0);
}

static void write_text(const char *path, const char *text) {
    FILE *f = fopen(path, "w");
    CHECK(f && fputs(text, f) >= 0 && fclose(f) == 0);
}

/* The folder holds exactly `count` entries (no temporary left behind). */
static void check_entries(int count) {
    DIR *d = opendir(dir);
    CHECK(d);
    int n = 0;
    for (struct dirent *e; (e = readdir(d)) != NULL;)
        if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) {
            n++;
            CHECK(strncmp(e->d_name, ".rsmooth", 8) != 0);
        }
    closedir(d);
    CHECK_EQ_INT(n, count);
}

int main(void) {
    snprintf(dir, sizeof dir, "stream-output-XXXXXX");
    CHECK(mkdtemp(dir));
    shape_mesh m;
    CHECK(shape_cube(&m, 8, 1.0) == 0);
    CHECK(shape_add_normal_noise(&m, 0.3, 3) == 0);
    write_ply(in_dir("in.ply"), &m);
    rsmooth_error err;
    snprintf(expected_path, sizeof expected_path, "%s", in_dir("expected.ply"));
    CHECK_STATUS(stream(expected_path, 0, NULL, NULL, &err), RSMOOTH_OK);
    int entries = 2;

    printf("special files are never replaced, even with replace:\n");
    CHECK(mkfifo(in_dir("fifo.ply"), 0600) == 0);
    expect_refused(in_dir("fifo.ply"), 1, NULL, RSMOOTH_ERROR_IO, "is not a regular file");
    struct stat st;
    CHECK(lstat(in_dir("fifo.ply"), &st) == 0 && S_ISFIFO(st.st_mode));
    CHECK(mkdir(in_dir("folder.ply"), 0700) == 0);
    expect_refused(in_dir("folder.ply"), 1, NULL, RSMOOTH_ERROR_IO, "is a directory");
    CHECK(symlink("nowhere.ply", in_dir("dangling.ply")) == 0);
    expect_refused(in_dir("dangling.ply"), 1, NULL, RSMOOTH_ERROR_IO, "which does not exist");
    CHECK(lstat(in_dir("dangling.ply"), &st) == 0 && S_ISLNK(st.st_mode));
    entries += 3;
    if (geteuid() == 0) {
        CHECK(mknod(in_dir("null.ply"), S_IFCHR | 0600, makedev(1, 3)) == 0);
        expect_refused(in_dir("null.ply"), 1, NULL, RSMOOTH_ERROR_IO, "is not a regular file");
        CHECK(lstat(in_dir("null.ply"), &st) == 0 && S_ISCHR(st.st_mode));
        entries++;
    } else {
        printf("  (not root: no device node tried)\n");
    }
    check_entries(entries);

    printf("a link to a file is written through, and stays a link:\n");
    write_text(in_dir("target.ply"), "old\n");
    CHECK(symlink("target.ply", in_dir("link.ply")) == 0);
    expect_refused(in_dir("link.ply"), 0, NULL, RSMOOTH_ERROR_IO, "set options->replace");
    CHECK_STATUS(stream(in_dir("link.ply"), 1, NULL, NULL, &err), RSMOOTH_OK);
    CHECK(lstat(in_dir("link.ply"), &st) == 0 && S_ISLNK(st.st_mode));
    CHECK(same_bytes(in_dir("target.ply"), expected_path));
    entries += 2;

    printf("a replaced file keeps its mode (and owner and group), hard links are reported:\n");
    write_text(in_dir("kept.ply"), "old\n");
    CHECK(chmod(in_dir("kept.ply"), 0640) == 0);
    bool root = geteuid() == 0;
    if (root)
        CHECK(chown(in_dir("kept.ply"), 65534, 65534) == 0);
    CHECK(link(in_dir("kept.ply"), in_dir("kept-too.ply")) == 0);
    char notes[400];
    CHECK_STATUS(stream(in_dir("kept.ply"), 1, NULL, notes, &err), RSMOOTH_OK);
    CHECK(stat(in_dir("kept.ply"), &st) == 0);
    printf("  mode %o, owner %ld:%ld; notes: %s\n", (unsigned)(st.st_mode & 07777), (long)st.st_uid,
           (long)st.st_gid, notes);
    CHECK_EQ_INT(st.st_mode & 07777, 0640);
    if (root)
        CHECK(st.st_uid == 65534 && st.st_gid == 65534);
    CHECK(strstr(notes, "the file has 2 hard links") != NULL);
    CHECK(same_bytes(in_dir("kept.ply"), expected_path));
    FILE *f = fopen(in_dir("kept-too.ply"), "r");
    char line[16] = "";
    CHECK(f && fgets(line, sizeof line, f) && fclose(f) == 0);
    CHECK(strcmp(line, "old\n") == 0);
    entries += 2;

    printf("a 250-byte output name, new and replaced:\n");
    char name[251];
    memset(name, 'n', 246);
    strcpy(name + 246, ".ply");
    CHECK_STATUS(stream(in_dir(name), 0, NULL, NULL, &err), RSMOOTH_OK);
    CHECK_STATUS(stream(in_dir(name), 1, NULL, NULL, &err), RSMOOTH_OK);
    CHECK(same_bytes(in_dir(name), expected_path));
    entries++;

    printf("options->tmpdir must name a folder:\n");
    expect_refused(in_dir("tmp.ply"), 0, "", RSMOOTH_ERROR_INVALID_ARGUMENT, "tmpdir is empty");
    char *longdir = malloc(5001);
    CHECK(longdir);
    memset(longdir, 'd', 5000);
    longdir[0] = '/';
    longdir[5000] = '\0';
    expect_refused(in_dir("tmp.ply"), 0, longdir, RSMOOTH_ERROR_INVALID_ARGUMENT,
                   "tmpdir is 5000 bytes long");
    free(longdir);
    expect_refused(in_dir("tmp.ply"), 0, in_dir("missing"), RSMOOTH_ERROR_IO, "tmpdir");
    expect_refused(in_dir("tmp.ply"), 0, in_dir("in.ply"), RSMOOTH_ERROR_IO, "not a folder");
    check_entries(entries);

    shape_free(&m);
    char command[128];
    snprintf(command, sizeof command, "rm -rf '%s'", dir);
    CHECK(system(command) == 0);
    printf("ok\n");
    return 0;
}
