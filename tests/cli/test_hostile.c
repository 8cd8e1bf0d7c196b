/* test_hostile.c: files and names meant to hurt, run through the program:
 * outputs over the files a command reads, names from a template that leave
 * the output directory, a signal in the middle of a commit, depfiles that
 * cannot be written or cannot say a name, program images outside their
 * base, and text that would drive a terminal or break JSON. Each case
 * ends in one line and a non-zero exit, with nothing changed that should
 * not be. */
#define _XOPEN_SOURCE 700 /* mkdtemp, nftw, realpath */
#define _DEFAULT_SOURCE    /* wait4 (cli_harness.h) */

#include "bumpbake.h"
#include "cli_harness.h"

#include <math.h>

TestSuite(hostile, .init = harness_setup, .fini = harness_teardown, .timeout = 60);

#define FAST "--scale", "6", "--slices", "4", "--filter-radius", "2"

static void height_file(const char *path) {
  bb_image h;
  cr_assert_eq(bb_image_alloc(&h, 16, 16, 1, NULL), BB_OK);
  for (int i = 0; i < 256; i++)
    h.pixels[i] = (float)(0.5 + 0.3 * sin(0.7 * (i % 16)) * cos(0.5 * (i / 16)));
  harness_write(path, &h, BB_DEPTH_16, BB_RANGE_UNIT);
  bb_image_free(&h);
}

static unsigned char *slurp_file(const char *path, size_t *size) {
  FILE *f = fopen(path, "rb");
  cr_assert_not_null(f, "%s", path);
  char *text = harness_slurp(f);
  fseek(f, 0, SEEK_END);
  *size = (size_t)ftell(f);
  fclose(f);
  return (unsigned char *)text;
}

/* 1 when the file's bytes are the same as before. */
static int unchanged(const char *path, const unsigned char *before, size_t size) {
  size_t now_size;
  unsigned char *now = slurp_file(path, &now_size);
  int same = now_size == size && memcmp(now, before, size) == 0;
  free(now);
  return same;
}

/* --------------------------------------------- outputs over what is read */

/* render checks its picture against every file it reads: the albedo, the
 * height, and each frame of an orbit. */
Test(hostile, render_never_writes_over_what_it_reads) {
  height_file(tmp("h.png"));
  const char *bake[] = {"bake", tmp("h.png"), FAST, "--ssbump", tmp("s.png"), NULL};
  cli_result r = harness_run(bake);
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  height_file(tmp("a.png")); /* an albedo */
  size_t size;
  unsigned char *albedo = slurp_file(tmp("a.png"), &size);
  const char *over_albedo[] = {"render", "--ssbump", tmp("s.png"), "--albedo", tmp("a.png"),
                               "-o", tmp("a.png"), NULL};
  harness_expect_refusal(NULL, over_albedo, 1, "would overwrite the input", 1);
  cr_expect(unchanged(tmp("a.png"), albedo, size), "the albedo was replaced");
  free(albedo);
  const char *over_height[] = {"render", tmp("h.png"), "--scale", "6", "--rays", "16",
                               "--albedo", tmp("a.png"), "-o",
                               tmp("h.png"), NULL};
  harness_expect_refusal(NULL, over_height, 1, "would overwrite the input", 2);
  /* An orbit's frame r_000.png is the ssbump it lights. */
  r = harness_run((const char *[]){"bake", tmp("h.png"), FAST, "--ssbump", tmp("r_000.png"),
                                   NULL});
  cli_result_free(&r);
  unsigned char *frame = slurp_file(tmp("r_000.png"), &size);
  const char *over_frame[] = {"render", "--ssbump", tmp("r_000.png"), "--orbit", "2", "-o",
                              tmp("r.png"), NULL};
  harness_expect_refusal(NULL, over_frame, 1, "would overwrite the input", 3);
  cr_expect(unchanged(tmp("r_000.png"), frame, size), "a frame replaced its input");
  cr_expect(!file_exists(tmp("r_001.png")), "a frame was written");
  free(frame);
}

/* ------------------------------------------------ names from a template */

/* An input named "...png" has the stem "..": "{stem}/{kind}.png" would
 * write ./normal.png beside the out-dir. */
Test(hostile, template_names_stay_inside_the_out_dir) {
  cr_assert_eq(mkdir(tmp("in"), 0755), 0);
  height_file(tmp("in/...png"));
  const char *args[] = {"bake", tmp("in/...png"), FAST, "--out-dir", tmp("out"), "--name",
                        "{stem}/{kind}.png", NULL};
  harness_expect_refusal(NULL, args, 2, "would leave the output directory", 4);
  cr_expect(!file_exists(tmp("normal.png")) && !file_exists(tmp("out/normal.png")));
  const char *literal[] = {"bake", tmp("in/...png"), FAST, "--out-dir", tmp("out"), "--name",
                           "../{stem}_{kind}.png", NULL};
  harness_expect_refusal(NULL, literal, 2, "would leave the output directory", 5);
  const char *absolute[] = {"bake", tmp("in/...png"), FAST, "--out-dir", tmp("out"), "--name",
                            "/tmp/{stem}_{kind}.png", NULL};
  harness_expect_refusal(NULL, absolute, 2, "relative to the output directory", 6);
}

/* ---------------------------------------------------- signals in commits */

/* 1 when strace can inject a signal into a child here (ptrace allowed). */
static int strace_works(void) {
  return system("strace -f -o /dev/null -e trace=none true >/dev/null 2>&1") == 0;
}

/* A SIGINT delivered at the second rename of a set: the old binary left two
 * maps new and two old; the set must be all old or all new. */
Test(hostile, a_signal_during_a_commit_leaves_the_set_whole) {
  if (!strace_works())
    cr_skip_test("strace cannot trace here");
  height_file(tmp("h.png"));
  const char *bin = harness_binary();
  char command[16384];
  snprintf(command, sizeof command,
           "cd '%s' && '%s' bake h.png --scale 4 --slices 4 -o r --bent r_bent.exr -q && "
           "cp r_normal.png n0 && cp r_ao.png a0 && cp r_bent.exr b0 && "
           "strace -f -o /dev/null -e trace=rename -e inject=rename:signal=SIGINT:when=2 "
           "'%s' bake h.png --scale 9 --slices 4 -o r --bent r_bent.exr -q; "
           "cmp -s r_normal.png n0; n=$?; cmp -s r_ao.png a0; a=$?; cmp -s r_bent.exr b0; "
           "b=$?; test $n = $a && test $a = $b",
           tmp(""), bin, bin);
  cr_expect_eq(system(command), 0, "after a SIGINT in the renames, some maps are new and "
                                   "some old");
  cr_expect_eq(files_starting_with(".bb-tmp"), 0, "a temporary was left");
}

/* ---------------------------------------------------------------- depfiles */

/* A depfile that cannot be written is found before the bake: the maps
 * stay as they were. */
Test(hostile, an_unwritable_depfile_is_refused_before_the_bake) {
  if (geteuid() == 0)
    cr_skip_test("root writes into read-only directories");
  height_file(tmp("h.png"));
  cr_assert_eq(mkdir(tmp("ro"), 0555), 0);
  const char *args[] = {"bake", tmp("h.png"), FAST, "--ao", tmp("ao.png"), "--depfile",
                        tmp("ro/h.d"), NULL};
  harness_expect_refusal(NULL, args, 1, "ro", 7);
  cr_expect(!file_exists(tmp("ao.png")), "the map was written");
}

/* A single bake's depfile goes in with its maps: a depfile over a
 * directory is refused before anything is baked. */
Test(hostile, a_depfile_on_a_directory_is_refused_before_the_bake) {
  height_file(tmp("h.png"));
  cr_assert_eq(mkdir(tmp("d"), 0755), 0);
  const char *args[] = {"bake", tmp("h.png"), FAST, "--ao", tmp("ao.png"), "--depfile",
                        tmp("d"), NULL};
  harness_expect_refusal(NULL, args, 1, "is a directory", 8);
  cr_expect(!file_exists(tmp("ao.png")));
}

/* Names make and ninja would misread are refused before the bake; a
 * backslash before a space is written as GCC writes it (\\\ ). */
Test(hostile, depfile_names_are_escaped_or_refused) {
  height_file(tmp("t\tx.png"));
  const char *tab[] = {"bake", tmp("t\tx.png"), FAST, "--normal", tmp("o.png"), "--depfile",
                       tmp("o.d"), NULL};
  harness_expect_refusal(NULL, tab, 1, "a tab", 9);
  static const char *const bad[] = {"c:d.png", "e=f.png", "g;h.png", "i%j.png",
                                    "k?l.png", "m*n.png", "p[q].png"};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    height_file(tmp(bad[i]));
    const char *args[] = {"bake", tmp(bad[i]), FAST, "--normal", tmp("o.png"), "--depfile",
                          tmp("o.d"), NULL};
    harness_expect_refusal(NULL, args, 1, "which a depfile cannot say", 10);
  }
  height_file(tmp("a\\ b#.png"));
  const char *ok[] = {"bake", tmp("a\\ b#.png"), FAST, "--normal", tmp("o.png"), "--depfile",
                      tmp("o.d"), NULL};
  cli_result r = harness_run(ok);
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  size_t size;
  char *text = (char *)slurp_file(tmp("o.d"), &size);
  cr_expect(strstr(text, "a\\\\\\ b\\#.png"), "depfile: %s", text);
  free(text);
}

/* Each name is either read back as itself by both make and ninja (deps =
 * gcc) from the depfile, or refused before the bake. "k*l.png" was written
 * "k\*l.png", which make reads right and ninja 1.11 reads with its
 * backslash, a file that never exists: ninja baked it on every run. */
Test(hostile, depfile_names_read_back_in_make_and_ninja_or_are_refused) {
  if (system("ninja --version >/dev/null 2>&1 && make --version >/dev/null 2>&1") != 0)
    cr_skip_test("no ninja or no make");
  static const char *const names[] = {"a\\ b.png", "c d.png", "e#f.png", "g$h.png",
                                      "i\\j.png",  "k*l.png", "m[n].png"};
  for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
    char dir[16], path[64];
    snprintf(dir, sizeof dir, "d%zu", i);
    const char *cwd = tmp(dir);
    cr_assert_eq(mkdir(cwd, 0755), 0);
    snprintf(path, sizeof path, "%s/%s", dir, names[i]);
    height_file(tmp(path));
    cli_result r = RUN_IN(cwd, "bake", names[i], FAST, "--normal", "o.png", "--depfile", "o.d");
    if (r.code == 1 && strstr(r.err, "which a depfile cannot say")) {
      snprintf(path, sizeof path, "%s/o.png", dir);
      cr_expect(!file_exists(tmp(path)), "%s: refused, but the map was written", names[i]);
      cli_result_free(&r);
      continue;
    }
    cr_assert_eq(r.code, 0, "%s: %s", names[i], r.err);
    cli_result_free(&r);
    /* make: the output is up to date only if the input's name reads back. */
    char command[512];
    snprintf(command, sizeof command,
             "cd '%s' && printf 'include o.d\\n' >mk && make -q -f mk o.png >make.log 2>&1",
             cwd);
    cr_expect_eq(system(command), 0, "%s: make misreads the depfile", names[i]);
    /* ninja: a rule whose depfile is this one; -t deps lists what it read. */
    snprintf(command, sizeof command,
             "cd '%s' && mv o.d o.d.src && printf 'rule r\\n  command = cp o.d.src o.d && "
             "touch o.png\\n  depfile = o.d\\n  deps = gcc\\nbuild o.png: r\\n' >build.ninja "
             "&& ninja >ninja.log 2>&1 && ninja -t deps o.png >deps.log 2>&1",
             cwd);
    cr_assert_eq(system(command), 0, "%s: ninja failed", names[i]);
    snprintf(path, sizeof path, "%s/deps.log", dir);
    size_t size;
    char *deps = (char *)slurp_file(tmp(path), &size);
    char want[64];
    snprintf(want, sizeof want, "\n    %s\n", names[i]);
    cr_expect(strstr(deps, want), "%s: ninja read %s", names[i], deps);
    free(deps);
  }
}

/* ---------------------------------------------------------------- programs */

/* A program's images stay inside --base unless --allow-outside-base. */
Test(hostile, program_images_stay_inside_the_base) {
  cr_assert_eq(mkdir(tmp("base"), 0755), 0);
  height_file(tmp("outside.png"));
  height_file(tmp("base/inside.png"));
  cr_assert_eq(symlink(tmp("outside.png"), tmp("base/link.png")), 0);
  const char *up[] = {"program", "invertColor(../outside.png)", "--base", tmp("base"), "-o",
                      tmp("o.png"), NULL};
  harness_expect_refusal(NULL, up, 1, "outside the base directory", 11);
  const char *absolute[] = {"program", "invertColor(/etc/passwd)", "--base", tmp("base"),
                            "-o", tmp("o.png"), NULL};
  harness_expect_refusal(NULL, absolute, 1, "an absolute path", 12);
  const char *link[] = {"program", "invertColor(link.png)", "--base", tmp("base"), "-o",
                        tmp("o.png"), NULL};
  harness_expect_refusal(NULL, link, 1, "outside the base directory", 13);
  cr_expect(!file_exists(tmp("o.png")));
  const char *inside[] = {"program", "invertColor(inside.png)", "--base", tmp("base"), "-o",
                          tmp("o.png"), NULL};
  cli_result r = harness_run(inside);
  cr_expect_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  const char *allowed[] = {"program", "invertColor(../outside.png)", "--base", tmp("base"),
                           "--allow-outside-base", "-o", tmp("o2.png"), NULL};
  r = harness_run(allowed);
  cr_expect_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
}

/* ---------------------------------------------------- what it prints */

/* 1 when s holds a byte that drives a terminal: C0 controls but newline,
 * DEL, or a C1 control (UTF-8 0xc2 0x80..0x9f). */
static int has_control(const char *s) {
  for (const unsigned char *c = (const unsigned char *)s; *c; c++)
    if ((*c < 0x20 && *c != '\n') || *c == 0x7f || (c[0] == 0xc2 && c[1] >= 0x80 && c[1] < 0xa0))
      return 1;
  return 0;
}

/* 1 when s is valid UTF-8. */
static int valid_utf8(const char *s) {
  for (const unsigned char *c = (const unsigned char *)s; *c;) {
    int n = *c < 0x80 ? 1 : (*c & 0xe0) == 0xc0 ? 2 : (*c & 0xf0) == 0xe0 ? 3 : (*c & 0xf8) == 0xf0 ? 4 : 0;
    if (!n || (n == 2 && *c < 0xc2))
      return 0;
    for (int i = 1; i < n; i++)
      if ((c[i] & 0xc0) != 0x80)
        return 0;
    c += n;
  }
  return 1;
}

/* A description holding an escape sequence and a byte that is not UTF-8,
 * and a file name with both: info, compare and errors print them escaped,
 * and --json stays valid UTF-8. */
Test(hostile, printed_text_never_drives_the_terminal) {
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, 4, 4, 1, NULL), BB_OK);
  const bb_write_options wo = {BB_DEPTH_8, BB_RANGE_UNIT,
                               "bumpbake_version=x\ncommand=\x1b]0;pwned\x07\x1b[31mred\xff\n", NULL};
  cr_assert_eq(bb_image_write(tmp("e.png"), &img, &wo, NULL), BB_OK);
  const char *name = "bad\x1b[2J\xff.png";
  cr_assert_eq(bb_image_write(tmp(name), &img, &wo, NULL), BB_OK);
  bb_image_free(&img);
  const char *runs[][6] = {{"info", tmp("e.png"), NULL},
                           {"info", tmp(name), NULL},
                           {"compare", tmp("e.png"), tmp(name), NULL},
                           {"bake", tmp(name), "--ao", tmp("x.jpg"), NULL},
                           {"info", tmp("missing\x1b[31m.png"), NULL}};
  for (size_t i = 0; i < sizeof runs / sizeof runs[0]; i++) {
    cli_result r = harness_run(runs[i]);
    cr_expect(!has_control(r.out), "%s stdout carries control bytes", runs[i][0]);
    cr_expect(!has_control(r.err), "%s stderr carries control bytes", runs[i][0]);
    cli_result_free(&r);
  }
  const char *json[] = {"info", "--json", tmp(name), NULL};
  cli_result r = harness_run(json);
  cr_expect_eq(r.code, 0, "%s", r.err);
  cr_expect(valid_utf8(r.out), "info --json is not UTF-8: %s", r.out);
  cr_expect(strstr(r.out, "\\udcff"), "the 0xff byte is not \\udcff: %s", r.out);
  cr_expect(strstr(r.out, "\\u001b"), "ESC is not escaped: %s", r.out);
  cli_result_free(&r);
}
