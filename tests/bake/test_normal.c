/* test_normal.c: the normal estimators on flat, planar, sine and symmetric height
 * fields. */
#include <criterion/criterion.h>

#include <math.h>
#include <stdint.h>
#include <string.h>

#include "bumpbake.h"
#include "bake/bake_internal.h"

#define PI 3.14159265358979323846

static const bb_normal_filter all_filters[] = {BB_NORMAL_VERTEX, BB_NORMAL_VALVE,
                                               BB_NORMAL_CENTRAL, BB_NORMAL_SOBEL};
#define FILTER_COUNT (sizeof all_filters / sizeof all_filters[0])

static void fill_constant(bb_image *h, float value) {
  for (int i = 0; i < h->width * h->height; i++)
    h->pixels[i] = value;
}

static void compute(const bb_image *h, float scale, bb_normal_filter f, bb_addressing a,
                    bb_image *out) {
  bb_error err = {{0}};
  cr_assert_eq(bb__normals_compute_all_cores(h, scale, f, a, out, &err), BB_OK, "%s", err.message);
  cr_assert_eq(out->channels, 3);
  cr_assert_eq(out->width, h->width);
  cr_assert_eq(out->height, h->height);
}

Test(normal, filter_names_round_trip) {
  for (size_t i = 0; i < FILTER_COUNT; i++) {
    bb_normal_filter parsed = (bb_normal_filter)-1;
    cr_assert_eq(bb__normal_filter_parse(bb__normal_filter_name(all_filters[i]), &parsed, NULL),
                 0);
    cr_assert_eq(parsed, all_filters[i]);
  }
  cr_assert_str_eq(bb__normal_filter_name(BB_NORMAL_VERTEX), "vertex");
  cr_assert_str_eq(bb__normal_filter_name(BB_NORMAL_VALVE), "valve");
  cr_assert_str_eq(bb__normal_filter_name(BB_NORMAL_CENTRAL), "central");
  cr_assert_str_eq(bb__normal_filter_name(BB_NORMAL_SOBEL), "sobel");
  bb_normal_filter f = BB_NORMAL_SOBEL;
  cr_assert_neq(bb__normal_filter_parse("Valve", &f, NULL), 0);
  cr_assert_neq(bb__normal_filter_parse("", &f, NULL), 0);
  cr_assert_eq(f, BB_NORMAL_SOBEL, "a failed parse must not write");
}

Test(normal, flat_is_straight_up_exactly) {
  bb_image h = {0}, n = {0};
  cr_assert_eq(bb_image_alloc(&h, 9, 7, 1, NULL), BB_OK);
  fill_constant(&h, 0.37f);
  for (size_t i = 0; i < FILTER_COUNT; i++)
    for (int a = 0; a < 2; a++) {
      compute(&h, 25.0f, all_filters[i], (bb_addressing)a, &n);
      for (int k = 0; k < 9 * 7; k++) {
        cr_assert(n.pixels[3 * k] == 0.0f && n.pixels[3 * k + 1] == 0.0f &&
                      n.pixels[3 * k + 2] == 1.0f,
                  "%s texel %d: (%g, %g, %g)", bb__normal_filter_name(all_filters[i]), k,
                  (double)n.pixels[3 * k], (double)n.pixels[3 * k + 1],
                  (double)n.pixels[3 * k + 2]);
      }
      bb_image_free(&n);
    }
  bb_image_free(&h);
}

/* h = 0.5 + 0.5 sin(2 pi u / P) along x (along_y = 0) or y (along_y = 1),
 * compared with normalize(-S dh/dx, -S dh/dy, 1) at the point each estimator
 * is centred on: the Valve one half a texel towards +x/+y. The errors are the
 * second-order discretisation errors measured at P = 32 (about 0.0105 for
 * Valve, 0.0025 for central and Sobel), with margin. A Valve estimate
 * compared at the texel itself would be off by about 0.05. */
static void check_sine(bb_normal_filter f, int along_y, double tolerance) {
  const int period = 32, w = along_y ? 5 : 2 * period, hgt = along_y ? 2 * period : 5;
  const double scale = period / PI; /* gradient amplitude S * 0.5 * 2 pi / P = 1 */
  bb_image h = {0}, n = {0};
  cr_assert_eq(bb_image_alloc(&h, w, hgt, 1, NULL), BB_OK);
  for (int y = 0; y < hgt; y++)
    for (int x = 0; x < w; x++)
      bb_image_texel(&h, x, y)[0] =
          (float)(0.5 + 0.5 * sin(2.0 * PI * (along_y ? y : x) / period));
  compute(&h, (float)scale, f, BB_ADDRESS_PERIODIC, &n);
  const double offset = f == BB_NORMAL_VALVE ? 0.5 : 0.0;
  for (int y = 0; y < hgt; y++)
    for (int x = 0; x < w; x++) {
      double u = (along_y ? y : x) + offset;
      double slope = scale * 0.5 * (2.0 * PI / period) * cos(2.0 * PI * u / period);
      double want[3] = {along_y ? 0.0 : -slope, along_y ? -slope : 0.0, 1.0};
      double len = sqrt(1.0 + slope * slope);
      const float *got = bb_image_texel(&n, x, y);
      for (int c = 0; c < 3; c++)
        cr_assert(fabs(got[c] - want[c] / len) < tolerance,
                  "%s (%d,%d) c%d: got %.5f want %.5f", bb__normal_filter_name(f), x, y, c,
                  (double)got[c], want[c] / len);
    }
  bb_image_free(&h);
  bb_image_free(&n);
}

Test(normal, sine_along_x_vertex) {
  check_sine(BB_NORMAL_VERTEX, 0, 0.016);
}
Test(normal, sine_along_y_vertex) {
  check_sine(BB_NORMAL_VERTEX, 1, 0.016);
}
Test(normal, sine_along_x_valve) {
  check_sine(BB_NORMAL_VALVE, 0, 0.015);
}
Test(normal, sine_along_y_valve) {
  check_sine(BB_NORMAL_VALVE, 1, 0.015);
}
Test(normal, sine_along_x_central) {
  check_sine(BB_NORMAL_CENTRAL, 0, 0.004);
}
Test(normal, sine_along_y_central) {
  check_sine(BB_NORMAL_CENTRAL, 1, 0.004);
}
Test(normal, sine_along_x_sobel) {
  check_sine(BB_NORMAL_SOBEL, 0, 0.004);
}
Test(normal, sine_along_y_sobel) {
  check_sine(BB_NORMAL_SOBEL, 1, 0.004);
}

/* h = gx * x + gy * y: every estimator is exact on a plane away from the
 * clamped border, and the signs follow the frame (x right, y DOWN). */
static void check_plane(double gx, double gy) {
  const float scale = 4.0f;
  bb_image h = {0}, n = {0};
  cr_assert_eq(bb_image_alloc(&h, 8, 8, 1, NULL), BB_OK);
  for (int y = 0; y < 8; y++)
    for (int x = 0; x < 8; x++)
      bb_image_texel(&h, x, y)[0] = (float)(gx * x + gy * y);
  double sx = -scale * gx, sy = -scale * gy, len = sqrt(sx * sx + sy * sy + 1.0);
  for (size_t i = 0; i < FILTER_COUNT; i++) {
    compute(&h, scale, all_filters[i], BB_ADDRESS_CLAMP, &n);
    for (int y = 2; y < 6; y++) /* vertex reads x-2..x+2, Valve up to x+2 */
      for (int x = 2; x < 6; x++) {
        const float *got = bb_image_texel(&n, x, y);
        cr_assert_float_eq(got[0], sx / len, 1e-6, "%s",
                           bb__normal_filter_name(all_filters[i]));
        cr_assert_float_eq(got[1], sy / len, 1e-6, "%s",
                           bb__normal_filter_name(all_filters[i]));
        cr_assert_float_eq(got[2], 1.0 / len, 1e-6, "%s",
                           bb__normal_filter_name(all_filters[i]));
      }
    bb_image_free(&n);
  }
  bb_image_free(&h);
}

Test(normal, plane_rising_down_the_rows_tilts_y_negative) {
  check_plane(0.0, 0.05);
  bb_image h = {0}, n = {0};
  cr_assert_eq(bb_image_alloc(&h, 8, 8, 1, NULL), BB_OK);
  for (int y = 0; y < 8; y++)
    for (int x = 0; x < 8; x++)
      bb_image_texel(&h, x, y)[0] = 0.1f * (float)y;
  compute(&h, 1.0f, BB_NORMAL_VALVE, BB_ADDRESS_CLAMP, &n);
  /* Height rises towards +y (down), so the surface faces up the image. */
  cr_assert_lt(bb_image_texel(&n, 3, 3)[1], -0.05f);
  cr_assert_eq(bb_image_texel(&n, 3, 3)[0], 0.0f);
  bb_image_free(&h);
  bb_image_free(&n);
}

Test(normal, plane_rising_right_tilts_x_negative) {
  check_plane(0.07, 0.0);
  check_plane(-0.03, 0.02);
}

/* Clamping repeats the border texel, so central differences see half the
 * slope at the border; periodic addressing sees the wrap-around cliff. */
Test(normal, clamp_and_periodic_borders) {
  bb_image h = {0}, clamp = {0}, periodic = {0};
  cr_assert_eq(bb_image_alloc(&h, 8, 3, 1, NULL), BB_OK);
  for (int y = 0; y < 3; y++)
    for (int x = 0; x < 8; x++)
      bb_image_texel(&h, x, y)[0] = 0.1f * (float)x;
  compute(&h, 2.0f, BB_NORMAL_CENTRAL, BB_ADDRESS_CLAMP, &clamp);
  compute(&h, 2.0f, BB_NORMAL_CENTRAL, BB_ADDRESS_PERIODIC, &periodic);
  double half = -2.0 * 0.1 / 2.0; /* (z(1) - z(0)) / 2 */
  cr_assert_float_eq(bb_image_texel(&clamp, 0, 1)[0], half / sqrt(half * half + 1.0),
                     1e-6);
  /* Periodic: z(-1) = z(7) = 1.4, so the slope at x = 0 is negative. */
  cr_assert_gt(bb_image_texel(&periodic, 0, 1)[0], 0.5f);
  bb_image_free(&h);
  bb_image_free(&clamp);
  bb_image_free(&periodic);
}

static double next_random(uint64_t *state) {
  *state = *state * 6364136223846793005ULL + 1442695040888963407ULL;
  return (double)(*state >> 11) * (1.0 / 9007199254740992.0);
}

Test(normal, unit_length_and_facing_up_on_noise) {
  bb_image h = {0}, n = {0};
  uint64_t state = 11;
  cr_assert_eq(bb_image_alloc(&h, 31, 17, 1, NULL), BB_OK);
  for (int i = 0; i < 31 * 17; i++)
    h.pixels[i] = (float)next_random(&state);
  for (size_t i = 0; i < FILTER_COUNT; i++) {
    compute(&h, 30.0f, all_filters[i], BB_ADDRESS_PERIODIC, &n);
    for (int k = 0; k < 31 * 17; k++) {
      const float *p = n.pixels + 3 * k;
      double len = sqrt((double)p[0] * p[0] + (double)p[1] * p[1] + (double)p[2] * p[2]);
      cr_assert(fabs(len - 1.0) < 1e-6, "length %.9f", len);
      cr_assert_gt(p[2], 0.0f);
    }
    bb_image_free(&n);
  }
  bb_image_free(&h);
}

Test(normal, periodic_shift_is_exact) {
  const int w = 37, hgt = 23, dx = 13, dy = 4;
  bb_image h = {0}, shifted = {0}, a = {0}, b = {0};
  uint64_t state = 3;
  cr_assert_eq(bb_image_alloc(&h, w, hgt, 1, NULL), BB_OK);
  cr_assert_eq(bb_image_alloc(&shifted, w, hgt, 1, NULL), BB_OK);
  for (int y = 0; y < hgt; y++)
    for (int x = 0; x < w; x++) {
      float v = (float)next_random(&state);
      bb_image_texel(&h, x, y)[0] = v;
      bb_image_texel(&shifted, (x + dx) % w, (y + dy) % hgt)[0] = v;
    }
  for (size_t i = 0; i < FILTER_COUNT; i++) {
    compute(&h, 10.0f, all_filters[i], BB_ADDRESS_PERIODIC, &a);
    compute(&shifted, 10.0f, all_filters[i], BB_ADDRESS_PERIODIC, &b);
    for (int y = 0; y < hgt; y++)
      for (int x = 0; x < w; x++)
        cr_assert_eq(memcmp(bb_image_texel(&a, x, y),
                            bb_image_texel(&b, (x + dx) % w, (y + dy) % hgt),
                            3 * sizeof(float)),
                     0, "%s (%d,%d)", bb__normal_filter_name(all_filters[i]), x, y);
    bb_image_free(&a);
    bb_image_free(&b);
  }
  bb_image_free(&h);
  bb_image_free(&shifted);
}

/* The estimators as direct per-texel sums (the form of docs/conventions.md), kept here
 * to check the library's per-cell form bit for bit. */
static double ref_z(const bb_image *h, double scale, int x, int y, bb_addressing a) {
  int ax, ay;
  if (a == BB_ADDRESS_PERIODIC) {
    ax = ((x % h->width) + h->width) % h->width;
    ay = ((y % h->height) + h->height) % h->height;
  } else {
    ax = x < 0 ? 0 : (x >= h->width ? h->width - 1 : x);
    ay = y < 0 ? 0 : (y >= h->height ? h->height - 1 : y);
  }
  return scale * (double)bb_image_texel(h, ax, ay)[0];
}

static void ref_add_unit(double sum[3], double nx, double ny, double nz) {
  double len = sqrt(nx * nx + ny * ny + nz * nz);
  sum[0] += nx / len;
  sum[1] += ny / len;
  sum[2] += nz / len;
}

static void ref_normal(const bb_image *h, double scale, bb_normal_filter f,
                       bb_addressing a, int x, int y, float out[3]) {
  double z[4][4]; /* z[j][i] = z(x - 1 + i, y - 1 + j) */
  for (int j = 0; j < 4; j++)
    for (int i = 0; i < 4; i++)
      z[j][i] = ref_z(h, scale, x - 1 + i, y - 1 + j, a);
  double n[3] = {0.0, 0.0, 1.0};
  if (f == BB_NORMAL_VERTEX) {
    /* c[j][i]: triangle a + triangle b of cell (x - 2 + i, y - 2 + j); then
     * the (1, 2, 2, 1) weights along x, then along y, mirror pairs first. */
    double c[4][4][3], r[4][3];
    for (int j = 0; j < 4; j++)
      for (int i = 0; i < 4; i++) {
        double z00 = ref_z(h, scale, x - 2 + i, y - 2 + j, a);
        double z10 = ref_z(h, scale, x - 1 + i, y - 2 + j, a);
        double z01 = ref_z(h, scale, x - 2 + i, y - 1 + j, a);
        double z11 = ref_z(h, scale, x - 1 + i, y - 1 + j, a);
        double ta[3] = {0.0, 0.0, 0.0}, tb[3] = {0.0, 0.0, 0.0};
        ref_add_unit(ta, -(z10 - z00), -(z01 - z00), 1.0);
        ref_add_unit(tb, z01 - z11, z10 - z11, 1.0);
        for (int k = 0; k < 3; k++)
          c[j][i][k] = ta[k] + tb[k];
      }
    for (int j = 0; j < 4; j++)
      for (int k = 0; k < 3; k++)
        r[j][k] = (c[j][0][k] + c[j][3][k]) + 2.0 * (c[j][1][k] + c[j][2][k]);
    for (int k = 0; k < 3; k++)
      n[k] = (r[0][k] + r[3][k]) + 2.0 * (r[1][k] + r[2][k]);
  } else if (f == BB_NORMAL_VALVE) {
    n[2] = 0.0;
    for (int j = 0; j < 3; j++)
      for (int i = 0; i < 3; i++) {
        double z00 = z[j][i], z10 = z[j][i + 1], z01 = z[j + 1][i], z11 = z[j + 1][i + 1];
        ref_add_unit(n, -(z10 - z00), -(z01 - z00), 1.0);
        ref_add_unit(n, z01 - z11, z10 - z11, 1.0);
      }
  } else if (f == BB_NORMAL_CENTRAL) {
    n[0] = -(z[1][2] - z[1][0]) / 2.0;
    n[1] = -(z[2][1] - z[0][1]) / 2.0;
  } else {
    n[0] = -(((z[0][2] + 2.0 * z[1][2] + z[2][2]) - (z[0][0] + 2.0 * z[1][0] + z[2][0])) /
             8.0);
    n[1] = -(((z[2][0] + 2.0 * z[2][1] + z[2][2]) - (z[0][0] + 2.0 * z[0][1] + z[0][2])) /
             8.0);
  }
  double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  for (int c = 0; c < 3; c++)
    out[c] = (float)(n[c] / len);
}

/* Sizes around the library's band (16 rows) and span (128 columns), and
 * images smaller than the 4x4 neighbourhood. */
Test(normal, matches_direct_sums_bit_for_bit) {
  const int sizes[][2] = {{1, 1}, {2, 3}, {5, 37}, {17, 16}, {130, 33}, {257, 5}};
  uint64_t state = 5;
  for (size_t s = 0; s < sizeof sizes / sizeof sizes[0]; s++) {
    const int w = sizes[s][0], hgt = sizes[s][1];
    bb_image h = {0}, n = {0};
    cr_assert_eq(bb_image_alloc(&h, w, hgt, 1, NULL), BB_OK);
    for (int i = 0; i < w * hgt; i++)
      h.pixels[i] = (float)next_random(&state);
    for (size_t f = 0; f < FILTER_COUNT; f++)
      for (int clamp = 0; clamp < 2; clamp++) {
        bb_addressing a = clamp ? BB_ADDRESS_CLAMP : BB_ADDRESS_PERIODIC;
        compute(&h, 40.0f, all_filters[f], a, &n);
        for (int y = 0; y < hgt; y++)
          for (int x = 0; x < w; x++) {
            float want[3];
            ref_normal(&h, 40.0, all_filters[f], a, x, y, want);
            cr_assert_eq(memcmp(bb_image_texel(&n, x, y), want, sizeof want), 0,
                         "%dx%d %s %s (%d,%d)", w, hgt,
                         bb__normal_filter_name(all_filters[f]),
                         clamp ? "clamp" : "periodic", x, y);
          }
        bb_image_free(&n);
      }
    bb_image_free(&h);
  }
}

/* A bump symmetric about texel (8, 8): the vertex estimator gives exactly
 * (0, 0, 1) at its peak (128, 128, 255 in 8 bits), Valve's, centred half a
 * texel off, leans towards -x and -y (down the bump's +x/+y flank). */
Test(normal, symmetric_bump_peak_is_straight_up_for_vertex_only) {
  bb_image h = {0}, n = {0};
  cr_assert_eq(bb_image_alloc(&h, 17, 17, 1, NULL), BB_OK);
  for (int y = 0; y < 17; y++)
    for (int x = 0; x < 17; x++) {
      double r2 = (x - 8) * (x - 8) + (y - 8) * (y - 8);
      bb_image_texel(&h, x, y)[0] = (float)exp(-r2 / 8.0);
    }
  compute(&h, 4.0f, BB_NORMAL_VERTEX, BB_ADDRESS_PERIODIC, &n);
  const float *peak = bb_image_texel(&n, 8, 8);
  cr_assert(peak[0] == 0.0f && peak[1] == 0.0f && peak[2] == 1.0f, "(%g, %g, %g)",
            (double)peak[0], (double)peak[1], (double)peak[2]);
  /* The flanks lean away from the peak, symmetrically. */
  cr_assert_gt(bb_image_texel(&n, 10, 8)[0], 0.1f);
  cr_assert_eq(bb_image_texel(&n, 10, 8)[0], -bb_image_texel(&n, 6, 8)[0]);
  cr_assert_gt(bb_image_texel(&n, 8, 10)[1], 0.1f);
  bb_image_free(&n);
  compute(&h, 4.0f, BB_NORMAL_VALVE, BB_ADDRESS_PERIODIC, &n);
  peak = bb_image_texel(&n, 8, 8);
  cr_assert_gt(peak[0], 0.05f, "Valve's estimate sits half a texel towards +x");
  cr_assert_gt(peak[1], 0.05f);
  bb_image_free(&n);
  bb_image_free(&h);
}

Test(normal, rejects_bad_arguments) {
  bb_image h = {0}, rgb = {0}, n = {0};
  bb_error err = {{0}};
  cr_assert_eq(bb_image_alloc(&h, 4, 4, 1, NULL), BB_OK);
  cr_assert_eq(bb_image_alloc(&rgb, 4, 4, 3, NULL), BB_OK);
  cr_assert_eq(
      bb__normals_compute_all_cores(&rgb, 1.0f, BB_NORMAL_VALVE, BB_ADDRESS_PERIODIC, &n, &err),
      BB_ERR_ARGUMENT);
  cr_assert(strstr(err.message, "channels") != NULL, "%s", err.message);
  cr_assert_eq(
      bb__normals_compute_all_cores(&h, NAN, BB_NORMAL_VALVE, BB_ADDRESS_PERIODIC, &n, &err),
      BB_ERR_ARGUMENT);
  cr_assert_eq(
      bb__normals_compute_all_cores(&h, INFINITY, BB_NORMAL_SOBEL, BB_ADDRESS_CLAMP, &n, &err),
      BB_ERR_ARGUMENT);
  cr_assert_eq(
      bb__normals_compute_all_cores(&h, 1.0f, (bb_normal_filter)7, BB_ADDRESS_PERIODIC, &n, &err),
      BB_ERR_ARGUMENT);
  cr_assert_eq(
      bb__normals_compute_all_cores(&h, 1.0f, BB_NORMAL_VALVE, BB_ADDRESS_PERIODIC, &h, &err),
      BB_ERR_ARGUMENT);
  bb_image_texel(&h, 2, 1)[0] = NAN;
  cr_assert_eq(
      bb__normals_compute_all_cores(&h, 1.0f, BB_NORMAL_CENTRAL, BB_ADDRESS_PERIODIC, &n, &err),
      BB_ERR_VALUE);
  cr_assert(strstr(err.message, "(2, 1)") != NULL, "%s", err.message);
  cr_assert_null(n.pixels);
  bb_image_free(&h);
  bb_image_free(&rgb);
}
