/* render_common.h: what `render` and `sheet` share: the lighting options
 * (--light, --light-color, --lightmap, --specular, --mode) and the note
 * printed when labels could not be drawn. Nothing here is part of the
 * library. */
#ifndef BB_CLI_RENDER_COMMON_H
#define BB_CLI_RENDER_COMMON_H

#include "bumpbake.h"
#include "options.h"

/* Option ids of render and sheet, after cli_common's (which stay below 1000). */
enum {
  CLI_RENDER_OPT_MODE = 1000,
  CLI_RENDER_OPT_LIGHT,
  CLI_RENDER_OPT_LIGHT_COLOR,
  CLI_RENDER_OPT_LIGHTMAP,
  CLI_RENDER_OPT_SPECULAR,
  CLI_RENDER_OPT_SPECULAR_STRENGTH,
  CLI_RENDER_OPT_ALBEDO,
  CLI_RENDER_OPT_ALBEDO_MODE,
  CLI_RENDER_OPT_TILE,
  CLI_RENDER_OPT_CROP,
  CLI_RENDER_OPT_ORBIT,
  CLI_RENDER_OPT_COMPARE,
  CLI_RENDER_OPT_IN_NORMAL,
  CLI_RENDER_OPT_IN_SSBUMP,
  CLI_RENDER_OPT_IN_AO,
  CLI_RENDER_OPT_IN_BENT,
  CLI_RENDER_OPT_IN_SLOPE, /* the IN_ ids stay consecutive: they index map paths */
  CLI_RENDER_OPT_PANEL_SIZE,
  CLI_RENDER_OPT_OUTPUT,
  CLI_RENDER_OPT_QUIET,
  CLI_RENDER_OPT_VIEW,
  CLI_RENDER_OPT_RELIEF
};

/* Rows of the lighting options, shared by both commands' tables. */
extern const cli_option cli_render_opt_mode, cli_render_opt_light,
    cli_render_opt_light_color, cli_render_opt_lightmap, cli_render_opt_specular,
    cli_render_opt_specular_strength,
    cli_render_opt_output, cli_render_opt_quiet;

/* Applies a lighting option (mode, light, light colour, lightmap, specular)
 * to o. Returns 0 when applied, BB_EXIT_USAGE after a usage error, and -1
 * when opt is not a lighting option (the caller handles it). A --lightmap
 * turns the static light on, and the dynamic light off unless --light was
 * given (in either order): *light_given tracks that. */
int cli_render_apply_lighting(const char *command, bb_render_options *o, int *light_given,
                              const cli_option *opt, const char *arg);

/* The note for a picture whose labels could not be drawn. */
void cli_render_no_font_note(const char *command);

#endif /* BB_CLI_RENDER_COMMON_H */
