/* test_cli_messages.c: what a new user reads: mistyped and abbreviated
 * options, a missing argument named as missing, every command saying what
 * it wrote, and the notes about an input (the channel taken, a JPEG, 8-bit
 * heights that terrace). */
#define _XOPEN_SOURCE 700 /* mkdtemp, nftw, realpath */
#define _DEFAULT_SOURCE    /* wait4 (cli_harness.h) */

#include "bumpbake.h"
#include "cli_harness.h"
#include "image/image_write.h"

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
  cr_assert_eq(bb__image_write(tmp("h.tif"), &img, NULL, NULL), BB_OK);
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

/* A directory given without --out-dir is a batch without its folder: a
 * usage error naming --out-dir, with or without -o (it was exit 1, "is a
 * directory", with -o). */
Test(cli_messages, a_directory_without_out_dir_is_a_usage_error) {
  cr_assert_eq(mkdir(tmp("heights"), 0755), 0);
  dome(tmp("heights/h.png"), 1, BB_DEPTH_16);
  const char *plain[] = {"bake", tmp("heights"), "--scale", "4", NULL};
  harness_expect_refusal(NULL, plain, 2,
                         "is a directory: a batch of its heights needs --out-dir DIR", 0);
  const char *prefix[] = {"bake", tmp("heights"), "--scale", "4", "-o", tmp("p"), NULL};
  harness_expect_refusal(NULL, prefix, 2, "needs --out-dir DIR", 1);
  const char *named[] = {"bake",     tmp("heights"), "--scale", "4",
                         "--normal", tmp("n.png"),   NULL};
  harness_expect_refusal(NULL, named, 2, "needs --out-dir DIR", 2);
}

/* A single bake makes the folders its outputs are named in, as a batch
 * makes its --out-dir (mkdir -p): maps, -o's prefix, the slope map and
 * its preview, a material. */
Test(cli_messages, a_single_bake_creates_its_output_folders) {
  dome(tmp("h.png"), 1, BB_DEPTH_16);
  cli_result r = harness_run((const char *[]){
      "bake", tmp("h.png"), "--scale", "4", "--rays", "4", "--normal", tmp("a/b/n.png"),
      "--slope", tmp("s/slope.png"), "--lit", "0,45", "--ssbump",
      tmp("game/materials/x/s.vtf"), "--vmt", tmp("game/materials/y/s.vmt"), NULL});
  cr_expect_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  const char *made[] = {"a/b/n.png", "s/slope.png", "s/slope_lit.png",
                        "game/materials/x/s.vtf", "game/materials/y/s.vmt"};
  for (size_t i = 0; i < sizeof made / sizeof *made; i++)
    cr_expect(file_exists(tmp(made[i])), "%s not written", made[i]);
  r = harness_run((const char *[]){"bake", tmp("h.png"), "--scale", "4", "-o",
                                   tmp("c/d/rock"), NULL});
  cr_expect_eq(r.code, 0, "%s", r.err);
  cr_expect(file_exists(tmp("c/d/rock_normal.png")) &&
            file_exists(tmp("c/d/rock_ao.png")));
  cli_result_free(&r);
  /* A file where a folder should be is still an error, and nothing is made. */
  write_bytes(tmp("file"), "x", 1);
  const char *blocked[] = {"bake",     tmp("h.png"),      "--scale", "4",
                           "--normal", tmp("file/n.png"), NULL};
  harness_expect_refusal(NULL, blocked, 1, "file/n.png: cannot write: ", 3);
  const char *below[] = {"bake", tmp("h.png"), "--scale", "4", "--normal",
                         tmp("file/sub/n.png"), NULL};
  harness_expect_refusal(NULL, below, 1, "file/sub/n.png: cannot write: ", 4);
}

/* A material names its colour map only when told (--basetexture): one
 * without it gets a note, one naming a colour map that is not there
 * another, one naming a file none. */
Test(cli_messages, a_material_without_a_base_texture_gets_a_note) {
  dome(tmp("h.png"), 1, BB_DEPTH_16);
  cr_assert_eq(mkdir(tmp("materials"), 0755), 0);
  cli_result r = harness_run(
      (const char *[]){"bake", tmp("h.png"), "--scale", "4", "--rays", "4", "--ssbump",
                       tmp("materials/s.vtf"), "--vmt", tmp("materials/s.vmt"), NULL});
  cr_expect_eq(r.code, 0, "%s", r.err);
  cr_expect(strstr(r.err, "s.vmt: note: the material has no $basetexture"), "%s", r.err);
  cli_result_free(&r);
  r = harness_run((const char *[]){"bake", tmp("h.png"), "--scale", "4", "--rays", "4",
                                   "--ssbump", tmp("materials/s.vtf"), "--vmt",
                                   tmp("materials/s.vmt"), "--basetexture",
                                   tmp("materials/colour.vtf"), NULL});
  cr_expect_eq(r.code, 0, "%s", r.err);
  cr_expect(!strstr(r.err, "$basetexture"), "%s", r.err);
  cr_expect(strstr(r.err, "s.vmt: note: --basetexture ") &&
                strstr(r.err, "materials/colour.vtf is not a file (yet)"),
            "%s", r.err);
  cr_expect_eq(harness_lines(r.err), 1, "%s", r.err);
  cli_result_free(&r);
  cr_assert_eq(link(tmp("materials/s.vtf"), tmp("materials/colour.vtf")), 0);
  r = harness_run((const char *[]){"bake", tmp("h.png"), "--scale", "4", "--rays", "4",
                                   "--ssbump", tmp("materials/s.vtf"), "--vmt",
                                   tmp("materials/s.vmt"), "--basetexture",
                                   tmp("materials/colour.vtf"), NULL});
  cr_expect_eq(r.code, 0, "%s", r.err);
  cr_expect_str_empty(r.err);
  cli_result_free(&r);
}

/* A material outside any folder named materials names the option that
 * says where the game's materials are. */
Test(cli_messages, a_material_outside_materials_names_the_option) {
  dome(tmp("h.png"), 1, BB_DEPTH_16);
  const char *args[] = {"bake",     tmp("h.png"), "--scale", "4",          "--rays", "4",
                        "--ssbump", tmp("s.vtf"), "--vmt",   tmp("s.vmt"), NULL};
  harness_expect_refusal(NULL, args, 2,
                         "name the game's materials folder with --materials DIR", 0);
}

/* The bytes of path, or NULL (*size then 0). */
static unsigned char *bytes_of(const char *path, size_t *size) {
  *size = 0;
  FILE *f = fopen(path, "rb");
  if (!f)
    return NULL;
  unsigned char *data = malloc(1 << 20);
  cr_assert_not_null(data);
  *size = fread(data, 1, 1 << 20, f);
  fclose(f);
  return data;
}

static void expect_same_bytes(const char *a, const char *b) {
  size_t na, nb;
  unsigned char *da = bytes_of(a, &na), *db = bytes_of(b, &nb);
  cr_expect(da && db && na && na == nb && !memcmp(da, db, na),
            "%s (%zu bytes) != %s (%zu)", a, na, b, nb);
  free(da);
  free(db);
}

/* A map named twice is written to both files from one bake, each in its
 * format and each the bytes a bake of it alone writes (its provenance
 * records the command less the map's other file); the other maps record
 * the command as typed. */
Test(cli_messages, a_map_named_twice_is_written_to_both_from_one_bake) {
  dome(tmp("h.png"), 1, BB_DEPTH_16);
  cr_assert_eq(mkdir(tmp("both"), 0700), 0);
  cr_assert_eq(mkdir(tmp("one"), 0700), 0);
  const char *h = tmp("h.png");
  cli_result r = RUN_IN(tmp("both"), "bake", h, "--scale", "4", "--rays", "4", "--ssbump",
                        "s.png", "--normal", "n.png", "--ssbump=s.vtf", "--json");
  cr_expect_eq(r.code, 0, "%s", r.err);
  cr_expect(strstr(r.out, "\"s.png\"") && strstr(r.out, "\"s.vtf\""), "%s", r.out);
  cli_result_free(&r);
  r = RUN_IN(tmp("one"), "bake", h, "--scale", "4", "--rays", "4", "--ssbump", "s.png",
             "--normal", "n.png", "-q");
  cr_expect_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  r = RUN_IN(tmp("one"), "bake", h, "--scale", "4", "--rays", "4", "--normal", "n.png",
             "--ssbump=s.vtf", "-q");
  cr_expect_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  expect_same_bytes(tmp("both/s.png"), tmp("one/s.png"));
  expect_same_bytes(tmp("both/s.vtf"), tmp("one/s.vtf"));
  bb_image_info info;
  bb_image n = harness_read(tmp("both/n.png"), &info);
  char command[512];
  snprintf(command, sizeof command,
           "\ncommand=bumpbake bake %s --scale 4 --rays 4 --ssbump s.png --normal n.png "
           "--ssbump=s.vtf\n",
           h);
  cr_expect(info.description && strstr(info.description, command), "%s",
            info.description ? info.description : "(none)");
  bb_image_info_free(&info);
  bb_image_free(&n);
  /* the same name twice is one file; a batch names its maps by --maps */
  r = RUN_IN(tmp("both"), "bake", h, "--scale", "4", "--rays", "4", "--ao", "a.png",
             "--ao", "a.png");
  cr_expect_eq(r.code, 0, "%s", r.err);
  cr_expect_eq(harness_lines(r.out), 1, "%s", r.out);
  cli_result_free(&r);
  const char *batch[] = {"bake", h,       "--scale", "4",     "--out-dir", tmp("o"),
                         "--ao", "a.png", "--ao",    "b.png", NULL};
  harness_expect_refusal(NULL, batch, 2, "--out-dir names the outputs", 0);
}

/* Ten files at most, said before any bake. */
Test(cli_messages, a_map_written_to_too_many_files_is_a_usage_error) {
  dome(tmp("h.png"), 1, BB_DEPTH_16);
  const char *args[32] = {"bake", tmp("h.png"), "--scale", "4", "--normal", tmp("n.png")};
  int n = 6;
  char names[10][16];
  for (int i = 0; i < 10; i++) {
    snprintf(names[i], sizeof names[i], "%d.png", i);
    args[n++] = "--ao";
    args[n++] = tmp(names[i]);
  }
  args[n] = NULL;
  harness_expect_refusal(NULL, args, 2, "a bake writes at most 10 files", 0);
  cr_expect_not(file_exists(tmp("n.png")));
}

/* combine takes -q as every command that writes files does: the wrote
 * line without it, nothing with it. */
Test(cli_messages, combine_takes_quiet) {
  dome(tmp("h.png"), 1, BB_DEPTH_16);
  cli_result r = harness_run((const char *[]){"normal", tmp("h.png"), "--scale", "4", "-o",
                                              tmp("n.png"), "-q", NULL});
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  r = harness_run((const char *[]){"combine", tmp("n.png"), tmp("n.png"), "--mix", "0.5", "-o",
                                   tmp("c.png"), NULL});
  cr_expect_eq(r.code, 0, "%s", r.err);
  cr_expect(strstr(r.out, "wrote "), "%s", r.out);
  cli_result_free(&r);
  r = harness_run((const char *[]){"combine", tmp("n.png"), tmp("n.png"), "--mix", "0.5", "-o",
                                   tmp("q.png"), "-q", NULL});
  cr_expect_eq(r.code, 0, "%s", r.err);
  cr_expect_str_empty(r.out, "%s", r.out);
  cr_expect(file_exists(tmp("q.png")));
  cli_result_free(&r);
}

/* A --scheduler address that cannot be one is a usage error of the
 * library's check, exit 2 before any Python or Dask starts (it took Python
 * and Dask 5 to 10 s to say so). BUMPBAKE_PYTHON names a stand-in that
 * leaves a mark when started: a well-formed address does start it. */
Test(cli_messages, a_bad_scheduler_address_is_refused_before_python_starts) {
  dome(tmp("h.png"), 1, BB_DEPTH_16);
  FILE *f = fopen(tmp("python"), "w");
  cr_assert_not_null(f);
  fprintf(f, "#!/bin/sh\ntouch '%s'\nexit 1\n", tmp("started"));
  cr_assert_eq(fclose(f), 0);
  cr_assert_eq(chmod(tmp("python"), 0755), 0);
  cr_assert_eq(setenv("BUMPBAKE_PYTHON", tmp("python"), 1), 0);
  static const char *bad[] = {"garbage",
                              "file:///tmp/x",
                              "tcp://",
                              "tcp://h:0",
                              "tcp://h:port",
                              "tcp://[::1]",
                              "fe80::1:8786",
                              "inproc://x",
                              "tcp://user@h:1",
                              "tcp://a b:1",
                              "",
                              "tcp://h:1\x1b[2J"};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    const char *args[] = {"bake",       tmp("h.png"),  "--scale", "4", "--normal",
                          tmp("n.png"), "--scheduler", bad[i],    NULL};
    cli_result r = harness_run(args);
    harness_expect_error(&r, 2, "bumpbake bake: --scheduler", bad[i]);
    cr_expect(!strchr(r.err, '\x1b'), "%s", r.err);
    cr_expect_lt(r.cpu_seconds, 1.0, "'%s' took %.2f s of CPU", bad[i], r.cpu_seconds);
    cli_result_free(&r);
    cr_expect(!file_exists(tmp("started")), "'%s' started Python", bad[i]);
  }
  const char *good[] = {"bake",       tmp("h.png"),  "--scale",           "4", "--normal",
                        tmp("n.png"), "--scheduler", "tcp://127.0.0.1:1", NULL};
  cli_result r = harness_run(good);
  cr_expect_neq(r.code, 0);
  cli_result_free(&r);
  cr_expect(file_exists(tmp("started")), "a well-formed address did not start Python");
  unsetenv("BUMPBAKE_PYTHON");
}
