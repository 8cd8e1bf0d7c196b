/* renderbump.c: `bumpbake renderbumpflat`, DOOM 3's RenderBumpFlat: a
 * flat sculpt (a model file) to its normal map, and optionally its height
 * with the scale that `bumpbake bake` needs to make ssbump and ao from it. */
#include "cli.h"
#include "common.h"
#include "options.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Option ids of this command only (the shared ones are in options.h). */
enum {
  OPT_SIZE = 1000, /* -size W H, taken out of argv before getopt */
  OPT_RECT,        /* --rect L B R T, likewise */
  OPT_HEIGHT,
  OPT_AXIS,
  OPT_SAMPLES,
  OPT_FACE_NORMALS,
  OPT_TILE,
  OPT_QUIET
};

static const cli_option opt_size = {
    .id = OPT_SIZE,
    .long_name = "size",
    .value_name = "W H",
    .default_text = "256 256",
    .range_text = "1..65536 each, W*H <= 8192*8192",
    .help = "output size in texels (DOOM 3's -size W H; one dash or two)"};
static const cli_option opt_output = {
    .id = CLI_OPT_OUTPUT,
    .long_name = "output",
    .short_name = 'o',
    .value_name = "OUT",
    .default_text = "MODEL_local.tga beside MODEL",
    .help = "normal map, RGB = N, A = coverage (.tga .png .tif .exr)"};
static const cli_option opt_height = {
    .id = OPT_HEIGHT,
    .long_name = "height",
    .value_name = "FILE",
    .help = "also write the height, 0..1 (16-bit png/tif, float exr), and print its scale"};
static const cli_option opt_axis = {
    .id = OPT_AXIS,
    .long_name = "axis",
    .value_name = "-y|+y|+z|-z|+x|-x",
    .default_text = "-y (DOOM 3)",
    .help = "the side the sculpt's front faces (+z: Blender's top view)"};
static const cli_option opt_samples = {
    .id = OPT_SAMPLES,
    .long_name = "samples",
    .value_name = "N",
    .default_text = "4 (16 samples per texel)",
    .range_text = "1..16",
    .help = "N x N samples per texel"};
static const cli_option opt_face_normals = {
    .id = OPT_FACE_NORMALS,
    .long_name = "face-normals",
    .default_text = "off",
    .help = "triangles' plane normals even where the model has vertex normals"};
static const cli_option opt_rect = {
    .id = OPT_RECT,
    .long_name = "rect",
    .value_name = "L B R T",
    .default_text = "the model's bounding rectangle",
    .help = "rectangle in model units along the image's right and up axes"};
static const cli_option opt_tile = {
    .id = OPT_TILE,
    .long_name = "tile",
    .default_text = "off",
    .help = "wrap geometry outside --rect into it (the sculpt tiles; needs --rect)"};
static const cli_option opt_quiet = {.id = OPT_QUIET,
                                     .long_name = "quiet",
                                     .short_name = 'q',
                                     .help = "print only errors, notes and the height scale"};

static const cli_option *const rbf_options[] = {
    &opt_size,  &opt_output,   &opt_height,       &opt_axis,         &opt_samples,
    &opt_face_normals, &opt_rect, &opt_tile, &cli_opt_normal_y, &cli_opt_threads,
    &opt_quiet, &cli_opt_help,
};

static const cli_command rbf_command = {
    "renderbumpflat",
    "[-size W H] MODEL [OPTIONS]",
    "DOOM 3's RenderBumpFlat: projects MODEL (any format Assimp reads) onto its\n"
    "bounding rectangle and writes the front-most surface's normals, 16x\n"
    "oversampled, with alpha = coverage.",
    rbf_options,
    (int)(sizeof rbf_options / sizeof rbf_options[0]),
    cli_settings_init,
};

typedef struct rbf_args {
  bb_renderbump_options render;
  cli_settings settings; /* --normal-y and --threads, through the shared rows */
  const char *model, *output, *height;
  char *default_output; /* malloc'd MODEL_local.tga */
  int quiet;
} rbf_args;

/* ------------------------------------------------------------- parsing */

static int rbf_option(void *ctx, const cli_option *opt, const char *arg) {
  rbf_args *a = ctx;
  switch (opt->id) {
  case CLI_OPT_OUTPUT:
    a->output = arg;
    return 0;
  case OPT_HEIGHT:
    a->height = arg;
    return 0;
  case OPT_AXIS:
    if (bb_axis_parse(arg, &a->render.axis, NULL))
      return cli_usage_error(rbf_command.name, "--axis must be one of %s (got '%s')",
                             opt->value_name, arg);
    return 0;
  case OPT_SAMPLES:
    return cli_parse_int(rbf_command.name, "--samples", arg, 1, 16, &a->render.samples);
  case OPT_FACE_NORMALS:
    a->render.face_normals = 1;
    return 0;
  case OPT_TILE:
    a->render.tile = 1;
    return 0;
  case OPT_QUIET:
    a->quiet = 1;
    return 0;
  case OPT_SIZE: /* only an abbreviation ("--si") reaches getopt */
  case OPT_RECT:
    return cli_usage_error(rbf_command.name, "--%s takes %s values: --%s %s",
                           opt->long_name, opt->id == OPT_SIZE ? "two" : "four",
                           opt->long_name, opt->value_name);
  default:
    return cli_settings_apply(rbf_command.name, &a->settings, opt, arg);
  }
}

static int parse_size(rbf_args *a, char **values) {
  int rc = cli_parse_int(rbf_command.name, "-size W", values[0], 1, BB_MAX_DIMENSION,
                         &a->render.width);
  if (!rc)
    rc = cli_parse_int(rbf_command.name, "-size H", values[1], 1, BB_MAX_DIMENSION,
                       &a->render.height);
  if (!rc && (long long)a->render.width * a->render.height > BB_MAX_PIXELS)
    rc = cli_usage_error(rbf_command.name, "-size %d %d is over %ld texels",
                         a->render.width, a->render.height, (long)BB_MAX_PIXELS);
  return rc;
}

static int parse_rect(rbf_args *a, char **values) {
  static const char *const names[4] = {"--rect L", "--rect B", "--rect R", "--rect T"};
  for (int k = 0; k < 4; k++) {
    int rc = cli_parse_double(rbf_command.name, names[k], values[k], -HUGE_VAL, 0, HUGE_VAL,
                              &a->render.rect[k]);
    if (rc)
      return rc;
  }
  if (!(a->render.rect[2] > a->render.rect[0]) || !(a->render.rect[3] > a->render.rect[1]))
    return cli_usage_error(rbf_command.name, "--rect needs L < R and B < T");
  a->render.rect_given = 1;
  return 0;
}

/* DOOM 3 writes "-size W H": options with several values, which getopt
 * cannot take. They are parsed here and removed from argv (before "--");
 * *argc shrinks accordingly. */
static int take_multi_value_options(rbf_args *a, int *argc, char **argv) {
  int kept = 1;
  for (int i = 1; i < *argc; i++) {
    const char *s = argv[i];
    int is_size = !strcmp(s, "-size") || !strcmp(s, "--size");
    int is_rect = !strcmp(s, "-rect") || !strcmp(s, "--rect");
    if (!strcmp(s, "--")) {
      while (i < *argc)
        argv[kept++] = argv[i++];
      break;
    }
    if (!is_size && !is_rect) {
      argv[kept++] = argv[i];
      continue;
    }
    int values = is_size ? 2 : 4;
    if (i + values >= *argc)
      return cli_usage_error(rbf_command.name, "%s needs %d values: %s", s, values,
                             is_size ? "-size W H" : "--rect L B R T");
    int rc = is_size ? parse_size(a, argv + i + 1) : parse_rect(a, argv + i + 1);
    if (rc)
      return rc;
    i += values;
  }
  *argc = kept;
  return 0;
}

static int check_outputs(rbf_args *a) {
  if (!a->output) {
    a->default_output = bb_path_with_suffix(a->model, "_local.tga");
    if (!a->default_output) {
      cli_file_error(a->model, "out of memory");
      return BB_EXIT_FAILURE;
    }
    a->output = a->default_output;
  }
  if (a->height && bb_same_file(a->height, a->output))
    return cli_usage_error(rbf_command.name, "--height and the normal map are both %s",
                           a->output);
  const bb_output_spec specs[2] = {
      {a->output, "normal", 4, BB_DEPTH_DEFAULT, 0, 0, 0, 0, BB_RANGE_SIGNED, NULL},
      {a->height, "height", 1, BB_DEPTH_DEFAULT, 0, 0, 0, 0, BB_RANGE_UNIT, NULL}};
  bb_error err = {{0}};
  bb_status st = bb_outputs_check(specs, a->height ? 2 : 1, &a->model, 1, &err);
  return st == BB_OK ? 0 : cli_library_error(rbf_command.name, st, &err);
}

/* The library's notes on a render name no file (it sees a mesh, not a path);
 * note_user carries the model's, so they read like every other note. */
static void rbf_note(void *model, const char *path, const char *text) {
  cli_note(NULL, path ? path : (const char *)model, text);
}

static int rbf_parse(int argc, char **argv, rbf_args *a) {
  int rc = take_multi_value_options(a, &argc, argv);
  int first = 0;
  if (!rc)
    rc = cli_parse_options(&rbf_command, argc, argv, rbf_option, a, &first);
  if (!rc)
    rc = cli_expect_positionals(&rbf_command, argc, argv, first, 1, "MODEL");
  if (rc)
    return rc;
  a->model = argv[first];
  if (a->render.tile && !a->render.rect_given)
    return cli_usage_error(rbf_command.name,
                           "--tile needs --rect L B R T: the tile the sculpt repeats with");
  a->render.threads = a->settings.bake.trace.threads;
  a->render.note = rbf_note;
  a->render.note_user = (void *)a->model;
  return check_outputs(a);
}

/* ------------------------------------------------------------- running */

static void print_summary(const rbf_args *a, const bb_mesh *mesh, const bb_renderbump_result *r) {
  cli_printf_line("renderbumpflat: %s: %zu triangles, %s normals, seen along %s; rectangle "
         "[%g, %g] x [%g, %g]; %d x %d texels, %d samples each",
         a->model, mesh->triangle_count, r->used_vertex_normals ? "vertex" : "face",
         bb_axis_name(a->render.axis), r->rect[0], r->rect[2], r->rect[1], r->rect[3],
         a->render.width, a->render.height, a->render.samples * a->render.samples);
}

static int write_outputs(const char *command_line, const rbf_args *a, const bb_mesh *mesh,
                         const bb_renderbump_result *r) {
  bb_error err = {{0}};
  bb_status st = bb_renderbump_write(r, &a->render, a->settings.bake.normal_y_up, a->model,
                                     bb_mesh_hash(mesh), command_line, a->output, a->height,
                                     &err);
  if (st != BB_OK) {
    cli_error_line(err.message);
    return BB_EXIT_FAILURE;
  }
  if (!a->quiet) {
    cli_printf_line("wrote normal %s", a->output);
    if (a->height)
      cli_printf_line("wrote height %s", a->height);
  }
  if (a->height && r->height_scale > 0.0)
    /* The one number the height is useless without: printed even with -q. */
    cli_printf_line("height scale %.6g texels per unit (bumpbake bake %s --scale %.6g ...)",
                    r->height_scale, a->height, r->height_scale);
  else if (a->height)
    cli_printf_line("height scale 0: the model is flat along %s, so its height is 0 "
                    "everywhere and a bake of it would trace nothing",
                    bb_axis_name(a->render.axis));
  return 0;
}

static int rbf_run(const char *command_line, rbf_args *a) {
  bb_mesh mesh;
  bb_renderbump_result result;
  memset(&mesh, 0, sizeof mesh);
  memset(&result, 0, sizeof result);
  bb_error err = {{0}};
  char note[512];
  bb_status st = bb_mesh_load_noted(a->model, &mesh, note, sizeof note, &err);
  if (st == BB_OK && note[0]) /* a missing .mtl and the like */
    cli_note(NULL, a->model, note);
  if (st == BB_OK)
    st = bb_renderbump_flat(&mesh, &a->render, &result, &err);
  int rc = cli_status_exit(a->model, st, &err);
  if (!rc) {
    if (!a->quiet)
      print_summary(a, &mesh, &result);
    rc = write_outputs(command_line, a, &mesh, &result);
  }
  bb_renderbump_result_free(&result);
  bb_mesh_free(&mesh);
  return rc;
}

int bb_cli_renderbumpflat(int argc, char **argv) {
  char *command_line = cli_command_line(argc, argv); /* before argv is rearranged */
  if (!command_line)
    return BB_EXIT_FAILURE;
  rbf_args a;
  memset(&a, 0, sizeof a);
  bb_renderbump_options_init(&a.render);
  cli_settings_init(&a.settings);
  int rc = rbf_parse(argc, argv, &a);
  if (rc < 0)
    rc = BB_EXIT_OK; /* --help */
  else if (rc == 0)
    rc = rbf_run(command_line, &a);
  free(a.default_output);
  free(command_line);
  return rc;
}
