/* test_cli_render.c: `bumpbake render` and `bumpbake sheet` run as programs:
 * outputs and their provenance, maps read back, orbits, threads, and bad
 * inputs (one line, no file). */
#define _XOPEN_SOURCE 700 /* mkdtemp, nftw, realpath, setenv */
#define _DEFAULT_SOURCE    /* wait4 (cli_harness.h) */

#include "bumpbake.h"
#include "cli_harness.h"
#include "hostile_headers.h"
#include "core/internal.h"
#include "image/image_write.h"
#include "image/oiio.h"
#include "render/render_internal.h"

#include <math.h>

TestSuite(cli_render, .init = harness_setup, .fini = harness_teardown);

/* A fixture of fixtures/ (BB_FIXTURES), as an absolute path. */
static const char *fixture(const char *name) {
  static char path[8][4096];
  static int next;
  const char *dir = getenv("BB_FIXTURES");
  char rel[4096];
  snprintf(rel, sizeof rel, "%s/%s", dir && *dir ? dir : "fixtures", name);
  char *out = path[next++ % 8];
  cr_assert(realpath(rel, out) != NULL, "fixture %s not found", rel);
  return out;
}

static bb_image read_image(const char *path, bb_image_info *info) {
  bb_image img;
  bb_error err = {{0}};
  cr_assert_eq(bb_image_read(path, &img, info, &err), BB_OK, "%s", err.message);
  return img;
}

/* The command failed with exit code, one line on stderr, nothing on stdout. */
static void expect_one_line_error(cli_result *r, int code, const char *words) {
  cr_assert_eq(r->code, code, "exit %d, expected %d; stderr: %s", r->code, code, r->err);
  cr_assert_eq(harness_lines(r->err), 1, "one line, got: %s", r->err);
  cr_assert(strstr(r->err, words), "'%s' not in: %s", words, r->err);
  cr_assert_str_eq(r->out, "");
}

/* Nothing was written into the test directory except what `keep` files
 * were there before (no output, no temporary file). */
static void expect_no_new_files(int before) {
  cr_assert_eq(files_starting_with(".bb-tmp"), 0, "a temporary file was left");
  cr_assert_eq(files_starting_with("") - 2, before, "a file was written");
}

/* Bakes the pit fixture's maps as EXR into the test directory. */
static void bake_pit_maps(void) {
  cli_result r = RUN("bake", fixture("pit_65x65.png"), "--scale", "8", "--rays", "64",
                     "-q", "--normal", tmp("n.exr"), "--ssbump", tmp("s.exr"), "--ao",
                     tmp("a.exr"), "--bent", tmp("b.exr"));
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
}

Test(cli_render, from_a_height_with_provenance) {
  cli_result r = RUN("render", fixture("pit_65x65.png"), "--scale", "8", "--rays", "64",
                     "-o", tmp("pit.png"), "--light", "0,20");
  cr_assert_eq(r.code, 0, "%s", r.err);
  cr_assert_str_eq(r.err, "");
  cr_assert(strstr(r.out, "wrote render"), "%s", r.out);
  cli_result_free(&r);
  bb_image_info info;
  bb_image img = read_image(tmp("pit.png"), &info);
  cr_assert_eq(img.width, 65);
  cr_assert_eq(img.channels, 3);
  const char *keys[] = {
      "output=render\n",      "input=pit_65x65.png\n", "scale=8\n",    "rayset=",
      "render_from=height\n", "render_mode=ssbump\n",  "light=0,20\n", "specular=0\n"};
  for (size_t i = 0; i < sizeof keys / sizeof keys[0]; i++)
    cr_assert(info.description && strstr(info.description, keys[i]),
              "%s missing from: %s", keys[i], info.description);
  bb_image_info_free(&info);
  bb_image_free(&img);
}

/* Maps baked to files light exactly as the maps of a bake on the fly. */
Test(cli_render, from_baked_maps_as_from_the_height) {
  bake_pit_maps();
  cli_result r = RUN("render", "--normal", tmp("n.exr"), "--ssbump", tmp("s.exr"), "--ao",
                     tmp("a.exr"), "--bent", tmp("b.exr"), "--compare", "--specular",
                     "20", "-o", tmp("maps.exr"), "-q");
  cr_assert_eq(r.code, 0, "%s", r.err);
  cr_assert_str_eq(r.out, "");
  cli_result_free(&r);
  r = RUN("render", fixture("pit_65x65.png"), "--scale", "8", "--rays", "64", "--compare",
          "--specular", "20", "-o", tmp("height.exr"), "-q");
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  bb_image_info info;
  bb_image a = read_image(tmp("maps.exr"), &info),
           b = read_image(tmp("height.exr"), NULL);
  cr_assert_eq(a.width, b.width);
  cr_assert_eq(a.height, b.height);
  size_t n = (size_t)a.width * (size_t)a.height * 3;
  for (size_t i = 0; i < n; i++)
    cr_assert_float_eq(a.pixels[i], b.pixels[i], 1e-5, "texel %zu", i / 3);
  cr_assert(
      strstr(info.description,
             "render_from=maps\nmap_normal_y=down\nmap_normal=n.exr\nmap_ssbump=s.exr\n"),
      "%s", info.description);
  cr_assert(!strstr(info.description, "scale="), "no bake options for baked maps");
  bb_image_info_free(&info);
  bb_image_free(&a);
  bb_image_free(&b);
}

/* --mode slope from a height lights the slope map bake --slope writes of the
 * same height, bit for bit; the sheet refuses the mode in one line. */
Test(cli_render, slope_mode_from_a_height_as_from_bake_slope) {
  cli_result r = RUN("bake", fixture("rock06_128.png"), "--scale", "200", "-q", "--slope",
                     tmp("slope.png"));
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  r = RUN("render", "--slope", tmp("slope.png"), "--mode", "slope", "--light", "30,40",
          "-o", tmp("from_map.exr"), "-q");
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  r = RUN("render", fixture("rock06_128.png"), "--scale", "200", "--mode", "slope",
          "--light", "30,40", "-o", tmp("from_height.exr"), "-q");
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  bb_image a = read_image(tmp("from_map.exr"), NULL),
           b = read_image(tmp("from_height.exr"), NULL);
  size_t n = (size_t)a.width * (size_t)a.height * 3, lit_levels = 0;
  for (size_t i = 0; i < n; i++) {
    cr_assert_eq(a.pixels[i], b.pixels[i], "texel %zu", i / 3);
    lit_levels += a.pixels[i] != a.pixels[0];
  }
  cr_assert_gt(lit_levels, n / 10, "the rock at scale 200 has slopes, not one flat value");
  bb_image_free(&a);
  bb_image_free(&b);
  int before = files_starting_with("") - 2;
  r = RUN("sheet", fixture("rock06_128.png"), "--scale", "8", "--mode", "slope", "-o",
          tmp("sheet.png"));
  expect_one_line_error(&r, 2, "--mode slope");
  cli_result_free(&r);
  expect_no_new_files(before);
}

Test(cli_render, orbit_as_gif_and_as_frames) {
  cli_result r = RUN("render", fixture("pit_65x65.png"), "--scale", "8", "--rays", "16",
                     "--orbit", "5", "--light", "30,25", "-o", tmp("orbit.gif"));
  cr_assert_eq(r.code, 0, "%s", r.err);
  cr_assert(strstr(r.out, "(5 frames)"), "%s", r.out);
  cli_result_free(&r);
  int frames = 0;
  cr_assert_eq(bb__image_frame_count(tmp("orbit.gif"), &frames, NULL), BB_OK);
  cr_assert_eq(frames, 5);

  r = RUN("render", fixture("pit_65x65.png"), "--scale", "8", "--rays", "16", "--orbit",
          "3", "--light", "30,25", "-o", tmp("f.png"), "-q");
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  cr_assert_eq(files_starting_with("f_"), 3);
  cr_assert(!file_exists(tmp("f.png")) && !file_exists(tmp("f_003.png")));
  bb_image_info info;
  bb_image img = read_image(tmp("f_002.png"), &info);
  cr_assert(strstr(info.description, "frame=2/3\n"), "%s", info.description);
  cr_assert(strstr(info.description, "light=270,25\n"), "30 + 2 x 120: %s",
            info.description);
  bb_image_info_free(&info);
  bb_image_free(&img);
}

/* Every frame of an orbit is checked against the inputs before anything is
 * made: a frame named as an input map is refused, and nothing is written. */
Test(cli_render, an_orbit_frame_that_is_an_input_is_refused) {
  cli_result r = RUN("bake", fixture("pit_65x65.png"), "--scale", "8", "--rays", "16",
                     "--ssbump", tmp("o_001.png"), "-q");
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  bb_image before = read_image(tmp("o_001.png"), NULL);
  r = RUN("render", "--ssbump", tmp("o_001.png"), "--orbit", "3", "--light", "30,25", "-o",
          tmp("o.png"));
  expect_one_line_error(&r, 1, "o_001.png: would overwrite the input ");
  cli_result_free(&r);
  cr_assert_eq(files_starting_with("o_"), 1, "no frame was written");
  bb_image after = read_image(tmp("o_001.png"), NULL);
  cr_assert_eq(bb__image_hash(&before), bb__image_hash(&after), "the input is untouched");
  bb_image_free(&before);
  bb_image_free(&after);
}

Test(cli_render, bit_identical_for_any_thread_count) {
  const char *outs[2] = {tmp("t1.png"), tmp("t2.png")};
  for (int i = 0; i < 2; i++) {
    cli_result r =
        RUN("render", fixture("noise_96x80.png"), "--scale", "16", "--rays", "32",
            "--compare", "--tile", "2", "--lightmap", "basis", "--light", "10,30",
            "--threads", i ? "2" : "1", "--depth", "16", "-o", outs[i], "-q");
    cr_assert_eq(r.code, 0, "%s", r.err);
    cli_result_free(&r);
  }
  bb_image a = read_image(outs[0], NULL), b = read_image(outs[1], NULL);
  cr_assert_eq(a.width, b.width);
  cr_assert_eq(
      memcmp(a.pixels, b.pixels, sizeof(float) * 3 * (size_t)a.width * (size_t)a.height),
      0);
  bb_image_free(&a);
  bb_image_free(&b);
}

/* Maps of different sizes, and a 1-channel file as the ssbump: exit 1, one
 * line naming the file, no output and no temporary file. */
Test(cli_render, bad_maps) {
  bake_pit_maps();
  cli_result r = RUN("bake", fixture("noise_96x80.png"), "--scale", "8", "--rays", "16",
                     "-q", "--ao", tmp("ao_noise.png"));
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  int before = files_starting_with("") - 2;
  r = RUN("render", "--normal", tmp("n.exr"), "--ao", tmp("ao_noise.png"), "--mode", "ao",
          "-o", tmp("out.png"));
  expect_one_line_error(&r, 1, "96x80, but the other maps are 65x65");
  cr_assert(strstr(r.err, "ao_noise.png"), "names the file: %s", r.err);
  cli_result_free(&r);
  r = RUN("render", "--ssbump", tmp("a.exr"), "-o", tmp("out.png"));
  expect_one_line_error(&r, 1, "a.exr: 1 channel; an ssbump map needs 3");
  cli_result_free(&r);
  expect_no_new_files(before);
}

/* Usage errors: exit 2, one line, before any work, no file. */
Test(cli_render, usage_errors) {
  const char *pit = fixture("pit_65x65.png");
  struct {
    const char *args[12];
    const char *words;
  } cases[] = {
      {{"render", pit, "--scale", "8", "--light", "0,95", "-o", tmp("o.png")}, "0..90"},
      {{"render", pit, "--scale", "8", "-o", tmp("o.gif")}, "--orbit"},
      {{"render", pit, "--scale", "8", "--ssbump", pit, "-o", tmp("o.png")}, "not both"},
      {{"render", "--normal", pit, "-o", tmp("o.png")}, "needs --ssbump"},
      {{"render", pit, "--scale", "8", "--crop", "60,0,10,10", "-o", tmp("o.png")},
       "not inside the 65x65"},
      {{"sheet", pit, "--scale", "8", "--panel-size", "4", "-o", tmp("s.png")},
       "16..4096"},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    cli_result r = harness_run(cases[i].args);
    expect_one_line_error(&r, 2, cases[i].words);
    cli_result_free(&r);
  }
  expect_no_new_files(0);
}

/* Checked once the size is known, before the bake: 8 x 4097 squared is over
 * the 32768 x 32768 maximum. */
Test(cli_render, tiles_over_the_maximum) {
  bb_image h;
  cr_assert_eq(bb_image_alloc(&h, 4097, 4097, 1, NULL), BB_OK);
  bb_write_options wo = {BB_DEPTH_8, BB_RANGE_UNIT, NULL, NULL};
  cr_assert_eq(bb__image_write(tmp("big.png"), &h, &wo, NULL), BB_OK);
  bb_image_free(&h);
  cli_result r =
      RUN("render", tmp("big.png"), "--scale", "8", "--tile", "8", "-o", tmp("o.png"));
  expect_one_line_error(&r, 2, "32776x32776 picture, over the maximum");
  cli_result_free(&r);
  expect_no_new_files(1);
}

/* render --normal n4096.png --tile 8 ran 62 s at 16 GB peak, and an 8192
 * map tiled 8 times was refused "over the maximum" only after 8 s and 1.7
 * GB: the picture is now worked out from the headers, before any pixel is
 * read (bb__render_files_check), as bakes are. The maps here are headers
 * without pixels (write_png_header): reading them would fail, so only the
 * check before the read can give these answers. */
Test(cli_render, a_picture_too_large_is_refused_before_any_pixel_is_read) {
  cr_assert_eq(write_png_header(tmp("n8192.png"), 8192, 8192), 0);
  cli_result r = RUN("render", "--normal", tmp("n8192.png"), "--mode", "normal", "--tile", "8",
                     "-o", tmp("o.png"));
  expect_one_line_error(&r, 2, "65536x65536 picture, over the maximum");
  cli_result_free(&r);
  /* 2048 x 2048 tiled 8 times fits the limits (16384 x 16384), not the
   * memory left under a 1.2 GB address space: refused with the figures. */
  cr_assert_eq(write_png_header(tmp("n2048.png"), 2048, 2048), 0);
  const run_limits lim = {-1,
#ifdef __SANITIZE_ADDRESS__
                          -1
#else
                          1200L << 20
#endif
  };
#ifdef __SANITIZE_ADDRESS__
  cr_skip_test("ASan reserves terabytes of address space: no RLIMIT_AS here");
#endif
  r = harness_run_limited(NULL, &lim,
                          (const char *[]){"render", "--normal", tmp("n2048.png"), "--mode",
                                           "normal", "--tile", "8", "-o", tmp("o.png"), NULL});
  expect_one_line_error(&r, 1, "a 16384 x 16384 render needs about");
  cr_expect(strstr(r.err, "is available (RLIMIT_AS)"), "%s", r.err);
  cli_result_free(&r);
  expect_no_new_files(2);
}

/* The estimate itself: the picture's size, and its memory from the sizes
 * alone (render, tiles, crop and the encoder's copy). */
Test(cli_render, the_render_estimate) {
  bb_render_options o;
  bb__render_options_init(&o);
  o.tile_x = o.tile_y = 8;
  int w = 0, h = 0;
  double bytes = 0.0;
  bb_error err = {{0}};
  cr_assert_eq(bb__render_estimate(4096, 4096, &o, 0, "r.png", BB_DEPTH_DEFAULT, &w, &h, &bytes,
                                  &err), BB_OK, "%s", err.message);
  cr_expect(w == 32768 && h == 32768);
  /* the tiled picture (12 bytes a texel) and its 8-bit RGB copy */
  cr_expect_float_eq(bytes, 32768.0 * 32768.0 * 15.0, 1.0);
  cr_expect_eq(bb__render_estimate(4096, 4096, &o, 0, "r.exr", BB_DEPTH_DEFAULT, NULL, NULL,
                                  &bytes, &err), BB_OK);
  cr_expect_float_eq(bytes, 32768.0 * 32768.0 * 24.0, 1.0); /* float EXR */
  o.crop_width = o.crop_height = 100;
  cr_expect_eq(bb__render_estimate(4096, 4096, &o, 0, NULL, BB_DEPTH_DEFAULT, &w, &h, &bytes,
                                  &err), BB_OK);
  cr_expect(w == 100 && h == 100);
  cr_expect_float_eq(bytes, (4096.0 * 4096.0 + 32768.0 * 32768.0) * 12.0, 1.0);
  o.crop_x = 32700;
  cr_expect_eq(bb__render_estimate(4096, 4096, &o, 0, NULL, BB_DEPTH_DEFAULT, NULL, NULL, NULL,
                                  &err), BB_ERR_ARGUMENT);
  cr_expect(strstr(err.message, "not inside the 32768x32768 picture"), "%s", err.message);
  o.crop_width = 0;
  cr_expect_eq(bb__render_estimate(4097, 4096, &o, 0, NULL, BB_DEPTH_DEFAULT, NULL, NULL, NULL,
                                  &err), BB_ERR_SIZE);
  /* bb__render itself refuses a picture over what is left, before
   * allocating it (here under no limit at all: more than the limits). */
  bb_image map;
  cr_assert_eq(bb_image_alloc(&map, 8192, 8192, 3, NULL), BB_OK);
  const bb_render_maps maps = {&map, NULL, NULL, NULL, NULL, NULL};
  o.mode = BB_RENDER_NORMAL;
  bb_image out;
  cr_expect_eq(bb__render(&maps, &o, &out, &err), BB_ERR_SIZE);
  cr_expect(strstr(err.message, "over the maximum"), "%s", err.message);
  bb_image_free(&map);
}

Test(cli_render, albedo_of_another_size) {
  int before = files_starting_with("") - 2;
  cli_result r = RUN("render", fixture("pit_65x65.png"), "--scale", "8", "--rays", "16",
                     "--albedo", fixture("noise_96x80.png"), "-o", tmp("o.png"));
  expect_one_line_error(&r, 1, "albedo is 96x80, but the maps are 65x65");
  cli_result_free(&r);
  expect_no_new_files(before);
}

Test(cli_render, sheet_with_and_without_a_font) {
  cli_result r = RUN("sheet", fixture("pit_65x65.png"), "--scale", "8", "--rays", "16",
                     "--panel-size", "64", "-o", tmp("sheet.png"));
  cr_assert_eq(r.code, 0, "%s", r.err);
  cr_assert_str_eq(r.err, "");
  cr_assert(strstr(r.out, "wrote sheet"), "%s", r.out);
  cli_result_free(&r);
  bb_image_info info;
  bb_image with = read_image(tmp("sheet.png"), &info);
  cr_assert_eq(with.width, 8 + 4 * (64 + 8));
  cr_assert(strstr(info.description, "output=sheet\n"), "%s", info.description);
  bb_image_info_free(&info);

  cr_assert_eq(setenv("BUMPBAKE_FONT", "/nonexistent/font.ttf", 1), 0);
  r = RUN("sheet", fixture("pit_65x65.png"), "--scale", "8", "--rays", "16",
          "--panel-size", "64", "-o", tmp("bare.png"), "-q");
  unsetenv("BUMPBAKE_FONT");
  cr_assert_eq(r.code, 0, "%s", r.err);
  cr_assert_eq(harness_lines(r.err), 1, "%s", r.err);
  cr_assert(strstr(r.err, "no font found"), "%s", r.err);
  cli_result_free(&r);
  bb_image bare = read_image(tmp("bare.png"), NULL);
  cr_assert_eq(bare.width, with.width);
  cr_assert_lt(bare.height, with.height, "no label strips");
  bb_image_free(&with);
  bb_image_free(&bare);
}

Test(cli_render, help_lists_the_options) {
  cli_result r = RUN("render", "--help");
  cr_assert_eq(r.code, 0);
  const char *words[] = {"--light AZ,EL", "default 135,45", "--lightmap", "--specular",
                         "--albedo",      "--albedo-mode",  "--compare",  "--tile",
                         "--orbit",       "--crop"};
  for (size_t i = 0; i < sizeof words / sizeof words[0]; i++)
    cr_assert(strstr(r.out, words[i]), "%s missing", words[i]);
  cli_result_free(&r);
  r = RUN("sheet", "--help");
  cr_assert_eq(r.code, 0);
  cr_assert(strstr(r.out, "--panel-size N"));
  cli_result_free(&r);
}
