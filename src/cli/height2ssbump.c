/* cli_height2ssbump.c: `bumpbake height2ssbump`, a drop-in for Valve's tool
 * of that name (docs/conventions.md "Valve compatibility"): same flags, same
 * defaults, same output files (FILE-ssbump.tga or FILE-bump.tga, RGBA). */
#include "common.h"

#include <float.h>
#include <stdlib.h>
#include <string.h>

/* Valve's defaults: 250 rays (-r), filter radius 10 (-f). */
enum { VALVE_RAYS = 250, VALVE_FILTER_RADIUS = 10 };

static const cli_option opt_rays = {.id = CLI_OPT_RAYS,
                                    .short_name = 'r',
                                    .value_name = "N",
                                    .range_text = "1..65536",
                                    .help = "ray budget: round(sqrt(N)) azimuth slices"};
static const cli_option opt_radius = {
    .id = CLI_OPT_FILTER_RADIUS,
    .short_name = 'f',
    .value_name = "R",
    .range_text = "0..4096",
    .help = "bilateral smoothing radius in texels, 0 = off"};
static const cli_option opt_normal = {
    .id = CLI_OPT_VALVE_NORMAL,
    .short_name = 'n',
    .default_text = "off",
    .help = "write FILE-bump.tga: RGB = normal map (0.5 + 0.5 N)"};
static const cli_option opt_ao_alpha = {
    .id = CLI_OPT_VALVE_AO_ALPHA,
    .short_name = 'A',
    .default_text = "off",
    .help = "put ambient occlusion in alpha, not the height"};
static const cli_option opt_dump = {
    .id = CLI_OPT_VALVE_DUMP,
    .short_name = 'D',
    .default_text = "off",
    .help = "also write the filtered height as ./filtered.tga"};
static const cli_option opt_detail = {
    .id = CLI_OPT_VALVE_DETAIL,
    .short_name = 'd',
    .default_text = "off",
    .help = "detail variant: RGB times (R+G+B)/sqrt(3) of the filtered input colour"};

static const cli_option *const h2s_options[] = {
    &opt_rays, &opt_normal, &opt_ao_alpha, &opt_radius,
    &opt_dump, &opt_detail, &cli_opt_help,
};

static void h2s_settings_init(cli_settings *s) {
  cli_settings_init(s);
  s->bake.rays = VALVE_RAYS;
  s->bake.smooth.radius_texels = VALVE_FILTER_RADIUS;
  s->bake.normal_filter = BB_NORMAL_VALVE; /* parity with Valve's tool */
  s->depth = BB_DEPTH_8; /* Valve writes 8-bit RGBA TGA */
}

static const cli_command h2s_command = {
    "height2ssbump",
    "[-r N] [-n] [-A] [-f R] [-D] [-d] FILE BUMPSCALE",
    "Valve-compatible: bakes FILE-ssbump.tga (RGB = ssbump, A = filtered height)\n"
    "next to FILE. The height is FILE's alpha channel, or the mean of R, G, B when\n"
    "it has none. BUMPSCALE (> 0) is the height scale in texels.",
    h2s_options,
    (int)(sizeof h2s_options / sizeof h2s_options[0]),
    h2s_settings_init,
};

typedef struct h2s_args {
  cli_settings settings;
  int normal_map, ao_in_alpha, dump_filtered, detail;
  const char *input;
  char *output; /* malloc'd FILE-ssbump.tga or FILE-bump.tga */
} h2s_args;

static const char dump_path[] = "filtered.tga";

static int h2s_option(void *ctx, const cli_option *opt, const char *arg) {
  h2s_args *a = ctx;
  switch (opt->id) {
  case CLI_OPT_VALVE_NORMAL:
    a->normal_map = 1;
    return 0;
  case CLI_OPT_VALVE_AO_ALPHA:
    a->ao_in_alpha = 1;
    return 0;
  case CLI_OPT_VALVE_DUMP:
    a->dump_filtered = 1;
    return 0;
  case CLI_OPT_VALVE_DETAIL:
    a->detail = 1;
    return 0;
  default:
    break;
  }
  return cli_settings_apply(h2s_command.name, &a->settings, opt, arg);
}

static int h2s_parse(int argc, char **argv, h2s_args *a) {
  int first = 0;
  int rc = cli_parse_options(&h2s_command, argc, argv, h2s_option, a, &first);
  if (!rc)
    rc = cli_expect_positionals(&h2s_command, argc, argv, first, 2, "FILE BUMPSCALE");
  if (rc)
    return rc;
  a->input = argv[first];
  double scale;
  rc = cli_parse_double(h2s_command.name, "BUMPSCALE", argv[first + 1], 0.0, 1,
                        (double)FLT_MAX, &scale);
  if (rc)
    return rc;
  a->settings.bake.height_scale = (float)scale;
  a->settings.scale_given = 1;
  /* The detail factor scales light response; on an encoded normal map it
   * would only corrupt the vectors. */
  if (a->detail && a->normal_map)
    return cli_usage_error(h2s_command.name,
                           "-d makes a detail ssbump; it cannot be used with -n");

  a->output = cli_path_with_suffix(a->input, a->normal_map ? "-bump.tga" : "-ssbump.tga");
  if (!a->output) {
    cli_file_error(a->input, "out of memory");
    return BB_EXIT_FAILURE;
  }
  rc = cli_check_output(h2s_command.name, a->input, a->output, a->settings.depth);
  if (!rc && a->dump_filtered)
    rc = cli_check_output(h2s_command.name, a->input, dump_path, a->settings.depth);
  if (!rc && a->dump_filtered && cli_same_file(a->output, dump_path))
    rc = cli_usage_error(h2s_command.name, "-D would write %s over the output %s",
                         dump_path, a->output);
  return rc;
}

/* Valve's channel rule: alpha when there is one, else (not Valve: it would
 * fail) the mean of R, G, B, which we say on stderr so nobody is surprised. */
static bb_channel valve_height_channel(const char *path, const bb_image *img,
                                       const bb_image_info *info) {
  if (info->alpha_channel >= 0)
    return BB_CHANNEL_A;
  if (img->channels >= 3) {
    fprintf(stderr,
            "bumpbake: %s: note: no alpha channel; using the mean of R, G, B as the "
            "height\n",
            path);
    return BB_CHANNEL_MEAN;
  }
  fprintf(stderr, "bumpbake: %s: note: no alpha channel; using its grey channel as the height\n",
          path);
  return BB_CHANNEL_AUTO;
}

/* Reads FILE once: its pixels (for -d) and the height by Valve's rule. */
static int load_input(h2s_args *a, bb_image *img, bb_image *height) {
  bb_image_info info;
  memset(&info, 0, sizeof info);
  bb_error err = {{0}};
  bb_status st = cli_read_image(a->input, img, &info, &err);
  if (st == BB_OK) {
    a->settings.channel = valve_height_channel(a->input, img, &info);
    st = bb_height_from_image(img, info.alpha_channel, a->settings.channel, height, &err);
  }
  bb_image_info_free(&info);
  return cli_status_exit(a->input, st, &err);
}

static const char *output_kind(const h2s_args *a) {
  if (a->normal_map)
    return a->ao_in_alpha ? "normal+ao" : "normal+height";
  if (a->detail)
    return a->ao_in_alpha ? "detail-ssbump+ao" : "detail-ssbump+height";
  return a->ao_in_alpha ? "ssbump+ao" : "ssbump+height";
}

/* Makes the RGBA image to write from the bake (and for -d the input). */
static int make_rgba(const h2s_args *a, const bb_image *img, const bb_image *height,
                     const bb_bake_result *r, bb_image *rgba) {
  bb_valve_options vo;
  bb_valve_options_init(&vo);
  vo.normal_map = a->normal_map;
  vo.ao_in_alpha = a->ao_in_alpha;
  bb_error err = {{0}};
  bb_status st = bb_valve_pack(r, &vo, rgba, &err);
  if (st == BB_OK && a->detail)
    st = bb_valve_detail(rgba, img, height, &a->settings.bake.smooth, &err);
  return cli_status_exit(a->input, st, &err);
}

static int h2s_run(cli_run *run, h2s_args *a) {
  bb_image img = {0}, height = {0}, rgba = {0};
  bb_bake_result result;
  memset(&result, 0, sizeof result);
  /* What Valve's RGBA layout takes, and -D's filtered height: only the -n
   * map with the height in alpha needs no rays. */
  a->settings.bake.outputs =
      BB_OUTPUT_BIT(a->normal_map ? BB_OUTPUT_NORMAL : BB_OUTPUT_SSBUMP) |
      BB_OUTPUT_BIT(a->ao_in_alpha ? BB_OUTPUT_AO : BB_OUTPUT_FILTERED) |
      (a->dump_filtered ? BB_OUTPUT_BIT(BB_OUTPUT_FILTERED) : 0u);

  int rc = load_input(a, &img, &height);
  if (!rc) {
    cli_progress progress;
    cli_progress_attach(&progress, "height2ssbump", 0, &a->settings.bake.trace);
    rc = cli_run_bake(a->input, &height, &a->settings.bake, &result);
    cli_progress_finish(&progress);
  }
  if (!rc)
    rc = make_rgba(a, &img, &height, &result, &rgba);
  if (!rc) {
    /* With -D, both files or neither (see cli_commit_outputs). */
    cli_run_set_input(run, a->input, &height, &a->settings);
    run->rayset_id = (a->settings.bake.outputs & BB_OUTPUTS_TRACED) ? result.rayset_id : NULL;
    cli_staged_output outs[2] = {{.kind = output_kind(a), .path = a->output},
                                 {.kind = "filtered", .path = dump_path}};
    const cli_stage_task tasks[2] = {{run, &rgba, BB_RANGE_UNIT, &outs[0]},
                                     {run, &result.filtered, BB_RANGE_UNIT, &outs[1]}};
    int n = a->dump_filtered ? 2 : 1;
    cli_stage_outputs(tasks, n, result.threads);
    rc = cli_commit_outputs(outs, n);
  }
  bb_image_free(&rgba);
  bb_bake_result_free(&result);
  bb_image_free(&height);
  bb_image_free(&img);
  return rc;
}

int bb_cli_height2ssbump(int argc, char **argv) {
  cli_run run;
  if (cli_run_init(&run, argc, argv)) /* before getopt permutes argv */
    return BB_EXIT_FAILURE;
  h2s_args a;
  memset(&a, 0, sizeof a);
  h2s_settings_init(&a.settings);
  int rc = h2s_parse(argc, argv, &a);
  if (rc < 0)
    rc = BB_EXIT_OK; /* --help */
  else if (rc == 0)
    rc = h2s_run(&run, &a);
  free(a.output);
  cli_run_free(&run);
  return rc;
}
