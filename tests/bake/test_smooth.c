/* test_smooth.c: the bilateral filter against a brute-force sum over the full window. */
#include <criterion/criterion.h>

#include <math.h>
#include <stdint.h>
#include <string.h>

#include "bumpbake.h"
#include "bake/bake_internal.h"

/* Deterministic pseudo-random numbers in [0, 1) (64-bit LCG, high bits). */
static double next_random(uint64_t *state) {
  *state = *state * 6364136223846793005ULL + 1442695040888963407ULL;
  return (double)(*state >> 11) * (1.0 / 9007199254740992.0);
}

/* A field where neighbours differ by about the default threshold, so the
 * range term is partly on and partly off: a slow slope plus noise, and a few
 * steps much larger than the threshold. */
static void fill_test_field(bb_image *img, uint64_t seed) {
  uint64_t state = seed;
  for (int y = 0; y < img->height; y++)
    for (int x = 0; x < img->width; x++)
      for (int c = 0; c < img->channels; c++) {
        double base = 0.4 + 0.002 * x + 0.001 * y + 0.1 * c;
        double step = ((x / 7 + y / 5) % 3 == 0) ? 0.2 : 0.0;
        bb_image_texel(img, x, y)[c] =
            (float)(base + step + (4.0 / 255.0) * next_random(&state));
      }
}

static int address(int i, int n, bb_addressing a) {
  if (a == BB_ADDRESS_PERIODIC)
    return ((i % n) + n) % n;
  return i < 0 ? 0 : (i >= n ? n - 1 : i);
}

/* docs/conventions.md "Smoothing" summed directly over the uncut (2R+1)^2 window. */
static double brute_force(const bb_image *in, const bb_image *guide, int x, int y, int c,
                          int radius, double threshold, bb_addressing a) {
  double centre = bb_image_texel(guide, x, y)[0];
  double num = 0.0, den = 0.0;
  for (int iy = -radius; iy <= radius; iy++)
    for (int ix = -radius; ix <= radius; ix++) {
      int qx = address(x + ix, in->width, a), qy = address(y + iy, in->height, a);
      double g = exp(-(double)(ix * ix + iy * iy) / (2.0 * radius * 0.033));
      double s =
          fmax(0.0, 1.0 - fabs(bb_image_texel(guide, qx, qy)[0] - centre) / threshold);
      num += s * g * bb_image_texel(in, qx, qy)[c];
      den += s * g;
    }
  return num / den;
}

/* Compares every texel of a small image (borders included) with the brute force. */
static void check_against_brute_force(int radius, bb_addressing a) {
  bb_image h = {0}, out = {0};
  bb_error err = {{0}};
  cr_assert_eq(bb_image_alloc(&h, 29, 19, 1, &err), BB_OK);
  fill_test_field(&h, 42u + (uint64_t)radius);
  bb_smooth_options o;
  bb__smooth_options_init(&o);
  o.radius_texels = radius;
  o.addressing = a;
  cr_assert_eq(bb__smooth_bilateral_all_cores(&h, &h, &o, &out, &err), BB_OK, "%s", err.message);
  int changed = 0;
  for (int y = 0; y < h.height; y++)
    for (int x = 0; x < h.width; x++) {
      double want = brute_force(&h, &h, x, y, 0, radius, (double)o.threshold, a);
      double got = bb_image_texel(&out, x, y)[0];
      cr_assert(fabs(got - want) < 1e-6, "R=%d texel (%d,%d): got %.9f want %.9f", radius,
                x, y, got, want);
      if (got != bb_image_texel(&h, x, y)[0])
        changed++;
    }
  /* The field must actually be smoothed, or the comparison proves little.
   * (At R = 1 Valve's g is 2.6e-7 at one texel, so floats barely move.) */
  if (radius >= 3)
    cr_assert_gt(changed, h.width * h.height / 2, "only %d texels changed", changed);
  bb_image_free(&h);
  bb_image_free(&out);
}

Test(smooth, options_defaults) {
  bb_smooth_options o;
  memset(&o, 0xff, sizeof o);
  bb__smooth_options_init(&o);
  cr_assert_eq(o.radius_texels, 10);
  cr_assert_float_eq(o.threshold, 2.0f / 255.0f, 1e-9f);
  cr_assert_eq(o.addressing, BB_ADDRESS_PERIODIC);
}

Test(smooth, brute_force_r1_periodic) {
  check_against_brute_force(1, BB_ADDRESS_PERIODIC);
}
Test(smooth, brute_force_r1_clamp) {
  check_against_brute_force(1, BB_ADDRESS_CLAMP);
}
Test(smooth, brute_force_r3_periodic) {
  check_against_brute_force(3, BB_ADDRESS_PERIODIC);
}
Test(smooth, brute_force_r3_clamp) {
  check_against_brute_force(3, BB_ADDRESS_CLAMP);
}
Test(smooth, brute_force_r10_periodic) {
  check_against_brute_force(10, BB_ADDRESS_PERIODIC);
}
Test(smooth, brute_force_r10_clamp) {
  check_against_brute_force(10, BB_ADDRESS_CLAMP);
}

/* R = 25 reaches past the 19-texel height: periodic wrapping and clamping of
 * offsets larger than the image must still agree with the direct sum. */
Test(smooth, brute_force_radius_larger_than_image) {
  check_against_brute_force(25, BB_ADDRESS_PERIODIC);
  check_against_brute_force(25, BB_ADDRESS_CLAMP);
}

/* Every channel is filtered with the weights of the guide's channel 0. */
Test(smooth, multichannel_with_separate_guide) {
  bb_image in = {0}, guide = {0}, out = {0};
  cr_assert_eq(bb_image_alloc(&in, 17, 13, 3, NULL), BB_OK);
  cr_assert_eq(bb_image_alloc(&guide, 17, 13, 2, NULL), BB_OK);
  fill_test_field(&in, 7);
  fill_test_field(&guide, 8);
  bb_smooth_options o;
  bb__smooth_options_init(&o);
  o.radius_texels = 4;
  o.threshold = 5.0f / 255.0f;
  cr_assert_eq(bb__smooth_bilateral_all_cores(&in, &guide, &o, &out, NULL), BB_OK);
  cr_assert_eq(out.channels, 3);
  for (int y = 0; y < in.height; y++)
    for (int x = 0; x < in.width; x++)
      for (int c = 0; c < 3; c++) {
        double want = brute_force(&in, &guide, x, y, c, 4, (double)o.threshold,
                                  BB_ADDRESS_PERIODIC);
        double got = bb_image_texel(&out, x, y)[c];
        cr_assert(fabs(got - want) < 1e-6, "(%d,%d,%d): got %.9f want %.9f", x, y, c, got,
                  want);
      }
  bb_image_free(&in);
  bb_image_free(&guide);
  bb_image_free(&out);
}

Test(smooth, radius_zero_is_identity) {
  bb_image h = {0}, out = {0};
  cr_assert_eq(bb_image_alloc(&h, 37, 23, 2, NULL), BB_OK);
  fill_test_field(&h, 3);
  bb_smooth_options o;
  bb__smooth_options_init(&o);
  o.radius_texels = 0;
  cr_assert_eq(bb__smooth_bilateral_all_cores(&h, &h, &o, &out, NULL), BB_OK);
  cr_assert_eq(out.width, 37);
  cr_assert_eq(out.height, 23);
  cr_assert_eq(out.channels, 2);
  cr_assert_eq(memcmp(out.pixels, h.pixels, 37 * 23 * 2 * sizeof(float)), 0);
  bb_image_free(&h);
  bb_image_free(&out);
}

/* A step far above the threshold is not blurred: the range term cuts it. */
Test(smooth, keeps_edges_above_threshold) {
  bb_image h = {0}, out = {0};
  cr_assert_eq(bb_image_alloc(&h, 32, 8, 1, NULL), BB_OK);
  for (int y = 0; y < 8; y++)
    for (int x = 0; x < 32; x++)
      bb_image_texel(&h, x, y)[0] = x < 16 ? 0.25f : 0.75f;
  bb_smooth_options o;
  bb__smooth_options_init(&o);
  cr_assert_eq(bb__smooth_bilateral_all_cores(&h, &h, &o, &out, NULL), BB_OK);
  for (int y = 0; y < 8; y++)
    for (int x = 0; x < 32; x++)
      cr_assert_float_eq(bb_image_texel(&out, x, y)[0], bb_image_texel(&h, x, y)[0],
                         1e-7f, "(%d,%d)", x, y);
  bb_image_free(&h);
  bb_image_free(&out);
}

/* Shifting the input periodically by (dx, dy) shifts the output bit for bit. */
Test(smooth, periodic_shift_is_exact) {
  const int w = 37, hgt = 23, dx = 11, dy = 5;
  bb_image h = {0}, shifted = {0}, out = {0}, out_shifted = {0};
  cr_assert_eq(bb_image_alloc(&h, w, hgt, 1, NULL), BB_OK);
  cr_assert_eq(bb_image_alloc(&shifted, w, hgt, 1, NULL), BB_OK);
  fill_test_field(&h, 99);
  for (int y = 0; y < hgt; y++)
    for (int x = 0; x < w; x++)
      bb_image_texel(&shifted, (x + dx) % w, (y + dy) % hgt)[0] =
          bb_image_texel(&h, x, y)[0];
  bb_smooth_options o;
  bb__smooth_options_init(&o);
  cr_assert_eq(bb__smooth_bilateral_all_cores(&h, &h, &o, &out, NULL), BB_OK);
  cr_assert_eq(bb__smooth_bilateral_all_cores(&shifted, &shifted, &o, &out_shifted, NULL), BB_OK);
  for (int y = 0; y < hgt; y++)
    for (int x = 0; x < w; x++) {
      float a = bb_image_texel(&out, x, y)[0];
      float b = bb_image_texel(&out_shifted, (x + dx) % w, (y + dy) % hgt)[0];
      cr_assert_eq(memcmp(&a, &b, sizeof a), 0, "(%d,%d): %.9g vs %.9g", x, y, (double)a,
                   (double)b);
    }
  bb_image_free(&h);
  bb_image_free(&shifted);
  bb_image_free(&out);
  bb_image_free(&out_shifted);
}

/* The filter runs on all cores (the options have no thread count), so two
 * runs over many rows must agree bit for bit whatever the scheduling. */
Test(smooth, repeated_runs_are_identical) {
  bb_image h = {0}, a = {0}, b = {0};
  cr_assert_eq(bb_image_alloc(&h, 64, 200, 1, NULL), BB_OK);
  fill_test_field(&h, 5);
  bb_smooth_options o;
  bb__smooth_options_init(&o);
  cr_assert_eq(bb__smooth_bilateral_all_cores(&h, &h, &o, &a, NULL), BB_OK);
  cr_assert_eq(bb__smooth_bilateral_all_cores(&h, &h, &o, &b, NULL), BB_OK);
  cr_assert_eq(memcmp(a.pixels, b.pixels, 64 * 200 * sizeof(float)), 0);
  bb_image_free(&h);
  bb_image_free(&a);
  bb_image_free(&b);
}

/* A 1-channel image is filtered 8 texels at a time away from the sides, a
 * 2-channel one texel by texel; both must give the same bits. Channel 1 of
 * the 2-channel copy is the height too, so the guide is the same. */
static void check_blocks_match_texels(int width, int radius, float threshold,
                                      bb_addressing a) {
  bb_image h = {0}, two = {0}, one_out = {0}, two_out = {0};
  cr_assert_eq(bb_image_alloc(&h, width, 9, 1, NULL), BB_OK);
  cr_assert_eq(bb_image_alloc(&two, width, 9, 2, NULL), BB_OK);
  fill_test_field(&h, 17u + (uint64_t)width);
  for (int i = 0; i < width * 9; i++)
    two.pixels[2 * i] = two.pixels[2 * i + 1] = h.pixels[i];
  bb_smooth_options o;
  bb__smooth_options_init(&o);
  o.radius_texels = radius;
  o.threshold = threshold;
  o.addressing = a;
  cr_assert_eq(bb__smooth_bilateral_all_cores(&h, &h, &o, &one_out, NULL), BB_OK);
  cr_assert_eq(bb__smooth_bilateral_all_cores(&two, &h, &o, &two_out, NULL), BB_OK);
  for (int y = 0; y < 9; y++)
    for (int x = 0; x < width; x++) {
      float got = bb_image_texel(&one_out, x, y)[0];
      for (int c = 0; c < 2; c++) {
        float want = bb_image_texel(&two_out, x, y)[c];
        cr_assert_eq(memcmp(&got, &want, sizeof got), 0,
                     "width %d R=%d (%d,%d): %.9g vs %.9g", width, radius, x, y,
                     (double)got, (double)want);
      }
    }
  bb_image_free(&h);
  bb_image_free(&two);
  bb_image_free(&one_out);
  bb_image_free(&two_out);
}

Test(smooth, blocks_match_per_texel_path_bit_for_bit) {
  const int widths[] = {1, 7, 14, 15, 23, 45, 64};
  for (size_t i = 0; i < sizeof widths / sizeof widths[0]; i++)
    for (int clamp = 0; clamp < 2; clamp++) {
      bb_addressing a = clamp ? BB_ADDRESS_CLAMP : BB_ADDRESS_PERIODIC;
      check_blocks_match_texels(widths[i], 10, 2.0f / 255.0f, a);
      check_blocks_match_texels(widths[i], 3, 0.5f, a);
      check_blocks_match_texels(widths[i], 40, 1.0f / 255.0f, a);
    }
}

static bb_status smooth_with(int radius, float threshold, const bb_image *guide,
                             bb_error *err) {
  bb_image h = {0}, out = {0};
  cr_assert_eq(bb_image_alloc(&h, 8, 8, 1, NULL), BB_OK);
  bb_smooth_options o;
  bb__smooth_options_init(&o);
  o.radius_texels = radius;
  o.threshold = threshold;
  bb_status st = bb__smooth_bilateral_all_cores(&h, guide ? guide : &h, &o, &out, err);
  if (st != BB_OK)
    cr_assert_null(out.pixels, "a failed call must leave no output");
  bb_image_free(&h);
  bb_image_free(&out);
  return st;
}

Test(smooth, rejects_bad_arguments) {
  bb_error err = {{0}};
  cr_assert_eq(smooth_with(-1, 0.01f, NULL, &err), BB_ERR_ARGUMENT);
  cr_assert(strstr(err.message, "radius") != NULL, "%s", err.message);
  cr_assert_eq(smooth_with(10, 0.0f, NULL, &err), BB_ERR_ARGUMENT);
  cr_assert(strstr(err.message, "threshold") != NULL, "%s", err.message);
  cr_assert_eq(smooth_with(10, -0.5f, NULL, &err), BB_ERR_ARGUMENT);
  cr_assert_eq(smooth_with(10, NAN, NULL, &err), BB_ERR_ARGUMENT);
  cr_assert_eq(smooth_with(10, 0.01f, NULL, NULL), BB_OK);
}

Test(smooth, rejects_guide_of_another_size) {
  bb_image guide = {0};
  bb_error err = {{0}};
  cr_assert_eq(bb_image_alloc(&guide, 8, 9, 1, NULL), BB_OK);
  cr_assert_eq(smooth_with(10, 0.01f, &guide, &err), BB_ERR_ARGUMENT);
  cr_assert(strstr(err.message, "guide") != NULL, "%s", err.message);
  bb_image_free(&guide);
}

Test(smooth, rejects_nan_guide) {
  bb_image guide = {0};
  bb_error err = {{0}};
  cr_assert_eq(bb_image_alloc(&guide, 8, 8, 1, NULL), BB_OK);
  bb_image_texel(&guide, 3, 4)[0] = NAN;
  cr_assert_eq(smooth_with(10, 0.01f, &guide, &err), BB_ERR_VALUE);
  cr_assert(strstr(err.message, "(3, 4)") != NULL, "%s", err.message);
  bb_image_free(&guide);
}

Test(smooth, rejects_output_aliasing_input) {
  bb_image h = {0};
  cr_assert_eq(bb_image_alloc(&h, 8, 8, 1, NULL), BB_OK);
  bb_smooth_options o;
  bb__smooth_options_init(&o);
  cr_assert_eq(bb__smooth_bilateral_all_cores(&h, &h, &o, &h, NULL), BB_ERR_ARGUMENT);
  cr_assert_not_null(h.pixels, "the input must survive");
  bb_image_free(&h);
}

/* The largest radius builds the largest cut kernel; one more is refused. */
Test(smooth, radius_limit) {
  bb_error err = {{0}};
  cr_assert_eq(smooth_with(BB_MAX_DIMENSION, 0.01f, NULL, &err), BB_OK, "%s",
               err.message);
  cr_assert_eq(smooth_with(BB_MAX_DIMENSION + 1, 0.01f, NULL, &err), BB_ERR_ARGUMENT);
}
