/* cmd_internal.h: what the commands family's files share (not public): an
 * option's description with the functions of its rule, a command's with
 * its rules, and a command in use. The family sits above job: it plans
 * jobs and reads every family's ranges; nothing below includes it. */
#ifndef BB_CMD_INTERNAL_H
#define BB_CMD_INTERNAL_H

#include "bumpbake.h"
#include "cmd/command_options.h"
#include "core/internal.h"
#include "job/bake_rows.h"

#include <stddef.h>
#include <stdio.h>

typedef struct bb__option bb__option;

/* The most numbers one option holds (--rect L B R T). */
#define BB__MAX_NUMBERS 4

/* Parses text into the option's field(s); the numbers to check against the
 * option's range go to values, *count of them (bb_command_check checks
 * them; the caller sets *count to the type's count first). */
typedef bb_status (*bb__set_fn)(bb_command *c, const bb__option *o, const char *text,
                                double *values, int *count, bb_error *err);
/* Appends the option's value as it takes it, from the options. */
typedef void (*bb__print_fn)(const bb_command *c, const bb__option *o, bb__text *t);
/* 1 when the option does something in c as it stands. */
typedef int (*bb__applies_fn)(const bb_command *c);

struct bb__option {
  bb_option_info info;       /* first: a bb_option_info * is a bb__option * */
  const bb__bake_row *job;   /* a bake option's row (job/bake_rows.h): its name,
                                field, words and printing, in place of field,
                                offset, names and sets (bb__option_field...) */
  bb__field field;
  size_t offset;             /* of the field in bb_command_options */
  const bb__range *range;    /* INT, NUMBER(S): each number's range */
  const char *range_of;      /* what of the value the range is of ("elevation"), or NULL */
  bb__name_fn names;         /* WORD(S): the enum's names */
  bb__parse_fn parse;        /* WORD(S): the enum's parser; an INT read by a parser of
                                its own (--vtf-version): that parser (bb_option_parse) */
  bb__set_fn set;            /* NULL: by type and field */
  bb__print_fn print;        /* NULL: by type and field */
  bb__applies_fn applies;    /* NULL: always applies */
  const char *required_note; /* REQUIRED: what it is, after "is required" */
  void (*range_words)(char *out, size_t cap); /* a range spelled from constants */
  bb__flag_sets sets;        /* FLAG, ANGLES: the other field it sets when given */
  int repeats;               /* a map's file (PATH, STRING at job.paths[kind]): given
                                again, a further file of the same map */
};

typedef struct bb__command bb__command;

/* A command's run (run_*.c): reads, makes and writes, appending what it
 * wrote to result (bb__result_add). */
typedef bb_status (*bb__run_fn)(bb_command *c, const bb_command_hooks *hooks,
                                bb_command_result *result, bb_error *err);

struct bb__command {
  bb_command_info info;               /* first, as bb__option's */
  const bb__option *const *options;
  void (*init)(bb_command_options *o);
  /* positional i (from 0) of text; NULL: each is an input */
  bb_status (*add_input)(bb_command *c, int i, const char *text, bb_error *err);
  /* the command's own rules, after the generic checks */
  bb_status (*check)(bb_command *c, bb_error *err);
  /* its job's options (commands through the job); NULL: none */
  bb_status (*job)(bb_command *c, bb_job_options *o, bb_error *err);
  /* its run when it makes one map or picture (render, sheet, the map
   * commands): read and make here, write through the job (job/output.c) */
  bb__run_fn run;
  /* notes said before run starts (what it will cost); NULL: none */
  void (*before_run)(const bb_command *c, const bb_command_hooks *hooks);
  /* the maps it asks whatever its outputs name (BB_MAP_BIT(kind)s), for
   * the rules that look at them: serve's page shows every map; 0: those
   * its job asks (bb__job_maps_asked) */
  unsigned maps_asked;
};

/* The most options one command has. */
#define BB__MAX_OPTIONS 64

struct bb_command {
  const bb__command *def;
  bb_command_options options;
  unsigned char given[BB__MAX_OPTIONS];
  unsigned char derived[BB__MAX_OPTIONS]; /* taken from another command's settings
                                            (bb_command_derive), not set by the caller:
                                            where it does nothing, the check drops it */
  double values[BB__MAX_OPTIONS][BB__MAX_NUMBERS]; /* the numbers each option set */
  int value_count[BB__MAX_OPTIONS];
  const char *texts[BB__MAX_OPTIONS]; /* the text each option was set from (NULL: a
                                        flag), owned: a hand-over sets it again */
  char **strings;                    /* owned copies the options point to */
  int string_count, string_capacity;
  char **inputs;
  int input_count;
  char *record_line, *record_options;
  int checked;                       /* bb_command_check passed */
  /* The further files of options that repeat (a map written to several
   * files, each in its format, from one bake): which option, which file. */
  int more_count;
  int more_option[BB_JOB_MAX_OUTPUTS];
  const char *more_path[BB_JOB_MAX_OUTPUTS]; /* owned: strings */
  /* The command line each such file records (bb_command_set_record of a path). */
  int file_record_count;
  char *file_record_path[BB_JOB_MAX_OUTPUTS], *file_record_line[BB_JOB_MAX_OUTPUTS];
  int in_memory;                     /* images in memory, not files */
  bb_spelling spelling;              /* how its messages name its options */
  unsigned memory_maps;              /* ... and the maps asked of them */
};

/* The commands' descriptions (commands.c), in bumpbake --help's order. */
extern const bb__command *const bb__commands[];
extern const int bb__command_total;

/* An option's field, its offset in bb_command_options, what it sets as a
 * flag (offset in bb_command_options) and its words: its bake row's when it
 * has one (values.c). */
bb__field bb__option_field(const bb__option *o);
size_t bb__option_offset(const bb__option *o);
bb__flag_sets bb__option_sets(const bb__option *o);
bb__name_fn bb__option_names(const bb__option *o);

/* 1 when the first length characters of name are option's name ('_'
 * read as '-'). */
int bb__names_option(const char *name, size_t length, const char *option);
/* Index of the option named name in c's table, or -1. */
int bb__option_find(const bb__command *c, const char *name);
/* 1 when option name of c was set. */
int bb__given(const bb_command *c, const char *name);
/* Option i's value as bb_command_value gives it ("1"/"0" for a flag, ""
 * for a file not given). */
void bb__command_value_text(const bb_command *c, int i, bb__text *t);

/* A copy of text owned by c (NULL when out of memory). */
char *bb__command_keep(bb_command *c, const char *text);

/* "--name" (or "-x" for a short-only spelling), for messages. */
void bb__option_spelling(const bb__option *o, char *out, size_t cap);

/* The options given, " --name value" each, in the order of --help (an
 * option given more than once, each time); only those that determine the
 * output with BB_OPTION_RECORDED (text.c). */
void bb__add_options(const bb_command *c, unsigned flags, bb__text *t);
/* The same for the one file path of option `option` (an option that
 * repeats): that option spelled once, naming it. */
void bb__add_options_of_file(const bb_command *c, unsigned flags, int option,
                             const char *path, bb__text *t);

/* message (capacity cap) with c's options spelled as c's client spells
 * them (bb_command_set_spelling); nothing changes for the command line's
 * spelling (spelling.c). */
void bb__respell(const bb_command *c, char *message, size_t cap);
/* st, after err's message is respelled when st is not BB_OK: every public
 * call on a command returns through it. */
bb_status bb__spelled(const bb_command *c, bb_status st, bb_error *err);

/* hooks whose notes reach the caller respelled: h (kept alive by the
 * caller for the call) or, for the command line's spelling or no note
 * function, hooks itself. */
typedef struct bb__spelled_hooks {
  const bb_command *command;
  const bb_command_hooks *caller;
  bb_command_hooks hooks;
} bb__spelled_hooks;
const bb_command_hooks *bb__spelled_hooks_of(const bb_command *c,
                                             const bb_command_hooks *hooks,
                                             bb__spelled_hooks *h);

/* Runs (results.c): a file written, added to result. */
bb_status bb__result_add(bb_command_result *r, const char *kind, const char *path,
                         bb_error *err);
/* The command line the outputs of c record: its record, else
 * bb_command_text's (malloc'd; NULL when out of memory). */
char *bb__command_record(const bb_command *c);
/* The runs of the commands that make one map or picture (run_render.c,
 * run_maps.c); their writes go through the job (bb__job_write). */
bb_status bb__run_render(bb_command *c, const bb_command_hooks *hooks, bb_command_result *r,
                         bb_error *err);
bb_status bb__run_sheet(bb_command *c, const bb_command_hooks *hooks, bb_command_result *r,
                        bb_error *err);
bb_status bb__run_normal2ssbump(bb_command *c, const bb_command_hooks *hooks,
                                bb_command_result *r, bb_error *err);
bb_status bb__run_ssbump2normal(bb_command *c, const bb_command_hooks *hooks,
                                bb_command_result *r, bb_error *err);
bb_status bb__run_combine(bb_command *c, const bb_command_hooks *hooks, bb_command_result *r,
                          bb_error *err);
bb_status bb__run_program(bb_command *c, const bb_command_hooks *hooks, bb_command_result *r,
                          bb_error *err);
/* The runs of the commands that look at files (run_files.c): compare
 * (result->compare, its exit code, its diff in files) and info
 * (result->info, exit code 1 when a file could not be read), each with
 * what the command line prints of it (result->prints, report_files.c:
 * bb__compare_prints, bb__info_prints). */
bb_status bb__run_compare(bb_command *c, const bb_command_hooks *hooks, bb_command_result *r,
                          bb_error *err);
bb_status bb__run_info(bb_command *c, const bb_command_hooks *hooks, bb_command_result *r,
                       bb_error *err);
bb_status bb__compare_prints(const bb_command *c, bb_command_result *r, bb_error *err);
bb_status bb__info_prints(const bb_command *c, bb_command_result *r, bb_error *err);
/* printf to f and a newline, cut at 4095 bytes and made printable
 * (bb_text_printable), as the command line prints a line (report_files.c). */
void bb__print_line(FILE *f, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
/* renderbumpflat's run (run_renderbump.c): the model rendered, its files
 * written through the job (bb__renderbump_write). */
bb_status bb__run_renderbumpflat(bb_command *c, const bb_command_hooks *hooks,
                                 bb_command_result *r, bb_error *err);

/* A render's tile and crop for maps of width x height (options_render.c):
 * BB_ERR_ARGUMENT when the tiled picture is over the maximum or the crop
 * is not inside it. */
bb_status bb__render_view_check(const bb_render_options *o, int width, int height,
                                bb_error *err);

/* Value parsers (values.c): one function per rule. */
bb_status bb__set_generic(bb_command *c, const bb__option *o, const char *text,
                          double *values, int *count, bb_error *err);
void bb__print_generic(const bb_command *c, const bb__option *o, bb__text *t);
/* "v0,v1,..." of n floats, each the shortest that reads back the same. */
void bb__print_floats(bb__text *t, const float *v, int n);
/* count numbers of text (comma-separated, or blank-separated when the
 * option takes several words) into v; BB_ERR_ARGUMENT naming the option. */
bb_status bb__parse_numbers(const bb__option *o, const char *text, int count, int integers,
                            double *v, bb_error *err);
/* The words of a WORD(S) option, '|'-separated. */
void bb__choices(const bb__option *o, char *out, size_t cap);

/* Rules between options and the outputs they look at (rules.c). */
int bb__applies_texture(const bb_command *c);
int bb__applies_vtf(const bb_command *c);
int bb__applies_traced(const bb_command *c);
int bb__applies_bounces(const bb_command *c);
int bb__applies_brightness(const bb_command *c);
int bb__applies_batch(const bb_command *c);

/* Rows several commands share (options_bake.c). */
extern const bb__option bb__opt_scale, bb__opt_scale_optional, bb__opt_rays,
    bb__opt_filter_radius, bb__opt_filter_threshold, bb__opt_bias, bb__opt_power,
    bb__opt_normal_filter, bb__opt_normal_y, bb__opt_threads, bb__opt_clamp, bb__opt_channel,
    bb__opt_depth, bb__opt_depth_like_input, bb__opt_depth_of_format, bb__opt_mips,
    bb__opt_json, bb__opt_quiet, bb__opt_help, bb__opt_texture_format, bb__opt_vtf_version,
    bb__opt_vtf_flags, bb__opt_nomip, bb__opt_fast_compression, bb__opt_light_color,
    bb__opt_albedo, bb__opt_slices, bb__opt_basis, bb__opt_bounce, bb__opt_bounces,
    bb__opt_bounce_albedo, bb__opt_brightness, bb__opt_maps, bb__opt_name;

/* The options' tables (options_*.c). */
extern const bb__command bb__command_bake, bb__command_normal, bb__command_height2ssbump,
    bb__command_compare, bb__command_info, bb__command_renderbumpflat, bb__command_render,
    bb__command_sheet, bb__command_normal2ssbump, bb__command_ssbump2normal,
    bb__command_combine, bb__command_program, bb__command_serve, bb__command_check;

/* The job of a checked command (cmd/command.c): bb_command_plan with the
 * command's job options made by job_of, its inputs from first_input on,
 * and the job's plan flags (BB__PLAN_READ_ONLY: a golden check's batch,
 * which writes nothing). check --bake plans its batch so. */
bb_status bb__command_plan(bb_command *c, const bb_command_hooks *hooks,
                           bb_status (*job_of)(bb_command *c, bb_job_options *o, bb_error *err),
                           int first_input, unsigned flags, bb_job **job, bb_error *err);

/* check --bake's job options from the command's bake options
 * (options_files.c): bake's batch into GOLDEN. */
bb_status bb__check_job_options(bb_command *c, bb_job_options *o, bb_error *err);

/* check --limits' rules (run_check.c): "SELECTOR: -option value ...",
 * separated by ';' or new lines; SELECTOR a map kind's name or a pattern of
 * names; the options idiff's limits, parsed and checked by compare's rows.
 * *rules malloc'd (bb__check_rules_free), *count of them. BB_ERR_ARGUMENT
 * naming the rule at fault. */
struct bb__check_rule;
bb_status bb__check_rules_parse(const char *text, struct bb__check_rule **rules, int *count,
                                bb_error *err);
void bb__check_rules_free(struct bb__check_rule *rules, int count);

/* Once in bumpbake.h, now internal (issue 41): no client of the
 * library calls these; the library, tests, tools and fuzz targets do. */

/* 1 when the command writes through the job (bb_command_plan plans it). */
int bb__command_has_job(const bb_command_info *command);

/* Once in bumpbake.h beside the functions that stay public there. */
/* The command nearest to a mistyped name (at most 2 edits away, for "did
 * you mean"), or NULL. */
const bb_command_info *bb__command_info_nearest(const char *name);
/* The words a BB_OPTION_WORD or WORDS option takes, '|'-separated
 * ("valve|central|sobel|vertex", the names of the library's enum), into out
 * (capacity cap); "" for other types. */
void bb__option_choices(const bb_option_info *option, char *out, size_t cap);

/* How many inputs were added (bb_command_input reads them). */
int bb__command_input_count(const bb_command *command);

/* The JSON object of r (an input baked with options b), without a
 * newline: input, status (when not NULL), size, the parameters used (the
 * channel the rule took, the threads that ran), seconds per stage,
 * horizons, extra_json's members (may be NULL) and the maps written
 * (report.c; bb_command_report_json's text). */
void bb__job_report_json(FILE *f, const bb_bake_options *b, const bb_job_report *r,
                         const char *status, const char *extra_json);

/* Once in bumpbake.h, now internal (issue 41): no client of the library
 * calls it; the library, tests and tools do. */
/* The options of the command's bake as set and checked (bake, normal,
 * height2ssbump; the bake of render's and sheet's HEIGHT; the depth, mips
 * and texture settings of every command writing maps): what a client that
 * reads the bake's settings (bb__bake_slices) hands
 * on. Owned by command; NULL for NULL. Every other option is read by
 * name (bb_command_value). */
const bb_job_options *bb__command_job_options(const bb_command *command);

#endif /* BB_CMD_INTERNAL_H */
