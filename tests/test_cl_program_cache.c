/* rsmooth's program cache (lib/opencl/cl_program_cache.c): a miss writes one file, the next context
 * hits it and smooths bit for bit as the source build; damaged files (truncated, flipped bytes,
 * wrong magic, empty, a folder in the file's place) are misses that get rewritten; folders that
 * cannot be made or written, and "off", build from source and leave nothing; the default folders;
 * and processes and threads starting together on an empty folder all succeed and leave one whole
 * file and no temporaries. Then trust: a binary built from modified kernels,
 * planted under the genuine key with a valid digest, is refused in a folder another user owns or
 * can write, and in the home chain, said in the context's program_cache_note, and the results are
 * the genuine program's; a FIFO, a link or a file of another user at the key's name is never opened
 * as a cache file. Everything happens in a fresh folder in the working directory. */
#define _POSIX_C_SOURCE 200809L
#include "core/blake2b.h"
#include "mesh_shapes.h"
#include "test_cl_util.h"

#include <dirent.h>
#include <fcntl.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#define PROCESSES 6
#define THREADS 4
/* The file format (lib/opencl/cl_program_cache.c): 64 bytes of words, BLAKE2b-256 of them and the
 * binary, the binary; the binary's size is the word at byte 48. */
#define HEADER_WORDS_BYTES 64
#define HEADER_BYTES 96

static char base[256]; /* this run's folder, absolute */

/* A context on the default device with the environment as it is, and where its program came from.
 */
static rsmooth_context *create(const char *expect) {
    rsmooth_context *ctx = NULL;
    rsmooth_error err;
    rsmooth_status st = rsmooth_context_create(NULL, &ctx, &err);
    if (st != RSMOOTH_OK) {
        fprintf(stderr, "context: %s: %s\n", rsmooth_status_str(st), err.message);
        exit(1);
    }
    rsmooth_context_info info = context_info(ctx);
    const char *got = info.program_cache;
    printf("  program cache %s, build %.1f ms%s%s\n", got, info.build_ms,
           *info.program_cache_note ? ": " : "", info.program_cache_note);
    /* a note exactly when refused */
    CHECK((strcmp(got, "refused") == 0) == (*info.program_cache_note != '\0'));
    if (expect && strcmp(got, expect) != 0) {
        fprintf(stderr, "%s:%d: program cache \"%s\", expected \"%s\"\n", __FILE__, __LINE__, got,
                expect);
        exit(1);
    }
    return ctx;
}

static void create_destroy(const char *expect) {
    rsmooth_context_destroy(create(expect));
}

/* Files in `dir` ending in .clbin, and the other entries (temporaries); -1 each when it cannot be
 * read. */
static void count_files(const char *dir, int *cache_files, int *others) {
    *cache_files = *others = 0;
    DIR *d = opendir(dir);
    if (!d) {
        *cache_files = *others = -1;
        return;
    }
    struct dirent *e;
    while ((e = readdir(d))) {
        if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0)
            continue;
        size_t n = strlen(e->d_name);
        if (n > 6 && strcmp(e->d_name + n - 6, ".clbin") == 0)
            (*cache_files)++;
        else
            (*others)++;
    }
    closedir(d);
}

/* The path of the one cache file in `dir` (which must hold exactly that). */
static void the_file(const char *dir, char *path, size_t size) {
    int files, others;
    count_files(dir, &files, &others);
    CHECK_EQ_INT(files, 1);
    CHECK_EQ_INT(others, 0);
    DIR *d = opendir(dir);
    CHECK(d);
    struct dirent *e;
    while ((e = readdir(d)))
        if (e->d_name[0] != '.')
            snprintf(path, size, "%s/%s", dir, e->d_name);
    closedir(d);
}

static void make_dir(char *path, size_t size, const char *name) {
    snprintf(path, size, "%s/%s", base, name);
    CHECK(mkdir(path, 0700) == 0);
}

static void use_dir(const char *dir) {
    CHECK(setenv("RSMOOTH_CACHE_DIR", dir, 1) == 0);
}

/* Smooths a noisy cube with the default normals and with the bilateral filter. */
static void smooth(rsmooth_context *ctx, const shape_mesh *m, double *out) {
    rsmooth_params p;
    rsmooth_params_init(&p);
    rsmooth_error err;
    size_t n = 3 * m->vertex_count;
    CHECK_STATUS(rsmooth_smooth(ctx, RSMOOTH_FLOAT64, m->xyz, m->vertex_count, m->indices,
                                m->triangle_count, &p, out, NULL, &err),
                 RSMOOTH_OK);
    p.normal_filter = RSMOOTH_NORMALS_BILATERAL;
    CHECK_STATUS(rsmooth_smooth(ctx, RSMOOTH_FLOAT64, m->xyz, m->vertex_count, m->indices,
                                m->triangle_count, &p, out + n, NULL, &err),
                 RSMOOTH_OK);
}

static size_t file_size(const char *path) {
    struct stat st;
    CHECK(stat(path, &st) == 0);
    return (size_t)st.st_size;
}

/* Damage kinds, each applied to a valid file. */
enum {
    TRUNCATE_HALF,
    TRUNCATE_HEADER,
    EMPTY,
    FLIP_BINARY,
    FLIP_DIGEST,
    FLIP_KEY,
    WRONG_MAGIC,
    LONGER,
    DAMAGE_COUNT
};
static const char *const damage_names[DAMAGE_COUNT] = {"truncated to half",
                                                       "truncated in the header",
                                                       "empty",
                                                       "a byte of the binary flipped",
                                                       "a byte of the digest flipped",
                                                       "a byte of the key flipped",
                                                       "wrong magic",
                                                       "a byte appended"};

static void flip(int fd, off_t at) {
    unsigned char c;
    CHECK(pread(fd, &c, 1, at) == 1);
    c ^= 0x5a;
    CHECK(pwrite(fd, &c, 1, at) == 1);
}

static void damage(const char *path, int kind) {
    size_t size = file_size(path);
    int fd = open(path, O_RDWR);
    CHECK(fd >= 0);
    switch (kind) {
    case TRUNCATE_HALF:
        CHECK(ftruncate(fd, (off_t)(size / 2)) == 0);
        break;
    case TRUNCATE_HEADER:
        CHECK(ftruncate(fd, 20) == 0);
        break;
    case EMPTY:
        CHECK(ftruncate(fd, 0) == 0);
        break;
    case FLIP_BINARY:
        flip(fd, (off_t)(size / 2));
        break;
    case FLIP_DIGEST:
        flip(fd, (off_t)(HEADER_BYTES - 3));
        break;
    case FLIP_KEY:
        flip(fd, 20);
        break;
    case WRONG_MAGIC:
        CHECK(pwrite(fd, "XXXXXXXX", 8, 0) == 8);
        break;
    case LONGER:
        CHECK(pwrite(fd, "x", 1, (off_t)size) == 1);
        break;
    }
    close(fd);
}

/* A child process of the concurrency check: one context, on the folder the environment names. */
static int child(void) {
    rsmooth_context *ctx = create(NULL);
    rsmooth_context_destroy(ctx);
    return 0;
}

static void *thread_create(void *arg) {
    rsmooth_context *ctx = NULL;
    rsmooth_error err;
    *(int *)arg = rsmooth_context_create(NULL, &ctx, &err) == RSMOOTH_OK;
    rsmooth_context_destroy(ctx);
    return NULL;
}

static void remove_tree(const char *path) {
    struct stat st;
    if (lstat(path, &st) != 0)
        return;
    if (S_ISDIR(st.st_mode)) {
        DIR *d = opendir(path);
        if (d) {
            struct dirent *e;
            while ((e = readdir(d))) {
                if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0)
                    continue;
                char sub[1024];
                snprintf(sub, sizeof sub, "%s/%s", path, e->d_name);
                remove_tree(sub);
            }
            closedir(d);
        }
        chmod(path, 0700);
        rmdir(path);
    } else {
        unlink(path);
    }
}

/* ---- trust -------------------------------------------------------------------------------------
 */

static unsigned char *read_whole(const char *path, size_t *size) {
    *size = file_size(path);
    unsigned char *data = malloc(*size + 1);
    FILE *f = fopen(path, "rb");
    CHECK(data && f && fread(data, 1, *size, f) == *size && fclose(f) == 0);
    data[*size] = 0; /* text files can be searched as strings */
    return data;
}

/* Writes `path` anew with exactly `mode` (whatever the umask). */
static void write_whole(const char *path, const void *data, size_t size, mode_t mode) {
    int fd = open(path, O_WRONLY | O_CREAT | O_TRUNC, 0600);
    CHECK(fd >= 0 && write(fd, data, size) == (ssize_t)size && fchmod(fd, mode) == 0);
    CHECK(close(fd) == 0);
}

/* A copy of the kernels in `dir` whose fast_exp2 takes a quarter of its argument: Gaussians twice
 * as wide, so every vertex moves differently. What an attacker's binary would compute. */
static void modified_kernels(const char *dir) {
    static const char *const names[] = {"common.cl", "mollify.cl", "bilateral.cl", "estimate.cl",
                                        "stage.cl",  "grid.cl",    "learned.cl"};
    static const char anchor[] = "inline lanef fast_exp2(lanef x) {";
    CHECK(mkdir(dir, 0700) == 0);
    for (int i = 0; i < (int)(sizeof names / sizeof *names); i++) {
        char from[1024], to[1024];
        snprintf(from, sizeof from, "%s/%s", RSMOOTH_KERNEL_SOURCE_DIR, names[i]);
        snprintf(to, sizeof to, "%s/%s", dir, names[i]);
        size_t size;
        unsigned char *text = read_whole(from, &size);
        FILE *f = fopen(to, "wb");
        CHECK(f);
        char *at = i == 0 ? strstr((char *)text, anchor) : NULL;
        if (i == 0) {
            CHECK(at && (size_t)(at - (char *)text) < size);
            size_t head = (size_t)(at - (char *)text) + sizeof anchor - 1;
            CHECK(fwrite(text, 1, head, f) == head);
            fputs(" x = 0.25f * x;", f);
            CHECK(fwrite(text + head, 1, size - head, f) == size - head);
        } else {
            CHECK(fwrite(text, 1, size, f) == size);
        }
        CHECK(fclose(f) == 0);
        free(text);
    }
}

/* Standard error between capture_begin and capture_count goes to a file. */
static int saved_stderr = -1;
static char capture_path[600];

static void capture_begin(void) {
    fflush(stderr);
    saved_stderr = dup(2);
    int fd = open(capture_path, O_WRONLY | O_CREAT | O_TRUNC, 0600);
    CHECK(saved_stderr >= 0 && fd >= 0 && dup2(fd, 2) == 2);
    close(fd);
}

/* Ends the capture, prints what was said, and counts the lines that contain `needle`. */
static int capture_count(const char *needle) {
    fflush(stderr);
    CHECK(dup2(saved_stderr, 2) == 2);
    close(saved_stderr);
    FILE *f = fopen(capture_path, "r");
    CHECK(f);
    char line[2048];
    int count = 0;
    while (fgets(line, sizeof line, f)) {
        printf("  stderr: %s", line);
        count += strstr(line, needle) != NULL;
    }
    fclose(f);
    return count;
}

static double max_difference(const double *a, const double *b, size_t n) {
    double most = 0;
    for (size_t i = 0; i < n; i++)
        most = fmax(most, fabs(a[i] - b[i]));
    return most;
}

/* A context that must refuse the cache; its results must be the genuine program's. */
static void expect_refused(const shape_mesh *cube, const double *genuine, double *out) {
    rsmooth_context *ctx = create("refused");
    smooth(ctx, cube, out);
    rsmooth_context_destroy(ctx);
    CHECK(memcmp(out, genuine, 6 * cube->vertex_count * sizeof *out) == 0);
}

/* The planted file `payload` at `name` in a fresh folder `folder` (made 0700, then given `mode`).
 */
static void plant(char *dir, size_t size, const char *folder, mode_t mode, const char *name,
                  const unsigned char *payload, size_t payload_size, mode_t file_mode) {
    make_dir(dir, size, folder);
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    write_whole(path, payload, payload_size, file_mode);
    CHECK(chmod(dir, mode) == 0);
}

static void trust(const shape_mesh *cube, const double *genuine) {
    size_t n = 6 * cube->vertex_count;
    double *out = malloc(n * sizeof *out), *modified = malloc(n * sizeof *modified);
    char dir[512], path[1024], kernels[512], name[256];
    CHECK(out && modified);
    alarm(600); /* a cache read that blocks (a FIFO) fails the test instead of hanging it */

    printf("trust: the genuine file and one built from modified kernels:\n");
    make_dir(dir, sizeof dir, "trust-genuine");
    use_dir(dir);
    create_destroy("miss");
    the_file(dir, path, sizeof path);
    snprintf(name, sizeof name, "%s", strrchr(path, '/') + 1);
    size_t genuine_size, modified_size;
    unsigned char *genuine_file = read_whole(path, &genuine_size);
    snprintf(kernels, sizeof kernels, "%s/modified-kernels", base);
    modified_kernels(kernels);
    CHECK(setenv("RSMOOTH_KERNEL_DIR", kernels, 1) == 0);
    make_dir(dir, sizeof dir, "trust-modified");
    use_dir(dir);
    rsmooth_context *ctx = create("miss");
    smooth(ctx, cube, modified);
    rsmooth_context_destroy(ctx);
    CHECK(unsetenv("RSMOOTH_KERNEL_DIR") == 0);
    printf("  modified kernels move vertices up to %.3g from the genuine results\n",
           max_difference(modified, genuine, n));
    CHECK(max_difference(modified, genuine, n) > 1e-3);
    the_file(dir, path, sizeof path);
    unsigned char *modified_file = read_whole(path, &modified_size);

    /* The attack: the genuine file's key words, the modified binary, a digest made to match. */
    CHECK(genuine_size > HEADER_BYTES && modified_size > HEADER_BYTES);
    size_t binary_size = modified_size - HEADER_BYTES, payload_size = modified_size;
    unsigned char *payload = malloc(payload_size);
    CHECK(payload);
    memcpy(payload, genuine_file, HEADER_WORDS_BYTES);
    for (int i = 0; i < 8; i++)
        payload[48 + i] = (unsigned char)((uint64_t)binary_size >> (8 * i));
    memcpy(payload + HEADER_BYTES, modified_file + HEADER_BYTES, binary_size);
    rs_blake2b digest;
    CHECK(rs_blake2b_init(&digest, 32));
    rs_blake2b_update(&digest, payload, HEADER_WORDS_BYTES);
    rs_blake2b_update(&digest, payload + HEADER_BYTES, binary_size);
    rs_blake2b_final(&digest, payload + HEADER_WORDS_BYTES);

    printf("in the user's own folder the planted file is a working payload (control):\n");
    plant(dir, sizeof dir, "trust-own", 0700, name, payload, payload_size, 0600);
    use_dir(dir);
    ctx = create("hit");
    smooth(ctx, cube, out);
    rsmooth_context_destroy(ctx);
    CHECK(memcmp(out, modified, n * sizeof *out) == 0);
    char own_payload[1024];
    snprintf(own_payload, sizeof own_payload, "%s/%s", dir, name);

    printf("the genuine key with the digest not matching the binary: a miss, replaced:\n");
    memcpy(payload + HEADER_WORDS_BYTES, genuine_file + HEADER_WORDS_BYTES, 32);
    plant(dir, sizeof dir, "trust-digest", 0700, name, payload, payload_size, 0600);
    use_dir(dir);
    ctx = create("miss");
    smooth(ctx, cube, out);
    rsmooth_context_destroy(ctx);
    CHECK(memcmp(out, genuine, n * sizeof *out) == 0);
    create_destroy("hit");
    free(payload);
    payload = read_whole(own_payload, &payload_size); /* the valid payload again */

    printf("a folder writable by others: refused, said in the context's note (the library prints "
           "nothing), nothing written:\n");
    snprintf(capture_path, sizeof capture_path, "%s/stderr.txt", base);
    plant(dir, sizeof dir, "trust-writable", 0777, name, payload, payload_size, 0600);
    use_dir(dir);
    capture_begin();
    ctx = create("refused");
    rsmooth_context_info info = context_info(ctx);
    CHECK(strstr(info.program_cache_note, "not using the program cache") != NULL);
    CHECK(strstr(info.program_cache_note, "writable by other users") != NULL);
    rsmooth_context_destroy(ctx);
    create_destroy("refused");
    CHECK_EQ_INT(capture_count("not using the program cache"), 0);
    expect_refused(cube, genuine, out);
    int files, others;
    count_files(dir, &files, &others);
    CHECK_EQ_INT(files, 1);
    CHECK_EQ_INT(others, 0);
    size_t after_size;
    snprintf(path, sizeof path, "%s/%s", dir, name);
    unsigned char *after = read_whole(path, &after_size);
    CHECK(after_size == payload_size && memcmp(after, payload, payload_size) == 0);
    free(after);
    plant(dir, sizeof dir, "trust-group", 0770, name, payload, payload_size, 0600);
    use_dir(dir);
    expect_refused(cube, genuine, out);

    printf("a file writable by others in the user's folder: refused:\n");
    plant(dir, sizeof dir, "trust-file-mode", 0700, name, payload, payload_size, 0666);
    use_dir(dir);
    expect_refused(cube, genuine, out);

    if (geteuid() == 0) {
        printf("a folder, and a file, of another user (uid 65534): refused:\n");
        plant(dir, sizeof dir, "trust-other-folder", 0700, name, payload, payload_size, 0600);
        CHECK(chown(dir, 65534, 65534) == 0);
        use_dir(dir);
        expect_refused(cube, genuine, out);
        plant(dir, sizeof dir, "trust-other-file", 0700, name, payload, payload_size, 0600);
        snprintf(path, sizeof path, "%s/%s", dir, name);
        CHECK(chown(path, 65534, 65534) == 0);
        use_dir(dir);
        expect_refused(cube, genuine, out);
    } else {
        printf("(not root: another user's folder and file are not tried)\n");
    }

    printf("the default folders: a home chain with a folder writable by others: refused:\n");
    char home[512], sub[700];
    make_dir(home, sizeof home, "trust-home");
    snprintf(sub, sizeof sub, "%s/.cache", home);
    CHECK(mkdir(sub, 0700) == 0);
    snprintf(sub, sizeof sub, "%s/.cache/rsmooth", home);
    CHECK(mkdir(sub, 0700) == 0);
    snprintf(path, sizeof path, "%s/%s", sub, name);
    write_whole(path, payload, payload_size, 0600);
    CHECK(setenv("HOME", home, 1) == 0);
    CHECK(unsetenv("RSMOOTH_CACHE_DIR") == 0 && unsetenv("XDG_CACHE_HOME") == 0);
    ctx = create("hit"); /* all the user's own: the payload is loaded (control) */
    rsmooth_context_destroy(ctx);
    snprintf(sub, sizeof sub, "%s/.cache", home);
    CHECK(chmod(sub, 0777) == 0);
    expect_refused(cube, genuine, out);
    CHECK(chmod(sub, 0700) == 0);
    snprintf(sub, sizeof sub, "%s/xdg", home); /* $XDG_CACHE_HOME below home: the same rule */
    CHECK(mkdir(sub, 0777) == 0 && chmod(sub, 0777) == 0);
    CHECK(setenv("XDG_CACHE_HOME", sub, 1) == 0);
    snprintf(sub, sizeof sub, "%s/xdg/rsmooth", home);
    CHECK(mkdir(sub, 0700) == 0);
    snprintf(path, sizeof path, "%s/%s", sub, name);
    write_whole(path, payload, payload_size, 0600);
    expect_refused(cube, genuine, out);
    CHECK(unsetenv("XDG_CACHE_HOME") == 0 && unsetenv("HOME") == 0);

    printf("a FIFO at the key's name: not opened for long (no hang), replaced by a file:\n");
    make_dir(dir, sizeof dir, "trust-fifo");
    snprintf(path, sizeof path, "%s/%s", dir, name);
    CHECK(mkfifo(path, 0600) == 0);
    use_dir(dir);
    create_destroy("miss");
    struct stat st;
    CHECK(lstat(path, &st) == 0 && S_ISREG(st.st_mode));
    create_destroy("hit");

    printf("a symbolic link at the key's name (to the working payload): not followed:\n");
    make_dir(dir, sizeof dir, "trust-link");
    snprintf(path, sizeof path, "%s/%s", dir, name);
    CHECK(symlink(own_payload, path) == 0);
    use_dir(dir);
    ctx = create("miss");
    smooth(ctx, cube, out);
    rsmooth_context_destroy(ctx);
    CHECK(memcmp(out, genuine, n * sizeof *out) == 0);
    CHECK(lstat(path, &st) == 0 && S_ISREG(st.st_mode)); /* the store replaced the link */
    alarm(0);
    free(payload);
    free(genuine_file);
    free(modified_file);
    free(out);
    free(modified);
}

int main(int argc, char **argv) {
    if (argc == 2 && strcmp(argv[1], "child") == 0)
        return child();
    char cwd[200]; /* absolute: XDG_CACHE_HOME must be */
    CHECK(getcwd(cwd, sizeof cwd));
    snprintf(base, sizeof base, "%s/program-cache-test-XXXXXX", cwd);
    CHECK(mkdtemp(base));
    char dir[512], path[1024], sub[600];

    /* a device at all (skips without one), with the cache off */
    use_dir("off");
    rsmooth_context_destroy(open_test_context());

    printf("miss, then hit, bit for bit:\n");
    make_dir(dir, sizeof dir, "plain");
    use_dir(dir);
    shape_mesh cube;
    CHECK(shape_cube(&cube, 12, 1.0) == 0);
    CHECK(shape_add_normal_noise(&cube, 0.3, 7) == 0);
    size_t n = 3 * cube.vertex_count;
    double *miss = malloc(2 * n * sizeof *miss), *hit = malloc(2 * n * sizeof *hit);
    CHECK(miss && hit);
    rsmooth_context *ctx = create("miss");
    smooth(ctx, &cube, miss);
    rsmooth_context_destroy(ctx);
    the_file(dir, path, sizeof path);
    struct stat st;
    CHECK(stat(dir, &st) == 0);
    size_t valid_size = file_size(path);
    printf("  %s: %zu bytes\n", path, valid_size);
    ctx = create("hit");
    smooth(ctx, &cube, hit);
    rsmooth_context_destroy(ctx);
    CHECK(memcmp(miss, hit, 2 * n * sizeof *hit) == 0);
    the_file(dir, path, sizeof path);

    printf("damaged files are misses, and rewritten:\n");
    for (int kind = 0; kind < DAMAGE_COUNT; kind++) {
        printf(" %s\n", damage_names[kind]);
        damage(path, kind);
        ctx = create("miss");
        if (kind == FLIP_BINARY) { /* the source build after a bad file smooths as before */
            smooth(ctx, &cube, hit);
            CHECK(memcmp(miss, hit, 2 * n * sizeof *hit) == 0);
        }
        rsmooth_context_destroy(ctx);
        the_file(dir, path, sizeof path);
        CHECK(file_size(path) > 64); /* whole: the next context hits it */
        create_destroy("hit");
    }

    printf("a folder in the file's place: built from source, left alone:\n");
    CHECK(unlink(path) == 0);
    CHECK(mkdir(path, 0700) == 0);
    create_destroy("miss");
    create_destroy("miss");
    int files, others;
    count_files(dir, &files, &others);
    CHECK_EQ_INT(others, 0);
    CHECK(stat(path, &st) == 0 && S_ISDIR(st.st_mode));

    printf("a cache folder below a file, and a file as the folder: no cache, no error:\n");
    snprintf(path, sizeof path, "%s/a-file", base);
    FILE *f = fopen(path, "w");
    CHECK(f && fclose(f) == 0);
    snprintf(dir, sizeof dir, "%s/a-file/cache", base);
    use_dir(dir);
    create_destroy("miss");
    create_destroy("miss");
    use_dir(path);
    create_destroy("miss");
    CHECK_EQ_INT(file_size(path), 0);

    printf("missing parents are made (0700):\n");
    snprintf(dir, sizeof dir, "%s/new/deeper/cache", base);
    use_dir(dir);
    create_destroy("miss");
    create_destroy("hit");
    CHECK(stat(dir, &st) == 0 && (st.st_mode & 0777) == 0700);
    the_file(dir, path, sizeof path);

    printf("\"off\" and \"\": nothing written, even where the defaults would go:\n");
    make_dir(dir, sizeof dir, "home");
    CHECK(setenv("HOME", dir, 1) == 0);
    CHECK(setenv("XDG_CACHE_HOME", dir, 1) == 0);
    use_dir("off");
    create_destroy("off");
    use_dir("");
    create_destroy("off");
    count_files(dir, &files, &others);
    CHECK_EQ_INT(files + others, 0);

    printf("unset: $XDG_CACHE_HOME/rsmooth, else $HOME/.cache/rsmooth:\n");
    CHECK(unsetenv("RSMOOTH_CACHE_DIR") == 0);
    create_destroy("miss");
    snprintf(sub, sizeof sub, "%s/rsmooth", dir);
    the_file(sub, path, sizeof path);
    CHECK(unsetenv("XDG_CACHE_HOME") == 0);
    create_destroy("miss");
    snprintf(sub, sizeof sub, "%s/.cache/rsmooth", dir);
    the_file(sub, path, sizeof path);
    create_destroy("hit");
    CHECK(unsetenv("HOME") == 0);
    create_destroy("off");

    printf("%d processes at once on an empty folder:\n", PROCESSES);
    make_dir(dir, sizeof dir, "processes");
    use_dir(dir);
    fflush(stdout);
    pid_t pids[PROCESSES];
    for (int i = 0; i < PROCESSES; i++) {
        pids[i] = fork();
        CHECK(pids[i] >= 0);
        if (pids[i] == 0) {
            execl("/proc/self/exe", argv[0], "child", (char *)NULL);
            execl(argv[0], argv[0], "child", (char *)NULL);
            _exit(127);
        }
    }
    for (int i = 0; i < PROCESSES; i++) {
        int status = 0;
        CHECK(waitpid(pids[i], &status, 0) == pids[i]);
        CHECK(WIFEXITED(status) && WEXITSTATUS(status) == 0);
    }
    the_file(dir, path, sizeof path);
    CHECK(file_size(path) > 64); /* whole: the next context hits it */
    create_destroy("hit");

    printf("%d threads at once on an empty folder:\n", THREADS);
    make_dir(dir, sizeof dir, "threads");
    use_dir(dir);
    pthread_t threads[THREADS];
    int ok[THREADS];
    for (int i = 0; i < THREADS; i++)
        CHECK(pthread_create(&threads[i], NULL, thread_create, &ok[i]) == 0);
    for (int i = 0; i < THREADS; i++) {
        CHECK(pthread_join(threads[i], NULL) == 0);
        CHECK(ok[i]);
    }
    the_file(dir, path, sizeof path);
    CHECK(file_size(path) > 64); /* whole: the next context hits it */
    create_destroy("hit");

    trust(&cube, miss);
    free(miss);
    free(hit);
    shape_free(&cube);
    remove_tree(base);
    printf("ok\n");
    return 0;
}
