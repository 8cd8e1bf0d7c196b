/* test_cli_convert.c: `bumpbake normal2ssbump` and `bumpbake ssbump2normal`
 * as a user runs them: Valve's default name, round trips through files
 * against `bake`'s own maps, decoding of 8/16-bit and float maps, errors. */
#define _XOPEN_SOURCE 700 /* mkdtemp, nftw, realpath */
#define _DEFAULT_SOURCE    /* wait4 (cli_harness.h) */

#include "bumpbake.h"
#include "cli_harness.h"

#include <criterion/criterion.h>

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

static void setup(void) {
  harness_setup();
}
static void teardown(void) {
  harness_teardown();
}
TestSuite(cli_convert, .init = setup, .fini = teardown, .timeout = 300);

/* A tiling height with slopes in every direction, steep enough in places
 * for some N.B_c < 0. */
static void write_height(const char *path, int w, int h, double amplitude) {
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, w, h, 1, NULL), BB_OK);
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++)
      img.pixels[y * w + x] =
          (float)(0.5 + amplitude * sin(2 * 3.14159265358979 * x / w) *
                            cos(2 * 3.14159265358979 * 2 * y / h));
  harness_write(path, &img, BB_DEPTH_16, BB_RANGE_UNIT);
  bb_image_free(&img);
}

static void write_uniform(const char *path, int w, int h, int channels,
                          const float *texel, bb_depth depth) {
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, w, h, channels, NULL), BB_OK);
  for (int i = 0; i < w * h; i++)
    memcpy(img.pixels + i * channels, texel, (size_t)channels * sizeof(float));
  harness_write(path, &img, depth, BB_RANGE_UNIT);
  bb_image_free(&img);
}

/* Unit normals of a tilted wave, written as bumpbake writes normal maps;
 * y_up negates green, as an OpenGL-style map holds it. */
static void write_normals(const char *path, int w, int h, double amplitude, int y_up,
                          bb_depth depth) {
  bb_image n;
  cr_assert_eq(bb_image_alloc(&n, w, h, 3, NULL), BB_OK);
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++) {
      double v[3] = {amplitude * sin(0.3 * x + 0.1 * y),
                     amplitude * cos(0.2 * y - 0.4 * x), 1.0};
      double len = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
      float *t = bb_image_texel(&n, x, y);
      t[0] = (float)(v[0] / len);
      t[1] = (float)((y_up ? -v[1] : v[1]) / len);
      t[2] = (float)(v[2] / len);
    }
  harness_write(path, &n, depth, BB_RANGE_SIGNED);
  bb_image_free(&n);
}

Test(cli_convert, help_lists_options_and_defaults) {
  const char *commands[] = {"normal2ssbump", "ssbump2normal"};
  const char *must[2][4] = {
      {"--normal-y", "NAME_ssbump.tga", "--depth", "2 code / max - 1"},
      {"--kind", "weights|ssbump", "--normal-y", "sqrt(w_c)"}};
  for (int c = 0; c < 2; c++) {
    cli_result r = RUN(commands[c], "--help");
    cr_expect_eq(r.code, 0);
    for (int i = 0; i < 4; i++)
      cr_expect(strstr(r.out, must[c][i]), "%s --help lacks %s", commands[c], must[c][i]);
    cli_result_free(&r);
  }
  cli_result r = RUN("--help");
  cr_expect(strstr(r.out, "normal2ssbump") && strstr(r.out, "ssbump2normal") &&
            strstr(r.out, "combine") && strstr(r.out, "program"));
  cli_result_free(&r);
}

/* Valve's tool writes NAME_ssbump.tga: NAME up to "_normal" (any case),
 * else up to the first '.' of the file name. */
Test(cli_convert, default_output_name_is_valves) {
  const char *cases[][2] = {{"rock_Normal_v2.tga", "rock_ssbump.tga"},
                            {"wall.v2.png", "wall_ssbump.tga"}};
  const float flat[3] = {0.5f, 0.5f, 1.0f};
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    const char *in = tmp(cases[i][0]);
    write_uniform(in, 4, 4, 3, flat, BB_DEPTH_DEFAULT);
    cli_result r = RUN_IN(harness_dir, "normal2ssbump", cases[i][0]);
    cr_expect_eq(r.code, 0, "%s: %s", cases[i][0], r.err);
    const char *expected = tmp(cases[i][1]);
    cr_expect(file_exists(expected), "%s should write %s", cases[i][0], cases[i][1]);
    cr_expect(strstr(r.out, cases[i][1]), "%s", r.out);
    bb_image_info info;
    bb_image w = harness_read(expected, &info);
    cr_expect_str_eq(info.format_name, "targa");
    cr_expect_eq(info.bits_per_sample, 8);
    for (int c = 0; c < 3; c++)
      cr_expect_float_eq(w.pixels[c], 85.0 / 255.0, 1.01 / 255.0,
                         "about 1/3 each (code 85)");
    bb_image_free(&w);
    bb_image_info_free(&info);
    remove(expected);
    cli_result_free(&r);
  }
  /* A directory with a dot or "_normal" in its name is not cut. */
  cr_assert_eq(mkdir(tmp("v1.2_normals"), 0777), 0);
  write_uniform(tmp("v1.2_normals/rock.png"), 4, 4, 3, flat, BB_DEPTH_DEFAULT);
  cli_result r = RUN("normal2ssbump", tmp("v1.2_normals/rock.png"));
  cr_expect_eq(r.code, 0, "%s", r.err);
  cr_expect(file_exists(tmp("v1.2_normals/rock_ssbump.tga")));
  cli_result_free(&r);
}

/* height -> normal (EXR) -> normal2ssbump (EXR) equals bake --weights. */
Test(cli_convert, normal2ssbump_of_a_bumpbake_normal_is_bakes_weights) {
  const char *h = tmp("h.png"), *n = tmp("n.exr"), *w = tmp("w.exr");
  const char *mine = tmp("mine.exr");
  write_height(h, 48, 40, 0.45);
  cli_result r = RUN("bake", h, "--scale", "24", "--normal", n, "--weights", w, "-q");
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  r = RUN("normal2ssbump", n, "-o", mine);
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  bb_image a = harness_read(w, NULL), b = harness_read(mine, NULL);
  double d = harness_max_difference(&a, &b);
  cr_expect_lt(d, 1e-5, "weights differ by %g", d);
  bb_image_free(&a);
  bb_image_free(&b);
}

/* An OpenGL-style (green up) map with --normal-y up gives the weights of
 * its DirectX twin; 16-bit in gives 16-bit out. */
Test(cli_convert, normal_y_up_and_16_bit_maps) {
  const char *dx = tmp("dx.png"), *gl = tmp("gl.png");
  const char *w_dx = tmp("w_dx.png"), *w_gl = tmp("w_gl.png");
  write_normals(dx, 24, 16, 0.6, 0, BB_DEPTH_16);
  write_normals(gl, 24, 16, 0.6, 1, BB_DEPTH_16);
  cli_result r = RUN("normal2ssbump", dx, "-o", w_dx);
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  r = RUN("normal2ssbump", gl, "-o", w_gl, "--normal-y", "up");
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  bb_image_info info;
  bb_image a = harness_read(w_dx, &info), b = harness_read(w_gl, NULL);
  cr_expect_eq(info.bits_per_sample, 16, "a 16-bit input gives a 16-bit output");
  double d = harness_max_difference(&a, &b);
  cr_expect_leq(d, 1.0 / 65535.0 + 1e-9, "green up and down disagree by %g", d);
  /* Without --normal-y up the OpenGL map lights the other way in y. */
  bb_image_free(&b);
  r = RUN("normal2ssbump", gl, "-o", w_gl);
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  b = harness_read(w_gl, NULL);
  cr_expect_gt(harness_max_difference(&a, &b), 0.1);
  bb_image_free(&a);
  bb_image_free(&b);
  bb_image_info_free(&info);
}

/* 127.5 of 255 is zero: an 8-bit map's (128, 128, 255) leans +1/255 in x
 * and y, which moves the weights by under one code; alpha is carried. */
Test(cli_convert, eight_bit_flat_and_alpha) {
  const char *in = tmp("flat.png"), *out = tmp("w.png");
  const float texel[4] = {128.0f / 255, 128.0f / 255, 1.0f, 0.25f};
  write_uniform(in, 5, 3, 4, texel, BB_DEPTH_8);
  cli_result r = RUN("normal2ssbump", in, "-o", out);
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  bb_image w = harness_read(out, NULL);
  cr_assert_eq(w.channels, 4);
  const int codes[4] = {86, 85, 84,
                        64}; /* 85.94, 85.34, 83.71 (85.0 when exactly flat) */
  for (int c = 0; c < 4; c++)
    cr_expect_eq((int)lrintf(w.pixels[c] * 255.0f), codes[c], "channel %d: %g", c,
                 (double)w.pixels[c] * 255.0);
  bb_image_free(&w);
}

/* ssbump2normal of an unoccluded bake's ssbump is its normal. */
Test(cli_convert, ssbump2normal_of_an_unoccluded_bake) {
  const char *h = tmp("h.png"), *n = tmp("n.exr"), *s = tmp("s.exr");
  const char *ao = tmp("ao.exr"), *back = tmp("back.exr");
  write_height(h, 48, 32, 0.25);
  /* exact horizons see any crest above the ray origin: a bias over the
   * field's 1-texel relief leaves none */
  cli_result r = RUN("bake", h, "--scale", "2", "--rays", "64", "--bias", "1.5", "--normal", n,
                     "--ssbump", s, "--ao", ao, "-q");
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  bb_image occlusion = harness_read(ao, NULL);
  for (int i = 0; i < 48 * 32; i++)
    cr_assert_eq(occlusion.pixels[i], 1.0f,
                 "texel %d is occluded: not the case under test", i);
  bb_image_free(&occlusion);
  r = RUN("ssbump2normal", s, "-o", back);
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  bb_image a = harness_read(n, NULL), b = harness_read(back, NULL);
  double d = harness_max_difference(&a, &b);
  cr_expect_lt(d, 1e-3, "normals differ by %g", d);
  bb_image_free(&a);
  bb_image_free(&b);
}

/* normal2ssbump then ssbump2normal --kind weights gives the normal back. */
Test(cli_convert, weights_round_trip) {
  const char *n = tmp("n.exr"), *w = tmp("w.exr");
  const char *back = tmp("back.exr"), *gl = tmp("gl.exr");
  write_normals(n, 40, 24, 0.4, 0, BB_DEPTH_FLOAT); /* tilts under 30 degrees */
  cli_result r = RUN("normal2ssbump", n, "-o", w);
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  r = RUN("ssbump2normal", w, "--kind", "weights", "-o", back);
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  bb_image a = harness_read(n, NULL), b = harness_read(back, NULL);
  cr_expect_lt(harness_max_difference(&a, &b), 1e-5);
  bb_image_free(&b);
  r = RUN("ssbump2normal", w, "--kind", "weights", "-o", gl, "--normal-y", "up");
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  b = harness_read(gl, NULL);
  for (int i = 0; i < 40 * 24; i++)
    cr_expect_float_eq(b.pixels[3 * i + 1], -a.pixels[3 * i + 1], 1e-5);
  bb_image_free(&a);
  bb_image_free(&b);
}

Test(cli_convert, bad_inputs) {
  const char *grey = tmp("grey.png"), *out = tmp("out.png");
  const char *nan = tmp("nan.exr");
  const float g[1] = {0.5f}, bad[3] = {NAN, 0.0f, 1.0f};
  write_uniform(grey, 4, 4, 1, g, BB_DEPTH_8);
  write_uniform(nan, 4, 4, 3, bad, BB_DEPTH_FLOAT);
  struct {
    const char *args[8];
    int code;
    const char *part;
  } cases[] = {
      {{"normal2ssbump", grey, "-o", out}, 1, "1 channel, needs 3"},
      {{"normal2ssbump", nan, "-o", out}, 1, "NaN"},
      {{"normal2ssbump", tmp("missing.png"), "-o", out}, 1, "no such file"},
      {{"normal2ssbump", grey, "-o", grey}, 1, "overwrite the input"},
      {{"ssbump2normal", grey}, 2, "-o OUT is required"},
      {{"ssbump2normal", nan, "-o", out, "--kind", "height"}, 2, "--kind"},
      {{"ssbump2normal", nan, "-o", out}, 1, "NaN"},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++)
    harness_expect_refusal(NULL, cases[i].args, cases[i].code, cases[i].part, i);
}
