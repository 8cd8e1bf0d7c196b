/* cli.h: the bumpbake command line, a client of bumpbake.h: a generic
 * driver over the library's descriptions of the commands (parse.c, help.c)
 * and, per command, what it prints (nothing here is part of the library). */
#ifndef BB_CLI_H
#define BB_CLI_H

#include "bumpbake.h"

#include <stddef.h>
#include <stdio.h>

/* Exit codes of every subcommand except compare and check (which follow
 * idiff). */
enum { BB_EXIT_OK = 0, BB_EXIT_FAILURE = 1, BB_EXIT_USAGE = 2 };

/* Runs the command named argv[0] with the arguments after it: parsed
 * against its description, checked by the library, then run and printed.
 * Returns the process exit code. */
int bb_cli_command(int argc, char **argv);

/* One command about to run: checked by the library. */
typedef struct cli_run cli_run;

/* The program: `bumpbake ARGS...` (argv[0] the program's name) from its
 * start to its exit code: --help, --version, each command. serve is
 * `bumpbake serve`'s run: main.c passes serve.c's; the test binary, which
 * links no serve, passes NULL and runs `serve` through the program. */
int cli_main(int argc, char **argv, int (*serve)(const cli_run *r));

/* bb_cli_command with the run of run (serve's, which the test binary does
 * not link), else the command's own. */
int bb_cli_command_with(int argc, char **argv, int (*run)(const cli_run *r));

struct cli_run {
  bb_command *command;
  int quiet, json;      /* --quiet, --json (cli_flag) */
  const char *record;   /* the command line its outputs record: the words as typed,
                           less those of options that do not change the output */
};

/* 1 when the flag name of r's command is on (given); 0 when off or not
 * an option of the command. */
int cli_flag(const cli_run *r, const char *name);
/* The value of option name of r's command, as bb_command_value spells it,
 * in out (capacity cap); NULL when it has none (a file not given) or does
 * not fit. */
const char *cli_text(const cli_run *r, const char *name, char *out, size_t cap);

/* Each command's run: what it does with the library and what it prints;
 * returns the exit code. */
int cli_run_job(const cli_run *r); /* bake, normal, height2ssbump: through the job */
int cli_run_render(const cli_run *r);
int cli_run_sheet(const cli_run *r);
int cli_run_normal2ssbump(const cli_run *r);
int cli_run_ssbump2normal(const cli_run *r);
int cli_run_combine(const cli_run *r);
int cli_run_program(const cli_run *r);
int cli_run_compare(const cli_run *r);
int cli_run_check(const cli_run *r);
int cli_run_info(const cli_run *r);
int cli_run_renderbumpflat(const cli_run *r);
int cli_run_serve(const cli_run *r); /* src/serve/serve.c: main.c links it in */

/* `bumpbake --help` and `bumpbake COMMAND --help` (help.c), from the
 * descriptions. */
void cli_print_usage(FILE *f);
void cli_print_help(const bb_command_info *command);

#endif /* BB_CLI_H */
