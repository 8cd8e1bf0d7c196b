/* accuracy_ref.c: a reference for ao and ssbump of bumpbake's own, dense in
 * azimuth, and how far given bakes are from it.
 *
 *   accuracy_ref MAP SCALE [--stride K] [--azimuths N] [--bias B] [--reach D]
 *                NAME=AO.exr,SSBUMP.exr ...
 *
 * At every K-th texel of every K-th row (default 4) of MAP (read as a bake
 * reads it, no smoothing, heights times SCALE, periodic), the horizon is
 * found in N azimuths (default 2048, spread evenly) by bb__ray_horizon, the
 * exact horizon of the triangle mesh along any direction out to D texels
 * (default 8 times the longer side), and docs/conventions.md's integrals are taken
 * per azimuth in closed form (power 1): ao from cos^2 of the horizon's
 * elevation, vis_c from the lobe max(0, w.B_c) above it. ssbump uses
 * Valve's normal (bb_normals_compute, BB_NORMAL_VALVE). This shares with the
 * bake neither its slices, nor its sweeps, nor its tables: only the
 * breakpoint test of the mesh.
 *
 * For each NAME=AO.exr,SSBUMP.exr (float images of MAP's size) prints the
 * signed mean and mean |difference| from the reference over those texels,
 * per channel, as one JSON line on stdout and a human line per result on
 * stderr. Exits 1 when a file cannot be read or does not match, 2 on a bad
 * command line.
 */
#include "bumpbake.h"
#include "core/internal.h"
#include "trace/testing.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_RESULTS 16

typedef struct args {
  const char *map;
  double scale, bias, reach;
  int stride, azimuths;
  int results;
  char *name[MAX_RESULTS], *ao[MAX_RESULTS], *ssbump[MAX_RESULTS];
} args;

static int usage(const char *reason) {
  fprintf(stderr,
          "accuracy_ref: %s\n"
          "usage: accuracy_ref MAP SCALE [--stride K] [--azimuths N] [--bias B] [--reach D] "
          "NAME=AO.exr,SSBUMP.exr ...\n",
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

static int parse_args(int argc, char **argv, args *a) {
  if (argc < 4) return usage("wrong number of arguments");
  memset(a, 0, sizeof *a);
  a->map = argv[1];
  a->stride = 4, a->azimuths = 2048, a->bias = 0.55, a->reach = 0.0;
  if (parse_number(argv[2], 1e-9, &a->scale)) return usage("SCALE must be > 0");
  for (int i = 3; i < argc; i++) {
    double v;
    if (!strncmp(argv[i], "--", 2)) {
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
  return a->results ? 0 : usage("nothing to compare");
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

/* The integral of (a cos + c sin) cos over [start, pi/2]: a lobe above an
 * elevation, where a = B's horizontal part along the azimuth, c = Bz > 0. */
static double lobe_above(const double b[3], double phi, double t) {
  const double a = b[0] * cos(phi) + b[1] * sin(phi), c = b[2];
  const double start = fmax(atan(fmax(t, 0.0)), atan2(-a, c)), end = 0.5 * BB__PI;
  if (start >= end) return 0.0;
  return a * ((end - start) / 2 + (sin(2 * end) - sin(2 * start)) / 4) +
         c * (1.0 - sin(start) * sin(start)) / 2;
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
  bb_json_quoted(stdout, a->map);
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
    bb_json_quoted(stdout, a->name[r]);
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
  bb_status st = bb_height_file_read(a.map, BB_CHANNEL_AUTO, 0.0f, NULL, NULL, &h, NULL, &err);
  if (st == BB_OK) st = bb_image_alloc(&z, h.width, h.height, 1, &err);
  if (st == BB_OK) {
    const float scale = (float)a.scale; /* float times float, as the bake scales */
    for (size_t i = 0; i < (size_t)h.width * (size_t)h.height; i++) z.pixels[i] = scale * h.pixels[i];
    st = bb_pyramid_build(&z, BB_ADDRESS_PERIODIC, &p, &err);
  }
  if (st == BB_OK)
    st = bb_normals_compute(&h, (float)a.scale, BB_NORMAL_VALVE, BB_ADDRESS_PERIODIC, &normal, &err);
  job j = {.a = &a, .p = p, .z = &z, .normal = &normal};
  if (st == BB_OK) {
    if (a.reach == 0.0) a.reach = 8.0 * (h.width > h.height ? h.width : h.height);
    j.columns = (h.width + a.stride - 1) / a.stride;
    const int rows = (h.height + a.stride - 1) / a.stride;
    for (int c = 0; c < 3; c++) bb_basis_vector(c, j.basis[c]);
    j.ao = malloc((size_t)rows * (size_t)j.columns * sizeof(float));
    j.ssbump = malloc(3 * (size_t)rows * (size_t)j.columns * sizeof(float));
    if (!j.ao || !j.ssbump) st = bb__fail(&err, BB_ERR_MEMORY, "out of memory");
    if (st == BB_OK) st = bb__parallel_for(rows, 0, reference_row, &j, NULL, NULL, &err);
  }
  if (st != BB_OK) {
    fprintf(stderr, "accuracy_ref: %s\n", err.message);
    rc = 1;
  } else {
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
