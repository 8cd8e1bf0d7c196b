/* command.c: the "command" a job's outputs record in their provenance: the
 * caller's command line when it gave one, else "bumpbake bake INPUT" and
 * the options as the caller spelled them (a command's, cmd/: only those
 * that determine the output). */
#include "core/internal.h"
#include "job/job_internal.h"

#include <stdlib.h>
#include <string.h>

char *bb__job_command_of(const bb_job *job, const bb__job_item *item) {
  if (job->command)
    return strdup(job->command);
  if (!job->command_options)
    return NULL; /* provenance then records an empty command */
  /* "bumpbake bake INPUT OPTIONS", as a batch run by hand records it. */
  bb__text t = {0};
  bb__text_add(&t, "bumpbake bake ");
  bb__text_add(&t, item->input);
  if (job->command_options[0]) {
    bb__text_add(&t, " ");
    bb__text_add(&t, job->command_options);
  }
  return bb__text_take(&t);
}
