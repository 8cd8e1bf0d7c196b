/* cli_sheet.c: `bumpbake sheet`, one labelled contact sheet of every map of
 * a bake and one lit render. */
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
  return cli_check_output(sheet_command.name, *input, a->output, a->settings.depth);
}

static int sheet_run(cli_run *run, sheet_args *a, const char *input) {
  bb_image height = {0}, sheet = {0};
  bb_bake_result result;
  memset(&result, 0, sizeof result);
  int rc = cli_load_height(input, &a->settings, &height);
  if (!rc) {
    cli_progress progress;
    cli_progress_attach(&progress, "sheet", a->quiet, &a->settings.bake.trace);
    rc = cli_run_bake(input, &height, &a->settings.bake, &result);
    cli_progress_finish(&progress);
  }
  int labels = 1;
  if (!rc) {
    bb_error err = {{0}};
    rc = cli_status_exit(
        a->output, bb_sheet_make(&height, &result, &a->sheet, &sheet, &labels, &err),
        &err);
  }
  if (!rc) {
    cli_run_set_input(run, input, &height, &a->settings);
    run->rayset_id = result.rayset_id;
    char *extra = bb_render_options_describe(&a->sheet.lit);
    rc = extra ? cli_render_write(run, &a->settings.bake, extra, "sheet", a->output,
                                  &sheet, a->settings.depth)
               : BB_EXIT_FAILURE;
    if (!extra)
      cli_file_error(a->output, "out of memory");
    free(extra);
  }
  if (!rc && !labels)
    cli_render_no_font_note(sheet_command.name);
  if (!rc && !a->quiet)
    printf("wrote sheet %s\n", a->output);
  bb_image_free(&sheet);
  bb_bake_result_free(&result);
  bb_image_free(&height);
  return rc;
}

int bb_cli_sheet(int argc, char **argv) {
  cli_run run;
  if (cli_run_init(&run, argc, argv)) /* before getopt permutes argv */
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
    rc = sheet_run(&run, &a, input);
  cli_run_free(&run);
  return rc;
}
