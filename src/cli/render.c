/* render.c: `bumpbake render`, the maps lit as Source lights them, from a
 * height map (baked on the fly) or from maps already baked; one picture, the
 * paper's four-panel comparison, or an orbit of the light. */
#include "cli.h"
#include "common.h"
#include "options.h"
#include "progress.h"
#include "render_common.h"

#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

/* The maps each mode needs, by the library's kinds of render map. */
static const unsigned map_need[BB_RENDER_MAP_COUNT] = {
    BB_RENDER_NEEDS_NORMAL, BB_RENDER_NEEDS_SSBUMP, BB_RENDER_NEEDS_AO, 0,
    BB_RENDER_NEEDS_SLOPE};

static const cli_option opt_in_normal = {
    .id = CLI_RENDER_OPT_IN_NORMAL,
    .long_name = "normal",
    .value_name = "FILE",
    .help = "baked normal map to light (instead of HEIGHT)"};
static const cli_option opt_in_ssbump = {.id = CLI_RENDER_OPT_IN_SSBUMP,
                                         .long_name = "ssbump",
                                         .value_name = "FILE",
                                         .help =
                                             "baked ssbump to light (instead of HEIGHT)"};
static const cli_option opt_in_ao = {.id = CLI_RENDER_OPT_IN_AO,
                                     .long_name = "ao",
                                     .value_name = "FILE",
                                     .help =
                                         "baked ambient occlusion (instead of HEIGHT)"};
static const cli_option opt_in_bent = {.id = CLI_RENDER_OPT_IN_BENT,
                                       .long_name = "bent",
                                       .value_name = "FILE",
                                       .default_text = "from the ssbump",
                                       .help = "baked bent normal for the specular"};
static const cli_option opt_in_slope = {
    .id = CLI_RENDER_OPT_IN_SLOPE,
    .long_name = "slope",
    .value_name = "FILE",
    .help = "baked flipcode slope map for --mode slope (instead of HEIGHT)"};
static const cli_option opt_albedo = {
    .id = CLI_RENDER_OPT_ALBEDO,
    .long_name = "albedo",
    .value_name = "FILE",
    .default_text = "white",
    .help = "colour map multiplying the diffuse light (same size as the maps)"};
static const cli_option opt_albedo_mode = {
    .id = CLI_RENDER_OPT_ALBEDO_MODE,
    .long_name = "albedo-mode",
    .value_name = "multiply|mod2x|ssbump",
    .default_text = "multiply",
    .help = "mod2x: 2 x albedo (0.5 is neutral); ssbump: a detail ssbump (height2ssbump "
            "-d) as albedo, x 2/3 (R + G + B)"};
static const cli_option opt_compare = {
    .id = CLI_RENDER_OPT_COMPARE,
    .long_name = "compare",
    .default_text = "off",
    .help = "four labelled panels: normal-mapped | ssbump | ssbump + specular | ao"};
static const cli_option opt_tile = {.id = CLI_RENDER_OPT_TILE,
                                    .long_name = "tile",
                                    .value_name = "N",
                                    .default_text = "1",
                                    .range_text = "1..8",
                                    .help = "repeat the render N x N, so seams show"};
static const cli_option opt_crop = {
    .id = CLI_RENDER_OPT_CROP,
    .long_name = "crop",
    .value_name = "X,Y,W,H",
    .default_text = "none",
    .help = "show only this window (texels of the tiled render), e.g. to zoom in"};
static const cli_option opt_orbit = {
    .id = CLI_RENDER_OPT_ORBIT,
    .long_name = "orbit",
    .value_name = "N",
    .default_text = "off",
    .range_text = "1..3600",
    .help = "N frames of the light circling at its elevation: OUT.gif animates at 10 "
            "frames/s, OUT.png/.exr writes OUT_000.png, ..."};

static const cli_option opt_view = {
    .id = CLI_RENDER_OPT_VIEW,
    .long_name = "view",
    .value_name = "AZ,EL",
    .default_text = "overhead",
    .range_text = "EL 1..90",
    .help = "a camera at azimuth AZ (as --light's) and elevation EL degrees, the "
            "surface tiling (270,30: from the bottom, receding up)"};
static const cli_option opt_relief = {
    .id = CLI_RENDER_OPT_RELIEF,
    .long_name = "relief",
    .default_text = "off",
    .help = "with --view and a HEIGHT: parallax occlusion mapping of the height, the "
            "maps read where each view ray meets it (shaders/ssbump_relief.glsl)"};

static const cli_option *const render_options[] = {
    &cli_opt_scale,
    &cli_opt_rays,
    &cli_opt_filter_radius,
    &cli_opt_filter_threshold,
    &cli_opt_bias,
    &cli_opt_power,
    &cli_opt_normal_filter,
    &cli_opt_normal_y,
    &cli_opt_threads,
    &cli_opt_clamp,
    &cli_opt_channel,
    &opt_in_normal,
    &opt_in_ssbump,
    &opt_in_ao,
    &opt_in_bent,
    &opt_in_slope,
    &cli_render_opt_mode,
    &cli_render_opt_light,
    &cli_render_opt_light_color,
    &cli_render_opt_lightmap,
    &cli_render_opt_specular,
    &cli_render_opt_specular_strength,
    &opt_albedo,
    &opt_albedo_mode,
    &opt_compare,
    &opt_tile,
    &opt_crop,
    &opt_orbit,
    &opt_view,
    &opt_relief,
    &cli_render_opt_output,
    &cli_opt_depth,
    &cli_render_opt_quiet,
    &cli_opt_help,
};

static const cli_command render_command = {
    "render",
    "(HEIGHT --scale S | --ssbump FILE | --normal FILE ...) -o OUT [OPTIONS]",
    "Lights the maps as Source does (static lightmaps, a dynamic light, specular from\n"
    "the bent normal) and writes the picture. From a HEIGHT the maps are baked first\n"
    "with bake's options; --normal/--ssbump/--ao/--bent read maps already baked\n"
    "(--normal-y up: those files are OpenGL-style).",
    render_options,
    (int)(sizeof render_options / sizeof render_options[0]),
    cli_settings_init,
};

typedef struct render_args {
  cli_settings settings;
  bb_render_options render;
  int light_given;
  const char *map_paths[BB_RENDER_MAP_COUNT];
  const char *height_path, *albedo_path, *output;
  int compare, orbit, quiet;
  int green_up; /* --normal-y up: the input normal and bent files */
} render_args;

static int parse_crop(render_args *a, const char *arg) {
  int v[4], n = 0;
  const char *p = arg;
  for (; n < 4; n++) {
    char *end = NULL;
    long x = strtol(p, &end, 10);
    if (end == p || x < 0 || x > BB_MAX_DIMENSION || (n < 3 ? *end != ',' : *end != '\0'))
      break;
    v[n] = (int)x;
    p = end + 1;
  }
  if (n < 4 || v[2] == 0 || v[3] == 0)
    return cli_usage_error(render_command.name,
                           "--crop needs X,Y,W,H: integers >= 0, W and H > 0 (got '%s')",
                           arg);
  a->render.crop_x = v[0];
  a->render.crop_y = v[1];
  a->render.crop_width = v[2];
  a->render.crop_height = v[3];
  return 0;
}

static int render_option(void *ctx, const cli_option *opt, const char *arg) {
  render_args *a = ctx;
  const char *cmd = render_command.name;
  int rc = cli_render_apply_lighting(cmd, &a->render, &a->light_given, opt, arg);
  if (rc >= 0)
    return rc;
  switch (opt->id) {
  case CLI_RENDER_OPT_IN_NORMAL:
  case CLI_RENDER_OPT_IN_SSBUMP:
  case CLI_RENDER_OPT_IN_AO:
  case CLI_RENDER_OPT_IN_BENT:
  case CLI_RENDER_OPT_IN_SLOPE:
    a->map_paths[opt->id - CLI_RENDER_OPT_IN_NORMAL] = arg;
    return 0;
  case CLI_RENDER_OPT_ALBEDO:
    a->albedo_path = arg;
    return 0;
  case CLI_RENDER_OPT_ALBEDO_MODE:
    if (bb_albedo_mode_parse(arg, &a->render.albedo_mode, NULL))
      return cli_usage_error(cmd, "--albedo-mode must be one of %s (got '%s')",
                             opt->value_name, arg);
    return 0;
  case CLI_RENDER_OPT_COMPARE:
    a->compare = 1;
    return 0;
  case CLI_RENDER_OPT_TILE:
    rc = cli_parse_int(cmd, "--tile", arg, 1, 8, &a->render.tile_x);
    a->render.tile_y = a->render.tile_x;
    return rc;
  case CLI_RENDER_OPT_CROP:
    return parse_crop(a, arg);
  case CLI_RENDER_OPT_ORBIT:
    return cli_parse_int(cmd, "--orbit", arg, 1, 3600, &a->orbit);
  case CLI_RENDER_OPT_VIEW: {
    char *end = NULL;
    const double az = strtod(arg, &end);
    const double el = end && *end == ',' ? strtod(end + 1, &end) : NAN;
    if (!end || *end != '\0' || !isfinite(az) || !(el >= 1.0 && el <= 90.0))
      return cli_usage_error(cmd, "--view needs AZ,EL: an azimuth and an elevation in "
                                  "1..90 degrees (got '%s')",
                             arg);
    a->render.view = 1, a->render.view_azimuth = az, a->render.view_elevation = el;
    return 0;
  }
  case CLI_RENDER_OPT_RELIEF:
    a->render.relief = 1;
    return 0;
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

/* The maps the picture reads: the mode's, or all three for --compare. */
static unsigned needed_maps(const render_args *a) {
  if (a->compare)
    return BB_RENDER_NEEDS_NORMAL | BB_RENDER_NEEDS_SSBUMP | BB_RENDER_NEEDS_AO;
  return bb_render_mode_needs(a->render.mode);
}

static int has_extension(const char *path, const char *ext) {
  const char *slash = strrchr(path, '/'), *dot = strrchr(slash ? slash + 1 : path, '.');
  return dot && strcasecmp(dot, ext) == 0;
}

/* Checks the inputs: a HEIGHT or the maps the picture needs, not both. */
static int check_inputs(const render_args *a) {
  const char *cmd = render_command.name;
  int any_map = 0;
  for (int m = 0; m < BB_RENDER_MAP_COUNT; m++)
    any_map |= a->map_paths[m] != NULL;
  if (a->height_path && any_map)
    return cli_usage_error(cmd,
                           "give a HEIGHT to bake or baked maps (--normal, --ssbump, "
                           "--ao, --bent, --slope), not both");
  if (a->render.relief && !a->render.view)
    return cli_usage_error(cmd, "--relief needs --view AZ,EL (from straight above a relief "
                                "shows nothing)");
  if (a->render.relief && !a->height_path)
    return cli_usage_error(cmd, "--relief reads the height: give a HEIGHT (and --scale)");
  if (a->height_path) {
    if (!a->settings.scale_given)
      return cli_usage_error(cmd, "--scale is required with a HEIGHT (texels of "
                                  "displacement per unit of height)");
    return 0;
  }
  if (!any_map)
    return cli_usage_error(cmd, "missing HEIGHT or baked maps (usage: bumpbake %s %s)",
                           cmd, render_command.synopsis);
  for (int m = 0; m < BB_RENDER_MAP_COUNT; m++)
    if ((needed_maps(a) & map_need[m]) && !a->map_paths[m])
      return cli_usage_error(cmd, "%s needs --%s FILE (or a HEIGHT to bake)",
                             a->compare ? "--compare"
                                        : bb_render_mode_name(a->render.mode),
                             bb_render_map_name((bb_render_map)m));
  return 0;
}

/* The files the picture will be: one, an orbit's frames, or one GIF. */
static int output_specs(const render_args *a, bb_output_spec **specs, char ***frames, int *n) {
  *n = a->orbit && !has_extension(a->output, ".gif") ? a->orbit : 1;
  *specs = calloc((size_t)*n, sizeof **specs);
  *frames = calloc((size_t)*n, sizeof **frames);
  if (!*specs || !*frames) {
    cli_file_error(a->output, "out of memory");
    return BB_EXIT_FAILURE;
  }
  for (int f = 0; f < *n; f++) {
    const char *path = a->output;
    if (*n > 1 || (a->orbit && !has_extension(a->output, ".gif"))) {
      if (!((*frames)[f] = bb_render_frame_path(a->output, f, a->orbit))) {
        cli_file_error(a->output, "out of memory");
        return BB_EXIT_FAILURE;
      }
      path = (*frames)[f];
    }
    /* A GIF is written by the animation writer, not bb_image_write: its
     * name is checked as a file, its format here. */
    (*specs)[f] = (bb_output_spec){path, a->compare ? "comparison" : "render", 0,
                                   a->settings.depth, 0, has_extension(path, ".gif"),
                                   0, 0, BB_RANGE_UNIT, NULL};
  }
  return 0;
}

/* Checks the output before any work: against every file the render reads
 * (the height or the maps, and the albedo), and every frame of an orbit. */
static int check_output(const render_args *a) {
  const char *cmd = render_command.name;
  if (!a->output)
    return cli_usage_error(cmd, "-o OUT is required");
  if (a->orbit && !a->render.dynamic_light)
    return cli_usage_error(cmd, "--orbit circles the dynamic light: give --light");
  if (has_extension(a->output, ".gif")) {
    if (!a->orbit)
      return cli_usage_error(cmd, "%s: GIF is for --orbit animations; use .png or .exr",
                             a->output);
    if (a->settings.depth != BB_DEPTH_DEFAULT && a->settings.depth != BB_DEPTH_8)
      return cli_usage_error(cmd, "%s: GIF files are 8-bit", a->output);
  }
  const char *reads[BB_RENDER_MAP_COUNT + 2];
  int n_reads = 0;
  for (int m = 0; m < BB_RENDER_MAP_COUNT; m++)
    if (a->map_paths[m])
      reads[n_reads++] = a->map_paths[m];
  if (a->height_path)
    reads[n_reads++] = a->height_path;
  if (a->albedo_path)
    reads[n_reads++] = a->albedo_path;
  bb_output_spec *specs = NULL;
  char **frames = NULL;
  int n = 0;
  int rc = output_specs(a, &specs, &frames, &n);
  if (!rc) {
    bb_error err = {{0}};
    bb_status st = bb_outputs_check(specs, n, reads, n_reads, &err);
    rc = st == BB_OK ? 0 : cli_library_error(cmd, st, &err);
  }
  for (int f = 0; frames && f < n; f++)
    free(frames[f]);
  free(frames);
  free(specs);
  return rc;
}

static int render_parse(int argc, char **argv, render_args *a) {
  int first = 0;
  int rc = cli_parse_options(&render_command, argc, argv, render_option, a, &first);
  if (rc)
    return rc;
  if (argc - first > 1)
    return cli_usage_error(render_command.name,
                           "unexpected argument '%s' (expected at most "
                           "one HEIGHT)",
                           argv[first + 1]);
  a->height_path = argc - first == 1 ? argv[first] : NULL;
  /* --normal-y describes input files; a bake on the fly stays +Y down. */
  a->green_up = a->settings.bake.normal_y_up;
  a->settings.bake.normal_y_up = 0;
  a->render.threads = a->settings.bake.trace.threads;
  rc = check_inputs(a);
  return rc ? rc : check_output(a);
}

/* ------------------------------------------------------------------ maps */

/* Everything a picture is made from, and what the provenance says of it. */
typedef struct render_inputs {
  bb_image height;
  bb_height_source source; /* the height's, when one was baked */
  bb_bake_result bake;
  bb_image maps[BB_RENDER_MAP_COUNT]; /* read from files */
  bb_image albedo;
  bb_image slope;      /* made from the bake's filtered height for --mode slope */
  bb_render_maps view; /* pointers into the above */
  bb_render_sources sources;
  const char *input;   /* the file the provenance's input keys describe */
  uint64_t input_hash;
} render_inputs;

static void inputs_free(render_inputs *in) {
  bb_image_free(&in->height);
  bb_bake_result_free(&in->bake);
  for (int m = 0; m < BB_RENDER_MAP_COUNT; m++)
    bb_image_free(&in->maps[m]);
  bb_image_free(&in->albedo);
  bb_image_free(&in->slope);
}

/* The maps a bake on the fly makes: the normal always (every mode lights
 * with it), the filtered height for the slope map and --relief, and the
 * traced maps when the view needs one. */
static unsigned baked_outputs(const render_args *a) {
  const int traced = (needed_maps(a) & (BB_RENDER_NEEDS_SSBUMP | BB_RENDER_NEEDS_AO)) != 0;
  return BB_OUTPUT_BIT(BB_OUTPUT_NORMAL) | BB_OUTPUT_BIT(BB_OUTPUT_FILTERED) |
         (traced ? BB_OUTPUTS_TRACED : 0u);
}

/* Before any pixel is read, from the files' headers (bb_render_files_check):
 * the maps' size, the picture the options make of it, and the memory the
 * whole render takes against what is left. A tile or crop this input
 * cannot take is a usage error. */
static int check_files(render_args *a) {
  bb_render_sources files;
  memset(&files, 0, sizeof files);
  for (int m = 0; m < BB_RENDER_MAP_COUNT; m++)
    files.maps[m] = a->map_paths[m];
  files.height = a->height_path;
  files.albedo = a->albedo_path;
  a->settings.bake.outputs = baked_outputs(a);
  int w = 0, h = 0;
  bb_error err = {{0}}, why = {{0}};
  bb_status st = bb_render_files_check(&files, &a->settings.bake, &a->render, a->compare,
                                       a->output, a->settings.depth, &w, &h, &err);
  if (st == BB_OK)
    return 0;
  if (w > 0 && bb_render_estimate(w, h, &a->render, a->compare, NULL, BB_DEPTH_DEFAULT, NULL,
                                  NULL, NULL, &why) != BB_OK)
    return cli_usage_error(render_command.name, "%s", why.message);
  cli_error_line(err.message[0] ? err.message : bb_status_name(st));
  return BB_EXIT_FAILURE;
}

static int load_maps(const render_args *a, render_inputs *in) {
  const bb_image *size = NULL;
  in->sources.maps_normal_y_up = a->green_up;
  for (int m = 0; m < BB_RENDER_MAP_COUNT; m++) {
    if (!a->map_paths[m])
      continue;
    bb_error err = {{0}};
    uint64_t hash = 0;
    bb_status st = bb_render_map_read(a->map_paths[m], (bb_render_map)m, a->green_up, size,
                                      &in->maps[m], &hash, &err);
    if (st != BB_OK)
      return cli_status_exit(a->map_paths[m], st, &err);
    in->sources.maps[m] = a->map_paths[m];
    if (!in->input) {
      in->input = a->map_paths[m];
      in->input_hash = hash;
    }
    if (!size)
      size = &in->maps[m];
  }
  in->view.normal = in->maps[BB_RENDER_MAP_NORMAL].pixels ? &in->maps[BB_RENDER_MAP_NORMAL] : NULL;
  in->view.ssbump = in->maps[BB_RENDER_MAP_SSBUMP].pixels ? &in->maps[BB_RENDER_MAP_SSBUMP] : NULL;
  in->view.ao = in->maps[BB_RENDER_MAP_AO].pixels ? &in->maps[BB_RENDER_MAP_AO] : NULL;
  in->view.bent = in->maps[BB_RENDER_MAP_BENT].pixels ? &in->maps[BB_RENDER_MAP_BENT] : NULL;
  in->view.slope = in->maps[BB_RENDER_MAP_SLOPE].pixels ? &in->maps[BB_RENDER_MAP_SLOPE] : NULL;
  return 0;
}

static int bake_height(render_args *a, render_inputs *in) {
  bb_error err = {{0}};
  bb_status st = bb_height_file_read(a->height_path, a->settings.channel,
                                     a->settings.bake.height_scale, cli_note, NULL, &in->height,
                                     &in->source, &err);
  int rc = cli_status_exit(a->height_path, st, &err);
  if (rc)
    return rc;
  a->settings.bake.outputs = baked_outputs(a);
  cli_progress progress;
  cli_progress_attach(&progress, "render", a->quiet, &a->settings.bake.trace);
  st = bb_bake(&in->height, &a->settings.bake, &in->bake, &err);
  cli_progress_finish(&progress);
  if (st != BB_OK)
    return cli_status_exit(a->height_path, st, &err);
  in->input = a->height_path;
  in->input_hash = in->source.height_hash;
  in->sources.height = a->height_path;
  bb_bake_result *r = &in->bake;
  a->render.relief_height = &r->filtered; /* --relief: the height as baked */
  a->render.relief_depth = (double)a->settings.bake.height_scale;
  in->view = (bb_render_maps){&r->normal, r->ssbump.pixels ? &r->ssbump : NULL,
                              r->ao.pixels ? &r->ao : NULL,
                              r->bent.pixels ? &r->bent : NULL, NULL, NULL};
  if (needed_maps(a) & BB_RENDER_NEEDS_SLOPE) {
    /* The slope map bake --slope would write, from the same filtered height. */
    st = bb_slope_map(&r->filtered, a->settings.bake.height_scale,
                      a->settings.bake.smooth.addressing, &in->slope, &err);
    if (st != BB_OK)
      return cli_status_exit(a->height_path, st, &err);
    in->view.slope = &in->slope;
  }
  return 0;
}

static int load_albedo(const render_args *a, render_inputs *in) {
  if (!a->albedo_path)
    return 0;
  bb_error err = {{0}};
  bb_status st = bb_image_read(a->albedo_path, &in->albedo, NULL, &err);
  if (st != BB_OK)
    return cli_status_exit(a->albedo_path, st, &err);
  const bb_image *size = in->view.normal ? in->view.normal : in->view.ssbump;
  if (size && (in->albedo.width != size->width || in->albedo.height != size->height)) {
    char reason[128];
    snprintf(reason, sizeof reason, "albedo is %dx%d, but the maps are %dx%d",
             in->albedo.width, in->albedo.height, size->width, size->height);
    cli_file_error(a->albedo_path, reason);
    return BB_EXIT_FAILURE;
  }
  in->view.albedo = &in->albedo;
  in->sources.albedo = a->albedo_path;
  in->sources.albedo_hash = bb_image_hash(&in->albedo);
  return 0;
}

/* -------------------------------------------------------------- pictures */

/* One picture (a render or the comparison) with the light at azimuth. */
static int make_picture(const render_args *a, const render_inputs *in, double azimuth,
                        bb_image *out, int *labels_drawn) {
  bb_render_options o = a->render;
  o.light_azimuth = azimuth;
  bb_error err = {{0}};
  bb_status st;
  *labels_drawn = 1;
  if (a->compare) {
    bb_panel_layout layout;
    bb_panel_layout_init(&layout);
    st = bb_render_compare(&in->view, &o, &layout, out, labels_drawn, &err);
  } else {
    st = bb_render(&in->view, &o, out, &err);
  }
  if (st == BB_OK)
    return 0;
  /* The maps were checked as they were read, so what is left is the view
   * (a crop outside the picture) or memory. */
  if (st == BB_ERR_ARGUMENT)
    return cli_usage_error(render_command.name, "%s", err.message);
  return cli_status_exit(a->output, st, &err);
}

/* The provenance of one picture: the input's keys, the bake's when a
 * height was baked, then the render's (bb_render_provenance). */
static char *describe(const render_args *a, const char *command_line, const render_inputs *in,
                      double azimuth, int frame) {
  bb_render_options o = a->render;
  o.light_azimuth = azimuth;
  bb_render_sources sources = in->sources;
  sources.frame = frame;
  sources.frames = a->orbit;
  char *extra = bb_render_provenance(&sources, &o);
  if (!extra)
    return NULL;
  const char *slash = strrchr(in->input, '/');
  const int baked = a->height_path != NULL;
  const int traced = baked && (a->settings.bake.outputs & BB_OUTPUTS_TRACED);
  bb_provenance p = {command_line,
                     slash ? slash + 1 : in->input,
                     in->input_hash,
                     a->compare ? "render-compare" : "render",
                     baked ? &a->settings.bake : NULL,
                     baked ? a->settings.channel : BB_CHANNEL_AUTO,
                     traced ? in->bake.rayset_id : NULL,
                     baked ? in->source.file_hash : 0,
                     extra};
  char *text = bb_provenance_format(&p);
  free(extra);
  return text;
}

/* Encodes one picture under a temporary name; the caller commits it. */
static int stage_picture(const render_args *a, const char *command_line,
                         const render_inputs *in, double azimuth, int frame, const char *path,
                         int *labels, bb_staged_file **staged) {
  bb_image picture = {0};
  int rc = make_picture(a, in, azimuth, &picture, labels);
  char *text = rc ? NULL : describe(a, command_line, in, azimuth, frame);
  if (!rc && !text) {
    cli_file_error(path, "out of memory");
    rc = BB_EXIT_FAILURE;
  }
  if (!rc) {
    const bb_write_options wo = {a->settings.depth, BB_RANGE_UNIT, text, NULL};
    bb_error err = {{0}};
    rc = cli_status_exit(path, bb_image_write_staged(path, &picture, &wo, staged, &err), &err);
  }
  free(text);
  bb_image_free(&picture);
  return rc;
}

static double frame_azimuth(const render_args *a, int frame) {
  return a->render.light_azimuth + 360.0 * frame / (a->orbit ? a->orbit : 1);
}

/* The picture, or every frame of an orbit, staged one by one (a frame in
 * memory at a time) and then put in place together: an orbit interrupted
 * or failed leaves the old frames, all of them. */
static int write_pictures(const render_args *a, const char *command_line,
                          const render_inputs *in, int *labels) {
  const int n = a->orbit ? a->orbit : 1;
  bb_staged_file **staged = calloc((size_t)n, sizeof *staged);
  char **paths = calloc((size_t)n, sizeof *paths);
  const char **kinds = calloc((size_t)n, sizeof *kinds);
  int rc = staged && paths && kinds ? 0 : BB_EXIT_FAILURE;
  if (rc)
    cli_file_error(a->output, "out of memory");
  for (int f = 0; f < n && !rc; f++) {
    paths[f] = a->orbit ? bb_render_frame_path(a->output, f, a->orbit) : strdup(a->output);
    kinds[f] = a->compare ? "comparison" : "render";
    rc = paths[f] ? stage_picture(a, command_line, in, frame_azimuth(a, f), f, paths[f],
                                  labels, &staged[f])
                  : BB_EXIT_FAILURE;
  }
  if (!rc) {
    bb_error err = {{0}};
    bb_status st = bb_staged_files_commit(staged, kinds, n, &err);
    if (st != BB_OK) {
      cli_error_line(err.message);
      rc = BB_EXIT_FAILURE;
    }
  }
  for (int f = 0; staged && f < n; f++)
    bb_staged_file_discard(staged[f]);
  if (!rc && !a->quiet && !a->orbit)
    cli_printf_line("wrote %s %s", a->compare ? "comparison" : "render", a->output);
  else if (!rc && !a->quiet)
    cli_printf_line("wrote %d frames %s%s%s", a->orbit, paths[0], n > 1 ? " .. " : "",
                    n > 1 ? paths[n - 1] : "");
  for (int f = 0; paths && f < n; f++)
    free(paths[f]);
  free(paths);
  free(kinds);
  free(staged);
  return rc;
}

static int write_gif(const render_args *a, const render_inputs *in, int *labels) {
  bb_animation *anim = NULL;
  bb_error err = {{0}};
  int rc = 0;
  for (int f = 0; f < a->orbit && !rc; f++) {
    bb_image picture = {0};
    rc = make_picture(a, in, frame_azimuth(a, f), &picture, labels);
    bb_status st = BB_OK;
    if (!rc && !anim)
      st = bb_animation_open(a->output, picture.width, picture.height, 10.0, &anim, &err);
    if (!rc && st == BB_OK)
      st = bb_animation_add_frame(anim, &picture, &err);
    if (!rc && st != BB_OK)
      rc = cli_status_exit(a->output, st, &err);
    bb_image_free(&picture);
  }
  if (rc) {
    bb_animation_abort(anim);
    return rc;
  }
  rc = cli_status_exit(a->output, bb_animation_close(anim, &err), &err);
  if (!rc && !a->quiet)
    cli_printf_line("wrote orbit %s (%d frames)", a->output, a->orbit);
  return rc;
}

static int render_run(const char *command_line, render_args *a) {
  render_inputs in;
  memset(&in, 0, sizeof in);
  int rc = check_files(a);
  if (rc)
    return rc;
  rc = a->height_path ? bake_height(a, &in) : load_maps(a, &in);
  if (!rc)
    rc = load_albedo(a, &in);
  int labels = 1;
  if (!rc && a->orbit && has_extension(a->output, ".gif"))
    rc = write_gif(a, &in, &labels);
  else if (!rc)
    rc = write_pictures(a, command_line, &in, &labels);
  if (!rc && !labels)
    cli_render_no_font_note(render_command.name);
  inputs_free(&in);
  return rc;
}

int bb_cli_render(int argc, char **argv) {
  char *command_line = cli_command_line(argc, argv); /* before getopt permutes argv */
  if (!command_line)
    return BB_EXIT_FAILURE;
  render_args a;
  memset(&a, 0, sizeof a);
  cli_settings_init(&a.settings);
  bb_render_options_init(&a.render);
  int rc = render_parse(argc, argv, &a);
  if (rc < 0)
    rc = BB_EXIT_OK; /* --help */
  else if (rc == 0)
    rc = render_run(command_line, &a);
  free(command_line);
  return rc;
}
