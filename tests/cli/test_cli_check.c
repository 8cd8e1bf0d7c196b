/* test_cli_check.c: `bumpbake check` run as a program: two trees paired by
 * name (missing, extra, different size, NaN, links out of the tree,
 * unreadable files), a batch baked in memory against its goldens (which it
 * leaves alone), limits by kind and name, the update that writes only what
 * failed, the reports, usage errors, and a tree of 10,000 files in bounded
 * time and memory. */
#define _XOPEN_SOURCE 700 /* mkdtemp, nftw, symlink */
#define _DEFAULT_SOURCE   /* wait4 (cli_harness.h) */

#include "bumpbake.h"
#include "cli_harness.h"
#include "files/provenance.h"

#include <fcntl.h>
#include <math.h>
#include <sys/stat.h>

TestSuite(cli_check, .init = harness_setup, .fini = harness_teardown, .timeout = 600);

static void make_dir(const char *path) {
  cr_assert_eq(mkdir(path, 0755), 0, "%s", path);
}

/* A small height with relief, different for each seed. */
static void height_file(const char *path, int seed) {
  bb_image h;
  cr_assert_eq(bb_image_alloc(&h, 24, 20, 1, NULL), BB_OK);
  for (int y = 0; y < 20; y++)
    for (int x = 0; x < 24; x++)
      h.pixels[y * 24 + x] =
          (float)(0.5 + 0.3 * sin(0.5 * x + seed) * cos(0.4 * y + 0.2 * x * seed));
  harness_write(path, &h, BB_DEPTH_16, BB_RANGE_UNIT);
  bb_image_free(&h);
}

/* A map of w x h x c with values from seed, as a file. */
static void map_file(const char *path, int w, int h, int c, int seed, bb_depth depth) {
  bb_image m;
  cr_assert_eq(bb_image_alloc(&m, w, h, c, NULL), BB_OK);
  for (int i = 0; i < w * h * c; i++)
    m.pixels[i] = (float)(0.5 + 0.4 * sin(0.3 * i + seed));
  harness_write(path, &m, depth, BB_RANGE_UNIT);
  bb_image_free(&m);
}

static char *read_text(const char *path) {
  FILE *f = fopen(path, "rb");
  cr_assert_not_null(f, "%s", path);
  char *text = harness_slurp(f);
  fclose(f);
  return text;
}

static int same_bytes(const char *a, const char *b) {
  char *x = read_text(a), *y = read_text(b);
  struct stat sa, sb;
  cr_assert_eq(stat(a, &sa), 0);
  cr_assert_eq(stat(b, &sb), 0);
  const int same = sa.st_size == sb.st_size && memcmp(x, y, (size_t)sa.st_size) == 0;
  free(x);
  free(y);
  return same;
}

/* Options that keep a bake of 24 x 20 texels quick. */
#define FAST "--scale", "6", "--slices", "4", "--filter-radius", "2"

/* Heights h/a.png and h/b.png, their goldens baked into g/ (normal, ssbump, ao). */
static void suite(void) {
  make_dir(tmp("h"));
  height_file(tmp("h/a.png"), 1);
  height_file(tmp("h/b.png"), 2);
  cli_result r = RUN("bake", tmp("h"), "--out-dir", tmp("g"), FAST, "-q");
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
}

/* ------------------------------------------------------------ the bake */

Test(cli_check, a_bake_matching_its_goldens_passes_and_writes_nothing) {
  suite();
  struct stat before;
  cr_assert_eq(stat(tmp("g/a_normal.png"), &before), 0);
  cli_result r = RUN("check", tmp("g"), tmp("h"), "--bake", FAST);
  cr_expect_eq(r.code, 0, "%s%s", r.out, r.err);
  cr_expect(strstr(r.out, "check: 6 maps: 6 passed"), "%s", r.out);
  cr_expect_eq(harness_lines(r.out), 1, "only the summary: %s", r.out);
  cli_result_free(&r);
  /* nothing written: the goldens' times, no temporary, no other file */
  struct stat after;
  cr_assert_eq(stat(tmp("g/a_normal.png"), &after), 0);
  cr_expect(after.st_mtim.tv_sec == before.st_mtim.tv_sec &&
                after.st_mtim.tv_nsec == before.st_mtim.tv_nsec,
            "a golden was touched");
  DIR *d = opendir(tmp("g"));
  int files = 0;
  for (struct dirent *e; (e = readdir(d));)
    files += e->d_name[0] != '.' || strncmp(e->d_name, ".bb-tmp", 7) == 0;
  closedir(d);
  cr_expect_eq(files, 6);
}

Test(cli_check, a_changed_parameter_fails_the_maps_it_changes_naming_it) {
  suite();
  cli_result r = RUN("check", tmp("g"), tmp("h"), "--bake", "--scale", "6", "--slices",
                     "5", "--filter-radius", "2");
  cr_expect_eq(r.code, 2, "%s%s", r.out, r.err);
  /* the normal maps do not depend on the slices: they pass */
  cr_expect_null(strstr(r.out, "_normal.png"), "%s", r.out);
  cr_expect(strstr(r.out, "FAILURE a_ssbump.png (ssbump): max abs error"), "%s", r.out);
  cr_expect(strstr(r.out, "  slices") == NULL &&
                strstr(r.out, "  rayset: bb-horizon-v1:a4:p1:hl2 "
                              "-> bb-horizon-v1:a5:p1:hl2"),
            "%s", r.out);
  cr_expect(strstr(r.out, "  rayset: bb-horizon-v1:a4 -> bb-horizon-v1:a5"), "ao's: %s",
            r.out);
  cr_expect(strstr(r.out, "check: 6 maps: 2 passed, 0 warnings, 4 failed"), "%s", r.out);
  cli_result_free(&r);
}

Test(cli_check, limits_by_kind_and_by_name_the_last_winning) {
  suite();
  /* scale 6.1: small differences everywhere */
  cli_result r =
      RUN("check", tmp("g"), tmp("h"), "--bake", "--scale", "6.1", "--slices", "4",
          "--filter-radius", "2", "--limits", "ao: -fail 1; *_normal.png: -fail 1",
          "--limits", "ssbump: -fail 1; b_*: -fail 0");
  cr_expect_eq(r.code, 2, "%s%s", r.out, r.err);
  /* --limits given twice: the second text; ssbump within 1, b_* exact */
  cr_expect(strstr(r.out, "FAILURE b_ssbump.png") && strstr(r.out, "FAILURE b_ao.png") &&
                strstr(r.out, "FAILURE b_normal.png") && !strstr(r.out, "a_ssbump.png") &&
                strstr(r.out, "FAILURE a_ao.png"),
            "%s", r.out);
  cli_result_free(&r);
  r = RUN("check", tmp("g"), tmp("h"), "--bake", "--scale", "6.1", "--slices", "4",
          "--filter-radius", "2", "-fail", "1", "--limits",
          "normal: -fail 0\n*a_normal*: -warn 0");
  /* a rule sets only what it names: a_normal fails by kind, warn 0 kept */
  cr_expect_eq(r.code, 2, "%s%s", r.out, r.err);
  cr_expect(strstr(r.out, "FAILURE a_normal.png") &&
                strstr(r.out, "FAILURE b_normal.png") && !strstr(r.out, "ssbump") &&
                !strstr(r.out, "_ao"),
            "%s", r.out);
  cli_result_free(&r);
}

Test(cli_check, update_writes_only_what_did_not_pass_then_passes) {
  suite();
  char *normal = read_text(tmp("g/a_normal.png"));
  struct stat normal_before;
  cr_assert_eq(stat(tmp("g/a_normal.png"), &normal_before), 0);
  cli_result r = RUN("check", tmp("g"), tmp("h"), "--bake", "--scale", "6", "--slices",
                     "5", "--filter-radius", "2", "--update");
  cr_expect_eq(r.code, 0, "every failure was updated: %s%s", r.out, r.err);
  cr_expect(strstr(r.out, "updated ") && strstr(r.out, "g/a_ssbump.png\n"), "%s", r.out);
  cr_expect(strstr(r.out, "4 goldens updated"), "%s", r.out);
  cli_result_free(&r);
  /* the passing goldens' bytes and times are as they were */
  struct stat normal_after;
  cr_assert_eq(stat(tmp("g/a_normal.png"), &normal_after), 0);
  cr_expect_eq(normal_after.st_mtim.tv_nsec, normal_before.st_mtim.tv_nsec);
  char *after = read_text(tmp("g/a_normal.png"));
  cr_expect_eq(memcmp(normal, after, (size_t)normal_after.st_size), 0);
  free(normal);
  free(after);
  /* the updated ones are what bake writes, byte for byte */
  cli_result b = RUN("bake", tmp("h/a.png"), "--scale", "6", "--slices", "5",
                     "--filter-radius", "2", "--ssbump", tmp("a_ssbump.png"), "-q");
  cr_assert_eq(b.code, 0, "%s", b.err);
  cli_result_free(&b);
  bb_image_info gi, ni;
  bb_image g = harness_read(tmp("g/a_ssbump.png"), &gi),
           n = harness_read(tmp("a_ssbump.png"), &ni);
  cr_expect(harness_same_pixels(&g, &n));
  char out_dir[64];
  cr_expect(bb__provenance_value(gi.description, "command", out_dir, sizeof out_dir));
  cr_expect(strstr(gi.description, "--out-dir "), "the golden records its batch: %s",
            gi.description);
  bb_image_free(&g);
  bb_image_free(&n);
  bb_image_info_free(&gi);
  bb_image_info_free(&ni);
  r = RUN("check", tmp("g"), tmp("h"), "--bake", "--scale", "6", "--slices", "5",
          "--filter-radius", "2");
  cr_expect_eq(r.code, 0, "%s%s", r.out, r.err);
  cli_result_free(&r);
}

Test(cli_check, goldens_no_input_makes_are_missing_and_maps_without_golden_extra) {
  suite();
  cr_assert_eq(rename(tmp("h/b.png"), tmp("b.png")), 0); /* b's goldens: no input */
  height_file(tmp("h/c.png"), 3);                        /* c: no goldens */
  make_dir(tmp("g/notes"));
  map_file(tmp("g/notes/plain.png"), 4, 4, 3, 0, BB_DEPTH_8); /* not a baked map */
  cli_result r = RUN("check", tmp("g"), tmp("h"), "--bake", FAST, "--maps", "normal,ao");
  cr_expect_eq(r.code, 2, "%s%s", r.out, r.err);
  cr_expect(strstr(r.out, "EXTRA c_normal.png") && strstr(r.out, "EXTRA c_ao.png"), "%s",
            r.out);
  cr_expect(strstr(r.out, "MISSING b_normal.png") && strstr(r.out, "MISSING b_ao.png"),
            "%s", r.out);
  /* the ssbump goldens are not this check's: it bakes no ssbump */
  cr_expect_null(strstr(r.out, "ssbump"), "%s", r.out);
  cr_expect_null(strstr(r.out, "plain.png"), "%s", r.out);
  cr_expect(strstr(r.out,
                   "check: 6 maps: 2 passed, 0 warnings, 0 failed, 0 of another size, "
                   "0 unreadable, 2 missing, 2 extra"),
            "%s", r.out);
  cli_result_free(&r);
  /* goldens of another template beside these are another suite's too */
  cr_assert_eq(rename(tmp("b.png"), tmp("h/b.png")), 0);
  cr_assert_eq(unlink(tmp("h/c.png")), 0);
  r = RUN("bake", tmp("h"), "--out-dir", tmp("g"), FAST, "--maps", "ao", "--name",
          "{stem}-{kind}.exr", "-q");
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  r = RUN("check", tmp("g"), tmp("h"), "--bake", FAST);
  cr_expect_eq(r.code, 0, "%s%s", r.out, r.err);
  cr_expect(strstr(r.out, "check: 6 maps: 6 passed"), "%s", r.out);
  cli_result_free(&r);
}

/* ------------------------------------------------------------ two trees */

/* g/ and n/ with one case of each kind. */
static void trees(void) {
  make_dir(tmp("g"));
  make_dir(tmp("n"));
  make_dir(tmp("g/sub"));
  make_dir(tmp("n/sub"));
  map_file(tmp("g/same.png"), 8, 8, 3, 1, BB_DEPTH_8);
  map_file(tmp("n/same.png"), 8, 8, 3, 1, BB_DEPTH_8);
  map_file(tmp("g/sub/changed.exr"), 8, 8, 3, 1, BB_DEPTH_FLOAT);
  map_file(tmp("n/sub/changed.exr"), 8, 8, 3, 2, BB_DEPTH_FLOAT);
  map_file(tmp("g/sized.png"), 8, 8, 3, 1, BB_DEPTH_8);
  map_file(tmp("n/sized.png"), 8, 6, 3, 1, BB_DEPTH_8);
  map_file(tmp("g/gone.png"), 4, 4, 1, 1, BB_DEPTH_8);
  map_file(tmp("n/new.png"), 4, 4, 1, 1, BB_DEPTH_8);
  write_bytes(tmp("g/notes.txt"), "not an image", 12);
}

Test(cli_check, two_trees_by_relative_name) {
  trees();
  cli_result r = RUN("check", tmp("g"), tmp("n"), "--junit", tmp("r.xml"));
  cr_expect_eq(r.code, 3, "different size is the worst: %s%s", r.out, r.err);
  cr_expect(strstr(r.out, "FAILURE sub/changed.exr: max abs error"), "%s", r.out);
  cr_expect(strstr(r.out,
                   "DIFFERENT SIZE sized.png: golden 8 x 8, 3 channels; new 8 x 6, 3 "
                   "channels"),
            "%s", r.out);
  cr_expect(strstr(r.out, "MISSING gone.png") && strstr(r.out, "EXTRA new.png"), "%s",
            r.out);
  cr_expect(strstr(r.out, "check: 5 maps: 1 passed"), "%s", r.out);
  cr_expect(strstr(r.out, "wrote junit "), "%s", r.out);
  cli_result_free(&r);
  char *xml = read_text(tmp("r.xml"));
  cr_expect(strstr(xml, "tests=\"5\" failures=\"4\" errors=\"0\""), "%s", xml);
  cr_expect(strstr(xml, "name=\"sub/changed.exr\""), "%s", xml);
  free(xml);
}

Test(cli_check, update_of_a_tree_copies_the_new_files_that_did_not_pass) {
  trees();
  char *same = read_text(tmp("g/same.png"));
  cli_result r = RUN("check", tmp("g"), tmp("n"), "--update", "-q");
  /* the missing golden stays (nothing new to take), so the check still fails */
  cr_expect_eq(r.code, 2, "%s%s", r.out, r.err);
  cr_expect_str_empty(r.out);
  cli_result_free(&r);
  cr_expect(same_bytes(tmp("g/sub/changed.exr"), tmp("n/sub/changed.exr")));
  cr_expect(same_bytes(tmp("g/sized.png"), tmp("n/sized.png")));
  cr_expect(same_bytes(tmp("g/new.png"), tmp("n/new.png")));
  cr_expect(file_exists(tmp("g/gone.png")));
  char *after = read_text(tmp("g/same.png"));
  cr_expect_str_eq(after, same);
  free(same);
  free(after);
}

Test(cli_check, a_nan_in_a_float_golden_fails_and_is_drawn) {
  make_dir(tmp("g"));
  make_dir(tmp("n"));
  bb_image m;
  cr_assert_eq(bb_image_alloc(&m, 6, 6, 1, NULL), BB_OK);
  for (int i = 0; i < 36; i++)
    m.pixels[i] = 0.5f;
  harness_write(tmp("n/ao.exr"), &m, BB_DEPTH_FLOAT, BB_RANGE_UNIT);
  m.pixels[7] = NAN;
  harness_write(tmp("g/ao.exr"), &m, BB_DEPTH_FLOAT, BB_RANGE_UNIT);
  bb_image_free(&m);
  cli_result r =
      RUN("check", tmp("g"), tmp("n"), "--html", tmp("rep"), "-hardfail", "1e30");
  cr_expect_eq(r.code, 2, "%s%s", r.out, r.err);
  cr_expect(strstr(r.out, "FAILURE ao.exr: max abs error inf at (1, 1) channel 0"), "%s",
            r.out);
  cli_result_free(&r);
  cr_expect(file_exists(tmp("rep/index.html")));
  /* the same NaN on both sides passes, as idiff's */
  cr_assert_eq(unlink(tmp("n/ao.exr")), 0);
  cr_assert_eq(link(tmp("g/ao.exr"), tmp("n/ao.exr")), 0);
  r = RUN("check", tmp("g"), tmp("n"));
  cr_expect_eq(r.code, 0, "%s%s", r.out, r.err);
  cli_result_free(&r);
}

Test(cli_check, links_out_of_a_tree_and_unreadable_files_are_not_read) {
  make_dir(tmp("g"));
  make_dir(tmp("n"));
  make_dir(tmp("outside"));
  /* a FIFO outside the tree: reading it would block the check */
  cr_assert_eq(mkfifo(tmp("outside/fifo.png"), 0644), 0);
  cr_assert_eq(symlink(tmp("outside/fifo.png"), tmp("g/link.png")), 0);
  map_file(tmp("n/link.png"), 4, 4, 3, 1, BB_DEPTH_8);
  cr_assert_eq(symlink("../../etc/passwd.png", tmp("g/up.png")), 0);
  map_file(tmp("n/up.png"), 4, 4, 3, 1, BB_DEPTH_8);
  /* a link inside the tree is followed */
  map_file(tmp("g/real.png"), 4, 4, 3, 1, BB_DEPTH_8);
  cr_assert_eq(symlink("real.png", tmp("g/inside.png")), 0);
  map_file(tmp("n/inside.png"), 4, 4, 3, 1, BB_DEPTH_8);
  map_file(tmp("n/real.png"), 4, 4, 3, 1, BB_DEPTH_8);
  /* a FIFO in the tree, and a corrupt file */
  cr_assert_eq(mkfifo(tmp("g/fifo.png"), 0644), 0);
  map_file(tmp("n/fifo.png"), 4, 4, 3, 1, BB_DEPTH_8);
  write_bytes(tmp("g/corrupt.png"), "\x89PNG\r\n\x1a\nnot really", 18);
  map_file(tmp("n/corrupt.png"), 4, 4, 3, 1, BB_DEPTH_8);
  cli_result r = RUN("check", tmp("g"), tmp("n"), "--update");
  cr_expect_eq(r.code, 4, "%s%s", r.out, r.err);
  cr_expect(strstr(r.out, "UNREADABLE link.png") &&
                strstr(r.out, "leading out of its tree"),
            "%s", r.out);
  cr_expect(strstr(r.out, "UNREADABLE up.png"), "%s", r.out);
  cr_expect(strstr(r.out, "UNREADABLE fifo.png") && strstr(r.out, "not a regular file"),
            "%s", r.out);
  cr_expect(strstr(r.out, "UNREADABLE corrupt.png"), "%s", r.out);
  cr_expect_null(strstr(r.out, "inside.png"), "%s", r.out);
  cli_result_free(&r);
  /* the update wrote through no link: the link is still a link to the FIFO */
  struct stat s;
  cr_assert_eq(lstat(tmp("g/link.png"), &s), 0);
  cr_expect(S_ISLNK(s.st_mode));
  cr_assert_eq(lstat(tmp("outside/fifo.png"), &s), 0);
  cr_expect(S_ISFIFO(s.st_mode));
}

/* A tree of 10,000 files: the walk and the pairing are sorted merges, the
 * cases a few hundred bytes each. */
Test(cli_check, ten_thousand_files_in_bounded_time_and_memory) {
  make_dir(tmp("g"));
  make_dir(tmp("n"));
  map_file(tmp("one.png"), 4, 4, 1, 1, BB_DEPTH_8);
  char *bytes = read_text(tmp("one.png"));
  struct stat s;
  cr_assert_eq(stat(tmp("one.png"), &s), 0);
  char name[64];
  for (int i = 0; i < 10000; i++) {
    snprintf(name, sizeof name, "g/%03d", i / 100);
    if (i % 100 == 0) {
      make_dir(tmp(name));
      snprintf(name, sizeof name, "n/%03d", i / 100);
      make_dir(tmp(name));
    }
    /* tmp() keeps 256 paths: build these by hand */
    char path[256];
    snprintf(path, sizeof path, "%s/g/%03d/m%05d.png", harness_dir, i / 100, i);
    write_bytes(path, bytes, (size_t)s.st_size);
    snprintf(path, sizeof path, "%s/n/%03d/m%05d.png", harness_dir, i / 100, i);
    write_bytes(path, bytes, (size_t)s.st_size);
  }
  free(bytes);
  const run_limits lim = {-1, 2L << 30};
  cli_result r = harness_run_limited(
      NULL, &lim,
      (const char *const[]){"check", tmp("g"), tmp("n"), "--junit", tmp("r.xml"), NULL});
  cr_expect_eq(r.code, 0, "%s%s", r.out, r.err);
  cr_expect(strstr(r.out, "check: 10000 maps: 10000 passed"), "%s", r.out);
  cr_expect_lt(r.cpu_seconds, 120.0, "%.1f s of CPU", r.cpu_seconds);
  cr_expect_lt(r.max_rss_kib, 400 * 1024, "%ld KiB", r.max_rss_kib);
  cr_log_info("10,000 files: %.2f s CPU, %.2f s wall, %ld KiB peak", r.cpu_seconds,
              r.seconds, r.max_rss_kib);
  cli_result_free(&r);
}

/* ------------------------------------------------------------- refusals */

Test(cli_check, usage_errors_exit_4_and_write_nothing) {
  suite();
  const char *const *cases[] = {
      (const char *const[]){"check", tmp("g"), tmp("h"), "--scale", "6", NULL},
      (const char *const[]){"check", tmp("g"), tmp("h"), "--bake", NULL},
      (const char *const[]){"check", tmp("g"), tmp("h"), tmp("h/a.png"), NULL},
      (const char *const[]){"check", tmp("g"), tmp("h"), "--limits", "ao -fail 1", NULL},
      (const char *const[]){"check", tmp("g"), tmp("h"), "--limits", "ao: -scale 1",
                            NULL},
      (const char *const[]){"check", tmp("g"), tmp("h"), "--limits", "ao: -fail -1",
                            NULL},
      (const char *const[]){"check", tmp("g"), tmp("h"), "--html", tmp("g/report"), NULL},
      (const char *const[]){"check", tmp("nothing"), tmp("h"), NULL},
      (const char *const[]){"check", tmp("g"), tmp("h/a.png"), NULL},
  };
  const char *parts[] = {"--scale is a bake's option",
                         "--scale is required with --bake",
                         "heights to bake need --bake",
                         "a rule is KIND: options",
                         "'-scale' is not one of idiff's limits",
                         "fail",
                         "lies in a tree it checks",
                         "no such golden",
                         "two directories"};
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++)
    harness_expect_refusal(NULL, cases[i], 4, parts[i], i);
}

/* ------------------------------------------------ what a map records */

/* A map records only what its pixels depend on: --rays and --power do not
 * bake a normal map again, nor show in compare's diff of it. */
Test(cli_check, a_normal_map_is_current_and_same_whatever_the_trace) {
  make_dir(tmp("h"));
  height_file(tmp("h/a.png"), 1);
  cli_result r = RUN("bake", tmp("h"), "--out-dir", tmp("o"), FAST, "--maps",
                     "normal,weights,filtered", "-q");
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  r = RUN("bake", tmp("h"), "--out-dir", tmp("o"), FAST, "--maps",
          "normal,weights,filtered", "--rays", "64", "--slices", "7", "--power", "2",
          "--bias", "1");
  cr_expect_eq(r.code, 0, "%s", r.err);
  cr_expect(strstr(r.out, "0 baked, 1 up to date"), "%s", r.out);
  cli_result_free(&r);
  r = RUN("bake", tmp("h/a.png"), FAST, "--slices", "7", "--normal", tmp("n7.png"),
          "--ao", tmp("a7.png"), "-q");
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  r = RUN("compare", tmp("o/a_normal.png"), tmp("n7.png"));
  cr_expect_eq(r.code, 0, "%s", r.out);
  cr_expect_null(strstr(r.out, "provenance differs"), "%s", r.out);
  cli_result_free(&r);
  /* an ao does depend on the slices */
  r = RUN("bake", tmp("h/a.png"), FAST, "--ao", tmp("a4.png"), "-q");
  cli_result_free(&r);
  r = RUN("compare", tmp("a4.png"), tmp("a7.png"));
  cr_expect(strstr(r.out, "rayset: bb-horizon-v1:a4 -> bb-horizon-v1:a7"), "%s", r.out);
  cli_result_free(&r);
}
