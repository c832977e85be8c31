/* Analytic test shapes (plane, cube, sphere, capped cylinder) and deterministic normal noise. */
#include "mesh_shapes.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* ---- small helpers --------------------------------------------------------------------------- */

static int mesh_alloc(shape_mesh *mesh, size_t vertex_count, size_t triangle_count) {
    memset(mesh, 0, sizeof *mesh);
    if (vertex_count > SIZE_MAX / (3 * sizeof(double)) ||
        triangle_count > SIZE_MAX / (3 * sizeof(uint32_t)))
        return -1;
    mesh->xyz = malloc(vertex_count ? 3 * vertex_count * sizeof(double) : 1);
    mesh->indices = malloc(triangle_count ? 3 * triangle_count * sizeof(uint32_t) : 1);
    if (!mesh->xyz || !mesh->indices) {
        shape_free(mesh);
        return -1;
    }
    mesh->vertex_count = vertex_count;
    mesh->triangle_count = triangle_count;
    return 0;
}

void shape_free(shape_mesh *mesh) {
    if (!mesh)
        return;
    free(mesh->xyz);
    free(mesh->indices);
    memset(mesh, 0, sizeof *mesh);
}

static void set_vertex(shape_mesh *mesh, size_t v, double x, double y, double z) {
    mesh->xyz[3 * v] = x;
    mesh->xyz[3 * v + 1] = y;
    mesh->xyz[3 * v + 2] = z;
}

static void set_triangle(shape_mesh *mesh, size_t t, uint32_t a, uint32_t b, uint32_t c) {
    mesh->indices[3 * t] = a;
    mesh->indices[3 * t + 1] = b;
    mesh->indices[3 * t + 2] = c;
}

/* Open-addressing map from 64-bit keys to 32-bit values (UINT32_MAX marks an empty slot). */
typedef struct key_map {
    size_t mask;
    uint64_t *keys;
    uint32_t *values;
} key_map;

static int key_map_init(key_map *map, size_t expected) {
    size_t size = 16;
    while (size < 2 * expected)
        size *= 2;
    map->mask = size - 1;
    map->keys = malloc(size * sizeof *map->keys);
    map->values = malloc(size * sizeof *map->values);
    if (!map->keys || !map->values) {
        free(map->keys);
        free(map->values);
        return -1;
    }
    for (size_t i = 0; i < size; i++)
        map->values[i] = UINT32_MAX;
    return 0;
}

static void key_map_free(key_map *map) {
    free(map->keys);
    free(map->values);
}

static uint64_t mix64(uint64_t z) {
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* Value stored for key, or inserts `value` and returns it. */
static uint32_t key_map_get_or_insert(key_map *map, uint64_t key, uint32_t value, int *inserted) {
    size_t slot = (size_t)mix64(key) & map->mask;
    while (map->values[slot] != UINT32_MAX) {
        if (map->keys[slot] == key) {
            *inserted = 0;
            return map->values[slot];
        }
        slot = (slot + 1) & map->mask;
    }
    map->keys[slot] = key;
    map->values[slot] = value;
    *inserted = 1;
    return value;
}

/* ---- noise ----------------------------------------------------------------------------------- */

static uint64_t splitmix64(uint64_t *state) {
    *state += 0x9E3779B97F4A7C15ull;
    return mix64(*state);
}

double shape_gaussian(uint64_t *state) {
    /* Box-Muller; u1 in (0, 1] so the logarithm is finite. */
    double u1 = ((double)(splitmix64(state) >> 11) + 1.0) * 0x1.0p-53;
    double u2 = (double)(splitmix64(state) >> 11) * 0x1.0p-53;
    return sqrt(-2.0 * log(u1)) * cos(2.0 * M_PI * u2);
}

/* ---- plane ----------------------------------------------------------------------------------- */

int shape_plane(shape_mesh *mesh, int nx, int ny, double spacing) {
    if (!mesh)
        return -1;
    memset(mesh, 0, sizeof *mesh);
    if (nx < 1 || ny < 1 || !(spacing > 0) || !isfinite(spacing) || nx > 60000 || ny > 60000)
        return -1;
    size_t w = (size_t)nx + 1;
    if (mesh_alloc(mesh, w * ((size_t)ny + 1), 2 * (size_t)nx * (size_t)ny) != 0)
        return -1;
    for (size_t j = 0; j <= (size_t)ny; j++)
        for (size_t i = 0; i < w; i++)
            set_vertex(mesh, j * w + i, (double)i * spacing, (double)j * spacing, 0.0);
    size_t t = 0;
    for (size_t j = 0; j < (size_t)ny; j++)
        for (size_t i = 0; i < (size_t)nx; i++) {
            uint32_t v00 = (uint32_t)(j * w + i), v10 = v00 + 1;
            uint32_t v01 = (uint32_t)(v00 + w), v11 = v01 + 1;
            set_triangle(mesh, t++, v00, v10, v11);
            set_triangle(mesh, t++, v00, v11, v01);
        }
    return 0;
}

/* ---- cube ------------------------------------------------------------------------------------ */

int shape_cube(shape_mesh *mesh, int n, double size) {
    if (!mesh)
        return -1;
    memset(mesh, 0, sizeof *mesh);
    if (n < 1 || n > 10000 || !(size > 0) || !isfinite(size))
        return -1;
    size_t nn = (size_t)n, m = nn + 1;
    if (mesh_alloc(mesh, 6 * nn * nn + 2, 12 * nn * nn) != 0)
        return -1;
    key_map map;
    if (key_map_init(&map, 6 * m * m) != 0) {
        shape_free(mesh);
        return -1;
    }
    uint32_t *face_vertex = malloc(m * m * sizeof *face_vertex);
    if (!face_vertex) {
        key_map_free(&map);
        shape_free(mesh);
        return -1;
    }
    size_t v = 0, t = 0;
    for (int axis = 0; axis < 3; axis++)
        for (int side = 0; side < 2; side++) {
            /* (first, second) axes with first x second = outward normal (+/- axis). */
            int u = (axis + 1) % 3, w = (axis + 2) % 3;
            int first = side ? u : w, second = side ? w : u;
            for (size_t j = 0; j < m; j++)
                for (size_t i = 0; i < m; i++) {
                    size_t lattice[3];
                    lattice[axis] = side ? nn : 0;
                    lattice[first] = i;
                    lattice[second] = j;
                    uint64_t key = ((uint64_t)lattice[0] * m + lattice[1]) * m + lattice[2];
                    int inserted;
                    uint32_t id = key_map_get_or_insert(&map, key, (uint32_t)v, &inserted);
                    if (inserted) {
                        double p[3];
                        for (int k = 0; k < 3; k++)
                            p[k] = -size / 2 + size * (double)lattice[k] / (double)nn;
                        set_vertex(mesh, v, p[0], p[1], p[2]);
                        v++;
                    }
                    face_vertex[j * m + i] = id;
                }
            for (size_t j = 0; j < nn; j++)
                for (size_t i = 0; i < nn; i++) {
                    uint32_t a = face_vertex[j * m + i], b = face_vertex[j * m + i + 1];
                    uint32_t c = face_vertex[(j + 1) * m + i + 1], d = face_vertex[(j + 1) * m + i];
                    set_triangle(mesh, t++, a, b, c);
                    set_triangle(mesh, t++, a, c, d);
                }
        }
    free(face_vertex);
    key_map_free(&map);
    if (v != mesh->vertex_count) { /* cannot happen: 6n^2 + 2 surface lattice points */
        shape_free(mesh);
        return -1;
    }
    return 0;
}

/* ---- sphere ---------------------------------------------------------------------------------- */

static void normalize3(double *p) {
    double len = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    p[0] /= len;
    p[1] /= len;
    p[2] /= len;
}

int shape_sphere(shape_mesh *mesh, int levels, double radius) {
    if (!mesh)
        return -1;
    memset(mesh, 0, sizeof *mesh);
    if (levels < 0 || levels > 12 || !(radius > 0) || !isfinite(radius))
        return -1;
    static const uint32_t ico_f[20][3] = {
        {0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
        {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
        {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
    size_t final_v = 12, final_t = 20;
    for (int l = 0; l < levels; l++) {
        final_v += final_t * 3 / 2; /* one new vertex per edge; E = 3F/2 */
        final_t *= 4;
    }
    if (mesh_alloc(mesh, final_v, final_t) != 0)
        return -1;
    uint32_t *scratch = malloc(3 * final_t * sizeof *scratch);
    if (!scratch) {
        shape_free(mesh);
        return -1;
    }
    /* The icosahedron: cyclic permutations of (+-1, +-t, 0), t the golden ratio. */
    const double g = (1.0 + sqrt(5.0)) / 2.0;
    const double ico_v[12][3] = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0},
                                 {0, -1, g}, {0, 1, g}, {0, -1, -g}, {0, 1, -g},
                                 {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
    for (size_t i = 0; i < 12; i++) {
        double p[3] = {ico_v[i][0], ico_v[i][1], ico_v[i][2]};
        normalize3(p);
        set_vertex(mesh, i, p[0], p[1], p[2]);
    }
    for (size_t f = 0; f < 20; f++)
        set_triangle(mesh, f, ico_f[f][0], ico_f[f][1], ico_f[f][2]);
    size_t v = 12, t = 20;
    for (int l = 0; l < levels; l++) {
        key_map map;
        if (key_map_init(&map, t * 3 / 2) != 0) {
            free(scratch);
            shape_free(mesh);
            return -1;
        }
        memcpy(scratch, mesh->indices, 3 * t * sizeof *scratch);
        size_t out = 0;
        for (size_t f = 0; f < t; f++) {
            const uint32_t *c = scratch + 3 * f;
            uint32_t mid[3];
            for (int e = 0; e < 3; e++) {
                uint32_t a = c[e], b = c[(e + 1) % 3];
                uint64_t key = a < b ? (uint64_t)a << 32 | b : (uint64_t)b << 32 | a;
                int inserted;
                mid[e] = key_map_get_or_insert(&map, key, (uint32_t)v, &inserted);
                if (inserted) {
                    double p[3];
                    for (int k = 0; k < 3; k++)
                        p[k] = 0.5 * (mesh->xyz[3 * (size_t)a + k] + mesh->xyz[3 * (size_t)b + k]);
                    normalize3(p);
                    set_vertex(mesh, v, p[0], p[1], p[2]);
                    v++;
                }
            }
            /* mid[0] on edge c0-c1, mid[1] on c1-c2, mid[2] on c2-c0 */
            set_triangle(mesh, out++, c[0], mid[0], mid[2]);
            set_triangle(mesh, out++, mid[0], c[1], mid[1]);
            set_triangle(mesh, out++, mid[2], mid[1], c[2]);
            set_triangle(mesh, out++, mid[0], mid[1], mid[2]);
        }
        key_map_free(&map);
        t = out;
    }
    free(scratch);
    for (size_t i = 0; i < 3 * v; i++)
        mesh->xyz[i] *= radius;
    return 0;
}

/* ---- capped cylinder ------------------------------------------------------------------------- */

/* Stitches ring A (na vertices from a0, angles offset_a + 2 pi i / na) to ring B (nb vertices from
 * b0) with na + nb triangles, walking both by increasing angle. Unflipped, (B_j, B_j+1, A_i) is
 * counter-clockwise seen from the side where A is "inside" (the cap's +z, or outside the side wall
 * when A is the upper ring). Returns the next triangle slot. */
static size_t stitch_rings(shape_mesh *mesh, size_t t, uint32_t a0, size_t na, double offset_a,
                           uint32_t b0, size_t nb, double offset_b, int flip) {
    size_t i = 0, j = 0;
    while (i < na || j < nb) {
        double next_a = offset_a + 2 * M_PI * (double)(i + 1) / (double)na;
        double next_b = offset_b + 2 * M_PI * (double)(j + 1) / (double)nb;
        uint32_t ai = a0 + (uint32_t)(i % na), bj = b0 + (uint32_t)(j % nb);
        int advance_a = j == nb || (i < na && next_a < next_b);
        uint32_t tri[3];
        if (advance_a) {
            tri[0] = ai;
            tri[1] = bj;
            tri[2] = a0 + (uint32_t)((i + 1) % na);
            i++;
        } else {
            tri[0] = bj;
            tri[1] = b0 + (uint32_t)((j + 1) % nb);
            tri[2] = ai;
            j++;
        }
        if (flip)
            set_triangle(mesh, t++, tri[0], tri[2], tri[1]);
        else
            set_triangle(mesh, t++, tri[0], tri[1], tri[2]);
    }
    return t;
}

int shape_capped_cylinder(shape_mesh *mesh, double radius, double height, size_t target_triangles) {
    if (!mesh)
        return -1;
    memset(mesh, 0, sizeof *mesh);
    if (!(radius > 0) || !isfinite(radius) || !(height > 0) || !isfinite(height) ||
        target_triangles < 1 || target_triangles > 100000000)
        return -1;
    /* Edge length e of equilateral triangles tiling the surface with about target triangles. */
    double area = 2 * M_PI * radius * height + 2 * M_PI * radius * radius;
    double e = sqrt(area / ((double)target_triangles * sqrt(3.0) / 4));
    size_t segments = (size_t)fmax(3.0, round(2 * M_PI * radius / e));
    /* Rows of the side: staggered rings are sqrt(3)/2 e apart in equilateral tiling. */
    size_t rows = (size_t)fmax(1.0, round(height / (e * sqrt(3.0) / 2)));
    size_t cap_rings = (size_t)fmax(1.0, round(radius / (e * sqrt(3.0) / 2)));
    /* ring j of a cap (1 <= j < cap_rings) at radius r j / cap_rings */
    size_t *ring_n = malloc((cap_rings + 1) * sizeof *ring_n);
    if (!ring_n)
        return -1;
    size_t cap_vertices = 1, cap_triangles = 0;
    ring_n[0] = 1;
    for (size_t j = 1; j <= cap_rings; j++) {
        ring_n[j] =
            j == cap_rings
                ? segments
                : (size_t)fmax(3.0, round((double)segments * (double)j / (double)cap_rings));
        if (j < cap_rings)
            cap_vertices += ring_n[j];
        cap_triangles += j == 1 ? ring_n[1] : ring_n[j - 1] + ring_n[j];
    }
    size_t side_vertices = (rows + 1) * segments;
    if (mesh_alloc(mesh, side_vertices + 2 * cap_vertices,
                   2 * rows * segments + 2 * cap_triangles) != 0) {
        free(ring_n);
        return -1;
    }
    const double step = 2 * M_PI / (double)segments;
    size_t v = 0;
    for (size_t k = 0; k <= rows; k++) {
        double z = -height / 2 + height * (double)k / (double)rows;
        double offset = (double)(k % 2) * step / 2;
        for (size_t s = 0; s < segments; s++) {
            double a = offset + step * (double)s;
            set_vertex(mesh, v++, radius * cos(a), radius * sin(a), z);
        }
    }
    size_t t = 0;
    for (size_t k = 0; k < rows; k++)
        t = stitch_rings(mesh, t, (uint32_t)((k + 1) * segments), segments,
                         (double)((k + 1) % 2) * step / 2, (uint32_t)(k * segments), segments,
                         (double)(k % 2) * step / 2, 0);
    for (int cap = 0; cap < 2; cap++) {
        /* cap 0: bottom (z = -h/2, outward -z, flipped); cap 1: top (outward +z) */
        double z = cap ? height / 2 : -height / 2;
        size_t outer_ring = cap ? rows : 0;
        uint32_t center = (uint32_t)v;
        set_vertex(mesh, v++, 0, 0, z);
        uint32_t prev_start = center;
        size_t prev_n = 1;
        double prev_offset = 0;
        for (size_t j = 1; j <= cap_rings; j++) {
            uint32_t start;
            double offset;
            if (j == cap_rings) {
                start = (uint32_t)(outer_ring * segments);
                offset = (double)(outer_ring % 2) * step / 2;
            } else {
                start = (uint32_t)v;
                offset = (double)(j % 2) * M_PI / (double)ring_n[j];
                double r = radius * (double)j / (double)cap_rings;
                for (size_t s = 0; s < ring_n[j]; s++) {
                    double a = offset + 2 * M_PI * (double)s / (double)ring_n[j];
                    set_vertex(mesh, v++, r * cos(a), r * sin(a), z);
                }
            }
            if (j == 1) { /* fan around the centre */
                for (size_t s = 0; s < ring_n[j]; s++) {
                    uint32_t b = start + (uint32_t)s, c = start + (uint32_t)((s + 1) % ring_n[j]);
                    if (cap)
                        set_triangle(mesh, t++, b, c, center);
                    else
                        set_triangle(mesh, t++, c, b, center);
                }
            } else {
                t = stitch_rings(mesh, t, prev_start, prev_n, prev_offset, start, ring_n[j], offset,
                                 !cap);
            }
            prev_start = start;
            prev_n = ring_n[j];
            prev_offset = offset;
        }
    }
    free(ring_n);
    if (v != mesh->vertex_count || t != mesh->triangle_count) { /* cannot happen */
        shape_free(mesh);
        return -1;
    }
    return 0;
}

/* ---- measures and transforms ----------------------------------------------------------------- */

static void face_cross(const double *xyz, const uint32_t *tri, double n[3]) {
    const double *a = xyz + 3 * (size_t)tri[0], *b = xyz + 3 * (size_t)tri[1],
                 *c = xyz + 3 * (size_t)tri[2];
    double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
}

int shape_vertex_normals(const shape_mesh *mesh, double *normals) {
    if (!mesh || !normals || (mesh->vertex_count && !mesh->xyz) ||
        (mesh->triangle_count && !mesh->indices))
        return -1;
    memset(normals, 0, 3 * mesh->vertex_count * sizeof *normals);
    for (size_t t = 0; t < mesh->triangle_count; t++) {
        const uint32_t *tri = mesh->indices + 3 * t;
        if (tri[0] >= mesh->vertex_count || tri[1] >= mesh->vertex_count ||
            tri[2] >= mesh->vertex_count)
            return -1;
        double n[3]; /* |cross| = 2 area: area weighting for free */
        face_cross(mesh->xyz, tri, n);
        for (int c = 0; c < 3; c++)
            for (int k = 0; k < 3; k++)
                normals[3 * (size_t)tri[c] + k] += n[k];
    }
    for (size_t v = 0; v < mesh->vertex_count; v++) {
        double *n = normals + 3 * v;
        double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (int k = 0; k < 3; k++)
            n[k] = len > 0 ? n[k] / len : 0;
    }
    return 0;
}

static int compare_u64(const void *a, const void *b) {
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

/* NAN on allocation failure; 0 when there is no edge. An edge is an unordered pair of distinct
 * indices; repeated pairs count once. */
double shape_mean_edge_length(const shape_mesh *mesh) {
    if (!mesh || mesh->triangle_count == 0)
        return 0;
    uint64_t *keys = malloc(3 * mesh->triangle_count * sizeof *keys);
    if (!keys)
        return NAN;
    size_t n = 0;
    for (size_t t = 0; t < mesh->triangle_count; t++)
        for (int e = 0; e < 3; e++) {
            uint32_t a = mesh->indices[3 * t + e], b = mesh->indices[3 * t + (e + 1) % 3];
            if (a == b)
                continue;
            keys[n++] = a < b ? (uint64_t)a << 32 | b : (uint64_t)b << 32 | a;
        }
    qsort(keys, n, sizeof *keys, compare_u64);
    double sum = 0;
    size_t unique = 0;
    for (size_t i = 0; i < n; i++) {
        if (i > 0 && keys[i] == keys[i - 1])
            continue;
        const double *a = mesh->xyz + 3 * (size_t)(keys[i] >> 32);
        const double *b = mesh->xyz + 3 * (size_t)(keys[i] & 0xffffffffu);
        double d[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
        sum += sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        unique++;
    }
    free(keys);
    return unique ? sum / (double)unique : 0;
}

int shape_add_normal_noise(shape_mesh *mesh, double sigma, uint64_t seed) {
    if (!mesh || !(sigma >= 0) || !isfinite(sigma))
        return -1;
    if (mesh->vertex_count == 0)
        return 0;
    double *normals = malloc(3 * mesh->vertex_count * sizeof *normals);
    if (!normals)
        return -1;
    double scale = sigma * shape_mean_edge_length(mesh);
    if (shape_vertex_normals(mesh, normals) != 0 || !isfinite(scale)) {
        free(normals);
        return -1;
    }
    uint64_t state = seed;
    for (size_t v = 0; v < mesh->vertex_count; v++) {
        double g = shape_gaussian(&state); /* drawn for every vertex: same stream for any mesh */
        for (int k = 0; k < 3; k++)
            mesh->xyz[3 * v + k] += scale * g * normals[3 * v + k];
    }
    free(normals);
    return 0;
}

int shape_unindex(const shape_mesh *in, shape_mesh *out) {
    if (!out)
        return -1;
    memset(out, 0, sizeof *out);
    if (!in || in->triangle_count > UINT32_MAX / 3)
        return -1;
    size_t tc = in->triangle_count;
    for (size_t i = 0; i < 3 * tc; i++)
        if (in->indices[i] >= in->vertex_count)
            return -1;
    if (mesh_alloc(out, 3 * tc, tc) != 0)
        return -1;
    for (size_t i = 0; i < 3 * tc; i++) {
        memcpy(out->xyz + 3 * i, in->xyz + 3 * (size_t)in->indices[i], 3 * sizeof(double));
        out->indices[i] = (uint32_t)i;
    }
    return 0;
}

int shape_copy(const shape_mesh *in, shape_mesh *out) {
    if (!out)
        return -1;
    memset(out, 0, sizeof *out);
    if (!in || mesh_alloc(out, in->vertex_count, in->triangle_count) != 0)
        return -1;
    if (in->vertex_count)
        memcpy(out->xyz, in->xyz, 3 * in->vertex_count * sizeof(double));
    if (in->triangle_count)
        memcpy(out->indices, in->indices, 3 * in->triangle_count * sizeof(uint32_t));
    return 0;
}

double shape_face_normal_error_deg(const shape_mesh *mesh, const double *other_xyz) {
    if (!mesh || !other_xyz)
        return NAN;
    double sum = 0;
    size_t count = 0;
    for (size_t t = 0; t < mesh->triangle_count; t++) {
        const uint32_t *tri = mesh->indices + 3 * t;
        double a[3], b[3];
        face_cross(mesh->xyz, tri, a);
        face_cross(other_xyz, tri, b);
        double la = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
        double lb = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
        if (!(la > 0) || !(lb > 0))
            continue;
        double c[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                       a[0] * b[1] - a[1] * b[0]};
        double sine = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
        double cosine = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        sum += atan2(sine, cosine) * (180.0 / M_PI);
        count++;
    }
    return count ? sum / (double)count : 0;
}
