/* test_run_files.c: compare and info run by the library (bb_command_run)
 * as the command line runs them: the report kept as data in the result
 * (result.compare, result.info, the exit code, a diff in files) and the
 * pieces the command line prints of it, in order (result.prints). */
#define _XOPEN_SOURCE 700 /* mkdtemp, nftw */

#include <criterion/criterion.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "bumpbake.h"
#include "command_words.h"
#include "scratch_dir.h"

static void setup(void) {
  scratch_dir_make("bb_run_files");
}
static void teardown(void) {
  scratch_dir_remove();
}

TestSuite(run_files, .init = setup, .fini = teardown, .timeout = 60);

/* A width x height image of channels, every sample base, except sample
 * (x, y, c) at base + bump; written to name in the scratch directory with
 * description (may be NULL) by the library's writer, as kind. */
static const char *write_image(const char *name, int width, int height, int channels,
                               float base, int x, int y, int c, float bump, const char *kind,
                               const char *description) {
  bb_image img = {0};
  bb_error err = {{0}};
  cr_assert_eq(bb_image_alloc(&img, width, height, channels, &err), BB_OK, "%s", err.message);
  const size_t w = (size_t)width, n = w * (size_t)height * (size_t)channels;
  for (size_t i = 0; i < n; i++)
    img.pixels[i] = base;
  img.pixels[((size_t)y * w + (size_t)x) * (size_t)channels + (size_t)c] += bump;
  const char *path = in_scratch_dir(name);
  const bb_output_file f = {.path = path,
                            .kind = kind,
                            .image = &img,
                            .range = BB_RANGE_UNIT,
                            .depth = BB_DEPTH_FLOAT,
                            .description = description};
  bb_output_file file = f;
  if (strstr(name, ".vtf") || strstr(name, ".png"))
    file.depth = BB_DEPTH_DEFAULT;
  cr_assert_eq(bb_outputs_write(&file, 1, 1, &err), BB_OK, "%s: %s", path, err.message);
  bb_image_free(&img);
  return path;
}

/* The command name with words (command_words.h), checked and run. */
static bb_command *run(const char *name, const char *const *words, bb_command_result *r) {
  bb_command *c = command(name, words);
  bb_error err = {{0}};
  cr_assert_eq(bb_command_check(c, &err), BB_OK, "%s", err.message);
  cr_assert_eq(bb_command_run(c, NULL, r, &err), BB_OK, "%s", err.message);
  return c;
}

/* a.exr, 4 x 3 x 2 of 0.5, and b.exr of bw x bh x bc, 0.5 but for sample
 * (2, 1, bc - 1) at 0.5 + bump. */
static void pair(const char **a, const char **b, int bw, int bh, int bc, float bump) {
  *a = write_image("a.exr", 4, 3, 2, 0.5f, 0, 0, 0, 0, "colour", NULL);
  *b = write_image("b.exr", bw, bh, bc, 0.5f, bw > 2 ? 2 : 0, bh > 1 ? 1 : 0, bc - 1, bump,
                   "colour", NULL);
}

static int starts_with(const char *s, const char *prefix) {
  return strncmp(s, prefix, strlen(prefix)) == 0;
}

static int ends_with(const char *s, const char *suffix) {
  const size_t n = strlen(s), m = strlen(suffix);
  return n >= m && strcmp(s + n - m, suffix) == 0;
}

/* ------------------------------------------------------------- compare */

/* One sample of 4 x 3 x 2 off by 0.25: the statistics, idiff's verdict and
 * exit code as data, and the text the command line prints from them. */
Test(run_files, compare_keeps_its_statistics_and_verdict_as_data) {
  const char *a, *b;
  pair(&a, &b, 4, 3, 2, 0.25f);
  bb_command_result r;
  bb_command *c = run("compare", (const char *const[]){a, b, NULL}, &r);
  cr_assert_not_null(r.compare);
  const bb_compare_report *k = r.compare;
  cr_expect_eq(k->same_shape, 1);
  cr_expect_eq(k->width, 4);
  cr_expect_eq(k->height, 3);
  cr_expect_eq(k->channels, 2);
  cr_expect_eq(k->stats.pixels, 12);
  cr_expect_float_eq(k->stats.max_abs, 0.25, 1e-9);
  cr_expect_float_eq(k->stats.mean_abs, 0.25 / 24, 1e-9);
  cr_expect_eq(k->stats.worst_x, 2);
  cr_expect_eq(k->stats.worst_y, 1);
  cr_expect_eq(k->stats.worst_channel, 1);
  cr_expect_eq(k->stats.over_fail, 1);
  cr_expect_eq(k->stats.over_warn, 1);
  cr_expect_eq(k->verdict, BB_COMPARE_FAIL);
  cr_expect_str_eq(k->result, "FAILURE");
  cr_expect_eq(r.exit_code, 2);
  cr_expect_eq(r.file_count, 0); /* no --diff */
  cr_expect_null(r.info);
  /* printed: the report's lines on stdout, no error */
  cr_assert_eq(r.print_count, 1);
  cr_expect_eq(r.prints[0].error, 0);
  char first[512];
  snprintf(first, sizeof first, "compare %s %s: 4 x 3, 2 channels\n", a, b);
  cr_expect(starts_with(r.prints[0].text, first), "%s", r.prints[0].text);
  cr_expect(strstr(r.prints[0].text, "  max abs error  0.25 at pixel (2, 1) channel 1\n"), "%s",
            r.prints[0].text);
  cr_expect(ends_with(r.prints[0].text, "\nFAILURE\n"), "%s", r.prints[0].text);
  bb_command_result_free(&r);
  cr_expect_null(r.compare);
  cr_expect_eq(r.print_count, 0);
  bb_command_free(c);
}

/* The same pair under -failpercent 10 passes (1 pixel of 12 fails), as one
 * JSON line; -q prints nothing; the diff is written and listed. */
Test(run_files, compare_limits_json_quiet_and_diff) {
  const char *a, *b;
  pair(&a, &b, 4, 3, 2, 0.25f);
  const char *diff = in_scratch_dir("d.exr");
  bb_command_result r;
  bb_command *c = run("compare",
                      (const char *const[]){a, b, "--failpercent", "10", "--warnpercent", "10",
                                            "--json", "1", "--diff", diff, NULL},
                      &r);
  cr_expect_eq(r.compare->verdict, BB_COMPARE_PASS);
  cr_expect_str_eq(r.compare->result, "PASS");
  cr_expect_eq(r.exit_code, 0);
  cr_expect_eq(r.compare->diff_written, 1);
  cr_assert_eq(r.file_count, 1);
  cr_expect_str_eq(r.files[0].kind, "diff");
  cr_expect_str_eq(r.files[0].path, diff);
  struct stat st;
  cr_expect_eq(stat(diff, &st), 0);
  cr_assert_eq(r.print_count, 1);
  const char *json = r.prints[0].text;
  cr_expect(json[0] == '{' && ends_with(json, "}\n") && !strchr(json, '\n')[1], "%s", json);
  cr_expect(strstr(json, "\"width\":4,\"height\":3,\"channels\":2,\"pixels\":12,"), "%s", json);
  cr_expect(strstr(json, "\"worst\":{\"x\":2,\"y\":1,\"channel\":1}"), "%s", json);
  cr_expect(strstr(json, "\"provenance_diff\":[],\"result\":\"PASS\",\"exit\":0}"), "%s", json);
  bb_command_result_free(&r);
  bb_command_free(c);

  c = run("compare", (const char *const[]){a, b, "--quiet", "1", NULL}, &r);
  cr_expect_eq(r.exit_code, 2);
  cr_expect_eq(r.print_count, 0);
  bb_command_result_free(&r);
  bb_command_free(c);
}

/* Different sizes are a report, not an error: exit 3, the error line
 * naming both sizes, and nothing else compared. */
Test(run_files, compare_of_different_sizes_is_a_report) {
  const char *a, *b;
  pair(&a, &b, 2, 2, 1, 0);
  bb_command_result r;
  bb_command *c = run("compare", (const char *const[]){a, b, NULL}, &r);
  cr_expect_eq(r.compare->same_shape, 0);
  cr_expect_eq(r.compare->b_width, 2);
  cr_expect_eq(r.compare->b_channels, 1);
  cr_expect_str_eq(r.compare->result, "DIFFERENT SIZE");
  cr_expect_eq(r.exit_code, BB_COMPARE_DIFFERENT_SIZE);
  cr_assert_eq(r.print_count, 1);
  cr_expect_eq(r.prints[0].error, 1);
  cr_expect_null(r.prints[0].path);
  char line[512];
  snprintf(line, sizeof line, "%s: 2 x 2, 1 channel, but %s is 4 x 3, 2 channels", b, a);
  cr_expect_str_eq(r.prints[0].text, line);
  bb_command_result_free(&r);
  bb_command_free(c);
}

/* A file that cannot be read is no report: the run fails naming it. */
Test(run_files, compare_of_an_unreadable_file_fails_naming_it) {
  const char *a = write_image("a.exr", 4, 3, 2, 0.5f, 0, 0, 0, 0, "colour", NULL);
  const char *missing = in_scratch_dir("missing.exr");
  bb_command *c = command("compare", (const char *const[]){a, missing, NULL});
  bb_command_result r;
  bb_error err = {{0}};
  cr_assert_eq(bb_command_check(c, &err), BB_OK, "%s", err.message);
  cr_expect_eq(bb_command_run(c, NULL, &r, &err), BB_ERR_IO);
  cr_expect(strstr(err.message, missing), "%s", err.message);
  cr_expect_null(r.compare);
  cr_expect_eq(r.print_count, 0);
  bb_command_free(c);
}

/* ---------------------------------------------------------------- info */

/* Two files and one missing: each file's header fields and provenance
 * entries as data, the missing one's status and message; exit 1; the text
 * printed per file with the error between, in input order. */
Test(run_files, info_keeps_each_files_header_and_provenance) {
  const char *p = write_image("p.exr", 5, 3, 1, 0.5f, 0, 0, 0, 0, "height",
                              "bumpbake_version=0.4.0\ncommand=x\nscale=8\nscale=9\n");
  const char *missing = in_scratch_dir("missing.png");
  const char *q = write_image("q.png", 2, 2, 3, 0.5f, 0, 0, 0, 0, "colour", "made elsewhere");
  bb_command_result r;
  bb_command *c = run("info", (const char *const[]){p, missing, q, NULL}, &r);
  cr_assert_eq(r.info_count, 3);
  /* the result owns its strings: read after the command is freed, as a
   * client that lets its command go first (Python's info) reads it */
  cr_expect(r.info[0].path != bb_command_input(c, 0));
  cr_expect(r.prints[1].path != bb_command_input(c, 1));
  bb_command_free(c);
  const bb_info_file *f = &r.info[0];
  cr_expect_str_eq(f->path, p);
  cr_expect_eq(f->status, BB_OK);
  cr_expect_eq(f->width, 5);
  cr_expect_eq(f->height, 3);
  cr_expect_eq(f->channels, 1);
  cr_expect_str_eq(f->image.format_name, "openexr");
  cr_expect_eq(f->image.is_float, 1);
  cr_expect_eq(f->provenance, BB_PROVENANCE_INTACT);
  cr_assert_eq(f->provenance_count, 3); /* scale's first value counts */
  cr_expect_eq(strncmp(f->provenance_entries[2].key, "scale", 5), 0);
  cr_expect_eq(f->provenance_entries[2].value_length, 1);
  cr_expect_eq(f->provenance_entries[2].value[0], '8');
  cr_expect_null(f->vtf);
  cr_expect_null(f->dds);
  cr_expect_null(f->error);
  f = &r.info[1];
  cr_expect_neq(f->status, BB_OK);
  cr_assert_not_null(f->error);
  cr_expect(strstr(f->error, missing), "%s", f->error);
  f = &r.info[2];
  cr_expect_eq(f->status, BB_OK);
  cr_expect_eq(f->channels, 3);
  cr_expect_eq(f->provenance, BB_PROVENANCE_NONE);
  cr_expect_eq(f->provenance_count, 0);
  cr_expect_str_eq(f->image.description, "made elsewhere");
  cr_expect_eq(r.exit_code, 1);
  /* printed: p's lines, the error about missing, then q's after a blank */
  cr_assert_eq(r.print_count, 3);
  char first[512];
  snprintf(first, sizeof first, "%s: 5 x 3, 1 channel, openexr, 32-bit float\nprovenance:\n", p);
  cr_expect(starts_with(r.prints[0].text, first), "%s", r.prints[0].text);
  cr_expect_eq(r.prints[1].error, 1);
  cr_expect_str_eq(r.prints[1].path, missing);
  cr_expect_str_eq(r.prints[1].text, r.info[1].error);
  snprintf(first, sizeof first, "\n%s: 2 x 2, 3 channels, png, 8-bit integer\n", q);
  cr_expect(starts_with(r.prints[2].text, first), "%s", r.prints[2].text);
  cr_expect(ends_with(r.prints[2].text, "no bumpbake provenance\ndescription: made elsewhere\n"),
            "%s", r.prints[2].text);
  bb_command_result_free(&r);

  /* --json: a line per file, the missing one's saying so */
  c = run("info", (const char *const[]){missing, p, "--json", "1", NULL}, &r);
  cr_assert_eq(r.print_count, 3);
  cr_expect_eq(r.prints[0].error, 1);
  char line[1024];
  snprintf(line, sizeof line, "{\"path\":\"%s\",\"error\":\"%s\"}\n", missing, r.info[0].error);
  cr_expect_str_eq(r.prints[1].text, line);
  cr_expect(strstr(r.prints[2].text, "\"provenance\":{\"bumpbake_version\":\"0.4.0\","
                                     "\"command\":\"x\",\"scale\":\"8\"}"),
            "%s", r.prints[2].text);
  bb_command_result_free(&r);
  bb_command_free(c);
}

/* A VTF's header and the names of its flags, by bit. */
Test(run_files, info_names_a_vtfs_flags_by_bit) {
  const char *v = write_image("s.vtf", 4, 4, 3, 0.5f, 0, 0, 0, 0, "ssbump", NULL);
  bb_command_result r;
  bb_command *c = run("info", (const char *const[]){v, NULL}, &r);
  const bb_info_file *f = &r.info[0];
  cr_assert_not_null(f->vtf);
  cr_expect_null(f->dds);
  cr_expect(f->vtf->flags & BB_VTF_FLAG_SSBUMP);
  int ssbump = 0;
  while (!(BB_VTF_FLAG_SSBUMP & (1u << ssbump)))
    ssbump++;
  cr_expect_str_eq(f->flag_names[ssbump], "SSBUMP");
  for (int bit = 0; bit < 32; bit++)
    if (!(f->vtf->flags & (1u << bit)))
      cr_expect_null(f->flag_names[bit], "bit %d", bit);
  cr_expect_eq(r.exit_code, 0);
  cr_assert_eq(r.print_count, 1);
  cr_expect(strstr(r.prints[0].text, "SSBUMP"), "%s", r.prints[0].text);
  bb_command_result_free(&r);
  bb_command_free(c);
}
