/* command.c: the "command" a job's outputs record in their provenance:
 * the line the command that planned it records (bb__command_plan: the
 * caller's line as typed, else the command spelled through its
 * descriptions, bb_command_text), or for a batch the options alone after
 * "bumpbake bake INPUT". Every job records one: a plan without a command
 * is refused (plan.c). */
#include "core/internal.h"
#include "job/job_internal.h"

#include <stdlib.h>
#include <string.h>

char *bb__job_command_of(const bb_job *job, const bb__job_item *item) {
  if (job->command)
    return strdup(job->command);
  /* "bumpbake bake INPUT OPTIONS", as a batch run by hand records it (the
   * options as the caller's record quoted them, or as bb__add_options
   * does). */
  bb__text t = {0};
  bb__text_add(&t, "bumpbake bake ");
  bb__text_add_word(&t, item->input);
  if (job->command_options && job->command_options[0]) {
    bb__text_add(&t, " ");
    bb__text_add(&t, job->command_options);
  }
  if (t.failed) {
    free(t.data);
    return NULL;
  }
  return t.data;
}
