/* help.c: `bumpbake --help` and `bumpbake COMMAND --help`, printed from the
 * library's descriptions of the commands and their options (so the help,
 * the reference pages made from it and the parser cannot disagree). */
#include "cli.h"

#include <stdio.h>
#include <string.h>

void cli_print_usage(FILE *f) {
  fprintf(f, "usage: bumpbake COMMAND [OPTIONS] ...\n"
             "Bakes normal maps, self-shadowed bump maps (Valve ssbump) and ambient\n"
             "occlusion from height maps.\n\ncommands:\n");
  const bb_command_info *c;
  for (int i = 0; (c = bb_command_info_get(i)) != NULL; i++)
    fprintf(f, "  %-14s %s\n", c->name, c->summary);
  fprintf(f, "\n'bumpbake COMMAND --help' lists a command's options.\n"
             "  --help       print this help\n"
             "  --version    print the version\n"
             "exit codes: 0 ok, 1 failure (file or image), 2 usage error\n");
}

void cli_print_help(const bb_command_info *command) {
  printf("usage: bumpbake %s %s\n%s\n\noptions:\n", command->name, command->synopsis,
         command->description);
  for (int i = 0; i < command->option_count; i++) {
    const bb_option_info *o = bb_command_option(command, i);
    char flags[96], value[96], dflt[160], range[160];
    int n = 0;
    if (o->short_name)
      n += snprintf(flags + n, sizeof flags - (size_t)n, "-%c", o->short_name);
    if (o->flags & BB_OPTION_SINGLE_DASH)
      n += snprintf(flags + n, sizeof flags - (size_t)n, "%s-%s", n ? ", " : "", o->name);
    n += snprintf(flags + n, sizeof flags - (size_t)n, "%s--%s", n ? ", " : "", o->name);
    bb_option_value_text(o, value, sizeof value);
    if (value[0])
      snprintf(flags + n, sizeof flags - (size_t)n, " %s", value);
    bb_option_default_text(command, o, dflt, sizeof dflt);
    bb_option_range_text(o, range, sizeof range);
    /* At least two spaces end the flags, also when they fill or overflow
     * their column: tools/gen_docs.py splits the line there, and an option
     * and its default stay on one line for whoever greps them. */
    if (strlen(flags) >= 36)
      printf("  %s  %s", flags, o->help);
    else
      printf("  %-36s %s", flags, o->help);
    if (dflt[0])
      printf("; default %s", dflt);
    if (range[0])
      printf("; range %s", range);
    putchar('\n');
  }
}
