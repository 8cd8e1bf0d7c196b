/* cli_render.c: `bumpbake render`, the maps lit as Source lights them, from a
 * height map (baked on the fly) or from maps already baked; one picture, the
 * paper's four-panel comparison, or an orbit of the light. */
#define _XOPEN_SOURCE 700 /* realpath */

#include "render_common.h"

#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

/* The baked maps render can read instead of a height, in this order. */
enum { MAP_NORMAL, MAP_SSBUMP, MAP_AO, MAP_BENT, MAP_SLOPE, MAP_COUNT };

static const struct {
  const char *name; /* option name and provenance key */
  unsigned need;    /* BB_RENDER_NEEDS_* bit, 0 for optional maps */
  int channels;     /* at least */
  int is_vector;    /* decoded as a normal map */
  const char *channels_why;
} map_kinds[MAP_COUNT] = {
    {"normal", BB_RENDER_NEEDS_NORMAL, 3, 1, "X, Y, Z"},
    {"ssbump", BB_RENDER_NEEDS_SSBUMP, 3, 0, "R, G, B = the basis B0, B1, B2"},
    {"ao", BB_RENDER_NEEDS_AO, 1, 0, "grey"},
    {"bent", 0, 3, 1, "X, Y, Z"},
    {"slope", BB_RENDER_NEEDS_SLOPE, 1, 0, "flipcode's slope byte, as bake --slope writes"},
};

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
  const char *map_paths[MAP_COUNT];
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
  for (int m = 0; m < MAP_COUNT; m++)
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
  for (int m = 0; m < MAP_COUNT; m++)
    if ((needed_maps(a) & map_kinds[m].need) && !a->map_paths[m])
      return cli_usage_error(cmd, "%s needs --%s FILE (or a HEIGHT to bake)",
                             a->compare ? "--compare"
                                        : bb_render_mode_name(a->render.mode),
                             map_kinds[m].name);
  return 0;
}

/* 1 when a and b are the same existing file. */
static int same_existing_file(const char *a, const char *b) {
  char ra[PATH_MAX], rb[PATH_MAX];
  return realpath(a, ra) && realpath(b, rb) && strcmp(ra, rb) == 0;
}

static int check_output(const render_args *a) {
  const char *cmd = render_command.name;
  const char *input = a->height_path;
  for (int m = 0; m < MAP_COUNT && !input; m++)
    input = a->map_paths[m];
  if (!a->output)
    return cli_usage_error(cmd, "-o OUT is required");
  if (a->orbit && !a->render.dynamic_light)
    return cli_usage_error(cmd, "--orbit circles the dynamic light: give --light");
  if (!has_extension(a->output, ".gif"))
    return cli_check_output(cmd, input, a->output, a->settings.depth);
  if (!a->orbit)
    return cli_usage_error(cmd, "%s: GIF is for --orbit animations; use .png or .exr",
                           a->output);
  if (a->settings.depth != BB_DEPTH_DEFAULT && a->settings.depth != BB_DEPTH_8)
    return cli_usage_error(cmd, "%s: GIF files are 8-bit", a->output);
  /* The directory check of cli_check_output, on a .png twin of the name. */
  size_t len = strlen(a->output);
  char twin[PATH_MAX];
  if (len >= sizeof twin)
    return cli_usage_error(cmd, "%s: path too long", a->output);
  memcpy(twin, a->output, len - 4);
  strcpy(twin + len - 4, ".png");
  for (int m = 0; m < MAP_COUNT + 1; m++) {
    const char *in = m < MAP_COUNT ? a->map_paths[m] : a->height_path;
    if (in && same_existing_file(in, a->output)) {
      cli_file_error(a->output, "output would overwrite the input file");
      return BB_EXIT_FAILURE;
    }
  }
  return cli_check_output(cmd, input, twin, BB_DEPTH_DEFAULT);
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
  bb_bake_result bake;
  bb_image maps[MAP_COUNT]; /* read from files */
  bb_image albedo;
  bb_image slope;      /* made from the bake's filtered height for --mode slope */
  bb_render_maps view; /* pointers into the above */
  char *extra;         /* provenance lines about the inputs, malloc'd */
} render_inputs;

static void inputs_free(render_inputs *in) {
  bb_image_free(&in->height);
  bb_bake_result_free(&in->bake);
  for (int m = 0; m < MAP_COUNT; m++)
    bb_image_free(&in->maps[m]);
  bb_image_free(&in->albedo);
  bb_image_free(&in->slope);
  free(in->extra);
}

/* Appends "key=value\n" to in->extra; 0, or BB_EXIT_FAILURE when out of memory. */
static int add_line(render_inputs *in, const char *key, const char *value) {
  size_t old = in->extra ? strlen(in->extra) : 0, add = strlen(key) + strlen(value) + 2;
  char *grown = realloc(in->extra, old + add + 1);
  if (!grown) {
    fprintf(stderr, "bumpbake: out of memory\n");
    return BB_EXIT_FAILURE;
  }
  snprintf(grown + old, add + 1, "%s=%s\n", key, value);
  in->extra = grown;
  return 0;
}

static const char *file_name_of(const char *path) {
  const char *slash = strrchr(path, '/');
  return slash ? slash + 1 : path;
}

/* Reads one map file and decodes it; the size must match *size when set. */
static int read_map(const char *path, int kind, int green_up, const bb_image **size,
                    bb_image *out) {
  bb_image raw = {0};
  bb_image_info info;
  bb_error err = {{0}};
  bb_status st = cli_read_image(path, &raw, &info, &err);
  if (st != BB_OK)
    return cli_status_exit(path, st, &err);
  int is_float = info.is_float;
  int rc = kind == MAP_SSBUMP ? cli_check_hl2_map(path, &raw, &info) : 0;
  bb_image_info_free(&info);
  if (rc) {
    bb_image_free(&raw);
    return rc;
  }
  char reason[256];
  if (raw.channels < map_kinds[kind].channels) {
    snprintf(reason, sizeof reason, "%d channel%s; %s %s map needs %d (%s)", raw.channels,
             raw.channels == 1 ? "" : "s",
             (kind == MAP_AO || kind == MAP_SSBUMP) ? "an" : "a", map_kinds[kind].name,
             map_kinds[kind].channels, map_kinds[kind].channels_why);
  } else if (*size && (raw.width != (*size)->width || raw.height != (*size)->height)) {
    snprintf(reason, sizeof reason, "%dx%d, but the other maps are %dx%d", raw.width,
             raw.height, (*size)->width, (*size)->height);
  } else {
    reason[0] = '\0';
  }
  if (reason[0]) {
    bb_image_free(&raw);
    cli_file_error(path, reason);
    return BB_EXIT_FAILURE;
  }
  if (map_kinds[kind].is_vector) {
    bb_normal_decode_options decode;
    bb_normal_decode_options_init(&decode);
    decode.normal_y_up = green_up;
    st = bb_normal_map_decode(&raw, is_float, &decode, out, &err);
    bb_image_free(&raw);
    if (st != BB_OK)
      return cli_status_exit(path, st, &err);
  } else {
    *out = raw;
  }
  if (!*size)
    *size = out;
  return 0;
}

/* A crop must fit the tiled picture: checked once the size is known, before
 * any baking. */
static int check_view(const render_args *a, const bb_image *size) {
  const bb_render_options *o = &a->render;
  long w = (long)size->width * o->tile_x, h = (long)size->height * o->tile_y;
  if (w > BB_MAX_DIMENSION || h > BB_MAX_DIMENSION || w * h > BB_MAX_PIXELS)
    return cli_usage_error(
        render_command.name,
        "--tile %d makes a %ldx%ld picture, over the maximum (%ld texels)", o->tile_x, w,
        h, (long)BB_MAX_PIXELS);
  if (o->crop_width > 0 &&
      ((long)o->crop_x + o->crop_width > w || (long)o->crop_y + o->crop_height > h))
    return cli_usage_error(render_command.name,
                           "--crop %d,%d,%d,%d is not inside the %ldx%ld picture",
                           o->crop_x, o->crop_y, o->crop_width, o->crop_height, w, h);
  return 0;
}

static int load_maps(const render_args *a, cli_run *run, render_inputs *in) {
  const bb_image *size = NULL;
  int rc = add_line(in, "render_from", "maps");
  if (!rc && (a->map_paths[MAP_NORMAL] || a->map_paths[MAP_BENT]))
    rc = add_line(in, "map_normal_y", a->green_up ? "up" : "down");
  for (int m = 0; m < MAP_COUNT && !rc; m++) {
    if (!a->map_paths[m])
      continue;
    rc = read_map(a->map_paths[m], m, a->green_up, &size, &in->maps[m]);
    if (!rc) {
      char key[32];
      snprintf(key, sizeof key, "map_%s", map_kinds[m].name);
      rc = add_line(in, key, file_name_of(a->map_paths[m]));
    }
    if (!rc && !run->input_path) {
      run->input_path = a->map_paths[m];
      run->input_hash = bb_image_hash(&in->maps[m]);
    }
  }
  if (!rc)
    rc = check_view(a, size);
  if (rc)
    return rc;
  in->view.normal = in->maps[MAP_NORMAL].pixels ? &in->maps[MAP_NORMAL] : NULL;
  in->view.ssbump = in->maps[MAP_SSBUMP].pixels ? &in->maps[MAP_SSBUMP] : NULL;
  in->view.ao = in->maps[MAP_AO].pixels ? &in->maps[MAP_AO] : NULL;
  in->view.bent = in->maps[MAP_BENT].pixels ? &in->maps[MAP_BENT] : NULL;
  in->view.slope = in->maps[MAP_SLOPE].pixels ? &in->maps[MAP_SLOPE] : NULL;
  return 0;
}

static int bake_height(render_args *a, cli_run *run, render_inputs *in) {
  int rc = cli_load_height(a->height_path, &a->settings, &in->height);
  if (!rc)
    rc = check_view(a, &in->height);
  if (rc)
    return rc;
  /* The normal always (every mode lights with it), the filtered height for
   * the slope map, and the traced maps when the view needs one. */
  const int traced = (needed_maps(a) & (BB_RENDER_NEEDS_SSBUMP | BB_RENDER_NEEDS_AO)) != 0;
  a->settings.bake.outputs =
      BB_OUTPUT_BIT(BB_OUTPUT_NORMAL) | BB_OUTPUT_BIT(BB_OUTPUT_FILTERED) |
      (traced ? BB_OUTPUTS_TRACED : 0u);
  cli_progress progress;
  cli_progress_attach(&progress, "render", a->quiet, &a->settings.bake.trace);
  rc = cli_run_bake(a->height_path, &in->height, &a->settings.bake, &in->bake);
  cli_progress_finish(&progress);
  if (rc)
    return rc;
  cli_run_set_input(run, a->height_path, &in->height, &a->settings);
  run->rayset_id = traced ? in->bake.rayset_id : NULL;
  bb_bake_result *r = &in->bake;
  a->render.relief_height = &r->filtered; /* --relief: the height as baked */
  a->render.relief_depth = (double)a->settings.bake.height_scale;
  in->view = (bb_render_maps){&r->normal, r->ssbump.pixels ? &r->ssbump : NULL,
                              r->ao.pixels ? &r->ao : NULL,
                              r->bent.pixels ? &r->bent : NULL, NULL, NULL};
  if (needed_maps(a) & BB_RENDER_NEEDS_SLOPE) {
    /* The slope map bake --slope would write, from the same filtered height. */
    bb_error err = {{0}};
    bb_status st = bb_slope_map(&r->filtered, a->settings.bake.height_scale,
                                a->settings.bake.smooth.addressing, &in->slope, &err);
    if (st != BB_OK)
      return cli_status_exit(a->height_path, st, &err);
    in->view.slope = &in->slope;
  }
  return add_line(in, "render_from", "height");
}

static int load_albedo(const render_args *a, render_inputs *in) {
  if (!a->albedo_path)
    return 0;
  bb_error err = {{0}};
  bb_status st = cli_read_image(a->albedo_path, &in->albedo, NULL, &err);
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
  char hash[32];
  snprintf(hash, sizeof hash, "%016llx", (unsigned long long)bb_image_hash(&in->albedo));
  int rc = add_line(in, "albedo", file_name_of(a->albedo_path));
  return rc ? rc : add_line(in, "albedo_hash", hash);
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

/* Provenance lines of one picture: the inputs', then the options'. */
static char *picture_lines(const render_args *a, const render_inputs *in, double azimuth,
                           int frame) {
  bb_render_options o = a->render;
  o.light_azimuth = azimuth;
  char *opts = bb_render_options_describe(&o);
  if (!opts)
    return NULL;
  char head[64] = "";
  if (a->orbit)
    snprintf(head, sizeof head, "frame=%d/%d\n", frame, a->orbit);
  size_t len = strlen(in->extra) + strlen(opts) + strlen(head) + 1;
  char *all = malloc(len);
  if (all)
    snprintf(all, len, "%s%s%s", in->extra, opts, head);
  free(opts);
  return all;
}

static int write_picture(const render_args *a, const cli_run *run,
                         const render_inputs *in, double azimuth, int frame,
                         const char *path, const bb_image *img) {
  char *extra = picture_lines(a, in, azimuth, frame);
  if (!extra) {
    cli_file_error(path, "out of memory");
    return BB_EXIT_FAILURE;
  }
  const bb_bake_options *bake = a->height_path ? &a->settings.bake : NULL;
  int rc = cli_render_write(run, bake, extra, a->compare ? "render-compare" : "render",
                            path, img, a->settings.depth);
  free(extra);
  return rc;
}

/* OUT_007.png for frame 7 of OUT.png; four digits past 1000 frames (--orbit
 * stops at 3600). */
static char *frame_path(const char *output, int frame, int frames) {
  const char *slash = strrchr(output, '/');
  const char *dot = strrchr(slash ? slash + 1 : output, '.');
  size_t stem = dot ? (size_t)(dot - output) : strlen(output);
  size_t len = strlen(output) + 8;
  char *path = malloc(len);
  if (path)
    snprintf(path, len, frames > 1000 ? "%.*s_%04d%s" : "%.*s_%03d%s", (int)stem, output,
             frame % 10000, dot ? dot : "");
  return path;
}

static double frame_azimuth(const render_args *a, int frame) {
  return a->render.light_azimuth + 360.0 * frame / (a->orbit ? a->orbit : 1);
}

static int write_single(const render_args *a, const cli_run *run, const render_inputs *in,
                        int *labels) {
  bb_image picture = {0};
  int rc = make_picture(a, in, a->render.light_azimuth, &picture, labels);
  if (!rc)
    rc = write_picture(a, run, in, a->render.light_azimuth, 0, a->output, &picture);
  bb_image_free(&picture);
  if (!rc && !a->quiet)
    printf("wrote %s %s\n", a->compare ? "comparison" : "render", a->output);
  return rc;
}

static int write_frames(const render_args *a, const cli_run *run, const render_inputs *in,
                        int *labels) {
  int rc = 0;
  char *first = NULL, *last = NULL;
  for (int f = 0; f < a->orbit && !rc; f++) {
    bb_image picture = {0};
    char *path = frame_path(a->output, f, a->orbit);
    rc = path ? make_picture(a, in, frame_azimuth(a, f), &picture, labels)
              : BB_EXIT_FAILURE;
    if (!rc)
      rc = write_picture(a, run, in, frame_azimuth(a, f), f, path, &picture);
    bb_image_free(&picture);
    if (f == 0)
      first = path;
    else {
      free(last);
      last = path;
    }
  }
  if (!rc && !a->quiet)
    printf("wrote %d frames %s%s%s\n", a->orbit, first, last ? " .. " : "",
           last ? last : "");
  free(first);
  free(last);
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
    printf("wrote orbit %s (%d frames)\n", a->output, a->orbit);
  return rc;
}

static int render_run(cli_run *run, render_args *a) {
  render_inputs in;
  memset(&in, 0, sizeof in);
  int rc = a->height_path ? bake_height(a, run, &in) : load_maps(a, run, &in);
  if (!rc)
    rc = load_albedo(a, &in);
  int labels = 1;
  if (!rc && !a->orbit)
    rc = write_single(a, run, &in, &labels);
  else if (!rc && has_extension(a->output, ".gif"))
    rc = write_gif(a, &in, &labels);
  else if (!rc)
    rc = write_frames(a, run, &in, &labels);
  if (!rc && !labels)
    cli_render_no_font_note(render_command.name);
  inputs_free(&in);
  return rc;
}

int bb_cli_render(int argc, char **argv) {
  cli_run run;
  if (cli_run_init(&run, argc, argv)) /* before getopt permutes argv */
    return BB_EXIT_FAILURE;
  render_args a;
  memset(&a, 0, sizeof a);
  cli_settings_init(&a.settings);
  bb_render_options_init(&a.render);
  int rc = render_parse(argc, argv, &a);
  if (rc < 0)
    rc = BB_EXIT_OK; /* --help */
  else if (rc == 0)
    rc = render_run(&run, &a);
  cli_run_free(&run);
  return rc;
}
