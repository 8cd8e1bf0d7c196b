/* ssbump2normal.c: `bumpbake ssbump2normal`, the normal an ssbump (or
 * normal2ssbump's weights) stands for: the paper's normalize(sum s_c B_c). */
#include "cli.h"
#include "common.h"
#include "maps.h"

#include <string.h>

static const cli_option opt_output = {
    .id = CLI_OPT_OUTPUT,
    .long_name = "output",
    .short_name = 'o',
    .value_name = "OUT",
    .help = "normal map to write (.png .tga .tif .exr); required"};
static const cli_option opt_kind = {
    .id = CLI_OPT_MAP_KIND,
    .long_name = "kind",
    .value_name = "ssbump|weights",
    .default_text = "ssbump",
    .help = "what SSBUMP holds: an ssbump (bake --ssbump, height2ssbump) or weights "
            "(normal2ssbump)"};
static const cli_option opt_normal_y = {
    .id = CLI_OPT_NORMAL_Y,
    .long_name = "normal-y",
    .value_name = "down|up",
    .default_text = "down",
    .help = "green axis of the output: down = Source/DirectX, up = OpenGL"};

static const cli_option *const s2n_options[] = {&opt_output,   &opt_kind,
                                                &opt_normal_y, &cli_maps_opt_depth,
                                                &cli_opt_mips, CLI_TEXTURE_OPTIONS,
                                                &cli_opt_help};

static const cli_command s2n_command = {
    "ssbump2normal",
    "SSBUMP -o OUT [OPTIONS]",
    "The normal of an ssbump: N = normalize(sum_c s_c B_c) over R, G, B (the\n"
    "paper's specular normal; alpha is ignored). With --kind weights, s_c is\n"
    "sqrt(w_c), which undoes normal2ssbump's square. Either gives back the\n"
    "normal of an unoccluded texel wherever every N.B_c >= 0.",
    s2n_options,
    (int)(sizeof s2n_options / sizeof s2n_options[0]),
    cli_settings_init,
};

typedef struct s2n_args {
  cli_settings settings;
  const char *output;
  bb_ssbump_kind kind;
} s2n_args;

static int s2n_option(void *ctx, const cli_option *opt, const char *arg) {
  s2n_args *a = ctx;
  if (opt->id == CLI_OPT_OUTPUT) {
    a->output = arg;
    return 0;
  }
  if (opt->id == CLI_OPT_MAP_KIND) {
    if (!strcmp(arg, "ssbump"))
      a->kind = BB_SSBUMP_LINEAR;
    else if (!strcmp(arg, "weights"))
      a->kind = BB_SSBUMP_SQUARED;
    else
      return cli_usage_error(s2n_command.name,
                             "--kind must be one of ssbump|weights (got '%s')", arg);
    return 0;
  }
  return cli_settings_apply(s2n_command.name, &a->settings, opt, arg);
}

static int s2n_parse(int argc, char **argv, s2n_args *a, const char **input) {
  int first = 0;
  int rc = cli_parse_options(&s2n_command, argc, argv, s2n_option, a, &first);
  if (!rc)
    rc = cli_expect_positionals(&s2n_command, argc, argv, first, 1, "SSBUMP");
  if (rc)
    return rc;
  *input = argv[first];
  if (!a->output)
    return cli_usage_error(s2n_command.name, "-o OUT is required");
  return cli_maps_check_output(s2n_command.name, *input, a->output, &a->settings);
}

static int s2n_run(const cli_run *run, s2n_args *a, const char *input) {
  bb_image ssbump = {0}, normals = {0};
  bb_image_info info = {0};
  int rc = cli_maps_read(input, &ssbump, &info);
  if (!rc)
    rc = cli_maps_check_hl2(input, &ssbump, &info);
  if (!rc) {
    bb_error err = {{0}};
    rc = cli_status_exit(input, bb_ssbump_to_normal(&ssbump, a->kind, &normals, &err),
                         &err);
  }
  if (!rc) {
    if (a->settings.bake.normal_y_up)
      bb_image_flip_green(&normals);
    bb_depth depth = cli_maps_output_depth(a->settings.depth, &info, a->output);
    rc = cli_maps_write(run, cli_maps_file_name(input), &ssbump, "normal", a->output,
                        &normals, BB_RANGE_SIGNED, depth, a->settings.mips,
                        &a->settings.texture);
  }
  if (!rc)
    cli_printf_line("wrote normal %s", a->output);
  bb_image_free(&normals);
  bb_image_free(&ssbump);
  bb_image_info_free(&info);
  return rc;
}

int bb_cli_ssbump2normal(int argc, char **argv) {
  cli_run run;
  if (cli_run_init(&run, argc, argv)) /* before getopt permutes argv */
    return BB_EXIT_FAILURE;
  s2n_args a;
  memset(&a, 0, sizeof a);
  cli_settings_init(&a.settings);
  a.kind = BB_SSBUMP_LINEAR;
  const char *input = NULL;
  int rc = s2n_parse(argc, argv, &a, &input);
  if (rc < 0)
    rc = BB_EXIT_OK; /* --help */
  else if (rc == 0)
    rc = s2n_run(&run, &a, input);
  cli_run_free(&run);
  return rc;
}
