/* The program cache's digest (lib/core/blake2b.c) against independent values: RFC 7693 Appendix A's
 * BLAKE2b-512 of "abc", and BLAKE2b-256 of bytes (7i + 3) mod 256 as coreutils' `b2sum -l 256`
 * prints them, at lengths around the 128-byte block; fed whole and in uneven pieces. */
#include "core/blake2b.h"
#include "test_util.h"

#include <stdio.h>
#include <string.h>

static void hex(const unsigned char *d, size_t n, char *out) {
    for (size_t i = 0; i < n; i++)
        sprintf(out + 2 * i, "%02x", d[i]);
}

/* The digest of `data` fed in pieces of `piece` bytes (0: whole), as hex. */
static void digest(const unsigned char *data, size_t size, size_t bytes, size_t piece, char *out) {
    rs_blake2b s;
    CHECK(rs_blake2b_init(&s, bytes));
    size_t step = piece ? piece : (size ? size : 1);
    for (size_t at = 0; at < size; at += step)
        rs_blake2b_update(&s, data + at, size - at < step ? size - at : step);
    unsigned char d[64];
    rs_blake2b_final(&s, d);
    hex(d, bytes, out);
}

int main(void) {
    char got[129];
    digest((const unsigned char *)"abc", 3, 64, 0, got);
    CHECK(strcmp(got, "ba80a53f981c4d0d6a2797b69f12f6e94c212f14685ac4b74b12bb6fdbffa2d1"
                      "7d87c5392aab792dc252d5de4533cc9518d38aa8dbf1925ab92386edd4009923") == 0);
    static const struct {
        size_t size;
        const char *b2sum;
    } cases[] = {{0, "0e5751c026e543b2e8ab2eb06099daa1d1e5df47778f7787faab45cdf12fe3a8"},
                 {3, "9facd640130c81e7f318a8d5c660bc1b0f5d03861ffbd4cc1358e0e904593c28"},
                 {128, "f0501d06597880592bc49234eef100ec1ff349058d0e9d9b753504e24af86dd6"},
                 {129, "a34a4e1e03c541dfbf3099c4b6c143c022ced65c28bd7e8a10e0a098461aecf0"},
                 {1000, "d62b6c768ce1afc8367e0498ab2f8e3f7c178c35b1429f14c4604b545d200f52"}};
    unsigned char data[1000];
    for (size_t i = 0; i < sizeof data; i++)
        data[i] = (unsigned char)(7 * i + 3);
    for (size_t c = 0; c < sizeof cases / sizeof *cases; c++)
        for (size_t piece = 0; piece <= 129; piece += 43) {
            digest(data, cases[c].size, 32, piece, got);
            if (strcmp(got, cases[c].b2sum) != 0) {
                fprintf(stderr, "%zu bytes in pieces of %zu: %s, b2sum says %s\n", cases[c].size,
                        piece, got, cases[c].b2sum);
                return 1;
            }
        }
    rs_blake2b s;
    CHECK(!rs_blake2b_init(&s, 0) && !rs_blake2b_init(&s, 65));
    printf("ok\n");
    return 0;
}
