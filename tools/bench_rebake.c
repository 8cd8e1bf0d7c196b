/* bench_rebake.c: times edit-local bakes (a context that keeps,
 * bb_bake_context_keep) against whole bakes of the same heights, and
 * checks that they are the same bits.
 *
 *   bench_rebake MAP SCALE [--edit SIDE] [--at X,Y] [--amount A] [--runs N]
 *                [--threads N] [--clamp]
 *
 * Reads MAP as a bake does (bb__height_file_read), bakes it whole through a
 * keeping context (the default maps and options of `bumpbake bake`), then
 * N times (default 10) edits it: a soft brush of SIDE x SIDE texels
 * (default 32) at X,Y (default the middle), A (default 0.1) of normalised
 * height at its centre, added and taken away in turns so that every bake
 * sees a change. Each edited height is baked through the context and whole
 * (bb__bake_checked), each timed in CPU seconds (the process's, all threads) and
 * wall seconds; every map must be the same bits, else it exits 1. Prints
 * the medians, their ratio and one JSON line.
 *
 * Under load, count instructions instead (the whole bake's and the edit's
 * own functions):
 *   valgrind --tool=callgrind --collect-atstart=no --toggle-collect=edit_bake \
 *     build/tools/bench_rebake MAP 64 --runs 1 --threads 1
 * and --toggle-collect=whole_bake for the whole bakes. */
#include "job/job_internal.h"
#include "bake/bake_internal.h"
#include "bumpbake.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

typedef struct args {
  const char *map;
  double scale, amount;
  int side, x, y, runs, threads, clamp, at_given;
} args;

static int usage(const char *why) {
  fprintf(stderr,
          "bench_rebake: %s\nusage: bench_rebake MAP SCALE [--edit SIDE] [--at X,Y] "
          "[--amount A] [--runs N] [--threads N] [--clamp]\n",
          why);
  return 2;
}

static int parse_args(int argc, char **argv, args *a) {
  if (argc < 3)
    return usage("MAP and SCALE are needed");
  *a = (args){.map = argv[1], .amount = 0.1, .side = 32, .runs = 10};
  char *end;
  a->scale = strtod(argv[2], &end);
  if (*end || !(a->scale > 0.0))
    return usage("SCALE must be > 0");
  for (int i = 3; i < argc; i++) {
    if (!strcmp(argv[i], "--clamp")) {
      a->clamp = 1;
      continue;
    }
    if (i + 1 >= argc)
      return usage("an option needs a value");
    const char *v = argv[++i];
    long n = strtol(v, &end, 10);
    if (!strcmp(argv[i - 1], "--edit")) {
      if (*end || n < 1 || n > 4096)
        return usage("--edit must be 1..4096");
      a->side = (int)n;
    } else if (!strcmp(argv[i - 1], "--runs")) {
      if (*end || n < 1 || n > 1000)
        return usage("--runs must be 1..1000");
      a->runs = (int)n;
    } else if (!strcmp(argv[i - 1], "--threads")) {
      if (*end || n < 0 || n > BB_MAX_THREADS)
        return usage("--threads must be 0..4096");
      a->threads = (int)n;
    } else if (!strcmp(argv[i - 1], "--amount")) {
      a->amount = strtod(v, &end);
      if (*end || !isfinite(a->amount))
        return usage("--amount must be a number");
    } else if (!strcmp(argv[i - 1], "--at")) {
      if (sscanf(v, "%d,%d", &a->x, &a->y) != 2 || a->x < 0 || a->y < 0)
        return usage("--at must be X,Y");
      a->at_given = 1;
    } else {
      return usage("unknown option");
    }
  }
  return 0;
}

static double seconds(clockid_t clock) {
  struct timespec t;
  clock_gettime(clock, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* The edit: a soft brush, sign +1 to add it, -1 to take it away again. */
static void brush(bb_image *h, const args *a, int sign) {
  const double r = a->side / 2.0;
  for (int j = 0; j < a->side; j++)
    for (int i = 0; i < a->side; i++) {
      const double dx = (i + 0.5 - r) / r, dy = (j + 0.5 - r) / r, d2 = dx * dx + dy * dy;
      if (d2 >= 1.0)
        continue;
      const int x = (a->x + i) % h->width, y = (a->y + j) % h->height;
      h->pixels[(size_t)y * (size_t)h->width + (size_t)x] +=
          (float)(sign * a->amount * (1.0 - d2) * (1.0 - d2));
    }
}

/* Kept apart (and not inlined) so that callgrind can count each alone. */
__attribute__((noinline)) static bb_status
edit_bake(bb_bake_context *c, const bb_image *h, const bb_bake_options *o,
          bb_bake_result *r, bb_region *changed, bb_error *err) {
  return bb__bake_context_bake(c, h, o, r, changed, err);
}

__attribute__((noinline)) static bb_status whole_bake(const bb_image *h,
                                                      const bb_bake_options *o,
                                                      bb_bake_result *r, bb_error *err) {
  return bb__bake_checked(h, o, r, err);
}

static int same_maps(const bb_bake_result *a, const bb_bake_result *b) {
  for (int k = 0; k < BB_MAP_BAKED_COUNT; k++) {
    const bb_image *x = bb__bake_result_image(a, (bb_map_kind)k);
    const bb_image *y = bb__bake_result_image(b, (bb_map_kind)k);
    if ((x->pixels == NULL) != (y->pixels == NULL))
      return 0;
    if (x->pixels &&
        memcmp(x->pixels, y->pixels,
               (size_t)x->width * (size_t)x->height * (size_t)x->channels * 4))
      return 0;
  }
  return 1;
}

static int by_value(const void *pa, const void *pb) {
  const double a = *(const double *)pa, b = *(const double *)pb;
  return (a > b) - (a < b);
}

static double median(double *v, int n) {
  qsort(v, (size_t)n, sizeof *v, by_value);
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

int main(int argc, char **argv) {
  args a;
  int st = parse_args(argc, argv, &a);
  if (st)
    return st;
  bb_error err = {{0}};
  bb_image h;
  if (bb__height_file_read(a.map, BB_CHANNEL_AUTO, (float)a.scale, NULL, NULL, &h, NULL,
                          &err)) {
    fprintf(stderr, "bench_rebake: %s\n", err.message);
    return 1;
  }
  if (!a.at_given)
    a.x = h.width / 2 - a.side / 2, a.y = h.height / 2 - a.side / 2;
  a.x %= h.width, a.y %= h.height;
  bb_bake_options o;
  bb__bake_options_init(&o);
  o.height_scale = (float)a.scale;
  o.outputs = BB_JOB_DEFAULT_MAPS;
  o.trace.threads = a.threads;
  if (a.clamp)
    o.smooth.addressing = BB_ADDRESS_CLAMP;
  bb_bake_context *c = NULL;
  bb_bake_result r, whole;
  bb_region changed;
  if (bb_bake_context_new(&c, &err) ||
      (bb_bake_context_keep(c, 1), edit_bake(c, &h, &o, &r, &changed, &err))) {
    fprintf(stderr, "bench_rebake: %s\n", err.message);
    return 1;
  }
  bb_bake_result_free(&r);
  double *edit_cpu = calloc((size_t)a.runs, sizeof(double)),
         *edit_wall = calloc((size_t)a.runs, sizeof(double)),
         *whole_cpu = calloc((size_t)a.runs, sizeof(double)),
         *whole_wall = calloc((size_t)a.runs, sizeof(double)),
         *found = calloc((size_t)a.runs, sizeof(double));
  long changed_texels = 0;
  for (int i = 0; i < a.runs; i++) {
    brush(&h, &a, i % 2 ? -1 : 1);
    double c0 = seconds(CLOCK_PROCESS_CPUTIME_ID), w0 = seconds(CLOCK_MONOTONIC);
    if (edit_bake(c, &h, &o, &r, &changed, &err)) {
      fprintf(stderr, "bench_rebake: %s\n", err.message);
      return 1;
    }
    edit_cpu[i] = seconds(CLOCK_PROCESS_CPUTIME_ID) - c0;
    edit_wall[i] = seconds(CLOCK_MONOTONIC) - w0;
    found[i] = r.horizons_found;
    changed_texels += (long)changed.width * changed.height;
    c0 = seconds(CLOCK_PROCESS_CPUTIME_ID), w0 = seconds(CLOCK_MONOTONIC);
    if (whole_bake(&h, &o, &whole, &err)) {
      fprintf(stderr, "bench_rebake: %s\n", err.message);
      return 1;
    }
    whole_cpu[i] = seconds(CLOCK_PROCESS_CPUTIME_ID) - c0;
    whole_wall[i] = seconds(CLOCK_MONOTONIC) - w0;
    if (!same_maps(&r, &whole)) {
      fprintf(stderr,
              "bench_rebake: edit %d: the edit-local bake differs from the whole bake\n",
              i + 1);
      return 1;
    }
    bb_bake_result_free(&r);
    bb_bake_result_free(&whole);
  }
  const double ec = median(edit_cpu, a.runs), ew = median(edit_wall, a.runs),
               wc = median(whole_cpu, a.runs), ww = median(whole_wall, a.runs),
               hf = median(found, a.runs);
  fprintf(stderr,
          "bench_rebake: %dx%d, a %dx%d brush of %g at (%d, %d), %d runs: edit-local "
          "%.3f s CPU "
          "(%.3f wall), whole %.3f s CPU (%.3f wall): %.1f%% of the CPU; horizons found "
          "again "
          "%.0f of %.0f; the same bits\n",
          h.width, h.height, a.side, a.side, a.amount, a.x, a.y, a.runs, ec, ew, wc, ww,
          100.0 * ec / wc, hf, (double)h.width * h.height * bb__bake_slices(&o));
  printf("{\"map\":\"%s\",\"width\":%d,\"height\":%d,\"edit\":%d,\"amount\":%g,\"x\":%d,"
         "\"y\":%d,"
         "\"runs\":%d,\"threads\":%d,\"addressing\":\"%s\",\"edit_cpu_s\":%.6f,"
         "\"edit_wall_s\":%.6f,\"whole_cpu_s\":%.6f,\"whole_wall_s\":%.6f,\"cpu_share\":%"
         ".4f,"
         "\"horizons_found\":%.0f,\"changed_texels_mean\":%.0f,\"identical\":true}\n",
         a.map, h.width, h.height, a.side, a.amount, a.x, a.y, a.runs, a.threads,
         a.clamp ? "clamp" : "periodic", ec, ew, wc, ww, ec / wc, hf,
         (double)changed_texels / a.runs);
  free(edit_cpu), free(edit_wall), free(whole_cpu), free(whole_wall), free(found);
  bb_bake_context_free(c);
  bb_image_free(&h);
  return 0;
}
