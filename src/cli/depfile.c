/* cli_depfile.c: Make/Ninja depfiles ("outputs: inputs"), so make -j and
 * ninja (depfile = ..., deps = gcc) learn what a bake reads. */
#include "batch.h"

#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* Writes name escaped as GCC's depfiles escape it; -1 on a write error. */
static int put_name(FILE *f, const char *name) {
  for (const char *s = name; *s; s++) {
    int ok;
    if (*s == ' ' || *s == '#')
      ok = fputc('\\', f) != EOF && fputc(*s, f) != EOF;
    else if (*s == '$')
      ok = fputs("$$", f) != EOF;
    else
      ok = fputc(*s, f) != EOF;
    if (!ok)
      return -1;
  }
  return 0;
}

static int put_names(FILE *f, const char *const *names, int count) {
  for (int i = 0; i < count; i++)
    if (fputc(' ', f) == EOF || put_name(f, names[i]) != 0)
      return -1;
  return 0;
}

static int put_rule(FILE *f, const cli_dep_rule *r) {
  if (r->target_count < 1)
    return 0;
  /* The first target without the leading space of put_names. */
  if (put_name(f, r->targets[0]) != 0 || put_names(f, r->targets + 1, r->target_count - 1) ||
      fputc(':', f) == EOF || put_names(f, r->prerequisites, r->prerequisite_count) ||
      fputc('\n', f) == EOF)
    return -1;
  return 0;
}

/* A name with a newline cannot be written in a depfile; 0, or the exit code
 * after printing. */
static int refuse_unwritable_names(const char *path, const cli_dep_rule *rules, int count) {
  for (int i = 0; i < count; i++) {
    int bad = 0;
    for (int t = 0; t < rules[i].target_count; t++)
      bad |= strchr(rules[i].targets[t], '\n') != NULL;
    for (int p = 0; p < rules[i].prerequisite_count; p++)
      bad |= strchr(rules[i].prerequisites[p], '\n') != NULL;
    if (bad) {
      cli_file_error(path, "a file name holds a newline, which a depfile cannot say");
      return BB_EXIT_FAILURE;
    }
  }
  return 0;
}

int cli_depfile_check(const char *command, const char *path, const cli_dep_rule *rules,
                      int count) {
  int rc = refuse_unwritable_names(path, rules, count);
  if (rc)
    return rc;
  /* A file the bake reads would be replaced by text (the input, as any
   * output over the input, is a failure); one it writes would be
   * clobbered by the other, which is a usage error as for two outputs. */
  for (int i = 0; i < count; i++) {
    for (int p = 0; p < rules[i].prerequisite_count; p++)
      if (cli_same_file(rules[i].prerequisites[p], path)) {
        cli_file_error(path, "the depfile would overwrite a file the bake reads");
        return BB_EXIT_FAILURE;
      }
    for (int t = 0; t < rules[i].target_count; t++)
      if (cli_same_file(rules[i].targets[t], path))
        return cli_usage_error(command, "--depfile %s is also an output of the bake", path);
  }
  struct stat st;
  if (stat(path, &st) == 0 && S_ISDIR(st.st_mode)) {
    cli_file_error(path, "cannot write the depfile: is a directory");
    return BB_EXIT_FAILURE;
  }
  return cli_check_output_directory(path);
}

/* The rules as depfile text, in a buffer the caller frees; NULL when out
 * of memory. */
static char *depfile_text(const cli_dep_rule *rules, int count, size_t *size) {
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

/* Composed in memory, then written by the library as images are (a
 * temporary renamed into place, removed on a signal). */
int cli_depfile_write(const char *path, const cli_dep_rule *rules, int count) {
  int rc = refuse_unwritable_names(path, rules, count);
  if (rc)
    return rc;
  size_t size = 0;
  char *text = depfile_text(rules, count, &size);
  if (!text) {
    cli_file_error(path, "out of memory");
    return BB_EXIT_FAILURE;
  }
  bb_error err;
  bb_status st = bb_file_write(path, text, size, &err);
  free(text);
  return st == BB_OK ? 0 : cli_status_exit(path, st, &err);
}
