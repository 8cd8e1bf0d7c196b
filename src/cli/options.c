/* options.c: the option rows every baking command shares, strict number
 * parsing, the option parser and --help built from a command's table, and
 * the shared bake settings (whose ranges the library checks). */
#include "common.h"
#include "options.h"

#include <errno.h>
#include <float.h>
#include <getopt.h>
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* ------------------------------------------------------- shared option rows */

const cli_option cli_opt_help = {.id = CLI_OPT_HELP,
                                 .long_name = "help",
                                 .short_name = 'h',
                                 .help = "print this help and exit"};
const cli_option cli_opt_scale = {
    .id = CLI_OPT_SCALE,
    .long_name = "scale",
    .value_name = "S",
    .default_text = "(required)",
    .range_text = "> 0",
    .help = "height scale: texels of displacement per unit of normalised height"};
const cli_option cli_opt_rays = {.id = CLI_OPT_RAYS,
                                 .long_name = "rays",
                                 .value_name = "N",
                                 .range_text = "1..65536",
                                 .help = "ray budget, as Valve's -r: round(sqrt(N)) azimuth slices"};
const cli_option cli_opt_filter_radius = {
    .id = CLI_OPT_FILTER_RADIUS,
    .long_name = "filter-radius",
    .value_name = "R",
    .range_text = "0..4096",
    .help = "bilateral smoothing radius in texels, 0 = off"};
const cli_option cli_opt_filter_threshold = {
    .id = CLI_OPT_FILTER_THRESHOLD,
    .long_name = "filter-threshold",
    .value_name = "T",
    .range_text = "> 0",
    .help = "smoothing range threshold in normalised height (2/255 = 0.00784)"};
const cli_option cli_opt_bias = {
    .id = CLI_OPT_BIAS,
    .long_name = "bias",
    .value_name = "B",
    .range_text = "0..1e6",
    .help = "ray origin lift above the vertex in texels (0.55 = Valve's offset)"};
const cli_option cli_opt_power = {.id = CLI_OPT_POWER,
                                  .long_name = "power",
                                  .value_name = "P",
                                  .range_text = "1..1e6",
                                  .help = "exponent of the basis lobes max(0, w.B)^P"};
const cli_option cli_opt_basis = {
    .id = CLI_OPT_BASIS,
    .long_name = "basis",
    .value_name = "hl2|hl2+z|dirs:N|FILE",
    .range_text = "N 3..16",
    .help = "directions occlusion is projected on, one channel each: Half-Life 2's, "
            "N evenly spread, or a file of x y z lines (docs/commands/bake.md, \"Bases\")"};
const cli_option cli_opt_normal_filter = {
    .id = CLI_OPT_NORMAL_FILTER,
    .long_name = "normal-filter",
    .value_name = "vertex|valve|central|sobel",
    .help = "normal estimator (vertex: centred on the ray origin; valve: Valve's)"};
const cli_option cli_opt_normal_y = {
    .id = CLI_OPT_NORMAL_Y,
    .long_name = "normal-y",
    .value_name = "down|up",
    .help = "green axis: down = Source/DirectX, up = OpenGL (flips green)"};
const cli_option cli_opt_threads = {.id = CLI_OPT_THREADS,
                                    .long_name = "threads",
                                    .value_name = "N",
                                    .range_text = "0..4096",
                                    .help = "worker threads of every stage, 0 = all cores"};
const cli_option cli_opt_clamp = {.id = CLI_OPT_CLAMP,
                                  .long_name = "clamp",
                                  .default_text = "periodic",
                                  .help = "extend border texels instead of tiling"};
const cli_option cli_opt_channel = {
    .id = CLI_OPT_CHANNEL,
    .long_name = "channel",
    .value_name = "r|g|b|a|luma|mean",
    .help = "height channel (auto: the grey; alpha where it holds the height, as Valve's "
            "tools keep it; else the mean of R, G, B; a note says which)"};
const cli_option cli_opt_mips = {
    .id = CLI_OPT_MIPS,
    .long_name = "mips",
    .default_text = "off",
    .help = "write mip-mapped files (.tif/.exr): each level box-filtered, normals renormalised"};
const cli_option cli_opt_depth = {
    .id = CLI_OPT_DEPTH,
    .long_name = "depth",
    .value_name = "8|16|half|float",
    .help = "sample depth (default: 8 for png/tga/tif, float for exr)"};
const cli_option cli_opt_texture_format = {
    .id = CLI_OPT_TEXTURE_FORMAT,
    .long_name = "texture-format",
    .value_name = "NAME",
    .default_text = "default",
    .range_text = "dxt1 dxt5 bgr888 bgra8888 rgba16f (vtf); bc1 bc3 bc4 bc5 rgba8 rgba16f "
                  "rgba32f (dds)",
    .help = ".vtf/.dds format; default: VTF DXT1 (DXT5 with alpha); DDS BC5 normals, BC4 "
            "grey, BC1 colour (docs/textures.md)"};
const cli_option cli_opt_vtf_version = {
    .id = CLI_OPT_VTF_VERSION,
    .long_name = "vtf-version",
    .value_name = "7.N",
    .default_text = "7.2",
    .range_text = "7.2..7.5",
    .help = "VTF version: 7.2 loads in every Source branch; 7.3 and up keep provenance"};
const cli_option cli_opt_vtf_flags = {
    .id = CLI_OPT_VTF_FLAGS,
    .long_name = "vtf-flags",
    .value_name = "HEX",
    .default_text = "0",
    .help = "TEXTUREFLAGS_* bits added to the map's own (SSBUMP, NORMAL), e.g. 0x4 = "
            "CLAMPS"};
const cli_option cli_opt_nomip = {
    .id = CLI_OPT_NOMIP,
    .long_name = "nomip",
    .default_text = "off",
    .help = "write .vtf/.dds without their mip chain (vtex's nomip)"};
const cli_option cli_opt_vmt = {
    .id = CLI_OPT_VMT,
    .long_name = "vmt",
    .value_name = "FILE",
    .help = "also write a Source material (LightmappedGeneric) naming the .vtf bump map"};
const cli_option cli_opt_materials = {
    .id = CLI_OPT_MATERIALS,
    .long_name = "materials",
    .value_name = "DIR",
    .default_text = "the folder named materials above the bump map",
    .help = "the game's materials folder the material's paths are relative to"};
const cli_option cli_opt_basetexture = {
    .id = CLI_OPT_BASETEXTURE,
    .long_name = "basetexture",
    .value_name = "FILE",
    .help = "the colour .vtf the material names as $basetexture"};
const cli_option cli_opt_fast_compression = {
    .id = CLI_OPT_FAST_COMPRESSION,
    .long_name = "fast-compression",
    .default_text = "off",
    .help = "block-compress with libsquish's range fit: far faster, ~1-2 dB lower PSNR on "
            "DXT1/DXT5"};

/* ---------------------------------------------------------------- numbers */

int cli_parse_double(const char *command, const char *option, const char *text,
                     double min, int min_exclusive, double max, double *out) {
  char *end = NULL;
  errno = 0;
  double v = strtod(text, &end);
  if (end == text || *end != '\0' || errno == ERANGE || !isfinite(v))
    return cli_usage_error(command, "%s needs a number (got '%s')", option, text);
  if (min_exclusive ? !(v > min) : !(v >= min))
    return cli_usage_error(command, "%s must be %s %.9g (got %s)", option,
                           min_exclusive ? ">" : ">=", min, text);
  if (v > max)
    return cli_usage_error(command, "%s must be <= %.9g (got %s)", option, max, text);
  *out = v;
  return 0;
}

int cli_parse_int(const char *command, const char *option, const char *text, long min,
                  long max, int *out) {
  char *end = NULL;
  errno = 0;
  long v = strtol(text, &end, 10);
  if (end == text || *end != '\0')
    return cli_usage_error(command, "%s needs an integer (got '%s')", option, text);
  if (errno == ERANGE || v < min || v > max) {
    if (min == INT_MIN && max == INT_MAX) /* the caller checks the range itself */
      return cli_usage_error(command, "%s is out of range (got %s)", option, text);
    if (max == INT_MAX)
      return cli_usage_error(command, "%s must be >= %ld (got %s)", option, min, text);
    return cli_usage_error(command, "%s must be in %ld..%ld (got %s)", option, min, max,
                           text);
  }
  *out = (int)v;
  return 0;
}

/* ------------------------------------------------------- option parsing */

/* How an option is named in messages: "--scale", or "-r" when short-only. */
static const char *option_display_name(const cli_option *opt, char *buf, size_t cap) {
  if (opt->long_name)
    snprintf(buf, cap, "--%s", opt->long_name);
  else
    snprintf(buf, cap, "-%c", opt->short_name);
  return buf;
}

static const cli_option *find_option(const cli_command *cmd, int getopt_value) {
  for (int i = 0; i < cmd->option_count; i++) {
    const cli_option *o = cmd->options[i];
    if (o->id == getopt_value || (o->short_name && o->short_name == getopt_value))
      return o;
  }
  return NULL;
}

/* The default of a shared setting, formatted from the command's own
 * initialised settings; NULL when the option has no such default. */
static const char *settings_default_text(int id, const cli_settings *d, char *buf,
                                         size_t cap) {
  const bb_bake_options *b = &d->bake;
  switch (id) {
  case CLI_OPT_RAYS:
    snprintf(buf, cap, "%d", b->rays);
    break;
  case CLI_OPT_FILTER_RADIUS:
    snprintf(buf, cap, "%d", b->smooth.radius_texels);
    break;
  case CLI_OPT_FILTER_THRESHOLD:
    snprintf(buf, cap, "%.5g", (double)b->smooth.threshold);
    break;
  case CLI_OPT_BIAS:
    snprintf(buf, cap, "%.5g", b->trace.bias_texels);
    break;
  case CLI_OPT_POWER:
    snprintf(buf, cap, "%.5g", b->power);
    break;
  case CLI_OPT_BASIS:
    snprintf(buf, cap, "%s", b->basis.name);
    break;
  case CLI_OPT_NORMAL_FILTER:
    snprintf(buf, cap, "%s", bb_normal_filter_name(b->normal_filter));
    break;
  case CLI_OPT_NORMAL_Y:
    snprintf(buf, cap, "%s", b->normal_y_up ? "up" : "down");
    break;
  case CLI_OPT_THREADS:
    snprintf(buf, cap, "%d", b->trace.threads);
    break;
  case CLI_OPT_CHANNEL:
    snprintf(buf, cap, "%s", bb_channel_name(d->channel));
    break;
  case CLI_OPT_DEPTH:
    snprintf(buf, cap, "by format");
    break;
  default:
    return NULL;
  }
  return buf;
}

static void print_help(const cli_command *cmd) {
  cli_settings defaults;
  if (cmd->init_settings)
    cmd->init_settings(&defaults);
  printf("usage: bumpbake %s %s\n%s\n\noptions:\n", cmd->name, cmd->synopsis,
         cmd->summary);
  for (int i = 0; i < cmd->option_count; i++) {
    const cli_option *o = cmd->options[i];
    char flags[64], dflt[64];
    int n = 0;
    if (o->short_name)
      n += snprintf(flags + n, sizeof flags - (size_t)n, "-%c", o->short_name);
    if (o->long_name && o->single_dash)
      n += snprintf(flags + n, sizeof flags - (size_t)n, "%s-%s", n ? ", " : "",
                    o->long_name);
    if (o->long_name)
      n += snprintf(flags + n, sizeof flags - (size_t)n, "%s--%s", n ? ", " : "",
                    o->long_name);
    if (o->value_name)
      snprintf(flags + n, sizeof flags - (size_t)n, " %s", o->value_name);
    const char *d = o->default_text ? o->default_text
                    : cmd->init_settings
                        ? settings_default_text(o->id, &defaults, dflt, sizeof dflt)
                        : NULL;
    /* At least two spaces end the flags, also when they fill or overflow
     * their column: tools/gen_docs.py splits the line there, and an option
     * and its default stay on one line for whoever greps them. */
    if (strlen(flags) >= 36)
      printf("  %s  %s", flags, o->help);
    else
      printf("  %-36s %s", flags, o->help);
    if (d)
      printf("; default %s", d);
    if (o->range_text)
      printf("; range %s", o->range_text);
    putchar('\n');
  }
}

/* Edit distance of a and b (each at most 63 characters), for "did you
 * mean". */
static size_t edit_distance(const char *a, size_t na, const char *b) {
  size_t nb = strlen(b), row[64];
  if (na > 63 || nb > 63)
    return 99;
  for (size_t j = 0; j <= nb; j++)
    row[j] = j;
  for (size_t i = 1; i <= na; i++) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= nb; j++) {
      size_t above = row[j];
      size_t best = diagonal + (a[i - 1] != b[j - 1]);
      if (above + 1 < best)
        best = above + 1;
      if (row[j - 1] + 1 < best)
        best = row[j - 1] + 1;
      row[j] = best;
      diagonal = above;
    }
  }
  return row[nb];
}

/* Every long option word must name an option in full: getopt_long would
 * take "--ray" for --rays silently. An unknown word gets the nearest
 * name; a prefix of several names lists them. The words after "--" and the
 * values of options that take one are not options. */
static int check_long_words(const cli_command *cmd, int argc, char **argv, int long_only) {
  for (int i = 1; i < argc; i++) {
    const char *w = argv[i];
    if (!strcmp(w, "--"))
      return 0;
    const int dashes = w[0] == '-' && w[1] == '-' ? 2 : (long_only && w[0] == '-' && w[1] && w[2]) ? 1 : 0;
    if (!dashes)
      continue;
    const char *name = w + dashes;
    const size_t n = strcspn(name, "=");
    const cli_option *exact = NULL;
    char candidates[256] = "";
    int prefix_of = 0;
    for (int k = 0; k < cmd->option_count; k++) {
      const cli_option *o = cmd->options[k];
      if (!o->long_name)
        continue;
      if (strlen(o->long_name) == n && !strncmp(o->long_name, name, n))
        exact = o;
      else if (strncmp(o->long_name, name, n) == 0) {
        prefix_of++;
        snprintf(candidates + strlen(candidates), sizeof candidates - strlen(candidates),
                 "%s--%s", candidates[0] ? ", " : "", o->long_name);
      }
    }
    if (exact) {
      if (exact->value_name && !name[n])
        i++; /* its value */
      continue;
    }
    if (dashes == 1) /* a cluster of short options ("-nA") is getopt's */
      continue;
    if (prefix_of > 1)
      return cli_usage_error(cmd->name, "option '--%.*s' is ambiguous: %s", (int)n, name,
                             candidates);
    if (prefix_of == 1)
      return cli_usage_error(cmd->name, "unknown option '--%.*s' (did you mean %s?)", (int)n,
                             name, candidates);
    const cli_option *near = NULL;
    size_t best = 3;
    for (int k = 0; k < cmd->option_count; k++) {
      const cli_option *o = cmd->options[k];
      size_t d = o->long_name ? edit_distance(name, n, o->long_name) : 99;
      if (d < best)
        best = d, near = o;
    }
    if (near)
      return cli_usage_error(cmd->name, "unknown option '--%.*s' (did you mean --%s?)",
                             (int)n, name, near->long_name);
    return cli_usage_error(cmd->name, "unknown option '--%.*s' (see --help)", (int)n, name);
  }
  return 0;
}

int cli_parse_options(const cli_command *cmd, int argc, char **argv,
                      cli_option_fn on_option, void *ctx, int *first_positional) {
  enum { MAX_OPTIONS = 48 };
  struct option longopts[MAX_OPTIONS + 1];
  /* Leading '+' would stop at the first positional; we want GNU permutation
   * (options after the file name), and ':' to report missing values. */
  char shortopts[2 * MAX_OPTIONS + 2];
  int nl = 0, ns = 0;
  if (cmd->option_count > MAX_OPTIONS)
    return cli_usage_error(cmd->name, "internal error: too many options");
  shortopts[ns++] = ':';
  int long_only = 0;
  for (int i = 0; i < cmd->option_count; i++) {
    const cli_option *o = cmd->options[i];
    long_only |= o->single_dash;
    int has_arg = o->value_name ? required_argument : no_argument;
    if (o->long_name)
      longopts[nl++] = (struct option){o->long_name, has_arg, NULL, o->id};
    if (o->short_name) {
      shortopts[ns++] = o->short_name;
      if (has_arg)
        shortopts[ns++] = ':';
    }
  }
  longopts[nl] = (struct option){NULL, 0, NULL, 0};
  shortopts[ns] = '\0';

  int rc = check_long_words(cmd, argc, argv, long_only);
  if (rc)
    return rc;
  opterr = 0; /* our messages, in our format */
  /* 0, not 1: glibc then forgets all its state, including its pointer into
   * the previous argv when that parse stopped inside a cluster such as
   * "-nx" (a later parse read freed memory through it: found by fuzz_cli). */
  optind = 0;
  for (;;) {
    int c = long_only
                ? getopt_long_only(argc, argv, shortopts, longopts, NULL)
                : getopt_long(argc, argv, shortopts, longopts, NULL);
    if (c == -1)
      break;
    if (c == '?') {
      char name[64];
      const cli_option *known = find_option(cmd, optopt);
      if (optopt > 0 && optopt < 256 && !known)
        return cli_usage_error(cmd->name, "unknown option '-%c' (see --help)", optopt);
      if (known) /* glibc reports "--flag=value" for a flag this way */
        return cli_usage_error(cmd->name, "%s takes no value",
                               option_display_name(known, name, sizeof name));
      return cli_usage_error(cmd->name, "unknown or ambiguous option '%s' (see --help)",
                             argv[optind - 1]);
    }
    if (c == ':') {
      const cli_option *o = find_option(cmd, optopt);
      char name[64];
      return cli_usage_error(cmd->name, "%s needs a value",
                             o ? option_display_name(o, name, sizeof name)
                               : argv[optind - 1]);
    }
    const cli_option *o = find_option(cmd, c);
    if (!o)
      return cli_usage_error(cmd->name, "internal: unhandled option %d", c);
    if (o->id == CLI_OPT_HELP) {
      print_help(cmd);
      return -1;
    }
    rc = on_option(ctx, o, optarg);
    if (rc)
      return rc;
  }
  *first_positional = optind;
  return 0;
}

int cli_expect_positionals(const cli_command *cmd, int argc, char **argv, int first,
                           int expected, const char *names) {
  int got = argc - first;
  if (got < expected)
    return cli_usage_error(cmd->name, "missing %s (usage: bumpbake %s %s)", names,
                           cmd->name, cmd->synopsis);
  if (got > expected)
    return cli_usage_error(cmd->name, "unexpected argument '%s' (expected only %s)",
                           argv[first + expected], names);
  return 0;
}

/* --------------------------------------------------------------- settings */

void cli_settings_init(cli_settings *s) {
  memset(s, 0, sizeof *s);
  bb_bake_options_init(&s->bake);
  s->channel = BB_CHANNEL_AUTO;
  s->depth = BB_DEPTH_DEFAULT;
  bb_texture_options_init(&s->texture);
  s->scale_given = 0;
}

/* Applies a choice-valued option ("--basis hl2"); a usage error names the
 * accepted words, which the row's value_name lists. */
static int bad_choice(const char *command, const cli_option *opt, const char *arg) {
  char name[64];
  return cli_usage_error(command, "%s must be one of %s (got '%s')",
                         option_display_name(opt, name, sizeof name), opt->value_name,
                         arg);
}

/* --basis: the library's rule (bb_basis_resolve): a name, else a basis
 * file. A word that is neither is a usage error; a file that is there but
 * wrong is the file's error (exit 1, "bumpbake: FILE:LINE: reason"). */
static int apply_basis(const char *command, const char *arg, cli_settings *s) {
  bb_error err = {{0}};
  int from_file = 0;
  bb_status st = bb_basis_resolve(arg, &s->bake.basis, &from_file, &err);
  if (st == BB_ERR_ARGUMENT && !from_file)
    return cli_usage_error(command, "--%s", err.message);
  if (st != BB_OK)
    return cli_status_exit(arg, st, &err);
  s->basis_file = from_file ? arg : NULL;
  return 0;
}

/* The ranges of --filter-radius, --bias, --power and --threads are the
 * library's (bb_bake_options_check), not the CLI's: the option is parsed
 * as a number, then the settings so far are checked by the library, and
 * its message becomes the usage error ("bumpbake bake: --threads: threads
 * must be in 0..4096 (got 5000)"). --scale may come later, so a valid
 * stand-in takes its place. */
static int check_with_library(const char *command, const char *name, const cli_settings *s) {
  bb_bake_options o = s->bake;
  if (!s->scale_given)
    o.height_scale = 1.0f;
  bb_error err = {{0}};
  if (bb_bake_options_check(&o, &err) == BB_OK)
    return 0;
  const char *why = err.message;
  if (strncmp(why, "bake: ", 6) == 0)
    why += 6;
  return cli_usage_error(command, "%s: %s", name, why);
}

int cli_settings_apply_slices(const char *command, cli_settings *s, const char *arg) {
  int rc = cli_parse_int(command, "--slices", arg, INT_MIN, INT_MAX, &s->bake.slices);
  if (!rc && s->bake.slices == 0) /* 0 means "from --rays" to the library */
    return cli_usage_error(command, "--slices: slices must be in 1..%d (got 0)",
                           BB_MAX_SLICES);
  return rc ? rc : check_with_library(command, "--slices", s);
}

int cli_settings_apply(const char *command, cli_settings *s, const cli_option *opt,
                       const char *arg) {
  bb_bake_options *b = &s->bake;
  char name[64];
  option_display_name(opt, name, sizeof name);
  double d;
  int rc;
  switch (opt->id) {
  case CLI_OPT_SCALE:
    rc = cli_parse_double(command, name, arg, 0.0, 1, (double)FLT_MAX, &d);
    if (!rc) {
      b->height_scale = (float)d;
      s->scale_given = 1;
    }
    return rc;
  case CLI_OPT_RAYS:
    rc = cli_parse_int(command, name, arg, INT_MIN, INT_MAX, &b->rays);
    return rc ? rc : check_with_library(command, name, s);
  case CLI_OPT_FILTER_RADIUS:
    rc = cli_parse_int(command, name, arg, INT_MIN, INT_MAX, &b->smooth.radius_texels);
    return rc ? rc : check_with_library(command, name, s);
  case CLI_OPT_FILTER_THRESHOLD:
    rc = cli_parse_double(command, name, arg, 0.0, 1, (double)FLT_MAX, &d);
    if (!rc)
      b->smooth.threshold = (float)d;
    return rc;
  case CLI_OPT_BIAS:
    rc = cli_parse_double(command, name, arg, -DBL_MAX, 0, DBL_MAX, &b->trace.bias_texels);
    return rc ? rc : check_with_library(command, name, s);
  case CLI_OPT_POWER:
    rc = cli_parse_double(command, name, arg, -DBL_MAX, 0, DBL_MAX, &b->power);
    return rc ? rc : check_with_library(command, name, s);
  case CLI_OPT_THREADS:
    rc = cli_parse_int(command, name, arg, INT_MIN, INT_MAX, &b->trace.threads);
    if (!rc)
      s->texture.threads = b->trace.threads; /* block compression too */
    return rc ? rc : check_with_library(command, name, s);
  case CLI_OPT_BASIS:
    return apply_basis(command, arg, s);
  case CLI_OPT_NORMAL_FILTER:
    return bb_normal_filter_parse(arg, &b->normal_filter, NULL) ? bad_choice(command, opt, arg)
                                                          : 0;
  case CLI_OPT_NORMAL_Y:
    if (strcmp(arg, "down") && strcmp(arg, "up"))
      return bad_choice(command, opt, arg);
    b->normal_y_up = strcmp(arg, "up") == 0;
    return 0;
  case CLI_OPT_CHANNEL:
    return bb_channel_parse(arg, &s->channel, NULL) ? bad_choice(command, opt, arg) : 0;
  case CLI_OPT_DEPTH:
    return bb_depth_parse(arg, &s->depth, NULL) ? bad_choice(command, opt, arg) : 0;
  case CLI_OPT_CLAMP:
    b->smooth.addressing = BB_ADDRESS_CLAMP;
    return 0;
  case CLI_OPT_MIPS:
    s->mips = 1;
    return 0;
  case CLI_OPT_TEXTURE_FORMAT: {
    bb_error err = {{0}};
    return bb_texture_format_parse(arg, &s->texture.format, &err) == BB_OK
               ? 0
               : cli_usage_error(command, "%s: %s", name, err.message);
  }
  case CLI_OPT_VTF_VERSION: {
    bb_error err = {{0}};
    return bb_vtf_version_parse(arg, &s->texture.vtf_version, &err) == BB_OK
               ? 0
               : cli_usage_error(command, "%s: %s", name, err.message);
  }
  case CLI_OPT_VTF_FLAGS: {
    bb_error err = {{0}};
    return bb_vtf_flags_parse(arg, &s->texture.vtf_flags, &err) == BB_OK
               ? 0
               : cli_usage_error(command, "%s: %s", name, err.message);
  }
  case CLI_OPT_NOMIP:
    s->texture.mips = 0;
    return 0;
  case CLI_OPT_FAST_COMPRESSION:
    s->texture.fast = 1;
    return 0;
  default: /* a table row whose subcommand forgot to handle it */
    return cli_usage_error(command, "internal error: option %s has no handler", name);
  }
}
