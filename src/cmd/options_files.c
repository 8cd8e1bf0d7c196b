/* options_files.c: the commands about files and models (compare, info,
 * renderbumpflat), their options described once and their rules. */
#include "cmd/cmd_internal.h"
#include "job/job_internal.h"
#include "maps/maps_internal.h"
#include "mesh/mesh_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define AT(member) offsetof(bb_command_options, member)
#define RECORDED BB_OPTION_RECORDED
#define IDIFF (RECORDED | BB_OPTION_SINGLE_DASH)

/* ------------------------------------------------------------- compare */

static bb_status set_allow_failures(bb_command *c, const bb__option *o, const char *text,
                                    double *values, int *count, bb_error *err) {
  bb_status st = bb__set_generic(c, o, text, values, count, err);
  if (st == BB_OK)
    c->options.limits.allow_failures = (long)values[0];
  return st;
}

static void print_allow_failures(const bb_command *c, const bb__option *o, bb__text *t) {
  (void)o;
  bb__text_printf(t, "%ld", c->options.limits.allow_failures);
}

/* idiff's limits: compare's (recorded: they decide its diff) and check's
 * (not: a golden check's record is its bake's), the same rows else. */
#define ROW_LIMIT(name_, value_, member_, range_, help_, flags_)                           \
  {.info = {.name = (name_), .value_name = (value_), .type = BB_OPTION_NUMBER, .count = 1, \
            .values = 1, .flags = (flags_), .help = (help_)},                              \
   .field = BB__FIELD_DOUBLE, .offset = AT(limits.member_), .range = &(range_)}
#define ROW_ALLOW_FAILURES(flags_)                                                          \
  {.info = {.name = "allowfailures", .value_name = "N", .type = BB_OPTION_INT, .count = 1, \
            .values = 1, .flags = (flags_),                                                \
            .help = "pass when at most N pixels fail, by any amount"},                     \
   .range = &bb__range_compare_count, .set = set_allow_failures,                           \
   .print = print_allow_failures}
#define LIMIT_ROWS(stem_, flags_)                                                           \
  static const bb__option stem_##fail =                                                     \
      ROW_LIMIT("fail", "T", fail, bb__range_compare_threshold,                             \
                "a pixel fails when a channel differs by more than T", flags_);             \
  static const bb__option stem_##fail_percent =                                             \
      ROW_LIMIT("failpercent", "P", fail_percent, bb__range_compare_percent,                \
                "failing pixels allowed, in % of all (then a warning)", flags_);            \
  static const bb__option stem_##hard_fail =                                                \
      ROW_LIMIT("hardfail", "T", hard_fail, bb__range_compare_threshold,                    \
                "fail when any difference exceeds T, even within -failpercent", flags_);    \
  static const bb__option stem_##allow_failures = ROW_ALLOW_FAILURES(flags_);               \
  static const bb__option stem_##warn =                                                     \
      ROW_LIMIT("warn", "T", warn, bb__range_compare_threshold,                             \
                "a pixel warns when a channel differs by more than T", flags_);             \
  static const bb__option stem_##warn_percent =                                             \
      ROW_LIMIT("warnpercent", "P", warn_percent, bb__range_compare_percent,                \
                "warning pixels allowed, in % of all", flags_);                             \
  static const bb__option stem_##hard_warn =                                                \
      ROW_LIMIT("hardwarn", "T", hard_warn, bb__range_compare_threshold,                    \
                "warn when any difference exceeds T", flags_);
LIMIT_ROWS(opt_, IDIFF)
LIMIT_ROWS(opt_check_, BB_OPTION_SINGLE_DASH)
static const bb__option opt_diff = {
    .info = {.name = "diff", .value_name = "FILE", .type = BB_OPTION_PATH, .count = 1,
             .values = 1, .flags = RECORDED | BB_OPTION_FILES,
             .help = "write |A-B| (raw in .exr, scaled to a maximum of 1 otherwise)"},
    .field = BB__FIELD_STRING, .offset = AT(diff)};
static const bb__option opt_compare_json = {
    .info = {.name = "json", .type = BB_OPTION_FLAG, .flags = BB_OPTION_CLIENT,
             .default_text = "off", .help = "print the report as one JSON line"},
    .field = BB__FIELD_INT, .offset = AT(json)};
static const bb__option opt_compare_quiet = {
    .info = {.name = "quiet", .short_name = 'q', .type = BB_OPTION_FLAG,
             .flags = BB_OPTION_CLIENT, .default_text = "off",
             .help = "print no report; the exit code tells"},
    .field = BB__FIELD_INT, .offset = AT(quiet)};

static const bb__option *const compare_options[] = {
    &opt_fail, &opt_fail_percent, &opt_hard_fail, &opt_allow_failures, &opt_warn,
    &opt_warn_percent, &opt_hard_warn, &opt_diff, &opt_compare_json, &opt_compare_quiet,
    &bb__opt_help, NULL};

static void compare_init(bb_command_options *o) {
  bb__compare_limits_init(&o->limits);
}

/* The diff is checked before the (possibly long) reads, and must not
 * overwrite either input. */
static bb_status compare_check(bb_command *c, bb_error *err) {
  if (!c->options.diff)
    return BB_OK;
  const bb__job_output diff = bb__compare_diff_output(c->options.diff);
  return bb__job_output_check(&diff, 0, (const char *const *)c->inputs, 2, err);
}

const bb__command bb__command_compare = {
    .info = {.name = "compare",
             .summary = "compare two images (statistics, provenance diff)",
             .synopsis = "A B [OPTIONS]",
             .description =
                 "Compares two images channel by channel, as OpenImageIO's idiff (whose\n"
                 "single-dash spellings are accepted), and lists differing provenance.\n"
                 "Verdict (idiff 2.4's): pass when at most -allowfailures pixels fail; else\n"
                 "fail when more than -failpercent % fail or any difference > -hardfail; else\n"
                 "warn when more than -warnpercent % warn or any difference > -hardwarn.\n"
                 "Exit: 0 pass, 1 warning, 2 failure, 3 different size or channels,\n"
                 "4 unreadable file or bad arguments.",
             .inputs = "A B", .min_inputs = 2, .max_inputs = 2,
             .usage_exit = BB_COMPARE_CANNOT_READ,
             .option_count = (int)(sizeof compare_options / sizeof compare_options[0]) - 1},
    .options = compare_options, .init = compare_init, .check = compare_check,
    .run = bb__run_compare};

/* --------------------------------------------------------------- check */

static const bb__option opt_limits = {
    .info = {.name = "limits", .value_name = "RULES", .type = BB_OPTION_TEXT, .count = 1,
             .values = 1,
             .help = "limits by map kind or file name, idiff's options after each: \"ao: "
                     "-fail 1e-3; *_normal.png: -fail 0.004\" (';' or a new line between "
                     "rules, '#' a comment; the last that selects a map wins)"},
    .field = BB__FIELD_STRING, .offset = AT(limit_rules)};
static const bb__option opt_update = {
    .info = {.name = "update", .type = BB_OPTION_FLAG, .flags = BB_OPTION_FILES,
             .default_text = "off",
             .help = "write new goldens where a map does not pass (and only there), saying "
                     "what changed"},
    .field = BB__FIELD_INT, .offset = AT(update)};
static const bb__option opt_junit = {
    .info = {.name = "junit", .value_name = "FILE", .type = BB_OPTION_PATH, .count = 1,
             .values = 1, .flags = BB_OPTION_FILES,
             .help = "write a JUnit XML report: a test case per map"},
    .field = BB__FIELD_STRING, .offset = AT(junit)};
static const bb__option opt_html = {
    .info = {.name = "html", .value_name = "DIR", .type = BB_OPTION_PATH, .count = 1,
             .values = 1, .flags = BB_OPTION_FILES,
             .help = "write an HTML report into DIR (index.html, img/): thumbnails, and "
                     "golden, new, difference, flip and slider of each map that does not pass"},
    .field = BB__FIELD_STRING, .offset = AT(html)};
static const bb__option opt_bake = {
    .info = {.name = "bake", .type = BB_OPTION_FLAG, .flags = BB_OPTION_FILES,
             .default_text = "off",
             .help = "the inputs after GOLDEN are heights (files or directories), baked in "
                     "memory as bake HEIGHT... --out-dir GOLDEN bakes them"},
    .field = BB__FIELD_INT, .offset = AT(check_bake)};
static const bb__option opt_check_json = {
    .info = {.name = "json", .type = BB_OPTION_FLAG, .flags = BB_OPTION_CLIENT,
             .default_text = "off", .help = "print a JSON line per map and one for the summary"},
    .field = BB__FIELD_INT, .offset = AT(json)};
static const bb__option opt_check_quiet = {
    .info = {.name = "quiet", .short_name = 'q', .type = BB_OPTION_FLAG,
             .flags = BB_OPTION_CLIENT, .default_text = "off",
             .help = "print nothing; the exit code tells"},
    .field = BB__FIELD_INT, .offset = AT(quiet)};

/* The options a batch of bake takes that check --bake takes too. */
static const bb__option *const check_bake_rows[] = {
    &bb__opt_scale_optional, &bb__opt_rays, &bb__opt_slices, &bb__opt_filter_radius,
    &bb__opt_filter_threshold, &bb__opt_bias, &bb__opt_power, &bb__opt_basis,
    &bb__opt_normal_filter, &bb__opt_normal_y, &bb__opt_threads, &bb__opt_clamp,
    &bb__opt_channel, &bb__opt_depth, &bb__opt_mips, &bb__opt_bounce, &bb__opt_bounces,
    &bb__opt_bounce_albedo, &bb__opt_brightness, &bb__opt_maps, &bb__opt_name,
    &bb__opt_texture_format, &bb__opt_vtf_version, &bb__opt_vtf_flags, &bb__opt_nomip,
    &bb__opt_fast_compression, NULL};

static const bb__option *const check_options[] = {
    &opt_check_fail, &opt_check_fail_percent, &opt_check_hard_fail, &opt_check_allow_failures,
    &opt_check_warn, &opt_check_warn_percent, &opt_check_hard_warn, &opt_limits, &opt_update,
    &opt_junit, &opt_html, &opt_bake, &bb__opt_scale_optional, &bb__opt_rays, &bb__opt_slices,
    &bb__opt_filter_radius, &bb__opt_filter_threshold, &bb__opt_bias, &bb__opt_power,
    &bb__opt_basis, &bb__opt_normal_filter, &bb__opt_normal_y, &bb__opt_threads,
    &bb__opt_clamp, &bb__opt_channel, &bb__opt_depth, &bb__opt_mips, &bb__opt_bounce,
    &bb__opt_bounces, &bb__opt_bounce_albedo, &bb__opt_brightness, &bb__opt_maps,
    &bb__opt_name, &bb__opt_texture_format, &bb__opt_vtf_version, &bb__opt_vtf_flags,
    &bb__opt_nomip, &bb__opt_fast_compression, &opt_check_json, &opt_check_quiet,
    &bb__opt_help, NULL};

static void check_init(bb_command_options *o) {
  bb__compare_limits_init(&o->limits);
}

/* GOLDEN is the batch's output directory: the bake options' rules (a
 * traced map asked, a .vtf name) then read as a batch's. */
static bb_status check_add_input(bb_command *c, int i, const char *text, bb_error *err) {
  if (i == 0 && !(c->options.job.out_dir = bb__command_keep(c, text)))
    return bb__fail(err, BB_ERR_MEMORY, "out of memory");
  return BB_OK;
}

static int is_bake_row(const bb__option *o) {
  for (int i = 0; check_bake_rows[i]; i++)
    if (check_bake_rows[i] == o)
      return 1;
  return 0;
}

static bb_status check_check(bb_command *c, bb_error *err) {
  const bb_command_options *o = &c->options;
  if (!c->in_memory && !o->check_bake && c->input_count != 2)
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "check GOLDEN NEW compares two trees (or files); heights to bake need "
                    "--bake");
  for (int i = 0; c->def->options[i] && !o->check_bake; i++)
    if (c->given[i] && is_bake_row(c->def->options[i]))
      return bb__fail(err, BB_ERR_ARGUMENT, "--%s is a bake's option: give --bake and heights",
                      c->def->options[i]->info.name);
  if (o->check_bake && !bb__given(c, "scale"))
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "--scale is required with --bake (texels of displacement per unit of "
                    "height)");
  /* --limits' rules are read when the check is planned (bb_check_plan) */
  bb_status st = BB_OK;
  if (o->junit && c->input_count) {
    const bb_output_spec junit = {.path = o->junit, .kind = "junit", .text = 1};
    st = bb_outputs_check(&junit, 1, (const char *const *)c->inputs, c->input_count, err);
  }
  return st;
}

bb_status bb__check_job_options(bb_command *c, bb_job_options *o, bb_error *err) {
  (void)err;
  *o = c->options.job; /* out_dir: GOLDEN (check_add_input) */
  o->force = 1;
  return BB_OK;
}

const bb__command bb__command_check = {
    .info = {.name = "check",
             .summary = "check a suite of maps against goldens (trees or a bake; reports)",
             .synopsis = "GOLDEN NEW [OPTIONS] | GOLDEN HEIGHT... --bake --scale S [OPTIONS]",
             .description =
                 "Compares every map with its golden as compare does (idiff's options and\n"
                 "verdicts, the provenance diff): GOLDEN and NEW, two directories paired by\n"
                 "relative name (a golden without a new map is MISSING, a new map without a\n"
                 "golden EXTRA: failures) or two files; or with --bake, the heights baked in\n"
                 "memory as bake HEIGHT... --out-dir GOLDEN bakes them, each map compared\n"
                 "with the file it would write (nothing is written). --limits sets idiff's\n"
                 "options per map kind or file name. --update writes the goldens of the\n"
                 "maps that do not pass, and only those. Prints each map that does not pass\n"
                 "and a summary. Exit: the worst map's, as idiff's: 0 pass, 1 warning,\n"
                 "2 failure (also missing or extra), 3 different size or channels,\n"
                 "4 unreadable file or bad arguments.",
             .inputs = "GOLDEN NEW", .min_inputs = 2, .max_inputs = -1,
             .usage_exit = BB_COMPARE_CANNOT_READ,
             .option_count = (int)(sizeof check_options / sizeof check_options[0]) - 1},
    .options = check_options, .init = check_init, .add_input = check_add_input,
    .check = check_check};

/* ---------------------------------------------------------------- info */

static const bb__option opt_info_json = {
    .info = {.name = "json", .type = BB_OPTION_FLAG, .flags = BB_OPTION_CLIENT,
             .default_text = "off",
             .help = "print one JSON object per file, one per line (JSON Lines)"},
    .field = BB__FIELD_INT, .offset = AT(json)};

static const bb__option *const info_options[] = {&opt_info_json, &bb__opt_help, NULL};

const bb__command bb__command_info = {
    .info = {.name = "info",
             .summary = "print an image's size, format and provenance",
             .synopsis = "FILE... [--json]",
             .description =
                 "Prints each image's size, channels, format, sample type and alpha channel,\n"
                 "and the provenance bumpbake stored in it, from the file's header alone (no\n"
                 "pixel is decoded); for a Source texture (.vtf) also its version, format,\n"
                 "flags and mip levels. A file that cannot be read is reported and skipped;\n"
                 "the exit code is then 1.",
             .inputs = "FILE", .min_inputs = 1, .max_inputs = -1, .usage_exit = 2,
             .option_count = (int)(sizeof info_options / sizeof info_options[0]) - 1},
    .options = info_options, .run = bb__run_info};

/* ------------------------------------------------------ renderbumpflat */

static const bb__range range_side = {"a side", 1, BB_MAX_DIMENSION, 0, 1};

/* -size W H: DOOM 3's, two words. */
static bb_status set_size(bb_command *c, const bb__option *o, const char *text, double *values,
                          int *count, bb_error *err) {
  bb_status st = bb__parse_numbers(o, text, 2, 1, values, err);
  *count = 2;
  if (st == BB_OK && bb__range_holds(&range_side, values[0]) &&
      bb__range_holds(&range_side, values[1]) && values[0] * values[1] > (double)BB_MAX_PIXELS)
    return bb__fail(err, BB_ERR_ARGUMENT, "-size %.0f %.0f is over %ld texels", values[0],
                    values[1], (long)BB_MAX_PIXELS);
  if (st == BB_OK) {
    c->options.renderbump.width = (int)fmin(fmax(values[0], 0), BB_MAX_DIMENSION + 1.0);
    c->options.renderbump.height = (int)fmin(fmax(values[1], 0), BB_MAX_DIMENSION + 1.0);
  }
  return st;
}

static void print_size(const bb_command *c, const bb__option *o, bb__text *t) {
  (void)o;
  bb__text_printf(t, "%d %d", c->options.renderbump.width, c->options.renderbump.height);
}

static void size_range(char *out, size_t cap) {
  snprintf(out, cap, "1..%d each, W*H <= %ld", BB_MAX_DIMENSION, (long)BB_MAX_PIXELS);
}

/* --rect L B R T: four numbers, L < R and B < T. */
static bb_status set_rect(bb_command *c, const bb__option *o, const char *text, double *values,
                          int *count, bb_error *err) {
  bb_status st = bb__parse_numbers(o, text, 4, 0, values, err);
  *count = 0;
  if (st == BB_OK && (!(values[2] > values[0]) || !(values[3] > values[1])))
    return bb__fail(err, BB_ERR_ARGUMENT, "--rect needs L < R and B < T");
  if (st == BB_OK) {
    for (int k = 0; k < 4; k++)
      c->options.renderbump.rect[k] = values[k];
    c->options.renderbump.rect_given = 1;
  }
  return st;
}

static void print_rect(const bb_command *c, const bb__option *o, bb__text *t) {
  (void)o;
  for (int k = 0; k < 4; k++) {
    char buf[40];
    bb__double_text(c->options.renderbump.rect[k], buf, sizeof buf);
    bb__text_printf(t, "%s%s", k ? " " : "", buf);
  }
}

static const bb__option opt_size = {
    .info = {.name = "size", .value_name = "W H", .type = BB_OPTION_NUMBERS, .count = 2,
             .values = 2, .flags = RECORDED | BB_OPTION_SINGLE_DASH,
             .help = "output size in texels (DOOM 3's -size W H; one dash or two)"},
    .range = &range_side, .set = set_size, .print = print_size, .range_words = size_range};
static const bb__option opt_rbf_output = {
    .info = {.name = "output", .short_name = 'o', .value_name = "OUT", .type = BB_OPTION_PATH,
             .count = 1, .values = 1, .flags = RECORDED | BB_OPTION_FILES,
             .default_text = "MODEL_local.tga beside MODEL",
             .help = "normal map, RGB = N, A = coverage (.tga .png .tif .exr)"},
    .field = BB__FIELD_STRING, .offset = AT(output)};
static const bb__option opt_height = {
    .info = {.name = "height", .value_name = "FILE", .type = BB_OPTION_PATH, .count = 1,
             .values = 1, .flags = RECORDED | BB_OPTION_FILES,
             .help = "also write the height, 0..1 (16-bit png/tif, float exr), and print its "
                     "scale"},
    .field = BB__FIELD_STRING, .offset = AT(height_output)};
static const bb__option opt_axis = {
    .info = {.name = "axis", .type = BB_OPTION_WORD, .count = 1, .values = 1, .flags = RECORDED,
             .default_text = "-y (DOOM 3)",
             .help = "the side the sculpt's front faces (+z: Blender's top view)"},
    .field = BB__FIELD_ENUM, .offset = AT(renderbump.axis), .names = bb__name_axis,
    .parse = bb__parse_axis};
static const bb__option opt_samples = {
    .info = {.name = "samples", .value_name = "N", .type = BB_OPTION_INT, .count = 1,
             .values = 1, .flags = RECORDED, .default_text = "4 (16 samples per texel)",
             .help = "N x N samples per texel"},
    .field = BB__FIELD_INT, .offset = AT(renderbump.samples),
    .range = &bb__range_renderbump_samples};
static const bb__option opt_face_normals = {
    .info = {.name = "face-normals", .type = BB_OPTION_FLAG, .flags = RECORDED,
             .default_text = "off",
             .help = "triangles' plane normals even where the model has vertex normals"},
    .field = BB__FIELD_INT, .offset = AT(renderbump.face_normals)};
static const bb__option opt_rect = {
    .info = {.name = "rect", .value_name = "L B R T", .type = BB_OPTION_NUMBERS, .count = 4,
             .values = 4, .flags = RECORDED | BB_OPTION_SINGLE_DASH,
             .default_text = "the model's bounding rectangle",
             .help = "rectangle in model units along the image's right and up axes"},
    .set = set_rect, .print = print_rect};
static const bb__option opt_rbf_tile = {
    .info = {.name = "tile", .type = BB_OPTION_FLAG, .flags = RECORDED, .default_text = "off",
             .help = "wrap geometry outside --rect into it (the sculpt tiles; needs --rect)"},
    .field = BB__FIELD_INT, .offset = AT(renderbump.tile)};
static const bb__option opt_rbf_normal_y = {
    .info = {.name = "normal-y", .type = BB_OPTION_WORD, .count = 1, .values = 1,
             .flags = RECORDED,
             .help = "green axis: down = Source/DirectX, up = OpenGL (flips green)"},
    .field = BB__FIELD_INT, .offset = AT(maps_normal_y_up), .names = bb__name_normal_y,
    .parse = bb__parse_normal_y};
static const bb__option opt_rbf_quiet = {
    .info = {.name = "quiet", .short_name = 'q', .type = BB_OPTION_FLAG,
             .flags = BB_OPTION_CLIENT, .help = "print only errors, notes and the height scale"},
    .field = BB__FIELD_INT, .offset = AT(quiet)};

static const bb__option *const rbf_options[] = {
    &opt_size, &opt_rbf_output, &opt_height, &opt_axis, &opt_samples, &opt_face_normals,
    &opt_rect, &opt_rbf_tile, &opt_rbf_normal_y, &bb__opt_threads, &opt_rbf_quiet,
    &bb__opt_help, NULL};

static void rbf_init(bb_command_options *o) {
  bb__renderbump_options_init(&o->renderbump);
}

/* --tile needs --rect; the normal map's default name; the outputs apart and
 * not over the model, as the job writes them (bb__renderbump_outputs). In
 * memory, nothing is written. */
static bb_status rbf_check(bb_command *c, bb_error *err) {
  bb_command_options *o = &c->options;
  if (o->renderbump.tile && !o->renderbump.rect_given)
    return bb__fail(err, BB_ERR_ARGUMENT,
                    "--tile needs --rect L B R T: the tile the sculpt repeats with");
  if (c->in_memory)
    return BB_OK;
  if (!o->output) {
    char *name = bb__path_with_suffix(c->inputs[0], "_local.tga");
    o->output = name ? bb__command_keep(c, name) : NULL;
    free(name);
    if (!o->output)
      return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", c->inputs[0]);
  }
  if (o->height_output && bb__same_file(o->height_output, o->output))
    return bb__fail(err, BB_ERR_ARGUMENT, "--height and the normal map are both %s", o->output);
  bb__job_output out[2];
  const int count = bb__renderbump_outputs(o->output, o->height_output, out);
  return bb__job_outputs_check(out, count, (const char *const *)c->inputs, 1, err);
}

const bb__command bb__command_renderbumpflat = {
    .info = {.name = "renderbumpflat",
             .summary = "DOOM 3's RenderBumpFlat: a flat sculpt's normal map and height",
             .synopsis = "[-size W H] MODEL [OPTIONS]",
             .description =
                 "DOOM 3's RenderBumpFlat: projects MODEL (any format Assimp reads) onto its\n"
                 "bounding rectangle and writes the front-most surface's normals, 16x\n"
                 "oversampled, with alpha = coverage.",
             .inputs = "MODEL", .min_inputs = 1, .max_inputs = 1, .usage_exit = 2,
             .option_count = (int)(sizeof rbf_options / sizeof rbf_options[0]) - 1},
    .options = rbf_options, .init = rbf_init, .check = rbf_check, .run = bb__run_renderbumpflat};
