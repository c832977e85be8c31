/* rsmooth's own cache of built OpenCL programs: the binary of a program built from source is kept
 * on disk under a key over the device, its driver and platform, and the complete source and build
 * options; a later context with the same key builds from that binary instead (about 5 ms with
 * PoCL, where a source build costs 30-40 ms even when PoCL's own cache has the kernels). Any
 * doubt about a file (size, magic, key, checksum, a failed build from it) is a miss, never an
 * error, and a directory that cannot be written only means building from source every time.
 *
 * A file is a 72-byte header of nine little-endian 64-bit words, the binary, and its checksum:
 *   magic "RSPRGBIN", format version, key hash (2 words), key bytes, key fields, 0 (reserved),
 *   binary size, 0 (reserved); the binary; its checksum (2 words, the key's two hashes).
 * The file's name is the key hash in hex; the words inside catch a collision of the name, and
 * the size and checksum a truncated or damaged file.
 * Writers write a temporary file beside the final one and rename it over it, so readers see a
 * whole file or none, and concurrent writers of one key leave one of their (equal) files. */
#define _POSIX_C_SOURCE 200809L
#include "cl_internal.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define FORMAT_VERSION 1
#define HEADER_WORDS 9
#define HEADER_BYTES (HEADER_WORDS * 8)
#define TRAILER_BYTES 16
/* A program binary larger than this is not cached (PoCL's are a few hundred KiB). */
#define MAX_BINARY_BYTES ((uint64_t)256 << 20)
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

/* Two independent 64-bit hashes over the same bytes (multiply-xorshift steps with different
 * constants over little-endian 64-bit words, then the bytes left), and how many bytes and fields
 * went in: a chance collision of all four is out of reach. Words, not bytes: the checksum of a
 * 500 KiB binary costs about 0.1 ms. */
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

/* One field of the key, its length first, so that no two sequences of fields hash the same bytes. */
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

/* The directory: RSMOOTH_CACHE_DIR (empty or "off": no cache), else $XDG_CACHE_HOME/rsmooth, else
 * $HOME/.cache/rsmooth. false when there is none, or its path does not fit. */
static bool cache_dir(char *dir, size_t size) {
    const char *env = getenv("RSMOOTH_CACHE_DIR");
    int n;
    if (env) {
        if (!*env || strcmp(env, "off") == 0)
            return false;
        n = snprintf(dir, size, "%s", env);
    } else if ((env = getenv("XDG_CACHE_HOME")) && env[0] == '/') { /* relative: ignored (spec) */
        n = snprintf(dir, size, "%s/rsmooth", env);
    } else if ((env = getenv("HOME")) && *env) {
        n = snprintf(dir, size, "%s/.cache/rsmooth", env);
    } else {
        return false;
    }
    return n > 0 && (size_t)n < size;
}

/* mkdir -p with mode 0700 for what it creates; true when `dir` is then a directory. */
static bool make_dirs(char *dir) {
    struct stat st;
    if (stat(dir, &st) == 0)
        return S_ISDIR(st.st_mode);
    for (char *p = dir + 1; *p; p++) {
        if (*p != '/')
            continue;
        *p = '\0';
        int r = mkdir(dir, 0700);
        *p = '/';
        if (r != 0 && errno != EEXIST)
            return false;
    }
    if (mkdir(dir, 0700) != 0 && errno != EEXIST)
        return false;
    return stat(dir, &st) == 0 && S_ISDIR(st.st_mode);
}

bool rs_program_cache_open(rs_program_cache *cache, const rsmooth_context *ctx, cl_uint count,
                           const char *const *sources, const size_t *sizes, const char *options) {
    memset(cache, 0, sizeof *cache);
    char dir[sizeof cache->path - 64];
    if (!cache_dir(dir, sizeof dir))
        return false;
    hash2 h;
    hash_init(&h);
    static const char format[] = "rsmooth program cache 1";
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
    int n = snprintf(cache->path, sizeof cache->path, "%s/%016llx%016llx.clbin", dir,
                     (unsigned long long)h.a, (unsigned long long)h.b);
    return n > 0 && (size_t)n < sizeof cache->path;
}

/* The binary of a valid file for the key (to rs_free), or NULL. */
static unsigned char *read_binary(const rs_program_cache *cache, size_t *size) {
    int fd = open(cache->path, O_RDONLY);
    if (fd < 0)
        return NULL;
    unsigned char *data = NULL, header[HEADER_BYTES];
    struct stat st;
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode) || read(fd, header, sizeof header) !=
                                                               (ssize_t)sizeof header)
        goto fail;
    uint64_t binary_size = get_u64(header + 56);
    if (memcmp(header, magic, 8) != 0 || get_u64(header + 8) != FORMAT_VERSION ||
        get_u64(header + 16) != cache->key[0] || get_u64(header + 24) != cache->key[1] ||
        get_u64(header + 32) != cache->key_bytes || get_u64(header + 40) != cache->key_fields ||
        binary_size == 0 || binary_size > MAX_BINARY_BYTES ||
        (uint64_t)st.st_size != HEADER_BYTES + binary_size + TRAILER_BYTES)
        goto fail;
    data = rs_alloc_array(binary_size + TRAILER_BYTES, 1);
    if (!data)
        goto fail;
    size_t done = 0, want = binary_size + TRAILER_BYTES;
    while (done < want) {
        ssize_t r = read(fd, data + done, want - done);
        if (r <= 0)
            goto fail;
        done += (size_t)r;
    }
    hash2 check;
    hash_init(&check);
    hash_bytes(&check, data, binary_size);
    if (get_u64(data + binary_size) != check.a || get_u64(data + binary_size + 8) != check.b)
        goto fail;
    close(fd);
    *size = binary_size;
    return data;
fail:
    rs_free(data);
    close(fd);
    return NULL;
}

cl_program rs_program_cache_load(const rs_program_cache *cache, const rsmooth_context *ctx,
                                 const char *options) {
    if (!cache->path[0])
        return NULL;
    size_t size = 0;
    unsigned char *binary = read_binary(cache, &size);
    if (!binary)
        return NULL;
    const unsigned char *binaries[1] = {binary};
    cl_int status = CL_SUCCESS, err = CL_SUCCESS;
    cl_program program = clCreateProgramWithBinary(ctx->context, 1, &ctx->device, &size, binaries,
                                                   &status, &err);
    rs_free(binary);
    if (err != CL_SUCCESS || status != CL_SUCCESS || !program ||
        clBuildProgram(program, 1, &ctx->device, options, NULL, NULL) != CL_SUCCESS) {
        if (program)
            clReleaseProgram(program);
        return NULL;
    }
    return program;
}

/* Writes all of `n` bytes; false on any failure. */
static bool write_all(int fd, const unsigned char *data, size_t n) {
    while (n > 0) {
        ssize_t w = write(fd, data, n);
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0)
            return false;
        data += w;
        n -= (size_t)w;
    }
    return true;
}

/* The binary of `program` for ctx's device (to rs_free), or NULL. */
static unsigned char *program_binary(const rsmooth_context *ctx, cl_program program,
                                     size_t *size) {
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

void rs_program_cache_store(const rs_program_cache *cache, const rsmooth_context *ctx,
                            cl_program program) {
    if (!cache->path[0])
        return;
    size_t size = 0;
    unsigned char *binary = program_binary(ctx, program, &size);
    if (!binary)
        return;
    char dir[sizeof cache->path], temp[sizeof cache->path + 8];
    snprintf(dir, sizeof dir, "%s", cache->path);
    char *slash = strrchr(dir, '/');
    if (slash && slash != dir)
        *slash = '\0';
    int fd = -1;
    bool ok = (!slash || slash == dir || make_dirs(dir)) &&
              snprintf(temp, sizeof temp, "%s.XXXXXX", cache->path) < (int)sizeof temp &&
              (fd = mkstemp(temp)) >= 0;
    if (ok) {
        unsigned char header[HEADER_BYTES], trailer[TRAILER_BYTES];
        const uint64_t words[HEADER_WORDS] = {0, FORMAT_VERSION, cache->key[0], cache->key[1],
                                              cache->key_bytes, cache->key_fields, 0, size, 0};
        memcpy(header, magic, 8);
        for (int i = 1; i < HEADER_WORDS; i++)
            put_u64(header + 8 * i, words[i]);
        hash2 check;
        hash_init(&check);
        hash_bytes(&check, binary, size);
        put_u64(trailer, check.a);
        put_u64(trailer + 8, check.b);
        ok = write_all(fd, header, sizeof header) && write_all(fd, binary, size) &&
             write_all(fd, trailer, sizeof trailer);
        ok = close(fd) == 0 && ok;
        /* rename replaces the final name at once: readers see the old file or the new one */
        if (!ok || rename(temp, cache->path) != 0)
            unlink(temp);
    }
    rs_free(binary);
}

const char *rsmooth_context_program_cache(const rsmooth_context *ctx) {
    if (!ctx)
        return "";
    return ctx->program_cache == RS_PROGRAM_CACHE_HIT    ? "hit"
           : ctx->program_cache == RS_PROGRAM_CACHE_MISS ? "miss"
                                                         : "off";
}
