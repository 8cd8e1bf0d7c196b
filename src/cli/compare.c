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
#include "json.h"
#include "options.h"

#include "bumpbake.h"

#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <stdlib.h>
#include <strings.h>

enum { COMPARE_CANNOT_READ = 4, COMPARE_USAGE = 4 };

/* Option ids of compare alone, above the shared cli_opt_id values (only
 * unique within one command's table). */
enum {
  OPT_FAIL = 0x1000,
  OPT_FAIL_PERCENT,
  OPT_HARD_FAIL,
  OPT_ALLOW_FAILURES,
  OPT_WARN,
  OPT_WARN_PERCENT,
  OPT_HARD_WARN,
  OPT_DIFF
};

static const cli_option opt_fail = {
    .id = OPT_FAIL,
    .long_name = "fail",
    .value_name = "T",
    .default_text = "1e-06",
    .range_text = ">= 0",
    .help = "a pixel fails when a channel differs by more than T",
    .single_dash = 1};
static const cli_option opt_fail_percent = {
    .id = OPT_FAIL_PERCENT,
    .long_name = "failpercent",
    .value_name = "P",
    .default_text = "0",
    .range_text = "0..100",
    .help = "failing pixels allowed, in % of all (then a warning)",
    .single_dash = 1};
static const cli_option opt_hard_fail = {
    .id = OPT_HARD_FAIL,
    .long_name = "hardfail",
    .value_name = "T",
    .default_text = "inf",
    .range_text = ">= 0",
    .help = "fail when any difference exceeds T, even within -failpercent",
    .single_dash = 1};
static const cli_option opt_allow_failures = {
    .id = OPT_ALLOW_FAILURES,
    .long_name = "allowfailures",
    .value_name = "N",
    .default_text = "0",
    .range_text = ">= 0 (integer)",
    .help = "pass when at most N pixels fail, by any amount",
    .single_dash = 1};
static const cli_option opt_warn = {
    .id = OPT_WARN,
    .long_name = "warn",
    .value_name = "T",
    .default_text = "1e-06",
    .range_text = ">= 0",
    .help = "a pixel warns when a channel differs by more than T",
    .single_dash = 1};
static const cli_option opt_warn_percent = {.id = OPT_WARN_PERCENT,
                                            .long_name = "warnpercent",
                                            .value_name = "P",
                                            .default_text = "0",
                                            .range_text = "0..100",
                                            .help = "warning pixels allowed, in % of all",
                                            .single_dash = 1};
static const cli_option opt_hard_warn = {.id = OPT_HARD_WARN,
                                         .long_name = "hardwarn",
                                         .value_name = "T",
                                         .default_text = "inf",
                                         .range_text = ">= 0",
                                         .help = "warn when any difference exceeds T",
                                         .single_dash = 1};
static const cli_option opt_diff = {
    .id = OPT_DIFF,
    .long_name = "diff",
    .value_name = "FILE",
    .help = "write |A-B| (raw in .exr, scaled to a maximum of 1 otherwise)"};
static const cli_option opt_json = {.id = CLI_OPT_JSON,
                                    .long_name = "json",
                                    .default_text = "off",
                                    .help = "print the report as one JSON line"};
static const cli_option opt_quiet = {.id = CLI_OPT_QUIET,
                                     .long_name = "quiet",
                                     .short_name = 'q',
                                     .default_text = "off",
                                     .help = "print no report; the exit code tells"};

static const cli_option *const compare_options[] = {
    &opt_fail, &opt_fail_percent, &opt_hard_fail, &opt_allow_failures,
    &opt_warn, &opt_warn_percent, &opt_hard_warn, &opt_diff,
    &opt_json, &opt_quiet,        &cli_opt_help,
};

static const cli_command compare_command = {
    "compare",
    "A B [OPTIONS]",
    "Compares two images channel by channel, as OpenImageIO's idiff (whose\n"
    "single-dash spellings are accepted), and lists differing provenance.\n"
    "Verdict (idiff 2.4's): pass when at most -allowfailures pixels fail; else\n"
    "fail when more than -failpercent % fail or any difference > -hardfail; else\n"
    "warn when more than -warnpercent % warn or any difference > -hardwarn.\n"
    "Exit: 0 pass, 1 warning, 2 failure, 3 different size or channels,\n"
    "4 unreadable file or bad arguments.",
    compare_options,
    (int)(sizeof compare_options / sizeof compare_options[0]),
    NULL, /* no baking settings */
};

typedef struct compare_args {
  const char *path_a, *path_b;
  bb_compare_limits limits;
  const char *diff_path;
  int json, quiet;
} compare_args;

/* ------------------------------------------------------------ arguments */

static int compare_option(void *ctx, const cli_option *opt, const char *arg) {
  compare_args *a = ctx;
  bb_compare_limits *l = &a->limits;
  const char *cmd = compare_command.name;
  char name[64];
  snprintf(name, sizeof name, "--%s", opt->long_name ? opt->long_name : "");
  int n = 0, rc = 0;
  switch (opt->id) {
  case OPT_FAIL:
    return cli_parse_double(cmd, name, arg, 0.0, 0, DBL_MAX, &l->fail);
  case OPT_FAIL_PERCENT:
    return cli_parse_double(cmd, name, arg, 0.0, 0, 100.0, &l->fail_percent);
  case OPT_HARD_FAIL:
    return cli_parse_double(cmd, name, arg, 0.0, 0, DBL_MAX, &l->hard_fail);
  case OPT_ALLOW_FAILURES:
    rc = cli_parse_int(cmd, name, arg, 0, INT_MAX, &n);
    l->allow_failures = n;
    return rc;
  case OPT_WARN:
    return cli_parse_double(cmd, name, arg, 0.0, 0, DBL_MAX, &l->warn);
  case OPT_WARN_PERCENT:
    return cli_parse_double(cmd, name, arg, 0.0, 0, 100.0, &l->warn_percent);
  case OPT_HARD_WARN:
    return cli_parse_double(cmd, name, arg, 0.0, 0, DBL_MAX, &l->hard_warn);
  case OPT_DIFF:
    a->diff_path = arg;
    return 0;
  case CLI_OPT_JSON:
    a->json = 1;
    return 0;
  case CLI_OPT_QUIET:
    a->quiet = 1;
    return 0;
  }
  return cli_usage_error(cmd, "internal error: option %s has no handler", name);
}

/* 0, -1 for --help, or BB_EXIT_USAGE after a one-line usage error. */
static int parse_compare_args(int argc, char **argv, compare_args *a) {
  memset(a, 0, sizeof *a);
  bb_compare_limits_init(&a->limits);
  int first = 0;
  int rc = cli_parse_options(&compare_command, argc, argv, compare_option, a, &first);
  if (!rc)
    rc = cli_expect_positionals(&compare_command, argc, argv, first, 2, "A B");
  if (rc)
    return rc;
  a->path_a = argv[first];
  a->path_b = argv[first + 1];
  /* The diff is checked before the (possibly long) reads, and must not
   * overwrite either input. */
  if (a->diff_path) {
    const bb_output_spec diff = {a->diff_path, "diff", 0, BB_DEPTH_DEFAULT, 0, 0, 0, 0,
                                 BB_RANGE_UNIT, NULL};
    const char *reads[2] = {a->path_a, a->path_b};
    bb_error err = {{0}};
    bb_status st = bb_outputs_check(&diff, 1, reads, 2, &err);
    if (st != BB_OK)
      rc = cli_library_error(compare_command.name, st, &err);
  }
  return rc;
}

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
static void json_provenance(cli_json *j, const char *prov_diff) {
  cli_json_open(j, "provenance_diff", '[');
  for (const char *line = prov_diff; line && *line;) {
    const char *end = strchr(line, '\n');
    size_t n = end ? (size_t)(end - line) : strlen(line);
    char *one = strndup(line, n);
    cli_json_string(j, NULL, one ? one : "");
    free(one);
    line = end ? end + 1 : line + n;
  }
  cli_json_close(j, ']');
}

static void json_paths(cli_json *j, const compare_args *a) {
  cli_json_string(j, "a", a->path_a);
  cli_json_string(j, "b", a->path_b);
}

static void print_json_report(const compare_args *a, const bb_compare_report *r) {
  const bb_compare_limits *l = &a->limits;
  const bb_compare_stats *s = &r->stats;
  cli_json j = {stdout, 0};
  cli_json_open(&j, NULL, '{');
  json_paths(&j, a);
  cli_json_int(&j, "width", r->width);
  cli_json_int(&j, "height", r->height);
  cli_json_int(&j, "channels", r->channels);
  cli_json_int(&j, "pixels", s->pixels);
  cli_json_number(&j, "mean_abs", s->mean_abs);
  cli_json_number(&j, "rms", s->rms);
  cli_json_number(&j, "max_abs", s->max_abs); /* null when a NaN differs */
  cli_json_open(&j, "worst", '{');
  cli_json_int(&j, "x", s->worst_x);
  cli_json_int(&j, "y", s->worst_y);
  cli_json_int(&j, "channel", s->worst_channel);
  cli_json_close(&j, '}');
  /* Limits under idiff's option names; infinite hard limits are null. */
  cli_json_number(&j, "fail", l->fail);
  cli_json_number(&j, "failpercent", l->fail_percent);
  cli_json_number(&j, "hardfail", l->hard_fail);
  cli_json_int(&j, "allowfailures", l->allow_failures);
  cli_json_int(&j, "over_fail", s->over_fail);
  cli_json_number(&j, "warn", l->warn);
  cli_json_number(&j, "warnpercent", l->warn_percent);
  cli_json_number(&j, "hardwarn", l->hard_warn);
  cli_json_int(&j, "over_warn", s->over_warn);
  json_provenance(&j, r->provenance_differences > 0 ? r->provenance_diff : "");
  cli_json_string(&j, "result", bb_compare_report_result(r));
  cli_json_int(&j, "exit", bb_compare_report_exit_code(r));
  cli_json_close(&j, '}');
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
    cli_json j = {stdout, 0};
    cli_json_open(&j, NULL, '{');
    json_paths(&j, a);
    cli_json_string(&j, "result", bb_compare_report_result(r));
    cli_json_int(&j, "exit", bb_compare_report_exit_code(r));
    cli_json_close(&j, '}');
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

int bb_cli_compare(int argc, char **argv) {
  compare_args a;
  int parsed = parse_compare_args(argc, argv, &a);
  if (parsed < 0)
    return BB_EXIT_OK; /* --help */
  if (parsed > 0)
    return COMPARE_USAGE;
  bb_compare_report r;
  bb_error err = {{0}};
  bb_status st = bb_compare_files(a.path_a, a.path_b, &a.limits, a.diff_path, &r, &err);
  if (st != BB_OK) {
    cli_error_line(err.message[0] ? err.message : bb_status_name(st));
    /* A file that cannot be read, a file over the size limits included,
     * is idiff's 4; two readable files of different sizes are a report
     * (same_shape 0, exit 3), never an error. */
    return COMPARE_CANNOT_READ;
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
