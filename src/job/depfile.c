/* depfile.c: Make/Ninja depfiles ("outputs: inputs"), so make -j and ninja
 * (depfile = ..., deps = gcc) learn what a bake reads.
 *
 * Names are escaped as GCC's -MD writes them, which both tools read: a space
 * as "\ " (a backslash run before a space doubled, so "a\ b" is "a\\\ b"),
 * '#' as "\#", '$' as "$$". A few characters neither tool can hold in a
 * name are refused before the bake: control characters (newline and tab end
 * a name for ninja), ':' and ';' (rule and recipe separators), '=' (make
 * reads an assignment), '%' (make's pattern), '|' (make's order-only
 * separator), and make's wildcards '?', '*' and '[': make globs them bare
 * (it reads "a[bc].png" as ab.png where that exists), and ninja 1.11 keeps
 * the backslash of "\*" and "\[" in the name it reads, so no spelling reads
 * back right in both. */
#include "core/internal.h"
#include "job/job_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The first character of name a depfile cannot hold, and why; 0 if none. */
static int unsayable(const char *name, const char **why) {
  for (const unsigned char *s = (const unsigned char *)name; *s; s++) {
    if (*s == '\n' || *s == '\r') {
      *why = "a newline";
      return *s;
    }
    if (*s == '\t') {
      *why = "a tab (which ends a name for ninja)";
      return *s;
    }
    if (*s < 0x20 || *s == 0x7f) {
      *why = "a control character";
      return *s;
    }
    switch (*s) {
    case ':': *why = "':' (make's rule separator)"; return *s;
    case ';': *why = "';' (make's recipe separator)"; return *s;
    case '=': *why = "'=' (make reads a variable assignment)"; return *s;
    case '%': *why = "'%' (make's pattern character)"; return *s;
    case '?': *why = "'?' (make's wildcard)"; return *s;
    case '*': *why = "'*' (make's wildcard)"; return *s;
    case '[': *why = "'[' (make's wildcard)"; return *s;
    case '|': *why = "'|' (make's order-only separator)"; return *s;
    default: break;
    }
  }
  return 0;
}

bb_status bb__depfile_check_names(const char *depfile, const bb__dep_rule *rules, int count,
                                  bb_error *err) {
  for (int i = 0; i < count; i++) {
    const bb__dep_rule *r = &rules[i];
    for (int k = 0; k < r->target_count + r->prerequisite_count; k++) {
      const char *name =
          k < r->target_count ? r->targets[k] : r->prerequisites[k - r->target_count];
      const char *why = NULL;
      if (unsayable(name, &why))
        return bb__fail(err, BB_ERR_IO, "%s: the file name %s holds %s, which a depfile cannot say",
                        depfile, name, why);
    }
  }
  return BB_OK;
}

/* Writes name escaped; -1 on a write error. */
static int put_name(FILE *f, const char *name) {
  for (const char *s = name; *s; s++) {
    int ok = 1;
    if (*s == '\\') {
      /* A run of backslashes is doubled only where a space follows it. */
      size_t run = strspn(s, "\\");
      const int before_space = s[run] == ' ';
      for (size_t k = 0; k < run * (before_space ? 2 : 1) && ok; k++)
        ok = fputc('\\', f) != EOF;
      s += run - 1;
    } else if (*s == ' ' || *s == '#') {
      ok = fputc('\\', f) != EOF && fputc(*s, f) != EOF;
    } else if (*s == '$') {
      ok = fputs("$$", f) != EOF;
    } else {
      ok = fputc(*s, f) != EOF;
    }
    if (!ok)
      return -1;
  }
  return 0;
}

static int put_rule(FILE *f, const bb__dep_rule *r) {
  if (r->target_count < 1)
    return 0;
  if (put_name(f, r->targets[0]) != 0)
    return -1;
  for (int i = 1; i < r->target_count; i++)
    if (fputc(' ', f) == EOF || put_name(f, r->targets[i]) != 0)
      return -1;
  if (fputc(':', f) == EOF)
    return -1;
  for (int i = 0; i < r->prerequisite_count; i++)
    if (fputc(' ', f) == EOF || put_name(f, r->prerequisites[i]) != 0)
      return -1;
  return fputc('\n', f) == EOF ? -1 : 0;
}

char *bb__depfile_text(const bb__dep_rule *rules, int count, size_t *size) {
  char *text = NULL;
  FILE *f = open_memstream(&text, size);
  if (!f)
    return NULL;
  int failed = 0;
  for (int i = 0; i < count && !failed; i++)
    failed = put_rule(f, &rules[i]) != 0;
  if (fclose(f) != 0)
    failed = 1;
  if (failed) {
    free(text);
    return NULL;
  }
  return text;
}
