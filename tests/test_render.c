/* mesh_render draws what the camera sees: framing, flat shading, depth order, panels, colours. */
#include "mesh_render.h"
#include "mesh_shapes.h"
#include "test_util.h"

#include <stdbool.h>
#include <stdint.h>
#include <string.h>

static uint8_t *render(const render_mesh *meshes, size_t count, const render_options *o, int w,
                       int h) {
    uint8_t *rgb = malloc(3 * (size_t)w * (size_t)h);
    CHECK(rgb);
    CHECK_STATUS(mesh_render(meshes, count, o, rgb, w, h), 0);
    return rgb;
}

static const uint8_t *pixel(const uint8_t *rgb, int w, int x, int y) {
    return rgb + 3 * ((size_t)y * (size_t)w + (size_t)x);
}

static bool is_white(const uint8_t *p) {
    return p[0] == 255 && p[1] == 255 && p[2] == 255;
}

static render_mesh view_of(const shape_mesh *m, const uint8_t *colors) {
    render_mesh r = {m->xyz, m->vertex_count, m->indices, m->triangle_count, colors};
    return r;
}

/* Head-on orthographic: the cube's front face is a centred square filling 1 - 2 * margin of the
 * panel, flat (one colour inside), on an exactly white background. */
static void test_head_on_square(const shape_mesh *cube) {
    const int w = 200, h = 200;
    render_options o;
    render_options_default(&o);
    o.azimuth_deg = 0;
    o.elevation_deg = 0;
    o.orthographic = true;
    o.margin = 0.1;
    render_mesh m = view_of(cube, NULL);
    uint8_t *rgb = render(&m, 1, &o, w, h);
    int x0 = w, x1 = -1, y0 = h, y1 = -1;
    for (int y = 0; y < h; y++) {
        for (int x = 0; x < w; x++) {
            if (!is_white(pixel(rgb, w, x, y))) {
                x0 = x < x0 ? x : x0;
                x1 = x > x1 ? x : x1;
                y0 = y < y0 ? y : y0;
                y1 = y > y1 ? y : y1;
            }
        }
    }
    /* The square spans [20, 180) in pixels: 0.1 * 200 on each side. */
    CHECK_NEAR(x0, 20, 2);
    CHECK_NEAR(x1, 179, 2);
    CHECK_NEAR(y0, 20, 2);
    CHECK_NEAR(y1, 179, 2);
    /* Everything outside the square is background, exactly white. */
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            if (x < 18 || x > 181 || y < 18 || y > 181)
                CHECK(is_white(pixel(rgb, w, x, y)));
    /* Flat shading: the face is one colour, a light grey, away from its antialiased border. */
    const uint8_t *centre = pixel(rgb, w, 100, 100);
    CHECK(centre[0] == centre[1] && centre[1] == centre[2]);
    CHECK(centre[0] > 100 && centre[0] < 255);
    for (int y = 23; y <= 176; y++)
        for (int x = 23; x <= 176; x++)
            CHECK(memcmp(pixel(rgb, w, x, y), centre, 3) == 0);
    free(rgb);
}

/* The default 3/4 view shows three faces of the cube in three clearly different shades. */
static void test_three_shades(const shape_mesh *cube) {
    const int w = 300, h = 300;
    render_options o;
    render_options_default(&o);
    render_mesh m = view_of(cube, NULL);
    uint8_t *rgb = render(&m, 1, &o, w, h);
    uint8_t shades[8];
    size_t counts[8];
    int distinct = 0;
    size_t covered = 0;
    size_t histogram[256] = {0};
    for (int y = 0; y < h; y++) {
        for (int x = 0; x < w; x++) {
            const uint8_t *p = pixel(rgb, w, x, y);
            if (is_white(p))
                continue;
            CHECK(p[0] == p[1] && p[1] == p[2]); /* grey base colour */
            histogram[p[0]]++;
            covered++;
        }
    }
    CHECK(covered > (size_t)(w * h) / 4);
    size_t in_major = 0;
    for (int v = 0; v < 256; v++) {
        if (histogram[v] > covered / 20) { /* a face, not an antialiased edge */
            CHECK(distinct < 8);
            shades[distinct] = (uint8_t)v;
            counts[distinct++] = histogram[v];
            in_major += histogram[v];
        }
    }
    CHECK_EQ_INT(distinct, 3);
    CHECK(in_major > covered * 9 / 10);
    for (int i = 0; i < distinct; i++) {
        CHECK(counts[i] > 0);
        for (int j = i + 1; j < distinct; j++)
            CHECK(abs((int)shades[i] - (int)shades[j]) >= 15);
    }
    printf("default view shades: %d %d %d\n", shades[0], shades[1], shades[2]);
    free(rgb);
}

/* Two panels of the same mesh share one camera, so they are identical pixel for pixel. */
static void test_panels_identical(const shape_mesh *sphere) {
    render_options o;
    render_options_default(&o);
    const int pw = 150, h = 160, w = 2 * pw + o.gap;
    render_mesh m[2] = {view_of(sphere, NULL), view_of(sphere, NULL)};
    uint8_t *rgb = render(m, 2, &o, w, h);
    size_t covered = 0;
    for (int y = 0; y < h; y++) {
        CHECK(memcmp(pixel(rgb, w, 0, y), pixel(rgb, w, pw + o.gap, y), 3 * (size_t)pw) == 0);
        for (int x = 0; x < pw; x++)
            covered += !is_white(pixel(rgb, w, x, y));
        for (int x = pw; x < pw + o.gap; x++) /* the gap between them */
            CHECK(!is_white(pixel(rgb, w, x, y)));
    }
    CHECK(covered > (size_t)(pw * h) / 4);
    free(rgb);
}

/* Per-vertex colours tint the faces. */
static void test_vertex_colours(const shape_mesh *cube) {
    uint8_t *red = malloc(3 * cube->vertex_count);
    CHECK(red);
    for (size_t v = 0; v < cube->vertex_count; v++) {
        red[3 * v] = 255;
        red[3 * v + 1] = red[3 * v + 2] = 0;
    }
    const int w = 120, h = 120;
    render_options o;
    render_options_default(&o);
    render_mesh m = view_of(cube, red);
    uint8_t *rgb = render(&m, 1, &o, w, h);
    size_t reddish = 0, covered = 0;
    for (int y = 0; y < h; y++) {
        for (int x = 0; x < w; x++) {
            const uint8_t *p = pixel(rgb, w, x, y);
            if (is_white(p))
                continue;
            covered++;
            reddish += p[0] > 60 && p[1] < p[0] / 2 && p[1] == p[2];
        }
    }
    CHECK(covered > 0);
    CHECK(reddish > covered * 9 / 10);
    free(rgb);
    free(red);
}

/* A big grey cube and a small red one on the axis, in one mesh: the z-buffer, not the order of the
 * triangles, decides which shows. */
static void test_depth(const shape_mesh *big, const shape_mesh *small) {
    size_t nv = big->vertex_count + small->vertex_count;
    size_t nt = big->triangle_count + small->triangle_count;
    double *xyz = malloc(3 * nv * sizeof *xyz);
    uint32_t *tri = malloc(3 * nt * sizeof *tri);
    uint8_t *col = malloc(3 * nv);
    CHECK(xyz && tri && col);
    render_options o;
    render_options_default(&o);
    o.azimuth_deg = 0;
    o.elevation_deg = 0;
    const int w = 100, h = 100;
    for (int front = 0; front < 2; front++) {
        /* Behind: the small cube's triangles come last, where drawing in order would show it.
         * In front: they come first, where drawing in order would cover it. */
        size_t sv = 0, bv = small->vertex_count;
        size_t st = 0, bt = small->triangle_count;
        if (!front) {
            bv = 0;
            sv = big->vertex_count;
            bt = 0;
            st = big->triangle_count;
        }
        for (size_t v = 0; v < big->vertex_count; v++) {
            memcpy(xyz + 3 * (bv + v), big->xyz + 3 * v, 3 * sizeof *xyz);
            memset(col + 3 * (bv + v), 200, 3);
        }
        for (size_t v = 0; v < small->vertex_count; v++) {
            memcpy(xyz + 3 * (sv + v), small->xyz + 3 * v, 3 * sizeof *xyz);
            xyz[3 * (sv + v) + 2] += front ? 1.6 : -1.6;
            col[3 * (sv + v)] = 255;
            col[3 * (sv + v) + 1] = col[3 * (sv + v) + 2] = 0;
        }
        for (size_t i = 0; i < 3 * big->triangle_count; i++)
            tri[3 * bt + i] = big->indices[i] + (uint32_t)bv;
        for (size_t i = 0; i < 3 * small->triangle_count; i++)
            tri[3 * st + i] = small->indices[i] + (uint32_t)sv;
        render_mesh m = {xyz, nv, tri, nt, col};
        for (int ortho = 0; ortho < 2; ortho++) {
            o.orthographic = ortho;
            uint8_t *rgb = render(&m, 1, &o, w, h);
            size_t red = 0;
            for (int y = 0; y < h; y++)
                for (int x = 0; x < w; x++)
                    red += pixel(rgb, w, x, y)[0] > pixel(rgb, w, x, y)[1] + 8;
            if (front)
                CHECK(red > 50);
            else
                CHECK_EQ_INT(red, 0);
            free(rgb);
        }
    }
    free(xyz);
    free(tri);
    free(col);
}

/* Same input, same bytes; and arguments it cannot draw are refused. */
static void test_deterministic_and_arguments(const shape_mesh *cube, const shape_mesh *sphere) {
    render_options o;
    render_options_default(&o);
    render_mesh m[2] = {view_of(cube, NULL), view_of(sphere, NULL)};
    const int w = 250, h = 130;
    uint8_t *a = render(m, 2, &o, w, h);
    uint8_t *b = render(m, 2, &o, w, h);
    CHECK(memcmp(a, b, 3 * (size_t)w * (size_t)h) == 0);
    o.elevation_deg = 90; /* the view direction would be the up axis: no right vector */
    CHECK_STATUS(mesh_render(m, 2, &o, a, w, h), -1);
    render_options_default(&o);
    CHECK_STATUS(mesh_render(m, 2, &o, a, 0, h), -1);
    CHECK_STATUS(mesh_render(m, 0, &o, a, w, h), -1);
    uint32_t bad[3] = {0, 1, (uint32_t)cube->vertex_count};
    render_mesh broken = {cube->xyz, cube->vertex_count, bad, 1, NULL};
    CHECK_STATUS(mesh_render(&broken, 1, &o, a, w, h), -1);
    free(a);
    free(b);
}

int main(void) {
    shape_mesh cube, small, sphere;
    CHECK_STATUS(shape_cube(&cube, 2, 2.0), 0);
    CHECK_STATUS(shape_cube(&small, 1, 0.5), 0);
    CHECK_STATUS(shape_sphere(&sphere, 3, 1.0), 0);
    test_head_on_square(&cube);
    test_three_shades(&cube);
    test_panels_identical(&sphere);
    test_vertex_colours(&cube);
    test_depth(&cube, &small);
    test_deterministic_and_arguments(&cube, &sphere);
    shape_free(&cube);
    shape_free(&small);
    shape_free(&sphere);
    printf("render: all checks passed\n");
    return 0;
}
