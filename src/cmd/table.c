/* table.c: the commands in the order `bumpbake --help` lists them, and
 * finding one, or an option, by a name mistyped ("did you mean"). */
#include "cmd/cmd_internal.h"

#include <string.h>

const bb__command *const bb__commands[] = {
    &bb__command_normal, &bb__command_bake, &bb__command_height2ssbump,
    &bb__command_compare, &bb__command_check, &bb__command_info, &bb__command_renderbumpflat,
    &bb__command_render, &bb__command_sheet, &bb__command_normal2ssbump,
    &bb__command_ssbump2normal, &bb__command_combine, &bb__command_program,
    &bb__command_serve,
};
const int bb__command_total = (int)(sizeof bb__commands / sizeof bb__commands[0]);

/* A public description is the first member of the library's. */
static const bb__command *command_of(const bb_command_info *info) {
  return (const bb__command *)(const void *)info;
}

/* Edit distance of a[0..na) and b, '_' taken as '-', at most 63 characters
 * each (else "far"). */
static size_t edit_distance(const char *a, size_t na, const char *b) {
  const size_t nb = strlen(b);
  size_t row[64];
  if (na > 63 || nb > 63)
    return 99;
  for (size_t j = 0; j <= nb; j++)
    row[j] = j;
  for (size_t i = 1; i <= na; i++) {
    size_t diagonal = row[0];
    row[0] = i;
    const char ai = a[i - 1] == '_' ? '-' : a[i - 1];
    for (size_t j = 1; j <= nb; j++) {
      const size_t above = row[j];
      size_t best = diagonal + (ai != b[j - 1]);
      if (above + 1 < best)
        best = above + 1;
      if (row[j - 1] + 1 < best)
        best = row[j - 1] + 1;
      row[j] = best;
      diagonal = above;
    }
  }
  return row[nb];
}

const bb_command_info *bb__command_info_nearest(const char *name) {
  const bb_command_info *near = NULL;
  size_t best = 3;
  for (int i = 0; name && i < bb__command_total; i++) {
    const size_t d = edit_distance(name, strlen(name), bb__commands[i]->info.name);
    if (d < best)
      best = d, near = &bb__commands[i]->info;
  }
  return near;
}

const bb_option_info *bb_option_nearest(const bb_command_info *command, const char *name,
                                        size_t length) {
  if (!command || !name)
    return NULL;
  const bb__command *c = command_of(command);
  const size_t n = length ? length : strlen(name);
  const bb_option_info *near = NULL;
  size_t best = 3;
  for (int i = 0; c->options[i]; i++) {
    const size_t d = edit_distance(name, n, c->options[i]->info.name);
    if (d < best)
      best = d, near = &c->options[i]->info;
  }
  return near;
}

