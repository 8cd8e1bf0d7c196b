/* test_bake_rows.c: the bake's options described once (job/bake_rows.h).
 * For every row: a value other than the default, set through bake's
 * parser, is spelled by the command's text (bb_command_text, the one
 * speller of the lines outputs record) as the option the command line
 * reads, and that line read back through the command API (bb_command_*)
 * spells the same. A row without a sample here, or a recorded option of
 * bake without a row, fails: a new option cannot be left out. */
#include "bumpbake.h"
#include "cmd/cmd_internal.h"
#include "job/job_internal.h"

#include <criterion/criterion.h>
#include <stdlib.h>
#include <string.h>

/* A value other than the default for each row, and what it needs given
 * with it (a batch's options need --out-dir; --lit needs --slope). Each is
 * spelled as the job spells it back: the enum's own word (bc3, not its
 * alias dxt5), a number as a user types it. */
typedef struct sample {
  const char *name, *value; /* value NULL: a flag */
  const char *needs, *needs_value;
} sample;

static const sample samples[] = {
    {"scale", "30", NULL, NULL}, /* a whole number: 30, not "3e+01" */
    {"rays", "64", NULL, NULL},
    {"slices", "12", NULL, NULL},
    {"filter-radius", "3", NULL, NULL},
    {"filter-threshold", "0.25", NULL, NULL},
    {"bias", "0.5", NULL, NULL},
    {"power", "20", NULL, NULL},
    {"basis", "dirs:6", NULL, NULL},
    {"normal-filter", "valve", NULL, NULL},
    {"normal-y", "up", NULL, NULL},
    {"clamp", NULL, NULL, NULL},
    {"channel", "a", NULL, NULL},
    {"depth", "16", NULL, NULL},
    {"mips", NULL, NULL, NULL},
    {"bounce", "0.5", NULL, NULL},
    {"bounces", "2", NULL, NULL},
    {"bounce-albedo", "albedo.png", NULL, NULL},
    {"brightness", "bright.png", NULL, NULL},
    {"normal", "n.png", NULL, NULL},
    {"weights", "w.png", NULL, NULL},
    {"ssbump", "s.png", NULL, NULL},
    {"ao", "ao.png", NULL, NULL},
    {"bent", "bent.png", NULL, NULL},
    {"filtered", "f.png", NULL, NULL},
    {"slope", "slope.png", NULL, NULL},
    {"lit", "35,45", "slope", "slope.png"},
    {"out-dir", "out", NULL, NULL},
    {"maps", "normal,ao", "out-dir", "out"},
    {"name", "{stem}-{kind}.png", "out-dir", "out"},
    {"texture-format", "bc3", NULL, NULL},
    {"vtf-version", "7.3", NULL, NULL},
    {"vtf-flags", "0x4", NULL, NULL},
    {"nomip", NULL, NULL, NULL},
    {"fast-compression", NULL, NULL, NULL},
    {"vmt", "m.vmt", NULL, NULL},
    {"materials", "materials", NULL, NULL},
    {"basetexture", "base.vtf", NULL, NULL},
};

static const sample *sample_of(const char *name) {
  for (size_t i = 0; i < sizeof samples / sizeof samples[0]; i++)
    if (!strcmp(samples[i].name, name))
      return &samples[i];
  return NULL;
}

static void set(bb_command *c, const char *name, const char *value) {
  bb_error err = {{0}};
  cr_assert_eq(bb_command_set(c, name, value, &err), BB_OK, "--%s %s: %s", name,
               value ? value : "", err.message);
}

/* The words of a line quoted for a POSIX shell as bb__text_add_word
 * quotes them (plain words, '...' and \' between quotes), into words
 * (malloc'd each), at most cap; their count. */
static int split_words(const char *line, char **words, int cap) {
  int n = 0;
  for (const char *p = line; *p && n < cap;) {
    while (*p == ' ')
      p++;
    if (!*p)
      break;
    char *w = calloc(strlen(p) + 1, 1);
    size_t k = 0;
    while (*p && *p != ' ') {
      if (*p == '\'') {
        for (p++; *p && *p != '\''; p++)
          w[k++] = *p;
        p += *p == '\'';
      } else if (*p == '\\' && p[1]) {
        w[k++] = p[1];
        p += 2;
      } else {
        w[k++] = *p++;
      }
    }
    words[n++] = w;
  }
  return n;
}

/* The command a recorded line reads back as: "bumpbake bake
 * INPUT --option [value] ...". */
static bb_command *read_back(const char *line) {
  char *words[128];
  const int n = split_words(line, words, 128);
  cr_assert_geq(n, 3);
  cr_assert_str_eq(words[0], "bumpbake");
  cr_assert_str_eq(words[1], "bake");
  bb_command *c = NULL;
  cr_assert_eq(bb_command_new("bake", &c, NULL), BB_OK);
  cr_assert_eq(bb_command_add_input(c, words[2], NULL), BB_OK);
  for (int i = 3; i < n; i++) {
    cr_assert(!strncmp(words[i], "--", 2), "'%s' in '%s' is no option", words[i], line);
    const bb_option_info *o = bb_option_find(bb_command_describe(c), words[i] + 2, 0);
    cr_assert_not_null(o, "%s", words[i]);
    const int flag = o->type == BB_OPTION_FLAG;
    cr_assert(flag || i + 1 < n, "%s has no value in '%s'", words[i], line);
    set(c, o->name, flag ? NULL : words[i + 1]);
    i += !flag;
  }
  for (int i = 0; i < n; i++)
    free(words[i]);
  return c;
}

/* Each row: set, spelled, read back the same. */
Test(bake_rows, every_row_is_spelled_as_the_command_line_reads_it_back) {
  const bb_command_info *bake = bb_command_info_find("bake");
  cr_assert_not_null(bake);
  for (int i = 0; i < bake->option_count; i++) {
    const bb__option *option = (const bb__option *)bb_command_option(bake, i);
    const bb__bake_row *row = option->job;
    if (!row)
      continue;
    const sample *s = sample_of(row->name);
    cr_assert_not_null(s, "the row --%s has no sample in this test", row->name);
    bb_command *c = NULL;
    cr_assert_eq(bb_command_new("bake", &c, NULL), BB_OK);
    cr_assert_eq(bb_command_add_input(c, "h.png", NULL), BB_OK);
    if (strcmp(row->name, "scale") != 0)
      set(c, "scale", "8");
    if (s->needs)
      set(c, s->needs, s->needs_value);
    set(c, s->name, s->value);
    char *text = bb_command_text(c, NULL, BB_OPTION_RECORDED);
    cr_assert_not_null(text);

    /* the option spelled as it was typed */
    char spelled[128];
    snprintf(spelled, sizeof spelled, " --%s%s%s", s->name, s->value ? " " : "",
             s->value ? s->value : "");
    char *quoted = bb_text_shell_quoted(s->value ? s->value : "");
    char spelled_quoted[160];
    snprintf(spelled_quoted, sizeof spelled_quoted, " --%s %s", s->name, quoted);
    const char *at = strstr(text, s->value ? spelled_quoted : spelled);
    cr_expect_not_null(at, "'%s' lacks '%s'", text, s->value ? spelled_quoted : spelled);
    if (at && !s->value) {
      const char end = at[strlen(spelled)];
      cr_expect(end == ' ' || end == '\0', "'%s': --%s is a flag", text, s->name);
    }
    free(quoted);

    /* read back: the same command, so the same line */
    bb_command *back = read_back(text);
    cr_expect(bb_command_given(back, s->name), "'%s' read back lost --%s", text, s->name);
    char *again = bb_command_text(back, NULL, BB_OPTION_RECORDED);
    cr_expect_str_eq(again, text);
    free(again);
    bb_command_free(back);
    free(text);
    bb_command_free(c);
  }
}

/* bake's options and the rows: each recorded option of bake but -o PREFIX
 * (its maps' files are what a bake records) has a row, named as the
 * option, a flag where the option is. */
Test(bake_rows, bakes_recorded_options_each_have_a_row) {
  const bb_command_info *bake = bb_command_info_find("bake");
  cr_assert_not_null(bake);
  int rows = 0;
  for (int i = 0; i < bake->option_count; i++) {
    const bb_option_info *info = bb_command_option(bake, i);
    const bb__option *o = (const bb__option *)info;
    if (!o->job) {
      cr_expect(!(info->flags & BB_OPTION_RECORDED) || !strcmp(info->name, "output"),
                "bake's recorded option --%s has no row (job/bake_rows.c)", info->name);
      continue;
    }
    rows++;
    cr_expect_str_eq(info->name, o->job->name);
    cr_expect_eq(o->job->flag, info->type == BB_OPTION_FLAG, "--%s", info->name);
  }
  cr_expect_eq(rows, (int)(sizeof samples / sizeof samples[0]),
               "every sample is a row of bake's, and every row has one");
}
