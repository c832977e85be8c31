/* The learned model's file (lib/learned/model_file.c, docs/model.md "The file"): a model made
 * here byte by byte reads back with its sizes, and every kind of bad file is refused with a
 * message saying what is wrong; the network in double against a direct sum; the built-in
 * model's manifest digest against models/learned-normals.manifest.json. */
#include "core/blake2b.h"
#include "learned/learned.h"
#include "rsmooth.h"
#include "test_model.h"
#include "test_util.h"

#include <stdint.h>
#include <string.h>

/* A model of `stages` stages of (inputs -> hidden relu -> 3), weights from a fixed sequence;
 * `last_out` the last layer's width (3 for a good model). Not sealed. */
static model_bytes make_model(uint32_t version, uint32_t layout, int stages, uint32_t hidden,
                              uint32_t last_out) {
    model_bytes b = {NULL, 0, 0};
    model_put(&b, "RSNN\r\n\x1a\n", 8);
    model_put_u32(&b, version);
    model_put_u32(&b, layout);
    model_put_u32(&b, RS_LEARNED_NEIGHBOURS);
    model_put_u32(&b, RS_LEARNED_INPUTS);
    unsigned char manifest[32];
    for (int i = 0; i < 32; i++)
        manifest[i] = (unsigned char)(7 * i + 1);
    model_put(&b, manifest, 32);
    model_put_u32(&b, (uint32_t)stages);
    uint32_t seed = 12345;
    for (int s = 0; s < stages; s++) {
        model_put_u32(&b, 2);
        uint32_t widths[3] = {RS_LEARNED_INPUTS, hidden, last_out};
        for (int l = 0; l < 2; l++) {
            model_put_u32(&b, widths[l]);
            model_put_u32(&b, widths[l + 1]);
            model_put_u32(&b, l == 0 ? 1 : 0);
            size_t n = (size_t)widths[l] * widths[l + 1] + widths[l + 1];
            for (size_t i = 0; i < n; i++) {
                seed = seed * 1664525u + 1013904223u;
                model_put_f32(&b, ((float)(seed >> 8) / 16777216.0f - 0.5f) * 0.2f);
            }
        }
    }
    return b;
}

/* The file is refused, and the message holds `what`. */
static void refused(const model_bytes *b, size_t size, const char *what) {
    rsmooth_error err;
    rs_learned_model m;
    rsmooth_status st = rs_learned_model_read(b->at, size, &m, &err, "test.rsnn");
    if (st != RSMOOTH_ERROR_PARSE || !strstr(err.message, what) ||
        !strstr(err.message, "test.rsnn")) {
        fprintf(stderr, "expected a refusal with '%s' for %zu bytes, got status %d: %s\n", what,
                size, (int)st, err.message);
        exit(1);
    }
    printf("refused (%zu bytes): %s\n", size, err.message);
}

static void check_network(const rs_learned_model *m) {
    double d[RS_LEARNED_INPUTS], out[3], hidden[64];
    for (int i = 0; i < RS_LEARNED_INPUTS; i++)
        d[i] = sin(0.37 * i);
    const rs_learned_stage *st = &m->stage[1];
    rs_learned_network(st, d, out);
    /* the same sums written out: relu(W0 d + b0), then W1 h + b1 */
    const rs_learned_layer *a = &st->layer[0], *b = &st->layer[1];
    CHECK(a->out <= 64);
    for (uint32_t o = 0; o < a->out; o++) {
        double s = a->bias[o];
        for (uint32_t i = 0; i < a->in; i++)
            s += (double)a->weight[o * a->in + i] * d[i];
        hidden[o] = s > 0 ? s : 0;
    }
    for (uint32_t o = 0; o < 3; o++) {
        double s = b->bias[o];
        for (uint32_t i = 0; i < b->in; i++)
            s += (double)b->weight[o * b->in + i] * hidden[i];
        CHECK_NEAR(out[o], s, 1e-12);
    }
    printf("network in double: %.6f %.6f %.6f, as the direct sums\n", out[0], out[1], out[2]);
}

static void check_builtin_manifest(void) {
    const char *path = RSMOOTH_SOURCE_DIR "/models/learned-normals.manifest.json";
    FILE *f = fopen(path, "rb");
    CHECK(f);
    rs_blake2b s;
    rs_blake2b_init(&s, 32);
    unsigned char chunk[65536], digest[32];
    size_t n;
    while ((n = fread(chunk, 1, sizeof chunk, f)) > 0)
        rs_blake2b_update(&s, chunk, n);
    fclose(f);
    rs_blake2b_final(&s, digest);
    rsmooth_model_info info = {.struct_size = sizeof info};
    rsmooth_error err;
    CHECK(rsmooth_model_check(NULL, 0, &info, &err) == RSMOOTH_OK);
    CHECK(memcmp(info.manifest, digest, 32) == 0);
    CHECK(info.parameters <= 200000);
    printf("built-in model: %d stages, %zu parameters, manifest digest matches %s\n", info.stages,
           info.parameters, path);
}

int main(void) {
    model_bytes good = make_model(1, RS_LEARNED_LAYOUT, 2, 24, 3);
    model_seal(&good);
    rs_learned_model m;
    rsmooth_error err;
    CHECK(rs_learned_model_read(good.at, good.size, &m, &err, "good") == RSMOOTH_OK);
    size_t per_stage = RS_LEARNED_INPUTS * 24 + 24 + 24 * 3 + 3;
    CHECK_EQ_INT(m.stage_count, 2);
    CHECK_EQ_INT(m.parameters, 2 * per_stage);
    CHECK_EQ_INT(m.stage[1].layer[0].activation, 1);
    check_network(&m);
    rs_learned_model_free(&m);
    rsmooth_model_info info = {.struct_size = sizeof info};
    CHECK(rsmooth_model_check(good.at, good.size, &info, &err) == RSMOOTH_OK);
    CHECK_EQ_INT(info.stages, 2);
    CHECK_EQ_INT(info.parameters, 2 * per_stage);
    CHECK_EQ_INT(info.manifest[1], 8);

    model_bytes bad = make_model(1, RS_LEARNED_LAYOUT, 2, 24, 3);
    model_seal(&bad);
    bad.at[0] = 'X';
    refused(&bad, bad.size, "not an rsmooth model");
    for (size_t cut = 9; cut < good.size; cut += good.size / 7)
        refused(&good, cut, "truncated");
    refused(&good, good.size - 1, "truncated");
    model_bytes v2 = make_model(2, RS_LEARNED_LAYOUT, 1, 8, 3);
    model_seal(&v2);
    refused(&v2, v2.size, "format version 2");
    model_bytes l2 = make_model(1, RS_LEARNED_LAYOUT + 1, 1, 8, 3);
    model_seal(&l2);
    refused(&l2, l2.size, "descriptor layout");
    model_bytes wide = make_model(1, RS_LEARNED_LAYOUT, 1, 8, 4);
    model_seal(&wide);
    refused(&wide, wide.size, "does not give 3 numbers");
    model_bytes flipped = make_model(1, RS_LEARNED_LAYOUT, 2, 24, 3);
    model_seal(&flipped);
    flipped.at[200] ^= 0x10;
    refused(&flipped, flipped.size, "checksum does not match");
    model_bytes longer = make_model(1, RS_LEARNED_LAYOUT, 1, 8, 3);
    model_seal(&longer);
    model_put(&longer, "x", 1);
    refused(&longer, longer.size, "bytes after its checksum");
    rsmooth_model_info small = {.struct_size = 4};
    CHECK(rsmooth_model_check(good.at, good.size, &small, &err) == RSMOOTH_ERROR_INVALID_ARGUMENT);
    check_builtin_manifest();
    free(good.at), free(bad.at), free(v2.at), free(l2.at), free(wide.at);
    free(flipped.at), free(longer.at);
    printf("learned model file: all checks passed\n");
    return 0;
}
