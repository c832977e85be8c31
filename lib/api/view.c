/* Mesh views: a host's strided vertex buffer and indices of any type, read into the packed arrays
 * the filter takes, and the result written back at the host's stride. The indices are checked
 * here, with their own type, so a negative int32 is named as the -1 it is rather than as the
 * 4294967295 it would wrap to. */
#include "core/rsmooth_internal.h"

#include <string.h>

rsmooth_status rsmooth_mesh_view_init(rsmooth_mesh_view *view) {
    if (!view)
        return RSMOOTH_ERROR_INVALID_ARGUMENT;
    memset(view, 0, sizeof *view);
    view->struct_size = sizeof *view;
    view->scalar = RSMOOTH_FLOAT32;
    view->index_type = RSMOOTH_INDEX_UINT32;
    return RSMOOTH_OK;
}

static size_t index_size(int type) {
    return type == RSMOOTH_INDEX_INT64 ? 8 : 4;
}

/* Bytes a strided array of `count` records of `record` bytes spans. */
static size_t span(size_t count, size_t stride, size_t record) {
    return count ? (count - 1) * stride + record : 0;
}

/* Checks the view's shape and packs its indices into `packed` (3 per triangle), each checked
 * against vertex_count in its own type. */
static rsmooth_status pack_indices(const rsmooth_mesh_view *m, size_t stride, uint32_t *packed,
                                   rsmooth_error *error, const char *where) {
    const unsigned char *base = m->indices;
    for (size_t t = 0; t < m->triangle_count; t++) {
        const unsigned char *row = base + t * stride;
        for (int c = 0; c < 3; c++) {
            int64_t index;
            if (m->index_type == RSMOOTH_INDEX_INT64) {
                memcpy(&index, row + 8 * c, 8);
            } else if (m->index_type == RSMOOTH_INDEX_INT32) {
                int32_t i32;
                memcpy(&i32, row + 4 * c, 4);
                index = i32;
            } else {
                uint32_t u32;
                memcpy(&u32, row + 4 * c, 4);
                index = u32;
            }
            if (index < 0 || (uint64_t)index >= m->vertex_count)
                return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                               "triangle %zu corner %d: index %lld is %s", t, c, (long long)index,
                               index < 0 ? "negative" : "beyond the vertices");
            packed[3 * t + (size_t)c] = (uint32_t)index;
        }
    }
    return RSMOOTH_OK;
}

static rsmooth_status check_view(const rsmooth_mesh_view *m, size_t *pstride, size_t *istride,
                                 rsmooth_error *error, const char *where) {
    if (!m)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "mesh is NULL");
    if (m->struct_size < sizeof *m)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "mesh->struct_size %zu is too small: call rsmooth_mesh_view_init first",
                       m->struct_size);
    if (m->scalar != RSMOOTH_FLOAT32 && m->scalar != RSMOOTH_FLOAT64)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "mesh->scalar %d is unknown",
                       (int)m->scalar);
    if (m->index_type != RSMOOTH_INDEX_UINT32 && m->index_type != RSMOOTH_INDEX_INT32 &&
        m->index_type != RSMOOTH_INDEX_INT64)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "mesh->index_type %d is unknown", m->index_type);
    size_t record = rs_vertex_bytes(m->scalar);
    size_t triple = 3 * index_size(m->index_type);
    *pstride = m->position_stride ? m->position_stride : record;
    *istride = m->index_stride ? m->index_stride : triple;
    if (*pstride < record || *istride < triple)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "a stride is smaller than its record (position_stride %zu < %zu or "
                       "index_stride %zu < %zu)",
                       *pstride, record, *istride, triple);
    if (!m->positions || m->vertex_count == 0)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "mesh->positions is NULL or vertex_count is 0");
    if (m->triangle_count && !m->indices)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "mesh->indices is NULL with %zu triangles", m->triangle_count);
    if (rs_mul_overflows(m->vertex_count, *pstride) || rs_mul_overflows(m->vertex_count, record) ||
        rs_mul_overflows(m->triangle_count, *istride) ||
        rs_mul_overflows(m->triangle_count, 3 * sizeof(uint32_t)))
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "the mesh's size overflows");
    return RSMOOTH_OK;
}

rsmooth_status rsmooth_smooth_view(rsmooth_context *ctx, const rsmooth_mesh_view *mesh,
                                   const rsmooth_params *params, void *out_positions,
                                   size_t out_stride, const rsmooth_outputs *outputs,
                                   rsmooth_error *error) {
    static const char where[] = "rsmooth_smooth_view";
    rs_error_clear(error);
    size_t pstride = 0, istride = 0;
    rsmooth_outputs o;
    rsmooth_status st = rs_read_outputs(outputs, &o, error, where);
    if (st == RSMOOTH_OK)
        st = check_view(mesh, &pstride, &istride, error, where);
    if (st != RSMOOTH_OK)
        return st;
    float *out_weight = o.weight, *out_confidence = o.confidence;
    size_t n = mesh->vertex_count;
    size_t record = rs_vertex_bytes(mesh->scalar);
    size_t ostride = out_stride ? out_stride : record;
    if (!out_positions)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "out_positions is NULL");
    if (ostride < record || rs_mul_overflows(n, ostride))
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "out_stride %zu is smaller than a vertex (%zu bytes) or overflows", ostride,
                       record);
    size_t out_span = span(n, ostride, record), per_vertex = n * sizeof(float);
    if (rs_ranges_overlap(out_positions, out_span, out_weight, per_vertex) ||
        rs_ranges_overlap(out_positions, out_span, out_confidence, per_vertex) ||
        rs_ranges_overlap(out_weight, per_vertex, out_confidence, per_vertex))
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "out_positions, out_weight and out_confidence overlap");

    unsigned char *positions = rs_alloc_array(n, record), *result = rs_alloc_array(n, record);
    uint32_t *indices =
        rs_alloc_array(mesh->triangle_count ? mesh->triangle_count : 1, 3 * sizeof *indices);
    float *weight = out_weight ? rs_alloc_array(n, sizeof *weight) : NULL;
    float *confidence = out_confidence ? rs_alloc_array(n, sizeof *confidence) : NULL;
    if (!positions || !result || !indices || (out_weight && !weight) ||
        (out_confidence && !confidence)) {
        st = rs_fail(error, RSMOOTH_ERROR_OUT_OF_MEMORY, where, "no memory for the packed mesh");
        goto done;
    }
    if ((st = pack_indices(mesh, istride, indices, error, where)) != RSMOOTH_OK)
        goto done;
    for (size_t v = 0; v < n; v++)
        memcpy(positions + v * record, (const unsigned char *)mesh->positions + v * pstride,
               record);
    /* the weights and confidences go to copies too: the caller's may share the vertex buffer */
    rsmooth_outputs packed = {sizeof packed, weight, confidence, o.report};
    st = rsmooth_smooth(ctx, mesh->scalar, positions, n, indices, mesh->triangle_count, params,
                        result, &packed, error);
    if (st == RSMOOTH_OK) {
        for (size_t v = 0; v < n; v++)
            memcpy((unsigned char *)out_positions + v * ostride, result + v * record, record);
        if (out_weight)
            memcpy(out_weight, weight, per_vertex);
        if (out_confidence)
            memcpy(out_confidence, confidence, per_vertex);
    }
done:
    rs_free(positions);
    rs_free(result);
    rs_free(indices);
    rs_free(weight);
    rs_free(confidence);
    return st;
}
