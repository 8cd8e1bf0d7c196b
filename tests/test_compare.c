/* test_compare.c: bb_compare_images statistics, and `bumpbake compare` / `info` run as a
 * process. */
#include "bumpbake.h"

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
  cr_assert_eq(bb_compare_images(&a, &b, 0.5, 0.25, &s, NULL, NULL), BB_OK);
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
  cr_assert_eq(bb_compare_images(&a, &a, 0, 0, &s, NULL, NULL), BB_OK);
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
  cr_assert_eq(bb_compare_images(&a, &b, 0.5, 0.5, &s, NULL, NULL), BB_OK);
  cr_assert_eq(s.over_fail, 1);
  cr_assert_eq(s.worst_channel, 0, "ties go to the first value in scan order");
}

Test(compare, nan_is_an_infinite_difference) {
  float x[4] = {0, 0, 0, NAN}, y[4] = {0, 0, 0, 0};
  bb_image a = wrap(x, 2, 2, 1), b = wrap(y, 2, 2, 1);
  bb_compare_stats s;
  bb_image diff = {0};
  cr_assert_eq(bb_compare_images(&b, &a, 1e30, 1e30, &s, &diff, NULL), BB_OK);
  cr_assert(isinf(s.max_abs) && s.max_abs > 0);
  cr_assert_eq(s.worst_x, 1);
  cr_assert_eq(s.worst_y, 1);
  cr_assert_eq(s.over_fail, 1, "NaN exceeds any finite threshold");
  cr_assert(isinf(diff.pixels[3]));
  cr_assert_eq(diff.pixels[0], 0);
  bb_image_free(&diff);
}

Test(compare, equal_infinities_do_not_differ) {
  float x[2] = {INFINITY, -INFINITY};
  bb_image a = wrap(x, 1, 1, 2);
  bb_compare_stats s;
  cr_assert_eq(bb_compare_images(&a, &a, 0, 0, &s, NULL, NULL), BB_OK);
  cr_assert_eq(s.max_abs, 0);
  cr_assert_eq(s.over_fail, 0);
}

Test(compare, diff_image_holds_absolute_differences) {
  bb_image a = wrap(pair_a, 2, 2, 2), b = wrap(pair_b, 2, 2, 2);
  bb_compare_stats s;
  bb_image diff = {0};
  cr_assert_eq(bb_compare_images(&a, &b, 1, 1, &s, &diff, NULL), BB_OK);
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
  cr_assert_eq(bb_compare_images(&a, &b, 0, 0, &s, NULL, &err), BB_ERR_SIZE);
  cr_assert_neq(err.message[0], '\0');
  cr_assert_eq(bb_compare_images(&a, &c, 0, 0, &s, NULL, &err), BB_ERR_SIZE);
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
  cr_assert_eq(bb_compare_images(&a, &b, 1, 1, &s, NULL, NULL), BB_OK);
  double expect = (2.0 + ((double)W * H - 1) * (double)1e-7f) / ((double)W * H);
  cr_assert_float_eq(s.mean_abs, expect, expect * 1e-9);
  bb_image_free(&a);
  bb_image_free(&b);
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

static char tmp_dir[64];

static void make_tmp_dir(void) {
  snprintf(tmp_dir, sizeof tmp_dir, "/tmp/bb-compare-XXXXXX");
  cr_assert_not_null(mkdtemp(tmp_dir));
}

static void remove_tmp_dir(void) {
  char cmd[128];
  snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmp_dir);
  if (system(cmd) != 0)
    fprintf(stderr, "cannot remove %s\n", tmp_dir);
}

static const char *tmp_file(const char *name) {
  static char paths[8][160];
  static int next;
  char *p = paths[next++ % 8];
  snprintf(p, sizeof paths[0], "%s/%s", tmp_dir, name);
  return p;
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
  const char *path = tmp_file(name);
  bb_error err = {{0}};
  cr_assert_eq(bb_image_write(path, &img, &wo, &err), BB_OK, "%s", err.message);
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
  make_tmp_dir();
  for (int i = 0; i < 16; i++)
    ramp[i] = (float)i / 16.0f;
}

TestSuite(compare_cli, .init = cli_setup, .fini = remove_tmp_dir, .timeout = 30);

Test(compare_cli, identical_files_pass_with_exit_0) {
  const char *a = ramp_with("a.exr", 0, 0), *b = ramp_with("b.exr", 0, 0);
  char out[4096];
  cr_assert_eq(run(out, sizeof out, "compare %s %s", a, b), 0, "%s", out);
  cr_assert_not_null(strstr(out, "PASS"), "%s", out);
}

Test(compare_cli, small_differences_warn_with_exit_1) {
  const char *a = ramp_with("a.exr", 0, 0), *b = ramp_with("b.exr", 3, 0.01f);
  char out[4096];
  int code = run(out, sizeof out, "compare %s %s --fail 0.1 --warn 0.001", a, b);
  cr_assert_eq(code, 1, "%s", out);
  cr_assert_not_null(strstr(out, "3 pixels (18.8%) over warn"), "%s", out);
  cr_assert_not_null(strstr(out, "WARNING"), "%s", out);
  /* Warnings allowed for up to 20% of the pixels: 3 of 16 is 18.75%. */
  code = run(out, sizeof out, "compare %s %s --fail 0.1 --warn 0.001 --warnpercent 20", a,
             b);
  cr_assert_eq(code, 0, "%s", out);
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
  /* 2 of 16 pixels = 12.5%: failure needs MORE than failpercent. */
  cr_assert_eq(run(out, sizeof out, "compare %s %s --failpercent 12.5", a, b), 0, "%s",
               out);
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
  const char *junk = tmp_file("junk.png");
  FILE *f = fopen(junk, "w");
  cr_assert_not_null(f);
  fputs("this is not a png", f);
  fclose(f);
  char out[4096];
  cr_assert_eq(run(out, sizeof out, "compare %s %s", a, tmp_file("missing.exr")), 4, "%s",
               out);
  cr_assert_not_null(strstr(out, "bumpbake: "), "%s", out);
  cr_assert_not_null(strstr(out, "missing.exr"), "%s", out);
  cr_assert_eq(run(out, sizeof out, "compare %s %s", junk, a), 4, "%s", out);
  cr_assert_eq(run(out, sizeof out, "compare %s", a), 4, "one file: %s", out);
  cr_assert_eq(run(out, sizeof out, "compare %s %s --fail", a, a), 4, "%s", out);
  cr_assert_eq(run(out, sizeof out, "compare %s %s --fail -1", a, a), 4, "%s", out);
  cr_assert_eq(run(out, sizeof out, "compare %s %s --bogus", a, a), 4, "%s", out);
}

Test(compare_cli, diff_exr_holds_raw_absolute_differences) {
  const char *a = ramp_with("a.exr", 0, 0), *b = ramp_with("b.exr", 2, 0.125f);
  char out[4096];
  cr_assert_eq(run(out, sizeof out, "compare %s %s --diff %s", a, b, tmp_file("d.exr")),
               2, "%s", out);
  bb_image d = {0};
  cr_assert_eq(bb_image_read(tmp_file("d.exr"), &d, NULL, NULL), BB_OK);
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
  run(out, sizeof out, "compare %s %s --diff %s", a, b, tmp_file("d.png"));
  bb_image d = {0};
  cr_assert_eq(bb_image_read(tmp_file("d.png"), &d, NULL, NULL), BB_OK, "%s", out);
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
  return bb_provenance_format(&p);
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
  cr_assert_eq(run(out, sizeof out, "info %s", tmp_file("missing.png")), 1, "%s", out);
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
  const char *ssbump = tmp_file("ssbump.exr");
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
           (unsigned long long)bb_image_hash(&img));
  bb_image_free(&img);
  cr_assert_not_null(strstr(out, hash), "input hash of the decoded height: %s", out);
}
