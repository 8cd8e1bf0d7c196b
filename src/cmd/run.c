/* run.c: a checked command run in one call (bb_command_run): planned and
 * run as a job (bake, normal, height2ssbump), or read and made by its own
 * run and written through the job (run_render.c, run_maps.c); what it
 * wrote, for the caller to report. */
#include "cmd/cmd_internal.h"
#include "image/oiio_module.h"

#include <stdlib.h>
#include <string.h>

/* Through the job: every input in order, stopping at the first failure. */
static bb_status run_job(bb_command *c, const bb_command_hooks *hooks, bb_command_result *r,
                         bb_error *err) {
  bb_job *job = NULL;
  bb_status st = bb_command_plan(c, hooks, &job, err);
  if (st != BB_OK)
    return st;
  st = bb_job_run(job, hooks ? hooks->progress : NULL, hooks ? hooks->progress_user : NULL,
                  NULL, NULL, err);
  for (int i = 0; st == BB_OK && i < bb_job_count(job); i++) {
    const bb_job_report *report = bb_job_report_get(job, i);
    for (int k = 0; report->outcome == BB_JOB_BAKED && st == BB_OK && k < report->output_count;
         k++)
      st = bb__result_add(r, report->outputs[k].kind, report->outputs[k].path, err);
  }
  bb_job_free(job);
  return st;
}

static bb_status run(bb_command *c, const bb_command_hooks *hooks, bb_command_result *r,
                     bb_error *err) {
  if (!c || !r)
    return bb__fail(err, BB_ERR_ARGUMENT, "command run: bad arguments");
  memset(r, 0, sizeof *r);
  r->labels_drawn = 1;
  if (!c->checked)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: the command is not checked (bb_command_check)",
                    c->def->info.name);
  /* A command reads or writes images: the OpenImageIO module is loaded
   * before any work (image/oiio_module.h), so that a process short of
   * memory fails here, in one line, and the estimates count what it maps. */
  if (!bb__oiio_module())
    return bb__oiio_failed(err);
  bb_status st;
  if (c->def->job)
    st = run_job(c, hooks, r, err);
  else if (c->def->run) {
    if (c->def->before_run)
      c->def->before_run(c, hooks);
    st = c->def->run(c, hooks, r, err);
  }
  else
    st = bb__fail(err, BB_ERR_ARGUMENT, "%s writes no file to run", c->def->info.name);
  if (st != BB_OK)
    bb_command_result_free(r);
  return st;
}

bb_status bb_command_run(bb_command *c, const bb_command_hooks *hooks,
                         bb_command_result *r, bb_error *err) {
  bb__spelled_hooks h;
  return bb__spelled(c, run(c, c ? bb__spelled_hooks_of(c, hooks, &h) : hooks, r, err),
                     err);
}
