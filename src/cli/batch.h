/* cli_batch.h: `bumpbake bake` over many inputs in one process (--out-dir):
 * directories expanded to the images they hold, output names made from a
 * template, name clashes refused before any bake, inputs whose outputs are
 * all current skipped, one JSON line per input, a summary, and a Make/Ninja
 * depfile. Baking one input stays the business of cli_bake.c, reached
 * through cli_batch_client. */
#ifndef BB_CLI_BATCH_H
#define BB_CLI_BATCH_H

#include "common.h"

/* The batch options as given (pointers into argv). */
typedef struct cli_batch_args {
  const char *out_dir;       /* --out-dir DIR: a batch; NULL: a single bake */
  const char *name_template; /* --name TEMPLATE, NULL = CLI_BATCH_DEFAULT_NAME */
  const char *maps;          /* --maps LIST, NULL = the kinds -o PREFIX writes */
  const char *depfile;       /* --depfile FILE (also for a single bake) */
  const char *basis_arg;     /* --basis as given: a basis file is a dependency */
  int keep_going, force;
} cli_batch_args;

#define CLI_BATCH_DEFAULT_NAME "{stem}_{kind}.png"

/* Option-table rows of the batch options, for bake's table. */
extern const cli_option cli_opt_out_dir, cli_opt_name, cli_opt_maps, cli_opt_keep_going,
    cli_opt_force, cli_opt_depfile;

/* 1 when opt is one of the rows above. */
int cli_batch_owns(const cli_option *opt);

/* Records one of the batch options; 0 (they take any value here: they are
 * checked once every option is known). */
int cli_batch_option(cli_batch_args *b, const cli_option *opt, const char *arg);

/* Without --out-dir, the options that only a batch uses are usage errors:
 * 0 or BB_EXIT_USAGE after printing. */
int cli_batch_check_single(const char *command, const cli_batch_args *b);

/* The maps a batch writes are the library's output kinds
 * (bb_output_kind_get): --maps and the template's {kind} use their names. */
enum { CLI_BATCH_MAX_KINDS = BB_OUTPUT_KIND_COUNT };

/* The name of kind (a bb_output_kind). */
static inline const char *cli_batch_kind_name(int kind) {
  return bb_output_kind_get((bb_output_kind)kind)->name;
}

/* What the batch needs of the command that bakes one input. paths has
 * BB_OUTPUT_KIND_COUNT entries, by bb_output_kind, NULL for a kind not
 * written. */
typedef struct cli_batch_client {
  const char *command;   /* "bake", for messages */
  unsigned default_maps; /* BB_OUTPUT_BIT(kind)s written without --maps */
  const cli_settings *settings; /* as parsed; the provenance of the outputs */
  int json, quiet;
  void *ctx;
  /* Checks one input's outputs as the single bake would, before any bake:
   * 0 or the exit code after printing the error. */
  int (*check)(void *ctx, const char *input, const char *const *paths);
  /* The depth kind is written with at path when input is baked. */
  bb_depth (*depth)(void *ctx, const char *input, int kind, const char *path);
  /* Bakes one input into paths (printing "wrote ..." or its JSON line with
   * the given status): 0 or the exit code after printing the error. */
  int (*bake)(void *ctx, cli_run *run, const char *input, const char *const *paths);
} cli_batch_client;

/* Runs the batch of the inputs argv[first..argc-1] (files and
 * directories) and returns the exit code: 0 when every input was baked or
 * up to date, BB_EXIT_FAILURE when any failed, BB_EXIT_USAGE for a usage
 * error found before the first bake. argv is the command's, after option
 * parsing (its options come first): each output's provenance records
 * "bumpbake COMMAND INPUT OPTIONS". */
int cli_batch_run(const cli_batch_client *c, const cli_batch_args *b, cli_run *run, int argc,
                  char **argv, int first);

/* Checks b->depfile for one bake before it runs (cli_depfile_check with
 * the rule cli_batch_write_depfile will write): 0, or the exit code after
 * printing. */
int cli_batch_check_depfile(const char *command, const cli_batch_args *b,
                            const cli_settings *s, const char *input,
                            const char *const *outputs, int output_count);

/* Writes b->depfile for one bake ("out1 out2: input [basis file]"), the
 * rule a batch writes for each of its inputs; s are the bake's settings.
 * 0 or BB_EXIT_FAILURE after printing. */
int cli_batch_write_depfile(const cli_batch_args *b, const cli_settings *s, const char *input,
                            const char *const *outputs, int output_count);

/* One rule of a depfile: every target depends on every prerequisite. */
typedef struct cli_dep_rule {
  const char *const *targets;
  int target_count;
  const char *const *prerequisites;
  int prerequisite_count;
} cli_dep_rule;

/* Checks path, a depfile to write with rules, before any bake: not a
 * prerequisite of a rule (BB_EXIT_FAILURE: it would replace a file the
 * bake reads), not a target (BB_EXIT_USAGE), not a directory, and in a
 * directory that exists. 0, or the exit code after printing. */
int cli_depfile_check(const char *command, const char *path, const cli_dep_rule *rules,
                      int count);

/* Writes a Make/Ninja depfile ("t1 t2: p1 p2" per rule; spaces and '#'
 * escaped with '\', '$' as "$$", as GCC's -MD writes them) to path,
 * through a temporary in its directory renamed into place: a failure
 * leaves the previous file. A name holding a newline cannot be written.
 * 0, or BB_EXIT_FAILURE after printing "bumpbake: PATH: reason". */
int cli_depfile_write(const char *path, const cli_dep_rule *rules, int count);

#endif /* BB_CLI_BATCH_H */
