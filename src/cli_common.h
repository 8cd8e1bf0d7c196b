/* cli_common.h: what the bumpbake subcommands share: option tables and their
 * parsing with range checks, error printing, output writing with provenance
 * and the progress bar (the JSON writer is cli_json.h). Nothing here is part
 * of the library. */
#ifndef BB_CLI_COMMON_H
#define BB_CLI_COMMON_H

#include "bumpbake.h"
#include "cli.h"
#include "cli_json.h" /* --json output */

#include <stdint.h>
#include <stdio.h>

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
  CLI_OPT_MIPS            /* --mips */
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

/* Prints "bumpbake NAME: message" on stderr and returns BB_EXIT_USAGE. */
int cli_usage_error(const char *command, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/* Prints the one-line error "bumpbake: FILE: reason" on stderr. The library's
 * messages often start with the file name already; it is not repeated. */
void cli_file_error(const char *path, const char *reason);

/* The exit code of a library call about path: 0 for BB_OK, else
 * BB_EXIT_FAILURE after printing err's message (or the status name when the
 * message is empty) as a file error. */
int cli_status_exit(const char *path, bb_status status, const bb_error *err);

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

/* Option-table rows of the shared settings, to build subcommand tables from
 * (the help text of each lives here once). */
extern const cli_option cli_opt_scale, cli_opt_rays, cli_opt_filter_radius,
    cli_opt_filter_threshold, cli_opt_bias, cli_opt_power, cli_opt_basis,
    cli_opt_normal_filter, cli_opt_normal_y, cli_opt_threads, cli_opt_clamp,
    cli_opt_channel, cli_opt_depth, cli_opt_help, cli_opt_mips;

/* ---------------------------------------------------------------- outputs */

/* Checks an output path before any work is done: BB_EXIT_USAGE for an
 * extension bb_image_write does not know or a depth its format cannot hold;
 * BB_EXIT_FAILURE when it names the input file or its directory does not
 * exist. Prints the error. Returns 0 when the path looks writable. */
int cli_check_output(const char *command, const char *input_path, const char *output_path,
                     bb_depth depth);

/* path without the extension of its last component, plus suffix
 * ("rock.png", "-ssbump.tga" -> "rock-ssbump.tga"), malloc'd; NULL when
 * out of memory. */
char *cli_path_with_suffix(const char *path, const char *suffix);

/* With --mips, an output must be a format that holds mip levels (.tif,
 * .tiff, .exr): else prints a usage error and returns BB_EXIT_USAGE. */
int cli_check_mips(const char *command, const cli_settings *s, const char *output_path);

/* bb_image_write, or with mips the file of img's mip chain (bb_mip_chain,
 * renormalised when wo->range is BB_RANGE_SIGNED, then
 * bb_image_write_mips). */
bb_status cli_write_image(const char *path, const bb_image *img, const bb_write_options *wo,
                          int mips, bb_error *err);

/* 1 when a and b name the same file: the same device and inode when both
 * exist (symbolic and hard links, "./", "..": a write of one would replace
 * or clobber the other), else the same name in the same directory (by the
 * directory's device and inode), else the same spelling. */
int cli_same_file(const char *a, const char *b);

/* What every output of one run shares, for its provenance. */
typedef struct cli_run {
  char *command_line; /* "bumpbake " + argv joined with spaces */
  const char *input_path;
  uint64_t input_hash; /* bb_image_hash of the decoded height */
  const cli_settings *settings;
  const char *rayset_id; /* NULL when nothing was traced */
  double seconds_write;  /* summed over cli_write_output calls */
} cli_run;

/* Starts a run: records the command line, so it must be called before
 * cli_parse_options (getopt_long permutes argv). The command line is
 * malloc'd; free it with cli_run_free. Returns BB_EXIT_FAILURE when out of
 * memory, after printing why. */
int cli_run_init(cli_run *run, int argc, char **argv);
/* Records the input once it is loaded: its path, the hash of its decoded
 * height and the settings the outputs are made with. */
void cli_run_set_input(cli_run *run, const char *input_path, const bb_image *height,
                       const cli_settings *settings);
void cli_run_free(cli_run *run);

/* Writes img to path with the run's depth, the given range and a provenance
 * description of kind; with --mips, as a mip-mapped file (normal maps,
 * BB_RANGE_SIGNED, renormalised per level). Prints "bumpbake: PATH: reason"
 * and returns BB_EXIT_FAILURE on failure, 0 on success. */
int cli_write_output(cli_run *run, const char *kind, const char *path,
                     const bb_image *img, bb_range range);

/* One output of a command that writes several: staged first (complete and
 * synced under a temporary name), then put in place with the others by
 * cli_commit_outputs, so that a failure changes nothing on disk. */
typedef struct cli_staged_output {
  const char *kind;     /* "normal", ... for provenance and messages */
  const char *path;     /* destination */
  bb_staged_file *file; /* the staged file, NULL when staging failed */
  bb_status status;     /* of staging, then of the commit */
  bb_error error;       /* why status is not BB_OK */
  int written;          /* set by cli_commit_outputs once in place */
} cli_staged_output;

/* Stages img for out->path like cli_write_output, without printing: the
 * result goes to out->status, out->error and out->file. Thread-safe for
 * distinct outputs (it does not touch run). */
void cli_stage_output(const cli_run *run, cli_staged_output *out, const bb_image *img,
                      bb_range range);

/* All or nothing: when every one of the n outputs was staged, renames them
 * into place in order and returns 0; otherwise removes every staged file.
 * A failure prints one line, "bumpbake: PATH: reason; no output was written"
 * (or "; already written: KIND PATH, ..." when a rename failed after
 * others), and returns BB_EXIT_FAILURE. */
int cli_commit_outputs(cli_staged_output *outs, int n);

/* Installs the CLI's signal handling, first thing in main: SIGINT, SIGTERM
 * and SIGHUP remove the temporaries of writes in progress
 * (bb_tempfiles_remove) and end the process by the same signal; SIGXFSZ is
 * ignored, so a write over RLIMIT_FSIZE is an ordinary write error. */
void cli_install_signal_handlers(void);

/* Loads the height of path by the settings' channel rule; prints the error
 * and returns BB_EXIT_FAILURE on failure. When the rule finds the height in
 * alpha (constant colour, varying alpha) it says so on stderr. */
int cli_load_height(const char *path, const cli_settings *s, bb_image *height);

/* What cli_load_height_source found out about the height's file. */
typedef struct cli_height_source {
  bb_channel channel;  /* the channel rule's choice (never BB_CHANNEL_AUTO) */
  int grey;            /* 1: one colour channel (grey, or grey + alpha) */
  int bits_per_sample; /* of the file: 8, 16, 32 */
  int is_float;        /* 1: float or half samples */
} cli_height_source;

/* cli_load_height, also filling *source (may be NULL). */
int cli_load_height_source(const char *path, const cli_settings *s, bb_image *height,
                           cli_height_source *source);

/* The name of the channel the height came from, for --json: "grey" for a
 * grey image (whose mean is its grey), else bb_channel_name's. */
const char *cli_height_channel_name(const cli_height_source *source);

/* The depth nearest the input's that path's format holds, for outputs that
 * are the height itself (--filtered): 16 bits for a 16-bit input, float or
 * half for a float or half input; BB_DEPTH_DEFAULT for an 8-bit input or
 * when the format holds nothing deeper (TGA). */
bb_depth cli_depth_like_input(const cli_height_source *source, const char *path);

/* Readers of basis maps (render, ssbump2normal, combine --detail) take
 * channels 0..2 as Half-Life 2's B0, B1, B2. 0 when the file at path (img,
 * its info) can be one: at most 4 channels, and a provenance basis, if any,
 * of hl2, hl2+z or dirs:3; else prints "bumpbake: PATH: reason" and
 * returns BB_EXIT_FAILURE. */
int cli_check_hl2_map(const char *path, const bb_image *img, const bb_image_info *info);

/* Runs bb_bake; prints the error (naming path) and returns BB_EXIT_FAILURE on
 * failure. */
int cli_run_bake(const char *path, const bb_image *height, const bb_bake_options *o,
                 bb_bake_result *result);

/* Monotonic seconds, for the per-stage timings the CLI measures itself. */
double cli_now_seconds(void);

/* Mutes stderr (libpng, inside OpenImageIO, prints its own line about a
 * corrupt PNG, which would make an error two lines) until
 * cli_unmute_stderr(saved) with what cli_mute_stderr returned. */
int cli_mute_stderr(void);
void cli_unmute_stderr(int saved);

/* bb_image_read with stderr muted. */
bb_status cli_read_image(const char *path, bb_image *img, bb_image_info *info, bb_error *err);

/* --------------------------------------------------------------- progress */

/* A one-line progress bar on stderr: "bake [#####.....] 42% ETA 1.3s". It
 * appears only once the work has run for about a second, so short bakes
 * print nothing, and only when stderr is a terminal. */
typedef struct cli_progress {
  const char *label;
  double start_seconds;
  double last_draw_seconds;
  int shown; /* a line is on screen and must be cleared */
} cli_progress;

/* Sets up p and, when stderr is a terminal and not quiet, points the trace
 * options' progress callback at it. */
void cli_progress_attach(cli_progress *p, const char *label, int quiet,
                         bb_trace_options *trace);
/* Clears the bar's line if one was drawn. */
void cli_progress_finish(cli_progress *p);

#endif /* BB_CLI_COMMON_H */
