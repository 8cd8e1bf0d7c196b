/* describe.c: the commands and their options as the public API shows them:
 * lookups, and each option's range, choices and default spelled for help
 * and the reference pages. */
#include "cmd/cmd_internal.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A public description is the first member of the library's. */
static const bb__command *command_of(const bb_command_info *info) {
  return (const bb__command *)(const void *)info;
}

static const bb__option *option_of(const bb_option_info *info) {
  return (const bb__option *)(const void *)info;
}

static int option_total(const bb__command *c) {
  int n = 0;
  while (c->options[n])
    n++;
  return n;
}

const bb_command_info *bb_command_info_get(int index) {
  if (index < 0 || index >= bb__command_total)
    return NULL;
  /* option_count is known from the table's end */
  return &bb__commands[index]->info;
}

const bb_command_info *bb_command_info_find(const char *name) {
  for (int i = 0; name && i < bb__command_total; i++)
    if (!strcmp(bb__commands[i]->info.name, name))
      return &bb__commands[i]->info;
  return NULL;
}

const bb_option_info *bb_command_option(const bb_command_info *command, int index) {
  if (!command)
    return NULL;
  const bb__command *c = command_of(command);
  return index >= 0 && index < option_total(c) ? &c->options[index]->info : NULL;
}

const char *bb_option_type_name(bb_option_type type) {
  static const char *const names[] = {"flag",    "integer", "number", "word",
                                      "words",   "numbers", "text",   "path"};
  return (int)type >= 0 && (size_t)type < sizeof names / sizeof names[0] ? names[type] : NULL;
}

bb_status bb_option_parse(const bb_option_info *option, const char *text, long long *value,
                          bb_error *err) {
  const bb__option *o = (const bb__option *)option;
  if (!o || !text || !value)
    return bb__fail(err, BB_ERR_ARGUMENT, "bb_option_parse: NULL argument");
  if (!o->parse) {
    char name[80];
    bb__option_spelling(o, name, sizeof name);
    return bb__fail(err, BB_ERR_ARGUMENT, "%s has no word or value of its own to parse", name);
  }
  return o->parse(text, value, err);
}

const char *bb_option_word(const bb_option_info *option, long long value) {
  const bb__option *o = (const bb__option *)option;
  const bb__name_fn names = o ? bb__option_names(o) : NULL;
  if (!names || value < 0 || value > INT_MAX)
    return NULL;
  /* only a word the option reads back as value: not "unknown", nor
   * depth's "default" (BB_DEPTH_DEFAULT is no word a user types) */
  const char *w = names((int)value);
  long long back = -1;
  return w && *w && o->parse && o->parse(w, &back, NULL) == BB_OK && back == value ? w : NULL;
}

const bb_option_info *bb_option_find(const bb_command_info *command, const char *name,
                                     size_t length) {
  if (!command || !name)
    return NULL;
  const bb__command *c = command_of(command);
  const size_t n = length ? length : strlen(name);
  for (int i = 0; c->options[i]; i++)
    if (bb__names_option(name, n, c->options[i]->info.name))
      return &c->options[i]->info;
  return NULL;
}

void bb__option_choices(const bb_option_info *option, char *out, size_t cap) {
  if (!cap)
    return;
  out[0] = '\0';
  if (option && (option->type == BB_OPTION_WORD || option->type == BB_OPTION_WORDS))
    bb__choices(option_of(option), out, cap);
}

void bb_option_value_text(const bb_option_info *option, char *out, size_t cap) {
  if (!cap)
    return;
  out[0] = '\0';
  if (!option || option->type == BB_OPTION_FLAG)
    return;
  if (option->value_name)
    snprintf(out, cap, "%s", option->value_name);
  else
    bb__option_choices(option, out, cap);
}

int bb_option_bounds(const bb_option_info *option, double *min, double *max,
                     int *min_exclusive) {
  const bb__option *o = option ? option_of(option) : NULL;
  if (!o || !o->range)
    return 0;
  if (min)
    *min = o->range->min;
  if (max)
    *max = o->range->max;
  if (min_exclusive)
    *min_exclusive = o->range->min_exclusive;
  return 1;
}

void bb_option_range_text(const bb_option_info *option, char *out, size_t cap) {
  if (!cap)
    return;
  out[0] = '\0';
  if (!option)
    return;
  const bb__option *o = option_of(option);
  if (option->range_text)
    snprintf(out, cap, "%s", option->range_text);
  else if (o->range_words)
    o->range_words(out, cap);
  else if (o->range && bb__option_field(o) == BB__FIELD_ANGLES) {
    char r[32];
    bb__range_text(o->range, r, sizeof r);
    snprintf(out, cap, "EL %s", r);
  } else if (o->range)
    bb__range_text(o->range, out, cap);
  else if (option->type == BB_OPTION_WORDS)
    bb__choices(o, out, cap);
  for (char *bar = option->type == BB_OPTION_WORDS ? strchr(out, '|') : NULL; bar;
       bar = strchr(bar, '|'))
    *bar = ' ';
}

void bb_option_default_text(const bb_command_info *command, const bb_option_info *option,
                            char *out, size_t cap) {
  if (!cap)
    return;
  out[0] = '\0';
  if (!command || !option)
    return;
  if (option->default_text) {
    snprintf(out, cap, "%s", option->default_text);
    return;
  }
  if (option->type == BB_OPTION_FLAG || option->type == BB_OPTION_PATH)
    return;
  const bb__option *o = option_of(option);
  bb_command *c = NULL;
  if (bb_command_new(command->name, &c, NULL) != BB_OK)
    return;
  bb__text t = {0};
  if (o->print)
    o->print(c, o, &t);
  else
    bb__print_generic(c, o, &t);
  char *text = bb__text_take(&t);
  /* a string not set is no default */
  if (text)
    snprintf(out, cap, "%s", text);
  free(text);
  bb_command_free(c);
}

int bb__command_has_job(const bb_command_info *command) {
  return command && command_of(command)->job != NULL;
}
