/* test_cli_combine.c: `bumpbake combine` through files: identities bit for
 * bit at every file depth, the blend and detail formulas, and errors. */
#define _XOPEN_SOURCE 700 /* mkdtemp, nftw, realpath */
#define _DEFAULT_SOURCE    /* wait4 (cli_harness.h) */

#include "bumpbake.h"
#include "cli_harness.h"

#include <criterion/criterion.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

static void setup(void) {
  harness_setup();
}
static void teardown(void) {
  harness_teardown();
}
TestSuite(cli_combine, .init = setup, .fini = teardown, .timeout = 300);

static bb_image noise(int w, int h, int channels, unsigned seed) {
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, w, h, channels, NULL), BB_OK);
  unsigned s = seed;
  for (size_t i = 0; i < (size_t)w * (size_t)h * (size_t)channels; i++) {
    s = s * 1664525u + 1013904223u;
    img.pixels[i] = (float)(s >> 8) / (float)(1u << 24);
  }
  return img;
}

static bb_image uniform(int w, int h, int channels, const float *texel) {
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, w, h, channels, NULL), BB_OK);
  for (int i = 0; i < w * h; i++)
    memcpy(img.pixels + i * channels, texel, (size_t)channels * sizeof(float));
  return img;
}

/* Unit normals encoded for the file's range (signed: 0.5 + 0.5 N). */
static bb_image noise_normals(int w, int h, unsigned seed) {
  bb_image n = noise(w, h, 3, seed);
  for (int i = 0; i < w * h; i++) {
    float *t = n.pixels + 3 * i;
    t[0] = 2 * t[0] - 1, t[1] = 2 * t[1] - 1, t[2] = t[2] + 0.3f;
    float len = sqrtf(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
    for (int k = 0; k < 3; k++)
      t[k] /= len;
  }
  return n;
}

static void run_ok(const char *const *args) {
  cli_result r = harness_run_in(NULL, args);
  cr_assert_eq(r.code, 0, "%s %s: %s", args[0], args[1], r.err);
  cli_result_free(&r);
}

/* Base read back from OUT must equal base read back from its own file. */
static void expect_same_file_pixels(const char *base, const char *out, const char *what) {
  bb_image a = harness_read(base, NULL), b = harness_read(out, NULL);
  cr_expect(harness_same_pixels(&a, &b), "%s: the base changed (max %g)", what,
            harness_max_difference(&a, &b));
  bb_image_free(&a);
  bb_image_free(&b);
}

/* A flat, unoccluded detail (as the file stores it) leaves the base
 * unchanged bit for bit, at 8 and 16 bits and in half float (full float is
 * test_combine.c's), for ssbumps (with Valve's alpha) and normal maps; so
 * do --mix 0 and a black mask. */
Test(cli_combine, identities_leave_the_base_bit_for_bit) {
  const struct {
    const char *ext;
    bb_depth depth;
  } files[] = {{"png", BB_DEPTH_8}, {"png", BB_DEPTH_16}, {"exr", BB_DEPTH_HALF}};
  const float ssbump_flat[4] = {(float)(1 / sqrt(3.0)), (float)(1 / sqrt(3.0)),
                                (float)(1 / sqrt(3.0)), 1.0f}; /* and an alpha */
  const float normal_flat[3] = {0.0f, 0.0f, 1.0f};
  const float black[1] = {0.0f};
  for (size_t f = 0; f < sizeof files / sizeof files[0]; f++)
    for (int normal = 0; normal <= 1; normal++) {
      char name[64];
      snprintf(name, sizeof name, "base%zu%d.%s", f, normal, files[f].ext);
      const char *base = tmp(name);
      snprintf(name, sizeof name, "detail%zu%d.%s", f, normal, files[f].ext);
      const char *detail = tmp(name);
      snprintf(name, sizeof name, "out%zu%d.%s", f, normal, files[f].ext);
      const char *out = tmp(name);
      const char *mask = tmp("mask.png");
      const bb_range range = normal ? BB_RANGE_SIGNED : BB_RANGE_UNIT;
      bb_image b = normal ? noise_normals(23, 9, 7u + (unsigned)f)
                          : noise(23, 9, 4, 3u + (unsigned)f);
      bb_image d =
          normal ? uniform(23, 9, 3, normal_flat) : uniform(23, 9, 4, ssbump_flat);
      bb_image m = uniform(23, 9, 1, black);
      harness_write(base, &b, files[f].depth, range);
      harness_write(detail, &d, files[f].depth, range);
      harness_write(mask, &m, BB_DEPTH_8, BB_RANGE_UNIT);
      const char *kind = normal ? "normal" : "ssbump";
      run_ok((const char *const[]){"combine", base, detail, "--detail", "--kind", kind,
                                   "-o", out, NULL});
      expect_same_file_pixels(base, out, name);
      if (f == 0) { /* the blend end points do not depend on the depth */
        run_ok((const char *const[]){"combine", base, detail, "--mix", "0", "--kind",
                                     kind, "-o", out, NULL});
        expect_same_file_pixels(base, out, name);
        run_ok((const char *const[]){"combine", base, detail, "--mask", mask, "--kind",
                                     kind, "-o", out, NULL});
        expect_same_file_pixels(base, out, name);
      }
      bb_image_free(&b);
      bb_image_free(&d);
      bb_image_free(&m);
    }
}

Test(cli_combine, blend_and_detail_formulas) {
  const char *a = tmp("a.exr"), *b = tmp("b.exr"), *out = tmp("o.exr");
  bb_image ia = uniform(4, 4, 3, (const float[]){0.2f, 0.5f, 0.8f});
  bb_image ib = uniform(4, 4, 3, (const float[]){0.6f, 0.1f, 0.0f});
  harness_write(a, &ia, BB_DEPTH_FLOAT, BB_RANGE_UNIT);
  harness_write(b, &ib, BB_DEPTH_FLOAT, BB_RANGE_UNIT);
  run_ok((const char *const[]){"combine", a, b, "--mix", "0.25", "-o", out, NULL});
  bb_image o = harness_read(out, NULL);
  for (int c = 0; c < 3; c++)
    cr_expect_float_eq(o.pixels[c], 0.75 * ia.pixels[c] + 0.25 * ib.pixels[c], 1e-6);
  bb_image_free(&o);
  run_ok((const char *const[]){"combine", a, b, "--detail", "--kind", "weights", "-o",
                               out, NULL});
  o = harness_read(out, NULL);
  for (int c = 0; c < 3; c++)
    cr_expect_float_eq(o.pixels[c], ia.pixels[c] * ib.pixels[c] * 3.0, 1e-6,
                       "A * B / (1/3)");
  bb_image_free(&o);
  bb_image_free(&ia);
  bb_image_free(&ib);
}

Test(cli_combine, errors) {
  const char *a = tmp("a.png"), *small = tmp("small.png");
  const char *grey = tmp("grey.png"), *out = tmp("out.png");
  bb_image ia = noise(8, 8, 3, 1), is = noise(4, 8, 3, 2), ig = noise(8, 8, 1, 3);
  harness_write(a, &ia, BB_DEPTH_8, BB_RANGE_UNIT);
  harness_write(small, &is, BB_DEPTH_8, BB_RANGE_UNIT);
  harness_write(grey, &ig, BB_DEPTH_8, BB_RANGE_UNIT);
  bb_image_free(&ia);
  bb_image_free(&is);
  bb_image_free(&ig);
  struct {
    const char *args[10];
    int code;
    const char *part;
  } cases[] = {
      {{"combine", a, small, "--mix", "0.5", "-o", out},
       1,
       "8x8 but the second map is 4x8"},
      {{"combine", a, a, "--mask", small, "-o", out}, 1, "the mask is 4x8"},
      {{"combine", a, grey, "--detail", "-o", out}, 1, "detail has 1 channel, needs 3"},
      {{"combine", a, a, "-o", out}, 2, "exactly one of --mix"},
      {{"combine", a, a, "--detail", "--kind", "height", "-o", out}, 2, "--kind"},
      {{"combine", a, small, "--detail", "-o", small}, 1, "overwrite the input"},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++)
    harness_expect_refusal(NULL, cases[i].args, cases[i].code, cases[i].part, i);
}
