/* cli_maps.c: reading, depth choice and writing shared by the map commands
 * (normal2ssbump, ssbump2normal, combine, program). */
#include "maps.h"

#include <stdlib.h>
#include <string.h>

const cli_option cli_maps_opt_depth = {
    .id = CLI_OPT_DEPTH,
    .long_name = "depth",
    .value_name = "8|16|half|float",
    .default_text =
        "the input's when the format holds it, else 8 (png/tga/tif) or float (exr)",
    .help = "sample depth of the output"};

int cli_maps_read(const char *path, bb_image *img, bb_image_info *info) {
  bb_error err = {{0}};
  bb_status st = cli_read_image(path, img, info, &err);
  return cli_status_exit(path, st, &err);
}

bb_depth cli_maps_output_depth(bb_depth requested, const bb_image_info *input,
                               const char *out_path) {
  if (requested != BB_DEPTH_DEFAULT || !input)
    return requested;
  bb_depth d = BB_DEPTH_DEFAULT;
  if (input->is_float)
    d = input->bits_per_sample == 16 ? BB_DEPTH_HALF : BB_DEPTH_FLOAT;
  else if (input->bits_per_sample == 16)
    d = BB_DEPTH_16;
  return bb_path_supports_depth(out_path, d) ? d : BB_DEPTH_DEFAULT;
}

const char *cli_maps_file_name(const char *path) {
  const char *slash = strrchr(path, '/');
  return slash ? slash + 1 : path;
}

int cli_maps_write(const cli_run *run, const char *input_name, const bb_image *input,
                   const char *kind, const char *path, const bb_image *img,
                   bb_range range, bb_depth depth, int mips) {
  bb_provenance p = {
      run->command_line, input_name, input ? bb_image_hash(input) : 0, kind, NULL,
      BB_CHANNEL_AUTO,   NULL, run->input_file_hash};
  char *description = bb_provenance_format(&p);
  if (!description) {
    cli_file_error(path, "out of memory");
    return BB_EXIT_FAILURE;
  }
  bb_write_options wo = {depth, range, description};
  bb_error err = {{0}};
  bb_status st = cli_write_image(path, img, &wo, mips, &err);
  free(description);
  return cli_status_exit(path, st, &err);
}
