/* bench_trace.c: times the batch trace (line sweeps), the per-texel
 * max-mip horizon march and its brute-force twin on one map, and checks that
 * they agree.
 *
 *   bench_trace MAP SCALE RAYS THREADS [--subset N] [--bias B] [--slices A]
 *               [--clamp]
 *
 * Prepares the map as a bake does (bb__height_file_read, the default bilateral
 * smoothing, times SCALE, max-mip pyramid, round(sqrt(RAYS)) slices of power
 * 1 on the HL2 basis, or A slices), times bb__trace_occlusion on THREADS
 * threads, then finds every slice's horizon at N deterministic texels
 * (default 2000) one at a time on one thread, once by the max-mip march and
 * once by brute force, and traces each of those texels alone as a one-texel
 * region (by marches) to compare with the whole trace. A timing under 10 s
 * is repeated to three runs and the median is reported. Prints one JSON
 * line on stdout and a human summary on stderr; exits 1 when the march and
 * brute force disagree on any horizon or a region differs from the whole
 * trace in any bit (a benchmark that disagrees is measuring a bug), 2 on a
 * bad command line.
 */
#include "job/job_internal.h"
#include "bumpbake.h"
#include "trace/march.h"
#include "trace/rayset.h"
#include "bake/bake_internal.h"
#include "core/internal.h"
#include "trace/pyramid.h"
#include "trace/trace.h"
#include "core/json.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>

#define DEFAULT_SUBSET 2000
#define REPEAT_UNDER_SECONDS 10.0 /* a timing shorter than this is taken 3 times */
#define MAX_RUNS 3

typedef struct args {
  const char *map;
  double scale;
  int rays, slices, threads, subset;
  double bias;
  bb_addressing addressing;
} args;

/* Everything prepared once and shared by the timed sections. */
typedef struct field {
  bb_image height, filtered, z;
  bb_pyramid *pyramid;
  bb_rayset *rs;
} field;

static double now_seconds(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int usage(const char *reason) {
  fprintf(stderr,
          "bench_trace: %s\n"
          "usage: bench_trace MAP SCALE RAYS THREADS [--subset N] [--bias B] [--slices A] "
          "[--clamp]\n",
          reason);
  return 2;
}

/* ------------------------------------------------------------ arguments */

static int parse_int(const char *s, int lo, int hi, int *out) {
  char *end;
  errno = 0;
  long v = strtol(s, &end, 10);
  if (errno || end == s || *end || v < lo || v > hi) return 1;
  *out = (int)v;
  return 0;
}

static int parse_nonnegative(const char *s, double *out) {
  char *end;
  errno = 0;
  double v = strtod(s, &end);
  if (errno || end == s || *end || !isfinite(v) || v < 0.0) return 1;
  *out = v;
  return 0;
}

/* Returns 0 and fills a, or a usage exit code. */
static int parse_args(int argc, char **argv, args *a) {
  if (argc < 5) return usage("wrong number of arguments");
  *a = (args){.map = argv[1], .subset = DEFAULT_SUBSET, .bias = 0.55};
  if (parse_nonnegative(argv[2], &a->scale) || !(a->scale > 0.0))
    return usage("SCALE must be a number > 0");
  if (parse_int(argv[3], 1, 65536, &a->rays)) return usage("RAYS must be 1..65536");
  if (parse_int(argv[4], 1, 4096, &a->threads)) return usage("THREADS must be 1..4096");
  a->slices = bb__slices_for_rays(a->rays);
  for (int i = 5; i < argc; i++) {
    if (!strcmp(argv[i], "--clamp")) {
      a->addressing = BB_ADDRESS_CLAMP;
      continue;
    }
    if (i + 1 >= argc) return usage("option without a value");
    const char *v = argv[++i];
    if (!strcmp(argv[i - 1], "--subset")) {
      if (parse_int(v, 0, 1 << 24, &a->subset)) return usage("--subset must be 0..16777216");
    } else if (!strcmp(argv[i - 1], "--bias")) {
      if (parse_nonnegative(v, &a->bias)) return usage("--bias must be >= 0");
    } else if (!strcmp(argv[i - 1], "--slices")) {
      if (parse_int(v, 1, BB_MAX_SLICES, &a->slices)) return usage("--slices must be 1..256");
    } else {
      return usage("unknown option");
    }
  }
  return 0;
}

/* -------------------------------------------------------------- timing */

typedef double (*timed_fn)(void *ctx); /* one run; returns its seconds, < 0 on failure */

static int compare_doubles(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

/* Runs f once, and twice more when that took under REPEAT_UNDER_SECONDS;
 * returns the median seconds (negative on failure) and the runs in *runs. */
static double median_seconds(timed_fn f, void *ctx, int *runs) {
  double t[MAX_RUNS];
  t[0] = f(ctx);
  *runs = 1;
  if (t[0] < 0.0 || t[0] >= REPEAT_UNDER_SECONDS) return t[0];
  for (; *runs < MAX_RUNS; (*runs)++) {
    t[*runs] = f(ctx);
    if (t[*runs] < 0.0) return t[*runs];
  }
  qsort(t, MAX_RUNS, sizeof t[0], compare_doubles);
  return t[MAX_RUNS / 2];
}

/* ----------------------------------------------------------- preparing */

/* Load -> smooth -> scale -> pyramid -> slices, as bb__bake_checked does them. */
static bb_status prepare(const args *a, field *f, bb_error *err) {
  bb_status st = bb__height_file_read(a->map, BB_CHANNEL_AUTO, 0.0f, NULL, NULL, &f->height, NULL, err);
  if (st != BB_OK) return st;
  bb_smooth_options so;
  bb__smooth_options_init(&so);
  so.addressing = a->addressing;
  st = bb__smooth_bilateral_all_cores(&f->height, &f->height, &so, &f->filtered, err);
  if (st == BB_OK) st = bb_image_alloc(&f->z, f->filtered.width, f->filtered.height, 1, err);
  if (st != BB_OK) return st;
  const float scale = (float)a->scale; /* float times float, exactly as the bake scales */
  const size_t n = (size_t)f->z.width * (size_t)f->z.height;
  for (size_t i = 0; i < n; i++) f->z.pixels[i] = scale * f->filtered.pixels[i];
  st = bb__pyramid_build_all_cores(&f->z, a->addressing, &f->pyramid, err);
  if (st == BB_OK) st = bb__rayset_new(a->slices, 1.0, NULL, &f->rs, err);
  return st;
}

static void field_free(field *f) {
  bb_image_free(&f->height);
  bb_image_free(&f->filtered);
  bb_image_free(&f->z);
  bb_pyramid_free(f->pyramid);
  bb_rayset_free(f->rs);
}

/* --------------------------------------------------------- batch trace */

typedef struct trace_run {
  const field *f;
  bb_trace_options options;
  bb_image vis; /* the last run's result */
  double horizons;
  bb_error err;
} trace_run;

static double run_trace(void *ctx) {
  trace_run *r = ctx;
  bb_image_free(&r->vis);
  double t0 = now_seconds();
  bb_status st =
      bb__trace_occlusion(r->f->pyramid, r->f->rs, &r->options, &r->vis, &r->horizons, &r->err);
  double t = now_seconds() - t0;
  return st == BB_OK ? t : -1.0;
}

/* ---------------------------------------------------------- the subset */

/* Texels spread evenly and deterministically over the map: the 2D R2
 * low-discrepancy sequence (additive recurrence on the plastic number), which
 * covers the map without the rows or columns a regular stride would favour. */
typedef struct subset {
  int count;
  int *x, *y;
  float *horizon; /* count * slices */
} subset;

static int subset_make(subset *s, int count, int width, int height, int slices) {
  s->count = count;
  s->x = malloc((size_t)(count ? count : 1) * sizeof(int));
  s->y = malloc((size_t)(count ? count : 1) * sizeof(int));
  s->horizon = malloc((size_t)(count ? count : 1) * (size_t)slices * sizeof(float));
  if (!s->x || !s->y || !s->horizon) return 1;
  const double g = 1.32471795724474602596, a1 = 1.0 / g, a2 = 1.0 / (g * g);
  for (int i = 0; i < count; i++) {
    double u = fmod(0.5 + a1 * (i + 1), 1.0), v = fmod(0.5 + a2 * (i + 1), 1.0);
    s->x[i] = (int)(u * width) % width;
    s->y[i] = (int)(v * height) % height;
  }
  return 0;
}

static void subset_free(subset *s) {
  free(s->x);
  free(s->y);
  free(s->horizon);
}

typedef float (*horizon_fn)(const bb_pyramid *p, int x, int y, double bias, int a, int b);

typedef struct subset_run {
  const field *f;
  subset *s;
  double bias;
  horizon_fn horizon;
} subset_run;

/* Every slice's horizon at every subset texel, one call each. */
static double run_subset(void *ctx) {
  subset_run *r = ctx;
  const bb_rayset *rs = r->f->rs;
  double t0 = now_seconds();
  for (int i = 0; i < r->s->count; i++)
    for (int k = 0; k < rs->slice_count; k++)
      r->s->horizon[(size_t)i * (size_t)rs->slice_count + (size_t)k] =
          r->horizon(r->f->pyramid, r->s->x[i], r->s->y[i], r->bias, rs->slice_step[2 * k],
                     rs->slice_step[2 * k + 1]);
  return now_seconds() - t0;
}

static long count_disagreements(const subset *a, const subset *b, int slices) {
  long n = 0;
  for (size_t i = 0; i < (size_t)a->count * (size_t)slices; i++) n += a->horizon[i] != b->horizon[i];
  return n;
}

/* Subset texels whose one-texel region trace differs in any bit from the
 * whole trace's. */
static long region_mismatches(const field *f, const subset *s, const bb_trace_options *o,
                              const bb_image *whole) {
  long n = 0;
  bb_trace_options one = *o;
  one.threads = 1;
  for (int i = 0; i < s->count; i++) {
    one.region = (bb_region){s->x[i], s->y[i], 1, 1};
    bb_image vis = {0};
    if (bb__trace_occlusion(f->pyramid, f->rs, &one, &vis, NULL, NULL) != BB_OK) return -1;
    n += memcmp(vis.pixels, bb_image_texel(whole, s->x[i], s->y[i]),
                (size_t)vis.channels * sizeof(float)) != 0;
    bb_image_free(&vis);
  }
  return n;
}

/* ------------------------------------------------------------- output */

typedef struct results {
  double trace_s, brute_s, march_s;
  int trace_runs, brute_runs, march_runs;
  long subset_horizons, positive, disagreements, mismatches;
  long maxrss_kib;
} results;

static double per_second(double work, double seconds) {
  return seconds > 0.0 ? work / seconds : 0.0;
}

static void print_json(const args *a, const field *f, const trace_run *t, const results *r) {
  printf("{\"map\":");
  bb__json_quoted(stdout, a->map);
  printf(",\"width\":%d,\"height\":%d,\"scale\":%g,\"rays\":%d,\"slices\":%d,\"threads\":%d,"
         "\"addressing\":\"%s\",\"bias\":%g,\"rayset\":",
         f->z.width, f->z.height, a->scale, a->rays, f->rs->slice_count, a->threads,
         a->addressing == BB_ADDRESS_CLAMP ? "clamp" : "periodic", a->bias);
  bb__json_quoted(stdout, f->rs->id);
  printf(",\"trace_s\":%.6f,\"trace_runs\":%d,\"horizons\":%.0f,\"horizons_per_s\":%.6g,"
         "\"subset_texels\":%d,\"subset_horizons\":%ld,\"positive_fraction\":%.6g,"
         "\"march_s\":%.6f,\"march_runs\":%d,\"march_horizons_per_s\":%.6g,"
         "\"brute_s\":%.6f,\"brute_runs\":%d,\"brute_horizons_per_s\":%.6g,"
         "\"trace_over_brute\":%.6g,\"disagreements\":%ld,\"region_mismatches\":%ld,"
         "\"maxrss_kib\":%ld}\n",
         r->trace_s, r->trace_runs, t->horizons, per_second(t->horizons, r->trace_s), a->subset,
         r->subset_horizons,
         r->subset_horizons ? (double)r->positive / (double)r->subset_horizons : 0.0, r->march_s,
         r->march_runs, per_second((double)r->subset_horizons, r->march_s), r->brute_s,
         r->brute_runs, per_second((double)r->subset_horizons, r->brute_s),
         per_second(t->horizons, r->trace_s) /
             (r->brute_s > 0 ? (double)r->subset_horizons / r->brute_s : 1.0),
         r->disagreements, r->mismatches, r->maxrss_kib);
}

static void print_human(const field *f, const trace_run *t, const results *r) {
  fprintf(stderr,
          "bench_trace: %dx%d, %d slices: trace %.3f s (median of %d), %.1f M horizons/s; "
          "march %.3f M/s, brute force %.3f M/s over %ld horizons; %ld disagreements, %ld "
          "region mismatches\n",
          f->z.width, f->z.height, f->rs->slice_count, r->trace_s, r->trace_runs,
          per_second(t->horizons, r->trace_s) / 1e6,
          per_second((double)r->subset_horizons, r->march_s) / 1e6,
          per_second((double)r->subset_horizons, r->brute_s) / 1e6, r->subset_horizons,
          r->disagreements, r->mismatches);
}

/* ---------------------------------------------------------------- main */

static int bench_subset(const args *a, const field *f, const trace_run *t, results *r) {
  subset march = {0}, brute = {0};
  const int slices = f->rs->slice_count;
  int fail = subset_make(&march, a->subset, f->z.width, f->z.height, slices) ||
             subset_make(&brute, a->subset, f->z.width, f->z.height, slices);
  if (!fail) {
    subset_run rm = {f, &march, a->bias, bb__slice_horizon};
    subset_run rb = {f, &brute, a->bias, bb__slice_horizon_brute};
    r->march_s = median_seconds(run_subset, &rm, &r->march_runs);
    r->brute_s = median_seconds(run_subset, &rb, &r->brute_runs);
    r->subset_horizons = (long)a->subset * slices;
    r->disagreements = count_disagreements(&march, &brute, slices);
    for (long i = 0; i < r->subset_horizons; i++) r->positive += march.horizon[i] > 0.0f;
    r->mismatches = region_mismatches(f, &march, &t->options, &t->vis);
    fail = r->mismatches < 0;
  }
  subset_free(&march);
  subset_free(&brute);
  return fail;
}

static int bench(const args *a) {
  field f = {0};
  bb_error err = {{0}};
  if (prepare(a, &f, &err) != BB_OK) {
    fprintf(stderr, "bench_trace: %s\n", err.message);
    field_free(&f);
    return 1;
  }
  trace_run t = {.f = &f};
  bb__trace_options_init(&t.options);
  t.options.threads = a->threads;
  t.options.bias_texels = a->bias;
  results r = {0};
  r.trace_s = median_seconds(run_trace, &t, &r.trace_runs);
  int rc = 0;
  if (r.trace_s < 0.0) {
    fprintf(stderr, "bench_trace: %s\n", t.err.message);
    rc = 1;
  } else if (bench_subset(a, &f, &t, &r)) {
    fprintf(stderr, "bench_trace: out of memory for the subset\n");
    rc = 1;
  } else {
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    r.maxrss_kib = ru.ru_maxrss;
    print_json(a, &f, &t, &r);
    print_human(&f, &t, &r);
    if (r.disagreements || r.mismatches) {
      fprintf(stderr, "bench_trace: the march, brute force and the sweeps disagree\n");
      rc = 1;
    }
  }
  bb_image_free(&t.vis);
  field_free(&f);
  return rc;
}

int main(int argc, char **argv) {
  args a;
  int rc = parse_args(argc, argv, &a);
  return rc ? rc : bench(&a);
}
