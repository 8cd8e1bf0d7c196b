/* test_cli.c: the bumpbake command line, run as a program (BB_BIN, default
 * build/bumpbake) on inputs the library writes into a temporary directory. */
#define _XOPEN_SOURCE 700 /* mkdtemp, nftw, realpath */
#define _DEFAULT_SOURCE    /* wait4 */

#include "bumpbake.h"
#include "hostile_tiff.h"

#include <criterion/criterion.h>

#include <ctype.h>
#include <fcntl.h>
#include <ftw.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <dirent.h>
#include <signal.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/time.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "cli_harness.h"
#include "image/image_write.h"
#include "files/provenance.h" /* bb__provenance_classify */

/* The whole content of a file (malloc'd), its size in *size. */
static unsigned char *read_bytes(const char *path, size_t *size) {
  FILE *f = fopen(path, "rb");
  cr_assert_not_null(f, "cannot open %s", path);
  fseek(f, 0, SEEK_END);
  long n = ftell(f);
  rewind(f);
  unsigned char *buf = malloc((size_t)n + 1);
  cr_assert_not_null(buf);
  *size = fread(buf, 1, (size_t)n, f);
  fclose(f);
  return buf;
}

/* ------------------------------------------------------- input images */

/* Writes a channels-deep image whose every texel is value(x, y, c). */
typedef float (*texel_fn)(int x, int y, int c);

static void write_image(const char *path, int w, int h, int channels, texel_fn value) {
  bb_image img;
  bb_error err;
  cr_assert_eq(bb_image_alloc(&img, w, h, channels, &err), BB_OK);
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++)
      for (int c = 0; c < channels; c++)
        bb_image_texel(&img, x, y)[c] = value(x, y, c);
  bb_write_options o = {BB_DEPTH_DEFAULT, BB_RANGE_UNIT, NULL, NULL};
  cr_assert_eq(bb__image_write(path, &img, &o, &err), BB_OK, "%s", err.message);
  bb_image_free(&img);
}

static float mid_grey(int x, int y, int c) {
  (void)x, (void)y, (void)c;
  return 0.5f;
}

/* Height rising downwards (+y) by 0.02 per texel. */
static float ramp_down(int x, int y, int c) {
  (void)x, (void)c;
  return 0.02f * (float)y;
}

static float not_a_number(int x, int y, int c) {
  (void)c;
  return (x == 3 && y == 2) ? NAN : 0.25f;
}

/* Reads an output and returns it (the test fails if it cannot be read). */
static bb_image read_image(const char *path, bb_image_info *info) {
  bb_image img;
  bb_error err;
  cr_assert_eq(bb_image_read(path, &img, info, &err), BB_OK, "%s: %s", path, err.message);
  return img;
}

/* Channel c of texel (x, y) of an 8-bit output, as the integer code. */
static int code8(const bb_image *img, int x, int y, int c) {
  return (int)lrintf(bb_image_texel(img, x, y)[c] * 255.0f);
}

/* Asserts every texel of an 8-bit file has the given codes (+-tol). */
static void expect_uniform8(const char *path, int channels, const int *codes, int tol) {
  bb_image img = read_image(path, NULL);
  cr_assert_eq(img.channels, channels, "%s: %d channels", path, img.channels);
  for (int y = 0; y < img.height; y++)
    for (int x = 0; x < img.width; x++)
      for (int c = 0; c < channels; c++) {
        int got = code8(&img, x, y, c);
        cr_assert(abs(got - codes[c]) <= tol, "%s (%d,%d) channel %d: %d, expected %d",
                  path, x, y, c, got, codes[c]);
      }
  bb_image_free(&img);
}

TestSuite(cli, .init = harness_setup, .fini = harness_teardown, .timeout = 600);

/* ---------------------------------------------------------- help, version */

Test(cli, help_and_version) {
  cli_result r = RUN("--help");
  cr_expect_eq(r.code, 0);
  cr_expect(strstr(r.out, "normal") && strstr(r.out, "bake") &&
                strstr(r.out, "height2ssbump"),
            "%s", r.out);
  cli_result_free(&r);

  r = RUN("--version");
  cr_expect_eq(r.code, 0);
  cr_expect_str_eq(r.out, "bumpbake " BB_VERSION_STRING "\n");
  cli_result_free(&r);

  /* A command's help lists every option with its default. */
  r = RUN("bake", "--help");
  cr_expect_eq(r.code, 0);
  const char *expected[] = {"--scale", "--rays",    "256",     "--filter-radius",
                            "--bias",  "0.55",      "--power", "--basis",
                            "hl2",     "--threads", "--json",  "--bent"};
  for (size_t i = 0; i < sizeof expected / sizeof expected[0]; i++)
    cr_expect(strstr(r.out, expected[i]), "bake --help lacks %s", expected[i]);
  cli_result_free(&r);

  r = RUN("height2ssbump", "--help");
  cr_expect_eq(r.code, 0);
  cr_expect(strstr(r.out, "250"), "height2ssbump --help should show 250 rays: %s", r.out);
  /* -f takes what --filter-radius takes (the library's 0..4096). */
  cr_expect(strstr(r.out, "default 10; range 0..4096"), "height2ssbump -f range: %s", r.out);
  cli_result_free(&r);
}

/* ------------------------------------------------------------ usage errors */

typedef struct usage_case {
  const char *args[12];
  const char *message_part; /* the message must name the problem */
} usage_case;

Test(cli, usage_errors_exit_2_with_a_message) {
  const char *in = tmp("h.png");
  write_image(in, 8, 8, 1, mid_grey);
  const char *out = tmp("o.png");
  const usage_case cases[] = {
      {{"frobnicate"}, "frobnicate"},
      {{"normal", in, "-o", out, "--scale", "1", "--bogus"}, "--bogus"},
      {{"normal", in, "-o", out, "--scale"}, "--scale"},
      {{"normal", in, "-o", out}, "--scale"},
      {{"normal", in, "-o", out, "--scale", "0"}, "--scale must be > 0"},
      {{"normal", in, "-o", out, "--scale", "-1"}, "--scale must be > 0 (got -1)"},
      {{"normal", in, "-o", out, "--scale", "abc"}, "abc"},
      {{"normal", in, "-o", out, "--scale", "1", "--filter-radius", "-1"},
       "--filter-radius"},
      {{"normal", in, "-o", out, "--scale", "1", "--filter-radius", "2.5"},
       "--filter-radius"},
      {{"normal", in, "-o", out, "--scale", "1", "--filter-threshold", "0"},
       "--filter-threshold"},
      {{"normal", in, "-o", out, "--scale", "1", "--normal-filter", "fancy"},
       "--normal-filter"},
      {{"normal", in, "-o", out, "--scale", "1", "--normal-y", "sideways"}, "--normal-y"},
      {{"normal", in, "-o", out, "--scale", "1", "--channel", "q"}, "--channel"},
      {{"normal", in, "--scale", "1"}, "-o"},
      {{"bake", in, "--scale", "1", "--rays", "0", "-o", tmp("p")}, "--rays"},
      {{"bake", in, "--scale", "1", "--rays", "65537", "-o", tmp("p")}, "--rays"},
      {{"bake", in, "--scale", "1", "--bias", "-0.1", "-o", tmp("p")}, "--bias"},
      {{"bake", in, "--scale", "1", "--power", "0.5", "-o", tmp("p")}, "--power"},
      /* Ranges of the library's parameters, each checked by its one range
       * (the library's words, naming the option). */
      {{"bake", in, "--scale", "1", "--threads", "4097", "-o", tmp("p")},
       "bumpbake bake: --threads must be in 0..4096 (got 4097)"},
      {{"normal", in, "-o", out, "--threads", "-1", "--scale", "1"},
       "bumpbake normal: --threads must be in 0..4096 (got -1)"},
      {{"bake", in, "--scale", "1", "--filter-radius", "4097", "-o", tmp("p")},
       "--filter-radius must be in 0..4096 (got 4097)"},
      {{"bake", in, "--scale", "1", "--bias", "2e6", "-o", tmp("p")},
       "--bias must be in 0..1e6 (got 2e6)"},
      {{"bake", in, "--scale", "1", "--power", "1e7", "-o", tmp("p")},
       "--power must be in 1..1e6 (got 1e7)"},
      {{"bake", in, "--scale", "1", "--threads", "99999999999", "-o", tmp("p")},
       "--threads must be in 0..4096 (got 99999999999)"},
      {{"bake", in, "--scale", "1", "--basis", "hl3", "-o", tmp("p")}, "--basis"},
      {{"bake", in, "--scale", "1"}, "nothing to write"},
      {{"bake", in, "--scale", "1", "--ao", tmp("ao.jpg2")},
       "unknown output format '.jpg2' (use .png, .tga, .tif, .tiff, .exr, .vtf or .dds)"},
      /* No extension at all is said so, not shown as an extension '.'. */
      {{"bake", in, "--scale", "1", "--ao", tmp("ao")},
       "ao: no extension to choose the format by (use .png, .tga, .tif, .tiff, .exr, .vtf or .dds)"},
      {{"bake", in, "--scale", "1", "--ao", tmp("ao.exr"), "--depth", "16"}, "--depth"},
      {{"bake", "--scale", "1", "-o", tmp("p")}, "HEIGHT"},
      {{"height2ssbump", in}, "BUMPSCALE"},
      {{"height2ssbump", in, "0"}, "BUMPSCALE"},
      {{"height2ssbump", "-r", "0", in, "2"}, "-r"},
      {{"height2ssbump", "-x", in, "2"}, "-x"},
  };
  size_t before_size;
  unsigned char *before = read_bytes(in, &before_size);
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    cli_result r = harness_run_in(NULL, cases[i].args);
    cr_expect_eq(r.code, 2, "case %zu (%s %s ...): exit %d, stderr: %s", i,
                 cases[i].args[0], cases[i].args[1] ? cases[i].args[1] : "", r.code,
                 r.err);
    cr_expect_eq(harness_lines(r.err), 1, "case %zu: stderr should be one line: %s", i,
                 r.err);
    cr_expect(strncmp(r.err, "bumpbake", 8) == 0, "case %zu: %s", i, r.err);
    cr_expect(strstr(r.err, cases[i].message_part), "case %zu: message '%s' lacks '%s'",
              i, r.err, cases[i].message_part);
    cr_expect_str_empty(r.out, "case %zu", i);
    cli_result_free(&r);
    /* Nothing was written: no output, no prefix output, no temporary file. */
    cr_expect(!file_exists(out) && !file_exists(tmp("p_normal.png")) &&
                  !file_exists(tmp("ao.exr")),
              "case %zu wrote a file", i);
  }
  size_t after_size;
  unsigned char *after = read_bytes(in, &after_size);
  cr_expect(before_size == after_size && !memcmp(before, after, before_size));
  free(before);
  free(after);
}

/* ------------------------------------------------------------- bad inputs */

/* Runs args; expects exit 1, one line on stderr naming named_file, the
 * output not created and the input unchanged. */
static void expect_failure(const char *const *args, const char *named_file,
                           const char *output, const char *input) {
  size_t before_size = 0, after_size = 0;
  unsigned char *before = file_exists(input) ? read_bytes(input, &before_size) : NULL;
  cli_result r = harness_run_in(NULL, args);
  cr_expect_eq(r.code, 1, "%s: exit %d, stderr: %s", named_file, r.code, r.err);
  cr_expect_eq(harness_lines(r.err), 1, "stderr should be one line: '%s'", r.err);
  cr_expect(strncmp(r.err, "bumpbake: ", 10) == 0, "%s", r.err);
  cr_expect(strstr(r.err, named_file), "message '%s' should name %s", r.err, named_file);
  cr_expect(!file_exists(output) || !strcmp(output, input), "%s was written", output);
  if (before) {
    unsigned char *after = read_bytes(input, &after_size);
    cr_expect(before_size == after_size && !memcmp(before, after, before_size),
              "%s changed", input);
    free(after);
  }
  free(before);
  cli_result_free(&r);
}

Test(cli, missing_input) {
  const char *in = tmp("nothere.png"), *out = tmp("o.png");
  expect_failure((const char *[]){"normal", in, "-o", out, "--scale", "2", NULL},
                 "nothere.png", out, in);
  expect_failure((const char *[]){"height2ssbump", in, "2", NULL}, "nothere.png",
                 tmp("nothere-ssbump.tga"), in);
}

Test(cli, corrupt_and_empty_inputs) {
  const char *corrupt = tmp("corrupt.png"), *empty = tmp("empty.png"),
             *out = tmp("o.png");
  /* A PNG signature followed by garbage: a reader must look inside. */
  const unsigned char junk[] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n',
                                1,    2,   3,   4,   5,    6,    7,    8};
  write_bytes(corrupt, junk, sizeof junk);
  write_bytes(empty, "", 0);
  expect_failure((const char *[]){"normal", corrupt, "-o", out, "--scale", "2", NULL},
                 "corrupt.png", out, corrupt);
  expect_failure((const char *[]){"bake", empty, "--scale", "2", "--ao", out, NULL},
                 "empty.png", out, empty);
}

Test(cli, nan_heights) {
  const char *in = tmp("nan.exr"), *out = tmp("o.png");
  write_image(in, 8, 8, 1, not_a_number);
  expect_failure((const char *[]){"bake", in, "--scale", "2", "--normal", out, NULL},
                 "nan.exr", out, in);
}

Test(cli, output_equal_to_input) {
  const char *in = tmp("h.png");
  write_image(in, 8, 8, 1, mid_grey);
  expect_failure((const char *[]){"normal", in, "-o", in, "--scale", "2", NULL}, "h.png",
                 in, in);
  /* The same file under another spelling is caught too (realpath). */
  char other[300];
  snprintf(other, sizeof other, "%s/./h.png", harness_dir);
  expect_failure((const char *[]){"bake", in, "--scale", "2", "--ao", other, NULL},
                 "h.png", in, in);
}

Test(cli, unwritable_output_directory) {
  /* A path under a regular file cannot be created, even by root. */
  const char *in = tmp("h.png"), *afile = tmp("afile");
  write_image(in, 8, 8, 1, mid_grey);
  write_bytes(afile, "x", 1);
  char out[300];
  snprintf(out, sizeof out, "%s/out.png", afile);
  expect_failure((const char *[]){"normal", in, "-o", out, "--scale", "2", NULL},
                 "afile/out.png", out, in);
}

/* ------------------------------------------------------------------ normal */

Test(cli, normal_of_flat_map_points_up) {
  const char *in = tmp("flat.png"), *out = tmp("n.png");
  write_image(in, 16, 16, 1, mid_grey);
  cli_result r = RUN("normal", in, "-o", out, "--scale", "8");
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  expect_uniform8(out, 3, (const int[]){128, 128, 255}, 0);
}

Test(cli, normal_y_up_flips_green) {
  const char *in = tmp("ramp.exr"), *down = tmp("down.png"), *up = tmp("up.png");
  write_image(in, 16, 16, 1, ramp_down);
  cli_result r =
      RUN("normal", in, "-o", down, "--scale", "20", "--filter-radius", "0", "--clamp");
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  r = RUN("normal", in, "-o", up, "--scale", "20", "--filter-radius", "0", "--clamp",
          "--normal-y", "up");
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  bb_image a = read_image(down, NULL), b = read_image(up, NULL);
  /* Height grows with y (down the image), so with +Y down the normal leans
   * to -y: green below 0.5; --normal-y up mirrors it. Red is untouched. */
  int g_down = code8(&a, 8, 8, 1), g_up = code8(&b, 8, 8, 1);
  cr_expect_lt(g_down, 110, "green (+Y down) %d", g_down);
  cr_expect(abs((g_down + g_up) - 255) <= 1, "green %d and %d are not mirrored", g_down,
            g_up);
  cr_expect_eq(code8(&a, 8, 8, 0), code8(&b, 8, 8, 0));
  cr_expect_eq(code8(&a, 8, 8, 2), code8(&b, 8, 8, 2));
  bb_image_free(&a);
  bb_image_free(&b);
}

Test(cli, normal_says_what_it_wrote_unless_quiet) {
  const char *in = tmp("flat.png"), *out = tmp("n.png");
  write_image(in, 8, 8, 1, mid_grey);
  cli_result r = RUN("normal", in, "-o", out, "--scale", "8");
  cr_assert_eq(r.code, 0, "%s", r.err);
  char expect[512];
  snprintf(expect, sizeof expect, "wrote normal %s\n", out);
  cr_expect_str_eq(r.out, expect, "as bake says it");
  cr_expect_str_empty(r.err);
  cli_result_free(&r);
  r = RUN("normal", in, "-o", out, "--scale", "8", "-q");
  cr_assert_eq(r.code, 0, "%s", r.err);
  cr_expect_str_empty(r.out, "--quiet");
  cli_result_free(&r);
}

/* Valve's convention: a white colour and the height (rising down) in alpha. */
static float white_with_height_in_alpha(int x, int y, int c) {
  (void)x;
  return c == 3 ? 0.02f * (float)y : 1.0f;
}

Test(cli, height_in_alpha_is_found_and_said) {
  const char *in = tmp("valve.tga"), *out = tmp("n.png"), *ss = tmp("ss.png");
  write_image(in, 16, 16, 4, white_with_height_in_alpha);
  cli_result r = RUN("normal", in, "-o", out, "--scale", "20", "--clamp");
  cr_assert_eq(r.code, 0, "%s", r.err);
  cr_expect_eq(harness_lines(r.err), 1, "one note: %s", r.err);
  cr_expect(strstr(r.err, "valve.tga: note: ") && strstr(r.err, "using alpha as the height"),
            "%s", r.err);
  cli_result_free(&r);
  bb_image n = read_image(out, NULL);
  cr_expect_lt(code8(&n, 8, 8, 1), 110, "the alpha ramp leans the normal (green %d)",
               code8(&n, 8, 8, 1));
  bb_image_free(&n);
  /* bake too; --channel mean asks for the (flat) colour: no note. */
  r = RUN("bake", in, "--scale", "20", "--rays", "16", "--ssbump", ss, "--quiet");
  cr_assert_eq(r.code, 0, "%s", r.err);
  cr_expect(strstr(r.err, "using alpha as the height"), "%s", r.err);
  cli_result_free(&r);
  r = RUN("normal", in, "-o", out, "--scale", "20", "--channel", "mean");
  cr_assert_eq(r.code, 0, "%s", r.err);
  cr_expect_str_empty(r.err);
  cli_result_free(&r);
  expect_uniform8(out, 3, (const int[]){128, 128, 255}, 0);
}

/* -------------------------------------------------------------------- bake */

Test(cli, bake_of_flat_map) {
  const char *in = tmp("flat.png"), *ss = tmp("ss.png"), *ao = tmp("ao.png");
  write_image(in, 16, 16, 1, mid_grey);
  cli_result r =
      RUN("bake", in, "--scale", "8", "--rays", "64", "--ssbump", ss, "--ao", ao);
  cr_assert_eq(r.code, 0, "%s", r.err);
  cr_expect_eq(harness_lines(r.out), 2, "one line per output: %s", r.out);
  cr_expect(strstr(r.out, ss) && strstr(r.out, ao), "%s", r.out);
  cli_result_free(&r);
  int s = (int)lrint(255.0 / sqrt(3.0)); /* 147 */
  expect_uniform8(ss, 3, (const int[]){s, s, s}, 1);
  expect_uniform8(ao, 1, (const int[]){255}, 0);

  /* Provenance travels with the file, with the command line as typed (not
   * as getopt_long permuted it). */
  bb_image_info info;
  bb_image img = read_image(ss, &info);
  char command[512];
  snprintf(command, sizeof command, "command=bumpbake bake %s --scale 8 --rays 64", in);
  cr_expect(info.description && strstr(info.description, command), "%s lacks '%s'",
            info.description ? info.description : "(none)", command);
  cr_expect(info.description && strstr(info.description, "flat.png"),
            "provenance should name the input: %s",
            info.description ? info.description : "(none)");
  bb_image_info_free(&info);
  bb_image_free(&img);
}

/* The command line recorded is quoted for a POSIX shell: pasted into one,
 * a name with a blank or a ';' stays one word and runs nothing. A batch
 * records each input's name quoted the same way. */
Test(cli, the_recorded_command_is_quoted_for_a_shell) {
  const char *in = tmp("my rock;x.png"), *ss = tmp("s s.png");
  write_image(in, 16, 16, 1, mid_grey);
  cli_result r = RUN("bake", in, "--scale", "8", "--rays", "16", "--ssbump", ss);
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  bb_image_info info;
  bb_image img = read_image(ss, &info);
  char command[1024];
  snprintf(command, sizeof command, "command=bumpbake bake '%s' --scale 8 --rays 16 --ssbump '%s'\n",
           in, ss);
  cr_expect(info.description && strstr(info.description, command), "%s lacks '%s'",
            info.description ? info.description : "(none)", command);
  bb_image_info_free(&info);
  bb_image_free(&img);

  const char *dir = tmp("in"), *out = tmp("out");
  cr_assert_eq(mkdir(dir, 0755), 0);
  write_image(tmp("in/a b.png"), 8, 8, 1, mid_grey);
  r = RUN("bake", dir, "--scale", "4", "--rays", "16", "--out-dir", out, "--maps", "ao",
          "--name", "{stem} {kind}.png", "-q");
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  img = read_image(tmp("out/a b ao.png"), &info);
  snprintf(command, sizeof command,
           "command=bumpbake bake '%s/a b.png' --scale 4 --rays 16 --out-dir %s --maps ao "
           "--name '{stem} {kind}.png'\n",
           dir, out);
  cr_expect(info.description && strstr(info.description, command), "%s lacks '%s'",
            info.description ? info.description : "(none)", command);
  bb_image_info_free(&info);
  bb_image_free(&img);
}

Test(cli, bake_prefix_and_quiet) {
  const char *in = tmp("flat.png");
  write_image(in, 8, 8, 1, mid_grey);
  cli_result r =
      RUN("bake", in, "--scale", "4", "--rays", "16", "-o", tmp("rock"), "--quiet");
  cr_assert_eq(r.code, 0, "%s", r.err);
  cr_expect_str_empty(r.out);
  cr_expect_str_empty(r.err);
  cli_result_free(&r);
  cr_expect(file_exists(tmp("rock_normal.png")));
  cr_expect(file_exists(tmp("rock_ssbump.png")));
  cr_expect(file_exists(tmp("rock_ao.png")));
}

/* A small JSON checker (RFC 8259 grammar, no semantics): enough to say the
 * line parses. Returns the position after the value, or NULL. */
static const char *json_value(const char *p);

static const char *json_ws(const char *p) {
  while (*p == ' ' || *p == '\t' || *p == '\n' || *p == '\r')
    p++;
  return p;
}

static const char *json_string(const char *p) {
  if (*p++ != '"')
    return NULL;
  for (; *p != '"'; p++) {
    if (!*p || (unsigned char)*p < 0x20)
      return NULL;
    if (*p == '\\') {
      p++;
      if (*p == 'u') {
        for (int i = 1; i <= 4; i++)
          if (!isxdigit((unsigned char)p[i]))
            return NULL;
        p += 4;
      } else if (!strchr("\"\\/bfnrt", *p) || !*p) {
        return NULL;
      }
    }
  }
  return p + 1;
}

static const char *json_number(const char *p) {
  const char *start = p;
  if (*p == '-')
    p++;
  if (!isdigit((unsigned char)*p))
    return NULL;
  if (*p == '0')
    p++;
  else
    while (isdigit((unsigned char)*p))
      p++;
  if (*p == '.') {
    p++;
    if (!isdigit((unsigned char)*p))
      return NULL;
    while (isdigit((unsigned char)*p))
      p++;
  }
  if (*p == 'e' || *p == 'E') {
    p++;
    if (*p == '+' || *p == '-')
      p++;
    if (!isdigit((unsigned char)*p))
      return NULL;
    while (isdigit((unsigned char)*p))
      p++;
  }
  return p > start ? p : NULL;
}

static const char *json_members(const char *p, char close, int keyed) {
  p = json_ws(p);
  if (*p == close)
    return p + 1;
  for (;;) {
    if (keyed) {
      p = json_string(json_ws(p));
      if (!p)
        return NULL;
      p = json_ws(p);
      if (*p++ != ':')
        return NULL;
    }
    p = json_value(p);
    if (!p)
      return NULL;
    p = json_ws(p);
    if (*p == close)
      return p + 1;
    if (*p++ != ',')
      return NULL;
  }
}

static const char *json_value(const char *p) {
  p = json_ws(p);
  if (*p == '{')
    return json_members(p + 1, '}', 1);
  if (*p == '[')
    return json_members(p + 1, ']', 0);
  if (*p == '"')
    return json_string(p);
  if (!strncmp(p, "true", 4))
    return p + 4;
  if (!strncmp(p, "false", 5))
    return p + 5;
  if (!strncmp(p, "null", 4))
    return p + 4;
  return json_number(p);
}

Test(cli, json_checker_rejects_bad_json) {
  /* The checker itself must be able to fail, or the JSON test proves nothing. */
  cr_expect_not_null(json_value("{\"a\":[1,2.5e3,\"x\\n\"],\"b\":{\"c\":null}}"));
  cr_expect_null(json_value("{\"a\":1,}"));
  cr_expect_null(json_value("{\"a\" 1}"));
  cr_expect_null(json_value("{\"a\":nan}"));
  cr_expect_null(json_value("[1,2"));
}

/* Every line of text is one JSON value; returns the count of lines. */
static int expect_json_lines(const char *text) {
  int lines = 0;
  for (const char *line = text; *line; lines++) {
    const char *end = json_value(line);
    cr_assert_not_null(end, "not JSON: %s", line);
    cr_assert_eq(*end, '\n', "one value per line: %s", line);
    line = end + 1;
  }
  return lines;
}

Test(cli, info_and_compare_json_parse) {
  const char *a = tmp("a.png"), *odd = tmp("q\"uo\\te\tx.tga");
  write_image(a, 8, 8, 1, mid_grey);
  cli_result r = RUN("bake", a, "--scale", "4", "--rays", "4", "--ao", odd, "--quiet");
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  r = RUN("info", "--json", a, odd, tmp("missing.png"));
  cr_expect_eq(r.code, 1, "%s", r.err);
  cr_expect_eq(expect_json_lines(r.out), 3, "%s", r.out);
  cli_result_free(&r);
  r = RUN("compare", "--json", a, a);
  cr_expect_eq(r.code, 0, "%s", r.err);
  cr_expect_eq(expect_json_lines(r.out), 1, "%s", r.out);
  cli_result_free(&r);
  r = RUN("compare", "--json", a, odd);
  cr_expect_eq(r.code, 2, "grey 0.5 against ao 1: %s", r.err);
  cr_expect_eq(expect_json_lines(r.out), 1, "%s", r.out);
  cli_result_free(&r);
  const char *rgb = tmp("rgb.png");
  write_image(rgb, 8, 8, 3, mid_grey);
  r = RUN("compare", "--json", a, rgb);
  cr_expect_eq(r.code, 3, "%s", r.err);
  cr_expect_eq(expect_json_lines(r.out), 1, "%s", r.out);
  /* One line, in words: "1 channel", not "1 channels". */
  cr_expect(strstr(r.err, "8 x 8, 3 channels, but") && strstr(r.err, "8 x 8, 1 channel\n"),
            "%s", r.err);
  cli_result_free(&r);
}

Test(cli, bake_json_is_one_line_with_the_keys) {
  const char *in = tmp("flat.png");
  write_image(in, 8, 8, 1, mid_grey);
  cli_result r = RUN("bake", in, "--scale", "4", "--rays", "16", "--ao", tmp("ao.png"),
                     "--normal", tmp("n.tga"), "--json");
  cr_assert_eq(r.code, 0, "%s", r.err);
  cr_expect_eq(harness_lines(r.out), 1, "%s", r.out);
  const char *end = json_value(r.out);
  cr_assert_not_null(end, "not JSON: %s", r.out);
  cr_expect_str_eq(json_ws(end), "", "trailing text after the JSON value: %s", r.out);
  const char *keys[] = {"input",         "width",         "height",
                        "parameters",    "scale",         "rays",          "slices",
                        "rayset",        "filter_radius", "filter_threshold",
                        "bias",          "power",         "basis",
                        "normal_filter", "normal_y",      "addressing",
                        "channel",       "threads",       "seconds",
                        "load",          "smooth",        "pyramid",
                        "trace",         "derive",        "write",
                        "horizons",      "outputs",       "kind",
                        "path"};
  for (size_t i = 0; i < sizeof keys / sizeof keys[0]; i++) {
    char quoted[64];
    snprintf(quoted, sizeof quoted, "\"%s\":", keys[i]);
    cr_expect(strstr(r.out, quoted), "JSON lacks %s: %s", keys[i], r.out);
  }
  cr_expect(strstr(r.out, "\"kind\":\"ao\"") && strstr(r.out, "\"kind\":\"normal\""),
            "%s", r.out);
  cr_expect(strstr(r.out, "\"horizons\":256"), "8x8 texels x 4 slices (16 rays): %s", r.out);
  cli_result_free(&r);
}

static float alpha_ramp(int x, int y, int c) {
  (void)y;
  return c < 3 ? 0.25f : (float)x / 8.0f;
}

/* --json reports the channel and the threads the bake used, not the
 * requests (auto, 0). */
Test(cli, bake_json_reports_the_channel_and_threads_used) {
  const char *grey = tmp("grey.png"), *rgba = tmp("rgba.png"), *rgb = tmp("rgb.png");
  write_image(grey, 8, 8, 1, mid_grey);
  write_image(rgba, 8, 8, 4, alpha_ramp);
  write_image(rgb, 8, 8, 3, mid_grey);
  const struct {
    const char *input, *threads, *json;
  } cases[] = {
      {grey, "3", "\"channel\":\"grey\",\"threads\":3"},
      {rgba, "1", "\"channel\":\"a\",\"threads\":1"},
      {rgb, "2", "\"channel\":\"mean\",\"threads\":2"},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    cli_result r = RUN("bake", cases[i].input, "--scale", "4", "--normal", tmp("n.png"),
                       "--threads", cases[i].threads, "--json");
    cr_assert_eq(r.code, 0, "%s", r.err);
    cr_expect(strstr(r.out, cases[i].json), "case %zu lacks %s: %s", i, cases[i].json, r.out);
    cli_result_free(&r);
  }
  /* --threads 0: the core count, which is at least 1. */
  cli_result r = RUN("bake", grey, "--scale", "4", "--normal", tmp("n.png"), "--json");
  cr_assert_eq(r.code, 0, "%s", r.err);
  const char *t = strstr(r.out, "\"threads\":");
  cr_assert_not_null(t, "%s", r.out);
  cr_expect_gt(atoi(t + strlen("\"threads\":")), 0, "%s", r.out);
  cli_result_free(&r);
}

/* --filtered writes the height at the input's depth where the format holds
 * it, unless --depth says otherwise; TGA holds 8 bits only. */
Test(cli, filtered_keeps_the_input_depth) {
  const char *in = tmp("h16.png");
  bb_image h;
  cr_assert_eq(bb_image_alloc(&h, 16, 16, 1, NULL), BB_OK);
  for (int i = 0; i < 256; i++)
    h.pixels[i] = (float)(i * 97 % 256) / 255.0f + 1.0f / 65535.0f * (float)(i % 7);
  bb_write_options wo = {BB_DEPTH_16, BB_RANGE_UNIT, NULL, NULL};
  cr_assert_eq(bb__image_write(in, &h, &wo, NULL), BB_OK);
  bb_image_free(&h);
  const struct {
    const char *out, *depth;
    int bits, is_float;
  } cases[] = {
      {"f.png", NULL, 16, 0}, {"f8.png", "8", 8, 0}, {"f.tif", NULL, 16, 0},
      {"f.tga", NULL, 8, 0},  {"f.exr", NULL, 32, 1},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    const char *out = tmp(cases[i].out);
    cli_result r = cases[i].depth
                       ? RUN("bake", in, "--scale", "4", "--filtered", out, "--depth",
                             cases[i].depth, "-q")
                       : RUN("bake", in, "--scale", "4", "--filtered", out, "-q");
    cr_assert_eq(r.code, 0, "%s", r.err);
    cli_result_free(&r);
    bb_image_info info;
    bb_image img = read_image(out, &info);
    cr_expect_eq(info.bits_per_sample, cases[i].bits, "%s", cases[i].out);
    cr_expect_eq(info.is_float, cases[i].is_float, "%s", cases[i].out);
    bb_image_info_free(&info);
    bb_image_free(&img);
  }
  /* An 8-bit input stays 8-bit. */
  const char *in8 = tmp("h8.png");
  write_image(in8, 8, 8, 1, mid_grey);
  cli_result r = RUN("bake", in8, "--scale", "4", "--filtered", tmp("g.png"), "-q");
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  bb_image_info info;
  bb_image img = read_image(tmp("g.png"), &info);
  cr_expect_eq(info.bits_per_sample, 8);
  bb_image_info_free(&info);
  bb_image_free(&img);
}

/* --slices overrides --rays, is recorded in the JSON and the ray-set id,
 * and is checked like any number. */
Test(cli, bake_slices_option) {
  const char *in = tmp("flat.png");
  write_image(in, 8, 8, 1, mid_grey);
  cli_result r = RUN("bake", in, "--scale", "4", "--rays", "16", "--slices", "7", "--ao",
                     tmp("ao.png"), "--json");
  cr_assert_eq(r.code, 0, "%s", r.err);
  cr_expect(strstr(r.out, "\"slices\":7,\"rayset\":\"bb-horizon-v1:a7:"), "%s", r.out);
  cr_expect(strstr(r.out, "\"horizons\":448"), "8x8 texels x 7 slices: %s", r.out);
  cli_result_free(&r);
  const char *bad[] = {"0", "257", "3.5", "x"};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    r = RUN("bake", in, "--scale", "4", "--slices", bad[i], "--ao", tmp("bad.png"));
    cr_expect_eq(r.code, 2, "--slices %s: exit %d", bad[i], r.code);
    cr_expect(strstr(r.err, "--slices"), "--slices %s: %s", bad[i], r.err);
    cr_expect(!file_exists(tmp("bad.png")));
    cli_result_free(&r);
  }
}

/* ------------------------------------------------------------ height2ssbump */

/* Mid-grey colour with a height of 0.25 in alpha: RGB and alpha differ, so
 * the test sees which one became the height. */
static float grey_with_low_alpha(int x, int y, int c) {
  (void)x, (void)y;
  return c == 3 ? 0.25f : 0.5f;
}

static void run_ok_in(const char *cwd, const char *const *args) {
  cli_result r = harness_run_in(cwd, args);
  cr_assert_eq(r.code, 0, "%s: exit %d, stderr: %s", args[0], r.code, r.err);
  cli_result_free(&r);
}

Test(cli, height2ssbump_writes_ssbump_with_height_in_alpha) {
  const char *in = tmp("wall.tga");
  write_image(in, 16, 16, 4, grey_with_low_alpha);
  size_t before_size, after_size;
  unsigned char *before = read_bytes(in, &before_size);
  cli_result r = RUN("height2ssbump", in, "4");
  cr_assert_eq(r.code, 0, "%s", r.err);
  cr_expect_str_empty(r.err, "alpha present: no note expected");
  cli_result_free(&r);
  int s = (int)lrint(255.0 / sqrt(3.0));
  expect_uniform8(tmp("wall-ssbump.tga"), 4, (const int[]){s, s, s, 64}, 1);
  unsigned char *after = read_bytes(in, &after_size);
  cr_expect(before_size == after_size && !memcmp(before, after, before_size));
  free(before);
  free(after);
}

Test(cli, height2ssbump_flags) {
  const char *in = tmp("wall.tga");
  write_image(in, 16, 16, 4, grey_with_low_alpha);
  /* -n: the normal map, height still in alpha. */
  run_ok_in(NULL, (const char *[]){"height2ssbump", "-n", in, "4", NULL});
  expect_uniform8(tmp("wall-bump.tga"), 4, (const int[]){128, 128, 255, 64}, 0);
  /* -A: ao in alpha, 1 on a flat map. */
  run_ok_in(NULL, (const char *[]){"height2ssbump", "-A", "-r", "32", in, "4", NULL});
  int s = (int)lrint(255.0 / sqrt(3.0));
  expect_uniform8(tmp("wall-ssbump.tga"), 4, (const int[]){s, s, s, 255}, 1);
  /* -d: a flat, unoccluded texel of mid-grey input is 0.5 (mod2x neutral). */
  run_ok_in(NULL, (const char *[]){"height2ssbump", "-d", "-r", "32", in, "4", NULL});
  expect_uniform8(tmp("wall-ssbump.tga"), 4, (const int[]){128, 128, 128, 64}, 1);
}

Test(cli, height2ssbump_dump_writes_filtered_in_cwd) {
  write_image(tmp("wall.tga"), 16, 16, 4, grey_with_low_alpha);
  run_ok_in(harness_dir,
            (const char *[]){"height2ssbump", "-D", "-r", "16", "wall.tga", "4", NULL});
  cr_expect(file_exists(tmp("wall-ssbump.tga")));
  bb_image f = read_image(tmp("filtered.tga"), NULL);
  cr_expect_eq(code8(&f, 5, 5, 0), 64);
  bb_image_free(&f);
}

Test(cli, height2ssbump_without_alpha_uses_mean_and_says_so) {
  const char *in = tmp("rgb.png");
  write_image(in, 16, 16, 3, mid_grey);
  cli_result r = RUN("height2ssbump", "-r", "16", in, "4");
  cr_assert_eq(r.code, 0, "%s", r.err);
  cr_expect_eq(harness_lines(r.err), 1, "one note on stderr: %s", r.err);
  /* A note about a file is worded as the other notes: "bumpbake: FILE: note: ...". */
  char prefix[4200];
  snprintf(prefix, sizeof prefix, "bumpbake: %s: note: no alpha channel; using the mean", in);
  cr_expect(strncmp(r.err, prefix, strlen(prefix)) == 0, "%s", r.err);
  cli_result_free(&r);
  int s = (int)lrint(255.0 / sqrt(3.0));
  expect_uniform8(tmp("rgb-ssbump.tga"), 4, (const int[]){s, s, s, 128}, 1);
}

/* Its TGA records the command line as every writing command's output does:
 * the comment's four rows of 80 characters cannot hold it beside the
 * parameters, so it goes to the header's image ID and is read back into
 * the provenance whole. */
Test(cli, height2ssbump_records_its_command) {
  write_image(tmp("wall.tga"), 16, 16, 4, grey_with_low_alpha);
  run_ok_in(harness_dir,
            (const char *[]){"height2ssbump", "-r", "16", "wall.tga", "4", NULL});
  bb_image_info info;
  bb_error err;
  cr_assert_eq(bb_image_read_info(tmp("wall-ssbump.tga"), NULL, NULL, NULL, &info, &err),
               BB_OK, "%s", err.message);
  cr_assert_not_null(info.description);
  cr_expect_eq(bb__provenance_classify(info.description), BB_PROVENANCE_INTACT, "%s",
               info.description);
  cr_expect(strstr(info.description, "\ncommand=bumpbake height2ssbump -r 16 wall.tga 4"),
            "%s", info.description);
  cr_expect(strstr(info.description, "\nfilter_threshold=") &&
                strstr(info.description, "\ninput=wall.tga"),
            "%s", info.description);
  bb_image_info_free(&info);
}

/* ---------------------------------------------------------- renderbumpflat */

/* A 16 x 16 plate in the XZ plane (facing -y, DOOM 3's side) with a square
 * hole over x, z in [6, 10]: four quads, which Assimp triangulates. */
static const char holey_obj[] =
    "v 0 0 0\nv 16 0 0\nv 16 0 6\nv 0 0 6\n"
    "v 0 0 10\nv 16 0 10\nv 16 0 16\nv 0 0 16\n"
    "v 6 0 6\nv 6 0 10\nv 10 0 6\nv 10 0 10\n"
    "f 1 2 3 4\nf 5 6 7 8\nf 4 9 10 5\nf 11 3 6 12\n";

/* An 8 x 8 plane whose height (towards -y) rises by 0.25 per unit along +x
 * and by 0.125 per unit down the image (-z): its normal is
 * normalize(-0.25, -0.125, 1) in the +Y-down tangent frame. */
static const char slope_obj[] =
    "v 0 -1 0\nv 8 -3 0\nv 8 -2 8\nv 0 0 8\nf 1 2 3 4\n";

Test(cli, renderbumpflat_writes_model_local_tga_with_coverage_alpha) {
  const char *model = tmp("holey.obj"), *out = tmp("holey_local.tga");
  write_bytes(model, holey_obj, strlen(holey_obj));
  cli_result r = RUN("renderbumpflat", "-size", "16", "16", model);
  cr_assert_eq(r.code, 0, "%s", r.err);
  cr_expect(strstr(r.out, "wrote normal") && strstr(r.out, "holey_local.tga"), "%s", r.out);
  cr_expect_str_empty(r.err);
  cli_result_free(&r);
  bb_image_info info;
  bb_image img = read_image(out, &info);
  cr_assert_eq(img.width, 16);
  cr_assert_eq(img.channels, 4);
  cr_expect_eq(info.alpha_channel, 3);
  for (int y = 0; y < 16; y++)
    for (int x = 0; x < 16; x++) {
      int hole = x >= 6 && x <= 9 && y >= 6 && y <= 9;
      cr_expect_eq(code8(&img, x, y, 3), hole ? 0 : 255, "alpha at (%d, %d)", x, y);
      cr_expect(code8(&img, x, y, 0) == 128 && code8(&img, x, y, 1) == 128 &&
                    code8(&img, x, y, 2) == 255,
                "flat normal at (%d, %d)", x, y);
    }
  cr_expect(info.description && strstr(info.description, "renderbumpflat"));
  bb_image_info_free(&info);
  bb_image_free(&img);
  /* The default size is DOOM 3's 256 x 256; -o names the file. */
  run_ok_in(NULL, (const char *[]){"renderbumpflat", model, "-o", tmp("n.png"), "-q", NULL});
  img = read_image(tmp("n.png"), NULL);
  cr_expect(img.width == 256 && img.height == 256 && img.channels == 4);
  bb_image_free(&img);
}

/* The height's printed scale is stored in its provenance, and `bumpbake
 * normal` of that height with that scale gives the rendered normal. */
Test(cli, renderbumpflat_height_and_its_scale_agree_with_normal) {
  const char *model = tmp("slope.obj"), *height = tmp("slope_h.png");
  write_bytes(model, slope_obj, strlen(slope_obj));
  cli_result r = RUN("renderbumpflat", "--size", "8", "8", model, "--height", height, "-q");
  cr_assert_eq(r.code, 0, "%s", r.err);
  /* texel centres 0.5 .. 7.5: heights 0.1875 .. 2.8125, a range of 2.625 */
  cr_expect(strstr(r.out, "height scale 2.625 "), "%s", r.out);
  cr_expect_eq(harness_lines(r.out), 1, "-q: only the scale: %s", r.out);
  cli_result_free(&r);
  bb_image_info info;
  bb_image h = read_image(height, &info);
  cr_expect(info.bits_per_sample == 16, "heights are 16-bit in PNG");
  cr_expect(info.description && strstr(info.description, "\nscale=2.625\n"), "%s",
            info.description ? info.description : "(none)");
  cr_expect_float_eq(bb_image_texel(&h, 0, 0)[0], 0.0f, 1e-9);
  cr_expect_float_eq(bb_image_texel(&h, 7, 7)[0], 1.0f, 1e-9);
  bb_image_info_free(&info);
  bb_image_free(&h);

  run_ok_in(NULL, (const char *[]){"normal", height, "--scale", "2.625", "--filter-radius",
                                   "0", "--clamp", "-o", tmp("n.png"), NULL});
  bb_image from_height = read_image(tmp("n.png"), NULL);
  bb_image rendered = read_image(tmp("slope_local.tga"), NULL);
  const int expect[3] = {97, 112, 250}; /* 0.5 + 0.5 normalize(-0.25, -0.125, 1) */
  for (int c = 0; c < 3; c++) {
    cr_expect(abs(code8(&rendered, 4, 4, c) - expect[c]) <= 1, "rendered channel %d: %d", c,
              code8(&rendered, 4, 4, c));
    cr_expect(abs(code8(&from_height, 4, 4, c) - expect[c]) <= 1, "from height %d: %d", c,
              code8(&from_height, 4, 4, c));
  }
  bb_image_free(&from_height);
  bb_image_free(&rendered);
}

Test(cli, renderbumpflat_bad_models_fail_with_one_line) {
  const char point_text[] = "v 0 0 0\nv 1 0 0\nv 0 0 1\n";
  /* a quad in the XY plane, seen along -y: a rectangle of zero height */
  const char edge_text[] = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";
  const char junk_bytes[] = {'s', 'o', 'l', 'i', 'd', (char)0xff, 0, 1, 2, 3};
  const struct {
    const char *name, *content;
    size_t size;
    const char *reason;
  } cases[] = {
      {"missing.obj", NULL, 0, "no such file"},
      {"empty.obj", "", 0, "empty file"},
      {"points.obj", point_text, sizeof point_text - 1, "no triangles"},
      {"edge_on.obj", edge_text, sizeof edge_text - 1, "degenerate"},
      {"junk.stl", junk_bytes, sizeof junk_bytes, "not a readable model"},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    const char *model = tmp(cases[i].name);
    if (cases[i].content)
      write_bytes(model, cases[i].content, cases[i].size);
    cli_result r = RUN("renderbumpflat", model, "--height", tmp("h.png"));
    cr_expect_eq(r.code, 1, "%s: exit %d, stderr: %s", cases[i].name, r.code, r.err);
    cr_expect_eq(harness_lines(r.err), 1, "%s: %s", cases[i].name, r.err);
    cr_expect(strncmp(r.err, "bumpbake: ", 10) == 0 && strstr(r.err, cases[i].name) &&
                  strstr(r.err, cases[i].reason),
              "%s: '%s' should name the file and say '%s'", cases[i].name, r.err,
              cases[i].reason);
    cli_result_free(&r);
    char *out = malloc(strlen(model) + 16);
    cr_assert_not_null(out);
    strcpy(out, model);
    strcpy(strrchr(out, '.'), "_local.tga");
    cr_expect(!file_exists(out) && !file_exists(tmp("h.png")), "%s: a file was written",
              cases[i].name);
    free(out);
  }
}

Test(cli, renderbumpflat_usage_errors_exit_2) {
  const char *model = tmp("holey.obj");
  write_bytes(model, holey_obj, strlen(holey_obj));
  const usage_case cases[] = {
      {{"renderbumpflat", "-size", "16", model}, "-size"},
      {{"renderbumpflat", model, "-size", "16"}, "-size needs 2 values"},
      {{"renderbumpflat", "-size", "0", "16", model}, "--size must be in 1..65536 (got 0)"},
      {{"renderbumpflat", "-size", "16", "x", model}, "--size needs 2 integers: --size W H"},
      {{"renderbumpflat", "-size", "65536", "65536", model}, "texels"},
      {{"renderbumpflat", model, "--samples", "0"}, "--samples"},
      {{"renderbumpflat", model, "--axis", "w"}, "--axis"},
      {{"renderbumpflat", model, "--tile"}, "--rect"},
      {{"renderbumpflat", model, "--rect", "1", "0", "0", "1"}, "L < R"},
      {{"renderbumpflat", model, "--bogus"}, "--bogus"},
      {{"renderbumpflat", model, "-o", tmp("n.jpg2")}, "n.jpg2"},
      {{"renderbumpflat", model, "--height", tmp("holey_local.tga")}, "both"},
      {{"renderbumpflat"}, "MODEL"},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    cli_result r = harness_run_in(NULL, cases[i].args);
    cr_expect_eq(r.code, 2, "case %zu: exit %d, stderr: %s", i, r.code, r.err);
    cr_expect_eq(harness_lines(r.err), 1, "case %zu: %s", i, r.err);
    cr_expect(strstr(r.err, cases[i].message_part), "case %zu: '%s' lacks '%s'", i, r.err,
              cases[i].message_part);
    cr_expect_str_empty(r.out, "case %zu", i);
    cli_result_free(&r);
    cr_expect(!file_exists(tmp("holey_local.tga")), "case %zu wrote a file", i);
  }
}

/* ----------------------------------------------------------------- hardening */

/* Deterministic noise in [0, 1): a bake of it has no flat, tiny outputs. */
static float noise(int x, int y, int c) {
  uint32_t v = (uint32_t)x * 73856093u ^ (uint32_t)y * 19349663u ^ (uint32_t)c * 83492791u;
  v ^= v >> 13;
  v *= 0x5bd1e995u;
  v ^= v >> 15;
  return (float)(v & 0xffffu) / 65536.0f;
}

/* Entries of dir whose name starts with prefix. */
static int count_entries(const char *dir, const char *prefix) {
  DIR *d = opendir(dir);
  cr_assert_not_null(d, "%s", dir);
  int n = 0;
  for (struct dirent *e; (e = readdir(d)) != NULL;)
    n += strncmp(e->d_name, prefix, strlen(prefix)) == 0;
  closedir(d);
  return n;
}

typedef struct output_format {
  const char *ext;
  const char *depth; /* --depth value */
} output_format;

static const output_format every_output_format[] = {
    {"png", "8"},  {"png", "16"}, {"tga", "8"},    {"tif", "8"},
    {"tif", "16"}, {"tif", "float"}, {"exr", "half"}, {"exr", "float"},
};

/* Item 1: a full disk (RLIMIT_FSIZE of a few bytes, and for PNG and TGA,
 * which once failed silently, one byte short of the largest output) is exit
 * 1, one line, and nothing changes on disk: the previous normal map stays
 * byte for byte, no ao appears, no temporary is left. The CLI ignores
 * SIGXFSZ itself, so the limit is a write error here and not a kill.
 * (test_image_files.c cuts every format and depth at three points.) */
Test(cli, full_disk_changes_nothing_for_every_format, .timeout = 900) {
  const char *in = tmp("noise.png");
  write_image(in, 64, 64, 1, noise);
  for (size_t i = 0; i < sizeof every_output_format / sizeof every_output_format[0]; i++) {
    const output_format *f = &every_output_format[i];
    char name[64], normal[64], ao[64];
    snprintf(name, sizeof name, "d%zu", i);
    cr_assert_eq(mkdir(tmp(name), 0700), 0);
    snprintf(normal, sizeof normal, "d%zu/n.%s", i, f->ext);
    snprintf(ao, sizeof ao, "d%zu/a.%s", i, f->ext);
    const char *args[] = {"bake",   in,   "--scale",    "8",      "--rays", "8",
                          "--depth", f->depth, "--normal", tmp(normal), "--ao", tmp(ao),
                          "-q",     NULL};
    long limits[2] = {100, -1};
    int cuts = 1;
    if (!strcmp(f->depth, "8") && (!strcmp(f->ext, "png") || !strcmp(f->ext, "tga"))) {
      /* The full size of the larger output, from a run with room. */
      cli_result r = harness_run_in(NULL, args);
      cr_assert_eq(r.code, 0, "%s/%s: %s", f->ext, f->depth, r.err);
      cli_result_free(&r);
      struct stat st;
      cr_assert_eq(stat(tmp(normal), &st), 0);
      long biggest = (long)st.st_size;
      cr_assert_eq(stat(tmp(ao), &st), 0);
      biggest = (long)st.st_size > biggest ? (long)st.st_size : biggest;
      cr_assert_eq(unlink(tmp(ao)), 0);
      limits[cuts++] = biggest - 1;
    }
    write_bytes(tmp(normal), "the previous map", 16);

    for (int k = 0; k < cuts; k++) {
      cli_result r;
      run_limits lim = {limits[k], -1};
      r = harness_run_limited(NULL, &lim, args);
      cr_expect_eq(r.code, 1, "%s/%s under %ld bytes: exit %d, %s", f->ext, f->depth,
                   limits[k], r.code, r.err);
      cr_expect_eq(harness_lines(r.err), 1, "%s", r.err);
      cr_expect(strstr(r.err, "cannot write: File too large") &&
                    strstr(r.err, "no output was written"),
                "%s/%s: %s", f->ext, f->depth, r.err);
      cli_result_free(&r);
      size_t size;
      unsigned char *kept = read_bytes(tmp(normal), &size);
      cr_expect(size == 16 && !memcmp(kept, "the previous map", 16),
                "%s/%s under %ld bytes: the previous normal map was replaced", f->ext,
                f->depth, limits[k]);
      free(kept);
      cr_expect_not(file_exists(tmp(ao)), "%s/%s: ao written alone", f->ext, f->depth);
      cr_expect_eq(count_entries(tmp(name), ".bb-tmp-"), 0, "%s/%s: temporary left",
                   f->ext, f->depth);
    }
  }
}

/* Six outputs staged side by side, of which the 3rd (ssbump) and
 * the 5th (bent) are EXR files several times larger than the PNGs around
 * them: under a file-size limit between the two, both fail while the others
 * stage. Whatever the thread count and whichever failure comes first in
 * time, the one reported is the first in output order, alone on one line,
 * and nothing is left: no output, no temporary. */
Test(cli, failed_third_of_six_outputs_leaves_nothing, .timeout = 300) {
  const char *in = tmp("noise6.png");
  write_image(in, 64, 64, 1, noise);
  cr_assert_eq(mkdir(tmp("six"), 0700), 0);
  static const char *const names[6] = {"six/n.png", "six/w.png", "six/s.exr",
                                       "six/a.png", "six/b.exr", "six/f.png"};
  char paths[6][600];
  for (int i = 0; i < 6; i++)
    snprintf(paths[i], sizeof paths[i], "%s", tmp(names[i]));
  for (int threads = 1; threads <= 6; threads += 5) {
    char t[16];
    snprintf(t, sizeof t, "%d", threads);
    const char *args[] = {"bake",      in,       "--scale",  "8",      "--rays",
                          "8",         "--threads", t,        "-q",     "--normal",
                          paths[0],    "--weights", paths[1], "--ssbump", paths[2],
                          "--ao",      paths[3], "--bent",   paths[4], "--filtered",
                          paths[5],    NULL};
    /* Sizes from a run with room: the limit lies between the PNGs and the EXRs. */
    cli_result r = harness_run_in(NULL, args);
    cr_assert_eq(r.code, 0, "%s", r.err);
    cli_result_free(&r);
    long png_max = 0, exr_min = LONG_MAX;
    for (int i = 0; i < 6; i++) {
      struct stat st;
      cr_assert_eq(stat(paths[i], &st), 0, "%s", paths[i]);
      int exr = i == 2 || i == 4;
      if (exr && (long)st.st_size < exr_min)
        exr_min = (long)st.st_size;
      if (!exr && (long)st.st_size > png_max)
        png_max = (long)st.st_size;
      cr_assert_eq(unlink(paths[i]), 0);
    }
    cr_assert_gt(exr_min, 2 * png_max, "EXR %ld bytes, PNG up to %ld", exr_min, png_max);

    run_limits lim = {(png_max + exr_min) / 2, -1};
    r = harness_run_limited(NULL, &lim, args);
    cr_expect_eq(r.code, 1, "threads %d: exit %d, %s", threads, r.code, r.err);
    cr_expect_eq(harness_lines(r.err), 1, "%s", r.err);
    char expected[700];
    snprintf(expected, sizeof expected,
             "bumpbake: %s: cannot write: File too large; no output was written\n", paths[2]);
    cr_expect_str_eq(r.err, expected, "threads %d", threads);
    cli_result_free(&r);
    for (int i = 0; i < 6; i++)
      cr_expect_not(file_exists(paths[i]), "threads %d: %s was written", threads, paths[i]);
    cr_expect_eq(count_entries(tmp("six"), ".bb-tmp-"), 0, "threads %d: temporary left",
                 threads);
  }
}

/* Item 2: the 186-byte TIFFs. In a release build the child's address space
 * is capped at 4 GiB, so a regression fails instead of taking the machine's
 * memory (ASan reserves terabytes of address space: no cap there). */
static const run_limits memory_safety_net = {-1,
#ifdef __SANITIZE_ADDRESS__
                                             -1
#else
                                             4L << 30
#endif
};

/* Peak memory of a run that must not depend on what a header declares: the
 * CLI's own ~130 MiB of libraries plus slack (ASan's runtime adds more). */
#ifdef __SANITIZE_ADDRESS__
enum { BOUNDED_RSS_KIB = 768 * 1024 };
#else
enum { BOUNDED_RSS_KIB = 400 * 1024 };
#endif

static cli_result run_bounded(const char *const *args) {
  cli_result r = harness_run_limited(NULL, &memory_safety_net, args);
  cr_expect_lt(r.max_rss_kib, BOUNDED_RSS_KIB, "%s %s took %ld MiB", args[0], args[1],
               r.max_rss_kib / 1024);
  cr_expect_lt(r.cpu_seconds, 10.0, "%s %s took %.1f s of CPU", args[0], args[1],
               r.cpu_seconds);
  return r;
}

Test(cli, hostile_headers_cost_bounded_time_and_memory) {
  const char *h64 = tmp("h64.tif"), *h4 = tmp("h4.tif");
  cr_assert_eq(write_hostile_tiff(h64, 8192, 8192, 64), 0);
  cr_assert_eq(write_hostile_tiff(h4, 8192, 8192, 4), 0);

  /* info reads the header only: it describes what is declared, at once. */
  cli_result r = run_bounded((const char *[]){"info", h4, NULL});
  cr_expect_eq(r.code, 0, "%s", r.err);
  cr_expect(strstr(r.out, "8192 x 8192, 4 channels, tiff"), "%s", r.out);
  cli_result_free(&r);

  /* 8192 x 8192 x 64 x 1 byte is 4 GiB of samples, 64 bytes a texel (an
   * image of RGBA floats is 16): a bake refuses it from the header; info
   * describes the header. */
  r = run_bounded((const char *[]){"bake", h64, "--scale", "2", "--normal", tmp("n.png"),
                                   NULL});
  cr_expect_eq(r.code, 1, "%s", r.err);
  cr_expect_eq(harness_lines(r.err), 1, "%s", r.err);
  cr_expect(strstr(r.err, "h64.tif") && strstr(r.err, "1024 MiB"), "%s", r.err);
  cli_result_free(&r);
  r = run_bounded((const char *[]){"info", h64, NULL});
  cr_expect_eq(r.code, 0, "%s", r.err);
  cr_expect(strstr(r.out, "8192 x 8192, 64 channels, tiff"), "%s", r.out);
  cli_result_free(&r);

  /* 4 channels fit the limit; the data ends in the first band. */
  r = run_bounded((const char *[]){"bake", h4, "--scale", "2", "--normal", tmp("n.png"),
                                   NULL});
  cr_expect_eq(r.code, 1, "%s", r.err);
  cr_expect_eq(harness_lines(r.err), 1, "%s", r.err);
  cr_expect(strstr(r.err, "truncated"), "%s", r.err);
  cr_expect_lt(strlen(r.err), 400, "one reason, not one per row: %s", r.err);
  cli_result_free(&r);
  cr_expect_not(file_exists(tmp("n.png")));
}

/* Item 3: two names of one output would write one map and lose the other. */
Test(cli, two_names_for_one_output_are_refused) {
  const char *in = tmp("h.png");
  write_image(in, 8, 8, 1, mid_grey);
  cr_assert_eq(mkdir(tmp("D"), 0700), 0);
  cr_assert_eq(symlink(tmp("D"), tmp("L")), 0);
  write_bytes(tmp("D/old.png"), "x", 1);
  cr_assert_eq(link(tmp("D/old.png"), tmp("D/hard.png")), 0);
  char dot[300];
  snprintf(dot, sizeof dot, "%s/D/./a.png", harness_dir);
  const char *pairs[][2] = {
      {tmp("D/a.png"), dot},                   /* "./" */
      {tmp("D/a.png"), tmp("L/a.png")},        /* a symlinked directory */
      {tmp("D/old.png"), tmp("D/hard.png")},   /* hard links of one file */
  };
  for (int i = 0; i < 3; i++) {
    cli_result r = RUN("bake", in, "--scale", "2", "--rays", "4", "--ao", pairs[i][0],
                       "--normal", pairs[i][1]);
    cr_expect_eq(r.code, 2, "case %d: exit %d, %s", i, r.code, r.err);
    cr_expect(strstr(r.err, "would both be written"), "case %d: %s", i, r.err);
    cr_expect_eq(harness_lines(r.err), 1, "%s", r.err);
    cli_result_free(&r);
  }
  cr_expect_not(file_exists(tmp("D/a.png")));
  /* The slope map and its preview are outputs too. */
  cli_result slope = RUN("bake", in, "--scale", "2", "--normal", tmp("D/s.png"), "--slope",
                         tmp("L/s.png"));
  cr_expect_eq(slope.code, 2, "%s", slope.err);
  cr_expect(strstr(slope.err, "would both be written"), "%s", slope.err);
  cli_result_free(&slope);
  slope = RUN("bake", in, "--scale", "2", "--normal", tmp("D/s_lit.png"), "--slope",
              tmp("D/s.png"), "--lit", "45,30");
  cr_expect_eq(slope.code, 2, "%s", slope.err);
  cr_expect(strstr(slope.err, "slope_lit"), "%s", slope.err);
  cli_result_free(&slope);
  cr_expect_not(file_exists(tmp("D/s.png")));
  /* Two different names in the same directory are fine. */
  cli_result r = RUN("bake", in, "--scale", "2", "--rays", "4", "--ao", tmp("D/a.png"),
                     "--normal", tmp("L/b.png"), "-q");
  cr_expect_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  cr_expect(file_exists(tmp("D/a.png")) && file_exists(tmp("D/b.png")));
}

/* Item 4: SIGINT or SIGTERM while outputs are being written. The child is
 * stopped (SIGSTOP) once a temporary exists and no output is in place, so
 * the signal, sent while it is stopped, lands mid-write however fast the
 * machine is; if the write finished between the look and the stop, the
 * attempt is made again. */
static int mid_write(const char *dir, const char *const *finals) {
  if (count_entries(dir, ".bb-tmp-") == 0)
    return 0;
  for (int i = 0; finals[i]; i++)
    if (file_exists(finals[i]))
      return 0;
  return 1;
}

static void interrupt_mid_write(int sig) {
  const char *in = tmp("big.png");
  if (!file_exists(in))
    write_image(in, 2048, 2048, 1, noise);
  const char *finals[] = {tmp("n.exr"), tmp("f.exr"), tmp("w.tif"), NULL};
  const char *args[] = {"bake", in, "--scale", "8", "--filter-radius", "0",
                        "--normal", finals[0], "--filtered", finals[1],
                        "--weights", finals[2], "--depth", "float", "-q", NULL};
  for (int attempt = 0; attempt < 5; attempt++) {
    FILE *out = tmpfile(), *err = tmpfile();
    pid_t pid = harness_spawn(NULL, &harness_no_limits, args, out, err);
    int caught = 0, status = 0;
    double deadline = harness_seconds_now() + 60;
    while (!caught && harness_seconds_now() < deadline && waitpid(pid, &status, WNOHANG) == 0) {
      if (!mid_write(harness_dir, finals)) {
        usleep(500);
        continue;
      }
      kill(pid, SIGSTOP);
      cr_assert_eq(waitpid(pid, &status, WUNTRACED), pid);
      cr_assert(WIFSTOPPED(status));
      caught = mid_write(harness_dir, finals);
      if (caught)
        kill(pid, sig);
      kill(pid, SIGCONT);
    }
    if (caught)
      cr_assert_eq(waitpid(pid, &status, 0), pid);
    fclose(out);
    fclose(err);
    for (int i = 0; finals[i]; i++)
      unlink(finals[i]);
    if (!caught) { /* the write slipped between look and stop: again */
      if (waitpid(pid, &status, 0) != pid)
        cr_assert_fail("lost the child");
      continue;
    }
    cr_expect(WIFSIGNALED(status) && WTERMSIG(status) == sig,
              "the CLI should die of signal %d (status %#x)", sig, status);
    cr_expect_eq(count_entries(harness_dir, ".bb-tmp-"), 0,
                 "signal %d left temporary files behind", sig);
    return;
  }
  cr_assert_fail("could not catch the write in 5 attempts");
}

Test(cli, sigterm_mid_write_leaves_no_temporary) {
  interrupt_mid_write(SIGTERM);
}

Test(cli, sigint_mid_write_leaves_no_temporary) {
  interrupt_mid_write(SIGINT);
}

/* renderbumpflat's two files, interrupted while the new ones are being
 * written over old ones (a temporary exists, both finals are still the
 * old size): both stay the old files, and no temporary is left. */
static int rbf_mid_write(const char *const *finals, const long *old_sizes) {
  if (count_entries(harness_dir, ".bb-tmp-") == 0)
    return 0;
  for (int i = 0; finals[i]; i++) {
    struct stat st;
    if (stat(finals[i], &st) != 0 || (long)st.st_size != old_sizes[i])
      return 0;
  }
  return 1;
}

Test(cli, renderbumpflat_interrupted_mid_write_leaves_the_old_files, .timeout = 300) {
  const char *model = tmp("slope_rbf.obj");
  write_bytes(model, slope_obj, strlen(slope_obj));
  const char *finals[] = {tmp("rbf_n.tga"), tmp("rbf_h.png"), NULL};
  unsigned char *old[2];
  size_t old_size[2];
  long sizes[2];
  const char *args[] = {"renderbumpflat", model, "-size", "2048", "2048", "--samples", "1",
                        "-o", finals[0], "--height", finals[1], "-q", NULL};
  for (int attempt = 0; attempt < 5; attempt++) {
    run_ok_in(NULL, (const char *[]){"renderbumpflat", model, "-size", "8", "8", "-o",
                                     finals[0], "--height", finals[1], "-q", NULL});
    for (int i = 0; i < 2; i++) {
      old[i] = read_bytes(finals[i], &old_size[i]);
      sizes[i] = (long)old_size[i];
    }
    FILE *out = tmpfile(), *err = tmpfile();
    pid_t pid = harness_spawn(NULL, &harness_no_limits, args, out, err);
    int caught = 0, status = 0;
    double deadline = harness_seconds_now() + 120;
    while (!caught && harness_seconds_now() < deadline && waitpid(pid, &status, WNOHANG) == 0) {
      if (!rbf_mid_write(finals, sizes)) {
        usleep(500);
        continue;
      }
      kill(pid, SIGSTOP);
      cr_assert_eq(waitpid(pid, &status, WUNTRACED), pid);
      caught = rbf_mid_write(finals, sizes);
      if (caught)
        kill(pid, SIGTERM);
      kill(pid, SIGCONT);
    }
    if (caught)
      cr_assert_eq(waitpid(pid, &status, 0), pid);
    else if (waitpid(pid, &status, 0) != pid)
      cr_assert_fail("lost the child");
    fclose(out);
    fclose(err);
    int same = caught;
    for (int i = 0; i < 2; i++) {
      size_t n;
      unsigned char *now = read_bytes(finals[i], &n);
      same = same && n == old_size[i] && memcmp(now, old[i], n) == 0;
      free(now);
      free(old[i]);
    }
    if (!caught) /* the write slipped between look and stop: again */
      continue;
    cr_expect(WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM, "status %#x", status);
    cr_expect(same, "an interrupted renderbumpflat replaced an old file");
    cr_expect_eq(count_entries(harness_dir, ".bb-tmp-"), 0, "a temporary was left");
    return;
  }
  cr_assert_fail("could not catch the write in 5 attempts");
}

/* Item 5: finite heights whose product with the scale overflows. */
static float huge_height(int x, int y, int c) {
  (void)c;
  return (x + y) % 2 ? 3.0e38f : 1.0f;
}

Test(cli, overflowing_scale_times_height_is_named) {
  const char *in = tmp("huge.exr");
  write_image(in, 8, 8, 1, huge_height);
  expect_failure((const char *[]){"bake", in, "--scale", "2", "--ao", tmp("ao.exr"), NULL},
                 "huge.exr", tmp("ao.exr"), in);
  cli_result r = RUN("bake", in, "--scale", "2", "--ao", tmp("ao.exr"));
  cr_expect(strstr(r.err, "height scale 2") && strstr(r.err, "3e+38") &&
                strstr(r.err, "texel (1, 0)"),
            "%s", r.err);
  cr_expect_not(strstr(r.err, "non-finite"), "%s", r.err);
  cli_result_free(&r);
}

/* Item 7: a truncated PNG makes OpenImageIO 2.4 leak one string; in the
 * DEBUG build LeakSanitizer would add a report (and exit 23) unless the CLI
 * suppresses exactly that leak. */
Test(cli, truncated_png_is_one_line_also_under_sanitizers) {
  const char *in = tmp("cut.png"), *out = tmp("o.png");
  write_image(in, 64, 64, 1, noise);
  struct stat st;
  cr_assert_eq(stat(in, &st), 0);
  cr_assert_eq(truncate(in, st.st_size / 2), 0);
  expect_failure((const char *[]){"bake", in, "--scale", "2", "--normal", out, NULL},
                 "cut.png", out, in);
  expect_failure((const char *[]){"normal", in, "--scale", "2", "-o", out, NULL}, "cut.png",
                 out, in);
}

/* ------------------------------------------- the CLI called, not executed */

/* The harness runs most CLI tests by calling the CLI's code (linked into
 * this binary) in a forked child instead of executing build/bumpbake
 * (cli_harness.h, harness_start): both must answer alike, byte for byte:
 * stdout, stderr, the exit code and the files written, for --version,
 * --help, usage errors, a bake of four maps and info on one of them. */
Test(cli, the_called_cli_answers_as_the_executed_binary) {
  const char *force = getenv("BB_CLI_EXEC");
  if (force && *force && strcmp(force, "0"))
    cr_skip_test("BB_CLI_EXEC is set: every run executes the binary");
  write_image(tmp("h.png"), 24, 20, 1, ramp_down);
  cr_assert(mkdir(tmp("out"), 0755) == 0);
  const char *const runs[][16] = {
      {"--version", NULL},
      {"--help", NULL},
      {"--frobnicate", NULL},
      {"bake", tmp("h.png"), "--scale", "-1", NULL},
      {"bake", tmp("h.png"), "--scale", "8", "--rays", "16", "--out-dir", tmp("out"), "--maps",
       "normal,ssbump,ao,bent", NULL},
      {"info", tmp("out/h_normal.png"), NULL},
  };
  static const char *const maps[] = {"out/h_normal.png", "out/h_ssbump.png", "out/h_ao.png",
                                     "out/h_bent.png"};
  enum { MAPS = sizeof maps / sizeof maps[0] };
  unsigned char *bytes[MAPS] = {0};
  size_t sizes[MAPS] = {0};
  for (size_t i = 0; i < sizeof runs / sizeof runs[0]; i++) {
    cr_assert(harness_may_call(runs[i]), "run %zu would not be called in a child", i);
    cli_result called = harness_run(runs[i]);
    if (i == 4) /* the bake: keep what the call wrote, for the binary to write again */
      for (size_t m = 0; m < MAPS; m++) {
        bytes[m] = read_bytes(tmp(maps[m]), &sizes[m]);
        cr_assert_eq(remove(tmp(maps[m])), 0);
      }
    cli_result executed = harness_run_exec(runs[i]);
    cr_expect_eq(called.code, executed.code, "run %zu: exit %d called, %d executed", i,
                 called.code, executed.code);
    cr_expect_str_eq(called.out, executed.out, "run %zu: stdout differs", i);
    cr_expect_str_eq(called.err, executed.err, "run %zu: stderr differs", i);
    cli_result_free(&called);
    cli_result_free(&executed);
  }
  for (size_t m = 0; m < MAPS; m++) {
    size_t n = 0;
    unsigned char *again = read_bytes(tmp(maps[m]), &n);
    cr_expect(n == sizes[m] && memcmp(again, bytes[m], n) == 0,
              "%s differs between the call and the binary", maps[m]);
    free(again);
    free(bytes[m]);
  }
}
