/* bench_trace.c: times the batch trace, the per-ray max-mip march and the brute-force
 * twin on one map.
 *
 *   bench_trace MAP SCALE RAYS THREADS [--subset N] [--bias B] [--peer-ao FILE]
 *   bench_trace --dump-dirs FILE RAYS
 *
 * The first form prepares the map as a bake does (bb_height_load, the default
 * bilateral smoothing, times SCALE, max-mip pyramid, ray set of power 1 on the
 * HL2 basis), times bb_trace_occlusion on THREADS threads, then traces every
 * ray of the set from N deterministic texels (default 2000) one ray at a time,
 * once with bb_ray_occluded_brute and once with bb_ray_occluded, on one thread.
 * A timing under 10 s is repeated to three runs and the median is reported.
 * Prints one JSON line on stdout and a human summary on stderr; exits 1 when
 * the brute-force and max-mip answers disagree on any ray (a benchmark that
 * disagrees is measuring a bug), 2 on a bad command line.
 *
 * With --peer-ao FILE nothing is timed: the subset is traced once by the
 * max-mip march and the ao the Embree peer (valve-embree) would compute from
 * those answers, sum of unblocked d.z over sum of d.z, is compared with FILE,
 * the peer's ao of the same (filtered) map, ray set and bias. This separates
 * "the tracers disagree about a ray" from "the estimators weight rays
 * differently". Prints one JSON line; exits 0 whatever the differences.
 *
 * The second form writes the ray set's unit directions, one "x y z" per line,
 * so another tracer can be run on exactly the same rays.
 */
#include "bumpbake.h"
#include "cli_json.h"

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
#define PEER_AO_TOLERANCE 1e-5 /* one flipped ray moves the peer's ao by >= ~1e-3 */

typedef struct args {
  const char *map;
  double scale;
  int rays, threads, subset;
  double bias;
  const char *peer_ao; /* --peer-ao FILE, or NULL */
} args;

/* Everything prepared once and shared by the timed sections. */
typedef struct field {
  bb_image height;   /* normalised h as loaded */
  bb_image filtered; /* after the default bilateral smoothing */
  bb_image z;        /* heights in texels: scale * filtered */
  bb_pyramid *pyramid;
  bb_rayset rs;
  double seconds_load, seconds_smooth, seconds_pyramid;
} field;

/* The per-ray pass over the subset: texel coordinates and one answer per ray. */
typedef struct subset {
  int count;
  int *x, *y;
  unsigned char *blocked; /* count * ray_count answers, texel-major */
} subset;

static double now_seconds(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int usage(const char *reason) {
  fprintf(stderr,
          "bench_trace: %s\n"
          "usage: bench_trace MAP SCALE RAYS THREADS [--subset N] [--bias B] [--peer-ao "
          "FILE]\n"
          "       bench_trace --dump-dirs FILE RAYS\n",
          reason);
  return 2;
}

/* ------------------------------------------------------------ arguments */

static int parse_int(const char *s, int lo, int hi, int *out) {
  char *end;
  errno = 0;
  long v = strtol(s, &end, 10);
  if (errno || end == s || *end || v < lo || v > hi)
    return 1;
  *out = (int)v;
  return 0;
}

static int parse_positive(const char *s, double *out) {
  char *end;
  errno = 0;
  double v = strtod(s, &end);
  if (errno || end == s || *end || !isfinite(v) || v < 0.0)
    return 1;
  *out = v;
  return 0;
}

/* Returns 0 and fills a, or a usage exit code. */
static int parse_args(int argc, char **argv, args *a) {
  if (argc < 5)
    return usage("wrong number of arguments");
  a->map = argv[1];
  a->subset = DEFAULT_SUBSET;
  a->bias = 0.55;
  a->peer_ao = NULL;
  if (parse_positive(argv[2], &a->scale) || !(a->scale > 0.0))
    return usage("SCALE must be a number > 0");
  if (parse_int(argv[3], 1, 65536, &a->rays))
    return usage("RAYS must be 1..65536");
  if (parse_int(argv[4], 1, 4096, &a->threads))
    return usage("THREADS must be 1..4096");
  for (int i = 5; i < argc; i += 2) {
    if (i + 1 >= argc)
      return usage("option without a value");
    if (!strcmp(argv[i], "--subset")) {
      if (parse_int(argv[i + 1], 0, 1 << 24, &a->subset))
        return usage("--subset must be 0..16777216");
    } else if (!strcmp(argv[i], "--bias")) {
      if (parse_positive(argv[i + 1], &a->bias))
        return usage("--bias must be >= 0");
    } else if (!strcmp(argv[i], "--peer-ao")) {
      a->peer_ao = argv[i + 1];
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
  if (t[0] < 0.0 || t[0] >= REPEAT_UNDER_SECONDS)
    return t[0];
  for (; *runs < MAX_RUNS; (*runs)++) {
    t[*runs] = f(ctx);
    if (t[*runs] < 0.0)
      return t[*runs];
  }
  qsort(t, MAX_RUNS, sizeof t[0], compare_doubles);
  return t[MAX_RUNS / 2];
}

/* ----------------------------------------------------------- preparing */

/* Load -> smooth -> scale -> pyramid -> ray set, as bb_bake does them. */
static bb_status prepare(const args *a, field *f, bb_error *err) {
  double t0 = now_seconds();
  bb_status st = bb_height_load(a->map, BB_CHANNEL_AUTO, &f->height, err);
  double t1 = now_seconds();
  f->seconds_load = t1 - t0;
  if (st != BB_OK)
    return st;
  bb_smooth_options so;
  bb_smooth_options_init(&so);
  st = bb_smooth_bilateral(&f->height, &f->height, &so, &f->filtered, err);
  double t2 = now_seconds();
  f->seconds_smooth = t2 - t1;
  if (st == BB_OK)
    st = bb_image_alloc(&f->z, f->filtered.width, f->filtered.height, 1, err);
  if (st != BB_OK)
    return st;
  /* float times float, exactly as the bake scales its heights */
  const float scale = (float)a->scale;
  const size_t n = (size_t)f->z.width * (size_t)f->z.height;
  for (size_t i = 0; i < n; i++)
    f->z.pixels[i] = scale * f->filtered.pixels[i];
  st = bb_pyramid_build(&f->z, BB_ADDRESS_PERIODIC, &f->pyramid, err);
  if (st == BB_OK)
    st = bb_rayset_make(a->rays, 1.0, BB_BASIS_HL2, &f->rs, err);
  f->seconds_pyramid = now_seconds() - t2;
  return st;
}

static void field_free(field *f) {
  bb_image_free(&f->height);
  bb_image_free(&f->filtered);
  bb_image_free(&f->z);
  bb_pyramid_free(f->pyramid);
  bb_rayset_free(&f->rs);
}

/* --------------------------------------------------------- batch trace */

typedef struct trace_run {
  const field *f;
  bb_trace_options options;
  bb_image vis; /* the last run's result */
  double rays_traced;
  bb_error err;
} trace_run;

static double run_trace(void *ctx) {
  trace_run *r = ctx;
  bb_image_free(&r->vis);
  double t0 = now_seconds();
  bb_status st = bb_trace_occlusion(r->f->pyramid, &r->f->rs, &r->options, &r->vis,
                                    &r->rays_traced, &r->err);
  double t = now_seconds() - t0;
  return st == BB_OK ? t : -1.0;
}

/* ---------------------------------------------------------- the subset */

/* Texels spread evenly and deterministically over the map: the 2D R2
 * low-discrepancy sequence (additive recurrence on the plastic number), which
 * covers the map without the rows or columns a regular stride would favour. */
static int subset_make(subset *s, int count, int width, int height, int rays) {
  s->count = count;
  s->x = malloc((size_t)(count ? count : 1) * sizeof(int));
  s->y = malloc((size_t)(count ? count : 1) * sizeof(int));
  s->blocked = malloc((size_t)(count ? count : 1) * (size_t)rays);
  if (!s->x || !s->y || !s->blocked)
    return 1;
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
  free(s->blocked);
}

typedef int (*occluded_fn)(const bb_pyramid *p, const bb_ray *ray);

typedef struct subset_run {
  const field *f;
  subset *s;
  double bias;
  occluded_fn occluded;
} subset_run;

/* Every ray of the set from every subset texel, one call per ray. */
static double run_subset(void *ctx) {
  subset_run *r = ctx;
  const bb_rayset *rs = &r->f->rs;
  double t0 = now_seconds();
  for (int i = 0; i < r->s->count; i++) {
    bb_ray ray;
    ray.origin[0] = r->s->x[i];
    ray.origin[1] = r->s->y[i];
    ray.origin[2] = (double)*bb_image_texel(&r->f->z, r->s->x[i], r->s->y[i]) + r->bias;
    unsigned char *out = r->s->blocked + (size_t)i * (size_t)rs->ray_count;
    for (int k = 0; k < rs->ray_count; k++) {
      memcpy(ray.direction, rs->direction + 3 * (size_t)k, sizeof ray.direction);
      out[k] = (unsigned char)r->occluded(r->f->pyramid, &ray);
    }
  }
  return now_seconds() - t0;
}

/* Rays answered differently by the two passes. */
static long count_disagreements(const subset *a, const subset *b, int rays) {
  long n = 0;
  for (size_t i = 0; i < (size_t)a->count * (size_t)rays; i++)
    n += a->blocked[i] != b->blocked[i];
  return n;
}

static long count_blocked(const subset *s, int rays) {
  long n = 0;
  for (size_t i = 0; i < (size_t)s->count * (size_t)rays; i++)
    n += s->blocked[i];
  return n;
}

/* Largest |ao| difference at the subset texels between the batch trace and
 * the ao rebuilt from the per-ray answers (information: both should agree to
 * float rounding unless a ray grazes a breakpoint). */
static double ao_max_difference(const subset *s, const bb_rayset *rs,
                                const bb_image *vis) {
  double worst = 0.0;
  for (int i = 0; i < s->count; i++) {
    const unsigned char *b = s->blocked + (size_t)i * (size_t)rs->ray_count;
    double sum = 0.0;
    for (int k = 0; k < rs->ray_count; k++)
      if (!b[k])
        sum += rs->weight_ao[k];
    double ao = rs->total_ao > 0.0 ? sum / rs->total_ao : 1.0;
    double d = fabs(ao - (double)*bb_image_texel(vis, s->x[i], s->y[i]));
    if (d > worst)
      worst = d;
  }
  return worst;
}

/* ------------------------------------------------------------- output */

typedef struct results {
  double trace_s, brute_s, maxmip_s, ao_diff;
  int trace_runs, brute_runs, maxmip_runs;
  long subset_rays, blocked, disagreements;
  long maxrss_kib;
} results;

static double per_second(double work, double seconds) {
  return seconds > 0.0 ? work / seconds : 0.0;
}

static void print_json(const args *a, const field *f, const trace_run *t,
                       const results *r) {
  const double subset_rays = (double)r->subset_rays;
  const double trace_rate = per_second(t->rays_traced, r->trace_s);
  const double brute_rate = per_second(subset_rays, r->brute_s);
  printf("{\"map\":");
  cli_json_quoted(stdout, a->map);
  printf(",\"width\":%d,\"height\":%d,\"scale\":%g,\"rays\":%d,\"threads\":%d,"
         "\"bias\":%g,",
         f->z.width, f->z.height, a->scale, a->rays, a->threads, a->bias);
  printf("\"load_s\":%.6f,\"smooth_s\":%.6f,\"pyramid_s\":%.6f,", f->seconds_load,
         f->seconds_smooth, f->seconds_pyramid);
  printf(
      "\"trace_s\":%.6f,\"trace_runs\":%d,\"trace_rays\":%.0f,\"trace_rays_per_s\":%.6g,",
      r->trace_s, r->trace_runs, t->rays_traced, trace_rate);
  printf("\"subset_texels\":%d,\"subset_rays\":%ld,\"subset_threads\":1,", a->subset,
         r->subset_rays);
  printf("\"brute_s\":%.6f,\"brute_runs\":%d,\"brute_rays_per_s\":%.6g,", r->brute_s,
         r->brute_runs, brute_rate);
  printf("\"maxmip_s\":%.6f,\"maxmip_runs\":%d,\"maxmip_rays_per_s\":%.6g,", r->maxmip_s,
         r->maxmip_runs, per_second(subset_rays, r->maxmip_s));
  printf("\"trace_over_brute\":%.6g,\"blocked_fraction\":%.6g,\"disagreements\":%ld,",
         brute_rate > 0.0 ? trace_rate / brute_rate : 0.0,
         r->subset_rays ? (double)r->blocked / subset_rays : 0.0, r->disagreements);
  printf("\"trace_ao_max_diff\":%.3g,\"maxrss_kib\":%ld}\n", r->ao_diff, r->maxrss_kib);
}

static void print_human(const args *a, const field *f, const trace_run *t,
                        const results *r) {
  fprintf(stderr,
          "bench_trace: %s %dx%d scale %g, %d rays, %d thread(s): trace %.3f s (median "
          "of %d) "
          "= %.1f Mrays/s",
          a->map, f->z.width, f->z.height, a->scale, a->rays, a->threads, r->trace_s,
          r->trace_runs, per_second(t->rays_traced, r->trace_s) / 1e6);
  if (r->subset_rays)
    fprintf(stderr,
            "; subset %d texels: brute %.2f Mrays/s, per-ray max-mip %.2f Mrays/s, "
            "%.1f%% blocked, %ld disagreements",
            a->subset, per_second((double)r->subset_rays, r->brute_s) / 1e6,
            per_second((double)r->subset_rays, r->maxmip_s) / 1e6,
            100.0 * (double)r->blocked / (double)r->subset_rays, r->disagreements);
  fprintf(stderr, "; peak RSS %.1f MiB\n", (double)r->maxrss_kib / 1024.0);
}

/* ------------------------------------------------- agreement with the peer */

/* The peer's ao at subset texel i from our answers: unblocked d.z / all d.z. */
static double peer_style_ao(const subset *s, const bb_rayset *rs, int i) {
  const unsigned char *b = s->blocked + (size_t)i * (size_t)rs->ray_count;
  double open = 0.0, all = 0.0;
  for (int k = 0; k < rs->ray_count; k++) {
    const double dz = rs->direction[3 * (size_t)k + 2];
    all += dz;
    if (!b[k])
      open += dz;
  }
  return all > 0.0 ? open / all : 1.0;
}

/* Traces the subset once and compares the peer-style ao with the peer's file. */
static int peer_agreement(const args *a, const field *f) {
  bb_image peer = {0};
  bb_error err = {{0}};
  if (bb_image_read(a->peer_ao, &peer, NULL, &err) != BB_OK) {
    fprintf(stderr, "bench_trace: %s\n", err.message);
    return 1;
  }
  int rc = 0;
  subset s = {0};
  if (peer.width != f->z.width || peer.height != f->z.height || peer.channels != 1) {
    fprintf(stderr, "bench_trace: %s is %dx%d with %d channel(s), the map %dx%d\n",
            a->peer_ao, peer.width, peer.height, peer.channels, f->z.width, f->z.height);
    rc = 1;
  } else if (subset_make(&s, a->subset, f->z.width, f->z.height, f->rs.ray_count)) {
    fprintf(stderr, "bench_trace: out of memory for the subset\n");
    rc = 1;
  } else {
    subset_run run = {f, &s, a->bias, bb_ray_occluded};
    run_subset(&run);
    double worst = 0.0, sum = 0.0;
    int over = 0;
    for (int i = 0; i < s.count; i++) {
      double d = fabs(peer_style_ao(&s, &f->rs, i) -
                      (double)*bb_image_texel(&peer, s.x[i], s.y[i]));
      sum += d;
      if (d > worst)
        worst = d;
      over += d > PEER_AO_TOLERANCE;
    }
    printf("{\"peer_ao\":");
    cli_json_quoted(stdout, a->peer_ao);
    printf(",\"subset_texels\":%d,\"mean_abs\":%.3g,\"max_abs\":%.3g,\"tolerance\":%g,"
           "\"texels_over\":%d}\n",
           s.count, s.count ? sum / s.count : 0.0, worst, PEER_AO_TOLERANCE, over);
    fprintf(
        stderr,
        "bench_trace: peer-style ao from bumpbake's per-ray answers vs %s at %d texels: "
        "max |d| %.3g, %d texel(s) over %g\n",
        a->peer_ao, s.count, worst, over, PEER_AO_TOLERANCE);
  }
  subset_free(&s);
  bb_image_free(&peer);
  return rc;
}

/* ------------------------------------------------------------ the runs */

/* Brute force and per-ray max-mip over the subset; fills r. Returns 0 or 1. */
static int bench_subset(const args *a, const field *f, const bb_image *vis, results *r) {
  subset brute = {0}, maxmip = {0};
  int fail = subset_make(&brute, a->subset, f->z.width, f->z.height, f->rs.ray_count) ||
             subset_make(&maxmip, a->subset, f->z.width, f->z.height, f->rs.ray_count);
  if (fail) {
    fprintf(stderr, "bench_trace: out of memory for the subset\n");
  } else {
    subset_run rb = {f, &brute, a->bias, bb_ray_occluded_brute};
    subset_run rm = {f, &maxmip, a->bias, bb_ray_occluded};
    r->brute_s = median_seconds(run_subset, &rb, &r->brute_runs);
    r->maxmip_s = median_seconds(run_subset, &rm, &r->maxmip_runs);
    r->subset_rays = (long)a->subset * f->rs.ray_count;
    r->blocked = count_blocked(&brute, f->rs.ray_count);
    r->disagreements = count_disagreements(&brute, &maxmip, f->rs.ray_count);
    r->ao_diff = ao_max_difference(&maxmip, &f->rs, vis);
  }
  subset_free(&brute);
  subset_free(&maxmip);
  return fail;
}

static int bench(const args *a) {
  field f = {0};
  bb_error err = {{0}};
  int rc = 0;
  if (prepare(a, &f, &err) != BB_OK) {
    fprintf(stderr, "bench_trace: %s\n", err.message);
    field_free(&f);
    return 1;
  }
  if (a->peer_ao) {
    rc = peer_agreement(a, &f);
    field_free(&f);
    return rc;
  }
  trace_run t = {.f = &f};
  bb_trace_options_init(&t.options);
  t.options.bias_texels = a->bias;
  t.options.threads = a->threads;
  results r = {0};
  r.trace_s = median_seconds(run_trace, &t, &r.trace_runs);
  if (r.trace_s < 0.0) {
    fprintf(stderr, "bench_trace: %s\n", t.err.message);
    rc = 1;
  }
  if (!rc && a->subset > 0)
    rc = bench_subset(a, &f, &t.vis, &r);
  if (!rc) {
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    r.maxrss_kib = ru.ru_maxrss;
    print_json(a, &f, &t, &r);
    print_human(a, &f, &t, &r);
    if (r.disagreements) {
      fprintf(stderr,
              "bench_trace: brute force and max-mip disagree on %ld of %ld rays\n",
              r.disagreements, r.subset_rays);
      rc = 1;
    }
  }
  bb_image_free(&t.vis);
  field_free(&f);
  return rc;
}

/* --dump-dirs FILE RAYS */
static int dump_dirs(const char *path, const char *rays_text) {
  int rays;
  if (parse_int(rays_text, 1, 65536, &rays))
    return usage("RAYS must be 1..65536");
  bb_rayset rs;
  bb_error err = {{0}};
  if (bb_rayset_make(rays, 1.0, BB_BASIS_HL2, &rs, &err) != BB_OK) {
    fprintf(stderr, "bench_trace: %s\n", err.message);
    return 1;
  }
  FILE *fp = fopen(path, "w");
  int rc = fp ? 0 : 1;
  if (fp) {
    fprintf(fp, "# bumpbake ray set %s: %d unit directions x y z\n", rs.id, rs.ray_count);
    for (int k = 0; k < rs.ray_count; k++) {
      const double *d = rs.direction + 3 * (size_t)k;
      fprintf(fp, "%.17g %.17g %.17g\n", d[0], d[1], d[2]);
    }
    rc = fclose(fp) != 0;
  }
  if (rc)
    fprintf(stderr, "bench_trace: cannot write %s: %s\n", path, strerror(errno));
  bb_rayset_free(&rs);
  return rc;
}

int main(int argc, char **argv) {
  if (argc >= 2 && !strcmp(argv[1], "--dump-dirs")) {
    if (argc != 4)
      return usage("--dump-dirs takes FILE RAYS");
    return dump_dirs(argv[2], argv[3]);
  }
  args a;
  int rc = parse_args(argc, argv, &a);
  return rc ? rc : bench(&a);
}
