/* render_common.c: the lighting options that `render` and `sheet` share. */
#include "common.h"
#include "render_common.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

const cli_option cli_render_opt_mode = {
    .id = CLI_RENDER_OPT_MODE,
    .long_name = "mode",
    .value_name = "ssbump|normal|ao|slope",
    .default_text = "ssbump",
    .help = "what is lit: the ssbump, the plain normal map, the normal map times ao, or "
            "flipcode's slope map through its 16x16 table"};
const cli_option cli_render_opt_light = {
    .id = CLI_RENDER_OPT_LIGHT,
    .long_name = "light",
    .value_name = "AZ,EL",
    .default_text = "135,45",
    .range_text = "EL 0..90",
    .help = "dynamic light, degrees: azimuth 0 = from the right, 90 = from the top "
            "(counter-clockwise on screen), elevation 90 = overhead"};
const cli_option cli_render_opt_light_color = {.id = CLI_RENDER_OPT_LIGHT_COLOR,
                                               .long_name = "light-color",
                                               .value_name = "R,G,B",
                                               .default_text = "1,1,1",
                                               .range_text = ">= 0",
                                               .help = "colour of the dynamic light"};
const cli_option cli_render_opt_lightmap = {
    .id = CLI_RENDER_OPT_LIGHTMAP,
    .long_name = "lightmap",
    .value_name = "basis|R,G,B,R,G,B,R,G,B",
    .default_text = "off",
    .range_text = ">= 0",
    .help = "static light: Source's three lightmap colours L0, L1, L2 (basis = red, "
            "green, blue); without --light, the only light"};
const cli_option cli_render_opt_specular = {
    .id = CLI_RENDER_OPT_SPECULAR,
    .long_name = "specular",
    .value_name = "EXPONENT",
    .default_text = "0 (off)",
    .range_text = "0..100000",
    .help = "Blinn-Phong highlight from the bent normal (ssbump) or N, viewer overhead"};
const cli_option cli_render_opt_specular_strength = {
    .id = CLI_RENDER_OPT_SPECULAR_STRENGTH,
    .long_name = "specular-strength",
    .value_name = "KS",
    .default_text = "1",
    .range_text = "0..1000",
    .help = "scale of the highlight (a material's specular intensity; 1 = the light's "
            "colour, which saturates readily at low light)"};
const cli_option cli_render_opt_output = {.id = CLI_RENDER_OPT_OUTPUT,
                                          .long_name = "output",
                                          .short_name = 'o',
                                          .value_name = "OUT",
                                          .default_text = "(required)",
                                          .help = "picture to write"};
const cli_option cli_render_opt_quiet = {.id = CLI_RENDER_OPT_QUIET,
                                         .long_name = "quiet",
                                         .short_name = 'q',
                                         .help = "no list of files written"};

/* Parses exactly `count` comma-separated finite numbers into out; a usage
 * error names the option. */
static int parse_numbers(const char *command, const char *option, const char *text,
                         int count, double *out) {
  const char *p = text;
  for (int i = 0; i < count; i++) {
    char *end = NULL;
    out[i] = strtod(p, &end);
    int last = i + 1 == count;
    if (end == p || !isfinite(out[i]) || (last ? *end != '\0' : *end != ','))
      return cli_usage_error(command, "%s needs %d comma-separated numbers (got '%s')",
                             option, count, text);
    p = end + 1;
  }
  return 0;
}

static int parse_color(const char *command, const char *option, const char *text,
                       const double *v, float *out) {
  for (int k = 0; k < 3; k++) {
    if (!(v[k] >= 0.0) || v[k] > 1e30)
      return cli_usage_error(command, "%s colours must be >= 0 (got '%s')", option, text);
    out[k] = (float)v[k];
  }
  return 0;
}

static int apply_light(const char *command, bb_render_options *o, const char *arg) {
  double v[2] = {0.0, 0.0};
  int rc = parse_numbers(command, "--light", arg, 2, v);
  if (rc)
    return rc;
  if (!(v[1] >= 0.0 && v[1] <= 90.0))
    return cli_usage_error(command, "--light elevation must be in 0..90 degrees (got %g)",
                           v[1]);
  o->light_azimuth = v[0];
  o->light_elevation = v[1];
  o->dynamic_light = 1;
  return 0;
}

static int apply_lightmap(const char *command, bb_render_options *o, const char *arg) {
  if (strcmp(arg, "basis") == 0) {
    for (int c = 0; c < 3; c++)
      for (int k = 0; k < 3; k++)
        o->lightmap[c][k] = c == k ? 1.0f : 0.0f;
  } else {
    double v[9] = {0.0};
    int rc = parse_numbers(command, "--lightmap", arg, 9, v);
    for (int c = 0; c < 3 && !rc; c++)
      rc = parse_color(command, "--lightmap", arg, v + 3 * c, o->lightmap[c]);
    if (rc)
      return rc;
  }
  o->static_light = 1;
  return 0;
}

int cli_render_apply_lighting(const char *command, bb_render_options *o, int *light_given,
                              const cli_option *opt, const char *arg) {
  double v[3] = {0.0, 0.0, 0.0};
  int rc;
  switch (opt->id) {
  case CLI_RENDER_OPT_MODE:
    if (bb_render_mode_parse(arg, &o->mode, NULL))
      return cli_usage_error(command, "--mode must be one of %s (got '%s')",
                             opt->value_name, arg);
    return 0;
  case CLI_RENDER_OPT_LIGHT:
    rc = apply_light(command, o, arg);
    if (!rc)
      *light_given = 1;
    return rc;
  case CLI_RENDER_OPT_LIGHT_COLOR:
    rc = parse_numbers(command, "--light-color", arg, 3, v);
    return rc ? rc : parse_color(command, "--light-color", arg, v, o->light_color);
  case CLI_RENDER_OPT_LIGHTMAP:
    rc = apply_lightmap(command, o, arg);
    if (!rc && !*light_given)
      o->dynamic_light = 0;
    return rc;
  case CLI_RENDER_OPT_SPECULAR:
    return cli_parse_double(command, "--specular", arg, 0.0, 0, 100000.0,
                            &o->specular_exponent);
  case CLI_RENDER_OPT_SPECULAR_STRENGTH:
    return cli_parse_double(command, "--specular-strength", arg, 0.0, 0, 1000.0,
                            &o->specular_strength);
  default:
    return -1;
  }
}

void cli_render_no_font_note(const char *command) {
  fprintf(stderr,
          "bumpbake %s: no font found for the labels (install fonts-dejavu-core, or set "
          "BUMPBAKE_FONT to a font file); drawn without labels\n",
          command);
}
