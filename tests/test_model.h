/* A learned model's bytes for the tests (lib/learned/model_file.c reads them: a header, the
 * stages' layers, a BLAKE2b-256 of every byte before it), with random weights, so that tests do
 * not lean on the shipped model. Needs lib/ on the include path and core/blake2b.c linked. */
#ifndef RSMOOTH_TEST_MODEL_H
#define RSMOOTH_TEST_MODEL_H

#include "core/blake2b.h"
#include "test_util.h"

#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* The descriptor layout the library reads (learned/learned.h: RS_LEARNED_LAYOUT, ...). */
#define MODEL_LAYOUT 1
#define MODEL_NEIGHBOURS 32
#define MODEL_INPUTS 240

typedef struct model_bytes {
    unsigned char *at;
    size_t size, capacity;
} model_bytes;

static inline void model_put(model_bytes *b, const void *data, size_t size) {
    if (b->size + size > b->capacity) {
        b->capacity = 2 * (b->size + size);
        b->at = realloc(b->at, b->capacity);
        CHECK(b->at);
    }
    memcpy(b->at + b->size, data, size);
    b->size += size;
}

static inline void model_put_u32(model_bytes *b, uint32_t v) {
    unsigned char le[4] = {(unsigned char)v, (unsigned char)(v >> 8), (unsigned char)(v >> 16),
                           (unsigned char)(v >> 24)};
    model_put(b, le, 4);
}

static inline void model_put_f32(model_bytes *b, float f) {
    uint32_t bits;
    memcpy(&bits, &f, 4);
    model_put_u32(b, bits);
}

/* Appends the BLAKE2b-256 of every byte so far: the file's last 32 bytes. */
static inline void model_seal(model_bytes *b) {
    unsigned char digest[32];
    rs_blake2b h;
    rs_blake2b_init(&h, 32);
    rs_blake2b_update(&h, b->at, b->size);
    rs_blake2b_final(&h, digest);
    model_put(b, digest, sizeof digest);
}

/* Uniform in [-1, 1) from a splitmix64 state. */
static inline double model_uniform(uint64_t *state) {
    uint64_t z = (*state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    z ^= z >> 31;
    return (double)(z >> 11) / 9007199254740992.0 * 2 - 1;
}

/* `stages` stages of layers MODEL_INPUTS -> hidden[0] -> ... -> 3, rectifiers between,
 * weights uniform within He's scale (each layer's outputs about as large as its inputs), the
 * last layer's a tenth of it. */
static inline model_bytes random_model(int stages, const uint32_t *hidden, int hidden_count,
                                       uint64_t seed) {
    model_bytes b = {NULL, 0, 0};
    model_put(&b, "RSNN\r\n\x1a\n", 8);
    model_put_u32(&b, 1); /* format version */
    model_put_u32(&b, MODEL_LAYOUT);
    model_put_u32(&b, MODEL_NEIGHBOURS);
    model_put_u32(&b, MODEL_INPUTS);
    unsigned char manifest[32] = {0};
    model_put(&b, manifest, sizeof manifest);
    model_put_u32(&b, (uint32_t)stages);
    for (int s = 0; s < stages; s++) {
        model_put_u32(&b, (uint32_t)hidden_count + 1);
        uint32_t in = MODEL_INPUTS;
        for (int l = 0; l <= hidden_count; l++) {
            bool last = l == hidden_count;
            uint32_t out = last ? 3 : hidden[l];
            model_put_u32(&b, in);
            model_put_u32(&b, out);
            model_put_u32(&b, last ? 0 : 1);
            /* the last layer's residuals about a tenth of the unit normal, as a trained model's
             * corrections are: not a normal that the residual nearly cancels, whose direction
             * float rounding would turn as far as it likes */
            double scale = sqrt(6.0 / in) * (last ? 0.1 : 1.0);
            for (size_t k = 0; k < (size_t)in * out; k++)
                model_put_f32(&b, (float)(scale * model_uniform(&seed)));
            for (uint32_t k = 0; k < out; k++)
                model_put_f32(&b, (float)(0.1 * model_uniform(&seed)));
            in = out;
        }
    }
    model_seal(&b);
    return b;
}

#endif /* RSMOOTH_TEST_MODEL_H */
