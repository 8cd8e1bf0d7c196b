/* test_cli_basis.c: `bake --basis` with more directions than Half-Life 2's
 * (dirs:N, basis files) run as a program: the channels written, refusals
 * before the bake for formats that cannot hold them, basis files' errors,
 * provenance, and the readers of Half-Life 2 maps refusing other bases. */
#define _XOPEN_SOURCE 700 /* mkdtemp, nftw, realpath */
#define _DEFAULT_SOURCE    /* wait4 (cli_harness.h) */

#include "bake/bake_internal.h"
#include "bumpbake.h"
#include "cli_harness.h"
#include "files/provenance.h"
#include "trace/basis.h"

#include <math.h>

TestSuite(cli_basis, .init = harness_setup, .fini = harness_teardown, .timeout = 300);

/* A small height field with relief in every direction, as a float TIFF. */
static const char *relief(void) {
  const char *path = tmp("relief.tif");
  bb_image h;
  cr_assert_eq(bb_image_alloc(&h, 24, 20, 1, NULL), BB_OK);
  for (int y = 0; y < 20; y++)
    for (int x = 0; x < 24; x++)
      h.pixels[y * 24 + x] = (float)(0.5 + 0.25 * sin(0.8 * x) * cos(0.6 * y + 0.3 * x));
  harness_write(path, &h, BB_DEPTH_FLOAT, BB_RANGE_UNIT);
  bb_image_free(&h);
  return path;
}

static void write_text(const char *path, const char *text) {
  FILE *f = fopen(path, "w");
  cr_assert_not_null(f);
  cr_assert(fputs(text, f) >= 0);
  cr_assert_eq(fclose(f), 0);
}

static void expect_ok(cli_result *r, const char *what) {
  cr_assert_eq(r->code, 0, "%s: exit %d: %s", what, r->code, r->err);
  cli_result_free(r);
}

static char *description_of(const char *path) {
  bb_image_info info;
  cr_assert_eq(bb_image_read_info(path, NULL, NULL, NULL, &info, NULL), BB_OK);
  return info.description; /* the caller frees it */
}

/* The files hold one channel per direction, the same bits as the library
 * bakes, and the provenance names the basis. */
Test(cli_basis, dirs_writes_a_channel_per_direction_to_exr_and_tiff) {
  const char *in = relief();
  cli_result r = RUN("bake", in, "--scale", "6", "--slices", "8", "--basis", "dirs:6",
                     "--ssbump", tmp("s.exr"), "--weights", tmp("w.tif"), "--bent",
                     tmp("b.png"), "--ao", tmp("a.png"), "--json");
  cr_assert_eq(r.code, 0, "%s", r.err);
  cr_expect(strstr(r.out, "\"basis\":\"dirs:6\""), "%s", r.out);
  cr_expect(strstr(r.out, "\"rayset\":\"bb-horizon-v1:a8:p1:dirs:6\""), "%s", r.out);
  cli_result_free(&r);

  bb_image height = harness_read(in, NULL), s = harness_read(tmp("s.exr"), NULL);
  bb_image w = harness_read(tmp("w.tif"), NULL);
  cr_assert_eq(s.channels, 6);
  cr_assert_eq(w.channels, 6);
  bb_bake_options o;
  bb__bake_options_init(&o);
  o.height_scale = 6.0f;
  o.slices = 8;
  cr_assert_eq(bb__basis_parse("dirs:6", &o.basis, NULL), BB_OK);
  bb_bake_result want;
  cr_assert_eq(bb__bake_checked(&height, &o, &want, NULL), BB_OK);
  cr_assert(harness_same_pixels(&s, &want.ssbump), "ssbump.exr holds the library's bits");
  cr_assert_leq(harness_max_difference(&w, &want.weights), 0.5 / 255 + 1e-6);
  char *text = description_of(tmp("s.exr")), value[64];
  cr_assert(bb__provenance_value(text, "basis", value, sizeof value));
  cr_assert_str_eq(value, "dirs:6");
  cr_assert(!bb__provenance_value(text, "basis_vectors", value, sizeof value),
            "a named basis needs no vectors");
  free(text);
  bb_bake_result_free(&want);
  bb_image_free(&w);
  bb_image_free(&s);
  bb_image_free(&height);
}

/* PNG and TGA hold 4 channels: a basis of more is refused before the bake
 * (exit 2, one line, no file), whichever way the output was named; hl2+z's
 * 4 still fit. */
Test(cli_basis, formats_without_room_are_refused_before_the_bake) {
  const char *in = relief();
  struct {
    const char *args[16];
    const char *part;
  } cases[] = {
      {{"bake", in, "--scale", "4", "--basis", "dirs:6", "--ssbump", tmp("s.png")},
       "s.png: --basis dirs:6 gives ssbump 6 channels and .png files hold at most 4"},
      {{"bake", in, "--scale", "4", "--basis", "dirs:5", "--weights", tmp("w.tga")},
       "w.tga: --basis dirs:5 gives weights 5 channels and .tga files hold at most 4"},
      {{"bake", in, "--scale", "4", "--basis", "dirs:16", "-o", tmp("p")},
       "p_ssbump.png: --basis dirs:16 gives ssbump 16 channels"},
      {{"bake", in, "--scale", "4", "--basis", "dirs:7", "--ao", tmp("a.exr"), "--ssbump",
        tmp("s.exr"), "--weights", tmp("w.png")},
       "(write it as .exr or .tif)"},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++)
    harness_expect_refusal(NULL, cases[i].args, 2, cases[i].part, i);
  /* a basis file is named as the user gave it, not by its hash */
  const char *five = tmp("five.txt");
  write_text(five, "1 0 1\n0 1 1\n-1 0 1\n0 -1 1\n0 0 1\n");
  char want[512];
  snprintf(want, sizeof want, "--basis %s gives ssbump 5 channels", five);
  const char *file_case[] = {"bake", in, "--scale", "4", "--basis", five, "--ssbump", tmp("f.png"),
                             NULL};
  harness_expect_refusal(NULL, file_case, 2, want, 99);
  cli_result r = RUN("bake", in, "--scale", "4", "--basis", "hl2+z", "--ssbump", tmp("z.png"),
                     "--weights", tmp("zw.tga"), "-q");
  expect_ok(&r, "hl2+z in RGBA");
  bb_image z = harness_read(tmp("z.png"), NULL);
  cr_assert_eq(z.channels, 4);
  bb_image_free(&z);
}

/* A word that is no basis is a usage error; a basis file that is there but
 * wrong is that file's error, naming its line. */
Test(cli_basis, bad_bases_and_bad_basis_files) {
  const char *in = relief();
  const char *short_line = tmp("short.txt"), *below = tmp("below.txt"), *dir = tmp("d");
  write_text(short_line, "# a basis\n0 0 1\n1 0 1\n\n0 1\n");
  write_text(below, "1 0 1\n0 1 1\n-1 0 -0.5\n");
  cr_assert_eq(mkdir(dir, 0700), 0);
  struct {
    const char *basis;
    int code;
    const char *part;
  } cases[] = {
      {"hl3", 2, "bumpbake bake: --basis must be hl2, hl2+z, dirs:N (N in 3..16) or a file "
                 "of directions (got 'hl3': No such file or directory)"},
      {"dirs:2", 2, "bumpbake bake: --basis dirs:N needs a whole N in 3..16 (got 'dirs:2')"},
      {"dirs:six", 2, "--basis dirs:N needs a whole N in 3..16"},
      {short_line, 1, "short.txt:5: 2 numbers; a direction is 3 (x y z)"},
      {below, 1, "below.txt:3: points below the surface (z < 0)"},
      {dir, 1, "is a directory"},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    const char *args[] = {"bake", in, "--scale", "4", "--basis", cases[i].basis,
                          "--ssbump", tmp("s.exr"), NULL};
    harness_expect_refusal(NULL, args, cases[i].code, cases[i].part, i);
  }
  cli_result r = RUN("bake", "--help");
  cr_assert_eq(r.code, 0);
  cr_expect(strstr(r.out, "--basis hl2|hl2+z|dirs:N|FILE"), "%s", r.out);
  cr_expect(strstr(r.out, "default hl2; range N 3..16"), "%s", r.out);
  cli_result_free(&r);
}

/* A basis file bakes as its vectors do, and the provenance keeps them. */
Test(cli_basis, a_basis_file_is_recorded_by_its_vectors) {
  const char *in = relief(), *file = tmp("five.txt");
  write_text(file, "# five lights\n1 0 1\n0 1 1 # from the bottom\n-1 0 1\n0 -1 1\n0 0 1\n");
  cli_result r = RUN("bake", in, "--scale", "5", "--slices", "6", "--basis", file, "--ssbump",
                     tmp("s.tif"), "--depth", "float", "-q");
  expect_ok(&r, "a basis file");
  const double v[5][3] = {{1, 0, 1}, {0, 1, 1}, {-1, 0, 1}, {0, -1, 1}, {0, 0, 1}};
  bb_bake_options o;
  bb__bake_options_init(&o);
  o.height_scale = 5.0f;
  o.slices = 6;
  cr_assert_eq(bb_basis_from_vectors(v, 5, &o.basis, NULL), BB_OK);
  bb_image height = harness_read(in, NULL), s = harness_read(tmp("s.tif"), NULL);
  bb_bake_result want;
  cr_assert_eq(bb__bake_checked(&height, &o, &want, NULL), BB_OK);
  cr_assert(harness_same_pixels(&s, &want.ssbump));
  char *text = description_of(tmp("s.tif")), value[1024];
  cr_assert(bb__provenance_value(text, "basis", value, sizeof value));
  cr_assert_str_eq(value, o.basis.name);
  cr_assert(bb__provenance_value(text, "basis_vectors", value, sizeof value));
  /* "x y z; ..." reads back, through a basis file's parser, as the basis. */
  for (char *c = value; *c; c++)
    if (*c == ';') *c = '\n';
  bb_basis again;
  cr_assert_eq(bb__basis_read_text(value, "provenance", &again, NULL), BB_OK, "%s", value);
  cr_assert(memcmp(again.vector, o.basis.vector, sizeof again.vector) == 0);
  free(text);
  bb_bake_result_free(&want);
  bb_image_free(&s);
  bb_image_free(&height);
}

/* render, ssbump2normal and combine --detail read Half-Life 2's three
 * channels: maps of another basis are refused (by channel count, or by the
 * provenance of a 3-direction basis), and dirs:3 (which is hl2) is read. */
Test(cli_basis, hl2_readers_refuse_other_bases) {
  const char *in = relief(), *file = tmp("three.txt");
  write_text(file, "1 0 1\n0 1 1\n-1 -1 1\n");
  cli_result r = RUN("bake", in, "--scale", "4", "--slices", "4", "--basis", "dirs:6",
                     "--ssbump", tmp("s6.exr"), "-q");
  expect_ok(&r, "dirs:6");
  r = RUN("bake", in, "--scale", "4", "--slices", "4", "--basis", file, "--ssbump",
          tmp("s3.png"), "-q");
  expect_ok(&r, "a 3-direction file");
  r = RUN("bake", in, "--scale", "4", "--slices", "4", "--basis", "dirs:3", "--ssbump",
          tmp("d3.png"), "-q");
  expect_ok(&r, "dirs:3");
  const char *s6 = tmp("s6.exr"), *s3 = tmp("s3.png"), *out = tmp("out.png");
  struct {
    const char *args[10];
    const char *part;
  } cases[] = {
      {{"render", "--ssbump", s6, "-o", out}, "s6.exr: baked with --basis dirs:6"},
      {{"render", "--ssbump", s3, "-o", out}, "s3.png: baked with --basis vectors:"},
      {{"ssbump2normal", s6, "-o", out}, "this reads Half-Life 2's basis"},
      {{"combine", s3, s3, "--detail", "-o", out}, "(bake with --basis hl2)"},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++)
    harness_expect_refusal(NULL, cases[i].args, 1, cases[i].part, i);
  r = RUN("render", "--ssbump", tmp("d3.png"), "-o", out);
  expect_ok(&r, "render of a dirs:3 ssbump");
  r = RUN("combine", s6, s6, "--mix", "0.5", "-o", tmp("mix.exr"));
  expect_ok(&r, "a blend of two dirs:6 maps");
  bb_image mix = harness_read(tmp("mix.exr"), NULL);
  cr_assert_eq(mix.channels, 6);
  bb_image_free(&mix);
}
