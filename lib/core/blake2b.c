/* BLAKE2b as RFC 7693 specifies it (sections 2 and 3; no key, no salt or personalisation). */
#include "core/blake2b.h"

#include <string.h>

/* The initial values: SHA-512's (RFC 7693, 2.6). */
static const uint64_t blake2b_iv[8] = {
    0x6a09e667f3bcc908u, 0xbb67ae8584caa73bu, 0x3c6ef372fe94f82bu, 0xa54ff53a5f1d36f1u,
    0x510e527fade682d1u, 0x9b05688c2b3e6c1fu, 0x1f83d9abfb41bd6bu, 0x5be0cd19137e2179u};

/* The message schedule (RFC 7693, 2.7): rounds 10 and 11 reuse rows 0 and 1. */
static const unsigned char sigma[10][16] = {{0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15},
                                            {14, 10, 4, 8, 9, 15, 13, 6, 1, 12, 0, 2, 11, 7, 5, 3},
                                            {11, 8, 12, 0, 5, 2, 15, 13, 10, 14, 3, 6, 7, 1, 9, 4},
                                            {7, 9, 3, 1, 13, 12, 11, 14, 2, 6, 5, 10, 4, 0, 15, 8},
                                            {9, 0, 5, 7, 2, 4, 10, 15, 14, 1, 11, 12, 6, 8, 3, 13},
                                            {2, 12, 6, 10, 0, 11, 8, 3, 4, 13, 7, 5, 15, 14, 1, 9},
                                            {12, 5, 1, 15, 14, 13, 4, 10, 0, 7, 6, 3, 9, 2, 8, 11},
                                            {13, 11, 7, 14, 12, 1, 3, 9, 5, 0, 15, 4, 8, 6, 2, 10},
                                            {6, 15, 14, 9, 11, 3, 0, 8, 12, 2, 13, 7, 1, 4, 10, 5},
                                            {10, 2, 8, 4, 7, 6, 1, 5, 15, 11, 9, 14, 3, 12, 13, 0}};

static uint64_t rotr64(uint64_t x, unsigned n) {
    return (x >> n) | (x << (64 - n));
}

static uint64_t load64(const unsigned char *p) {
    uint64_t v = 0;
    for (int i = 7; i >= 0; i--)
        v = v << 8 | p[i];
    return v;
}

/* The mixing function G (RFC 7693, 3.1), rotation constants R1..R4 = 32, 24, 16, 63. */
#define G(a, b, c, d, x, y)                                                                        \
    do {                                                                                           \
        v[a] = v[a] + v[b] + (x);                                                                  \
        v[d] = rotr64(v[d] ^ v[a], 32);                                                            \
        v[c] = v[c] + v[d];                                                                        \
        v[b] = rotr64(v[b] ^ v[c], 24);                                                            \
        v[a] = v[a] + v[b] + (y);                                                                  \
        v[d] = rotr64(v[d] ^ v[a], 16);                                                            \
        v[c] = v[c] + v[d];                                                                        \
        v[b] = rotr64(v[b] ^ v[c], 63);                                                            \
    } while (0)

/* The compression function F (RFC 7693, 3.2) on the 128 bytes in s->block. */
static void compress(rs_blake2b *s, int last) {
    uint64_t v[16], m[16];
    for (int i = 0; i < 16; i++)
        m[i] = load64(s->block + 8 * i);
    for (int i = 0; i < 8; i++) {
        v[i] = s->h[i];
        v[i + 8] = blake2b_iv[i];
    }
    v[12] ^= s->t[0];
    v[13] ^= s->t[1];
    if (last)
        v[14] = ~v[14];
    for (int r = 0; r < 12; r++) {
        const unsigned char *z = sigma[r % 10];
        G(0, 4, 8, 12, m[z[0]], m[z[1]]);
        G(1, 5, 9, 13, m[z[2]], m[z[3]]);
        G(2, 6, 10, 14, m[z[4]], m[z[5]]);
        G(3, 7, 11, 15, m[z[6]], m[z[7]]);
        G(0, 5, 10, 15, m[z[8]], m[z[9]]);
        G(1, 6, 11, 12, m[z[10]], m[z[11]]);
        G(2, 7, 8, 13, m[z[12]], m[z[13]]);
        G(3, 4, 9, 14, m[z[14]], m[z[15]]);
    }
    for (int i = 0; i < 8; i++)
        s->h[i] ^= v[i] ^ v[i + 8];
}

static void count_bytes(rs_blake2b *s, size_t n) {
    s->t[0] += n;
    if (s->t[0] < n)
        s->t[1]++;
}

int rs_blake2b_init(rs_blake2b *s, size_t digest_size) {
    if (digest_size < 1 || digest_size > RS_BLAKE2B_MAX_DIGEST)
        return 0;
    memset(s, 0, sizeof *s);
    memcpy(s->h, blake2b_iv, sizeof s->h);
    s->h[0] ^= 0x01010000u ^ (uint64_t)digest_size; /* depth 1, fanout 1, no key */
    s->digest_size = digest_size;
    return 1;
}

void rs_blake2b_update(rs_blake2b *s, const void *data, size_t size) {
    const unsigned char *in = data;
    while (size > 0) {
        /* a full block is compressed only once more input follows: the last one is final's */
        if (s->filled == RS_BLAKE2B_BLOCK) {
            count_bytes(s, RS_BLAKE2B_BLOCK);
            compress(s, 0);
            s->filled = 0;
        }
        size_t take = RS_BLAKE2B_BLOCK - s->filled;
        if (take > size)
            take = size;
        memcpy(s->block + s->filled, in, take);
        s->filled += take;
        in += take;
        size -= take;
    }
}

void rs_blake2b_final(rs_blake2b *s, unsigned char *out) {
    count_bytes(s, s->filled);
    memset(s->block + s->filled, 0, RS_BLAKE2B_BLOCK - s->filled);
    compress(s, 1);
    for (size_t i = 0; i < s->digest_size; i++)
        out[i] = (unsigned char)(s->h[i / 8] >> (8 * (i % 8)));
}
