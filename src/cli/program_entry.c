/* program_entry.c: what the bumpbake program does with its arguments:
 * --help and --version, and every command through the generic driver
 * (parse.c). main.c calls it with serve's run; the test binary, which links
 * the CLI without serve, calls it in a forked child (tests/cli_harness.h). */
#include "cli.h"
#include "common.h"

#include <stdio.h>
#include <string.h>

int cli_main(int argc, char **argv, int (*serve)(const cli_run *r)) {
  cli_install_signal_handlers();
  if (argc < 2) {
    cli_print_usage(stderr);
    return BB_EXIT_USAGE;
  }
  const char *name = argv[1];
  if (!strcmp(name, "--help") || !strcmp(name, "-h")) {
    cli_print_usage(stdout);
    return BB_EXIT_OK;
  }
  if (!strcmp(name, "--version")) {
    printf("bumpbake %s\n", BB_VERSION_STRING);
    return BB_EXIT_OK;
  }
  if (name[0] == '-') {
    char line[512];
    snprintf(line, sizeof line, "unknown option '%s' (see bumpbake --help)", name);
    cli_error_line(line);
    return BB_EXIT_USAGE;
  }
  if (serve && !strcmp(name, "serve")) /* its server is the program's alone */
    return bb_cli_command_with(argc - 1, argv + 1, serve);
  return bb_cli_command(argc - 1, argv + 1);
}
