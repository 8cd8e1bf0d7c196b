/* command.c: the "command" a job's outputs record in their provenance: the
 * caller's command line when it gave one, else the bake's options written
 * out as `bumpbake bake` spells them (through their rows, bake_rows.c), so
 * the same job writes the same bytes from the command line and from
 * Python. Every word is quoted for a POSIX shell (bb__text_add_word): typed
 * in one, the line is that job. */
#include "core/internal.h"
#include "job/bake_rows.h"
#include "job/job_internal.h"

#include <stdlib.h>
#include <string.h>

/* The bake's options that differ from bb__job_options_init's, in the order
 * of `bumpbake bake --help` (bb__bake_rows: each row says when it is
 * written and how). threads is no row: the bytes are the same for any
 * count. */
char *bb__job_command_text(const bb_job_options *o, const char *input) {
  if (!o || !input)
    return NULL;
  bb_job_options d;
  bb__job_options_init(&d);
  bb__text t = {0};
  bb__text_add(&t, "bumpbake bake ");
  bb__text_add_word(&t, input);
  for (int i = 0; bb__bake_rows[i]; i++) {
    const bb__bake_row *r = bb__bake_rows[i];
    if (!bb__bake_row_differs(r, o, &d))
      continue;
    bb__text_printf(&t, " --%s", r->name);
    if (r->flag)
      continue;
    bb__text value = {0};
    bb__bake_row_value(r, o, &value);
    bb__text_add(&t, " ");
    bb__text_add_word(&t, value.data ? value.data : "");
    t.failed |= value.failed;
    bb__text_free(&value);
  }
  return bb__text_take(&t);
}

char *bb__job_command_of(const bb_job *job, const bb__job_item *item) {
  if (job->command)
    return strdup(job->command);
  if (!job->command_options) {
    bb_job_options as_given = job->options; /* rays spelled as asked, not resolved */
    as_given.bake.slices = job->asked_slices;
    return bb__job_command_text(&as_given, item->input);
  }
  /* "bumpbake bake INPUT OPTIONS", as a batch run by hand records it (the
   * options as the caller's record quoted them, or as bb__add_options
   * does). */
  bb__text t = {0};
  bb__text_add(&t, "bumpbake bake ");
  bb__text_add_word(&t, item->input);
  if (job->command_options[0]) {
    bb__text_add(&t, " ");
    bb__text_add(&t, job->command_options);
  }
  if (t.failed) {
    free(t.data);
    return NULL;
  }
  return t.data;
}
