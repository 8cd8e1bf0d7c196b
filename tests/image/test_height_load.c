/* test_height_load.c: the height channel rule (src/image/height_load.c), on buffers and on files. */
#include <criterion/criterion.h>

#include "bumpbake.h"
#include "image/height_channel.h"
#include "image/image_write.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

/* ------------------------------------------------------------- fixtures */

static char tmpdir[256];

static void make_tmpdir(void) {
  snprintf(tmpdir, sizeof tmpdir, "/tmp/bb-test-load-XXXXXX");
  cr_assert_not_null(mkdtemp(tmpdir), "mkdtemp: %s", strerror(errno));
}

/* Every test names its files from this list, so cleanup needs no directory walk. */
static const char *const FILE_NAMES[] = {"g.png", "ga.png", "rgb.png", "rgba.tga",
                                         "rgb.exr", "nan.exr", "inf.exr"};

static void remove_tmpdir(void) {
  char path[512];
  for (size_t i = 0; i < sizeof FILE_NAMES / sizeof FILE_NAMES[0]; i++) {
    snprintf(path, sizeof path, "%s/%s", tmpdir, FILE_NAMES[i]);
    unlink(path);
  }
  rmdir(tmpdir);
}

TestSuite(load, .init = make_tmpdir, .fini = remove_tmpdir);

static const char *tmp_path(const char *name) {
  static char buf[512];
  snprintf(buf, sizeof buf, "%s/%s", tmpdir, name);
  return buf;
}

/* A w x h image whose channel c of texel (x, y) is (1 + c) * 0.1 + 0.01 x + 0.001 y. */
static bb_image make_image(int w, int h, int channels) {
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, w, h, channels, NULL), BB_OK);
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++)
      for (int c = 0; c < channels; c++)
        bb_image_texel(&img, x, y)[c] = (float)((1 + c) * 0.1 + 0.01 * x + 0.001 * y);
  return img;
}

/* Height of (x, y) by the rule, computed here independently of height_load.c. */
static float expected(const bb_image *img, int x, int y, bb_channel ch) {
  const float *t = bb_image_texel(img, x, y);
  if (ch == BB_CHANNEL_LUMA && img->channels >= 3)
    return (float)(0.2126 * t[0] + 0.7152 * t[1] + 0.0722 * t[2]);
  if ((ch == BB_CHANNEL_AUTO || ch == BB_CHANNEL_MEAN) && img->channels >= 3)
    return (float)(((double)t[0] + (double)t[1] + (double)t[2]) / 3.0);
  if (ch == BB_CHANNEL_G) return t[1];
  if (ch == BB_CHANNEL_B) return t[2];
  if (ch == BB_CHANNEL_A) return t[img->channels - 1];
  return t[0];
}

/* The rule asked for ch gives the heights of channel as (AUTO resolves). */
static void check_rule_as(const bb_image *img, int alpha_channel, bb_channel ch, bb_channel as) {
  bb_image h;
  bb_error err = {{0}};
  cr_assert_eq(bb_height_from_image(img, alpha_channel, ch, &h, &err), BB_OK, "%s",
               err.message);
  for (int y = 0; y < img->height; y++)
    for (int x = 0; x < img->width; x++)
      cr_assert_eq(*bb_image_texel(&h, x, y), expected(img, x, y, as),
                   "%d channels, '%s' as '%s', texel (%d, %d)", img->channels,
                   bb__channel_name(ch), bb__channel_name(as), x, y);
  bb_image_free(&h);
}

static void check_rule(const bb_image *img, int alpha_channel, bb_channel ch) {
  bb_image h;
  bb_error err = {{0}};
  cr_assert_eq(bb_height_from_image(img, alpha_channel, ch, &h, &err), BB_OK, "%s: %s",
               bb__channel_name(ch), err.message);
  cr_assert_eq(h.channels, 1);
  cr_assert_eq(h.width, img->width);
  cr_assert_eq(h.height, img->height);
  for (int y = 0; y < img->height; y++)
    for (int x = 0; x < img->width; x++)
      cr_assert_eq(*bb_image_texel(&h, x, y), expected(img, x, y, ch),
                   "%d channels, '%s', texel (%d, %d)", img->channels, bb__channel_name(ch), x,
                   y);
  bb_image_free(&h);
}

static void check_refused(const bb_image *img, int alpha_channel, bb_channel ch,
                          bb_status want) {
  bb_image h = {5, 5, 1, (float *)&h};
  bb_error err = {{0}};
  cr_assert_eq(bb_height_from_image(img, alpha_channel, ch, &h, &err), want, "%s",
               bb__channel_name(ch));
  cr_assert_null(h.pixels);
  cr_assert_neq(err.message[0], '\0');
}

/* -------------------------------------------------------------- parsing */

Test(load, parse_every_name_and_back) {
  const char *names[] = {"auto", "r", "g", "b", "a", "luma", "mean"};
  const bb_channel values[] = {BB_CHANNEL_AUTO, BB_CHANNEL_R, BB_CHANNEL_G, BB_CHANNEL_B,
                               BB_CHANNEL_A, BB_CHANNEL_LUMA, BB_CHANNEL_MEAN};
  for (int i = 0; i < 7; i++) {
    bb_channel c = (bb_channel)99;
    cr_assert_eq(bb__channel_parse(names[i], &c, NULL), 0, "%s", names[i]);
    cr_assert_eq(c, values[i]);
    cr_assert_str_eq(bb__channel_name(values[i]), names[i]);
  }
}

Test(load, parse_ignores_case_and_rejects_others) {
  bb_channel c = BB_CHANNEL_AUTO;
  cr_assert_eq(bb__channel_parse("LUMA", &c, NULL), 0);
  cr_assert_eq(c, BB_CHANNEL_LUMA);
  c = BB_CHANNEL_R;
  cr_assert_neq(bb__channel_parse("alpha", &c, NULL), 0);
  cr_assert_neq(bb__channel_parse("", &c, NULL), 0);
  cr_assert_neq(bb__channel_parse(NULL, &c, NULL), 0);
  cr_assert_neq(bb__channel_parse("r ", &c, NULL), 0);
  cr_assert_eq(c, BB_CHANNEL_R, "a failed parse changed the output");
  cr_assert_str_eq(bb__channel_name((bb_channel)42), "unknown");
}

/* ---------------------------------------------------- rule on buffers */

Test(load, one_channel_image) {
  bb_image img = make_image(4, 3, 1);
  check_rule(&img, -1, BB_CHANNEL_AUTO);
  check_rule(&img, -1, BB_CHANNEL_R);
  check_rule(&img, -1, BB_CHANNEL_LUMA); /* the luma of grey is the grey */
  check_rule(&img, -1, BB_CHANNEL_MEAN);
  check_refused(&img, -1, BB_CHANNEL_G, BB_ERR_ARGUMENT);
  check_refused(&img, -1, BB_CHANNEL_B, BB_ERR_ARGUMENT);
  check_refused(&img, -1, BB_CHANNEL_A, BB_ERR_ARGUMENT);
  bb_image_free(&img);
}

Test(load, grey_alpha_image_uses_grey) {
  bb_image img = make_image(4, 3, 2);
  for (int alpha = -1; alpha <= 1; alpha += 2) {
    check_rule(&img, alpha, BB_CHANNEL_AUTO);
    check_rule(&img, alpha, BB_CHANNEL_A);
    check_refused(&img, alpha, BB_CHANNEL_G, BB_ERR_ARGUMENT);
  }
  bb_image_free(&img);
}

Test(load, rgb_image_uses_mean_in_double) {
  bb_image img = make_image(5, 4, 3);
  /* A texel where float summation would round differently from double. */
  float *t = bb_image_texel(&img, 1, 2);
  t[0] = 16777216.0f;
  t[1] = 1.0f;
  t[2] = 1.0f;
  check_rule(&img, -1, BB_CHANNEL_AUTO);
  check_rule(&img, -1, BB_CHANNEL_MEAN);
  bb_image h;
  cr_assert_eq(bb_height_from_image(&img, -1, BB_CHANNEL_AUTO, &h, NULL), BB_OK);
  cr_assert_eq(*bb_image_texel(&h, 1, 2), (float)(16777218.0 / 3.0));
  bb_image_free(&h);
  check_rule(&img, -1, BB_CHANNEL_R);
  check_rule(&img, -1, BB_CHANNEL_G);
  check_rule(&img, -1, BB_CHANNEL_B);
  check_rule(&img, -1, BB_CHANNEL_LUMA);
  check_refused(&img, -1, BB_CHANNEL_A, BB_ERR_ARGUMENT);
  bb_image_free(&img);
}

Test(load, luma_uses_rec709_weights) {
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, 3, 1, 3, NULL), BB_OK);
  for (int x = 0; x < 3; x++) bb_image_texel(&img, x, 0)[x] = 1.0f; /* pure R, G, B */
  bb_image h;
  cr_assert_eq(bb_height_from_image(&img, -1, BB_CHANNEL_LUMA, &h, NULL), BB_OK);
  cr_assert_float_eq(h.pixels[0], 0.2126f, 1e-7);
  cr_assert_float_eq(h.pixels[1], 0.7152f, 1e-7);
  cr_assert_float_eq(h.pixels[2], 0.0722f, 1e-7);
  bb_image_free(&h);
  bb_image_free(&img);
}

/* Valve's convention where the image shows it: a colour (R, G, B differ)
 * with a graded alpha bakes the alpha; the mean is there when asked. */
Test(load, rgba_colour_with_graded_alpha_takes_alpha) {
  bb_image img = make_image(3, 3, 4);
  check_rule_as(&img, 3, BB_CHANNEL_AUTO, BB_CHANNEL_A);
  check_rule_as(&img, -1, BB_CHANNEL_AUTO, BB_CHANNEL_A); /* an unflagged 4th is alpha */
  check_rule(&img, 3, BB_CHANNEL_MEAN);
  check_rule(&img, 3, BB_CHANNEL_A);
  bb_image_free(&img);
}

/* A cutout mask (alpha at its extremes but for an edge) is no height: the
 * colour's mean stays the height. */
Test(load, rgba_colour_with_a_mask_keeps_the_colour) {
  bb_image img = make_image(4, 4, 4);
  for (int i = 0; i < 16; i++)
    img.pixels[4 * i + 3] = i < 9 ? 1.0f : i < 15 ? 0.0f : 0.5f;
  check_rule_as(&img, 3, BB_CHANNEL_AUTO, BB_CHANNEL_MEAN);
  /* A grey image with a graded alpha keeps its grey as well. */
  for (int i = 0; i < 16; i++) {
    float *t = img.pixels + 4 * i;
    t[1] = t[2] = t[0];
    t[3] = 0.1f + 0.05f * (float)i;
  }
  cr_assert_eq(bb__height_channel(&img, 3, BB_CHANNEL_AUTO), BB_CHANNEL_MEAN);
  bb_image_free(&img);
}

Test(load, alpha_index_outside_the_image_is_refused) {
  bb_image img = make_image(2, 2, 3);
  check_refused(&img, 3, BB_CHANNEL_AUTO, BB_ERR_ARGUMENT);
  bb_image_free(&img);
}

Test(load, five_channels_use_flagged_alpha) {
  bb_image img = make_image(2, 2, 5);
  bb_image h;
  cr_assert_eq(bb_height_from_image(&img, 4, BB_CHANNEL_A, &h, NULL), BB_OK);
  cr_assert_eq(h.pixels[0], img.pixels[4]);
  bb_image_free(&h);
  check_refused(&img, -1, BB_CHANNEL_A, BB_ERR_ARGUMENT);
  bb_image_free(&img);
}

/* Valve's convention: a constant colour (0.75) and the height in the last
 * channel, alpha = 0.1 x + 0.01 y. */
static bb_image height_in_alpha(int w, int h, int channels) {
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, w, h, channels, NULL), BB_OK);
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++) {
      float *t = bb_image_texel(&img, x, y);
      for (int c = 0; c < channels - 1; c++)
        t[c] = 0.75f;
      t[channels - 1] = (float)(0.1 * x + 0.01 * y);
    }
  return img;
}

Test(load, auto_takes_alpha_when_only_alpha_varies) {
  for (int channels = 2; channels <= 4; channels += 2) {
    bb_image img = height_in_alpha(4, 3, channels);
    cr_assert_eq(bb__height_channel(&img, -1, BB_CHANNEL_AUTO), BB_CHANNEL_A);
    cr_assert_eq(bb__height_channel(&img, channels - 1, BB_CHANNEL_AUTO), BB_CHANNEL_A);
    check_rule(&img, -1, BB_CHANNEL_A);
    bb_image h;
    cr_assert_eq(bb_height_from_image(&img, -1, BB_CHANNEL_AUTO, &h, NULL), BB_OK);
    for (int y = 0; y < 3; y++)
      for (int x = 0; x < 4; x++)
        cr_assert_eq(*bb_image_texel(&h, x, y), bb_image_texel(&img, x, y)[channels - 1],
                     "%d channels, texel (%d, %d): auto should read alpha", channels, x, y);
    bb_image_free(&h);
    /* An explicit request is kept: the mean of the constant colour is flat. */
    cr_assert_eq(bb__height_channel(&img, -1, BB_CHANNEL_MEAN), BB_CHANNEL_MEAN);
    cr_assert_eq(bb_height_from_image(&img, -1, BB_CHANNEL_MEAN, &h, NULL), BB_OK);
    cr_assert_eq(*bb_image_texel(&h, 3, 2), 0.75f);
    bb_image_free(&h);
    bb_image_free(&img);
  }
}

Test(load, auto_keeps_the_colour_otherwise) {
  bb_image img = height_in_alpha(4, 3, 4);
  /* The last texel's green differs: a colour, and alpha a graded height. */
  bb_image_texel(&img, 3, 2)[1] = 0.5f;
  cr_assert_eq(bb__height_channel(&img, -1, BB_CHANNEL_AUTO), BB_CHANNEL_A);
  /* A constant alpha too: nothing varies, nothing to prefer. */
  bb_image_texel(&img, 3, 2)[1] = 0.75f;
  for (int i = 0; i < 12; i++)
    img.pixels[i * 4 + 3] = 0.5f;
  cr_assert_eq(bb__height_channel(&img, -1, BB_CHANNEL_AUTO), BB_CHANNEL_MEAN);
  /* Alpha flagged inside the colour channels, or outside the image. */
  cr_assert_eq(bb__height_channel(&img, 1, BB_CHANNEL_AUTO), BB_CHANNEL_MEAN);
  cr_assert_eq(bb__height_channel(&img, 7, BB_CHANNEL_AUTO), BB_CHANNEL_MEAN);
  bb_image_free(&img);
  /* No alpha: a constant RGB image stays the mean. */
  img = height_in_alpha(4, 3, 3);
  cr_assert_eq(bb__height_channel(&img, -1, BB_CHANNEL_AUTO), BB_CHANNEL_MEAN);
  bb_image_free(&img);
  /* Five channels: only a flagged alpha counts. */
  img = height_in_alpha(4, 3, 5);
  cr_assert_eq(bb__height_channel(&img, -1, BB_CHANNEL_AUTO), BB_CHANNEL_MEAN);
  cr_assert_eq(bb__height_channel(&img, 4, BB_CHANNEL_AUTO), BB_CHANNEL_A);
  bb_image_free(&img);
  /* One texel cannot vary. */
  img = height_in_alpha(1, 1, 4);
  cr_assert_eq(bb__height_channel(&img, -1, BB_CHANNEL_AUTO), BB_CHANNEL_MEAN);
  bb_image_free(&img);
  cr_assert_eq(bb__height_channel(NULL, -1, BB_CHANNEL_AUTO), BB_CHANNEL_MEAN);
}

Test(load, nan_height_names_the_first_bad_texel) {
  bb_image img = make_image(4, 3, 1);
  *bb_image_texel(&img, 3, 2) = NAN;
  *bb_image_texel(&img, 2, 1) = INFINITY; /* earlier in row order */
  bb_image h;
  bb_error err;
  cr_assert_eq(bb_height_from_image(&img, -1, BB_CHANNEL_AUTO, &h, &err), BB_ERR_VALUE);
  cr_assert_null(h.pixels);
  cr_assert_not_null(strstr(err.message, "(2, 1)"), "%s", err.message);
  cr_assert_not_null(strstr(err.message, "infinite"), "%s", err.message);
  bb_image_free(&img);
}

Test(load, nan_in_one_colour_channel_poisons_the_mean) {
  bb_image img = make_image(3, 2, 3);
  bb_image_texel(&img, 1, 1)[2] = NAN;
  bb_image h;
  bb_error err;
  cr_assert_eq(bb_height_from_image(&img, -1, BB_CHANNEL_AUTO, &h, &err), BB_ERR_VALUE);
  cr_assert_not_null(strstr(err.message, "(1, 1)"), "%s", err.message);
  cr_assert_not_null(strstr(err.message, "NaN"), "%s", err.message);
  /* R alone is finite. */
  cr_assert_eq(bb_height_from_image(&img, -1, BB_CHANNEL_R, &h, &err), BB_OK);
  bb_image_free(&h);
  bb_image_free(&img);
}

Test(load, nan_in_unused_alpha_is_fine) {
  bb_image img = make_image(2, 2, 4);
  bb_image_texel(&img, 0, 0)[3] = NAN;
  bb_image h;
  cr_assert_eq(bb_height_from_image(&img, 3, BB_CHANNEL_AUTO, &h, NULL), BB_OK);
  bb_image_free(&h);
  cr_assert_eq(bb_height_from_image(&img, 3, BB_CHANNEL_A, &h, NULL), BB_ERR_VALUE);
  bb_image_free(&img);
}

Test(load, empty_image_is_refused) {
  bb_image img = {0, 0, 0, NULL};
  check_refused(&img, -1, BB_CHANNEL_AUTO, BB_ERR_ARGUMENT);
}

/* ------------------------------------------------------- rule on files */

static void write_file(const char *name, const bb_image *img, bb_depth depth) {
  bb_write_options o = {depth, BB_RANGE_UNIT, NULL, NULL};
  bb_error err;
  cr_assert_eq(bb__image_write(tmp_path(name), img, &o, &err), BB_OK, "%s", err.message);
}

/* Loads name with the rule and compares with expected() on the written
 * image, within tol (the file's quantisation). */
static void check_load(const char *name, const bb_image *img, bb_channel ch, double tol) {
  bb_image h;
  bb_error err = {{0}};
  cr_assert_eq(bb__height_load(tmp_path(name), ch, &h, &(bb__height_loaded){0}, &err), BB_OK, "%s", err.message);
  cr_assert_eq(h.channels, 1);
  for (int y = 0; y < img->height; y++)
    for (int x = 0; x < img->width; x++)
      cr_assert_float_eq(*bb_image_texel(&h, x, y), expected(img, x, y, ch), tol,
                         "%s '%s' texel (%d, %d)", name, bb__channel_name(ch), x, y);
  bb_image_free(&h);
}

#define STEP_8 (0.5 / 255.0 + 1e-6)

Test(load, files_with_one_to_four_channels) {
  bb_image g = make_image(6, 5, 1), ga = make_image(6, 5, 2);
  bb_image rgb = make_image(6, 5, 3), rgba = make_image(6, 5, 4);
  write_file("g.png", &g, BB_DEPTH_DEFAULT);
  write_file("ga.png", &ga, BB_DEPTH_DEFAULT);
  write_file("rgb.png", &rgb, BB_DEPTH_DEFAULT);
  write_file("rgba.tga", &rgba, BB_DEPTH_DEFAULT);
  write_file("rgb.exr", &rgb, BB_DEPTH_DEFAULT);
  check_load("g.png", &g, BB_CHANNEL_AUTO, STEP_8);
  check_load("ga.png", &ga, BB_CHANNEL_AUTO, STEP_8);
  check_load("ga.png", &ga, BB_CHANNEL_A, STEP_8);
  check_load("rgb.png", &rgb, BB_CHANNEL_AUTO, STEP_8);
  check_load("rgb.png", &rgb, BB_CHANNEL_LUMA, STEP_8);
  check_load("rgb.png", &rgb, BB_CHANNEL_B, STEP_8);
  check_load("rgba.tga", &rgba, BB_CHANNEL_MEAN, STEP_8);
  check_load("rgba.tga", &rgba, BB_CHANNEL_A, STEP_8);
  check_load("rgb.exr", &rgb, BB_CHANNEL_AUTO, 0.0);
  check_load("rgb.exr", &rgb, BB_CHANNEL_G, 0.0);
  /* A TGA with a constant colour and the height in alpha loads its alpha. */
  bb_image valve = height_in_alpha(6, 5, 4);
  write_file("rgba.tga", &valve, BB_DEPTH_DEFAULT);
  check_load("rgba.tga", &valve, BB_CHANNEL_A, STEP_8);
  bb_image h;
  cr_assert_eq(bb__height_load(tmp_path("rgba.tga"), BB_CHANNEL_AUTO, &h, &(bb__height_loaded){0}, NULL), BB_OK);
  cr_assert_float_eq(*bb_image_texel(&h, 5, 4), 0.54, STEP_8, "alpha at (5, 4)");
  bb_image_free(&h);
  bb_image_free(&valve);
  bb_image_free(&g);
  bb_image_free(&ga);
  bb_image_free(&rgb);
  bb_image_free(&rgba);
}

Test(load, file_errors_name_the_file) {
  bb_image g = make_image(3, 3, 1);
  write_file("g.png", &g, BB_DEPTH_DEFAULT);
  bb_image h;
  bb_error err;
  cr_assert_eq(bb__height_load(tmp_path("g.png"), BB_CHANNEL_G, &h, &(bb__height_loaded){0}, &err), BB_ERR_ARGUMENT);
  cr_assert_null(h.pixels);
  cr_assert_eq(strncmp(err.message, tmp_path("g.png"), strlen(tmp_path("g.png"))), 0, "%s",
               err.message);
  cr_assert_eq(bb__height_load(tmp_path("missing.png"), BB_CHANNEL_AUTO, &h, &(bb__height_loaded){0}, &err), BB_ERR_IO);
  cr_assert_not_null(strstr(err.message, "missing.png: no such file"), "%s", err.message);
  bb_image_free(&g);
}

static void check_bad_float_file(const char *name, float bad, const char *word) {
  bb_image img = make_image(5, 4, 3);
  bb_image_texel(&img, 4, 3)[1] = bad;
  write_file(name, &img, BB_DEPTH_FLOAT);
  bb_image h;
  bb_error err;
  cr_assert_eq(bb__height_load(tmp_path(name), BB_CHANNEL_AUTO, &h, &(bb__height_loaded){0}, &err), BB_ERR_VALUE);
  cr_assert_null(h.pixels);
  cr_assert_not_null(strstr(err.message, name), "%s", err.message);
  cr_assert_not_null(strstr(err.message, "(4, 3)"), "%s", err.message);
  cr_assert_not_null(strstr(err.message, word), "%s", err.message);
  /* Red is finite there, so asking for it loads. */
  cr_assert_eq(bb__height_load(tmp_path(name), BB_CHANNEL_R, &h, &(bb__height_loaded){0}, &err), BB_OK, "%s",
               err.message);
  bb_image_free(&h);
  bb_image_free(&img);
}

Test(load, nan_in_float_exr_is_a_value_error) { check_bad_float_file("nan.exr", NAN, "NaN"); }
Test(load, inf_in_float_exr_is_a_value_error) {
  check_bad_float_file("inf.exr", -INFINITY, "infinite");
}
