/* cli_compare.c: `bumpbake compare`, an idiff-style image diff for CI.
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

#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>

enum { COMPARE_DIFFERENT_SIZE = 3, COMPARE_CANNOT_READ = 4, COMPARE_USAGE = 4 };

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
    rc =
        cli_check_output(compare_command.name, a->path_a, a->diff_path, BB_DEPTH_DEFAULT);
    if (!rc)
      rc = cli_check_output(compare_command.name, a->path_b, a->diff_path,
                            BB_DEPTH_DEFAULT);
  }
  return rc;
}

/* ----------------------------------------------------------------- files */

static int has_extension(const char *path, const char *ext) {
  size_t n = strlen(path), m = strlen(ext);
  return n >= m && strcasecmp(path + n - m, ext) == 0;
}

/* Writes |A-B|. EXR keeps the raw differences; integer formats would round
 * typical golden differences (1e-5) to 0, so the image is scaled to make the
 * largest finite difference white and NaN/infinite differences clip to 1. */
static int write_diff_image(const char *path, bb_image *diff, double max_finite) {
  bb_write_options wo = {0};
  wo.range = BB_RANGE_UNIT;
  if (has_extension(path, ".exr")) {
    wo.depth = BB_DEPTH_FLOAT;
  } else if (max_finite > 0) {
    size_t n = (size_t)diff->width * (size_t)diff->height * (size_t)diff->channels;
    for (size_t i = 0; i < n; i++)
      diff->pixels[i] =
          isfinite(diff->pixels[i]) ? (float)(diff->pixels[i] / max_finite) : 1.0f;
  }
  bb_error err = {{0}};
  return cli_status_exit(path, bb_image_write(path, diff, &wo, &err), &err);
}

static double max_finite_value(const bb_image *img) {
  size_t n = (size_t)img->width * (size_t)img->height * (size_t)img->channels;
  double m = 0;
  for (size_t i = 0; i < n; i++)
    if (isfinite(img->pixels[i]) && img->pixels[i] > m)
      m = img->pixels[i];
  return m;
}

/* --------------------------------------------------------------- reports */

static const char *verdict_name(bb_compare_verdict v) {
  switch (v) {
  case BB_COMPARE_PASS:
    return "PASS";
  case BB_COMPARE_WARN:
    return "WARNING";
  case BB_COMPARE_FAIL:
    return "FAILURE";
  }
  return "ERROR";
}

static double percent_of(long count, long total) {
  return total > 0 ? 100.0 * (double)count / (double)total : 0.0;
}

static void print_text_report(const compare_args *a, const bb_image *img,
                              const bb_compare_stats *s, const char *prov_diff,
                              int prov_count, bb_compare_verdict v) {
  const bb_compare_limits *l = &a->limits;
  printf("compare %s %s: %d x %d, %d channel%s\n", a->path_a, a->path_b, img->width,
         img->height, img->channels, img->channels == 1 ? "" : "s");
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
  if (prov_count > 0)
    printf("provenance differs:\n%s", prov_diff);
  printf("%s\n", verdict_name(v));
}

/* The provenance differences, one string per "key: a -> b" line. */
static void json_provenance(cli_json *j, const char *prov_diff) {
  cli_json_open(j, "provenance_diff", '[');
  for (const char *line = prov_diff; line && *line;) {
    const char *end = strchr(line, '\n');
    size_t n = end ? (size_t)(end - line) : strlen(line);
    char buf[600];
    snprintf(buf, sizeof buf, "%.*s", (int)(n < sizeof buf ? n : sizeof buf - 1), line);
    cli_json_string(j, NULL, buf);
    line = end ? end + 1 : line + n;
  }
  cli_json_close(j, ']');
}

static void json_paths(cli_json *j, const compare_args *a) {
  cli_json_string(j, "a", a->path_a);
  cli_json_string(j, "b", a->path_b);
}

static void print_json_report(const compare_args *a, const bb_image *img,
                              const bb_compare_stats *s, const char *prov_diff,
                              bb_compare_verdict v) {
  const bb_compare_limits *l = &a->limits;
  cli_json j = {stdout, 0};
  cli_json_open(&j, NULL, '{');
  json_paths(&j, a);
  cli_json_int(&j, "width", img->width);
  cli_json_int(&j, "height", img->height);
  cli_json_int(&j, "channels", img->channels);
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
  json_provenance(&j, prov_diff);
  cli_json_string(&j, "result", verdict_name(v));
  cli_json_int(&j, "exit", (int)v);
  cli_json_close(&j, '}');
  fputc('\n', stdout);
}

/* ------------------------------------------------------------- decisions */

static int read_image(const char *path, bb_image *img, bb_image_info *info) {
  bb_error err = {{0}};
  return cli_status_exit(path, cli_read_image(path, img, info, &err), &err);
}

static int report_size_mismatch(const compare_args *a, const bb_image *x,
                                const bb_image *y) {
  fprintf(stderr, "bumpbake: %s: %d x %d, %d channel%s, but %s is %d x %d, %d channel%s\n",
          a->path_b, y->width, y->height, y->channels, y->channels == 1 ? "" : "s",
          a->path_a, x->width, x->height, x->channels, x->channels == 1 ? "" : "s");
  if (a->json && !a->quiet) {
    cli_json j = {stdout, 0};
    cli_json_open(&j, NULL, '{');
    json_paths(&j, a);
    cli_json_string(&j, "result", "DIFFERENT SIZE");
    cli_json_int(&j, "exit", COMPARE_DIFFERENT_SIZE);
    cli_json_close(&j, '}');
    fputc('\n', stdout);
  }
  return COMPARE_DIFFERENT_SIZE;
}

/* Says why provenance was not compared when a file has a damaged copy; on
 * stderr, so --json output stays one line. */
static void note_damaged_provenance(const compare_args *a, const bb_image_info *ix,
                                    const bb_image_info *iy) {
  const char *paths[2] = {a->path_a, a->path_b};
  const bb_image_info *infos[2] = {ix, iy};
  for (int i = 0; i < 2; i++)
    if (bb_provenance_classify(infos[i]->description) == BB_PROVENANCE_DAMAGED)
      fprintf(stderr,
              "bumpbake: %s: provenance is cut or re-wrapped by the file format; "
              "not compared\n",
              paths[i]);
}

/* Compares two decoded images and reports; returns the exit code. */
static int compare_loaded(const compare_args *a, const bb_image *x, const bb_image *y,
                          const bb_image_info *ix, const bb_image_info *iy) {
  if (x->width != y->width || x->height != y->height || x->channels != y->channels)
    return report_size_mismatch(a, x, y);
  bb_compare_stats stats;
  bb_image diff = {0};
  bb_error err = {{0}};
  bb_status st = bb_compare_images(x, y, a->limits.fail, a->limits.warn, &stats,
                                   a->diff_path ? &diff : NULL, &err);
  if (st != BB_OK) {
    cli_file_error(a->path_b, err.message);
    return st == BB_ERR_SIZE ? COMPARE_DIFFERENT_SIZE : COMPARE_CANNOT_READ;
  }
  char prov_diff[4096] = "";
  int prov_count = 0;
  if (bb_provenance_classify(ix->description) == BB_PROVENANCE_INTACT &&
      bb_provenance_classify(iy->description) == BB_PROVENANCE_INTACT) {
    prov_count =
        bb_provenance_diff(ix->description, iy->description, prov_diff, sizeof prov_diff);
    if (prov_count < 0)
      fprintf(stderr, "bumpbake: out of memory comparing provenance; not compared\n");
  } else
    note_damaged_provenance(a, ix, iy);
  bb_compare_verdict v = bb_compare_judge(&stats, &a->limits);
  if (a->quiet)
    ; /* the exit code is the answer */
  else if (a->json)
    print_json_report(a, x, &stats, prov_diff, v);
  else
    print_text_report(a, x, &stats, prov_diff, prov_count, v);
  /* A diff that cannot be written is reported but does not change the
   * verdict: the comparison itself was made. */
  if (a->diff_path)
    write_diff_image(a->diff_path, &diff, max_finite_value(&diff));
  bb_image_free(&diff);
  return (int)v;
}

int bb_cli_compare(int argc, char **argv) {
  compare_args a;
  int parsed = parse_compare_args(argc, argv, &a);
  if (parsed < 0)
    return BB_EXIT_OK; /* --help */
  if (parsed > 0)
    return COMPARE_USAGE;

  bb_image x = {0}, y = {0};
  bb_image_info ix = {0}, iy = {0};
  int code = COMPARE_CANNOT_READ;
  if (read_image(a.path_a, &x, &ix) == 0 && read_image(a.path_b, &y, &iy) == 0)
    code = compare_loaded(&a, &x, &y, &ix, &iy);
  bb_image_free(&x);
  bb_image_free(&y);
  bb_image_info_free(&ix);
  bb_image_info_free(&iy);
  fflush(stdout);
  return code;
}
