/* Robust estimation (Jones et al. 2003, Eq. 3): p' = sum Pi_q(p) a_q f g / k(p), Pi_q(p) = p + t
 * n_q with t = n_q . (c_q - p), f = exp(-|c_q - p|^2 / (2 sigma_f^2)), g = exp(-t^2 / (2
 * sigma_g^2)).
 *
 * robust_block: one work-item per vertex block writes, per lane,
 *   block_result: the displacement p' - p in cell units (x, y, z) and k' = the sum of the weights
 *                 used (4 components per lane)
 *   block_extra:  sum a f and the exponent shift e_s (2 components per lane), so that
 *                 k(p) = k' 2^-e_s in mean-area units (exponents are in base 2 here).
 * When k' falls below RS_RESCUE_WEIGHT, float32 weights have (nearly) underflowed: the vertex's
 * sums are then redone with its smallest influence exponent subtracted (e_s), as the reference path
 * does. `want_confidence` = 0 skips sum a f (one exp per pair instead of two).
 * `predict_centroid` = 1 predicts c_q instead of Pi_q(p) (isotropic Gaussian smoothing when
 * inv_2sg2 = 0).
 * `influence` (an RS_INFLUENCE_ value) picks g; every one but the Gaussian is a function of
 * u = x^2 / sigma_g^2 (x = |prediction - p|, inv_sg2 = h^2 / sigma_g^2) multiplying a f, and
 * has no rescue: a lane they give no weight at all (Tukey's) stays where it is.
 * `use_color` = 1 multiplies each weight by the colour factor 2^-(|C_q - C_p|^2 inv_2sc2)
 * (inv_2sc2 = log2 e / 2 sigma_c^2): C_q = facet_color[q].xyz, the mean colour of q's corners,
 * C_p the lane's colour from block_color (per block, as block_pos: every lane's first component,
 * then the second, then the third). With the Gaussian its exponent joins the influence's; the
 * other influence functions multiply their weight by it. Either way the rescue covers it (with
 * the other functions, the colour exponent alone is shifted). sum a f never includes it. The
 * loops without colour are the specialisations they were (use_color = 0 folds every colour term
 * away).
 */

typedef struct robust_acc {
    lanef x, y, z, k, kf;
} robust_acc;

/* g(u) of the influence functions other than the Gaussian, u = x^2 / sigma_g^2. */
inline __attribute__((always_inline)) lanef influence_weight(lanef u, int influence) {
    if (influence == RS_INFLUENCE_TUKEY) { /* (1 - x^2 / c^2)^2 below c^2 = 5 sigma_g^2 */
        lanef r = 1.0f - u * 0.2f;
        return select((lanef)0.0f, r * r, u < 5.0f);
    }
    if (influence == RS_INFLUENCE_LORENTZIAN)
        return 1.0f / (1.0f + u);
    return select((lanef)1.0f, rsqrt(u), u > 1.0f); /* Huber: min(1, sigma_g / x) */
}

/* Sums of Eq. 3 for the lanes at (px, py, pz) (box [lo, hi]) over the facets within reach of the
 * block's anchor, with influence exponents shifted down by `shift`; *pairs counts the facets.
 * Inlined, so the flags are constants in each call and the inner loop keeps what it needs in
 * registers. ROBUST_SUMS defines it as NAME, with SEARCH (FOR_EACH_FACET_NEAR or
 * FOR_EACH_FACET_OWN, common.cl) as its walk over the facets. */
#define ROBUST_SUMS(NAME, SEARCH, EXTRA_PARAMS)                                                    \
    inline __attribute__((always_inline)) robust_acc NAME(                                         \
        lanef px, lanef py, lanef pz, lanei ox, lanei oy, lanei oz, float3 lo, float3 hi,          \
        int4 anchor, float reach2, float inv_2sf2, float inv_2sg2, lanef shift,                    \
        int want_confidence, int predict_centroid, int influence, float inv_sg2, int use_color,    \
        lanef cr, lanef cg, lanef cb, float inv_2sc2, __global const float4 *facet_color,          \
        __global const float4 *facet_centroid, __global const float4 *normal,                      \
        __global const int4 *cell_coord, __global const uint *cell_start,                          \
        __global const uint *column_first, __global const int *column_table, uint column_mask,     \
        uint *pairs EXTRA_PARAMS) {                                                                \
        robust_acc a;                                                                              \
        a.x = a.y = a.z = a.k = a.kf = 0.0f;                                                       \
        SEARCH(reach2, normal, *pairs, {                                                           \
            lanef ex = c.x - qx, ey = c.y - qy, ez = c.z - qz;                                     \
            lanef d2 = ex * ex + ey * ey + ez * ez;                                                \
            lanei near = d2 <= reach2;                                                             \
            lanef t = n.x * ex + n.y * ey + n.z * ez;                                              \
            /* |prediction - p|^2: t^2 for the projection, d2 for the centroid */                  \
            lanef x2 = predict_centroid ? d2 : t * t;                                              \
            lanef w, af = 0.0f, ec = 0.0f;                                                         \
            if (use_color) { /* the colour exponent */                                             \
                float4 fc = facet_color[q];                                                        \
                lanef dr = fc.x - cr, dg = fc.y - cg, db = fc.z - cb;                              \
                ec = (dr * dr + dg * dg + db * db) * inv_2sc2;                                     \
            }                                                                                      \
            if (influence == RS_INFLUENCE_GAUSSIAN) {                                              \
                lanef e = x2 * inv_2sg2;                                                           \
                if (use_color)                                                                     \
                    e += ec;                                                                       \
                w = select((lanef)0.0f, fast_exp2(c.w - d2 * inv_2sf2 - (e - shift)), near);       \
            } else {                                                                               \
                af = select((lanef)0.0f, fast_exp2(c.w - d2 * inv_2sf2), near);                    \
                w = af * influence_weight(x2 * inv_sg2, influence);                                \
                if (use_color)                                                                     \
                    w *= fast_exp2(shift - ec); /* shifted by the rescue, as the Gaussian's */     \
            }                                                                                      \
            if (predict_centroid) {                                                                \
                a.x += w * ex;                                                                     \
                a.y += w * ey;                                                                     \
                a.z += w * ez;                                                                     \
            } else {                                                                               \
                lanef wt = w * t;                                                                  \
                a.x += wt * n.x;                                                                   \
                a.y += wt * n.y;                                                                   \
                a.z += wt * n.z;                                                                   \
            }                                                                                      \
            a.k += w;                                                                              \
            if (influence != RS_INFLUENCE_GAUSSIAN)                                                \
                a.kf += af; /* computed anyway */                                                  \
            else if (want_confidence)                                                              \
                a.kf += select((lanef)0.0f, fast_exp2(c.w - d2 * inv_2sf2), near);                 \
        })                                                                                         \
        return a;                                                                                  \
    }

ROBUST_SUMS(robust_sums, FOR_EACH_FACET_NEAR, STAGE_PARAMS)
#if RS_LANES == 1
/* The group variant's rescue: rare, so each work-item walks its own vertex's cells alone (no
 * barriers under a condition, which PoCL's compiler handles very slowly). */
ROBUST_SUMS(robust_sums_own, FOR_EACH_FACET_OWN, )
#endif

/* Per lane, the smallest influence exponent over the facets within reach (MAXFLOAT where none):
 * the shift that keeps a lane's largest weight near one. Only the rare rescue needs it. With
 * use_color the colour exponent adds to it (inv_2sg2 = 0: the colour exponent alone), and
 * `tukey` leaves out the facets Tukey's weight rejects (x^2 inv_sg2 >= 5). */
lanef smallest_exponent(lanef px, lanef py, lanef pz, lanei ox, lanei oy, lanei oz, float3 lo,
                        float3 hi, int4 anchor, float reach2, float inv_2sg2, int predict_centroid,
                        int tukey, float inv_sg2, int use_color, lanef cr, lanef cg, lanef cb,
                        float inv_2sc2, __global const float4 *facet_color,
                        __global const float4 *facet_centroid, __global const float4 *normal,
                        __global const int4 *cell_coord, __global const uint *cell_start,
                        __global const uint *column_first, __global const int *column_table,
                        uint column_mask) {
    lanef e_min = MAXFLOAT;
    /* Tukey's test applies to every lane or none: picked by select() rather than an `if`, which
     * the compiler turns into a choice between boolean vectors, one of them all true, and
     * Oclgrind computes that one as all false (its error 4 in tests/test_oclgrind.c) */
    lanei tukey_lanes = (lanei)(tukey ? -1 : 0);
    uint pairs = 0; /* not counted: the rescue's second pass counts its facets */
    FOR_EACH_FACET_OWN(reach2, normal, pairs, {
        lanef ex = c.x - qx, ey = c.y - qy, ez = c.z - qz;
        lanef d2 = ex * ex + ey * ey + ez * ez;
        lanef t = n.x * ex + n.y * ey + n.z * ez;
        lanef e = (predict_centroid ? d2 : t * t) * inv_2sg2;
        lanei near = d2 <= reach2;
        if (use_color) {
            float4 fc = facet_color[q];
            lanef dr = fc.x - cr, dg = fc.y - cg, db = fc.z - cb;
            e += (dr * dr + dg * dg + db * db) * inv_2sc2;
        }
        /* with Tukey's weight, only the facets it does not reject */
        lanei counts =
            select(near, near && (predict_centroid ? d2 : t * t) * inv_sg2 < 5.0f, tukey_lanes);
        e_min = select(e_min, fmin(e_min, e), counts);
    })
    return e_min;
}

/* A lane whose Gaussian weights (nearly) all underflowed: redo its sums with the exponents
 * shifted by their smallest value, as the reference path does. Shifting never changes the
 * weighted average, only how well float32 holds it. The other influence functions keep
 * their sums: a weight of zero there is a verdict, not an underflow; but with colour, their
 * colour factors can underflow, and the colour exponent alone is shifted. Returns each lane's
 * shift (0 where its sums stand) and replaces *a's sums where it redid them. */
lanef rescued_sums(robust_acc *a, lanef px, lanef py, lanef pz, lanei ox, lanei oy, lanei oz,
                   float3 lo, float3 hi, int4 anchor, float reach2, float inv_2sf2, float inv_2sg2,
                   int influence, float inv_sg2, int predict_centroid, int use_color, lanef cr,
                   lanef cg, lanef cb, float inv_2sc2, __global const float4 *facet_color,
                   __global const float4 *facet_centroid, __global const float4 *normal,
                   __global const int4 *cell_coord, __global const uint *cell_start,
                   __global const uint *column_first, __global const int *column_table,
                   uint column_mask, uint *rescue_pairs) {
#define NO_COLOR 0, (lanef)0.0f, (lanef)0.0f, (lanef)0.0f, inv_2sc2, facet_color
#define COLOR 1, cr, cg, cb, inv_2sc2, facet_color
    bool gaussian = influence == RS_INFLUENCE_GAUSSIAN;
    lanei rescue = gaussian || use_color ? a->k < RS_RESCUE_WEIGHT : (lanei)0;
    lanef shift = 0.0f;
#if RS_LANES == 1
    /* the group variant's rescue: each work-item searches around its own vertex alone */
    float3 own = (float3)(px + (float)ox, py + (float)oy, pz + (float)oz);
#define RESCUE_BOX own, own
#define RESCUE_SUMS robust_sums_own
#else
#define RESCUE_BOX lo, hi
#define RESCUE_SUMS robust_sums
#endif
    if (lane_any(rescue)) {
        lanef e_min = smallest_exponent(
            px, py, pz, ox, oy, oz, RESCUE_BOX, anchor, reach2, gaussian ? inv_2sg2 : 0.0f,
            predict_centroid, influence == RS_INFLUENCE_TUKEY, inv_sg2, use_color, cr, cg, cb,
            inv_2sc2, facet_color, facet_centroid, normal, cell_coord, cell_start, column_first,
            column_table, column_mask);
        shift = select((lanef)0.0f, e_min, rescue && e_min < MAXFLOAT);
    }
    if (lane_any(shift != 0.0f)) {
        robust_acc r;
        if (use_color)
            r = RESCUE_SUMS(px, py, pz, ox, oy, oz, RESCUE_BOX, anchor, reach2, inv_2sf2, inv_2sg2,
                            shift, 0, predict_centroid, influence, inv_sg2, COLOR, facet_centroid,
                            normal, cell_coord, cell_start, column_first, column_table, column_mask,
                            rescue_pairs);
        else
            r = RESCUE_SUMS(px, py, pz, ox, oy, oz, RESCUE_BOX, anchor, reach2, inv_2sf2, inv_2sg2,
                            shift, 0, predict_centroid, RS_INFLUENCE_GAUSSIAN, inv_sg2, NO_COLOR,
                            facet_centroid, normal, cell_coord, cell_start, column_first,
                            column_table, column_mask, rescue_pairs);
        lanei redo = shift != 0.0f;
        a->x = select(a->x, r.x, redo);
        a->y = select(a->y, r.y, redo);
        a->z = select(a->z, r.z, redo);
        a->k = select(a->k, r.k, redo);
    }
#undef NO_COLOR
#undef COLOR
#undef RESCUE_BOX
#undef RESCUE_SUMS
    return shift;
}

__kernel void robust_block(uint block_count, float reach2, float inv_2sf2, float inv_2sg2,
                           int influence, float inv_sg2, int want_confidence, int predict_centroid,
                           int use_color, float inv_2sc2, __global const float *block_pos,
                           __global const int4 *block_cell, __global const uchar *block_offset,
                           __global const float *block_color, __global const float4 *facet_centroid,
                           __global const float4 *normal, __global const float4 *facet_color,
                           __global const int4 *cell_coord, __global const uint *cell_start,
                           __global const uint *column_first, __global const int *column_table,
                           uint column_mask, __global float *block_result,
                           __global float *block_extra, __global uint *block_pairs) {
    uint b = get_global_id(0);
    BEGIN_BLOCK(b, block_count, block_pos, block_cell, block_offset);
    uint pairs = 0;
    lanef cr = 0.0f, cg = 0.0f, cb = 0.0f; /* the lanes' colours, when use_color */
    if (use_color) {
        size_t own = min(b, block_count - 1); /* the group variant's spare work-items */
        __global const float *col = block_color + 3 * RS_LANES * own;
        cr = load_lanes(0, col);
        cg = load_lanes(1, col);
        cb = load_lanes(2, col);
    }
    /* The colourless loops pass these: use_color 0 folds every colour term away. */
#define NO_COLOR 0, (lanef)0.0f, (lanef)0.0f, (lanef)0.0f, inv_2sc2, facet_color
#define COLOR 1, cr, cg, cb, inv_2sc2, facet_color
    robust_acc a;
#if RS_LANES == 1
    /* the group variant: one copy, the flags as they come (the same for every work-item, so their
     * branches never diverge); each copy of a loop with barriers costs PoCL much compile time */
    a = robust_sums(px, py, pz, ox, oy, oz, lo, hi, anchor, reach2, inv_2sf2, inv_2sg2, (lanef)0.0f,
                    want_confidence, predict_centroid, influence, inv_sg2, use_color, cr, cg, cb,
                    inv_2sc2, facet_color, facet_centroid, normal, cell_coord, cell_start,
                    column_first, column_table, column_mask, &pairs STAGE_ARGS);
#else
    /* one specialised copy of the loop per flag combination (the other influence functions
     * always sum a f: it is part of their weight); with colour, one copy for every mode */
    if (use_color)
        a = robust_sums(px, py, pz, ox, oy, oz, lo, hi, anchor, reach2, inv_2sf2, inv_2sg2,
                        (lanef)0.0f, want_confidence, predict_centroid, influence, inv_sg2, COLOR,
                        facet_centroid, normal, cell_coord, cell_start, column_first, column_table,
                        column_mask, &pairs STAGE_ARGS);
    else if (influence != RS_INFLUENCE_GAUSSIAN && predict_centroid)
        a = robust_sums(px, py, pz, ox, oy, oz, lo, hi, anchor, reach2, inv_2sf2, inv_2sg2,
                        (lanef)0.0f, 1, 1, influence, inv_sg2, NO_COLOR, facet_centroid, normal,
                        cell_coord, cell_start, column_first, column_table, column_mask,
                        &pairs STAGE_ARGS);
    else if (influence == RS_INFLUENCE_TUKEY)
        a = robust_sums(px, py, pz, ox, oy, oz, lo, hi, anchor, reach2, inv_2sf2, inv_2sg2,
                        (lanef)0.0f, 1, 0, RS_INFLUENCE_TUKEY, inv_sg2, NO_COLOR, facet_centroid,
                        normal, cell_coord, cell_start, column_first, column_table, column_mask,
                        &pairs STAGE_ARGS);
    else if (influence == RS_INFLUENCE_LORENTZIAN)
        a = robust_sums(px, py, pz, ox, oy, oz, lo, hi, anchor, reach2, inv_2sf2, inv_2sg2,
                        (lanef)0.0f, 1, 0, RS_INFLUENCE_LORENTZIAN, inv_sg2, NO_COLOR,
                        facet_centroid, normal, cell_coord, cell_start, column_first, column_table,
                        column_mask, &pairs STAGE_ARGS);
    else if (influence == RS_INFLUENCE_HUBER)
        a = robust_sums(px, py, pz, ox, oy, oz, lo, hi, anchor, reach2, inv_2sf2, inv_2sg2,
                        (lanef)0.0f, 1, 0, RS_INFLUENCE_HUBER, inv_sg2, NO_COLOR, facet_centroid,
                        normal, cell_coord, cell_start, column_first, column_table, column_mask,
                        &pairs STAGE_ARGS);
    else if (predict_centroid)
        a = robust_sums(px, py, pz, ox, oy, oz, lo, hi, anchor, reach2, inv_2sf2, inv_2sg2,
                        (lanef)0.0f, want_confidence, 1, RS_INFLUENCE_GAUSSIAN, inv_sg2, NO_COLOR,
                        facet_centroid, normal, cell_coord, cell_start, column_first, column_table,
                        column_mask, &pairs STAGE_ARGS);
    else if (want_confidence)
        a = robust_sums(px, py, pz, ox, oy, oz, lo, hi, anchor, reach2, inv_2sf2, inv_2sg2,
                        (lanef)0.0f, 1, 0, RS_INFLUENCE_GAUSSIAN, inv_sg2, NO_COLOR, facet_centroid,
                        normal, cell_coord, cell_start, column_first, column_table, column_mask,
                        &pairs STAGE_ARGS);
    else
        a = robust_sums(px, py, pz, ox, oy, oz, lo, hi, anchor, reach2, inv_2sf2, inv_2sg2,
                        (lanef)0.0f, 0, 0, RS_INFLUENCE_GAUSSIAN, inv_sg2, NO_COLOR, facet_centroid,
                        normal, cell_coord, cell_start, column_first, column_table, column_mask,
                        &pairs STAGE_ARGS);
#endif
    lanef kf = a.kf;
    uint rescue_pairs = 0;
    lanef shift = rescued_sums(&a, px, py, pz, ox, oy, oz, lo, hi, anchor, reach2, inv_2sf2,
                               inv_2sg2, influence, inv_sg2, predict_centroid, use_color, cr, cg,
                               cb, inv_2sc2, facet_color, facet_centroid, normal, cell_coord,
                               cell_start, column_first, column_table, column_mask, &rescue_pairs);
#undef NO_COLOR
#undef COLOR
    if (b >= block_count) /* the group variant's spare work-items */
        return;
    lanei some = a.k > 0.0f;
    __global float *out = block_result + 4 * RS_LANES * (size_t)b;
    store_lanes(select((lanef)0.0f, a.x / a.k, some), 0, out);
    store_lanes(select((lanef)0.0f, a.y / a.k, some), 1, out);
    store_lanes(select((lanef)0.0f, a.z / a.k, some), 2, out);
    store_lanes(a.k, 3, out);
    __global float *extra = block_extra + 2 * RS_LANES * (size_t)b;
    store_lanes(kf, 0, extra);
    store_lanes(shift, 1, extra);
    block_pairs[2 * (size_t)b + 1] = pairs + rescue_pairs;
}
