/* program.c: `bumpbake program`, a DOOM 3 image program (the text of a
 * material's bumpmap or diffusemap stage) evaluated outside the engine. */
#include "cli.h"
#include "common.h"
#include "maps.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const cli_option opt_output = {.id = CLI_OPT_OUTPUT,
                                      .long_name = "output",
                                      .short_name = 'o',
                                      .value_name = "OUT",
                                      .help =
                                          "image to write (.png .tga .tif .exr); a "
                                          "normal map as bumpbake writes them; required"};
static const cli_option opt_base = {
    .id = CLI_OPT_MAP_BASE_DIR,
    .long_name = "base",
    .value_name = "DIR",
    .default_text = "the current directory",
    .help = "directory image names are relative to (a game's base/, say)"};
static const cli_option opt_depth = {.id = CLI_OPT_DEPTH,
                                     .long_name = "depth",
                                     .value_name = "8|16|half|float",
                                     .default_text = "8 (png/tga/tif) or float (exr)",
                                     .help = "sample depth of the output"};

static const cli_option opt_allow_outside = {
    .id = CLI_OPT_MAP_ALLOW_OUTSIDE,
    .long_name = "allow-outside-base",
    .default_text = "off",
    .help = "read images outside --base too (absolute paths, .., links out)"};

static const cli_option *const program_options[] = {
    &opt_output, &opt_base, &opt_allow_outside, &opt_depth, &cli_opt_mips, CLI_TEXTURE_OPTIONS,
    &cli_opt_help};

static const cli_command program_command = {
    "program",
    "EXPR -o OUT [OPTIONS]",
    "Evaluates a DOOM 3 image program, e.g. 'addnormals(a_local.tga, heightmap(a_h.tga, "
    "4))',\n"
    "with id Tech 4's formulas (docs/commands/program.md): heightmap(img, scale),\n"
    "addnormals(a, b), smoothnormals(a), add(a, b), scale(a, r, g, b, a),\n"
    "invertAlpha(a), invertColor(a), makeIntensity(a), makeAlpha(a), _flat.\n"
    "A program that makes a normal map is written as bumpbake writes normals\n"
    "(0.5 + 0.5 N; N in EXR), any other as RGBA.",
    program_options,
    (int)(sizeof program_options / sizeof program_options[0]),
    cli_settings_init,
};

typedef struct program_args {
  cli_settings settings;
  const char *output, *base_dir;
  int allow_outside_base;
} program_args;

static int program_option(void *ctx, const cli_option *opt, const char *arg) {
  program_args *a = ctx;
  if (opt->id == CLI_OPT_OUTPUT) {
    a->output = arg;
    return 0;
  }
  if (opt->id == CLI_OPT_MAP_BASE_DIR) {
    a->base_dir = arg;
    return 0;
  }
  if (opt->id == CLI_OPT_MAP_ALLOW_OUTSIDE) {
    a->allow_outside_base = 1;
    return 0;
  }
  return cli_settings_apply(program_command.name, &a->settings, opt, arg);
}

/* The output must not replace any image the program reads: every one of
 * them, however many the program names (bb_outputs_check against all). */
static int check_output_against_images(const program_args *a, const bb_program *program) {
  size_t count = bb_program_images(program, NULL, 0);
  const char **names = malloc((count ? count : 1) * sizeof *names);
  char (*paths)[4096] = malloc((count ? count : 1) * sizeof *paths);
  const char **reads = malloc((count ? count : 1) * sizeof *reads);
  int rc = 0;
  if (!names || !paths || !reads) {
    cli_file_error(a->output, "out of memory");
    rc = BB_EXIT_FAILURE;
  }
  int n = 0;
  if (!rc) {
    bb_program_images(program, names, count);
    for (size_t i = 0; i < count; i++) {
      /* a name too long to resolve is refused when the program runs, before
       * anything is written; a cut path is no input to compare with */
      const int len = bb_program_image_path(a->base_dir, names[i], paths[n], sizeof paths[n]);
      if (len >= 0 && (size_t)len < sizeof paths[n])
        reads[n] = paths[n], n++;
    }
    const bb_output_spec spec = {a->output, "output", 0, a->settings.depth, a->settings.mips, 0,
                                 0, 0, BB_RANGE_UNIT, &a->settings.texture};
    bb_error err = {{0}};
    bb_status st = bb_outputs_check(&spec, 1, reads, n, &err);
    rc = st == BB_OK ? 0 : cli_library_error(program_command.name, st, &err);
  }
  free(names);
  free(paths);
  free(reads);
  return rc;
}

/* Parses the command line and the program: a syntax error is a usage error. */
static int program_parse(int argc, char **argv, program_args *a, const char **text,
                         bb_program **program) {
  int first = 0;
  int rc = cli_parse_options(&program_command, argc, argv, program_option, a, &first);
  if (!rc)
    rc = cli_expect_positionals(&program_command, argc, argv, first, 1, "EXPR");
  if (rc)
    return rc;
  *text = argv[first];
  if (!a->output)
    return cli_usage_error(program_command.name, "-o OUT is required");
  bb_error err = {{0}};
  if (bb_program_parse(*text, program, &err) != BB_OK)
    return cli_usage_error(program_command.name, "%s", err.message);
  return check_output_against_images(a, *program);
}

static int program_run(const cli_run *run, const program_args *a, const char *text,
                       const bb_program *program) {
  bb_program_options o;
  bb_program_options_init(&o);
  o.base_dir = a->base_dir;
  o.allow_outside_base = a->allow_outside_base;
  bb_image out = {0};
  int is_normal = 0;
  bb_error err = {{0}};
  bb_status st = bb_program_run(program, &o, &out, &is_normal, &err);
  if (st != BB_OK) {
    /* The message names the image file or the function at fault. */
    cli_error_line(err.message[0] ? err.message : bb_status_name(st));
    return BB_EXIT_FAILURE;
  }
  const char *kind = is_normal ? "normal" : "colour";
  int rc = cli_maps_write(run, text, NULL, kind, a->output, &out,
                          is_normal ? BB_RANGE_SIGNED : BB_RANGE_UNIT, a->settings.depth,
                          a->settings.mips, &a->settings.texture);
  if (!rc)
    cli_printf_line("wrote %s %s", kind, a->output);
  bb_image_free(&out);
  return rc;
}

int bb_cli_program(int argc, char **argv) {
  cli_run run;
  if (cli_run_init(&run, argc, argv)) /* before getopt permutes argv */
    return BB_EXIT_FAILURE;
  program_args a;
  memset(&a, 0, sizeof a);
  cli_settings_init(&a.settings);
  bb_program *program = NULL;
  const char *text = NULL;
  int rc = program_parse(argc, argv, &a, &text, &program);
  if (rc < 0)
    rc = BB_EXIT_OK; /* --help */
  else if (rc == 0)
    rc = program_run(&run, &a, text, program);
  bb_program_free(program);
  cli_run_free(&run);
  return rc;
}
