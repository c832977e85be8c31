/* rsmooth's program cache (lib/cl_program_cache.c): a miss writes one file, the next context hits
 * it and smooths bit for bit as the source build; damaged files (truncated, flipped bytes, wrong
 * magic, empty, a folder in the file's place) are misses that get rewritten; folders that cannot be
 * made or written, and "off", build from source and leave nothing; the default folders; and
 * processes and threads starting together on an empty folder all succeed and leave one whole file
 * and no temporaries. Everything happens in a fresh folder in the working directory. */
#define _POSIX_C_SOURCE 200809L
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

static char base[256]; /* this run's folder, absolute */

/* A context on the default device with the environment as it is, and where its program came from. */
static rsmooth_context *create(const char *expect) {
    rsmooth_context *ctx = NULL;
    rsmooth_error err;
    rsmooth_status st = rsmooth_context_create(NULL, &ctx, &err);
    if (st != RSMOOTH_OK) {
        fprintf(stderr, "context: %s: %s\n", rsmooth_status_str(st), err.message);
        exit(1);
    }
    const char *got = rsmooth_context_program_cache(ctx);
    printf("  program cache %s, build %.1f ms\n", got, rsmooth_context_build_ms(ctx));
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
                                m->triangle_count, &p, out, NULL, NULL, NULL, &err),
                 RSMOOTH_OK);
    p.normal_filter = RSMOOTH_NORMALS_BILATERAL;
    CHECK_STATUS(rsmooth_smooth(ctx, RSMOOTH_FLOAT64, m->xyz, m->vertex_count, m->indices,
                                m->triangle_count, &p, out + n, NULL, NULL, NULL, &err),
                 RSMOOTH_OK);
}

static size_t file_size(const char *path) {
    struct stat st;
    CHECK(stat(path, &st) == 0);
    return (size_t)st.st_size;
}

/* Damage kinds, each applied to a valid file. */
enum { TRUNCATE_HALF, TRUNCATE_HEADER, EMPTY, FLIP_BINARY, FLIP_CHECKSUM, FLIP_KEY, WRONG_MAGIC,
       LONGER, DAMAGE_COUNT };
static const char *const damage_names[DAMAGE_COUNT] = {
    "truncated to half", "truncated in the header", "empty", "a byte of the binary flipped",
    "a byte of the checksum flipped", "a byte of the key flipped", "wrong magic",
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
    case FLIP_CHECKSUM:
        flip(fd, (off_t)(size - 3));
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

    free(miss);
    free(hit);
    shape_free(&cube);
    remove_tree(base);
    printf("ok\n");
    return 0;
}
