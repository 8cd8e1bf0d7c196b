/* cli_maps.h: what the map commands (normal2ssbump, ssbump2normal, combine,
 * program) share: their option ids and rows, reading a map, choosing the
 * output depth and writing with provenance. Nothing here is library. */
#ifndef BB_CLI_MAPS_H
#define BB_CLI_MAPS_H

#include "common.h"

/* Option ids of the map commands, far above cli_opt_id's so the two lists
 * can grow apart. */
enum cli_maps_opt_id {
  CLI_OPT_MAP_KIND = 1024, /* --kind ssbump|weights|ao|normal */
  CLI_OPT_MAP_MIX,         /* --mix T */
  CLI_OPT_MAP_MASK,        /* --mask FILE */
  CLI_OPT_MAP_DETAIL,      /* --detail */
  CLI_OPT_MAP_BASE_DIR,    /* --base DIR */
  CLI_OPT_SLOPE,           /* bake --slope FILE */
  CLI_OPT_SLOPE_LIT,       /* bake --lit AZ,EL */
  CLI_OPT_MAP_BRIGHTNESS   /* combine --brightness FILE */
};

/* --depth for commands whose default follows their input. */
extern const cli_option cli_maps_opt_depth;

/* Reads a map with cli_read_image; prints the error and returns
 * BB_EXIT_FAILURE on failure. */
int cli_maps_read(const char *path, bb_image *img, bb_image_info *info);

/* The depth to write out_path with: the requested one, else the input's
 * (16-bit, half or float) when out_path's format holds it, else the
 * format's default. */
bb_depth cli_maps_output_depth(bb_depth requested, const bb_image_info *input,
                               const char *out_path);

/* The file name part of path (after the last '/'). */
const char *cli_maps_file_name(const char *path);

/* Writes img with provenance (command line, input name and the hash of the
 * decoded input, kind; no bake parameters: the command line holds every
 * option). input_name (a file name, or a program's text) and input may be
 * NULL. mips: write a mip-mapped file (cli_write_image). Prints the error
 * and returns BB_EXIT_FAILURE on failure. */
int cli_maps_write(const cli_run *run, const char *input_name, const bb_image *input,
                   const char *kind, const char *path, const bb_image *img,
                   bb_range range, bb_depth depth, int mips);

#endif /* BB_CLI_MAPS_H */
