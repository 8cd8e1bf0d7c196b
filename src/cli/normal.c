/* cli_normal.c: `bumpbake normal`, a normal map from a height map (no
 * tracing). */
#include "common.h"

#include <string.h>

static const cli_option opt_output = {
    .id = CLI_OPT_OUTPUT,
    .long_name = "output",
    .short_name = 'o',
    .value_name = "OUT",
    .help = "normal map to write (.png .tga .tif .exr); required"};

static const cli_option opt_quiet = {.id = CLI_OPT_QUIET,
                                     .long_name = "quiet",
                                     .short_name = 'q',
                                     .default_text = "off",
                                     .help = "no \"wrote ...\" line"};

static const cli_option *const normal_options[] = {
    &opt_output,
    &cli_opt_scale,
    &cli_opt_filter_radius,
    &cli_opt_filter_threshold,
    &cli_opt_normal_filter,
    &cli_opt_normal_y,
    &cli_opt_threads,
    &cli_opt_clamp,
    &cli_opt_channel,
    &cli_opt_depth,
    &cli_opt_mips,
    &opt_quiet,
    &cli_opt_help,
};

static const cli_command normal_command = {
    "normal",
    "HEIGHT -o OUT --scale S [OPTIONS]",
    "Smooths HEIGHT and writes its tangent-space normals (0.5 + 0.5 N in integer\n"
    "files, N in EXR).",
    normal_options,
    (int)(sizeof normal_options / sizeof normal_options[0]),
    cli_settings_init,
};

typedef struct normal_args {
  cli_settings settings;
  const char *output;
  int quiet;
} normal_args;

static int normal_option(void *ctx, const cli_option *opt, const char *arg) {
  normal_args *a = ctx;
  if (opt->id == CLI_OPT_OUTPUT) {
    a->output = arg;
    return 0;
  }
  if (opt->id == CLI_OPT_QUIET) {
    a->quiet = 1;
    return 0;
  }
  return cli_settings_apply(normal_command.name, &a->settings, opt, arg);
}

/* Parses and validates the whole command line; *input receives HEIGHT. */
static int normal_parse(int argc, char **argv, normal_args *a, const char **input) {
  int first = 0;
  int rc = cli_parse_options(&normal_command, argc, argv, normal_option, a, &first);
  if (rc)
    return rc;
  rc = cli_expect_positionals(&normal_command, argc, argv, first, 1, "HEIGHT");
  if (rc)
    return rc;
  *input = argv[first];
  if (!a->output)
    return cli_usage_error(normal_command.name, "-o OUT is required");
  if (!a->settings.scale_given)
    return cli_usage_error(
        normal_command.name,
        "--scale is required (texels of displacement per unit of height)");
  int rc2 = cli_check_output(normal_command.name, *input, a->output, a->settings.depth);
  return rc2 ? rc2 : cli_check_mips(normal_command.name, &a->settings, a->output);
}

static int normal_run(cli_run *run, normal_args *a, const char *input) {
  bb_image height = {0};
  bb_bake_result result;
  memset(&result, 0, sizeof result);
  int rc = cli_load_height(input, &a->settings, &height);
  if (!rc)
    rc = cli_run_bake(input, &height, &a->settings.bake, &result);
  if (!rc) {
    cli_run_set_input(run, input, &height, &a->settings);
    rc = cli_write_output(run, "normal", a->output, &result.normal, BB_RANGE_SIGNED);
  }
  if (!rc && !a->quiet) /* as bake says it */
    printf("wrote normal %s\n", a->output);
  bb_bake_result_free(&result);
  bb_image_free(&height);
  return rc;
}

int bb_cli_normal(int argc, char **argv) {
  cli_run run;
  if (cli_run_init(&run, argc, argv)) /* before getopt permutes argv */
    return BB_EXIT_FAILURE;
  normal_args a;
  memset(&a, 0, sizeof a);
  cli_settings_init(&a.settings);
  a.settings.bake.outputs = BB_OUTPUT_BIT(BB_OUTPUT_NORMAL); /* no rays, nothing else */
  const char *input = NULL;
  int rc = normal_parse(argc, argv, &a, &input);
  if (rc < 0)
    rc = BB_EXIT_OK; /* --help */
  else if (rc == 0)
    rc = normal_run(&run, &a, input);
  cli_run_free(&run);
  return rc;
}
