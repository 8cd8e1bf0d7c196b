/* slope.h: bake's --slope FILE and --lit AZ,EL (flipcode's slope map and
 * its lit preview), parsed apart from bake.c; the library makes and writes
 * them (bb_job_options). */
#ifndef BB_CLI_SLOPE_H
#define BB_CLI_SLOPE_H

#include "options.h"

typedef struct cli_slope_args {
  const char *path; /* --slope FILE, or NULL */
  int lit;          /* --lit given */
  double azimuth, elevation;
} cli_slope_args;

extern const cli_option cli_opt_slope, cli_opt_slope_lit;

/* 1 when opt is one of the rows above. */
int cli_slope_owns(const cli_option *opt);

/* Applies --slope or --lit; 0, or BB_EXIT_USAGE after a usage error. */
int cli_slope_option(const char *command, cli_slope_args *a, const cli_option *opt,
                     const char *arg);

#endif /* BB_CLI_SLOPE_H */
