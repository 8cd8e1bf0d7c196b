/* cli_batch_plan.h: what a batch will do, decided before any bake: the
 * inputs (directories expanded), the maps chosen by --maps and each
 * input's output paths from the --name template, with clashes refused. */
#ifndef BB_CLI_BATCH_PLAN_H
#define BB_CLI_BATCH_PLAN_H

#include "batch.h"

typedef struct cli_batch_item {
  char *input;                           /* malloc'd */
  char *paths[CLI_BATCH_MAX_KINDS];      /* malloc'd; NULL = kind not written */
} cli_batch_item;

typedef struct cli_batch_plan {
  cli_batch_item *items;
  int count;
} cli_batch_plan;

/* Makes the plan of inputs[0..input_count-1] (files and directories):
 * a directory gives the files in it (not below it) whose extension
 * OpenImageIO reads, sorted by name, leaving out names starting with '.'
 * and files whose provenance says bake wrote them (so a directory can be
 * its own --out-dir); a file named twice (also through its directory)
 * counts once. Each input gets OUT_DIR/NAME per chosen kind. Returns 0, or
 * BB_EXIT_USAGE after printing a usage error (bad --maps or --name, no
 * input, two outputs on one path, an output on an input) or
 * BB_EXIT_FAILURE (a directory that cannot be read, out of memory). The
 * plan is freed by cli_batch_plan_free in every case. */
int cli_batch_plan_make(const cli_batch_client *c, const cli_batch_args *b,
                        char *const *inputs, int input_count, cli_batch_plan *plan);

void cli_batch_plan_free(cli_batch_plan *plan);

#endif /* BB_CLI_BATCH_PLAN_H */
