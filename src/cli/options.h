/* options.h: option tables, their parsing with range checks and --help,
 * and the bake settings the baking commands share (cli_options.c). */
#ifndef BB_CLI_OPTIONS_H
#define BB_CLI_OPTIONS_H

#include "bumpbake.h"
#include "cli.h"

/* --------------------------------------------------------------- options */

/* Identifiers of every option any subcommand knows. Values above 255 so they
 * never collide with the short option letters getopt_long returns. */
typedef enum cli_opt_id {
  CLI_OPT_HELP = 256,
  CLI_OPT_SCALE,
  CLI_OPT_RAYS,
  CLI_OPT_SLICES,
  CLI_OPT_FILTER_RADIUS,
  CLI_OPT_FILTER_THRESHOLD,
  CLI_OPT_BIAS,
  CLI_OPT_POWER,
  CLI_OPT_BASIS,
  CLI_OPT_NORMAL_FILTER,
  CLI_OPT_NORMAL_Y,
  CLI_OPT_THREADS,
  CLI_OPT_CLAMP,
  CLI_OPT_CHANNEL,
  CLI_OPT_DEPTH,
  CLI_OPT_OUTPUT,     /* -o: the output file (normal) or prefix (bake) */
  CLI_OPT_OUT_NORMAL, /* bake's per-kind outputs, in bake_output_kinds order */
  CLI_OPT_OUT_WEIGHTS,
  CLI_OPT_OUT_SSBUMP,
  CLI_OPT_OUT_AO,
  CLI_OPT_OUT_BENT,
  CLI_OPT_OUT_FILTERED,
  CLI_OPT_JSON,
  CLI_OPT_QUIET,
  /* height2ssbump's Valve-style flags */
  CLI_OPT_VALVE_NORMAL,   /* -n */
  CLI_OPT_VALVE_AO_ALPHA, /* -A */
  CLI_OPT_VALVE_DUMP,     /* -D */
  CLI_OPT_VALVE_DETAIL,   /* -d */
  CLI_OPT_MIPS,           /* --mips */
  /* bake's batches */
  CLI_OPT_OUT_DIR,
  CLI_OPT_NAME,
  CLI_OPT_MAPS,
  CLI_OPT_KEEP_GOING,
  CLI_OPT_FORCE,
  CLI_OPT_DEPFILE,
  CLI_OPT_SLOPE,     /* bake --slope FILE */
  CLI_OPT_SLOPE_LIT, /* bake --lit AZ,EL */
  CLI_OPT_SCHEDULER, /* bake --scheduler ADDRESS: on a Dask cluster */
  /* bake's inter-reflection and brightness */
  CLI_OPT_BOUNCE,
  CLI_OPT_BOUNCES,
  CLI_OPT_BOUNCE_ALBEDO,
  CLI_OPT_BRIGHTNESS,
  /* engine textures (.vtf, .dds) and Source materials */
  CLI_OPT_TEXTURE_FORMAT,
  CLI_OPT_VTF_VERSION,
  CLI_OPT_VTF_FLAGS,
  CLI_OPT_NOMIP,
  CLI_OPT_FAST_COMPRESSION,
  CLI_OPT_VMT,
  CLI_OPT_MATERIALS,
  CLI_OPT_BASETEXTURE
} cli_opt_id;

/* One row of a subcommand's option table: getopt_long's struct option and
 * the --help text are both generated from it, so they cannot disagree. */
typedef struct cli_option {
  int id;                   /* cli_opt_id */
  const char *long_name;    /* without "--", or NULL for a short-only option */
  char short_name;          /* 0 when none */
  const char *value_name;   /* "S", "N", ...; NULL for a flag */
  const char *default_text; /* shown in --help; NULL when there is none */
  const char *range_text;   /* shown in --help; NULL when there is none */
  const char *help;         /* one line */
  /* 1: also spelled with one dash ("-fail 0.1"), as OpenImageIO's idiff
   * spells it. A table with such a row is parsed with getopt_long_only, so
   * all its long options then take one dash; "-x" stays a short option
   * when no long option starts with x. */
  int single_dash;
} cli_option;

/* What a subcommand does with one option: 0 when accepted, BB_EXIT_USAGE
 * after printing a usage error. */
typedef int (*cli_option_fn)(void *ctx, const cli_option *opt, const char *arg);

typedef struct cli_settings cli_settings;

/* A subcommand's command-line description. */
typedef struct cli_command {
  const char *name;                 /* "normal", "bake", ... */
  const char *synopsis;             /* usage line after "bumpbake NAME " */
  const char *summary;              /* one line for --help */
  const cli_option *const *options; /* rows, shared rows by address */
  int option_count;
  /* Fills the command's default settings; --help prints the defaults of the
   * shared settings from it, so the help cannot drift from the behaviour.
   * NULL for a command without baking settings (compare, info). */
  void (*init_settings)(cli_settings *s);
} cli_command;

/* Parses argv (argv[0] = the subcommand name) with getopt_long against
 * cmd's table, calling on_option for each option, and leaves the index of
 * the first positional argument in *first_positional (getopt permutes, so
 * every positional is at the end). --help prints the help and returns -1
 * (the caller exits 0). Unknown options and missing values print a usage
 * error and return BB_EXIT_USAGE. Returns 0 otherwise. */
int cli_parse_options(const cli_command *cmd, int argc, char **argv,
                      cli_option_fn on_option, void *ctx, int *first_positional);

/* Checks the count of positional arguments (argv[first..argc-1]) against
 * expected; names is the synopsis of them ("HEIGHT", "FILE BUMPSCALE") for
 * the message. Returns 0 or BB_EXIT_USAGE after a usage error. */
int cli_expect_positionals(const cli_command *cmd, int argc, char **argv, int first,
                           int expected, const char *names);

/* Strict number parsing for option values: the whole text must be a finite
 * number inside the range, else a usage error naming the option is printed
 * and BB_EXIT_USAGE returned. min_exclusive makes the lower bound strict
 * (for "> 0"). */
int cli_parse_double(const char *command, const char *option, const char *text,
                     double min, int min_exclusive, double max, double *out);
int cli_parse_int(const char *command, const char *option, const char *text, long min,
                  long max, int *out);

/* ------------------------------------------------- bake settings (shared) */

/* Everything the options of normal, bake and height2ssbump set that is not
 * an output path. */
struct cli_settings {
  bb_bake_options bake;
  bb_channel channel;
  bb_depth depth;
  int scale_given;
  int mips; /* --mips: outputs are mip-mapped TIFF or EXR files */
  const char *basis_file; /* --basis FILE (a file, not a name), or NULL */
  bb_texture_options texture; /* .vtf and .dds outputs (--texture-format...) */
};

/* Library defaults, plus the CLI's own (channel auto, default depth). */
void cli_settings_init(cli_settings *s);

/* Applies one of the options every baking command shares (scale, rays,
 * filter radius/threshold, bias, power, basis, normal filter and y, threads,
 * clamp, channel, depth): subcommands hand it every option they do
 * not handle themselves. Returns 0 when applied, else BB_EXIT_USAGE after a
 * usage error (also for an option it does not know: an internal error). */
int cli_settings_apply(const char *command, cli_settings *s, const cli_option *opt,
                       const char *arg);

/* --slices A: an integer, its range the library's. */
int cli_settings_apply_slices(const char *command, cli_settings *s, const char *arg);

/* Option-table rows of the shared settings, to build subcommand tables from
 * (the help text of each lives here once). */
extern const cli_option cli_opt_scale, cli_opt_rays, cli_opt_filter_radius,
    cli_opt_filter_threshold, cli_opt_bias, cli_opt_power, cli_opt_basis,
    cli_opt_normal_filter, cli_opt_normal_y, cli_opt_threads, cli_opt_clamp,
    cli_opt_channel, cli_opt_depth, cli_opt_help, cli_opt_mips;

/* The rows of the engine texture settings (cli_settings.texture), for the
 * tables of every command that writes maps. */
extern const cli_option cli_opt_texture_format, cli_opt_vtf_version, cli_opt_vtf_flags,
    cli_opt_nomip, cli_opt_fast_compression;
/* A Source material's rows (bake, height2ssbump). */
extern const cli_option cli_opt_vmt, cli_opt_materials, cli_opt_basetexture;
#define CLI_TEXTURE_OPTIONS                                                              \
  &cli_opt_texture_format, &cli_opt_vtf_version, &cli_opt_vtf_flags, &cli_opt_nomip,     \
      &cli_opt_fast_compression

#endif /* BB_CLI_OPTIONS_H */
