/* maps.h: what the map commands (normal2ssbump, ssbump2normal, combine,
 * program) share: their option ids and rows, and the library's output
 * checks, reads and writes as those commands call them. Nothing here is
 * library. */
#ifndef BB_CLI_MAPS_H
#define BB_CLI_MAPS_H

#include "bumpbake.h"
#include "options.h"

/* Option ids of the map commands, far above cli_opt_id's so the two lists
 * can grow apart. */
enum cli_maps_opt_id {
  CLI_OPT_MAP_KIND = 1024, /* --kind ssbump|weights|ao|normal */
  CLI_OPT_MAP_MIX,         /* --mix T */
  CLI_OPT_MAP_MASK,        /* --mask FILE */
  CLI_OPT_MAP_DETAIL,      /* --detail */
  CLI_OPT_MAP_BASE_DIR,    /* --base DIR */
  CLI_OPT_MAP_ALLOW_OUTSIDE, /* --allow-outside-base */
  CLI_OPT_MAP_BRIGHTNESS     /* combine --brightness FILE */
};

/* --depth for commands whose default follows their input. */
extern const cli_option cli_maps_opt_depth;

/* The command line a map command records in its outputs' provenance. */
typedef struct cli_run {
  char *command_line; /* "bumpbake " + argv, malloc'd */
} cli_run;

/* Records the command line; call before parsing (getopt permutes argv).
 * BB_EXIT_FAILURE when out of memory (printed). */
int cli_run_init(cli_run *run, int argc, char **argv);
void cli_run_free(cli_run *run);

/* The output checked before any work against one file it reads (input may
 * be "" when there is none yet), with --depth and --mips (bb_outputs_check):
 * 0, BB_EXIT_USAGE or BB_EXIT_FAILURE after printing. */
int cli_maps_check_output(const char *command, const char *input, const char *output,
                          const cli_settings *s);

/* Reads a map with bb_image_read; prints the error and returns
 * BB_EXIT_FAILURE on failure. */
int cli_maps_read(const char *path, bb_image *img, bb_image_info *info);

/* A map read as Half-Life 2's basis (bb_basis_map_check): 0, or
 * BB_EXIT_FAILURE after "bumpbake: PATH: reason". */
int cli_maps_check_hl2(const char *path, const bb_image *img, const bb_image_info *info);

/* The depth to write out_path with: the requested one, else the input's
 * where the format holds it (bb_depth_like_input). */
bb_depth cli_maps_output_depth(bb_depth requested, const bb_image_info *input,
                               const char *out_path);

/* The file name part of path (after the last '/'). */
const char *cli_maps_file_name(const char *path);

/* Writes img with provenance (command line, input name and the hash of the
 * decoded input, kind; no bake parameters: the command line holds every
 * option). input_name (a file name, or a program's text) and input may be
 * NULL. mips: the mip chain (bb_outputs_write); texture: a .vtf or .dds
 * output's settings. Prints the error and returns BB_EXIT_FAILURE on
 * failure. */
int cli_maps_write(const cli_run *run, const char *input_name, const bb_image *input,
                   const char *kind, const char *path, const bb_image *img,
                   bb_range range, bb_depth depth, int mips,
                   const bb_texture_options *texture);

#endif /* BB_CLI_MAPS_H */
