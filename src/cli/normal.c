/* normal.c: `bumpbake normal`, a normal map from a height map (no tracing):
 * a bake job of one map. */
#include "cli.h"
#include "common.h"
#include "job_json.h"
#include "options.h"

#include <stdlib.h>
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

static const cli_option opt_json = {.id = CLI_OPT_JSON,
                                    .long_name = "json",
                                    .default_text = "off",
                                    .help = "print one JSON line describing the bake on stdout"};

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
    CLI_TEXTURE_OPTIONS,
    &opt_json,
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
  int json, quiet;
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
  if (opt->id == CLI_OPT_JSON) {
    a->json = 1;
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
  return 0;
}

/* A bake of the normal map alone (nothing is traced), through the job. */
static int normal_run(normal_args *a, const char *command_line, const char *input) {
  bb_job_options o;
  bb_job_options_init(&o);
  o.bake = a->settings.bake;
  o.channel = a->settings.channel;
  o.depth = a->settings.depth;
  o.mips = a->settings.mips;
  o.texture = a->settings.texture;
  o.paths[BB_OUTPUT_NORMAL] = a->output;
  o.force = 1;
  o.command = command_line;
  o.note = cli_note;
  bb_job *job = NULL;
  bb_error err = {{0}};
  bb_status st = bb_job_plan(&input, 1, &o, &job, &err);
  if (st != BB_OK)
    return cli_library_error(normal_command.name, st, &err);
  int rc = BB_EXIT_OK;
  if (bb_job_run_item(job, 0, NULL, NULL) != BB_OK) {
    cli_error_line(bb_job_report_get(job, 0)->error.message);
    rc = BB_EXIT_FAILURE;
  } else if (a->json) {
    cli_job_json(&o.bake, bb_job_report_get(job, 0), NULL);
  } else if (!a->quiet) { /* as bake says it */
    cli_printf_line("wrote normal %s", a->output);
  }
  bb_job_free(job);
  return rc;
}

int bb_cli_normal(int argc, char **argv) {
  char *command_line = cli_command_line(argc, argv); /* before getopt permutes argv */
  if (!command_line)
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
    rc = normal_run(&a, command_line, input);
  free(command_line);
  return rc;
}
