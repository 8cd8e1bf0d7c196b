/* cli_bake.c: `bumpbake bake`, every map from one height map in one pass
 * (one bb_bake call, so ssbump, ao and bent share a single trace). */
#include "batch.h"
#include "common.h"
#include "slope.h"

#include <stddef.h>
#include <stdlib.h>
#include <string.h>

/* The maps are the library's (bb_output_kind_get); CLI_OPT_OUT_* follow
 * its order. */
enum { OUTPUT_KIND_COUNT = BB_OUTPUT_KIND_COUNT };
_Static_assert(CLI_OPT_OUT_FILTERED - CLI_OPT_OUT_NORMAL + 1 == BB_OUTPUT_KIND_COUNT,
               "one --KIND option per output kind, in bb_output_kind order");

/* What -o PREFIX writes (as PREFIX_kind.png): Valve's trio. */
static const unsigned prefix_kinds = BB_OUTPUT_BIT(BB_OUTPUT_NORMAL) |
                                     BB_OUTPUT_BIT(BB_OUTPUT_SSBUMP) |
                                     BB_OUTPUT_BIT(BB_OUTPUT_AO);

static const bb_output_kind_info *kind_info(int kind) {
  return bb_output_kind_get((bb_output_kind)kind);
}

static const cli_option opt_prefix = {
    .id = CLI_OPT_OUTPUT,
    .long_name = "output",
    .short_name = 'o',
    .value_name = "PREFIX",
    .help = "write PREFIX_normal.png, PREFIX_ssbump.png and PREFIX_ao.png"};
static const cli_option opt_out_normal = {.id = CLI_OPT_OUT_NORMAL,
                                          .long_name = "normal",
                                          .value_name = "FILE",
                                          .help = "write the normal map"};
static const cli_option opt_out_weights = {.id = CLI_OPT_OUT_WEIGHTS,
                                           .long_name = "weights",
                                           .value_name = "FILE",
                                           .help =
                                               "write the basis weights (normal2ssbump)"};
static const cli_option opt_out_ssbump = {
    .id = CLI_OPT_OUT_SSBUMP,
    .long_name = "ssbump",
    .value_name = "FILE",
    .help = "write the self-shadowed bump map (traces)"};
static const cli_option opt_out_ao = {.id = CLI_OPT_OUT_AO,
                                      .long_name = "ao",
                                      .value_name = "FILE",
                                      .help = "write the ambient occlusion (traces)"};
static const cli_option opt_out_bent = {.id = CLI_OPT_OUT_BENT,
                                        .long_name = "bent",
                                        .value_name = "FILE",
                                        .help = "write the bent normal (traces)"};
static const cli_option opt_out_filtered = {.id = CLI_OPT_OUT_FILTERED,
                                            .long_name = "filtered",
                                            .value_name = "FILE",
                                            .help = "write the smoothed height"};
static const cli_option opt_slices = {
    .id = CLI_OPT_SLICES,
    .long_name = "slices",
    .value_name = "A",
    .default_text = "from --rays",
    .range_text = "1..256",
    .help = "azimuth slices, each integrated exactly above its horizon (overrides --rays)"};
static const cli_option opt_json = {
    .id = CLI_OPT_JSON,
    .long_name = "json",
    .help = "print one JSON line describing the bake on stdout"};
static const cli_option opt_quiet = {.id = CLI_OPT_QUIET,
                                     .long_name = "quiet",
                                     .short_name = 'q',
                                     .help = "no progress bar, no list of files written"};

static const cli_option opt_bounce = {
    .id = CLI_OPT_BOUNCE,
    .long_name = "bounce",
    .value_name = "RHO",
    .default_text = "0 (none; 1 with --bounce-albedo)",
    .range_text = "0..1",
    .help = "inter-reflection: ao, ssbump and bent include the light the relief "
            "reflects, albedo RHO (README \"Inter-reflection\")"};
static const cli_option opt_bounces = {
    .id = CLI_OPT_BOUNCES,
    .long_name = "bounces",
    .value_name = "N",
    .default_text = "0 (until converged)",
    .range_text = "0..64",
    .help = "bounces of reflected light to follow"};
static const cli_option opt_bounce_albedo = {
    .id = CLI_OPT_BOUNCE_ALBEDO,
    .long_name = "bounce-albedo",
    .value_name = "FILE",
    .help = "albedo map (grey; RGB: luma) of the height's size, times RHO"};
static const cli_option opt_brightness = {
    .id = CLI_OPT_BRIGHTNESS,
    .long_name = "brightness",
    .value_name = "FILE",
    .help = "brightness map (grey; RGB: luma) multiplying ssbump and weights "
            "(a texel over 1 is scaled down whole)"};

static const cli_option *const bake_options[] = {
    &cli_opt_scale,
    &cli_opt_rays,
    &opt_slices,
    &cli_opt_filter_radius,
    &cli_opt_filter_threshold,
    &cli_opt_bias,
    &cli_opt_power,
    &cli_opt_basis,
    &cli_opt_normal_filter,
    &cli_opt_normal_y,
    &cli_opt_threads,
    &cli_opt_clamp,
    &cli_opt_channel,
    &cli_opt_depth,
    &cli_opt_mips,
    &opt_bounce,
    &opt_bounces,
    &opt_bounce_albedo,
    &opt_brightness,
    &opt_out_normal,
    &opt_out_weights,
    &opt_out_ssbump,
    &opt_out_ao,
    &opt_out_bent,
    &opt_out_filtered,
    &cli_opt_slope,
    &cli_opt_slope_lit,
    &opt_prefix,
    &cli_opt_out_dir,
    &cli_opt_maps,
    &cli_opt_name,
    &cli_opt_keep_going,
    &cli_opt_force,
    &cli_opt_depfile,
    &opt_json,
    &opt_quiet,
    &cli_opt_help,
};

static const cli_command bake_command = {
    "bake",
    "HEIGHT --scale S [OPTIONS] (-o PREFIX | --normal FILE | --ssbump FILE | ... | "
    "--out-dir DIR)",
    "Bakes the requested maps from HEIGHT in one pass; tracing runs only when\n"
    "ssbump, ao or bent is asked for. Tracing finds each texel's exact horizon\n"
    "in each azimuth slice and integrates the slice above it exactly; what is\n"
    "left is azimuth sampling. Cost and mean |error| against converged truth\n"
    "(rock06, 1024 x 1024 at scale 128, 2 cores; error on its 256 x 256 downsample):\n"
    "  budget       slices   trace     ao      ssbump\n"
    "  64 rays         8     ~0.4 s   0.0015   0.0030\n"
    "  256 rays       16     ~0.7 s   0.0004   0.0010   (the default)\n"
    "  1024 rays      32     ~2.6 s   0.0001   0.0004\n"
    "With --clamp the trace takes 2.3 to 3.4 times as long. See the README's\n"
    "Performance and Accuracy.\n"
    "\n"
    "Batches: bumpbake bake HEIGHT|DIR... --scale S --out-dir DIR [--maps LIST]\n"
    "bakes every HEIGHT (a directory: the images in it, sorted, not below it)\n"
    "in one process into DIR/--name, and skips an input whose outputs are\n"
    "up to date: their provenance names the same input bytes, parameters\n"
    "and bumpbake version (--force bakes anyway).",
    bake_options,
    (int)(sizeof bake_options / sizeof bake_options[0]),
    cli_settings_init,
};

typedef struct bake_args {
  cli_settings settings;
  const char *paths[OUTPUT_KIND_COUNT];  /* NULL = not written */
  char *prefix_paths[OUTPUT_KIND_COUNT]; /* malloc'd paths made from -o */
  const char *prefix;
  int json, quiet;
  cli_slope_args slope; /* --slope FILE, --lit AZ,EL */
  cli_batch_args batch; /* --out-dir, --maps, --name, ..., --depfile */
  const char *json_status; /* a batch's "status" field of the JSON line */
  const char *bounce_albedo_path, *brightness_path;
  int bounce_given;
  bb_image bounce_albedo_map, brightness_map;
} bake_args;

static int bake_option(void *ctx, const cli_option *opt, const char *arg) {
  bake_args *a = ctx;
  if (opt->id >= CLI_OPT_OUT_NORMAL && opt->id <= CLI_OPT_OUT_FILTERED) {
    a->paths[opt->id - CLI_OPT_OUT_NORMAL] = arg;
    return 0;
  }
  if (cli_slope_owns(opt))
    return cli_slope_option(bake_command.name, &a->slope, opt, arg);
  if (cli_batch_owns(opt))
    return cli_batch_option(&a->batch, opt, arg);
  if (opt->id == CLI_OPT_BASIS)
    a->batch.basis_arg = arg; /* a basis file is a dependency of the bake */
  switch (opt->id) {
  case CLI_OPT_OUTPUT:
    a->prefix = arg;
    return 0;
  case CLI_OPT_JSON:
    a->json = 1;
    return 0;
  case CLI_OPT_QUIET:
    a->quiet = 1;
    return 0;
  case CLI_OPT_SLICES:
    return cli_parse_int(bake_command.name, "--slices", arg, 1, BB_MAX_SLICES,
                         &a->settings.bake.slices);
  case CLI_OPT_BOUNCE:
    a->bounce_given = 1;
    return cli_parse_double(bake_command.name, "--bounce", arg, 0.0, 0, 1.0,
                            &a->settings.bake.bounce_albedo);
  case CLI_OPT_BOUNCES:
    return cli_parse_int(bake_command.name, "--bounces", arg, 0, BB_MAX_BOUNCES,
                         &a->settings.bake.bounces);
  case CLI_OPT_BOUNCE_ALBEDO:
    a->bounce_albedo_path = arg;
    return 0;
  case CLI_OPT_BRIGHTNESS:
    a->brightness_path = arg;
    return 0;
  default:
    break;
  }
  return cli_settings_apply(bake_command.name, &a->settings, opt, arg);
}

/* -o PREFIX names the outputs not given one by one. */
static int expand_prefix(bake_args *a) {
  if (!a->prefix)
    return 0;
  for (int k = 0; k < OUTPUT_KIND_COUNT; k++) {
    if (!(prefix_kinds & BB_OUTPUT_BIT(k)) || a->paths[k])
      continue;
    const char *name = kind_info(k)->name;
    size_t len = strlen(a->prefix) + strlen(name) + sizeof "_.png";
    a->prefix_paths[k] = malloc(len);
    if (!a->prefix_paths[k]) {
      cli_file_error(a->prefix, "out of memory");
      return BB_EXIT_FAILURE;
    }
    snprintf(a->prefix_paths[k], len, "%s_%s.png", a->prefix, name);
    a->paths[k] = a->prefix_paths[k];
  }
  return 0;
}

/* The slope map and its preview must not name a file another output does. */
static int check_slope_names(const bake_args *a) {
  const char *slope[2] = {a->slope.path, a->slope.lit_path};
  const char *slope_kind[2] = {"slope", "slope_lit"};
  for (int s = 0; s < 2; s++) {
    if (!slope[s])
      continue;
    for (int k = 0; k < OUTPUT_KIND_COUNT; k++)
      if (a->paths[k] && cli_same_file(a->paths[k], slope[s]))
        return cli_usage_error(bake_command.name, "%s and %s would both be written to %s",
                               kind_info(k)->name, slope_kind[s], slope[s]);
  }
  if (slope[0] && slope[1] && cli_same_file(slope[0], slope[1]))
    return cli_usage_error(bake_command.name, "slope and slope_lit would both be written to %s",
                           slope[1]);
  return 0;
}

/* A map with a channel per basis direction needs a format with room for
 * them: PNG and TGA hold 4, so "hl2+z" still fits RGBA. Refused before the
 * bake, not after it. */
static int check_channels(const bake_args *a, int k) {
  const bb_basis *basis = &a->settings.bake.basis;
  const int room = bb_path_max_channels(a->paths[k]);
  if (kind_info(k)->channels != 0 || basis->count <= room) /* 0: one per direction */
    return 0;
  const char *dot = strrchr(a->paths[k], '.');
  return cli_usage_error(bake_command.name,
                         "%s: --basis %s gives %s %d channels and %s files hold at most %d "
                         "(write it as .exr or .tif)",
                         a->paths[k], a->batch.basis_arg ? a->batch.basis_arg : basis->name,
                         kind_info(k)->name, basis->count,
                         dot ? dot : "such", room);
}

/* Every output is checked before the (possibly long) bake starts. */
static int check_outputs(bake_args *a, const char *input) {
  int any = a->slope.path != NULL;
  for (int k = 0; k < OUTPUT_KIND_COUNT; k++) {
    if (!a->paths[k])
      continue;
    any = 1;
    const char *maps[2] = {a->bounce_albedo_path, a->brightness_path};
    for (int m = 0; m < 2; m++)
      if (maps[m] && cli_same_file(maps[m], a->paths[k]))
        return cli_usage_error(bake_command.name, "%s would overwrite the input %s",
                               kind_info(k)->name, maps[m]);
    for (int j = 0; j < k; j++)
      if (a->paths[j] && cli_same_file(a->paths[j], a->paths[k]))
        return cli_usage_error(bake_command.name, "%s and %s would both be written to %s",
                               kind_info(j)->name, kind_info(k)->name, a->paths[k]);
    int rc = cli_check_output(bake_command.name, input, a->paths[k], a->settings.depth);
    if (!rc)
      rc = cli_check_mips(bake_command.name, &a->settings, a->paths[k]);
    if (!rc)
      rc = check_channels(a, k);
    if (rc)
      return rc;
  }
  if (!any)
    return cli_usage_error(
        bake_command.name,
        "nothing to write: give -o PREFIX or at least one of --normal, "
        "--weights, --ssbump, --ao, --bent, --filtered, --slope");
  int rc = cli_slope_check(bake_command.name, &a->slope, input, a->settings.depth);
  return rc ? rc : check_slope_names(a);
}

/* A batch names its outputs itself (--maps, --name). */
static int check_batch_args(const bake_args *a) {
  int named = a->prefix || a->slope.path;
  for (int k = 0; k < OUTPUT_KIND_COUNT; k++)
    named |= a->paths[k] != NULL;
  if (!named)
    return 0;
  return cli_usage_error(bake_command.name, "--out-dir names the outputs: choose the maps "
                                            "with --maps, not -o, --MAP FILE or --slope");
}

static int check_positionals(const bake_args *a, int argc, char **argv, int first) {
  if (argc - first > 1 && !a->batch.out_dir)
    return cli_usage_error(bake_command.name, "several HEIGHT files need --out-dir DIR");
  return cli_expect_positionals(&bake_command, argc, argv, first,
                                a->batch.out_dir && argc - first > 1 ? argc - first : 1,
                                "HEIGHT");
}

/* --bounce-albedo and --brightness: read once, for every HEIGHT (the
 * library checks their size against each). --bounce-albedo alone bounces
 * with the map as it is (RHO 1). */
static int load_bake_maps(bake_args *a) {
  const char *paths[2] = {a->bounce_albedo_path, a->brightness_path};
  bb_image *maps[2] = {&a->bounce_albedo_map, &a->brightness_map};
  for (int m = 0; m < 2; m++) {
    if (!paths[m])
      continue;
    bb_error err = {{0}};
    bb_status st = cli_read_image(paths[m], maps[m], NULL, &err);
    if (st != BB_OK)
      return cli_status_exit(paths[m], st, &err);
  }
  if (a->bounce_albedo_path) {
    a->settings.bake.bounce_albedo_map = &a->bounce_albedo_map;
    if (!a->bounce_given)
      a->settings.bake.bounce_albedo = 1.0;
  }
  if (a->brightness_path)
    a->settings.bake.brightness = &a->brightness_map;
  return 0;
}

/* Parses and checks the command line; *first receives the index of the
 * first HEIGHT. */
static int bake_parse(int argc, char **argv, bake_args *a, int *first) {
  int rc = cli_parse_options(&bake_command, argc, argv, bake_option, a, first);
  if (!rc)
    rc = load_bake_maps(a);
  if (!rc && !a->batch.out_dir)
    rc = cli_batch_check_single(bake_command.name, &a->batch);
  if (!rc)
    rc = check_positionals(a, argc, argv, *first);
  if (rc)
    return rc;
  if (!a->settings.scale_given)
    return cli_usage_error(
        bake_command.name,
        "--scale is required (texels of displacement per unit of height)");
  if (a->batch.out_dir)
    return check_batch_args(a);
  rc = expand_prefix(a);
  return rc ? rc : check_outputs(a, argv[*first]);
}

static int traced(const bake_args *a) {
  return (a->settings.bake.outputs & BB_OUTPUTS_TRACED) != 0;
}

/* Timings the CLI measures around the library's own. */
typedef struct bake_timing {
  double load, write;
} bake_timing;

/* Parameters are those used: the channel the rule took and the threads
 * that ran, not "auto" and 0. */
static void print_json(const bake_args *a, const char *input, const bb_image *height,
                       const cli_height_source *source, const bb_bake_result *r,
                       const bake_timing *t) {
  const bb_bake_options *b = &a->settings.bake;
  cli_json j = {stdout, 0};
  cli_json_open(&j, NULL, '{');
  cli_json_string(&j, "input", input);
  if (a->json_status)
    cli_json_string(&j, "status", a->json_status);
  cli_json_number(&j, "width", height->width);
  cli_json_number(&j, "height", height->height);

  cli_json_open(&j, "parameters", '{');
  cli_json_number(&j, "scale", (double)b->height_scale);
  cli_json_number(&j, "rays", b->rays);
  cli_json_number(&j, "slices", b->slices ? b->slices : bb_slices_for_rays(b->rays));
  cli_json_string(&j, "rayset", traced(a) ? r->rayset_id : NULL);
  cli_json_number(&j, "filter_radius", b->smooth.radius_texels);
  cli_json_number(&j, "filter_threshold", (double)b->smooth.threshold);
  cli_json_number(&j, "bias", b->trace.bias_texels);
  cli_json_number(&j, "power", b->power);
  cli_json_string(&j, "basis", b->basis.name);
  cli_json_string(&j, "normal_filter", bb_normal_filter_name(b->normal_filter));
  cli_json_string(&j, "normal_y", b->normal_y_up ? "up" : "down");
  cli_json_string(&j, "addressing",
                  b->smooth.addressing == BB_ADDRESS_CLAMP ? "clamp" : "periodic");
  cli_json_string(&j, "channel", cli_height_channel_name(source));
  cli_json_number(&j, "threads", r->threads);
  if (b->bounce_albedo > 0.0) {
    cli_json_number(&j, "bounce", b->bounce_albedo);
    cli_json_number(&j, "bounces", r->bounces);
  }
  cli_json_close(&j, '}');

  cli_json_open(&j, "seconds", '{');
  cli_json_number(&j, "load", t->load);
  cli_json_number(&j, "smooth", r->seconds_smooth);
  cli_json_number(&j, "pyramid", r->seconds_pyramid);
  cli_json_number(&j, "trace", r->seconds_trace);
  if (b->bounce_albedo > 0.0)
    cli_json_number(&j, "bounce", r->seconds_bounce);
  cli_json_number(&j, "derive", r->seconds_derive);
  cli_json_number(&j, "write", t->write);
  cli_json_close(&j, '}');

  cli_json_number(&j, "horizons", r->horizons_found);
  cli_json_open(&j, "outputs", '[');
  for (int k = 0; k < OUTPUT_KIND_COUNT; k++) {
    if (!a->paths[k])
      continue;
    cli_json_open(&j, NULL, '{');
    cli_json_string(&j, "kind", kind_info(k)->name);
    cli_json_string(&j, "path", a->paths[k]);
    cli_json_close(&j, '}');
  }
  cli_json_close(&j, ']');
  cli_json_close(&j, '}');
  fputc('\n', stdout);
}

/* The slope map and its preview (--slope, --lit), written with the others
 * but with their own settings (cli_slope_settings). */
typedef struct slope_outputs {
  bb_image map, lit;
  cli_settings map_settings, lit_settings;
  cli_run map_run, lit_run;
} slope_outputs;

enum { MAX_OUTPUTS = OUTPUT_KIND_COUNT + 2 };

/* Writes every requested output, all or nothing: each is staged (complete
 * and synced under a temporary name) and they are renamed into place only
 * when every one succeeded, so a full disk leaves the previous files as they
 * were. */
static int write_outputs(const bake_args *a, cli_run *run, const bb_bake_result *r,
                         const slope_outputs *slope, const cli_run *filtered_run) {
  cli_staged_output outs[MAX_OUTPUTS];
  cli_stage_task tasks[MAX_OUTPUTS];
  int n = 0;
  const double t0 = cli_now_seconds();
  for (int k = 0; k < OUTPUT_KIND_COUNT; k++)
    if (a->paths[k]) {
      outs[n] = (cli_staged_output){.kind = kind_info(k)->name, .path = a->paths[k]};
      tasks[n] = (cli_stage_task){k == BB_OUTPUT_FILTERED ? filtered_run : run,
                                  bb_bake_result_image(r, (bb_output_kind)k),
                                  kind_info(k)->range, &outs[n]};
      n++;
    }
  if (slope->map.pixels) {
    outs[n] = (cli_staged_output){.kind = "slope", .path = a->slope.path};
    tasks[n] = (cli_stage_task){&slope->map_run, &slope->map, BB_RANGE_UNIT, &outs[n]};
    n++;
  }
  if (slope->lit.pixels) {
    outs[n] = (cli_staged_output){.kind = "slope_lit", .path = a->slope.lit_path};
    tasks[n] = (cli_stage_task){&slope->lit_run, &slope->lit, BB_RANGE_UNIT, &outs[n]};
    n++;
  }
  /* --threads bounds this stage as every other (r->threads is the count
   * the bake resolved: all cores for 0). */
  cli_stage_outputs(tasks, n, r->threads);
  int rc = cli_commit_outputs(outs, n);
  run->seconds_write += cli_now_seconds() - t0;
  for (int i = 0; i < n && !rc; i++)
    if (!a->json && !a->quiet)
      printf("wrote %s %s\n", outs[i].kind, outs[i].path);
  return rc;
}

/* Makes the slope outputs when --slope asked for them; 0 or the exit code
 * after printing the error. */
static int make_slope(const bake_args *a, const cli_run *run, const bb_image *filtered,
                      slope_outputs *s) {
  memset(s, 0, sizeof *s);
  if (!a->slope.path)
    return 0;
  cli_slope_settings(run->settings, 1, &s->map_settings);
  cli_slope_settings(run->settings, 0, &s->lit_settings);
  s->map_run = *run;
  s->map_run.settings = &s->map_settings;
  s->lit_run = *run;
  s->lit_run.settings = &s->lit_settings;
  return cli_slope_make(run, &a->slope, filtered, &s->map, &s->lit);
}

/* The maps to bake: those with a path, and the filtered height for --slope. */
static unsigned asked_outputs(const bake_args *a) {
  unsigned mask = 0;
  for (int k = 0; k < OUTPUT_KIND_COUNT; k++)
    if (a->paths[k])
      mask |= BB_OUTPUT_BIT(k);
  if (a->slope.path)
    mask |= BB_OUTPUT_BIT(BB_OUTPUT_FILTERED);
  return mask;
}


/* The depth of kind's file at path: --depth, but the filtered height keeps
 * the input's depth unless --depth says otherwise (a 16-bit height stays
 * 16-bit where the format can hold it). */
static bb_depth output_depth(const cli_settings *s, const cli_height_source *source, int kind,
                             const char *path) {
  if (kind == BB_OUTPUT_FILTERED && s->depth == BB_DEPTH_DEFAULT)
    return cli_depth_like_input(source, path);
  return s->depth;
}

/* write_outputs, with the filtered height at output_depth. */
static int write_outputs_keeping_depth(const bake_args *a, cli_run *run,
                                       const bb_bake_result *r, const slope_outputs *slope,
                                       const cli_height_source *source) {
  cli_settings filtered_settings = *run->settings;
  const char *path = a->paths[BB_OUTPUT_FILTERED];
  if (path)
    filtered_settings.depth = output_depth(run->settings, source, BB_OUTPUT_FILTERED, path);
  cli_run filtered_run = *run;
  filtered_run.settings = &filtered_settings;
  return write_outputs(a, run, r, slope, &filtered_run);
}

static int bake_run(cli_run *run, bake_args *a, const char *input) {
  bb_image height = {0};
  bb_bake_result result;
  memset(&result, 0, sizeof result);
  bake_timing t = {0, 0};
  a->settings.bake.outputs = asked_outputs(a);

  /* The bytes hashed before they are decoded: provenance must never pair
   * a newer file's hash with an older file's pixels. */
  if (!run->input_file_hash && bb_file_hash(input, &run->input_file_hash, NULL) != BB_OK)
    run->input_file_hash = 0;
  double t0 = cli_now_seconds();
  cli_height_source source;
  int rc = cli_load_height_source(input, &a->settings, &height, &source);
  t.load = cli_now_seconds() - t0;
  if (!rc) {
    cli_progress progress;
    cli_progress_attach(&progress, "bake", a->quiet, &a->settings.bake.trace);
    rc = cli_run_bake(input, &height, &a->settings.bake, &result);
    cli_progress_finish(&progress);
  }
  if (!rc) {
    cli_run_set_input(run, input, &height, &a->settings);
    run->rayset_id = traced(a) ? result.rayset_id : NULL;
    slope_outputs slope;
    rc = make_slope(a, run, &result.filtered, &slope);
    if (!rc)
      rc = write_outputs_keeping_depth(a, run, &result, &slope, &source);
    bb_image_free(&slope.map);
    bb_image_free(&slope.lit);
    t.write = run->seconds_write;
  }
  if (!rc && a->json)
    print_json(a, input, &height, &source, &result, &t);
  bb_bake_result_free(&result);
  bb_image_free(&height);
  return rc;
}

/* The files a single bake writes; their count. */
static int single_outputs(const bake_args *a, const char **outputs) {
  int n = 0;
  for (int k = 0; k < OUTPUT_KIND_COUNT; k++)
    if (a->paths[k])
      outputs[n++] = a->paths[k];
  if (a->slope.path)
    outputs[n++] = a->slope.path;
  if (a->slope.lit_path)
    outputs[n++] = a->slope.lit_path;
  return n;
}

/* --depfile of a single bake: every file it wrote depends on the input.
 * Checked before the bake, so it cannot replace the input or an output. */
static int bake_single(cli_run *run, bake_args *a, const char *input) {
  const char *outputs[MAX_OUTPUTS];
  const int n = single_outputs(a, outputs);
  int rc = a->batch.depfile ? cli_batch_check_depfile(bake_command.name, &a->batch,
                                                      &a->settings, input, outputs, n)
                            : 0;
  if (!rc)
    rc = bake_run(run, a, input);
  return rc == 0 && a->batch.depfile
             ? cli_batch_write_depfile(&a->batch, &a->settings, input, outputs, n)
             : rc;
}

/* ---------------------------------------------------------------- batches */

static void set_batch_paths(bake_args *a, const char *const *paths) {
  for (int k = 0; k < OUTPUT_KIND_COUNT; k++)
    a->paths[k] = paths[k];
}

static int batch_check(void *ctx, const char *input, const char *const *paths) {
  bake_args *a = ctx;
  set_batch_paths(a, paths);
  return check_outputs(a, input);
}

static int batch_bake(void *ctx, cli_run *run, const char *input, const char *const *paths) {
  bake_args *a = ctx;
  set_batch_paths(a, paths);
  a->json_status = "baked";
  return bake_run(run, a, input);
}

/* output_depth for a batch's up-to-date check, from the input's header
 * (the bake itself takes it from the decoded file). */
static bb_depth batch_depth(void *ctx, const char *input, int kind, const char *path) {
  const bake_args *a = ctx;
  if (kind != BB_OUTPUT_FILTERED || a->settings.depth != BB_DEPTH_DEFAULT)
    return a->settings.depth;
  bb_image_info info;
  int saved = cli_mute_stderr();
  bb_status st = bb_image_read_info(input, NULL, NULL, NULL, &info, NULL);
  cli_unmute_stderr(saved);
  if (st != BB_OK)
    return a->settings.depth; /* the bake will say what is wrong */
  cli_height_source source = {.bits_per_sample = info.bits_per_sample,
                              .is_float = info.is_float};
  bb_image_info_free(&info);
  return output_depth(&a->settings, &source, kind, path);
}

static int run_batch(cli_run *run, bake_args *a, int argc, char **argv, int first) {
  cli_batch_client client = {bake_command.name, prefix_kinds, &a->settings, a->json, a->quiet,
                             a, batch_check, batch_depth, batch_bake};
  return cli_batch_run(&client, &a->batch, run, argc, argv, first);
}

int bb_cli_bake(int argc, char **argv) {
  cli_run run;
  if (cli_run_init(&run, argc, argv)) /* before getopt permutes argv */
    return BB_EXIT_FAILURE;
  bake_args a;
  memset(&a, 0, sizeof a);
  cli_settings_init(&a.settings);
  int first = 0;
  int rc = bake_parse(argc, argv, &a, &first);
  if (rc < 0)
    rc = BB_EXIT_OK; /* --help */
  else if (rc == 0 && a.batch.out_dir)
    rc = run_batch(&run, &a, argc, argv, first);
  else if (rc == 0)
    rc = bake_single(&run, &a, argv[first]);
  for (int k = 0; k < OUTPUT_KIND_COUNT; k++)
    free(a.prefix_paths[k]);
  cli_slope_free(&a.slope);
  bb_image_free(&a.bounce_albedo_map);
  bb_image_free(&a.brightness_map);
  cli_run_free(&run);
  return rc;
}
