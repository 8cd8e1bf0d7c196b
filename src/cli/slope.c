/* slope.c: bake's --slope FILE (flipcode's one byte of slopes per texel)
 * and --lit AZ,EL (that map lit through the 16 x 16 table, as a preview). */
#include "common.h"
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
