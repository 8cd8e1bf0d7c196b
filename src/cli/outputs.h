/* cli_outputs.h: output paths checked before a bake, and outputs written
 * with provenance, alone or all or nothing (cli_outputs.c). */
#ifndef BB_CLI_OUTPUTS_H
#define BB_CLI_OUTPUTS_H

#include "bumpbake.h"
#include "options.h"

#include <stdint.h>

/* ---------------------------------------------------------------- outputs */

/* Checks an output path before any work is done: BB_EXIT_USAGE for an
 * extension bb_image_write does not know or a depth its format cannot hold;
 * BB_EXIT_FAILURE when it names the input file or its directory does not
 * exist. Prints the error. Returns 0 when the path looks writable. */
int cli_check_output(const char *command, const char *input_path, const char *output_path,
                     bb_depth depth);

/* 0 when the directory part of path exists and is a directory; else prints
 * "bumpbake: PATH: cannot write: ..." and returns BB_EXIT_FAILURE. */
int cli_check_output_directory(const char *path);

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
  uint64_t input_file_hash; /* bb_file_hash of the input file; 0 = not yet */
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
 * height and the settings the outputs are made with; and the hash of the
 * input file's bytes, unless the caller set input_file_hash before loading
 * (bake does, to record the bytes it then decoded). */
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

/* One output to stage: cli_stage_output(run, out, image, range). */
typedef struct cli_stage_task {
  const cli_run *run;
  const bb_image *image;
  bb_range range;
  cli_staged_output *out;
} cli_stage_task;

/* Stages every task with cli_stage_output, several at once: encoding (zlib
 * for PNG, TIFF and EXR) is most of a write, so outputs are encoded side by
 * side on at most `threads` threads (the caller's included; 0 = one per
 * task). Returns when all n are staged; the results are in each task's out,
 * whatever order they finished in. */
void cli_stage_outputs(const cli_stage_task *tasks, int n, int threads);

/* All or nothing: when every one of the n outputs was staged, renames them
 * into place in order and returns 0; otherwise removes every staged file.
 * A failure prints one line, "bumpbake: PATH: reason; no output was written"
 * (or "; already written: KIND PATH, ..." when a rename failed after
 * others), and returns BB_EXIT_FAILURE. */
int cli_commit_outputs(cli_staged_output *outs, int n);

#endif /* BB_CLI_OUTPUTS_H */
