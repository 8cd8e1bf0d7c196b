/* cli_compare.c: `bumpbake compare` (idiff-style image diff for CI) and `bumpbake info`.
 *
 * compare's exit codes are OpenImageIO idiff's, so a CI script written for
 * idiff works unchanged:
 *   0 within tolerance, 1 warning, 2 failure, 3 different size or channel
 *   count, 4 a file cannot be read.
 * Usage errors also exit 4. idiff itself returns 1 (EXIT_FAILURE) for a bad
 * command line, which a script would take for a mere warning; 4 ("could not
 * compare") makes a broken CI invocation fail loudly instead.
 */
#include "cli.h"
#include "cli_common.h"

#include "bumpbake.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

enum {
  COMPARE_PASS = 0,
  COMPARE_WARN = 1,
  COMPARE_FAIL = 2,
  COMPARE_DIFFERENT_SIZE = 3,
  COMPARE_CANNOT_READ = 4,
  COMPARE_USAGE = 4
};

static const char compare_usage[] =
    "usage: bumpbake compare A B [--fail T] [--failpercent P] [--warn T]\n"
    "                            [--warnpercent P] [--diff FILE] [--json]\n"
    "  fails (exit 2) when more than P% of pixels (default 0) have a channel\n"
    "  differing by more than T (default 1e-6); --warn likewise (exit 1, off by\n"
    "  default). Exit 3: different size or channels; 4: unreadable file or bad\n"
    "  arguments. --diff writes |A-B| (raw in EXR, scaled to max = 1 otherwise).\n";

typedef struct compare_args {
  const char *path_a, *path_b;
  double fail_threshold, fail_percent;
  double warn_threshold, warn_percent;
  int warn_enabled;
  const char *diff_path;
  int json;
} compare_args;

/* ------------------------------------------------------------ arguments */

static int usage_error(const char *what, const char *detail) {
  fprintf(stderr, "bumpbake: compare: %s%s%s\n", what, detail ? " " : "",
          detail ? detail : "");
  fputs(compare_usage, stderr);
  return COMPARE_USAGE;
}

/* Parses a non-negative number (thresholds, percentages); 0 on success. */
static int parse_non_negative(const char *s, double *out) {
  char *end;
  double v = strtod(s, &end);
  if (end == s || *end != '\0' || isnan(v) || v < 0)
    return 1;
  *out = v;
  return 0;
}

/* Options that take a number, and where each one's value goes. */
static double *numeric_option(compare_args *a, const char *name) {
  if (strcmp(name, "--fail") == 0)
    return &a->fail_threshold;
  if (strcmp(name, "--failpercent") == 0)
    return &a->fail_percent;
  if (strcmp(name, "--warn") == 0)
    return &a->warn_threshold;
  if (strcmp(name, "--warnpercent") == 0)
    return &a->warn_percent;
  return NULL;
}

static int parse_compare_args(int argc, char **argv, compare_args *a) {
  memset(a, 0, sizeof *a);
  a->fail_threshold = 1e-6; /* idiff's default */
  a->warn_threshold = INFINITY;
  int positional = 0;
  for (int i = 1; i < argc; i++) {
    const char *arg = argv[i];
    double *target = numeric_option(a, arg);
    if (target) {
      if (i + 1 >= argc)
        return usage_error("missing value after", arg);
      if (parse_non_negative(argv[++i], target) != 0)
        return usage_error("expected a non-negative number after", arg);
      if (target == &a->warn_threshold)
        a->warn_enabled = 1;
    } else if (strcmp(arg, "--diff") == 0) {
      if (i + 1 >= argc)
        return usage_error("missing value after", arg);
      a->diff_path = argv[++i];
    } else if (strcmp(arg, "--json") == 0) {
      a->json = 1;
    } else if (strcmp(arg, "-h") == 0 || strcmp(arg, "--help") == 0) {
      fputs(compare_usage, stdout);
      return -1;
    } else if (arg[0] == '-' && arg[1] != '\0') {
      return usage_error("unknown option", arg);
    } else if (positional < 2) {
      *(positional++ == 0 ? &a->path_a : &a->path_b) = arg;
    } else {
      return usage_error("too many files:", arg);
    }
  }
  if (positional != 2)
    return usage_error("needs two image files", NULL);
  if (a->fail_percent > 100 || a->warn_percent > 100)
    return usage_error("a percentage is over 100", NULL);
  return 0;
}

/* ----------------------------------------------------------------- files */

/* Prints a library error as one "bumpbake: FILE: reason" line; the I/O
 * layer usually names the file itself, so it is not repeated. */
static void print_file_error(const char *path, const bb_error *err) {
  if (strstr(err->message, path))
    fprintf(stderr, "bumpbake: %s\n", err->message);
  else
    fprintf(stderr, "bumpbake: %s: %s\n", path, err->message);
}

static int has_extension(const char *path, const char *ext) {
  size_t n = strlen(path), m = strlen(ext);
  return n >= m && strcasecmp(path + n - m, ext) == 0;
}

/* True when a description looks like bumpbake provenance (and is not some
 * other tool's ImageDescription). */
static int is_bumpbake_provenance(const char *description) {
  return description && (strncmp(description, "bumpbake_version=", 17) == 0 ||
                         strstr(description, "\nbumpbake_version="));
}

static int is_key_char(char ch) {
  return (ch >= 'a' && ch <= 'z') || (ch >= '0' && ch <= '9') || ch == '_';
}

/* True when every non-empty line is key=value with a lowercase key. Some
 * formats cut or re-wrap long comments (TGA keeps 4 lines of 80 characters),
 * and diffing such remains would list keys that never changed. */
static int is_well_formed_provenance(const char *text) {
  if (!is_bumpbake_provenance(text))
    return 0;
  for (const char *line = text; *line;) {
    const char *end = strchr(line, '\n');
    size_t n = end ? (size_t)(end - line) : strlen(line);
    size_t k = 0;
    while (k < n && is_key_char(line[k]))
      k++;
    if (n > 0 && (k == 0 || k == n || line[k] != '='))
      return 0;
    line = end ? end + 1 : line + n;
  }
  return 1;
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
  if (bb_image_write(path, diff, &wo, &err) != BB_OK) {
    print_file_error(path, &err);
    return 1;
  }
  return 0;
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

static void json_string(FILE *f, const char *s) {
  fputc('"', f);
  for (; s && *s; s++) {
    unsigned char ch = (unsigned char)*s;
    if (ch == '"' || ch == '\\')
      fprintf(f, "\\%c", ch);
    else if (ch == '\n')
      fputs("\\n", f);
    else if (ch < 0x20)
      fprintf(f, "\\u%04x", ch);
    else
      fputc(ch, f);
  }
  fputc('"', f);
}

/* JSON has no infinity or NaN: such values are written as null. */
static void json_number(FILE *f, double v) {
  if (isfinite(v))
    fprintf(f, "%.9g", v);
  else
    fputs("null", f);
}

static const char *result_name(int code) {
  switch (code) {
  case COMPARE_PASS:
    return "PASS";
  case COMPARE_WARN:
    return "WARNING";
  case COMPARE_FAIL:
    return "FAILURE";
  }
  return "ERROR";
}

static double percent_of(long count, long total) {
  return total > 0 ? 100.0 * (double)count / (double)total : 0.0;
}

static void print_text_report(const compare_args *a, const bb_image *img,
                              const bb_compare_stats *s, const char *prov_diff,
                              int prov_count, int code) {
  printf("compare %s %s: %d x %d, %d channel%s\n", a->path_a, a->path_b, img->width,
         img->height, img->channels, img->channels == 1 ? "" : "s");
  printf("  mean abs error %.6g\n", s->mean_abs);
  printf("  RMS error      %.6g\n", s->rms);
  printf("  max abs error  %.6g", s->max_abs);
  if (s->max_abs > 0)
    printf(" at pixel (%d, %d) channel %d", s->worst_x, s->worst_y, s->worst_channel);
  printf("\n");
  printf("  %ld pixels (%.3g%%) over fail %g (allowed %g%%)\n", s->over_fail,
         percent_of(s->over_fail, s->pixels), a->fail_threshold, a->fail_percent);
  if (a->warn_enabled)
    printf("  %ld pixels (%.3g%%) over warn %g (allowed %g%%)\n", s->over_warn,
           percent_of(s->over_warn, s->pixels), a->warn_threshold, a->warn_percent);
  if (prov_count > 0)
    printf("provenance differs:\n%s", prov_diff);
  printf("%s\n", result_name(code));
}

static void json_provenance(const char *prov_diff) {
  printf("[");
  const char *line = prov_diff;
  for (int first = 1; line && *line; first = 0) {
    const char *end = strchr(line, '\n');
    size_t n = end ? (size_t)(end - line) : strlen(line);
    char buf[600];
    snprintf(buf, sizeof buf, "%.*s", (int)(n < sizeof buf ? n : sizeof buf - 1), line);
    if (!first)
      printf(",");
    json_string(stdout, buf);
    line = end ? end + 1 : line + n;
  }
  printf("]");
}

static void print_json_report(const compare_args *a, const bb_image *img,
                              const bb_compare_stats *s, const char *prov_diff,
                              int code) {
  printf("{\"a\":");
  json_string(stdout, a->path_a);
  printf(",\"b\":");
  json_string(stdout, a->path_b);
  printf(",\"width\":%d,\"height\":%d,\"channels\":%d,\"pixels\":%ld", img->width,
         img->height, img->channels, s->pixels);
  printf(",\"mean_abs\":");
  json_number(stdout, s->mean_abs);
  printf(",\"rms\":");
  json_number(stdout, s->rms);
  printf(",\"max_abs\":");
  json_number(stdout, s->max_abs);
  printf(",\"worst\":{\"x\":%d,\"y\":%d,\"channel\":%d}", s->worst_x, s->worst_y,
         s->worst_channel);
  printf(",\"fail\":");
  json_number(stdout, a->fail_threshold);
  printf(",\"failpercent\":%.9g,\"over_fail\":%ld", a->fail_percent, s->over_fail);
  printf(",\"warn\":");
  json_number(stdout, a->warn_enabled ? a->warn_threshold : NAN);
  printf(",\"warnpercent\":%.9g,\"over_warn\":%ld", a->warn_percent,
         a->warn_enabled ? s->over_warn : 0L);
  printf(",\"provenance_diff\":");
  json_provenance(prov_diff);
  printf(",\"result\":\"%s\",\"exit\":%d}\n", result_name(code), code);
}

/* ------------------------------------------------------------- decisions */

/* idiff's rule: a level is reached when MORE than percent % of the pixels
 * exceed its threshold (so with percent 0, a single pixel is enough). */
static int compare_verdict(const compare_args *a, const bb_compare_stats *s) {
  double pixels = (double)s->pixels;
  if ((double)s->over_fail > a->fail_percent / 100.0 * pixels)
    return COMPARE_FAIL;
  if (a->warn_enabled && (double)s->over_warn > a->warn_percent / 100.0 * pixels)
    return COMPARE_WARN;
  return COMPARE_PASS;
}

static int read_image(const char *path, bb_image *img, bb_image_info *info) {
  bb_error err = {{0}};
  if (cli_read_image(path, img, info, &err) != BB_OK) {
    print_file_error(path, &err);
    return 1;
  }
  return 0;
}

static int report_size_mismatch(const compare_args *a, const bb_image *x,
                                const bb_image *y) {
  fprintf(stderr, "bumpbake: %s: %d x %d, %d channels, but %s is %d x %d, %d channels\n",
          a->path_b, y->width, y->height, y->channels, a->path_a, x->width, x->height,
          x->channels);
  if (a->json) {
    printf("{\"a\":");
    json_string(stdout, a->path_a);
    printf(",\"b\":");
    json_string(stdout, a->path_b);
    printf(",\"result\":\"DIFFERENT SIZE\",\"exit\":%d}\n", COMPARE_DIFFERENT_SIZE);
  }
  return COMPARE_DIFFERENT_SIZE;
}

/* Says why provenance was not compared when a file has a damaged copy; on
 * stderr, so --json output stays one line. */
static void note_malformed_provenance(const compare_args *a, const bb_image_info *ix,
                                      const bb_image_info *iy) {
  const char *paths[2] = {a->path_a, a->path_b};
  const bb_image_info *infos[2] = {ix, iy};
  for (int i = 0; i < 2; i++)
    if (is_bumpbake_provenance(infos[i]->description) &&
        !is_well_formed_provenance(infos[i]->description))
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
  bb_status st = bb_compare_images(x, y, a->fail_threshold, a->warn_threshold, &stats,
                                   a->diff_path ? &diff : NULL, &err);
  if (st != BB_OK) {
    fprintf(stderr, "bumpbake: %s: %s\n", a->path_b, err.message);
    return st == BB_ERR_SIZE ? COMPARE_DIFFERENT_SIZE : COMPARE_CANNOT_READ;
  }
  char prov_diff[4096] = "";
  int prov_count = 0;
  if (is_well_formed_provenance(ix->description) &&
      is_well_formed_provenance(iy->description))
    prov_count =
        bb_provenance_diff(ix->description, iy->description, prov_diff, sizeof prov_diff);
  else
    note_malformed_provenance(a, ix, iy);
  int code = compare_verdict(a, &stats);
  if (a->json)
    print_json_report(a, x, &stats, prov_diff, code);
  else
    print_text_report(a, x, &stats, prov_diff, prov_count, code);
  /* A diff that cannot be written is reported but does not change the
   * verdict: the comparison itself was made. */
  if (a->diff_path)
    write_diff_image(a->diff_path, &diff, max_finite_value(&diff));
  bb_image_free(&diff);
  return code;
}

int bb_cli_compare(int argc, char **argv) {
  compare_args a;
  int parsed = parse_compare_args(argc, argv, &a);
  if (parsed < 0)
    return COMPARE_PASS; /* --help */
  if (parsed > 0)
    return parsed;

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

/* ------------------------------------------------------------------ info */

static const char info_usage[] = "usage: bumpbake info FILE\n";

int bb_cli_info(int argc, char **argv) {
  if (argc == 2 && (strcmp(argv[1], "-h") == 0 || strcmp(argv[1], "--help") == 0)) {
    fputs(info_usage, stdout);
    return BB_EXIT_OK;
  }
  if (argc != 2 || (argv[1][0] == '-' && argv[1][1] != '\0')) {
    fprintf(stderr, "bumpbake: info: needs exactly one image file\n%s", info_usage);
    return BB_EXIT_USAGE;
  }
  const char *path = argv[1];
  bb_image img = {0};
  bb_image_info info = {0};
  if (read_image(path, &img, &info) != 0)
    return BB_EXIT_FAILURE;

  printf("%s: %d x %d, %d channel%s, %s, %d-bit %s\n", path, img.width, img.height,
         img.channels, img.channels == 1 ? "" : "s", info.format_name,
         info.bits_per_sample, info.is_float ? "float" : "integer");
  if (info.alpha_channel >= 0)
    printf("alpha channel: %d\n", info.alpha_channel);
  if (is_bumpbake_provenance(info.description)) {
    if (!is_well_formed_provenance(info.description))
      printf("provenance (cut or re-wrapped by the file format):\n");
    else
      printf("provenance:\n");
    printf("%s", info.description);
    size_t n = strlen(info.description);
    if (n && info.description[n - 1] != '\n')
      printf("\n");
  } else {
    printf("no bumpbake provenance\n");
    if (info.description && *info.description)
      printf("description: %s\n", info.description);
  }
  bb_image_free(&img);
  bb_image_info_free(&info);
  return BB_EXIT_OK;
}
