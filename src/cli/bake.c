/* bake.c: the commands that run through the library's job (bake, normal,
 * height2ssbump): planned by the library from the checked command
 * (bb_command_plan), run, and reported here: the files written, a JSON
 * line per input, a batch's summary (the library's lines, bb_job_report_lines);
 * --scheduler hands the command to the cluster. */
#include "cli.h"
#include "cluster.h"
#include "common.h"
#include "progress.h"
#include "bumpbake_cluster.h"

#include <stdio.h>
#include <stdlib.h>

/* What the command line says of the inputs as they run. */
typedef struct printer {
  const bb_command *command;
  int batch;
  int counts[5];          /* by bb_job_outcome */
  cli_progress *progress; /* cleared before a report is printed */
} printer;

static void print_report(void *user, const bb_job_report *r) {
  printer *p = user;
  cli_progress_finish(p->progress);
  p->counts[r->outcome]++;
  if (r->outcome == BB_JOB_FAILED)
    cli_error_line(r->error.message[0] ? r->error.message : bb_status_name(r->status));
  cli_put_lines(bb_job_report_lines(p->command, r, p->batch, NULL));
}

int cli_run_job(const cli_run *r) {
  const char *name = bb_command_describe(r->command)->name;
  if (bb_command_given(r->command, "scheduler"))
    return cli_cluster_exec(r); /* returns only on failure */
  /* The bar is the notes' user: a note clears it before its line. */
  cli_progress progress;
  cli_progress_start(&progress, name, r->quiet);
  const bb_command_hooks hooks = {cli_progress_note, &progress, NULL, NULL, NULL, NULL};
  bb_job *job = NULL;
  bb_error err = {{0}};
  bb_status st = bb_command_plan(r->command, &hooks, &job, &err);
  if (st != BB_OK)
    return cli_library_error(name, st, &err);
  progress.job = job; /* the bar names the block compression stage */
  printer p = {r->command, bb_command_given(r->command, "out-dir"), {0}, &progress};
  st = bb_job_run(job, cli_progress_fn(&progress), &progress, print_report, &p, &err);
  cli_progress_finish(&progress);
  int rc = BB_EXIT_OK;
  if (st != BB_OK) {
    rc = BB_EXIT_FAILURE;
    /* An input's failure was printed with its report; what is left is the
     * depfile's. */
    if (!p.counts[BB_JOB_FAILED])
      cli_error_line(err.message);
  }
  if (p.batch)
    cli_put_lines(bb_job_summary_lines(p.command, p.counts, bb_job_count(job)));
  bb_job_free(job);
  return rc;
}
