/* test_integrate.c: the sector integrals and their tables against an
 * independent quadrature (elevation inside, in closed form where it has one;
 * azimuth outside, adaptive Simpson), and the ray set's totals. */
#include "trace/rayset.h"
#include <criterion/criterion.h>

#include <math.h>
#include <string.h>

#include "bumpbake.h"
#include "trace/integrate.h"
#include "trace/basis.h"

static const double PI = 3.14159265358979323846;

/* ---- the reference: integral over phi in [lo, hi] and theta in [theta0,
 * pi/2] of max(0, w.b)^p cos(theta), azimuth outside, elevation inside ---- */

typedef struct lobe_ref {
  double b[3], p, theta0;
} lobe_ref;

static double simpson(double (*f)(const void *, double), const void *ctx, double a, double b,
                      double fa, double fm, double fb, double whole, double tolerance,
                      int depth) {
  const double m = 0.5 * (a + b), lm = 0.5 * (a + m), rm = 0.5 * (m + b);
  const double flm = f(ctx, lm), frm = f(ctx, rm);
  const double left = (m - a) / 6 * (fa + 4 * flm + fm), right = (b - m) / 6 * (fm + 4 * frm + fb);
  if (depth > 40 || fabs(left + right - whole) <= 15 * tolerance)
    return left + right + (left + right - whole) / 15;
  return simpson(f, ctx, a, m, fa, flm, fm, left, tolerance / 2, depth + 1) +
         simpson(f, ctx, m, b, fm, frm, fb, right, tolerance / 2, depth + 1);
}

static double integrate(double (*f)(const void *, double), const void *ctx, double a, double b,
                        double tolerance) {
  if (!(b > a)) return 0.0;
  const double fa = f(ctx, a), fm = f(ctx, 0.5 * (a + b)), fb = f(ctx, b);
  return simpson(f, ctx, a, b, fa, fm, fb, (b - a) / 6 * (fa + 4 * fm + fb), tolerance, 0);
}

typedef struct ring {
  const lobe_ref *l;
  double phi;
} ring;

static double lobe_at(const void *ctx, double theta) {
  const ring *r = ctx;
  const double w[3] = {cos(theta) * cos(r->phi), cos(theta) * sin(r->phi), sin(theta)};
  const double d = w[0] * r->l->b[0] + w[1] * r->l->b[1] + w[2] * r->l->b[2];
  return d > 0 ? pow(d, r->l->p) * cos(theta) : 0.0;
}

/* The elevation integral at one azimuth: from theta0 (or where the lobe
 * turns positive) to pi/2; in closed form at power 1. */
static double elevation_integral(const void *ctx, double phi) {
  const lobe_ref *l = ctx;
  const double a = l->b[0] * cos(phi) + l->b[1] * sin(phi), c = l->b[2];
  /* a cos(theta) + c sin(theta) > 0 for theta above `start` */
  double start = l->theta0;
  if (c > 0) start = fmax(start, atan2(-a, c));
  else if (c < 0) return 0.0 * a; /* negative near pi/2: the tests use c >= 0 only */
  else if (a <= 0) return 0.0;
  if (start >= PI / 2) return 0.0;
  if (l->p == 1.0) { /* integral of a cos^2 + c sin cos */
    const double A = PI / 2, B = start;
    return a * ((A - B) / 2 + (sin(2 * A) - sin(2 * B)) / 4) +
           c * (sin(A) * sin(A) - sin(B) * sin(B)) / 2;
  }
  const ring r = {l, phi};
  return integrate(lobe_at, &r, start, PI / 2, 1e-11);
}

static double reference(double lo, double hi, const double b[3], double p, double t) {
  const lobe_ref l = {{b[0], b[1], b[2]}, p, atan(fmax(t, 0.0))};
  return integrate(elevation_integral, &l, lo, hi, 1e-10);
}

/* ---------------------------------------------------------------- tests */

static void unit(double v[3]) {
  const double n = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  for (int k = 0; k < 3; k++) v[k] /= n;
}

/* What a table gives, against the reference, at horizons across the range,
 * for sectors of 1, 5 and 16 slices, the HL2 lobes, straight up, a tilted
 * unit vector and powers 1, 1.5 and 4: within 1e-6 (the losses, from
 * elevation 0 up to the horizon, are of the order of the sector's width). */
Test(integrate, tables_match_an_independent_quadrature) {
  double basis[4][3];
  for (int c = 0; c < 3; c++) bb__basis_vector(c, basis[c]);
  basis[3][0] = 0.3, basis[3][1] = -0.8, basis[3][2] = 0.2;
  unit(basis[3]);
  const double powers[] = {1.0, 1.5, 4.0};
  const double tangents[] = {0.0, 0.01, 0.37, 1.0, 2.5, 120.0};
  const int sector_counts[] = {1, 5, 16};
  double worst = 0.0;
  for (size_t pi = 0; pi < 3; pi++)
    for (size_t si = 0; si < 3; si++) {
      const double width = 2 * PI / sector_counts[si], lo = 0.3 - width / 2, hi = lo + width;
      static double table[BB__TABLE_INTERVALS * 4 * 4];
      double share[4];
      bb__slice_table_build(lo, hi, (const double(*)[3])basis, 4, powers[pi], table, share);
      const bb__slice_integral si_ = {table, 0.5 * (hi - lo), 4};
      for (int c = 0; c < 4; c++) {
        const double whole = reference(lo, hi, basis[c], powers[pi], 0.0);
        cr_assert_float_eq(share[c], whole, 1e-9, "share, power %g, %d slices, lobe %d: %.12g vs %.12g",
                           powers[pi], sector_counts[si], c, share[c], whole);
        for (size_t ti = 0; ti < sizeof tangents / sizeof tangents[0]; ti++) {
          double blocked[5];
          bb__slice_blocked(&si_, tangents[ti], blocked);
          const double expected = whole - reference(lo, hi, basis[c], powers[pi], tangents[ti]);
          const double error = fabs(blocked[1 + c] - expected);
          worst = fmax(worst, error);
          cr_assert_leq(error, 1e-6, "power %g, %d slices, lobe %d, t %g: %.12g vs %.12g",
                        powers[pi], sector_counts[si], c, tangents[ti], blocked[1 + c], expected);
        }
      }
    }
  cr_log_info("largest difference from the reference: %.3g", worst);
}

/* Between its nodes the table is a cubic: its largest error, against the
 * library's own quadrature at the middle of every third interval, stays
 * under 1e-7 of the sector's share (docs/how-it-works.md says so; measured 2.5e-8 for
 * quarter-turn sectors, 1.4e-9 for 16 and 32 slices). */
Test(integrate, interpolation_error_is_under_1e_7_of_the_share) {
  double basis[3][3];
  for (int c = 0; c < 3; c++) bb__basis_vector(c, basis[c]);
  const int sector_counts[] = {4, 16, 32};
  for (size_t si = 0; si < 3; si++) {
    const double width = 2 * PI / sector_counts[si], lo = 1.1 - width / 2, hi = lo + width;
    static double table[BB__TABLE_INTERVALS * 3 * 4];
    double share[3];
    bb__slice_table_build(lo, hi, (const double(*)[3])basis, 3, 1.0, table, share);
    const bb__slice_integral si_ = {table, 0.5 * (hi - lo), 3};
    double worst = 0.0;
    for (int k = 0; k < BB__TABLE_INTERVALS; k += 3) {
      const double q = (k + 0.5) / BB__TABLE_INTERVALS, t = q / (1 - q);
      double blocked[4];
      bb__slice_blocked(&si_, t, blocked);
      for (int c = 0; c < 3; c++) {
        const double exact = bb__lobe_blocked_exact(lo, hi, basis[c], 1.0, t);
        worst = fmax(worst, fabs(blocked[1 + c] - exact) / share[c]);
      }
    }
    cr_log_info("%d slices: relative interpolation error %g", sector_counts[si], worst);
    cr_assert_lt(worst, 1e-7, "%d slices: relative interpolation error %g", sector_counts[si], worst);
  }
}

/* ao's closed form is the integral of sin(theta) cos(theta) above the
 * horizon, and a horizon at or below 0 loses exactly nothing. */
Test(integrate, ao_in_closed_form_and_nothing_lost_below_the_plane) {
  double basis[3][3];
  for (int c = 0; c < 3; c++) bb__basis_vector(c, basis[c]);
  static double table[BB__TABLE_INTERVALS * 3 * 4];
  double share[3];
  bb__slice_table_build(0.0, 0.4, (const double(*)[3])basis, 3, 1.0, table, share);
  const bb__slice_integral si = {table, 0.2, 3};
  const double up[3] = {0, 0, 1};
  for (double t = 0.05; t < 40; t *= 1.7) {
    double blocked[4];
    bb__slice_blocked(&si, t, blocked);
    /* w.z over the sector is the lobe (0, 0, 1) at power 1 */
    const double expected = reference(0.0, 0.4, up, 1.0, 0.0) - reference(0.0, 0.4, up, 1.0, t);
    cr_assert_float_eq(blocked[0], expected, 1e-12, "t %g", t);
  }
  double zero[4];
  bb__slice_blocked(&si, 0.0, zero);
  for (int c = 0; c < 4; c++) cr_assert_eq(zero[c], 0.0, "channel %d", c);
}

/* The ray set's sectors tile the circle, its totals are the whole integrals
 * (pi for ao), and a horizon of 0 everywhere leaves every channel at 1. */
Test(integrate, rayset_sectors_and_totals) {
  const int counts[] = {1, 2, 7, 16, 32, 256};
  for (size_t i = 0; i < sizeof counts / sizeof counts[0]; i++) {
    bb_rayset rs;
    bb_error err;
    bb_basis hl2z;
    cr_assert_eq(bb__basis_parse("hl2+z", &hl2z, NULL), BB_OK);
    cr_assert_eq(bb__rayset_make(counts[i], 1.0, &hl2z, 0, &rs, &err), BB_OK, "%s", err.message);
    double width = 0.0;
    for (int s = 0; s < rs.slice_count; s++) {
      const double lo = rs.sector[2 * s], hi = rs.sector[2 * s + 1];
      cr_assert_lt(lo, hi);
      width += hi - lo;
      if (s + 1 < rs.slice_count)
        cr_assert_float_eq(remainder(rs.sector[2 * s + 2] - hi, 2 * PI), 0.0, 1e-12, "gap after slice %d", s);
    }
    cr_assert_float_eq(width, 2 * PI, 1e-12);
    cr_assert_float_eq(rs.total[0], PI, 1e-12);
    for (int c = 0; c < rs.basis_count; c++) {
      double b[3];
      bb__basis_vector(c, b);
      const double whole = reference(0.0, 2 * PI, b, 1.0, 0.0);
      cr_assert_float_eq(rs.total[1 + c], whole, 1e-9, "%d slices, lobe %d", counts[i], c);
    }
    bb__rayset_release(&rs);
  }
}

Test(integrate, rayset_rejects_bad_arguments) {
  bb_rayset rs;
  bb_error err;
  cr_assert_eq(bb__rayset_make(0, 1.0, NULL, 0, &rs, &err), BB_ERR_ARGUMENT);
  cr_assert_eq(bb__rayset_make(BB_MAX_SLICES + 1, 1.0, NULL, 0, &rs, &err), BB_ERR_ARGUMENT);
  cr_assert_eq(bb__rayset_make(16, 0.5, NULL, 0, &rs, &err), BB_ERR_ARGUMENT);
  cr_assert_eq(bb__rayset_make(16, NAN, NULL, 0, &rs, &err), BB_ERR_ARGUMENT);
}

Test(integrate, slices_for_rays_follow_valves_count) {
  cr_assert_eq(bb__slices_for_rays(250), 16);
  cr_assert_eq(bb__slices_for_rays(256), 16);
  cr_assert_eq(bb__slices_for_rays(64), 8);
  cr_assert_eq(bb__slices_for_rays(1024), 32);
  cr_assert_eq(bb__slices_for_rays(1), 1);
  cr_assert_eq(bb__slices_for_rays(65536), 256);
}

/* The four channels at once (three lobes, bb__slice_accumulate4, the
 * sweeps' path) add exactly the bits the lobes one by one add (the
 * march's path), over horizons from none to nearly vertical. */
Test(integrate, four_channels_at_once_add_the_same_bits) {
  double basis[3][3];
  for (int c = 0; c < 3; c++) bb__basis_vector(c, basis[c]);
  static double table[BB__TABLE_INTERVALS * 3 * 4];
  static bb__channels4 table4[BB__TABLE_INTERVALS * 4];
  double share[3];
  bb__slice_table_build(0.7, 0.7 + 2 * PI / 16, (const double(*)[3])basis, 3, 1.0, table, share);
  const bb__slice_integral si = {table, PI / 16, 3};
  bb__slice_table4(&si, table4);
  float one[5] = {0.25f, 0.5f, 0.0f, 1.0f, 0.0f}, four[5]; /* room for a 4th lobe's channel */
  memcpy(four, one, sizeof four);
  long compared = 0;
  for (float h = -1.0f; h < 1e6f; h = h < 1e-3f ? h + 0.0137f : h * 1.013f) {
    bb__slice_accumulate(&si, h, one);
    bb__slice_accumulate4(&si, table4, h, four);
    cr_assert(memcmp(one, four, 4 * sizeof(float)) == 0, "horizon %.9g: %.9g %.9g %.9g %.9g against %.9g %.9g %.9g %.9g",
              (double)h, one[0], one[1], one[2], one[3], four[0], four[1], four[2], four[3]);
    compared++;
  }
  cr_assert(compared > 1000, "%ld horizons", compared);
}
