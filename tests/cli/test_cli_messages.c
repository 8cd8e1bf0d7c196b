/* test_cli_messages.c: what a new user reads: mistyped and abbreviated
 * options, a missing argument named as missing, every command saying what
 * it wrote, and the notes about an input (the channel taken, a JPEG, 8-bit
 * heights that terrace). */
#define _XOPEN_SOURCE 700 /* mkdtemp, nftw, realpath */
#define _DEFAULT_SOURCE    /* wait4 (cli_harness.h) */

#include "bumpbake.h"
#include "cli_harness.h"

#include <math.h>

TestSuite(cli_messages, .init = harness_setup, .fini = harness_teardown, .timeout = 300);

static void dome(const char *path, int channels, bb_depth depth) {
  bb_image h;
  cr_assert_eq(bb_image_alloc(&h, 32, 32, channels, NULL), BB_OK);
  for (int y = 0; y < 32; y++)
    for (int x = 0; x < 32; x++) {
      float *t = bb_image_texel(&h, x, y);
      const double r2 = ((x - 16) * (x - 16) + (y - 16) * (y - 16)) / 200.0;
      for (int c = 0; c < channels; c++)
        t[c] = (float)(c == 3 ? exp(-r2) : 0.2 + 0.2 * c + 0.01 * x);
    }
  harness_write(path, &h, depth, BB_RANGE_UNIT);
  bb_image_free(&h);
}

static void expect_usage(const char *const *args, const char *part) {
  cli_result r = harness_run(args);
  harness_expect_error(&r, 2, part, args[1]);
  cli_result_free(&r);
}

Test(cli_messages, options_must_be_named_in_full) {
  expect_usage((const char *[]){"bake", "h.png", "--normals", "n.png", NULL},
               "did you mean --normal?");
  expect_usage((const char *[]){"bake", "h.png", "--out", "p", NULL},
               "ambiguous: --output, --out-dir");
  /* getopt would take --ray for --rays without a word. */
  expect_usage((const char *[]){"bake", "h.png", "--ray", "16", NULL}, "did you mean --rays?");
  expect_usage((const char *[]){"height2ssbump", "rock.tga", NULL}, "missing BUMPSCALE");
}

Test(cli_messages, every_command_says_what_it_wrote) {
  dome(tmp("h.png"), 1, BB_DEPTH_16);
  cli_result r = harness_run(
      (const char *[]){"height2ssbump", "-r", "16", "-f", "2", tmp("h.png"), "8", NULL});
  cr_expect_eq(r.code, 0, "%s", r.err);
  cr_expect(strstr(r.out, "wrote ssbump+height ") && strstr(r.out, "h-ssbump.tga"), "%s",
            r.out);
  cli_result_free(&r);
  r = harness_run((const char *[]){"compare", tmp("h.png"), tmp("h.png"), "--diff",
                                   tmp("d.exr"), NULL});
  cr_expect(strstr(r.out, "wrote diff "), "%s", r.out);
  cli_result_free(&r);
  r = harness_run((const char *[]){"normal", tmp("h.png"), "--scale", "4", "-o", tmp("n.png"),
                                   "--json", NULL});
  cr_expect_eq(r.code, 0, "%s", r.err);
  cr_expect(r.out[0] == '{' && strstr(r.out, "\"kind\":\"normal\""), "%s", r.out);
  cli_result_free(&r);
}

/* Notes say which channel became the height when the image left a choice,
 * and what a JPEG or an 8-bit height at a high scale will cost. */
Test(cli_messages, notes_about_the_input) {
  dome(tmp("colour.tga"), 4, BB_DEPTH_8); /* colour in RGB, a graded height in alpha */
  cli_result r = harness_run((const char *[]){"normal", tmp("colour.tga"), "--scale", "4",
                                              "-o", tmp("n.png"), NULL});
  cr_expect_eq(r.code, 0, "%s", r.err);
  cr_expect(strstr(r.err, "note: ") && strstr(r.err, "using alpha as the height"), "%s", r.err);
  cli_result_free(&r);
  dome(tmp("h8.png"), 1, BB_DEPTH_8);
  r = harness_run((const char *[]){"normal", tmp("h8.png"), "--scale", "128", "-o",
                                   tmp("n.png"), NULL});
  cr_expect(strstr(r.err, "8-bit heights") && strstr(r.err, "16-bit height avoids them"), "%s",
            r.err);
  cli_result_free(&r);
  r = harness_run((const char *[]){"normal", tmp("h8.png"), "--scale", "16", "-o", tmp("n.png"),
                                   NULL});
  cr_expect_str_empty(r.err, "no terraces to speak of at scale 16: %s", r.err);
  cli_result_free(&r);
  /* A JPEG height, written by OpenImageIO itself. */
  bb_image img;
  cr_assert_eq(bb_image_read(tmp("h8.png"), &img, NULL, NULL), BB_OK);
  cr_assert_eq(bb_image_write(tmp("h.tif"), &img, NULL, NULL), BB_OK);
  bb_image_free(&img);
  char command[8192];
  snprintf(command, sizeof command, "oiiotool '%s' -o '%s' >/dev/null 2>&1", tmp("h.tif"),
           tmp("h.jpg"));
  if (system(command) != 0)
    cr_skip_test("oiiotool cannot write JPEG here");
  r = harness_run((const char *[]){"normal", tmp("h.jpg"), "--scale", "4", "-o", tmp("n.png"),
                                   NULL});
  cr_expect(strstr(r.err, "a JPEG height"), "%s", r.err);
  cli_result_free(&r);
}
