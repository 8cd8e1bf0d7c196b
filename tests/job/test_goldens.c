/* test_goldens.c: re-bakes every case of fixtures/goldens/cases.txt and compares it with
 * its golden.
 *
 * Tolerances (the bake is deterministic, bit-identical for any thread count,
 * so these only leave room for compiler and libm differences between
 * machines, far below anything a parameter or formula change produces):
 *   float outputs (EXR): no channel value may differ by more than 1e-5;
 *   8-bit outputs (TGA): no value may differ by more than one code (1/255),
 *   which allows a value sitting on a rounding boundary to land either side.
 * In both cases failpercent is 0: a single pixel over the tolerance fails.
 *
 * The binary comes from BB_BIN (default build/bumpbake), the fixtures from
 * BB_FIXTURES (default fixtures). Regenerate goldens with `make goldens`.
 */
#include "bumpbake.h"

#include <criterion/criterion.h>
#include <criterion/parameterized.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#define FLOAT_TOLERANCE "1e-5"
#define CODE_TOLERANCE "0.0040" /* one 8-bit code is 1/255 = 0.00392 */

enum { MAX_CASES = 64, FIELD = 256 };

typedef struct golden_case {
  char name[64];
  char input[FIELD];
  char command[32];
  char arguments[FIELD];
  char outputs[FIELD];
} golden_case;

static const char *env_or(const char *name, const char *fallback) {
  const char *v = getenv(name);
  return v && *v ? v : fallback;
}

static const char *fixtures_dir(void) {
  return env_or("BB_FIXTURES", "fixtures");
}

/* ------------------------------------------------------------- case list */

/* Copies field s (up to a '|' or the end) into out, trimmed of spaces, and
 * returns the position after the '|' (NULL at the end of the line). */
static const char *take_field(const char *s, char *out, size_t cap) {
  while (*s == ' ' || *s == '\t')
    s++;
  const char *end = strchr(s, '|');
  size_t n = end ? (size_t)(end - s) : strlen(s);
  while (n &&
         (s[n - 1] == ' ' || s[n - 1] == '\t' || s[n - 1] == '\n' || s[n - 1] == '\r'))
    n--;
  snprintf(out, cap, "%.*s", (int)n, s);
  return end ? end + 1 : NULL;
}

static int parse_case(const char *line, golden_case *c) {
  memset(c, 0, sizeof *c);
  const char *s = take_field(line, c->name, sizeof c->name);
  if (s)
    s = take_field(s, c->input, sizeof c->input);
  if (s)
    s = take_field(s, c->command, sizeof c->command);
  if (s)
    s = take_field(s, c->arguments, sizeof c->arguments);
  if (s)
    s = take_field(s, c->outputs, sizeof c->outputs);
  return c->name[0] && c->input[0] && c->command[0] && c->outputs[0];
}

/* Reads cases.txt into cases (capacity MAX_CASES); returns the count, or -1
 * when the file cannot be read or a line is malformed. */
static int load_cases(golden_case *cases) {
  char path[512], line[1024];
  snprintf(path, sizeof path, "%s/goldens/cases.txt", fixtures_dir());
  FILE *f = fopen(path, "r");
  if (!f)
    return -1;
  int n = 0;
  while (fgets(line, sizeof line, f)) {
    const char *s = line + strspn(line, " \t");
    if (*s == '#' || *s == '\n' || *s == '\0')
      continue;
    if (n == MAX_CASES || !parse_case(s, &cases[n])) {
      n = -1;
      break;
    }
    n++;
  }
  fclose(f);
  return n;
}

/* The golden (and the fresh output's) file name of one output kind. */
static void output_name(const golden_case *c, const char *kind, char *out, size_t cap) {
  int is_valve = strcmp(c->command, "height2ssbump") == 0;
  snprintf(out, cap, "%.63s_%.255s.%s", c->name, kind, is_valve ? "tga" : "exr");
}

/* Calls fn(c, kind, user) for each word of c->outputs. */
static void for_each_output(const golden_case *c,
                            void (*fn)(const golden_case *, const char *, void *),
                            void *user) {
  char list[FIELD];
  snprintf(list, sizeof list, "%s", c->outputs);
  char *save = NULL;
  for (char *kind = strtok_r(list, " \t", &save); kind;
       kind = strtok_r(NULL, " \t", &save))
    fn(c, kind, user);
}

/* ---------------------------------------------------------- running */

/* Runs a shell command, appending its stdout+stderr to out; returns the
 * exit code (-1 when it did not exit normally). */
static int run(char *out, size_t cap, const char *fmt, ...) {
  char cmd[4096];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(cmd, sizeof cmd, fmt, ap);
  va_end(ap);
  char shell[4200];
  snprintf(shell, sizeof shell, "( %s ) 2>&1", cmd); /* stderr of every command in cmd */
  FILE *p = popen(shell, "r");
  if (!p)
    return -1;
  size_t used = strlen(out);
  size_t n = fread(out + used, 1, cap - used - 1, p);
  out[used + n] = '\0';
  int status = pclose(p);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/* The case's arguments with IN replaced by input (single-quoted). */
static void expand_arguments(const golden_case *c, const char *input, char *out,
                             size_t cap) {
  char words[FIELD];
  snprintf(words, sizeof words, "%s", c->arguments);
  out[0] = '\0';
  char *save = NULL;
  for (char *w = strtok_r(words, " \t", &save); w; w = strtok_r(NULL, " \t", &save)) {
    size_t used = strlen(out);
    if (strcmp(w, "IN") == 0)
      snprintf(out + used, cap - used, " '%s'", input);
    else
      snprintf(out + used, cap - used, " %s", w);
  }
}

typedef struct bake_flags {
  const char *dir;
  char text[2048];
} bake_flags;

static void add_output_flag(const golden_case *c, const char *kind, void *user) {
  bake_flags *f = user;
  char name[400];
  output_name(c, kind, name, sizeof name);
  size_t used = strlen(f->text);
  snprintf(f->text + used, sizeof f->text - used, " --%s '%s/%s'", kind, f->dir, name);
}

/* Re-bakes case c into dir, naming outputs as the goldens are named. */
static int rebake(const golden_case *c, const char *dir, char *log, size_t cap) {
  char input[600], args[1024];
  snprintf(input, sizeof input, "%s/%s", fixtures_dir(), c->input);
  const char *bin = env_or("BB_BIN", "build/bumpbake");
  if (strcmp(c->command, "bake") == 0) {
    bake_flags flags = {.dir = dir, .text = ""};
    for_each_output(c, add_output_flag, &flags);
    expand_arguments(c, input, args, sizeof args);
    return run(log, cap, "'%s' bake%s%s --quiet", bin, args, flags.text);
  }
  /* height2ssbump writes INPUT-ssbump.tga next to its input: run on a copy. */
  char copy[600], stem[600];
  snprintf(copy, sizeof copy, "%s/%s", dir, c->input);
  snprintf(stem, sizeof stem, "%s", copy);
  char *dot = strrchr(stem, '.');
  if (dot)
    *dot = '\0';
  expand_arguments(c, copy, args, sizeof args);
  return run(
      log, cap,
      "cp '%s' '%s' && '%s' height2ssbump%s && mv '%s-ssbump.tga' '%s/%s_ssbump.tga'",
      input, copy, bin, args, stem, dir, c->name);
}

typedef struct comparison {
  const char *dir;
  int failures;
  char report[16384];
} comparison;

/* Compares one output with its golden; a failure appends compare's whole
 * report (errors, worst pixel, provenance differences) under a heading. */
static void compare_output(const golden_case *c, const char *kind, void *user) {
  comparison *cmp = user;
  char name[400], out[8192] = "";
  output_name(c, kind, name, sizeof name);
  const char *tolerance = strstr(name, ".tga") ? CODE_TOLERANCE : FLOAT_TOLERANCE;
  int code = run(out, sizeof out, "'%s' compare '%s/goldens/%s' '%s/%s' --fail %s",
                 env_or("BB_BIN", "build/bumpbake"), fixtures_dir(), name, cmp->dir, name,
                 tolerance);
  if (code == 0)
    return;
  cmp->failures++;
  size_t used = strlen(cmp->report);
  /* Same provenance means same input and parameters: the code changed. */
  const char *hint =
      code == 2 && !strstr(out, "provenance differs")
          ? "(provenance matches: same input and parameters, so the bake's "
            "code changed)\n"
          : "";
  snprintf(cmp->report + used, sizeof cmp->report - used,
           "\n--- golden %s, output %s: compare exit %d (tolerance --fail %s)\n%s%s",
           c->name, kind, code, tolerance, out, hint);
}

/* ------------------------------------------------------------------ tests */

ParameterizedTestParameters(goldens, rebake_matches_golden) {
  golden_case buffer[MAX_CASES];
  int n = load_cases(buffer);
  if (n <= 0)
    return cr_make_param_array(golden_case, NULL, 0);
  /* Criterion copies parameters into each test process: cr_malloc memory. */
  golden_case *cases = cr_malloc(sizeof *cases * (size_t)n);
  memcpy(cases, buffer, sizeof *cases * (size_t)n);
  return cr_make_param_array(golden_case, cases, (size_t)n);
}

ParameterizedTest(golden_case *c, goldens, rebake_matches_golden, .timeout = 300) {
  char dir[] = "/tmp/bb-golden-XXXXXX";
  cr_assert_not_null(mkdtemp(dir));
  char log[8192] = "";
  int code = rebake(c, dir, log, sizeof log);
  comparison cmp = {.dir = dir};
  if (code == 0)
    for_each_output(c, compare_output, &cmp);
  char rm[128] = "";
  run(rm, sizeof rm, "rm -rf '%s'", dir);
  cr_assert_eq(code, 0, "golden %s: re-bake failed (exit %d):\n%s", c->name, code, log);
  cr_assert_eq(cmp.failures, 0, "golden %s: %d output(s) differ from the goldens:%s",
               c->name, cmp.failures, cmp.report);
}

typedef struct existence {
  int missing;
  char report[2048];
} existence;

static void check_golden_exists(const golden_case *c, const char *kind, void *user) {
  existence *e = user;
  char name[400], path[1000];
  output_name(c, kind, name, sizeof name);
  snprintf(path, sizeof path, "%s/goldens/%s", fixtures_dir(), name);
  struct stat st;
  if (stat(path, &st) == 0 && st.st_size > 0 && st.st_size < 1024 * 1024)
    return;
  e->missing++;
  size_t used = strlen(e->report);
  snprintf(e->report + used, sizeof e->report - used,
           "\n  %s (missing, empty or >= 1 MB)", path);
}

/* Guards the parameterized test: a case list that fails to load would make
 * it run zero cases and pass. */
Test(goldens, case_list_loads_and_every_golden_exists) {
  golden_case cases[MAX_CASES];
  int n = load_cases(cases);
  cr_assert_gt(n, 0,
               "cannot read cases from %s/goldens/cases.txt (or a line is malformed)",
               fixtures_dir());
  existence e = {0};
  for (int i = 0; i < n; i++) {
    char input[700];
    snprintf(input, sizeof input, "%s/%s", fixtures_dir(), cases[i].input);
    cr_assert_eq(access(input, R_OK), 0, "case %s: input %s is missing", cases[i].name,
                 input);
    cr_assert(strcmp(cases[i].command, "bake") == 0 ||
                  strcmp(cases[i].command, "height2ssbump") == 0,
              "case %s: unknown subcommand %s", cases[i].name, cases[i].command);
    for_each_output(&cases[i], check_golden_exists, &e);
  }
  cr_assert_eq(e.missing, 0, "goldens to regenerate with `make goldens`:%s", e.report);
}

/* ------------------------------------------------- synthetic fixture maps */

/* build/tools/genheight next to the binary under test. */
static void genheight_path(char *out, size_t cap) {
  char bin[512];
  snprintf(bin, sizeof bin, "%s", env_or("BB_BIN", "build/bumpbake"));
  char *slash = strrchr(bin, '/');
  if (slash)
    slash[1] = '\0';
  else
    bin[0] = '\0';
  snprintf(out, cap, "%stools/genheight", bin);
}

/* The committed synthetic fixtures are exactly what fixtures/SOURCES.md's
 * commands make, so anyone can rebuild or extend them. */
Test(fixtures, genheight_remakes_the_committed_maps_exactly) {
  static const char *const maps[][3] = {
      {"noise", "96", "80"}, {"bricks", "128", "64"}, {"pit", "65", "65"}};
  char dir[] = "/tmp/bb-fixtures-XXXXXX", gen[600], log[8192] = "";
  cr_assert_not_null(mkdtemp(dir));
  genheight_path(gen, sizeof gen);
  for (size_t i = 0; i < sizeof maps / sizeof maps[0]; i++) {
    char name[64];
    snprintf(name, sizeof name, "%s_%sx%s.png", maps[i][0], maps[i][1], maps[i][2]);
    int code = run(log, sizeof log,
                   "'%s' %s %s %s '%s/%s' && '%s' compare '%s/%s' '%s/%s' --fail 0", gen,
                   maps[i][0], maps[i][1], maps[i][2], dir, name,
                   env_or("BB_BIN", "build/bumpbake"), fixtures_dir(), name, dir, name);
    cr_expect_eq(code, 0, "%s differs from a fresh genheight run:\n%s", name, log);
  }
  char rm[128] = "";
  run(rm, sizeof rm, "rm -rf '%s'", dir);
}

/* Mean |h(x+1) - h(x)| across the wrap-around edge divided by the mean over
 * interior steps (and the same for rows): about 1 when the map tiles. */
static void seam_ratios(const bb_image *h, double *horizontal, double *vertical) {
  double seam_x = 0, step_x = 0, seam_y = 0, step_y = 0;
  for (int y = 0; y < h->height; y++)
    for (int x = 0; x < h->width; x++) {
      float v = *bb_image_texel(h, x, y);
      double dx = fabs(*bb_image_texel(h, (x + 1) % h->width, y) - v);
      double dy = fabs(*bb_image_texel(h, x, (y + 1) % h->height) - v);
      if (x == h->width - 1)
        seam_x += dx;
      else
        step_x += dx;
      if (y == h->height - 1)
        seam_y += dy;
      else
        step_y += dy;
    }
  *horizontal = (seam_x / h->height) / (step_x / (h->height * (h->width - 1.0)));
  *vertical = (seam_y / h->width) / (step_y / (h->width * (h->height - 1.0)));
}

Test(fixtures, genheight_noise_tiles_at_odd_sizes) {
  static const int sizes[][2] = {{37, 53}, {96, 80}, {129, 31}};
  char dir[] = "/tmp/bb-fixtures-XXXXXX", gen[600];
  cr_assert_not_null(mkdtemp(dir));
  genheight_path(gen, sizeof gen);
  for (size_t i = 0; i < sizeof sizes / sizeof sizes[0]; i++) {
    char path[700], log[2048] = "";
    snprintf(path, sizeof path, "%s/n%zu.exr", dir, i);
    cr_assert_eq(run(log, sizeof log, "'%s' noise %d %d '%s' --seed 3", gen, sizes[i][0],
                     sizes[i][1], path),
                 0, "%s", log);
    bb_image h = {0};
    cr_assert_eq(bb_image_read(path, &h, NULL, NULL), BB_OK);
    double rh, rv;
    seam_ratios(&h, &rh, &rv);
    bb_image_free(&h);
    cr_expect(rh > 0.5 && rh < 2 && rv > 0.5 && rv < 2,
              "%dx%d: seam/interior step ratio %.2f horizontal, %.2f vertical",
              sizes[i][0], sizes[i][1], rh, rv);
  }
  char rm[128] = "";
  run(rm, sizeof rm, "rm -rf '%s'", dir);
}
