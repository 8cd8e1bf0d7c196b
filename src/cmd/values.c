/* values.c: an option's value from text, by its type: the one function of
 * each rule (an integer, a number, one of an enum's words, a list of
 * numbers, a path), whose words every client prints; and the value spelled
 * back as the option takes it, for the provenance's command and for
 * handing a command to another process. Ranges are checked by
 * bb_command_check, against each parameter's one range. Also what every
 * file of the family needs of a command: its strings kept, its options
 * found by name. */
#include "cmd/cmd_internal.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

char *bb__command_keep(bb_command *c, const char *text) {
  if (c->string_count == c->string_capacity) {
    const int cap = c->string_capacity ? 2 * c->string_capacity : 16;
    char **grown = realloc(c->strings, (size_t)cap * sizeof *grown);
    if (!grown)
      return NULL;
    c->strings = grown;
    c->string_capacity = cap;
  }
  char *copy = strdup(text);
  if (copy)
    c->strings[c->string_count++] = copy;
  return copy;
}

int bb__given(const bb_command *c, const char *name) {
  const int i = bb__option_find(c->def, name);
  return i >= 0 && c->given[i];
}

/* name (its first length characters) is the option's long name, '_' read
 * as '-'. */
int bb__names_option(const char *name, size_t length, const char *option) {
  if (strlen(option) != length)
    return 0;
  for (size_t i = 0; i < length; i++)
    if ((name[i] == '_' ? '-' : name[i]) != option[i])
      return 0;
  return 1;
}

int bb__option_find(const bb__command *c, const char *name) {
  for (int i = 0; name && c->options[i]; i++)
    if (bb__names_option(name, strlen(name), c->options[i]->info.name))
      return i;
  return -1;
}

void bb__option_spelling(const bb__option *o, char *out, size_t cap) {
  snprintf(out, cap, "--%s", o->info.name);
}

void bb__choices(const bb__option *o, char *out, size_t cap) {
  size_t used = 0;
  out[0] = '\0';
  const bb__name_fn names = bb__option_names(o);
  for (int i = 0; names && i < 64; i++) {
    const char *name = names(i);
    if (!name || !strcmp(name, "unknown"))
      break;
    if (!strcmp(name, "default") || !name[0]) /* the enum's "not asked", or a value
                                                  the option does not take */
      continue;
    int n = snprintf(out + used, cap - used, "%s%s", used ? "|" : "", name);
    if (n < 0 || (size_t)n >= cap - used)
      break;
    used += (size_t)n;
  }
}

bb__field bb__option_field(const bb__option *o) {
  return o->job ? o->job->field : o->field;
}

size_t bb__option_offset(const bb__option *o) {
  return o->job ? offsetof(bb_command_options, job) + o->job->offset : o->offset;
}

bb__flag_sets bb__option_sets(const bb__option *o) {
  if (!o->job)
    return o->sets;
  bb__flag_sets s = o->job->sets;
  s.offset += offsetof(bb_command_options, job);
  return s;
}

bb__name_fn bb__option_names(const bb__option *o) {
  return o->job ? o->job->names : o->names;
}

static void *field_of(bb_command *c, const bb__option *o) {
  return (char *)&c->options + bb__option_offset(o);
}

/* The integer of text: the whole text, decimal. */
static bb_status parse_integer(const bb__option *o, const char *text, double *v, bb_error *err) {
  char name[80];
  bb__option_spelling(o, name, sizeof name);
  char *end = NULL;
  errno = 0;
  const long long x = strtoll(text, &end, 10);
  if (end == text || *end != '\0')
    return bb__fail(err, BB_ERR_ARGUMENT, "%s needs an integer (got '%.64s')", name, text);
  *v = errno == ERANGE ? (x < 0 ? -HUGE_VAL : HUGE_VAL) : (double)x;
  /* what an int cannot hold is out of any range an option has */
  if (*v < INT_MIN || *v > INT_MAX)
    return o->range ? bb__range_check(o->range, *v, name, err)
                    : bb__fail(err, BB_ERR_ARGUMENT, "%s is out of range (got %.64s)", name,
                               text);
  return BB_OK;
}

/* A finite number: the whole text as strtod reads it (a denormal such as
 * 5e-324 is a number; 1e999 is not finite). */
static bb_status parse_number(const bb__option *o, const char *text, double *v, bb_error *err) {
  char name[80];
  bb__option_spelling(o, name, sizeof name);
  char *end = NULL;
  const double x = strtod(text, &end);
  if (end == text || *end != '\0' || !isfinite(x))
    return bb__fail(err, BB_ERR_ARGUMENT, "%s needs a number (got '%.64s')", name, text);
  *v = x;
  return BB_OK;
}

bb_status bb__parse_numbers(const bb__option *o, const char *text, int count, int integers,
                            double *v, bb_error *err) {
  char name[80];
  bb__option_spelling(o, name, sizeof name);
  const char *p = text;
  const int words = o->info.values > 1;
  for (int i = 0; i < count; i++) {
    char *end = NULL;
    while (words && *p == ' ')
      p++;
    v[i] = integers ? (double)strtol(p, &end, 10) : strtod(p, &end);
    const int last = i + 1 == count;
    const char sep = words ? ' ' : ',';
    if (end == p || !isfinite(v[i]) || (last ? *end != '\0' : *end != sep)) {
      if (words)
        return bb__fail(err, BB_ERR_ARGUMENT, "%s needs %d %s: %s %s (got '%.64s')", name,
                        count, integers ? "integers" : "numbers", name, o->info.value_name,
                        text);
      return bb__fail(err, BB_ERR_ARGUMENT, "%s needs %s: %d comma-separated %s (got '%.64s')",
                      name, o->info.value_name, count, integers ? "integers" : "numbers",
                      text);
    }
    p = end + 1;
  }
  return BB_OK;
}

static bb_status parse_word(const bb__option *o, const char *text, int *value, bb_error *err) {
  long long v = 0;
  if (o->parse(text, &v, NULL) == BB_OK) {
    *value = (int)v;
    return BB_OK;
  }
  char name[80], choices[256];
  bb__option_spelling(o, name, sizeof name);
  char listed[320] = "";
  if (o->info.range_text) {
    /* The words as --help gives them, grouped as there (texture formats by
     * container: dxt1 for a VTF, bc1 for a DDS), ", " between the words of
     * a group. */
    size_t used = 0;
    for (const char *r = o->info.range_text; *r && used + 3 < sizeof listed; r++) {
      if (*r == ' ' && r > o->info.range_text && r[-1] != ';' && r[1] != '(')
        listed[used++] = ',';
      listed[used++] = *r;
    }
    listed[used] = '\0';
    return bb__fail(err, BB_ERR_ARGUMENT, "%s must be one of %s (got '%.64s')", name, listed,
                    text);
  }
  bb__choices(o, choices, sizeof choices);
  for (char *bar = strchr(choices, '|'); bar; bar = strchr(bar, '|'))
    *bar = ',';
  /* ", " between the words, as every enum parser of the library lists them */
  for (const char *w = choices; *w;) {
    const size_t n = strcspn(w, ",");
    snprintf(listed + strlen(listed), sizeof listed - strlen(listed), "%s%.*s",
             listed[0] ? ", " : "", (int)n, w);
    w += n + (w[n] == ',');
  }
  return bb__fail(err, BB_ERR_ARGUMENT, "%s must be one of %s (got '%.64s')", name, listed,
                  text);
}

/* A given flag's other field (bb__flag_sets). */
static void set_flag_sets(bb_command *c, const bb__option *o) {
  const bb__flag_sets s = bb__option_sets(o);
  void *field = (char *)&c->options + s.offset;
  switch (s.field) {
  case BB__FIELD_INT:
  case BB__FIELD_ENUM: *(int *)field = s.value; break;
  case BB__FIELD_STRING: *(const char **)field = s.text; break;
  case BB__FIELD_NONE:
  case BB__FIELD_FLOAT:
  case BB__FIELD_DOUBLE:
  case BB__FIELD_ANGLES:
  case BB__FIELD_KEPT: break;
  }
}

/* AZ,EL into the two doubles at the field; the range is the elevation's. */
static bb_status set_angles(bb_command *c, const bb__option *o, const char *text,
                            double *values, int *count, bb_error *err) {
  bb_status st = bb__parse_numbers(o, text, 2, 0, values, err);
  if (st != BB_OK)
    return st;
  double *angles = field_of(c, o);
  angles[0] = values[0];
  angles[1] = values[1];
  set_flag_sets(c, o);
  values[0] = values[1];
  *count = 1;
  return BB_OK;
}

bb_status bb__set_generic(bb_command *c, const bb__option *o, const char *text,
                          double *values, int *count, bb_error *err) {
  char name[80];
  bb__option_spelling(o, name, sizeof name);
  void *field = field_of(c, o);
  const bb__field kind = bb__option_field(o);
  bb_status st = BB_OK;
  *count = o->info.type == BB_OPTION_INT || o->info.type == BB_OPTION_NUMBER;
  switch (o->info.type) {
  case BB_OPTION_FLAG:
    /* "0" (Python's False) unsets the flag; bb_command_set then counts it
     * as not given. */
    if (text && !strcmp(text, "0") && kind == BB__FIELD_INT) {
      *(int *)field = 0;
      return BB_OK;
    }
    if (text && *text && strcmp(text, "1") != 0)
      return bb__fail(err, BB_ERR_ARGUMENT, "%s takes no value", name);
    if (kind == BB__FIELD_INT)
      *(int *)field = 1;
    set_flag_sets(c, o);
    return BB_OK;
  case BB_OPTION_INT:
    st = parse_integer(o, text, &values[0], err);
    if (st == BB_OK && kind == BB__FIELD_INT)
      *(int *)field = (int)values[0];
    return st;
  case BB_OPTION_NUMBER:
    st = parse_number(o, text, &values[0], err);
    if (st == BB_OK && kind == BB__FIELD_FLOAT)
      *(float *)field = (float)values[0];
    else if (st == BB_OK && kind == BB__FIELD_DOUBLE)
      *(double *)field = values[0];
    return st;
  case BB_OPTION_WORD: {
    int v = 0;
    st = parse_word(o, text, &v, err);
    if (st == BB_OK && (kind == BB__FIELD_ENUM || kind == BB__FIELD_INT))
      *(int *)field = v;
    return st;
  }
  case BB_OPTION_PATH:
  case BB_OPTION_TEXT: {
    if (o->info.type == BB_OPTION_PATH && !*text)
      return bb__fail(err, BB_ERR_ARGUMENT, "%s needs a path (got '')", name);
    if (kind == BB__FIELD_KEPT)
      return BB_OK; /* bb_command_set keeps the text */
    if (kind != BB__FIELD_STRING)
      return bb__fail(err, BB_ERR_ARGUMENT, "%s: no field to set", name);
    char *kept = bb__command_keep(c, text);
    if (!kept)
      return bb__fail(err, BB_ERR_MEMORY, "out of memory");
    *(const char **)field = kept;
    return BB_OK;
  }
  case BB_OPTION_NUMBERS:
    if (kind == BB__FIELD_ANGLES)
      return set_angles(c, o, text, values, count, err);
    break;
  case BB_OPTION_WORDS:
    break;
  }
  return bb__fail(err, BB_ERR_ARGUMENT, "%s: no parser", name);
}

void bb__print_floats(bb__text *t, const float *v, int n) {
  for (int k = 0; k < n; k++) {
    char buf[32];
    bb__float_text(v[k], buf, sizeof buf);
    bb__text_printf(t, "%s%s", k ? "," : "", buf);
  }
}

void bb__print_generic(const bb_command *c, const bb__option *o, bb__text *t) {
  if (o->job) {
    bb__bake_row_value(o->job, &c->options.job, t);
  } else if (o->field == BB__FIELD_KEPT) {
    /* an option of no field (a client's own, serve's --port): its text */
    const int i = bb__option_find(c->def, o->info.name);
    bb__text_add(t, i >= 0 ? c->texts[i] : NULL);
  } else {
    bb__field_text(o->field, o->info.type == BB_OPTION_FLAG, o->names,
                   (const char *)&c->options + o->offset, t);
  }
}
