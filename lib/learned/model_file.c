/* The learned model's file (docs/model.md, "The file"): little-endian, a fixed header, the
 * stages' layers, then a BLAKE2b-256 of every byte before it, so a truncated or altered file is
 * told apart from a model of another layout. Written by train/model_file.py. */
#include "core/blake2b.h"
#include "learned/learned.h"

#include <string.h>

#define MAGIC "RSNN\r\n\x1a\n"
#define MAGIC_SIZE 8
#define FORMAT_VERSION 1
#define HEADER_SIZE (MAGIC_SIZE + 4 * 4 + 32 + 4)
#define DIGEST_SIZE 32
/* Bounds well above any model this format is for; they keep a hostile file's sizes small. */
#define MAX_STAGES 8
#define MAX_LAYERS 16
#define MAX_PARAMETERS (1u << 22)

typedef struct reader {
    const unsigned char *at, *end;
} reader;

static bool read_u32(reader *r, uint32_t *v) {
    if (r->end - r->at < 4)
        return false;
    *v = (uint32_t)r->at[0] | (uint32_t)r->at[1] << 8 | (uint32_t)r->at[2] << 16 |
         (uint32_t)r->at[3] << 24;
    r->at += 4;
    return true;
}

static bool read_floats(reader *r, float *out, size_t count) {
    if ((size_t)(r->end - r->at) / 4 < count)
        return false;
    for (size_t i = 0; i < count; i++) {
        uint32_t bits = (uint32_t)r->at[0] | (uint32_t)r->at[1] << 8 | (uint32_t)r->at[2] << 16 |
                        (uint32_t)r->at[3] << 24;
        memcpy(out + i, &bits, 4);
        r->at += 4;
    }
    return true;
}

/* The layers' shapes, checked, and how many parameters they hold; the reader is left at the
 * digest. Returns NULL when they are fine, else what is wrong. */
static const char *scan_layers(reader r, uint32_t stages, uint32_t inputs, size_t *parameters,
                               size_t *layers) {
    *parameters = 0;
    *layers = 0;
    for (uint32_t s = 0; s < stages; s++) {
        uint32_t count, width = inputs;
        if (!read_u32(&r, &count))
            return "truncated in a stage's header";
        if (count < 1 || count > MAX_LAYERS)
            return "a stage's layer count outside 1..16";
        for (uint32_t l = 0; l < count; l++) {
            uint32_t in, out, activation;
            if (!read_u32(&r, &in) || !read_u32(&r, &out) || !read_u32(&r, &activation))
                return "truncated in a layer's header";
            if (in != width)
                return "a layer's input count is not the previous layer's output count";
            if (out < 1 || out > RS_LEARNED_MAX_WIDTH || activation > 1)
                return "a layer's width outside 1..1024 or an unknown activation";
            if (l + 1 == count && (out != 3 || activation != 0))
                return "a stage's last layer does not give 3 numbers without activation";
            size_t n = (size_t)in * out + out;
            if (*parameters + n > MAX_PARAMETERS)
                return "more parameters than this format allows (2^22)";
            if ((size_t)(r.end - r.at) / 4 < n)
                return "truncated in a layer's weights";
            r.at += 4 * n;
            *parameters += n;
            width = out;
        }
        *layers += count;
    }
    if (r.end - r.at != DIGEST_SIZE)
        return r.end - r.at < DIGEST_SIZE ? "truncated before its checksum"
                                          : "bytes after its checksum";
    return NULL;
}

static bool digest_matches(const unsigned char *bytes, size_t size) {
    unsigned char digest[DIGEST_SIZE];
    rs_blake2b s;
    rs_blake2b_init(&s, DIGEST_SIZE);
    rs_blake2b_update(&s, bytes, size - DIGEST_SIZE);
    rs_blake2b_final(&s, digest);
    return memcmp(digest, bytes + size - DIGEST_SIZE, DIGEST_SIZE) == 0;
}

/* Fills the stages' layers from the (checked) file into the model's storage. */
static void fill_layers(reader r, rs_learned_model *model, float *values) {
    rs_learned_layer *layer = (rs_learned_layer *)(model->stage + model->stage_count);
    for (uint32_t s = 0; s < model->stage_count; s++) {
        rs_learned_stage *stage = &model->stage[s];
        read_u32(&r, &stage->layer_count);
        stage->layer = layer;
        for (uint32_t l = 0; l < stage->layer_count; l++, layer++) {
            read_u32(&r, &layer->in);
            read_u32(&r, &layer->out);
            read_u32(&r, &layer->activation);
            read_floats(&r, values, (size_t)layer->in * layer->out);
            layer->weight = values;
            values += (size_t)layer->in * layer->out;
            read_floats(&r, values, layer->out);
            layer->bias = values;
            values += layer->out;
        }
    }
}

rsmooth_status rs_learned_model_read(const void *bytes, size_t size, rs_learned_model *model,
                                     rsmooth_error *error, const char *name) {
    static const char where[] = "learned model";
    memset(model, 0, sizeof *model);
    const unsigned char *b = bytes;
    if (!b || size < MAGIC_SIZE || memcmp(b, MAGIC, MAGIC_SIZE) != 0)
        return rs_fail(error, RSMOOTH_ERROR_PARSE, where,
                       "%s: not an rsmooth model (it does not start with RSNN)", name);
    if (size < HEADER_SIZE + DIGEST_SIZE)
        return rs_fail(error, RSMOOTH_ERROR_PARSE, where, "%s: truncated (%zu bytes)", name, size);
    reader r = {b + MAGIC_SIZE, b + size};
    uint32_t version = 0, layout = 0, neighbours = 0, inputs = 0, stages = 0;
    read_u32(&r, &version);
    read_u32(&r, &layout);
    read_u32(&r, &neighbours);
    read_u32(&r, &inputs);
    if (version != FORMAT_VERSION)
        return rs_fail(error, RSMOOTH_ERROR_PARSE, where,
                       "%s: format version %u; this rsmooth reads version %d", name, version,
                       FORMAT_VERSION);
    if (layout != RS_LEARNED_LAYOUT || neighbours != RS_LEARNED_NEIGHBOURS ||
        inputs != RS_LEARNED_INPUTS)
        return rs_fail(error, RSMOOTH_ERROR_PARSE, where,
                       "%s: trained on descriptor layout %u (%u neighbours, %u inputs); this "
                       "rsmooth computes layout %d (%d neighbours, %d inputs)",
                       name, layout, neighbours, inputs, RS_LEARNED_LAYOUT, RS_LEARNED_NEIGHBOURS,
                       RS_LEARNED_INPUTS);
    memcpy(model->manifest, r.at, 32);
    r.at += 32;
    read_u32(&r, &stages);
    if (stages < 1 || stages > MAX_STAGES)
        return rs_fail(error, RSMOOTH_ERROR_PARSE, where, "%s: %u stages (1..%d expected)", name,
                       stages, MAX_STAGES);
    size_t parameters, layers;
    const char *problem = scan_layers(r, stages, inputs, &parameters, &layers);
    if (problem)
        return rs_fail(error, RSMOOTH_ERROR_PARSE, where, "%s: %s", name, problem);
    if (!digest_matches(b, size))
        return rs_fail(error, RSMOOTH_ERROR_PARSE, where,
                       "%s: its checksum does not match its contents (damaged or altered)", name);
    size_t head = stages * sizeof(rs_learned_stage) + layers * sizeof(rs_learned_layer);
    model->storage = rs_alloc_array(1, head + parameters * sizeof(float));
    if (!model->storage)
        return rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "%s: out of memory", name);
    model->format_version = version;
    model->layout = layout;
    model->neighbours = neighbours;
    model->inputs = inputs;
    model->stage_count = stages;
    model->parameters = parameters;
    model->stage = model->storage;
    fill_layers(r, model, (float *)((unsigned char *)model->storage + head));
    return RSMOOTH_OK;
}

void rs_learned_model_free(rs_learned_model *model) {
    rs_free(model->storage);
    memset(model, 0, sizeof *model);
}

extern const unsigned char rs_model_learned_normals[];
extern const size_t rs_model_learned_normals_size;

rsmooth_status rs_learned_model_builtin(rs_learned_model *model, rsmooth_error *error) {
    return rs_learned_model_read(rs_model_learned_normals, rs_model_learned_normals_size, model,
                                 error, "the built-in model");
}
