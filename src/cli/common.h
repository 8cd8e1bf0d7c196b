/* cli_common.h: what the bumpbake subcommands share. Options and settings
 * are cli_options.h, outputs cli_outputs.h, the progress bar cli_progress.h,
 * JSON cli_json.h; this header includes them all and adds error printing,
 * reading inputs and signal handling (cli_common.c). Nothing here is part
 * of the library. */
#ifndef BB_CLI_COMMON_H
#define BB_CLI_COMMON_H

#include "bumpbake.h"
#include "cli.h"
#include "json.h" /* --json output */
#include "options.h"
#include "outputs.h"
#include "progress.h"

#include <stdint.h>
#include <stdio.h>

/* ----------------------------------------------------------------- errors */

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

/* ------------------------------------------------- inputs, signals, time */

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

#endif /* BB_CLI_COMMON_H */
