/* main.c: the bumpbake program (program_entry.c), with `bumpbake serve`'s
 * server, which only the program links. */
#include "cli.h"

int main(int argc, char **argv) { return cli_main(argc, argv, cli_run_serve); }
