/* integrate.h: a slice's exact integration over its sector: the
 * tables rayset.c builds (integrate.c) and the inline loss every path of the
 * trace adds, so the same horizon gives the same bits. */
#ifndef BB_TRACE_INTEGRATE_H
#define BB_TRACE_INTEGRATE_H

#include "trace/rayset.h"

#include <stddef.h>
#include <string.h>

/* Intervals of a slice's table in q = t / (1 + t) (integrate.c). */
#define BB__TABLE_INTERVALS 256

/* Fills table (BB__TABLE_INTERVALS * basis_count * 4 doubles) with the cubic
 * pieces of G_c(q) for the sector [lo, hi] (azimuths, radians) and each lobe
 * max(0, w.B_c)^power, and share[c] with the sector's whole integral of it. */
void bb__slice_table_build(double lo, double hi, const double (*basis)[3], int basis_count,
                           double power, double *table, double *share);

/* The integral the tables interpolate, by adaptive quadrature (for tests):
 * what the sector [lo, hi] loses to a horizon of tangent t, for the lobe
 * max(0, w.b)^power. */
double bb__lobe_blocked_exact(double lo, double hi, const double b[3], double power,
                              double tan_horizon);

/* Nodes x[0..n-1] and weights w[0..n-1] of the n-point Gauss-Legendre rule
 * on [-1, 1] (Newton on P_n, to 1e-16). */
void bb__gauss_legendre(int n, double *x, double *w);

/* One slice's integration, gathered for the inner loops. */
typedef struct bb__slice_integral {
  const double *table; /* the slice's table (layout in integrate.c) */
  double half_width;   /* (last - first azimuth) / 2: ao's share over 2 */
  int lobes;           /* basis_count */
} bb__slice_integral;

static inline bb__slice_integral bb__slice_integral_of(const bb_rayset *rs, int s) {
  const bb__slice_integral si = {
      rs->table + (size_t)s * BB__TABLE_INTERVALS * (size_t)rs->basis_count * 4,
      rs->half_width[s], rs->basis_count};
  return si;
}

/* Lobes past the fourth (bases of more than 4 directions), out of line so
 * the inner loops of 3 and 4 lobes keep their values in registers:
 * blocked[1 + c] for c = 4..lobes-1 from a table interval's coefficients
 * coef at fraction f; and bb__slice_accumulate for any count. */
void bb__slice_blocked_more(const double *coef, double f, int lobes, double *blocked);
void bb__slice_accumulate_more(const bb__slice_integral *si, float horizon, float *sums);

/* One lobe's cubic piece at fraction f of its interval. */
#define BB__HERMITE(coef, f, c)                                                                  \
  ((coef)[4 * (c)] +                                                                             \
   (f) * ((coef)[4 * (c) + 1] + (f) * ((coef)[4 * (c) + 2] + (f) * (coef)[4 * (c) + 3])))

/* What the slice loses to a horizon of tangent t >= 0 (the float the
 * tracer found, as a double): blocked[0] for ao, blocked[1 + c] per lobe,
 * for up to the first 4 lobes; *coef and *f receive the interval's
 * coefficients and fraction for bb__slice_blocked_more. */
static inline void bb__slice_blocked4(const bb__slice_integral *si, double t, double *blocked,
                                      const double **coef_out, double *f_out) {
  /* one division for both t^2 / (1 + t^2) and q = t / (1 + t) */
  const double tt = t * t, one_t = 1.0 + t, one_tt = 1.0 + tt;
  const double inverse = 1.0 / (one_t * one_tt);
  blocked[0] = si->half_width * (tt * one_t * inverse);
  const double x = t * one_tt * inverse * BB__TABLE_INTERVALS;
  int k = (int)x;
  if (k > BB__TABLE_INTERVALS - 1) k = BB__TABLE_INTERVALS - 1;
  const double f = x - (double)k;
  const double *coef = si->table + (size_t)k * (size_t)si->lobes * 4;
  blocked[1] = BB__HERMITE(coef, f, 0);
  blocked[2] = BB__HERMITE(coef, f, 1);
  blocked[3] = BB__HERMITE(coef, f, 2);
  if (si->lobes > 3) blocked[4] = BB__HERMITE(coef, f, 3);
  *coef_out = coef;
  *f_out = f;
}

/* What the slice loses to a horizon of tangent t >= 0: blocked[0] for ao,
 * blocked[1 + c] per lobe (1 + lobes values). One inline function for
 * every path, so the same horizon gives the same bits; lobes is
 * 3..BB_MAX_BASIS, the first 4 unrolled. */
static inline void bb__slice_blocked(const bb__slice_integral *si, double t, double *blocked) {
  const double *coef;
  double f;
  bb__slice_blocked4(si, t, blocked, &coef, &f);
  if (si->lobes > 4) bb__slice_blocked_more(coef, f, si->lobes, blocked);
}

/* Adds the slice's loss at a horizon to a texel's float sums (1 + lobes
 * channels), always in the same order of operations. A horizon of 0 loses
 * nothing, and adding zeros would change no bit, so it adds nothing. */
static inline void bb__slice_accumulate(const bb__slice_integral *si, float horizon, float *sums) {
  if (!(horizon > 0.0f)) return;
  if (si->lobes > 4) {
    bb__slice_accumulate_more(si, horizon, sums);
    return;
  }
  double blocked[1 + 4];
  const double *coef;
  double f;
  bb__slice_blocked4(si, (double)horizon, blocked, &coef, &f);
  sums[0] += (float)blocked[0];
  sums[1] += (float)blocked[1];
  sums[2] += (float)blocked[2];
  sums[3] += (float)blocked[3];
  if (si->lobes > 3) sums[4] += (float)blocked[4];
}

/* Three lobes (Half-Life 2's basis and any other of 3 vectors), the four
 * channels of a texel's sums at once: a slice's table laid out again, per
 * interval its 4 coefficients as vectors of the 4 channels (channel 0, ao,
 * zero: ao is not a table), so one vector operation does the Hermite
 * piece's step for every lobe, each lane exactly as BB__HERMITE does it
 * (the same operations in the same order; ao's lane adds f * 0 = 0 to
 * ao), and the four floats are added to the sums at once. The same bits
 * as bb__slice_accumulate; rock06: a third of the integration's
 * instructions. */
typedef double bb__channels4 __attribute__((vector_size(4 * sizeof(double))));
typedef float bb__channels4f __attribute__((vector_size(4 * sizeof(float))));

/* out: BB__TABLE_INTERVALS * 4 vectors, from si's table (si->lobes == 3). */
static inline void bb__slice_table4(const bb__slice_integral *si, bb__channels4 *out) {
  for (int k = 0; k < BB__TABLE_INTERVALS; k++)
    for (int e = 0; e < 4; e++) {
      const double *coef = si->table + (size_t)k * 12;
      out[k * 4 + e] = (bb__channels4){0.0, coef[e], coef[4 + e], coef[8 + e]};
    }
}

static inline __attribute__((always_inline)) void bb__slice_accumulate4(
    const bb__slice_integral *si, const bb__channels4 *table4, float horizon, float *sums) {
  if (!(horizon > 0.0f)) return;
  const double t = (double)horizon; /* as bb__slice_blocked4 */
  const double tt = t * t, one_t = 1.0 + t, one_tt = 1.0 + tt;
  const double inverse = 1.0 / (one_t * one_tt);
  const double ao = si->half_width * (tt * one_t * inverse);
  const double x = t * one_tt * inverse * BB__TABLE_INTERVALS;
  int k = (int)x;
  if (k > BB__TABLE_INTERVALS - 1) k = BB__TABLE_INTERVALS - 1;
  const double f = x - (double)k;
  const bb__channels4 *c = table4 + (size_t)k * 4;
  bb__channels4 c0 = c[0];
  c0[0] = ao;
  const bb__channels4 blocked = c0 + f * (c[1] + f * (c[2] + f * c[3]));
  bb__channels4f add = __builtin_convertvector(blocked, bb__channels4f), sum;
  memcpy(&sum, sums, sizeof sum);
  sum += add;
  memcpy(sums, &sum, sizeof sum);
}

#endif /* BB_TRACE_INTEGRATE_H */
