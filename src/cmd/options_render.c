/* options_render.c: the options of the commands that light maps (render
 * and sheet), each described once, and those two commands with their
 * rules. */
#include "cmd/cmd_internal.h"
#include "core/file_names.h"
#include "job/job_internal.h"
#include "render/render_internal.h"
#include "core/internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#define AT(member) offsetof(bb_command_options, member)
#define RECORDED BB_OPTION_RECORDED

/* The ranges of render's and sheet's own options, whose values no struct of
 * the library holds (their one home). */
static const bb__range range_orbit = {"orbit", 1, 3600, 0, 1};
static const bb__range range_panel_size = {"panel size", 16, 4096, 0, 1};

/* ----------------------------------------------------------- set & print */

/* --lightmap basis|R,G,B,R,G,B,R,G,B: the static light (on). */
static bb_status set_lightmap(bb_command *c, const bb__option *o, const char *text,
                              double *values, int *count, bb_error *err) {
  bb_render_options *r = &c->options.render;
  *count = 0;
  if (strcmp(text, "basis") == 0) {
    for (int l = 0; l < 3; l++)
      for (int k = 0; k < 3; k++)
        r->lightmap[l][k] = l == k ? 1.0f : 0.0f;
  } else {
    double v[9];
    char name[80];
    bb__option_spelling(o, name, sizeof name);
    const char *p = text;
    for (int i = 0; i < 9; i++) {
      char *end = NULL;
      v[i] = strtod(p, &end);
      if (end == p || !isfinite(v[i]) || (i == 8 ? *end != '\0' : *end != ','))
        return bb__fail(err, BB_ERR_ARGUMENT, "%s needs basis or 9 comma-separated numbers "
                        "(got '%.64s')", name, text);
      p = end + 1;
    }
    for (int i = 0; i < 9; i++) {
      r->lightmap[i / 3][i % 3] = (float)v[i];
      values[i < BB__MAX_NUMBERS ? i : BB__MAX_NUMBERS - 1] = v[i];
    }
    /* every colour in range: the largest and the smallest stand for all */
    double lo = v[0], hi = v[0];
    for (int i = 1; i < 9; i++)
      lo = v[i] < lo ? v[i] : lo, hi = v[i] > hi ? v[i] : hi;
    values[0] = lo, values[1] = hi;
    *count = 2;
  }
  r->static_light = 1;
  return BB_OK;
}

static void print_lightmap(const bb_command *c, const bb__option *o, bb__text *t) {
  (void)o;
  const bb_render_options *r = &c->options.render;
  int basis = 1;
  for (int l = 0; l < 3; l++)
    for (int k = 0; k < 3; k++)
      basis &= r->lightmap[l][k] == (l == k ? 1.0f : 0.0f);
  if (basis) {
    bb__text_add(t, "basis");
    return;
  }
  for (int l = 0; l < 3; l++) {
    bb__text_add(t, l ? "," : "");
    bb__print_floats(t, r->lightmap[l], 3);
  }
}

static bb_status set_tile(bb_command *c, const bb__option *o, const char *text, double *values,
                          int *count, bb_error *err) {
  bb_status st = bb__set_generic(c, o, text, values, count, err);
  if (st == BB_OK)
    c->options.render.tile_x = c->options.render.tile_y = (int)values[0];
  return st;
}

static void print_tile(const bb_command *c, const bb__option *o, bb__text *t) {
  (void)o;
  bb__text_printf(t, "%d", c->options.render.tile_x);
}

/* --crop X,Y,W,H: integers, X and Y >= 0, W and H > 0. */
static bb_status set_crop(bb_command *c, const bb__option *o, const char *text,
                          double *values, int *count, bb_error *err) {
  *count = 0;
  double v[4];
  bb_status st = bb__parse_numbers(o, text, 4, 1, v, err);
  for (int k = 0; st == BB_OK && k < 4; k++)
    if (v[k] < (k < 2 ? 0 : 1) || v[k] > BB_MAX_DIMENSION)
      st = BB_ERR_ARGUMENT;
  if (st != BB_OK)
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "--crop needs X,Y,W,H: integers >= 0, W and H > 0 (got '%.64s')", text);
  (void)values;
  bb_render_options *r = &c->options.render;
  r->crop_x = (int)v[0], r->crop_y = (int)v[1], r->crop_width = (int)v[2],
  r->crop_height = (int)v[3];
  return BB_OK;
}

static void print_crop(const bb_command *c, const bb__option *o, bb__text *t) {
  (void)o;
  const bb_render_options *r = &c->options.render;
  bb__text_printf(t, "%d,%d,%d,%d", r->crop_x, r->crop_y, r->crop_width, r->crop_height);
}

/* ------------------------------------------------------------ the rows */

/* --light and --view are AZ,EL fields (BB__FIELD_ANGLES): two doubles. */
_Static_assert(offsetof(bb_render_options, light_elevation) ==
                   offsetof(bb_render_options, light_azimuth) + sizeof(double),
               "--light: azimuth, then elevation");
_Static_assert(offsetof(bb_render_options, view_elevation) ==
                   offsetof(bb_render_options, view_azimuth) + sizeof(double),
               "--view: azimuth, then elevation");

static const bb__option opt_mode = {
    .info = {.name = "mode", .type = BB_OPTION_WORD, .count = 1, .values = 1,
             .flags = RECORDED,
             .help = "what is lit: the ssbump, the plain normal map, the normal map times ao, "
                     "or flipcode's slope map through its 16x16 table"},
    .field = BB__FIELD_ENUM, .offset = AT(render.mode), .names = bb__name_render_mode,
    .parse = bb__parse_render_mode};

static const bb__option opt_light = {
    .info = {.name = "light", .value_name = "AZ,EL", .type = BB_OPTION_NUMBERS, .count = 2,
             .values = 1, .flags = RECORDED,
             .help = "dynamic light, degrees: azimuth 0 = from the right, 90 = from the top "
                     "(counter-clockwise on screen), elevation 90 = overhead"},
    .field = BB__FIELD_ANGLES, .offset = AT(render.light_azimuth),
    .sets = {BB__FIELD_INT, AT(render.dynamic_light), 1, NULL},
    .range = &bb__range_light_elevation, .range_of = "elevation"};

static const bb__option opt_lightmap = {
    .info = {.name = "lightmap", .value_name = "basis|R,G,B,R,G,B,R,G,B",
             .type = BB_OPTION_TEXT, .count = 1, .values = 1, .flags = RECORDED,
             .default_text = "off",
             .help = "static light: Source's three lightmap colours L0, L1, L2 (basis = red, "
                     "green, blue); without --light, the only light"},
    .range = &bb__range_colour, .set = set_lightmap, .print = print_lightmap};

static const bb__option opt_specular = {
    .info = {.name = "specular", .value_name = "EXPONENT", .type = BB_OPTION_NUMBER,
             .count = 1, .values = 1, .flags = RECORDED, .default_text = "0 (off)",
             .help = "Blinn-Phong highlight from the bent normal (ssbump) or N, viewer "
                     "overhead"},
    .field = BB__FIELD_DOUBLE, .offset = AT(render.specular_exponent),
    .range = &bb__range_specular_exponent};

static const bb__option opt_specular_strength = {
    .info = {.name = "specular-strength", .value_name = "KS", .type = BB_OPTION_NUMBER,
             .count = 1, .values = 1, .flags = RECORDED,
             .help = "scale of the highlight (a material's specular intensity; 1 = the "
                     "light's colour, which saturates readily at low light)"},
    .field = BB__FIELD_DOUBLE, .offset = AT(render.specular_strength),
    .range = &bb__range_specular_strength};

static const bb__option opt_output = {
    .info = {.name = "output", .short_name = 'o', .value_name = "OUT", .type = BB_OPTION_PATH,
             .count = 1, .values = 1, .flags = RECORDED | BB_OPTION_REQUIRED | BB_OPTION_FILES,
             .default_text = "(required)", .help = "picture to write"},
    .field = BB__FIELD_STRING, .offset = AT(output)};

#define ROW_MAP_IN(name_, map_, help_, default_)                                            \
  {.info = {.name = (name_), .value_name = "FILE", .type = BB_OPTION_PATH, .count = 1,     \
            .values = 1, .flags = RECORDED, .default_text = (default_), .help = (help_)},   \
   .field = BB__FIELD_STRING, .offset = AT(render_maps[map_])}
static const bb__option opt_in_normal = ROW_MAP_IN(
    "normal", BB_MAP_NORMAL, "baked normal map to light (instead of HEIGHT)", NULL);
static const bb__option opt_in_ssbump =
    ROW_MAP_IN("ssbump", BB_MAP_SSBUMP, "baked ssbump to light (instead of HEIGHT)", NULL);
static const bb__option opt_in_ao =
    ROW_MAP_IN("ao", BB_MAP_AO, "baked ambient occlusion (instead of HEIGHT)", NULL);
static const bb__option opt_in_bent = ROW_MAP_IN(
    "bent", BB_MAP_BENT, "baked bent normal for the specular", "from the ssbump");
static const bb__option opt_in_slope =
    ROW_MAP_IN("slope", BB_MAP_SLOPE,
               "baked flipcode slope map for --mode slope (instead of HEIGHT)", NULL);

static const bb__option opt_albedo_mode = {
    .info = {.name = "albedo-mode", .type = BB_OPTION_WORD, .count = 1, .values = 1,
             .flags = RECORDED,
             .help = "mod2x: 2 x albedo (0.5 is neutral); ssbump: a detail ssbump "
                     "(height2ssbump -d) as albedo, x 2/3 (R + G + B)"},
    .field = BB__FIELD_ENUM, .offset = AT(render.albedo_mode), .names = bb__name_albedo_mode,
    .parse = bb__parse_albedo_mode};

static const bb__option opt_compare = {
    .info = {.name = "compare", .type = BB_OPTION_FLAG, .flags = RECORDED, .default_text = "off",
             .help = "four labelled panels: normal-mapped | ssbump | ssbump + specular | ao"},
    .field = BB__FIELD_INT, .offset = AT(render_compare)};

static const bb__option opt_tile = {
    .info = {.name = "tile", .value_name = "N", .type = BB_OPTION_INT, .count = 1, .values = 1,
             .flags = RECORDED, .help = "repeat the render N x N, so seams show"},
    .range = &bb__range_tile, .set = set_tile, .print = print_tile};

static const bb__option opt_crop = {
    .info = {.name = "crop", .value_name = "X,Y,W,H", .type = BB_OPTION_NUMBERS, .count = 4,
             .values = 1, .flags = RECORDED, .default_text = "none",
             .help = "show only this window (texels of the tiled render), e.g. to zoom in"},
    .set = set_crop, .print = print_crop};

static const bb__option opt_orbit = {
    .info = {.name = "orbit", .value_name = "N", .type = BB_OPTION_INT, .count = 1, .values = 1,
             .flags = RECORDED | BB_OPTION_FILES, .default_text = "off",
             .help = "N frames of the light circling at its elevation: OUT.gif animates at 10 "
                     "frames/s, OUT.png/.exr writes OUT_000.png, ..."},
    .field = BB__FIELD_INT, .offset = AT(orbit), .range = &range_orbit};

static const bb__option opt_view = {
    .info = {.name = "view", .value_name = "AZ,EL", .type = BB_OPTION_NUMBERS, .count = 2,
             .values = 1, .flags = RECORDED, .default_text = "overhead",
             .help = "a camera at azimuth AZ (as --light's) and elevation EL degrees, the "
                     "surface tiling (270,30: from the bottom, receding up)"},
    .field = BB__FIELD_ANGLES, .offset = AT(render.view_azimuth),
    .sets = {BB__FIELD_INT, AT(render.view), 1, NULL},
    .range = &bb__range_view_elevation, .range_of = "elevation"};

static const bb__option opt_relief = {
    .info = {.name = "relief", .type = BB_OPTION_FLAG, .flags = RECORDED, .default_text = "off",
             .help = "with --view and a HEIGHT: parallax occlusion mapping of the height, the "
                     "maps read where each view ray meets it (shaders/ssbump_relief.glsl)"},
    .field = BB__FIELD_INT, .offset = AT(render.relief)};

static const bb__option opt_normal_y_maps = {
    .info = {.name = "normal-y", .type = BB_OPTION_WORD, .count = 1, .values = 1,
             .flags = RECORDED,
             .help = "green axis of the --normal and --bent files: down = Source/DirectX, up = "
                     "OpenGL"},
    .field = BB__FIELD_INT, .offset = AT(maps_normal_y_up), .names = bb__name_normal_y,
    .parse = bb__parse_normal_y};

static const bb__option opt_panel_size = {
    .info = {.name = "panel-size", .value_name = "N", .type = BB_OPTION_INT, .count = 1,
             .values = 1, .flags = RECORDED, .help = "width of each panel in pixels"},
    .field = BB__FIELD_INT, .offset = AT(panel_size), .range = &range_panel_size};

/* ------------------------------------------------------------ render */

static const bb__option *const render_options[] = {
    &bb__opt_scale_optional, &bb__opt_rays, &bb__opt_filter_radius, &bb__opt_filter_threshold,
    &bb__opt_bias, &bb__opt_power, &bb__opt_normal_filter, &opt_normal_y_maps,
    &bb__opt_threads, &bb__opt_clamp, &bb__opt_channel, &opt_in_normal, &opt_in_ssbump,
    &opt_in_ao, &opt_in_bent, &opt_in_slope, &opt_mode, &opt_light, &bb__opt_light_color,
    &opt_lightmap, &opt_specular, &opt_specular_strength, &bb__opt_albedo, &opt_albedo_mode,
    &opt_compare, &opt_tile, &opt_crop, &opt_orbit, &opt_view, &opt_relief, &opt_output,
    &bb__opt_depth, &bb__opt_quiet, &bb__opt_help, NULL};

static void render_init(bb_command_options *o) {
  (void)o; /* bb__render_options_init's defaults */
}

/* The maps the picture reads: the mode's, or all three for --compare. */
static unsigned needed_maps(const bb_command_options *o) {
  if (o->render_compare)
    return BB_RENDER_NEEDS_NORMAL | BB_RENDER_NEEDS_SSBUMP | BB_RENDER_NEEDS_AO;
  return bb__render_mode_needs(o->render.mode);
}

/* The files a render of c reads, and the bake of its HEIGHT (the maps the
 * picture is lit from), for the estimates before any pixel is read. */
static void render_files(const bb_command *c, bb_render_sources *files,
                         bb_bake_options *bake) {
  const bb_command_options *o = &c->options;
  memset(files, 0, sizeof *files);
  for (int m = 0; m < BB_MAP_KIND_COUNT; m++)
    files->maps[m] = o->render_maps[m];
  files->height = c->input_count ? c->inputs[0] : NULL;
  files->albedo = o->albedo;
  *bake = o->job.bake;
  const int traced =
      (needed_maps(o) & (BB_RENDER_NEEDS_SSBUMP | BB_RENDER_NEEDS_AO)) != 0;
  bake->outputs = BB_MAP_BIT(BB_MAP_NORMAL) | BB_MAP_BIT(BB_MAP_FILTERED) |
                  (traced ? BB_MAPS_TRACED : 0u);
}

/* A note, through hooks, of what a render of files will cost when that is
 * over what any read takes (bb__memory_note): said before it starts. */
static void render_cost_note(const bb_command *c, const bb_command_hooks *hooks) {
  if (!hooks || !hooks->note || c->in_memory)
    return;
  bb_render_sources files;
  bb_bake_options bake;
  render_files(c, &files, &bake);
  const bb_command_options *o = &c->options;
  double need = 0.0;
  const char *path = NULL;
  char what[128], text[256];
  bb_error ignored = {{0}};
  if (bb__render_files_need(&files, &bake, &o->render, o->render_compare, o->output,
                            o->job.depth, NULL, NULL, &need, &path, what, sizeof what,
                            &ignored) == BB_OK &&
      bb__memory_note(need, what, text, sizeof text))
    hooks->note(hooks->note_user, path, text);
}

/* A lightmap without --light is the only light. */
static void lights(bb_command *c) {
  if (c->options.render.static_light && !bb__given(c, "light"))
    c->options.render.dynamic_light = 0;
}

/* A HEIGHT or the maps the picture needs, not both; what --relief,
 * --orbit and a GIF need. */
static bb_status render_check(bb_command *c, bb_error *err) {
  static const unsigned map_need[BB_MAP_KIND_COUNT] = {
      [BB_MAP_NORMAL] = BB_RENDER_NEEDS_NORMAL, [BB_MAP_SSBUMP] = BB_RENDER_NEEDS_SSBUMP,
      [BB_MAP_AO] = BB_RENDER_NEEDS_AO, [BB_MAP_SLOPE] = BB_RENDER_NEEDS_SLOPE};
  bb_command_options *o = &c->options;
  lights(c);
  int any_map = 0;
  for (int m = 0; m < BB_MAP_KIND_COUNT; m++)
    any_map |= o->render_maps[m] != NULL;
  const char *height = c->input_count ? c->inputs[0] : NULL;
  if (height && any_map)
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "give a HEIGHT to bake or baked maps (--normal, --ssbump, --ao, --bent, "
                    "--slope), not both");
  if (o->render.relief && !o->render.view)
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "--relief needs --view AZ,EL (from straight above a relief shows nothing)");
  if (o->render.relief && !height)
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "--relief reads the height: give a HEIGHT (and --scale)");
  if (height && !bb__given(c, "scale"))
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "--scale is required with a HEIGHT (texels of displacement per unit of "
                    "height)");
  if (!height && !any_map && !c->in_memory)
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "missing HEIGHT or baked maps (usage: bumpbake render %s)",
                    bb__command_render.info.synopsis);
  for (int m = 0; !height && m < BB_MAP_KIND_COUNT; m++)
    if ((needed_maps(o) & map_need[m]) && !o->render_maps[m])
      return bb__fail(err, BB_ERR_ARGUMENT, "%s needs --%s FILE (or a HEIGHT to bake)",
                      o->render_compare ? "--compare" : bb__render_mode_name(o->render.mode),
                      bb__map_kind_name((bb_map_kind)m));
  /* before any pixel is read, from the files' headers: the maps' size, the
   * picture the options make of it, the memory the render takes
   * (bb__render_files_check); a tile or crop the input cannot take is a
   * usage error, anything else the files' */
  if (!c->in_memory) {
    bb_render_sources files;
    bb_bake_options bake;
    render_files(c, &files, &bake);
    int w = 0, h = 0;
    bb_error why = {{0}};
    bb_status st = bb__render_files_check(&files, &bake, &o->render, o->render_compare, o->output,
                                         o->job.depth, &w, &h, err);
    if (st != BB_OK && w > 0 &&
        bb__render_estimate(w, h, &o->render, o->render_compare, NULL, BB_DEPTH_DEFAULT, NULL,
                           NULL, NULL, &why) != BB_OK)
      return bb__fail(err, BB_ERR_ARGUMENT, "%s", why.message);
    if (st == BB_ERR_ARGUMENT)
      return BB_ERR_FORMAT; /* the files' own fault (maps of two sizes): not a usage error */
    if (st != BB_OK)
      return st;
  }
  if (!o->output)
    return BB_OK; /* the generic check says -o is required */
  if (o->orbit && !o->render.dynamic_light)
    return bb__fail(err, BB_ERR_ARGUMENT, "--orbit circles the dynamic light: give --light");
  if (bb__path_has_extension(o->output, "gif")) {
    if (!o->orbit)
      return bb__fail(err, BB_ERR_ARGUMENT,
                      "%s: GIF is for --orbit animations; use .png or .exr", o->output);
    if (o->job.depth != BB_DEPTH_DEFAULT && o->job.depth != BB_DEPTH_8)
      return bb__fail(err, BB_ERR_ARGUMENT, "%s: GIF files are 8-bit", o->output);
  }
  /* the output against every file read, every frame of an orbit */
  const char *reads[BB_MAP_KIND_COUNT + 2];
  int n_reads = 0;
  for (int m = 0; m < BB_MAP_KIND_COUNT; m++)
    if (o->render_maps[m])
      reads[n_reads++] = o->render_maps[m];
  if (height)
    reads[n_reads++] = height;
  if (o->albedo)
    reads[n_reads++] = o->albedo;
  const bb__job_output out = {o->output, o->render_compare ? "comparison" : "render",
                              BB_RANGE_UNIT, o->job.depth, NULL, 0, NULL};
  return bb__job_output_check(&out, o->orbit, reads, n_reads, err);
}

const bb__command bb__command_render = {
    .info = {.name = "render",
             .summary = "light the maps as Source does (ssbump, normal, ao; orbit)",
             .synopsis = "(HEIGHT --scale S | --ssbump FILE | --normal FILE ...) -o OUT "
                         "[OPTIONS]",
             .description =
                 "Lights the maps as Source does (static lightmaps, a dynamic light, specular "
                 "from\nthe bent normal) and writes the picture. From a HEIGHT the maps are "
                 "baked first\nwith bake's options; --normal/--ssbump/--ao/--bent read maps "
                 "already baked\n(--normal-y up: those files are OpenGL-style).",
             .inputs = "HEIGHT", .min_inputs = 0, .max_inputs = 1, .usage_exit = 2,
             .option_count = (int)(sizeof render_options / sizeof render_options[0]) - 1},
    .options = render_options, .init = render_init, .check = render_check, .run = bb__run_render,
    .before_run = render_cost_note};

/* ------------------------------------------------------------- sheet */

static const bb__option *const sheet_options[] = {
    &bb__opt_scale, &bb__opt_rays, &bb__opt_filter_radius, &bb__opt_filter_threshold,
    &bb__opt_bias, &bb__opt_power, &bb__opt_normal_filter, &bb__opt_threads, &bb__opt_clamp,
    &bb__opt_channel, &opt_mode, &opt_light, &bb__opt_light_color, &opt_lightmap, &opt_specular,
    &opt_specular_strength, &opt_panel_size, &opt_output, &bb__opt_depth, &bb__opt_quiet,
    &bb__opt_help, NULL};

static void sheet_init(bb_command_options *o) {
  bb_sheet_options s;
  bb__sheet_options_init(&s);
  o->render = s.lit;
  o->panel_size = s.layout.panel_width;
}

static bb_status sheet_check(bb_command *c, bb_error *err) {
  bb_command_options *o = &c->options;
  lights(c);
  if (o->render.mode == BB_RENDER_SLOPE)
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "--mode slope is render's (bumpbake render HEIGHT --mode slope); the sheet "
                    "lights the ssbump, normal or ao");
  if (!o->output)
    return BB_OK;
  const bb__job_output out = {o->output, "sheet", BB_RANGE_UNIT, o->job.depth, NULL, 0, NULL};
  return bb__job_output_check(&out, 0, (const char *const *)c->inputs, c->input_count, err);
}

const bb__command bb__command_sheet = {
    .info = {.name = "sheet",
             .summary = "one labelled contact sheet of every map of a bake",
             .synopsis = "HEIGHT --scale S -o OUT [OPTIONS]",
             .description =
                 "Bakes HEIGHT with bake's options and writes one labelled contact sheet: "
                 "height,\nfiltered height, normal, weights, ssbump, ao, bent normal and one "
                 "lit render\n(--mode and the lighting options choose it).",
             .inputs = "HEIGHT", .min_inputs = 1, .max_inputs = 1, .usage_exit = 2,
             .option_count = (int)(sizeof sheet_options / sizeof sheet_options[0]) - 1},
    .options = sheet_options, .init = sheet_init, .check = sheet_check, .run = bb__run_sheet};
