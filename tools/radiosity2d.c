/* radiosity2d.c: the exact inter-reflection of a height field that is one
 * profile extruded along y, to hold the bake's bounce to.
 *
 *   radiosity2d profile NAME OUT          trench | vgroove | step | sine | trench-small
 *   radiosity2d solve MAP SCALE [options]
 *   radiosity2d compare MAP SCALE [options] --base AO.exr,SS.exr NAME=AO.exr,SS.exr ...
 *
 * options: --rho R (0.5), --bias B (0.55), --bounces N (0: converged),
 * --basis NAME (hl2), --power P (1), --strip L (0.1), --normal-filter NAME
 * (vertex), --texels (compare: every column's figures on stderr).
 *
 * MAP is read as a bake reads it (bb__height_file_read, heights times SCALE
 * in float); every row must be the same, and the bake it is compared with
 * must be a clamped one (`bake --clamp --filter-radius 0`): then the bake's
 * surface, two triangles per cell, is exactly the profile's polyline
 * extruded along y, flat past the image's left and right edges at the
 * border's height. The light of such a surface is a 2D problem. The
 * profile, its flat extensions out to 1e6 texels included, is cut into
 * strips (at most --strip texels long in the image, growing by a quarter
 * each outside it), each Lambertian with albedo rho and one radiance per
 * channel. The view factor between two strips is Hottel's crossed strings,
 *   F_ij = (|a_i a_j| + |b_i b_j| - |a_i b_j| - |b_i a_j|) / (2 |a_i b_i|),
 * each string pulled taut over the profile (its length the upper convex
 * hull of the profile between its ends), which makes the occlusion exact;
 * what a strip does not see of the profile is sky. Channel k's radiances J
 * solve the linear system
 *   J_i = rho (S_ik + sum_j F_ij J_j)
 * (Gaussian elimination; --bounces N iterates it N times from 0 instead),
 * where S_ik is the sky's light on strip i over pi: for ao (radiance 1)
 * 1 - sum_j F_ij, for lobe c (radiance max(0, w.B_c)^P, docs/conventions.md)
 * an integral over the directions strip i sees open, taken at 8 points of
 * the strip (a lune of directions between its two horizons, in closed form
 * across y for P = 1, by Gauss-Legendre otherwise). The ao closure is also
 * integrated that way, and solve reports how far the two differ (the
 * quadrature's error).
 *
 * A texel's origin (x, z + bias) sees, above its horizontal, the pieces of
 * strips no nearer strip hides (a walk out from it, each way); the light
 * they add (the bake's "added light": with the bounce, minus without):
 *   ao:    sum J_ao (cos a0 - cos a1) / 2
 *   vis_c: sum J_c 2 (a1 - a0) / T_c,   T_c = integral_H max(0, w.B_c)^P dw
 * over each piece's angles a0 < a1 from the horizontal in the profile's
 * plane (the y direction integrated out). Also the texel's own ao and
 * vis_c without a bounce, from its two horizons.
 *
 * solve prints one JSON line per column (x, the direct ao and vis, the
 * added light) and a summary line. compare reads the bakes with and without
 * the bounce (float EXRs of ao and ssbump, MAP's size) and prints, per
 * result, the largest and mean |added - exact added| over every texel, its
 * bias, and where the largest is, for ao and each ssbump channel (ssbump's
 * added light is max(0, N.B_c) times vis_c's, N the bake's normal; texels
 * whose ssbump reaches 1 are left out and counted). Exits 1 when a file
 * cannot be read or is not such a profile, 2 on a bad command line.
 */
#include "job/job_internal.h"
#include "bumpbake.h"
#include "core/internal.h"
#include "trace/integrate.h"
#include "bake/bake_internal.h"
#include "image/image_write.h"
#include "trace/basis.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_LOBES BB_MAX_BASIS
#define MAX_CHANNELS (1 + MAX_LOBES)
#define FAR 1e6        /* texels: how far the flat extensions reach */
#define GROWTH 1.25    /* strip length ratio outside the image */
#define STRIP_POINTS 8 /* Gauss-Legendre points along a strip */
#define PSI_NODES 48   /* across y, for P != 1 */
#define MAX_RESULTS 16

typedef struct args {
  const char *map;
  double scale, rho, bias, power, strip;
  int bounces, texels;
  bb_basis basis;
  bb_normal_filter filter;
} args;

static int usage(const char *reason) {
  fprintf(stderr,
          "radiosity2d: %s\n"
          "usage: radiosity2d profile trench|vgroove|step|sine|trench-small OUT\n"
          "       radiosity2d solve MAP SCALE [--rho R] [--bias B] [--bounces N] "
          "[--basis NAME]\n"
          "                   [--power P] [--strip L]\n"
          "       radiosity2d compare MAP SCALE [the options of solve] [--normal-filter "
          "NAME]\n"
          "                   [--texels] --base AO.exr,SS.exr NAME=AO.exr,SS.exr ...\n",
          reason);
  return 2;
}

static int parse_number(const char *s, double lo, double hi, double *out) {
  char *end;
  errno = 0;
  const double v = strtod(s, &end);
  if (errno || end == s || *end || !isfinite(v) || v < lo || v > hi)
    return 1;
  *out = v;
  return 0;
}

/* ------------------------------------------------------------ profiles */

/* The profiles the bench and tests use, heights in [0, 1] (bake them at
 * scale 12, --clamp): a trench of 16 floor texels between walls rising 12
 * within one texel; a V groove 12 deep and 16 wide (slopes of 1.5); a step
 * of 12 within one texel; three periods of a sine of period 16, 12 from
 * trough to crest, between plateaus at the crest. trench-small (scale 6):
 * 8 floor texels between walls of 6, for the tests. */
static int write_profile(const char *name, const char *out) {
  int w = 40, rows = 8;
  if (!strcmp(name, "sine"))
    w = 57;
  if (!strcmp(name, "trench-small"))
    w = 20, rows = 4;
  bb_image h;
  bb_error err;
  if (bb_image_alloc(&h, w, rows, 1, &err) != BB_OK) {
    fprintf(stderr, "radiosity2d: %s\n", err.message);
    return 1;
  }
  for (int x = 0; x < w; x++) {
    double v;
    if (!strcmp(name, "trench"))
      v = x <= 11 || x >= 28 ? 1.0 : 0.0;
    else if (!strcmp(name, "trench-small"))
      v = x <= 5 || x >= 14 ? 1.0 : 0.0;
    else if (!strcmp(name, "vgroove"))
      v = x <= 11 || x >= 27 ? 1.0 : fabs(x - 19.0) / 8.0;
    else if (!strcmp(name, "step"))
      v = x <= 19 ? 0.0 : 1.0;
    else if (!strcmp(name, "sine"))
      v = x <= 4 || x >= 52 ? 1.0 : 0.5 + 0.5 * cos(2.0 * BB__PI * (x - 4) / 16.0);
    else {
      bb_image_free(&h);
      return usage("the profiles are trench, vgroove, step, sine and trench-small");
    }
    for (int y = 0; y < rows; y++)
      *bb_image_texel(&h, x, y) = (float)v;
  }
  const bb_write_options wo = {BB_DEPTH_FLOAT, BB_RANGE_UNIT, NULL, NULL};
  const bb_status st = bb__image_write(out, &h, &wo, &err);
  bb_image_free(&h);
  if (st != BB_OK)
    fprintf(stderr, "radiosity2d: %s\n", err.message);
  return st != BB_OK;
}

/* ------------------------------------------------------------- the sky */

typedef struct sky {
  int lobes;
  double basis[MAX_LOBES][3], power;
  double total[MAX_LOBES]; /* T_c */
  double gl_x[PSI_NODES], gl_w[PSI_NODES];
} sky;

/* Across y, for a direction whose angle in the profile's plane is phi:
 * integral over psi in (-pi/2, pi/2) of max(0, A cos psi + b_y sin psi)^P
 * cos^k psi, A = b_x cos phi + b_z sin phi (w = (cos psi cos phi, sin psi,
 * cos psi sin phi), dw = cos psi dpsi dphi; k = 1 for solid angle, 2 with
 * the cosine of a normal in the plane). */
static double across(const sky *k, const double b[3], double phi, int power_of_cos) {
  const double A = b[0] * cos(phi) + b[2] * sin(phi), R = hypot(A, b[1]);
  if (!(R > 0.0))
    return 0.0;
  const double delta = atan2(b[1], A);
  const double lo = fmax(-0.5 * BB__PI, delta - 0.5 * BB__PI);
  const double hi = fmin(0.5 * BB__PI, delta + 0.5 * BB__PI);
  if (!(hi > lo))
    return 0.0;
  if (k->power == 1.0) { /* R cos(psi - delta) cos^k psi, in closed form */
    if (power_of_cos == 1) {
#define F1(p) (sin(2.0 * (p)-delta) / 4.0 + (p)*cos(delta) / 2.0)
      return R * (F1(hi) - F1(lo));
#undef F1
    }
#define F2(p)                                                                            \
  (sin((p)-delta) / 2.0 + sin(3.0 * (p)-delta) / 12.0 + sin((p) + delta) / 4.0)
    return R * (F2(hi) - F2(lo));
#undef F2
  }
  /* the lobe vanishes at an end of (lo, hi) that is delta -+ pi/2: spread
   * the nodes there (psi = end + L t^2), where (cos)^P is least smooth */
  const int zero_lo = lo == delta - 0.5 * BB__PI, zero_hi = hi == delta + 0.5 * BB__PI;
  double sum = 0.0;
  const double mid = zero_lo && zero_hi ? 0.5 * (lo + hi) : (zero_lo ? hi : lo);
  for (int part = 0; part < 2; part++) {
    const double a = part ? mid : lo, e = part ? hi : mid;
    if (!(e > a))
      continue;
    const int spread_a = part == 0 && zero_lo, spread_e = part == 1 && zero_hi;
    const double len = e - a;
    for (int i = 0; i < PSI_NODES; i++) {
      const double t = 0.5 * (k->gl_x[i] + 1.0), wt = 0.5 * k->gl_w[i];
      double psi, jac;
      if (spread_a)
        psi = a + len * t * t, jac = 2.0 * len * t;
      else if (spread_e)
        psi = e - len * t * t, jac = 2.0 * len * t;
      else
        psi = a + len * t, jac = len;
      const double v = R * cos(psi - delta);
      if (v > 0.0)
        sum += wt * jac * pow(v, k->power) * pow(cos(psi), power_of_cos);
    }
  }
  return sum;
}

/* Adaptive Gauss-Kronrod (7, 15) of across(...) times max(0, cos(phi -
 * phi_n)) when with_normal (k = 2), else of across(...) alone (k = 1), over
 * phi in [a, b]. */
static const double gk_x[8] = {0.991455371120812639, 0.949107912342758525,
                               0.864864423359769073, 0.741531185599394440,
                               0.586087235467691130, 0.405845151377397167,
                               0.207784955007898468, 0.0};
static const double gk_wk[8] = {0.022935322010529225, 0.063092092629978553,
                                0.104790010322250184, 0.140653259715525919,
                                0.169004726639267903, 0.190350578064785410,
                                0.204432940075298892, 0.209482141084727828};
static const double gk_wg[4] = {0.129484966168869693, 0.279705391489276668,
                                0.381830050505118945, 0.417959183673469388};

typedef struct lune {
  const sky *k;
  const double *b;
  int with_normal;
  double phi_n;
} lune;

static double lune_at(const lune *l, double phi) {
  const double v = across(l->k, l->b, phi, l->with_normal ? 2 : 1);
  return l->with_normal ? v * fmax(0.0, cos(phi - l->phi_n)) : v;
}

static double gk15(const lune *l, double a, double b, double *error) {
  const double c = 0.5 * (a + b), h = 0.5 * (b - a);
  double fc = lune_at(l, c), kron = gk_wk[7] * fc, gauss = gk_wg[3] * fc;
  for (int i = 0; i < 7; i++) {
    const double f = lune_at(l, c - h * gk_x[i]) + lune_at(l, c + h * gk_x[i]);
    kron += gk_wk[i] * f;
    if (i % 2 == 1)
      gauss += gk_wg[i / 2] * f;
  }
  *error = fabs((kron - gauss) * h);
  return kron * h;
}

static double adaptive(const lune *l, double a, double b, double tolerance, int depth) {
  double error;
  const double whole = gk15(l, a, b, &error);
  if (error <= tolerance || depth > 30)
    return whole;
  const double m = 0.5 * (a + b);
  return adaptive(l, a, m, 0.5 * tolerance, depth + 1) +
         adaptive(l, m, b, 0.5 * tolerance, depth + 1);
}

/* The integral over phi in [a, b] of the lune, split where the lobe's
 * horizontal part A changes sign (the integrand's kinks). */
static double lune_integral(const sky *k, const double *b, int with_normal, double phi_n,
                            double a, double bb) {
  if (!(bb > a))
    return 0.0;
  const lune l = {k, b, with_normal, phi_n};
  double cuts[8];
  int n = 0;
  cuts[n++] = a;
  const double zero = atan2(-b[0], b[2]); /* A = 0 there and a half turn on */
  for (int m = -2; m <= 2; m++) {
    const double z = zero + m * BB__PI;
    if (z > a && z < bb)
      cuts[n++] = z;
  }
  cuts[n++] = bb;
  for (int i = 1; i < n; i++) /* sorted: a < the zeros (rising) < bb */
    for (int j = i; j > 0 && cuts[j] < cuts[j - 1]; j--) {
      const double t = cuts[j];
      cuts[j] = cuts[j - 1], cuts[j - 1] = t;
    }
  double sum = 0.0;
  for (int i = 0; i + 1 < n; i++)
    sum += adaptive(&l, cuts[i], cuts[i + 1], 1e-13, 0);
  return sum;
}

static void sky_init(sky *k, const args *a) {
  memset(k, 0, sizeof *k);
  k->lobes = a->basis.count;
  k->power = a->power;
  bb__gauss_legendre(PSI_NODES, k->gl_x, k->gl_w);
  for (int c = 0; c < k->lobes; c++) {
    memcpy(k->basis[c], a->basis.vector[c], sizeof k->basis[c]);
    k->total[c] = lune_integral(k, k->basis[c], 0, 0.0, 0.0, BB__PI);
  }
}

/* ------------------------------------------------------------- strips */

typedef struct point2 {
  double x, z;
} point2;

typedef struct model {
  int width; /* texels */
  double *z; /* the profile, per column */
  point2 *e; /* strip ends, by rising x */
  int ends, strips;
  double *length;     /* per strip */
  double *F;          /* strips x strips */
  double *sky;        /* per strip and channel: S_ik */
  double *J;          /* per strip and channel: the radiance */
  double closure_gap; /* largest |ao's sky by quadrature - 1 + sum F| */
} model;

static int add_end(model *m, int *cap, double x, double z) {
  if (m->ends == *cap) {
    *cap = *cap ? 2 * *cap : 1024;
    point2 *e = realloc(m->e, (size_t)*cap * sizeof *e);
    if (!e)
      return 1;
    m->e = e;
  }
  m->e[m->ends++] = (point2){x, z};
  return 0;
}

static int build_ends(model *m, double strip) {
  int cap = 0;
  const double z0 = m->z[0], z1 = m->z[m->width - 1];
  /* left: from FAR to 0, the strips shrinking towards the image */
  double offsets[512];
  int n = 0;
  for (double len = strip, at = 0.0; at < FAR && n < 512; len *= GROWTH)
    offsets[n++] = at += len;
  for (int i = n - 1; i >= 0; i--)
    if (add_end(m, &cap, -offsets[i], z0))
      return 1;
  for (int x = 0; x + 1 < m->width; x++) {
    const double dz = m->z[x + 1] - m->z[x];
    const int pieces = (int)ceil(hypot(1.0, dz) / strip);
    for (int k = 0; k < pieces; k++)
      if (add_end(m, &cap, x + (double)k / pieces, m->z[x] + dz * k / pieces))
        return 1;
  }
  if (add_end(m, &cap, m->width - 1, z1))
    return 1;
  for (int i = 0; i < n; i++)
    if (add_end(m, &cap, m->width - 1 + offsets[i], z1))
      return 1;
  m->strips = m->ends - 1;
  return 0;
}

/* The taut string's length from end p to every end (over the profile:
 * the upper convex hull of the ends between them, built end by end away
 * from p); stack and sum are scratch of m->ends each. */
static void taut_row(const model *m, int p, double *out, int *stack, double *sum) {
  out[p] = 0.0;
  for (int dir = -1; dir <= 1; dir += 2) {
    int size = 0;
    stack[size] = p, sum[size++] = 0.0;
    for (int q = p + dir; q >= 0 && q < m->ends; q += dir) {
      const point2 Q = m->e[q];
      while (size >= 2) {
        const point2 A = m->e[stack[size - 2]], B = m->e[stack[size - 1]];
        /* B on or under the line from A to Q (x mirrored going left) */
        const double cross =
            ((B.x - A.x) * (Q.z - A.z) - (B.z - A.z) * (Q.x - A.x)) * dir;
        if (cross < 0.0)
          break;
        size--;
      }
      const point2 T = m->e[stack[size - 1]];
      sum[size] = sum[size - 1] + hypot(Q.x - T.x, Q.z - T.z);
      stack[size] = q;
      out[q] = sum[size++];
    }
  }
}

static int view_factors(model *m) {
  const int n = m->strips, ends = m->ends;
  double *row_a = malloc((size_t)ends * sizeof(double)),
         *row_b = malloc((size_t)ends * sizeof(double));
  double *sum = malloc((size_t)ends * sizeof(double));
  int *stack = malloc((size_t)ends * sizeof(int));
  m->F = malloc((size_t)n * (size_t)n * sizeof(double));
  m->length = malloc((size_t)n * sizeof(double));
  if (!row_a || !row_b || !sum || !stack || !m->F || !m->length) {
    free(row_a), free(row_b), free(sum), free(stack);
    return 1;
  }
  for (int i = 0; i < n; i++)
    m->length[i] = hypot(m->e[i + 1].x - m->e[i].x, m->e[i + 1].z - m->e[i].z);
  int bad = 0;
  taut_row(m, 0, row_b, stack, sum);
  for (int i = 0; i < n; i++) {
    double *t = row_a;
    row_a = row_b, row_b = t; /* row_a: from a_i = e_i, row_b: from b_i = e_{i+1} */
    taut_row(m, i + 1, row_b, stack, sum);
    double *F = m->F + (size_t)i * (size_t)n;
    for (int j = 0; j < n; j++) {
      double f = 0.0;
      if (j != i) {
        f = (row_a[j] + row_b[j + 1] - row_a[j + 1] - row_b[j]) / (2.0 * m->length[i]);
        /* roundoff grows with the strings' lengths (1e6 out on the extensions) */
        if (f < -1e-12 - 1e-14 * (row_a[j] + row_b[j + 1]) / m->length[i])
          bad = 1;
        f = fmax(f, 0.0);
      }
      F[j] = f;
    }
  }
  free(row_a), free(row_b), free(sum), free(stack);
  if (bad)
    fprintf(stderr, "radiosity2d: a negative view factor (a bug)\n");
  return bad;
}

/* The open directions from a point of the profile: angles (from +x, in the
 * profile's plane) above the right horizon and below pi minus the left
 * one. lift raises the point; floor0 keeps them at or above 0. */
static void horizons(const model *m, point2 p, double *right, double *left) {
  double r = -0.5 * BB__PI, l = -0.5 * BB__PI;
  for (int q = 0; q < m->ends; q++) {
    const double dx = m->e[q].x - p.x, dz = m->e[q].z - p.z;
    if (dx > 1e-12)
      r = fmax(r, atan2(dz, dx));
    else if (dx < -1e-12)
      l = fmax(l, atan2(dz, -dx));
  }
  *right = r, *left = l;
}

static int sky_light(model *m, const sky *k) {
  const int n = m->strips, channels = 1 + k->lobes;
  m->sky = calloc((size_t)n * (size_t)channels, sizeof(double));
  if (!m->sky)
    return 1;
  double gx[STRIP_POINTS], gw[STRIP_POINTS];
  bb__gauss_legendre(STRIP_POINTS, gx, gw);
  m->closure_gap = 0.0;
  for (int i = 0; i < n; i++) {
    const point2 a = m->e[i], b = m->e[i + 1];
    const double phi_n = atan2(b.x - a.x, -(b.z - a.z)); /* the up normal (-dz, dx) */
    double seen = 0.0, quad_ao = 0.0;
    for (int j = 0; j < n; j++)
      seen += m->F[(size_t)i * (size_t)n + (size_t)j];
    double *S = m->sky + (size_t)i * (size_t)channels;
    S[0] = fmax(0.0, 1.0 - seen);
    for (int g = 0; g < STRIP_POINTS; g++) {
      const double t = 0.5 * (gx[g] + 1.0), wt = 0.5 * gw[g];
      const point2 p = {a.x + t * (b.x - a.x), a.z + t * (b.z - a.z)};
      double right, left;
      horizons(m, p, &right, &left);
      const double lo = fmax(right, phi_n - 0.5 * BB__PI),
                   hi = fmin(BB__PI - left, phi_n + 0.5 * BB__PI);
      if (!(hi > lo))
        continue;
      quad_ao += wt * 0.5 * (sin(hi - phi_n) - sin(lo - phi_n));
      for (int c = 0; c < k->lobes; c++)
        S[1 + c] += wt * lune_integral(k, k->basis[c], 1, phi_n, lo, hi) / BB__PI;
    }
    m->closure_gap = fmax(m->closure_gap, fabs(quad_ao - S[0]));
  }
  return 0;
}

/* J from the linear system (I - rho F) J = rho S, every channel at once
 * (Gaussian elimination: the matrix is diagonally dominant, rho F's rows
 * summing to at most rho), or bounces iterations from J = 0. */
static int solve_light(model *m, int channels, double rho, int bounces) {
  const int n = m->strips;
  m->J = calloc((size_t)n * (size_t)channels, sizeof(double));
  if (!m->J)
    return 1;
  if (bounces > 0) {
    double *next = malloc((size_t)n * (size_t)channels * sizeof(double));
    if (!next)
      return 1;
    for (int it = 0; it < bounces; it++) {
      for (int i = 0; i < n; i++)
        for (int c = 0; c < channels; c++) {
          double e = m->sky[(size_t)i * (size_t)channels + (size_t)c];
          const double *F = m->F + (size_t)i * (size_t)n;
          for (int j = 0; j < n; j++)
            e += F[j] * m->J[(size_t)j * (size_t)channels + (size_t)c];
          next[(size_t)i * (size_t)channels + (size_t)c] = rho * e;
        }
      memcpy(m->J, next, (size_t)n * (size_t)channels * sizeof(double));
    }
    free(next);
    return 0;
  }
  double *A = malloc((size_t)n * (size_t)n * sizeof(double));
  if (!A)
    return 1;
  for (int i = 0; i < n; i++) {
    for (int j = 0; j < n; j++)
      A[(size_t)i * (size_t)n + (size_t)j] =
          (i == j) - rho * m->F[(size_t)i * (size_t)n + (size_t)j];
    for (int c = 0; c < channels; c++)
      m->J[(size_t)i * (size_t)channels + (size_t)c] =
          rho * m->sky[(size_t)i * (size_t)channels + (size_t)c];
  }
  for (int p = 0; p < n; p++) {
    const double *rp = A + (size_t)p * (size_t)n;
    for (int i = p + 1; i < n; i++) {
      double *ri = A + (size_t)i * (size_t)n;
      const double f = ri[p] / rp[p];
      if (f == 0.0)
        continue;
      for (int j = p; j < n; j++)
        ri[j] -= f * rp[j];
      for (int c = 0; c < channels; c++)
        m->J[(size_t)i * (size_t)channels + (size_t)c] -=
            f * m->J[(size_t)p * (size_t)channels + (size_t)c];
    }
  }
  for (int i = n - 1; i >= 0; i--) {
    const double *ri = A + (size_t)i * (size_t)n;
    for (int c = 0; c < channels; c++) {
      double v = m->J[(size_t)i * (size_t)channels + (size_t)c];
      for (int j = i + 1; j < n; j++)
        v -= ri[j] * m->J[(size_t)j * (size_t)channels + (size_t)c];
      m->J[(size_t)i * (size_t)channels + (size_t)c] = v / ri[i];
    }
  }
  free(A);
  return 0;
}

/* --------------------------------------------------------- the texels */

typedef struct texel_light {
  double direct[MAX_CHANNELS]; /* ao, vis_c without the bounce */
  double added[MAX_CHANNELS];  /* what the bounce adds */
} texel_light;

/* What column x's origin receives: each way, the strips' pieces no nearer
 * one hides, above its horizontal. */
static void texel_at(const model *m, const sky *k, int x, double bias, texel_light *out) {
  const int channels = 1 + k->lobes;
  memset(out, 0, sizeof *out);
  const point2 o = {x, m->z[x] + bias};
  double horizon[2];
  for (int side = 0; side < 2; side++) {
    const int dir = side ? -1 : 1;
    /* the ends are sorted by x and x is one of them: the first strip out */
    int first = 0;
    while (first < m->ends && m->e[first].x < x - 1e-9)
      first++;
    double seen = 0.0; /* the steepest angle so far, from the horizontal */
    for (int i = dir > 0 ? first : first - 1; i >= 0 && i < m->strips; i += dir) {
      const point2 near = m->e[dir > 0 ? i : i + 1], far = m->e[dir > 0 ? i + 1 : i];
      const double a0 = atan2(near.z - o.z, fabs(near.x - o.x)),
                   a1 = atan2(far.z - o.z, fabs(far.x - o.x));
      const double from = fmax(a0, seen);
      if (a1 > from) {
        const double *J = m->J + (size_t)i * (size_t)channels;
        out->added[0] += J[0] * 0.5 * (cos(from) - cos(a1));
        for (int c = 0; c < k->lobes; c++)
          out->added[1 + c] += J[1 + c] * 2.0 * (a1 - from);
        seen = a1;
      }
    }
    horizon[side] = seen;
  }
  /* the added vis_c: solid angle per channel over T_c */
  for (int c = 0; c < k->lobes; c++)
    out->added[1 + c] /= k->total[c];
  out->direct[0] = 0.5 * (cos(horizon[0]) + cos(horizon[1]));
  for (int c = 0; c < k->lobes; c++)
    out->direct[1 + c] =
        lune_integral(k, k->basis[c], 0, 0.0, horizon[0], BB__PI - horizon[1]) /
        k->total[c];
}

/* ------------------------------------------------------------- commands */

static int parse_options(int argc, char **argv, int first, args *a, const char **base,
                         int *results_at) {
  a->rho = 0.5, a->bias = 0.55, a->power = 1.0, a->strip = 0.1;
  a->filter = BB_NORMAL_VERTEX;
  bb__basis_init(&a->basis);
  if (results_at)
    *results_at = argc;
  for (int i = first; i < argc; i++) {
    const char *o = argv[i];
    if (!strcmp(o, "--texels")) {
      a->texels = 1;
      continue;
    }
    if (results_at && strchr(o, '=') && o[0] != '-') {
      *results_at = i;
      return 0;
    }
    if (i + 1 >= argc)
      return usage("an option lacks its value");
    const char *v = argv[++i];
    double x;
    bb_error err;
    if (!strcmp(o, "--basis")) {
      if (bb__basis_parse(v, &a->basis, &err) != BB_OK)
        return usage(err.message);
    } else if (!strcmp(o, "--normal-filter")) {
      if (bb__normal_filter_parse(v, &a->filter, &err) != BB_OK)
        return usage(err.message);
    } else if (!strcmp(o, "--base") && base) {
      *base = v;
    } else if (parse_number(v, 0.0, 1e6, &x)) {
      return usage("bad option value");
    } else if (!strcmp(o, "--rho") && x <= 1.0)
      a->rho = x;
    else if (!strcmp(o, "--bias"))
      a->bias = x;
    else if (!strcmp(o, "--bounces") && x == floor(x))
      a->bounces = (int)x;
    else if (!strcmp(o, "--power") && x >= 1.0)
      a->power = x;
    else if (!strcmp(o, "--strip") && x >= 0.005 && x <= 1.0)
      a->strip = x;
    else
      return usage("unknown option or value out of range");
  }
  return 0;
}

/* Reads MAP, checks it is a profile, and solves its light. */
static int model_make(const args *a, const sky *k, bb_image *h, model *m) {
  bb_error err;
  memset(m, 0, sizeof *m);
  if (bb__height_file_read(a->map, BB_CHANNEL_AUTO, 0.0f, NULL, NULL, h, NULL, &err) !=
      BB_OK) {
    fprintf(stderr, "radiosity2d: %s\n", err.message);
    return 1;
  }
  for (int y = 1; y < h->height; y++)
    if (memcmp(bb_image_texel(h, 0, y), h->pixels, (size_t)h->width * sizeof(float))) {
      fprintf(
          stderr,
          "radiosity2d: %s: row %d differs from row 0 (not a profile extruded along y)\n",
          a->map, y);
      return 1;
    }
  if (h->width < 2) {
    fprintf(stderr, "radiosity2d: %s: a profile needs 2 columns or more\n", a->map);
    return 1;
  }
  m->width = h->width;
  m->z = malloc((size_t)h->width * sizeof(double));
  if (!m->z)
    return 1;
  const float s = (float)a->scale; /* float times float, as the bake scales */
  for (int x = 0; x < h->width; x++)
    m->z[x] = (double)(s * h->pixels[x]);
  if (build_ends(m, a->strip) || view_factors(m) || sky_light(m, k) ||
      solve_light(m, 1 + k->lobes, a->rho, a->bounces)) {
    fprintf(stderr, "radiosity2d: %s: out of memory or a bad view factor\n", a->map);
    return 1;
  }
  return 0;
}

static void model_free(model *m) {
  free(m->z), free(m->e), free(m->length), free(m->F), free(m->sky), free(m->J);
}

static int run_solve(int argc, char **argv) {
  if (argc < 4)
    return usage("solve needs MAP and SCALE");
  args a;
  memset(&a, 0, sizeof a);
  a.map = argv[2];
  if (parse_number(argv[3], 1e-9, 1e9, &a.scale))
    return usage("SCALE must be > 0");
  int rc = parse_options(argc, argv, 4, &a, NULL, NULL);
  if (rc)
    return rc;
  sky k;
  sky_init(&k, &a);
  bb_image h = {0};
  model m;
  const double t0 = bb__now_seconds();
  rc = model_make(&a, &k, &h, &m);
  const int channels = 1 + k.lobes;
  for (int x = 0; !rc && x < m.width; x++) {
    texel_light t;
    texel_at(&m, &k, x, a.bias, &t);
    printf("{\"x\":%d,\"direct\":[", x);
    for (int c = 0; c < channels; c++)
      printf("%s%.9f", c ? "," : "", t.direct[c]);
    printf("],\"added\":[");
    for (int c = 0; c < channels; c++)
      printf("%s%.9f", c ? "," : "", t.added[c]);
    printf("]}\n");
  }
  for (int i = 0; !rc && a.texels && i < m.strips; i++)
    if (m.e[i].x >= 0.0 && m.e[i + 1].x <= m.width - 1)
      printf("{\"strip\":%d,\"x\":%.4f,\"z\":%.4f,\"J\":%.6f}\n", i,
             0.5 * (m.e[i].x + m.e[i + 1].x), 0.5 * (m.e[i].z + m.e[i + 1].z),
             m.J[(size_t)i * (size_t)channels]);
  if (!rc)
    printf("{\"map\":\"%s\",\"strips\":%d,\"closure_gap\":%.3g,\"seconds\":%.2f}\n",
           a.map, m.strips, m.closure_gap, bb__now_seconds() - t0);
  model_free(&m);
  bb_image_free(&h);
  return rc;
}

/* Reads AO.exr,SS.exr into ao and ss (MAP's size). */
static int read_pair(const char *pair, const bb_image *h, int lobes, bb_image *ao,
                     bb_image *ss) {
  char text[2048];
  snprintf(text, sizeof text, "%s", pair);
  char *comma = strchr(text, ',');
  if (!comma) {
    usage("a result is AO.exr,SS.exr");
    return 2;
  }
  *comma = '\0';
  bb_error err;
  if (bb_image_read(text, ao, NULL, &err) != BB_OK ||
      bb_image_read(comma + 1, ss, NULL, &err) != BB_OK) {
    fprintf(stderr, "radiosity2d: %s\n", err.message);
    return 1;
  }
  if (ao->width != h->width || ao->height != h->height || ss->width != h->width ||
      ss->height != h->height || ss->channels < lobes) {
    fprintf(stderr, "radiosity2d: %s does not match the map\n", pair);
    return 1;
  }
  return 0;
}

static int run_compare(int argc, char **argv) {
  if (argc < 4)
    return usage("compare needs MAP and SCALE");
  args a;
  memset(&a, 0, sizeof a);
  a.map = argv[2];
  if (parse_number(argv[3], 1e-9, 1e9, &a.scale))
    return usage("SCALE must be > 0");
  const char *base = NULL;
  int results_at;
  int rc = parse_options(argc, argv, 4, &a, &base, &results_at);
  if (rc)
    return rc;
  if (!base || results_at >= argc)
    return usage("compare needs --base and a result");
  sky k;
  sky_init(&k, &a);
  const int channels = 1 + k.lobes;
  bb_image h = {0}, normal = {0}, base_ao = {0}, base_ss = {0};
  model m;
  rc = model_make(&a, &k, &h, &m);
  bb_error err;
  if (!rc && bb__normals_compute_all_cores(&h, (float)a.scale, a.filter, BB_ADDRESS_CLAMP, &normal,
                                &err) != BB_OK) {
    fprintf(stderr, "radiosity2d: %s\n", err.message);
    rc = 1;
  }
  if (!rc)
    rc = read_pair(base, &h, k.lobes, &base_ao, &base_ss);
  texel_light *exact = rc ? NULL : malloc((size_t)m.width * sizeof *exact);
  if (!rc && !exact)
    rc = 1;
  for (int x = 0; !rc && x < m.width; x++)
    texel_at(&m, &k, x, a.bias, &exact[x]);
  if (!rc)
    printf("{\"map\":\"%s\",\"rho\":%g,\"strips\":%d,\"closure_gap\":%.3g,\"results\":[",
           a.map, a.rho, m.strips, m.closure_gap);
  for (int r = results_at; !rc && r < argc; r++) {
    char *eq = strchr(argv[r], '=');
    bb_image ao = {0}, ss = {0};
    rc = read_pair(eq + 1, &h, k.lobes, &ao, &ss);
    if (rc)
      break;
    double worst[MAX_CHANNELS] = {0}, sum_abs[MAX_CHANNELS] = {0},
           sum[MAX_CHANNELS] = {0};
    double direct_worst = 0.0;
    int worst_x[MAX_CHANNELS] = {0}, capped = 0;
    long count[MAX_CHANNELS] = {0};
    for (int y = 0; y < h.height; y++)
      for (int x = 0; x < h.width; x++) {
        const float *n = bb_image_texel(&normal, x, y);
        for (int c = 0; c < channels; c++) {
          double got, want;
          if (c == 0) {
            got = (double)bb_image_texel(&ao, x, y)[0] -
                  (double)bb_image_texel(&base_ao, x, y)[0];
            want = exact[x].added[0];
            direct_worst =
                fmax(direct_worst, fabs((double)bb_image_texel(&base_ao, x, y)[0] -
                                        exact[x].direct[0]));
          } else {
            const double *b = k.basis[c - 1];
            const double nb = fmax(0.0, n[0] * b[0] + n[1] * b[1] + n[2] * b[2]);
            const float s1 = bb_image_texel(&ss, x, y)[c - 1];
            if (s1 >= 1.0f) {
              capped++;
              continue;
            }
            got = (double)s1 - (double)bb_image_texel(&base_ss, x, y)[c - 1];
            want = nb * exact[x].added[c];
          }
          const double e = got - want;
          if (fabs(e) > worst[c])
            worst[c] = fabs(e), worst_x[c] = x;
          sum_abs[c] += fabs(e), sum[c] += e, count[c]++;
        }
      }
    *eq = '\0';
    printf("%s{\"name\":\"%s\",\"capped\":%d,\"direct_ao_worst\":%.6f,\"channels\":[",
           r > results_at ? "," : "", argv[r], capped, direct_worst);
    fprintf(
        stderr,
        "radiosity2d: %s, %s (rho %g): largest |added - exact| (at x) / mean / bias:\n",
        a.map, argv[r], a.rho);
    for (int c = 0; c < channels; c++) {
      const double mean_abs = count[c] ? sum_abs[c] / (double)count[c] : 0.0;
      const double bias = count[c] ? sum[c] / (double)count[c] : 0.0;
      const double want = c ? 0.0 : exact[worst_x[c]].added[0];
      printf("%s{\"worst\":%.6f,\"worst_x\":%d,\"mean_abs\":%.6f,\"bias\":%.6f,\"exact_"
             "there\":%.6f}",
             c ? "," : "", worst[c], worst_x[c], mean_abs, bias, want);
      char name[16];
      if (c)
        snprintf(name, sizeof name, "ss%d", c - 1);
      else
        snprintf(name, sizeof name, "ao");
      fprintf(stderr, "  %-4s %.5f (x %d) / %.5f / %+.5f\n", name, worst[c], worst_x[c],
              mean_abs, bias);
    }
    printf("]}");
    if (a.texels) {
      const int y = h.height / 2;
      fprintf(stderr,
              "  x: exact added ao, bake added ao, error; exact direct ao, bake's; "
              "exact added ss0, error\n");
      for (int x = 0; x < m.width; x++) {
        const double got = (double)bb_image_texel(&ao, x, y)[0] -
                           (double)bb_image_texel(&base_ao, x, y)[0];
        const float *nn = bb_image_texel(&normal, x, y);
        const double *b0 = k.basis[0];
        const double nb = fmax(0.0, nn[0] * b0[0] + nn[1] * b0[1] + nn[2] * b0[2]);
        const double ss_got = (double)bb_image_texel(&ss, x, y)[0] -
                              (double)bb_image_texel(&base_ss, x, y)[0];
        fprintf(stderr, "  %3d: %.5f %.5f %+.5f; %.5f %.5f; %.5f %+.5f\n", x,
                exact[x].added[0], got, got - exact[x].added[0], exact[x].direct[0],
                (double)bb_image_texel(&base_ao, x, y)[0], nb * exact[x].added[1],
                ss_got - nb * exact[x].added[1]);
      }
    }
    bb_image_free(&ao);
    bb_image_free(&ss);
  }
  if (!rc)
    printf("]}\n");
  free(exact);
  model_free(&m);
  bb_image_free(&h);
  bb_image_free(&normal);
  bb_image_free(&base_ao);
  bb_image_free(&base_ss);
  return rc;
}

int main(int argc, char **argv) {
  if (argc >= 2 && !strcmp(argv[1], "profile")) {
    if (argc != 4)
      return usage("profile needs NAME and OUT");
    return write_profile(argv[2], argv[3]);
  }
  if (argc >= 2 && !strcmp(argv[1], "solve"))
    return run_solve(argc, argv);
  if (argc >= 2 && !strcmp(argv[1], "compare"))
    return run_compare(argc, argv);
  return usage("the first argument is profile, solve or compare");
}
