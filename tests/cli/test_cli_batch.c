/* test_cli_batch.c: `bumpbake bake INPUTS... --out-dir DIR` run as a
 * program: names, directories, --keep-going, up-to-date skips and what
 * re-bakes, --force, depfiles (read by a real make), clashes refused before
 * any bake, and the single bake unchanged. */
#define _XOPEN_SOURCE 700 /* mkdtemp, nftw, realpath */
#define _DEFAULT_SOURCE    /* wait4 (cli_harness.h) */

#include "bumpbake.h"
#include "cli_harness.h"
#include "files/provenance.h"

#include <fcntl.h>
#include <math.h>
#include <sys/stat.h>
#include <time.h>

TestSuite(cli_batch, .init = harness_setup, .fini = harness_teardown, .timeout = 300);

/* A small height with relief, different for each seed. */
static void height_file(const char *path, int seed) {
  bb_image h;
  cr_assert_eq(bb_image_alloc(&h, 24, 24, 1, NULL), BB_OK);
  for (int y = 0; y < 24; y++)
    for (int x = 0; x < 24; x++)
      h.pixels[y * 24 + x] =
          (float)(0.5 + 0.3 * sin(0.5 * x + seed) * cos(0.4 * y + 0.2 * x * seed));
  harness_write(path, &h, BB_DEPTH_16, BB_RANGE_UNIT);
  bb_image_free(&h);
}

static void write_text(const char *path, const char *text) {
  FILE *f = fopen(path, "w");
  cr_assert_not_null(f);
  cr_assert(fputs(text, f) >= 0);
  cr_assert_eq(fclose(f), 0);
}

static char *read_text(const char *path) {
  FILE *f = fopen(path, "r");
  cr_assert_not_null(f, "%s", path);
  char *text = harness_slurp(f);
  fclose(f);
  return text;
}

static void make_dir(const char *path) { cr_assert_eq(mkdir(path, 0755), 0, "%s", path); }

/* Modification time in nanoseconds. */
static long long mtime_of(const char *path) {
  struct stat st;
  cr_assert_eq(stat(path, &st), 0, "%s", path);
  return (long long)st.st_mtim.tv_sec * 1000000000LL + st.st_mtim.tv_nsec;
}

/* Options that keep a bake of 24 x 24 texels quick. */
#define FAST "--scale", "6", "--slices", "4", "--filter-radius", "2"

static void expect_ok(cli_result *r, const char *what) {
  cr_expect_eq(r->code, 0, "%s: exit %d: %s", what, r->code, r->err);
}

/* Files and a directory in one run; each output has the bits a single bake
 * of its input gives. */
Test(cli_batch, files_and_a_directory_bake_like_single_bakes) {
  make_dir(tmp("tex"));
  make_dir(tmp("out"));
  make_dir(tmp("ref"));
  height_file(tmp("a.png"), 1);
  height_file(tmp("tex/b.png"), 2);
  height_file(tmp("tex/c.tif"), 3);
  write_text(tmp("tex/notes.txt"), "not an image\n");
  write_text(tmp("tex/.hidden.png"), "skipped\n");
  cli_result r = RUN_IN(harness_dir, "bake", "a.png", "tex", FAST, "--out-dir", "out");
  expect_ok(&r, "batch");
  cr_expect(strstr(r.out, "wrote ssbump out/c_ssbump.png\n"), "%s", r.out);
  cr_expect(strstr(r.out, "bake: 3 files: 3 baked, 0 up to date, 0 failed\n"), "%s", r.out);
  cli_result_free(&r);
  static const char *const names[] = {"a", "b", "c"};
  static const char *const inputs[] = {"a.png", "tex/b.png", "tex/c.tif"};
  for (int i = 0; i < 3; i++) {
    char prefix[64], path[64], ref[64];
    snprintf(prefix, sizeof prefix, "ref/%s", names[i]);
    r = RUN_IN(harness_dir, "bake", inputs[i], FAST, "-o", prefix);
    expect_ok(&r, inputs[i]);
    cli_result_free(&r);
    static const char *const kinds[] = {"normal", "ssbump", "ao"};
    for (int k = 0; k < 3; k++) {
      snprintf(path, sizeof path, "out/%s_%s.png", names[i], kinds[k]);
      snprintf(ref, sizeof ref, "ref/%s_%s.png", names[i], kinds[k]);
      bb_image got = harness_read(tmp(path), NULL), want = harness_read(tmp(ref), NULL);
      cr_expect(harness_same_pixels(&got, &want), "%s", path);
      bb_image_free(&got);
      bb_image_free(&want);
    }
  }
  cr_expect(!file_exists(tmp("out/notes_normal.png")));
  cr_expect(!file_exists(tmp("out/.hidden_normal.png")));
}

/* --name and --maps choose the files; {ext} keeps the input's format. */
Test(cli_batch, name_template_and_maps) {
  make_dir(tmp("out"));
  height_file(tmp("a.tif"), 1);
  height_file(tmp("b.png"), 2);
  cli_result r = RUN_IN(harness_dir, "bake", "a.tif", "b.png", FAST, "--out-dir", "out/",
                        "--maps", "ao,bent", "--name", "{kind}-{{{stem}}}.{ext}");
  expect_ok(&r, "template");
  cli_result_free(&r);
  cr_expect(file_exists(tmp("out/ao-{a}.tif")));
  cr_expect(file_exists(tmp("out/bent-{a}.tif")));
  cr_expect(file_exists(tmp("out/ao-{b}.png")));
  cr_expect(file_exists(tmp("out/bent-{b}.png")));
  cr_expect(!file_exists(tmp("out/normal-{a}.tif")), "--maps leaves normal out");
  bb_image_info info;
  cr_assert_eq(bb_image_read_info(tmp("out/ao-{a}.tif"), NULL, NULL, NULL, &info, NULL), BB_OK);
  cr_expect_str_eq(info.format_name, "tiff");
  char value[256];
  cr_expect(bb__provenance_value(info.description, "command", value, sizeof value));
  cr_expect(strncmp(value, "bumpbake bake a.tif ", 20) == 0,
            "each output's command bakes its own input: %s", value);
  bb_image_info_free(&info);

  static const struct {
    const char *tmpl, *maps, *part;
  } bad[] = {
      {"{stem}_{colour}.png", "normal", "unknown field {colour}"},
      {"{stem.png", "normal", "'{' without '}'"},
      {"{stem}}.png", "normal", "'}' without '{'"},
      {"{stem}.png", "normal,glow", "unknown map 'glow'"},
      {"{stem}.jpg", "normal", "unknown output format"},
      {"{stem}.png", "normal,ao", "normal and ao would both be written to out/a.png"},
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++)
    harness_expect_refusal(harness_dir,
                           (const char *const[]){"bake", "a.tif", FAST, "--out-dir", "out",
                                                 "--name", bad[i].tmpl, "--maps", bad[i].maps,
                                                 NULL},
                           2, bad[i].part, i);
}

/* Without --keep-going the batch stops at the first failure; with it, the
 * others are baked. Either way the exit is 1 and the summary counts. */
Test(cli_batch, keep_going_past_a_bad_file) {
  make_dir(tmp("out"));
  height_file(tmp("a.png"), 1);
  write_text(tmp("b.png"), "not a png\n");
  height_file(tmp("c.png"), 3);
  cli_result r =
      RUN_IN(harness_dir, "bake", "a.png", "b.png", "c.png", FAST, "--out-dir", "out");
  cr_expect_eq(r.code, 1);
  cr_expect(strstr(r.err, "bumpbake: b.png: "), "%s", r.err);
  cr_expect(strstr(r.out, "bake: 3 files: 1 baked, 0 up to date, 1 failed, 1 not run"), "%s",
            r.out);
  cr_expect(file_exists(tmp("out/a_ao.png")));
  cr_expect(!file_exists(tmp("out/c_normal.png")), "stopped at b.png");
  cli_result_free(&r);

  r = RUN_IN(harness_dir, "bake", "a.png", "b.png", "c.png", FAST, "--out-dir", "out",
             "--keep-going", "--json");
  cr_expect_eq(r.code, 1);
  cr_expect_eq(harness_lines(r.out), 4, "a line per file and the summary: %s", r.out);
  cr_expect(strstr(r.out, "{\"input\":\"a.png\",\"status\":\"up to date\""), "%s", r.out);
  cr_expect(strstr(r.out, "{\"input\":\"b.png\",\"status\":\"failed\",\"exit_code\":1"), "%s",
            r.out);
  cr_expect(strstr(r.out, "{\"input\":\"c.png\",\"status\":\"baked\",\"width\":24"), "%s",
            r.out);
  cr_expect(strstr(r.out, "{\"summary\":{\"files\":3,\"baked\":1,\"up_to_date\":1,"
                          "\"failed\":1,\"not_run\":0}}\n"),
            "%s", r.out);
  cr_expect(file_exists(tmp("out/c_normal.png")));
  cr_expect(!file_exists(tmp("out/b_normal.png")));
  cli_result_free(&r);
}

/* A directory's dangling link or FIFO under an image's name is reported
 * as a corrupt image is (it was left out without a word); a subdirectory
 * named like an image is not an input (a batch does not go below). */
Test(cli_batch, a_directorys_dangling_link_is_reported_like_a_corrupt_image) {
  make_dir(tmp("in"));
  height_file(tmp("in/a.png"), 1);
  cr_assert_eq(symlink("gone.png", tmp("in/b.png")), 0);
  write_text(tmp("in/c.png"), "not a png\n");
  cr_assert_eq(mkfifo(tmp("in/d.png"), 0644), 0);
  make_dir(tmp("in/e.png"));
  cli_result r = RUN_IN(harness_dir, "bake", "in", FAST, "--out-dir", "out", "--keep-going");
  cr_expect_eq(r.code, 1, "%s", r.err);
  cr_expect(strstr(r.err, "bumpbake: in/b.png: ") &&
                strstr(r.err, "a symbolic link to a missing file"),
            "%s", r.err);
  cr_expect(strstr(r.err, "bumpbake: in/c.png: "), "%s", r.err);
  cr_expect(strstr(r.err, "bumpbake: in/d.png: ") && strstr(r.err, "is a FIFO"), "%s", r.err);
  cr_expect(!strstr(r.err, "e.png"), "%s", r.err);
  cr_expect(strstr(r.out, "bake: 4 files: 1 baked, 0 up to date, 3 failed"), "%s", r.out);
  cr_expect(file_exists(tmp("out/a_ao.png")));
  cli_result_free(&r);
}

static void run_batch(const char *what, const char *extra, const char *expect) {
  cli_result r = extra ? RUN_IN(harness_dir, "bake", "a.png", "b.png", FAST, "--out-dir",
                                "out", extra)
                       : RUN_IN(harness_dir, "bake", "a.png", "b.png", FAST, "--out-dir", "out");
  expect_ok(&r, what);
  cr_expect(strstr(r.out, expect), "%s: %s", what, r.out);
  cli_result_free(&r);
}

/* A second run touches nothing; a changed input re-bakes that input only;
 * --force re-bakes all; --threads does not count (pixels do not depend on
 * it); a pixel-affecting option re-bakes. */
Test(cli_batch, up_to_date_outputs_are_skipped) {
  make_dir(tmp("out"));
  height_file(tmp("a.png"), 1);
  height_file(tmp("b.png"), 2);
  run_batch("first", NULL, "2 files: 2 baked, 0 up to date");
  long long a0 = mtime_of(tmp("out/a_ssbump.png")), b0 = mtime_of(tmp("out/b_ssbump.png"));

  run_batch("again", NULL, "2 files: 0 baked, 2 up to date");
  cr_expect_eq(mtime_of(tmp("out/a_ssbump.png")), a0, "an up-to-date output is not rewritten");
  run_batch("threads", "--threads=1", "0 baked, 2 up to date");

  height_file(tmp("a.png"), 5); /* new bytes */
  run_batch("changed input", NULL, "2 files: 1 baked, 1 up to date");
  cr_expect_neq(mtime_of(tmp("out/a_ssbump.png")), a0);
  cr_expect_eq(mtime_of(tmp("out/b_ssbump.png")), b0);

  run_batch("force", "--force", "2 files: 2 baked, 0 up to date");
  run_batch("bias", "--bias=0.3", "2 baked, 0 up to date");
  run_batch("depth", "--depth=16", "2 baked, 0 up to date");
  run_batch("depth again", "--depth=16", "0 baked, 2 up to date");
  run_batch("back to 8 bits", NULL, "2 baked, 0 up to date");

  /* One output missing is enough to bake the input again. */
  cr_assert_eq(remove(tmp("out/b_ao.png")), 0);
  run_batch("missing output", NULL, "1 baked, 1 up to date");
}

/* A directory can be its own --out-dir: the maps baked into it are not
 * taken for heights on the next run. (The input is 16-bit, so the filtered
 * height is written at 16 bits, as bake keeps the input's depth for it; the
 * up-to-date check must expect that depth, not --depth's default.) */
Test(cli_batch, a_directory_is_its_own_out_dir) {
  make_dir(tmp("tex"));
  height_file(tmp("tex/a.png"), 1);
  cli_result r = RUN_IN(harness_dir, "bake", "tex", FAST, "--out-dir", "tex", "--maps",
                        "normal,filtered");
  expect_ok(&r, "first");
  cli_result_free(&r);
  r = RUN_IN(harness_dir, "bake", "tex", FAST, "--out-dir", "tex", "--maps", "normal,filtered");
  expect_ok(&r, "second");
  cr_expect(strstr(r.out, "bake: 1 file: 0 baked, 1 up to date"), "%s", r.out);
  cli_result_free(&r);
  cr_expect(!file_exists(tmp("tex/a_normal_normal.png")));
  cr_expect(!file_exists(tmp("tex/a_filtered_normal.png")));
}

/* Two inputs on one output name, or an output on another input: refused
 * before anything is baked. */
Test(cli_batch, clashing_names_are_refused_before_any_bake) {
  make_dir(tmp("out"));
  height_file(tmp("a.png"), 1);
  height_file(tmp("a.tif"), 2);
  harness_expect_refusal(
      harness_dir,
      (const char *const[]){"bake", "a.png", "a.tif", FAST, "--out-dir", "out", NULL}, 2,
      "a.png and a.tif would both be written to out/a_ao.png", 0);
  /* b's filtered height would overwrite the input a_filtered.png (exit 1,
   * as any output on an input)... */
  height_file(tmp("a_filtered.png"), 3);
  harness_expect_refusal(harness_dir,
                         (const char *const[]){"bake", "a.png", "a_filtered.png", FAST,
                                               "--out-dir", ".", "--maps", "filtered", NULL},
                         1, "would overwrite the input a_filtered.png", 1);
  /* ...and naming one file twice bakes it once. */
  cli_result r = RUN_IN(harness_dir, "bake", "a.png", "./a.png", FAST, "--out-dir", "out",
                        "--maps", "normal");
  expect_ok(&r, "twice");
  cr_expect(strstr(r.out, "bake: 1 file: 1 baked"), "%s", r.out);
  cli_result_free(&r);
}

/* The single bake is as it was; batch options need --out-dir. */
Test(cli_batch, single_bakes_are_unchanged_and_batch_options_need_out_dir) {
  height_file(tmp("a.png"), 1);
  cli_result r = RUN_IN(harness_dir, "bake", "a.png", FAST, "-o", "p");
  expect_ok(&r, "single");
  cr_expect_str_eq(r.out, "wrote normal p_normal.png\nwrote ssbump p_ssbump.png\n"
                          "wrote ao p_ao.png\n");
  cli_result_free(&r);
  static const char *const batch_only[][2] = {
      {"--name", "{stem}.png"}, {"--maps", "normal"}, {"--keep-going", NULL}};
  for (size_t i = 0; i < 3; i++)
    harness_expect_refusal(
        harness_dir,
        (const char *const[]){"bake", "a.png", FAST, "-o", "q", batch_only[i][0],
                              batch_only[i][1], NULL},
        2, "is for batches: give --out-dir DIR", i);
  /* a single bake always bakes: --force would do nothing */
  harness_expect_refusal(harness_dir,
                         (const char *const[]){"bake", "a.png", FAST, "-o", "q", "--force", NULL},
                         2, "--force does nothing without --out-dir DIR", 3);
  height_file(tmp("b.png"), 2);
  harness_expect_refusal(harness_dir,
                         (const char *const[]){"bake", "a.png", "b.png", FAST, "-o", "q", NULL},
                         2, "several HEIGHT files need --out-dir DIR", 10);
  harness_expect_refusal(harness_dir,
                         (const char *const[]){"bake", "a.png", FAST, "--out-dir", ".",
                                               "--ssbump", "s.png", NULL},
                         2, "choose the maps with --maps", 11);
}

/* The depfile names every output of an input and what the bake read. */
Test(cli_batch, depfiles) {
  make_dir(tmp("out"));
  height_file(tmp("a.png"), 1);
  height_file(tmp("my tex$.png"), 2);
  write_text(tmp("lights.txt"), "1 0 1\n0 1 1\n-1 0 1\n0 -1 1\n");
  cli_result r = RUN_IN(harness_dir, "bake", "a.png", "my tex$.png", FAST, "--out-dir", "out",
                        "--maps", "normal,ao", "--depfile", "out/all.d");
  expect_ok(&r, "batch");
  cli_result_free(&r);
  char *text = read_text(tmp("out/all.d"));
  cr_expect_str_eq(text, "out/a_normal.png out/a_ao.png: a.png\n"
                         "out/my\\ tex$$_normal.png out/my\\ tex$$_ao.png: my\\ tex$$.png\n");
  free(text);

  r = RUN_IN(harness_dir, "bake", "a.png", FAST, "--basis", "lights.txt", "--ssbump",
             "out/s.exr", "-o", "out/p", "--depfile", "out/one.d");
  expect_ok(&r, "single");
  cli_result_free(&r);
  text = read_text(tmp("out/one.d"));
  cr_expect_str_eq(text, "out/p_normal.png out/s.exr out/p_ao.png: a.png lights.txt\n");
  free(text);
}

/* A depfile on a file the bake reads (exit 1, as any output on its input)
 * or writes (exit 2, as two outputs on one name), where it cannot be
 * written, or naming a file it cannot say, is refused before the bake: no file is written or replaced. */
Test(cli_batch, depfile_on_an_input_or_an_output_is_refused) {
  make_dir(tmp("out"));
  height_file(tmp("a.png"), 1);
  write_text(tmp("lights.txt"), "1 0 1\n0 1 1\n-1 0 1\n");
  const long long height_time = mtime_of(tmp("a.png"));
  const long long basis_time = mtime_of(tmp("lights.txt"));
  static const struct {
    const char *args[16];
    int code;
    const char *part;
  } cases[] = {
      {{"bake", "a.png", FAST, "--ao", "ao.png", "--depfile", "a.png"}, 1, "a.png: "},
      {{"bake", "a.png", FAST, "--ao", "ao.png", "--depfile", "./a.png"}, 1, "would overwrite the input"},
      {{"bake", "a.png", FAST, "--basis", "lights.txt", "--ao", "ao.png", "--depfile",
        "lights.txt"},
       1, "lights.txt: "},
      {{"bake", "a.png", FAST, "--ao", "ao.png", "--depfile", "ao.png"}, 2, "ao.png"},
      {{"bake", "a.png", FAST, "-o", "out/p", "--depfile", "out/p_normal.png"}, 2,
       "out/p_normal.png"},
      {{"bake", "a.png", FAST, "--ao", "ao.png", "--depfile", "nodir/a.d"}, 1, "nodir"},
      {{"bake", "a.png", FAST, "--ao", "ao.png", "--depfile", "out"}, 1, "directory"},
      {{"bake", "a.png", FAST, "--out-dir", "out", "--depfile", "a.png"}, 1, "a.png: "},
      {{"bake", "a.png", FAST, "--out-dir", "out", "--depfile", "out/a_ao.png"}, 2,
       "out/a_ao.png"},
      {{"bake", "a.png", FAST, "--out-dir", "out", "--depfile", "nodir/a.d"}, 1, "nodir"},
      /* a name a depfile cannot hold is found before the bake writes it */
      {{"bake", "a.png", FAST, "--ao", "a\no.png", "--depfile", "a.d"}, 1, "newline"},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++)
    harness_expect_refusal(harness_dir, cases[i].args, cases[i].code, cases[i].part, i);
  cr_expect_eq(mtime_of(tmp("a.png")), height_time, "the input was rewritten");
  cr_expect_eq(mtime_of(tmp("lights.txt")), basis_time, "the basis file was rewritten");
}

/* make schedules bakes with the depfile: a changed basis file re-bakes,
 * which the Makefile's own rule does not say. */
Test(cli_batch, make_runs_bakes_from_depfiles) {
  if (system("make --version >/dev/null 2>&1") != 0)
    cr_skip_test("no make");
  height_file(tmp("a.png"), 1);
  height_file(tmp("b.png"), 2);
  write_text(tmp("lights.txt"), "1 0 1\n0 1 1\n-1 0 1\n0 -1 1\n");
  char makefile[8192];
  snprintf(makefile, sizeof makefile,
           "BB := %s\n"
           "all: out/a_ssbump.exr out/b_ssbump.exr\n"
           "out/%%_ssbump.exr: %%.png\n"
           "\t@mkdir -p out\n"
           "\t$(BB) bake $< --scale 6 --slices 4 --filter-radius 2 --basis lights.txt "
           "--out-dir out --maps ssbump --name '{stem}_{kind}.exr' --depfile out/$*.d -q\n"
           "-include out/a.d out/b.d\n",
           harness_binary());
  write_text(tmp("Makefile"), makefile);
  char command[512];
  snprintf(command, sizeof command, "make -s -j2 -C %s >%s 2>&1", harness_dir, tmp("make.log"));
  cr_assert_eq(system(command), 0, "make: %s", read_text(tmp("make.log")));
  cr_expect(file_exists(tmp("out/a_ssbump.exr")));
  cr_expect(file_exists(tmp("out/b_ssbump.exr")));
  char *dep = read_text(tmp("out/a.d"));
  cr_expect_str_eq(dep, "out/a_ssbump.exr: a.png lights.txt\n");
  free(dep);

  snprintf(command, sizeof command, "make -q -C %s >/dev/null 2>&1", harness_dir);
  cr_expect_eq(system(command), 0, "everything is up to date for make");
  /* A newer basis file: make must run the bakes again, and they re-bake. */
  long long before = mtime_of(tmp("out/a_ssbump.exr"));
  struct timespec pause = {0, 20 * 1000 * 1000};
  nanosleep(&pause, NULL);
  write_text(tmp("lights.txt"), "1 0 1\n0 1 1\n-1 0 1\n0 -1 1\n0 0 1\n");
  cr_expect_neq(system(command), 0, "make -q sees lights.txt through the depfile");
  snprintf(command, sizeof command, "make -s -j2 -C %s >%s 2>&1", harness_dir, tmp("make.log"));
  cr_assert_eq(system(command), 0, "make: %s", read_text(tmp("make.log")));
  cr_expect_gt(mtime_of(tmp("out/a_ssbump.exr")), before);
  bb_image s = harness_read(tmp("out/b_ssbump.exr"), NULL);
  cr_expect_eq(s.channels, 5, "baked with the new 5-direction basis");
  bb_image_free(&s);

  /* A touched, unchanged input: make runs the rule, the bake finds its
   * output up to date and bakes nothing, but sets the output's time, so a
   * second make has nothing to do (make compares times: it ran the rule
   * on every make before). */
  snprintf(command, sizeof command, "cp %s %s", tmp("out/a_ssbump.exr"), tmp("baked.exr"));
  cr_assert_eq(system(command), 0);
  nanosleep(&pause, NULL);
  cr_assert_eq(utimensat(AT_FDCWD, tmp("a.png"), NULL, 0), 0);
  cr_assert_gt(mtime_of(tmp("a.png")), mtime_of(tmp("out/a_ssbump.exr")));
  snprintf(command, sizeof command, "make -C %s >%s 2>&1", harness_dir, tmp("make.log"));
  cr_assert_eq(system(command), 0, "make: %s", read_text(tmp("make.log")));
  char same[512];
  snprintf(same, sizeof same, "cmp -s %s %s", tmp("out/a_ssbump.exr"), tmp("baked.exr"));
  cr_expect_eq(system(same), 0, "the touched input was baked again");
  cr_expect_geq(mtime_of(tmp("out/a_ssbump.exr")), mtime_of(tmp("a.png")));
  char *log = read_text(tmp("make.log"));
  cr_expect(strstr(log, "bake a.png"), "make ran the rule: %s", log);
  free(log);
  cr_assert_eq(system(command), 0, "make: %s", read_text(tmp("make.log")));
  log = read_text(tmp("make.log"));
  cr_expect(!strstr(log, "bake "), "the second make ran a bake: %s", log);
  free(log);
  snprintf(command, sizeof command, "make -q -C %s >/dev/null 2>&1", harness_dir);
  cr_expect_eq(system(command), 0, "make -q: everything up to date after the touch");
}

/* ninja reads the depfile too (deps = gcc), with both outputs of a bake
 * as targets; restat sees an up-to-date bake leave its outputs alone. */
Test(cli_batch, ninja_runs_bakes_from_depfiles) {
  if (system("ninja --version >/dev/null 2>&1") != 0)
    cr_skip_test("no ninja");
  height_file(tmp("rock.png"), 1);
  write_text(tmp("lights.txt"), "1 0 1\n0 1 1\n-1 0 1\n0 -1 1\n");
  make_dir(tmp("out"));
  char ninja[8192];
  snprintf(ninja, sizeof ninja,
           "rule bake\n"
           "  command = %s bake $in --scale 6 --slices 4 --filter-radius 2 --basis lights.txt "
           "--out-dir out --maps ssbump,ao --name '{stem}_{kind}.exr' --depfile $depfile -q\n"
           "  depfile = out/$stem.d\n"
           "  deps = gcc\n"
           "  restat = 1\n"
           "build out/rock_ssbump.exr out/rock_ao.exr: bake rock.png\n"
           "  stem = rock\n",
           harness_binary());
  write_text(tmp("build.ninja"), ninja);
  char command[512], deps[512];
  snprintf(command, sizeof command, "ninja -C %s >%s 2>&1", harness_dir, tmp("ninja.log"));
  snprintf(deps, sizeof deps, "ninja -C %s -t deps >%s 2>&1", harness_dir, tmp("deps.log"));
  cr_assert_eq(system(command), 0, "ninja: %s", read_text(tmp("ninja.log")));
  cr_assert_eq(system(deps), 0);
  char *text = read_text(tmp("deps.log"));
  cr_expect(strstr(text, "out/rock_ao.exr: #deps 2"), "%s", text);
  cr_expect(strstr(text, "    lights.txt\n"), "%s", text);
  free(text);
  /* A new basis file re-bakes; a second ninja has nothing to do. */
  long long before = mtime_of(tmp("out/rock_ssbump.exr"));
  struct timespec pause = {0, 20 * 1000 * 1000};
  nanosleep(&pause, NULL);
  write_text(tmp("lights.txt"), "1 0 1\n0 1 1\n-1 0 1\n0 -1 1\n0 0 1\n");
  cr_assert_eq(system(command), 0, "ninja: %s", read_text(tmp("ninja.log")));
  cr_expect_gt(mtime_of(tmp("out/rock_ssbump.exr")), before);
  cr_assert_eq(system(command), 0);
  text = read_text(tmp("ninja.log"));
  cr_expect(strstr(text, "no work to do"), "%s", text);
  free(text);
}
