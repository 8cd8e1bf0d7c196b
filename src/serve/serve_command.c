/* serve_command.c: the `bumpbake bake` command of the options now, which
 * serve plans its bakes and writes through (bb_command_plan), and the line
 * its files record and the page shows. */
#include "serve.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

bb_status serve_bake_command(const serve_state *s, bb_command **out, char **line,
                             bb_error *err) {
  *out = NULL;
  *line = NULL;
  bb_command *bake = NULL;
  bb_status st = bb_command_derive(s->command, "bake", &bake, err);
  for (int k = 0; st == BB_OK && k < BB_MAP_BAKED_COUNT; k++)
    if (s->write_files[k])
      st = bb_command_set(bake, bb_map_kind_get((bb_map_kind)k)->name, s->write_files[k], err);
  if (st == BB_OK)
    st = bb_command_check(bake, err);
  char *spelled = st == BB_OK ? bb_command_text(bake, NULL, BB_OPTION_RECORDED) : NULL;
  if (st == BB_OK && !spelled) {
    st = BB_ERR_MEMORY;
    snprintf(err->message, sizeof err->message, "out of memory");
  }
  if (st != BB_OK) {
    bb_command_free(bake);
    return st;
  }
  *out = bake;
  *line = spelled;
  return BB_OK;
}
