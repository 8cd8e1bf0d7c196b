/* test_cli_mips.c: `--mips` on the commands' outputs: mip-mapped TIFF and
 * EXR files with every level, normals renormalised, and refusals. */
#define _XOPEN_SOURCE 700 /* mkdtemp, nftw, realpath */
#define _DEFAULT_SOURCE    /* wait4 (cli_harness.h) */

#include "image/oiio.h"
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
TestSuite(cli_mips, .init = setup, .fini = teardown, .timeout = 300);

static void write_height(const char *path) {
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, 32, 16, 1, NULL), BB_OK);
  for (int y = 0; y < 16; y++)
    for (int x = 0; x < 32; x++)
      img.pixels[y * 32 + x] = (float)(0.5 + 0.4 * sin(x * 0.7) * cos(y * 1.1));
  harness_write(path, &img, BB_DEPTH_16, BB_RANGE_UNIT);
  bb_image_free(&img);
}

static bb_image read_level(const char *path, int level, int *count) {
  bb_image img;
  bb_error err;
  cr_assert_eq(bb__image_read_mip(path, level, &img, NULL, count, &err), BB_OK, "%s",
               err.message);
  return img;
}

Test(cli_mips, bake_and_normal2ssbump_write_every_level) {
  const char *h = tmp("h.png"), *n = tmp("n.tif"), *s = tmp("s.exr");
  const char *w = tmp("w.exr");
  write_height(h);
  cli_result r = RUN("bake", h, "--scale", "8", "--rays", "16", "--normal", n, "--ssbump",
                     s, "--mips", "-q");
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  int count = 0;
  bb_image top = read_level(s, 0, &count);
  cr_expect_eq(count, 6, "32x16 down to 1x1");
  for (int k = 1; k < count; k++) {
    bb_image up = read_level(s, k - 1, NULL), lv = read_level(s, k, NULL);
    if (up.height >= 2) /* plain 2 x 2 means, in float */
      for (int c = 0; c < 3; c++) {
        double m = 0.0;
        for (int dy = 0; dy < 2; dy++)
          for (int dx = 0; dx < 2; dx++)
            m += bb_image_texel(&up, dx, dy)[c] / 4.0;
        cr_expect_float_eq(lv.pixels[c], m, 1e-6, "ssbump level %d channel %d", k, c);
      }
    bb_image_free(&up);
    bb_image_free(&lv);
  }
  bb_image_free(&top);
  for (int k = 0; k < 6; k++) { /* 8-bit codes of unit normals */
    bb_image lv = read_level(n, k, NULL);
    for (int i = 0; i < lv.width * lv.height; i++) {
      double v[3], len = 0.0;
      for (int c = 0; c < 3; c++) {
        v[c] = 2.0 * lv.pixels[3 * i + c] - 1.0;
        len += v[c] * v[c];
      }
      cr_expect_float_eq(sqrt(len), 1.0, 0.012, "normal level %d texel %d", k, i);
    }
    bb_image_free(&lv);
  }
  r = RUN("normal2ssbump", n, "-o", w, "--mips");
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  bb_image lv = read_level(w, 5, &count);
  cr_expect(count == 6 && lv.width == 1 && lv.height == 1);
  bb_image_free(&lv);
}

Test(cli_mips, formats_without_levels_are_refused) {
  const char *h = tmp("h.png");
  write_height(h);
  struct {
    const char *args[12];
  } cases[] = {
      {{"bake", h, "--scale", "4", "--normal", tmp("n.png"), "--mips"}},
      {{"normal", h, "--scale", "4", "-o", tmp("n.tga"), "--mips"}},
      {{"combine", h, h, "--mix", "0.5", "--kind", "ao", "-o", tmp("c.png"), "--mips"}},
      {{"program", "_flat", "-o", tmp("f.png"), "--mips"}},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++)
    harness_expect_refusal(NULL, cases[i].args, 2, "--mips needs a .tif or .exr output",
                           i);
}
