/* test_cli_program.c: `bumpbake program` and bake's `--slope`/`--lit` run
 * as programs: outputs, exit codes, one-line errors, no file left behind. */
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
TestSuite(cli_program, .init = setup, .fini = teardown, .timeout = 300);

/* 4 x 4 heights as 8-bit grey, in id's bytes. */
static void write_heights(const char *path) {
  static const int bytes[16] = {10, 40, 90, 200, 30, 60,  120, 250,
                                0,  20, 80, 160, 50, 100, 150, 255};
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, 4, 4, 1, NULL), BB_OK);
  for (int i = 0; i < 16; i++)
    img.pixels[i] = (float)bytes[i] / 255.0f;
  harness_write(path, &img, BB_DEPTH_8, BB_RANGE_UNIT);
  bb_image_free(&img);
}

Test(cli_program, heightmap_writes_a_bumpbake_normal_map) {
  write_heights(tmp("h.tga"));
  const char *out = tmp("n.exr"), *png = tmp("n.png");
  cli_result r = RUN("program", "addnormals(heightmap(h.tga, 4), _flat)", "--base",
                     harness_dir, "-o", out);
  cr_assert_eq(r.code, 0, "%s", r.err);
  cr_expect(strstr(r.out, "wrote normal"), "%s", r.out);
  cli_result_free(&r);
  bb_image n = harness_read(out, NULL);
  cr_assert(n.channels == 3 && n.width == 4 && n.height == 4);
  for (int i = 0; i < 16; i++) {
    const float *t = n.pixels + 3 * i;
    cr_expect_float_eq(t[0] * t[0] + t[1] * t[1] + t[2] * t[2], 1.0, 1e-5,
                       "unit N in EXR");
  }
  /* The same as PNG: 0.5 + 0.5 N, as every bumpbake normal map. */
  r = RUN_IN(harness_dir, "program", "heightmap(h.tga,4)", "-o", png);
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  bb_image p = harness_read(png, NULL);
  for (int i = 0; i < 48; i++)
    cr_expect_float_eq(p.pixels[i], 0.5 + 0.5 * n.pixels[i], 0.51 / 255.0, "sample %d",
                       i);
  bb_image_free(&p);
  bb_image_free(&n);
}

Test(cli_program, colour_programs_write_rgba) {
  write_heights(tmp("h.png"));
  const char *out = tmp("c.png");
  cli_result r =
      RUN_IN(harness_dir, "program", "makeAlpha(invertColor(h.png))", "-o", out);
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  bb_image c = harness_read(out, NULL);
  cr_assert_eq(c.channels, 4);
  cr_expect_eq(c.pixels[0], 1.0f);
  cr_expect_float_eq(c.pixels[3], (255.0 - 10.0) / 255.0, 1e-6, "alpha = 1 - height");
  bb_image_free(&c);
}

Test(cli_program, errors) {
  const char *h = tmp("h.png"), *out = tmp("out.png");
  write_heights(h);
  struct {
    const char *args[8];
    int code;
    const char *part;
  } cases[] = {
      {{"program", "heightmap(h.png 4)", "-o", out}, 2, "syntax error at column 17"},
      {{"program", "bumpmap(h.png)", "-o", out},
       2,
       "unknown function 'bumpmap' at column 1 "
       "(known: heightmap, addnormals"},
      {{"program", "heightmap(missing.png, 4)", "-o", out},
       1,
       "missing.png: no such file"},
      {{"program", "add(h.png, h.png)", "-o", h}, 1, "overwrite the input"},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++)
    harness_expect_refusal(harness_dir, cases[i].args, cases[i].code, cases[i].part, i);
}

/* The output was checked against the first 64 image names only: a longer
 * program naming its own output after those replaced that input. */
Test(cli_program, output_checked_against_every_image_past_64) {
  write_heights(tmp("h.png"));
  write_heights(tmp("out.png"));
  /* add(add(...add(h.png, h.png)..., h.png), out.png): 64 calls deep (the
   * limit), 65 names, out.png last. */
  char program[2048] = "";
  for (int i = 0; i < 64; i++)
    strcat(program, "add(");
  strcat(program, "h.png");
  for (int i = 0; i < 63; i++)
    strcat(program, ", h.png)");
  strcat(program, ", out.png)");
  bb_image before = harness_read(tmp("out.png"), NULL);
  const char *args[] = {"program", program, "-o", "out.png", NULL};
  harness_expect_refusal(harness_dir, args, 1, "overwrite the input", 0);
  bb_image after = harness_read(tmp("out.png"), NULL);
  cr_expect(harness_same_pixels(&before, &after), "out.png was replaced");
  bb_image_free(&after);
  bb_image_free(&before);
}

/* ----------------------------------------------------------- bake --slope */

Test(cli_program, bake_slope_bytes_and_lit_preview) {
  const char *h = tmp("ramp.png"), *slope = tmp("ramp_slope.png");
  bb_image ramp;
  cr_assert_eq(bb_image_alloc(&ramp, 12, 4, 1, NULL), BB_OK);
  for (int y = 0; y < 4; y++)
    for (int x = 0; x < 12; x++)
      ramp.pixels[y * 12 + x] = (float)(2 * x) / 255.0f; /* 2 codes per texel */
  harness_write(h, &ramp, BB_DEPTH_8, BB_RANGE_UNIT);
  bb_image_free(&ramp);
  cli_result r = RUN("bake", h, "--scale", "255", "--filter-radius", "0", "--clamp",
                     "--slope", slope, "--lit", "0,45", "--depth", "16");
  cr_assert_eq(r.code, 0, "%s", r.err);
  cr_expect(strstr(r.out, "wrote slope") && strstr(r.out, "ramp_slope_lit.png"), "%s",
            r.out);
  cli_result_free(&r);
  bb_image_info info;
  bb_image s = harness_read(slope, &info);
  cr_expect_eq(info.bits_per_sample, 8, "one byte per texel whatever --depth says");
  cr_expect_eq(s.channels, 1);
  for (int x = 0; x < 12; x++) /* dx = 2, dy = 0; the last column is flat (clamp) */
    cr_expect_eq((int)lrintf(s.pixels[12 + x] * 255.0f), x < 11 ? 0x02 : 0x00, "x %d", x);
  bb_image_free(&s);
  bb_image_info_free(&info);
  bb_image lit = harness_read(tmp("ramp_slope_lit.png"), &info);
  cr_expect_eq(info.bits_per_sample, 16, "the preview follows --depth");
  /* Rising to the right faces away from a light from the right. */
  double n = 1.0 / sqrt(5.0), expected = n * cos(0.25 * 3.14159265358979) * -2.0 +
                                         n * sin(0.25 * 3.14159265358979);
  cr_expect_float_eq(lit.pixels[0], expected > 0 ? expected : 0.0, 1e-4);
  cr_expect_float_eq(lit.pixels[11], sin(0.25 * 3.14159265358979), 1e-4, "flat: sin(el)");
  bb_image_free(&lit);
  bb_image_info_free(&info);
}

Test(cli_program, bake_slope_errors) {
  const char *h = tmp("h.png");
  write_heights(h);
  struct {
    const char *args[10];
    const char *part;
  } cases[] = {
      {{"bake", h, "--scale", "4", "--lit", "0,45", "--normal", tmp("n.png")},
       "--lit previews the slope map"},
      {{"bake", h, "--scale", "4", "--slope", tmp("s.exr")}, "one byte per texel"},
      {{"bake", h, "--scale", "4", "--slope", tmp("s.png"), "--lit", "0,95"},
       "elevation must be in 0..90"},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++)
    harness_expect_refusal(NULL, cases[i].args, 2, cases[i].part, i);
}
