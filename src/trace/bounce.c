/* bounce.c: inter-reflection: the light the surrounding height field
 * reflects into each texel's ao and lobes, worked out from the horizons the
 * line sweeps find.
 *
 * The model (docs/conventions.md "Inter-reflection"). Every triangle is
 * Lambertian with albedo rho; the sky of channel k (ao: radiance 1; lobe c:
 * max(0, w.B_c)^P) lights it directly, and the rest of the surface lights
 * it again. A texel's blocked directions no longer bring nothing: each
 * brings the radiance of the surface it meets.
 *
 * What a triangle reflects is kept at its corners: for vertex v and each of
 * its 6 triangles f ("slots", below), R = rho(v) / pi E_k(v, n_f), the
 * irradiance of channel k on f's own plane near v. Over a triangle the
 * radiance is the linear blend of its three corners: a wall one cell wide
 * gets its own light at its top and at its foot, which a vertex normal
 * (half wall, half floor or plateau) would not give. The vertex itself is
 * a poor place to sample a triangle's light, since in every valley its
 * neighbours shadow it as no point inside the triangle is: the corners are
 * sampled `lift` (a quarter texel) above it, which took the bias of the
 * bounced light on the test maps from -0.001 to under 0.0003 (README
 * "Accuracy").
 *
 * E_k(v, n_f) is integrated per slice like the bake's visibility: the
 * sector above max(horizon, f's plane along the slice, 0) gives n_f .
 * integral of sky_k(w) w dw over it, from tables of the three components
 * (built here, like integrate.c's, in q = t / (1 + t)). The bounces after
 * the first add what the surface below the horizons reflects, gathered the
 * same way over every direction above f's plane (the surface below the
 * horizontal too: a wall's foot sees the floor there).
 *
 * The gather. Along a slice's line the surface is a profile of breakpoints
 * (the sweeps' template, every point of it: between two neighbours the
 * profile lies in one triangle). Walking from the origin towards the
 * horizon's own point, the profile is seen where its slope from the origin
 * rises above every nearer point's: each such piece of a segment is a band
 * of elevations in which the rays meet that segment, at a point found from
 * the band's slope, with the radiance blended there. The last band ends at
 * the horizon. Every breakpoint counts within exact_steps lattice steps;
 * further on only the texels (the surface between two taken as straight),
 * stretches wholly under the rays passed at once through a max pyramid
 * over the steps; past far_steps the band left meets the horizon's own
 * point (at 0 and 0 steps that is the whole blocked band: the
 * horizon-point approximation, measured in README "Accuracy"). A band's
 * weight is exact (ao: w.z; lobes: solid angle; a corner: n_f . w above its
 * plane), its radiance the mean of its ends, or of finer pieces when it
 * spans more than 0.1 radians over which the radiance changes.
 *
 * Passes (each a sweep of every slice, in the trace's order, so every sum
 * is made in a fixed order and the result is the same on any thread
 * count): the direct light of every corner; then, for each further bounce,
 * the light its corners gather from the surface, over half the slices (the
 * light of later bounces is smooth); last, what each texel's origin
 * (lifted by the bake's bias) gathers, added to its visibility. With
 * bounces N that is N - 1 surface passes from the first bounce. With
 * bounces 0 (converged) the corners start from an estimate of all their
 * light (estimate_ratio), one surface pass gathers from it, and the rest
 * of the series, close to geometric, is added as the last move times
 * lambda / (1 - lambda), lambda the ratio of the last two moves summed
 * over every corner. Progress counts every pass's slices, weighted by
 * what they cost (slice_work).
 */
#include "core/internal.h"
#include "trace/bounce.h"
#include "trace/integrate.h"
#include "trace/march.h"
#include "trace/pyramid.h"
#include "trace/rayset.h"
#include "trace/sweep.h"

#include <math.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

enum { FACES = 6, MAX_CHANNELS = 1 + BB_MAX_BASIS };
#define WIDE_BAND 0.1 /* radians: a band wider than this is cut into pieces */
#define STEEPEST 1e15 /* a slope standing for straight down */

typedef enum pass_mode {
  PASS_DIRECT,  /* corners: what the sky's open sectors give */
  PASS_SURFACE, /* corners: what the surface below the horizons reflects */
  PASS_TEXEL    /* texels' origins: what the surface reflects to them */
} pass_mode;

/* ---------------------------------------------------------------- faces */

/* The 6 triangles around vertex (x, y): the cell (x + dx, y + dy) and its
 * half (0: (0,0)-(1,0)-(0,1); 1: (1,0)-(1,1)-(0,1)); the vertex is corner
 * `corner` of it. A triangle's corners, in that order, are those of its
 * half. */
static const int slot_dx[FACES] = {0, -1, -1, 0, 0, -1};
static const int slot_dy[FACES] = {0, 0, 0, -1, -1, -1};
static const int slot_upper[FACES] = {0, 0, 1, 0, 1, 1};
/* Which corner of its triangle the vertex is, for each slot: the corners
 * of half 0 are (0,0), (1,0), (0,1); of half 1, (1,0), (1,1), (0,1). */
static const int slot_corner[FACES] = {0, 1, 0, 2, 2, 1};

/* v modulo n, in [0, n): without a division when v is within one period
 * of it (the neighbours and lattice steps of the image's own texels). */
static inline long wrap(long v, long n) {
  if (v >= 0 && v < n) return v;
  if (v >= n && v < 2 * n) return v - n;
  if (v < 0 && v >= -n) return v + n;
  const long r = v % n;
  return r < 0 ? r + n : r;
}

/* What the corners reflect is kept cell by cell, so the three corners of a
 * triangle lie together: ((cell * 2 + half) * 3 + corner) * channels.
 * The index of vertex (x, y)'s slot f, or SIZE_MAX where the cell lies
 * outside a clamped image (corner_fixup fills its border cells). */
static inline size_t corner_index(const bb_pyramid *p, long x, long y, int f, int channels) {
  long cx = x + slot_dx[f], cy = y + slot_dy[f];
  if (p->addressing == BB_ADDRESS_PERIODIC) {
    if (cx < 0) cx += p->width;
    if (cy < 0) cy += p->height;
  } else if (cx < 0 || cy < 0) {
    return SIZE_MAX;
  }
  const size_t cell = (size_t)cy * (size_t)p->width + (size_t)cx;
  return ((cell * 2 + (size_t)slot_upper[f]) * 3 + (size_t)slot_corner[f]) * (size_t)channels;
}

/* The three corners of half `upper` of cell (cx, cy) (any coordinates:
 * periodic ones wrap, clamped ones are held to the image's cells). */
static inline const float *triangle_corners(const bb_pyramid *p, const float *radiance, long cx,
                                            long cy, int upper, int channels) {
  long x = cx, y = cy;
  if (p->addressing == BB_ADDRESS_PERIODIC) {
    x = wrap(x, p->width), y = wrap(y, p->height);
  } else {
    x = x < 0 ? 0 : (x >= p->width ? p->width - 1 : x);
    y = y < 0 ? 0 : (y >= p->height ? p->height - 1 : y);
  }
  const size_t cell = (size_t)y * (size_t)p->width + (size_t)x;
  return radiance + (cell * 2 + (size_t)upper) * 3 * (size_t)channels;
}

static inline size_t vertex_at(const bb_pyramid *p, long x, long y) {
  if (p->addressing == BB_ADDRESS_PERIODIC)
    return (size_t)wrap(y, p->height) * (size_t)p->width + (size_t)wrap(x, p->width);
  const long cx = x < 0 ? 0 : (x >= p->width ? p->width - 1 : x);
  const long cy = y < 0 ? 0 : (y >= p->height ? p->height - 1 : y);
  return (size_t)cy * (size_t)p->width + (size_t)cx;
}

static inline double height_at(const bb_pyramid *p, long x, long y) {
  return (double)p->z[vertex_at(p, x, y)];
}

/* The normals of the 6 triangles around vertex (x, y): face_normal's
 * arithmetic, each of the 7 heights around it read once. */
static void vertex_faces(const bb_pyramid *p, long x, long y, double n[FACES][3]) {
  double z[3][3]; /* z[1 + dy][1 + dx]; (-1, -1) and (+1, +1) are no triangle's corner */
  for (int j = -1; j <= 1; j++)
    for (int i = -1; i <= 1; i++)
      if (i != j || i == 0) z[1 + j][1 + i] = height_at(p, x + i, y + j);
  for (int f = 0; f < FACES; f++) {
    const int cx = 1 + slot_dx[f], cy = 1 + slot_dy[f]; /* the cell's (0, 0) in z */
    if (slot_upper[f])
      n[f][0] = z[cy + 1][cx] - z[cy + 1][cx + 1], n[f][1] = z[cy][cx + 1] - z[cy + 1][cx + 1];
    else
      n[f][0] = z[cy][cx] - z[cy][cx + 1], n[f][1] = z[cy][cx] - z[cy + 1][cx];
    const double len = sqrt(n[f][0] * n[f][0] + n[f][1] * n[f][1] + 1.0);
    n[f][0] /= len, n[f][1] /= len, n[f][2] = 1.0 / len;
  }
}

/* ------------------------------------------------ vector sector tables */

/* For slice s and channel k (0: ao's sky, 1 + c: lobe c), component j of
 *   G(t) = integral over the sector, elevations 0..atan(t), of sky_k(w) w_j cos(el)
 * as cubic Hermite pieces in q = t / (1 + t), and its whole (t = inf). The
 * lobes' rings are Gauss-Legendre sums over the arcs where they are
 * positive (near a zero of the lobe, psi = end + L x^2 spreads the nodes
 * where (psi - end)^P is least smooth); the elevations by 8-point rules
 * per interval. Good to about 1e-7 of the sector's share: bounced light is
 * scaled by rho and by the blocked part of the sky, so this is far under
 * anything a map shows. */
enum { RING_NODES = 24, THETA_NODES = 8 };

typedef struct rules {
  double ring_x[RING_NODES], ring_w[RING_NODES];
  double theta_x[THETA_NODES], theta_w[THETA_NODES];
} rules;

typedef struct lobe_ring {
  const rules *r;
  double rho, beta, bz, power; /* B's horizontal length and azimuth, B_z, P */
  double lo, hi;               /* the sector */
} lobe_ring;

/* Adds to out[0..2] the integral over psi in [a, b] of
 * max(0, A cos psi + C)^P (cos(psi + beta), sin(psi + beta), 1); zero_a,
 * zero_b: the lobe vanishes at that end. */
static void ring_piece(const lobe_ring *l, double A, double C, double a, double b, int zero_a,
                       int zero_b, double out[3]) {
  if (!(b > a)) return;
  if (zero_a && zero_b) {
    const double mid = 0.5 * (a + b);
    ring_piece(l, A, C, a, mid, 1, 0, out);
    ring_piece(l, A, C, mid, b, 0, 1, out);
    return;
  }
  const double length = b - a;
  for (int i = 0; i < RING_NODES; i++) {
    const double x = 0.5 * (l->r->ring_x[i] + 1.0), w = 0.5 * l->r->ring_w[i];
    double psi, jacobian;
    if (zero_a) psi = a + length * x * x, jacobian = 2.0 * length * x;
    else if (zero_b) psi = b - length * x * x, jacobian = 2.0 * length * x;
    else psi = a + length * x, jacobian = length;
    const double v = A * cos(psi) + C;
    if (!(v > 0.0)) continue;
    const double f = (l->power == 1.0 ? v : pow(v, l->power)) * w * jacobian;
    out[0] += f * cos(psi + l->beta);
    out[1] += f * sin(psi + l->beta);
    out[2] += f;
  }
}

/* The ring at elevation theta: integral over the sector of
 * sky(w) (w_x, w_y, w_z) dphi. */
static void lobe_ring_at(const lobe_ring *l, double theta, double out[3]) {
  const double ct = cos(theta), st = sin(theta);
  const double A = l->rho * ct, C = l->bz * st;
  const double lo = l->lo - l->beta, hi = l->hi - l->beta;
  double sum[3] = {0.0, 0.0, 0.0};
  if (!(A > 1e-15 * fabs(C))) { /* the lobe is constant around the ring */
    if (C > 0.0) {
      const double f = l->power == 1.0 ? C : pow(C, l->power);
      sum[0] = f * (sin(l->hi) - sin(l->lo));
      sum[1] = f * (cos(l->lo) - cos(l->hi));
      sum[2] = f * (l->hi - l->lo);
    }
  } else {
    const double kappa = -C / A; /* positive where cos(psi) > kappa */
    if (kappa <= -1.0) {
      ring_piece(l, A, C, lo, hi, 0, 0, sum);
    } else if (kappa < 1.0) {
      const double alpha = acos(kappa), period = 2.0 * BB__PI;
      const int k_first = (int)ceil((lo - alpha) / period);
      const int k_last = (int)floor((hi + alpha) / period);
      for (int k = k_first; k <= k_last; k++) {
        const double start = -alpha + period * k, end = alpha + period * k;
        const double a = lo > start ? lo : start, b = hi < end ? hi : end;
        ring_piece(l, A, C, a, b, a == start, b == end, sum);
      }
    }
  }
  out[0] = ct * sum[0], out[1] = ct * sum[1], out[2] = st * sum[2];
}

/* ao's sky, radiance 1: in closed form. */
static void uniform_ring_at(double lo, double hi, double theta, double out[3]) {
  const double ct = cos(theta);
  out[0] = ct * (sin(hi) - sin(lo));
  out[1] = ct * (cos(lo) - cos(hi));
  out[2] = sin(theta) * (hi - lo);
}

typedef struct vtables {
  int channels;       /* 1 + lobes */
  size_t per_slice;   /* doubles of one slice's table */
  double *coef;       /* per slice: interval k, channel k, component j: 4 coefficients */
  double *total;      /* per slice: 3 per channel */
  double all[3 * MAX_CHANNELS]; /* the totals summed over the slices */
} vtables;

typedef struct table_job {
  const bb_rayset *rs;
  vtables *t;
  const rules *r;
} table_job;

static void ring_of(const table_job *job, int s, int k, double theta, double out[3]) {
  const bb_rayset *rs = job->rs;
  const double lo = rs->sector[2 * s], hi = rs->sector[2 * s + 1];
  if (k == 0) {
    uniform_ring_at(lo, hi, theta, out);
    return;
  }
  const double *b = rs->basis[k - 1];
  lobe_ring l = {job->r, hypot(b[0], b[1]), 0.0, b[2], rs->power, lo, hi};
  l.beta = l.rho > 0.0 ? atan2(b[1], b[0]) : 0.0;
  lobe_ring_at(&l, theta, out);
}

static void build_slice(void *user, int s) {
  table_job *job = user;
  vtables *t = job->t;
  enum { N = BB__TABLE_INTERVALS };
  const int channels = t->channels, width = 3 * channels;
  double *coef = t->coef + (size_t)s * t->per_slice;
  double *total = t->total + (size_t)s * (size_t)width;
  const double h = 1.0 / N;
  for (int k = 0; k < channels; k++) {
    double value[3] = {0.0, 0.0, 0.0}, ring[3];
    double theta = 0.0, slope[3];
    ring_of(job, s, k, 0.0, ring);
    for (int j = 0; j < 3; j++) slope[j] = ring[j]; /* cos 0 = 1, dtheta/dq = 1 at q = 0 */
    for (int i = 0; i < N; i++) {
      const double q1 = (double)(i + 1) * h, theta1 = atan2(q1, 1.0 - q1);
      double step[3] = {0.0, 0.0, 0.0};
      const double mid = 0.5 * (theta + theta1), half = 0.5 * (theta1 - theta);
      for (int n = 0; n < THETA_NODES; n++) {
        const double th = mid + half * job->r->theta_x[n];
        ring_of(job, s, k, th, ring);
        for (int j = 0; j < 3; j++) step[j] += job->r->theta_w[n] * ring[j] * cos(th);
      }
      const double dtheta_dq = 1.0 / ((1.0 - q1) * (1.0 - q1) + q1 * q1);
      ring_of(job, s, k, theta1, ring);
      for (int j = 0; j < 3; j++) {
        const double value1 = value[j] + step[j] * half;
        const double slope1 = ring[j] * cos(theta1) * dtheta_dq;
        const double delta = value1 - value[j], d0 = h * slope[j], d1 = h * slope1;
        double *c = coef + ((size_t)i * (size_t)width + (size_t)(3 * k + j)) * 4;
        c[0] = value[j];
        c[1] = d0;
        c[2] = 3.0 * delta - 2.0 * d0 - d1;
        c[3] = -2.0 * delta + d0 + d1;
        value[j] = value1, slope[j] = slope1;
      }
      theta = theta1;
    }
    for (int j = 0; j < 3; j++) total[3 * k + j] = value[j];
  }
}

static bb_status vtables_build(const bb_rayset *rs, int threads, vtables *t, bb_error *err) {
  memset(t, 0, sizeof *t);
  t->channels = 1 + rs->basis_count;
  t->per_slice = (size_t)BB__TABLE_INTERVALS * 3 * (size_t)t->channels * 4;
  t->coef = malloc((size_t)rs->slice_count * t->per_slice * sizeof(double));
  t->total = malloc((size_t)rs->slice_count * 3 * (size_t)t->channels * sizeof(double));
  if (!t->coef || !t->total) return bb__fail(err, BB_ERR_MEMORY, "bounce: out of memory");
  rules r;
  bb__gauss_legendre(RING_NODES, r.ring_x, r.ring_w);
  bb__gauss_legendre(THETA_NODES, r.theta_x, r.theta_w);
  table_job job = {rs, t, &r};
  bb_status st = bb__parallel_for(rs->slice_count, threads, build_slice, &job, NULL, NULL, err);
  for (int s = 0; s < rs->slice_count; s++) /* in slice order, whatever the threads did */
    for (int i = 0; i < 3 * t->channels; i++) t->all[i] += t->total[(size_t)s * 3 * (size_t)t->channels + (size_t)i];
  return st;
}

static void vtables_free(vtables *t) {
  free(t->coef);
  free(t->total);
}

/* G at tangent t >= 0 for every channel and component (3 per channel). */
static void vtables_eval(const vtables *t, int s, double tan_el, double *g) {
  const int width = 3 * t->channels;
  if (!(tan_el > 0.0)) {
    for (int i = 0; i < width; i++) g[i] = 0.0;
    return;
  }
  if (tan_el > 1e100) tan_el = 1e100;
  const double x = tan_el / (1.0 + tan_el) * BB__TABLE_INTERVALS;
  int k = (int)x;
  if (k > BB__TABLE_INTERVALS - 1) k = BB__TABLE_INTERVALS - 1;
  const double f = x - (double)k;
  const double *coef = t->coef + (size_t)s * t->per_slice + (size_t)k * (size_t)width * 4;
  for (int i = 0; i < width; i++) g[i] = BB__HERMITE(coef, f, i);
}

/* ------------------------------------------------------------ the passes */

typedef struct scratch {
  atomic_flag busy;
  size_t points, steps;
  double *z, *step_max, *mip;
  long *step_x, *step_y;
  float *radiance;
  unsigned char *ready;
} scratch;

typedef struct bounce_ctx {
  const bb_pyramid *p;
  const bb_rayset *rs;
  const vtables *vt;
  pass_mode mode;
  int channels;
  int exact_steps, far_steps;
  float *sums;          /* DIRECT: blocked per corner; SURFACE: gathered per corner
                           (FACES x channels per vertex); TEXEL: channels per texel */
  const float *radiance; /* FACES x channels per vertex: what each corner reflects */
  scratch *slots;
  int slot_count;
  atomic_int out_of_memory;
} bounce_ctx;

static scratch *slot_take(bounce_ctx *ctx) {
  for (;;)
    for (int i = 0; i < ctx->slot_count; i++)
      if (!atomic_flag_test_and_set(&ctx->slots[i].busy)) return &ctx->slots[i];
}

/* The corners' direct light: what slice s's sector above max(horizon,
 * plane of f, 0) gives each corner f of vertex (x, y), as its blocked part,
 * n_f . G, added to sums. */
static void direct_texel(const bounce_ctx *ctx, int s, double dx, double dy,
                         const double n[FACES][3], float horizon, float *sums) {
  const vtables *vt = ctx->vt;
  const int channels = ctx->channels;
  double base[3 * MAX_CHANNELS], own[3 * MAX_CHANNELS];
  const double floor_t = horizon > 0.0f ? (double)horizon : 0.0;
  vtables_eval(vt, s, floor_t, base);
  for (int f = 0; f < FACES; f++) {
    const double plane = -(n[f][0] * dx + n[f][1] * dy) / n[f][2];
    const double *g = base;
    if (plane > floor_t) {
      vtables_eval(vt, s, plane, own);
      g = own;
    }
    float *out = sums + (size_t)f * (size_t)channels;
    for (int k = 0; k < channels; k++)
      out[k] += (float)(n[f][0] * g[3 * k] + n[f][1] * g[3 * k + 1] + n[f][2] * g[3 * k + 2]);
  }
}

/* --- the gather ---------------------------------------------------------- */

/* A segment of the profile seen from an origin: its near end (d0 steps
 * away, z0 above the origin) and far end, and their radiance. */
typedef struct segment {
  double d0, z0, d1, z1;
  const float *near, *far;
} segment;

/* Where, along a segment (0 near .. 1 far), the ray of slope sigma (per
 * step) meets it. */
static inline double segment_at(const segment *g, double sigma) {
  const double den = (g->z1 - g->z0) - sigma * (g->d1 - g->d0);
  if (!(den > 0.0)) return 1.0;
  const double s = (sigma * g->d0 - g->z0) / den;
  return s < 0.0 ? 0.0 : (s > 1.0 ? 1.0 : s);
}

/* What one origin gathers over one slice, and how it weighs a band. */
typedef struct gather {
  const bounce_ctx *ctx;
  int channels;
  pass_mode mode;
  double inverse_length; /* texels per step: slopes per step to tangents */
  double half_width;     /* the sector's (hi - lo) / 2 */
  double cx, cy;         /* PASS_SURFACE: integral over the sector of cos, sin of azimuth */
  /* PASS_SURFACE: per corner, n_f's weight of cos^2 (n_x cx + n_y cy) and
   * of sin cos (n_z (hi - lo) / 2), and its plane's tangent along the
   * slice with that tangent's atan, sin^2 and sin cos */
  double horizontal[FACES], vertical[FACES];
  double plane[FACES], plane_theta[FACES], plane_sin2[FACES], plane_sincos[FACES];
  double plane_low, plane_high; /* the lowest and highest of the planes */
  double last_t, last_theta; /* the last atan taken: bands chain */
  double last_tex_t, last_sin2, last_sin; /* PASS_TEXEL: the last band's far end's
                                             sin^2 and sin of its atan */
  double acc[FACES * MAX_CHANNELS];
  /* PASS_SURFACE: over bands above every corner's plane, n_f . w is linear
   * in n_f: what they bring is summed once, per channel the integrals of
   * cos^2 and the change of sin^2, shared out at the end (gather_share) */
  double above[2 * MAX_CHANNELS];
} gather;

static inline double sin2(double t) { /* sin^2 of atan t */
  return t * t / (1.0 + t * t);
}

static inline double sincos_of(double t) { /* sin cos of atan t */
  return t / (1.0 + t * t);
}

static inline double theta_of(gather *g, double t) {
  if (t != g->last_t) g->last_t = t, g->last_theta = atan(t);
  return g->last_theta;
}

/* Adds the band of tangents [ta, tb] seeing radiance r (channels values);
 * theta_a, theta_b: their atan when known, else NAN. */
static void band_add(gather *g, double ta, double tb, double theta_a, double theta_b,
                     const double *r) {
  const int channels = g->channels;
  if (g->mode == PASS_TEXEL) {
    /* bands chain: the last band's far end is most often this one's near */
    double s2a, sna;
    if (ta == g->last_tex_t) s2a = g->last_sin2, sna = g->last_sin;
    else s2a = sin2(ta), sna = ta / sqrt(1.0 + ta * ta);
    const double s2b = sin2(tb), snb = tb / sqrt(1.0 + tb * tb);
    g->last_tex_t = tb, g->last_sin2 = s2b, g->last_sin = snb;
    const double w_ao = g->half_width * (s2b - s2a);
    const double w_solid = 2.0 * g->half_width * (snb - sna);
    g->acc[0] += w_ao * r[0];
    for (int k = 1; k < channels; k++) g->acc[k] += w_solid * r[k];
    return;
  }
  if (!(tb > g->plane_low)) return; /* under every corner's plane */
  if (isnan(theta_a)) theta_a = theta_of(g, ta);
  if (isnan(theta_b)) theta_b = theta_of(g, tb);
  g->last_t = tb, g->last_theta = theta_b;
  const double s2b = sin2(tb), scb = sincos_of(tb);
  if (ta >= g->plane_high) {
    const double cos2 = 0.5 * (theta_b - theta_a) + 0.5 * (scb - sincos_of(ta));
    const double sc = s2b - sin2(ta);
    for (int k = 0; k < channels; k++) {
      g->above[2 * k] += cos2 * r[k];
      g->above[2 * k + 1] += sc * r[k];
    }
    return;
  }
  const double s2a = sin2(ta), sca = sincos_of(ta);
  for (int f = 0; f < FACES; f++) {
    double th_a = theta_a, s2 = s2a, sc = sca;
    if (g->plane[f] > ta) {
      if (!(tb > g->plane[f])) continue;
      if (isnan(g->plane_theta[f])) g->plane_theta[f] = atan(g->plane[f]); /* when first met */
      th_a = g->plane_theta[f], s2 = g->plane_sin2[f], sc = g->plane_sincos[f];
    }
    const double cos2 = 0.5 * (theta_b - th_a) + 0.5 * (scb - sc);
    const double w = g->horizontal[f] * cos2 + g->vertical[f] * (s2b - s2);
    double *out = g->acc + (size_t)f * (size_t)channels;
    for (int k = 0; k < channels; k++) out[k] += w * r[k];
  }
}

/* The band of slopes (per step) [sa, sb] over segment seg: its radiance
 * blended where the band's ends meet it; a band wider than WIDE_BAND
 * radians over which the point met moves, in pieces; a corner's band
 * across the highest plane, in two (below it the corners differ). */
static void band_pieces(gather *g, const segment *seg, double sa, double sb);
static void band_on_segment(gather *g, const segment *seg, double sa, double sb) {
  if (g->mode == PASS_SURFACE) {
    const double high = g->plane_high / g->inverse_length;
    if (sb <= g->plane_low / g->inverse_length) return;
    if (sa < high && sb > high) {
      band_pieces(g, seg, sa, high);
      band_pieces(g, seg, high, sb);
      return;
    }
  }
  band_pieces(g, seg, sa, sb);
}

static void band_pieces(gather *g, const segment *seg, double sa, double sb) {
  const int channels = g->channels;
  const double ta = sa * g->inverse_length, tb = sb * g->inverse_length;
  const double at_a = segment_at(seg, sa), at_b = segment_at(seg, sb);
  int pieces = 1;
  double theta_a = 0.0, theta_b = 0.0;
  /* The mean of the ends is off where the point met moves unevenly over a
   * wide band and the radiance changes along the segment: only then is
   * the band cut (a tall wall seen from its foot, not a short segment). */
  const double nearest = ta < 0.0 && tb > 0.0 ? 0.0 : (fabs(ta) < fabs(tb) ? fabs(ta) : fabs(tb));
  double change = 0.0; /* only for a wide band: most are narrow */
  if ((tb - ta) / (1.0 + nearest * nearest) > WIDE_BAND)
    for (int k = 0; k < channels; k++) {
      const double c = fabs((double)seg->far[k] - (double)seg->near[k]);
      change = c > change ? c : change;
    }
  if (fabs(at_b - at_a) * change > 0.01 && (tb - ta) / (1.0 + nearest * nearest) > WIDE_BAND) {
    theta_a = theta_of(g, ta), theta_b = atan(tb); /* the bound above is not the width */
    pieces = (int)ceil((theta_b - theta_a) / WIDE_BAND);
    if (pieces < 1) pieces = 1;
  }
  double prev_t = ta, prev_at = at_a, prev_theta = pieces > 1 ? theta_a : NAN;
  for (int i = 1; i <= pieces; i++) {
    const double theta = i == pieces ? (pieces > 1 ? theta_b : NAN)
                                     : theta_a + (theta_b - theta_a) * i / pieces;
    const double t = i == pieces ? tb : tan(theta);
    const double at = i == pieces ? at_b : segment_at(seg, t / g->inverse_length);
    const double mid = 0.5 * (prev_at + at);
    double r[MAX_CHANNELS];
    for (int k = 0; k < channels; k++)
      r[k] = (double)seg->near[k] + mid * ((double)seg->far[k] - (double)seg->near[k]);
    band_add(g, prev_t, t, prev_theta, theta, r);
    prev_t = t, prev_at = at, prev_theta = theta;
  }
}

/* A line's profile for a gather, point by point in the order of u (step
 * by step, the template's points; the last of a step is the next texel):
 * each point's height; the highest point of each step, so a gather can
 * pass over what lies below its rays; and, made when first asked for, the
 * radiance at the two ends of the segment from the point before it to it,
 * blended over the segment's triangle. */
typedef struct line_profile {
  const bounce_ctx *ctx;
  const bb__line_view *line;
  const struct template_segment *segments;
  int count;       /* points per step */
  int channels;
  long total;      /* points */
  long origin0;    /* the profile step of texel 0 */
  double *z;
  double *step_max;
  double *mip;     /* levels 1.. of step_max's max pyramid: block i of level
                      k (2^k steps from step i 2^k) at mip[level_at[k] + i] */
  long level_at[64];
  int levels;
  long *step_x, *step_y; /* each step's first texel */
  float *radiance; /* 2 x channels per point: its segment's near and far end */
  unsigned char *ready;
  double z_begin;  /* the vertex before the first point (lines with ends) */
  double frac[4 * BB__MAX_LATTICE_STEP + 1];
} line_profile;

/* Which triangle a template segment lies in, relative to its step's start
 * texel, and its corners' weights at the segment's ends. */
typedef struct template_segment {
  int cx, cy, upper;
  double near[3], far[3];
} template_segment;

static void corner_weights(int upper, double fx, double fy, double w[3]) {
  if (upper) w[0] = 1.0 - fy, w[1] = fx + fy - 1.0, w[2] = 1.0 - fx;
  else w[0] = 1.0 - fx - fy, w[1] = fx, w[2] = fy;
}

static void template_segments(const bb__line_view *line, template_segment *ts) {
  for (int k = 0; k < line->point_count; k++) {
    const double f0 = k ? line->points[k - 1].frac : 0.0, f1 = line->points[k].frac;
    const double mx = 0.5 * (f0 + f1) * line->a, my = 0.5 * (f0 + f1) * line->b;
    ts[k].cx = (int)floor(mx), ts[k].cy = (int)floor(my);
    ts[k].upper = (mx - ts[k].cx) + (my - ts[k].cy) > 1.0;
    corner_weights(ts[k].upper, f0 * line->a - ts[k].cx, f0 * line->b - ts[k].cy, ts[k].near);
    corner_weights(ts[k].upper, f1 * line->a - ts[k].cx, f1 * line->b - ts[k].cy, ts[k].far);
  }
}

static inline long step_coordinate(const bb__line_view *line, long base, long step, int along_x) {
  const long v = base + step * (along_x ? line->a : line->b);
  if (line->p->addressing != BB_ADDRESS_PERIODIC) return v;
  return wrap(v, along_x ? line->p->width : line->p->height);
}

static inline double step_start_z(const line_profile *lp, long ps);

static void profile_build(const bounce_ctx *ctx, const bb__line_view *line,
                          const template_segment *ts, line_profile *lp) {
  const bb_pyramid *p = line->p;
  const int count = line->point_count;
  lp->ctx = ctx;
  lp->segments = ts;
  lp->total = (long)line->steps * count;
  lp->origin0 = line->round ? 0 : -line->first_step;
  for (int k = 0; k < count; k++) lp->frac[k] = line->points[k].frac;
  memset(lp->ready, 0, (size_t)lp->total);
  for (int s = 0; s < line->steps; s++) {
    const long step = line->first_step + s;
    const long bx = step_coordinate(line, line->x0, step, 1);
    const long by = step_coordinate(line, line->y0, step, 0);
    lp->step_x[s] = bx, lp->step_y[s] = by;
    double top = -INFINITY;
    for (int k = 0; k < count; k++) {
      const bb__template_point *t = &line->points[k];
      const double z = bb__lattice_height(height_at(p, bx + t->x1, by + t->y1),
                                          height_at(p, bx + t->x2, by + t->y2), t->w);
      lp->z[(size_t)s * (size_t)count + (size_t)k] = z;
      top = z > top ? z : top;
    }
    lp->step_max[s] = top;
  }
  lp->z_begin = height_at(p, step_coordinate(line, line->x0, line->first_step, 1),
                          step_coordinate(line, line->y0, line->first_step, 0));
  /* the max pyramid over the steps, for passing over long stretches */
  long n = line->steps, at = 0;
  const double *below = lp->step_max;
  lp->levels = 1;
  while (n > 1 && lp->levels < 63) {
    const long m = (n + 1) / 2;
    double *level = lp->mip + at;
    for (long i = 0; i < m; i++)
      level[i] = 2 * i + 1 < n ? fmax(below[2 * i], below[2 * i + 1]) : below[2 * i];
    lp->level_at[lp->levels++] = at;
    below = level, at += m, n = m;
  }
}

/* How many steps from profile step ps on (forward) or back (behind) lie
 * wholly under the ray of slope `seen` from the origin: the largest
 * aligned block of the pyramid that does, within `room` steps; 0 when
 * none. near: the block's near end's distance. The pyramid is climbed
 * from its smallest blocks: a block that fails every test fails them
 * for every larger block holding it (aligned the same way, within the
 * room and the profile, its top no lower, its far end no nearer), so
 * the first to fail ends the climb, most often at once. */
static long block_under(const line_profile *lp, long ps, int forward, double near, double oz,
                        double seen, long room) {
  long found = 0;
  for (int k = 1; k < lp->levels; k++) {
    const long size = 1L << k;
    if (size > room) break;
    const long first = forward ? ps : ps - size + 1;
    if (first < 0 || first + size > lp->line->steps || (first & (size - 1))) break;
    double top = lp->mip[lp->level_at[k] + (first >> k)];
    if (!forward) top = fmax(top, step_start_z(lp, first)); /* visited going back */
    if (!(top - oz <= seen * (seen >= 0.0 ? near : near + (double)size))) break;
    found = size;
  }
  return found;
}

/* The radiance at the near (0) or far (1) end of point q's segment. */
static void point_radiance_fill(line_profile *lp, long q, float *out);
static inline const float *point_radiance(line_profile *lp, long q, int far) {
  const int channels = lp->channels;
  float *out = lp->radiance + (size_t)q * 2 * (size_t)channels;
  if (!lp->ready[q]) point_radiance_fill(lp, q, out); /* the first ask only: out of line */
  return out + (far ? channels : 0);
}

static void point_radiance_fill(line_profile *lp, long q, float *out) {
  const int channels = lp->channels;
  const long s = q / lp->count;
  const template_segment *g = &lp->segments[q - s * lp->count];
  const float *corners = triangle_corners(lp->line->p, lp->ctx->radiance, lp->step_x[s] + g->cx,
                                          lp->step_y[s] + g->cy, g->upper, channels);
  for (int c = 0; c < channels; c++) {
    double near = 0.0, farther = 0.0;
    for (int i = 0; i < 3; i++) {
      near += g->near[i] * (double)corners[(size_t)i * (size_t)channels + (size_t)c];
      farther += g->far[i] * (double)corners[(size_t)i * (size_t)channels + (size_t)c];
    }
    out[c] = (float)near, out[channels + c] = (float)farther;
  }
  lp->ready[q] = 1;
}

/* The band [seen, upto] of slopes (per step) over the segment from (d0,
 * z0) to (d1, z1) (heights above the origin), whose ends have the
 * radiance near and far. */
static void seen_band(gather *g, double d0, double z0, double d1, double z1, const float *near,
                      const float *far, double seen, double upto) {
  const segment seg = {d0, z0, d1, z1, near, far};
  band_on_segment(g, &seg, seen, upto);
}

/* Index of the profile step `r` steps from the origin's (forward: 0 is
 * its own; behind: 1 is the one before it), or -1 outside the profile. */
static inline long step_at(const line_profile *lp, long origin_step, long r, int forward) {
  long ps = forward ? origin_step + r : origin_step - r;
  const long steps = lp->line->steps;
  if (lp->line->round) return wrap(ps, steps);
  return ps >= 0 && ps < steps ? ps : -1;
}

/* Height of the vertex at the start of profile step ps. */
static inline double step_start_z(const line_profile *lp, long ps) {
  if (ps > 0) return lp->z[(size_t)ps * (size_t)lp->count - 1];
  return lp->line->round ? lp->z[lp->total - 1] : lp->z_begin;
}

/* Texel j's gather along one side of the line (forward: along (a, b)), up
 * to its horizon (tangent t_h per texel) and the horizon's point: the
 * bands of the profile it sees, into g->acc. A point is seen when it
 * rises above every nearer one. Within exact_steps steps every point of
 * the profile counts; further, up to far_steps, only the texels (the
 * surface between two of them taken as straight); what is left then
 * meets the horizon's own point. Distances are whole steps plus the
 * template's fraction, the same whatever texel the line starts at. */
static void scan_origin(gather *g, line_profile *lp, int j, int forward, float t_h,
                        int64_t tangent_key) {
  const bb__line_view *line = lp->line;
  const int count = lp->count, last = count - 1;
  const long exact = g->ctx->exact_steps, limit = g->ctx->far_steps;
  if (!(t_h > 0.0f) && g->mode == PASS_TEXEL) return; /* nothing blocked */
  const double oz = line->vz[j] + line->bias;
  const double top = (double)t_h / g->inverse_length; /* the horizon's slope per step */
  const long origin_step = lp->origin0 + j;
  /* the tangent point: its step counted away from the origin (ahead: 0 is
   * the origin's own step; behind: 1 is the step before it) and index */
  const long tangent_r = forward ? bb__key_step(tangent_key) : -bb__key_step(tangent_key);
  const int tangent_k = bb__key_point(tangent_key);
  /* the steepest slope so far: a texel's H starts at 0; a corner also sees
   * the surface below (on steep triangles a good part of its light) */
  double seen = g->mode == PASS_TEXEL ? 0.0 : -STEEPEST;
  const float *last_far = NULL;
  long r = forward ? 0 : 1;
  for (; r <= tangent_r && r < (forward ? limit : limit + 1); r++) {
    const long ps = step_at(lp, origin_step, r, forward);
    if (ps < 0) break;
    /* the step's near and far ends (going away from the origin) */
    const double d_near = forward ? (double)r : (double)(r - 1), d_far = d_near + 1.0;
    /* far out, whole stretches under the ray are passed at once */
    if (seen > -STEEPEST && r >= (forward ? exact : exact + 1)) {
      const long room = (tangent_r - 1) - r + 1 < limit - r ? (tangent_r - 1) - r + 1 : limit - r;
      const long skip = block_under(lp, ps, forward, forward ? (double)r : (double)(r - 1), oz,
                                    seen, room);
      if (skip > 1) {
        r += skip - 1;
        continue;
      }
    }
    /* under the ray through the steepest point so far: the points visited
     * here are the step's own going forward, and going back the step's
     * start vertex instead of its end vertex */
    const double highest = forward ? lp->step_max[ps] : fmax(lp->step_max[ps], step_start_z(lp, ps));
    if (seen > -STEEPEST && highest - oz <= seen * (seen >= 0.0 ? d_near : d_far)) continue;
    const size_t base = (size_t)ps * (size_t)count;
    if (r < (forward ? exact : exact + 1)) {
      /* every point, from the near end: forward k = 0.. (k - 1 before
       * it), behind k = count - 2.. down to -1 (the step's start vertex) */
      double d0 = d_near, z0 = (forward ? step_start_z(lp, ps) : lp->z[base + (size_t)last]) - oz;
      for (int i = 0; i < count; i++) {
        const int k = forward ? i : last - 1 - i;
        const double d = forward ? (double)r + lp->frac[k] : (double)r - (k >= 0 ? lp->frac[k] : 0.0);
        const double z = (k >= 0 ? lp->z[base + (size_t)k] : step_start_z(lp, ps)) - oz;
        if (z > seen * d) {
          const double slope = z / d, upto = slope < top ? slope : top;
          /* the segment's own index: forward the point's, behind the one after */
          const long q = (long)base + (forward ? k : k + 1);
          const float *near = point_radiance(lp, q, forward ? 0 : 1);
          const float *far = point_radiance(lp, q, forward ? 1 : 0);
          if (upto > seen) seen_band(g, d0, z0, d, z, near, far, seen, upto);
          seen = slope, last_far = far;
          if (seen >= top) return;
        }
        /* the point's own step and index: behind, the start vertex is the
         * last point of the step after it (further away) */
        const long id_r = !forward && k < 0 ? r + 1 : r;
        const int id_k = k < 0 ? last : k;
        if (id_r == tangent_r && id_k == tangent_k) goto remainder;
        d0 = d, z0 = z;
      }
    } else {
      /* the far end's texel only, seen along the straight line from the
       * near end's; the radiance at each end from the segment beside it */
      const double z0 = (forward ? step_start_z(lp, ps) : lp->z[base + (size_t)last]) - oz;
      const double z = (forward ? lp->z[base + (size_t)last] : step_start_z(lp, ps)) - oz;
      /* the horizon's point inside this step: left to the remainder */
      if (r == tangent_r && (!forward || tangent_k != last)) break;
      if (z > seen * d_far) {
        const double slope = z / d_far, upto = slope < top ? slope : top;
        const float *near = forward ? point_radiance(lp, (long)base, 0)
                                    : point_radiance(lp, (long)base + last, 1);
        const float *far = forward ? point_radiance(lp, (long)base + last, 1)
                                   : point_radiance(lp, (long)base, 0);
        if (upto > seen) seen_band(g, d_near, z0, d_far, z, near, far, seen, upto);
        seen = slope, last_far = far;
        if (seen >= top) return;
      }
      if (forward ? r == tangent_r : r + 1 == tangent_r && tangent_k == last) break;
    }
  }
remainder:
  if (seen >= top) return;
  {
    /* What is left meets the horizon's own point (the scan was cut short,
     * or rounding kept it a hair under the horizon). */
    const float *at = NULL;
    const long ps = step_at(lp, origin_step, tangent_r, forward);
    if (ps >= 0) {
      const long q = ps * count + tangent_k;
      if (forward) at = point_radiance(lp, q, 1);
      else if (tangent_k < last) at = point_radiance(lp, q + 1, 0);
      else {
        const long next = step_at(lp, origin_step, tangent_r - 1, 0);
        if (next >= 0) at = point_radiance(lp, next * count, 0);
      }
    }
    if (!at) at = last_far;
    if (!at) return;
    double rad[MAX_CHANNELS];
    for (int c = 0; c < g->channels; c++) rad[c] = (double)at[c];
    band_add(g, seen * g->inverse_length, (double)t_h, NAN, NAN, rad);
  }
}

static int scratch_reserve(scratch *sc, size_t steps, size_t points, int channels) {
  if (points <= sc->points && steps <= sc->steps) return 1;
  free(sc->z), free(sc->step_max), free(sc->step_x), free(sc->step_y);
  free(sc->radiance), free(sc->ready), free(sc->mip);
  sc->mip = malloc((steps + 64) * sizeof(double));
  sc->z = malloc(points * sizeof(double));
  sc->radiance = malloc(points * 2 * (size_t)channels * sizeof(float));
  sc->ready = malloc(points);
  sc->step_max = malloc(steps * sizeof(double));
  sc->step_x = malloc(steps * sizeof(long));
  sc->step_y = malloc(steps * sizeof(long));
  const int ok = sc->z && sc->radiance && sc->ready && sc->step_max && sc->step_x && sc->step_y &&
                 sc->mip;
  sc->points = ok ? points : 0;
  sc->steps = ok ? steps : 0;
  return ok;
}

/* The setup of one origin's gather over slice s. */
static void gather_slice(gather *g, const bounce_ctx *ctx, int s, const bb__line_view *line) {
  const bb_rayset *rs = ctx->rs;
  g->ctx = ctx;
  g->channels = ctx->channels;
  g->mode = ctx->mode;
  g->half_width = rs->half_width[s];
  g->inverse_length = bb__step_inverse(line->a, line->b);
  const double lo = rs->sector[2 * s], hi = rs->sector[2 * s + 1];
  g->cx = sin(hi) - sin(lo);
  g->cy = cos(lo) - cos(hi);
  g->last_t = NAN;
  g->last_tex_t = NAN;
}

/* PASS_SURFACE: the corners of a vertex, its faces' normals n, as seen
 * along slice s. */
static void gather_corners(gather *g, const double n[FACES][3], double dx, double dy) {
  for (int f = 0; f < FACES; f++) {
    const double plane = -(n[f][0] * dx + n[f][1] * dy) / n[f][2];
    g->horizontal[f] = n[f][0] * g->cx + n[f][1] * g->cy;
    g->vertical[f] = n[f][2] * g->half_width;
    g->plane[f] = plane;
    g->plane_theta[f] = NAN; /* band_add takes its atan when a band crosses the plane */
    g->plane_sin2[f] = sin2(plane);
    g->plane_sincos[f] = sincos_of(plane);
    g->plane_low = f == 0 || plane < g->plane_low ? plane : g->plane_low;
    g->plane_high = f == 0 || plane > g->plane_high ? plane : g->plane_high;
  }
}

/* PASS_SURFACE: what the bands above every plane brought, to each corner. */
static void gather_share(gather *g) {
  const int channels = g->channels;
  for (int f = 0; f < FACES; f++)
    for (int k = 0; k < channels; k++)
      g->acc[f * channels + k] +=
          g->horizontal[f] * g->above[2 * k] + g->vertical[f] * g->above[2 * k + 1];
}

static void line_hook(void *user, const bb__line_view *line) {
  bounce_ctx *ctx = user;
  const int channels = ctx->channels, W = line->p->width;
  /* texel by texel, both sides of the line with one vertex_faces: each
   * texel's sums take the sides in the same order as side by side */
  if (ctx->mode == PASS_DIRECT) {
    for (int j = 0; j < line->len; j++) {
      const size_t v = line->texel[j];
      double n[FACES][3];
      vertex_faces(ctx->p, (long)(v % (size_t)W), (long)(v / (size_t)W), n);
      for (int side = 0; side < 2; side++) {
        const bb__sweep_dir *dir = line->dir[side];
        if (!dir) continue;
        const int s = dir->slice;
        const double dx = ctx->rs->slice_dir[2 * s], dy = ctx->rs->slice_dir[2 * s + 1];
        direct_texel(ctx, s, dx, dy, (const double(*)[3])n, line->found[side][j],
                     ctx->sums + v * FACES * (size_t)channels);
      }
    }
    return;
  }
  scratch *sc = slot_take(ctx);
  const size_t points = (size_t)line->steps * (size_t)line->point_count;
  if (!scratch_reserve(sc, (size_t)line->steps, points, channels)) {
    atomic_store(&ctx->out_of_memory, 1);
    atomic_flag_clear(&sc->busy);
    return;
  }
  template_segment ts[4 * BB__MAX_LATTICE_STEP + 1];
  template_segments(line, ts);
  line_profile lp = {.line = line, .count = line->point_count, .channels = channels,
                     .z = sc->z, .step_max = sc->step_max, .mip = sc->mip, .step_x = sc->step_x,
                     .step_y = sc->step_y, .radiance = sc->radiance, .ready = sc->ready};
  profile_build(ctx, line, ts, &lp);
  gather g[2];
  for (int side = 0; side < 2; side++)
    if (line->dir[side]) gather_slice(&g[side], ctx, line->dir[side]->slice, line);
  const int lanes = ctx->mode == PASS_SURFACE ? FACES * channels : channels;
  for (int j = 0; j < line->len; j++) {
    const size_t v = line->texel[j];
    double n[FACES][3];
    if (ctx->mode == PASS_SURFACE)
      vertex_faces(line->p, (long)(v % (size_t)W), (long)(v / (size_t)W), n);
    for (int side = 0; side < 2; side++) {
      const bb__sweep_dir *dir = line->dir[side];
      if (!dir) continue;
      gather *gs = &g[side];
      if (ctx->mode == PASS_SURFACE) {
        const int s = dir->slice;
        gather_corners(gs, (const double(*)[3])n, ctx->rs->slice_dir[2 * s],
                       ctx->rs->slice_dir[2 * s + 1]);
      }
      for (int i = 0; i < lanes; i++) gs->acc[i] = 0.0;
      for (int i = 0; i < 2 * channels; i++) gs->above[i] = 0.0;
      scan_origin(gs, &lp, j, side == 0, line->found[side][j], line->tangent_key[side][j]);
      if (ctx->mode == PASS_SURFACE) gather_share(gs);
      float *out = ctx->sums + v * (size_t)lanes;
      for (int i = 0; i < lanes; i++) out[i] += (float)gs->acc[i];
    }
  }
  atomic_flag_clear(&sc->busy);
}

/* ------------------------------------------------------------ the driver */

/* A move in fixed point (2^-40 of the sky's radiance), summed exactly: the
 * sum, and so the tail, does not depend on the order of the texels, which
 * a periodic shift of the map changes. */
typedef unsigned __int128 exact_sum;
static inline exact_sum fixed(double v) {
  return (exact_sum)(uint64_t)llround(v * 0x1p40); /* ldexp(v, 40): exact, as a product */
}

typedef struct driver {
  bounce_ctx ctx;
  const bb__bounce_options *o;
  const bb_rayset *fine; /* the trace's slices: the direct light and the texels */
  const int *order;
  bb_rayset coarse;      /* the further bounces' slices (none: the trace's) */
  int *coarse_order;
  float *direct;   /* E of every corner from the sky (FACES x channels per vertex) */
  float *radiance; /* what every corner reflects now */
  const float *albedo;
  exact_sum *row_sum;
  double tail; /* the last move's multiple added as the series' rest (0: none) */
  long work, work_done; /* bb__bounce_work, and what the passes so far did */
} driver;

static void zero_row(void *user, int y) {
  driver *d = user;
  const size_t n = (size_t)d->ctx.p->width * FACES * (size_t)d->ctx.channels;
  memset(d->ctx.sums + (size_t)y * n, 0, n * sizeof(float));
}

/* What one slice of each pass costs, in a trace's slices (instructions,
 * rock06 256 x 256 at scale 32, callgrind): the progress's weights. */
static int slice_work(pass_mode mode) {
  return mode == PASS_DIRECT ? 3 : mode == PASS_SURFACE ? 16 : 10;
}

static int surface_passes(const bb__bounce_options *o) {
  if (o->bounces > 0) return o->bounces - 1;
  return o->estimate_passes > 1 ? o->estimate_passes : 1;
}

static int coarse_slices(const bb_rayset *rs, const bb__bounce_options *o) {
  const int n = o->surface_slices;
  if (n > 0) return n < rs->slice_count ? n : rs->slice_count;
  return rs->slice_count / 2 >= 4 ? rs->slice_count / 2 : rs->slice_count;
}

long bb__bounce_work(const bb_rayset *rs, const bb__bounce_options *o) {
  return (long)rs->slice_count * (slice_work(PASS_DIRECT) + slice_work(PASS_TEXEL)) +
         (long)surface_passes(o) * coarse_slices(rs, o) * slice_work(PASS_SURFACE);
}

static bb_status run_pass(driver *d, pass_mode mode, double bias, bb_error *err) {
  bounce_ctx *ctx = &d->ctx;
  const int coarse = mode == PASS_SURFACE && d->coarse.slice_count;
  const bb_rayset *rs = coarse ? &d->coarse : d->fine;
  const int *order = coarse ? d->coarse_order : d->order;
  const bb__bounce_options *o = d->o;
  ctx->rs = rs;
  ctx->mode = mode;
  ctx->exact_steps = mode == PASS_TEXEL ? o->exact_steps : o->surface_exact_steps;
  ctx->far_steps = mode == PASS_TEXEL ? o->far_steps : o->surface_far_steps;
  bb_status st = bb__parallel_for(ctx->p->height, o->threads, zero_row, d, NULL, NULL, err);
  for (int k = 0; st == BB_OK && k < rs->slice_count;) {
    const int s = order[k];
    const int pair = k + 1 < rs->slice_count &&
                     rs->slice_step[2 * s] == -rs->slice_step[2 * order[k + 1]] &&
                     rs->slice_step[2 * s + 1] == -rs->slice_step[2 * order[k + 1] + 1];
    const bb__sweep_dir along = {rs, s, NULL, NULL};
    const bb__sweep_dir opposite = {rs, pair ? order[k + 1] : 0, NULL, NULL};
    /* a slice of a pass at 2048 x 2048 takes seconds: cancel inside it */
    const bb__checkpoint cancel = {o->progress, o->progress_user};
    st = bb__sweep_lines_hooked(ctx->p, rs->slice_step[2 * s], rs->slice_step[2 * s + 1],
                                &along, pair ? &opposite : NULL, bias, o->threads, 0,
                                line_hook, ctx, &cancel, err);
    k += pair ? 2 : 1;
    if (st == BB_OK && atomic_load(&ctx->out_of_memory))
      st = bb__fail(err, BB_ERR_MEMORY, "bounce: out of memory for a line");
    /* monotone over the whole: what the passes before this one did, and
     * this one's slices so far */
    const long done = o->progress_before + d->work_done + (long)k * slice_work(mode);
    const long total = o->progress_before + d->work + o->progress_after;
    if (st == BB_OK && o->progress && o->progress(o->progress_user, done, total))
      st = bb__fail(err, BB_ERR_CANCELLED, "bounce: cancelled by the progress callback");
  }
  d->work_done += (long)rs->slice_count * slice_work(mode);
  return st;
}

/* Bounces 0 starts from an estimate of each corner's converged light: as
 * though every surface it sees were as bright as itself, the light it
 * reflects is its first bounce times 1 / (1 - lambda), lambda = rho beta,
 * beta the part of its hemisphere (cosine-weighted) that the surface
 * blocks, 1 - E_ao / pi (held under 0.9). One surface pass from there
 * brings the texels within what 4 or 5 passes from the first bounce did
 * (docs/accuracy.md "Inter-reflection"). Lobes take the ao channel's
 * ratio: the surfaces seen are lit by the same lobe. */
static double estimate_ratio(const driver *d, double rho, size_t v, int f) {
  const double e_ao = (double)d->direct[(v * FACES + (size_t)f) * (size_t)d->ctx.channels];
  double beta = 1.0 - e_ao / BB__PI;
  beta = beta < 0.0 ? 0.0 : (beta > 1.0 ? 1.0 : beta);
  const double lambda = rho * beta;
  return lambda < 0.9 ? lambda : 0.9;
}

/* After the direct pass: each corner's E from the sky, and its radiance. */
static void direct_row(void *user, int y) {
  driver *d = user;
  const bounce_ctx *ctx = &d->ctx;
  const int channels = ctx->channels, W = ctx->p->width;
  exact_sum sum = 0;
  for (int x = 0; x < W; x++) {
    const size_t v = (size_t)y * (size_t)W + (size_t)x;
    const double rho = d->o->rho * (d->albedo ? (double)d->albedo[v] : 1.0);
    double n[FACES][3];
    vertex_faces(ctx->p, x, y, n);
    for (int f = 0; f < FACES; f++) {
      const size_t out = corner_index(ctx->p, x, y, f, channels);
      for (int k = 0; k < channels; k++) {
        const size_t i = (v * FACES + (size_t)f) * (size_t)channels + (size_t)k;
        const double *all = ctx->vt->all + 3 * k;
        const double e = n[f][0] * all[0] + n[f][1] * all[1] + n[f][2] * all[2] - (double)ctx->sums[i];
        d->direct[i] = (float)(e > 0.0 ? e : 0.0);
        if (out != SIZE_MAX) {
          /* the first bounce, or (bounces 0) the corner's estimate of all */
          const double gain = d->o->bounces ? 1.0 : 1.0 / (1.0 - estimate_ratio(d, rho, v, f));
          d->radiance[out + (size_t)k] = (float)(rho / BB__PI * (double)d->direct[i] * gain);
          sum += fixed((double)d->radiance[out + (size_t)k]);
        }
      }
    }
  }
  d->row_sum[y] = sum;
}

/* After a surface pass: how far each corner's radiance would move, summed
 * per row; then the move, and with it, when the bounces stop here, the
 * rest of the series estimated as geometric. */
static double corner_radiance(const driver *d, size_t v, size_t i) {
  const double rho = d->o->rho * (d->albedo ? (double)d->albedo[v] : 1.0);
  const double e = (double)d->direct[i] + (double)d->ctx.sums[i];
  return rho / BB__PI * (e > 0.0 ? e : 0.0);
}

static void change_row(void *user, int y) {
  driver *d = user;
  const int channels = d->ctx.channels;
  const size_t W = (size_t)d->ctx.p->width;
  exact_sum sum = 0;
  for (size_t x = 0; x < W; x++) {
    const size_t v = (size_t)y * W + x;
    for (int f = 0; f < FACES; f++) {
      const size_t out = corner_index(d->ctx.p, (long)x, y, f, channels);
      if (out == SIZE_MAX) continue;
      for (int k = 0; k < channels; k++) {
        const size_t i = (v * FACES + (size_t)f) * (size_t)channels + (size_t)k;
        sum += fixed(fabs((double)(float)corner_radiance(d, v, i) -
                          (double)d->radiance[out + (size_t)k]));
      }
    }
  }
  d->row_sum[y] = sum;
}

static void update_row(void *user, int y) {
  driver *d = user;
  const int channels = d->ctx.channels;
  const size_t W = (size_t)d->ctx.p->width;
  for (size_t x = 0; x < W; x++) {
    const size_t v = (size_t)y * W + x;
    for (int f = 0; f < FACES; f++) {
      const size_t out = corner_index(d->ctx.p, (long)x, y, f, channels);
      if (out == SIZE_MAX) continue;
      for (int k = 0; k < channels; k++) {
        const size_t i = (v * FACES + (size_t)f) * (size_t)channels + (size_t)k;
        const double r = corner_radiance(d, v, i);
        d->radiance[out + (size_t)k] = (float)(r + d->tail * (r - (double)d->radiance[out + (size_t)k]));
      }
    }
  }
}

/* Clamp mode: the last column and row of cells reach vertices past the
 * image (the border extruded), which no vertex's slots fill. Such a cell
 * is flat along the extrusion, its two triangles in one plane, so a
 * corner out there takes the value of the corner inside it was extruded
 * from, on either triangle. */
static void corner_fixup(driver *d) {
  const bb_pyramid *p = d->ctx.p;
  if (p->addressing == BB_ADDRESS_PERIODIC) return;
  const size_t C = (size_t)d->ctx.channels, W = (size_t)p->width, H = (size_t)p->height;
  float *r = d->radiance;
#define CORNER(cell, half, corner) (r + (((cell) * 2 + (size_t)(half)) * 3 + (size_t)(corner)) * C)
#define COPY(to, from) memcpy((to), (from), C * sizeof(float))
  for (size_t y = 0; y + 1 < H; y++) { /* x = W - 1: (1,0) from (0,0), (1,1) from (0,1) */
    const size_t cell = y * W + W - 1;
    COPY(CORNER(cell, 0, 1), CORNER(cell, 0, 0));
    COPY(CORNER(cell, 1, 0), CORNER(cell, 0, 0));
    COPY(CORNER(cell, 1, 1), CORNER(cell, 1, 2));
  }
  for (size_t x = 0; x + 1 < W; x++) { /* y = H - 1: (0,1) from (0,0), (1,1) from (1,0) */
    const size_t cell = (H - 1) * W + x;
    COPY(CORNER(cell, 0, 2), CORNER(cell, 0, 0));
    COPY(CORNER(cell, 1, 2), CORNER(cell, 0, 0));
    COPY(CORNER(cell, 1, 1), CORNER(cell, 1, 0));
  }
  const size_t last = H * W - 1; /* only its (0,0) corner is inside */
  for (int half = 0; half < 2; half++)
    for (int corner = 0; corner < 3; corner++)
      if (half || corner) COPY(CORNER(last, half, corner), CORNER(last, 0, 0));
#undef COPY
#undef CORNER
}

typedef struct finish_job {
  const driver *d;
  bb_image *vis;
} finish_job;

static void finish_row(void *user, int y) {
  const finish_job *job = user;
  const bounce_ctx *ctx = &job->d->ctx;
  const bb_rayset *rs = ctx->rs;
  const int channels = ctx->channels, W = job->vis->width;
  for (int x = 0; x < W; x++) {
    const size_t v = (size_t)y * (size_t)W + (size_t)x;
    float *out = job->vis->pixels + v * (size_t)job->vis->channels;
    const float *sum = ctx->sums + v * (size_t)channels;
    const double ao = (double)out[0] + (double)sum[0] / BB__PI;
    out[0] = (float)(ao < 1.0 ? ao : 1.0);
    for (int k = 1; k < channels; k++)
      out[k] = (float)((double)out[k] + (double)sum[k] / rs->total[k]);
  }
}

void bb__bounce_options_init(bb__bounce_options *o) {
  memset(o, 0, sizeof *o);
  o->estimate_passes = 1;
  o->lift = 0.25;
  o->exact_steps = 4;
  o->surface_exact_steps = 1;
  o->far_steps = 1024;
  o->surface_far_steps = 16;
}

bb_status bb__bounce_add(const bb_pyramid *p, const bb_rayset *rs, const bb__bounce_options *o,
                         bb_image *vis, int *bounces_done, bb_error *err) {
  if (bounces_done) *bounces_done = 0;
  if (!p || !rs || !o || !vis || !vis->pixels || vis->width != p->width ||
      vis->height != p->height || vis->channels != 1 + rs->basis_count)
    return bb__fail(err, BB_ERR_ARGUMENT, "bounce: the visibility does not match the pyramid");
  if (o->albedo && (o->albedo->width != p->width || o->albedo->height != p->height ||
                    o->albedo->channels != 1))
    return bb__fail(err, BB_ERR_ARGUMENT, "bounce: the albedo map does not match the height");
  const int channels = 1 + rs->basis_count, threads = bb__thread_count(o->threads);
  const size_t texels = (size_t)p->width * (size_t)p->height;
  const size_t corners = texels * FACES * (size_t)channels;
  vtables vt = {0};
  driver d = {.o = o, .albedo = o->albedo ? o->albedo->pixels : NULL};
  bounce_ctx *ctx = &d.ctx;
  ctx->p = p, ctx->rs = rs, ctx->vt = &vt, ctx->channels = channels;
  atomic_init(&ctx->out_of_memory, 0);
  int *order = malloc((size_t)rs->slice_count * sizeof(int));
  ctx->sums = malloc(corners * sizeof(float));
  d.direct = malloc(corners * sizeof(float));
  d.radiance = malloc(corners * sizeof(float));
  d.row_sum = malloc((size_t)p->height * sizeof *d.row_sum);
  ctx->slot_count = threads < 256 ? threads : 256;
  ctx->slots = calloc((size_t)ctx->slot_count, sizeof(scratch));
  bb_status st = BB_OK;
  if (!order || !ctx->sums || !d.direct || !d.radiance || !d.row_sum || !ctx->slots ||
      bb_trace_slice_order(rs, order, NULL) != BB_OK)
    st = bb__fail(err, BB_ERR_MEMORY, "bounce: out of memory (%zu corners)", corners / (size_t)channels);
  d.order = order;
  d.fine = rs;
  const int surface_slices = coarse_slices(rs, o);
  d.work = bb__bounce_work(rs, o);
  if (st == BB_OK && surface_slices < rs->slice_count) {
    bb_basis basis = {.count = rs->basis_count, .name = "bounce"};
    memcpy(basis.vector, rs->basis, sizeof basis.vector);
    st = bb__rayset_make(surface_slices, rs->power, &basis, o->threads, &d.coarse, err);
    d.coarse_order = st == BB_OK ? malloc((size_t)surface_slices * sizeof(int)) : NULL;
    if (st == BB_OK && (!d.coarse_order ||
                        bb_trace_slice_order(&d.coarse, d.coarse_order, NULL) != BB_OK))
      st = bb__fail(err, BB_ERR_MEMORY, "bounce: out of memory");
  }
  for (int i = 0; st == BB_OK && i < ctx->slot_count; i++) atomic_flag_clear(&ctx->slots[i].busy);
  if (st == BB_OK) st = vtables_build(rs, o->threads, &vt, err);
  if (st == BB_OK) st = run_pass(&d, PASS_DIRECT, o->lift, err);
  if (st == BB_OK) st = bb__parallel_for(p->height, o->threads, direct_row, &d, NULL, NULL, err);
  if (st == BB_OK) corner_fixup(&d);
  ctx->radiance = d.radiance;
  /* The bounces: each pass adds what the corners gather of the last one.
   * bounces N: N - 1 passes from the first bounce. bounces 0: the passes
   * from the estimate; the terms left are then about the last move times
   * lambda / (1 - lambda), lambda the ratio of the last two moves summed
   * over every corner (the series of bounces is close to geometric), and
   * that is added. */
  int done = 1;
  exact_sum last_sum = 0;
  for (int y = 0; st == BB_OK && y < p->height; y++) last_sum += d.row_sum[y];
  const int passes = surface_passes(o);
  for (int pass = 0; st == BB_OK && pass < passes; pass++) {
    st = run_pass(&d, PASS_SURFACE, o->lift, err);
    if (st == BB_OK) st = bb__parallel_for(p->height, o->threads, change_row, &d, NULL, NULL, err);
    if (st != BB_OK) break;
    exact_sum sum = 0;
    for (int y = 0; y < p->height; y++) sum += d.row_sum[y];
    d.tail = 0.0;
    if (o->bounces == 0 && pass == passes - 1 && last_sum > 0) {
      double lambda = (double)sum / (double)last_sum;
      lambda = lambda < 0.9 ? lambda : 0.9;
      d.tail = lambda / (1.0 - lambda);
    }
    last_sum = sum;
    st = bb__parallel_for(p->height, o->threads, update_row, &d, NULL, NULL, err);
    if (st == BB_OK) corner_fixup(&d);
    done++;
  }
  if (st == BB_OK) st = run_pass(&d, PASS_TEXEL, o->bias, err);
  if (st == BB_OK) {
    finish_job fj = {&d, vis};
    st = bb__parallel_for(p->height, o->threads, finish_row, &fj, NULL, NULL, err);
  }
  if (st == BB_OK && bounces_done) *bounces_done = done;
  for (int i = 0; ctx->slots && i < ctx->slot_count; i++) {
    scratch *sc = &ctx->slots[i];
    free(sc->z), free(sc->step_max), free(sc->step_x), free(sc->step_y);
    free(sc->radiance), free(sc->ready), free(sc->mip);
  }
  free(ctx->slots);
  vtables_free(&vt);
  free(order);
  free(ctx->sums);
  free(d.direct);
  free(d.radiance);
  free(d.row_sum);
  bb__rayset_release(&d.coarse);
  free(d.coarse_order);
  return st;
}
