/* derive.c: a command made from another one's settings (bb_command_derive):
 * serve's page holds a `serve` command and bakes and writes through the
 * `bake` command its settings are. */
#include "cmd/cmd_internal.h"

#include <stdlib.h>
#include <string.h>

/* 1 for an option naming a file the command writes (-o PREFIX, a map's
 * file): the derived command writes what its caller names. */
static int names_an_output(const bb__option *o) {
  return o->repeats || !strcmp(o->info.name, "output");
}

/* Option i of from onto to, when to takes it, it names no output and from
 * holds it at another value than fresh (a new command of to's name) does,
 * by their text: every value that reaches the outputs is then named (the
 * provenance records --rays also under --slices, which override it), so
 * that the derived command's text, run again, makes the same bytes.
 * Marked derived: the check drops it where it does nothing. */
static bb_status copy_option(const bb_command *from, int i, const bb_command *fresh,
                             bb_command *to, bb_error *err) {
  const bb__option *o = from->def->options[i];
  const int j = bb__option_find(to->def, o->info.name);
  if (j < 0 || names_an_output(to->def->options[j]))
    return BB_OK;
  bb__text value = {0}, unset = {0};
  bb__command_value_text(from, i, &value);
  bb__command_value_text(fresh, j, &unset);
  const char *v = value.data ? value.data : "", *u = unset.data ? unset.data : "";
  bb_status st = BB_OK;
  if (value.failed || unset.failed)
    st = bb__fail(err, BB_ERR_MEMORY, "out of memory");
  else if (strcmp(v, u) != 0 && (st = bb_command_set(to, o->info.name, v, err)) == BB_OK)
    to->derived[j] = 1;
  bb__text_free(&value);
  bb__text_free(&unset);
  return st;
}

bb_status bb_command_derive(const bb_command *from, const char *name, bb_command **out,
                            bb_error *err) {
  if (!out)
    return bb__fail(err, BB_ERR_ARGUMENT, "command derive: bad arguments");
  *out = NULL;
  if (!from || !name)
    return bb__fail(err, BB_ERR_ARGUMENT, "command derive: bad arguments");
  bb_command *to = NULL, *fresh = NULL;
  bb_status st = bb_command_new(name, &to, err);
  if (st == BB_OK)
    st = bb_command_new(name, &fresh, err);
  for (int i = 0; st == BB_OK && i < from->input_count; i++)
    st = bb_command_add_input(to, from->inputs[i], err);
  for (int i = 0; st == BB_OK && from->def->options[i]; i++)
    if (from->given[i])
      st = copy_option(from, i, fresh, to, err);
  bb_command_free(fresh);
  if (st != BB_OK) {
    bb_command_free(to);
    return st;
  }
  *out = to;
  return BB_OK;
}
