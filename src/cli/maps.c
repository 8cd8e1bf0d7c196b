/* maps.c: the library's output checks, reads and writes as the map commands
 * (normal2ssbump, ssbump2normal, combine, program) call them. */
#include "maps.h"
#include "cli.h"
#include "common.h"

#include <stdlib.h>
#include <string.h>

const cli_option cli_maps_opt_depth = {
    .id = CLI_OPT_DEPTH,
    .long_name = "depth",
    .value_name = "8|16|half|float",
    .default_text =
        "the input's when the format holds it, else 8 (png/tga/tif) or float (exr)",
    .help = "sample depth of the output"};

int cli_run_init(cli_run *run, int argc, char **argv) {
  run->command_line = cli_command_line(argc, argv);
  return run->command_line ? 0 : BB_EXIT_FAILURE;
}

void cli_run_free(cli_run *run) {
  free(run->command_line);
  run->command_line = NULL;
}

int cli_maps_check_output(const char *command, const char *input, const char *output,
                          const cli_settings *s) {
  const bb_output_spec spec = {output, "output", 0, s->depth, s->mips, 0, 0, 0, BB_RANGE_UNIT,
                               &s->texture};
  bb_error err = {{0}};
  bb_status st = bb_outputs_check(&spec, 1, &input, input && *input ? 1 : 0, &err);
  return st == BB_OK ? 0 : cli_library_error(command, st, &err);
}

int cli_maps_read(const char *path, bb_image *img, bb_image_info *info) {
  bb_error err = {{0}};
  bb_status st = bb_image_read(path, img, info, &err);
  return cli_status_exit(path, st, &err);
}

int cli_maps_check_hl2(const char *path, const bb_image *img, const bb_image_info *info) {
  bb_error err = {{0}};
  return cli_status_exit(path, bb_basis_map_check(img, info ? info->description : NULL, &err),
                         &err);
}

bb_depth cli_maps_output_depth(bb_depth requested, const bb_image_info *input,
                               const char *out_path) {
  if (requested != BB_DEPTH_DEFAULT || !input)
    return requested;
  return bb_depth_like_input(input->bits_per_sample, input->is_float, out_path);
}

const char *cli_maps_file_name(const char *path) {
  const char *slash = strrchr(path, '/');
  return slash ? slash + 1 : path;
}

int cli_maps_write(const cli_run *run, const char *input_name, const bb_image *input,
                   const char *kind, const char *path, const bb_image *img,
                   bb_range range, bb_depth depth, int mips,
                   const bb_texture_options *texture) {
  bb_provenance p = {run->command_line,
                     input_name,
                     input ? bb_image_hash(input) : 0,
                     kind,
                     NULL,
                     BB_CHANNEL_AUTO,
                     NULL,
                     0,
                     NULL};
  char *description = bb_provenance_format(&p);
  if (!description) {
    cli_file_error(path, "out of memory");
    return BB_EXIT_FAILURE;
  }
  const bb_output_file file = {path, kind, img, range, depth, mips, description, NULL, 0,
                               texture};
  bb_error err = {{0}};
  bb_status st = bb_outputs_write(&file, 1, 1, &err);
  free(description);
  return cli_status_exit(path, st, &err);
}
