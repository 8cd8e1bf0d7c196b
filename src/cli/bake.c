/* bake.c: the commands that run through the library's job (bake, normal,
 * height2ssbump): planned by the library from the checked command
 * (bb_command_plan), run, and reported here: the files written, a JSON
 * line per input, a batch's summary; --scheduler hands the command to the
 * cluster. */
#include "cli.h"
#include "cluster.h"
#include "common.h"
#include "job_json.h"
#include "json.h"
#include "progress.h"

#include <stdio.h>
#include <string.h>

/* What the command line says of the inputs as they run. */
typedef struct printer {
  const bb_command_options *o;
  int batch;
  int counts[5]; /* by bb_job_outcome */
  cli_progress *progress; /* cleared before a report is printed */
} printer;

static void print_report(void *user, const bb_job_report *r) {
  printer *p = user;
  cli_progress_finish(p->progress);
  p->counts[r->outcome]++;
  if (r->outcome == BB_JOB_FAILED)
    cli_error_line(r->error.message[0] ? r->error.message : bb_status_name(r->status));
  if (r->outcome == BB_JOB_NOT_RUN)
    return;
  if (p->o->json) {
    if (r->outcome == BB_JOB_BAKED)
      cli_job_json(&p->o->job.bake, r, p->batch ? "baked" : NULL);
    else if (p->batch)
      cli_job_json_short(r);
  } else if (!p->o->quiet) {
    const char *verb = r->outcome == BB_JOB_BAKED     ? "wrote"
                       : r->outcome == BB_JOB_CURRENT ? "up to date"
                                                      : NULL;
    for (int i = 0; verb && i < r->output_count; i++)
      cli_printf_line("%s %s %s", verb, r->outputs[i].kind, r->outputs[i].path);
  }
  fflush(stdout);
}

static void print_summary(const char *command, const printer *p, int files) {
  if (p->o->json) {
    cli_json j = {stdout, 0};
    cli_json_open(&j, NULL, '{');
    cli_json_open(&j, "summary", '{');
    cli_json_int(&j, "files", files);
    cli_json_int(&j, "baked", p->counts[BB_JOB_BAKED]);
    cli_json_int(&j, "up_to_date", p->counts[BB_JOB_CURRENT]);
    cli_json_int(&j, "failed", p->counts[BB_JOB_FAILED]);
    cli_json_int(&j, "not_run", p->counts[BB_JOB_NOT_RUN]);
    cli_json_close(&j, '}');
    cli_json_close(&j, '}');
    fputc('\n', stdout);
  } else if (!p->o->quiet) {
    printf("%s: %d file%s: %d baked, %d up to date, %d failed", command, files,
           files == 1 ? "" : "s", p->counts[BB_JOB_BAKED], p->counts[BB_JOB_CURRENT],
           p->counts[BB_JOB_FAILED]);
    if (p->counts[BB_JOB_NOT_RUN])
      printf(", %d not run (stopped at the first failure; --keep-going goes on)",
             p->counts[BB_JOB_NOT_RUN]);
    fputc('\n', stdout);
  }
}

int cli_run_job(const cli_run *r) {
  const char *name = bb_command_describe(r->command)->name;
  if (r->options->scheduler)
    return cli_cluster_exec(r); /* returns only on failure */
  /* The bar is the notes' user: a note clears it before its line. */
  cli_progress progress;
  cli_progress_start(&progress, name, r->options->quiet);
  const bb_command_hooks hooks = {cli_progress_note, &progress, NULL, NULL, NULL, NULL};
  bb_job *job = NULL;
  bb_error err = {{0}};
  bb_status st = bb_command_plan(r->command, &hooks, &job, &err);
  if (st != BB_OK)
    return cli_library_error(name, st, &err);
  printer p = {r->options, r->options->job.out_dir != NULL, {0}, &progress};
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
    print_summary(name, &p, bb_job_count(job));
  bb_job_free(job);
  return rc;
}
