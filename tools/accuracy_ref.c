/* accuracy_ref.c: a reference for ao and ssbump of bumpbake's own, dense in
 * azimuth, and how far given bakes are from it.
 *
 *   accuracy_ref MAP SCALE [--stride K] [--azimuths N] [--bias B] [--reach D]
 *                [--rules S,S,...] NAME=AO.exr,SSBUMP.exr ...
 *
 * At every K-th texel of every K-th row (default 4) of MAP (read as a bake
 * reads it, no smoothing, heights times SCALE, periodic), the horizon is
 * found in N azimuths (default 2048, spread evenly) by bb__ray_horizon, the
 * exact horizon of the triangle mesh along any direction out to D texels
 * (default 8 times the longer side), and docs/conventions.md's integrals are taken
 * per azimuth in closed form (power 1): ao from cos^2 of the horizon's
 * elevation, vis_c from the lobe max(0, w.B_c) above it. ssbump uses
 * Valve's normal (bb__normals_compute_all_cores, BB_NORMAL_VALVE). This shares with the
 * bake neither its slices, nor its sweeps, nor its tables: only the
 * breakpoint test of the mesh.
 *
 * For each NAME=AO.exr,SSBUMP.exr (float images of MAP's size) prints the
 * signed mean and mean |difference| from the reference over those texels,
 * per channel, as one JSON line on stdout and a human line per result on
 * stderr. With --rules (and then no results needed), also how far azimuth
 * rules of S slices, fed exact horizons, are from the same reference (the
 * rules section below): one JSON line on stdout and a table on stderr.
 * Exits 1 when a file cannot be read or does not match, 2 on a bad command
 * line.
 */
#include "job/job_internal.h"
#include "bumpbake.h"
#include "core/internal.h"
#include "trace/rayset.h"
#include "trace/testing.h"
#include "bake/bake_internal.h"
#include "trace/basis.h"
#include "trace/pyramid.h"
#include "core/json.h"

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_RESULTS 16
#define MAX_SLICE_COUNTS 16

typedef struct args {
  const char *map;
  double scale, bias, reach;
  int stride, azimuths;
  int results;
  int slice_counts, slice_count[MAX_SLICE_COUNTS]; /* --rules */
  char *name[MAX_RESULTS], *ao[MAX_RESULTS], *ssbump[MAX_RESULTS];
} args;

static int usage(const char *reason) {
  fprintf(stderr,
          "accuracy_ref: %s\n"
          "usage: accuracy_ref MAP SCALE [--stride K] [--azimuths N] [--bias B] [--reach D] "
          "[--rules S,S,...] NAME=AO.exr,SSBUMP.exr ...\n",
          reason);
  return 2;
}

static int parse_number(const char *s, double lo, double *out) {
  char *end;
  errno = 0;
  const double v = strtod(s, &end);
  if (errno || end == s || *end || !isfinite(v) || v < lo) return 1;
  *out = v;
  return 0;
}

/* NAME=AO,SSBUMP: split in place. */
static int parse_result(char *text, args *a) {
  char *eq = strchr(text, '='), *comma = eq ? strchr(eq, ',') : NULL;
  if (!eq || !comma || a->results == MAX_RESULTS) return 1;
  *eq = *comma = '\0';
  a->name[a->results] = text;
  a->ao[a->results] = eq + 1;
  a->ssbump[a->results] = comma + 1;
  a->results++;
  return 0;
}

/* S,S,...: the slice counts of --rules. */
static int parse_counts(const char *text, args *a) {
  const char *at = text;
  for (;;) {
    char *end;
    errno = 0;
    const long s = strtol(at, &end, 10);
    if (errno || end == at || s < 2 || s > BB_MAX_SLICES || a->slice_counts == MAX_SLICE_COUNTS)
      return 1;
    a->slice_count[a->slice_counts++] = (int)s;
    if (!*end) return 0;
    if (*end != ',') return 1;
    at = end + 1;
  }
}

static int parse_args(int argc, char **argv, args *a) {
  if (argc < 4) return usage("wrong number of arguments");
  memset(a, 0, sizeof *a);
  a->map = argv[1];
  a->stride = 4, a->azimuths = 2048, a->bias = 0.55, a->reach = 0.0;
  if (parse_number(argv[2], 1e-9, &a->scale)) return usage("SCALE must be > 0");
  for (int i = 3; i < argc; i++) {
    double v;
    if (!strcmp(argv[i], "--rules")) {
      if (i + 1 >= argc || parse_counts(argv[++i], a)) return usage("--rules wants S,S,... in 2..256");
    } else if (!strncmp(argv[i], "--", 2)) {
      if (i + 1 >= argc || parse_number(argv[i + 1], 0.0, &v)) return usage("bad option value");
      if (!strcmp(argv[i], "--stride") && v >= 1) a->stride = (int)v;
      else if (!strcmp(argv[i], "--azimuths") && v >= 1) a->azimuths = (int)v;
      else if (!strcmp(argv[i], "--bias")) a->bias = v;
      else if (!strcmp(argv[i], "--reach") && v > 0) a->reach = v;
      else return usage("unknown option");
      i++;
    } else if (parse_result(argv[i], a)) {
      return usage("results are NAME=AO.exr,SSBUMP.exr (at most 16)");
    }
  }
  return a->results || a->slice_counts ? 0 : usage("nothing to compare");
}

/* ---------------------------------------------------------- reference */

typedef struct job {
  const args *a;
  const bb_pyramid *p;
  const bb_image *z, *normal;
  int columns;     /* reference texels per row */
  double basis[3][3];
  float *ao, *ssbump; /* per reference texel: 1 and 3 values */
} job;

/* The integral of (a cos + c sin) cos over [start, pi/2], where a = B's
 * horizontal part along the azimuth, c = Bz > 0: the lobe open above the
 * elevation start (not below the lobe's own edge atan2(-a, c): callers
 * take the larger). */
static double lobe_open(double a, double c, double start) {
  const double end = 0.5 * BB__PI;
  if (start >= end) return 0.0;
  return a * ((end - start) / 2 + (sin(2 * end) - sin(2 * start)) / 4) +
         c * (1.0 - sin(start) * sin(start)) / 2;
}

/* The lobe of b open above the horizon of tangent t at azimuth phi. */
static double lobe_above(const double b[3], double phi, double t) {
  const double a = b[0] * cos(phi) + b[1] * sin(phi), c = b[2];
  return lobe_open(a, c, fmax(atan(fmax(t, 0.0)), atan2(-a, c)));
}

static void reference_row(void *user, int row) {
  job *j = user;
  const args *a = j->a;
  const int y = row * a->stride;
  for (int i = 0; i < j->columns; i++) {
    const int x = i * a->stride;
    const bb__ray base = {{x, y, (double)*bb_image_texel(j->z, x, y) + a->bias}, {1, 0, 0}};
    double open_ao = 0.0, open[3] = {0}, all[3] = {0};
    for (int k = 0; k < a->azimuths; k++) {
      const double phi = 2.0 * BB__PI * (k + 0.5) / a->azimuths;
      bb__ray r = base;
      r.direction[0] = cos(phi), r.direction[1] = sin(phi);
      const double t = bb__ray_horizon(j->p, &r, a->reach);
      open_ao += 1.0 / (1.0 + t * t);
      for (int c = 0; c < 3; c++) {
        open[c] += lobe_above(j->basis[c], phi, t);
        all[c] += lobe_above(j->basis[c], phi, 0.0);
      }
    }
    const size_t at = (size_t)row * (size_t)j->columns + (size_t)i;
    j->ao[at] = (float)(open_ao / a->azimuths);
    const float *n = bb_image_texel(j->normal, x, y);
    for (int c = 0; c < 3; c++) {
      const double *b = j->basis[c];
      const double ndotb = (double)n[0] * b[0] + (double)n[1] * b[1] + (double)n[2] * b[2];
      j->ssbump[3 * at + (size_t)c] = (float)(fmax(0.0, ndotb) * open[c] / all[c]);
    }
  }
}

/* -------------------------------------------------------------- rules
 *
 * --rules S1,S2,...: what azimuth rules would give at S slices, from exact
 * horizons alone (no bake, no tables). At each reference texel the horizon
 * is also found along each of the S slices' lattice directions (the bake's
 * own, from bb__rayset_new), and each rule turns those S horizons into a
 * horizon at every one of the N reference azimuths; ao and ssbump are then
 * integrated over the N azimuths with the reference's own lobe integral
 * (lobe_open) and compared with the reference (reference_row), so what
 * differs is the rule alone:
 *
 *   const     the bake's: each slice's horizon over the sector halfway to
 *             its neighbours (an azimuth bin a sector edge cuts is split)
 *   lin_elev  elevation interpolated linearly in azimuth between slices
 *   lin_cos2  cos^2 of the elevation (ao's integrand) interpolated so
 *   lin_tan   the horizon's tangent interpolated so
 *   cubic     elevation by Catmull-Rom through four slices
 *   rotated   const over S evenly spread exact directions, turned per
 *             texel by a hashed fraction of the spacing (a model of per-
 *             texel rotated slice sets: no lattice) */

enum { RULE_CONST, RULE_LIN_ELEV, RULE_LIN_COS2, RULE_LIN_TAN, RULE_CUBIC, RULE_ROTATED, RULES };
static const char *const rule_name[RULES] = {"const", "lin_elev", "lin_cos2",
                                             "lin_tan", "cubic",    "rotated"};

typedef struct rule_job {
  const job *j;
  int n;          /* azimuths */
  double *cosphi, *sinphi;
  double *a, *alpha; /* per azimuth and lobe: B's horizontal part along it, atan2(-a, Bz) */
  double *slice_phi[MAX_SLICE_COUNTS]; /* per slice count: lattice azimuths in [0, 2 pi), rising */
  float *out; /* per count, rule, texel: ao, ss0..2 */
  long texels;
} rule_job;

/* Open ao and open lobes at azimuth k for elevation theta, times weight, into sums. */
static void rule_add(const rule_job *r, int k, double theta, double weight, double sums[4]) {
  if (theta < 0.0) theta = 0.0;
  if (theta > 0.5 * BB__PI) theta = 0.5 * BB__PI;
  const double co = cos(theta);
  sums[0] += weight * co * co;
  for (int c = 0; c < 3; c++)
    sums[1 + c] += weight * lobe_open(r->a[3 * k + c], r->j->basis[c][2],
                                      fmax(theta, r->alpha[3 * k + c]));
}

static double elevation(double t) { return atan(t > 0.0 ? t : 0.0); }

/* Angle from a to b going up, in [0, 2 pi). */
static double turn(double a, double b) {
  double d = fmod(b - a, 2.0 * BB__PI);
  return d < 0.0 ? d + 2.0 * BB__PI : d;
}

/* ao and ssbump from open sums (sums of N azimuths) into out[4]. */
static void rule_finish(const rule_job *r, const double open[4], const double all[4], const float *n,
                        float *out) {
  out[0] = (float)(open[0] / r->n);
  for (int c = 0; c < 3; c++) {
    const double *b = r->j->basis[c];
    const double ndotb = (double)n[0] * b[0] + (double)n[1] * b[1] + (double)n[2] * b[2];
    out[1 + c] = (float)(fmax(0.0, ndotb) * open[1 + c] / all[1 + c]);
  }
}

/* const over slices at phi[0..S-1] (rising, in [0, 2 pi)) with horizons t. */
static void rule_const(const rule_job *r, const double *phi, const double *t, int S, double sums[4]) {
  const double h = 2.0 * BB__PI / r->n;
  for (int s = 0; s < S; s++) {
    const int prev = (s + S - 1) % S, next = (s + 1) % S;
    const double lo = phi[s] - 0.5 * (S > 1 ? turn(phi[prev], phi[s]) : BB__PI);
    const double hi = phi[s] + 0.5 * (S > 1 ? turn(phi[s], phi[next]) : BB__PI);
    const double theta = elevation(t[s]);
    /* bins k with [k h, (k + 1) h] meeting [lo, hi], lo may be negative */
    for (int k = (int)floor(lo / h); (double)k * h < hi; k++) {
      const double from = fmax(lo, (double)k * h), to = fmin(hi, (double)(k + 1) * h);
      if (to > from) rule_add(r, bb__wrap(k, r->n), theta, (to - from) / h, sums);
    }
  }
}

static void rule_row(void *user, int row) {
  rule_job *r = user;
  const job *j = r->j;
  const args *a = j->a;
  const int y = row * a->stride;
  for (int i = 0; i < j->columns; i++) {
    const int x = i * a->stride;
    const long at = (long)row * j->columns + i;
    const bb__ray base = {{x, y, (double)*bb_image_texel(j->z, x, y) + a->bias}, {1, 0, 0}};
    const float *n = bb_image_texel(j->normal, x, y);
    double all[4] = {0}; /* the lobes open to the whole hemisphere */
    for (int k = 0; k < r->n; k++)
      rule_add(r, k, 0.0, 1.0, all);
    /* the dense reference of this texel (reference_row) */
    const float ref[4] = {j->ao[at], j->ssbump[3 * at], j->ssbump[3 * at + 1],
                          j->ssbump[3 * at + 2]};
    /* a hashed turn in [0, 1) per texel for the rotated sets */
    uint32_t hash = (uint32_t)x * 73856093u ^ (uint32_t)y * 19349663u;
    hash ^= hash >> 13, hash *= 0x5bd1e995u, hash ^= hash >> 15;
    const double u = (hash & 0xffffff) / 16777216.0;
    for (int m = 0; m < a->slice_counts; m++) {
      const int S = a->slice_count[m];
      const double *phi = r->slice_phi[m];
      double t[BB_MAX_SLICES], rphi[BB_MAX_SLICES], rt[BB_MAX_SLICES];
      for (int s = 0; s < S; s++) {
        bb__ray ray = base;
        ray.direction[0] = cos(phi[s]), ray.direction[1] = sin(phi[s]);
        t[s] = bb__ray_horizon(j->p, &ray, a->reach);
        rphi[s] = 2.0 * BB__PI * (s + u) / S;
        ray.direction[0] = cos(rphi[s]), ray.direction[1] = sin(rphi[s]);
        rt[s] = bb__ray_horizon(j->p, &ray, a->reach);
      }
      for (int rule = 0; rule < RULES; rule++) {
        double sums[4] = {0};
        if (rule == RULE_CONST) rule_const(r, phi, t, S, sums);
        else if (rule == RULE_ROTATED) rule_const(r, rphi, rt, S, sums);
        else {
          int below = 0; /* slices at azimuths <= p */
          for (int k = 0; k < r->n; k++) {
            const double p = 2.0 * BB__PI * (k + 0.5) / r->n;
            while (below < S && phi[below] <= p) below++;
            const int s = (below + S - 1) % S, s1 = (s + 1) % S;
            const double w = turn(phi[s], p) / turn(phi[s], phi[s1]);
            const double t0 = fmax(t[s], 0.0), t1 = fmax(t[s1], 0.0);
            double theta;
            if (rule == RULE_LIN_ELEV) {
              theta = (1 - w) * atan(t0) + w * atan(t1);
            } else if (rule == RULE_LIN_COS2) {
              const double c2 = (1 - w) / (1 + t0 * t0) + w / (1 + t1 * t1);
              theta = acos(sqrt(c2));
            } else if (rule == RULE_LIN_TAN) {
              theta = atan((1 - w) * t0 + w * t1);
            } else { /* cubic */
              const double e0 = elevation(t[(s + S - 1) % S]), e1 = atan(t0), e2 = atan(t1),
                           e3 = elevation(t[(s + 2) % S]);
              theta = e1 + 0.5 * w * (e2 - e0 + w * (2 * e0 - 5 * e1 + 4 * e2 - e3 +
                                                     w * (3 * (e1 - e2) + e3 - e0)));
            }
            rule_add(r, k, theta, 1.0, sums);
          }
        }
        float got[4];
        rule_finish(r, sums, all, n, got);
        float *o = r->out + (((size_t)m * RULES + (size_t)rule) * (size_t)r->texels + (size_t)at) * 4;
        for (int c = 0; c < 4; c++) o[c] = got[c] - ref[c];
      }
    }
  }
}

/* Per slice count and rule: mean |error| and bias of ao and each ssbump channel. */
static bb_status rules_run(const args *a, const job *j, int rows, bb_error *err) {
  rule_job r = {.j = j, .n = a->azimuths, .texels = (long)rows * j->columns};
  const size_t n = (size_t)r.n;
  r.cosphi = malloc(n * sizeof(double));
  r.sinphi = malloc(n * sizeof(double));
  r.a = malloc(3 * n * sizeof(double));
  r.alpha = malloc(3 * n * sizeof(double));
  r.out = calloc((size_t)a->slice_counts * RULES * (size_t)r.texels * 4, sizeof(float));
  bb_status st = BB_OK;
  if (!r.cosphi || !r.sinphi || !r.a || !r.alpha || !r.out) st = bb__fail(err, BB_ERR_MEMORY, "out of memory");
  for (size_t k = 0; st == BB_OK && k < n; k++) {
    const double phi = 2.0 * BB__PI * ((double)k + 0.5) / r.n;
    r.cosphi[k] = cos(phi), r.sinphi[k] = sin(phi);
    for (size_t c = 0; c < 3; c++) {
      const double *b = j->basis[c];
      r.a[3 * k + c] = b[0] * r.cosphi[k] + b[1] * r.sinphi[k];
      r.alpha[3 * k + c] = atan2(-r.a[3 * k + c], b[2]);
    }
  }
  for (int m = 0; st == BB_OK && m < a->slice_counts; m++) {
    bb_rayset *rs = NULL;
    st = bb__rayset_new(a->slice_count[m], 1.0, NULL, &rs, err);
    if (st != BB_OK) break;
    r.slice_phi[m] = malloc((size_t)rs->slice_count * sizeof(double));
    for (int s = 0; r.slice_phi[m] && s < rs->slice_count; s++) {
      const double phi = atan2(rs->slice_step[2 * s + 1], rs->slice_step[2 * s]);
      r.slice_phi[m][s] = phi < 0.0 ? phi + 2.0 * BB__PI : phi;
    }
    bb_rayset_free(rs);
    if (!r.slice_phi[m]) st = bb__fail(err, BB_ERR_MEMORY, "out of memory");
  }
  if (st == BB_OK) st = bb__parallel_for(rows, 0, rule_row, &r, NULL, NULL, err);
  if (st == BB_OK) {
    printf("{\"map\":");
    bb__json_quoted(stdout, a->map);
    printf(",\"scale\":%g,\"stride\":%d,\"azimuths\":%d,\"texels\":%ld,\"rules\":[", a->scale,
           a->stride, a->azimuths, r.texels);
    fprintf(stderr, "%-9s %6s %9s %9s %9s %9s  (ssmax: the ssbump channel of largest mean |error|)\n",
            "rule", "slices", "ao|e|", "ao bias", "ssmax|e|", "ss bias");
    for (int m = 0; m < a->slice_counts; m++)
      for (int rule = 0; rule < RULES; rule++) {
        double mean[4] = {0}, mean_abs[4] = {0};
        const float *o = r.out + ((size_t)m * RULES + (size_t)rule) * (size_t)r.texels * 4;
        for (long t = 0; t < r.texels; t++)
          for (int c = 0; c < 4; c++) mean[c] += o[4 * t + c], mean_abs[c] += fabs(o[4 * t + c]);
        int worst = 1;
        for (int c = 0; c < 4; c++) {
          mean[c] /= (double)r.texels, mean_abs[c] /= (double)r.texels;
          if (c > 1 && mean_abs[c] > mean_abs[worst]) worst = c;
        }
        printf("%s{\"rule\":\"%s\",\"slices\":%d", m || rule ? "," : "", rule_name[rule],
               a->slice_count[m]);
        for (int c = 0; c < 4; c++)
          printf(",\"%s\":{\"mean\":%.6g,\"mean_abs\":%.6g}", c ? (c == 1 ? "ss0" : c == 2 ? "ss1" : "ss2") : "ao",
                 mean[c], mean_abs[c]);
        printf("}");
        fprintf(stderr, "%-9s %6d %9.5f %+9.5f %9.5f %+9.5f\n", rule_name[rule], a->slice_count[m],
                mean_abs[0], mean[0], mean_abs[worst], mean[worst]);
      }
    printf("]}\n");
  }
  for (int m = 0; m < a->slice_counts; m++) free(r.slice_phi[m]);
  free(r.cosphi), free(r.sinphi), free(r.a), free(r.alpha), free(r.out);
  return st;
}

/* ------------------------------------------------------------ compare */

typedef struct stats {
  double mean, mean_abs;
} stats;

static stats difference(const job *j, const bb_image *img, const float *ref, int c, int stride_ref) {
  stats s = {0, 0};
  const int rows = (img->height + j->a->stride - 1) / j->a->stride;
  const long n = (long)rows * j->columns;
  for (int row = 0; row < rows; row++)
    for (int i = 0; i < j->columns; i++) {
      const double d = (double)bb_image_texel(img, i * j->a->stride, row * j->a->stride)[c] -
                       (double)ref[((size_t)row * (size_t)j->columns + (size_t)i) * (size_t)stride_ref + (size_t)c];
      s.mean += d;
      s.mean_abs += fabs(d);
    }
  s.mean /= (double)n, s.mean_abs /= (double)n;
  return s;
}

static int read_matching(const char *path, int width, int height, int channels, bb_image *img) {
  bb_error err = {{0}};
  if (bb_image_read(path, img, NULL, &err) != BB_OK) {
    fprintf(stderr, "accuracy_ref: %s\n", err.message);
    return 1;
  }
  if (img->width != width || img->height != height || img->channels < channels) {
    fprintf(stderr, "accuracy_ref: %s is %dx%d with %d channel(s), not %dx%d with %d\n", path,
            img->width, img->height, img->channels, width, height, channels);
    return 1;
  }
  return 0;
}

static int compare_all(const args *a, const job *j, int width, int height) {
  printf("{\"map\":");
  bb__json_quoted(stdout, a->map);
  printf(",\"scale\":%g,\"stride\":%d,\"azimuths\":%d,\"reach\":%g,\"texels\":%ld,\"results\":[",
         a->scale, a->stride, a->azimuths, a->reach,
         (long)((height + a->stride - 1) / a->stride) * j->columns);
  for (int r = 0; r < a->results; r++) {
    bb_image ao = {0}, ss = {0};
    if (read_matching(a->ao[r], width, height, 1, &ao) ||
        read_matching(a->ssbump[r], width, height, 3, &ss)) {
      bb_image_free(&ao);
      return 1;
    }
    const stats sa = difference(j, &ao, j->ao, 0, 1);
    printf("%s{\"name\":", r ? "," : "");
    bb__json_quoted(stdout, a->name[r]);
    printf(",\"ao\":{\"mean\":%.6g,\"mean_abs\":%.6g},\"ssbump\":[", sa.mean, sa.mean_abs);
    fprintf(stderr, "accuracy_ref: %-10s ao %+.5f / %.5f", a->name[r], sa.mean, sa.mean_abs);
    for (int c = 0; c < 3; c++) {
      const stats s = difference(j, &ss, j->ssbump, c, 3);
      printf("%s{\"mean\":%.6g,\"mean_abs\":%.6g}", c ? "," : "", s.mean, s.mean_abs);
      fprintf(stderr, "  ss%d %+.5f / %.5f", c, s.mean, s.mean_abs);
    }
    printf("]}");
    fprintf(stderr, "  (mean / mean |d|)\n");
    bb_image_free(&ao);
    bb_image_free(&ss);
  }
  printf("]}\n");
  return 0;
}

int main(int argc, char **argv) {
  args a;
  int rc = parse_args(argc, argv, &a);
  if (rc) return rc;
  bb_image h = {0}, z = {0}, normal = {0};
  bb_pyramid *p = NULL;
  bb_error err = {{0}};
  bb_status st = bb__height_file_read(a.map, BB_CHANNEL_AUTO, 0.0f, NULL, NULL, &h, NULL, &err);
  if (st == BB_OK) st = bb_image_alloc(&z, h.width, h.height, 1, &err);
  if (st == BB_OK) {
    const float scale = (float)a.scale; /* float times float, as the bake scales */
    for (size_t i = 0; i < (size_t)h.width * (size_t)h.height; i++) z.pixels[i] = scale * h.pixels[i];
    st = bb__pyramid_build_all_cores(&z, BB_ADDRESS_PERIODIC, &p, &err);
  }
  if (st == BB_OK)
    st = bb__normals_compute_all_cores(&h, (float)a.scale, BB_NORMAL_VALVE, BB_ADDRESS_PERIODIC, &normal, &err);
  job j = {.a = &a, .p = p, .z = &z, .normal = &normal};
  if (st == BB_OK) {
    if (a.reach == 0.0) a.reach = 8.0 * (h.width > h.height ? h.width : h.height);
    j.columns = (h.width + a.stride - 1) / a.stride;
    const int rows = (h.height + a.stride - 1) / a.stride;
    for (int c = 0; c < 3; c++) bb__basis_vector(c, j.basis[c]);
    j.ao = malloc((size_t)rows * (size_t)j.columns * sizeof(float));
    j.ssbump = malloc(3 * (size_t)rows * (size_t)j.columns * sizeof(float));
    if (!j.ao || !j.ssbump) st = bb__fail(&err, BB_ERR_MEMORY, "out of memory");
    if (st == BB_OK) /* the dense reference, which results and rules compare with */
      st = bb__parallel_for(rows, 0, reference_row, &j, NULL, NULL, &err);
    if (st == BB_OK && a.slice_counts) st = rules_run(&a, &j, rows, &err);
  }
  if (st != BB_OK) {
    fprintf(stderr, "accuracy_ref: %s\n", err.message);
    rc = 1;
  } else if (a.results) {
    rc = compare_all(&a, &j, h.width, h.height);
  }
  free(j.ao);
  free(j.ssbump);
  bb_pyramid_free(p);
  bb_image_free(&normal);
  bb_image_free(&z);
  bb_image_free(&h);
  return rc;
}
