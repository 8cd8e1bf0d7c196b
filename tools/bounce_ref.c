/* bounce_ref.c: an independent reference for the bake's inter-reflection, a
 * Monte Carlo path tracer over the bake's surface model, and how far given
 * bakes are from it.
 *
 *   bounce_ref trace MAP SCALE -o REF.exr [--rho R] [--albedo FILE]
 *                    [--bounces N] [--paths N] [--stride K] [--bias B]
 *                    [--power P] [--basis NAME] [--clamp] [--seed S]
 *                    [--threads T]
 *   bounce_ref compare REF.exr MAP SCALE [--normal-filter NAME]
 *                    NAME=AO.exr,SSBUMP.exr ...
 *
 * trace: at every K-th texel of every K-th row (default 8) of MAP (read as a
 * bake reads it, no smoothing, heights times SCALE, periodic or --clamp), it
 * estimates what docs/conventions.md "Inter-reflection" defines:
 *
 *   ao'    = 1/pi  integral_H L_ao(w) w.z dw
 *   vis_c' = 1/T_c integral_H L_c(w) dw,   T_c = integral_H max(0, w.B_c)^P dw
 *
 * where L_k(w) is the radiance arriving from w at the texel's origin (x, y,
 * z + bias): the sky's (ao: 1; lobe c: max(0, w.B_c)^P) where the ray
 * escapes, else what the surface it hits reflects. The surface is the
 * bake's: two triangles per cell split along (x+1, y)-(x, y+1), each
 * Lambertian with its own plane normal and albedo rho (or rho times the
 * albedo map, interpolated over the triangle from its vertices), lit by the
 * same sky and by the rest of the surface. Paths: primary directions
 * uniform over H, stratified; at each hit one cosine-weighted direction
 * about the triangle's normal, the throughput multiplied by the albedo
 * there, up to N bounces (default 0: until the throughput is under 1e-6, so
 * what is left out is under 1e-6). One path serves every channel.
 *
 * It shares nothing with the bake's integration: rays meet the triangles in
 * a cell walk of its own (a 2D DDA, the height along the ray piecewise
 * linear over each cell's two triangles, blocks of 8 x 8 cells skipped
 * where the ray passes above their highest vertex), and T_c is its own
 * quadrature. Every texel has its own random sequence (seeded from --seed,
 * x and y), so the result is the same on any thread count.
 *
 * Sampling error: each texel's paths are 16 independent batches of m x m
 * stratified primary directions (paths rounded to 16 m^2); the standard
 * error of a texel's value is the spread of its batch means over sqrt(16),
 * and that of the mean over the texels sqrt(sum of squares) / texels. REF
 * is a float EXR of ceil(W / K) x ceil(H / K) texels holding 2 (1 + lobes)
 * channels: ao', vis_0', ... then the standard error of each; its
 * description records the parameters. One JSON line on stdout, a human
 * summary on stderr.
 *
 * compare: for each NAME=AO.exr,SSBUMP.exr (float images of MAP's size,
 * baked from MAP at SCALE with the reference's parameters), prints the
 * signed mean (bias) and mean |difference| from the reference over the
 * reference's texels, for ao and each ssbump channel: the reference's
 * ssbump is min(1, max(0, N.B_c) vis_c') with N the bake's normal of MAP
 * (Valve's by default, --normal-filter to match another bake), and its ao
 * min(1, ao'). Also prints the reference's own standard errors, in the same
 * units. Exits 1 when a file cannot be read or does not match, 2 on a bad
 * command line.
 */
#include "job/job_internal.h"
#include "bumpbake.h"
#include "core/internal.h"
#include "bake/bake_internal.h"
#include "files/provenance.h"
#include "image/image_write.h"
#include "trace/basis.h"
#include "core/json.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define BATCHES 16
#define BLOCK 8 /* cells per side of a skip block */
#define MAX_LOBES BB_MAX_BASIS
#define MAX_CHANNELS (1 + MAX_LOBES)
#define DEFAULT_PATHS 4096
#define CONVERGED_THROUGHPUT 1e-6
#define MAX_DEPTH 100000

/* ------------------------------------------------------------ arguments */

#define MAX_TEXELS 64

typedef struct args {
  const char *map, *out, *albedo_path;
  int texels, texel_x[MAX_TEXELS], texel_y[MAX_TEXELS]; /* --texel: these only */
  double scale, rho, bias, power;
  int bounces, paths, stride, threads;
  unsigned long long seed;
  bb_addressing addressing;
  bb_basis basis;
} args;

static int usage(const char *reason) {
  fprintf(stderr,
          "bounce_ref: %s\n"
          "usage: bounce_ref trace MAP SCALE -o REF.exr [--rho R] [--albedo FILE] [--bounces N]\n"
          "                  [--paths N] [--stride K] [--bias B] [--power P] [--basis NAME]\n"
          "                  [--clamp] [--seed S] [--threads T]\n"
          "       bounce_ref compare REF.exr MAP SCALE [--normal-filter NAME] "
          "NAME=AO.exr,SSBUMP.exr ...\n",
          reason);
  return 2;
}

static int parse_number(const char *s, double lo, double hi, double *out) {
  char *end;
  errno = 0;
  const double v = strtod(s, &end);
  if (errno || end == s || *end || !isfinite(v) || v < lo || v > hi) return 1;
  *out = v;
  return 0;
}

static int parse_trace_args(int argc, char **argv, args *a) {
  if (argc < 4) return usage("trace needs MAP and SCALE");
  memset(a, 0, sizeof *a);
  a->map = argv[2];
  a->rho = 0.5, a->bias = 0.55, a->power = 1.0;
  a->paths = DEFAULT_PATHS, a->stride = 8, a->seed = 1;
  bb__basis_init(&a->basis);
  if (parse_number(argv[3], 1e-9, 1e30, &a->scale)) return usage("SCALE must be > 0");
  for (int i = 4; i < argc; i++) {
    const char *o = argv[i];
    if (!strcmp(o, "--clamp")) {
      a->addressing = BB_ADDRESS_CLAMP;
      continue;
    }
    if (i + 1 >= argc) return usage("an option lacks its value");
    const char *v = argv[++i];
    double x;
    if (!strcmp(o, "-o")) a->out = v;
    else if (!strcmp(o, "--texel")) {
      char *end;
      const long tx = strtol(v, &end, 10);
      const long y = *end == ',' ? strtol(end + 1, &end, 10) : -1;
      if (*end || tx < 0 || y < 0 || tx > 65535 || y > 65535 || a->texels == MAX_TEXELS)
        return usage("--texel takes X,Y (at most 64 of them)");
      a->texel_x[a->texels] = (int)tx, a->texel_y[a->texels++] = (int)y;
    }
    else if (!strcmp(o, "--albedo")) a->albedo_path = v;
    else if (!strcmp(o, "--basis")) {
      bb_error err;
      if (bb__basis_parse(v, &a->basis, &err) != BB_OK) return usage(err.message);
    } else if (parse_number(v, 0.0, 1e12, &x)) return usage("bad option value");
    else if (!strcmp(o, "--rho") && x <= 1.0) a->rho = x;
    else if (!strcmp(o, "--bias")) a->bias = x;
    else if (!strcmp(o, "--power") && x >= 1.0) a->power = x;
    else if (!strcmp(o, "--bounces") && x <= 1e6) a->bounces = (int)x;
    else if (!strcmp(o, "--paths") && x >= BATCHES && x <= 1e9) a->paths = (int)x;
    else if (!strcmp(o, "--stride") && x >= 1 && x <= 65536) a->stride = (int)x;
    else if (!strcmp(o, "--threads") && x <= BB_MAX_THREADS) a->threads = (int)x;
    else if (!strcmp(o, "--seed")) a->seed = (unsigned long long)x;
    else return usage("unknown option or value out of range");
  }
  if (!a->out && !a->texels) return usage("trace needs -o REF.exr or --texel X,Y");
  /* 16 batches of m x m strata */
  const int m = (int)lround(sqrt((double)a->paths / BATCHES));
  a->paths = BATCHES * (m < 1 ? 1 : m) * (m < 1 ? 1 : m);
  return 0;
}

/* ------------------------------------------------------------ random */

static uint64_t splitmix64(uint64_t *state) {
  uint64_t z = (*state += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

/* xoshiro256**, seeded through splitmix64 */
typedef struct rng {
  uint64_t s[4];
} rng;

static void rng_seed(rng *r, uint64_t seed, uint64_t a, uint64_t b, uint64_t c) {
  uint64_t state = seed;
  state ^= splitmix64(&state) ^ a * 0x632be59bd9b4e019ULL;
  state ^= splitmix64(&state) ^ b * 0x85157af5ULL;
  state ^= splitmix64(&state) ^ c * 0x9e3779b97f4a7c15ULL;
  for (int i = 0; i < 4; i++) r->s[i] = splitmix64(&state);
}

static inline uint64_t rotl(uint64_t x, int k) {
  return (x << k) | (x >> (64 - k));
}

static inline double rng_next(rng *r) {
  uint64_t *s = r->s;
  const uint64_t result = rotl(s[1] * 5, 7) * 9, t = s[1] << 17;
  s[2] ^= s[0];
  s[3] ^= s[1];
  s[1] ^= s[2];
  s[0] ^= s[3];
  s[2] ^= t;
  s[3] = rotl(s[3], 45);
  return (double)(result >> 11) * 0x1.0p-53; /* [0, 1) */
}

/* ------------------------------------------------------------ surface */

typedef struct surface {
  int w, h;
  bb_addressing addressing;
  const float *z;      /* heights in texels */
  const float *albedo; /* per vertex, in [0, 1], or NULL */
  double rho;
  double zmax;
  int bw, bh;          /* skip blocks per row and column (periodic, inside) */
  float *block_max;    /* highest vertex of each block's cells */
  double epsilon;      /* lift of a bounce's origin off its triangle */
} surface;

static inline int wrap(long i, int n) {
  long r = i % n;
  return (int)(r < 0 ? r + n : r);
}

static inline long clampl(long i, long lo, long hi) {
  return i < lo ? lo : (i > hi ? hi : i);
}

static inline size_t vertex_index(const surface *s, long x, long y) {
  if (s->addressing == BB_ADDRESS_PERIODIC)
    return (size_t)wrap(y, s->h) * (size_t)s->w + (size_t)wrap(x, s->w);
  return (size_t)clampl(y, 0, s->h - 1) * (size_t)s->w + (size_t)clampl(x, 0, s->w - 1);
}

static inline double vz(const surface *s, long x, long y) {
  return (double)s->z[vertex_index(s, x, y)];
}

static int surface_blocks(surface *s) {
  s->bw = (s->w + BLOCK - 1) / BLOCK;
  s->bh = (s->h + BLOCK - 1) / BLOCK;
  s->block_max = malloc((size_t)s->bw * (size_t)s->bh * sizeof(float));
  if (!s->block_max) return 1;
  for (int by = 0; by < s->bh; by++)
    for (int bx = 0; bx < s->bw; bx++) {
      float m = -INFINITY;
      /* the cells of the block and the vertices at their far sides */
      for (int y = by * BLOCK; y <= (by + 1) * BLOCK && y <= s->h; y++)
        for (int x = bx * BLOCK; x <= (bx + 1) * BLOCK && x <= s->w; x++) {
          const float v = s->z[vertex_index(s, x, y)];
          m = v > m ? v : m;
        }
      s->block_max[by * s->bw + bx] = m;
    }
  return 0;
}

/* What a ray met: the point, the triangle (cell and half) and its unit
 * normal, and the albedo there. */
typedef struct hit {
  double p[3], n[3];
  double albedo;
} hit;

/* The cell along an axis entered by a point at v moving with sign s. */
static inline long cell_along(double v, int s) {
  return s > 0 ? (long)floor(v) : -(long)floor(-v) - 1;
}

/* The height of the surface over cell (cx, cy) at local (fx, fy). */
typedef struct cell {
  double z00, z10, z01, z11;
} cell;

static inline double cell_height(const cell *c, double fx, double fy, int upper) {
  return upper ? c->z10 + (c->z11 - c->z10) * fy + (c->z01 - c->z11) * (1.0 - fx)
               : c->z00 + (c->z10 - c->z00) * fx + (c->z01 - c->z00) * fy;
}

static void fill_hit(const surface *s, long cx, long cy, const cell *c, int upper,
                     const double o[3], const double d[3], double t, hit *out) {
  double n[3];
  if (upper) n[0] = c->z01 - c->z11, n[1] = c->z10 - c->z11;
  else n[0] = c->z00 - c->z10, n[1] = c->z00 - c->z01;
  n[2] = 1.0;
  const double len = sqrt(n[0] * n[0] + n[1] * n[1] + 1.0);
  for (int k = 0; k < 3; k++) out->n[k] = n[k] / len, out->p[k] = o[k] + t * d[k];
  out->albedo = s->rho;
  if (s->albedo) {
    const double fx = out->p[0] - (double)cx, fy = out->p[1] - (double)cy;
    double a;
    if (upper) /* corners (1,0), (1,1), (0,1) */
      a = (1.0 - fy) * s->albedo[vertex_index(s, cx + 1, cy)] +
          (fx + fy - 1.0) * s->albedo[vertex_index(s, cx + 1, cy + 1)] +
          (1.0 - fx) * s->albedo[vertex_index(s, cx, cy + 1)];
    else /* corners (0,0), (1,0), (0,1) */
      a = (1.0 - fx - fy) * s->albedo[vertex_index(s, cx, cy)] +
          fx * s->albedo[vertex_index(s, cx + 1, cy)] + fy * s->albedo[vertex_index(s, cx, cy + 1)];
    out->albedo = s->rho * (a < 0.0 ? 0.0 : (a > 1.0 ? 1.0 : a));
  }
}

/* One piece of the ray over a cell, [ta, tb], on one triangle: the height
 * of the ray above the surface is linear there. A hit is where it goes
 * from >= 0 to < 0 (or from > 0 to 0): so a ray leaving a vertex (bias 0)
 * into the surface is blocked at once, and one starting below the surface
 * by rounding is not blocked until it has come out. */
static int piece_hit(const cell *c, long cx, long cy, const double o[3], const double d[3],
                     double ta, double tb, double *t_hit, int *upper) {
  const double tm = 0.5 * (ta + tb);
  const double fxm = o[0] + tm * d[0] - (double)cx, fym = o[1] + tm * d[1] - (double)cy;
  const int up = fxm + fym > 1.0;
  const double ga = o[2] + ta * d[2] - cell_height(c, o[0] + ta * d[0] - (double)cx,
                                                   o[1] + ta * d[1] - (double)cy, up);
  const double gb = o[2] + tb * d[2] - cell_height(c, o[0] + tb * d[0] - (double)cx,
                                                   o[1] + tb * d[1] - (double)cy, up);
  if (!((ga >= 0.0 && gb < 0.0) || (ga > 0.0 && gb == 0.0))) return 0;
  *t_hit = ta + (tb - ta) * (ga / (ga - gb));
  *upper = up;
  return 1;
}

/* The first hit of the ray o + t d (d unit), t > 0: 1, with *out filled;
 * 0 when it escapes; -1 when it is lost (see max_t). */
static int trace_ray(const surface *s, const double o[3], const double d[3], hit *out) {
  const int sx = d[0] < 0.0 ? -1 : 1, sy = d[1] < 0.0 ? -1 : 1;
  long cx = cell_along(o[0], sx), cy = cell_along(o[1], sy);
  const double inv_x = d[0] != 0.0 ? 1.0 / d[0] : INFINITY;
  const double inv_y = d[1] != 0.0 ? 1.0 / d[1] : INFINITY;
  const double step_x = fabs(inv_x), step_y = fabs(inv_y);
  double next_x = d[0] != 0.0 ? ((double)(sx > 0 ? cx + 1 : cx) - o[0]) * inv_x : INFINITY;
  double next_y = d[1] != 0.0 ? ((double)(sy > 0 ? cy + 1 : cy) - o[1]) * inv_y : INFINITY;
  const double dsum = d[0] + d[1];
  double t = 0.0;
  /* the block last found clear, unwrapped: clear for the rest of the walk
   * through it, since the ray only moves away from where it was tested */
  long clear_bx = LONG_MIN, clear_by = LONG_MIN;
  const double max_t = 1e5 + 4.0 * ((double)s->w + (double)s->h);
  for (;;) {
    const double z = o[2] + t * d[2];
    if (z > s->zmax && d[2] >= 0.0) return 0;
    /* A ray within a hair of horizontal would walk for ever: past max_t,
     * one going up counts as escaped and one going down as absorbed
     * (both over a vanishing solid angle). */
    if (t > max_t) return d[2] >= 0.0 ? 0 : -1;
    const double t_exit = next_x < next_y ? next_x : next_y;
    /* a block the ray passes above is walked without testing its cells */
    int clear = 0;
    const int inside = s->addressing == BB_ADDRESS_PERIODIC ||
                       (cx >= 0 && cx < s->w && cy >= 0 && cy < s->h);
    if (inside) {
      const long px = s->addressing == BB_ADDRESS_PERIODIC ? (long)floor((double)cx / s->w) : 0;
      const long py = s->addressing == BB_ADDRESS_PERIODIC ? (long)floor((double)cy / s->h) : 0;
      const int wx = (int)(cx - px * s->w), wy = (int)(cy - py * s->h);
      const int bx = wx / BLOCK, by = wy / BLOCK;
      const long ubx = px * (long)s->bw + bx, uby = py * (long)s->bh + by;
      if (ubx == clear_bx && uby == clear_by) {
        clear = 1;
      } else {
        /* where the ray leaves the block's cells */
        const long x0 = px * s->w + (long)bx * BLOCK, y0 = py * s->h + (long)by * BLOCK;
        const long x1 = px * s->w + ((bx + 1) * BLOCK < s->w ? (bx + 1) * BLOCK : s->w);
        const long y1 = py * s->h + ((by + 1) * BLOCK < s->h ? (by + 1) * BLOCK : s->h);
        const double tx = d[0] != 0.0 ? ((double)(sx > 0 ? x1 : x0) - o[0]) * inv_x : INFINITY;
        const double ty = d[1] != 0.0 ? ((double)(sy > 0 ? y1 : y0) - o[1]) * inv_y : INFINITY;
        const double t_out = tx < ty ? tx : ty;
        const double z_out = o[2] + (isfinite(t_out) ? t_out : 0.0) * d[2];
        const double z_low = d[2] >= 0.0 ? z : (isfinite(t_out) ? z_out : -INFINITY);
        if (z_low > (double)s->block_max[by * s->bw + bx]) {
          clear = 1;
          clear_bx = ubx, clear_by = uby;
        }
      }
    }
    if (!clear) {
      cell c = {vz(s, cx, cy), vz(s, cx + 1, cy), vz(s, cx, cy + 1), vz(s, cx + 1, cy + 1)};
      /* the diagonal fx + fy = 1 splits the cell into its two triangles */
      double t_diag = dsum != 0.0 ? (1.0 + (double)cx + (double)cy - o[0] - o[1]) / dsum : -1.0;
      double t_hit;
      int upper;
      if (t_diag > t && t_diag < t_exit) {
        if (piece_hit(&c, cx, cy, o, d, t, t_diag, &t_hit, &upper) ||
            piece_hit(&c, cx, cy, o, d, t_diag, t_exit, &t_hit, &upper)) {
          fill_hit(s, cx, cy, &c, upper, o, d, t_hit, out);
          return 1;
        }
      } else if (piece_hit(&c, cx, cy, o, d, t, t_exit, &t_hit, &upper)) {
        fill_hit(s, cx, cy, &c, upper, o, d, t_hit, out);
        return 1;
      }
    }
    if (!isfinite(t_exit)) return 0; /* vertical ray above its cell's surface */
    t = t_exit;
    if (next_x < next_y) {
      cx += sx;
      next_x += step_x;
    } else {
      cy += sy;
      next_y += step_y;
    }
  }
}

/* ------------------------------------------------------------ paths */

typedef struct sky {
  int lobes;
  double basis[MAX_LOBES][3];
  double power;
  double total[MAX_LOBES]; /* T_c */
} sky;

static void sky_radiance(const sky *k, const double w[3], double *out) {
  out[0] = 1.0;
  for (int c = 0; c < k->lobes; c++) {
    const double b = w[0] * k->basis[c][0] + w[1] * k->basis[c][1] + w[2] * k->basis[c][2];
    out[1 + c] = b > 0.0 ? (k->power == 1.0 ? b : pow(b, k->power)) : 0.0;
  }
}

/* T_c = integral over H of max(0, w.B_c)^P: a midpoint rule in elevation
 * and azimuth (the integrand's kink where w.B_c = 0 costs O(1/n^2)). */
static double lobe_total(const double b[3], double power) {
  enum { NE = 4096, NA = 4096 };
  static double horizontal[NA]; /* b's horizontal part along each azimuth */
  for (int j = 0; j < NA; j++) {
    const double az = 2.0 * BB__PI * (j + 0.5) / NA;
    horizontal[j] = cos(az) * b[0] + sin(az) * b[1];
  }
  double sum = 0.0;
  for (int i = 0; i < NE; i++) {
    const double el = 0.5 * BB__PI * (i + 0.5) / NE, ce = cos(el), se = sin(el);
    double ring = 0.0;
    for (int j = 0; j < NA; j++) {
      const double v = ce * horizontal[j] + se * b[2];
      if (v > 0.0) ring += power == 1.0 ? v : pow(v, power);
    }
    sum += ring * ce;
  }
  return sum * (0.5 * BB__PI / NE) * (2.0 * BB__PI / NA);
}

/* A unit vector about n: cosine-weighted (Duff et al.'s orthonormal basis). */
static void cosine_about(const double n[3], double u1, double u2, double out[3]) {
  const double sign = n[2] >= 0.0 ? 1.0 : -1.0;
  const double a = -1.0 / (sign + n[2]), b = n[0] * n[1] * a;
  const double t[3] = {1.0 + sign * n[0] * n[0] * a, sign * b, -sign * n[0]};
  const double bt[3] = {b, sign + n[1] * n[1] * a, -n[1]};
  const double r = sqrt(u1), phi = 2.0 * BB__PI * u2;
  const double x = r * cos(phi), y = r * sin(phi), z = sqrt(1.0 - u1 > 0.0 ? 1.0 - u1 : 0.0);
  for (int k = 0; k < 3; k++) out[k] = x * t[k] + y * bt[k] + z * n[k];
}

/* The radiance arriving at o from direction w, every channel, one path. */
static void radiance(const surface *s, const sky *k, int bounces, const double o[3],
                     const double w[3], rng *r, double *out) {
  const int channels = 1 + k->lobes;
  hit h;
  for (int c = 0; c < channels; c++) out[c] = 0.0;
  int met = trace_ray(s, o, w, &h);
  if (met < 0) return;
  if (!met) {
    sky_radiance(k, w, out);
    return;
  }
  double throughput = 1.0;
  for (int depth = 1;; depth++) {
    throughput *= h.albedo;
    if (throughput <= 0.0) return;
    if (bounces > 0 ? depth > bounces : (throughput < CONVERGED_THROUGHPUT || depth > MAX_DEPTH))
      return;
    double next[3], from[3];
    cosine_about(h.n, rng_next(r), rng_next(r), next);
    for (int i = 0; i < 3; i++) from[i] = h.p[i] + s->epsilon * h.n[i];
    met = trace_ray(s, from, next, &h);
    if (met < 0) return;
    if (!met) {
      double L[MAX_CHANNELS];
      sky_radiance(k, next, L);
      for (int c = 0; c < channels; c++) out[c] = throughput * L[c];
      return;
    }
  }
}

/* ------------------------------------------------------------ trace job */

typedef struct trace_job {
  const args *a;
  const surface *s;
  const sky *k;
  int columns, channels, m; /* m x m strata per batch */
  float *out;               /* per reference texel: values then errors */
} trace_job;

static void trace_row(void *user, int row) {
  const trace_job *j = user;
  const args *a = j->a;
  const int channels = j->channels;
  const double scale_lobe = 2.0 * BB__PI;
  for (int i = 0; i < j->columns; i++) {
    const int x = a->texels ? a->texel_x[i] : i * a->stride;
    const int y = a->texels ? a->texel_y[i] : row * a->stride;
    const double o[3] = {x, y, vz(j->s, x, y) + a->bias};
    double batch_mean[BATCHES][MAX_CHANNELS];
    for (int b = 0; b < BATCHES; b++) {
      rng r;
      rng_seed(&r, a->seed, (uint64_t)x, (uint64_t)y, (uint64_t)b);
      double sum[MAX_CHANNELS] = {0};
      for (int su = 0; su < j->m; su++)
        for (int sv = 0; sv < j->m; sv++) {
          /* uniform over H: w.z uniform in (0, 1], azimuth uniform */
          const double wz = 1.0 - (su + rng_next(&r)) / j->m;
          const double phi = 2.0 * BB__PI * (sv + rng_next(&r)) / j->m;
          const double rr = sqrt(1.0 - wz * wz > 0.0 ? 1.0 - wz * wz : 0.0);
          const double w[3] = {rr * cos(phi), rr * sin(phi), wz};
          double L[MAX_CHANNELS];
          radiance(j->s, j->k, a->bounces, o, w, &r, L);
          sum[0] += 2.0 * wz * L[0]; /* (1/pi) L w.z / (1 / 2 pi) */
          for (int c = 0; c < j->k->lobes; c++) sum[1 + c] += scale_lobe * L[1 + c] / j->k->total[c];
        }
      for (int c = 0; c < channels; c++) batch_mean[b][c] = sum[c] / ((double)j->m * j->m);
    }
    float *out = j->out + ((size_t)row * (size_t)j->columns + (size_t)i) * 2 * (size_t)channels;
    for (int c = 0; c < channels; c++) {
      double mean = 0.0, var = 0.0;
      for (int b = 0; b < BATCHES; b++) mean += batch_mean[b][c];
      mean /= BATCHES;
      for (int b = 0; b < BATCHES; b++) var += (batch_mean[b][c] - mean) * (batch_mean[b][c] - mean);
      out[c] = (float)mean;
      out[channels + c] = (float)sqrt(var / (BATCHES * (BATCHES - 1.0)));
    }
  }
}

/* Albedo per vertex from an image: 1 channel as it is, 2 (grey and alpha)
 * the grey, 3 or more Rec. 709 luma of R, G, B; clamped to [0, 1]. */
static int load_albedo(const char *path, int w, int h, float **out) {
  bb_image img = {0};
  bb_error err;
  if (bb_image_read(path, &img, NULL, &err) != BB_OK) {
    fprintf(stderr, "bounce_ref: %s\n", err.message);
    return 1;
  }
  if (img.width != w || img.height != h) {
    fprintf(stderr, "bounce_ref: %s is %dx%d, not the map's %dx%d\n", path, img.width,
            img.height, w, h);
    bb_image_free(&img);
    return 1;
  }
  float *a = malloc((size_t)w * (size_t)h * sizeof(float));
  if (!a) {
    bb_image_free(&img);
    return 1;
  }
  for (size_t i = 0; i < (size_t)w * (size_t)h; i++) {
    const float *p = img.pixels + i * (size_t)img.channels;
    double v = img.channels >= 3 ? 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2] : p[0];
    a[i] = (float)(v < 0.0 ? 0.0 : (v > 1.0 ? 1.0 : v));
  }
  bb_image_free(&img);
  *out = a;
  return 0;
}

static int load_scaled(const char *map, double scale, bb_image *h, bb_image *z) {
  bb_error err;
  if (bb__height_file_read(map, BB_CHANNEL_AUTO, 0.0f, NULL, NULL, h, NULL, &err) != BB_OK ||
      bb_image_alloc(z, h->width, h->height, 1, &err) != BB_OK) {
    fprintf(stderr, "bounce_ref: %s\n", err.message);
    return 1;
  }
  const float s = (float)scale; /* float times float, as the bake scales */
  for (size_t i = 0; i < (size_t)h->width * (size_t)h->height; i++) z->pixels[i] = s * h->pixels[i];
  return 0;
}

/* "ao" for channel 0, else the lobe's name: PREFIX and its index. */
static void channel_name(int c, const char *prefix, char *out, size_t cap) {
  if (c == 0) snprintf(out, cap, "ao");
  else snprintf(out, cap, "%s%d", prefix, c - 1);
}

static double now_seconds(void) {
  return bb__now_seconds();
}

static int run_trace(int argc, char **argv) {
  args a;
  int rc = parse_trace_args(argc, argv, &a);
  if (rc) return rc;
  bb_image h = {0}, z = {0}, out = {0};
  float *albedo = NULL;
  if (load_scaled(a.map, a.scale, &h, &z)) return 1;
  if (a.albedo_path && load_albedo(a.albedo_path, h.width, h.height, &albedo)) {
    bb_image_free(&h);
    bb_image_free(&z);
    return 1;
  }
  surface s = {.w = z.width, .h = z.height, .addressing = a.addressing, .z = z.pixels,
               .albedo = albedo, .rho = a.rho, .zmax = -INFINITY};
  double zabs = 1.0;
  for (size_t i = 0; i < (size_t)s.w * (size_t)s.h; i++) {
    s.zmax = fmax(s.zmax, (double)z.pixels[i]);
    zabs = fmax(zabs, fabs((double)z.pixels[i]));
  }
  s.epsilon = 1e-5 * zabs;
  sky k = {.lobes = a.basis.count, .power = a.power};
  for (int c = 0; c < k.lobes; c++) {
    memcpy(k.basis[c], a.basis.vector[c], sizeof k.basis[c]);
    k.total[c] = lobe_total(k.basis[c], a.power);
  }
  trace_job j = {.a = &a, .s = &s, .k = &k, .channels = 1 + k.lobes};
  j.m = (int)lround(sqrt((double)a.paths / BATCHES));
  j.columns = a.texels ? a.texels : (s.w + a.stride - 1) / a.stride;
  const int rows = a.texels ? 1 : (s.h + a.stride - 1) / a.stride;
  for (int t = 0; t < a.texels; t++)
    if (a.texel_x[t] >= s.w || a.texel_y[t] >= s.h) {
      fprintf(stderr, "bounce_ref: --texel %d,%d is outside the %dx%d map\n", a.texel_x[t],
              a.texel_y[t], s.w, s.h);
      free(albedo);
      bb_image_free(&z);
      bb_image_free(&h);
      return 2;
    }
  bb_error err = {{0}};
  bb_status st = surface_blocks(&s) ? bb__fail(&err, BB_ERR_MEMORY, "out of memory") : BB_OK;
  if (st == BB_OK) st = bb_image_alloc(&out, j.columns, rows, 2 * j.channels, &err);
  const double t0 = now_seconds();
  if (st == BB_OK) {
    j.out = out.pixels;
    st = bb__parallel_for(rows, a.threads, trace_row, &j, NULL, NULL, &err);
  }
  const double seconds = now_seconds() - t0;
  char description[1024];
  snprintf(description, sizeof description,
           "bounce_ref=1\nmap_width=%d\nmap_height=%d\nscale=%.17g\nstride=%d\nrho=%.17g\n"
           "albedo=%s\nbounces=%d\npaths=%d\nbias=%.17g\npower=%.17g\nbasis=%s\n"
           "addressing=%s\nseed=%llu\n",
           s.w, s.h, a.scale, a.stride, a.rho, a.albedo_path ? a.albedo_path : "none", a.bounces,
           a.paths, a.bias, a.power, a.basis.name,
           a.addressing == BB_ADDRESS_CLAMP ? "clamp" : "periodic", a.seed);
  bb_write_options wo = {BB_DEPTH_FLOAT, BB_RANGE_UNIT, description, NULL};
  if (st == BB_OK && a.out) st = bb__image_write(a.out, &out, &wo, &err);
  if (st == BB_OK && a.texels) { /* one line per texel: value and standard error */
    for (int t = 0; t < a.texels; t++) {
      const float *v = out.pixels + (size_t)t * (size_t)out.channels;
      printf("{\"x\":%d,\"y\":%d,\"values\":[", a.texel_x[t], a.texel_y[t]);
      for (int c = 0; c < j.channels; c++) printf("%s%.7g", c ? "," : "", (double)v[c]);
      printf("],\"se\":[");
      for (int c = 0; c < j.channels; c++) printf("%s%.3g", c ? "," : "", (double)v[j.channels + c]);
      printf("]}\n");
    }
    bb_image_free(&out);
  }
  if (st != BB_OK) {
    fprintf(stderr, "bounce_ref: %s\n", err.message);
    rc = 1;
  } else if (!a.texels) {
    /* the mean value, the mean standard error per texel and that of the mean */
    const long texels = (long)rows * j.columns;
    printf("{\"map\":");
    bb__json_quoted(stdout, a.map);
    printf(",\"scale\":%g,\"rho\":%g,\"bounces\":%d,\"paths\":%d,\"stride\":%d,\"texels\":%ld,"
           "\"seconds\":%.3f,\"channels\":[",
           a.scale, a.rho, a.bounces, a.paths, a.stride, texels, seconds);
    fprintf(stderr, "bounce_ref: %s: %ld texels x %d paths, %.1f s\n", a.map, texels, a.paths,
            seconds);
    for (int c = 0; c < j.channels; c++) {
      double mean = 0.0, se = 0.0, se2 = 0.0;
      for (long t = 0; t < texels; t++) {
        const float *v = out.pixels + (size_t)t * (size_t)out.channels;
        mean += v[c], se += v[j.channels + c], se2 += (double)v[j.channels + c] * v[j.channels + c];
      }
      printf("%s{\"mean\":%.6g,\"texel_se\":%.3g,\"mean_se\":%.3g}", c ? "," : "",
             mean / (double)texels, se / (double)texels, sqrt(se2) / (double)texels);
      char name[16];
      channel_name(c, "vis", name, sizeof name);
      fprintf(stderr, "  %-6s mean %.5f, standard error per texel %.5f (mean of them), of the mean %.6f\n",
              name, mean / (double)texels, se / (double)texels, sqrt(se2) / (double)texels);
    }
    printf("]}\n");
  }
  free(s.block_max);
  free(albedo);
  bb_image_free(&out);
  bb_image_free(&z);
  bb_image_free(&h);
  return rc;
}

/* ------------------------------------------------------------ compare */

static int read_key(const char *description, const char *key, double *out) {
  char value[128];
  return bb__provenance_value(description, key, value, sizeof value) &&
                 !parse_number(value, -1e300, 1e300, out)
             ? 0
             : 1;
}

typedef struct stats {
  double mean, mean_abs;
} stats;

static int run_compare(int argc, char **argv) {
  if (argc < 6) return usage("compare needs REF.exr, MAP, SCALE and a result");
  const char *ref_path = argv[2], *map = argv[3];
  double scale;
  if (parse_number(argv[4], 1e-9, 1e30, &scale)) return usage("SCALE must be > 0");
  bb_normal_filter filter = BB_NORMAL_VALVE;
  int first = 5;
  if (!strcmp(argv[5], "--normal-filter")) {
    bb_error err;
    if (argc < 8 || bb__normal_filter_parse(argv[6], &filter, &err) != BB_OK)
      return usage("bad --normal-filter");
    first = 7;
  }
  bb_image ref = {0}, h = {0}, normal = {0};
  bb_image_info info = {0};
  bb_error err = {{0}};
  if (bb_image_read(ref_path, &ref, &info, &err) != BB_OK) {
    fprintf(stderr, "bounce_ref: %s\n", err.message);
    return 1;
  }
  double stride_d, width_d, height_d, bias, clamp_flag = 0;
  char basis_name[64], addressing[32];
  if (!info.description || read_key(info.description, "stride", &stride_d) ||
      read_key(info.description, "map_width", &width_d) ||
      read_key(info.description, "map_height", &height_d) ||
      read_key(info.description, "bias", &bias) ||
      !bb__provenance_value(info.description, "basis", basis_name, sizeof basis_name) ||
      !bb__provenance_value(info.description, "addressing", addressing, sizeof addressing)) {
    fprintf(stderr, "bounce_ref: %s: not a bounce_ref reference\n", ref_path);
    bb_image_free(&ref);
    bb_image_info_free(&info);
    return 1;
  }
  clamp_flag = !strcmp(addressing, "clamp");
  bb_image_info_free(&info);
  bb_basis basis;
  if (bb__basis_parse(basis_name, &basis, &err) != BB_OK) {
    fprintf(stderr, "bounce_ref: %s: %s\n", ref_path, err.message);
    bb_image_free(&ref);
    return 1;
  }
  const int stride = (int)stride_d, lobes = basis.count, channels = 1 + lobes;
  if (bb__height_file_read(map, BB_CHANNEL_AUTO, 0.0f, NULL, NULL, &h, NULL, &err) != BB_OK ||
      bb__normals_compute_all_cores(&h, (float)scale, filter,
                         clamp_flag ? BB_ADDRESS_CLAMP : BB_ADDRESS_PERIODIC, &normal,
                         &err) != BB_OK) {
    fprintf(stderr, "bounce_ref: %s\n", err.message);
    bb_image_free(&ref);
    bb_image_free(&h);
    return 1;
  }
  const int columns = (h.width + stride - 1) / stride, rows = (h.height + stride - 1) / stride;
  if (h.width != (int)width_d || h.height != (int)height_d || ref.width != columns ||
      ref.height != rows || ref.channels != 2 * channels) {
    fprintf(stderr, "bounce_ref: %s does not belong to %s\n", ref_path, map);
    bb_image_free(&ref);
    bb_image_free(&h);
    bb_image_free(&normal);
    return 1;
  }
  const long texels = (long)rows * columns;
  /* the reference's own standard errors, in the units compared */
  double se_mean[MAX_CHANNELS] = {0}, se_of_mean[MAX_CHANNELS] = {0};
  for (int row = 0; row < rows; row++)
    for (int i = 0; i < columns; i++) {
      const float *v = bb_image_texel(&ref, i, row);
      const float *n = bb_image_texel(&normal, i * stride, row * stride);
      for (int c = 0; c < channels; c++) {
        double f = 1.0;
        if (c > 0) {
          const double *b = basis.vector[c - 1];
          f = fmax(0.0, (double)n[0] * b[0] + (double)n[1] * b[1] + (double)n[2] * b[2]);
        }
        const double e = f * v[channels + c];
        se_mean[c] += e, se_of_mean[c] += e * e;
      }
    }
  printf("{\"reference\":");
  bb__json_quoted(stdout, ref_path);
  printf(",\"texels\":%ld,\"reference_se\":[", texels);
  fprintf(stderr, "bounce_ref: %s: %ld texels; reference standard error per texel / of the mean:",
          ref_path, texels);
  for (int c = 0; c < channels; c++) {
    printf("%s{\"texel\":%.3g,\"mean\":%.3g}", c ? "," : "", se_mean[c] / (double)texels,
           sqrt(se_of_mean[c]) / (double)texels);
    fprintf(stderr, " %.5f / %.6f", se_mean[c] / (double)texels, sqrt(se_of_mean[c]) / (double)texels);
  }
  fprintf(stderr, "\n");
  printf("],\"results\":[");
  int rc = 0;
  for (int r = first, printed = 0; r < argc; r++) {
    char *text = argv[r], *eq = strchr(text, '='), *comma = eq ? strchr(eq, ',') : NULL;
    if (!eq || !comma) {
      rc = usage("results are NAME=AO.exr,SSBUMP.exr");
      break;
    }
    *eq = *comma = '\0';
    bb_image ao = {0}, ss = {0};
    if (bb_image_read(eq + 1, &ao, NULL, &err) != BB_OK ||
        bb_image_read(comma + 1, &ss, NULL, &err) != BB_OK) {
      fprintf(stderr, "bounce_ref: %s\n", err.message);
      bb_image_free(&ao);
      rc = 1;
      break;
    }
    if (ao.width != h.width || ao.height != h.height || ss.width != h.width ||
        ss.height != h.height || ss.channels < lobes) {
      fprintf(stderr, "bounce_ref: %s or %s does not match %s\n", eq + 1, comma + 1, map);
      bb_image_free(&ao);
      bb_image_free(&ss);
      rc = 1;
      break;
    }
    stats st[MAX_CHANNELS] = {{0, 0}};
    for (int row = 0; row < rows; row++)
      for (int i = 0; i < columns; i++) {
        const int x = i * stride, y = row * stride;
        const float *v = bb_image_texel(&ref, i, row), *n = bb_image_texel(&normal, x, y);
        for (int c = 0; c < channels; c++) {
          double want, got;
          if (c == 0) {
            want = fmin(1.0, (double)v[0]);
            got = bb_image_texel(&ao, x, y)[0];
          } else {
            const double *b = basis.vector[c - 1];
            const double ndotb = (double)n[0] * b[0] + (double)n[1] * b[1] + (double)n[2] * b[2];
            want = fmin(1.0, fmax(0.0, ndotb) * (double)v[c]);
            got = bb_image_texel(&ss, x, y)[c - 1];
          }
          st[c].mean += got - want;
          st[c].mean_abs += fabs(got - want);
        }
      }
    printf("%s{\"name\":", printed++ ? "," : "");
    bb__json_quoted(stdout, text);
    printf(",\"channels\":[");
    fprintf(stderr, "bounce_ref: %-12s", text);
    for (int c = 0; c < channels; c++) {
      st[c].mean /= (double)texels, st[c].mean_abs /= (double)texels;
      printf("%s{\"mean\":%.6g,\"mean_abs\":%.6g}", c ? "," : "", st[c].mean, st[c].mean_abs);
      char name[16];
      channel_name(c, "ss", name, sizeof name);
      fprintf(stderr, "  %s %.5f (%+.5f)", name, st[c].mean_abs, st[c].mean);
    }
    fprintf(stderr, "   (mean |error| (bias))\n");
    printf("]}");
    bb_image_free(&ao);
    bb_image_free(&ss);
  }
  printf("]}\n");
  bb_image_free(&ref);
  bb_image_free(&h);
  bb_image_free(&normal);
  return rc;
}

int main(int argc, char **argv) {
  if (argc >= 2 && !strcmp(argv[1], "trace")) return run_trace(argc, argv);
  if (argc >= 2 && !strcmp(argv[1], "compare")) return run_compare(argc, argv);
  return usage("the first argument is trace or compare");
}
