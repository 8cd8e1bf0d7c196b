/* march.h: horizons of single rays and of lattice slices,
 * marched through the max-mip pyramid (march.c), and the canonical parts of
 * a breakpoint that the sweeps share so every path finds the same bits. */
#ifndef BB_TRACE_MARCH_H
#define BB_TRACE_MARCH_H

#include "bumpbake.h"


#include <math.h>

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

/* The horizon of lattice step (a, b) from vertex (x, y) lifted by bias, as
 * every path of the bake computes it: each breakpoint from integers (its
 * crossing index n and family count m: distance n / m steps, interpolation
 * weight r / m), the largest slope per step over one period of a periodic
 * line (nothing further is new) or up to where a clamped line turns flat,
 * 0 when none is positive, divided by |(a, b)| and rounded to float. */
float bb__slice_horizon(const bb_pyramid *p, int x, int y, double bias, int a, int b);
float bb__slice_horizon_brute(const bb_pyramid *p, int x, int y, double bias, int a, int b);
/* bb__slice_horizon for texels marched one after another along a row: *hint
 * (0 at first) keeps where the last texel's horizon was, which the march
 * tries first; the horizon found is the same. */
float bb__slice_horizon_hinted(const bb_pyramid *p, int x, int y, double bias, int a, int b,
                               double *hint);
/* bb__slice_horizon for a texel whose horizon is known to be at least
 * `slope` per step, the canonical slope of one of its breakpoints, and to
 * be no other breakpoint's within from_steps steps (a sweep's tangent over
 * that much of the line): the march starts from that slope and that
 * distance, so whole nodes below it are skipped from the start, and finds
 * the same horizon. */
float bb__slice_horizon_above(const bb_pyramid *p, int x, int y, double bias, int a,
                              int b, double slope, double from_steps);

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

#endif /* BB_TRACE_MARCH_H */
