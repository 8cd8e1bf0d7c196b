/* cli_common.c: option parsing, errors, output writing and progress
 * shared by the bumpbake subcommands, so none of them repeats another's. */
/* realpath() is an XSI function, outside plain POSIX.1-2008. */
#define _XOPEN_SOURCE 700

#include "cli_common.h"

#include <errno.h>
#include <fcntl.h>
#include <float.h>
#include <getopt.h>
#include <limits.h>
#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

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
            "N evenly spread, or a file of x y z lines (README \"Bases\")"};
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
    .help = "height channel (auto: grey, or mean of R, G, B)"};
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

/* ----------------------------------------------------------------- errors */

int cli_usage_error(const char *command, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  fprintf(stderr, "bumpbake %s: ", command);
  vfprintf(stderr, fmt, ap);
  fputc('\n', stderr);
  va_end(ap);
  return BB_EXIT_USAGE;
}

void cli_file_error(const char *path, const char *reason) {
  /* Errors are one line, whatever a lower layer put in its message. */
  char line[2 * sizeof(bb_error)];
  snprintf(line, sizeof line, "%s", reason && *reason ? reason : "unknown error");
  for (char *c = line; *c; c++)
    if (*c == '\n' || *c == '\r')
      *c = ' ';
  size_t n = strlen(path);
  if (strncmp(line, path, n) == 0 && line[n] == ':')
    fprintf(stderr, "bumpbake: %s\n", line);
  else
    fprintf(stderr, "bumpbake: %s: %s\n", path, line);
}

int cli_status_exit(const char *path, bb_status status, const bb_error *err) {
  if (status == BB_OK)
    return 0;
  cli_file_error(path, err->message[0] ? err->message : bb_status_name(status));
  return BB_EXIT_FAILURE;
}

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
    printf("  %-36s %s", flags, o->help);
    if (d)
      printf("; default %s", d);
    if (o->range_text)
      printf("; range %s", o->range_text);
    putchar('\n');
  }
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
    int rc = on_option(ctx, o, optarg);
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
  s->scale_given = 0;
}

static int parse_depth(const char *text, bb_depth *out) {
  static const struct {
    const char *name;
    bb_depth depth;
  } depths[] = {{"8", BB_DEPTH_8},
                {"16", BB_DEPTH_16},
                {"half", BB_DEPTH_HALF},
                {"float", BB_DEPTH_FLOAT}};
  for (size_t i = 0; i < sizeof depths / sizeof depths[0]; i++)
    if (strcmp(text, depths[i].name) == 0) {
      *out = depths[i].depth;
      return 0;
    }
  return -1;
}

/* Applies a choice-valued option ("--basis hl2"); a usage error names the
 * accepted words, which the row's value_name lists. */
static int bad_choice(const char *command, const cli_option *opt, const char *arg) {
  char name[64];
  return cli_usage_error(command, "%s must be one of %s (got '%s')",
                         option_display_name(opt, name, sizeof name), opt->value_name,
                         arg);
}

/* --basis: a name ("hl2", "hl2+z", "dirs:N"; names win over a file of the
 * same name, which ./NAME reaches) or else a basis file. A word that is
 * neither is a usage error; a file that is there but wrong is the file's
 * error (exit 1, "bumpbake: FILE:LINE: reason"). */
static int apply_basis(const char *command, const char *arg, bb_basis *out) {
  bb_error err = {{0}};
  if (!strcmp(arg, "hl2") || !strcmp(arg, "hl2+z") || !strncmp(arg, "dirs:", 5)) {
    if (bb_basis_parse(arg, out, &err) == BB_OK)
      return 0;
    return cli_usage_error(command, "--basis dirs:N needs a whole N in 3..%d (got '%s')",
                           BB_MAX_BASIS, arg);
  }
  struct stat st;
  if (stat(arg, &st) != 0)
    return cli_usage_error(command,
                           "--basis must be hl2, hl2+z, dirs:N (N in 3..%d) or a file of "
                           "directions (got '%s': %s)",
                           BB_MAX_BASIS, arg, strerror(errno));
  return cli_status_exit(arg, bb_basis_load(arg, out, &err), &err);
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
    return cli_parse_int(command, name, arg, 1, 65536, &b->rays);
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
    return rc ? rc : check_with_library(command, name, s);
  case CLI_OPT_BASIS:
    return apply_basis(command, arg, &b->basis);
  case CLI_OPT_NORMAL_FILTER:
    return bb_normal_filter_parse(arg, &b->normal_filter) ? bad_choice(command, opt, arg)
                                                          : 0;
  case CLI_OPT_NORMAL_Y:
    if (strcmp(arg, "down") && strcmp(arg, "up"))
      return bad_choice(command, opt, arg);
    b->normal_y_up = strcmp(arg, "up") == 0;
    return 0;
  case CLI_OPT_CHANNEL:
    return bb_channel_parse(arg, &s->channel) ? bad_choice(command, opt, arg) : 0;
  case CLI_OPT_DEPTH:
    return parse_depth(arg, &s->depth) ? bad_choice(command, opt, arg) : 0;
  case CLI_OPT_CLAMP:
    b->smooth.addressing = BB_ADDRESS_CLAMP;
    return 0;
  case CLI_OPT_MIPS:
    s->mips = 1;
    return 0;
  default: /* a table row whose subcommand forgot to handle it */
    return cli_usage_error(command, "internal error: option %s has no handler", name);
  }
}

/* ---------------------------------------------------------------- outputs */

/* Lower-case extension of path's last component, without the dot ("" when
 * none), into buf. */
static const char *path_extension(const char *path, char *buf, size_t cap) {
  const char *slash = strrchr(path, '/');
  const char *dot = strrchr(slash ? slash + 1 : path, '.');
  size_t n = 0;
  if (dot)
    for (const char *c = dot + 1; *c && n + 1 < cap; c++)
      buf[n++] = (char)((*c >= 'A' && *c <= 'Z') ? *c - 'A' + 'a' : *c);
  buf[n] = '\0';
  return buf;
}

static const char *depth_name(bb_depth d) {
  switch (d) {
  case BB_DEPTH_8:
    return "8";
  case BB_DEPTH_16:
    return "16";
  case BB_DEPTH_HALF:
    return "half";
  case BB_DEPTH_FLOAT:
    return "float";
  case BB_DEPTH_DEFAULT:
    break;
  }
  return "default";
}

/* The directory part of path ("." when none), into dir. */
static void directory_part(const char *path, char *dir, size_t cap) {
  const char *slash = strrchr(path, '/');
  if (!slash)
    snprintf(dir, cap, ".");
  else if (slash == path)
    snprintf(dir, cap, "/");
  else
    snprintf(dir, cap, "%.*s", (int)(slash - path), path);
}

/* The directory entry a write of path replaces: its directory's device and
 * inode and its last component. Returns 0 when the directory exists. */
typedef struct dir_entry {
  dev_t dev;
  ino_t ino;
  const char *name;
} dir_entry;

static int entry_of(const char *path, dir_entry *e) {
  char dir[PATH_MAX];
  directory_part(path, dir, sizeof dir);
  struct stat st;
  if (stat(dir, &st) != 0)
    return -1;
  const char *slash = strrchr(path, '/');
  e->dev = st.st_dev;
  e->ino = st.st_ino;
  e->name = slash ? slash + 1 : path;
  return 0;
}

int cli_same_file(const char *a, const char *b) {
  /* Two names of one existing file (symbolic or hard links, "./", ".."). */
  struct stat sa, sb;
  if (stat(a, &sa) == 0 && stat(b, &sb) == 0)
    return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
  /* Files not made yet: the same name in the same directory, however the
   * directory is spelled. */
  dir_entry ea, eb;
  if (entry_of(a, &ea) == 0 && entry_of(b, &eb) == 0)
    return ea.dev == eb.dev && ea.ino == eb.ino && strcmp(ea.name, eb.name) == 0;
  return strcmp(a, b) == 0;
}

/* 0 when the directory part of path exists and is a directory; else prints
 * why not and returns BB_EXIT_FAILURE. */
static int check_output_directory(const char *path) {
  char dir[PATH_MAX];
  directory_part(path, dir, sizeof dir);
  struct stat st;
  if (stat(dir, &st) != 0) {
    char reason[PATH_MAX + 128];
    snprintf(reason, sizeof reason, "cannot write: directory %s: %s", dir,
             strerror(errno));
    cli_file_error(path, reason);
    return BB_EXIT_FAILURE;
  }
  if (!S_ISDIR(st.st_mode)) {
    char reason[PATH_MAX + 128];
    snprintf(reason, sizeof reason, "cannot write: %s is not a directory", dir);
    cli_file_error(path, reason);
    return BB_EXIT_FAILURE;
  }
  return 0;
}

int cli_check_output(const char *command, const char *input_path, const char *output_path,
                     bb_depth depth) {
  char ext[16];
  if (!bb_path_is_writable_format(output_path))
    return cli_usage_error(
        command, "%s: unknown output format '.%s' (use .png, .tga, .tif, .tiff or .exr)",
        output_path, path_extension(output_path, ext, sizeof ext));
  /* Checked before baking, so a bad combination fails before a long bake. */
  if (!bb_path_supports_depth(output_path, depth))
    return cli_usage_error(command, "%s: --depth %s is not available in .%s files",
                           output_path, depth_name(depth),
                           path_extension(output_path, ext, sizeof ext));
  if (cli_same_file(input_path, output_path)) {
    cli_file_error(output_path, "output would overwrite the input file");
    return BB_EXIT_FAILURE;
  }
  return check_output_directory(output_path);
}

char *cli_path_with_suffix(const char *path, const char *suffix) {
  const char *slash = strrchr(path, '/');
  const char *dot = strrchr(slash ? slash + 1 : path, '.');
  size_t stem = dot ? (size_t)(dot - path) : strlen(path);
  size_t len = stem + strlen(suffix) + 1;
  char *out = malloc(len);
  if (out)
    snprintf(out, len, "%.*s%s", (int)stem, path, suffix);
  return out;
}

int cli_check_mips(const char *command, const cli_settings *s, const char *output_path) {
  if (!s->mips || bb_path_supports_mips(output_path))
    return 0;
  return cli_usage_error(command, "%s: --mips needs a .tif or .exr output", output_path);
}

/* img's mip chain (renormalised when wo->range is BB_RANGE_SIGNED) written
 * as one file: at path, or staged into *staged when staged is not NULL. */
static bb_status write_mip_file(const char *path, const bb_image *img,
                                const bb_write_options *wo, bb_staged_file **staged,
                                bb_error *err) {
  bb_image *levels = NULL;
  int count = 0;
  bb_mip_filter filter = wo->range == BB_RANGE_SIGNED ? BB_MIP_RENORMALIZE : BB_MIP_AVERAGE;
  bb_status st = bb_mip_chain(img, filter, &levels, &count, err);
  if (st == BB_OK)
    st = staged ? bb_image_write_mips_staged(path, levels, count, wo, staged, err)
                : bb_image_write_mips(path, levels, count, wo, err);
  bb_mip_chain_free(levels, count);
  return st;
}

bb_status cli_write_image(const char *path, const bb_image *img, const bb_write_options *wo,
                          int mips, bb_error *err) {
  return mips ? write_mip_file(path, img, wo, NULL, err) : bb_image_write(path, img, wo, err);
}

/* cli_write_image staged (complete under a temporary name) into *staged. */
static bb_status stage_image(const char *path, const bb_image *img, const bb_write_options *wo,
                             int mips, bb_staged_file **staged, bb_error *err) {
  *staged = NULL;
  return mips ? write_mip_file(path, img, wo, staged, err)
              : bb_image_write_staged(path, img, wo, staged, err);
}

static const char *file_name_of(const char *path) {
  const char *slash = strrchr(path, '/');
  return slash ? slash + 1 : path;
}

int cli_run_init(cli_run *run, int argc, char **argv) {
  memset(run, 0, sizeof *run);
  size_t len = strlen("bumpbake") + 1;
  for (int i = 0; i < argc; i++)
    len += strlen(argv[i]) + 1;
  run->command_line = malloc(len);
  if (!run->command_line) {
    fprintf(stderr, "bumpbake: out of memory\n");
    return BB_EXIT_FAILURE;
  }
  strcpy(run->command_line, "bumpbake");
  for (int i = 0; i < argc; i++) {
    strcat(run->command_line, " ");
    strcat(run->command_line, argv[i]);
  }
  return 0;
}

void cli_run_set_input(cli_run *run, const char *input_path, const bb_image *height,
                       const cli_settings *settings) {
  run->input_path = input_path;
  run->input_hash = bb_image_hash(height);
  run->settings = settings;
}

void cli_run_free(cli_run *run) {
  free(run->command_line);
  run->command_line = NULL;
}

/* The write options of one output of run: its depth and range and a
 * provenance description of kind (malloc'd into *description). */
static bb_status output_options(const cli_run *run, const char *kind, bb_range range,
                                bb_write_options *wo, char **description, bb_error *err) {
  bb_provenance p = {
      run->command_line,    file_name_of(run->input_path), run->input_hash, kind,
      &run->settings->bake, run->settings->channel,        run->rayset_id};
  *description = bb_provenance_format(&p);
  if (!*description) {
    snprintf(err->message, sizeof err->message, "out of memory");
    return BB_ERR_MEMORY;
  }
  *wo = (bb_write_options){run->settings->depth, range, *description};
  return BB_OK;
}

int cli_write_output(cli_run *run, const char *kind, const char *path,
                     const bb_image *img, bb_range range) {
  bb_write_options wo;
  char *description = NULL;
  bb_error err = {{0}};
  bb_status st = output_options(run, kind, range, &wo, &description, &err);
  double t0 = cli_now_seconds();
  if (st == BB_OK)
    st = cli_write_image(path, img, &wo, run->settings->mips, &err);
  run->seconds_write += cli_now_seconds() - t0;
  free(description);
  return cli_status_exit(path, st, &err);
}

void cli_stage_output(const cli_run *run, cli_staged_output *out, const bb_image *img,
                      bb_range range) {
  bb_write_options wo;
  char *description = NULL;
  out->file = NULL;
  memset(&out->error, 0, sizeof out->error);
  out->status = output_options(run, out->kind, range, &wo, &description, &out->error);
  if (out->status == BB_OK)
    out->status = stage_image(out->path, img, &wo, run->settings->mips, &out->file,
                              &out->error);
  free(description);
}

/* Appends to text (capacity cap) the outputs in place, or says that none
 * is. */
static void describe_written(const cli_staged_output *outs, int n, char *text, size_t cap) {
  size_t len = strlen(text);
  int any = 0;
  for (int i = 0; i < n && len < cap; i++) {
    if (!outs[i].written)
      continue;
    len += (size_t)snprintf(text + len, cap - len, "%s%s %s",
                            any ? ", " : "; already written: ", outs[i].kind, outs[i].path);
    any = 1;
  }
  if (!any && len < cap)
    snprintf(text + len, cap - len, "; no output was written");
}

static void discard_all(cli_staged_output *outs, int n) {
  for (int i = 0; i < n; i++) {
    bb_staged_file_discard(outs[i].file);
    outs[i].file = NULL;
  }
}

int cli_commit_outputs(cli_staged_output *outs, int n) {
  int failed = -1;
  for (int i = 0; i < n; i++) {
    outs[i].written = 0;
    if (failed < 0 && outs[i].status != BB_OK)
      failed = i;
  }
  /* All or nothing: one failure discards every staged file. Only a rename
   * can still fail after this, which leaves the ones before it in place. */
  for (int i = 0; i < n && failed < 0; i++) {
    bb_staged_file *f = outs[i].file;
    outs[i].file = NULL;
    outs[i].status = bb_staged_file_commit(f, &outs[i].error);
    if (outs[i].status == BB_OK)
      outs[i].written = 1;
    else
      failed = i;
  }
  discard_all(outs, n);
  if (failed < 0)
    return 0;
  char reason[2 * sizeof(bb_error)];
  snprintf(reason, sizeof reason, "%s",
           outs[failed].error.message[0] ? outs[failed].error.message
                                         : bb_status_name(outs[failed].status));
  if (n > 1)
    describe_written(outs, n, reason, sizeof reason);
  cli_file_error(outs[failed].path, reason);
  return BB_EXIT_FAILURE;
}

/* libpng, inside OpenImageIO, prints its own "libpng error: ..." line on
 * stderr for a corrupt PNG before OpenImageIO returns the error we report.
 * The CLI mutes stderr while decoding so every error stays one line; the
 * library leaves the process's file descriptors alone. */
int cli_mute_stderr(void) {
  fflush(stderr);
  int saved = dup(STDERR_FILENO), null_fd = open("/dev/null", O_WRONLY);
  if (saved >= 0 && null_fd >= 0) dup2(null_fd, STDERR_FILENO);
  if (null_fd >= 0) close(null_fd);
  return saved;
}

void cli_unmute_stderr(int saved) {
  if (saved < 0) return;
  dup2(saved, STDERR_FILENO);
  close(saved);
}

bb_status cli_read_image(const char *path, bb_image *img, bb_image_info *info, bb_error *err) {
  int saved = cli_mute_stderr();
  bb_status st = bb_image_read(path, img, info, err);
  cli_unmute_stderr(saved);
  return st;
}

int cli_load_height(const char *path, const cli_settings *s, bb_image *height) {
  return cli_load_height_source(path, s, height, NULL);
}

int cli_load_height_source(const char *path, const cli_settings *s, bb_image *height,
                           cli_height_source *source) {
  bb_image img = {0};
  bb_image_info info;
  bb_error err = {{0}};
  bb_status st = cli_read_image(path, &img, &info, &err);
  if (st == BB_OK) {
    /* The rule's own choice, so a height found in alpha is said once. */
    bb_channel used = bb_height_channel(&img, info.alpha_channel, s->channel);
    if (source) {
      const int alpha = info.alpha_channel >= 0 || img.channels == 2 || img.channels == 4;
      *source = (cli_height_source){used, img.channels - alpha < 3, info.bits_per_sample,
                                    info.is_float};
    }
    if (s->channel == BB_CHANNEL_AUTO && used == BB_CHANNEL_A)
      fprintf(stderr,
              "bumpbake: %s: note: the colour is constant and alpha is not; using "
              "alpha as the height (Valve's convention; --channel chooses)\n",
              path);
    st = bb_height_from_image(&img, info.alpha_channel, used, height, &err);
    bb_image_info_free(&info);
    bb_image_free(&img);
  }
  return cli_status_exit(path, st, &err);
}

const char *cli_height_channel_name(const cli_height_source *source) {
  /* The mean of one colour channel is that channel. */
  if (source->grey && (source->channel == BB_CHANNEL_MEAN || source->channel == BB_CHANNEL_LUMA))
    return "grey";
  return bb_channel_name(source->channel);
}

bb_depth cli_depth_like_input(const cli_height_source *source, const char *path) {
  /* The closest the format holds, from the input's own depth downwards. */
  static const bb_depth float_order[] = {BB_DEPTH_FLOAT, BB_DEPTH_HALF, BB_DEPTH_16};
  static const bb_depth half_order[] = {BB_DEPTH_HALF, BB_DEPTH_FLOAT, BB_DEPTH_16};
  static const bb_depth int16_order[] = {BB_DEPTH_16, BB_DEPTH_FLOAT};
  const bb_depth *order = NULL;
  size_t n = 0;
  if (source->is_float && source->bits_per_sample <= 16)
    order = half_order, n = 3;
  else if (source->is_float)
    order = float_order, n = 3;
  else if (source->bits_per_sample > 8)
    order = int16_order, n = 2;
  for (size_t i = 0; i < n; i++)
    if (bb_path_supports_depth(path, order[i]))
      return order[i];
  return BB_DEPTH_DEFAULT;
}

int cli_check_hl2_map(const char *path, const bb_image *img, const bb_image_info *info) {
  char basis[64], reason[256];
  bb_provenance_value(info ? info->description : NULL, "basis", basis, sizeof basis);
  if (basis[0] && strcmp(basis, "hl2") && strcmp(basis, "hl2+z") && strcmp(basis, "dirs:3"))
    snprintf(reason, sizeof reason,
             "baked with --basis %s; this reads Half-Life 2's basis (bake with --basis hl2)",
             basis);
  else if (img->channels > 4)
    snprintf(reason, sizeof reason,
             "%d channels, one per direction of a basis other than Half-Life 2's; this "
             "reads Half-Life 2's 3 (bake with --basis hl2)",
             img->channels);
  else
    return 0;
  cli_file_error(path, reason);
  return BB_EXIT_FAILURE;
}

int cli_run_bake(const char *path, const bb_image *height, const bb_bake_options *o,
                 bb_bake_result *result) {
  bb_error err = {{0}};
  bb_status st = bb_bake(height, o, result, &err);
  return cli_status_exit(path, st, &err);
}

double cli_now_seconds(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ---------------------------------------------------------------- signals */

/* Removes the temporaries of the writes in progress, then dies of the same
 * signal: SA_RESETHAND has restored the default action, and the signal,
 * blocked while this runs, is delivered when it returns, so the exit status
 * is what a shell expects of Ctrl-C or kill. Only async-signal-safe calls. */
static void remove_temporaries_and_die(int sig) {
  bb_tempfiles_remove();
  raise(sig);
}

void cli_install_signal_handlers(void) {
  /* Over RLIMIT_FSIZE a write then fails with EFBIG, reported and cleaned
   * up like a full disk, instead of SIGXFSZ killing the process with its
   * temporary left behind. */
  struct sigaction ignore;
  memset(&ignore, 0, sizeof ignore);
  ignore.sa_handler = SIG_IGN;
  sigemptyset(&ignore.sa_mask);
  sigaction(SIGXFSZ, &ignore, NULL);

  static const int fatal[] = {SIGINT, SIGTERM, SIGHUP};
  for (size_t i = 0; i < sizeof fatal / sizeof fatal[0]; i++) {
    struct sigaction old, sa;
    /* A signal ignored by whoever started us (nohup, a background job)
     * stays ignored. */
    if (sigaction(fatal[i], NULL, &old) == 0 && old.sa_handler == SIG_IGN)
      continue;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = remove_temporaries_and_die;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = (int)SA_RESETHAND;
    sigaction(fatal[i], &sa, NULL);
  }
}

/* --------------------------------------------------------------- progress */

enum { PROGRESS_BAR_WIDTH = 20 };

/* Never cancels: Ctrl-C ends the process (cli_install_signal_handlers). */
static int progress_draw(void *user, long done, long total) {
  cli_progress *p = user;
  double now = cli_now_seconds(), elapsed = now - p->start_seconds;
  /* Short bakes stay silent; long ones redraw ten times a second at most. */
  if (elapsed < 1.0 || total <= 0 || now - p->last_draw_seconds < 0.1)
    return 0;
  p->last_draw_seconds = now;
  double frac = done <= 0 ? 0.0 : (double)done / (double)total;
  if (frac > 1.0)
    frac = 1.0;
  int filled = (int)(frac * PROGRESS_BAR_WIDTH); /* full only when done */
  char bar[PROGRESS_BAR_WIDTH + 1];
  for (int i = 0; i < PROGRESS_BAR_WIDTH; i++)
    bar[i] = i < filled ? '#' : '.';
  bar[PROGRESS_BAR_WIDTH] = '\0';
  fprintf(stderr, "\r%s [%s] %3d%%", p->label, bar, (int)(frac * 100.0));
  if (frac > 0.0)
    fprintf(stderr, " ETA %.1fs", elapsed * (1.0 - frac) / frac);
  fputs("\033[K", stderr); /* erase what a longer previous line left */
  fflush(stderr);
  p->shown = 1;
  return 0;
}

void cli_progress_attach(cli_progress *p, const char *label, int quiet,
                         bb_trace_options *trace) {
  memset(p, 0, sizeof *p);
  p->label = label;
  p->start_seconds = cli_now_seconds();
  if (quiet || !isatty(STDERR_FILENO))
    return;
  trace->progress = progress_draw;
  trace->progress_user = p;
}

void cli_progress_finish(cli_progress *p) {
  if (!p->shown)
    return;
  fputs("\r\033[K", stderr);
  fflush(stderr);
  p->shown = 0;
}
