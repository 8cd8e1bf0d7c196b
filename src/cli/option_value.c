/* option_value.c: what a command's run reads of its checked options, by
 * name through the library (bb_command_value): a flag, or a value the
 * command line gave. */
#include "cli.h"

#include <string.h>

int cli_flag(const cli_run *r, const char *name) {
  char text[2];
  return bb_command_value(r->command, name, text, sizeof text, NULL) == BB_OK &&
         !strcmp(text, "1");
}

const char *cli_text(const cli_run *r, const char *name, char *out, size_t cap) {
  if (bb_command_value(r->command, name, out, cap, NULL) != BB_OK || !out[0])
    return NULL;
  return out;
}
