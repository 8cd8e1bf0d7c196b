/* cli_slope.h: bake's --slope FILE and --lit AZ,EL (flipcode's slope map
 * and its lit preview), kept apart from cli_bake.c. */
#ifndef BB_CLI_SLOPE_H
#define BB_CLI_SLOPE_H

#include "maps.h"

typedef struct cli_slope_args {
  const char *path; /* --slope FILE, or NULL */
  int lit;          /* --lit given */
  double azimuth, elevation;
  char *lit_path; /* malloc'd FILE with "_lit" before its extension */
} cli_slope_args;

extern const cli_option cli_opt_slope, cli_opt_slope_lit;

/* 1 when opt is one of the rows above. */
int cli_slope_owns(const cli_option *opt);

/* Applies --slope or --lit; 0, or BB_EXIT_USAGE after a usage error. */
int cli_slope_option(const char *command, cli_slope_args *a, const cli_option *opt,
                     const char *arg);

/* Checks the paths before any work: --lit needs --slope, the slope map is
 * 8-bit (png, tga, tif), the preview path is made and checked. 0 or the exit
 * code after printing the error. */
int cli_slope_check(const char *command, cli_slope_args *a, const char *input,
                    bb_depth depth);

/* Makes the slope map of the smoothed height into *slope and, with --lit,
 * its preview into *lit (zeroed otherwise); nothing when --slope was not
 * given. 0, or BB_EXIT_FAILURE after printing the error. bake writes them
 * with its other outputs, all or none (cli_commit_outputs). */
int cli_slope_make(const cli_run *run, const cli_slope_args *a, const bb_image *filtered,
                   bb_image *slope, bb_image *lit);

/* The settings the slope files are written with: no mip levels (an average
 * of slope bytes means nothing, and the preview is a picture), and with
 * eight_bit (the map itself) 8 bits whatever --depth says: its bytes are the
 * map. */
void cli_slope_settings(const cli_settings *run_settings, int eight_bit, cli_settings *out);

void cli_slope_free(cli_slope_args *a);

#endif /* BB_CLI_SLOPE_H */
