/* run_check.c: `check` planned from its command: --limits' rules parsed by
 * compare's own rows (so a limit means and refuses here what it does
 * there), the trees or the bake's batch (planned as bake plans it, read
 * only unless --update), the reports' places checked, and the job's check
 * made (job/check.c). */
#define _XOPEN_SOURCE 700 /* realpath */
#include "cmd/cmd_internal.h"
#include "job/check.h"
#include "job/job_internal.h"
#include "core/internal.h"

#include <ctype.h>
#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* ------------------------------------------------------------------ rules */

/* idiff's limits, by compare's option names, and the fields they set. */
static const struct {
  const char *name;
  unsigned field;
} limit_options[] = {
    {"fail", BB__LIMIT_FAIL},          {"failpercent", BB__LIMIT_FAIL_PERCENT},
    {"hardfail", BB__LIMIT_HARD_FAIL}, {"allowfailures", BB__LIMIT_ALLOW_FAILURES},
    {"warn", BB__LIMIT_WARN},          {"warnpercent", BB__LIMIT_WARN_PERCENT},
    {"hardwarn", BB__LIMIT_HARD_WARN}};
enum { LIMIT_OPTIONS = sizeof limit_options / sizeof limit_options[0] };

void bb__check_rules_free(bb__check_rule *rules, int count) {
  for (int i = 0; rules && i < count; i++)
    free(rules[i].selector);
  free(rules);
}

static int is_kind_name(const char *s) {
  for (int k = 0; k < BB_MAP_KIND_COUNT; k++)
    if (!strcmp(s, bb__map_kind_name((bb_map_kind)k)))
      return 1;
  return 0;
}

/* The next blank-separated word of *s (at most cap - 1 characters), or 0
 * when none is left. */
static int next_word(const char **s, char *word, size_t cap) {
  while (isspace((unsigned char)**s))
    (*s)++;
  const size_t n = strcspn(*s, " \t\r\v\f");
  if (!n)
    return 0;
  snprintf(word, cap, "%.*s", (int)(n < cap ? n : cap - 1), *s);
  *s += n;
  return 1;
}

/* One rule, "SELECTOR: -option value ...", into r. */
static bb_status parse_rule(const char *text, bb__check_rule *r, bb_error *err) {
  memset(r, 0, sizeof r[0]);
  const char *colon = strchr(text, ':');
  if (!colon)
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "--limits '%.200s': a rule is KIND: options or PATTERN: options",
                    text);
  const char *start = text, *end = colon;
  while (start < end && isspace((unsigned char)*start))
    start++;
  while (end > start && isspace((unsigned char)end[-1]))
    end--;
  if (start == end)
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "--limits '%.200s': no kind or pattern before ':'", text);
  if (!(r->selector = strndup(start, (size_t)(end - start))))
    return bb__fail(err, BB_ERR_MEMORY, "out of memory");
  r->is_kind = is_kind_name(r->selector);
  bb_command *scratch = NULL;
  bb_status st = bb_command_new("compare", &scratch, err);
  if (st == BB_OK)
    bb_command_set_in_memory(scratch, 0);
  const char *s = colon + 1;
  char name[64], value[128];
  int pairs = 0;
  while (st == BB_OK && next_word(&s, name, sizeof name)) {
    const char *bare = name + (name[0] == '-') + (name[0] == '-' && name[1] == '-');
    int known = -1;
    for (int i = 0; i < LIMIT_OPTIONS && name[0] == '-'; i++)
      if (!strcmp(bare, limit_options[i].name))
        known = i;
    if (known < 0)
      st = bb__fail(
          err, BB_ERR_ARGUMENT,
          "--limits '%.200s': '%s' is not one of idiff's limits (-fail, "
          "-failpercent, -hardfail, -allowfailures, -warn, -warnpercent, -hardwarn)",
          text, name);
    else if (!next_word(&s, value, sizeof value))
      st = bb__fail(err, BB_ERR_ARGUMENT, "--limits '%.200s': %s needs a value", text,
                    name);
    else {
      bb_error e = {{0}};
      if ((st = bb_command_set(scratch, bare, value, &e)) != BB_OK)
        bb__fail(err, st, "--limits '%.200s': %s", text, e.message);
      r->given |= limit_options[known].field;
      pairs++;
    }
  }
  if (st == BB_OK && !pairs)
    st = bb__fail(err, BB_ERR_ARGUMENT, "--limits '%.200s': no limit given", text);
  bb_error e = {{0}};
  if (st == BB_OK && (st = bb_command_check(scratch, &e)) != BB_OK)
    bb__fail(err, st, "--limits '%.200s': %s", text, e.message);
  if (st == BB_OK)
    r->limits = bb__command_options_of(scratch)->limits;
  bb_command_free(scratch);
  return st;
}

bb_status bb__check_rules_parse(const char *text, bb__check_rule **rules, int *count,
                                bb_error *err) {
  *rules = NULL;
  *count = 0;
  int capacity = 0;
  bb_status st = BB_OK;
  for (const char *s = text ? text : ""; *s && st == BB_OK;) {
    const size_t n = strcspn(s, ";\n");
    char *one = strndup(s, n);
    s += n + (s[n] != '\0');
    if (!one) {
      st = bb__fail(err, BB_ERR_MEMORY, "out of memory");
      break;
    }
    const char *p = one;
    while (isspace((unsigned char)*p))
      p++;
    if (*p == '#') /* a comment, in a file of rules */
      p += strlen(p);
    if (*p && *count == capacity) {
      capacity = capacity ? 2 * capacity : 8;
      bb__check_rule *grown = realloc(*rules, (size_t)capacity * sizeof *grown);
      if (!grown)
        st = bb__fail(err, BB_ERR_MEMORY, "out of memory");
      else
        *rules = grown;
    }
    if (*p && st == BB_OK) {
      st = parse_rule(one, &(*rules)[*count], err);
      if (st == BB_OK)
        (*count)++;
      else
        free((*rules)[*count].selector);
    }
    free(one);
  }
  if (st != BB_OK) {
    bb__check_rules_free(*rules, *count);
    *rules = NULL;
    *count = 0;
  }
  return st;
}

/* ------------------------------------------------------------------ plan */

/* path made absolute and resolved where it exists: the real path of its
 * nearest existing folder, then the rest as written. 0 when too long. */
static int absolute_path(const char *path, char *out) {
  char head[PATH_MAX];
  if ((size_t)snprintf(head, sizeof head, "%s", path) >= sizeof head)
    return 0;
  size_t cut = strlen(head);
  for (;;) {
    const char saved = head[cut];
    head[cut] = '\0';
    const int found = realpath(cut ? head : path[0] == '/' ? "/" : ".", out) != NULL;
    head[cut] = saved;
    if (found) {
      const char *rest = path + cut + (path[cut] == '/');
      if (*rest && strlen(out) + 1 + strlen(rest) >= PATH_MAX)
        return 0;
      if (*rest) {
        strcat(out, "/");
        strcat(out, rest);
      }
      return 1;
    }
    if (!cut)
      return 0;
    while (cut > 0 && head[cut - 1] != '/')
      cut--;
    if (cut > 0)
      cut--; /* the slash */
  }
}

/* 1 when dir lies in (or is) tree. */
static int inside(const char *dir, const char *tree) {
  char a[PATH_MAX], b[PATH_MAX];
  if (!tree || !absolute_path(dir, a) || !realpath(tree, b))
    return 0;
  const size_t n = strlen(b);
  return strncmp(a, b, n) == 0 && (a[n] == '/' || a[n] == '\0');
}

bb_status bb_check_plan(bb_command *c, const bb_command_hooks *hooks, bb_check **out,
                        bb_error *err) {
  if (!out)
    return bb__fail(err, BB_ERR_ARGUMENT, "check plan: no place for it");
  *out = NULL;
  if (!c || strcmp(c->def->info.name, "check") != 0)
    return bb__fail(err, BB_ERR_ARGUMENT, "check plan: not a check command");
  if (!c->checked)
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "check: the command is not checked (bb_command_check)");
  const bb_command_options *o = &c->options;
  const char *golden = c->inputs[0], *fresh = o->check_bake ? NULL : c->inputs[1];
  struct stat gs, fs;
  const int golden_there = stat(golden, &gs) == 0;
  if (!golden_there && !o->update)
    return bb__fail(err, BB_ERR_IO,
                    "%s: no such golden directory or file (--update makes it)", golden);
  if (fresh && stat(fresh, &fs) != 0)
    return bb__fail(err, BB_ERR_IO, "%s: cannot read: %s", fresh, strerror(errno));
  if (fresh && golden_there && S_ISDIR(gs.st_mode) != S_ISDIR(fs.st_mode))
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "%s and %s: compare two directories or two files", golden, fresh);
  if (o->check_bake && golden_there && !S_ISDIR(gs.st_mode))
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: --bake's goldens are a directory", golden);
  if (o->html && (inside(o->html, golden) || inside(o->html, fresh)))
    return bb__fail(
        err, BB_ERR_ARGUMENT,
        "--html %s lies in a tree it checks: its pictures would be checked too", o->html);
  bb__check_setup setup = {.golden = golden,
                           .fresh = fresh,
                           .limits = o->limits,
                           .update = o->update,
                           .junit = o->junit,
                           .html = o->html,
                           .json = o->json,
                           .quiet = o->quiet,
                           .threads = o->job.bake.trace.threads};
  bb_status st =
      bb__check_rules_parse(o->limit_rules, &setup.rules, &setup.rule_count, err);
  if (st == BB_OK && fresh && !golden_there && S_ISDIR(fs.st_mode))
    st = bb__directory_create(golden, err); /* an update into a new tree */
  if (st == BB_OK && o->check_bake)
    st = bb__command_plan(c, hooks, bb__check_job_options, 1,
                          o->update ? 0u : BB__PLAN_READ_ONLY, &setup.job, err);
  if (st != BB_OK) {
    bb__check_rules_free(setup.rules, setup.rule_count);
    return st;
  }
  return bb__check_new(&setup, out, err);
}
