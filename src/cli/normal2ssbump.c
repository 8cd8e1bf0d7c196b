/* normal2ssbump.c: `bumpbake normal2ssbump`, Valve's SDK tool of that
 * name: a normal map to unshadowed basis weights, written by default where
 * Valve's tool writes them (NAME_ssbump.tga). */
#include "cli.h"
#include "common.h"
#include "maps.h"

#include <stdlib.h>
#include <string.h>
#include <strings.h>

static const cli_option opt_output = {
    .id = CLI_OPT_OUTPUT,
    .long_name = "output",
    .short_name = 'o',
    .value_name = "OUT",
    .default_text = "NAME_ssbump.tga next to NORMAL, as Valve's tool",
    .help = "weights to write (.png .tga .tif .exr)"};
static const cli_option opt_normal_y = {
    .id = CLI_OPT_NORMAL_Y,
    .long_name = "normal-y",
    .value_name = "down|up",
    .default_text = "down",
    .help = "green axis of NORMAL: down = Source/DirectX, up = OpenGL"};

static const cli_option *const n2s_options[] = {
    &opt_output, &opt_normal_y, &cli_maps_opt_depth, &cli_opt_mips, CLI_TEXTURE_OPTIONS,
    &cli_opt_help};

static const cli_command n2s_command = {
    "normal2ssbump",
    "NORMAL [-o OUT] [OPTIONS]",
    "Valve's normal2ssbump: the basis weights sat(N.B_c)^2 / sum_k sat(N.B_k)^2 of a\n"
    "normal map (no self-shadowing; bake --ssbump traces that). NORMAL's codes\n"
    "decode as N = 2 code / max - 1 (127.5 of 255 is 0), float files as N; an\n"
    "alpha channel is copied. Without -o, writes NAME_ssbump.tga next to NORMAL,\n"
    "NAME being NORMAL's file name up to its first \"_normal\" (any case), else up\n"
    "to its first '.' (Valve's rule: wall.v2.png gives wall_ssbump.tga).",
    n2s_options,
    (int)(sizeof n2s_options / sizeof n2s_options[0]),
    cli_settings_init,
};

typedef struct n2s_args {
  cli_settings settings;
  const char *output;
  char *default_output; /* malloc'd Valve-style name */
} n2s_args;

static int n2s_option(void *ctx, const cli_option *opt, const char *arg) {
  n2s_args *a = ctx;
  if (opt->id == CLI_OPT_OUTPUT) {
    a->output = arg;
    return 0;
  }
  return cli_settings_apply(n2s_command.name, &a->settings, opt, arg);
}

/* Valve's normal2ssbump output name: the input up to its first "_normal"
 * (any case), else up to its first '.', then "_ssbump.tga". Valve's tool
 * searches the whole path; this searches the file name only, so a directory
 * such as maps_normal/ or v1.2/ is left alone. */
static char *valve_output_name(const char *input) {
  const char *slash = strrchr(input, '/');
  const char *name = slash ? slash + 1 : input;
  const char *cut = NULL;
  for (const char *p = name; *p && !cut; p++)
    if (strncasecmp(p, "_normal", 7) == 0)
      cut = p;
  if (!cut)
    cut = strchr(name, '.');
  if (!cut)
    cut = name + strlen(name);
  size_t keep = (size_t)(cut - input);
  char *out = malloc(keep + sizeof "_ssbump.tga");
  if (out) {
    memcpy(out, input, keep);
    strcpy(out + keep, "_ssbump.tga");
  }
  return out;
}

static int n2s_parse(int argc, char **argv, n2s_args *a, const char **input) {
  int first = 0;
  int rc = cli_parse_options(&n2s_command, argc, argv, n2s_option, a, &first);
  if (!rc)
    rc = cli_expect_positionals(&n2s_command, argc, argv, first, 1, "NORMAL");
  if (rc)
    return rc;
  *input = argv[first];
  if (!a->output) {
    a->default_output = valve_output_name(*input);
    if (!a->default_output) {
      cli_file_error(*input, "out of memory");
      return BB_EXIT_FAILURE;
    }
    a->output = a->default_output;
  }
  return cli_maps_check_output(n2s_command.name, *input, a->output, &a->settings);
}

/* Appends the input's alpha (channel 3 of RGBA) to the weights, as Valve's
 * tool rewrites only R, G and B. */
static int with_alpha(const char *path, const bb_image *input, const bb_image_info *info,
                      bb_image *weights) {
  int alpha =
      info->alpha_channel >= 3 ? info->alpha_channel : (input->channels >= 4 ? 3 : -1);
  if (alpha < 0)
    return 0;
  bb_image rgba;
  bb_error err = {{0}};
  if (bb_image_alloc(&rgba, weights->width, weights->height, 4, &err) != BB_OK)
    return cli_status_exit(path, BB_ERR_MEMORY, &err);
  const size_t n = (size_t)weights->width * (size_t)weights->height;
  for (size_t i = 0; i < n; i++) {
    memcpy(rgba.pixels + 4 * i, weights->pixels + 3 * i, 3 * sizeof(float));
    rgba.pixels[4 * i + 3] = input->pixels[i * (size_t)input->channels + (size_t)alpha];
  }
  bb_image_free(weights);
  *weights = rgba;
  return 0;
}

static int n2s_run(const cli_run *run, n2s_args *a, const char *input) {
  bb_image values = {0}, normals = {0}, weights = {0};
  bb_image_info info = {0};
  int rc = cli_maps_read(input, &values, &info);
  if (!rc) {
    bb_normal_decode_options o;
    bb_normal_decode_options_init(&o);
    o.normal_y_up = a->settings.bake.normal_y_up;
    bb_error err = {{0}};
    bb_status st = bb_normal_map_decode(&values, info.is_float, &o, &normals, &err);
    if (st == BB_OK)
      st = bb_derive_weights(&normals, NULL, &weights, &err);
    rc = cli_status_exit(input, st, &err);
  }
  if (!rc)
    rc = with_alpha(input, &values, &info, &weights);
  if (!rc) {
    bb_depth depth = cli_maps_output_depth(a->settings.depth, &info, a->output);
    rc = cli_maps_write(run, cli_maps_file_name(input), &values, "weights", a->output,
                        &weights, BB_RANGE_UNIT, depth, a->settings.mips,
                        &a->settings.texture);
  }
  if (!rc)
    cli_printf_line("wrote weights %s", a->output);
  bb_image_free(&weights);
  bb_image_free(&normals);
  bb_image_free(&values);
  bb_image_info_free(&info);
  return rc;
}

int bb_cli_normal2ssbump(int argc, char **argv) {
  cli_run run;
  if (cli_run_init(&run, argc, argv)) /* before getopt permutes argv */
    return BB_EXIT_FAILURE;
  n2s_args a;
  memset(&a, 0, sizeof a);
  cli_settings_init(&a.settings);
  const char *input = NULL;
  int rc = n2s_parse(argc, argv, &a, &input);
  if (rc < 0)
    rc = BB_EXIT_OK; /* --help */
  else if (rc == 0)
    rc = n2s_run(&run, &a, input);
  free(a.default_output);
  cli_run_free(&run);
  return rc;
}
