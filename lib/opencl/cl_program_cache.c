/* rsmooth's own cache of built OpenCL programs: the binary of a program built from source is kept
 * on disk under a key over the device, its driver and platform, and the complete source and build
 * options; a later context with the same key builds from that binary instead (about 5 ms with
 * PoCL, where a source build costs 30-40 ms even when PoCL's own cache has the kernels).
 *
 * A program binary is native code the OpenCL runtime loads and runs, so a cache file is trusted
 * only as far as its folder is: a file is used only when it, its folder and every folder between
 * the user's home and it (or the folder RSMOOTH_CACHE_DIR names, alone) belong to the effective
 * user and are writable by nobody else. Anything else is refused (the reason is the context's
 * program_cache_note: the library prints nothing),
 * and the program built from source. Folders are walked by descriptor with O_NOFOLLOW below the
 * starting folder, and each checked with fstat on what was opened, so no link or rename between
 * check and use can swap in another file. The file is opened O_NOFOLLOW | O_NONBLOCK (a FIFO or
 * device cannot block), must be a regular file of bounded size, and its whole content must match
 * the BLAKE2b digest in its header; any other doubt (missing, truncated, corrupt, another key, a
 * build that fails) is a miss, built from source and the file replaced. A folder that cannot be
 * written only means building from source every time.
 *
 * A file is a 96-byte header of eight little-endian 64-bit words and the digest, then the binary:
 *   magic "RSPRGBIN", format version, key hash (2 words), key bytes, key fields, binary size,
 *   0 (reserved); BLAKE2b-256 of those 64 bytes and the binary.
 * The file's name is the key hash in hex; the words inside catch a collision of the name.
 * Writers write a temporary file beside the final one and rename it over it, so readers see a
 * whole file or none, and concurrent writers of one key leave one of their (equal) files. */
#define _POSIX_C_SOURCE 200809L
#include "core/blake2b.h"
#include "opencl/cl_internal.h"

#include <errno.h>
#include <fcntl.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#ifndef O_CLOEXEC
#define O_CLOEXEC 0
#endif

#define FORMAT_VERSION 2
#define HEADER_WORDS 8
#define DIGEST_BYTES 32
#define HEADER_BYTES (HEADER_WORDS * 8 + DIGEST_BYTES)
/* A program binary larger than this is not cached (PoCL's are a few hundred KiB): the most a
 * cache file makes the library read. */
#define MAX_BINARY_BYTES ((uint64_t)64 << 20)
static const char magic[8] = {'R', 'S', 'P', 'R', 'G', 'B', 'I', 'N'};

static void put_u64(unsigned char *out, uint64_t v) {
    for (int i = 0; i < 8; i++)
        out[i] = (unsigned char)(v >> (8 * i));
}

static uint64_t get_u64(const unsigned char *in) {
    uint64_t v = 0;
    for (int i = 7; i >= 0; i--)
        v = v << 8 | in[i];
    return v;
}

/* ---- the key -------------------------------------------------------------------------------- */

/* Two independent 64-bit hashes over the same bytes (multiply-xorshift steps with different
 * constants over little-endian 64-bit words, then the bytes left), and how many bytes and fields
 * went in: the file's name and the words that must match it. Not a defence (the ownership checks
 * and the digest are): only a name that no two keys share by chance. */
typedef struct hash2 {
    uint64_t a, b, bytes, fields;
} hash2;

static void hash_init(hash2 *h) {
    h->a = 0xcbf29ce484222325u;
    h->b = 0x9e3779b97f4a7c15u;
    h->bytes = h->fields = 0;
}

static void hash_bytes(hash2 *h, const void *data, size_t n) {
    const unsigned char *p = data;
    uint64_t a = h->a, b = h->b;
    size_t i = 0;
    for (; i + 8 <= n; i += 8) {
        uint64_t w = get_u64(p + i);
        a = (a ^ w) * 0x100000001b3u; /* FNV's prime */
        a ^= a >> 29;
        b = (b ^ w) * 0xbf58476d1ce4e5b9u; /* splitmix64's */
        b ^= b >> 31;
    }
    for (; i < n; i++) {
        a = (a ^ p[i]) * 0x100000001b3u;
        a ^= a >> 29;
        b = (b ^ p[i]) * 0xbf58476d1ce4e5b9u;
        b ^= b >> 31;
    }
    h->a = a;
    h->b = b;
    h->bytes += n;
}

/* One field of the key, its length first, so that no two sequences of fields hash the same bytes.
 */
static void hash_field(hash2 *h, const void *data, size_t n) {
    unsigned char length[8];
    put_u64(length, n);
    hash_bytes(h, length, sizeof length);
    hash_bytes(h, data, n);
    h->fields++;
}

/* A string property of the device (platform NULL) or of the platform, into the key; a property
 * that cannot be read goes in as a failure marker (the key then still differs from a readable
 * one). */
static void hash_info(hash2 *h, cl_platform_id platform, cl_device_id device, cl_uint param) {
    size_t need = 0;
    cl_int err = platform ? clGetPlatformInfo(platform, param, 0, NULL, &need)
                          : clGetDeviceInfo(device, param, 0, NULL, &need);
    char *text = err == CL_SUCCESS && need ? rs_alloc_array(need, 1) : NULL;
    if (text && (platform ? clGetPlatformInfo(platform, param, need, text, NULL)
                          : clGetDeviceInfo(device, param, need, text, NULL)) == CL_SUCCESS)
        hash_field(h, text, strnlen(text, need));
    else
        hash_field(h, "?", 1);
    rs_free(text);
}

/* ---- where the cache is, and whether it can be trusted --------------------------------------- */

/* The folder to start from (`top`, opened following links: the user named it) and the folders
 * below it down to the cache (`below`, "a/b" or ""), each of which must be the user's own:
 * RSMOOTH_CACHE_DIR (empty or "off": no cache) alone; else $XDG_CACHE_HOME/rsmooth, from the home
 * folder when it lies below it; else $HOME/.cache/rsmooth from $HOME. false when there is none, or
 * its path does not fit. */
static bool cache_location(rs_program_cache *cache, const rs_environment *environment) {
    const char *env = environment->value[RS_ENV_CACHE_DIR], *home = environment->value[RS_ENV_HOME];
    int n, m = 0;
    size_t home_length = home ? strlen(home) : 0;
    while (home_length > 1 && home[home_length - 1] == '/')
        home_length--;
    if (env) {
        if (!*env || strcmp(env, "off") == 0)
            return false;
        n = snprintf(cache->top, sizeof cache->top, "%s", env);
    } else if ((env = environment->value[RS_ENV_XDG_CACHE_HOME]) &&
               env[0] == '/') { /* relative: ignored (spec) */
        if (home && home[0] == '/' && home_length > 1 && strncmp(env, home, home_length) == 0 &&
            env[home_length] == '/') {
            n = snprintf(cache->top, sizeof cache->top, "%.*s", (int)home_length, home);
            m = snprintf(cache->below, sizeof cache->below, "%s/rsmooth", env + home_length + 1);
        } else {
            n = snprintf(cache->top, sizeof cache->top, "%s/rsmooth", env);
        }
    } else if (home && *home) {
        n = snprintf(cache->top, sizeof cache->top, "%s", home);
        m = snprintf(cache->below, sizeof cache->below, ".cache/rsmooth");
    } else {
        return false;
    }
    return n > 0 && (size_t)n < sizeof cache->top && m >= 0 && (size_t)m < sizeof cache->below;
}

/* Why a folder or file someone else could have written is not to be used, or NULL when it is the
 * effective user's own and writable by nobody else. */
static const char *untrusted(const struct stat *st) {
    if (st->st_uid != geteuid())
        return "belongs to another user";
    if (st->st_mode & (S_IWGRP | S_IWOTH))
        return "is writable by other users";
    return NULL;
}

/* Says why `what` was refused into note[size] (NULL: nowhere), for the context's
 * program_cache_note. */
static void say_refusal(char *note, size_t size, const char *what, const char *why,
                        const struct stat *st) {
    if (note)
        snprintf(note, size,
                 "not using the program cache: %.300s %s (owner uid %ld, mode %04o; you are uid "
                 "%ld): the OpenCL program is built from source instead. Use a folder of your own "
                 "(RSMOOTH_CACHE_DIR) or turn the cache off (RSMOOTH_CACHE_DIR=off)",
                 what, why, (long)st->st_uid, (unsigned)(st->st_mode & 07777), (long)geteuid());
}

enum { WALK_OK, WALK_MISSING, WALK_REFUSED, WALK_FAILED };

/* Opens the cache folder by descriptor into *dir_fd: `top` following links, then each folder of
 * `below` with O_NOFOLLOW, creating missing ones (0700) when `create`; each checked to be the
 * user's own where the rules above ask it. WALK_REFUSED has been said in note[size] (NULL: not
 * said). */
static int open_cache_dir(const rs_program_cache *cache, bool create, int *dir_fd, char *note,
                          size_t size) {
    *dir_fd = -1;
    struct stat st;
    if (create && !cache->below[0] && stat(cache->top, &st) != 0 && errno == ENOENT) {
        /* RSMOOTH_CACHE_DIR or $XDG_CACHE_HOME/rsmooth made with its missing parents, all 0700 */
        char path[sizeof cache->top];
        snprintf(path, sizeof path, "%s", cache->top);
        for (char *p = path + 1; *p; p++)
            if (*p == '/') {
                *p = '\0';
                if (mkdir(path, 0700) != 0 && errno != EEXIST)
                    return WALK_FAILED;
                *p = '/';
            }
        if (mkdir(path, 0700) != 0 && errno != EEXIST)
            return WALK_FAILED;
    }
    int fd = open(cache->top, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0)
        return errno == ENOENT ? WALK_MISSING : WALK_FAILED;
    if (!cache->below[0]) { /* the named folder itself must be the user's */
        const char *why = fstat(fd, &st) == 0 ? untrusted(&st) : "cannot be examined";
        if (why) {
            say_refusal(note, size, cache->top, why, &st);
            close(fd);
            return WALK_REFUSED;
        }
    }
    char below[sizeof cache->below], path[sizeof cache->top + sizeof cache->below];
    snprintf(below, sizeof below, "%s", cache->below);
    snprintf(path, sizeof path, "%s", cache->top);
    for (char *name = below, *next; name && *name; name = next) {
        next = strchr(name, '/');
        if (next)
            *next++ = '\0';
        if (!*name)
            continue;
        size_t used = strlen(path);
        snprintf(path + used, sizeof path - used, "/%s", name);
        const int flags = O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC;
        int sub = openat(fd, name, flags);
        if (sub < 0 && errno == ENOENT && create &&
            (mkdirat(fd, name, 0700) == 0 || errno == EEXIST))
            sub = openat(fd, name, flags);
        int open_errno = errno;
        close(fd);
        if (sub < 0)
            return open_errno == ENOENT ? WALK_MISSING : WALK_FAILED;
        fd = sub;
        const char *why = fstat(fd, &st) == 0 ? untrusted(&st) : "cannot be examined";
        if (why) {
            say_refusal(note, size, path, why, &st);
            close(fd);
            return WALK_REFUSED;
        }
    }
    *dir_fd = fd;
    return WALK_OK;
}

bool rs_program_cache_open(rs_program_cache *cache, const rsmooth_context *ctx, cl_uint count,
                           const char *const *sources, const size_t *sizes, const char *options) {
    memset(cache, 0, sizeof *cache);
    if (!cache_location(cache, &ctx->env))
        return false;
    hash2 h;
    hash_init(&h);
    static const char format[] = "rsmooth program cache 2";
    hash_field(&h, format, sizeof format - 1);
    cl_platform_id platform = NULL;
    if (clGetDeviceInfo(ctx->device, CL_DEVICE_PLATFORM, sizeof platform, &platform, NULL) !=
            CL_SUCCESS ||
        !platform)
        return false;
    hash_info(&h, platform, NULL, CL_PLATFORM_NAME);
    hash_info(&h, platform, NULL, CL_PLATFORM_VERSION);
    hash_info(&h, NULL, ctx->device, CL_DEVICE_NAME);
    hash_info(&h, NULL, ctx->device, CL_DEVICE_VENDOR);
    hash_info(&h, NULL, ctx->device, CL_DRIVER_VERSION);
    hash_info(&h, NULL, ctx->device, CL_DEVICE_VERSION);
    for (cl_uint i = 0; i < count; i++) /* a size of 0 means a terminated string (OpenCL) */
        hash_field(&h, sources[i], sizes && sizes[i] ? sizes[i] : strlen(sources[i]));
    hash_field(&h, options, strlen(options));
    cache->key[0] = h.a;
    cache->key[1] = h.b;
    cache->key_bytes = h.bytes;
    cache->key_fields = h.fields;
    snprintf(cache->name, sizeof cache->name, "%016llx%016llx.clbin", (unsigned long long)h.a,
             (unsigned long long)h.b);
    cache->enabled = true;
    return true;
}

/* ---- reading ------------------------------------------------------------------------------- */

/* The header's first 64 bytes for this key and binary size. */
static void header_words(const rs_program_cache *cache, uint64_t binary_size,
                         unsigned char *header) {
    const uint64_t words[HEADER_WORDS] = {0,
                                          FORMAT_VERSION,
                                          cache->key[0],
                                          cache->key[1],
                                          cache->key_bytes,
                                          cache->key_fields,
                                          binary_size,
                                          0};
    memcpy(header, magic, 8);
    for (int i = 1; i < HEADER_WORDS; i++)
        put_u64(header + 8 * i, words[i]);
}

static void digest_of(const unsigned char *header, const unsigned char *binary, size_t size,
                      unsigned char *digest) {
    rs_blake2b s;
    rs_blake2b_init(&s, DIGEST_BYTES);
    rs_blake2b_update(&s, header, HEADER_WORDS * 8);
    rs_blake2b_update(&s, binary, size);
    rs_blake2b_final(&s, digest);
}

/* The binary of a valid file for the key (to rs_free), or NULL; *refused when the file (or its
 * folder) was refused as untrusted rather than missing or invalid. */
static unsigned char *read_binary(rs_program_cache *cache, size_t *size, bool *refused) {
    int dir_fd;
    int walk = open_cache_dir(cache, false, &dir_fd, cache->note, sizeof cache->note);
    *refused = walk == WALK_REFUSED;
    if (walk != WALK_OK)
        return NULL;
    int fd = openat(dir_fd, cache->name, O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
    close(dir_fd);
    if (fd < 0)
        return NULL;
    unsigned char *data = NULL, header[HEADER_BYTES], expected[HEADER_WORDS * 8];
    unsigned char digest[DIGEST_BYTES];
    struct stat st;
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode))
        goto fail; /* a FIFO, device or folder at the name: a miss, replaced by the store */
    const char *why = untrusted(&st);
    if (why) {
        char what[sizeof cache->top + sizeof cache->below + sizeof cache->name + 2];
        snprintf(what, sizeof what, "%s%s%s/%s", cache->top, cache->below[0] ? "/" : "",
                 cache->below, cache->name);
        say_refusal(cache->note, sizeof cache->note, what, why, &st);
        *refused = true;
        goto fail;
    }
    if (st.st_size < HEADER_BYTES || (uint64_t)st.st_size > HEADER_BYTES + MAX_BINARY_BYTES ||
        !rs_pread_all(fd, header, sizeof header, 0))
        goto fail;
    uint64_t binary_size = (uint64_t)st.st_size - HEADER_BYTES;
    header_words(cache, binary_size, expected);
    if (binary_size == 0 || memcmp(header, expected, sizeof expected) != 0)
        goto fail;
    data = rs_alloc_array((size_t)binary_size, 1);
    if (!data || !rs_pread_all(fd, data, (size_t)binary_size, HEADER_BYTES))
        goto fail;
    digest_of(header, data, (size_t)binary_size, digest);
    if (memcmp(digest, header + HEADER_WORDS * 8, DIGEST_BYTES) != 0)
        goto fail;
    close(fd);
    *size = (size_t)binary_size;
    return data;
fail:
    rs_free(data);
    close(fd);
    return NULL;
}

cl_program rs_program_cache_load(rs_program_cache *cache, const rsmooth_context *ctx,
                                 const char *options) {
    if (!cache->enabled)
        return NULL;
    size_t size = 0;
    unsigned char *binary = read_binary(cache, &size, &cache->refused);
    if (!binary)
        return NULL;
    const unsigned char *binaries[1] = {binary};
    cl_int status = CL_SUCCESS, err = CL_SUCCESS;
    cl_program program =
        clCreateProgramWithBinary(ctx->context, 1, &ctx->device, &size, binaries, &status, &err);
    rs_free(binary);
    if (err != CL_SUCCESS || status != CL_SUCCESS || !program ||
        clBuildProgram(program, 1, &ctx->device, options, NULL, NULL) != CL_SUCCESS) {
        if (program)
            clReleaseProgram(program);
        return NULL;
    }
    return program;
}

/* ---- writing ------------------------------------------------------------------------------- */

/* The binary of `program` for ctx's device (to rs_free), or NULL. */
static unsigned char *program_binary(const rsmooth_context *ctx, cl_program program, size_t *size) {
    cl_uint device_count = 0;
    if (clGetProgramInfo(program, CL_PROGRAM_NUM_DEVICES, sizeof device_count, &device_count,
                         NULL) != CL_SUCCESS ||
        device_count == 0 || device_count > 64)
        return NULL;
    cl_device_id devices[64];
    size_t sizes[64];
    unsigned char *binaries[64] = {NULL};
    if (clGetProgramInfo(program, CL_PROGRAM_DEVICES, device_count * sizeof *devices, devices,
                         NULL) != CL_SUCCESS ||
        clGetProgramInfo(program, CL_PROGRAM_BINARY_SIZES, device_count * sizeof *sizes, sizes,
                         NULL) != CL_SUCCESS)
        return NULL;
    cl_uint mine = device_count;
    for (cl_uint i = 0; i < device_count; i++)
        if (devices[i] == ctx->device)
            mine = i;
    if (mine == device_count || sizes[mine] == 0 || sizes[mine] > MAX_BINARY_BYTES)
        return NULL;
    /* OpenCL 1.2 asks for a buffer per device: the others' are fetched and dropped */
    bool ok = true;
    for (cl_uint i = 0; i < device_count && ok; i++)
        ok = (binaries[i] = rs_alloc_array(sizes[i] ? sizes[i] : 1, 1)) != NULL;
    ok = ok && clGetProgramInfo(program, CL_PROGRAM_BINARIES, device_count * sizeof *binaries,
                                binaries, NULL) == CL_SUCCESS;
    unsigned char *result = ok ? binaries[mine] : NULL;
    for (cl_uint i = 0; i < device_count; i++)
        if (binaries[i] != result)
            rs_free(binaries[i]);
    *size = sizes[mine];
    return result;
}

/* A new file "<name>.<random>" in the folder, created exclusively, mode 0600; -1 on failure. */
static int create_temporary(int dir_fd, const char *name, char *temporary, size_t size) {
    static _Atomic uint64_t counter;
    uint64_t state = (uint64_t)time(NULL) ^ ((uint64_t)getpid() << 20) ^
                     (uint64_t)(uintptr_t)&state ^ (atomic_fetch_add(&counter, 1) << 40);
    for (int attempt = 0; attempt < 100; attempt++) {
        state = state * 6364136223846793005u + 1442695040888963407u;
        snprintf(temporary, size, "%s.%08llx", name, (unsigned long long)(state >> 32));
        int fd =
            openat(dir_fd, temporary, O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600);
        if (fd >= 0 || errno != EEXIST)
            return fd;
    }
    return -1;
}

void rs_program_cache_store(const rs_program_cache *cache, const rsmooth_context *ctx,
                            cl_program program) {
    if (!cache->enabled || cache->refused)
        return;
    size_t size = 0;
    unsigned char *binary = program_binary(ctx, program, &size);
    if (!binary)
        return;
    int dir_fd = -1;
    if (open_cache_dir(cache, true, &dir_fd, NULL, 0) == WALK_OK) {
        unsigned char header[HEADER_BYTES];
        header_words(cache, size, header);
        digest_of(header, binary, size, header + HEADER_WORDS * 8);
        char temporary[sizeof cache->name + 16];
        int fd = create_temporary(dir_fd, cache->name, temporary, sizeof temporary);
        if (fd >= 0) {
            bool ok = rs_pwrite_all(fd, header, sizeof header, 0) &&
                      rs_pwrite_all(fd, binary, size, sizeof header);
            ok = close(fd) == 0 && ok;
            /* rename replaces the final name at once: readers see the old file or the new one */
            if (!ok || renameat(dir_fd, temporary, dir_fd, cache->name) != 0)
                unlinkat(dir_fd, temporary, 0);
        }
        close(dir_fd);
    }
    rs_free(binary);
}

const char *rs_program_cache_name(int state) {
    return state == RS_PROGRAM_CACHE_HIT       ? "hit"
           : state == RS_PROGRAM_CACHE_MISS    ? "miss"
           : state == RS_PROGRAM_CACHE_REFUSED ? "refused"
                                               : "off";
}
