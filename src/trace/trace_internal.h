/* trace_internal.h: the pyramid's layout, the horizon march, the line sweeps
 * and the sector integration, shared by pyramid.c, trace.c, sweep.c,
 * integrate.c, rayset.c and the tracer's tests. */
#ifndef BB_TRACE_INTERNAL_H
#define BB_TRACE_INTERNAL_H

#include "bumpbake.h"

#include <math.h>
#include <stdint.h>

#define BB__MAX_LEVELS 32

struct bb_pyramid {
  int width, height;              /* texels = cells per row / column */
  bb_addressing addressing;
  float *z;                       /* heights in texels, width*height */
  int levels;                     /* level levels-1 has one node */
  int level_width[BB__MAX_LEVELS];
  int level_height[BB__MAX_LEVELS];
  float *level_max[BB__MAX_LEVELS]; /* node maxima, row-major per level */
  float global_max, global_min;
  float border_max;               /* max over the border vertices (clamp mode) */
};

/* ------------------------------------------------------------ integration */

/* Intervals of a slice's table in q = t / (1 + t) (integrate.c). */
#define BB__TABLE_INTERVALS 256

/* Fills table (BB__TABLE_INTERVALS * basis_count * 4 doubles) with the cubic
 * pieces of G_c(q) for the sector [lo, hi] (azimuths, radians) and each lobe
 * max(0, w.B_c)^power, and share[c] with the sector's whole integral of it. */
void bb__slice_table_build(double lo, double hi, const double (*basis)[3], int basis_count,
                           double power, double *table, double *share);

/* The integrals the tables interpolate, by adaptive quadrature (for tests):
 * what the sector [lo, hi] loses to a horizon of tangent t, for the lobe
 * max(0, w.b)^power and for ao (w.z, in closed form). */
double bb__lobe_blocked_exact(double lo, double hi, const double b[3], double power,
                              double tan_horizon);
double bb__ao_blocked(double lo, double hi, double tan_horizon);

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

/* ------------------------------------------------------------------ march */

/* A ray for the march: origin, unit horizontal direction. */
typedef struct bb__march_ray {
  double ox, oy, oz;
  double dx, dy;
} bb__march_ray;

/* 1 when some breakpoint of the surface along the ray's vertical half-plane
 * (cell edge or diagonal crossing, horizontal distance t > 0) has slope
 * (surface - oz) / t >= tan_el, else 0. Max-mip march / brute-force DDA. */
int bb__march_occluded(const bb_pyramid *p, const bb__march_ray *r, double tan_el);
int bb__march_occluded_brute(const bb_pyramid *p, const bb__march_ray *r, double tan_el);

/* The largest slope (surface - oz) / t over the breakpoints at 0 < t <=
 * max_distance, or 0 when none is positive. */
double bb__march_horizon(const bb_pyramid *p, const bb__march_ray *r, double max_distance);
double bb__march_horizon_brute(const bb_pyramid *p, const bb__march_ray *r,
                               double max_distance);

/* The horizon of lattice step (a, b) from vertex (x, y) lifted by bias, as
 * every path of the bake computes it: each breakpoint from integers (its
 * crossing index n and family count m: distance n / m steps, interpolation
 * weight r / m), the largest slope per step over one period of a periodic
 * line (nothing further is new) or up to where a clamped line turns flat,
 * 0 when none is positive, divided by |(a, b)| and rounded to float. */
float bb__slice_horizon(const bb_pyramid *p, int x, int y, double bias, int a, int b);
float bb__slice_horizon_brute(const bb_pyramid *p, int x, int y, double bias, int a, int b);

/* Steps after which a periodic line of step (a, b) comes back to its start. */
long bb__line_period(const bb_pyramid *p, int a, int b);

/* Canonical parts of a breakpoint, shared by the march and the sweeps so
 * both compute the same bits (plain IEEE operations, no contraction): the
 * distance n / m steps and the weight r / m, both as a product with the
 * rounded 1 / m (a multiply is cheaper than a division in the sweeps' inner
 * loops; what matters is that every path rounds alike), and the height at
 * weight w between za and zb. */
static inline double bb__lattice_inverse(int m) {
  return 1.0 / (double)m;
}
static inline double bb__lattice_distance(long n, double inverse_m) {
  return (double)n * inverse_m;
}
static inline double bb__lattice_weight(long r, double inverse_m) {
  return (double)r * inverse_m;
}
static inline double bb__lattice_height(double za, double zb, double w) {
  return za + (zb - za) * w;
}
/* |(a, b)|, one correctly rounded square root, and its inverse. */
static inline double bb__step_length(int a, int b) {
  return sqrt((double)a * (double)a + (double)b * (double)b);
}
static inline double bb__step_inverse(int a, int b) {
  return 1.0 / bb__step_length(a, b);
}
/* The horizon in texels of the best slope per step (>= 0). */
static inline float bb__lattice_horizon(double best_per_step, double step_inverse) {
  return (float)(best_per_step * step_inverse);
}

/* ----------------------------------------------------------------- sweeps */

/* How bb_trace_occlusion finds each texel's horizons. */
typedef enum bb__trace_path {
  BB__TRACE_MARCH, /* texel by texel, every slice by a max-mip march */
  BB__TRACE_SWEEP  /* slice by slice, line sweeps */
} bb__trace_path;

/* bb_trace_occlusion with the path chosen by the caller. For tests. */
bb_status bb__trace_occlusion_path(const bb_pyramid *p, const bb_rayset *rs,
                                   const bb_trace_options *o, bb__trace_path path,
                                   bb_image *vis, bb_error *err);

/* One direction of a line sweep: slice s of rs, whose loss at each texel is
 * added to sums (1 + basis_count floats per texel); horizon (may be NULL)
 * receives each texel's horizon, for tests. */
typedef struct bb__sweep_dir {
  const bb_rayset *rs;
  int slice;
  float *sums;
  float *horizon;
} bb__sweep_dir;

/* Either addressing mode: for the lattice step (a, b) of `along` and its
 * opposite, by line sweeps (sweep.c), origins lifted by bias. Either
 * direction may be NULL; both share one profile of each line. Periodic lines
 * longer than long_line steps (0: the default) are cut into chunks whose far
 * texels are checked, and marched when the chunk cannot vouch for them. */
bb_status bb__sweep_lines(const bb_pyramid *p, int a, int b, const bb__sweep_dir *along,
                          const bb__sweep_dir *opposite, double bias, int threads,
                          long long_line, bb_error *err);

#endif /* BB_TRACE_INTERNAL_H */
