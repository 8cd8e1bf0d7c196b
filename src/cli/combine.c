/* combine.c: `bumpbake combine`, blending two maps by a mask or a
 * constant, or overlaying a detail map (docs/commands/combine.md). */
#include "cli.h"
#include "common.h"
#include "maps.h"

#include <float.h>
#include <string.h>

static const cli_option opt_output = {
    .id = CLI_OPT_OUTPUT,
    .long_name = "output",
    .short_name = 'o',
    .value_name = "OUT",
    .help = "combined map to write (.png .tga .tif .exr); required"};
static const cli_option opt_kind = {.id = CLI_OPT_MAP_KIND,
                                    .long_name = "kind",
                                    .value_name = "ssbump|weights|ao|normal",
                                    .default_text = "ssbump",
                                    .help = "what A and B hold"};
static const cli_option opt_mix = {.id = CLI_OPT_MAP_MIX,
                                   .long_name = "mix",
                                   .value_name = "T",
                                   .range_text = "0..1",
                                   .help = "blend (1 - T) A + T B"};
static const cli_option opt_mask = {
    .id = CLI_OPT_MAP_MASK,
    .long_name = "mask",
    .value_name = "FILE",
    .help =
        "blend with T per texel from FILE (grey, or mean of R, G, B; clamped to 0..1)"};
static const cli_option opt_detail = {
    .id = CLI_OPT_MAP_DETAIL,
    .long_name = "detail",
    .help = "overlay B on A as detail (ssbump/weights/ao: A * B / flat; normal: "
            "DOOM 3's addnormals)"};
static const cli_option opt_brightness = {
    .id = CLI_OPT_MAP_BRIGHTNESS,
    .long_name = "brightness",
    .value_name = "FILE",
    .help = "multiply A by FILE's grey (RGB: luma), the paper's brightness stored in the "
            "ssbump; a texel over 1 is scaled down whole (no B)"};
static const cli_option opt_normal_y = {
    .id = CLI_OPT_NORMAL_Y,
    .long_name = "normal-y",
    .value_name = "down|up",
    .default_text = "down",
    .help = "green axis of normal maps in and out (up = OpenGL)"};

static const cli_option *const combine_options[] = {
    &opt_output,         &opt_mix,      &opt_mask,
    &opt_detail,         &opt_brightness, &opt_kind, &opt_normal_y,
    &cli_maps_opt_depth, &cli_opt_mips, CLI_TEXTURE_OPTIONS, &cli_opt_help};

static const cli_command combine_command = {
    "combine",
    "A B -o OUT (--mix T | --mask FILE | --detail) [OPTIONS] | A --brightness FILE -o OUT",
    "Combines two maps of the same size. --mix and --mask blend them,\n"
    "(1 - T) A + T B, linear for ssbump, weights and ao (they are linear in light),\n"
    "renormalised for normal maps. --detail overlays B on A: A * B / flat for\n"
    "ssbump, weights and ao (flat = B's flat, unoccluded value as its file holds\n"
    "it: 147 in an 8-bit ssbump), DOOM 3's addnormals for normal maps. A flat B,\n"
    "T = 0 or a black mask leaves A unchanged bit for bit. Channels past the\n"
    "kind's (an alpha) blend like the rest, or with --detail are A's.\n"
    "--brightness multiplies one map by a grey brightness map (ssbump, weights: a\n"
    "texel whose largest channel would pass 1 is scaled so it is 1, its ratios kept;\n"
    "ao: clipped at 1).",
    combine_options,
    (int)(sizeof combine_options / sizeof combine_options[0]),
    cli_settings_init,
};

typedef struct combine_args {
  cli_settings settings;
  const char *output, *mask, *brightness;
  bb_map_kind kind;
  double mix;
  int mix_given, detail;
} combine_args;

static int combine_option(void *ctx, const cli_option *opt, const char *arg) {
  combine_args *a = ctx;
  switch (opt->id) {
  case CLI_OPT_OUTPUT:
    a->output = arg;
    return 0;
  case CLI_OPT_MAP_MASK:
    a->mask = arg;
    return 0;
  case CLI_OPT_MAP_DETAIL:
    a->detail = 1;
    return 0;
  case CLI_OPT_MAP_BRIGHTNESS:
    a->brightness = arg;
    return 0;
  case CLI_OPT_MAP_MIX:
    a->mix_given = 1;
    return cli_parse_double(combine_command.name, "--mix", arg, 0.0, 0, 1.0, &a->mix);
  case CLI_OPT_MAP_KIND:
    if (bb_map_kind_parse(arg, &a->kind, NULL))
      return cli_usage_error(combine_command.name,
                             "--kind must be one of ssbump|weights|ao|normal (got '%s')",
                             arg);
    return 0;
  default:
    return cli_settings_apply(combine_command.name, &a->settings, opt, arg);
  }
}

static int combine_parse(int argc, char **argv, combine_args *a, const char **in) {
  int first = 0;
  int rc = cli_parse_options(&combine_command, argc, argv, combine_option, a, &first);
  if (!rc)
    rc = cli_expect_positionals(&combine_command, argc, argv, first, a->brightness ? 1 : 2,
                                a->brightness ? "A" : "A B");
  if (rc)
    return rc;
  in[0] = argv[first];
  in[1] = a->brightness ? a->brightness : argv[first + 1];
  if (!a->output)
    return cli_usage_error(combine_command.name, "-o OUT is required");
  int modes = a->mix_given + (a->mask != NULL) + a->detail + (a->brightness != NULL);
  if (modes != 1)
    return cli_usage_error(combine_command.name,
                           "give exactly one of --mix T, --mask FILE, --detail "
                           "and --brightness FILE");
  /* The output must not replace A, B (or the brightness map) or the mask. */
  const bb_output_spec spec = {a->output, "output", 0, a->settings.depth, a->settings.mips, 0,
                               0, 0, BB_RANGE_UNIT, &a->settings.texture};
  const char *reads[3] = {in[0], in[1], a->mask};
  bb_error err = {{0}};
  bb_status st = bb_outputs_check(&spec, 1, reads, a->mask ? 3 : 2, &err);
  rc = st == BB_OK ? 0 : cli_library_error(combine_command.name, st, &err);
  return rc;
}

/* A map as read, and the values the library combines (normals decoded). */
typedef struct map_input {
  bb_image file, values;
  bb_image_info info;
} map_input;

static void map_input_free(map_input *m) {
  bb_image_free(&m->file);
  bb_image_free(&m->values);
  bb_image_info_free(&m->info);
}

static int load_map(const combine_args *a, const char *path, map_input *m) {
  int rc = cli_maps_read(path, &m->file, &m->info);
  /* --detail scales Half-Life 2's three channels; a blend is linear in
   * every channel, so it takes maps of any basis (of the same count). */
  if (!rc && a->detail && (a->kind == BB_MAP_SSBUMP || a->kind == BB_MAP_WEIGHTS))
    rc = cli_maps_check_hl2(path, &m->file, &m->info);
  if (rc || a->kind != BB_MAP_NORMAL)
    return rc;
  /* Not renormalised: a texel the operators copy must keep its code. */
  bb_normal_decode_options o;
  bb_normal_decode_options_init(&o);
  o.normal_y_up = a->settings.bake.normal_y_up;
  o.normalize = 0;
  bb_error err = {{0}};
  return cli_status_exit(
      path, bb_normal_map_decode(&m->file, m->info.is_float, &o, &m->values, &err), &err);
}

static const bb_image *values_of(const map_input *m) {
  return m->values.pixels ? &m->values : &m->file;
}

static int load_mask(const char *path, bb_image *mask) {
  map_input m = {{0}, {0}, {0}};
  int rc = cli_maps_read(path, &m.file, &m.info);
  if (!rc) {
    bb_error err = {{0}};
    bb_status st =
        bb_height_from_image(&m.file, m.info.alpha_channel, BB_CHANNEL_AUTO, mask, &err);
    rc = cli_status_exit(path, st, &err);
  }
  map_input_free(&m);
  return rc;
}

/* Runs the library; errors about two images name the first input. */
static int combine_maps(const combine_args *a, const char *const *in, const map_input *m,
                        const bb_image *mask, bb_image *out) {
  bb_error err = {{0}};
  bb_status st;
  if (a->brightness) {
    st = bb_combine_brightness(values_of(&m[0]), &m[1].file, a->kind, out, &err);
  } else if (a->detail) {
    float flat[3];
    bb_map_flat_texel(a->kind, m[1].info.bits_per_sample, m[1].info.is_float, flat);
    st = bb_combine_detail(values_of(&m[0]), values_of(&m[1]), a->kind, flat, out, &err);
  } else {
    st = bb_combine_blend(values_of(&m[0]), values_of(&m[1]), mask->pixels ? mask : NULL,
                          (float)a->mix, a->kind, out, &err);
  }
  return cli_status_exit(in[0], st, &err);
}

static int combine_run(const cli_run *run, combine_args *a, const char *const *in) {
  map_input m[2] = {{{0}, {0}, {0}}, {{0}, {0}, {0}}};
  bb_image mask = {0}, out = {0};
  int rc = load_map(a, in[0], &m[0]);
  if (!rc && a->brightness) /* a grey to multiply by, whatever the kind */
    rc = cli_maps_read(in[1], &m[1].file, &m[1].info);
  else if (!rc)
    rc = load_map(a, in[1], &m[1]);
  if (!rc && a->mask)
    rc = load_mask(a->mask, &mask);
  if (!rc)
    rc = combine_maps(a, in, m, &mask, &out);
  if (!rc) {
    const int normal = a->kind == BB_MAP_NORMAL;
    if (normal && a->settings.bake.normal_y_up)
      bb_image_flip_green(&out); /* back to the inputs' convention */
    bb_depth depth = cli_maps_output_depth(a->settings.depth, &m[0].info, a->output);
    rc = cli_maps_write(
        run, cli_maps_file_name(in[0]), &m[0].file, bb_map_kind_name(a->kind), a->output,
        &out, normal ? BB_RANGE_SIGNED : BB_RANGE_UNIT, depth, a->settings.mips,
        &a->settings.texture);
  }
  if (!rc)
    cli_printf_line("wrote %s %s", bb_map_kind_name(a->kind), a->output);
  bb_image_free(&out);
  bb_image_free(&mask);
  map_input_free(&m[0]);
  map_input_free(&m[1]);
  return rc;
}

int bb_cli_combine(int argc, char **argv) {
  cli_run run;
  if (cli_run_init(&run, argc, argv)) /* before getopt permutes argv */
    return BB_EXIT_FAILURE;
  combine_args a;
  memset(&a, 0, sizeof a);
  cli_settings_init(&a.settings);
  a.kind = BB_MAP_SSBUMP;
  const char *in[2] = {NULL, NULL};
  int rc = combine_parse(argc, argv, &a, in);
  if (rc < 0)
    rc = BB_EXIT_OK; /* --help */
  else if (rc == 0)
    rc = combine_run(&run, &a, in);
  cli_run_free(&run);
  return rc;
}
