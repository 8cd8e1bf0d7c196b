/* cli_batch.c: `bumpbake bake INPUTS... --out-dir DIR`: every input baked
 * in one process (OpenImageIO's start-up paid once), inputs whose outputs
 * are all current skipped (bb_output_check), a line per input, a summary,
 * and a depfile. The plan (inputs, names, clashes) is cli_batch_plan.c's. */
#include "batch.h"
#include "batch_plan.h"

#include <stdlib.h>
#include <string.h>

/* ---------------------------------------------------------------- options */

const cli_option cli_opt_out_dir = {
    .id = CLI_OPT_OUT_DIR,
    .long_name = "out-dir",
    .value_name = "DIR",
    .help = "a batch: bake every HEIGHT (files, or directories of images) into DIR"};
const cli_option cli_opt_name = {
    .id = CLI_OPT_NAME,
    .long_name = "name",
    .value_name = "TEMPLATE",
    .default_text = CLI_BATCH_DEFAULT_NAME,
    .range_text = "{stem} {kind} {ext}",
    .help = "a batch's file names: the input's stem, the map, the input's extension"};
const cli_option cli_opt_maps = {
    .id = CLI_OPT_MAPS,
    .long_name = "maps",
    .value_name = "LIST",
    .default_text = "normal,ssbump,ao",
    .range_text = "normal weights ssbump ao bent filtered",
    .help = "the maps a batch writes, comma-separated"};
const cli_option cli_opt_keep_going = {
    .id = CLI_OPT_KEEP_GOING,
    .long_name = "keep-going",
    .help = "a batch goes on after an input fails (and exits 1 at the end)"};
const cli_option cli_opt_force = {
    .id = CLI_OPT_FORCE,
    .long_name = "force",
    .help = "a batch bakes inputs whose outputs are up to date, too"};
const cli_option cli_opt_depfile = {
    .id = CLI_OPT_DEPFILE,
    .long_name = "depfile",
    .value_name = "FILE",
    .help = "write a Make/Ninja depfile: the outputs depend on the input (and --basis FILE)"};

int cli_batch_owns(const cli_option *opt) {
  return opt->id >= CLI_OPT_OUT_DIR && opt->id <= CLI_OPT_DEPFILE;
}

int cli_batch_option(cli_batch_args *b, const cli_option *opt, const char *arg) {
  switch (opt->id) {
  case CLI_OPT_OUT_DIR: b->out_dir = arg; break;
  case CLI_OPT_NAME: b->name_template = arg; break;
  case CLI_OPT_MAPS: b->maps = arg; break;
  case CLI_OPT_KEEP_GOING: b->keep_going = 1; break;
  case CLI_OPT_FORCE: b->force = 1; break;
  case CLI_OPT_DEPFILE: b->depfile = arg; break;
  default: break;
  }
  return 0;
}

int cli_batch_check_single(const char *command, const cli_batch_args *b) {
  const char *batch_only = b->name_template ? "--name"
                           : b->maps        ? "--maps"
                           : b->keep_going  ? "--keep-going"
                           : b->force       ? "--force"
                                            : NULL;
  if (!batch_only)
    return 0;
  return cli_usage_error(command, "%s is for batches: give --out-dir DIR", batch_only);
}

/* -------------------------------------------------------------- depfiles */

/* The files a bake reads beyond its input: a basis file (its name is the
 * --basis argument when the basis is a caller's vectors). */
static int extra_prerequisites(const cli_batch_args *b, const cli_settings *s,
                               const char **out) {
  if (b->basis_arg && strncmp(s->bake.basis.name, "vectors:", 8) == 0) {
    out[0] = b->basis_arg;
    return 1;
  }
  return 0;
}

/* Fills prereq (room for 2) with input and the extra files; the count. */
static int prerequisites_of(const cli_batch_args *b, const cli_settings *s, const char *input,
                            const char **prereq) {
  prereq[0] = input;
  return 1 + extra_prerequisites(b, s, prereq + 1);
}

int cli_batch_check_depfile(const char *command, const cli_batch_args *b,
                            const cli_settings *s, const char *input,
                            const char *const *outputs, int output_count) {
  const char *prereq[2];
  cli_dep_rule rule = {outputs, output_count, prereq, prerequisites_of(b, s, input, prereq)};
  return cli_depfile_check(command, b->depfile, &rule, 1);
}

int cli_batch_write_depfile(const cli_batch_args *b, const cli_settings *s, const char *input,
                            const char *const *outputs, int output_count) {
  const char *prereq[2];
  cli_dep_rule rule = {outputs, output_count, prereq, prerequisites_of(b, s, input, prereq)};
  return cli_depfile_write(b->depfile, &rule, 1);
}

/* ------------------------------------------------------------------ runs */

typedef enum outcome { NOT_RUN = 0, BAKED, CURRENT, FAILED } outcome;

/* The outputs of an item as a compact list (the paths' non-NULL entries). */
static int outputs_of(const cli_batch_item *item, const char **out, const char **kinds) {
  int n = 0;
  for (int k = 0; k < BB_OUTPUT_KIND_COUNT; k++)
    if (item->paths[k]) {
      if (kinds)
        kinds[n] = cli_batch_kind_name(k);
      out[n++] = item->paths[k];
    }
  return n;
}

/* 1 when every output of item is what baking it now would write. */
static int item_is_current(const cli_batch_client *c, const cli_batch_item *item,
                           uint64_t file_hash) {
  bb_bake_options o = c->settings->bake;
  /* The client's kinds are the library's, in bb_output_kind order. */
  o.outputs = 0;
  for (int k = 0; k < BB_OUTPUT_KIND_COUNT; k++)
    if (item->paths[k])
      o.outputs |= BB_OUTPUT_BIT(k);
  char rayset[64];
  bb_bake_rayset_id(&o, rayset, sizeof rayset);
  for (int k = 0; k < BB_OUTPUT_KIND_COUNT; k++) {
    if (!item->paths[k])
      continue;
    bb_provenance want = {NULL, NULL, 0, cli_batch_kind_name(k), &o, c->settings->channel,
                          rayset[0] ? rayset : NULL, file_hash};
    bb_output_state state;
    bb_depth depth = c->depth(c->ctx, item->input, k, item->paths[k]);
    if (bb_output_check(item->paths[k], &want, depth, c->settings->mips, &state, NULL, 0,
                        NULL) != BB_OK ||
        state != BB_OUTPUT_CURRENT)
      return 0;
  }
  return 1;
}

/* "bumpbake COMMAND INPUT OPTIONS...": what bakes this input alone, for
 * its outputs' provenance (argv's options come first after parsing). */
static char *command_line_for(const char *input, char **argv, int first) {
  size_t len = strlen("bumpbake ") + strlen(argv[0]) + strlen(input) + 3;
  for (int i = 1; i < first; i++)
    len += strlen(argv[i]) + 1;
  char *line = malloc(len);
  if (!line)
    return NULL;
  snprintf(line, len, "bumpbake %s %s", argv[0], input);
  for (int i = 1; i < first; i++) {
    strcat(line, " ");
    strcat(line, argv[i]);
  }
  return line;
}

static void print_line(const cli_batch_client *c, const cli_batch_item *item, outcome o,
                       int code) {
  const char *paths[CLI_BATCH_MAX_KINDS], *kinds[CLI_BATCH_MAX_KINDS];
  int n = outputs_of(item, paths, kinds);
  if (!c->json) {
    for (int i = 0; i < n && o == CURRENT && !c->quiet; i++)
      printf("up to date %s %s\n", kinds[i], paths[i]);
    return;
  }
  cli_json j = {stdout, 0};
  cli_json_open(&j, NULL, '{');
  cli_json_string(&j, "input", item->input);
  cli_json_string(&j, "status", o == CURRENT ? "up to date" : "failed");
  if (o == FAILED)
    cli_json_int(&j, "exit_code", code);
  cli_json_open(&j, "outputs", '[');
  for (int i = 0; i < n; i++) {
    cli_json_open(&j, NULL, '{');
    cli_json_string(&j, "kind", kinds[i]);
    cli_json_string(&j, "path", paths[i]);
    cli_json_close(&j, '}');
  }
  cli_json_close(&j, ']');
  cli_json_close(&j, '}');
  fputc('\n', stdout);
}

/* Bakes one input unless its outputs are current; prints its line. */
static outcome run_item(const cli_batch_client *c, const cli_batch_args *b, cli_run *run,
                        const cli_batch_item *item, char **argv, int first) {
  uint64_t hash = 0;
  bb_error err = {{0}};
  bb_status st = bb_file_hash(item->input, &hash, &err);
  int code = cli_status_exit(item->input, st, &err);
  if (!code && !b->force && item_is_current(c, item, hash)) {
    print_line(c, item, CURRENT, 0);
    return CURRENT;
  }
  char *line = code ? NULL : command_line_for(item->input, argv, first);
  if (!code && !line) {
    cli_file_error(item->input, "out of memory");
    code = BB_EXIT_FAILURE;
  }
  if (!code) {
    char *batch_line = run->command_line;
    run->command_line = line;
    run->input_file_hash = hash; /* the bytes checked, not a later read's */
    run->rayset_id = NULL;
    run->seconds_write = 0;
    code = c->bake(c->ctx, run, item->input, (const char *const *)item->paths);
    run->command_line = batch_line;
    free(line);
  }
  if (code)
    print_line(c, item, FAILED, code);
  fflush(stdout);
  return code ? FAILED : BAKED;
}

/* A batch's depfile rules, in arrays of their own. */
typedef struct batch_rules {
  const char *(*targets)[CLI_BATCH_MAX_KINDS];
  const char *(*prereq)[2];
  cli_dep_rule *rules;
  int count;
} batch_rules;

static void batch_rules_free(batch_rules *r) {
  free(r->targets);
  free(r->prereq);
  free(r->rules);
}

/* A rule per input baked or up to date (every input when outcomes is
 * NULL: the plan before it runs); 0, or -1 when out of memory. */
static int batch_rules_make(const cli_batch_client *c, const cli_batch_args *b,
                            const cli_batch_plan *plan, const outcome *outcomes,
                            batch_rules *r) {
  r->targets = malloc((size_t)plan->count * sizeof *r->targets);
  r->prereq = malloc((size_t)plan->count * sizeof *r->prereq);
  r->rules = malloc((size_t)plan->count * sizeof *r->rules);
  r->count = 0;
  if (!r->targets || !r->prereq || !r->rules) {
    batch_rules_free(r);
    return -1;
  }
  for (int i = 0; i < plan->count; i++) {
    if (outcomes && outcomes[i] != BAKED && outcomes[i] != CURRENT)
      continue;
    const int n = r->count++;
    int count = outputs_of(&plan->items[i], r->targets[n], NULL);
    r->rules[n] = (cli_dep_rule){r->targets[n], count, r->prereq[n],
                                 prerequisites_of(b, c->settings, plan->items[i].input,
                                                  r->prereq[n])};
  }
  return 0;
}

/* The depfile of a batch: a rule per input baked or up to date. */
static int write_batch_depfile(const cli_batch_client *c, const cli_batch_args *b,
                               const cli_batch_plan *plan, const outcome *outcomes) {
  batch_rules r;
  if (batch_rules_make(c, b, plan, outcomes, &r) != 0) {
    cli_file_error(b->depfile, "out of memory");
    return BB_EXIT_FAILURE;
  }
  int rc = cli_depfile_write(b->depfile, r.rules, r.count);
  batch_rules_free(&r);
  return rc;
}

/* The depfile's path against every input and output of the plan, before
 * the first bake. */
static int check_batch_depfile(const cli_batch_client *c, const cli_batch_args *b,
                               const cli_batch_plan *plan) {
  batch_rules r;
  if (batch_rules_make(c, b, plan, NULL, &r) != 0) {
    cli_file_error(b->depfile, "out of memory");
    return BB_EXIT_FAILURE;
  }
  int rc = cli_depfile_check(c->command, b->depfile, r.rules, r.count);
  batch_rules_free(&r);
  return rc;
}

static void print_summary(const cli_batch_client *c, const int *counts, int files) {
  if (c->json) {
    cli_json j = {stdout, 0};
    cli_json_open(&j, NULL, '{');
    cli_json_open(&j, "summary", '{');
    cli_json_int(&j, "files", files);
    cli_json_int(&j, "baked", counts[BAKED]);
    cli_json_int(&j, "up_to_date", counts[CURRENT]);
    cli_json_int(&j, "failed", counts[FAILED]);
    cli_json_int(&j, "not_run", counts[NOT_RUN]);
    cli_json_close(&j, '}');
    cli_json_close(&j, '}');
    fputc('\n', stdout);
  } else if (!c->quiet) {
    printf("%s: %d file%s: %d baked, %d up to date, %d failed", c->command, files,
           files == 1 ? "" : "s", counts[BAKED], counts[CURRENT], counts[FAILED]);
    if (counts[NOT_RUN])
      printf(", %d not run (stopped at the first failure; --keep-going goes on)",
             counts[NOT_RUN]);
    fputc('\n', stdout);
  }
}

/* Every input's outputs checked as a single bake would, before any bake. */
static int check_plan(const cli_batch_client *c, const cli_batch_plan *plan) {
  for (int i = 0; i < plan->count; i++) {
    int rc = c->check(c->ctx, plan->items[i].input, (const char *const *)plan->items[i].paths);
    if (rc)
      return rc;
  }
  return 0;
}

int cli_batch_run(const cli_batch_client *c, const cli_batch_args *b, cli_run *run, int argc,
                  char **argv, int first) {
  cli_batch_plan plan;
  int rc = cli_batch_plan_make(c, b, argv + first, argc - first, &plan);
  if (!rc)
    rc = check_plan(c, &plan);
  if (!rc && b->depfile)
    rc = check_batch_depfile(c, b, &plan);
  outcome *outcomes = rc ? NULL : calloc((unsigned)plan.count, sizeof *outcomes);
  if (!rc && !outcomes) {
    cli_file_error(plan.items[0].input, "out of memory");
    rc = BB_EXIT_FAILURE;
  }
  if (rc) {
    cli_batch_plan_free(&plan);
    return rc;
  }
  int counts[4] = {0};
  int stopped = 0;
  for (int i = 0; i < plan.count; i++) {
    outcomes[i] = stopped ? NOT_RUN : run_item(c, b, run, &plan.items[i], argv, first);
    counts[outcomes[i]]++;
    stopped |= outcomes[i] == FAILED && !b->keep_going;
  }
  rc = counts[FAILED] ? BB_EXIT_FAILURE : 0;
  if (b->depfile && write_batch_depfile(c, b, &plan, outcomes) != 0)
    rc = BB_EXIT_FAILURE;
  print_summary(c, counts, plan.count);
  free(outcomes);
  cli_batch_plan_free(&plan);
  return rc;
}
