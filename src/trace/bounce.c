/* bounce.c: inter-reflection: the light the surrounding height field
 * reflects into each texel's ao and lobes, gathered from what the line
 * sweeps' own walks see.
 *
 * The model (docs/conventions.md "Inter-reflection"). Every triangle is
 * Lambertian with albedo rho; the sky of channel k (ao: radiance 1; lobe c:
 * max(0, w.B_c)^P) lights it directly, and the rest of the surface lights
 * it again. A texel's blocked directions no longer bring nothing: each
 * brings the radiance of the surface it meets.
 *
 * What the surface reflects. Each triangle's light is kept at its three
 * corners: for vertex v and each of its 6 triangles f ("slots"),
 * R = rho(v) / pi E_k(v, n_f), the irradiance of channel k on f's own plane
 * a tenth of a texel (`lift`) above v (at v itself its neighbours shadow it in
 * every valley as no point inside the triangle is), blended linearly over
 * the triangle. A steep triangle (one rising more than `steep` texels: a
 * cliff one texel wide) is lit very differently at its foot and its top, so
 * it gets a column instead: its light at `column_samples` heights from its
 * foot to its top, sampled in front of it (above its lowest vertex, on its
 * own plane), and read at the height where a ray meets it.
 *
 * E is integrated per slice like the bake's visibility: the sector above
 * max(horizon, the plane's own elevation along the slice, 0) gives n .
 * integral of sky_k(w) w dw over it, from tables of the three components
 * (built here, like integrate.c's, in q = t / (1 + t)).
 *
 * The gather. Along a slice's line the surface is a profile, and the sweep
 * walks it with the upper hull of the points beyond each origin. An origin
 * sees, in its blocked band of elevations, the hull's vertices from the
 * nearest up to its tangent point (the horizon's), each rising above every
 * nearer point; and for a few fixed slopes shared by the whole line, where
 * that ray first meets the profile (a stack per slope of the points beyond,
 * in coordinates sheared by it: the first point above a ray is the first
 * greater element, found in the stack from its near end). These known
 * points of the visible surface, in order of elevation, stand for it: the
 * band between two of them meets the straight chord between them, its
 * radiance blended along the chord, in pieces when the band is wide. Every
 * point is pushed once on each stack, each origin asks each stack once, so
 * a pass costs time proportional to texels x slices, whatever the map's
 * size or relief.
 *
 * Passes (each a sweep of every slice of its set, in the trace's order, so
 * every sum is made in a fixed order and the result is the same on any
 * thread count): the direct light of every corner and column sample; then,
 * for the bounces after the first, what they gather from the surface (over
 * a set of fewer slices: that light is smooth), from below their
 * horizontal too; last, what each texel's origin (lifted by the bake's
 * bias) gathers, added to its visibility. With bounces N that is N - 1
 * surface passes from the first bounce. With bounces 0 (converged) each
 * sample starts from an estimate of all its light (estimate_ratio),
 * estimate_passes surface passes gather from it, and the rest of the
 * series, close to geometric, is added as the last move times
 * lambda / (1 - lambda), lambda the ratio of the last two moves summed over
 * every sample. Progress counts every pass's sweeps, weighted by what they
 * cost (pass_work); each sweep polls the caller's progress every 50 ms, so
 * a cancel is seen within a fraction of a second.
 *
 * The coarse level. On a map 512 texels or more on its longer side
 * (bb__bounce_level) all of this runs on the heights at every f-th vertex
 * (add_coarse), and each texel gets the light added there per unit of
 * blocked visibility, bilinear, times its own blocked visibility from the
 * map's trace (lift_row): the bounce then costs a quarter of the map's (or
 * less), the map's occlusion stays exactly the bake's.
 */
#include "trace/bounce.h"
#include "core/internal.h"
#include "trace/integrate.h"
#include "trace/march.h"
#include "trace/pyramid.h"
#include "trace/rayset.h"
#include "trace/sweep.h"
#include "bumpbake_cluster.h"

#include <limits.h>
#include <math.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

enum { FACES = 6, MAX_CHANNELS = 1 + BB_MAX_BASIS, MAX_SLOPES = 8, MAX_KNOWN = 48 };
#define WIDE_BAND 0.1           /* radians: a band wider than this is cut into pieces */
#define TAN_WIDE_BAND 0.1003347 /* its tangent */
#define CHANGE_PER_PIECE 0.02   /* radiance: a band's pieces change by at most this */
#define FLAT_CHANGE 1e-3 /* radiance: a band changing less sees the mean of its ends */
#define MAX_PIECES 2
#define CROSSING_WALK 64 /* breakpoints a ray's crossing is looked for among */
#define THIN_BAND                                                                        \
  0.05 /* tangent: a face's plane this little above its horizon is not clipped */

typedef enum pass_mode {
  PASS_DIRECT,  /* samples: what the sky's open sectors give */
  PASS_SURFACE, /* samples: what the surface reflects to them */
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
  if (v >= 0 && v < n)
    return v;
  if (v >= n && v < 2 * n)
    return v - n;
  if (v < 0 && v >= -n)
    return v + n;
  const long r = v % n;
  return r < 0 ? r + n : r;
}

/* What the corners reflect is kept cell by cell, so the three corners of a
 * triangle lie together: ((cell * 2 + half) * 3 + corner) * channels.
 * The index of vertex (x, y)'s slot f, or SIZE_MAX where the cell lies
 * outside a clamped image (corner_fixup fills its border cells). */
static inline size_t corner_index(const bb_pyramid *p, long x, long y, int f,
                                  int channels) {
  long cx = x + slot_dx[f], cy = y + slot_dy[f];
  if (p->addressing == BB_ADDRESS_PERIODIC) {
    if (cx < 0)
      cx += p->width;
    if (cy < 0)
      cy += p->height;
  } else if (cx < 0 || cy < 0) {
    return SIZE_MAX;
  }
  const size_t cell = (size_t)cy * (size_t)p->width + (size_t)cx;
  return ((cell * 2 + (size_t)slot_upper[f]) * 3 + (size_t)slot_corner[f]) *
         (size_t)channels;
}

/* The three corners of half `upper` of cell (cx, cy) (any coordinates:
 * periodic ones wrap, clamped ones are held to the image's cells). */
static inline const float *triangle_corners(const bb_pyramid *p, const float *radiance,
                                            long cx, long cy, int upper, int channels) {
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
enum { RING_NODES = 16, THETA_NODES = 4, VT_INTERVALS = 64 };

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
static void ring_piece(const lobe_ring *l, double A, double C, double a, double b,
                       int zero_a, int zero_b, double out[3]) {
  if (!(b > a))
    return;
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
    if (zero_a)
      psi = a + length * x * x, jacobian = 2.0 * length * x;
    else if (zero_b)
      psi = b - length * x * x, jacobian = 2.0 * length * x;
    else
      psi = a + length * x, jacobian = length;
    const double v = A * cos(psi) + C;
    if (!(v > 0.0))
      continue;
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
  int channels;     /* 1 + lobes */
  size_t per_slice; /* doubles of one slice's table */
  double *coef;     /* per slice: interval k, channel k, component j: 4 coefficients */
  double *total;    /* per slice: 3 per channel */
  double all[3 * MAX_CHANNELS]; /* the totals summed over the slices */
} vtables;

typedef struct table_job {
  const bb_rayset *rs;
  const double *sector;        /* 2 per slice: the azimuths its tables cover */
  const unsigned char *wanted; /* per slice: its tables are built (NULL: all) */
  vtables *t;
  const rules *r;
} table_job;

static void ring_of(const table_job *job, int s, int k, double theta, double out[3]) {
  const bb_rayset *rs = job->rs;
  const double lo = job->sector[2 * s], hi = job->sector[2 * s + 1];
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
  if (job->wanted && !job->wanted[s])
    return;
  enum { N = VT_INTERVALS };
  const int channels = t->channels, width = 3 * channels;
  double *coef = t->coef + (size_t)s * t->per_slice;
  double *total = t->total + (size_t)s * (size_t)width;
  const double h = 1.0 / N;
  for (int k = 0; k < channels; k++) {
    double value[3] = {0.0, 0.0, 0.0}, ring[3];
    double theta = 0.0, slope[3];
    ring_of(job, s, k, 0.0, ring);
    for (int j = 0; j < 3; j++)
      slope[j] = ring[j]; /* cos 0 = 1, dtheta/dq = 1 at q = 0 */
    for (int i = 0; i < N; i++) {
      const double q1 = (double)(i + 1) * h, theta1 = atan2(q1, 1.0 - q1);
      double step[3] = {0.0, 0.0, 0.0};
      const double mid = 0.5 * (theta + theta1), half = 0.5 * (theta1 - theta);
      for (int n = 0; n < THETA_NODES; n++) {
        const double th = mid + half * job->r->theta_x[n];
        ring_of(job, s, k, th, ring);
        for (int j = 0; j < 3; j++)
          step[j] += job->r->theta_w[n] * ring[j] * cos(th);
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
    for (int j = 0; j < 3; j++)
      total[3 * k + j] = value[j];
  }
}

/* The tables of rs's slices, each over sector[2 s] .. sector[2 s + 1]
 * (NULL: the slice's own), those wanted only (NULL: all). */
static bb_status vtables_build(const bb_rayset *rs, const double *sector,
                               const unsigned char *wanted, int threads, vtables *t,
                               bb_error *err) {
  memset(t, 0, sizeof *t);
  t->channels = 1 + rs->basis_count;
  t->per_slice = (size_t)VT_INTERVALS * 3 * (size_t)t->channels * 4;
  t->coef = calloc((size_t)rs->slice_count * t->per_slice, sizeof(double));
  t->total = calloc((size_t)rs->slice_count * 3 * (size_t)t->channels, sizeof(double));
  if (!t->coef || !t->total)
    return bb__fail(err, BB_ERR_MEMORY, "bounce: out of memory");
  rules r;
  bb__gauss_legendre(RING_NODES, r.ring_x, r.ring_w);
  bb__gauss_legendre(THETA_NODES, r.theta_x, r.theta_w);
  table_job job = {rs, sector ? sector : rs->sector, wanted, t, &r};
  bb_status st =
      bb__parallel_for(rs->slice_count, threads, build_slice, &job, NULL, NULL, err);
  for (int s = 0; s < rs->slice_count; s++) /* in slice order, whatever the threads did */
    for (int i = 0; i < 3 * t->channels; i++)
      t->all[i] += t->total[(size_t)s * 3 * (size_t)t->channels + (size_t)i];
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
    for (int i = 0; i < width; i++)
      g[i] = 0.0;
    return;
  }
  if (tan_el > 1e100)
    tan_el = 1e100;
  const double x = tan_el / (1.0 + tan_el) * VT_INTERVALS;
  int k = (int)x;
  if (k > VT_INTERVALS - 1)
    k = VT_INTERVALS - 1;
  const double f = x - (double)k;
  const double *coef = t->coef + (size_t)s * t->per_slice + (size_t)k * (size_t)width * 4;
  for (int i = 0; i < width; i++)
    g[i] = BB__HERMITE(coef, f, i);
}

/* ------------------------------------------------------------- columns */

/* The corners of half `upper` of a cell, offsets from its (0, 0) vertex. */
static const int corner_ox[2][3] = {{0, 1, 0}, {1, 1, 0}};
static const int corner_oy[2][3] = {{0, 0, 1}, {0, 1, 1}};

/* Steep triangles (cell * 2 + half) and the light of each at several
 * heights: its column. A column's samples lie above its triangle's lowest
 * vertex (an image texel: the sweeps' origins are texels), from `lift`
 * above it up to the triangle's top, evenly spaced, each lit on the
 * triangle's own plane. */
typedef struct columns {
  int count, samples;
  int *of_triangle; /* per triangle: its column, or -1 */
  int *start; /* per vertex, and one more: its columns are list[start[v] .. start[v + 1])
               */
  int *list;
  int *vertex;                     /* per column: the texel below it */
  unsigned char *top;              /* per column: the triangle's corner at its top */
  double *normal;                  /* per column: the triangle's unit normal (3) */
  float *z;                        /* per column: its samples' heights */
  float *direct, *radiance, *sums; /* per column: samples x channels */
} columns;

static void columns_free(columns *c) {
  free(c->of_triangle), free(c->start), free(c->list), free(c->vertex), free(c->top),
      free(c->normal);
  free(c->z), free(c->direct), free(c->radiance), free(c->sums);
  memset(c, 0, sizeof *c);
}

/* The columns of every triangle rising more than steep texels (none when
 * steep <= 0 or samples < 2); 1 when out of memory. */
static int columns_build(const bb_pyramid *p, double steep, int samples, double lift,
                         int channels, columns *c) {
  memset(c, 0, sizeof *c);
  const long W = p->width, H = p->height;
  const size_t triangles = (size_t)W * (size_t)H * 2, vertices = (size_t)W * (size_t)H;
  c->samples = samples;
  c->of_triangle = malloc(triangles * sizeof(int));
  c->start = calloc(vertices + 1, sizeof(int));
  if (!c->of_triangle || !c->start)
    return 1;
  for (size_t t = 0; t < triangles; t++)
    c->of_triangle[t] = -1;
  if (!(steep > 0.0) || samples < 2)
    return 0;
  /* count, then fill: the columns numbered in triangle order */
  for (int pass = 0; pass < 2; pass++) {
    int n = 0;
    for (long cy = 0; cy < H; cy++)
      for (long cx = 0; cx < W; cx++)
        for (int u = 0; u < 2; u++) {
          double z[3];
          int low = 0, high = 0;
          for (int k = 0; k < 3; k++) {
            z[k] = height_at(p, cx + corner_ox[u][k], cy + corner_oy[u][k]);
            if (z[k] < z[low])
              low = k;
            if (z[k] > z[high])
              high = k;
          }
          if (!(z[high] - z[low] > steep))
            continue;
          if (pass == 1) {
            const size_t v = vertex_at(p, cx + corner_ox[u][low], cy + corner_oy[u][low]);
            c->of_triangle[((size_t)cy * (size_t)W + (size_t)cx) * 2 + (size_t)u] = n;
            c->vertex[n] = (int)v;
            c->top[n] = (unsigned char)high;
            double *nv = c->normal + 3 * (size_t)n;
            if (u)
              nv[0] = z[2] - z[1], nv[1] = z[0] - z[1];
            else
              nv[0] = z[0] - z[1], nv[1] = z[0] - z[2];
            const double len = sqrt(nv[0] * nv[0] + nv[1] * nv[1] + 1.0);
            nv[0] /= len, nv[1] /= len, nv[2] = 1.0 / len;
            const double bottom = z[low] + lift,
                         top = z[high] > bottom ? z[high] : bottom;
            for (int i = 0; i < samples; i++)
              c->z[(size_t)n * (size_t)samples + (size_t)i] =
                  (float)(bottom + (top - bottom) * i / (samples - 1));
            c->start[v + 1]++;
          }
          n++;
        }
    if (pass == 0) {
      c->count = n;
      const size_t lanes = (size_t)n * (size_t)samples * (size_t)channels;
      c->vertex = malloc(((size_t)n + 1) * sizeof(int));
      c->top = malloc((size_t)n + 1);
      c->list = malloc(((size_t)n + 1) * sizeof(int));
      c->normal = malloc(((size_t)n + 1) * 3 * sizeof(double));
      c->z = malloc(((size_t)n + 1) * (size_t)samples * sizeof(float));
      c->direct = malloc((lanes + 1) * sizeof(float));
      c->radiance = malloc((lanes + 1) * sizeof(float));
      c->sums = malloc((lanes + 1) * sizeof(float));
      if (!c->vertex || !c->top || !c->list || !c->normal || !c->z || !c->direct ||
          !c->radiance || !c->sums)
        return 1;
    }
  }
  for (size_t v = 0; v < vertices; v++)
    c->start[v + 1] += c->start[v];
  int *fill = calloc(vertices, sizeof(int));
  if (!fill)
    return 1;
  for (int n = 0; n < c->count; n++) {
    const size_t v = (size_t)c->vertex[n];
    c->list[c->start[v] + fill[v]++] = n;
  }
  free(fill);
  return 0;
}

/* A column's light at height z, linear between its samples, and bent to
 * meet its triangle's own top corner (top, channels values) at its top:
 * the samples stand a texel in front of the surface at most, which on a
 * cliff sees as the surface does, and on a slope of 2 or 3 misses a few
 * percent of the surface's light towards its top. */
static inline void column_light(const columns *c, int n, double z, const float *top,
                                int channels, double *out) {
  const float *zs = c->z + (size_t)n * (size_t)c->samples;
  const float *r = c->radiance + (size_t)n * (size_t)c->samples * (size_t)channels;
  const int last = c->samples - 1;
  int i = 0;
  double t = 0.0;
  if (z >= (double)zs[last])
    i = last - 1, t = 1.0;
  else if (z > (double)zs[0]) {
    while (i < last - 1 && z > (double)zs[i + 1])
      i++;
    t = (z - (double)zs[i]) / ((double)zs[i + 1] - (double)zs[i]);
  }
  const double up = ((double)i + t) / last; /* how far up the column */
  for (int k = 0; k < channels; k++) {
    const double a = (double)r[(size_t)i * (size_t)channels + (size_t)k];
    const double b = (double)r[(size_t)(i + 1) * (size_t)channels + (size_t)k];
    const double miss =
        (double)top[k] - (double)r[(size_t)last * (size_t)channels + (size_t)k];
    out[k] = a + t * (b - a) + up * miss;
  }
}

/* ------------------------------------------------------------ the passes */

/* Which triangle a template segment lies in, relative to its step's start
 * texel, and its corners' weights at the segment's ends. */
typedef struct template_segment {
  int cx, cy, upper;
  double near[3], far[3];
} template_segment;

static void corner_weights(int upper, double fx, double fy, double w[3]) {
  if (upper)
    w[0] = 1.0 - fy, w[1] = fx + fy - 1.0, w[2] = 1.0 - fx;
  else
    w[0] = 1.0 - fx - fy, w[1] = fx, w[2] = fy;
}

static void template_segments(const bb__line_view *line, template_segment *ts) {
  for (int k = 0; k < line->point_count; k++) {
    const double f0 = k ? line->points[k - 1].frac : 0.0, f1 = line->points[k].frac;
    const double mx = 0.5 * (f0 + f1) * line->a, my = 0.5 * (f0 + f1) * line->b;
    ts[k].cx = (int)floor(mx), ts[k].cy = (int)floor(my);
    ts[k].upper = (mx - ts[k].cx) + (my - ts[k].cy) > 1.0;
    corner_weights(ts[k].upper, f0 * line->a - ts[k].cx, f0 * line->b - ts[k].cy,
                   ts[k].near);
    corner_weights(ts[k].upper, f1 * line->a - ts[k].cx, f1 * line->b - ts[k].cy,
                   ts[k].far);
  }
}

/* An entry of a slope's stack: a point beyond the origins (walk
 * coordinates), z - slope u, and the point just nearer than it along the
 * profile the sweep kept (set when that one is pushed; until then, the
 * origin's own vertex). */
typedef struct entry {
  double s;
  bb__walk_point p, pred;
  int has_pred;
} entry;

/* A worker's buffers, kept from one line to the next and grown as needed. */
typedef struct scratch {
  atomic_flag busy;
  size_t points, lanes, len;
  entry *stack[2][MAX_SLOPES];
  float *acc[2];         /* per side: what each texel gathered (offset[j] ..) */
  size_t *offset;        /* per texel, and one more */
  long *step_x, *step_y; /* per profiled step (line_state) */
  size_t steps;
  float *used[2]; /* PASS_TEXEL: the horizon each texel's gather went up to */
  float *last[2]; /* PASS_TEXEL: the radiance of its highest known point */
} scratch;

typedef struct bounce_ctx {
  const bb_pyramid *p;
  const bb_rayset *rs;
  const vtables *vt;
  pass_mode mode;
  int channels;
  double lift;          /* the samples' lift (DIRECT, SURFACE) or the bias (TEXEL) */
  const float *normals; /* unit normals of the triangles of cells -1 .. W-1, -1 .. H-1 */
  columns *cols;
  int slopes;
  double slope[MAX_SLOPES]; /* tangents of the fixed rays, rising */
  int chain;                /* the hull vertices an origin knows at most */
  double small_band;        /* TEXEL: a horizon under this is a small band */
  float *sums;              /* SURFACE: gathered per corner, FACES x channels per vertex;
                               TEXEL: channels per texel */
  /* DIRECT: the horizon each vertex's corners are lit from, a plane per
   * slice of the pass (corner_plane[s]: slice s's), turned into light
   * afterwards row by row (direct_row): the sweep only stores a float */
  float *corner_horizons;
  const int *corner_plane;
  size_t texels; /* the image's: the planes below hold one value per texel each */
  /* when the passes are the trace too: each slice's horizons, a plane per
   * slice (texel v of slice s at s * texels + v: a sweep's neighbouring
   * lines write neighbouring floats, not a cache line per texel) */
  float *horizons;
  /* 4 planes: per texel, the weights of its blocked bands (ao, solid angle)
   * over the slices it gathers in, then over those it does not */
  float *fill;
  int corner_hull; /* DIRECT: the sweep is the trace's, at the texels' bias; the
                      corners' horizons are asked of its hulls at their lift */
  double corner_lift;
  int turns; /* SURFACE: a line of a sweep is walked when its class is the
                sweep's (surface_line_wanted), its gathers weighed turns times */
  const float
      *radiance; /* FACES x channels per vertex, by cell: what each corner reflects */
  scratch *slots;
  int slot_count;
  atomic_int out_of_memory;
} bounce_ctx;

static scratch *slot_take(bounce_ctx *ctx) {
  for (;;)
    for (int i = 0; i < ctx->slot_count; i++)
      if (!atomic_flag_test_and_set(&ctx->slots[i].busy))
        return &ctx->slots[i];
}

static void scratch_release(scratch *sc) {
  for (int s = 0; s < 2; s++) {
    for (int k = 0; k < MAX_SLOPES; k++)
      free(sc->stack[s][k]);
    free(sc->acc[s]), free(sc->used[s]), free(sc->last[s]);
  }
  free(sc->offset), free(sc->step_x), free(sc->step_y);
}

static int scratch_steps(scratch *sc, size_t steps) {
  if (steps <= sc->steps)
    return 1;
  free(sc->step_x), free(sc->step_y);
  sc->step_x = malloc(steps * sizeof(long));
  sc->step_y = malloc(steps * sizeof(long));
  sc->steps = sc->step_x && sc->step_y ? steps : 0;
  return sc->steps != 0;
}

static int scratch_reserve(scratch *sc, size_t points, size_t lanes, size_t len,
                           int channels) {
  if (points > sc->points) {
    sc->points = 0;
    for (int s = 0; s < 2; s++) {
      for (int k = 0; k < MAX_SLOPES; k++) {
        free(sc->stack[s][k]);
        sc->stack[s][k] = malloc(points * sizeof(entry));
        if (!sc->stack[s][k])
          return 0;
      }
    }
    sc->points = points;
  }
  if (lanes > sc->lanes) {
    sc->lanes = 0;
    for (int s = 0; s < 2; s++) {
      free(sc->acc[s]);
      sc->acc[s] = malloc(lanes * sizeof(float));
      if (!sc->acc[s])
        return 0;
    }
    sc->lanes = lanes;
  }
  if (len > sc->len) {
    sc->len = 0;
    free(sc->offset);
    sc->offset = malloc((len + 1) * sizeof(size_t));
    if (!sc->offset)
      return 0;
    for (int s = 0; s < 2; s++) {
      free(sc->used[s]), free(sc->last[s]);
      sc->used[s] = malloc(len * sizeof(float));
      sc->last[s] = malloc(len * (size_t)channels * sizeof(float));
      if (!sc->used[s] || !sc->last[s])
        return 0;
    }
    sc->len = len;
  }
  return 1;
}

/* The unit normal of half `upper` of cell (cx, cy), -1 <= cx < W, -1 <= cy < H. */
static inline const float *triangle_normal(const bounce_ctx *ctx, long cx, long cy,
                                           int upper) {
  const size_t row = (size_t)ctx->p->width + 1;
  return ctx->normals +
         (((size_t)(cy + 1) * row + (size_t)(cx + 1)) * 2 + (size_t)upper) * 3;
}

/* The normals of the 6 triangles around vertex (x, y), in slot order. */
static void vertex_normals(const bounce_ctx *ctx, long x, long y, double n[FACES][3]) {
  for (int f = 0; f < FACES; f++) {
    const float *t = triangle_normal(ctx, x + slot_dx[f], y + slot_dy[f], slot_upper[f]);
    n[f][0] = (double)t[0], n[f][1] = (double)t[1], n[f][2] = (double)t[2];
  }
}

typedef struct normals_job {
  const bb_pyramid *p;
  float *normals;
} normals_job;

/* Row cy - 1 of the triangles' normals (the plane through each triangle's
 * corners). */
static void normals_row(void *user, int row) {
  const normals_job *job = user;
  const bb_pyramid *p = job->p;
  const long cy = row - 1, W = p->width;
  float *out = job->normals + (size_t)row * (size_t)(W + 1) * 6;
  for (long cx = -1; cx < W; cx++, out += 6) {
    const double z00 = height_at(p, cx, cy), z10 = height_at(p, cx + 1, cy);
    const double z01 = height_at(p, cx, cy + 1), z11 = height_at(p, cx + 1, cy + 1);
    const double n[2][2] = {{z00 - z10, z00 - z01}, {z01 - z11, z10 - z11}};
    for (int u = 0; u < 2; u++) {
      const double len = sqrt(n[u][0] * n[u][0] + n[u][1] * n[u][1] + 1.0);
      out[3 * u] = (float)(n[u][0] / len), out[3 * u + 1] = (float)(n[u][1] / len);
      out[3 * u + 2] = (float)(1.0 / len);
    }
  }
}

/* What one origin's gather over one slice weighs: per side, the sector's
 * constants; per origin, its faces. */
typedef struct gather {
  int channels;
  pass_mode mode;
  double inverse_length; /* steps per texel: slopes per step to tangents */
  double half_width;     /* the sector's (hi - lo) / 2 */
  double cx, cy;         /* integral over the sector of cos, sin of azimuth */
  double dx, dy;         /* the slice's unit direction */
  /* PASS_SURFACE: per face, n's weight of cos^2 (n_x cx + n_y cy) and of
   * sin cos (n_z (hi - lo) / 2), and its plane's tangent along the slice
   * with that tangent's atan, sin^2 and sin cos */
  int faces;
  double horizontal[FACES], vertical[FACES];
  double plane[FACES], plane_theta[FACES], plane_sin2[FACES], plane_sincos[FACES];
  double plane_low, plane_high; /* the lowest and highest of the planes */
  double acc[FACES * MAX_CHANNELS];
  /* PASS_SURFACE: over bands above every face's plane, n . w is linear in
   * n: what they bring is summed once, per channel the integrals of cos^2
   * and the change of sin^2, shared out at the end (gather_share) */
  double above[2 * MAX_CHANNELS];
} gather;

/* One line's state while it is walked. */
typedef struct line_state {
  bounce_ctx *ctx;
  scratch *sc;
  bb__line_view line;
  int count;
  template_segment ts[4 * BB__MAX_LATTICE_STEP + 1];
  double frac[4 * BB__MAX_LATTICE_STEP + 1];
  double inverse_length;
  double sigma[MAX_SLOPES]; /* the fixed rays' slopes per step */
  int size[2][MAX_SLOPES];
  gather side[2];
  long *step_x, *step_y; /* each profiled step's first texel (periodic: wrapped) */
  int narrow;            /* periodic and the image narrower than a step can reach */
} line_state;

/* Step s's first texel (any step: round lines' copies one period on or
 * back fold onto the profile's). */
static inline void step_start(const line_state *ls, long s, long *x, long *y) {
  const bb__line_view *l = &ls->line;
  if (l->round)
    s = s < 0 ? s + l->len : (s >= l->len ? s - l->len : s);
  const long i = s - l->first_step;
  if (i >= 0 && i < l->steps) {
    *x = ls->step_x[i], *y = ls->step_y[i];
    return;
  }
  *x = l->x0 + s * l->a, *y = l->y0 + s * l->b;
  if (l->p->addressing == BB_ADDRESS_PERIODIC)
    *x = wrap(*x, l->p->width), *y = wrap(*y, l->p->height);
}

/* A coordinate a template's offset away from a wrapped step start, back in
 * the image (periodic) or held to it (clamped). */
static inline long fold(const line_state *ls, long v, long n) {
  if (ls->line.p->addressing != BB_ADDRESS_PERIODIC)
    return v < 0 ? 0 : (v >= n ? n - 1 : v);
  if (ls->narrow)
    return wrap(v, n);
  return v < 0 ? v + n : (v >= n ? v - n : v);
}

static inline double sin2(double t) { /* sin^2 of atan t */
  return t * t / (1.0 + t * t);
}

static inline double sincos_of(double t) { /* sin cos of atan t */
  return t / (1.0 + t * t);
}

static inline double sin_of(double t) { /* sin of atan t */
  return t / sqrt(1.0 + t * t);
}

static void gather_side(gather *g, const bounce_ctx *ctx, int s, double inverse_length) {
  const bb_rayset *rs = ctx->rs;
  g->channels = ctx->channels;
  g->mode = ctx->mode;
  g->half_width = rs->half_width[s];
  g->inverse_length = inverse_length;
  const double lo = rs->sector[2 * s], hi = rs->sector[2 * s + 1];
  g->cx = sin(hi) - sin(lo);
  g->cy = cos(lo) - cos(hi);
  g->dx = rs->slice_dir[2 * s], g->dy = rs->slice_dir[2 * s + 1];
}

/* The faces of a sample (PASS_SURFACE): normals n[faces], as seen along
 * the gather's slice. */
static void gather_faces(gather *g, const double (*n)[3], int faces) {
  g->faces = faces;
  for (int f = 0; f < faces; f++) {
    const double plane = -(n[f][0] * g->dx + n[f][1] * g->dy) / n[f][2];
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

static void gather_clear(gather *g) {
  const int lanes = g->mode == PASS_TEXEL ? g->channels : g->faces * g->channels;
  for (int i = 0; i < lanes; i++)
    g->acc[i] = 0.0;
  for (int i = 0; i < 2 * g->channels; i++)
    g->above[i] = 0.0;
}

/* PASS_SURFACE: what the bands above every plane brought, to each face. */
static void gather_share(gather *g) {
  const int channels = g->channels;
  for (int f = 0; f < g->faces; f++)
    for (int k = 0; k < channels; k++)
      g->acc[f * channels + k] +=
          g->horizontal[f] * g->above[2 * k] + g->vertical[f] * g->above[2 * k + 1];
}

/* Adds the band of tangents [ta, tb] seeing radiance r (channels values);
 * theta_a, theta_b, their atan, are read by PASS_SURFACE only. A texel
 * weighs a band by w.z (ao) or by its solid angle (lobes), both algebraic
 * in the tangents. */
static void band_add(gather *g, double ta, double tb, double theta_a, double theta_b,
                     const double *r) {
  const int channels = g->channels;
  if (g->mode == PASS_TEXEL) {
    const double w_ao = g->half_width * (sin2(tb) - sin2(ta));
    const double w_solid = 2.0 * g->half_width * (sin_of(tb) - sin_of(ta));
    g->acc[0] += w_ao * r[0];
    for (int k = 1; k < channels; k++)
      g->acc[k] += w_solid * r[k];
    return;
  }
  if (!(tb > g->plane_low))
    return; /* under every face's plane */
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
  for (int f = 0; f < g->faces; f++) {
    double th_a = theta_a, s2 = s2a, sc = sca;
    if (g->plane[f] > ta) {
      if (!(tb > g->plane[f]))
        continue;
      if (isnan(g->plane_theta[f]))
        g->plane_theta[f] = atan(g->plane[f]); /* when first met */
      th_a = g->plane_theta[f], s2 = g->plane_sin2[f], sc = g->plane_sincos[f];
    }
    const double cos2 = 0.5 * (theta_b - th_a) + 0.5 * (scb - sc);
    const double w = g->horizontal[f] * cos2 + g->vertical[f] * (s2b - s2);
    double *out = g->acc + (size_t)f * (size_t)channels;
    for (int k = 0; k < channels; k++)
      out[k] += w * r[k];
  }
}

/* The atan a pass needs of a tangent: PASS_SURFACE's weights read it. */
static inline double theta_for(const gather *g, double t) {
  return g->mode == PASS_SURFACE ? atan(t) : NAN;
}

/* A point of the visible surface an origin knows: its slope per step from
 * the origin, its tangent (and atan, for PASS_SURFACE), where it is
 * relative to the origin (steps along the walk, height) and on the
 * profile, and its radiance. */
typedef struct known {
  double sigma, t, theta;
  double d, z;
  long step;   /* template segment `segment` of step `step` holds it, */
  int segment; /* at fraction `at` of the segment; -1: not known */
  double at;
  double r[MAX_CHANNELS];
} known;

/* Where a gather's origin is: walk coordinates, and which way it walks. */
typedef struct origin_at {
  double u0, oz;
  int side;
} origin_at;

/* The radiance of the surface on template segment k of step s of the line
 * (from point k - 1, or the step's start, to point k), at fraction t of it
 * (its height z, for a column). */
static void segment_light(const line_state *ls, long s, int k, double t, double z,
                          double *out) {
  const bounce_ctx *ctx = ls->ctx;
  const bb_pyramid *p = ctx->p;
  const int channels = ctx->channels;
  t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
  const template_segment *g = &ls->ts[k];
  long bx, by;
  step_start(ls, s, &bx, &by);
  const long cx = fold(ls, bx + g->cx, p->width), cy = fold(ls, by + g->cy, p->height);
  const size_t triangle =
      ((size_t)cy * (size_t)p->width + (size_t)cx) * 2 + (size_t)g->upper;
  const int column = ctx->cols->of_triangle[triangle];
  const float *corners = ctx->radiance + triangle * 3 * (size_t)channels;
  if (column >= 0) {
    column_light(ctx->cols, column, z,
                 corners + (size_t)ctx->cols->top[column] * (size_t)channels, channels,
                 out);
    return;
  }
  double w[3];
  for (int i = 0; i < 3; i++)
    w[i] = g->near[i] + t * (g->far[i] - g->near[i]);
  for (int c = 0; c < channels; c++)
    out[c] = w[0] * (double)corners[c] + w[1] * (double)corners[channels + c] +
             w[2] * (double)corners[2 * channels + c];
}

/* The radiance at a profile point (its key) on the face towards an origin
 * before it along the line (smaller u) or after it. */
static void point_light(const line_state *ls, int64_t key, double z, int before,
                        known *q) {
  long s = bb__key_step(key);
  int k = bb__key_point(key);
  if (!before && ++k == ls->count)
    k = 0, s++;
  q->step = s, q->segment = k, q->at = before ? 1.0 : 0.0;
  segment_light(ls, s, k, q->at, z, q->r);
}

/* The radiance at u along the line (steps from its texel 0) and height z,
 * where no key says which segment holds it. */
static void surface_light(const line_state *ls, double u, double z, double *out) {
  const double fl = floor(u);
  const long s = (long)fl;
  const double f = u - fl;
  int k = 0;
  while (k < ls->count - 1 && ls->frac[k] < f)
    k++;
  const double f0 = k ? ls->frac[k - 1] : 0.0, f1 = ls->frac[k];
  segment_light(ls, s, k, (f - f0) / (f1 - f0), z, out);
}

/* The band between two known points, meeting the chord between them: the
 * mean of their radiance; or, when the radiance changes along it, pieces
 * of it cut at evenly spaced points of the chord (where a ray grazes a
 * long slope, the point it meets moves fast, so even cuts in angle would
 * not do), none wider than WIDE_BAND radians, each seeing the light
 * between its ends: when both ends lie on one straight segment the chord
 * is the surface, and its own light is read (a column's is not linear);
 * when they are within a step of each other, the chord runs close to the
 * surface, and the light of the surface under or over it is read;
 * otherwise the chord's ends' light is blended. */
static void band_between(const line_state *ls, gather *g, const known *a, const known *b,
                         const origin_at *o) {
  const int channels = g->channels;
  if (!(b->t > a->t))
    return;
  double change = 0.0;
  for (int k = 0; k < channels; k++) {
    const double c = fabs(b->r[k] - a->r[k]);
    change = c > change ? c : change;
  }
  double r[MAX_CHANNELS];
  if (change < FLAT_CHANGE) { /* too little to matter how it spreads */
    for (int k = 0; k < channels; k++)
      r[k] = 0.5 * (a->r[k] + b->r[k]);
    band_add(g, a->t, b->t, a->theta, b->theta, r);
    return;
  }
  const int same = a->segment >= 0 && a->step == b->step && a->segment == b->segment;
  const int close =
      !same && a->segment >= 0 && b->segment >= 0 && labs(a->step - b->step) <= 1;
  if (g->mode == PASS_TEXEL && !same && !close) {
    /* the radiance linear along the chord (lambda 0 .. 1), each channel's
     * weight W(lambda) a function of the ray through the chord's point:
     * integral of L dW = L_a (W_b - W_a) + (L_b - L_a) (W_b - mean of W),
     * the mean by Simpson's rule */
    const double dm = 0.5 * (a->d + b->d), zm = 0.5 * (a->z + b->z);
    double tm = zm / dm * g->inverse_length;
    tm = tm < a->t ? a->t : (tm > b->t ? b->t : tm);
    const double ao_a = sin2(a->t), ao_b = sin2(b->t), ao_m = sin2(tm);
    const double so_a = sin_of(a->t), so_b = sin_of(b->t), so_m = sin_of(tm);
    const double w_ao = g->half_width * (ao_b - ao_a);
    const double m_ao = g->half_width * (ao_b - (ao_a + 4.0 * ao_m + ao_b) / 6.0);
    const double w_solid = 2.0 * g->half_width * (so_b - so_a);
    const double m_solid =
        2.0 * g->half_width * (so_b - (so_a + 4.0 * so_m + so_b) / 6.0);
    g->acc[0] += a->r[0] * w_ao + (b->r[0] - a->r[0]) * m_ao;
    for (int k = 1; k < channels; k++)
      g->acc[k] += a->r[k] * w_solid + (b->r[k] - a->r[k]) * m_solid;
    return;
  }
  int pieces = (int)(change / CHANGE_PER_PIECE) + 1;
  pieces = pieces > MAX_PIECES ? MAX_PIECES : pieces;
  /* the band's width in radians, atan of (tb - ta) / (1 + ta tb), without it when narrow
   */
  const double spread = (b->t - a->t) / (1.0 + a->t * b->t);
  if (spread > TAN_WIDE_BAND) {
    const int by_angle = (int)(atan(spread) / WIDE_BAND) + 1;
    pieces = pieces > by_angle ? pieces : by_angle;
  }
  double prev_t = a->t, prev_theta = a->theta, prev_at = 0.0;
  for (int i = 1; i <= pieces; i++) {
    const double at = (double)i / pieces;
    double t = b->t, theta = b->theta;
    if (i < pieces) { /* the ray through the chord's point at `at` */
      const double d = a->d + at * (b->d - a->d), z = a->z + at * (b->z - a->z);
      t = z / d * g->inverse_length;
      t = t < prev_t ? prev_t : (t > b->t ? b->t : t);
      theta = theta_for(g, t);
    }
    const double mid = 0.5 * (prev_at + at);
    if (same)
      segment_light(ls, a->step, a->segment, a->at + mid * (b->at - a->at),
                    o->oz + a->z + mid * (b->z - a->z), r);
    else if (close) {
      const double u = o->u0 + a->d + mid * (b->d - a->d);
      surface_light(ls, o->side ? -u : u, o->oz + a->z + mid * (b->z - a->z), r);
    } else
      for (int k = 0; k < channels; k++)
        r[k] = a->r[k] + mid * (b->r[k] - a->r[k]);
    band_add(g, prev_t, t, prev_theta, theta, r);
    prev_t = t, prev_theta = theta, prev_at = at;
  }
}

/* The first entry of a stack (size entries, nearest last) whose sheared
 * height is above q, searched from the near end; NULL when none is. */
static const entry *stack_find(const entry *e, int size, double q) {
  if (size <= 0)
    return NULL;
  int hi = size - 1; /* entries above hi are at or under q */
  if (e[hi].s > q)
    return &e[hi];
  int step = 1, lo = hi;
  for (;;) { /* gallop away from the near end */
    lo = hi - step;
    if (lo < 0) {
      lo = -1;
      break;
    }
    if (e[lo].s > q)
      break;
    hi = lo, step *= 2;
  }
  if (lo < 0 && !(e[0].s > q))
    return NULL;
  if (lo < 0)
    lo = 0;
  /* e[lo] above q, e[hi] not: the last above before hi */
  while (hi - lo > 1) {
    const int mid = (lo + hi) / 2;
    if (e[mid].s > q)
      lo = mid;
    else
      hi = mid;
  }
  return &e[lo];
}

/* A point pushed on a side's hull: its place on each fixed ray's stack. */
static void on_push(void *state, int side, const bb__walk_point *hull, int pushed) {
  line_state *ls = state;
  const bb__walk_point *p = &hull[pushed - 1];
  for (int k = 0; k < ls->ctx->slopes; k++) {
    entry *e = ls->sc->stack[side][k];
    int size = ls->size[side][k];
    const double s = p->z - ls->sigma[k] * p->u;
    const int before = size;
    while (size > 0 && e[size - 1].s <= s)
      size--;
    if (size == before && size > 0)
      e[size - 1].pred = *p, e[size - 1].has_pred = 1;
    e[size].s = s, e[size].p = *p, e[size].has_pred = 0;
    ls->size[side][k] = size + 1;
  }
}

/* The height of template point k of step s of the line (any step: periodic
 * coordinates wrap, clamped ones are held to the image). */
static double template_height(const line_state *ls, long s, int k) {
  const bb__template_point *t = &ls->line.points[k];
  const bb_pyramid *p = ls->ctx->p;
  long bx, by;
  step_start(ls, s, &bx, &by);
  const size_t W = (size_t)p->width;
  const size_t i1 = (size_t)fold(ls, by + t->y1, p->height) * W +
                    (size_t)fold(ls, bx + t->x1, p->width);
  const size_t i2 = (size_t)fold(ls, by + t->y2, p->height) * W +
                    (size_t)fold(ls, bx + t->x2, p->width);
  return bb__lattice_height((double)p->z[i1], (double)p->z[i2], t->w);
}

/* The segment of the whole profile (every breakpoint, not only the points
 * the sweep kept) where the ray of slope sigma from (u0, oz) first meets
 * it, given e, the first kept point above the ray: into a (under the ray)
 * and b (above it), walk coordinates. The points the sweep dropped between
 * e and the kept point before it lie under the chord between those two, a
 * convex run, which the ray, under e and over its predecessor, crosses
 * once: so the crossing is found going back from e to the first point
 * under the ray (within a bounded walk; past it, or past the predecessor,
 * the chord to the predecessor, or to the origin's own vertex, stands in).
 * Returns 1 when a and b are neighbours on the profile, their keys set. */
static int ray_crossing(const line_state *ls, int side, const entry *e, double u0,
                        double oz, double vz, double sigma, bb__walk_point *a,
                        bb__walk_point *b) {
  const bb__walk_point pred = e->has_pred ? e->pred : (bb__walk_point){u0, vz, 0};
  *b = e->p, *a = pred;
  if (e->has_pred && bb__key_step(e->p.key) == bb__key_step(pred.key) &&
      bb__key_point(e->p.key) == bb__key_point(pred.key) + (side ? -1 : 1))
    return 1; /* neighbours already */
  const int count = ls->count,
            dir = side ? 1 : -1; /* towards the origin, in template order */
  long s = bb__key_step(e->p.key);
  int k = bb__key_point(e->p.key);
  const double step_u = side ? -1.0 : 1.0;
  for (int walked = 0; walked < CROSSING_WALK; walked++) {
    k += dir;
    if (k < 0)
      k = count - 1, s--;
    else if (k >= count)
      k = 0, s++;
    const double u = step_u * ((double)s + ls->frac[k]);
    /* the predecessor and the origin's vertex lie under the ray: the walk
     * stops at them at the latest */
    if (u < pred.u - 1e-9 || u < u0 - 1e-9)
      return 0;
    const double z = template_height(ls, s, k);
    if (z - sigma * (u - u0) <= oz) {
      *a = (bb__walk_point){u, z, (int64_t)s * BB__KEY_STEP + k};
      return 1;
    }
    *b = (bb__walk_point){u, z, (int64_t)s * BB__KEY_STEP + k};
  }
  return 0;
}

/* What an origin at (u0, oz) (walk coordinates; its vertex at vz) knows of
 * the surface it sees between slopes low and top (per step; top its
 * horizon's, reached at hull vertex `tangent`): the fixed rays' first
 * points, the hull's vertices on the way to the tangent, the tangent
 * itself, in rising order, into out. Returns how many. */
static int known_points(const line_state *ls, const gather *g, int side, double u0,
                        double oz, double vz, const bb__walk_point *hull, int tangent,
                        int size, double low, double top, known *pool,
                        const known **out) {
  const double inv = ls->inverse_length;
  const int before = side == 0; /* the faces seen: those towards the origin */
  known *rays = pool, *chain = pool + MAX_SLOPES;
  int nr = 0, nc = 0;
  for (int k = 0; k < ls->ctx->slopes; k++) {
    const double sigma = ls->sigma[k];
    if (!(sigma < top))
      break;
    if (sigma < low)
      continue;
    const entry *e =
        stack_find(ls->sc->stack[side][k], ls->size[side][k], oz - sigma * u0);
    if (!e)
      continue;
    bb__walk_point a, b;
    const int neighbours = ray_crossing(ls, side, e, u0, oz, vz, sigma, &a, &b);
    const double den = (b.z - a.z) - sigma * (b.u - a.u);
    double lambda = den > 0.0 ? (oz + sigma * (a.u - u0) - a.z) / den : 1.0;
    lambda = lambda < 0.0 ? 0.0 : (lambda > 1.0 ? 1.0 : lambda);
    known *q = &rays[nr++];
    const double u = a.u + lambda * (b.u - a.u);
    q->sigma = sigma, q->t = sigma * inv, q->theta = theta_for(g, q->t);
    q->d = u - u0, q->z = a.z + lambda * (b.z - a.z) - oz;
    if (neighbours) { /* the segment between them: the farther's along (a, b), the
                         nearer's back */
      q->step = bb__key_step(side ? a.key : b.key),
      q->segment = bb__key_point(side ? a.key : b.key);
      q->at = side ? 1.0 - lambda : lambda;
      segment_light(ls, q->step, q->segment, q->at, q->z + oz, q->r);
    } else {
      q->step = LONG_MIN, q->segment = -1, q->at = 0.0;
      surface_light(ls, side ? -u : u, q->z + oz, q->r);
    }
  }
  if (tangent >= 0) {
    /* a long way up a dome: every stride-th vertex, and the tangent */
    const int span = size - tangent, most = ls->ctx->chain;
    const int stride = span <= most ? 1 : (span + most - 2) / (most > 1 ? most - 1 : 1);
    for (int i = most > 1 ? size - 1 : tangent;; i -= stride) {
      if (i < tangent)
        i = tangent;
      const double d = hull[i].u - u0, z = hull[i].z - oz;
      double sigma = i == tangent ? top : z / d;
      if (sigma > top)
        sigma = top;
      if (sigma > low) {
        known *q = &chain[nc++];
        q->sigma = sigma, q->t = sigma * inv, q->theta = theta_for(g, q->t);
        q->d = d, q->z = z;
        point_light(ls, hull[i].key, hull[i].z, before, q);
      }
      if (i == tangent)
        break;
    }
  }
  int n = 0, a = 0, b = 0;
  while (a < nr || b < nc)
    out[n++] =
        b >= nc || (a < nr && rays[a].sigma <= chain[b].sigma) ? &rays[a++] : &chain[b++];
  return n;
}

/* What an origin knows of a small band: its tangent point alone (and the
 * band below it sees that point's light). */
static int horizon_point(const line_state *ls, const gather *g, int side, double u0,
                         double oz, const bb__walk_point *hull, int tangent, double top,
                         known *pool, const known **out) {
  if (tangent < 0)
    return 0;
  known *q = pool;
  q->sigma = top, q->t = top * ls->inverse_length, q->theta = theta_for(g, q->t);
  q->d = hull[tangent].u - u0, q->z = hull[tangent].z - oz;
  point_light(ls, hull[tangent].key, hull[tangent].z, side == 0, q);
  out[0] = q;
  return 1;
}

/* The bands from slope low up to the last known point: below the first,
 * its own radiance; between two, the chord between them. */
static void gather_bands(const line_state *ls, gather *g, const known *const *q, int n,
                         double low, const origin_at *o) {
  if (n == 0)
    return;
  const double t_low = low * g->inverse_length;
  if (q[0]->t > t_low)
    band_add(g, t_low, q[0]->t, theta_for(g, t_low), q[0]->theta, q[0]->r);
  for (int i = 1; i < n; i++)
    band_between(ls, g, q[i - 1], q[i], o);
}

/* The horizon (tangent, >= 0) from a point of height z at u0 over the
 * hull, and the index of its tangent vertex. */
static double horizon_from(const line_state *ls, const bb__walk_point *hull, int size,
                           double u0, double z, int *tangent) {
  const int i = bb__hull_tangent(hull, size, u0, z);
  *tangent = i;
  if (i < 0)
    return 0.0;
  const double t = (hull[i].z - z) / (hull[i].u - u0) * ls->inverse_length;
  return t > 0.0 ? t : 0.0;
}

/* A face's direct light along slice s: what the sector above max(horizon,
 * its plane, 0) gives it, as its blocked part n . G, into out. */
static void direct_face(const bounce_ctx *ctx, int s, double dx, double dy,
                        const double *n, double horizon, float *out) {
  double g[3 * MAX_CHANNELS];
  const double plane = -(n[0] * dx + n[1] * dy) / n[2];
  vtables_eval(ctx->vt, s, fmax(fmax(horizon, plane), 0.0), g);
  for (int k = 0; k < ctx->channels; k++)
    out[k] += (float)(n[0] * g[3 * k] + n[1] * g[3 * k + 1] + n[2] * g[3 * k + 2]);
}

/* A vertex's corners' direct light along slice s (from the horizon the
 * sweep found, lifted by `lift`), added to its sums: the vector integrals
 * blocked below max(horizon, 0), once for the vertex (vec, 3 x channels),
 * and for each face (normals n) whose plane rises above that, the part
 * between the two, n . (G(plane) - G(h)) (corr, FACES x channels). */
static void direct_corners(const bounce_ctx *ctx, int s, double dx, double dy,
                           const double (*n)[3], float horizon, float *vec, float *corr) {
  const int channels = ctx->channels, width = 3 * channels;
  double base[3 * MAX_CHANNELS], own[3 * MAX_CHANNELS];
  const double floor_t = horizon > 0.0f ? (double)horizon : 0.0;
  vtables_eval(ctx->vt, s, floor_t, base);
  for (int i = 0; i < width; i++)
    vec[i] += (float)base[i];
  for (int f = 0; f < FACES; f++) {
    const double plane = -(n[f][0] * dx + n[f][1] * dy) / n[f][2];
    /* the band between the horizon and the plane, behind the face: thin,
     * it weighs about its width squared (n . w vanishes on the plane) */
    if (!(plane > floor_t + THIN_BAND))
      continue;
    vtables_eval(ctx->vt, s, plane, own);
    for (int k = 0; k < channels; k++)
      corr[f * channels + k] += (float)(n[f][0] * (own[3 * k] - base[3 * k]) +
                                        n[f][1] * (own[3 * k + 1] - base[3 * k + 1]) +
                                        n[f][2] * (own[3 * k + 2] - base[3 * k + 2]));
  }
}

static void on_origin(void *state, int side, int j, double u0, double oz,
                      const bb__walk_point *hull, int size, int tangent, float horizon) {
  line_state *ls = state;
  bounce_ctx *ctx = ls->ctx;
  const int channels = ctx->channels;
  const int s = ls->line.dir[side]->slice;
  gather *g = &ls->side[side];
  float *acc = ls->sc->acc[side] + ls->sc->offset[j];
  const double vz = ls->line.vz[j], inv = ls->inverse_length;
  known pool[MAX_SLOPES + MAX_KNOWN];
  const known *q[MAX_SLOPES + MAX_KNOWN];
  if (ctx->mode == PASS_TEXEL) {
    ls->sc->used[side][j] = horizon;
    if (!(horizon > 0.0f))
      return;
    /* a small band sees, near enough, its horizon point's light */
    const int small = (double)horizon < ctx->small_band;
    const int n = small ? horizon_point(ls, g, side, u0, oz, hull, tangent,
                                        (double)horizon / inv, pool, q)
                        : known_points(ls, g, side, u0, oz, vz, hull, tangent, size, 0.0,
                                       (double)horizon / inv, pool, q);
    gather_clear(g);
    gather_bands(ls, g, q, n, 0.0, &(origin_at){u0, oz, side});
    float *last = ls->sc->last[side] + (size_t)j * (size_t)channels;
    for (int k = 0; k < channels; k++) {
      acc[k] += (float)g->acc[k];
      last[k] = n ? (float)q[n - 1]->r[k] : 0.0f;
    }
    return;
  }
  const size_t v = ls->line.texel[j];
  const columns *cols = ctx->cols;
  const int first = cols->start[v], last = cols->start[v + 1], samples = cols->samples;
  float *col_acc = acc + (ctx->mode == PASS_SURFACE ? FACES * channels : 0);
  if (ctx->mode ==
      PASS_DIRECT) { /* the corners are done at the line's end, the columns here */
    if (ctx->corner_hull) {
      int t;
      ls->sc->used[side][j] =
          (float)horizon_from(ls, hull, size, u0, vz + ctx->corner_lift, &t);
    }
    for (int c = first; c < last; c++) {
      const int col = cols->list[c];
      const double *cn = cols->normal + 3 * (size_t)col;
      for (int i = 0; i < samples; i++) {
        int t;
        const double z = (double)cols->z[(size_t)col * (size_t)samples + (size_t)i];
        direct_face(ctx, s, g->dx, g->dy, cn, horizon_from(ls, hull, size, u0, z, &t),
                    col_acc);
        col_acc += channels;
      }
    }
    return;
  }
  /* PASS_SURFACE: every face of the vertex's corners, then each column's samples */
  double n[FACES][3];
  vertex_normals(ctx, (long)(v % (size_t)ctx->p->width),
                 (long)(v / (size_t)ctx->p->width), n);
  gather_faces(g, (const double(*)[3])n, FACES);
  gather_clear(g);
  const double low = g->plane_low / inv;
  const int small = (double)horizon - g->plane_low < ctx->small_band;
  int count = small ? horizon_point(ls, g, side, u0, oz, hull, tangent,
                                    fmax((double)horizon / inv, low), pool, q)
                    : known_points(ls, g, side, u0, oz, vz, hull, tangent, size, low,
                                   fmax((double)horizon / inv, low), pool, q);
  gather_bands(ls, g, q, count, low, &(origin_at){u0, oz, side});
  gather_share(g);
  const double gain = (double)ctx->turns;
  for (int i = 0; i < FACES * channels; i++)
    acc[i] += (float)(gain * g->acc[i]);
  for (int c = first; c < last; c++) {
    const int col = cols->list[c];
    const double(*cn)[3] = (const double(*)[3])(cols->normal + 3 * (size_t)col);
    gather_faces(g, cn, 1);
    const double lo = g->plane_low / inv;
    for (int i = 0; i < samples; i++) {
      const double z = (double)cols->z[(size_t)col * (size_t)samples + (size_t)i];
      int t;
      const double h = horizon_from(ls, hull, size, u0, z, &t);
      gather_clear(g);
      count = known_points(ls, g, side, u0, z, vz, hull, t, size, lo, fmax(h / inv, lo),
                           pool, q);
      gather_bands(ls, g, q, count, lo, &(origin_at){u0, z, side});
      gather_share(g);
      for (int k = 0; k < channels; k++)
        col_acc[k] += (float)(gain * g->acc[k]);
      col_acc += channels;
    }
  }
}

static void *on_line_begin(void *user, const bb__line_view *line) {
  bounce_ctx *ctx = user;
  scratch *sc = slot_take(ctx);
  const int channels = ctx->channels;
  const columns *cols = ctx->cols;
  const size_t points =
      ctx->mode != PASS_DIRECT ? (size_t)line->steps * (size_t)line->point_count + 2 : 1;
  const size_t len = (size_t)line->len;
  if (!scratch_reserve(sc, points, 1, len, channels)) {
    atomic_flag_clear(&sc->busy);
    return NULL;
  }
  /* the accumulators' room: per texel its lanes */
  size_t lanes = 0;
  for (size_t j = 0; j < len; j++) {
    sc->offset[j] = lanes;
    if (ctx->mode == PASS_TEXEL) {
      lanes += (size_t)channels;
      continue;
    }
    const size_t v = line->texel[j];
    lanes += (size_t)channels *
             ((ctx->mode == PASS_SURFACE ? FACES : 0) +
              (size_t)(cols->start[v + 1] - cols->start[v]) * (size_t)cols->samples);
  }
  sc->offset[len] = lanes;
  line_state *ls = malloc(sizeof *ls);
  if (!ls || !scratch_reserve(sc, points, lanes + 1, len, channels) ||
      !scratch_steps(sc, (size_t)line->steps)) {
    free(ls);
    atomic_flag_clear(&sc->busy);
    return NULL;
  }
  ls->ctx = ctx, ls->sc = sc, ls->line = *line, ls->count = line->point_count;
  ls->step_x = sc->step_x, ls->step_y = sc->step_y;
  const bb_pyramid *p = ctx->p;
  const int periodic = p->addressing == BB_ADDRESS_PERIODIC;
  ls->narrow = periodic && (p->width <= 2 * BB__MAX_LATTICE_STEP + 2 ||
                            p->height <= 2 * BB__MAX_LATTICE_STEP + 2);
  for (int i = 0; i < line->steps; i++) {
    const long s = line->first_step + i;
    long x = line->x0 + s * line->a, y = line->y0 + s * line->b;
    if (periodic)
      x = wrap(x, p->width), y = wrap(y, p->height);
    ls->step_x[i] = x, ls->step_y[i] = y;
  }
  template_segments(line, ls->ts);
  for (int k = 0; k < ls->count; k++)
    ls->frac[k] = line->points[k].frac;
  ls->inverse_length = bb__step_inverse(line->a, line->b);
  for (int k = 0; k < ctx->slopes; k++)
    ls->sigma[k] = ctx->slope[k] / ls->inverse_length;
  for (int side = 0; side < 2; side++) {
    for (int k = 0; k < MAX_SLOPES; k++)
      ls->size[side][k] = 0;
    if (!line->dir[side])
      continue;
    gather_side(&ls->side[side], ctx, line->dir[side]->slice, ls->inverse_length);
    memset(sc->acc[side], 0, lanes * sizeof(float));
  }
  return ls;
}

/* After the walks: each texel's gathers added to the pass's sums, along
 * (a, b) first, then along (-a, -b), as the slices' order wants (and when
 * the pass is the trace too, what its horizons lose, added as the trace
 * adds it); in a chunk, a texel whose horizon the sweep marched (the chunk
 * could not vouch for it) has the band above its chunk's tangent met at
 * that tangent's radiance. PASS_DIRECT keeps its corners' horizons. */
static void on_line_end(void *state, const bb__line_view *line) {
  line_state *ls = state;
  bounce_ctx *ctx = ls->ctx;
  scratch *sc = ls->sc;
  const int channels = ctx->channels;
  const columns *cols = ctx->cols;
  for (int j = 0; j < line->len; j++) {
    const size_t v = line->texel[j];
    for (int side = 0; side < 2; side++) {
      if (!line->dir[side])
        continue;
      const float *acc = sc->acc[side] + sc->offset[j];
      const float found = line->found[side][j];
      if (ctx->horizons)
        ctx->horizons[(size_t)line->dir[side]->slice * ctx->texels + v] = found;
      if (ctx->fill && found > 0.0f && (ctx->mode == PASS_TEXEL || ctx->corner_hull)) {
        /* the texel's band's weights: ao's, solid angle's */
        const gather *g = &ls->side[side];
        float *w = ctx->fill + (ctx->mode == PASS_TEXEL ? 0 : 2) * ctx->texels + v;
        w[0] += (float)(g->half_width * sin2((double)found));
        w[ctx->texels] += (float)(2.0 * g->half_width * sin_of((double)found));
      }
      if (ctx->mode == PASS_TEXEL) {
        float *out = ctx->sums + v * (size_t)channels;
        const float used = sc->used[side][j];
        double extra[MAX_CHANNELS] = {0};
        if (found > used) {
          gather *g = &ls->side[side];
          gather_clear(g);
          double r[MAX_CHANNELS];
          for (int k = 0; k < channels; k++)
            r[k] = (double)sc->last[side][(size_t)j * (size_t)channels + (size_t)k];
          band_add(g, (double)used, (double)found, NAN, NAN, r);
          for (int k = 0; k < channels; k++)
            extra[k] = g->acc[k];
        }
        for (int k = 0; k < channels; k++)
          out[k] += (float)((double)acc[k] + extra[k]);
        continue;
      }
      if (ctx->mode == PASS_DIRECT) {
        const size_t plane = (size_t)ctx->corner_plane[line->dir[side]->slice];
        ctx->corner_horizons[plane * ctx->texels + v] =
            ctx->corner_hull ? sc->used[side][j] : found;
      } else {
        float *out = ctx->sums + v * FACES * (size_t)channels;
        for (int i = 0; i < FACES * channels; i++)
          out[i] += acc[i];
        acc += FACES * channels;
      }
      for (int c = cols->start[v]; c < cols->start[v + 1]; c++) {
        float *col_out =
            cols->sums + (size_t)cols->list[c] * (size_t)cols->samples * (size_t)channels;
        for (int i = 0; i < cols->samples * channels; i++)
          col_out[i] += acc[i];
        acc += cols->samples * channels;
      }
    }
  }
  atomic_flag_clear(&sc->busy);
  free(ls);
}

/* ------------------------------------------------------------ the driver */

/* A move in fixed point (2^-40 of the sky's radiance), summed exactly: the
 * sum, and so the tail, does not depend on the order of the texels, which
 * a periodic shift of the map changes. v >= 0 and far under 2^12, so
 * v 2^40 + 1/2 is exact and its truncation is llround's, without the call. */
typedef unsigned __int128 exact_sum;
static inline exact_sum fixed(double v) {
  return (exact_sum)(uint64_t)(v * 0x1p40 + 0.5); /* ldexp(v, 40): exact, as a product */
}

typedef struct driver {
  bounce_ctx ctx;
  const bb__bounce_options *o;
  const bb_rayset *fine; /* the trace's slices: the texels' */
  const int *order;
  bb_rayset surface_set; /* the further bounces' slices (none: the trace's) */
  int *surface_order;
  vtables vt;
  columns cols;
  float *normals;  /* the triangles' unit normals (bounce_ctx) */
  float *direct;   /* E of every corner from the sky (FACES x channels per vertex) */
  int *direct_seq; /* the direct pass's slices in the order it adds them; */
  int direct_count;
  int *corner_plane; /* by slice, its place there (-1: not in the pass) */
  float *radiance; /* what every corner reflects now, by cell */
  const float *albedo;
  exact_sum *row_sum;
  double tail;          /* the last move's multiple added as the series' rest (0: none) */
  long work, work_done; /* bb__bounce_work, and what the passes so far did */
  bb__checkpoint checkpoint;
} driver;

/* The caller's progress as a checkpoint for a step, or NULL without one. */
static const bb__checkpoint *checkpoint_of(const driver *d) {
  return d->o->progress ? &d->checkpoint : NULL;
}

static void zero_rows(void *user, int y) {
  driver *d = user;
  const size_t W = (size_t)d->ctx.p->width, C = (size_t)d->ctx.channels;
  memset(d->ctx.sums + (size_t)y * W * FACES * C, 0, W * FACES * C * sizeof(float));
}

/* What one slice of each pass costs against one of the trace's
 * (instructions, rock06 at 512 x 512, scale 32, callgrind): the progress's
 * weights. The texel pass is the trace itself too when the bake asks. */
static int pass_work(pass_mode mode) {
  return mode == PASS_DIRECT ? 2 : mode == PASS_SURFACE ? 4 : 3;
}

static int surface_passes(const bb__bounce_options *o) {
  if (o->bounces > 0)
    return o->bounces - 1;
  return o->estimate_passes > 0 ? o->estimate_passes : 0;
}

/* A pass's slices: wanted when set (at most the trace's), else the trace's
 * divided by `divide`, at least 4 (or the trace's, when fewer). */
static int slice_set(const bb_rayset *rs, int wanted, int divide) {
  if (wanted > 0)
    return wanted < rs->slice_count ? wanted : rs->slice_count;
  const int n = rs->slice_count / divide;
  return n >= 4 ? n : (rs->slice_count < 4 ? rs->slice_count : 4);
}

/* The turns of the surface passes' slices (bounce.h): o's, while the
 * trace has as many slices as they sweep; else 1. */
static int surface_turns(const bb_rayset *rs, const bb__bounce_options *o) {
  const int turns = o->surface_turns > 1 ? o->surface_turns : 1;
  return (long)slice_set(rs, o->surface_slices, 4) * turns <= rs->slice_count ? turns : 1;
}

/* What a slice the surface passes sweep costs: each sample gathers in one
 * of `turns` of them. */
static int surface_work(int turns) {
  const int w = pass_work(PASS_SURFACE) / turns;
  return w > 0 ? w : 1;
}

/* Whether the slice of rank k and the next share a sweep (opposite steps). */
static int sweep_pairs(const bb_rayset *rs, const int *order, int k) {
  return k + 1 < rs->slice_count &&
         rs->slice_step[2 * order[k]] == -rs->slice_step[2 * order[k + 1]] &&
         rs->slice_step[2 * order[k] + 1] == -rs->slice_step[2 * order[k + 1] + 1];
}

/* The trace's slices are split between the direct light and the texels'
 * gathers (the sweeps of even rank and those of odd) once there are 4 of
 * them or more; fewer, and each pass sweeps them all. */
static int split_slices(const bb_rayset *rs) {
  return rs->slice_count >= 4;
}

long bb__bounce_work(const bb_rayset *rs, const bb__bounce_options *o) {
  const long direct = split_slices(rs) ? rs->slice_count / 2 : rs->slice_count;
  const long texel = split_slices(rs) ? rs->slice_count - direct : rs->slice_count;
  const long work = direct * pass_work(PASS_DIRECT) + texel * pass_work(PASS_TEXEL) +
                    (long)surface_passes(o) * slice_set(rs, o->surface_slices, 4) *
                        surface_turns(rs, o) * surface_work(surface_turns(rs, o));
  const long f = o->level > 1 ? o->level : 1; /* a coarse level: f^2 times fewer texels */
  return work / (f * f) > 0 ? work / (f * f) : 1;
}

/* The direct light's sectors when the slices are split: each slice swept
 * for it (even rank) stands for its own sector and half of each
 * neighbouring one in azimuth, swept for the texels only; wanted[s] marks
 * the first. Slices are numbered by azimuth, their sectors contiguous. */
static void direct_sectors(const bb_rayset *rs, const int *order, double *sector,
                           unsigned char *wanted) {
  const int n = rs->slice_count;
  memset(wanted, 0, (size_t)n);
  for (int k = 0, rank = 0; k < n; rank++) {
    const int pair = sweep_pairs(rs, order, k);
    if (rank % 2 == 0)
      wanted[order[k]] = 1, wanted[order[k + pair]] = 1;
    k += pair ? 2 : 1;
  }
  for (int s = 0; s < n; s++) {
    sector[2 * s] = rs->sector[2 * s], sector[2 * s + 1] = rs->sector[2 * s + 1];
    if (!wanted[s])
      continue;
    const int before = (s + n - 1) % n, after = (s + 1) % n;
    if (!wanted[before])
      sector[2 * s] -= rs->half_width[before];
    if (!wanted[after])
      sector[2 * s + 1] += rs->half_width[after];
  }
}

/* The slices a pass of the given parity sweeps (run_pass), in the order
 * each texel gets them: each sweep's along, then its opposite; into seq,
 * and slice s's place in it into place[s] (-1: not swept). Their count. */
static int pass_sequence(const bb_rayset *rs, const int *order, int parity, int *seq,
                         int *place) {
  int count = 0;
  for (int s = 0; s < rs->slice_count; s++)
    place[s] = -1;
  for (int k = 0, rank = 0; k < rs->slice_count; rank++) {
    const int pair = sweep_pairs(rs, order, k);
    if (parity < 0 || rank % 2 == parity)
      for (int i = 0; i <= pair; i++)
        place[order[k + i]] = count, seq[count++] = order[k + i];
    k += pair ? 2 : 1;
  }
  return count;
}

/* PASS_SURFACE with turns: whether a sweep walks the line, its class
 * (b x0 - a y0 mod turns, the same for every texel of the line) the
 * sweep's (its slice's rank in azimuth within the half circle, mod turns).
 * With 8 slices, 2 turns (steps (5, 2), (2, 5), (-2, 5), (-5, 2)) a texel
 * is on a walked line of exactly one of the first and last sweeps (y's
 * parity decides both) and of the middle two (x's): 4 of the 8 slices. */
static int surface_line_wanted(void *user, const bb__line_view *line) {
  const bounce_ctx *ctx = user;
  if (ctx->mode != PASS_SURFACE || ctx->turns <= 1)
    return 1;
  const int t = ctx->turns, half = (ctx->rs->slice_count + 1) / 2;
  const long c = ((long)line->b * line->x0 - (long)line->a * line->y0) % t;
  const bb__sweep_dir *dir = line->dir[0] ? line->dir[0] : line->dir[1];
  return (c + t) % t == (dir->slice % half) % t;
}

static const bb__walk_visitor gather_visitor = {on_line_begin, on_push, on_origin,
                                                on_line_end, surface_line_wanted};
static const bb__walk_visitor direct_visitor = {on_line_begin, NULL, on_origin,
                                                on_line_end, NULL};

/* The sweeps of a pass, in the order of its ray set's slices: every one
 * (parity -1), or those of even or odd rank (0, 1): the trace's halves. */
static bb_status run_pass(driver *d, pass_mode mode, int parity, bb_error *err) {
  bounce_ctx *ctx = &d->ctx;
  const bb__bounce_options *o = d->o;
  const bb_rayset *rs = d->fine;
  const int *order = d->order;
  if (mode == PASS_SURFACE && d->surface_set.slice_count)
    rs = &d->surface_set, order = d->surface_order;
  ctx->rs = rs;
  ctx->mode = mode;
  /* a sweep of the trace's slices finds the texels' horizons, at its bias */
  ctx->lift = mode == PASS_TEXEL || ctx->corner_hull ? o->bias : o->lift;
  const double *slopes = mode == PASS_TEXEL ? o->texel_slopes : o->surface_slopes;
  ctx->slopes = 0;
  ctx->chain = o->chain > 0 && o->chain < MAX_KNOWN ? o->chain : MAX_KNOWN;
  ctx->small_band = o->small_band;
  for (int k = 0; k < MAX_SLOPES && mode != PASS_DIRECT && !isnan(slopes[k]); k++)
    ctx->slope[ctx->slopes++] = slopes[k];
  bb_status st = BB_OK;
  if (mode == PASS_TEXEL) {
    const size_t n =
        (size_t)ctx->p->width * (size_t)ctx->p->height * (size_t)ctx->channels;
    memset(ctx->sums, 0, n * sizeof(float));
  } else {
    if (mode == PASS_SURFACE)
      st = bb__parallel_for(ctx->p->height, o->threads, zero_rows, d, NULL, NULL, err);
    const size_t lanes =
        (size_t)d->cols.count * (size_t)d->cols.samples * (size_t)ctx->channels;
    if (lanes)
      memset(d->cols.sums, 0, lanes * sizeof(float));
  }
  const bb__walk_visitor *visitor =
      mode == PASS_DIRECT ? &direct_visitor : &gather_visitor;
  const int work = mode == PASS_SURFACE ? surface_work(ctx->turns) : pass_work(mode);
  int swept = 0; /* slices so far */
  for (int k = 0, rank = 0; st == BB_OK && k < rs->slice_count; rank++) {
    const int s = order[k];
    const int pair = sweep_pairs(rs, order, k);
    k += pair ? 2 : 1;
    if (parity >= 0 && rank % 2 != parity)
      continue;
    const bb__sweep_dir along = {rs, s, NULL, NULL};
    const bb__sweep_dir opposite = {rs, pair ? order[k - 1] : 0, NULL, NULL};
    st = bb__sweep_lines_walked(ctx->p, rs->slice_step[2 * s], rs->slice_step[2 * s + 1],
                                &along, pair ? &opposite : NULL, ctx->lift, o->threads,
                                visitor, ctx, checkpoint_of(d), err);
    swept += pair ? 2 : 1;
    if (st == BB_OK && atomic_load(&ctx->out_of_memory))
      st = bb__fail(err, BB_ERR_MEMORY, "bounce: out of memory for a line");
    /* monotone over the whole: what the passes before this one did, and
     * this one's slices so far */
    const long done = o->progress_before + d->work_done + (long)swept * work;
    const long total = o->progress_before + d->work + o->progress_after;
    if (st == BB_OK && o->progress && o->progress(o->progress_user, done, total))
      st = bb__fail(err, BB_ERR_CANCELLED, "bounce: cancelled by the progress callback");
  }
  if (st == BB_ERR_CANCELLED)
    bb__fail(err, st, "bounce: cancelled by the progress callback");
  d->work_done += (long)swept * work;
  return st;
}

/* Bounces 0 starts from an estimate of each sample's converged light: as
 * though every surface it sees were as bright as itself, the light it
 * reflects is its first bounce times 1 / (1 - lambda), lambda = rho beta,
 * beta the part of its hemisphere (cosine-weighted) that the surface
 * blocks, 1 - E_ao / pi (held under 0.9). Lobes take the ao channel's
 * ratio: the surfaces seen are lit by the same lobe. */
static double estimate_gain(const driver *d, double rho, double e_ao) {
  if (d->o->bounces)
    return 1.0;
  double beta = 1.0 - e_ao / BB__PI;
  beta = beta < 0.0 ? 0.0 : (beta > 1.0 ? 1.0 : beta);
  double lambda = rho * beta;
  lambda = lambda < 0.9 ? lambda : 0.9;
  return 1.0 / (1.0 - lambda);
}

static double rho_at(const driver *d, size_t v) {
  return d->o->rho * (d->albedo ? (double)d->albedo[v] : 1.0);
}

/* After the direct pass: each corner's E from the sky (all of it, less
 * what its face's blocked vector integrals and its corrections took, added
 * up slice by slice in the pass's order from the horizons it kept), and
 * its radiance. */
static void direct_row(void *user, int y) {
  driver *d = user;
  const bounce_ctx *ctx = &d->ctx;
  const bb_rayset *rs = d->fine;
  const int channels = ctx->channels, W = ctx->p->width;
  exact_sum sum = 0;
  for (int x = 0; x < W; x++) {
    const size_t v = (size_t)y * (size_t)W + (size_t)x;
    const double rho = rho_at(d, v);
    double n[FACES][3];
    vertex_normals(ctx, x, y, n);
    float blocked[3 * MAX_CHANNELS] = {0}, corr[FACES * MAX_CHANNELS] = {0};
    for (int q = 0; q < d->direct_count; q++) {
      const int s = d->direct_seq[q];
      direct_corners(ctx, s, rs->slice_dir[2 * s], rs->slice_dir[2 * s + 1],
                     (const double(*)[3])n, ctx->corner_horizons[(size_t)q * ctx->texels + v],
                     blocked, corr);
    }
    for (int f = 0; f < FACES; f++) {
      const size_t out = corner_index(ctx->p, x, y, f, channels);
      double gain = 1.0;
      for (int k = 0; k < channels; k++) {
        const size_t i = (v * FACES + (size_t)f) * (size_t)channels + (size_t)k;
        double open[3];
        for (int j = 0; j < 3; j++)
          open[j] = ctx->vt->all[3 * k + j] - (double)blocked[3 * k + j];
        const double e = n[f][0] * open[0] + n[f][1] * open[1] + n[f][2] * open[2] -
                         (double)corr[f * channels + k];
        d->direct[i] = (float)(e > 0.0 ? e : 0.0);
        if (k == 0)
          gain = estimate_gain(d, rho, (double)d->direct[i]);
        if (out != SIZE_MAX) {
          d->radiance[out + (size_t)k] =
              (float)(rho / BB__PI * (double)d->direct[i] * gain);
          sum += fixed((double)d->radiance[out + (size_t)k]);
        }
      }
    }
  }
  d->row_sum[y] = sum;
}

/* The columns' loops run in chunks of this many columns on every thread
 * (steep relief has millions of samples: serial, they kept a cancel
 * waiting a second), each chunk's sum kept apart; the sums are integers,
 * so their total is the same in any order. */
enum { COLUMN_CHUNK = 4096 };
typedef struct columns_job {
  driver *d;
  int update;      /* columns_step_chunk: move the radiance rather than sum the change */
  exact_sum *sums; /* by chunk */
} columns_job;

static int column_chunks(const columns *c) {
  return (c->count + COLUMN_CHUNK - 1) / COLUMN_CHUNK;
}

/* One past the last column of a chunk. */
static int chunk_end(const columns *c, int chunk) {
  const int end = (chunk + 1) * COLUMN_CHUNK;
  return end < c->count ? end : c->count;
}

/* Runs fn over the columns' chunks, polling the checkpoint, and adds the
 * chunks' sums into *sum. */
static bb_status columns_run(driver *d, bb__work_fn fn, int update, exact_sum *sum,
                             bb_error *err) {
  const int chunks = column_chunks(&d->cols);
  if (chunks == 0)
    return BB_OK;
  columns_job job = {d, update, calloc((size_t)chunks, sizeof(exact_sum))};
  if (!job.sums)
    return bb__fail(err, BB_ERR_MEMORY, "bounce: out of memory for the columns");
  bb_status st =
      bb__parallel_for_checked(chunks, d->o->threads, fn, &job, checkpoint_of(d), err);
  for (int i = 0; i < chunks; i++)
    *sum += job.sums[i];
  free(job.sums);
  return st;
}

/* The same for the columns (the direct pass added what each sample's sky
 * loses). */
static void direct_columns_chunk(void *user, int chunk) {
  columns_job *job = user;
  driver *d = job->d;
  columns *c = &d->cols;
  const int channels = d->ctx.channels;
  const int last = chunk_end(c, chunk);
  exact_sum sum = 0;
  for (int n = chunk * COLUMN_CHUNK; n < last; n++) {
    const double *nv = c->normal + 3 * (size_t)n;
    const double rho = rho_at(d, (size_t)c->vertex[n]);
    for (int i = 0; i < c->samples; i++) {
      const size_t at = ((size_t)n * (size_t)c->samples + (size_t)i) * (size_t)channels;
      double gain = 1.0;
      for (int k = 0; k < channels; k++) {
        const double *all = d->vt.all + 3 * k;
        const double e = nv[0] * all[0] + nv[1] * all[1] + nv[2] * all[2] -
                         (double)c->sums[at + (size_t)k];
        c->direct[at + (size_t)k] = (float)(e > 0.0 ? e : 0.0);
        if (k == 0)
          gain = estimate_gain(d, rho, (double)c->direct[at]);
        c->radiance[at + (size_t)k] =
            (float)(rho / BB__PI * (double)c->direct[at + (size_t)k] * gain);
        sum += fixed((double)c->radiance[at + (size_t)k]);
      }
    }
  }
  job->sums[chunk] = sum;
}

/* After a surface pass: how far each sample's radiance would move, summed
 * per row; then the move, and with it, when the bounces stop here, the
 * rest of the series estimated as geometric. */
static double sample_radiance(double rho, float direct, float gathered) {
  const double e = (double)direct + (double)gathered;
  return rho / BB__PI * (e > 0.0 ? e : 0.0);
}

static void change_row(void *user, int y) {
  driver *d = user;
  const int channels = d->ctx.channels;
  const size_t W = (size_t)d->ctx.p->width;
  exact_sum sum = 0;
  for (size_t x = 0; x < W; x++) {
    const size_t v = (size_t)y * W + x;
    const double rho = rho_at(d, v);
    for (int f = 0; f < FACES; f++) {
      const size_t out = corner_index(d->ctx.p, (long)x, y, f, channels);
      if (out == SIZE_MAX)
        continue;
      for (int k = 0; k < channels; k++) {
        const size_t i = (v * FACES + (size_t)f) * (size_t)channels + (size_t)k;
        sum +=
            fixed(fabs((double)(float)sample_radiance(rho, d->direct[i], d->ctx.sums[i]) -
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
    const double rho = rho_at(d, v);
    for (int f = 0; f < FACES; f++) {
      const size_t out = corner_index(d->ctx.p, (long)x, y, f, channels);
      if (out == SIZE_MAX)
        continue;
      for (int k = 0; k < channels; k++) {
        const size_t i = (v * FACES + (size_t)f) * (size_t)channels + (size_t)k;
        const double r = sample_radiance(rho, d->direct[i], d->ctx.sums[i]);
        d->radiance[out + (size_t)k] =
            (float)(r + d->tail * (r - (double)d->radiance[out + (size_t)k]));
      }
    }
  }
}

/* The columns' move (update 0) or their update (1). */
static void columns_step_chunk(void *user, int chunk) {
  columns_job *job = user;
  driver *d = job->d;
  columns *c = &d->cols;
  const size_t per_column = (size_t)c->samples * (size_t)d->ctx.channels;
  const int last = chunk_end(c, chunk);
  exact_sum sum = 0;
  for (int n = chunk * COLUMN_CHUNK; n < last; n++) {
    const double rho = rho_at(d, (size_t)c->vertex[n]);
    for (size_t i = (size_t)n * per_column; i < (size_t)(n + 1) * per_column; i++) {
      const double r = sample_radiance(rho, c->direct[i], c->sums[i]);
      if (job->update)
        c->radiance[i] = (float)(r + d->tail * (r - (double)c->radiance[i]));
      else
        sum += fixed(fabs((double)(float)r - (double)c->radiance[i]));
    }
  }
  job->sums[chunk] = sum;
}

/* Clamp mode: the last column and row of cells reach vertices past the
 * image (the border extruded), which no vertex's slots fill. Such a cell
 * is flat along the extrusion, its two triangles in one plane, so a
 * corner out there takes the value of the corner inside it was extruded
 * from, on either triangle. */
static void corner_fixup(driver *d) {
  const bb_pyramid *p = d->ctx.p;
  if (p->addressing == BB_ADDRESS_PERIODIC)
    return;
  const size_t C = (size_t)d->ctx.channels, W = (size_t)p->width, H = (size_t)p->height;
  float *r = d->radiance;
#define CORNER(cell, half, corner)                                                       \
  (r + (((cell)*2 + (size_t)(half)) * 3 + (size_t)(corner)) * C)
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
      if (half || corner)
        COPY(CORNER(last, half, corner), CORNER(last, 0, 0));
#undef COPY
#undef CORNER
}

typedef struct finish_job {
  const driver *d;
  bb_image *vis;
  float *added; /* when set: the light added, channels per texel, written here
                   rather than added to vis */
} finish_job;

/* When the passes were the trace too: each texel's losses added up from
 * its stored horizons, slice by slice in the order every trace adds them
 * (bb_trace_slice_order), with the trace's own integration, so the sums,
 * once finished, are bb__trace_occlusion's visibility bit for bit. */
static void trace_row(void *user, int y) {
  const finish_job *job = user;
  const driver *d = job->d;
  const bb_rayset *rs = d->fine;
  const int channels = d->ctx.channels, W = job->vis->width, n = rs->slice_count;
  for (int x = 0; x < W; x++) {
    const size_t v = (size_t)y * (size_t)W + (size_t)x;
    float *sums = job->vis->pixels + v * (size_t)channels;
    const float *h = d->ctx.horizons + v;
    for (int k = 0; k < channels; k++)
      sums[k] = 0.0f;
    for (int k = 0; k < n; k++) {
      const bb__slice_integral si = bb__slice_integral_of(rs, d->order[k]);
      bb__slice_accumulate(&si, h[(size_t)d->order[k] * d->ctx.texels], sums);
    }
  }
}

static void finish_row(void *user, int y) {
  const finish_job *job = user;
  const bounce_ctx *ctx = &job->d->ctx;
  const bb_rayset *rs = job->d->fine;
  const int channels = ctx->channels, W = job->vis->width;
  for (int x = 0; x < W; x++) {
    const size_t v = (size_t)y * (size_t)W + (size_t)x;
    float *out = job->vis->pixels + v * (size_t)job->vis->channels;
    const float *sum = ctx->sums + v * (size_t)channels;
    /* the slices it did not gather in see what those it gathered in saw,
     * per unit of their bands' weights */
    double scale[2] = {1.0, 1.0};
    if (ctx->fill) {
      const float *w = ctx->fill + v;
      const size_t plane = ctx->texels;
      for (size_t i = 0; i < 2; i++)
        if (w[i * plane] > 0.0f)
          scale[i] += (double)w[(2 + i) * plane] / (double)w[i * plane];
    }
    if (job->added) {
      float *a = job->added + v * (size_t)channels;
      a[0] = (float)((double)sum[0] * scale[0] / BB__PI);
      for (int k = 1; k < channels; k++)
        a[k] = (float)((double)sum[k] * scale[1] / rs->total[k]);
      continue;
    }
    const double ao = (double)out[0] + (double)sum[0] * scale[0] / BB__PI;
    out[0] = (float)(ao < 1.0 ? ao : 1.0);
    for (int k = 1; k < channels; k++)
      out[k] = (float)((double)out[k] + (double)sum[k] * scale[1] / rs->total[k]);
  }
}

void bb__bounce_options_init(bb__bounce_options *o) {
  memset(o, 0, sizeof *o);
  o->estimate_passes = 1;
  o->lift = 0.1;
  o->steep = 2.0;
  o->small_band = 0.25;
  o->column_samples = 5;
  o->surface_turns = 1;
  static const double texel[] = {0.0, 1.0};
  static const double surface[] = {-1.0, 0.0};
  for (int k = 0; k < BB__BOUNCE_MAX_SLOPES; k++) {
    o->texel_slopes[k] = k < (int)(sizeof texel / sizeof texel[0]) ? texel[k] : NAN;
    o->surface_slopes[k] =
        k < (int)(sizeof surface / sizeof surface[0]) ? surface[k] : NAN;
  }
}

/* A ray set of `slices` slices for a pass (none when it is the trace's),
 * with the order its sweeps take. */
static bb_status pass_set(const bb_rayset *rs, int slices, int threads, bb_rayset *out,
                          int **order, bb_error *err) {
  if (slices >= rs->slice_count)
    return BB_OK;
  bb_basis basis = {.count = rs->basis_count, .name = "bounce"};
  memcpy(basis.vector, rs->basis, sizeof basis.vector);
  bb_status st = bb__rayset_make(slices, rs->power, &basis, threads, out, err);
  *order = st == BB_OK ? malloc((size_t)slices * sizeof(int)) : NULL;
  if (st == BB_OK && (!*order || bb_trace_slice_order(out, *order, NULL) != BB_OK))
    st = bb__fail(err, BB_ERR_MEMORY, "bounce: out of memory");
  return st;
}

/* The bounce on the map's own level: added to vis, or with `added` set,
 * written there (channels per texel) and vis left as it was (or, when the
 * passes are the trace too, made: the trace's visibility). */
static bb_status add_on_level(const bb_pyramid *p, const bb_rayset *rs,
                              const bb__bounce_options *o, bb_image *vis, float *added,
                              int *bounces_done, bb_error *err) {
  if (bounces_done)
    *bounces_done = 0;
  const int traced = vis && !vis->pixels; /* the passes are the trace too */
  if (!p || !rs || !o || !vis ||
      (!traced && (vis->width != p->width || vis->height != p->height ||
                   vis->channels != 1 + rs->basis_count)))
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "bounce: the visibility does not match the pyramid");
  if (o->albedo && (o->albedo->width != p->width || o->albedo->height != p->height ||
                    o->albedo->channels != 1))
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "bounce: the albedo map does not match the height");
  const int channels = 1 + rs->basis_count, threads = bb__thread_count(o->threads);
  const int split = split_slices(rs);
  const size_t texels = (size_t)p->width * (size_t)p->height;
  const size_t corners = texels * FACES * (size_t)channels;
  driver d = {.o = o,
              .albedo = o->albedo ? o->albedo->pixels : NULL,
              .checkpoint = {o->progress, o->progress_user}};
  bounce_ctx *ctx = &d.ctx;
  ctx->p = p, ctx->rs = rs, ctx->vt = &d.vt, ctx->channels = channels,
  ctx->cols = &d.cols, ctx->texels = texels;
  ctx->corner_lift = o->lift;
  ctx->turns = surface_turns(rs, o);
  atomic_init(&ctx->out_of_memory, 0);
  int *order = malloc((size_t)rs->slice_count * sizeof(int));
  double *sector = malloc((size_t)rs->slice_count * 2 * sizeof(double));
  unsigned char *wanted = malloc((size_t)rs->slice_count);
  const size_t normal_floats = ((size_t)p->width + 1) * ((size_t)p->height + 1) * 6;
  d.normals = malloc(normal_floats * sizeof(float));
  ctx->sums = malloc(corners * sizeof(float));
  d.direct_seq = malloc((size_t)rs->slice_count * sizeof(int));
  d.corner_plane = malloc((size_t)rs->slice_count * sizeof(int));
  d.direct = malloc(corners * sizeof(float));
  d.radiance = malloc(corners * sizeof(float));
  d.row_sum = malloc((size_t)p->height * sizeof *d.row_sum);
  if (traced)
    ctx->horizons = malloc(texels * (size_t)rs->slice_count * sizeof(float));
  if (split)
    ctx->fill = calloc(texels * 4, sizeof(float));
  ctx->slot_count = threads < 256 ? threads : 256;
  ctx->slots = calloc((size_t)ctx->slot_count, sizeof(scratch));
  bb_status st = BB_OK;
  if (!order || !sector || !wanted || !d.normals || !ctx->sums || !d.direct_seq ||
      !d.corner_plane || !d.direct || !d.radiance || !d.row_sum || !ctx->slots ||
      (traced && !ctx->horizons) || (split && !ctx->fill) ||
      bb_trace_slice_order(rs, order, NULL) != BB_OK)
    st = bb__fail(err, BB_ERR_MEMORY, "bounce: out of memory (%zu corners)",
                  corners / (size_t)channels);
  if (st == BB_OK) {
    d.direct_count =
        pass_sequence(rs, order, split ? 0 : -1, d.direct_seq, d.corner_plane);
    ctx->corner_plane = d.corner_plane;
    ctx->corner_horizons = malloc(texels * (size_t)d.direct_count * sizeof(float));
    if (!ctx->corner_horizons)
      st = bb__fail(err, BB_ERR_MEMORY, "bounce: out of memory (%zu corners)",
                    corners / (size_t)channels);
  }
  ctx->normals = d.normals;
  /* every step after the allocations polls the caller's progress */
  const bb__checkpoint *checkpoint = checkpoint_of(&d);
  d.order = order;
  d.fine = rs;
  d.work = bb__bounce_work(rs, o);
  if (st == BB_OK)
    st = pass_set(rs, slice_set(rs, o->surface_slices, 4) * surface_turns(rs, o), o->threads,
                  &d.surface_set, &d.surface_order, err);
  if (st == BB_OK &&
      columns_build(p, o->steep, o->column_samples, o->lift, channels, &d.cols))
    st = bb__fail(err, BB_ERR_MEMORY, "bounce: out of memory for the columns");
  for (int i = 0; st == BB_OK && i < ctx->slot_count; i++)
    atomic_flag_clear(&ctx->slots[i].busy);
  if (st == BB_OK) {
    normals_job nj = {p, d.normals};
    st = bb__parallel_for_checked(p->height + 1, o->threads, normals_row, &nj, checkpoint, err);
  }
  /* The direct light: over the trace's sweeps of even rank (they find the
   * texels' horizons too), the corners asking their hulls at their lift;
   * or, with fewer than 4 slices, a pass of its own over all of them */
  if (split)
    direct_sectors(rs, order, sector, wanted);
  if (st == BB_OK)
    st = vtables_build(rs, split ? sector : NULL, split ? wanted : NULL, o->threads,
                       &d.vt, err);
  ctx->corner_hull = split;
  if (st == BB_OK)
    st = run_pass(&d, PASS_DIRECT, split ? 0 : -1, err);
  ctx->corner_hull = 0;
  if (st == BB_OK)
    st = bb__parallel_for_checked(p->height, o->threads, direct_row, &d, checkpoint, err);
  exact_sum last_sum = 0;
  if (st == BB_OK) {
    corner_fixup(&d);
    for (int y = 0; y < p->height; y++)
      last_sum += d.row_sum[y];
    st = columns_run(&d, direct_columns_chunk, 0, &last_sum, err);
  }
  ctx->radiance = d.radiance;
  /* The bounces: each pass adds what the samples gather of the last one.
   * bounces N: N - 1 passes from the first bounce. bounces 0: the passes
   * from the estimate; the terms left are then about the last move times
   * lambda / (1 - lambda), lambda the ratio of the last two moves summed
   * over every sample (the series of bounces is close to geometric), and
   * that is added. */
  float *horizons = ctx->horizons;
  ctx->horizons = NULL; /* the surface passes' slices are their own */
  int done = 1;
  const int passes = surface_passes(o);
  for (int pass = 0; st == BB_OK && pass < passes; pass++) {
    st = run_pass(&d, PASS_SURFACE, -1, err);
    if (st == BB_OK)
      st = bb__parallel_for_checked(p->height, o->threads, change_row, &d, checkpoint, err);
    exact_sum sum = 0;
    if (st == BB_OK)
      st = columns_run(&d, columns_step_chunk, 0, &sum, err);
    if (st != BB_OK)
      break;
    for (int y = 0; y < p->height; y++)
      sum += d.row_sum[y];
    d.tail = 0.0;
    if (o->bounces == 0 && pass == passes - 1 && last_sum > 0) {
      double lambda = (double)sum / (double)last_sum;
      lambda = lambda < 0.9 ? lambda : 0.9;
      d.tail = lambda / (1.0 - lambda);
    }
    last_sum = sum;
    st = bb__parallel_for_checked(p->height, o->threads, update_row, &d, checkpoint, err);
    if (st == BB_OK)
      st = columns_run(&d, columns_step_chunk, 1, &(exact_sum){0}, err);
    if (st == BB_OK)
      corner_fixup(&d);
    done++;
  }
  ctx->horizons = horizons;
  /* the texels' gathers, over the trace's sweeps of odd rank (or all) */
  if (st == BB_OK)
    st = run_pass(&d, PASS_TEXEL, split ? 1 : -1, err);
  finish_job fj = {&d, vis, added};
  if (st == BB_OK && traced) {
    st = bb_image_alloc(vis, p->width, p->height, channels, err);
    if (st == BB_OK)
      st = bb__parallel_for_checked(p->height, o->threads, trace_row, &fj, checkpoint, err);
    if (st == BB_OK)
      st = bb_trace_finish(rs, vis, o->threads, err);
  }
  if (st == BB_OK)
    st = bb__parallel_for_checked(p->height, o->threads, finish_row, &fj, checkpoint, err);
  if (st != BB_OK && traced)
    bb_image_free(vis);
  if (st == BB_OK && bounces_done)
    *bounces_done = done;
  for (int i = 0; ctx->slots && i < ctx->slot_count; i++)
    scratch_release(&ctx->slots[i]);
  free(ctx->slots);
  vtables_free(&d.vt);
  columns_free(&d.cols);
  free(order);
  free(sector);
  free(wanted);
  free(d.normals);
  free(ctx->sums);
  free(ctx->corner_horizons);
  free(d.direct_seq);
  free(d.corner_plane);
  free(ctx->horizons);
  free(ctx->fill);
  free(d.direct);
  free(d.radiance);
  free(d.row_sum);
  bb__rayset_release(&d.surface_set);
  free(d.surface_order);
  return st;
}

/* ------------------------------------------------------ the coarse level */

/* A map LEVEL_FROM texels or more on its longer side has its bounce
 * computed on a height field coarser by a power of 2 (2, then more while
 * its longer side would pass LEVEL_SIDE), and the light it adds lifted to
 * the map's texels: bounced light is smooth, the bounce's cost is then a
 * quarter (or less) of the map's own, and the trace stays the map's. */
enum { LEVEL_FROM = 512, LEVEL_SIDE = 1024, LEVEL_MAX = 8 };
#define LIFT_GAIN 4.0 /* the most a lift multiplies the coarse level's added light by */

int bb__bounce_level(const bb__bounce_options *o, int width, int height,
                     bb_addressing addressing) {
  int f = o->level > 0 ? o->level : 1;
  if (o->level == 0) {
    const int side = width > height ? width : height;
    if (side >= LEVEL_FROM)
      f = 2;
    while (f > 1 && f < LEVEL_MAX && side / f > LEVEL_SIDE)
      f *= 2;
  }
  /* periodic: the coarse lattice must tile the map */
  while (f > 1 && addressing == BB_ADDRESS_PERIODIC && (width % f || height % f))
    f /= 2;
  while (f > 1 && (width / f < 2 || height / f < 2))
    f /= 2;
  return f;
}

/* The coarse level's size along a side of n texels (vertices). */
static int coarse_side(int n, int f, bb_addressing addressing) {
  return addressing == BB_ADDRESS_PERIODIC ? n / f : (n - 1 + f - 1) / f + 1;
}

/* The coarse level of a map's field: vertex (i, j) is the map's vertex
 * (f i, f j) (clamp: the last past the image is its last), times unit
 * (1 / f for heights in texels). Taken, not filtered: a wall one texel
 * wide stays a wall one (coarse) texel wide, where a filter made it a
 * slope lit from above (on the profiles of docs/accuracy.md, a tent filter
 * was 1.5 to 4 times further from the exact added light). */
static bb_status decimate(const float *in, int width, int height, int f,
                          bb_addressing addressing, double unit, bb_image *out,
                          bb_error *err) {
  bb_status st = bb_image_alloc(out, coarse_side(width, f, addressing),
                                coarse_side(height, f, addressing), 1, err);
  for (int j = 0; st == BB_OK && j < out->height; j++) {
    const long y = (long)j * f < height ? (long)j * f : height - 1;
    for (int i = 0; i < out->width; i++) {
      const long x = (long)i * f < width ? (long)i * f : width - 1;
      out->pixels[(size_t)j * (size_t)out->width + (size_t)i] =
          (float)((double)in[(size_t)y * (size_t)width + (size_t)x] * unit);
    }
  }
  return st;
}

typedef struct lift_job {
  const float *added;   /* the coarse level's added light, channels per texel */
  const float *visible; /* and its visibility before it */
  int cw, ch, f, channels;
  bb_addressing addressing;
  bb_image *vis;
} lift_job;

/* Row y of the map: texel x is at (x / f, y / f) of the coarse level. The
 * light added there per unit of blocked visibility (1 - vis, per channel),
 * bilinear in both between the four nearest coarse texels, times the
 * texel's own blocked visibility: the radiance of what is seen comes from
 * the coarse level, how much of the sky the surface hides from the map's
 * trace, so a texel open to the sky gets nothing beside a deep coarse one.
 * Added to vis as finish_row adds it (ao capped at 1). */
static void lift_row(void *user, int y) {
  const lift_job *job = user;
  const int f = job->f, C = job->channels;
  const int j0 = y / f;
  const double ty = (double)(y - j0 * f) / f;
  const int j1 = job->addressing == BB_ADDRESS_PERIODIC ? (j0 + 1) % job->ch
                                                        : (j0 + 1 < job->ch ? j0 + 1 : j0);
  for (int x = 0; x < job->vis->width; x++) {
    const int i0 = x / f;
    const double tx = (double)(x - i0 * f) / f;
    const int i1 = job->addressing == BB_ADDRESS_PERIODIC ? (i0 + 1) % job->cw
                                                          : (i0 + 1 < job->cw ? i0 + 1 : i0);
    const size_t at[4] = {(size_t)j0 * (size_t)job->cw + (size_t)i0,
                          (size_t)j0 * (size_t)job->cw + (size_t)i1,
                          (size_t)j1 * (size_t)job->cw + (size_t)i0,
                          (size_t)j1 * (size_t)job->cw + (size_t)i1};
    const double w[4] = {(1.0 - ty) * (1.0 - tx), (1.0 - ty) * tx, ty * (1.0 - tx), ty * tx};
    float *out = job->vis->pixels + ((size_t)y * (size_t)job->vis->width + (size_t)x) * (size_t)C;
    for (int k = 0; k < C; k++) {
      double added = 0.0, blocked = 0.0;
      for (int i = 0; i < 4; i++) {
        const double b = 1.0 - (double)job->visible[at[i] * (size_t)C + (size_t)k];
        added += w[i] * (double)job->added[at[i] * (size_t)C + (size_t)k];
        blocked += w[i] * (b > 0.0 ? b : 0.0);
      }
      const double own = 1.0 - (double)out[k];
      /* where the coarse level is far more open than the texel, its ratio
       * is of almost nothing: the texel gets at most LIFT_GAIN times the
       * coarse level's added light */
      const double floor = own / LIFT_GAIN;
      const double v = (double)out[k] +
                       (own > 0.0 ? own * added / (blocked > floor ? blocked : floor) : 0.0);
      out[k] = (float)(k == 0 && v > 1.0 ? 1.0 : v);
    }
  }
}

/* The coarse run's progress, as a part of the whole: its passes count
 * bb__bounce_work of the options the caller planned with. */
typedef struct coarse_progress {
  const bb__bounce_options *o;
  long work; /* the caller's bb__bounce_work */
} coarse_progress;

static int coarse_progress_of(void *user, long done, long total) {
  const coarse_progress *c = user;
  if (total <= 0) /* a checkpoint */
    return c->o->progress(c->o->progress_user, done, total);
  const long part = (long)((double)c->work * (double)done / (double)total);
  return c->o->progress(c->o->progress_user, c->o->progress_before + part,
                        c->o->progress_before + c->work + c->o->progress_after);
}

static bb_status add_coarse(const bb_pyramid *p, const bb_rayset *rs,
                            const bb__bounce_options *o, int f, bb_image *vis,
                            int *bounces_done, bb_error *err) {
  const int channels = 1 + rs->basis_count;
  bb_image z = {0}, albedo = {0}, coarse_vis = {0};
  bb_pyramid *coarse = NULL;
  float *added = NULL;
  bb_status st = decimate(p->z, p->width, p->height, f, p->addressing, 1.0 / f, &z, err);
  if (st == BB_OK && o->albedo)
    st = decimate(o->albedo->pixels, p->width, p->height, f, p->addressing, 1.0, &albedo, err);
  if (st == BB_OK)
    st = bb__pyramid_build(&z, p->addressing, o->threads, &coarse, err);
  if (st == BB_OK) {
    added = malloc((size_t)z.width * (size_t)z.height * (size_t)channels * sizeof(float));
    if (!added)
      st = bb__fail(err, BB_ERR_MEMORY, "bounce: out of memory for the coarse level");
  }
  bb__bounce_options co = *o;
  co.level = 1;
  co.albedo = albedo.pixels ? &albedo : NULL;
  co.bias = o->bias / f; /* the same lift, in the coarse level's texels */
  coarse_progress cp = {o, bb__bounce_work(rs, o)};
  if (o->progress) {
    co.progress = coarse_progress_of, co.progress_user = &cp;
    co.progress_before = co.progress_after = 0;
  }
  if (st == BB_OK)
    st = add_on_level(coarse, rs, &co, &coarse_vis, added, bounces_done, err);
  if (st == BB_OK) {
    lift_job job = {added, coarse_vis.pixels, z.width, z.height, f, channels, p->addressing, vis};
    st = bb__parallel_for(p->height, o->threads, lift_row, &job, NULL, NULL, err);
  }
  free(added);
  bb_image_free(&coarse_vis);
  bb_pyramid_free(coarse);
  bb_image_free(&albedo);
  bb_image_free(&z);
  return st;
}

bb_status bb__bounce_add(const bb_pyramid *p, const bb_rayset *rs,
                         const bb__bounce_options *o, bb_image *vis, int *bounces_done,
                         bb_error *err) {
  const int traced = vis && !vis->pixels;
  const int f = p && o && !traced ? bb__bounce_level(o, p->width, p->height, p->addressing) : 1;
  if (f > 1 && rs && vis->width == p->width && vis->height == p->height &&
      vis->channels == 1 + rs->basis_count &&
      (!o->albedo || (o->albedo->width == p->width && o->albedo->height == p->height &&
                      o->albedo->channels == 1)))
    return add_coarse(p, rs, o, f, vis, bounces_done, err);
  return add_on_level(p, rs, o, vis, NULL, bounces_done, err);
}
