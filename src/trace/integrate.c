/* integrate.c: the exact integrals of one azimuth sector above a horizon, and
 * the tables that make them cheap per texel.
 *
 * For a height field the visibility along one azimuth is a step in elevation:
 * a direction is open exactly when it rises above the horizon. A slice
 * stands for the azimuth sector [lo, hi] around its direction, with one
 * horizon elevation theta0 = atan(t) for the whole sector (t = the horizon's
 * tangent, rise per horizontal texel). What the sector loses to the horizon
 * is, for an integrand f(w) over H (the hemisphere z > 0, dw = cos(theta)
 * dtheta dphi):
 *
 *   G(t) = integral over phi in [lo, hi], theta in [0, theta0] of f(w) cos(theta)
 *
 * with theta0 = atan(max(t, 0)): a horizon below the tangent plane z = 0
 * blocks nothing of H, so G(t <= 0) = 0; G(+inf) is the sector's whole share.
 *
 * ao (f = w.z = sin(theta)) has the closed form G = (hi - lo)/2 * t^2/(1+t^2).
 * A basis lobe f = max(0, w.B)^P (B any unit vector, P >= 1) is clipped where
 * w.B < 0; its G has no closed form in general, so it is tabulated once per
 * bake: G as a function of q = t / (1 + t) in [0, 1) (q is smooth in theta0
 * and costs one division), at BB__TABLE_INTERVALS + 1 nodes, each value and
 * slope computed by adaptive Gauss-Legendre quadrature, and interpolated by
 * cubic Hermite pieces. With 256 intervals the interpolation error is under
 * 1e-7 of the sector's share (measured: 2.5e-8 for quarter-turn sectors,
 * 1.4e-9 for 16 and 32 slices; tests/test_integrate.c checks it and the
 * tables against an independent quadrature); node values are exact to
 * rounding.
 *
 * Layout of a slice's table: for interval k (q in [k, k+1] / N) and channel c,
 * 4 coefficients of the cubic in the interval's local coordinate, at
 * table[(k * channels + c) * 4]. q = 0 gives exactly 0, so an unobstructed
 * slice loses exactly nothing.
 */
#include "core/internal.h"
#include "trace/integrate.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* ---------------------------------------------- Gauss-Legendre quadrature */

/* Tolerance of every quadrature, relative to the scale of its integral: far
 * under the 1e-9 the tables are good for. */
#define RELATIVE_TOLERANCE 1e-14

/* A piece is split when the two rules differ by more than its tolerance, at
 * most MAX_DEPTH times: smooth pieces (every piece at power 1) never are. */
enum { GL_LOW = 7, GL_HIGH = 14, MAX_DEPTH = 12 };

void bb__gauss_legendre(int n, double *x, double *w) {
  for (int i = 0; i < n; i++) {
    double z = cos(BB__PI * (i + 0.75) / (n + 0.5)), dp = 1.0;
    for (int iteration = 0; iteration < 100; iteration++) {
      double p0 = 1.0, p1 = 0.0;
      for (int k = 1; k <= n; k++) {
        const double p2 = p1;
        p1 = p0;
        p0 = ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p2) / k;
      }
      dp = n * (z * p0 - p1) / (z * z - 1.0);
      const double step = p0 / dp;
      z -= step;
      if (fabs(step) < 1e-16) break;
    }
    x[i] = z;
    w[i] = 2.0 / ((1.0 - z * z) * dp * dp);
  }
}

typedef struct rules {
  double xl[GL_LOW], wl[GL_LOW], xh[GL_HIGH], wh[GL_HIGH];
} rules;

static void rules_init(rules *r) {
  bb__gauss_legendre(GL_LOW, r->xl, r->wl);
  bb__gauss_legendre(GL_HIGH, r->xh, r->wh);
}

typedef double (*integrand_fn)(const void *ctx, double x);

static double rule_apply(integrand_fn f, const void *ctx, double a, double b, int n,
                         const double *x, const double *w) {
  const double mid = 0.5 * (a + b), half = 0.5 * (b - a);
  double sum = 0.0;
  for (int i = 0; i < n; i++) sum += w[i] * f(ctx, mid + half * x[i]);
  return sum * half;
}

/* Integral of f over [a, b]: the 14-point rule where it agrees with the
 * 7-point one to within tolerance, else the two halves. */
static double adaptive(const rules *r, integrand_fn f, const void *ctx, double a, double b,
                       double tolerance, int depth) {
  const double high = rule_apply(f, ctx, a, b, GL_HIGH, r->xh, r->wh);
  const double low = rule_apply(f, ctx, a, b, GL_LOW, r->xl, r->wl);
  if (fabs(high - low) <= tolerance || depth >= MAX_DEPTH || !(b > a)) return high;
  const double mid = 0.5 * (a + b);
  return adaptive(r, f, ctx, a, mid, 0.5 * tolerance, depth + 1) +
         adaptive(r, f, ctx, mid, b, 0.5 * tolerance, depth + 1);
}

/* ------------------------------------------ a lobe over one ring of H */

/* max(0, w.B)^P with w at elevation theta, azimuth phi is
 * max(0, A cos(phi - beta) + C)^P, A = rho cos(theta), C = Bz sin(theta). */
typedef struct lobe {
  double rho, beta, bz, power;
  double lo, hi; /* the sector's azimuths */
  const rules *r;
} lobe;

/* The piece of a ring where the lobe is positive, in psi = phi - beta,
 * integrated numerically. `zero` says which ends are zeros of the lobe
 * (1: a, 2: b); near a zero, psi = end + (length) x^2 spreads the rule's
 * nodes where (psi - end)^P is least smooth. */
typedef struct piece {
  double a, b, amplitude, offset, power;
  int zero;
} piece;

static double piece_value(const piece *p, double psi) {
  const double v = p->amplitude * cos(psi) + p->offset;
  return v > 0.0 ? pow(v, p->power) : 0.0;
}

static double piece_from_a(const void *ctx, double x) {
  const piece *p = ctx;
  return piece_value(p, p->a + (p->b - p->a) * x * x) * 2.0 * (p->b - p->a) * x;
}

static double piece_from_b(const void *ctx, double x) {
  const piece *p = ctx;
  return piece_value(p, p->b - (p->b - p->a) * x * x) * 2.0 * (p->b - p->a) * x;
}

static double piece_plain(const void *ctx, double psi) {
  return piece_value(ctx, psi);
}

static double piece_integral(const rules *r, piece *p) {
  if (!(p->b > p->a)) return 0.0;
  if (p->power == 1.0) /* closed form */
    return p->amplitude * (sin(p->b) - sin(p->a)) + p->offset * (p->b - p->a);
  const double scale = (p->b - p->a) * pow(fabs(p->amplitude) + fabs(p->offset), p->power);
  const double tolerance = RELATIVE_TOLERANCE * scale + 1e-300;
  if (p->zero == 3) { /* zeros at both ends: each half from its zero */
    const double mid = 0.5 * (p->a + p->b);
    piece left = *p, right = *p;
    left.b = mid, left.zero = 1;
    right.a = mid, right.zero = 2;
    return piece_integral(r, &left) + piece_integral(r, &right);
  }
  if (p->zero == 1) return adaptive(r, piece_from_a, p, 0.0, 1.0, tolerance, 0);
  if (p->zero == 2) return adaptive(r, piece_from_b, p, 0.0, 1.0, tolerance, 0);
  return adaptive(r, piece_plain, p, p->a, p->b, tolerance, 0);
}

/* I(theta): the integral over the sector of max(0, w.B)^P at elevation theta. */
static double lobe_ring(const lobe *l, double theta) {
  const double amplitude = l->rho * cos(theta), offset = l->bz * sin(theta);
  const double lo = l->lo - l->beta, hi = l->hi - l->beta;
  piece p = {lo, hi, amplitude, offset, l->power, 0};
  if (!(amplitude > 1e-15 * fabs(offset))) /* constant around the ring */
    return offset > 0.0 ? (hi - lo) * pow(offset, l->power) : 0.0;
  const double kappa = -offset / amplitude; /* positive where cos(psi) > kappa */
  if (kappa <= -1.0) return piece_integral(l->r, &p);
  if (kappa >= 1.0) return 0.0;
  const double alpha = acos(kappa), period = 2.0 * BB__PI;
  double sum = 0.0;
  const int k_first = (int)ceil((lo - alpha) / period), k_last = (int)floor((hi + alpha) / period);
  for (int k = k_first; k <= k_last; k++) {
    const double start = -alpha + period * k, end = alpha + period * k;
    p.a = lo > start ? lo : start;
    p.b = hi < end ? hi : end;
    p.zero = (p.a == start ? 1 : 0) | (p.b == end ? 2 : 0);
    sum += piece_integral(l->r, &p);
  }
  return sum;
}

/* cos(theta) I(theta), the theta integrand of G. */
static double lobe_theta(const void *ctx, double theta) {
  return cos(theta) * lobe_ring(ctx, theta);
}

/* Elevations where I(theta) is not smooth: where the ends of the positive
 * arc (cos(psi) = kappa(theta)) cross the sector's edges, and where the arc
 * closes into the whole ring. Sorted into out; returns how many. */
static int lobe_kinks(const lobe *l, double *out) {
  int n = 0;
  if (!(l->rho > 0.0) || l->bz == 0.0) return 0;
  const double edges[2] = {l->lo - l->beta, l->hi - l->beta};
  for (int e = 0; e < 2; e++) { /* kappa = cos(edge): tan(theta) = -rho cos(edge) / Bz */
    const double theta = atan(-l->rho * cos(edges[e]) / l->bz);
    if (theta > 0.0 && theta < 0.5 * BB__PI) out[n++] = theta;
  }
  const double closes = atan(l->rho / fabs(l->bz)); /* |kappa| = 1 */
  if (closes > 0.0 && closes < 0.5 * BB__PI) out[n++] = closes;
  for (int i = 1; i < n; i++)
    for (int j = i; j > 0 && out[j] < out[j - 1]; j--) {
      const double swap = out[j];
      out[j] = out[j - 1];
      out[j - 1] = swap;
    }
  return n;
}

/* The integral of cos(theta) I(theta) over [a, b], split at the kinks.
 * At power 1 each piece is analytic and far narrower than its curvature
 * (a table interval is at most 1/256 of a quarter turn), so the 7-point
 * rule alone is exact to rounding; other powers are checked adaptively. */
static double lobe_between(const lobe *l, const double *kinks, int kink_count, double a,
                           double b, double tolerance) {
  double sum = 0.0, from = a;
  for (int i = 0; i <= kink_count; i++) {
    const double to = i < kink_count && kinks[i] < b ? kinks[i] : b;
    if (to > from) {
      sum += l->power == 1.0 && to - from < 0.01
                 ? rule_apply(lobe_theta, l, from, to, GL_LOW, l->r->xl, l->r->wl)
                 : adaptive(l->r, lobe_theta, l, from, to, tolerance, 0);
      from = to;
    }
    if (to >= b) break;
  }
  return sum;
}

static void lobe_init(lobe *l, const rules *r, double lo, double hi, const double b[3],
                      double power) {
  l->rho = hypot(b[0], b[1]);
  l->beta = l->rho > 0.0 ? atan2(b[1], b[0]) : 0.0;
  l->bz = b[2];
  l->power = power;
  l->lo = lo;
  l->hi = hi;
  l->r = r;
}

/* ------------------------------------------------------------- public side */

static double elevation_of_q(double q) {
  return atan2(q, 1.0 - q); /* atan(t), t = q / (1 - q); exactly pi/2 at q = 1 */
}

double bb__lobe_blocked_exact(double lo, double hi, const double b[3], double power,
                              double tan_horizon) {
  if (!(tan_horizon > 0.0)) return 0.0;
  rules r;
  rules_init(&r);
  lobe l;
  lobe_init(&l, &r, lo, hi, b, power);
  double kinks[3];
  const int n = lobe_kinks(&l, kinks);
  return lobe_between(&l, kinks, n, 0.0, atan(tan_horizon), RELATIVE_TOLERANCE * (hi - lo));
}

/* One channel of a slice's table: node values and slopes in q, then the
 * Hermite cubic of each interval. Returns the sector's whole share, G(q = 1). */
static double fill_channel(const rules *r, double lo, double hi, const double b[3],
                           double power, double *table, int channels, int c) {
  enum { N = BB__TABLE_INTERVALS };
  lobe l;
  lobe_init(&l, r, lo, hi, b, power);
  double kinks[3];
  const int kink_count = lobe_kinks(&l, kinks);
  const double h = 1.0 / N, tolerance = RELATIVE_TOLERANCE * h * (hi - lo);
  double value = 0.0, theta = 0.0;
  double slope = lobe_theta(&l, 0.0); /* dG/dq at q = 0, where dtheta/dq = 1 */
  for (int k = 0; k < N; k++) {
    const double q1 = (double)(k + 1) * h, theta1 = elevation_of_q(q1);
    const double value1 = value + lobe_between(&l, kinks, kink_count, theta, theta1, tolerance);
    const double dtheta_dq = 1.0 / ((1.0 - q1) * (1.0 - q1) + q1 * q1);
    const double slope1 = lobe_theta(&l, theta1) * dtheta_dq;
    const double delta = value1 - value, d0 = h * slope, d1 = h * slope1;
    double *coef = table + ((size_t)k * (size_t)channels + (size_t)c) * 4;
    coef[0] = value;
    coef[1] = d0;
    coef[2] = 3.0 * delta - 2.0 * d0 - d1;
    coef[3] = -2.0 * delta + d0 + d1;
    value = value1, theta = theta1, slope = slope1;
  }
  return value;
}

void bb__slice_blocked_more(const double *coef, double f, int lobes, double *blocked) {
  for (int c = 4; c < lobes; c++) blocked[1 + c] = BB__HERMITE(coef, f, c);
}

void bb__slice_accumulate_more(const bb__slice_integral *si, float horizon, float *sums) {
  double blocked[1 + BB_MAX_BASIS];
  bb__slice_blocked(si, (double)horizon, blocked);
  for (int c = 0; c <= si->lobes; c++) sums[c] += (float)blocked[c];
}

void bb__slice_table_build(double lo, double hi, const double (*basis)[3], int basis_count,
                           double power, double *table, double *share) {
  rules r;
  rules_init(&r);
  for (int c = 0; c < basis_count; c++)
    share[c] = fill_channel(&r, lo, hi, basis[c], power, table, basis_count, c);
}
