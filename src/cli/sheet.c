/* sheet.c: `bumpbake sheet`, one labelled contact sheet of every map of a
 * bake and one lit render. */
#include "cli.h"
#include "common.h"
#include "options.h"
#include "progress.h"
#include "render_common.h"

#include <stdlib.h>
#include <string.h>

static const cli_option opt_panel_size = {.id = CLI_RENDER_OPT_PANEL_SIZE,
                                          .long_name = "panel-size",
                                          .value_name = "N",
                                          .default_text = "256",
                                          .range_text = "16..4096",
                                          .help = "width of each panel in pixels"};

static const cli_option *const sheet_options[] = {
    &cli_opt_scale,
    &cli_opt_rays,
    &cli_opt_filter_radius,
    &cli_opt_filter_threshold,
    &cli_opt_bias,
    &cli_opt_power,
    &cli_opt_normal_filter,
    &cli_opt_threads,
    &cli_opt_clamp,
    &cli_opt_channel,
    &cli_render_opt_mode,
    &cli_render_opt_light,
    &cli_render_opt_light_color,
    &cli_render_opt_lightmap,
    &cli_render_opt_specular,
    &cli_render_opt_specular_strength,
    &opt_panel_size,
    &cli_render_opt_output,
    &cli_opt_depth,
    &cli_render_opt_quiet,
    &cli_opt_help,
};

static const cli_command sheet_command = {
    "sheet",
    "HEIGHT --scale S -o OUT [OPTIONS]",
    "Bakes HEIGHT with bake's options and writes one labelled contact sheet: height,\n"
    "filtered height, normal, weights, ssbump, ao, bent normal and one lit render\n"
    "(--mode and the lighting options choose it).",
    sheet_options,
    (int)(sizeof sheet_options / sizeof sheet_options[0]),
    cli_settings_init,
};

typedef struct sheet_args {
  cli_settings settings;
  bb_sheet_options sheet;
  int light_given;
  const char *output;
  int quiet;
} sheet_args;

static int sheet_option(void *ctx, const cli_option *opt, const char *arg) {
  sheet_args *a = ctx;
  const char *cmd = sheet_command.name;
  int rc = cli_render_apply_lighting(cmd, &a->sheet.lit, &a->light_given, opt, arg);
  if (rc >= 0)
    return rc;
  switch (opt->id) {
  case CLI_RENDER_OPT_PANEL_SIZE:
    return cli_parse_int(cmd, "--panel-size", arg, 16, 4096,
                         &a->sheet.layout.panel_width);
  case CLI_RENDER_OPT_OUTPUT:
    a->output = arg;
    return 0;
  case CLI_RENDER_OPT_QUIET:
    a->quiet = 1;
    return 0;
  default:
    return cli_settings_apply(cmd, &a->settings, opt, arg);
  }
}

static int sheet_parse(int argc, char **argv, sheet_args *a, const char **input) {
  int first = 0;
  int rc = cli_parse_options(&sheet_command, argc, argv, sheet_option, a, &first);
  if (!rc)
    rc = cli_expect_positionals(&sheet_command, argc, argv, first, 1, "HEIGHT");
  if (rc)
    return rc;
  *input = argv[first];
  if (!a->settings.scale_given)
    return cli_usage_error(
        sheet_command.name,
        "--scale is required (texels of displacement per unit of height)");
  if (!a->output)
    return cli_usage_error(sheet_command.name, "-o OUT is required");
  if (a->sheet.lit.mode == BB_RENDER_SLOPE)
    return cli_usage_error(sheet_command.name,
                           "--mode slope is render's (bumpbake render HEIGHT --mode slope); "
                           "the sheet lights the ssbump, normal or ao");
  a->sheet.lit.threads = a->settings.bake.trace.threads;
  const bb_output_spec spec = {a->output, "sheet", 0, a->settings.depth, 0, 0, 0, 0,
                               BB_RANGE_UNIT, NULL};
  bb_error err = {{0}};
  bb_status st = bb_outputs_check(&spec, 1, input, 1, &err);
  return st == BB_OK ? 0 : cli_library_error(sheet_command.name, st, &err);
}

/* The sheet's provenance: the height's and the bake's keys, then the lit
 * panel's options. */
static char *describe(const sheet_args *a, const char *command_line, const char *input,
                      const bb_height_source *source, const bb_bake_result *result) {
  char *extra = bb_render_options_describe(&a->sheet.lit);
  if (!extra)
    return NULL;
  const char *slash = strrchr(input, '/');
  bb_provenance p = {command_line, slash ? slash + 1 : input, source->height_hash, "sheet",
                     &a->settings.bake, a->settings.channel, result->rayset_id,
                     source->file_hash, extra};
  char *text = bb_provenance_format(&p);
  free(extra);
  return text;
}

static int sheet_run(const char *command_line, sheet_args *a, const char *input) {
  bb_image height = {0}, sheet = {0};
  bb_bake_result result;
  memset(&result, 0, sizeof result);
  bb_height_source source;
  bb_error err = {{0}};
  bb_status st = bb_height_file_read(input, a->settings.channel, a->settings.bake.height_scale,
                                     cli_note, NULL, &height, &source, &err);
  int rc = cli_status_exit(input, st, &err);
  if (!rc) {
    cli_progress progress;
    cli_progress_attach(&progress, "sheet", a->quiet, &a->settings.bake.trace);
    rc = cli_status_exit(input, bb_bake(&height, &a->settings.bake, &result, &err), &err);
    cli_progress_finish(&progress);
  }
  int labels = 1;
  if (!rc)
    rc = cli_status_exit(
        a->output, bb_sheet_make(&height, &result, &a->sheet, &sheet, &labels, &err), &err);
  char *text = rc ? NULL : describe(a, command_line, input, &source, &result);
  if (!rc && !text) {
    cli_file_error(a->output, "out of memory");
    rc = BB_EXIT_FAILURE;
  }
  if (!rc) {
    const bb_output_file file = {a->output, "sheet", &sheet, BB_RANGE_UNIT, a->settings.depth,
                                 0, text, NULL, 0, NULL};
    rc = cli_status_exit(a->output, bb_outputs_write(&file, 1, 1, &err), &err);
  }
  free(text);
  if (!rc && !labels)
    cli_render_no_font_note(sheet_command.name);
  if (!rc && !a->quiet)
    cli_printf_line("wrote sheet %s", a->output);
  bb_image_free(&sheet);
  bb_bake_result_free(&result);
  bb_image_free(&height);
  return rc;
}

int bb_cli_sheet(int argc, char **argv) {
  char *command_line = cli_command_line(argc, argv); /* before getopt permutes argv */
  if (!command_line)
    return BB_EXIT_FAILURE;
  sheet_args a;
  memset(&a, 0, sizeof a);
  cli_settings_init(&a.settings);
  bb_sheet_options_init(&a.sheet);
  const char *input = NULL;
  int rc = sheet_parse(argc, argv, &a, &input);
  if (rc < 0)
    rc = BB_EXIT_OK; /* --help */
  else if (rc == 0)
    rc = sheet_run(command_line, &a, input);
  free(command_line);
  return rc;
}
