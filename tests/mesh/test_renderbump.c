/* test_renderbump.c: the flat render bump (DOOM 3's RenderBumpFlat) against
 * bumpbake's own normal estimators, analytic sphere normals, holes, edges,
 * tiling, axes and thread counts; meshes round-tripped through Assimp. */
#define _XOPEN_SOURCE 700 /* mkdtemp, nftw */

#include <criterion/criterion.h>

#include <ftw.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "bumpbake.h"
#include "bake/bake_internal.h"
#include "mesh/mesh_internal.h"

#define PI 3.14159265358979323846

/* ---------------------------------------------------------- mesh making */

/* A surface over a lattice of nx x nz cells on [x0, x1] x [z0, z1] of the
 * model's XZ plane, facing -Y (DOOM 3's side): the vertex at (x, z) is
 * (x, -depth(x, z), z). */
typedef struct lattice {
  int nx, nz;
  double x0, x1, z0, z1;
  double (*depth)(const void *ctx, double x, double z);
  /* Model-space normal at (x, z) into n; NULL for a mesh without normals. */
  void (*normal)(const void *ctx, double x, double z, float n[3]);
  /* 1 for a cell (i, k) to leave out (a hole); NULL keeps every cell. */
  int (*skip)(const void *ctx, int i, int k);
  const void *ctx;
} lattice;

static void make_lattice(const lattice *l, bb_mesh *m) {
  size_t vx = (size_t)l->nx + 1, vz = (size_t)l->nz + 1;
  size_t cells = 0;
  for (int k = 0; k < l->nz; k++)
    for (int i = 0; i < l->nx; i++)
      cells += !(l->skip && l->skip(l->ctx, i, k));
  bb_error err = {{0}};
  cr_assert_eq(bb__mesh_alloc(m, vx * vz, 2 * cells, l->normal != NULL, &err), BB_OK, "%s",
               err.message);
  for (size_t k = 0; k < vz; k++)
    for (size_t i = 0; i < vx; i++) {
      double x = l->x0 + (l->x1 - l->x0) * (double)i / l->nx;
      double z = l->z0 + (l->z1 - l->z0) * (double)k / l->nz;
      float *p = m->positions + 3 * (k * vx + i);
      p[0] = (float)x, p[1] = (float)-l->depth(l->ctx, x, z), p[2] = (float)z;
      if (l->normal)
        l->normal(l->ctx, x, z, m->normals + 3 * (k * vx + i));
    }
  /* Cell (i, k) as bumpbake's height-field mesh splits it, seen along -y
   * with rows k counted downwards from the top (z1): corners (i, k) ..
   * (i+1, k+1) in image order, split along (i+1, top)-(i, bottom). */
  uint32_t *t = m->indices;
  for (int k = 0; k < l->nz; k++)
    for (int i = 0; i < l->nx; i++) {
      if (l->skip && l->skip(l->ctx, i, k))
        continue;
      uint32_t top = (uint32_t)(((size_t)l->nz - (size_t)k) * vx), bottom = top - (uint32_t)vx;
      uint32_t v00 = top + (uint32_t)i, v10 = v00 + 1, v01 = bottom + (uint32_t)i,
               v11 = v01 + 1;
      uint32_t tri[6] = {v00, v10, v01, v10, v11, v01};
      memcpy(t, tri, sizeof tri);
      t += 6;
    }
}

static void render(const bb_mesh *m, const bb_renderbump_options *o, bb_renderbump_result *r) {
  bb_error err = {{0}};
  cr_assert_eq(bb__renderbump_flat(m, o, r, &err), BB_OK, "%s", err.message);
  cr_assert_eq(r->normal.channels, 4);
  cr_assert_eq(r->normal.width, o->width);
  cr_assert_eq(r->height.channels, 1);
}

static double angle_degrees(const float *a, const float *b) {
  double d = (double)a[0] * b[0] + (double)a[1] * b[1] + (double)a[2] * b[2];
  return acos(fmin(1.0, fmax(-1.0, d))) * 180.0 / PI;
}

static int same_pixels(const bb_image *a, const bb_image *b) {
  size_t n = (size_t)a->width * (size_t)a->height * (size_t)a->channels;
  return a->width == b->width && a->height == b->height && a->channels == b->channels &&
         memcmp(a->pixels, b->pixels, n * sizeof(float)) == 0;
}

/* ------------------------------------------- a height field as a grid mesh */

/* h(x, y) = 0.5 + 0.25 sin(2 pi x / 48) cos(2 pi y / 24), periodic in 48;
 * at scale 6 its slopes reach 21 degrees. */
enum { GRID = 48 };
static const double GRID_SCALE = 6.0;

static double wave(double x, double y) {
  return 0.5 + 0.25 * sin(2.0 * PI * x / 48.0) * cos(2.0 * PI * y / 24.0);
}

static void wave_image(bb_image *h) {
  cr_assert_eq(bb_image_alloc(h, GRID, GRID, 1, NULL), BB_OK);
  for (int y = 0; y < GRID; y++)
    for (int x = 0; x < GRID; x++)
      *bb_image_texel(h, x, y) = (float)wave(x, y);
}

/* Texel (x, y) of the height is the vertex (x, -S h, -y): image columns run
 * along +X and rows down -Z, as DOOM 3 projects. */
static double wave_depth(const void *ctx, double x, double z) {
  (void)ctx;
  return GRID_SCALE * (double)(float)wave(x, -z);
}

/* The central-difference normal of the stored heights at a vertex, as
 * bb__normals_compute_all_cores's central estimator makes it, turned to model space:
 * tangent (tx, ty, tz) = model (tx, -tz, -ty). */
static void wave_central_normal(const void *ctx, double x, double z, float n[3]) {
  (void)ctx;
  double y = -z;
  double tx = -GRID_SCALE * ((float)wave(x + 1, y) - (float)wave(x - 1, y)) / 2.0;
  double ty = -GRID_SCALE * ((float)wave(x, y + 1) - (float)wave(x, y - 1)) / 2.0;
  double len = sqrt(tx * tx + ty * ty + 1.0);
  n[0] = (float)(tx / len), n[1] = (float)(-1.0 / len), n[2] = (float)(-ty / len);
}

static void wave_mesh(bb_mesh *m, int with_normals) {
  lattice l = {GRID, GRID, 0.0, GRID, -GRID, 0.0, wave_depth,
               with_normals ? wave_central_normal : NULL, NULL, NULL};
  make_lattice(&l, m);
}

/* Angles (degrees) between a render and bb__normals_compute_all_cores's estimate of
 * the wave with filter f: the largest and the mean over all texels. */
static void angle_to_estimator(const bb_renderbump_result *r, bb_normal_filter f,
                               double *max_deg, double *mean_deg) {
  bb_image h = {0}, expected = {0};
  wave_image(&h);
  cr_assert_eq(bb__normals_compute_all_cores(&h, (float)GRID_SCALE, f, BB_ADDRESS_PERIODIC, &expected,
                                  NULL),
               BB_OK);
  double sum = 0.0;
  *max_deg = 0.0;
  for (int y = 0; y < GRID; y++)
    for (int x = 0; x < GRID; x++) {
      double a =
          angle_degrees(bb_image_texel(&r->normal, x, y), bb_image_texel(&expected, x, y));
      sum += a;
      *max_deg = fmax(*max_deg, a);
    }
  *mean_deg = sum / (GRID * GRID);
  bb_image_free(&expected);
  bb_image_free(&h);
}

/* The render is within the bounds of the matching estimator and at least
 * 3x closer to it (in the mean) than to the other one. */
static void expect_estimator(const bb_renderbump_result *r, bb_normal_filter match,
                             bb_normal_filter other, double max_bound, double mean_bound) {
  double max_deg, mean_deg, max_other, mean_other;
  angle_to_estimator(r, match, &max_deg, &mean_deg);
  angle_to_estimator(r, other, &max_other, &mean_other);
  cr_assert_lt(max_deg, max_bound, "%s: max %.3f degrees", bb__normal_filter_name(match),
               max_deg);
  cr_assert_lt(mean_deg, mean_bound, "%s: mean %.3f degrees", bb__normal_filter_name(match),
               mean_deg);
  cr_assert_gt(mean_other, 3.0 * mean_deg, "%s %.3f vs %s %.3f", bb__normal_filter_name(other),
               mean_other, bb__normal_filter_name(match), mean_deg);
}

/* Face normals, texels on the cells: each texel averages the two triangles
 * of its cell, centred at (x + 1/2, y + 1/2) as Valve's estimator (the mean
 * over the 9 cells around that point) is. The two differ by the 3x3 cell
 * blur of the Valve estimate: measured 0.72 degrees at most, 0.39 mean (the
 * blur's share grows with curvature: 1.7 degrees at half the wavelengths).
 * Central differences, centred half a texel away, are 4x further off. */
Test(renderbump, face_normals_of_a_height_grid_match_the_valve_estimator) {
  bb_mesh m;
  wave_mesh(&m, 0);
  bb_renderbump_options o;
  bb__renderbump_options_init(&o);
  o.width = o.height = GRID;
  bb_renderbump_result r;
  render(&m, &o, &r);
  cr_assert_eq(r.used_vertex_normals, 0);
  expect_estimator(&r, BB_NORMAL_VALVE, BB_NORMAL_CENTRAL, 0.8, 0.45);
  for (int i = 0; i < GRID * GRID; i++)
    cr_assert_eq(r.normal.pixels[4 * i + 3], 1.0f, "the grid covers every texel");
  bb_renderbump_result_free(&r);
  bb__mesh_free(&m);
}

/* Vertex normals (the central differences), texels on the vertices: the
 * rectangle is shifted half a texel and the border half-cells come from the
 * other side by tile. Each texel averages the interpolated normals around
 * its vertex: measured 0.21 degrees at most, 0.12 mean, from central; Valve
 * (centred half a texel away) is 10x further off. The height, mapped back
 * to model units with the result's depth range, is the vertex height within
 * 0.02 texels. */
Test(renderbump, vertex_normals_of_a_tiled_grid_match_central_differences) {
  bb_mesh m;
  wave_mesh(&m, 1);
  bb_renderbump_options o;
  bb__renderbump_options_init(&o);
  o.width = o.height = GRID;
  o.rect_given = 1;
  o.tile = 1;
  double rect[4] = {-0.5, -GRID + 0.5, GRID - 0.5, 0.5};
  memcpy(o.rect, rect, sizeof rect);
  bb_renderbump_result r;
  render(&m, &o, &r);
  cr_assert_eq(r.used_vertex_normals, 1);
  expect_estimator(&r, BB_NORMAL_CENTRAL, BB_NORMAL_VALVE, 0.25, 0.15);

  cr_assert_float_eq(r.texel_size, 1.0, 1e-12);
  double worst = 0.0;
  for (int y = 0; y < GRID; y++)
    for (int x = 0; x < GRID; x++) {
      double depth = r.depth_min + *bb_image_texel(&r.height, x, y) * r.height_scale;
      worst = fmax(worst, fabs(depth - wave_depth(NULL, x, -y)));
    }
  cr_assert_lt(worst, 0.02, "height off by %.4f texels", worst);
  cr_assert_float_eq(r.height_scale, r.depth_max - r.depth_min, 1e-9);
  bb_renderbump_result_free(&r);
  bb__mesh_free(&m);
}

/* --------------------------------------------------------- sphere cap */

static const double SPHERE_R = 1.5;

static double cap_depth(const void *ctx, double x, double z) {
  (void)ctx;
  return sqrt(SPHERE_R * SPHERE_R - x * x - z * z);
}

static void cap_normal(const void *ctx, double x, double z, float n[3]) {
  n[0] = (float)(x / SPHERE_R);
  n[1] = (float)(-cap_depth(ctx, x, z) / SPHERE_R);
  n[2] = (float)(z / SPHERE_R);
}

static void cap_mesh(bb_mesh *m, int with_normals) {
  lattice l = {40, 40, -1.0, 1.0, -1.0, 1.0, cap_depth, with_normals ? cap_normal : NULL,
               NULL, NULL};
  make_lattice(&l, m);
}

/* Worst component error against the analytic normal at the texel centres
 * of a 32 x 32 render of the cap over [-1, 1]^2 (tangent: x/R, -z/R, d/R). */
static double cap_error(const bb_renderbump_result *r) {
  double worst = 0.0;
  for (int j = 0; j < 32; j++)
    for (int i = 0; i < 32; i++) {
      double x = -1.0 + (i + 0.5) / 16.0, z = 1.0 - (j + 0.5) / 16.0;
      double expect[3] = {x / SPHERE_R, -z / SPHERE_R, cap_depth(NULL, x, z) / SPHERE_R};
      const float *n = bb_image_texel(&r->normal, i, j);
      for (int c = 0; c < 3; c++)
        worst = fmax(worst, fabs(n[c] - expect[c]));
    }
  return worst;
}

/* Interpolated analytic vertex normals reproduce the sphere within 0.004
 * per component (measured 0.0028, at the corners, where the cap is
 * steepest); plane normals, faceted, within 0.025 (measured 0.017) but not
 * within the vertex normals' bound. */
Test(renderbump, sphere_cap_gives_its_analytic_normals) {
  bb_renderbump_options o;
  bb__renderbump_options_init(&o);
  o.width = o.height = 32;
  bb_mesh smooth, faceted;
  cap_mesh(&smooth, 1);
  cap_mesh(&faceted, 0);
  bb_renderbump_result rs, rf;
  render(&smooth, &o, &rs);
  render(&faceted, &o, &rf);
  double es = cap_error(&rs), ef = cap_error(&rf);
  cr_assert_lt(es, 0.004, "vertex normals: %.5f", es);
  cr_assert_lt(ef, 0.025, "face normals: %.5f", ef);
  cr_assert_gt(ef, 0.004, "face normals should be faceted: %.5f", ef);

  /* --face-normals makes the smooth mesh faceted too, identically. */
  o.face_normals = 1;
  bb_renderbump_result rff;
  render(&smooth, &o, &rff);
  cr_assert(same_pixels(&rff.normal, &rf.normal));
  cr_assert_eq(rff.used_vertex_normals, 0);
  bb_renderbump_result_free(&rff);
  bb_renderbump_result_free(&rs);
  bb_renderbump_result_free(&rf);
  bb__mesh_free(&smooth);
  bb__mesh_free(&faceted);
}

/* The front-most surface is taken whatever the winding, and vertex normals
 * pointing away from the viewer as a whole are turned round: reversing
 * every triangle, or negating every normal, changes nothing. */
Test(renderbump, winding_and_normal_sign_do_not_matter) {
  bb_renderbump_options o;
  bb__renderbump_options_init(&o);
  o.width = o.height = 24;
  bb_mesh m;
  cap_mesh(&m, 1);
  bb_renderbump_result base, other;
  render(&m, &o, &base);
  for (size_t t = 0; t < m.triangle_count; t++) {
    uint32_t swap = m.indices[3 * t + 1];
    m.indices[3 * t + 1] = m.indices[3 * t + 2];
    m.indices[3 * t + 2] = swap;
  }
  render(&m, &o, &other);
  cr_assert(same_pixels(&base.normal, &other.normal), "reversed winding");
  bb_renderbump_result_free(&other);
  for (size_t i = 0; i < 3 * m.vertex_count; i++)
    m.normals[i] = -m.normals[i];
  render(&m, &o, &other);
  cr_assert(same_pixels(&base.normal, &other.normal), "negated normals");
  cr_assert(same_pixels(&base.height, &other.height));
  bb_renderbump_result_free(&other);
  bb_renderbump_result_free(&base);
  bb__mesh_free(&m);
}

/* ------------------------------------------------------------- coverage */

static double flat_depth(const void *ctx, double x, double z) {
  (void)ctx, (void)x, (void)z;
  return 0.0;
}

/* A 4 x 4 cell hole at cells 6..9 of a 16 x 16 plane. */
static int hole_cells(const void *ctx, int i, int k) {
  (void)ctx;
  return i >= 6 && i <= 9 && k >= 6 && k <= 9;
}

static void hole_mesh(bb_mesh *m) {
  lattice l = {16, 16, 0.0, 16.0, -16.0, 0.0, flat_depth, NULL, hole_cells, NULL};
  make_lattice(&l, m);
}

Test(renderbump, a_hole_has_alpha_0_and_the_rest_1) {
  bb_mesh m;
  hole_mesh(&m);
  bb_renderbump_options o;
  bb__renderbump_options_init(&o);
  o.width = o.height = 16;
  bb_renderbump_result r;
  render(&m, &o, &r);
  for (int y = 0; y < 16; y++)
    for (int x = 0; x < 16; x++) {
      const float *p = bb_image_texel(&r.normal, x, y);
      int in_hole = hole_cells(NULL, x, y);
      cr_assert_eq(p[3], in_hole ? 0.0f : 1.0f, "alpha at (%d, %d): %g", x, y, (double)p[3]);
      cr_assert(p[0] == 0.0f && p[1] == 0.0f && p[2] == 1.0f, "flat (0, 0, 1) everywhere");
      cr_assert_eq(*bb_image_texel(&r.height, x, y), 0.0f);
    }
  cr_assert_eq(r.height_scale, 0.0, "a flat plane has no height");
  bb_renderbump_result_free(&r);
  bb__mesh_free(&m);
}

/* Covered fraction of texel (i, j) of a 32 x 32 image of [0, 32]^2 under
 * the line z = 5 + 0.3 x, by a fine midpoint sum (error < 1e-4). */
static double exact_coverage(int i, int j) {
  double z_low = 31 - j, sum = 0.0;
  for (int s = 0; s < 4096; s++) {
    double x = i + (s + 0.5) / 4096.0;
    sum += fmin(1.0, fmax(0.0, 5.0 + 0.3 * x - z_low));
  }
  return sum / 4096.0;
}

/* A quad (corners in order, XZ plane) and options rendering the square
 * [0, side]^2 of X and Z onto side x side texels. */
static void quad_scene(const float corners[12], int side, bb_mesh *m,
                       bb_renderbump_options *o) {
  static const uint32_t tris[6] = {0, 1, 2, 0, 2, 3};
  cr_assert_eq(bb__mesh_alloc(m, 4, 2, 0, NULL), BB_OK);
  memcpy(m->positions, corners, 12 * sizeof(float));
  memcpy(m->indices, tris, sizeof tris);
  bb__renderbump_options_init(o);
  o->width = o->height = side;
  o->rect_given = 1;
  double rect[4] = {0, 0, side, side};
  memcpy(o->rect, rect, sizeof rect);
}

static void coverage_errors(int samples, double *max_err, double *mean_err) {
  static const float quad[12] = {0, 0, 0, 32, 0, 0, 32, 0, 14.6f, 0, 0, 5};
  bb_mesh m;
  bb_renderbump_options o;
  quad_scene(quad, 32, &m, &o);
  o.samples = samples;
  bb_renderbump_result r;
  render(&m, &o, &r);
  *max_err = *mean_err = 0.0;
  for (int j = 0; j < 32; j++)
    for (int i = 0; i < 32; i++) {
      double e = fabs(bb_image_texel(&r.normal, i, j)[3] - exact_coverage(i, j));
      *max_err = fmax(*max_err, e);
      *mean_err += e / (32 * 32);
    }
  bb_renderbump_result_free(&r);
  bb__mesh_free(&m);
}

/* One sample per texel gives alpha 0 or 1 along a slanted edge (errors up
 * to 0.5 and more); 4 x 4 samples follow the exact coverage within 1/16
 * plus the sampling error of a straight edge. */
Test(renderbump, oversampling_smooths_an_edge_that_one_sample_aliases) {
  double max1, mean1, max16, mean16;
  coverage_errors(1, &max1, &mean1);
  coverage_errors(4, &max16, &mean16);
  cr_assert_gt(max1, 0.4, "1x: max %.3f", max1);
  cr_assert_lt(max16, 0.09, "16x: max %.3f", max16);
  cr_assert_lt(mean16, mean1 / 3.0, "16x mean %.4f vs 1x mean %.4f", mean16, mean1);
}

/* ---------------------------------------------------------------- tiling */

/* A 2 x 2 square straddling the right edge of an 8 x 8 rectangle: clipped
 * without tile, wrapped onto the left edge with it. */
Test(renderbump, tile_wraps_what_crosses_the_edges) {
  static const float square[12] = {7, 0, 3, 9, 0, 3, 9, 0, 5, 7, 0, 5};
  bb_mesh m;
  bb_renderbump_options o;
  quad_scene(square, 8, &m, &o);
  for (int tile = 0; tile < 2; tile++) {
    o.tile = tile;
    bb_renderbump_result r;
    render(&m, &o, &r);
    for (int y = 0; y < 8; y++)
      for (int x = 0; x < 8; x++) {
        /* rows 3 and 4 hold z in [3, 5] */
        int covered = (y == 3 || y == 4) && (x == 7 || (tile && x == 0));
        cr_assert_eq(bb_image_texel(&r.normal, x, y)[3], covered ? 1.0f : 0.0f,
                     "tile %d, texel (%d, %d)", tile, x, y);
      }
    cr_assert_eq(r.triangles_drawn, tile ? 4u : 2u, "tile copies");
    bb_renderbump_result_free(&r);
  }
  bb__mesh_free(&m);
}

/* ----------------------------------------------------------------- axes */

Test(renderbump, axis_names_and_frames) {
  static const char *const names[] = {"-y", "+y", "+z", "-z", "+x", "-x"};
  for (int a = 0; a < 6; a++) {
    bb_axis parsed;
    cr_assert_eq(bb__axis_parse(names[a], &parsed, NULL), 0);
    cr_assert_eq((int)parsed, a);
    cr_assert_str_eq(bb__axis_name((bb_axis)a), names[a]);
    double r[3], u[3], o[3];
    bb__axis_frame((bb_axis)a, r, u, o);
    /* right x up = out: a right-handed frame, so no view is a mirror. */
    double c[3] = {r[1] * u[2] - r[2] * u[1], r[2] * u[0] - r[0] * u[2],
                   r[0] * u[1] - r[1] * u[0]};
    for (int k = 0; k < 3; k++)
      cr_assert_eq(c[k], o[k], "%s", names[a]);
  }
  bb_axis parsed = BB_AXIS_NEG_X;
  cr_assert_eq(bb__axis_parse("z", &parsed, NULL), 0);
  cr_assert_eq(parsed, BB_AXIS_POS_Z);
  cr_assert_neq(bb__axis_parse("up", &parsed, NULL), 0);
  cr_assert_neq(bb__axis_parse("", &parsed, NULL), 0);
  cr_assert_neq(bb__axis_parse("*z", &parsed, NULL), 0);
  cr_assert_eq(parsed, BB_AXIS_POS_Z, "a failed parse must not write");
}

/* The cap turned so that each axis sees what -y saw renders the same bits. */
Test(renderbump, every_axis_sees_the_turned_model_alike) {
  bb_mesh m;
  cap_mesh(&m, 1);
  bb_renderbump_options o;
  bb__renderbump_options_init(&o);
  o.width = 20, o.height = 12; /* not square: a swapped frame would show */
  bb_renderbump_result base;
  render(&m, &o, &base);
  double r0[3], u0[3], o0[3];
  bb__axis_frame(BB_AXIS_NEG_Y, r0, u0, o0);
  for (int a = 1; a < 6; a++) {
    double r[3], u[3], out[3];
    bb__axis_frame((bb_axis)a, r, u, out);
    bb_mesh t;
    cr_assert_eq(bb__mesh_alloc(&t, m.vertex_count, m.triangle_count, 1, NULL), BB_OK);
    memcpy(t.indices, m.indices, 3 * m.triangle_count * sizeof(uint32_t));
    for (size_t i = 0; i < m.vertex_count; i++)
      for (int k = 0; k < 3; k++) {
        const float *p = m.positions + 3 * i, *n = m.normals + 3 * i;
        double pr = p[0] * r0[0] + p[1] * r0[1] + p[2] * r0[2];
        double pu = p[0] * u0[0] + p[1] * u0[1] + p[2] * u0[2];
        double po = p[0] * o0[0] + p[1] * o0[1] + p[2] * o0[2];
        double nr = n[0] * r0[0] + n[1] * r0[1] + n[2] * r0[2];
        double nu = n[0] * u0[0] + n[1] * u0[1] + n[2] * u0[2];
        double no = n[0] * o0[0] + n[1] * o0[1] + n[2] * o0[2];
        t.positions[3 * i + (size_t)k] = (float)(pr * r[k] + pu * u[k] + po * out[k]);
        t.normals[3 * i + (size_t)k] = (float)(nr * r[k] + nu * u[k] + no * out[k]);
      }
    o.axis = (bb_axis)a;
    bb_renderbump_result rt;
    render(&t, &o, &rt);
    cr_assert(same_pixels(&rt.normal, &base.normal), "axis %s", bb__axis_name((bb_axis)a));
    cr_assert(same_pixels(&rt.height, &base.height), "axis %s", bb__axis_name((bb_axis)a));
    bb_renderbump_result_free(&rt);
    bb__mesh_free(&t);
  }
  bb_renderbump_result_free(&base);
  bb__mesh_free(&m);
}

/* --------------------------------------------------------- determinism */

Test(renderbump, same_bits_for_any_thread_count) {
  bb_mesh m;
  wave_mesh(&m, 1);
  bb_renderbump_options o;
  bb__renderbump_options_init(&o);
  o.width = 96, o.height = 80;
  o.threads = 1;
  bb_renderbump_result one;
  render(&m, &o, &one);
  for (int threads = 2; threads <= 5; threads += 3) {
    o.threads = threads;
    bb_renderbump_result many;
    render(&m, &o, &many);
    cr_assert(same_pixels(&one.normal, &many.normal), "%d threads", threads);
    cr_assert(same_pixels(&one.height, &many.height), "%d threads", threads);
    bb_renderbump_result_free(&many);
  }
  bb_renderbump_result_free(&one);
  bb__mesh_free(&m);
}

/* -------------------------------------------------------- files (Assimp) */

static char tmpdir[64];

static int remove_entry(const char *path, const struct stat *st, int flag, struct FTW *ftw) {
  (void)st, (void)flag, (void)ftw;
  return remove(path);
}

static void make_tmpdir(void) {
  snprintf(tmpdir, sizeof tmpdir, "/tmp/bb_mesh_XXXXXX");
  cr_assert_not_null(mkdtemp(tmpdir));
}

static void remove_tmpdir(void) {
  nftw(tmpdir, remove_entry, 16, FTW_DEPTH | FTW_PHYS);
}

static const char *tmp_path(char *buf, size_t cap, const char *name) {
  snprintf(buf, cap, "%s/%s", tmpdir, name);
  return buf;
}

TestSuite(renderbump_files, .init = make_tmpdir, .fini = remove_tmpdir);

static void load(const char *path, bb_mesh *m) {
  bb_error err = {{0}};
  cr_assert_eq(bb__mesh_load(path, m, &err), BB_OK, "%s", err.message);
}

/* The same mesh written as OBJ and as PLY by Assimp's exporters and read
 * back renders to the same bits, and to the bits of the mesh in memory. */
Test(renderbump_files, obj_and_ply_of_the_same_mesh_give_identical_maps) {
  bb_mesh m, from_obj, from_ply;
  cap_mesh(&m, 1);
  char obj[128], ply[128];
  bb_error err = {{0}};
  cr_assert_eq(bb__mesh_write(tmp_path(obj, sizeof obj, "cap.obj"), &m, &err), BB_OK, "%s",
               err.message);
  cr_assert_eq(bb__mesh_write(tmp_path(ply, sizeof ply, "cap.ply"), &m, &err), BB_OK, "%s",
               err.message);
  load(obj, &from_obj);
  load(ply, &from_ply);
  cr_assert_eq(from_obj.triangle_count, m.triangle_count);
  cr_assert_not_null(from_obj.normals);
  cr_assert_not_null(from_ply.normals);
  bb_renderbump_options o;
  bb__renderbump_options_init(&o);
  o.width = o.height = 40;
  bb_renderbump_result rm, ro, rp;
  render(&m, &o, &rm);
  render(&from_obj, &o, &ro);
  render(&from_ply, &o, &rp);
  cr_assert(same_pixels(&ro.normal, &rp.normal), "OBJ vs PLY normal map");
  cr_assert(same_pixels(&ro.height, &rp.height), "OBJ vs PLY height");
  cr_assert(same_pixels(&ro.normal, &rm.normal), "file vs memory");
  bb_renderbump_result_free(&rm);
  bb_renderbump_result_free(&ro);
  bb_renderbump_result_free(&rp);
  bb__mesh_free(&m);
  bb__mesh_free(&from_obj);
  bb__mesh_free(&from_ply);
}

static void write_text(const char *path, const char *text) {
  FILE *f = fopen(path, "wb");
  cr_assert_not_null(f);
  cr_assert_eq(fputs(text, f) >= 0, 1);
  cr_assert_eq(fclose(f), 0);
}

static bb_status load_status(const char *path, char *message, size_t cap) {
  bb_mesh m;
  bb_error err = {{0}};
  bb_status st = bb__mesh_load(path, &m, &err);
  snprintf(message, cap, "%s", err.message);
  if (st == BB_OK)
    bb__mesh_free(&m);
  else
    cr_assert_null(m.positions, "a failed load leaves the mesh empty");
  return st;
}

Test(renderbump_files, unreadable_empty_truncated_and_triangle_free_models_fail,
     .timeout = 300) {
  char path[128], msg[512];
  bb_error err = {{0}};
  cr_assert_eq(load_status(tmp_path(path, sizeof path, "missing.obj"), msg, sizeof msg),
               BB_ERR_IO);
  cr_assert(strstr(msg, "no such file"), "%s", msg);
  cr_assert_eq(load_status(tmpdir, msg, sizeof msg), BB_ERR_IO);
  write_text(tmp_path(path, sizeof path, "empty.obj"), "");
  cr_assert_eq(load_status(path, msg, sizeof msg), BB_ERR_FORMAT);
  cr_assert(strstr(msg, "empty"), "%s", msg);
  write_text(tmp_path(path, sizeof path, "junk.ply"), "not a model at all\n\x01\x02\x03");
  cr_assert_eq(load_status(path, msg, sizeof msg), BB_ERR_FORMAT, "%s", msg);
  /* Tiny literal files: only points, and only a line. */
  write_text(tmp_path(path, sizeof path, "points.obj"), "v 0 0 0\nv 1 0 0\nv 0 0 1\n");
  cr_assert_eq(load_status(path, msg, sizeof msg), BB_ERR_FORMAT);
  cr_assert(strstr(msg, "no triangles"), "%s", msg);
  write_text(tmp_path(path, sizeof path, "line.obj"), "v 0 0 0\nv 1 0 0\nv 0 0 1\nl 1 2\n");
  cr_assert_eq(load_status(path, msg, sizeof msg), BB_ERR_FORMAT);
  cr_assert(strstr(msg, "no triangles"), "%s", msg);
  /* A binary PLY cut short inside its header: Assimp 5.2.4 alone re-reads
   * it forever (checked: plain Importer::ReadFile on such a file does not
   * return); the read budget turns that into an error. */
  bb_mesh cap;
  cap_mesh(&cap, 1);
  char whole[128];
  cr_assert_eq(bb__mesh_write(tmp_path(whole, sizeof whole, "whole.ply"), &cap, &err), BB_OK);
  bb__mesh_free(&cap);
  FILE *f = fopen(whole, "rb");
  cr_assert_not_null(f);
  char bytes[4096];
  size_t got = fread(bytes, 1, sizeof bytes, f);
  fclose(f);
  const char *end = strstr(bytes, "end_header\n");
  cr_assert(end && got == sizeof bytes);
  size_t cut = (size_t)(end - bytes) + 5; /* "end_h" */
  f = fopen(tmp_path(path, sizeof path, "cut.ply"), "wb");
  cr_assert(f && fwrite(bytes, 1, cut, f) == cut && fclose(f) == 0);
  cr_assert_eq(load_status(path, msg, sizeof msg), BB_ERR_FORMAT, "%s", msg);
  /* A quad is triangulated. */
  write_text(tmp_path(path, sizeof path, "quad.obj"),
             "v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nf 1 2 3 4\n");
  bb_mesh m;
  load(path, &m);
  cr_assert_eq(m.triangle_count, 2);
  cr_assert_null(m.normals);
  bb__mesh_free(&m);
}

Test(renderbump_files, mesh_write_errors_leave_no_file) {
  bb_mesh m;
  hole_mesh(&m);
  char path[128];
  bb_error err = {{0}};
  cr_assert_eq(bb__mesh_write(tmp_path(path, sizeof path, "m.xyz"), &m, &err), BB_ERR_FORMAT);
  cr_assert_eq(bb__mesh_write(tmp_path(path, sizeof path, "no/such/dir/m.obj"), &m, &err),
               BB_ERR_IO);
  m.indices[5] = (uint32_t)m.vertex_count;
  cr_assert_eq(bb__mesh_write(tmp_path(path, sizeof path, "bad.ply"), &m, &err),
               BB_ERR_ARGUMENT);
  cr_assert_neq(access(path, F_OK), 0, "no file after a refused write");
  bb__mesh_free(&m);
}

/* --------------------------------------------------------------- errors */

Test(renderbump, bad_meshes_and_options_are_refused) {
  bb_renderbump_options o;
  bb__renderbump_options_init(&o);
  bb_renderbump_result r;
  bb_error err = {{0}};
  bb_mesh m;
  cap_mesh(&m, 0);

  /* seen along +x, the cap (in XZ, facing -y) is edge-on: zero width */
  static const float wall[9] = {0, 0, 0, 0, 1, 0, 0, 0, 1};
  bb_mesh edge_on;
  cr_assert_eq(bb__mesh_alloc(&edge_on, 3, 1, 0, NULL), BB_OK);
  memcpy(edge_on.positions, wall, sizeof wall);
  edge_on.indices[0] = 0, edge_on.indices[1] = 1, edge_on.indices[2] = 2;
  cr_assert_eq(bb__renderbump_flat(&edge_on, &o, &r, &err), BB_ERR_ARGUMENT);
  cr_assert(strstr(err.message, "degenerate"), "%s", err.message);
  cr_assert_null(r.normal.pixels);
  bb__mesh_free(&edge_on);

  o.samples = 0;
  cr_assert_eq(bb__renderbump_flat(&m, &o, &r, &err), BB_ERR_ARGUMENT);
  o.samples = 17;
  cr_assert_eq(bb__renderbump_flat(&m, &o, &r, &err), BB_ERR_ARGUMENT);
  bb__renderbump_options_init(&o);
  o.width = 0;
  cr_assert_eq(bb__renderbump_flat(&m, &o, &r, &err), BB_ERR_SIZE);
  bb__renderbump_options_init(&o);
  o.rect_given = 1; /* all zero: left == right */
  cr_assert_eq(bb__renderbump_flat(&m, &o, &r, &err), BB_ERR_ARGUMENT);
  /* a rectangle far from the model: nothing to see */
  double far_away[4] = {100, 100, 101, 101};
  memcpy(o.rect, far_away, sizeof far_away);
  cr_assert_eq(bb__renderbump_flat(&m, &o, &r, &err), BB_ERR_ARGUMENT);
  cr_assert(strstr(err.message, "no surface"), "%s", err.message);
  /* tiled, the same far rectangle is a window on the repeated cap */
  o.tile = 1;
  cr_assert_eq(bb__renderbump_flat(&m, &o, &r, &err), BB_OK, "%s", err.message);
  bb_renderbump_result_free(&r);
  /* but not a million tiles away */
  double too_far[4] = {0, 0, 1e-7, 1e-7};
  memcpy(o.rect, too_far, sizeof too_far);
  cr_assert_eq(bb__renderbump_flat(&m, &o, &r, &err), BB_ERR_SIZE);

  /* a rectangle so small that the model's image coordinates overflow */
  double tiny[4] = {0, 0, 1e-310, 1e-310};
  memcpy(o.rect, tiny, sizeof tiny);
  for (o.tile = 0; o.tile < 2; o.tile++)
    cr_assert_eq(bb__renderbump_flat(&m, &o, &r, &err), BB_ERR_ARGUMENT, "tile %d", o.tile);

  bb__renderbump_options_init(&o);
  m.positions[4] = NAN;
  cr_assert_eq(bb__renderbump_flat(&m, &o, &r, &err), BB_ERR_VALUE);
  m.positions[4] = 0.0f;
  m.indices[7] = (uint32_t)m.vertex_count;
  cr_assert_eq(bb__renderbump_flat(&m, &o, &r, &err), BB_ERR_ARGUMENT);
  m.triangle_count = 0;
  cr_assert_eq(bb__renderbump_flat(&m, &o, &r, &err), BB_ERR_ARGUMENT);
  cr_assert(strstr(err.message, "no triangles"), "%s", err.message);
  bb__mesh_free(&m);
}

Test(renderbump, mesh_hash_sees_every_array) {
  bb_mesh m;
  cap_mesh(&m, 1);
  uint64_t h0 = bb__mesh_hash(&m);
  m.positions[10] += 1.0f;
  uint64_t h1 = bb__mesh_hash(&m);
  m.positions[10] -= 1.0f;
  m.normals[10] += 1.0f;
  uint64_t h2 = bb__mesh_hash(&m);
  m.normals[10] -= 1.0f;
  m.indices[0]++;
  uint64_t h3 = bb__mesh_hash(&m);
  m.indices[0]--;
  cr_assert(h0 != h1 && h0 != h2 && h0 != h3);
  cr_assert_eq(bb__mesh_hash(&m), h0);
  bb__mesh_free(&m);
}

Test(renderbump, describe_lists_the_parameters) {
  bb_mesh m;
  cap_mesh(&m, 1);
  bb_renderbump_options o;
  bb__renderbump_options_init(&o);
  o.width = 16, o.height = 8;
  bb_renderbump_result r;
  render(&m, &o, &r);
  char *text = bb__renderbump_describe(&o, &r);
  cr_assert_not_null(text);
  cr_assert(strstr(text, "axis=-y\n") && strstr(text, "size=16x8\n") &&
                strstr(text, "samples=4\n") && strstr(text, "normals=vertex\n") &&
                strstr(text, "tile=off\n") && strstr(text, "scale="),
            "%s", text);
  double scale = atof(strstr(text, "scale=") + 6);
  cr_assert_float_eq(scale, r.height_scale, 1e-6 * r.height_scale);
  free(text);
  bb_renderbump_result_free(&r);
  bb__mesh_free(&m);
}
