/* compare.c: `bumpbake compare`, an idiff-style image diff for CI.
 *
 * Options and exit codes are OpenImageIO idiff's (2.4), so a CI script
 * written for idiff works unchanged: -fail, -failpercent, -hardfail,
 * -allowfailures, -warn, -warnpercent, -hardwarn (also with two dashes), and
 *   0 pass, 1 warning, 2 failure, 3 different size or channel count,
 *   4 a file cannot be read.
 * Usage errors also exit 4: idiff returns 1 (EXIT_FAILURE) for a bad
 * command line, which a script would take for a mere warning; 4 ("could not
 * compare") makes a broken CI invocation fail loudly instead.
 */
#include "cli.h"
#include "common.h"

#include "bumpbake.h"
#include "../core/json.h" /* the JSON writer, compiled into the CLI (Makefile) */

#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <stdlib.h>
#include <strings.h>

typedef struct compare_args {
  const char *path_a, *path_b;
  bb_compare_limits limits;
  const char *diff_path;
  int json, quiet;
} compare_args;

/* --------------------------------------------------------------- reports */

static double percent_of(long count, long total) {
  return total > 0 ? 100.0 * (double)count / (double)total : 0.0;
}

static void print_text_report(const compare_args *a, const bb_compare_report *r) {
  const bb_compare_limits *l = &a->limits;
  const bb_compare_stats *s = &r->stats;
  cli_printf_line("compare %s %s: %d x %d, %d channel%s", a->path_a, a->path_b, r->width,
                  r->height, r->channels, r->channels == 1 ? "" : "s");
  printf("  mean abs error %.6g\n", s->mean_abs);
  printf("  RMS error      %.6g\n", s->rms);
  printf("  max abs error  %.6g", s->max_abs);
  if (s->max_abs > 0)
    printf(" at pixel (%d, %d) channel %d", s->worst_x, s->worst_y, s->worst_channel);
  printf("\n");
  printf("  %ld pixels (%.3g%%) over fail %g (allowed %g%%", s->over_fail,
         percent_of(s->over_fail, s->pixels), l->fail, l->fail_percent);
  if (l->allow_failures > 0)
    printf(", or %ld pixels", l->allow_failures);
  if (isfinite(l->hard_fail))
    printf("; hard fail %g", l->hard_fail);
  printf(")\n");
  printf("  %ld pixels (%.3g%%) over warn %g (allowed %g%%", s->over_warn,
         percent_of(s->over_warn, s->pixels), l->warn, l->warn_percent);
  if (isfinite(l->hard_warn))
    printf("; hard warn %g", l->hard_warn);
  printf(")\n");
  if (r->provenance_differences > 0) {
    printf("provenance differs:\n");
    for (const char *line = r->provenance_diff; line && *line;) {
      size_t n = strcspn(line, "\n");
      cli_printf_line("%.*s", (int)n, line);
      line += n + (line[n] == '\n');
    }
  }
  printf("%s\n", bb_compare_report_result(r));
}

/* The provenance differences, one string per "key: a -> b" line. */
static void json_provenance(bb__json *j, const char *prov_diff) {
  bb__json_open(j, "provenance_diff", '[');
  for (const char *line = prov_diff; line && *line;) {
    const char *end = strchr(line, '\n');
    size_t n = end ? (size_t)(end - line) : strlen(line);
    char *one = strndup(line, n);
    bb__json_string(j, NULL, one ? one : "");
    free(one);
    line = end ? end + 1 : line + n;
  }
  bb__json_close(j, ']');
}

static void json_paths(bb__json *j, const compare_args *a) {
  bb__json_string(j, "a", a->path_a);
  bb__json_string(j, "b", a->path_b);
}

static void print_json_report(const compare_args *a, const bb_compare_report *r) {
  const bb_compare_limits *l = &a->limits;
  const bb_compare_stats *s = &r->stats;
  bb__json j = {stdout, 0};
  bb__json_open(&j, NULL, '{');
  json_paths(&j, a);
  bb__json_int(&j, "width", r->width);
  bb__json_int(&j, "height", r->height);
  bb__json_int(&j, "channels", r->channels);
  bb__json_int(&j, "pixels", s->pixels);
  bb__json_number(&j, "mean_abs", s->mean_abs);
  bb__json_number(&j, "rms", s->rms);
  bb__json_number(&j, "max_abs", s->max_abs); /* null when a NaN differs */
  bb__json_open(&j, "worst", '{');
  bb__json_int(&j, "x", s->worst_x);
  bb__json_int(&j, "y", s->worst_y);
  bb__json_int(&j, "channel", s->worst_channel);
  bb__json_close(&j, '}');
  /* Limits under idiff's option names; infinite hard limits are null. */
  bb__json_number(&j, "fail", l->fail);
  bb__json_number(&j, "failpercent", l->fail_percent);
  bb__json_number(&j, "hardfail", l->hard_fail);
  bb__json_int(&j, "allowfailures", l->allow_failures);
  bb__json_int(&j, "over_fail", s->over_fail);
  bb__json_number(&j, "warn", l->warn);
  bb__json_number(&j, "warnpercent", l->warn_percent);
  bb__json_number(&j, "hardwarn", l->hard_warn);
  bb__json_int(&j, "over_warn", s->over_warn);
  json_provenance(&j, r->provenance_differences > 0 ? r->provenance_diff : "");
  bb__json_string(&j, "result", bb_compare_report_result(r));
  bb__json_int(&j, "exit", bb_compare_report_exit_code(r));
  bb__json_close(&j, '}');
  fputc('\n', stdout);
}

/* ------------------------------------------------------------- decisions */

static int report_size_mismatch(const compare_args *a, const bb_compare_report *r) {
  char line[1024];
  snprintf(line, sizeof line, "%s: %d x %d, %d channel%s, but %s is %d x %d, %d channel%s",
           a->path_b, r->b_width, r->b_height, r->b_channels, r->b_channels == 1 ? "" : "s",
           a->path_a, r->width, r->height, r->channels, r->channels == 1 ? "" : "s");
  cli_error_line(line);
  if (a->json && !a->quiet) {
    bb__json j = {stdout, 0};
    bb__json_open(&j, NULL, '{');
    json_paths(&j, a);
    bb__json_string(&j, "result", bb_compare_report_result(r));
    bb__json_int(&j, "exit", bb_compare_report_exit_code(r));
    bb__json_close(&j, '}');
    fputc('\n', stdout);
  }
  return bb_compare_report_exit_code(r);
}

/* Says why provenance was not compared when a file has a damaged copy; on
 * stderr, so --json output stays one line. */
static void note_damaged_provenance(const compare_args *a, const bb_compare_report *r) {
  const char *paths[2] = {a->path_a, a->path_b};
  const bb_provenance_class classes[2] = {r->provenance_a, r->provenance_b};
  for (int i = 0; i < 2; i++)
    if (classes[i] == BB_PROVENANCE_DAMAGED)
      cli_file_error(paths[i],
                     "provenance is cut or re-wrapped by the file format; not compared");
}

int cli_run_compare(const cli_run *run) {
  const bb_command_options *o = run->options;
  const compare_args a = {bb_command_input(run->command, 0), bb_command_input(run->command, 1),
                          o->limits, o->diff, o->json, o->quiet};
  bb_compare_report r;
  bb_error err = {{0}};
  /* what it will cost, said before it starts when that is much */
  bb_status st =
      bb_compare_files_check(a.path_a, a.path_b, a.diff_path, cli_note, NULL, &err);
  if (st == BB_OK)
    st = bb_compare_files(a.path_a, a.path_b, &a.limits, a.diff_path, &r, &err);
  if (st != BB_OK) {
    cli_error_line(err.message[0] ? err.message : bb_status_name(st));
    /* A file that cannot be read, a file over the size limits included,
     * is idiff's 4; two readable files of different sizes are a report
     * (same_shape 0, exit 3), never an error. */
    return BB_COMPARE_CANNOT_READ;
  }
  int code;
  if (!r.same_shape) {
    code = report_size_mismatch(&a, &r);
  } else {
    note_damaged_provenance(&a, &r);
    if (a.quiet)
      ; /* the exit code is the answer */
    else if (a.json)
      print_json_report(&a, &r);
    else
      print_text_report(&a, &r);
    /* A diff that cannot be written is reported but does not change the
     * verdict: the comparison itself was made. */
    if (a.diff_path && !r.diff_written)
      cli_file_error(a.diff_path, r.diff_error.message);
    else if (a.diff_path && !a.quiet && !a.json)
      cli_printf_line("wrote diff %s", a.diff_path);
    code = bb_compare_report_exit_code(&r);
  }
  bb_compare_report_free(&r);
  fflush(stdout);
  return code;
}
