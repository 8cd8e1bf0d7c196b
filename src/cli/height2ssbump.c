/* height2ssbump.c: `bumpbake height2ssbump`, a drop-in for Valve's tool
 * of that name (docs/conventions.md "Valve compatibility"): same flags, same
 * defaults, same output files (FILE-ssbump.tga or FILE-bump.tga, RGBA). */
#include "cli.h"
#include "common.h"
#include "options.h"
#include "progress.h"

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

static const cli_option opt_quiet = {.id = CLI_OPT_QUIET,
                                     .short_name = 'q',
                                     .default_text = "off",
                                     .help = "no list of files written"};

static const cli_option opt_output = {
    .id = CLI_OPT_OUTPUT,
    .short_name = 'o',
    .long_name = "output",
    .value_name = "FILE",
    .default_text = "FILE-ssbump.tga (-n: FILE-bump.tga)",
    .help = "write FILE instead, in its extension's format (.vtf: a Source texture)"};

static const cli_option *const h2s_options[] = {
    &opt_rays,   &opt_normal,        &opt_ao_alpha,         &opt_radius,
    &opt_dump,   &opt_detail,        &opt_quiet,            &opt_output,
    CLI_TEXTURE_OPTIONS,             &cli_opt_vmt,          &cli_opt_materials,
    &cli_opt_basetexture,            &cli_opt_help,
};

static void h2s_settings_init(cli_settings *s) {
  cli_settings_init(s);
  s->bake.rays = VALVE_RAYS;
  s->bake.smooth.radius_texels = VALVE_FILTER_RADIUS;
  s->bake.normal_filter = BB_NORMAL_VALVE; /* parity with Valve's tool */
  /* Valve writes 8-bit RGBA TGA: the format's default depth, which leaves
   * a texture (.vtf) to its texture format. */
  s->depth = BB_DEPTH_DEFAULT;
}

static const cli_command h2s_command = {
    "height2ssbump",
    "[-r N] [-n] [-A] [-f R] [-D] [-d] FILE BUMPSCALE",
    "Valve-compatible: bakes FILE-ssbump.tga (RGB = ssbump, A = filtered height)\n"
    "next to FILE. The height is FILE's alpha channel, or the mean of R, G, B when\n"
    "it has none. BUMPSCALE (> 0) is the height scale in texels. -o names another\n"
    "file; with -o NAME-ssbump.vtf --vmt NAME.vmt it goes straight into a Source\n"
    "game's materials (docs/textures.md).",
    h2s_options,
    (int)(sizeof h2s_options / sizeof h2s_options[0]),
    h2s_settings_init,
};

typedef struct h2s_args {
  cli_settings settings;
  int normal_map, ao_in_alpha, dump_filtered, detail, quiet;
  const char *input;
  const char *output_given;               /* -o FILE, or NULL */
  char *output; /* malloc'd: -o's, or FILE-ssbump.tga or FILE-bump.tga */
  const char *vmt, *materials, *basetexture; /* --vmt and its paths */
  char *vmt_text;                         /* the material's bytes */
  size_t vmt_size;
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
  case CLI_OPT_QUIET:
    a->quiet = 1;
    return 0;
  case CLI_OPT_OUTPUT:
    a->output_given = arg;
    return 0;
  case CLI_OPT_VMT:
    a->vmt = arg;
    return 0;
  case CLI_OPT_MATERIALS:
    a->materials = arg;
    return 0;
  case CLI_OPT_BASETEXTURE:
    a->basetexture = arg;
    return 0;
  default:
    break;
  }
  return cli_settings_apply(h2s_command.name, &a->settings, opt, arg);
}

static const char *output_kind(const h2s_args *a) {
  if (a->normal_map)
    return a->ao_in_alpha ? "normal+ao" : "normal+height";
  if (a->detail)
    return a->ao_in_alpha ? "detail-ssbump+ao" : "detail-ssbump+height";
  return a->ao_in_alpha ? "ssbump+ao" : "ssbump+height";
}

static int h2s_parse(int argc, char **argv, h2s_args *a) {
  int first = 0;
  int rc = cli_parse_options(&h2s_command, argc, argv, h2s_option, a, &first);
  if (!rc)
    rc = cli_expect_positionals(&h2s_command, argc, argv, first, 2,
                                argc - first == 1 ? "BUMPSCALE" : "FILE BUMPSCALE");
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

  a->output = a->output_given
                  ? strdup(a->output_given)
                  : bb_path_with_suffix(a->input, a->normal_map ? "-bump.tga" : "-ssbump.tga");
  if (!a->output) {
    cli_file_error(a->input, "out of memory");
    return BB_EXIT_FAILURE;
  }
  if (a->dump_filtered && bb_same_file(a->output, dump_path))
    return cli_usage_error(h2s_command.name, "-D would write %s over the output %s",
                           dump_path, a->output);
  if ((a->materials || a->basetexture) && !a->vmt)
    return cli_usage_error(h2s_command.name,
                           "--materials and --basetexture name a material's paths: give "
                           "--vmt FILE");
  bb_error err = {{0}};
  if (a->vmt) {
    const bb_vmt_options v = {a->materials, a->output, a->basetexture, !a->normal_map};
    bb_status st = bb_vmt_text(a->vmt, &v, &a->vmt_text, &a->vmt_size, &err);
    if (st != BB_OK)
      return cli_library_error(h2s_command.name, st, &err);
  }
  /* The input's size, so a texture the size cannot make is refused now. */
  int width = 0, height = 0;
  if (bb_image_read_info(a->input, &width, &height, NULL, NULL, NULL) != BB_OK)
    width = height = 0; /* the bake says why */
  bb_output_spec outputs[3] = {
      {a->output, output_kind(a), 4, a->settings.depth, 0, 0, width, height, BB_RANGE_UNIT,
       &a->settings.texture},
      {dump_path, "filtered", 1, a->settings.depth, 0, 0, 0, 0, BB_RANGE_UNIT, NULL},
      {a->vmt, "material", 0, BB_DEPTH_DEFAULT, 0, 1, 0, 0, BB_RANGE_UNIT, NULL}};
  int n = a->dump_filtered ? 2 : 1;
  if (a->vmt)
    outputs[n++] = outputs[2];
  bb_status st = bb_outputs_check(outputs, n, &a->input, 1, &err);
  return st == BB_OK ? 0 : cli_library_error(h2s_command.name, st, &err);
}

/* Makes the RGBA image to write from the bake (and for -d the input's
 * colour, read again: the height reader keeps only the height). */
static int make_rgba(const h2s_args *a, const bb_image *height, const bb_bake_result *r,
                     bb_image *rgba) {
  bb_valve_options vo;
  bb_valve_options_init(&vo);
  vo.normal_map = a->normal_map;
  vo.ao_in_alpha = a->ao_in_alpha;
  bb_error err = {{0}};
  bb_status st = bb_valve_pack(r, &vo, rgba, &err);
  if (st == BB_OK && a->detail) {
    bb_image colour = {0};
    st = bb_image_read(a->input, &colour, NULL, &err);
    if (st == BB_OK)
      st = bb_valve_detail(rgba, &colour, height, &a->settings.bake.smooth, &err);
    bb_image_free(&colour);
  }
  return cli_status_exit(a->input, st, &err);
}

/* Valve's RGBA file (and -D's filtered height), written together with the
 * library's provenance under Valve's kind names. */
static int write_outputs(const h2s_args *a, const char *command_line,
                         const bb_height_source *source, const bb_bake_result *r,
                         const bb_image *rgba) {
  const int traced = (a->settings.bake.outputs & BB_OUTPUTS_TRACED) != 0;
  const char *slash = strrchr(a->input, '/');
  bb_provenance p = {command_line,     slash ? slash + 1 : a->input,
                     source->height_hash, output_kind(a),
                     &a->settings.bake, source->channel,
                     traced ? r->rayset_id : NULL, source->file_hash,
                     NULL};
  char *texts[2] = {bb_provenance_format(&p), NULL};
  p.output_kind = "filtered";
  texts[1] = bb_provenance_format(&p);
  int rc = 0;
  bb_error err = {{0}};
  if (!texts[0] || !texts[1]) {
    cli_file_error(a->output, "out of memory");
    rc = BB_EXIT_FAILURE;
  } else {
    /* With -D and --vmt, every file or none. */
    bb_output_file files[3] = {{a->output, output_kind(a), rgba, BB_RANGE_UNIT,
                                a->settings.depth, 0, texts[0], NULL, 0, &a->settings.texture},
                               {dump_path, "filtered", &r->filtered, BB_RANGE_UNIT,
                                a->settings.depth, 0, texts[1], NULL, 0, NULL},
                               {a->vmt, "material", NULL, BB_RANGE_UNIT, BB_DEPTH_DEFAULT, 0,
                                NULL, a->vmt_text, a->vmt_size, NULL}};
    int n = a->dump_filtered ? 2 : 1;
    if (a->vmt)
      files[n++] = files[2];
    bb_status st = bb_outputs_write(files, n, r->threads, &err);
    if (st != BB_OK) {
      cli_error_line(err.message);
      rc = BB_EXIT_FAILURE;
    }
    for (int i = 0; !rc && !a->quiet && i < n; i++)
      cli_printf_line("wrote %s %s", files[i].kind, files[i].path);
  }
  free(texts[0]);
  free(texts[1]);
  return rc;
}

static int h2s_run(const char *command_line, h2s_args *a) {
  bb_image height = {0}, rgba = {0};
  bb_bake_result result;
  memset(&result, 0, sizeof result);
  /* What Valve's RGBA layout takes, and -D's filtered height: only the -n
   * map with the height in alpha needs no rays. */
  a->settings.bake.outputs =
      BB_OUTPUT_BIT(a->normal_map ? BB_OUTPUT_NORMAL : BB_OUTPUT_SSBUMP) |
      BB_OUTPUT_BIT(a->ao_in_alpha ? BB_OUTPUT_AO : BB_OUTPUT_FILTERED) |
      (a->dump_filtered ? BB_OUTPUT_BIT(BB_OUTPUT_FILTERED) : 0u);
  bb_height_source source;
  bb_error err = {{0}};
  /* Valve's channel rule: alpha when there is one, else (Valve's tool would
   * fail) the grey or the mean of R, G, B, which a note says. */
  bb_status st = bb_height_file_read(a->input, BB_CHANNEL_VALVE, a->settings.bake.height_scale,
                                     cli_note, NULL, &height,
                                     &source, &err);
  int rc = cli_status_exit(a->input, st, &err);
  if (!rc) {
    cli_progress progress;
    cli_progress_attach(&progress, "height2ssbump", 0, &a->settings.bake.trace);
    rc = cli_status_exit(a->input, bb_bake(&height, &a->settings.bake, &result, &err), &err);
    cli_progress_finish(&progress);
  }
  if (!rc)
    rc = make_rgba(a, &height, &result, &rgba);
  if (!rc)
    rc = write_outputs(a, command_line, &source, &result, &rgba);
  bb_image_free(&rgba);
  bb_bake_result_free(&result);
  bb_image_free(&height);
  return rc;
}

int bb_cli_height2ssbump(int argc, char **argv) {
  char *command_line = cli_command_line(argc, argv); /* before getopt permutes argv */
  if (!command_line)
    return BB_EXIT_FAILURE;
  h2s_args a;
  memset(&a, 0, sizeof a);
  h2s_settings_init(&a.settings);
  int rc = h2s_parse(argc, argv, &a);
  if (rc < 0)
    rc = BB_EXIT_OK; /* --help */
  else if (rc == 0)
    rc = h2s_run(command_line, &a);
  free(a.output);
  free(a.vmt_text);
  free(command_line);
  return rc;
}
