/* cli_slope.c: bake's --slope FILE (flipcode's one byte of slopes per texel)
 * and --lit AZ,EL (that map lit through the 16 x 16 table, as a preview). */
#include "slope.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

const cli_option cli_opt_slope = {
    .id = CLI_OPT_SLOPE,
    .long_name = "slope",
    .value_name = "FILE",
    .help = "write flipcode's slope map: 1 byte per texel, dx low nibble, dy high (8-bit "
            ".png .tga .tif)"};
const cli_option cli_opt_slope_lit = {
    .id = CLI_OPT_SLOPE_LIT,
    .long_name = "lit",
    .value_name = "AZ,EL",
    .range_text = "degrees, EL 0..90",
    .help = "also write the slope map lit through its 16x16 table as FILE_lit (AZ 0 = "
            "light from the right, 90 = from the top, as render's --light)"};

int cli_slope_owns(const cli_option *opt) {
  return opt->id == CLI_OPT_SLOPE || opt->id == CLI_OPT_SLOPE_LIT;
}

/* "AZ,EL" in degrees: two finite numbers, the elevation in 0..90. */
static int parse_light(const char *command, const char *arg, double *az, double *el) {
  char *end = NULL;
  errno = 0;
  *az = strtod(arg, &end);
  if (end == arg || *end != ',' || errno == ERANGE || !isfinite(*az))
    return cli_usage_error(command, "--lit needs AZ,EL in degrees (got '%s')", arg);
  const char *second = end + 1;
  *el = strtod(second, &end);
  if (end == second || *end != '\0' || errno == ERANGE || !isfinite(*el))
    return cli_usage_error(command, "--lit needs AZ,EL in degrees (got '%s')", arg);
  if (*el < 0.0 || *el > 90.0)
    return cli_usage_error(command, "--lit elevation must be in 0..90 (got %s)", second);
  return 0;
}

int cli_slope_option(const char *command, cli_slope_args *a, const cli_option *opt,
                     const char *arg) {
  if (opt->id == CLI_OPT_SLOPE) {
    a->path = arg;
    return 0;
  }
  a->lit = 1;
  return parse_light(command, arg, &a->azimuth, &a->elevation);
}

/* path with "_lit" before the extension of its file name (or at its end). */
static char *lit_path_of(const char *path) {
  const char *slash = strrchr(path, '/');
  const char *dot = strrchr(slash ? slash + 1 : path, '.');
  size_t stem = dot ? (size_t)(dot - path) : strlen(path);
  char *out = malloc(strlen(path) + sizeof "_lit");
  if (out) {
    memcpy(out, path, stem);
    strcpy(out + stem, "_lit");
    strcat(out, path + stem);
  }
  return out;
}

int cli_slope_check(const char *command, cli_slope_args *a, const char *input,
                    bb_depth depth) {
  if (!a->path) {
    if (a->lit)
      return cli_usage_error(command,
                             "--lit previews the slope map: give --slope FILE too");
    return 0;
  }
  if (!bb_path_supports_depth(a->path, BB_DEPTH_8))
    return cli_usage_error(command,
                           "%s: the slope map is one byte per texel: use .png, .tga "
                           "or .tif",
                           a->path);
  int rc = cli_check_output(command, input, a->path, BB_DEPTH_8);
  if (rc || !a->lit)
    return rc;
  a->lit_path = lit_path_of(a->path);
  if (!a->lit_path) {
    cli_file_error(a->path, "out of memory");
    return BB_EXIT_FAILURE;
  }
  return cli_check_output(command, input, a->lit_path, depth);
}

void cli_slope_settings(const cli_settings *run_settings, int eight_bit,
                        cli_settings *out) {
  *out = *run_settings;
  out->mips = 0;
  if (eight_bit)
    out->depth = BB_DEPTH_8;
}

int cli_slope_make(const cli_run *run, const cli_slope_args *a, const bb_image *filtered,
                   bb_image *slope, bb_image *lit) {
  memset(slope, 0, sizeof *slope);
  memset(lit, 0, sizeof *lit);
  if (!a->path)
    return 0;
  const bb_bake_options *o = &run->settings->bake;
  bb_error err = {{0}};
  bb_status st = bb_slope_map(filtered, o->height_scale, o->smooth.addressing, slope, &err);
  int rc = cli_status_exit(a->path, st, &err);
  if (!rc && a->lit) {
    double light[3];
    float table[256];
    bb_light_direction(a->azimuth, a->elevation, light);
    bb_slope_table(light, table);
    rc = cli_status_exit(a->lit_path, bb_slope_light(slope, table, lit, &err), &err);
  }
  if (rc) {
    bb_image_free(slope);
    bb_image_free(lit);
  }
  return rc;
}

void cli_slope_free(cli_slope_args *a) {
  free(a->lit_path);
  a->lit_path = NULL;
}
