/* test_compare.c: bb__compare_images statistics, and `bumpbake compare` / `info` run as a
 * process. */
#define _XOPEN_SOURCE 700 /* mkdtemp, nftw (scratch_dir.h) */
#define _DEFAULT_SOURCE   /* wait4 (child_call.h) */

#include "bumpbake.h"
#include "child_call.h"
#include "hostile_headers.h"
#include "scratch_dir.h"
#include "core/internal.h"
#include "image/image_write.h"
#include "job/job_internal.h"
#include "maps/maps_internal.h"

#include <criterion/criterion.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

/* ---------------------------------------------------------------- helpers */

/* A 2x2, 2-channel pair with differences chosen to be exact in binary:
 *   (0,0): 0.5, 0      (1,0): 0, 0.75
 *   (0,1): 0.25, 0.25  (1,1): 0, 0
 * By hand: sum 1.75 over 8 values -> mean 0.21875; squares 0.9375 -> RMS
 * sqrt(0.1171875); max 0.75 at (1,0) channel 1. */
static float pair_a[8] = {1, 1, 1, 1, 1, 1, 1, 1};
static float pair_b[8] = {1.5f, 1, 1, 0.25f, 0.75f, 1.25f, 1, 1};

static bb_image wrap(float *px, int w, int h, int c) {
  bb_image img = {.width = w, .height = h, .channels = c, .pixels = px};
  return img;
}

/* ------------------------------------------------------------ statistics */

Test(compare, stats_match_hand_computation) {
  bb_image a = wrap(pair_a, 2, 2, 2), b = wrap(pair_b, 2, 2, 2);
  bb_compare_stats s;
  cr_assert_eq(bb__compare_images(&a, &b, 0.5, 0.25, &s, NULL, NULL), BB_OK);
  cr_assert_float_eq(s.mean_abs, 0.21875, 1e-15);
  cr_assert_float_eq(s.rms, sqrt(0.1171875), 1e-15);
  cr_assert_float_eq(s.max_abs, 0.75, 1e-15);
  cr_assert_eq(s.worst_x, 1);
  cr_assert_eq(s.worst_y, 0);
  cr_assert_eq(s.worst_channel, 1);
  cr_assert_eq(s.pixels, 4);
  /* "More than" the threshold: 0.5 at (0,0) is not over 0.5; 0.25 is not over 0.25. */
  cr_assert_eq(s.over_fail, 1, "only (1,0) differs by more than 0.5");
  cr_assert_eq(s.over_warn, 2, "(0,0) and (1,0) differ by more than 0.25");
}

Test(compare, identical_images_give_zero_everything) {
  bb_image a = wrap(pair_a, 2, 2, 2);
  bb_compare_stats s;
  cr_assert_eq(bb__compare_images(&a, &a, 0, 0, &s, NULL, NULL), BB_OK);
  cr_assert_eq(s.mean_abs, 0);
  cr_assert_eq(s.rms, 0);
  cr_assert_eq(s.max_abs, 0);
  cr_assert_eq(s.over_fail, 0, "threshold 0: equal values are not over it");
  cr_assert_eq(s.over_warn, 0);
}

Test(compare, a_pixel_counts_once_however_many_channels_differ) {
  float x[6] = {0, 0, 0, 0, 0, 0}, y[6] = {1, 1, 1, 0, 0, 0};
  bb_image a = wrap(x, 2, 1, 3), b = wrap(y, 2, 1, 3);
  bb_compare_stats s;
  cr_assert_eq(bb__compare_images(&a, &b, 0.5, 0.5, &s, NULL, NULL), BB_OK);
  cr_assert_eq(s.over_fail, 1);
  cr_assert_eq(s.worst_channel, 0, "ties go to the first value in scan order");
}

Test(compare, nan_is_an_infinite_difference) {
  float x[4] = {0, 0, 0, NAN}, y[4] = {0, 0, 0, 0};
  bb_image a = wrap(x, 2, 2, 1), b = wrap(y, 2, 2, 1);
  bb_compare_stats s;
  bb_image diff = {0};
  cr_assert_eq(bb__compare_images(&b, &a, 1e30, 1e30, &s, &diff, NULL), BB_OK);
  cr_assert(isinf(s.max_abs) && s.max_abs > 0);
  cr_assert_eq(s.worst_x, 1);
  cr_assert_eq(s.worst_y, 1);
  cr_assert_eq(s.over_fail, 1, "NaN exceeds any finite threshold");
  cr_assert(isinf(diff.pixels[3]));
  cr_assert_eq(diff.pixels[0], 0);
  bb_image_free(&diff);
}

/* An image with NaN compared with itself passes, as idiff finds it. */
Test(compare, nan_against_nan_does_not_differ) {
  float x[4] = {0, NAN, 1, NAN};
  bb_image a = wrap(x, 2, 2, 1);
  bb_compare_stats s;
  cr_assert_eq(bb__compare_images(&a, &a, 0.0, 0.0, &s, NULL, NULL), BB_OK);
  cr_assert_eq(s.max_abs, 0.0);
  cr_assert_eq(s.over_fail, 0);
  bb_compare_limits l;
  bb__compare_limits_init(&l);
  cr_assert_eq(bb__compare_judge(&s, &l), BB_COMPARE_PASS);
}

Test(compare, equal_infinities_do_not_differ) {
  float x[2] = {INFINITY, -INFINITY};
  bb_image a = wrap(x, 1, 1, 2);
  bb_compare_stats s;
  cr_assert_eq(bb__compare_images(&a, &a, 0, 0, &s, NULL, NULL), BB_OK);
  cr_assert_eq(s.max_abs, 0);
  cr_assert_eq(s.over_fail, 0);
}

Test(compare, diff_image_holds_absolute_differences) {
  bb_image a = wrap(pair_a, 2, 2, 2), b = wrap(pair_b, 2, 2, 2);
  bb_compare_stats s;
  bb_image diff = {0};
  cr_assert_eq(bb__compare_images(&a, &b, 1, 1, &s, &diff, NULL), BB_OK);
  cr_assert_eq(diff.width, 2);
  cr_assert_eq(diff.height, 2);
  cr_assert_eq(diff.channels, 2);
  for (int i = 0; i < 8; i++)
    cr_assert_eq(diff.pixels[i], fabsf(pair_a[i] - pair_b[i]), "value %d", i);
  bb_image_free(&diff);
}

Test(compare, different_shapes_are_a_size_error) {
  float x[8] = {0}, y[8] = {0};
  bb_image a = wrap(x, 2, 2, 2), b = wrap(y, 4, 1, 2), c = wrap(y, 2, 2, 1);
  bb_compare_stats s;
  bb_error err = {{0}};
  cr_assert_eq(bb__compare_images(&a, &b, 0, 0, &s, NULL, &err), BB_ERR_SIZE);
  cr_assert_neq(err.message[0], '\0');
  cr_assert_eq(bb__compare_images(&a, &c, 0, 0, &s, NULL, &err), BB_ERR_SIZE);
}

Test(compare, accumulates_in_double) {
  /* One difference of 2 and a million of 1e-7: a float running sum stalls at
   * 2, where 1e-7 is under half an ulp, and would report a mean of 2/N; the
   * double sum keeps the extra 0.1. */
  enum { W = 1024, H = 1024 };
  bb_image a, b;
  cr_assert_eq(bb_image_alloc(&a, W, H, 1, NULL), BB_OK);
  cr_assert_eq(bb_image_alloc(&b, W, H, 1, NULL), BB_OK);
  for (size_t i = 0; i < (size_t)W * H; i++)
    b.pixels[i] = 1e-7f;
  b.pixels[0] = 2.0f;
  bb_compare_stats s;
  cr_assert_eq(bb__compare_images(&a, &b, 1, 1, &s, NULL, NULL), BB_OK);
  double expect = (2.0 + ((double)W * H - 1) * (double)1e-7f) / ((double)W * H);
  cr_assert_float_eq(s.mean_abs, expect, expect * 1e-9);
  bb_image_free(&a);
  bb_image_free(&b);
}

/* --------------------------------------------------------------- verdict */

/* One comparison as idiff 2.4.7 judged it: a 10 x 10 image where 2 pixels
 * differ by 0.1 and 3 by 0.01 (over_fail and over_warn as
 * bb__compare_images counts them for the thresholds of the row), and the
 * exit code `idiff` itself returned for the same options and images. */
typedef struct verdict_case {
  const char *idiff_options;
  double fail, fail_percent, hard_fail, warn, hard_warn;
  long allow_failures, over_fail, over_warn;
  bb_compare_verdict expect;
} verdict_case;

static const verdict_case verdict_cases[] = {
    {"-fail 0.05", 0.05, 0, INFINITY, 1e-6, INFINITY, 0, 2, 5, BB_COMPARE_FAIL},
    /* No failing pixel: idiff passes, whatever is over -warn. */
    {"-fail 0.2", 0.2, 0, INFINITY, 1e-6, INFINITY, 0, 0, 5, BB_COMPARE_PASS},
    {"-fail 0.2 -hardwarn 0.09", 0.2, 0, INFINITY, 1e-6, 0.09, 0, 0, 5, BB_COMPARE_PASS},
    {"-fail 0.05 -warn 0.2", 0.05, 0, INFINITY, 0.2, INFINITY, 0, 2, 0, BB_COMPARE_FAIL},
    /* Failures allowed by -failpercent are reported as a warning. */
    {"-fail 0.05 -failpercent 2", 0.05, 2, INFINITY, 1e-6, INFINITY, 0, 2, 5,
     BB_COMPARE_WARN},
    {"-fail 0.05 -failpercent 1.9", 0.05, 1.9, INFINITY, 1e-6, INFINITY, 0, 2, 5,
     BB_COMPARE_FAIL},
    {"-fail 0.05 -failpercent 2 -hardfail 0.09", 0.05, 2, 0.09, 1e-6, INFINITY, 0, 2, 5,
     BB_COMPARE_FAIL},
    {"-fail 0.05 -failpercent 2 -hardfail 0.11", 0.05, 2, 0.11, 1e-6, INFINITY, 0, 2, 5,
     BB_COMPARE_WARN},
    /* -allowfailures passes before anything else, -hardfail included. */
    {"-fail 0.05 -allowfailures 2", 0.05, 0, INFINITY, 1e-6, INFINITY, 2, 2, 5,
     BB_COMPARE_PASS},
    {"-fail 0.05 -allowfailures 1", 0.05, 0, INFINITY, 1e-6, INFINITY, 1, 2, 5,
     BB_COMPARE_FAIL},
    {"-fail 0.05 -allowfailures 2 -hardfail 0.09", 0.05, 0, 0.09, 1e-6, INFINITY, 2, 2, 5,
     BB_COMPARE_PASS},
    {"-fail 0.05 -allowfailures 1 -failpercent 2", 0.05, 2, INFINITY, 1e-6, INFINITY, 1, 2,
     5, BB_COMPARE_WARN},
};

Test(compare, verdict_follows_idiff_case_by_case) {
  for (size_t i = 0; i < sizeof verdict_cases / sizeof verdict_cases[0]; i++) {
    const verdict_case *c = &verdict_cases[i];
    bb_compare_limits l;
    bb__compare_limits_init(&l);
    l.fail = c->fail;
    l.fail_percent = c->fail_percent;
    l.hard_fail = c->hard_fail;
    l.warn = c->warn;
    l.hard_warn = c->hard_warn;
    l.allow_failures = c->allow_failures;
    bb_compare_stats s = {.max_abs = 0.1, .pixels = 100, .over_fail = c->over_fail,
                          .over_warn = c->over_warn};
    cr_expect_eq(bb__compare_judge(&s, &l), c->expect, "idiff %s gives %d", c->idiff_options,
                 (int)c->expect);
  }
}

Test(compare, verdict_defaults_are_idiffs) {
  bb_compare_limits l;
  bb__compare_limits_init(&l);
  cr_assert_eq(l.fail, 1e-6);
  cr_assert_eq(l.warn, 1e-6);
  cr_assert(isinf(l.hard_fail) && isinf(l.hard_warn));
  cr_assert_eq(l.fail_percent, 0);
  cr_assert_eq(l.warn_percent, 0);
  cr_assert_eq(l.allow_failures, 0);
  bb_compare_stats same = {.pixels = 16};
  cr_assert_eq(bb__compare_judge(&same, &l), BB_COMPARE_PASS);
  bb_compare_stats one = {.max_abs = 1e-5, .pixels = 16, .over_fail = 1, .over_warn = 1};
  cr_assert_eq(bb__compare_judge(&one, &l), BB_COMPARE_FAIL, "one pixel is enough");
}

/* ------------------------------------------------------- the binary, run */

static const char *bin_path(void) {
  const char *b = getenv("BB_BIN");
  return b && *b ? b : "build/bumpbake";
}

/* Runs `BB_BIN args` with stdout and stderr captured into out; returns the
 * exit code (or -1 if it did not exit normally). */
static int run(char *out, size_t cap, const char *fmt, ...) {
  char args[2048], cmd[2300];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(args, sizeof args, fmt, ap);
  va_end(ap);
  snprintf(cmd, sizeof cmd, "'%s' %s 2>&1", bin_path(), args);
  FILE *p = popen(cmd, "r");
  cr_assert_not_null(p, "cannot run %s", cmd);
  size_t n = fread(out, 1, cap - 1, p);
  out[n] = '\0';
  int status = pclose(p);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/* Writes a w x h x c float image whose values are value_at(i) to name in the
 * temp dir (format from the extension) and returns its path. */
static const char *write_image(const char *name, int w, int h, int c, const float *values,
                               const char *description) {
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, w, h, c, NULL), BB_OK);
  memcpy(img.pixels, values, sizeof(float) * (size_t)(w * h * c));
  bb_write_options wo = {
      .depth = BB_DEPTH_DEFAULT, .range = BB_RANGE_UNIT, .description = description};
  const char *path = in_scratch_dir(name);
  bb_error err = {{0}};
  cr_assert_eq(bb__image_write(path, &img, &wo, &err), BB_OK, "%s", err.message);
  bb_image_free(&img);
  return path;
}

/* 4x4 grey ramp and copies with a known number of pixels changed by delta. */
static float ramp[16];
static const char *ramp_with(const char *name, int changed, float delta) {
  float v[16];
  memcpy(v, ramp, sizeof v);
  for (int i = 0; i < changed; i++)
    v[i * 5 % 16] += delta;
  return write_image(name, 4, 4, 1, v, NULL);
}

static void cli_setup(void) {
  scratch_dir_make("bb_compare");
  for (int i = 0; i < 16; i++)
    ramp[i] = (float)i / 16.0f;
}

TestSuite(compare_cli, .init = cli_setup, .fini = scratch_dir_remove, .timeout = 300);

Test(compare_cli, identical_files_pass_with_exit_0) {
  const char *a = ramp_with("a.exr", 0, 0), *b = ramp_with("b.exr", 0, 0);
  char out[4096];
  cr_assert_eq(run(out, sizeof out, "compare %s %s", a, b), 0, "%s", out);
  cr_assert_not_null(strstr(out, "PASS"), "%s", out);
}

/* `compare` of an EXR holding NaN with itself: it failed (exit 2) where
 * idiff passes. */
Test(compare_cli, an_image_with_nan_passes_against_itself) {
  const float values[4] = {0.25f, NAN, 1.0f, NAN};
  const char *a = write_image("nan.exr", 2, 2, 1, values, NULL);
  char out[4096];
  cr_assert_eq(run(out, sizeof out, "compare %s %s", a, a), 0, "%s", out);
  cr_assert_not_null(strstr(out, "PASS"), "%s", out);
}

Test(compare_cli, allowed_failures_warn_with_exit_1) {
  const char *a = ramp_with("a.exr", 0, 0), *b = ramp_with("b.exr", 3, 0.01f);
  char out[4096];
  /* 3 of 16 pixels (18.75%) fail, within --failpercent 20: idiff calls that a
   * warning (the default --warn is 1e-6, as idiff's). */
  int code = run(out, sizeof out, "compare %s %s --fail 0.001 --failpercent 20", a, b);
  cr_assert_eq(code, 1, "%s", out);
  cr_assert_not_null(strstr(out, "3 pixels (18.8%) over warn 1e-06"), "%s", out);
  cr_assert_not_null(strstr(out, "WARNING"), "%s", out);
  code = run(out, sizeof out, "compare %s %s --fail 0.001 --failpercent 20 --warnpercent 20",
             a, b);
  cr_assert_eq(code, 0, "warnings allowed for 20%% of the pixels: %s", out);
  /* As in idiff, no failing pixel means a pass, whatever is over --warn. */
  code = run(out, sizeof out, "compare %s %s --fail 0.1 --warn 0.001 --hardwarn 0.005", a, b);
  cr_assert_eq(code, 0, "%s", out);
  cr_assert_not_null(strstr(out, "PASS"), "%s", out);
}

Test(compare_cli, idiff_spellings_hardfail_and_allowfailures) {
  const char *a = ramp_with("a.exr", 0, 0), *b = ramp_with("b.exr", 2, 0.5f);
  char out[4096];
  /* 2 of 16 pixels differ by 0.5. */
  cr_assert_eq(run(out, sizeof out, "compare -fail 0.1 %s %s", a, b), 2, "%s", out);
  cr_assert_eq(run(out, sizeof out, "compare %s %s -fail 0.1 -failpercent 12.5", a, b), 1,
               "%s", out);
  cr_assert_eq(
      run(out, sizeof out, "compare %s %s -fail 0.1 -failpercent 12.5 -hardfail 0.4", a, b),
      2, "a difference over -hardfail fails within -failpercent: %s", out);
  cr_assert_not_null(strstr(out, "hard fail 0.4"), "%s", out);
  cr_assert_eq(run(out, sizeof out, "compare %s %s -allowfailures 2", a, b), 0, "%s", out);
  cr_assert_eq(run(out, sizeof out, "compare %s %s -allowfailures 2 -hardfail 0.1", a, b),
               0, "-allowfailures passes them by any amount: %s", out);
  cr_assert_eq(run(out, sizeof out, "compare -q %s %s --allowfailures=1", a, b), 2, "%s",
               out);
  cr_assert_eq(out[0], '\0', "-q prints nothing: %s", out);
  cr_assert_eq(run(out, sizeof out, "compare %s %s -failpercent 101", a, b), 4, "%s", out);
}

/* The exit codes of `idiff` itself (OpenImageIO's tools, when installed) for
 * the cases of compare/verdict_follows_idiff_case_by_case, on real files. */
Test(compare_cli, exit_codes_equal_idiffs) {
  if (system("command -v idiff >/dev/null 2>&1") != 0)
    cr_skip_test("idiff (openimageio-tools) is not installed");
  float va[100], vb[100];
  for (int i = 0; i < 100; i++)
    va[i] = vb[i] = 0.5f;
  vb[0] = vb[1] = 0.625f; /* 2 pixels 0.125 apart, 3 pixels 0.0078125 apart */
  vb[10] = vb[11] = vb[12] = 0.5078125f;
  const char *a = write_image("a.exr", 10, 10, 1, va, NULL);
  const char *b = write_image("b.exr", 10, 10, 1, vb, NULL);
  /* One case per branch of the rule (the unit test has them all): a process
   * of each costs about 0.3 s. */
  static const char *const options[] = {
      "-fail 0.2 -hardwarn 0.09",                   /* no failure: PASS */
      "-fail 0.05 -failpercent 2",                  /* allowed failures: WARNING */
      "-fail 0.05 -failpercent 2 -hardfail 0.09",   /* over -hardfail: FAILURE */
      "-fail 0.05 -allowfailures 2 -hardfail 0.09", /* -allowfailures first: PASS */
      "",                                           /* defaults: FAILURE */
  };
  char out[4096], cmd[1024];
  for (size_t i = 0; i < sizeof options / sizeof options[0]; i++) {
    snprintf(cmd, sizeof cmd, "idiff -q %s '%s' '%s' >/dev/null 2>&1", options[i], a, b);
    int status = system(cmd);
    cr_assert(WIFEXITED(status), "%s", cmd);
    int ours = run(out, sizeof out, "compare %s %s %s", options[i], a, b);
    cr_expect_eq(ours, WEXITSTATUS(status), "'%s': idiff %d, bumpbake %d\n%s", options[i],
                 WEXITSTATUS(status), ours, out);
  }
}

Test(compare_cli, default_tolerance_fails_with_exit_2_and_names_worst_pixel) {
  const char *a = ramp_with("a.exr", 0, 0), *b = ramp_with("b.exr", 1, 0.5f);
  char out[4096];
  cr_assert_eq(run(out, sizeof out, "compare %s %s", a, b), 2, "%s", out);
  cr_assert_not_null(strstr(out, "max abs error  0.5 at pixel (0, 0) channel 0"), "%s",
                     out);
  cr_assert_not_null(strstr(out, "1 pixels (6.25%) over fail 1e-06"), "%s", out);
  cr_assert_not_null(strstr(out, "FAILURE"), "%s", out);
}

Test(compare_cli, failpercent_allows_that_share_of_pixels) {
  const char *a = ramp_with("a.exr", 0, 0), *b = ramp_with("b.exr", 2, 0.5f);
  char out[4096];
  /* 2 of 16 pixels = 12.5%: failure needs MORE than failpercent; failures
   * allowed that way are a warning, as in idiff, unless warnings are too. */
  cr_assert_eq(run(out, sizeof out, "compare %s %s --failpercent 12.5", a, b), 1, "%s",
               out);
  cr_assert_eq(
      run(out, sizeof out, "compare %s %s --failpercent 12.5 --warnpercent 12.5", a, b), 0,
      "%s", out);
  cr_assert_eq(run(out, sizeof out, "compare %s %s --failpercent 12", a, b), 2, "%s",
               out);
  cr_assert_eq(run(out, sizeof out, "compare %s %s --fail 0.5", a, b), 0,
               "a difference equal to the threshold is not over it: %s", out);
}

Test(compare_cli, different_size_or_channels_exit_3) {
  float v[32] = {0};
  const char *a = write_image("a.exr", 4, 4, 1, v, NULL);
  const char *wide = write_image("wide.exr", 8, 2, 1, v, NULL);
  const char *two = write_image("two.exr", 4, 4, 2, v, NULL);
  char out[4096];
  cr_assert_eq(run(out, sizeof out, "compare %s %s", a, wide), 3, "%s", out);
  cr_assert_eq(run(out, sizeof out, "compare %s %s", a, two), 3, "%s", out);
}

Test(compare_cli, unreadable_file_or_bad_arguments_exit_4) {
  const char *a = ramp_with("a.exr", 0, 0);
  const char *junk = in_scratch_dir("junk.png");
  FILE *f = fopen(junk, "w");
  cr_assert_not_null(f);
  fputs("this is not a png", f);
  fclose(f);
  char out[4096];
  cr_assert_eq(run(out, sizeof out, "compare %s %s", a, in_scratch_dir("missing.exr")), 4, "%s",
               out);
  cr_assert_not_null(strstr(out, "bumpbake: "), "%s", out);
  cr_assert_not_null(strstr(out, "missing.exr"), "%s", out);
  cr_assert_eq(run(out, sizeof out, "compare %s %s", junk, a), 4, "%s", out);
  /* Usage errors: exit 4, one line "bumpbake compare: problem". */
  static const char *const bad[] = {"%s", "%s %s --fail", "%s %s --fail -1",
                                    "%s %s --bogus", "%s %s -x", "%s %s -fail nan"};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    char args[512];
    snprintf(args, sizeof args, bad[i], a, a);
    cr_assert_eq(run(out, sizeof out, "compare %s", args), 4, "compare %s: %s", args, out);
    cr_assert(strncmp(out, "bumpbake compare: ", 18) == 0, "compare %s: %s", args, out);
    char *nl = strchr(out, '\n');
    cr_assert(nl && nl[1] == '\0', "one line for compare %s: %s", args, out);
  }
}

/* A diff that would overwrite a compared file is refused before anything
 * is read: exit 4 as every other refusal of compare (1 is a warning). */
Test(compare_cli, a_diff_over_an_input_exits_4) {
  const char *a = ramp_with("a.exr", 0, 0), *b = ramp_with("b.exr", 0, 0);
  char out[4096];
  cr_assert_eq(run(out, sizeof out, "compare %s %s --diff %s", a, b, a), 4, "%s", out);
  cr_assert_not_null(strstr(out, "would overwrite the input"), "%s", out);
}

/* A file over the size limit cannot be read: idiff's 4, as for any file
 * that cannot be read, not 3 ("different size"), which bumpbake gave for
 * a 65535 x 65535 PNG header, an oversize DDS, a TIFF of huge tiles and
 * one of 65535 channels. */
Test(compare_cli, a_file_over_the_size_limit_is_unreadable_exit_4) {
  const char *a = ramp_with("a.exr", 0, 0);
  cr_assert_eq(write_png_header(in_scratch_dir("wide.png"), 65535, 65535), 0);
  cr_assert_eq(write_dds_header(in_scratch_dir("big.dds"), 65536, 65536), 0);
  cr_assert_eq(write_tiled_tiff(in_scratch_dir("tiles.tif"), 1, 1, 16384, 16384), 0);
  cr_assert_eq(write_hostile_tiff(in_scratch_dir("channels.tif"), 4, 4, 65535), 0);
  const char *files[] = {"wide.png", "big.dds", "tiles.tif", "channels.tif"};
  for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) {
    char out[4096];
    const char *path = in_scratch_dir(files[i]);
    cr_expect_eq(run(out, sizeof out, "compare %s %s", i % 2 ? a : path, i % 2 ? path : a), 4,
                 "%s: %s", files[i], out);
    cr_expect(strstr(out, files[i]), "%s: %s", files[i], out);
  }
}

/* A 148-byte DDS header declaring 16384 x 16384 RGBA floats (a sparse 4 GiB
 * file) is within the read's limits, but comparing two took 60 s and 8.5
 * GB: what a comparison will take is worked out from the headers before a
 * pixel is read, refused with the figures when it will not fit, and said
 * when it is large (over what any read takes: 1 GiB). */
static void keep_note(void *user, const char *path, const char *text) {
  snprintf(user, 512, "%s: %s", path, text);
}

static bb_status check_pair(const char *path, bb_error *err) {
  return bb__compare_files_check(path, path, NULL, NULL, NULL, err);
}

Test(compare_cli, a_large_comparison_says_its_cost_before_it_starts) {
  const char *huge = in_scratch_dir("huge.dds"), *big = in_scratch_dir("big.dds");
  cr_assert_eq(write_dds_float_header(huge, 16384, 16384), 0);
  cr_assert_eq(write_dds_float_header(big, 4096, 8192), 0);
  /* under 2 GB of address space: refused from the headers, with both figures */
  child_outcome o = child_call(check_pair, huge, 30, 2000L << 20);
  cr_expect_eq(o.status, BB_ERR_MEMORY, "%s", o.message);
  cr_expect(strstr(o.message,
                   "huge.dds: comparing two 16384 x 16384 images of 4 channels "
                   "needs about 12.6 GiB of memory; "),
            "%s", o.message);
  cr_expect_lt(o.max_rss_kib, 200 * 1024, "it read pixels: %ld KiB", o.max_rss_kib);
  bb_error err = {{0}};
  char note[512] = "";
  uint64_t room = 0;
  cr_assert_eq(bb__memory_available(&room, NULL, NULL), BB_OK);
  if ((double)room < 2.0 * (1 << 30))
    cr_skip_test("less than 2 GiB of memory available for the note's case");
  /* 4096 x 8192 RGBA floats: 512 MiB a file, 1.6 GiB to compare: said */
  cr_assert_eq(bb__compare_files_check(big, big, NULL, keep_note, note, &err), BB_OK, "%s",
               err.message);
  cr_expect(strstr(note,
                   "big.dds: comparing two 4096 x 8192 images of 4 channels takes about "
                   "1.6 GiB of memory ("),
            "%s", note);
  /* a small one: nothing to say */
  note[0] = '\0';
  const char *a = ramp_with("a.exr", 0, 0);
  cr_assert_eq(bb__compare_files_check(a, a, NULL, keep_note, note, &err), BB_OK);
  cr_expect_str_empty(note);
}

Test(compare_cli, diff_exr_holds_raw_absolute_differences) {
  const char *a = ramp_with("a.exr", 0, 0), *b = ramp_with("b.exr", 2, 0.125f);
  char out[4096];
  cr_assert_eq(run(out, sizeof out, "compare %s %s --diff %s", a, b, in_scratch_dir("d.exr")),
               2, "%s", out);
  bb_image d = {0};
  cr_assert_eq(bb_image_read(in_scratch_dir("d.exr"), &d, NULL, NULL), BB_OK);
  cr_assert_eq(d.width, 4);
  cr_assert_eq(d.channels, 1);
  for (int i = 0; i < 16; i++) {
    float expect = (i == 0 || i == 5) ? 0.125f : 0.0f;
    cr_assert_float_eq(d.pixels[i], expect, 1e-7, "pixel %d", i);
  }
  bb_image_free(&d);
}

Test(compare_cli, diff_png_is_scaled_so_the_largest_difference_is_white) {
  const char *a = ramp_with("a.exr", 0, 0);
  float v[16];
  memcpy(v, ramp, sizeof v);
  v[3] += 0.01f;
  v[7] += 0.002f;
  const char *b = write_image("b.exr", 4, 4, 1, v, NULL);
  char out[4096];
  run(out, sizeof out, "compare %s %s --diff %s", a, b, in_scratch_dir("d.png"));
  bb_image d = {0};
  cr_assert_eq(bb_image_read(in_scratch_dir("d.png"), &d, NULL, NULL), BB_OK, "%s", out);
  cr_assert_float_eq(d.pixels[3], 1.0f, 1e-6);
  cr_assert_float_eq(d.pixels[7], 0.2f, 1.0 / 255, "0.002 / 0.01 of full scale");
  cr_assert_eq(d.pixels[0], 0.0f);
  bb_image_free(&d);
}

Test(compare_cli, json_is_one_line_with_the_numbers) {
  const char *a = ramp_with("a.exr", 0, 0), *b = ramp_with("b.exr", 1, 0.5f);
  char out[4096];
  cr_assert_eq(run(out, sizeof out, "compare %s %s --json", a, b), 2, "%s", out);
  cr_assert_eq(out[0], '{', "%s", out);
  char *nl = strchr(out, '\n');
  cr_assert(nl && nl[1] == '\0', "exactly one line: %s", out);
  cr_assert_not_null(strstr(out, "\"max_abs\":0.5,"), "%s", out);
  cr_assert_not_null(strstr(out, "\"worst\":{\"x\":0,\"y\":0,\"channel\":0}"), "%s", out);
  cr_assert_not_null(strstr(out, "\"over_fail\":1,"), "%s", out);
  cr_assert_not_null(strstr(out, "\"result\":\"FAILURE\",\"exit\":2}"), "%s", out);
}

static char *provenance_with_scale(float scale) {
  bb_bake_options o;
  memset(&o, 0, sizeof o);
  o.height_scale = scale;
  o.rays = 64;
  o.power = 1;
  bb_provenance p = {.command = "test",
                     .input_name = "ramp.png",
                     .output_kind = "normal",
                     .options = &o,
                     .rayset_id = "test"};
  return bb__provenance_format(&p);
}

Test(compare_cli, differing_provenance_is_listed) {
  char *p16 = provenance_with_scale(16), *p32 = provenance_with_scale(32);
  const char *a = write_image("a.exr", 4, 4, 1, ramp, p16);
  const char *b = write_image("b.exr", 4, 4, 1, ramp, p32);
  const char *c = write_image("c.exr", 4, 4, 1, ramp, p16);
  char out[4096];
  cr_assert_eq(run(out, sizeof out, "compare %s %s", a, b), 0, "%s", out);
  cr_assert_not_null(strstr(out, "provenance differs:\nscale: 16 -> 32\n"), "%s", out);
  cr_assert_eq(run(out, sizeof out, "compare %s %s", a, c), 0, "%s", out);
  cr_assert_null(strstr(out, "provenance differs"), "%s", out);
  free(p16);
  free(p32);
}

Test(compare_cli, info_prints_size_format_and_provenance) {
  char *p16 = provenance_with_scale(16);
  const char *a = write_image("a.exr", 4, 4, 1, ramp, p16);
  const char *b = write_image("b.png", 4, 4, 1, ramp, NULL);
  char out[4096];
  cr_assert_eq(run(out, sizeof out, "info %s", a), 0, "%s", out);
  cr_assert_not_null(strstr(out, "4 x 4, 1 channel, openexr, 32-bit float"), "%s", out);
  cr_assert_not_null(strstr(out, "provenance:\nbumpbake_version="), "%s", out);
  cr_assert_not_null(strstr(out, "\nscale=16\n"), "%s", out);
  cr_assert_eq(run(out, sizeof out, "info %s", b), 0, "%s", out);
  cr_assert_not_null(strstr(out, "png, 8-bit integer"), "%s", out);
  cr_assert_not_null(strstr(out, "no bumpbake provenance"), "%s", out);
  free(p16);
}

Test(compare_cli, info_on_unreadable_file_is_one_line_and_exit_1) {
  char out[4096];
  cr_assert_eq(run(out, sizeof out, "info %s", in_scratch_dir("missing.png")), 1, "%s", out);
  cr_assert(strncmp(out, "bumpbake: ", 10) == 0, "%s", out);
  char *nl = strchr(out, '\n');
  cr_assert(nl && nl[1] == '\0', "one line: %s", out);
}

Test(compare_cli, damaged_provenance_is_not_diffed) {
  /* As a TGA comment re-wrapped at 80 columns leaves it: a value split. */
  const char *cut = "bumpbake_version=0.1.0\nscale=1\n6\nrays=64\n";
  char *p16 = provenance_with_scale(16);
  const char *a = write_image("a.exr", 4, 4, 1, ramp, p16);
  const char *b = write_image("b.exr", 4, 4, 1, ramp, cut);
  char out[4096];
  cr_assert_eq(run(out, sizeof out, "compare %s %s", a, b), 0, "%s", out);
  cr_assert_null(strstr(out, "provenance differs"), "%s", out);
  cr_assert_not_null(strstr(out, "b.exr: provenance is cut or re-wrapped"), "%s", out);
  free(p16);
}

Test(compare_cli, info_of_a_fresh_bake_lists_its_parameters) {
  float v[256];
  for (int i = 0; i < 256; i++)
    v[i] = (float)((i * 37) % 256) / 255.0f;
  const char *height = write_image("h.png", 16, 16, 1, v, NULL);
  const char *ssbump = in_scratch_dir("ssbump.exr");
  char out[4096];
  int code = run(out, sizeof out,
                 "bake %s --scale 5 --rays 16 --power 2 --clamp --basis hl2+z --quiet "
                 "--ssbump %s",
                 height, ssbump);
  cr_assert_eq(code, 0, "bake failed: %s", out);
  cr_assert_eq(run(out, sizeof out, "info %s", ssbump), 0, "%s", out);
  cr_assert_not_null(strstr(out, "16 x 16, 4 channels, openexr"), "%s", out);
  static const char *const lines[] = {
      "\ninput=h.png\n", "\noutput=ssbump\n", "\nscale=5\n",         "\nrays=16\n",
      "\npower=2\n",     "\nbasis=hl2+z\n",   "\naddressing=clamp\n"};
  for (size_t i = 0; i < sizeof lines / sizeof lines[0]; i++)
    cr_assert_not_null(strstr(out, lines[i]), "missing %s in:\n%s", lines[i] + 1, out);
  bb_image img = {0};
  cr_assert_eq(bb_image_read(height, &img, NULL, NULL), BB_OK);
  char hash[64];
  snprintf(hash, sizeof hash, "\ninput_hash=%016llx\n",
           (unsigned long long)bb__image_hash(&img));
  bb_image_free(&img);
  cr_assert_not_null(strstr(out, hash), "input hash of the decoded height: %s", out);
}

Test(compare_cli, info_takes_several_files_and_reads_headers_only) {
  char *p16 = provenance_with_scale(16);
  const char *a = write_image("a.exr", 4, 4, 1, ramp, p16);
  enum { W = 64, H = 64 };
  float v[W * H * 2];
  for (int i = 0; i < W * H * 2; i++)
    v[i] = (float)((i * 7919) % 251) / 250.0f; /* noise: a long pixel stream */
  const char *b = write_image("b.tif", W, H, 2, v, NULL);
  /* The same TIFF cut in the middle of its pixels: header whole, pixels not.
   * (TIFF, not PNG: libpng's longjmp out of a truncated PNG leaks a few
   * bytes inside OpenImageIO, which the sanitized build reports.) */
  const char *cut = in_scratch_dir("cut.tif");
  struct stat st;
  cr_assert_eq(stat(b, &st), 0);
  char cmd[512];
  snprintf(cmd, sizeof cmd, "head -c %lld '%s' > '%s'", (long long)st.st_size / 2, b, cut);
  cr_assert_eq(system(cmd), 0);
  char out[8192];
  cr_assert_eq(run(out, sizeof out, "compare %s %s", cut, b), 4,
               "the cut file cannot be decoded: %s", out);
  cr_assert_eq(run(out, sizeof out, "info %s %s %s", a, b, cut), 0, "%s", out);
  cr_assert_not_null(strstr(out, "a.exr: 4 x 4, 1 channel, openexr"), "%s", out);
  cr_assert_not_null(strstr(out, "\n\n"), "a blank line between files: %s", out);
  cr_assert_not_null(strstr(out, "b.tif: 64 x 64, 2 channels, tiff, 8-bit integer\n"), "%s",
                     out);
  cr_assert_not_null(strstr(out, "cut.tif: 64 x 64, 2 channels, tiff"),
                     "info reads the header alone: %s", out);
  free(p16);
}

/* The lines of text that start with '{', in order; returns their count. */
static int json_lines(char *text, char **lines, int cap) {
  int n = 0;
  for (char *line = strtok(text, "\n"); line; line = strtok(NULL, "\n"))
    if (line[0] == '{' && n < cap)
      lines[n++] = line;
  return n;
}

Test(compare_cli, info_json_is_one_object_per_file) {
  char *p16 = provenance_with_scale(16);
  const char *a = write_image("a.exr", 4, 4, 1, ramp, p16);
  /* A name JSON must escape: quote, backslash, tab. */
  const char *odd = write_image("o\"d\\d\t.png", 4, 4, 3, (float[48]){0}, "made elsewhere");
  const char *missing = in_scratch_dir("missing.png");
  char out[8192];
  cr_assert_eq(run(out, sizeof out, "info --json %s '%s' %s", a, odd, missing), 1,
               "a missing file: exit 1: %s", out);
  cr_assert_not_null(strstr(out, "bumpbake: "), "its error on stderr: %s", out);
  char *lines[8];
  cr_assert_eq(json_lines(out, lines, 8), 3, "one line per file");
  cr_assert_not_null(strstr(lines[0], "\"width\":4,\"height\":4,\"channels\":1,"
                                      "\"format\":\"openexr\",\"bits_per_sample\":32,"
                                      "\"float\":true,"),
                     "%s", lines[0]);
  cr_assert_not_null(strstr(lines[0], "\"provenance_state\":\"intact\",\"provenance\":{"
                                      "\"bumpbake_version\":"),
                     "%s", lines[0]);
  cr_assert_not_null(strstr(lines[0], ",\"scale\":\"16\","), "%s", lines[0]);
  cr_assert_not_null(strstr(lines[1], "o\\\"d\\\\d\\t.png\",\"width\""), "escaped: %s",
                     lines[1]);
  cr_assert_not_null(strstr(lines[1], "\"provenance_state\":\"none\",\"provenance\":null,"
                                      "\"description\":\"made elsewhere\"}"),
                     "%s", lines[1]);
  cr_assert_not_null(strstr(lines[2], "missing.png\",\"error\":\""), "%s", lines[2]);
  free(p16);
}

Test(compare_cli, tga_provenance_is_compared_key_by_key) {
  float v[256];
  for (int i = 0; i < 256; i++)
    v[i] = (float)((i * 37) % 256) / 255.0f;
  write_image("h1.png", 16, 16, 1, v, NULL);
  write_image("h2.png", 16, 16, 1, v, NULL);
  char out[8192];
  cr_assert_eq(run(out, sizeof out, "height2ssbump -r 4 %s 4", in_scratch_dir("h1.png")), 0, "%s",
               out);
  cr_assert_eq(run(out, sizeof out, "height2ssbump -r 4 %s 8", in_scratch_dir("h2.png")), 0, "%s",
               out);
  const char *t1 = in_scratch_dir("h1-ssbump.tga"), *t2 = in_scratch_dir("h2-ssbump.tga");
  cr_assert_eq(run(out, sizeof out, "info %s", t1), 0, "%s", out);
  cr_assert_not_null(strstr(out, "provenance:\n"), "intact, not cut: %s", out);
  cr_assert_not_null(strstr(out, "\ninput=h1.png\n"), "%s", out);
  run(out, sizeof out, "compare %s %s", t1, t2);
  cr_assert_not_null(strstr(out, "provenance differs:\n"), "%s", out);
  cr_assert_not_null(strstr(out, "\nscale: 4 -> 8\n"), "%s", out);
  cr_assert_not_null(strstr(out, "\ninput: h1.png -> h2.png\n"), "%s", out);
  cr_assert_null(strstr(out, "cut or re-wrapped"), "%s", out);
}

/* ------------------------------------------------ a report's words and code */

/* bb__compare_files on files, its report in idiff's words and exit code: the
 * one rule `bumpbake compare` and Python's bumpbake.compare both print. */
Test(compare_cli, report_result_and_exit_code_are_idiffs) {
  const char *a = ramp_with("ra.exr", 0, 0), *same = ramp_with("rs.exr", 0, 0);
  const char *off = ramp_with("ro.exr", 3, 0.25f);
  float wide[32] = {0};
  const char *other = write_image("rw.exr", 8, 4, 1, wide, NULL);
  struct {
    const char *b;
    long allow;
    double fail_percent;
    const char *result;
    int code;
  } cases[] = {
      {same, 0, 0, "PASS", 0},
      {off, 0, 0, "FAILURE", 2},
      {off, 0, 50, "WARNING", 1}, /* 3 of 16 fail, within 50 %: warned */
      {off, 3, 0, "PASS", 0},     /* allowed failures pass by any amount */
      {other, 0, 0, "DIFFERENT SIZE", 3},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    bb_compare_limits l;
    bb__compare_limits_init(&l);
    l.allow_failures = cases[i].allow;
    l.fail_percent = cases[i].fail_percent;
    bb_compare_report r;
    bb_error err = {{0}};
    cr_assert_eq(bb__compare_files(a, cases[i].b, &l, NULL, &r, &err), BB_OK, "%s",
                 err.message);
    cr_expect_str_eq(r.result, cases[i].result, "case %zu", i);
    cr_expect_eq(bb__compare_report_exit_code(&r), cases[i].code, "case %zu", i);
    bb__compare_report_free(&r);
  }
  cr_assert_eq(BB_COMPARE_DIFFERENT_SIZE, 3, "idiff's exit code for a size mismatch");
}

/* Limits out of range are refused by the library, naming idiff's option,
 * so every caller (the CLI parses its own ranges; Python does not) gets
 * the same answer; bb__compare_files checks them before reading. */
Test(compare_cli, limits_out_of_range_are_refused) {
  bb_compare_limits l;
  bb__compare_limits_init(&l);
  bb_error err = {{0}};
  cr_assert_eq(bb__compare_limits_check(&l, &err), BB_OK, "idiff's defaults");
  l.hard_fail = l.hard_warn = INFINITY;
  l.fail_percent = l.warn_percent = 100.0;
  cr_expect_eq(bb__compare_limits_check(&l, &err), BB_OK, "the ends of the ranges");
  const struct {
    int field;
    double value;
    const char *message;
  } bad[] = {{0, -1e-6, "compare: fail must be >= 0 (got -1e-6)"},
             {1, 150.0, "compare: failpercent must be in 0..100 (got 150)"},
             {2, NAN, "compare: hardfail must be >= 0 (got nan)"},
             {3, -1.0, "compare: warn must be >= 0 (got -1)"},
             {4, -0.5, "compare: warnpercent must be in 0..100 (got -0.5)"},
             {5, -INFINITY, "compare: hardwarn must be >= 0 (got -inf)"}};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    bb__compare_limits_init(&l);
    double *fields[] = {&l.fail, &l.fail_percent, &l.hard_fail,
                        &l.warn, &l.warn_percent, &l.hard_warn};
    *fields[bad[i].field] = bad[i].value;
    cr_expect_eq(bb__compare_limits_check(&l, &err), BB_ERR_ARGUMENT, "case %zu", i);
    cr_expect_str_eq(err.message, bad[i].message);
  }
  bb__compare_limits_init(&l);
  l.allow_failures = -1;
  cr_expect_eq(bb__compare_limits_check(&l, &err), BB_ERR_ARGUMENT);
  cr_expect_str_eq(err.message, "compare: allowfailures must be >= 0 (got -1)");
  /* Before any read: the files need not exist. */
  bb_compare_report r;
  cr_expect_eq(bb__compare_files(in_scratch_dir("none1.png"), in_scratch_dir("none2.png"), &l, NULL, &r,
                                &err),
               BB_ERR_ARGUMENT);
  cr_expect_str_eq(err.message, "compare: allowfailures must be >= 0 (got -1)");
}
