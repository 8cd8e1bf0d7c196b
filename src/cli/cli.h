/* cli.h: entry points of the bumpbake subcommands (the CLI is a client of
 * bumpbake.h; nothing here is part of the library). */
#ifndef BB_CLI_H
#define BB_CLI_H

/* Exit codes of every subcommand except compare (which follows idiff). */
enum { BB_EXIT_OK = 0, BB_EXIT_FAILURE = 1, BB_EXIT_USAGE = 2 };

/* Each takes the arguments after the program name, argv[0] being the
 * subcommand's name, and returns the process exit code. */
int bb_cli_normal(int argc, char **argv);
int bb_cli_bake(int argc, char **argv);
int bb_cli_height2ssbump(int argc, char **argv);
int bb_cli_compare(int argc, char **argv);
int bb_cli_info(int argc, char **argv);
int bb_cli_renderbumpflat(int argc, char **argv);
int bb_cli_render(int argc, char **argv);
int bb_cli_sheet(int argc, char **argv);
int bb_cli_normal2ssbump(int argc, char **argv);
int bb_cli_ssbump2normal(int argc, char **argv);
int bb_cli_combine(int argc, char **argv);
int bb_cli_program(int argc, char **argv);
int bb_cli_serve(int argc, char **argv);

#endif /* BB_CLI_H */
